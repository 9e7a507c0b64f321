//! The protective verdict with controller-supplied stop paths (SPEC §8, "Where the controller
//! knows more") against brute force: whenever it proves a tick (FREE or WARN), stops that the
//! promise and the stopping model allow (the fastest, the slowest and random speed profiles
//! along each path, offset within the tolerance) are checked with the exact model every
//! 0.2 ms, the two robots at the same moments, every profile of one with every profile of the
//! other; none may bring two boxes into contact. Also the
//! path's statuses, no allocation per tick, and the STOP counts on the scenarios with the
//! programmed path ahead as the stop path.

use delta_collide::cell::protective::{
    Protective, ProtectiveChecker, ProtectiveRequest, ProtectiveStatus, StopPath,
};
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

mod protective_common;
use protective_common::{cell, programmed_paths, tcp_toward_other, unit, STIFF};

/// The point at arc length `s` of the polyline `points` (written here, not the library's).
fn along(points: &[Vec3], s: Real) -> Vec3 {
    let mut rest = s;
    for w in points.windows(2) {
        let len = (w[1] - w[0]).norm();
        if rest <= len {
            return w[0] + (w[1] - w[0]) * (rest / len.max(1e-300));
        }
        rest -= len;
    }
    *points.last().unwrap()
}

/// A random stop path from `tcp`: along `velocity` (or anywhere), with one or two corners,
/// each vertex moved by up to the tolerance; the TCP stays within the tolerance of it.
fn random_path(tcp: &Vec3, velocity: &Vec3, tol: Real, rng: &mut StdRng) -> Vec<Vec3> {
    let mut dir = if velocity.norm() > 0.0 && rng.random_range(0.0..1.0) < 0.7 {
        velocity.normalize()
    } else {
        unit(rng)
    };
    let mut points = vec![tcp + unit(rng) * rng.random_range(0.0..=tol)];
    for _ in 0..rng.random_range(1..=3) {
        let last = *points.last().unwrap();
        points.push(last + dir * rng.random_range(5.0..250.0));
        dir = (dir + unit(rng) * rng.random_range(0.0..1.5)).normalize();
    }
    points
}

/// Samples of a stop over time (s): every [`STEP_S`] until the robot stands.
const STEP_S: Real = 0.2e-3;

/// One stop of robot `j` that the promise and the model allow, as its TCP every [`STEP_S`]:
/// the TCP follows `path` (offset by up to `tol`) with a speed profile that starts within
/// `a_max dt` of the measured velocity `vel`, does anything within `a_max` and `v_max` for the
/// reaction (the verdict's latency of one tick included), then brakes at a deceleration
/// between `decel` and `a_max`. `kind` 0 is the fastest such stop, 1 the slowest, others
/// random. `None` when no speed along the path agrees with `vel`, or when the TCP would move
/// faster than the acceleration bound allows (a corner taken at speed): such a motion is
/// not one the model allows.
#[allow(clippy::too_many_arguments)]
fn stop_motion(
    stop: &StopModel,
    tick_s: Real,
    path: &[Vec3],
    tcp: &Vec3,
    vel: &Vec3,
    tol: Real,
    kind: usize,
    rng: &mut StdRng,
) -> Option<Vec<Vec3>> {
    let (a, vmax, dec) = (stop.max_accel_mm_s2, stop.max_speed_mm_s, stop.decel_mm_s2);
    let reaction = stop.reaction_ms * 1e-3 + tick_s;
    // The path's first direction and the speeds along it within `a dt` of the measured one.
    let first = path.windows(2).map(|w| w[1] - w[0]).find(|d| d.norm() > 1e-9)?;
    let u = first.normalize();
    let along = vel.dot(&u);
    let across = (vel - u * along).norm();
    let slack = a * tick_s;
    if across > slack {
        return None;
    }
    let half = (slack * slack - across * across).sqrt();
    let (v_lo, v_hi) = ((along - half).max(0.0), (along + half).min(vmax));
    if v_lo > v_hi {
        return None;
    }
    let mut v = match kind {
        0 => v_hi,
        1 => v_lo,
        _ => rng.random_range(v_lo..=v_hi),
    };
    let react_accel = match kind {
        0 => a,
        1 => -a,
        _ => rng.random_range(-a..=a),
    };
    let brake = match kind {
        0 => dec,
        1 => a,
        _ => rng.random_range(dec..=a),
    };
    // The start: the path's nearest point to the TCP, the offset kept for the whole stop.
    let (mut s, mut best) = (0.0, Real::INFINITY);
    let total: Real = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    for i in 0..=2000 {
        let x = total * i as Real / 2000.0;
        let d = (along_path(path, x) - tcp).norm();
        if d < best {
            (s, best) = (x, d);
        }
    }
    let offset = tcp - along_path(path, s);
    if offset.norm() > tol {
        return None;
    }
    let mut out = vec![*tcp];
    let mut t = 0.0;
    while v > 0.0 || t < reaction {
        let acc = if t < reaction { react_accel } else { -brake };
        let v_next = (v + acc * STEP_S).clamp(0.0, vmax);
        s += 0.5 * (v + v_next) * STEP_S;
        (v, t) = (v_next, t + STEP_S);
        let p = along_path(path, s) + offset;
        // A necessary condition of the acceleration bound (the velocity stays within
        // `a (dt + t)` of the measured one): a motion breaking it is not the model's.
        if (p - tcp - vel * t).norm() > a * (tick_s * t + 0.5 * t * t) + 1e-6 {
            return None;
        }
        out.push(p);
        if t > 1.0 {
            break;
        }
    }
    Some(out)
}

