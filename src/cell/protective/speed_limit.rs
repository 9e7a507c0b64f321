//! Each robot's speed limit (the module doc of `protective` defines it): the largest
//! measured speed at which every pair involving it is still proved, the other robots as they
//! are, searched by bisection on a grid of `v_max / 2^LIMIT_STEPS` within a budget of tests
//! per tick.

use super::stop_sweeps::first_unproved;
use super::{Protective, ProtectiveChecker, LIMIT_STEPS};
use crate::math::{Real, Vec3};

impl ProtectiveChecker {
    /// Each robot's speed limit when they are asked for (else NaN), with this tick's stop
    /// references of every robot already set (the limits search about them).
    pub(super) fn speed_limits_of(&mut self, tcps_mcs: &[Vec3], from_history: bool) {
        (self.report.limit_tests, self.report.limit_budget_spent) = (0, false);
        if !self.model.speed_limits {
            self.report.robots.iter_mut().for_each(|r| r.speed_limit_mm_s = Real::NAN);
            return;
        }
        // This tick's verdict, when not STOP, proved every pair at each robot's measured speed
        // (with its measured direction, the ball the search's tests build at that speed too).
        let proved_now = self.report.verdict != Protective::Stop;
        let n = tcps_mcs.len();
        // Without a history (`check_at_speeds`) no search has a last limit to start from, so
        // none would get far with a few tests: those searches are not capped.
        let cap = if from_history { self.model.limit_tests } else { u32::MAX };
        let (first, mut left) = (self.calls.limit_turn % n.max(1), cap);
        self.calls.limit_turn = self.calls.limit_turn.wrapping_add(1);
        for i in 0..n {
            let j = (first + i) % n;
            let tcp = &tcps_mcs[j];
            let start = self.robots[j].history.limit.filter(|_| from_history);
            let v = self.report.robots[j].speed_mm_s;
            let floor =
                if proved_now && v <= self.cell().stops[j].max_speed_mm_s { v } else { 0.0 };
            // What is left, but one test for each robot after this one (while there are any).
            let after = (n - 1 - i) as u32;
            let budget = if left > after { left - after } else { left.min(1) };
            let (limit, used, step) = self.speed_limit(j, tcp, start, floor, budget);
            left -= used;
            (self.report.robots[j].speed_limit_mm_s, self.robots[j].limit_step) = (limit, step);
        }
        self.report.limit_tests = cap - left;
        self.report.limit_budget_spent = n > 0 && left == 0;
    }

    /// Robot `j`'s speed limit (module doc), the other robots' sweeps as they are: the search
    /// from `start` (the last tick's limit and the step of the first test above it), never
    /// below `floor`, a speed this tick's verdict proved for `j` (0 when none), with at most
    /// `budget` tests of the table's tier. Returns the limit, the tests used, and the step of
    /// the next tick's first test above the limit.
    fn speed_limit(
        &mut self,
        j: usize,
        tcp_mcs: &Vec3,
        start: Option<(Real, Real)>,
        floor: Real,
        budget: u32,
    ) -> (Real, u32, Real) {
        // Robot `j`'s state, whose reference each test replaces: restored after the search.
        let saved = self.robots[j];
        let inside = self.kept.inside(j);
        let mut search = LimitBisection::new(self.cell().stops[j].max_speed_mm_s, floor, budget);
        let tier = if self.model.precise_limits { self.model.precise_splits } else { 0 };
        let mut proved = |v: Real, tier: Option<u32>| self.speed_proved(j, tcp_mcs, v, tier);
        // Tier 1 alone: the default limit (capped), and the floor of the precise one (not).
        let ((lo, hi), next_step) = match start {
            _ if tier == 0 => {
                let (lo, step) = search.capped(start, |v| proved(v, Some(0)));
                ((lo, search.vmax), step)
            }
            Some((h, _)) => (search.near(h, |v| proved(v, Some(0))), search.resolution),
            None => (search.below(search.vmax, |v| proved(v, Some(0))), search.resolution),
        };
        let limit = if tier == 0 || lo == search.vmax {
            lo
        } else {
            search.precise((lo, hi), |v, precise| proved(v, precise.then_some(tier)))
        };
        self.robots[j] = saved;
        self.kept.restore_inside(j, inside);
        // The step is kept only when the limit is the one the steps were taken from.
        let next_step = if limit >= floor { next_step } else { search.resolution };
        (limit.max(floor), search.used, next_step)
    }

