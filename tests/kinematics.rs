//! Delta3 kinematics and the box model against SPEC §2-§4: IK/FK round trips on random
//! reachable TCPs, the elbow-out branch against an independent atan2/acos oracle, the reported
//! unreachable cases, the unreachable share of the thesis workspace, and the thesis 2.5 chain
//! of transforms against the direct box form.

use delta_collide::math::{Real, Vec3};
use delta_collide::robot::delta3::{radial, tangent};
use delta_collide::robot::{Delta3, ModelOptions, RobotModel, ToolBox, Unreachable};
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::f64::consts::{PI, TAU};

/// SPEC §4 workspace of the thesis robot, depth `d = -z`.
const ZU: Real = 365.0;
const HCY: Real = 135.0;
const RCY: Real = 225.0;
const HCO: Real = 30.0;
const RCO: Real = 173.0;

/// Workspace radius at depth `d`, or `None` outside the depth range.
fn workspace_radius(d: Real) -> Option<Real> {
    if (ZU..=ZU + HCY).contains(&d) {
        Some(RCY)
    } else if (ZU + HCY..=ZU + HCY + HCO).contains(&d) {
        Some(RCY - (RCY - RCO) * (d - ZU - HCY) / HCO)
    } else {
        None
    }
}

/// A uniform random point of the SPEC §4 workspace (rejection from its bounding box).
fn workspace_point(rng: &mut StdRng) -> Vec3 {
    loop {
        let p = Vec3::new(
            rng.random_range(-RCY..=RCY),
            rng.random_range(-RCY..=RCY),
            -rng.random_range(ZU..=ZU + HCY + HCO),
        );
        if workspace_radius(-p.z).is_some_and(|r| p.x.hypot(p.y) <= r) {
            return p;
        }
    }
}

/// A uniform random point of a box well around the workspace (most of it unreachable).
fn wide_point(rng: &mut StdRng) -> Vec3 {
    Vec3::new(
        rng.random_range(-500.0..=500.0),
        rng.random_range(-500.0..=500.0),
        rng.random_range(-800.0..=0.0),
    )
}

/// `t` wrapped to (-pi, pi].
fn wrap(t: Real) -> Real {
    let w = (t + PI).rem_euclid(TAU) - PI;
    if w <= -PI {
        PI
    } else {
        w
    }
}

/// Absolute difference of two angles on the circle.
fn angle_gap(a: Real, b: Real) -> Real {
    wrap(a - b).abs()
}

/// The two SPEC §2 solutions of one arm, `-atan2(c, a) +/- acos(K / R)`, wrapped, or `None`.
fn oracle_solutions(d: &Delta3, arm: usize, tcp: &Vec3) -> Option<(Real, Real)> {
    let p = d.platform_joint(arm, tcp) - d.motor_point(arm);
    let (a, b, c) = (p.dot(&radial(arm)), p.dot(&tangent(arm)), p.z);
    let k = (a * a + c * c + d.rf * d.rf - (d.re * d.re - b * b)) / (2.0 * d.rf);
    let r = a.hypot(c);
    if b * b > d.re * d.re || k.abs() > r {
        return None;
    }
    let base = -c.atan2(a);
    let spread = (k / r).acos();
    Some((wrap(base + spread), wrap(base - spread)))
}

/// The SPEC's elbow-out angle of one arm by the oracle: the solution with the larger cosine.
fn oracle_elbow_out(d: &Delta3, arm: usize, tcp: &Vec3) -> Option<(Real, Real)> {
    let (t1, t2) = oracle_solutions(d, arm, tcp)?;
    Some(if t1.cos() >= t2.cos() { (t1, t2) } else { (t2, t1) })
}

/// Largest `| |G_i - E_i| - re |` over the three arms of an IK solution.
fn loop_error(d: &Delta3, tcp: &Vec3) -> Real {
    let sol = d.inverse_kinematics(tcp).unwrap();
    (0..3)
        .map(|arm| {
            ((d.elbow(arm, sol.cos[arm], sol.sin[arm]) - d.platform_joint(arm, tcp)).norm() - d.re)
                .abs()
        })
        .fold(0.0, Real::max)
}

