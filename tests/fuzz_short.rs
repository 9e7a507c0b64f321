//! Fuzzing in the test suite (docs/FUZZING.md). The targets live in
//! `fuzz/src/` and are compiled into this test as well (`#[path]`), so that:
//! - every committed seed in `fuzz/seeds/<target>/` and every past finding in
//!   `tests/data/fuzz/<target>/` is replayed in-process on every run, with no fuzzer needed (a
//!   seed may fail to load, e.g. after a format change; it must not panic);
//! - each target then runs briefly under libFuzzer (`cargo fuzz run`, stable toolchain, no
//!   sanitizer) from those seeds. Without cargo-fuzz that part is skipped with a note, except
//!   under `CI` (set and not "false"), where a missing fuzzer fails the test: `.ci/run`
//!   installs it.
//!
//! Regenerate the seeds written by code with
//! `DC_REGENERATE_FUZZ_SEEDS=1 cargo test --release --test fuzz_short seeds` (after a table
//! format change; the cell files and corrupted tables are copied from `cells/`, `tests/data/`).

#[allow(dead_code)]
#[path = "../fuzz/src/lib.rs"]
mod targets;

use delta_collide::cell::parse_cell;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Symmetry, Workspace};
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::format::to_bytes;
use delta_collide::table::synthetic::{space, Pattern};
use delta_collide::table::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// libFuzzer executions per target in the short run.
const SHORT_RUNS: u32 = 50_000;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn seed_dir(target: &str) -> PathBuf {
    root().join("fuzz/seeds").join(target)
}

/// The committed seeds, then the inputs of past findings (`tests/data/fuzz/<target>/`).
fn corpus_dirs(target: &str) -> Vec<PathBuf> {
    let found = root().join("tests/data/fuzz").join(target);
    std::iter::once(seed_dir(target)).chain(found.is_dir().then_some(found)).collect()
}

fn seed_files(target: &str) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in corpus_dirs(target) {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        files.extend(entries.map(|e| e.unwrap().path()).filter(|p| p.is_file()));
    }
    files.sort();
    files
}

#[test]
fn committed_seeds_replay_without_a_finding() {
    let mut findings = Vec::new();
    for (name, target) in targets::TARGETS {
        let files = seed_files(name);
        assert!(
            files.len() >= 5,
            "{name}: only {} seeds in {}",
            files.len(),
            seed_dir(name).display()
        );
        for file in files {
            let data = std::fs::read(&file).unwrap();
            if let Err(e) = catch_unwind(AssertUnwindSafe(|| target(&data))) {
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or(e.downcast_ref::<&str>().map(|s| s.to_string()));
                findings.push(format!("{name}: {}: {}", file.display(), msg.unwrap_or_default()));
            }
        }
    }
    assert!(findings.is_empty(), "seeds that fail their target:\n{}", findings.join("\n"));
}

