//! Certified clearance tables against the exact clearance (SPEC §8) on the reference cells:
//! the table's bound never exceeds the exact signed clearance, on 10,000,000 random
//! configurations per cell, and the configurations with a level are exactly those the
//! boolean certified table of the same labels calls free.
//!
//! Configurations are drawn inside the table's sampled grid cells, in four equal streams:
//! uniform grid cell pairs with a uniform point in each; and *near-contact* pairs (the grid
//! cell pairs whose level is the lowest or the next: their neighbours may collide) with a
//! uniform point, a point on a cell face, and a point at a cell corner. A configuration with
//! an unreachable TCP has no clearance: it is skipped and counted, and drawing goes on until
//! 10,000,000 reachable ones are checked.

use delta_collide::cell::protective::clearance_now;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{Progress, SampleGrid, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_tables, to_bytes, Labelling, Ladder, Table, TableAnswer, TableChecker, TableKind, Variant,
};

/// Configurations per reference cell.
const PER_CELL: u64 = 10_000_000;
/// Grid resolution: the tables build in seconds.
const K: u32 = 16;

/// splitmix64: a small seeded generator, one per thread.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Where in a grid cell a point is drawn.
#[derive(Clone, Copy)]
enum Spot {
    /// Uniform in the cell.
    Inside,
    /// On one face (a random axis at its lower or upper bound, a hair inside), else uniform.
    Face,
    /// At one of the 8 corners, a hair inside.
    Corner,
}

/// A point of `grid`'s cell `c` (MCS).
fn point_in(grid: &SampleGrid, c: [u16; 3], spot: Spot, rng: &mut Rng) -> Vec3 {
    let edge = |rng: &mut Rng| if rng.next_u64() & 1 == 0 { 1e-9 } else { 1.0 - 1e-9 };
    let face_axis = rng.below(3);
    let lo = grid.center(c) - Vec3::repeat(0.5 * grid.r);
    Vec3::from_fn(|a, _| {
        let u = match spot {
            Spot::Inside => rng.unit(),
            Spot::Face if a == face_axis => edge(rng),
            Spot::Face => rng.unit(),
            Spot::Corner => edge(rng),
        };
        lo[a] + u * grid.r
    })
}

/// What one run over a cell found.
#[derive(Default, Clone)]
struct Tally {
    /// Configurations per number of proved levels (index 0: no level).
    per_level: Vec<u64>,
    /// Per level: the smallest exact clearance minus the bound seen.
    slack: Vec<f64>,
    violations: u64,
    /// Level present but the boolean table says collision, or the reverse.
    free_set_mismatches: u64,
    unreachable: u64,
    first_violation: Option<String>,
}

impl Tally {
    fn new(levels: usize) -> Tally {
        Tally {
            per_level: vec![0; levels + 1],
            slack: vec![f64::INFINITY; levels + 1],
            ..Tally::default()
        }
    }

    fn merge(&mut self, o: &Tally) {
        self.per_level.iter_mut().zip(&o.per_level).for_each(|(a, b)| *a += b);
        self.slack.iter_mut().zip(&o.slack).for_each(|(a, b)| *a = a.min(*b));
        self.violations += o.violations;
        self.free_set_mismatches += o.free_set_mismatches;
        self.unreachable += o.unreachable;
        if self.first_violation.is_none() {
            self.first_violation.clone_from(&o.first_violation);
        }
    }
}

