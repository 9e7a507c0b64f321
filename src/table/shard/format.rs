//! The shard file format: a fixed little-endian header, both robots' sampling grids, the
//! shard's labels packed 2 bits each, its sub-cells or its clearance levels, and a checksum,
//! validated once when read.
//!
//! # Layout (all integers and floats little-endian)
//! ```text
//! offset size  field
//!      0    8  magic b"DCSHARD\0"
//!      8    4  endianness marker 0x01020304
//!     12    4  shard format version (VERSION)
//!     16    4  shard index i        20  4  shard count n
//!     24    4  k                    28  4  table kind (position in TableKind::ALL)
//!     32    4  threshold t (4-D kinds, else 0)
//!     36    4  labelling: 0 certified, 1 thesis
//!     40    4  symmetry: 0 whole, 1 mirrored in y
//!     44    4  flags: bit 0 = sub-cells follow (shared-sub only)
//!     48    8  seconds spent labelling   56  8  of which on sub-cells
//!     64    8  cell fingerprint     72  8  r (mm)
//!     80   24  origin of A's grid  104 24  origin of B's grid (mm)
//!    128   40  workspace Zu, Hcy, Rcy, Hco, Rco (mm)
//!    168    8  margin (mm)         176  4  certification
//!    180    4  n, clearance levels (kind clearance: 1 to 16; else 0)
//!    184    8  n_p, cell parameters     192  8  na, samples of A   200  8  nb, samples of B
//!    208    8  rows labelled: those of Rows { first: i, step: n } below na
//!    216    8  m, sub-cell entries
//!    224  8 n_p  the cell's parameter values (f64)
//!          7 na  A's sample cells: ix, iy, iz (u16 each), then one byte per sample, 1 when its
//!                centre is reachable
//!          7 nb  B's, likewise
//!          ceil(rows nb / 4)  labels, 2 bits each (0 free, 1 collision, 2 unreachable), row
//!                after row, label `j` at bits 2 (j mod 4) of byte j / 4; unused bits 0
//!         24 m   sub-cells: pair ia nb + ib, care mask, collision mask (u64 each), pairs
//!                increasing, each in a row of this shard
//!          8 n   the clearance ladder (f64, mm, increasing)
//!          rows nb (n > 0 only) per pair, how many of the n levels are proved (one byte,
//!                at most n; 0 for a pair not labelled free), in the labels' order
//!    end-8  8  FNV-1a 64 of every byte before it
//! ```

use super::error::{corrupt, ShardError};
use super::ShardIndex;
use crate::cell::{fingerprint_of, fnv1a64};
use crate::cspace::{CellIndex, SampleGrid, Symmetry, Workspace};
use crate::math::Vec3;
use crate::table::build::{Labelling, RowLabels};
use crate::table::clearance::MAX_RUNGS;
use crate::table::reader::Reader;
use crate::table::{Certification, Header, Ladder, TableKind};

/// The first eight bytes of every shard file.
pub const MAGIC: [u8; 8] = *b"DCSHARD\0";
/// The shard format version written and read.
pub const VERSION: u32 = 2;
const ENDIAN_MARK: u32 = 0x0102_0304;
const FIXED_LEN: usize = 224;
/// Most cell parameters a shard records (as a table file).
const MAX_CELL_PARAMETERS: u64 = 4096;

/// Everything a shard file records besides its grids, labels and sub-cells.
#[derive(Clone, Debug, PartialEq)]
pub struct ShardInfo {
    /// Which shard of how many.
    pub shard: ShardIndex,
    /// Grid cells per axis.
    pub k: u32,
    /// The table the shards are for.
    pub kind: TableKind,
    /// Its similarity threshold (4-D kinds; else 0).
    pub t: u32,
    /// How the shard was labelled.
    pub labelling: Labelling,
    /// The cell's symmetry, which the table builder needs.
    pub symmetry: Symmetry,
    /// Seconds the shard spent labelling.
    pub label_secs: f64,
    /// Of which on the sub-cells.
    pub sub_secs: f64,
    /// The header of the table the merge writes (cell fingerprint and parameters, grids'
    /// spacing and origins, workspace, margin, certification).
    pub header: Header,
    /// Samples of A and of B.
    pub samples: (usize, usize),
    /// Rows of A labelled in this shard.
    pub rows: usize,
    /// Sub-cell entries.
    pub sub_entries: usize,
    /// The clearance ladder (kind clearance only).
    pub ladder: Option<Ladder>,
}

