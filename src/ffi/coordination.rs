//! The coordination (SPEC section 9): each robot's speed override from the robots'
//! programmes ahead (`crate::coord`), its reset and its clearance; the state behind it in
//! every handle ([`Coordination`]), with the buffers the programmes' points are converted into.

use super::collider::Collider;
use super::handle::{boundary, flatten, live, DcCollider};
use super::settings::set_on_handle;
use super::types::*;
use crate::cell::{Cell, MAX_ROBOTS};
use crate::coord::{
    CoordinationConfig, CoordinationError, CoordinationReport, CoordinationRequest, Coordinator,
    Programme, RightOfWay, RobotCoordination, MAX_SAMPLES,
};
use crate::math::Vec3;
use std::mem::{offset_of, size_of};
use std::time::Instant;

// The header states this bound as a number (cbindgen writes no paths): keep them equal.
const _: () = assert!(DC_MAX_ROBOTS == MAX_ROBOTS);

/// The coordination behind a handle: the coordinator of its cell (with the stopping models of
/// its protective verdict) and, per robot, its programme's horizon converted to vectors.
/// Everything is allocated when it is made; [`Coordination::coordinate`] allocates nothing.
pub(crate) struct Coordination {
    coordinator: Coordinator,
    /// Per robot, the points of its horizon (from the one at or behind its progress on).
    points: Vec<[Vec3; MAX_SAMPLES]>,
}

impl Coordination {
    /// The coordination of `cell` with the default settings.
    pub(crate) fn new(cell: Cell) -> Coordination {
        Coordination::with_config(cell, CoordinationConfig::default())
    }

    fn with_config(cell: Cell, config: CoordinationConfig) -> Coordination {
        let n = cell.robots.len();
        Coordination {
            coordinator: Coordinator::new(cell, config),
            points: vec![[Vec3::zeros(); MAX_SAMPLES]; n],
        }
    }

    /// Remakes the coordination for `cell` (new stopping models), its settings kept.
    pub(crate) fn set_cell(&mut self, cell: Cell) {
        *self = Coordination::with_config(cell, *self.coordinator.config());
    }

    /// Remakes the coordinator with `clearance_mm` (finite, > 0), or says why not.
    fn set_clearance(&mut self, clearance_mm: f64) -> Result<(), String> {
        if !(clearance_mm > 0.0 && clearance_mm.is_finite()) {
            return Err(format!(
                "clearance_mm = {clearance_mm}: give a finite clearance greater than 0 (mm)"
            ));
        }
        let config = CoordinationConfig { clearance_mm, ..*self.coordinator.config() };
        self.coordinator = Coordinator::new(self.coordinator.cell().clone(), config);
        Ok(())
    }

    /// Remakes the coordinator with the right of way `rule`, or says why not.
    fn set_right_of_way(&mut self, rule: DcRightOfWay) -> Result<(), String> {
        let right_of_way = match rule {
            DC_RIGHT_OF_WAY_ARRIVAL => RightOfWay::Arrival,
            DC_RIGHT_OF_WAY_PROGRAMMED => RightOfWay::Programmed,
            _ => {
                return Err(format!(
                    "right of way {rule}: give DC_RIGHT_OF_WAY_ARRIVAL (0) or \
                     DC_RIGHT_OF_WAY_PROGRAMMED (1)"
                ))
            }
        };
        let config = CoordinationConfig { right_of_way, ..*self.coordinator.config() };
        self.coordinator = Coordinator::new(self.coordinator.cell().clone(), config);
        Ok(())
    }

    /// Diagram cells the last call tested.
    fn cells_tested(&self) -> u64 {
        self.coordinator.report().cells_tested
    }

    /// Forgets every decision and sample ([`Coordinator::reset`]).
    fn reset(&mut self) {
        self.coordinator.reset();
    }

