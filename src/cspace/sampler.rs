//! The workspace of one robot and its sampling grid (thesis 3.2.2, Algorithm 1 with the bounds
//! fixed as SPEC §4 says).
//!
//! # Conventions
//! Spacing `r = max(Rcy, Zu + Hcy + Hco) / k`, `k = 2^levels`. The grid is the cube of `k`
//! cells per axis with corner `origin = (-k r / 2, -k r / 2, -k r)`: x and y centred on the
//! robot's axis, z from `-k r` up to 0. Cell `(ix, iy, iz)` is the closed cube of side `r`
//! with centre `origin + r (ix + 1/2, iy + 1/2, iz + 1/2)`; a point on a face shared by two
//! cells belongs to the one with the larger index ([`SampleGrid::cell_of`] floors).
//!
//! A cell is sampled when its depth layer meets the workspace's depth range and its centre
//! lies within `c_r + r / sqrt(2)` of the axis, where `c_r` is the largest workspace radius
//! over the part of the workspace's depth range that the layer covers. (The thesis evaluates
//! `c_r` at the centre's depth; in the frustum that misses a rim up to `r/2 * (Rcy - Rco) / Hco`
//! wide, about 14 mm at k = 32, so a workspace point could fall in an unsampled cell. With the
//! layer's largest radius every workspace point lies in a sampled cell: its cell's centre is
//! within the half-diagonal `r / sqrt(2)` of it horizontally.)
//!
//! # Numerics
//! Centres are computed as `r * (i + 1/2 - k/2)` so that the grid is exactly symmetric under
//! `y -> -y` in floating point (thesis 3.2.8 relies on it); membership tests err toward
//! keeping a cell.

use crate::math::{float, Real, Vec3};
use crate::robot::Delta3;
use alloc::{format, string::String, vec::Vec};

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
    pub const THESIS: Workspace =
        Workspace { zu: 365.0, hcy: 135.0, rcy: 225.0, hco: 30.0, rco: 173.0 };

    /// The workspace the tables of `cell` sample: thesis 3.2.2's, for every cell. The CLI
    /// builds with it and [`crate::table::TableChecker`] refuses a table that records another,
    /// since a wider workspace in a header would make cells that the table never labelled
    /// look sampled.
    pub fn for_cell(_cell: &crate::cell::Cell) -> Workspace {
        Workspace::THESIS
    }

    /// The deepest depth of the workspace, `Zu + Hcy + Hco`.
    pub fn max_depth(&self) -> Real {
        self.zu + self.hcy + self.hco
    }

    /// The largest radius at any depth.
    pub fn max_radius(&self) -> Real {
        self.rcy.max(self.rco)
    }

    /// The workspace radius at depth `d` (clamped into the depth range).
    pub fn radius_at(&self, d: Real) -> Real {
        let d = d.clamp(self.zu, self.max_depth());
        if d <= self.zu + self.hcy || self.hco == 0.0 {
            self.rcy
        } else {
            self.rcy + (self.rco - self.rcy) * (d - self.zu - self.hcy) / self.hco
        }
    }

    /// The largest workspace radius over the depths `[d0, d1]` intersected with the depth range,
    /// or `None` when they do not meet (closed intervals).
    pub fn max_radius_over(&self, d0: Real, d1: Real) -> Option<Real> {
        let (lo, hi) = (d0.max(self.zu), d1.min(self.max_depth()));
        if lo > hi {
            return None;
        }
        let knee = self.zu + self.hcy;
        let mut best = self.radius_at(lo).max(self.radius_at(hi));
        if lo <= knee && knee <= hi {
            best = best.max(self.rcy);
        }
        Some(best)
    }

    /// Whether the TCP `p` (MCS) lies in the workspace (closed).
    pub fn contains(&self, p: &Vec3) -> bool {
        let d = -p.z;
        d >= self.zu && d <= self.max_depth() && float::hypot(p.x, p.y) <= self.radius_at(d)
    }

    fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("Zu", self.zu),
            ("Hcy", self.hcy),
            ("Rcy", self.rcy),
            ("Hco", self.hco),
            ("Rco", self.rco),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("workspace {name} = {v} must be a finite length >= 0 (mm)"));
            }
        }
        if !(self.zu > 0.0 && self.rcy > 0.0 && self.hcy + self.hco > 0.0) {
            return Err(
                "workspace needs Zu > 0, Rcy > 0 and Hcy + Hco > 0 (the TCP works below the base)"
                    .into(),
            );
        }
        Ok(())
    }
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

