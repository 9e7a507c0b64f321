//! The kinds of table under one name each (thesis 3.2.4-3.2.6 and the shared 6-D quadtree;
//! SPEC §6): the strings of the CLI's `--variant`, the variant number a table file stores,
//! and the builder's [`Variant`](super::Variant). Adding a kind starts here.

use super::{Ladder, SliceAxes, Table};
use core::fmt;
use core::str::FromStr;

/// A kind of table, as the CLI names it and as a table file records it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TableKind {
    /// Condensed 6-D linear quadtree (thesis 3.2.4).
    D6,
    /// 5-D quadtree with `z'` collision intervals (thesis 3.2.5).
    D5,
    /// 4-D quadtree of yy'-slices grouped by similarity (thesis 3.2.6).
    D4yy,
    /// 4-D quadtree of zz'-slices grouped by similarity (thesis 3.2.6).
    D4zz,
    /// 6-D quadtree with shared subtrees.
    Shared,
    /// As `Shared`, collision cells cut into 64 sub-cells (certified labelling only).
    SharedSub,
    /// Certified clearance levels per grid cell (certified labelling only).
    Clearance,
}

impl TableKind {
    /// Every kind, in the order the CLI lists them.
    pub const ALL: [TableKind; 7] = [
        TableKind::D6,
        TableKind::D5,
        TableKind::D4yy,
        TableKind::D4zz,
        TableKind::Shared,
        TableKind::SharedSub,
        TableKind::Clearance,
    ];

    /// The name the CLI takes and prints (`--variant`).
    pub const fn name(self) -> &'static str {
        match self {
            TableKind::D6 => "6d",
            TableKind::D5 => "5d",
            TableKind::D4yy => "4d-yy",
            TableKind::D4zz => "4d-zz",
            TableKind::Shared => "shared",
            TableKind::SharedSub => "shared-sub",
            TableKind::Clearance => "clearance",
        }
    }

    /// One line on what the kind is, for the CLI's help.
    pub const fn description(self) -> &'static str {
        match self {
            TableKind::D6 => "Condensed 6-D linear quadtree (thesis 3.2.4)",
            TableKind::D5 => "5-D quadtree with z' collision intervals (thesis 3.2.5)",
            TableKind::D4yy => "4-D quadtree of yy'-slices grouped by similarity (thesis 3.2.6)",
            TableKind::D4zz => "4-D quadtree of zz'-slices grouped by similarity (thesis 3.2.6)",
            TableKind::Shared => "6-D quadtree with shared subtrees",
            TableKind::SharedSub => {
                "As shared, collision cells cut into 64 sub-cells (certified labelling only)"
            }
            TableKind::Clearance => {
                "Certified clearance levels per grid cell (--levels; certified labelling only)"
            }
        }
    }

    /// The variant number a table file stores (`src/table/format.rs`); the 4-D kinds share
    /// 4 and tell their slice axes apart in a field of their own, the shared kinds share 7
    /// and tell sub-cells apart by a flag; clearance tables are 8.
    pub const fn file_variant(self) -> u32 {
        match self {
            TableKind::D6 => 6,
            TableKind::D5 => 5,
            TableKind::D4yy | TableKind::D4zz => 4,
            TableKind::Shared | TableKind::SharedSub => 7,
            TableKind::Clearance => 8,
        }
    }

    /// Whether the kind groups slices with a similarity threshold `t` (the 4-D kinds).
    pub const fn has_threshold(self) -> bool {
        matches!(self, TableKind::D4yy | TableKind::D4zz)
    }

    /// The kind of `table`.
    pub fn of(table: &Table) -> TableKind {
        match table {
            Table::D6(_) => TableKind::D6,
            Table::D5(_) => TableKind::D5,
            Table::D4(t) if t.axes() == SliceAxes::YY => TableKind::D4yy,
            Table::D4(_) => TableKind::D4zz,
            Table::Shared(t) if t.sub_levels() > 0 => TableKind::SharedSub,
            Table::Shared(_) => TableKind::Shared,
            Table::Clearance(_) => TableKind::Clearance,
        }
    }

    /// What the builder makes for this kind, with threshold `t` for the 4-D kinds (and the
    /// default ladder for clearance tables: [`Variant::Clearance`](super::Variant) takes
    /// another).
    #[cfg(feature = "std")]
    pub fn variant(self, t: u32) -> super::Variant {
        use super::Variant;
        match self {
            TableKind::D6 => Variant::D6,
            TableKind::D5 => Variant::D5,
            TableKind::D4yy => Variant::D4 { axes: SliceAxes::YY, t },
            TableKind::D4zz => Variant::D4 { axes: SliceAxes::ZZ, t },
            TableKind::Shared => Variant::Shared,
            TableKind::SharedSub => Variant::SharedSubdivided,
            TableKind::Clearance => Variant::Clearance(super::Ladder::default_ladder()),
        }
    }
}

impl fmt::Display for TableKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not a kind's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownTableKind;

impl fmt::Display for UnknownTableKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not a table kind; use 6d, 5d, 4d-yy, 4d-zz, shared, shared-sub or clearance")
    }
}

impl FromStr for TableKind {
    type Err = UnknownTableKind;

    /// The kind named `s` ([`name`](TableKind::name)).
    fn from_str(s: &str) -> Result<TableKind, UnknownTableKind> {
        TableKind::ALL.into_iter().find(|k| k.name() == s).ok_or(UnknownTableKind)
    }
}

/// Which linear quadtree to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Thesis 3.2.4: condensed 6-D linear quadtree.
    D6,
    /// Thesis 3.2.5: 5-D quadtree with `z'` collision intervals.
    D5,
    /// Thesis 3.2.6: 4-D quadtree of 2-D slices grouped with similarity threshold `t`.
    D4 {
        /// The two ignored dimensions.
        axes: SliceAxes,
        /// Similarity threshold (0: lossless).
        t: u32,
    },
    /// The 6-D quadtree with shared subtrees ([`SharedQuadtree6d`](super::SharedQuadtree6d)).
    Shared,
    /// As `Shared`, with every certified collision cell cut into 64 sub-cells
    /// certified on their own ([`crate::cspace::label_space_subdivided`]; certified labelling
    /// only).
    SharedSubdivided,
    /// Certified clearance levels of the ladder per grid cell ([`ClearanceTable`](super::ClearanceTable); certified
    /// labelling only).
    Clearance(Ladder),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_are_distinct() {
        for k in TableKind::ALL {
            assert_eq!(k.name().parse::<TableKind>(), Ok(k));
        }
        assert_eq!("6D".parse::<TableKind>(), Err(UnknownTableKind));
    }
}
