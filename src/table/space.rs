//! The labelled space as the table builders see it: validated, with the reflection symmetry
//! folded in (thesis 3.2.8; SPEC §6 "unreachable cells: store whatever compresses best").
//!
//! # Conventions
//! With `symmetric`, only configurations with A's `iy >= k/2` (TCP `y >= 0`, since the grid's
//! y origin is `-k r / 2`) are stored; a query with `iy < k/2` is reflected first,
//! `(iy, iy') -> (k-1-iy, k-1-iy')`, both robots together and keyed on A's `y` alone (the
//! thesis's "y >= 0 and y' >= 0" would lose `y >= 0 > y'`). The stored label of an upper-half
//! sample merges it with its mirror image (collision wins, then free), so a cell that is not
//! exactly symmetric still loses no collision.
//!
//! Only [`fold`] is on the query side; the rest serves the builders and needs `std`.

#[cfg(feature = "std")]
use super::code::MAX_LEVELS;
#[cfg(feature = "std")]
use super::error::{bad_input, TableError};
#[cfg(feature = "std")]
use crate::cspace::symmetry::in_stored_half;
#[cfg(feature = "std")]
use crate::cspace::{Label, LabelledSpace, SampleGrid};

#[cfg(feature = "std")]
pub(crate) const NONE: u32 = u32::MAX;

/// A validated labelled space with the symmetry fold (see the module doc).
#[cfg(feature = "std")]
pub(crate) struct SpaceView<'a> {
    pub space: &'a LabelledSpace,
    pub k: u32,
    pub levels: u32,
    pub symmetric: bool,
    refl_a: Vec<u32>,
    refl_b: Vec<u32>,
    nb: usize,
    /// Whether every stored pair's label equals its mirror pair's (as the certified labelling
    /// writes a symmetric cell's labels): then [`SpaceView::label`] need not read the mirror.
    mirrored_exactly: bool,
}

/// Collision wins over free, free over unreachable.
#[cfg(feature = "std")]
pub(crate) fn merge(a: Label, b: Label) -> Label {
    match (a, b) {
        (Label::Collision, _) | (_, Label::Collision) => Label::Collision,
        (Label::Free, _) | (_, Label::Free) => Label::Free,
        _ => Label::Unreachable,
    }
}

/// For each sample of `g`, the index of its mirror sample (`iy -> k-1-iy`), or `NONE`. By a
/// dense map rather than [`crate::cspace::symmetry::mirror_samples`]' binary searches: a
/// table's grids need not list their cells in order ([`check_grids`] does not ask it).
#[cfg(feature = "std")]
pub(crate) fn reflections(g: &SampleGrid) -> Vec<u32> {
    let k = g.k as usize;
    let mut dense = vec![NONE; k * k * k];
    for (i, c) in g.cells.iter().enumerate() {
        dense[(c[0] as usize * k + c[1] as usize) * k + c[2] as usize] = i as u32;
    }
    g.cells
        .iter()
        .map(|c| dense[(c[0] as usize * k + (k - 1 - c[1] as usize)) * k + c[2] as usize])
        .collect()
}

/// Both grids valid (`k = 2^levels`, indices below `k`) and of equal `k`.
#[cfg(feature = "std")]
pub(crate) fn check_grids(ga: &SampleGrid, gb: &SampleGrid) -> Result<(), TableError> {
    check_grid("grid_a", ga)?;
    check_grid("grid_b", gb)?;
    if ga.k != gb.k {
        return Err(bad_input(format!("grid_a.k = {} differs from grid_b.k = {}", ga.k, gb.k)));
    }
    Ok(())
}

#[cfg(feature = "std")]
fn check_grid(name: &str, g: &SampleGrid) -> Result<(), TableError> {
    if g.levels == 0 || g.levels > MAX_LEVELS || g.k != 1 << g.levels {
        return Err(bad_input(format!(
            "{name}: k = {} with levels = {} must be 2^levels with 1 <= levels <= {MAX_LEVELS}",
            g.k, g.levels
        )));
    }
    if let Some(c) = g.cells.iter().find(|c| c.iter().any(|&v| u32::from(v) >= g.k)) {
        return Err(bad_input(format!("{name}: cell {c:?} has an index >= k = {}", g.k)));
    }
    Ok(())
}

