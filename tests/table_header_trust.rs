//! A table's header is not trusted where the cell decides: fields edited with the checksum
//! recomputed (as a hand-fixed file, another builder or a deliberate edit would) are refused,
//! and a table refused for another cell names the parameter that differs.
//!
//! The edits are made at the byte offsets of the layout documented in `src/table/format.rs`.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::format::{fnv1a64, from_bytes};
use delta_collide::table::{
    build_tables, to_bytes, Labelling, SliceAxes, TableAnswer, TableChecker, TableError, Variant,
};
use std::sync::OnceLock;

const FLAGS: usize = 28;
const RCY: usize = 104 + 2 * 8;

const VARIANTS: [Variant; 6] = [
    Variant::D6,
    Variant::D5,
    Variant::D4 { axes: SliceAxes::YY, t: 0 },
    Variant::D4 { axes: SliceAxes::ZZ, t: 0 },
    Variant::Shared,
    Variant::SharedSubdivided,
];

/// Every variant's file for the reference cell `cell` (T1 or T3) at k = 16, built once.
fn files(cell: &Cell) -> Vec<(Variant, Vec<u8>)> {
    type Files = Vec<(Variant, Vec<u8>)>;
    static T1: OnceLock<Files> = OnceLock::new();
    static T3: OnceLock<Files> = OnceLock::new();
    let build = || {
        let (header, tables, _) = build_tables(
            cell,
            16,
            &Workspace::THESIS,
            &VARIANTS,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap();
        VARIANTS.iter().copied().zip(tables.iter().map(|t| to_bytes(t, &header))).collect()
    };
    match cell.name.as_str() {
        "T1" => T1.get_or_init(build).clone(),
        "T3" => T3.get_or_init(build).clone(),
        other => panic!("no files for {other}"),
    }
}

/// `bytes` with `edit` applied and the checksum recomputed.
fn resealed(bytes: &[u8], edit: impl Fn(&mut [u8])) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let body = b.len() - 8;
    edit(&mut b[..body]);
    let sum = fnv1a64(&b[..body]);
    b[body..].copy_from_slice(&sum.to_le_bytes());
    b
}

#[test]
fn a_cleared_symmetric_flag_is_refused_for_a_symmetric_cell() {
    let t1 = reference_cell("T1").unwrap();
    for (variant, bytes) in files(&t1) {
        assert!(
            TableChecker::new(t1.clone(), &bytes).is_ok(),
            "{variant:?}: the built table loads"
        );
        let edited = resealed(&bytes, |b| b[FLAGS] &= !1);
        // A 4D/yy' table's slices change length with the flag; others load and would answer.
        let err = TableChecker::new(t1.clone(), &edited).map(|_| ()).unwrap_err();
        if !matches!(variant, Variant::D4 { axes: SliceAxes::YY, .. }) {
            assert!(matches!(err, TableError::WrongCell { .. }), "{variant:?}: {err}");
            assert!(err.to_string().contains("mirror-symmetric"), "{variant:?}: {err}");
        }
    }
}

#[test]
fn a_set_symmetric_flag_on_an_asymmetric_table_is_refused() {
    let t3 = reference_cell("T3").unwrap();
    for (variant, bytes) in files(&t3) {
        let edited = resealed(&bytes, |b| b[FLAGS] |= 1);
        let loaded = from_bytes(&edited);
        if let Err(e) = &loaded {
            // The codes in the half a symmetric table does not store give it away.
            assert!(matches!(e, TableError::Corrupt { .. }), "{variant:?}: {e}");
        }
        assert!(
            TableChecker::new(t3.clone(), &edited).is_err(),
            "{variant:?}: loaded as symmetric"
        );
    }
    // At least the 6-D file is refused as corrupt by itself, before any cell is known.
    let six = &files(&t3)[0].1;
    let err = from_bytes(&resealed(six, |b| b[FLAGS] |= 1)).unwrap_err();
    assert!(err.to_string().contains("does not store"), "{err}");
}

#[test]
fn an_edited_workspace_is_refused_naming_the_field() {
    let t1 = reference_cell("T1").unwrap();
    for (variant, bytes) in files(&t1) {
        let edited = resealed(&bytes, |b| b[RCY..RCY + 8].copy_from_slice(&231.0f64.to_le_bytes()));
        match TableChecker::new(t1.clone(), &edited) {
            Ok(_) => panic!("{variant:?}: a table with Rcy = 231 mm was accepted"),
            Err(e) => assert!(e.to_string().contains("workspace.rcy"), "{variant:?}: {e}"),
        }
    }
}

#[test]
fn negative_zero_is_the_same_cell() {
    let t1 = reference_cell("T1").unwrap();
    let mut minus = t1.clone();
    minus.robots[1].placement.t.y = -0.0;
    minus.robots[0].placement.t = Vec3::new(-0.0, -0.0, -0.0);
    assert_eq!(minus.fingerprint(), t1.fingerprint());
    let (_, bytes) = &files(&t1)[0];
    let mut checker = TableChecker::new(minus.clone(), bytes).expect("-0.0 and 0.0 are one cell");
    let tcps = [Vec3::new(180.0, 0.0, -450.0), Vec3::new(-180.0, 0.0, -450.0)];
    assert_eq!(checker.check(&tcps).unwrap(), TableAnswer::Collision);
    assert!(ExactChecker::new(minus).check(&tcps).unwrap().collides());
}

#[test]
fn another_cell_is_refused_naming_the_parameter_that_differs() {
    let t1 = reference_cell("T1").unwrap();
    let (_, bytes) = &files(&t1)[0];
    let err = TableChecker::new(reference_cell("T2").unwrap(), bytes).map(|_| ()).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, TableError::WrongCell { .. }), "{text}");
    assert!(text.contains("robot 1: placement.translation.x is 450"), "{text}");
    assert!(text.contains("400"), "{text}");
    let mut margin = t1.clone();
    margin.robots[0].model.options.margin = 2.5;
    let text = TableChecker::new(margin, bytes).map(|_| ()).unwrap_err().to_string();
    assert!(
        text.contains("robot 0: model.margin is 0 in the table's cell and 2.5 in this one"),
        "{text}"
    );
}

#[test]
fn stored_parameters_that_do_not_give_the_fingerprint_are_corrupt() {
    let t1 = reference_cell("T1").unwrap();
    let (_, bytes) = &files(&t1)[0];
    // The first stored parameter (the robot count, at offset 192) changed from 2 to 3.
    let edited = resealed(bytes, |b| b[192..200].copy_from_slice(&3.0f64.to_le_bytes()));
    let err = from_bytes(&edited).unwrap_err();
    assert!(
        matches!(err, TableError::Corrupt { .. }) && err.to_string().contains("fingerprint"),
        "{err}"
    );
}
