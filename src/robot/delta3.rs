//! Delta3 geometry, inverse and forward kinematics (thesis 2.2 and 2.7, SPEC §2).
//!
//! # Conventions
//! Arm `i` has azimuth `phi_i = i 2 pi / 3`, radial unit `u_i`, tangent `t_i` and `z` up.
//! `F_i = f u_i` is the motor axis point, `G_i = F_i + rf (cos th_i u_i - sin th_i z)` the
//! elbow (positive `th_i` moves the elbow down), `E_i = p + e u_i` the platform joint of the
//! TCP `p`, and the loop closes when `|G_i - E_i| = re`. The assembled robot is elbow-out:
//! of the two solutions of each arm, the one with the larger `cos th_i` (no tie: they tie
//! only for a TCP level with the motor axes, and the TCP must be below the base).
//! Motor angles are normalised to (-pi, pi]; a motor is within its limits when `th_i` lies on
//! the arc from `theta_min` to `theta_max`, i.e. `(th - theta_min) mod 2 pi <= theta_max -
//! theta_min` (the plain interval test when both limits lie in (-pi, pi], as they should).
//! A TCP must also lie below the base plane (`z < 0`, SPEC §1): above it the loop equations
//! still close, with the platform through the base frame.
//!
//! # Numerics
//! The inverse kinematics needs no trigonometric call on its fast path: `cos th` and `sin th`
//! come from the closed form below, and the limit test first uses a cheap approximate angle
//! (error < [`APPROX_ANGLE_MAX_ERROR`]); only when that lands within [`LIMIT_FAST_MARGIN`] of a
//! limit is the exact `atan2` taken. [`Delta3::inverse_kinematics_cos_sin`] stops there;
//! [`Delta3::inverse_kinematics`] adds one `atan2` per arm for the angles themselves.

use crate::math::{float, Real, Vec3, MAX_LENGTH};
use alloc::{format, string::String};
use core::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Parameters of one Delta3 robot, in mm and rad (SPEC §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delta3 {
    /// MCS origin to motor axis point `F_i`.
    pub f: Real,
    /// Upper link length, `F_i` to elbow `G_i`.
    pub rf: Real,
    /// Lower link length, `G_i` to `E_i`.
    pub re: Real,
    /// TCP to platform joint `E_i`.
    pub e: Real,
    /// Lower motor limit (rad).
    pub theta_min: Real,
    /// Upper motor limit (rad).
    pub theta_max: Real,
}

/// Why a TCP cannot be reached; `arm` is 0, 1 or 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unreachable {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// The TCP is not below the base plane (`z >= 0`; SPEC §1: the TCP works below the base).
    AboveBase,
    /// The lower link of `arm` cannot span the distance (`b^2 > re^2` or `|K| > R`).
    OutOfReach {
        /// The arm that cannot close its loop.
        arm: u8,
    },
    /// The elbow-out solution of `arm` lies outside the motor limits.
    MotorLimit {
        /// The arm whose motor would leave its range.
        arm: u8,
        /// The angle it would need (rad).
        theta: Real,
    },
}

impl core::fmt::Display for Unreachable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Unreachable::NonFinite => write!(f, "TCP has a NaN or infinite coordinate"),
            Unreachable::AboveBase => {
                write!(f, "TCP is not below the base plane (z must be negative)")
            }
            Unreachable::OutOfReach { arm } => write!(f, "arm {arm} cannot reach the TCP"),
            Unreachable::MotorLimit { arm, theta } => {
                write!(f, "arm {arm} would need motor angle {theta:.4} rad, outside its limits")
            }
        }
    }
}

/// The elbow-out inverse kinematics of one TCP: motor angles with their cosines and sines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmSolution {
    /// Motor angles `th_i` in (-pi, pi].
    pub theta: [Real; 3],
    /// `cos th_i`.
    pub cos: [Real; 3],
    /// `sin th_i`.
    pub sin: [Real; 3],
}

