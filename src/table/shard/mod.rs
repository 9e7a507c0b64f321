//! Tables built in shards: shard `i` of `n` labels a deterministic part of the grid (the rows
//! `i, i + n, i + 2 n, ...` of robot A's samples, [`Rows`]), which is where a build spends its
//! time; [`merge_shards`] puts the labels of all `n` shards together and builds the table,
//! byte for byte the one a one-shot [`build_table`](super::build_table) writes (SPEC §6).
//!
//! Every variant shards: the shards carry labels (and, for `shared-sub`, the sub-cells of
//! their collision pairs; for `clearance`, the ladder and each pair's proved level count),
//! not parts of a tree, so the merge builds whichever variant the shards were labelled for.
//! A pair's level count depends on the pair alone (its two cells' sweeps and its label), so
//! the counts of the rows of all shards are the one-shot build's. The merge therefore needs
//! the whole label set in memory (2 bits per pair of samples; a clearance table a byte more
//! for the counts), as a one-shot build does; the shards need `1/n` of it each.
//!
//! A shard file (`format.rs`) records the cell, `k`, the variant, the labelling, `i` and `n`
//! and a checksum; [`merge_shards`] refuses a missing, duplicated, truncated or corrupt shard
//! and one of another cell, `k`, variant, labelling or `n`, naming the file
//! ([`ShardError`]). Scheduler environments (Slurm, Kubernetes, AWS Batch) are read by the
//! command line, not here.

mod error;
mod format;
mod merge;

pub use error::ShardError;
pub use format::{read_shard_info, ShardInfo, MAGIC, VERSION};
pub use merge::merge_shards;

use super::build::{label_rows, Labelling};
use super::{BuildError, Variant};
use super::{Header, SliceAxes, TableKind};
use crate::cell::Cell;
use crate::cspace::certify::clearance::clearance_counts;
use crate::cspace::{Progress, Rows, Symmetry, Workspace};
use std::time::Instant;

/// Which part of a build a shard does: shard `index` of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardIndex {
    index: u32,
    count: u32,
}

impl ShardIndex {
    /// Shard `index` of `count` (`index` from 0 to `count - 1`).
    ///
    /// # Errors
    /// [`ShardError::BadIndex`] when `count` is 0 or `index >= count`.
    pub fn new(index: u32, count: u32) -> Result<ShardIndex, ShardError> {
        if count == 0 || index >= count {
            return Err(ShardError::BadIndex { index, count });
        }
        Ok(ShardIndex { index, count })
    }

    /// The shard's number, from 0.
    pub fn index(self) -> u32 {
        self.index
    }

    /// How many shards the build has.
    pub fn count(self) -> u32 {
        self.count
    }

    /// The rows of A this shard labels.
    pub fn rows(self) -> Rows {
        Rows { first: self.index as usize, step: self.count as usize }
    }
}

/// What [`build_shard`] did, for the command line's summary.
#[derive(Clone, Debug, PartialEq)]
pub struct ShardReport {
    /// Rows of A labelled (of `samples.0`).
    pub rows: usize,
    /// Samples per robot (A, B).
    pub samples: (usize, usize),
    /// Pairs labelled: `rows * samples.1`.
    pub pairs: usize,
    /// Seconds spent labelling.
    pub label_secs: f64,
}

/// Labels shard `shard` of the table `kind` (threshold `t` for the 4-D kinds, else 0; the
/// default ladder for clearance tables) of the two-robot `cell` at `k` and returns the shard
/// file's bytes.
///
/// # Errors
/// As [`build_table`](super::build_table): not two robots, a bad `k`, sub-cells or
/// clearance levels with the thesis labelling.
pub fn build_shard(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    (kind, t): (TableKind, u32),
    labelling: Labelling,
    shard: ShardIndex,
    progress: Progress,
) -> Result<(Vec<u8>, ShardReport), BuildError> {
    build_shard_of(cell, k, ws, kind.variant(t), labelling, shard, progress)
}

/// The kind and threshold of `variant`.
fn kind_of(variant: Variant) -> (TableKind, u32) {
    match variant {
        Variant::D6 => (TableKind::D6, 0),
        Variant::D5 => (TableKind::D5, 0),
        Variant::D4 { axes: SliceAxes::YY, t } => (TableKind::D4yy, t),
        Variant::D4 { t, .. } => (TableKind::D4zz, t),
        Variant::Shared => (TableKind::Shared, 0),
        Variant::SharedSubdivided => (TableKind::SharedSub, 0),
        Variant::Clearance(_) => (TableKind::Clearance, 0),
    }
}

