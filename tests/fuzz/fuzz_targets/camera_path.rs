#![no_main]
//! cargo +nightly fuzz run --fuzz-dir tests/fuzz camera_path (see README: Fuzzing).

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    harness::camera_path(data);
});
