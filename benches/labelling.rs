//! Labelling all k = 16 sample pairs of reference cell T1 (thesis 3.2.3):
//! ours (each robot's boxes built once per sample, x-sorted pruning, rayon) next to the naive
//! per-pair [`ExactChecker`] (IK and boxes of both robots for every pair, rayon too), and the
//! certified labelling (SPEC §6) for scale. Both exact labellings are checked to agree on
//! every pair before timing, and each timed run asserts its collision count.
//!
//! A second group labels all k = 32 pairs (the 10 s target).
//!
//! `cargo bench --bench labelling -- --warm-up-time 1 --measurement-time 5`

use criterion::{criterion_group, criterion_main, Criterion};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{
    label_space, label_space_certified, Label, Progress, SampleGrid, Workspace,
};
use rayon::prelude::*;
use std::hint::black_box;

const K: u32 = 16;

/// Labels of every pair from one exact check per pair.
fn naive_labels(cell: &Cell, ga: &SampleGrid, gb: &SampleGrid) -> Vec<Label> {
    let nb = gb.cells.len();
    let mut labels = vec![Label::Unreachable; ga.cells.len() * nb];
    labels.par_chunks_mut(nb).enumerate().for_each_init(
        || ExactChecker::new(cell.clone()),
        |checker, (ia, row)| {
            let pa = ga.sample_center(ia);
            for (ib, l) in row.iter_mut().enumerate() {
                let v = checker.check(&[pa, gb.sample_center(ib)]).unwrap();
                *l = if !v.all_reachable() {
                    Label::Unreachable
                } else if v.collides() {
                    Label::Collision
                } else {
                    Label::Free
                };
            }
        },
    );
    labels
}

fn collisions(labels: impl IntoIterator<Item = Label>) -> usize {
    labels.into_iter().filter(|&l| l == Label::Collision).count()
}

fn bench_labelling(c: &mut Criterion) {
    let cell = reference_cell("T1").unwrap();
    let ws = Workspace::THESIS;
    let ours = label_space(&cell, K, &ws, 0.0, Progress::Silent).unwrap();
    let naive = naive_labels(&cell, &ours.grid_a, &ours.grid_b);
    assert_eq!(ours.labels.len(), naive.len());
    let differ = ours.labels.iter().zip(naive.iter().copied()).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "product-structure labels differ from the per-pair exact check");
    let expected = collisions(naive.iter().copied());
    assert!(expected > 0);
    let certified = label_space_certified(&cell, K, &ws, Progress::Silent).unwrap();
    let certified_expected = collisions(certified.space.labels.iter());

    let mut group = c.benchmark_group(format!("label_T1_k{K}_{}_pairs", naive.len()));
    group.sample_size(10);
    group.bench_function("ours_product_pruned", |b| {
        b.iter(|| {
            let s = label_space(black_box(&cell), K, &ws, 0.0, Progress::Silent).unwrap();
            assert_eq!(collisions(s.labels.iter()), expected);
        })
    });
    group.bench_function("naive_exact_checker_per_pair", |b| {
        b.iter(|| {
            let l = naive_labels(black_box(&cell), &ours.grid_a, &ours.grid_b);
            assert_eq!(collisions(l), expected);
        })
    });
    group.bench_function("ours_certified_refined", |b| {
        b.iter(|| {
            let s = label_space_certified(black_box(&cell), K, &ws, Progress::Silent).unwrap();
            assert_eq!(collisions(s.space.labels.iter()), certified_expected);
        })
    });
    group.finish();
}

/// The target: all k = 32 pairs of T1 (about 39.5 million) labelled in under 10 s.
fn bench_labelling_k32(c: &mut Criterion) {
    let cell = reference_cell("T1").unwrap();
    let ws = Workspace::THESIS;
    let expected =
        collisions(label_space(&cell, 32, &ws, 0.0, Progress::Silent).unwrap().labels.iter());
    let mut group = c.benchmark_group("label_T1_k32_all_pairs");
    group.sample_size(10);
    group.bench_function("ours_product_pruned", |b| {
        b.iter(|| {
            let s = label_space(black_box(&cell), 32, &ws, 0.0, Progress::Silent).unwrap();
            assert_eq!(collisions(s.labels.iter()), expected);
        })
    });
    group.finish();
}

criterion_group!(benches, bench_labelling, bench_labelling_k32);
criterion_main!(benches);
