//! One robot's motion bound: how far any point of any box of a robot can move while its TCP
//! stays in a cube (a table's grid cell, thesis 3.2.7, SPEC §6: `cspace::guarantee`) or a
//! ball (the TCPs of a stop, SPEC §8: `cell::protective`), by interval inverse kinematics.
//!
//! The thesis blows the model up by `r / sqrt(2)`, the TCP's worst displacement in a 2-D
//! square. That is not a proof: the cube's half-diagonal is `r sqrt(3) / 2`, and a link point
//! moves further than the TCP when the elbow swings and the link turns. This module bounds,
//! per sample and per box, the displacement `rho` of every point of the box (with the robot's
//! own margin `m`) when the TCP moves from the cell centre `p0` to any reachable `p` of the
//! closed cell. Then, for every `p` in the cell, box(p) lies in box(p0) inflated by `rho`
//! (every point of box(p) is within `rho` of the point with the same box coordinates in
//! box(p0), and a box inflated by `rho` on each half-extent holds the `rho`-ball around each
//! of its points). So if the inflated centre boxes of A and B are disjoint, no configuration
//! of the 6-D cell collides: a free label is a proof.
//!
//! # Direction-aware form
//! The same derivation gives more than a length: each displacement is a sum of terms whose
//! directions are known. The TCP's `D` lies in the cube `Z` of half-edges `h_a` (not just in
//! the ball of radius `dp`); the elbow's `G - G0` lies in the arm's vertical plane (the disc
//! `D` of radius `dG` orthogonal to `t`); only the turn of the link's `y` and `z` axes stays a
//! ball. [`cube_box_sweeps`] returns that set as a [`Sweep`] per box, and
//! [`crate::geometry::sweep`] tests box(p0) plus the set by its support function on the 15
//! axes of the two boxes. On every axis the support is at most the length `rho` above (its
//! [`Sweep::radius`]), and on most axes less: a face axis along `t` sees no elbow motion at
//! all, and a world axis sees `h`, not `h sqrt(3)`, of the TCP's. Where the TCP stays in the
//! ball of radius `h` (the protective verdict's stop, SPEC §8), [`box_sweep_forms_into`] also
//! gives the same derivation with `D` in that ball: the ball takes `Z`'s place (the sweep's
//! `round`) and steps 1 and 6 below read `|D| <= h` and `|D . t| <= h |t|`.
//!
//! # Reference point
//! Displacements are measured from a reachable TCP `p0` of the cell: its centre when that is
//! reachable, else a reachable lattice point near it ([`reference_point`]); the cell's boxes
//! are built at `p0`. Below, `h = r/2` is the cube's half-side and `h_a = h + |c_a - p0_a|`
//! bounds `|p_a - p0_a|` on axis `a` for every `p` of the cube (`h_a = h` at the centre `c`).
//!
//! # Derivation (lower link of arm i; `t = t_i`, `u = u_i`)
//! Write `G, E` for the elbow and platform joint at `p`, `G0, E0` at `p0`, `D = p - p0`.
//! 1. `|D| <= dp = |(h_x, h_y, h_z)|` (at the centre the cube's half-diagonal `h sqrt(3)`;
//!    the thesis used `r/sqrt(2)`).
//! 2. `E = p + e u`, so `|E - E0| = |D| <= dp`.
//! 3. `G = F + rf (cos th u - sin th z)` moves on a circle of radius `rf`:
//!    `|G - G0| = 2 rf sin(|th - th0| / 2) <= dG := 2 rf sin(dth / 2)`, with
//!    `dth >= max |th(p) - th0|` over the reachable part of the cell, enclosed with interval
//!    arithmetic ([`theta_range`]): `th = -atan2(c, a) - acos(K / R)` (elbow-out, `c < 0`),
//!    `a = p.u + e - f`, `b = p.t`, `c = p.z`, `R = hypot(a, c)`,
//!    `K / R = R / (2 rf) + C / (2 rf R)` with `C = rf^2 - re^2 + b^2`, which for `C <= 0` is
//!    increasing in `R` and in `C`, so it is enclosed without dependency; the cell is split
//!    into `splits^3` sub-boxes and the enclosures united.
//! 4. Box point `P = (1 - l) G + l E + s_y y + s_z z` with `l in [-mu, 1 + mu]`, `mu = m/re`
//!    (the box spans `G - m x` to `E + m x` since `|E - G| = re`), `|s_y| <= H + m`,
//!    `|s_z| <= D + m`. The displacement is affine in `(l, s_y, s_z)`, so by the triangle
//!    inequality `|P - P0| <= ax + (H + m) |y - y0| + (D + m) |z - z0|` where
//!    `ax = max((1 + mu) dG + mu dp, mu dG + (1 + mu) dp)` (the two ends of `l`).
//! 5. `x = (E - G) / re`: `|x - x0| <= dx := (dp + dG) / re`.
//! 6. `x.t = (E - G).t / re = p.t / re` (`G.t = 0`, `u.t = 0`), so over the cell
//!    `|x.t| <= beta := (|p0.t| + h_x |t_x| + h_y |t_y|) / re` and
//!    `|(x - x0).t| <= (h_x |t_x| + h_y |t_y|) / re`.
//! 7. Normalising is Lipschitz away from 0: for `|v|, |w| >= w0`,
//!    `|v/|v| - w/|w|| <= |v - w| / w0` (`v -> w0 v/|v|` is the projection onto a convex ball).
//! 8. `z = (x cross t) / |x cross t|`, `|x cross t| = sqrt(1 - (x.t)^2) >= w0 := sqrt(1 - beta^2)`,
//!    `|(x - x0) cross t| <= dx`, so `|z - z0| <= dx / w0`.
//! 9. `y = z cross x = (t - (x.t) x) / sqrt(1 - (x.t)^2)`; the numerator changes by
//!    `(x.t) (x - x0) + ((x - x0).t) x0`, so `|y - y0| <= (beta dx + (h_x |t_x| + h_y |t_y|) / re)
//! / w0`.
//! 10. (Stops only, [`box_sweep_forms_into`].) The same `y`, written exactly: with `s = x.t`,
//!     `w = sqrt(1 - s^2)` and `s0, w'` at `p0`,
//!     `t - s x = (t - s0 x0) - (s - s0) x0 - s (x - x0)`,
//!     so `y - y0 = (w'/w - 1) y0 - ((s - s0) / w) x0 - (s / w)(x - x0)`. With `|s| <= beta`
//!     (`w >= w0`) and `|s - s0| <= (h_x |t_x| + h_y |t_y|) / re =: tt` (step 6): a segment
//!     along the link's own axis `x0` of half-length `tt / w0`, plus a ball of radius
//!     `beta dx / w0 + max(1 - w', w'/w0 - 1)`. Step 9's ball becomes that ball and segment
//!     (each times `H + m`): the sum of their lengths exceeds step 9's bound by the last term
//!     only, and on the axes across the link, such as the cross product of two links' axes,
//!     the segment adds nothing.
//! 11. (Stops only.) `z` and `z0` are unit vectors orthogonal to `t`, so `z` is `z0` turned
//!     about `t` by an angle `phi` with `2 sin(|phi| / 2) = |z - z0| <= dz` (step 8):
//!     `z - z0 = (cos phi - 1) z0 + sin phi (t x z0)`, and `t x z0 = (x0 - s0 t) / w'`
//!     (`z0 = x0 x t / w'`). So `z - z0` is a segment along `x0` of half-length
//!     `sin phi_max / w'` (`phi_max = 2 asin(dz / 2)`, `sin` taken at `min(phi_max, pi/2)`)
//!     plus a ball of radius `sin phi_max |s0| / w' + 1 - cos phi_max`; times `D + m`. Both
//!     segments lie along `x0`, so they add into one.
//!
//! # Motor angles over a ball
//! Where the TCP stays in a ball, its motor angles are also enclosed over the ball itself
//! ([`ball_theta_range`], in the arm's polar coordinates) and intersected with the cube's:
//! both hold every angle of the ball. Over a world cube the same ranges are wider (its
//! corners reach `sqrt 3` times as far as the ball).
//!
//! Upper links (`F` to `G`, fixed `F`): `x.t = 0` so `y = t` never turns, `|z - z0| = dG / rf`,
//! and points move at most `(1 + m/rf) dG + (d_u + m) dG / rf`. Platform and tool boxes
//! translate with the TCP: `Z`, at most `dp`. Unit vectors differ by at most 2, so every `|.|`
//! above is capped at 2.
//!
//! # Numerics
//! The cell is widened by a relative 1e-12 before enclosing (so rounding in a table's
//! `SampleGrid::cell_of` is covered), the interval arithmetic is outward ([`Interval`]), and every
//! bound gets `BOUND_SLACK` added: all err toward a larger bound, i.e. toward "collision".

