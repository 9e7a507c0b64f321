//! Scalar and vector types and the named tolerances, in one place (SPEC §1: mm, rad).
//!
//! # Numerics
//! Every tolerance here errs toward "collision": a tie or a rounding error may turn a free
//! configuration into a reported collision, never the other way round.

#[cfg(feature = "std")]
pub(crate) mod interval;

/// The one scalar type of the crate.
pub type Real = f64;
/// A point or direction in 3-D, in millimetres.
pub type Vec3 = nalgebra::Vector3<Real>;
/// A 3x3 matrix; for boxes and placements, a rotation whose columns are unit axes.
pub type Mat3 = nalgebra::Matrix3<Real>;

/// Added to every `|R_ij|` of the separating axis test, so that nearly parallel edges
/// (where the cross-product axis degenerates) err toward overlap (Gottschalk, Coal/FCL).
///
/// 1e-12, not Coal's 1e-6: rounding in `R` is about 4e-16, and 1e-6 also inflated real gaps
/// (2.4e-3 mm boxes reported colliding in `tests/sat_oracle.rs`, beyond its 1e-3 mm band).
pub const SAT_EPSILON: Real = 1e-12;

/// Slack, in mm, added to every box half-extent comparison of the separating axis test: an
/// axis separates only when the gap exceeds this, so touching boxes (and boxes whose gap is
/// lost in rounding) report a collision.
pub const SAT_TOUCH_TOLERANCE: Real = 1e-9;

/// The largest length, margin, box offset or placement coordinate a cell accepts (mm): 1 km.
///
/// Far beyond any robot cell, and far below overflow: sums and squares of such values (the
/// AABB of a robot, the loop equations, `|t|^2`) stay finite, where `1e308` would turn a
/// bounding-box centre into NaN.
pub const MAX_LENGTH: Real = 1e6;

/// Cross products `A_i x B_j` shorter than this are left out of the normalised axes of the
/// clearance (`geometry::clearance`): their edges are parallel to 1e-6 rad, the face axes
/// then stand for them, and normalising would divide rounding errors of about 1e-16 mm per
/// mm of size by this length.
pub const CROSS_AXIS_MIN_NORM: Real = 1e-6;

/// The float functions the per-tick code needs that `core` lacks (SPEC §1 units: rad).
///
/// With the `std` feature they are `f64`'s own methods, so results are exactly those of
/// std; without it (`no_std`) they are `libm`'s, correctly rounded where libm is (sqrt,
/// floor) and within an ulp or so elsewhere. Per-tick code calls these, never the methods.
pub mod float {
    use super::Real;

