#![no_main]
//! cargo +nightly fuzz run --fuzz-dir tests/fuzz overrides (see README: Fuzzing).

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    harness::overrides(data);
});
