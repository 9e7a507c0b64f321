//! Rows of TCPs from a CSV input, as `check` and `replay` read them: `x,y,z` of each robot in
//! its own MCS; and the text of the numbers they write. Blank lines are skipped; a first line
//! none of whose fields is a number is a header, and must name every robot's columns (`x,y,z`
//! or `x1,y1,z1` for the first robot, `x2,y2,z2` for the second, and so on), selected by
//! name, its other columns (`tick`, anything else) ignored; any other first line (a malformed
//! row, a line split by semicolons) is an error naming line 1. Without a header a row is
//! exactly `3 n` numbers in robot order.

use crate::args::clip;
use delta_collide::math::Vec3;
use std::io::BufRead;

/// The CSV text of `v`: with `decimals` that many, else the shortest text that reads back as
/// the same double (Rust's `{}` for `f64`; `inf`, `-inf`, `NaN` as they are).
pub fn real(v: f64, decimals: Option<u8>) -> String {
    match decimals {
        Some(d) => format!("{v:.*}", usize::from(d)),
        None => format!("{v}"),
    }
}

/// Where a row's numbers are.
enum Layout {
    /// The `3 n` fields, in robot order, and nothing else.
    InOrder,
    /// Robot `j`'s `x, y, z` in fields `xyz[3 j..3 j + 3]`; `tick` the field of that name.
    Named { xyz: Vec<usize>, tick: Option<usize> },
}

/// The names of `n` robots' columns: `x,y,z,x2,y2,z2,...`.
fn column_names(n: usize) -> String {
    let names: Vec<String> = (0..n)
        .flat_map(|j| {
            let suffix = if j == 0 { String::new() } else { (j + 1).to_string() };
            ["x", "y", "z"].map(|c| format!("{c}{suffix}"))
        })
        .collect();
    names.join(",")
}

/// The layout a header gives for `n` robots.
fn layout(header: &str, n: usize) -> Layout {
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |name: &str| names.iter().position(|f| f.eq_ignore_ascii_case(name));
    // The first robot's columns also as `x1,y1,z1`.
    let find_robot = |name: &str| match name {
        "x" | "y" | "z" => find(name).or_else(|| find(&format!("{name}1"))),
        _ => find(name),
    };
    let xyz: Option<Vec<usize>> = column_names(n).split(',').map(find_robot).collect();
    match xyz {
        Some(xyz) => Layout::Named { xyz, tick: find("tick") },
        None => Layout::InOrder,
    }
}

/// Calls `each(line_no, tick, tcps)` for every data row of `input` (`line_no` from 1; `tick`
/// the row's `tick` field when the header names one).
///
/// # Errors
/// A row without its numbers (naming its line), a read error, or `each`'s error.
pub fn for_each_row(
    input: &mut dyn BufRead,
    n: usize,
    mut each: impl FnMut(usize, Option<&str>, &[Vec3]) -> Result<(), String>,
) -> Result<(), String> {
    let mut tcps = vec![Vec3::zeros(); n];
    let mut values = Vec::with_capacity(3 * n);
    let (mut first, mut columns) = (true, Layout::InOrder);
    for (i, line) in input.lines().enumerate() {
        let line_no = i + 1;
        let line = line.map_err(|e| format!("line {line_no}: {e}"))?;
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let header = first && line.split(',').all(|f| f.trim().parse::<f64>().is_err());
        first = false;
        if header {
            columns = layout(line, n);
            if matches!(columns, Layout::InOrder) {
                return Err(format!(
                    "line {line_no}: `{}` is neither a header naming the columns {} (others, \
                     such as tick, ignored) nor {} numbers separated by commas",
                    clip(line),
                    column_names(n),
                    3 * n
                ));
            }
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        values.clear();
        let tick = match &columns {
            Layout::InOrder if fields.len() == 3 * n => fields
                .iter()
                .try_for_each(|f| f.parse::<f64>().map(|v| values.push(v)))
                .ok()
                .map(|()| None),
            Layout::InOrder => None,
            Layout::Named { xyz, tick } => xyz
                .iter()
                .try_for_each(|&k| {
                    fields.get(k).and_then(|f| f.parse::<f64>().ok()).map(|v| values.push(v))
                })
                .map(|()| tick.and_then(|k| fields.get(k).copied())),
        };
        let Some(tick) = tick else {
            let expected = match columns {
                Layout::InOrder => {
                    format!("{} numbers (x,y,z per robot) separated by commas", 3 * n)
                }
                Layout::Named { .. } => {
                    "a number in each of the header's x,y,z columns".to_string()
                }
            };
            return Err(format!("line {line_no}: expected {expected}, got `{}`", clip(line)));
        };
        for (j, t) in tcps.iter_mut().enumerate() {
            *t = Vec3::new(values[3 * j], values[3 * j + 1], values[3 * j + 2]);
        }
        each(line_no, tick, &tcps)?;
    }
    Ok(())
}
