//! Delta3 geometry, inverse and forward kinematics (thesis 2.2 and 2.7, SPEC §2).
//!
//! # Conventions
//! Arm `i` has azimuth `phi_i = i 2 pi / 3`, radial unit `u_i`, tangent `t_i` and `z` up.
//! `F_i = f u_i` is the motor axis point, `G_i = F_i + rf (cos th_i u_i - sin th_i z)` the
//! elbow (positive `th_i` moves the elbow down), `E_i = p + e u_i` the platform joint of the
//! TCP `p`, and the loop closes when `|G_i - E_i| = re`. The assembled robot is elbow-out:
//! of the two solutions of each arm, the one with the larger `cos th_i`.
//!
//! # Numerics
//! The inverse kinematics needs no trigonometric call: `cos th` and `sin th` come from the
//! half-angle-free closed form below, and the motor limits are checked as an arc test
//! (`cos(th - mid) >= cos(half_span)`); `th` itself is one `atan2` per arm, kept for callers.

use crate::math::{Real, Vec3};
use std::f64::consts::PI;

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

impl std::fmt::Display for Unreachable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unreachable::NonFinite => write!(f, "TCP has a NaN or infinite coordinate"),
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

/// Radial unit vectors `u_i` of the three arms.
pub const ARM_RADIAL: [[Real; 2]; 3] = [
    [1.0, 0.0],
    [-0.5, 0.866_025_403_784_438_6],
    [-0.5, -0.866_025_403_784_438_6],
];

/// `u_i`, the radial unit of arm `i`.
pub fn radial(arm: usize) -> Vec3 {
    Vec3::new(ARM_RADIAL[arm][0], ARM_RADIAL[arm][1], 0.0)
}

/// `t_i`, the tangent unit of arm `i` (`z x u_i`, the motor axis direction).
pub fn tangent(arm: usize) -> Vec3 {
    Vec3::new(-ARM_RADIAL[arm][1], ARM_RADIAL[arm][0], 0.0)
}

impl Delta3 {
    /// The robot of the thesis (2.7): f = 100, rf = 150, re = 400, e = 40, default limits.
    pub const THESIS: Delta3 =
        Delta3 { f: 100.0, rf: 150.0, re: 400.0, e: 40.0, theta_min: -PI / 2.0, theta_max: 2.0 * PI / 3.0 };

