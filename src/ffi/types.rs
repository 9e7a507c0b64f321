//! The C-visible data types and codes of the ABI (thesis appendix A: the POU's interface).
//!
//! Numbers of statuses and verdicts are never reused. Enumerations are plain `u32` in C, so
//! a C caller can pass any value: Rust validates every one it reads.

use crate::math::Vec3;

/// Result code of every fallible function; `DC_STATUS_OK` is 0.
pub type DcStatus = u32;
/// The call succeeded.
pub const DC_STATUS_OK: DcStatus = 0;
/// A required pointer argument is NULL.
pub const DC_STATUS_NULL_POINTER: DcStatus = 1;
/// An input number is NaN or infinite.
pub const DC_STATUS_NON_FINITE: DcStatus = 2;
/// A TCP cannot be reached; the report's `unreachable_mask` says which robot.
pub const DC_STATUS_UNREACHABLE: DcStatus = 3;
/// A configuration value is out of range (negative length, no robots, unknown method, ...).
pub const DC_STATUS_INVALID_CONFIG: DcStatus = 4;
/// The number of TCPs differs from the number of robots in the cell.
pub const DC_STATUS_WRONG_ROBOT_COUNT: DcStatus = 5;
/// A file could not be read.
pub const DC_STATUS_IO: DcStatus = 6;
/// A cell file is not valid TOML or does not follow the schema.
pub const DC_STATUS_PARSE: DcStatus = 7;
/// An internal error was caught at the boundary; destroy the handle.
pub const DC_STATUS_PANIC: DcStatus = 8;
/// An argument is malformed (path not UTF-8, capacity too small, ...).
pub const DC_STATUS_INVALID_ARGUMENT: DcStatus = 9;
/// Table mode: the table buffer or file ends before its header, a section or the checksum is
/// complete. Copy the whole table file again.
pub const DC_STATUS_TABLE_TRUNCATED: DcStatus = 10;
/// Table mode: the buffer does not start with the table magic `DCTABLE\0`: not a table.
pub const DC_STATUS_TABLE_BAD_MAGIC: DcStatus = 11;
/// Table mode: the table's format version is not the one this library reads; rebuild it
/// with `delta-collide build`.
pub const DC_STATUS_TABLE_UNSUPPORTED_VERSION: DcStatus = 12;
/// Table mode: the table was written big-endian; this library reads little-endian tables.
pub const DC_STATUS_TABLE_WRONG_ENDIANNESS: DcStatus = 13;
/// Table mode: the checksum does not match or a field breaks an invariant (a flipped bit, a
/// bad copy); rebuild the table or copy it again.
pub const DC_STATUS_TABLE_CORRUPT: DcStatus = 14;
/// Table mode: the table was built for another cell than the configured one (geometry, boxes,
/// margins or placements differ); rebuild it with `delta-collide build --cell ...`.
pub const DC_STATUS_TABLE_WRONG_CELL: DcStatus = 15;
/// Table mode: the cell has fewer than two robots, so no pair for a table to answer; use
/// `dc_init` (exact mode) for it.
pub const DC_STATUS_TABLE_NOT_TWO_ROBOTS: DcStatus = 16;
/// Protective query: a TCP moved further, or changed its velocity more, in one tick than its
/// robot's stopping model allows (`max_speed_mm_s`, `max_accel_mm_s2`); the report's
/// `unreachable_mask` names the robot. The next query has no previous TCP.
pub const DC_STATUS_IMPLAUSIBLE_MOTION: DcStatus = 17;
/// Table mode, a cell of more than two robots: the bundle holds no table for a pair of robots
/// that can meet (`dc_last_init_error` names the pair and where it stands); rebuild the bundle
/// with `delta-collide build --cell ...` for this cell.
pub const DC_STATUS_TABLE_MISSING_PAIR: DcStatus = 18;
/// Table mode: the bundle's table for a pair of robots was built for another placement or
/// model of that pair (another spacing of the line; `dc_last_init_error` names the value that
/// differs); rebuild the bundle with `delta-collide build --cell ...` for this cell.
pub const DC_STATUS_TABLE_WRONG_PAIR: DcStatus = 19;
/// Timed protective query: the same cycle (or timestamp) as the last call, with other TCPs.
/// (The same cycle with the same TCPs gets the last call's verdict and report unchanged.)
pub const DC_STATUS_TIME_REPEATED: DcStatus = 20;
/// Timed protective query: a cycle or timestamp before the last call's.
pub const DC_STATUS_TIME_BACKWARDS: DcStatus = 21;
/// Timed protective query: more than `DC_MAX_INTERVAL_TICKS` ticks after the last call.
pub const DC_STATUS_TIME_JUMP: DcStatus = 22;
/// Timed protective query (`DC_CLOCK_NANOS`): less than half a tick after the last call.
pub const DC_STATUS_TIME_EARLY: DcStatus = 23;
/// Timed protective query: a cycle counter after a timestamp, or the reverse.
pub const DC_STATUS_CLOCK_CHANGED: DcStatus = 24;
/// The handle is in use by another call (another task or thread) right now; nothing was
/// done. A handle is for one task: give each task its own.
pub const DC_STATUS_BUSY: DcStatus = 25;
/// Coordination (`dc_coordinate`): a programme breaks its contract: no points or more than
/// `DC_MAX_PROGRAMME_POINTS`, `stride_ticks` 0, `first_tick` not a multiple of
/// `stride_ticks`, or its last point's tick beyond `UINT64_MAX`.
pub const DC_STATUS_INVALID_PROGRAMME: DcStatus = 26;
/// Coordination (`dc_coordinate`): a programme's `progress` lies outside its points' ticks
/// (from `first_tick` to the last point's), or its `override_now` outside [0, 1].
pub const DC_STATUS_PROGRESS_OUT_OF_RANGE: DcStatus = 27;

