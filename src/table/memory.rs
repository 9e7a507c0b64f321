//! How much memory a table build needs and how a build bounded by `max` bytes spends it:
//! the fixed part (both robots' boxes and sweeps, 2 bits of label per sample pair, the tree
//! builder's maps) must fit, and a subdivided build streams its sub-cells by blocks of the
//! quadtree sized from what is left ([`MemoryPlan`]).
//!
//! The figures are estimates, not measurements of the running process: the per-sample bytes
//! were measured (peak resident of a build labelling few rows: T1 at k = 64, 2.15 GB for
//! 2 x 47,548 samples, `docs/record/2026-11-24-shards.md`) and rounded up.

use super::error::BuildError;
use super::kind::Variant;
use crate::cspace::PairLabels;

/// Bytes per sample of either robot that a labelling holds whatever the rows: boxes and
/// sweeps of the whole cells and of their octants, with their cores (measured 22.6 KB).
pub const FIXED_BYTES_PER_SAMPLE: u64 = 24_000;

/// Bytes the process holds besides the labelling and the tree builder's maps: the program,
/// the node pool of the table being built (the size of the output, megabytes) and slack.
pub const RESERVE_BYTES: u64 = 256 << 20;

/// Bytes per pair of a block of a streamed subdivided build (which holds two blocks at a time:
/// the one the tree is in, and the next, found meanwhile), counted twice as a margin: when
/// every pair is a collision (the worst case), the pair numbers while they are gathered,
/// their masks and the block's [`crate::cspace::SubCells`] take `8 + 16 + 24` bytes a pair,
/// and the estimate leaves out the sub-octant boxes a block makes beyond the cache.
pub const BLOCK_BYTES_PER_PAIR: u64 = 2 * (8 + 16 + 24);

/// The bound of a build not given one ([`default_max_memory`]): 7 GiB. A `shared-sub` build
/// spends what its fixed part leaves on blocks and on the sub-octant cache, so the machine's
/// whole memory as the bound lets the cache grow past 8 GB at k = 64 (T3: 8.06 GB peak
/// resident on a 24 GB machine, when a label took a byte). The reference cells' fixed part at
/// k = 64 is estimated at 3.12 GB; 7 GiB (7.5 GB) leaves 4.4 GB for the blocks and the cache,
/// and about half a gigabyte below 8 GB for what the estimate leaves out (a block's
/// sub-octant boxes made beyond the cache before it is dropped, the allocator's slack).
pub const DEFAULT_MAX_MEMORY: u64 = 7 << 30;

/// The bound of a build not given one, whose fixed part needs `fixed` bytes
/// ([`MemoryPlan::fixed`]) on a machine with `total` bytes (when known):
/// [`DEFAULT_MAX_MEMORY`] when the fixed part fits in it, never more than the machine has;
/// otherwise the machine's memory, so that a build that cannot fit in the default is bounded
/// only by what the machine has. The bound changes where the sub-cells are found and when
/// the cache is dropped, never the table.
pub fn default_max_memory(fixed: u64, total: Option<u64>) -> u64 {
    let total = total.unwrap_or(u64::MAX);
    if fixed <= DEFAULT_MAX_MEMORY {
        DEFAULT_MAX_MEMORY.min(total)
    } else {
        total
    }
}

/// How a build spends its memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryPlan {
    /// Bytes held whatever the blocks (boxes, labels, builder, reserve).
    pub fixed: u64,
    /// Of `fixed`: the labels (2 bits per sample pair).
    pub labels: u64,
    /// Subdivided builds: the depth of the quadtree whose subtrees are the blocks (0: the
    /// whole table is one block).
    pub block_depth: u32,
    /// Subdivided builds: the bytes of sub-octant boxes kept between blocks (made again
    /// when needed beyond this).
    pub cache: u64,
}

/// The plan of a build of `variant` at `k` (`2^levels`) for `na` x `nb` samples within
/// `max` bytes.
///
/// # Errors
/// [`BuildError::Memory`] when the fixed part alone needs more than `max`.
pub fn plan_memory(
    na: u64,
    nb: u64,
    k: u32,
    variant: Variant,
    max: u64,
) -> Result<MemoryPlan, BuildError> {
    let labels = PairLabels::bytes_for(na.saturating_mul(nb));
    // A clearance build holds one more byte per pair: its proved level count.
    let counts = if matches!(variant, Variant::Clearance(_)) { na.saturating_mul(nb) } else { 0 };
    let fixed = FIXED_BYTES_PER_SAMPLE
        .saturating_mul(na + nb)
        .saturating_add(labels)
        .saturating_add(counts)
        .saturating_add(builder_bytes(k))
        .saturating_add(RESERVE_BYTES);
    if fixed > max {
        return Err(BuildError::Memory { needed: fixed, labels, max });
    }
    let rest = max - fixed;
    let (block_depth, cache) = match variant {
        // Half for the sub-octant cache, half for two blocks: the tree's and the next.
        Variant::SharedSubdivided => (block_depth(k, rest / 4), rest / 2),
        _ => (0, 0),
    };
    Ok(MemoryPlan { fixed, labels, block_depth, cache })
}

