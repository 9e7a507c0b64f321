//! Merging the shards of a table build: check that they are exactly the `n` shards of one
//! build, put their labels and sub-cells together in the one-shot build's order, and build
//! the table from them (the same builder, so the same bytes).

use super::error::ShardError;
use super::format::{parse, unpack_row, Parsed};
use crate::cspace::{Label, LabelledSpace, SubCells};
use crate::table::build::{assemble, RowLabels};
use crate::table::{BuildReport, Header, Table};

/// Merges the shard files `files` (each a name for messages and the file's bytes), in any
/// order, into the table a one-shot build writes: its header, the table and the build's
/// report (`label_secs` is the sum of the shards' labelling times).
///
/// # Errors
/// [`ShardError::InFile`] for a file that is not a valid shard (naming it), `Foreign` for a
/// shard of another cell, `k`, variant, labelling or shard count, `Duplicate`, `Missing`,
/// `NoShards`, or `Build` when the table builder refuses the labels.
pub fn merge_shards(files: &[(String, &[u8])]) -> Result<(Header, Table, BuildReport), ShardError> {
    let mut shards = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let parsed = parse(bytes).map_err(|e| ShardError::InFile { file: name.clone(), error: Box::new(e) })?;
        shards.push((name.as_str(), parsed));
    }
    let ((first_name, first), rest) = shards.split_first().ok_or(ShardError::NoShards)?;
    for (name, s) in rest {
        if let Some(what) = differs(first, s) {
            return Err(ShardError::Foreign { file: name.to_string(), first: first_name.to_string(), what });
        }
    }
    let count = first.info.shard.count();
    let mut holder: Vec<Option<&str>> = vec![None; count as usize];
    for (name, s) in &shards {
        let i = s.info.shard.index();
        if let Some(other) = holder[i as usize] {
            return Err(ShardError::Duplicate { index: i, first: other.to_string(), second: name.to_string() });
        }
        holder[i as usize] = Some(name);
    }
    let missing: Vec<u32> = (0..count).filter(|&i| holder[i as usize].is_none()).collect();
    if !missing.is_empty() {
        return Err(ShardError::Missing { missing, count });
    }
    let info = &first.info;
    let (na, nb) = info.samples;
    let mut labels = vec![Label::Unreachable; na * nb];
    let mut sub = Vec::new();
    for (_, s) in &shards {
        let rows = s.info.shard.rows();
        for j in 0..s.info.rows {
            let ia = rows.row(j);
            unpack_row(s.labels, j, &mut labels[ia * nb..(ia + 1) * nb]);
        }
        sub.extend(s.sub.chunks_exact(24).map(|e| {
            let word = |w: usize| u64::from_le_bytes(core::array::from_fn(|i| e[8 * w + i]));
            (word(0), word(1), word(2))
        }));
    }
    sub.sort_unstable_by_key(|&(pair, _, _)| pair);
    let sub = (info.kind == crate::table::TableKind::SharedSub).then(|| SubCells {
        pairs: sub.iter().map(|e| e.0).collect(),
        care: sub.iter().map(|e| e.1).collect(),
        collision: sub.iter().map(|e| e.2).collect(),
    });
    let (grid_a, grid_b) = (first.grid_a.clone(), first.grid_b.clone());
    let space = LabelledSpace { grid_a, grid_b, labels, margin: info.header.margin };
    let secs = |f: fn(&Parsed) -> f64| shards.iter().map(|(_, s)| f(s)).sum::<f64>();
    let (label_secs, sub_secs) = (secs(|s| s.info.label_secs), secs(|s| s.info.sub_secs));
    let row_labels =
        RowLabels { space, sub, sub_secs, certification: info.header.certification, labelling: info.labelling };
    let variant = info.kind.variant(info.t);
    let (mut tables, report) = assemble(row_labels, info.symmetry, &[variant], label_secs).map_err(ShardError::Build)?;
    let table = tables.pop().ok_or(ShardError::NoShards)?;
    Ok((info.header.clone(), table, report))
}

/// What makes shard `b` part of another build than `a`, if anything.
fn differs(a: &Parsed, b: &Parsed) -> Option<String> {
    let (x, y) = (&a.info, &b.info);
    let (hx, hy) = (&x.header, &y.header);
    Some(if hx.cell_fingerprint != hy.cell_fingerprint {
        format!("cell {:#018x}, not {:#018x}", hy.cell_fingerprint, hx.cell_fingerprint)
    } else if x.k != y.k {
        format!("k = {}, not {}", y.k, x.k)
    } else if (x.kind, x.t) != (y.kind, y.t) {
        format!("variant {} t = {}, not {} t = {}", y.kind, y.t, x.kind, x.t)
    } else if x.labelling != y.labelling {
        format!("labelling {:?}, not {:?}", y.labelling, x.labelling)
    } else if x.shard.count() != y.shard.count() {
        format!("one of {} shards, not of {}", y.shard.count(), x.shard.count())
    } else if hx != hy || x.symmetry != y.symmetry || x.samples != y.samples || a.grid_bytes != b.grid_bytes {
        "the same cell and k, but another workspace, margin or sampling grid".to_string()
    } else {
        return None;
    })
}
