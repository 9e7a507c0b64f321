//! The shared table's query layout with separate arrays, the peer of `table_report`'s shared
//! rows: masks, bases and child indices in separate arrays, nodes depth by depth; a query reads
//! per node step the mask pair and the base, then the child index, and at the end one leaf
//! (at most `levels + sub_levels - 1` steps). Built from [`SharedQuadtree6d::parts`], so it
//! holds the same nodes, and timed in the same run as the table's own layout.

use delta_collide::table::ChildIndices;
use delta_collide::table::SharedQuadtree6d;

/// The separate-arrays layout (see the module doc).
pub struct SeparateArrays {
    fine: u32,
    symmetric: bool,
    masks: Vec<[u64; 2]>,
    bases: Vec<u32>,
    depth_start: Vec<u32>,
    children: ChildIndices,
    leaves: Vec<u64>,
}

/// The 6-bit child index of `c` at bit `shift` of every coordinate.
#[inline]
fn child_index(c: &[u16; 6], shift: u32) -> u32 {
    c.iter().fold(0, |i, &v| i << 1 | (u32::from(v) >> shift & 1))
}

impl SeparateArrays {
    pub fn new(t: &SharedQuadtree6d) -> SeparateArrays {
        let p = t.parts();
        SeparateArrays {
            fine: t.levels() + t.sub_levels(),
            symmetric: t.symmetric(),
            masks: p.masks,
            bases: p.bases,
            depth_start: p.depth_start,
            children: p.children,
            leaves: p.leaves,
        }
    }

    /// As `SharedQuadtree6d::query` did before the layout work.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let k = 1u32 << self.fine;
        if cell.iter().any(|&v| u32::from(v) >= k) {
            return true;
        }
        let mut c = cell;
        if self.symmetric && u32::from(c[1]) < k / 2 {
            let top = (k - 1) as u16;
            c[1] = top - c[1];
            c[4] = top - c[4];
        }
        let mut node = 0usize;
        let depths = self.fine - 1;
        for d in 0..depths {
            let bit = 1u64 << child_index(&c, self.fine - 1 - d);
            let [nonuniform, collision] = self.masks[node];
            if nonuniform & bit == 0 {
                return collision & bit != 0;
            }
            let i = self.bases[node] as usize + (nonuniform & (bit - 1)).count_ones() as usize;
            let child = match &self.children {
                ChildIndices::Narrow(v) => usize::from(v[i]),
                ChildIndices::Wide(v) => v[i] as usize,
            };
            node = if d + 1 < depths {
                self.depth_start[d as usize + 1] as usize + child
            } else {
                child
            };
        }
        self.leaves[node] >> child_index(&c, 0) & 1 == 1
    }

    /// Bytes of the struct and its arrays (as `memory_bytes` counted them).
    pub fn memory_bytes(&self) -> usize {
        let children = match &self.children {
            ChildIndices::Narrow(v) => 2 * v.len(),
            ChildIndices::Wide(v) => 4 * v.len(),
        };
        std::mem::size_of::<Self>()
            + 16 * self.masks.len()
            + 4 * (self.bases.len() + self.depth_start.len())
            + children
            + 8 * self.leaves.len()
    }

    /// The address and byte length of every array a query may read.
    pub fn memory_regions(&self) -> Vec<(usize, usize)> {
        fn region<T>(v: &[T]) -> (usize, usize) {
            (v.as_ptr() as usize, std::mem::size_of_val(v))
        }
        let children = match &self.children {
            ChildIndices::Narrow(v) => region(v),
            ChildIndices::Wide(v) => region(v),
        };
        vec![
            region(&self.masks),
            region(&self.bases),
            region(&self.depth_start),
            children,
            region(&self.leaves),
        ]
    }
}
