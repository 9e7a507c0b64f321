//! The closest points of two boxes swept by graded balls
//! ([`Sweep::graded_ball`](crate::geometry::Sweep::graded_ball)): the points `x` of box `a`
//! and `y` of box `b` that minimise `F(x, y) = |x - y| - r_a(x) - r_b(y)`, where
//! `r(x)` is the graded radius at `x` (`r_0` at the box's face at `-half_0 u_0`, growing
//! linearly along `u_0` to `r_1` at the face at `+half_0 u_0`). The protective verdict uses
//! them twice (module doc of `cell::protective`, steps 5 and 6):
//!
//! - **A certificate that the swept sets meet.** The set of box `a` swept by its graded ball
//!   holds the ball of radius `r_a(x)` around each of its points `x`. When
//!   `|x - y| <= r_a(x) + r_b(y) - 2 MEET_DEPTH` for some pair, the point of the segment `x y`
//!   at `r_a / (r_a + r_b)` of the way lies in both sets, more than `MEET_DEPTH` inside one of
//!   them, so on every axis `n` their projections overlap by more than `MEET_DEPTH |n|`: no
//!   axis separates them ([`GradedClosest::meet`]).
//! - **An axis that separates them when they are apart.** The separating axis theorem for two
//!   boxes needs 15 axes; two swept boxes are not boxes, and the axis that separates them is
//!   the direction between their closest points. `F` is convex (a norm less two affine
//!   functions), and at its minimum `(x*, y*)` over the two boxes, with `n = y* - x*`, the
//!   first-order condition for `x` reads `(x - x*) . (-n / |n| - grad r_a) >= 0` for every `x`
//!   of `a`: `x . n / |n| + r_a(x) <= x* . n / |n| + r_a(x*)`, so along `n` the swept set of
//!   `a` reaches no further than `x* . n / |n| + r_a(x*)`, and likewise that of `b` from the
//!   other side: the gap along `n` is `F(x*, y*)` itself. Any axis is sound for a proof (a
//!   swept-box test checks its own gap), so points near the minimum are all that is needed.
//!
//! # The minimisation
//! Alternating exact minimisation: `x` for the `y` at hand, then `y` for that `x`, from the
//! point of `a` nearest a given point. For fixed `y`, in the box's frame (`t` along `u_0`,
//! `g = (r_1 - r_0) / (2 half_0)` the radius's slope), the cross-section's coordinates take
//! `y`'s, clamped (they enter only `|x - y|`), leaving `rho` across; then
//! `sqrt((t - y_0)^2 + rho^2) - g t` is convex in `t`, least at `t = y_0 + g rho / sqrt(1 - g^2)`
//! for `|g| < 1` (clamped to the box), and at the end `sign(g) half_0` for `|g| >= 1`. Where
//! the boxes run side by side the steps zig-zag, so after each step the points go on along it,
//! twice as far each time, while that lowers `F` (each box's own projection keeps them in
//! it). No step increases `F`; the iteration stops when a step moves the two points by no
//! more than [`STILL_MM`] together, or after [`MAX_STEPS`] steps.

use crate::geometry::obb::Obb;
use crate::geometry::sweep::MEET_DEPTH;
use crate::math::{float, Real, Vec3};

/// Movement (mm) of the two points together in one step at or below which the minimisation
/// stops.
pub const STILL_MM: Real = 1e-2;

/// The most steps (each moving `x`, then `y`) the minimisation takes.
pub const MAX_STEPS: u32 = 24;

/// The most strides along a step after it, each twice as long as the last (module doc, "The
/// minimisation").
pub const MAX_STRIDES: u32 = 8;

/// Points of two boxes swept by graded balls near their closest (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradedClosest {
    /// `x` of box `a` and `y` of box `b`.
    pub points: [Vec3; 2],
    /// `F(x, y) = |x - y| - r_a(x) - r_b(y)`: an upper bound on the least `F`, so a negative
    /// value shows the swept sets overlapping by at least its magnitude.
    pub margin: Real,
}

impl GradedClosest {
    /// Whether the swept sets certainly share a point, so that no axis separates them (module
    /// doc): `F <= -2 MEET_DEPTH`.
    pub fn meet(&self) -> bool {
        self.margin <= -2.0 * MEET_DEPTH
    }

    /// The direction from `x` to `y`: near the best axis to separate the swept sets.
    pub fn axis(&self) -> Vec3 {
        self.points[1] - self.points[0]
    }
}

