//! Signed clearance of two oriented boxes, and a certified lower bound on it that costs about
//! one separating axis test (SPEC §8 "Clearance", §3 boxes).
//!
//! # Conventions
//! Clearance is positive when the boxes are apart (the Euclidean gap), negative when they
//! intersect (minus the penetration depth: the smallest overlap of the two boxes' projections
//! over the 15 SAT axes, each normalised, cross products shorter than
//! [`CROSS_AXIS_MIN_NORM`] left out) and 0 when they touch. The witness points satisfy
//! `point_b - point_a = distance * n`, with `n` the unit direction from A toward B: the
//! closest points when apart; when intersecting, a deepest vertex of A along the axis of
//! least overlap and that vertex moved back by the overlap.
//!
//! # Method
//! Apart: for disjoint convex polytopes the vector `d` between closest points is unique, and
//! the closest pairs are the intersection of A's supporting face in direction `d` with B's
//! supporting face in `-d` (moved by `d`). A vertex of that polygon is a vertex of A or of B
//! (the 16 vertex-to-box distances find it), or the crossing of an edge of A along `A_i` with
//! an edge of B along `B_j`, both perpendicular to `d`, so `d` is parallel to `A_i x B_j` and
//! the two edges are the supporting edges of that direction. Hence the 16 vertex distances
//! and one supporting edge pair per cross axis (9 line-line solves) give the exact distance;
//! where a sign of the supporting direction is within rounding of 0 (parallel faces), every
//! edge pair of that axis is tried. Each candidate is a distance between two points of the
//! boxes, so extra candidates can only leave the minimum unchanged.
//!
//! # Numerics
//! Whether the boxes are apart is decided by the separating axis test's own inequalities
//! (`sat.rs`, with [`SAT_EPSILON`] and [`SAT_TOUCH_TOLERANCE`]), so "apart" here is exactly
//! [`separating_axis`](crate::geometry::separating_axis)`.is_some()`; a gap inside that
//! tolerance reports 0 (touching). The lower bound subtracts the same guards before
//! normalising, which keeps it below the exact value and makes `bound > 0` imply that the
//! SAT separates. Any NaN or infinite input gives a NaN distance.

// `!(x >= y)` is deliberate: it is true when either side is NaN, which sends NaN to the
// "check it" or "colliding" side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod coherent;
pub use coherent::{CoherentClearance, WARM_MIN_GAP};

use crate::geometry::obb::Obb;
use crate::math::{float, Real, Vec3, CROSS_AXIS_MIN_NORM, SAT_EPSILON, SAT_TOUCH_TOLERANCE};

/// Signed clearance of two boxes, with witness points (world frame, mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Gap when positive, minus the penetration depth when negative, 0 when touching.
    pub distance: Real,
    /// Witness point on (or, penetrating, of) box A.
    pub point_a: Vec3,
    /// Witness point of box B: `point_a + distance * n`, `n` the unit direction A -> B.
    pub point_b: Vec3,
}

/// Signed clearance of two robots: the minimum over their box pairs, and which pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairClearance {
    /// The smallest signed clearance over all box pairs (`+inf` when a slice is empty).
    pub distance: Real,
    /// Index of the box of the first robot.
    pub box_a: usize,
    /// Index of the box of the second robot.
    pub box_b: usize,
    /// Witness point on box `a[box_a]`.
    pub point_a: Vec3,
    /// Witness point on box `b[box_b]`.
    pub point_b: Vec3,
}

impl PairClearance {
    /// No pair yet: `+inf` with indices 0.
    const NONE: PairClearance = PairClearance {
        distance: Real::INFINITY,
        box_a: 0,
        box_b: 0,
        point_a: Vec3::new(0.0, 0.0, 0.0),
        point_b: Vec3::new(0.0, 0.0, 0.0),
    };

    /// Box `box_a` of the first robot and `box_b` of the second at clearance `c`.
    fn of(box_a: usize, box_b: usize, c: &Clearance) -> PairClearance {
        PairClearance { distance: c.distance, box_a, box_b, point_a: c.point_a, point_b: c.point_b }
    }
}

/// Relative error allowed for in the lower bound on top of the SAT guards: a few units in
/// the last place of the largest term of an axis inequality.
const BOUND_REL_SLACK: Real = 1e-14;

/// A component of a supporting direction this close to 0 (relative to unit axes) may have
/// the wrong sign after rounding (about 1e-16 here): both signs are then tried.
const SIGN_TIE: Real = 1e-9;

/// Cross products shorter than this (squared) are parallel edges for the closest-point
/// solve: the vertex distances cover them (the error is below `|edge| * 1e-10`).
const PARALLEL_NORM2: Real = 1e-20;