    /// Forgets the coordinator's decisions and zeroes its report, as its own errors do:
    /// a request without programmes is its documented wrong robot count (a cell has robots).
    fn forget(&mut self) {
        let _ = self.coordinator.coordinate(&CoordinationRequest { programmes: &[] });
    }

    /// Coordinates `programmes`, robot j's points read as `views[j]` (3 numbers a point):
    /// each is checked ([`horizon_of`]), its horizon copied into the buffers and passed on
    /// with its `first_tick` moved to the horizon's first point. Never allocates.
    fn coordinate(
        &mut self,
        programmes: &[DcProgramme],
        views: &[&[f64]],
    ) -> Result<&CoordinationReport, DcStatus> {
        if programmes.len() != self.points.len() || views.len() != programmes.len() {
            return Err(DC_STATUS_WRONG_ROBOT_COUNT);
        }
        let mut horizons = [(0u64, 0usize); MAX_ROBOTS];
        for (j, (p, view)) in programmes.iter().zip(views).enumerate() {
            let (k0, count) = horizon_of(p, view)?;
            let from = view[3 * k0..].chunks_exact(3);
            for (dst, src) in self.points[j].iter_mut().zip(from).take(count) {
                *dst = Vec3::new(src[0], src[1], src[2]);
            }
            horizons[j] = (p.first_tick + u64::from(p.stride_ticks) * k0 as u64, count);
        }
        let none = Programme {
            first_tick: 0,
            stride_ticks: 1,
            points: &[],
            progress: 0.0,
            override_now: 0.0,
        };
        let mut list = [none; MAX_ROBOTS];
        for (j, (entry, p)) in list.iter_mut().zip(programmes).enumerate() {
            let (first_tick, count) = horizons[j];
            *entry = Programme {
                first_tick,
                stride_ticks: p.stride_ticks,
                points: &self.points[j][..count],
                progress: p.progress,
                override_now: p.override_now,
            };
        }
        let request = CoordinationRequest { programmes: &list[..programmes.len()] };
        self.coordinator.coordinate(&request).map_err(|e| match e {
            CoordinationError::WrongRobotCount { .. } => DC_STATUS_WRONG_ROBOT_COUNT,
            CoordinationError::InvalidProgramme { .. } => DC_STATUS_INVALID_PROGRAMME,
        })
    }
}

/// Checks programme `p` (its points `view`, `3 * n_points` numbers) against its contract and
/// returns its horizon: the index of the point at or just behind the progress, and how many
/// points from it on the coordination reads (at most [`MAX_SAMPLES`]). That point's tick is
/// at or before the progress in floating point too, as the coordinator checks it.
fn horizon_of(p: &DcProgramme, view: &[f64]) -> Result<(usize, usize), DcStatus> {
    let n = p.n_points as usize;
    let stride = u64::from(p.stride_ticks);
    if n == 0 || n > DC_MAX_PROGRAMME_POINTS as usize || view.len() != 3 * n {
        return Err(DC_STATUS_INVALID_PROGRAMME);
    }
    if stride == 0
        || p.first_tick % stride != 0
        || p.first_tick.checked_add(stride * (n as u64 - 1)).is_none()
    {
        return Err(DC_STATUS_INVALID_PROGRAMME);
    }
    if !(p.progress.is_finite() && p.override_now.is_finite() && view.iter().all(|v| v.is_finite()))
    {
        return Err(DC_STATUS_NON_FINITE);
    }
    let (first, stride_r) = (p.first_tick as f64, f64::from(p.stride_ticks));
    let last = first + stride_r * (n - 1) as f64;
    if !(p.progress >= first && p.progress <= last && (0.0..=1.0).contains(&p.override_now)) {
        return Err(DC_STATUS_PROGRESS_OUT_OF_RANGE);
    }
    let mut k0 = (((p.progress - first) / stride_r).floor() as usize).min(n - 1);
    while k0 > 0 && p.progress < (p.first_tick + stride * k0 as u64) as f64 {
        k0 -= 1;
    }
    Ok((k0, (n - k0).min(MAX_SAMPLES)))
}

