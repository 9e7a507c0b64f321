//! The `dc_init*` calls of the `c_abi` target: configs edited from the thesis robot, tables
//! from the seeds (mutated, optionally resealed) or from the input, paths of every kind; after
//! each call `dc_last_init_error` is read back.

use super::Input;
use super::{keep, null_if, sentinel, Live};
use delta_collide::cell::{Cell, Placement, RobotSpec, SatMethod};
use delta_collide::ffi::*;
use delta_collide::math::Vec3;
use delta_collide::robot::{Delta3, ModelOptions, RobotModel, ToolBox};
use delta_collide::table::format::fnv1a64;
use delta_collide::table::{is_bundle, BundleChecker, Confirmation, TableChecker, TableKind};
use std::ffi::{c_char, CStr, CString};
use std::sync::OnceLock;

/// Robots per `dc_init` at most (32 are allowed; more must be refused).
const MAX_INIT_ROBOTS: u8 = 40;

/// Seed tables of cell T1 (k = 16) that `dc_init_with_table` starts from, one per kind; a
/// table's source byte is its index here ([`table_source`]), so committed inputs keep their
/// meaning only while this order stays.
const TABLES: [(TableKind, &[u8]); 6] = [
    (TableKind::D6, include_bytes!("../../seeds/table_bytes/t1_k16_6d_cut.dct")),
    (TableKind::D5, include_bytes!("../../seeds/table_bytes/t1_k16_5d_cut.dct")),
    (TableKind::D4yy, include_bytes!("../../seeds/table_bytes/t1_k16_4d_yy_cut.dct")),
    (TableKind::Shared, include_bytes!("../../seeds/table_bytes/t1_k16_shared_cut.dct")),
    (TableKind::SharedSub, include_bytes!("../../seeds/table_bytes/t1_k16_shared_sub_cut.dct")),
    (TableKind::Clearance, include_bytes!("../../seeds/table_bytes/t1_k16_clearance_whole.dct")),
];

/// The source byte of `Op::InitWithTable` that starts from the seed table of `kind`, if
/// there is one.
pub(super) fn table_source(kind: TableKind) -> Option<u8> {
    TABLES.iter().position(|&(k, _)| k == kind).map(|i| i as u8)
}

/// Sets field `field` of `r` from `input`; fields 0-5 are the geometry.
pub(super) fn edit(r: &mut DcRobotConfig, field: u8, input: &mut Input) {
    let flag = |input: &mut Input| match input.byte() % 3 {
        0 => 0,
        1 => 1,
        _ => input.u32(),
    };
    let (g, p, t) = (&mut r.geometry, &mut r.platform, &mut r.tool);
    let target: &mut f64 = match field % 30 {
        0 => &mut g.f,
        1 => &mut g.rf,
        2 => &mut g.re,
        3 => &mut g.e,
        4 => &mut g.theta_min,
        5 => &mut g.theta_max,
        6 => &mut r.half_height,
        7 => &mut r.half_depth,
        8 => &mut r.margin,
        9 => &mut r.upper_half_height,
        10 => &mut r.upper_half_depth,
        11 => &mut p.offset.x,
        12 => &mut p.offset.z,
        13 => &mut p.half.x,
        14 => &mut p.half.y,
        15 => &mut p.half.z,
        16 => &mut t.offset.y,
        17 => &mut t.offset.z,
        18 => &mut t.half.x,
        19 => &mut t.half.y,
        20 => &mut t.half.z,
        21 => &mut r.alpha,
        22 => &mut r.translation.x,
        23 => &mut r.translation.y,
        24 => &mut r.translation.z,
        25 => return r.has_upper_links = flag(input),
        26 => return r.has_platform = flag(input),
        27 => return r.has_tool = flag(input),
        28 => {
            let [x, y, z] = input.point();
            return r.translation = DcVec3 { x, y, z: z + 450.0 };
        }
        _ => {
            return r.geometry =
                DcDelta3 { theta_min: input.f64(), theta_max: input.f64(), ..r.geometry }
        }
    };
    *target = input.f64();
}

