//! For the report tool only (`eval` feature): the thesis's 4-D tables of the sub-cell labels
//! at `2 k`, made without the dense labels, and a lower bound on their size for when building
//! them would take hours. The controller never loads such a table; the report compares it
//! with the shared table of sub-cells.

use super::build::{put, ranges};
use super::grouping::Grouping;
use super::{shape, LinearQuadtree4d, SliceAxes};
use crate::cspace::symmetry::Symmetry;
use crate::cspace::{Label, SubdividedLabels};
use crate::table::error::TableError;
use crate::table::space::{check_grids, merge, reflections, NONE};
use rayon::prelude::*;

impl LinearQuadtree4d {
    /// The table [`build`](Self::build) makes from [`SubdividedLabels::to_dense`]
    /// (the same table, tested), without those dense labels ([`subdivided_slices`]).
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ.
    pub fn build_subdivided(
        labels: &SubdividedLabels,
        symmetry: Symmetry,
        axes: SliceAxes,
        t: u32,
    ) -> Result<LinearQuadtree4d, TableError> {
        let symmetric = symmetry.is_mirrored();
        let mut grouping = Grouping::new(labels.grid_a.levels, symmetric, axes, t);
        subdivided_slices(labels, symmetric, axes, |range, s, care| grouping.add(range, s, care))?;
        Ok(grouping.finish())
    }
}

/// The slices of the table of the sub-cell labels at `2k` ([`SubdividedLabels`]), each with
/// its range and care mask, in the thesis's order, as [`LinearQuadtree4d::build`] makes them
/// from the dense labels: only the ranges inside a coarse range that holds a collision,
/// itself or by its mirror, can hold one, so only they are visited, their pairs' labels read
/// from `labels` and their slices made in parallel, a block of ranges at a time.
///
/// # Errors
/// [`TableError::BadInput`] when the grids differ.
pub fn subdivided_slices(
    labels: &SubdividedLabels,
    symmetric: bool,
    axes: SliceAxes,
    mut visit: impl FnMut([u16; 4], &[u64], &[u64]),
) -> Result<(), TableError> {
    let (ga, gb) = (&labels.grid_a, &labels.grid_b);
    check_grids(ga, gb)?;
    let (k, levels) = (ga.k, ga.levels);
    let (second, ignored) = axes.dims();
    let (a0, wps) = shape(levels, symmetric, axes);
    let ra = ranges(&ga.cells, |i| !symmetric || u32::from(ga.cells[i][1]) >= k / 2, second);
    let rb = ranges(&gb.cells, |_| true, second);
    let (refl_a, refl_b) =
        if symmetric { (reflections(ga), reflections(gb)) } else { (vec![], vec![]) };
    let coarse = labels.coarse();
    let (ca0, cb0, k0) = (&coarse.grid_a.cells, &coarse.grid_b.cells, coarse.grid_a.k as u16);
    let nb0 = cb0.len().max(1);
    let mut coarse_ranges: Vec<[u16; 4]> = (0..coarse.labels.len() / nb0)
        .into_par_iter()
        .flat_map_iter(|pa| {
            let (a, mut out) = (ca0[pa], Vec::new());
            for pb in (0..nb0).filter(|&pb| coarse.labels[pa * nb0 + pb] == Label::Collision) {
                let b = cb0[pb];
                out.push([a[0], a[second], b[0], b[second]]);
                if symmetric && second == 1 {
                    out.push([a[0], k0 - 1 - a[1], b[0], k0 - 1 - b[1]]);
                }
            }
            out.sort_unstable();
            out.dedup();
            out
        })
        .collect();
    coarse_ranges.par_sort_unstable();
    coarse_ranges.dedup();
    let mut fine: Vec<[u16; 4]> = coarse_ranges
        .iter()
        .flat_map(|c| (0..16u16).map(move |o| core::array::from_fn(|d| 2 * c[d] + (o >> d & 1))))
        .filter(|f: &[u16; 4]| ra.contains_key(&(f[0], f[1])) && rb.contains_key(&(f[2], f[3])))
        .collect();
    // The thesis order (x, x', then the second dimension of each).
    fine.par_sort_unstable_by_key(|f| (f[0], f[2], f[1], f[3]));
    let slice = |f: &[u16; 4]| -> Option<(Vec<u64>, Vec<u64>)> {
        let (ias, ibs) = (&ra[&(f[0], f[1])], &rb[&(f[2], f[3])]);
        let own_b: Vec<u32> = ibs.iter().map(|&ib| ib as u32).collect();
        let mirror_b: Vec<u32> =
            if symmetric { ibs.iter().map(|&ib| refl_b[ib]).collect() } else { vec![] };
        let (mut own, mut mirror) =
            (vec![Label::Unreachable; ibs.len()], vec![Label::Unreachable; ibs.len()]);
        let (mut s, mut care, mut any) = (vec![0u64; wps], vec![0u64; wps], false);
        for &ia in ias {
            labels.row(Some(ia), &own_b, &mut own);
            if symmetric {
                let m = refl_a[ia];
                labels.row((m != NONE).then_some(m as usize), &mirror_b, &mut mirror);
            }
            let row = (u32::from(ga.cells[ia][ignored]) - a0) * k;
            for (n, &ib) in ibs.iter().enumerate() {
                let bit = (row + u32::from(gb.cells[ib][ignored])) as usize;
                // A missing mirror reads "don't care", which `merge` leaves as `own`.
                any |= put(&mut s, &mut care, bit, merge(own[n], mirror[n]));
            }
        }
        any.then_some((s, care))
    };
    for block in fine.chunks(4096) {
        let slices: Vec<_> = block.par_iter().map(slice).collect();
        for (f, s) in block.iter().zip(slices) {
            if let Some((s, care)) = s {
                visit(*f, &s, &care);
            }
        }
    }
    Ok(())
}

