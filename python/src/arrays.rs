//! Reading and writing the numpy arrays of a call: every argument's dtype, shape, layout and
//! (for inputs) finiteness checked, with a `ValueError` that names the argument and what it
//! must be.

use delta_collide::math::Vec3;
use numpy::{Element, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyReadwriteArrayDyn};
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The TCPs of configuration `i` of a C-ordered (N, robots, 3) array's `values` into `out`.
#[inline(always)]
pub fn configuration(values: &[f64], robots: usize, i: usize, out: &mut [Vec3]) {
    for (j, t) in out.iter_mut().enumerate() {
        let k = 3 * (i * robots + j);
        *t = Vec3::new(values[k], values[k + 1], values[k + 2]);
    }
}

/// The dtype name of `obj` as numpy prints it, or its Python type when it is no array.
fn dtype_of(obj: &Bound<'_, PyAny>) -> String {
    match obj.cast::<PyUntypedArray>() {
        Ok(a) => a.dtype().to_string(),
        Err(_) => format!("a {}", obj.get_type().name().map_or("?".into(), |n| n.to_string())),
    }
}

/// `want` as text: `(N, 2, 3)` with `None` for any length.
fn shape_text(want: &[Option<usize>], names: &[&str]) -> String {
    let parts: Vec<String> =
        want.iter().zip(names).map(|(w, n)| w.map_or(n.to_string(), |v| v.to_string())).collect();
    format!("({})", parts.join(", "))
}

/// Checks `shape` against `want` (a `None` entry takes any length).
fn check_shape(arg: &str, shape: &[usize], want: &[Option<usize>], names: &[&str]) -> PyResult<()> {
    let fits =
        shape.len() == want.len() && shape.iter().zip(want).all(|(s, w)| w.is_none_or(|w| *s == w));
    if fits {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{arg} has shape {shape:?}, it must have shape {}",
            shape_text(want, names)
        )))
    }
}

/// The numpy name of `T`'s dtype.
fn dtype_name<T: Element>(py: Python<'_>) -> String {
    T::get_dtype(py).to_string()
}

/// A read-only view of input `arg`: a C-contiguous array of dtype `T` and shape `want`.
pub fn input<'py, T: Element>(
    arg: &str,
    obj: &Bound<'py, PyAny>,
    want: &[Option<usize>],
    names: &[&str],
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    let py = obj.py();
    let array = obj.cast::<PyArrayDyn<T>>().map_err(|_| {
        PyValueError::new_err(format!(
            "{arg} must be a numpy array of dtype {}, not {}; convert it with \
             numpy.ascontiguousarray({arg}, dtype=numpy.{})",
            dtype_name::<T>(py),
            dtype_of(obj),
            dtype_name::<T>(py)
        ))
    })?;
    check_shape(arg, array.shape(), want, names)?;
    if !array.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{arg} must be C-contiguous; pass numpy.ascontiguousarray({arg})"
        )));
    }
    array.try_readonly().map_err(|e| PyValueError::new_err(format!("{arg}: {e}")))
}

/// A writable view of output `arg`: a C-contiguous, writeable array of dtype `T` and shape
/// `want`.
pub fn output<'py, T: Element>(
    arg: &str,
    obj: &Bound<'py, PyAny>,
    want: &[Option<usize>],
    names: &[&str],
) -> PyResult<PyReadwriteArrayDyn<'py, T>> {
    let py = obj.py();
    let array = obj.cast::<PyArrayDyn<T>>().map_err(|_| {
        PyValueError::new_err(format!(
            "{arg} must be a numpy array of dtype {}, not {}",
            dtype_name::<T>(py),
            dtype_of(obj)
        ))
    })?;
    check_shape(arg, array.shape(), want, names)?;
    if !array.is_c_contiguous() {
        return Err(PyValueError::new_err(format!("{arg} must be C-contiguous")));
    }
    array.try_readwrite().map_err(|e| {
        PyValueError::new_err(format!(
            "{arg} must be writeable and not overlap another argument ({e})"
        ))
    })
}

/// `Err` naming the first non-finite number of `values` (laid out as `shape`) as
/// `arg[i, j, k] = value`.
pub fn finite(arg: &str, values: &[f64], shape: &[usize]) -> Result<(), String> {
    let Some(at) = values.iter().position(|v| !v.is_finite()) else { return Ok(()) };
    let mut index = vec![0; shape.len()];
    let mut rest = at;
    for (d, len) in shape.iter().enumerate().rev() {
        index[d] = rest % len.max(&1);
        rest /= len.max(&1);
    }
    let index: Vec<String> = index.iter().map(|i| i.to_string()).collect();
    Err(format!("{arg}[{}] = {}: every coordinate must be finite", index.join(", "), values[at]))
}
