//! Signed clearance (`geometry::obb_clearance`, `boxes_clearance`) and its lower bound against
//! an oracle written here from scratch, on random box pairs of many kinds and on random
//! configurations of two thesis robots in cell T1, also tick by tick along runs
//! (`CoherentClearance`); parry3d-f64's distance compared on a sample.
//!
//! Oracle: apart when some of the 15 axes (each normalised, skipping only degenerate cross
//! products) shows a positive gap between the projections of the 8 vertices of each box; then
//! the smallest of the 16 vertex-to-box and 144 edge-to-edge distances (segment distance as the
//! smallest of the four endpoint-to-segment distances and, when inside both segments, the
//! common perpendicular). Otherwise minus the smallest projection overlap over the 15 axes
//! (cross products shorter than `CROSS_AXIS_MIN_NORM` left out). Agreement: `TOL` mm.

// `!(x >= y)` is deliberate: it is true when either side is NaN, which sends NaN to the
// "check it" or "colliding" side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use delta_collide::geometry::{
    boxes_clearance, boxes_clearance_lower_bound, obb_clearance, obb_clearance_lower_bound,
    separating_axis, CoherentClearance, Obb,
};
use delta_collide::math::{Mat3, Real, Vec3, CROSS_AXIS_MIN_NORM};
use delta_collide::robot::RobotModel;
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

const TOL: Real = 1e-6;

// ---------------------------------------------------------------------------------------------
// The oracle.

fn corners(o: &Obb) -> [Vec3; 8] {
    let u = [
        o.axes.column(0).into_owned(),
        o.axes.column(1).into_owned(),
        o.axes.column(2).into_owned(),
    ];
    std::array::from_fn(|v| {
        let s = |k: usize| if v & (1 << k) != 0 { o.half[k] } else { -o.half[k] };
        o.center + u[0] * s(0) + u[1] * s(1) + u[2] * s(2)
    })
}

/// The 12 edges of a box as vertex index pairs (indices differ in one bit).
fn edges() -> impl Iterator<Item = (usize, usize)> {
    (0..8).flat_map(|v| (0..3).filter(move |k| v & (1 << k) == 0).map(move |k| (v, v | (1 << k))))
}

/// The closest point of box `o` to `p`.
fn closest_in_box(o: &Obb, p: &Vec3) -> Vec3 {
    let d = p - o.center;
    let mut q = o.center;
    for k in 0..3 {
        let u = o.axes.column(k).into_owned();
        q += u * d.dot(&u).clamp(-o.half[k], o.half[k]);
    }
    q
}

fn closest_on_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> Vec3 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    a + ab * t
}

/// The closest pair of points of segments `p0 p1` and `q0 q1`.
fn segments_closest(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> (Real, Vec3, Vec3) {
    let mut best = (Real::INFINITY, *p0, *q0);
    let mut keep = |p: Vec3, q: Vec3| {
        let d = (p - q).norm();
        if d < best.0 {
            best = (d, p, q);
        }
    };
    keep(*p0, closest_on_segment(p0, q0, q1));
    keep(*p1, closest_on_segment(p1, q0, q1));
    keep(closest_on_segment(q0, p0, p1), *q0);
    keep(closest_on_segment(q1, p0, p1), *q1);
    let (u, v) = (p1 - p0, q1 - q0);
    let n = u.cross(&v);
    let n2 = n.norm_squared();
    if n2 > 1e-18 * u.norm_squared() * v.norm_squared() {
        let w = q0 - p0;
        let (s, t) = (w.cross(&v).dot(&n) / n2, w.cross(&u).dot(&n) / n2);
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
            keep(p0 + u * s, q0 + v * t);
        }
    }
    best
}

/// The 15 candidate axes, normalised, with the length of the raw cross product (1 for faces).
fn axes15(a: &Obb, b: &Obb) -> [(Vec3, Real); 15] {
    let u = |o: &Obb, k: usize| o.axes.column(k).into_owned();
    std::array::from_fn(|k| match k {
        0..=2 => (u(a, k), 1.0),
        3..=5 => (u(b, k - 3), 1.0),
        _ => {
            let c = u(a, (k - 6) / 3).cross(&u(b, (k - 6) % 3));
            let n = c.norm();
            (if n > 0.0 { c / n } else { c }, n)
        }
    })
}