/// The point at arc length `s` of `path`, clamped (the test's own walk).
fn along_path(path: &[Vec3], s: Real) -> Vec3 {
    along(path, s.max(0.0))
}

/// What [`brute_force`] counted.
#[derive(Debug)]
struct Counts {
    /// Ticks proved (FREE or WARN) with paths, all checked.
    checked: usize,
    /// Of those, ticks that are STOP without paths.
    gained: usize,
    /// Of those, ticks proved only with the stops cut into time slices.
    sliced: usize,
}

/// Random ticks of two robots moving with paths. Each proved tick is checked against stops the
/// model allows, the two robots' positions taken at the same moments (the verdict pairs them
/// in time).
fn brute_force(name: &str, stop: StopModel, ticks: usize, seed: u64) -> Counts {
    let cell = cell(name, stop);
    let mut c = ProtectiveChecker::new(cell.clone(), 5.0).unwrap().with_speed_limits(false);
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = StdRng::seed_from_u64(seed);
    let tick_s = cell.tick_ms * 1e-3;
    let mut counts = Counts { checked: 0, gained: 0, sliced: 0 };
    for t in 0..ticks {
        let tcps = [tcp_toward_other(&cell, 0, &mut rng), tcp_toward_other(&cell, 1, &mut rng)];
        let vel: [Vec3; 2] = std::array::from_fn(|_| {
            unit(&mut rng) * rng.random_range(0.0..stop.max_speed_mm_s * 0.9)
        });
        let tol = rng.random_range(0.0..3.0);
        let paths: Vec<Vec<Vec3>> =
            (0..2).map(|j| random_path(&tcps[j], &vel[j], tol, &mut rng)).collect();
        c.reset();
        let prev = [tcps[0] - vel[0] * tick_s, tcps[1] - vel[1] * tick_s];
        if c.check(&prev).unwrap().status != ProtectiveStatus::Ok {
            continue;
        }
        let without = c.clone().check(&tcps).unwrap().verdict;
        let stop_paths: Vec<Option<StopPath>> =
            paths.iter().map(|p| Some(StopPath { points: p, tolerance_mm: tol })).collect();
        let r = c.check(ProtectiveRequest::new(&tcps).with_paths(&stop_paths)).unwrap().clone();
        assert_eq!(r.status, ProtectiveStatus::Ok, "tick {t}: {r:?}");
        assert!(r.verdict <= without, "tick {t}: a path made the verdict worse");
        if r.verdict == Protective::Stop {
            continue;
        }
        counts.checked += 1;
        counts.gained += (without == Protective::Stop) as usize;
        counts.sliced += usize::from(r.time_sliced);
        let motions: Vec<Vec<Vec<Vec3>>> = (0..2)
            .map(|j| {
                (0..10)
                    .filter_map(|kind| {
                        let m = stop_motion(
                            &stop, tick_s, &paths[j], &tcps[j], &vel[j], tol, kind, &mut rng,
                        );
                        m.filter(|m| m.iter().all(|p| cell.robots[j].model.delta.is_reachable(p)))
                    })
                    .collect()
            })
            .collect();
        for ma in &motions[0] {
            for mb in &motions[1] {
                for i in 0..ma.len().max(mb.len()) {
                    let (pa, pb) = (ma[i.min(ma.len() - 1)], mb[i.min(mb.len() - 1)]);
                    let v = exact.check(&[pa, pb]).unwrap();
                    assert!(
                        !v.collides(),
                        "tick {t}: {:?} with paths, but a stop brings the boxes into contact \
                         {:.2} ms in, at {pa:?} {pb:?}\n\
                         tcps {tcps:?} vel {vel:?} tol {tol} paths {paths:?}",
                        r.verdict,
                        i as Real * STEP_S * 1e3
                    );
                }
            }
        }
    }
    counts
}

