//! Fuzz target `exact_oracle`: two TCPs in a reference cell, the exact check against a brute
//! force that does not use the box frame (so it holds at singular poses, where the frame is a
//! choice).
//!
//! Input: a byte picking the cell (T1, T2, T3), then one TCP per robot, each either a point
//! ([`Input::point`]: raw numbers included) or a pose on a singular family of the thesis robot
//! (a lower link along its motor axis, near it, the elbow straight, the TCP in an arm's plane),
//! parameterised by the following bytes so that mutations walk along the family.
//!
//! Checks: a non-finite or unreachable TCP is reported, never answered; when the brute force's
//! inscribed balls meet (`rho = min(H, D)` around each link axis, `rho` from its ends) the
//! verdict is a collision; when its enclosing capsules (radius `hypot(H, D)`) are apart it is
//! free.

use super::input::{Encoder, Input};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use std::f64::consts::{PI, TAU};

const CELLS: [&str; 3] = ["T1", "T2", "T3"];
/// The thesis robot's f, rf, re, e (mm; SPEC §2).
const F: f64 = 100.0;
const RF: f64 = 150.0;
const RE: f64 = 400.0;
const E: f64 = 40.0;

/// Arm `i`'s radial and tangent units.
fn frame(arm: usize) -> (Vec3, Vec3) {
    let phi = arm as f64 * TAU / 3.0;
    (Vec3::new(phi.cos(), phi.sin(), 0.0), Vec3::new(-phi.sin(), phi.cos(), 0.0))
}

/// A TCP: a plain point, or a pose on a singular family picked and placed by the input.
fn tcp(input: &mut Input) -> Vec3 {
    let tag = input.byte() % 6;
    if tag < 2 {
        return Vec3::from(input.point());
    }
    let arm = usize::from(input.byte() % 3);
    let (u, t) = frame(arm);
    let at = |a: f64, b: f64, c: f64| u * (a + F - E) + t * b + Vec3::z() * c;
    // An angle below the base plane and a fraction in [0, 1), both from 16 bits.
    let psi = -PI * (f64::from(u16::from_le_bytes(input.bytes())) + 0.5) / 65536.0;
    let s = f64::from(u16::from_le_bytes(input.bytes())) / 65536.0;
    let sign = if input.flag() { 1.0 } else { -1.0 };
    match tag {
        // Lower link along the motor axis: b = +-re, hypot(a, c) = rf.
        2 => at(RF * psi.cos(), sign * RE, RF * psi.sin()),
        // Near it: b = re - delta with delta from 1e-15 to 1 mm, R inside the reachable tube.
        3 => {
            let b = RE - 10f64.powf(-15.0 * s);
            let r = RF + (2.0 * s - 1.0) * (RE * RE - b * b).sqrt();
            at(r * psi.cos(), sign * b, r * psi.sin())
        }
        // Elbow straight: |P - F| in the arm's plane at rf + sqrt(re^2 - b^2).
        4 => {
            let b = sign * RE * s * 0.9;
            let r = RF + (RE * RE - b * b).sqrt();
            at(r * psi.cos(), b, r * psi.sin())
        }
        // TCP in the arm's plane: b = 0.
        _ => at(300.0 * (2.0 * s - 1.0), 0.0, -300.0 + 250.0 * psi / PI),
    }
}

/// The lower links `(G_i, E_i)` of the thesis robot at `tcp` (MCS) by SPEC §2's angle form,
/// or `None` when unreachable.
fn lower_links(p: Vec3) -> Option<[(Vec3, Vec3); 3]> {
    if !(p.iter().all(|v| v.is_finite()) && p.z < 0.0) {
        return None;
    }
    let mut out = [(Vec3::zeros(), Vec3::zeros()); 3];
    for (arm, link) in out.iter_mut().enumerate() {
        let (u, t) = frame(arm);
        let q = p + u * (E - F);
        let (a, b, c) = (q.dot(&u), q.dot(&t), q.z);
        let r = a.hypot(c);
        let k = (a * a + c * c + RF * RF - (RE * RE - b * b)) / (2.0 * RF);
        if !(b * b <= RE * RE && k.abs() <= r && r > 0.0) {
            return None;
        }
        let th = -c.atan2(a) - (k / r).acos();
        if !(-PI / 2.0..=2.0 * PI / 3.0).contains(&th) {
            return None;
        }
        *link = (u * F + (u * th.cos() - Vec3::z() * th.sin()) * RF, p + u * E);
    }
    Some(out)
}

