//! The clearance of two robots tick after tick, starting from what the last tick found
//! (temporal coherence, as Bullet's cached separating axes and Coal's cached GJK guesses do).
//!
//! Between two 1 ms ticks a box moves a few millimetres, so the closest features of a box pair
//! and the direction between them barely change. Two facts make that usable without losing
//! exactness:
//!
//! 1. **Any direction gives a lower bound.** For a unit `n`, the gap of the two boxes'
//!    projections on `n`, `n . (c_B - c_A) - sum_k a_k |n . A_k| - sum_l b_l |n . B_l|`, is at
//!    most the signed clearance (apart: no two points are closer than the slab between the
//!    projections; intersecting: the overlap on `n` is at least the smallest overlap over the
//!    15 axes, the penetration depth). A box pair whose gap along last tick's direction
//!    already reaches the smallest clearance found this tick cannot be the minimum: skipped,
//!    at the cost of seven dot products.
//! 2. **A pair of points with a matching gap is the distance.** Last tick's closest features
//!    (a vertex and its closest point of the other box, or two edges) give two points `p`, `q`
//!    of the boxes now, so the distance is at most `|q - p|`; the gap along
//!    `u = (q - p) / |q - p|` is at most the distance. When the gap reaches `|q - p|` (to the
//!    rounding slack of [`obb_clearance`]'s own shortcut), `|q - p|` is the distance. Otherwise,
//!    or for gaps under [`WARM_MIN_GAP`] (where the separating axis test's tolerances decide
//!    touching), the pair is computed from scratch by [`obb_clearance`].
//!
//! So every answer is [`boxes_clearance`]'s, to that rounding slack, whatever the memory
//! holds: a stale direction only costs a skipped pair being computed, a stale feature only a
//! computation from scratch. No allocation.
//!
//! [`obb_clearance`]: crate::geometry::clearance::obb_clearance

#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{
    boxes_clearance, edge_pair, finite, obb_clearance_with_feature, rel, sign, Best, Clearance,
    Feature, PairClearance, Rel, MAX_PAIRS, PARALLEL_NORM2,
};
use crate::geometry::obb::Obb;
use crate::math::{float, Real, Vec3};

/// Below this distance (mm) a warm start is not taken: the pair is computed from scratch, so
/// that touching and nearly touching boxes are decided by the separating axis test's own
/// tolerances, as in [`obb_clearance`](crate::geometry::clearance::obb_clearance).
pub const WARM_MIN_GAP: Real = 0.01;

/// The shortest distance between the witness points (mm) from which a pair keeps their
/// direction: far above the rounding of coordinates of a few metres (about 1e-12 mm).
const DIRECTION_MIN_MM: Real = 1e-6;

/// What one box pair's clearance was when last computed.
#[derive(Clone, Copy, Debug, Default)]
struct PairMemory {
    /// Unit direction from box A toward box B along which the gap was the clearance (world
    /// frame); zero when unknown.
    direction: Vec3,
    /// The features its closest points lay on.
    feature: Feature,
}

/// The clearance of one pair of robots, remembered from call to call
/// ([`CoherentClearance::boxes_clearance`]).
#[derive(Clone, Debug)]
pub struct CoherentClearance {
    pairs: [PairMemory; MAX_PAIRS],
    /// The box pair of the smallest clearance at the last call (`a` index times `b.len()`
    /// plus `b` index): computed first.
    closest: usize,
}

impl Default for CoherentClearance {
    fn default() -> Self {
        CoherentClearance { pairs: [PairMemory::default(); MAX_PAIRS], closest: 0 }
    }
}

impl CoherentClearance {
    /// An empty memory: the first call computes every pair not skipped by the cheaper bound.
    pub fn new() -> Self {
        Self::default()
    }

