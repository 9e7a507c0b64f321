//! The coordination calls of the `c_abi` target (`Op::Coordinate`, `Op::CoordinationSettings`):
//! `dc_coordinate` with programmes whose counts, strides, first ticks, progress, overrides and
//! points come from the input (NaN, infinities and huge values among them, point counts of 0
//! and above `DC_MAX_PROGRAMME_POINTS`), or with the handle's last answered programmes one
//! tick on as a controller follows them; its reset and clearance.

use super::{handle_of, null_if, pick, Input, Live};
use delta_collide::ffi::*;
use std::mem::size_of;

/// Distinct points read per programme at most; a longer programme repeats its last one (the
/// robot stands there), so that counts up to `DC_MAX_PROGRAMME_POINTS + 1` cost no input.
const READ_POINTS: u32 = 48;

/// What an output holds until the call writes it: no override (they lie in [0, 1]) nor
/// robot answer is this.
const UNWRITTEN: f64 = 7.0;
const UNWRITTEN_ROBOT: DcRobotCoordination =
    DcRobotCoordination { override_factor: UNWRITTEN, held_by: 7, hold_mm: 7.0, rank: 7 };

/// Every status `dc_coordinate` documents, but BUSY (one thread here) and PANIC (a bug).
const STATUSES: [DcStatus; 7] = [
    DC_STATUS_OK,
    DC_STATUS_NULL_POINTER,
    DC_STATUS_INVALID_ARGUMENT,
    DC_STATUS_WRONG_ROBOT_COUNT,
    DC_STATUS_INVALID_PROGRAMME,
    DC_STATUS_NON_FINITE,
    DC_STATUS_PROGRESS_OUT_OF_RANGE,
];

/// One robot's programme as the input gave it; `points` holds `3 * n_points` numbers (also
/// above the maximum: the contract wants them readable even where they are refused).
#[derive(Clone, Debug)]
pub(super) struct Programme {
    first_tick: u64,
    stride_ticks: u32,
    n_points: u32,
    points: Vec<f64>,
    progress: f64,
    override_now: f64,
}

impl Programme {
    /// Stride (byte % 8: 0, 1, 1 + byte, a `u32`, `u32::MAX`), first tick (byte % 4: 0, a
    /// `u16` multiple of the stride, a `u64`, the last multiple below `u64::MAX`, whose
    /// second point's tick overflows), point count (byte: 254 the maximum, 255 one above,
    /// else byte % 48), up to [`READ_POINTS`] points, progress (byte % 8: any `f64`, three
    /// fractions byte / 255 of the span, the first tick, the last, 1 to 4 strides before the
    /// first, 1 + byte after the last), override_now (byte % 4: any `f64`, 1, byte / 255, 0).
    fn read(input: &mut Input) -> Programme {
        let stride_ticks = match input.byte() % 8 {
            0 => 0,
            1 => 1,
            2..=5 => 1 + u32::from(input.byte()),
            6 => input.u32(),
            _ => u32::MAX,
        };
        let stride = u64::from(stride_ticks.max(1));
        let first_tick = match input.byte() % 4 {
            0 => 0,
            1 => stride * u64::from(u16::from_le_bytes(input.bytes())),
            2 => input.u64(),
            _ => u64::MAX - u64::MAX % stride,
        };
        let n_points = match input.byte() {
            254 => DC_MAX_PROGRAMME_POINTS,
            255 => DC_MAX_PROGRAMME_POINTS + 1,
            b => u32::from(b % 48),
        };
        let mut points = Vec::with_capacity(3 * n_points as usize);
        for _ in 0..n_points.min(READ_POINTS) {
            points.extend(input.point());
        }
        while points.len() < 3 * n_points as usize {
            let last: [f64; 3] = points[points.len() - 3..].try_into().unwrap();
            points.extend(last);
        }
        // The ticks in floating point, as the library compares the progress with them.
        let first = first_tick as f64;
        let last = first + f64::from(stride_ticks) * f64::from(n_points.saturating_sub(1));
        let progress = match input.byte() % 8 {
            0 => input.f64(),
            1..=3 => first + (last - first) * f64::from(input.byte()) / 255.0,
            4 => first,
            5 => last,
            6 => first - f64::from(stride_ticks) * f64::from(1 + input.byte() % 4),
            _ => last + 1.0 + f64::from(input.byte()),
        };
        let override_now = match input.byte() % 4 {
            0 => input.f64(),
            1 => 1.0,
            2 => f64::from(input.byte()) / 255.0,
            _ => 0.0,
        };
        Programme { first_tick, stride_ticks, n_points, points, progress, override_now }
    }