/// The tree builder's per-robot maps at `k`: a `u32` per grid cell and its occupancy per
/// depth (a byte per block, `k^3 / 7` over the depths).
fn builder_bytes(k: u32) -> u64 {
    let cells = u64::from(k).pow(3);
    2 * (4 * cells + cells.div_ceil(7) + 1)
}

/// The smallest depth (largest blocks) whose blocks, at worst, hold at most `bytes`: a block
/// at depth `d` has `(k / 2^d)^6` pairs. Never past the grid cells' parents.
fn block_depth(k: u32, bytes: u64) -> u32 {
    let levels = k.max(2).trailing_zeros();
    (0..levels.saturating_sub(1))
        .find(|&d| {
            u64::from(k >> d).saturating_pow(6).saturating_mul(BLOCK_BYTES_PER_PAIR) <= bytes
        })
        .unwrap_or(levels.saturating_sub(1))
}

/// Parses a byte count: digits, optionally followed by `K`, `M`, `G` or `T` (powers of
/// 1024, an optional trailing `B` or `iB`), e.g. `8G`, `512M`, `1073741824`.
///
/// # Errors
/// A message naming the accepted forms.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t.strip_suffix("iB").or_else(|| t.strip_suffix('B')).unwrap_or(t);
    let split = t.find(|c: char| !c.is_ascii_digit() && c != '.').unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" => 0,
        "K" => 10,
        "M" => 20,
        "G" => 30,
        "T" => 40,
        _ => {
            return Err(format!(
                "'{s}': a byte count is digits with an optional K, M, G or T (e.g. 8G)"
            ))
        }
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("'{s}': a byte count is digits with an optional K, M, G or T"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes >= u64::MAX as f64 {
        return Err(format!("'{s}': a byte count from 1 byte to 16 EB"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_parse_with_binary_units() {
        assert_eq!(parse_bytes("8G"), Ok(8 << 30));
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes("4096"), Ok(4096));
        assert!(
            parse_bytes("8X").is_err() && parse_bytes("").is_err() && parse_bytes("0").is_err()
        );
    }

    /// Blocks shrink as the memory left shrinks, down to the grid cells' parents; a fixed
    /// part that does not fit is refused.
    #[test]
    fn plans_choose_smaller_blocks_for_less_memory() {
        let sub = Variant::SharedSubdivided;
        let big = plan_memory(6_000, 6_000, 32, sub, 64 << 30).unwrap();
        let small = plan_memory(6_000, 6_000, 32, sub, big.fixed + (1 << 20)).unwrap();
        assert_eq!(big.block_depth, 1);
        assert!(small.block_depth > 1 && small.block_depth <= 4, "{small:?}");
        assert_eq!(plan_memory(6_000, 6_000, 32, sub, big.fixed).unwrap().block_depth, 4);
        assert!(matches!(
            plan_memory(6_000, 6_000, 32, sub, big.fixed - 1),
            Err(BuildError::Memory { .. })
        ));
        assert_eq!(plan_memory(6_000, 6_000, 32, Variant::D6, 64 << 30).unwrap().cache, 0);
    }

    /// The default bound is 7 GiB where the fixed part fits in it (and the machine has as
    /// much), the machine's memory otherwise; at k = 64 it leaves a reference cell's
    /// `shared-sub` build blocks and a cache, at k = 32 the blocks of the machine-wide bound.
    #[test]
    fn default_bound_is_7_gib_where_the_fixed_part_fits() {
        let sub = Variant::SharedSubdivided;
        assert_eq!(default_max_memory(1 << 30, Some(24 << 30)), DEFAULT_MAX_MEMORY);
        assert_eq!(default_max_memory(1 << 30, None), DEFAULT_MAX_MEMORY);
        assert_eq!(default_max_memory(1 << 30, Some(4 << 30)), 4 << 30);
        assert_eq!(default_max_memory(DEFAULT_MAX_MEMORY + 1, Some(24 << 30)), 24 << 30);
        // T1 at k = 64 (47,548 samples per robot).
        let k64 = plan_memory(47_548, 47_548, 64, sub, u64::MAX).unwrap();
        let plan =
            plan_memory(47_548, 47_548, 64, sub, default_max_memory(k64.fixed, Some(24 << 30)))
                .unwrap();
        assert!(plan.cache > 1 << 30 && plan.block_depth == 3, "{plan:?}");
        let k32 = plan_memory(6_284, 6_284, 32, sub, u64::MAX).unwrap();
        let at_32 = |max| plan_memory(6_284, 6_284, 32, sub, max).unwrap().block_depth;
        assert_eq!(at_32(default_max_memory(k32.fixed, Some(24 << 30))), at_32(24 << 30));
    }

    /// A clearance build holds a level count per pair besides the label: one byte more per
    /// pair in the fixed part, so a limit that fits the boolean build exactly refuses it.
    #[test]
    fn clearance_builds_count_their_level_counts() {
        let clearance = Variant::Clearance(crate::table::Ladder::default_ladder());
        let shared = plan_memory(6_000, 5_000, 32, Variant::Shared, 64 << 30).unwrap();
        let with_levels = plan_memory(6_000, 5_000, 32, clearance, 64 << 30).unwrap();
        assert_eq!(with_levels.fixed, shared.fixed + 30_000_000);
        assert!(matches!(
            plan_memory(6_000, 5_000, 32, clearance, shared.fixed),
            Err(BuildError::Memory { .. })
        ));
    }
}
