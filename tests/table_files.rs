//! The table file format: round trips, and every kind of damage gives its
//! specific `TableError`, never a panic nor a table that loads. Corrupted files kept in
//! `tests/data/` are described in `tests/data/README.md`.

use delta_collide::cspace::{LabelledSpace, Progress, Symmetry, Workspace};
use delta_collide::table::format::{fnv1a64, from_bytes, from_bytes_for_cell};
use delta_collide::table::synthetic::{space, Pattern};
use delta_collide::table::*;

const FINGERPRINT: u64 = 0x0123_4567_89ab_cdef;

fn small_space() -> LabelledSpace {
    space(2, Pattern::Noise { p: 0.3, seed: 4 })
}

fn tables(s: &LabelledSpace) -> Vec<Table> {
    vec![
        Table::D6(LinearQuadtree6d::build(s, Symmetry::Whole).unwrap()),
        Table::D6(LinearQuadtree6d::build(s, Symmetry::MirrorY).unwrap()),
        Table::D5(LinearQuadtree5d::build(s, Symmetry::Whole).unwrap()),
        Table::D4(LinearQuadtree4d::build(s, Symmetry::MirrorY, SliceAxes::YY, 0).unwrap()),
        Table::D4(LinearQuadtree4d::build(s, Symmetry::Whole, SliceAxes::ZZ, 3).unwrap()),
        Table::Shared(SharedQuadtree6d::build(s, Symmetry::MirrorY).unwrap()),
        Table::Shared(
            SharedQuadtree6d::build_subdivided(s, &sub_cells(s), Symmetry::Whole).unwrap(),
        ),
        Table::Clearance(Box::new(
            ClearanceTable::build(s, &level_counts(s), Ladder::default_ladder(), Symmetry::MirrorY)
                .unwrap(),
        )),
    ]
}

/// Clearance level counts of every pair: 0 unless free, else 1 to 7 from the pair's number.
fn level_counts(s: &LabelledSpace) -> Vec<u8> {
    let free = |l: delta_collide::cspace::Label| l == delta_collide::cspace::Label::Free;
    s.labels
        .iter()
        .enumerate()
        .map(|(i, l)| if free(l) { 1 + (i * 7 / 3 % 7) as u8 } else { 0 })
        .collect()
}

/// Sub-cells of every collision pair: every other sub-cell a collision, some "don't care".
fn sub_cells(s: &LabelledSpace) -> delta_collide::cspace::SubCells {
    let mut sub = delta_collide::cspace::SubCells::default();
    for (pair, l) in s.labels.iter().enumerate() {
        if l == delta_collide::cspace::Label::Collision {
            sub.pairs.push(pair as u64);
            sub.care.push(!0xff00u64.rotate_left(pair as u32 % 64));
            sub.collision.push(0x5555_5555_5555_5555u64.rotate_left(pair as u32 % 2));
        }
    }
    sub
}

fn header(s: &LabelledSpace) -> Header {
    Header::for_space(s, FINGERPRINT, Workspace::THESIS, Certification::SweptBound)
}

/// Where the sections start in these files: after the 184-byte header and the parameter
/// count, with no cell parameters recorded (`src/table/format.rs`).
const SECTIONS: usize = 192;

/// Recomputes the checksum after a deliberate edit, so that only the field check can object.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 8;
    let sum = fnv1a64(&bytes[..n]);
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
}

#[test]
fn every_variant_round_trips() {
    let s = small_space();
    for t in tables(&s) {
        let bytes = to_bytes(&t, &header(&s));
        let (h, back) = from_bytes_for_cell(&bytes, FINGERPRINT).unwrap();
        assert_eq!(h, header(&s));
        assert_eq!(back, t, "{} did not round trip", t.name());
        assert_eq!(to_bytes(&back, &h), bytes);
    }
}

#[test]
fn truncation_at_every_offset_is_an_error() {
    let s = small_space();
    for t in tables(&s) {
        let bytes = to_bytes(&t, &header(&s));
        for n in 0..bytes.len() {
            match from_bytes(&bytes[..n]) {
                Err(TableError::Truncated { needed, have, .. }) => {
                    assert!(needed > have && have == n)
                }
                Err(TableError::Corrupt { .. }) => {}
                other => panic!("{}: truncated to {n} bytes gave {other:?}", t.name()),
            }
        }
    }
}

