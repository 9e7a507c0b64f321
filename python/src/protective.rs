//! `protective`: the protective verdict (SPEC §8) tick by tick over a run of TCPs, as the
//! controller calls `dc_protective_query` (untimed: one tick between calls), from a checker
//! reset at the run's start, the GIL released, nothing allocated once the cell's checker
//! exists.

use crate::arrays::{finite, input, output};
use crate::count_alloc;
use crate::errors::cell_error;
use crate::pycell::{Protectives, PyCell};
use crate::table::PyTable;
use delta_collide::cell::protective::{
    ClearanceBound, Protective, ProtectiveChecker, ProtectiveRequest, ProtectiveStatus, StopPath,
    TimingFault, MAX_PATH_POINTS,
};
use delta_collide::cell::MAX_ROBOTS;
use delta_collide::math::Vec3;
use numpy::PyUntypedArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The C ABI's verdict number (`DC_VERDICT_*`).
fn verdict_code(v: Protective) -> u32 {
    match v {
        Protective::Stop => 0,
        Protective::Free => 1,
        Protective::Warn => 3,
    }
}

/// The C ABI's status number (`DC_STATUS_*`, numbers never reused).
fn status_code(s: ProtectiveStatus) -> u32 {
    match s {
        ProtectiveStatus::Ok => 0,
        ProtectiveStatus::NonFinite(_) => 2,
        ProtectiveStatus::Unreachable(_) => 3,
        ProtectiveStatus::ImplausibleMotion(_) => 17,
        ProtectiveStatus::InvalidPath(_) => 9,
        ProtectiveStatus::Timing(TimingFault::Repeated) => 20,
        ProtectiveStatus::Timing(TimingFault::Backwards) => 21,
        ProtectiveStatus::Timing(TimingFault::Jump) => 22,
        ProtectiveStatus::Timing(TimingFault::Early) => 23,
        ProtectiveStatus::Timing(TimingFault::ClockChanged) => 24,
    }
}

/// The outputs of one run, each with a row per tick.
struct Outputs<'a> {
    verdict: &'a mut [u32],
    status: &'a mut [u32],
    clearance: &'a mut [f64],
    protective_mm: &'a mut [f64],
    speed_limit: &'a mut [f64],
}

/// The protective verdict of every tick of `run` (T, robots, 3; robot j's TCP in its MCS),
/// with `paths` (T, robots, P, 3; each robot's stop path per tick, P <= 32) or None and
/// `path_tolerance_mm`, into `verdict` (T,) uint32 (0 STOP, 1 FREE, 3 WARN), `status` (T,)
/// uint32 (`DC_STATUS_*`), `clearance` (T,) float64 (mm; NaN when not computed),
/// `protective_mm` and `speed_limit` (T, robots) float64 (mm, mm/s; speed limits NaN when off).
#[pyfunction]
#[pyo3(signature = (cell, run, paths, path_tolerance_mm, warn_mm, speed_limits, verdict, status,
    clearance, protective_mm, speed_limit, table=None))]
