//! The safe state behind the opaque `DcCollider` handle: an exact checker or a precomputed
//! table, plus the per-tick buffers (thesis appendix A; table mode: thesis 3.2 query phase,
//! SPEC §6). No `unsafe` here: `ffi/mod.rs` checks the pointers and calls these functions.
//!
//! Everything a tick needs is allocated when the collider is made; [`Collider::query`], the
//! protective queries and the coordination allocate nothing in either mode.

use crate::cell::exact::PairState;
use crate::cell::protective::{
    BoxPair, Protective, ProtectiveChecker, ProtectiveReport, ProtectiveRequest, ProtectiveStatus,
    StopPath, TickTime, TimingFault, DEFAULT_WARN_MM,
};
use crate::cell::{Cell, ExactChecker, MAX_ROBOTS};
use crate::ffi::convert::{cell_error_status, table_error_status, InitError};
use crate::ffi::coordination::Coordination;
use crate::ffi::stats::TickStats;
use crate::ffi::types::*;
use crate::math::Vec3;
use crate::robot::StopModel;
use crate::table::{is_bundle, BundleChecker, Confirmation, TableAnswer, TableChecker};
use std::path::Path;
use std::time::Instant;

/// How a collider answers.
enum Checker {
    /// Every box pair with the separating axis test (thesis 3.1).
    Exact(Box<ExactChecker>),
    /// One lookup in a table built offline for a two-robot cell (thesis 3.2).
    Table(Box<TableChecker>),
    /// One lookup per pair of robots that can meet, each in its pair's table of a bundle.
    Bundle(Box<BundleChecker>),
}

/// A collider: its checker and the buffers of one tick.
pub(crate) struct Collider {
    checker: Checker,
    /// The TCPs of the current query, converted; sized once.
    tcps: Vec<Vec3>,
    /// Table mode: whether the last query answered COLLISION (for `dc_pair_results`).
    table_collides: bool,
    /// The protective verdict (either mode: it reads the exact boxes).
    protective: ProtectiveChecker,
    /// Per robot, the points of its stop path of the current query, converted; sized once.
    path_points: Vec<[Vec3; DC_MAX_PATH_POINTS]>,
    /// Table mode: protective queries so far answered FREE by the clearance table's bound
    /// alone (kept across `dc_set_stop_model`).
    protective_lookups: u64,
    /// The coordination of the cell (either mode: it reads the exact boxes), with its
    /// buffers; made with the handle, remade by `dc_set_stop_model`.
    coordination: Coordination,
    /// Per kind of call, its time and work so far (`dc_tick_stats`).
    pub(crate) stats: TickStats,
}

/// The protective checker of a handle until `dc_set_stop_model` sets one: without the motor-angle
/// tables, so that `dc_init` builds nothing a caller of `dc_query` alone would not use.
fn protective_for(cell: &Cell) -> ProtectiveChecker {
    ProtectiveChecker::without_motor_tables(cell.clone(), DEFAULT_WARN_MM)
        .expect("the default warn_mm is valid")
}

impl Collider {
    /// An exact-mode collider for `cell`.
    pub(crate) fn exact(cell: Cell) -> Collider {
        let n = cell.robots.len();
        let protective = protective_for(&cell);
        Collider {
            coordination: Coordination::new(protective.cell().clone()),
            stats: TickStats::default(),
            protective,
            checker: Checker::Exact(Box::new(ExactChecker::new(cell))),
            tcps: vec![Vec3::zeros(); n],
            table_collides: false,
            path_points: vec![[Vec3::zeros(); DC_MAX_PATH_POINTS]; n],
            protective_lookups: 0,
        }
    }

