//! Cell files: a human-edited TOML description of the robots of a cell (SPEC §1, §5).
//!
//! Lengths in mm; angles in degrees only where the key says so (`alpha_deg`,
//! `theta_min_deg`). Every key but `[[robot]]` has a default: the thesis robot with the
//! physical box sizes, placed at the WCS origin. Unknown keys are errors, so a typo never
//! silently falls back to a default.
//!
//! ```toml
//! name = "T1"
//! method = "sat-cache"            # or "sat"
//! [[robot]]
//! name = "A"
//! [[robot]]
//! name = "B"
//! placement = { alpha_deg = 0.0, t = [450.0, 0.0, 0.0] }
//! model = { margin = 5.0, upper_links = { half_height = 30.0, half_depth = 15.0 } }
//! stop = { reaction_ms = 4.0, decel_mm_s2 = 40000.0, max_accel_mm_s2 = 130000.0, max_speed_mm_s =
//! 4600.0 }
//! ```
//!
//! The top-level `tick_ms` (default 1) and each robot's `stop` (SPEC §8; defaults in
//! [`StopModel::DEFAULT`]) serve the protective verdict only; the top-level `table_confirm`
//! (`"exact"`, the default, or `"none"`) serves table mode only ([`Confirmation`]).

use super::Confirmation;
use crate::cell::placement::Placement;
use crate::cell::{Cell, CellError, RobotSpec, SatMethod};
use crate::math::{Real, Vec3};
use crate::robot::{Delta3, ModelOptions, RobotModel, StopModel, ToolBox, DEFAULT_TICK_MS};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CellFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    method: Option<String>,
    #[serde(default)]
    tick_ms: Option<Real>,
    #[serde(default)]
    table_confirm: Option<String>,
    #[serde(rename = "robot")]
    robots: Vec<RobotFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    geometry: GeometryFile,
    #[serde(default)]
    model: ModelFile,
    #[serde(default)]
    placement: PlacementFile,
    #[serde(default)]
    stop: StopFile,
}

/// A robot's `stop = { ... }`: every key defaults to [`StopModel::DEFAULT`] (its doc says why).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct StopFile {
    reaction_ms: Real,
    decel_mm_s2: Real,
    max_accel_mm_s2: Real,
    max_speed_mm_s: Real,
}

