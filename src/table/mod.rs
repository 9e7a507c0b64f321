//! Precomputed tables of the configuration space: the three linear quadtrees of the thesis,
//! the shared 6-D quadtree, their file format, and one [`Table`] enum to query them
//! (thesis 3.2.4-3.2.6 and 3.2.8; SPEC §6).
//!
//! A table answers "is the 6-D grid cell `(ix, iy, iz, ix', iy', iz')` a collision" without
//! allocating. Built from a [`LabelledSpace`](crate::cspace::LabelledSpace), it reports
//! `false` for every free sample and `true` for every collision sample (lossy 4-D tables with
//! `t > 0` may also report `true` for free samples; a subdivided shared table answers per
//! sub-cell, [`Table::sub_levels`]). Unreachable pairs and cells outside the sampled grid are
//! "don't care": the answer there is whatever compressed best, so the caller must check
//! reachability and the workspace itself ([`TableChecker`] does). Indices beyond the grid
//! answer `true`.
//!
//! Without the `std` feature this module holds the query side only: loading a table from
//! bytes ([`from_bytes`], needs `alloc`), the queries of every variant and [`TableChecker`]
//! (docs/PORTABILITY.md). The builders ([`build`], `build` of each
//! variant, [`synthetic`]) need `std`.

#[cfg(feature = "std")]
pub(crate) mod build;
pub mod bundle;
mod bundle_checker;
pub mod clearance;
pub mod code;
pub(crate) mod error;
pub mod format;
mod kind;
pub(crate) mod lookup;
#[cfg(feature = "std")]
pub mod memory;
pub(crate) mod quadtree4d;
pub(crate) mod quadtree5d;
pub(crate) mod quadtree6d;
mod reader;
#[cfg(feature = "std")]
pub mod shard;
pub(crate) mod shared6d;
mod space;
#[cfg(feature = "std")]
pub mod synthetic;

#[cfg(test)]
mod agreement_tests;

use alloc::{format, string::String};
#[cfg(feature = "eval")]
use alloc::{vec, vec::Vec};
#[cfg(feature = "std")]
pub use build::{
    build_table, build_table_bounded, build_tables, memory_plan, BoundedBuild, BuildReport,
    Labelling,
};
pub use bundle::{bundle_from_bytes, bundle_to_bytes, is_bundle, pair_cell, Bundle, BundlePair};
pub use bundle_checker::{BundleChecker, PairAnswer};
pub use clearance::{ClearanceTable, Ladder};
#[cfg(feature = "std")]
pub use error::BuildError;
pub use error::TableError;
pub use format::{from_bytes, to_bytes, Certification, Header};
pub use kind::{TableKind, UnknownTableKind, Variant};
pub use lookup::{Confirmation, TableAnswer, TableChecker};
#[cfg(feature = "std")]
pub use memory::{default_max_memory, parse_bytes, MemoryPlan, DEFAULT_MAX_MEMORY};
#[cfg(feature = "eval")]
pub use quadtree4d::{subdivided_slices, SliceBound};
pub use quadtree4d::{LinearQuadtree4d, SliceAxes};
pub use quadtree5d::LinearQuadtree5d;
pub use quadtree6d::LinearQuadtree6d;
pub use shared6d::{ChildIndices, SharedParts, SharedQuadtree6d};

/// One of the three table variants of the thesis (3.2.4, 3.2.5, 3.2.6) or the shared 6-D
/// quadtree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Table {
    /// Linear 6-D quadtree, condensed.
    D6(LinearQuadtree6d),
    /// Linear 5-D quadtree with `iz'` intervals.
    D5(LinearQuadtree5d),
    /// Linear 4-D quadtree with grouped 2-D slices.
    D4(LinearQuadtree4d),
    /// 6-D quadtree with shared subtrees (beyond the thesis).
    Shared(SharedQuadtree6d),
    /// Certified clearance levels per grid cell (two shared 6-D quadtrees; boxed, being the
    /// largest variant by far).
    Clearance(alloc::boxed::Box<ClearanceTable>),
}

impl Table {
    /// Whether the 6-D cell is stored as collision, its indices at `2^(levels + sub_levels)`
    /// per axis (`true` also for an index beyond). Never allocates, never panics.
    #[inline]
    pub fn query(&self, cell6: [u16; 6]) -> bool {
        match self {
            Table::D6(t) => t.query(cell6),
            Table::D5(t) => t.query(cell6),
            Table::D4(t) => t.query(cell6),
            Table::Shared(t) => t.query(cell6),
            Table::Clearance(t) => t.query(cell6),
        }
    }