/// A shard file read and validated, its bulk left in place.
pub(super) struct Parsed<'a> {
    pub info: ShardInfo,
    /// Both grids as stored (compared between shards).
    pub grid_bytes: &'a [u8],
    pub grid_a: SampleGrid,
    pub grid_b: SampleGrid,
    /// The packed labels.
    pub labels: &'a [u8],
    /// The sub-cell entries, 24 bytes each.
    pub sub: &'a [u8],
    /// Per pair of the rows, its proved clearance level count (kind clearance; else empty).
    pub counts: &'a [u8],
}

fn put(out: &mut Vec<u8>, v: &[u8]) {
    out.extend_from_slice(v);
}

fn put_grid(out: &mut Vec<u8>, g: &SampleGrid) {
    g.cells.iter().flatten().for_each(|v| put(out, &v.to_le_bytes()));
    g.reachable.iter().for_each(|&r| out.push(u8::from(r)));
}

/// The bytes of a shard with `info` and the labels of its rows (see the module doc).
pub(super) fn to_bytes(info: &ShardInfo, labels: &RowLabels) -> Vec<u8> {
    let h = &info.header;
    let (ga, gb) = (&labels.space.grid_a, &labels.space.grid_b);
    let n = labels.space.labels.len();
    let mut out = Vec::with_capacity(
        FIXED_LEN
            + 8 * h.cell_parameters.len()
            + 7 * (ga.cells.len() + gb.cells.len())
            + n / 4
            + 32,
    );
    put(&mut out, &MAGIC);
    let kind = TableKind::ALL.iter().position(|&k| k == info.kind).unwrap_or(0) as u32;
    let labelling = u32::from(info.labelling == Labelling::ThesisMargin);
    let flags = u32::from(labels.sub.is_some());
    let (i, count) = (info.shard.index(), info.shard.count());
    let symmetric = u32::from(info.symmetry.is_mirrored());
    for v in [ENDIAN_MARK, VERSION, i, count, info.k, kind, info.t, labelling, symmetric, flags] {
        put(&mut out, &v.to_le_bytes());
    }
    put(&mut out, &info.label_secs.to_le_bytes());
    put(&mut out, &info.sub_secs.to_le_bytes());
    put(&mut out, &h.cell_fingerprint.to_le_bytes());
    let w = &h.workspace;
    let floats = [h.r].into_iter().chain(h.origin_a).chain(h.origin_b);
    for v in floats.chain([w.zu, w.hcy, w.rcy, w.hco, w.rco, h.margin]) {
        put(&mut out, &v.to_le_bytes());
    }
    put(&mut out, &(h.certification as u32).to_le_bytes());
    let clearance = labels.clearance.first().filter(|_| info.kind == TableKind::Clearance);
    put(&mut out, &(clearance.map_or(0, |(l, _)| l.len()) as u32).to_le_bytes());
    let sub = labels.sub.as_ref();
    for v in [
        h.cell_parameters.len(),
        ga.cells.len(),
        gb.cells.len(),
        info.rows,
        sub.map_or(0, |s| s.pairs.len()),
    ] {
        put(&mut out, &(v as u64).to_le_bytes());
    }
    h.cell_parameters.iter().for_each(|v| put(&mut out, &v.to_le_bytes()));
    put_grid(&mut out, ga);
    put_grid(&mut out, gb);
    put(&mut out, labels.space.labels.bytes());
    if let Some(s) = sub {
        for ((p, c), x) in s.pairs.iter().zip(&s.care).zip(&s.collision) {
            [p, c, x].iter().for_each(|v| put(&mut out, &v.to_le_bytes()));
        }
    }
    if let Some((ladder, counts)) = clearance {
        ladder.mm().iter().for_each(|v| put(&mut out, &v.to_le_bytes()));
        put(&mut out, counts);
    }
    let sum = fnv1a64(&out);
    put(&mut out, &sum.to_le_bytes());
    out
}

/// The prefix up to the header fields: magic, endianness, version.
fn read_prefix(r: &mut Reader<ShardError>) -> Result<(), ShardError> {
    let magic = r.take(8, "magic")?;
    if magic != MAGIC {
        return Err(ShardError::BadMagic { table: magic == crate::table::format::MAGIC });
    }
    match r.u32("endianness marker")? {
        ENDIAN_MARK => {}
        m if m == ENDIAN_MARK.swap_bytes() => return Err(ShardError::WrongEndianness),
        m => return Err(corrupt(format!("endianness marker = {m:#010x}, expected 0x01020304"))),
    }
    match r.u32("version")? {
        VERSION => Ok(()),
        found => Err(ShardError::UnsupportedVersion { found, supported: VERSION }),
    }
}

