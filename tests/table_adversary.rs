//! An adversary against the certified labels (SPEC §6) where they are hardest to keep.
//! `tests/table_guarantee.rs` checks a million random configurations; few of them land in the
//! FREE regions that border collisions. Here a search looks, inside such regions, for the
//! configuration of the two robots with the least exact signed clearance, and none may
//! collide:
//! - the sub-cells proved free inside cell pairs labelled collision (level 3 of the
//!   labelling: the free parts of pairs that do collide somewhere), drawn at random;
//! - the cell pairs labelled free whose centres are closest, among many drawn at random.
//!
//! A region is a 6-D box: each robot's TCP anywhere in its cube (a cell of side `r`, or an
//! octant of side `r / 2`, pulled in by 1e-9 mm), unreachable TCPs left out. The search is the
//! protective adversary's (1+1) evolution strategy (`tests/protective_common/adversary.rs`)
//! from the centre and three random starts, over six numbers whose sines place the TCPs in
//! their cubes (so that no step leaves the region). That it has teeth is asserted too: in
//! sub-cells left collision it finds colliding configurations.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{label_space_subdivided, CertifiedSpace, Label, Progress, Workspace};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::RobotBoxes;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

mod protective_common;
use protective_common::adversary::{clearance_at, descend};

const K: u32 = 16;

/// The bit of sub-cell (A's octant `i`, B's octant `j`) in a mask, as `SubCells` documents
/// it: `ax << 5 | ay << 4 | az << 3 | bx << 2 | by << 1 | bz`, an octant's bit set for the
/// upper half of its cube along that axis.
fn sub_cell_bit(i: usize, j: usize) -> u64 {
    let b = |o: usize, axis: usize| (o >> axis & 1) as u64;
    1 << (b(i, 0) << 5 | b(i, 1) << 4 | b(i, 2) << 3 | b(j, 0) << 2 | b(j, 1) << 1 | b(j, 2))
}

/// Evaluations per start of the search: 200, or `ADVERSARY_EVALUATIONS`.
fn evaluations() -> usize {
    std::env::var("ADVERSARY_EVALUATIONS")
        .map_or(200, |v| v.parse().expect("ADVERSARY_EVALUATIONS: a count"))
}

/// One region: each robot's cube (centre, half-side), MCS.
#[derive(Clone, Copy, Debug)]
struct Region {
    a: (Vec3, Real),
    b: (Vec3, Real),
}

/// The exact clearance of the robots at TCPs inside a region, `+inf` where a TCP is
/// unreachable.
struct Objective {
    exact: ExactChecker,
    boxes: [RobotBoxes; 2],
}

impl Objective {
    fn tcps(r: &Region, x: &[Real; 6]) -> [Vec3; 2] {
        let at = |(c, h): (Vec3, Real), o: usize| {
            c + Vec3::new(x[o], x[o + 1], x[o + 2]).map(|t| t.sin() * h)
        };
        [at(r.a, 0), at(r.b, 3)]
    }

    fn clearance(&mut self, r: &Region, x: &[Real; 6]) -> Real {
        clearance_at(&self.exact, &mut self.boxes, &Self::tcps(r, x))
    }
}

/// The least clearance found in `region` and the TCPs there.
fn worst_in(f: &mut Objective, region: &Region, rng: &mut StdRng) -> (Real, [Vec3; 2]) {
    let mut worst = (Real::INFINITY, [0.0; 6]);
    for start in 0..4 {
        let x: Vec<Real> =
            (0..6).map(|_| if start == 0 { 0.0 } else { rng.random_range(-1.0..1.0) }).collect();
        let (best, x) =
            descend(|x| f.clearance(region, &std::array::from_fn(|i| x[i])), x, evaluations(), rng);
        if best < worst.0 {
            worst = (best, std::array::from_fn(|i| x[i]));
        }
    }
    (worst.0, Objective::tcps(region, &worst.1))
}

