//! Swept boxes: an oriented box with a convex set of displacements of its points, and a
//! separating-axis test between two of them (certified labelling with a
//! direction-aware bound, beyond the thesis's uniform blow-up of 3.2.7).
//!
//! # The displacement set
//! A [`Sweep`] is the convex, centrally symmetric set
//! `S = ball(c) + [-l, l] + hull(E_1 u E_2)`, `E_k = e_k Z + d_k A`, where `[-l, l]` is a
//! segment (a lower link's turn along its own axis, `robot::motion_bound` steps 10-11), `Z` is the
//! box `[-w_0, w_0] + [-w_1, w_1] + [-w_2, w_2]` plus the ball of radius `r` (the TCP's cell: `w_a`
//! is its half-edge along axis `a`, `r = 0`; or the TCP's ball: `w = 0`, `r` its radius) and
//! `A` the rectangle `[-v_0, v_0] + [-v_1, v_1]` (around the arc an elbow moves on:
//! `v_0` along the arc's tangent, `v_1` toward its centre). Its support function, for any
//! vector `n` (not only unit ones), is
//!
//! `h_S(n) = c |n| + |l . n| + max_k ( e_k (sum_a |w_a . n| + r |n|) + d_k sum_b |v_b . n| )`.
//!
//! # Graded along the box
//! The sets `E_1` and `E_2` belong to the box's two faces across its axis 0 (`u_0`, the link's
//! axis for a link box): `E_1` to the face at `-half_0 u_0`, `E_2` to the one at `+half_0 u_0`.
//! A sweep built for a box (`robot::motion_bound`) also bounds each point's displacement
//! by where the point lies: the point at fraction `f` of the way from the first face to the
//! second moves within `ball(c) + [-l, l] + (1 - f) E_1 + f E_2` (for a lower link the point at
//! `l` along the link moves within `|l| Z + |1 - l| A`, convex in `l`, so below its chord
//! between the faces; the other boxes have `E_1 = E_2`). That set is inside `S` (the hull holds
//! every convex combination), so this *graded* reading claims less motion than `S`. Along a
//! vector `m` pointing from the box toward the other box, the swept box then reaches, beyond
//! the box's own projection, at most
//!
//! `g(m) = c |m| + |l . m| + max(h_1 - half_0 (s + |s|), h_2 + half_0 (s - |s|))`,
//!
//! with `h_k = e_k (sum_a |w_a . m| + r |m|) + d_k sum_b |v_b . m|` and `s = u_0 . m`: the reach
//! `max_f ((2 f - 1) half_0 s + (1 - f) h_1 + f h_2)` is linear in `f`, so attained at a face,
//! and the box's own projection on `m` is `half_0 |s|` plus the terms of axes 1 and 2.
//! `g(m) <= h_S(m)` (both brackets are at most `max(h_1, h_2)`), with equality where `s = 0`
//! or `E_1 = E_2`: the gain is on axes along the box (for two lower links, their own face 0 and
//! the edges across it), where the end nearer the other box moves with its own set only.
//! [`swept_boxes_apart_either`] and [`balls_swept_apart_with`] read sweeps so (the protective
//! verdict); [`swept_boxes_apart`] reads every point in all of `S` (the tables' test, whose
//! faster form [`crate::cspace::swept_sat`] is kept equal to it).
//! The graded tests also take one more axis, any vector, or test that axis alone ([`Axes`]):
//! the 15 axes decide whether two boxes meet, but not whether two swept sets
//! do, so a good guess proves pairs that none of the 15 does (the protective verdict tries the
//! direction between the boxes' closest points now, then that between the closest points of
//! the boxes swept by graded balls: [`crate::geometry::graded_closest`]).
//!
//! # The test
//! If every point of a box at some configuration lies within `S` of the point with the same
//! box coordinates at the reference configuration (box `B0`), the box lies in `B0 + S`. On an
//! axis `n`, `B0 + S` projects to the interval of centre `n . c` and radius
//! `sum_i half_i |u_i . n| + h_S(n)`. So `B0_A + S_A` and `B0_B + S_B` are disjoint when, on
//! one of the 15 axes of the two boxes (face normals and edge cross products, as in
//! [`super::sat`]), `|n . (c_B - c_A)|` exceeds the two radii: a sufficient condition (the
//! swept sets are not boxes, so it is not necessary), which is all a proof of "free" needs.
//!
//! # Numerics
//! A cross-product axis shorter than `1e-5` is skipped (its direction is not known well
//! enough), and an axis separates only when the gap exceeds [`SWEEP_GAP`] (mm): both err
//! toward "not apart".
//!
//! # Certain intersection: the cores
//! The converse question, "do the boxes intersect for *every* displacement?", has a cheap
//! sufficient answer ([`swept_boxes_always_meet`]). Let box `A` (centre `c`, unit axes `u_k`,
//! half-extents `a_k`) move rigidly, `p -> f(p)`, with `f(p) - p` in `S` for every point `p`
//! of `A` (as above; `S` is centrally symmetric, so `max_{s in S} |u . s| = h_S(u)` for a unit
//! `u`). Its *core* is `A` shrunk along each of its axes by `s_k = h_S(u_k)`: half-extents
//! `a_k - s_k`. Every point `x` of the core's interior lies in the moved box `f(A)`:
//! - the homotopy `g_t(p) = p + t (f(p) - p)`, `t` in `[0, 1]`, joins the identity to `f` on
//!   `A`; for `p` on the boundary of `A` some `k` has `|u_k . (p - c)| = a_k`, so
//!   `|u_k . (x - g_t(p))| >= a_k - |u_k . (x - c)| - t h_S(u_k) > a_k - (a_k - s_k) - s_k = 0`:
//!   `g_t` never maps the boundary onto `x`;
//! - so the degree of `g_t` at `x` (Brouwer) stays that of the identity, 1, and `x` is in
//!   `g_1(A) = f(A)`.
//!
//! Hence if the cores of `A` (under `S_A`) and of `B` (under `S_B`) share an interior point,
//! that point lies in both moved boxes for every pair of displacements: the boxes always
//! intersect. The cores' interiors meet when no one of their 15 axes separates them even
//! weakly (the separating axis theorem for closed boxes, which also holds for touching ones:
//! a supporting plane of the Minkowski difference through the origin has one of the 15
//! normals).
//!
//! Numerics: the test asks every axis for an overlap above [`MEET_DEPTH`] (mm), far above
//! rounding, and a cross-product axis shorter than `1e-5` (edges nearly parallel: its
//! computed direction is off by more than the depth can absorb) makes the answer "not
//! certain", as does a core with a half-extent that is not positive. All err toward "not
//! certain", the safe side for a proof of "collision for every configuration".

use crate::geometry::obb::Obb;
use crate::math::{float, Mat3, Real, Vec3};

/// The smallest gap (mm) between two swept boxes along an axis that counts as apart.
pub const SWEEP_GAP: Real = 1e-6;

/// The smallest overlap (mm) of two cores along every axis that counts as a certain
/// intersection ([`swept_boxes_always_meet`]).
pub const MEET_DEPTH: Real = 1e-6;

