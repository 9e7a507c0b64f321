//! The exact check of a cell: every robot pair that can meet, every box pair, with the
//! separating axis test (thesis 3.1, 3.1.4; SPEC §3).
//!
//! Per tick: one inverse kinematics and one box model per robot (each in its MCS, then moved
//! to the WCS), then for every pair an axis-aligned bounding-box test of the two robots'
//! boxes before the box-pair tests. All buffers live in the checker: a check never allocates.

use crate::cell::{Cell, SatMethod};
use crate::geometry::{first_intersecting_pair, Obb, WitnessCache};
use crate::math::{max_or_nan, min_or_nan, Mat3, Vec3};
use crate::robot::{RobotBoxes, Unreachable};
use alloc::{vec, vec::Vec};

/// What the check found for one robot pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairState {
    /// The robots' boxes do not intersect.
    Free,
    /// Box `.0` of robot `a` intersects box `.1` of robot `b`.
    Collides(usize, usize),
    /// A TCP of the pair is unreachable: no answer.
    Undecided,
}

/// One robot pair's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairVerdict {
    /// First robot (index in the cell), `a < b`.
    pub a: usize,
    /// Second robot.
    pub b: usize,
    /// The result.
    pub state: PairState,
}

/// The result of one check: reachability per robot and a state per pair that can meet.
#[derive(Clone, Debug, PartialEq)]
pub struct CellVerdict {
    /// Bit `j` set: robot `j`'s TCP is unreachable (or not finite).
    pub unreachable_mask: u32,
    /// The first unreachable robot and why.
    pub first_unreachable: Option<(usize, Unreachable)>,
    /// One entry per pair that can meet, in the order of [`Cell::pairs_that_can_meet`].
    pub pairs: Vec<PairVerdict>,
}

impl CellVerdict {
    /// Whether every TCP was reachable (so every pair has an answer).
    pub fn all_reachable(&self) -> bool {
        self.unreachable_mask == 0
    }

    /// The first colliding pair, if any.
    pub fn first_collision(&self) -> Option<&PairVerdict> {
        self.pairs.iter().find(|p| matches!(p.state, PairState::Collides(..)))
    }

    /// Whether any pair collides.
    pub fn collides(&self) -> bool {
        self.first_collision().is_some()
    }

    /// How many pairs collide.
    pub fn colliding_pairs(&self) -> usize {
        self.pairs.iter().filter(|p| matches!(p.state, PairState::Collides(..))).count()
    }
}

/// Why a check could not run at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QueryError {
    /// The number of TCPs differs from the number of robots.
    WrongRobotCount {
        /// Robots in the cell.
        expected: usize,
        /// TCPs given.
        found: usize,
    },
}

impl core::fmt::Display for QueryError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            QueryError::WrongRobotCount { expected, found } => {
                write!(f, "the cell has {expected} robots but {found} TCPs were given")
            }
        }
    }
}

impl core::error::Error for QueryError {}

/// The exact check of one cell, with every per-tick buffer preallocated.
#[derive(Clone, Debug)]
pub struct ExactChecker {
    cell: Cell,
    /// Robots placed at the WCS origin without rotation skip the box transform.
    at_origin: Vec<bool>,
    /// Robots placed without rotation (`alpha == 0`, a line along a conveyor) only have their
    /// boxes' centres moved: their rotation is the identity exactly (`sin 0 = 0`, `cos 0 = 1`),
    /// so the product with it gives back every finite axis and centre as they are, and the
    /// centre plus `t` is what the full transform computes.
    translated_only: Vec<bool>,
    /// Per robot, the rotation of its placement (MCS to WCS): fixed, so its sine and cosine
    /// are taken once here rather than every tick.
    rotations: Vec<Mat3>,
    boxes: Vec<RobotBoxes>,
    /// Per robot: centre and half-extents of the AABB of all its boxes (WCS).
    aabb: Vec<(Vec3, Vec3)>,
    caches: Vec<WitnessCache>,
    verdict: CellVerdict,
}

impl ExactChecker {
    /// A checker for `cell`; prunes, once, the robot pairs that can never meet.
    pub fn new(cell: Cell) -> Self {
        let n = cell.robots.len();
        let pairs: Vec<PairVerdict> = cell
            .pairs_that_can_meet()
            .into_iter()
            .map(|(a, b)| PairVerdict { a, b, state: PairState::Undecided })
            .collect();
        ExactChecker {
            at_origin: cell
                .robots
                .iter()
                .map(|r| r.placement.alpha == 0.0 && r.placement.t == Vec3::zeros())
                .collect(),
            translated_only: cell.robots.iter().map(|r| r.placement.alpha == 0.0).collect(),
            rotations: cell.robots.iter().map(|r| r.placement.rotation()).collect(),
            boxes: vec![RobotBoxes::empty(); n],
            aabb: vec![(Vec3::zeros(), Vec3::zeros()); n],
            caches: vec![WitnessCache::new(); pairs.len()],
            verdict: CellVerdict { unreachable_mask: 0, first_unreachable: None, pairs },
            cell,
        }
    }

