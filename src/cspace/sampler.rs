//! The workspace of one robot and its sampling grid (thesis 3.2.2, Algorithm 1 with the bounds
//! fixed as SPEC §4 says).
//!
//! # Conventions
//! Spacing `r = max(Rcy, Zu + Hcy + Hco) / k`, `k = 2^levels`. The grid is the cube of `k`
//! cells per axis with corner `origin = (-k r / 2, -k r / 2, -k r)`: x and y centred on the
//! robot's axis, z from `-k r` up to 0. Cell `(ix, iy, iz)` has centre
//! `origin + r (ix + 1/2, iy + 1/2, iz + 1/2)`. A cell is sampled when its depth layer
//! overlaps the workspace's depth range and its centre lies within `c_r + r / sqrt(2)` of the
//! axis, `c_r` the workspace radius at the centre's depth.

use crate::math::{Real, Vec3};

/// Cylinder + frustum workspace of one robot (thesis 3.2.2, SPEC §4); depth `d = -z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Workspace {
    /// Depth of the cylinder's top.
    pub zu: Real,
    /// Height of the cylinder.
    pub hcy: Real,
    /// Radius of the cylinder.
    pub rcy: Real,
    /// Height of the frustum below the cylinder.
    pub hco: Real,
    /// Radius at the frustum's bottom.
    pub rco: Real,
}

impl Workspace {
    /// The thesis's values: Zu 365, Hcy 135, Rcy 225, Hco 30, Rco 173.
    pub const THESIS: Workspace = Workspace { zu: 365.0, hcy: 135.0, rcy: 225.0, hco: 30.0, rco: 173.0 };
}

/// Grid index of one robot's cell: `(ix, iy, iz)`, each in `0..k`.
pub type CellIndex = [u16; 3];

/// The sampled cells of one robot's grid.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleGrid {
    /// Cells per axis, `2^levels`.
    pub k: u32,
    /// Quadtree levels, `log2 k`.
    pub levels: u32,
    /// Cell side (mm).
    pub r: Real,
    /// Corner of the grid cube with the smallest coordinates (mm, MCS).
    pub origin: Vec3,
    /// Sampled cells in lexicographic `(ix, iy, iz)` order.
    pub cells: Vec<CellIndex>,
    /// Whether each sampled cell's centre is reachable (same order as `cells`).
    pub reachable: Vec<bool>,
}
