//! Oriented boxes, the exact test between two of them (thesis 2.4 and 3.1, SPEC §3), their
//! distance (for reports and pictures) and their signed clearance (SPEC §8).

pub mod clearance;
pub mod distance;
pub mod obb;
pub mod sat;
pub mod sweep;
pub mod witness;

pub use clearance::{
    boxes_clearance, boxes_clearance_lower_bound, obb_clearance, obb_clearance_lower_bound, Clearance, PairClearance,
};
pub use distance::obb_distance;
pub use obb::Obb;
pub use sat::{obbs_intersect, separating_axis, separating_axis_hinted, Axis};
pub use sweep::{swept_boxes_apart, Sweep};
pub use witness::{first_intersecting_pair, WitnessCache};

/// A small xorshift generator for the geometry unit tests: reproducible, no dependency.
#[cfg(test)]
pub(crate) struct TestRng(pub u64);

#[cfg(test)]
impl TestRng {
    /// The next value, uniform in `[-1, 1)`.
    pub fn unit(&mut self) -> crate::math::Real {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as crate::math::Real / (1u64 << 53) as crate::math::Real * 2.0 - 1.0
    }

    /// A vector with components uniform in `[-s, s)`.
    pub fn vec(&mut self, s: crate::math::Real) -> crate::math::Vec3 {
        crate::math::Vec3::new(self.unit(), self.unit(), self.unit()) * s
    }
}
