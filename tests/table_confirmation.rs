//! Table mode with confirmation against exact mode on the thesis's scenarios (SPEC §5, §6):
//! on every tick of the practical and collision runs of T1, T2 and T3, a table whose
//! COLLISION lookups are confirmed by the exact check answers exactly as `ExactChecker`
//! (the oracle), and the confirmation counter equals the ticks the lookup said COLLISION.
//! The tables are certified 6-D tables at k = 16, built here (coarse, so that they raise
//! false alarms the confirmation has to clear).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{CellVerdict, ExactChecker};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_table, to_bytes, Confirmation, Labelling, TableAnswer, TableChecker, Variant,
};

/// The exact verdict in the table's terms.
fn exact_answer(v: &CellVerdict) -> TableAnswer {
    match (v.unreachable_mask, v.collides()) {
        (0, true) => TableAnswer::Collision,
        (0, false) => TableAnswer::Free,
        (m, _) => TableAnswer::Unreachable(m),
    }
}

#[test]
fn confirmed_table_mode_answers_as_exact_mode_on_every_scenario_tick() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let scenarios = parse_scenarios(&text).unwrap();
    let mut false_alarms_cleared = 0;
    for name in ["T1", "T2", "T3"] {
        let cell = reference_cell(name).unwrap();
        let (header, table, _) = build_table(
            &cell,
            16,
            &Workspace::THESIS,
            Variant::D6,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap();
        let bytes = to_bytes(&table, &header);
        for case in ["practical", "collision"] {
            let s = scenarios
                .iter()
                .find(|s| s.cell == name && s.case == case)
                .expect("scenario in the file");
            let mut exact = ExactChecker::new(cell.clone());
            let mut raw =
                TableChecker::with_confirmation(cell.clone(), &bytes, Confirmation::None).unwrap();
            let mut confirmed =
                TableChecker::with_confirmation(cell.clone(), &bytes, Confirmation::Exact).unwrap();
            assert_eq!(
                TableChecker::new(cell.clone(), &bytes).unwrap().confirmation(),
                Confirmation::None
            );
            let (mut lookup_hits, mut collisions, mut alarms) = (0u64, 0, 0);
            let mut tcps = [Vec3::zeros(); 2];
            for tick in 0..RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                let truth = exact_answer(exact.check(&tcps).unwrap());
                let fallbacks = raw.fallbacks();
                let label = raw.check(&tcps).unwrap();
                let answer = confirmed.check(&tcps).unwrap();
                assert_eq!(answer, truth, "{name} {case} tick {tick}: {tcps:?}");
                assert!(
                    label == truth || label == TableAnswer::Collision,
                    "{name} {case} tick {tick}: {label:?}"
                );
                lookup_hits +=
                    u64::from(label == TableAnswer::Collision && raw.fallbacks() == fallbacks);
                collisions += usize::from(truth == TableAnswer::Collision);
                alarms +=
                    usize::from(label == TableAnswer::Collision && truth == TableAnswer::Free);
            }
            println!(
                "{name} {case}: {collisions} collision ticks, {lookup_hits} COLLISION lookups confirmed, \
                 {alarms} false alarms cleared, {} fallbacks",
                confirmed.fallbacks()
            );
            assert_eq!(
                confirmed.confirmations(),
                lookup_hits,
                "{name} {case}: one confirmation per COLLISION lookup"
            );
            assert_eq!(
                (raw.confirmations(), confirmed.fallbacks()),
                (0, raw.fallbacks()),
                "{name} {case}"
            );
            assert_eq!(
                case == "collision",
                collisions > 0,
                "{name} {case}: the run collides only in the collision case"
            );
            false_alarms_cleared += alarms;
        }
    }
    assert!(
        false_alarms_cleared > 0,
        "the k = 16 tables raise false alarms on these runs, so the test can fail"
    );
}

#[test]
fn confirmation_can_be_switched_on_a_loaded_checker() {
    let cell = reference_cell("T1").unwrap();
    let bytes =
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/golden/t1_k16_6d.dct"))
            .unwrap();
    let mut checker = TableChecker::new(cell.clone(), &bytes).unwrap();
    let mut exact = ExactChecker::new(cell);
    // Robots reaching toward each other: apart, until the table's first false alarm.
    let mut alarm = None;
    for i in 0..200 {
        let d = 60.0 + i as f64;
        let tcps = [Vec3::new(d, 0.0, -450.0), Vec3::new(-d, 10.0, -450.0)];
        let truth = exact_answer(exact.check(&tcps).unwrap());
        if truth == TableAnswer::Free && checker.check(&tcps).unwrap() == TableAnswer::Collision {
            alarm = Some(tcps);
            break;
        }
    }
    let tcps = alarm.expect("a k = 16 table raises a false alarm on this line");
    checker.set_confirmation(Confirmation::Exact);
    assert_eq!((checker.check(&tcps).unwrap(), checker.confirmations()), (TableAnswer::Free, 1));
    checker.set_confirmation(Confirmation::None);
    assert_eq!(
        (checker.check(&tcps).unwrap(), checker.confirmations()),
        (TableAnswer::Collision, 1)
    );
    for (name, c) in Confirmation::ALL {
        assert_eq!((Confirmation::from_name(name), c.name()), (Some(c), name));
    }
    assert_eq!(Confirmation::from_name("Exact"), None, "names are lower case, as in cell files");
    assert_eq!(Confirmation::default(), Confirmation::Exact);
}