    /// The cell being checked.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }

    /// Robot `i`'s placement rotation (MCS to WCS), computed once: the same matrix as
    /// `placement.rotation()`.
    pub fn rotation(&self, i: usize) -> &Mat3 {
        &self.rotations[i]
    }

    /// Robot `i`'s boxes for the TCP `tcp_mcs` (its MCS) moved to the WCS by the full placement
    /// transform, into `out`: what the protective check measures its sweeps from, at points
    /// other than the TCP now (ball centres, kept balls, path pieces).
    ///
    /// # Errors
    /// Why the TCP is unreachable (`out` then holds no usable boxes).
    pub fn boxes_in_wcs(
        &self,
        i: usize,
        tcp_mcs: &Vec3,
        out: &mut RobotBoxes,
    ) -> Result<(), Unreachable> {
        let robot = &self.cell.robots[i];
        robot.model.boxes_into(tcp_mcs, out)?;
        for b in &mut out.boxes[..out.len] {
            *b = b.transformed(&self.rotations[i], &robot.placement.t);
        }
        Ok(())
    }

    /// Robot `i`'s boxes in the WCS as of the last check (meaningless if it was unreachable).
    pub fn boxes(&self, i: usize) -> &RobotBoxes {
        &self.boxes[i]
    }

    /// The result of the last check (all pairs undecided before the first).
    pub fn verdict(&self) -> &CellVerdict {
        &self.verdict
    }

    /// Checks one configuration: `tcps_mcs[j]` is robot `j`'s TCP in its own MCS.
    ///
    /// Unreachable or non-finite TCPs are reported in the verdict (their pairs are
    /// [`PairState::Undecided`]), not as errors.
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] when `tcps_mcs.len()` differs from the robot count.
    pub fn check(&mut self, tcps_mcs: &[Vec3]) -> Result<&CellVerdict, QueryError> {
        // The loop below sets every pair's state: no need to mark them undecided first.
        self.place(tcps_mcs, true)?;
        for (k, pair) in self.verdict.pairs.iter_mut().enumerate() {
            let (a, b) = (pair.a, pair.b);
            pair.state = if self.verdict.unreachable_mask & (1 << a | 1 << b) != 0 {
                PairState::Undecided
            } else {
                let robot =
                    |j: usize| RobotInWcs { boxes: self.boxes[j].as_slice(), aabb: &self.aabb[j] };
                let cache = match self.cell.method {
                    SatMethod::Sat => None,
                    SatMethod::SatCache => Some(&mut self.caches[k]),
                };
                pair_state(&robot(a), &robot(b), cache)
            };
        }
        Ok(&self.verdict)
    }

    /// The first half of [`ExactChecker::check`]: every robot's boxes in the WCS and which
    /// TCPs are unreachable, with every pair left [`PairState::Undecided`] (for callers that
    /// measure the boxes' clearance instead of testing them).
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] when `tcps_mcs.len()` differs from the robot count.
    pub fn place_boxes(&mut self, tcps_mcs: &[Vec3]) -> Result<&CellVerdict, QueryError> {
        // The AABBs serve only the pair tests, which this leaves out.
        self.place(tcps_mcs, false)?;
        self.verdict.pairs.iter_mut().for_each(|p| p.state = PairState::Undecided);
        Ok(&self.verdict)
    }

    /// Every robot's boxes in the WCS, which TCPs are unreachable, and with `aabbs` each
    /// reachable robot's AABB; the pair states are left as they were.
    fn place(&mut self, tcps_mcs: &[Vec3], aabbs: bool) -> Result<(), QueryError> {
        let n = self.cell.robots.len();
        if tcps_mcs.len() != n {
            return Err(QueryError::WrongRobotCount { expected: n, found: tcps_mcs.len() });
        }
        self.verdict.unreachable_mask = 0;
        self.verdict.first_unreachable = None;
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            let robot = &self.cell.robots[j];
            match robot.model.boxes_into(tcp, &mut self.boxes[j]) {
                Ok(()) => {
                    let boxes = &mut self.boxes[j];
                    if self.at_origin[j] {
                        // Already in the WCS.
                    } else if self.translated_only[j] {
                        // Non-finite boxes may differ here from the full transform (0 * inf is
                        // NaN there), but either way they are non-finite, which the pair test
                        // answers as colliding at the same first non-finite box.
                        let t = &robot.placement.t;
                        for b in &mut boxes.boxes[..boxes.len] {
                            b.center += t;
                        }
                    } else {
                        let (rot, t) = (&self.rotations[j], &robot.placement.t);
                        for b in &mut boxes.boxes[..boxes.len] {
                            *b = b.transformed(rot, t);
                        }
                    }
                    if aabbs {
                        self.aabb[j] = aabb_of(boxes);
                    }
                }
                Err(why) => {
                    self.verdict.unreachable_mask |= 1 << j;
                    self.verdict.first_unreachable.get_or_insert((j, why));
                }
            }
        }
        Ok(())
    }
}

