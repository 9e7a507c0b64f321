//! The table file format: a fixed little-endian header, up to three sections and a checksum,
//! validated once when loaded from a memory buffer (SPEC §6).
//!
//! # Layout (all integers and floats little-endian)
//! ```text
//! offset size  field
//!      0    8  magic b"DCTABLE\0"
//!      8    4  endianness marker 0x01020304 (reads 0x04030201 when byte-swapped)
//!     12    4  format version (VERSION)
//!     16    4  variant: 6, 5, 4, 7 (the shared 6-D quadtree) or 8 (clearance levels)
//!     20    4  levels        24  4  k = 2^levels
//!     28    4  flags: bit 0 = symmetric (reflection, thesis 3.2.8); bit 1 = sub-cells (one
//!              extra level, variant 7 only); bit 2 = packed child indices (variant 8
//!              only, set by every writer; files without it hold them as u32); other bits 0
//!     32    4  slice axes: 0 (6D, 5D), 1 = yy', 2 = zz' (4D)
//!     36    4  similarity threshold t (0 unless 4D); variant 8: the number n of clearance levels
//!     40    8  fingerprint of the cell (`Cell::fingerprint`)
//!     48    8  r (mm)        56 24  origin of A's grid (mm)    80 24  origin of B's grid
//!    104   40  workspace Zu, Hcy, Rcy, Hco, Rco (mm)
//!    144    8  margin (mm)  152  4  certification kind       156  4  reserved, 0
//!    160   24  element counts of sections 0, 1, 2 (u64 each)
//!    184    8  n, the number of cell parameters
//!    192   8n  the cell's parameter values (`Cell::parameters`, f64 each), so that a table
//!              refused for another cell names the field that differs
//!              section 0: codes, u64 each
//!              section 1: 5D offsets (m + 1) / 4D slice index per code, u32 each; 6D none
//!              section 2: 5D intervals [begin, end] u8 pairs / 4D slice words u64; 6D none
//!              variant 7: section 0 = node masks [nonuniform, collision] then leaves (u64);
//!              section 1 = depth starts (levels entries) then per-node bases (u32);
//!              section 2 = child indices (u32); bases are the running counts (as
//!              written; loading lays the nodes out again for the query, `shared6d/pool.rs`)
//!              variant 8 (flag bit 1 clear), two shared trees, exact then level
//!              (`clearance/mod.rs`): section 0 = the n levels in mm (f64 bits), then
//!              shift, nodes and leaves of the exact tree, nodes and leaves of the level
//!              tree (u64 each), then per tree masks then leaves; section 1 = per tree depth
//!              starts (levels, then levels - shift + 1 entries) then bases; section 2 = per
//!              tree child indices (the exact tree's: its masks' non-uniform count), packed
//!              (bit 2; section 2's count is then in bytes): each inner depth's indices in
//!              1, 2 or 4 bytes as what they point into (the next depth's nodes, the leaves
//!              after the last inner depth) has at most 256, 65,536 or more entries
//!              (`clearance::child_width`)
//!    end-8  8  FNV-1a 64 of every byte before it
//! ```
//! Loading checks magic, endianness and version first (so those errors are specific), then
//! every length with checked arithmetic, the checksum, and finally every field and index
//! (via the variants' `from_parts`), so a loaded table never panics nor reads out of bounds.

use super::clearance::{ClearanceTable, TreeParts};
use super::error::{corrupt, TableError};
use super::quadtree4d::{LinearQuadtree4d, SliceAxes};
use super::quadtree5d::LinearQuadtree5d;
use super::quadtree6d::LinearQuadtree6d;
use super::reader::Reader;
use super::shared6d::{SharedParts, SharedQuadtree6d};
use super::{Table, TableKind};
#[cfg(feature = "std")]
use crate::cspace::LabelledSpace;
use crate::cspace::Workspace;
use alloc::{format, vec, vec::Vec};

