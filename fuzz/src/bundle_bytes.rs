//! Target `bundle_bytes`: a bundle file's bytes (the tables of a line, `table::bundle`),
//! loaded with `bundle_from_bytes` and with `BundleChecker` for the four-robot line of
//! `cells/line4.toml` and for T1, then queried ("a loaded bundle never panics, and with the
//! exact confirmation answers as exact mode").
//!
//! The input is loaded twice: as it is, and *sealed*: each table's fingerprint set to its
//! directory entry's, each table's own checksum, its directory checksum and the bundle's
//! checksum recomputed, so that mutations reach the directory's and the tables' field checks.
//! Properties checked:
//! - loading and checking never panic;
//! - a bundle that loads re-serialises to the same bytes (there is one encoding per bundle);
//! - a checker that loads, with the exact confirmation, answers COLLISION (for a pair or the
//!   tick) only where the exact model does, names the unreachable robots as it does, and
//!   refuses a wrong number of TCPs;
//! - loaded as it is (every checksum genuine: the tables are a build's), it gives every pair
//!   and the tick exactly the exact model's answer. A sealed input may not: its checksums were
//!   recomputed over changed labels, so a FREE label there is no longer a proof. The
//!   checksums are what tell a built table from a changed one (docs/TABLES.md).

use delta_collide::cell::exact::PairState;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{parse_cell, Cell, ExactChecker};
use delta_collide::math::Vec3;
use delta_collide::table::format::{fnv1a64, to_bytes};
use delta_collide::table::{
    bundle_from_bytes, bundle_to_bytes, is_bundle, Bundle, BundleChecker, Confirmation, TableAnswer,
};
use std::sync::OnceLock;

/// Offset of the cell fingerprint in a table file's header (see `table::format`).
const TABLE_FINGERPRINT_AT: usize = 40;
/// Size of the bundle header before the directory, and of one directory entry.
const HEADER: usize = 40;
const ENTRY: usize = 32;
/// Most directory entries the sealing walks (the format's own limit).
const MAX_TABLES: usize = 496;
/// Random configurations per loaded checker.
const CONFIGURATIONS: usize = 12;

/// The cells a bundle is tried on: the line of four, and T1 (a single table file reads as a
/// bundle of one table).
fn cells() -> &'static [Cell] {
    static CELLS: OnceLock<Vec<Cell>> = OnceLock::new();
    CELLS.get_or_init(|| {
        let line = parse_cell(include_str!("../../cells/line4.toml")).expect("cells/line4.toml");
        vec![line, reference_cell("T1").expect("T1")]
    })
}

fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

