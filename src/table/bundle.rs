//! Bundles: the tables of a line of robots in one file, one table per pair of robots that can
//! meet, shared by the pairs that stand alike (SPEC §1, §6).
//!
//! # Why one table serves several pairs
//! A table's configuration is each robot's TCP in its own MCS, and what decides a collision
//! of a pair is the two models and where the second robot stands relative to the first. A
//! pair's table is therefore built for its *pair cell* ([`pair_cell`]): the first robot at
//! the WCS origin, the second at its placement relative to the first. Pairs with the same pair
//! cell (the same fingerprint, [`Cell::fingerprint`]) share one table: the neighbours of an
//! equally spaced line all use one. Rigid motions about z keep every box pair's intersection,
//! so the table of the pair cell answers for the pair where it stands.
//!
//! # Layout (little-endian)
//! ```text
//! offset size  field
//!      0    8  magic b"DCBUNDLE"
//!      8    4  endianness marker 0x01020304
//!     12    4  bundle format version (VERSION)
//!     16    8  fingerprint of the cell the bundle was built for (`Cell::fingerprint`)
//!     24    4  robots of that cell     28  4  tables T     32  4  pairs P     36  4  reserved, 0
//!     40  32T  per table: pair-cell fingerprint, offset and length of its bytes in the
//!              bundle, FNV-1a 64 of those bytes (u64 each)
//!      .  16P  per pair that can meet of the built cell: robot a, robot b (a < b), table
//!              index, reserved 0 (u32 each)
//!      .       the tables, each a whole table file (`format.rs`, with its own checksum), in
//!              directory order, back to back
//!  end-8    8  FNV-1a 64 of every byte before it
//! ```
//! Loading checks magic, endianness and version first, then the directory's bounds, the whole
//! checksum, each table's checksum, and loads each table as a table file whose recorded
//! fingerprint must be its directory entry's.

use super::error::{corrupt, TableError};
use super::format::{from_bytes, Header};
use super::reader::Reader;
use super::Table;
use crate::cell::{fnv1a64, Cell, Placement, RobotSpec};
use alloc::{format, string::String, vec, vec::Vec};

/// The first eight bytes of every bundle.
pub const BUNDLE_MAGIC: [u8; 8] = *b"DCBUNDLE";
/// The bundle format version written and read.
pub const BUNDLE_VERSION: u32 = 1;
const ENDIAN_MARK: u32 = 0x0102_0304;
/// Most tables and pairs a bundle holds: every pair of 32 robots.
const MAX_ENTRIES: u32 = 496;

/// The two-robot cell a table for robots `a` and `b` of `cell` is built for: robot `a` at the
/// WCS origin, robot `b` at its placement relative to `a` (`Rz(-alpha_a) (t_b - t_a)`,
/// `alpha_b - alpha_a`), with both robots' models, stopping models and the cell's method.
///
/// # Panics
/// When `a` or `b` is not a robot of `cell`, or they are the same.
pub fn pair_cell(cell: &Cell, a: usize, b: usize) -> Cell {
    assert!(
        a != b && a < cell.robots.len() && b < cell.robots.len(),
        "pair ({a}, {b}) of {} robots",
        cell.robots.len()
    );
    let (ra, rb) = (&cell.robots[a], &cell.robots[b]);
    let relative = Placement {
        alpha: rb.placement.alpha - ra.placement.alpha,
        t: ra.placement.to_mcs(&rb.placement.t),
    };
    let robots = vec![
        RobotSpec { placement: Placement::IDENTITY, ..ra.clone() },
        RobotSpec { placement: relative, ..rb.clone() },
    ];
    Cell {
        name: format!("{} {}-{}", cell.name, ra.name, rb.name),
        robots,
        method: cell.method,
        tick_ms: cell.tick_ms,
        stops: vec![cell.stops[a], cell.stops[b]],
    }
}

/// One pair of robots of a line and the table that answers for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BundlePair {
    /// First robot (index in the cell), `a < b`.
    pub a: usize,
    /// Second robot.
    pub b: usize,
    /// Index of its table in the bundle.
    pub table: usize,
}

