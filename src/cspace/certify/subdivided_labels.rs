//! For the report tool only (`eval` feature): the labels a subdivided labelling stands for,
//! spelled out on the grid of `2 k` cells per axis, so that the thesis's tables of them can be
//! built as a baseline for the shared table of sub-cells.

use super::{sub_cell_index, CertifiedSpace, SubCells};
use crate::cell::Cell;
use crate::cspace::label::two_robot_grids;
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::symmetry::{mirror_samples, reflection_y};
use crate::cspace::{Label, LabelledSpace, PairLabels};

/// Per sample of a grid: the index of its mirror sample (`iy -> k - 1 - iy`), if sampled.
type Mirrors = Vec<Option<usize>>;

/// The labels a subdivided labelling ([`label_space_subdivided`]) stands for, on the grid of
/// `2k` cells per axis (the octants of the `k` grid), found pair by pair: a sub-cell takes
/// its pair's label, or, for a pair with sub-cells, its own ("don't care" outside `care`). A
/// sample of the `2k` grid whose parent cell is not sampled at `k` is "don't care": queries
/// there never reach the table. A plain table built from these labels answers as the
/// subdivided one does on every sub-cell (the baseline for its size); at `k = 64` the dense
/// labels ([`SubdividedLabels::to_dense`]) would not fit in memory, so the 4-D builder reads them
/// here ([`crate::table::LinearQuadtree4d::build_subdivided`]). A symmetric cell's sub-cells
/// are found for the stored half only (module doc of `certify`, "Symmetric cells"): a pair
/// of the other half takes its mirror pair's, reflected.
pub struct SubdividedLabels<'a> {
    coarse: &'a LabelledSpace,
    sub: &'a SubCells,
    /// A's samples at `2k`.
    pub grid_a: SampleGrid,
    /// B's samples at `2k`.
    pub grid_b: SampleGrid,
    /// Per sample at `2k`: its parent sample at `k` and its octant (bits x, y, z = 0, 1, 2).
    parent_a: Vec<Option<(u32, u8)>>,
    parent_b: Vec<Option<(u32, u8)>>,
    /// `sub.pairs[row_start[ia]..row_start[ia + 1]]` are the pairs of A's sample `ia` at `k`.
    row_start: Vec<usize>,
    /// For a symmetric cell, per sample at `k` of A, then of B: its mirror sample, if any.
    mirrors: Option<(Mirrors, Mirrors)>,
}

