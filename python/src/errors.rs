//! The library's errors as Python exceptions, with the library's own messages: `CellError`
//! (a cell file or value), `TableError` (a table file), `BuildError` (a table build). Each is
//! a `ValueError`, so `except ValueError` catches them all.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::PyErr;

create_exception!(delta_collide, CellError, PyValueError, "A cell file or value is invalid.");
create_exception!(delta_collide, TableError, PyValueError, "A table file is unusable here.");
create_exception!(delta_collide, BuildError, PyValueError, "A table could not be built.");

/// `CellError` with the message the CLI and `dc_last_init_error` give.
pub fn cell_error(e: delta_collide::cell::CellError) -> PyErr {
    CellError::new_err(e.to_string())
}

/// `TableError` with the library's message.
pub fn table_error(e: delta_collide::table::TableError) -> PyErr {
    TableError::new_err(e.to_string())
}

/// `BuildError` with the library's message.
pub fn build_error(e: delta_collide::table::BuildError) -> PyErr {
    BuildError::new_err(e.to_string())
}
