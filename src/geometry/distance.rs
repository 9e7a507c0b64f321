//! The Euclidean distance between two oriented boxes (for reports and pictures, not the tick).
//!
//! Two disjoint convex polytopes have a closest pair of points in which one point is a vertex,
//! or both lie on edges: when a closest point lies inside a face and the other inside a face or
//! an edge, those features are parallel and the pair slides, at the same distance, until one
//! point reaches a vertex or an edge. So the distance of two disjoint boxes is the smallest of
//! the 16 vertex-to-box distances and the 144 edge-to-edge distances. Overlapping boxes (the
//! separating axis test finds no axis) are at distance 0.
//!
//! # Numerics
//! Closed boxes, as everywhere: touching boxes are at distance 0. A pair that
//! [`separating_axis`] calls intersecting is reported at exactly 0, so the distance is 0
//! exactly when the exact check reports a collision.

use crate::geometry::{separating_axis, Obb};
use crate::math::{Real, Vec3};

/// The distance (mm) between two closed boxes: 0 when they touch or overlap.
pub fn obb_distance(a: &Obb, b: &Obb) -> Real {
    if separating_axis(a, b).is_none() {
        return 0.0;
    }
    let (va, vb) = (a.vertices(), b.vertices());
    let mut d = Real::INFINITY;
    for v in &va {
        d = d.min(point_obb_distance(v, b));
    }
    for v in &vb {
        d = d.min(point_obb_distance(v, a));
    }
    for (p0, p1) in box_edges(&va) {
        for (q0, q1) in box_edges(&vb) {
            d = d.min(segment_distance(&p0, &p1, &q0, &q1));
        }
    }
    d
}

/// The distance from point `p` to the closed box `b` (0 inside).
pub fn point_obb_distance(p: &Vec3, b: &Obb) -> Real {
    let local = b.axes.tr_mul(&(p - b.center));
    let outside = Vec3::from_fn(|k, _| (local[k].abs() - b.half[k]).max(0.0));
    outside.norm()
}

/// The 12 edges of a box from its vertices, indexed by sign bits as [`Obb::vertices`] does.
fn box_edges(v: &[Vec3; 8]) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
    (0..8).flat_map(move |i| {
        (0..3).filter(move |k| i >> k & 1 == 0).map(move |k| (v[i], v[i | 1 << k]))
    })
}

/// The distance between segments `p0 p1` and `q0 q1` (Ericson, *Real-Time Collision
/// Detection*, 5.1.9); degenerate (zero-length) segments are points.
pub fn segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> Real {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t) = if a <= Real::EPSILON && e <= Real::EPSILON {
        (0.0, 0.0)
    } else if a <= Real::EPSILON {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= Real::EPSILON {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat3;

    fn cube(center: Vec3, half: Real) -> Obb {
        Obb::new(center, Mat3::identity(), Vec3::repeat(half))
    }

    #[test]
    fn face_edge_and_corner_gaps_of_axis_aligned_cubes() {
        let a = cube(Vec3::zeros(), 1.0);
        assert_eq!(obb_distance(&a, &cube(Vec3::new(5.0, 0.3, -0.2), 1.0)), 3.0, "face to face");
        let corner = obb_distance(&a, &cube(Vec3::new(4.0, 4.0, 4.0), 1.0));
        assert!((corner - 12f64.sqrt()).abs() < 1e-12, "corner to corner {corner}");
        assert_eq!(obb_distance(&a, &cube(Vec3::new(2.0, 0.0, 0.0), 1.0)), 0.0, "touching");
        assert_eq!(obb_distance(&a, &cube(Vec3::new(0.5, 0.5, 0.0), 1.0)), 0.0, "overlapping");
    }

    #[test]
    fn crossing_edges_of_two_turned_cubes() {
        // A turned 45 degrees about y has a top edge along y at z = sqrt 2; B turned 45 degrees
        // about x has a bottom edge along x: the closest features are these two crossing edges.
        let s = core::f64::consts::FRAC_1_SQRT_2;
        let about_y = Mat3::new(s, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, s);
        let about_x = Mat3::new(1.0, 0.0, 0.0, 0.0, s, -s, 0.0, s, s);
        let a = Obb::new(Vec3::zeros(), about_y, Vec3::repeat(1.0));
        let b = Obb::new(Vec3::new(0.0, 0.0, 2.0 * 2f64.sqrt() + 0.5), about_x, Vec3::repeat(1.0));
        let d = obb_distance(&a, &b);
        assert!((d - 0.5).abs() < 1e-12, "{d}");
        assert_eq!(segment_distance(&Vec3::zeros(), &Vec3::zeros(), &Vec3::x(), &Vec3::x()), 1.0);
    }
}