#[test]
fn verdicts_proved_along_paths_survive_every_stop_the_paths_allow() {
    let mut sliced = 0;
    for (name, stop, seed) in [("T1", STIFF, 1), ("T2", StopModel::DEFAULT, 2), ("T3", STIFF, 3)] {
        let c = brute_force(name, stop, 1_500, seed);
        println!(
            "{name}: {} ticks proved with paths, {} of them only thanks to the paths, {} only \
             in time slices",
            c.checked, c.gained, c.sliced
        );
        assert!(c.gained >= 50, "{name}: the paths should prove ticks the ball cannot ({c:?})");
        sliced += c.sliced;
    }
    // The time slices are where the stops' positions are paired in time: they must be checked.
    assert!(sliced >= 10, "only {sliced} ticks proved in time slices were checked");
}

#[test]
fn a_broken_path_is_a_status_with_stop_and_the_history_is_forgotten() {
    let cell = cell("T1", StopModel::DEFAULT);
    let mut c = ProtectiveChecker::new(cell, 10.0).unwrap();
    let (a, b) = (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0));
    c.check(&[a, b]).unwrap();
    assert_eq!(c.check(&[a, b]).unwrap().verdict, Protective::Free);
    let far = [Vec3::new(-150.0, 40.0, -450.0), Vec3::new(-150.0, 80.0, -450.0)];
    for (path, why) in [(&far[..], "the TCP is 40 mm from the path"), (&[][..], "no point")] {
        let paths = [Some(StopPath { points: path, tolerance_mm: 1.0 }), None];
        let r = c.check(ProtectiveRequest::new(&[a, b]).with_paths(&paths)).unwrap();
        assert_eq!(
            (r.verdict, r.status),
            (Protective::Stop, ProtectiveStatus::InvalidPath(0)),
            "{why}"
        );
        // Forgotten: the next tick assumes full speed, so it is not the FREE of a still robot.
        assert_eq!(c.check(&[a, b]).unwrap().robots[0].speed_bound_mm_s, 4_600.0, "{why}");
        c.check(&[a, b]).unwrap();
    }
    let on = [a, a + Vec3::new(50.0, 0.0, 0.0)];
    let nan = [Some(StopPath { points: &on, tolerance_mm: Real::NAN }), None];
    assert_eq!(
        c.check(ProtectiveRequest::new(&[a, b]).with_paths(&nan)).unwrap().status,
        ProtectiveStatus::InvalidPath(0)
    );
    assert!(
        c.check(ProtectiveRequest::new(&[a, b]).with_paths(&[None])).is_err(),
        "one path per robot"
    );
}

