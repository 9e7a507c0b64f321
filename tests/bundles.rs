//! Bundles (`table::bundle`): one table per pair cell of a line, shared by the pairs that
//! stand alike, checked against the exact model of the whole line (robots at their absolute
//! placements, nothing of the pair cells), and the bundle file's refusals.

use delta_collide::cell::exact::PairState;
use delta_collide::cell::{parse_cell, Cell, ExactChecker, Placement};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::bundle::{build_bundle, plan, BUNDLE_VERSION};
use delta_collide::table::{
    bundle_from_bytes, bundle_to_bytes, BundleChecker, Confirmation, Labelling, TableAnswer,
    TableError, Variant,
};
use std::sync::OnceLock;

const LINE4: &str = include_str!("../cells/line4.toml");
/// Small enough that building a bundle takes seconds.
const K: u32 = 16;

fn line4() -> Cell {
    parse_cell(LINE4).expect("cells/line4.toml")
}

/// `n` thesis robots `spacing` mm apart along x, then moved as a whole by `shift`.
fn line(n: usize, spacing: f64, shift: Vec3) -> Cell {
    let mut cell = line4();
    let robot = cell.robots[0].clone();
    cell.robots = (0..n)
        .map(|j| {
            let t = Vec3::new(spacing * j as f64, 0.0, 0.0) + shift;
            let mut r = robot.clone();
            (r.name, r.placement) = (format!("R{}", j + 1), Placement { alpha: 0.0, t });
            r
        })
        .collect();
    cell.stops = vec![cell.stops[0]; n];
    cell
}

/// Three robots neither equally spaced nor aligned nor facing alike: the rotation of the
/// relative placement matters.
fn skewed() -> Cell {
    let mut cell = line(3, 450.0, Vec3::zeros());
    cell.robots[1].placement =
        Placement { alpha: std::f64::consts::FRAC_PI_6, t: Vec3::new(430.0, 150.0, 0.0) };
    cell.robots[2].placement = Placement { alpha: -0.9, t: Vec3::new(820.0, -120.0, 0.0) };
    cell
}

fn bundle_of(cell: &Cell) -> Vec<u8> {
    build_bundle(
        cell,
        K,
        &Workspace::THESIS,
        Variant::Shared,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap_or_else(|e| panic!("building the bundle of {}: {e}", cell.name))
    .bytes
}

fn line4_bundle() -> &'static [u8] {
    static B: OnceLock<Vec<u8>> = OnceLock::new();
    B.get_or_init(|| bundle_of(&line4()))
}

/// A small xorshift: the same configurations on every run.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// A TCP in (or a little beyond) the workspace, in its robot's MCS.
    fn tcp(&mut self) -> Vec3 {
        let (r, a) = (240.0 * self.next().sqrt(), std::f64::consts::TAU * self.next());
        Vec3::new(r * a.cos(), r * a.sin(), -360.0 - 180.0 * self.next())
    }
}

#[test]
fn a_line_needs_one_table_per_spacing_that_can_meet() {
    let (cells, pairs) = plan(&line4());
    assert_eq!(
        (cells.len(), pairs.len()),
        (3, 6),
        "spacings 450, 900 and 1350 mm; every pair of four"
    );
    for p in &pairs {
        assert_eq!(p.table, p.b - p.a - 1, "pair {p:?}: its table is its spacing's");
    }
    // Eight equally spaced robots: 18 pairs can meet (up to three bases apart), three tables.
    let (cells, pairs) = plan(&line(8, 450.0, Vec3::zeros()));
    assert_eq!((cells.len(), pairs.len()), (3, 18));
    // The bundle of four serves the line of eight, and a line of four moved as a whole.
    for cell in [line(8, 450.0, Vec3::zeros()), line(4, 450.0, Vec3::new(1000.0, -300.0, 0.0))] {
        let checker = BundleChecker::new(cell.clone(), line4_bundle(), Confirmation::Exact)
            .unwrap_or_else(|e| panic!("{} robots: {e}", cell.robots.len()));
        assert_eq!(checker.table_count(), 3);
    }
}

