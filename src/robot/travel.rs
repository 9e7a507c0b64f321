//! Where a point of a robot's box can be after the TCP moves a short way, bounded from the box
//! at the start alone, without inverse kinematics at the end. The protective check settles its
//! certain STOPs with it without building the boxes at the stop ball's centre
//! (`cell::protective`, module doc, step 6).
//!
//! # The bound (a lower link; SPEC §3's box, all in the MCS)
//! Arm `i` with radial unit `u`, tangent `t` (the motor axis) and vertical `z`: the motor point
//! `F = f u`, the elbow `G(th) = F + rf r(th)` with `r = cos th u - sin th z`, its unit tangent
//! `g = dr/dth = -sin th u - cos th z`, the platform joint `E(q) = q + e u`. The TCP moves along
//! `q(s) = p + s D`, `s` in `[0, 1]`, `d = |D|`; the motor angle follows the inverse kinematics'
//! branch `th(s)`, and the link's unit `x = (E - G) / re` keeps `|E - G| = re`.
//! 1. Differentiating `|E - G|^2 = re^2`: `x . (D - rf g th') = 0`, so
//!    `th' = (x . D) / (rf k)` with `k = x . g`; `|x'| = |D - rf g th'| / re`, and `|g'| = |th'|`.
//! 2. Hence `|k'| <= |x'| + |g'| <= d / re + d (1 / re + 1 / rf) / |k|`. While
//!    `|k| >= k0 / 2` (`k0 = |k(0)|`), `|k'| <= L = d / re + 2 d (1 / re + 1 / rf) / k0`; when
//!    `L <= k0 / 2`, `|k(s)| >= k0 - L s >= k0 / 2` on all of `[0, 1]` (the first `s` where
//!    `|k|` reached `k0 / 2` would contradict the slope bound). `k = 0` is exactly where the
//!    inverse kinematics' two roots meet (the link tangent to the elbow's circle), so the branch
//!    exists along the whole segment and ends at the root the inverse kinematics computes at
//!    `q(1)` (it takes one root by one sign throughout, and the roots never cross).
//! 3. `|th'| <= (|x . D|) / (rf k_min)`, `k_min = k0 - L`, and `|x(s) . D| <= |x0 . D| + d X1`
//!    with `X1 = (d + d / k_min) / re` the crude length of `x`'s path (`rf |th'| <= d / k_min`):
//!    `|th(s) - th(0)| <= T := (|x0 . D| + d X1) / (rf k_min)`, and `|G(1) - G(0)| <= rf T`.
//!    The code takes `1 / k_min <= (1 + 2 L / k0) / k0` (`1 / (1 - e) <= 1 + 2 e` for
//!    `e <= 1/2`): one division fewer.
//! 4. `x`'s path: `|x'| <= |D - rf th' g0| / re + rf |th'| |g - g0| / re`, where
//!    `rf th'` lies in `[-rf T, rf T]` and `|g - g0| <= T`: its length is at most
//!    `X := (max(|D - rf T g0|, |D + rf T g0|) + rf T^2) / re` (a norm is convex in `th'`).
//! 5. The frame: `tau = x . t`, `n = |x x t| = sqrt(1 - tau^2)`, `y = (t - tau x) / n`,
//!    `z_box = (x x t) / n`. For a step `dx` of `x` (perpendicular to `x`, so `|dx . t| <= n
//!    |dx|`): `|dy| <= (1 + 2 |tau| / n) |dx|` and `|dz_box| <= (1 + |tau|) / n |dx|`. Along
//!    the path `|tau| <= |tau0| + X` and `n >= n_min = sqrt(1 - (|tau0| + X)^2)`; so
//!    `|y(1) - y(0)| <= Y := X (1 + 2 tau_max / n_min)` and `|z(1) - z(0)| <= Z := X (1 +
//!    tau_max) / n_min`, with `1 / n_min` from the chords of `inverse_cosine_bound`. `n_min` well above the box's `PARALLEL_TO_MOTOR_AXIS` keeps the box
//!    built the same way at both ends.
//! 6. A body point `P = (G + E) / 2 + a x + b y + c z_box = (1/2 - a/re) G + (1/2 + a/re) E +
//!    b y + c z_box` moves by `(1/2 + a/re) D` (the platform joint's exact move) plus at most
//!    `|1/2 - a/re| rf T + |b| Y + |c| Z`.
//!
//! The platform and tool boxes translate with the TCP: their points move by exactly `D`.
//! Upper links are not bounded here (`None`).

