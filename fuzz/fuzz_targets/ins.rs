#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| estimator_fuzz_checks::fuzz_one(
    data,
    estimator_fuzz_checks::run_ins
));
