//! The stop's sweeps of a robot's boxes in the WCS (module doc of `protective`, steps 3-4)
//! and the swept-box proof over the box pairs of two robots (step 5): the first box pair that
//! no axis proves apart in either sweep form.

use super::{BoxPair, STOP_SPLITS};
use crate::cell::exact::PairVerdict;
use crate::geometry::graded_closest::{graded_closest, GradedClosest};
use crate::geometry::sweep::{swept_boxes_apart_either, Axes, FaceTerms};
use crate::geometry::{Obb, Sweep};
use crate::math::{Real, Vec3};
use crate::robot::motion_bound::{box_sweep_forms_into, theta_range, Enclosure};
use crate::robot::motor_table::MotorTable;
use crate::robot::{RobotBoxes, RobotModel, MAX_BOXES};

/// A robot's boxes swept over every TCP of a ball (module doc of `protective`, steps 3-6):
/// the ball, the boxes at its centre, their sweeps in both forms, the face terms of each box
/// under each form and the boxes' graded radii. A stop's reference, a kept ball and a piece of
/// a stop path are each one.
#[derive(Clone, Copy, Debug)]
pub(super) struct SweptBall {
    /// The ball's centre (MCS) and radius (mm).
    pub(super) centre: Vec3,
    pub(super) radius: Real,
    /// The robot's boxes (WCS) at the centre.
    pub(super) boxes: RobotBoxes,
    /// Per form and box, the displacements of the box's points over the ball (WCS).
    pub(super) sweeps: SweepForms,
    /// Per form and box, the face terms of the box under that sweep.
    pub(super) faces: [[FaceTerms; MAX_BOXES]; 2],
    /// Per box, the radii of the graded ball that every sweep of the box holds (step 6).
    pub(super) graded: GradedRadii,
}

impl SweptBall {
    /// No ball: no boxes, zero sweeps, `faces` for every face term (those of a box without
    /// sweep).
    pub(super) fn empty(faces: FaceTerms) -> SweptBall {
        let (sweeps, faces) = ([[Sweep::ZERO; MAX_BOXES]; 2], [[faces; MAX_BOXES]; 2]);
        SweptBall {
            centre: Vec3::zeros(),
            radius: 0.0,
            boxes: RobotBoxes::empty(),
            sweeps,
            faces,
            graded: [[0.0; 2]; MAX_BOXES],
        }
    }

    /// Sets the face terms of every box from its sweeps.
    pub(super) fn set_faces(&mut self) {
        for (form, faces) in self.faces.iter_mut().enumerate() {
            for (k, b) in self.boxes.as_slice().iter().enumerate() {
                faces[k] = FaceTerms::new(b, &self.sweeps[form][k]);
            }
        }
    }
}

/// The WCS displacement sets of the boxes of a robot at `tcp_mcs` when its TCP may go
/// anywhere within `s` of it (module doc, steps 3-4); infinite balls when unbounded. The motor
/// angles come from `table` (built for `model.delta`) where it covers the cube, else from the
/// interval inverse kinematics with [`STOP_SPLITS`]: the first tier, without the second.
pub fn stop_sweeps_wcs(
    model: &RobotModel,
    rot_wcs: &crate::math::Mat3,
    tcp_mcs: &Vec3,
    s: Real,
    table: Option<&MotorTable>,
) -> SweepForms {
    let mut out = [[Sweep::ZERO; MAX_BOXES]; 2];
    stop_sweeps_wcs_into(&mut out, model, rot_wcs, tcp_mcs, s, table, 0, 0);
    out
}