impl Default for StopFile {
    fn default() -> Self {
        let s = StopModel::DEFAULT;
        StopFile {
            reaction_ms: s.reaction_ms,
            decel_mm_s2: s.decel_mm_s2,
            max_accel_mm_s2: s.max_accel_mm_s2,
            max_speed_mm_s: s.max_speed_mm_s,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GeometryFile {
    f: Real,
    rf: Real,
    re: Real,
    e: Real,
    theta_min_deg: Real,
    theta_max_deg: Real,
}

impl Default for GeometryFile {
    fn default() -> Self {
        let d = Delta3::THESIS;
        GeometryFile {
            f: d.f,
            rf: d.rf,
            re: d.re,
            e: d.e,
            theta_min_deg: d.theta_min.to_degrees(),
            theta_max_deg: d.theta_max.to_degrees(),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct ModelFile {
    half_height: Real,
    half_depth: Real,
    margin: Real,
    upper_links: Option<UpperLinksFile>,
    platform: Option<BoxFile>,
    tool: Option<BoxFile>,
}

impl Default for ModelFile {
    fn default() -> Self {
        let o = ModelOptions::THESIS;
        ModelFile {
            half_height: o.half_height,
            half_depth: o.half_depth,
            margin: o.margin,
            upper_links: None,
            platform: None,
            tool: None,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UpperLinksFile {
    half_height: Real,
    half_depth: Real,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxFile {
    #[serde(default)]
    offset: [Real; 3],
    half: [Real; 3],
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct PlacementFile {
    alpha_deg: Real,
    t: [Real; 3],
}

fn tool_box(b: &BoxFile) -> ToolBox {
    ToolBox { offset: Vec3::from(b.offset), half: Vec3::from(b.half) }
}

/// What a cell file holds: the validated cell and the settings of table mode.
#[derive(Clone, Debug, PartialEq)]
pub struct CellFileContents {
    /// The cell.
    pub cell: Cell,
    /// `table_confirm`: what table mode does with a COLLISION lookup (default exact).
    pub table_confirmation: Confirmation,
}

/// Parses a cell file's text into a validated [`Cell`].
///
/// # Errors
/// As [`parse_cell_file`].
pub fn parse_cell(text: &str) -> Result<Cell, CellError> {
    parse_cell_file(text).map(|f| f.cell)
}

/// Parses a cell file's text into a validated [`Cell`] and its table-mode settings.
///
/// # Errors
/// [`CellError::Parse`] for TOML or schema errors (with line and column) and an unknown
/// `table_confirm`, and the validation errors of [`Cell::new`].
pub fn parse_cell_file(text: &str) -> Result<CellFileContents, CellError> {
    let file: CellFile = toml::from_str(text).map_err(|e| CellError::Parse(e.to_string()))?;
    let table_confirmation = match file.table_confirm.as_deref() {
        None => Confirmation::default(),
        Some(name) => Confirmation::from_name(name).ok_or_else(|| {
            CellError::Parse(format!(
                "table_confirm = \"{name}\" is unknown; use \"exact\" or \"none\""
            ))
        })?,
    };
    let method = match file.method.as_deref() {
        None | Some("sat-cache") => SatMethod::SatCache,
        Some("sat") => SatMethod::Sat,
        Some(other) => {
            return Err(CellError::Parse(format!(
                "method = \"{other}\" is unknown; use \"sat\" or \"sat-cache\""
            )))
        }
    };
    let robots = file
        .robots
        .iter()
        .enumerate()
        .map(|(i, r)| RobotSpec {
            name: r.name.clone().unwrap_or_else(|| ((b'A' + (i % 26) as u8) as char).to_string()),
            model: RobotModel {
                delta: Delta3 {
                    f: r.geometry.f,
                    rf: r.geometry.rf,
                    re: r.geometry.re,
                    e: r.geometry.e,
                    theta_min: r.geometry.theta_min_deg.to_radians(),
                    theta_max: r.geometry.theta_max_deg.to_radians(),
                },
                options: ModelOptions {
                    half_height: r.model.half_height,
                    half_depth: r.model.half_depth,
                    margin: r.model.margin,
                    upper_links: r
                        .model
                        .upper_links
                        .as_ref()
                        .map(|u| (u.half_height, u.half_depth)),
                    platform: r.model.platform.as_ref().map(tool_box),
                    tool: r.model.tool.as_ref().map(tool_box),
                },
            },
            placement: Placement {
                alpha: r.placement.alpha_deg.to_radians(),
                t: Vec3::from(r.placement.t),
            },
        })
        .collect();
    let stops = file
        .robots
        .iter()
        .map(|r| StopModel {
            reaction_ms: r.stop.reaction_ms,
            decel_mm_s2: r.stop.decel_mm_s2,
            max_accel_mm_s2: r.stop.max_accel_mm_s2,
            max_speed_mm_s: r.stop.max_speed_mm_s,
        })
        .collect();
    let cell = Cell::new(file.name.unwrap_or_else(|| "unnamed".into()), robots, method)?
        .with_stopping(file.tick_ms.unwrap_or(DEFAULT_TICK_MS), stops)?;
    Ok(CellFileContents { cell, table_confirmation })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_thesis_robot() {
        let cell =
            parse_cell("[[robot]]\n[[robot]]\nplacement = { t = [450.0, 0.0, 0.0] }\n").unwrap();
        assert_eq!(cell.robots.len(), 2);
        assert_eq!(cell.robots[0].model, RobotModel::THESIS);
        assert_eq!(cell.robots[1].placement.t, Vec3::new(450.0, 0.0, 0.0));
        assert_eq!(cell.robots[1].name, "B");
    }

    #[test]
    fn typos_and_bad_values_are_named() {
        let err = parse_cell("[[robot]]\nmodel = { margn = 3.0 }\n").unwrap_err().to_string();
        assert!(err.contains("margn"), "{err}");
        let err = parse_cell("[[robot]]\nmodel = { margin = -1.0 }\n").unwrap_err().to_string();
        assert!(err.contains("margin"), "{err}");
        let err = parse_cell("method = \"gjk\"\n[[robot]]\n").unwrap_err().to_string();
        assert!(err.contains("gjk"), "{err}");
    }

    #[test]
    fn stop_models_and_tick_are_read_defaulted_and_checked() {
        let cell =
            parse_cell("tick_ms = 2.0\n[[robot]]\nstop = { reaction_ms = 6.0 }\n[[robot]]\n")
                .unwrap();
        assert_eq!(cell.tick_ms, 2.0);
        assert_eq!(cell.stops[0], StopModel { reaction_ms: 6.0, ..StopModel::DEFAULT });
        assert_eq!(cell.stops[1], StopModel::DEFAULT);
        let err = |text: &str| parse_cell(text).unwrap_err().to_string();
        assert!(err("[[robot]]\nstop = { reaction = 6.0 }\n").contains("reaction"));
        assert!(err("[[robot]]\nstop = { decel_mm_s2 = -1.0 }\n").contains("decel_mm_s2"));
        assert!(err("[[robot]]\nstop = { max_speed_mm_s = nan }\n").contains("max_speed_mm_s"));
        assert!(err("[[robot]]\nstop = { decel_mm_s2 = 200000.0 }\n").contains("max_accel_mm_s2"));
        assert!(err("tick_ms = 0.0\n[[robot]]\n").contains("tick_ms"));
    }

    #[test]
    fn table_confirm_is_read_defaulted_and_checked() {
        let confirm = |text: &str| parse_cell_file(text).map(|f| f.table_confirmation);
        assert_eq!(confirm("[[robot]]\n"), Ok(Confirmation::Exact));
        assert_eq!(confirm("table_confirm = \"exact\"\n[[robot]]\n"), Ok(Confirmation::Exact));
        assert_eq!(confirm("table_confirm = \"none\"\n[[robot]]\n"), Ok(Confirmation::None));
        let err = confirm("table_confirm = \"maybe\"\n[[robot]]\n").unwrap_err().to_string();
        assert!(err.contains("maybe") && err.contains("\"none\""), "{err}");
        assert!(confirm("table_confirm = true\n[[robot]]\n").is_err());
    }
}
