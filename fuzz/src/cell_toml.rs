//! Target `cell_toml`: a cell file's text (`cell::parse_cell`), then the exact check of the
//! cell it describes, and the same cell through the C ABI (`dc_init` / `dc_query`).
//!
//! Bytes that are not UTF-8 are parsed after lossy conversion. Properties checked:
//! - parsing, building the checker and querying never panic;
//! - a cell that parses is accepted by `dc_init` when given as a `DcCellConfig` (both paths
//!   validate alike), and `dc_query` then agrees with the exact checker on every probe:
//!   status OK and the same verdict when every TCP is reachable, else a non-OK status and STOP;
//! - the unreachable mask names exactly the robots whose TCP inverse kinematics rejects.

use delta_collide::cell::{parse_cell, Cell, ExactChecker, SatMethod, MAX_ROBOTS};
use delta_collide::ffi::*;
use delta_collide::math::Vec3;

/// The target: never panics on any input.
pub fn cell_toml(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let cell = match parse_cell(&text) {
        Ok(cell) => cell,
        Err(e) => return drop(e.to_string()),
    };
    let n = cell.robots.len();
    assert!((1..=MAX_ROBOTS).contains(&n), "{n} robots accepted");
    let _ = (cell.fingerprint(), (0..n).map(|i| cell.reach_radius(i)).sum::<f64>());
    let mut exact = ExactChecker::new(cell.clone());
    let c = CHandle::new(&cell);
    for tcps in probes(&cell) {
        let v = exact.check(&tcps).expect("one TCP per robot");
        for (j, tcp) in tcps.iter().enumerate() {
            let reachable = cell.robots[j].model.delta.is_reachable(tcp);
            assert_eq!(v.unreachable_mask >> j & 1 == 0, reachable, "robot {j} at {tcp:?}");
        }
        let (status, verdict) = c.query(&tcps);
        if v.unreachable_mask == 0 {
            let expected = if v.collides() { DC_VERDICT_COLLISION } else { DC_VERDICT_FREE };
            assert_eq!((status, verdict), (DC_STATUS_OK, expected), "C ABI disagrees at {tcps:?}");
        } else {
            assert!(
                status != DC_STATUS_OK && verdict == DC_VERDICT_STOP,
                "status {status}, verdict {verdict}"
            );
        }
    }
    let home = vec![Vec3::new(0.0, 0.0, -450.0); n + 1];
    assert!(
        exact.check(&home).is_err() && exact.check(&home[..n - 1]).is_err(),
        "wrong TCP count accepted"
    );
}

/// TCP sets, one TCP per robot (each in its own MCS): everyone at a few common points, every
/// robot at the world midpoint of robots 0 and 1 (where neighbours collide), one robot at a
/// NaN / above-base / deep point with the others at home.
fn probes(cell: &Cell) -> Vec<Vec<Vec3>> {
    let n = cell.robots.len();
    let home = Vec3::new(0.0, 0.0, -450.0);
    let common = [
        home,
        Vec3::new(150.0, 0.0, -400.0),
        Vec3::new(-120.0, 90.0, -500.0),
        Vec3::new(0.0, 0.0, -1e6),
    ];
    let mut out: Vec<Vec<Vec3>> = common.iter().map(|&p| vec![p; n]).collect();
    let t1 = cell.robots.get(1).map_or(Vec3::zeros(), |r| r.placement.t);
    let mid = (cell.robots[0].placement.t + t1) * 0.5 + Vec3::new(0.0, 0.0, -450.0);
    out.push(cell.robots.iter().map(|r| r.placement.to_mcs(&mid)).collect());
    for odd in
        [Vec3::new(f64::NAN, 0.0, -450.0), Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -2000.0)]
    {
        let mut tcps = vec![home; n];
        tcps[n - 1] = odd;
        out.push(tcps);
    }
    out
}

/// A handle made from a [`Cell`] through `dc_init`, destroyed on drop.
struct CHandle(*mut DcCollider);

impl CHandle {
    fn new(cell: &Cell) -> Self {
        let robots: Vec<DcRobotConfig> = cell.robots.iter().map(DcRobotConfig::from_spec).collect();
        let method =
            if cell.method == SatMethod::Sat { DC_METHOD_SAT } else { DC_METHOD_SAT_CACHE };
        let config = DcCellConfig { robots: robots.as_ptr(), n_robots: robots.len(), method };
        let mut h = std::ptr::null_mut();
        // SAFETY: `config` points to `n_robots` robots; `h` is writable.
        let status = unsafe { dc_init(&config, &mut h) };
        assert_eq!(status, DC_STATUS_OK, "a parsed cell is refused by dc_init");
        CHandle(h)
    }

    fn query(&self, tcps: &[Vec3]) -> (DcStatus, DcVerdict) {
        let tcps: Vec<DcVec3> = tcps.iter().map(DcVec3::from_vec3).collect();
        let mut verdict = DC_VERDICT_FREE;
        // SAFETY: live handle; `tcps` holds `len` points; `verdict` is writable.
        let status = unsafe {
            dc_query(self.0, tcps.as_ptr(), tcps.len(), &mut verdict, std::ptr::null_mut())
        };
        (status, verdict)
    }
}

impl Drop for CHandle {
    fn drop(&mut self) {
        // SAFETY: live handle from dc_init, destroyed once.
        unsafe { dc_destroy(self.0) }
    }
}
