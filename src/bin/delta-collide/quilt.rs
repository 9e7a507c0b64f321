//! `quilt`: 2-D slices of a table, as in the thesis's Figures 3.16 and 3.17 (3.2.6).
//!
//! A 6-D grid cell is `(ix, iy, iz, ix', iy', iz')`: A's cell, then B's (SPEC §4). A quilt
//! fixes one pair of dimensions and lays out, in a grid over a second pair (the "quilt"), the
//! 2-D slices over the third pair: with `--axes yy`, yy'-slices in a quilt over (z, z') at
//! fixed (x, x') (Figure 3.16); with `zz`, zz'-slices over (y, y') (Figure 3.17); with `xx`,
//! xx'-slices over (z, z') at fixed (y, y'). Inside a slice and across the quilt the first
//! dimension runs to the right and the primed one up, counted from the bottom left as in the
//! thesis's Figure 3.15. With `--a ix,iy,iz`, A's cell is fixed and each panel is an
//! x'y'-slice of B's grid at one depth `z'`: where B may go while A is in that cell.
//!
//! Colours: black where the table stores a collision, white where it stores free, orange
//! where either robot's cell is proved wholly unreachable ([`cube_unreachable`]: no query can
//! land there, the table may store anything), grey where either cell lies outside the sampled
//! grid (no table entry: queries there fall back to the exact check). A cell whose centre is
//! unreachable but which may hold reachable TCPs shows the table's answer. A clearance
//! table's free cells are shaded by their proved clearance level, white for the lowest to
//! dark blue for the top.

use crate::args::{usage_error, QuiltArgs, QuiltAxes};
use crate::picture::{
    draw_png, legend, plot_err, text, Swatch, COLLISION, FREE, OUTSIDE, UNREACHABLE,
};
use crate::{load_table, Failure};
use clap::error::ErrorKind;
use delta_collide::cell::Cell;
use delta_collide::cspace::{SampleGrid, Workspace};
use delta_collide::math::Vec3;
use delta_collide::robot::motion_bound::cube_unreachable;
use delta_collide::robot::Delta3;
use delta_collide::table::Table;
use plotters::coord::Shift;
use plotters::prelude::*;

const NAMES: [&str; 6] = ["x", "y", "z", "x'", "y'", "z'"];
const TITLE: u32 = 92;
const LEFT: u32 = 78;
const BOTTOM: u32 = 44;
const PAD: u32 = 12;

/// What a grid cell of one robot is: outside the sampled grid, sampled but proved wholly
/// unreachable, or sampled and (possibly partly) reachable.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sampled {
    Outside,
    Unreachable,
    Reachable,
}

/// One robot's grid as a dense `k^3` map, plus the index range each axis's samples span.
struct GridMap {
    grid: SampleGrid,
    state: Vec<Sampled>,
    range: [(u16, u16); 3],
}

impl GridMap {
    /// The map of `grid` for a robot of geometry `delta`.
    fn new(grid: SampleGrid, delta: &Delta3) -> Self {
        let k = grid.k as usize;
        let mut state = vec![Sampled::Outside; k * k * k];
        let mut range = [(u16::MAX, 0u16); 3];
        for (c, &centre_reachable) in grid.cells.iter().zip(&grid.reachable) {
            let unreachable =
                !centre_reachable && cube_unreachable(delta, &grid.center(*c), 0.5 * grid.r);
            state[(c[0] as usize * k + c[1] as usize) * k + c[2] as usize] =
                if unreachable { Sampled::Unreachable } else { Sampled::Reachable };
            for a in 0..3 {
                range[a] = (range[a].0.min(c[a]), range[a].1.max(c[a]));
            }
        }
        GridMap { grid, state, range }
    }

    fn at(&self, c: [u16; 3]) -> Sampled {
        let k = self.grid.k as usize;
        self.state[(c[0] as usize * k + c[1] as usize) * k + c[2] as usize]
    }
}

/// One slice on the picture: where it goes in the quilt and the indices it fixes.
struct Panel {
    col: usize,
    row: usize,
    /// The 6-D cell with the two inner dimensions still to be filled in.
    cell: [u16; 6],
    caption: Option<String>,
}

