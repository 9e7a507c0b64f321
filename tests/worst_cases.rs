//! Worst-case inputs of the per-tick entry points, found by search and kept as test data
//! (`tests/data/worst_cases/`, replayed under callgrind with a budget each by
//! `tests/instruction_budgets.rs`).
//!
//! The search is an adversary that maximises the instructions callgrind counts for one call
//! of an entry point, as `protective_adversary.rs` minimises the clearance of a stop. A
//! candidate is a short sequence of ticks 1 ms apart (the history a protective call reads its
//! speeds from, and a query's witness caches; then the measured call) from the numbers of
//! [`Genome`]: per robot its TCP at the measured tick, its velocity and a constant
//! acceleration (the TCPs of earlier ticks follow from them, so the finite differences stay
//! within the stopping model's speed and acceleration), and with stop paths its path's shape
//! (1-32 points, 0.1-4 mm tolerance, straight or turning, along the motion, toward the other
//! robot or anywhere). Every TCP is reachable, and the cell's exact clearance at the measured
//! tick lies in a window ([`Call::window`]).
//!
//! Generation 0 is random samples: each robot's TCP set by bisection on the clearance to a
//! robot before it, a quarter of the robots standing, the others mostly slow; for a
//! protective call one robot is then moved, by bisection on the verdict of the Rust checker
//! run natively, onto a place where the verdict changes (FREE to WARN, WARN to STOP), where
//! the proofs barely hold or barely fail and cost the most. Each later generation mutates the
//! most expensive candidates so far (a third of the mutants moved onto a verdict edge nearby)
//! and adds fresh samples (random restarts); every generation is counted in one callgrind run
//! of `tests/data/instruction_budgets.c`, one dump per candidate. The same seed and library
//! give the same files; a change of the library changes the counts, and so what is found.
//!
//! `cargo test --release --test worst_cases -- --ignored --nocapture` runs the search and
//! prints, per entry point, the hand-made approach's largest count (the approach of
//! `instruction_budgets.c`, where it measures that entry point), the largest among the random
//! samples alone and the searched worst; `DC_REGENERATE_WORST_CASES=1` writes the worst cases
//! into `tests/data/worst_cases/` (else into cargo's scratch directory);
//! `DC_WORST_CASES_GENERATIONS`, `DC_WORST_CASES_SEED` and `DC_WORST_CASES_ONLY` (names,
//! comma-separated) change the run. The test that is not ignored checks that the stored cases
//! are inputs a controller can give: reachable TCPs, motion within the stopping model, paths
//! within the C ABI's limits, the clearance in its window, every tick's status OK.

mod harness_build;
mod native_libs;

use delta_collide::cell::protective::{clearance_now, MAX_PATH_POINTS};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveRequest};
use delta_collide::cell::protective::{ProtectiveStatus, StopPath};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::geometry::clearance::boxes_clearance;
use delta_collide::math::{Real, Vec3};
use harness_build::{budget_program, in_ci, repo_root, run, scratch_dir, text};
use native_libs::NATIVE_LIBS;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

/// Which entry point a case file drives (its `call` line).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Call {
    /// `dc_query`, exact mode.
    Query,
    /// `dc_protective_query`, speed limits on.
    Protective,
    /// `dc_protective_query_with_paths`, speed limits on.
    Paths,
}

impl Call {
    fn word(self) -> &'static str {
        match self {
            Call::Query => "query",
            Call::Protective => "protective",
            Call::Paths => "paths",
        }
    }

    /// The window of the exact clearance at the measured tick (mm): for a query, near
    /// contact (-10 to 80 mm: colliding ticks count too), where bounding boxes overlap and box
    /// pairs need many axes; for a protective call, 0 to 400 mm, out to where a stop from
    /// full speed can still be proved (the proofs cost most where they barely hold: the
    /// hand-made approach's dearest ticks are at 100-110 mm, before its first STOP at 102 mm).
    fn window(self) -> (Real, Real) {
        match self {
            Call::Query => (-10.0, 80.0),
            _ => (0.0, 400.0),
        }
    }
}

/// One entry point and cell to search, and the part of the hand-made approach that measures
/// the same entry point on the same cell, if any.
struct Target {
    name: &'static str,
    cell: &'static str,
    call: Call,
    approach: Option<&'static str>,
    /// Candidates per generation (mutants, fresh samples), fewer where a call costs more.
    batch: (usize, usize),
}

const TARGETS: [Target; 6] = [
    Target {
        name: "query_t1",
        cell: "cells/t1.toml",
        call: Call::Query,
        approach: Some("dc_query"),
        batch: (48, 16),
    },
    Target {
        name: "query_line8",
        cell: "cells/line8.toml",
        call: Call::Query,
        approach: None,
        batch: (48, 16),
    },
    Target {
        name: "protective_t1",
        cell: "cells/t1.toml",
        call: Call::Protective,
        approach: Some("dc_protective_query"),
        batch: (36, 12),
    },
    Target {
        name: "protective_t2",
        cell: "cells/t2.toml",
        call: Call::Protective,
        approach: None,
        batch: (36, 12),
    },
    Target {
        name: "paths_t1",
        cell: "cells/t1.toml",
        call: Call::Paths,
        approach: Some("dc_protective_query_with_paths"),
        batch: (36, 12),
    },
    Target {
        name: "protective_line8",
        cell: "cells/line8.toml",
        call: Call::Protective,
        approach: None,
        batch: (18, 6),
    },
];

