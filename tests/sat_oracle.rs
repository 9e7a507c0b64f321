//! The separating axis test (thesis 3.1, SPEC §3) against parry3d-f64 as the oracle, on a
//! million seeded random box pairs, plus exactly touching boxes and libccd-style sweeps.
//!
//! Policy checked here: a "free" verdict of ours must be free for parry too, with a positive
//! distance (a false negative is always a failure); a "collision" of ours that parry calls
//! separated is allowed only within `BAND` mm of touching. Touching boxes collide; parry
//! misses many exactly touching pairs, so those are checked on their own, without parry, in
//! `tests/sat_touching.rs`.
//! Failing cases are printed as Rust literals to paste into `regressions()`.

use delta_collide::geometry::{separating_axis, Obb};
use delta_collide::math::{Mat3, Real, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

/// How close to touching (mm, parry's distance) a collision-side disagreement may be.
const BAND: Real = 1e-3;

/// One box pair: unit quaternions `[x, y, z, w]`, centres and half-extents.
#[derive(Clone, Copy, Debug)]
struct Case {
    qa: [Real; 4],
    ca: [Real; 3],
    ha: [Real; 3],
    qb: [Real; 4],
    cb: [Real; 3],
    hb: [Real; 3],
}

fn matrix(q: &[Real; 4]) -> Mat3 {
    let uq = UnitQuaternion::new_unchecked(Quaternion::new(q[3], q[0], q[1], q[2]));
    *uq.to_rotation_matrix().matrix()
}

fn obb(q: &[Real; 4], c: &[Real; 3], h: &[Real; 3]) -> Obb {
    Obb::new(Vec3::from(*c), matrix(q), Vec3::from(*h))
}

fn pose(q: &[Real; 4], c: &[Real; 3]) -> Pose {
    Pose::from_parts(Vector::new(c[0], c[1], c[2]), Rotation::from_xyzw(q[0], q[1], q[2], q[3]))
}

impl Case {
    fn ours_free(&self) -> bool {
        separating_axis(&obb(&self.qa, &self.ca, &self.ha), &obb(&self.qb, &self.cb, &self.hb))
            .is_some()
    }

    fn parry_parts(&self) -> (Pose, Cuboid, Pose, Cuboid) {
        (
            pose(&self.qa, &self.ca),
            Cuboid::new(Vector::from_array(self.ha)),
            pose(&self.qb, &self.cb),
            Cuboid::new(Vector::from_array(self.hb)),
        )
    }

    fn parry_intersects(&self) -> bool {
        let (pa, sa, pb, sb) = self.parry_parts();
        query::intersection_test(&pa, &sa, &pb, &sb).unwrap().intersecting
    }

    fn parry_distance(&self) -> Real {
        let (pa, sa, pb, sb) = self.parry_parts();
        query::distance(&pa, &sa, &pb, &sb).unwrap().distance
    }

    /// The distance between the closest vertex/edge features of the two boxes: exact for
    /// disjoint boxes and an upper bound on the distance always (a second opinion where parry's
    /// GJK distance stalls on nearly parallel faces).
    fn feature_distance(&self) -> Real {
        let (a, b) = (obb(&self.qa, &self.ca, &self.ha), obb(&self.qb, &self.cb, &self.hb));
        let (va, vb) = (a.vertices(), b.vertices());
        let mut d = Real::MAX;
        for v in &va {
            d = d.min(point_box_distance(v, &b));
        }
        for v in &vb {
            d = d.min(point_box_distance(v, &a));
        }
        for (p0, p1) in box_edges(&va) {
            for (q0, q1) in box_edges(&vb) {
                d = d.min(segment_distance(&p0, &p1, &q0, &q1));
            }
        }
        d
    }
}

fn point_box_distance(p: &Vec3, b: &Obb) -> Real {
    let local = b.axes.tr_mul(&(p - b.center));
    let clamped = Vec3::from_fn(|k, _| local[k].clamp(-b.half[k], b.half[k]));
    (local - clamped).norm()
}

/// The 12 edges of a box from its vertices (indexed by sign bits, as `Obb::vertices`).
fn box_edges(v: &[Vec3; 8]) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
    (0..8).flat_map(move |i| {
        (0..3).filter(move |k| i >> k & 1 == 0).map(move |k| (v[i], v[i | 1 << k]))
    })
}

/// Distance between segments `p0 p1` and `q0 q1` (Ericson, Real-Time Collision Detection 5.1.9).
fn segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> Real {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let c = d1.dot(&r);
    let b = d1.dot(&d2);
    let denom = a * e - b * b;
    let mut s = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

fn normalize4(q: [Real; 4]) -> [Real; 4] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
}