/// The graded radius of `r` at point `x` of box `b` (`x`'s place along `u_0` clamped to the box).
pub fn graded_radius(b: &Obb, r: [Real; 2], x: &Vec3) -> Real {
    if r[0] == r[1] {
        return r[0];
    }
    let t = b.axes.column(0).dot(&(x - b.center));
    let f = (0.5 + 0.5 * t / b.half.x).clamp(0.0, 1.0);
    r[0] + (r[1] - r[0]) * f
}

/// A box in its own frame with its graded radii: what a step of the minimisation reads.
#[derive(Clone, Copy)]
struct GradedBox {
    half: Vec3,
    r: [Real; 2],
    /// `g / sqrt(1 - g^2)` for the radius's slope `g` along `u_0` (module doc), or `None` for
    /// `|g| >= 1`, when the end `sign(g) half_0` is nearest.
    lean: Option<Real>,
    /// `sign(g)`.
    sign: Real,
}

impl GradedBox {
    fn new(b: &Obb, r: [Real; 2]) -> GradedBox {
        let g = if b.half.x > 0.0 { (r[1] - r[0]) / (2.0 * b.half.x) } else { 0.0 };
        let lean = (g.abs() < 1.0).then(|| g / float::sqrt(1.0 - g * g));
        GradedBox { half: b.half, r, lean, sign: g.signum() }
    }

    /// The radius at the point of local coordinates `l` (as [`graded_radius`]).
    fn radius(&self, l: &Vec3) -> Real {
        if self.r[0] == self.r[1] {
            return self.r[0];
        }
        let f = (0.5 + 0.5 * l.x / self.half.x).clamp(0.0, 1.0);
        self.r[0] + (self.r[1] - self.r[0]) * f
    }

    /// The local point of the box that minimises `|x - y| - r(x)` for the local point `y`
    /// (module doc, "The minimisation").
    fn nearest(&self, y: &Vec3) -> Vec3 {
        let h = &self.half;
        let (x1, x2) = (y.y.clamp(-h.y, h.y), y.z.clamp(-h.z, h.z));
        let t = match self.lean {
            Some(lean) => {
                y.x + lean * float::sqrt((x1 - y.y) * (x1 - y.y) + (x2 - y.z) * (x2 - y.z))
            }
            None => self.sign * h.x,
        };
        Vec3::new(t.clamp(-h.x, h.x), x1, x2)
    }

    /// The local point of the box nearest `y` (a plain projection).
    fn clamp(&self, y: &Vec3) -> Vec3 {
        let h = &self.half;
        Vec3::new(y.x.clamp(-h.x, h.x), y.y.clamp(-h.y, h.y), y.z.clamp(-h.z, h.z))
    }
}