use super::delta3::{radial, tangent, ArmSolution};
use super::{BoxKind, Delta3, RobotModel, MAX_BOXES};
use crate::geometry::Sweep;
use crate::math::interval::Interval;
use crate::math::{Real, Vec3};

/// Added to every displacement bound (mm): covers rounding in the model's own arithmetic.
pub const BOUND_SLACK: Real = 1e-6;

/// What [`theta_range`] found over a box of TCPs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Enclosure {
    /// No TCP of the box is reachable by the arm (the loop cannot close anywhere in it).
    Empty,
    /// The motor angle of every reachable TCP of the box lies in this interval.
    Range(Interval),
    /// No enclosure (the box reaches `z >= 0`, where the elbow-out branch changes formula).
    Unbounded,
}

impl Enclosure {
    /// The intersection of two enclosures of the same angles over the same box (both sound,
    /// so is it): `Empty` when either is or they are disjoint, the other when one is
    /// unbounded.
    pub fn intersect(self, other: Enclosure) -> Enclosure {
        match (self, other) {
            (Enclosure::Range(x), Enclosure::Range(y)) if x.lo.max(y.lo) <= x.hi.min(y.hi) => {
                Enclosure::Range(Interval::new(x.lo.max(y.lo), x.hi.min(y.hi)))
            }
            (Enclosure::Range(_), Enclosure::Range(_))
            | (Enclosure::Empty, _)
            | (_, Enclosure::Empty) => Enclosure::Empty,
            (Enclosure::Unbounded, other) | (other, Enclosure::Unbounded) => other,
        }
    }
}

/// An enclosure of the elbow-out motor angle of `arm` over the reachable TCPs of the box
/// `[lo, hi]` (MCS), split `splits` times per axis and united.
pub fn theta_range(delta: &Delta3, arm: usize, lo: &Vec3, hi: &Vec3, splits: u32) -> Enclosure {
    let (u, t) = (radial(arm), tangent(arm));
    let step = (hi - lo) / splits as Real;
    let end = |i: u32, a: usize| if i == splits { hi[a] } else { lo[a] + step[a] * i as Real };
    let mut out = Enclosure::Empty;
    for i in 0..splits {
        for j in 0..splits {
            for k in 0..splits {
                let x = Interval::new(end(i, 0), end(i + 1, 0));
                let y = Interval::new(end(j, 1), end(j + 1, 1));
                let z = Interval::new(end(k, 2), end(k + 1, 2));
                match (theta_over_box(delta, &u, &t, x, y, z), out) {
                    (Enclosure::Unbounded, _) => return Enclosure::Unbounded,
                    (Enclosure::Empty, _) => {}
                    (Enclosure::Range(r), Enclosure::Range(o)) => {
                        out = Enclosure::Range(o.hull(&r))
                    }
                    (Enclosure::Range(r), _) => out = Enclosure::Range(r),
                }
            }
        }
    }
    out
}

/// Absolute widening (mm) of a cube before proving it unreachable: a TCP that the
/// floating-point inverse kinematics calls reachable is, in exact arithmetic, reachable or
/// within far less than this of a reachable point, so the proof covers every TCP that
/// [`Delta3::is_reachable`] accepts.
pub const REACH_SLACK: Real = 1e-6;

/// Deepest bisection of [`cube_unreachable`] (a cube is cut into at most `8^depth` boxes).
pub const UNREACHABLE_DEPTH: u32 = 4;

/// Whether no TCP of the closed cube of centre `c` and half-side `h` (widened by
/// [`REACH_SLACK`]) is reachable, proved by interval inverse kinematics: the cube is bisected
/// (up to [`UNREACHABLE_DEPTH`] times) until, in every piece, some arm either cannot close
/// its loop anywhere ([`Enclosure::Empty`]) or has its whole motor-angle enclosure outside
/// its limits. `false` means "not proved", not "reachable".
///
/// A table may store a cube proved unreachable as anything ("don't care", SPEC §6): a query
/// reaches the table only for a TCP that passed [`Delta3::is_reachable`], and that TCP does
/// not lie in such a cube.
pub fn cube_unreachable(delta: &Delta3, c: &Vec3, h: Real) -> bool {
    let h = h * (1.0 + 1e-12) + REACH_SLACK;
    box_unreachable(delta, &c.add_scalar(-h), &c.add_scalar(h), UNREACHABLE_DEPTH)
}

fn box_unreachable(delta: &Delta3, lo: &Vec3, hi: &Vec3, depth: u32) -> bool {
    let iv = |a: usize| Interval::new(lo[a], hi[a]);
    let arm_excludes = |arm: usize| match theta_over_box(
        delta,
        &radial(arm),
        &tangent(arm),
        iv(0),
        iv(1),
        iv(2),
    ) {
        Enclosure::Empty => true,
        Enclosure::Range(th) => outside_limits(delta, th),
        Enclosure::Unbounded => false,
    };
    if (0..3).any(arm_excludes) {
        return true;
    }
    if depth == 0 {
        return false;
    }
    let mid = (lo + hi) * 0.5;
    (0..8).all(|i: usize| {
        let pick = |a: usize| if i >> a & 1 == 0 { (lo[a], mid[a]) } else { (mid[a], hi[a]) };
        let (x, y, z) = (pick(0), pick(1), pick(2));
        box_unreachable(delta, &Vec3::new(x.0, y.0, z.0), &Vec3::new(x.1, y.1, z.1), depth - 1)
    })
}

/// Whether every angle of `th` lies outside the motor's arc `[theta_min, theta_max]` (mod
/// `2 pi`, as [`Delta3::motor_within_limits`]): `th` fits strictly inside the complement arc
/// that starts at `theta_max`.
fn outside_limits(delta: &Delta3, th: Interval) -> bool {
    let gap = std::f64::consts::TAU - (delta.theta_max - delta.theta_min);
    let start = (th.lo - delta.theta_max).rem_euclid(std::f64::consts::TAU);
    start > 1e-12 && start + (th.hi - th.lo) < gap - 1e-12
}

/// Relative margin of [`cube_reachable`] on `b^2 <= re^2` and `|K / R| <= 1`, and absolute
/// margin (rad) on the motor limits. [`Delta3::is_reachable`] decides the same inequalities on
/// floating-point values whose error is near 1e-15 relative; the worst-conditioned of them,
/// the angle near `|K / R| = 1` where `S = sqrt(R^2 - K^2)` loses digits, is still off by less
/// than 1e-10 rad at this margin. So every TCP that the margins prove reachable passes
/// `is_reachable` too.
pub const REACH_MARGIN: Real = 1e-9;

/// Whether every TCP of the closed cube of centre `c` and half-side `h` (widened by a
/// relative 1e-12 and by [`REACH_SLACK`]) is reachable, proved by interval inverse kinematics
/// with [`REACH_MARGIN`]: for each arm, over the whole cube, `z < 0`, `b^2 < re^2`,
/// `|K / R| < 1` and the motor angle strictly inside its limits, each with the margin.
/// `false` means "not proved", not "unreachable".
///
/// The widening covers the rounding of a TCP's grid cell (one subtraction and one division,
/// far below 1e-6 mm): a TCP that a table maps to a proved cell lies in the widened cube, so
/// [`Delta3::is_reachable`] accepts it and a lookup may skip the inverse kinematics.
pub fn cube_reachable(delta: &Delta3, c: &Vec3, h: Real) -> bool {
    let h = h * (1.0 + 1e-12) + REACH_SLACK;
    let (lo, hi) = (c.add_scalar(-h), c.add_scalar(h));
    let iv = |a: usize| Interval::new(lo[a], hi[a]);
    (0..3).all(|arm| arm_reaches_box(delta, &radial(arm), &tangent(arm), iv(0), iv(1), iv(2)))
}

#[allow(clippy::neg_cmp_op_on_partial_ord)] // written so that NaN fails the tests
fn arm_reaches_box(d: &Delta3, u: &Vec3, t: &Vec3, x: Interval, y: Interval, z: Interval) -> bool {
    // z < 0 everywhere also keeps R^2 >= z^2 > 0.
    if !(z.hi < 0.0) {
        return false;
    }
    let (a, b2, c) = arm_frame(d, u, t, x, y, z);
    let m = 1.0 - REACH_MARGIN;
    if !(b2.hi < d.re * d.re * m) {
        return false;
    }
    let Some(q) = cos_ratio(d, a, b2, c) else { return false };
    if !(q.lo > -m && q.hi < m) {
        return false;
    }
    let (Some(psi), Some(phi)) = (q.acos(), Interval::atan2(c, a)) else { return false };
    inside_limits(d, phi.neg().sub(psi))
}

