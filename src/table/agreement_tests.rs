//! Every variant against the raw labels and against the 6-D table, on every sample of
//! several synthetic spaces ("the variants with t = 0 answer exactly as the
//! 6D table does on every sample").

use super::synthetic::{space, Pattern};
use super::*;
use crate::cspace::{Label, LabelledSpace, Symmetry};

fn variants(s: &LabelledSpace, symmetric: bool, t: u32) -> Vec<Table> {
    vec![
        Table::D6(LinearQuadtree6d::build(s, Symmetry::from_flag(symmetric)).unwrap()),
        Table::D5(LinearQuadtree5d::build(s, Symmetry::from_flag(symmetric)).unwrap()),
        Table::D4(
            LinearQuadtree4d::build(s, Symmetry::from_flag(symmetric), SliceAxes::YY, t).unwrap(),
        ),
        Table::D4(
            LinearQuadtree4d::build(s, Symmetry::from_flag(symmetric), SliceAxes::ZZ, t).unwrap(),
        ),
    ]
}

/// Per table: (free samples answered true, unreachable samples where it differs from 6-D).
fn check_all(s: &LabelledSpace, tables: &[Table], lossy: bool) -> Vec<(usize, usize)> {
    let nb = s.grid_b.cells.len();
    let mut out = vec![(0, 0); tables.len()];
    for (ia, a) in s.grid_a.cells.iter().enumerate() {
        for (ib, b) in s.grid_b.cells.iter().enumerate() {
            let cell = [a[0], a[1], a[2], b[0], b[1], b[2]];
            let label = s.labels[ia * nb + ib];
            let d6 = tables[0].query(cell);
            for (t, o) in tables.iter().zip(out.iter_mut()) {
                let got = t.query(cell);
                match label {
                    Label::Collision => {
                        assert!(got, "{}: collision {cell:?} reported free", t.name())
                    }
                    Label::Free if got => {
                        assert!(lossy, "{}: free {cell:?} reported collision", t.name());
                        o.0 += 1;
                    }
                    Label::Free => {}
                    Label::Unreachable => o.1 += usize::from(got != d6),
                }
            }
        }
    }
    out
}

fn patterns() -> Vec<(u32, Pattern)> {
    vec![
        (3, Pattern::Blobs),
        (4, Pattern::Blobs),
        (3, Pattern::Noise { p: 0.2, seed: 1 }),
        (4, Pattern::Noise { p: 0.05, seed: 2 }),
        (2, Pattern::Noise { p: 0.5, seed: 3 }),
        (3, Pattern::AllFree),
        (3, Pattern::AllCollision),
    ]
}

#[test]
fn exact_variants_answer_every_sample_as_the_labels() {
    for (levels, pattern) in patterns() {
        let s = space(levels, pattern);
        let unreachable = s.labels.iter().any(|l| l == Label::Unreachable);
        assert!(levels < 3 || unreachable, "the spaces must have unreachable pairs");
        for symmetric in [false, true] {
            let tables = variants(&s, symmetric, 0);
            let diffs = check_all(&s, &tables, false);
            eprintln!(
                "k = {} {pattern:?} symmetric {symmetric}: unreachable differing from 6D {diffs:?}",
                1 << levels
            );
        }
    }
}

#[test]
fn symmetric_tables_answer_as_full_tables_and_store_less() {
    let s = space(4, Pattern::Blobs);
    let full = variants(&s, false, 0);
    let half = variants(&s, true, 0);
    for (f, h) in full.iter().zip(&half) {
        assert!(
            h.memory_bytes() < f.memory_bytes(),
            "{}: {} not below {}",
            f.name(),
            h.memory_bytes(),
            f.memory_bytes()
        );
    }
    // Every sample of the full grid (reachable or not) agrees where the labels decide it.
    check_all(&s, &half, false);
}

#[test]
fn wrong_symmetry_flag_loses_no_collision() {
    let s = space(3, Pattern::AsymmetricNoise { p: 0.1, seed: 9 });
    assert!(symmetry_mismatches(&s).unwrap() > 0, "the space must really be asymmetric");
    assert_eq!(symmetry_mismatches(&space(3, Pattern::Blobs)).unwrap(), 0);
    check_all(&s, &variants(&s, true, 0), true);
}

#[test]
fn lossy_4d_never_loses_a_collision() {
    let s = space(4, Pattern::Blobs);
    let nfree = s.labels.count(Label::Free);
    let mut last_slices = usize::MAX;
    for t in [0, 5, 25, 150] {
        let yy = LinearQuadtree4d::build(&s, Symmetry::Whole, SliceAxes::YY, t).unwrap();
        let slices = yy.slice_count();
        let tables =
            [Table::D6(LinearQuadtree6d::build(&s, Symmetry::Whole).unwrap()), Table::D4(yy)];
        let fp = check_all(&s, &tables, t > 0)[1].0;
        eprintln!("k = 16 blobs 4D/yy t = {t}: {slices} slices, {fp} of {nfree} free samples answered collision");
        assert!(slices <= last_slices, "more slices at a larger t");
        last_slices = slices;
    }
}