impl SampleGrid {
    /// The grid of `k` cells per axis over workspace `ws`, with the reachability of every
    /// sample's centre for robot geometry `delta`.
    ///
    /// # Errors
    /// When `k` is not a power of two >= 2 (at most 2^15), the workspace has a bad value, or
    /// the grid's x/y half-extent `k r / 2` cannot hold the workspace radius plus one cell.
    pub fn new(ws: &Workspace, k: u32, delta: &Delta3) -> Result<SampleGrid, String> {
        ws.validate()?;
        if !(k >= 2 && k.is_power_of_two() && k <= 1 << 15) {
            return Err(format!(
                "k = {k} must be a power of two between 2 and 32768 (for example 32)"
            ));
        }
        let side = ws.max_radius().max(ws.max_depth());
        let r = side / k as Real;
        let half_extent = 0.5 * side;
        if half_extent < ws.max_radius() + r {
            let fix = if half_extent > ws.max_radius() {
                let k_min = float::ceil(side / (half_extent - ws.max_radius())) as u32;
                format!("use k >= {} (a power of two)", k_min.next_power_of_two())
            } else {
                "no k can: the workspace must be at least twice as deep (Zu + Hcy + Hco) as it is wide (Rcy, Rco)"
                    .into()
            };
            return Err(format!(
                "the grid's x/y half-extent k r / 2 = {half_extent} mm cannot hold the workspace radius {} mm plus one cell r = {r} mm; {fix}",
                ws.max_radius()
            ));
        }
        let kf = k as Real;
        let origin = Vec3::new(-0.5 * kf * r, -0.5 * kf * r, -kf * r);
        let reach2 = |c_r: Real| {
            let reach = c_r + r * core::f64::consts::FRAC_1_SQRT_2;
            reach * reach * (1.0 + 1e-12)
        };
        let mut cells = Vec::new();
        let mut reachable = Vec::new();
        for ix in 0..k {
            for iy in 0..k {
                for iz in 0..k {
                    let c = centre_of(r, k, [ix as u16, iy as u16, iz as u16]);
                    let (d_top, d_bottom) = (-(c.z + 0.5 * r), -(c.z - 0.5 * r));
                    let Some(c_r) = ws.max_radius_over(d_top, d_bottom) else { continue };
                    if c.x * c.x + c.y * c.y <= reach2(c_r) {
                        cells.push([ix as u16, iy as u16, iz as u16]);
                        reachable.push(delta.inverse_kinematics(&c).is_ok());
                    }
                }
            }
        }
        Ok(SampleGrid { k, levels: k.trailing_zeros(), r, origin, cells, reachable })
    }

    /// The centre of grid cell `cell` (MCS, mm).
    pub fn center(&self, cell: CellIndex) -> Vec3 {
        centre_of(self.r, self.k, cell)
    }

    /// The centre of sample `i` (an index into `cells`).
    pub fn sample_center(&self, i: usize) -> Vec3 {
        self.center(self.cells[i])
    }

    /// The grid cell holding `p` (MCS), or `None` outside the closed grid cube. A point on a
    /// face shared by two cells goes to the one with the larger index; on the cube's upper
    /// faces, to the last cell.
    pub fn cell_of(&self, p: &Vec3) -> Option<CellIndex> {
        let mut out = [0u16; 3];
        for a in 0..3 {
            let t = (p[a] - self.origin[a]) / self.r;
            if !(t >= 0.0 && t <= self.k as Real) {
                return None;
            }
            out[a] = (float::floor(t) as u32).min(self.k - 1) as u16;
        }
        Some(out)
    }

    /// The sample index of grid cell `cell`, or `None` when it is not sampled.
    pub fn index_of(&self, cell: CellIndex) -> Option<usize> {
        self.cells.binary_search(&cell).ok()
    }

    /// The sample index of the cell holding `p`, or `None` outside the sampled cells.
    pub fn sample_of(&self, p: &Vec3) -> Option<usize> {
        self.cell_of(p).and_then(|c| self.index_of(c))
    }

    /// How many samples have a reachable centre.
    pub fn reachable_count(&self) -> usize {
        self.reachable.iter().filter(|&&r| r).count()
    }
}

