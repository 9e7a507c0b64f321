//! Clearance benchmarks (SPEC §8): the nine lower-link box pairs of two thesis robots in cell
//! T1 (B at (450, 0, 0)), at configurations in four bands of clearance, ours next to
//! parry3d-f64 in the same run.
//!
//! - `clearance/<band>`: `boxes_clearance` (pairs skipped by their lower bound), all nine
//!   `obb_clearance` calls, and parry3d-f64's `query::distance` on the same nine pairs.
//! - `bound/<band>`: `boxes_clearance_lower_bound` against the plain separating axis loop
//!   (every pair until the first intersecting one).
//!
//! - `clearance/tick_by_tick`: the same nine pairs along a run at 1 ms ticks (both TCPs on
//!   circles at about 3 m/s, clearances from touching to far): `CoherentClearance`, which
//!   starts from the last tick's closest pair, directions and features, against
//!   `boxes_clearance` from scratch and parry3d-f64's nine distances.
//!
//! Bands: far (> 100 mm), near (5 to 30 mm), touching (|clearance| < 1e-6 mm, found by
//! bisection from near configurations) and colliding (< -1 mm). Each is a ring of 64
//! configurations; every timed call checks its answer against one computed before timing.
//! Run: `cargo bench --bench clearance -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use delta_collide::geometry::{
    boxes_clearance, boxes_clearance_lower_bound, obb_clearance, separating_axis,
    CoherentClearance, Obb, PairClearance,
};
use delta_collide::math::{Mat3, Real, Vec3};
use delta_collide::robot::model::RobotModel;
use nalgebra::{Rotation3, UnitQuaternion};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const RING: usize = 64;

/// The nine-pair input in both representations.
struct Config {
    a: [Obb; 3],
    b: [Obb; 3],
    parry_a: [(Pose, Cuboid); 3],
    parry_b: [(Pose, Cuboid); 3],
}

fn parry_parts(o: &Obb) -> (Pose, Cuboid) {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(o.axes));
    let pose = Pose::from_parts(
        Vector::new(o.center.x, o.center.y, o.center.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    );
    (pose, Cuboid::new(Vector::new(o.half.x, o.half.y, o.half.z)))
}

/// The lower links of A (at the origin) and B (at (450, 0, 0)), or `None` when unreachable.
fn config(tcp_a: &Vec3, tcp_b: &Vec3) -> Option<Config> {
    let model = RobotModel::THESIS;
    let (ra, rb) = (model.boxes(tcp_a).ok()?, model.boxes(tcp_b).ok()?);
    let shift = Vec3::new(450.0, 0.0, 0.0);
    let a: [Obb; 3] = std::array::from_fn(|k| ra.boxes[k]);
    let b: [Obb; 3] = std::array::from_fn(|k| rb.boxes[k].transformed(&Mat3::identity(), &shift));
    Some(Config {
        parry_a: a.each_ref().map(parry_parts),
        parry_b: b.each_ref().map(parry_parts),
        a,
        b,
    })
}

/// A TCP in the cylinder part of the thesis workspace (SPEC §4).
fn random_tcp(rng: &mut StdRng) -> Vec3 {
    loop {
        let (x, y) = (rng.random_range(-225.0..225.0), rng.random_range(-225.0..225.0));
        if x * x + y * y <= 225.0 * 225.0 {
            return Vec3::new(x, y, -rng.random_range(365.0..500.0));
        }
    }
}

/// Rings of far, near, touching and colliding configurations.
fn rings() -> [(&'static str, Vec<Config>); 4] {
    let mut rng = StdRng::seed_from_u64(0xc1ea);
    let (mut far, mut near, mut touching, mut colliding) = (vec![], vec![], vec![], vec![]);
    let clearance =
        |ta: &Vec3, tb: &Vec3| config(ta, tb).map(|c| boxes_clearance(&c.a, &c.b).distance);
    while far.len() < RING || near.len() < RING || touching.len() < RING || colliding.len() < RING {
        let (ta, tb) = (random_tcp(&mut rng), random_tcp(&mut rng));
        let Some(d) = clearance(&ta, &tb) else { continue };
        if d > 100.0 && far.len() < RING {
            far.extend(config(&ta, &tb));
        } else if d < -1.0 && colliding.len() < RING {
            colliding.extend(config(&ta, &tb));
        } else if (5.0..30.0).contains(&d) && (near.len() < RING || touching.len() < RING) {
            if touching.len() < RING {
                // Move both TCPs toward each other along x until the clearance crosses 0.
                let at = |s: Real| (ta + Vec3::x() * s, tb - Vec3::x() * s);
                let (mut lo, mut hi) = (0.0, 60.0);
                let f = |s: Real| {
                    let (x, y) = at(s);
                    clearance(&x, &y)
                };
                if matches!(f(hi), Some(v) if v < 0.0) {
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        match f(mid) {
                            Some(v) if v > 0.0 => lo = mid,
                            _ => hi = mid,
                        }
                    }
                    let (x, y) = at(lo);
                    if matches!(f(lo), Some(v) if v.abs() < 1e-6) {
                        touching.extend(config(&x, &y));
                    }
                }
            }
            if near.len() < RING {
                near.extend(config(&ta, &tb));
            }
        }
    }
    [("far", far), ("near", near), ("touching", touching), ("colliding", colliding)]
}

