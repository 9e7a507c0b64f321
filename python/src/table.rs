//! `delta_collide.Table`: a precomputed table of a two-robot cell (thesis 3.2, SPEC §6),
//! built, loaded from a file or saved, queried over arrays of configurations as table mode
//! answers each tick (`dc_query`), with its clearance bound (`dc_table_clearance_bound`).

use crate::arrays::{configuration, finite, input, output};
use crate::count_alloc;
use crate::errors::{build_error, table_error, BuildError, TableError};
use crate::pycell::PyCell;
use delta_collide::cell::reference::{reference_cell, REFERENCE_CELL_FILES};
use delta_collide::cell::{Confirmation, MAX_ROBOTS};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::{
    build_table_bounded, bundle_from_bytes, default_max_memory, from_bytes, is_bundle, memory_plan,
    to_bytes, BoundedBuild, BundleChecker, Labelling, Ladder, Table, TableAnswer, TableChecker,
    TableKind, Variant,
};
use numpy::PyUntypedArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// A table (two robots) or a bundle of tables (a line of robots) with its cell: queries go
/// through the library's table or bundle checker, as table mode's `dc_query`.
#[pyclass(name = "Table", module = "delta_collide", frozen)]
pub struct PyTable {
    bytes: Vec<u8>,
    pub(crate) checker: Mutex<Checker>,
    pub(crate) cell: Py<PyCell>,
}

/// The checker of a table file or of a bundle.
pub(crate) enum Checker {
    Table(Box<TableChecker>),
    Bundle(Box<BundleChecker>),
}

impl Checker {
    /// The clearance table's bound of robots `a`, `b` at their TCPs `tcps` (`[tcp_a, tcp_b]`),
    /// as table mode's protective query reads it; `None` without clearance tables.
    pub(crate) fn pair_bound(&self, a: usize, b: usize, tcps: &[Vec3]) -> Option<f64> {
        match self {
            Checker::Table(t) => t.clearance_bound(tcps),
            Checker::Bundle(bundle) => bundle.clearance_bound(a, b, tcps),
        }
    }

    /// Whether the protective query of table mode uses the bound (clearance tables only).
    pub(crate) fn has_clearance(&self) -> bool {
        match self {
            Checker::Table(t) => t.table().as_clearance().is_some(),
            Checker::Bundle(b) => b.has_clearance(),
        }
    }

    fn confirmation(&self) -> Confirmation {
        match self {
            Checker::Table(t) => t.confirmation(),
            Checker::Bundle(b) => b.confirmation(),
        }
    }

    fn set_confirmation(&mut self, confirmation: Confirmation) {
        match self {
            Checker::Table(t) => t.set_confirmation(confirmation),
            Checker::Bundle(b) => b.set_confirmation(confirmation),
        }
    }
}

/// The Python callback of the build under way (one build with progress at a time).
static PROGRESS: Mutex<Option<Py<PyAny>>> = Mutex::new(None);
/// Builds take turns: the progress callback is process-wide.
static BUILDING: Mutex<()> = Mutex::new(());

/// Called by the labelling's worker threads: hands `(rows_done, rows)` to the callback.
fn report_rows(done: u64, rows: u64) {
    Python::attach(|py| {
        let callback = PROGRESS.lock().ok().and_then(|c| c.as_ref().map(|c| c.clone_ref(py)));
        if let Some(callback) = callback {
            if let Err(e) = callback.call1(py, (done, rows)) {
                e.write_unraisable(py, None);
            }
        }
    });
}

/// The confirmation named `name`, else the cell's own.
fn confirmation(name: Option<&str>, cell: &PyCell) -> PyResult<Confirmation> {
    match name {
        None => Ok(cell.confirmation),
        Some("exact") => Ok(Confirmation::Exact),
        Some("none") => Ok(Confirmation::None),
        Some(other) => Err(PyValueError::new_err(format!(
            "confirm = {other:?}: use \"exact\" (the exact check confirms a COLLISION lookup) or \
             \"none\" (the labels alone)"
        ))),
    }
}

impl PyTable {
    fn from_bytes(
        py: Python<'_>,
        bytes: Vec<u8>,
        cell: Py<PyCell>,
        confirm: Option<&str>,
        what: &str,
    ) -> PyResult<PyTable> {
        let c = cell.get();
        let confirmation = confirmation(confirm, c)?;
        let at = |e: delta_collide::table::TableError| TableError::new_err(format!("{what}: {e}"));
        // As the CLI and `dc_init_with_table`: a bundle, or any table for more than two robots.
        let checker = if c.cell.robots.len() == 2 && !is_bundle(&bytes) {
            let t = TableChecker::with_confirmation(c.cell.clone(), &bytes, confirmation);
            Checker::Table(Box::new(t.map_err(at)?))
        } else {
            let b = BundleChecker::new(c.cell.clone(), &bytes, confirmation);
            Checker::Bundle(Box::new(b.map_err(at)?))
        };
        let _ = py;
        Ok(PyTable { bytes, checker: Mutex::new(checker), cell })
    }
}