    /// Checks that lengths are finite and positive and the motor range is a proper arc.
    ///
    /// # Errors
    /// A sentence naming the bad parameter.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [("f", self.f), ("rf", self.rf), ("re", self.re), ("e", self.e)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("Delta3 parameter {name} = {v} must be a positive finite length in mm"));
            }
        }
        let span = self.theta_max - self.theta_min;
        if !(self.theta_min.is_finite() && self.theta_max.is_finite() && span > 0.0 && span < 2.0 * PI) {
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
        let u = radial(arm);
        Vec3::new(u.x * (self.f + self.rf * cos_th), u.y * (self.f + self.rf * cos_th), -self.rf * sin_th)
    }

    /// `E_i`, the platform joint of arm `i` for the TCP `p`.
    pub fn platform_joint(&self, arm: usize, tcp: &Vec3) -> Vec3 {
        tcp + radial(arm) * self.e
    }

    /// Elbow-out motor angles for a TCP in the MCS.
    ///
    /// # Errors
    /// [`Unreachable`] when a coordinate is not finite, an arm cannot close its loop, or a
    /// motor would leave its limits.
    pub fn inverse_kinematics(&self, tcp: &Vec3) -> Result<ArmSolution, Unreachable> {
        if !(tcp.x.is_finite() && tcp.y.is_finite() && tcp.z.is_finite()) {
            return Err(Unreachable::NonFinite);
        }
        let mid = 0.5 * (self.theta_min + self.theta_max);
        let (cos_mid, sin_mid) = (mid.cos(), mid.sin());
        let cos_half_span = (0.5 * (self.theta_max - self.theta_min)).cos();
        let mut sol = ArmSolution { theta: [0.0; 3], cos: [0.0; 3], sin: [0.0; 3] };
        for arm in 0..3 {
            let [ux, uy] = ARM_RADIAL[arm];
            // P = E_i - F_i = p + (e - f) u_i, in the arm's (u, t, z) frame.
            let px = tcp.x + (self.e - self.f) * ux;
            let py = tcp.y + (self.e - self.f) * uy;
            let (a, b, c) = (px * ux + py * uy, -px * uy + py * ux, tcp.z);
            let r2 = a * a + c * c;
            let k = (r2 + self.rf * self.rf - (self.re * self.re - b * b)) / (2.0 * self.rf);
            if b * b > self.re * self.re || k * k > r2 || r2 == 0.0 {
                return Err(Unreachable::OutOfReach { arm: arm as u8 });
            }
            // th = -atan2(c, a) +/- acos(K / R): cos th = (a K +/- c S) / R^2 and
            // sin th = (-c K +/- a S) / R^2 with S = sqrt(R^2 - K^2); elbow-out takes the
            // sign that makes cos th larger, i.e. +/- = sign(c) (+ when c = 0).
            let s = (r2 - k * k).sqrt();
            let sign = if c < 0.0 { -1.0 } else { 1.0 };
            let cos_th = (a * k + sign * c * s) / r2;
            let sin_th = (-c * k + sign * a * s) / r2;
            let theta = sin_th.atan2(cos_th);
            if cos_th * cos_mid + sin_th * sin_mid < cos_half_span {
                return Err(Unreachable::MotorLimit { arm: arm as u8, theta });
            }
            sol.theta[arm] = theta;
            sol.cos[arm] = cos_th;
            sol.sin[arm] = sin_th;
        }
        Ok(sol)
    }

    /// The TCP for motor angles `theta`: the lower intersection of the three spheres of
    /// radius `re` around `G_i - e u_i`, or `None` when the spheres do not meet.
    pub fn forward_kinematics(&self, theta: &[Real; 3]) -> Option<Vec3> {
        let c: [Vec3; 3] = std::array::from_fn(|i| {
            self.elbow(i, theta[i].cos(), theta[i].sin()) - radial(i) * self.e
        });
        let (d1, d2) = (c[1] - c[0], c[2] - c[0]);
        let n = d1.cross(&d2);
        let (n2, d11, d22, d12) = (n.norm_squared(), d1.norm_squared(), d2.norm_squared(), d1.dot(&d2));
        if !(n2 > 0.0) {
            return None;
        }
        // q0 = alpha d1 + beta d2 with d1.q0 = |d1|^2 / 2 and d2.q0 = |d2|^2 / 2.
        let det = d11 * d22 - d12 * d12;
        let alpha = 0.5 * (d11 * d22 - d12 * d22) / det;
        let beta = 0.5 * (d11 * d22 - d12 * d11) / det;
        let q0 = d1 * alpha + d2 * beta;
        let h2 = self.re * self.re - q0.norm_squared();
        if !(h2 >= 0.0) {
            return None;
        }
        let gamma = (h2 / n2).sqrt();
        let gamma = if n.z > 0.0 { -gamma } else { gamma };
        Some(c[0] + q0 + n * gamma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn home_position_round_trips() {
        let d = Delta3::THESIS;
        let p = Vec3::new(0.0, 0.0, -450.0);
        let sol = d.inverse_kinematics(&p).unwrap();
        // Symmetric TCP on the axis: all three motors agree.
        assert!((sol.theta[0] - sol.theta[1]).abs() < 1e-12);
        let q = d.forward_kinematics(&sol.theta).unwrap();
        assert!((p - q).norm() < 1e-9, "{p} vs {q}");
    }

    #[test]
    fn far_away_tcp_is_out_of_reach() {
        let d = Delta3::THESIS;
        assert!(matches!(
            d.inverse_kinematics(&Vec3::new(0.0, 0.0, -900.0)),
            Err(Unreachable::OutOfReach { .. })
        ));
        assert_eq!(d.inverse_kinematics(&Vec3::new(f64::NAN, 0.0, -400.0)), Err(Unreachable::NonFinite));
    }
}