/// A convex set of displacements (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Half-edges of the box `Z` (orthogonal).
    pub cube: [Vec3; 3],
    /// Radius `r` of the ball that rounds `Z` (`Z` is the box plus this ball).
    pub round: Real,
    /// Half-edges of the rectangle `A` (orthogonal).
    pub arc: [Vec3; 2],
    /// `(e_k, d_k)` of the two hulled sets `E_k = e_k Z + d_k A`.
    pub ends: [(Real, Real); 2],
    /// Radius `c` of the ball added to everything.
    pub ball: Real,
    /// Half-edge `l` of the segment added to everything.
    pub line: Vec3,
}

impl Sweep {
    /// No displacement at all.
    pub const ZERO: Sweep = Sweep {
        cube: [Vec3::new(0.0, 0.0, 0.0); 3],
        round: 0.0,
        arc: [Vec3::new(0.0, 0.0, 0.0); 2],
        ends: [(0.0, 0.0); 2],
        ball: 0.0,
        line: Vec3::new(0.0, 0.0, 0.0),
    };

    /// Whether this is no displacement at all.
    pub fn is_zero(&self) -> bool {
        let point = |v: &[Vec3]| v.iter().all(|w| *w == Vec3::zeros());
        let (z, a) = (point(&self.cube) && self.round == 0.0, point(&self.arc));
        self.ball == 0.0
            && self.line == Vec3::zeros()
            && self.ends.iter().all(|&(e, d)| (e == 0.0 || z) && (d == 0.0 || a))
    }

    /// `h_S(n)`, the support function (module doc); `n` need not be unit.
    #[inline]
    pub fn support(&self, n: &Vec3) -> Real {
        self.support_with_norm(n, float::sqrt(n.norm_squared()))
    }

    /// [`Sweep::support`] with `norm = float::sqrt(n.norm_squared())` already at hand (the
    /// same value).
    #[inline(always)]
    fn support_with_norm(&self, n: &Vec3, norm: Real) -> Real {
        let [h1, h2] = self.end_terms(n, norm);
        self.ball * norm + self.line.dot(n).abs() + h1.max(h2)
    }

    /// `h_1` and `h_2` of the module doc ("Graded along the box"): the supports of `E_1` and
    /// `E_2` on `n`, of norm `norm`.
    #[inline(always)]
    fn end_terms(&self, n: &Vec3, norm: Real) -> [Real; 2] {
        let z = self.cube[0].dot(n).abs()
            + self.cube[1].dot(n).abs()
            + self.cube[2].dot(n).abs()
            + self.round * norm;
        let a = self.arc[0].dot(n).abs() + self.arc[1].dot(n).abs();
        let [(e1, d1), (e2, d2)] = self.ends;
        [e1 * z + d1 * a, e2 * z + d2 * a]
    }

    /// `g(m)` of the module doc ("Graded along the box"): how far a box swept by this set
    /// reaches along `m` (of norm `norm`) beyond the box's own projection, where
    /// `half_s = half_0 (u_0 . m)` for the box's axis 0 and half-extent along it.
    #[inline(always)]
    pub fn graded_support(&self, m: &Vec3, norm: Real, half_s: Real) -> Real {
        self.ball * norm + self.line.dot(m).abs() + graded_ends(self.end_terms(m, norm), half_s)
    }

    /// The support on `n` of the set that the point of a box on face `end` (0: at
    /// `-half_0 u_0`, 1: at `+half_0 u_0`) moves within under the graded reading (module doc):
    /// `c |n| + |l . n| + h_end`.
    #[cfg(test)]
    pub(crate) fn face_support(&self, end: usize, n: &Vec3) -> Real {
        let norm = float::sqrt(n.norm_squared());
        self.ball * norm + self.line.dot(n).abs() + self.end_terms(n, norm)[end]
    }

    /// The largest displacement in the set: `h_S` over unit vectors is at most this.
    pub fn radius(&self) -> Real {
        let z = float::sqrt(self.cube.iter().map(|w| w.norm_squared()).sum::<Real>()) + self.round;
        let a = float::sqrt(self.arc.iter().map(|v| v.norm_squared()).sum::<Real>());
        let [(e1, d1), (e2, d2)] = self.ends;
        self.ball + self.line.norm() + (e1 * z + d1 * a).max(e2 * z + d2 * a)
    }

    /// The set rotated by `rot` (a rotation matrix).
    pub fn rotated(&self, rot: &Mat3) -> Sweep {
        Sweep {
            cube: self.cube.map(|w| rot * w),
            arc: self.arc.map(|v| rot * v),
            line: rot * self.line,
            ..*self
        }
    }
}

/// The bracket of `g(m)` (module doc, "Graded along the box"): the larger of what the two
/// faces' sets add, `h[0]` and `h[1]`, less what each face lies behind the box's front along
/// `m` (`half_s = half_0 (u_0 . m)`). Never above `max(h[0], h[1])`.
#[inline(always)]
fn graded_ends(h: [Real; 2], half_s: Real) -> Real {
    (h[0] - (half_s + half_s.abs())).max(h[1] + (half_s - half_s.abs()))
}

/// Half-extents of the world-axis-aligned box around `b + s`, rounded up by a relative 1e-12.
pub fn swept_aabb_half(b: &Obb, s: &Sweep) -> Vec3 {
    let h = b.aabb_half();
    let e = |a: usize| {
        let mut n = Vec3::zeros();
        n[a] = 1.0;
        (h[a] + s.support(&n)) * (1.0 + 1e-12)
    };
    Vec3::new(e(0), e(1), e(2))
}

/// The terms of the swept tests on a box's own face axes that depend on that box and its sweep
/// alone: per axis `u_k`, the box's projected radius and the sweep's support, and the graded
/// supports along `-u_0` and `+u_0` (module doc, "Graded along the box"). Computed once per
/// swept box ([`swept_boxes_apart_with`], [`swept_boxes_apart_either`]), with the very
/// operations the tests would use, so that the answers are the same to the bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceTerms {
    /// The box's axes (columns of `axes`).
    u: [Vec3; 3],
    /// `sum_i half_i |u_i . u_k|`, per `k`.
    radius: [Real; 3],
    /// `h_S(u_k)`, per `k`.
    support: [Real; 3],
    /// `g(-u_0)` and `g(u_0)`; on axes 1 and 2 the graded tests take `h_S(u_k)`, which is at
    /// least `g(+-u_k)` (sound; `u_0 . u_k` is a rounding error there, so it is all they lose).
    graded_x: [Real; 2],
    /// `float::sqrt(|u_k|^2)`, per `k`.
    norm: [Real; 3],
    /// Whether `|u_k|^2 < 1e-10` (never for a box's unit axes; kept to answer as the test).
    short: [bool; 3],
}

impl FaceTerms {
    /// The face terms of box `b` swept by `s`.
    pub fn new(b: &Obb, s: &Sweep) -> FaceTerms {
        let graded = |n: &Vec3, len, half_s| s.graded_support(n, len, half_s);
        FaceTerms::from_supports(b, |n, len| s.support_with_norm(n, len), graded)
    }

