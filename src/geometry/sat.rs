//! The separating axis test (SAT) for two oriented boxes, 15 axes (thesis 3.1.2-3.1.3, SPEC §3).
//!
//! The two boxes overlap exactly when none of the 15 candidate axes separates their
//! projections: the three face normals of each box and the nine cross products of an edge
//! of one with an edge of the other (Gottschalk et al.). All work happens in A's frame:
//! `r_ab = A^T B` and `t_ab = A^T (c_B - c_A)` ("B expressed in A's frame"), so that the
//! inequalities take the optimised form of thesis 3.1.3: a face axis of A reads
//! `|t_i| > a_i + sum_j b_j |R_ij|`, and an edge axis `A_i x B_j` uses Observation 3.1.2 for
//! its left-hand side, `t . (A_i x B_j) = t_i2 R_i1j - t_i1 R_i2j` with `(i, i1, i2)` cyclic.
//! The test is written out axis by axis, cheap face axes first, with an early exit (as in
//! Coal/FCL's `obbDisjoint`).
//!
//! # Numerics
//! `|r_ab|` is enlarged by [`SAT_EPSILON`] so that a cross-product axis of nearly parallel
//! edges, whose length is close to zero, cannot separate by rounding alone; an axis separates
//! only when the gap exceeds [`SAT_TOUCH_TOLERANCE`]. Both err toward collision; touching
//! boxes collide.

use crate::geometry::obb::Obb;
use crate::math::{Real, SAT_EPSILON, SAT_TOUCH_TOLERANCE};

/// One of the 15 candidate separating axes.
///
/// `0..3`: A's axes x, y, z; `3..6`: B's axes; `6 + 3 i + j`: `A_i x B_j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Axis(pub u8);

impl Axis {
    /// The number of candidate axes.
    pub const COUNT: u8 = 15;
}

/// B relative to A: `r[i][j] = A_i . B_j`, `ar = |r| + SAT_EPSILON`, `t = A^T (c_B - c_A)`.
struct Relative {
    r: [[Real; 3]; 3],
    ar: [[Real; 3]; 3],
    t: [Real; 3],
}

#[inline(always)]
fn dot(u: &[Real; 3], v: &[Real; 3]) -> Real {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

/// A box in the flat form the unrolled test reads: axes as rows, plus its bounding radius.
///
/// Build one per box and per tick with [`PreparedBox::new`] when a box meets several others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedBox {
    /// Centre (mm).
    pub c: [Real; 3],
    /// Unit axes, `u[k]` is axis k.
    pub u: [[Real; 3]; 3],
    /// Half-extents along the axes.
    pub h: [Real; 3],
    /// Half-extents of the enclosing axis-aligned box (slightly enlarged, see [`Self::new`]).
    pub aabb: [Real; 3],
}

impl PreparedBox {
    /// A point-sized box at the origin (a filler for fixed arrays).
    pub const ZERO: PreparedBox =
        PreparedBox { c: [0.0; 3], u: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], h: [0.0; 3], aabb: [0.0; 3] };

    /// The flat form of `b`; the AABB half-extents are rounded up by a relative 1e-12 so
    /// that the AABB pre-reject can only err toward "overlap".
    #[inline]
    pub fn new(b: &Obb) -> Self {
        let m = &b.axes;
        let u = [
            [m[(0, 0)], m[(1, 0)], m[(2, 0)]],
            [m[(0, 1)], m[(1, 1)], m[(2, 1)]],
            [m[(0, 2)], m[(1, 2)], m[(2, 2)]],
        ];
        let h = [b.half.x, b.half.y, b.half.z];
        let mut aabb = [0.0; 3];
        for (k, e) in aabb.iter_mut().enumerate() {
            let s = u[0][k].abs() * h[0] + u[1][k].abs() * h[1] + u[2][k].abs() * h[2];
            *e = s * (1.0 + 1e-12);
        }
        PreparedBox { c: [b.center.x, b.center.y, b.center.z], u, h, aabb }
    }
}

/// Whether the world-axis-aligned boxes around `a` and `b` are apart by more than the touch
/// tolerance: a cheap, exact-safe reason for "no intersection".
#[inline(always)]
pub fn aabbs_disjoint(a: &PreparedBox, b: &PreparedBox) -> bool {
    ((b.c[0] - a.c[0]).abs() > a.aabb[0] + b.aabb[0] + SAT_TOUCH_TOLERANCE)
        | ((b.c[1] - a.c[1]).abs() > a.aabb[1] + b.aabb[1] + SAT_TOUCH_TOLERANCE)
        | ((b.c[2] - a.c[2]).abs() > a.aabb[2] + b.aabb[2] + SAT_TOUCH_TOLERANCE)
}