/// A bundle's content: its tables with their headers, and the pairs of the cell it was built
/// for.
#[derive(Clone, Debug)]
pub struct Bundle {
    /// `Cell::fingerprint` of the cell the bundle was built for.
    pub cell_fingerprint: u64,
    /// Robots of that cell.
    pub robots: usize,
    /// The tables; each header's fingerprint is its pair cell's.
    pub tables: Vec<(Header, Table)>,
    /// The pairs that can meet of the built cell and their tables.
    pub pairs: Vec<BundlePair>,
}

/// The tables `cell` needs: its pairs that can meet, each with the index of its pair cell in
/// the returned list of distinct pair cells (first appearance order).
pub fn plan(cell: &Cell) -> (Vec<Cell>, Vec<BundlePair>) {
    let mut cells: Vec<Cell> = Vec::new();
    let mut pairs = Vec::new();
    for (a, b) in cell.pairs_that_can_meet() {
        let pc = pair_cell(cell, a, b);
        let fingerprint = pc.fingerprint();
        let table = match cells.iter().position(|c| c.fingerprint() == fingerprint) {
            Some(i) => i,
            None => {
                cells.push(pc);
                cells.len() - 1
            }
        };
        pairs.push(BundlePair { a, b, table });
    }
    (cells, pairs)
}

/// The bytes of a bundle for the cell with `cell_fingerprint` and `robots` robots: `tables`
/// are the table files' bytes (`format::to_bytes`) in the order `pairs` index them.
///
/// # Errors
/// [`TableError::BadInput`] when a pair names a table that is not given, a table's bytes are
/// not a table file, or there are more than 496 tables or pairs.
pub fn bundle_to_bytes(
    cell_fingerprint: u64,
    robots: usize,
    tables: &[Vec<u8>],
    pairs: &[BundlePair],
) -> Result<Vec<u8>, TableError> {
    let bad = |what: String| TableError::BadInput { what };
    if tables.len() > MAX_ENTRIES as usize || pairs.len() > MAX_ENTRIES as usize {
        return Err(bad(format!(
            "{} tables and {} pairs, at most {MAX_ENTRIES} each",
            tables.len(),
            pairs.len()
        )));
    }
    if let Some(p) = pairs.iter().find(|p| p.table >= tables.len() || p.a >= p.b || p.b >= robots) {
        return Err(bad(format!(
            "pair {p:?} of {robots} robots names table {} of {}",
            p.table,
            tables.len()
        )));
    }
    let mut out = Vec::new();
    out.extend_from_slice(&BUNDLE_MAGIC);
    for v in [ENDIAN_MARK, BUNDLE_VERSION] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&cell_fingerprint.to_le_bytes());
    for v in [robots, tables.len(), pairs.len(), 0] {
        out.extend_from_slice(&(v as u32).to_le_bytes());
    }
    let mut offset = 40 + 32 * tables.len() + 16 * pairs.len();
    for t in tables {
        let (header, _) = from_bytes(t).map_err(|e| bad(format!("a bundle's table: {e}")))?;
        for v in [header.cell_fingerprint, offset as u64, t.len() as u64, fnv1a64(t)] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        offset += t.len();
    }
    for p in pairs {
        for v in [p.a, p.b, p.table, 0] {
            out.extend_from_slice(&(v as u32).to_le_bytes());
        }
    }
    tables.iter().for_each(|t| out.extend_from_slice(t));
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    Ok(out)
}

/// What [`build_bundle`] built: per table of the bundle (in its order) the header, the table,
/// the build's report and the table file's bytes; the pairs; the bundle's bytes.
#[cfg(feature = "std")]
pub struct BuiltBundle {
    /// The tables, one per pair cell.
    pub tables: Vec<(Header, Table, super::BuildReport, Vec<u8>)>,
    /// The pairs that can meet and their tables.
    pub pairs: Vec<BundlePair>,
    /// The bundle file's bytes.
    pub bytes: Vec<u8>,
}