#[pymethods]
impl PyTable {
    /// Reads a table file for `cell` (default: the reference cell whose fingerprint the table
    /// records); `confirm` "exact" or "none" (default: the cell file's `table_confirm`).
    #[staticmethod]
    #[pyo3(signature = (path, cell=None, confirm=None))]
    fn load(
        py: Python<'_>,
        path: std::path::PathBuf,
        cell: Option<Py<PyCell>>,
        confirm: Option<&str>,
    ) -> PyResult<PyTable> {
        let what = path.display().to_string();
        let bytes = std::fs::read(&path)
            .map_err(|e| PyErr::new::<pyo3::exceptions::PyOSError, _>(format!("{what}: {e}")))?;
        let cell = match cell {
            Some(c) => c,
            None => {
                let fingerprint = bundle_from_bytes(&bytes)
                    .map_err(|e| TableError::new_err(format!("{what}: {e}")))?
                    .cell_fingerprint;
                let found = REFERENCE_CELL_FILES
                    .iter()
                    .filter_map(|(n, _)| reference_cell(n))
                    .find(|c| c.fingerprint() == fingerprint)
                    .ok_or_else(|| {
                        TableError::new_err(format!(
                            "{what}: built for cell fingerprint {:#018x}, no reference cell; \
                             pass cell=Cell.from_file(...) of the cell it was built for",
                            fingerprint
                        ))
                    })?;
                Py::new(py, PyCell::new(found, Confirmation::Exact))?
            }
        };
        PyTable::from_bytes(py, bytes, cell, confirm, &what)
    }

