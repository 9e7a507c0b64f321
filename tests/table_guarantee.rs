//! The safety guarantee of a labelled configuration space (SPEC §6): over at
//! least a million random off-grid configurations per reference cell, the certified labels
//! never report free where the exact physical model (margin 0) collides. The thesis's global
//! blow-up `r / sqrt(2)` is measured the same way and its false negatives are printed, not
//! asserted (it is not a proof).
//!
//! The lookup is a plain array lookup on the [`LabelledSpace`]; the quadtrees are tested
//! elsewhere.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::cspace::symmetry::{grid_is_y_symmetric, mirror_cell, reflection_y};
use delta_collide::cspace::{
    label_space, label_space_certified, label_space_thesis, Label, LabelledSpace, Progress,
    Workspace,
};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::Delta3;
use rand::{rngs::StdRng, RngExt, SeedableRng};
use rayon::prelude::*;

const K: u32 = 32;
const CONFIGS: usize = 1_000_000;
const CHUNK: usize = 10_000;

/// A TCP drawn uniformly from the workspace volume (MCS), reachable by `delta`.
fn random_tcp(rng: &mut StdRng, ws: &Workspace, delta: &Delta3) -> Vec3 {
    let r = ws.max_radius();
    loop {
        let p = Vec3::new(
            rng.random_range(-r..=r),
            rng.random_range(-r..=r),
            -rng.random_range(ws.zu..=ws.max_depth()),
        );
        if ws.contains(&p) && delta.inverse_kinematics(&p).is_ok() {
            return p;
        }
    }
}

/// Table answer vs exact answer, with the table's "unreachable" kept apart.
#[derive(Clone, Copy, Debug, Default)]
struct Confusion {
    tp: u64,
    tn: u64,
    fp: u64,
    fn_: u64,
    /// Table says unreachable (centre unreachable), the exact model collides / is free.
    unreachable_collide: u64,
    unreachable_free: u64,
}

impl Confusion {
    fn add(mut self, o: Confusion) -> Confusion {
        self.tp += o.tp;
        self.tn += o.tn;
        self.fp += o.fp;
        self.fn_ += o.fn_;
        self.unreachable_collide += o.unreachable_collide;
        self.unreachable_free += o.unreachable_free;
        self
    }

    fn total(&self) -> u64 {
        self.tp + self.tn + self.fp + self.fn_ + self.unreachable_collide + self.unreachable_free
    }

    /// Accuracy with "unreachable" counted as a reported collision (the controller stops).
    fn accuracy(&self) -> f64 {
        (self.tp + self.tn + self.unreachable_collide) as f64 / self.total() as f64
    }

    fn print(&self, what: &str) {
        println!(
            "  {what:<28} TP {:>7}  TN {:>7}  FP {:>6}  FN {:>4}  unreachable(col/free) {}/{}  accuracy {:.2} %",
            self.tp,
            self.tn,
            self.fp,
            self.fn_,
            self.unreachable_collide,
            self.unreachable_free,
            100.0 * self.accuracy()
        );
    }
}

fn classify(label: Label, collides: bool) -> Confusion {
    let mut c = Confusion::default();
    match (label, collides) {
        (Label::Collision, true) => c.tp = 1,
        (Label::Collision, false) => c.fp = 1,
        (Label::Free, false) => c.tn = 1,
        (Label::Free, true) => c.fn_ = 1,
        (Label::Unreachable, true) => c.unreachable_collide = 1,
        (Label::Unreachable, false) => c.unreachable_free = 1,
    }
    c
}

