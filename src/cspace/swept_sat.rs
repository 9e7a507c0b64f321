//! The swept-box separating axis test of the certified labelling, written in A's frame (as
//! Coal/FCL's `obbDisjoint` writes the plain one): the same 15 axes and the same inequality as
//! [`crate::geometry::sweep`] (module doc there, "The test"), with the boxes' terms read from
//! `R = A^T B` and `t = A^T d` instead of from explicit cross products.
//!
//! # The terms
//! For boxes with orthonormal axes `a_k`, `b_k` (columns), half-extents `ha`, `hb`,
//! `R_ij = a_i . b_j`, `d = c_B - c_A` and `t_k = a_k . d`:
//! - face axis `a_k`: `|d . a_k| = |t_k|`, A's radius `ha_k`, B's `sum_j hb_j |R_kj|`;
//! - face axis `b_k`: `|d . b_k|`, A's radius `sum_i ha_i |R_ik|`, B's `hb_k`;
//! - edge axis `n = a_i x b_j`, `(i, i1, i2)` and `(j, j1, j2)` cyclic: writing `n` in A's
//!   frame, `a_k . n = b_j . (a_k x a_i)`, which is 0 for `k = i`, `-s R_i2j` for `k = i1` and
//!   `s R_i1j` for `k = i2`, `s = det(a) = +/-1`. So `|d . n| = |t_i2 R_i1j - t_i1 R_i2j|`,
//!   A's radius `sum_k ha_k |a_k . n| = ha_i1 |R_i2j| + ha_i2 |R_i1j|`, and likewise B's,
//!   `hb_j1 |R_ij2| + hb_j2 |R_ij1|`; `|n|^2 = 1 - R_ij^2`. Only the absolute values enter,
//!   so the handedness `s` of either frame does not matter.
//!
//! The sweeps' supports `h_S(n)` are computed from `n` itself (face axes: the axis; edge
//! axes: the cross product), and only on the axes where the boxes alone come apart.
//!
//! # Order of the axes
//! The answer is whether *some* axis separates: it depends neither on the order in which the
//! axes are read nor on where reading stops, and each axis's terms are computed by the same
//! operations whatever the order, so every order gives the same answers to the bit. A test
//! that finds an axis stops there, so the axes are read in the order that finds one soonest
//! for the robots' link boxes (axis 0 along the link): counted over every swept test of a
//! `shared-sub` build of T1 (k = 16 and 32, `docs/record/2026-11-25-build-axes.md`), the
//! first separating axis in the order A's faces, B's faces, edges was, at k = 32 (k = 16),
//! `a_0 x b_0` for 35 % (33 %) of the tests, A's face 2 for 17 % (17 %), B's face 1 for 3 %
//! (8 %), any other axis for 3 % (2 %) together; 43 % (40 %) found none. So `a_0 x b_0`,
//! A's face 2 and B's face 1 come first, then the other faces and the other edges in the
//! order above. `R` and `t` are computed whole first (the first axis already reads most of
//! them).
//!
//! # Numerics
//! The identities above hold for exactly orthonormal frames; the boxes' frames are rotation
//! matrices to a few units in the last place (about 1e-15), and every dot product rounds by
//! about as much. Each `|R_ij|` is enlarged by [`R_GUARD`] = 1e-12 before it enters a radius,
//! which adds at least `1e-12 (ha_i1 + ha_i2 + hb_j1 + hb_j2)` to the radii, and an axis
//! separates only when its gap exceeds [`SWEEP_GAP`]` |n|` (1e-6 mm along the unit axis) as
//! in the reference test; edge axes with `|n|^2 < 1e-10` are skipped as there. For boxes and
//! distances below 1e4 mm the rounding of `|d . n|` and of the radii is below 1e-10 `|n|` mm
//! (`|n| >= 1e-5` on a tested edge axis), far inside the 1e-6 `|n|` mm gap: an axis called
//! separating separates the exact swept sets. Face axes use `|n| = 1` (the sweeps' ball term
//! `c |n|` and the gap are off by `c` or 1e-6 times 1e-15 mm). All of it errs toward "not
//! apart"; a value that is not finite (NaN) never separates.