    /// A table-mode collider for the two-robot `cell` from a table file's bytes, validated
    /// and copied here (the caller's buffer is not kept), answering a COLLISION lookup as
    /// `confirmation` says.
    pub(crate) fn table(
        cell: Cell,
        bytes: &[u8],
        confirmation: Confirmation,
    ) -> Result<Collider, InitError> {
        if cell.robots.len() < 2 {
            return Err(InitError::new(
                DC_STATUS_TABLE_NOT_TWO_ROBOTS,
                format!(
                    "tables serve cells of two or more robots (a two-robot cell or its pairs), this cell has {} \
                     robot; use dc_init (exact mode) for it",
                    cell.robots.len()
                ),
            ));
        }
        if cell.robots.len() > 2 || is_bundle(bytes) {
            return Collider::bundle(cell, bytes, confirmation);
        }
        let protective = protective_for(&cell);
        let checker = TableChecker::with_confirmation(cell, bytes, confirmation)
            .map_err(|e| InitError::new(table_error_status(&e), e.to_string()))?;
        Ok(Collider {
            checker: Checker::Table(Box::new(checker)),
            tcps: vec![Vec3::zeros(); 2],
            table_collides: false,
            coordination: Coordination::new(protective.cell().clone()),
            stats: TickStats::default(),
            protective,
            path_points: vec![[Vec3::zeros(); DC_MAX_PATH_POINTS]; 2],
            protective_lookups: 0,
        })
    }

    /// A table-mode collider for a cell of two or more robots from a bundle's bytes (or a table
    /// file's, read as a bundle of one table), validated and copied here.
    fn bundle(cell: Cell, bytes: &[u8], confirmation: Confirmation) -> Result<Collider, InitError> {
        let n = cell.robots.len();
        let protective = protective_for(&cell);
        let checker = BundleChecker::new(cell, bytes, confirmation)
            .map_err(|e| InitError::new(table_error_status(&e), e.to_string()))?;
        Ok(Collider {
            checker: Checker::Bundle(Box::new(checker)),
            tcps: vec![Vec3::zeros(); n],
            table_collides: false,
            coordination: Coordination::new(protective.cell().clone()),
            stats: TickStats::default(),
            protective,
            path_points: vec![[Vec3::zeros(); DC_MAX_PATH_POINTS]; n],
            protective_lookups: 0,
        })
    }

    /// A table-mode collider from a TOML cell file and a table file, each read once, here;
    /// the cell file's `table_confirm` chooses the confirmation.
    pub(crate) fn from_files(cell_path: &Path, table_path: &Path) -> Result<Collider, InitError> {
        let file = Cell::read_file(cell_path)
            .map_err(|e| InitError::new(cell_error_status(&e), e.to_string()))?;
        let bytes = std::fs::read(table_path).map_err(|e| {
            InitError::new(
                DC_STATUS_IO,
                format!("cannot read table file {}: {e}", table_path.display()),
            )
        })?;
        Collider::table(file.cell, &bytes, file.table_confirmation)
    }

    /// `DC_MODE_EXACT` or `DC_MODE_TABLE`.
    pub(crate) fn mode(&self) -> DcMode {
        match self.checker {
            Checker::Exact(_) => DC_MODE_EXACT,
            Checker::Table(_) | Checker::Bundle(_) => DC_MODE_TABLE,
        }
    }

    /// Robots of the cell.
    pub(crate) fn robot_count(&self) -> usize {
        self.tcps.len()
    }

    /// Robot pairs reported by [`Collider::pair_results`]: those that can meet (exact mode),
    /// or the one pair a table covers.
    pub(crate) fn pair_count(&self) -> usize {
        match &self.checker {
            Checker::Exact(c) => c.verdict().pairs.len(),
            Checker::Table(_) => 1,
            Checker::Bundle(b) => b.pairs().len(),
        }
    }

    /// Table mode: queries so far answered by the exact check because a TCP lay outside the
    /// table's sampled grid; 0 in exact mode.
    pub(crate) fn table_fallbacks(&self) -> u64 {
        match &self.checker {
            Checker::Exact(_) => 0,
            Checker::Table(t) => t.fallbacks(),
            Checker::Bundle(b) => b.fallbacks(),
        }
    }

    /// Table mode: queries so far whose lookup said COLLISION and were confirmed by the exact
    /// check; 0 in exact mode.
    pub(crate) fn table_confirmations(&self) -> u64 {
        match &self.checker {
            Checker::Exact(_) => 0,
            Checker::Table(t) => t.confirmations(),
            Checker::Bundle(b) => b.confirmations(),
        }
    }

    /// Table mode: protective queries so far answered FREE by the clearance table's bound
    /// alone, without the exact protective proof; 0 in exact mode and with a boolean table.
    pub(crate) fn table_protective_lookups(&self) -> u64 {
        self.protective_lookups
    }