/// Every pair's label (no confirmation) against the exact model of the whole cell: never FREE
/// where that pair's boxes intersect; with the exact confirmation, every pair's answer is the
/// exact model's. Returns the colliding pair answers seen.
fn agrees_with_the_exact_model(
    cell: &Cell,
    bytes: &[u8],
    configurations: usize,
    seed: u64,
) -> usize {
    let mut labels =
        BundleChecker::new(cell.clone(), bytes, Confirmation::None).expect("bundle loads");
    let mut confirmed =
        BundleChecker::new(cell.clone(), bytes, Confirmation::Exact).expect("bundle loads");
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = Rng(seed);
    let (mut collisions, mut false_alarms) = (0, 0);
    let mut tcps = vec![Vec3::zeros(); cell.robots.len()];
    for i in 0..configurations {
        tcps.iter_mut().for_each(|t| *t = rng.tcp());
        let v = exact.check(&tcps).unwrap();
        let (l, c) = (labels.check(&tcps).unwrap(), confirmed.check(&tcps).unwrap());
        assert_eq!(labels.pairs().len(), v.pairs.len(), "one answer per pair that can meet");
        for ((pl, pc), pe) in labels.pairs().iter().zip(confirmed.pairs()).zip(&v.pairs) {
            assert_eq!((pl.a, pl.b), (pe.a, pe.b));
            let want = match pe.state {
                PairState::Collides(..) => TableAnswer::Collision,
                PairState::Free => TableAnswer::Free,
                PairState::Undecided => {
                    assert!(
                        matches!(pl.answer, TableAnswer::Unreachable(_)),
                        "configuration {i}: {tcps:?}"
                    );
                    continue;
                }
            };
            collisions += usize::from(want == TableAnswer::Collision);
            assert!(
                !(want == TableAnswer::Collision && pl.answer == TableAnswer::Free),
                "{}: pair {}-{} labelled FREE where the exact model collides: {tcps:?}",
                cell.name,
                pl.a,
                pl.b
            );
            false_alarms +=
                usize::from(want == TableAnswer::Free && pl.answer == TableAnswer::Collision);
            assert_eq!(
                pc.answer, want,
                "{}: confirmed pair {}-{} at {tcps:?}",
                cell.name, pc.a, pc.b
            );
        }
        let whole = match (v.unreachable_mask, v.collides()) {
            (0, true) => TableAnswer::Collision,
            (0, false) => TableAnswer::Free,
            (m, _) => TableAnswer::Unreachable(m),
        };
        assert_eq!(c, whole, "{}: configuration {i}", cell.name);
        assert!(!(l == TableAnswer::Free && whole == TableAnswer::Collision));
    }
    println!(
        "{}: {collisions} colliding pair answers, {false_alarms} false alarms of the labels",
        cell.name
    );
    assert!(
        false_alarms > 0,
        "the labels are coarser than the exact model, so the confirmation is exercised"
    );
    collisions
}

#[test]
fn each_pair_is_answered_where_it_stands() {
    let collisions =
        agrees_with_the_exact_model(&line4(), line4_bundle(), 100_000, 0x9e37_79b9_7f4a_7c15);
    assert!(collisions > 1000, "the configurations bring neighbours into contact: {collisions}");
    // The same tables serve a line moved as a whole.
    let moved = line(4, 450.0, Vec3::new(-2000.0, 730.0, 0.0));
    assert!(agrees_with_the_exact_model(&moved, line4_bundle(), 20_000, 7) > 100);
    // Rotated and offset robots: the relative placement's rotation is the table's.
    let skewed = skewed();
    let bytes = bundle_of(&skewed);
    assert!(agrees_with_the_exact_model(&skewed, &bytes, 100_000, 11) > 1000);
}

/// The bundle with its whole checksum recomputed after `edit`.
fn edited(edit: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let mut b = line4_bundle().to_vec();
    edit(&mut b);
    let n = b.len() - 8;
    let sum = delta_collide::table::format::fnv1a64(&b[..n]);
    b[n..].copy_from_slice(&sum.to_le_bytes());
    b
}