/// One robot's grid: `n` cells and their reachability, at spacing `r` from `origin`.
fn read_grid(
    r: &mut Reader<ShardError>,
    n: usize,
    k: u32,
    spacing: f64,
    origin: [f64; 3],
) -> Result<SampleGrid, ShardError> {
    let cells: Vec<CellIndex> = r
        .items(n, 6, "grid cells")?
        .chunks_exact(6)
        .map(|c| [0, 2, 4].map(|i| u16::from_le_bytes([c[i], c[i + 1]])))
        .collect();
    if let Some(c) = cells.iter().find(|c| c.iter().any(|&v| u32::from(v) >= k)) {
        return Err(corrupt(format!("grid cell {c:?} has an index >= k = {k}")));
    }
    if cells.windows(2).any(|w| w[0] >= w[1]) {
        return Err(corrupt("grid cells are not in increasing (ix, iy, iz) order"));
    }
    let reach = r.items(n, 1, "grid reachability")?;
    if reach.iter().any(|&b| b > 1) {
        return Err(corrupt("grid reachability byte other than 0 or 1"));
    }
    let reachable = reach.iter().map(|&b| b == 1).collect();
    Ok(SampleGrid {
        k,
        levels: k.trailing_zeros(),
        r: spacing,
        origin: Vec3::from(origin),
        cells,
        reachable,
    })
}

/// Reads and validates a shard file (see the module doc); its labels and sub-cells stay in
/// `bytes`.
///
/// # Errors
/// The specific [`ShardError`]: `Truncated`, `BadMagic`, `WrongEndianness`,
/// `UnsupportedVersion`, or `Corrupt` naming the field (checksum, lengths, indices, labels).
pub(super) fn parse(bytes: &[u8]) -> Result<Parsed<'_>, ShardError> {
    let mut r = Reader::<ShardError>::new(bytes);
    read_prefix(&mut r)?;
    let (index, count, k) = (r.u32("shard index")?, r.u32("shard count")?, r.u32("k")?);
    let shard =
        ShardIndex::new(index, count).map_err(|_| corrupt(format!("shard {index} of {count}")))?;
    if !(2..=1 << crate::table::code::MAX_LEVELS).contains(&k) || !k.is_power_of_two() {
        return Err(corrupt(format!("k = {k} is not a power of two from 2 to 256")));
    }
    let kind_number = r.u32("table kind")?;
    let kind = *TableKind::ALL.get(kind_number as usize).ok_or_else(|| {
        corrupt(format!("table kind = {kind_number}, expected 0 to {}", TableKind::ALL.len() - 1))
    })?;
    let t = r.u32("threshold t")?;
    let labelling = match r.u32("labelling")? {
        0 => Labelling::Certified,
        1 => Labelling::ThesisMargin,
        v => return Err(corrupt(format!("labelling = {v}, expected 0 or 1"))),
    };
    let symmetry = match r.u32("symmetry")? {
        0 => Symmetry::Whole,
        1 => Symmetry::MirrorY,
        v => return Err(corrupt(format!("symmetry = {v}, expected 0 or 1"))),
    };
    let flags = r.u32("flags")?;
    if t != 0 && !kind.has_threshold()
        || flags > 1
        || (flags == 1) != (kind == TableKind::SharedSub)
    {
        return Err(corrupt(format!("kind {kind} with threshold t = {t} and flags = {flags:#x}")));
    }
    let (label_secs, sub_secs) = (r.f64("label seconds")?, r.f64("sub-cell seconds")?);
    let cell_fingerprint = r.u64("cell fingerprint")?;
    let spacing = r.f64("r")?;
    let (origin_a, origin_b) = (r.f64x3("origin_a")?, r.f64x3("origin_b")?);
    let ws: [f64; 5] = [
        r.f64("workspace")?,
        r.f64("workspace")?,
        r.f64("workspace")?,
        r.f64("workspace")?,
        r.f64("workspace")?,
    ];
    let margin = r.f64("margin")?;
    let certification = match r.u32("certification")? {
        1 => Certification::ThesisBlowUp,
        2 => Certification::SweptBound,
        c => return Err(corrupt(format!("certification = {c}, expected 1 or 2"))),
    };
    let rungs = r.u32("clearance levels")?;
    let clearance = kind == TableKind::Clearance;
    if clearance != (1..=MAX_RUNGS as u32).contains(&rungs) || !clearance && rungs != 0 {
        return Err(corrupt(format!(
            "kind {kind} with {rungs} clearance levels (clearance: 1 to {MAX_RUNGS}, else 0)"
        )));
    }
    let n_params = r.u64("cell parameter count")?;
    let (na, nb, rows, m) = (
        r.size("samples of A")?,
        r.size("samples of B")?,
        r.size("rows")?,
        r.size("sub-cell count")?,
    );
    if n_params > MAX_CELL_PARAMETERS {
        return Err(corrupt(format!(
            "cell parameter count = {n_params} exceeds {MAX_CELL_PARAMETERS}"
        )));
    }
    if rows != shard.rows().count(na) {
        return Err(corrupt(format!(
            "{rows} rows, shard {index} of {count} of {na} samples has {}",
            shard.rows().count(na)
        )));
    }
    if m > 0 && kind != TableKind::SharedSub {
        return Err(corrupt(format!("{m} sub-cell entries in a shard of kind {kind}")));
    }
    let cell_parameters =
        (0..n_params).map(|_| r.f64("cell parameter")).collect::<Result<Vec<_>, _>>()?;
    if fingerprint_of(cell_parameters.iter().copied()) != cell_fingerprint {
        return Err(corrupt("cell parameters do not give the recorded cell fingerprint"));
    }
    let grids_start = r.pos();
    let grid_a = read_grid(&mut r, na, k, spacing, origin_a)?;
    let grid_b = read_grid(&mut r, nb, k, spacing, origin_b)?;
    let grid_bytes = &bytes[grids_start..r.pos()];
    let pairs = rows.checked_mul(nb).ok_or_else(|| corrupt("rows x samples of B overflows"))?;
    let labels = r.take(pairs.div_ceil(4), "labels")?;
    let sub = r.items(m, 24, "sub-cells")?;
    let ladder_mm = (0..rungs).map(|_| r.f64("clearance level")).collect::<Result<Vec<_>, _>>()?;
    let counts = if clearance { r.items(pairs, 1, "clearance counts")? } else { &[] };
    r.checksum()?;
    check_labels(labels, pairs)?;
    check_sub_cells(sub, shard, na, nb)?;
    let ladder = match clearance {
        true => {
            Some(Ladder::new(&ladder_mm).map_err(|e| corrupt(format!("clearance ladder: {e}")))?)
        }
        false => None,
    };
    check_counts(counts, labels, rungs)?;
    let workspace = Workspace { zu: ws[0], hcy: ws[1], rcy: ws[2], hco: ws[3], rco: ws[4] };
    let header = Header {
        cell_fingerprint,
        r: spacing,
        origin_a,
        origin_b,
        workspace,
        margin,
        certification,
        cell_parameters,
    };
    let info = ShardInfo {
        shard,
        k,
        kind,
        t,
        labelling,
        symmetry,
        label_secs,
        sub_secs,
        header,
        samples: (na, nb),
        rows,
        sub_entries: m,
        ladder,
    };
    Ok(Parsed { info, grid_bytes, grid_a, grid_b, labels, sub, counts })
}

