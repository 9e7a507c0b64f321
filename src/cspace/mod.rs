//! The configuration space of two robots, discretised: workspace, sampling grid, labels
//! (thesis 3.2.2-3.2.3, 3.2.7-3.2.8; SPEC §4, §6).
//!
//! A two-robot configuration is `c = (x, y, z, x', y', z')`: robot A's TCP in A's MCS and
//! robot B's TCP in B's MCS. Each robot's TCP space is cut into cubic grid cells of side `r`
//! aligned with the quadtree leaves; a sample is a cell centre.
//!
//! Without the `std` feature only the workspace, the sampling grid, the symmetry test and the
//! label types are here (loading a table needs them); labelling and certification need `std`.

#[cfg(feature = "std")]
pub(crate) mod certify;
#[cfg(feature = "std")]
pub mod guarantee;
#[cfg(feature = "std")]
pub(crate) mod label;
pub mod pair_labels;
pub mod sampler;
#[cfg(feature = "std")]
pub(crate) mod swept_sat;
pub mod symmetry;

#[cfg(feature = "eval")]
pub use certify::SubdividedLabels;
#[cfg(feature = "std")]
pub use certify::{
    label_space_certified, label_space_certified_with, label_space_subdivided, CertifiedSpace,
    CertifyConfig, Refinement, SubCells,
};
#[cfg(feature = "std")]
pub use label::{label_space, label_space_thesis, Progress, Rows};
pub use pair_labels::PairLabels;
pub use sampler::{CellIndex, SampleGrid, Workspace};
pub use symmetry::Symmetry;

/// The label of one two-robot sample (one 6-D grid cell).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Label {
    /// Proved free (or, for thesis-style tables, free at the cell centre with the margin).
    Free = 0,
    /// Collides (or could not be proved free).
    Collision = 1,
    /// One of the TCPs is unreachable: "don't care". Exact and thesis-style labellings mean
    /// the cell's *centre* (the thesis's convention: the cell may still hold reachable TCPs);
    /// the certified labelling means the *whole cell*, proved, so it cannot occur in operation.
    Unreachable = 2,
}

/// Labels of every pair of samples of two robots' grids.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelledSpace {
    /// Robot A's grid.
    pub grid_a: SampleGrid,
    /// Robot B's grid.
    pub grid_b: SampleGrid,
    /// `labels[ia * grid_b.cells.len() + ib]` for sample `ia` of A and `ib` of B, a row per
    /// sample of A.
    pub labels: PairLabels,
    /// The margin (mm) added to every box half-extent when labelling.
    pub margin: f64,
}

impl LabelledSpace {
    /// The label of sample pair `(ia, ib)`.
    pub fn label(&self, ia: usize, ib: usize) -> Label {
        self.labels[ia * self.grid_b.cells.len() + ib]
    }
}