/// The elbow-out solution without the angles: `cos th_i` and `sin th_i`, all the box model needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorCosSin {
    /// `cos th_i`.
    pub cos: [Real; 3],
    /// `sin th_i`.
    pub sin: [Real; 3],
}

impl MotorCosSin {
    /// The motor angle of `arm`, normalised to (-pi, pi].
    pub fn theta(&self, arm: usize) -> Real {
        normalized_angle(self.cos[arm], self.sin[arm])
    }

    /// The full solution, with the three angles.
    pub fn with_angles(&self) -> ArmSolution {
        ArmSolution { theta: core::array::from_fn(|i| self.theta(i)), cos: self.cos, sin: self.sin }
    }
}

/// Radial unit vectors `u_i` of the three arms.
pub const ARM_RADIAL: [[Real; 2]; 3] =
    [[1.0, 0.0], [-0.5, 0.866_025_403_784_438_6], [-0.5, -0.866_025_403_784_438_6]];

/// Bound on the error of the approximate angle used by the fast motor-limit test (rad).
pub const APPROX_ANGLE_MAX_ERROR: Real = 2e-3;

/// An approximate angle at least this far (rad) inside both limits is accepted without `atan2`.
pub const LIMIT_FAST_MARGIN: Real = 1e-2;

const _: () =
    assert!(APPROX_ANGLE_MAX_ERROR < LIMIT_FAST_MARGIN, "the fast limit test must be conservative");

/// `u_i`, the radial unit of arm `i`.
pub fn radial(arm: usize) -> Vec3 {
    Vec3::new(ARM_RADIAL[arm][0], ARM_RADIAL[arm][1], 0.0)
}

/// `t_i`, the tangent unit of arm `i` (`z x u_i`, the motor axis direction).
pub fn tangent(arm: usize) -> Vec3 {
    Vec3::new(-ARM_RADIAL[arm][1], ARM_RADIAL[arm][0], 0.0)
}

/// `atan2(sin, cos)` mapped to (-pi, pi] (`-pi` becomes `pi`).
fn normalized_angle(cos: Real, sin: Real) -> Real {
    let th = float::atan2(sin, cos);
    if th <= -PI {
        PI
    } else {
        th
    }
}

/// `atan2(sin, cos)` to within [`APPROX_ANGLE_MAX_ERROR`], without a library call (octant
/// reduction and the fit `atan x ~ pi/4 x - x (x - 1)(0.2447 + 0.0663 x)`); the arguments
/// need not be normalised. NaN when both are zero or one is NaN.
#[inline]
pub fn approx_angle(cos: Real, sin: Real) -> Real {
    let (ac, as_) = (cos.abs(), sin.abs());
    let fit = |x: Real| FRAC_PI_4 * x - x * (x - 1.0) * (0.2447 + 0.0663 * x);
    // Selects rather than min/max, so that a NaN in either argument reaches the result.
    let (num, den) = if ac >= as_ { (as_, ac) } else { (ac, as_) };
    let x = fit(num / den);
    let mut a = if ac >= as_ { x } else { FRAC_PI_2 - x };
    if cos < 0.0 {
        a = PI - a;
    }
    if sin < 0.0 {
        -a
    } else {
        a
    }
}

impl Delta3 {
    /// The robot of the thesis (2.7): f = 100, rf = 150, re = 400, e = 40, default limits.
    pub const THESIS: Delta3 = Delta3 {
        f: 100.0,
        rf: 150.0,
        re: 400.0,
        e: 40.0,
        theta_min: -PI / 2.0,
        theta_max: 2.0 * PI / 3.0,
    };

