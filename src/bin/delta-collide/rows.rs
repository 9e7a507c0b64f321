//! Rows of TCPs from a CSV input, as `check` and `replay` read them: `3 n` numbers per row
//! (`x,y,z` of each robot in its own MCS), blank lines skipped, a first line taken as a header
//! only when none of its fields is a number (so a malformed first data row is an error).

use crate::args::clip;
use delta_collide::math::Vec3;
use std::io::BufRead;

/// Calls `each(line_no, tcps)` for every data row of `input` (`line_no` from 1).
///
/// # Errors
/// A row that is not `3 n` numbers (naming its line), a read error, or `each`'s error.
pub fn for_each_row(
    input: &mut dyn BufRead,
    n: usize,
    mut each: impl FnMut(usize, &[Vec3]) -> Result<(), String>,
) -> Result<(), String> {
    let mut tcps = vec![Vec3::zeros(); n];
    let mut values = Vec::with_capacity(3 * n);
    let mut first = true;
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
            continue;
        }
        values.clear();
        let parsed = line.split(',').try_for_each(|f| f.trim().parse::<f64>().map(|v| values.push(v)));
        if parsed.is_err() || values.len() != 3 * n {
            return Err(format!(
                "line {line_no}: expected {} numbers (x,y,z per robot) separated by commas, got `{}`",
                3 * n,
                clip(line)
            ));
        }
        for (j, t) in tcps.iter_mut().enumerate() {
            *t = Vec3::new(values[3 * j], values[3 * j + 1], values[3 * j + 2]);
        }
        each(line_no, &tcps)?;
    }
    Ok(())
}
