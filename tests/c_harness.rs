//! The C harness (thesis appendix A.1, SPEC §5): builds `c_harness/*.c` with the system C
//! compiler against the generated header `include/delta_collide.h` and the static library,
//! runs it from the repository root and checks its verdict line. Also compiles the header
//! into two C++ translation units (wasmtime's double-include check) and records whether it
//! is valid C89.
//!
//! The static library is the one cargo builds in the same run: the test executable is
//! `target/<profile>/deps/c_harness-HASH` and the library lies next to it in `deps/`.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Native libraries the static library needs on Linux (`--print native-static-libs`).
const NATIVE_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"];

/// Strict C flags of the house style (rustls-ffi's CI).
const C_FLAGS: &[&str] = &["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2"];

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The static library built in this cargo run. `cargo test` writes it next to the test
/// executable (`target/<profile>/deps/libdelta_collide.a`) and does not copy it up to
/// `target/<profile>/` (only `cargo build` does), so the copy there may be stale or absent.
fn static_lib() -> PathBuf {
    let exe = std::env::current_exe().expect("path of the test executable");
    let deps_dir = exe.parent().expect("exe lies in target/<profile>/deps");
    let profile_dir = deps_dir.parent().expect("deps lies in target/<profile>");
    let candidates = [deps_dir.join("libdelta_collide.a"), profile_dir.join("libdelta_collide.a")];
    candidates
        .iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("static library not found at {candidates:?} (crate-type staticlib?)"))
        .clone()
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// Runs a command, returning its output; panics with the command line when it cannot start.
fn run(cmd: &mut Command) -> Output {
    cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"))
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Parses the last `N passed, M failed` line of the harness output.
fn verdict_line(stdout: &str) -> Option<(u64, u64)> {
    stdout.lines().rev().find_map(|line| {
        let (passed, failed) = line.trim().split_once(" passed, ")?;
        let failed = failed.strip_suffix(" failed")?;
        Some((passed.parse().ok()?, failed.parse().ok()?))
    })
}

#[test]
fn c_harness_builds_with_strict_flags_and_passes() {
    let root = repo_root();
    let dir = scratch_dir("c_harness");
    let exe = dir.join("c_harness");
    let mut sources: Vec<PathBuf> = std::fs::read_dir(root.join("c_harness"))
        .expect("c_harness/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "c"))
        .collect();
    sources.sort();
    assert_eq!(sources.len(), 3, "expected main.c, mock_robotics.c, pou.c; found {sources:?}");

    let out = run(Command::new("cc")
        .args(C_FLAGS)
        .arg("-I")
        .arg(root.join("include"))
        .arg("-I")
        .arg(root.join("c_harness"))
        .args(&sources)
        .arg(static_lib())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe));
    assert!(out.status.success(), "cc failed:\n{}{}", text(&out.stdout), text(&out.stderr));

    let out = run(Command::new(&exe).arg(&dir).current_dir(&root));
    let stdout = text(&out.stdout);
    println!("{stdout}");
    eprintln!("{}", text(&out.stderr));
    let (passed, failed) = verdict_line(&stdout).expect("harness prints `N passed, N failed` last");
    assert!(passed > 0, "the harness ran no checks");
    assert_eq!(failed, 0, "the harness reported failures (see above)");
    assert!(out.status.success(), "harness exit status {:?} with 0 failures", out.status);
}

#[test]
fn header_compiles_in_two_cpp_translation_units() {
    let root = repo_root();
    let dir = scratch_dir("c_harness_cpp");
    let a = dir.join("a.cpp");
    let b = dir.join("b.cpp");
    let exe = dir.join("two_units");
    // Included twice in one unit (include guard) and once more in the other (no definitions
    // with external linkage in the header, or the link fails).
    std::fs::write(
        &a,
        "#include \"delta_collide.h\"\n#include \"delta_collide.h\"\n\
         const char *version_from_a() { DcVec3 v = {1.0, 2.0, 3.0}; (void)v; return dc_version(); }\n",
    )
    .unwrap();
    std::fs::write(
        &b,
        "#include <cstdio>\n#include <cstring>\n#include \"delta_collide.h\"\n\
         const char *version_from_a();\n\
         int main() {\n  const char *v = dc_version();\n\
           if (std::strcmp(v, version_from_a()) != 0) return 2;\n\
           std::printf(\"%s\\n\", v);\n  return dc_robot_count(NULL) == 0 ? 0 : 3;\n}\n",
    )
    .unwrap();
    let out = run(Command::new("c++")
        .args(["-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(root.join("include"))
        .arg(&a)
        .arg(&b)
        .arg(static_lib())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe));
    assert!(out.status.success(), "c++ failed:\n{}{}", text(&out.stdout), text(&out.stderr));
    let out = run(&mut Command::new(&exe));
    assert!(out.status.success(), "C++ program exit status {:?}", out.status);
    assert_eq!(text(&out.stdout).trim(), env!("CARGO_PKG_VERSION"), "dc_version() from C++");
}

/// Records whether the header is valid C89 (a controller's compiler may be strict ANSI C).
/// cbindgen's defaults write `// __cplusplus` after `#endif` (extra tokens, not comments, in
/// C89, as in rustls.h) and include `<stdint.h>` (C99, though gcc ships it in C89 mode too).
/// The test prints the outcome under `-pedantic` and `-pedantic-errors` and asserts that
/// every diagnostic is one of those known reasons, so a new C89 problem shows up here.
#[test]
fn header_as_c89_is_recorded() {
    let root = repo_root();
    let dir = scratch_dir("c_harness_c89");
    let src = dir.join("c89.c");
    std::fs::write(&src, "#include \"delta_collide.h\"\nint c89_unit_is_not_empty;\n").unwrap();
    let known = [
        "extra tokens at end of #endif",
        "C++ style comments",
        "stdint.h",
        "stdbool.h",
        "long long",
        "_Bool",
        "boolean",
    ];
    for strictness in ["-pedantic", "-pedantic-errors"] {
        let out = run(Command::new("cc")
            .args(["-std=c89", strictness, "-fsyntax-only", "-I"])
            .arg(root.join("include"))
            .arg(&src));
        let stderr = text(&out.stderr);
        let verdict = if out.status.success() { "compiles" } else { "does NOT compile" };
        println!("header {verdict} with cc -std=c89 {strictness}; diagnostics:\n{stderr}");
        for line in stderr.lines().filter(|l| l.contains("warning") || l.contains("error")) {
            assert!(
                known.iter().any(|k| line.contains(k)),
                "C89 diagnostic for a reason other than cbindgen's C99-isms: {line}"
            );
        }
    }
}