/// A lower bound on the size of every 4-D table of a stream of slices at `t = 0`, for when
/// the grouping itself would take hours (`6D-shared/sub`'s baseline at `k = 64`: millions of
/// slices of 8,192 bits).
///
/// At `t = 0` every slice of a group agrees with its representative on the slice's care bits
/// (module doc), so two slices of one group agree on every bit both care for. So for any
/// window `W` of slice bits, slices that care for all of `W` and differ on it are in
/// different groups: the number of their distinct patterns on `W` is at most the number of
/// groups. The bound is the largest such number over square windows of sides from a
/// sixteenth to all of the slice's rows (4 to 64), each side's windows overlapping by half
/// (patterns are counted by a 64-bit hash: a collision only lowers the count).
pub struct SliceBound {
    k: usize,
    wps: usize,
    /// `(first row, first column, side)` of each window, with the hashes of its patterns.
    windows: Vec<((usize, usize, usize), std::collections::HashSet<u64>)>,
    /// Slices seen (each is one code of the table).
    pub codes: usize,
}

impl SliceBound {
    /// For the slices of a table with these parameters.
    pub fn new(levels: u32, symmetric: bool, axes: SliceAxes) -> SliceBound {
        let (a0, wps) = shape(levels, symmetric, axes);
        let k = 1usize << levels;
        let rows = k - a0 as usize;
        let mut windows = Vec::new();
        for side in [rows / 16, rows / 8, rows / 4, rows / 2, rows]
            .into_iter()
            .filter(|w| (4..=64).contains(w))
        {
            for r0 in (0..=rows - side).step_by(side / 2) {
                for c0 in (0..=k - side).step_by(side / 2) {
                    windows.push(((r0, c0, side), Default::default()));
                }
            }
        }
        SliceBound { k, wps, windows, codes: 0 }
    }

    /// One slice: its collision bits `s` and care mask `care`.
    pub fn add(&mut self, s: &[u64], care: &[u64]) {
        self.codes += 1;
        let k = self.k;
        for ((r0, c0, side), seen) in &mut self.windows {
            let full = if *side == 64 { !0 } else { (1u64 << *side) - 1 };
            let rows = *r0..*r0 + *side;
            if rows.clone().all(|r| window_bits(care, r * k + *c0, *side) == full) {
                let h = rows.fold(0u64, |h, r| {
                    (h.rotate_left(5) ^ window_bits(s, r * k + *c0, *side))
                        .wrapping_mul(0x517c_c1b7_2722_0a95)
                });
                seen.insert(h);
            }
        }
    }

