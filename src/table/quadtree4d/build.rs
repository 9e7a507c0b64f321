//! The builder of the linear 4-D quadtree from labelled samples (thesis 3.2.6, Algorithm 8):
//! one slice per range in the thesis's order, grouped by [`Grouping`].

use super::grouping::Grouping;
use super::{shape, LinearQuadtree4d, SliceAxes};
use crate::cspace::symmetry::Symmetry;
use crate::cspace::{Label, LabelledSpace};
use crate::table::error::TableError;
use crate::table::space::SpaceView;
use std::collections::BTreeMap;

/// Samples of one robot grouped by its two quadtree coordinates `(ix, second)`.
pub(super) fn ranges(
    cells: &[[u16; 3]],
    keep: impl Fn(usize) -> bool,
    second: usize,
) -> BTreeMap<(u16, u16), Vec<usize>> {
    let mut m: BTreeMap<(u16, u16), Vec<usize>> = BTreeMap::new();
    for (i, c) in cells.iter().enumerate().filter(|(i, _)| keep(*i)) {
        m.entry((c[0], c[second])).or_default().push(i);
    }
    m
}

/// Puts `label` at slice bit `bit`; whether it is a collision.
pub(super) fn put(s: &mut [u64], care: &mut [u64], bit: usize, label: Label) -> bool {
    if label != Label::Unreachable {
        care[bit / 64] |= 1 << (bit % 64);
    }
    let collision = label == Label::Collision;
    if collision {
        s[bit / 64] |= 1 << (bit % 64);
    }
    collision
}

impl LinearQuadtree4d {
    /// Builds the table of `space` with threshold `t` (thesis Algorithm 8); with
    /// [`Symmetry::MirrorY`], only A's upper half `iy >= k/2` is stored.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or the label count is wrong.
    #[cfg(feature = "std")]
    pub fn build(
        space: &LabelledSpace,
        symmetry: Symmetry,
        axes: SliceAxes,
        t: u32,
    ) -> Result<LinearQuadtree4d, TableError> {
        let symmetric = symmetry.is_mirrored();
        let view = SpaceView::new(space, symmetric)?;
        let (k, levels) = (view.k, view.levels);
        let (second, ignored) = axes.dims();
        let (a0, wps) = shape(levels, symmetric, axes);
        let (ca, cb) = (&space.grid_a.cells, &space.grid_b.cells);
        let ra = ranges(ca, |i| view.stored(i), second);
        let rb = ranges(cb, |_| true, second);
        let mut grouping = Grouping::new(levels, symmetric, axes, t);
        let (mut s, mut care) = (vec![0u64; wps], vec![0u64; wps]);
        // Thesis order x, x', z, z': the A and B maps are sorted by (ix, second).
        let xs_a: Vec<u16> =
            ra.keys().map(|k| k.0).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let xs_b: Vec<u16> =
            rb.keys().map(|k| k.0).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        for &xa in &xs_a {
            for &xb in &xs_b {
                for ((_, za), ias) in ra.range((xa, 0)..=(xa, u16::MAX)) {
                    for ((_, zb), ibs) in rb.range((xb, 0)..=(xb, u16::MAX)) {
                        s.fill(0);
                        care.fill(0);
                        let mut any = false;
                        for &ia in ias {
                            let row = (u32::from(ca[ia][ignored]) - a0) * k;
                            for &ib in ibs {
                                let bit = (row + u32::from(cb[ib][ignored])) as usize;
                                any |= put(&mut s, &mut care, bit, view.label(ia, ib));
                            }
                        }
                        if any {
                            grouping.add([xa, *za, xb, *zb], &s, &care);
                        }
                    }
                }
            }
        }
        Ok(grouping.finish())
    }
}