/// A laid-out quilt: inner dimensions, panels, outer labels, title.
struct Quilt {
    inner: [usize; 2],
    cols: usize,
    rows: usize,
    panels: Vec<Panel>,
    /// Labels under each column and beside each row (thesis layout), with the axes' names.
    col_labels: Option<(String, Vec<String>)>,
    row_labels: Option<(String, Vec<String>)>,
    title: String,
}

/// `quilt`: draws the slices `args` asks for.
pub fn quilt(args: &QuiltArgs) -> Result<(), Failure> {
    let cell = &args.cell;
    let checker = load_table(cell, &args.table)?;
    let (header, table) = (checker.header(), checker.table());
    let k = 1u32 << table.levels();
    let grid = |j: usize| {
        let delta = &cell.robots[j].model.delta;
        SampleGrid::new(&header.workspace, k, delta).map(|g| GridMap::new(g, delta))
    };
    let maps = [grid(0)?, grid(1)?];
    let path = args.table.display();
    let what = format!(
        "cell {}, table {} ({}, k = {k}, r = {:.2} mm)",
        cell.name,
        path,
        table.name(),
        header.r
    );
    let quilt = match args.a {
        Some(a) => b_slices(&maps, within_grid("--a", a, k)?, &what),
        None => {
            let fix = args.fix.map(|f| within_grid("--fix", f, k)).transpose()?;
            thesis_quilt(cell, &maps, &header.workspace, args.axes, fix, &what)
        }
    };
    let (output, size) = (&args.output, (args.width, args.height));
    layout(&quilt, &maps, size).map_err(|m| usage_error("quilt", ErrorKind::ValueValidation, m))?;
    let counts = count(&quilt, &maps, table);
    draw_png(output, size, |root| draw(root, &quilt, &maps, table))?;
    println!(
        "{}: {} x {} pixels, {} slices of {} x {} cells: {} collision, {} free, {} unreachable, {} outside the grid",
        output.display(),
        size.0,
        size.1,
        quilt.panels.len(),
        span(&maps, quilt.inner[0]).len(),
        span(&maps, quilt.inner[1]).len(),
        counts[0],
        counts[1],
        counts[2],
        counts[3]
    );
    Ok(())
}

/// Where the panels go: cells per panel, caption and gap heights, pixels per grid cell.
struct Layout {
    nh: usize,
    nv: usize,
    caption: u32,
    gap: u32,
    s: f64,
}

/// The layout of `q` on a `w` x `h` picture.
///
/// # Errors
/// When a grid cell would get less than one pixel, with the size that would do.
fn layout(q: &Quilt, maps: &[GridMap; 2], (w, h): (u32, u32)) -> Result<Layout, String> {
    let (nh, nv) = (span(maps, q.inner[0]).len(), span(maps, q.inner[1]).len());
    let caption = if q.panels.iter().any(|p| p.caption.is_some()) { 18 } else { 0 };
    let gap = 3;
    let avail_w = w.saturating_sub(LEFT + PAD + gap * q.cols as u32) as f64;
    let avail_h = h.saturating_sub(TITLE + BOTTOM + PAD + (gap + caption) * q.rows as u32) as f64;
    // Pixels per grid cell: fractional, so that the quilt fills the picture.
    let s = (avail_w / (q.cols * nh) as f64).min(avail_h / (q.rows * nv) as f64);
    if s < 1.0 {
        return Err(format!(
            "the picture is too small for {} x {} slices of {nh} x {nv} cells: give at least --width {} --height {}",
            q.cols,
            q.rows,
            LEFT + PAD + (gap + (nh as u32)) * q.cols as u32,
            TITLE + BOTTOM + PAD + (gap + caption + nv as u32) * q.rows as u32
        ));
    }
    Ok(Layout { nh, nv, caption, gap, s })
}

