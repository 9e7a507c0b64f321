//! The order in which a block of sample pairs is given its sub-cells: tiles of a few rows of
//! A by a few columns of B, so that the boxes a tile's pairs read (each sample's octants,
//! sub-octants and cores, tens of kilobytes) are read from the cache by the tile's other
//! pairs instead of from memory. The sub-cells of a pair depend on that pair alone, so any
//! order gives the same answers; only the time changes.

/// Distinct rows (samples of A) per tile.
pub(crate) const TILE_ROWS: usize = 8;
/// Distinct columns (samples of B) per tile.
pub(crate) const TILE_COLUMNS: usize = 8;

/// The positions of `pairs` (numbered `ia * nb + ib`) in tile order: the rows present are
/// grouped `rows` at a time in increasing order, the columns present `columns` at a time, and
/// the tiles are taken row group by row group, column group by column group; inside a tile,
/// row by row, each row's columns upward. A permutation of `0..pairs.len()`.
pub(crate) fn tile_order(pairs: &[u64], nb: u64, rows: usize, columns: usize) -> Vec<usize> {
    let (rows, columns) = (rows.max(1), columns.max(1));
    let ranks = |of: &dyn Fn(u64) -> u64| {
        let mut present: Vec<u64> = pairs.iter().map(|&p| of(p)).collect();
        present.sort_unstable();
        present.dedup();
        present
    };
    let (row_ids, column_ids) = (ranks(&|p| p / nb), ranks(&|p| p % nb));
    let group = |ids: &[u64], id: u64, size: usize| ids.partition_point(|&x| x < id) / size;
    let key = |p: u64| {
        let (ia, ib) = (p / nb, p % nb);
        (group(&row_ids, ia, rows), group(&column_ids, ib, columns), ia, ib)
    };
    let mut order: Vec<usize> = (0..pairs.len()).collect();
    order.sort_by_cached_key(|&i| key(pairs[i]));
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The order holds every position once, and a tile's pairs come together: along the
        /// order, the (row group, column group) of the pairs never comes back to one left
        /// before, and within a tile the pairs go row by row, columns upward.
        #[test]
        fn tile_order_is_a_permutation_in_tiles(mut pairs in prop::collection::vec(0..400u64, 0..300),
                rows in 1..6usize, columns in 1..6usize) {
            let nb = 20;
            pairs.sort_unstable();
            pairs.dedup();
            let order = tile_order(&pairs, nb, rows, columns);
            let mut seen = order.clone();
            seen.sort_unstable();
            prop_assert_eq!(seen, (0..pairs.len()).collect::<Vec<_>>());
            let rank = |ids: Vec<u64>, id: u64| ids.iter().filter(|&&x| x < id).count();
            let distinct = |f: fn(u64, u64) -> u64| {
                let mut v: Vec<u64> = pairs.iter().map(|&p| f(p, nb)).collect();
                v.sort_unstable();
                v.dedup();
                v
            };
            let tile = |p: u64| {
                (rank(distinct(|p, nb| p / nb), p / nb) / rows, rank(distinct(|p, nb| p % nb), p % nb) / columns)
            };
            let tiles: Vec<(usize, usize)> = order.iter().map(|&i| tile(pairs[i])).collect();
            let mut left = std::collections::HashSet::new();
            for w in tiles.windows(2) {
                if w[0] != w[1] {
                    prop_assert!(left.insert(w[0]), "tile {:?} comes back", w[0]);
                    prop_assert!(!left.contains(&w[1]));
                }
            }
            for w in order.windows(2) {
                if tile(pairs[w[0]]) == tile(pairs[w[1]]) {
                    prop_assert!(pairs[w[0]] < pairs[w[1]]);
                }
            }
        }
    }
}
