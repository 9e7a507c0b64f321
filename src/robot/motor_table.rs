//! A precomputed table of certified motor-angle enclosures over a robot's TCP space, for the
//! protective verdict's per-tick sweeps (SPEC §8 "Link points outrun the TCP"; the interval
//! inverse kinematics of `robot::motion_bound`, thesis 3.2.7).
//!
//! # What it answers
//! [`MotorTable::enclose`] returns, per arm, an interval holding the elbow-out motor angle of
//! every reachable TCP of an axis-aligned box `[lo, hi]` (MCS): the meaning of
//! [`theta_range`], at the cost of 8 table reads per arm instead of `splits^3` interval
//! inverse kinematics.
//!
//! # Why it is a proof
//! 1. **Cells.** Space is cut into closed cubic cells of side [`MOTOR_CELL_MM`] from `origin`.
//!    Each cell's entry is [`theta_range`] over the cell widened by [`CELL_SLACK`] (one
//!    sub-box), rounded outward to `f32` (the lower end down, the upper end up). An empty
//!    enclosure (no reachable TCP) is stored as `[+inf, -inf]`, an unbounded one as
//!    `[-inf, +inf]`.
//! 2. **Blocks.** Level `k` holds, for every cell offset, the hull of the cells of the cube of
//!    `2^k` cells per axis starting there; it is the hull of 8 blocks of level `k - 1`
//!    (`min`/`max` of `f32`, exact). So a block's entry holds the angle of every reachable TCP
//!    in any of its cells.
//! 3. **Cover.** A point `x` of `[lo, hi]` has its computed cell index
//!    `floor((x - origin) / side)` between those of `lo` and `hi` (rounding is monotone); in
//!    exact arithmetic `x` lies in that cell or within far less than [`CELL_SLACK`] of it, so
//!    in the widened cell. The index range is covered by blocks of the largest level that fits
//!    (two per axis when it spans fewer than `2^(k+1)` cells), so the hull of their entries
//!    holds the angle of every reachable TCP of `[lo, hi]`.
//! 4. **Outside.** The table spans every TCP with `|x|, |y| <= |f - e| + rf + re + side` and
//!    `-(rf + re) - side <= z <= 0`. No reachable TCP lies outside: the loop of arm `i` closes
//!    only when `|p + e u_i - F_i| <= rf + re`, i.e. `p + (e - f) u_i` lies in the ball of
//!    radius `rf + re` about the origin (a TCP that the floating-point inverse kinematics
//!    accepts is within far less than a cell of such a point). So the part of a box outside
//!    the table holds no reachable TCP, and the box is clipped to the table.
//! 5. **Fallback.** A box meeting an unbounded cell (`z` up to 0, where the elbow-out formula
//!    changes) gets `None`: the caller then encloses with the interval inverse kinematics.
//!
//! The table is coarser than a direct enclosure for boxes of a few cells (the cover rounds out
//! to whole cells), and tighter for large ones (16 mm cells against `splits^3` sub-boxes of
//! the whole box); [`MotorTable::enclose`] intersects it with one direct interval enclosure
//! of the box when the box spans at most [`DIRECT_CELLS`] cells on an axis (both are sound,
//! so is their intersection).

use super::motion_bound::{theta_range, Enclosure};
use crate::math::interval::Interval;
use crate::math::{Real, Vec3};
use crate::robot::Delta3;
use alloc::vec::Vec;

/// Side of a table cell (mm).
pub const MOTOR_CELL_MM: Real = 16.0;

/// Absolute widening (mm) of each cell before enclosing: covers the rounding of the index
/// computation (about `1e-13` mm here).
pub const CELL_SLACK: Real = 1e-6;

/// Highest level: blocks of `2^MAX_LEVEL` cells per axis (512 mm at 16 mm cells, enough for
/// a cube of side 1 m with two blocks per axis).
pub const MAX_LEVEL: usize = 5;

/// Boxes spanning at most this many cells on some axis are also enclosed directly.
pub const DIRECT_CELLS: i64 = 3;

/// One level: `[lo, hi]` of arms 0, 1, 2 per block, x fastest.
#[derive(Clone, Debug)]
struct Level {
    dims: [usize; 3],
    data: Vec<[f32; 6]>,
}