/// `indices`, when each is below the table's `k` (a usage error otherwise).
fn within_grid<const N: usize>(
    name: &str,
    indices: [u16; N],
    k: u32,
) -> Result<[u16; N], clap::Error> {
    if indices.iter().all(|&i| u32::from(i) < k) {
        return Ok(indices);
    }
    let shown: Vec<String> = indices.iter().map(u16::to_string).collect();
    Err(usage_error(
        "quilt",
        ErrorKind::ValueValidation,
        format!(
            "{name} {}: the table has k = {k}, so each grid index must be from 0 to {}",
            shown.join(","),
            k - 1
        ),
    ))
}

/// The sampled index range of 6-D dimension `d`.
fn span(maps: &[GridMap; 2], d: usize) -> std::ops::RangeInclusive<u16> {
    let (lo, hi) = maps[d / 3].range[d % 3];
    lo..=hi
}

/// The centre coordinate (mm, the robot's MCS) of index `i` along 6-D dimension `d`.
fn coordinate(maps: &[GridMap; 2], d: usize, i: u16) -> f64 {
    let mut c = [0u16; 3];
    c[d % 3] = i;
    maps[d / 3].grid.center(c)[d % 3]
}

/// Figures 3.16 / 3.17: slices over one dimension pair in a quilt over another, the third
/// pair fixed.
fn thesis_quilt(
    cell: &Cell,
    maps: &[GridMap; 2],
    ws: &Workspace,
    axes: QuiltAxes,
    fix: Option<[u16; 2]>,
    what: &str,
) -> Quilt {
    let (inner, outer, fixed) = match axes {
        QuiltAxes::Yy => (1, 2, 0),
        QuiltAxes::Zz => (2, 1, 0),
        QuiltAxes::Xx => (0, 2, 1),
    };
    let fixed_idx = fix.unwrap_or_else(|| default_fix(cell, maps, ws, fixed));
    let (cols, rows) = (span(maps, outer), span(maps, outer + 3));
    let mut panels = Vec::new();
    for (row, iv) in rows.clone().enumerate() {
        for (col, ih) in cols.clone().enumerate() {
            let mut c = [0u16; 6];
            c[outer] = ih;
            c[outer + 3] = iv;
            c[fixed] = fixed_idx[0];
            c[fixed + 3] = fixed_idx[1];
            panels.push(Panel { col, row, cell: c, caption: None });
        }
    }
    let labels = |d: usize, r: std::ops::RangeInclusive<u16>| -> (String, Vec<String>) {
        (
            format!("{} (mm)", NAMES[d]),
            r.map(|i| format!("{:.0}", coordinate(maps, d, i))).collect(),
        )
    };
    let (a, b) = (fixed_idx[0], fixed_idx[1]);
    Quilt {
        inner: [inner, inner + 3],
        cols: cols.len(),
        rows: rows.len(),
        col_labels: Some(labels(outer, cols)),
        row_labels: Some(labels(outer + 3, rows)),
        panels,
        title: format!(
            "{what}\n{i}{i}'-slices ({i} right, {i}' up) in a quilt over {o} (right) and {o}' (up)\n\
             fixed: {f} = {:.1} mm (index {a}), {f}' = {:.1} mm (index {b})",
            coordinate(maps, fixed, a),
            coordinate(maps, fixed + 3, b),
            i = NAMES[inner],
            o = NAMES[outer],
            f = NAMES[fixed],
        ),
    }
}

/// The fixed pair's default indices: half the workspace radius from each robot's axis toward
/// the other robot, at the middle of the workspace's cylinder.
fn default_fix(cell: &Cell, maps: &[GridMap; 2], ws: &Workspace, dim: usize) -> [u16; 2] {
    let (pa, pb) = (&cell.robots[0].placement, &cell.robots[1].placement);
    let toward = [pa.to_mcs(&pb.t), pb.to_mcs(&pa.t)];
    std::array::from_fn(|j| {
        let g = &maps[j].grid;
        let dir = Vec3::new(toward[j].x, toward[j].y, 0.0);
        let offset = if dir.norm() > 0.0 { dir.normalize() * 0.5 * ws.rcy } else { Vec3::zeros() };
        let p = Vec3::new(offset.x, offset.y, -(ws.zu + 0.5 * ws.hcy));
        g.cell_of(&p).map_or(g.k as u16 / 2, |c| c[dim])
    })
}