    /// At least this many groups: `(groups, (first row, first column, side) of its window)`.
    pub fn groups_at_least(&self) -> (usize, (usize, usize, usize)) {
        self.windows.iter().map(|(w, seen)| (seen.len(), *w)).max().unwrap_or((0, (0, 0, 0)))
    }

    /// At least this many bytes in memory ([`LinearQuadtree4d::memory_bytes`]): the codes
    /// and slice indices, and the groups' slices.
    pub fn bytes_at_least(&self) -> usize {
        core::mem::size_of::<LinearQuadtree4d>()
            + 12 * self.codes
            + 8 * self.wps * self.groups_at_least().0
    }
}

/// Bits `start .. start + len` of `words` (`len <= 64`), the first in bit 0.
fn window_bits(words: &[u64], start: usize, len: usize) -> u64 {
    let (w, o) = (start / 64, start % 64);
    let mut v = words[w] >> o;
    if o > 0 && o + len > 64 {
        v |= words[w + 1] << (64 - o);
    }
    if len == 64 {
        v
    } else {
        v & ((1u64 << len) - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::Symmetry;

    /// The builder without dense labels makes the table the dense builder makes from the
    /// sub-cell labels: the same ranges, slices and groups (so the same order), on T1 and T2
    /// (symmetric) and T3 (not), for both slice axes, exact and lossy; and [`SliceBound`]
    /// stays below it.
    #[test]
    fn subdivided_build_is_the_dense_build_of_the_sub_cell_labels() {
        use crate::cell::reference::reference_cell;
        use crate::cspace::symmetry::reflection_y;
        use crate::cspace::{label_space_subdivided, Progress, SubdividedLabels, Workspace};
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let mut certified =
                label_space_subdivided(&cell, 16, &Workspace::THESIS, Progress::Silent).unwrap();
            // Every fifth pair's sub-cells all collisions: labels no longer mirror-symmetric,
            // so the symmetric tables must merge each pair with its mirror as the dense one does.
            let sub = certified.sub.as_mut().unwrap();
            sub.collision.iter_mut().zip(&sub.care).step_by(5).for_each(|(c, &care)| *c = care);
            let sparse = SubdividedLabels::new(&cell, &Workspace::THESIS, &certified).unwrap();
            let dense = sparse.to_dense();
            let symmetric = reflection_y(&cell);
            for axes in [SliceAxes::YY, SliceAxes::ZZ] {
                for t in [0, 40] {
                    let want =
                        LinearQuadtree4d::build(&dense, Symmetry::from_flag(symmetric), axes, t)
                            .unwrap();
                    let got = LinearQuadtree4d::build_subdivided(
                        &sparse,
                        Symmetry::from_flag(symmetric),
                        axes,
                        t,
                    )
                    .unwrap();
                    assert!(
                        want.codes.len() > 100 && want.slice_count() > 10,
                        "{name} {axes:?} t={t}: too small"
                    );
                    assert!(got == want, "{name} {axes:?} t={t}: the tables differ");
                    if t == 0 {
                        // The lower bound is not above the table it bounds, and not trivial.
                        let mut bound = SliceBound::new(sparse.grid_a.levels, symmetric, axes);
                        subdivided_slices(&sparse, symmetric, axes, |_, s, care| {
                            bound.add(s, care)
                        })
                        .unwrap();
                        let (groups, _) = bound.groups_at_least();
                        assert_eq!(bound.codes, got.codes.len(), "{name} {axes:?}");
                        assert!(
                            groups > 10 && groups <= got.slice_count(),
                            "{name} {axes:?}: {groups} groups"
                        );
                        assert!(bound.bytes_at_least() <= got.memory_bytes(), "{name} {axes:?}");
                    }
                }
            }
        }
    }
}