/// Cases kept per entry point: the most expensive ones of the search.
const KEPT: usize = 4;
/// Most ticks of a case (history and the measured one): up to three earlier ticks, so that
/// a protective call has a measured speed and a speed-limit search to go on from.
const MAX_TICKS: usize = 4;
/// Every speed and acceleration a case's finite differences show stays below this share of
/// the stopping model's limit (the checker's own slack is far smaller).
const PLAUSIBLE: Real = 0.99;

/// A stop path's shape: `n_points` points `spacing` apart from the TCP, the first step along
/// `dir`, each next one turned by `turn` rad about `axis`.
#[derive(Clone, Debug)]
struct PathGenes {
    n_points: usize,
    tolerance_mm: Real,
    spacing_mm: Real,
    dir: Vec3,
    turn: Real,
    axis: Vec3,
}

/// One robot's numbers: TCP at the measured tick (MCS), velocity and acceleration.
#[derive(Clone, Debug)]
struct RobotGenes {
    tcp: Vec3,
    velocity: Vec3,
    accel: Vec3,
    path: PathGenes,
}

/// A candidate: how many ticks, every robot's numbers.
#[derive(Clone, Debug)]
struct Genome {
    ticks: usize,
    robots: Vec<RobotGenes>,
}

/// A case as the C program reads it: per tick, every robot's TCP and (call `paths`) path.
#[derive(Clone, Debug, PartialEq)]
struct Case {
    tcps: Vec<Vec<Vec3>>,
    paths: Vec<Vec<(Vec<Vec3>, Real)>>,
}

impl Case {
    /// Tick `t`'s stop paths, one per robot (none for a call without paths).
    fn stop_paths(&self, t: usize) -> Vec<Option<StopPath<'_>>> {
        let at = self.paths.get(t).into_iter().flatten();
        at.map(|(points, tol)| Some(StopPath { points, tolerance_mm: *tol })).collect()
    }
}

impl Genome {
    /// The ticks of this genome, 1 ms apart, the last at the genome's TCPs.
    fn case(&self, call: Call, tick_s: Real) -> Case {
        let at = |r: &RobotGenes, i: usize| {
            let t = (i as Real - (self.ticks - 1) as Real) * tick_s;
            r.tcp + r.velocity * t + r.accel * (0.5 * t * t)
        };
        let tcps: Vec<Vec<Vec3>> =
            (0..self.ticks).map(|i| self.robots.iter().map(|r| at(r, i)).collect()).collect();
        let paths = if call == Call::Paths {
            tcps.iter()
                .map(|row| {
                    row.iter().zip(&self.robots).map(|(p, r)| path_points(p, &r.path)).collect()
                })
                .collect()
        } else {
            Vec::new()
        };
        Case { tcps, paths }
    }
}

/// The points of a path of shape `g` from `start`, and its tolerance.
fn path_points(start: &Vec3, g: &PathGenes) -> (Vec<Vec3>, Real) {
    let mut points = vec![*start];
    let mut dir = g.dir;
    let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(g.axis), g.turn);
    while points.len() < g.n_points {
        let next = points[points.len() - 1] + dir * g.spacing_mm;
        points.push(next);
        dir = rot * dir;
    }
    (points, g.tolerance_mm)
}

/// The text of `cases` as the C program reads it (numbers to 0.1 um), after `header`.
fn case_file(header: &str, cell: &str, call: Call, cases: &[Case]) -> String {
    let mut out = String::from(header);
    writeln!(out, "cell {cell}\ncall {}", call.word()).unwrap();
    let vec =
        |out: &mut String, v: &Vec3| write!(out, " {:.4} {:.4} {:.4}", v.x, v.y, v.z).unwrap();
    for (i, case) in cases.iter().enumerate() {
        writeln!(out, "case {i} ticks {}", case.tcps.len()).unwrap();
        for (t, row) in case.tcps.iter().enumerate() {
            out.push('t');
            row.iter().for_each(|p| vec(&mut out, p));
            out.push('\n');
            for (points, tol) in case.paths.get(t).into_iter().flatten() {
                write!(out, "p {} {tol:.4}", points.len()).unwrap();
                points.iter().for_each(|p| vec(&mut out, p));
                out.push('\n');
            }
        }
    }
    out
}

/// The words of a case file's text, comments (`#` to the end of the line) left out.
struct Words<'a>(std::vec::IntoIter<&'a str>);

impl<'a> Words<'a> {
    fn new(text: &'a str) -> Self {
        let words: Vec<&str> =
            text.lines().flat_map(|l| l.split('#').next().unwrap().split_whitespace()).collect();
        Words(words.into_iter())
    }