/// `|det|` of the unit lower-link directions `(E_i - G_i) / re`: 0 at a parallel (type II)
/// singularity, where the spheres meet at a grazing angle and the FK is ill-conditioned.
fn link_determinant(d: &Delta3, tcp: &Vec3) -> Real {
    let sol = d.inverse_kinematics(tcp).unwrap();
    let n: [Vec3; 3] = std::array::from_fn(|i| {
        (d.platform_joint(i, tcp) - d.elbow(i, sol.cos[i], sol.sin[i])) / d.re
    });
    n[0].dot(&n[1].cross(&n[2])).abs()
}

#[test]
fn fk_of_ik_returns_the_tcp_on_100k_random_reachable_points() {
    let d = Delta3::THESIS;
    let mut rng = StdRng::seed_from_u64(0x5eed_0001);
    let (mut reachable, mut drawn, mut worst, mut worst_loop) =
        (0usize, 0usize, 0.0 as Real, 0.0 as Real);
    let (mut wide_reachable, mut wide_drawn, mut singular, mut worst_singular) =
        (0usize, 0usize, 0usize, 0.0 as Real);
    while reachable < 100_000 || wide_reachable < 50_000 {
        let from_workspace = reachable < 100_000;
        let p = if from_workspace { workspace_point(&mut rng) } else { wide_point(&mut rng) };
        if from_workspace {
            drawn += 1;
        } else {
            wide_drawn += 1;
        }
        let Ok(sol) = d.inverse_kinematics(&p) else { continue };
        if from_workspace {
            reachable += 1;
        } else {
            wide_reachable += 1;
        }
        let q = d.forward_kinematics(&sol.theta).expect("FK exists for an IK solution");
        let err = (p - q).norm();
        worst_loop = worst_loop.max(loop_error(&d, &p));
        let det = link_determinant(&d, &p);
        if det < 1e-3 {
            // Within 1e-3 of a parallel singularity (outside the workspace): the error grows as
            // 1e-13 / det, the bound is that law with a 100x allowance.
            assert!(!from_workspace, "workspace point {p:?} near a singularity (det {det:e})");
            assert!(err * det < 1e-11, "FK(IK({p:?})) = {q:?}, error {err:e} mm at det {det:e}");
            singular += 1;
            worst_singular = worst_singular.max(err);
            continue;
        }
        assert!(err < 1e-9, "FK(IK({p:?})) = {q:?}, error {err:e} mm (det {det:e})");
        worst = worst.max(err);
    }
    println!(
        "round trip: {reachable} reachable of {drawn} workspace draws, {wide_reachable} of {wide_drawn} wide-box \
         draws; worst |FK(IK(p)) - p| = {worst:e} mm; {singular} wide-box points within det < 1e-3 of a \
         parallel singularity, worst {worst_singular:e} mm; worst loop error {worst_loop:e} mm"
    );
    assert!(worst_loop < 1e-9, "a loop does not close: {worst_loop:e}");
    assert!(reachable + wide_reachable - singular >= 100_000);
}

#[test]
fn ik_picks_the_elbow_out_branch_of_the_spec_formula() {
    let d = Delta3::THESIS;
    let mut rng = StdRng::seed_from_u64(0x5eed_0002);
    let (mut checked, mut ties) = (0usize, 0usize);
    for i in 0..40_000 {
        let p = if i % 2 == 0 { workspace_point(&mut rng) } else { wide_point(&mut rng) };
        let Ok(sol) = d.inverse_kinematics(&p) else { continue };
        for arm in 0..3 {
            let (out, other) = oracle_elbow_out(&d, arm, &p).expect("oracle agrees the arm closes");
            if (out.cos() - other.cos()).abs() < 1e-9 {
                ties += 1; // cosines tie: either branch is "the larger".
                continue;
            }
            assert!(
                angle_gap(sol.theta[arm], out) < 1e-9,
                "arm {arm} of {p:?}: {} vs oracle {out}",
                sol.theta[arm]
            );
            assert!(sol.theta[arm] > -PI && sol.theta[arm] <= PI);
            assert!(sol.cos[arm] > other.cos());
            checked += 1;
        }
    }
    println!("elbow-out branch: {checked} arms checked against the oracle, {ties} ties skipped");
    assert!(checked > 50_000);
}