/// Whether every angle of `th` lies in the motor's arc `[theta_min, theta_max]` (mod `2 pi`,
/// as [`Delta3::motor_within_limits`]) with [`REACH_MARGIN`] to spare at both ends.
fn inside_limits(delta: &Delta3, th: Interval) -> bool {
    let start = (th.lo - delta.theta_min).rem_euclid(std::f64::consts::TAU);
    start >= REACH_MARGIN
        && start + (th.hi - th.lo) <= delta.theta_max - delta.theta_min - REACH_MARGIN
}

/// The TCP box in arm `u, t`'s frame: `a = p.u + e - f`, `b^2 = (p.t)^2`, `c = p.z`.
fn arm_frame(
    d: &Delta3,
    u: &Vec3,
    t: &Vec3,
    x: Interval,
    y: Interval,
    z: Interval,
) -> (Interval, Interval, Interval) {
    let a = x.scale(u.x).add(y.scale(u.y)).shift(d.e - d.f);
    let b = x.scale(t.x).add(y.scale(t.y));
    (a, b.sqr(), z)
}

/// An enclosure of `K / R` over the box (`None`: no bound), with `R = hypot(a, c)`,
/// `K = (R^2 + C) / (2 rf)`, `C = rf^2 - re^2 + b^2`.
fn cos_ratio(d: &Delta3, a: Interval, b2: Interval, c: Interval) -> Option<Interval> {
    let r2 = a.sqr().add(c.sqr());
    cos_ratio_of(d, r2, r2.sqrt()?, b2)
}

/// [`cos_ratio`] from enclosures of `R^2` and `R`.
fn cos_ratio_of(d: &Delta3, r2: Interval, r: Interval, b2: Interval) -> Option<Interval> {
    let cc = b2.shift(d.rf * d.rf - d.re * d.re);
    let two_rf = 2.0 * d.rf;
    if cc.hi <= 0.0 {
        // K/R = R/(2 rf) + C/(2 rf R): increasing in R (C <= 0) and in C (R > 0).
        let g = |rv: Real, cv: Real| {
            Some(
                Interval::point(rv / two_rf)
                    .add(Interval::point(cv).div(Interval::point(two_rf * rv))?),
            )
        };
        let (glo, ghi) = (g(r.lo, cc.lo)?, g(r.hi, cc.hi)?);
        Some(Interval::new(glo.lo, ghi.hi))
    } else {
        r2.add(cc).scale(1.0 / two_rf).div(r)
    }
}

/// `th = -atan2(c, a) - acos(K / R)` over one sub-box (SPEC §2, elbow-out with `c < 0`).
fn theta_over_box(
    d: &Delta3,
    u: &Vec3,
    t: &Vec3,
    x: Interval,
    y: Interval,
    z: Interval,
) -> Enclosure {
    if z.hi >= 0.0 {
        return Enclosure::Unbounded;
    }
    let (a, b2, c) = arm_frame(d, u, t, x, y, z);
    if b2.lo > d.re * d.re {
        return Enclosure::Empty;
    }
    let Some(q) = cos_ratio(d, a, b2, c) else { return Enclosure::Unbounded };
    let Some(psi) = q.acos() else { return Enclosure::Empty };
    let Some(phi) = Interval::atan2(c, a) else { return Enclosure::Unbounded };
    Enclosure::Range(phi.neg().sub(psi))
}

/// An enclosure of the elbow-out motor angle of `arm` over the reachable TCPs of the closed
/// ball of centre `c` (MCS) and radius `rho`, in the arm's polar coordinates: the frame
/// `(a, b, z) = (p.u + e - f, p.t, p.z)` is `p`'s orthonormal coordinates shifted, so the
/// ball stays a ball of radius `rho` there and its shadow on the `(a, z)` plane is the disc
/// of radius `rho` around `(a0, z0)`. Over that disc, when `rho < R0`, the polar angle
/// `phi = atan2(z, a)` lies within `T = asin(rho / R0)` of `phi0` (the disc's tangents from
/// the origin), and `b` within `rho` of `b0`. The angles `phi - phi0` are cut into
/// [`BALL_WEDGES`] wedges; over each, `R = hypot(a, z)` lies in [`wedge_radii`] (within `rho`
/// of `R0` on the middle one, closer on the others). Then `th = -phi - acos(K / R)` is
/// enclosed as [`theta_over_box`] does, with `R` and `C` in those ranges, and the wedges'
/// enclosures united (the two wedges at the same distance from the middle share their `R`
/// range, so one enclosure of `acos(K / R)` serves both). Over a world-aligned cube of
/// half-side `rho` the ranges are wider: the square's shadow reaches `rho sqrt 2` from its
/// centre, and `rho (|u_x| + |u_y|)` along `a` for an arm not along a world axis.
///
/// Rounding: `a0`, `b0`, `R0` and `phi0` are computed in floating point, off by far less
/// than [`POLAR_SLACK`] (mm, and rad), which widens each range.
pub fn ball_theta_range(delta: &Delta3, arm: usize, c: &Vec3, rho: Real) -> Enclosure {
    let (u, t) = (radial(arm), tangent(arm));
    let slack = Interval::new(-POLAR_SLACK, POLAR_SLACK);
    let spread = Interval::new(-rho, rho).add(slack);
    if Interval::point(c.z).add(spread).hi >= 0.0 {
        return Enclosure::Unbounded;
    }
    let a0 = c.x * u.x + c.y * u.y + (delta.e - delta.f);
    let b2 = Interval::point(c.x * t.x + c.y * t.y).add(spread).sqr();
    if b2.lo > delta.re * delta.re {
        return Enclosure::Empty;
    }
    let r0 = Interval::point(a0.hypot(c.z)).add(slack);
    // `rho / R0` rounded up, its arcsine widened far beyond the rounding of `asin`.
    let ratio = rho / r0.lo * (1.0 + 4.0 * Real::EPSILON);
    if !(ratio < 1.0 && r0.lo > rho) {
        return Enclosure::Unbounded;
    }
    let turn = ratio.asin() * (1.0 + 1e-12) + POLAR_SLACK;
    let minus_phi0 = Interval::point(-c.z.atan2(a0));
    let step = 2.0 * turn / BALL_WEDGES as Real;
    let mut out = Enclosure::Empty;
    for k in 0..=BALL_WEDGES / 2 {
        // The wedges `|phi - phi0|` in `[(k - 1/2) step, (k + 1/2) step]`, or within `step / 2`
        // for `k = 0`.
        let nearest = (k as Real - 0.5).max(0.0) * step;
        let farthest = if k == BALL_WEDGES / 2 { turn } else { (k as Real + 0.5) * step };
        let r = wedge_radii(r0, rho, nearest);
        let Some(q) = cos_ratio_of(delta, r.sqr(), r, b2) else { return Enclosure::Unbounded };
        let Some(psi) = q.acos() else { continue };
        let th = minus_phi0.add(Interval::new(-farthest, farthest)).sub(psi);
        out = match out {
            Enclosure::Range(o) => Enclosure::Range(o.hull(&th)),
            _ => Enclosure::Range(th),
        };
    }
    out
}

/// Wedges of the polar angle in [`ball_theta_range`] (odd: one in the middle).
pub const BALL_WEDGES: u32 = 3;

/// Absolute widening (mm, and rad for angles) of the ranges of [`ball_theta_range`]: far
/// above the rounding of the few operations before them.
const POLAR_SLACK: Real = 1e-9;

/// `R` over the part of the disc of radius `rho` whose centre lies at distance `r0` from the
/// origin, within the wedge of directions at least `nearest` from the centre's direction: a
/// ray at angle `delta` meets the disc at `R = r0 cos delta -+ sqrt(rho^2 - r0^2 sin^2 delta)`,
/// the nearer root increasing and the farther decreasing in `|delta|` (for `rho < r0`), so
/// both are widest at `|delta| = nearest`.
fn wedge_radii(r0: Interval, rho: Real, nearest: Real) -> Interval {
    if nearest == 0.0 {
        return r0.add(Interval::new(-rho, rho));
    }
    let (sin, cos) = nearest.sin_cos();
    let along = r0.scale(cos);
    let across = Interval::point(rho).sqr().sub(r0.sqr().scale(sin * sin));
    let half = Interval::new(across.lo.max(0.0), across.hi.max(0.0))
        .sqrt()
        .unwrap_or(Interval::point(0.0));
    Interval::new(along.sub(half).lo, along.add(half).hi)
}