    /// The last point's tick in floating point (the library's bound on the progress).
    fn last_tick(&self) -> f64 {
        self.first_tick as f64
            + f64::from(self.stride_ticks) * f64::from(self.n_points.saturating_sub(1))
    }

    /// The status the contract gives this programme in the library's order of checks, with
    /// `null_points` its points NULL: the count and the NULL first ([`Programme::early`]),
    /// then the ticks, the numbers, the range ([`Programme::late`]). `None`: it passes.
    fn early(&self, null_points: bool) -> Option<DcStatus> {
        if self.n_points == 0 || self.n_points > DC_MAX_PROGRAMME_POINTS {
            Some(DC_STATUS_INVALID_PROGRAMME)
        } else if null_points {
            Some(DC_STATUS_NULL_POINTER)
        } else {
            None
        }
    }

    /// The checks after every programme's count and pointer passed (so `n_points >= 1`).
    fn late(&self) -> Option<DcStatus> {
        let stride = u64::from(self.stride_ticks);
        let ticks_fit = stride != 0
            && self.first_tick % stride == 0
            && self.first_tick.checked_add(stride * u64::from(self.n_points - 1)).is_some();
        let finite = self.progress.is_finite()
            && self.override_now.is_finite()
            && self.points.iter().all(|v| v.is_finite());
        let within = self.progress >= self.first_tick as f64
            && self.progress <= self.last_tick()
            && (0.0..=1.0).contains(&self.override_now);
        if !ticks_fit {
            Some(DC_STATUS_INVALID_PROGRAMME)
        } else if !finite {
            Some(DC_STATUS_NON_FINITE)
        } else if !within {
            Some(DC_STATUS_PROGRESS_OUT_OF_RANGE)
        } else {
            None
        }
    }
}

/// A handle's last answered `dc_coordinate` call: its programmes and overrides.
#[derive(Clone, Debug)]
pub(super) struct Coordinated {
    programmes: Vec<Programme>,
    overrides: Vec<f64>,
}

impl Coordinated {
    /// Its programmes one tick on as a controller follows the overrides: each progress
    /// advanced by its override (within its last tick), which is the next `override_now`.
    fn next(&self) -> Vec<Programme> {
        let mut next = self.programmes.clone();
        for (p, &o) in next.iter_mut().zip(&self.overrides) {
            p.progress = (p.progress + o).min(p.last_tick());
            p.override_now = o;
        }
        next
    }
}

/// The request as read through a `struct_size` up to its size plus 16: what a later version's
/// larger struct would hold beyond it is readable, as the contract wants.
#[repr(C)]
#[derive(Debug)]
struct Padded {
    request: DcCoordinationRequest,
    later: [u64; 2],
}