/// What shard file `bytes` records, validated as [`merge_shards`](super::merge_shards)
/// validates it (its labels and sub-cells too).
///
/// # Errors
/// As the merge, for this file: `Truncated`, `BadMagic`, `WrongEndianness`,
/// `UnsupportedVersion` or `Corrupt`.
pub fn read_shard_info(bytes: &[u8]) -> Result<ShardInfo, ShardError> {
    parse(bytes).map(|p| p.info)
}

/// No label is 3, and the bits after the last label are 0.
fn check_labels(packed: &[u8], pairs: usize) -> Result<(), ShardError> {
    if let Some(i) = packed.iter().position(|&b| (0..4).any(|j| b >> (2 * j) & 3 == 3)) {
        return Err(corrupt(format!("labels byte {i} holds the undefined label 3")));
    }
    let used = pairs % 4;
    if used != 0 && packed.last().is_some_and(|&b| b >> (2 * used) != 0) {
        return Err(corrupt("bits after the last label are not 0"));
    }
    Ok(())
}

/// Every clearance count at most `n`, and 0 on a pair not labelled free (the counts of the
/// one-shot build, `clearance_counts`, are).
fn check_counts(counts: &[u8], packed: &[u8], n: u32) -> Result<(), ShardError> {
    for (j, &c) in counts.iter().enumerate() {
        let free = packed[j / 4] >> (2 * (j % 4)) & 3 == 0;
        if u32::from(c) > n || c > 0 && !free {
            return Err(corrupt(format!(
                "clearance count {c} of pair {j}: above {n} levels, or on a pair not free"
            )));
        }
    }
    Ok(())
}

/// Sub-cell pairs increasing, each in one of the shard's rows.
fn check_sub_cells(sub: &[u8], shard: ShardIndex, na: usize, nb: usize) -> Result<(), ShardError> {
    let mut last = None;
    for e in sub.chunks_exact(24) {
        let pair = u64::from_le_bytes(core::array::from_fn(|i| e[i]));
        let ia = pair / nb.max(1) as u64;
        if ia >= na as u64
            || ia % u64::from(shard.count()) != u64::from(shard.index())
            || last >= Some(pair)
        {
            return Err(corrupt(format!(
                "sub-cell pair {pair} is not in this shard's rows, or out of order"
            )));
        }
        last = Some(pair);
    }
    Ok(())
}
