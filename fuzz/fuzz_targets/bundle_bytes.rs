//! `cargo fuzz run bundle_bytes`: see `delta_collide_fuzz::bundle_bytes`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| delta_collide_fuzz::bundle_bytes(data));