    /// Table mode: chooses what a COLLISION lookup does from the next query on; exact mode
    /// answers exactly whatever is chosen.
    pub(crate) fn set_table_confirmation(&mut self, confirmation: Confirmation) {
        match &mut self.checker {
            Checker::Table(t) => t.set_confirmation(confirmation),
            Checker::Bundle(b) => b.set_confirmation(confirmation),
            Checker::Exact(_) => {}
        }
    }

    /// The per-tick query: fills `report` (which starts as [`DcQueryReport::STOP`]) and
    /// returns the status; the verdict in `report` is decided only with `DC_STATUS_OK`.
    pub(crate) fn query(&mut self, tcps: &[DcVec3], report: &mut DcQueryReport) -> DcStatus {
        let started = Instant::now();
        let status = self.query_untimed(tcps, report);
        self.stats.query.record(started.elapsed(), 0, false);
        status
    }

    fn query_untimed(&mut self, tcps: &[DcVec3], report: &mut DcQueryReport) -> DcStatus {
        self.table_collides = false;
        if tcps.len() != self.tcps.len() {
            return DC_STATUS_WRONG_ROBOT_COUNT;
        }
        let mut non_finite = 0u32;
        for (j, (dst, src)) in self.tcps.iter_mut().zip(tcps).enumerate() {
            non_finite |= (!src.is_finite() as u32) << j;
            *dst = src.to_vec3();
        }
        if non_finite != 0 {
            report.unreachable_mask = non_finite;
            return DC_STATUS_NON_FINITE;
        }
        match &mut self.checker {
            Checker::Exact(c) => query_exact(c, &self.tcps, report),
            Checker::Table(t) => {
                let status = query_table(t, &self.tcps, report);
                self.table_collides =
                    status == DC_STATUS_OK && report.verdict == DC_VERDICT_COLLISION;
                status
            }
            Checker::Bundle(b) => query_bundle(b, &self.tcps, report),
        }
    }

    /// Table mode with a clearance table: the certified lower bound on the clearance (mm) of
    /// the grid cell of `tcps` ([`TableChecker::clearance_bound`]), `-inf` when nothing is
    /// proved (no level, a TCP outside the grid, exact mode or a boolean table). The status
    /// as [`query`](Self::query) gives it for the same TCPs; the bound is `-inf` unless OK.
    /// Never allocates.
    pub(crate) fn clearance_bound(&mut self, tcps: &[DcVec3]) -> (DcStatus, f64) {
        let none = f64::NEG_INFINITY;
        if tcps.len() != self.tcps.len() {
            return (DC_STATUS_WRONG_ROBOT_COUNT, none);
        }
        if tcps.iter().any(|t| !t.is_finite()) {
            return (DC_STATUS_NON_FINITE, none);
        }
        for (dst, src) in self.tcps.iter_mut().zip(tcps) {
            *dst = src.to_vec3();
        }
        match &self.checker {
            Checker::Exact(c)
                if c.cell()
                    .robots
                    .iter()
                    .zip(&self.tcps)
                    .any(|(r, t)| !r.model.delta.is_reachable(t)) =>
            {
                (DC_STATUS_UNREACHABLE, none)
            }
            Checker::Exact(_) => (DC_STATUS_OK, none),
            Checker::Table(t) => match t.located_clearance_bound(&self.tcps) {
                Ok(bound) => (DC_STATUS_OK, bound.unwrap_or(none)),
                Err(_) => (DC_STATUS_UNREACHABLE, none),
            },
            Checker::Bundle(b) if b.unreachable_mask(&self.tcps) != 0 => {
                (DC_STATUS_UNREACHABLE, none)
            }
            Checker::Bundle(_) => (DC_STATUS_OK, none),
        }
    }

    /// The coordination of the cell and its buffers.
    pub(crate) fn coordination(&mut self) -> &mut Coordination {
        &mut self.coordination
    }

