//! `delta_collide.Cell`: a validated cell (SPEC §1, §5) with every field readable, and the
//! checkers its calls reuse, so that a call with `out=` allocates nothing.

use crate::errors::cell_error;
use delta_collide::cell::protective::ProtectiveChecker;
use delta_collide::cell::reference::{reference_cell, REFERENCE_CELL_FILES};
use delta_collide::cell::{Cell, Confirmation, ExactChecker, SatMethod};
use delta_collide::math::Vec3;
use delta_collide::robot::ToolBox;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::Mutex;

/// A cell of Delta robots: robots, placements, stopping models, the exact test.
#[pyclass(name = "Cell", module = "delta_collide", frozen)]
pub struct PyCell {
    pub cell: Cell,
    pub confirmation: Confirmation,
    /// The exact checker of `check` and `clearance` (one call at a time per cell).
    pub exact: Mutex<ExactChecker>,
    /// The protective checkers of `protective`, made on first use.
    pub protective: Mutex<Option<Protectives>>,
}

/// The protective checker of a `warn_mm`, reset before each run (`ProtectiveChecker::reset`
/// forgets the previous TCPs and the warm starts of each pair's clearance): each run answers
/// as a fresh C handle does.
pub struct Protectives {
    pub warn_mm: f64,
    pub work: ProtectiveChecker,
}

impl PyCell {
    pub fn new(cell: Cell, confirmation: Confirmation) -> PyCell {
        PyCell {
            exact: Mutex::new(ExactChecker::new(cell.clone())),
            protective: Mutex::new(None),
            cell,
            confirmation,
        }
    }
}

fn vec3(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn tool_box<'py>(py: Python<'py>, b: Option<ToolBox>) -> PyResult<Bound<'py, PyAny>> {
    match b {
        None => Ok(py.None().into_bound(py)),
        Some(b) => {
            let d = PyDict::new(py);
            d.set_item("offset", vec3(&b.offset))?;
            d.set_item("half", vec3(&b.half))?;
            Ok(d.into_any())
        }
    }
}

#[pymethods]
impl PyCell {
    /// Reads and validates a TOML cell file; `CellError` with the library's message.
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<PyCell> {
        let file = Cell::read_file(&path).map_err(cell_error)?;
        Ok(PyCell::new(file.cell, file.table_confirmation))
    }

    /// Parses and validates the text of a TOML cell file.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<PyCell> {
        let file = delta_collide::cell::parse_cell_file(text).map_err(cell_error)?;
        Ok(PyCell::new(file.cell, file.table_confirmation))
    }

    /// A reference cell of SPEC §5: "T1", "T2" or "T3" (any case).
    #[staticmethod]
    fn reference(name: &str) -> PyResult<PyCell> {
        let cell = reference_cell(name).ok_or_else(|| {
            let names: Vec<&str> = REFERENCE_CELL_FILES.iter().map(|(n, _)| *n).collect();
            PyValueError::new_err(format!(
                "no reference cell {name:?}; the reference cells are {}",
                names.join(", ")
            ))
        })?;
        Ok(PyCell::new(cell, Confirmation::Exact))
    }

    /// The cell's name.
    #[getter]
    fn name(&self) -> &str {
        &self.cell.name
    }

    /// "sat" or "sat-cache".
    #[getter]
    fn method(&self) -> &'static str {
        match self.cell.method {
            SatMethod::Sat => "sat",
            SatMethod::SatCache => "sat-cache",
        }
    }

    /// The controller's tick (ms).
    #[getter]
    fn tick_ms(&self) -> f64 {
        self.cell.tick_ms
    }

    /// "exact" or "none": how table mode answers a COLLISION lookup.
    #[getter]
    fn table_confirm(&self) -> &'static str {
        match self.confirmation {
            Confirmation::Exact => "exact",
            Confirmation::None => "none",
        }
    }

    /// How many robots.
    #[getter]
    fn n_robots(&self) -> usize {
        self.cell.robots.len()
    }

    /// The robot pairs `(a, b)` that can meet, in the order of the per-pair results.
    #[getter]
    fn pairs(&self) -> Vec<(usize, usize)> {
        self.cell.pairs_that_can_meet()
    }

    /// The cell fingerprint tables record.
    #[getter]
    fn fingerprint(&self) -> u64 {
        self.cell.fingerprint()
    }

    /// Every value that decides a collision, named as a cell file names it.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in self.cell.parameters() {
            d.set_item(name, v)?;
        }
        Ok(d)
    }

    /// One dict per robot: name, geometry (mm, rad), model (box half-extents, margin,
    /// optional boxes: None when absent), placement (alpha rad, t mm), stop (stopping model).
    #[getter]
    fn robots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for (r, s) in self.cell.robots.iter().zip(&self.cell.stops) {
            let (g, o, p) = (&r.model.delta, &r.model.options, &r.placement);
            let geometry = PyDict::new(py);
            for (k, v) in [
                ("f", g.f),
                ("rf", g.rf),
                ("re", g.re),
                ("e", g.e),
                ("theta_min", g.theta_min),
                ("theta_max", g.theta_max),
            ] {
                geometry.set_item(k, v)?;
            }
            let model = PyDict::new(py);
            model.set_item("half_height", o.half_height)?;
            model.set_item("half_depth", o.half_depth)?;
            model.set_item("margin", o.margin)?;
            let upper = o.upper_links.map(|(h, d)| {
                [("half_height", h), ("half_depth", d)].into_iter().collect::<Vec<_>>()
            });
            match upper {
                Some(u) => {
                    let ud = PyDict::new(py);
                    for (k, v) in u {
                        ud.set_item(k, v)?;
                    }
                    model.set_item("upper_links", ud)?;
                }
                None => model.set_item("upper_links", py.None())?,
            }
            model.set_item("platform", tool_box(py, o.platform)?)?;
            model.set_item("tool", tool_box(py, o.tool)?)?;
            let placement = PyDict::new(py);
            placement.set_item("alpha", p.alpha)?;
            placement.set_item("t", vec3(&p.t))?;
            let stop = PyDict::new(py);
            stop.set_item("reaction_ms", s.reaction_ms)?;
            stop.set_item("decel_mm_s2", s.decel_mm_s2)?;
            stop.set_item("max_accel_mm_s2", s.max_accel_mm_s2)?;
            stop.set_item("max_speed_mm_s", s.max_speed_mm_s)?;
            let robot = PyDict::new(py);
            robot.set_item("name", &r.name)?;
            robot.set_item("geometry", geometry)?;
            robot.set_item("model", model)?;
            robot.set_item("placement", placement)?;
            robot.set_item("stop", stop)?;
            list.append(robot)?;
        }
        Ok(list)
    }

    /// How many boxes each robot's model has (3 lower links, then upper links, platform, tool).
    #[getter]
    fn box_counts(&self) -> Vec<usize> {
        self.cell
            .robots
            .iter()
            .map(|r| {
                let o = &r.model.options;
                3 + if o.upper_links.is_some() { 3 } else { 0 }
                    + usize::from(o.platform.is_some())
                    + usize::from(o.tool.is_some())
            })
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Cell({:?}, {} robots, {} pairs can meet)",
            self.cell.name,
            self.cell.robots.len(),
            self.cell.pairs_that_can_meet().len()
        )
    }
}
