//! Safe conversions between the C structs and the crate's types (no `unsafe` here).

use crate::cell::{Cell, CellError, Placement, RobotSpec, SatMethod};
use crate::ffi::types::*;
use crate::math::Vec3;
use crate::robot::{Delta3, ModelOptions, RobotModel, ToolBox};
use crate::table::TableError;

/// Why a collider could not be made: the status for C and a message naming the cause and
/// the fix (kept for `dc_last_init_error`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct InitError {
    pub status: DcStatus,
    pub message: String,
}

impl InitError {
    pub(crate) fn new(status: DcStatus, message: impl Into<String>) -> Self {
        InitError { status, message: message.into() }
    }
}

/// [`crate::robot::StopModel::DEFAULT`] as a C struct, `struct_size` set.
pub(crate) fn stop_config_default() -> DcStopConfig {
    let s = crate::robot::StopModel::DEFAULT;
    DcStopConfig {
        struct_size: size_of::<DcStopConfig>(),
        reaction_ms: s.reaction_ms,
        decel_mm_s2: s.decel_mm_s2,
        max_accel_mm_s2: s.max_accel_mm_s2,
        max_speed_mm_s: s.max_speed_mm_s,
    }
}

/// The confirmation a C value names, or `None` for a value that names none.
pub(crate) fn confirmation_from_c(c: DcConfirmation) -> Option<crate::table::Confirmation> {
    match c {
        DC_CONFIRMATION_EXACT => Some(crate::table::Confirmation::Exact),
        DC_CONFIRMATION_NONE => Some(crate::table::Confirmation::None),
        _ => None,
    }
}

/// The status a cell error maps to.
pub(crate) fn cell_error_status(e: &CellError) -> DcStatus {
    match e {
        CellError::Io(_) => DC_STATUS_IO,
        CellError::Parse(_) => DC_STATUS_PARSE,
        CellError::Invalid(_) => DC_STATUS_INVALID_CONFIG,
    }
}

/// The status a table error maps to, one per [`TableError`] variant: what `dc_init_with_table`
/// and `dc_init_from_files` return for it (the fuzz crate checks them against this map).
pub fn table_error_status(e: &TableError) -> DcStatus {
    match e {
        TableError::Truncated { .. } => DC_STATUS_TABLE_TRUNCATED,
        TableError::BadMagic { .. } => DC_STATUS_TABLE_BAD_MAGIC,
        TableError::UnsupportedVersion { .. } => DC_STATUS_TABLE_UNSUPPORTED_VERSION,
        TableError::WrongEndianness => DC_STATUS_TABLE_WRONG_ENDIANNESS,
        TableError::Corrupt { .. } => DC_STATUS_TABLE_CORRUPT,
        TableError::WrongCell { .. } => DC_STATUS_TABLE_WRONG_CELL,
        TableError::MissingPair { .. } => DC_STATUS_TABLE_MISSING_PAIR,
        TableError::WrongPair { .. } => DC_STATUS_TABLE_WRONG_PAIR,
        // `TableChecker::new` reports a cell without two robots as bad input.
        TableError::BadInput { .. } => DC_STATUS_TABLE_NOT_TWO_ROBOTS,
    }
}

fn delta3(g: &DcDelta3) -> Delta3 {
    Delta3 { f: g.f, rf: g.rf, re: g.re, e: g.e, theta_min: g.theta_min, theta_max: g.theta_max }
}

fn tool_box(flag: u32, b: &DcBox) -> Option<ToolBox> {
    (flag != 0).then(|| ToolBox { offset: b.offset.to_vec3(), half: b.half.to_vec3() })
}

/// A robot from its C description (validated later by [`Cell::new`]).
pub(crate) fn robot_spec(index: usize, r: &DcRobotConfig) -> RobotSpec {
    RobotSpec {
        name: format!("robot {index}"),
        model: RobotModel {
            delta: delta3(&r.geometry),
            options: ModelOptions {
                half_height: r.half_height,
                half_depth: r.half_depth,
                margin: r.margin,
                upper_links: (r.has_upper_links != 0)
                    .then_some((r.upper_half_height, r.upper_half_depth)),
                platform: tool_box(r.has_platform, &r.platform),
                tool: tool_box(r.has_tool, &r.tool),
            },
        },
        placement: Placement { alpha: r.alpha, t: r.translation.to_vec3() },
    }
}

/// A validated cell from the C robots and method code.
pub(crate) fn cell_from_c(robots: &[DcRobotConfig], method: u32) -> Result<Cell, InitError> {
    let method = match method {
        DC_METHOD_SAT => SatMethod::Sat,
        DC_METHOD_SAT_CACHE => SatMethod::SatCache,
        m => {
            return Err(InitError::new(
                DC_STATUS_INVALID_CONFIG,
                format!("config->method = {m}: use DC_METHOD_SAT (0) or DC_METHOD_SAT_CACHE (1)"),
            ))
        }
    };
    let specs = robots.iter().enumerate().map(|(i, r)| robot_spec(i, r)).collect();
    Cell::new("C config".into(), specs, method)
        .map_err(|e| InitError::new(cell_error_status(&e), e.to_string()))
}

