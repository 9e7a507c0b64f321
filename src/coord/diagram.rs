//! The coordination diagram of two robots' programmes (Kant and Zucker's path-velocity
//! decomposition; SPEC §9), sampled: robot `i`'s programme samples `a` against robot `j`'s
//! samples `b`, a cell `(a, b)` in conflict when the two robots' boxes, each grown by
//! `clearance_mm / 2`, are not separated by an axis (then their clearance may be under
//! `clearance_mm`; a grown box holds every point within the growth of the box).
//!
//! Samples live in rings indexed by their absolute sample number (`programme tick / stride`)
//! modulo [`MAX_SAMPLES`], so that a cell once tested is not tested again while both samples
//! stay in the horizon: each tick tests only the cells of samples the horizon gained. A
//! sample whose set-point changed (a replanned programme) is placed again and its row or
//! column forgotten.

use crate::cell::exact::{aabb_of, pair_state, PairState, RobotInWcs};
use crate::cell::ExactChecker;
use crate::math::{Real, Vec3};
use crate::robot::RobotBoxes;

/// Samples of one robot's horizon at most (the ring's size; a row of the diagram is one
/// `u128` mask).
pub const MAX_SAMPLES: usize = 128;

/// One programme sample of a robot: its set-point and its boxes there, grown and in the WCS.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Absolute sample number (`programme tick / stride`); `u64::MAX` when the slot is empty.
    pub number: u64,
    /// The set-point (MCS, mm).
    pub tcp: Vec3,
    /// Whether the set-point is reachable (an unreachable one conflicts with everything).
    pub reachable: bool,
    /// The boxes, each grown by half the diagram's clearance, in the WCS.
    pub boxes: RobotBoxes,
    /// Centre and half-extents of their AABB.
    pub aabb: (Vec3, Vec3),
}

impl Sample {
    fn empty() -> Sample {
        let zero = Vec3::zeros();
        Sample {
            number: u64::MAX,
            tcp: zero,
            reachable: false,
            boxes: RobotBoxes::empty(),
            aabb: (zero, zero),
        }
    }
}

/// One robot's ring of samples.
#[derive(Clone, Debug)]
pub struct Track {
    /// Slot `number % MAX_SAMPLES` holds sample `number`.
    pub slots: alloc::boxed::Box<[Sample; MAX_SAMPLES]>,
    /// Slots placed again since the diagrams last read this track (bit per slot).
    pub replaced: u128,
}

impl Default for Track {
    fn default() -> Self {
        Track { slots: alloc::boxed::Box::new([Sample::empty(); MAX_SAMPLES]), replaced: 0 }
    }
}

impl Track {
    /// Puts sample `number` with set-point `tcp` of robot `robot` in its slot, unless that slot
    /// already holds it with the same set-point bit for bit.
    pub fn place(
        &mut self,
        exact: &ExactChecker,
        robot: usize,
        number: u64,
        tcp: &Vec3,
        growth_mm: Real,
    ) {
        let slot = (number % MAX_SAMPLES as u64) as usize;
        let s = &mut self.slots[slot];
        let same =
            |a: &Vec3, b: &Vec3| a.iter().zip(b.iter()).all(|(x, y)| x.to_bits() == y.to_bits());
        if s.number == number && same(&s.tcp, tcp) {
            return;
        }
        s.number = number;
        s.tcp = *tcp;
        s.reachable = exact.boxes_in_wcs(robot, tcp, &mut s.boxes).is_ok();
        if s.reachable {
            for b in &mut s.boxes.boxes[..s.boxes.len] {
                *b = b.inflated(growth_mm);
            }
            s.aabb = aabb_of(&s.boxes);
        }
        self.replaced |= 1 << slot;
    }

    /// Empties every slot (in place: no allocation).
    pub fn clear(&mut self) {
        self.slots.iter_mut().for_each(|s| s.number = u64::MAX);
        self.replaced = u128::MAX;
    }

    /// The slot of sample `number` when the ring holds it.
    pub fn slot_of(&self, number: u64) -> Option<usize> {
        let slot = (number % MAX_SAMPLES as u64) as usize;
        (self.slots[slot].number == number).then_some(slot)
    }
}

/// What is known of the cells of one robot pair `(i, j)`: per slot of `i`, the slots of `j`
/// tested and those in conflict; and the same by columns.
#[derive(Clone, Debug)]
pub struct Diagram {
    rows_known: [u128; MAX_SAMPLES],
    rows_conflict: [u128; MAX_SAMPLES],
    cols_known: [u128; MAX_SAMPLES],
    cols_conflict: [u128; MAX_SAMPLES],
    /// Cells tested so far (for reports and budgets).
    pub tests: u64,
}