/// Builds the table of every pair cell `cell`'s pairs that can meet need ([`plan`]), each
/// once, with [`super::build_table`]'s arguments, and the bundle of them.
///
/// # Errors
/// The first build's error, prefixed by its pair.
#[cfg(feature = "std")]
pub fn build_bundle(
    cell: &Cell,
    k: u32,
    ws: &crate::cspace::Workspace,
    variant: super::Variant,
    labelling: super::Labelling,
    progress: crate::cspace::Progress,
) -> Result<BuiltBundle, String> {
    let (pair_cells, pairs) = plan(cell);
    let mut tables = Vec::with_capacity(pair_cells.len());
    for (i, pc) in pair_cells.iter().enumerate() {
        let first = pairs.iter().find(|p| p.table == i).expect("every pair cell comes from a pair");
        let (header, table, report) = super::build_table(pc, k, ws, variant, labelling, progress)
            .map_err(|e| {
            format!("table {i} for {}: {e}", describe_pair(cell, first.a, first.b))
        })?;
        let bytes = super::to_bytes(&table, &header);
        tables.push((header, table, report, bytes));
    }
    let files: Vec<Vec<u8>> = tables.iter().map(|t| t.3.clone()).collect();
    let bytes = bundle_to_bytes(cell.fingerprint(), cell.robots.len(), &files, &pairs)
        .map_err(|e| e.to_string())?;
    Ok(BuiltBundle { tables, pairs, bytes })
}

/// Whether `bytes` start as a bundle (rather than as a table file).
pub fn is_bundle(bytes: &[u8]) -> bool {
    bytes.starts_with(&BUNDLE_MAGIC)
}

/// Reads and validates a bundle (see the module doc). A table file (magic `DCTABLE\0`) reads
/// as a bundle of that one table and no pairs.
///
/// # Errors
/// The specific [`TableError`]: `Truncated`, `BadMagic`, `WrongEndianness`,
/// `UnsupportedVersion`, or `Corrupt` naming the field (directory, checksums, a table's
/// fingerprint); a table's own errors.
pub fn bundle_from_bytes(bytes: &[u8]) -> Result<Bundle, TableError> {
    if !is_bundle(bytes) {
        let (header, table) = from_bytes(bytes)?;
        return Ok(Bundle {
            cell_fingerprint: header.cell_fingerprint,
            robots: 2,
            tables: vec![(header, table)],
            pairs: vec![],
        });
    }
    let mut r = Reader::<TableError>::new(bytes);
    r.take(8, "bundle magic")?;
    match r.u32("bundle endianness marker")? {
        ENDIAN_MARK => {}
        m if m == ENDIAN_MARK.swap_bytes() => return Err(TableError::WrongEndianness),
        m => {
            return Err(corrupt(format!(
                "bundle endianness marker = {m:#010x}, expected 0x01020304"
            )))
        }
    }
    let version = r.u32("bundle version")?;
    if version != BUNDLE_VERSION {
        return Err(TableError::UnsupportedVersion { found: version, supported: BUNDLE_VERSION });
    }
    let cell_fingerprint = r.u64("bundle cell fingerprint")?;
    let robots = r.u32("bundle robots")?;
    let (n_tables, n_pairs) = (r.u32("bundle table count")?, r.u32("bundle pair count")?);
    if r.u32("bundle reserved")? != 0 {
        return Err(corrupt("bundle reserved field is not 0"));
    }
    if robots as usize > crate::cell::MAX_ROBOTS || n_tables > MAX_ENTRIES || n_pairs > MAX_ENTRIES
    {
        return Err(corrupt(format!(
            "bundle of {robots} robots, {n_tables} tables, {n_pairs} pairs: too many"
        )));
    }
    let mut entries = Vec::with_capacity(n_tables as usize);
    for _ in 0..n_tables {
        let e = [
            r.u64("bundle table fingerprint")?,
            r.u64("bundle table offset")?,
            r.u64("bundle table length")?,
        ];
        entries.push((e, r.u64("bundle table checksum")?));
    }
    let mut pairs = Vec::with_capacity(n_pairs as usize);
    for _ in 0..n_pairs {
        let v = [
            r.u32("bundle pair robot a")?,
            r.u32("bundle pair robot b")?,
            r.u32("bundle pair table")?,
        ];
        if r.u32("bundle pair reserved")? != 0 || !(v[0] < v[1] && v[1] < robots && v[2] < n_tables)
        {
            return Err(corrupt(format!(
                "bundle pair (robot {}, robot {}, table {}) out of range",
                v[0], v[1], v[2]
            )));
        }
        pairs.push(BundlePair { a: v[0] as usize, b: v[1] as usize, table: v[2] as usize });
    }
    let mut next = r.pos() as u64;
    for (i, ([_, offset, len], _)) in entries.iter().enumerate() {
        if *offset != next {
            return Err(corrupt(format!(
                "bundle table {i} starts at {offset}, expected {next} (back to back)"
            )));
        }
        next = offset
            .checked_add(*len)
            .ok_or_else(|| corrupt(format!("bundle table {i} length overflows")))?;
    }
    let body = usize::try_from(next - r.pos() as u64)
        .map_err(|_| corrupt("bundle tables do not fit in memory"))?;
    r.take(body, "bundle tables")?;
    r.checksum()?;
    let mut tables = Vec::with_capacity(entries.len());
    for (i, ([fingerprint, offset, len], sum)) in entries.into_iter().enumerate() {
        let t = &bytes[offset as usize..(offset + len) as usize];
        if fnv1a64(t) != sum {
            return Err(corrupt(format!(
                "bundle table {i}: checksum = {sum:#018x}, its bytes give {:#018x}",
                fnv1a64(t)
            )));
        }
        let (header, table) = from_bytes(t)?;
        if header.cell_fingerprint != fingerprint {
            return Err(corrupt(format!(
                "bundle table {i} records cell {:#018x}, the directory {fingerprint:#018x}",
                header.cell_fingerprint
            )));
        }
        tables.push((header, table));
    }
    Ok(Bundle { cell_fingerprint, robots: robots as usize, tables, pairs })
}

