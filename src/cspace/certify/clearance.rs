//! Certified clearance levels of every sample pair (SPEC §8's clearance, SPEC §6's proof):
//! how many levels of a ladder are proved for the whole 6-D grid cell, for the clearance
//! tables (`crate::table::clearance`).
//!
//! Level `L` is proved for a pair when robot A's whole-cell boxes, each swept by its
//! displacement set with `L` mm added to the set's ball, are proved apart from B's swept
//! boxes (level 1 of the certified labelling with a gap, as the protective verdict proves a
//! gap of `extra` mm): every point of A's boxes then lies more than `L` from every point of
//! B's boxes for every configuration of the cell, so the clearance there is at least `L`.
//! Level 0 is the certified label itself: a pair labelled free (by level 1 or by the octants
//! of level 2) has clearance `>= 0`, a pair labelled collision or unreachable has no level,
//! so the pairs with a level are exactly the free ones when the ladder starts at 0.
//!
//! The largest proved level is found by testing the top level first (far pairs), then by
//! bisection over the ladder. Each answer is a proof on its own, so a ladder on which the
//! proofs are not monotone only costs levels, never soundness.

use super::sweeps::{cell_sweeps, inflation, references, unreachable_cells};
use crate::cell::Cell;
use crate::cspace::label::{entries_collide, two_robot_grids, Inflation, Rows, SampleBoxes, Slot};
use crate::cspace::sampler::Workspace;
use crate::cspace::{Label, PairLabels};
use crate::geometry::Sweep;
use crate::math::Real;
use rayon::prelude::*;

/// Per pair of the rows `rows` of A (laid out as `labels`, the certified labels of those
/// rows), how many levels of `ladder_mm` (increasing, mm) are proved; 0 for every pair not
/// labelled free.
///
/// # Errors
/// As [`crate::cspace::label_space`] (the grids of `cell` at `k`), or when `labels` does not
/// hold one label per pair of the rows.
pub(crate) fn clearance_counts(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    labels: &PairLabels,
    ladder_mm: &[Real],
    rows: Rows,
) -> Result<Vec<u8>, String> {
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (na, nb) = (grid_a.cells.len(), grid_b.cells.len());
    if labels.len() != rows.count(na) * nb {
        return Err(format!("{} labels for {} x {nb} pairs", labels.len(), rows.count(na)));
    }
    let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
    let (sweeps_a, empty_a, refs_a) = (
        cell_sweeps(&ra.model, &grid_a),
        unreachable_cells(&ra.model, &grid_a),
        references(&ra.model, &grid_a),
    );
    let (sweeps_b, empty_b, refs_b) = (
        cell_sweeps(&rb.model, &grid_b),
        unreachable_cells(&rb.model, &grid_b),
        references(&rb.model, &grid_b),
    );
    let b = SampleBoxes::new(&rb.model, &rb.placement, &refs_b, |s| {
        if empty_b[s] {
            Inflation::Unreachable
        } else {
            inflation(sweeps_b[s])
        }
    });
    // A's boxes once per level, every sweep's ball grown by the level.
    let a_at: Vec<SampleBoxes> = ladder_mm
        .iter()
        .map(|&extra| {
            SampleBoxes::new(&ra.model, &ra.placement, &refs_a, |s| {
                match (empty_a[s], inflation(sweeps_a[s])) {
                    (true, _) => Inflation::Unreachable,
                    (false, Inflation::Swept(sw)) => {
                        Inflation::Swept(sw.map(|w| Sweep { ball: w.ball + extra, ..w }))
                    }
                    (false, other) => other,
                }
            })
        })
        .collect();
    let mut counts = vec![0u8; labels.len()];
    if nb == 0 {
        return Ok(counts);
    }
    counts.par_chunks_mut(nb).enumerate().for_each(|(j, row)| {
        let ia = rows.row(j);
        for (ib, c) in row.iter_mut().enumerate() {
            if labels[j * nb + ib] == Label::Free {
                *c = proved_levels(ladder_mm, |i| {
                    let a = &a_at[i];
                    a.slot[ia] == Slot::Boxes
                        && b.slot[ib] == Slot::Boxes
                        && !entries_collide(a, ia, &b, ib)
                });
            }
        }
    });
    Ok(counts)
}

/// How many levels of a pair labelled free are proved, `apart(i)` proving level `i` (with
/// `ladder_mm[i]` added): a level of 0 mm needs no test (the free label proves it); the top
/// level is tried first, then the ladder is bisected.
fn proved_levels(ladder_mm: &[Real], apart: impl Fn(usize) -> bool) -> u8 {
    let n = ladder_mm.len();
    let proved = |i: usize| ladder_mm[i] == 0.0 || apart(i);
    if proved(n - 1) {
        return n as u8;
    }
    // Invariant: level `lo - 1` proved (or `lo == 0`), level `hi` not.
    let (mut lo, mut hi) = (0usize, n - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if proved(mid) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_finds_the_largest_proved_level_of_a_monotone_ladder() {
        let ladder = [0.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0];
        for gap in [-1.0, 0.0, 3.0, 5.0, 7.0, 19.0, 20.0, 100.0, 159.0, 200.0] {
            let want = ladder.iter().filter(|&&l| l < gap || l == 0.0).count() as u8;
            let got = proved_levels(&ladder, |i| ladder[i] < gap);
            assert_eq!(got, want, "gap {gap}");
        }
        // Without a 0 mm level, nothing is given for free.
        assert_eq!(proved_levels(&[1.0, 2.0], |_| false), 0);
        assert_eq!(proved_levels(&[1.0, 2.0], |i| i == 0), 1);
    }

    #[test]
    fn a_non_monotone_proof_only_ever_returns_a_proved_level() {
        let ladder = [1.0, 2.0, 3.0, 4.0, 5.0];
        for mask in 0u32..32 {
            let got = proved_levels(&ladder, |i| mask >> i & 1 == 1) as usize;
            assert!(got == 0 || mask >> (got - 1) & 1 == 1, "mask {mask:05b}: {got}");
        }
    }
}