/// What the controller should do; 0 is STOP so that zeroed memory fails closed.
pub type DcVerdict = u32;
/// Could not decide (any error): stop the robots.
pub const DC_VERDICT_STOP: DcVerdict = 0;
/// No pair of robots collides. Only ever written together with `DC_STATUS_OK`.
pub const DC_VERDICT_FREE: DcVerdict = 1;
/// At least one pair of robots collides.
pub const DC_VERDICT_COLLISION: DcVerdict = 2;
/// Protective query: a stop started now is proved to keep every box apart, but with less
/// than `warn_mm` to spare. Only ever written together with `DC_STATUS_OK`.
pub const DC_VERDICT_WARN: DcVerdict = 3;

/// What `DcProtectiveRequest::time` counts (`clock`).
pub type DcClock = u32;
/// The controller's cycle counter: one more per tick (`dc_set_stop_model`'s `tick_ms`); the
/// TCPs are that cycle's set-points, or positions measured at the cycle's nominal time.
pub const DC_CLOCK_CYCLE: DcClock = 0;
/// A monotonic timestamp in nanoseconds of the moment the TCPs were measured.
pub const DC_CLOCK_NANOS: DcClock = 1;

/// Who has the right of way where two programmes conflict (`dc_set_coordination_right_of_way`).
pub type DcRightOfWay = u32;
/// The robot that reaches its hold point first at its programmed speed (the default): for
/// programmes each on a clock of its own.
pub const DC_RIGHT_OF_WAY_ARRIVAL: DcRightOfWay = 0;
/// The robot the programmes put there first: for programmes whose ticks are one clock of the
/// line (a planner timed the robots together). No set of robots then waits for each other.
pub const DC_RIGHT_OF_WAY_PROGRAMMED: DcRightOfWay = 1;

/// Most ticks between two timed protective calls whose interval still bounds the speeds; a
/// longer gap answers `DC_STATUS_TIME_JUMP`.
pub const DC_MAX_INTERVAL_TICKS: u64 = 4;

/// Most robots of a cell; the size of the per-robot arrays of `DcProtectiveReport`.
pub const DC_MAX_ROBOTS: usize = 32;

