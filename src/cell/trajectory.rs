//! Trajectories of the thesis's test cases (3.1.5; SPEC §5): waypoints per robot joined by
//! linear moves with a minimum-jerk profile, read from the scenario file that the C harness
//! reads too (`c_harness/scenarios.txt`).
//!
//! File format, one waypoint per line, `#` starts a comment:
//! `CELL CASE ROBOT TICK X Y Z`, e.g. `T1 practical 0 0 -150 0 -450`. A robot's TCP (mm, its
//! own MCS) moves from one waypoint to the next along a straight line with
//! `s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`, and holds the last waypoint afterwards.

use crate::math::{Real, Vec3};
use alloc::{format, string::String, vec::Vec};

/// Ticks of one run (6 s at 1 ms, SPEC §5).
pub const RUN_TICKS: u32 = 6000;

/// One waypoint: the TCP at a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Tick at which the TCP is here.
    pub tick: u32,
    /// TCP in the robot's MCS (mm).
    pub tcp: Vec3,
}

/// The minimum-jerk progress `s(tau)` for `tau` in [0, 1]: 0 to 1 with zero velocity and
/// acceleration at both ends.
pub fn minimum_jerk(tau: Real) -> Real {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// A robot's TCP at `tick` along `waypoints` (sorted by tick, at least one).
pub fn position_at(waypoints: &[Waypoint], tick: u32) -> Vec3 {
    let next = waypoints.partition_point(|w| w.tick <= tick);
    match (next.checked_sub(1).map(|i| &waypoints[i]), waypoints.get(next)) {
        (None, Some(first)) => first.tcp,
        (Some(last), None) => last.tcp,
        (Some(a), Some(b)) => {
            let s = minimum_jerk(Real::from(tick - a.tick) / Real::from(b.tick - a.tick));
            a.tcp + (b.tcp - a.tcp) * s
        }
        (None, None) => Vec3::zeros(),
    }
}

/// The programmed path ahead of `tick` along `waypoints` (sorted by tick, at least one), as a
/// controller performing a path-maintaining stop knows it: the TCP at `tick`, then the
/// following waypoints until `out` is full or the path from the TCP is at least `length_mm`
/// long (the last waypoint ends it: the robot holds there). Returns the number of points
/// written (at least 1 when `out` is not empty).
pub fn path_ahead(waypoints: &[Waypoint], tick: u32, length_mm: Real, out: &mut [Vec3]) -> usize {
    let Some(first) = out.first_mut() else { return 0 };
    *first = position_at(waypoints, tick);
    let (mut n, mut length) = (1, 0.0);
    for w in waypoints.iter().filter(|w| w.tick > tick) {
        if n == out.len() || length >= length_mm {
            break;
        }
        length += (w.tcp - out[n - 1]).norm();
        out[n] = w.tcp;
        n += 1;
    }
    n
}

/// One test case on one cell: a waypoint list per robot.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Reference cell name ("T1").
    pub cell: String,
    /// Case name ("practical", "collision").
    pub case: String,
    /// `robots[j]` is robot j's waypoint list, sorted by tick.
    pub robots: Vec<Vec<Waypoint>>,
}

impl Scenario {
    /// Every robot's TCP at `tick`, into `out` (one entry per robot).
    pub fn tcps_at(&self, tick: u32, out: &mut [Vec3]) {
        for (o, w) in out.iter_mut().zip(&self.robots) {
            *o = position_at(w, tick);
        }
    }
}

/// Parses a scenario file.
///
/// # Errors
/// A message with the line number for a malformed line, a robot with no waypoints or
/// waypoints out of tick order.
pub fn parse_scenarios(text: &str) -> Result<Vec<Scenario>, String> {
    let mut out: Vec<Scenario> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let bad = || {
            format!("scenario line {}: expected `CELL CASE ROBOT TICK X Y Z`, got `{line}`", n + 1)
        };
        if f.len() != 7 {
            return Err(bad());
        }
        let robot: usize = f[2].parse().map_err(|_| bad())?;
        let tick: u32 = f[3].parse().map_err(|_| bad())?;
        let xyz: Vec<Real> = f[4..]
            .iter()
            .map(|v| v.parse::<Real>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        if robot >= 32 || !xyz.iter().all(|v| v.is_finite()) {
            return Err(bad());
        }
        let idx = match out.iter().position(|s| s.cell == f[0] && s.case == f[1]) {
            Some(i) => i,
            None => {
                out.push(Scenario { cell: f[0].into(), case: f[1].into(), robots: Vec::new() });
                out.len() - 1
            }
        };
        let s = &mut out[idx];
        if s.robots.len() <= robot {
            s.robots.resize(robot + 1, Vec::new());
        }
        let path = &mut s.robots[robot];
        if path.last().is_some_and(|w| w.tick >= tick) {
            return Err(format!("scenario line {}: ticks of robot {robot} must increase", n + 1));
        }
        path.push(Waypoint { tick, tcp: Vec3::new(xyz[0], xyz[1], xyz[2]) });
    }
    if let Some(s) = out.iter().find(|s| s.robots.iter().any(|w| w.is_empty())) {
        return Err(format!("scenario {} {}: a robot has no waypoints", s.cell, s.case));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_jerk_profile_is_smooth_and_monotone() {
        assert_eq!((minimum_jerk(0.0), minimum_jerk(1.0)), (0.0, 1.0));
        assert!((minimum_jerk(0.5) - 0.5).abs() < 1e-15);
        let h = 1e-6;
        assert!(
            minimum_jerk(h) < 1e-15 && (1.0 - minimum_jerk(1.0 - h)) < 1e-15,
            "zero velocity at the ends"
        );
        assert!(
            (0..100).all(|i| minimum_jerk(i as f64 / 100.0) < minimum_jerk((i + 1) as f64 / 100.0))
        );
    }

    #[test]
    fn parse_and_interpolate() {
        let s = parse_scenarios(
            "# c\nT1 practical 0 0 0 0 -400\nT1 practical 0 100 100 0 -400 # x\nT1 practical 1 0 0 0 -450\n",
        )
        .unwrap();
        assert_eq!(s.len(), 1);
        let mut tcps = [Vec3::zeros(); 2];
        s[0].tcps_at(50, &mut tcps);
        assert_eq!(tcps, [Vec3::new(50.0, 0.0, -400.0), Vec3::new(0.0, 0.0, -450.0)]);
        s[0].tcps_at(5000, &mut tcps);
        assert_eq!(tcps[0], Vec3::new(100.0, 0.0, -400.0));
        assert!(parse_scenarios("T1 practical 0 10 0 0 -400\nT1 practical 0 5 0 0 -400\n").is_err());
        assert!(parse_scenarios("T1 practical 0 x 0 0 -400\n").unwrap_err().contains("line 1"));
    }
}
