//! Builds bounded by `--max-memory`, through the real command line: a subdivided table built
//! with its sub-cells streamed by many small blocks (16 MiB above the fixed part) is
//! byte for byte the one-shot library build's (T1, T2, T3 at k = 16, the smallest k the
//! workspace allows); a bound below the fixed part is refused up front with exit code 1.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::{build_table, memory_plan, to_bytes, Labelling, Variant};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_delta-collide");

fn cli(args: &[&str]) -> Output {
    Command::new(BIN)
        .arg("--quiet")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// The table file of the one-shot library build of `cell` at k = 16.
fn one_shot(cell: &str) -> Vec<u8> {
    let cell = reference_cell(cell).unwrap();
    let (header, table, _) = build_table(
        &cell,
        16,
        &Workspace::THESIS,
        Variant::SharedSubdivided,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    to_bytes(&table, &header)
}

/// Bytes just above the fixed part of a subdivided build of `cell` at k = 16: blocks of
/// 4^3 x 4^3 cells and a sub-octant cache of 8 MiB, dropped again and again.
fn tight(cell: &str) -> u64 {
    let c = reference_cell(cell).unwrap();
    let plan =
        memory_plan(&c, 16, &Workspace::THESIS, Variant::SharedSubdivided, u64::MAX).unwrap();
    let tight =
        memory_plan(&c, 16, &Workspace::THESIS, Variant::SharedSubdivided, plan.fixed + (16 << 20))
            .unwrap();
    assert_eq!(tight.block_depth, 2, "{cell}: {tight:?}");
    plan.fixed + (16 << 20)
}

fn streamed_matches_one_shot(cell: &str) {
    let tmp = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let dir = tmp.join(format!("dc-bounded-{cell}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("t.dct");
    let max = tight(cell).to_string();
    let args =
        ["build", "--cell", cell, "--k", "16", "--variant", "shared-sub", "--max-memory", &max];
    let out = cli(&[&args[..], &["--output", file.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{cell}: {}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read(&file).unwrap() == one_shot(cell), "{cell}: the streamed table differs");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn streamed_sub_cells_give_the_one_shot_table_t1_t3() {
    streamed_matches_one_shot("T1");
    streamed_matches_one_shot("T3");
}

#[test]
fn streamed_sub_cells_give_the_one_shot_table_t2() {
    streamed_matches_one_shot("T2");
}

/// Less memory than the boxes and labels need: refused before labelling, naming the bound.
#[test]
fn an_impossible_bound_is_refused_up_front() {
    let start = std::time::Instant::now();
    let out = cli(&[
        "build",
        "--cell",
        "T1",
        "--k",
        "32",
        "--variant",
        "6d",
        "--max-memory",
        "64M",
        "--output",
        "x",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("more than the 0.07 GB allowed") && err.contains("labels"), "{err}");
    assert!(start.elapsed().as_secs() < 20, "refused only after {:?}", start.elapsed());
    let out = cli(&["build", "--cell", "T1", "--max-memory", "8X", "--output", "x"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}
