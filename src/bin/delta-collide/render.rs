//! `render`: a cell at one configuration, in top view (x-y) and side view (x-z) of the WCS.
//!
//! Each robot is drawn as the exact check sees it: its boxes (thesis 2.5-2.6, SPEC §3) as the
//! outlines of their projections (the convex hull of the eight projected corners), with the
//! boxes that intersect a box of another robot filled red. For orientation only, the base
//! (radius `f`), the upper links `F_i G_i` as lines, the platform (radius `e`) and the
//! thesis workspace's outline (SPEC §4) are drawn thinly; they take no part in the verdict
//! unless the cell file switches on boxes for them.

use crate::args::RenderArgs;
use crate::picture::{convex_hull, draw_png, legend, plot_err, text, Swatch, HIT, ROBOT};
use crate::Failure;
use delta_collide::cell::exact::PairState;
use delta_collide::cell::{Cell, CellVerdict, ExactChecker};
use delta_collide::cspace::Workspace;
use delta_collide::geometry::{obb_distance, obbs_intersect, Obb};
use delta_collide::math::Vec3;
use delta_collide::robot::BoxKind;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Pixels around and beside each view's plotting area (margin, axis label areas, title).
const MARGIN: u32 = 12;
const X_LABELS: u32 = 40;
const Y_LABELS: u32 = 60;
const VIEW_TITLE: u32 = 26;
const TITLE: u32 = 56;

/// One robot as drawn: its boxes (WCS), which of them collide, and the orientation lines.
struct RobotPicture {
    name: String,
    boxes: Vec<Obb>,
    kinds: Vec<BoxKind>,
    hit: Vec<bool>,
    base: Vec3,
    /// `(F_i, G_i)` per arm, WCS.
    upper: Vec<(Vec3, Vec3)>,
    tcp: Option<Vec3>,
    platform_radius: f64,
    base_radius: f64,
}

/// `render`: draws `args.cell` at the TCPs `args.tcp` (one per robot, checked when parsed).
pub fn render(args: &RenderArgs) -> Result<(), Failure> {
    let (cell, tcps, output) = (&args.cell, &args.tcp, &args.output);
    let size = (args.width, args.height);
    let mut checker = ExactChecker::new(cell.clone());
    let verdict = checker.check(tcps).map_err(|e| e.to_string())?.clone();
    let robots = pictures_of(cell, &checker, &verdict, tcps);
    let title = describe(cell, &verdict, &robots, tcps);
    draw_png(output, size, |root| draw(root, &robots, &title))?;
    println!("{}: {} x {} pixels; {title}", output.display(), size.0, size.1);
    Ok(())
}

/// The drawable state of every robot after the check.
fn pictures_of(
    cell: &Cell,
    checker: &ExactChecker,
    verdict: &CellVerdict,
    tcps: &[Vec3],
) -> Vec<RobotPicture> {
    let mut robots: Vec<RobotPicture> = cell
        .robots
        .iter()
        .enumerate()
        .map(|(j, spec)| {
            let (d, pl) = (&spec.model.delta, &spec.placement);
            let reachable = verdict.unreachable_mask & (1 << j) == 0;
            let boxes: Vec<Obb> =
                if reachable { checker.boxes(j).as_slice().to_vec() } else { Vec::new() };
            let upper = match d.inverse_kinematics(&tcps[j]) {
                Ok(sol) => (0..3)
                    .map(|i| {
                        (
                            pl.to_wcs(&d.motor_point(i)),
                            pl.to_wcs(&d.elbow(i, sol.cos[i], sol.sin[i])),
                        )
                    })
                    .collect(),
                Err(_) => Vec::new(),
            };
            RobotPicture {
                name: spec.name.clone(),
                kinds: (0..boxes.len()).map(|i| spec.model.box_kind(i)).collect(),
                hit: vec![false; boxes.len()],
                boxes,
                base: pl.t,
                upper,
                tcp: reachable.then(|| pl.to_wcs(&tcps[j])),
                platform_radius: d.e,
                base_radius: d.f,
            }
        })
        .collect();
    for p in &verdict.pairs {
        if let PairState::Collides(..) = p.state {
            for i in 0..robots[p.a].boxes.len() {
                for k in 0..robots[p.b].boxes.len() {
                    if obbs_intersect(&robots[p.a].boxes[i], &robots[p.b].boxes[k]) {
                        robots[p.a].hit[i] = true;
                        robots[p.b].hit[k] = true;
                    }
                }
            }
        }
    }
    robots
}

fn kind_name(k: BoxKind) -> String {
    match k {
        BoxKind::LowerLink(i) => format!("lower link {i}"),
        BoxKind::UpperLink(i) => format!("upper link {i}"),
        BoxKind::Platform => "platform".into(),
        BoxKind::Tool => "tool".into(),
    }
}