use crate::geometry::sweep::{Sweep, SWEEP_GAP};
use crate::geometry::Obb;
use crate::math::{float, Real, Vec3};

/// Added to every `|R_ij|` entering a radius (module doc, "Numerics").
pub const R_GUARD: Real = 1e-12;

/// A table's displacement set: a [`Sweep`] without its segment `line`, which the tables'
/// sweeps ([`crate::robot::motion_bound::cube_box_sweeps`]) never have, so that [`support`]
/// leaves it out and a swept box need not hold it (24 bytes fewer per box).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableSweep {
    /// [`Sweep::cube`].
    pub cube: [Vec3; 3],
    /// [`Sweep::round`].
    pub round: Real,
    /// [`Sweep::arc`].
    pub arc: [Vec3; 2],
    /// [`Sweep::ends`].
    pub ends: [(Real, Real); 2],
    /// [`Sweep::ball`].
    pub ball: Real,
}

impl TableSweep {
    /// `s` without its segment; `None` when the segment is not zero (the swept test would
    /// leave out displacements of the set).
    pub fn of(s: &Sweep) -> Option<TableSweep> {
        let Sweep { cube, round, arc, ends, ball, line } = *s;
        (line == Vec3::zeros()).then_some(TableSweep { cube, round, arc, ends, ball })
    }

    /// The sweep it holds, with a zero segment: [`Sweep::support`] and everything built on
    /// it give what they gave on the sweep it was made from, to the bit (a zero segment adds
    /// `|0 . n| = +0` to a support, whatever the signs of its zeros).
    pub fn sweep(&self) -> Sweep {
        let TableSweep { cube, round, arc, ends, ball } = *self;
        Sweep { cube, round, arc, ends, ball, line: Vec3::zeros() }
    }
}

/// One swept box as [`swept_apart`] reads it: axes as rows, half-extents, and the sweep's
/// support on the box's own axes (computed once per box, used by every pair).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweptFrame {
    /// `u[k]`: the box's axis `k` (column `k` of [`Obb::axes`]).
    pub u: [[Real; 3]; 3],
    /// Half-extents.
    pub h: [Real; 3],
    /// `h_S(u[k])`, the sweep's support on axis `k` (as a unit vector).
    pub face_support: [Real; 3],
}

impl SweptFrame {
    /// The frame of box `b` swept by `s`.
    pub fn new(b: &Obb, s: &TableSweep) -> SweptFrame {
        let m = &b.axes;
        let u: [[Real; 3]; 3] = core::array::from_fn(|k| [m[(0, k)], m[(1, k)], m[(2, k)]]);
        SweptFrame {
            u,
            h: [b.half.x, b.half.y, b.half.z],
            face_support: u.map(|n| support(s, &n, 1.0)),
        }
    }
}