/// Whether every number `dc_init` reads from `r` is finite.
fn finite(r: &DcRobotConfig) -> bool {
    let g = &r.geometry;
    let b = |on: u32, b: &DcBox| {
        on == 0
            || [b.offset, b.half]
                .iter()
                .all(|v| v.x.is_finite() && v.y.is_finite() && v.z.is_finite())
    };
    let upper =
        r.has_upper_links == 0 || r.upper_half_height.is_finite() && r.upper_half_depth.is_finite();
    let t = &r.translation;
    [
        g.f,
        g.rf,
        g.re,
        g.e,
        g.theta_min,
        g.theta_max,
        r.half_height,
        r.half_depth,
        r.margin,
        r.alpha,
        t.x,
        t.y,
        t.z,
    ]
    .iter()
    .all(|v| v.is_finite())
        && upper
        && b(r.has_platform, &r.platform)
        && b(r.has_tool, &r.tool)
}

/// The cell `dc_init` makes of `robots`, built here through the Rust API (the same validation).
fn cell_of(robots: &[DcRobotConfig], method: u32) -> Option<Cell> {
    let method = match method {
        DC_METHOD_SAT => SatMethod::Sat,
        DC_METHOD_SAT_CACHE => SatMethod::SatCache,
        _ => return None,
    };
    let v = |v: &DcVec3| Vec3::new(v.x, v.y, v.z);
    let tool =
        |on: u32, b: &DcBox| (on != 0).then(|| ToolBox { offset: v(&b.offset), half: v(&b.half) });
    let spec = |(i, r): (usize, &DcRobotConfig)| {
        let g = &r.geometry;
        let delta = Delta3 {
            f: g.f,
            rf: g.rf,
            re: g.re,
            e: g.e,
            theta_min: g.theta_min,
            theta_max: g.theta_max,
        };
        let options = ModelOptions {
            half_height: r.half_height,
            half_depth: r.half_depth,
            margin: r.margin,
            upper_links: (r.has_upper_links != 0)
                .then_some((r.upper_half_height, r.upper_half_depth)),
            platform: tool(r.has_platform, &r.platform),
            tool: tool(r.has_tool, &r.tool),
        };
        let placement = Placement { alpha: r.alpha, t: v(&r.translation) };
        RobotSpec { name: format!("robot {i}"), model: RobotModel { delta, options }, placement }
    };
    Cell::new("fuzz".into(), robots.iter().enumerate().map(spec).collect(), method).ok()
}

/// A config read from `input`: robot count, method, NULL flags (bit 0 config, bit 1 robots),
/// and edits of thesis robots standing 450 mm apart along x.
struct Config {
    robots: Vec<DcRobotConfig>,
    n: usize,
    method: u32,
    nulls: u8,
}

impl Config {
    fn read(input: &mut Input, max_robots: u8) -> Config {
        let n = usize::from(input.byte() % (max_robots + 1));
        let method = match input.byte() % 4 {
            0 => DC_METHOD_SAT,
            1 => DC_METHOD_SAT_CACHE,
            2 => 2,
            _ => input.u32(),
        };
        let nulls = input.byte();
        let mut robots: Vec<DcRobotConfig> = (0..n.max(1))
            .map(|i| DcRobotConfig {
                translation: DcVec3 { x: 450.0 * i as f64, y: 0.0, z: 0.0 },
                ..dc_robot_config_thesis()
            })
            .collect();
        for _ in 0..input.byte() % 16 {
            let i = usize::from(input.byte()) % robots.len();
            let field = input.byte();
            edit(&mut robots[i], field, input);
        }
        Config { robots, n, method, nulls }
    }

    /// Calls `make` with the `DcCellConfig` pointer (NULL when asked).
    fn with_ptr<R>(&mut self, make: impl FnOnce(*const DcCellConfig) -> R) -> R {
        let robots = null_if(self.nulls & 2 != 0, self.robots.as_mut_ptr());
        let config = DcCellConfig { robots, n_robots: self.n, method: self.method };
        make(if self.nulls & 1 != 0 { std::ptr::null() } else { &config })
    }

