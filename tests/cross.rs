//! Cross builds for the controller, run (docs/PORTABILITY.md, README "Portability and
//! cross-compiling"):
//! - 64-bit ARM (`aarch64-unknown-linux-gnu`) and 32-bit ARM with hard float
//!   (`armv7-unknown-linux-gnueabihf`): the controller's library
//!   (`--no-default-features --features std`) is built with the cross gcc as linker, its
//!   native libraries are checked against the pinned list, the C harness is compiled with the
//!   cross C compiler against the generated header and run under qemu-user, in exact and
//!   table mode on T1, T2, T3, and must end as the host's run does (same summary lines, same
//!   number of passed checks, none failed);
//! - x86-64 without AVX: the host's static library and harness run under
//!   `qemu-x86_64 -cpu qemu64` (SSE2/SSE3 only; qemu traps AVX there, which a probe checks).
//!
//! The builds use their own target directory `target/cross` (host build scripts shared by the
//! targets), so the suite's build cache is untouched. A missing tool (Rust target, cross gcc,
//! qemu) skips a test with a note saying what to install, except under `CI` (set and not
//! "false"), where it fails: `.ci/run` installs them.

mod harness_build;
mod native_libs;

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::{build_tables, to_bytes, Labelling, Variant};
use harness_build::{both, compile_harness, in_ci, repo_root, run, scratch_dir};
use native_libs::{native_static_libs, CROSS_NATIVE_LIBS, NATIVE_LIBS};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::time::Instant;

/// Table resolution: k = 16 keeps the labelling (host side) to about a second; the harness's
/// table mode runs the same code paths as at k = 32.
const TABLE_K: u32 = 16;

/// One Linux cross target: triple, cross C compiler, qemu-user binary, its sysroot, ELF machine.
struct Target {
    triple: &'static str,
    cc: &'static str,
    qemu: &'static str,
    sysroot: &'static str,
    elf_machine: u16,
    packages: &'static str,
}

const AARCH64: Target = Target {
    triple: "aarch64-unknown-linux-gnu",
    cc: "aarch64-linux-gnu-gcc",
    qemu: "qemu-aarch64",
    sysroot: "/usr/aarch64-linux-gnu",
    elf_machine: 183, // EM_AARCH64
    packages: "gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user",
};

const ARMV7: Target = Target {
    triple: "armv7-unknown-linux-gnueabihf",
    cc: "arm-linux-gnueabihf-gcc",
    qemu: "qemu-arm",
    sysroot: "/usr/arm-linux-gnueabihf",
    elf_machine: 40, // EM_ARM
    packages: "gcc-arm-linux-gnueabihf libc6-dev-armhf-cross qemu-user",
};

/// `Err(what to install)` unless `program --version` runs.
fn tool(program: &str, install: &str) -> Result<(), String> {
    match Command::new(program).arg("--version").output() {
        Ok(o) if o.status.success() => Ok(()),
        _ => Err(format!("`{program}` is missing: install {install}")),
    }
}

/// `Err(what to install)` unless the Rust standard library for `triple` is installed.
fn rust_target(triple: &str) -> Result<(), String> {
    let out = Command::new("rustc").args(["--print", "target-libdir", "--target", triple]).output();
    let dir = out
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
    let has_core = dir.and_then(|d| std::fs::read_dir(d).ok()).is_some_and(|mut entries| {
        entries.any(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with("libcore-")))
    });
    if has_core {
        Ok(())
    } else {
        Err(format!(
            "the Rust target {triple} is missing: install it with `rustup target add {triple}`"
        ))
    }
}

/// Whether the test may go on: every requirement met, or (outside CI) a note and a skip.
fn requirements_met(test: &str, checks: &[Result<(), String>]) -> bool {
    let missing: Vec<&str> =
        checks.iter().filter_map(|c| c.as_ref().err().map(String::as_str)).collect();
    if missing.is_empty() {
        return true;
    }
    let why = missing.join("; ");
    assert!(!in_ci(), "{test} cannot be skipped on CI: {why} (.ci/run installs them)");
    println!("skipped: {test}: {why}");
    false
}

/// The e_machine field of an ELF file.
fn elf_machine(path: &Path) -> u16 {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(bytes.get(..4), Some(&b"\x7fELF"[..]), "{} is not an ELF file", path.display());
    u16::from_le_bytes([bytes[18], bytes[19]])
}