fn all_nine(c: &Config) -> Real {
    let mut d = Real::INFINITY;
    for x in &c.a {
        for y in &c.b {
            d = d.min(obb_clearance(black_box(x), black_box(y)).distance);
        }
    }
    d
}

fn parry_nine(c: &Config) -> Real {
    let mut d = Real::INFINITY;
    for (pa, sa) in &c.parry_a {
        for (pb, sb) in &c.parry_b {
            d = d.min(query::distance(black_box(pa), sa, black_box(pb), sb).unwrap().distance);
        }
    }
    d
}

/// The plain separating axis loop: whether any pair intersects.
fn sat_loop(c: &Config) -> bool {
    c.a.iter().any(|x| c.b.iter().any(|y| separating_axis(black_box(x), black_box(y)).is_none()))
}

fn clearance(c: &mut Criterion) {
    for (band, ring) in rings() {
        let ours: Vec<PairClearance> = ring.iter().map(|c| boxes_clearance(&c.a, &c.b)).collect();
        let nine: Vec<Real> = ring.iter().map(all_nine).collect();
        let parry: Vec<Real> = ring.iter().map(parry_nine).collect();
        let worst = ours
            .iter()
            .zip(&parry)
            .map(|(o, p)| (o.distance.max(0.0) - p).abs())
            .fold(0.0, Real::max);
        let (lo, hi) = ours.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(l, h), o| {
            (l.min(o.distance), h.max(o.distance))
        });
        println!("{band}: clearance {lo:.6} .. {hi:.6} mm; largest |ours (0 if < 0) - parry| {worst:e} mm");

        let mut g = c.benchmark_group(format!("clearance/{band}"));
        let mut k = 0;
        g.bench_function("ours_boxes_clearance", |bench| {
            bench.iter(|| {
                k = (k + 1) % RING;
                let c = &ring[k];
                assert_eq!(boxes_clearance(black_box(&c.a), black_box(&c.b)), ours[k]);
            })
        });
        g.bench_function("ours_nine_obb_clearance", |bench| {
            bench.iter(|| {
                k = (k + 1) % RING;
                assert_eq!(all_nine(&ring[k]), nine[k]);
            })
        });
        g.bench_function("parry3d_f64_nine_distance", |bench| {
            bench.iter(|| {
                k = (k + 1) % RING;
                assert_eq!(parry_nine(&ring[k]), parry[k]);
            })
        });
        g.finish();

        let bound: Vec<Real> =
            ring.iter().map(|c| boxes_clearance_lower_bound(&c.a, &c.b)).collect();
        let hit: Vec<bool> = ring.iter().map(sat_loop).collect();
        assert!(bound.iter().zip(&ours).all(|(b, o)| b <= &o.distance));
        let mut g = c.benchmark_group(format!("bound/{band}"));
        g.bench_function("ours_boxes_clearance_lower_bound", |bench| {
            bench.iter(|| {
                k = (k + 1) % RING;
                let c = &ring[k];
                assert_eq!(boxes_clearance_lower_bound(black_box(&c.a), black_box(&c.b)), bound[k]);
            })
        });
        g.bench_function("plain_sat_loop", |bench| {
            bench.iter(|| {
                k = (k + 1) % RING;
                assert_eq!(sat_loop(&ring[k]), hit[k]);
            })
        });
        g.finish();
    }
}

/// Ticks of a run: A's TCP on a circle of radius 150 mm, B's on another, both at 20 rad/s
/// (3 m/s), sampled every 1 ms; unreachable ticks left out.
fn run() -> Vec<Config> {
    let tcp = |t: Real, phase: Real, x: Real| {
        Vec3::new(
            x + 150.0 * (20.0 * t + phase).cos(),
            150.0 * (20.0 * t + phase).sin(),
            -420.0 - 40.0 * (7.0 * t).sin(),
        )
    };
    (0..3000)
        .filter_map(|i| {
            config(&tcp(i as Real * 1e-3, 0.0, 40.0), &tcp(i as Real * 1e-3, 2.0, -40.0))
        })
        .collect()
}

fn tick_by_tick(c: &mut Criterion) {
    let run = run();
    let cold: Vec<PairClearance> = run.iter().map(|c| boxes_clearance(&c.a, &c.b)).collect();
    let (lo, hi) = cold.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(l, h), o| {
        (l.min(o.distance), h.max(o.distance))
    });
    println!("tick_by_tick: {} ticks, clearance {lo:.3} .. {hi:.3} mm", run.len());
    let mut g = c.benchmark_group("clearance/tick_by_tick");
    let (mut k, mut memory) = (0, CoherentClearance::new());
    g.bench_function("ours_coherent", |bench| {
        bench.iter(|| {
            k = (k + 1) % run.len();
            let d = memory.boxes_clearance(black_box(&run[k].a), black_box(&run[k].b)).distance;
            assert!(
                (d - cold[k].distance).abs() <= 1e-9,
                "tick {k}: {d} against {}",
                cold[k].distance
            );
        })
    });
    g.bench_function("ours_boxes_clearance", |bench| {
        bench.iter(|| {
            k = (k + 1) % run.len();
            assert_eq!(boxes_clearance(black_box(&run[k].a), black_box(&run[k].b)), cold[k]);
        })
    });
    g.bench_function("parry3d_f64_nine_distance", |bench| {
        bench.iter(|| {
            k = (k + 1) % run.len();
            black_box(parry_nine(&run[k]));
        })
    });
    g.finish();
}

criterion_group!(benches, clearance, tick_by_tick);
criterion_main!(benches);