/// The verdict in one line: the colliding boxes, or the smallest distance between robots.
fn describe(cell: &Cell, verdict: &CellVerdict, robots: &[RobotPicture], tcps: &[Vec3]) -> String {
    let at: Vec<String> = robots
        .iter()
        .zip(tcps)
        .map(|(r, t)| format!("{} ({:.0}, {:.0}, {:.0})", r.name, t.x, t.y, t.z))
        .collect();
    let head = format!("cell {}, TCPs {}: ", cell.name, at.join(", "));
    if let Some((j, why)) = verdict.first_unreachable {
        return format!("{head}unreachable: robot {} ({why})", robots[j].name);
    }
    let first = verdict.pairs.iter().find_map(|p| match p.state {
        PairState::Collides(i, k) => Some((p, i, k)),
        _ => None,
    });
    if let Some((p, i, k)) = first {
        let (a, b) = (&robots[p.a], &robots[p.b]);
        let more = verdict.colliding_pairs() - 1;
        let more = if more > 0 { format!(" (and {more} more robot pairs)") } else { String::new() };
        return format!(
            "{head}COLLISION: {} {} × {} {}{more}",
            a.name,
            kind_name(a.kinds[i]),
            b.name,
            kind_name(b.kinds[k])
        );
    }
    let gap = verdict
        .pairs
        .iter()
        .map(|p| {
            let (a, b) = (&robots[p.a].boxes, &robots[p.b].boxes);
            a.iter()
                .flat_map(|x| b.iter().map(move |y| obb_distance(x, y)))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min);
    if gap.is_finite() {
        format!("{head}free, closest boxes {gap:.1} mm apart")
    } else {
        format!("{head}free (no robot pair can meet)")
    }
}

/// A projection of the WCS onto a view's two axes.
#[derive(Clone, Copy)]
enum View {
    Top,
    Side,
}

impl View {
    fn project(self, p: &Vec3) -> (f64, f64) {
        match self {
            View::Top => (p.x, p.y),
            View::Side => (p.x, p.z),
        }
    }
}

/// Points of a circle of radius `r` about `c` in the x-y plane.
fn circle(c: &Vec3, r: f64) -> Vec<Vec3> {
    (0..=64)
        .map(|i| i as f64 * std::f64::consts::TAU / 64.0)
        .map(|a| c + Vec3::new(r * a.cos(), r * a.sin(), 0.0))
        .collect()
}

/// The outline of the thesis workspace below a base, in the given view.
fn workspace_outline(base: &Vec3, view: View) -> Vec<(f64, f64)> {
    let ws = Workspace::THESIS;
    match view {
        View::Top => circle(&(base - Vec3::new(0.0, 0.0, ws.zu)), ws.rcy)
            .iter()
            .map(|p| view.project(p))
            .collect(),
        View::Side => {
            let knee = ws.zu + ws.hcy;
            let right = [(ws.rcy, ws.zu), (ws.rcy, knee), (ws.rco, ws.max_depth())];
            let mut pts: Vec<(f64, f64)> =
                right.iter().map(|&(r, d)| (base.x + r, base.z - d)).collect();
            pts.extend(right.iter().rev().map(|&(r, d)| (base.x - r, base.z - d)));
            pts.push(pts[0]);
            pts
        }
    }
}

/// Everything a view shows, for its ranges.
fn extent(robots: &[RobotPicture], view: View) -> ((f64, f64), (f64, f64)) {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in robots {
        pts.extend(r.boxes.iter().flat_map(|b| b.vertices()).map(|v| view.project(&v)));
        pts.extend(circle(&r.base, r.base_radius).iter().map(|p| view.project(p)));
        pts.extend(workspace_outline(&r.base, view));
        pts.extend(r.upper.iter().flat_map(|(f, g)| [view.project(f), view.project(g)]));
    }
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for (x, y) in pts {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    ((lo.0, hi.0), (lo.1, hi.1))
}

/// Widens `(lo, hi)` about its middle to `span`.
fn widen((lo, hi): (f64, f64), span: f64) -> (f64, f64) {
    let mid = 0.5 * (lo + hi);
    (mid - 0.5 * span, mid + 0.5 * span)
}

fn draw(
    root: &DrawingArea<BitMapBackend, Shift>,
    robots: &[RobotPicture],
    title: &str,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(plot_err)?;
    let (w, h) = root.dim_in_pixel();
    let (head, body) = root.split_vertically(TITLE);
    draw_title(&head, robots, title)?;
    let (left, right) = body.split_horizontally(w / 2);
    // One scale (mm per pixel) for both views, sharing the x range, so that they line up.
    let plot_w = (w / 2 - 2 * MARGIN - Y_LABELS) as f64;
    let plot_h = (h - TITLE - VIEW_TITLE - 2 * MARGIN - X_LABELS) as f64;
    let (top_x, top_y) = extent(robots, View::Top);
    let (side_x, side_z) = extent(robots, View::Side);
    let x = (top_x.0.min(side_x.0), top_x.1.max(side_x.1));
    let pad = 1.06;
    let scale =
        [(x.1 - x.0) / plot_w, (top_y.1 - top_y.0) / plot_h, (side_z.1 - side_z.0) / plot_h]
            .into_iter()
            .fold(0.0, f64::max)
            * pad;
    let x = widen(x, scale * plot_w);
    draw_view(&left, robots, View::Top, "top view (x-y, WCS)", x, widen(top_y, scale * plot_h))?;
    draw_view(&right, robots, View::Side, "side view (x-z, WCS)", x, widen(side_z, scale * plot_h))
}

fn draw_title(
    area: &DrawingArea<BitMapBackend, Shift>,
    robots: &[RobotPicture],
    title: &str,
) -> Result<(), String> {
    let hit = robots.iter().any(|r| r.hit.iter().any(|&h| h));
    area.draw(&Text::new(
        title.to_string(),
        (MARGIN as i32, 8),
        text(18, if hit { HIT } else { BLACK }),
    ))
    .map_err(plot_err)?;
    let names: Vec<String> = robots.iter().map(|r| format!("robot {} boxes", r.name)).collect();
    let mut entries: Vec<(Swatch, &str)> = names
        .iter()
        .enumerate()
        .map(|(j, n)| {
            (Swatch::Outlined(ROBOT[j % ROBOT.len()].mix(0.2), ROBOT[j % ROBOT.len()]), n.as_str())
        })
        .collect();
    entries.push((Swatch::Outlined(HIT.mix(0.45), HIT), "box in collision"));
    entries.push((
        Swatch::Line(RGBColor(150, 150, 150)),
        "base, upper links, platform, workspace (drawn only)",
    ));
    legend(area, (MARGIN as i32, 34), &entries).map(|_| ())
}

fn draw_view(
    area: &DrawingArea<BitMapBackend, Shift>,
    robots: &[RobotPicture],
    view: View,
    caption: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<(), String> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, text(16, BLACK))
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(plot_err)?;
    let y_desc = if let View::Top = view { "y (mm)" } else { "z (mm)" };
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(235, 235, 235))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("x (mm)")
        .y_desc(y_desc)
        .label_style(text(12, BLACK))
        .axis_desc_style(text(13, BLACK))
        .draw()
        .map_err(plot_err)?;
    let thin = RGBColor(150, 150, 150);
    let line = |pts: Vec<(f64, f64)>, style: ShapeStyle| PathElement::new(pts, style);
    for (j, r) in robots.iter().enumerate() {
        let c = ROBOT[j % ROBOT.len()];
        chart
            .draw_series([line(workspace_outline(&r.base, view), thin.mix(0.5).stroke_width(1))])
            .map_err(plot_err)?;
        let base: Vec<(f64, f64)> =
            circle(&r.base, r.base_radius).iter().map(|p| view.project(p)).collect();
        chart.draw_series([line(base, c.stroke_width(2))]).map_err(plot_err)?;
        for (f, g) in &r.upper {
            chart
                .draw_series([line(
                    vec![view.project(f), view.project(g)],
                    c.mix(0.7).stroke_width(3),
                )])
                .map_err(plot_err)?;
        }
        if let Some(t) = r.tcp {
            let platform: Vec<(f64, f64)> =
                circle(&t, r.platform_radius).iter().map(|p| view.project(p)).collect();
            chart.draw_series([line(platform, c.stroke_width(1))]).map_err(plot_err)?;
            chart
                .draw_series([Cross::new(view.project(&t), 5, c.stroke_width(2))])
                .map_err(plot_err)?;
        }
    }
    // Free boxes first, colliding ones on top.
    for hit_pass in [false, true] {
        for (j, r) in robots.iter().enumerate() {
            let c = ROBOT[j % ROBOT.len()];
            for b in r.boxes.iter().zip(&r.hit).filter(|&(_, &h)| h == hit_pass).map(|(b, _)| b) {
                let hull =
                    convex_hull(&b.vertices().iter().map(|v| view.project(v)).collect::<Vec<_>>());
                let (fill, stroke) = if hit_pass { (HIT.mix(0.45), HIT) } else { (c.mix(0.2), c) };
                chart.draw_series([Polygon::new(hull.clone(), fill.filled())]).map_err(plot_err)?;
                let mut closed = hull;
                closed.push(closed[0]);
                chart.draw_series([line(closed, stroke.stroke_width(2))]).map_err(plot_err)?;
            }
        }
    }
    if let View::Top = view {
        for (j, r) in robots.iter().enumerate() {
            let c = ROBOT[j % ROBOT.len()];
            let (bx, by) = view.project(&r.base);
            chart
                .draw_series([Text::new(
                    r.name.clone(),
                    (bx, by),
                    text(18, c).pos(text_anchor_centre()),
                )])
                .map_err(plot_err)?;
            for (i, b) in r.boxes.iter().enumerate() {
                if let BoxKind::LowerLink(arm) = r.kinds[i] {
                    let label = Text::new(
                        arm.to_string(),
                        view.project(&b.center),
                        text(13, BLACK).pos(text_anchor_centre()),
                    );
                    chart.draw_series([label]).map_err(plot_err)?;
                }
            }
        }
    }
    Ok(())
}

fn text_anchor_centre() -> plotters::style::text_anchor::Pos {
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    Pos::new(HPos::Center, VPos::Center)
}
