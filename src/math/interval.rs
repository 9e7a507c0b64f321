//! A tiny closed-interval arithmetic, enough to enclose the inverse kinematics over a box of
//! TCPs (SPEC §6 and §8; used by [`crate::robot::motion_bound`]).
//!
//! # Numerics
//! Every operation is computed in round-to-nearest and its result widened outward by a few
//! ulps (`widen`): IEEE `+ - * / sqrt` are correctly rounded (error <= 1/2 ulp), and the libm
//! `acos`/`atan2` used are within a few ulps, so every returned interval encloses the exact
//! range of its operation over its operands. An empty result is reported as `None`.

use crate::math::Real;

/// The closed interval `[lo, hi]`, `lo <= hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lo: Real,
    /// Upper end.
    pub hi: Real,
}

/// Outward slack of one operation: 4 ulps relative plus the smallest normal number.
fn widen(lo: Real, hi: Real) -> Interval {
    let slack = |v: Real| v.abs() * 4.0 * Real::EPSILON + Real::MIN_POSITIVE;
    Interval { lo: lo - slack(lo), hi: hi + slack(hi) }
}

// The operations are outward-rounded enclosures, not the exact arithmetic `std::ops` promises,
// so they keep their own names.
#[allow(clippy::should_implement_trait)]
impl Interval {
    /// `[lo, hi]` (the ends are sorted).
    pub fn new(lo: Real, hi: Real) -> Interval {
        Interval { lo: lo.min(hi), hi: lo.max(hi) }
    }

    /// The degenerate interval `[v, v]`.
    pub fn point(v: Real) -> Interval {
        Interval { lo: v, hi: v }
    }

    /// Whether `v` lies in the interval.
    pub fn contains(&self, v: Real) -> bool {
        self.lo <= v && v <= self.hi
    }

    /// The smallest interval holding both.
    pub fn hull(&self, o: &Interval) -> Interval {
        Interval { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }

    /// `self + o`.
    pub fn add(self, o: Interval) -> Interval {
        widen(self.lo + o.lo, self.hi + o.hi)
    }

    /// `self - o`.
    pub fn sub(self, o: Interval) -> Interval {
        widen(self.lo - o.hi, self.hi - o.lo)
    }

    /// `self * s` for a scalar.
    pub fn scale(self, s: Real) -> Interval {
        let (a, b) = (self.lo * s, self.hi * s);
        widen(a.min(b), a.max(b))
    }

    /// `self + s` for a scalar.
    pub fn shift(self, s: Real) -> Interval {
        widen(self.lo + s, self.hi + s)
    }

    /// `self * o`.
    pub fn mul(self, o: Interval) -> Interval {
        let p = [self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi];
        widen(
            p.iter().copied().fold(Real::INFINITY, Real::min),
            p.iter().copied().fold(Real::NEG_INFINITY, Real::max),
        )
    }

    /// `self^2` (tighter than `self * self` when the interval holds 0).
    pub fn sqr(self) -> Interval {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo <= 0.0 && self.hi >= 0.0 {
            widen(0.0, a.max(b)).clamp_lo(0.0)
        } else {
            widen(a.min(b), a.max(b)).clamp_lo(0.0)
        }
    }

    /// `self / o`, or `None` when `o` holds 0.
    pub fn div(self, o: Interval) -> Option<Interval> {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return None;
        }
        let q = [self.lo / o.lo, self.lo / o.hi, self.hi / o.lo, self.hi / o.hi];
        Some(widen(
            q.iter().copied().fold(Real::INFINITY, Real::min),
            q.iter().copied().fold(Real::NEG_INFINITY, Real::max),
        ))
    }

    /// `sqrt` over the non-negative part, or `None` when the interval is negative.
    pub fn sqrt(self) -> Option<Interval> {
        if self.hi < 0.0 {
            return None;
        }
        Some(widen(self.lo.max(0.0).sqrt(), self.hi.sqrt()).clamp_lo(0.0))
    }

    /// `acos` over the part inside `[-1, 1]` (decreasing), or `None` when there is none.
    pub fn acos(self) -> Option<Interval> {
        let (lo, hi) = (self.lo.max(-1.0), self.hi.min(1.0));
        if lo > hi {
            return None;
        }
        Some(widen(hi.acos(), lo.acos()))
    }

