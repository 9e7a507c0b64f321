//! Oriented boxes, the exact test between two of them (thesis 2.4 and 3.1, SPEC §3), their
//! distance (for reports and pictures) and their signed clearance (SPEC §8).

pub mod clearance;
pub mod distance;
pub mod graded_closest;
pub mod obb;
pub mod sat;
pub mod sweep;
pub mod witness;

pub use clearance::{
    boxes_clearance, boxes_clearance_lower_bound, obb_clearance, obb_clearance_lower_bound,
    Clearance, CoherentClearance, PairClearance,
};
pub use distance::obb_distance;
pub use obb::Obb;
pub use sat::{obbs_intersect, separating_axis, separating_axis_hinted, Axis};
pub use sweep::{swept_boxes_apart, Sweep};
pub use witness::{first_intersecting_pair, WitnessCache};

/// Most boxes in one set of the all-pairs tests and the witness cache ([`witness`]): one
/// robot's boxes (3 lower links, 3 upper links, platform, tool), in fixed arrays so that no
/// test allocates.
pub const MAX_BOXES: usize = 8;
