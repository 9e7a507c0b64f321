//! The native libraries the static library needs at link time on Linux, as
//! `cargo rustc --release --lib --crate-type staticlib -- --print native-static-libs` prints
//! them. Pinned here once: `c_harness.rs` links with them, `portability.rs` checks that the
//! build still asks for exactly these, and README.md lists them.

/// In rustc's order.
pub const NATIVE_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"];
