//! The command line as a user runs it: `demo` and `check` on real files, the help, the
//! version, completions and man page, usage errors (exit code 2) and failures (exit code 1),
//! and outputs that are never left looking complete when they are not.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_delta-collide");

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(BIN).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

/// `cli` with `input` on stdin.
fn cli_stdin(args: &[&str], input: &str) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input.as_bytes()).unwrap();
    child.wait_with_output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A new empty directory of this test process.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The names of the files in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `demo --cell FILE` on the four-robot line runs its own scenarios
/// (`c_harness/line_scenarios.txt`): no collision in the practical run, R3-R4 first meeting at
/// tick 3810 in the collision run (as T1's pair), a STOP before it, and in both runs a clear
/// stop.
#[test]
fn demo_runs_the_line_of_four_robots() {
    let out = cli(&["demo", "--cell", "cells/line4.toml"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .filter(|l| l.starts_with("line4"))
        .map(|l| l.split_whitespace().collect())
        .collect();
    let firsts: Vec<_> =
        rows.iter().filter(|r| r[2].starts_with("SAT")).map(|r| (r[1], r[3])).collect();
    let expected = [
        ("practical", "none"),
        ("practical", "none"),
        ("collision", "tick"),
        ("collision", "tick"),
    ];
    assert_eq!(firsts, expected, "{text}");
    let at_3810 = text
        .lines()
        .filter(|l| l.starts_with("line4 collision") && l.contains("tick 3810"))
        .count();
    assert_eq!(at_3810, 2, "SAT and SAT-cache: R3-R4 meet at tick 3810\n{text}");
    let protective: Vec<&Vec<&str>> = rows.iter().filter(|r| r.len() == 10).collect();
    assert_eq!(protective.len(), 2, "{text}");
    for r in protective {
        let before_contact = r[1] == "practical" || r[3].parse::<u32>().unwrap() < 3810;
        assert!(before_contact && r[6] == "clear", "{r:?}");
    }
}

#[test]
fn demo_reports_no_collision_when_practical_the_same_first_tick_for_both_methods_and_a_clear_stop()
{
    let out = cli(&["demo", "--cell", "all"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    println!("{text}");
    for cell in ["T1", "T2", "T3"] {
        let all: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| l.starts_with(cell))
            .map(|l| l.split_whitespace().collect())
            .collect();
        let rows: Vec<&Vec<&str>> = all.iter().filter(|r| r[2].starts_with("SAT")).collect();
        assert_eq!(rows.len(), 4, "{cell}: practical and collision, SAT and SAT-cache");
        for r in rows.iter().filter(|r| r[1] == "practical") {
            assert_eq!((r[3], r[4]), ("none", "0"), "{cell} practical never collides");
        }
        let ticks: Vec<u32> =
            rows.iter().filter(|r| r[1] == "collision").map(|r| r[4].parse().unwrap()).collect();
        assert_eq!(ticks.len(), 2);
        assert_eq!(ticks[0], ticks[1], "{cell}: SAT and SAT-cache stop at the same tick");
        assert!(ticks[0] > 3000 && ticks[0] < 6000, "{cell}: the last part of the run collides");
        // The protective rows: cell case firstWARN firstSTOP WARN STOP stop stop_ms closest
        // median_us.
        let protective: Vec<&Vec<&str>> = all.iter().filter(|r| r.len() == 10).collect();
        assert_eq!(protective.len(), 2, "{cell}: one protective row per scenario");
        for r in protective {
            let first_stop: u32 =
                r[3].parse().expect("the scenarios come close enough to need a STOP");
            assert!(
                first_stop < ticks[0],
                "{cell} {}: STOP at {first_stop}, before the contact at {}",
                r[1],
                ticks[0]
            );
            let (warn, stop): (u32, u32) = (r[4].parse().unwrap(), r[5].parse().unwrap());
            assert!(stop > 0 && warn + stop <= 6000, "{r:?}");
            assert_eq!(r[6], "clear", "{cell} {}: the simulated stop never touches", r[1]);
            assert!(
                r[7].parse::<f64>().unwrap() > 0.0 && r[8].parse::<f64>().unwrap() > 0.0,
                "{r:?}"
            );
            assert!(
                r[9].parse::<f64>().unwrap() > 0.0,
                "{cell} {}: a tick takes some time: {r:?}",
                r[1]
            );
        }
    }
}

#[test]
fn check_writes_one_line_per_row_matching_the_exact_checker() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join("in.csv"), dir.join("out.csv"));
    let mut rows = vec!["x,y,z,x2,y2,z2".to_string()];
    let mut expected = vec!["reachable,collide".to_string()];
    let mut checker = ExactChecker::new(reference_cell("T2").unwrap());
    for i in 0..501 {
        let s = i as f64 / 500.0;
        let z = if i == 500 { -900.0 } else { -450.0 - 60.0 * s };
        let tcps =
            [Vec3::new(-200.0 + 400.0 * s, 20.0, z), Vec3::new(180.0 - 380.0 * s, -10.0, -470.0)];
        rows.push(format!(
            "{},{},{},{},{},{}",
            tcps[0].x, tcps[0].y, tcps[0].z, tcps[1].x, tcps[1].y, tcps[1].z
        ));
        let v = checker.check(&tcps).unwrap();
        expected.push(
            match (v.all_reachable(), v.collides()) {
                (false, _) => "0,NA",
                (true, true) => "1,1",
                (true, false) => "1,0",
            }
            .to_string(),
        );
    }
    std::fs::write(&input, rows.join("\n")).unwrap();
    let out = cli(&[
        "check",
        "--cell",
        "cells/t2.toml",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got = std::fs::read_to_string(&output).unwrap();
    let got: Vec<&str> = got.lines().collect();
    assert_eq!(got, expected);
    for kind in ["0,NA", "1,1", "1,0"] {
        assert!(got.contains(&kind), "the rows cover {kind}");
    }
}

#[test]
fn bad_arguments_and_rows_fail_with_a_message() {
    let out = cli(&["check", "--cell", "cells/nope.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.toml"));
    let out = cli(&["demo", "--cel", "T1"]);
    assert_eq!(out.status.code(), Some(2));
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("bad.csv");
    std::fs::write(&input, "1,2,3,4,5,6\n1,2,three,4,5,6\n").unwrap();
    let out = cli(&["check", "--cell", "T1", "--input", input.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "a bad row is a failure, not a usage error");
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 2"));
}

#[test]
fn build_inspect_eval_and_check_with_a_table() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-cli-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table = dir.join("t3.dct");
    let table = table.to_str().unwrap();
    let out = cli(&["build", "--cell", "T3", "--k", "16", "--variant", "5d", "--output", table]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("symmetric: false"),
        "T3 has no symmetry"
    );
    let out = cli(&["inspect", table]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success() && text.contains("5D") && text.contains("SweptBound"), "{text}");
    let out = cli(&["eval", "--cell", "T3", "--table", table, "--random", "20000"]);
    let text = String::from_utf8(out.stdout).unwrap();
    println!("{text}");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let fns: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split("FN").nth(1))
        .map(|r| r.split_whitespace().next().unwrap())
        .collect();
    assert_eq!(fns, vec!["0", "0", "0"], "practical, collision and random: no false negative");
    let out = cli(&["eval", "--cell", "T1", "--table", table, "--random", "10"]);
    assert_eq!(out.status.code(), Some(1), "a T3 table is refused for T1");
    assert!(String::from_utf8_lossy(&out.stderr).contains("rebuild"));
    let input = dir.join("in.csv");
    // Robots reaching toward each other (B's MCS is turned by 30 degrees), apart, unreachable.
    std::fs::write(
        &input,
        "190,70,-450,-200,-20,-450\n-150,0,-450,150,0,-450\n0,0,-900,0,0,-450\n",
    )
    .unwrap();
    let out = cli(&["check", "--cell", "T3", "--table", table, "--input", input.to_str().unwrap()]);
    assert_eq!(String::from_utf8(out.stdout).unwrap(), "reachable,collide\n1,1\n1,0\n0,NA\n");
    // --clearance in table mode: the exact signed clearance beside the table's answer.
    let out = cli(&[
        "check",
        "--cell",
        "T3",
        "--table",
        table,
        "--clearance",
        "--input",
        input.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(text.lines().next(), Some("reachable,collide,clearance_mm"));
    let tcps = [
        [Vec3::new(190.0, 70.0, -450.0), Vec3::new(-200.0, -20.0, -450.0)],
        [Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0)],
    ];
    for (row, t) in rows.iter().zip(&tcps) {
        let truth = oracle_clearance("T3", t).unwrap();
        let got: f64 = row[2].parse().unwrap();
        assert!((got - truth).abs() < 2e-3, "T3 {t:?}: printed {got}, oracle {truth}");
    }
    assert!(rows[0][2].starts_with('-') && !rows[1][2].starts_with('-'), "{text}");
    assert_eq!(rows[2], ["0", "NA", "NA"]);
}

/// A clearance table through the command line: `build --variant clearance --levels`,
/// `inspect` shows the levels and the grid cells per level, `eval` finds no false
/// negative, and `check --table --clearance` writes the table's bound, never above the
/// independent oracle's clearance, `-inf` where a row's cell may collide, NA when unreachable.
#[test]
fn clearance_table_through_build_inspect_eval_and_check() {
    let dir = fresh_dir("clearance-table");
    let table = dir.join("t1c.dct");
    let table = table.to_str().unwrap();
    let out = cli(&[
        "build",
        "--cell",
        "T1",
        "--k",
        "16",
        "--variant",
        "clearance",
        "--levels",
        "0,10,30,90",
        "--output",
        table,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("sample pairs per level: no level"), "{}", stdout(&out));
    let out = cli(&["inspect", table]);
    let text = stdout(&out);
    assert!(
        out.status.success()
            && text.contains("6D-clearance")
            && text.contains("[0.0, 10.0, 30.0, 90.0]"),
        "{text}"
    );
    assert!(
        text.contains(">= 90 mm") && text.contains("grid cells (all k^6, as stored) per level"),
        "{text}"
    );
    let out = cli(&["eval", "--cell", "T1", "--table", table, "--random", "20000"]);
    let text = stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    let fns: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split("FN").nth(1))
        .map(|r| r.split_whitespace().next().unwrap())
        .collect();
    assert_eq!(fns, vec!["0", "0", "0"], "practical, collision and random: no false negative");
    // T1's collision scenario every 20 ticks (far apart, then intersecting), and one unreachable
    // row.
    let scenarios = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("c_harness/scenarios.txt"),
    )
    .unwrap();
    let scenarios = delta_collide::cell::trajectory::parse_scenarios(&scenarios).unwrap();
    let s = scenarios.iter().find(|s| s.cell == "T1" && s.case == "collision").unwrap();
    let mut configs: Vec<Vec<Vec3>> = (0..6000)
        .step_by(20)
        .map(|tick| {
            let mut t = vec![Vec3::zeros(); 2];
            s.tcps_at(tick, &mut t);
            t
        })
        .collect();
    configs.push(vec![Vec3::new(0.0, 0.0, -900.0), Vec3::new(0.0, 0.0, -450.0)]);
    let text = check_clearance(&dir, &["--cell", "T1", "--table", table], &configs);
    let (mut levelled, mut none) = (0, 0);
    for (line, t) in text.lines().skip(1).zip(&configs) {
        let f: Vec<&str> = line.split(',').collect();
        let Some(truth) = oracle_clearance("T1", t) else {
            assert_eq!(f, ["0", "NA", "NA"], "{t:?}");
            continue;
        };
        if f[2] == "-inf" {
            none += 1;
            continue;
        }
        let bound: f64 = f[2].parse().unwrap();
        assert!([0.0, 10.0, 30.0, 90.0].contains(&bound), "{line}");
        assert!(bound <= truth, "{t:?}: the table's bound {bound} exceeds the clearance {truth}");
        assert_eq!(f[1], "0", "a row with a level is free: {line}");
        levelled += 1;
    }
    assert!(levelled > 10 && none > 0, "{levelled} rows with a level, {none} without:\n{text}");
    // replay --table: T1 practical with a stiff stopping model on a table with the default
    // levels; the share of ticks answered by the lookup alone goes to stderr (on this smooth
    // run, proofs kept from earlier ticks come first and leave the lookups almost nothing:
    // `tests/bundles.rs` replays a line where they prove pairs); statuses and the (exact)
    // clearance agree with exact mode's, and table mode never stops where exact mode does not.
    let ladder_table = dir.join("t1d.dct");
    let ladder_table = ladder_table.to_str().unwrap();
    let out = cli(&[
        "build",
        "--cell",
        "T1",
        "--k",
        "16",
        "--variant",
        "clearance",
        "--output",
        ladder_table,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let cell = dir.join("t1_stiff.toml");
    let stop = "stop = { reaction_ms = 2.0, decel_mm_s2 = 120000.0, max_accel_mm_s2 = 130000.0, max_speed_mm_s = 4600.0 }";
    let toml = format!(
        "name = \"T1\"\ntick_ms = 1.0\n\n[[robot]]\nname = \"A\"\n{stop}\n\n[[robot]]\nname = \"B\"\n\
         placement = {{ alpha_deg = 0.0, t = [450.0, 0.0, 0.0] }}\n{stop}\n"
    );
    std::fs::write(&cell, toml).unwrap();
    let cell = cell.to_str().unwrap();
    let rows = scenario_rows("T1", "practical", 6000);
    let exact = cli_stdin(&["replay", "--cell", cell], &rows);
    let table_mode = cli_stdin(&["replay", "--cell", cell, "--table", ladder_table], &rows);
    assert!(exact.status.success() && table_mode.status.success(), "{}", stderr(&table_mode));
    assert!(
        stderr(&table_mode).contains(" of 6000 ticks"),
        "no lookup share: {}",
        stderr(&table_mode)
    );
    let (exact, table_mode) = (stdout(&exact), stdout(&table_mode));
    assert_eq!(exact.lines().count(), table_mode.lines().count());
    for (e, t) in exact.lines().zip(table_mode.lines()).skip(1) {
        let (e, t): (Vec<&str>, Vec<&str>) = (e.split(',').collect(), t.split(',').collect());
        assert_eq!((e[0], e[2], e[3]), (t[0], t[2], t[3]), "tick, status and clearance");
        assert!(
            t[1] != "stop" || e[1] == "stop",
            "table mode stops at tick {} where exact mode does not",
            t[0]
        );
    }
    // quilt shades free cells by level: the middle levels' blues cover many cells.
    let png = dir.join("quilt.png");
    let out = cli(&[
        "quilt",
        "--cell",
        "T1",
        "--table",
        table,
        "--axes",
        "zz",
        "--output",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (_, _, pixels) = read_png(&png);
    // The quilt's level colours for 4 levels: white, two blues between, the top's dark blue.
    let middle = [[177u8, 193, 227], [98, 132, 198]];
    let shaded = pixels.iter().filter(|p| middle.contains(p)).count();
    assert!(shaded > 1000, "{shaded} pixels of the middle levels' colours");
}

/// Signed clearance of the cell `cell` at `tcps` computed here, apart from
/// `geometry::clearance`: apart, the smallest box distance of `geometry::distance` (vertex and
/// edge distances); intersecting, minus the smallest overlap (the shift that separates them)
/// of the 8-vertex projections of two boxes over their 15 normalised axes. `None` when a TCP is
/// unreachable.
fn oracle_clearance(cell: &str, tcps: &[Vec3]) -> Option<f64> {
    use delta_collide::geometry::{obb_distance, Obb};
    let mut exact = ExactChecker::new(reference_cell(cell).unwrap());
    if !exact.check(tcps).unwrap().all_reachable() {
        return None;
    }
    let overlap = |a: &Obb, b: &Obb| -> f64 {
        let mut axes: Vec<Vec3> =
            (0..3).flat_map(|i| [a.axes.column(i).into(), b.axes.column(i).into()]).collect();
        for i in 0..3 {
            for j in 0..3 {
                let c: Vec3 = a.axes.column(i).cross(&b.axes.column(j));
                if c.norm() >= delta_collide::math::CROSS_AXIS_MIN_NORM {
                    axes.push(c.normalize());
                }
            }
        }
        let range = |o: &Obb, n: &Vec3| {
            o.vertices()
                .iter()
                .map(|v| v.dot(n))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
        };
        axes.iter()
            .map(|n| {
                let ((a0, a1), (b0, b1)) = (range(a, n), range(b, n));
                // How far one must move along n to separate them (containment included).
                (a1 - b0).min(b1 - a0)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut best = f64::INFINITY;
    for p in &exact.verdict().pairs {
        for a in exact.boxes(p.a).as_slice() {
            for b in exact.boxes(p.b).as_slice() {
                let o = overlap(a, b);
                best = best.min(if o > 0.0 { -o } else { obb_distance(a, b) });
            }
        }
    }
    Some(best)
}

/// Runs `check ARGS --clearance` on the two-robot configurations `configs` (one CSV row each,
/// written into `dir`) and returns its output, after checking that it succeeded and that
/// its header names the clearance column.
fn check_clearance(dir: &Path, args: &[&str], configs: &[Vec<Vec3>]) -> String {
    let rows: Vec<String> = configs
        .iter()
        .map(|t| format!("{},{},{},{},{},{}", t[0].x, t[0].y, t[0].z, t[1].x, t[1].y, t[1].z))
        .collect();
    let input = dir.join("in.csv");
    std::fs::write(&input, rows.join("\n")).unwrap();
    let out =
        cli(&[&["check"], args, &["--clearance", "--input", input.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert_eq!(text.lines().next(), Some("reachable,collide,clearance_mm"));
    text
}

/// `check --clearance` along T1's collision scenario (far apart at first, intersecting at the
/// end) and one unreachable row: every printed clearance matches the oracle.
#[test]
fn check_clearance_matches_an_independent_signed_distance() {
    let dir = fresh_dir("clearance");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("c_harness/scenarios.txt"),
    )
    .unwrap();
    let scenarios = delta_collide::cell::trajectory::parse_scenarios(&text).unwrap();
    let s = scenarios.iter().find(|s| s.cell == "T1" && s.case == "collision").unwrap();
    let mut configs = Vec::new();
    for tick in (0..6000).step_by(25) {
        let mut t = vec![Vec3::zeros(); 2];
        s.tcps_at(tick, &mut t);
        configs.push(t);
    }
    configs.push(vec![Vec3::new(0.0, 0.0, 100.0), Vec3::new(150.0, 0.0, -450.0)]);
    let text = check_clearance(&dir, &["--cell", "T1"], &configs);
    let (mut negative, mut far) = (0, 0);
    for (line, t) in text.lines().skip(1).zip(&configs) {
        let f: Vec<&str> = line.split(',').collect();
        let Some(truth) = oracle_clearance("T1", t) else {
            assert_eq!(f, ["0", "NA", "NA"], "{t:?}");
            continue;
        };
        let got: f64 = f[2].parse().unwrap();
        assert!((got - truth).abs() < 2e-3, "{t:?}: printed {got}, oracle {truth}");
        assert_eq!(f[1] == "1", got <= 0.0, "{t:?}: collide and the sign agree: {line}");
        negative += (got < -1.0) as u32;
        far += (got > 100.0) as u32;
    }
    assert!(negative > 0 && far > 0, "the run covers intersecting and far configurations:\n{text}");
    assert_eq!(text.lines().count(), configs.len() + 1);
}

/// The fenced block after "delta-collide --help" in the README's "Command line" section.
fn readme_help_block() -> String {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let section = readme.split("\n## Command line\n").nth(1).expect("a \"Command line\" section");
    let section = section.split("\n## ").next().unwrap();
    let block = section.split("```text\n").nth(1).expect("a ```text block in \"Command line\"");
    block.split("\n```").next().unwrap().to_string()
}

/// The README is a manual read in one sitting; measurements belong in `docs/record/`.
#[test]
fn readme_stays_a_manual_under_25_kb() {
    let bytes =
        std::fs::metadata(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap().len();
    assert!(bytes < 25_000, "README.md is {bytes} bytes: move detail to docs/ or docs/record/");
}

fn trim_lines(s: &str) -> String {
    s.trim_end().lines().map(str::trim_end).collect::<Vec<_>>().join("\n")
}

#[test]
fn help_lists_every_command_and_the_readme_shows_it() {
    let out = cli(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let help = stdout(&out);
    let commands = [
        "demo",
        "check",
        "build",
        "merge",
        "inspect",
        "eval",
        "render",
        "quilt",
        "completions",
        "man",
    ];
    for command in commands.into_iter().chain(["--quiet"]) {
        assert!(help.contains(command), "{command} in\n{help}");
    }
    assert_eq!(
        trim_lines(&readme_help_block()),
        trim_lines(&help),
        "README.md \"Command line\" shows an outdated `delta-collide --help`; paste the new one in"
    );
    // No command at all: the help, as a usage error.
    let out = cli(&[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("Usage:"));
}

#[test]
fn each_command_explains_its_flags_units_and_defaults() {
    let help = |cmd: &str| {
        let out = cli(&[cmd, "--help"]);
        assert_eq!(out.status.code(), Some(0), "{cmd}");
        stdout(&out)
    };
    for cmd in ["check", "build", "eval", "render", "quilt"] {
        assert!(help(cmd).contains("T1, T2, T3 or a .toml file"), "{cmd} names the built-in cells");
    }
    assert!(help("demo").contains("T1, T2, T3, all"));
    let build = help("build");
    let parts = [
        "[default: 32]",
        "power of two from 2 to 256",
        "[default: 6d]",
        "4d-yy",
        "shared-sub",
        "[default: 0]",
    ];
    let shards = [
        "--shard <I/N|auto>",
        "every variant shards",
        "JOB_COMPLETION_INDEX",
        "DELTA_COLLIDE_SHARDS",
    ];
    for part in parts.into_iter().chain(shards) {
        assert!(build.contains(part), "build --help: {part}\n{build}");
    }
    assert!(
        help("render").contains("own MCS (mm)") && help("render").contains("[default: render.png]")
    );
    assert!(help("eval").contains("[default: 1000000]") && help("eval").contains("pixels"));
    assert!(help("quilt").contains("[default: yy]") && help("quilt").contains("[default: 1200]"));
}

#[test]
fn version_names_the_table_format_it_writes() {
    let out = cli(&["--version"]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(text.contains(env!("CARGO_PKG_VERSION")), "{text}");
    let format = format!("table format version {}", delta_collide::table::format::VERSION);
    assert!(text.contains(&format), "{text}");
}

/// Each usage error: exit code 2 and a message with `what` in it.
#[test]
fn usage_errors_exit_with_2_and_say_what_is_wrong() {
    let dir = fresh_dir("usage");
    let table = dir.join("t.dct");
    let table = table.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["frobnicate"], "unrecognized subcommand"),
        (&["demo", "--cel", "T1"], "unexpected argument '--cel'"),
        (&["check"], "--cell <CELL>"),
        (
            &["build", "--cell", "T1", "--output", table, "--k", "16", "--k", "32"],
            "cannot be used multiple times",
        ),
        (&["build", "--cell", "T1", "--output", table, "--k", "512"], "power of two from 2 to 256"),
        (&["build", "--cell", "T1", "--output", table, "--k", "48"], "power of two"),
        (&["build", "--cell", "T1", "--output", table, "--k", "lots"], "power of two"),
        (
            &["build", "--cell", "T1", "--output", table, "--variant", "7d"],
            "use 6d, 5d, 4d-yy, 4d-zz, shared, shared-sub or clearance",
        ),
        (
            &["build", "--cell", "T1", "--output", table, "--variant", "6d", "--t", "5"],
            "--t 5 applies to --variant 4d-yy",
        ),
        (&["build", "--cell", "T1", "--output", table, "--t", "5"], "not to --variant 6d"),
        (
            &[
                "build",
                "--cell",
                "T1",
                "--output",
                table,
                "--variant",
                "shared-sub",
                "--labelling",
                "thesis",
            ],
            "certified",
        ),
        (
            &["build", "--cell", "T1", "--output", table, "--levels", "0,5"],
            "--variant clearance only",
        ),
        (
            &[
                "build",
                "--cell",
                "T1",
                "--output",
                table,
                "--variant",
                "clearance",
                "--levels",
                "5,5",
            ],
            "must increase",
        ),
        (
            &[
                "build",
                "--cell",
                "T1",
                "--output",
                table,
                "--variant",
                "clearance",
                "--levels",
                "0,x",
            ],
            "'0,x'",
        ),
        (
            &[
                "build",
                "--cell",
                "T1",
                "--output",
                table,
                "--variant",
                "clearance",
                "--labelling",
                "thesis",
            ],
            "certified",
        ),
        (&["build", "--cell", "T9", "--output", table], "T1, T2, T3"),
        (&["build", "--cell", "cells/nope.toml", "--output", table], "nope.toml"),
        (&["inspect", "A", "B"], "unexpected argument 'B'"),
        (&["inspect"], "<FILE.dct>"),
        (&["eval", "--cell", "T1", "--table", table, "--width", "900"], "--plot"),
        (&["eval", "--cell", "T1", "--table", table, "--seed", "0"], "must not be 0"),
        (&["eval", "--cell", "T1", "--table", table, "--random", "-3"], "'-3'"),
        (&["render", "--cell", "T1", "--tcp", "1,2", "--tcp", "0,0,-450"], "three numbers"),
        (&["render", "--cell", "T1", "--tcp", "0,0,-450"], "one --tcp x,y,z per robot"),
        (
            &["quilt", "--cell", "T1", "--table", table, "--a", "1,2,3", "--axes", "zz"],
            "cannot be used with",
        ),
        (
            &["quilt", "--cell", "T1", "--table", table, "--a", "1,2,3", "--fix", "1,2"],
            "cannot be used with",
        ),
        (&["completions", "tcsh"], "use bash"),
    ];
    for (args, what) in cases {
        let out = cli(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(what), "{args:?}: `{what}` in\n{}", stderr(&out));
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    assert!(names_in(&dir).is_empty(), "no usage error writes a file");
}

#[test]
fn the_unknown_cell_error_names_the_built_in_cells() {
    let out = cli(&["check", "--cell", "T9"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("'T9'") && err.contains("T1, T2, T3") && err.contains(".toml"), "{err}");
    let out = cli(&["demo", "--cell", "T9"]);
    assert!(
        stderr(&out).contains("T1, T2, T3") && stderr(&out).contains("all"),
        "{}",
        stderr(&out)
    );
}

/// Failures (a file that cannot be read, a table that is not one): exit code 1.
#[test]
fn failures_exit_with_1() {
    let dir = fresh_dir("failures");
    let missing = dir.join("missing.dct");
    let missing = missing.to_str().unwrap();
    let out = cli(&["inspect", missing]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("missing.dct"));
    let out = cli_stdin(&["check", "--cell", "T1", "--table", missing], "");
    assert_eq!(out.status.code(), Some(1));
    let not_a_table = dir.join("not.dct");
    std::fs::write(&not_a_table, "hello").unwrap();
    let out = cli(&["inspect", not_a_table.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let out = cli(&["check", "--cell", "T1", "--input", dir.join("missing.csv").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn completions_and_man_pages_are_generated_from_the_definition() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let out = cli(&["completions", shell]);
        assert_eq!(out.status.code(), Some(0), "{shell}: {}", stderr(&out));
        let script = stdout(&out);
        for word in ["delta-collide", "build", "quilt", "--variant"] {
            assert!(script.contains(word), "{shell} completion: {word}");
        }
        if ["bash", "zsh", "fish"].contains(&shell) {
            assert!(script.contains("shared-sub"), "{shell} completes the variants");
        }
    }
    let out = cli(&["man"]);
    assert_eq!(out.status.code(), Some(0));
    let page = stdout(&out);
    assert!(
        page.starts_with(".ie") && page.contains(".TH delta-collide 1"),
        "{}",
        &page[..page.len().min(300)]
    );
    for word in ["build", "check", "quilt", "completions", "quiet"] {
        assert!(page.contains(word), "man page: {word}");
    }
    let dir = fresh_dir("man");
    let out = cli(&["man", "--output", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let names = names_in(&dir);
    for name in [
        "delta-collide.1",
        "delta-collide-build.1",
        "delta-collide-check.1",
        "delta-collide-quilt.1",
    ] {
        assert!(names.contains(&name.to_string()), "{name} in {names:?}");
    }
    let build = std::fs::read_to_string(dir.join("delta-collide-build.1")).unwrap();
    assert!(build.contains("\\-\\-variant") && build.contains("shared\\-sub"), "{build}");
}

/// Issue: `printf '150,0,-450,-150,0,-450,\n' | delta-collide check --cell T1` took the
/// malformed row for a header and printed only the header, exit 0.
#[test]
fn a_malformed_first_row_is_an_error_not_a_header() {
    let out = cli_stdin(&["check", "--cell", "T1"], "150,0,-450,-150,0,-450,\n");
    assert_eq!(out.status.code(), Some(1), "{}", stdout(&out));
    assert!(stderr(&out).contains("line 1"), "{}", stderr(&out));
    let out = cli_stdin(&["check", "--cell", "T1"], "150,0,-450,-150,0\n");
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("line 1: expected 6 numbers"), "{}", stderr(&out));
    // A header (no number in it) is skipped; a first row of numbers is answered.
    let out = cli_stdin(&["check", "--cell", "T1"], "x,y,z,x2,y2,z2\n-150,0,-450,150,0,-450\n");
    assert_eq!((out.status.code(), stdout(&out).as_str()), (Some(0), "reachable,collide\n1,0\n"));
    let out = cli_stdin(&["check", "--cell", "T1"], "\n-150,0,-450,150,0,-450\n");
    assert_eq!((out.status.code(), stdout(&out).as_str()), (Some(0), "reachable,collide\n1,0\n"));
    // Only the first line can be a header.
    let out = cli_stdin(&["check", "--cell", "T1"], "x,y,z,x2,y2,z2\nx,y,z,x2,y2,z2\n");
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("line 2"));
}

/// Issue: an error that echoed a bad CSV line or value echoed all of it.
#[test]
fn errors_echo_at_most_a_few_dozen_characters_of_the_input() {
    let long = format!("1,2,{}", "9".repeat(5000)) + ",x";
    let out = cli_stdin(&["check", "--cell", "T1"], &format!("{long}\n"));
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("line 1") && err.contains("...") && err.len() < 200, "{err}");
    let out = cli(&["render", "--cell", "T1", "--tcp", &long, "--tcp", "0,0,-450"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("...") && stderr(&out).len() < 300, "{}", stderr(&out));
    let out = cli(&["build", "--cell", "T1", "--output", "x.dct", "--k", &long]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("...") && stderr(&out).len() < 300, "{}", stderr(&out));
    let out = cli(&["build", "--cell", "T1", "--output", "x.dct", "--variant", &long]);
    assert!(stderr(&out).contains("...") && stderr(&out).len() < 300, "{}", stderr(&out));
}

/// Issue: `check --output` wrote in place, so a bad row left a shorter file that looked
/// complete (and the file it replaced was gone).
#[test]
fn check_output_is_untouched_when_a_row_fails() {
    let dir = fresh_dir("check-output");
    let (input, output) = (dir.join("in.csv"), dir.join("out.csv"));
    std::fs::write(&input, "-150,0,-450,150,0,-450\n-150,0,-450,150,0,-450\n1,2,three,4,5,6\n")
        .unwrap();
    std::fs::write(&output, "the previous answers\n").unwrap();
    let args = [
        "check",
        "--cell",
        "T1",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
    ];
    let out = cli(&args);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("line 3"));
    assert_eq!(std::fs::read_to_string(&output).unwrap(), "the previous answers\n");
    assert_eq!(names_in(&dir), ["in.csv", "out.csv"], "no temporary file is left");
    // Once the input is good the file is replaced whole.
    std::fs::write(&input, "-150,0,-450,150,0,-450\n").unwrap();
    assert_eq!(cli(&args).status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(&output).unwrap(), "reachable,collide\n1,0\n");
    assert_eq!(names_in(&dir), ["in.csv", "out.csv"]);
}

/// Runs the CLI under a file-size limit of `blocks` (as `ulimit -f` counts them): a write
/// past it kills the process, as a full disk or a crash would stop it mid-file.
#[cfg(unix)]
fn cli_with_file_limit(blocks: u32, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -f {blocks} && exec \"$0\" \"$@\""))
        .arg(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// Issue: `build --output` wrote the table in place, so a rebuild stopped mid-write
/// destroyed the good table it was replacing.
#[cfg(unix)]
#[test]
fn a_build_stopped_mid_write_leaves_the_old_table_intact() {
    let dir = fresh_dir("build-output");
    let table = dir.join("t1.dct");
    let t = table.to_str().unwrap();
    let out =
        cli(&["build", "--quiet", "--cell", "T1", "--k", "16", "--variant", "5d", "--output", t]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(out.stderr.is_empty(), "--quiet: {}", stderr(&out));
    let good = std::fs::read(&table).unwrap();
    assert!(good.len() > 8 * 1024, "the table is bigger than the limit below");
    let out = cli_with_file_limit(
        8,
        &["build", "--cell", "T1", "--k", "16", "--variant", "6d", "--output", t],
    );
    assert!(!out.status.success(), "the limit stops the write");
    assert_eq!(std::fs::read(&table).unwrap(), good, "the old table is intact");
    assert!(cli(&["inspect", t]).status.success());
    // A picture stopped mid-write: the old file stays as it was, too.
    let picture = dir.join("render.png");
    std::fs::write(&picture, "the previous picture").unwrap();
    let p = picture.to_str().unwrap();
    let out = cli_with_file_limit(
        8,
        &["render", "--cell", "T1", "--tcp", "0,0,-450", "--tcp", "0,0,-450", "--output", p],
    );
    assert!(!out.status.success());
    assert_eq!(std::fs::read_to_string(&picture).unwrap(), "the previous picture");
}

/// Issue: `build --k 512` aborted after trying to allocate 29 GB, and `--k 1024` ran away.
#[test]
fn a_k_beyond_the_format_or_the_memory_is_refused_before_allocating() {
    let dir = fresh_dir("big-k");
    let table = dir.join("t.dct");
    let t = table.to_str().unwrap();
    for k in ["512", "1024"] {
        let out = cli(&["build", "--cell", "T1", "--k", k, "--output", t]);
        assert_eq!(out.status.code(), Some(2), "k = {k} is not a k of the format");
        assert!(stderr(&out).contains("at most 8 levels"), "{}", stderr(&out));
    }
    if cfg!(target_os = "linux") {
        // k = 256: about 9 TB of labels, far beyond any machine this runs on.
        let start = std::time::Instant::now();
        let out = cli(&["build", "--cell", "T1", "--k", "256", "--output", t]);
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains("needs about")
                && err.contains("GB of memory")
                && err.contains("smaller k"),
            "{err}"
        );
        assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
        assert!(start.elapsed().as_secs() < 60, "refused before labelling");
    }
    assert!(names_in(&dir).is_empty(), "nothing written");
}

#[test]
fn progress_never_goes_into_the_data() {
    let dir = fresh_dir("progress");
    let table = dir.join("t.dct");
    let out = cli(&[
        "build",
        "--cell",
        "T1",
        "--k",
        "16",
        "--variant",
        "5d",
        "--output",
        table.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(
        !text.contains("rows of A") && !text.contains('\r') && !text.contains('\u{1b}'),
        "{text}"
    );
    let out = cli_stdin(&["check", "--quiet", "--cell", "T1"], "-150,0,-450,150,0,-450\n");
    assert_eq!((stdout(&out).as_str(), stderr(&out).as_str()), ("reachable,collide\n1,0\n", ""));
}

/// `replay`: one line per tick, the first tick STOP (no previous TCP), robots standing apart
/// FREE afterwards; the header names the columns (`tick` and the others ignored columns kept
/// out of the TCPs, in any order); without a header, `3 n` numbers per row; a malformed row
/// is an error naming its line.
#[test]
fn replay_writes_one_verdict_per_tick() {
    let rows = "tick,x,y,z,x2,y2,z2,note\n7,-150,0,-450,150,0,-450,a\n8,-150,0,-450,150,0,-450,b\n9,-150,0,-450,150,0,-450,c\n";
    let out = cli_stdin(&["replay", "--cell", "T1"], rows);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    assert!(lines[0].starts_with(
        "tick,verdict,clearance_mm,status,protective_mm_A,protective_mm_B,speed_limit_mm_s_A"
    ));
    assert!(lines[1].starts_with("7,stop,") && lines[1].split(',').nth(3) == Some("ok"), "{text}");
    assert!(lines[2].starts_with("8,free,") && lines[3].starts_with("9,free,"), "{text}");
    let clearance: f64 = lines[2].split(',').nth(2).unwrap().parse().unwrap();
    assert!(clearance > 0.0, "{text}");
    // Columns found by name: B's first, a tick last; no header: robot order, ticks from 0.
    let swapped = "x2,y2,z2,x,y,z,tick\n150,0,-450,-150,0,-450,1\n150,0,-450,-150,0,-450,2\n";
    let out = cli_stdin(&["replay", "--cell", "T1"], swapped);
    let swapped_lines: Vec<String> = stdout(&out).lines().map(str::to_string).collect();
    assert_eq!(
        swapped_lines[2].split_once(',').unwrap().1,
        lines[2].split_once(',').unwrap().1,
        "{swapped_lines:?}"
    );
    let out =
        cli_stdin(&["replay", "--cell", "T1"], "-150,0,-450,150,0,-450\n-150,0,-450,150,0,-450\n");
    assert!(stdout(&out).lines().nth(2).unwrap().starts_with("1,free,"), "{}", stdout(&out));
    for (bad, line) in [("1,2,3\n", "line 1"), ("tick,x,y,z,x2,y2,z2\n0,1,2,3,4,5,six\n", "line 2")]
    {
        let out = cli_stdin(&["replay", "--cell", "T1"], bad);
        assert_eq!(out.status.code(), Some(1));
        assert!(stderr(&out).contains(line), "{}", stderr(&out));
    }
}

/// `replay` reads the tick column as the controller's cycle: a repeated tick with the same
/// TCPs repeats its row, with other TCPs it is STOP; a tick that goes back or jumps by more
/// than four is STOP; the ticks after each fault assume full speed (STOP here, then FREE).
#[test]
fn replay_takes_the_tick_column_as_the_cycle() {
    let (a, b) = ("-150,0,-450,150,0,-450", "-150,0,-449.5,150,0,-450");
    let rows = format!("tick,x,y,z,x2,y2,z2\n7,{a}\n8,{a}\n8,{a}\n8,{b}\n9,{a}\n10,{a}\n4,{a}\n5,{a}\n6,{a}\n20,{a}\n");
    let out = cli_stdin(&["replay", "--cell", "T1"], &rows);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().skip(1).collect();
    let rest = |i: usize| lines[i].split_once(',').unwrap().1;
    let field = |i: usize, k: usize| lines[i].split(',').nth(k).unwrap();
    assert!(lines[1].starts_with("8,free,") && rest(2) == rest(1), "{text}");
    assert_eq!((field(3, 1), field(3, 3)), ("stop", "timing repeated"), "{text}");
    assert!(lines[4].starts_with("9,stop,") && lines[5].starts_with("10,free,"), "{text}");
    assert_eq!((field(6, 1), field(6, 3)), ("stop", "timing backwards"), "{text}");
    assert!(lines[7].starts_with("5,stop,") && lines[8].starts_with("6,free,"), "{text}");
    assert_eq!((field(9, 1), field(9, 3)), ("stop", "timing jump"), "{text}");
}

/// `replay` on the four-robot line: columns `x,y,z` to `x4,y4,z4`, a protective distance and
/// a speed limit per robot, the verdict of every pair that can meet.
#[test]
fn replay_runs_a_line_of_four_robots() {
    let apart = "-100,0,-450,100,0,-450,-100,0,-450,100,0,-450";
    let rows = format!("x,y,z,x2,y2,z2,x3,y3,z3,x4,y4,z4\n{apart}\n{apart}\n");
    let out = cli_stdin(&["replay", "--cell", "cells/line4.toml"], &rows);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].ends_with("speed_limit_mm_s_R3,speed_limit_mm_s_R4"), "{text}");
    assert!(lines[1].starts_with("0,stop,") && lines[2].starts_with("1,free,"), "{text}");
    assert_eq!(lines[2].split(',').count(), 4 + 2 * 4, "{text}");
    // --pairs: one clearance per pair that can meet (neighbours and pairs two apart, 1,350 mm
    // of bases apart and more pruned), the smallest of them the cell's.
    let out = cli_stdin(&["replay", "--cell", "cells/line4.toml", "--pairs"], &rows);
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<&str> = lines[0].split(',').skip(12).collect();
    assert!(
        header.len() >= 3
            && header.contains(&"clearance_mm_R1_R2")
            && header.contains(&"clearance_mm_R3_R4"),
        "{text}"
    );
    let row: Vec<f64> =
        lines[2].split(',').skip(2).map(|f| f.parse().unwrap_or(f64::NAN)).collect();
    let smallest = row[10..].iter().copied().fold(f64::INFINITY, f64::min);
    assert!((smallest - row[0]).abs() < 2e-3 && row[0] > 0.0, "{text}");
}

/// The rows of a scenario of `c_harness/scenarios.txt` for its first `ticks` ticks, as CSV.
fn scenario_rows(cell: &str, case: &str, ticks: u32) -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("c_harness/scenarios.txt"),
    )
    .unwrap();
    let scenarios = delta_collide::cell::trajectory::parse_scenarios(&text).unwrap();
    let s = scenarios.iter().find(|s| s.cell == cell && s.case == case).unwrap();
    let mut rows = String::from("x,y,z,x2,y2,z2\n");
    let mut t = vec![Vec3::zeros(); 2];
    for tick in 0..ticks {
        s.tcps_at(tick, &mut t);
        rows += &format!("{},{},{},{},{},{}\n", t[0].x, t[0].y, t[0].z, t[1].x, t[1].y, t[1].z);
    }
    rows
}

/// An 8-bit RGB PNG file's width, height and pixels.
fn read_png(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut rgb).unwrap();
    assert_eq!((info.color_type, info.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight));
    rgb.truncate(info.buffer_size());
    (info.width, info.height, rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
}

/// `replay --plot`: the verdicts as without it, and a PNG of the requested size whose
/// verdict band holds FREE, WARN and STOP ticks (T1's collision run has all three).
#[test]
fn replay_plot_writes_a_png_of_the_requested_size() {
    let dir = fresh_dir("replay-plot");
    let (input, output, plot) =
        (dir.join("run.csv"), dir.join("verdicts.csv"), dir.join("run.png"));
    std::fs::write(&input, scenario_rows("T1", "collision", 4000)).unwrap();
    let args = [
        "replay",
        "--cell",
        "T1",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
    ];
    let out =
        cli(&[&args[..], &["--plot", plot.to_str().unwrap(), "--width", "900", "--height", "450"]]
            .concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("900 x 450 pixels, 4000 ticks"), "{}", stderr(&out));
    let verdicts = std::fs::read_to_string(&output).unwrap();
    assert_eq!(verdicts.lines().count(), 4001);
    let (w, h, pixels) = read_png(&plot);
    assert_eq!((w, h), (900, 450));
    for (name, colour) in
        [("free", [120, 200, 120]), ("warn", [240, 170, 60]), ("stop", [220, 30, 30])]
    {
        assert!(verdicts.contains(&format!(",{name},")), "the run has {name} ticks");
        assert!(pixels.iter().filter(|&&p| p == colour).count() > 20, "{name} band missing");
    }
    // Without --plot the verdicts are the same.
    let out = cli(&args);
    assert!(out.status.success());
    assert_eq!(std::fs::read_to_string(&output).unwrap(), verdicts);
}

#[test]
fn replay_plot_refuses_bad_arguments_with_a_clear_message() {
    let dir = fresh_dir("replay-plot-bad");
    let input = dir.join("run.csv");
    std::fs::write(&input, scenario_rows("T1", "practical", 5)).unwrap();
    let input = input.to_str().unwrap();
    let plot = dir.join("p.png");
    let plot = plot.to_str().unwrap();
    let usage: [(&[&str], &str); 5] = [
        (&["--plot", plot, "--width", "100"], "at least 500"),
        (&["--plot", plot, "--height", "x"], "--height"),
        (&["--width", "900"], "--plot"),
        (&["--plot", "run.csv"], "ending in .png"),
        (&["--plot", plot, "--output", plot], "same file"),
    ];
    for (extra, message) in usage {
        let out = cli(&[&["replay", "--cell", "T1", "--input", input][..], extra].concat());
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(message), "{extra:?}: {}", stderr(&out));
    }
    let missing = dir.join("no-such-dir").join("p.png");
    let out =
        cli(&["replay", "--cell", "T1", "--input", input, "--plot", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("no-such-dir"), "{}", stderr(&out));
    let out = cli_stdin(&["replay", "--cell", "T1", "--plot", plot], "x,y,z,x2,y2,z2\n");
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("no rows"), "{}", stderr(&out));
    assert_eq!(names_in(&dir), ["run.csv"], "no picture is left behind by a failure");
}

/// `check` on the four-robot line of `cells/line4.toml` (12 coordinates a row) answers as
/// the two-robot cells of each pair checked one by one with the library, and so does each
/// column of `--pairs`.
#[test]
fn check_on_a_line_of_four_answers_as_its_pairs_one_by_one() {
    use delta_collide::cell::{placement::Placement, Cell};
    use rand::{rngs::StdRng, RngExt, SeedableRng};
    let t1 = reference_cell("T1").unwrap();
    let pair_cell = |gap: usize| {
        let mut robots = t1.robots.clone();
        robots[1].placement = Placement { alpha: 0.0, t: Vec3::new(450.0 * gap as f64, 0.0, 0.0) };
        ExactChecker::new(Cell::new(format!("gap{gap}"), robots, t1.method).unwrap())
    };
    let mut checkers: Vec<ExactChecker> = (1..4).map(pair_cell).collect();
    let mut rng = StdRng::seed_from_u64(44);
    let mut rows = Vec::new();
    let mut truth = Vec::new();
    let mut pair_truth: Vec<String> = Vec::new();
    while rows.len() < 400 {
        let tcps: Vec<Vec3> = (0..4)
            .map(|_| {
                Vec3::new(
                    rng.random_range(-250.0..250.0),
                    rng.random_range(-150.0..150.0),
                    rng.random_range(-560.0..-360.0),
                )
            })
            .collect();
        let mut reachable = true;
        let mut collide = false;
        let mut flags = String::new();
        for a in 0..4 {
            for b in a + 1..4 {
                let v = checkers[b - a - 1].check(&[tcps[a], tcps[b]]).unwrap();
                reachable &= v.unreachable_mask == 0;
                collide |= v.collides();
                flags += if v.collides() { ",1" } else { ",0" };
            }
        }
        if !reachable {
            continue;
        }
        truth.push(collide);
        pair_truth.push(flags);
        rows.push(
            tcps.iter().map(|p| format!("{},{},{}", p.x, p.y, p.z)).collect::<Vec<_>>().join(","),
        );
    }
    let out = cli_stdin(&["check", "--cell", "cells/line4.toml"], &rows.join("\n"));
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let answers: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(answers.len(), rows.len(), "{text}");
    for ((line, hit), row) in answers.iter().zip(&truth).zip(&rows) {
        assert_eq!(line.split(',').nth(1), Some(if *hit { "1" } else { "0" }), "{row}: {line}");
    }
    let hits = truth.iter().filter(|h| **h).count();
    assert!(hits > 20 && hits < 380, "the rows mix free and colliding lines: {hits}");
    // --pairs: one column per pair that can meet (every pair of this line: the pruning keeps
    // robots 1,350 mm apart, whose reach disks of radius 675 mm touch), in the loop's order.
    let out = cli_stdin(&["check", "--cell", "cells/line4.toml", "--pairs"], &rows.join("\n"));
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let mut lines = text.lines();
    let header = "reachable,collide,collide_R1_R2,collide_R1_R3,collide_R1_R4,collide_R2_R3,collide_R2_R4,collide_R3_R4";
    assert_eq!(lines.next(), Some(header));
    for ((line, flags), row) in lines.zip(&pair_truth).zip(&rows) {
        assert_eq!(&line[line.find(',').unwrap() + 2..], flags.as_str(), "{row}: {line}");
    }
}

#[test]
fn check_with_a_table_confirmed_answers_row_for_row_as_check_without_one() {
    let dir = fresh_dir("confirm");
    let table = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/golden/t1_k16_6d.dct");
    let table = table.to_str().unwrap();
    let mut false_alarms = 0;
    for case in ["practical", "collision"] {
        let input = dir.join(format!("{case}.csv"));
        std::fs::write(&input, scenario_rows("T1", case, 6000)).unwrap();
        let run = |extra: &[&str]| {
            let mut args = vec!["check", "--cell", "T1", "--input", input.to_str().unwrap()];
            args.extend_from_slice(extra);
            let out = cli(&args);
            assert!(out.status.success(), "{args:?}: {}", stderr(&out));
            stdout(&out)
        };
        let exact = run(&[]);
        let confirmed = run(&["--table", table, "--confirm", "exact"]);
        let raw = run(&["--table", table, "--confirm", "none"]);
        assert_eq!(exact.lines().count(), 6001, "a header and one row per tick");
        for (tick, (e, c)) in exact.lines().zip(confirmed.lines()).enumerate().skip(1) {
            assert_eq!(
                c,
                e,
                "T1 {case} tick {}: --confirm exact and the exact check differ",
                tick - 1
            );
        }
        assert_eq!(run(&["--table", table]), confirmed, "--confirm exact is the default");
        for (tick, (e, r)) in exact.lines().zip(raw.lines()).enumerate().skip(1) {
            assert!(
                r == e || r == "1,1",
                "T1 {case} tick {}: the table says {r}, the exact check {e}",
                tick - 1
            );
            false_alarms += usize::from(r != e);
        }
        assert_eq!(exact.contains("1,1"), case == "collision", "T1 {case}");
    }
    assert!(
        false_alarms > 0,
        "the k = 16 table raises false alarms, so the comparison above can fail"
    );
    let out = cli(&["check", "--cell", "T1", "--confirm", "exact"]);
    assert_eq!(out.status.code(), Some(2), "--confirm without --table is a usage error");
    assert!(stderr(&out).contains("--confirm applies to --table"), "{}", stderr(&out));
    let out = cli(&["check", "--cell", "T1", "--table", table, "--confirm", "maybe"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("use exact or none"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `replay --stop-path-mm`: each robot's stop path is its recorded run ahead; the verdict is
/// never worse than without paths, and on T1's practical run it STOPs on fewer ticks.
#[test]
fn replay_with_stop_paths_from_the_rows_ahead_stops_less() {
    let rows = scenario_rows("T1", "practical", 3000);
    let verdicts = |extra: &[&str]| -> Vec<String> {
        let out = cli_stdin(&[&["replay", "--cell", "T1"][..], extra].concat(), &rows);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out).lines().skip(1).map(|l| l.split(',').nth(1).unwrap().to_string()).collect()
    };
    let (without, with) =
        (verdicts(&[]), verdicts(&["--stop-path-mm", "400", "--path-tolerance-mm", "0.5"]));
    assert_eq!(without.len(), with.len());
    let rank = |v: &str| ["free", "warn", "stop"].iter().position(|x| *x == v).unwrap();
    for (tick, (a, b)) in without.iter().zip(&with).enumerate() {
        assert!(rank(b) <= rank(a), "tick {tick}: {b} with paths, {a} without");
    }
    let stops = |v: &[String]| v.iter().filter(|x| *x == "stop").count();
    assert!(
        stops(&with) < stops(&without),
        "{} STOP ticks with paths, {} without",
        stops(&with),
        stops(&without)
    );
    for bad in [["--stop-path-mm", "0"], ["--stop-path-mm", "nan"]] {
        assert_eq!(
            cli(&[&["replay", "--cell", "T1"][..], &bad[..]].concat()).status.code(),
            Some(2),
            "{bad:?}"
        );
    }
    let tolerance_alone = cli(&["replay", "--cell", "T1", "--path-tolerance-mm", "1"]);
    assert_eq!(tolerance_alone.status.code(), Some(2), "--path-tolerance-mm needs --stop-path-mm");
}

/// The issue's finds: `check` took a first line split by semicolons for a header and wrote
/// nothing with exit 0; `build --k -1` answered "unexpected argument"; `check --clearance`
/// wrote 3 decimals of a clearance exact to 1e-13 mm.
#[test]
fn csv_numbers_round_trip_and_bad_first_lines_and_negative_values_are_named() {
    let out = cli_stdin(&["check", "--cell", "T1"], "150;0;-450;-150;0;-450\n");
    assert_eq!(out.status.code(), Some(1), "{}", stdout(&out));
    let e = stderr(&out);
    assert!(e.contains("line 1") && e.contains("x,y,z,x2,y2,z2"), "{e}");
    let out = cli_stdin(&["check", "--cell", "T1"], "a,b,c,d,e,f\n-150,0,-450,150,0,-450\n");
    assert_eq!(out.status.code(), Some(1), "a header that names no column: {}", stdout(&out));

    let out = cli(&["build", "--cell", "T1", "--k", "-1", "--output", "unused.dct"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(e.contains("--k") && e.contains("power of two"), "{e}");

    // Each clearance written reads back as the library's double, bit for bit, and is the
    // shortest such text; --decimals 3 writes three.
    let rows =
        [[-150.0, 0.0, -450.0, 150.0, 0.0, -450.0], [40.0, 10.0, -470.0, -60.0, 0.0, -430.0]];
    let input: String = rows
        .iter()
        .map(|r| r.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let out = cli_stdin(&["check", "--cell", "T1", "--clearance"], &input);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let mut exact = ExactChecker::new(reference_cell("T1").unwrap());
    for (line, r) in stdout(&out).lines().skip(1).zip(&rows) {
        let tcps = [Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5])];
        exact.check(&tcps).unwrap();
        let want = delta_collide::cell::protective::clearance_now(&exact).0;
        let text = line.split(',').nth(2).unwrap();
        let got: f64 = text.parse().unwrap();
        assert_eq!(got.to_bits(), want.to_bits(), "{text} against {want:e}");
        assert_eq!(text, format!("{want}"), "not the shortest text");
    }
    let out = cli_stdin(&["check", "--cell", "T1", "--clearance", "--decimals", "3"], &input);
    for line in stdout(&out).lines().skip(1) {
        let text = line.split(',').nth(2).unwrap();
        assert_eq!(text.split('.').nth(1).map(str::len), Some(3), "{line}");
    }
}

#[test]
fn simulate_writes_a_trace_with_one_row_per_tick() {
    let dir = fresh_dir("simulate_trace");
    let file = dir.join("run.csv");
    let out = cli(&[
        "simulate",
        "--cell",
        "T1",
        "--runs",
        "1",
        "--ticks",
        "300",
        "--mode",
        "coordinate",
        "--trace",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&file).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 13, "tick, five columns per robot, verdict, clearance: {header:?}");
    assert_eq!((header[0], header[11], header[12]), ("tick", "verdict", "clearance_mm"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() >= 300, "{} rows for a programme of 300 ticks", rows.len());
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
        assert!(["FREE", "WARN", "STOP"].contains(&r[11]), "{r:?}");
        assert!(r[12].parse::<f64>().is_ok_and(|c| c > 0.0), "a contact in {r:?}");
    }
}