/// T1's and T3's real tables at k = 16 cut down to their first codes or nodes (a few hundred
/// bytes that load and pass `TableChecker::new`), the whole 4D yy' and clearance tables of T1,
/// synthetic k = 4 tables of every variant, and the corrupted files of `tests/data/`.
fn table_seeds() -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for (cell_name, kinds) in [("t1", &TableKind::ALL[..]), ("t3", &[TableKind::D6][..])] {
        let cell = reference_cell(cell_name).unwrap();
        for &kind in kinds {
            // Seed file names spell a kind with '_' (`4d_yy`) where the CLI writes '-'.
            let v = kind.name().replace('-', "_");
            let variant = kind.variant(if kind == TableKind::D4zz { 2 } else { 0 });
            let (header, table, _) = build_table(
                &cell,
                16,
                &Workspace::THESIS,
                variant,
                Labelling::Certified,
                Progress::Silent,
            )
            .unwrap();
            if let Some(small) = cut(&table, 24) {
                out.push((format!("{cell_name}_k16_{v}_cut.dct"), to_bytes(&small, &header)));
            }
            if cell_name == "t1" && matches!(kind, TableKind::D4yy | TableKind::Clearance) {
                out.push((format!("{cell_name}_k16_{v}_whole.dct"), to_bytes(&table, &header)));
            }
        }
    }
    let s = space(2, Pattern::Noise { p: 0.3, seed: 4 });
    let header =
        Header::for_space(&s, 0x0123_4567_89ab_cdef, Workspace::THESIS, Certification::SweptBound);
    let synthetic = [
        ("6d", Table::D6(LinearQuadtree6d::build(&s, Symmetry::Whole).unwrap())),
        ("6d_symmetric", Table::D6(LinearQuadtree6d::build(&s, Symmetry::MirrorY).unwrap())),
        ("5d", Table::D5(LinearQuadtree5d::build(&s, Symmetry::Whole).unwrap())),
        (
            "4d_yy",
            Table::D4(LinearQuadtree4d::build(&s, Symmetry::MirrorY, SliceAxes::YY, 0).unwrap()),
        ),
        (
            "4d_zz",
            Table::D4(LinearQuadtree4d::build(&s, Symmetry::Whole, SliceAxes::ZZ, 3).unwrap()),
        ),
        ("shared", Table::Shared(SharedQuadtree6d::build(&s, Symmetry::MirrorY).unwrap())),
    ];
    for (v, t) in synthetic {
        out.push((format!("synthetic_k4_{v}.dct"), to_bytes(&t, &header)));
    }
    for entry in std::fs::read_dir(root().join("tests/data")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "dctable") {
            out.push((
                path.file_name().unwrap().to_str().unwrap().into(),
                std::fs::read(&path).unwrap(),
            ));
        }
    }
    out
}

/// The bundle of `cells/line4.toml` at k = 16 (three `shared` tables for six pairs), whole and
/// with its tables cut to their first nodes; one without its last pair and table, which the
/// line must refuse; a bundle of one table for T1.
fn bundle_seeds() -> Vec<(String, Vec<u8>)> {
    let line =
        parse_cell(&std::fs::read_to_string(root().join("cells/line4.toml")).unwrap()).unwrap();
    let built = build_bundle(
        &line,
        16,
        &Workspace::THESIS,
        Variant::Shared,
        Labelling::Certified,
        Progress::Silent,
    )
    .expect("the line's bundle");
    let (fingerprint, robots) = (line.fingerprint(), line.robots.len());
    let cut_files: Vec<Vec<u8>> =
        built.tables.iter().map(|(h, t, _, _)| to_bytes(&cut(t, 24).unwrap(), h)).collect();
    let bundle = |files: &[Vec<u8>], pairs: &[BundlePair]| {
        bundle_to_bytes(fingerprint, robots, files, pairs).unwrap()
    };
    let short: Vec<BundlePair> = built.pairs.iter().copied().filter(|p| p.table < 2).collect();
    let t1 = reference_cell("t1").unwrap();
    let (t1_files, t1_pairs) =
        (vec![cut_files[0].clone()], vec![BundlePair { a: 0, b: 1, table: 0 }]);
    let cut_bundle = bundle(&cut_files, &built.pairs);
    vec![
        ("line4_k16_shared_whole.dcb".into(), built.bytes.clone()),
        ("line4_k16_shared_cut_truncated.dcb".into(), cut_bundle[..cut_bundle.len() / 2].to_vec()),
        ("line4_k16_shared_cut.dcb".into(), cut_bundle),
        ("line4_k16_shared_cut_short.dcb".into(), bundle(&cut_files[..2], &short)),
        (
            "t1_spacing_one_table.dcb".into(),
            bundle_to_bytes(t1.fingerprint(), 2, &t1_files, &t1_pairs).unwrap(),
        ),
    ]
}

