//! The workload of the `no_std` table check (README "Without an operating system"), compiled
//! twice from this one file: into `consumer.rs` against the `--no-default-features` build
//! (maths from libm) and into `tests/portability.rs` against the std build. Both load the
//! same table bytes for cell T1, answer the same generated configurations with
//! [`TableChecker`] and summarise the answers; the test requires equal summaries.

use alloc::vec;
use delta_collide::cell::{Cell, Placement, RobotSpec, SatMethod};
use delta_collide::math::Vec3;
use delta_collide::robot::RobotModel;
use delta_collide::table::{TableAnswer, TableChecker, TableError};

/// What one run saw. `#[repr(C)]`: the consumer returns it to `driver.c` by value.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// 0 when the table loaded, else 1 + the [`TableError`] variant's position.
    pub status: u32,
    /// Answers by kind.
    pub free: u32,
    /// Collision answers.
    pub collision: u32,
    /// Unreachable answers (either robot).
    pub unreachable: u32,
    /// Queries answered by the exact fallback (TCP outside the sampled grid).
    pub fallbacks: u32,
    /// FNV-1a over the answers in order (0 free, 1 collision, 2 + mask unreachable, 255 error).
    pub hash: u64,
    /// Allocations made by the queries (the load excluded); the caller counts them.
    pub query_allocs: u32,
}

/// Cell T1 of SPEC §5 in code (`cells/t1.toml` needs the std-only TOML reader): two thesis
/// robots, B at (450, 0, 0).
pub fn cell_t1() -> Cell {
    let robot = |name: &str, t: Vec3| RobotSpec {
        name: name.into(),
        model: RobotModel::THESIS,
        placement: Placement { alpha: 0.0, t },
    };
    let robots = vec![robot("A", Vec3::zeros()), robot("B", Vec3::new(450.0, 0.0, 0.0))];
    Cell::new("T1".into(), robots, SatMethod::SatCache).expect("T1 is a valid cell")
}

fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Configuration `i` of `seed`: each TCP in its own MCS, x and y in [-230, 230] mm, z in
/// [-535, -345] mm. That box holds collisions, free pairs, unreachable TCPs and reachable
/// TCPs above the sampled workspace (answered by the exact fallback): on T1 at k = 16 about
/// 40 % table lookups, 20 % fallbacks, 40 % unreachable.
pub fn configuration(seed: u64, i: u32) -> [Vec3; 2] {
    let mut state = splitmix(seed ^ u64::from(i) << 32);
    let mut unit = || {
        state = splitmix(state);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut tcp =
        || Vec3::new(460.0 * unit() - 230.0, 460.0 * unit() - 230.0, -345.0 - 190.0 * unit());
    [tcp(), tcp()]
}

fn error_code(e: &TableError) -> u32 {
    match e {
        TableError::Truncated { .. } => 1,
        TableError::BadMagic { .. } => 2,
        TableError::UnsupportedVersion { .. } => 3,
        TableError::WrongEndianness => 4,
        TableError::Corrupt { .. } => 5,
        TableError::WrongCell { .. } => 6,
        TableError::BadInput { .. } => 7,
        TableError::MissingPair { .. } => 8,
        TableError::WrongPair { .. } => 9,
    }
}

/// Loads `bytes` for T1 and answers configurations `0..n` of `seed`; `allocations` reads the
/// caller's allocation counter (or 0 where it has none).
pub fn run(bytes: &[u8], seed: u64, n: u32, allocations: impl Fn() -> u64) -> Summary {
    let mut checker = match TableChecker::new(cell_t1(), bytes) {
        Ok(c) => c,
        Err(e) => return Summary { status: 1 + error_code(&e), ..Summary::default() },
    };
    let mut s = Summary { hash: 0xcbf2_9ce4_8422_2325, ..Summary::default() };
    let before = allocations();
    for i in 0..n {
        let code = match checker.check(&configuration(seed, i)) {
            Ok(TableAnswer::Free) => {
                s.free += 1;
                0
            }
            Ok(TableAnswer::Collision) => {
                s.collision += 1;
                1
            }
            Ok(TableAnswer::Unreachable(mask)) => {
                s.unreachable += 1;
                2 + mask as u8
            }
            Err(_) => 255,
        };
        s.hash = (s.hash ^ u64::from(code)).wrapping_mul(0x0100_0000_01b3);
    }
    s.query_allocs = (allocations() - before) as u32;
    s.fallbacks = checker.fallbacks() as u32;
    s
}
