//! Portability to the controller: the link line of the static library is
//! pinned, the per-tick code builds without std, and there is no SIMD path that would need
//! a CPU feature beyond the target's baseline. The cross builds for ARM Linux and the run on
//! an x86-64 CPU without AVX are in `tests/cross.rs`.
//!
//! The first builds run the cargo of this test run in their own target directory
//! (`target/portability`, dev profile: the native libraries and the `no_std` check do not
//! depend on optimisation), so they never wait for the lock of the build running the tests;
//! after the first run they are incremental (under a second).
//!
//! Without std, a firmware's view (`tests/no_std_consumer/`): a `#![no_std]` static library
//! with its own panic handler and allocator that loads tables from bytes and answers ticks
//! with `TableChecker`, compiled with `rustc` against the `--no-default-features` build
//! (`target/cross`, release, `panic = "abort"`). On the host it is linked into a C driver
//! and run, and must answer as the std build does; for `thumbv7em-none-eabihf` (Cortex-M4F,
//! no operating system) it is linked with `rust-lld`. Where the bare-metal Rust target is
//! missing that test is skipped with a note, except under `CI`, where it fails.

extern crate alloc;

mod native_libs;
#[path = "no_std_consumer/workload.rs"]
mod workload;

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::{build_tables, to_bytes, Labelling, SliceAxes, Variant};
use native_libs::{native_static_libs, NATIVE_LIBS};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::time::Instant;

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
    assert_eq!(
        native_static_libs(&log),
        NATIVE_LIBS,
        "the static library's native libs changed:\n{log}"
    );
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    assert!(
        readme.contains(&NATIVE_LIBS.join(" ")),
        "README.md must list `{}`",
        NATIVE_LIBS.join(" ")
    );
}

/// Without the `std` feature the library (math, geometry, robot, the exact check, table
/// loading and queries) compiles as `#![no_std]` with `alloc`. On the host target std exists, so a
/// dependency could pull it in unnoticed; the staticlib build proves it does not: with std anywhere
/// in the graph it would link, without it rustc asks for the `#[panic_handler]` and allocator that
/// a firmware provides.
#[test]
fn per_tick_code_builds_without_std() {
    let out = cargo_rustc(&["--no-default-features", "--crate-type", "rlib"]);
    assert!(out.status.success(), "no_std rlib build failed:\n{}", text(&out));
    let out = cargo_rustc(&["--no-default-features", "--crate-type", "staticlib"]);
    let log = text(&out);
    assert!(
        !out.status.success(),
        "a no_std staticlib linked, so std is in the dependency graph:\n{log}"
    );
    assert!(
        log.contains("`#[panic_handler]` function required"),
        "expected the missing panic handler:\n{log}"
    );
    assert!(
        log.contains("no global memory allocator found"),
        "expected the missing allocator:\n{log}"
    );
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
    let markers = [
        "arch::",
        "target_feature",
        "is_x86_feature_detected",
        "is_aarch64_feature_detected",
        "simd",
    ];
    for f in files {
        let src = std::fs::read_to_string(&f).expect("readable source");
        for m in markers {
            assert!(
                !src.contains(m),
                "{} contains `{m}`: give it a scalar twin and a test",
                f.display()
            );
        }
    }
}

/// Whether this run is CI's (`CI` set and not "false"), where nothing may be skipped.
fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The output of `rustc <args>` (the rustc cargo runs: the first `rustc` on `PATH`).
fn rustc_print(args: &[&str]) -> Option<String> {
    let out = Command::new("rustc").args(args).output().ok().filter(|o| o.status.success())?;
    Some(String::from_utf8_lossy(&out.stdout).trim().to_owned())
}

/// `Err(what to install)` unless the Rust standard library for `triple` is installed.
fn rust_target(triple: &str) -> Result<(), String> {
    let dir = rustc_print(&["--print", "target-libdir", "--target", triple]);
    let has_core = dir.and_then(|d| std::fs::read_dir(d).ok()).is_some_and(|mut entries| {
        entries.any(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with("libcore-")))
    });
    has_core
        .then_some(())
        .ok_or(format!("`rustup target add {triple}` (its standard library is missing)"))
}