    /// The range of `atan2(y, x)` over the box `y x x`; `None` (no useful bound) when the box
    /// meets the origin or the branch cut (`x <= 0`, `y = 0`). Otherwise the box lies in an
    /// open half-plane cut-free wedge and the angle is extreme at a corner.
    ///
    /// Which corners, when the box lies wholly below or above the x axis: the partial
    /// derivatives are `d/dx = -y / r^2` and `d/dy = x / r^2`. Below (`y < 0`) the angle grows
    /// with `x`, so it is least on the side `x = x.lo` and greatest on `x = x.hi`; along a side
    /// it grows with `y` where that side's `x >= 0` and falls where `x < 0`. Above (`y > 0`)
    /// it falls with `x`: least on `x = x.hi`, greatest on `x = x.lo`, with `y` as before.
    /// So two `atan2` give both ends there (the inverse kinematics' boxes have `y = z < 0`);
    /// other boxes take all four corners. The ends are widened by 1e-15, more than the
    /// rounding of `atan2` near `pi` (4.4e-16), so they hold the exact extremes.
    pub fn atan2(y: Interval, x: Interval) -> Option<Interval> {
        let meets_cut = x.lo <= 0.0 && y.lo <= 0.0 && y.hi >= 0.0;
        if meets_cut {
            return None;
        }
        // `y` at which the angle is extreme on the side at `side_x`: `larger` picks the end
        // that makes it grow (`d/dy` has the sign of `x`).
        let end_y =
            |side_x: Real, larger: bool| if (side_x >= 0.0) == larger { y.hi } else { y.lo };
        let (lo, hi) = if y.hi < 0.0 {
            (end_y(x.lo, false).atan2(x.lo), end_y(x.hi, true).atan2(x.hi))
        } else if y.lo > 0.0 {
            (end_y(x.hi, false).atan2(x.hi), end_y(x.lo, true).atan2(x.lo))
        } else {
            let corners = [y.lo.atan2(x.lo), y.lo.atan2(x.hi), y.hi.atan2(x.lo), y.hi.atan2(x.hi)];
            let lo = corners.iter().copied().fold(Real::INFINITY, Real::min);
            (lo, corners.iter().copied().fold(Real::NEG_INFINITY, Real::max))
        };
        Some(Interval { lo: lo - 1e-15, hi: hi + 1e-15 })
    }

    /// `-self`.
    pub fn neg(self) -> Interval {
        Interval { lo: -self.hi, hi: -self.lo }
    }

    fn clamp_lo(self, v: Real) -> Interval {
        Interval { lo: self.lo.max(v), hi: self.hi.max(v) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation's result holds the operation applied to points of its operands.
    #[test]
    fn operations_enclose_pointwise_results() {
        let pts = |i: &Interval| {
            let i = *i;
            (0..=10).map(move |s| i.lo + (i.hi - i.lo) * s as f64 / 10.0)
        };
        let cases = [Interval::new(-3.0, 2.0), Interval::new(0.5, 4.0), Interval::new(-7.0, -0.25)];
        for a in &cases {
            for b in &cases {
                for x in pts(a) {
                    for y in pts(b) {
                        assert!(a.add(*b).contains(x + y));
                        assert!(a.sub(*b).contains(x - y));
                        assert!(a.mul(*b).contains(x * y));
                        if let Some(q) = a.div(*b) {
                            assert!(q.contains(x / y));
                        }
                        if let Some(t) = Interval::atan2(*a, *b) {
                            assert!(t.contains(x.atan2(y)), "atan2({x}, {y}) not in {t:?}");
                        }
                    }
                }
                assert!(a.sqr().contains(pts(a).map(|x| x * x).fold(0.0, f64::max)));
            }
        }
        assert!(Interval::new(-1.0, 1.0).div(Interval::new(-1.0, 1.0)).is_none());
        assert_eq!(Interval::new(-3.0, -2.0).sqrt(), None);
        let ac = Interval::new(-0.5, 3.0).acos().unwrap();
        assert!(ac.contains(0.0) && ac.contains(2.0 * std::f64::consts::FRAC_PI_3) && ac.hi < 2.1);
        assert_eq!(Interval::new(1.5, 3.0).acos(), None);
        assert!(
            Interval::atan2(Interval::new(-1.0, 1.0), Interval::new(-2.0, -1.0)).is_none(),
            "branch cut"
        );
        assert!(Interval::atan2(Interval::new(-1.0, 1.0), Interval::new(1.0, 2.0)).is_some());
    }

    /// Boxes wholly below or above the x axis (where two corners give the ends), on both sides
    /// of `x = 0`, touching it, and thin: the enclosure holds `atan2` at all four corners and at
    /// a grid of interior points, and its ends are corner values (no wider than the rounding).
    #[test]
    fn atan2_of_half_plane_boxes_holds_every_corner() {
        let mut rng = crate::test_rng::TestRng(7);
        let mut pick = |scale: f64| rng.unit() * scale;
        for i in 0..20_000 {
            let scale = [1e-3, 1.0, 300.0][i % 3];
            let (x0, x1) = (pick(scale), pick(scale));
            let (mut y0, mut y1) = (pick(scale).abs(), pick(scale).abs());
            if i % 7 == 0 {
                y0 = 0.0; // touching the axis from one side
            }
            if i % 2 == 0 {
                (y0, y1) = (-y0, -y1);
            }
            let (x, y) = (Interval::new(x0, x1), Interval::new(y0, y1));
            let Some(t) = Interval::atan2(y, x) else { continue };
            let corners = [y.lo.atan2(x.lo), y.lo.atan2(x.hi), y.hi.atan2(x.lo), y.hi.atan2(x.hi)];
            for c in corners {
                assert!(t.contains(c), "atan2 over {y:?} x {x:?}: corner {c} not in {t:?}");
            }
            let least = corners.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(t.lo >= least - 2e-15, "{y:?} x {x:?}: {t:?} wider than the corners' {least}");
            for s in 0..=4 {
                for u in 0..=4 {
                    // Clamped: the rounded sum may step past the far end.
                    let at = |i: &Interval, f: usize| {
                        (i.lo + (i.hi - i.lo) * f as f64 / 4.0).clamp(i.lo, i.hi)
                    };
                    let (px, py) = (at(&x, s), at(&y, u));
                    assert!(
                        t.contains(py.atan2(px)),
                        "atan2({py}, {px}) not in {t:?}, box {y:?} x {x:?}"
                    );
                }
            }
        }
    }
}