/// B relative to A: `r[i][j] = A_i . B_j`, `t` = `c_B - c_A` in A's frame, `tb` in B's frame.
/// Computed with the same expressions, in the same order, as `sat.rs`.
struct Rel {
    r: [[Real; 3]; 3],
    t: [Real; 3],
    tb: [Real; 3],
    a: [Real; 3],
    b: [Real; 3],
}

#[inline(always)]
fn dot(u: &[Real; 3], v: &[Real; 3]) -> Real {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

#[inline(always)]
fn rel(a: &Obb, b: &Obb) -> Rel {
    let (ma, mb) = (&a.axes, &b.axes);
    let ua: [[Real; 3]; 3] = core::array::from_fn(|i| [ma[(0, i)], ma[(1, i)], ma[(2, i)]]);
    let ub: [[Real; 3]; 3] = core::array::from_fn(|j| [mb[(0, j)], mb[(1, j)], mb[(2, j)]]);
    let r: [[Real; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|j| dot(&ua[i], &ub[j])));
    let d = [b.center.x - a.center.x, b.center.y - a.center.y, b.center.z - a.center.z];
    let t = [dot(&ua[0], &d), dot(&ua[1], &d), dot(&ua[2], &d)];
    let tb = core::array::from_fn(|j| t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j]);
    Rel { r, t, tb, a: [a.half.x, a.half.y, a.half.z], b: [b.half.x, b.half.y, b.half.z] }
}

/// Whether every input number is finite (a NaN or an infinity anywhere gives `false`).
#[inline(always)]
fn finite(a: &Obb, b: &Obb) -> bool {
    let s =
        a.center.sum() + a.axes.sum() + a.half.sum() + b.center.sum() + b.axes.sum() + b.half.sum();
    (s * 0.0) == 0.0
}

/// One of the 15 axes as the SAT writes it: `|lhs|` against `rhs`, `norm` its length.
/// `lhs` is signed (positive when B lies on the axis' positive side).
#[derive(Clone, Copy)]
struct AxisTerms {
    lhs: Real,
    rhs: Real,
    rhs_guarded: Real,
    norm2: Real,
}

/// The terms of axis `k` (numbered as [`Axis`](crate::geometry::Axis)); `rhs_guarded` is
/// `sat.rs`'s right-hand side to the last rounding (|R| + SAT_EPSILON, + touch tolerance).
#[inline(always)]
fn axis_terms(rel: &Rel, k: usize) -> AxisTerms {
    let (r, t, a, b) = (&rel.r, &rel.t, &rel.a, &rel.b);
    let g = |x: Real| x.abs() + SAT_EPSILON;
    match k {
        0..=2 => {
            let i = k;
            AxisTerms {
                lhs: t[i],
                rhs: a[i] + b[0] * r[i][0].abs() + b[1] * r[i][1].abs() + b[2] * r[i][2].abs(),
                rhs_guarded: a[i]
                    + b[0] * g(r[i][0])
                    + b[1] * g(r[i][1])
                    + b[2] * g(r[i][2])
                    + SAT_TOUCH_TOLERANCE,
                norm2: 1.0,
            }
        }
        3..=5 => {
            let j = k - 3;
            AxisTerms {
                lhs: rel.tb[j],
                rhs: a[0] * r[0][j].abs() + a[1] * r[1][j].abs() + a[2] * r[2][j].abs() + b[j],
                rhs_guarded: a[0] * g(r[0][j])
                    + a[1] * g(r[1][j])
                    + a[2] * g(r[2][j])
                    + b[j]
                    + SAT_TOUCH_TOLERANCE,
                norm2: 1.0,
            }
        }
        _ => {
            let (i, j) = ((k - 6) / 3, (k - 6) % 3);
            let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
            AxisTerms {
                lhs: t[i2] * r[i1][j] - t[i1] * r[i2][j],
                rhs: a[i1] * r[i2][j].abs()
                    + a[i2] * r[i1][j].abs()
                    + b[j1] * r[i][j2].abs()
                    + b[j2] * r[i][j1].abs(),
                rhs_guarded: a[i1] * g(r[i2][j])
                    + a[i2] * g(r[i1][j])
                    + b[j1] * g(r[i][j2])
                    + b[j2] * g(r[i][j1])
                    + SAT_TOUCH_TOLERANCE,
                norm2: r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j],
            }
        }
    }
}

/// The 15 axes' terms; `axis_terms` is inlined with a constant `k` each time, so the
/// index arithmetic folds away.
#[inline(always)]
fn all_axes(rel: &Rel) -> [AxisTerms; 15] {
    [
        axis_terms(rel, 0),
        axis_terms(rel, 1),
        axis_terms(rel, 2),
        axis_terms(rel, 3),
        axis_terms(rel, 4),
        axis_terms(rel, 5),
        axis_terms(rel, 6),
        axis_terms(rel, 7),
        axis_terms(rel, 8),
        axis_terms(rel, 9),
        axis_terms(rel, 10),
        axis_terms(rel, 11),
        axis_terms(rel, 12),
        axis_terms(rel, 13),
        axis_terms(rel, 14),
    ]
}

