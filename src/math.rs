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