/// Lattice points per half-axis searched by [`reference_point`] (`(2 n + 1)^3` in all).
pub const REFERENCE_STEPS: i32 = 3;

/// Points of [`reference_point`]'s lattice.
const LATTICE_POINTS: usize = (2 * REFERENCE_STEPS + 1).pow(3) as usize;

/// [`reference_point`]'s lattice offsets `(i, j, l)` in the order it tries them, for cells with
/// `y >= 0` (`[1]`) and `y < 0` (`[0]`): by `i^2 + j^2 + l^2`, then `|i|`, `|j|`, `|l|`, `i`,
/// `l`, then `j` downward for `y >= 0` and upward for `y < 0`, so that mirror cells try mirror
/// points. That key names each offset once, so the order is a strict one. Made when compiling.
const LATTICE: [[[i32; 3]; LATTICE_POINTS]; 2] = [lattice_order(-1), lattice_order(1)];

/// The offsets of [`LATTICE`] for `side` (`1`: `y >= 0`, `-1`: `y < 0`), written out in order:
/// each shell `i^2 + j^2 + l^2 = s` in turn, its absolute values `(|i|, |j|, |l|)` in increasing
/// order, then the signs (`-|i|` before `|i|`, likewise `l`; `j` as `side` says; a zero once).
const fn lattice_order(side: i32) -> [[i32; 3]; LATTICE_POINTS] {
    let n = REFERENCE_STEPS;
    let w = n + 1;
    let mut out = [[0; 3]; LATTICE_POINTS];
    let mut len = 0;
    let mut shell = 0;
    while shell <= 3 * n * n {
        // `q` runs over the absolute values (slowest: `|i|`, then `|j|`, `|l|`) and, for each, the
        // sign choices (slowest: `i`, then `l`, `j`).
        let mut q = 0;
        while q < 8 * w * w * w {
            let (abs, signs) = (q / 8, q % 8);
            let (ai, aj, al) = (abs / (w * w), abs / w % w, abs % w);
            let (si, sl, sj) = (signs / 4, signs / 2 % 2, signs % 2);
            let zero_once = (ai > 0 || si == 0) && (aj > 0 || sj == 0) && (al > 0 || sl == 0);
            if zero_once && ai * ai + aj * aj + al * al == shell {
                let i = if si == 0 { -ai } else { ai };
                let j = if sj == 0 { side * aj } else { -side * aj };
                let l = if sl == 0 { -al } else { al };
                out[len] = [i, j, l];
                len += 1;
            }
            q += 1;
        }
        shell += 1;
    }
    assert!(len == LATTICE_POINTS);
    out
}

/// The point of the closed cube of centre `c` and half-side `h` that displacements are
/// measured from: the centre when it is reachable, otherwise the reachable point nearest the
/// centre on the lattice `c + h (i, j, l) / n` (`|i|, |j|, |l| <= n = REFERENCE_STEPS`), ties
/// broken the same way in mirror cells (`y -> -y`; [`LATTICE`]). `None` when no lattice point
/// is reachable.
pub fn reference_point(delta: &Delta3, c: &Vec3, h: Real) -> Option<Vec3> {
    if delta.is_reachable(c) {
        return Some(*c);
    }
    // `y < 0` takes side -1, anything else (NaN too) side 1.
    let offsets = &LATTICE[if c.y < 0.0 { 0 } else { 1 }];
    let step = h / REFERENCE_STEPS as Real;
    offsets
        .iter()
        .map(|o| c + Vec3::new(o[0] as Real, o[1] as Real, o[2] as Real) * step)
        .find(|p| delta.is_reachable(p))
}

/// Per box of `model`, an unbounded sweep (an infinite ball): nothing could be bounded.
pub(crate) fn unbounded_sweeps(model: &RobotModel) -> [Sweep; MAX_BOXES] {
    let mut out = [Sweep::ZERO; MAX_BOXES];
    out[..model.box_count()].fill(Sweep { ball: Real::INFINITY, ..Sweep::ZERO });
    out
}

/// Per box of `model`, the set of displacements of its points (MCS, module doc) when the TCP
/// moves from `p0` to any reachable point of the closed cube of centre `c` and half-side `h`
/// (widened by a relative 1e-12); `p0` is a reachable point of the cube ([`reference_point`]),
/// enclosing the motor angles with `splits^3` sub-boxes. `None` when no TCP of the cube is
/// reachable (nothing to bound: the cube can never be occupied); infinite entries when `p0`
/// is unreachable or the angles cannot be enclosed.
///
/// Per box kind (module doc; `Z` is the cube of half-edges `reach`, `D` the disc orthogonal to
/// the arm's tangent `t` that the elbow moves in):
/// - lower link: `hull((1 + mu) dG D + mu Z, mu dG D + (1 + mu) Z) + ball((H + m) dy + (D + m)
///   dz)`;
/// - upper link: `((1 + m/rf) dG + (d_u + m) dG / rf) D`;
/// - platform and tool: `Z`.
pub fn cube_box_sweeps(
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    p0: &Vec3,
    splits: u32,
) -> Option<[Sweep; MAX_BOXES]> {
    let d = &model.delta;
    cube_box_sweeps_with(model, c, h, p0, |lo, hi| {
        core::array::from_fn(|arm| theta_range(d, arm, lo, hi, splits))
    })
}

/// As [`cube_box_sweeps`], with the motor angles over the widened cube `[lo, hi]` enclosed by
/// `enclose` (per arm, with the meaning of [`theta_range`]: every reachable TCP of the box
/// has its angle in the range), e.g. from a precomputed
/// [`MotorTable`](crate::robot::motor_table::MotorTable).
pub fn cube_box_sweeps_with(
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    p0: &Vec3,
    enclose: impl FnOnce(&Vec3, &Vec3) -> [Enclosure; 3],
) -> Option<[Sweep; MAX_BOXES]> {
    let (angles, h) = angles_over_cube(model, c, h, p0, enclose)?;
    let Some((sol, th)) = angles else { return Some(unbounded_sweeps(model)) };
    let swing = CubeSwing::new(model, &sol, &th, 0b111, LinkTurn::Ball);
    let mut out = [Sweep::ZERO; MAX_BOXES];
    for (j, slot) in out[..model.box_count()].iter_mut().enumerate() {
        *slot = swing.box_sweep(model, p0, j, &TcpMotion::cube(c, h, p0));
    }
    Some(out)
}

/// Both forms of the sweeps of a stop, for every reachable TCP of the ball of radius `h` around
/// `c`: the motor angles `enclose` gives over the cube of centre `c` and half-side `h`
/// intersected with [`ball_theta_range`], and each lower link's turn split as in steps 10 and 11.
/// `[0]` takes the TCP's own displacement `D` in the cube (as [`cube_box_sweeps_with`]); `[1]`
/// in the ball of radius `|p0 - c| + h` (widened as the cube), which takes the place of the
/// box `Z` inside the hull of each lower link (the sweep's `round`), and the link's turn is
/// bounded with `|D|` at most that radius and `|D . t|` at most that radius times `|t|`
/// (module doc, steps 1, 6). On an axis either form may be the smaller. Written into `out`
/// (the per-tick path: no copy of the 2.5 KB set); `false`, with nothing written, when no TCP
/// of the cube is reachable.
pub fn box_sweep_forms_into(
    out: &mut [[Sweep; MAX_BOXES]; 2],
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    p0: &Vec3,
    enclose: impl FnOnce(&Vec3, &Vec3) -> [Enclosure; 3],
) -> bool {
    let Some((angles, h)) = angles_over_cube(model, c, h, p0, enclose) else { return false };
    let motions = [TcpMotion::cube(c, h, p0), TcpMotion::ball(c, h, p0)];
    let swing = angles.map(|(sol, th)| {
        CubeSwing::new(
            model,
            &sol,
            &narrowed_to_ball(&model.delta, c, h, &th),
            0b111,
            LinkTurn::AlongLink,
        )
    });
    let n = model.box_count();
    for (form, motion) in out.iter_mut().zip(&motions) {
        for (j, slot) in form.iter_mut().enumerate() {
            *slot = match &swing {
                _ if j >= n => Sweep::ZERO,
                Some(swing) => swing.box_sweep(model, p0, j, motion),
                None => Sweep { ball: Real::INFINITY, ..Sweep::ZERO },
            };
        }
    }
    true
}