/// Whether axis `k` takes part in the normalised gaps (face axes always; cross axes when
/// the cross product is at least [`CROSS_AXIS_MIN_NORM`] long).
#[inline(always)]
fn included(k: usize, norm2: Real) -> bool {
    k < 6 || norm2 >= CROSS_AXIS_MIN_NORM * CROSS_AXIS_MIN_NORM
}

/// A lower bound on the signed clearance (mm) at about the cost of one separating axis test.
///
/// The largest gap between the two boxes' projections over the 15 axes (each normalised;
/// cross products shorter than [`CROSS_AXIS_MIN_NORM`] left out); when no axis separates,
/// this is minus the smallest overlap, the exact penetration clearance. It is rounded down
/// by the SAT's guards, so it never exceeds [`obb_clearance`], and when it is positive
/// [`separating_axis`](crate::geometry::separating_axis) finds a separating axis. NaN or
/// infinite input gives NaN.
#[inline]
pub fn obb_clearance_lower_bound(a: &Obb, b: &Obb) -> Real {
    if !finite(a, b) {
        return Real::NAN;
    }
    let axes = all_axes(&rel(a, b));
    let gap: [Real; 15] = core::array::from_fn(|k| guarded_gap(&axes[k]));
    let mut best = gap[0].max(gap[1]).max(gap[2]).max(gap[3]).max(gap[4]).max(gap[5]);
    for k in 6..15 {
        // Normalising costs a square root: only for axes that could beat the best, that
        // is `gap / |n| > best` with `|n| <= 1`, compared in squares when both are positive.
        let n2 = axes[k].norm2;
        if included(k, n2) && (best < 0.0 || (gap[k] > 0.0 && gap[k] * gap[k] > best * best * n2)) {
            let g = gap[k] / float::sqrt(n2);
            if g > best {
                best = g;
            }
        }
    }
    best
}

/// The gap of one axis before normalising, less the SAT's guards and the rounding slack:
/// positive only when `sat.rs` finds that axis separating.
#[inline(always)]
fn guarded_gap(ax: &AxisTerms) -> Real {
    let diff = ax.lhs.abs() - ax.rhs_guarded;
    diff - BOUND_REL_SLACK * (ax.lhs.abs() + ax.rhs_guarded)
}

/// The face-axis part of [`obb_clearance_lower_bound`] (so never above it), at about a
/// third of its cost: the bound by which robot-level searches skip pairs.
#[inline]
fn face_bound(a: &Obb, b: &Obb) -> Real {
    if !finite(a, b) {
        return Real::NAN;
    }
    let rel = rel(a, b);
    let g = |k: usize| guarded_gap(&axis_terms(&rel, k));
    g(0).max(g(1)).max(g(2)).max(g(3)).max(g(4)).max(g(5))
}

/// Most box pairs whose cheap bounds [`pairs_by_bound`] keeps on the stack.
const MAX_PAIRS: usize = 64;

/// Calls `visit(k, bound_k)` for every pair `k = i * b.len() + j` of `a[i]`, `b[j]`, the pair
/// with the smallest [`face_bound`] first (usually the closest pair, so that the others can
/// be skipped by their bound). Beyond [`MAX_PAIRS`] pairs, in order with bound `-inf`.
#[inline(always)]
fn pairs_by_bound(a: &[Obb], b: &[Obb], mut visit: impl FnMut(usize, Real)) {
    let n = a.len().saturating_mul(b.len());
    let m = b.len().max(1);
    let mut bound = [Real::NEG_INFINITY; MAX_PAIRS];
    let mut first = 0;
    if n <= MAX_PAIRS {
        for k in 0..n {
            bound[k] = face_bound(&a[k / m], &b[k % m]);
            if !(bound[k] >= bound[first]) {
                first = k;
            }
        }
    }
    for k in (0..n).map(|k| (k + first) % n) {
        visit(k, if n <= MAX_PAIRS { bound[k] } else { Real::NEG_INFINITY });
    }
}

/// The smallest [`obb_clearance_lower_bound`] over all pairs of a box of `a` and a box of
/// `b` (`+inf` when either is empty; NaN when any box holds a NaN). Pairs whose face-axis
/// bound already reaches the smallest so far are skipped: their bound cannot be smaller.
pub fn boxes_clearance_lower_bound(a: &[Obb], b: &[Obb]) -> Real {
    let (mut best, m) = (Real::INFINITY, b.len().max(1));
    pairs_by_bound(a, b, |k, cheap| {
        if !(cheap >= best) && !best.is_nan() {
            let d = obb_clearance_lower_bound(&a[k / m], &b[k % m]);
            if !(d >= best) {
                best = d;
            }
        }
    });
    best
}

