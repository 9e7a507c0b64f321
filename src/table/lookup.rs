//! Table-backed queries for a two-robot cell: one lookup per tick (thesis 3.2.4-3.2.6 query
//! phase; SPEC §6).
//!
//! Per tick: each TCP is mapped to its grid cell and checked for reachability (the inverse
//! kinematics, no box model; skipped in a cell proved wholly reachable when the table was
//! loaded), and the 6-D cell is looked up. A reachable TCP outside the sampled grid
//! has no table entry: that tick falls back to the exact check (counted in
//! [`TableChecker::fallbacks`]), so the answer is never a guess. A cell labelled COLLISION may
//! hold free configurations (only FREE labels are proofs); with [`Confirmation::Exact`] such a
//! tick is answered by the exact check (counted in [`TableChecker::confirmations`]), so table
//! mode then answers as exact mode while a free cell costs one lookup. Nothing allocates per
//! tick.

use crate::cell::exact::PairState;
pub use crate::cell::Confirmation;
use crate::cell::{Cell, ExactChecker, QueryError};
use crate::cspace::symmetry::reflection_y;
use crate::cspace::SampleGrid;
use crate::cspace::Workspace;
use crate::math::Vec3;
#[cfg(feature = "std")]
use crate::robot::motion_bound::cube_reachable;
use crate::robot::{Delta3, RobotModel};
use crate::table::format::from_bytes;
use crate::table::{Header, Table, TableError};
use alloc::{format, string::String, vec, vec::Vec};

/// The answer of one table-backed query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableAnswer {
    /// The table proves the configuration free (or the exact check, a fallback or a
    /// confirmation, found it free).
    Free,
    /// The table stores the cell as collision (confirmed by the exact check with
    /// [`Confirmation::Exact`]), or the exact fallback found a collision.
    Collision,
    /// Bit j set: robot j's TCP is unreachable or not finite.
    Unreachable(u32),
}

/// Refuses a table whose header disagrees with what the cell determines: the workspace its
/// grids sample and whether only the mirror-symmetric half is stored. Both change answers, and
/// a header edited with its checksum recomputed passes every other check.
fn check_determined_by_cell(header: &Header, table: &Table, cell: &Cell) -> Result<(), TableError> {
    let fingerprint = cell.fingerprint();
    let wrong = |differs: String| TableError::WrongCell {
        expected: fingerprint,
        found: fingerprint,
        differs: Some(differs),
    };
    let (w, ours) = (&header.workspace, Workspace::for_cell(cell));
    let fields = [
        ("zu", w.zu, ours.zu),
        ("hcy", w.hcy, ours.hcy),
        ("rcy", w.rcy, ours.rcy),
        ("hco", w.hco, ours.hco),
    ];
    for (name, theirs, ours) in fields.into_iter().chain([("rco", w.rco, ours.rco)]) {
        if theirs.to_bits() != ours.to_bits() {
            return Err(wrong(format!(
                "workspace.{name} is {theirs} mm in the table and {ours} mm for this cell"
            )));
        }
    }
    let symmetric = reflection_y(cell);
    if table.symmetric() != symmetric {
        let says = |s: bool| if s { "mirror-symmetric" } else { "not mirror-symmetric" };
        return Err(wrong(format!(
            "the table is stored as {} and the cell is {}",
            says(table.symmetric()),
            says(symmetric)
        )));
    }
    Ok(())
}

/// A set of one robot's grid cells: a dense bitmap over the `k^3` cells.
#[derive(Clone, Debug, PartialEq)]
struct CellSet {
    k: usize,
    bits: Vec<u64>,
}