/// How a handle answers (`dc_mode`).
pub type DcMode = u32;
/// No handle (`dc_mode(NULL)`).
pub const DC_MODE_NONE: DcMode = 0;
/// Exact mode (`dc_init`, `dc_init_from_cell_file`): every box pair, separating axis test.
pub const DC_MODE_EXACT: DcMode = 1;
/// Table mode (`dc_init_with_table`, `dc_init_from_files`): one lookup in a precomputed
/// table per pair of robots that can meet (a bundle for more than two robots), which never
/// answers FREE where the robots collide.
pub const DC_MODE_TABLE: DcMode = 2;

/// Table mode: what a query does when the table's lookup says COLLISION
/// (`dc_set_table_confirmation`). A lookup's FREE is a proof and is answered as it is.
pub type DcConfirmation = u32;
/// Answer the table's label: COLLISION may come where the robots are a little apart.
pub const DC_CONFIRMATION_NONE: DcConfirmation = 0;
/// Confirm by the exact check and answer its verdict: table mode then answers as exact mode.
/// The default of every new table-mode handle (a cell file may say `table_confirm = "none"`).
pub const DC_CONFIRMATION_EXACT: DcConfirmation = 1;

/// Plain separating axis test.
pub const DC_METHOD_SAT: u32 = 0;
/// Separating axis test with the two-layer witness cache (thesis 3.1.4).
pub const DC_METHOD_SAT_CACHE: u32 = 1;

/// "No box" / "no robot" in reports.
pub const DC_BOX_NONE: u32 = u32::MAX;

/// A point or offset in mm.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcVec3 {
    /// x (mm).
    pub x: f64,
    /// y (mm).
    pub y: f64,
    /// z (mm).
    pub z: f64,
}

impl DcVec3 {
    /// As the crate's vector type.
    pub fn to_vec3(self) -> Vec3 {
        Vec3::new(self.x, self.y, self.z)
    }

    /// From the crate's vector type.
    pub fn from_vec3(v: &Vec3) -> Self {
        DcVec3 { x: v.x, y: v.y, z: v.z }
    }

    pub(crate) fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

/// Delta3 geometry (SPEC section 2): lengths in mm, motor limits in rad.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcDelta3 {
    /// MCS origin to motor axis point.
    pub f: f64,
    /// Upper link length.
    pub rf: f64,
    /// Lower link length.
    pub re: f64,
    /// TCP to lower link joint.
    pub e: f64,
    /// Lower motor limit (rad).
    pub theta_min: f64,
    /// Upper motor limit (rad).
    pub theta_max: f64,
}

/// A box at `TCP + offset`, aligned with the robot's MCS, with half-extents `half` (mm).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcBox {
    /// Centre relative to the TCP.
    pub offset: DcVec3,
    /// Half-extents.
    pub half: DcVec3,
}

/// One robot of a cell: geometry, box model and placement.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcRobotConfig {
    /// Kinematic parameters.
    pub geometry: DcDelta3,
    /// Half-extent H of a lower link box across the parallelogram (70 for the thesis robot).
    pub half_height: f64,
    /// Half-extent D of a lower link box in the arm's plane (17.5).
    pub half_depth: f64,
    /// Safety margin added to every half-extent of every box (mm, >= 0).
    pub margin: f64,
    /// 1: model the upper links too; 0: not (the thesis's choice).
    pub has_upper_links: u32,
    /// Upper link half-extent across the motor axis direction.
    pub upper_half_height: f64,
    /// Upper link half-extent in the arm's plane.
    pub upper_half_depth: f64,
    /// 1: model the moving platform as `platform`.
    pub has_platform: u32,
    /// The platform box.
    pub platform: DcBox,
    /// 1: model the tool as `tool`.
    pub has_tool: u32,
    /// The tool box (must enclose the tool over its whole rotation).
    pub tool: DcBox,
    /// Placement: rotation about z (rad).
    pub alpha: f64,
    /// Placement: `p_wcs = Rz(alpha) p_mcs + translation` (mm).
    pub translation: DcVec3,
}

