//! The coordination's C ABI (`dc_coordinate`, `src/ffi/coordination.rs`), exercised from Rust
//! through the exported functions: every bad input's status with every override written 0.0
//! (fail closed), the same answers bit for bit as the Rust `Coordinator` on the same inputs
//! over a closed loop on T1 (an independent check of the conversion of the C programmes and
//! their horizon), and no allocation in `dc_coordinate` after the first call.

mod ffi_common;
mod protective_common;

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::Cell;
use delta_collide::coord::{
    CoordinationConfig, CoordinationRequest, Coordinator, Programme, RightOfWay, RobotCoordination,
};
use delta_collide::ffi::*;
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;
use ffi_common::{last_init_error, two_robot_cell};
use protective_common::allocations;
use std::mem::size_of;

/// Programme ticks between two points, as the C harness passes them.
const STRIDE: u32 = 4;

/// The minimum-jerk profile of the mock's trajectories.
fn min_jerk(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 + t * (-15.0 + 6.0 * t))
}

/// One pick-and-place cycle of 1000 ticks in a robot's MCS, `toward` (+1 or -1) the other
/// robot along x: pick on the far side at x = -150 toward, place at the midpoint of the bases
/// (225 mm toward), the same ticks for both robots; `cycles` of them, ending at the pick (the
/// C harness's `mr_pick_place_programme` on T1).
fn waypoints(toward: f64, cycles: u64) -> Vec<(u64, Vec3)> {
    let p = |x: f64, z: f64| Vec3::new(toward * x, 0.0, z);
    let cycle = [
        (80, p(-150.0, -470.0)),
        (180, p(-150.0, -400.0)),
        (430, p(225.0, -400.0)),
        (530, p(225.0, -440.0)),
        (580, p(225.0, -440.0)),
        (680, p(225.0, -400.0)),
        (900, p(-150.0, -400.0)),
        (1000, p(-150.0, -470.0)),
    ];
    let mut out = vec![(0, p(-150.0, -470.0))];
    for c in 0..cycles {
        out.extend(cycle.iter().map(|&(t, q)| (1000 * c + t, q)));
    }
    out
}

/// The set-point at `tick` of the trajectory through `w`.
fn setpoint(w: &[(u64, Vec3)], tick: u64) -> Vec3 {
    for pair in w.windows(2) {
        let ((t0, a), (t1, b)) = (pair[0], pair[1]);
        if tick <= t1 {
            let s = min_jerk((tick.saturating_sub(t0)) as f64 / (t1 - t0) as f64);
            return a + (b - a) * s;
        }
    }
    w[w.len() - 1].1
}

/// A robot's programme points from `first_tick` (a multiple of [`STRIDE`]) to the
/// trajectory's end, as vectors and as the C ABI's flat doubles.
fn programme(w: &[(u64, Vec3)], first_tick: u64) -> (Vec<Vec3>, Vec<f64>) {
    let end = w[w.len() - 1].0;
    let points: Vec<Vec3> =
        (first_tick..=end).step_by(STRIDE as usize).map(|t| setpoint(w, t)).collect();
    let flat = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    (points, flat)
}

fn t1() -> Cell {
    reference_cell("T1").unwrap()
}

/// Robot A's and B's programmes on T1: A's from tick 0, B's from tick 8 (its first points
/// dropped, as a controller passes only what lies ahead).
struct Line {
    points: [Vec<Vec3>; 2],
    flat: [Vec<f64>; 2],
    first: [u64; 2],
}

impl Line {
    fn new() -> Line {
        let cell = t1();
        let (a, b) = (waypoints(1.0, 3), waypoints(-1.0, 3));
        let ((pa, fa), (pb, fb)) = (programme(&a, 0), programme(&b, 8));
        for (j, points) in [&pa, &pb].into_iter().enumerate() {
            for q in points {
                assert!(cell.robots[j].model.delta.is_reachable(q), "robot {j}: {q:?}");
            }
        }
        Line { points: [pa, pb], flat: [fa, fb], first: [0, 8] }
    }