    /// Whether robot `j` at TCP `tcp_mcs` and measured speed `v` has every pair involving it
    /// proved, with the motor angles of `tier` (`None`: only the certain-STOP test, no
    /// sweeps, which every tier needs to pass). Replaces `j`'s reference.
    fn speed_proved(&mut self, j: usize, tcp_mcs: &Vec3, v: Real, tier: Option<u32>) -> bool {
        let s = self.stop_reference(j, tcp_mcs, v);
        let reference = &self.robots[j].reference;
        let balls = [(reference.centre, reference.radius), (*tcp_mcs, s)];
        if self.kept.set_inside(j, &balls) && self.kept_free(Some(j)) {
            return true;
        }
        if self.report.closest.is_some_and(|h| (h.a == j || h.b == j) && self.ball_swept_meet(h)) {
            return false;
        }
        let Some(tier) = tier else { return true };
        // The robots that can meet `j` as they are, with the motor angles of the same tier;
        // with tier 1, another robot keeps the sweeps it has for this tick's reference, tier 1
        // or the verdict's second tier on some arms: each encloses every box of its stop
        // (module doc, step 4), the second tier within the first, so a test proved with them
        // is a proof, and tier 2 on every arm proves it too (the precise limit stays the
        // higher); only a robot without sweeps gets tier 1's.
        for k in 0..self.exact.verdict().pairs.len() {
            let p = self.exact.verdict().pairs[k];
            if p.a == j || p.b == j {
                for i in [p.a, p.b] {
                    if i == j || tier > 0 || self.robots[i].tier.is_none() {
                        self.sweeps_at(i, tier, 0b111);
                    }
                }
            }
        }
        let (robots, pairs) = (&self.robots, &self.pairs);
        let (ball, axis) = (|i: usize| &robots[i].reference, |k: usize| &pairs[k].axis);
        first_unproved(&self.exact.verdict().pairs, ball, axis, Some(j), 0.0).is_none()
    }
}

/// A bracket `(lo, hi)`: `lo` proved, `hi` not (or both the answer).
type Bracket = (Real, Real);

/// One robot's search for the largest proved speed (module doc): tests on the grid of
/// `v_max / 2^LIMIT_STEPS` only, so that searches of the same proof end at the same bracket
/// (`v_max` is `2^LIMIT_STEPS` steps exactly; so is every grid speed a whole number of them),
/// over a predicate that says whether a speed is proved.
struct LimitBisection {
    vmax: Real,
    resolution: Real,
    /// A speed this tick's verdict proved (0 when none): never worth going below.
    floor: Real,
    /// Tests of the capped search at most, and those used.
    budget: u32,
    used: u32,
}

impl LimitBisection {
    fn new(vmax: Real, floor: Real, budget: u32) -> LimitBisection {
        let resolution = vmax / (1u32 << LIMIT_STEPS) as Real;
        LimitBisection { vmax, resolution, floor, budget, used: 0 }
    }

    /// The grid speed nearest the middle of `lo` and `hi` (grid speeds, at least two steps
    /// apart), strictly between them.
    fn middle(&self, lo: Real, hi: Real) -> Real {
        lo + (0.5 * (hi - lo) / self.resolution).floor().max(1.0) * self.resolution
    }

    /// `h` on the grid, within `[0, v_max]`.
    fn on_grid(&self, h: Real) -> Real {
        ((h / self.resolution).round() * self.resolution).clamp(0.0, self.vmax)
    }

    /// From `lo` (proved) and `hi` (not), halves until they are `resolution` apart.
    fn bisect(&self, (mut lo, mut hi): Bracket, mut proved: impl FnMut(Real) -> bool) -> Bracket {
        while hi - lo > self.resolution {
            let mid = self.middle(lo, hi);
            if proved(mid) {
                lo = mid
            } else {
                hi = mid
            }
        }
        (lo, hi)
    }

    /// The bracket of one test alone below `top` (not proved there, unless `top = v_max`).
    fn below(&self, top: Real, mut proved: impl FnMut(Real) -> bool) -> Bracket {
        if top == self.vmax && proved(self.vmax) {
            (self.vmax, self.vmax)
        } else if !proved(0.0) {
            (0.0, 0.0)
        } else {
            self.bisect((0.0, top), proved)
        }
    }

