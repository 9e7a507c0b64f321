//! The box distance (`geometry::obb_distance`, used by `eval --plot`) against parry3d-f64 as the
//! oracle, and against the separating-axis lower bound that needs no oracle.
//!
//! Policy: our distance is exact up to rounding, so it is never above parry's by more than
//! `TOL` (parry's GJK may stall above the true distance on nearly parallel faces; those cases
//! are counted and must stay rare); it is never below the largest gap along the 15 candidate
//! axes (a lower bound on the true distance); it is 0 whenever parry finds an intersection, and
//! 0 for a pair parry calls separated only within `BAND` mm of touching (the separating axis
//! test errs toward collision there, and a zero distance follows it).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::geometry::{obb_distance, Obb};
use delta_collide::math::{Mat3, Real, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

const TOL: Real = 1e-6;
const BAND: Real = 1e-3;

fn random_box(rng: &mut StdRng, spread: Real) -> (Obb, [Real; 4]) {
    let q: [Real; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
    let n = q.iter().map(|v| v * v).sum::<Real>().sqrt().max(1e-9);
    let q = q.map(|v| v / n);
    let uq = UnitQuaternion::new_unchecked(Quaternion::new(q[3], q[0], q[1], q[2]));
    let half = match rng.random_range(0..3) {
        0 => Vec3::new(200.0, 70.0, 17.5),
        1 => Vec3::repeat(rng.random_range(1.0..100.0)),
        _ => Vec3::from_fn(|_, _| rng.random_range(0.5..200.0)),
    };
    let c = Vec3::from_fn(|_, _| rng.random_range(-spread..spread));
    (Obb::new(c, *uq.to_rotation_matrix().matrix(), half), q)
}

fn parry_distance(a: &Obb, qa: &[Real; 4], b: &Obb, qb: &[Real; 4]) -> (bool, Real) {
    let pose = |o: &Obb, q: &[Real; 4]| {
        Pose::from_parts(
            Vector::new(o.center.x, o.center.y, o.center.z),
            Rotation::from_xyzw(q[0], q[1], q[2], q[3]),
        )
    };
    let cuboid = |o: &Obb| Cuboid::new(Vector::new(o.half.x, o.half.y, o.half.z));
    let (pa, pb, sa, sb) = (pose(a, qa), pose(b, qb), cuboid(a), cuboid(b));
    let hit = query::intersection_test(&pa, &sa, &pb, &sb).unwrap().intersecting;
    (hit, query::distance(&pa, &sa, &pb, &sb).unwrap().distance)
}

/// The largest gap between the projections of the two boxes on the 15 candidate axes: a lower
/// bound on their distance.
fn axis_gap_lower_bound(a: &Obb, b: &Obb) -> Real {
    let cols =
        |m: &Mat3| [m.column(0).into_owned(), m.column(1).into_owned(), m.column(2).into_owned()];
    let (ua, ub) = (cols(&a.axes), cols(&b.axes));
    let mut axes: Vec<Vec3> = ua.iter().chain(ub.iter()).copied().collect();
    for u in &ua {
        for v in &ub {
            let c = u.cross(v);
            if c.norm() > 1e-6 {
                axes.push(c.normalize());
            }
        }
    }
    let radius =
        |u: &[Vec3; 3], h: &Vec3, l: &Vec3| (0..3).map(|k| h[k] * u[k].dot(l).abs()).sum::<Real>();
    let t = b.center - a.center;
    axes.iter()
        .map(|l| t.dot(l).abs() - radius(&ua, &a.half, l) - radius(&ub, &b.half, l))
        .fold(Real::MIN, Real::max)
}

#[test]
fn random_box_pairs_match_parry_and_the_axis_lower_bound() {
    let mut rng = StdRng::seed_from_u64(0x0bb_d157);
    let (mut free, mut hit, mut stalls) = (0, 0, 0);
    for i in 0..100_000 {
        let spread = if i % 2 == 0 { 150.0 } else { 400.0 };
        let ((a, qa), (b, qb)) = (random_box(&mut rng, spread), random_box(&mut rng, spread));
        let ours = obb_distance(&a, &b);
        let (parry_hit, parry) = parry_distance(&a, &qa, &b, &qb);
        let case = format!(
            "case {i}: a {a:?} qa {qa:?} b {b:?} qb {qb:?}: ours {ours:e}, parry {parry:e}"
        );
        if parry_hit {
            assert_eq!(ours, 0.0, "parry intersects, {case}");
            hit += 1;
            continue;
        }
        if ours == 0.0 {
            assert!(parry <= BAND, "ours touching, {case}");
            continue;
        }
        free += 1;
        assert!(ours <= parry + TOL * (1.0 + parry), "ours above parry, {case}");
        stalls += (parry > ours + TOL * (1.0 + parry)) as u32;
        let lower = axis_gap_lower_bound(&a, &b);
        assert!(ours >= lower - TOL * (1.0 + ours), "ours below the axis gap {lower:e}, {case}");
    }
    println!("{free} separated, {hit} intersecting, {stalls} where parry's GJK stayed above ours");
    assert!(free > 20_000 && hit > 20_000, "both outcomes are exercised");
    assert!(
        stalls * 1000 < free,
        "parry disagrees on {stalls} of {free}: more than GJK stalls explain"
    );
}

#[test]
fn robot_boxes_along_reach_in_cell_t2_match_parry() {
    // Real link boxes of two robots reaching toward each other: the distance the plot shows.
    let cell = reference_cell("T2").unwrap();
    let mut checker = ExactChecker::new(cell);
    let mut rng = StdRng::seed_from_u64(7);
    let mut checked = 0;
    while checked < 2_000 {
        let tcp = |rng: &mut StdRng, x0: Real| {
            Vec3::new(
                x0 + rng.random_range(-120.0..120.0),
                rng.random_range(-150.0..150.0),
                rng.random_range(-520.0..-380.0),
            )
        };
        let tcps = [tcp(&mut rng, 80.0), tcp(&mut rng, -80.0)];
        if !checker.check(&tcps).unwrap().all_reachable() {
            continue;
        }
        let collides = checker.verdict().collides();
        let (ba, bb) = (checker.boxes(0).as_slice(), checker.boxes(1).as_slice());
        let ours = ba
            .iter()
            .flat_map(|a| bb.iter().map(move |b| obb_distance(a, b)))
            .fold(Real::INFINITY, Real::min);
        let q = |o: &Obb| {
            let uq = UnitQuaternion::from_matrix(&o.axes);
            [uq.i, uq.j, uq.k, uq.w]
        };
        let parry = ba
            .iter()
            .flat_map(|a| bb.iter().map(move |b| parry_distance(a, &q(a), b, &q(b)).1))
            .fold(Real::INFINITY, Real::min);
        assert_eq!(
            ours == 0.0,
            collides,
            "zero distance exactly when the exact check collides: {tcps:?}"
        );
        assert!(
            (ours - parry).abs() <= 1e-4 * (1.0 + parry) || (collides && parry <= BAND),
            "{tcps:?}: ours {ours} parry {parry}"
        );
        checked += 1;
    }
}
