//! Building and running the C harness from a test: the strict C flags, the harness's sources
//! and the process helpers that `c_harness.rs` (host) and `cross.rs` (cross targets, qemu)
//! both use.
#![allow(dead_code)] // each test file uses a subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Strict C flags of the house style (rustls-ffi's CI).
pub const C_FLAGS: &[&str] = &["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2"];

pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `name` under cargo's scratch directory for integration tests, created.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// Whether this run is CI's (`CI` set and not "false" or "0"), where a missing tool is an
/// error rather than a skip.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The static library built in this cargo run. `cargo test` writes it next to the test
/// executable (`target/<profile>/deps/libdelta_collide.a`) and does not copy it up to
/// `target/<profile>/` (only `cargo build` does), so the copy there may be stale or absent.
pub fn static_lib() -> PathBuf {
    let exe = std::env::current_exe().expect("path of the test executable");
    let deps_dir = exe.parent().expect("exe lies in target/<profile>/deps");
    let profile_dir = deps_dir.parent().expect("deps lies in target/<profile>");
    let candidates = [deps_dir.join("libdelta_collide.a"), profile_dir.join("libdelta_collide.a")];
    candidates
        .iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| {
            panic!("static library not found at {candidates:?} (crate-type staticlib?)")
        })
        .clone()
}

/// Runs a command, returning its output; panics with the command line when it cannot start.
pub fn run(cmd: &mut Command) -> Output {
    cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"))
}

/// Bytes of an output stream as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Standard output then standard error.
pub fn both(out: &Output) -> String {
    text(&out.stdout) + &text(&out.stderr)
}

/// The C sources of the harness, sorted.
pub fn harness_sources() -> Vec<PathBuf> {
    let mut sources: Vec<PathBuf> = std::fs::read_dir(repo_root().join("c_harness"))
        .expect("c_harness/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "c"))
        .collect();
    sources.sort();
    let names: Vec<_> =
        sources.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    let expected = [
        "bad_input.c",
        "coordination.c",
        "harness.c",
        "line.c",
        "main.c",
        "mock_robotics.c",
        "pou.c",
        "protective.c",
        "speed_override.c",
        "table_mode.c",
        "timing.c",
    ];
    assert_eq!(names, expected, "c_harness/ sources changed: update this list and the README");
    sources
}

/// Compiles the harness into `exe` with compiler `cc`, the strict flags plus `extra`, against
/// the generated header, the static library `lib` and the native libraries `libs`.
pub fn compile_harness(cc: &str, extra: &[&str], lib: &Path, libs: &[&str], exe: &Path) {
    let root = repo_root();
    let out = run(Command::new(cc)
        .args(C_FLAGS)
        .args(extra)
        .arg("-I")
        .arg(root.join("include"))
        .arg("-I")
        .arg(root.join("c_harness"))
        .args(harness_sources())
        .arg(lib)
        .args(libs)
        .arg("-o")
        .arg(exe));
    assert!(out.status.success(), "{cc} {extra:?} failed on the harness:\n{}", both(&out));
}

/// The program `tests/data/instruction_budgets.c` compiled into `dir` against the static
/// library and its native libraries `libs` (`native_libs::NATIVE_LIBS`).
pub fn budget_program(dir: &Path, libs: &[&str]) -> PathBuf {
    let exe = dir.join("instruction_budgets");
    let out = run(Command::new("cc")
        .args(C_FLAGS)
        .arg("-I")
        .arg(repo_root().join("include"))
        .arg(repo_root().join("tests/data/instruction_budgets.c"))
        .arg(static_lib())
        .args(libs)
        .arg("-o")
        .arg(&exe));
    assert!(out.status.success(), "the program does not compile:\n{}", text(&out.stderr));
    exe
}
