//! Table-backed queries for a cell of any number of robots: one lookup per pair that can meet,
//! each in the table of its pair cell from a bundle (thesis 3.2 query phase; SPEC §6).
//!
//! The pairs are the exact checker's ([`Cell::pairs_that_can_meet`]); a pair whose robots can
//! never meet has no table and no lookup. Each distinct table is loaded once into a
//! [`TableChecker`] of its pair cell, which every pair using it shares: a pair's lookup is that
//! checker's lookup on the pair's two TCPs, each in its own MCS, with the same exact fallback
//! and confirmation as for two robots. A pair whose robots stay in the cells of its last FREE
//! label keeps that answer without a lookup. Nothing allocates per tick.

use crate::cell::{Cell, QueryError};
use crate::math::Vec3;
use crate::robot::RobotModel;
use crate::table::bundle::{bundle_from_bytes, pair_cell, Bundle};
use crate::table::{Confirmation, TableAnswer, TableChecker, TableError};
use alloc::vec::Vec;

/// One pair's answer in the last query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairAnswer {
    /// First robot (index in the cell), `a < b`.
    pub a: usize,
    /// Second robot.
    pub b: usize,
    /// Index of the pair's table (of [`BundleChecker::table_count`]).
    pub table: usize,
    /// The pair's answer; [`TableAnswer::Unreachable`] when a TCP of the cell was unreachable
    /// (no lookup was made).
    pub answer: TableAnswer,
    /// The colliding boxes (robot `a`'s, robot `b`'s) when the exact check answered COLLISION.
    pub boxes: Option<(usize, usize)>,
}

/// One robot's TCP on one grid: the robot, and the table checker and side (0 or 1) whose grid
/// it is; every pair whose table has an equal grid on that robot's side reads the same cell.
#[derive(Clone, Copy, Debug)]
struct GridSlot {
    robot: usize,
    checker: usize,
    side: usize,
}

/// The loaded tables of a bundle and the pairs of the controller's cell that use them.
#[derive(Clone, Debug)]
pub struct BundleChecker {
    cell: Cell,
    models: Vec<RobotModel>,
    checkers: Vec<TableChecker>,
    pairs: Vec<PairAnswer>,
    /// The distinct (robot, grid) cells a tick needs: a line's tables share one grid, so each
    /// robot's cell is taken once per tick rather than once per pair it is in.
    slots: Vec<GridSlot>,
    /// Per pair, the slots of its robots `a` and `b`.
    pair_slots: Vec<[usize; 2]>,
    /// Per slot, the cell of the last tick (`None`: robot unreachable or outside the grid).
    cells: Vec<Option<[u16; 3]>>,
    /// The robots in no pair that can meet (no slot decides their reachability).
    unpaired: Vec<usize>,
    /// Robots `a < b`'s table at `a n + b` (`n` robots; `None`: the pair can never meet).
    pair_tables: Vec<Option<usize>>,
    /// Per pair, the robots' cells of its last lookup that the table labelled FREE.
    free_cells: Vec<Option<[[u16; 3]; 2]>>,
}

impl BundleChecker {
    /// Loads the bundle `bytes` (or a single table file) for `cell`, validating it once; each
    /// pair that can meet gets the table of its pair cell, and COLLISION lookups are answered
    /// as `confirmation` says.
    ///
    /// # Errors
    /// Every [`TableError`] of loading a bundle and its tables; [`TableError::MissingPair`] or
    /// [`TableError::WrongPair`] for the first pair the bundle does not serve;
    /// [`TableError::WrongCell`] when a table disagrees with what its pair cell determines.
    pub fn new(
        cell: Cell,
        bytes: &[u8],
        confirmation: Confirmation,
    ) -> Result<BundleChecker, TableError> {
        BundleChecker::from_bundle(cell, &bundle_from_bytes(bytes)?, confirmation)
    }

