//! The oriented bounding box (OBB) that models one link (thesis 2.4.1, Figure 2.9; SPEC §3).
//!
//! # Conventions
//! `axes` holds the box's unit axes as columns (x along the link, y across the
//! parallelogram, z across the link in the arm's plane); `half` holds the half-extents
//! `(W, H, D)` along them. Boxes are closed sets: a box touches everything on its surface.

use crate::math::{Mat3, Real, Vec3};

/// An oriented box: centre, orthonormal axes (columns of `axes`) and half-extents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Centre of the box.
    pub center: Vec3,
    /// Unit axes of the box as the columns of a rotation matrix.
    pub axes: Mat3,
    /// Half-extents along the three axes (all >= 0).
    pub half: Vec3,
}

impl Obb {
    /// A box from its centre, axes (columns) and half-extents.
    pub fn new(center: Vec3, axes: Mat3, half: Vec3) -> Self {
        Obb { center, axes, half }
    }

    /// The same box with every half-extent enlarged by `margin` (the "blown-up" model).
    pub fn inflated(&self, margin: Real) -> Obb {
        Obb { half: self.half.add_scalar(margin), ..*self }
    }

    /// The box moved by the rigid motion `p -> rot * p + t`.
    pub fn transformed(&self, rot: &Mat3, t: &Vec3) -> Obb {
        Obb { center: rot * self.center + t, axes: rot * self.axes, half: self.half }
    }

    /// The point of the box nearest to `p`: `p`'s box coordinates clamped to the
    /// half-extents (Ericson, *Real-Time Collision Detection*, 5.1.4).
    pub fn closest_point(&self, p: &Vec3) -> Vec3 {
        let local = self.axes.tr_mul(&(p - self.center));
        self.center + self.axes * Vec3::from_fn(|k, _| local[k].clamp(-self.half[k], self.half[k]))
    }

    /// Half-extents of the axis-aligned box that encloses this box.
    pub fn aabb_half(&self) -> Vec3 {
        self.axes.abs() * self.half
    }

    /// The eight corners of the box.
    pub fn vertices(&self) -> [Vec3; 8] {
        let mut out = [Vec3::zeros(); 8];
        for (i, v) in out.iter_mut().enumerate() {
            let s = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            *v = self.center + self.axes * s.component_mul(&self.half);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aabb_of_rotated_box_contains_its_vertices() {
        let rot = *nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 2.0).matrix();
        let b = Obb::new(Vec3::new(1.0, 2.0, 3.0), rot, Vec3::new(200.0, 70.0, 17.5));
        let h = b.aabb_half();
        for v in b.vertices() {
            let d = (v - b.center).abs();
            assert!(d.x <= h.x + 1e-9 && d.y <= h.y + 1e-9 && d.z <= h.z + 1e-9);
        }
    }

    #[test]
    fn inflating_grows_every_half_extent() {
        let b = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.inflated(0.5).half, Vec3::new(1.5, 2.5, 3.5));
    }
}