    fn word(&mut self) -> &'a str {
        self.0.next().expect("the case file ends early")
    }

    fn expect(&mut self, word: &str) {
        assert_eq!(self.word(), word, "case file: `{word}` expected");
    }

    fn num<T: std::str::FromStr>(&mut self) -> T {
        let w = self.word();
        w.parse().unwrap_or_else(|_| panic!("case file: `{w}` is not a number"))
    }

    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.num(), self.num(), self.num())
    }
}

/// The cell, call and cases of a case file's text; `robots` gives the cell's robot count.
fn parse_case_file(text: &str, robots: impl Fn(&str) -> usize) -> (String, Call, Vec<Case>) {
    let mut w = Words::new(text);
    w.expect("cell");
    let cell = w.word().to_string();
    w.expect("call");
    let call = match w.word() {
        "query" => Call::Query,
        "protective" => Call::Protective,
        "paths" => Call::Paths,
        other => panic!("unknown call {other}"),
    };
    let n = robots(&cell);
    let mut cases = Vec::new();
    while w.0.len() > 0 {
        w.expect("case");
        let _index: usize = w.num();
        w.expect("ticks");
        let ticks: usize = w.num();
        let mut case = Case { tcps: Vec::new(), paths: Vec::new() };
        for _ in 0..ticks {
            w.expect("t");
            case.tcps.push((0..n).map(|_| w.vec3()).collect());
            if call == Call::Paths {
                let row = (0..n)
                    .map(|_| {
                        w.expect("p");
                        let points: usize = w.num();
                        let tol: Real = w.num();
                        ((0..points).map(|_| w.vec3()).collect(), tol)
                    })
                    .collect();
                case.paths.push(row);
            }
        }
        cases.push(case);
    }
    (cell, call, cases)
}

/// A case rounded as its text holds it (0.1 um: `{:.4}` of the rounded number parses back
/// to the same number), so that what is checked here is what the C program reads.
fn rounded(case: &Case) -> Case {
    let r = |x: Real| (x * 1e4).round() / 1e4;
    let v = |p: &Vec3| Vec3::new(r(p.x), r(p.y), r(p.z));
    Case {
        tcps: case.tcps.iter().map(|row| row.iter().map(v).collect()).collect(),
        paths: case
            .paths
            .iter()
            .map(|row| {
                row.iter().map(|(pts, tol)| (pts.iter().map(v).collect(), r(*tol))).collect()
            })
            .collect(),
    }
}

/// Why `case` is not an input a controller can give the cell of `exact` with `call`, or the
/// cell's exact clearance at its measured tick (module doc).
fn check_case(exact: &mut ExactChecker, call: Call, case: &Case) -> Result<Real, String> {
    let cell = exact.cell().clone();
    let tick_s = cell.tick_ms * 1e-3;
    if case.tcps.is_empty() || case.tcps.len() > MAX_TICKS {
        return Err(format!("{} ticks", case.tcps.len()));
    }
    for (t, row) in case.tcps.iter().enumerate() {
        for (j, p) in row.iter().enumerate() {
            if !cell.robots[j].model.delta.is_reachable(p) {
                return Err(format!("tick {t}: robot {j}'s TCP {p:?} is unreachable"));
            }
        }
    }
    for j in 0..cell.robots.len() {
        let stop = cell.stops[j];
        let v: Vec<Vec3> = case.tcps.windows(2).map(|w| (w[1][j] - w[0][j]) / tick_s).collect();
        if let Some(v) = v.iter().find(|v| v.norm() > PLAUSIBLE * stop.max_speed_mm_s) {
            return Err(format!("robot {j} moves at {} mm/s", v.norm()));
        }
        let dv = v.windows(2).map(|w| (w[1] - w[0]).norm() / tick_s).fold(0.0, Real::max);
        if dv > PLAUSIBLE * stop.max_accel_mm_s2 {
            return Err(format!("robot {j} accelerates at {dv} mm/s^2"));
        }
    }
    if call == Call::Paths {
        for (t, row) in case.paths.iter().enumerate() {
            for (j, (points, tol)) in row.iter().enumerate() {
                let ok = (1..=MAX_PATH_POINTS).contains(&points.len())
                    && (0.1..=4.0).contains(tol)
                    && (points[0] - case.tcps[t][j]).norm() <= *tol;
                if !ok {
                    return Err(format!("tick {t}: robot {j}'s path is outside the limits"));
                }
            }
        }
    }
    exact.place_boxes(case.tcps.last().unwrap()).map_err(|e| e.to_string())?;
    let clearance = clearance_now(exact).0;
    let (lo, hi) = call.window();
    if !(lo..=hi).contains(&clearance) {
        return Err(format!("clearance {clearance} mm outside [{lo}, {hi}]"));
    }
    Ok(clearance)
}

