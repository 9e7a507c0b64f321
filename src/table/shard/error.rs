//! Why a shard file cannot be read, or a set of shards cannot be merged into a table.

use crate::table::BuildError;
use core::fmt;

/// Why a shard file cannot be read, or shards cannot be merged; each message says how to
/// fix it.
#[derive(Clone, Debug, PartialEq)]
pub enum ShardError {
    /// A shard number outside `0..count`, or no shard at all (`count` 0).
    BadIndex {
        /// The shard's number.
        index: u32,
        /// How many shards the build was to have.
        count: u32,
    },
    /// The buffer ends before `what` is complete.
    Truncated {
        /// The field or section being read.
        what: &'static str,
        /// Bytes the field needs from the start of the buffer.
        needed: usize,
        /// Bytes the buffer has.
        have: usize,
    },
    /// Not a shard file (`table` when it is a table file instead).
    BadMagic {
        /// Whether the file is a whole table (magic `DCTABLE`).
        table: bool,
    },
    /// A shard format version this library does not read.
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The version this library writes and reads.
        supported: u32,
    },
    /// The endianness marker reads byte-swapped.
    WrongEndianness,
    /// The checksum does not match, or a field breaks an invariant.
    Corrupt {
        /// The field and what is wrong with it.
        what: String,
    },
    /// The file could not be read.
    Unreadable {
        /// Why (the system's message).
        what: String,
    },
    /// A shard file that could not be read, with the reason.
    InFile {
        /// The file's name as given.
        file: String,
        /// Why.
        error: Box<ShardError>,
    },
    /// A shard of another build: another cell, `k`, variant, labelling or shard count.
    Foreign {
        /// The shard's file.
        file: String,
        /// The first shard's file, which the others are compared with.
        first: String,
        /// What differs.
        what: String,
    },
    /// Two files hold the same shard.
    Duplicate {
        /// The shard's number.
        index: u32,
        /// The first file holding it.
        first: String,
        /// The second.
        second: String,
    },
    /// Shards of the build were not given.
    Missing {
        /// The shards missing.
        missing: Vec<u32>,
        /// How many shards the build has.
        count: u32,
    },
    /// No shard was given.
    NoShards,
    /// The labels were merged but the table builder refused them.
    Build(BuildError),
}

impl fmt::Display for ShardError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShardError::BadIndex { index, count } => write!(
                f,
                "shard {index}/{count}: a build of N shards has shards 0 to N-1 (N at least 1); \
                 give --shard I/N with 0 <= I < N"
            ),
            ShardError::Truncated { what, needed, have } => write!(
                f,
                "shard is truncated: {what} needs {needed} bytes, the file has {have}; \
                 copy it again or build the shard again"
            ),
            ShardError::BadMagic { table: true } => {
                f.write_str("this is a table file, not a shard; merge takes the files of `build --shard I/N`")
            }
            ShardError::BadMagic { table: false } => f.write_str(
                "not a delta-collide shard (magic is not \"DCSHARD\\0\"); \
                 merge takes the files of `build --shard I/N`",
            ),
            ShardError::UnsupportedVersion { found, supported } => write!(
                f,
                "shard format version {found} is not supported (this library reads version {supported}); \
                 build the shards again with this delta-collide"
            ),
            ShardError::WrongEndianness => {
                f.write_str("shard was written big-endian; build it again on a little-endian machine")
            }
            ShardError::Corrupt { what } => {
                write!(f, "shard is corrupt: {what}; build the shard again or copy it again")
            }
            ShardError::Unreadable { what } => f.write_str(what),
            ShardError::InFile { file, error } => write!(f, "{file}: {error}"),
            ShardError::Foreign { file, first, what } => write!(
                f,
                "{file}: shard of another build than {first} ({what}); merge the shards of one \
                 `build --shard I/N` run with the same cell, k, variant, labelling and N"
            ),
            ShardError::Duplicate { index, first, second } => {
                write!(f, "{first} and {second} both hold shard {index}; give each shard once")
            }
            ShardError::Missing { missing, count } => {
                let list: Vec<String> = missing.iter().take(20).map(u32::to_string).collect();
                let more = if missing.len() > 20 { format!(" and {} more", missing.len() - 20) } else { String::new() };
                write!(
                    f,
                    "{} of {count} shards missing: {}{more}; build them with `build --shard I/{count}` \
                     and give every shard file",
                    missing.len(),
                    list.join(", ")
                )
            }
            ShardError::NoShards => f.write_str("no shard files given; merge takes every file of `build --shard I/N`"),
            ShardError::Build(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ShardError {}

/// A [`ShardError::Corrupt`] naming `what`.
pub(super) fn corrupt(what: impl Into<String>) -> ShardError {
    ShardError::Corrupt { what: what.into() }
}

impl crate::table::reader::ReadError for ShardError {
    fn truncated(what: &'static str, needed: usize, have: usize) -> Self {
        ShardError::Truncated { what, needed, have }
    }

    fn corrupt(what: String) -> Self {
        corrupt(what)
    }
}
