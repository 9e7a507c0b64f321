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

/// A box as the unrolled test reads it: axes as rows. Built on the fly from an [`Obb`]; when
/// inlined this is only a view of the box's fields (no copy of arrays of boxes: on this
/// machine a moved array of prepared boxes cost more than the tests themselves).
#[derive(Clone, Copy)]
struct Flat {
    c: [Real; 3],
    u: [[Real; 3]; 3],
    h: [Real; 3],
}

#[inline(always)]
fn flat(b: &Obb) -> Flat {
    let m = &b.axes;
    Flat {
        c: [b.center.x, b.center.y, b.center.z],
        u: [
            [m[(0, 0)], m[(1, 0)], m[(2, 0)]],
            [m[(0, 1)], m[(1, 1)], m[(2, 1)]],
            [m[(0, 2)], m[(1, 2)], m[(2, 2)]],
        ],
        h: [b.half.x, b.half.y, b.half.z],
    }
}

/// Half-extents of the world-axis-aligned box around `b`, rounded up by a relative 1e-12 so
/// that [`aabbs_disjoint`] can only err toward "overlap".
#[inline]
pub fn aabb_half_rounded_up(b: &Obb) -> [Real; 3] {
    let m = &b.axes;
    core::array::from_fn(|k| {
        (m[(k, 0)].abs() * b.half.x + m[(k, 1)].abs() * b.half.y + m[(k, 2)].abs() * b.half.z)
            * (1.0 + 1e-12)
    })
}

/// Whether the world-axis-aligned boxes around `a` and `b` (half-extents `ea`, `eb` from
/// [`aabb_half_rounded_up`]) are apart by more than the touch tolerance: a cheap, exact-safe
/// reason for "no intersection".
#[inline(always)]
pub fn aabbs_disjoint(a: &Obb, ea: &[Real; 3], b: &Obb, eb: &[Real; 3]) -> bool {
    let d = b.center - a.center;
    (d.x.abs() > ea[0] + eb[0] + SAT_TOUCH_TOLERANCE)
        | (d.y.abs() > ea[1] + eb[1] + SAT_TOUCH_TOLERANCE)
        | (d.z.abs() > ea[2] + eb[2] + SAT_TOUCH_TOLERANCE)
}

/// `A_i . B_j` for j = 0..3: row `i` of `r_ab`.
#[inline(always)]
fn r_row(a: &Flat, b: &Flat, i: usize) -> [Real; 3] {
    [dot(&a.u[i], &b.u[0]), dot(&a.u[i], &b.u[1]), dot(&a.u[i], &b.u[2])]
}

#[inline(always)]
fn guarded(row: &[Real; 3]) -> [Real; 3] {
    [row[0].abs() + SAT_EPSILON, row[1].abs() + SAT_EPSILON, row[2].abs() + SAT_EPSILON]
}

#[inline(always)]
fn translation(a: &Flat, b: &Flat) -> [Real; 3] {
    let d = [b.c[0] - a.c[0], b.c[1] - a.c[1], b.c[2] - a.c[2]];
    [dot(&a.u[0], &d), dot(&a.u[1], &d), dot(&a.u[2], &d)]
}

#[inline(always)]
fn relative(a: &Flat, b: &Flat) -> Relative {
    let r = [r_row(a, b, 0), r_row(a, b, 1), r_row(a, b, 2)];
    Relative { ar: [guarded(&r[0]), guarded(&r[1]), guarded(&r[2])], r, t: translation(a, b) }
}

/// Face axis `A_i`: `|t_i| > a_i + sum_j b_j |R_ij|` (the optimised form of thesis 3.1.3).
#[inline(always)]
fn face_a_separates(
    i: usize,
    t: &[Real; 3],
    ar_i: &[Real; 3],
    a: &[Real; 3],
    b: &[Real; 3],
) -> bool {
    t[i].abs() > a[i] + b[0] * ar_i[0] + b[1] * ar_i[1] + b[2] * ar_i[2] + SAT_TOUCH_TOLERANCE
}

