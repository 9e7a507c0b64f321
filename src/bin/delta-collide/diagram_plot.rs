//! `simulate --plot`: the coordination diagram of a run's first robot pair (Kant and Zucker's
//! picture of path-velocity coordination): robot A's progress across, robot B's up, the
//! sample pairs of the two whole programmes whose boxes come within the coordination's
//! clearance shaded, the programmed timing as the diagonal, and the run's course through
//! the diagram with its STOP events. A course that stays on the diagonal kept the programmed
//! timing; where it leaves it, a robot waited.

use crate::picture::{draw_mesh, draw_png, legend, plot_err, text, Swatch, HIT, ROBOT};
use delta_collide::sim::cells::ConflictCells;
use delta_collide::sim::run::Trace;
use plotters::prelude::*;

const TITLE: u32 = 60;
const CONFLICT: RGBColor = RGBColor(150, 150, 150);
const PLANNED: RGBColor = RGBColor(120, 200, 120);

/// Draws the diagram of robots `pair` (their names in `names`) of one run into the PNG file
/// `path`.
///
/// # Errors
/// A run without ticks, or the drawing's or the file's error.
pub fn draw_diagram(
    path: &std::path::Path,
    title: &str,
    names: (&str, &str),
    pair: (usize, usize),
    cells: &ConflictCells,
    trace: &Trace,
) -> Result<(), String> {
    if trace.progress.is_empty() {
        return Err(format!("{}: the run has no ticks to plot", path.display()));
    }
    let (a, b) = pair;
    let s = cells.stride as f64;
    let (w, h) = (cells.rows as f64 * s, cells.cols as f64 * s);
    draw_png(path, (900, 940), |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        root.draw(&Text::new(title.to_string(), (12, 8), text(17, BLACK))).map_err(plot_err)?;
        let entries = [
            (Swatch::Square(CONFLICT), "boxes within the clearance"),
            (Swatch::Line(PLANNED), "programmed timing"),
            (Swatch::Line(ROBOT[0]), "the run"),
            (Swatch::Square(HIT), "STOP event"),
        ];
        legend(root, (12, 36), &entries)?;
        let (_, body) = root.split_vertically(TITLE);
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..w, 0.0..h)
            .map_err(plot_err)?;
        let x_desc = format!("progress of {} (programme ticks)", names.0);
        let y_desc = format!("progress of {} (programme ticks)", names.1);
        draw_mesh(&mut chart, &x_desc, &y_desc)?;
        let shaded = (0..cells.rows).flat_map(|i| (0..cells.cols).map(move |k| (i, k)));
        chart
            .draw_series(shaded.filter(|&(i, k)| cells.cells[i * cells.cols + k]).map(|(i, k)| {
                let (x, y) = (i as f64 * s, k as f64 * s);
                Rectangle::new([(x, y), (x + s, y + s)], CONFLICT.filled())
            }))
            .map_err(plot_err)?;
        let diagonal = vec![(0.0, 0.0), (w.min(h), w.min(h))];
        chart.draw_series(LineSeries::new(diagonal, PLANNED.stroke_width(2))).map_err(plot_err)?;
        let course = trace.progress.iter().map(|p| (p[a], p[b]));
        chart.draw_series(LineSeries::new(course, ROBOT[0].stroke_width(2))).map_err(plot_err)?;
        chart
            .draw_series(trace.stops.iter().map(|p| Circle::new((p[a], p[b]), 4, HIT.filled())))
            .map_err(plot_err)?;
        Ok(())
    })
}
