//! Separating axis test benchmarks (thesis 3.1.5), ours next to parry3d-f64 in the same run.
//!
//! - `box_pair`: one box pair, on a ring of 128 seeded random pairs of realistic link boxes
//!   (about a third colliding). Ours against parry3d-f64's `intersection_test`, and its
//!   cuboid routine called directly with a precomputed relative pose.
//! - `nine_pairs`: the 3 x 3 lower links of two thesis robots (cell T2, d = 400 mm) at 128
//!   random configurations: a plain scalar loop, the batched `first_intersecting_pair` (AABB
//!   pre-reject), and the witness cache (on unrelated configurations: its worst case).
//! - `trajectory`: the thesis's two cases (3.1.5) on cell T1, 6,000 ticks each (per-tick time
//!   = reported time / 6,000): "practical" (robots approach, never collide) and "collision"
//!   (the last part collides), SAT vs SAT-cache.
//!
//! Every timed call checks its verdict against one computed before timing.
//! Run: `cargo bench --bench sat -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use delta_collide::geometry::{
    first_intersecting_pair, obbs_intersect, separating_axis, Obb, WitnessCache,
};
use delta_collide::math::{Mat3, Real, Vec3};
use delta_collide::robot::model::RobotModel;
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const RING: usize = 128;
const LINK_HALF: [Real; 3] = [200.0, 70.0, 17.5];

fn random_quat(rng: &mut StdRng) -> [Real; 4] {
    loop {
        let q: [Real; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n2: Real = q.iter().map(|v| v * v).sum();
        if n2 > 1e-4 && n2 <= 1.0 {
            let n = n2.sqrt();
            return q.map(|v| v / n);
        }
    }
}

/// A box pair in both representations.
struct Pair {
    a: Obb,
    b: Obb,
    pose_a: Pose,
    pose_b: Pose,
    pose_ab: Pose,
    cuboid: Cuboid,
}

fn pair_ring() -> Vec<Pair> {
    let mut rng = StdRng::seed_from_u64(2024);
    let cuboid = Cuboid::new(Vector::from_array(LINK_HALF));
    let mat = |q: [Real; 4]| {
        *nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]))
            .to_rotation_matrix()
            .matrix()
    };
    let pose = |q: [Real; 4], c: Vec3| {
        Pose::from_parts(Vector::new(c.x, c.y, c.z), Rotation::from_xyzw(q[0], q[1], q[2], q[3]))
    };
    (0..RING)
        .map(|_| {
            let (qa, qb) = (random_quat(&mut rng), random_quat(&mut rng));
            let ca =
                Vec3::new(rng.random_range(-500.0..500.0), rng.random_range(-500.0..500.0), -430.0);
            let offset = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let cb = ca + offset * 220.0;
            let (pose_a, pose_b) = (pose(qa, ca), pose(qb, cb));
            Pair {
                a: Obb::new(ca, mat(qa), Vec3::from(LINK_HALF)),
                b: Obb::new(cb, mat(qb), Vec3::from(LINK_HALF)),
                pose_a,
                pose_b,
                pose_ab: pose_a.inv_mul(&pose_b),
                cuboid,
            }
        })
        .collect()
}

fn box_pair(c: &mut Criterion) {
    let ring = pair_ring();
    let ours: Vec<bool> = ring.iter().map(|p| obbs_intersect(&p.a, &p.b)).collect();
    let parry: Vec<bool> = ring
        .iter()
        .map(|p| {
            query::intersection_test(&p.pose_a, &p.cuboid, &p.pose_b, &p.cuboid)
                .unwrap()
                .intersecting
        })
        .collect();
    let agree = ours.iter().zip(&parry).filter(|(a, b)| a == b).count();
    println!(
        "box_pair ring: {} of {RING} pairs collide; ours and parry agree on {agree}",
        ours.iter().filter(|&&v| v).count()
    );

    let mut g = c.benchmark_group("box_pair");
    let mut k = 0;
    g.bench_function("ours_separating_axis", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let p = &ring[k];
            assert_eq!(obbs_intersect(black_box(&p.a), black_box(&p.b)), ours[k]);
        })
    });
    g.bench_function("parry3d_f64_intersection_test", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let p = &ring[k];
            let hit = query::intersection_test(
                black_box(&p.pose_a),
                &p.cuboid,
                black_box(&p.pose_b),
                &p.cuboid,
            )
            .unwrap();
            assert_eq!(hit.intersecting, parry[k]);
        })
    });
    g.bench_function("parry3d_f64_cuboid_cuboid_pos12", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let p = &ring[k];
            let hit = query::details::intersection_test_cuboid_cuboid(
                black_box(&p.pose_ab),
                &p.cuboid,
                &p.cuboid,
            );
            assert_eq!(hit, parry[k]);
        })
    });
    g.finish();
}

