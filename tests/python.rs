//! The Python package (`python/`): makes a virtual environment under `target/py-venv` (reused
//! when present), installs maturin, numpy, pytest, hypothesis, matplotlib and the oracles Coal
//! and python-fcl from PyPI, builds and installs the package from this repository, and runs
//! its pytest suite (`python/tests`) and the notebook-shaped example `examples/line_layout.py`.
//! The tests compare every answer with this crate's C ABI (the shared library this cargo run
//! built), so both sides come from the same sources.
//!
//! Without Python 3.11+ or without the registry this test skips with the reason, unless `CI`
//! is set: there a missing tool fails it.

mod harness_build;

use harness_build::{both, in_ci, run};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// What the venv gets from PyPI (the package's own dependency, numpy, among them).
const REQUIREMENTS: &[&str] =
    &["maturin>=1.7,<2", "numpy", "pytest", "hypothesis", "matplotlib", "coal", "python-fcl"];

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Skips (printing why) outside CI, fails under CI.
fn missing(why: &str) {
    assert!(!in_ci(), "CI: {why}");
    println!("skipped: {why}");
}

/// A Python 3.11 or later to make the venv with: `$PYTHON`, else `python3`.
fn base_python() -> Option<PathBuf> {
    let python = std::env::var_os("PYTHON").map_or_else(|| PathBuf::from("python3"), PathBuf::from);
    let out = Command::new(&python)
        .args(["-c", "import sys, venv; print(sys.version_info >= (3, 11))"])
        .output()
        .ok()?;
    (out.status.success() && String::from_utf8_lossy(&out.stdout).trim() == "True")
        .then_some(python)
}

/// The shared library of this crate that this cargo run built (`cargo test` leaves it in
/// `target/<profile>/deps`), else the one of a `cargo build` in `target/<profile>`; the newer.
fn cdylib() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let deps = exe.parent()?;
    let candidates = [deps.join("libdelta_collide.so"), deps.parent()?.join("libdelta_collide.so")];
    candidates
        .into_iter()
        .filter(|p| p.is_file())
        .max_by_key(|p| p.metadata().and_then(|m| m.modified()).ok())
}

/// Runs `cmd` in the venv's environment; panics with its output when it fails.
fn step(what: &str, cmd: &mut Command, venv: &Path) -> String {
    let started = Instant::now();
    let bin = venv.join("bin");
    let path = std::env::join_paths(
        std::iter::once(bin.clone())
            .chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .expect("PATH joins");
    let out = run(cmd.env("PATH", path).env("VIRTUAL_ENV", venv).env_remove("PYTHONHOME"));
    let log = both(&out);
    assert!(out.status.success(), "{what} failed:\n{log}");
    println!("{what}: {:.1} s", started.elapsed().as_secs_f64());
    log
}

/// The venv with the requirements, made or completed; `None` (after saying why) when it cannot
/// be made.
fn venv(root: &Path) -> Option<PathBuf> {
    let venv = root.join("target/py-venv");
    let python = venv.join("bin/python");
    let stamp = venv.join("delta-collide-requirements.txt");
    let wanted = REQUIREMENTS.join("\n");
    if !python.is_file() {
        let Some(base) = base_python() else {
            missing("no Python 3.11 or later with venv (set PYTHON to one)");
            return None;
        };
        let out = run(Command::new(base).arg("-m").arg("venv").arg(&venv));
        if !out.status.success() {
            missing(&format!("python -m venv failed:\n{}", both(&out)));
            return None;
        }
    }
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(wanted.as_str()) {
        let mut pip = Command::new(&python);
        pip.args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(REQUIREMENTS);
        let out = run(pip.env("VIRTUAL_ENV", &venv));
        if !out.status.success() {
            missing(&format!(
                "pip install of the requirements failed (no registry?):\n{}",
                both(&out)
            ));
            return None;
        }
        std::fs::write(&stamp, &wanted).expect("stamp file written");
    }
    Some(venv)
}

#[test]
fn python_package_builds_and_its_tests_pass() {
    let root = repo_root();
    let Some(venv) = venv(&root) else { return };
    let python = venv.join("bin/python");
    let Some(lib) = cdylib() else {
        missing("libdelta_collide.so not found beside the test executable (crate-type cdylib?)");
        return;
    };
    // The extension's own target directory: never this cargo run's, whose lock it holds.
    step(
        "build and install the package",
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--no-build-isolation", "--no-deps"])
            .args(["--disable-pip-version-check", "--force-reinstall"])
            .arg(root.join("python"))
            .env("CARGO_TARGET_DIR", root.join("python/target")),
        &venv,
    );
    let log = step(
        "pytest python/tests",
        Command::new(&python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs"])
            .arg(root.join("python/tests"))
            .current_dir(&root)
            .env("DELTA_COLLIDE_CDYLIB", &lib)
            .env("DELTA_COLLIDE_REPO", &root)
            .env("HYPOTHESIS_STORAGE_DIRECTORY", root.join("target/py-hypothesis"))
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("MPLBACKEND", "Agg"),
        &venv,
    );
    println!("{}", log.lines().rev().take(3).collect::<Vec<_>>().join("\n"));
    // Nothing may be skipped under CI: every test must have run.
    if in_ci() {
        assert!(!log.contains(" skipped"), "CI: some Python tests skipped:\n{log}");
    }
}
