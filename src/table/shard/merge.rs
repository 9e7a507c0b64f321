//! Merging the shards of a table build: check that they are exactly the `n` shards of one
//! build, put their labels and sub-cells together in the one-shot build's order, and build
//! the table from them (the same builder, so the same bytes).

use super::error::ShardError;
use super::format::{parse, Parsed, ShardInfo};
use crate::cspace::pair_labels::label_in;
use crate::cspace::{Label, LabelledSpace, PairLabels, SampleGrid, SubCells};
use crate::table::build::{assemble, RowLabels};
use crate::table::Variant;
use crate::table::{BuildReport, Header, Table, TableKind};

/// Merges the shard files `files` (names, in any order; `read` gives a file's bytes) into
/// the table a one-shot build writes: its header, the table and the build's report
/// (`label_secs` is the sum of the shards' labelling times). The files are read one at a
/// time, each dropped once its labels are copied: the merge holds the whole label set (2
/// bits per pair of samples), the sub-cells and one file. A subdivided table's files are read
/// twice: first for the labels and for how many sub-cell entries each row of A has, then to
/// put each entry at its place in the pair order, so that the sub-cells are held once (a
/// shard's rows are interleaved with the others', so its entries are not in one run).
///
/// # Errors
/// [`ShardError::InFile`] for a file that cannot be read or is not a valid shard (naming it),
/// `Foreign` for a shard of another cell, `k`, variant, labelling or shard count than the
/// first file's, `Duplicate`, `Missing`, `NoShards`, or `Build` when the table builder
/// refuses the labels.
pub fn merge_shards(
    files: &[String],
    read: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
) -> Result<(Header, Table, BuildReport), ShardError> {
    let in_file = |file: &str, error: ShardError| ShardError::InFile {
        file: file.to_string(),
        error: Box::new(error),
    };
    let mut first: Option<First> = None;
    let mut secs = (0.0, 0.0);
    for name in files {
        let bytes = read(name).map_err(|what| in_file(name, ShardError::Unreadable { what }))?;
        let s = parse(&bytes).map_err(|e| in_file(name, e))?;
        let f = match &mut first {
            None => first.insert(First::new(name, &s)),
            Some(f) => {
                if let Some(what) = differs(f, &s) {
                    return Err(ShardError::Foreign {
                        file: name.clone(),
                        first: f.name.clone(),
                        what,
                    });
                }
                f
            }
        };
        let i = s.info.shard.index() as usize;
        if let Some(other) = f.holder[i].replace(name.clone()) {
            return Err(ShardError::Duplicate {
                index: i as u32,
                first: other,
                second: name.clone(),
            });
        }
        let (rows, nb) = (s.info.shard.rows(), s.info.samples.1);
        let mut row = vec![Label::Free; nb];
        for j in 0..s.info.rows {
            let ia = rows.row(j);
            row.iter_mut().enumerate().for_each(|(ib, l)| *l = label_in(s.labels, j * nb + ib));
            f.labels.set_row(ia, &row);
            if !s.counts.is_empty() {
                f.counts[ia * nb..(ia + 1) * nb].copy_from_slice(&s.counts[j * nb..(j + 1) * nb]);
            }
        }
        for e in s.sub.chunks_exact(24) {
            f.row_entries[(entry(e, 0) / nb.max(1) as u64) as usize] += 1;
        }
        secs = (secs.0 + s.info.label_secs, secs.1 + s.info.sub_secs);
    }
    let f = first.ok_or(ShardError::NoShards)?;
    let missing: Vec<u32> =
        (0..f.holder.len() as u32).filter(|&i| f.holder[i as usize].is_none()).collect();
    if !missing.is_empty() {
        return Err(ShardError::Missing { missing, count: f.holder.len() as u32 });
    }
    let cells = if f.info.kind == TableKind::SharedSub {
        sub_cells_in_order(&f, read)?
    } else {
        SubCells::default()
    };
    let info = f.info;
    let space = LabelledSpace {
        grid_a: f.grid_a,
        grid_b: f.grid_b,
        labels: f.labels,
        margin: info.header.margin,
    };
    let sub = (info.kind == TableKind::SharedSub).then_some(cells);
    let clearance: Vec<_> = info.ladder.map(|l| (l, f.counts)).into_iter().collect();
    let variant = match info.ladder {
        Some(ladder) => Variant::Clearance(ladder),
        None => info.kind.variant(info.t),
    };
    let labels = RowLabels {
        space,
        sub,
        sub_secs: secs.1,
        certification: info.header.certification,
        labelling: info.labelling,
        clearance,
    };
    let (mut tables, report) =
        assemble(labels, info.symmetry, &[variant], secs.0).map_err(ShardError::Build)?;
    let table = tables.pop().ok_or(ShardError::NoShards)?;
    Ok((info.header, table, report))
}