fn interval(v: &[Vec3; 8], n: &Vec3) -> (Real, Real) {
    v.iter()
        .map(|p| p.dot(n))
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
}

#[derive(Debug, Clone, Copy)]
struct Truth {
    distance: Real,
    /// Apart: the closest points. Penetrating: unused.
    p: Vec3,
    q: Vec3,
}

/// The 12 edges of a box: end points, midpoint and half-length.
fn edge_list(v: &[Vec3; 8]) -> [(Vec3, Vec3, Vec3, Real); 12] {
    let mut out = [(Vec3::zeros(), Vec3::zeros(), Vec3::zeros(), 0.0); 12];
    for (e, (i, j)) in out.iter_mut().zip(edges()) {
        *e = (v[i], v[j], (v[i] + v[j]) * 0.5, (v[j] - v[i]).norm() * 0.5);
    }
    out
}

fn oracle(a: &Obb, b: &Obb) -> Truth {
    let (va, vb) = (corners(a), corners(b));
    let (mut gap, mut overlap) = (Real::NEG_INFINITY, Real::INFINITY);
    for (n, len) in axes15(a, b) {
        if len <= 1e-12 {
            continue;
        }
        let ((a0, a1), (b0, b1)) = (interval(&va, &n), interval(&vb, &n));
        gap = gap.max((b0 - a1).max(a0 - b1));
        if len >= CROSS_AXIS_MIN_NORM {
            overlap = overlap.min((a1 - b0).min(b1 - a0));
        }
    }
    if gap <= 0.0 {
        return Truth { distance: -overlap, p: a.center, q: b.center };
    }
    let mut best = (Real::INFINITY, a.center, b.center);
    for v in &vb {
        let p = closest_in_box(a, v);
        let d = (v - p).norm();
        if d < best.0 {
            best = (d, p, *v);
        }
    }
    for v in &va {
        let q = closest_in_box(b, v);
        let d = (v - q).norm();
        if d < best.0 {
            best = (d, *v, q);
        }
    }
    let (ea, eb) = (edge_list(&va), edge_list(&vb));
    for (p0, p1, mp, hp) in &ea {
        for (q0, q1, mq, hq) in &eb {
            // Every point of a segment is within half its length of its midpoint: pairs
            // whose midpoints are too far apart cannot be closer than the best so far.
            let reach = best.0 + hp + hq;
            if (mp - mq).norm_squared() > reach * reach {
                continue;
            }
            let c = segments_closest(p0, p1, q0, q1);
            if c.0 < best.0 {
                best = c;
            }
        }
    }
    Truth { distance: best.0, p: best.1, q: best.2 }
}

fn dist_to_box(o: &Obb, p: &Vec3) -> Real {
    (p - closest_in_box(o, p)).norm()
}

// ---------------------------------------------------------------------------------------------
// Random boxes of many kinds.