impl DcRobotCoordination {
    /// The C form of one robot's answer.
    fn from_rust(r: &RobotCoordination) -> DcRobotCoordination {
        DcRobotCoordination {
            override_factor: r.override_factor,
            held_by: r.held_by.map_or(-1, |j| j as i32),
            hold_mm: r.hold_mm,
            rank: r.rank as u32,
        }
    }
}

/// A `DcCoordinationRequest` with `struct_size` set, no robots and no programmes: set
/// `n_robots` and `programmes` before each call.
#[no_mangle]
pub extern "C" fn dc_coordination_request_default() -> DcCoordinationRequest {
    DcCoordinationRequest {
        struct_size: size_of::<DcCoordinationRequest>() as u32,
        n_robots: 0,
        programmes: std::ptr::null(),
    }
}

/// The coordination (SPEC section 9), the call for the tick loop before the protective query:
/// each robot's speed override for the next tick from the robots' programmes ahead, so that a
/// line keeps moving without the protective verdict having to stop it. Robot j yields to
/// another where their programmes conflict (their boxes may come within the coordination's
/// clearance, `dc_set_coordination_clearance`): it slows down to stand before the shared
/// region, the other goes on. `req->programmes[j]` is robot j's programme (`DcProgramme`);
/// of its points the coordination reads `dc_coordination_horizon()` from the one at or
/// behind the progress on (all are checked). The controller scales robot j's progress by
/// `out_overrides[j]` over the next tick, and passes what it followed as the next call's
/// `override_now`; each factor is ramped within the robot's `max_accel_mm_s2`
/// (`dc_set_stop_model`). Nothing here is a proof: the protective query stays the last word,
/// and an override the robots do not follow costs at most a STOP.
///
/// Writes `out_overrides[0 .. n_robots]` (and `out_robots[0 .. n_robots]` when not NULL) on
/// every call whose `req` is not NULL and holds `n_robots` (at most `DC_MAX_ROBOTS` entries;
/// with `req` NULL nothing can be written, the status alone says stand): the
/// overrides in [0, 1] with `DC_STATUS_OK`; on every other status every override is 0.0 (fail
/// closed: the robots stand), every robot `held_by` -1, and the decisions are forgotten.
/// Statuses: `DC_STATUS_NULL_POINTER` (handle, req, its programmes, a programme's points or
/// out_overrides NULL), `DC_STATUS_INVALID_ARGUMENT` (a `struct_size` smaller than this
/// header's `sizeof(DcCoordinationRequest)`), `DC_STATUS_WRONG_ROBOT_COUNT` (`n_robots` is not
/// the cell's robot count), `DC_STATUS_INVALID_PROGRAMME`, `DC_STATUS_NON_FINITE` (a point,
/// progress or override_now NaN or infinite), `DC_STATUS_PROGRESS_OUT_OF_RANGE`,
/// `DC_STATUS_BUSY` (nothing done), `DC_STATUS_PANIC` (destroy the handle). Never allocates,
/// locks or does I/O.
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*`; `req` must be NULL or point to a
/// readable `DcCoordinationRequest` of `struct_size` bytes, whose `programmes` is NULL or
/// points to `n_robots` readable `DcProgramme`, each with `points` NULL or pointing to
/// `3 * n_points` readable doubles; `out_overrides` must be NULL or hold `n_robots` writable
/// doubles, `out_robots` NULL or `n_robots` writable `DcRobotCoordination`.
#[no_mangle]
pub unsafe extern "C" fn dc_coordinate(
    handle: *mut DcCollider,
    req: *const DcCoordinationRequest,
    out_overrides: *mut f64,
    out_robots: *mut DcRobotCoordination,
) -> DcStatus {
    // SAFETY: the caller guarantees `req` is NULL or readable for its `struct_size`.
    let n_out = unsafe { outputs_of(req) };
    let coordinate = |c: &mut Collider| {
        let started = Instant::now();
        let coordination = c.coordination();
        // SAFETY: the caller's guarantees on the request and the outputs are passed on.
        let status = unsafe { coordinate_on(coordination, req, out_overrides, out_robots) };
        if status != DC_STATUS_OK {
            coordination.forget();
        }
        let cells = if status == DC_STATUS_OK { coordination.cells_tested() } else { 0 };
        c.stats.coordinate.record(started.elapsed(), cells, false);
        status
    };
    // SAFETY: the caller guarantees `handle` is NULL or live.
    let status = boundary(|| flatten(unsafe { live(handle, coordinate) }));
    if status != DC_STATUS_OK {
        // SAFETY: the caller guarantees `n_out` writable elements behind each output not NULL.
        unsafe { write_standing(n_out, out_overrides, out_robots) };
    }
    status
}

/// How many outputs a call writes: the request's `n_robots` (at most `DC_MAX_ROBOTS`); 0 when
/// the request is NULL or its `struct_size` too small to hold `n_robots`.
///
/// # Safety
/// `req` must be NULL or point to a readable request of `struct_size` bytes.
unsafe fn outputs_of(req: *const DcCoordinationRequest) -> usize {
    if req.is_null() {
        return 0;
    }
    // SAFETY: non-null and readable; `struct_size` is the first field of every version.
    let size = unsafe { std::ptr::addr_of!((*req).struct_size).read() } as usize;
    if size < offset_of!(DcCoordinationRequest, n_robots) + size_of::<u32>() {
        return 0;
    }
    // SAFETY: readable, and `struct_size` says the request holds `n_robots`.
    let n = unsafe { std::ptr::addr_of!((*req).n_robots).read() };
    (n as usize).min(DC_MAX_ROBOTS)
}

/// The body of `dc_coordinate` on a live handle's coordination: reads and checks the request,
/// coordinates and writes the outputs on success.
///
/// # Safety
/// As `dc_coordinate` for `req` and the outputs.
unsafe fn coordinate_on(
    coordination: &mut Coordination,
    req: *const DcCoordinationRequest,
    out_overrides: *mut f64,
    out_robots: *mut DcRobotCoordination,
) -> DcStatus {
    if req.is_null() || out_overrides.is_null() {
        return DC_STATUS_NULL_POINTER;
    }
    // SAFETY: non-null and readable; `struct_size` is the first field of every version.
    if (unsafe { std::ptr::addr_of!((*req).struct_size).read() } as usize)
        < size_of::<DcCoordinationRequest>()
    {
        return DC_STATUS_INVALID_ARGUMENT;
    }
    // SAFETY: readable, and `struct_size` says it holds the whole struct.
    let req = unsafe { req.read() };
    let n = req.n_robots as usize;
    if req.programmes.is_null() {
        return DC_STATUS_NULL_POINTER;
    }
    if n != coordination.points.len() {
        return DC_STATUS_WRONG_ROBOT_COUNT;
    }
    // SAFETY: non-null, and the caller guarantees `n_robots` readable programmes.
    let programmes = unsafe { std::slice::from_raw_parts(req.programmes, n) };
    let mut views: [&[f64]; MAX_ROBOTS] = [&[]; MAX_ROBOTS];
    for (view, p) in views.iter_mut().zip(programmes) {
        if p.n_points == 0 || p.n_points > DC_MAX_PROGRAMME_POINTS {
            return DC_STATUS_INVALID_PROGRAMME;
        }
        if p.points.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees `3 * n_points` readable doubles.
        *view = unsafe { std::slice::from_raw_parts(p.points, 3 * p.n_points as usize) };
    }
    let report = match coordination.coordinate(programmes, &views[..n]) {
        Ok(report) => report,
        Err(status) => return status,
    };
    for (j, r) in report.robots.iter().enumerate().take(n) {
        // SAFETY: non-null, and the caller guarantees `n_robots` writable doubles.
        unsafe { out_overrides.add(j).write(r.override_factor) };
        if !out_robots.is_null() {
            // SAFETY: non-null, and the caller guarantees `n_robots` writable elements.
            unsafe { out_robots.add(j).write(DcRobotCoordination::from_rust(r)) };
        }
    }
    DC_STATUS_OK
}

/// Writes "stand" (override 0.0, held by no one) to the first `n` elements of the outputs
/// that are not NULL.
///
/// # Safety
/// Each output must be NULL or hold `n` writable elements.
unsafe fn write_standing(n: usize, out_overrides: *mut f64, out_robots: *mut DcRobotCoordination) {
    for j in 0..n {
        if !out_overrides.is_null() {
            // SAFETY: non-null, and the caller guarantees `n` writable doubles.
            unsafe { out_overrides.add(j).write(0.0) };
        }
        if !out_robots.is_null() {
            // SAFETY: non-null, and the caller guarantees `n` writable elements.
            unsafe { out_robots.add(j).write(DcRobotCoordination::STAND) };
        }
    }
}

/// How many points of each programme `dc_coordinate` reads at most, from the one at or just
/// behind the robot's progress on (its horizon); points beyond are checked but not used. A
/// property of this library build (it may grow in later versions), not of a handle.
#[no_mangle]
pub extern "C" fn dc_coordination_horizon() -> u32 {
    MAX_SAMPLES as u32
}

/// Forgets every decision and sample of the coordination (a restart of the line, or after a
/// STOP: the robots stand where the programmes did not expect them). NULL is a no-op; a panic
/// inside poisons the handle. Allocates nothing.
///
/// # Safety
/// `handle` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dc_coordination_reset(handle: *mut DcCollider) {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    let _ = unsafe { live(handle, |c| c.coordination().reset()) };
}

/// Sets the coordination's clearance (mm, default 40): two robots' programme samples
/// conflict when their boxes may come closer than this, so it is the room the protective
/// verdict needs beyond contact to prove a stop of the moving robot apart (a larger one keeps
/// the robots further apart, and makes them wait more). The other settings are kept, the
/// decisions forgotten. Setup only, like
/// `dc_set_stop_model`: it allocates (the coordinator is made again); call it before the tick
/// loop. `dc_set_stop_model` keeps it.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_INVALID_ARGUMENT` (not finite
/// or not > 0; the handle keeps its clearance and `dc_last_init_error` says so),
/// `DC_STATUS_BUSY`, `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dc_set_coordination_clearance(
    handle: *mut DcCollider,
    clearance_mm: f64,
) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { set_on_handle(handle, |c| c.coordination().set_clearance(clearance_mm)) }
}

/// Sets who has the right of way where two programmes conflict (default
/// `DC_RIGHT_OF_WAY_ARRIVAL`). With `DC_RIGHT_OF_WAY_PROGRAMMED` the programmes' ticks must be
/// one clock of the line (`DcProgramme::first_tick` and `progress` counted alike for every
/// robot, as a planner that timed the robots together has them): a robot then waits at a
/// conflict only for a robot programmed to pass it at least two strides sooner, so the
/// robots keep their programmed order, and no set of robots waits for each other (README,
/// "Keeping a line moving"). The other settings are kept, the decisions forgotten. Setup
/// only, like `dc_set_coordination_clearance` (it allocates); `dc_set_stop_model` keeps it.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_INVALID_ARGUMENT` (another
/// value; the handle keeps its rule and `dc_last_init_error` says so), `DC_STATUS_BUSY`,
/// `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dc_set_coordination_right_of_way(
    handle: *mut DcCollider,
    rule: DcRightOfWay,
) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { set_on_handle(handle, |c| c.coordination().set_right_of_way(rule)) }
}