#[cfg(feature = "std")]
impl<'a> SpaceView<'a> {
    /// Validates `space` (equal k on both grids, indices below k, one label per pair).
    pub fn new(space: &'a LabelledSpace, symmetric: bool) -> Result<SpaceView<'a>, TableError> {
        let (ga, gb) = (&space.grid_a, &space.grid_b);
        check_grids(ga, gb)?;
        let nb = gb.cells.len();
        if space.labels.len() != ga.cells.len() * nb {
            return Err(bad_input(format!(
                "labels has {} entries, the grids give {} x {nb} pairs",
                space.labels.len(),
                ga.cells.len()
            )));
        }
        let (refl_a, refl_b) =
            if symmetric { (reflections(ga), reflections(gb)) } else { (vec![], vec![]) };
        let (k, levels) = (ga.k, ga.levels);
        let mut view =
            SpaceView { space, k, levels, symmetric, refl_a, refl_b, nb, mirrored_exactly: false };
        view.mirrored_exactly = symmetric && view.labels_equal_their_mirrors();
        Ok(view)
    }

    /// Whether the label of every pair of the stored half that has a mirror pair equals the
    /// mirror pair's (rows in parallel, each row's mirror read within one row of labels).
    fn labels_equal_their_mirrors(&self) -> bool {
        use rayon::prelude::*;
        (0..self.space.grid_a.cells.len())
            .into_par_iter()
            .filter(|&ia| self.stored(ia))
            .all(|ia| self.row_with_mirrors(ia).all(|(own, mirror)| own == mirror))
    }

    /// Row `ia`'s labels paired with their mirror pairs' labels, for the pairs that have one
    /// (none when `ia` has no mirror sample).
    fn row_with_mirrors(&self, ia: usize) -> impl Iterator<Item = (Label, Label)> + '_ {
        let labels = &self.space.labels;
        let ra = self.refl_a.get(ia).copied().filter(|&ra| ra != NONE);
        ra.into_iter().flat_map(move |ra| {
            (0..self.nb).filter_map(move |ib| {
                let rb = self.refl_b[ib];
                (rb != NONE).then(|| {
                    (labels[ia * self.nb + ib], labels[ra as usize * self.nb + rb as usize])
                })
            })
        })
    }

    /// Whether A's sample `ia` is in the stored half (always, without symmetry).
    #[inline]
    pub fn stored(&self, ia: usize) -> bool {
        let grid_a = &self.space.grid_a;
        !self.symmetric || in_stored_half(grid_a, grid_a.cells[ia])
    }

    /// The label stored for the pair `(ia, ib)` of the stored half: merged with its mirror.
    #[inline]
    pub fn label(&self, ia: usize, ib: usize) -> Label {
        let own = self.space.labels[ia * self.nb + ib];
        if !self.symmetric || self.mirrored_exactly {
            return own;
        }
        let (ra, rb) = (self.refl_a[ia], self.refl_b[ib]);
        if ra == NONE || rb == NONE {
            return own;
        }
        merge(own, self.space.labels[ra as usize * self.nb + rb as usize])
    }

    /// The label of `(ia, ib)` itself, not merged with its mirror.
    #[inline]
    pub fn own_label(&self, ia: usize, ib: usize) -> Label {
        self.space.labels[ia * self.nb + ib]
    }

    /// The mirror pair whose label [`label`](Self::label) merges in, if any.
    pub fn mirror_pair(&self, ia: usize, ib: usize) -> Option<(usize, usize)> {
        if !self.symmetric {
            return None;
        }
        let (ra, rb) = (self.refl_a[ia], self.refl_b[ib]);
        (ra != NONE && rb != NONE).then_some((ra as usize, rb as usize))
    }

    /// Pairs of the stored half where the label and its mirror's disagree as free/collision.
    pub fn asymmetric_pairs(&self) -> usize {
        if !self.symmetric {
            return 0;
        }
        let disagree = |(own, other): (Label, Label)| {
            own != Label::Unreachable && other != Label::Unreachable && other != own
        };
        (0..self.space.grid_a.cells.len())
            .filter(|&ia| self.stored(ia))
            .map(|ia| self.row_with_mirrors(ia).filter(|&p| disagree(p)).count())
            .sum()
    }
}

/// Maps a query cell into the stored half: `None` when an index is `>= k` (the caller then
/// answers collision), else the cell, reflected when symmetric and `iy < k/2`.
#[inline]
pub(crate) fn fold(cell: [u16; 6], k: u32, symmetric: bool) -> Option<[u16; 6]> {
    if cell.iter().any(|&v| u32::from(v) >= k) {
        return None;
    }
    let mut c = cell;
    if symmetric && u32::from(c[1]) < k / 2 {
        let top = (k - 1) as u16;
        c[1] = top - c[1];
        c[4] = top - c[4];
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::synthetic::{space, Pattern};

    /// A symmetric view answers each stored pair with its label merged with its mirror pair's,
    /// whether it reads the mirror (labels that are not mirror images) or knows it need not
    /// (labels that are).
    #[test]
    fn stored_labels_merge_with_their_mirrors_read_or_not() {
        for (pattern, exact) in [
            (Pattern::Noise { p: 0.3, seed: 5 }, true),
            (Pattern::AsymmetricNoise { p: 0.3, seed: 5 }, false),
        ] {
            let s = space(3, pattern);
            let view = SpaceView::new(&s, true).unwrap();
            assert_eq!(view.mirrored_exactly, exact, "{pattern:?}");
            let (mut merged, mut changed) = (0, 0);
            for ia in (0..s.grid_a.cells.len()).filter(|&ia| view.stored(ia)) {
                for ib in 0..s.grid_b.cells.len() {
                    let own = s.label(ia, ib);
                    let want = view
                        .mirror_pair(ia, ib)
                        .map_or(own, |(ra, rb)| merge(own, s.label(ra, rb)));
                    assert_eq!(view.label(ia, ib), want, "{pattern:?} ({ia}, {ib})");
                    merged += usize::from(view.mirror_pair(ia, ib).is_some());
                    changed += usize::from(want != own);
                }
            }
            assert!(
                merged > 0 && (changed > 0) != exact,
                "{pattern:?}: {merged} merged, {changed} changed"
            );
        }
    }
}