/// The `--no-default-features` library for `triple`, release with `panic = "abort"` (a
/// firmware's profile), in `target/cross`; returns the directory with
/// `libdelta_collide.rlib` and `deps/`.
fn no_std_rlib(triple: &str) -> PathBuf {
    let root = repo_root();
    let start = Instant::now();
    let out = Command::new(env!("CARGO"))
        .current_dir(&root)
        .env("CARGO_PROFILE_RELEASE_PANIC", "abort")
        .args([
            "rustc",
            "--release",
            "--lib",
            "--crate-type",
            "rlib",
            "--no-default-features",
            "--target",
            triple,
        ])
        .arg("--target-dir")
        .arg(root.join("target/cross"))
        .output()
        .expect("cargo runs");
    assert!(out.status.success(), "no_std build for {triple} failed:\n{}", text(&out));
    println!("{triple}: no_std library built in {:.1} s", start.elapsed().as_secs_f64());
    root.join("target/cross").join(triple).join("release")
}

/// The tables of T1 at k = 16 that `no_std_consumer/consumer.rs` embeds, in its order, from
/// one certified labelling with sub-cells; built once per test process.
fn consumer_tables() -> &'static (PathBuf, Vec<Vec<u8>>) {
    static TABLES: OnceLock<(PathBuf, Vec<Vec<u8>>)> = OnceLock::new();
    TABLES.get_or_init(|| {
        let variants = [
            ("6d", Variant::D6),
            ("5d", Variant::D5),
            ("4d_yy", Variant::D4 { axes: SliceAxes::YY, t: 0 }),
            ("4d_zz", Variant::D4 { axes: SliceAxes::ZZ, t: 0 }),
            ("shared", Variant::Shared),
            ("shared_sub", Variant::SharedSubdivided),
        ];
        let cell = reference_cell("T1").expect("T1");
        let kinds: Vec<Variant> = variants.iter().map(|v| v.1).collect();
        let (header, tables, _) = build_tables(
            &cell,
            16,
            &Workspace::THESIS,
            &kinds,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the T1 tables: {e}"));
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("no_std_tables");
        std::fs::create_dir_all(&dir).expect("create the table dir");
        let bytes: Vec<Vec<u8>> = tables.iter().map(|t| to_bytes(t, &header)).collect();
        for ((name, _), b) in variants.iter().zip(&bytes) {
            std::fs::write(dir.join(format!("t1_{name}.dct")), b).expect("write a table");
        }
        (dir, bytes)
    })
}

/// `tests/no_std_consumer/consumer.rs` as a static library for `triple` against the
/// `no_std` library in `rlib_dir`; asserts that it needs no native library.
fn consumer_staticlib(triple: &str, rlib_dir: &Path) -> PathBuf {
    let out_dir =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("no_std_consumer_{triple}"));
    std::fs::create_dir_all(&out_dir).expect("create the consumer dir");
    let out = Command::new("rustc")
        .env("DC_NOSTD_TABLES", &consumer_tables().0)
        .args([
            "--edition",
            "2021",
            "--crate-type",
            "staticlib",
            "--crate-name",
            "dc_nostd_consumer",
        ])
        .args(["-C", "panic=abort", "-C", "opt-level=2", "--target", triple, "--extern"])
        .arg(format!("delta_collide={}", rlib_dir.join("libdelta_collide.rlib").display()))
        .arg("-L")
        .arg(format!("dependency={}", rlib_dir.join("deps").display()))
        .arg("--out-dir")
        .arg(&out_dir)
        .arg(repo_root().join("tests/no_std_consumer/consumer.rs"))
        .args(["--print", "native-static-libs"])
        .output()
        .expect("rustc runs");
    let log = text(&out);
    assert!(out.status.success(), "the no_std consumer for {triple} does not compile:\n{log}");
    assert_eq!(
        native_static_libs(&log),
        Vec::<String>::new(),
        "a no_std library needs no native library:\n{log}"
    );
    out_dir.join("libdc_nostd_consumer.a")
}