    /// The same bracket found from `h`, the last tick's limit: steps of doubling length up
    /// (while proved) or down (while not) to a bracket, then the bisection. Limits change
    /// little from tick to tick, so this takes a few tests instead of `LIMIT_STEPS + 2`.
    fn near(&self, h: Real, mut proved: impl FnMut(Real) -> bool) -> Bracket {
        let h = self.on_grid(h);
        let up = proved(h);
        let (mut from, mut step) = (h, self.resolution);
        loop {
            let to = if up { (from + step).min(self.vmax) } else { (from - step).max(0.0) };
            if to == from {
                return (from, from);
            }
            if proved(to) != up {
                return self.bisect(if up { (from, to) } else { (to, from) }, proved);
            }
            (from, step) = (to, 2.0 * step);
        }
    }

    /// [`LimitBisection::below`] or [`LimitBisection::near`] within the budget: the largest speed a
    /// test proved (0 when none did, or when every speed above `floor` that the search would
    /// still test is at most `floor`: `floor` is the answer then), and where the next tick's
    /// first step up starts: where this one's steps or bisection stopped for want of tests
    /// (`resolution` when the search ended).
    fn capped(
        &mut self,
        start: Option<Bracket>,
        mut proved: impl FnMut(Real) -> bool,
    ) -> (Real, Real) {
        let (vmax, resolution, floor) = (self.vmax, self.resolution, self.floor);
        let mut test = |me: &mut Self, v: Real| {
            let left = me.used < me.budget;
            me.used += u32::from(left);
            left.then(|| proved(v))
        };
        // `lo` proved, `hi` not (`None`: no such speed tested yet).
        let (mut lo, mut hi) = (None, None);
        let mut step = resolution;
        match start {
            Some((h, carried)) => {
                let h = self.on_grid(h);
                match test(self, h) {
                    None => return (0.0, resolution),
                    Some(true) => (lo, step) = (Some(h), carried.max(resolution)),
                    Some(false) => hi = Some(h),
                }
            }
            None => {
                match test(self, vmax) {
                    None => return (0.0, resolution),
                    Some(true) => return (vmax, resolution),
                    Some(false) => hi = Some(vmax),
                }
                match test(self, 0.0) {
                    Some(true) => lo = Some(0.0),
                    _ => return (0.0, resolution),
                }
            }
        }
        loop {
            let (to, up) = match (lo, hi) {
                (Some(l), None) if l >= vmax => return (vmax, resolution),
                (Some(l), None) => ((l + step).min(vmax), true),
                (None, Some(h)) if h <= floor || h <= 0.0 => return (0.0, resolution),
                (None, Some(h)) => ((h - step).max(0.0), false),
                _ => break,
            };
            match test(self, to) {
                // Out of tests while going up: the next tick goes on with the next step.
                None => return (lo.unwrap_or(0.0), if up { step } else { resolution }),
                Some(true) => lo = Some(to),
                Some(false) => hi = Some(to),
            }
            // A bracket found going down from `hi` ends the steps; going up, so does `hi`.
            if !up && lo.is_some() {
                break;
            }
            step *= 2.0;
        }
        let (Some(mut lo), Some(mut hi)) = (lo, hi) else { return (lo.unwrap_or(0.0), resolution) };
        while hi - lo > resolution && hi > floor {
            let mid = self.middle(lo, hi);
            match test(self, mid) {
                // Out of tests: the next tick tries the middle of the bracket first.
                None => return (lo, mid - lo),
                Some(true) => lo = mid,
                Some(false) => hi = mid,
            }
        }
        (lo, resolution)
    }

    /// The precise limit from tier 1's bracket `(lo, hi)`: `proved(v, true)` tests with both
    /// tiers, `proved(v, false)` the certain-STOP test alone, above whose failure no tier
    /// proves anything.
    fn precise(&self, (lo, hi): Bracket, mut proved: impl FnMut(Real, bool) -> bool) -> Real {
        let top = self.below(self.vmax, |v| proved(v, false)).1;
        if top == 0.0 {
            0.0
        } else if hi == 0.0 {
            // The table proves not even standing still: the second tier alone.
            self.below(top, |v| proved(v, true)).0
        } else if hi >= top || !proved(hi, true) {
            lo
        } else if top == self.vmax && proved(self.vmax, true) {
            self.vmax
        } else {
            self.bisect((hi, top), |v| proved(v, true)).0
        }
    }
}
