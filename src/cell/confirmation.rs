//! What table mode does when a table's lookup says COLLISION: a setting of the cell (the cell
//! file's `table_confirm`, `dc_set_table_confirmation`), read by the table checkers.

/// What table mode does when its lookup says COLLISION (the lookup's FREE is a proof and is
/// answered as it is).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Confirmation {
    /// Confirm by the exact check and answer its verdict: the same verdicts as exact mode, at
    /// the exact check's cost on those ticks only. The default of C handles, cell files and
    /// `check --table`.
    #[default]
    Exact,
    /// Answer the table's label: COLLISION may come where the robots are a little apart.
    None,
}

impl Confirmation {
    /// Every setting, by its name in cell files and on the command line.
    pub const ALL: [(&'static str, Confirmation); 2] =
        [("exact", Confirmation::Exact), ("none", Confirmation::None)];

    /// The setting named `name` (`"exact"` or `"none"`).
    pub fn from_name(name: &str) -> Option<Confirmation> {
        Confirmation::ALL.iter().find(|(n, _)| *n == name).map(|&(_, c)| c)
    }

    /// Its name in cell files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Confirmation::Exact => "exact",
            Confirmation::None => "none",
        }
    }
}
