//! `eval --plot`: along each trajectory scenario of the cell, the distance between the two
//! robots' boxes and the label per tick as the table and the exact model report it.
//!
//! The distance is the exact Euclidean distance between the closest boxes of the physical
//! model (margin 0; [`obb_distance`]), 0 exactly when the exact check reports a collision.
//! It shows how close a run comes and how early the table's conservative labels stop it: a
//! table tick labelled collision over a positive distance is a false positive; a tick labelled
//! free at distance 0 would be a false negative.

use crate::picture::{
    colour_strip, draw_mesh, draw_png, legend, plot_err, text, Swatch, HIT, OUTSIDE, ROBOT,
};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::geometry::obb_distance;
use delta_collide::math::Vec3;
use delta_collide::table::TableAnswer;
use plotters::coord::Shift;
use plotters::prelude::*;

const TITLE: u32 = 58;
const STRIP: i32 = 16;
/// Free ticks in the label strips.
const FREE_TICK: RGBColor = RGBColor(120, 200, 120);

/// One run's record: per tick, the distance (NaN where a TCP is unreachable), the table's
/// answer and the exact model's verdict.
pub struct Trace {
    name: String,
    distance: Vec<f64>,
    table: Vec<TableAnswer>,
    exact: Vec<Option<bool>>,
    checker: ExactChecker,
}

impl Trace {
    /// An empty record of the run called `name` on a two-robot `cell`.
    pub fn new(cell: &Cell, name: String) -> Trace {
        let checker = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
        Trace { name, distance: Vec::new(), table: Vec::new(), exact: Vec::new(), checker }
    }

    /// Records one tick: the table's answer for `tcps` (each in its robot's MCS), and the
    /// exact verdict and box distance computed here.
    pub fn push(&mut self, tcps: &[Vec3], table: TableAnswer) -> Result<(), String> {
        let v = self.checker.check(tcps).map_err(|e| e.to_string())?;
        let (reachable, collides) = (v.all_reachable(), v.collides());
        let distance = if reachable {
            let (a, b) = (self.checker.boxes(0).as_slice(), self.checker.boxes(1).as_slice());
            a.iter()
                .flat_map(|x| b.iter().map(move |y| obb_distance(x, y)))
                .fold(f64::INFINITY, f64::min)
        } else {
            f64::NAN
        };
        self.distance.push(distance);
        self.table.push(table);
        self.exact.push(reachable.then_some(collides));
        Ok(())
    }

    /// False positives and negatives of the table against the exact model on this run.
    fn errors(&self) -> (usize, usize) {
        let mut fp_fn = (0, 0);
        for (t, e) in self.table.iter().zip(&self.exact) {
            match (t, e) {
                (TableAnswer::Collision, Some(false)) => fp_fn.0 += 1,
                (TableAnswer::Free, Some(true)) => fp_fn.1 += 1,
                _ => {}
            }
        }
        fp_fn
    }
}

/// Draws one panel per trace into a PNG.
pub fn draw_plot(
    path: &std::path::Path,
    size: (u32, u32),
    title: &str,
    traces: &[Trace],
) -> Result<(), String> {
    if traces.is_empty() {
        return Err("the cell has no scenario in c_harness/scenarios.txt to plot".into());
    }
    draw_png(path, size, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        root.draw(&Text::new(title.to_string(), (12, 8), text(17, BLACK))).map_err(plot_err)?;
        draw_legend(root)?;
        let (_, body) = root.split_vertically(TITLE);
        for (area, trace) in body.split_evenly((traces.len(), 1)).iter().zip(traces) {
            draw_trace(area, trace)?;
        }
        Ok(())
    })
}

fn draw_legend(root: &DrawingArea<BitMapBackend, Shift>) -> Result<(), String> {
    let entries = [
        (Swatch::Line(ROBOT[0]), "distance between the robots' boxes (exact model, margin 0)"),
        (Swatch::Square(HIT), "collision"),
        (Swatch::Square(FREE_TICK), "free"),
        (Swatch::Square(OUTSIDE), "unreachable"),
    ];
    let x = legend(root, (12, 34), &entries)?;
    root.draw(&Text::new(
        "(strips: table, then exact model)",
        (x, 34),
        text(13, RGBColor(90, 90, 90)),
    ))
    .map_err(plot_err)
}

fn draw_trace(area: &DrawingArea<BitMapBackend, Shift>, trace: &Trace) -> Result<(), String> {
    let n = trace.distance.len();
    let max = trace.distance.iter().copied().filter(|d| d.is_finite()).fold(0.0, f64::max).max(1.0);
    let closest =
        trace.distance.iter().copied().filter(|d| d.is_finite()).fold(f64::INFINITY, f64::min);
    let (fp, fneg) = trace.errors();
    let caption = format!(
        "{}: closest {closest:.1} mm; table vs exact: {fp} false positive, {fneg} false negative ticks",
        trace.name
    );
    let mut chart = ChartBuilder::on(area)
        .caption(caption, text(15, BLACK))
        .margin(10)
        .margin_bottom(2 * STRIP as u32 + 14)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..n as f64, 0.0..max * 1.08)
        .map_err(plot_err)?;
    draw_mesh(&mut chart, "tick (1 ms)", "distance (mm)")?;
    // The distance as line segments between unreachable ticks.
    let mut segment: Vec<(f64, f64)> = Vec::new();
    for (t, &d) in trace.distance.iter().enumerate().chain([(n, &f64::NAN)]) {
        if d.is_finite() {
            segment.push((t as f64, d));
        } else if !segment.is_empty() {
            chart
                .draw_series(LineSeries::new(
                    std::mem::take(&mut segment),
                    ROBOT[0].stroke_width(2),
                ))
                .map_err(plot_err)?;
        }
    }
    // The label strips under the plotting area, aligned with its x axis.
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let (bx, by) = area.get_base_pixel();
    let (left, width) = (xr.start - bx, (xr.end - xr.start) as f64);
    let top = yr.end - by + 36 + 4;
    let rows: [(&str, Vec<RGBColor>); 2] = [
        ("table", trace.table.iter().map(|a| table_colour(*a)).collect()),
        ("exact", trace.exact.iter().map(|e| exact_colour(*e)).collect()),
    ];
    for (r, (label, colours)) in rows.iter().enumerate() {
        colour_strip(area, label, (left, width), top + r as i32 * STRIP, STRIP, colours)?;
    }
    Ok(())
}

fn table_colour(a: TableAnswer) -> RGBColor {
    match a {
        TableAnswer::Collision => HIT,
        TableAnswer::Free => FREE_TICK,
        TableAnswer::Unreachable(_) => OUTSIDE,
    }
}

fn exact_colour(e: Option<bool>) -> RGBColor {
    match e {
        Some(true) => HIT,
        Some(false) => FREE_TICK,
        None => OUTSIDE,
    }
}