    /// The clearance table, when this is one.
    pub fn as_clearance(&self) -> Option<&ClearanceTable> {
        match self {
            Table::Clearance(t) => Some(t),
            _ => None,
        }
    }

    /// Whether any configuration of the grid cell `cell` (indices at `k`) is stored as
    /// collision: [`query`](Self::query) itself, or over its 64 sub-cells for a subdivided
    /// table. For pictures and reports, not the per-tick path.
    pub fn query_grid_cell(&self, cell: [u16; 6]) -> bool {
        match self.sub_levels() {
            0 => self.query(cell),
            _ => (0..64u16)
                .any(|c| self.query(core::array::from_fn(|j| 2 * cell[j] + (c >> (5 - j) & 1)))),
        }
    }

    /// Quadtree levels; cells per axis `k = 2^levels`.
    pub fn levels(&self) -> u32 {
        match self {
            Table::D6(t) => t.levels(),
            Table::D5(t) => t.levels(),
            Table::D4(t) => t.levels(),
            Table::Shared(t) => t.levels(),
            Table::Clearance(t) => t.levels(),
        }
    }

    /// Extra levels of sub-cells below the sampled grid (the subdivided shared table: 1;
    /// otherwise 0): [`query`](Self::query) takes indices at `2^(levels + sub_levels)`.
    pub fn sub_levels(&self) -> u32 {
        match self {
            Table::Shared(t) => t.sub_levels(),
            _ => 0,
        }
    }

    /// Whether only A's upper half is stored (reflection symmetry, thesis 3.2.8).
    pub fn symmetric(&self) -> bool {
        match self {
            Table::D6(t) => t.symmetric(),
            Table::D5(t) => t.symmetric(),
            Table::D4(t) => t.symmetric(),
            Table::Shared(t) => t.symmetric(),
            Table::Clearance(t) => t.symmetric(),
        }
    }

    /// Bytes the table occupies in memory.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Table::D6(t) => t.memory_bytes(),
            Table::D5(t) => t.memory_bytes(),
            Table::D4(t) => t.memory_bytes(),
            Table::Shared(t) => t.memory_bytes(),
            Table::Clearance(t) => t.memory_bytes(),
        }
    }

    /// The address and byte length of every array a query may read (for benchmarks that
    /// flush them from the caches between queries; the report tool).
    #[cfg(feature = "eval")]
    pub fn memory_regions(&self) -> Vec<(usize, usize)> {
        fn region<T>(v: &[T]) -> (usize, usize) {
            (v.as_ptr() as usize, core::mem::size_of_val(v))
        }
        match self {
            Table::D6(t) => vec![region(t.codes())],
            Table::D5(t) => {
                let (codes, offsets, intervals) = t.parts();
                vec![region(codes), region(offsets), region(intervals)]
            }
            Table::D4(t) => {
                let (codes, slice_of, slices) = t.parts();
                vec![region(codes), region(slice_of), region(slices)]
            }
            Table::Shared(t) => vec![t.memory_region()],
            Table::Clearance(t) => vec![t.exact_tree().memory_region(), t.level_region()],
        }
    }

    /// A short name: `6D`, `5D`, `4D/yy t=0`, `6D-shared`.
    pub fn name(&self) -> String {
        match self {
            Table::D6(_) => "6D".into(),
            Table::D5(_) => "5D".into(),
            Table::D4(t) => format!(
                "4D/{} t={}",
                if t.axes() == SliceAxes::YY { "yy" } else { "zz" },
                t.threshold()
            ),
            Table::Shared(t) if t.sub_levels() > 0 => "6D-shared/sub".into(),
            Table::Shared(_) => "6D-shared".into(),
            Table::Clearance(_) => "6D-clearance".into(),
        }
    }
}

/// Pairs of A's upper half (`iy >= k/2`) whose label and mirror image's label disagree as
/// free/collision: 0 for a cell that is reflection symmetric (thesis 3.2.8). Symmetric
/// tables stay safe either way (collision wins in the merge), but they answer some free
/// samples with collision when this is not 0.
///
/// # Errors
/// [`TableError::BadInput`] when the space is malformed.
#[cfg(feature = "std")]
pub fn symmetry_mismatches(space: &crate::cspace::LabelledSpace) -> Result<usize, TableError> {
    Ok(space::SpaceView::new(space, true)?.asymmetric_pairs())
}
