//! `cargo fuzz run cell_toml`: see `delta_collide_fuzz::cell_toml`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| delta_collide_fuzz::cell_toml(data));