/// Points near the closest of box `a` swept by the graded ball of radii `ra` and box `b` by
/// that of `rb`, sought from the point `from` (module doc). The steps run in each box's own
/// frame, where a box is three intervals: `x` in `a`'s, `y` in `b`'s, each read in the other's
/// frame through `M = R_a^T R_b`.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // written so that NaN stops the steps
pub fn graded_closest(
    a: &Obb,
    ra: [Real; 2],
    b: &Obb,
    rb: [Real; 2],
    from: &Vec3,
) -> GradedClosest {
    let (ga, gb) = (GradedBox::new(a, ra), GradedBox::new(b, rb));
    let m = a.axes.tr_mul(&b.axes);
    let offset = a.axes.tr_mul(&(b.center - a.center));
    // `y` (in `b`'s frame) in `a`'s frame, and `x` (in `a`'s) in `b`'s.
    let in_a = |y: &Vec3| m * y + offset;
    let in_b = |x: &Vec3| m.tr_mul(&(x - offset));
    let f = |x: &Vec3, y: &Vec3| (in_a(y) - x).norm() - ga.radius(x) - gb.radius(y);
    let mut x = ga.nearest(&a.axes.tr_mul(&(from - a.center)));
    let mut y = gb.nearest(&in_b(&x));
    let mut value = f(&x, &y);
    for _ in 0..MAX_STEPS {
        let x1 = ga.nearest(&in_a(&y));
        let y1 = gb.nearest(&in_b(&x1));
        let (dx, dy) = (x1 - x, y1 - y);
        (x, y, value) = (x1, y1, f(&x1, &y1));
        if !(dx.norm() + dy.norm() > STILL_MM) {
            break;
        }
        // Alternating steps zig-zag where the boxes run side by side: go on along the step
        // while that lowers `F`, doubling it each time.
        let mut scale = 2.0;
        for _ in 0..MAX_STRIDES {
            let (xe, ye) = (ga.clamp(&(x + dx * scale)), gb.clamp(&(y + dy * scale)));
            let further = f(&xe, &ye);
            if !(further < value) {
                break;
            }
            (x, y, value, scale) = (xe, ye, further, scale * 2.0);
        }
    }
    GradedClosest { points: [a.center + a.axes * x, b.center + b.axes * y], margin: value }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sweep::tests::{any_box, any_radii, rot, unit};
    use crate::geometry::sweep::{balls_swept_apart_with, Axes, FaceTerms};
    use crate::math::Mat3;
    use proptest::prelude::*;

    /// `F` at the points of a 9 x 9 x 9 grid over each box: the brute-force oracle.
    fn grid_minimum(a: &Obb, ra: [Real; 2], b: &Obb, rb: [Real; 2]) -> Real {
        let grid = |o: &Obb| {
            let at = |i: usize, h: Real| h * (i as Real / 4.0 - 1.0);
            let mut v = Vec::with_capacity(729);
            for (i, j, k) in (0..729).map(|n| (n / 81, n / 9 % 9, n % 9)) {
                v.push(
                    o.center
                        + o.axes * Vec3::new(at(i, o.half.x), at(j, o.half.y), at(k, o.half.z)),
                );
            }
            v
        };
        let (ga, gb) = (grid(a), grid(b));
        let rb_at: Vec<Real> = gb.iter().map(|y| graded_radius(b, rb, y)).collect();
        let mut least = Real::INFINITY;
        for x in &ga {
            let rx = graded_radius(a, ra, x);
            for (y, ry) in gb.iter().zip(&rb_at) {
                least = least.min((y - x).norm() - rx - ry);
            }
        }
        least
    }

    /// Whether `p` lies in box `b` (to rounding).
    fn inside(b: &Obb, p: &Vec3) -> bool {
        let l = b.axes.tr_mul(&(p - b.center));
        (0..3).all(|k| l[k].abs() <= b.half[k] * (1.0 + 1e-12) + 1e-9)
    }

    proptest! {
        /// The points lie in their boxes, `margin` is `F` there (to rounding), and where the swept
        /// sets are apart it is no more than the least `F` over a grid of each box (brute force)
        /// plus
        /// 0.5 mm: the minimisation finds the minimum within what the oracle can tell. With
        /// parallel boxes (the slowest case of alternating steps) and zero radii. (Where the
        /// sets overlap, alternating steps stop at the first point the boxes share: `F` is not
        /// smooth there. The separating tests need no more: no axis separates them either way.)
        #[test]
        fn closest_points_reach_the_grid_minimum(a in any_box(), b in any_box(), ra in any_radii(),
                rb in any_radii(), parallel in any::<bool>(), from in prop::array::uniform3(-300.0..300.0f64)) {
            let b = if parallel { Obb { axes: a.axes, ..b } } else { b };
            let c = graded_closest(&a, ra, &b, rb, &Vec3::from(from));
            prop_assert!(inside(&a, &c.points[0]) && inside(&b, &c.points[1]));
            let [x, y] = c.points;
            let f = (y - x).norm() - graded_radius(&a, ra, &x) - graded_radius(&b, rb, &y);
            prop_assert!((f - c.margin).abs() <= 1e-9 * (1.0 + c.margin.abs()), "{} {}", f, c.margin);
            let oracle = grid_minimum(&a, ra, &b, rb);
            if oracle > 0.0 {
                prop_assert!(c.margin <= oracle + 0.5, "{} > grid {}", c.margin, oracle);
            }
        }

        /// Swept sets whose points meet are never proved apart, on the 15 axes, on any other
        /// axis or on their own; swept sets apart by more than 1 mm are proved apart on the
        /// points' axis alone. Also right where the answer flips (B moved along `v` by
        /// bisection), with parallel boxes and zero radii.
        #[test]
        fn the_points_axis_separates_what_does_not_meet(a in any_box(), b in any_box(), ra in any_radii(),
                rb in any_radii(), v in prop::array::uniform3(-1.0..1.0f64), parallel in any::<bool>(),
                other in prop::array::uniform3(-2.0..2.0f64)) {
            let v = unit(Vec3::from(v));
            let b = if parallel { Obb { axes: a.axes, ..b } } else { b };
            let fa = FaceTerms::ball(&a, ra);
            let check = |t: Real| -> Result<bool, TestCaseError> {
                let b = Obb { center: a.center + v * t, ..b };
                let fb = FaceTerms::ball(&b, rb);
                let c = graded_closest(&a, ra, &b, rb, &a.center);
                let along = balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::Only(&c.axis()));
                if c.meet() {
                    let other = Axes::FifteenAnd(&Vec3::from(other));
                    prop_assert!(!along && !balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, other));
                }
                if c.margin > 1.0 {
                    prop_assert!(along, "margin {}", c.margin);
                }
                Ok(c.meet())
            };
            let (mut lo, mut hi) = (0.0, 2000.0);
            let (met, far) = (check(lo)?, check(hi)?);
            if met && !far {
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if check(mid)? { lo = mid } else { hi = mid }
                }
            }
        }

        /// Started at the centre two boxes share, the points find them meeting exactly when
        /// their radii there reach `2 MEET_DEPTH`.
        #[test]
        fn boxes_sharing_a_point_meet(a in any_box(), b in any_box(), ra in any_radii(), rb in any_radii()) {
            let b = Obb { center: a.center, ..b };
            let c = graded_closest(&a, ra, &b, rb, &a.center);
            let middle = |r: [Real; 2]| r[0] + (r[1] - r[0]) * 0.5;
            prop_assert_eq!(c.meet(), middle(ra) + middle(rb) >= 2.0 * MEET_DEPTH, "{:?}", c);
        }
    }

    /// Round numbers where the certificate flips: two boxes 10 mm apart face to face (and edge
    /// to edge, turned by 45 degrees), swept by balls of 4 and 6 mm at the faces that meet,
    /// at the origin and 10 m away. At exactly 10 mm the points say "not known" (the slack),
    /// 1e-5 mm closer they say "meet", and no axis separates them.
    #[test]
    fn balls_meeting_at_round_numbers() {
        let turned = rot((0.0, 0.0, core::f64::consts::FRAC_PI_4));
        for origin in [Vec3::zeros(), Vec3::new(1e4, -1e4, 1e4)] {
            for (axes, gap_scale) in [(Mat3::identity(), 1.0), (turned, core::f64::consts::SQRT_2)]
            {
                let a = Obb::new(origin, axes, Vec3::new(20.0, 20.0, 20.0));
                let at = |gap: Real| {
                    // B's nearest face (or edge) `gap` from A's along x.
                    let c = origin + Vec3::new(2.0 * 20.0 * gap_scale + gap, 0.0, 0.0);
                    Obb::new(c, axes, Vec3::new(20.0, 20.0, 20.0))
                };
                let near = origin + Vec3::new(20.0 * gap_scale, 0.0, 0.0);
                // The radii where the boxes face each other (A's face or edge at `+half_0 u_0`,
                // B's at `-half_0 u_0`): 4 mm and 6 mm, graded or not.
                for (ra, rb) in
                    [([4.0; 2], [6.0; 2]), ([8.0, 4.0], [6.0, 6.0]), ([0.0, 4.0], [6.0, 0.0])]
                {
                    assert!(
                        !graded_closest(&a, ra, &at(10.0), rb, &near).meet(),
                        "{origin} {gap_scale}"
                    );
                    let b = at(10.0 - 1e-5);
                    assert!(graded_closest(&a, ra, &b, rb, &near).meet(), "{origin} {gap_scale}");
                    let (fa, fb) = (FaceTerms::ball(&a, ra), FaceTerms::ball(&b, rb));
                    for also in [Vec3::zeros(), Vec3::x(), Vec3::new(1.0, 1.0, 0.0)] {
                        assert!(!balls_swept_apart_with(
                            &a,
                            ra,
                            &fa,
                            &b,
                            rb,
                            &fb,
                            Axes::FifteenAnd(&also)
                        ));
                    }
                }
            }
        }
    }

    /// Two links side by side, 40 mm apart across their length and swept by balls of 0 mm at
    /// one end and 30 mm at the other, the ends turned opposite ways: the swept sets are
    /// 10 mm apart at the thin ends only, along a direction tilted from every one of the 15
    /// axes, which none of them separates and the points' axis does.
    #[test]
    fn tilted_links_are_separated_by_the_points_axis_alone() {
        let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::new(200.0, 10.0, 10.0));
        let b = Obb::new(Vec3::new(0.0, 60.0, 0.0), Mat3::identity(), Vec3::new(200.0, 10.0, 10.0));
        let (ra, rb) = ([0.0, 30.0], [30.0, 0.0]);
        let (fa, fb) = (FaceTerms::ball(&a, ra), FaceTerms::ball(&b, rb));
        assert!(!balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::FifteenAnd(&Vec3::y())));
        let c = graded_closest(&a, ra, &b, rb, &Vec3::new(0.0, 30.0, 0.0));
        assert!(!c.meet() && c.margin > 0.0, "{c:?}");
        assert!(balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::Only(&c.axis())), "{c:?}");
    }
}