    /// The cell `dc_init` would make, when the pointers are given and the config is valid.
    fn cell(&self) -> Option<Cell> {
        (self.nulls & 3 == 0 && self.n > 0)
            .then(|| cell_of(&self.robots[..self.n], self.method))
            .flatten()
    }

    /// The status `dc_init` must give when the table (if any) is not the problem.
    fn expected_status(&self) -> DcStatus {
        if self.nulls & 3 != 0 {
            DC_STATUS_NULL_POINTER
        } else if self.cell().is_some() {
            DC_STATUS_OK
        } else {
            DC_STATUS_INVALID_CONFIG
        }
    }

    fn into_live(mut self, handle: *mut DcCollider) -> Live {
        self.robots.truncate(self.n);
        Live::new(handle, self.robots)
    }
}

/// Checks `*out_handle` and `dc_last_init_error` after a `dc_init*` call; keeps a new handle.
fn finish(
    status: DcStatus,
    out: Option<*mut DcCollider>,
    input: &mut Input,
) -> Option<*mut DcCollider> {
    assert_ne!(status, DC_STATUS_PANIC, "a dc_init* call panicked");
    // SAFETY: NULL and 0 ask for the length only.
    let len = unsafe { dc_last_init_error(std::ptr::null_mut(), 0) };
    assert_eq!(len == 0, status == DC_STATUS_OK, "status {status} with a {len}-byte init error");
    let capacity = usize::from(input.byte());
    let mut buf = vec![0x55 as c_char; capacity.max(1)];
    // SAFETY: `buf` holds at least `capacity` writable bytes.
    assert_eq!(unsafe { dc_last_init_error(buf.as_mut_ptr(), capacity) }, len);
    if capacity > 0 {
        // SAFETY: `dc_last_init_error` NUL-terminated the buffer within `capacity` bytes.
        let text = unsafe { CStr::from_ptr(buf.as_ptr()) };
        assert_eq!(
            text.to_bytes().len(),
            len.min(capacity - 1),
            "init error cut wrongly: {text:?}"
        );
    }
    let out = out?;
    assert!(out != sentinel(), "dc_init* did not write *out_handle");
    assert_eq!(status == DC_STATUS_OK, !out.is_null(), "status {status} with handle {out:?}");
    (status == DC_STATUS_OK).then_some(out)
}

/// `Op::Init`.
pub(super) fn init(input: &mut Input, live: &mut Vec<Live>) {
    let mut config = Config::read(input, MAX_INIT_ROBOTS);
    let null_out = input.flag();
    let mut out = sentinel();
    // SAFETY: the config is NULL or valid with `n_robots <= robots.len()`; `out` NULL or writable.
    let status = config.with_ptr(|c| unsafe { dc_init(c, null_if(null_out, &mut out)) });
    let expected = if null_out { DC_STATUS_NULL_POINTER } else { config.expected_status() };
    assert_eq!(status, expected, "dc_init of {:?}", &config.robots[..config.n]);
    let Some(h) = finish(status, (!null_out).then_some(out), input) else { return };
    let n = config.n;
    assert!(
        config.robots[..n].iter().all(finite),
        "a non-finite config accepted: {:?}",
        &config.robots[..n]
    );
    // SAFETY: `h` is a live handle.
    let (count, pairs, mode) = unsafe { (dc_robot_count(h), dc_pair_count(h), dc_mode(h)) };
    assert!(count == n && pairs <= n * (n - 1) / 2, "{count} robots, {pairs} pairs for n = {n}");
    // SAFETY: `h` is a live handle.
    assert!(mode == DC_MODE_EXACT && unsafe { dc_table_fallbacks(h) } == 0);
    keep(live, config.into_live(h));
}

