//! `simulate`: the closed-loop benchmark of coordination (SPEC §9, `delta_collide::sim`) on
//! one seeded programme per robot, as `delta-collide simulate` runs it: its figures, each
//! robot's progress per tick, and the STOP events.

use crate::pycell::PyCell;
use delta_collide::coord::{CoordinationConfig, RightOfWay};
use delta_collide::sim::run::{run_traced, Trace};
use delta_collide::sim::{programmes, Mode, ProgrammeConfig, Rng, SimConfig};
use numpy::PyArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};

fn rows(py: Python<'_>, rows: &[Vec<f64>], width: usize) -> PyResult<Py<PyAny>> {
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    let array = numpy::PyArray1::from_vec(py, flat).reshape([rows.len(), width])?;
    Ok(array.into_any().unbind())
}

/// One closed-loop run: `mode` "coordinate", "limits", "interlock" or "free"; `paths` whether
/// the protective verdict gets the programme ahead as stop path; programmes from `seed` of
/// `ticks` programme ticks with `gap_mm` between the robots; `clearance_mm` the coordination's
/// clearance (None: its default); `right_of_way` "arrival" or "programmed". A dict of the
/// run's figures, with `progress` (ticks, robots) and `stops` (events, robots) arrays and the
/// programmes (robots, programme ticks + 1, 3; a robot that ends earlier stands at its last point).
#[pyfunction]
#[pyo3(signature = (cell, mode="coordinate", paths=true, seed=1, ticks=6000, gap_mm=10.0,
    clearance_mm=None, right_of_way="arrival"))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    cell: &PyCell,
    mode: &str,
    paths: bool,
    seed: u64,
    ticks: u32,
    gap_mm: f64,
    clearance_mm: Option<f64>,
    right_of_way: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let mode = Mode::ALL.into_iter().find(|m| m.name() == mode).ok_or_else(|| {
        PyValueError::new_err(format!(
            "mode = {mode:?}: use \"coordinate\", \"limits\", \"interlock\" or \"free\""
        ))
    })?;
    let right_of_way = match right_of_way {
        "arrival" => RightOfWay::Arrival,
        "programmed" => RightOfWay::Programmed,
        other => {
            return Err(PyValueError::new_err(format!(
                "right_of_way = {other:?}: use \"arrival\" or \"programmed\""
            )))
        }
    };
    if !(gap_mm.is_finite() && gap_mm >= 0.0) {
        return Err(PyValueError::new_err(format!("gap_mm = {gap_mm} must be finite and >= 0")));
    }
    let mut coordination = CoordinationConfig { right_of_way, ..CoordinationConfig::default() };
    if let Some(c) = clearance_mm {
        if !(c.is_finite() && c >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "clearance_mm = {c} must be finite and >= 0"
            )));
        }
        coordination.clearance_mm = c;
    }
    let programme = ProgrammeConfig { ticks, gap_mm, ..ProgrammeConfig::default() };
    let config = SimConfig { mode, paths, coordination, ..SimConfig::default() };
    let c = &cell.cell;
    let (metrics, trace, progs) = py.detach(|| {
        let progs = programmes(c, &programme, &mut Rng::new(seed));
        let mut trace = Trace::default();
        let m = run_traced(c, &progs, &config, Some(&mut trace));
        (m, trace, progs)
    });
    let n = c.robots.len();
    let d = PyDict::new(py);
    d.set_item("mode", mode.name())?;
    d.set_item("programmed_ticks", metrics.programmed_ticks)?;
    d.set_item("ticks", metrics.ticks)?;
    d.set_item("finished", metrics.finished)?;
    d.set_item("throughput", metrics.throughput)?;
    d.set_item("stop_events", metrics.stop_events)?;
    d.set_item("deadlock", metrics.deadlock)?;
    d.set_item("contact_ticks", metrics.contact_ticks)?;
    d.set_item("contact_stop_samples", metrics.contact_stop_samples)?;
    let [free, warn, stop] = metrics.verdicts;
    d.set_item("verdicts", [("free", free), ("warn", warn), ("stop", stop)].into_py_dict(py)?)?;
    for (name, t) in [
        ("ours_ns", metrics.ours_ns),
        ("coordination_ns", metrics.coordination_ns),
        ("exact_ns", metrics.exact_ns),
    ] {
        d.set_item(name, [("median", t.median), ("p99", t.p99), ("max", t.max)].into_py_dict(py)?)?;
    }
    d.set_item("cells_tested_max", metrics.cells_tested_max)?;
    d.set_item("progress", rows(py, &trace.progress, n)?)?;
    d.set_item("stops", rows(py, &trace.stops, n)?)?;
    let longest = progs.iter().map(Vec::len).max().unwrap_or(0);
    // A robot whose programme ends earlier stands at its last point (as the loop parks it).
    let mut flat = vec![0.0; n * longest * 3];
    for (j, p) in progs.iter().enumerate() {
        for k in 0..longest {
            let v = p[k.min(p.len() - 1)];
            flat[(j * longest + k) * 3..(j * longest + k) * 3 + 3].copy_from_slice(v.as_slice());
        }
    }
    let programmes = numpy::PyArray1::from_vec(py, flat).reshape([n, longest, 3])?;
    d.set_item("programmes", programmes)?;
    Ok(d)
}