/// A standard normal number (Box-Muller).
fn gauss(rng: &mut StdRng) -> Real {
    let u: Real = rng.random_range(Real::EPSILON..1.0);
    let v: Real = rng.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

fn unit(rng: &mut StdRng) -> Vec3 {
    loop {
        let v = Vec3::new(gauss(rng), gauss(rng), gauss(rng));
        if v.norm() > 1e-6 {
            return v.normalize();
        }
    }
}

/// The horizontal unit direction from robot `j`'s base to robot `k`'s, in `j`'s MCS.
fn toward(cell: &Cell, j: usize, k: usize) -> Vec3 {
    let d = cell.robots[k].placement.t - cell.robots[j].placement.t;
    let (s, c) = cell.robots[j].placement.alpha.sin_cos();
    Vec3::new(c * d.x + s * d.y, -s * d.x + c * d.y, 0.0).normalize()
}

/// The robot nearest to robot `j` (by base).
fn neighbour(cell: &Cell, j: usize) -> usize {
    let base = |k: usize| cell.robots[k].placement.t;
    (0..cell.robots.len())
        .filter(|&k| k != j)
        .min_by(|&a, &b| (base(a) - base(j)).norm().total_cmp(&(base(b) - base(j)).norm()))
        .unwrap()
}

/// Makes and mutates candidates for one target (module doc).
struct Sampler {
    exact: ExactChecker,
    /// The protective checker the C handle holds (the default warn_mm), run natively to
    /// find where a verdict changes.
    protective: Option<ProtectiveChecker>,
    call: Call,
    tick_s: Real,
}

impl Sampler {
    fn new(cell: Cell, call: Call) -> Self {
        let tick_s = cell.tick_ms * 1e-3;
        let protective =
            (call != Call::Query).then(|| ProtectiveChecker::new(cell.clone(), 10.0).unwrap());
        Sampler { exact: ExactChecker::new(cell), protective, call, tick_s }
    }

    /// The verdict of the measured tick of `case`, from a reset checker (as the C program
    /// replays it).
    fn verdict(&mut self, case: &Case) -> Protective {
        let checker = self.protective.as_mut().expect("a protective call");
        checker.reset();
        let mut verdict = Protective::Stop;
        for (t, tcps) in case.tcps.iter().enumerate() {
            let paths = case.stop_paths(t);
            verdict =
                checker.check(ProtectiveRequest::new(tcps).with_paths(&paths)).unwrap().verdict;
        }
        verdict
    }

    /// `g` with robot `j`'s whole motion shifted by `s` along `dir`, when valid.
    fn shifted(
        &mut self,
        g: &Genome,
        j: usize,
        dir: Vec3,
        s: Real,
    ) -> Option<(Genome, Case, Real)> {
        let mut m = g.clone();
        m.robots[j].tcp += dir * s;
        self.valid(&m).map(|(case, c)| (m, case, c))
    }

    /// `g` moved onto an edge of the protective verdict, where the proofs barely hold or
    /// barely fail and cost the most: robot `j` shifted along `dir` by bisection within
    /// `[-reach, reach]` between two shifts whose verdicts differ, ending on either side at
    /// random; `None` when both ends are invalid or give one verdict.
    fn snap_to_edge(
        &mut self,
        g: &Genome,
        j: usize,
        dir: Vec3,
        reach: Real,
        rng: &mut StdRng,
    ) -> Option<(Genome, Case, Real)> {
        let (mut a, mut b) = (-reach, reach);
        let end_a = self.shifted(g, j, dir, a)?;
        let end_b = self.shifted(g, j, dir, b)?;
        let (va, vb) = (self.verdict(&end_a.1), self.verdict(&end_b.1));
        if va == vb {
            return None;
        }
        let (mut best_a, mut best_b) = (end_a, end_b);
        for _ in 0..16 {
            let mid = 0.5 * (a + b);
            let m = self.shifted(g, j, dir, mid)?;
            if self.verdict(&m.1) == va {
                (a, best_a) = (mid, m);
            } else {
                (b, best_b) = (mid, m);
            }
        }
        Some(if rng.random_range(0..2) == 0 { best_a } else { best_b })
    }

    /// `found` snapped to a verdict edge along a random robot's direction toward its
    /// neighbour (or any direction, `any`), or `found` itself where there is none to find.
    fn on_edge(
        &mut self,
        found: (Genome, Case, Real),
        reach: Real,
        any: bool,
        rng: &mut StdRng,
    ) -> (Genome, Case, Real) {
        if self.call == Call::Query {
            return found;
        }
        let j = rng.random_range(0..found.0.robots.len());
        let dir = if any { unit(rng) } else { toward(self.cell(), j, neighbour(self.cell(), j)) };
        self.snap_to_edge(&found.0, j, dir, reach, rng).unwrap_or(found)
    }

    fn cell(&self) -> &Cell {
        self.exact.cell()
    }

    /// The case of `g` rounded as its text, with its clearance, when it is a valid input.
    fn valid(&mut self, g: &Genome) -> Option<(Case, Real)> {
        let case = rounded(&g.case(self.call, self.tick_s));
        check_case(&mut self.exact, self.call, &case).ok().map(|c| (case, c))
    }

    /// The smallest clearance between robot `j` at `tcps[j]` and the robots before it that it
    /// can meet (NaN when a TCP is unreachable).
    fn clearance_to_earlier(&mut self, tcps: &[Vec3], j: usize) -> Real {
        let verdict = self.exact.place_boxes(tcps).unwrap();
        if verdict.unreachable_mask & ((2u32 << j) - 1) != 0 {
            return Real::NAN;
        }
        let pairs: Vec<usize> =
            verdict.pairs.iter().filter(|p| p.b == j && p.a < j).map(|p| p.a).collect();
        let boxes = |k: usize| self.exact.boxes(k).as_slice();
        pairs
            .iter()
            .map(|&a| boxes_clearance(boxes(a), boxes(j)).distance)
            .fold(Real::INFINITY, Real::min)
    }

    /// TCPs near contact: robot 0 out toward robot 1, each later robot placed by bisection
    /// along the direction to the robot before it so that its clearance to the robots before
    /// it is a random one of the window; `None` when a bracket fails.
    fn fresh_tcps(&mut self, rng: &mut StdRng) -> Option<Vec<Vec3>> {
        let n = self.cell().robots.len();
        let (lo, hi) = self.call.window();
        let mut tcps = vec![Vec3::new(0.0, 0.0, -450.0); n];
        let spot = |d: Vec3, rng: &mut StdRng| {
            let side = Vec3::new(-d.y, d.x, 0.0);
            (side * rng.random_range(-140.0..140.0), Vec3::z() * rng.random_range(-530.0..-370.0))
        };
        let d0 = toward(self.cell(), 0, 1);
        let (side, depth) = spot(d0, rng);
        tcps[0] = d0 * rng.random_range(-60.0..230.0) + side + depth;
        if !self.cell().robots[0].model.delta.is_reachable(&tcps[0]) {
            return None;
        }
        for j in 1..n {
            // In a line, half the robots lean toward the next one instead, which then comes
            // near them.
            let ahead = j + 1 < n && rng.random_range(0..2) == 0;
            let d = toward(self.cell(), j, if ahead { j + 1 } else { j - 1 });
            let (side, depth) = spot(d, rng);
            let target = rng.random_range(lo..hi);
            let (mut far, mut near) = (-80.0, 260.0);
            let f = |s: Real, me: &mut Self, tcps: &mut Vec<Vec3>| {
                tcps[j] = d * s + side + depth;
                me.clearance_to_earlier(tcps, j)
            };
            if ahead || f(near, self, &mut tcps) >= target {
                // Robot j does not come that near the robots before it: anywhere along the
                // line apart from them.
                let c = f(rng.random_range(far..near), self, &mut tcps);
                if c.is_nan() || c < lo {
                    return None;
                }
                continue;
            }
            let c = f(far, self, &mut tcps);
            if c.is_nan() || c <= target {
                return None;
            }
            for _ in 0..40 {
                let mid = 0.5 * (far + near);
                let c = f(mid, self, &mut tcps);
                if c.is_nan() {
                    return None;
                }
                if c > target {
                    far = mid;
                } else {
                    near = mid;
                }
            }
            f(far, self, &mut tcps);
        }
        Some(tcps)
    }

    /// A random valid candidate (a random restart of the search).
    fn fresh(&mut self, rng: &mut StdRng) -> (Genome, Case, Real) {
        loop {
            let Some(tcps) = self.fresh_tcps(rng) else { continue };
            let robots = (0..tcps.len())
                .map(|j| {
                    let stop = self.cell().stops[j];
                    let other = toward(self.cell(), j, neighbour(self.cell(), j));
                    let dir = match rng.random_range(0..4) {
                        0 | 1 => (other + unit(rng) * 0.3).normalize(),
                        2 => unit(rng),
                        _ => -other,
                    };
                    // A quarter of the robots stand; the others mostly move slowly, where a
                    // stop ball is small enough for a proof to come near holding.
                    let u: Real = rng.random_range(0.0..1.0);
                    let speed = if rng.random_range(0..4) == 0 { 0.0 } else { u * u };
                    let velocity = dir * speed * 0.97 * stop.max_speed_mm_s;
                    let a = if speed == 0.0 || rng.random_range(0..2) == 0 { 0.0 } else { 0.97 };
                    let accel = unit(rng) * rng.random_range(0.0..1.0) * a * stop.max_accel_mm_s2;
                    let path_dir = match rng.random_range(0..4) {
                        0 | 1 if velocity.norm() > 1.0 => velocity.normalize(),
                        2 => other,
                        _ => unit(rng),
                    };
                    let path = PathGenes {
                        n_points: rng.random_range(1..=MAX_PATH_POINTS),
                        tolerance_mm: rng.random_range(0.1..4.0),
                        spacing_mm: rng.random_range(0.5..25.0),
                        dir: path_dir,
                        turn: rng.random_range(-0.5..0.5),
                        axis: unit(rng),
                    };
                    RobotGenes { tcp: tcps[j], velocity, accel, path }
                })
                .collect();
            let mut g = Genome { ticks: rng.random_range(1..=MAX_TICKS), robots };
            // Slower motions until the finite differences fit the stopping model.
            for _ in 0..8 {
                if let Some((case, c)) = self.valid(&g) {
                    return self.on_edge((g, case, c), 150.0, false, rng);
                }
                g.robots
                    .iter_mut()
                    .for_each(|r| (r.velocity, r.accel) = (r.velocity * 0.8, r.accel * 0.8));
            }
        }
    }

    /// A valid mutant of `g`, its steps `scale` times the largest (a fresh candidate when
    /// no mutant is valid).
    fn mutate(&mut self, g: &Genome, scale: Real, rng: &mut StdRng) -> (Genome, Case, Real) {
        for _ in 0..50 {
            let mut m = g.clone();
            if rng.random_range(0.0..1.0) < 0.15 {
                let t = m.ticks as i64 + if rng.random_range(0..2) == 0 { -1 } else { 1 };
                m.ticks = t.clamp(1, MAX_TICKS as i64) as usize;
            }
            let n = m.robots.len();
            let first = rng.random_range(0..n);
            for (j, r) in m.robots.iter_mut().enumerate() {
                if j != first && rng.random_range(0..2) == 0 {
                    continue;
                }
                let stop = self.exact.cell().stops[j];
                let mut coin = || rng.random_range(0..2) == 0;
                let (a, b, c, d) = (coin(), coin(), coin(), coin());
                if a {
                    r.tcp += unit(rng) * (gauss(rng) * 12.0 * scale);
                }
                if b {
                    r.velocity += unit(rng) * (gauss(rng) * 600.0 * scale);
                    r.velocity = clamp_norm(r.velocity, 0.97 * stop.max_speed_mm_s);
                }
                if c {
                    r.accel += unit(rng) * (gauss(rng) * 30_000.0 * scale);
                    r.accel = clamp_norm(r.accel, 0.97 * stop.max_accel_mm_s2);
                }
                if d && self.call == Call::Paths {
                    let p = &mut r.path;
                    let n_points = p.n_points as Real + (gauss(rng) * 4.0 * scale).round();
                    p.n_points = n_points.clamp(1.0, MAX_PATH_POINTS as Real) as usize;
                    p.tolerance_mm =
                        (p.tolerance_mm * (gauss(rng) * 0.4 * scale).exp()).clamp(0.1, 4.0);
                    p.spacing_mm =
                        (p.spacing_mm * (gauss(rng) * 0.4 * scale).exp()).clamp(0.3, 30.0);
                    p.dir = (p.dir + unit(rng) * (gauss(rng) * 0.5 * scale)).normalize();
                    p.turn = (p.turn + gauss(rng) * 0.2 * scale).clamp(-0.8, 0.8);
                    p.axis = (p.axis + unit(rng) * (gauss(rng) * 0.5 * scale)).normalize();
                }
            }
            if let Some((case, c)) = self.valid(&m) {
                if rng.random_range(0..3) == 0 {
                    return self.on_edge((m, case, c), 20.0 * scale.max(0.25), true, rng);
                }
                return (m, case, c);
            }
        }
        self.fresh(rng)
    }
}

/// `v` shortened to at most `max`.
fn clamp_norm(v: Vec3, max: Real) -> Vec3 {
    let n = v.norm();
    if n > max {
        v * (max / n)
    } else {
        v
    }
}

/// Runs `exe args` under callgrind, each measured call collected alone and dumped in `dir`:
/// its standard output and each part's count (the dump's trigger names the part).
fn callgrind(exe: &Path, args: &[&str], dir: &Path) -> (String, BTreeMap<String, u64>) {
    let dumps = |dir: &Path| {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("callgrind.out."))
            .collect::<Vec<_>>()
    };
    dumps(dir).iter().for_each(|p| std::fs::remove_file(p).unwrap());
    let out = run(Command::new("valgrind")
        .args(["--tool=callgrind", "--collect-atstart=no", "--dump-line=no"])
        .arg(format!("--callgrind-out-file={}/callgrind.out.%p", dir.display()))
        .arg(exe)
        .args(args));
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "the run failed:\n{stdout}{}", text(&out.stderr));
    let mut counts = BTreeMap::new();
    for path in dumps(dir) {
        let dump = std::fs::read_to_string(&path).unwrap();
        let trigger = dump.lines().find_map(|l| l.strip_prefix("desc: Trigger: Client Request: "));
        let count = dump.lines().find_map(|l| l.strip_prefix("summary: "));
        if let (Some(part), Some(count)) = (trigger, count) {
            let count: u64 = count.trim().parse().expect("a count");
            let e = counts.entry(part.trim().to_string()).or_insert(0);
            *e = count.max(*e);
        }
        std::fs::remove_file(path).unwrap();
    }
    (stdout, counts)
}