/// How a pair of robots stands, for messages: `R2-R3 (robots 1 and 2: R3 at (450, 0, 0) mm,
/// alpha 0 rad from R2)`.
pub fn describe_pair(cell: &Cell, a: usize, b: usize) -> String {
    let pc = pair_cell(cell, a, b);
    let (p, names) = (pc.robots[1].placement, (&cell.robots[a].name, &cell.robots[b].name));
    format!(
        "{}-{} (robots {a} and {b}: {} at ({}, {}, {}) mm, alpha {} rad from {})",
        names.0,
        names.1,
        names.1,
        p.t.x + 0.0,
        p.t.y + 0.0,
        p.t.z + 0.0,
        p.alpha + 0.0,
        names.0
    )
}

impl Bundle {
    /// The table that answers for robots `a` and `b` of `cell`: the one built for their pair
    /// cell (found by its fingerprint).
    ///
    /// # Errors
    /// [`TableError::WrongPair`] when the bundle names a table for this pair that was built
    /// for another placement or model (the message names the value that differs);
    /// [`TableError::MissingPair`] when it holds none.
    pub fn table_for(&self, cell: &Cell, a: usize, b: usize) -> Result<usize, TableError> {
        let pc = pair_cell(cell, a, b);
        let fingerprint = pc.fingerprint();
        if let Some(i) = self.tables.iter().position(|(h, _)| h.cell_fingerprint == fingerprint) {
            return Ok(i);
        }
        let pair = describe_pair(cell, a, b);
        if let Some(p) = self.pairs.iter().find(|p| (p.a, p.b) == (a, b)) {
            let differs = match self.tables[p.table].0.check_cell_parameters(&pc) {
                Err(TableError::WrongCell { differs: Some(d), .. }) => d,
                _ => String::from("its pair cell's fingerprint differs"),
            };
            return Err(TableError::WrongPair {
                what: format!(
                    "the bundle's table for {pair} was built for another pair: {differs}"
                ),
            });
        }
        Err(TableError::MissingPair {
            what: format!(
                "the bundle holds no table for {pair} ({} tables, none for this pair cell)",
                self.tables.len()
            ),
        })
    }
}
