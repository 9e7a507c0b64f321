//! `cargo fuzz run exact_oracle`: see `delta_collide_fuzz::exact_oracle`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| delta_collide_fuzz::exact_oracle(data));