/// One evaluated candidate: its count, numbers, case and the C program's line on it.
#[derive(Clone)]
struct Found {
    count: u64,
    genome: Genome,
    case: Case,
    line: String,
}

/// What the search of one target found.
struct Search {
    /// The most expensive candidates, most first.
    best: Vec<Found>,
    /// The largest count among the random samples alone, and how many there were.
    fresh: (u64, usize),
    evaluations: usize,
}

/// Counts every candidate of `batch` in one callgrind run.
fn evaluate(
    target: &Target,
    batch: Vec<(Genome, Case, Real)>,
    exe: &Path,
    dir: &Path,
) -> Vec<Found> {
    let cases: Vec<Case> = batch.iter().map(|(_, c, _)| c.clone()).collect();
    let file = dir.join(format!("batch_{}.txt", target.name));
    std::fs::write(&file, case_file("", target.cell, target.call, &cases)).unwrap();
    let root = repo_root();
    let args =
        ["--root", root.to_str().unwrap(), "--replay", file.to_str().unwrap(), "cand", "default"];
    let (stdout, counts) = callgrind(exe, &args, dir);
    batch
        .into_iter()
        .enumerate()
        .map(|(i, (genome, case, _))| {
            let part = format!("cand#{i}");
            let count = *counts.get(&part).unwrap_or_else(|| panic!("no count of {part}"));
            let head = format!("part {part} ");
            let line = stdout.lines().find_map(|l| l.strip_prefix(&head)).unwrap_or("").to_string();
            Found { count, genome, case, line }
        })
        .collect()
}