/// The first eight bytes of every table.
pub const MAGIC: [u8; 8] = *b"DCTABLE\0";
/// The format version written and read.
pub const VERSION: u32 = 2;
const ENDIAN_MARK: u32 = 0x0102_0304;
/// Flag bit 2: a clearance table's child indices packed (module doc).
const PACKED_CHILDREN: u32 = 4;
const HEADER_LEN: usize = 184;

/// How the margin the table was labelled with was obtained (SPEC §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Certification {
    /// Not recorded.
    Unspecified = 0,
    /// The thesis's blow-up by r / sqrt 2 (3.2.7): not a proof.
    ThesisBlowUp = 1,
    /// A per-cell bound on how far any link point moves within a grid cell: a proof.
    SweptBound = 2,
}

/// Everything a table file records besides the table itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// `Cell::fingerprint` of the cell the table was built for.
    pub cell_fingerprint: u64,
    /// Grid spacing (mm).
    pub r: f64,
    /// Corner of A's grid (mm, A's MCS).
    pub origin_a: [f64; 3],
    /// Corner of B's grid (mm, B's MCS).
    pub origin_b: [f64; 3],
    /// The workspace the grids sample.
    pub workspace: Workspace,
    /// Margin added to every box half-extent when labelling (mm).
    pub margin: f64,
    /// How the margin was obtained.
    pub certification: Certification,
    /// The values of `Cell::parameters` of the cell the table was built for (their hash is
    /// `cell_fingerprint`); empty when the builder did not record them.
    pub cell_parameters: Vec<f64>,
}

impl Header {
    /// The header of a table built from `space` for the cell with `fingerprint`.
    #[cfg(feature = "std")]
    pub fn for_space(
        space: &LabelledSpace,
        fingerprint: u64,
        workspace: Workspace,
        certification: Certification,
    ) -> Header {
        let o = |g: &crate::cspace::SampleGrid| [g.origin.x, g.origin.y, g.origin.z];
        Header {
            cell_fingerprint: fingerprint,
            r: space.grid_a.r,
            origin_a: o(&space.grid_a),
            origin_b: o(&space.grid_b),
            workspace,
            margin: space.margin,
            certification,
            cell_parameters: Vec::new(),
        }
    }

    /// The header for `cell`: its fingerprint and parameter values recorded.
    #[cfg(feature = "std")]
    pub fn for_cell(
        space: &LabelledSpace,
        cell: &crate::cell::Cell,
        workspace: Workspace,
        certification: Certification,
    ) -> Header {
        Header {
            cell_parameters: cell.parameters().into_iter().map(|(_, v)| v).collect(),
            ..Header::for_space(space, cell.fingerprint(), workspace, certification)
        }
    }

    /// Checks that the table was built for the controller's cell.
    ///
    /// # Errors
    /// [`TableError::WrongCell`] when the fingerprints differ.
    pub fn check_cell(&self, expected: u64) -> Result<(), TableError> {
        if self.cell_fingerprint == expected {
            Ok(())
        } else {
            Err(TableError::WrongCell { expected, found: self.cell_fingerprint, differs: None })
        }
    }

    /// Checks that the table was built for `cell`, naming the first parameter that differs
    /// when the table recorded its cell's parameters.
    ///
    /// # Errors
    /// [`TableError::WrongCell`] when the fingerprints differ.
    pub fn check_cell_parameters(&self, cell: &crate::cell::Cell) -> Result<(), TableError> {
        let expected = cell.fingerprint();
        if self.cell_fingerprint == expected {
            return Ok(());
        }
        let ours = cell.parameters();
        let stored = &self.cell_parameters;
        let differs = if stored.is_empty() {
            None
        } else if let Some(((name, v), t)) =
            ours.iter().zip(stored).find(|((_, v), t)| v.to_bits() != t.to_bits())
        {
            Some(format!("{name} is {t} in the table's cell and {v} in this one"))
        } else {
            Some(format!(
                "the table's cell has {} parameters, this one {}",
                stored.len(),
                ours.len()
            ))
        };
        Err(TableError::WrongCell { expected, found: self.cell_fingerprint, differs })
    }
}