impl CellSet {
    fn new<'a>(k: u32, cells: impl Iterator<Item = &'a [u16; 3]>) -> Self {
        let k = k as usize;
        let mut bits = vec![0u64; (k * k * k).div_ceil(64)];
        for c in cells {
            let i = (c[0] as usize * k + c[1] as usize) * k + c[2] as usize;
            bits[i / 64] |= 1 << (i % 64);
        }
        CellSet { k, bits }
    }

    /// The grid's sampled cells.
    fn sampled(grid: &SampleGrid) -> Self {
        CellSet::new(grid.k, grid.cells.iter())
    }

    /// The sampled cells of which every TCP is proved reachable by `delta`
    /// (`robot::motion_bound::cube_reachable`), so that a TCP found in one needs no inverse
    /// kinematics.
    #[cfg(feature = "std")]
    fn reachable(grid: &SampleGrid, delta: &Delta3) -> Self {
        let h = 0.5 * grid.r;
        CellSet::new(
            grid.k,
            grid.cells.iter().filter(|c| cube_reachable(delta, &grid.center(**c), h)),
        )
    }

    /// Without `std` there is no interval arithmetic to prove a cell: none is, and every TCP
    /// takes the inverse kinematics.
    #[cfg(not(feature = "std"))]
    fn reachable(grid: &SampleGrid, _delta: &Delta3) -> Self {
        CellSet::new(grid.k, core::iter::empty())
    }

    fn contains(&self, c: [u16; 3]) -> bool {
        let i = (c[0] as usize * self.k + c[1] as usize) * self.k + c[2] as usize;
        self.bits.get(i / 64).is_some_and(|w| w >> (i % 64) & 1 == 1)
    }
}

/// A loaded, validated table with what each tick needs.
#[derive(Clone, Debug)]
pub struct TableChecker {
    header: Header,
    table: Table,
    models: [RobotModel; 2],
    origins: [Vec3; 2],
    sampled: [CellSet; 2],
    /// Per robot, the sampled cells proved wholly reachable.
    reachable: [CellSet; 2],
    /// The query resolution, fixed by the table: `2^sub_levels` cells per grid cell and axis,
    /// cells per axis at it, and their side (mm).
    sub_levels: u32,
    query_k: f64,
    query_r: f64,
    exact: ExactChecker,
    fallbacks: u64,
    confirmation: Confirmation,
    confirmations: u64,
    /// The colliding box pair of the last check, when the exact check answered it.
    exact_boxes: Option<(usize, usize)>,
}

impl TableChecker {
    /// Loads `bytes` (a table file's content) for `cell`, validating it once; the checker
    /// answers the table's labels ([`Confirmation::None`]), as the table's evaluation needs:
    /// [`TableChecker::with_confirmation`] chooses.
    ///
    /// # Errors
    /// As [`TableChecker::with_confirmation`].
    pub fn new(cell: Cell, bytes: &[u8]) -> Result<TableChecker, TableError> {
        TableChecker::with_confirmation(cell, bytes, Confirmation::None)
    }

    /// Loads `bytes` (a table file's content) for `cell`, validating it once, answering a
    /// COLLISION lookup as `confirmation` says.
    ///
    /// # Errors
    /// Every [`TableError`] of loading; [`TableError::WrongCell`] when the table was built for
    /// another cell; [`TableError::BadInput`] when the cell does not have two robots or the
    /// header's grid differs from the one its parameters define.
    pub fn with_confirmation(
        cell: Cell,
        bytes: &[u8],
        confirmation: Confirmation,
    ) -> Result<TableChecker, TableError> {
        if cell.robots.len() != 2 {
            return Err(TableError::BadInput {
                what: format!("tables serve two-robot cells; this one has {}", cell.robots.len()),
            });
        }
        let (header, table) = from_bytes(bytes)?;
        TableChecker::from_loaded(cell, header, table, confirmation)
    }

    /// As [`TableChecker::with_confirmation`], from a table already read and validated as
    /// bytes (a bundle's).
    pub(crate) fn from_loaded(
        cell: Cell,
        header: Header,
        table: Table,
        confirmation: Confirmation,
    ) -> Result<TableChecker, TableError> {
        header.check_cell_parameters(&cell)?;
        check_determined_by_cell(&header, &table, &cell)?;
        let k = 1u32 << table.levels();
        let grid = |j: usize| {
            SampleGrid::new(&header.workspace, k, &cell.robots[j].model.delta)
                .map_err(|e| TableError::Corrupt { what: format!("header grid parameters: {e}") })
        };
        let (grid_a, grid_b) = (grid(0)?, grid(1)?);
        let same = |g: &SampleGrid, o: &[f64; 3]| g.r == header.r && g.origin == Vec3::from(*o);
        if !same(&grid_a, &header.origin_a) || !same(&grid_b, &header.origin_b) {
            return Err(TableError::Corrupt {
                what: "header r / grid origins disagree with its workspace and k".into(),
            });
        }
        let sub_levels = table.sub_levels();
        Ok(TableChecker {
            models: [cell.robots[0].model, cell.robots[1].model],
            origins: [grid_a.origin, grid_b.origin],
            sampled: [CellSet::sampled(&grid_a), CellSet::sampled(&grid_b)],
            reachable: [
                CellSet::reachable(&grid_a, &cell.robots[0].model.delta),
                CellSet::reachable(&grid_b, &cell.robots[1].model.delta),
            ],
            sub_levels,
            query_k: f64::from(k << sub_levels),
            query_r: header.r / f64::from(1u32 << sub_levels),
            exact: ExactChecker::new(cell),
            header,
            table,
            fallbacks: 0,
            confirmation,
            confirmations: 0,
            exact_boxes: None,
        })
    }