#[test]
fn a_flipped_bit_anywhere_is_an_error() {
    let s = small_space();
    for t in tables(&s) {
        let mut bytes = to_bytes(&t, &header(&s));
        for bit in 0..8 * bytes.len() {
            bytes[bit / 8] ^= 1 << (bit % 8);
            assert!(from_bytes(&bytes).is_err(), "{}: bit {bit} flipped still loads", t.name());
            bytes[bit / 8] ^= 1 << (bit % 8);
        }
        assert!(from_bytes(&bytes).is_ok());
    }
}

#[test]
fn magic_endianness_version_and_cell_give_their_errors() {
    let s = small_space();
    let good = to_bytes(&tables(&s)[0], &header(&s));
    let mut b = good.clone();
    b[0] = b'X';
    assert!(matches!(from_bytes(&b), Err(TableError::BadMagic { .. })));
    let mut b = good.clone();
    b[8..12].copy_from_slice(&0x0102_0304u32.to_be_bytes());
    assert_eq!(from_bytes(&b).unwrap_err(), TableError::WrongEndianness);
    let mut b = good.clone();
    b[12..16].copy_from_slice(&1u32.to_le_bytes());
    assert_eq!(
        from_bytes(&b).unwrap_err(),
        TableError::UnsupportedVersion { found: 1, supported: format::VERSION }
    );
    let e = from_bytes_for_cell(&good, 42).unwrap_err();
    assert_eq!(e, TableError::WrongCell { expected: 42, found: FINGERPRINT, differs: None });
    let msg = e.to_string();
    assert!(
        msg.contains("0x0123456789abcdef") && msg.contains("delta-collide build --cell"),
        "{msg}"
    );
    let mut b = good.clone();
    let last = b.len() - 1;
    b[last] ^= 1;
    assert!(
        matches!(from_bytes(&b), Err(TableError::Corrupt { what }) if what.contains("checksum"))
    );
}

/// Checksum-valid files whose fields break an invariant (what a bad writer could produce).
fn corrupted_files(s: &LabelledSpace) -> Vec<(&'static str, Vec<u8>, &'static str)> {
    let ts = tables(s);
    let mut out = Vec::new();
    // 6D: the first two codes swapped.
    let mut b = to_bytes(&ts[0], &header(s));
    let (a, c) = (SECTIONS, SECTIONS + 8);
    let first: [u8; 8] = b[a..a + 8].try_into().unwrap();
    b.copy_within(c..c + 8, a);
    b[c..c + 8].copy_from_slice(&first);
    reseal(&mut b);
    out.push(("unsorted_codes_6d.dctable", b, "not sorted"));
    // 4D: the first slice index set past the slice count.
    let mut b = to_bytes(&ts[3], &header(s));
    let m = u64::from_le_bytes(b[160..168].try_into().unwrap()) as usize;
    let at = SECTIONS + 8 * m;
    b[at..at + 4].copy_from_slice(&1000u32.to_le_bytes());
    reseal(&mut b);
    out.push(("slice_index_out_of_range_4d.dctable", b, "slice_of[0]"));
    // 5D: the first interval's end set to k.
    let mut b = to_bytes(&ts[2], &header(s));
    let m = u64::from_le_bytes(b[160..168].try_into().unwrap()) as usize;
    let at = SECTIONS + 8 * m + 4 * (m + 1);
    b[at + 1] = 4;
    reseal(&mut b);
    out.push(("interval_beyond_k_5d.dctable", b, "intervals[0]"));
    // Shared 6-D: the first child index set past the nodes of its depth.
    let mut b = to_bytes(&ts[5], &header(s));
    let count =
        |i: usize| u64::from_le_bytes(b[160 + 8 * i..168 + 8 * i].try_into().unwrap()) as usize;
    let at = SECTIONS + 8 * count(0) + 4 * count(1);
    b[at..at + 4].copy_from_slice(&60_000u32.to_le_bytes());
    reseal(&mut b);
    out.push(("child_index_out_of_range_shared.dctable", b, "child index"));
    // Clearance: the level tree's first leaf set to a word that is no level's.
    let Table::Clearance(t) = &ts[7] else {
        unreachable!("tables() ends with the clearance table")
    };
    let mut b = to_bytes(&ts[7], &header(s));
    let (e, l) = t.parts();
    assert!(!l.leaves.is_empty(), "the synthetic clearance table has level leaves");
    let words = t.ladder().len() + 5 + 2 * e.masks.len() + e.leaves.len() + 2 * l.masks.len();
    let at = SECTIONS + 8 * words;
    b[at..at + 8].copy_from_slice(&0b1010u64.to_le_bytes());
    reseal(&mut b);
    out.push(("leaf_not_a_level_clearance.dctable", b, "clearance leaf"));
    // Clearance: packed child indices, the section cut short by one byte (its count too).
    let mut b = to_bytes(&ts[7], &header(s));
    let n2 = u64::from_le_bytes(b[176..184].try_into().unwrap());
    b[176..184].copy_from_slice(&(n2 - 1).to_le_bytes());
    b.remove(b.len() - 9);
    reseal(&mut b);
    out.push(("packed_children_short_clearance.dctable", b, "child indices of"));
    out
}