pub use crate::cell::fnv1a64;

/// The bytes of `table` with `header` (see the module doc for the layout).
pub fn to_bytes(table: &Table, header: &Header) -> Vec<u8> {
    let owned: Vec<u64>;
    let variant = TableKind::of(table).file_variant();
    let (axes, t, s0, s1, s2): (u32, u32, &[u64], Vec<u32>, Vec<u8>) = match table {
        Table::D6(q) => (0, 0, q.codes(), vec![], vec![]),
        Table::D5(q) => {
            let (codes, offsets, ivs) = q.parts();
            (0, 0, codes, offsets.to_vec(), ivs.iter().flatten().copied().collect())
        }
        Table::D4(q) => {
            let (codes, slice_of, words) = q.parts();
            let axes = if q.axes() == SliceAxes::YY { 1 } else { 2 };
            (
                axes,
                q.threshold(),
                codes,
                slice_of.to_vec(),
                words.iter().flat_map(|w| w.to_le_bytes()).collect(),
            )
        }
        Table::Shared(q) => {
            let (words, aux, children) = shared_sections(&[], q.parts());
            owned = words;
            (0, 0, &owned[..], aux, children)
        }
        Table::Clearance(q) => {
            let (e, l) = q.parts();
            let mut head: Vec<u64> = q.ladder().mm().iter().map(|v| v.to_bits()).collect();
            let len = |n: usize| n as u64;
            head.extend([
                u64::from(q.shift()),
                len(e.masks.len()),
                len(e.leaves.len()),
                len(l.masks.len()),
                len(l.leaves.len()),
            ]);
            owned = head.into_iter().chain(tree_words(&e)).chain(tree_words(&l)).collect();
            let aux = e
                .depth_start
                .iter()
                .chain(&e.bases)
                .chain(&l.depth_start)
                .chain(&l.bases)
                .copied()
                .collect();
            let children = [e.packed_children(), l.packed_children()].concat();
            (0, q.ladder().len() as u32, &owned[..], aux, children)
        }
    };
    let n2 = match variant {
        5 => s2.len() / 2,
        7 => s2.len() / 4,
        8 => s2.len(),
        _ => s2.len() / 8,
    };
    let mut out = Vec::with_capacity(HEADER_LEN + 8 * s0.len() + 4 * s1.len() + s2.len() + 8);
    out.extend_from_slice(&MAGIC);
    let levels = table.levels();
    let packed = if variant == 8 { PACKED_CHILDREN } else { 0 };
    let flags = u32::from(table.symmetric()) | table.sub_levels() << 1 | packed;
    for v in [ENDIAN_MARK, VERSION, variant, levels, 1 << levels, flags, axes, t] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&header.cell_fingerprint.to_le_bytes());
    let w = &header.workspace;
    let floats = [header.r].into_iter().chain(header.origin_a).chain(header.origin_b);
    for v in floats.chain([w.zu, w.hcy, w.rcy, w.hco, w.rco, header.margin]) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&(header.certification as u32).to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    for n in [s0.len(), s1.len(), n2, header.cell_parameters.len()] {
        out.extend_from_slice(&(n as u64).to_le_bytes());
    }
    header.cell_parameters.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    s0.iter().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
    s1.iter().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
    out.extend_from_slice(&s2);
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// The sections of a shared tree: `head` then masks then leaves (u64), depth starts then
/// bases (u32), child indices as bytes.
fn shared_sections(head: &[u64], p: SharedParts) -> (Vec<u64>, Vec<u32>, Vec<u8>) {
    let words = head.iter().chain(p.masks.iter().flatten()).chain(&p.leaves).copied().collect();
    let aux = p.depth_start.iter().chain(&p.bases).copied().collect();
    (words, aux, p.children.to_u32().iter().flat_map(|c| c.to_le_bytes()).collect())
}

/// A tree's masks then leaves, as section 0 holds them.
fn tree_words(p: &TreeParts) -> impl Iterator<Item = u64> + '_ {
    p.masks.iter().flatten().chain(&p.leaves).copied()
}