/// The bundle seeds reach the checker: the whole and cut bundles load for the line, the one
/// without its last table is refused for the line's farthest pairs.
#[test]
fn bundle_seeds_load_for_the_line() {
    let line =
        parse_cell(&std::fs::read_to_string(root().join("cells/line4.toml")).unwrap()).unwrap();
    let seed = |name: &str| std::fs::read(seed_dir("bundle_bytes").join(name)).unwrap();
    for name in ["line4_k16_shared_whole.dcb", "line4_k16_shared_cut.dcb"] {
        let checker = BundleChecker::new(line.clone(), &seed(name), Confirmation::Exact);
        assert_eq!(checker.map(|c| c.table_count()).map_err(|e| e.to_string()), Ok(3), "{name}");
    }
    let short =
        BundleChecker::new(line, &seed("line4_k16_shared_cut_short.dcb"), Confirmation::Exact);
    assert!(matches!(short, Err(TableError::MissingPair { .. })), "{:?}", short.map(|_| ()));
}

/// The table's first `n` codes with their data (the shared quadtree: `n` nodes per depth):
/// small, and valid by construction.
fn cut(table: &Table, n: usize) -> Option<Table> {
    Some(match table {
        Table::D6(q) => {
            let codes = q.codes()[..n.min(q.codes().len())].to_vec();
            Table::D6(LinearQuadtree6d::from_parts(q.levels(), q.symmetric(), codes).unwrap())
        }
        Table::D5(q) => {
            let (codes, offsets, ivs) = q.parts();
            let n = n.min(codes.len());
            let ivs = ivs[..offsets[n] as usize].to_vec();
            let parts = (codes[..n].to_vec(), offsets[..=n].to_vec(), ivs);
            Table::D5(
                LinearQuadtree5d::from_parts(q.levels(), q.symmetric(), parts.0, parts.1, parts.2)
                    .unwrap(),
            )
        }
        Table::D4(q) => {
            let (codes, slice_of, slices) = q.parts();
            let n = n.min(codes.len());
            let wps = slices.len() / q.slice_count();
            let mut kept: Vec<u32> = slice_of[..n].to_vec();
            kept.sort_unstable();
            kept.dedup();
            let new_slice_of =
                slice_of[..n].iter().map(|s| kept.binary_search(s).unwrap() as u32).collect();
            let words = kept
                .iter()
                .flat_map(|&s| slices[s as usize * wps..][..wps].iter().copied())
                .collect();
            let (levels, sym, axes, t) = (q.levels(), q.symmetric(), q.axes(), q.threshold());
            Table::D4(
                LinearQuadtree4d::from_parts(
                    levels,
                    sym,
                    axes,
                    t,
                    codes[..n].to_vec(),
                    new_slice_of,
                    words,
                )
                .unwrap(),
            )
        }
        Table::Shared(q) => Table::Shared(prune_shared(q, n)),
        // Two trees that must agree: kept whole (`table_seeds`).
        Table::Clearance(_) => return None,
    })
}