#[test]
fn a_damaged_bundle_is_a_specific_error() {
    let good = line4_bundle();
    let directory = 40 + 32 * 3 + 16 * 6;
    for len in (0..directory + 16).chain([good.len() / 2, good.len() - 9, good.len() - 1]) {
        let e = bundle_from_bytes(&good[..len]).unwrap_err();
        let ok = matches!(e, TableError::Truncated { .. })
            || (len < 8 && matches!(e, TableError::BadMagic { .. }));
        assert!(ok, "truncated to {len}: {e}");
    }
    for at in [20, 41, 60, directory + 3, directory + 500, good.len() - 20] {
        let mut b = good.to_vec();
        b[at] ^= 0x10;
        assert!(
            matches!(bundle_from_bytes(&b), Err(TableError::Corrupt { .. })),
            "bit flipped at {at}"
        );
    }
    // A table's byte changed with the whole checksum recomputed: the table's own catches it.
    let e = bundle_from_bytes(&edited(|b| b[directory + 300] ^= 1)).unwrap_err();
    assert!(e.to_string().contains("bundle table 0: checksum"), "{e}");
    let e = bundle_from_bytes(&edited(|b| {
        b[12..16].copy_from_slice(&(BUNDLE_VERSION + 1).to_le_bytes())
    }))
    .unwrap_err();
    assert_eq!(
        e,
        TableError::UnsupportedVersion { found: BUNDLE_VERSION + 1, supported: BUNDLE_VERSION }
    );
    let e = bundle_from_bytes(&edited(|b| b[8..12].reverse())).unwrap_err();
    assert_eq!(e, TableError::WrongEndianness);
    let e = bundle_from_bytes(&edited(|b| b[..8].copy_from_slice(b"DCBUNDLX"))).unwrap_err();
    assert!(matches!(e, TableError::BadMagic { .. }), "{e}");
    // A pair naming a table the bundle does not have.
    let e = bundle_from_bytes(&edited(|b| {
        b[40 + 96 + 8..40 + 96 + 12].copy_from_slice(&7u32.to_le_bytes())
    }))
    .unwrap_err();
    assert!(
        matches!(e, TableError::Corrupt { .. }) && e.to_string().contains("out of range"),
        "{e}"
    );
}

#[test]
fn a_bundle_for_another_spacing_or_without_a_pair_is_refused_naming_the_pair() {
    // The line 460 mm apart: the bundle's table for R1-R2 was built 450 mm apart.
    let e = BundleChecker::new(line(4, 460.0, Vec3::zeros()), line4_bundle(), Confirmation::Exact)
        .unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, TableError::WrongPair { .. }), "{text}");
    assert!(
        text.contains("R1-R2")
            && text.contains("placement.translation.x is 450")
            && text.contains("460"),
        "{text}"
    );
    assert!(text.contains("rebuild the bundle"), "{text}");
    // Without the table of the spacing 1350 mm (R1-R4): that pair is missing.
    let b = bundle_from_bytes(line4_bundle()).unwrap();
    let files: Vec<Vec<u8>> =
        b.tables[..2].iter().map(|(h, t)| delta_collide::table::to_bytes(t, h)).collect();
    let pairs: Vec<_> = b.pairs.iter().copied().filter(|p| p.table < 2).collect();
    let short = bundle_to_bytes(b.cell_fingerprint, 4, &files, &pairs).unwrap();
    let e = BundleChecker::new(line4(), &short, Confirmation::Exact).unwrap_err();
    let text = e.to_string();
    assert!(
        matches!(e, TableError::MissingPair { .. })
            && text.contains("R1-R4")
            && text.contains("1350"),
        "{text}"
    );
    // That bundle still serves a line of three.
    assert!(BundleChecker::new(line(3, 450.0, Vec3::zeros()), &short, Confirmation::Exact).is_ok());
}