/// Word `w` (little-endian `u64`) of sub-cell entry `e`: its pair, care and collision masks.
fn entry(e: &[u8], w: usize) -> u64 {
    u64::from_le_bytes(core::array::from_fn(|i| e[8 * w + i]))
}

/// The sub-cells of every shard of `f` (all read once before), in the order of their pairs:
/// each file read again, each entry written at its row's place (the rows before it hold
/// `row_entries` entries; the entries of one row are one shard's, in order). A file that
/// is not what the first reading found (another shard, or other entries) is refused.
fn sub_cells_in_order(
    f: &First,
    read: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
) -> Result<SubCells, ShardError> {
    // Row `ia`'s entries go to `next[ia]..ends[ia]`, after those of the rows before it.
    let mut ends = f.row_entries.clone();
    for ia in 1..ends.len() {
        ends[ia] += ends[ia - 1];
    }
    let mut next: Vec<usize> = ends.iter().zip(&f.row_entries).map(|(end, k)| end - k).collect();
    let n = ends.last().copied().unwrap_or(0);
    let mut cells = SubCells { pairs: vec![0; n], care: vec![0; n], collision: vec![0; n] };
    let nb = f.info.samples.1.max(1) as u64;
    for (index, name) in f.holder.iter().enumerate() {
        let Some(name) = name else { continue };
        let changed = |what: &str| ShardError::InFile {
            file: name.clone(),
            error: Box::new(ShardError::Unreadable {
                what: format!("changed during the merge: {what}"),
            }),
        };
        let bytes = read(name).map_err(|e| changed(&e))?;
        let s = parse(&bytes).map_err(|e| changed(&e.to_string()))?;
        if let Some(what) = differs(f, &s) {
            return Err(changed(&what));
        }
        if s.info.shard.index() as usize != index {
            return Err(changed("another shard"));
        }
        for e in s.sub.chunks_exact(24) {
            let row = (entry(e, 0) / nb) as usize;
            let at = next[row];
            if at == ends[row] {
                return Err(changed("more sub-cell entries"));
            }
            (cells.pairs[at], cells.care[at], cells.collision[at]) =
                (entry(e, 0), entry(e, 1), entry(e, 2));
            next[row] += 1;
        }
    }
    if next != ends {
        return Err(ShardError::Unreadable {
            what: "a shard changed during the merge: fewer sub-cell entries".into(),
        });
    }
    Ok(cells)
}

/// The first shard read: what the others must match, and the merge's state.
struct First {
    name: String,
    info: ShardInfo,
    grid_bytes: Vec<u8>,
    grid_a: SampleGrid,
    grid_b: SampleGrid,
    /// Per shard number, the file holding it.
    holder: Vec<Option<String>>,
    /// Every pair's label.
    labels: PairLabels,
    /// Every pair's clearance level count (clearance shards; else empty).
    counts: Vec<u8>,
    /// Per row of A: how many sub-cell entries the shards hold.
    row_entries: Vec<usize>,
}

impl First {
    fn new(name: &str, s: &Parsed) -> First {
        let (na, nb) = s.info.samples;
        First {
            name: name.to_string(),
            info: s.info.clone(),
            grid_bytes: s.grid_bytes.to_vec(),
            grid_a: s.grid_a.clone(),
            grid_b: s.grid_b.clone(),
            holder: vec![None; s.info.shard.count() as usize],
            labels: PairLabels::filled(na, nb, Label::Unreachable),
            counts: if s.info.ladder.is_some() { vec![0; na * nb] } else { vec![] },
            row_entries: vec![0; na],
        }
    }
}

/// What makes shard `b` part of another build than `a`, if anything.
fn differs(a: &First, b: &Parsed) -> Option<String> {
    let (x, y) = (&a.info, &b.info);
    let (hx, hy) = (&x.header, &y.header);
    Some(if hx.cell_fingerprint != hy.cell_fingerprint {
        format!("cell {:#018x}, not {:#018x}", hy.cell_fingerprint, hx.cell_fingerprint)
    } else if x.k != y.k {
        format!("k = {}, not {}", y.k, x.k)
    } else if (x.kind, x.t) != (y.kind, y.t) {
        format!("variant {} t = {}, not {} t = {}", y.kind, y.t, x.kind, x.t)
    } else if x.ladder != y.ladder {
        format!(
            "clearance levels {:?}, not {:?}",
            y.ladder.map(|l| l.mm().to_vec()),
            x.ladder.map(|l| l.mm().to_vec())
        )
    } else if x.labelling != y.labelling {
        format!("labelling {:?}, not {:?}", y.labelling, x.labelling)
    } else if x.shard.count() != y.shard.count() {
        format!("one of {} shards, not of {}", y.shard.count(), x.shard.count())
    } else if hx != hy
        || x.symmetry != y.symmetry
        || x.samples != y.samples
        || a.grid_bytes != b.grid_bytes
    {
        "the same cell and k, but another workspace, margin or sampling grid".to_string()
    } else {
        return None;
    })
}