/// `r (i + 1/2 - k/2)` for x and y, `r (i + 1/2 - k)` for z: exactly symmetric in x and y.
fn centre_of(r: Real, k: u32, cell: CellIndex) -> Vec3 {
    let kf = k as Real;
    let c = |i: u16, shift: Real| r * (i as Real + 0.5 - shift);
    Vec3::new(c(cell[0], 0.5 * kf), c(cell[1], 0.5 * kf), c(cell[2], kf))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thesis_grid(k: u32) -> SampleGrid {
        SampleGrid::new(&Workspace::THESIS, k, &Delta3::THESIS).unwrap()
    }

    #[test]
    fn grid_convention_and_counts_at_k32() {
        let g = thesis_grid(32);
        assert_eq!((g.levels, g.r), (5, 530.0 / 32.0));
        assert_eq!(g.origin, Vec3::new(-265.0, -265.0, -530.0));
        assert!((g.center([0, 0, 0]) - (g.origin + Vec3::repeat(0.5 * g.r))).norm() < 1e-12);
        assert!(g.cells.windows(2).all(|w| w[0] < w[1]), "lexicographic and unique");
        // SPEC §4: about 6,000 samples per robot (thesis 5,946); about 12 % unreachable.
        let n = g.cells.len();
        assert!((5_800..6_600).contains(&n), "{n} samples");
        let unreachable = 1.0 - g.reachable_count() as f64 / n as f64;
        assert!((0.05..0.20).contains(&unreachable), "{unreachable}");
    }

    #[test]
    fn small_k_and_bad_k_are_refused_with_the_fix() {
        let err = SampleGrid::new(&Workspace::THESIS, 8, &Delta3::THESIS).unwrap_err();
        assert!(err.contains("k >= 16"), "{err}");
        assert!(SampleGrid::new(&Workspace::THESIS, 16, &Delta3::THESIS).is_ok());
        let err = SampleGrid::new(&Workspace::THESIS, 24, &Delta3::THESIS).unwrap_err();
        assert!(err.contains("power of two"), "{err}");
        let wide = Workspace { rcy: 400.0, ..Workspace::THESIS };
        assert!(SampleGrid::new(&wide, 32, &Delta3::THESIS).unwrap_err().contains("no k can"));
    }

    #[test]
    fn cell_of_and_index_of_round_trip_and_faces_are_consistent() {
        let g = thesis_grid(32);
        for (i, &c) in g.cells.iter().enumerate() {
            let p = g.center(c);
            assert_eq!(g.cell_of(&p), Some(c));
            assert_eq!(g.index_of(c), Some(i));
            // A corner point shared by eight cells goes to the largest index.
            let corner = p + Vec3::repeat(0.5 * g.r);
            let got = g.cell_of(&corner).unwrap();
            for a in 0..3 {
                assert!(got[a] == c[a] + 1 || (c[a] as u32 == g.k - 1 && got[a] == c[a]));
            }
        }
        assert_eq!(g.cell_of(&Vec3::new(0.0, 0.0, 1.0)), None);
        assert_eq!(g.cell_of(&Vec3::new(-265.0, -265.0, -530.0)), Some([0, 0, 0]));
        assert_eq!(g.cell_of(&Vec3::new(265.0, 265.0, 0.0)), Some([31, 31, 31]));
        assert_eq!(g.cell_of(&Vec3::new(f64::NAN, 0.0, -400.0)), None);
        assert_eq!(g.index_of([0, 0, 31]), None, "above the workspace");
    }

    #[test]
    fn every_workspace_point_lies_in_a_sampled_cell_and_grid_is_y_symmetric() {
        let ws = Workspace::THESIS;
        for k in [16, 32, 64] {
            let g = thesis_grid(k);
            // A dense deterministic sweep over the workspace's boundary and interior.
            for id in 0..=120 {
                let d = ws.zu + (ws.max_depth() - ws.zu) * id as f64 / 120.0;
                for ia in 0..180 {
                    for &f in &[1.0, 0.999, 0.7, 0.3] {
                        let a = ia as f64 * std::f64::consts::TAU / 180.0;
                        let rr = ws.radius_at(d) * f;
                        let p = Vec3::new(rr * a.cos(), rr * a.sin(), -d);
                        assert!(ws.contains(&p) || f == 1.0);
                        if ws.contains(&p) {
                            assert!(g.sample_of(&p).is_some(), "k {k}: {p:?} not covered");
                        }
                    }
                }
            }
            for (i, c) in g.cells.iter().enumerate() {
                let m = [c[0], (k - 1) as u16 - c[1], c[2]];
                let j = g.index_of(m).expect("mirror cell sampled");
                assert_eq!(
                    g.sample_center(j),
                    g.sample_center(i).component_mul(&Vec3::new(1.0, -1.0, 1.0))
                );
                assert_eq!(g.reachable[i], g.reachable[j]);
            }
        }
    }

    #[test]
    fn workspace_radius_is_piecewise_linear() {
        let ws = Workspace::THESIS;
        assert_eq!(ws.radius_at(400.0), 225.0);
        assert_eq!(ws.radius_at(530.0), 173.0);
        assert!((ws.radius_at(515.0) - 199.0).abs() < 1e-12);
        assert_eq!(ws.max_radius_over(490.0, 520.0), Some(225.0));
        assert_eq!(ws.max_radius_over(531.0, 540.0), None);
    }
}
