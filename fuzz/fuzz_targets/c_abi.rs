//! `cargo fuzz run c_abi`: see `delta_collide_fuzz::c_abi`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| delta_collide_fuzz::c_abi(data));