/// A targeted search for the thesis margin's false negatives: the pairs it labels free with
/// the least clearance (collision once the margin grows by a quarter), checked at the 64
/// corners of their 6-D cell (pulled in by 1e-9 mm). Returns (pairs searched, pairs with a
/// colliding corner, example).
fn hunt_thesis_false_negatives(
    cell: &delta_collide::cell::Cell,
    thesis: &LabelledSpace,
    tighter: &LabelledSpace,
) -> (usize, usize, Option<(Vec3, Vec3)>) {
    let nb = thesis.grid_b.cells.len();
    let band: Vec<usize> = (0..thesis.labels.len())
        .filter(|&i| thesis.labels[i] == Label::Free && tighter.labels[i] == Label::Collision)
        .collect();
    let step = (band.len() / 4000).max(1);
    let picked: Vec<usize> = band.iter().step_by(step).copied().collect();
    let half = 0.5 * thesis.grid_a.r - 1e-9;
    let found: Vec<(Vec3, Vec3)> = picked
        .par_iter()
        .map_init(
            || ExactChecker::new(cell.clone()),
            |checker, &i| {
                let (ca, cb) =
                    (thesis.grid_a.sample_center(i / nb), thesis.grid_b.sample_center(i % nb));
                (0..64u32).find_map(|corner| {
                    let s = |bit: u32| if corner >> bit & 1 == 1 { half } else { -half };
                    let (pa, pb) =
                        (ca + Vec3::new(s(0), s(1), s(2)), cb + Vec3::new(s(3), s(4), s(5)));
                    let v = checker.check(&[pa, pb]).unwrap();
                    (v.all_reachable() && v.collides()).then_some((pa, pb))
                })
            },
        )
        .flatten()
        .collect();
    (picked.len(), found.len(), found.first().copied())
}

/// Random configurations of `cell`, each looked up in both labellings and checked exactly.
fn evaluate(name: &str, seed: u64) -> (Confusion, Confusion) {
    let cell = reference_cell(name).unwrap();
    let ws = Workspace::THESIS;
    let certified = label_space_certified(&cell, K, &ws, Progress::Silent).unwrap();
    let thesis = label_space_thesis(&cell, K, &ws, Progress::Silent).unwrap();
    let tighter = label_space(&cell, K, &ws, 1.25 * thesis.margin, Progress::Silent).unwrap();
    let (searched, bad, example) = hunt_thesis_false_negatives(&cell, &thesis, &tighter);
    println!(
        "{name}: thesis margin {:.3} mm vs certified bounds up to {:.3} mm; corner search over {searched} thesis-free pairs with the least clearance: {bad} collide at a corner (e.g. {example:?})",
        thesis.margin, certified.space.margin
    );
    let (da, db) = (cell.robots[0].model.delta, cell.robots[1].model.delta);
    let lookup = |s: &LabelledSpace, pa: &Vec3, pb: &Vec3| {
        let ia = s.grid_a.sample_of(pa).expect("every workspace point lies in a sampled cell of A");
        let ib = s.grid_b.sample_of(pb).expect("every workspace point lies in a sampled cell of B");
        s.label(ia, ib)
    };
    (0..CONFIGS / CHUNK)
        .into_par_iter()
        .map_init(
            || ExactChecker::new(cell.clone()),
            |checker, chunk| {
                let mut rng = StdRng::seed_from_u64(seed * 1_000_003 + chunk as u64);
                let (mut ours, mut theirs) = (Confusion::default(), Confusion::default());
                for _ in 0..CHUNK {
                    let (pa, pb) = (random_tcp(&mut rng, &ws, &da), random_tcp(&mut rng, &ws, &db));
                    let verdict = checker.check(&[pa, pb]).unwrap();
                    assert!(verdict.all_reachable());
                    let collides = verdict.collides();
                    let c = classify(lookup(&certified.space, &pa, &pb), collides);
                    if c.fn_ > 0 {
                        panic!("{name}: false negative at A {pa:?} B {pb:?} (certified labels said free)");
                    }
                    ours = ours.add(c);
                    theirs = theirs.add(classify(lookup(&thesis, &pa, &pb), collides));
                }
                (ours, theirs)
            },
        )
        .reduce(|| (Confusion::default(), Confusion::default()), |a, b| (a.0.add(b.0), a.1.add(b.1)))
}

