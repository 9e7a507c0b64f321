//! The whole table path on a reference cell: certified labels, each quadtree variant, the
//! file bytes, loading for the cell, and per-tick lookups against the exact physical model
//! on random off-grid configurations (SPEC §6: no false negatives, ever).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_table, build_tables, to_bytes, Labelling, SliceAxes, TableAnswer, TableChecker, TableError, Variant,
};
use rand::{RngExt, SeedableRng};

fn random_tcp(rng: &mut rand::rngs::StdRng) -> Vec3 {
    // Uniform in a box around the workspace (some samples unreachable or outside the grid).
    Vec3::new(rng.random_range(-260.0..260.0), rng.random_range(-260.0..260.0), rng.random_range(-545.0..-350.0))
}

#[test]
fn every_variant_has_no_false_negative_on_random_configurations() {
    let cell = reference_cell("T2").unwrap();
    let mut exact = ExactChecker::new(cell.clone());
    let variants = [
        Variant::D6,
        Variant::D5,
        Variant::D4 { axes: SliceAxes::YY, t: 0 },
        Variant::D4 { axes: SliceAxes::ZZ, t: 0 },
        Variant::D4 { axes: SliceAxes::YY, t: 50 },
        Variant::Shared,
        Variant::SharedSubdivided,
    ];
    let (header, tables, _) =
        build_tables(&cell, 16, &Workspace::THESIS, &variants, Labelling::Certified, Progress::Silent).unwrap();
    let mut checkers: Vec<TableChecker> =
        tables.iter().map(|t| TableChecker::new(cell.clone(), &to_bytes(t, &header)).unwrap()).collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (mut hits, mut frees, mut sub_freed) = (0, 0, 0);
    for _ in 0..200_000 {
        let tcps = [random_tcp(&mut rng), random_tcp(&mut rng)];
        let v = exact.check(&tcps).unwrap();
        let (reachable, collides) = (v.all_reachable(), v.collides());
        let answers: Vec<TableAnswer> = checkers.iter_mut().map(|c| c.check(&tcps).unwrap()).collect();
        for (a, variant) in answers.iter().zip(&variants) {
            match a {
                TableAnswer::Unreachable(_) => assert!(!reachable, "{variant:?}: reachable reported unreachable"),
                TableAnswer::Free => assert!(reachable && !collides, "{variant:?}: false negative at {tcps:?}"),
                TableAnswer::Collision => assert!(reachable),
            }
        }
        // Lossless variants answer alike; sub-cells only turn collisions into free.
        assert!(answers[..4].windows(2).all(|w| w[0] == w[1]), "lossless variants disagree at {tcps:?}");
        assert_eq!(answers[5], answers[0], "the shared table disagrees with the 6-D table at {tcps:?}");
        assert!(answers[6] == answers[0] || answers[0] == TableAnswer::Collision, "sub-cells freed a free cell?");
        sub_freed += usize::from(answers[6] == TableAnswer::Free && answers[0] == TableAnswer::Collision);
        hits += collides as usize;
        frees += (answers[0] == TableAnswer::Free) as usize;
    }
    assert!(hits > 1000 && frees > 10_000, "the sample covers both sides ({hits} collisions, {frees} table-free)");
    assert!(checkers.iter().all(|c| c.fallbacks() > 0), "some TCPs fall outside the sampled grid");
    assert!(sub_freed > 100, "sub-cells prove some configurations of collision cells free ({sub_freed})");
}

#[test]
fn a_table_refuses_another_cell() {
    let t1 = reference_cell("T1").unwrap();
    let (header, table, report) =
        build_table(&t1, 16, &Workspace::THESIS, Variant::D6, Labelling::Certified, Progress::Silent).unwrap();
    assert!(report.symmetric, "T1 is mirror-symmetric (SPEC section 5)");
    let bytes = to_bytes(&table, &header);
    let err = TableChecker::new(reference_cell("T2").unwrap(), &bytes).unwrap_err();
    assert!(matches!(err, TableError::WrongCell { .. }), "{err}");
    assert!(err.to_string().contains("rebuild"), "{err}");
    assert!(TableChecker::new(t1, &bytes[..bytes.len() - 1]).is_err());
}