/// Random restarts plus mutation of the most expensive candidates (module doc).
fn search(target: &Target, exe: &Path, dir: &Path, seed: u64, generations: usize) -> Search {
    const ELITES: usize = 6;
    let root = repo_root();
    let cell = Cell::from_file(&root.join(target.cell)).unwrap();
    let mut sampler = Sampler::new(cell, target.call);
    let mut rng = StdRng::seed_from_u64(seed);
    let (mutants, fresh) = target.batch;
    let first: Vec<_> = (0..mutants + fresh).map(|_| sampler.fresh(&mut rng)).collect();
    let mut pool = evaluate(target, first, exe, dir);
    let mut best_fresh = (pool.iter().map(|f| f.count).max().unwrap(), pool.len());
    let mut evaluations = pool.len();
    pool.sort_by_key(|f| std::cmp::Reverse(f.count));
    for g in 1..=generations {
        pool.dedup_by(|a, b| a.case == b.case);
        pool.truncate(ELITES.max(KEPT));
        let scale = 0.8_f64.powi(g as i32 - 1).max(0.1);
        let mut batch: Vec<_> = (0..mutants)
            .map(|_| {
                // The best parents more often: rank by the square of a uniform number.
                let u: Real = rng.random_range(0.0..1.0);
                let parent = &pool[((u * u * ELITES as Real) as usize).min(pool.len() - 1)];
                sampler.mutate(&parent.genome, scale, &mut rng)
            })
            .collect();
        batch.extend((0..fresh).map(|_| sampler.fresh(&mut rng)));
        let found = evaluate(target, batch, exe, dir);
        let fresh_best = found[mutants..].iter().map(|f| f.count).max().unwrap();
        best_fresh = (best_fresh.0.max(fresh_best), best_fresh.1 + fresh);
        evaluations += found.len();
        pool.extend(found);
        pool.sort_by_key(|f| std::cmp::Reverse(f.count));
        println!(
            "{}: generation {g}, largest {} instructions (random samples alone {})",
            target.name, pool[0].count, best_fresh.0
        );
    }
    // Cases of one count mostly take one path through the code: one of each.
    pool.dedup_by(|a, b| a.count == b.count);
    pool.truncate(KEPT);
    Search { best: pool, fresh: best_fresh, evaluations }
}

