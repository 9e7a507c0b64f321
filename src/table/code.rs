//! Location codes of linear quadtrees by bit interleaving over 6, 5 or 4 dimensions
//! (thesis 3.2.4, Algorithm 2).
//!
//! # Conventions
//! A code has one *group* of `stride` bits per level, level-major: level 1 (the root's
//! children) in the most significant group, level `levels` (the leaves) in the least. Within a
//! group the child index holds one bit per dimension, dimension 0 in the group's highest index
//! bit: for 6-D `(ix, iy, iz, ix', iy', iz')` the index is `bx << 5 | by << 4 | ... | bz'`.
//! Sorting codes therefore lists leaves in the quadtree's preorder (children 0 to 2^D - 1).
//!
//! Strides: 7 for the stored 6-D code (index bits 0..6 plus the condensation mark, bit 6 of
//! each group, the thesis's "seventh bit"), 6 for the plain 6-D code used while building, 5
//! and 4 for the 5-D and 4-D codes (never condensed). Coordinates are below `2^levels`,
//! `levels <= MAX_LEVELS`.

/// Most quadtree levels a table may have (k up to 256; 8 levels of 7 bits fit a `u64`).
pub const MAX_LEVELS: u32 = 8;

/// Bit of a 7-bit 6-D group that marks a condensed node (thesis Algorithm 3 line 13).
pub const MARK: u64 = 1 << 6;

/// `SPREAD[v]` puts bit `j` of `v` at bit `j * stride`.
const fn spread_table(stride: u32) -> [u64; 256] {
    let mut t = [0u64; 256];
    let mut v = 0;
    while v < 256 {
        let mut j = 0;
        while j < 8 {
            if v & (1 << j) != 0 {
                t[v] |= 1 << (j * stride);
            }
            j += 1;
        }
        v += 1;
    }
    t
}

static SPREAD4: [u64; 256] = spread_table(4);
static SPREAD5: [u64; 256] = spread_table(5);
static SPREAD6: [u64; 256] = spread_table(6);
static SPREAD7: [u64; 256] = spread_table(7);

fn table(stride: u32) -> &'static [u64; 256] {
    match stride {
        4 => &SPREAD4,
        5 => &SPREAD5,
        6 => &SPREAD6,
        _ => &SPREAD7,
    }
}

/// The code of a leaf with coordinates `idx` (each `< 256`), `stride` bits per level
/// (`D <= stride <= 7`). Bits of `idx` above `levels` must be zero.
#[inline]
pub fn encode<const D: usize>(idx: [u16; D], stride: u32) -> u64 {
    let t = table(stride);
    let mut code = 0;
    for (d, &v) in idx.iter().enumerate() {
        code |= t[(v & 0xff) as usize] << (D - 1 - d);
    }
    code
}

/// The stored 6-D leaf code (stride 7, no marks).
#[inline]
pub fn code6(c: [u16; 6]) -> u64 {
    let t = &SPREAD7;
    t[(c[0] & 0xff) as usize] << 5
        | t[(c[1] & 0xff) as usize] << 4
        | t[(c[2] & 0xff) as usize] << 3
        | t[(c[3] & 0xff) as usize] << 2
        | t[(c[4] & 0xff) as usize] << 1
        | t[(c[5] & 0xff) as usize]
}

/// The coordinates of a leaf code: the inverse of [`encode`] for `levels` levels.
pub fn decode<const D: usize>(code: u64, stride: u32, levels: u32) -> [u16; D] {
    let mut idx = [0u16; D];
    for j in 0..levels {
        let group = code >> (j * stride);
        for (d, v) in idx.iter_mut().enumerate() {
            *v |= (((group >> (D - 1 - d)) & 1) as u16) << j;
        }
    }
    idx
}

/// Re-packs a code from `from` bits per level to `to` bits per level (group values kept).
pub fn restride(code: u64, from: u32, to: u32, levels: u32) -> u64 {
    let mask = (1u64 << from) - 1;
    (0..levels).fold(0, |acc, j| acc | ((code >> (j * from)) & mask) << (j * to))
}

/// The stored 6-D code of a condensed node: the leaf `plain` (stride 6) with its lowest
/// `free_levels` groups replaced by the bare mark (index 0, mark bit set). `free_levels = 0`
/// is the leaf itself; `free_levels = levels` is the root, covering everything.
pub fn condensed6(plain: u64, free_levels: u32, levels: u32) -> u64 {
    let code = restride(plain, 6, 7, levels);
    let marks = (0..free_levels).fold(0, |acc, j| acc | MARK << (7 * j));
    let kept = if free_levels >= 64 / 7 { 0 } else { !0u64 << (7 * free_levels) };
    (code & kept) | marks
}

/// Whether the stored 6-D code `node` (a leaf or condensed node) covers the leaf `leaf`,
/// given `node >= leaf`: equal, or `node` carries the mark in the highest group where they
/// differ (thesis Algorithm 5, the "condensed node that equals L").
#[inline]
pub fn covers6(node: u64, leaf: u64) -> bool {
    let x = node ^ leaf;
    if x == 0 {
        return true;
    }
    let group = (63 - x.leading_zeros()) / 7;
    node & (MARK << (7 * group)) != 0
}