/// The signed clearance of two closed boxes (mm), with witness points in the world frame.
///
/// Apart (the separating axis test finds an axis): the Euclidean distance and the closest
/// points. Otherwise minus the smallest normalised overlap over the 15 axes, capped at 0
/// (a gap within the SAT's touch tolerance reads as touching). NaN or infinite input gives
/// a NaN distance.
pub fn obb_clearance(a: &Obb, b: &Obb) -> Clearance {
    obb_clearance_with_feature(a, b).0
}

/// [`obb_clearance`] and, when apart, the features its closest points lie on.
fn obb_clearance_with_feature(a: &Obb, b: &Obb) -> (Clearance, Feature) {
    if !finite(a, b) {
        return (
            Clearance { distance: Real::NAN, point_a: a.center, point_b: b.center },
            Feature::None,
        );
    }
    let rel = rel(a, b);
    let axes = all_axes(&rel);
    if axes.iter().any(|ax| ax.lhs.abs() > ax.rhs_guarded) {
        let best = separated(&rel, &axes);
        (best.clearance(a), best.feature)
    } else {
        (penetrating(a, &rel, &axes), Feature::None)
    }
}

/// Local point `p` of box `o` in the world frame.
#[inline(always)]
fn to_world(o: &Obb, p: &[Real; 3]) -> Vec3 {
    o.center + o.axes * Vec3::new(p[0], p[1], p[2])
}

/// `+1` or `-1` by the sign of `x` (`+1` for 0).
#[inline(always)]
fn sign(x: Real) -> Real {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Penetrating or touching: minus the smallest normalised overlap, capped at 0.
fn penetrating(a: &Obb, rel: &Rel, axes: &[AxisTerms; 15]) -> Clearance {
    let (mut best, mut axis, mut lhs) = (Real::INFINITY, 0, 0.0);
    for (k, ax) in axes.iter().enumerate() {
        if !included(k, ax.norm2) {
            continue;
        }
        let n = if k < 6 { 1.0 } else { float::sqrt(ax.norm2) };
        let overlap = (ax.rhs - ax.lhs.abs()) / n;
        if overlap < best {
            (best, axis, lhs) = (overlap, k, ax.lhs / n);
        }
    }
    // The unit axis toward B, in A's frame.
    let (r, s) = (&rel.r, sign(lhs));
    let dir: [Real; 3] = match axis {
        0..=2 => core::array::from_fn(|m| if m == axis { s } else { 0.0 }),
        3..=5 => core::array::from_fn(|m| s * r[m][axis - 3]),
        _ => {
            let (i, j) = ((axis - 6) / 3, (axis - 6) % 3);
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            let n = float::sqrt(r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j]);
            let mut v = [0.0; 3];
            (v[i1], v[i2]) = (-s * r[i2][j] / n, s * r[i1][j] / n);
            v
        }
    };
    let distance = if best > 0.0 { -best } else { 0.0 };
    // A's deepest vertex along the axis, and that vertex moved back by the overlap.
    let pa: [Real; 3] = core::array::from_fn(|m| sign(dir[m]) * rel.a[m]);
    let pb: [Real; 3] = core::array::from_fn(|m| pa[m] + distance * dir[m]);
    Clearance { distance, point_a: to_world(a, &pa), point_b: to_world(a, &pb) }
}

/// The closest pair found so far, in A's frame, and the features it lies on.
struct Best {
    d2: Real,
    p: [Real; 3],
    q: [Real; 3],
    feature: Feature,
}

impl Best {
    /// The clearance these points give, in the world frame (`a` is box A).
    #[inline(always)]
    fn clearance(&self, a: &Obb) -> Clearance {
        Clearance {
            distance: float::sqrt(self.d2),
            point_a: to_world(a, &self.p),
            point_b: to_world(a, &self.q),
        }
    }
}

/// The pair of features a candidate pair of points lies on, by the signs (`-1` or `+1`) that
/// pick a vertex or an edge of a box: what [`coherent`] recomputes first at the next tick.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Feature {
    /// Nothing to start from (penetrating, touching, or never computed).
    #[default]
    None,
    /// B's vertex `t + sum_l sg_l b_l B_l` and its closest point of A.
    VertexOfB([i8; 3]),
    /// A's vertex `sum_k sg_k a_k A_k` and its closest point of B.
    VertexOfA([i8; 3]),
    /// A's edge along `A_i` against B's edge along `B_j`, with [`edge_pair`]'s signs.
    Edges { i: u8, j: u8, sg: [i8; 4] },
}