fn random_rotation(rng: &mut StdRng) -> Mat3 {
    loop {
        let q: [Real; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n2: Real = q.iter().map(|v| v * v).sum();
        if n2 > 1e-4 && n2 <= 1.0 {
            let uq =
                UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
            return *uq.to_rotation_matrix().matrix();
        }
    }
}

fn random_unit(rng: &mut StdRng) -> Vec3 {
    loop {
        let v = Vec3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A rotation by a multiple of 90 degrees (axes permuted, signs flipped, determinant +1).
fn right_angle_rotation(rng: &mut StdRng) -> Mat3 {
    let perm =
        [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]][rng.random_range(0..6)];
    let mut m = Mat3::zeros();
    for (c, &r) in perm.iter().enumerate() {
        m[(r, c)] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    }
    if m.determinant() < 0.0 {
        m.column_mut(2).neg_mut();
    }
    m
}

fn random_half(rng: &mut StdRng) -> Vec3 {
    let scale = 10f64.powf(rng.random_range(-1.0..2.5));
    match rng.random_range(0..4) {
        0 => Vec3::new(200.0, 70.0, 17.5),
        1 => Vec3::repeat(scale),
        2 => Vec3::from_fn(|_, _| rng.random_range(0.05..1.0) * scale),
        _ => Vec3::new(
            scale,
            rng.random_range(0.01..0.3) * scale,
            rng.random_range(0.01..0.3) * scale,
        ),
    }
}

/// Half-width of box `o` along unit `n`.
fn support(o: &Obb, n: &Vec3) -> Real {
    (0..3).map(|k| o.half[k] * o.axes.column(k).dot(n).abs()).sum()
}

fn signed_gap(rng: &mut StdRng) -> Real {
    let g = 10f64.powf(rng.random_range(-9.0..1.0));
    match rng.random_range(0..4) {
        0 => -g,
        1 => 0.0,
        _ => g,
    }
}

/// Two boxes of one of seven kinds (`kind` in 0..7).
fn random_pair(rng: &mut StdRng, kind: usize) -> (Obb, Obb) {
    let ra = random_rotation(rng);
    let a = Obb::new(Vec3::from_fn(|_, _| rng.random_range(-500.0..500.0)), ra, random_half(rng));
    let b = match kind {
        // Uniform: random poses within a spread of the boxes' size.
        0 => {
            let hb = random_half(rng);
            let spread = (a.half.norm() + hb.norm()) * rng.random_range(0.3..1.5);
            Obb::new(a.center + random_unit(rng) * spread, random_rotation(rng), hb)
        }
        // Near-touching along a random direction: the gap along it is small or negative.
        1 => {
            let b0 = Obb::new(Vec3::zeros(), random_rotation(rng), random_half(rng));
            let n = random_unit(rng);
            let c = a.center + n * (support(&a, &n) + support(&b0, &n) + signed_gap(rng));
            Obb { center: c, ..b0 }
        }
        // Parallel faces, turned about the common normal or not, offset sideways.
        2 => {
            let k = rng.random_range(0..3);
            let mut rb = ra * right_angle_rotation(rng);
            if rng.random_bool(0.5) {
                let axis = Unit::new_normalize(ra.column(k).into_owned());
                rb = Rotation3::from_axis_angle(&axis, rng.random_range(-3.2..3.2)).matrix() * rb;
            }
            let b0 = Obb::new(Vec3::zeros(), rb, random_half(rng));
            let n = ra.column(k).into_owned() * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let side: Vec3 = (0..3)
                .filter(|&m| m != k)
                .map(|m| ra.column(m) * rng.random_range(-1.0..1.0) * (a.half[m] + b0.half.max()))
                .sum();
            Obb {
                center: a.center + n * (a.half[k] + support(&b0, &n) + signed_gap(rng)) + side,
                ..b0
            }
        }
        // Edge on edge: see `edge_on_edge`.
        3 => {
            let g = signed_gap(rng);
            edge_on_edge(rng, &a, g).0
        }
        // One inside the other.
        4 => {
            let hb = a.half.map(|h| h * rng.random_range(0.05..0.5));
            let off = Vec3::from_fn(|m, _| rng.random_range(-0.5..0.5) * a.half[m]);
            Obb::new(a.center + ra * off, random_rotation(rng), hb)
        }
        // Round numbers: axis-aligned (up to right angles), integer centres and half-extents.
        5 => {
            let round = |rng: &mut StdRng| {
                Obb::new(
                    Vec3::from_fn(|_, _| rng.random_range(-6..=6) as Real),
                    right_angle_rotation(rng),
                    Vec3::from_fn(|_, _| rng.random_range(1..=4) as Real),
                )
            };
            return (round(rng), round(rng));
        }
        // Nearly parallel, near-touching along a face normal of A.
        _ => {
            let axis = Unit::new_normalize(random_unit(rng));
            let tilt = Rotation3::from_axis_angle(&axis, 10f64.powf(rng.random_range(-10.0..-2.0)));
            let b0 = Obb::new(
                Vec3::zeros(),
                tilt.matrix() * ra * right_angle_rotation(rng),
                random_half(rng),
            );
            let k = rng.random_range(0..3);
            let n = ra.column(k).into_owned();
            let side = ra.column((k + 1) % 3) * rng.random_range(-1.0..1.0) * a.half[(k + 1) % 3];
            Obb {
                center: a.center + n * (a.half[k] + support(&b0, &n) + signed_gap(rng)) + side,
                ..b0
            }
        }
    };
    (a, b)
}

/// A box B whose edge crosses the edge of A along `A_0` at `(+a_1, +a_2)`, at distance `g`
/// along a direction `n` normal to both edges: when `g > 0` the clearance is exactly `g`.
fn edge_on_edge(rng: &mut StdRng, a: &Obb, g: Real) -> (Obb, Real) {
    let u = |k: usize| a.axes.column(k).into_owned();
    let phi: Real = rng.random_range(0.05..1.52);
    let n = u(1) * phi.cos() + u(2) * phi.sin();
    // B_0 normal to n, not parallel to A_0; B_1, B_2 turned about B_0 so that both lean on n.
    let e = n.cross(&u(0)).normalize();
    let psi: Real = rng.random_range(0.1..3.04);
    let b0 = (u(0) * psi.cos() + e * psi.sin()).normalize();
    let w = b0.cross(&n);
    let chi: Real = rng.random_range(0.05..1.52);
    let b1 = n * chi.cos() + w * chi.sin();
    let b2 = b0.cross(&b1);
    let hb = random_half(rng);
    let p = a.center
        + u(0) * rng.random_range(-0.9..0.9) * a.half[0]
        + u(1) * a.half[1]
        + u(2) * a.half[2];
    // B's supporting edge in -n passes through p + g n.
    let s = |v: &Vec3| if v.dot(&n) > 0.0 { 1.0 } else { -1.0 };
    let c = p
        + n * g
        + b1 * (s(&b1) * hb[1])
        + b2 * (s(&b2) * hb[2])
        + b0 * rng.random_range(-0.9..0.9) * hb[0];
    (Obb::new(c, Mat3::from_columns(&[b0, b1, b2]), hb), g)
}

// ---------------------------------------------------------------------------------------------
// Checks.

/// Ours against the oracle for one pair; witness points checked too. `Err` describes a failure.
fn check_pair(a: &Obb, b: &Obb) -> Result<(Real, Truth), String> {
    let ours = obb_clearance(a, b);
    let truth = oracle(a, b);
    let lb = obb_clearance_lower_bound(a, b);
    let case = || format!("a = {a:?}; b = {b:?}; ours {ours:?}, oracle {truth:?}, bound {lb:e}");
    let d = ours.distance;
    if !((d - truth.distance).abs() <= TOL) {
        return Err(format!("distance differs: {}", case()));
    }
    if !(lb <= d) {
        return Err(format!("bound above clearance: {}", case()));
    }
    if (d > 0.0) != separating_axis(a, b).is_some() {
        return Err(format!("sign differs from the SAT: {}", case()));
    }
    if !(dist_to_box(a, &ours.point_a) <= TOL
        && ((ours.point_b - ours.point_a).norm() - d.abs()).abs() <= TOL)
    {
        return Err(format!("witness: {}", case()));
    }
    if d > 0.0 && !(dist_to_box(b, &ours.point_b) <= TOL) {
        return Err(format!("witness b: {}", case()));
    }
    Ok((d, truth))
}

#[test]
fn random_box_pairs_of_seven_kinds_match_the_oracle() {
    const N: usize = 1_050_000;
    let mut rng = StdRng::seed_from_u64(0xc1ea_0001);
    let (mut apart, mut inside, mut touching) = ([0usize; 7], [0usize; 7], 0);
    for i in 0..N {
        let kind = i % 7;
        let (a, b) = random_pair(&mut rng, kind);
        let (d, _) = check_pair(&a, &b).unwrap_or_else(|e| panic!("pair {i}, kind {kind}: {e}"));
        // Swapping the boxes gives the same clearance.
        let swapped = obb_clearance(&b, &a).distance;
        assert!((swapped - d).abs() <= TOL, "pair {i}: swapped {swapped} vs {d}");
        if d > 0.0 {
            apart[kind] += 1;
        } else {
            inside[kind] += 1;
        }
        touching += (d == 0.0) as usize;
    }
    println!("apart by kind {apart:?}, intersecting by kind {inside:?}, exactly 0: {touching}");
    assert!(inside.iter().all(|&n| n > 500), "every kind has intersecting pairs");
    assert!(
        apart.iter().enumerate().all(|(k, &n)| k == 4 || n > 50_000),
        "every kind but 'inside' has apart pairs"
    );
}

#[test]
fn crossing_edges_are_at_exactly_their_constructed_gap() {
    let mut rng = StdRng::seed_from_u64(0xc1ea_0002);
    for i in 0..100_000 {
        let (a, _) = random_pair(&mut rng, 0);
        let g = 10f64.powf(rng.random_range(-6.0..2.0));
        let (b, g) = edge_on_edge(&mut rng, &a, g);
        let c = obb_clearance(&a, &b);
        assert!(
            (c.distance - g).abs() <= 1e-9 * (1.0 + g),
            "case {i}: {c:?} vs {g}; a = {a:?}; b = {b:?}"
        );
    }
}

#[test]
fn nan_never_gives_a_positive_clearance() {
    let a = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::repeat(1.0));
    let b = Obb::new(Vec3::new(5.0, 0.0, 0.0), Mat3::identity(), Vec3::repeat(1.0));
    for field in 0..15 {
        let mut x = b;
        match field {
            0..=2 => x.center[field] = Real::NAN,
            3..=11 => x.axes[field - 3] = Real::NAN,
            _ => x.half[field - 12] = Real::NAN,
        }
        for (p, q) in [(a, x), (x, a)] {
            assert!(!(obb_clearance(&p, &q).distance > 0.0), "field {field}");
            assert!(!(obb_clearance_lower_bound(&p, &q) > 0.0), "field {field}");
            assert!(!(boxes_clearance(&[a, p], &[q, a]).distance > 0.0), "field {field}");
            assert!(!(boxes_clearance_lower_bound(&[p], &[q]) > 0.0), "field {field}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Two robots in cell T1.

/// A TCP uniformly in the thesis workspace of SPEC §4 (cylinder, then frustum).
fn random_tcp(rng: &mut StdRng) -> Vec3 {
    loop {
        let (x, y) = (rng.random_range(-225.0..225.0), rng.random_range(-225.0..225.0));
        let depth = rng.random_range(365.0..530.0);
        let radius =
            if depth <= 500.0 { 225.0 } else { 225.0 - (depth - 500.0) / 30.0 * (225.0 - 173.0) };
        if Real::hypot(x, y) <= radius {
            return Vec3::new(x, y, -depth);
        }
    }
}

#[test]
fn random_configurations_of_cell_t1_match_the_oracle() {
    const N: usize = 1_000_000;
    let model = RobotModel::THESIS;
    let shift = Vec3::new(450.0, 0.0, 0.0);
    let mut rng = StdRng::seed_from_u64(0xc1ea_0003);
    let (mut done, mut colliding, mut pairs_checked) = (0, 0, 0);
    while done < N {
        let (Ok(ra), Ok(rb)) =
            (model.boxes(&random_tcp(&mut rng)), model.boxes(&random_tcp(&mut rng)))
        else {
            continue;
        };
        let a = ra.as_slice();
        let b: Vec<Obb> =
            rb.as_slice().iter().map(|o| o.transformed(&Mat3::identity(), &shift)).collect();
        let ours = boxes_clearance(a, &b);
        let (truth, checked) = oracle_over_pairs(a, &b);
        pairs_checked += checked;
        let case = || format!("config {done}: a = {a:?}; b = {b:?}; ours {ours:?}, oracle {truth}");
        assert!((ours.distance - truth).abs() <= TOL, "{}", case());
        let pair = obb_clearance(&a[ours.box_a], &b[ours.box_b]);
        assert_eq!(pair.distance, ours.distance, "{}", case());
        let lb = boxes_clearance_lower_bound(a, &b);
        assert!(lb <= ours.distance, "bound {lb}: {}", case());
        colliding += (ours.distance <= 0.0) as usize;
        done += 1;
    }
    println!(
        "{N} configurations, {colliding} colliding, {pairs_checked} pairs through the full oracle"
    );
    assert!(colliding > 10_000 && colliding < N / 2);
}

/// The oracle's clearance of two robots: the minimum over their box pairs, the full feature
/// search only where the oracle's own bounds do not already rule a pair out; and how many
/// pairs took the full search.
fn oracle_over_pairs(a: &[Obb], b: &[Obb]) -> (Real, usize) {
    let (mut truth, mut checked) = (Real::INFINITY, 0);
    let mut order: Vec<(Real, usize, usize)> = Vec::with_capacity(a.len() * b.len());
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            // Bounding spheres: a lower bound on the distance.
            order.push(((x.center - y.center).norm() - x.half.norm() - y.half.norm(), i, j));
        }
    }
    order.sort_by(|p, q| p.0.total_cmp(&q.0));
    for &(sphere_gap, i, j) in &order {
        if sphere_gap >= truth {
            break;
        }
        if axis_gap_only(&a[i], &b[j]) >= truth {
            continue;
        }
        truth = truth.min(oracle(&a[i], &b[j]).distance);
        checked += 1;
    }
    (truth, checked)
}

/// `CoherentClearance` along runs of cell T1 at 1 ms ticks, where it starts from the last
/// tick's features: each TCP moves at up to 4.5 m/s and turns at up to 130 m/s^2 (the
/// stiff stopping model's limits), bouncing off the workspace, through near, touching and
/// colliding configurations.
#[test]
fn runs_of_cell_t1_tick_by_tick_match_the_oracle() {
    const RUNS: usize = 300;
    const TICKS: usize = 2_000;
    let model = RobotModel::THESIS;
    let shift = Vec3::new(450.0, 0.0, 0.0);
    let mut rng = StdRng::seed_from_u64(0xc1ea_0004);
    let (mut ticks, mut close) = (0, 0);
    for _ in 0..RUNS {
        let mut memory = CoherentClearance::new();
        let mut tcp = [random_tcp(&mut rng), random_tcp(&mut rng)];
        let mut vel = [random_unit(&mut rng) * 2.0, random_unit(&mut rng) * 2.0];
        for _ in 0..TICKS {
            for j in 0..2 {
                // mm per tick; 0.13 mm per tick^2 is 130 m/s^2.
                let v = vel[j] + random_unit(&mut rng) * 0.13 * rng.random::<Real>();
                vel[j] = v * (4.5 / v.norm()).min(1.0);
                let next = tcp[j] + vel[j];
                if model.boxes(&next).is_ok() {
                    tcp[j] = next;
                } else {
                    vel[j] = -vel[j];
                }
            }
            let (Ok(ra), Ok(rb)) = (model.boxes(&tcp[0]), model.boxes(&tcp[1])) else { continue };
            let a = ra.as_slice();
            let b: Vec<Obb> =
                rb.as_slice().iter().map(|o| o.transformed(&Mat3::identity(), &shift)).collect();
            let ours = memory.boxes_clearance(a, &b);
            let (truth, _) = oracle_over_pairs(a, &b);
            assert!(
                (ours.distance - truth).abs() <= TOL,
                "tick {ticks}: a = {a:?}; b = {b:?}; ours {ours:?}, oracle {truth}"
            );
            let pair = obb_clearance(&a[ours.box_a], &b[ours.box_b]).distance;
            assert!(
                (pair - ours.distance).abs() <= TOL,
                "tick {ticks}: the pair named gives {pair}, {ours:?}"
            );
            close += usize::from(ours.distance < 20.0);
            ticks += 1;
        }
    }
    println!("{ticks} ticks in {RUNS} runs, {close} with clearance under 20 mm");
    assert!(close > ticks / 20, "too few close ticks to test: {close} of {ticks}");
}

/// The oracle's largest projection gap over the 15 axes (a lower bound on the clearance).
fn axis_gap_only(a: &Obb, b: &Obb) -> Real {
    let (va, vb) = (corners(a), corners(b));
    let mut gap = Real::NEG_INFINITY;
    for (n, len) in axes15(a, b) {
        if len >= CROSS_AXIS_MIN_NORM {
            let ((a0, a1), (b0, b1)) = (interval(&va, &n), interval(&vb, &n));
            gap = gap.max((b0 - a1).max(a0 - b1));
        }
    }
    gap
}

// ---------------------------------------------------------------------------------------------
// parry3d-f64.

fn parry_parts(o: &Obb) -> (Pose, Cuboid) {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(o.axes));
    let pose = Pose::from_parts(
        Vector::new(o.center.x, o.center.y, o.center.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    );
    (pose, Cuboid::new(Vector::new(o.half.x, o.half.y, o.half.z)))
}

/// Where parry's distance and the oracle's differ by more than `TOL` on separated pairs, the
/// oracle's value is the right one: its closest points lie on the two boxes (checked here) and
/// are that far apart, so the distance can be no larger, and parry's value is above it (GJK
/// stopping short on nearly parallel faces: the same behaviour `tests/obb_distance.rs` counts).
/// parry's distance is never below the oracle's by more than `TOL`.
#[test]
fn parry_distance_against_the_oracle() {
    let mut rng = StdRng::seed_from_u64(0xc1ea_0004);
    let (mut apart, mut parry_above, mut worst) = (0, 0, 0.0 as Real);
    for i in 0..70_000 {
        let kind = i % 7;
        let (a, b) = random_pair(&mut rng, kind);
        let truth = oracle(&a, &b);
        if truth.distance <= 1e-6 {
            continue;
        }
        apart += 1;
        let ((pa, sa), (pb, sb)) = (parry_parts(&a), parry_parts(&b));
        let parry = query::distance(&pa, &sa, &pb, &sb).unwrap().distance;
        let case = format!(
            "pair {i}, kind {kind}: a = {a:?}; b = {b:?}; oracle {truth:?}, parry {parry:e}"
        );
        assert!(parry >= truth.distance - TOL, "parry below the oracle: {case}");
        if parry > truth.distance + TOL {
            // The oracle's points are on the boxes and realise its distance: it is right.
            assert!(
                dist_to_box(&a, &truth.p) <= 1e-9 && dist_to_box(&b, &truth.q) <= 1e-9,
                "{case}"
            );
            assert!(((truth.p - truth.q).norm() - truth.distance).abs() <= 1e-9, "{case}");
            parry_above += 1;
            worst = worst.max(parry - truth.distance);
        }
    }
    println!(
        "{apart} separated pairs; parry above the oracle by more than {TOL} mm on {parry_above} (worst {worst:e} mm)"
    );
    assert!(parry_above * 100 < apart, "parry disagrees on {parry_above} of {apart}");
}

// ---------------------------------------------------------------------------------------------
// Properties.

fn obb() -> impl Strategy<Value = Obb> {
    (
        prop::array::uniform3(-300.0..300.0f64),
        prop::array::uniform4(-1.0..1.0f64),
        prop::array::uniform3(0.5..250.0f64),
    )
        .prop_filter_map("degenerate rotation", |(c, q, h)| {
            let q = nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]);
            (q.norm() > 1e-3).then(|| {
                let r = *UnitQuaternion::from_quaternion(q).to_rotation_matrix().matrix();
                Obb::new(Vec3::from(c), r, Vec3::from(h))
            })
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, ..ProptestConfig::default() })]

    /// The bound never exceeds the clearance (to the last rounding), and a positive bound means
    /// the separating axis test separates.
    #[test]
    fn lower_bound_is_below_the_clearance_and_agrees_with_the_sat(a in obb(), b in obb()) {
        let (lb, c) = (obb_clearance_lower_bound(&a, &b), obb_clearance(&a, &b).distance);
        prop_assert!(lb <= c, "a = {:?}; b = {:?}; bound {} clearance {}", a, b, lb, c);
        if lb > 0.0 {
            prop_assert!(separating_axis(&a, &b).is_some(), "a = {:?}; b = {:?}", a, b);
        }
        prop_assert_eq!(c > 0.0, separating_axis(&a, &b).is_some());
        prop_assert!((c - oracle(&a, &b).distance).abs() <= TOL);
    }
}