/// TCP uniformly in the thesis workspace's cylinder part (radius 225, depth 365..500).
fn random_tcp(rng: &mut StdRng) -> Vec3 {
    loop {
        let (x, y) = (rng.random_range(-225.0..225.0), rng.random_range(-225.0..225.0));
        if x * x + y * y <= 225.0 * 225.0 {
            return Vec3::new(x, y, -rng.random_range(365.0..500.0));
        }
    }
}

/// The three lower-link boxes of robot A (at the origin) and of robot B (at `(d, 0, 0)`).
fn lower_links(
    model: &RobotModel,
    tcp_a: &Vec3,
    tcp_b: &Vec3,
    d: Real,
) -> Option<([Obb; 3], [Obb; 3])> {
    let a = model.boxes(tcp_a).ok()?;
    let b = model.boxes(tcp_b).ok()?;
    let shift = Vec3::new(d, 0.0, 0.0);
    Some((
        std::array::from_fn(|k| a.boxes[k]),
        std::array::from_fn(|k| b.boxes[k].transformed(&Mat3::identity(), &shift)),
    ))
}

/// The plain scalar loop: every pair through the 15-axis test, first hit wins.
fn plain_loop(a: &[Obb], b: &[Obb]) -> Option<(usize, usize)> {
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            if separating_axis(x, y).is_none() {
                return Some((i, j));
            }
        }
    }
    None
}

fn nine_pairs(c: &mut Criterion) {
    let model = RobotModel::THESIS;
    let mut rng = StdRng::seed_from_u64(7);
    let mut ring = Vec::with_capacity(RING);
    while ring.len() < RING {
        let (ta, tb) = (random_tcp(&mut rng), random_tcp(&mut rng));
        if let Some(boxes) = lower_links(&model, &ta, &tb, 400.0) {
            ring.push(boxes);
        }
    }
    let expected: Vec<bool> = ring.iter().map(|(a, b)| plain_loop(a, b).is_some()).collect();
    println!(
        "nine_pairs ring: {} of {RING} configurations collide",
        expected.iter().filter(|&&v| v).count()
    );

    let mut g = c.benchmark_group("nine_pairs");
    let mut k = 0;
    g.bench_function("plain_scalar_loop", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let (a, b) = &ring[k];
            assert_eq!(plain_loop(black_box(a), black_box(b)).is_some(), expected[k]);
        })
    });
    g.bench_function("first_intersecting_pair", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let (a, b) = &ring[k];
            assert_eq!(first_intersecting_pair(black_box(a), black_box(b)).is_some(), expected[k]);
        })
    });
    let mut cache = WitnessCache::new();
    g.bench_function("witness_cache_unrelated_configs", |bench| {
        bench.iter(|| {
            k = (k + 1) % RING;
            let (a, b) = &ring[k];
            assert_eq!(
                cache.first_intersecting_pair(black_box(a), black_box(b)).is_some(),
                expected[k]
            );
        })
    });
    g.finish();
}

/// 6,000 ticks on cell T1 (d = 450): A's TCP moves from (-150, 40, -430) toward B and B's
/// from (150, -40, -430) toward A, `reach` mm each; the boxes of every tick.
fn trajectory(reach: Real) -> Vec<([Obb; 3], [Obb; 3])> {
    let model = RobotModel::THESIS;
    (0..6000)
        .map(|tick| {
            let s = tick as Real / 5999.0;
            let ta = Vec3::new(-150.0 + s * reach, 40.0, -430.0);
            let tb = Vec3::new(150.0 - s * reach, -40.0, -430.0);
            lower_links(&model, &ta, &tb, 450.0).expect("trajectory stays reachable")
        })
        .collect()
}

fn trajectories(c: &mut Criterion) {
    let (practical, collision) = (trajectory(300.0), trajectory(400.0));
    assert!(
        practical.iter().all(|(a, b)| plain_loop(a, b).is_none()),
        "the practical case never collides"
    );
    let colliding = collision.iter().filter(|(a, b)| plain_loop(a, b).is_some()).count();
    println!("trajectory: practical 0 of 6000 ticks collide, collision case {colliding} of 6000");
    assert!(colliding > 300, "the collision case collides in its last part");

    let mut g = c.benchmark_group("trajectory");
    g.throughput(Throughput::Elements(6000));
    for (name, run) in [("practical", &practical), ("collision", &collision)] {
        let expected: Vec<bool> = run.iter().map(|(a, b)| plain_loop(a, b).is_some()).collect();
        g.bench_function(format!("{name}/sat"), |bench| {
            bench.iter(|| {
                for ((a, b), &e) in run.iter().zip(&expected) {
                    assert_eq!(first_intersecting_pair(black_box(a), black_box(b)).is_some(), e);
                }
            })
        });
        g.bench_function(format!("{name}/sat_cache"), |bench| {
            bench.iter_batched_ref(
                WitnessCache::new,
                |cache| {
                    for ((a, b), &e) in run.iter().zip(&expected) {
                        assert_eq!(
                            cache.first_intersecting_pair(black_box(a), black_box(b)).is_some(),
                            e
                        );
                    }
                },
                BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, box_pair, nine_pairs, trajectories);
criterion_main!(benches);