/// The motor angles `th` over the cube of centre `c` and half-side `h`, each intersected with
/// [`ball_theta_range`] over the ball of radius `h` around `c` (both hold the angle of every
/// reachable TCP of the ball, so does their intersection); `th` as it is where the ball's
/// enclosure gives nothing.
fn narrowed_to_ball(delta: &Delta3, c: &Vec3, h: Real, th: &[Interval; 3]) -> [Interval; 3] {
    core::array::from_fn(|arm| {
        match Enclosure::Range(th[arm]).intersect(ball_theta_range(delta, arm, c, h)) {
            Enclosure::Range(r) => r,
            Enclosure::Empty | Enclosure::Unbounded => th[arm],
        }
    })
}

/// The inverse kinematics at `p0` and the motor angles over the cube of centre `c` and
/// half-side `h`, with that half-side widened: `None` when no TCP of the cube is reachable,
/// `Some(None)` when `p0` is unreachable or the angles cannot be enclosed.
#[allow(clippy::type_complexity)]
fn angles_over_cube(
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    p0: &Vec3,
    enclose: impl FnOnce(&Vec3, &Vec3) -> [Enclosure; 3],
) -> Option<(Option<(ArmSolution, [Interval; 3])>, Real)> {
    let d = &model.delta;
    let h = h * (1.0 + 1e-12) + 1e-12;
    let (lo, hi) = (c.add_scalar(-h), c.add_scalar(h));
    let mut th = [Interval::point(0.0); 3];
    let enclosures = enclose(&lo, &hi);
    for (arm, slot) in th.iter_mut().enumerate() {
        match enclosures[arm] {
            Enclosure::Empty => return None,
            Enclosure::Unbounded => return Some((None, h)),
            Enclosure::Range(r) => *slot = r,
        }
    }
    let Ok(sol) = d.inverse_kinematics(p0) else { return Some((None, h)) };
    Some((Some((sol, th)), h))
}

/// Both forms of [`box_sweep_forms_into`] for box `j` alone, measured from the reachable `p0`
/// with its inverse kinematics `sol`, with the motor angles `th` as given (not narrowed
/// further): for angles that hold every reachable TCP of the ball, a sound bound, and the
/// same operations as [`box_sweep_forms_into`] after it narrows. Only box `j`'s arm's entries
/// of `sol` and `th` are read.
pub fn box_sweep_forms(
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    p0: &Vec3,
    sol: &ArmSolution,
    th: &[Interval; 3],
    j: usize,
) -> [Sweep; 2] {
    let h = h * (1.0 + 1e-12) + 1e-12;
    let arms = match model.box_kind(j) {
        BoxKind::LowerLink(arm) | BoxKind::UpperLink(arm) => 1 << arm,
        BoxKind::Platform | BoxKind::Tool => 0,
    };
    let swing = CubeSwing::new(model, sol, th, arms, LinkTurn::AlongLink);
    [TcpMotion::cube(c, h, p0), TcpMotion::ball(c, h, p0)]
        .map(|motion| swing.box_sweep(model, p0, j, &motion))
}

/// Where the TCP's displacement `D = p - p0` lies: in the box of half-edges `reach` (per
/// axis) or in the ball of radius `radius`.
enum TcpMotion {
    Cube(Vec3),
    Ball(Real),
}

impl TcpMotion {
    /// Every `p` of the cube of centre `c` and half-side `h`: per axis, at most
    /// `|p0_a - c_a| + h` from `p0` (`h` at the centre).
    fn cube(c: &Vec3, h: Real, p0: &Vec3) -> TcpMotion {
        TcpMotion::Cube((p0 - c).abs().add_scalar(h))
    }

    /// Every `p` of the ball of radius `h` around `c`: at most `|p0 - c| + h` from `p0`.
    fn ball(c: &Vec3, h: Real, p0: &Vec3) -> TcpMotion {
        TcpMotion::Ball((p0 - c).norm() + h)
    }

    /// `dp >= |D|`.
    fn length(&self) -> Real {
        match self {
            TcpMotion::Cube(reach) => reach.norm(),
            TcpMotion::Ball(r) => *r,
        }
    }

    /// A bound on `|D . t|` (module doc, step 6).
    fn along(&self, t: &Vec3) -> Real {
        match self {
            TcpMotion::Cube(reach) => reach.x * t.x.abs() + reach.y * t.y.abs(),
            TcpMotion::Ball(r) => r * t.norm(),
        }
    }

    /// The set of `D` as a sweep's `Z`: its box and its rounding ball.
    fn as_z(&self) -> ([Vec3; 3], Real) {
        match self {
            TcpMotion::Cube(reach) => {
                ([Vec3::x() * reach.x, Vec3::y() * reach.y, Vec3::z() * reach.z], 0.0)
            }
            TcpMotion::Ball(r) => ([Vec3::zeros(); 3], *r),
        }
    }
}

/// How a lower link's sweep holds the turn of the box's `y` and `z` axes (module doc, steps 8-11).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LinkTurn {
    /// All of it in the sweep's ball (steps 8, 9): the tables' sweeps.
    Ball,
    /// Its part along the link's own axis as the sweep's segment (steps 10 and 11): the stops'.
    AlongLink,
}

/// What every box's sweep over a cube shares, per arm: the largest turn `dth`, the elbow's
/// chord `dG` and its arc (module doc, step 3); only for the arms asked for (the others stay 0
/// and are not to be read).
struct CubeSwing {
    dg: [Real; 3],
    turn: LinkTurn,
    /// The elbow's arc: `G - G0 = rf (sin D tau0 + (cos D - 1) nu0)` for `|D| <= dth`, as
    /// `(tau0, nu0, sin min(dth, pi/2), 1 - cos dth)`.
    arcs: [(Vec3, Vec3, Real, Real); 3],
}

impl CubeSwing {
    fn new(
        model: &RobotModel,
        sol: &ArmSolution,
        th: &[Interval; 3],
        arms: u8,
        turn: LinkTurn,
    ) -> CubeSwing {
        let d = &model.delta;
        let (mut dg, mut arcs) = ([0.0; 3], [(Vec3::zeros(), Vec3::zeros(), 0.0, 0.0); 3]);
        for arm in (0..3).filter(|arm| arms >> arm & 1 == 1) {
            let theta0 = sol.theta[arm];
            let dth =
                (th[arm].hi - theta0).max(theta0 - th[arm].lo).clamp(0.0, std::f64::consts::PI);
            dg[arm] = 2.0 * d.rf * (0.5 * dth).sin();
            let (s, c) = (theta0.sin(), theta0.cos());
            let u = radial(arm);
            let (nu0, tau0) = (u * c - Vec3::z() * s, -u * s - Vec3::z() * c);
            arcs[arm] = (tau0, nu0, dth.min(std::f64::consts::FRAC_PI_2).sin(), 1.0 - dth.cos());
        }
        CubeSwing { dg, arcs, turn }
    }