    /// The table's header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// How many queries so far fell back to the exact check (TCP outside the sampled grid).
    pub fn fallbacks(&self) -> u64 {
        self.fallbacks
    }

    /// How a COLLISION lookup is answered.
    pub fn confirmation(&self) -> Confirmation {
        self.confirmation
    }

    /// Chooses how a COLLISION lookup is answered from the next query on.
    pub fn set_confirmation(&mut self, confirmation: Confirmation) {
        self.confirmation = confirmation;
    }

    /// How many queries so far the table said COLLISION and the exact check was asked
    /// ([`Confirmation::Exact`]); fallbacks are not counted here.
    pub fn confirmations(&self) -> u64 {
        self.confirmations
    }

    /// The colliding boxes (robot 0's, robot 1's; [`RobotModel::boxes`] order) of the last
    /// check when it answered COLLISION through the exact check (a confirmation or a
    /// fallback); `None` otherwise: a lookup knows the cell, not the boxes.
    pub fn colliding_boxes(&self) -> Option<(usize, usize)> {
        self.exact_boxes
    }

    /// The cell of robot `j`'s TCP at the table's query resolution (`2^sub_levels` per grid
    /// cell and axis), or `None` when its grid cell is not sampled.
    pub(crate) fn cell_of(&self, j: usize, tcp: &Vec3) -> Option<[u16; 3]> {
        let mut c = [0u16; 3];
        for (a, ci) in c.iter_mut().enumerate() {
            // The cell is floor(u); with query_k a whole number, floor(u) lies in [0, query_k)
            // exactly when u does (NaN in neither), and for u >= 0 the cast truncates to floor(u):
            // no call to floor, which is a library call on x86-64 without SSE4.1.
            let u = (tcp[a] - self.origins[j][a]) / self.query_r;
            if !(u >= 0.0 && u < self.query_k) {
                return None;
            }
            *ci = u as u16;
        }
        self.sampled[j].contains(c.map(|v| v >> self.sub_levels)).then_some(c)
    }

    /// Robot `j`'s TCP (its own MCS) located: `None` when it is unreachable or not finite
    /// ([`Delta3::is_reachable`]), else [`TableChecker::cell_of`]. A TCP in a grid cell proved
    /// wholly reachable (`robot::motion_bound::cube_reachable`, whose margins make
    /// `is_reachable` accept every TCP of the cell) skips the inverse kinematics.
    pub(crate) fn locate(&self, j: usize, tcp: &Vec3) -> Option<Option<[u16; 3]>> {
        let cell = self.cell_of(j, tcp);
        let proved =
            cell.is_some_and(|c| self.reachable[j].contains(c.map(|v| v >> self.sub_levels)));
        (proved || self.models[j].delta.is_reachable(tcp)).then_some(cell)
    }

    /// Whether robot `j`'s grid here and robot `i`'s grid in `other` give every TCP the same
    /// cell (origin, query resolution and sampled cells all equal), so that
    /// [`TableChecker::cell_of`] of one serves the other (a bundle's pairs share their robots'
    /// cells).
    pub(crate) fn same_grid(&self, j: usize, other: &TableChecker, i: usize) -> bool {
        self.origins[j] == other.origins[i]
            && self.query_r.to_bits() == other.query_r.to_bits()
            && self.query_k.to_bits() == other.query_k.to_bits()
            && self.sub_levels == other.sub_levels
            && self.sampled[j] == other.sampled[i]
    }

