//! The IEC 61131-3 function blocks of `plc/` (plc/README.md): their Structured Text parsed by
//! two real parsers, blark and tree-sitter's IEC 61131-3 grammar, and compared with the
//! generated header by `plc/check_st.py`, which must also fail when the header or the blocks
//! change under it.
//!
//! The parsers are Python packages: a venv under `target/plc-venv` (reused while it holds the
//! pinned versions) gets them from PyPI. Without python3 or a working venv/pip the tests skip
//! with the reason, except under `CI`, where that fails them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

mod harness_build;
use harness_build::{both, in_ci, repo_root, run, scratch_dir};

/// The packages the checker needs, as plc/README.md and shared notes pin them.
const PACKAGES: [&str; 3] = ["blark==0.8.3", "tree-sitter", "tree-sitter-iec61131-3-st==0.1.2"];

/// Imports that prove a venv holds the pinned parsers.
const PROBE: &str = "import blark, tree_sitter, tree_sitter_iec61131_3_st; \
                     assert blark.__version__.startswith('0.8.3'), blark.__version__";

/// The venv's python, or why there is none.
fn venv_python() -> Result<&'static Path, &'static str> {
    static PYTHON: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    PYTHON.get_or_init(make_venv).as_deref().map_err(String::as_str)
}

fn make_venv() -> Result<PathBuf, String> {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("target dir").to_owned();
    let venv = target.join("plc-venv");
    let python = venv.join("bin").join("python");
    let works =
        |p: &Path| Command::new(p).args(["-c", PROBE]).output().is_ok_and(|o| o.status.success());
    if works(&python) {
        return Ok(python);
    }
    match Command::new("python3").arg("--version").output() {
        Ok(o) if o.status.success() => {}
        _ => return Err("python3 is not installed (apt-get install python3 python3-venv)".into()),
    }
    let out = run(Command::new("python3").arg("-m").arg("venv").arg("--clear").arg(&venv));
    if !out.status.success() {
        return Err(format!("python3 -m venv failed (python3-venv missing?):\n{}", both(&out)));
    }
    let out = run(Command::new(venv.join("bin").join("pip"))
        .args(["install", "-q", "--disable-pip-version-check"])
        .args(PACKAGES));
    if !out.status.success() {
        return Err(format!("pip install {} failed:\n{}", PACKAGES.join(" "), both(&out)));
    }
    if !works(&python) {
        return Err(format!("the venv at {} does not import the parsers", venv.display()));
    }
    Ok(python)
}

/// The venv's python; `None` (after printing why) when the test may skip.
fn python_or_skip(test: &str) -> Option<&'static Path> {
    match venv_python() {
        Ok(p) => Some(p),
        Err(why) => {
            assert!(!in_ci(), "{test}: {why}");
            println!("SKIPPED {test}: {why} (outside CI; under CI=true this test fails)");
            None
        }
    }
}

/// Runs the checker with extra arguments (`--header`, `--src`, `--readme`).
fn check_st(python: &Path, args: &[&std::ffi::OsStr]) -> Output {
    run(Command::new(python).arg(repo_root().join("plc/check_st.py")).args(args))
}

/// The `check_st: N passed, M failed` line's numbers.
fn verdict(stdout: &str) -> (u64, u64) {
    let line = stdout
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("check_st: "))
        .unwrap_or_else(|| panic!("no `check_st:` line in:\n{stdout}"));
    let (passed, failed) = line.split_once(" passed, ").expect("N passed, M failed");
    (passed.parse().unwrap(), failed.trim_end_matches(" failed").parse().unwrap())
}

/// The rows `| Tn | FROM | ... | TO |` of plc/README.md's state machine.
fn transition_rows() -> Vec<u32> {
    let readme = std::fs::read_to_string(repo_root().join("plc/README.md")).unwrap();
    let section = readme.split("### State machine").nth(1).expect("a state machine section");
    section.lines().filter_map(|l| l.strip_prefix("| T")?.split(' ').next()?.parse().ok()).collect()
}

#[test]
fn structured_text_parses_with_both_parsers_and_matches_the_header() {
    let Some(python) = python_or_skip("structured_text_parses_with_both_parsers") else {
        return;
    };
    let out = check_st(python, &[]);
    let text = both(&out);
    println!("{text}");
    assert!(out.status.success(), "plc/check_st.py failed:\n{text}");
    let (passed, failed) = verdict(&text);
    assert_eq!(failed, 0, "{text}");
    assert!(passed > 100, "the checker ran few checks: {passed}");
    // Every .st file and both of its broken copies went through both parsers.
    let files = std::fs::read_dir(repo_root().join("plc/src"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "st"))
        .count();
    assert!(files >= 6, "plc/src holds {files} .st files");
    assert!(
        text.contains(&format!(
            "parsed {files} files with blark and tree-sitter; broken copies rejected by both: \
             {} of {}",
            2 * files,
            2 * files
        )),
        "{text}"
    );
    // Each block takes every row of the table, read here from the README too.
    let rows = transition_rows();
    assert!(rows.len() >= 9, "{rows:?}");
    for fb in ["FB_DeltaCollide", "FB_DeltaProtect"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{fb}: ")))
            .unwrap_or_else(|| panic!("no line for {fb}"));
        assert!(line.ends_with(&format!("rows {rows:?}")), "{line}");
    }
    // The externals the blocks call are the C functions of their lifecycle.
    for name in ["dc_init", "dc_init_with_table", "dc_query", "dc_destroy", "dc_coordinate"] {
        assert!(text.contains(&format!(" {name},")) || text.contains(&format!(" {name}\n")));
    }
}

