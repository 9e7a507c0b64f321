//! The command line as a user runs it: `demo` and `check` on real files.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use std::process::Command;

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_delta-collide"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

#[test]
fn demo_reports_no_collision_when_practical_and_the_same_first_tick_for_both_methods() {
    let out = cli(&["demo", "--cell", "all"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    println!("{text}");
    for cell in ["T1", "T2", "T3"] {
        let rows: Vec<Vec<&str>> =
            text.lines().filter(|l| l.starts_with(cell)).map(|l| l.split_whitespace().collect()).collect();
        assert_eq!(rows.len(), 4, "{cell}: practical and collision, SAT and SAT-cache");
        for r in rows.iter().filter(|r| r[1] == "practical") {
            assert_eq!((r[3], r[4]), ("none", "0"), "{cell} practical never collides");
        }
        let ticks: Vec<u32> = rows.iter().filter(|r| r[1] == "collision").map(|r| r[4].parse().unwrap()).collect();
        assert_eq!(ticks.len(), 2);
        assert_eq!(ticks[0], ticks[1], "{cell}: SAT and SAT-cache stop at the same tick");
        assert!(ticks[0] > 3000 && ticks[0] < 6000, "{cell}: the last part of the run collides");
    }
}

#[test]
fn check_writes_one_line_per_row_matching_the_exact_checker() {
    let dir = std::env::temp_dir().join(format!("dc-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join("in.csv"), dir.join("out.csv"));
    let mut rows = vec!["x,y,z,x2,y2,z2".to_string()];
    let mut expected = vec!["reachable,collide".to_string()];
    let mut checker = ExactChecker::new(reference_cell("T2").unwrap());
    for i in 0..501 {
        let s = i as f64 / 500.0;
        let z = if i == 500 { -900.0 } else { -450.0 - 60.0 * s };
        let tcps = [Vec3::new(-200.0 + 400.0 * s, 20.0, z), Vec3::new(180.0 - 380.0 * s, -10.0, -470.0)];
        rows.push(format!("{},{},{},{},{},{}", tcps[0].x, tcps[0].y, tcps[0].z, tcps[1].x, tcps[1].y, tcps[1].z));
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
    let dir = std::env::temp_dir().join(format!("dc-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("bad.csv");
    std::fs::write(&input, "1,2,3,4,5,6\n1,2,three,4,5,6\n").unwrap();
    let out = cli(&["check", "--cell", "T1", "--input", input.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 2"));
}

#[test]
fn build_inspect_eval_and_check_with_a_table() {
    let dir = std::env::temp_dir().join(format!("dc-cli-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table = dir.join("t3.dct");
    let table = table.to_str().unwrap();
    let out = cli(&["build", "--cell", "T3", "--k", "16", "--variant", "5d", "--output", table]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("symmetric: false"), "T3 has no symmetry");
    let out = cli(&["inspect", table]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success() && text.contains("5D") && text.contains("SweptBound"), "{text}");
    let out = cli(&["eval", "--cell", "T3", "--table", table, "--random", "20000"]);
    let text = String::from_utf8(out.stdout).unwrap();
    println!("{text}");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let fns: Vec<&str> =
        text.lines().filter_map(|l| l.split("FN").nth(1)).map(|r| r.split_whitespace().next().unwrap()).collect();
    assert_eq!(fns, vec!["0", "0", "0"], "practical, collision and random: no false negative");
    let out = cli(&["eval", "--cell", "T1", "--table", table, "--random", "10"]);
    assert_eq!(out.status.code(), Some(2), "a T3 table is refused for T1");
    assert!(String::from_utf8_lossy(&out.stderr).contains("rebuild"));
    let input = dir.join("in.csv");
    // Robots reaching toward each other (B's MCS is turned by 30 degrees), apart, unreachable.
    std::fs::write(&input, "190,70,-450,-200,-20,-450\n-150,0,-450,150,0,-450\n0,0,-900,0,0,-450\n").unwrap();
    let out = cli(&["check", "--cell", "T3", "--table", table, "--input", input.to_str().unwrap()]);
    assert_eq!(String::from_utf8(out.stdout).unwrap(), "reachable,collide\n1,1\n1,0\n0,NA\n");
}
