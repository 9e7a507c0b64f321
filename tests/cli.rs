//! The command line as a user runs it: `demo` and `check` on real files.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use std::process::Command;

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_delta-collide")).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

#[test]
fn demo_reports_no_collision_when_practical_and_the_same_first_tick_for_both_methods() {
    let out = cli(&["demo", "--cell", "all"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    println!("{text}");
    for cell in ["T1", "T2", "T3"] {
        let rows: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| l.starts_with(cell))
            .map(|l| l.split_whitespace().collect())
            .collect();
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
        expected.push(match (v.all_reachable(), v.collides()) {
            (false, _) => "0,NA",
            (true, true) => "1,1",
            (true, false) => "1,0",
        }
        .to_string());
    }
    std::fs::write(&input, rows.join("\n")).unwrap();
    let out = cli(&["check", "--cell", "cells/t2.toml", "--input", input.to_str().unwrap(), "--output", output.to_str().unwrap()]);
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