    /// The C programmes at `progress` and `override_now` per robot.
    fn c_programmes(&self, progress: [f64; 2], override_now: [f64; 2]) -> [DcProgramme; 2] {
        [0, 1].map(|j| DcProgramme {
            first_tick: self.first[j],
            stride_ticks: STRIDE,
            n_points: self.points[j].len() as u32,
            points: self.flat[j].as_ptr(),
            progress: progress[j],
            override_now: override_now[j],
        })
    }

    /// The last programme tick of robot `j`.
    fn end(&self, j: usize) -> f64 {
        (self.first[j] + u64::from(STRIDE) * (self.points[j].len() as u64 - 1)) as f64
    }
}

/// `dc_coordinate` on `programmes` with the outputs preset to garbage (0.5, rank 7), so that
/// an output left unwritten shows: (status, overrides, robots).
fn coordinate(
    h: *mut DcCollider,
    programmes: &[DcProgramme],
) -> (DcStatus, [f64; 2], [DcRobotCoordination; 2]) {
    let request = DcCoordinationRequest {
        n_robots: programmes.len() as u32,
        programmes: programmes.as_ptr(),
        ..dc_coordination_request_default()
    };
    coordinate_raw(h, &request)
}

const GARBAGE: DcRobotCoordination =
    DcRobotCoordination { override_factor: 0.5, held_by: 7, hold_mm: 7.0, rank: 7 };

fn coordinate_raw(
    h: *mut DcCollider,
    request: *const DcCoordinationRequest,
) -> (DcStatus, [f64; 2], [DcRobotCoordination; 2]) {
    let mut overrides = [0.5; 2];
    let mut robots = [GARBAGE; 2];
    // SAFETY: h is NULL or live; the request is NULL or valid for the test's cases; the
    // outputs hold two elements, and no request below has n_robots above 2 without a buffer
    // of its own.
    let s = unsafe { dc_coordinate(h, request, overrides.as_mut_ptr(), robots.as_mut_ptr()) };
    (s, overrides, robots)
}

/// The outputs of a failed call: every robot stands.
fn assert_standing(what: &str, s: DcStatus, overrides: [f64; 2], robots: [DcRobotCoordination; 2]) {
    assert_ne!(s, DC_STATUS_OK, "{what}");
    assert_eq!(overrides, [0.0; 2], "{what}: status {s}");
    for r in robots {
        assert_eq!((r.override_factor, r.held_by, r.rank), (0.0, -1, 0), "{what}: {r:?}");
    }
}

