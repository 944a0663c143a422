#![no_main]
//! cargo +nightly fuzz run --fuzz-dir tests/fuzz mitsuba_scene (see the book: Stress and fuzzing).

#[path = "../import_harness.rs"]
mod import_harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    import_harness::mitsuba_scene(data);
});