/// Fixed header fields that decide the table's shape.
struct Shape {
    variant: u32,
    levels: u32,
    sub_levels: u32,
    symmetric: bool,
    /// Variant 8 only: child indices packed (flag bit 2).
    packed: bool,
    axes: u32,
    t: u32,
}

fn read_prefix(r: &mut Reader<TableError>) -> Result<Shape, TableError> {
    let magic = r.take(8, "magic")?;
    if magic != MAGIC {
        return Err(TableError::BadMagic { found: core::array::from_fn(|i| magic[i]) });
    }
    match r.u32("endianness marker")? {
        ENDIAN_MARK => {}
        m if m == ENDIAN_MARK.swap_bytes() => return Err(TableError::WrongEndianness),
        m => return Err(corrupt(format!("endianness marker = {m:#010x}, expected 0x01020304"))),
    }
    let version = r.u32("version")?;
    if version != VERSION {
        return Err(TableError::UnsupportedVersion { found: version, supported: VERSION });
    }
    let variant = r.u32("variant")?;
    let levels = r.u32("levels")?;
    let k = r.u32("k")?;
    let flags = r.u32("flags")?;
    let axes = r.u32("slice axes")?;
    let t = r.u32("threshold t")?;
    if !matches!(variant, 4..=8) {
        return Err(corrupt(format!("variant = {variant}, expected 6, 5, 4, 7 or 8")));
    }
    if levels == 0 || levels > super::code::MAX_LEVELS || k != 1 << levels {
        return Err(corrupt(format!(
            "levels = {levels}, k = {k}: k must be 2^levels, levels in 1..=8"
        )));
    }
    if flags > 7
        || (flags & 2 != 0 && variant != 7)
        || (flags & PACKED_CHILDREN != 0 && variant != 8)
    {
        return Err(corrupt(format!(
            "flags = {flags:#x}: only bit 0 (symmetric), for variant 7 bit 1 (sub-cells) and for variant 8 bit 2 \
             (packed child indices) are defined"
        )));
    }
    let rungs = super::clearance::MAX_RUNGS as u32;
    if variant == 8 && (axes != 0 || !(1..=rungs).contains(&t)) {
        return Err(corrupt(format!(
            "variant 8 with slice axes = {axes}, {t} clearance levels (1 to {rungs})"
        )));
    }
    if (variant == 4 && !matches!(axes, 1 | 2))
        || (!matches!(variant, 4 | 8) && (axes != 0 || t != 0))
    {
        return Err(corrupt(format!("variant {variant} with slice axes = {axes}, t = {t}")));
    }
    let (sub_levels, symmetric, packed) =
        (flags >> 1 & 1, flags & 1 == 1, flags & PACKED_CHILDREN != 0);
    Ok(Shape { variant, levels, sub_levels, symmetric, packed, axes, t })
}

fn read_header(r: &mut Reader<TableError>) -> Result<Header, TableError> {
    let cell_fingerprint = r.u64("cell fingerprint")?;
    let grid_r = r.f64("r")?;
    let origin_a = r.f64x3("origin_a")?;
    let origin_b = r.f64x3("origin_b")?;
    let ws = [
        r.f64("workspace.zu")?,
        r.f64("workspace.hcy")?,
        r.f64("workspace.rcy")?,
        r.f64("workspace.hco")?,
        r.f64("workspace.rco")?,
    ];
    let margin = r.f64("margin")?;
    let certification = match r.u32("certification")? {
        0 => Certification::Unspecified,
        1 => Certification::ThesisBlowUp,
        2 => Certification::SweptBound,
        c => return Err(corrupt(format!("certification = {c}, expected 0, 1 or 2"))),
    };
    if r.u32("reserved")? != 0 {
        return Err(corrupt("reserved field is not 0"));
    }
    if grid_r <= 0.0 || margin < 0.0 {
        return Err(corrupt(format!("r = {grid_r} must be > 0 and margin = {margin} >= 0")));
    }
    let workspace = Workspace { zu: ws[0], hcy: ws[1], rcy: ws[2], hco: ws[3], rco: ws[4] };
    let cell_parameters = Vec::new();
    Ok(Header {
        cell_fingerprint,
        r: grid_r,
        origin_a,
        origin_b,
        workspace,
        margin,
        certification,
        cell_parameters,
    })
}