impl Level {
    #[inline(always)]
    fn at(&self, i: usize, j: usize, l: usize) -> &[f32; 6] {
        &self.data[(l * self.dims[1] + j) * self.dims[0] + i]
    }
}

/// Certified motor-angle enclosures over a grid of TCP cells (module doc).
#[derive(Clone)]
pub struct MotorTable {
    delta: Delta3,
    origin: Vec3,
    side: Real,
    levels: Vec<Level>,
}

impl core::fmt::Debug for MotorTable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("MotorTable")
            .field("origin", &self.origin)
            .field("side", &self.side)
            .field("cells", &self.levels[0].dims)
            .field("levels", &self.levels.len())
            .finish()
    }
}

/// `x` rounded down to an `f32` (NaN to `-inf`).
fn down(x: Real) -> f32 {
    let y = x as f32;
    if x.is_nan() {
        f32::NEG_INFINITY
    } else if (y as Real) > x {
        // The next `f32` toward -inf (`f32::next_down` needs Rust 1.86); `y` is not NaN.
        if y == 0.0 {
            -f32::from_bits(1)
        } else if y > 0.0 {
            f32::from_bits(y.to_bits() - 1)
        } else {
            f32::from_bits(y.to_bits() + 1)
        }
    } else {
        y
    }
}

/// `x` rounded up to an `f32` (NaN to `+inf`).
fn up(x: Real) -> f32 {
    let y = x as f32;
    if x.is_nan() {
        f32::INFINITY
    } else if (y as Real) < x {
        // The next `f32` toward +inf (`f32::next_up` needs Rust 1.86); `y` is not NaN.
        if y == 0.0 {
            f32::from_bits(1)
        } else if y > 0.0 {
            f32::from_bits(y.to_bits() + 1)
        } else {
            f32::from_bits(y.to_bits() - 1)
        }
    } else {
        y
    }
}

const EMPTY: [f32; 6] = [
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
];

fn hull(a: &mut [f32; 6], b: &[f32; 6]) {
    for arm in 0..3 {
        a[2 * arm] = a[2 * arm].min(b[2 * arm]);
        a[2 * arm + 1] = a[2 * arm + 1].max(b[2 * arm + 1]);
    }
}