/// The regions to search: free sub-cells of pairs labelled collision (`free_subs` of them)
/// and sub-cells left collision (`stop_subs`), then the free cell pairs with the closest
/// centres (`close` of `drawn`).
fn regions(
    space: &CertifiedSpace,
    cell: &Cell,
    rng: &mut StdRng,
) -> (Vec<Region>, Vec<Region>, Vec<Region>) {
    let s = &space.space;
    let (ga, gb) = (&s.grid_a, &s.grid_b);
    let nb = gb.cells.len() as u64;
    let (cell_half, oct_half) = (0.5 * ga.r - 1e-9, 0.25 * ga.r - 1e-9);
    let octant = |c: Vec3, o: usize| {
        c + Vec3::from_fn(|a, _| if o >> a & 1 == 1 { 0.25 * ga.r } else { -0.25 * ga.r })
    };
    let sub = space.sub.as_ref().expect("subdivided labels");
    let (mut free, mut stop) = (Vec::new(), Vec::new());
    for _ in 0..200_000 {
        if free.len() >= 1500 && stop.len() >= 300 {
            break;
        }
        let n = rng.random_range(0..sub.pairs.len());
        let (pair, care, collision) = (sub.pairs[n], sub.care[n], sub.collision[n]);
        let (i, j) = (rng.random_range(0..8usize), rng.random_range(0..8usize));
        let bit = sub_cell_bit(i, j);
        if care & bit == 0 {
            continue;
        }
        let (ca, cb) =
            (ga.sample_center((pair / nb) as usize), gb.sample_center((pair % nb) as usize));
        let region = Region { a: (octant(ca, i), oct_half), b: (octant(cb, j), oct_half) };
        match (collision & bit != 0, free.len() < 1500, stop.len() < 300) {
            (false, true, _) => free.push(region),
            (true, _, true) => stop.push(region),
            _ => {}
        }
    }
    // The free cell pairs whose centres are closest, among 200,000 drawn.
    let mut f = Objective {
        exact: ExactChecker::new(cell.clone()),
        boxes: [RobotBoxes::empty(), RobotBoxes::empty()],
    };
    let mut drawn: Vec<(Real, Region)> = (0..200_000)
        .filter_map(|_| {
            let i = rng.random_range(0..s.labels.len());
            (s.labels[i] == Label::Free).then(|| {
                let (ca, cb) =
                    (ga.sample_center(i / nb as usize), gb.sample_center(i % nb as usize));
                let region = Region { a: (ca, cell_half), b: (cb, cell_half) };
                (f.clearance(&region, &[0.0; 6]), region)
            })
        })
        .collect();
    drawn.sort_by(|x, y| x.0.total_cmp(&y.0));
    let close = drawn.into_iter().take(1000).map(|(_, r)| r).collect();
    (free, stop, close)
}

/// The least clearance over the regions (panics at a collision when `free`), and how many
/// collide.
fn search(cell: &Cell, regions: &[Region], free: bool, seed: u64) -> (Real, usize) {
    regions
        .par_iter()
        .enumerate()
        .map_init(
            || Objective {
                exact: ExactChecker::new(cell.clone()),
                boxes: [RobotBoxes::empty(), RobotBoxes::empty()],
            },
            |f, (n, region)| {
                let mut rng = StdRng::seed_from_u64(seed * 1_000_003 + n as u64);
                let (least, tcps) = worst_in(f, region, &mut rng);
                let v = f.exact.check(&tcps).unwrap();
                let collides = v.all_reachable() && v.collides();
                assert!(
                    !free || (least > 0.0 && !collides),
                    "a region labelled free holds a configuration with clearance {least} mm: \
                     TCPs {tcps:?} in {region:?}"
                );
                (least, usize::from(collides))
            },
        )
        .reduce(|| (Real::INFINITY, 0), |a, b| (a.0.min(b.0), a.1 + b.1))
}

fn check_cell(name: &str, seed: u64) {
    let cell = reference_cell(name).unwrap();
    let space = label_space_subdivided(&cell, K, &Workspace::THESIS, Progress::Silent).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let (free, stop, close) = regions(&space, &cell, &mut rng);
    let (free_least, _) = search(&cell, &free, true, seed);
    let (close_least, _) = search(&cell, &close, true, seed + 1);
    let (_, touched) = search(&cell, &stop, false, seed + 2);
    println!(
        "{name}, k = {K}: {} free sub-cells of collision pairs, least clearance found {free_least:.3} mm; \
         {} closest free cell pairs, {close_least:.3} mm; {touched} of {} sub-cells left collision collide",
        free.len(),
        close.len(),
        stop.len()
    );
    assert!(
        free.len() >= 500 && close.len() >= 500,
        "too few regions: {} {}",
        free.len(),
        close.len()
    );
    assert!(
        touched * 4 >= stop.len(),
        "the search finds too few collisions: {touched} of {}",
        stop.len()
    );
}

#[test]
fn t1_no_configuration_in_a_free_region_collides() {
    check_cell("T1", 11);
}

#[test]
fn t2_no_configuration_in_a_free_region_collides() {
    check_cell("T2", 12);
}

#[test]
fn t3_no_configuration_in_a_free_region_collides() {
    check_cell("T3", 13);
}