/// `delta-collide` with `args`; panics with its stderr unless it succeeds. Returns stdout.
fn cli(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_delta-collide"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run delta-collide");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// `build` on the line writes one bundle, `inspect` lists its pairs and their tables, and
/// `check --table BUNDLE --confirm exact` answers row for row (with every pair's column) as
/// `check` without a table: on both line cases, tick by tick, and on random rows with
/// unreachable TCPs.
#[test]
fn build_inspect_and_check_a_line_with_its_bundle() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bundles_cli");
    std::fs::create_dir_all(&dir).unwrap();
    let bundle = dir.join("line4.dcb");
    let b = bundle.to_str().unwrap();
    let built = cli(&[
        "-q",
        "build",
        "--cell",
        "cells/line4.toml",
        "--k",
        "16",
        "--variant",
        "shared",
        "--output",
        b,
    ]);
    assert!(built.contains("6 pairs that can meet, 3 tables"), "{built}");
    assert_eq!(
        std::fs::read(&bundle).unwrap(),
        line4_bundle(),
        "the CLI writes the library's bundle"
    );
    let inspected = cli(&["inspect", b]);
    for (pair, table) in [("0-1", 0), ("0-2", 1), ("0-3", 2), ("1-2", 0), ("1-3", 1), ("2-3", 0)] {
        assert!(
            inspected.contains(&format!("pair robots {pair}: table {table}")),
            "{pair}: {inspected}"
        );
    }
    assert!(inspected.contains("second robot at (900, 0, 0) mm"), "{inspected}");
    let scenarios = delta_collide::cell::trajectory::parse_scenarios(include_str!(
        "../c_harness/line_scenarios.txt"
    ))
    .unwrap();
    let mut rows = String::from("x1,y1,z1,x2,y2,z2,x3,y3,z3,x4,y4,z4\n");
    let mut tcps = vec![Vec3::zeros(); 4];
    for s in &scenarios {
        for tick in 0..delta_collide::cell::trajectory::RUN_TICKS {
            s.tcps_at(tick, &mut tcps);
            rows += &tcps
                .iter()
                .map(|p| format!("{},{},{}", p.x, p.y, p.z))
                .collect::<Vec<_>>()
                .join(",");
            rows.push('\n');
        }
    }
    let mut rng = Rng(3);
    for _ in 0..20_000 {
        rows += &(0..4)
            .map(|_| rng.tcp())
            .map(|p| format!("{},{},{}", p.x, p.y, p.z))
            .collect::<Vec<_>>()
            .join(",");
        rows.push('\n');
    }
    let input = dir.join("rows.csv");
    std::fs::write(&input, rows).unwrap();
    let i = input.to_str().unwrap();
    let exact = cli(&["check", "--cell", "cells/line4.toml", "--input", i, "--pairs"]);
    let table = cli(&[
        "check",
        "--cell",
        "cells/line4.toml",
        "--table",
        b,
        "--confirm",
        "exact",
        "--input",
        i,
        "--pairs",
    ]);
    let labels = cli(&[
        "check",
        "--cell",
        "cells/line4.toml",
        "--table",
        b,
        "--confirm",
        "none",
        "--input",
        i,
        "--pairs",
    ]);
    let count = |text: &str, what: &str| text.lines().filter(|l| l.starts_with(what)).count();
    assert_eq!(exact.lines().count(), 1 + 12_000 + 20_000);
    assert!(
        count(&exact, "1,1") > 1000 && count(&exact, "1,0") > 1000 && count(&exact, "0,NA") > 1000,
        "every outcome"
    );
    for (n, (e, t)) in exact.lines().zip(table.lines()).enumerate() {
        assert_eq!(t, e, "row {n}: the bundle confirmed answers as exact mode");
    }
    assert!(count(&labels, "1,1") > count(&exact, "1,1"), "the labels alone stop early somewhere");
}

/// `eval --pairs` on the line: per scenario and for the random configurations, the whole
/// tick's and each pair's counts; on the scenarios each pair's TP and FP as counted here from
/// the library's labels and the exact model, and no FN anywhere.
#[test]
fn eval_counts_every_pair_of_a_line() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bundles_eval");
    std::fs::create_dir_all(&dir).unwrap();
    let bundle = dir.join("line4.dcb");
    std::fs::write(&bundle, line4_bundle()).unwrap();
    let b = bundle.to_str().unwrap();
    let out =
        cli(&["eval", "--cell", "cells/line4.toml", "--table", b, "--random", "3000", "--pairs"]);
    assert!(out.contains("6 pairs that can meet, 3 tables"), "{out}");
    let field = |line: &str, name: &str| -> u64 {
        let words: Vec<&str> = line.split_whitespace().collect();
        let at =
            words.iter().position(|w| *w == name).unwrap_or_else(|| panic!("{name} in {line}"));
        words[at + 1].parse().unwrap()
    };
    let counted: Vec<&str> = out.lines().filter(|l| l.contains(" TP ")).collect();
    assert_eq!(
        counted.len(),
        3 * 7,
        "practical, collision, random: the tick and six pairs each\n{out}"
    );
    assert!(counted.iter().all(|l| field(l, "FN") == 0), "{out}");
    let mut labels = BundleChecker::new(line4(), line4_bundle(), Confirmation::None).unwrap();
    let mut exact = ExactChecker::new(line4());
    let scenarios = delta_collide::cell::trajectory::parse_scenarios(include_str!(
        "../c_harness/line_scenarios.txt"
    ))
    .unwrap();
    let mut tcps = vec![Vec3::zeros(); 4];
    for (s, block) in scenarios.iter().zip(counted.chunks(7)) {
        assert!(block[0].starts_with(&format!("line4 {}", s.case)), "{}", block[0]);
        let (mut tp, mut fp) = ([0u64; 6], [0u64; 6]);
        for tick in 0..delta_collide::cell::trajectory::RUN_TICKS {
            s.tcps_at(tick, &mut tcps);
            labels.check(&tcps).unwrap();
            let v = exact.check(&tcps).unwrap();
            for (k, (p, e)) in labels.pairs().iter().zip(&v.pairs).enumerate() {
                let hit = matches!(e.state, PairState::Collides(..));
                tp[k] += u64::from(p.answer == TableAnswer::Collision && hit);
                fp[k] += u64::from(p.answer == TableAnswer::Collision && !hit);
            }
        }
        for (k, line) in block[1..].iter().enumerate() {
            assert_eq!((field(line, "TP"), field(line, "FP")), (tp[k], fp[k]), "{line}");
        }
    }
}