/// Checks one stored 6-D code: bits only within `levels` groups, each group either an
/// unmarked index (< 64) or the bare mark, and marked groups form a suffix (the lowest groups).
pub fn valid6(code: u64, levels: u32) -> bool {
    if levels < 64 / 7 + 1 && code >> (7 * levels) != 0 {
        return false;
    }
    let mut marked_below = true;
    for j in 0..levels {
        let g = (code >> (7 * j)) & 0x7f;
        if g == MARK {
            if !marked_below {
                return false;
            }
        } else if g & MARK != 0 {
            return false;
        } else {
            marked_below = false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The next draw of the test generator seeded with (and advancing) `s`, 31 bits.
    fn draw(s: &mut u64) -> u64 {
        let mut rng = crate::test_rng::TestRng(*s);
        *s = rng.next_u64();
        *s >> 33
    }

    #[test]
    fn round_trip_every_stride() {
        let mut s = 7;
        for levels in 1..=MAX_LEVELS {
            let k = 1u64 << levels;
            for _ in 0..200 {
                let c6: [u16; 6] = std::array::from_fn(|_| (draw(&mut s) % k) as u16);
                for stride in [6, 7] {
                    assert_eq!(decode::<6>(encode(c6, stride), stride, levels), c6);
                }
                assert_eq!(code6(c6), encode(c6, 7));
                let c5: [u16; 5] = std::array::from_fn(|i| c6[i]);
                assert_eq!(decode::<5>(encode(c5, 5), 5, levels), c5);
                let c4: [u16; 4] = std::array::from_fn(|i| c6[i]);
                assert_eq!(decode::<4>(encode(c4, 4), 4, levels), c4);
                assert_eq!(restride(encode(c6, 6), 6, 7, levels), encode(c6, 7));
            }
        }
    }

    /// Walks the quadtree in preorder (child 0 first) and returns its leaves.
    fn preorder<const D: usize>(
        levels: u32,
        prefix: [u16; D],
        depth: u32,
        out: &mut Vec<[u16; D]>,
    ) {
        if depth == levels {
            out.push(prefix);
            return;
        }
        for child in 0..(1u16 << D) {
            let next = std::array::from_fn(|d| prefix[d] << 1 | ((child >> (D - 1 - d)) & 1));
            preorder(levels, next, depth + 1, out);
        }
    }

    #[test]
    fn sorted_codes_are_the_preorder_of_leaves() {
        let mut leaves = Vec::new();
        preorder::<4>(3, [0; 4], 0, &mut leaves);
        let codes: Vec<u64> = leaves.iter().map(|&l| encode(l, 4)).collect();
        assert_eq!(codes.len(), 1 << 12);
        assert!(codes.windows(2).all(|w| w[0] < w[1]), "4-D codes not increasing in preorder");
        let mut leaves6 = Vec::new();
        preorder::<6>(2, [0; 6], 0, &mut leaves6);
        for stride in [6, 7] {
            let codes: Vec<u64> = leaves6.iter().map(|&l| encode(l, stride)).collect();
            assert!(codes.windows(2).all(|w| w[0] < w[1]), "6-D stride {stride} not in preorder");
        }
        let mut leaves5 = Vec::new();
        preorder::<5>(2, [0; 5], 0, &mut leaves5);
        assert!(leaves5.windows(2).all(|w| encode(w[0], 5) < encode(w[1], 5)));
    }

    #[test]
    fn thesis_example_two_bit_code() {
        // Figure 3.10: indices l1 = 1, l2 = 3, l3 = 2 give 0b01_11_10 = 30. With the child
        // index bx << 1 | by, x has bits 0,1,1 (x = 3) and y bits 1,1,0 (y = 6).
        let code = encode::<2>([3, 6], 4);
        assert_eq!(restride(code, 4, 2, 3), 30);
    }

    #[test]
    fn condensed_node_covers_exactly_its_subtree() {
        let levels = 3;
        let mut s = 11;
        for _ in 0..300 {
            let a: [u16; 6] = std::array::from_fn(|_| (draw(&mut s) % 8) as u16);
            let b: [u16; 6] = std::array::from_fn(|_| (draw(&mut s) % 8) as u16);
            for free in 0..=levels {
                let node = condensed6(encode(a, 6), free, levels);
                assert!(valid6(node, levels));
                let leaf = code6(b);
                let inside = (0..6).all(|d| a[d] >> free == b[d] >> free);
                if node >= leaf {
                    assert_eq!(covers6(node, leaf), inside, "node {a:?}/{free} leaf {b:?}");
                } else {
                    assert!(!inside, "a covered leaf must sort before its node");
                }
            }
        }
    }

    #[test]
    fn invalid_codes_are_rejected() {
        assert!(valid6(0, 3));
        assert!(!valid6(1 << 21, 3), "bits above the levels");
        assert!(!valid6(MARK << 7, 3), "mark above an unmarked group");
        assert!(!valid6(MARK | 1, 3), "mark mixed with an index");
        assert!(valid6(MARK | MARK << 7 | MARK << 14, 3), "root");
    }
}