fn point_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let d = b - a;
    let s = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
    (p - (a + d * s)).norm()
}

/// Segment distance by golden-section search over the first segment (the distance from a
/// point moving along a line to a segment is convex).
fn segment_segment(a0: &Vec3, a1: &Vec3, b0: &Vec3, b1: &Vec3) -> f64 {
    let at = |s: f64| point_segment(&(a0 + (a1 - a0) * s), b0, b1);
    let (mut lo, mut hi, g) = (0.0, 1.0, (5f64.sqrt() - 1.0) / 2.0);
    for _ in 0..45 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if at(m1) < at(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    at(0.5 * (lo + hi)).min(at(0.0)).min(at(1.0))
}

/// The target: see the module doc.
pub fn exact_oracle(data: &[u8]) {
    let mut input = Input::new(data);
    let cell = reference_cell(CELLS[usize::from(input.byte() % 3)]).expect("reference cell");
    let tcps = [tcp(&mut input), tcp(&mut input)];
    let mut checker = ExactChecker::new(cell.clone());
    let v = checker.check(&tcps).expect("two TCPs");
    let links = [lower_links(tcps[0]), lower_links(tcps[1])];
    let [Some(la), Some(lb)] = links else {
        // Unreachable for the brute force: we must not answer free unless we find the TCP
        // reachable by a rounding step on the boundary, and then a free answer is checked
        // only through the capsules below, which need both links.
        if tcps.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
            assert!(!v.all_reachable() && !v.collides(), "a non-finite TCP was answered: {tcps:?}");
        }
        return;
    };
    if !v.all_reachable() {
        return; // the two inverse kinematics round differently on the reach boundary
    }
    let placed =
        |j: usize, p: &Vec3| cell.robots[j].placement.rotation() * p + cell.robots[j].placement.t;
    let (rho, outer) = (17.5f64, 70f64.hypot(17.5));
    let (mut inner, mut apart) = (f64::INFINITY, f64::INFINITY);
    for (ga, ea) in &la {
        for (gb, eb) in &lb {
            let (ga, ea, gb, eb) = (placed(0, ga), placed(0, ea), placed(1, gb), placed(1, eb));
            let shrink = |g: &Vec3, e: &Vec3| {
                let x = (e - g).normalize();
                (g + x * rho, e - x * rho)
            };
            let (sa, sb) = (shrink(&ga, &ea), shrink(&gb, &eb));
            inner = inner.min(segment_segment(&sa.0, &sa.1, &sb.0, &sb.1));
            apart = apart.min(segment_segment(&ga, &ea, &gb, &eb));
        }
    }
    if inner < 2.0 * rho - 1e-6 {
        assert!(
            v.collides(),
            "{}: inscribed balls meet ({inner} mm) but the check says free: {tcps:?}",
            cell.name
        );
    }
    if apart > 2.0 * outer + 1e-6 {
        assert!(
            !v.collides(),
            "{}: capsules apart ({apart} mm) but the check says collision: {tcps:?}",
            cell.name
        );
    }
}

/// Seeds: each singular family in each cell, the pose an adversarial review found answered
/// free, and raw points.
pub fn seeds() -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for (c, name) in CELLS.iter().enumerate() {
        for tag in 2..6u8 {
            let mut e = Encoder::default();
            e.byte(c as u8).byte(tag).byte(0).u16(40_000).u16(30_000).byte(1);
            e.byte(tag).byte(1).u16(20_000).u16(50_000).byte(0);
            out.push((format!("{}_family_{tag}.bin", name.to_lowercase()), e.bytes.clone()));
        }
    }
    // T1 with A within 1e-2 mm of (60, 400, -150), link 0 along its motor axis (psi next to
    // -pi/2: a ~ 0, c ~ -rf, so the TCP is ~(f - e, re, -rf)), and B where the review put it.
    let mut e = Encoder::default();
    e.byte(0).byte(2).byte(0).u16(32_767).u16(0).byte(1);
    e.byte(0).byte(0);
    for v in [-258.412_635_626_196_7_f64, 256.221_584_677_934_97, -152.074_085_853_705_7] {
        e.byte(1).bytes.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    out.push(("t1_reported_singular_pose.bin".into(), e.bytes));
    out
}