    /// Samples, labels and builds a table of `variant` ("6d", "5d", "4d-yy", "4d-zz",
    /// "shared", "shared-sub", "clearance") for the two-robot `cell` at `k` cells per axis;
    /// `levels` the clearance ladder (mm), `t` the 4-D similarity threshold, `labelling`
    /// "certified" or "thesis", `progress(rows_done, rows)` called from the labelling.
    #[staticmethod]
    #[pyo3(signature = (cell, k, variant="shared-sub", levels=None, t=0, labelling="certified",
        progress=None, max_memory=None))]
    #[allow(clippy::too_many_arguments)]
    fn build(
        py: Python<'_>,
        cell: Py<PyCell>,
        k: u32,
        variant: &str,
        levels: Option<Vec<f64>>,
        t: u32,
        labelling: &str,
        progress: Option<Py<PyAny>>,
        max_memory: Option<u64>,
    ) -> PyResult<PyTable> {
        let kind: TableKind =
            variant.parse().map_err(|e: delta_collide::table::UnknownTableKind| {
                PyValueError::new_err(format!("variant = {variant:?}: {e}"))
            })?;
        let variant = match (kind, levels) {
            (TableKind::Clearance, Some(mm)) => {
                Variant::Clearance(Ladder::new(&mm).map_err(table_error)?)
            }
            (TableKind::Clearance, None) => Variant::Clearance(Ladder::default_ladder()),
            (_, Some(_)) => {
                return Err(PyValueError::new_err(
                    "levels are the ladder of a clearance table: pass variant=\"clearance\"",
                ))
            }
            (kind, None) => kind.variant(t),
        };
        let labelling = match labelling {
            "certified" => Labelling::Certified,
            "thesis" => Labelling::ThesisMargin,
            other => {
                return Err(PyValueError::new_err(format!(
                    "labelling = {other:?}: use \"certified\" or \"thesis\""
                )))
            }
        };
        let c = cell.get();
        let ws = Workspace::THESIS;
        let max_memory = max_memory.unwrap_or_else(|| {
            let fixed = memory_plan(&c.cell, k, &ws, variant, u64::MAX).map_or(0, |p| p.fixed);
            default_max_memory(fixed, None)
        });
        let with_progress = progress.is_some();
        let progress_fn =
            if with_progress { Progress::Rows(report_rows) } else { Progress::Silent };
        let build = BoundedBuild { k, ws, variant, labelling, progress: progress_fn, max_memory };
        let bytes = py.detach(|| {
            let _turn = BUILDING.lock().unwrap_or_else(|e| e.into_inner());
            if with_progress {
                Python::attach(|_| {
                    *PROGRESS.lock().unwrap_or_else(|e| e.into_inner()) = progress;
                });
            }
            // A line of robots: a bundle of one table per relative placement that can meet.
            let built = if c.cell.robots.len() > 2 {
                build_bundle(&c.cell, k, &ws, variant, labelling, progress_fn)
                    .map(|b| b.bytes)
                    .map_err(BuildError::new_err)
            } else {
                build_table_bounded(&c.cell, &build)
                    .map(|(header, table, _)| to_bytes(&table, &header))
                    .map_err(build_error)
            };
            if with_progress {
                Python::attach(|_| {
                    PROGRESS.lock().unwrap_or_else(|e| e.into_inner()).take();
                });
            }
            built
        })?;
        PyTable::from_bytes(py, bytes, cell, None, "built table")
    }

    /// Writes the table file (what `delta-collide build --output` writes).
    fn save(&self, path: std::path::PathBuf) -> PyResult<()> {
        std::fs::write(&path, &self.bytes).map_err(|e| {
            PyErr::new::<pyo3::exceptions::PyOSError, _>(format!("{}: {e}", path.display()))
        })
    }

    /// The table file's bytes.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, pyo3::types::PyBytes> {
        pyo3::types::PyBytes::new(py, &self.bytes)
    }

    /// The cell the table answers for.
    #[getter]
    fn cell(&self, py: Python<'_>) -> Py<PyCell> {
        self.cell.clone_ref(py)
    }

    /// What the table file holds, as `delta-collide inspect` prints it; a bundle: `bundle`
    /// True, its `tables` (each as a table's dict) and `pairs` (robot a, robot b, table).
    fn inspect<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        if !is_bundle(&self.bytes) {
            let (h, table) = from_bytes(&self.bytes).map_err(table_error)?;
            let d = inspect_dict(py, &h, &table, self.bytes.len())?;
            d.set_item("bundle", false)?;
            return Ok(d);
        }
        let b = bundle_from_bytes(&self.bytes).map_err(table_error)?;
        let d = PyDict::new(py);
        d.set_item("bundle", true)?;
        d.set_item("cell_fingerprint", b.cell_fingerprint)?;
        d.set_item("robots", b.robots)?;
        d.set_item("file_bytes", self.bytes.len())?;
        let tables = pyo3::types::PyList::empty(py);
        for (h, t) in &b.tables {
            tables.append(inspect_dict(py, h, t, 0)?)?;
        }
        d.set_item("tables", tables)?;
        let pairs: Vec<(usize, usize, usize)> =
            b.pairs.iter().map(|p| (p.a, p.b, p.table)).collect();
        d.set_item("pairs", pairs)?;
        Ok(d)
    }

    /// Table mode over every configuration of `tcps` (N, robots, 3) into `reachable` (N,)
    /// bool, `collide` (N,) bool (false unless every TCP is reachable) and `pairs` (N, pairs)
    /// bool (each pair that can meet, `cell.pairs` order), as `dc_query` and
    /// `dc_pair_results` answer each tick; `confirm` "exact" or "none" for this call only
    /// (default: the table's).
    #[pyo3(signature = (tcps, reachable, collide, pairs, confirm=None))]
    fn query_into(
        &self,
        py: Python<'_>,
        tcps: &Bound<'_, PyAny>,
        reachable: &Bound<'_, PyAny>,
        collide: &Bound<'_, PyAny>,
        pairs: &Bound<'_, PyAny>,
        confirm: Option<&str>,
    ) -> PyResult<()> {
        let cell = self.cell.get();
        let confirm = match confirm {
            Some(name) => Some(confirmation(Some(name), cell)?),
            None => None,
        };
        let robots = cell.cell.robots.len();
        let n_pairs = cell.cell.pairs_that_can_meet().len();
        let t = input::<f64>("tcps", tcps, &[None, Some(robots), Some(3)], &TCPS)?;
        let n = t.shape()[0];
        let mut r = output::<bool>("reachable", reachable, &[Some(n)], &["N"])?;
        let mut c = output::<bool>("collide", collide, &[Some(n)], &["N"])?;
        let mut p = output::<bool>("pairs", pairs, &[Some(n), Some(n_pairs)], &["N", "pairs"])?;
        let shape = t.shape().to_vec();
        let values = t.as_slice()?;
        let (r, c, p) = (r.as_slice_mut()?, c.as_slice_mut()?, p.as_slice_mut()?);
        py.detach(|| {
            count_alloc::work(|| {
                finite("tcps", values, &shape)?;
                let mut checker = self.checker.lock().map_err(|_| "the table is poisoned")?;
                let kept = checker.confirmation();
                checker.set_confirmation(confirm.unwrap_or(kept));
                let mut buf = [Vec3::zeros(); MAX_ROBOTS];
                let buf = &mut buf[..robots];
                for i in 0..n {
                    configuration(values, robots, i, buf);
                    let answer = match &mut *checker {
                        Checker::Table(t) => {
                            let a = t.check(buf);
                            p[i] = a == Ok(TableAnswer::Collision);
                            a
                        }
                        Checker::Bundle(b) => {
                            let a = b.check(buf);
                            for (k, pair) in b.pairs().iter().enumerate() {
                                p[i * n_pairs + k] = pair.answer == TableAnswer::Collision;
                            }
                            a
                        }
                    };
                    (r[i], c[i]) = match answer.map_err(|e| e.to_string())? {
                        TableAnswer::Free => (true, false),
                        TableAnswer::Collision => (true, true),
                        TableAnswer::Unreachable(_) => (false, false),
                    };
                }
                checker.set_confirmation(kept);
                Ok::<(), String>(())
            })
        })
        .map_err(PyValueError::new_err)
    }

    /// The certified lower bound on the clearance (mm) of the grid cell of every configuration
    /// of `tcps` (N, robots, 3) into `out` (N,) float64: `-inf` where nothing is proved (no
    /// level, outside the grid, a boolean table), NaN where a TCP is unreachable. A bundle's
    /// bound is the least of its pairs' (`dc_table_clearance_bound` answers `-inf` for a
    /// bundle).
    fn clearance_bound_into(
        &self,
        py: Python<'_>,
        tcps: &Bound<'_, PyAny>,
        out: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let cell = self.cell.get();
        let robots = cell.cell.robots.len();
        let t = input::<f64>("tcps", tcps, &[None, Some(robots), Some(3)], &TCPS)?;
        let n = t.shape()[0];
        let mut o = output::<f64>("out", out, &[Some(n)], &["N"])?;
        let shape = t.shape().to_vec();
        let values = t.as_slice()?;
        let o = o.as_slice_mut()?;
        py.detach(|| {
            count_alloc::work(|| {
                finite("tcps", values, &shape)?;
                let checker = self.checker.lock().map_err(|_| "the table is poisoned")?;
                let mut buf = [Vec3::zeros(); MAX_ROBOTS];
                let buf = &mut buf[..robots];
                for (i, slot) in o.iter_mut().enumerate() {
                    configuration(values, robots, i, buf);
                    *slot = match &*checker {
                        Checker::Table(t) => match t.located_clearance_bound(buf) {
                            Ok(bound) if t.table().as_clearance().is_some() => {
                                bound.unwrap_or(f64::NEG_INFINITY)
                            }
                            Ok(_) => f64::NEG_INFINITY,
                            Err(_) => f64::NAN,
                        },
                        Checker::Bundle(b) if b.unreachable_mask(buf) != 0 => f64::NAN,
                        Checker::Bundle(b) => b.pairs().iter().fold(f64::INFINITY, |m, p| {
                            let pair = [buf[p.a], buf[p.b]];
                            m.min(b.clearance_bound(p.a, p.b, &pair).unwrap_or(f64::NEG_INFINITY))
                        }),
                    };
                }
                Ok::<(), String>(())
            })
        })
        .map_err(PyValueError::new_err)
    }

    fn __repr__(&self) -> PyResult<String> {
        if is_bundle(&self.bytes) {
            let b = bundle_from_bytes(&self.bytes).map_err(table_error)?;
            return Ok(format!(
                "Table(bundle of {} tables, {} bytes)",
                b.tables.len(),
                self.bytes.len()
            ));
        }
        let (_, table) = from_bytes(&self.bytes).map_err(table_error)?;
        Ok(format!(
            "Table({}, k={}, {} bytes)",
            table.name(),
            1u32 << table.levels(),
            self.bytes.len()
        ))
    }
}

