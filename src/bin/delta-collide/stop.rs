//! A simulated stop of the scenario robots, the stop `c_harness/protective.c` simulates:
//! from the STOP, each robot keeps its commanded motion for its reaction time, then brakes
//! along its own path at its configured deceleration until still, never past the path's next
//! waypoint (a path-maintaining stop). The exact model checks every 0.1 ms of it for contact.
//!
//! The scenario paths are straight segments with a minimum-jerk profile
//! ([`delta_collide::cell::trajectory`]), so braking is tracked as the fraction `s` of the
//! current segment and is exact along it (the C harness walks the path in small steps).

use crate::clearance::signed_clearance;
use delta_collide::cell::trajectory::{minimum_jerk, Scenario, Waypoint};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;

/// Steps of the contact check per millisecond.
const STEPS_PER_MS: u32 = 10;

/// The longest stop simulated (ms): far beyond any stopping model's, so a stop that has not
/// ended by then is reported as never ending rather than looping.
const MAX_STOP_MS: f64 = 10_000.0;

/// What a simulated stop found.
#[derive(Clone, Copy, Debug)]
pub struct StopOutcome {
    /// Time until every robot stood still (ms).
    pub stop_ms: f64,
    /// 0.1 ms samples checked with the exact model.
    pub samples: u32,
    /// Samples where two boxes touch or intersect, or a TCP is unreachable.
    pub contacts: u32,
    /// The smallest signed clearance over the samples (mm).
    pub closest_mm: f64,
}

/// The segment of `w` that holds fractional tick `t`: its end points and ticks.
fn segment(w: &[Waypoint], t: f64) -> Option<(&Waypoint, &Waypoint)> {
    let next = w.partition_point(|p| f64::from(p.tick) <= t);
    Some((w.get(next.checked_sub(1)?)?, w.get(next)?))
}

/// The commanded TCP at fractional tick `t` (the scenario's profile in continuous time).
pub fn path_at(w: &[Waypoint], t: f64) -> Vec3 {
    match segment(w, t) {
        Some((a, b)) => a.tcp + (b.tcp - a.tcp) * minimum_jerk(tau(a, b, t)),
        None if t < f64::from(w.first().map_or(0, |p| p.tick)) => {
            w.first().map_or(Vec3::zeros(), |p| p.tcp)
        }
        None => w.last().map_or(Vec3::zeros(), |p| p.tcp),
    }
}

fn tau(a: &Waypoint, b: &Waypoint, t: f64) -> f64 {
    (t - f64::from(a.tick)) / f64::from(b.tick - a.tick)
}

/// One robot during its stop.
#[derive(Clone, Copy)]
enum Phase<'a> {
    /// Keeping its commanded motion: where on its path (fractional tick).
    Reacting(f64),
    /// Braking along segment `a -> b` at fraction `s`, at `speed` (mm/s).
    Braking {
        a: &'a Waypoint,
        b: &'a Waypoint,
        s: f64,
        speed: f64,
    },
    Still(Vec3),
}

#[derive(Clone, Copy)]
struct Robot<'a> {
    path: &'a [Waypoint],
    stop: StopModel,
    phase: Phase<'a>,
}

impl<'a> Robot<'a> {
    fn tcp(&self) -> Vec3 {
        match self.phase {
            Phase::Reacting(t) => path_at(self.path, t),
            Phase::Braking { a, b, s, .. } => a.tcp + (b.tcp - a.tcp) * s,
            Phase::Still(p) => p,
        }
    }

    /// Advances the stop by `dt_ms`; `elapsed_ms` is the time since the STOP after the step.
    fn step(&mut self, dt_ms: f64, elapsed_ms: f64, tick_ms: f64) {
        self.phase = match self.phase {
            Phase::Reacting(t) if elapsed_ms <= self.stop.reaction_ms => {
                Phase::Reacting(t + dt_ms / tick_ms)
            }
            Phase::Reacting(t) => match segment(self.path, t) {
                // Braking starts at the commanded speed of that instant.
                Some((a, b)) => {
                    let u = tau(a, b, t);
                    let ds_dtick =
                        30.0 * u * u * (1.0 - u) * (1.0 - u) / f64::from(b.tick - a.tick);
                    let speed = (b.tcp - a.tcp).norm() * ds_dtick / (tick_ms * 1e-3);
                    let braking = Phase::Braking { a, b, s: minimum_jerk(u), speed };
                    Robot { phase: braking, ..*self }.braked(dt_ms)
                }
                None => Phase::Still(path_at(self.path, t)),
            },
            Phase::Braking { .. } => self.braked(dt_ms),
            Phase::Still(p) => Phase::Still(p),
        };
    }

