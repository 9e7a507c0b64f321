//! How many STOP ticks of the C harness's runs (default stopping model) two sound tightenings
//! of the swept-box proof would prove, measured before building them into the library:
//! `stop_room`.
//!
//! Per STOP tick, each box pair is tried with the sweeps of `stop_sweeps_wcs` (tier 1 over
//! the ball of radius `S` around the TCP, the boxes now as references; the checker itself
//! uses the smaller ball ahead along the velocity, so these counts are a conservative
//! estimate), on three sets of axes and supports:
//! - today's: the 15 axes of the two boxes, each sweep's support symmetric (the control: it
//!   should prove almost none of the checker's STOP ticks);
//! - plus the direction between the pair's closest points as a 16th axis (any direction on
//!   which the projections of two convex sets are apart proves them apart);
//! - directed supports on those 16 axes: a lower link's body point at `l` along the link
//!   (`l = 0` at the elbow `G`, 1 at the platform joint `E`, `[-mu, 1 + mu]` with the margin)
//!   moves within `|l| Z + |1 - l| A` plus the frame's terms (`cspace::guarantee`, step 4),
//!   so the swept box reaches along `n` at most
//!   `max over l in {-mu, 0, 1, 1 + mu} of (l - 1/2) re (n . x) + |l| h_Z(n) + |1 - l| h_A(n)`
//!   plus the terms across the link, instead of `hx |n . x| + max(ends)`: the end that leads
//!   along `n` carries only its own displacement set. Each robot's reach is taken toward the
//!   other (`n` for A, `-n` for B).
//!
//! A tick counts when every box pair is proved.
//!
//! `stop_room T1practical 350` prints, for that tick instead, the closest box pair's sweep
//! supports along the direction between its closest points (each robot toward the other),
//! today's and directed, beside how far the boxes reach along it over 50,000 TCPs drawn in
//! each ball.

use delta_collide::cell::protective::{stop_sweeps_wcs, Protective, ProtectiveChecker, SweepForms};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::geometry::{obb_clearance, Obb, Sweep};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

/// How far box `b` swept by `s` reaches along `n` beyond `n . centre`: symmetric (today's),
/// or directed for a lower link's sweep (ends `(mu, 1 + mu)`, `(1 + mu, mu)`: module doc).
fn reach(b: &Obb, s: &Sweep, n: &Vec3, directed: bool) -> Real {
    let (len, x) = (n.norm(), b.axes.column(0).into_owned());
    let across = (1..3).map(|i| b.half[i] * n.dot(&b.axes.column(i)).abs()).sum::<Real>();
    let common = across + s.ball * len + s.line.dot(n).abs();
    let z = s.cube.iter().map(|w| w.dot(n).abs()).sum::<Real>() + s.round * len;
    let a = s.arc.iter().map(|v| v.dot(n).abs()).sum::<Real>();
    let [(e1, d1), (e2, d2)] = s.ends;
    let link = e1 == d2 && d1 == e2 && e1 >= 0.0 && (d1 - e1 - 1.0).abs() < 1e-12;
    if !(directed && link) {
        return common + b.half.x * n.dot(&x).abs() + (e1 * z + d1 * a).max(e2 * z + d2 * a);
    }
    let (sx, half_re) = (n.dot(&x), b.half.x / (1.0 + 2.0 * e1));
    let at = |pos: Real, e: Real, d: Real| pos * sx + e * z + d * a;
    common + at(-b.half.x, e1, d1).max(at(-half_re, 0.0, 1.0)).max(at(half_re, 1.0, 0.0)).max(at(b.half.x, e2, d2))
}

/// Whether the pair is proved apart on the 15 axes (and the closest direction with `closest`),
/// the smaller reach of either sweep form per box and axis.
fn proved(a: &Obb, fa: [&Sweep; 2], b: &Obb, fb: [&Sweep; 2], closest: bool, directed: bool) -> bool {
    let c = obb_clearance(a, b);
    // Boxes that touch or overlap now (or a NaN) are not proved apart.
    if c.distance.is_nan() || c.distance <= 0.0 {
        return false;
    }
    let cols = |o: &Obb| [0, 1, 2].map(|i| o.axes.column(i).into_owned());
    let (ua, ub) = (cols(a), cols(b));
    let mut axes: Vec<Vec3> = ua.iter().chain(&ub).copied().collect();
    axes.extend(ua.iter().flat_map(|x| ub.iter().map(move |y| x.cross(y))).filter(|n| n.norm_squared() > 1e-10));
    if closest {
        axes.push(c.point_b - c.point_a);
    }
    axes.iter().any(|n0| {
        let d = n0.dot(&(b.center - a.center));
        let n = if d >= 0.0 { *n0 } else { -n0 };
        let least = |o: &Obb, f: [&Sweep; 2], n: &Vec3| reach(o, f[0], n, directed).min(reach(o, f[1], n, directed));
        d.abs() - least(a, fa, &n) - least(b, fb, &(-n)) > 1e-6 * n.norm()
    })
}