/// `bytes` of a clearance table rewritten as files without flag bit 2 hold it: section 2 the
/// trees' child indices as u32 each.
fn with_wide_children(bytes: &[u8], t: &ClearanceTable) -> Vec<u8> {
    let count =
        |i: usize| u64::from_le_bytes(bytes[160 + 8 * i..168 + 8 * i].try_into().unwrap()) as usize;
    let start = SECTIONS + 8 * count(0) + 4 * count(1);
    let (e, l) = t.parts();
    let mut out = bytes[..start].to_vec();
    out.extend(e.children.iter().chain(&l.children).flat_map(|c| c.to_le_bytes()));
    out[176..184].copy_from_slice(&((e.children.len() + l.children.len()) as u64).to_le_bytes());
    let flags = u32::from_le_bytes(out[28..32].try_into().unwrap());
    assert_eq!(flags & 4, 4, "the writer packs child indices");
    out[28..32].copy_from_slice(&(flags & !4).to_le_bytes());
    out.extend_from_slice(&[0; 8]);
    reseal(&mut out);
    out
}

/// Clearance files pack their child indices (flag bit 2) into fewer bytes; a file holding
/// them as u32 each (flag clear, as files were first written) loads as the same table, and
/// so does the kept file `tests/data/clearance_wide_children.dct` written that way, which
/// the packed writer then writes smaller.
#[test]
fn clearance_files_with_packed_or_wide_child_indices_load_alike() {
    let s = small_space();
    let t = tables(&s).pop().unwrap();
    let Table::Clearance(c) = &t else { unreachable!("tables() ends with the clearance table") };
    let packed = to_bytes(&t, &header(&s));
    let wide = with_wide_children(&packed, c);
    assert!(packed.len() < wide.len(), "packed {} bytes, wide {}", packed.len(), wide.len());
    assert_eq!(from_bytes(&wide).unwrap().1, t);
    assert_eq!(from_bytes(&packed).unwrap().1, t);
    let kept_path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/clearance_wide_children.dct");
    let kept = std::fs::read(kept_path).unwrap();
    let (h, old) = from_bytes(&kept).unwrap();
    assert_eq!(
        u32::from_le_bytes(kept[28..32].try_into().unwrap()) & 4,
        0,
        "the kept file is of the wide form"
    );
    let again = to_bytes(&old, &h);
    assert!(again.len() < kept.len());
    assert_eq!(from_bytes(&again).unwrap().1, old);
    // A wide file whose flags claim packed indices is refused, not misread.
    let mut claimed = wide.clone();
    claimed[28] |= 4;
    reseal(&mut claimed);
    assert!(matches!(from_bytes(&claimed), Err(TableError::Corrupt { .. })));
}