/// A cell: `n_robots` robot configurations and the exact test to use.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct DcCellConfig {
    /// Array of `n_robots` robots; robot 0's MCS is normally the WCS.
    pub robots: *const DcRobotConfig,
    /// Number of robots, 1 to 32.
    pub n_robots: usize,
    /// `DC_METHOD_SAT` or `DC_METHOD_SAT_CACHE`.
    pub method: u32,
}

/// Summary of one query, written on every call when the pointer is not NULL.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DcQueryReport {
    /// Same value as `*out_verdict`.
    pub verdict: DcVerdict,
    /// Number of robot pairs that collide.
    pub colliding_pairs: u32,
    /// Bit j set: robot j's TCP is unreachable or not finite.
    pub unreachable_mask: u32,
    /// First colliding pair's first robot, or `DC_BOX_NONE`.
    pub first_robot_a: u32,
    /// First colliding pair's second robot, or `DC_BOX_NONE`.
    pub first_robot_b: u32,
    /// Box of `first_robot_a`: 0..2 lower links, then upper links, platform, tool. In table
    /// mode `DC_BOX_NONE` when the lookup alone answered (no exact check ran).
    pub first_box_a: u32,
    /// Box of `first_robot_b`.
    pub first_box_b: u32,
}

impl DcQueryReport {
    pub(crate) const STOP: DcQueryReport = DcQueryReport {
        verdict: DC_VERDICT_STOP,
        colliding_pairs: 0,
        unreachable_mask: 0,
        first_robot_a: DC_BOX_NONE,
        first_robot_b: DC_BOX_NONE,
        first_box_a: DC_BOX_NONE,
        first_box_b: DC_BOX_NONE,
    };
}

/// One robot pair's result of the last query.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DcPairResult {
    /// First robot, `robot_a < robot_b`.
    pub robot_a: u32,
    /// Second robot.
    pub robot_b: u32,
    /// 1 when the pair collides; 0 when free or undecided (see `dc_query`'s status).
    pub collides: u32,
    /// Colliding box of `robot_a`, or `DC_BOX_NONE`.
    pub box_a: u32,
    /// Colliding box of `robot_b`, or `DC_BOX_NONE`.
    pub box_b: u32,
}

/// One robot's stopping model (SPEC section 8) for `dc_set_stop_model`; start from
/// `dc_stop_config_default()`, which also sets `struct_size`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcStopConfig {
    /// `sizeof(DcStopConfig)` as the caller compiled it: lets later versions add fields.
    pub struct_size: usize,
    /// Time from a STOP until braking starts (ms); the TCP may do anything within the
    /// limits meanwhile. Default 4.
    pub reaction_ms: f64,
    /// Least deceleration along the path while braking (mm/s^2). Default 40000.
    pub decel_mm_s2: f64,
    /// Largest TCP acceleration at any time (mm/s^2); at least `decel_mm_s2`. Default 130000.
    pub max_accel_mm_s2: f64,
    /// Largest TCP speed at any time (mm/s). Default 4600.
    pub max_speed_mm_s: f64,
}

/// Most points of one `DcStopPath`.
pub const DC_MAX_PATH_POINTS: usize = 32;

/// Units of work a protective query spends per tick on the proof along the stop paths until
/// `dc_set_path_work` sets another cap.
pub const DC_DEFAULT_PATH_WORK: u32 = 500;

/// The path one robot's TCP will follow over its stop, as a controller performing a
/// path-maintaining stop knows it (SPEC section 8, "Where the controller knows more"), for
/// `dc_protective_query_with_paths`. It promises that from this tick until the robot stands
/// still its TCP follows the polyline through `points` in order (the point it follows never
/// goes back) and stays within `tolerance_mm` of it. `n_points` 0
/// (with `points` NULL or not): no path known for this robot.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct DcStopPath {
    /// The polyline's vertices in the order the TCP follows them (MCS, mm); the TCP now must
    /// be within `tolerance_mm` of the polyline.
    pub points: *const DcVec3,
    /// How many (0 to `DC_MAX_PATH_POINTS`).
    pub n_points: usize,
    /// How far the TCP may be from the polyline at any moment of the stop (mm, >= 0).
    pub tolerance_mm: f64,
}

