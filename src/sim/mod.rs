//! The closed-loop benchmark (SPEC §9): seeded dense pick-and-place programmes for any cell
//! (`programme.rs`), a controller that follows them tick by tick with the library in the loop
//! (`run.rs`), the vendor-style zone interlock as a baseline (`interlock.rs`), and the
//! figures of a run: throughput kept, STOP events, deadlocks, contacts, per-tick times beside
//! the exact check's in the same loop.
//!
//! Evaluation only (feature `sim`, which the CLI turns on): the controller's library does not
//! need it.

pub mod cells;
pub mod interlock;
pub mod programme;
pub mod rng;
pub mod run;

use crate::coord::CoordinationConfig;
use crate::math::Real;
pub use programme::{programmes, ProgrammeConfig, Programmes};
pub use rng::Rng;

/// What the controller applies as each robot's override.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The programme as it is (override 1); the protective verdict may stop it.
    Free,
    /// The protective verdict's speed limits as a speed cap (`c_harness/speed_override.c`).
    Limits,
    /// The zone interlock (`interlock.rs`).
    Interlock,
    /// The coordination (`coord`), each override capped by the speed limits as in `Limits`,
    /// with the same release in turn.
    Coordinate,
}

impl Mode {
    /// Every mode, in the order of the reports.
    pub const ALL: [Mode; 4] = [Mode::Free, Mode::Limits, Mode::Interlock, Mode::Coordinate];

    /// The name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Free => "free",
            Mode::Limits => "limits",
            Mode::Interlock => "interlock",
            Mode::Coordinate => "coordinate",
        }
    }
}

/// A run's settings.
#[derive(Clone, Copy, Debug)]
pub struct SimConfig {
    /// What the override comes from.
    pub mode: Mode,
    /// Whether the protective verdict gets each robot's programme ahead as its stop path.
    pub paths: bool,
    /// The coordination's settings (its clearance also sets the interlock's zones).
    pub coordination: CoordinationConfig,
    /// The protective verdict's `warn_mm`.
    pub warn_mm: Real,
    /// Programme ticks between the set-points passed to the coordination.
    pub stride_ticks: u32,
    /// How long a stop path the protective verdict gets (mm).
    pub path_length_mm: Real,
    /// A run that has not finished after this many times its programmed ticks ends.
    pub max_ticks_factor: Real,
    /// Units of work the protective verdict may spend per tick along the stop paths
    /// ([`ProtectiveChecker::with_path_work`](crate::cell::protective::ProtectiveChecker)).
    pub path_work: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            mode: Mode::Coordinate,
            paths: true,
            coordination: CoordinationConfig::default(),
            warn_mm: 5.0,
            stride_ticks: 4,
            path_length_mm: 400.0,
            max_ticks_factor: 4.0,
            path_work: crate::cell::protective::DEFAULT_PATH_WORK,
        }
    }
}

/// Median, 99th percentile and largest of a sample (ns).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Median.
    pub median: u64,
    /// 99th percentile.
    pub p99: u64,
    /// Largest.
    pub max: u64,
}

impl Timings {
    /// The figures of `sample` (sorted in place).
    pub fn of(sample: &mut [u64]) -> Self {
        if sample.is_empty() {
            return Timings::default();
        }
        sample.sort_unstable();
        let max = sample[sample.len() - 1];
        Timings { median: percentile(sample, 0.5), p99: percentile(sample, 0.99), max }
    }
}

/// The value at quantile `q` of a sorted, non-empty sample: the nearest rank.
pub fn percentile(sorted: &[u64], q: Real) -> u64 {
    sorted[((sorted.len() - 1) as Real * q).round() as usize]
}

/// The figures of one run (SPEC §9 defines them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunMetrics {
    /// The longest programme's ticks.
    pub programmed_ticks: usize,
    /// Ticks the run took (to finish, or until it ended).
    pub ticks: usize,
    /// Whether every programme finished.
    pub finished: bool,
    /// Programmed ticks over the ticks taken (0 when unfinished).
    pub throughput: Real,
    /// Ticks at which a STOP was issued to moving robots.
    pub stop_events: usize,
    /// Whether the robots together travelled under 1 mm in 3 s with a programme unfinished.
    pub deadlock: bool,
    /// Ticks at which two robots' boxes intersect.
    pub contact_ticks: usize,
    /// Samples of simulated stops at which two robots' boxes intersect.
    pub contact_stop_samples: usize,
    /// Ticks answered FREE, WARN and STOP.
    pub verdicts: [usize; 3],
    /// Per tick, the coordination and the protective verdict together.
    pub ours_ns: Timings,
    /// Per tick, the coordination alone.
    pub coordination_ns: Timings,
    /// Per tick, the exact check in the same loop.
    pub exact_ns: Timings,
    /// The most diagram cells one call tested.
    pub cells_tested_max: u64,
    /// The most units of work one protective call spent along the stop paths.
    pub path_work_max: u32,
    /// Protective calls that ran out of their work along the paths.
    pub path_work_spent: usize,
}