/// Hamilton product `p q` of quaternions `[x, y, z, w]`.
fn qmul(p: &[Real; 4], q: &[Real; 4]) -> [Real; 4] {
    let (px, py, pz, pw) = (p[0], p[1], p[2], p[3]);
    let (qx, qy, qz, qw) = (q[0], q[1], q[2], q[3]);
    [
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
        pw * qw - px * qx - py * qy - pz * qz,
    ]
}

fn random_quat(rng: &mut StdRng) -> [Real; 4] {
    loop {
        let q: [Real; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n2: Real = q.iter().map(|v| v * v).sum();
        if n2 > 1e-4 && n2 <= 1.0 {
            return normalize4(q);
        }
    }
}

/// Rotation by `angle` about coordinate axis `k`.
fn axis_quat(k: usize, angle: Real) -> [Real; 4] {
    let mut q = [0.0, 0.0, 0.0, (angle / 2.0).cos()];
    q[k] = (angle / 2.0).sin();
    q
}

fn random_unit(rng: &mut StdRng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

/// Half-extents: realistic links, random boxes, thin plates and needles.
fn random_half(rng: &mut StdRng) -> [Real; 3] {
    let mut h: [Real; 3] = match rng.random_range(0..4) {
        0 => {
            let s = rng.random_range(0.5..1.5);
            [200.0 * s, 70.0 * s, 17.5 * s]
        }
        1 => std::array::from_fn(|_| rng.random_range(1.0..300.0)),
        2 => [
            rng.random_range(10.0..300.0),
            rng.random_range(10.0..300.0),
            rng.random_range(0.01..1.0),
        ],
        _ => [
            rng.random_range(10.0..300.0),
            rng.random_range(0.01..1.0),
            rng.random_range(0.01..1.0),
        ],
    };
    let k = rng.random_range(0..3);
    h.swap(0, k);
    h
}

/// Support of a box along the unit direction `n`, from its centre.
fn support(q: &[Real; 4], h: &[Real; 3], n: &Vec3) -> Real {
    let m = matrix(q);
    (0..3).map(|k| m.column(k).dot(n).abs() * h[k]).sum()
}

/// Uniform poses, B's centre within reach of A so that about half the pairs collide.
fn uniform_case(rng: &mut StdRng) -> Case {
    let (ha, hb) = (random_half(rng), random_half(rng));
    let reach = ha.iter().chain(&hb).cloned().fold(0.0, Real::max) * 1.2;
    let ca: [Real; 3] = std::array::from_fn(|_| rng.random_range(-1000.0..1000.0));
    let cb: [Real; 3] = std::array::from_fn(|k| ca[k] + rng.random_range(-reach..reach));
    Case { qa: random_quat(rng), ca, ha, qb: random_quat(rng), cb, hb }
}

/// B placed at a controlled gap `+-10^log10_gap` mm from A along a direction that is random,
/// a face normal of A or B, or the cross product of an edge of each, with a lateral offset.
fn near_touching(
    rng: &mut StdRng,
    qa: [Real; 4],
    qb: [Real; 4],
    log10_gap: std::ops::Range<Real>,
) -> Case {
    let (ha, hb) = (random_half(rng), random_half(rng));
    let (ma, mb) = (matrix(&qa), matrix(&qb));
    let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let n = match rng.random_range(0..4) {
        0 => random_unit(rng),
        1 => ma.column(rng.random_range(0..3)).into_owned() * sign,
        2 => mb.column(rng.random_range(0..3)).into_owned() * sign,
        _ => {
            let c = ma.column(rng.random_range(0..3)).cross(&mb.column(rng.random_range(0..3)));
            if c.norm() < 1e-6 {
                random_unit(rng)
            } else {
                c.normalize() * sign
            }
        }
    };
    let gap =
        10f64.powf(rng.random_range(log10_gap)) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let ca: [Real; 3] = std::array::from_fn(|_| rng.random_range(-1000.0..1000.0));
    // A lateral shift orthogonal to n, up to a fraction of the smaller box.
    let lateral = {
        let v = random_unit(rng);
        let v = v - n * n.dot(&v);
        let s = ha.iter().chain(&hb).cloned().fold(Real::MAX, Real::min).max(1.0);
        v * rng.random_range(0.0..s)
    };
    let d = n * (support(&qa, &ha, &n) + support(&qb, &hb, &n) + gap) + lateral;
    let cb = [ca[0] + d.x, ca[1] + d.y, ca[2] + d.z];
    Case { qa, ca, ha, qb, cb, hb }
}

/// B's orientation with one axis parallel or anti-parallel to one of A's axes, exactly (A
/// axis-aligned, or rounding of one quaternion product) or within 1e-12 rad.
fn parallel_orientations(rng: &mut StdRng) -> ([Real; 4], [Real; 4]) {
    let k = rng.random_range(0..3);
    let mut rel = axis_quat(k, rng.random_range(-3.2..3.2));
    if rng.random_bool(0.5) {
        // Flip the axis: a half turn about another coordinate axis.
        rel = qmul(&axis_quat((k + 1) % 3, std::f64::consts::PI), &rel);
    }
    if rng.random_bool(0.3) {
        // Also swap which of B's axes is the parallel one.
        rel = qmul(&rel, &axis_quat((k + 2) % 3, std::f64::consts::FRAC_PI_2));
    }
    if rng.random_bool(0.5) {
        let v = random_unit(rng) * rng.random_range(0.0..1e-12);
        rel = normalize4(qmul(&rel, &[v.x / 2.0, v.y / 2.0, v.z / 2.0, 1.0]));
    }
    if rng.random_bool(0.3) {
        return ([0.0, 0.0, 0.0, 1.0], rel);
    }
    let qa = random_quat(rng);
    (qa, normalize4(qmul(&qa, &rel)))
}

/// B's orientation with one axis within `10^[-9, -1]` rad of one of A's axes: the regime where
/// a cross-product axis is short and the guards of the SAT matter most.
fn nearly_parallel_orientations(rng: &mut StdRng) -> ([Real; 4], [Real; 4]) {
    let k = rng.random_range(0..3);
    let rel = axis_quat(k, rng.random_range(-3.2..3.2));
    let v = random_unit(rng) * 10f64.powf(rng.random_range(-9.0..-1.0));
    let rel = normalize4(qmul(&rel, &[v.x / 2.0, v.y / 2.0, v.z / 2.0, 1.0]));
    let qa = random_quat(rng);
    (qa, normalize4(qmul(&qa, &rel)))
}

#[derive(Default, Debug)]
struct Tally {
    both_collide: usize,
    both_free: usize,
    ours_collide_parry_touching: usize,
    ours_collide_parry_within_band: usize,
    max_band_distance: Real,
    parry_distance_too_large: usize,
    failures: Vec<(Case, String)>,
}

impl Tally {
    fn check(&mut self, case: Case) {
        let ours_free = case.ours_free();
        let parry_hit = case.parry_intersects();
        match (ours_free, parry_hit) {
            (false, true) => self.both_collide += 1,
            (true, true) => self.fail(case, "ours free, parry intersecting".into()),
            (true, false) => {
                // Only near-contact pairs can hide a zero distance behind parry's SAT.
                let dist = case.parry_distance();
                if dist > 0.0 {
                    self.both_free += 1;
                } else {
                    self.fail(case, format!("ours free, parry distance {dist:e}"));
                }
            }
            (false, false) => {
                // Both distances bound the true one from above; parry's GJK can stall high.
                let (parry, features) = (case.parry_distance(), case.feature_distance());
                if parry > features + 1e-6 {
                    self.parry_distance_too_large += 1;
                }
                let dist = parry.min(features);
                if dist <= 0.0 {
                    self.ours_collide_parry_touching += 1;
                } else if dist <= BAND {
                    self.ours_collide_parry_within_band += 1;
                    self.max_band_distance = self.max_band_distance.max(dist);
                } else {
                    self.fail(case, format!("ours collision, parry separated by {dist:e} mm"));
                }
            }
        }
    }

    fn fail(&mut self, case: Case, why: String) {
        self.failures.push((case, why));
    }

    fn assert_clean(&self, name: &str) {
        println!(
            "{name}: both collide {}, both free {}, ours collide / parry touching (distance 0) {}, \
             ours collide / parry within {BAND} mm {} (max {:e} mm), \
             parry's distance above the feature distance {}, failures {}",
            self.both_collide,
            self.both_free,
            self.ours_collide_parry_touching,
            self.ours_collide_parry_within_band,
            self.max_band_distance,
            self.parry_distance_too_large,
            self.failures.len()
        );
        for (case, why) in self.failures.iter().take(20) {
            println!("    // {why}\n    {case:?},");
        }
        assert!(
            self.failures.is_empty(),
            "{name}: {} disagreements outside the policy",
            self.failures.len()
        );
    }
}

fn run(name: &str, seed: u64, n: usize, mut gen: impl FnMut(&mut StdRng) -> Case) -> Tally {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut tally = Tally::default();
    for _ in 0..n {
        tally.check(gen(&mut rng));
    }
    tally.assert_clean(name);
    tally
}

#[test]
fn uniform_random_pairs_agree_with_parry() {
    let t = run("uniform", 1, 400_000, uniform_case);
    assert!(t.both_collide > 100_000 && t.both_free > 100_000, "a real mix of verdicts");
}

#[test]
fn near_touching_pairs_agree_with_parry() {
    let t = run("near-touching", 2, 400_000, |rng| {
        let (qa, qb) = (random_quat(rng), random_quat(rng));
        near_touching(rng, qa, qb, -4.0..0.0)
    });
    assert!(t.both_collide > 20_000 && t.both_free > 50_000, "a real mix of verdicts");
}

#[test]
fn parallel_and_antiparallel_pairs_agree_with_parry() {
    let t = run("parallel", 3, 200_000, |rng| {
        let (qa, qb) = parallel_orientations(rng);
        if rng.random_bool(0.5) {
            near_touching(rng, qa, qb, -4.0..0.0)
        } else {
            Case { qa, qb, ..uniform_case(rng) }
        }
    });
    assert!(t.both_collide > 20_000 && t.both_free > 20_000, "a real mix of verdicts");
}

#[test]
fn nearly_parallel_near_touching_pairs_agree_with_parry() {
    let t = run("nearly parallel", 4, 100_000, |rng| {
        let (qa, qb) = nearly_parallel_orientations(rng);
        near_touching(rng, qa, qb, -4.0..0.0)
    });
    assert!(t.both_collide > 5_000 && t.both_free > 5_000, "a real mix of verdicts");
}

/// Cases once found by the random runs, pasted back as printed.
#[test]
fn regressions() {
    let cases = [
        // Parallel y axes, true gap 1e-4 mm along B's x: parry's GJK distance stalled at 5.03 mm,
        // and SAT_EPSILON = 1e-6 made ours report a collision.
        Case {
            qa: [0.0, 0.0, 0.0, 1.0],
            ca: [-499.4063285323844, -513.1341135416737, 545.0559513704],
            ha: [68.35093023644366, 252.26136124196114, 136.05417091179672],
            qb: [0.0, 0.009245647161966375, 0.0, 0.9999572580908428],
            cb: [-419.1678508381914, -511.80217675208115, 552.3759287669375],
            hb: [9.234354021183707, 186.48194961734185, 213.8524478991838],
        },
        // Anti-parallel needle, true gap 1.25e-4 mm: parry's GJK distance stalled at 79.7 mm.
        Case {
            qa: [-0.3715170064936598, 0.8951385366866326, 0.10635967402752275, -0.2222380115220238],
            ca: [-18.64460092687409, 310.09414247025234, -38.19754448636604],
            ha: [67.46295673206116, 192.75130494874614, 16.86573918301529],
            qb: [-0.618093019075355, 0.09744506938078926, -0.688590859494412, -0.3664807040547061],
            cb: [23.846096168927048, 358.09413758955066, -60.507486903315424],
            hb: [0.6358309541148788, 0.4089801293336501, 299.2653327385397],
        },
        // Large boxes 2.4e-3 mm apart: SAT_EPSILON = 1e-6 on |R| reported a collision.
        Case {
            qa: [0.43259627381925025, -0.256195703428533, 0.04268114038697688, -0.8633669820405031],
            ca: [-711.3121573668058, -977.959802334337, -577.9318842893724],
            ha: [128.53829367670915, 110.70228415126523, 217.22105916965006],
            qb: [
                0.6395188695689836,
                -0.6030284929141175,
                -0.03894701330515094,
                0.47524244586689185,
            ],
            cb: [-1220.9420474569777, -1162.7152436951196, -605.8336859246883],
            hb: [259.05881398088934, 235.25881787681757, 197.60835048338032],
        },
    ];
    let mut tally = Tally::default();
    for case in cases {
        tally.check(case);
    }
    tally.assert_clean("regressions");
    assert_eq!(tally.both_free, 3, "all three are separated");
}

/// Gaps of `+-10^[-9, -4]` mm, below what parry resolves: a free verdict of ours must still
/// be free for parry, and a collision of ours within the band of touching.
#[test]
fn very_near_touching_pairs_err_toward_collision() {
    run("very near", 5, 50_000, |rng| {
        let (qa, qb) = if rng.random_bool(0.5) {
            parallel_orientations(rng)
        } else {
            (random_quat(rng), random_quat(rng))
        };
        near_touching(rng, qa, qb, -9.0..-4.0)
    });
}
