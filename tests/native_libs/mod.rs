//! The native libraries the static library needs at link time on Linux, as
//! `cargo rustc --release --lib --crate-type staticlib -- --print native-static-libs` prints
//! them (with `--target T` for another target). Pinned here once: `c_harness.rs` links with
//! them, `portability.rs` and `cross.rs` check that the builds still ask for exactly these,
//! and README.md lists them.
#![allow(dead_code)] // each test file uses a subset

/// The host target, x86-64 Linux (glibc), in rustc's order.
pub const NATIVE_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"];

/// The cross targets `tests/cross.rs` builds (the controller's library,
/// `--no-default-features --features std`), in rustc's order.
pub const CROSS_NATIVE_LIBS: &[(&str, &[&str])] = &[
    (
        "aarch64-unknown-linux-gnu",
        &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"],
    ),
    (
        "armv7-unknown-linux-gnueabihf",
        &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"],
    ),
];

/// The libraries rustc names in its `native-static-libs` note.
pub fn native_static_libs(log: &str) -> Vec<String> {
    let line = log.lines().find_map(|l| l.split_once("native-static-libs:")).map(|(_, libs)| libs);
    line.unwrap_or_else(|| panic!("no native-static-libs note in:\n{log}"))
        .split_whitespace()
        .map(str::to_owned)
        .collect()
}