    /// Replaces the tick, WARN threshold and stopping models of the protective verdict (and
    /// forgets the previous TCPs), and remakes the coordination on them (its settings kept,
    /// its decisions forgotten).
    pub(crate) fn set_stopping(
        &mut self,
        tick_ms: f64,
        warn_mm: f64,
        stops: &[DcStopConfig],
    ) -> Result<(), InitError> {
        let invalid = |m: String| InitError::new(DC_STATUS_INVALID_CONFIG, m);
        if let Some((i, c)) =
            stops.iter().enumerate().find(|(_, c)| c.struct_size != size_of::<DcStopConfig>())
        {
            return Err(InitError::new(
                DC_STATUS_INVALID_ARGUMENT,
                format!(
                    "stops[{i}].struct_size = {}, this library's DcStopConfig has {} bytes: start from \
                     dc_stop_config_default() and compile against this header",
                    c.struct_size,
                    size_of::<DcStopConfig>()
                ),
            ));
        }
        let models = stops
            .iter()
            .map(|c| StopModel {
                reaction_ms: c.reaction_ms,
                decel_mm_s2: c.decel_mm_s2,
                max_accel_mm_s2: c.max_accel_mm_s2,
                max_speed_mm_s: c.max_speed_mm_s,
            })
            .collect();
        let cell = self
            .protective
            .cell()
            .clone()
            .with_stopping(tick_ms, models)
            .map_err(|e| invalid(e.to_string()))?;
        let (limits, tests) = (self.protective.speed_limits(), self.protective.limit_tests());
        let path_work = self.protective.path_work();
        self.protective = ProtectiveChecker::new(cell, warn_mm)
            .map_err(|e| invalid(e.to_string()))?
            .with_speed_limits(limits)
            .with_limit_tests(tests)
            .with_path_work(path_work);
        self.coordination.set_cell(self.protective.cell().clone());
        Ok(())
    }

    /// Caps the speeds the speed-limit searches test per tick, all robots together.
    pub(crate) fn set_limit_tests(&mut self, tests: u32) {
        self.protective.set_limit_tests(tests);
    }

    /// Caps the units of work the proof along the stop paths spends per tick.
    pub(crate) fn set_path_work(&mut self, units: u32) {
        self.protective.set_path_work(units);
    }

    /// Whether the protective queries to come find each robot's speed limit.
    pub(crate) fn set_speed_limits(&mut self, on: bool) {
        self.protective.set_speed_limits(on);
    }

    /// Forgets the previous TCPs of the protective verdict.
    pub(crate) fn reset_protective(&mut self) {
        self.protective.reset();
    }

    /// The protective query at `time` with the robots' stop paths (`None`: no paths;
    /// `paths[j].0` empty: none for robot j; the caller checked that every path's points are
    /// readable and at most `DC_MAX_PATH_POINTS`): fills `report` (which starts as
    /// [`DcProtectiveReport::STOP`]) and returns the status; the verdict is FREE or WARN only
    /// with `DC_STATUS_OK`.
    pub(crate) fn protective_query(
        &mut self,
        time: TickTime,
        tcps: &[DcVec3],
        paths: Option<&[(&[DcVec3], f64)]>,
        report: &mut DcProtectiveReport,
    ) -> DcStatus {
        let started = Instant::now();
        let status = self.protective_query_untimed(time, tcps, paths, report);
        let r = self.protective.report();
        let ok = status == DC_STATUS_OK;
        let work = if ok { u64::from(r.limit_tests) + u64::from(r.path_work) } else { 0 };
        let spent = ok && (r.limit_budget_spent || r.path_work_spent);
        self.stats.protective.record(started.elapsed(), work, spent);
        status
    }

    fn protective_query_untimed(
        &mut self,
        time: TickTime,
        tcps: &[DcVec3],
        paths: Option<&[(&[DcVec3], f64)]>,
        report: &mut DcProtectiveReport,
    ) -> DcStatus {
        if tcps.len() != self.tcps.len() || paths.is_some_and(|p| p.len() != self.tcps.len()) {
            return DC_STATUS_WRONG_ROBOT_COUNT;
        }
        for (dst, src) in self.tcps.iter_mut().zip(tcps) {
            *dst = src.to_vec3();
        }
        let paths = paths.unwrap_or(&[]);
        for (dst, (src, _)) in self.path_points.iter_mut().zip(paths) {
            for (d, s) in dst.iter_mut().zip(src.iter()) {
                *d = s.to_vec3();
            }
        }
        let mut stop_paths: [Option<StopPath>; MAX_ROBOTS] = [None; MAX_ROBOTS];
        let n_paths = paths.len();
        for (j, (points, tolerance_mm)) in paths.iter().enumerate() {
            if !points.is_empty() {
                stop_paths[j] = Some(StopPath {
                    points: &self.path_points[j][..points.len()],
                    tolerance_mm: *tolerance_mm,
                });
            }
        }
        let request =
            ProtectiveRequest::new(&self.tcps).at(time).with_paths(&stop_paths[..n_paths]);
        let r = match &self.checker {
            Checker::Table(t) if t.table().as_clearance().is_some() => {
                self.protective.check(request.with_table(&|_, _, tcps| t.clearance_bound(tcps)))
            }
            Checker::Bundle(b) if b.has_clearance() => self
                .protective
                .check(request.with_table(&|i, j, tcps| b.clearance_bound(i, j, tcps))),
            _ => self.protective.check(request),
        };
        let Ok(r) = r else { return DC_STATUS_WRONG_ROBOT_COUNT };
        self.protective_lookups += u64::from(r.table_lookup);
        write_protective(r, report)
    }