    /// Box `j`'s sweep for the TCP's displacements `motion` (module doc, per box kind).
    fn box_sweep(&self, model: &RobotModel, p0: &Vec3, j: usize, motion: &TcpMotion) -> Sweep {
        let (d, o) = (&model.delta, &model.options);
        let (dp, (cube, round)) = (motion.length(), motion.as_z());
        let m = o.margin;
        let sweep = match model.box_kind(j) {
            BoxKind::LowerLink(arm) => {
                let (arm, t) = (arm as usize, tangent(arm as usize));
                let dx = ((dp + self.dg[arm]) / d.re).min(2.0);
                let tt = motion.along(&t) / d.re;
                let beta = p0.dot(&t).abs() / d.re + tt;
                if beta >= 1.0 {
                    Sweep { ball: Real::INFINITY, ..Sweep::ZERO }
                } else {
                    let w0 = (1.0 - beta * beta).sqrt();
                    let dz = (dx / w0).min(2.0);
                    let dy = ((beta * dx + tt) / w0).min(2.0);
                    let (h, depth) = (o.half_height + m, o.half_depth + m);
                    let (tau0, nu0, along, inward) = self.arcs[arm];
                    let (ball, line) = match self.turn {
                        // Steps 10 and 11: the turns of `y` and `z`, each as a segment along `x0`
                        // and a ball; `x0` is the link's axis `(E0 - G0) / re`, `G0 - F = rf nu0`.
                        LinkTurn::AlongLink => {
                            let x0 = (p0 + radial(arm) * (d.e - d.f) - nu0 * d.rf) / d.re;
                            let s0 = p0.dot(&t) / d.re;
                            let w = (1.0 - s0 * s0).max(0.0).sqrt();
                            let (y_ball, y_line) = match dy < 2.0 {
                                true => (
                                    h * (beta * dx / w0 + (1.0 - w).max(w / w0 - 1.0)),
                                    h * tt / w0,
                                ),
                                false => (h * dy, 0.0),
                            };
                            let phi = if dz < 2.0 {
                                2.0 * (0.5 * dz).asin()
                            } else {
                                std::f64::consts::PI
                            };
                            let sin = phi.min(std::f64::consts::FRAC_PI_2).sin();
                            let z_ball = depth * (sin * s0.abs() / w + (1.0 - phi.cos()));
                            (y_ball + z_ball, x0 * (y_line + depth * sin / w))
                        }
                        LinkTurn::Ball => (h * dy + depth * dz, Vec3::zeros()),
                    };
                    let arc = [tau0 * (d.rf * along), nu0 * (d.rf * inward)];
                    // The elbow's end (`l = -mu`, the box's face at `-half_0 x`) first.
                    let [elbow_end, joint_end] = tcp_weights(model, j);
                    Sweep {
                        cube,
                        round,
                        arc,
                        ends: [(elbow_end, joint_end), (joint_end, elbow_end)],
                        ball,
                        line,
                    }
                }
            }
            BoxKind::UpperLink(arm) => {
                // `lambda (G - G0) + s_z (z - z0)`, `|lambda| <= 1 + m/rf`, `|s_z| <= d_u + m`,
                // with `z - z0` the link axis's turn: `sin D` along nu0, `1 - cos D` along tau0.
                let (_, du) = o.upper_links.expect("upper link boxes exist");
                let (tau0, nu0, along, inward) = self.arcs[arm as usize];
                let (l, w) = (d.rf + m, du + m);
                let arc = [tau0 * (l * along + w * inward), nu0 * (l * inward + w * along)];
                let [e1, e2] = tcp_weights(model, j);
                Sweep { cube, round, arc, ends: [(e1, 1.0), (e2, 1.0)], ..Sweep::ZERO }
            }
            BoxKind::Platform | BoxKind::Tool => {
                let [e1, e2] = tcp_weights(model, j);
                Sweep { cube, round, ends: [(e1, 0.0), (e2, 0.0)], ..Sweep::ZERO }
            }
        };
        Sweep { ball: sweep.ball + BOUND_SLACK, ..sweep }
    }
}