fn put_u64(bytes: &mut [u8], at: usize, v: u64) {
    bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

/// The input with every table's fingerprint and checksum, every directory checksum and the
/// bundle's checksum made consistent (as far as the directory's offsets point into it).
pub fn sealed(data: &[u8]) -> Vec<u8> {
    let mut bytes = data.to_vec();
    if !is_bundle(&bytes) || bytes.len() < HEADER + 8 {
        return bytes;
    }
    let tables = u32::from_le_bytes(bytes[28..32].try_into().unwrap()) as usize;
    let body_end = bytes.len() - 8;
    for i in 0..tables.min(MAX_TABLES) {
        let entry = HEADER + ENTRY * i;
        let (Some(fingerprint), Some(offset), Some(len)) =
            (u64_at(&bytes, entry), u64_at(&bytes, entry + 8), u64_at(&bytes, entry + 16))
        else {
            break;
        };
        let (Ok(start), Ok(len)) = (usize::try_from(offset), usize::try_from(len)) else {
            continue;
        };
        if entry + ENTRY > body_end
            || len < TABLE_FINGERPRINT_AT + 16
            || start.saturating_add(len) > body_end
        {
            continue;
        }
        let table = &mut bytes[start..start + len];
        put_u64(table, TABLE_FINGERPRINT_AT, fingerprint);
        let sum = fnv1a64(&table[..len - 8]);
        put_u64(table, len - 8, sum);
        let sum = fnv1a64(&bytes[start..start + len]);
        put_u64(&mut bytes, entry + 24, sum);
    }
    let sum = fnv1a64(&bytes[..body_end]);
    put_u64(&mut bytes, body_end, sum);
    bytes
}

/// The target: never panics on any input.
pub fn bundle_bytes(data: &[u8]) {
    let mut rng = Rng(fnv1a64(data) | 1);
    load_and_probe(data, &mut rng, Origin::AsGiven);
    load_and_probe(&sealed(data), &mut rng, Origin::Sealed);
}

/// Whether the bytes are the input as given (checksums genuine) or sealed here.
#[derive(Clone, Copy, PartialEq)]
enum Origin {
    AsGiven,
    Sealed,
}

fn load_and_probe(bytes: &[u8], rng: &mut Rng, origin: Origin) {
    let bundle = match bundle_from_bytes(bytes) {
        Ok(bundle) => bundle,
        Err(e) => return drop(e.to_string()),
    };
    if is_bundle(bytes) {
        assert!(
            reserialised(&bundle).as_deref() == Some(bytes),
            "a loaded bundle re-serialises to other bytes"
        );
    }
    for cell in cells() {
        match BundleChecker::from_bundle(cell.clone(), &bundle, Confirmation::Exact) {
            Ok(mut checker) => probe_checker(&mut checker, cell, rng, origin),
            Err(e) => drop(e.to_string()),
        }
    }
}

fn reserialised(bundle: &Bundle) -> Option<Vec<u8>> {
    let files: Vec<Vec<u8>> = bundle.tables.iter().map(|(h, t)| to_bytes(t, h)).collect();
    bundle_to_bytes(bundle.cell_fingerprint, bundle.robots, &files, &bundle.pairs).ok()
}

/// Random, home and non-finite configurations: every pair's answer and the tick's are exact
/// mode's (for a sealed input: COLLISION only where exact mode collides).
fn probe_checker(checker: &mut BundleChecker, cell: &Cell, rng: &mut Rng, origin: Origin) {
    let agrees = |answer: TableAnswer, want: TableAnswer| match origin {
        Origin::AsGiven => answer == want,
        Origin::Sealed => {
            answer == want || (answer, want) == (TableAnswer::Free, TableAnswer::Collision)
        }
    };
    let n = cell.robots.len();
    let mut exact = ExactChecker::new(cell.clone());
    let home = Vec3::new(0.0, 0.0, -450.0);
    for i in 0..CONFIGURATIONS + 2 {
        let tcps: Vec<Vec3> = match i {
            0 => vec![home; n],
            1 => (0..n)
                .map(|j| if j == 1 { Vec3::new(f64::NAN, 0.0, -450.0) } else { home })
                .collect(),
            _ => (0..n).map(|_| rng.tcp()).collect(),
        };
        let answer = checker.check(&tcps).expect("one TCP per robot is accepted");
        let v = exact.check(&tcps).expect("one TCP per robot");
        let whole = match (v.unreachable_mask, v.collides()) {
            (0, true) => TableAnswer::Collision,
            (0, false) => TableAnswer::Free,
            (m, _) => TableAnswer::Unreachable(m),
        };
        assert!(
            agrees(answer, whole),
            "{}: {answer:?}, exact mode {whole:?} at {tcps:?}",
            cell.name
        );
        assert_eq!(checker.pairs().len(), v.pairs.len(), "one answer per pair that can meet");
        for (p, e) in checker.pairs().iter().zip(&v.pairs) {
            assert_eq!((p.a, p.b), (e.a, e.b));
            let want = match e.state {
                PairState::Collides(..) => TableAnswer::Collision,
                PairState::Free => TableAnswer::Free,
                PairState::Undecided => continue,
            };
            assert!(
                agrees(p.answer, want),
                "{}: pair {}-{}: {:?}, exact {want:?} at {tcps:?}",
                cell.name,
                p.a,
                p.b,
                p.answer
            );
        }
    }
    assert!(checker.check(&vec![home; n + 1]).is_err(), "wrong TCP count accepted");
}

/// xorshift64: configurations that vary with the input, reproducibly.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A TCP in (or a little beyond) the workspace, in its robot's MCS.
    fn tcp(&mut self) -> Vec3 {
        let (r, a) = (240.0 * self.unit().sqrt(), core::f64::consts::TAU * self.unit());
        Vec3::new(r * a.cos(), r * a.sin(), -360.0 - 180.0 * self.unit())
    }
}
