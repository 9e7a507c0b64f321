//! Inverse kinematics and the box model of two robots (thesis 2.7, Figure 2.12; SPEC §2-§3).
//!
//! Groups: `ik` (ours, with and without the angles, next to a plain SPEC-formula IK with
//! atan2/acos), `model_two_robots` (both robots' boxes from two TCPs, the thesis 2.5 chain of
//! homogeneous transforms next to the direct vector form, returned by value and written into
//! reused buffers). Inputs are a ring of 128 seeded
//! reachable TCPs of the SPEC §4 workspace; every timed call checks its answer.
//!
//! Run: `cargo bench --bench kinematics -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::delta3::{radial, tangent};
use delta_collide::robot::{Delta3, RobotBoxes, RobotModel};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::f64::consts::{PI, TAU};
use std::hint::black_box;

const LEN: usize = 1 << 7;

/// 128 reachable TCPs of the SPEC §4 workspace (cylinder + frustum), seeded.
fn ring(seed: u64) -> Vec<Vec3> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(LEN);
    while out.len() < LEN {
        let p = Vec3::new(
            rng.random_range(-225.0..=225.0),
            rng.random_range(-225.0..=225.0),
            -rng.random_range(365.0..=530.0),
        );
        let d = -p.z;
        let r = if d <= 500.0 { 225.0 } else { 225.0 - 52.0 * (d - 500.0) / 30.0 };
        if p.x.hypot(p.y) <= r && Delta3::THESIS.is_reachable(&p) {
            out.push(p);
        }
    }
    out
}

/// The peer: SPEC §2 written out plainly, `th = -atan2(c, a) +/- acos(K / R)`, the one with the
/// larger cosine, wrapped to (-pi, pi], limits compared on the angle.
fn spec_formula_ik(d: &Delta3, tcp: &Vec3) -> Option<[Real; 3]> {
    let mut theta = [0.0; 3];
    for (arm, th) in theta.iter_mut().enumerate() {
        let p = d.platform_joint(arm, tcp) - d.motor_point(arm);
        let (a, b, c) = (p.dot(&radial(arm)), p.dot(&tangent(arm)), p.z);
        let k = (a * a + c * c + d.rf * d.rf - (d.re * d.re - b * b)) / (2.0 * d.rf);
        let r = a.hypot(c);
        if b * b > d.re * d.re || k.abs() > r {
            return None;
        }
        let (base, spread) = (-c.atan2(a), (k / r).acos());
        let (t1, t2) = (base + spread, base - spread);
        let t = if t1.cos() >= t2.cos() { t1 } else { t2 };
        let t = (t + PI).rem_euclid(TAU) - PI;
        let t = if t <= -PI { PI } else { t };
        if !(d.theta_min..=d.theta_max).contains(&t) {
            return None;
        }
        *th = t;
    }
    Some(theta)
}

fn bench_ik(c: &mut Criterion) {
    let d = Delta3::THESIS;
    let tcps = ring(0x1c_0001);
    let expected: Vec<[Real; 3]> =
        tcps.iter().map(|p| d.inverse_kinematics(p).unwrap().theta).collect();
    for (p, t) in tcps.iter().zip(&expected) {
        let peer = spec_formula_ik(&d, p).unwrap();
        assert!((0..3).all(|i| (peer[i] - t[i]).abs() < 1e-9), "peer and ours disagree at {p:?}");
    }
    let expected_cos0: Vec<Real> = expected.iter().map(|t| t[0].cos()).collect();
    let mut g = c.benchmark_group("ik");
    let mut i = 0usize;
    g.bench_function("ours_cos_sin", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            let sol = d.inverse_kinematics_cos_sin(black_box(&tcps[i])).unwrap();
            assert!((sol.cos[0] - expected_cos0[i]).abs() < 1e-9);
            sol
        })
    });
    g.bench_function("ours_with_angles", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            let sol = d.inverse_kinematics(black_box(&tcps[i])).unwrap();
            assert_eq!(sol.theta, expected[i]);
            sol
        })
    });
    g.bench_function("peer_spec_formula_atan2_acos", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            let theta = spec_formula_ik(&d, black_box(&tcps[i])).unwrap();
            assert!((theta[0] - expected[i][0]).abs() < 1e-9);
            theta
        })
    });
    g.finish();
}

fn bench_model(c: &mut Criterion) {
    let model = RobotModel::THESIS;
    let (ring_a, ring_b) = (ring(0x1c_0002), ring(0x1c_0003));
    // Reference centres of box 0 (A) and box 2 (B), from the direct form.
    let expected: Vec<(Vec3, Vec3)> = (0..LEN)
        .map(|i| {
            (
                model.boxes(&ring_a[i]).unwrap().boxes[0].center,
                model.boxes(&ring_b[i]).unwrap().boxes[2].center,
            )
        })
        .collect();
    let mut g = c.benchmark_group("model_two_robots");
    let mut i = 0usize;
    g.bench_function("direct", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            let a = model.boxes(black_box(&ring_a[i])).unwrap();
            let bb = model.boxes(black_box(&ring_b[i])).unwrap();
            assert!(a.boxes[0].center == expected[i].0 && bb.boxes[2].center == expected[i].1);
            black_box((&a, &bb));
        })
    });
    let (mut buf_a, mut buf_b) = (RobotBoxes::empty(), RobotBoxes::empty());
    g.bench_function("direct_into_buffers", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            model.boxes_into(black_box(&ring_a[i]), &mut buf_a).unwrap();
            model.boxes_into(black_box(&ring_b[i]), &mut buf_b).unwrap();
            assert!(
                buf_a.boxes[0].center == expected[i].0 && buf_b.boxes[2].center == expected[i].1
            );
            black_box((&buf_a, &buf_b));
        })
    });
    g.bench_function("chain_m1_m6", |b| {
        b.iter(|| {
            i = (i + 1) % LEN;
            let a = model.boxes_chain(black_box(&ring_a[i])).unwrap();
            let bb = model.boxes_chain(black_box(&ring_b[i])).unwrap();
            assert!((a.boxes[0].center - expected[i].0).norm() < 1e-9);
            assert!((bb.boxes[2].center - expected[i].1).norm() < 1e-9);
            black_box((&a, &bb));
        })
    });
    g.finish();
}

criterion_group!(benches, bench_ik, bench_model);
criterion_main!(benches);