/// The weights `e_1`, `e_2` of the TCP's displacement set `Z` in the two end sets of box `k`'s
/// sweeps ([`Sweep::ends`], the face at `-half_0 u_0` first): `|l|` at the ends
/// `l = -mu, 1 + mu` of a lower link (step 4), 1 for the boxes that translate with the TCP,
/// 0 for an upper link.
pub fn tcp_weights(model: &RobotModel, k: usize) -> [Real; 2] {
    match model.box_kind(k) {
        BoxKind::LowerLink(_) => {
            let mu = model.options.margin / model.delta.re;
            [mu, 1.0 + mu]
        }
        BoxKind::UpperLink(_) => [0.0; 2],
        BoxKind::Platform | BoxKind::Tool => [1.0; 2],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::{SampleGrid, Workspace};
    use crate::robot::ModelOptions;
    use rand::{rngs::StdRng, RngExt, SeedableRng};

    /// Sub-boxes per axis of the tests' angle enclosures (the tables' choice).
    const SPLITS: u32 = 4;

    /// The sweeps of a grid cell, as a table's labelling takes them (its reference point, or
    /// unbounded).
    fn grid_cell_sweeps(
        model: &RobotModel,
        grid: &SampleGrid,
        sample: usize,
    ) -> [Sweep; MAX_BOXES] {
        let (c, h) = (grid.sample_center(sample), 0.5 * grid.r);
        reference_point(&model.delta, &c, h)
            .and_then(|p0| cube_box_sweeps(model, &c, h, &p0, SPLITS))
            .unwrap_or_else(|| unbounded_sweeps(model))
    }

    /// Per box, the displacements of its eight corners between the reference `p0` and `p`,
    /// each with the face across the box's axis 0 it lies on at `p0` (0: `-half_0 u_0`).
    fn measured(model: &RobotModel, p0: &Vec3, p: &Vec3) -> Option<Vec<[(Vec3, usize); 8]>> {
        let (b0, b1) = (model.boxes(p0).ok()?, model.boxes(p).ok()?);
        let moved = |j: usize| {
            let (v0, v1) = (b0.boxes[j].vertices(), b1.boxes[j].vertices());
            let x = b0.boxes[j].axes.column(0).into_owned();
            std::array::from_fn(|i| {
                (v1[i] - v0[i], usize::from(x.dot(&(v0[i] - b0.boxes[j].center)) > 0.0))
            })
        };
        Some((0..b0.len).map(moved).collect())
    }

    /// Checks every corner displacement `v` against its box's sweep: `|v| <= radius` and
    /// `v . n <= support(n)`, and under the graded reading `v . n <= face_support(end, n)` for
    /// the end set of the corner's face, for `n` = `v` itself and the 13 axis, face and corner
    /// directions (the corners' displacements bound every point's: it is affine along the box).
    /// Returns the largest `|v| / radius` seen.
    fn check_bounds_against_brute_force(
        model: RobotModel,
        k: u32,
        cells: usize,
        points: usize,
        seed: u64,
    ) -> Real {
        let grid = SampleGrid::new(&Workspace::THESIS, k, &model.delta).unwrap();
        let mut rng = StdRng::seed_from_u64(seed);
        let mut worst_ratio: Real = 0.0;
        let dirs = lattice_directions();
        // Half of the cells are drawn from those with an unreachable centre (the boundary of
        // the reachable space), where the bound is measured from an off-centre reference.
        let boundary: Vec<usize> = (0..grid.cells.len()).filter(|&s| !grid.reachable[s]).collect();
        for i in 0..cells {
            let s = if i % 2 == 0 {
                rng.random_range(0..grid.cells.len())
            } else {
                boundary[rng.random_range(0..boundary.len())]
            };
            let sweeps = grid_cell_sweeps(&model, &grid, s);
            let bounds = sweeps.map(|w| w.radius());
            let c = grid.sample_center(s);
            let Some(p0) = reference_point(&model.delta, &c, 0.5 * grid.r) else {
                assert!(bounds[..model.box_count()].iter().all(|b| b.is_infinite()));
                continue;
            };
            assert_eq!(p0 == c, grid.reachable[s]);
            let mut worst = [0.0; MAX_BOXES];
            for q in 0..points {
                // Corners and face centres of the cell first, then random points.
                let off = if q < 8 {
                    Vec3::new(
                        (q & 1) as Real - 0.5,
                        ((q >> 1) & 1) as Real - 0.5,
                        ((q >> 2) & 1) as Real - 0.5,
                    )
                } else {
                    Vec3::new(
                        rng.random::<Real>() - 0.5,
                        rng.random::<Real>() - 0.5,
                        rng.random::<Real>() - 0.5,
                    )
                };
                let Some(m) = measured(&model, &p0, &(c + off * grid.r)) else { continue };
                for (j, corners) in m.iter().enumerate() {
                    for (v, end) in corners {
                        let len = v.norm();
                        assert!(
                            len <= bounds[j],
                            "sample {s} box {j}: moved {len} > bound {}",
                            bounds[j]
                        );
                        let along = if len > 0.0 { v / len } else { Vec3::z() };
                        for n in dirs.iter().chain([&along]) {
                            let (h, g) = (sweeps[j].support(n), sweeps[j].face_support(*end, n));
                            assert!(
                                v.dot(n) <= h + 1e-9,
                                "sample {s} box {j}: {v:?} . {n:?} > support {h}"
                            );
                            assert!(
                                v.dot(n) <= g + 1e-9,
                                "sample {s} box {j} face {end}: {v:?} . {n:?} > {g}"
                            );
                        }
                        worst[j] = Real::max(worst[j], len);
                    }
                }
            }
            for j in 0..model.box_count() {
                if worst[j] > 0.0 {
                    worst_ratio = worst_ratio.max(worst[j] / bounds[j]);
                }
            }
        }
        worst_ratio
    }

    #[test]
    fn bounds_hold_against_brute_force_corner_displacements() {
        for (k, seed) in [(16, 1), (32, 2), (64, 3)] {
            let ratio = check_bounds_against_brute_force(RobotModel::THESIS, k, 300, 60, seed);
            println!("k = {k}: worst measured / bound = {ratio:.3}");
            assert!(ratio > 0.3, "the bound should not be absurdly loose: {ratio}");
        }
    }

    /// The 26 unit directions to the neighbours of a cube lattice point: axes, edges, corners.
    fn lattice_directions() -> Vec<Vec3> {
        (0..27)
            .map(|i: i32| {
                Vec3::new((i % 3 - 1) as Real, (i / 3 % 3 - 1) as Real, (i / 9 - 1) as Real)
            })
            .filter(|d| *d != Vec3::zeros())
            .map(|d| d.normalize())
            .collect()
    }

    /// The thesis robot with a 5 mm margin, upper link boxes, a platform box and `tool`.
    fn with_extra_boxes(tool: Option<crate::robot::ToolBox>) -> RobotModel {
        let options = ModelOptions {
            margin: 5.0,
            upper_links: Some((30.0, 15.0)),
            platform: Some(crate::robot::ToolBox {
                offset: Vec3::zeros(),
                half: Vec3::new(50.0, 50.0, 10.0),
            }),
            tool,
            ..ModelOptions::THESIS
        };
        RobotModel { options, ..RobotModel::THESIS }
    }

    #[test]
    fn bounds_hold_with_margin_and_extra_boxes() {
        let model = with_extra_boxes(None);
        let ratio = check_bounds_against_brute_force(model, 32, 150, 40, 4);
        assert!(ratio <= 1.0);
    }

    /// Both forms of [`box_sweep_forms_into`] bound the displacement of every box corner for
    /// every TCP of the ball: on random balls of 2 to 150 mm across the reachable space (the
    /// reference at the centre, or off it), with a margin and every kind of box, for TCPs on
    /// the sphere in the 26 axis, edge and corner directions and at random, then inside it; on
    /// those directions, on the axes of every box at the reference, on the displacement's own
    /// and on each form's radius; also for lower links four times as wide or 16 times as deep,
    /// where the turn of their `y` or `z` axis is most of their motion.
    #[test]
    fn ball_and_cube_forms_hold_every_tcp_of_the_ball() {
        let tool = crate::robot::ToolBox {
            offset: Vec3::new(0.0, 0.0, -30.0),
            half: Vec3::new(20.0, 20.0, 30.0),
        };
        let wide = RobotModel {
            options: ModelOptions { half_height: 280.0, ..ModelOptions::THESIS },
            ..RobotModel::THESIS
        };
        let deep = RobotModel {
            options: ModelOptions { half_height: 10.0, half_depth: 280.0, ..ModelOptions::THESIS },
            ..RobotModel::THESIS
        };
        for model in [with_extra_boxes(Some(tool)), wide, deep] {
            forms_hold_every_tcp_of_the_ball(&model);
        }
    }

    fn forms_hold_every_tcp_of_the_ball(model: &RobotModel) {
        let d = &model.delta;
        let mut rng = StdRng::seed_from_u64(11);
        let dirs = lattice_directions();
        let unit = |rng: &mut StdRng| loop {
            let v = Vec3::from_fn(|_, _| rng.random::<Real>() * 2.0 - 1.0);
            if v.norm() > 0.1 && v.norm() <= 1.0 {
                break v.normalize();
            }
        };
        let (mut balls, mut tighter, mut tighter_faces) = (0, 0, 0);
        while balls < 400 {
            let c = Vec3::new(
                rng.random_range(-500.0..500.0),
                rng.random_range(-500.0..500.0),
                rng.random_range(-1100.0..-300.0),
            );
            let h = rng.random_range(2.0..150.0);
            let p0 =
                if balls % 2 == 0 { c } else { c + unit(&mut rng) * (h * rng.random::<Real>()) };
            if !d.is_reachable(&c) || !d.is_reachable(&p0) {
                continue;
            }
            balls += 1;
            let enclose = |lo: &Vec3, hi: &Vec3| {
                core::array::from_fn(|arm| theta_range(d, arm, lo, hi, SPLITS))
            };
            let mut forms = [[Sweep { ball: Real::NAN, ..Sweep::ZERO }; MAX_BOXES]; 2];
            assert!(box_sweep_forms_into(&mut forms, model, &c, h, &p0, enclose));
            let reference = model.boxes(&p0).unwrap();
            let axes: Vec<Vec3> = reference
                .as_slice()
                .iter()
                .flat_map(|b| [0, 1, 2].map(|k| b.axes.column(k).into()))
                .collect();
            for q in 0..120 {
                let dir = if q < dirs.len() { dirs[q] } else { unit(&mut rng) };
                let depth = if q < 60 { 1.0 } else { rng.random::<Real>().cbrt() };
                let Some(m) = measured(model, &p0, &(c + dir * (h * depth))) else { continue };
                for (j, corners) in m.iter().enumerate() {
                    for (v, end) in corners {
                        let along = v.try_normalize(0.0).unwrap_or(Vec3::z());
                        for (f, w) in forms.iter().map(|form| &form[j]).enumerate() {
                            assert!(
                                v.norm() <= w.radius() + 1e-9,
                                "form {f} box {j}: moved {} > {}",
                                v.norm(),
                                w.radius()
                            );
                            for n in dirs.iter().chain(&axes).chain([&along]) {
                                let (support, graded) = (w.support(n), w.face_support(*end, n));
                                assert!(
                                    v.dot(n) <= support + 1e-9,
                                    "form {f} box {j}: {v:?} . {n:?} > {support}"
                                );
                                let at = format_args!("form {f} box {j} face {end}");
                                assert!(
                                    v.dot(n) <= graded + 1e-9,
                                    "{at}: {v:?} . {n:?} > {graded}"
                                );
                                tighter_faces += usize::from(graded < support - 1.0);
                            }
                        }
                    }
                }
            }
            // The ball form is the smaller on some axis of a lower link (else it adds nothing).
            let n = unit(&mut rng);
            tighter += usize::from(forms[1][0].support(&n) < forms[0][0].support(&n));
        }
        assert!(tighter > 100, "the ball form is tighter on only {tighter} of 400 random axes");
        // The graded reading claims less than the whole set, by more than 1 mm, on many tests.
        assert!(tighter_faces > 10_000, "graded tighter by 1 mm on only {tighter_faces} tests");
    }

    /// `n` points of the closed cube of centre `c` and half-side `h`: first the 9^3 lattice
    /// of quarter steps (every corner, edge and face among them), then random points.
    fn cube_points(c: &Vec3, h: Real, n: usize, rng: &mut StdRng) -> Vec<Vec3> {
        let off = |q: usize, rng: &mut StdRng| match q < 729 {
            true => {
                Vec3::new((q % 9) as Real, (q / 9 % 9) as Real, (q / 81) as Real) / 4.0
                    - Vec3::repeat(1.0)
            }
            false => Vec3::from_fn(|_, _| rng.random::<Real>()) * 2.0 - Vec3::repeat(1.0),
        };
        (0..n).map(|q| c + off(q, rng) * h).collect()
    }

    /// [`LATTICE`], written out in order when compiling, is the lattice sorted by the key its
    /// doc states (here by a sort), for both sides.
    #[test]
    fn lattice_is_in_key_order() {
        let n = REFERENCE_STEPS;
        for (index, side) in [(0, -1), (1, 1)] {
            let mut sorted: Vec<[i32; 3]> = (-n..=n)
                .flat_map(|i| (-n..=n).flat_map(move |j| (-n..=n).map(move |l| [i, j, l])))
                .collect();
            sorted.sort_by_key(|o| {
                (
                    o[0] * o[0] + o[1] * o[1] + o[2] * o[2],
                    o[0].abs(),
                    o[1].abs(),
                    o[2].abs(),
                    o[0],
                    o[2],
                    -side * o[1],
                )
            });
            assert_eq!(LATTICE[index].to_vec(), sorted, "side {side}");
        }
    }

    /// A cube proved unreachable holds no TCP that the inverse kinematics accepts (dense
    /// lattice and random points, on the cells of k = 32 whose centre is unreachable), and the
    /// proof succeeds for most such cells far from the reachable space.
    #[test]
    fn cubes_proved_unreachable_hold_no_reachable_tcp() {
        let d = Delta3::THESIS;
        let grid = SampleGrid::new(&Workspace::THESIS, 32, &d).unwrap();
        let mut rng = StdRng::seed_from_u64(7);
        let (mut proved, mut tried) = (0, 0);
        for s in (0..grid.cells.len()).filter(|&s| !grid.reachable[s]) {
            tried += 1;
            let (c, h) = (grid.sample_center(s), 0.5 * grid.r);
            if !cube_unreachable(&d, &c, h) {
                continue;
            }
            proved += 1;
            for p in cube_points(&c, h, 2000, &mut rng) {
                assert!(
                    !d.is_reachable(&p),
                    "sample {s}: {p:?} is reachable in a cube proved unreachable"
                );
            }
        }
        println!("{proved} of {tried} cells with an unreachable centre proved unreachable");
        assert!(proved * 2 > tried, "{proved} of {tried}");
        // A cube around a reachable point is never proved unreachable.
        assert!(!cube_unreachable(&d, &Vec3::new(0.0, 0.0, -450.0), 1.0));
    }

    /// A cube proved wholly reachable holds no TCP that the inverse kinematics rejects: a
    /// dense lattice with every corner, edge and face of the closed cell, and random points, on
    /// every sampled cell of k = 16 and 32 (the thesis robot, and one whose motor limits cut
    /// through its workspace); and the proof succeeds for most cells whose centre is reachable.
    #[test]
    fn cubes_proved_reachable_hold_only_reachable_tcps() {
        let narrow = Delta3 { theta_min: -0.2, theta_max: 0.9, ..Delta3::THESIS };
        let mut rng = StdRng::seed_from_u64(11);
        for (d, k, points) in
            [(Delta3::THESIS, 16, 2000), (Delta3::THESIS, 32, 400), (narrow, 32, 400)]
        {
            let grid = SampleGrid::new(&Workspace::THESIS, k, &d).unwrap();
            let (mut proved, mut centred) = (0, 0);
            for s in 0..grid.cells.len() {
                let (c, h) = (grid.sample_center(s), 0.5 * grid.r);
                centred += usize::from(grid.reachable[s]);
                if !cube_reachable(&d, &c, h) {
                    continue;
                }
                proved += 1;
                assert!(grid.reachable[s], "a cell proved reachable has an unreachable centre");
                for p in cube_points(&c, h, points, &mut rng) {
                    assert!(
                        d.is_reachable(&p),
                        "k = {k}, sample {s}: {p:?} unreachable in a cube proved reachable"
                    );
                }
            }
            println!("k = {k}: {proved} of {centred} cells with a reachable centre proved wholly reachable");
            assert!(proved * 2 > centred, "{proved} of {centred}");
        }
        // A cube reaching the base plane, or beyond the reach, is never proved reachable.
        assert!(!cube_reachable(&Delta3::THESIS, &Vec3::new(0.0, 0.0, -5.0), 10.0));
        assert!(!cube_reachable(&Delta3::THESIS, &Vec3::new(0.0, 0.0, -1500.0), 10.0));
    }

    #[test]
    fn reference_points_are_reachable_and_in_the_cell() {
        let d = Delta3::THESIS;
        let grid = SampleGrid::new(&Workspace::THESIS, 32, &d).unwrap();
        let (mut found, mut boundary) = (0, 0);
        for s in (0..grid.cells.len()).filter(|&s| !grid.reachable[s]) {
            let (c, h) = (grid.sample_center(s), 0.5 * grid.r);
            boundary += 1;
            if let Some(p) = reference_point(&d, &c, h) {
                found += 1;
                assert!(d.is_reachable(&p));
                assert!((p - c).amax() <= h * (1.0 + 1e-12), "{p:?} outside the cell of {c:?}");
            }
        }
        assert!(found > 0 && found < boundary, "{found} of {boundary}");
    }

    #[test]
    fn theta_enclosure_holds_the_sampled_angles() {
        let d = Delta3::THESIS;
        let (lo, hi) = (Vec3::new(150.0, -40.0, -520.0), Vec3::new(175.0, -10.0, -500.0));
        for arm in 0..3 {
            let Enclosure::Range(th) = theta_range(&d, arm, &lo, &hi, 3) else {
                panic!("arm {arm}")
            };
            for s in 0..1000 {
                let f = |v: u32| (v % 10) as Real / 9.0;
                let p = lo + (hi - lo).component_mul(&Vec3::new(f(s), f(s / 10), f(s / 100)));
                if let Ok(sol) = d.inverse_kinematics(&p) {
                    assert!(
                        th.contains(sol.theta[arm]),
                        "arm {arm} {p:?}: {} not in {th:?}",
                        sol.theta[arm]
                    );
                }
            }
        }
        assert_eq!(
            theta_range(&d, 0, &Vec3::new(0.0, 0.0, -10.0), &Vec3::new(1.0, 1.0, 1.0), 2),
            Enclosure::Unbounded
        );
        assert_eq!(
            theta_range(&d, 0, &Vec3::new(0.0, 0.0, -990.0), &Vec3::new(1.0, 1.0, -980.0), 2),
            Enclosure::Empty
        );
    }

    /// [`ball_theta_range`] holds the angle of every reachable TCP of the ball: on 3,000 random
    /// balls of 1 to 250 mm (many reaching past the workspace's edge), for TCPs on the sphere
    /// where the angle is largest and smallest to first order (along `E - G`, its gradient), in
    /// random directions and inside; it is `Empty` only where none is reachable. On balls
    /// within reach it is narrower than [`theta_range`] over the cube around the ball.
    #[test]
    fn ball_enclosure_holds_every_angle_of_the_ball() {
        let d = Delta3::THESIS;
        let mut rng = StdRng::seed_from_u64(5);
        let (mut narrower, mut compared) = (0, 0);
        for _ in 0..3000 {
            let c = Vec3::new(
                rng.random_range(-600.0..600.0),
                rng.random_range(-600.0..600.0),
                rng.random_range(-1200.0..-150.0),
            );
            let rho = rng.random_range(1.0..250.0);
            for arm in 0..3 {
                let e = ball_theta_range(&d, arm, &c, rho);
                let mut points = Vec::new();
                if let Ok(sol) = d.inverse_kinematics(&c) {
                    let u = radial(arm);
                    let w = c
                        + u * (d.e - d.f - d.rf * sol.cos[arm])
                        + Vec3::z() * (d.rf * sol.sin[arm]);
                    points.extend([c, c + w.normalize() * rho, c - w.normalize() * rho]);
                }
                for q in 0..200 {
                    let v = Vec3::from_fn(|_, _| rng.random::<Real>() * 2.0 - 1.0);
                    let depth = if q < 100 { 1.0 } else { rng.random::<Real>().cbrt() };
                    points.push(c + v.try_normalize(1e-9).unwrap_or(Vec3::z()) * (rho * depth));
                }
                for p in &points {
                    let Ok(sol) = d.inverse_kinematics(p) else { continue };
                    match e {
                        Enclosure::Range(th) => {
                            assert!(
                                th.contains(sol.theta[arm]),
                                "arm {arm} ball {c:?} {rho}: {p:?}"
                            )
                        }
                        Enclosure::Empty => panic!("arm {arm} ball {c:?} {rho}: {p:?} reachable"),
                        Enclosure::Unbounded => {}
                    }
                }
                let (lo, hi) = (c.add_scalar(-rho), c.add_scalar(rho));
                if let (Enclosure::Range(b), Enclosure::Range(q)) =
                    (e, theta_range(&d, arm, &lo, &hi, 2))
                {
                    compared += 1;
                    narrower += usize::from(b.hi - b.lo < q.hi - q.lo);
                }
            }
        }
        assert!(
            compared > 1000 && narrower * 10 > compared * 9,
            "{narrower} of {compared} narrower"
        );
    }

    /// The largest [`Sweep::radius`] of [`grid_cell_sweeps`]: no point of the robot's model
    /// moves further than this while the TCP stays in sample `sample`'s cell (mm; `INFINITY`
    /// when unknown).
    fn displacement_bound(model: &RobotModel, grid: &SampleGrid, sample: usize) -> Real {
        grid_cell_sweeps(model, grid, sample).iter().map(|s| s.radius()).fold(0.0, Real::max)
    }

    #[test]
    fn bound_exceeds_the_cube_half_diagonal_and_shrinks_with_k() {
        let mut last = Real::INFINITY;
        for k in [16, 32, 64] {
            let grid = SampleGrid::new(&Workspace::THESIS, k, &Delta3::THESIS).unwrap();
            let worst = (0..grid.cells.len())
                .filter(|&s| grid.reachable[s])
                .map(|s| displacement_bound(&RobotModel::THESIS, &grid, s))
                .fold(0.0, Real::max);
            assert!(worst.is_finite() && worst > 0.5 * grid.r * 3f64.sqrt());
            assert!(worst < last);
            last = worst;
        }
    }
}