/// `Op::Coordinate` (encoding in [`super::Op`]): the status names the cause in the order the
/// library checks, its outputs are written exactly as the documentation says (on an error
/// every override 0.0 and every robot standing, held by no one; on OK every override in
/// [0, 1] and the robots' answers consistent), and nothing past them.
pub(super) fn coordinate(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    let robots = l.map_or(0, |l| l.robots.len());
    let last = l.and_then(|l| l.coordinated.borrow().clone());
    let programmes: Vec<Programme> = match (input.flag(), &last) {
        (true, Some(last)) => last.next(),
        _ => {
            let count = match input.byte() {
                b @ 192.. => usize::from(b % 40),
                _ => robots,
            };
            (0..count).map(|_| Programme::read(input)).collect()
        }
    };
    let n = programmes.len();
    let size = size_of::<DcCoordinationRequest>();
    // Right, none, `struct_size` alone, short of `programmes` (`n_robots` still readable: the
    // outputs are written), a byte short, a later version's.
    let struct_size = match input.byte() % 8 {
        0..=2 => size,
        3 => 0,
        4 => 4,
        5 => 8,
        6 => size - 1,
        _ => size_of::<Padded>(),
    };
    // NULL flags: request, programmes, out_overrides, out_robots, the first programme's points,
    // the last one's.
    let nulls = input.byte();
    let null_points = |j: usize| (nulls & 16 != 0 && j == 0) || (nulls & 32 != 0 && j + 1 == n);
    let c_programmes: Vec<DcProgramme> = programmes
        .iter()
        .enumerate()
        .map(|(j, p)| DcProgramme {
            first_tick: p.first_tick,
            stride_ticks: p.stride_ticks,
            n_points: p.n_points,
            points: if null_points(j) { std::ptr::null() } else { p.points.as_ptr() },
            progress: p.progress,
            override_now: p.override_now,
        })
        .collect();
    let padded = Padded {
        request: DcCoordinationRequest {
            struct_size: struct_size as u32,
            n_robots: n as u32,
            programmes: if nulls & 2 != 0 { std::ptr::null() } else { c_programmes.as_ptr() },
        },
        later: [u64::MAX; 2],
    };
    let req: *const DcCoordinationRequest =
        if nulls & 1 != 0 { std::ptr::null() } else { &padded.request };
    // Two more of each output than the call may write: what lies past `n_robots` stays.
    let mut overrides = vec![UNWRITTEN; n + 2];
    let mut answers = vec![UNWRITTEN_ROBOT; n + 2];
    // SAFETY: the handle is NULL or live; the request is NULL or readable for its
    // `struct_size` (at most `size_of::<Padded>()`), its programmes hold `n_robots` entries
    // whose points are NULL or hold `3 * n_points` numbers; each output is NULL or holds
    // `n_robots` writable elements.
    let status = unsafe {
        dc_coordinate(
            handle_of(l),
            req,
            null_if(nulls & 4 != 0, overrides.as_mut_ptr()),
            null_if(nulls & 8 != 0, answers.as_mut_ptr()),
        )
    };
    assert_ne!(status, DC_STATUS_PANIC, "dc_coordinate panicked");
    assert!(STATUSES.contains(&status), "dc_coordinate: status {status}");
    // How many elements of each output the call writes: `n_robots` (at most `DC_MAX_ROBOTS`)
    // wherever the request holds it, on errors too.
    let written = if nulls & 1 == 0 && struct_size >= 8 { n.min(DC_MAX_ROBOTS) } else { 0 };
    let (overrides_out, answers_out) = (nulls & 4 == 0, nulls & 8 == 0);
    if status == DC_STATUS_OK {
        assert!(overrides_out && written == n && n == robots, "OK for {n} of {robots} robots");
        for (j, &o) in overrides[..n].iter().enumerate() {
            assert!((0.0..=1.0).contains(&o), "robot {j}: override {o}, {programmes:?}");
        }
        if answers_out {
            for (j, r) in answers[..n].iter().enumerate() {
                assert!(
                    r.override_factor.to_bits() == overrides[j].to_bits()
                        && (r.held_by == -1 || (0..n as i32).contains(&r.held_by))
                        && r.held_by != j as i32
                        && (r.rank as usize) < n
                        && r.hold_mm >= 0.0,
                    "robot {j}: {r:?} with override {}",
                    overrides[j]
                );
            }
        }
    } else {
        if overrides_out {
            let zero = overrides[..written].iter().all(|o| o.to_bits() == 0.0f64.to_bits());
            assert!(zero, "status {status}: overrides {:?}", &overrides[..written]);
        }
        if answers_out {
            let stand = answers[..written].iter().all(|r| {
                (r.override_factor.to_bits(), r.held_by, r.hold_mm.to_bits(), r.rank)
                    == (0.0f64.to_bits(), -1, 0.0f64.to_bits(), 0)
            });
            assert!(stand, "status {status}: robots {:?}", &answers[..written]);
        }
    }
    let written_ok = if status == DC_STATUS_OK { n } else { written };
    assert!(
        overrides[written_ok..].iter().all(|o| *o == UNWRITTEN)
            && (!overrides_out || written_ok == 0 || overrides[0] != UNWRITTEN),
        "{written_ok} overrides written: {overrides:?}"
    );
    let answers_kept = answers[written_ok..].iter().all(|r| *r == UNWRITTEN_ROBOT);
    assert!(answers_kept, "{written_ok} robots written: {:?}", &answers[written_ok..]);
    assert_eq!(status, expected(l, struct_size, nulls, &programmes, null_points), "{padded:?}");
    if let (DC_STATUS_OK, Some(l)) = (status, l) {
        let overrides = overrides[..n].to_vec();
        *l.coordinated.borrow_mut() = Some(Coordinated { programmes, overrides });
    }
}