/// The shared quadtree with at most `budget` nodes per depth (and leaves): the first ones met
/// from the root; a child past the budget becomes uniform collision. Valid by construction.
fn prune_shared(q: &SharedQuadtree6d, budget: usize) -> SharedQuadtree6d {
    let p = q.parts();
    let children = p.children.to_u32();
    let depths = p.depth_start.len() - 1;
    // kept[d]: old ids (relative to depth d; leaves at d = depths) in the order met.
    let mut kept: Vec<Vec<u32>> = vec![vec![0]];
    let (mut masks, mut bases, mut new_children) = (Vec::new(), Vec::new(), Vec::new());
    let mut depth_start = vec![0u32];
    for d in 0..depths {
        let mut next: Vec<u32> = Vec::new();
        for &old in &kept[d] {
            let node = p.depth_start[d] as usize + old as usize;
            let [mut nonuniform, mut collision] = p.masks[node];
            bases.push(new_children.len() as u32);
            for (rank, bit) in
                (0..64).map(|i| 1u64 << i).filter(|b| p.masks[node][0] & b != 0).enumerate()
            {
                let child = children[p.bases[node] as usize + rank];
                let id = next.iter().position(|&c| c == child).or_else(|| {
                    (next.len() < budget).then(|| {
                        next.push(child);
                        next.len() - 1
                    })
                });
                match id {
                    Some(id) => new_children.push(id as u32),
                    None => (nonuniform, collision) = (nonuniform & !bit, collision | bit),
                }
            }
            masks.push([nonuniform, collision]);
        }
        depth_start.push(depth_start[d] + kept[d].len() as u32);
        kept.push(next);
    }
    let leaves = kept[depths].iter().map(|&l| p.leaves[l as usize]).collect();
    SharedQuadtree6d::from_parts(
        q.levels(),
        q.sub_levels(),
        q.symmetric(),
        masks,
        bases,
        depth_start,
        new_children,
        leaves,
    )
    .unwrap()
}

/// The reference cell files, every key of the schema, and files that must be refused.
fn cell_seeds() -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = ["t1", "t2", "t3"]
        .iter()
        .map(|n| {
            (format!("{n}.toml"), std::fs::read(root().join(format!("cells/{n}.toml"))).unwrap())
        })
        .collect();
    let every_key = r#"name = "every key"
method = "sat"
[[robot]]
name = "A"
geometry = { f = 100.0, rf = 150.0, re = 400.0, e = 40.0, theta_min_deg = -90.0, theta_max_deg = 120.0 }
model = { half_height = 70.0, half_depth = 17.5, margin = 2.5, upper_links = { half_height = 30.0, half_depth = 15.0 }, platform = { offset = [0.0, 0.0, -10.0], half = [50.0, 50.0, 10.0] }, tool = { offset = [0.0, 0.0, -60.0], half = [30.0, 30.0, 60.0] } }
[[robot]]
name = "B"
placement = { alpha_deg = 180.0, t = [380.0, 0.0, 0.0] }
model = { tool = { half = [25.0, 25.0, 80.0] } }
"#;
    out.push(("every_key.toml".into(), every_key.into()));
    let line = |n: usize, dx: f64| {
        let robots: String = (0..n)
            .map(|i| format!("[[robot]]\nplacement = {{ t = [{:.1}, 0.0, 0.0] }}\n", dx * i as f64))
            .collect();
        format!("name = \"line\"\n{robots}").into_bytes()
    };
    out.push(("three_robots_close.toml".into(), line(3, 300.0)));
    out.push(("thirty_two_robots.toml".into(), line(32, 450.0)));
    out.push(("thirty_three_robots_refused.toml".into(), line(33, 450.0)));
    out.push(("typo_refused.toml".into(), b"[[robot]]\nmodel = { margn = 3.0 }\n".to_vec()));
    out.push((
        "negative_margin_refused.toml".into(),
        b"[[robot]]\nmodel = { margin = -1.0 }\n".to_vec(),
    ));
    out.push(("no_robot_refused.toml".into(), b"name = \"empty\"\nrobot = []\n".to_vec()));
    out.push(("huge_lengths.toml".into(), b"[[robot]]\ngeometry = { f = 1e300, rf = 1e300, re = 1e300, e = 1e-300, theta_min_deg = -90.0, theta_max_deg = 120.0 }\n[[robot]]\n".to_vec()));
    out
}

fn generated_seeds(target: &str) -> Vec<(String, Vec<u8>)> {
    match target {
        "table_bytes" => table_seeds(),
        "bundle_bytes" => bundle_seeds(),
        "cell_toml" => cell_seeds(),
        "exact_oracle" => targets::exact_oracle::seeds(),
        _ => targets::c_abi::seeds().into_iter().map(|(n, b)| (format!("{n}.bin"), b)).collect(),
    }
}