/// The inputs of one timed protective query (`dc_protective_query_timed`); start from
/// `dc_protective_request_default()`, which sets `struct_size`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct DcProtectiveRequest {
    /// `sizeof(DcProtectiveRequest)` as the caller compiled it: lets later versions add fields.
    pub struct_size: usize,
    /// What `time` counts: `DC_CLOCK_CYCLE` (the default) or `DC_CLOCK_NANOS`.
    pub clock: DcClock,
    /// The cycle counter, or the timestamp (ns), at which `tcps_mcs` hold.
    pub time: u64,
    /// Robot j's TCP at `time`, in its own MCS: `n_tcps` entries, one per robot.
    pub tcps_mcs: *const DcVec3,
    /// How many TCPs.
    pub n_tcps: usize,
    /// Per robot, the path its stop will follow (as for `dc_protective_query_with_paths`), or
    /// NULL with `n_paths` 0: no paths.
    pub paths: *const DcStopPath,
    /// How many paths: 0, or one per robot.
    pub n_paths: usize,
}

/// Summary of one protective query, written on every call when the pointer is not NULL.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcProtectiveReport {
    /// Same value as `*out_verdict`: `DC_VERDICT_FREE`, `DC_VERDICT_WARN` or `DC_VERDICT_STOP`.
    pub verdict: DcVerdict,
    /// Bit j set: robot j's TCP is not finite, unreachable or moved implausibly.
    pub unreachable_mask: u32,
    /// Signed clearance of the cell now (mm, SPEC section 8): over the box pairs of robots that can
    /// meet, the smallest gap when apart, minus the penetration depth when boxes intersect,
    /// 0 when touching; NaN when not computed (status not OK). Exact in table mode too.
    pub clearance_mm: f64,
    /// Closest box pair now: robots and boxes, or `DC_BOX_NONE`.
    pub closest_robot_a: u32,
    /// See `closest_robot_a`.
    pub closest_robot_b: u32,
    /// See `closest_robot_a`.
    pub closest_box_a: u32,
    /// See `closest_robot_a`.
    pub closest_box_b: u32,
    /// A box pair not proved apart over a stop (STOP) or not with `warn_mm` to spare (WARN):
    /// robots and boxes, or `DC_BOX_NONE`. The closest pair now when that one is certain to
    /// stay unproved, else the first such pair in the order of the robots and boxes.
    pub limiting_robot_a: u32,
    /// See `limiting_robot_a`.
    pub limiting_robot_b: u32,
    /// See `limiting_robot_a`.
    pub limiting_box_a: u32,
    /// See `limiting_robot_a`.
    pub limiting_box_b: u32,
    /// Number of entries used in the arrays below (the cell's robots).
    pub n_robots: u32,
    /// Per robot: how far its TCP may travel until it stands still after a stop now (mm).
    pub protective_mm: [f64; 32],
    /// Per robot: the largest measured TCP speed (mm/s) at which FREE would still hold, the
    /// other robots as they are; 0 when not even standing still is proved; NaN when the
    /// handle's speed limits are off (`dc_set_speed_limits`).
    pub speed_limit_mm_s: [f64; 32],
}

impl DcProtectiveReport {
    pub(crate) const STOP: DcProtectiveReport = DcProtectiveReport {
        verdict: DC_VERDICT_STOP,
        unreachable_mask: 0,
        clearance_mm: f64::NAN,
        closest_robot_a: DC_BOX_NONE,
        closest_robot_b: DC_BOX_NONE,
        closest_box_a: DC_BOX_NONE,
        closest_box_b: DC_BOX_NONE,
        limiting_robot_a: DC_BOX_NONE,
        limiting_robot_b: DC_BOX_NONE,
        limiting_box_a: DC_BOX_NONE,
        limiting_box_b: DC_BOX_NONE,
        n_robots: 0,
        protective_mm: [0.0; 32],
        speed_limit_mm_s: [0.0; 32],
    };
}

