//! Robots, their placements in the world, and the exact check of a whole cell
//! (thesis 2.3 and 3.1; SPEC §1 and §5).
//!
//! A [`Cell`] is validated once; [`ExactChecker`] then answers, per tick and without
//! allocating, which robot pairs collide for one TCP per robot.

#[cfg(feature = "std")]
pub mod config;
mod confirmation;
pub mod exact;
pub mod placement;
#[cfg(feature = "std")]
pub mod protective;
#[cfg(feature = "std")]
pub mod reference;
pub mod trajectory;

#[cfg(feature = "std")]
pub use config::{parse_cell, parse_cell_file, CellFileContents};
pub use confirmation::Confirmation;
pub use exact::{CellVerdict, ExactChecker, PairVerdict, QueryError};
pub use placement::Placement;

use crate::math::{float, Real, MAX_LENGTH};
use crate::robot::{RobotModel, StopModel, DEFAULT_TICK_MS};
use alloc::{format, string::String, vec::Vec};

/// Most robots in one cell (the unreachable mask of a report is a `u32`).
pub const MAX_ROBOTS: usize = 32;

/// Which exact test the checker runs (thesis 3.1.5 compares both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SatMethod {
    /// The plain separating axis test on every box pair.
    Sat,
    /// The same, with the two-layer witness cache of thesis 3.1.4.
    SatCache,
}

/// One robot of a cell: its model and where it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotSpec {
    /// A name for reports.
    pub name: String,
    /// Geometry and box options.
    pub model: RobotModel,
    /// Its MCS in the WCS.
    pub placement: Placement,
}

/// A validated cell: robots, placements and the exact test to use.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// A name for reports.
    pub name: String,
    /// The robots; robot 0's MCS is the WCS by convention (not enforced).
    pub robots: Vec<RobotSpec>,
    /// Plain SAT or SAT with witness cache.
    pub method: SatMethod,
    /// The controller's cycle (ms; SPEC §8): the protective verdict's speed estimate.
    pub tick_ms: Real,
    /// One stopping model per robot (SPEC §8); [`StopModel::DEFAULT`] unless set.
    pub stops: Vec<StopModel>,
}

/// Why a cell cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum CellError {
    /// A cell file could not be read.
    Io(String),
    /// A cell file is not valid TOML or does not follow the schema.
    Parse(String),
    /// A value is out of range; the text names it.
    Invalid(String),
}

impl core::fmt::Display for CellError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CellError::Io(m) => write!(f, "cannot read cell file: {m}"),
            CellError::Parse(m) => write!(f, "invalid cell file: {m}"),
            CellError::Invalid(m) => write!(f, "invalid cell: {m}"),
        }
    }
}

impl core::error::Error for CellError {}

fn check_length(what: &str, v: Real, allow_zero: bool) -> Result<(), CellError> {
    if v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0)) && v <= MAX_LENGTH {
        Ok(())
    } else {
        let need = if allow_zero { ">= 0" } else { "> 0" };
        Err(CellError::Invalid(format!(
            "{what} = {v} must be finite, {need} and <= {MAX_LENGTH:e} (mm)"
        )))
    }
}

fn check_coordinate(what: &str, v: Real) -> Result<(), CellError> {
    if v.is_finite() && v.abs() <= MAX_LENGTH {
        Ok(())
    } else {
        Err(CellError::Invalid(format!(
            "{what} = {v} must be finite with |value| <= {MAX_LENGTH:e} (mm)"
        )))
    }
}