use crate::math::{float, Real, Vec3};
use crate::robot::delta3::{radial, tangent};
use crate::robot::{BoxKind, RobotModel};

/// The smallest `k0` (the cosine between the link and the elbow's path) bounded: below it the
/// inverse kinematics loses digits (its error grows like `eps / k`) and the bound is useless.
const MIN_TANGENCY: Real = 1e-3;

/// The smallest `n_min` (the sine between the link and the motor axis) bounded: far above the
/// `1e-6` below which the box takes its other frame.
const MIN_ACROSS_MOTOR_AXIS: Real = 1e-3;

/// An upper bound on `1 / n = 1 / sqrt(1 - q)` for `q = tau^2` (step 5), mostly without a root
/// or a division: the function is convex and increasing in `q`, so below its chord over
/// `[0, Q]` for `Q` = 1/4, 1/2, 3/4 (slopes `(1 / sqrt(1 - Q) - 1) / Q`, rounded up); above
/// that the root itself, up to `n = MIN_ACROSS_MOTOR_AXIS`; `None` beyond (or for a NaN).
fn inverse_cosine_bound(q: Real) -> Option<Real> {
    let chord = |slope: Real| Some(1.0 + q * slope);
    if q <= 0.25 {
        chord(0.618_802_153_517_01)
    } else if q <= 0.5 {
        chord(0.828_427_124_746_20)
    } else if q <= 0.75 {
        chord(1.333_333_333_333_34)
    } else if q <= 1.0 - MIN_ACROSS_MOTOR_AXIS * MIN_ACROSS_MOTOR_AXIS {
        Some(1.0 / float::sqrt(1.0 - q))
    } else {
        None
    }
}

/// Where a body point is after the TCP's move `D`: at `P + along D + e`, `|e| <= spread`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointTravel {
    /// The share of the TCP's move that the point surely makes (`1/2 + a / re` on a lower link,
    /// 1 on a box that translates with the TCP).
    pub along: Real,
    /// The bound on the rest of the point's move (mm).
    pub spread: Real,
}

