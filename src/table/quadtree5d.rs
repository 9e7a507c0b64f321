//! The linear 5-D quadtree: location codes over `(x, y, z, x', y')` with the collision
//! intervals of the ignored `z'` at each leaf (thesis 3.2.5, Algorithms 6 and 7,
//! Observation 3.2.2; SPEC §6).
//!
//! Intervals are grid indices `[begin, end]` of `iz'` (one byte each, `k <= 256`) instead of
//! the thesis's pairs of doubles; the leaves' intervals lie in one array, indexed by an offset
//! array. Don't-care `iz'` values (unreachable or unsampled) join two collision runs when no
//! free sample lies between them, so a monotone column is always one interval.

use super::code::{encode, MAX_LEVELS};
use super::error::{corrupt, TableError};
use super::space::fold;
#[cfg(feature = "std")]
use super::space::SpaceView;
#[cfg(feature = "std")]
use crate::cspace::symmetry::Symmetry;
#[cfg(feature = "std")]
use crate::cspace::{Label, LabelledSpace};
use alloc::{format, vec::Vec};

/// Sorted 5-D codes with the `iz'` collision intervals of each (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinearQuadtree5d {
    levels: u32,
    symmetric: bool,
    codes: Vec<u64>,
    offsets: Vec<u32>,
    intervals: Vec<[u8; 2]>,
}

/// The collision intervals of one column, given `(iz', label)` in increasing `iz'`.
#[cfg(feature = "std")]
fn column_intervals(column: impl Iterator<Item = (u16, Label)>, out: &mut Vec<[u8; 2]>) {
    let mut open: Option<[u8; 2]> = None;
    let mut free_since = false;
    for (z, label) in column {
        match label {
            Label::Collision => {
                match open.as_mut() {
                    Some(iv) if !free_since => iv[1] = z as u8,
                    _ => {
                        out.extend(open.take());
                        open = Some([z as u8, z as u8]);
                    }
                }
                free_since = false;
            }
            Label::Free => free_since = true,
            Label::Unreachable => {}
        }
    }
    out.extend(open);
}

impl LinearQuadtree5d {
    /// Builds the table of `space` (thesis Algorithm 6); with [`Symmetry::MirrorY`], only A's upper
    /// half `iy >= k/2` is stored.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or the label count is wrong.
    #[cfg(feature = "std")]
    pub fn build(
        space: &LabelledSpace,
        symmetry: Symmetry,
    ) -> Result<LinearQuadtree5d, TableError> {
        let symmetric = symmetry.is_mirrored();
        let view = SpaceView::new(space, symmetric)?;
        let cells_b = &space.grid_b.cells;
        // B's samples in (ix', iy', iz') order, cut into columns of equal (ix', iy').
        let mut order: Vec<usize> = (0..cells_b.len()).collect();
        order.sort_by_key(|&i| cells_b[i]);
        let columns: Vec<&[usize]> =
            order.chunk_by(|&i, &j| cells_b[i][..2] == cells_b[j][..2]).collect();
        let mut nodes: Vec<(u64, Vec<[u8; 2]>)> = Vec::new();
        let mut buf = Vec::new();
        for (ia, a) in space.grid_a.cells.iter().enumerate() {
            if !view.stored(ia) {
                continue;
            }
            for col in &columns {
                buf.clear();
                column_intervals(
                    col.iter().map(|&ib| (cells_b[ib][2], view.label(ia, ib))),
                    &mut buf,
                );
                if !buf.is_empty() {
                    let b = cells_b[col[0]];
                    nodes.push((encode([a[0], a[1], a[2], b[0], b[1]], 5), buf.clone()));
                }
            }
        }
        nodes.sort_unstable_by_key(|n| n.0);
        let mut t = LinearQuadtree5d {
            levels: view.levels,
            symmetric,
            codes: vec![],
            offsets: vec![0],
            intervals: vec![],
        };
        for (code, ivs) in nodes {
            t.codes.push(code);
            t.intervals.extend(ivs);
            t.offsets.push(t.intervals.len() as u32);
        }
        Ok(t)
    }