impl DcRobotConfig {
    /// The C description of `r`, the inverse of [`robot_spec`] (up to the name): what a Rust
    /// caller of the C ABI (the fuzz targets, for one) passes for a cell it holds.
    pub fn from_spec(r: &RobotSpec) -> Self {
        let (d, o) = (&r.model.delta, &r.model.options);
        let (upper_half_height, upper_half_depth) = o.upper_links.unwrap_or((0.0, 0.0));
        let dc_box = |b: Option<ToolBox>| {
            let b = b.unwrap_or(ToolBox { offset: Vec3::zeros(), half: Vec3::zeros() });
            DcBox { offset: DcVec3::from_vec3(&b.offset), half: DcVec3::from_vec3(&b.half) }
        };
        DcRobotConfig {
            geometry: DcDelta3 {
                f: d.f,
                rf: d.rf,
                re: d.re,
                e: d.e,
                theta_min: d.theta_min,
                theta_max: d.theta_max,
            },
            half_height: o.half_height,
            half_depth: o.half_depth,
            margin: o.margin,
            has_upper_links: u32::from(o.upper_links.is_some()),
            upper_half_height,
            upper_half_depth,
            has_platform: u32::from(o.platform.is_some()),
            platform: dc_box(o.platform),
            has_tool: u32::from(o.tool.is_some()),
            tool: dc_box(o.tool),
            alpha: r.placement.alpha,
            translation: DcVec3::from_vec3(&r.placement.t),
        }
    }
}

/// The thesis robot as a C config, placed at the WCS origin.
pub(crate) fn thesis_robot_config() -> DcRobotConfig {
    DcRobotConfig::from_spec(&RobotSpec {
        name: String::new(),
        model: RobotModel { delta: Delta3::THESIS, options: ModelOptions::THESIS },
        placement: Placement::IDENTITY,
    })
}

/// The C geometry as a validated [`Delta3`].
pub(crate) fn delta3_from_c(g: &DcDelta3) -> Result<Delta3, DcStatus> {
    let d = delta3(g);
    let all = [g.f, g.rf, g.re, g.e, g.theta_min, g.theta_max];
    if !all.iter().all(|v| v.is_finite()) {
        return Err(DC_STATUS_NON_FINITE);
    }
    d.validate().map_err(|_| DC_STATUS_INVALID_CONFIG)?;
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    #[test]
    fn from_spec_is_the_inverse_of_robot_spec() {
        let tool =
            ToolBox { offset: Vec3::new(1.0, -2.0, -30.0), half: Vec3::new(20.0, 25.0, 30.0) };
        let mut specs: Vec<RobotSpec> = ["T1", "T2", "T3"]
            .iter()
            .flat_map(|n| crate::cell::reference::reference_cell(n).unwrap().robots)
            .collect();
        let mut full = specs[1].clone();
        full.model.options.upper_links = Some((12.0, 9.0));
        full.model.options.platform =
            Some(ToolBox { offset: Vec3::zeros(), half: Vec3::new(45.0, 45.0, 8.0) });
        full.model.options.tool = Some(tool);
        specs.push(full);
        for (i, r) in specs.iter().enumerate() {
            let back = robot_spec(i, &DcRobotConfig::from_spec(r));
            assert_eq!((back.model, back.placement), (r.model, r.placement), "robot {i}");
        }
    }

    #[test]
    fn each_table_error_has_its_own_status_from_10_with_a_text() {
        let errors = [
            TableError::Truncated { what: "magic", needed: 8, have: 0 },
            TableError::BadMagic { found: *b"XCTABLE\0" },
            TableError::UnsupportedVersion { found: 2, supported: 1 },
            TableError::WrongEndianness,
            TableError::Corrupt { what: "checksum".into() },
            TableError::WrongCell { expected: 1, found: 2, differs: None },
            TableError::BadInput { what: "three robots".into() },
            TableError::MissingPair { what: "R3-R4".into() },
            TableError::WrongPair { what: "R1-R2".into() },
        ];
        let statuses: Vec<DcStatus> = errors.iter().map(table_error_status).collect();
        // 17 is the protective query's; the bundle statuses came after it.
        let expected: Vec<DcStatus> = (10..=16).chain([18, 19]).collect();
        assert_eq!(statuses, expected, "one status per variant, in order, from 10");
        for s in statuses {
            // SAFETY: dc_status_str returns a static NUL-terminated string.
            let text = unsafe { CStr::from_ptr(crate::ffi::dc_status_str(s)) }.to_str().unwrap();
            assert!(text.contains("table"), "status {s}: {text}");
        }
    }
}
