//! The fuzz targets of delta-collide, as plain functions over bytes.
//!
//! Each `fuzz_targets/<name>.rs` binary hands libFuzzer's input to one of them; the main
//! crate's `tests/fuzz_short.rs` compiles this same file (`#[path]`) to replay the committed
//! seeds in `fuzz/seeds/<name>/` in-process, and runs each binary briefly with `cargo fuzz`.
//! A target panics (an `assert!`) on a finding; any input at all is valid.
//!
//! | target | input | checks |
//! |---|---|---|
//! | [`table_bytes`] | a table file | `table::from_bytes`, `TableChecker::new`, queries |
//! | [`bundle_bytes`] | a bundle file | `table::bundle_from_bytes`, `BundleChecker` against exact mode |
//! | [`cell_toml`] | a cell file | `cell::parse_cell`, `ExactChecker`, the same cell through `dc_init` |
//! | [`c_abi`] | a call sequence ([`c_abi::Op`]) | every `extern "C"` function, fail-closed outputs |
//! | [`exact_oracle`] | two TCPs, plain or on a singular family | `ExactChecker` against a frame-free brute force |
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod bundle_bytes;
pub mod c_abi;
pub mod cell_toml;
pub mod exact_oracle;
pub mod input;
pub mod table_bytes;

pub use bundle_bytes::bundle_bytes;
pub use c_abi::c_abi;
pub use cell_toml::cell_toml;
pub use exact_oracle::exact_oracle;
pub use table_bytes::table_bytes;

/// A fuzz target: panics on a finding.
pub type Target = fn(&[u8]);

/// The targets by name, as `cargo fuzz` and `fuzz/seeds/` name them.
pub const TARGETS: [(&str, Target); 5] = [
    ("table_bytes", table_bytes),
    ("bundle_bytes", bundle_bytes),
    ("cell_toml", cell_toml),
    ("c_abi", c_abi),
    ("exact_oracle", exact_oracle),
];