    /// A table from stored parts, validated so that [`query`](Self::query) is exact and safe.
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field: levels, a code out of range or
    /// out of order, offsets not running from 0 to the interval count, an interval with
    /// `begin > end` or `end >= k`.
    pub fn from_parts(
        levels: u32,
        symmetric: bool,
        codes: Vec<u64>,
        offsets: Vec<u32>,
        intervals: Vec<[u8; 2]>,
    ) -> Result<LinearQuadtree5d, TableError> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(corrupt(format!("levels = {levels} must be in 1..={MAX_LEVELS}")));
        }
        if let Some(i) = codes.iter().position(|&c| c >> (5 * levels) != 0) {
            return Err(corrupt(format!(
                "codes[{i}] = {:#x} has bits above {levels} 5-bit levels",
                codes[i]
            )));
        }
        if let Some(i) = codes.windows(2).position(|w| w[0] >= w[1]) {
            return Err(corrupt(format!(
                "codes[{}] is not greater than codes[{i}]: codes are not sorted",
                i + 1
            )));
        }
        if offsets.len() != codes.len() + 1
            || offsets[0] != 0
            || offsets[codes.len()] as usize != intervals.len()
        {
            return Err(corrupt(format!(
                "offsets must hold {} entries from 0 to the interval count {}",
                codes.len() + 1,
                intervals.len()
            )));
        }
        if let Some(i) = offsets.windows(2).position(|w| w[0] > w[1]) {
            return Err(corrupt(format!("offsets[{}] is below offsets[{i}]", i + 1)));
        }
        let k = 1u32 << levels;
        if let Some(i) = intervals.iter().position(|iv| iv[0] > iv[1] || u32::from(iv[1]) >= k) {
            return Err(corrupt(format!(
                "intervals[{i}] = {:?} is not within 0..{k} in order",
                intervals[i]
            )));
        }
        Ok(LinearQuadtree5d { levels, symmetric, codes, offsets, intervals })
    }

    /// Whether the 6-D cell is stored as collision (thesis Algorithm 7); an index `>= k`
    /// answers `true`. Never allocates.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let Some(c) = fold(cell, 1 << self.levels, self.symmetric) else {
            return true;
        };
        let Ok(i) = self.codes.binary_search(&encode([c[0], c[1], c[2], c[3], c[4]], 5)) else {
            return false;
        };
        let (lo, hi) = (self.offsets.get(i), self.offsets.get(i + 1));
        let Some(ivs) =
            lo.zip(hi).and_then(|(&lo, &hi)| self.intervals.get(lo as usize..hi as usize))
        else {
            return true;
        };
        let z = c[5];
        ivs.iter().any(|iv| u16::from(iv[0]) <= z && z <= u16::from(iv[1]))
    }

    /// Quadtree levels (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// The stored parts: codes, offsets (`m + 1`), intervals.
    pub fn parts(&self) -> (&[u64], &[u32], &[[u8; 2]]) {
        (&self.codes, &self.offsets, &self.intervals)
    }

    /// Bytes this table occupies in memory (struct plus its arrays).
    pub fn memory_bytes(&self) -> usize {
        core::mem::size_of::<Self>()
            + 8 * self.codes.len()
            + 4 * self.offsets.len()
            + 2 * self.intervals.len()
    }

    /// The thesis's figure for the same counts, `12 m + 16 i + 64` (Observation 3.2.2).
    pub fn thesis_bytes(&self) -> usize {
        12 * self.codes.len() + 16 * self.intervals.len() + 64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Label::{Collision as C, Free as F, Unreachable as U};

    fn ivs(col: &[(u16, Label)]) -> Vec<[u8; 2]> {
        let mut out = Vec::new();
        column_intervals(col.iter().copied(), &mut out);
        out
    }

    #[test]
    fn intervals_of_columns() {
        assert_eq!(ivs(&[(0, F), (1, C), (2, C), (3, F)]), vec![[1, 2]]);
        assert_eq!(ivs(&[(0, C), (1, F), (2, C)]), vec![[0, 0], [2, 2]]);
        assert_eq!(ivs(&[(0, C), (1, U), (3, C), (4, U)]), vec![[0, 3]], "don't care joins runs");
        assert_eq!(ivs(&[(0, C), (1, U), (2, F), (3, U), (4, C)]), vec![[0, 0], [4, 4]]);
        assert!(ivs(&[(0, F), (1, U)]).is_empty());
    }

    #[test]
    fn from_parts_rejects_bad_intervals() {
        assert!(LinearQuadtree5d::from_parts(2, false, vec![1], vec![0, 1], vec![[0, 3]]).is_ok());
        assert!(
            LinearQuadtree5d::from_parts(2, false, vec![1], vec![0, 1], vec![[0, 4]]).is_err(),
            "end >= k"
        );
        assert!(
            LinearQuadtree5d::from_parts(2, false, vec![1], vec![0, 1], vec![[2, 1]]).is_err(),
            "reversed"
        );
        assert!(
            LinearQuadtree5d::from_parts(2, false, vec![1], vec![0, 2], vec![[0, 1]]).is_err(),
            "offset"
        );
        assert!(
            LinearQuadtree5d::from_parts(2, false, vec![2, 1], vec![0, 0, 1], vec![[0, 1]])
                .is_err(),
            "order"
        );
        assert!(
            LinearQuadtree5d::from_parts(2, false, vec![1 << 10], vec![0, 1], vec![[0, 1]])
                .is_err(),
            "bits"
        );
    }
}