/// One robot's boxes in the WCS and the AABB around them, as the pair test reads them.
#[derive(Clone, Copy, Debug)]
pub struct RobotInWcs<'a> {
    /// The boxes.
    pub boxes: &'a [Obb],
    /// Centre and half-extents of the AABB of all of them (from [`aabb_of`]: NaN-propagating).
    pub aabb: &'a (Vec3, Vec3),
}

/// The exact state of one robot pair: the AABB test, then the box tests (plain, or through the
/// witness `cache`).
///
/// Fails closed: a non-finite value in any box (a degenerate frame, an overflow) makes the
/// robot's AABB non-finite, and the pair is then reported colliding at its first non-finite
/// boxes without any test, since no comparison with a NaN can be trusted to say "apart".
pub fn pair_state(a: &RobotInWcs, b: &RobotInWcs, cache: Option<&mut WitnessCache>) -> PairState {
    let finite = |r: &RobotInWcs| r.aabb.0.iter().chain(r.aabb.1.iter()).all(|v| v.is_finite());
    if !(finite(a) && finite(b)) {
        return PairState::Collides(first_non_finite(a.boxes), first_non_finite(b.boxes));
    }
    if aabbs_apart(a.aabb, b.aabb) {
        return PairState::Free;
    }
    let hit = match cache {
        None => first_intersecting_pair(a.boxes, b.boxes),
        Some(cache) => cache.first_intersecting_pair(a.boxes, b.boxes),
    };
    hit.map_or(PairState::Free, |(i, j)| PairState::Collides(i, j))
}

/// The index of the first box holding a non-finite value (0 when all are finite).
fn first_non_finite(boxes: &[Obb]) -> usize {
    let finite =
        |b: &Obb| b.center.iter().chain(b.axes.iter()).chain(b.half.iter()).all(|v| v.is_finite());
    boxes.iter().position(|b| !finite(b)).unwrap_or(0)
}

/// Centre and half-extents of the axis-aligned box around all of a robot's boxes; NaN
/// when any box holds a NaN (see [`min_or_nan`]).
pub fn aabb_of(boxes: &RobotBoxes) -> (Vec3, Vec3) {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for b in boxes.as_slice() {
        let h = b.aabb_half();
        lo = lo.zip_map(&(b.center - h), min_or_nan);
        hi = hi.zip_map(&(b.center + h), max_or_nan);
    }
    ((lo + hi) * 0.5, (hi - lo) * 0.5)
}