    /// The smallest signed clearance between a box of `a` and a box of `b`, and which pair:
    /// [`boxes_clearance`]'s answer, found from the last call's closest pair, directions and
    /// features (module doc). The slices should be the same robots' boxes from call to call
    /// (other boxes give the same answer, only slower). No allocation.
    pub fn boxes_clearance(&mut self, a: &[Obb], b: &[Obb]) -> PairClearance {
        let n = a.len().saturating_mul(b.len());
        if n > MAX_PAIRS {
            return boxes_clearance(a, b);
        }
        let m = b.len().max(1);
        let mut out = PairClearance::NONE;
        let first = if self.closest < n { self.closest } else { 0 };
        // Box pair `k = i m + l` is `(a[i], b[l])`; counted from `first`, wrapping, with the
        // two indices stepped along (an integer division per pair costs as much as its skip test).
        let (mut i, mut l) = (first / m, first % m);
        for _ in 0..n {
            let k = i * m + l;
            let (ba, bb) = (&a[i], &b[l]);
            let memory = &mut self.pairs[k];
            // NaN never skips: a box with a NaN is computed and shows as a NaN distance.
            let skip = memory.direction != Vec3::zeros()
                && gap_along(ba, bb, &memory.direction) >= out.distance;
            if !skip {
                let c = pair_clearance(ba, bb, memory);
                if !(c.distance >= out.distance) {
                    out = PairClearance::of(i, l, &c);
                    if c.distance.is_nan() {
                        break;
                    }
                }
            }
            l += 1;
            if l == m {
                l = 0;
                i = if i + 1 == a.len() { 0 } else { i + 1 };
            }
        }
        self.closest = out.box_a * m + out.box_b;
        out
    }
}

/// The gap of the projections of `a` and `b` on the unit direction `n` (A toward B), less
/// its rounding: never above the signed clearance (module doc, fact 1). NaN for NaN input.
#[inline(always)]
fn gap_along(a: &Obb, b: &Obb, n: &Vec3) -> Real {
    let centres = n.dot(&(b.center - a.center));
    let support = |o: &Obb| {
        o.half.x * n.dot(&o.axes.column(0)).abs()
            + o.half.y * n.dot(&o.axes.column(1)).abs()
            + o.half.z * n.dot(&o.axes.column(2)).abs()
    };
    let (sa, sb) = (support(a), support(b));
    centres - sa - sb - 1e-13 * (centres.abs() + sa + sb)
}

/// One box pair's clearance: from last time's features when they certify it, else from
/// scratch; the memory updated either way.
#[inline(always)]
fn pair_clearance(a: &Obb, b: &Obb, memory: &mut PairMemory) -> Clearance {
    if let Some((c, direction)) = warm(a, b, memory.feature) {
        // The warm start's unit direction between its points, turned to the world frame.
        memory.direction = direction;
        return c;
    }
    let (c, feature) = obb_clearance_with_feature(a, b);
    // Unit by construction: a gap along a longer vector would not be a lower bound. Where the
    // points are too close to give a direction (rounding of the coordinates), none is kept.
    let d = (c.point_b - c.point_a) * c.distance.signum();
    let length = d.norm();
    memory.direction =
        if length > DIRECTION_MIN_MM && length.is_finite() { d / length } else { Vec3::zeros() };
    memory.feature = feature;
    c
}

/// The clearance from the features `feature` when the gap along the direction between their
/// closest points certifies it (module doc, fact 2), with that unit direction in the world
/// frame (A's axes times the unit vector in A's frame: unit to rounding, and at least
/// [`WARM_MIN_GAP`] between the points, far above [`DIRECTION_MIN_MM`]); `None` otherwise.
#[inline(always)]
fn warm(a: &Obb, b: &Obb, feature: Feature) -> Option<(Clearance, Vec3)> {
    if feature == Feature::None || !finite(a, b) {
        return None;
    }
    let rel = rel(a, b);
    let best = feature_points(&rel, feature)?;
    let d = float::sqrt(best.d2);
    if !(d >= WARM_MIN_GAP) {
        return None;
    }
    let inv_d = 1.0 / d;
    let u: [Real; 3] = core::array::from_fn(|k| (best.q[k] - best.p[k]) * inv_d);
    let (r, t) = (&rel.r, &rel.t);
    let centres = u[0] * t[0] + u[1] * t[1] + u[2] * t[2];
    let sa = rel.a[0] * u[0].abs() + rel.a[1] * u[1].abs() + rel.a[2] * u[2].abs();
    let sb: Real =
        (0..3).map(|l| rel.b[l] * (u[0] * r[0][l] + u[1] * r[1][l] + u[2] * r[2][l]).abs()).sum();
    // The same slack as `separated`'s shortcut: the size of the problem times 1e-13.
    let size = rel.t.iter().chain(&rel.a).chain(&rel.b).map(|x| x.abs()).sum::<Real>();
    (d <= centres - sa - sb + 1e-13 * size)
        .then(|| (best.clearance(a), a.axes * Vec3::new(u[0], u[1], u[2])))
}