    macro_rules! unary {
        ($($(#[$doc:meta])* $name:ident),*) => {$(
            $(#[$doc])*
            #[inline]
            pub fn $name(x: Real) -> Real {
                #[cfg(feature = "std")]
                return x.$name();
                #[cfg(not(feature = "std"))]
                return libm::$name(x);
            }
        )*};
    }
    unary!(
        /// Square root.
        sqrt,
        /// Sine.
        sin,
        /// Cosine.
        cos,
        /// Arc cosine, in [0, pi]; NaN outside [-1, 1].
        acos,
        /// Largest integer not above `x`.
        floor,
        /// Smallest integer not below `x`.
        ceil
    );

    /// `(sin x, cos x)`.
    #[inline]
    pub fn sin_cos(x: Real) -> (Real, Real) {
        #[cfg(feature = "std")]
        return x.sin_cos();
        #[cfg(not(feature = "std"))]
        return libm::sincos(x);
    }

    /// The angle of `(x, y)` from the x axis, in [-pi, pi] (`y.atan2(x)`).
    #[inline]
    pub fn atan2(y: Real, x: Real) -> Real {
        #[cfg(feature = "std")]
        return y.atan2(x);
        #[cfg(not(feature = "std"))]
        return libm::atan2(y, x);
    }

    /// `sqrt(x^2 + y^2)` without undue overflow.
    #[inline]
    pub fn hypot(x: Real, y: Real) -> Real {
        #[cfg(feature = "std")]
        return x.hypot(y);
        #[cfg(not(feature = "std"))]
        return libm::hypot(x, y);
    }

    /// The least non-negative remainder of `x / m` (`x.rem_euclid(m)`, same formula).
    #[inline]
    pub fn rem_euclid(x: Real, m: Real) -> Real {
        #[cfg(feature = "std")]
        return x.rem_euclid(m);
        #[cfg(not(feature = "std"))]
        {
            let r = x % m;
            if r < 0.0 {
                r + m.abs()
            } else {
                r
            }
        }
    }
}

/// The smaller of `a` and `b`, NaN when either is NaN.
///
/// `f64::min` returns the other operand when one is NaN, so a bounding box folded with it
/// silently drops a NaN box, and a pair whose boxes were never tested is reported free. Every
/// bound that decides "free" is folded with this and [`max_or_nan`] instead.
#[inline]
pub fn min_or_nan(a: Real, b: Real) -> Real {
    if a.is_nan() || b.is_nan() {
        Real::NAN
    } else {
        a.min(b)
    }
}

/// The larger of `a` and `b`, NaN when either is NaN (see [`min_or_nan`]).
#[inline]
pub fn max_or_nan(a: Real, b: Real) -> Real {
    if a.is_nan() || b.is_nan() {
        Real::NAN
    } else {
        a.max(b)
    }
}

#[cfg(test)]
mod tests {
    use super::float;

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        assert!(
            a.is_finite() && b.is_finite() && (a == b || a.signum() == b.signum()),
            "{a} vs {b}"
        );
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    /// The `no_std` build takes libm's functions: on the arguments the kinematics see they
    /// agree with std's to within 1 ulp (sqrt and floor exactly), and with `std` the shim
    /// is std's methods themselves.
    #[test]
    fn nan_propagating_min_and_max() {
        use super::{max_or_nan, min_or_nan};
        assert_eq!((min_or_nan(1.0, 2.0), max_or_nan(1.0, 2.0)), (1.0, 2.0));
        for (a, b) in [(f64::NAN, 1.0), (1.0, f64::NAN), (f64::NAN, f64::NAN)] {
            assert!(min_or_nan(a, b).is_nan() && max_or_nan(a, b).is_nan());
        }
    }

    #[test]
    fn libm_agrees_with_std_within_one_ulp() {
        let mut rng = crate::test_rng::TestRng(0x2545_f491_4f6c_dd1d_u64);
        let mut next = || rng.unit();
        for _ in 0..100_000 {
            let (a, b) = (1000.0 * next(), 1000.0 * next());
            assert_eq!(libm::sqrt(a.abs()), a.abs().sqrt());
            assert_eq!(libm::floor(a), a.floor());
            assert!(ulps(libm::atan2(a, b), a.atan2(b)) <= 1, "atan2({a}, {b})");
            assert!(ulps(libm::hypot(a, b), a.hypot(b)) <= 1, "hypot({a}, {b})");
            assert!(ulps(libm::acos(a / 1000.0), (a / 1000.0).acos()) <= 1, "acos({a} / 1000)");
            let (t, (s, c)) = (a / 100.0, libm::sincos(a / 100.0));
            assert!(
                (s - t.sin()).abs() <= 2.0 * f64::EPSILON
                    && (c - t.cos()).abs() <= 2.0 * f64::EPSILON,
                "{t}"
            );
            assert_eq!(float::sqrt(a.abs()), a.abs().sqrt());
            assert_eq!(float::atan2(a, b), a.atan2(b));
            assert_eq!(float::sin_cos(t), t.sin_cos());
            assert_eq!(float::rem_euclid(a, 7.0), a.rem_euclid(7.0));
        }
    }
}
