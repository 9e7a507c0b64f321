//! `check`, `clearance` and `boxes` over arrays of configurations: the exact check of the cell
//! (thesis 3.1), its exact signed clearance (SPEC §8) and its boxes, one configuration after
//! the other with the cell's checker, the GIL released, nothing allocated.

use crate::arrays::{configuration, finite, input, output};
use crate::count_alloc;
use crate::pycell::PyCell;
use delta_collide::cell::exact::PairState;
use delta_collide::cell::protective::clearance_now;
use delta_collide::math::Vec3;
use numpy::PyUntypedArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `tcps` as `(N, robots, 3)` float64: its numbers and N.
fn tcps_shape(cell: &PyCell) -> [Option<usize>; 3] {
    [None, Some(cell.cell.robots.len()), Some(3)]
}

const TCPS: [&str; 3] = ["N", "robots", "3"];

/// The exact check of every configuration of `tcps` (N, robots, 3), into `reachable` (N,)
/// bool, `collide` (N,) bool (false unless every TCP is reachable) and `pairs` (N, pairs) bool,
/// each pair that can meet in `cell.pairs` order (false when one of its TCPs is unreachable).
#[pyfunction]
pub fn check_into(
    py: Python<'_>,
    cell: &PyCell,
    tcps: &Bound<'_, PyAny>,
    reachable: &Bound<'_, PyAny>,
    collide: &Bound<'_, PyAny>,
    pairs: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let t = input::<f64>("tcps", tcps, &tcps_shape(cell), &TCPS)?;
    let n = t.shape()[0];
    let n_pairs = cell.cell.pairs_that_can_meet().len();
    let mut r = output::<bool>("reachable", reachable, &[Some(n)], &["N"])?;
    let mut c = output::<bool>("collide", collide, &[Some(n)], &["N"])?;
    let mut p = output::<bool>("pairs", pairs, &[Some(n), Some(n_pairs)], &["N", "pairs"])?;
    let shape = t.shape().to_vec();
    let values = t.as_slice()?;
    let (r, c, p) = (r.as_slice_mut()?, c.as_slice_mut()?, p.as_slice_mut()?);
    let robots = cell.cell.robots.len();
    py.detach(|| {
        count_alloc::work(|| {
            finite("tcps", values, &shape)?;
            let mut checker = cell.exact.lock().map_err(|_| "the cell's checker is poisoned")?;
            let mut buf = [Vec3::zeros(); delta_collide::cell::MAX_ROBOTS];
            let buf = &mut buf[..robots];
            for i in 0..n {
                configuration(values, robots, i, buf);
                let v = checker.check(buf).map_err(|e| e.to_string())?;
                // As `dc_query` and the CLI: no verdict unless every TCP is reachable; the
                // pairs of reachable robots are still decided.
                r[i] = v.all_reachable();
                c[i] = r[i] && v.collides();
                for (k, pair) in v.pairs.iter().enumerate() {
                    p[i * n_pairs + k] = matches!(pair.state, PairState::Collides(..));
                }
            }
            Ok::<(), String>(())
        })
    })
    .map_err(PyValueError::new_err)
}

/// The exact signed clearance of every configuration of `tcps` (N, robots, 3) into `out` (N,)
/// float64 (mm): the gap, or minus the penetration depth; NaN when a TCP is unreachable,
/// `inf` when no pair can meet.
#[pyfunction]
pub fn clearance_into(
    py: Python<'_>,
    cell: &PyCell,
    tcps: &Bound<'_, PyAny>,
    out: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let t = input::<f64>("tcps", tcps, &tcps_shape(cell), &TCPS)?;
    let n = t.shape()[0];
    let mut o = output::<f64>("out", out, &[Some(n)], &["N"])?;
    let shape = t.shape().to_vec();
    let values = t.as_slice()?;
    let o = o.as_slice_mut()?;
    let robots = cell.cell.robots.len();
    py.detach(|| {
        count_alloc::work(|| {
            finite("tcps", values, &shape)?;
            let mut checker = cell.exact.lock().map_err(|_| "the cell's checker is poisoned")?;
            let mut buf = [Vec3::zeros(); delta_collide::cell::MAX_ROBOTS];
            let buf = &mut buf[..robots];
            for (i, slot) in o.iter_mut().enumerate() {
                configuration(values, robots, i, buf);
                let v = checker.place_boxes(buf).map_err(|e| e.to_string())?;
                *slot = if v.all_reachable() { clearance_now(&checker).0 } else { f64::NAN };
            }
            Ok::<(), String>(())
        })
    })
    .map_err(PyValueError::new_err)
}

/// The boxes (WCS) of every configuration of `tcps` (N, robots, 3): `centers` (N, robots,
/// boxes, 3), `axes` (N, robots, boxes, 3, 3; the box axes as columns), `half` (N, robots,
/// boxes, 3), `boxes` the most boxes of a robot; NaN for a robot whose TCP is unreachable and
/// for boxes past a robot's count.
#[pyfunction]
pub fn boxes_into(
    py: Python<'_>,
    cell: &PyCell,
    tcps: &Bound<'_, PyAny>,
    centers: &Bound<'_, PyAny>,
    axes: &Bound<'_, PyAny>,
    half: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let t = input::<f64>("tcps", tcps, &tcps_shape(cell), &TCPS)?;
    let (n, robots) = (t.shape()[0], cell.cell.robots.len());
    let nb = delta_collide::robot::MAX_BOXES;
    let dims = [Some(n), Some(robots), Some(nb)];
    let names = ["N", "robots", "MAX_BOXES"];
    let mut c = output::<f64>("centers", centers, &[dims[0], dims[1], dims[2], Some(3)], &names)?;
    let mut a =
        output::<f64>("axes", axes, &[dims[0], dims[1], dims[2], Some(3), Some(3)], &names)?;
    let mut h = output::<f64>("half", half, &[dims[0], dims[1], dims[2], Some(3)], &names)?;
    let shape = t.shape().to_vec();
    let values = t.as_slice()?;
    let (c, a, h) = (c.as_slice_mut()?, a.as_slice_mut()?, h.as_slice_mut()?);
    py.detach(|| {
        count_alloc::work(|| {
            finite("tcps", values, &shape)?;
            let checker = cell.exact.lock().map_err(|_| "the cell's checker is poisoned")?;
            let mut boxes = delta_collide::robot::RobotBoxes::empty();
            c.fill(f64::NAN);
            a.fill(f64::NAN);
            h.fill(f64::NAN);
            for i in 0..n {
                for j in 0..robots {
                    let k = 3 * (i * robots + j);
                    let tcp = Vec3::new(values[k], values[k + 1], values[k + 2]);
                    if checker.boxes_in_wcs(j, &tcp, &mut boxes).is_err() {
                        continue;
                    }
                    for (b, o) in boxes.as_slice().iter().enumerate() {
                        let at = (i * robots + j) * nb + b;
                        c[3 * at..3 * at + 3].copy_from_slice(o.center.as_slice());
                        h[3 * at..3 * at + 3].copy_from_slice(o.half.as_slice());
                        for r in 0..3 {
                            for col in 0..3 {
                                a[9 * at + 3 * r + col] = o.axes[(r, col)];
                            }
                        }
                    }
                }
            }
            Ok::<(), String>(())
        })
    })
    .map_err(PyValueError::new_err)
}
