//! The four-robot line's trajectory cases (`c_harness/line_scenarios.txt` on
//! `cells/line4.toml`; SPEC §5's two cases on a line): every waypoint is reachable, the
//! practical case never collides in the exact model and brings every neighbour pair close, the
//! collision case collides only late in the run and only between neighbours. The C harness
//! (`c_harness/line.c`) runs the same file and relies on these properties.
//!
//! The line's cases live in their own file because every scenario of `c_harness/scenarios.txt`
//! is run on a two-robot reference cell by other tests and benches.

use delta_collide::cell::exact::PairState;
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::{parse_cell, ExactChecker};
use delta_collide::geometry::boxes_clearance;
use delta_collide::math::Vec3;

const LINE_SCENARIOS: &str = include_str!("../c_harness/line_scenarios.txt");
const LINE_CELL: &str = include_str!("../cells/line4.toml");

/// Ticks before which the collision case must be free (SPEC §5: the last part of the run
/// collides), as the C harness's STOP_AFTER_TICK.
const COLLISION_AFTER_TICK: u32 = 3000;

/// What the exact model sees over one case's 6,000 ticks.
struct Run {
    /// Per pair that can meet (`(a, b)`): the smallest signed clearance (mm).
    min_clearance: Vec<((usize, usize), f64)>,
    /// The first colliding tick and the pairs colliding then.
    first_collision: Option<(u32, Vec<(usize, usize)>)>,
    /// Every pair that collides at some tick.
    colliding_pairs: Vec<(usize, usize)>,
}

fn scenario(case: &str) -> Scenario {
    let all = parse_scenarios(LINE_SCENARIOS).expect("c_harness/line_scenarios.txt parses");
    assert!(all.iter().all(|s| s.cell == "line4"), "only line4 cases in the line's file");
    all.into_iter().find(|s| s.case == case).unwrap_or_else(|| panic!("no line4 {case} case"))
}

fn run(case: &str) -> Run {
    let cell = parse_cell(LINE_CELL).expect("cells/line4.toml");
    let s = scenario(case);
    assert_eq!(s.robots.len(), cell.robots.len(), "{case}: one trajectory per robot of the line");
    let mut exact = ExactChecker::new(cell);
    let pairs: Vec<(usize, usize)> = exact.verdict().pairs.iter().map(|p| (p.a, p.b)).collect();
    let mut out = Run {
        min_clearance: pairs.iter().map(|&p| (p, f64::INFINITY)).collect(),
        first_collision: None,
        colliding_pairs: Vec::new(),
    };
    let mut tcps = vec![Vec3::zeros(); s.robots.len()];
    for tick in 0..RUN_TICKS {
        s.tcps_at(tick, &mut tcps);
        let v = exact.check(&tcps).unwrap().clone();
        // Every waypoint is the TCP at its tick, so this covers them all.
        assert!(
            v.all_reachable(),
            "{case} tick {tick}: unreachable TCP {:?} ({tcps:?})",
            v.first_unreachable
        );
        let now: Vec<(usize, usize)> = v
            .pairs
            .iter()
            .filter(|p| matches!(p.state, PairState::Collides(..)))
            .map(|p| (p.a, p.b))
            .collect();
        if !now.is_empty() && out.first_collision.is_none() {
            out.first_collision = Some((tick, now.clone()));
        }
        for p in now {
            if !out.colliding_pairs.contains(&p) {
                out.colliding_pairs.push(p);
            }
        }
        for ((a, b), min) in &mut out.min_clearance {
            let c =
                boxes_clearance(exact.boxes(*a).as_slice(), exact.boxes(*b).as_slice()).distance;
            *min = min.min(c);
        }
    }
    println!("line4 {case}: smallest clearance per pair {:?}", out.min_clearance);
    println!(
        "line4 {case}: first collision {:?}, colliding pairs {:?}",
        out.first_collision, out.colliding_pairs
    );
    out
}

#[test]
fn line_practical_case_never_collides_and_brings_every_neighbour_pair_close() {
    let r = run("practical");
    assert_eq!(r.first_collision, None, "the practical case collides");
    for &((a, b), min) in &r.min_clearance {
        if b == a + 1 {
            assert!(
                min > 10.0 && min < 100.0,
                "neighbours ({a}, {b}): smallest clearance {min:.1} mm, not 10-100 mm"
            );
        } else {
            assert!(min > 10.0, "pair ({a}, {b}): smallest clearance {min:.1} mm");
        }
    }
}

#[test]
fn line_collision_case_collides_late_and_between_neighbours_only() {
    let r = run("collision");
    let (first, pairs) = r.first_collision.expect("the collision case collides");
    assert!(
        first > COLLISION_AFTER_TICK,
        "first collision at tick {first}, in the first half of the run"
    );
    assert_eq!(pairs, vec![(2, 3)], "R3 and R4 collide first, alone");
    let mut all = r.colliding_pairs.clone();
    all.sort_unstable();
    assert_eq!(
        all,
        vec![(0, 1), (1, 2), (2, 3)],
        "every neighbour pair collides at some tick, no other pair"
    );
}