#[test]
fn every_bad_input_has_its_status_and_every_robot_stands() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT);
    let line = Line::new();
    let good = line.c_programmes([40.0, 40.0], [1.0, 1.0]);
    let (s, overrides, _) = coordinate(h, &good);
    assert_eq!(s, DC_STATUS_OK);
    assert!(overrides.iter().all(|o| (0.0..=1.0).contains(o)), "{overrides:?}");

    let case = |what: &str, expected: DcStatus, programmes: &[DcProgramme; 2]| {
        let (s, overrides, robots) = coordinate(h, programmes);
        assert_eq!(s, expected, "{what}");
        assert_standing(what, s, overrides, robots);
        // A valid call after the error answers again.
        assert_eq!(coordinate(h, &good).0, DC_STATUS_OK, "after {what}");
    };
    let with = |j: usize, f: &dyn Fn(&mut DcProgramme)| {
        let mut p = good;
        f(&mut p[j]);
        p
    };
    let mut nan_far = line.flat[1].clone();
    nan_far[3 * 300 + 1] = f64::NAN; // beyond the horizon: checked all the same
    let mut inf_near = line.flat[0].clone();
    inf_near[3 * 11 + 2] = f64::INFINITY;
    case("NULL points", DC_STATUS_NULL_POINTER, &with(1, &|p| p.points = std::ptr::null()));
    case("a NaN point far ahead", DC_STATUS_NON_FINITE, &with(1, &|p| p.points = nan_far.as_ptr()));
    case("an infinite point", DC_STATUS_NON_FINITE, &with(0, &|p| p.points = inf_near.as_ptr()));
    case("NaN progress", DC_STATUS_NON_FINITE, &with(0, &|p| p.progress = f64::NAN));
    case("infinite override", DC_STATUS_NON_FINITE, &with(1, &|p| p.override_now = f64::INFINITY));
    let before = DC_STATUS_PROGRESS_OUT_OF_RANGE;
    case("progress before the first point", before, &with(1, &|p| p.progress = 7.5));
    let end = line.end(0);
    case("progress after the last point", before, &with(0, &|p| p.progress = end + 0.25));
    case("negative progress", before, &with(0, &|p| p.progress = -1.0));
    case("override above 1", before, &with(0, &|p| p.override_now = 1.5));
    case("negative override", before, &with(1, &|p| p.override_now = -0.1));
    let invalid = DC_STATUS_INVALID_PROGRAMME;
    case("stride 0", invalid, &with(0, &|p| p.stride_ticks = 0));
    case("first tick not a multiple of the stride", invalid, &with(1, &|p| p.first_tick = 6));
    case("no points", invalid, &with(0, &|p| p.n_points = 0));
    case("too many points", invalid, &with(1, &|p| p.n_points = DC_MAX_PROGRAMME_POINTS + 1));
    case(
        "the last tick beyond 2^64",
        invalid,
        &with(0, &|p| {
            p.first_tick = u64::MAX - 3;
            p.progress = p.first_tick as f64;
        }),
    );
    // The progress exactly on the last point, and a programme of one point, are valid.
    let at_end = with(0, &|p| p.progress = end);
    assert_eq!(coordinate(h, &at_end).0, DC_STATUS_OK);
    let one = [line.flat[0][0], line.flat[0][1], line.flat[0][2]];
    let single = with(0, &|p| {
        (p.points, p.n_points, p.progress) = (one.as_ptr(), 1, 0.0);
    });
    assert_eq!(coordinate(h, &single).0, DC_STATUS_OK);

    // The request itself.
    let request = |f: &dyn Fn(&mut DcCoordinationRequest)| {
        let mut r = DcCoordinationRequest {
            n_robots: 2,
            programmes: good.as_ptr(),
            ..dc_coordination_request_default()
        };
        f(&mut r);
        r
    };
    let expect = |what: &str, status: DcStatus, r: DcCoordinationRequest| {
        let (s, overrides, robots) = coordinate_raw(h, &r);
        assert_eq!(s, status, "{what}");
        assert_standing(what, s, overrides, robots);
    };
    let size = std::mem::size_of::<DcCoordinationRequest>() as u32;
    assert_eq!(dc_coordination_request_default().struct_size, size);
    assert_eq!(dc_coordination_request_default().n_robots, 0);
    expect(
        "NULL programmes",
        DC_STATUS_NULL_POINTER,
        request(&|r| r.programmes = std::ptr::null()),
    );
    expect(
        "a short struct_size",
        DC_STATUS_INVALID_ARGUMENT,
        request(&|r| r.struct_size = size - 1),
    );
    // One programme: the one output the request holds stands, the other is not touched.
    let (s, overrides, robots) = coordinate_raw(h, &request(&|r| r.n_robots = 1));
    assert_eq!((s, overrides), (DC_STATUS_WRONG_ROBOT_COUNT, [0.0, 0.5]));
    assert_eq!(robots, [STAND, GARBAGE]);
    expect("struct_size 8", DC_STATUS_INVALID_ARGUMENT, request(&|r| r.struct_size = 8));
    // A longer struct (a later header's) is read as this one.
    assert_eq!(coordinate_raw(h, &request(&|r| r.struct_size = size + 16)).0, DC_STATUS_OK);
    // Three programmes: all three outputs stand.
    let three = [good[0], good[1], good[0]];
    let r3 = request(&|r| (r.n_robots, r.programmes) = (3, three.as_ptr()));
    let (mut overrides, mut robots) = ([0.5; 3], [GARBAGE; 3]);
    // SAFETY: live handle, a valid request, outputs of three elements.
    let s = unsafe { dc_coordinate(h, &r3, overrides.as_mut_ptr(), robots.as_mut_ptr()) };
    assert_eq!((s, overrides), (DC_STATUS_WRONG_ROBOT_COUNT, [0.0; 3]));
    assert!(robots.iter().all(|r| *r == STAND), "{robots:?}");
    // Without a request, or a struct_size too small to hold n_robots, nothing can be written.
    let (s, overrides, _) = coordinate_raw(h, std::ptr::null());
    assert_eq!((s, overrides), (DC_STATUS_NULL_POINTER, [0.5; 2]));
    let (s, overrides, _) = coordinate_raw(h, &request(&|r| r.struct_size = 4));
    assert_eq!((s, overrides), (DC_STATUS_INVALID_ARGUMENT, [0.5; 2]));
    // NULL outputs and handle.
    let r = request(&|_| ());
    let mut robots = [GARBAGE; 2];
    // SAFETY: live handle and valid request; NULL overrides is the input under test.
    let s = unsafe { dc_coordinate(h, &r, std::ptr::null_mut(), robots.as_mut_ptr()) };
    assert_eq!(s, DC_STATUS_NULL_POINTER);
    assert!(robots.iter().all(|r| r.override_factor == 0.0 && r.held_by == -1));
    let (s, overrides, robots) = coordinate_raw(std::ptr::null_mut(), &r);
    assert_eq!(s, DC_STATUS_NULL_POINTER);
    assert_standing("NULL handle", s, overrides, robots);
    let mut overrides = [0.5; 2];
    // SAFETY: live handle and valid request; NULL robots is allowed.
    let s = unsafe { dc_coordinate(h, &r, overrides.as_mut_ptr(), std::ptr::null_mut()) };
    assert_eq!(s, DC_STATUS_OK);
    assert!(overrides.iter().all(|o| (0.0..=1.0).contains(o)));

    // The clearance setter.
    // SAFETY: live handle, or NULL.
    unsafe {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(dc_set_coordination_clearance(h, bad), DC_STATUS_INVALID_ARGUMENT, "{bad}");
            assert!(last_init_error().contains("clearance_mm"), "{}", last_init_error());
        }
        assert_eq!(
            dc_set_coordination_clearance(std::ptr::null_mut(), 30.0),
            DC_STATUS_NULL_POINTER
        );
        assert_eq!(dc_set_coordination_clearance(h, 30.0), DC_STATUS_OK);
        assert_eq!(last_init_error(), "");
        dc_coordination_reset(std::ptr::null_mut());
        dc_coordination_reset(h);
    }
    assert_eq!(coordinate(h, &good).0, DC_STATUS_OK);
    for s in [DC_STATUS_INVALID_PROGRAMME, DC_STATUS_PROGRESS_OUT_OF_RANGE] {
        // SAFETY: dc_status_str returns a static NUL-terminated string.
        let text = unsafe { std::ffi::CStr::from_ptr(dc_status_str(s)) }.to_str().unwrap();
        assert!(text.contains("programme"), "status {s}: {text}");
    }
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