/// A symmetric table stores only A's half `iy >= k/2` (thesis 3.2.8) and folds every query
/// into it. A code (or a root child of the shared tree) wholly in the other half is never
/// read, so a file that holds one was not written by a symmetric build: refuse it.
///
/// Codes put dimension 1 (`iy`) in the top level's group at index bit `D - 2` (`code.rs`);
/// a 6-D group that is the bare mark (the root, condensed) spans both halves. 4D/yy' tables
/// have no `iy` in their codes: their slices start at row `k/2` by construction.
fn check_unstored_half(shape: &Shape, words: &[u64]) -> Result<(), TableError> {
    let top = |stride: u32, c: u64| (c >> (stride * (shape.levels - 1))) & ((1 << stride) - 1);
    let lower = |i: usize| {
        corrupt(format!("symmetric table has codes[{i}] in the half it does not store (iy < k/2)"))
    };
    match shape.variant {
        6 => match words
            .iter()
            .position(|&c| top(7, c) != super::code::MARK && top(7, c) & 1 << 4 == 0)
        {
            Some(i) => Err(lower(i)),
            None => Ok(()),
        },
        5 => words.iter().position(|&c| top(5, c) & 1 << 3 == 0).map_or(Ok(()), |i| Err(lower(i))),
        4 if shape.axes == 2 => {
            words.iter().position(|&c| top(4, c) & 1 << 2 == 0).map_or(Ok(()), |i| Err(lower(i)))
        }
        7 | 8 => {
            // The root's 64 children, child index `bx << 5 | by << 4 | ...`: those with by = 0.
            let lower_children =
                (0..64u64).filter(|c| c >> 4 & 1 == 0).fold(0u64, |m, c| m | 1 << c);
            match words.get(..2) {
                Some(&[nonuniform, collision]) if (nonuniform | collision) & lower_children != 0 => {
                    Err(corrupt("symmetric shared table has root children in the half it does not store (iy < k/2)"))
                }
                _ => Ok(()),
            }
        }
        _ => Ok(()),
    }
}

/// Most cell parameters a table records: 32 robots of at most 30 values, with room to spare.
const MAX_CELL_PARAMETERS: u64 = 4096;

/// The cell parameter values; when present, their fingerprint must be the recorded one.
fn read_cell_parameters(
    r: &mut Reader<TableError>,
    fingerprint: u64,
) -> Result<Vec<f64>, TableError> {
    let n = r.u64("cell parameter count")?;
    if n > MAX_CELL_PARAMETERS {
        return Err(corrupt(format!("cell parameter count = {n} exceeds {MAX_CELL_PARAMETERS}")));
    }
    let values = (0..n).map(|_| r.f64("cell parameter")).collect::<Result<Vec<_>, _>>()?;
    if !values.is_empty() && crate::cell::fingerprint_of(values.iter().copied()) != fingerprint {
        return Err(corrupt("cell parameters do not give the recorded cell fingerprint"));
    }
    Ok(values)
}

fn words<const N: usize, T>(bytes: &[u8], f: impl Fn([u8; N]) -> T) -> Vec<T> {
    bytes.chunks_exact(N).map(|c| f(core::array::from_fn(|i| c[i]))).collect()
}

