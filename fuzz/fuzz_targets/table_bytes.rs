//! `cargo fuzz run table_bytes`: see `delta_collide_fuzz::table_bytes`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| delta_collide_fuzz::table_bytes(data));
