//! The C ABI: the only `extern "C"` functions, `#[no_mangle]` symbols and `unsafe` of the
//! crate (thesis appendix A: the POU's init / per-tick query / destroy).
//!
//! # Conventions
//! - Argument order: handle, inputs, outputs. Lengths in mm, angles in rad; each TCP in its
//!   own robot's MCS.
//! - Every exported function catches panics (`DC_STATUS_PANIC`); none crosses into C.
//! - Every pointer is checked; NaN and infinity are rejected.
//! - `*out_verdict` and `*out_report`, when not NULL, are written on every call, and read
//!   `DC_VERDICT_FREE` only together with `DC_STATUS_OK` (fail closed).
//! - `dc_init*` allocate; `dc_query`, the protective queries and `dc_coordinate` never
//!   allocate, lock or do I/O.
//! - Two modes behind one handle: exact (`dc_init`, `dc_init_from_cell_file`) and table
//!   (`dc_init_with_table`, `dc_init_from_files`; a table, or a bundle of one table per pair
//!   that can meet); `dc_query` is the same.
//! - Table mode confirms a COLLISION lookup by the exact check unless
//!   `dc_set_table_confirmation` (or the cell file's `table_confirm`) says otherwise, so it
//!   answers as exact mode; `dc_table_confirmations` counts those ticks. With a clearance
//!   table the protective verdict is FREE by one lookup where the table's bound proves it
//!   (`dc_table_protective_lookups`), else the exact protective check.
//! - A handle is used by one task at a time; distinct handles are independent. A call that
//!   finds its handle in use by another call returns `DC_STATUS_BUSY` and does nothing
//!   (`handle::live`: the handle's state is reached only under its busy flag).
//!
//! # Files
//! `handle.rs` (the handle and the guard of every call), `init.rs` (make and free a handle),
//! `query.rs` (the collision query and its reports), `protective.rs` (the protective
//! queries), `coordination.rs` (the coordination's overrides, and its state behind a
//! handle), `settings.rs` (setup calls), `stats.rs` (the tick statistics), `status.rs`
//! (status text, version),
//! `kinematics.rs` (the Delta3 kinematics); the safe state behind a handle in `collider.rs`,
//! conversions from C in `convert.rs`, the C types in `types.rs`.
#![allow(unsafe_code)]

mod collider;
mod convert;
mod coordination;
mod handle;
mod init;
mod kinematics;
mod protective;
mod query;
mod settings;
mod stats;
mod status;
pub mod types;

pub use convert::table_error_status;
pub use coordination::*;
pub use handle::DcCollider;
pub use init::*;
pub use kinematics::*;
pub use protective::*;
pub use query::*;
pub use settings::*;
pub use stats::*;
pub use status::*;
pub use types::*;
