//! Portability to the controller (issue 5 item 5): the link line of the static library is
//! pinned, the per-tick code builds without std, and there is no SIMD path that would need
//! a CPU feature beyond the target's baseline.
//!
//! The two builds run the cargo of this test run in their own target directory
//! (`target/portability`, dev profile: the native libraries and the `no_std` check do not
//! depend on optimisation), so they never wait for the lock of the build running the tests;
//! after the first run they are incremental (under a second).

mod native_libs;

use native_libs::NATIVE_LIBS;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `cargo rustc --lib <args>` in the repository with its own target directory.
fn cargo_rustc(args: &[&str]) -> Output {
    let root = repo_root();
    Command::new(env!("CARGO"))
        .current_dir(&root)
        .args(["rustc", "--offline", "--lib", "--target-dir"])
        .arg(root.join("target/portability"))
        .args(args)
        .output()
        .expect("cargo runs")
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout)
}

/// The libraries rustc names in its `native-static-libs` note.
fn native_static_libs(log: &str) -> Vec<String> {
    let line = log.lines().find_map(|l| l.split_once("native-static-libs:")).map(|(_, libs)| libs);
    line.unwrap_or_else(|| panic!("no native-static-libs note in:\n{log}"))
        .split_whitespace()
        .map(str::to_owned)
        .collect()
}

#[test]
fn parses_the_native_static_libs_note() {
    let log = "   Compiling x\nnote: native-static-libs: -lgcc_s -lc\n    Finished";
    assert_eq!(native_static_libs(log), ["-lgcc_s", "-lc"]);
}

/// A new dependency that needs another system library fails here: add it to
/// `tests/native_libs/mod.rs` and to README.md's link line.
#[test]
fn static_library_needs_exactly_the_pinned_native_libs() {
    let out = cargo_rustc(&["--crate-type", "staticlib", "--", "--print", "native-static-libs"]);
    let log = text(&out);
    assert!(out.status.success(), "staticlib build failed:\n{log}");
    assert_eq!(native_static_libs(&log), NATIVE_LIBS, "the static library's native libs changed:\n{log}");
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    assert!(readme.contains(&NATIVE_LIBS.join(" ")), "README.md must list `{}`", NATIVE_LIBS.join(" "));
}

/// Without the `std` feature the library (math, geometry, robot, the exact check) compiles
/// as `#![no_std]` with `alloc`. On the host target std exists, so a dependency could pull it
/// in unnoticed; the staticlib build proves it does not: with std anywhere in the graph it
/// would link, without it rustc asks for the `#[panic_handler]` and allocator that a
/// firmware provides.
#[test]
fn per_tick_code_builds_without_std() {
    let out = cargo_rustc(&["--no-default-features", "--crate-type", "rlib"]);
    assert!(out.status.success(), "no_std rlib build failed:\n{}", text(&out));
    let out = cargo_rustc(&["--no-default-features", "--crate-type", "staticlib"]);
    let log = text(&out);
    assert!(!out.status.success(), "a no_std staticlib linked, so std is in the dependency graph:\n{log}");
    assert!(log.contains("`#[panic_handler]` function required"), "expected the missing panic handler:\n{log}");
    assert!(log.contains("no global memory allocator found"), "expected the missing allocator:\n{log}");
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable source directory") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The library is scalar code only, so the default build runs on the baseline of x86-64 and
/// ARM. A SIMD path must come with a scalar twin, be chosen at run time or by a feature,
/// and be tested against the twin; then this test is to be replaced by that one.
#[test]
fn library_has_no_simd_or_target_feature_code() {
    let mut files = Vec::new();
    rust_files(&repo_root().join("src"), &mut files);
    assert!(files.len() > 30, "found only {} source files", files.len());
    let markers = ["arch::", "target_feature", "is_x86_feature_detected", "is_aarch64_feature_detected", "simd"];
    for f in files {
        let src = std::fs::read_to_string(&f).expect("readable source");
        for m in markers {
            assert!(!src.contains(m), "{} contains `{m}`: give it a scalar twin and a test", f.display());
        }
    }
}