fn validate_robot(i: usize, r: &RobotSpec) -> Result<(), CellError> {
    let name = format!("robot {i} ({})", r.name);
    r.model.delta.validate().map_err(|m| CellError::Invalid(format!("{name}: {m}")))?;
    let o = &r.model.options;
    check_length(&format!("{name}: model.half_height"), o.half_height, true)?;
    check_length(&format!("{name}: model.half_depth"), o.half_depth, true)?;
    check_length(&format!("{name}: model.margin"), o.margin, true)?;
    if let Some((h, d)) = o.upper_links {
        check_length(&format!("{name}: model.upper_links.half_height"), h, true)?;
        check_length(&format!("{name}: model.upper_links.half_depth"), d, true)?;
    }
    for (what, b) in [("platform", o.platform), ("tool", o.tool)] {
        if let Some(b) = b {
            for k in 0..3 {
                check_length(&format!("{name}: model.{what}.half[{k}]"), b.half[k], true)?;
                check_coordinate(&format!("{name}: model.{what}.offset[{k}]"), b.offset[k])?;
            }
        }
    }
    let p = &r.placement;
    if !p.alpha.is_finite() {
        return Err(CellError::Invalid(format!(
            "{name}: placement.alpha = {} rad must be finite",
            p.alpha
        )));
    }
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        check_coordinate(&format!("{name}: placement.translation.{axis}"), p.t[k])?;
    }
    Ok(())
}

impl Cell {
    /// A validated cell.
    ///
    /// # Errors
    /// [`CellError::Invalid`] naming the first bad value: no robots, more than
    /// [`MAX_ROBOTS`], a non-positive length, a negative margin, bad motor limits or a
    /// non-finite placement.
    pub fn new(name: String, robots: Vec<RobotSpec>, method: SatMethod) -> Result<Cell, CellError> {
        if robots.is_empty() || robots.len() > MAX_ROBOTS {
            return Err(CellError::Invalid(format!(
                "a cell needs 1 to {MAX_ROBOTS} robots, this one has {}",
                robots.len()
            )));
        }
        for (i, r) in robots.iter().enumerate() {
            validate_robot(i, r)?;
        }
        let stops = alloc::vec![StopModel::DEFAULT; robots.len()];
        Ok(Cell { name, robots, method, tick_ms: DEFAULT_TICK_MS, stops })
    }

    /// This cell with the controller's tick and one stopping model per robot (SPEC §8).
    ///
    /// # Errors
    /// [`CellError::Invalid`] naming the field: a count other than one model per robot, a
    /// `tick_ms` or stop field that is NaN, infinite or not > 0, or a `decel_mm_s2` above
    /// `max_accel_mm_s2`.
    pub fn with_stopping(self, tick_ms: Real, stops: Vec<StopModel>) -> Result<Cell, CellError> {
        crate::robot::stopping::validate_tick_ms(tick_ms).map_err(CellError::Invalid)?;
        if stops.len() != self.robots.len() {
            return Err(CellError::Invalid(format!(
                "{} stopping models given for {} robots: give one per robot",
                stops.len(),
                self.robots.len()
            )));
        }
        for (i, (s, r)) in stops.iter().zip(&self.robots).enumerate() {
            s.validate(&format!("robot {i} ({}): stop", r.name)).map_err(CellError::Invalid)?;
        }
        Ok(Cell { tick_ms, stops, ..self })
    }

    /// Reads and validates a TOML cell file.
    ///
    /// # Errors
    /// As [`Cell::read_file`].
    #[cfg(feature = "std")]
    pub fn from_file(path: &std::path::Path) -> Result<Cell, CellError> {
        Cell::read_file(path).map(|f| f.cell)
    }

    /// Reads and validates a TOML cell file, with its table-mode settings.
    ///
    /// # Errors
    /// [`CellError::Io`] when the file cannot be read, [`CellError::Parse`] when it is not
    /// UTF-8 text, else as [`parse_cell_file`].
    #[cfg(feature = "std")]
    pub fn read_file(path: &std::path::Path) -> Result<CellFileContents, CellError> {
        let bytes =
            std::fs::read(path).map_err(|e| CellError::Io(format!("{}: {e}", path.display())))?;
        // A file that was read but is not text is a parse error (not TOML), not an I/O error.
        let text = String::from_utf8(bytes).map_err(|e| {
            CellError::Parse(format!(
                "{}: not UTF-8 text (byte {} is invalid), so not TOML",
                path.display(),
                e.utf8_error().valid_up_to()
            ))
        })?;
        parse_cell_file(&text)
    }