/// Reads and validates a table (see the module doc); the cell is not checked here, call
/// [`Header::check_cell`] or use [`from_bytes_for_cell`].
///
/// # Errors
/// The specific [`TableError`]: `Truncated`, `BadMagic`, `WrongEndianness`,
/// `UnsupportedVersion`, or `Corrupt` naming the field (checksum, lengths, order, indices).
pub fn from_bytes(bytes: &[u8]) -> Result<(Header, Table), TableError> {
    let mut r = Reader::<TableError>::new(bytes);
    let shape = read_prefix(&mut r)?;
    let mut header = read_header(&mut r)?;
    let counts = [r.u64("section 0 count")?, r.u64("section 1 count")?, r.u64("section 2 count")?];
    header.cell_parameters = read_cell_parameters(&mut r, header.cell_fingerprint)?;
    let sizes: [usize; 3] = match shape.variant {
        6 => [8, 4, 0],
        5 => [8, 4, 2],
        8 if shape.packed => [8, 4, 1],
        7 | 8 => [8, 4, 4],
        _ => [8, 4, 8],
    };
    let names = [
        "section 0 (codes)",
        "section 1 (offsets or slice indices)",
        "section 2 (intervals or slices)",
    ];
    let mut lens = [0usize; 3];
    for i in 0..3 {
        let n = usize::try_from(counts[i]).ok().and_then(|n| n.checked_mul(sizes[i]));
        lens[i] =
            n.ok_or_else(|| corrupt(format!("{} count = {} overflows", names[i], counts[i])))?;
        if sizes[i] == 0 && counts[i] != 0 || shape.variant == 6 && i > 0 && counts[i] != 0 {
            return Err(corrupt(format!(
                "{} count = {} must be 0 for variant {}",
                names[i], counts[i], shape.variant
            )));
        }
    }
    let sections =
        [r.take(lens[0], names[0])?, r.take(lens[1], names[1])?, r.take(lens[2], names[2])?];
    r.checksum()?;
    let mut codes = words(sections[0], u64::from_le_bytes);
    let aux = words(sections[1], u32::from_le_bytes);
    if shape.variant == 8 {
        let n = shape.t as usize;
        if codes.len() < n + 5 {
            return Err(corrupt(format!(
                "section 0 has {} words, fewer than the {n} clearance levels and 5 counts",
                codes.len()
            )));
        }
        let ladder: Vec<f64> = codes.drain(..n).map(f64::from_bits).collect();
        let counts: Vec<u64> = codes.drain(..5).collect();
        if shape.symmetric {
            check_unstored_half(&shape, &codes)?;
        }
        let children = match shape.packed {
            true => Children::Packed(sections[2]),
            false => Children::Wide(words(sections[2], u32::from_le_bytes)),
        };
        let table = clearance_from_sections(&shape, &ladder, &counts, codes, aux, children)?;
        return Ok((header, Table::Clearance(alloc::boxed::Box::new(table))));
    }
    if shape.symmetric {
        check_unstored_half(&shape, &codes)?;
    }
    let table = match shape.variant {
        6 => Table::D6(LinearQuadtree6d::from_parts(shape.levels, shape.symmetric, codes)?),
        5 => {
            let ivs = words(sections[2], |b: [u8; 2]| b);
            Table::D5(LinearQuadtree5d::from_parts(shape.levels, shape.symmetric, codes, aux, ivs)?)
        }
        7 => {
            let starts = (shape.levels + shape.sub_levels) as usize;
            if aux.len() < starts {
                return Err(corrupt(format!(
                    "section 1 has {} entries, fewer than the {starts} depth starts",
                    aux.len()
                )));
            }
            let nodes = aux.len() - starts;
            if codes.len() < 2 * nodes {
                return Err(corrupt(format!(
                    "section 0 has {} words, fewer than 2 per node ({nodes} nodes)",
                    codes.len()
                )));
            }
            let masks = codes[..2 * nodes].chunks_exact(2).map(|m| [m[0], m[1]]).collect();
            let leaves = codes[2 * nodes..].to_vec();
            let children = words(sections[2], u32::from_le_bytes);
            let (starts, bases) = (aux[..starts].to_vec(), aux[starts..].to_vec());
            Table::Shared(SharedQuadtree6d::from_parts(
                shape.levels,
                shape.sub_levels,
                shape.symmetric,
                masks,
                bases,
                starts,
                children,
                leaves,
            )?)
        }
        _ => {
            let axes = if shape.axes == 1 { SliceAxes::YY } else { SliceAxes::ZZ };
            let slices = words(sections[2], u64::from_le_bytes);
            Table::D4(LinearQuadtree4d::from_parts(
                shape.levels,
                shape.symmetric,
                axes,
                shape.t,
                codes,
                aux,
                slices,
            )?)
        }
    };
    Ok((header, table))
}