    /// [`FaceTerms::new`] for [`Sweep::graded_ball`]`(r)`: the same values to the bit, without
    /// evaluating the terms of a sweep that are zero.
    pub fn ball(b: &Obb, r: [Real; 2]) -> FaceTerms {
        FaceTerms::from_supports(
            b,
            |_, len| (r[0] * len).max(r[1] * len),
            |_, len, half_s| graded_ends([r[0] * len, r[1] * len], half_s),
        )
    }

    /// The face terms of box `b` from a sweep's support `(n, |n|)` and graded support
    /// `(n, |n|, half_s)`.
    #[inline(always)]
    fn from_supports(
        b: &Obb,
        support: impl Fn(&Vec3, Real) -> Real,
        graded: impl Fn(&Vec3, Real, Real) -> Real,
    ) -> FaceTerms {
        let u = axes(b);
        let norm = u.map(|n| float::sqrt(n.norm_squared()));
        let along = b.half.x * u[0].dot(&u[0]);
        FaceTerms {
            short: u.map(|n| n.norm_squared() < 1e-10),
            u,
            radius: core::array::from_fn(|k| radius(&u, &b.half, &u[k])),
            support: core::array::from_fn(|k| support(&u[k], norm[k])),
            graded_x: [-along, along].map(|half_s| graded(&u[0], norm[0], half_s)),
            norm,
        }
    }

    /// The graded support on the box's own face axis `k`, toward the other box when
    /// `sign > 0` points `u_k` that way.
    #[inline(always)]
    fn graded(&self, k: usize, sign: Real) -> Real {
        match k {
            0 => self.graded_x[usize::from(sign > 0.0)],
            _ => self.support[k],
        }
    }
}

impl Sweep {
    /// The ball of radius `r[0]` at the face of a box at `-half_0 u_0`, growing linearly to
    /// `r[1]` at the face at `+half_0 u_0` under the graded reading (module doc), and of
    /// radius `max(r[0], r[1])` under the other: `E_k = r_k Z` with `Z` the unit ball.
    pub fn graded_ball(r: [Real; 2]) -> Sweep {
        Sweep { round: 1.0, ends: [(r[0], 0.0), (r[1], 0.0)], ..Sweep::ZERO }
    }
}

/// [`swept_boxes_apart_either`] with one form per box, each box swept by its
/// [`Sweep::graded_ball`] (`fa = FaceTerms::ball(a, ra)`, `fb = FaceTerms::ball(b, rb)`), on
/// `axes`: the same answer to the bit, the supports on the cross axes taken from the radii
/// directly.
#[inline]
pub fn balls_swept_apart_with(
    a: &Obb,
    ra: [Real; 2],
    fa: &FaceTerms,
    b: &Obb,
    rb: [Real; 2],
    fb: &FaceTerms,
    axes: Axes,
) -> bool {
    apart_on_an_axis(
        axes,
        (a, fa, |k: usize, sign| fa.graded(k, sign), graded_ball_support(ra, fa.u[0], a.half.x)),
        (b, fb, |k: usize, sign| fb.graded(k, sign), graded_ball_support(rb, fb.u[0], b.half.x)),
    )
}

/// The graded support of [`Sweep::graded_ball`]`(r)` for a box with axis 0 `x` and half-extent
/// `half` along it: `(m, |m|, sign)` to `g(sign m)`.
#[inline(always)]
fn graded_ball_support(r: [Real; 2], x: Vec3, half: Real) -> impl Fn(&Vec3, Real, Real) -> Real {
    move |n: &Vec3, len: Real, sign: Real| {
        graded_ends([r[0] * len, r[1] * len], half * (sign * x.dot(n)))
    }
}

/// The smaller graded support of two sweeps of a box with axis 0 `x` and half-extent `half`
/// along it: `(m, |m|, sign)` to `min_f g_f(sign m)`.
#[inline(always)]
fn least_graded_support<'a>(
    s: [&'a Sweep; 2],
    x: Vec3,
    half: Real,
) -> impl Fn(&Vec3, Real, Real) -> Real + 'a {
    move |n: &Vec3, len: Real, sign: Real| {
        let half_s = half * (sign * x.dot(n));
        s[0].graded_support(n, len, half_s).min(s[1].graded_support(n, len, half_s))
    }
}

fn axes(b: &Obb) -> [Vec3; 3] {
    [b.axes.column(0).into_owned(), b.axes.column(1).into_owned(), b.axes.column(2).into_owned()]
}

/// The radius of the projection on `n` of the box with axes `u` and half-extents `half`.
#[inline(always)]
fn radius(u: &[Vec3; 3], half: &Vec3, n: &Vec3) -> Real {
    half.x * u[0].dot(n).abs() + half.y * u[1].dot(n).abs() + half.z * u[2].dot(n).abs()
}

/// Whether `a + sa` and `b + sb` are proved disjoint by one of the 15 axes of `a` and `b`,
/// every point of a box moving anywhere in its set (see the module doc; `false` means "not
/// proved").
pub fn swept_boxes_apart(a: &Obb, sa: &Sweep, b: &Obb, sb: &Sweep) -> bool {
    swept_boxes_apart_with(a, sa, &FaceTerms::new(a, sa), b, sb, &FaceTerms::new(b, sb))
}

/// [`swept_boxes_apart`] with the face terms of both swept boxes computed beforehand
/// (`fa = FaceTerms::new(a, sa)`, `fb = FaceTerms::new(b, sb)`): the same answer, cheaper when
/// a box meets many others.
#[inline]
pub fn swept_boxes_apart_with(
    a: &Obb,
    sa: &Sweep,
    fa: &FaceTerms,
    b: &Obb,
    sb: &Sweep,
    fb: &FaceTerms,
) -> bool {
    let (ha, hb) = (|k: usize, _| fa.support[k], |k: usize, _| fb.support[k]);
    apart_on_an_axis(
        Axes::FifteenAnd(&Vec3::zeros()),
        (a, fa, ha, |n: &Vec3, len, _| sa.support_with_norm(n, len)),
        (b, fb, hb, |n: &Vec3, len, _| sb.support_with_norm(n, len)),
    )
}

/// Whether `a` and `b` are proved apart on one of `axes` (the 15 of the two boxes and one more
/// vector, or that vector alone; a vector shorter than `1e-5` is none) under the graded reading
/// of their sweeps (module doc,
/// "Graded along the box"; `sa[f]` a sweep of `a` with face terms
/// `fa[f] = FaceTerms::new(a, sa[f])`, likewise `b`), when each box has two sound bounds on
/// its displacements: one pass over the axes instead of four. The same answer, to the
/// bit, as trying the four pairs of forms one by one: on an axis, a pair separates when
/// `dn - (ra + rb) > gap` (the same for all pairs) and `dn - ((ra + rb + ga) + gb) > gap`; a
/// rounded sum never decreases when an addend grows, so the smaller graded support of each
/// box gives the smallest sum, and some pair separates exactly when that one does. A NaN
/// support fails its pairs, and `min` takes the other form's.
pub fn swept_boxes_apart_either(
    a: &Obb,
    sa: [&Sweep; 2],
    fa: [&FaceTerms; 2],
    b: &Obb,
    sb: [&Sweep; 2],
    fb: [&FaceTerms; 2],
    axes: Axes,
) -> bool {
    let (ga, gb) = (
        |k: usize, sign| fa[0].graded(k, sign).min(fa[1].graded(k, sign)),
        |k: usize, sign| fb[0].graded(k, sign).min(fb[1].graded(k, sign)),
    );
    // The axes, radii and norms depend on the boxes alone: the same in both forms.
    apart_on_an_axis(
        axes,
        (a, fa[0], ga, least_graded_support(sa, fa[0].u[0], a.half.x)),
        (b, fb[0], gb, least_graded_support(sb, fb[0].u[0], b.half.x)),
    )
}

