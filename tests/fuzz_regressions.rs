//! Bugs the fuzz targets found (docs/FUZZING.md), one test per case, named after it. The
//! inputs that found them are kept in `tests/data/fuzz/<target>/` (listed in
//! `tests/data/fuzz/README.md`) and replayed, with the seeds, by `tests/fuzz_short.rs`.

use delta_collide::cspace::{Symmetry, Workspace};
use delta_collide::ffi::*;
use delta_collide::robot::Delta3;
use delta_collide::table::format::fnv1a64;
use delta_collide::table::synthetic::{space, Pattern};
use delta_collide::table::*;
use std::path::Path;

fn data(target: &str, name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz").join(target).join(name),
    )
    .unwrap()
}

/// c_abi, `fk_huge_re_nan_tcp.bin`: with `re = f64::MAX` (then accepted: finite and
/// positive), `dc_delta3_forward_kinematics` returned `DC_STATUS_OK` with the TCP (NaN, NaN,
/// -inf): `re * re` overflowed. Forward kinematics reports an overflowing point as no solution,
/// and the C ABI refuses a length above `math::MAX_LENGTH` (1e6 mm) as an invalid geometry.
#[test]
fn forward_kinematics_with_a_huge_lower_link_is_unreachable_not_nan() {
    let d = Delta3 { re: f64::MAX, ..Delta3::THESIS };
    assert_eq!(d.forward_kinematics(&[0.0; 3]), None);
    let g = DcDelta3 { re: f64::MAX, ..dc_robot_config_thesis().geometry };
    let mut tcp = DcVec3 { x: 1.0, y: 2.0, z: 3.0 };
    // SAFETY: valid geometry, 3 readable doubles, writable output.
    let status = unsafe { dc_delta3_forward_kinematics(&g, [0.0; 3].as_ptr(), &mut tcp) };
    assert_eq!(status, DC_STATUS_INVALID_CONFIG);
    assert_eq!(tcp, DcVec3 { x: 1.0, y: 2.0, z: 3.0 }, "nothing written on failure");
}

/// table_bytes, `slice_axes_nonzero_6d.dct`: a 6D table of T1 whose "slice axes" header field
/// read 0x7a00 loaded; the loader refused only the 4D values 1 and 2 outside 4D tables, so a
/// corrupt field passed (and the table re-serialised to other bytes). It must be 0 there.
#[test]
fn a_nonzero_slice_axes_field_outside_4d_tables_is_corrupt() {
    let corrupt_axes = |r: Result<(Header, Table), TableError>| matches!(r, Err(TableError::Corrupt { what }) if what.contains("slice axes"));
    assert!(corrupt_axes(from_bytes(&data("table_bytes", "slice_axes_nonzero_6d.dct"))));
    let s = space(2, Pattern::Noise { p: 0.3, seed: 4 });
    let header = Header::for_space(&s, 1, Workspace::THESIS, Certification::SweptBound);
    let tables = [
        Table::D6(LinearQuadtree6d::build(&s, Symmetry::Whole).unwrap()),
        Table::D5(LinearQuadtree5d::build(&s, Symmetry::MirrorY).unwrap()),
    ];
    for t in tables {
        for axes in [1u32, 2, 3, 0x7a00, u32::MAX] {
            let mut b = to_bytes(&t, &header);
            b[32..36].copy_from_slice(&axes.to_le_bytes());
            let n = b.len() - 8;
            let sum = fnv1a64(&b[..n]);
            b[n..].copy_from_slice(&sum.to_le_bytes());
            assert!(corrupt_axes(from_bytes(&b)), "{} with slice axes {axes:#x} loaded", t.name());
        }
    }
}

/// bundle_bytes, `relabelled_and_resealed.dcb`: the line's bundle with labels of its first
/// table edited and, once sealed by the target, every checksum recomputed: it then loads and
/// answers FREE where the robots collide, which the target had asserted could not happen. A
/// label is not checked on loading (only a new build could); the checksum is what refuses an
/// edited table, so the target asserts exact answers only for its input as given. Here: as
/// given, the edit is refused by the table's checksum.
#[test]
fn an_edited_label_is_refused_by_the_checksum() {
    let edited = data("bundle_bytes", "relabelled_and_resealed.dcb");
    let e = bundle_from_bytes(&edited).unwrap_err();
    assert!(matches!(&e, TableError::Corrupt { what } if what.contains("checksum")), "{e}");
}