    /// Writes the per-pair results of the last query into `out[..pair_count()]`, which the
    /// caller sized.
    pub(crate) fn pair_results(&self, out: &mut [DcPairResult]) {
        match &self.checker {
            Checker::Exact(c) => {
                for (o, p) in out.iter_mut().zip(&c.verdict().pairs) {
                    let (collides, box_a, box_b) = match p.state {
                        PairState::Collides(a, b) => (1, a as u32, b as u32),
                        _ => (0, DC_BOX_NONE, DC_BOX_NONE),
                    };
                    *o = DcPairResult {
                        robot_a: p.a as u32,
                        robot_b: p.b as u32,
                        collides,
                        box_a,
                        box_b,
                    };
                }
            }
            Checker::Table(t) => {
                let collides = u32::from(self.table_collides);
                let boxes = t.colliding_boxes().filter(|_| self.table_collides);
                let [box_a, box_b] = boxes.map_or([DC_BOX_NONE; 2], |(a, b)| [a as u32, b as u32]);
                out[0] = DcPairResult { robot_a: 0, robot_b: 1, collides, box_a, box_b };
            }
            Checker::Bundle(b) => {
                for (o, p) in out.iter_mut().zip(b.pairs()) {
                    let collides = p.answer == TableAnswer::Collision;
                    let boxes = p.boxes.filter(|_| collides);
                    let [box_a, box_b] =
                        boxes.map_or([DC_BOX_NONE; 2], |(a, b)| [a as u32, b as u32]);
                    let (robot_a, robot_b) = (p.a as u32, p.b as u32);
                    *o = DcPairResult {
                        robot_a,
                        robot_b,
                        collides: u32::from(collides),
                        box_a,
                        box_b,
                    };
                }
            }
        }
    }
}

/// Writes the protective report `r` into the C report; returns its status.
fn write_protective(r: &ProtectiveReport, report: &mut DcProtectiveReport) -> DcStatus {
    report.n_robots = r.robots.len() as u32;
    report.clearance_mm = r.clearance_mm;
    for (j, robot) in r.robots.iter().enumerate() {
        (report.protective_mm[j], report.speed_limit_mm_s[j]) =
            (robot.protective_mm, robot.speed_limit_mm_s);
    }
    let ids = |p: Option<BoxPair>| {
        p.map_or([DC_BOX_NONE; 4], |p| [p.a as u32, p.b as u32, p.box_a as u32, p.box_b as u32])
    };
    [report.closest_robot_a, report.closest_robot_b, report.closest_box_a, report.closest_box_b] =
        ids(r.closest);
    [
        report.limiting_robot_a,
        report.limiting_robot_b,
        report.limiting_box_a,
        report.limiting_box_b,
    ] = ids(r.limiting);
    let (status, robot) = match r.status {
        ProtectiveStatus::Ok => (DC_STATUS_OK, None),
        ProtectiveStatus::NonFinite(j) => (DC_STATUS_NON_FINITE, Some(j)),
        ProtectiveStatus::Unreachable(j) => (DC_STATUS_UNREACHABLE, Some(j)),
        ProtectiveStatus::ImplausibleMotion(j) => (DC_STATUS_IMPLAUSIBLE_MOTION, Some(j)),
        ProtectiveStatus::InvalidPath(j) => (DC_STATUS_INVALID_ARGUMENT, Some(j)),
        ProtectiveStatus::Timing(fault) => (timing_status(fault), None),
    };
    report.unreachable_mask = robot.map_or(0, |j| 1 << j);
    report.verdict = match r.verdict {
        Protective::Free => DC_VERDICT_FREE,
        Protective::Warn => DC_VERDICT_WARN,
        Protective::Stop => DC_VERDICT_STOP,
    };
    status
}