/// Which axes a graded swept test tries.
#[derive(Clone, Copy, Debug)]
pub enum Axes<'a> {
    /// The 15 of the two boxes, and this vector first: a guess that proves pairs none of the
    /// 15 does (module doc, "Graded along the box").
    FifteenAnd(&'a Vec3),
    /// This vector alone.
    Only(&'a Vec3),
}

/// The 15 axes of the swept tests, and `also` first, or `also` alone ([`Axes`]; an axis is
/// skipped, as a cross-product axis is, when shorter than `1e-5`), for each box's terms
/// `(box, face terms, its support on its own face axis k, its support on any vector of the
/// given norm)`; each support is also given
/// the sign (`1` or `-1`) that turns the axis toward the other box (along `d = c_b - c_a` for
/// `a`, against it for `b`), which the graded supports read and the others ignore.
///
/// Axis `n` of norm `len` separates when `|n . d|` exceeds the four radii by the gap: `ra`,
/// `rb` the boxes', `ha`, `hb` the sweeps' supports, `(ra + rb + ha) + hb`. The supports are
/// never negative (a sweep's sizes are not, and a graded bracket is at least `h_1` or `h_2`),
/// so a rounded sum with them is never below the rounded `ra + rb`: when the boxes alone do
/// not clear the gap (or do not even come apart, then the norm is not needed either), the
/// swept ones do not, and what is left is not computed. The same answer, to the bit, as
/// computing everything.
#[inline(always)]
fn apart_on_an_axis(
    axes: Axes,
    (a, fa, face_a_support, a_support): (
        &Obb,
        &FaceTerms,
        impl Fn(usize, Real) -> Real,
        impl Fn(&Vec3, Real, Real) -> Real,
    ),
    (b, fb, face_b_support, b_support): (
        &Obb,
        &FaceTerms,
        impl Fn(usize, Real) -> Real,
        impl Fn(&Vec3, Real, Real) -> Real,
    ),
) -> bool {
    let d = b.center - a.center;
    let (ua, ub) = (&fa.u, &fb.u);
    /// `ha(sign)`, `hb(sign)`: the sweeps' supports, `sign` turning `n` from `a` toward `b`.
    #[inline(always)]
    fn separates(
        d: &Vec3,
        n: &Vec3,
        len: impl Fn() -> Real,
        ra: Real,
        rb: Real,
        ha: impl Fn(Real) -> Real,
        hb: impl Fn(Real) -> Real,
    ) -> bool {
        let dn_signed = d.dot(n);
        let (dn, boxes) = (dn_signed.abs(), ra + rb);
        // The boxes alone overlap along `n` (or a value is NaN): not apart.
        if (dn - boxes).is_nan() || dn - boxes <= 0.0 {
            return false;
        }
        let gap = SWEEP_GAP * len();
        let sign = if dn_signed >= 0.0 { 1.0 } else { -1.0 };
        dn - boxes > gap && dn - (boxes + ha(sign) + hb(-sign)) > gap
    }
    let face_a = |k: usize| {
        let (n, len) = (&ua[k], fa.norm[k]);
        let rb = radius(ub, &b.half, n);
        let (ha, hb) = (|sign| face_a_support(k, sign), |sign| b_support(n, len, sign));
        !fa.short[k] && separates(&d, n, || len, fa.radius[k], rb, ha, hb)
    };
    let face_b = |k: usize| {
        let (n, len) = (&ub[k], fb.norm[k]);
        let ra = radius(ua, &a.half, n);
        let (ha, hb) = (|sign| a_support(n, len, sign), |sign| face_b_support(k, sign));
        !fb.short[k] && separates(&d, n, || len, ra, fb.radius[k], ha, hb)
    };
    let any = |n: &Vec3| {
        let len2 = n.norm_squared();
        if len2 < 1e-10 {
            return false;
        }
        let len = || float::sqrt(len2);
        let (ra, rb) = (radius(ua, &a.half, n), radius(ub, &b.half, n));
        separates(
            &d,
            n,
            len,
            ra,
            rb,
            |sign| a_support(n, len(), sign),
            |sign| b_support(n, len(), sign),
        )
    };
    let edge = |i: usize, j: usize| any(&ua[i].cross(&ub[j]));
    match axes {
        Axes::Only(n) => any(n),
        Axes::FifteenAnd(also) => {
            any(also)
                || (0..3).any(face_a)
                || (0..3).any(face_b)
                || (0..3).any(|i| (0..3).any(|j| edge(i, j)))
        }
    }
}

/// The core of `b` under the displacement set `s` (module doc): the box shrunk along each of
/// its axes by the support of `s` along it; `None` when a half-extent would not stay positive.
pub fn core(b: &Obb, s: &Sweep) -> Option<Obb> {
    let half = Vec3::from_fn(|k, _| b.half[k] - s.support(&b.axes.column(k).into_owned()));
    (half.min() > 0.0).then_some(Obb { half, ..*b })
}

/// Whether the closed boxes `a` and `b` overlap by more than [`MEET_DEPTH`] on every one of
/// their 15 axes (so their interiors meet); `false` also when a cross-product axis is
/// shorter than `1e-5` (module doc, "Numerics").
pub fn boxes_overlap_deeply(a: &Obb, b: &Obb) -> bool {
    let d = b.center - a.center;
    let (ua, ub) = (axes(a), axes(b));
    let overlaps = |n: &Vec3| {
        let len2 = n.norm_squared();
        len2 >= 1e-10
            && radius(&ua, &a.half, n) + radius(&ub, &b.half, n) - d.dot(n).abs()
                > MEET_DEPTH * float::sqrt(len2)
    };
    ua.iter().chain(&ub).all(overlaps)
        && ua.iter().all(|x| ub.iter().all(|y| overlaps(&x.cross(y))))
}

/// Whether `a` moved by any displacements within `sa` and `b` by any within `sb` (each point
/// of a box by a displacement of its set, as a rigid motion does) always intersect: proved
/// when their cores overlap deeply (module doc). `false` means "not proved".
pub fn swept_boxes_always_meet(a: &Obb, sa: &Sweep, b: &Obb, sb: &Sweep) -> bool {
    match (core(a, sa), core(b, sb)) {
        (Some(ca), Some(cb)) => boxes_overlap_deeply(&ca, &cb),
        _ => false,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geometry::sat::separating_axis;
    use proptest::prelude::*;

    pub(crate) fn unit(v: Vec3) -> Vec3 {
        if v.norm() < 1e-6 {
            Vec3::z()
        } else {
            v.normalize()
        }
    }

    pub(crate) fn rot(e: (Real, Real, Real)) -> Mat3 {
        *nalgebra::Rotation3::from_euler_angles(e.0, e.1, e.2).matrix()
    }

    prop_compose! {
        pub(crate) fn any_box()(c in prop::array::uniform3(-300.0..300.0f64), e in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64),
                     h in prop::array::uniform3(1.0..150.0f64)) -> Obb {
            Obb::new(Vec3::from(c), rot(e), Vec3::from(h))
        }
    }

    prop_compose! {
        pub(crate) fn any_sweep()(w in prop::array::uniform3(0.0..30.0f64), e in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64),
                       f in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64), v in prop::array::uniform2(0.0..40.0f64),
                       ends in prop::array::uniform4(0.0..2.0f64), ball in 0.0..10.0f64,
                       round in prop_oneof![Just(0.0), 0.0..20.0f64]) -> Sweep {
            let (r, q) = (rot(e), rot(f));
            Sweep {
                cube: [r.column(0) * w[0], r.column(1) * w[1], r.column(2) * w[2]],
                round,
                arc: [q.column(0) * v[0], q.column(1) * v[1]],
                ends: [(ends[0], ends[1]), (ends[2], ends[3])],
                ball,
                line: Vec3::zeros(),
            }
        }
    }

    prop_compose! {
        /// [`any_sweep`], half of them with a segment.
        pub(crate) fn any_sweep_with_line()(s in any_sweep(), l in prop::array::uniform3(-25.0..25.0f64),
                                            on in any::<bool>()) -> Sweep {
            Sweep { line: if on { Vec3::from(l) } else { Vec3::zeros() }, ..s }
        }
    }

    /// A point of the displacement set `s` (module doc), from parameters in `[-1, 1]`: one of
    /// the two hulled sets, a point of its cube and rectangle, plus a point of the ball and
    /// one of the segment.
    pub(crate) fn point_of(s: &Sweep, t: &[Real; 8]) -> Vec3 {
        let k = if t[0] < 0.0 { 0 } else { 1 };
        let into_ball = |v: Vec3| if v.norm() > 1.0 { v.normalize() } else { v };
        end_set_point(s, k, t, into_ball) + s.line * (2.0 * t[0].abs() - 1.0)
    }

    /// A point of `E_end` plus one of the ball `c`, from `t[1..8]`: a point of the box `Z` and
    /// one of its rounding ball (from the same parameters), one of the rectangle `A`; `into_ball`
    /// maps `[-1, 1]^3` into the unit ball.
    fn end_set_point(
        s: &Sweep,
        end: usize,
        t: &[Real; 8],
        into_ball: impl Fn(Vec3) -> Vec3,
    ) -> Vec3 {
        let (e, d) = s.ends[end];
        let cube = s.cube[0] * t[1] + s.cube[1] * t[2] + s.cube[2] * t[3];
        let z = cube + into_ball(Vec3::new(t[1], t[2], t[3])) * s.round;
        let a = s.arc[0] * t[4] + s.arc[1] * t[5];
        z * e + a * d + into_ball(Vec3::new(t[5], t[6], t[7])) * s.ball
    }

    prop_compose! {
        /// Radii of a [`Sweep::graded_ball`]: equal, graded, or zero at one end.
        pub(crate) fn any_radii()(r in prop::array::uniform2(0.0..60.0f64), kind in 0..4usize) -> [Real; 2] {
            match kind { 0 => [r[0]; 2], 1 => [0.0, r[1]], 2 => [r[0], 0.0], _ => r }
        }
    }

    /// A point of the set that the points of a box's face `end` move within under the graded
    /// reading (module doc): `E_end` plus a point of the ball and one of the segment, from
    /// parameters in `[-1, 1]` pushed to the set's boundary for a third of their range.
    fn point_of_end(s: &Sweep, end: usize, t: &[Real; 8]) -> Vec3 {
        let t = t.map(|x| (1.5 * x).clamp(-1.0, 1.0));
        end_set_point(s, end, &t, |v: Vec3| v.try_normalize(1e-9).unwrap_or(v)) + s.line * t[0]
    }

    /// The corners of `b` after its face at `-half_0 u_0` moved by `d[0]` and the one at
    /// `+half_0 u_0` by `d[1]` (every point in between by the mix of the two, as the graded
    /// reading allows).
    fn deformed_corners(b: &Obb, d: [Vec3; 2]) -> [Vec3; 8] {
        let x = b.axes.column(0).into_owned();
        b.vertices().map(|v| v + d[usize::from(x.dot(&(v - b.center)) > 0.0)])
    }

    /// Whether one of the 15 axes of `a` and `b`, or `also`, separates the point sets `pa` and
    /// `pb`.
    fn corners_apart(a: &Obb, b: &Obb, pa: &[Vec3; 8], pb: &[Vec3; 8], also: &Vec3) -> bool {
        let (ua, ub) = (axes(a), axes(b));
        let apart = |n: &Vec3| {
            let range = |p: &[Vec3; 8]| {
                p.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), q| {
                    (lo.min(q.dot(n)), hi.max(q.dot(n)))
                })
            };
            let ((alo, ahi), (blo, bhi)) = (range(pa), range(pb));
            ahi < blo || bhi < alo
        };
        apart(also)
            || ua.iter().chain(&ub).any(apart)
            || ua.iter().any(|x| ub.iter().any(|y| apart(&x.cross(y))))
    }

    prop_compose! {
        /// An extra axis for the graded tests: none, or any vector.
        fn any_axis()(v in prop::array::uniform3(-2.0..2.0f64), on in any::<bool>()) -> Vec3 {
            if on { Vec3::from(v) } else { Vec3::zeros() }
        }
    }

    /// [`swept_boxes_apart_either`] with one sweep per box, given as both forms.
    fn graded_apart(a: &Obb, sa: &Sweep, b: &Obb, sb: &Sweep, also: &Vec3) -> bool {
        let (fa, fb) = (FaceTerms::new(a, sa), FaceTerms::new(b, sb));
        swept_boxes_apart_either(
            a,
            [sa, sa],
            [&fa, &fa],
            b,
            [sb, sb],
            [&fb, &fb],
            Axes::FifteenAnd(also),
        )
    }

    /// Displacement parameters for [`point_of`], one per robot box, as the property tests draw
    /// them.
    pub(crate) type Moves = Vec<([Real; 8], [Real; 8])>;

    /// Whether `apart` proves `a` swept by `sa` and `b` swept by `sb` apart; fails the case when
    /// the proof is not symmetric, or when boxes it proves apart meet (plain separating axis
    /// test) after being moved by displacements `moves` of their sets.
    pub(crate) fn proved_and_stay_apart(
        apart: impl Fn(&Obb, &Sweep, &Obb, &Sweep) -> bool,
        (a, sa): (&Obb, &Sweep),
        (b, sb): (&Obb, &Sweep),
        moves: &Moves,
    ) -> Result<bool, TestCaseError> {
        let proved = apart(a, sa, b, sb);
        prop_assert_eq!(proved, apart(b, sb, a, sa));
        if proved {
            for (ta, tb) in moves {
                let ma = Obb { center: a.center + point_of(sa, ta), ..*a };
                let mb = Obb { center: b.center + point_of(sb, tb), ..*b };
                prop_assert!(separating_axis(&ma, &mb).is_some());
            }
        }
        Ok(proved)
    }

    /// The test as first written (one closure for all 15 axes, supports recomputed): the
    /// prepared form must answer as it does, to the bit.
    fn swept_boxes_apart_as_written(a: &Obb, sa: &Sweep, b: &Obb, sb: &Sweep) -> bool {
        let d = b.center - a.center;
        let ua = [
            a.axes.column(0).into_owned(),
            a.axes.column(1).into_owned(),
            a.axes.column(2).into_owned(),
        ];
        let ub = [
            b.axes.column(0).into_owned(),
            b.axes.column(1).into_owned(),
            b.axes.column(2).into_owned(),
        ];
        let radius = |u: &[Vec3; 3], half: &Vec3, n: &Vec3| {
            half.x * u[0].dot(n).abs() + half.y * u[1].dot(n).abs() + half.z * u[2].dot(n).abs()
        };
        let support = |s: &Sweep, n: &Vec3| {
            let norm = float::sqrt(n.norm_squared());
            let z = s.cube[0].dot(n).abs()
                + s.cube[1].dot(n).abs()
                + s.cube[2].dot(n).abs()
                + s.round * norm;
            let a = s.arc[0].dot(n).abs() + s.arc[1].dot(n).abs();
            let [(e1, d1), (e2, d2)] = s.ends;
            s.ball * norm + s.line.dot(n).abs() + (e1 * z + d1 * a).max(e2 * z + d2 * a)
        };
        let separates = |n: &Vec3| {
            let len2 = n.norm_squared();
            if len2 < 1e-10 {
                return false;
            }
            let reach =
                radius(&ua, &a.half, n) + radius(&ub, &b.half, n) + support(sa, n) + support(sb, n);
            d.dot(n).abs() - reach > SWEEP_GAP * float::sqrt(len2)
        };
        ua.iter().chain(&ub).any(separates)
            || ua.iter().any(|x| ub.iter().any(|y| separates(&x.cross(y))))
    }

    /// Checks `same(t)` (whether two tests agree with B moved by `t` mm, and the reference
    /// test's answer there) at 0 and 2,000 mm and, where the answer flips from "not apart" to
    /// "apart" between them, at each of 80 bisection steps toward the flip.
    fn agree_through_the_flip(same: impl Fn(Real) -> (bool, bool)) -> Result<(), TestCaseError> {
        let (mut lo, mut hi) = (0.0, 2000.0);
        prop_assert!(same(lo).0 && same(hi).0);
        if !same(lo).1 && same(hi).1 {
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                let (ok, apart) = same(mid);
                prop_assert!(ok, "differs at {}", mid);
                if apart {
                    hi = mid
                } else {
                    lo = mid
                }
            }
        }
        Ok(())
    }

    proptest! {
        /// The test with prepared face terms answers as the test as first written, also right at
        /// the threshold (B moved along `v` by bisection to where the answer flips, both sides).
        #[test]
        fn prepared_swept_test_answers_as_written(a in any_box(), b in any_box(), sa in any_sweep_with_line(),
                sb in any_sweep_with_line(),
                v in prop::array::uniform3(-1.0..1.0f64)) {
            let v = unit(Vec3::from(v));
            let at = |t: Real| Obb { center: a.center + v * t, ..b };
            let same = |t: Real| {
                let b = at(t);
                let fast = swept_boxes_apart_with(&a, &sa, &FaceTerms::new(&a, &sa), &b, &sb, &FaceTerms::new(&b, &sb));
                (fast == swept_boxes_apart_as_written(&a, &sa, &b, &sb), fast)
            };
            agree_through_the_flip(same)?;
        }

        /// The test of boxes swept by graded balls answers as the general graded test with those
        /// balls as sweeps, also right at the threshold (B moved along `v` by bisection to where
        /// the answer flips), with parallel boxes and with zero radii.
        #[test]
        fn ball_swept_test_answers_as_the_general_one(a in any_box(), b in any_box(), ra in any_radii(),
                rb in any_radii(), v in prop::array::uniform3(-1.0..1.0f64), parallel in any::<bool>(),
                also in any_axis()) {
            let v = unit(Vec3::from(v));
            let b = if parallel { Obb { axes: a.axes, ..b } } else { b };
            let (sa, sb) = (Sweep::graded_ball(ra), Sweep::graded_ball(rb));
            prop_assert_eq!(FaceTerms::ball(&a, ra), FaceTerms::new(&a, &sa));
            let same = |t: Real| {
                let b = Obb { center: a.center + v * t, ..b };
                let general = graded_apart(&a, &sa, &b, &sb, &also);
                let (fa, fb) = (FaceTerms::ball(&a, ra), FaceTerms::ball(&b, rb));
                (balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::FifteenAnd(&also)) == general, general)
            };
            agree_through_the_flip(same)?;
        }

        /// The one-pass graded test over two forms per box answers as the four pairs of forms tried
        /// one by one, also right at the threshold of each pair (B moved along `v` by bisection
        /// to where that pair's answer flips, both sides), with parallel boxes (`b` turned like
        /// `a`) and with sweeps that are NaN or infinite in one form.
        #[test]
        fn either_form_test_answers_as_the_four_pairs(a in any_box(), b in any_box(), sa in any_sweep_with_line(),
                sa1 in any_sweep_with_line(), sb in any_sweep_with_line(), sb1 in any_sweep_with_line(), v in prop::array::uniform3(-1.0..1.0f64),
                parallel in any::<bool>(), odd in 0..4usize, also in any_axis()) {
            let v = unit(Vec3::from(v));
            let b = if parallel { Obb { axes: a.axes, ..b } } else { b };
            let sa1 = match odd { 1 => Sweep { ball: Real::NAN, ..sa1 }, 2 => Sweep { ball: Real::INFINITY, ..sa1 }, _ => sa1 };
            let at = |t: Real| Obb { center: a.center + v * t, ..b };
            let same = |t: Real| {
                let b = at(t);
                let (fa, fb) = ([sa, sa1].map(|w| FaceTerms::new(&a, &w)), [sb, sb1].map(|w| FaceTerms::new(&b, &w)));
                let pairs: [(usize, usize); 4] = [(0, 0), (1, 1), (0, 1), (1, 0)];
                let (wa, wb) = ([&sa, &sa1], [&sb, &sb1]);
                let each = pairs.map(|(i, k)| graded_apart(&a, wa[i], &b, wb[k], &also));
                let (fa, fb) = ([&fa[0], &fa[1]], [&fb[0], &fb[1]]);
                let once = swept_boxes_apart_either(&a, wa, fa, &b, wb, fb, Axes::FifteenAnd(&also));
                (once == each.iter().any(|&x| x), each)
            };
            prop_assert!(same(0.0).0 && same(2000.0).0);
            for pair in 0..4 {
                let (mut lo, mut hi) = (0.0, 2000.0);
                if same(lo).1[pair] || !same(hi).1[pair] {
                    continue;
                }
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    let (ok, each) = same(mid);
                    prop_assert!(ok, "differs at {}", mid);
                    if each[pair] { hi = mid } else { lo = mid }
                }
            }
        }

        /// Boxes moved by any displacements of their sets never intersect when the swept boxes
        /// are proved apart; and the proof is symmetric.
        #[test]
        fn apart_swept_boxes_stay_apart_under_every_displacement(a in any_box(), b in any_box(),
                sa in any_sweep_with_line(), sb in any_sweep_with_line(),
                ts in prop::collection::vec((prop::array::uniform8(-1.0..1.0f64), prop::array::uniform8(-1.0..1.0f64)), 32)) {
            proved_and_stay_apart(swept_boxes_apart, (&a, &sa), (&b, &sb), &ts)?;
        }

        /// Boxes whose faces across axis 0 move by any displacements of their own end sets (and
        /// every point in between by the mix, a deformation the graded reading allows) stay
        /// apart on one of the 15 axes when the graded test proves them apart (brute force on
        /// the moved corners); the proof is symmetric, and it proves at least what the test
        /// that moves every point in all of `S` proves.
        #[test]
        fn graded_apart_boxes_stay_apart_under_every_graded_displacement(a in any_box(), b in any_box(),
                sa in any_sweep_with_line(), sb in any_sweep_with_line(), toward in prop::array::uniform3(-1.0..1.0f64),
                also in any_axis(),
                ts in prop::collection::vec(prop::array::uniform4(prop::array::uniform8(-1.0..1.0f64)), 32)) {
            // B near A, so that both answers occur.
            let b = Obb { center: a.center + Vec3::from(toward) * 400.0, ..b };
            let proved = graded_apart(&a, &sa, &b, &sb, &also);
            prop_assert_eq!(proved, graded_apart(&b, &sb, &a, &sa, &also));
            prop_assert!(proved || !swept_boxes_apart(&a, &sa, &b, &sb));
            if proved {
                for t in &ts {
                    let pa = deformed_corners(&a, [point_of_end(&sa, 0, &t[0]), point_of_end(&sa, 1, &t[1])]);
                    let pb = deformed_corners(&b, [point_of_end(&sb, 0, &t[2]), point_of_end(&sb, 1, &t[3])]);
                    prop_assert!(corners_apart(&a, &b, &pa, &pb, &also));
                }
            }
        }

        /// The graded support is the reach of the swept box beyond the box along `m`, attained:
        /// the largest `m . (corner + displacement)` over the corners and the vertices of the
        /// corner's face's end set (brute force), less the box's own reach.
        #[test]
        fn graded_support_is_the_reach_of_the_corners(b in any_box(), s in any_sweep_with_line(),
                m in prop::array::uniform3(-1.0..1.0f64)) {
            let m = Vec3::from(m);
            let x = b.axes.column(0).into_owned();
            let sign = |i: usize, j: usize| if i >> j & 1 == 1 { 1.0 } else { -1.0 };
            let signs = |k: usize| (0..1 << k).map(move |i| (0..k).map(|j| sign(i, j)).collect::<Vec<Real>>());
            let mut reach = Real::NEG_INFINITY;
            for v in b.vertices() {
                let end = usize::from(x.dot(&(v - b.center)) > 0.0);
                let (e, d) = s.ends[end];
                for z in signs(3) {
                    for a in signs(2) {
                        for l in [-1.0, 1.0] {
                            let cube = s.cube[0] * z[0] + s.cube[1] * z[1] + s.cube[2] * z[2];
                            let disp = (cube + m.normalize() * s.round) * e + (s.arc[0] * a[0] + s.arc[1] * a[1]) * d
                                + m.normalize() * s.ball + s.line * l;
                            reach = reach.max(m.dot(&(v - b.center + disp)));
                        }
                    }
                }
            }
            let own = radius(&axes(&b), &b.half, &m);
            let g = s.graded_support(&m, m.norm(), b.half.x * x.dot(&m));
            prop_assert!((own + g - reach).abs() <= 1e-9 * (1.0 + reach.abs()), "{} + {} vs {}", own, g, reach);
            prop_assert!(g <= s.support(&m) + 1e-12);
        }

        /// With no displacement the test is the separating-axis test (up to its tolerances), and
        /// the support never exceeds the radius on unit vectors.
        #[test]
        fn zero_sweeps_agree_with_the_separating_axis_test(a in any_box(), b in any_box(), s in any_sweep_with_line(),
                n in prop::array::uniform3(-1.0..1.0f64)) {
            let apart = swept_boxes_apart(&a, &Sweep::ZERO, &b, &Sweep::ZERO);
            if apart {
                prop_assert!(separating_axis(&a, &b).is_some());
            }
            let n = unit(Vec3::from(n));
            prop_assert!(s.support(&n) <= s.radius() + 1e-9);
            prop_assert!((s.rotated(&rot((0.3, 0.2, 1.0))).support(&(rot((0.3, 0.2, 1.0)) * n)) - s.support(&n)).abs() < 1e-9);
        }
    }

    prop_compose! {
        /// A rigid motion `p -> pivot + rot (p - pivot) + t`, small enough that the cores often
        /// survive.
        fn small_motion()(e in (-0.2..0.2f64, -0.2..0.2f64, -0.2..0.2f64), pivot in prop::array::uniform3(-300.0..300.0f64),
                          t in prop::array::uniform3(-15.0..15.0f64)) -> (Mat3, Vec3, Vec3) {
            (rot(e), Vec3::from(pivot), Vec3::from(t))
        }
    }

    /// `b` moved by `(rot, pivot, t)` and its two displacement sets: a ball of the largest
    /// corner displacement, and a box along `b`'s axes of the largest corner displacement
    /// along each (a rigid motion's displacement is affine in the point, so its largest values
    /// over the box are at corners).
    fn moved(b: &Obb, (rot, pivot, t): &(Mat3, Vec3, Vec3)) -> (Obb, Sweep, Sweep) {
        let f = |p: Vec3| pivot + rot * (p - pivot) + t;
        let d = b.vertices().map(|v| f(v) - v);
        let up = |x: Real| x + 1e-9;
        let ball =
            Sweep { ball: up(d.iter().map(|v| v.norm()).fold(0.0, Real::max)), ..Sweep::ZERO };
        let along = |k: usize| {
            let u = b.axes.column(k).into_owned();
            u * up(d.iter().map(|v| u.dot(v).abs()).fold(0.0, Real::max))
        };
        let cube =
            Sweep { cube: [along(0), along(1), along(2)], ends: [(1.0, 0.0); 2], ..Sweep::ZERO };
        (Obb { center: f(b.center), axes: rot * b.axes, half: b.half }, ball, cube)
    }

    proptest! {
        /// Boxes whose cores overlap deeply intersect after any rigid motions within their
        /// displacement sets (exact separating axis test), whether the sets are balls of the
        /// largest corner displacement or boxes along the box's axes; and the test is symmetric.
        #[test]
        fn boxes_that_always_meet_intersect_after_every_small_motion(a in any_box(), b in any_box(),
                offset in prop::array::uniform3(-150.0..150.0f64), ma in small_motion(), mb in small_motion()) {
            let b = Obb { center: a.center + Vec3::from(offset), ..b };
            let ((fa, ball_a, cube_a), (fb, ball_b, cube_b)) = (moved(&a, &ma), moved(&b, &mb));
            for (sa, sb) in [(ball_a, ball_b), (cube_a, cube_b), (ball_a, cube_b)] {
                let meet = swept_boxes_always_meet(&a, &sa, &b, &sb);
                prop_assert_eq!(meet, swept_boxes_always_meet(&b, &sb, &a, &sa));
                if meet {
                    prop_assert!(separating_axis(&fa, &fb).is_none(), "{:?} {:?} -> {:?} {:?}", a, b, fa, fb);
                }
            }
        }

        /// A deep overlap is an intersection of the boxes themselves, and the cores under no
        /// displacement are the boxes.
        #[test]
        fn deep_overlap_implies_intersection(a in any_box(), b in any_box(), offset in prop::array::uniform3(-150.0..150.0f64)) {
            let b = Obb { center: a.center + Vec3::from(offset), ..b };
            if boxes_overlap_deeply(&a, &b) {
                prop_assert!(separating_axis(&a, &b).is_none());
            }
            prop_assert_eq!(core(&a, &Sweep::ZERO), Some(a));
        }
    }

    /// Two crossing plates (like two lower links) always meet under small displacements, not
    /// under ones as large as a plate's half-thickness, nor when merely touching.
    #[test]
    fn crossing_plates_always_meet_under_small_displacements() {
        let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::new(200.0, 70.0, 17.5));
        let b =
            Obb::new(Vec3::new(50.0, 0.0, 0.0), rot((0.0, 1.2, 0.3)), Vec3::new(200.0, 70.0, 17.5));
        let ball = |r: Real| Sweep { ball: r, ..Sweep::ZERO };
        assert!(swept_boxes_always_meet(&a, &ball(8.0), &b, &ball(8.0)));
        assert!(!swept_boxes_always_meet(&a, &ball(17.5), &b, &ball(1.0)));
        let touching =
            Obb::new(Vec3::new(400.0, 0.0, 0.0), Mat3::identity(), Vec3::new(200.0, 70.0, 17.5));
        assert!(!swept_boxes_always_meet(&a, &Sweep::ZERO, &touching, &Sweep::ZERO));
        let parallel =
            Obb::new(Vec3::new(10.0, 5.0, 1.0), Mat3::identity(), Vec3::new(200.0, 70.0, 17.5));
        assert!(
            !boxes_overlap_deeply(&a, &parallel),
            "parallel edges: degenerate axes, not certain"
        );
    }

    /// Over many random cases the test is not vacuous: it proves a good share of the pairs
    /// whose moved boxes intersect.
    #[test]
    fn always_meet_proves_many_intersections() {
        let mut rng = crate::test_rng::TestRng(0x2545_f491_4f6c_dd1d_u64);
        let mut next = move || rng.unit();
        let (mut proved, mut intersecting) = (0, 0);
        for _ in 0..20_000 {
            let x: [Real; 30] = std::array::from_fn(|_| next());
            let v = |i: usize| Vec3::new(x[i], x[i + 1], x[i + 2]);
            let rnd_box = |c: Vec3, i: usize| {
                let r = rot((3.2 * x[i], 3.2 * x[i + 1], 3.2 * x[i + 2]));
                Obb::new(
                    c,
                    r,
                    Vec3::new(
                        100.0 + 99.0 * x[i + 3],
                        40.0 + 30.0 * x[i + 4],
                        20.0 + 10.0 * x[i + 5],
                    ),
                )
            };
            let (a, b) = (rnd_box(Vec3::zeros(), 0), rnd_box(v(6) * 150.0, 9));
            let motion = |i: usize| {
                (
                    rot((0.05 * x[i], 0.05 * x[i + 1], 0.05 * x[i + 2])),
                    v(i + 3) * 200.0,
                    v(i + 6) * 3.0,
                )
            };
            let ((fa, sa, _), (fb, sb, _)) = (moved(&a, &motion(15)), moved(&b, &motion(21)));
            let meet = swept_boxes_always_meet(&a, &sa, &b, &sb);
            intersecting += separating_axis(&fa, &fb).is_none() as usize;
            if meet {
                assert!(separating_axis(&fa, &fb).is_none(), "{a:?} {b:?}");
                proved += 1;
            }
        }
        assert!(proved * 4 > intersecting, "{proved} proved of {intersecting} intersecting");
    }

    /// Two cubes corner to corner, swept by balls: no face axis separates the rounded boxes
    /// (and their edge axes are degenerate), the direction between the corners does, and only
    /// while the corners are farther apart than the two radii.
    #[test]
    fn the_extra_axis_proves_what_the_fifteen_cannot() {
        let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::repeat(1.0));
        let b = Obb::new(Vec3::repeat(2.5), Mat3::identity(), Vec3::repeat(1.0));
        let (fa, fb) = (FaceTerms::ball(&a, [0.3; 2]), FaceTerms::ball(&b, [0.3; 2]));
        let diagonal = Vec3::repeat(1.0);
        assert!(!balls_swept_apart_with(
            &a,
            [0.3; 2],
            &fa,
            &b,
            [0.3; 2],
            &fb,
            Axes::FifteenAnd(&Vec3::zeros())
        ));
        assert!(balls_swept_apart_with(
            &a,
            [0.3; 2],
            &fa,
            &b,
            [0.3; 2],
            &fb,
            Axes::FifteenAnd(&diagonal)
        ));
        // The corners are 0.866 apart: radii of 0.44 each leave no room on any axis.
        let (ga, gb) = (FaceTerms::ball(&a, [0.44; 2]), FaceTerms::ball(&b, [0.44; 2]));
        assert!(!balls_swept_apart_with(
            &a,
            [0.44; 2],
            &ga,
            &b,
            [0.44; 2],
            &gb,
            Axes::FifteenAnd(&diagonal)
        ));
    }

    #[test]
    fn zero_sweep_is_zero_and_a_ball_is_not() {
        assert!(Sweep::ZERO.is_zero());
        assert!(!Sweep { ball: 1.0, ..Sweep::ZERO }.is_zero());
        let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::repeat(1.0));
        let b = Obb::new(Vec3::new(3.0, 0.0, 0.0), Mat3::identity(), Vec3::repeat(1.0));
        assert!(swept_boxes_apart(&a, &Sweep::ZERO, &b, &Sweep::ZERO));
        assert!(swept_boxes_apart(&a, &Sweep { ball: 0.9, ..Sweep::ZERO }, &b, &Sweep::ZERO));
        assert!(!swept_boxes_apart(&a, &Sweep { ball: 1.0, ..Sweep::ZERO }, &b, &Sweep::ZERO));
    }
}