/// Whether two AABBs given as (centre, half-extents) are apart on some world axis by more
/// than the rounding slack: only then is the pair free without its box tests.
///
/// Written as "some gap exceeds", so that a NaN anywhere (the comparison is then false) leaves
/// the pair to the box tests, which answer NaN as intersecting.
fn aabbs_apart(a: &(Vec3, Vec3), b: &(Vec3, Vec3)) -> bool {
    let d = (a.0 - b.0).abs();
    let r = a.1 + b.1;
    (0..3).any(|k| d[k] > r[k] * (1.0 + 1e-12) + 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Placement, RobotSpec};
    use crate::robot::RobotModel;
    use crate::test_rng::TestRng;

    fn row_of_robots(n: usize, spacing: f64, method: SatMethod) -> Cell {
        let robots = (0..n)
            .map(|i| RobotSpec {
                name: format!("R{i}"),
                model: RobotModel::THESIS,
                placement: Placement { alpha: 0.0, t: Vec3::new(spacing * i as f64, 0.0, 0.0) },
            })
            .collect();
        Cell::new("row".into(), robots, method).unwrap()
    }

    /// Robots placed without rotation have their boxes' centres moved, nothing else: value for
    /// value the boxes are those of the full rigid transform of the MCS boxes (rotation of the
    /// placement, then its translation), and so are the verdicts.
    #[test]
    fn unrotated_placements_give_the_full_transforms_boxes() {
        let robots = (0..4)
            .map(|i| RobotSpec {
                name: format!("R{i}"),
                model: RobotModel::THESIS,
                placement: Placement {
                    alpha: 0.0,
                    t: Vec3::new(450.0 * i as f64 + 0.37, -31.3 * i as f64, 0.0),
                },
            })
            .collect();
        let cell = Cell::new("row".into(), robots, SatMethod::SatCache).unwrap();
        let mut checker = ExactChecker::new(cell.clone());
        let (mut rng, mut collisions) = (TestRng(0x2545_f491_4f6c_dd1d), 0);
        for _ in 0..5_000 {
            let mut tcp =
                || Vec3::new(250.0 * rng.unit(), 250.0 * rng.unit(), -450.0 - 100.0 * rng.unit());
            let tcps: Vec<Vec3> = (0..4).map(|_| tcp()).collect();
            let verdict = checker.check(&tcps).unwrap().clone();
            collisions += verdict.colliding_pairs();
            for (j, (tcp, robot)) in tcps.iter().zip(&cell.robots).enumerate() {
                let Ok(mcs) = robot.model.boxes(tcp) else {
                    assert!(verdict.unreachable_mask >> j & 1 == 1);
                    continue;
                };
                let (rot, t) = (robot.placement.rotation(), robot.placement.t);
                let want: Vec<Obb> =
                    mcs.as_slice().iter().map(|b| b.transformed(&rot, &t)).collect();
                assert_eq!(checker.boxes(j).as_slice(), &want[..], "robot {j} at {tcp:?}");
            }
            for p in &verdict.pairs {
                if verdict.unreachable_mask & (1 << p.a | 1 << p.b) != 0 {
                    continue;
                }
                let boxes = |j: usize| {
                    let (rot, t) =
                        (cell.robots[j].placement.rotation(), cell.robots[j].placement.t);
                    let b = RobotModel::THESIS.boxes(&tcps[j]).unwrap();
                    b.as_slice().iter().map(|b| b.transformed(&rot, &t)).collect::<Vec<Obb>>()
                };
                let hit = first_intersecting_pair(&boxes(p.a), &boxes(p.b)).is_some();
                assert_eq!(
                    matches!(p.state, PairState::Collides(..)),
                    hit,
                    "pair {}-{} at {tcps:?}",
                    p.a,
                    p.b
                );
            }
        }
        assert!(collisions > 100, "{collisions} colliding pairs: the test must see some");
    }

    #[test]
    fn far_pairs_are_pruned_and_middle_robot_meets_one_neighbour() {
        assert_eq!(
            row_of_robots(3, 800.0, SatMethod::Sat).pairs_that_can_meet(),
            vec![(0, 1), (1, 2)]
        );
        let mut checker = ExactChecker::new(row_of_robots(3, 450.0, SatMethod::Sat));
        let home = Vec3::new(0.0, 0.0, -450.0);
        // Robot 1 reaches back toward robot 0 while robot 0 reaches forward: only (0, 1) meets.
        let v = checker
            .check(&[Vec3::new(180.0, 0.0, -450.0), Vec3::new(-180.0, 0.0, -450.0), home])
            .unwrap();
        assert!(v.all_reachable());
        let states: Vec<_> = v
            .pairs
            .iter()
            .map(|p| (p.a, p.b, matches!(p.state, PairState::Collides(..))))
            .collect();
        assert_eq!(states, vec![(0, 1, true), (0, 2, false), (1, 2, false)]);
    }

    #[test]
    fn unreachable_robot_leaves_its_pairs_undecided_and_wrong_count_is_an_error() {
        let mut checker = ExactChecker::new(row_of_robots(3, 450.0, SatMethod::SatCache));
        let home = Vec3::new(0.0, 0.0, -450.0);
        let v = checker.check(&[home, Vec3::new(0.0, 0.0, 100.0), home]).unwrap();
        assert_eq!(v.unreachable_mask, 0b010);
        assert!(v
            .pairs
            .iter()
            .filter(|p| p.a == 1 || p.b == 1)
            .all(|p| p.state == PairState::Undecided));
        assert_eq!(
            checker.check(&[home]).unwrap_err(),
            QueryError::WrongRobotCount { expected: 3, found: 1 }
        );
    }

    /// A NaN in any quantity between the TCP and the verdict (a motor cosine or sine, any
    /// scalar of any box, any AABB bound) never yields "free", with or without the cache.
    #[test]
    fn a_nan_anywhere_never_yields_free() {
        use crate::cell::reference::reference_cell;
        use crate::robot::{MotorCosSin, RobotModel};
        type BoxEdit<'a> = &'a dyn Fn(&mut [RobotBoxes; 2]);
        type AabbEdit<'a> = &'a dyn Fn(&mut [(Vec3, Vec3); 2]);
        let cell = reference_cell("T1").unwrap();
        let model = RobotModel::THESIS;
        let (rot, t) = (cell.robots[1].placement.rotation(), cell.robots[1].placement.t);
        // Far apart (free by the AABBs), close (free by the box tests) and colliding.
        let configs = [
            (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0)),
            (Vec3::new(60.0, 30.0, -420.0), Vec3::new(-60.0, -30.0, -430.0)),
            (Vec3::new(180.0, 0.0, -450.0), Vec3::new(-180.0, 0.0, -450.0)),
        ];
        let mut injected = 0;
        for (ta, tb) in configs {
            let ik = |p: &Vec3| model.delta.inverse_kinematics_cos_sin(p).unwrap();
            let sol = [ik(&ta), ik(&tb)];
            let mut check =
                |sol: &[MotorCosSin; 2], edit_boxes: BoxEdit, edit_aabb: AabbEdit, what: &str| {
                    let mut boxes = [
                        model.boxes_from_cos_sin(&ta, &sol[0]),
                        model.boxes_from_cos_sin(&tb, &sol[1]),
                    ];
                    for b in &mut boxes[1].boxes[..3] {
                        *b = b.transformed(&rot, &t);
                    }
                    edit_boxes(&mut boxes);
                    let mut aabb = [aabb_of(&boxes[0]), aabb_of(&boxes[1])];
                    edit_aabb(&mut aabb);
                    let robot =
                        |j: usize| RobotInWcs { boxes: boxes[j].as_slice(), aabb: &aabb[j] };
                    let mut cache = WitnessCache::new();
                    for state in [
                        pair_state(&robot(0), &robot(1), None),
                        pair_state(&robot(0), &robot(1), Some(&mut cache)),
                    ] {
                        assert_ne!(state, PairState::Free, "NaN in {what} at {ta:?} {tb:?}");
                    }
                    injected += 1;
                };
            for robot in 0..2 {
                for arm in 0..3 {
                    let (mut c, mut s) = (sol, sol);
                    c[robot].cos[arm] = f64::NAN;
                    s[robot].sin[arm] = f64::NAN;
                    check(&c, &|_| {}, &|_| {}, &format!("cos of robot {robot} motor {arm}"));
                    check(&s, &|_| {}, &|_| {}, &format!("sin of robot {robot} motor {arm}"));
                }
                for bi in 0..3 {
                    for k in 0..15 {
                        let edit = |boxes: &mut [RobotBoxes; 2]| {
                            let b = &mut boxes[robot].boxes[bi];
                            match k {
                                0..=2 => b.center[k] = f64::NAN,
                                3..=11 => b.axes[k - 3] = f64::NAN,
                                _ => b.half[k - 12] = f64::NAN,
                            }
                        };
                        check(
                            &sol,
                            &edit,
                            &|_| {},
                            &format!("scalar {k} of box {bi} of robot {robot}"),
                        );
                    }
                }
                for k in 0..6 {
                    let edit = |aabb: &mut [(Vec3, Vec3); 2]| {
                        if k < 3 {
                            aabb[robot].0[k] = f64::NAN
                        } else {
                            aabb[robot].1[k - 3] = f64::NAN
                        }
                    };
                    check(&sol, &|_| {}, &edit, &format!("AABB bound {k} of robot {robot}"));
                }
            }
        }
        assert_eq!(injected, 3 * 2 * (6 + 45 + 6));
    }

    #[test]
    fn cached_and_plain_checks_agree_along_a_sweep() {
        let mut plain = ExactChecker::new(row_of_robots(2, 450.0, SatMethod::Sat));
        let mut cached = ExactChecker::new(row_of_robots(2, 450.0, SatMethod::SatCache));
        let mut collisions = 0;
        for k in 0..2000 {
            let s = k as f64 / 2000.0;
            let tcps = [
                Vec3::new(-150.0 + 350.0 * s, 40.0 * s, -450.0),
                Vec3::new(150.0 - 350.0 * s, -30.0, -420.0),
            ];
            let p = plain.check(&tcps).unwrap().collides();
            assert_eq!(p, cached.check(&tcps).unwrap().collides(), "step {k}");
            collisions += p as usize;
        }
        assert!(collisions > 0 && collisions < 2000);
    }
}
