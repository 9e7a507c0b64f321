//! `delta_collide._native`: the Python extension over the delta-collide crate (PyO3, abi3,
//! CPython 3.11+). Each call takes numpy arrays for its inputs and outputs (the Python package
//! `delta_collide` allocates the outputs unless `out=` is given), checks their dtype, shape,
//! layout and finiteness, releases the GIL and runs the library's per-tick code over them.
//!
//! | module | what |
//! |---|---|
//! | [`pycell`] | `Cell`: from a file, a TOML text or a reference name; every field |
//! | [`exact`] | `check`, `clearance`, `boxes`: the exact check, its clearance, the boxes |
//! | [`protective`] | `protective`: the protective verdict over a run |
//! | [`table`] | `Table`: build, load, save, inspect, query, clearance bound |
//! | [`sim`] | `simulate`: the closed-loop benchmark |
//! | [`errors`] | the library's errors as Python exceptions |
//! | [`count_alloc`] | a counting allocator: the tests show the `out=` forms allocate nothing |

mod arrays;
mod count_alloc;
mod errors;
mod exact;
mod protective;
mod pycell;
mod sim;
mod table;

use pyo3::prelude::*;

#[global_allocator]
static ALLOCATOR: count_alloc::Counting = count_alloc::Counting;

/// Allocations of the extension so far: `(in all, during calls' work)`, for the tests.
#[pyfunction]
fn _alloc_counts() -> (u64, u64) {
    count_alloc::counts()
}

/// The version of the delta-collide library inside.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<pycell::PyCell>()?;
    m.add_class::<table::PyTable>()?;
    m.add_function(wrap_pyfunction!(exact::check_into, m)?)?;
    m.add_function(wrap_pyfunction!(exact::clearance_into, m)?)?;
    m.add_function(wrap_pyfunction!(exact::boxes_into, m)?)?;
    m.add_function(wrap_pyfunction!(protective::protective_into, m)?)?;
    m.add_function(wrap_pyfunction!(sim::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(_alloc_counts, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("CellError", py.get_type::<errors::CellError>())?;
    m.add("TableError", py.get_type::<errors::TableError>())?;
    m.add("BuildError", py.get_type::<errors::BuildError>())?;
    m.add("MAX_BOXES", delta_collide::robot::MAX_BOXES)?;
    m.add("MAX_PATH_POINTS", delta_collide::cell::protective::MAX_PATH_POINTS)?;
    Ok(())
}