impl Default for Diagram {
    fn default() -> Self {
        let none = [0; MAX_SAMPLES];
        Diagram {
            rows_known: none,
            rows_conflict: none,
            cols_known: none,
            cols_conflict: none,
            tests: 0,
        }
    }
}

/// Whether two samples' grown boxes may touch (module doc).
fn conflict_of(a: &Sample, b: &Sample) -> bool {
    if !(a.reachable && b.reachable) {
        return true;
    }
    let ra = RobotInWcs { boxes: a.boxes.as_slice(), aabb: &a.aabb };
    let rb = RobotInWcs { boxes: b.boxes.as_slice(), aabb: &b.aabb };
    !matches!(pair_state(&ra, &rb, None), PairState::Free)
}

impl Diagram {
    /// Forgets the rows of `i`'s replaced slots and the columns of `j`'s.
    pub fn forget(&mut self, replaced_i: u128, replaced_j: u128) {
        for slot in ones(replaced_i) {
            self.rows_known[slot] = 0;
            self.rows_conflict[slot] = 0;
        }
        for slot in ones(replaced_j) {
            self.cols_known[slot] = 0;
            self.cols_conflict[slot] = 0;
        }
        let (keep_cols, keep_rows) = (!replaced_j, !replaced_i);
        for r in 0..MAX_SAMPLES {
            self.rows_known[r] &= keep_cols;
            self.rows_conflict[r] &= keep_cols;
            self.cols_known[r] &= keep_rows;
            self.cols_conflict[r] &= keep_rows;
        }
    }

    /// Whether sample slot `a` of `i` conflicts with any slot of `j` in `window` (bit per slot),
    /// testing the cells not yet known.
    pub fn row_conflicts(&mut self, ti: &Track, tj: &Track, a: usize, window: u128) -> bool {
        self.line_conflicts(ti, tj, a, window, true)
    }

    /// Whether sample slot `b` of `j` conflicts with any slot of `i` in `window`.
    pub fn col_conflicts(&mut self, ti: &Track, tj: &Track, b: usize, window: u128) -> bool {
        self.line_conflicts(ti, tj, b, window, false)
    }

    /// A row (`row`: slot `at` of `i` against `j`'s slots in `window`) or a column (slot `at`
    /// of `j` against `i`'s): whether it holds a conflict, testing the cells not yet known.
    fn line_conflicts(
        &mut self,
        ti: &Track,
        tj: &Track,
        at: usize,
        window: u128,
        row: bool,
    ) -> bool {
        let (known, conflict) = if row {
            (self.rows_known[at], self.rows_conflict[at])
        } else {
            (self.cols_known[at], self.cols_conflict[at])
        };
        if conflict & window != 0 {
            return true;
        }
        for other in ones(window & !known) {
            let (a, b) = if row { (at, other) } else { (other, at) };
            let hit = conflict_of(&ti.slots[a], &tj.slots[b]);
            self.record(a, b, hit);
            if hit {
                return true;
            }
        }
        false
    }

    fn record(&mut self, a: usize, b: usize, hit: bool) {
        self.tests += 1;
        self.rows_known[a] |= 1 << b;
        self.cols_known[b] |= 1 << a;
        if hit {
            self.rows_conflict[a] |= 1 << b;
            self.cols_conflict[b] |= 1 << a;
        }
    }
}

/// The set bits of `mask`, lowest first (at most 128: a bounded loop).
fn ones(mut mask: u128) -> impl Iterator<Item = usize> {
    core::iter::from_fn(move || {
        (mask != 0).then(|| {
            let bit = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            bit
        })
    })
}

/// The slots of samples `first .. first + count` (`count <= MAX_SAMPLES`) as a mask.
pub fn window(first: u64, count: usize) -> u128 {
    let mut mask = 0u128;
    for k in 0..count.min(MAX_SAMPLES) as u64 {
        mask |= 1 << ((first + k) % MAX_SAMPLES as u64);
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_wrap_around_the_ring() {
        assert_eq!(window(0, 3), 0b111);
        assert_eq!(window(126, 3), (1 << 126) | (1 << 127) | 1);
        assert_eq!(window(5, MAX_SAMPLES), u128::MAX);
        assert_eq!(ones(0b1010_0001).collect::<alloc::vec::Vec<_>>(), [0, 5, 7]);
    }
}
