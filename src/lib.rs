//! # delta-collide
//!
//! Tells a robot motion controller, every 1 ms tick, whether Delta3 packaging robots that
//! share a conveyor are about to collide. The design follows the thesis in
//! `shared/seed/000_463851a3086e019d.txt`; `shared/SPEC.md` fixes the conventions.
//!
//! | module | what | thesis | SPEC |
//! |---|---|---|---|
//! | [`math`] | scalar and vector aliases, named tolerances, interval arithmetic | | §1 |
//! | [`geometry`] | oriented boxes, separating axis test, witness cache, swept boxes, clearance | 2.4, 3.1 | §3, §8 |
//! | [`robot`] | Delta3 kinematics, one robot's boxes, its motion bound, its stopping model | 2.2-2.7 | §2, §3, §8 |
//! | [`cell`] | robots, placements, the exact check of a cell, the protective verdict | 2.3, 3.1 | §1, §5, §8 |
//! | [`cspace`] | the sampled configuration space of two robots and its certified labels | 3.2.2-3.2.8 | §4, §6 |
//! | [`table`] | precomputed tables: quadtrees, files, bundles, shards, their queries | 3.2.4-3.2.6 | §6 |
//! | [`coord`] | coordination: speed overrides from the programmes ahead, right of way | | §9 |
//! | [`sim`] | the closed-loop benchmark (feature `sim`): programmes, loop, zone interlock | | §9 |
//! | [`ffi`] | the only `extern "C"` surface (opaque handle, POU lifecycle) | App. A | |
//!
//! # Features
//! - `std` (default): everything above plus [`cspace`], the table builders and the C ABI.
//!   Without it the crate is `#![no_std]` (with `alloc`, maths from `libm`) and holds the
//!   per-tick code only: [`math`], [`geometry`], [`robot`], the exact check of [`cell`] and
//!   the table queries (docs/PORTABILITY.md).
//! - `pictures` (default): the CLI's PNG pictures; the controller's library does not need it.
//!
//! Units: millimetres and radians everywhere. Frames: each robot's TCP is given in its own
//! machine coordinate system (MCS); the world (WCS) is robot 0's MCS.
#![cfg_attr(not(feature = "std"), no_std)]
#![deny(unsafe_code)]
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]
#![warn(missing_docs)]

extern crate alloc;

pub mod cell;
pub mod coord;
pub mod cspace;
#[cfg(feature = "std")]
pub mod ffi;
pub mod geometry;
pub mod math;
pub mod robot;
#[cfg(feature = "sim")]
pub mod sim;
pub mod table;
#[cfg(test)]
mod test_rng;
