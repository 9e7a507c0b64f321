//! Tables built in shards, through the real command line: `build --shard I/N` for every `I`
//! and `merge` write the one-shot `build`'s table byte for byte (T1, T2, T3 at k = 16, the
//! smallest k the workspace allows, N = 1, 2, 3, 5; several variants, clearance tables with
//! their ladders, and both labellings);
//! a missing, duplicated, foreign, truncated or corrupt shard is refused with exit code 1 and
//! a message naming the file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_delta-collide");
const K: &str = "16";

fn cli(args: &[&str]) -> Output {
    Command::new(BIN)
        .arg("--quiet")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> Output {
    let out = cli(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// A failure (exit code 1) whose message contains every one of `needles`.
fn fails(args: &[&str], needles: &[&str]) {
    let out = cli(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: the message lacks {n:?}: {err}");
    }
}

fn fresh_dir(name: &str) -> PathBuf {
    let tmp = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let dir = tmp.join(format!("dc-shards-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `build` with `extra` flags, one-shot into `out`.
fn build(cell: &str, extra: &[&str], out: &Path) {
    let mut args = vec!["build", "--cell", cell, "--k", K, "--output", s(out)];
    args.extend_from_slice(extra);
    ok(&args);
}

/// Every shard of `n` into `dir`, returned in index order.
fn shards(cell: &str, extra: &[&str], n: u32, dir: &Path, tag: &str) -> Vec<PathBuf> {
    (0..n)
        .map(|i| {
            let path = dir.join(format!("{tag}-{i}-of-{n}.dcs"));
            let shard = format!("{i}/{n}");
            let mut args =
                vec!["build", "--cell", cell, "--k", K, "--shard", &shard, "--output", s(&path)];
            args.extend_from_slice(extra);
            ok(&args);
            path
        })
        .collect()
}

/// Merges `files` into `out`.
fn merge(files: &[PathBuf], out: &Path) {
    let mut args = vec!["merge", "--output", s(out)];
    args.extend(files.iter().map(|f| s(f)));
    ok(&args);
}

/// For `cell` and the build flags `extra`: the one-shot table, then for each N the shards
/// merged in reverse order, byte for byte equal.
fn merged_equals_one_shot(cell: &str, extra: &[&str], counts: &[u32]) {
    let tag = format!("{cell}{}", extra.join("").replace('-', ""));
    let dir = fresh_dir(&tag);
    let one_shot = dir.join("one-shot.dct");
    build(cell, extra, &one_shot);
    let want = std::fs::read(&one_shot).unwrap();
    assert!(want.len() > 1000, "{cell}: a real table");
    for &n in counts {
        let mut files = shards(cell, extra, n, &dir, &tag);
        files.reverse();
        let merged = dir.join(format!("merged-{n}.dct"));
        merge(&files, &merged);
        let got = std::fs::read(&merged).unwrap();
        assert!(got == want, "{cell} {extra:?}: {n} shards merged differ from the one-shot build");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn t1_shards_merge_into_the_one_shot_table() {
    merged_equals_one_shot("T1", &[], &[1, 2, 3, 5]);
}

#[test]
fn t2_shards_merge_into_the_one_shot_table() {
    merged_equals_one_shot("T2", &[], &[1, 2, 3, 5]);
}

#[test]
fn t3_shards_merge_into_the_one_shot_table() {
    merged_equals_one_shot("T3", &[], &[1, 2, 3, 5]);
}

#[test]
fn every_kind_of_table_and_both_labellings_shard() {
    merged_equals_one_shot("T1", &["--variant", "shared-sub"], &[3]);
    merged_equals_one_shot("T3", &["--variant", "shared"], &[2]);
    merged_equals_one_shot("T3", &["--variant", "4d-zz", "--t", "3"], &[2]);
    merged_equals_one_shot("T2", &["--variant", "5d", "--labelling", "thesis"], &[2]);
}

/// Clearance tables shard: the shards carry each pair's proved level count and the ladder,
/// and the merge writes the one-shot table (default ladder, and one given with `--levels`).
#[test]
fn clearance_tables_shard() {
    merged_equals_one_shot("T3", &["--variant", "clearance"], &[2, 3]);
    merged_equals_one_shot("T1", &["--variant", "clearance", "--levels", "0,15,60"], &[2]);
}

/// A clearance shard of another ladder, or of another variant, belongs to another build.
#[test]
fn clearance_shards_of_another_ladder_are_refused() {
    let dir = fresh_dir("ladders");
    let out = dir.join("t.dct");
    let o = s(&out);
    let three = shards("T3", &["--variant", "clearance"], 3, &dir, "t3c");
    let (a, b) = (s(&three[0]), s(&three[1]));
    let other = shards("T3", &["--variant", "clearance", "--levels", "0,10"], 3, &dir, "t3l");
    fails(&["merge", "--output", o, a, b, s(&other[2])], &["t3l-2-of-3.dcs", "clearance levels"]);
    let shared = shards("T3", &["--variant", "shared"], 3, &dir, "t3s");
    fails(&["merge", "--output", o, a, b, s(&shared[2])], &["t3s-2-of-3.dcs", "variant shared"]);
    fails(&["merge", "--output", o, a, b], &["1 of 3 shards missing: 2"]);
    assert!(!out.exists(), "no table is written when the merge fails");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn more_shards_than_rows_leave_some_empty_and_the_index_must_be_below_the_count() {
    let dir = fresh_dir("empty");
    let path = dir.join("last.dcs");
    let out = ok(&["build", "--cell", "T3", "--k", K, "--shard", "999/1000", "--output", s(&path)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("shard 999/1000, rows 0 of"), "{text}");
    // Alone it is one shard of 1000: the others are missing, and the message counts them.
    fails(
        &["merge", "--output", s(&dir.join("t.dct")), s(&path)],
        &["999 of 1000 shards missing: 0, 1, 2"],
    );
    for bad in ["3/3", "1/0", "x/2", "2"] {
        let out = cli(&["build", "--cell", "T3", "--k", K, "--shard", bad, "--output", s(&path)]);
        assert_eq!(
            out.status.code(),
            Some(2),
            "--shard {bad}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = cli(&[
        "build",
        "--cell",
        "T3",
        "--k",
        K,
        "--shard",
        "0/2",
        "--shards",
        "2",
        "--output",
        s(&path),
    ]);
    assert_eq!(out.status.code(), Some(2), "--shards goes with --shard auto only");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn shard_auto_reads_the_schedulers_environment() {
    let dir = fresh_dir("auto");
    let run = |vars: &[(&str, &str)], extra: &[&str]| {
        let mut c = Command::new(BIN);
        for v in [
            "SLURM_ARRAY_TASK_ID",
            "SLURM_ARRAY_TASK_COUNT",
            "SLURM_ARRAY_TASK_MIN",
            "SLURM_ARRAY_TASK_STEP",
        ] {
            c.env_remove(v);
        }
        for v in [
            "JOB_COMPLETION_INDEX",
            "AWS_BATCH_JOB_ARRAY_INDEX",
            "AWS_BATCH_JOB_ARRAY_SIZE",
            "DELTA_COLLIDE_SHARDS",
        ] {
            c.env_remove(v);
        }
        c.envs(vars.iter().copied());
        let out_path = dir.join("auto-{index}-of-{count}.dcs");
        c.args([
            "-q",
            "build",
            "--cell",
            "T3",
            "--k",
            K,
            "--shard",
            "auto",
            "--output",
            s(&out_path),
        ]);
        c.args(extra).output().unwrap()
    };
    let out = run(
        &[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("SLURM_ARRAY_TASK_MIN", "3"),
        ],
        &[],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.join("auto-2-of-4.dcs").exists(), "Slurm task 5 of the array 3-6 is shard 2 of 4");
    let out = run(&[("JOB_COMPLETION_INDEX", "1")], &["--shards", "7"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.join("auto-1-of-7.dcs").exists());
    let out = run(&[("AWS_BATCH_JOB_ARRAY_INDEX", "0"), ("AWS_BATCH_JOB_ARRAY_SIZE", "9")], &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.join("auto-0-of-9.dcs").exists());
    let out = run(&[("JOB_COMPLETION_INDEX", "1")], &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--shards N"));
    let out = run(&[], &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no scheduler"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_duplicate_foreign_truncated_and_corrupt_shards_are_refused_naming_the_file() {
    let dir = fresh_dir("errors");
    let out = dir.join("t.dct");
    let o = s(&out);
    let three = shards("T3", &[], 3, &dir, "t3");
    let (a, b, c) = (s(&three[0]), s(&three[1]), s(&three[2]));
    fails(&["merge", "--output", o, a, c], &["1 of 3 shards missing: 1", "build --shard I/3"]);
    let copy = dir.join("copy-of-0.dcs");
    std::fs::copy(&three[0], &copy).unwrap();
    fails(&["merge", "--output", o, a, b, c, s(&copy)], &["both hold shard 0", a, "copy-of-0.dcs"]);
    // Another N, another cell, another variant, another labelling.
    let two = shards("T3", &[], 2, &dir, "t3two");
    fails(
        &["merge", "--output", o, a, b, s(&two[1])],
        &["t3two-1-of-2.dcs", "one of 2 shards, not of 3"],
    );
    let t1 = shards("T1", &[], 3, &dir, "t1");
    fails(&["merge", "--output", o, a, b, s(&t1[2])], &["t1-2-of-3.dcs", "another build", "cell"]);
    let other = shards("T3", &["--variant", "5d"], 3, &dir, "t35d");
    fails(&["merge", "--output", o, a, s(&other[1]), c], &["t35d-1-of-3.dcs", "variant 5d"]);
    let thesis = shards("T3", &["--labelling", "thesis"], 3, &dir, "t3thesis");
    fails(&["merge", "--output", o, a, b, s(&thesis[2])], &["t3thesis-2-of-3.dcs", "labelling"]);
    // Truncated, a flipped byte, a table given as a shard, a file that is not there.
    let bytes = std::fs::read(&three[1]).unwrap();
    let cut = dir.join("cut.dcs");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    fails(&["merge", "--output", o, a, s(&cut), c], &["cut.dcs", "truncated"]);
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 2] ^= 0x10;
    let bad = dir.join("flipped.dcs");
    std::fs::write(&bad, &flipped).unwrap();
    fails(&["merge", "--output", o, a, s(&bad), c], &["flipped.dcs", "checksum"]);
    let table = dir.join("whole.dct");
    build("T3", &[], &table);
    fails(&["merge", "--output", o, a, s(&table), c], &["whole.dct", "table file, not a shard"]);
    fails(&["merge", "--output", o, a, b, s(&dir.join("nope.dcs"))], &["nope.dcs"]);
    assert!(!out.exists(), "no table is written when the merge fails");
    merge(&three, &out);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&table).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}