    /// A horizontal radius around robot `i`'s base axis that holds every point of every box
    /// of its model in any configuration: the elbow is within `f + rf` of the axis, every
    /// link point within `re` more, plus the box cross-section and margin.
    pub fn reach_radius(&self, i: usize) -> Real {
        let m = &self.robots[i].model;
        let (d, o) = (&m.delta, &m.options);
        let lower =
            d.f + d.rf + d.re + float::hypot(o.half_height + o.margin, o.half_depth + o.margin);
        let upper = o
            .upper_links
            .map_or(0.0, |(h, dz)| d.f + d.rf + float::hypot(h + o.margin, dz + o.margin));
        let extra = [o.platform, o.tool]
            .into_iter()
            .flatten()
            .map(|b| d.f + d.rf + d.re + b.offset.norm() + b.half.add_scalar(o.margin).norm())
            .fold(0.0, Real::max);
        lower.max(upper).max(extra)
    }

    /// The robot pairs `(a, b)`, `a < b`, whose reach can overlap; all others can never meet.
    pub fn pairs_that_can_meet(&self) -> Vec<(usize, usize)> {
        let n = self.robots.len();
        let mut pairs = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                let d = self.robots[b].placement.t - self.robots[a].placement.t;
                if float::hypot(d.x, d.y) <= self.reach_radius(a) + self.reach_radius(b) {
                    pairs.push((a, b));
                }
            }
        }
        pairs
    }

    /// Every value that decides a collision (geometry, boxes, margins, placements; not names
    /// or the SAT method), named as a cell file names it, in a fixed order. An absent optional
    /// box is the single value -1. `-0.0` is written as `0.0`: the two describe the same cell,
    /// and their bits differ.
    ///
    /// Tables store these values, so that a table refused for another cell can name the field
    /// that differs.
    pub fn parameters(&self) -> Vec<(String, Real)> {
        let mut out = Vec::new();
        let mut put = |name: String, v: Real| out.push((name, v + 0.0));
        put("robots".into(), self.robots.len() as Real);
        for (i, r) in self.robots.iter().enumerate() {
            let (d, o, p) = (&r.model.delta, &r.model.options, &r.placement);
            let geometry = [("f", d.f), ("rf", d.rf), ("re", d.re), ("e", d.e)];
            for (key, v) in
                geometry.into_iter().chain([("theta_min", d.theta_min), ("theta_max", d.theta_max)])
            {
                put(format!("robot {i}: geometry.{key}"), v);
            }
            for (key, v) in
                [("half_height", o.half_height), ("half_depth", o.half_depth), ("margin", o.margin)]
            {
                put(format!("robot {i}: model.{key}"), v);
            }
            let (uh, ud) = o.upper_links.unwrap_or((-1.0, -1.0));
            put(format!("robot {i}: model.upper_links.half_height"), uh);
            put(format!("robot {i}: model.upper_links.half_depth"), ud);
            for (key, b) in [("platform", o.platform), ("tool", o.tool)] {
                match b {
                    Some(b) => {
                        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                            put(format!("robot {i}: model.{key}.offset.{axis}"), b.offset[k]);
                        }
                        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                            put(format!("robot {i}: model.{key}.half.{axis}"), b.half[k]);
                        }
                    }
                    None => put(format!("robot {i}: model.{key} (absent)"), -1.0),
                }
            }
            put(format!("robot {i}: placement.alpha"), p.alpha);
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                put(format!("robot {i}: placement.translation.{axis}"), p.t[k]);
            }
        }
        out
    }

    /// A 64-bit FNV-1a hash of [`Cell::parameters`]' values: tables record it to refuse
    /// being used with another cell.
    pub fn fingerprint(&self) -> u64 {
        fingerprint_of(self.parameters().iter().map(|(_, v)| *v))
    }
}

/// The fingerprint of a list of cell parameter values (see [`Cell::fingerprint`]).
pub fn fingerprint_of(values: impl Iterator<Item = Real>) -> u64 {
    let bytes: Vec<u8> = values.flat_map(|v| (v + 0.0).to_le_bytes()).collect();
    fnv1a64(&bytes)
}

/// FNV-1a 64 of `bytes` (cell fingerprints, table checksums).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}