impl<'a> SubdividedLabels<'a> {
    /// The `2k` grids of `cell` and the parents of their samples in `certified`'s grids.
    ///
    /// # Errors
    /// When `certified` has no sub-cells, or as [`crate::cspace::label_space`].
    pub fn new(
        cell: &Cell,
        ws: &Workspace,
        certified: &'a CertifiedSpace,
    ) -> Result<SubdividedLabels<'a>, String> {
        let sub = certified.sub.as_ref().ok_or("the labelling has no sub-cells")?;
        let coarse = &certified.space;
        let (grid_a, grid_b) = two_robot_grids(cell, 2 * coarse.grid_a.k, ws)?;
        let parents = |fine: &SampleGrid, coarse: &SampleGrid| -> Vec<Option<(u32, u8)>> {
            let of = |c: &[u16; 3]| {
                let p = coarse.index_of([c[0] / 2, c[1] / 2, c[2] / 2])?;
                Some((
                    p as u32,
                    (c[0] & 1) as u8 | ((c[1] & 1) as u8) << 1 | ((c[2] & 1) as u8) << 2,
                ))
            };
            fine.cells.iter().map(of).collect()
        };
        let (parent_a, parent_b) =
            (parents(&grid_a, &coarse.grid_a), parents(&grid_b, &coarse.grid_b));
        let nb0 = coarse.grid_b.cells.len() as u64;
        let row_start = (0..=coarse.grid_a.cells.len() as u64)
            .map(|ia| sub.pairs.partition_point(|&p| p < ia * nb0))
            .collect();
        let mirrors = reflection_y(cell)
            .then(|| (mirror_samples(&coarse.grid_a), mirror_samples(&coarse.grid_b)));
        Ok(SubdividedLabels { coarse, sub, grid_a, grid_b, parent_a, parent_b, row_start, mirrors })
    }

    /// These labels as one array (`8^2` times the bytes of the labels at `k`).
    pub fn to_dense(&self) -> LabelledSpace {
        let nb = self.grid_b.cells.len();
        let ibs: Vec<u32> = (0..nb as u32).collect();
        let labels = PairLabels::from_rows(self.grid_a.cells.len(), nb, |ia, row| {
            self.row(Some(ia), &ibs, row)
        });
        let (grid_a, grid_b) = (self.grid_a.clone(), self.grid_b.clone());
        LabelledSpace { grid_a, grid_b, labels, margin: self.coarse.margin }
    }

    /// The labels at `k` the sub-cells refine.
    pub fn coarse(&self) -> &LabelledSpace {
        self.coarse
    }

    /// The labels of A's sample `ia` with each of B's samples `ibs` (`u32::MAX`, or `ia =
    /// None`: no sample, "don't care"), into `out`.
    pub fn row(&self, ia: Option<usize>, ibs: &[u32], out: &mut [Label]) {
        let Some((pa, i)) = ia.and_then(|ia| self.parent_a[ia]) else {
            out.fill(Label::Unreachable);
            return;
        };
        let pa = pa as usize;
        for (l, &ib) in out.iter_mut().zip(ibs) {
            let Some(&Some((pb, j))) = self.parent_b.get(ib as usize) else {
                *l = Label::Unreachable;
                continue;
            };
            let (pb, i, j) = (pb as usize, usize::from(i), usize::from(j));
            *l = self
                .spelled(pa, pb, i, j)
                .or_else(|| {
                    let (ma, mb) = self.mirrors.as_ref()?;
                    // The mirror sub-cell: the y octant bit (bit 1) of both robots flipped.
                    self.spelled(ma[pa]?, mb[pb]?, i ^ 2, j ^ 2)
                })
                .unwrap_or(Label::Collision);
        }
    }

    /// The label of sub-cell (A's octant `i`, B's octant `j`) of pair `(pa, pb)` at `k`: its
    /// pair's label, or for a pair labelled collision its sub-cell's; `None` for a collision
    /// pair without sub-cells.
    fn spelled(&self, pa: usize, pb: usize, i: usize, j: usize) -> Option<Label> {
        let nb0 = self.coarse.grid_b.cells.len();
        let label = self.coarse.labels[pa * nb0 + pb];
        if label != Label::Collision {
            return Some(label);
        }
        let (first, last) = (self.row_start[pa], self.row_start[pa + 1]);
        let e =
            first + self.sub.pairs[first..last].binary_search(&((pa * nb0 + pb) as u64)).ok()?;
        let bit = 1u64 << sub_cell_index(i, j);
        Some(if self.sub.care[e] & bit == 0 {
            Label::Unreachable
        } else if self.sub.collision[e] & bit != 0 {
            Label::Collision
        } else {
            Label::Free
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::cspace::certify::label_space_subdivided;
    use crate::cspace::symmetry::mirror_cell;
    use crate::cspace::Progress;

    /// The `2k` labels of a subdivided labelling: every sub-cell of a collision pair as its
    /// mask says (looked up the plain way), everything else as its parent pair. T2 is
    /// symmetric, so the pairs of A's lower half have no sub-cells of their own: each takes
    /// the label of its mirror sample pair at `2k` (both robots' `iy` reflected).
    #[test]
    fn subdivided_labels_spell_out_the_sub_cells() {
        let ws = Workspace::THESIS;
        let cell = reference_cell("T2").unwrap();
        let c = label_space_subdivided(&cell, 16, &ws, Progress::Silent).unwrap();
        let fine = SubdividedLabels::new(&cell, &ws, &c).unwrap().to_dense();
        let sub = c.sub.as_ref().unwrap();
        let (coarse, nb0) = (&c.space, c.space.grid_b.cells.len());
        let up = |g: &SampleGrid, x: &[u16; 3]| g.index_of([x[0] / 2, x[1] / 2, x[2] / 2]);
        let octant = |x: &[u16; 3]| {
            usize::from(x[0] & 1) | usize::from(x[1] & 1) << 1 | usize::from(x[2] & 1) << 2
        };
        // The label spelled from the pair's own sub-cells; `None` for a collision pair without.
        let own =
            |ca: &[u16; 3], cb: &[u16; 3]| match (up(&coarse.grid_a, ca), up(&coarse.grid_b, cb)) {
                (Some(ia), Some(ib)) => match sub.get((ia * nb0 + ib) as u64) {
                    Some((care, collision)) => {
                        let bit = 1u64 << sub_cell_index(octant(ca), octant(cb));
                        Some(match (care & bit != 0, collision & bit != 0) {
                            (false, _) => Label::Unreachable,
                            (true, true) => Label::Collision,
                            (true, false) => Label::Free,
                        })
                    }
                    None => Some(coarse.label(ia, ib)).filter(|&l| l != Label::Collision),
                },
                _ => Some(Label::Unreachable),
            };
        let (mut seen, mut freed, mut mirrored) = (0, 0, 0);
        for (ja, ca) in fine.grid_a.cells.iter().enumerate() {
            for (jb, cb) in fine.grid_b.cells.iter().enumerate() {
                let want = own(ca, cb).unwrap_or_else(|| {
                    mirrored += 1;
                    let (ma, mb) = (mirror_cell(&fine.grid_a, *ca), mirror_cell(&fine.grid_b, *cb));
                    own(&ma, &mb).unwrap_or(Label::Collision)
                });
                seen += 1;
                freed += usize::from(want == Label::Free && coarse_collision(coarse, &up, ca, cb));
                assert_eq!(fine.label(ja, jb), want, "fine pair ({ja}, {jb})");
            }
        }
        assert!(
            seen > 0 && freed > 0 && mirrored > 0,
            "{seen} pairs, {freed} sub-cells freed, {mirrored} mirrored"
        );
    }

    /// Whether the parent pair of fine cells `ca`, `cb` is labelled collision at `k`.
    fn coarse_collision(
        coarse: &LabelledSpace,
        up: &impl Fn(&SampleGrid, &[u16; 3]) -> Option<usize>,
        ca: &[u16; 3],
        cb: &[u16; 3],
    ) -> bool {
        let nb0 = coarse.grid_b.cells.len();
        matches!((up(&coarse.grid_a, ca), up(&coarse.grid_b, cb)), (Some(ia), Some(ib)) if coarse.labels[ia * nb0 + ib] == Label::Collision)
    }
}
