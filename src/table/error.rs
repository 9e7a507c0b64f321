//! Why a table cannot be built or loaded (SPEC §6).
//!
//! Every variant names the field it is about and the message says how to fix it, in the
//! manner of regex-automata's deserialisation errors.

use alloc::string::String;

/// Why a table could not be built from a labelled space, or loaded from bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TableError {
    /// The buffer ends before `what` is complete: `needed` bytes, `have` bytes.
    Truncated {
        /// The field or section being read.
        what: &'static str,
        /// Bytes the field needs from the start of the buffer.
        needed: usize,
        /// Bytes the buffer has.
        have: usize,
    },
    /// The buffer does not start with the table magic `b"DCTABLE\0"`.
    BadMagic {
        /// The first eight bytes found.
        found: [u8; 8],
    },
    /// The format version is not one this library reads.
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The version this library writes and reads.
        supported: u32,
    },
    /// The endianness marker reads byte-swapped: the file was written big-endian.
    WrongEndianness,
    /// The checksum does not match, or a field breaks an invariant (`what` names it).
    Corrupt {
        /// The field and what is wrong with it.
        what: String,
    },
    /// The table was built for another cell.
    WrongCell {
        /// The fingerprint of the cell the controller is configured for.
        expected: u64,
        /// The fingerprint recorded in the table.
        found: u64,
        /// The first parameter that differs, when the table recorded its cell's parameters.
        differs: Option<String>,
    },
    /// A bundle holds no table for a pair of robots that can meet.
    MissingPair {
        /// The pair, where it stands, and what the bundle holds.
        what: String,
    },
    /// A bundle's table for a pair of robots was built for another placement or model of
    /// that pair (another spacing of the line).
    WrongPair {
        /// The pair and the first value that differs.
        what: String,
    },
    /// The labelled space or the parameters given to a builder are not usable.
    BadInput {
        /// The input and what is wrong with it.
        what: String,
    },
}

impl core::fmt::Display for TableError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            TableError::Truncated { what, needed, have } => write!(
                f,
                "table is truncated: {what} needs {needed} bytes, the buffer has {have}; \
                 copy the whole table file again"
            ),
            TableError::BadMagic { found } => write!(
                f,
                "not a delta-collide table: magic is {found:02x?}, expected \"DCTABLE\\0\"; \
                 check that the right file or buffer is given"
            ),
            TableError::UnsupportedVersion { found, supported } => write!(
                f,
                "table format version {found} is not supported (this library reads version \
                 {supported}); rebuild the table with `delta-collide build`"
            ),
            TableError::WrongEndianness => write!(
                f,
                "table endianness marker is byte-swapped: the file is big-endian, this library \
                 reads little-endian tables only; rebuild it with `delta-collide build`"
            ),
            TableError::Corrupt { what } => {
                write!(f, "table is corrupt: {what}; rebuild it with `delta-collide build` or copy it again")
            }
            TableError::WrongCell { expected, found, differs } => {
                write!(
                    f,
                    "table was built for cell {found:#018x}, this controller is configured for {expected:#018x}"
                )?;
                if let Some(d) = differs {
                    write!(f, " ({d})")?;
                }
                write!(f, "; rebuild with `delta-collide build --cell ...` for this cell")
            }
            TableError::MissingPair { what } | TableError::WrongPair { what } => write!(
                f,
                "table bundle does not fit this cell: {what}; rebuild the bundle with \
                 `delta-collide build --cell CELL_FILE --output BUNDLE` for this cell"
            ),
            TableError::BadInput { what } => write!(f, "cannot build a table: {what}"),
        }
    }
}

impl core::error::Error for TableError {}

/// A [`TableError::Corrupt`] naming `what`.
pub(crate) fn corrupt(what: impl Into<String>) -> TableError {
    TableError::Corrupt { what: what.into() }
}

/// A [`TableError::BadInput`] naming `what`.
#[cfg(feature = "std")]
pub(crate) fn bad_input(what: impl Into<String>) -> TableError {
    TableError::BadInput { what: what.into() }
}

impl crate::table::reader::ReadError for TableError {
    fn truncated(what: &'static str, needed: usize, have: usize) -> Self {
        TableError::Truncated { what, needed, have }
    }

    fn corrupt(what: String) -> Self {
        corrupt(what)
    }
}

#[cfg(feature = "std")]
/// Why a table could not be built (apart from [`TableError`], which says why a table file
/// could not be loaded).
#[derive(Clone, Debug, PartialEq)]
pub enum BuildError {
    /// Tables are built for two-robot cells only.
    NotTwoRobots {
        /// The cell's name.
        cell: String,
        /// How many robots it has.
        robots: usize,
    },
    /// The labelling refused the grid: `k` not a power of two, or too small to hold the
    /// workspace (the message names the fix).
    Labelling(String),
    /// Sub-cells are certified: `SharedSubdivided` needs the certified labelling.
    SubCellsNeedCertified,
    /// Clearance levels are proofs: `Clearance` needs the certified labelling.
    ClearanceNeedsCertified,
    /// A builder refused the labels.
    Table(TableError),
    /// A build bounded to `max` bytes ([`build_table_bounded`]) needs more for its fixed
    /// part ([`crate::table::memory`]).
    Memory {
        /// Bytes of the fixed part (estimated).
        needed: u64,
        /// Of `needed`: the labels.
        labels: u64,
        /// The bound.
        max: u64,
    },
}

#[cfg(feature = "std")]
impl core::fmt::Display for BuildError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            BuildError::NotTwoRobots { cell, robots } => {
                write!(f, "tables are built for two-robot cells; {cell} has {robots}")
            }
            BuildError::Labelling(m) => f.write_str(m),
            BuildError::SubCellsNeedCertified => f.write_str("sub-cells are certified; use the certified labelling"),
            BuildError::ClearanceNeedsCertified => {
                f.write_str("clearance levels are certified; use the certified labelling")
            }
            BuildError::Table(e) => write!(f, "{e}"),
            BuildError::Memory { needed, labels, max } => write!(
                f,
                "the build needs about {} of memory whatever the block size (the robots' boxes and sweeps, \
                 and {} of labels, 2 bits per sample pair), more than the {} allowed; allow more \
                 memory, use a smaller k (each halving needs 64 times less for the labels) or shards",
                gigabytes(*needed),
                gigabytes(*labels),
                gigabytes(*max)
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for BuildError {}

#[cfg(feature = "std")]
fn gigabytes(bytes: u64) -> String {
    alloc::format!("{:.2} GB", bytes as f64 / 1e9)
}

#[cfg(feature = "std")]
impl From<TableError> for BuildError {
    fn from(e: TableError) -> BuildError {
        BuildError::Table(e)
    }
}

#[cfg(feature = "std")]
impl From<BuildError> for String {
    fn from(e: BuildError) -> String {
        e.to_string()
    }
}