#[test]
fn ik_of_fk_returns_the_motor_angles() {
    let d = Delta3::THESIS;
    let mut rng = StdRng::seed_from_u64(0x5eed_0003);
    let (mut out_branch, mut in_branch, mut no_fk, mut other) = (0usize, 0usize, 0usize, 0usize);
    let mut worst: Real = 0.0;
    for _ in 0..100_000 {
        let theta: [Real; 3] = std::array::from_fn(|_| rng.random_range(d.theta_min..=d.theta_max));
        let Some(p) = d.forward_kinematics(&theta) else {
            no_fk += 1;
            continue;
        };
        // Is `theta` the elbow-out solution of every arm at p (by the oracle, away from ties)?
        let branches: Vec<_> = (0..3).map(|arm| oracle_elbow_out(&d, arm, &p)).collect();
        if p.z >= 0.0 || branches.iter().any(|b| b.is_none_or(|(o, i)| angle_gap(o, i) < 1e-3)) {
            other += 1;
            continue;
        }
        let is_out = (0..3).all(|arm| angle_gap(theta[arm], branches[arm].unwrap().0) < 1e-6);
        let sol = d.inverse_kinematics(&p);
        if is_out {
            let sol = sol.expect("elbow-out angles within limits: reachable");
            for arm in 0..3 {
                let gap = angle_gap(sol.theta[arm], theta[arm]);
                worst = worst.max(gap);
                assert!(gap < 1e-9, "IK(FK({theta:?})) = {:?}", sol.theta);
            }
            out_branch += 1;
        } else {
            // Some arm was elbow-in: IK answers the elbow-out branch (or its limit), same TCP.
            if let Ok(sol) = sol {
                let q = d.forward_kinematics(&sol.theta).unwrap();
                assert!((p - q).norm() < 1e-9);
                assert!((0..3).any(|arm| angle_gap(sol.theta[arm], theta[arm]) > 1e-6));
            }
            in_branch += 1;
        }
    }
    println!(
        "IK(FK(theta)): {out_branch} elbow-out (worst {worst:e} rad), {in_branch} with an elbow-in arm, \
         {no_fk} without FK, {other} near a branch tie or above the base"
    );
    assert!(out_branch > 10_000 && in_branch > 1_000);
}

#[test]
fn unreachable_points_are_reported_with_their_reason() {
    let d = Delta3::THESIS;
    let mut rng = StdRng::seed_from_u64(0x5eed_0004);
    for _ in 0..10_000 {
        // Beyond |p| > rf + re + |e - f| no arm can close: arm 0 fails first.
        let dir = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..-0.01),
        );
        let p = dir.normalize() * rng.random_range(611.0..5_000.0);
        assert_eq!(d.inverse_kinematics(&p), Err(Unreachable::OutOfReach { arm: 0 }), "{p:?}");
        // Above (or on) the base plane.
        let q = Vec3::new(
            rng.random_range(-300.0..300.0),
            rng.random_range(-300.0..300.0),
            rng.random_range(0.0..400.0),
        );
        assert_eq!(d.inverse_kinematics(&q), Err(Unreachable::AboveBase), "{q:?}");
    }
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for k in 0..3 {
            let mut p = Vec3::new(10.0, 20.0, -450.0);
            p[k] = bad;
            assert_eq!(d.inverse_kinematics(&p), Err(Unreachable::NonFinite));
            assert!(
                RobotModel::THESIS.boxes(&p).is_err()
                    && RobotModel::THESIS.boxes_chain(&p).is_err()
            );
        }
    }
    // One arm out of reach along its own radial line, the others fine: that arm is named.
    for arm in 0..3 {
        let p = radial(arm) * 330.0 + Vec3::new(0.0, 0.0, -450.0);
        let oracle: Vec<bool> = (0..3).map(|i| oracle_solutions(&d, i, &p).is_some()).collect();
        let first_bad = oracle.iter().position(|ok| !ok).expect("some arm out of reach");
        assert_eq!(d.inverse_kinematics(&p), Err(Unreachable::OutOfReach { arm: first_bad as u8 }));
    }
}