/// The table query path without std, run: the consumer's answers for every table variant of
/// T1 (6-D, 5-D, both 4-D, shared, shared with sub-cells) over 20,000 configurations equal
/// the std build's (maths from libm against std's), and its queries allocate nothing.
#[test]
fn table_queries_without_std_answer_as_with_std() {
    let host = rustc_print(&["-vV"])
        .and_then(|v| v.lines().find_map(|l| l.strip_prefix("host: ").map(str::to_owned)));
    let host = host.expect("rustc -vV names the host");
    let lib = consumer_staticlib(&host, &no_std_rlib(&host));
    let driver = lib.with_file_name("driver");
    let out = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2"])
        .arg(repo_root().join("tests/no_std_consumer/driver.c"))
        .arg(&lib)
        .arg("-o")
        .arg(&driver)
        .output()
        .expect("cc runs");
    assert!(out.status.success(), "cc driver.c failed:\n{}", text(&out));
    let (seed, n) = (0x5eed_u64, 20_000u32);
    for (i, bytes) in consumer_tables().1.iter().enumerate() {
        let out = Command::new(&driver)
            .args([i.to_string(), seed.to_string(), n.to_string()])
            .output()
            .unwrap();
        assert!(out.status.success(), "driver {i}: {:?}\n{}", out.status, text(&out));
        let f: Vec<u64> =
            text(&out).split_whitespace().map(|v| v.parse().expect("a number")).collect();
        assert_eq!(f.len(), 7, "driver {i} printed {f:?}");
        let no_std = workload::Summary {
            status: f[0] as u32,
            free: f[1] as u32,
            collision: f[2] as u32,
            unreachable: f[3] as u32,
            fallbacks: f[4] as u32,
            hash: f[5],
            query_allocs: f[6] as u32,
        };
        let std = workload::run(bytes, seed, n, || 0);
        println!("table {i}: no_std {no_std:?}");
        assert_eq!(std.status, 0, "table {i} does not load with std: {std:?}");
        let lookups = n - std.unreachable - std.fallbacks;
        assert!(
            std.collision > 0 && std.free > 0 && std.fallbacks > 0 && lookups > n / 4,
            "weak workload: {std:?}"
        );
        assert_eq!(
            no_std, std,
            "table {i}: the no_std build answers differently (or its queries allocate)"
        );
    }
}

/// The per-tick code on a microcontroller without an operating system: the no_std library
/// and the consumer compile for `thumbv7em-none-eabihf` and link with `rust-lld` into an
/// ARM executable whose entry is the consumer's tick loop, with nothing left undefined (no
/// std, no C library); the table loader and the exact check are in it.
#[test]
fn table_queries_link_for_bare_metal_arm() {
    let triple = "thumbv7em-none-eabihf";
    if let Err(why) = rust_target(triple) {
        assert!(!in_ci(), "the bare-metal build cannot be skipped on CI: {why} (.ci/run does)");
        println!("skipped: the {triple} build needs {why}");
        return;
    }
    let lib = consumer_staticlib(triple, &no_std_rlib(triple));
    let sysroot = rustc_print(&["--print", "sysroot"]).expect("rustc --print sysroot");
    let host = rustc_print(&["-vV"])
        .and_then(|v| v.lines().find_map(|l| l.strip_prefix("host: ").map(str::to_owned)));
    let lld = Path::new(&sysroot)
        .join("lib/rustlib")
        .join(host.expect("host triple"))
        .join("bin/rust-lld");
    assert!(lld.is_file(), "rust-lld ships with rustc, but {} is missing", lld.display());
    let elf = lib.with_file_name("consumer.elf");
    let out = Command::new(&lld)
        .args([
            "-flavor",
            "gnu",
            "--gc-sections",
            "-u",
            "dc_nostd_run",
            "--entry",
            "dc_nostd_run",
            "-o",
        ])
        .arg(&elf)
        .arg(&lib)
        .output()
        .expect("rust-lld runs");
    assert!(
        out.status.success(),
        "rust-lld cannot link the no_std consumer for {triple}:\n{}",
        text(&out)
    );
    let bytes = std::fs::read(&elf).expect("the linked executable");
    assert_eq!(&bytes[..5], b"\x7fELF\x01", "not a 32-bit ELF file");
    assert_eq!(u16::from_le_bytes([bytes[18], bytes[19]]), 40, "not an ARM executable (EM_ARM)");
    assert_ne!(
        u32::from_le_bytes([bytes[24], bytes[25], bytes[26], bytes[27]]),
        0,
        "no entry point"
    );
    let has = |name: &str| bytes.windows(name.len()).any(|w| w == name.as_bytes());
    for symbol in ["dc_nostd_run", "5table6format10from_bytes", "12ExactChecker5check"] {
        assert!(has(symbol), "the {triple} executable lacks `{symbol}`");
    }
}