/// `replay --table` on the line with the bundle of its clearance tables (stiff stopping
/// models, so that the lookups can prove far pairs): one row per tick with the verdicts of
/// exact mode or better (never a STOP where exact mode has none), the exact clearance in both,
/// and the pairs the lookups proved reported on stderr. Kept proofs settle nearly every tick
/// of this run before any lookup (the graded axes prove the line's pairs apart), so only a
/// few lookups are asked.
#[test]
fn replay_a_line_in_table_mode() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bundles_replay");
    std::fs::create_dir_all(&dir).unwrap();
    let variant = Variant::Clearance(delta_collide::table::Ladder::default_ladder());
    let built = build_bundle(
        &line4(),
        K,
        &Workspace::THESIS,
        variant,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    let bundle = dir.join("line4-clearance.dcb");
    std::fs::write(&bundle, &built.bytes).unwrap();
    let stop = "stop = { reaction_ms = 2.0, decel_mm_s2 = 120000.0, max_accel_mm_s2 = 130000.0, max_speed_mm_s = 4600.0 }";
    let cell = LINE4.replace("\n[[robot]]", &format!("\n[[robot]]\n{stop}"));
    let cell = format!("tick_ms = 1.0\n{cell}");
    let cell_path = dir.join("line4-stiff.toml");
    std::fs::write(&cell_path, &cell).unwrap();
    let scenario = &delta_collide::cell::trajectory::parse_scenarios(include_str!(
        "../c_harness/line_scenarios.txt"
    ))
    .unwrap()[0];
    let mut rows = String::from("tick,x,y,z,x2,y2,z2,x3,y3,z3,x4,y4,z4\n");
    let mut tcps = vec![Vec3::zeros(); 4];
    for tick in 0..6_000 {
        scenario.tcps_at(tick, &mut tcps);
        rows += &format!("{tick},");
        rows +=
            &tcps.iter().map(|p| format!("{},{},{}", p.x, p.y, p.z)).collect::<Vec<_>>().join(",");
        rows.push('\n');
    }
    let input = dir.join("line.csv");
    std::fs::write(&input, rows).unwrap();
    let (c, i, b) =
        (cell_path.to_str().unwrap(), input.to_str().unwrap(), bundle.to_str().unwrap());
    let exact = cli(&["replay", "--cell", c, "--input", i]);
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_delta-collide"))
        .args(["replay", "--cell", c, "--input", i, "--table", b])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let (table, note) =
        (String::from_utf8(run.stdout).unwrap(), String::from_utf8(run.stderr).unwrap());
    assert_eq!(table.lines().count(), 1 + 6_000);
    let mut stops = [0; 2];
    for (e, t) in exact.lines().zip(table.lines()).skip(1) {
        let (e, t): (Vec<&str>, Vec<&str>) = (e.split(',').collect(), t.split(',').collect());
        assert_eq!((e[0], e[2]), (t[0], t[2]), "tick and exact clearance");
        stops[0] += usize::from(e[1] == "stop");
        stops[1] += usize::from(t[1] == "stop");
        assert!(
            t[1] != "stop" || e[1] == "stop",
            "table mode stops at tick {} where exact mode does not",
            t[0]
        );
    }
    assert!(stops[0] > 0, "the line's neighbours come close enough to stop");
    let pairs: usize = note
        .split("answered FREE by the lookup alone, ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{note}"));
    assert!(pairs > 0, "{note}");
}