/// The header comment of a target's case file.
fn header(target: &Target, s: &Search, seed: u64, generations: usize) -> String {
    let entry = match target.call {
        Call::Query => "dc_query (exact mode)",
        Call::Protective => "dc_protective_query (speed limits on)",
        Call::Paths => "dc_protective_query_with_paths (speed limits on)",
    };
    let counts: Vec<String> = s.best.iter().map(|f| f.count.to_string()).collect();
    format!(
        "# Worst-case inputs of {entry}\n\
         # on {cell}: the {kept} cases with the most instructions (callgrind, the measured call\n\
         # alone) among {n} candidates of the search in tests/worst_cases.rs (seed {seed},\n\
         # {generations} generations), made by\n\
         #   DC_REGENERATE_WORST_CASES=1 cargo test --release --test worst_cases -- --ignored\n\
         # and replayed with a budget by tests/instruction_budgets.rs.\n\
         # Counts when found, case 0 first: {counts} instructions;\n\
         # the largest of the {nf} random samples alone: {f}.\n\
         # Format: `cell` (path from the repository root), `call` (query, protective, paths),\n\
         # then per case `case I ticks N` and N lines `t`: every robot's TCP (x y z, its MCS,\n\
         # mm), ticks 1 ms apart, the last one measured. For `paths` each `t` line is followed\n\
         # by one line `p` per robot: its stop path's point count, tolerance (mm) and points.\n",
        cell = target.cell,
        kept = s.best.len(),
        n = s.evaluations,
        counts = counts.join(" "),
        nf = s.fresh.1,
        f = s.fresh.0,
    )
}