/// The practical and collision scenarios with the programmed path ahead as each robot's stop
/// path: never more STOPs than without, and on the practical runs at least a tenth fewer.
#[test]
fn programmed_paths_ahead_bring_the_stops_of_the_scenarios_down() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    for (s, (stop, model)) in parse_scenarios(&text)
        .unwrap()
        .iter()
        .flat_map(|s| [(s, (StopModel::DEFAULT, "default")), (s, (STIFF, "stiff"))])
    {
        let cell = cell(&s.cell, stop);
        let mut with = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let mut without = with.clone();
        let mut tcps = vec![Vec3::zeros(); s.robots.len()];
        let mut points = vec![[Vec3::zeros(); 32]; s.robots.len()];
        let (mut stops_with, mut stops_without, mut warn_with) = (0, 0, 0);
        let started = std::time::Instant::now();
        for tick in 0..RUN_TICKS {
            s.tcps_at(tick, &mut tcps);
            let v0 = without.check(&tcps).unwrap().verdict;
            let paths = programmed_paths(s, tick, &mut points);
            let r = with.check(ProtectiveRequest::new(&tcps).with_paths(&paths)).unwrap();
            assert!(r.verdict <= v0, "{} {} tick {tick}: worse with paths", s.cell, s.case);
            stops_with += (r.verdict == Protective::Stop) as u32;
            warn_with += (r.verdict == Protective::Warn) as u32;
            stops_without += (v0 == Protective::Stop) as u32;
        }
        println!(
            "{model} {} {}: STOP {stops_without} without paths, {stops_with} with the programmed path ahead (WARN {warn_with}); \
             {:.1} us per tick for both",
            s.cell,
            s.case,
            started.elapsed().as_secs_f64() * 1e6 / RUN_TICKS as f64
        );
        if s.case == "practical" && model == "default" {
            assert!(
                stops_with * 10 <= stops_without * 9,
                "{} practical: {stops_with} of {stops_without}",
                s.cell
            );
        }
    }
}

/// The work budget along the paths (`ProtectiveChecker::with_path_work`) on the practical and
/// collision scenarios with the programmed path ahead, speed limits on: no tick spends more
/// units than its budget; a tick that did not run out answers as without a cap; one that ran
/// out is never better than without a cap nor worse than without paths; with no units at
/// all the answer is bit for bit the one without paths.
#[test]
fn a_work_budget_bounds_the_work_along_the_paths_and_only_loses_proofs() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let budgets = [0, 10, 60, u32::MAX];
    let mut ran_out = [0u32; 4];
    let mut most = [0u32; 4];
    for s in parse_scenarios(&text).unwrap().iter().filter(|s| s.cell != "T3") {
        let cell = cell(&s.cell, StopModel::DEFAULT);
        let mut plain = ProtectiveChecker::new(cell, 10.0).unwrap();
        let mut capped: Vec<_> = budgets.iter().map(|&b| plain.clone().with_path_work(b)).collect();
        let mut tcps = vec![Vec3::zeros(); s.robots.len()];
        let mut points = vec![[Vec3::zeros(); 32]; s.robots.len()];
        for tick in (0..RUN_TICKS).take(2_000) {
            s.tcps_at(tick, &mut tcps);
            let without = plain.check(&tcps).unwrap().clone();
            let paths = programmed_paths(s, tick, &mut points);
            let reports: Vec<_> = capped
                .iter_mut()
                .map(|c| c.check(ProtectiveRequest::new(&tcps).with_paths(&paths)).unwrap().clone())
                .collect();
            let full = &reports[3];
            let at = format!("{} {} tick {tick}", s.cell, s.case);
            for (k, r) in reports.iter().enumerate() {
                assert!(r.path_work <= budgets[k], "{at}: {} units of {}", r.path_work, budgets[k]);
                assert!(r.verdict <= without.verdict, "{at}: worse than without paths");
                assert!(r.verdict >= full.verdict, "{at}: better than without a cap");
                if !r.path_work_spent {
                    assert_eq!(r.verdict, full.verdict, "{at}: a budget not spent changed it");
                }
                ran_out[k] += u32::from(r.path_work_spent);
                most[k] = most[k].max(r.path_work);
            }
            let limits = |r: &delta_collide::cell::protective::ProtectiveReport| {
                r.robots.iter().map(|x| x.speed_limit_mm_s.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(reports[0].verdict, without.verdict, "{at}: no units, not as without");
            assert_eq!(limits(&reports[0]), limits(&without), "{at}: no units, other limits");
        }
    }
    println!("ticks that ran out per budget {budgets:?}: {ran_out:?}; most units spent {most:?}");
    // The caps bind where the proof along the paths needs more (else this tests nothing).
    assert!(ran_out[1] > 100 && ran_out[2] > 10, "{ran_out:?}");
    assert!(ran_out[3] == 0 && most[3] > budgets[2], "{most:?}");
}
