//! The vendor-style baseline of the benchmark: a zone interlock (FANUC interference zones,
//! ABB world zones, Siemens semaphores). Per robot pair one cuboid of the world holds every
//! set-point (of either robot's whole programme) at which the two may come within the
//! coordination's clearance of each other; a robot enters it only while it owns the pair's
//! semaphore, which it asks for when it must start braking to stop short of the entry,
//! gets when the neighbour does not hold it (the nearer robot first), and gives back when it
//! has left the cuboid.

use super::cells::conflict_cells;
use super::programme::Programmes;
use crate::cell::{Cell, ExactChecker};
use crate::coord::speed::{allowed_speed, stopping_mm};
use crate::math::{Real, Vec3};

/// Programme ticks between the samples that the zones are found from.
const ZONE_STRIDE: usize = 4;

/// How far ahead along its programme a robot looks for its next entry (ticks).
const LOOKAHEAD_TICKS: usize = 600;

/// One pair's zone and semaphore.
#[derive(Clone, Debug)]
struct Zone {
    robots: (usize, usize),
    /// Per robot of the pair, per programme tick: whether its TCP is inside the cuboid.
    inside: [Vec<bool>; 2],
    owner: Option<usize>,
    entered: bool,
}

/// The zone interlock of a cell running given programmes.
#[derive(Clone, Debug)]
pub struct Interlock {
    zones: Vec<Zone>,
    margin_mm: Real,
}

impl Interlock {
    /// The zones of `cell`'s pairs that can meet, from the whole `programmes` (offline, as an
    /// integrator sets them up), for robots that must come no closer than `clearance_mm`.
    pub fn new(cell: &Cell, programmes: &Programmes, clearance_mm: Real, margin_mm: Real) -> Self {
        let exact = ExactChecker::new(cell.clone());
        let wcs = |j: usize, p: &Vec3| exact.rotation(j) * p + cell.robots[j].placement.t;
        let mut zones = Vec::new();
        for (a, b) in cell.pairs_that_can_meet() {
            let (mut lo, mut hi) = (Vec3::repeat(Real::INFINITY), Vec3::repeat(Real::NEG_INFINITY));
            let c = conflict_cells(cell, programmes, (a, b), ZONE_STRIDE, clearance_mm);
            let mut marked = [vec![false; c.rows], vec![false; c.cols]];
            for i in 0..c.rows {
                for k in 0..c.cols {
                    if c.cells[i * c.cols + k] {
                        marked[0][i] = true;
                        marked[1][k] = true;
                    }
                }
            }
            for (side, &j) in [a, b].iter().enumerate() {
                for (i, _) in marked[side].iter().enumerate().filter(|(_, m)| **m) {
                    let p = wcs(j, &programmes[j][i * ZONE_STRIDE]);
                    lo = lo.inf(&p);
                    hi = hi.sup(&p);
                }
            }
            // The samples are ZONE_STRIDE ticks apart: grow the cuboid by a stride's travel.
            let reach = Vec3::repeat(
                ZONE_STRIDE as Real
                    * cell.stops[a].max_speed_mm_s.max(cell.stops[b].max_speed_mm_s)
                    * cell.tick_ms
                    * 1e-3,
            );
            let (lo, hi) = (lo - reach, hi + reach);
            let inside = |j: usize| -> Vec<bool> {
                programmes[j]
                    .iter()
                    .map(|p| {
                        let w = wcs(j, p);
                        (0..3).all(|d| w[d] >= lo[d] && w[d] <= hi[d])
                    })
                    .collect()
            };
            zones.push(Zone {
                robots: (a, b),
                inside: [inside(a), inside(b)],
                owner: None,
                entered: false,
            });
        }
        Interlock { zones, margin_mm }
    }

    /// Each robot's override target this tick (1 unless it must stop short of a zone it does
    /// not own), with each robot's `progress` (programme ticks) and the programmed speed ahead
    /// (mm/s).
    pub fn targets(
        &mut self,
        cell: &Cell,
        programmes: &Programmes,
        progress: &[Real],
        speed_now_mm_s: &[Real],
        speed_ahead_mm_s: &[Real],
        out: &mut [Real],
    ) {
        out.iter_mut().for_each(|o| *o = 1.0);
        for zone in &mut self.zones {
            let (a, b) = zone.robots;
            let tick = |j: usize| (progress[j].floor() as usize).min(programmes[j].len() - 1);
            let now_in = [zone.inside[0][tick(a)], zone.inside[1][tick(b)]];
            // Arc length to each robot's next entry, 0 when inside, infinite when none ahead.
            let entry = |side: usize, j: usize| -> Real {
                let (p, t0) = (&programmes[j], tick(j));
                let mut arc = 0.0;
                for t in t0..(t0 + LOOKAHEAD_TICKS).min(p.len()) {
                    if zone.inside[side][t] {
                        return arc;
                    }
                    if t + 1 < p.len() {
                        arc += (p[t + 1] - p[t]).norm();
                    }
                }
                Real::INFINITY
            };
            let d = [entry(0, a), entry(1, b)];
            // Give back: the owner has been inside and is out.
            if let Some(o) = zone.owner {
                let side = usize::from(o == b);
                if now_in[side] {
                    zone.entered = true;
                } else if zone.entered {
                    zone.owner = None;
                    zone.entered = false;
                }
            }
            // Ask: a robot that must brake now to stop short of its entry (nearer first).
            let must_ask = |side: usize, j: usize| {
                now_in[side]
                    || stopping_mm(cell, j, speed_now_mm_s[j]) + 2.0 * self.margin_mm + 50.0
                        >= d[side]
            };
            let order = if d[1] < d[0] { [1, 0] } else { [0, 1] };
            for side in order {
                let j = [a, b][side];
                if zone.owner.is_none() && must_ask(side, j) {
                    zone.owner = Some(j);
                    zone.entered = now_in[side];
                }
            }
            for (side, &j) in [a, b].iter().enumerate() {
                if zone.owner.is_some_and(|o| o != j) && d[side].is_finite() {
                    let v = allowed_speed(cell, j, d[side] - self.margin_mm);
                    let t = if speed_ahead_mm_s[j] > 0.0 {
                        (v / speed_ahead_mm_s[j]).min(1.0)
                    } else {
                        1.0
                    };
                    out[j] = out[j].min(t);
                }
            }
        }
    }
}