#[allow(clippy::too_many_arguments)]
pub fn protective_into(
    py: Python<'_>,
    cell: &PyCell,
    run: &Bound<'_, PyAny>,
    paths: Option<&Bound<'_, PyAny>>,
    path_tolerance_mm: f64,
    warn_mm: f64,
    speed_limits: bool,
    verdict: &Bound<'_, PyAny>,
    status: &Bound<'_, PyAny>,
    clearance: &Bound<'_, PyAny>,
    protective_mm: &Bound<'_, PyAny>,
    speed_limit: &Bound<'_, PyAny>,
    table: Option<&PyTable>,
) -> PyResult<()> {
    let robots = cell.cell.robots.len();
    if let Some(t) = table {
        if t.cell.get().cell.fingerprint() != cell.cell.fingerprint() {
            return Err(PyValueError::new_err(format!(
                "table was built for cell {:?}, not for this cell {:?}: pass its own table",
                t.cell.get().cell.name,
                cell.cell.name
            )));
        }
    }
    let r = input::<f64>("run", run, &[None, Some(robots), Some(3)], &["T", "robots", "3"])?;
    let t = r.shape()[0];
    let p = match paths {
        Some(p) => Some(input::<f64>(
            "paths",
            p,
            &[Some(t), Some(robots), None, Some(3)],
            &["T", "robots", "P", "3"],
        )?),
        None => None,
    };
    let n_points = p.as_ref().map_or(0, |p| p.shape()[2]);
    if p.is_some() && !(1..=MAX_PATH_POINTS).contains(&n_points) {
        return Err(PyValueError::new_err(format!(
            "paths has {n_points} points per stop path, it must have 1 to {MAX_PATH_POINTS}"
        )));
    }
    if !(path_tolerance_mm.is_finite() && path_tolerance_mm >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "path_tolerance_mm = {path_tolerance_mm} must be finite and >= 0 (mm)"
        )));
    }
    let mut v = output::<u32>("verdict", verdict, &[Some(t)], &["T"])?;
    let mut s = output::<u32>("status", status, &[Some(t)], &["T"])?;
    let mut c = output::<f64>("clearance", clearance, &[Some(t)], &["T"])?;
    let per_robot = [Some(t), Some(robots)];
    let mut pm = output::<f64>("protective_mm", protective_mm, &per_robot, &["T", "robots"])?;
    let mut sl = output::<f64>("speed_limit", speed_limit, &per_robot, &["T", "robots"])?;
    {
        let mut slot = cell.protective.lock().map_err(|_| PyValueError::new_err("poisoned"))?;
        if slot.as_ref().is_none_or(|p| p.warn_mm.to_bits() != warn_mm.to_bits()) {
            // Made once per cell and warn_mm (its motor-angle tables take a while): outside
            // the counted work, like the controller's `dc_set_stop_model` at start-up.
            let made = py.detach(|| ProtectiveChecker::new(cell.cell.clone(), warn_mm));
            *slot = Some(Protectives { warn_mm, work: made.map_err(cell_error)? });
        }
    }
    let shape = r.shape().to_vec();
    let path_shape = p.as_ref().map(|p| p.shape().to_vec());
    let values = r.as_slice()?;
    let path_values = match &p {
        Some(p) => Some(p.as_slice()?),
        None => None,
    };
    let mut out = Outputs {
        verdict: v.as_slice_mut()?,
        status: s.as_slice_mut()?,
        clearance: c.as_slice_mut()?,
        protective_mm: pm.as_slice_mut()?,
        speed_limit: sl.as_slice_mut()?,
    };
    py.detach(|| {
        count_alloc::work(|| {
            finite("run", values, &shape)?;
            if let (Some(pv), Some(ps)) = (path_values, &path_shape) {
                finite("paths", pv, ps)?;
            }
            let mut slot = cell.protective.lock().map_err(|_| "the cell's checker is poisoned")?;
            let p = slot.as_mut().ok_or("no protective checker")?;
            let checker = &mut p.work;
            checker.set_speed_limits(speed_limits);
            checker.reset();
            let inputs = Inputs {
                values,
                paths: path_values,
                n_points,
                tolerance_mm: path_tolerance_mm,
                robots,
            };
            match table {
                None => run_ticks(checker, &inputs, None, &mut out),
                Some(t) => {
                    let guard = t.checker.lock().map_err(|_| "the table is poisoned")?;
                    // As table mode's `dc_protective_query`: the bound of clearance tables only.
                    let bound = |a: usize, b: usize, tcps: &[Vec3]| guard.pair_bound(a, b, tcps);
                    let bound: ClearanceBound = &bound;
                    run_ticks(checker, &inputs, guard.has_clearance().then_some(bound), &mut out)
                }
            }
        })
    })
    .map_err(PyValueError::new_err)
}

/// A run's inputs, checked: TCPs (T, robots, 3) and stop paths (T, robots, P, 3) as numbers.
struct Inputs<'a> {
    values: &'a [f64],
    paths: Option<&'a [f64]>,
    n_points: usize,
    tolerance_mm: f64,
    robots: usize,
}

/// The ticks of one run, with the clearance table's `bound` when given.
fn run_ticks(
    checker: &mut ProtectiveChecker,
    inputs: &Inputs,
    bound: Option<ClearanceBound>,
    out: &mut Outputs,
) -> Result<(), String> {
    let (robots, n_points) = (inputs.robots, inputs.n_points);
    let mut tcps = [Vec3::zeros(); MAX_ROBOTS];
    let mut points = [[Vec3::zeros(); MAX_PATH_POINTS]; MAX_ROBOTS];
    let at = |k: usize, v: &[f64]| Vec3::new(v[k], v[k + 1], v[k + 2]);
    for i in 0..out.verdict.len() {
        for (j, tcp) in tcps[..robots].iter_mut().enumerate() {
            *tcp = at(3 * (i * robots + j), inputs.values);
        }
        let mut stop_paths: [Option<StopPath>; MAX_ROBOTS] = [None; MAX_ROBOTS];
        let mut n_paths = 0;
        if let Some(pv) = inputs.paths {
            for (j, robot_points) in points[..robots].iter_mut().enumerate() {
                for (q, point) in robot_points[..n_points].iter_mut().enumerate() {
                    *point = at(3 * ((i * robots + j) * n_points + q), pv);
                }
            }
            for (sp, pts) in stop_paths[..robots].iter_mut().zip(&points) {
                *sp =
                    Some(StopPath { points: &pts[..n_points], tolerance_mm: inputs.tolerance_mm });
            }
            n_paths = robots;
        }
        let mut request =
            ProtectiveRequest::new(&tcps[..robots]).with_paths(&stop_paths[..n_paths]);
        if let Some(b) = bound {
            request = request.with_table(b);
        }
        let report = checker.check(request).map_err(|e| e.to_string())?;
        out.verdict[i] = verdict_code(report.verdict);
        out.status[i] = status_code(report.status);
        out.clearance[i] = report.clearance_mm;
        for (j, rp) in report.robots.iter().enumerate() {
            out.protective_mm[i * robots + j] = rp.protective_mm;
            out.speed_limit[i * robots + j] = rp.speed_limit_mm_s;
        }
    }
    Ok(())
}