/// As [`build_shard`] for `variant` (a clearance table's own ladder).
///
/// # Errors
/// As [`build_shard`].
pub fn build_shard_of(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    variant: Variant,
    labelling: Labelling,
    shard: ShardIndex,
    progress: Progress,
) -> Result<(Vec<u8>, ShardReport), BuildError> {
    let start = Instant::now();
    let (kind, t) = kind_of(variant);
    let subdivide = kind == TableKind::SharedSub;
    if matches!(variant, Variant::Clearance(_)) && labelling != Labelling::Certified {
        return Err(BuildError::ClearanceNeedsCertified);
    }
    let mut labels = label_rows(cell, k, ws, subdivide, labelling, shard.rows(), progress)?;
    if let Variant::Clearance(ladder) = variant {
        let counts = clearance_counts(cell, k, ws, &labels.space.labels, ladder.mm(), shard.rows())
            .map_err(BuildError::Labelling)?;
        labels.clearance.push((ladder, counts));
    }
    let label_secs = start.elapsed().as_secs_f64();
    let header = Header::for_cell(&labels.space, cell, *ws, labels.certification);
    let (na, nb) = (labels.space.grid_a.cells.len(), labels.space.grid_b.cells.len());
    let rows = shard.rows().count(na);
    let info = ShardInfo {
        shard,
        k,
        kind,
        t: if kind.has_threshold() { t } else { 0 },
        labelling,
        symmetry: Symmetry::of(cell),
        label_secs,
        sub_secs: labels.sub_secs,
        header,
        samples: (na, nb),
        rows,
        sub_entries: labels.sub.as_ref().map_or(0, |s| s.pairs.len()),
        ladder: labels.clearance.first().map(|(l, _)| *l),
    };
    let bytes = format::to_bytes(&info, &labels);
    Ok((bytes, ShardReport { rows, samples: (na, nb), pairs: rows * nb, label_secs }))
}

#[cfg(test)]
mod tests {
    use super::format::parse;
    use super::*;
    use crate::cell::fnv1a64;
    use crate::cell::reference::reference_cell;

    /// Shard 0 of 200 of T3's `shared-sub` table at k = 16: five rows, with sub-cells.
    fn small_shard() -> Vec<u8> {
        let cell = reference_cell("T3").unwrap();
        let shard = ShardIndex::new(0, 200).unwrap();
        let kind = (TableKind::SharedSub, 0);
        build_shard(
            &cell,
            16,
            &Workspace::THESIS,
            kind,
            Labelling::Certified,
            shard,
            Progress::Silent,
        )
        .unwrap()
        .0
    }

