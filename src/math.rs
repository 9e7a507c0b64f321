//! Scalar and vector types and the named tolerances, in one place (SPEC §1: mm, rad).
//!
//! # Numerics
//! Every tolerance here errs toward "collision": a tie or a rounding error may turn a free
//! configuration into a reported collision, never the other way round.

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
        floor
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
