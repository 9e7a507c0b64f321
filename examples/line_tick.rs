//! Profiling aid: replays T1 practical on a line of `n` thesis robots 450 mm apart, in exact
//! mode, in table mode (bundle of `cells/line4.toml`'s spacing) or through the protective
//! verdict (default stopping model, no speed limits), for `perf record`.
//! `cargo run --release --example line_tick -- exact|table|protective N SECONDS [K]`.

use delta_collide::cell::protective::ProtectiveChecker;
use delta_collide::cell::ExactChecker;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::{BundleChecker, Confirmation, Labelling, TableAnswer, Variant};
use std::hint::black_box;
use std::time::Instant;

#[path = "../benches/support/line_run.rs"]
mod line_run;
use line_run::{line, ticks};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("exact", String::as_str).to_string();
    let n: usize = args.get(2).map_or(8, |s| s.parse().unwrap());
    let secs: f64 = args.get(3).map_or(5.0, |s| s.parse().unwrap());
    let k: u32 = args.get(4).map_or(32, |s| s.parse().unwrap());
    let run = ticks(n);
    let cell = line(n);
    let mut exact = ExactChecker::new(cell.clone());
    let hits: Vec<bool> = run.iter().map(|t| exact.check(t).unwrap().collides()).collect();
    let mut table = (mode == "table").then(|| {
        let built = build_bundle(
            &line(4),
            k,
            &Workspace::THESIS,
            Variant::Shared,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap();
        BundleChecker::new(cell.clone(), &built.bytes, Confirmation::Exact).unwrap()
    });
    let mut protective = (mode == "protective")
        .then(|| ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false));
    // Ticks per protective verdict (FREE, WARN, STOP), over every pass.
    let mut verdicts = [0u64; 3];
    eprintln!("start");
    let start = Instant::now();
    let mut ticks = 0u64;
    while start.elapsed().as_secs_f64() < secs {
        for (t, hit) in run.iter().zip(&hits) {
            if let Some(p) = &mut protective {
                let v = p.check(black_box(t)).unwrap().verdict;
                verdicts[v as usize] += 1;
                continue;
            }
            let c = match &mut table {
                Some(table) => table.check(black_box(t)).unwrap() == TableAnswer::Collision,
                None => exact.check(black_box(t)).unwrap().collides(),
            };
            assert_eq!(c, *hit);
        }
        ticks += run.len() as u64;
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / ticks as f64;
    println!("{mode} n={n}: {ns:.0} ns per tick over {ticks} ticks");
    if protective.is_some() {
        println!("FREE, WARN, STOP ticks {verdicts:?}");
    }
    if let Some(t) = &table {
        println!("confirmations {} fallbacks {}", t.confirmations(), t.fallbacks());
    }
}