    /// Checks that lengths are finite and positive and the motor range is a proper arc.
    ///
    /// # Errors
    /// A sentence naming the bad parameter.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [("f", self.f), ("rf", self.rf), ("re", self.re), ("e", self.e)] {
            if !(v.is_finite() && v > 0.0 && v <= MAX_LENGTH) {
                return Err(format!(
                    "Delta3 parameter {name} = {v} must be a length in (0, {MAX_LENGTH:e}] mm"
                ));
            }
        }
        let span = self.theta_max - self.theta_min;
        if !(self.theta_min.is_finite()
            && self.theta_max.is_finite()
            && span > 0.0
            && span < 2.0 * PI)
        {
            return Err(format!(
                "motor limits [{}, {}] rad must be finite with 0 < theta_max - theta_min < 2 pi",
                self.theta_min, self.theta_max
            ));
        }
        Ok(())
    }

    /// `F_i`, the motor axis point of arm `i`, in the MCS.
    pub fn motor_point(&self, arm: usize) -> Vec3 {
        radial(arm) * self.f
    }

    /// `G_i`, the elbow of arm `i` for a motor angle given by its cosine and sine.
    pub fn elbow(&self, arm: usize, cos_th: Real, sin_th: Real) -> Vec3 {
        let [ux, uy] = ARM_RADIAL[arm];
        let r = self.f + self.rf * cos_th;
        Vec3::new(ux * r, uy * r, -self.rf * sin_th)
    }

    /// `E_i`, the platform joint of arm `i` for the TCP `p`.
    pub fn platform_joint(&self, arm: usize, tcp: &Vec3) -> Vec3 {
        tcp + radial(arm) * self.e
    }

    /// Whether an angle known to within [`APPROX_ANGLE_MAX_ERROR`] is surely within the limits.
    #[inline]
    fn clearly_within_limits(&self, approx: Real) -> bool {
        approx >= self.theta_min + LIMIT_FAST_MARGIN && approx <= self.theta_max - LIMIT_FAST_MARGIN
    }

    /// Whether the motor angle with this cosine and sine lies within the limits; `Err` carries
    /// the exact angle when it does not (NaN inputs give `Err(NaN)`).
    pub fn motor_within_limits(&self, cos_th: Real, sin_th: Real) -> Result<(), Real> {
        if self.clearly_within_limits(approx_angle(cos_th, sin_th)) {
            return Ok(());
        }
        let theta = normalized_angle(cos_th, sin_th);
        if float::rem_euclid(theta - self.theta_min, TAU) <= self.theta_max - self.theta_min {
            Ok(())
        } else {
            Err(theta)
        }
    }

    /// Elbow-out `cos th_i` and `sin th_i` for a TCP in the MCS, limits checked (SPEC §2).
    ///
    /// # Errors
    /// [`Unreachable`] when a coordinate is not finite, the TCP is not below the base plane
    /// (`z >= 0`), an arm cannot close its loop, or a motor would leave its limits; the first
    /// failing arm (0, 1, 2 in order) is reported.
    pub fn inverse_kinematics_cos_sin(&self, tcp: &Vec3) -> Result<MotorCosSin, Unreachable> {
        let mut out = MotorCosSin { cos: [0.0; 3], sin: [0.0; 3] };
        self.solve::<true>(tcp, &mut out)?;
        Ok(out)
    }

    /// The inverse kinematics, arm by arm; with `OUT` the cosines and sines are written to
    /// `out`, without it only reachability is decided, by the very same tests on the very same
    /// values (the division by `R^2` is then taken only where the exact limit test needs it).
    #[inline(always)]
    fn solve<const OUT: bool>(&self, tcp: &Vec3, out: &mut MotorCosSin) -> Result<(), Unreachable> {
        if !(tcp.x.is_finite() && tcp.y.is_finite() && tcp.z.is_finite()) {
            return Err(Unreachable::NonFinite);
        }
        // The loop equations alone would also close above the base, through the base frame.
        if tcp.z >= 0.0 {
            return Err(Unreachable::AboveBase);
        }
        let (re2, rf2, ef) = (self.re * self.re, self.rf * self.rf, self.e - self.f);
        let half_inv_rf = 0.5 / self.rf;
        let c = tcp.z;
        for (arm, &[ux, uy]) in ARM_RADIAL.iter().enumerate() {
            // P = E_i - F_i = p + (e - f) u_i, in the arm's (u, t, z) frame: (a, b, c).
            let a = tcp.x * ux + tcp.y * uy + ef;
            let b = -tcp.x * uy + tcp.y * ux;
            let r2 = a * a + c * c;
            let k = (r2 + rf2 - (re2 - b * b)) * half_inv_rf;
            // Written so that NaN (from overflowing squares) fails too.
            if !(b * b <= re2 && k * k <= r2 && r2 > 0.0) {
                return Err(Unreachable::OutOfReach { arm: arm as u8 });
            }
            // th = -atan2(c, a) +/- acos(K / R): cos th = (a K +/- c S) / R^2 and
            // sin th = (-c K +/- a S) / R^2 with S = sqrt(R^2 - K^2); elbow-out takes the
            // sign that makes cos th larger, +/- = sign(c), and c = z < 0 here: minus.
            let s = -float::sqrt(r2 - k * k);
            let (cos_n, sin_n) = (a * k + c * s, a * s - c * k); // R^2 (cos th, sin th)
                                                                 // The approximate angle is
                                                                 // scale-free: it needs no 1 / R^2
                                                                 // and runs beside it.
            let fast_ok = self.clearly_within_limits(approx_angle(cos_n, sin_n));
            if OUT || !fast_ok {
                let inv_r2 = 1.0 / r2;
                let (cos_th, sin_th) = (cos_n * inv_r2, sin_n * inv_r2);
                if !fast_ok {
                    if let Err(theta) = self.motor_within_limits(cos_th, sin_th) {
                        if theta.is_nan() {
                            return Err(Unreachable::OutOfReach { arm: arm as u8 });
                        }
                        return Err(Unreachable::MotorLimit { arm: arm as u8, theta });
                    }
                }
                if OUT {
                    out.cos[arm] = cos_th;
                    out.sin[arm] = sin_th;
                }
            }
        }
        Ok(())
    }

    /// Elbow-out motor angles for a TCP in the MCS (SPEC §2), with their cosines and sines.
    ///
    /// # Errors
    /// As [`Delta3::inverse_kinematics_cos_sin`].
    pub fn inverse_kinematics(&self, tcp: &Vec3) -> Result<ArmSolution, Unreachable> {
        Ok(self.inverse_kinematics_cos_sin(tcp)?.with_angles())
    }

    /// Whether the TCP (MCS) is reachable: every loop closes and every motor is within limits.
    ///
    /// The same tests on the same values as [`Delta3::inverse_kinematics_cos_sin`], without
    /// writing the cosines and sines (a table lookup needs only the verdict).
    pub fn is_reachable(&self, tcp: &Vec3) -> bool {
        let mut unused = MotorCosSin { cos: [0.0; 3], sin: [0.0; 3] };
        self.solve::<false>(tcp, &mut unused).is_ok()
    }

    /// The TCP for motor angles `theta`: the lower intersection (smaller z) of the three
    /// spheres of radius `re` around `C_i = G_i - e u_i`. `None` when an angle is not finite,
    /// the spheres do not meet, their centres are collinear, the plane of the centres is
    /// vertical (no lower intersection), or the point overflows (a length near `f64::MAX`).
    /// Motor limits are not checked.
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // written so that NaN fails the tests
    pub fn forward_kinematics(&self, theta: &[Real; 3]) -> Option<Vec3> {
        let c: [Vec3; 3] = core::array::from_fn(|i| {
            let (s, co) = float::sin_cos(theta[i]);
            self.elbow(i, co, s) - radial(i) * self.e
        });
        let (d1, d2) = (c[1] - c[0], c[2] - c[0]);
        let n = d1.cross(&d2);
        let n2 = n.norm_squared();
        let scale2 = d1.norm_squared().max(d2.norm_squared());
        // Collinear (or non-finite) centres, or a vertical plane: no unique lower point.
        if !(n2 > 1e-20 * scale2 * scale2) || n.z == 0.0 {
            return None;
        }
        // Circumcentre of the triangle relative to C_0 (Lagrange's identity: det = |n|^2):
        // q0 = (|d1|^2 (d2 x n) + |d2|^2 (n x d1)) / (2 |n|^2).
        let q0 = (d2.cross(&n) * d1.norm_squared() + n.cross(&d1) * d2.norm_squared()) * (0.5 / n2);
        let h2 = self.re * self.re - q0.norm_squared();
        if !(h2 >= 0.0) {
            return None;
        }
        let gamma = float::sqrt(h2 / n2);
        let gamma = if n.z > 0.0 { -gamma } else { gamma };
        let p = c[0] + q0 + n * gamma;
        p.iter().all(|v| v.is_finite()).then_some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// Uniform in [0, 1): the same TCPs on every run.
    fn next(rng: &mut TestRng) -> Real {
        0.5 * (rng.unit() + 1.0)
    }

    /// `is_reachable` decides exactly as the inverse kinematics does, on random TCPs in and
    /// around the workspace, on TCPs within an ulp of the reach boundary (bisection between a
    /// reachable and an unreachable TCP), with a motor at or an ulp beyond either limit
    /// (forward kinematics from a limit angle), and on non-finite or above-base TCPs; for the
    /// thesis robot and for narrow limits that make the motor limits bind often.
    #[test]
    fn is_reachable_decides_as_the_inverse_kinematics() {
        let narrow = Delta3 { theta_min: -0.3, theta_max: 0.9, ..Delta3::THESIS };
        let wide = Delta3 { theta_min: -PI + 1e-3, theta_max: PI, ..Delta3::THESIS };
        let mut rng = TestRng(0x9e37_79b9_7f4a_7c15);
        let (mut reachable, mut unreachable, mut at_boundary) = (0, 0, 0);
        for d in [Delta3::THESIS, narrow, wide] {
            let agree = |p: &Vec3| {
                let ik = d.inverse_kinematics_cos_sin(p).is_ok();
                assert_eq!(d.is_reachable(p), ik, "{d:?} at {p:?}");
                ik
            };
            let home = Vec3::new(0.0, 0.0, -450.0);
            for _ in 0..50_000 {
                let p =
                    Vec3::new(350.0 * rng.unit(), 350.0 * rng.unit(), -350.0 * rng.unit() - 300.0);
                if agree(&p) {
                    reachable += 1;
                } else {
                    unreachable += 1;
                    // The boundary on the segment from home (reachable for all three) to p.
                    if !agree(&home) {
                        continue;
                    }
                    let (mut lo, mut hi) = (home, p);
                    for _ in 0..80 {
                        let mid = (lo + hi) * 0.5;
                        if agree(&mid) {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    at_boundary += 1;
                    for q in [lo, hi, lo.map(|v| v.next_up()), hi.map(|v| v.next_down())] {
                        agree(&q);
                    }
                }
            }
            // A motor exactly at a limit and one ulp either side of it, the others random.
            for i in 0..3000 {
                let span = d.theta_max - d.theta_min;
                let mut theta: [Real; 3] =
                    core::array::from_fn(|_| d.theta_min + span * next(&mut rng));
                let limit = if i % 2 == 0 { d.theta_min } else { d.theta_max };
                for th in [limit, limit.next_up(), limit.next_down()] {
                    theta[i % 3] = th;
                    if let Some(p) = d.forward_kinematics(&theta) {
                        agree(&p);
                        agree(&p.map(|v| v.next_up()));
                        agree(&p.map(|v| v.next_down()));
                    }
                }
            }
            for p in [
                Vec3::new(f64::NAN, 0.0, -400.0),
                Vec3::new(0.0, f64::INFINITY, -400.0),
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(1e300, 0.0, -1e300),
                Vec3::new(0.0, 0.0, -f64::MIN_POSITIVE),
            ] {
                assert!(!agree(&p), "{p:?}");
            }
        }
        assert!(
            reachable > 2_000 && at_boundary > 2_000,
            "{reachable} {unreachable} {at_boundary}"
        );
    }

    #[test]
    fn home_position_round_trips() {
        let d = Delta3::THESIS;
        let p = Vec3::new(0.0, 0.0, -450.0);
        let sol = d.inverse_kinematics(&p).unwrap();
        // Symmetric TCP on the axis: all three motors agree.
        assert!((sol.theta[0] - sol.theta[1]).abs() < 1e-12);
        assert!((sol.theta[0] - sol.theta[2]).abs() < 1e-12);
        let q = d.forward_kinematics(&sol.theta).unwrap();
        assert!((p - q).norm() < 1e-9, "{p} vs {q}");
    }

    #[test]
    fn home_position_matches_hand_computation() {
        // On the axis: a = e - f = -60, b = 0, c = -450. K = (60^2 + 450^2 + 150^2 - 400^2) / 300.
        let d = Delta3::THESIS;
        let (a, c): (Real, Real) = (-60.0, -450.0);
        let k = (a * a + c * c + 150.0 * 150.0 - 400.0 * 400.0) / 300.0;
        let r = a.hypot(c);
        let th1 = -c.atan2(a) + (k / r).acos();
        let th2 = -c.atan2(a) - (k / r).acos();
        let wrap = |t: Real| (t + PI).rem_euclid(TAU) - PI;
        let expected = if th1.cos() > th2.cos() { wrap(th1) } else { wrap(th2) };
        let sol = d.inverse_kinematics(&Vec3::new(0.0, 0.0, -450.0)).unwrap();
        assert!((sol.theta[0] - expected).abs() < 1e-12, "{} vs {expected}", sol.theta[0]);
        assert!(
            (sol.cos[0] - expected.cos()).abs() < 1e-12
                && (sol.sin[0] - expected.sin()).abs() < 1e-12
        );
    }

    #[test]
    fn every_arm_closes_its_loop() {
        let d = Delta3::THESIS;
        for p in [
            Vec3::new(120.0, -80.0, -420.0),
            Vec3::new(-150.0, 30.0, -480.0),
            Vec3::new(0.0, 210.0, -380.0),
        ] {
            let sol = d.inverse_kinematics(&p).unwrap();
            for arm in 0..3 {
                let g = d.elbow(arm, sol.cos[arm], sol.sin[arm]);
                let len = (g - d.platform_joint(arm, &p)).norm();
                assert!((len - d.re).abs() < 1e-9, "arm {arm}: |GE| = {len}");
                assert!((sol.cos[arm] - sol.theta[arm].cos()).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn far_away_tcp_is_out_of_reach() {
        let d = Delta3::THESIS;
        assert!(matches!(
            d.inverse_kinematics(&Vec3::new(0.0, 0.0, -900.0)),
            Err(Unreachable::OutOfReach { .. })
        ));
        assert_eq!(d.inverse_kinematics(&Vec3::new(0.0, 0.0, 0.0)), Err(Unreachable::AboveBase));
        // The loops would close here (elbows down, links pointing up through the base).
        assert_eq!(d.inverse_kinematics(&Vec3::new(0.0, 0.0, 300.0)), Err(Unreachable::AboveBase));
        assert!(matches!(
            d.inverse_kinematics(&Vec3::new(1e200, 0.0, -400.0)),
            Err(Unreachable::OutOfReach { .. })
        ));
        assert!(matches!(
            d.inverse_kinematics(&Vec3::new(0.0, -1e200, -1e200)),
            Err(Unreachable::OutOfReach { .. })
        ));
        assert_eq!(
            d.inverse_kinematics(&Vec3::new(f64::NAN, 0.0, -400.0)),
            Err(Unreachable::NonFinite)
        );
        assert_eq!(
            d.inverse_kinematics(&Vec3::new(0.0, f64::INFINITY, -400.0)),
            Err(Unreachable::NonFinite)
        );
        assert!(!d.is_reachable(&Vec3::new(0.0, 0.0, -900.0)));
        assert!(d.is_reachable(&Vec3::new(0.0, 0.0, -450.0)));
    }

    #[test]
    fn tightened_limit_reports_the_needed_angle() {
        let p = Vec3::new(0.0, 0.0, -450.0);
        let th = Delta3::THESIS.inverse_kinematics(&p).unwrap().theta[0];
        let below = Delta3 { theta_max: th - 1e-6, ..Delta3::THESIS };
        match below.inverse_kinematics(&p) {
            Err(Unreachable::MotorLimit { arm: 0, theta }) => assert!((theta - th).abs() < 1e-12),
            other => panic!("expected a motor limit on arm 0, got {other:?}"),
        }
        let above = Delta3 { theta_min: th + 1e-6, theta_max: th + 1.0, ..Delta3::THESIS };
        assert!(matches!(
            above.inverse_kinematics(&p),
            Err(Unreachable::MotorLimit { arm: 0, .. })
        ));
        // Exactly on a limit is within it.
        let on = Delta3 { theta_max: th, ..Delta3::THESIS };
        assert!(on.inverse_kinematics(&p).is_ok());
    }

    #[test]
    fn limits_are_an_arc() {
        let d = Delta3 { theta_min: 2.5, theta_max: 4.0, ..Delta3::THESIS };
        // -3.0 rad is 3.28 rad on the circle, inside [2.5, 4.0]; 0 is not.
        assert!(d.motor_within_limits((-3.0f64).cos(), (-3.0f64).sin()).is_ok());
        assert!(d.motor_within_limits(1.0, 0.0).is_err());
        assert!(d.motor_within_limits(f64::NAN, 0.0).unwrap_err().is_nan());
    }

    #[test]
    fn approximate_angle_propagates_nan() {
        for (c, s) in [
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
            (f64::NAN, 0.0),
            (0.0, 0.0),
            (f64::INFINITY, f64::NAN),
        ] {
            assert!(approx_angle(c, s).is_nan(), "({c}, {s})");
        }
        assert!((approx_angle(-3.0, 4.0) - 4.0f64.atan2(-3.0)).abs() < APPROX_ANGLE_MAX_ERROR);
    }

    #[test]
    fn approximate_angle_is_within_its_bound() {
        let mut worst: Real = 0.0;
        for i in 0..=200_000 {
            let t = -PI + TAU * i as Real / 200_000.0;
            let err = (approx_angle(t.cos(), t.sin()) - t).abs();
            // Near +/- pi the two ends of the circle are the same angle.
            worst = worst.max(err.min((err - TAU).abs()));
        }
        assert!(worst < APPROX_ANGLE_MAX_ERROR, "worst error {worst}");
    }

    #[test]
    fn theta_is_normalised_to_the_half_open_interval() {
        assert_eq!(normalized_angle(-1.0, -0.0), PI);
        assert_eq!(normalized_angle(-1.0, 0.0), PI);
        assert_eq!(normalized_angle(1.0, 0.0), 0.0);
    }

    #[test]
    fn forward_kinematics_rejects_degenerate_input() {
        let d = Delta3::THESIS;
        assert_eq!(d.forward_kinematics(&[f64::NAN, 0.0, 0.0]), None);
        // Horizontal upper links: the centres lie 210 mm from the axis, beyond a 10 mm lower link.
        let short = Delta3 { re: 10.0, ..d };
        assert_eq!(short.forward_kinematics(&[0.0, 0.0, 0.0]), None);
        let p = d.forward_kinematics(&[0.3, 0.3, 0.3]).unwrap();
        assert!(p.x.abs() < 1e-9 && p.y.abs() < 1e-9 && p.z < 0.0);
    }
}