/// The controller's library for `t`: `cargo rustc --release --lib --no-default-features
/// --features std --target T -- --print native-static-libs` with the cross gcc as linker
/// (it links the cdylib). Returns the static library.
fn cross_library(t: &Target) -> PathBuf {
    let root = repo_root();
    let start = Instant::now();
    let linker_var = format!("CARGO_TARGET_{}_LINKER", t.triple.to_uppercase().replace('-', "_"));
    let out = run(Command::new(env!("CARGO"))
        .current_dir(&root)
        .env(linker_var, t.cc)
        .args([
            "rustc",
            "--release",
            "--lib",
            "--no-default-features",
            "--features",
            "std",
            "--target",
            t.triple,
        ])
        .arg("--target-dir")
        .arg(root.join("target/cross"))
        .args(["--", "--print", "native-static-libs"]));
    let log = both(&out);
    assert!(out.status.success(), "cross build for {} failed:\n{log}", t.triple);
    println!("{}: library built in {:.1} s", t.triple, start.elapsed().as_secs_f64());
    let pinned =
        CROSS_NATIVE_LIBS.iter().find(|(triple, _)| *triple == t.triple).expect("pinned libs").1;
    assert_eq!(
        native_static_libs(&log),
        pinned,
        "{}: the static library's native libs changed:\n{log}",
        t.triple
    );
    let dir = root.join("target/cross").join(t.triple).join("release");
    assert_eq!(
        elf_machine(&dir.join("libdelta_collide.so")),
        t.elf_machine,
        "{}: cdylib machine",
        t.triple
    );
    dir.join("libdelta_collide.a")
}

/// Table files of T1 (6-D), T2 (shared 6-D quadtree), T3 (6-D) at k = [`TABLE_K`], built once
/// per test process: `--table` arguments of the harness.
fn table_args() -> &'static [String] {
    static ARGS: OnceLock<Vec<String>> = OnceLock::new();
    ARGS.get_or_init(|| {
        let dir = scratch_dir("cross_tables");
        let start = Instant::now();
        // The protective scenarios' interval arithmetic takes many minutes under qemu-user: the
        // host and the emulated runs both do T1 collision only (the host harness test does all).
        let mut args = vec!["--protective-quick".to_string()];
        for (name, variant) in [("T1", Variant::D6), ("T2", Variant::Shared), ("T3", Variant::D6)] {
            let cell = reference_cell(name).expect("reference cell");
            let (header, tables, _) = build_tables(
                &cell,
                TABLE_K,
                &Workspace::THESIS,
                &[variant],
                Labelling::Certified,
                Progress::Silent,
            )
            .unwrap_or_else(|e| panic!("building the {name} table: {e}"));
            let path = dir.join(format!("{name}_k{TABLE_K}.dct"));
            std::fs::write(&path, to_bytes(&tables[0], &header)).expect("write table");
            args.extend(["--table".to_string(), format!("{name}={}", path.display())]);
        }
        println!("tables T1 T2 T3 (k = {TABLE_K}) built in {:.1} s", start.elapsed().as_secs_f64());
        args
    })
}

/// What a harness run must reproduce elsewhere: its summary lines and `N passed, 0 failed`.
fn outcome(what: &str, out: &Output) -> Vec<String> {
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{what}: exit status {:?}\n{stdout}{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let last = stdout.lines().last().unwrap_or_default();
    assert!(
        last.ends_with(" passed, 0 failed") && !last.starts_with("0 "),
        "{what}: verdict line `{last}`"
    );
    let summaries: Vec<String> =
        stdout.lines().filter(|l| l.starts_with("summary ")).map(str::to_owned).collect();
    assert_eq!(summaries.len(), 6, "{what}: a table-mode summary per cell and case:\n{stdout}");
    summaries.into_iter().chain([last.to_owned()]).collect()
}

/// The static library of this cargo run (next to the test executable, as `c_harness.rs`).
fn host_static_lib() -> PathBuf {
    let exe = std::env::current_exe().expect("path of the test executable");
    let deps = exe.parent().expect("deps dir");
    [
        deps.join("libdelta_collide.a"),
        deps.parent().expect("profile dir").join("libdelta_collide.a"),
    ]
    .into_iter()
    .find(|p| p.is_file())
    .expect("the static library of this cargo run")
}

/// The harness for the host, compiled once per test process.
fn host_harness() -> &'static Path {
    static EXE: OnceLock<PathBuf> = OnceLock::new();
    EXE.get_or_init(|| {
        let exe = scratch_dir("cross_host").join("c_harness");
        compile_harness("cc", &[], &host_static_lib(), NATIVE_LIBS, &exe);
        exe
    })
}

/// The host harness's outcome on the tables of [`table_args`], run natively once.
fn host_outcome() -> &'static [String] {
    static OUTCOME: OnceLock<Vec<String>> = OnceLock::new();
    OUTCOME.get_or_init(|| {
        let tmp = scratch_dir("cross_host_tmp");
        let out = run(Command::new(host_harness())
            .arg("--tmp")
            .arg(&tmp)
            .args(table_args())
            .current_dir(repo_root()));
        outcome("host harness", &out)
    })
}