#[inline(always)]
fn dot(u: &[Real; 3], v: &[Real; 3]) -> Real {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

/// `h_S(n)` of the sweep module doc for a vector `n` of length `norm`.
#[inline(always)]
fn support(s: &TableSweep, n: &[Real; 3], norm: Real) -> Real {
    let d = |w: &Vec3| (w.x * n[0] + w.y * n[1] + w.z * n[2]).abs();
    let z = d(&s.cube[0]) + d(&s.cube[1]) + d(&s.cube[2]) + s.round * norm;
    let a = d(&s.arc[0]) + d(&s.arc[1]);
    let [(e1, d1), (e2, d2)] = s.ends;
    s.ball * norm + (e1 * z + d1 * a).max(e2 * z + d2 * a)
}

/// Whether an axis with `|d . n| = dn`, boxes' radii summing to `boxes` and length `len`
/// separates the swept boxes, the sweeps' supports `sweeps()` found only when the boxes
/// alone come apart by the gap.
#[inline(always)]
fn separates(
    dn: Real,
    boxes: Real,
    len: impl Fn() -> Real,
    sweeps: impl FnOnce(Real) -> Real,
) -> bool {
    let apart = dn - boxes;
    // The boxes alone overlap along the axis (or a value is NaN): not apart.
    if apart.is_nan() || apart <= 0.0 {
        return false;
    }
    let l = len();
    let gap = SWEEP_GAP * l;
    apart > gap && dn - (boxes + sweeps(l)) > gap
}

/// What every axis of one swept test reads: `d = c_B - c_A`, `R = A^T B` (`r`), `|R|` enlarged
/// by the guard (`ar`), `t = A^T d`, and the two frames and sweeps.
struct Pair<'a> {
    d: [Real; 3],
    r: [[Real; 3]; 3],
    ar: [[Real; 3]; 3],
    t: [Real; 3],
    fa: &'a SweptFrame,
    sa: &'a TableSweep,
    fb: &'a SweptFrame,
    sb: &'a TableSweep,
}