/// The C status of a timing fault.
fn timing_status(fault: TimingFault) -> DcStatus {
    match fault {
        TimingFault::Repeated => DC_STATUS_TIME_REPEATED,
        TimingFault::Backwards => DC_STATUS_TIME_BACKWARDS,
        TimingFault::Jump => DC_STATUS_TIME_JUMP,
        TimingFault::Early => DC_STATUS_TIME_EARLY,
        TimingFault::ClockChanged => DC_STATUS_CLOCK_CHANGED,
    }
}

// The header states these bounds as numbers (cbindgen writes no paths): keep them equal.
const _: () = assert!(DC_MAX_INTERVAL_TICKS == crate::cell::protective::MAX_INTERVAL_TICKS);
const _: () = assert!(DC_MAX_PATH_POINTS == crate::cell::protective::MAX_PATH_POINTS);
const _: () = assert!(DC_DEFAULT_PATH_WORK == crate::cell::protective::DEFAULT_PATH_WORK);

fn query_exact(checker: &mut ExactChecker, tcps: &[Vec3], report: &mut DcQueryReport) -> DcStatus {
    let Ok(v) = checker.check(tcps) else { return DC_STATUS_WRONG_ROBOT_COUNT };
    report.unreachable_mask = v.unreachable_mask;
    report.colliding_pairs = v.colliding_pairs() as u32;
    if let Some(p) = v.first_collision() {
        if let PairState::Collides(ba, bb) = p.state {
            (report.first_robot_a, report.first_robot_b) = (p.a as u32, p.b as u32);
            (report.first_box_a, report.first_box_b) = (ba as u32, bb as u32);
        }
    }
    if !v.all_reachable() {
        return DC_STATUS_UNREACHABLE;
    }
    report.verdict = if v.collides() { DC_VERDICT_COLLISION } else { DC_VERDICT_FREE };
    DC_STATUS_OK
}

fn query_table(checker: &mut TableChecker, tcps: &[Vec3], report: &mut DcQueryReport) -> DcStatus {
    match checker.check(tcps) {
        Err(_) => DC_STATUS_WRONG_ROBOT_COUNT,
        Ok(TableAnswer::Unreachable(mask)) => {
            report.unreachable_mask = mask;
            DC_STATUS_UNREACHABLE
        }
        Ok(TableAnswer::Free) => {
            report.verdict = DC_VERDICT_FREE;
            DC_STATUS_OK
        }
        Ok(TableAnswer::Collision) => {
            (report.verdict, report.colliding_pairs) = (DC_VERDICT_COLLISION, 1);
            (report.first_robot_a, report.first_robot_b) = (0, 1);
            if let Some((a, b)) = checker.colliding_boxes() {
                (report.first_box_a, report.first_box_b) = (a as u32, b as u32);
            }
            DC_STATUS_OK
        }
    }
}

/// A bundle's answer in the report: as exact mode's, with the first colliding pair's robots,
/// and its boxes when the exact check answered it.
fn query_bundle(
    checker: &mut BundleChecker,
    tcps: &[Vec3],
    report: &mut DcQueryReport,
) -> DcStatus {
    let Ok(answer) = checker.check(tcps) else { return DC_STATUS_WRONG_ROBOT_COUNT };
    let colliding = checker.pairs().iter().filter(|p| p.answer == TableAnswer::Collision);
    report.colliding_pairs = colliding.clone().count() as u32;
    if let Some(p) = colliding.clone().next() {
        (report.first_robot_a, report.first_robot_b) = (p.a as u32, p.b as u32);
        if let Some((a, b)) = p.boxes {
            (report.first_box_a, report.first_box_b) = (a as u32, b as u32);
        }
    }
    match answer {
        TableAnswer::Unreachable(mask) => {
            report.unreachable_mask = mask;
            DC_STATUS_UNREACHABLE
        }
        TableAnswer::Collision => {
            report.verdict = DC_VERDICT_COLLISION;
            DC_STATUS_OK
        }
        TableAnswer::Free => {
            report.verdict = DC_VERDICT_FREE;
            DC_STATUS_OK
        }
    }
}