/// Writes `text` with `from` replaced by `to` (which must occur) into the scratch file `name`.
fn altered(original: &Path, from: &str, to: &str, name: &str) -> PathBuf {
    let text = std::fs::read_to_string(original).unwrap();
    assert!(text.contains(from), "{} no longer contains `{from}`", original.display());
    let path = scratch_dir("plc_altered").join(name);
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path
}

/// Asserts that the checker fails with `flag altered`, naming `expected`.
fn assert_fails(python: &Path, flag: &str, altered: &Path, expected: &str) {
    let out = check_st(python, &[flag.as_ref(), altered.as_os_str()]);
    let text = both(&out);
    assert_eq!(out.status.code(), Some(1), "the checker passed {}:\n{text}", altered.display());
    let (_, failed) = verdict(&text);
    assert!(failed > 0, "{text}");
    assert!(
        text.lines().any(|l| l.starts_with("FAIL: ") && l.contains(expected)),
        "no FAIL line naming `{expected}` for {}:\n{text}",
        altered.display()
    );
}

/// A change of the C ABI that the blocks miss fails the checker, which names it: parameters
/// swapped, a status added, a struct field renamed, a typedef narrowed.
#[test]
fn checker_fails_when_the_header_changes_under_the_blocks() {
    let Some(python) = python_or_skip("checker_fails_when_the_header_changes") else {
        return;
    };
    let header = repo_root().join("include/delta_collide.h");
    let cases = [
        (
            "const struct DcVec3 *tcps_mcs, size_t n_tcps, DcVerdict *out_verdict, struct \
             DcQueryReport *out_report);",
            "size_t n_tcps, const struct DcVec3 *tcps_mcs, DcVerdict *out_verdict, struct \
             DcQueryReport *out_report);",
            "dc_query: parameter #1",
        ),
        (
            "#define DC_STATUS_OK 0\n",
            "#define DC_STATUS_OK 0\n#define DC_STATUS_SOMETHING_NEW 99\n",
            "DC_STATUS_SOMETHING_NEW",
        ),
        ("  double clearance_mm;", "  double clearance;", "ST_DcProtectiveReport: field #2"),
        ("typedef uint32_t DcVerdict;", "typedef uint8_t DcVerdict;", "dc_query: parameter #3"),
        ("  uint32_t stride_ticks;", "  uint64_t stride_ticks;", "ST_DcProgramme: field #1"),
        ("#define DC_MAX_ROBOTS 32", "#define DC_MAX_ROBOTS 64", "DC_MAX_ROBOTS"),
    ];
    for (i, (from, to, expected)) in cases.iter().enumerate() {
        let h = altered(&header, from, to, &format!("header_{i}.h"));
        assert_fails(python, "--header", &h, expected);
    }
}

/// The blocks and the README are checked against each other: a transition to a state the
/// table does not give, a status without its row, a DiagCode or type row changed, fails.
#[test]
fn checker_fails_on_a_wrong_transition_or_an_undocumented_status() {
    let Some(python) = python_or_skip("checker_fails_on_a_wrong_transition") else {
        return;
    };
    let src = repo_root().join("plc/src");
    let dir = scratch_dir("plc_altered_src");
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
    }
    let fb = dir.join("FB_DeltaCollide.st");
    let text = std::fs::read_to_string(&fb).unwrap();
    let from = "State := E_DcFbState.IDLE;\n            Transition := 4;";
    assert!(text.contains(from), "FB_DeltaCollide.st changed: update this test");
    std::fs::write(
        &fb,
        text.replace(from, "State := E_DcFbState.ERROR;\n            Transition := 4;"),
    )
    .unwrap();
    assert_fails(python, "--src", &dir, "T4 ACTIVE -> ERROR is not a row of the table");
    std::fs::write(&fb, text).unwrap();

    let readme = repo_root().join("plc/README.md");
    let row = "| 14 | `DC_STATUS_TABLE_CORRUPT` | 14 | 16#C10E | 16#C20E |";
    assert_fails(
        python,
        "--readme",
        &altered(
            &readme,
            row,
            "| 14 | `DC_STATUS_TABLE_CORRUPT` | 14 | 16#C10E | 16#C20F |",
            "r1.md",
        ),
        "query DiagCode of DC_STATUS_TABLE_CORRUPT",
    );
    assert_fails(
        python,
        "--readme",
        &altered(
            &readme,
            row,
            "| 14 | `DC_STATUS_TABLE_CORRUPTED` | 14 | 16#C10E | 16#C20E |",
            "r2.md",
        ),
        "DC_STATUS_TABLE_CORRUPT has no row",
    );
    assert_fails(
        python,
        "--readme",
        &altered(&readme, "| `size_t` | `__UXINT` |", "| `size_t` | `UDINT` |", "r3.md"),
        "dc_init_with_table: parameter #2",
    );
    assert_fails(
        python,
        "--readme",
        &altered(&readme, "| 16#8002 |", "| 16#8012 |", "r4.md"),
        "DiagCode 16#8002 is set by the code but has no row",
    );
}