/// The signs `sg` as a feature's compact form.
#[inline(always)]
fn signs<const N: usize>(sg: [Real; N]) -> [i8; N] {
    sg.map(|x| if x < 0.0 { -1 } else { 1 })
}

/// Apart: the exact distance, from the 16 vertex-to-box distances and the supporting edge
/// pairs of the nine cross axes (module doc).
///
/// The gap along any unit axis is at most the distance, and along the direction of a
/// crossing edge pair of cross axis `k` it equals the distance: so only the cross axes whose
/// normalised gap reaches the largest gap `g` over the 15 axes (to rounding) need their edge
/// pair, and none does when a vertex is already at distance `g`.
fn separated(rel: &Rel, axes: &[AxisTerms; 15]) -> Best {
    // Rounding of a normalised gap: about 1e-16 * size / |n|, |n| >= CROSS_AXIS_MIN_NORM.
    // Generous for choosing edge pairs (an extra pair costs time only), tight for stopping
    // at a vertex (a vertex above the true distance by the tolerance would be kept).
    let size = rel.t.iter().chain(&rel.a).chain(&rel.b).map(|x| x.abs()).sum::<Real>();
    let tol = 1e-8 * size + 1e-12;
    let (mut g, mut widest) = (Real::NEG_INFINITY, 0);
    for (k, ax) in axes[..6].iter().enumerate() {
        if ax.lhs.abs() - ax.rhs > g {
            (g, widest) = (ax.lhs.abs() - ax.rhs, k);
        }
    }
    let mut gap = [Real::NEG_INFINITY; 9];
    for (m, ax) in axes[6..].iter().enumerate() {
        let raw = ax.lhs.abs() - ax.rhs;
        if ax.norm2 >= CROSS_AXIS_MIN_NORM * CROSS_AXIS_MIN_NORM {
            // `raw / |n| > g - tol` (|n| <= 1), tested in squares to spare most square
            // roots; `g` only grows, so an axis left out stays below the final `g - tol`.
            let low = g - tol;
            if raw > 0.0 && (low < 0.0 || raw * raw > low * low * ax.norm2) {
                gap[m] = raw / float::sqrt(ax.norm2);
                if gap[m] > g {
                    (g, widest) = (gap[m], 6 + m);
                }
            }
        } else {
            // Too short to normalise accurately: always tried.
            gap[m] = Real::INFINITY;
        }
    }
    let reach = (g + 1e-13 * size).max(0.0);
    // The features that support the axis of the largest gap: when they are `g` apart (to
    // rounding), no pair of points is closer, and the rest is not needed.
    let widest = supporting_features(rel, widest, axes[widest].lhs);
    if widest.d2 <= reach * reach {
        return widest;
    }
    let mut best = vertices(rel);
    if widest.d2 < best.d2 {
        best = widest;
    }
    if best.d2 > reach * reach {
        let near = |m: usize| gap[m] >= g - tol;
        // Written out so that each call is inlined with constant indices.
        if near(0) {
            edge_axis(rel, 0, 0, &mut best);
        }
        if near(1) {
            edge_axis(rel, 0, 1, &mut best);
        }
        if near(2) {
            edge_axis(rel, 0, 2, &mut best);
        }
        if near(3) {
            edge_axis(rel, 1, 0, &mut best);
        }
        if near(4) {
            edge_axis(rel, 1, 1, &mut best);
        }
        if near(5) {
            edge_axis(rel, 1, 2, &mut best);
        }
        if near(6) {
            edge_axis(rel, 2, 0, &mut best);
        }
        if near(7) {
            edge_axis(rel, 2, 1, &mut best);
        }
        if near(8) {
            edge_axis(rel, 2, 2, &mut best);
        }
    }
    best
}

