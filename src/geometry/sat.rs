//! The separating axis test (SAT) for two oriented boxes, 15 axes (thesis 3.1.2-3.1.3).
//!
//! The two boxes overlap exactly when none of the 15 candidate axes separates their
//! projections: the three face normals of each box and the nine cross products of an edge
//! of one with an edge of the other (Gottschalk et al.). All work happens in A's frame:
//! `r_ab = A^T B` and `t_ab = A^T (c_B - c_A)` ("B expressed in A's frame").
//!
//! # Numerics
//! `|r_ab|` is enlarged by [`SAT_EPSILON`] so that a cross-product axis of nearly parallel
//! edges, whose length is close to zero, cannot separate by rounding alone; an axis separates
//! only when the gap exceeds [`SAT_TOUCH_TOLERANCE`]. Both err toward collision; touching
//! boxes collide.

use crate::geometry::obb::Obb;
use crate::math::{Mat3, Real, Vec3, SAT_EPSILON, SAT_TOUCH_TOLERANCE};

/// One of the 15 candidate separating axes.
///
/// `0..3`: A's axes x, y, z; `3..6`: B's axes; `6 + 3 i + j`: `A_i x B_j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Axis(pub u8);

impl Axis {
    /// The number of candidate axes.
    pub const COUNT: u8 = 15;
}

/// The rotation and translation of B in A's frame, with the guarded `|R|`.
struct Relative {
    r: Mat3,
    abs_r: Mat3,
    t: Vec3,
}

fn relative(a: &Obb, b: &Obb) -> Relative {
    let r = a.axes.tr_mul(&b.axes);
    let abs_r = r.abs().add_scalar(SAT_EPSILON);
    let t = a.axes.tr_mul(&(b.center - a.center));
    Relative { r, abs_r, t }
}

/// Whether `axis` separates the two boxes (strictly, beyond the touch tolerance).
fn separates(axis: u8, a: &Vec3, b: &Vec3, rel: &Relative) -> bool {
    let (r, ar, t) = (&rel.r, &rel.abs_r, &rel.t);
    let (dist, ra, rb) = match axis {
        // A's face normals: |t_i| vs a_i + sum_j b_j |R_ij|.
        0..=2 => {
            let i = axis as usize;
            (t[i].abs(), a[i], b[0] * ar[(i, 0)] + b[1] * ar[(i, 1)] + b[2] * ar[(i, 2)])
        }
        // B's face normals: |t . B_j| vs sum_i a_i |R_ij| + b_j.
        3..=5 => {
            let j = axis as usize - 3;
            let tb = t[0] * r[(0, j)] + t[1] * r[(1, j)] + t[2] * r[(2, j)];
            (tb.abs(), a[0] * ar[(0, j)] + a[1] * ar[(1, j)] + a[2] * ar[(2, j)], b[j])
        }
        // A_i x B_j: with (i, i1, i2) and (j, j1, j2) cyclic,
        // |t_i2 R_i1j - t_i1 R_i2j| vs a_i1 |R_i2j| + a_i2 |R_i1j| + b_j1 |R_ij2| + b_j2 |R_ij1|.
        _ => {
            let k = axis as usize - 6;
            let (i, j) = (k / 3, k % 3);
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            (
                (t[i2] * r[(i1, j)] - t[i1] * r[(i2, j)]).abs(),
                a[i1] * ar[(i2, j)] + a[i2] * ar[(i1, j)],
                b[j1] * ar[(i, j2)] + b[j2] * ar[(i, j1)],
            )
        }
    };
    dist > ra + rb + SAT_TOUCH_TOLERANCE
}

/// The first axis that separates `a` and `b`, or `None` when the boxes intersect.
///
/// Boxes are closed: touching boxes intersect.
pub fn separating_axis(a: &Obb, b: &Obb) -> Option<Axis> {
    let rel = relative(a, b);
    (0..Axis::COUNT).find(|&k| separates(k, &a.half, &b.half, &rel)).map(Axis)
}

/// As [`separating_axis`], but tries `hint` (for example last tick's witness) first.
pub fn separating_axis_hinted(a: &Obb, b: &Obb, hint: Axis) -> Option<Axis> {
    let rel = relative(a, b);
    if separates(hint.0, &a.half, &b.half, &rel) {
        return Some(hint);
    }
    (0..Axis::COUNT)
        .filter(|&k| k != hint.0)
        .find(|&k| separates(k, &a.half, &b.half, &rel))
        .map(Axis)
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
}