    /// `bytes` with the checksum recomputed, as a deliberate edit would leave it.
    fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
        let end = bytes.len() - 8;
        let sum = fnv1a64(&bytes[..end]);
        bytes[end..].copy_from_slice(&sum.to_le_bytes());
        bytes
    }

    #[test]
    fn shard_numbers_must_be_below_the_count() {
        assert!(ShardIndex::new(0, 1).is_ok() && ShardIndex::new(4, 5).is_ok());
        assert_eq!(ShardIndex::new(5, 5), Err(ShardError::BadIndex { index: 5, count: 5 }));
        assert!(ShardIndex::new(0, 0).is_err());
        let rows = ShardIndex::new(2, 5).unwrap().rows();
        assert_eq!((rows.count(12), rows.row(0), rows.row(1)), (2, 2, 7));
    }

    #[test]
    fn every_truncation_and_every_flipped_byte_is_refused_without_panic() {
        let bytes = small_shard();
        let info = parse(&bytes).unwrap().info;
        assert_eq!((info.rows, info.shard.count()), (5, 200));
        assert!(info.sub_entries > 0, "the rows hold collision pairs with sub-cells");
        for n in 0..bytes.len() {
            let e = parse(&bytes[..n])
                .err()
                .unwrap_or_else(|| panic!("a shard cut to {n} bytes was read"));
            assert!(
                matches!(e, ShardError::Truncated { .. } | ShardError::Corrupt { .. }),
                "cut to {n}: {e}"
            );
        }
        for i in 0..bytes.len() {
            let mut flipped = bytes.clone();
            flipped[i] ^= 0x20;
            assert!(parse(&flipped).is_err(), "byte {i} flipped was read");
        }
    }

    /// A clearance shard carries its ladder and a count per pair of its rows; a count above
    /// the ladder or on a pair not free is refused, checksum or not.
    #[test]
    fn clearance_shards_carry_checked_counts() {
        let cell = reference_cell("T3").unwrap();
        let shard = ShardIndex::new(1, 200).unwrap();
        let ladder = crate::table::Ladder::new(&[0.0, 20.0]).unwrap();
        let variant = Variant::Clearance(ladder);
        let bytes = build_shard_of(
            &cell,
            16,
            &Workspace::THESIS,
            variant,
            Labelling::Certified,
            shard,
            Progress::Silent,
        )
        .unwrap()
        .0;
        let p = parse(&bytes).unwrap();
        assert_eq!(p.info.ladder, Some(ladder));
        assert_eq!(p.counts.len(), p.info.rows * p.info.samples.1);
        assert!(
            p.counts.contains(&2) && p.counts.iter().all(|&c| c <= 2),
            "levels proved in the rows"
        );
        let start = bytes.len() - 8 - p.counts.len();
        let high = p.counts.iter().position(|&c| c > 0).unwrap();
        let not_free =
            (0..p.counts.len()).find(|&j| p.labels[j / 4] >> (2 * (j % 4)) & 3 != 0).unwrap();
        for (at, v) in [(high, 3u8), (not_free, 1)] {
            let mut edited = bytes.clone();
            edited[start + at] = v;
            let e = parse(&resealed(edited)).err().unwrap().to_string();
            assert!(e.contains("clearance count"), "{e}");
        }
        let thesis = Labelling::ThesisMargin;
        let thesis =
            build_shard_of(&cell, 16, &Workspace::THESIS, variant, thesis, shard, Progress::Silent);
        assert!(matches!(thesis, Err(BuildError::ClearanceNeedsCertified)));
    }

    /// The merge reads a subdivided table's files twice (the labels, then the sub-cells in
    /// the pairs' order): a file that is another shard at the second reading is refused,
    /// naming it; read unchanged, the same files merge.
    #[test]
    fn a_shard_changed_during_the_merge_is_refused() {
        let cell = reference_cell("T3").unwrap();
        let kind = (TableKind::SharedSub, 0);
        let shard = |i| {
            let index = ShardIndex::new(i, 2).unwrap();
            build_shard(
                &cell,
                16,
                &Workspace::THESIS,
                kind,
                Labelling::Certified,
                index,
                Progress::Silent,
            )
            .unwrap()
            .0
        };
        let files = [shard(0), shard(1)];
        let names = ["s0".to_string(), "s1".to_string()];
        let mut reads = 0;
        let mut swapped = |name: &str| {
            reads += 1;
            Ok(files[usize::from((name == "s1") != (reads > 2))].clone())
        };
        let e = merge_shards(&names, &mut swapped).err().unwrap().to_string();
        assert!(e.contains("s0") && e.contains("another shard"), "{e}");
        let mut unchanged = |name: &str| Ok(files[usize::from(name == "s1")].clone());
        assert!(merge_shards(&names, &mut unchanged).is_ok());
    }

    #[test]
    fn fields_are_checked_beyond_the_checksum() {
        let bytes = small_shard();
        let labels_end = bytes.len() - 8 - 24 * parse(&bytes).unwrap().info.sub_entries;
        let mut undefined = bytes.clone();
        undefined[labels_end - 1] |= 0b11;
        let e = parse(&resealed(undefined)).err().unwrap().to_string();
        assert!(e.contains("label 3"), "{e}");
        let mut other_index = bytes.clone();
        other_index[16] = 100;
        let e = parse(&resealed(other_index)).err().unwrap().to_string();
        assert!(e.contains("5 rows, shard 100 of 200"), "shard 100 of 200 has 4 rows: {e}");
        let mut table = bytes.clone();
        table[..8].copy_from_slice(&crate::table::format::MAGIC);
        assert_eq!(parse(&table).err(), Some(ShardError::BadMagic { table: true }));
    }
}