impl Pair<'_> {
    /// Whether A's face axis `k` separates.
    #[inline(always)]
    fn face_a(&self, k: usize) -> bool {
        let (ar, hb, fa) = (&self.ar, &self.fb.h, self.fa);
        let rb = hb[0] * ar[k][0] + hb[1] * ar[k][1] + hb[2] * ar[k][2];
        separates(
            self.t[k].abs(),
            fa.h[k] + rb,
            || 1.0,
            |l| fa.face_support[k] + support(self.sb, &fa.u[k], l),
        )
    }

    /// Whether B's face axis `k` separates.
    #[inline(always)]
    fn face_b(&self, k: usize) -> bool {
        let (ar, ha, fb) = (&self.ar, &self.fa.h, self.fb);
        let ra = ha[0] * ar[0][k] + ha[1] * ar[1][k] + ha[2] * ar[2][k];
        let n = &fb.u[k];
        separates(
            dot(n, &self.d).abs(),
            ra + fb.h[k],
            || 1.0,
            |l| support(self.sa, n, l) + fb.face_support[k],
        )
    }

    /// Whether the edge axis `a_i x b_j` separates.
    #[inline(always)]
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // written so that NaN fails the tests
    fn edge(&self, i: usize, j: usize) -> bool {
        let (r, ar, t, ha, hb) = (&self.r, &self.ar, &self.t, &self.fa.h, &self.fb.h);
        let len2 = 1.0 - r[i][j] * r[i][j];
        // Nearly parallel edges (or a NaN): the axis's direction is not known well enough.
        if !(len2 >= 1e-10) {
            return false;
        }
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        let dn = (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs();
        let boxes =
            ha[i1] * ar[i2][j] + ha[i2] * ar[i1][j] + hb[j1] * ar[i][j2] + hb[j2] * ar[i][j1];
        let sweeps = |l: Real| {
            let (x, y) = (&self.fa.u[i], &self.fb.u[j]);
            let n =
                [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
            support(self.sa, &n, l) + support(self.sb, &n, l)
        };
        separates(dn, boxes, || float::sqrt(len2), sweeps)
    }
}

/// Whether box A (centre `ca`, frame `fa`) swept by `sa` and box B (centre `cb`, frame `fb`)
/// swept by `sb` are proved disjoint by one of their 15 axes (module doc); `false` means "not
/// proved". The axes are read in the order of the module doc, "Order of the axes", each
/// stopping the test when it separates.
#[inline]
pub fn swept_apart(
    ca: &Vec3,
    fa: &SweptFrame,
    sa: &TableSweep,
    cb: &Vec3,
    fb: &SweptFrame,
    sb: &TableSweep,
) -> bool {
    let dv = cb - ca;
    let d = [dv.x, dv.y, dv.z];
    let (ua, ub) = (&fa.u, &fb.u);
    let mut r = [[0.0; 3]; 3];
    let mut ar = [[0.0; 3]; 3];
    let mut t = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&ua[i], &ub[j]);
            ar[i][j] = r[i][j].abs() + R_GUARD;
        }
        t[i] = dot(&ua[i], &d);
    }
    let p = Pair { d, r, ar, t, fa, sa, fb, sb };
    p.edge(0, 0)
        || p.face_a(2)
        || p.face_b(1)
        || p.face_a(1)
        || p.face_a(0)
        || p.face_b(0)
        || p.face_b(2)
        || p.edge(0, 1)
        || p.edge(0, 2)
        || p.edge(1, 0)
        || p.edge(1, 1)
        || p.edge(1, 2)
        || p.edge(2, 0)
        || p.edge(2, 1)
        || p.edge(2, 2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sat::separating_axis;
    use crate::geometry::sweep::swept_boxes_apart;
    use crate::geometry::sweep::tests::{
        any_box, any_sweep, any_sweep_with_line, proved_and_stay_apart, rot,
    };
    use crate::math::Mat3;
    use proptest::prelude::*;

    /// [`swept_apart`] as first written: face axes of A first, then B's, then the edges, each
    /// axis's terms computed when it is reached, stopping at the first that separates. The
    /// statement the reordered form must answer as, to the bit.
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // written so that NaN fails the tests
    fn swept_apart_in_first_order(
        a: &Obb,
        fa: &SweptFrame,
        sa: &TableSweep,
        b: &Obb,
        fb: &SweptFrame,
        sb: &TableSweep,
    ) -> bool {
        let dv = b.center - a.center;
        let d = [dv.x, dv.y, dv.z];
        let (ua, ub, ha, hb) = (&fa.u, &fb.u, &fa.h, &fb.h);
        let mut r = [[0.0; 3]; 3];
        let mut ar = [[0.0; 3]; 3];
        let mut t = [0.0; 3];
        for k in 0..3 {
            r[k] = [dot(&ua[k], &ub[0]), dot(&ua[k], &ub[1]), dot(&ua[k], &ub[2])];
            ar[k] = r[k].map(|x| x.abs() + R_GUARD);
            t[k] = dot(&ua[k], &d);
            let rb = hb[0] * ar[k][0] + hb[1] * ar[k][1] + hb[2] * ar[k][2];
            let n = &ua[k];
            if separates(t[k].abs(), ha[k] + rb, || 1.0, |l| fa.face_support[k] + support(sb, n, l))
            {
                return true;
            }
        }
        for k in 0..3 {
            let ra = ha[0] * ar[0][k] + ha[1] * ar[1][k] + ha[2] * ar[2][k];
            let n = &ub[k];
            if separates(
                dot(n, &d).abs(),
                ra + hb[k],
                || 1.0,
                |l| support(sa, n, l) + fb.face_support[k],
            ) {
                return true;
            }
        }
        for i in 0..3 {
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            for j in 0..3 {
                let len2 = 1.0 - r[i][j] * r[i][j];
                // Nearly parallel edges (or a NaN): the axis's direction is not known well enough.
                if !(len2 >= 1e-10) {
                    continue;
                }
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                let dn = (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs();
                let boxes = ha[i1] * ar[i2][j]
                    + ha[i2] * ar[i1][j]
                    + hb[j1] * ar[i][j2]
                    + hb[j2] * ar[i][j1];
                let sweeps = |l: Real| {
                    let (x, y) = (&ua[i], &ub[j]);
                    let n = [
                        x[1] * y[2] - x[2] * y[1],
                        x[2] * y[0] - x[0] * y[2],
                        x[0] * y[1] - x[1] * y[0],
                    ];
                    support(sa, &n, l) + support(sb, &n, l)
                };
                if separates(dn, boxes, || float::sqrt(len2), sweeps) {
                    return true;
                }
            }
        }
        false
    }

    /// [`swept_apart`], checked against [`swept_apart_in_first_order`] (the same answer) on
    /// every case of the tests below: random, close, parallel and touching boxes.
    fn apart(a: &Obb, sa: &Sweep, b: &Obb, sb: &Sweep) -> bool {
        let (ta, tb) = (TableSweep::of(sa).unwrap(), TableSweep::of(sb).unwrap());
        let (fa, fb) = (SweptFrame::new(a, &ta), SweptFrame::new(b, &tb));
        let proved = swept_apart(&a.center, &fa, &ta, &b.center, &fb, &tb);
        assert_eq!(
            proved,
            swept_apart_in_first_order(a, &fa, &ta, b, &fb, &tb),
            "{a:?} {sa:?} {b:?} {sb:?}"
        );
        proved
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// A table's sweep is the sweep without its segment: made only from a sweep whose
        /// segment is zero, and what it gives back has every number of the sweep given, to the
        /// bit, and the same support on any vector (a segment of zeros of either sign adds +0).
        #[test]
        fn table_sweep_keeps_every_number_but_the_zero_segment(s in any_sweep_with_line(),
                n in prop::array::uniform3(-2.0..2.0f64), signs in prop::array::uniform3(any::<bool>())) {
            let zero = Vec3::from(signs.map(|neg| if neg { -0.0 } else { 0.0 }));
            let s = if s.line == Vec3::zeros() { Sweep { line: zero, ..s } } else { s };
            match TableSweep::of(&s) {
                None => prop_assert!(s.line != Vec3::zeros()),
                Some(t) => {
                    let back = t.sweep();
                    let bits = |w: &Sweep| {
                        let v = w.cube.iter().chain(&w.arc).flat_map(|v| v.iter().copied());
                        let e = w.ends.iter().flat_map(|&(e, d)| [e, d]);
                        v.chain(e).chain([w.round, w.ball]).map(Real::to_bits).collect::<Vec<_>>()
                    };
                    prop_assert_eq!(bits(&back), bits(&s));
                    prop_assert_eq!(back.line, Vec3::zeros());
                    let n = Vec3::from(n);
                    prop_assert_eq!(back.support(&n).to_bits(), s.support(&n).to_bits());
                }
            }
        }

        /// The reordered test answers as the one first written right at the threshold: B moved
        /// from A's centre along `v` by bisection to where the answer flips, both sides checked
        /// at each step (`apart`), with no sweep, one, or two.
        #[test]
        fn reordered_test_answers_as_first_written_at_the_threshold(a in any_box(), b in any_box(),
                sa in any_sweep(), sb in any_sweep(), v in prop::array::uniform3(-1.0..1.0f64), zero in 0..4u8) {
            let (sa, sb) = match zero { 0 => (Sweep::ZERO, Sweep::ZERO), 1 => (sa, Sweep::ZERO), _ => (sa, sb) };
            let v = Vec3::from(v);
            let v = if v.norm() < 1e-6 { Vec3::z() } else { v.normalize() };
            let at = |t: Real| apart(&a, &sa, &Obb { center: a.center + v * t, ..b }, &sb);
            let (mut lo, mut hi) = (0.0, 2000.0);
            if !at(lo) && at(hi) {
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    if at(mid) { hi = mid } else { lo = mid }
                }
            }
        }

        /// Boxes proved apart stay apart (plain separating axis test) when each is moved by
        /// any displacement of its set; the proof is symmetric; and it agrees with the 15-axis
        /// test of `geometry::sweep`, which computes every axis by explicit cross products.
        #[test]
        fn apart_boxes_stay_apart_and_agree_with_the_reference_test(a in any_box(), b in any_box(),
                sa in any_sweep(), sb in any_sweep(),
                ts in prop::collection::vec(
                    (prop::array::uniform8(-1.0..1.0f64), prop::array::uniform8(-1.0..1.0f64)), 16)) {
            let proved = proved_and_stay_apart(apart, (&a, &sa), (&b, &sb), &ts)?;
            prop_assert_eq!(proved, swept_boxes_apart(&a, &sa, &b, &sb));
        }

        /// Close boxes (centres within 60 mm, so many touch or nearly do): the same answers as
        /// the reference test, and never "apart" when the boxes at the references meet.
        #[test]
        fn close_boxes_agree_with_the_reference_test(a in any_box(), off in prop::array::uniform3(-60.0..60.0f64),
                e in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64), h in prop::array::uniform3(0.5..40.0f64),
                sa in any_sweep(), sb in any_sweep(), zero in 0..4u8) {
            let b = Obb::new(a.center + Vec3::from(off), rot(e), Vec3::from(h));
            let (sa, sb) = match zero { 0 => (Sweep::ZERO, Sweep::ZERO), 1 => (sa, Sweep::ZERO), _ => (sa, sb) };
            let proved = apart(&a, &sa, &b, &sb);
            prop_assert_eq!(proved, swept_boxes_apart(&a, &sa, &b, &sb));
            if separating_axis(&a, &b).is_none() {
                prop_assert!(!proved);
            }
        }

        /// Parallel and touching boxes (same axes up to quarter turns, so that every edge axis
        /// is degenerate or exact): touching or overlapping boxes are never apart, whatever
        /// the sweeps; a face gap wider than both sweeps' radii plus 1e-3 mm is.
        #[test]
        fn parallel_boxes(e in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64), turn in 0..4u8, axis in 0..3usize,
                ha in prop::array::uniform3(1.0..50.0f64), hb in prop::array::uniform3(1.0..50.0f64),
                gap in -5.0..5.0f64, sa in any_sweep(), sb in any_sweep()) {
            let ra = rot(e);
            let quarter = rot((0.0, 0.0, Real::from(turn) * core::f64::consts::FRAC_PI_2));
            let rb = ra * quarter;
            let a = Obb::new(Vec3::new(10.0, -20.0, 30.0), ra, Vec3::from(ha));
            let b_half = Vec3::from(hb);
            // B's extent along A's axis `axis`: its half-extents through the quarter turn.
            let u = ra.column(axis).into_owned();
            let reach = (0..3).map(|k| b_half[k] * (rb.column(k).dot(&u)).abs()).sum::<Real>();
            let b = Obb::new(a.center + u * (ha[axis] + reach + gap), rb, b_half);
            for (sa, sb) in [(Sweep::ZERO, Sweep::ZERO), (sa, Sweep::ZERO), (sa, sb)] {
                let proved = apart(&a, &sa, &b, &sb);
                if gap <= 0.0 {
                    prop_assert!(!proved, "gap {}", gap);
                }
                if gap > sa.radius() + sb.radius() + 1e-3 {
                    prop_assert!(proved, "gap {} radii {} {}", gap, sa.radius(), sb.radius());
                }
            }
        }
    }

    #[test]
    fn face_touching_boxes_are_not_apart_and_a_gap_is() {
        let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::new(1.0, 1.0, 1.0));
        let at =
            |x: Real| Obb::new(Vec3::new(x, 0.0, 0.0), Mat3::identity(), Vec3::new(1.0, 1.0, 1.0));
        assert!(!apart(&a, &Sweep::ZERO, &at(2.0), &Sweep::ZERO));
        assert!(apart(&a, &Sweep::ZERO, &at(2.001), &Sweep::ZERO));
        let ball = Sweep { ball: 0.01, ..Sweep::ZERO };
        assert!(!apart(&a, &ball, &at(2.001), &Sweep::ZERO));
        assert!(apart(&a, &ball, &at(2.02), &Sweep::ZERO));
    }
}
