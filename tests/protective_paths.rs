//! The protective verdict with controller-supplied stop paths (SPEC §8, "Where the controller
//! knows more") against brute force: whenever it proves a tick (FREE or WARN), every TCP the
//! promise and the stopping model allow (any point of the path within the stopping distance
//! along it, moved by up to the tolerance in any direction) is checked with the exact model,
//! for both robots in every combination; none may bring two boxes into contact. Also the
//! path's statuses, no allocation per tick, and the STOP counts on the scenarios with the
//! programmed path ahead as the stop path.

use delta_collide::cell::protective::{
    Protective, ProtectiveChecker, ProtectiveRequest, ProtectiveStatus, StopPath,
};
use delta_collide::cell::trajectory::{parse_scenarios, path_ahead, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

mod protective_common;
use protective_common::{cell, tcp_toward_other, unit, STIFF};

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

/// Every TCP robot `j` may reach under the promise: points of its path up to arc length `s`
/// (plus the reachable part of the start's neighbourhood), each moved by `tol` in a random
/// direction; only reachable ones.
fn reachable_samples(
    cell: &Cell,
    j: usize,
    path: &[Vec3],
    s: Real,
    tol: Real,
    n: usize,
    rng: &mut StdRng,
) -> Vec<Vec3> {
    let delta = &cell.robots[j].model.delta;
    let total: Real = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let reach = s.min(total);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // The far end, the start, and points between (the worst motion goes as far as it may).
        let arc = match i {
            0 => reach,
            1 => 0.0,
            _ => rng.random_range(0.0..=reach),
        };
        let offset = if i < 2 { Vec3::zeros() } else { unit(rng) * tol };
        let p = along(path, arc) + offset;
        if delta.is_reachable(&p) {
            out.push(p);
        }
    }
    out
}

/// Random ticks of two robots moving with paths; returns (ticks proved only thanks to the
/// paths, ticks checked).
fn brute_force(name: &str, stop: StopModel, ticks: usize, seed: u64) -> (usize, usize) {
    let cell = cell(name, stop);
    let mut c = ProtectiveChecker::new(cell.clone(), 5.0).unwrap().with_speed_limits(false);
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = StdRng::seed_from_u64(seed);
    let tick_s = cell.tick_ms * 1e-3;
    let (mut gained, mut checked) = (0, 0);
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
        checked += 1;
        gained += (without == Protective::Stop) as usize;
        let reach: Vec<Real> = r.robots.iter().map(|x| x.protective_mm).collect();
        let a = reachable_samples(&cell, 0, &paths[0], reach[0], tol, 24, &mut rng);
        let b = reachable_samples(&cell, 1, &paths[1], reach[1], tol, 24, &mut rng);
        for pa in &a {
            for pb in &b {
                let v = exact.check(&[*pa, *pb]).unwrap();
                assert!(
                    !v.collides(),
                    "tick {t}: {:?} with paths, but the stop can bring the boxes into contact at {pa:?} {pb:?}\n\
                     tcps {tcps:?} vel {vel:?} tol {tol} paths {paths:?}",
                    r.verdict
                );
            }
        }
    }
    (gained, checked)
}

#[test]
fn verdicts_proved_along_paths_survive_every_position_the_paths_allow() {
    for (name, stop, seed) in [("T1", STIFF, 1), ("T2", StopModel::DEFAULT, 2), ("T3", STIFF, 3)] {
        let (gained, checked) = brute_force(name, stop, 1_500, seed);
        println!(
            "{name}: {checked} ticks proved with paths, {gained} of them only thanks to the paths"
        );
        assert!(gained >= 50, "{name}: the paths should prove ticks the ball cannot ({gained})");
    }
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
            let lens: Vec<usize> = (0..tcps.len())
                .map(|j| path_ahead(&s.robots[j], tick, 400.0, &mut points[j]))
                .collect();
            let paths: Vec<Option<StopPath>> = (0..tcps.len())
                .map(|j| Some(StopPath { points: &points[j][..lens[j]], tolerance_mm: 0.1 }))
                .collect();
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