/// A pair of points of the two boxes on the features that support axis `k` (numbered as
/// [`Axis`](crate::geometry::Axis)): for a face axis of one box, the other box's vertex
/// deepest toward it and that vertex's closest point of the first box; for a cross axis, its
/// supporting edge pair (every pair when a sign is within rounding of 0). Where the gap on
/// axis `k` is the distance, these points realise it (module doc, "Method"); elsewhere they
/// are still two points of the boxes, so never closer than the distance.
#[inline(always)]
fn supporting_features(rel: &Rel, k: usize, lhs: Real) -> Best {
    let (r, t, tb, a, b) = (&rel.r, &rel.t, &rel.tb, &rel.a, &rel.b);
    let side = sign(lhs);
    match k {
        0..=2 => {
            // B's vertex lowest along side * A_k, in A's frame, and its clamp into A.
            let sg: [Real; 3] = core::array::from_fn(|l| -side * sign(r[k][l]));
            let q: [Real; 3] = core::array::from_fn(|m| {
                t[m] + sg[0] * b[0] * r[m][0] + sg[1] * b[1] * r[m][1] + sg[2] * b[2] * r[m][2]
            });
            let p: [Real; 3] = core::array::from_fn(|m| q[m].clamp(-a[m], a[m]));
            let feature = Feature::VertexOfB(signs(sg));
            Best { d2: (0..3).map(|m| (q[m] - p[m]) * (q[m] - p[m])).sum(), p, q, feature }
        }
        3..=5 => {
            // A's vertex highest along side * B_j, and its clamp into B, back in A's frame.
            let j = k - 3;
            let p: [Real; 3] = core::array::from_fn(|m| side * sign(r[m][j]) * a[m]);
            let xb: [Real; 3] = core::array::from_fn(|l| {
                (-tb[l] + p[0] * r[0][l] + p[1] * r[1][l] + p[2] * r[2][l]).clamp(-b[l], b[l])
            });
            let q: [Real; 3] = core::array::from_fn(|m| {
                t[m] + r[m][0] * xb[0] + r[m][1] * xb[1] + r[m][2] * xb[2]
            });
            let feature = Feature::VertexOfA(core::array::from_fn(|m| {
                if side * sign(r[m][j]) < 0.0 {
                    -1
                } else {
                    1
                }
            }));
            Best { d2: (0..3).map(|m| (q[m] - p[m]) * (q[m] - p[m])).sum(), p, q, feature }
        }
        _ => {
            let mut best =
                Best { d2: Real::INFINITY, p: [0.0; 3], q: [0.0; 3], feature: Feature::None };
            edge_axis(rel, (k - 6) / 3, (k - 6) % 3, &mut best);
            best
        }
    }
}

/// The vertex of the 16 that is closest to the other box, with its closest point.
#[inline(always)]
fn vertices(rel: &Rel) -> Best {
    let (r, t, tb, a, b) = (&rel.r, &rel.t, &rel.tb, &rel.a, &rel.b);
    // B's vertices in A's frame, t + sum_l +-b_l R_.l, against A.
    let cb: [[Real; 3]; 3] = core::array::from_fn(|k| core::array::from_fn(|l| b[l] * r[k][l]));
    let d2b: [Real; 8] = core::array::from_fn(|v| {
        let sg = |l: usize| if v >> l & 1 == 0 { -1.0 } else { 1.0 };
        let o: [Real; 3] = core::array::from_fn(|k| {
            let x = t[k] + sg(0) * cb[k][0] + sg(1) * cb[k][1] + sg(2) * cb[k][2];
            (x.abs() - a[k]).max(0.0)
        });
        o[0] * o[0] + o[1] * o[1] + o[2] * o[2]
    });
    // A's vertices in B's frame, -tb + sum_k +-a_k R_k., against B.
    let ca: [[Real; 3]; 3] = core::array::from_fn(|l| core::array::from_fn(|k| a[k] * r[k][l]));
    let d2a: [Real; 8] = core::array::from_fn(|v| {
        let sg = |k: usize| if v >> k & 1 == 0 { -1.0 } else { 1.0 };
        let o: [Real; 3] = core::array::from_fn(|l| {
            let x = -tb[l] + sg(0) * ca[l][0] + sg(1) * ca[l][1] + sg(2) * ca[l][2];
            (x.abs() - b[l]).max(0.0)
        });
        o[0] * o[0] + o[1] * o[1] + o[2] * o[2]
    });
    let (mut vb, mut va) = (0, 0);
    for v in 1..8 {
        if d2b[v] < d2b[vb] {
            vb = v;
        }
        if d2a[v] < d2a[va] {
            va = v;
        }
    }
    let sgn = |v: usize, m: usize| if v >> m & 1 == 0 { -1.0 } else { 1.0 };
    if d2b[vb] <= d2a[va] {
        let q: [Real; 3] = core::array::from_fn(|k| {
            t[k] + (0..3).map(|l| sgn(vb, l) * b[l] * r[k][l]).sum::<Real>()
        });
        let p = core::array::from_fn(|k| q[k].clamp(-a[k], a[k]));
        Best {
            d2: d2b[vb],
            p,
            q,
            feature: Feature::VertexOfB(core::array::from_fn(|l| sgn(vb, l) as i8)),
        }
    } else {
        // A's vertex in A's frame, and its closest point of B (clamped in B's frame) back in A's.
        let p: [Real; 3] = core::array::from_fn(|k| sgn(va, k) * a[k]);
        let xb: [Real; 3] = core::array::from_fn(|l| {
            (-tb[l] + (0..3).map(|k| p[k] * r[k][l]).sum::<Real>()).clamp(-b[l], b[l])
        });
        let q = core::array::from_fn(|k| t[k] + (0..3).map(|l| r[k][l] * xb[l]).sum::<Real>());
        Best {
            d2: d2a[va],
            p,
            q,
            feature: Feature::VertexOfA(core::array::from_fn(|k| sgn(va, k) as i8)),
        }
    }
}