/// The sweeps of [`stop_sweeps_wcs`] written into `out` (the tick's are recomputed in place,
/// many times per tick by the speed limits' tests, without whole sets copied on the way),
/// with the second tier for the arms in the bit mask `arms`: the table's motor angles
/// intersected with the interval inverse kinematics in `precise^3` sub-boxes (none when
/// `precise` is 0).
#[allow(clippy::too_many_arguments)]
pub(super) fn stop_sweeps_wcs_into(
    out: &mut SweepForms,
    model: &RobotModel,
    rot_wcs: &crate::math::Mat3,
    tcp_mcs: &Vec3,
    s: Real,
    table: Option<&MotorTable>,
    precise: u32,
    arms: u8,
) {
    let d = &model.delta;
    let direct = |lo: &Vec3, hi: &Vec3, splits: u32| -> [Enclosure; 3] {
        core::array::from_fn(|arm| theta_range(d, arm, lo, hi, splits))
    };
    let filled = match table.filter(|t| t.delta() == d) {
        Some(t) => box_sweep_forms_into(out, model, tcp_mcs, s, tcp_mcs, |lo, hi| {
            match t.enclose(lo, hi) {
                Some(th) if precise > 0 => {
                    let refine = |arm: usize| arms >> arm & 1 == 1;
                    core::array::from_fn(|arm| {
                        if refine(arm) {
                            th[arm].intersect(theta_range(d, arm, lo, hi, precise))
                        } else {
                            th[arm]
                        }
                    })
                }
                Some(th) => th,
                None => direct(lo, hi, STOP_SPLITS),
            }
        }),
        None => box_sweep_forms_into(out, model, tcp_mcs, s, tcp_mcs, |lo, hi| {
            direct(lo, hi, STOP_SPLITS)
        }),
    };
    write_forms(out, filled, rot_wcs);
}

/// Both forms of the sweeps in `out` (MCS, when `filled`) rotated to the WCS with `rot_wcs`
/// in place; infinite balls when not `filled`.
fn write_forms(out: &mut SweepForms, filled: bool, rot_wcs: &crate::math::Mat3) {
    if filled {
        for w in out.iter_mut().flatten() {
            *w = w.rotated(rot_wcs);
        }
    } else {
        *out = [[Sweep { ball: Real::INFINITY, ..Sweep::ZERO }; MAX_BOXES]; 2];
    }
}

/// Two forms of the same bound on each box's displacements (module doc, step 4): `[0]` with
/// the TCP's motion as a cube, `[1]` as a ball; either alone is sound.
pub type SweepForms = [[Sweep; MAX_BOXES]; 2];

/// The first box pair (of the pairs involving `only`, or of all pairs) not proved apart
/// with `extra` mm added to the first robot's sweep, robot `j` swept as `ball(j)`, each pair
/// `k` also tried on `axis(k)`.
pub(super) fn first_unproved<'a>(
    pairs: &[PairVerdict],
    ball: impl Fn(usize) -> &'a SweptBall,
    axis: impl Fn(usize) -> &'a Vec3,
    only: Option<usize>,
    extra: Real,
) -> Option<BoxPair> {
    for (k, p) in
        pairs.iter().enumerate().filter(|(_, p)| only.is_none_or(|j| p.a == j || p.b == j))
    {
        if let Some((box_a, box_b)) = first_unproved_between(ball(p.a), ball(p.b), extra, axis(k)) {
            return Some(BoxPair { a: p.a, b: p.b, box_a, box_b });
        }
    }
    None
}

/// Whether box `a` swept by `sa` (one per form, `extra` mm added to its ball) and box `b`
/// swept by `sb` are proved apart in some combination of forms, on their 15 axes, on `axis`
/// or on their graded axis ([`graded_points`]) from the graded radii `ra` and `rb`
/// ([`first_unproved_between`]'s test for one box pair).
pub(super) fn pair_apart_in_some_form(
    (a, sa, ra): (&Obb, [&Sweep; 2], [Real; 2]),
    (b, sb, rb): (&Obb, [&Sweep; 2], [Real; 2]),
    extra: Real,
    axis: &Vec3,
) -> bool {
    let mut wider = None;
    let sa = with_extra(sa, extra, &mut wider);
    let (fa0, fa1) = (FaceTerms::new(a, sa[0]), FaceTerms::new(a, sa[1]));
    let (fb0, fb1) = (FaceTerms::new(b, sb[0]), FaceTerms::new(b, sb[1]));
    swept_pair_apart((a, sa, [&fa0, &fa1], ra), (b, sb, [&fb0, &fb1], rb), extra, axis)
}