const STAND: DcRobotCoordination =
    DcRobotCoordination { override_factor: 0.0, held_by: -1, hold_mm: 0.0, rank: 0 };

/// The C form of a Rust answer.
fn c_form(r: &RobotCoordination) -> DcRobotCoordination {
    DcRobotCoordination {
        override_factor: r.override_factor,
        held_by: r.held_by.map_or(-1, |j| j as i32),
        hold_mm: r.hold_mm,
        rank: r.rank as u32,
    }
}

/// What a closed loop saw.
#[derive(Debug, Default)]
struct Loop {
    /// Ticks on which some robot was held, and the smallest override answered.
    held_ticks: usize,
    least_override: f64,
    /// Allocations by the `dc_coordinate` calls after the first.
    allocations: usize,
    /// Allocations by `dc_coordination_reset`.
    reset_allocations: usize,
}

/// `ticks` of a closed loop on T1 (`cell`, the handle's model): each tick the same programmes
/// go to `dc_coordinate` on `h` and to a Rust `Coordinator` with `config`; the answers must
/// agree bit for bit, and the robots follow them. At tick `fault` both get a programme with a
/// NaN point (both forget their decisions); at tick `reset` both are reset.
fn closed_loop(
    h: *mut DcCollider,
    cell: Cell,
    config: CoordinationConfig,
    ticks: usize,
    (fault, reset): (usize, usize),
) -> Loop {
    let line = Line::new();
    let mut rust = Coordinator::new(cell, config);
    let mut progress = [0.0, 8.0];
    let mut override_now = [0.0; 2];
    let mut seen = Loop { least_override: 1.0, ..Loop::default() };
    let mut nan = line.flat[0].clone();
    nan[3 * 40] = f64::NAN;
    let mut nan_points = line.points[0].clone();
    nan_points[40].x = f64::NAN;
    for tick in 0..ticks {
        if tick == reset {
            rust.reset();
            let before = allocations();
            // SAFETY: live handle.
            unsafe { dc_coordination_reset(h) };
            seen.reset_allocations = allocations() - before;
        }
        let mut c = line.c_programmes(progress, override_now);
        let mut r: Vec<Programme> = (0..2)
            .map(|j| Programme {
                first_tick: line.first[j],
                stride_ticks: STRIDE,
                points: &line.points[j],
                progress: progress[j],
                override_now: override_now[j],
            })
            .collect();
        if tick == fault {
            c[0].points = nan.as_ptr();
            r[0].points = &nan_points;
        }
        let request = DcCoordinationRequest {
            n_robots: 2,
            programmes: c.as_ptr(),
            ..dc_coordination_request_default()
        };
        let (mut overrides, mut robots) = ([0.5; 2], [GARBAGE; 2]);
        let before = allocations();
        // SAFETY: live handle, valid request (its points outlive the call), outputs of 2.
        let s = unsafe { dc_coordinate(h, &request, overrides.as_mut_ptr(), robots.as_mut_ptr()) };
        if tick > 0 && tick != reset {
            seen.allocations += allocations() - before;
        }
        let answer = rust.coordinate(&CoordinationRequest { programmes: &r });
        match answer {
            Ok(report) => {
                assert_eq!(s, DC_STATUS_OK, "tick {tick}");
                let expected: Vec<DcRobotCoordination> = report.robots.iter().map(c_form).collect();
                for j in 0..2 {
                    assert_eq!(
                        overrides[j].to_bits(),
                        expected[j].override_factor.to_bits(),
                        "tick {tick} robot {j}: {} (C) != {} (Rust)",
                        overrides[j],
                        expected[j].override_factor
                    );
                    assert_eq!(robots[j].override_factor.to_bits(), overrides[j].to_bits());
                    assert_eq!(
                        (robots[j].held_by, robots[j].hold_mm.to_bits(), robots[j].rank),
                        (expected[j].held_by, expected[j].hold_mm.to_bits(), expected[j].rank),
                        "tick {tick} robot {j}: {:?} != {:?}",
                        robots[j],
                        expected[j]
                    );
                }
            }
            Err(e) => {
                assert_eq!(tick, fault, "the Rust coordinator refused tick {tick}: {e}");
                assert_eq!(s, DC_STATUS_NON_FINITE);
                assert_eq!(overrides, [0.0; 2]);
            }
        }
        seen.held_ticks += usize::from(robots.iter().any(|r| r.held_by >= 0));
        for j in 0..2 {
            seen.least_override = seen.least_override.min(overrides[j]);
            let end = line.end(j);
            progress[j] = (progress[j] + overrides[j]).min(end);
            override_now[j] = if progress[j] >= end { 0.0 } else { overrides[j] };
        }
    }
    seen
}