/// Table bytes: a seed table or bytes of the input (source byte), up to 7 byte edits, and
/// optionally resealed (fingerprint of `cell`, checksum) so that edits reach the field checks.
fn table_bytes(input: &mut Input, cell: Option<&Cell>) -> Vec<u8> {
    let source = input.byte();
    let mut bytes = match TABLES.get(usize::from(source % 7)) {
        Some((_, t)) => t.to_vec(),
        None => {
            let len = usize::from(u16::from_le_bytes(input.bytes()) % 512);
            (0..len).map(|_| input.byte()).collect()
        }
    };
    for _ in 0..input.byte() % 8 {
        let (at, value) = (usize::from(u16::from_le_bytes(input.bytes())), input.byte());
        if let Some(b) = bytes.len().checked_sub(1).and_then(|last| bytes.get_mut(at.min(last))) {
            *b = value;
        }
    }
    if input.flag() {
        if let (Some(cell), Some(field)) = (cell, bytes.get_mut(40..48)) {
            field.copy_from_slice(&cell.fingerprint().to_le_bytes());
        }
        if let Some(n) = bytes.len().checked_sub(8) {
            let sum = fnv1a64(&bytes[..n]);
            bytes[n..].copy_from_slice(&sum.to_le_bytes());
        }
    }
    bytes
}

/// `Op::InitWithTable`: the status must be the one `TableChecker::new` implies.
pub(super) fn init_with_table(input: &mut Input, live: &mut Vec<Live>) {
    let mut config = Config::read(input, 3);
    let cell = config.cell();
    let bytes = table_bytes(input, cell.as_ref());
    let (null_table, null_out) = (input.flag(), input.flag());
    let table_ptr = if null_table { std::ptr::null() } else { bytes.as_ptr() };
    let mut out = sentinel();
    // SAFETY: the config is NULL or valid; `table_ptr` NULL or `bytes.len()` readable bytes;
    // `out` NULL or writable.
    let status = config.with_ptr(|c| unsafe {
        dc_init_with_table(c, table_ptr, bytes.len(), null_if(null_out, &mut out))
    });
    let expected = match (null_out, config.expected_status(), cell) {
        (true, _, _) => DC_STATUS_NULL_POINTER,
        (_, DC_STATUS_OK, _) if null_table => DC_STATUS_NULL_POINTER,
        (_, DC_STATUS_OK, Some(cell)) if cell.robots.len() < 2 => DC_STATUS_TABLE_NOT_TWO_ROBOTS,
        // More robots, or a bundle: one table per pair that can meet, from the bundle.
        (_, DC_STATUS_OK, Some(cell)) if cell.robots.len() > 2 || is_bundle(&bytes) => {
            BundleChecker::new(cell, &bytes, Confirmation::Exact)
                .map_or_else(|e| table_error_status(&e), |_| DC_STATUS_OK)
        }
        (_, DC_STATUS_OK, Some(cell)) => TableChecker::new(cell, &bytes)
            .map_or_else(|e| table_error_status(&e), |_| DC_STATUS_OK),
        (_, s, _) => s,
    };
    assert_eq!(status, expected, "dc_init_with_table");
    let Some(h) = finish(status, (!null_out).then_some(out), input) else { return };
    // SAFETY: `h` is a live handle.
    let (count, pairs, mode) = unsafe { (dc_robot_count(h), dc_pair_count(h), dc_mode(h)) };
    let expected_pairs = if count == 2 && !is_bundle(&bytes) {
        1
    } else {
        config.cell().map_or(0, |c| c.pairs_that_can_meet().len())
    };
    assert!(
        count >= 2 && pairs == expected_pairs && mode == DC_MODE_TABLE,
        "{count} robots, {pairs} pairs, mode {mode}"
    );
    keep(live, config.into_live(h));
}

/// A file next to the crate that compiled this file (the fuzz crate or the main crate's
/// tests): `rel` from the repository root.
fn repo_file(rel: &str) -> CString {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = [dir.join(rel), dir.join("..").join(rel)].into_iter().find(|p| p.exists());
    let file = file.unwrap_or_else(|| panic!("{rel} next to the crate or one folder up"));
    CString::new(file.to_str().expect("UTF-8 path")).expect("no NUL in the path")
}

/// Paths of every kind (NULL, not UTF-8, missing, a folder, empty, a real file), by `kind % 6`.
fn path(kind: u8, real: &'static CStr) -> *const c_char {
    match kind % 6 {
        0 => std::ptr::null(),
        1 => c"/tmp/\xff\xfe.toml".as_ptr(),
        2 => c"/nonexistent/delta-collide/cell.toml".as_ptr(),
        3 => c"/".as_ptr(),
        4 => c"".as_ptr(),
        _ => real.as_ptr(),
    }
}