fn check_cell(name: &str, seed: u64) {
    let (ours, theirs) = evaluate(name, seed);
    println!(
        "{name}, k = {K}, {CONFIGS} random reachable configurations vs the exact model (margin 0):"
    );
    ours.print("certified per-box bounds");
    theirs.print("thesis margin r/sqrt(2)");
    assert_eq!(ours.total(), CONFIGS as u64);
    assert_eq!(ours.fn_, 0, "{name}: certified labels gave false negatives");
    // Certified "unreachable" means the whole cell was proved unreachable: no reachable TCP
    // may land there.
    assert_eq!(
        ours.unreachable_collide + ours.unreachable_free,
        0,
        "{name}: a reachable TCP in a cell proved unreachable"
    );
    // The test must be able to fail: collisions and free configurations both occur, and the
    // certified labels are not trivially "collision everywhere".
    assert!(ours.tp > 1000 && ours.tn > CONFIGS as u64 / 4, "{ours:?}");
}

#[test]
fn t1_certified_labels_have_no_false_negatives() {
    check_cell("T1", 1);
}

#[test]
fn t2_certified_labels_have_no_false_negatives() {
    check_cell("T2", 2);
}

#[test]
fn t3_certified_labels_have_no_false_negatives() {
    check_cell("T3", 3);
}

/// Thesis 3.2.8 at k = 32: T1 is detected symmetric, its grids are y-symmetric, and every
/// certified label equals its mirror's.
#[test]
fn t1_certified_labels_are_mirror_symmetric_at_k32() {
    let cell = reference_cell("T1").unwrap();
    assert!(reflection_y(&cell));
    let s = label_space_certified(&cell, K, &Workspace::THESIS, Progress::Silent).unwrap().space;
    let (ga, gb) = (&s.grid_a, &s.grid_b);
    assert!(grid_is_y_symmetric(ga) && grid_is_y_symmetric(gb));
    let mb: Vec<usize> =
        gb.cells.iter().map(|&c| gb.index_of(mirror_cell(gb, c)).unwrap()).collect();
    let nb = gb.cells.len();
    let bad: usize = (0..ga.cells.len())
        .into_par_iter()
        .map(|ia| {
            let ma = ga.index_of(mirror_cell(ga, ga.cells[ia])).unwrap();
            (0..nb).filter(|&ib| s.labels[ia * nb + ib] != s.labels[ma * nb + mb[ib]]).count()
        })
        .sum();
    assert_eq!(bad, 0);
}

/// Sample counts and the share of the workspace volume that is unreachable (SPEC §4).
#[test]
fn sample_counts_and_unreachable_volume() {
    let ws = Workspace::THESIS;
    let d = Delta3::THESIS;
    for k in [16, 32, 64] {
        let g = delta_collide::cspace::SampleGrid::new(&ws, k, &d).unwrap();
        let n = g.cells.len();
        println!(
            "k = {k}: r = {:.4} mm, {n} samples per robot, {} reachable centres ({:.1} % unreachable), {} pairs",
            g.r,
            g.reachable_count(),
            100.0 * (1.0 - g.reachable_count() as Real / n as Real),
            n * n
        );
    }
    let mut rng = StdRng::seed_from_u64(7);
    let (mut inside, mut unreachable) = (0u32, 0u32);
    while inside < 200_000 {
        let r = ws.max_radius();
        let p = Vec3::new(
            rng.random_range(-r..=r),
            rng.random_range(-r..=r),
            -rng.random_range(ws.zu..=ws.max_depth()),
        );
        if ws.contains(&p) {
            inside += 1;
            unreachable += d.inverse_kinematics(&p).is_err() as u32;
        }
    }
    let share = unreachable as f64 / inside as f64;
    println!("unreachable share of the workspace volume: {:.1} %", 100.0 * share);
    assert!((0.08..0.16).contains(&share), "SPEC §4 says about 12 %: {share}");
}