/// The supporting edge pair(s) of cross axis `A_i x B_j`, solved as lines and clamped to the
/// edges (a true distance between points of the boxes, exact when the edges cross).
#[inline(always)]
fn edge_axis(rel: &Rel, i: usize, j: usize, best: &mut Best) {
    let (r, t) = (&rel.r, &rel.t);
    let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
    let n2 = r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j];
    if !(n2 >= PARALLEL_NORM2) {
        return;
    }
    let nt = t[i2] * r[i1][j] - t[i1] * r[i2][j];
    // Signs of the supporting edges: A's in direction s n, B's in -s n, n = A_i x B_j with
    // n . A_i1 = -R_i2j, n . A_i2 = R_i1j, n . B_j1 = R_ij2, n . B_j2 = -R_ij1.
    let comps = [-r[i2][j], r[i1][j], r[i][j2], -r[i][j1]];
    let tie_t = 1e-12 * (t[0].abs() + t[1].abs() + t[2].abs());
    if nt.abs() > tie_t && comps.iter().all(|c| c.abs() > SIGN_TIE) {
        let s = sign(nt);
        let sg = [s * sign(comps[0]), s * sign(comps[1]), -s * sign(comps[2]), -s * sign(comps[3])];
        edge_pair(rel, i, j, n2, sg, best);
    } else {
        for m in 0..16 {
            let sg = core::array::from_fn(|q| if m >> q & 1 == 0 { -1.0 } else { 1.0 });
            edge_pair(rel, i, j, n2, sg, best);
        }
    }
}

/// The edge of A along `A_i` at signs `(sg0, sg1)` on `(A_i1, A_i2)` against the edge of B
/// along `B_j` at signs `(sg2, sg3)` on `(B_j1, B_j2)`; keeps the pair if closer.
#[inline(always)]
fn edge_pair(rel: &Rel, i: usize, j: usize, n2: Real, sg: [Real; 4], best: &mut Best) {
    let (r, t, a, b) = (&rel.r, &rel.t, &rel.a, &rel.b);
    let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
    let mut p = [0.0; 3];
    (p[i1], p[i2]) = (sg[0] * a[i1], sg[1] * a[i2]);
    let (bj1, bj2) = (sg[2] * b[j1], sg[3] * b[j2]);
    let q0: [Real; 3] = core::array::from_fn(|k| t[k] + bj1 * r[k][j1] + bj2 * r[k][j2]);
    let w: [Real; 3] = core::array::from_fn(|k| p[k] - q0[k]);
    // Minimise |w + s e_i - u B_j|^2: s = (c w.B_j - w_i) / (1 - c^2), then u given s.
    let c = r[i][j];
    let wr = w[0] * r[0][j] + w[1] * r[1][j] + w[2] * r[2][j];
    let s = ((c * wr - w[i]) / n2).clamp(-a[i], a[i]);
    let u = (wr + c * s).clamp(-b[j], b[j]);
    p[i] = s;
    let q: [Real; 3] = core::array::from_fn(|k| q0[k] + u * r[k][j]);
    let d2 = (p[0] - q[0]) * (p[0] - q[0])
        + (p[1] - q[1]) * (p[1] - q[1])
        + (p[2] - q[2]) * (p[2] - q[2]);
    if d2 < best.d2 {
        *best =
            Best { d2, p, q, feature: Feature::Edges { i: i as u8, j: j as u8, sg: signs(sg) } };
    }
}

