//! The Rust loop the Python calls are measured against (`python/bench/speed.py`): the same
//! configurations (a file of little-endian f64, `N x robots x 3`), the same checker calls and
//! the same outputs as `check` and `clearance` of the package, timed around the loop alone.
//!
//! `cargo run --release --example rust_loop -- CELL FILE REPS` prints one line per repetition:
//! `check_s clearance_s collisions clearance_sum`.

use delta_collide::cell::exact::PairState;
use delta_collide::cell::protective::clearance_now;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, cell, file, reps] = &args[..] else {
        panic!("usage: rust_loop CELL FILE REPS");
    };
    let cell = reference_cell(cell).expect("a reference cell name");
    let robots = cell.robots.len();
    let bytes = std::fs::read(file).expect("the configurations file");
    let values: Vec<f64> =
        bytes.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes"))).collect();
    let n = values.len() / (3 * robots);
    let n_pairs = cell.pairs_that_can_meet().len();
    let mut checker = ExactChecker::new(cell);
    let (mut reachable, mut collide) = (vec![false; n], vec![false; n]);
    let mut pairs = vec![false; n * n_pairs];
    let mut clearance = vec![0.0; n];
    let mut tcps = vec![Vec3::zeros(); robots];
    let load = |i: usize, tcps: &mut [Vec3]| {
        for (j, t) in tcps.iter_mut().enumerate() {
            let k = 3 * (i * robots + j);
            *t = Vec3::new(values[k], values[k + 1], values[k + 2]);
        }
    };
    for _ in 0..reps.parse::<u32>().expect("REPS is a number") {
        let started = Instant::now();
        // As the package: every number checked finite first, then the loop.
        assert!(black_box(&values).iter().all(|v| v.is_finite()));
        for i in 0..n {
            load(i, &mut tcps);
            let v = checker.check(&tcps).expect("one TCP per robot");
            reachable[i] = v.all_reachable();
            collide[i] = reachable[i] && v.collides();
            for (k, p) in v.pairs.iter().enumerate() {
                pairs[i * n_pairs + k] = matches!(p.state, PairState::Collides(..));
            }
        }
        let check_s = started.elapsed().as_secs_f64();
        let started = Instant::now();
        assert!(black_box(&values).iter().all(|v| v.is_finite()));
        for (i, slot) in clearance.iter_mut().enumerate() {
            load(i, &mut tcps);
            let v = checker.place_boxes(&tcps).expect("one TCP per robot");
            *slot = if v.all_reachable() { clearance_now(&checker).0 } else { f64::NAN };
        }
        let clearance_s = started.elapsed().as_secs_f64();
        let collisions = black_box(&collide).iter().filter(|c| **c).count();
        let sum: f64 = black_box(&clearance).iter().filter(|c| c.is_finite()).sum();
        println!("{check_s} {clearance_s} {collisions} {sum}");
    }
}