/// Writes the seeds with `DC_REGENERATE_FUZZ_SEEDS` set; otherwise checks that the call
/// sequences of `c_abi` (whose encoding lives in `fuzz/src/c_abi.rs`) are committed as written.
#[test]
fn seeds_are_committed() {
    if std::env::var_os("DC_REGENERATE_FUZZ_SEEDS").is_some() {
        for (target, _) in targets::TARGETS {
            let dir = seed_dir(target);
            std::fs::create_dir_all(&dir).unwrap();
            for (name, bytes) in generated_seeds(target) {
                std::fs::write(dir.join(name), bytes).unwrap();
            }
        }
    }
    for (name, bytes) in generated_seeds("c_abi") {
        let path = seed_dir("c_abi").join(&name);
        assert_eq!(
            std::fs::read(&path).ok(),
            Some(bytes),
            "{} is stale; regenerate (module doc)",
            path.display()
        );
    }
}

/// Whether this run is CI's (`CI` set and not "false"), where nothing may be skipped.
fn on_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

fn cargo() -> Command {
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.current_dir(root());
    cmd
}

/// `cargo fuzz <args>` with the flags of the short run: no sanitizer (the stable toolchain has
/// none), debug assertions on (cargo-fuzz's default), the fuzz crate's own target folder.
fn cargo_fuzz(verb: &str) -> Command {
    let mut cmd = cargo();
    cmd.args(["fuzz", verb, "--sanitizer", "none", "--target-dir", "fuzz/target"]);
    cmd
}

fn output_text(out: &std::process::Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

#[test]
fn each_target_fuzzes_briefly_without_a_finding() {
    let probe = cargo().args(["fuzz", "--version"]).output();
    if !probe.as_ref().is_ok_and(|o| o.status.success()) {
        let why = "cargo-fuzz is not installed (`cargo install cargo-fuzz --locked`; .ci/run does)";
        assert!(!on_ci(), "{why}: the short fuzz run cannot be skipped on CI");
        eprintln!("skipped: {why}");
        return;
    }
    let start = Instant::now();
    let out = cargo_fuzz("build").output().expect("cargo fuzz build");
    assert!(out.status.success(), "cargo fuzz build failed:\n{}", output_text(&out));
    println!("cargo fuzz build: {:.1} s", start.elapsed().as_secs_f64());
    for (name, _) in targets::TARGETS {
        let scratch =
            PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz-corpus-{name}"));
        let _ = std::fs::remove_dir_all(&scratch);
        std::fs::create_dir_all(&scratch).unwrap();
        let artifacts =
            PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz-artifacts-{name}/"));
        std::fs::create_dir_all(&artifacts).unwrap();
        let mut cmd = cargo_fuzz("run");
        // New inputs go to the first corpus folder (scratch), so the seeds stay as committed.
        cmd.arg(name).arg(&scratch).args(corpus_dirs(name)).arg("--");
        cmd.args([format!("-runs={SHORT_RUNS}"), "-seed=1".into(), "-timeout=60".into()]);
        cmd.arg(format!("-artifact_prefix={}", artifacts.display()));
        let dict = root().join(format!("fuzz/{name}.dict"));
        if dict.exists() {
            cmd.arg(format!("-dict={}", dict.display()));
        }
        let start = Instant::now();
        let out = cmd.output().expect("cargo fuzz run");
        let text = output_text(&out);
        assert!(
            out.status.success(),
            "{name}: a finding (input kept in {}):\n{text}",
            artifacts.display()
        );
        let done = text.lines().find(|l| l.starts_with("Done ")).unwrap_or("no `Done` line");
        println!("{name}: {done} ({:.1} s wall)", start.elapsed().as_secs_f64());
        assert!(done.starts_with(&format!("Done {SHORT_RUNS} runs")), "{name}: {done}\n{text}");
    }
}
