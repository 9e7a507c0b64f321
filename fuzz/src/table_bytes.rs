//! Target `table_bytes`: a table file's bytes, loaded with `table::from_bytes` and with
//! `TableChecker::new`, then queried ("a loaded table never panics nor reads
//! out of bounds").
//!
//! The input is loaded twice: as it is, and *sealed*: its fingerprint field set to the
//! reference cell it names (T1 when it names none) and its checksum recomputed, so that
//! mutations reach the field checks and the lookups behind the checksum. Properties checked:
//! - loading and querying never panic;
//! - a table that loads re-serialises to the same bytes (there is one encoding per table);
//! - an index `>= k` answers collision (fail closed);
//! - the checker answers `Free`/`Collision` only when both TCPs are reachable, flags a NaN
//!   TCP as unreachable, and refuses a wrong number of TCPs.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::Cell;
use delta_collide::math::Vec3;
use delta_collide::table::format::{fnv1a64, from_bytes, to_bytes};
use delta_collide::table::{Header, Table, TableAnswer, TableChecker};
use std::sync::OnceLock;

/// Offset of the cell fingerprint in the header (see `table::format`).
const FINGERPRINT_AT: usize = 40;

/// The reference cells with their fingerprints, built once.
fn reference_cells() -> &'static [(u64, Cell)] {
    static CELLS: OnceLock<Vec<(u64, Cell)>> = OnceLock::new();
    CELLS.get_or_init(|| {
        ["T1", "T2", "T3"]
            .iter()
            .map(|n| reference_cell(n).expect("reference cell"))
            .map(|c| (c.fingerprint(), c))
            .collect()
    })
}

/// The input with the fingerprint of the reference cell it names (else T1) and a valid
/// checksum, and that cell.
pub fn sealed(data: &[u8]) -> (Vec<u8>, &'static Cell) {
    let cells = reference_cells();
    let mut bytes = data.to_vec();
    let mut cell = &cells[0];
    if let Some(field) = bytes.get_mut(FINGERPRINT_AT..FINGERPRINT_AT + 8) {
        let named = u64::from_le_bytes(std::array::from_fn(|i| field[i]));
        cell = cells.iter().find(|(f, _)| *f == named).unwrap_or(&cells[0]);
        field.copy_from_slice(&cell.0.to_le_bytes());
    }
    if let Some(n) = bytes.len().checked_sub(8) {
        let sum = fnv1a64(&bytes[..n]);
        bytes[n..].copy_from_slice(&sum.to_le_bytes());
    }
    (bytes, &cell.1)
}

/// The target: never panics on any input.
pub fn table_bytes(data: &[u8]) {
    let mut rng = Rng(fnv1a64(data) | 1);
    load_and_probe(data, &mut rng);
    let (bytes, cell) = sealed(data);
    load_and_probe(&bytes, &mut rng);
    match TableChecker::new(cell.clone(), &bytes) {
        Ok(mut checker) => probe_checker(&mut checker, cell, &mut rng),
        Err(e) => drop(e.to_string()),
    }
}

fn load_and_probe(bytes: &[u8], rng: &mut Rng) {
    match from_bytes(bytes) {
        Ok((header, table)) => {
            let again = to_bytes(&table, &header);
            if again != bytes {
                // A clearance file with u32 child indices (variant 8, flag bit 2 clear) is
                // written back with them packed: the same table in fewer bytes.
                let field = |at: usize| {
                    bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                };
                let wide_clearance = field(16) == Some(8) && field(28).is_some_and(|f| f & 4 == 0);
                assert!(wide_clearance, "a loaded table re-serialises to other bytes");
                let back = from_bytes(&again).expect("a clearance table written back packed loads");
                assert!(
                    back == (header.clone(), table.clone()),
                    "a clearance table written back packed differs"
                );
                assert!(
                    again.len() <= bytes.len(),
                    "packed child indices take more bytes than u32 ones"
                );
            }
            probe_table(&table, &header, rng);
        }
        Err(e) => drop(e.to_string()),
    }
}

/// Queries corner, random and out-of-range cells.
fn probe_table(table: &Table, header: &Header, rng: &mut Rng) {
    let _ = (table.name(), table.memory_bytes(), table.symmetric(), header.check_cell(0));
    let grid_k = 1u32 << table.levels();
    for _ in 0..4 {
        table.query_grid_cell(std::array::from_fn(|_| rng.below(grid_k) as u16));
    }
    // Query indices run to k at the table's resolution (sub-cells included).
    let k = 1u32 << (table.levels() + table.sub_levels());
    let top = (k - 1) as u16;
    table.query([0; 6]);
    table.query([top; 6]);
    table.query([0, top, 0, top, 0, top]);
    for _ in 0..16 {
        table.query(std::array::from_fn(|_| rng.below(k) as u16));
    }
    for _ in 0..16 {
        let mut cell: [u16; 6] = std::array::from_fn(|_| rng.below(k) as u16);
        let bad = rng.below(6) as usize;
        cell[bad] = match rng.below(3) {
            0 => k as u16,
            1 => u16::MAX,
            _ => (k + rng.below(k)).min(u32::from(u16::MAX)) as u16,
        };
        assert!(table.query(cell), "index {cell:?} >= k = {k} answered free");
    }
}

/// Queries grid-cell centres, grid corners and special points through the checker.
fn probe_checker(checker: &mut TableChecker, cell: &Cell, rng: &mut Rng) {
    let h = checker.header().clone();
    let k = 1u32 << checker.table().levels();
    let origins = [Vec3::from(h.origin_a), Vec3::from(h.origin_b)];
    let centre =
        |j: usize, c: [u32; 3]| origins[j] + Vec3::from(c.map(|i| (f64::from(i) + 0.5) * h.r));
    let mut pairs: Vec<[Vec3; 2]> = (0..24)
        .map(|_| {
            [
                centre(0, [rng.below(k), rng.below(k), rng.below(k)]),
                centre(1, [rng.below(k), rng.below(k), rng.below(k)]),
            ]
        })
        .collect();
    let corner = |j: usize| origins[j] + Vec3::repeat(f64::from(k) * h.r);
    let home = Vec3::new(0.0, 0.0, -450.0);
    let nan = Vec3::new(f64::NAN, 0.0, -450.0);
    pairs.extend([
        [home, home],
        [origins[0], origins[1]],
        [corner(0), corner(1)],
        [nan, home],
        [home, nan],
        [Vec3::new(0.0, 0.0, 1.0), home],
        [Vec3::repeat(f64::INFINITY), Vec3::repeat(-1e300)],
    ]);
    for tcps in pairs {
        let answer = checker.check(&tcps).expect("two TCPs are accepted");
        let reachable = |j: usize| cell.robots[j].model.delta.is_reachable(&tcps[j]);
        match answer {
            TableAnswer::Free | TableAnswer::Collision => {
                assert!(reachable(0) && reachable(1), "{answer:?} for an unreachable TCP {tcps:?}")
            }
            TableAnswer::Unreachable(mask) => {
                assert!(mask != 0 && mask < 4, "mask {mask:#b}");
                assert!(
                    (0..2).all(|j| (mask >> j & 1 == 0) == reachable(j)),
                    "mask {mask:#b} for {tcps:?}"
                );
            }
        }
    }
    assert!(
        checker.check(&[home]).is_err() && checker.check(&[home; 3]).is_err(),
        "wrong TCP count accepted"
    );
}

/// xorshift64: query cells that vary with the input, reproducibly.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: u32) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % u64::from(n.max(1))) as u32
    }
}