/// Face axis `B_j`: `|t . R_*j| > sum_i a_i |R_ij| + b_j`.
#[inline(always)]
fn face_b_separates(j: usize, a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> bool {
    let (r, ar, t) = (&rel.r, &rel.ar, &rel.t);
    let s = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
    s.abs() > a[0] * ar[0][j] + a[1] * ar[1][j] + a[2] * ar[2][j] + b[j] + SAT_TOUCH_TOLERANCE
}

/// Edge axis `A_i x B_j`, with `(i, i1, i2)` and `(j, j1, j2)` cyclic; left side by
/// Observation 3.1.2: `|t_i2 R_i1j - t_i1 R_i2j| > a_i1 |R_i2j| + a_i2 |R_i1j| + b_j1 |R_ij2| +
/// b_j2 |R_ij1|`.
#[inline(always)]
fn edge_separates(i: usize, j: usize, a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> bool {
    let (r, ar, t) = (&rel.r, &rel.ar, &rel.t);
    let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
    let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
    let s = t[i2] * r[i1][j] - t[i1] * r[i2][j];
    s.abs()
        > a[i1] * ar[i2][j]
            + a[i2] * ar[i1][j]
            + b[j1] * ar[i][j2]
            + b[j2] * ar[i][j1]
            + SAT_TOUCH_TOLERANCE
}

/// Whether the single axis `axis` separates the boxes (beyond the touch tolerance).
#[inline(always)]
fn separates(axis: u8, a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> bool {
    match axis {
        0..=2 => face_a_separates(axis as usize, &rel.t, &rel.ar[axis as usize], a, b),
        3..=5 => face_b_separates(axis as usize - 3, a, b, rel),
        _ => edge_separates((axis as usize - 6) / 3, (axis as usize - 6) % 3, a, b, rel),
    }
}

/// B's face axes and the nine edge axes, in [`Axis`] order; the first that separates.
#[inline(always)]
fn first_separating_b_and_edges(a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> Option<Axis> {
    // L = B0, B1, B2: B's face normals.
    if face_b_separates(0, a, b, rel) {
        return Some(Axis(3));
    }
    if face_b_separates(1, a, b, rel) {
        return Some(Axis(4));
    }
    if face_b_separates(2, a, b, rel) {
        return Some(Axis(5));
    }
    // L = A0 x B0: |t2 R10 - t1 R20| > a1 |R20| + a2 |R10| + b1 |R02| + b2 |R01|
    if edge_separates(0, 0, a, b, rel) {
        return Some(Axis(6));
    }
    // L = A0 x B1: |t2 R11 - t1 R21| > a1 |R21| + a2 |R11| + b2 |R00| + b0 |R02|
    if edge_separates(0, 1, a, b, rel) {
        return Some(Axis(7));
    }
    // L = A0 x B2: |t2 R12 - t1 R22| > a1 |R22| + a2 |R12| + b0 |R01| + b1 |R00|
    if edge_separates(0, 2, a, b, rel) {
        return Some(Axis(8));
    }
    // L = A1 x B0: |t0 R20 - t2 R00| > a2 |R00| + a0 |R20| + b1 |R12| + b2 |R11|
    if edge_separates(1, 0, a, b, rel) {
        return Some(Axis(9));
    }
    // L = A1 x B1: |t0 R21 - t2 R01| > a2 |R01| + a0 |R21| + b2 |R10| + b0 |R12|
    if edge_separates(1, 1, a, b, rel) {
        return Some(Axis(10));
    }
    // L = A1 x B2: |t0 R22 - t2 R02| > a2 |R02| + a0 |R22| + b0 |R11| + b1 |R10|
    if edge_separates(1, 2, a, b, rel) {
        return Some(Axis(11));
    }
    // L = A2 x B0: |t1 R00 - t0 R10| > a0 |R10| + a1 |R00| + b1 |R22| + b2 |R21|
    if edge_separates(2, 0, a, b, rel) {
        return Some(Axis(12));
    }
    // L = A2 x B1: |t1 R01 - t0 R11| > a0 |R11| + a1 |R01| + b2 |R20| + b0 |R22|
    if edge_separates(2, 1, a, b, rel) {
        return Some(Axis(13));
    }
    // L = A2 x B2: |t1 R02 - t0 R12| > a0 |R12| + a1 |R02| + b0 |R21| + b1 |R20|
    if edge_separates(2, 2, a, b, rel) {
        return Some(Axis(14));
    }
    None
}

/// The first axis (in [`Axis`] order) that separates the boxes, or `None`. Rows of `r_ab`
/// are computed only as A's face axes need them, so that the common early exits cost a
/// third of the products.
#[inline(always)]
fn first_separating_axis(a: &Flat, b: &Flat) -> Option<Axis> {
    let (ha, hb) = (&a.h, &b.h);
    let t = translation(a, b);
    // L = A0: |t0| > a0 + b . |R0*|
    let r0 = r_row(a, b, 0);
    let ar0 = guarded(&r0);
    if face_a_separates(0, &t, &ar0, ha, hb) {
        return Some(Axis(0));
    }
    // L = A1: |t1| > a1 + b . |R1*|
    let r1 = r_row(a, b, 1);
    let ar1 = guarded(&r1);
    if face_a_separates(1, &t, &ar1, ha, hb) {
        return Some(Axis(1));
    }
    // L = A2: |t2| > a2 + b . |R2*|
    let r2 = r_row(a, b, 2);
    let ar2 = guarded(&r2);
    if face_a_separates(2, &t, &ar2, ha, hb) {
        return Some(Axis(2));
    }
    first_separating_b_and_edges(ha, hb, &Relative { r: [r0, r1, r2], ar: [ar0, ar1, ar2], t })
}

/// As [`first_separating_axis`], but tries `hint` first.
#[inline(always)]
fn first_separating_axis_hinted(a: &Flat, b: &Flat, hint: Axis) -> Option<Axis> {
    let rel = relative(a, b);
    let (ha, hb) = (&a.h, &b.h);
    if separates(hint.0, ha, hb, &rel) {
        return Some(hint);
    }
    // L = A0, A1, A2: A's face normals.
    for i in 0..3 {
        if face_a_separates(i, &rel.t, &rel.ar[i], ha, hb) {
            return Some(Axis(i as u8));
        }
    }
    first_separating_b_and_edges(ha, hb, &rel)
}

/// The first axis (in [`Axis`] order) that separates `a` and `b`, or `None` when the boxes
/// intersect.
///
/// Boxes are closed: touching boxes intersect.
#[inline]
pub fn separating_axis(a: &Obb, b: &Obb) -> Option<Axis> {
    first_separating_axis(&flat(a), &flat(b))
}

/// As [`separating_axis`], but tries `hint` (for example last tick's witness) first, then
/// the others.
#[inline]
pub fn separating_axis_hinted(a: &Obb, b: &Obb, hint: Axis) -> Option<Axis> {
    first_separating_axis_hinted(&flat(a), &flat(b), hint)
}

/// Whether the two closed boxes intersect.
#[inline]
pub fn obbs_intersect(a: &Obb, b: &Obb) -> bool {
    separating_axis(a, b).is_none()
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

    /// The per-axis formula written with index arithmetic, independently of the helpers.
    fn generic_separates(axis: u8, a: &[Real; 3], b: &[Real; 3], rel: &Relative) -> bool {
        let (r, ar, t) = (&rel.r, &rel.ar, &rel.t);
        let (dist, ra, rb) = match axis {
            0..=2 => {
                let i = axis as usize;
                (t[i].abs(), a[i], b[0] * ar[i][0] + b[1] * ar[i][1] + b[2] * ar[i][2])
            }
            3..=5 => {
                let j = axis as usize - 3;
                let tb = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
                (tb.abs(), a[0] * ar[0][j] + a[1] * ar[1][j] + a[2] * ar[2][j], b[j])
            }
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

    /// The unrolled test and the per-axis formula agree axis by axis: for every axis `k`
    /// that the unrolled test returns, no earlier axis separates and `k` does.
    #[test]
    fn unrolled_axes_match_the_generic_formula() {
        let mut rng = crate::test_rng::TestRng(0x9e37_79b9_7f4a_7c15_u64);
        let mut next = move || rng.unit();
        let mut seen = [0usize; 16];
        for _ in 0..200_000 {
            let rot = |x: Real, y: Real, z: Real| {
                *nalgebra::Rotation3::from_euler_angles(x * 3.2, y * 3.2, z * 3.2).matrix()
            };
            let a = Obb::new(
                Vec3::zeros(),
                rot(next(), next(), next()),
                Vec3::new(3.0 + next(), 2.0 + next(), 1.5 + next()),
            );
            let c = Vec3::new(next(), next(), next()) * 6.0;
            let b = Obb::new(
                c,
                rot(next(), next(), next()),
                Vec3::new(3.0 + next(), 2.0 + next(), 1.5 + next()),
            );
            let (pa, pb) = (flat(&a), flat(&b));
            let rel = relative(&pa, &pb);
            let generic =
                (0..Axis::COUNT).find(|&k| generic_separates(k, &pa.h, &pb.h, &rel)).map(Axis);
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
            let b =
                Obb::new(Vec3::new(k as Real * 0.02, 0.3, -0.1), rot, Vec3::new(1.0, 0.5, 0.25));
            if aabbs_disjoint(&a, &aabb_half_rounded_up(&a), &b, &aabb_half_rounded_up(&b)) {
                assert!(separating_axis(&a, &b).is_some());
            }
        }
    }
}