#[test]
fn dc_coordinate_answers_as_the_rust_coordinator_bit_for_bit_and_never_allocates() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT);
    let seen = closed_loop(h, t1(), CoordinationConfig::default(), 1600, (700, 1100));
    println!("default settings: {seen:?}");
    assert!(seen.held_ticks > 50, "the programmes conflict: a robot is held ({seen:?})");
    assert!(seen.least_override < 0.5, "a robot slows down for the other ({seen:?})");
    assert_eq!(seen.allocations, 0, "dc_coordinate allocated");
    assert_eq!(seen.reset_allocations, 0, "dc_coordination_reset allocated");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

#[test]
fn the_clearance_and_the_stop_models_reach_the_coordination() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    let stiff = StopModel {
        reaction_ms: 2.0,
        decel_mm_s2: 120_000.0,
        max_accel_mm_s2: 130_000.0,
        max_speed_mm_s: 4_600.0,
    };
    let c_stop = DcStopConfig {
        reaction_ms: stiff.reaction_ms,
        decel_mm_s2: stiff.decel_mm_s2,
        max_accel_mm_s2: stiff.max_accel_mm_s2,
        max_speed_mm_s: stiff.max_speed_mm_s,
        ..dc_stop_config_default()
    };
    // SAFETY: live handle, two readable stop models.
    unsafe {
        assert_eq!(dc_set_coordination_clearance(h, 60.0), DC_STATUS_OK);
        assert_eq!(dc_set_stop_model(h, 2.0, 10.0, [c_stop; 2].as_ptr(), 2), DC_STATUS_OK);
    }
    let cell = t1().with_stopping(2.0, vec![stiff; 2]).unwrap();
    let config = CoordinationConfig { clearance_mm: 60.0, ..CoordinationConfig::default() };
    let seen = closed_loop(h, cell, config, 900, (usize::MAX, 400));
    println!("clearance 60 mm, stiff stops, 2 ms tick: {seen:?}");
    assert!(seen.held_ticks > 0, "{seen:?}");
    assert_eq!(seen.allocations, 0, "dc_coordinate allocated");
    assert_eq!(seen.reset_allocations, 0, "dc_coordination_reset allocated");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

