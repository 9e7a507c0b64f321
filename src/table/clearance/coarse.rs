//! The level tree's input (module doc of `clearance`): the labelled space coarsened by
//! `2^shift` grid cells per axis and robot, each coarse pair holding the smallest level
//! count of the free pairs in it.

use crate::cspace::{CellIndex, Label, LabelledSpace, PairLabels, SampleGrid};

/// `grid` with every cell index shifted right by `shift`: the coarse cells that hold a
/// sample, sorted, and for each sample its coarse cell's index.
fn coarse_grid(grid: &SampleGrid, shift: u32) -> (SampleGrid, Vec<u32>) {
    let mut cells: Vec<CellIndex> = grid.cells.iter().map(|c| c.map(|v| v >> shift)).collect();
    cells.sort_unstable();
    cells.dedup();
    let index = grid
        .cells
        .iter()
        .map(|c| cells.binary_search(&c.map(|v| v >> shift)).expect("a coarse cell") as u32);
    let index = index.collect();
    let reachable = vec![true; cells.len()];
    let coarse = SampleGrid {
        k: grid.k >> shift,
        levels: grid.levels - shift,
        r: grid.r * f64::from(1u32 << shift),
        origin: grid.origin,
        cells,
        reachable,
    };
    (coarse, index)
}

/// The coarse space and its counts: a coarse pair with a free pair in it gets the smallest
/// count among its free pairs, and is labelled free when that is `n_top` (every level),
/// collision otherwise; a coarse pair with no free pair in it is unreachable ("don't care":
/// the exact tree answers its cells).
pub(super) fn coarsen(
    space: &LabelledSpace,
    counts: &[u8],
    shift: u32,
    n_top: u8,
) -> (LabelledSpace, Vec<u8>) {
    let (ga, ia_of) = coarse_grid(&space.grid_a, shift);
    let (gb, ib_of) = coarse_grid(&space.grid_b, shift);
    let (nb, cnb) = (space.grid_b.cells.len(), gb.cells.len());
    let mut min = vec![u8::MAX; ga.cells.len() * cnb];
    for (pair, (l, &c)) in space.labels.iter().zip(counts).enumerate() {
        if l == Label::Free {
            let m = &mut min[ia_of[pair / nb] as usize * cnb + ib_of[pair % nb] as usize];
            *m = (*m).min(c);
        }
    }
    let labels: Vec<Label> = min
        .iter()
        .map(|&m| match m {
            u8::MAX => Label::Unreachable,
            m if m >= n_top => Label::Free,
            _ => Label::Collision,
        })
        .collect();
    let labels = PairLabels::from_labels(cnb, &labels);
    let counts = min.iter().map(|&m| if m == u8::MAX { 0 } else { m }).collect();
    (LabelledSpace { grid_a: ga, grid_b: gb, labels, margin: space.margin }, counts)
}
