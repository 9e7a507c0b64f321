//! The whole table path on a reference cell: certified labels, each quadtree variant, the
//! file bytes, loading for the cell, and per-tick lookups against the exact physical model
//! on random off-grid configurations (SPEC §6: no false negatives, ever).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::ExactChecker;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_table, build_tables, to_bytes, Labelling, SliceAxes, TableAnswer, TableChecker,
    TableError, Variant,
};
use rand::{RngExt, SeedableRng};

fn random_tcp(rng: &mut rand::rngs::StdRng) -> Vec3 {
    // Uniform in a box around the workspace (some samples unreachable or outside the grid).
    Vec3::new(
        rng.random_range(-260.0..260.0),
        rng.random_range(-260.0..260.0),
        rng.random_range(-545.0..-350.0),
    )
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
    let (header, tables, _) = build_tables(
        &cell,
        16,
        &Workspace::THESIS,
        &variants,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    let mut checkers: Vec<TableChecker> = tables
        .iter()
        .map(|t| TableChecker::new(cell.clone(), &to_bytes(t, &header)).unwrap())
        .collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (mut hits, mut frees, mut sub_freed) = (0, 0, 0);
    for _ in 0..200_000 {
        let tcps = [random_tcp(&mut rng), random_tcp(&mut rng)];
        let v = exact.check(&tcps).unwrap();
        let (reachable, collides) = (v.all_reachable(), v.collides());
        let answers: Vec<TableAnswer> =
            checkers.iter_mut().map(|c| c.check(&tcps).unwrap()).collect();
        for (a, variant) in answers.iter().zip(&variants) {
            match a {
                TableAnswer::Unreachable(m) => {
                    assert_eq!(*m, v.unreachable_mask, "{variant:?} at {tcps:?}")
                }
                TableAnswer::Free => {
                    assert!(reachable && !collides, "{variant:?}: false negative at {tcps:?}")
                }
                TableAnswer::Collision => assert!(reachable),
            }
            assert_eq!(
                matches!(a, TableAnswer::Unreachable(_)),
                !reachable,
                "{variant:?} at {tcps:?}"
            );
        }
        // Lossless variants answer alike; sub-cells only turn collisions into free.
        assert!(
            answers[..4].windows(2).all(|w| w[0] == w[1]),
            "lossless variants disagree at {tcps:?}"
        );
        assert_eq!(
            answers[5], answers[0],
            "the shared table disagrees with the 6-D table at {tcps:?}"
        );
        assert!(
            answers[6] == answers[0] || answers[0] == TableAnswer::Collision,
            "sub-cells freed a free cell?"
        );
        sub_freed +=
            usize::from(answers[6] == TableAnswer::Free && answers[0] == TableAnswer::Collision);
        hits += collides as usize;
        frees += (answers[0] == TableAnswer::Free) as usize;
    }
    assert!(
        hits > 1000 && frees > 10_000,
        "the sample covers both sides ({hits} collisions, {frees} table-free)"
    );
    assert!(checkers.iter().all(|c| c.fallbacks() > 0), "some TCPs fall outside the sampled grid");
    assert!(
        sub_freed > 100,
        "sub-cells prove some configurations of collision cells free ({sub_freed})"
    );
}

#[test]
fn a_table_refuses_another_cell() {
    let t1 = reference_cell("T1").unwrap();
    let (header, table, report) = build_table(
        &t1,
        16,
        &Workspace::THESIS,
        Variant::D6,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    assert!(report.symmetric, "T1 is mirror-symmetric (SPEC section 5)");
    let bytes = to_bytes(&table, &header);
    let err = TableChecker::new(reference_cell("T2").unwrap(), &bytes).unwrap_err();
    assert!(matches!(err, TableError::WrongCell { .. }), "{err}");
    assert!(err.to_string().contains("rebuild"), "{err}");
    assert!(TableChecker::new(t1, &bytes[..bytes.len() - 1]).is_err());
}

/// A lookup skips the inverse kinematics for a TCP in a grid cell proved wholly reachable:
/// its reachability must still be exactly the inverse kinematics' own, hardest on the cells'
/// corners, edges and faces (a TCP on a face belongs to one cell by rounding) and at the reach
/// boundary (TCPs walked outward from the centre of the workspace until they fail).
#[test]
fn lookups_decide_reachability_as_the_inverse_kinematics_on_cell_faces_and_the_reach_boundary() {
    let t1 = reference_cell("T1").unwrap();
    let (header, table, _) = build_table(
        &t1,
        16,
        &Workspace::THESIS,
        Variant::Shared,
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    let checker = TableChecker::new(t1.clone(), &to_bytes(&table, &header)).unwrap();
    let delta = t1.robots[0].model.delta;
    let home = Vec3::new(0.0, 0.0, -450.0);
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut tried = [0usize; 2];
    let mut check = |p: Vec3| {
        let want = delta.is_reachable(&p);
        tried[usize::from(want)] += 1;
        assert_eq!(checker.unreachable_mask(&[p, home]) == 0, want, "robot A at {p:?}");
    };
    // The lattice of cell corners (and points an ulp either side) over the grid's cube.
    let (o, r) = (Vec3::from(header.origin_a), header.r);
    for i in 0..=16 {
        for j in 0..=16 {
            for l in 0..=16 {
                let p = o + Vec3::new(i as f64, j as f64, l as f64) * r;
                for q in [p, p.map(|v| v.next_up()), p.map(|v| v.next_down())] {
                    check(q);
                }
                // Points on the faces and edges through this corner.
                let f = rng.random_range(0.0..1.0) * r;
                check(p + Vec3::new(f, 0.0, 0.0));
                check(p + Vec3::new(0.0, f, f));
            }
        }
    }
    // The reach boundary: walk outward in random directions, in steps that shrink to an ulp.
    for _ in 0..2000 {
        let dir = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let (mut inside, mut step) = (home, 200.0);
        while step > 1e-9 {
            let next = inside + dir * step;
            if delta.is_reachable(&next) {
                inside = next;
            } else {
                step *= 0.5;
            }
            check(next);
        }
        check(inside);
    }
    println!("{} reachable and {} unreachable TCPs checked", tried[1], tried[0]);
    assert!(tried[0] > 10_000 && tried[1] > 10_000, "{tried:?}");
}