#[inline(always)]
fn relative(a: &PreparedBox, b: &PreparedBox) -> Relative {
    let d = [b.c[0] - a.c[0], b.c[1] - a.c[1], b.c[2] - a.c[2]];
    let t = [dot(&a.u[0], &d), dot(&a.u[1], &d), dot(&a.u[2], &d)];
    let mut r = [[0.0; 3]; 3];
    let mut ar = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&a.u[i], &b.u[j]);
            ar[i][j] = r[i][j].abs() + SAT_EPSILON;
        }
    }
    Relative { r, ar, t }
}

/// Whether the single axis `axis` separates the boxes (beyond the touch tolerance).
fn separates(axis: u8, a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> bool {
    let (r, ar, t) = (&rel.r, &rel.ar, &rel.t);
    let (dist, ra, rb) = match axis {
        // A's face normals: |t_i| vs a_i + sum_j b_j |R_ij|.
        0..=2 => {
            let i = axis as usize;
            (t[i].abs(), a[i], b[0] * ar[i][0] + b[1] * ar[i][1] + b[2] * ar[i][2])
        }
        // B's face normals: |t . B_j| vs sum_i a_i |R_ij| + b_j.
        3..=5 => {
            let j = axis as usize - 3;
            let tb = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
            (tb.abs(), a[0] * ar[0][j] + a[1] * ar[1][j] + a[2] * ar[2][j], b[j])
        }
        // A_i x B_j: with (i, i1, i2) and (j, j1, j2) cyclic,
        // |t_i2 R_i1j - t_i1 R_i2j| vs a_i1 |R_i2j| + a_i2 |R_i1j| + b_j1 |R_ij2| + b_j2 |R_ij1|.
        _ => {
            let k = axis as usize - 6;
            let (i, j) = (k / 3, k % 3);
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            (
                (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs(),
                a[i1] * ar[i2][j] + a[i2] * ar[i1][j],
                b[j1] * ar[i][j2] + b[j2] * ar[i][j1],
            )
        }
    };
    dist > ra + rb + SAT_TOUCH_TOLERANCE
}

/// The 15 axes written out, in the order of [`Axis`]; the first that separates, or `None`.
#[inline(always)]
fn first_separating(a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> Option<Axis> {
    let (r, ar, t) = (&rel.r, &rel.ar, &rel.t);
    let tol = SAT_TOUCH_TOLERANCE;
    // L = A0: |t0| > a0 + b . |R0*|
    if t[0].abs() > a[0] + b[0] * ar[0][0] + b[1] * ar[0][1] + b[2] * ar[0][2] + tol {
        return Some(Axis(0));
    }
    // L = A1
    if t[1].abs() > a[1] + b[0] * ar[1][0] + b[1] * ar[1][1] + b[2] * ar[1][2] + tol {
        return Some(Axis(1));
    }
    // L = A2
    if t[2].abs() > a[2] + b[0] * ar[2][0] + b[1] * ar[2][1] + b[2] * ar[2][2] + tol {
        return Some(Axis(2));
    }
    // L = B0: |t . R*0| > a . |R*0| + b0
    let s = t[0] * r[0][0] + t[1] * r[1][0] + t[2] * r[2][0];
    if s.abs() > a[0] * ar[0][0] + a[1] * ar[1][0] + a[2] * ar[2][0] + b[0] + tol {
        return Some(Axis(3));
    }
    // L = B1
    let s = t[0] * r[0][1] + t[1] * r[1][1] + t[2] * r[2][1];
    if s.abs() > a[0] * ar[0][1] + a[1] * ar[1][1] + a[2] * ar[2][1] + b[1] + tol {
        return Some(Axis(4));
    }
    // L = B2
    let s = t[0] * r[0][2] + t[1] * r[1][2] + t[2] * r[2][2];
    if s.abs() > a[0] * ar[0][2] + a[1] * ar[1][2] + a[2] * ar[2][2] + b[2] + tol {
        return Some(Axis(5));
    }
    // L = A0 x B0: |t2 R10 - t1 R20| > a1 |R20| + a2 |R10| + b1 |R02| + b2 |R01|
    let s = t[2] * r[1][0] - t[1] * r[2][0];
    if s.abs() > a[1] * ar[2][0] + a[2] * ar[1][0] + b[1] * ar[0][2] + b[2] * ar[0][1] + tol {
        return Some(Axis(6));
    }
    // L = A0 x B1: |t2 R11 - t1 R21| > a1 |R21| + a2 |R11| + b0 |R02| + b2 |R00|
    let s = t[2] * r[1][1] - t[1] * r[2][1];
    if s.abs() > a[1] * ar[2][1] + a[2] * ar[1][1] + b[2] * ar[0][0] + b[0] * ar[0][2] + tol {
        return Some(Axis(7));
    }
    // L = A0 x B2: |t2 R12 - t1 R22| > a1 |R22| + a2 |R12| + b0 |R01| + b1 |R00|
    let s = t[2] * r[1][2] - t[1] * r[2][2];
    if s.abs() > a[1] * ar[2][2] + a[2] * ar[1][2] + b[0] * ar[0][1] + b[1] * ar[0][0] + tol {
        return Some(Axis(8));
    }
    // L = A1 x B0: |t0 R20 - t2 R00| > a0 |R20| + a2 |R00| + b1 |R12| + b2 |R11|
    let s = t[0] * r[2][0] - t[2] * r[0][0];
    if s.abs() > a[2] * ar[0][0] + a[0] * ar[2][0] + b[1] * ar[1][2] + b[2] * ar[1][1] + tol {
        return Some(Axis(9));
    }
    // L = A1 x B1: |t0 R21 - t2 R01| > a0 |R21| + a2 |R01| + b0 |R12| + b2 |R10|
    let s = t[0] * r[2][1] - t[2] * r[0][1];
    if s.abs() > a[2] * ar[0][1] + a[0] * ar[2][1] + b[2] * ar[1][0] + b[0] * ar[1][2] + tol {
        return Some(Axis(10));
    }
    // L = A1 x B2: |t0 R22 - t2 R02| > a0 |R22| + a2 |R02| + b0 |R11| + b1 |R10|
    let s = t[0] * r[2][2] - t[2] * r[0][2];
    if s.abs() > a[2] * ar[0][2] + a[0] * ar[2][2] + b[0] * ar[1][1] + b[1] * ar[1][0] + tol {
        return Some(Axis(11));
    }
    // L = A2 x B0: |t1 R00 - t0 R10| > a0 |R10| + a1 |R00| + b1 |R22| + b2 |R21|
    let s = t[1] * r[0][0] - t[0] * r[1][0];
    if s.abs() > a[0] * ar[1][0] + a[1] * ar[0][0] + b[1] * ar[2][2] + b[2] * ar[2][1] + tol {
        return Some(Axis(12));
    }
    // L = A2 x B1: |t1 R01 - t0 R11| > a0 |R11| + a1 |R01| + b0 |R22| + b2 |R20|
    let s = t[1] * r[0][1] - t[0] * r[1][1];
    if s.abs() > a[0] * ar[1][1] + a[1] * ar[0][1] + b[2] * ar[2][0] + b[0] * ar[2][2] + tol {
        return Some(Axis(13));
    }
    // L = A2 x B2: |t1 R02 - t0 R12| > a0 |R12| + a1 |R02| + b0 |R21| + b1 |R20|
    let s = t[1] * r[0][2] - t[0] * r[1][2];
    if s.abs() > a[0] * ar[1][2] + a[1] * ar[0][2] + b[0] * ar[2][1] + b[1] * ar[2][0] + tol {
        return Some(Axis(14));
    }
    None
}

/// The first axis (in [`Axis`] order) that separates two prepared boxes, or `None` when they
/// intersect.
#[inline]
pub fn separating_axis_prepared(a: &PreparedBox, b: &PreparedBox) -> Option<Axis> {
    first_separating(&a.h, &b.h, &relative(a, b))
}

/// As [`separating_axis_prepared`], but tries `hint` first; the answer (`Some`/`None`) is
/// the same, only the returned axis may differ.
#[inline]
pub fn separating_axis_prepared_hinted(a: &PreparedBox, b: &PreparedBox, hint: Axis) -> Option<Axis> {
    let rel = relative(a, b);
    if separates(hint.0, &a.h, &b.h, &rel) {
        return Some(hint);
    }
    first_separating(&a.h, &b.h, &rel)
}

/// The first axis (in [`Axis`] order) that separates `a` and `b`, or `None` when the boxes
/// intersect.
///
/// Boxes are closed: touching boxes intersect.
pub fn separating_axis(a: &Obb, b: &Obb) -> Option<Axis> {
    separating_axis_prepared(&PreparedBox::new(a), &PreparedBox::new(b))
}

/// As [`separating_axis`], but tries `hint` (for example last tick's witness) first, then
/// the others.
pub fn separating_axis_hinted(a: &Obb, b: &Obb, hint: Axis) -> Option<Axis> {
    separating_axis_prepared_hinted(&PreparedBox::new(a), &PreparedBox::new(b), hint)
}

/// Whether the two closed boxes intersect.
pub fn obbs_intersect(a: &Obb, b: &Obb) -> bool {
    separating_axis(a, b).is_none()
}

/// The gap along the direction of the centres' difference, a cheap lower bound used only in
/// tests and tools; `Real` in mm, negative when the boxes' projections overlap on it.
pub fn gap_along_centres(a: &Obb, b: &Obb) -> Real {
    let d = b.center - a.center;
    let n = d.norm();
    if n == 0.0 {
        return Real::NEG_INFINITY;
    }
    let u = d / n;
    let ra = (a.axes.transpose() * u).abs().dot(&a.half);
    let rb = (b.axes.transpose() * u).abs().dot(&b.half);
    n - ra - rb
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat3, Vec3};

    fn unit_box(center: Vec3) -> Obb {
        Obb::new(center, Mat3::identity(), Vec3::new(1.0, 1.0, 1.0))
    }

    #[test]
    fn face_touching_boxes_collide_and_a_gap_separates() {
        let a = unit_box(Vec3::zeros());
        assert!(obbs_intersect(&a, &unit_box(Vec3::new(2.0, 0.0, 0.0))));
        assert_eq!(separating_axis(&a, &unit_box(Vec3::new(2.001, 0.0, 0.0))), Some(Axis(0)));
    }

    #[test]
    fn hint_is_returned_when_it_still_separates() {
        let a = unit_box(Vec3::zeros());
        let b = unit_box(Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(separating_axis_hinted(&a, &b, Axis(5)), Some(Axis(5)));
        assert_eq!(separating_axis_hinted(&a, &b, Axis(0)), Some(Axis(2)));
    }

    /// The unrolled test and the per-axis formula agree axis by axis: for every axis `k`
    /// that the unrolled test returns, no earlier axis separates and `k` does.
    #[test]
    fn unrolled_axes_match_the_generic_formula() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
        };
        let mut seen = [0usize; 16];
        for _ in 0..200_000 {
            let rot = |x: Real, y: Real, z: Real| *nalgebra::Rotation3::from_euler_angles(x * 3.2, y * 3.2, z * 3.2).matrix();
            let a = Obb::new(Vec3::zeros(), rot(next(), next(), next()), Vec3::new(3.0 + next(), 2.0 + next(), 1.5 + next()));
            let c = Vec3::new(next(), next(), next()) * 6.0;
            let b = Obb::new(c, rot(next(), next(), next()), Vec3::new(3.0 + next(), 2.0 + next(), 1.5 + next()));
            let (pa, pb) = (PreparedBox::new(&a), PreparedBox::new(&b));
            let rel = relative(&pa, &pb);
            let generic = (0..Axis::COUNT).find(|&k| separates(k, &pa.h, &pb.h, &rel)).map(Axis);
            let got = separating_axis(&a, &b);
            assert_eq!(got, generic, "{a:?} {b:?}");
            seen[got.map_or(15, |k| k.0 as usize)] += 1;
            for hint in 0..Axis::COUNT {
                assert_eq!(separating_axis_hinted(&a, &b, Axis(hint)).is_none(), got.is_none());
            }
        }
        assert!(seen.iter().all(|&n| n > 0), "every axis (and 'intersect') is exercised: {seen:?}");
    }

    #[test]
    fn aabb_pre_reject_never_rejects_an_intersecting_pair() {
        let a = unit_box(Vec3::zeros());
        let rot = *nalgebra::Rotation3::from_euler_angles(0.3, 0.2, 0.9).matrix();
        for k in 0..200 {
            let b = Obb::new(Vec3::new(k as Real * 0.02, 0.3, -0.1), rot, Vec3::new(1.0, 0.5, 0.25));
            let (pa, pb) = (PreparedBox::new(&a), PreparedBox::new(&b));
            if aabbs_disjoint(&pa, &pb) {
                assert!(separating_axis(&a, &b).is_some());
            }
        }
    }
}