#[test]
fn tightened_motor_limits_are_reported() {
    let d = Delta3::THESIS;
    let tight = Delta3 { theta_min: 0.2, theta_max: 1.2, ..d };
    let mut rng = StdRng::seed_from_u64(0x5eed_0005);
    let (mut inside, mut outside) = (0usize, 0usize);
    for _ in 0..50_000 {
        let p = workspace_point(&mut rng);
        let Ok(sol) = d.inverse_kinematics(&p) else { continue };
        let first_bad = (0..3).find(|&arm| !(0.2..=1.2).contains(&sol.theta[arm]));
        match (first_bad, tight.inverse_kinematics(&p)) {
            (None, Ok(t)) => {
                assert_eq!(t.theta, sol.theta);
                inside += 1;
            }
            (Some(arm), Err(Unreachable::MotorLimit { arm: a, theta })) => {
                assert_eq!(a as usize, arm, "{p:?}");
                assert!((theta - sol.theta[arm]).abs() < 1e-12);
                outside += 1;
            }
            (expected, got) => panic!("{p:?}: expected first bad arm {expected:?}, got {got:?}"),
        }
    }
    println!("tightened limits [0.2, 1.2]: {inside} inside, {outside} reported as MotorLimit");
    assert!(inside > 1_000 && outside > 1_000);
}

#[test]
fn about_twelve_percent_of_the_workspace_is_unreachable() {
    // SPEC §4 says ~12 % and motor angles within about [-0.23, 2.06]. A dense grid (run while
    // writing this test) finds the geometric band [-0.2355, 2.112] rad: next to the reach
    // boundary, on a sliver of about 1e-6 of the volume, the default 2 pi / 3 limit binds.
    let d = Delta3::THESIS;
    let mut rng = StdRng::seed_from_u64(0x5eed_0006);
    let n = 200_000;
    let (mut out_of_reach, mut motor_limit) = (0usize, 0usize);
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    for _ in 0..n {
        let p = workspace_point(&mut rng);
        match d.inverse_kinematics(&p) {
            Ok(sol) => {
                for t in sol.theta {
                    lo = lo.min(t);
                    hi = hi.max(t);
                }
            }
            Err(Unreachable::OutOfReach { .. }) => out_of_reach += 1,
            Err(Unreachable::MotorLimit { .. }) => motor_limit += 1,
            Err(e) => panic!("{p:?}: a workspace point cannot fail with {e}"),
        }
    }
    let share = (out_of_reach + motor_limit) as Real / n as Real;
    println!(
        "workspace: {:.2} % unreachable ({out_of_reach} out of reach, {motor_limit} beyond a motor limit, of {n}); \
         motor angles in [{lo:.4}, {hi:.4}] rad",
        100.0 * share
    );
    assert!((0.08..=0.16).contains(&share), "unreachable share {share}");
    assert!((motor_limit as Real) < 1e-3 * n as Real, "motor limits bind on {motor_limit} points");
    assert!((-0.26..=-0.2).contains(&lo), "lowest motor angle {lo}");
    assert!((2.0..=2.0 * PI / 3.0).contains(&hi), "highest motor angle {hi}");
}

fn full_options(margin: Real) -> ModelOptions {
    ModelOptions {
        margin,
        upper_links: Some((25.0, 20.0)),
        platform: Some(ToolBox {
            offset: Vec3::new(0.0, 0.0, 15.0),
            half: Vec3::new(70.0, 70.0, 15.0),
        }),
        tool: Some(ToolBox {
            offset: Vec3::new(5.0, -5.0, -60.0),
            half: Vec3::new(30.0, 30.0, 60.0),
        }),
        ..ModelOptions::THESIS
    }
}