/// Splits `n` items off the front of `v`, or says which field is short.
fn split_front<T>(v: &mut Vec<T>, n: u64, what: &str) -> Result<Vec<T>, TableError> {
    match usize::try_from(n).ok().filter(|&n| n <= v.len()) {
        Some(n) => Ok(v.drain(..n).collect()),
        None => Err(corrupt(format!("{what}: {n} entries, the section has {} left", v.len()))),
    }
}

/// A clearance table's section 2: child indices packed (flag bit 2) or u32 each.
enum Children<'a> {
    Packed(&'a [u8]),
    Wide(Vec<u32>),
}

/// The two trees of a clearance table from its sections (module doc: variant 8), `counts`
/// being shift, nodes and leaves of the exact tree, nodes and leaves of the level tree.
fn clearance_from_sections(
    shape: &Shape,
    ladder: &[f64],
    counts: &[u64],
    mut words: Vec<u64>,
    mut aux: Vec<u32>,
    mut children: Children,
) -> Result<ClearanceTable, TableError> {
    let &[shift, nodes_e, leaves_e, nodes_l, leaves_l] = counts else {
        return Err(corrupt("clearance table counts"));
    };
    let shift = u32::try_from(shift).ok().filter(|&s| s + 2 <= shape.levels).ok_or_else(|| {
        corrupt(format!(
            "clearance level tree shift = {shift} with levels = {}: need levels - shift >= 2",
            shape.levels
        ))
    })?;
    let mut tree =
        |nodes: u64, leaves: u64, depths: u32, what: &str| -> Result<TreeParts, TableError> {
            let m = split_front(&mut words, nodes.saturating_mul(2), what)?;
            let masks: Vec<[u64; 2]> = m.chunks_exact(2).map(|m| [m[0], m[1]]).collect();
            let leaves = split_front(&mut words, leaves, what)?;
            let depth_start = split_front(&mut aux, u64::from(depths), what)?;
            let bases = split_front(&mut aux, nodes, what)?;
            let children = match &mut children {
                Children::Packed(bytes) => {
                    TreeParts::unpack_children(&masks, &depth_start, leaves.len(), bytes, what)?
                }
                Children::Wide(all) => {
                    let n_children: u64 = masks.iter().map(|m| u64::from(m[0].count_ones())).sum();
                    split_front(all, n_children, what)?
                }
            };
            Ok(TreeParts { masks, bases, depth_start, children, leaves })
        };
    let exact = tree(nodes_e, leaves_e, shape.levels, "clearance exact tree")?;
    let levels = tree(nodes_l, leaves_l, shape.levels - shift + 1, "clearance level tree")?;
    let children_left = match &children {
        Children::Packed(bytes) => bytes.len(),
        Children::Wide(all) => all.len(),
    };
    if !(words.is_empty() && aux.is_empty() && children_left == 0) {
        return Err(corrupt("clearance table sections hold more than their two trees"));
    }
    ClearanceTable::from_parts(shape.levels, shape.symmetric, ladder, shift, exact, levels)
}

/// [`from_bytes`], then [`Header::check_cell`] against the controller's cell fingerprint.
///
/// # Errors
/// As [`from_bytes`], or [`TableError::WrongCell`].
pub fn from_bytes_for_cell(bytes: &[u8], fingerprint: u64) -> Result<(Header, Table), TableError> {
    let (header, table) = from_bytes(bytes)?;
    header.check_cell(fingerprint)?;
    Ok((header, table))
}
