//! Synthetic labelled spaces for table tests and benches: the grid shape of SPEC §4 with
//! labels from an analytic function of the 6-D cell, so tables can be checked on every sample
//! without the (slow) exact labelling. Not a model of any robot.
//!
//! The grid follows SPEC §4 (r = max(Rcy, Zu+Hcy+Hco)/k, origin (-kr/2, -kr/2, -kr), cells in
//! the cylinder + frustum plus r/sqrt 2), with deep far cells marked unreachable (like the real
//! robot's ~12 %). It is symmetric in y by construction.

use crate::cspace::{CellIndex, Label, LabelledSpace, PairLabels, SampleGrid, Workspace};
use crate::math::Vec3;

/// Which labels a synthetic space gets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pattern {
    /// Monotone collision blobs: the robots collide when B's TCP comes within a depth-
    /// and offset-dependent distance of A's along x (B stands at x = 450). Symmetric in y.
    Blobs,
    /// Collision with probability `p` per sample from a seeded hash, symmetric in y.
    Noise {
        /// Probability of collision.
        p: f64,
        /// Seed of the hash.
        seed: u64,
    },
    /// As `Noise` but not symmetric: for checking that a wrong symmetry flag loses nothing.
    AsymmetricNoise {
        /// Probability of collision.
        p: f64,
        /// Seed of the hash.
        seed: u64,
    },
    /// Every reachable pair free.
    AllFree,
    /// Every reachable pair colliding.
    AllCollision,
}

/// The sampled grid of one robot with `k = 2^levels` cells per axis (SPEC §4 shape).
pub fn grid(levels: u32) -> SampleGrid {
    let w = Workspace::THESIS;
    let k = 1u32 << levels;
    let r = w.rcy.max(w.zu + w.hcy + w.hco) / f64::from(k);
    let kr = f64::from(k) * r;
    let origin = Vec3::new(-kr / 2.0, -kr / 2.0, -kr);
    let (mut cells, mut reachable) = (Vec::new(), Vec::new());
    for ix in 0..k {
        for iy in 0..k {
            for iz in 0..k {
                let c = origin
                    + r * Vec3::new(f64::from(ix) + 0.5, f64::from(iy) + 0.5, f64::from(iz) + 0.5);
                let (top, bottom) = (-(c.z + r / 2.0), -(c.z - r / 2.0));
                let deepest = w.zu + w.hcy + w.hco;
                if bottom < w.zu || top > deepest {
                    continue;
                }
                let d = (-c.z).clamp(w.zu, deepest);
                let cr = if d <= w.zu + w.hcy {
                    w.rcy
                } else {
                    w.rcy - (w.rcy - w.rco) * (d - w.zu - w.hcy) / w.hco
                };
                let rho = c.x.hypot(c.y);
                if rho <= cr + r / std::f64::consts::SQRT_2 {
                    cells.push([ix as u16, iy as u16, iz as u16] as CellIndex);
                    reachable.push(!(-c.z > 470.0 && rho > 190.0));
                }
            }
        }
    }
    SampleGrid { k, levels, r, origin, cells, reachable }
}

fn splitmix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

fn noise(cell: [u16; 6], seed: u64, p: f64) -> bool {
    let key = cell.iter().fold(seed, |h, &v| splitmix(h ^ u64::from(v)));
    ((key >> 11) as f64 / (1u64 << 53) as f64) < p
}

/// The label of a reachable pair of TCP cell centres `pa`, `pb` (each in its own MCS).
fn label_of(pattern: Pattern, cell: [u16; 6], k: u16, pa: Vec3, pb: Vec3) -> bool {
    match pattern {
        Pattern::Blobs => {
            let gap = 450.0 + pb.x - pa.x;
            let reach =
                110.0 + 0.25 * ((-pa.z - 365.0) + (-pb.z - 365.0)) - 0.2 * (pa.y - pb.y).abs();
            gap < reach
                || (pa.y - 120.0).abs() + (pb.y - 120.0).abs() + (gap - 260.0).abs() < 40.0
                || (pa.y + 120.0).abs() + (pb.y + 120.0).abs() + (gap - 260.0).abs() < 40.0
        }
        Pattern::Noise { p, seed } => {
            let mut c = cell;
            if c[1] < k / 2 {
                c[1] = k - 1 - c[1];
                c[4] = k - 1 - c[4];
            }
            noise(c, seed, p)
        }
        Pattern::AsymmetricNoise { p, seed } => noise(cell, seed, p),
        Pattern::AllFree => false,
        Pattern::AllCollision => true,
    }
}

/// A labelled space of two robots on [`grid`]`(levels)` with labels from `pattern`; pairs
/// with an unreachable TCP are [`Label::Unreachable`].
pub fn space(levels: u32, pattern: Pattern) -> LabelledSpace {
    let g = grid(levels);
    // Centres relative to the axis, computed so that iy -> k-1-iy negates y exactly.
    let h = f64::from(g.k) / 2.0;
    let centre = |c: &CellIndex| {
        g.r * Vec3::new(
            f64::from(c[0]) - h + 0.5,
            f64::from(c[1]) - h + 0.5,
            f64::from(c[2]) - 2.0 * h + 0.5,
        )
    };
    let k = g.k as u16;
    let mut labels = Vec::with_capacity(g.cells.len() * g.cells.len());
    for (a, &ra) in g.cells.iter().zip(&g.reachable) {
        let pa = centre(a);
        for (b, &rb) in g.cells.iter().zip(&g.reachable) {
            let cell = [a[0], a[1], a[2], b[0], b[1], b[2]];
            labels.push(if !(ra && rb) {
                Label::Unreachable
            } else if label_of(pattern, cell, k, pa, centre(b)) {
                Label::Collision
            } else {
                Label::Free
            });
        }
    }
    let labels = PairLabels::from_labels(g.cells.len(), &labels);
    LabelledSpace { grid_a: g.clone(), grid_b: g, labels, margin: 0.0 }
}