/// The closest points of the two features now (A's frame); `None` for edges now parallel.
#[inline(always)]
fn feature_points(rel: &Rel, feature: Feature) -> Option<Best> {
    let (r, t, tb, a, b) = (&rel.r, &rel.t, &rel.tb, &rel.a, &rel.b);
    match feature {
        Feature::None => None,
        Feature::VertexOfB(sg) => {
            let s = sg.map(Real::from);
            let q: [Real; 3] = core::array::from_fn(|k| {
                t[k] + s[0] * b[0] * r[k][0] + s[1] * b[1] * r[k][1] + s[2] * b[2] * r[k][2]
            });
            let p: [Real; 3] = core::array::from_fn(|k| q[k].clamp(-a[k], a[k]));
            let d2 = (0..3).map(|k| (q[k] - p[k]) * (q[k] - p[k])).sum();
            Some(Best { d2, p, q, feature })
        }
        Feature::VertexOfA(sg) => {
            let p: [Real; 3] = core::array::from_fn(|k| Real::from(sg[k]) * a[k]);
            let xb: [Real; 3] = core::array::from_fn(|l| {
                (-tb[l] + p[0] * r[0][l] + p[1] * r[1][l] + p[2] * r[2][l]).clamp(-b[l], b[l])
            });
            let q: [Real; 3] = core::array::from_fn(|k| {
                t[k] + r[k][0] * xb[0] + r[k][1] * xb[1] + r[k][2] * xb[2]
            });
            let d2 = (0..3).map(|k| (q[k] - p[k]) * (q[k] - p[k])).sum();
            Some(Best { d2, p, q, feature })
        }
        Feature::Edges { i, j, sg } => {
            let (i, j) = (usize::from(i), usize::from(j));
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            let n2 = r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j];
            if !(n2 >= PARALLEL_NORM2) {
                return None;
            }
            let mut best = Best { d2: Real::INFINITY, p: [0.0; 3], q: [0.0; 3], feature };
            edge_pair(rel, i, j, n2, sg.map(|x| sign(Real::from(x))), &mut best);
            Some(best)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::obb_clearance;
    use crate::math::Mat3;
    use crate::test_rng::TestRng;

    fn rotation(rng: &mut TestRng, max_angle: Real) -> Mat3 {
        let axis = nalgebra::Unit::new_normalize(rng.vec(1.0) + Vec3::new(0.0, 0.0, 1e-3));
        *nalgebra::Rotation3::from_axis_angle(&axis, max_angle * rng.unit()).matrix()
    }

    /// Moves a box by a small random rotation and translation, as one tick moves a link.
    fn step(rng: &mut TestRng, o: &Obb, mm: Real) -> Obb {
        Obb::new(o.center + rng.vec(mm), rotation(rng, 0.02) * o.axes, o.half)
    }

    /// Three links per robot, B's some 80-400 mm from A's, both turned at random.
    fn robots(rng: &mut TestRng) -> ([Obb; 3], [Obb; 3]) {
        let link = Vec3::new(150.0, 8.0, 8.0);
        let a = core::array::from_fn(|i| {
            Obb::new(Vec3::new(0.0, 60.0 * i as Real, 0.0), rotation(rng, 3.0), link)
        });
        let b = core::array::from_fn(|i| {
            let x = 240.0 + 160.0 * rng.unit();
            Obb::new(Vec3::new(x, 60.0 * i as Real, 0.0), rotation(rng, 3.0), link)
        });
        (a, b)
    }

    #[test]
    fn equals_the_computation_from_scratch_along_random_motions() {
        let mut rng = TestRng(17);
        let (mut warm_starts, mut total) = (0, 0);
        for _ in 0..200 {
            let (mut a, mut b) = robots(&mut rng);
            let mut memory = CoherentClearance::new();
            for _ in 0..60 {
                // Whether last call's closest pair is certified from its features now.
                let k = memory.closest;
                warm_starts +=
                    usize::from(warm(&a[k / 3], &b[k % 3], memory.pairs[k].feature).is_some());
                let cold = boxes_clearance(&a, &b);
                let coherent = memory.boxes_clearance(&a, &b);
                let scale = 1e-9 * (1.0 + cold.distance.abs());
                assert!(
                    (coherent.distance - cold.distance).abs() <= scale,
                    "{coherent:?} {cold:?}"
                );
                let pair = obb_clearance(&a[coherent.box_a], &b[coherent.box_b]).distance;
                assert!(
                    (pair - coherent.distance).abs() <= scale,
                    "the pair named realises it: {pair} {coherent:?}"
                );
                let gap = (coherent.point_b - coherent.point_a).norm();
                assert!((gap - coherent.distance.abs()).abs() <= scale, "{coherent:?}");
                total += 1;
                a = a.map(|o| step(&mut rng, &o, 3.0));
                b = b.map(|o| step(&mut rng, &o, 3.0));
            }
        }
        assert!(warm_starts > total / 2, "the features are reused: {warm_starts} of {total}");
    }

    #[test]
    fn the_gap_along_any_direction_is_a_lower_bound() {
        let mut rng = TestRng(5);
        for _ in 0..100_000 {
            let a = Obb::new(
                rng.vec(50.0),
                rotation(&mut rng, 3.0),
                rng.vec(40.0).abs() + Vec3::repeat(1.0),
            );
            let b = Obb::new(
                rng.vec(150.0),
                rotation(&mut rng, 3.0),
                rng.vec(40.0).abs() + Vec3::repeat(1.0),
            );
            let n = (rng.vec(1.0) + Vec3::new(1e-3, 0.0, 0.0)).normalize();
            let exact = obb_clearance(&a, &b).distance;
            assert!(gap_along(&a, &b, &n) <= exact, "{a:?} {b:?} {n}");
        }
    }

    #[test]
    fn kept_directions_are_unit_even_for_a_tiny_overlap_far_from_the_origin() {
        let half = Vec3::new(150.0, 8.0, 8.0);
        for overlap in [1e-12, 1e-10, 1e-7, 1e-3] {
            let a = [Obb::new(Vec3::new(700.0, 300.0, -450.0), Mat3::identity(), half)];
            let b = [Obb::new(Vec3::new(1000.0 - overlap, 300.5, -450.25), Mat3::identity(), half)];
            let mut memory = CoherentClearance::new();
            let c = memory.boxes_clearance(&a, &b);
            let n = memory.pairs[0].direction;
            assert!(
                n == Vec3::zeros() || (n.norm() - 1.0).abs() < 1e-12,
                "overlap {overlap}: {c:?}, direction {n}"
            );
            assert!(gap_along(&a[0], &b[0], &n) <= c.distance || n == Vec3::zeros());
        }
    }

    #[test]
    fn nan_boxes_give_nan_whatever_the_memory_holds() {
        let mut rng = TestRng(3);
        let a = [Obb::new(Vec3::zeros(), rotation(&mut rng, 3.0), Vec3::repeat(10.0))];
        let b = [Obb::new(Vec3::new(100.0, 0.0, 0.0), rotation(&mut rng, 3.0), Vec3::repeat(10.0))];
        let mut memory = CoherentClearance::new();
        assert!(memory.boxes_clearance(&a, &b).distance > 0.0);
        assert!(memory.boxes_clearance(&a, &b).distance > 0.0, "a second call, from memory");
        let mut bad = b;
        bad[0].center.x = Real::NAN;
        assert!(memory.boxes_clearance(&a, &bad).distance.is_nan());
        bad[0] = Obb::new(b[0].center, Mat3::identity() * Real::INFINITY, b[0].half);
        assert!(memory.boxes_clearance(&a, &bad).distance.is_nan());
        assert!(memory.boxes_clearance(&a, &b).distance > 0.0, "recovers");
    }
}