/// The status `dc_coordinate` documents for the call, in the order it checks: the handle,
/// the request and `out_overrides`, `struct_size`, the programmes array, the robot count, each
/// programme's count and points pointer, then each programme's ticks and numbers.
fn expected(
    l: Option<&Live>,
    struct_size: usize,
    nulls: u8,
    programmes: &[Programme],
    null_points: impl Fn(usize) -> bool,
) -> DcStatus {
    let Some(l) = l else { return DC_STATUS_NULL_POINTER };
    if nulls & 5 != 0 {
        return DC_STATUS_NULL_POINTER;
    }
    if struct_size < size_of::<DcCoordinationRequest>() {
        return DC_STATUS_INVALID_ARGUMENT;
    }
    if nulls & 2 != 0 {
        return DC_STATUS_NULL_POINTER;
    }
    if programmes.len() != l.robots.len() {
        return DC_STATUS_WRONG_ROBOT_COUNT;
    }
    let early = programmes.iter().enumerate().find_map(|(j, p)| p.early(null_points(j)));
    early.or_else(|| programmes.iter().find_map(Programme::late)).unwrap_or(DC_STATUS_OK)
}

/// `Op::CoordinationSettings`: `dc_coordination_reset` (NULL a no-op),
/// `dc_set_coordination_clearance` (OK for a finite clearance above 0) or
/// `dc_set_coordination_right_of_way` (OK for `DC_RIGHT_OF_WAY_ARRIVAL` or `_PROGRAMMED`),
/// else `DC_STATUS_INVALID_ARGUMENT` with a message in `dc_last_init_error`, cleared on
/// success; then `dc_tick_stats` (its struct size checked) and `dc_coordination_horizon` and
/// `dc_coordination_request_default`, which take nothing.
pub(super) fn settings(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    let (status, expected, what) = match input.byte() % 4 {
        0 => {
            // SAFETY: NULL or live.
            unsafe { dc_coordination_reset(handle_of(l)) };
            (DC_STATUS_OK, DC_STATUS_OK, String::new())
        }
        3 => {
            let rule = DcRightOfWay::from(input.byte() % 4);
            // SAFETY: NULL or live.
            let status = unsafe { dc_set_coordination_right_of_way(handle_of(l), rule) };
            let valid = rule == DC_RIGHT_OF_WAY_ARRIVAL || rule == DC_RIGHT_OF_WAY_PROGRAMMED;
            (status, setter_status(l, valid), format!("dc_set_coordination_right_of_way({rule})"))
        }
        b => {
            let mm = if b == 1 { input.f64() } else { f64::from(input.byte()) };
            // SAFETY: NULL or live.
            let status = unsafe { dc_set_coordination_clearance(handle_of(l), mm) };
            let valid = mm > 0.0 && mm.is_finite();
            (status, setter_status(l, valid), format!("dc_set_coordination_clearance({mm})"))
        }
    };
    assert_eq!(status, expected, "{what}");
    if l.is_some() && !what.is_empty() {
        // SAFETY: NULL and 0 ask for the length only.
        let len = unsafe { dc_last_init_error(std::ptr::null_mut(), 0) };
        assert_eq!(len == 0, status == DC_STATUS_OK, "status {status}, {len}-byte error");
    }
    // The tick statistics: any handle, a struct size too small or right.
    let full = size_of::<DcTickStats>() as u32;
    let size = if input.byte() % 2 == 0 { full } else { full - 8 };
    let mut stats = DcTickStats { struct_size: size, ..Default::default() };
    // SAFETY: NULL or live; `stats` writable.
    let status = unsafe { dc_tick_stats(handle_of(l), &mut stats) };
    let expected = match (l, size == full) {
        (None, _) => DC_STATUS_NULL_POINTER,
        (_, true) => DC_STATUS_OK,
        _ => DC_STATUS_INVALID_ARGUMENT,
    };
    assert_eq!(status, expected, "dc_tick_stats with struct_size {size}");
    let c = stats.coordinate;
    assert!(c.largest_ns >= c.last_ns && c.largest_work >= c.last_work, "{stats:?}");
    // A property of the build: the point at or behind the progress at least.
    assert!(dc_coordination_horizon() >= 1, "horizon {}", dc_coordination_horizon());
    let d = dc_coordination_request_default();
    assert!(
        d.struct_size as usize == size_of::<DcCoordinationRequest>()
            && d.n_robots == 0
            && d.programmes.is_null(),
        "{d:?}"
    );
}

/// The status of a setter on handle `l` (NULL when `None`) with a `valid` argument.
fn setter_status(l: Option<&Live>, valid: bool) -> DcStatus {
    match (l, valid) {
        (None, _) => DC_STATUS_NULL_POINTER,
        (_, true) => DC_STATUS_OK,
        _ => DC_STATUS_INVALID_ARGUMENT,
    }
}