#[test]
fn checksum_valid_but_inconsistent_files_are_corrupt() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let regenerate = std::env::var_os("DC_REGENERATE_TABLE_DATA").is_some();
    for (name, fresh, needle) in corrupted_files(&small_space()) {
        let path = dir.join(name);
        if regenerate {
            std::fs::write(&path, &fresh).unwrap();
        }
        for bytes in [fresh, std::fs::read(&path).unwrap()] {
            match from_bytes(&bytes) {
                Err(TableError::Corrupt { what }) => {
                    assert!(what.contains(needle), "{name}: {what}")
                }
                other => panic!("{name}: {other:?}"),
            }
        }
    }
}

#[test]
fn a_loaded_table_answers_as_the_built_one() {
    let s = space(3, Pattern::Blobs);
    let t = Table::D4(LinearQuadtree4d::build(&s, Symmetry::MirrorY, SliceAxes::ZZ, 10).unwrap());
    let (_, back) = from_bytes(&to_bytes(&t, &header(&s))).unwrap();
    for a in &s.grid_a.cells {
        for b in &s.grid_b.cells {
            let c = [a[0], a[1], a[2], b[0], b[1], b[2]];
            assert_eq!(back.query(c), t.query(c));
        }
    }
}

/// The file name of each table of [`tables`] in `tests/data/golden/`.
const GOLDEN_SYNTHETIC: [&str; 8] =
    ["6d", "6d_sym", "5d", "4d_yy_t0_sym", "4d_zz_t3", "shared_sym", "shared_sub", "clearance_sym"];

/// The variants built from a reference cell for `tests/data/golden/`, with their file names.
fn golden_variants() -> Vec<(&'static str, Variant)> {
    vec![
        ("6d", Variant::D6),
        ("5d", Variant::D5),
        ("4d_yy_t0", Variant::D4 { axes: SliceAxes::YY, t: 0 }),
        ("4d_zz_t2", Variant::D4 { axes: SliceAxes::ZZ, t: 2 }),
        ("shared", Variant::Shared),
        ("shared_sub", Variant::SharedSubdivided),
        ("clearance", Variant::Clearance(Ladder::default_ladder())),
    ]
}

/// Compares `fresh` with the committed file `tests/data/golden/{name}.dct` byte for byte
/// (or writes it under `DC_REGENERATE_TABLE_DATA`).
fn assert_golden(name: &str, fresh: &[u8]) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/golden")
        .join(format!("{name}.dct"));
    if std::env::var_os("DC_REGENERATE_TABLE_DATA").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, fresh).unwrap();
    }
    let kept = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        kept == fresh,
        "{name}: the table built now differs from {} ({} bytes now, {} kept)",
        path.display(),
        fresh.len(),
        kept.len()
    );
}

/// Every table kind built from fixed synthetic labels is byte for byte the committed file:
/// a change of the builders or the writer that changes a file shows here.
#[test]
fn synthetic_tables_are_byte_identical_to_the_kept_files() {
    let s = small_space();
    for (t, name) in tables(&s).iter().zip(GOLDEN_SYNTHETIC) {
        assert_golden(&format!("synthetic_{name}"), &to_bytes(t, &header(&s)));
    }
}

/// Every table kind built from T1 and T3 at k = 16, the smallest the grid allows (certified
/// labels with sub-cells; the thesis labelling for T1's shared table) is byte for byte the
/// committed file: this covers the labelling as well as the builders and the writer.
#[test]
fn reference_cell_tables_are_byte_identical_to_the_kept_files() {
    use delta_collide::cell::reference::reference_cell;
    for cell_name in ["T1", "T3"] {
        let cell = reference_cell(cell_name).unwrap();
        let (names, variants): (Vec<_>, Vec<_>) = golden_variants().into_iter().unzip();
        let (h, ts, _) = build_tables(
            &cell,
            16,
            &Workspace::THESIS,
            &variants,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap();
        for (t, name) in ts.iter().zip(names) {
            assert_golden(&format!("{}_k16_{name}", cell_name.to_lowercase()), &to_bytes(t, &h));
        }
    }
    let cell = reference_cell("T1").unwrap();
    let (h, t, _) = build_table(
        &cell,
        16,
        &Workspace::THESIS,
        Variant::Shared,
        Labelling::ThesisMargin,
        Progress::Silent,
    )
    .unwrap();
    assert_golden("t1_k16_shared_thesis", &to_bytes(&t, &h));
}
