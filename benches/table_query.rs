//! Table query per variant (thesis Tables 3.6-3.7: 2 to 3 us; target < 100 ns median) on a
//! ring of 128 seeded cells of a synthetic k = 32 space, next to the plain label array
//! lookup; every call's answer is asserted inside the timed loop.
//!
//! Run: `cargo bench --bench table_query -- --warm-up-time 1 --measurement-time 2`.
//! The setup also prints build times and memory (ours and the thesis's formula) per variant.

use criterion::{criterion_group, criterion_main, Criterion};
use delta_collide::cspace::{Label, LabelledSpace, Symmetry};
use delta_collide::table::synthetic::{space, Pattern};
use delta_collide::table::*;
use std::hint::black_box;
use std::time::Instant;

#[allow(dead_code)]
#[path = "support/rng.rs"]
mod rng;
use rng::BenchRng;

const LEN: usize = 1 << 7;

/// 128 reachable samples, half collision and half free: (cell, expected answer).
fn ring(s: &LabelledSpace) -> Vec<([u16; 6], bool)> {
    let (na, nb) = (s.grid_a.cells.len(), s.grid_b.cells.len());
    let mut rng = BenchRng(2024);
    let mut out = Vec::new();
    while out.len() < LEN {
        let (ia, ib) = (rng.next_u64() as usize % na, rng.next_u64() as usize % nb);
        let want = out.len() % 2 == 0;
        let label = s.labels[ia * nb + ib];
        if label != Label::Unreachable && (label == Label::Collision) == want {
            let (a, b) = (s.grid_a.cells[ia], s.grid_b.cells[ib]);
            out.push(([a[0], a[1], a[2], b[0], b[1], b[2]], want));
        }
    }
    out
}

/// The peer: per-robot dense cell -> sample index maps, then the label array.
struct LabelArray<'a> {
    k: usize,
    index_a: Vec<u32>,
    index_b: Vec<u32>,
    space: &'a LabelledSpace,
}

impl<'a> LabelArray<'a> {
    fn new(space: &'a LabelledSpace) -> Self {
        let k = space.grid_a.k as usize;
        let dense = |cells: &[[u16; 3]]| {
            let mut m = vec![u32::MAX; k * k * k];
            cells.iter().enumerate().for_each(|(i, c)| {
                m[(c[0] as usize * k + c[1] as usize) * k + c[2] as usize] = i as u32
            });
            m
        };
        LabelArray {
            k,
            index_a: dense(&space.grid_a.cells),
            index_b: dense(&space.grid_b.cells),
            space,
        }
    }

    fn query(&self, c: [u16; 6]) -> bool {
        let k = self.k;
        let ia = self.index_a[(c[0] as usize * k + c[1] as usize) * k + c[2] as usize] as usize;
        let ib = self.index_b[(c[3] as usize * k + c[4] as usize) * k + c[5] as usize] as usize;
        self.space.labels[ia * self.space.grid_b.cells.len() + ib] == Label::Collision
    }
}