/// A's cell fixed; one x'y'-slice of B's grid per sampled depth z', in rows of panels.
fn b_slices(maps: &[GridMap; 2], a: [u16; 3], what: &str) -> Quilt {
    let depths: Vec<u16> = span(maps, 5).rev().collect();
    let cols = (depths.len() as f64).sqrt().ceil() as usize;
    let rows = depths.len().div_ceil(cols);
    let panels = depths
        .iter()
        .enumerate()
        .map(|(n, &iz)| Panel {
            col: n % cols,
            row: rows - 1 - n / cols,
            cell: [a[0], a[1], a[2], 0, 0, iz],
            caption: Some(format!("z' = {:.0}", coordinate(maps, 5, iz))),
        })
        .collect();
    let centre = maps[0].grid.center(a);
    let state = match maps[0].at(a) {
        Sampled::Outside => " (outside A's sampled grid)",
        Sampled::Unreachable => " (proved unreachable)",
        Sampled::Reachable => "",
    };
    Quilt {
        inner: [3, 4],
        cols,
        rows,
        panels,
        col_labels: None,
        row_labels: None,
        title: format!(
            "{what}\nA's TCP in cell ({}, {}, {}), centre ({:.1}, {:.1}, {:.1}) mm{state}\n\
             each panel: B's TCP over x' (right) and y' (up) at one depth z'",
            a[0], a[1], a[2], centre.x, centre.y, centre.z
        ),
    }
}

/// What a 6-D cell looks like on the picture.
fn colour_of(maps: &[GridMap; 2], table: &Table, c: [u16; 6]) -> (usize, RGBColor) {
    match (maps[0].at([c[0], c[1], c[2]]), maps[1].at([c[3], c[4], c[5]])) {
        (Sampled::Outside, _) | (_, Sampled::Outside) => (3, OUTSIDE),
        (Sampled::Unreachable, _) | (_, Sampled::Unreachable) => (2, UNREACHABLE),
        _ if table.query_grid_cell(c) => (0, COLLISION),
        _ => match table.as_clearance() {
            Some(t) => (1, level_colour(t.level_count(c), t.ladder().len())),
            None => (1, FREE),
        },
    }
}

/// The colour of a free cell of a clearance table with `count` of `n` levels proved: white
/// for the lowest level, darker blue for each level above, the darkest for the top.
fn level_colour(count: usize, n: usize) -> RGBColor {
    let t = count.saturating_sub(1) as f64 / n.saturating_sub(1).max(1) as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    RGBColor(mix(255.0, 20.0), mix(255.0, 70.0), mix(255.0, 170.0))
}

