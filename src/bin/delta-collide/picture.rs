//! What the three pictures share: an RGB canvas that plotters draws into, the font compiled
//! into the binary, PNG output, colours and a 2-D convex hull.
//!
//! No system font or external program is used: text is drawn with DejaVu Sans (a subset, see
//! `font/LICENSE`) through plotters' `ab_glyph` backend, and the PNG is encoded by the `png`
//! crate.

use crate::files::write_file;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans, printable ASCII and a few symbols (`font/LICENSE` says how it was cut).
const FONT: &[u8] = include_bytes!("font/DejaVuSans-subset.ttf");

/// Free configurations and boxes.
pub const FREE: RGBColor = RGBColor(255, 255, 255);
/// Collisions (thesis Figures 3.16-3.17 draw them black).
pub const COLLISION: RGBColor = RGBColor(0, 0, 0);
/// Colliding boxes and collision ticks.
pub const HIT: RGBColor = RGBColor(220, 30, 30);
/// Cells whose centre is unreachable.
pub const UNREACHABLE: RGBColor = RGBColor(240, 170, 60);
/// Cells outside the sampled grid.
pub const OUTSIDE: RGBColor = RGBColor(200, 200, 200);
/// One colour per robot (cycled).
pub const ROBOT: [RGBColor; 4] =
    [RGBColor(40, 90, 200), RGBColor(20, 150, 80), RGBColor(150, 60, 170), RGBColor(180, 120, 20)];

/// Makes the compiled-in font the `sans-serif` family of plotters (once per process).
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_err() {
            panic!("the compiled-in font is not a valid TrueType file");
        }
    });
}

/// A plotters error as a message.
pub fn plot_err<E: std::fmt::Debug>(e: E) -> String {
    format!("drawing failed: {e:?}")
}

/// Draws with `draw` on a white `width` x `height` RGB canvas and writes it to `path` as PNG
/// (replacing `path` only once the file is complete).
///
/// # Errors
/// The drawing's error, or the file's.
pub fn draw_png(
    path: &Path,
    (width, height): (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<(), String> {
    register_font();
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        draw(&root)?;
        root.present().map_err(plot_err)?;
    }
    write_png(path, &rgb, width, height)
}

/// Encodes an 8-bit RGB buffer as a PNG file.
fn write_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<(), String> {
    let shown = path.display();
    write_file(path, |out| {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().map_err(|e| format!("{shown}: {e}"))?;
        writer.write_image_data(rgb).map_err(|e| format!("{shown}: {e}"))?;
        writer.finish().map_err(|e| format!("{shown}: {e}"))
    })
}

/// A text style of the compiled-in font.
pub fn text(size: u32, color: RGBColor) -> TextStyle<'static> {
    ("sans-serif", size).into_font().color(&color)
}

/// What a legend entry shows before its label.
pub enum Swatch {
    /// A filled square with a thin black border.
    Square(RGBColor),
    /// A filled square (translucent fill) with a border of its own colour.
    Outlined(RGBAColor, RGBColor),
    /// A short line.
    Line(RGBColor),
}

/// Draws legend entries in a row from `(x, y)` (top left); returns the x after the last one.
pub fn legend(
    area: &DrawingArea<BitMapBackend, Shift>,
    (mut x, y): (i32, i32),
    entries: &[(Swatch, &str)],
) -> Result<i32, String> {
    let style = text(13, BLACK);
    for (swatch, label) in entries {
        let square = [(x, y + 1), (x + 14, y + 13)];
        match swatch {
            Swatch::Square(c) => {
                area.draw(&Rectangle::new(square, c.filled())).map_err(plot_err)?;
                area.draw(&Rectangle::new(square, BLACK.stroke_width(1))).map_err(plot_err)?;
            }
            Swatch::Outlined(fill, c) => {
                area.draw(&Rectangle::new(square, fill.filled())).map_err(plot_err)?;
                area.draw(&Rectangle::new(square, c.stroke_width(2))).map_err(plot_err)?;
            }
            Swatch::Line(c) => {
                area.draw(&PathElement::new(vec![(x, y + 7), (x + 14, y + 7)], c.stroke_width(2)))
                    .map_err(plot_err)?;
            }
        }
        area.draw(&Text::new(label.to_string(), (x + 20, y), style.clone())).map_err(plot_err)?;
        let (w, _) = area.estimate_text_size(label, &style).map_err(plot_err)?;
        x += 20 + w as i32 + 18;
    }
    Ok(x)
}

/// A strip of one colour per tick, `height` pixels tall (2 of them left as a gap) from `y`,
/// over `(left, width)` pixels of `area` (the x range of a chart's plotting area), with
/// `label` right-aligned before it.
pub fn colour_strip(
    area: &DrawingArea<BitMapBackend, Shift>,
    label: &str,
    (left, width): (i32, f64),
    y: i32,
    height: i32,
    colours: &[RGBColor],
) -> Result<(), String> {
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let n = colours.len().max(1);
    let label_pos = (left - 6, y + height / 2);
    area.draw(&Text::new(
        label.to_string(),
        label_pos,
        text(12, BLACK).pos(Pos::new(HPos::Right, VPos::Center)),
    ))
    .map_err(plot_err)?;
    // One run of equal colour at a time.
    let mut start = 0;
    for t in 1..=colours.len() {
        if t == colours.len() || colours[t] != colours[start] {
            let px = |tick: usize| left + (tick as f64 / n as f64 * width).round() as i32;
            let (a, b) = (px(start), px(t).max(px(start) + 1));
            area.draw(&Rectangle::new([(a, y), (b, y + height - 2)], colours[start].filled()))
                .map_err(plot_err)?;
            start = t;
        }
    }
    Ok(())
}

/// The convex hull of 2-D points, counter-clockwise, without repeated points (Andrew's
/// monotone chain).
pub fn convex_hull(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.to_vec();
    p.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// A chart of `f64` against `f64` on a bitmap: the plots' one coordinate system.
pub type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The plots' grid, whole-number labels and axis names.
pub fn draw_mesh(chart: &mut Chart, x_desc: &str, y_desc: &str) -> Result<(), String> {
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(230, 230, 230))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(text(12, BLACK))
        .axis_desc_style(text(13, BLACK))
        .draw()
        .map_err(plot_err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts =
            [(0.0, 0.0), (1.0, 0.0), (0.5, 0.5), (1.0, 1.0), (0.0, 1.0), (0.2, 0.8), (1.0, 0.5)];
        assert_eq!(convex_hull(&pts), vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
    }
}