    /// The braking phase `dt_ms` later: speed down by `decel dt`, never past the segment's end.
    fn braked(&self, dt_ms: f64) -> Phase<'a> {
        let Phase::Braking { a, b, s, speed } = self.phase else { return Phase::Still(self.tcp()) };
        let next = (speed - self.stop.decel_mm_s2 * dt_ms * 1e-3).max(0.0);
        let length = (b.tcp - a.tcp).norm();
        let s = if length > 0.0 { s + 0.5 * (speed + next) * dt_ms * 1e-3 / length } else { 1.0 };
        if next == 0.0 || s >= 1.0 {
            Phase::Still(a.tcp + (b.tcp - a.tcp) * s.min(1.0))
        } else {
            Phase::Braking { a, b, s, speed: next }
        }
    }
}

/// Simulates the stop issued at `stop_tick` of `scenario` on `cell` (its `tick_ms` and
/// stopping models), checking every 0.1 ms with the exact model until every robot is still.
///
/// # Errors
/// A scenario whose robot count differs from the cell's.
pub fn simulate_stop(
    cell: &Cell,
    scenario: &Scenario,
    stop_tick: u32,
) -> Result<StopOutcome, String> {
    let n = cell.robots.len();
    if scenario.robots.len() != n {
        return Err(format!(
            "scenario {} {} has {} robots, the cell {n}",
            scenario.cell,
            scenario.case,
            scenario.robots.len()
        ));
    }
    let mut robots: Vec<Robot> = scenario
        .robots
        .iter()
        .zip(&cell.stops)
        .map(|(path, stop)| Robot {
            path,
            stop: *stop,
            phase: Phase::Reacting(f64::from(stop_tick)),
        })
        .collect();
    let mut exact = ExactChecker::new(cell.clone());
    let mut tcps = vec![Vec3::zeros(); n];
    let mut out = StopOutcome { stop_ms: 0.0, samples: 0, contacts: 0, closest_mm: f64::INFINITY };
    let dt_ms = 1.0 / f64::from(STEPS_PER_MS);
    let mut step = 0u32;
    while robots.iter().any(|r| !matches!(r.phase, Phase::Still(_))) && out.stop_ms < MAX_STOP_MS {
        step += 1;
        let elapsed_ms = f64::from(step) * dt_ms;
        for (r, t) in robots.iter_mut().zip(tcps.iter_mut()) {
            r.step(dt_ms, elapsed_ms, cell.tick_ms);
            *t = r.tcp();
        }
        out.stop_ms = elapsed_ms;
        let v = exact.check(&tcps).map_err(|e| e.to_string())?;
        out.samples += 1;
        if v.collides() || !v.all_reachable() {
            out.contacts += 1;
        }
        if let Some(d) = signed_clearance(&exact) {
            out.closest_mm = out.closest_mm.min(d);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use delta_collide::cell::reference::reference_cell;
    use delta_collide::cell::trajectory::parse_scenarios;

    fn t1_collision() -> (Cell, Scenario) {
        let scenarios = parse_scenarios(crate::SCENARIOS).unwrap();
        let s = scenarios.into_iter().find(|s| s.cell == "T1" && s.case == "collision").unwrap();
        (reference_cell("T1").unwrap(), s)
    }

    /// A stop issued when the boxes already intersect is reported as touching: the check can fail.
    #[test]
    fn a_stop_issued_at_contact_touches() {
        let (cell, s) = t1_collision();
        let mut exact = ExactChecker::new(cell.clone());
        let mut tcps = vec![Vec3::zeros(); 2];
        let contact = (0..6000)
            .find(|&t| {
                s.tcps_at(t, &mut tcps);
                exact.check(&tcps).unwrap().collides()
            })
            .unwrap();
        let out = simulate_stop(&cell, &s, contact).unwrap();
        assert!(out.contacts > 0 && out.closest_mm <= 0.0, "{out:?}");
    }

    /// Mid-segment, the stop lasts the reaction plus about `v / decel`, one sample per 0.1 ms.
    #[test]
    fn a_stop_lasts_the_reaction_plus_the_braking() {
        let (cell, s) = t1_collision();
        let stop = cell.stops[0];
        // Mid-segment (A moves from tick 400 to 800), the speeds from the path at a fine step.
        let tick = 600;
        let speed = |w: &[Waypoint]| {
            (path_at(w, f64::from(tick) + 1e-3) - path_at(w, f64::from(tick))).norm() * 1e6
        };
        let vmax = s.robots.iter().map(|w| speed(w)).fold(0.0, f64::max);
        assert!(vmax > 100.0, "the robots move at tick {tick}: {vmax} mm/s");
        let out = simulate_stop(&cell, &s, tick).unwrap();
        let expected = stop.reaction_ms + vmax / stop.decel_mm_s2 * 1e3;
        assert!((out.stop_ms - expected).abs() <= 1.0, "{out:?}, expected {expected} ms");
        assert_eq!(out.samples, (out.stop_ms * 10.0).round() as u32);
    }
}