    /// As [`BundleChecker::new`], from a bundle already read.
    ///
    /// # Errors
    /// As [`BundleChecker::new`], apart from reading.
    pub fn from_bundle(
        cell: Cell,
        bundle: &Bundle,
        confirmation: Confirmation,
    ) -> Result<BundleChecker, TableError> {
        let mut used: Vec<(usize, usize)> = Vec::new(); // (bundle table index, our index)
        let mut checkers = Vec::new();
        let mut pairs = Vec::new();
        for (a, b) in cell.pairs_that_can_meet() {
            let i = bundle.table_for(&cell, a, b)?;
            let table = match used.iter().find(|(t, _)| *t == i) {
                Some(&(_, ours)) => ours,
                None => {
                    let (header, table) = bundle.tables[i].clone();
                    checkers.push(TableChecker::from_loaded(
                        pair_cell(&cell, a, b),
                        header,
                        table,
                        confirmation,
                    )?);
                    used.push((i, checkers.len() - 1));
                    checkers.len() - 1
                }
            };
            pairs.push(PairAnswer {
                a,
                b,
                table,
                answer: TableAnswer::Unreachable(0),
                boxes: None,
            });
        }
        let mut slots: Vec<GridSlot> = Vec::new();
        let mut pair_slots = Vec::with_capacity(pairs.len());
        for p in &pairs {
            let mut slot_of = |robot: usize, side: usize| {
                let same = |s: &GridSlot| {
                    s.robot == robot
                        && checkers[s.checker].same_grid(s.side, &checkers[p.table], side)
                };
                slots.iter().position(same).unwrap_or_else(|| {
                    slots.push(GridSlot { robot, checker: p.table, side });
                    slots.len() - 1
                })
            };
            pair_slots.push([slot_of(p.a, 0), slot_of(p.b, 1)]);
        }
        let cells = alloc::vec![None; slots.len()];
        let models = cell.robots.iter().map(|r| r.model).collect();
        let unpaired =
            (0..cell.robots.len()).filter(|&j| !slots.iter().any(|s| s.robot == j)).collect();
        let free_cells = alloc::vec![None; pairs.len()];
        let n = cell.robots.len();
        let mut pair_tables = alloc::vec![None; n * n];
        for p in &pairs {
            pair_tables[p.a * n + p.b] = Some(p.table);
        }
        Ok(BundleChecker {
            cell,
            models,
            checkers,
            pairs,
            slots,
            pair_slots,
            cells,
            unpaired,
            pair_tables,
            free_cells,
        })
    }

    /// The cell.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }

    /// The distinct tables the pairs use.
    pub fn table_count(&self) -> usize {
        self.checkers.len()
    }

    /// The checker of table `i` (its pair cell, header and table).
    pub fn table_checker(&self, i: usize) -> &TableChecker {
        &self.checkers[i]
    }

    /// The pairs that can meet with their last answers.
    pub fn pairs(&self) -> &[PairAnswer] {
        &self.pairs
    }

    /// Queries so far answered by the exact check because a TCP lay outside a table's grid,
    /// summed over the pairs.
    pub fn fallbacks(&self) -> u64 {
        self.checkers.iter().map(TableChecker::fallbacks).sum()
    }

    /// Lookups so far that said COLLISION and were confirmed by the exact check, summed over
    /// the pairs.
    pub fn confirmations(&self) -> u64 {
        self.checkers.iter().map(TableChecker::confirmations).sum()
    }

    /// Whether every table the pairs use is a clearance table (`build --variant clearance`),
    /// so that [`BundleChecker::clearance_bound`] can prove something for every pair.
    pub fn has_clearance(&self) -> bool {
        !self.checkers.is_empty()
            && self.checkers.iter().all(|c| c.table().as_clearance().is_some())
    }

    /// The certified lower bound on the clearance (mm) of robots `a` and `b` (a pair that can
    /// meet, `a < b`) with TCPs `[tcp_a, tcp_b]`, each in its own MCS: their table's
    /// [`TableChecker::clearance_bound`]. `None` when nothing is proved, or for a pair that
    /// has no table (it can never meet: no bound is needed).
    pub fn clearance_bound(&self, a: usize, b: usize, tcps_mcs: &[Vec3]) -> Option<f64> {
        let n = self.models.len();
        if !(a < b && b < n) {
            return None;
        }
        let table = self.pair_tables[a * n + b]?;
        self.checkers[table].clearance_bound(tcps_mcs)
    }

    /// How a COLLISION lookup is answered.
    pub fn confirmation(&self) -> Confirmation {
        self.checkers.first().map_or(Confirmation::Exact, TableChecker::confirmation)
    }

    /// Chooses how a COLLISION lookup is answered from the next query on.
    pub fn set_confirmation(&mut self, confirmation: Confirmation) {
        self.checkers.iter_mut().for_each(|c| c.set_confirmation(confirmation));
    }