    /// Answers one tick; `tcps_mcs[j]` is robot j's TCP in its own MCS.
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] unless exactly two TCPs are given.
    pub fn check(&mut self, tcps_mcs: &[Vec3]) -> Result<TableAnswer, QueryError> {
        if tcps_mcs.len() != 2 {
            return Err(QueryError::WrongRobotCount { expected: 2, found: tcps_mcs.len() });
        }
        self.exact_boxes = None;
        let located = [self.locate(0, &tcps_mcs[0]), self.locate(1, &tcps_mcs[1])];
        match located {
            [Some(a), Some(b)] => self.check_cells([a, b], tcps_mcs),
            _ => Ok(TableAnswer::Unreachable(
                u32::from(located[0].is_none()) | u32::from(located[1].is_none()) << 1,
            )),
        }
    }

    /// [`TableChecker::check`] for two reachable TCPs with their cells already taken
    /// (`cells[j]` must be [`TableChecker::cell_of`]`(j, &tcps_mcs[j])`, or that of a grid
    /// [`TableChecker::same_grid`] finds equal).
    pub(crate) fn check_cells(
        &mut self,
        cells: [Option<[u16; 3]>; 2],
        tcps_mcs: &[Vec3],
    ) -> Result<TableAnswer, QueryError> {
        self.exact_boxes = None;
        match cells {
            [Some(a), Some(b)] if self.labelled_free(a, b) => Ok(TableAnswer::Free),
            [Some(_), Some(_)] => match self.confirmation {
                Confirmation::None => Ok(TableAnswer::Collision),
                Confirmation::Exact => {
                    self.confirmations += 1;
                    self.exact_answer(tcps_mcs)
                }
            },
            _ => {
                self.fallbacks += 1;
                self.exact_answer(tcps_mcs)
            }
        }
    }

    /// Whether the table labels the 6-D cell of robot cells `a` and `b` FREE: a proof for every
    /// configuration of that cell, whatever TCPs in it a tick brings.
    pub(crate) fn labelled_free(&self, a: [u16; 3], b: [u16; 3]) -> bool {
        !self.table.query([a[0], a[1], a[2], b[0], b[1], b[2]])
    }

    /// Bit j set: robot j's TCP (of the first two of `tcps_mcs`, each in its own MCS) is
    /// unreachable or not finite.
    pub fn unreachable_mask(&self, tcps_mcs: &[Vec3]) -> u32 {
        let reachable = |j: usize| tcps_mcs.get(j).is_some_and(|t| self.locate(j, t).is_some());
        (0..2).fold(0u32, |m, j| m | u32::from(!reachable(j)) << j)
    }

    /// The certified lower bound on the clearance (SPEC §8, mm) that a clearance table
    /// ([`Table::Clearance`]) stores for the grid cell of `tcps_mcs` (robot j's TCP in its own
    /// MCS): every configuration of that cell has at least this clearance. `None` when
    /// nothing is proved: no level for the cell (it may collide), a TCP unreachable or outside
    /// the table's grid, not two TCPs, or not a clearance table. One lookup, no allocation.
    pub fn clearance_bound(&self, tcps_mcs: &[Vec3]) -> Option<f64> {
        self.table.as_clearance()?;
        self.located_clearance_bound(tcps_mcs).ok().flatten()
    }

    /// As [`clearance_bound`](Self::clearance_bound), each TCP located once, with an
    /// unreachable one told apart: `Err` of [`unreachable_mask`](Self::unreachable_mask)'s
    /// bits when that is not 0.
    pub fn located_clearance_bound(&self, tcps_mcs: &[Vec3]) -> Result<Option<f64>, u32> {
        let cells = [0, 1].map(|j| tcps_mcs.get(j).and_then(|t| self.locate(j, t)));
        match cells {
            [Some(a), Some(b)] => {
                let (Some(a), Some(b), Some(table)) = (a, b, self.table.as_clearance()) else {
                    return Ok(None);
                };
                Ok(table.bound_mm([a[0], a[1], a[2], b[0], b[1], b[2]]))
            }
            _ => Err(cells
                .iter()
                .enumerate()
                .fold(0u32, |m, (j, c)| m | u32::from(c.is_none()) << j)),
        }
    }

    /// The exact check's verdict in the table's terms.
    fn exact_answer(&mut self, tcps_mcs: &[Vec3]) -> Result<TableAnswer, QueryError> {
        let v = self.exact.check(tcps_mcs)?;
        self.exact_boxes = v.first_collision().and_then(|p| match p.state {
            PairState::Collides(a, b) => Some((a, b)),
            _ => None,
        });
        Ok(match (v.unreachable_mask, v.collides()) {
            (0, true) => TableAnswer::Collision,
            (0, false) => TableAnswer::Free,
            (m, _) => TableAnswer::Unreachable(m),
        })
    }
}
