//! Properties of the separating axis test and the witness cache (thesis 3.1, SPEC §3):
//! symmetry in A and B, invariance under a common rigid motion, monotonicity in the safety
//! margin, and the cache answering as the plain test on any sequence of queries.
//!
//! Where two evaluations of the same geometry may round differently (swap, rigid motion),
//! they may disagree only inside a thin band around touching, measured by an independent
//! gap computed from the boxes' vertices.

use delta_collide::geometry::{
    first_intersecting_pair, obbs_intersect, separating_axis, Obb, WitnessCache,
};
use delta_collide::math::{Mat3, Real, Vec3};
use nalgebra::Rotation3;
use proptest::prelude::*;

/// Gaps (mm) inside `[-BAND_IN, BAND_OUT]` of touching are where rounding may flip a verdict.
const BAND_IN: Real = 1e-9;
const BAND_OUT: Real = 1e-5;

fn rotation() -> impl Strategy<Value = Mat3> {
    (-3.2..3.2, -1.6..1.6, -3.2..3.2)
        .prop_map(|(r, p, y): (Real, Real, Real)| *Rotation3::from_euler_angles(r, p, y).matrix())
}

fn half_extents() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        (0.5..1.5).prop_map(|s: Real| Vec3::new(200.0, 70.0, 17.5) * s),
        (1.0..300.0, 1.0..300.0, 1.0..300.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        (10.0..300.0, 10.0..300.0, 0.01..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
    ]
}

/// A box anywhere in a cell-sized region, any orientation, realistic or thin.
fn obb() -> impl Strategy<Value = Obb> {
    ((-400.0..400.0, -400.0..400.0, -400.0..400.0), rotation(), half_extents())
        .prop_map(|((x, y, z), axes, half)| Obb::new(Vec3::new(x, y, z), axes, half))
}

/// A rigid motion `p -> rot p + t`.
fn rigid_motion() -> impl Strategy<Value = (Mat3, Vec3)> {
    (rotation(), (-3000.0..3000.0, -3000.0..3000.0, -3000.0..3000.0))
        .prop_map(|(rot, (x, y, z))| (rot, Vec3::new(x, y, z)))
}

/// Two boxes, B placed along one of A's face normals or a random direction at a gap that is
/// zero, tiny, or up to a millimetre either way.
fn near_pair() -> impl Strategy<Value = (Obb, Obb)> {
    let gap = prop_oneof![Just(0.0), -1e-6..1e-6, -1.0..1.0];
    (obb(), rotation(), half_extents(), 0usize..4, gap, (-1.0..1.0, -1.0..1.0, -1.0..1.0)).prop_map(
        |(a, axes, half, dir, gap, (x, y, z))| {
            let v = Vec3::new(x, y, z);
            let n = if dir < 3 {
                a.axes.column(dir).into_owned()
            } else if v.norm() > 1e-3 {
                v.normalize()
            } else {
                Vec3::x()
            };
            let support =
                |b: &Obb| (0..3).map(|k| b.axes.column(k).dot(&n).abs() * b.half[k]).sum::<Real>();
            let b = Obb::new(Vec3::zeros(), axes, half);
            let center = a.center + n * (support(&a) + support(&b) + gap);
            (a, Obb { center, ..b })
        },
    )
}

fn pair() -> impl Strategy<Value = (Obb, Obb)> {
    prop_oneof![(obb(), obb()), near_pair()]
}

/// The largest gap between the boxes' projections over the 15 SAT axes (normalised; mm),
/// from the vertices: negative when no axis separates (the boxes overlap). Cross products
/// shorter than 1e-3 are skipped: the SAT's touch tolerance is not normalised and may widen
/// the band by up to `1e-9 / |L|` mm on such an axis.
fn vertex_gap(a: &Obb, b: &Obb) -> Real {
    let mut axes: Vec<Vec3> = (0..3).map(|k| a.axes.column(k).into_owned()).collect();
    axes.extend((0..3).map(|k| b.axes.column(k).into_owned()));
    for i in 0..3 {
        for j in 0..3 {
            let c = a.axes.column(i).cross(&b.axes.column(j));
            if c.norm() > 1e-3 {
                axes.push(c.normalize());
            }
        }
    }
    let (va, vb) = (a.vertices(), b.vertices());
    let range = |vs: &[Vec3; 8], l: &Vec3| {
        vs.iter()
            .map(|v| v.dot(l))
            .fold((Real::MAX, Real::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)))
    };
    axes.iter()
        .map(|l| {
            let ((la, ha), (lb, hb)) = (range(&va, l), range(&vb, l));
            (lb - ha).max(la - hb)
        })
        .fold(Real::MIN, Real::max)
}