/// Every cell of every panel: `(panel, i, j, 6-D cell)`.
fn cells<'a>(
    q: &'a Quilt,
    maps: &'a [GridMap; 2],
) -> impl Iterator<Item = (&'a Panel, usize, usize, [u16; 6])> + 'a {
    q.panels.iter().flat_map(move |p| {
        span(maps, q.inner[0]).enumerate().flat_map(move |(i, ih)| {
            span(maps, q.inner[1]).enumerate().map(move |(j, iv)| {
                let mut c = p.cell;
                c[q.inner[0]] = ih;
                c[q.inner[1]] = iv;
                (p, i, j, c)
            })
        })
    })
}

/// Cells shown per colour: collision, free, unreachable, outside.
fn count(q: &Quilt, maps: &[GridMap; 2], table: &Table) -> [usize; 4] {
    let mut n = [0; 4];
    for (_, _, _, c) in cells(q, maps) {
        n[colour_of(maps, table, c).0] += 1;
    }
    n
}

fn draw(
    root: &DrawingArea<BitMapBackend, Shift>,
    q: &Quilt,
    maps: &[GridMap; 2],
    table: &Table,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(plot_err)?;
    let (w, h) = root.dim_in_pixel();
    for (n, line) in q.title.lines().enumerate() {
        root.draw(&Text::new(line.to_string(), (PAD as i32, 6 + 19 * n as i32), text(15, BLACK)))
            .map_err(plot_err)?;
    }
    let top = table.as_clearance().map(|t| {
        (t.ladder().len(), format!("free, >= {} mm", t.ladder().mm()[t.ladder().len() - 1]))
    });
    let mut entries = vec![
        (Swatch::Square(COLLISION), "collision"),
        (Swatch::Square(FREE), if top.is_some() { "free, lowest level" } else { "free" }),
    ];
    if let Some((n, label)) = &top {
        entries.push((Swatch::Square(level_colour(*n, *n)), label.as_str()));
    }
    entries.push((Swatch::Square(UNREACHABLE), "a cell proved unreachable (don't care)"));
    entries.push((Swatch::Square(OUTSIDE), "outside the sampled grid"));
    legend(root, (PAD as i32, TITLE as i32 - 20), &entries)?;
    let Layout { nh, nv, caption, gap, s } = layout(q, maps, (w, h))?;
    let (pw, ph) = (nh as f64 * s, nv as f64 * s);
    let (gap, caption) = (gap as f64, caption as f64);
    let panel_origin = |p: &Panel| {
        let x = LEFT as f64 + p.col as f64 * (pw + gap);
        let y = TITLE as f64 + (q.rows - 1 - p.row) as f64 * (ph + gap + caption) + caption;
        (x, y)
    };
    let px = |v: f64| v.round() as i32;
    for p in &q.panels {
        let (x, y) = panel_origin(p);
        let frame = [(px(x) - 1, px(y) - 1), (px(x + pw) + 1, px(y + ph) + 1)];
        root.draw(&Rectangle::new(frame, RGBColor(120, 120, 120).filled())).map_err(plot_err)?;
        if let Some(c) = &p.caption {
            root.draw(&Text::new(c.clone(), (px(x), px(y - caption)), text(13, BLACK)))
                .map_err(plot_err)?;
        }
    }
    for (p, i, j, c) in cells(q, maps) {
        let (x, y) = panel_origin(p);
        let (x0, x1) = (px(x + i as f64 * s), px(x + (i + 1) as f64 * s));
        let (y0, y1) = (px(y + ph - (j + 1) as f64 * s), px(y + ph - j as f64 * s));
        root.draw(&Rectangle::new([(x0, y0), (x1, y1)], colour_of(maps, table, c).1.filled()))
            .map_err(plot_err)?;
    }
    let (pw, ph, gap, caption) = (pw.round() as i32, ph.round() as i32, gap as i32, caption as i32);
    let bottom = TITLE as i32 + q.rows as i32 * (ph + gap + caption);
    if let Some((name, labels)) = &q.col_labels {
        let every = label_stride(pw, 44);
        for (col, l) in labels.iter().enumerate().filter(|(c, _)| c % every == 0) {
            let x = LEFT as i32 + col as i32 * (pw + gap) + pw / 2;
            root.draw(&Text::new(l.clone(), (x, bottom + 2), text(12, BLACK).pos(centre_top())))
                .map_err(plot_err)?;
        }
        let x = LEFT as i32 + q.cols as i32 * (pw + gap) / 2;
        root.draw(&Text::new(
            format!("{name} →"),
            (x, bottom + 20),
            text(14, BLACK).pos(centre_top()),
        ))
        .map_err(plot_err)?;
    }
    if let Some((name, labels)) = &q.row_labels {
        let every = label_stride(ph, 16);
        for (row, l) in labels.iter().enumerate().filter(|(r, _)| r % every == 0) {
            let y = TITLE as i32 + (q.rows - 1 - row) as i32 * (ph + gap) + ph / 2;
            root.draw(&Text::new(
                l.clone(),
                (LEFT as i32 - 6, y),
                text(12, BLACK).pos(right_centre()),
            ))
            .map_err(plot_err)?;
        }
        root.draw(&Text::new(format!("{name} ↑"), (4, bottom + 20), text(14, BLACK)))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Label every n-th panel so that labels stay at least `min` pixels apart.
fn label_stride(panel: i32, min: i32) -> usize {
    ((min + panel - 1) / panel.max(1)).max(1) as usize
}

fn centre_top() -> plotters::style::text_anchor::Pos {
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    Pos::new(HPos::Center, VPos::Top)
}

fn right_centre() -> plotters::style::text_anchor::Pos {
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    Pos::new(HPos::Right, VPos::Center)
}