const TCPS: [&str; 3] = ["N", "robots", "3"];

fn inspect_dict<'py>(
    py: Python<'py>,
    h: &delta_collide::table::Header,
    table: &Table,
    file_bytes: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("variant", TableKind::of(table).name())?;
    d.set_item("name", table.name())?;
    d.set_item("k", 1u32 << table.levels())?;
    d.set_item("levels", table.levels())?;
    d.set_item("sub_levels", table.sub_levels())?;
    d.set_item("r", h.r)?;
    d.set_item("symmetric", table.symmetric())?;
    d.set_item("cell_fingerprint", h.cell_fingerprint)?;
    d.set_item("margin", h.margin)?;
    d.set_item("certification", format!("{:?}", h.certification))?;
    d.set_item("origin_a", h.origin_a)?;
    d.set_item("origin_b", h.origin_b)?;
    let w = &h.workspace;
    let ws = PyDict::new(py);
    for (k, v) in [("zu", w.zu), ("hcy", w.hcy), ("rcy", w.rcy), ("hco", w.hco), ("rco", w.rco)] {
        ws.set_item(k, v)?;
    }
    d.set_item("workspace", ws)?;
    d.set_item("memory_bytes", table.memory_bytes())?;
    d.set_item("file_bytes", file_bytes)?;
    d.set_item("clearance_levels_mm", table.as_clearance().map(|q| q.ladder().mm().to_vec()))?;
    Ok(d)
}
