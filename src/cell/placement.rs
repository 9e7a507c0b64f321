//! Where a robot stands in the world: rotation about z, then translation (thesis 2.3, SPEC §1).
//!
//! `p_wcs = Rz(alpha) p_mcs + t`. Robots are never tilted about x or y.

use crate::geometry::Obb;
use crate::math::{float, Mat3, Real, Vec3};

/// A robot's placement: its MCS expressed in the WCS.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Rotation about z (rad).
    pub alpha: Real,
    /// Position of the MCS origin in the WCS (mm).
    pub t: Vec3,
}

impl Placement {
    /// The WCS itself (robot 0 by convention).
    pub const IDENTITY: Placement = Placement { alpha: 0.0, t: Vec3::new(0.0, 0.0, 0.0) };

    /// `Rz(alpha)`.
    pub fn rotation(&self) -> Mat3 {
        let (s, c) = float::sin_cos(self.alpha);
        Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    }

    /// A point of this robot's MCS in the WCS.
    pub fn to_wcs(&self, p_mcs: &Vec3) -> Vec3 {
        self.rotation() * p_mcs + self.t
    }

    /// A WCS point in this robot's MCS.
    pub fn to_mcs(&self, p_wcs: &Vec3) -> Vec3 {
        self.rotation().tr_mul(&(p_wcs - self.t))
    }

    /// A box given in this robot's MCS, expressed in the WCS.
    pub fn obb_to_wcs(&self, b: &Obb) -> Obb {
        b.transformed(&self.rotation(), &self.t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_rotation_sense() {
        let pl = Placement { alpha: core::f64::consts::FRAC_PI_2, t: Vec3::new(450.0, 0.0, 0.0) };
        // MCS x axis points along WCS +y after a quarter turn.
        assert!((pl.to_wcs(&Vec3::new(1.0, 0.0, 0.0)) - Vec3::new(450.0, 1.0, 0.0)).norm() < 1e-12);
        let p = Vec3::new(12.0, -7.0, -400.0);
        assert!((pl.to_mcs(&pl.to_wcs(&p)) - p).norm() < 1e-12);
    }
}