/// Two verdicts on the same geometry may differ only near touching.
fn assert_same_or_near_touching(
    a: &Obb,
    b: &Obb,
    first: bool,
    second: bool,
    what: &str,
) -> Result<(), TestCaseError> {
    if first != second {
        let gap = vertex_gap(a, b);
        prop_assert!(
            (-BAND_IN..=BAND_OUT).contains(&gap),
            "{what}: verdicts differ at gap {gap:e} mm\n  a = {a:?}\n  b = {b:?}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn verdict_matches_the_vertex_gap_outside_the_band((a, b) in pair()) {
        let gap = vertex_gap(&a, &b);
        let collide = obbs_intersect(&a, &b);
        if gap < -BAND_IN {
            prop_assert!(collide, "overlapping boxes (gap {gap:e}) reported free\n  a = {a:?}\n  b = {b:?}");
        }
        if gap > BAND_OUT {
            prop_assert!(!collide, "boxes {gap:e} mm apart reported colliding\n  a = {a:?}\n  b = {b:?}");
        }
    }

    #[test]
    fn swapping_a_and_b_keeps_the_verdict((a, b) in pair()) {
        assert_same_or_near_touching(&a, &b, obbs_intersect(&a, &b), obbs_intersect(&b, &a), "swap")?;
    }

    #[test]
    fn a_common_rigid_motion_keeps_the_verdict((a, b) in pair(), (rot, t) in rigid_motion()) {
        let (ma, mb) = (a.transformed(&rot, &t), b.transformed(&rot, &t));
        assert_same_or_near_touching(&a, &b, obbs_intersect(&a, &b), obbs_intersect(&ma, &mb), "rigid motion")?;
    }

    #[test]
    fn growing_the_margin_never_frees_a_collision((a, b) in pair(), m1 in 0.0..5.0, dm in prop_oneof![Just(0.0), 0.0..1e-6, 0.0..5.0]) {
        let before = obbs_intersect(&a.inflated(m1), &b.inflated(m1));
        let after = obbs_intersect(&a.inflated(m1 + dm), &b.inflated(m1 + dm));
        prop_assert!(!before || after, "margin {m1} collides, margin {} is free\n  a = {a:?}\n  b = {b:?}", m1 + dm);
    }

    #[test]
    fn cached_test_answers_as_the_plain_one(
        queries in prop::collection::vec((prop::collection::vec(obb(), 0..5), prop::collection::vec(obb(), 0..5)), 1..40),
    ) {
        let mut cache = WitnessCache::new();
        for (a, b) in &queries {
            let plain = first_intersecting_pair(a, b);
            let cached = cache.first_intersecting_pair(a, b);
            prop_assert_eq!(plain.is_some(), cached.is_some());
            if let Some((i, j)) = cached {
                prop_assert!(separating_axis(&a[i], &b[j]).is_none());
            }
        }
    }

    /// The same, with slowly moving boxes so that both cache layers actually hit.
    #[test]
    fn cached_test_answers_as_the_plain_one_on_small_steps(
        a0 in prop::collection::vec(obb(), 1..4),
        b0 in prop::collection::vec(obb(), 1..4),
        steps in prop::collection::vec(((-2.0..2.0, -2.0..2.0, -2.0..2.0), rotation()), 1..60),
    ) {
        let mut cache = WitnessCache::new();
        let (mut a, mut b) = (a0, b0);
        for ((x, y, z), rot) in steps {
            // A small step: translate A's boxes, turn B's boxes by a hundredth of `rot`.
            let small = Rotation3::from_matrix_unchecked(rot).powf(0.01);
            for o in a.iter_mut() {
                o.center += Vec3::new(x, y, z);
            }
            for o in b.iter_mut() {
                o.axes = small.matrix() * o.axes;
            }
            let plain = first_intersecting_pair(&a, &b);
            prop_assert_eq!(plain.is_some(), cache.first_intersecting_pair(&a, &b).is_some());
        }
    }
}