/// The single-tick report of the module doc.
fn one_tick(run: &str, tick: u32) {
    let s = parse_scenarios(SCENARIOS).unwrap().into_iter().find(|s| format!("{}{}", s.cell, s.case) == run).unwrap();
    let cell = reference_cell(&s.cell).unwrap().with_stopping(1.0, vec![StopModel::DEFAULT; 2]).unwrap();
    let mut checker = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let mut tcps = [Vec3::zeros(); 2];
    for t in 0..=tick {
        s.tcps_at(t, &mut tcps);
        checker.check(&tcps).unwrap();
    }
    let r = checker.report().clone();
    let mut exact = ExactChecker::new(cell.clone());
    exact.place_boxes(&tcps).unwrap();
    let (boxes, c) = ([*exact.boxes(0), *exact.boxes(1)], r.closest.unwrap());
    let closest = obb_clearance(&boxes[0].as_slice()[c.box_a], &boxes[1].as_slice()[c.box_b]);
    let u = (closest.point_b - closest.point_a) / closest.distance;
    let (verdict, gap) = (r.verdict, closest.distance);
    println!("{run} tick {tick}: {verdict:?}, clearance {gap:.1} mm, box pair {} {}", c.box_a, c.box_b);
    let mut rng = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    };
    for (j, k, n) in [(0, c.box_a, u), (1, c.box_b, -u)] {
        let s_mm = r.robots[j].protective_mm;
        let sweeps = stop_sweeps_wcs(&cell.robots[j].model, exact.rotation(j), &tcps[j], s_mm, None);
        let b = boxes[j].as_slice()[k];
        let beyond = |directed: bool| {
            let box_reach = (0..3).map(|i| b.half[i] * n.dot(&b.axes.column(i)).abs()).sum::<Real>();
            reach(&b, &sweeps[0][k], &n, directed).min(reach(&b, &sweeps[1][k], &n, directed)) - box_reach
        };
        let across = |o: &Obb| (0..3).map(|i| o.half[i] * n.dot(&o.axes.column(i)).abs()).sum::<Real>();
        let reach_of = |o: &Obb| n.dot(&o.center) + across(o);
        let (mut sampled, mut out) = (0.0 as Real, delta_collide::robot::RobotBoxes::empty());
        for _ in 0..50_000 {
            let p = loop {
                let v = Vec3::new(uniform(), uniform(), uniform());
                if v.norm() <= 1.0 {
                    break tcps[j] + v * s_mm;
                }
            };
            if exact.boxes_in_wcs(j, &p, &mut out).is_ok() {
                sampled = sampled.max(reach_of(&out.as_slice()[k]) - reach_of(&b));
            }
        }
        println!(
            "  robot {j} box {k}, S {s_mm:.1} mm: beyond the box toward the other, today's sweep {:.1} mm, \
             directed {:.1} mm; the boxes over the ball {sampled:.1} mm",
            beyond(false),
            beyond(true)
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let (Some(run), Some(tick)) = (args.get(1), args.get(2)) {
        return one_tick(run, tick.parse().expect("a tick number"));
    }
    for s in parse_scenarios(SCENARIOS).unwrap() {
        let cell = reference_cell(&s.cell).unwrap().with_stopping(1.0, vec![StopModel::DEFAULT; 2]).unwrap();
        let mut checker = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let mut exact = ExactChecker::new(cell.clone());
        let mut tcps = [Vec3::zeros(); 2];
        let (mut stops, mut counts) = (0, [0; 3]);
        for t in 1..RUN_TICKS {
            s.tcps_at(t, &mut tcps);
            let r = checker.check(&tcps).unwrap();
            if r.verdict != Protective::Stop {
                continue;
            }
            let reach_mm = [r.robots[0].protective_mm, r.robots[1].protective_mm];
            stops += 1;
            exact.place_boxes(&tcps).unwrap();
            let sweeps: Vec<SweepForms> = (0..2)
                .map(|j| stop_sweeps_wcs(&cell.robots[j].model, exact.rotation(j), &tcps[j], reach_mm[j], None))
                .collect();
            for (count, (closest, directed)) in counts.iter_mut().zip([(false, false), (true, false), (true, true)]) {
                let all = exact.boxes(0).as_slice().iter().enumerate().all(|(k, a)| {
                    exact.boxes(1).as_slice().iter().enumerate().all(|(l, b)| {
                        let (fa, fb) = ([&sweeps[0][0][k], &sweeps[0][1][k]], [&sweeps[1][0][l], &sweeps[1][1][l]]);
                        proved(a, fa, b, fb, closest, directed)
                    })
                });
                *count += usize::from(all);
            }
        }
        println!(
            "{} {}: {stops} STOP ticks; proved by today's 15 axes {}, with the closest direction {}, \
             with directed supports on those 16 axes {}",
            s.cell, s.case, counts[0], counts[1], counts[2]
        );
    }
}
