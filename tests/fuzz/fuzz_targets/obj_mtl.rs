#![no_main]
//! cargo +nightly fuzz run --fuzz-dir tests/fuzz obj_mtl (see README: Fuzzing).

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    harness::obj_mtl(data);
});