/// Most points of one `DcProgramme`.
pub const DC_MAX_PROGRAMME_POINTS: u32 = 4096;

/// One robot's programme ahead for `dc_coordinate` (SPEC section 9): its set-points at the
/// nominal timing, as its path planner has them, and how far along it the robot is. Point `k`
/// is the set-point of programme tick `first_tick + k * stride_ticks`; between two points the
/// robot moves on the straight line.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct DcProgramme {
    /// The programme tick of the first point: a multiple of `stride_ticks`.
    pub first_tick: u64,
    /// Programme ticks between two points (at least 1).
    pub stride_ticks: u32,
    /// How many points (1 to `DC_MAX_PROGRAMME_POINTS`); the robot stands at the last one
    /// when its programme ends there. Give at least its longest stop's worth.
    pub n_points: u32,
    /// `n_points * 3` numbers: x, y, z of each point in the robot's MCS (mm).
    pub points: *const f64,
    /// The robot's progress now, in programme ticks: from `first_tick` to the last point's
    /// tick (at full speed one programme tick per controller tick).
    pub progress: f64,
    /// The override the robot followed over the last tick, in [0, 1] (0 when it stands).
    pub override_now: f64,
}

/// The inputs of `dc_coordinate`; start from `dc_coordination_request_default()`, which sets
/// `struct_size`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct DcCoordinationRequest {
    /// `sizeof(DcCoordinationRequest)` as the caller compiled it: lets later versions add fields.
    pub struct_size: u32,
    /// How many programmes: one per robot of the cell.
    pub n_robots: u32,
    /// Robot j's programme ahead is `programmes[j]`.
    pub programmes: *const DcProgramme,
}

/// What `dc_coordinate` answers for one robot.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcRobotCoordination {
    /// The override to apply over the next tick, in [0, 1] (the same as `out_overrides[j]`).
    pub override_factor: f64,
    /// The robot it yields to (whose conflict sets its hold point), or -1 for none.
    pub held_by: i32,
    /// Arc length from the TCP now to the hold point (mm); `INFINITY` when not held.
    pub hold_mm: f64,
    /// Its place in this tick's ranking (0: yields in no conflict; it may still stand short
    /// of where another robot can be until that one stands).
    pub rank: u32,
}

impl DcRobotCoordination {
    /// What every robot gets on an error: stand, held by no one.
    pub(crate) const STAND: DcRobotCoordination =
        DcRobotCoordination { override_factor: 0.0, held_by: -1, hold_mm: 0.0, rank: 0 };
}

/// One kind of call's figures in `DcTickStats`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcCallStats {
    /// Calls counted.
    pub calls: u64,
    /// Time of the last call inside the library (ns).
    pub last_ns: u64,
    /// Time of the longest call (ns).
    pub largest_ns: u64,
    /// Mean time of the calls counted (ns; 0 without calls).
    pub mean_ns: u64,
    /// Work units of the last call (`dc_tick_stats`).
    pub last_work: u64,
    /// Work units of the call with the most.
    pub largest_work: u64,
    /// Calls that used their whole work budget.
    pub budget_spent: u64,
}

/// A handle's tick statistics (`dc_tick_stats`): set `struct_size` to
/// `sizeof(DcTickStats)` before the call.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcTickStats {
    /// `sizeof(DcTickStats)` of the caller's header; written back as this library's.
    pub struct_size: u32,
    /// `dc_query`.
    pub query: DcCallStats,
    /// `dc_protective_query`, `dc_protective_query_with_paths`, `dc_protective_query_timed`.
    pub protective: DcCallStats,
    /// `dc_coordinate`.
    pub coordinate: DcCallStats,
}