impl MotorTable {
    /// The table of `delta` over every TCP with `|x|, |y| <= |f - e| + rf + re` and
    /// `-(rf + re) <= z <= 0` (every reachable TCP: `|p + e u_i - F_i| <= rf + re`), in cells
    /// of [`MOTOR_CELL_MM`]. About 0.2 s and 20 MB for the thesis robot.
    pub fn new(delta: &Delta3) -> MotorTable {
        let side = MOTOR_CELL_MM;
        let reach = (delta.f - delta.e).abs() + delta.rf + delta.re;
        let nxy = (reach / side).ceil() as usize + 1;
        let nz = ((delta.rf + delta.re) / side).ceil() as usize + 1;
        let origin = Vec3::new(-(nxy as Real) * side, -(nxy as Real) * side, -(nz as Real) * side);
        let dims = [2 * nxy, 2 * nxy, nz];
        let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for l in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let lo = origin + Vec3::new(i as Real, j as Real, l as Real) * side;
                    let (lo, hi) = (lo.add_scalar(-CELL_SLACK), lo.add_scalar(side + CELL_SLACK));
                    let mut entry = EMPTY;
                    for arm in 0..3 {
                        (entry[2 * arm], entry[2 * arm + 1]) =
                            match theta_range(delta, arm, &lo, &hi, 1) {
                                Enclosure::Empty => (f32::INFINITY, f32::NEG_INFINITY),
                                Enclosure::Unbounded => (f32::NEG_INFINITY, f32::INFINITY),
                                Enclosure::Range(r) => (down(r.lo), up(r.hi)),
                            };
                    }
                    data.push(entry);
                }
            }
        }
        let mut levels = alloc::vec![Level { dims, data }];
        for k in 1..=MAX_LEVEL {
            let below = &levels[k - 1];
            let half = 1usize << (k - 1);
            let size = 1usize << k;
            if dims.iter().any(|&n| n < size) {
                break;
            }
            let d = dims.map(|n| n - size + 1);
            let mut data = Vec::with_capacity(d[0] * d[1] * d[2]);
            for l in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        let mut entry = EMPTY;
                        for c in 0..8 {
                            let o = |a: usize| (c >> a & 1) * half;
                            hull(&mut entry, below.at(i + o(0), j + o(1), l + o(2)));
                        }
                        data.push(entry);
                    }
                }
            }
            levels.push(Level { dims: d, data });
        }
        MotorTable { delta: *delta, origin, side, levels }
    }

    /// The robot the table was built for.
    pub fn delta(&self) -> &Delta3 {
        &self.delta
    }

    /// Bytes held by the table.
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.data.len() * core::mem::size_of::<[f32; 6]>()).sum()
    }

    /// Per arm, an enclosure of the motor angle of every reachable TCP of the box
    /// `[lo, hi]` (MCS; module doc); `None` when the box leaves the table or meets an
    /// unbounded cell. No allocation.
    pub fn enclose(&self, lo: &Vec3, hi: &Vec3) -> Option<[Enclosure; 3]> {
        let index = |x: Real, a: usize| ((x - self.origin[a]) / self.side).floor();
        let mut first = [0usize; 3];
        let mut last = [0usize; 3];
        let mut span = i64::MAX;
        for a in 0..3 {
            let (i0, i1) = (index(lo[a], a), index(hi[a], a));
            let top = (self.levels[0].dims[a] - 1) as Real;
            // Also true for NaN.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(i0 <= i1) {
                return None;
            }
            if i1 < 0.0 || i0 > top {
                // Wholly outside the table: no reachable TCP (module doc, step 4).
                return Some([Enclosure::Empty; 3]);
            }
            (first[a], last[a]) = (i0.max(0.0) as usize, i1.min(top) as usize);
            span = span.min((last[a] - first[a] + 1) as i64);
        }
        let k = (63 - span.leading_zeros() as usize).min(self.levels.len() - 1);
        let (level, size) = (&self.levels[k], 1usize << k);
        // Block starts per axis: from `first` every `size` cells, the last one ending at `last`.
        let starts = |a: usize, out: &mut [usize; 8]| {
            let mut n = 0;
            let end = last[a] + 1 - size;
            let mut s = first[a];
            while s < end && n < 7 {
                out[n] = s;
                n += 1;
                s += size;
            }
            out[n] = end;
            n + 1
        };
        let (mut sx, mut sy, mut sz) = ([0; 8], [0; 8], [0; 8]);
        let (nx, ny, nz) = (starts(0, &mut sx), starts(1, &mut sy), starts(2, &mut sz));
        // More than 8 blocks per axis would be needed only past the top level's reach.
        if (nx == 8 && sx[6] + size < sx[7])
            || (ny == 8 && sy[6] + size < sy[7])
            || (nz == 8 && sz[6] + size < sz[7])
        {
            return None;
        }
        let mut entry = EMPTY;
        for &l in &sz[..nz] {
            for &j in &sy[..ny] {
                for &i in &sx[..nx] {
                    hull(&mut entry, level.at(i, j, l));
                }
            }
        }
        let mut out = [Enclosure::Empty; 3];
        for arm in 0..3 {
            let (a, b) = (entry[2 * arm], entry[2 * arm + 1]);
            if a == f32::NEG_INFINITY || b == f32::INFINITY {
                return None;
            }
            if a <= b {
                out[arm] = Enclosure::Range(Interval::new(a as Real, b as Real));
            }
        }
        if span <= DIRECT_CELLS {
            for (arm, slot) in out.iter_mut().enumerate() {
                *slot = slot.intersect(theta_range(&self.delta, arm, lo, hi, 1));
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, RngExt, SeedableRng};

    #[test]
    fn outward_rounding_brackets_with_adjacent_f32s() {
        for x in
            [1.0 + 1e-10, -1.0 - 1e-10, 1e-50, -1e-50, 0.1, -0.1, 3.4e38 * 1.000_000_1, 2.0, 0.0]
        {
            let (lo, hi) = (down(x), up(x));
            assert!((lo as Real) <= x && x <= hi as Real, "{x}: [{lo}, {hi}]");
            // Equal when `x` is an `f32`, else neighbours: the number line's order is that of
            // the bits for positives and the reverse for negatives.
            let step = |a: f32, b: f32| (a.to_bits() as i64 - b.to_bits() as i64).abs();
            let adjacent = lo == hi
                || (lo.is_sign_positive() == hi.is_sign_positive() && step(lo, hi) == 1)
                || (lo < 0.0 && hi >= 0.0 && step(lo, -0.0) + step(hi, 0.0) <= 1);
            assert!(adjacent, "{x}: [{lo}, {hi}] are not neighbours");
        }
    }

    /// Every sampled reachable TCP of random boxes (small to 600 mm, near the reach boundary
    /// included) has its motor angles inside the table's enclosure, and large boxes get an
    /// enclosure no wider than the direct one with 2^3 sub-boxes more often than not.
    #[test]
    fn enclosures_hold_sampled_angles_of_random_boxes() {
        let d = Delta3::THESIS;
        let table = MotorTable::new(&d);
        let mut rng = StdRng::seed_from_u64(5);
        let (mut tighter, mut compared, mut checked) = (0, 0, 0);
        for _ in 0..3_000 {
            let c = Vec3::new(
                rng.random_range(-450.0..450.0),
                rng.random_range(-450.0..450.0),
                rng.random_range(-850.0..-250.0),
            );
            let h: Real = if rng.random::<bool>() {
                rng.random_range(0.5..20.0)
            } else {
                rng.random_range(20.0..300.0)
            };
            let (lo, hi) = (c.add_scalar(-h), c.add_scalar(h));
            let Some(th) = table.enclose(&lo, &hi) else { continue };
            for q in 0..200 {
                let f = |r: &mut StdRng| if q < 8 { (q & 1) as Real } else { r.random::<Real>() };
                let t = Vec3::new(
                    f(&mut rng),
                    if q < 8 { (q >> 1 & 1) as Real } else { f(&mut rng) },
                    if q < 8 { (q >> 2 & 1) as Real } else { f(&mut rng) },
                );
                let p = lo + (hi - lo).component_mul(&t);
                let Ok(sol) = d.inverse_kinematics(&p) else { continue };
                for arm in 0..3 {
                    let Enclosure::Range(r) = th[arm] else {
                        panic!("{p:?} reachable in a box said empty: {th:?}")
                    };
                    assert!(
                        r.contains(sol.theta[arm]),
                        "arm {arm} {p:?}: {} not in {r:?}",
                        sol.theta[arm]
                    );
                    checked += 1;
                }
            }
            if h > 50.0 {
                if let (Enclosure::Range(a), Enclosure::Range(b)) =
                    (th[0], theta_range(&d, 0, &lo, &hi, 2))
                {
                    compared += 1;
                    tighter += (a.hi - a.lo <= b.hi - b.lo) as usize;
                }
            }
        }
        println!("{checked} angles checked; table no wider than 2^3 sub-boxes in {tighter} of {compared} large boxes; {} bytes", table.bytes());
        assert!(checked > 10_000 && tighter * 2 > compared);
    }

    #[test]
    fn boxes_outside_or_at_z_zero_fall_back() {
        let table = MotorTable::new(&Delta3::THESIS);
        assert!(table
            .enclose(&Vec3::new(-10.0, -10.0, -20.0), &Vec3::new(10.0, 10.0, 5.0))
            .is_none());
        assert_eq!(
            table.enclose(&Vec3::new(2_000.0, 0.0, -500.0), &Vec3::new(2_010.0, 10.0, -490.0)),
            Some([Enclosure::Empty; 3])
        );
        assert!(table
            .enclose(&Vec3::new(0.0, 0.0, Real::NAN), &Vec3::new(1.0, 1.0, -400.0))
            .is_none());
        let deep = table.enclose(&Vec3::new(-5.0, -5.0, -900.0), &Vec3::new(5.0, 5.0, -890.0));
        assert_eq!(deep, Some([Enclosure::Empty; 3]));
    }
}