fn build(s: &LabelledSpace) -> Vec<Table> {
    let sym = symmetry_mismatches(s).unwrap() == 0;
    let b = s.grid_a.cells.iter().map(|c| c[1]).collect::<std::collections::BTreeSet<_>>().len();
    let collisions = s.labels.count(Label::Collision);
    eprintln!(
        "k = 32 synthetic blobs: {} samples per robot, {} pairs, {collisions} collisions, symmetric {sym}",
        s.grid_a.cells.len(),
        s.labels.len()
    );
    let mut out = Vec::new();
    let mut timed = |name: &str, f: &dyn Fn() -> Table| {
        let t0 = Instant::now();
        let t = f();
        let thesis = match &t {
            Table::D6(q) => q.thesis_bytes(),
            Table::D5(q) => q.thesis_bytes(),
            Table::D4(q) => q.thesis_bytes(b),
            Table::Shared(q) => q.memory_bytes(),
            Table::Clearance(q) => q.memory_bytes(),
        };
        let detail = match &t {
            Table::D6(q) => format!("{} codes ({} condensed)", q.codes().len(), q.condensed()),
            Table::D5(q) => format!("{} codes, {} intervals", q.parts().0.len(), q.parts().2.len()),
            Table::D4(q) => format!("{} codes, {} slices", q.parts().0.len(), q.slice_count()),
            Table::Shared(q) => format!("nodes per depth, leaves {:?}", q.nodes_per_depth()),
            Table::Clearance(q) => format!("level tree at k / {}", 1u32 << q.shift()),
        };
        eprintln!(
            "  {name:<22} build {:>7.3} s  {detail:<32} ours {:>10} B  thesis formula {:>10} B",
            t0.elapsed().as_secs_f64(),
            t.memory_bytes(),
            thesis
        );
        out.push(t);
    };
    for symmetric in [false, sym] {
        let tag = if symmetric { " sym" } else { "" };
        timed(&format!("6D{tag}"), &|| {
            Table::D6(LinearQuadtree6d::build(s, Symmetry::from_flag(symmetric)).unwrap())
        });
        timed(&format!("5D{tag}"), &|| {
            Table::D5(LinearQuadtree5d::build(s, Symmetry::from_flag(symmetric)).unwrap())
        });
        for (axes, t) in [(SliceAxes::YY, 0), (SliceAxes::YY, 150), (SliceAxes::ZZ, 0)] {
            timed(&format!("4D/{axes:?} t={t}{tag}"), &|| {
                Table::D4(
                    LinearQuadtree4d::build(s, Symmetry::from_flag(symmetric), axes, t).unwrap(),
                )
            });
        }
        timed(&format!("6D-shared{tag}"), &|| {
            Table::Shared(SharedQuadtree6d::build(s, Symmetry::from_flag(symmetric)).unwrap())
        });
        if !sym {
            break;
        }
    }
    out
}

/// Per-query latency percentiles, each query timed alone with `Instant` (its own overhead,
/// measured on an empty body, is printed beside): criterion gives means and medians of
/// batches, not the tail the controller cares about.
fn tail(name: &str, cases: &[([u16; 6], bool)], q: &dyn Fn([u16; 6]) -> bool) {
    const N: usize = 1 << 20;
    let mut ns = Vec::with_capacity(N);
    let mut empty = Vec::with_capacity(N);
    for i in 0..N {
        let (cell, want) = cases[i % LEN];
        let t0 = Instant::now();
        let got = q(black_box(cell));
        ns.push(t0.elapsed().as_nanos() as u64);
        assert!(got == want || got, "{name}: lost a collision at {cell:?}");
        let t0 = Instant::now();
        black_box(cell);
        empty.push(t0.elapsed().as_nanos() as u64);
    }
    ns.sort_unstable();
    empty.sort_unstable();
    let p = |v: &[u64], f: f64| v[((v.len() - 1) as f64 * f) as usize];
    eprintln!(
        "  {name:<26} single-query ns: median {:>4} p99.9 {:>5} max {:>7}   (timer alone: median {} p99.9 {})",
        p(&ns, 0.5),
        p(&ns, 0.999),
        ns[N - 1],
        p(&empty, 0.5),
        p(&empty, 0.999)
    );
}

fn bench_query(c: &mut Criterion) {
    let s = space(5, Pattern::Blobs);
    let tables = build(&s);
    let cases = ring(&s);
    let peer0 = LabelArray::new(&s);
    tail("label_array (peer)", &cases, &|c| peer0.query(c));
    for t in &tables {
        tail(&format!("{}{}", t.name(), if t.symmetric() { " sym" } else { "" }), &cases, &|c| {
            t.query(c)
        });
    }
    let peer = LabelArray::new(&s);
    let mut g = c.benchmark_group("table_query_k32");
    let mut i = 0usize;
    g.bench_function("label_array (peer)", |b| {
        b.iter(|| {
            let (cell, want) = cases[i % LEN];
            i = i.wrapping_add(1);
            assert_eq!(peer.query(black_box(cell)), want);
        })
    });
    for t in &tables {
        let exact = !matches!(t, Table::D4(q) if q.threshold() > 0);
        let name = format!("{}{}", t.name(), if t.symmetric() { " sym" } else { "" });
        g.bench_function(&name, |b| {
            b.iter(|| {
                let (cell, want) = cases[i % LEN];
                i = i.wrapping_add(1);
                let got = t.query(black_box(cell));
                // Lossy 4-D tables may answer collision for a free sample, never the reverse.
                assert!(got == want || (!exact && got), "{name}: {cell:?}");
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_query);
criterion_main!(benches);