/// Builds for `t`, compiles the harness with its C compiler and runs it under qemu-user.
fn harness_runs_under_qemu(t: &Target) {
    let test = format!("C harness on {}", t.triple);
    let sysroot = if Path::new(t.sysroot).join("lib").is_dir() {
        Ok(())
    } else {
        Err(format!(
            "the C library for qemu under {} is missing: install {}",
            t.sysroot, t.packages
        ))
    };
    let checks =
        [rust_target(t.triple), tool(t.cc, t.packages), tool(t.qemu, "qemu-user"), sysroot];
    if !requirements_met(&test, &checks) {
        return;
    }
    let lib = cross_library(t);
    let pinned =
        CROSS_NATIVE_LIBS.iter().find(|(triple, _)| *triple == t.triple).expect("pinned libs").1;
    let exe = scratch_dir(&format!("cross_{}", t.triple)).join("c_harness");
    compile_harness(t.cc, &[], &lib, pinned, &exe);
    assert_eq!(elf_machine(&exe), t.elf_machine, "{}: harness machine", t.triple);
    let tmp = scratch_dir(&format!("cross_{}_tmp", t.triple));
    let start = Instant::now();
    let out = run(Command::new(t.qemu)
        .args(["-L", t.sysroot])
        .arg(&exe)
        .arg("--tmp")
        .arg(&tmp)
        .args(table_args())
        .current_dir(repo_root()));
    let ran = outcome(&format!("{test} under {}", t.qemu), &out);
    println!("{test} under {}: {:.1} s\n{}", t.qemu, start.elapsed().as_secs_f64(), ran.join("\n"));
    assert_eq!(ran, host_outcome(), "{test}: the run differs from the host's");
}

#[test]
fn c_harness_runs_on_aarch64_under_qemu() {
    harness_runs_under_qemu(&AARCH64);
}

#[test]
fn c_harness_runs_on_armv7_hard_float_under_qemu() {
    harness_runs_under_qemu(&ARMV7);
}

/// Executes AVX (`vaddpd` on ymm registers): SIGILL on a CPU without AVX.
const AVX_PROBE_C: &str = r#"#include <immintrin.h>
#include <stdio.h>
__attribute__((target("avx"))) static double sum4(const double *a) {
    double out[4];
    __m256d v = _mm256_loadu_pd(a);
    _mm256_storeu_pd(out, _mm256_add_pd(v, v));
    return out[0] + out[1] + out[2] + out[3];
}
int main(int argc, char **argv) {
    double a[4] = { 1.0, 2.0, 3.0, 4.0 };
    (void)argv;
    a[3] += argc;
    printf("%g\n", sum4(a));
    return 0;
}
"#;

/// The default build needs only the x86-64 baseline: the harness on the host's static library
/// gives the host's outcome under qemu's `qemu64` CPU (SSE2, SSE3; no SSSE3, SSE4, POPCNT,
/// AVX, FMA), where qemu traps AVX (the probe shows it does).
#[test]
fn c_harness_runs_on_x86_64_baseline_without_avx() {
    let test = "C harness on an x86-64 CPU without AVX";
    if !requirements_met(test, &[tool("qemu-x86_64", "qemu-user")]) {
        return;
    }
    let dir = scratch_dir("cross_x86_64_baseline");
    let probe = dir.join("avx_probe");
    std::fs::write(dir.join("avx_probe.c"), AVX_PROBE_C).unwrap();
    let out = run(Command::new("cc").args(["-O1", "-o"]).arg(&probe).arg(dir.join("avx_probe.c")));
    assert!(out.status.success(), "cc avx_probe:\n{}", both(&out));
    let max = run(Command::new("qemu-x86_64").args(["-cpu", "max"]).arg(&probe));
    assert!(max.status.success(), "the AVX probe fails on qemu's `max` CPU:\n{}", both(&max));
    let baseline = run(Command::new("qemu-x86_64").args(["-cpu", "qemu64"]).arg(&probe));
    assert!(
        !baseline.status.success(),
        "qemu64 ran AVX code, so it cannot show that AVX is not needed"
    );
    let tmp = scratch_dir("cross_x86_64_baseline_tmp");
    let start = Instant::now();
    let out = run(Command::new("qemu-x86_64")
        .args(["-cpu", "qemu64"])
        .arg(host_harness())
        .arg("--tmp")
        .arg(&tmp)
        .args(table_args())
        .current_dir(repo_root()));
    let ran = outcome("harness under qemu-x86_64 -cpu qemu64", &out);
    println!("{test}: {:.1} s\n{}", start.elapsed().as_secs_f64(), ran.join("\n"));
    assert_eq!(ran, host_outcome(), "{test}: the run differs from the native one");
}

/// docs/PORTABILITY.md lists each cross target's native libraries as pinned here.
#[test]
fn portability_doc_lists_the_native_libs_of_every_target() {
    let doc = std::fs::read_to_string(repo_root().join("docs/PORTABILITY.md"))
        .expect("docs/PORTABILITY.md");
    let rows = CROSS_NATIVE_LIBS.iter().chain([&("x86_64-unknown-linux-gnu", NATIVE_LIBS)]);
    for (triple, libs) in rows {
        let row = format!("| `{triple}` | `{}` |", libs.join(" "));
        assert!(doc.contains(&row), "docs/PORTABILITY.md must have the row {row}");
    }
}