/// The smallest signed clearance between a box of `a` and a box of `b`, and which pair.
///
/// Pairs whose face-axis lower bound (part of [`obb_clearance_lower_bound`]) is not below
/// the best clearance found so far are skipped: their clearance cannot be smaller. `+inf`
/// with indices 0 when either slice is empty; a NaN distance when any box holds a NaN. No
/// allocation.
pub fn boxes_clearance(a: &[Obb], b: &[Obb]) -> PairClearance {
    let m = b.len().max(1);
    let mut out = PairClearance::NONE;
    pairs_by_bound(a, b, |k, cheap| {
        if !(cheap >= out.distance) && !out.distance.is_nan() {
            let c = obb_clearance(&a[k / m], &b[k % m]);
            if !(c.distance >= out.distance) {
                out = PairClearance::of(k / m, k % m, &c);
            }
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat3;

    fn cube(center: Vec3, half: Real) -> Obb {
        Obb::new(center, Mat3::identity(), Vec3::repeat(half))
    }

    #[test]
    fn face_corner_touching_and_penetrating_cubes() {
        let a = cube(Vec3::zeros(), 1.0);
        let c = obb_clearance(&a, &cube(Vec3::new(5.0, 0.3, -0.2), 1.0));
        assert_eq!(c.distance, 3.0, "face to face");
        assert!((c.point_b - c.point_a - Vec3::new(3.0, 0.0, 0.0)).norm() < 1e-12, "{c:?}");
        let c = obb_clearance(&a, &cube(Vec3::new(4.0, 4.0, 4.0), 1.0));
        assert!((c.distance - 12f64.sqrt()).abs() < 1e-12, "corner to corner {c:?}");
        assert!(
            (c.point_a - Vec3::repeat(1.0)).norm() < 1e-12
                && (c.point_b - Vec3::repeat(3.0)).norm() < 1e-12
        );
        assert_eq!(
            obb_clearance(&a, &cube(Vec3::new(2.0, 0.0, 0.0), 1.0)).distance,
            0.0,
            "touching"
        );
        // Overlapping by 0.5 along x and 1.5 along y: the depth is the smaller overlap.
        let b = cube(Vec3::new(1.5, 0.5, 0.0), 1.0);
        let c = obb_clearance(&a, &b);
        assert_eq!(c.distance, -0.5);
        assert!((c.point_b - c.point_a - Vec3::new(-0.5, 0.0, 0.0)).norm() < 1e-12, "{c:?}");
        let lb = obb_clearance_lower_bound(&a, &b);
        assert!(lb <= -0.5 && lb > -0.5 - 1e-8, "the SAT guards, about 1e-9 below: {lb}");
    }

    #[test]
    fn crossing_edges_of_two_turned_cubes() {
        // A turned 45 degrees about y has a top edge along y at z = sqrt 2; B turned 45 degrees
        // about x has a bottom edge along x: the closest features are these two edges.
        let s = core::f64::consts::FRAC_1_SQRT_2;
        let about_y = Mat3::new(s, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, s);
        let about_x = Mat3::new(1.0, 0.0, 0.0, 0.0, s, -s, 0.0, s, s);
        let a = Obb::new(Vec3::zeros(), about_y, Vec3::repeat(1.0));
        let b = Obb::new(Vec3::new(0.0, 0.0, 2.0 * 2f64.sqrt() + 0.5), about_x, Vec3::repeat(1.0));
        let c = obb_clearance(&a, &b);
        assert!((c.distance - 0.5).abs() < 1e-12, "{c:?}");
        assert!((c.point_a - Vec3::new(0.0, 0.0, 2f64.sqrt())).norm() < 1e-12, "{c:?}");
        let lb = obb_clearance_lower_bound(&a, &b);
        assert!(
            lb <= 0.5 && lb > 0.5 - 1e-8,
            "the edge axis gives the bound, less the SAT guards: {lb}"
        );
    }

    #[test]
    fn robot_level_picks_the_closest_pair_and_skips_nothing_it_needs() {
        let a = [cube(Vec3::zeros(), 1.0), cube(Vec3::new(0.0, 10.0, 0.0), 1.0)];
        let b = [cube(Vec3::new(0.0, 30.0, 0.0), 1.0), cube(Vec3::new(0.0, 13.5, 0.0), 1.0)];
        let c = boxes_clearance(&a, &b);
        assert_eq!((c.distance, c.box_a, c.box_b), (1.5, 1, 1));
        assert!(boxes_clearance_lower_bound(&a, &b) <= 1.5);
        assert_eq!(boxes_clearance(&a, &[]).distance, Real::INFINITY);
        assert_eq!(boxes_clearance_lower_bound(&[], &b), Real::INFINITY);
    }

    #[test]
    fn random_pairs_agree_with_obb_distance_when_apart() {
        let mut rng = crate::test_rng::TestRng(0x5eed_c1ea);
        for _ in 0..20_000 {
            let rot = |r: &mut crate::test_rng::TestRng| {
                *nalgebra::Rotation3::from_euler_angles(
                    r.unit() * 3.2,
                    r.unit() * 3.2,
                    r.unit() * 3.2,
                )
                .matrix()
            };
            let a = Obb::new(rng.vec(5.0), rot(&mut rng), rng.vec(2.0).abs().add_scalar(0.1));
            let b = Obb::new(rng.vec(5.0), rot(&mut rng), rng.vec(2.0).abs().add_scalar(0.1));
            let (c, d) = (obb_clearance(&a, &b), crate::geometry::obb_distance(&a, &b));
            assert!((c.distance.max(0.0) - d).abs() < 1e-9, "{a:?} {b:?}: {c:?} vs {d}");
            assert!(obb_clearance_lower_bound(&a, &b) <= c.distance);
        }
    }
}