    /// Bit j set: robot j's TCP (in its own MCS) is unreachable or not finite.
    pub fn unreachable_mask(&self, tcps_mcs: &[Vec3]) -> u32 {
        let reachable =
            |j: usize| tcps_mcs.get(j).is_some_and(|t| self.models[j].delta.is_reachable(t));
        (0..self.models.len()).fold(0u32, |m, j| m | u32::from(!reachable(j)) << j)
    }

    /// Answers one tick; `tcps_mcs[j]` is robot j's TCP in its own MCS. COLLISION when any
    /// pair's answer is COLLISION; every pair is answered ([`BundleChecker::pairs`]).
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] unless one TCP per robot is given.
    pub fn check(&mut self, tcps_mcs: &[Vec3]) -> Result<TableAnswer, QueryError> {
        if tcps_mcs.len() != self.models.len() {
            return Err(QueryError::WrongRobotCount {
                expected: self.models.len(),
                found: tcps_mcs.len(),
            });
        }
        // As the exact check: a pair with an unreachable robot has no answer, every other pair
        // is answered, and the tick's answer is unreachable.
        // Each robot's cell once per grid, which also decides its reachability (the same answer
        // on every grid: `TableChecker::locate`); an unreachable robot's pairs look nothing up.
        let mut mask = 0u32;
        for (cell, s) in self.cells.iter_mut().zip(&self.slots) {
            let located = self.checkers[s.checker].locate(s.side, &tcps_mcs[s.robot]);
            mask |= u32::from(located.is_none()) << s.robot;
            *cell = located.flatten();
        }
        for &j in &self.unpaired {
            mask |= u32::from(!self.models[j].delta.is_reachable(&tcps_mcs[j])) << j;
        }
        let mut answer = if mask != 0 { TableAnswer::Unreachable(mask) } else { TableAnswer::Free };
        for ((p, [sa, sb]), free) in
            self.pairs.iter_mut().zip(&self.pair_slots).zip(&mut self.free_cells)
        {
            (p.answer, p.boxes) = (TableAnswer::Unreachable(mask), None);
            if mask >> p.a & 1 == 1 || mask >> p.b & 1 == 1 {
                continue;
            }
            let checker = &mut self.checkers[p.table];
            (p.answer, p.boxes) = match [self.cells[*sa], self.cells[*sb]] {
                // The table's FREE is a function of the two cells alone, so while both robots stay
                // in the cells of the pair's last such label the answer stands without a lookup
                // (a confirmed answer depends on the TCPs and is not kept).
                [Some(a), Some(b)] if *free == Some([a, b]) || checker.labelled_free(a, b) => {
                    *free = Some([a, b]);
                    (TableAnswer::Free, None)
                }
                cells => match checker.check_cells(cells, &[tcps_mcs[p.a], tcps_mcs[p.b]])? {
                    // The pair checker's bits name the pair's robots; fail closed on the cell's.
                    TableAnswer::Unreachable(m) => {
                        (TableAnswer::Unreachable((m & 1) << p.a | (m >> 1 & 1) << p.b), None)
                    }
                    other => (other, checker.colliding_boxes()),
                },
            };
            answer = match (answer, p.answer) {
                (TableAnswer::Unreachable(m), TableAnswer::Unreachable(n)) => {
                    TableAnswer::Unreachable(m | n)
                }
                (TableAnswer::Unreachable(m), _) | (_, TableAnswer::Unreachable(m)) => {
                    TableAnswer::Unreachable(m)
                }
                (TableAnswer::Collision, _) | (_, TableAnswer::Collision) => TableAnswer::Collision,
                _ => TableAnswer::Free,
            };
        }
        Ok(answer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Placement, RobotSpec, SatMethod};
    use crate::cspace::{Progress, Workspace};
    use crate::table::bundle::build_bundle;
    use crate::table::{Labelling, Variant};
    use alloc::{format, vec};

    fn line(n: usize) -> Cell {
        let robots = (0..n)
            .map(|i| RobotSpec {
                name: format!("R{i}"),
                model: RobotModel::THESIS,
                placement: Placement { alpha: 0.0, t: Vec3::new(450.0 * i as f64, 0.0, 0.0) },
            })
            .collect();
        Cell::new("line".into(), robots, SatMethod::SatCache).unwrap()
    }

    /// In a line every robot's pairs share its grid, so each robot's cell is taken once per
    /// tick; and every pair answers as its own table checker does alone (which takes both
    /// cells and the reachability itself), labels compared (no confirmation), on random TCPs
    /// inside, beyond and outside the grids and unreachable ones; the robots walk in steps of
    /// a few mm with rare jumps, so pairs often keep their cells (and their last FREE label)
    /// from one tick to the next and often leave them.
    #[test]
    fn a_lines_pairs_share_each_robots_cell_and_answer_as_their_own_checkers() {
        let (variant, labelling) = (Variant::Shared, Labelling::Certified);
        let built =
            build_bundle(&line(4), 16, &Workspace::THESIS, variant, labelling, Progress::Silent)
                .unwrap();
        let cell = line(8);
        let mut bundle =
            BundleChecker::new(cell.clone(), &built.bytes, Confirmation::None).unwrap();
        // Per robot, one cell per query resolution among its tables (the three tables may
        // differ in sub-levels), against one per pair and side (36) taken pair by pair.
        let mut resolutions =
            bundle.checkers.iter().map(|c| c.table().sub_levels()).collect::<Vec<_>>();
        resolutions.sort_unstable();
        resolutions.dedup();
        let distinct = resolutions.len();
        assert!(
            bundle.slots.len() <= 8 * distinct,
            "{} slots, sub-levels {resolutions:?}",
            bundle.slots.len()
        );
        assert!((0..8).all(|j| bundle.slots.iter().any(|s| s.robot == j)));
        let loaded = bundle_from_bytes(&built.bytes).unwrap();
        let mut alone: Vec<TableChecker> = bundle
            .pairs()
            .iter()
            .map(|p| {
                let (header, table) =
                    loaded.tables[loaded.table_for(&cell, p.a, p.b).unwrap()].clone();
                TableChecker::from_loaded(
                    pair_cell(&cell, p.a, p.b),
                    header,
                    table,
                    Confirmation::None,
                )
                .unwrap()
            })
            .collect();
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut seen = [0usize; 3]; // free, collision, unreachable
        let (mut kept, mut moved) = (0usize, 0usize); // FREE pairs that kept / left their cells
        let mut tcps = vec![Vec3::new(0.0, 0.0, -450.0); 8];
        for _ in 0..40_000 {
            for t in &mut tcps {
                let jump = next() < 0.02;
                let step = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 10.0;
                *t = match jump {
                    true => Vec3::new(
                        600.0 * next() - 300.0,
                        600.0 * next() - 300.0,
                        -300.0 - 300.0 * next(),
                    ),
                    false => *t + step,
                };
            }
            let cells_of = |b: &BundleChecker| -> Vec<_> {
                b.pair_slots
                    .iter()
                    .zip(&b.pairs)
                    .map(|(s, p)| (b.cells[s[0]], b.cells[s[1]], p.answer))
                    .collect()
            };
            let before = cells_of(&bundle);
            bundle.check(&tcps).unwrap();
            for ((ca, cb, was), (na, nb, now)) in before.iter().zip(&cells_of(&bundle)) {
                if (*was, *now) == (TableAnswer::Free, TableAnswer::Free)
                    && ca.is_some()
                    && cb.is_some()
                {
                    let same = (ca, cb) == (na, nb);
                    (kept, moved) = (kept + usize::from(same), moved + usize::from(!same));
                }
            }
            let mask = bundle.unreachable_mask(&tcps);
            for (p, checker) in bundle.pairs().iter().zip(&mut alone) {
                let want = checker.check(&[tcps[p.a], tcps[p.b]]).unwrap();
                if mask >> p.a & 1 == 1 || mask >> p.b & 1 == 1 {
                    assert!(matches!(want, TableAnswer::Unreachable(_)));
                    assert_eq!(p.answer, TableAnswer::Unreachable(mask));
                    seen[2] += 1;
                    continue;
                }
                assert_eq!(
                    p.answer, want,
                    "pair {}-{} at {:?} {:?}",
                    p.a, p.b, tcps[p.a], tcps[p.b]
                );
                seen[usize::from(want == TableAnswer::Collision)] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n > 100), "free, collision, unreachable answers: {seen:?}");
        assert!(
            kept > 10_000 && moved > 1_000,
            "FREE pairs that kept their cells {kept}, that left them {moved}"
        );
        assert!(bundle.fallbacks() > 0, "some TCPs lie outside the grid");
    }
}