#[test]
fn chain_and_direct_models_give_the_same_boxes() {
    let mut rng = StdRng::seed_from_u64(0x5eed_0007);
    let models = [
        RobotModel::THESIS,
        RobotModel {
            delta: Delta3::THESIS,
            options: ModelOptions { margin: 8.28, ..ModelOptions::THESIS },
        },
        RobotModel { delta: Delta3::THESIS, options: full_options(0.0) },
        RobotModel { delta: Delta3::THESIS, options: full_options(11.0) },
    ];
    let mut compared = 0usize;
    for i in 0..8_000 {
        let p = if i % 4 == 0 { wide_point(&mut rng) } else { workspace_point(&mut rng) };
        for model in &models {
            let (direct, chain) = (model.boxes(&p), model.boxes_chain(&p));
            let (Ok(direct), Ok(chain)) = (direct, chain) else {
                assert_eq!(direct.err(), chain.err());
                continue;
            };
            assert_eq!(direct.len, model.box_count());
            assert_eq!(chain.len, direct.len);
            for (k, (a, b)) in direct.as_slice().iter().zip(chain.as_slice()).enumerate() {
                let gaps = [
                    (a.center - b.center).norm(),
                    (a.axes - b.axes).norm(),
                    (a.half - b.half).norm(),
                ];
                assert!(
                    gaps.iter().all(|g| *g < 1e-9),
                    "box {k} of {p:?} ({:?}): {gaps:?}",
                    model.box_kind(k)
                );
                assert!(
                    (a.axes.transpose() * a.axes - delta_collide::math::Mat3::identity()).norm()
                        < 1e-12
                );
                assert!(a.axes.determinant() > 0.0, "right-handed axes");
            }
            compared += 1;
        }
    }
    println!("chain vs direct: {compared} reachable (TCP, model) pairs agree");
    assert!(compared > 20_000);
}

proptest! {
    // About a third of this box lies outside the reachable workspace (a CI run: 1,024
    // rejects for 1,906 accepted, 35 %), so 2,000 accepted cases take about 1,000 rejects on
    // average, as many as proptest's default cap of 1,024: the test failed on some seeds. The
    // cap is raised to 10 rejects per accepted case: a box that drifted out of reach would
    // still fail here rather than pass on a few points.
    #![proptest_config(ProptestConfig {
        cases: 2_000,
        max_global_rejects: 20_000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn ik_fk_round_trip(x in -260.0..260.0f64, y in -260.0..260.0f64, z in -560.0..-300.0f64) {
        let d = Delta3::THESIS;
        let p = Vec3::new(x, y, z);
        let sol = d.inverse_kinematics(&p);
        prop_assume!(sol.is_ok());
        let sol = sol.unwrap();
        let q = d.forward_kinematics(&sol.theta).unwrap();
        prop_assert!((p - q).norm() < 1e-9, "FK(IK({:?})) = {:?}", p, q);
        for arm in 0..3 {
            prop_assert!((sol.theta[arm].cos() - sol.cos[arm]).abs() < 1e-14);
            prop_assert!(sol.theta[arm] >= d.theta_min && sol.theta[arm] <= d.theta_max);
        }
    }
}

// Found by a dense grid over the workspace: inside it (r = 218.2 <= 225 at depth 474.4), yet an
// arm would need more than the default 2 pi / 3, so the SPEC §4 remark "limits never bind" is
// not quite true. It must be reported as a motor limit, not as out of reach.
#[test]
fn workspace_point_beyond_the_default_motor_limit() {
    let p = Vec3::new(120.46024704435666, -181.9955806661595, -474.4);
    assert!(workspace_radius(-p.z).is_some_and(|r| p.x.hypot(p.y) <= r));
    match Delta3::THESIS.inverse_kinematics(&p) {
        Err(Unreachable::MotorLimit { theta, .. }) => {
            assert!(theta > 2.0 * PI / 3.0 && theta < 2.12, "{theta}")
        }
        other => panic!("expected a motor limit, got {other:?}"),
    }
    let free = Delta3 { theta_max: 2.2, ..Delta3::THESIS };
    let sol = free.inverse_kinematics(&p).unwrap();
    assert!((free.forward_kinematics(&sol.theta).unwrap() - p).norm() < 1e-9);
}