impl RobotModel {
    /// Bounds the move of one point of box `k` when the TCP goes from `tcp` to `tcp + step`
    /// along the straight segment (module doc), from the box's first axis `link_axis` at `tcp`
    /// (MCS; a lower link's `x`) and the point's coordinates `local` in the box's frame (within
    /// its half-extents). `None` when the bound does not hold or is not derived: an upper link,
    /// a segment that nears a singular pose (the link tangent to the elbow's path, or along the
    /// motor axis), a step too long for the bound, or a non-finite input.
    #[inline]
    pub fn point_travel(
        &self,
        k: usize,
        tcp: &Vec3,
        step: &Vec3,
        link_axis: &Vec3,
        local: &Vec3,
    ) -> Option<PointTravel> {
        let arm = match self.box_kind(k) {
            BoxKind::Platform | BoxKind::Tool => return Some(PointTravel { along: 1.0, spread: 0.0 }),
            BoxKind::UpperLink(_) => return None,
            BoxKind::LowerLink(arm) => arm as usize,
        };
        let dl = &self.delta;
        let (u, t, d) = (radial(arm), tangent(arm), step.norm());
        let (inv_re, inv_rf) = (1.0 / dl.re, 1.0 / dl.rf);
        // The elbow from the link: G = E - re x, and r = (G - F) / rf.
        let elbow = tcp + u * dl.e - link_axis * dl.re;
        let r = (elbow - u * dl.f) * inv_rf;
        let g0 = u * r.z - Vec3::z() * r.dot(&u);
        let k0 = link_axis.dot(&g0).abs();
        let inv_k0 = 1.0 / k0;
        let slope = d * (inv_re + 2.0 * (inv_re + inv_rf) * inv_k0);
        // Written so that a NaN fails too.
        if !(k0 >= MIN_TANGENCY && slope <= 0.5 * k0) {
            return None;
        }
        // 1 / k_min = (1 / k0) / (1 - slope / k0) <= (1 + 2 slope / k0) / k0 for slope <= k0 / 2:
        // one division fewer on the way to the bound.
        let inv_k_min = inv_k0 * (1.0 + 2.0 * slope * inv_k0);
        let x1 = d * (1.0 + inv_k_min) * inv_re;
        let turn = (link_axis.dot(step).abs() + d * x1) * inv_k_min * inv_rf;
        let elbow_move = dl.rf * turn;
        // max(|D - m g0|, |D + m g0|)^2 = d^2 + m^2 + 2 m |D . g0| (|g0| = 1, m = rf T).
        let widest = d * d + elbow_move * elbow_move + 2.0 * elbow_move * step.dot(&g0).abs();
        let x = (float::sqrt(widest) + elbow_move * turn) * inv_re;
        let tau = link_axis.dot(&t).abs() + x;
        let inv_n = inverse_cosine_bound(tau * tau)?;
        let (y, z) = (x * (1.0 + 2.0 * tau * inv_n), x * (1.0 + tau) * inv_n);
        let a = local.x * inv_re;
        let spread = (0.5 - a).abs() * elbow_move + local.y.abs() * y + local.z.abs() * z;
        spread.is_finite().then_some(PointTravel { along: 0.5 + a, spread })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Obb;
    use crate::robot::ModelOptions;
    use crate::test_rng::TestRng;

    /// A value uniform in `[lo, hi)`.
    fn uniform(rng: &mut TestRng, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * 0.5 * (rng.unit() + 1.0)
    }

    /// The body point at `local` of box `b`.
    fn point(b: &Obb, local: &Vec3) -> Vec3 {
        b.center + b.axes * local
    }

    /// A reachable TCP at random; with `edge`, moved outward along a random direction by
    /// bisection to within `1e-6` mm of where the inverse kinematics fails.
    fn tcp_near_edge(model: &RobotModel, rng: &mut TestRng, edge: bool) -> Option<Vec3> {
        let p = Vec3::new(uniform(rng, -500.0, 500.0), uniform(rng, -500.0, 500.0), uniform(rng, -700.0, -150.0));
        model.boxes(&p).ok()?;
        if !edge {
            return Some(p);
        }
        let dir = Vec3::new(uniform(rng, -1.0, 1.0), uniform(rng, -1.0, 1.0), uniform(rng, -1.0, 1.0));
        let (mut lo, mut hi) = (0.0, 2000.0);
        model.boxes(&(p + dir * hi)).err()?;
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if model.boxes(&(p + dir * mid)).is_ok() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(p + dir * lo)
    }

    /// Checked against the boxes built at both ends by the inverse kinematics (the oracle): at
    /// random and at the workspace's edge (where the link nears the elbow's tangent), with
    /// steps up to 40 mm, corners, face centres and random points of the lower links and the
    /// platform lie where the bound says; the bound is nearly reached.
    #[test]
    fn points_move_within_the_bound() {
        let options = ModelOptions {
            margin: 5.0,
            platform: Some(crate::robot::ToolBox {
                offset: Vec3::new(0.0, 0.0, -20.0),
                half: Vec3::new(60.0, 60.0, 15.0),
            }),
            ..ModelOptions::THESIS
        };
        let mut rng = TestRng(41);
        let (mut checked, mut bounded, mut worst) = (0, 0, 0.0_f64);
        for model in [RobotModel::THESIS, RobotModel { options, ..RobotModel::THESIS }] {
            let mut tried = 0;
            while tried < 40_000 {
                let Some(p) = tcp_near_edge(&model, &mut rng, tried % 2 == 1) else { continue };
                tried += 1;
                let len = [40.0, 10.0, 2.5, 1e-3][tried % 4] * uniform(&mut rng, 0.0, 1.0);
                let dir =
                    Vec3::new(uniform(&mut rng, -1.0, 1.0), uniform(&mut rng, -1.0, 1.0), uniform(&mut rng, -1.0, 1.0));
                let step = dir.try_normalize(0.0).map_or(Vec3::zeros(), |v| v * len);
                let (Ok(start), Ok(end)) = (model.boxes(&p), model.boxes(&(p + step))) else { continue };
                for k in 0..start.len {
                    let (b0, b1) = (&start.as_slice()[k], &end.as_slice()[k]);
                    let half = b0.half;
                    // Corners, face centres and random points.
                    let pick = |rng: &mut TestRng| match uniform(rng, 0.0, 3.0) as u32 {
                        0 => half.map(|h| if uniform(rng, 0.0, 1.0) < 0.5 { -h } else { h }),
                        1 => Vec3::new(half.x, 0.0, 0.0) * if uniform(rng, 0.0, 1.0) < 0.5 { -1.0 } else { 1.0 },
                        _ => half.map(|h| uniform(rng, -h, h)),
                    };
                    let axis = b0.axes.column(0).into_owned();
                    for _ in 0..4 {
                        let local = pick(&mut rng);
                        let Some(travel) = model.point_travel(k, &p, &step, &axis, &local) else { continue };
                        let moved = point(b1, &local) - point(b0, &local) - step * travel.along;
                        assert!(
                            moved.norm() <= travel.spread + 1e-9,
                            "box {k} at {p:?} step {step:?} local {local:?}: off {} > {}",
                            moved.norm(),
                            travel.spread
                        );
                        if step.norm() > 0.1 {
                            worst = worst.max(moved.norm() / travel.spread.max(1e-12));
                        }
                        bounded += 1;
                    }
                    checked += 4;
                }
            }
        }
        std::eprintln!("{bounded} of {checked} points bounded; largest move / bound with steps over 0.1 mm {worst:.3}");
        // The bound must be useful, not only true: most points away from singular poses.
        assert!(bounded * 2 > checked, "{bounded} of {checked}");
        // And tight: some point moves nearly as far as its bound.
        assert!(worst > 0.9, "largest move / bound {worst}");
    }

    /// At round numbers: the TCP on the axis, a step straight down and one sideways; the
    /// platform translates exactly, the upper links are not bounded, a zero step moves nothing.
    #[test]
    fn round_numbers_and_kinds() {
        let model = RobotModel::THESIS;
        let p = Vec3::new(0.0, 0.0, -400.0);
        let start = model.boxes(&p).unwrap();
        for step in [Vec3::new(0.0, 0.0, -10.0), Vec3::new(10.0, 0.0, 0.0), Vec3::zeros()] {
            let end = model.boxes(&(p + step)).unwrap();
            for k in 0..3 {
                let (b0, b1) = (&start.as_slice()[k], &end.as_slice()[k]);
                let local = b0.half;
                let travel = model.point_travel(k, &p, &step, &b0.axes.column(0).into_owned(), &local).unwrap();
                let moved = point(b1, &local) - point(b0, &local) - step * travel.along;
                assert!(moved.norm() <= travel.spread + 1e-9, "{k} {step:?}");
                if step == Vec3::zeros() {
                    assert_eq!(travel.spread, 0.0);
                }
            }
        }
        let axis = Vec3::x();
        let upper =
            RobotModel { options: ModelOptions { upper_links: Some((20.0, 20.0)), ..ModelOptions::THESIS }, ..model };
        assert_eq!(upper.point_travel(3, &p, &Vec3::x(), &axis, &Vec3::zeros()), None);
        assert_eq!(model.point_travel(0, &p, &Vec3::new(Real::NAN, 0.0, 0.0), &axis, &Vec3::zeros()), None);
    }
}
