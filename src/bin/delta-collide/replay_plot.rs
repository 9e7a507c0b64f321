//! `replay --plot`: along a replayed run, per tick, the cell's signed clearance now, each
//! robot's protective distance (how far its TCP may travel until it stands still, `S` of
//! SPEC §8) and the protective verdict as a colour band. Where the clearance line stays above
//! the protective distances the run is comfortably stoppable; the band shows where the
//! verdict could not prove it.

use crate::picture::{
    colour_strip, draw_mesh, draw_png, legend, plot_err, text, Chart, Swatch, HIT, OUTSIDE, ROBOT,
};
use delta_collide::cell::protective::{Protective, ProtectiveReport, ProtectiveStatus};
use plotters::coord::Shift;
use plotters::prelude::*;

const TITLE: u32 = 60;
const STRIP: i32 = 22;
const FREE_TICK: RGBColor = RGBColor(120, 200, 120);
const WARN_TICK: RGBColor = RGBColor(240, 170, 60);

/// A replayed run: per tick the signed clearance (mm; NaN without an exact check), each
/// robot's protective distance (mm; NaN without a proof attempt), the verdict and whether
/// its status was OK.
pub struct ReplayTrace {
    robots: Vec<String>,
    clearance: Vec<f64>,
    protective: Vec<Vec<f64>>,
    verdict: Vec<(Protective, bool)>,
}

impl ReplayTrace {
    /// An empty run of the robots called `robots`.
    pub fn new(robots: Vec<String>) -> ReplayTrace {
        let protective = vec![Vec::new(); robots.len()];
        ReplayTrace { robots, clearance: Vec::new(), protective, verdict: Vec::new() }
    }

    /// Records one tick: the checker's report and the signed clearance computed beside it.
    pub fn push(&mut self, r: &ProtectiveReport, clearance: Option<f64>) {
        let ok = r.status == ProtectiveStatus::Ok;
        self.clearance.push(clearance.unwrap_or(f64::NAN));
        for (p, x) in self.protective.iter_mut().zip(&r.robots) {
            p.push(if ok { x.protective_mm } else { f64::NAN });
        }
        self.verdict.push((r.verdict, ok));
    }

    /// Ticks recorded.
    pub fn len(&self) -> usize {
        self.verdict.len()
    }
}

fn verdict_colour((v, ok): (Protective, bool)) -> RGBColor {
    match (v, ok) {
        (Protective::Free, _) => FREE_TICK,
        (Protective::Warn, _) => WARN_TICK,
        (Protective::Stop, true) => HIT,
        (Protective::Stop, false) => OUTSIDE,
    }
}

/// Draws `trace` into the PNG file `path` of `size` pixels.
///
/// # Errors
/// An empty run (nothing to draw), or the drawing's or the file's error.
pub fn draw_replay(
    path: &std::path::Path,
    size: (u32, u32),
    title: &str,
    trace: &ReplayTrace,
) -> Result<(), String> {
    if trace.len() == 0 {
        return Err(format!(
            "{}: the input has no rows, so there is nothing to plot",
            path.display()
        ));
    }
    draw_png(path, size, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        root.draw(&Text::new(title.to_string(), (12, 8), text(17, BLACK))).map_err(plot_err)?;
        draw_legend(root, trace)?;
        let (_, body) = root.split_vertically(TITLE);
        draw_run(&body, trace)
    })
}

fn draw_legend(
    root: &DrawingArea<BitMapBackend, Shift>,
    trace: &ReplayTrace,
) -> Result<(), String> {
    let names: Vec<String> =
        trace.robots.iter().map(|r| format!("protective distance {r}")).collect();
    let mut entries = vec![(Swatch::Line(ROBOT[0]), "clearance (exact, signed)")];
    for (k, name) in names.iter().enumerate() {
        entries.push((Swatch::Line(ROBOT[1 + k % (ROBOT.len() - 1)]), name.as_str()));
    }
    entries.extend([
        (Swatch::Square(FREE_TICK), "FREE"),
        (Swatch::Square(WARN_TICK), "WARN"),
        (Swatch::Square(HIT), "STOP"),
        (Swatch::Square(OUTSIDE), "STOP, status not OK"),
    ]);
    legend(root, (12, 36), &entries)?;
    Ok(())
}

/// `(min, max)` of the finite values, with 0 included.
fn range<'a>(values: impl Iterator<Item = &'a f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((0.0, 0.0), |(lo, hi), &v| (f64::min(lo, v), f64::max(hi, v)))
}

fn draw_run(area: &DrawingArea<BitMapBackend, Shift>, trace: &ReplayTrace) -> Result<(), String> {
    let n = trace.len();
    let (lo, hi) = range(trace.clearance.iter().chain(trace.protective.iter().flatten()));
    let pad = 0.06 * (hi - lo).max(1.0);
    let count = |v: Protective| trace.verdict.iter().filter(|x| x.0 == v).count();
    let caption = format!(
        "{n} ticks: FREE {}, WARN {}, STOP {}; smallest clearance {:.1} mm",
        count(Protective::Free),
        count(Protective::Warn),
        count(Protective::Stop),
        trace.clearance.iter().copied().filter(|c| !c.is_nan()).fold(f64::INFINITY, f64::min)
    );
    let mut chart = ChartBuilder::on(area)
        .caption(caption, text(15, BLACK))
        .margin(10)
        .margin_bottom(STRIP as u32 + 14)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..n.max(2) as f64 - 1.0, lo - pad..hi + pad)
        .map_err(plot_err)?;
    draw_mesh(&mut chart, "tick", "mm")?;
    if lo < 0.0 {
        let zero = vec![(0.0, 0.0), (n as f64, 0.0)];
        chart.draw_series(LineSeries::new(zero, BLACK.stroke_width(1))).map_err(plot_err)?;
    }
    for (k, p) in trace.protective.iter().enumerate() {
        line(&mut chart, p, ROBOT[1 + k % (ROBOT.len() - 1)])?;
    }
    line(&mut chart, &trace.clearance, ROBOT[0])?;
    // The verdict band under the plotting area, aligned with its x axis.
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let (bx, by) = area.get_base_pixel();
    let (left, width) = (xr.start - bx, (xr.end - xr.start) as f64);
    let colours: Vec<RGBColor> = trace.verdict.iter().map(|&v| verdict_colour(v)).collect();
    colour_strip(area, "verdict", (left, width), yr.end - by + 36 + 4, STRIP, &colours)
}

/// `values` per tick as line segments between the NaN ticks.
fn line(chart: &mut Chart, values: &[f64], colour: RGBColor) -> Result<(), String> {
    let mut segment: Vec<(f64, f64)> = Vec::new();
    for (t, &d) in values.iter().enumerate().chain([(values.len(), &f64::NAN)]) {
        if d.is_finite() {
            segment.push((t as f64, d));
        } else if !segment.is_empty() {
            chart
                .draw_series(LineSeries::new(std::mem::take(&mut segment), colour.stroke_width(2)))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}