/// Both tables of `cell` at [`K`] from one labelling, loaded through their file bytes:
/// the clearance table and the boolean shared table. The clearance file is at most 3x the
/// boolean one (the size target of clearance tables).
fn checkers(cell: &Cell, ladder: Ladder) -> (TableChecker, TableChecker) {
    let variants = [Variant::Clearance(ladder), Variant::Shared];
    let (header, tables, _) = build_tables(
        cell,
        K,
        &Workspace::THESIS,
        &variants,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    assert_eq!(TableKind::of(&tables[0]), TableKind::Clearance);
    let files: Vec<Vec<u8>> = tables.iter().map(|t: &Table| to_bytes(t, &header)).collect();
    let (clearance, boolean) = (files[0].len(), files[1].len());
    assert!(clearance <= 3 * boolean, "clearance file {clearance} bytes, boolean {boolean}");
    let load = |bytes: &[u8]| TableChecker::new(cell.clone(), bytes).unwrap();
    (load(&files[0]), load(&files[1]))
}

/// Runs configurations from seed `seed` until `n` have both TCPs reachable, the `i`-th drawn
/// from stream `i % 4` (see the module doc).
#[allow(clippy::too_many_arguments)]
fn run(
    cell: &Cell,
    grids: &[SampleGrid; 2],
    near: &[(usize, usize)],
    clearance: &TableChecker,
    boolean: &TableChecker,
    n: u64,
    seed: u64,
) -> Tally {
    let table = clearance.table().as_clearance().unwrap();
    let ladder = table.ladder().mm().to_vec();
    let mut boolean = boolean.clone();
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = Rng(seed);
    let mut t = Tally::new(ladder.len());
    let (mut i, mut checked) = (0u64, 0u64);
    while checked < n {
        i += 1;
        let (stream, pick_near) = (i % 4, i % 4 != 0);
        let (ia, ib) = if pick_near {
            near[rng.below(near.len())]
        } else {
            (rng.below(grids[0].cells.len()), rng.below(grids[1].cells.len()))
        };
        let spot = [Spot::Inside, Spot::Inside, Spot::Face, Spot::Corner][stream as usize];
        let tcps = [
            point_in(&grids[0], grids[0].cells[ia], spot, &mut rng),
            point_in(&grids[1], grids[1].cells[ib], spot, &mut rng),
        ];
        let v = exact.check(&tcps).unwrap();
        if !v.all_reachable() {
            t.unreachable += 1;
            continue;
        }
        checked += 1;
        let bound = clearance.clearance_bound(&tcps);
        let level = bound.map_or(0, |b| 1 + ladder.iter().position(|&l| l == b).unwrap());
        t.per_level[level] += 1;
        let free = boolean.check(&tcps).unwrap() == TableAnswer::Free;
        t.free_set_mismatches += u64::from(free != bound.is_some());
        if let Some(b) = bound {
            let exact_mm = clearance_now(&exact).0;
            t.slack[level] = t.slack[level].min(exact_mm - b);
            // Written negated so that a NaN bound or clearance counts as a violation.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(b <= exact_mm) {
                t.violations += 1;
                if t.first_violation.is_none() {
                    t.first_violation =
                        Some(format!("bound {b} mm, exact {exact_mm} mm at {tcps:?}"));
                }
            }
        }
    }
    t
}

/// The grid cell pairs (sample indices) whose level is the lowest proved or the next.
fn near_contact(grids: &[SampleGrid; 2], table: &Table) -> Vec<(usize, usize)> {
    let t = table.as_clearance().unwrap();
    let mut out = Vec::new();
    for (ia, a) in grids[0].cells.iter().enumerate() {
        for (ib, b) in grids[1].cells.iter().enumerate() {
            if matches!(t.level_count([a[0], a[1], a[2], b[0], b[1], b[2]]), 1 | 2) {
                out.push((ia, ib));
            }
        }
    }
    out
}

/// The bound never exceeds the exact clearance, and has a level exactly where the boolean
/// table is free, on [`PER_CELL`] configurations of each reference cell.
#[test]
fn clearance_bound_never_exceeds_the_exact_clearance() {
    let ladder = Ladder::default_ladder();
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()).clamp(1, 8) as u64;
    for name in ["T1", "T2", "T3"] {
        let start = std::time::Instant::now();
        let cell = reference_cell(name).unwrap();
        let (clearance, boolean) = checkers(&cell, ladder);
        let grid =
            |j: usize| SampleGrid::new(&Workspace::THESIS, K, &cell.robots[j].model.delta).unwrap();
        let grids = [grid(0), grid(1)];
        let near = near_contact(&grids, clearance.table());
        assert!(near.len() > 1000, "{name}: {} near-contact pairs", near.len());
        let built = start.elapsed().as_secs_f64();
        let mut total = Tally::new(ladder.len());
        std::thread::scope(|s| {
            let runs: Vec<_> = (0..threads)
                .map(|j| {
                    let n = PER_CELL / threads + u64::from(j < PER_CELL % threads);
                    let (cell, grids, near, clearance, boolean) =
                        (&cell, &grids, &near, &clearance, &boolean);
                    s.spawn(move || {
                        run(cell, grids, near, clearance, boolean, n, 0x5eed ^ (j << 32))
                    })
                })
                .collect();
            runs.into_iter().for_each(|r| total.merge(&r.join().unwrap()));
        });
        let checked: u64 = total.per_level.iter().sum();
        eprintln!(
            "{name}: {PER_CELL} reachable configurations ({} unreachable skipped) in {:.1} s (tables {built:.1} s); per level \
             (none, {:?} mm): {:?}; smallest exact - bound per level: {:?}; violations {}; free-set mismatches {}",
            total.unreachable,
            start.elapsed().as_secs_f64(),
            ladder.mm(),
            total.per_level,
            total.slack,
            total.violations,
            total.free_set_mismatches
        );
        assert_eq!(checked, PER_CELL);
        assert_eq!(
            total.violations, 0,
            "{name}: the bound exceeds the exact clearance: {:?}",
            total.first_violation
        );
        assert_eq!(
            total.free_set_mismatches, 0,
            "{name}: levels and the boolean table's free set differ"
        );
        // The sample reaches every level the ladder has below the top, and the collisions.
        assert!(
            total.per_level[0] > 10_000,
            "{name}: few configurations without a level: {:?}",
            total.per_level
        );
        let levelled = total.per_level[1..ladder.len()].iter().filter(|&&c| c > 1000).count();
        assert!(levelled >= 4, "{name}: few levels reached: {:?}", total.per_level);
    }
}