#[test]
fn the_right_of_way_reaches_the_coordination() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    // SAFETY: live handle, or NULL.
    unsafe {
        for bad in [2, u32::MAX] {
            assert_eq!(dc_set_coordination_right_of_way(h, bad), DC_STATUS_INVALID_ARGUMENT);
            assert!(last_init_error().contains("right of way"), "{}", last_init_error());
        }
        assert_eq!(
            dc_set_coordination_right_of_way(std::ptr::null_mut(), DC_RIGHT_OF_WAY_PROGRAMMED),
            DC_STATUS_NULL_POINTER
        );
        assert_eq!(dc_set_coordination_right_of_way(h, DC_RIGHT_OF_WAY_PROGRAMMED), DC_STATUS_OK);
        assert_eq!(last_init_error(), "");
    }
    // Bit for bit the Rust coordinator under the programmed order: the setting arrived.
    let config = CoordinationConfig {
        right_of_way: RightOfWay::Programmed,
        ..CoordinationConfig::default()
    };
    let seen = closed_loop(h, t1(), config, 900, (usize::MAX, 400));
    println!("programmed order: {seen:?}");
    assert!(seen.held_ticks > 0, "{seen:?}");
    // The tick statistics counted each dc_coordinate, with its diagram cells as work.
    let mut stats =
        DcTickStats { struct_size: size_of::<DcTickStats>() as u32, ..Default::default() };
    // SAFETY: live handle, writable out with its size set.
    assert_eq!(unsafe { dc_tick_stats(h, &mut stats) }, DC_STATUS_OK);
    let c = stats.coordinate;
    assert!(c.calls >= 900 && c.largest_work > 0 && c.largest_ns >= c.mean_ns, "{c:?}");
    assert_eq!(seen.allocations, 0, "dc_coordinate allocated");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}