/// The status a path of this kind gives before anything is parsed (`None` for the real file).
fn path_status(kind: u8) -> Option<DcStatus> {
    match kind % 6 {
        0 => Some(DC_STATUS_NULL_POINTER),
        1 => Some(DC_STATUS_INVALID_ARGUMENT),
        2..=4 => Some(DC_STATUS_IO),
        _ => None,
    }
}

fn t1_cell_path() -> &'static CStr {
    static PATH: OnceLock<CString> = OnceLock::new();
    PATH.get_or_init(|| repo_file("cells/t1.toml"))
}

fn t1_table_path() -> &'static CStr {
    static PATH: OnceLock<CString> = OnceLock::new();
    PATH.get_or_init(|| repo_file("fuzz/seeds/table_bytes/t1_k16_6d_cut.dct"))
}

/// The two thesis robots of T1 as `dc_init` takes them.
fn t1_robots() -> Vec<DcRobotConfig> {
    let b = DcRobotConfig {
        translation: DcVec3 { x: 450.0, y: 0.0, z: 0.0 },
        ..dc_robot_config_thesis()
    };
    vec![dc_robot_config_thesis(), b]
}

/// `Op::InitFromFile`: path kind (byte), NULL out flag (byte).
pub(super) fn init_from_file(input: &mut Input, live: &mut Vec<Live>) {
    let kind = input.byte();
    let null_out = input.flag();
    let mut out = sentinel();
    // SAFETY: the path is NULL or NUL-terminated; `out` NULL or writable.
    let status =
        unsafe { dc_init_from_cell_file(path(kind, t1_cell_path()), null_if(null_out, &mut out)) };
    let expected =
        if null_out { DC_STATUS_NULL_POINTER } else { path_status(kind).unwrap_or(DC_STATUS_OK) };
    assert_eq!(status, expected, "dc_init_from_cell_file, path kind {kind}");
    if let Some(h) = finish(status, (!null_out).then_some(out), input) {
        keep(live, Live::new(h, t1_robots()));
    }
}

/// `Op::InitFromFiles`: cell path kind, table path kind (bytes), NULL out flag.
pub(super) fn init_from_files(input: &mut Input, live: &mut Vec<Live>) {
    let (cell_kind, table_kind, null_out) = (input.byte(), input.byte(), input.flag());
    let mut out = sentinel();
    let (cell_path, table_path) =
        (path(cell_kind, t1_cell_path()), path(table_kind, t1_table_path()));
    // SAFETY: both paths NULL or NUL-terminated; `out` NULL or writable.
    let status = unsafe { dc_init_from_files(cell_path, table_path, null_if(null_out, &mut out)) };
    let loaded = || {
        let bytes = std::fs::read(t1_table_path().to_str().unwrap()).unwrap();
        let t1 = delta_collide::cell::reference::reference_cell("T1").unwrap();
        TableChecker::new(t1, &bytes).map_or_else(|e| table_error_status(&e), |_| DC_STATUS_OK)
    };
    let expected = match (null_out, path_status(cell_kind), path_status(table_kind)) {
        (true, _, _) => DC_STATUS_NULL_POINTER,
        // Both paths are checked before either file is read.
        (_, Some(DC_STATUS_NULL_POINTER | DC_STATUS_INVALID_ARGUMENT), _) => {
            path_status(cell_kind).unwrap()
        }
        (_, _, Some(s @ (DC_STATUS_NULL_POINTER | DC_STATUS_INVALID_ARGUMENT))) => s,
        (_, Some(s), _) | (_, None, Some(s)) => s,
        (_, None, None) => loaded(),
    };
    assert_eq!(status, expected, "dc_init_from_files, path kinds {cell_kind}, {table_kind}");
    if let Some(h) = finish(status, (!null_out).then_some(out), input) {
        keep(live, Live::new(h, t1_robots()));
    }
}