/// Whether box `a` swept by `sa` (face terms `fa`, graded radii `ra`, `extra` already in its
/// sweeps) and box `b` are proved apart in some combination of forms: on the 15 axes and
/// `axis`, then on their graded axis ([`graded_points`], only for a pair the others leave
/// unproved). Not tried where the graded points show the graded balls meeting: every sweep
/// holds its box's graded ball, so then no axis separates the sweeps (the same answer,
/// without the test).
fn swept_pair_apart(
    (a, sa, fa, ra): (&Obb, [&Sweep; 2], [&FaceTerms; 2], [Real; 2]),
    (b, sb, fb, rb): (&Obb, [&Sweep; 2], [&FaceTerms; 2], [Real; 2]),
    extra: Real,
    axis: &Vec3,
) -> bool {
    if swept_boxes_apart_either(a, sa, fa, b, sb, fb, Axes::FifteenAnd(axis)) {
        return true;
    }
    let closest = graded_points((a, ra), (b, rb), extra);
    !closest.meet() && swept_boxes_apart_either(a, sa, fa, b, sb, fb, Axes::Only(&closest.axis()))
}

/// The closest points of box `a` swept by the graded ball of radii `ra` (plus `extra`) and box
/// `b` by that of `rb`, sought from `b`'s centre ([`graded_closest`]); the direction between
/// them is the axis the swept-box proofs try for the box pair besides the 15 and the robot
/// pair's (module doc of `protective`, step 5). Every sweep of a box holds its graded ball
/// (step 6), so the direction looks where the sweeps come nearest; a function of the boxes and
/// radii alone, so that the certain STOPs (steps 6 and 7) test the very axis the proof would.
pub(super) fn graded_points(
    (a, ra): (&Obb, [Real; 2]),
    (b, rb): (&Obb, [Real; 2]),
    extra: Real,
) -> GradedClosest {
    graded_closest(a, ra.map(|r| r + extra), b, rb, &b.center)
}

/// Both forms of a sweep with `extra` mm added to their balls: the forms themselves for 0
/// (`ball + 0` is `ball`: the tests of the speed limits ask this many times per tick), else
/// copies kept in `wider`.
fn with_extra<'a>(
    forms: [&'a Sweep; 2],
    extra: Real,
    wider: &'a mut Option<[Sweep; 2]>,
) -> [&'a Sweep; 2] {
    if extra == 0.0 {
        return forms;
    }
    let copies: &'a [Sweep; 2] = wider.insert(forms.map(|w| Sweep { ball: w.ball + extra, ..*w }));
    [&copies[0], &copies[1]]
}

/// Per box of a robot, the radii of the graded ball that every sweep of the box holds (module
/// doc of `protective`, step 6): what graded axis ([`graded_points`]) reads.
pub(super) type GradedRadii = [[Real; 2]; MAX_BOXES];

/// The first box pair `(i, k)` of two robots' swept boxes not proved apart with `extra` mm
/// added to the first robot's sweeps, any combination of sweep forms allowed, on the 15 axes
/// of each box pair, on `axis` or on the pair's graded axis ([`graded_points`]) (computed only for
/// the pairs that the others leave unproved).
pub(super) fn first_unproved_between(
    a: &SweptBall,
    b: &SweptBall,
    extra: Real,
    axis: &Vec3,
) -> Option<(usize, usize)> {
    let (boxes_a, sweeps_a, faces_a, radii_a) =
        (a.boxes.as_slice(), &a.sweeps, &a.faces, &a.graded);
    let (boxes_b, sweeps_b, faces_b, radii_b) =
        (b.boxes.as_slice(), &b.sweeps, &b.faces, &b.graded);
    let mut copy = None;
    if extra != 0.0 {
        let terms = copy.insert(*faces_a);
        for (form, terms) in terms.iter_mut().enumerate() {
            for (i, box_a) in boxes_a.iter().enumerate() {
                let sa = &sweeps_a[form][i];
                terms[i] = FaceTerms::new(box_a, &Sweep { ball: sa.ball + extra, ..*sa });
            }
        }
    }
    let widened = copy.as_ref().unwrap_or(faces_a);
    for (i, box_a) in boxes_a.iter().enumerate() {
        let mut wider = None;
        let sa = with_extra([&sweeps_a[0][i], &sweeps_a[1][i]], extra, &mut wider);
        for (k, box_b) in boxes_b.iter().enumerate() {
            let (fa, fb) = ([&widened[0][i], &widened[1][i]], [&faces_b[0][k], &faces_b[1][k]]);
            let sb = [&sweeps_b[0][k], &sweeps_b[1][k]];
            if !swept_pair_apart(
                (box_a, sa, fa, radii_a[i]),
                (box_b, sb, fb, radii_b[k]),
                extra,
                axis,
            ) {
                return Some((i, k));
            }
        }
    }
    None
}