fn valgrind_present() -> bool {
    if Command::new("valgrind").arg("--version").output().is_ok() {
        return true;
    }
    assert!(!in_ci(), "valgrind is not installed: .ci/run installs it");
    println!("SKIPPED: valgrind is not installed (outside CI; under CI=true this test fails)");
    false
}

#[test]
#[ignore = "the search itself: about 9 minutes under callgrind (module doc)"]
fn search_for_the_worst_inputs_of_each_entry_point() {
    if !valgrind_present() {
        return;
    }
    let env = |name: &str, default: u64| {
        std::env::var(name).ok().map_or(default, |v| v.parse().expect("a number"))
    };
    let seed = env("DC_WORST_CASES_SEED", 49);
    let generations = env("DC_WORST_CASES_GENERATIONS", 25) as usize;
    let dir = scratch_dir("worst_cases");
    let exe = budget_program(&dir, NATIVE_LIBS);
    let out_dir = if std::env::var_os("DC_REGENERATE_WORST_CASES").is_some() {
        repo_root().join("tests/data/worst_cases")
    } else {
        dir.join("found")
    };
    std::fs::create_dir_all(&out_dir).unwrap();
    let (_, approach) = callgrind(&exe, &["--approach"], &dir);
    let mut table = Vec::new();
    let only = std::env::var("DC_WORST_CASES_ONLY").ok();
    for (k, target) in TARGETS.iter().enumerate() {
        if only.as_deref().is_some_and(|o| !o.split(',').any(|n| n == target.name)) {
            continue;
        }
        let started = std::time::Instant::now();
        let s = search(target, &exe, &dir, seed + k as u64, generations);
        let cases: Vec<Case> = s.best.iter().map(|f| f.case.clone()).collect();
        let file = out_dir.join(format!("{}.txt", target.name));
        let text = header(target, &s, seed, generations);
        std::fs::write(&file, case_file(&text, target.cell, target.call, &cases)).unwrap();
        let hand = target.approach.map(|part| approach[part]);
        println!(
            "{}: {} evaluations in {:.0} s; worst {} instructions ({}), random samples alone {} \
             ({} of them), hand-made approach {}; written to {}",
            target.name,
            s.evaluations,
            started.elapsed().as_secs_f64(),
            s.best[0].count,
            s.best[0].line,
            s.fresh.0,
            s.fresh.1,
            hand.map_or("-".to_string(), |c| c.to_string()),
            file.display()
        );
        table.push((target.name, hand, s.fresh.0, s.best[0].count));
    }
    println!("\n| entry point | hand-made approach | best random sample | searched worst |");
    for (name, hand, fresh, worst) in &table {
        let hand = hand.map_or("-".to_string(), |c| c.to_string());
        println!("| {name} | {hand} | {fresh} | {worst} |");
    }
    // The search has teeth: where the approach measures the same call, it finds a dearer one.
    for (name, hand, _, worst) in table {
        if let Some(hand) = hand {
            assert!(worst > hand, "{name}: the search found {worst}, the approach {hand}");
        }
    }
}

#[test]
fn stored_worst_cases_are_inputs_a_controller_can_give() {
    let root = repo_root();
    for target in &TARGETS {
        let path = root.join("tests/data/worst_cases").join(format!("{}.txt", target.name));
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (the search writes it)", path.display()));
        let robots = |cell: &str| Cell::from_file(&root.join(cell)).unwrap().robots.len();
        let (cell_path, call, cases) = parse_case_file(&text, robots);
        assert_eq!((cell_path.as_str(), call), (target.cell, target.call), "{}", path.display());
        assert_eq!(cases.len(), KEPT, "{}", path.display());
        let cell = Cell::from_file(&root.join(&cell_path)).unwrap();
        let mut exact = ExactChecker::new(cell.clone());
        let mut checker =
            (call != Call::Query).then(|| ProtectiveChecker::new(cell, 10.0).unwrap());
        for (i, case) in cases.iter().enumerate() {
            let what = format!("{} case {i}", target.name);
            check_case(&mut exact, call, case).unwrap_or_else(|e| panic!("{what}: {e}"));
            let Some(checker) = checker.as_mut() else { continue };
            checker.reset();
            for (t, tcps) in case.tcps.iter().enumerate() {
                let paths = case.stop_paths(t);
                let request = ProtectiveRequest::new(tcps);
                let status = checker.check(request.with_paths(&paths)).unwrap().status;
                assert_eq!(status, ProtectiveStatus::Ok, "{what}, tick {t}");
            }
        }
    }
}
