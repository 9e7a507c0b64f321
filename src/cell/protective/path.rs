//! The protective verdict when the controller knows the path of the stop (SPEC §8, "Where the
//! controller knows more"): a controller that performs a path-maintaining stop can give, per
//! robot, the polyline its TCP will follow until it stands still, with a tolerance.
//!
//! # The promise and the bound
//! A [`StopPath`] promises that from this tick until the robot stands still its TCP stays
//! within `tolerance_mm` of the polyline `points` (its commanded set-points, which the servo
//! follows within that error). The stopping model still holds as well, so the TCP also stays
//! within the stopping distance `S` of where it is now (module doc of `protective`, step 3).
//! Every TCP of the stop therefore lies in `tube(Q, tol) ∩ ball(p, S)`.
//!
//! 1. **Cover.** Let `[s0, s1]` be the arc range of `Q` from the first to the last point of
//!    `Q` within `S + tol` of `p` ([`arc_range`]). A TCP of the stop is within `tol` of a
//!    point `q` of `Q` with `|q - p| <= S + tol`, so `q = Q(s)` with `s` in `[s0, s1]`. A
//!    piece `[a, b]` of that range holds points within `(b - a) / 2` of `Q((a + b) / 2)`
//!    (arc length is at least distance), so its TCPs lie in the ball of radius
//!    `(b - a) / 2 + tol` around that point ([`piece_ball`]).
//! 2. **Pieces apart.** Each piece's ball gives a reference and box sweeps exactly as the
//!    whole stop's ball does (`stop_sweeps_wcs`, tier 1). When robot `a`'s piece and robot
//!    `b`'s piece are proved apart, so is every pair of sub-pieces (their TCPs are subsets).
//!    So the prover splits the larger piece of an unproved pair in halves and proves both
//!    halves ([`MAX_DEPTH`] halvings per robot at most); all pairs proved: FREE.
//! 3. **Fallback.** A robot without a path is one piece: the ball of the verdict without
//!    paths. A piece whose ball is not smaller than that ball, or whose centre is unreachable,
//!    uses that ball too (it holds every TCP of the stop), and keeps its arc range: its halves
//!    may be smaller or reachable. The path verdict is taken only where it is better than the verdict
//!    without paths (both are proofs).
//! 4. **In time.** A pair that steps 1-2 leave unproved is tried again with both stops cut
//!    into time slices (`slices.rs`): per slice, the arc range each robot can be in at those
//!    moments, proved apart as in step 2; every slice proved: the pair is. This pairs the
//!    robots' positions at the same time, which steps 1-2 do not (a robot leaving the place
//!    the other is heading for). It needs the path followed in order (the commanded arc
//!    position never goes back) and the stopping model's acceleration bound for braking too.
//!    The speed limits do not: in the closed-loop benchmark, limits raised by it let robots
//!    close in faster and cost more STOPs than they saved.
//!
//! A path that breaks its promise at once (the TCP now is farther than `tol` from `Q`, a
//! non-finite point or tolerance, a negative tolerance, no point) is
//! [`ProtectiveStatus::InvalidPath`](super::ProtectiveStatus::InvalidPath): STOP. Nothing here
//! allocates.

use super::certain_stop::graded_radii;
use super::slices::{slice_arcs, stands_by, StopMotion, SLICES};
use super::stop_sweeps::SweptBall;
use super::{first_unproved_between, stop_sweeps_wcs, BoxPair, Protective, ProtectiveChecker};
use crate::geometry::distance::segment_distance;
use crate::math::{Real, Vec3};
use crate::robot::{RobotBoxes, MAX_BOXES};

/// Most points of one stop path that a controller passes (the C ABI's
/// `DC_MAX_PATH_POINTS`): a stop of a few hundred mm in points a few ticks apart, in a
/// buffer of fixed size. The proof itself takes any number.
pub const MAX_PATH_POINTS: usize = 32;

/// Halvings of one robot's piece at most, per robot pair (up to `2^MAX_DEPTH` pieces).
pub const MAX_DEPTH: u32 = 3;

/// Tests of the proof along the paths that may raise one robot's speed limit per tick.
pub const PATH_LIMIT_TESTS: u32 = 4;

/// The path a robot's TCP will follow over its stop (module doc): the polyline through
/// `points` (MCS, mm), in order (the point of the polyline it follows never goes back), left
/// by at most `tolerance_mm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopPath<'a> {
    /// The polyline's vertices, in the order the TCP follows them (MCS, mm).
    pub points: &'a [Vec3],
    /// How far the TCP may be from the polyline at any moment of the stop (mm).
    pub tolerance_mm: Real,
}

/// Length of the polyline `points`.
fn length(points: &[Vec3]) -> Real {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// The point at arc length `s` (clamped) of the polyline `points`.
pub fn point_at(points: &[Vec3], s: Real) -> Vec3 {
    let mut rest = s.max(0.0);
    for w in points.windows(2) {
        let len = (w[1] - w[0]).norm();
        if rest <= len && len > 0.0 {
            return w[0] + (w[1] - w[0]) * (rest / len);
        }
        rest -= len;
    }
    points[points.len() - 1]
}

/// The distance from `p` to the polyline `points` (at least one point).
pub fn distance_to(points: &[Vec3], p: &Vec3) -> Real {
    let mut best = (points[0] - p).norm();
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let len2 = d.norm_squared();
        let t = if len2 > 0.0 { ((p - w[0]).dot(&d) / len2).clamp(0.0, 1.0) } else { 0.0 };
        best = best.min((w[0] + d * t - p).norm());
    }
    best
}

/// The arc range `[s0, s1]` of the polyline `points` from its first to its last point within
/// `r` of `c` (module doc, step 1); `None` when no point is.
pub fn arc_range(points: &[Vec3], c: &Vec3, r: Real) -> Option<(Real, Real)> {
    let mut range: Option<(Real, Real)> = None;
    let mut start = 0.0;
    let mut add = |s: Real| range = Some(range.map_or((s, s), |(a, b)| (a.min(s), b.max(s))));
    if points.len() == 1 {
        return ((points[0] - c).norm() <= r).then_some((0.0, 0.0));
    }
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let len = d.norm();
        // |w0 + t d - c|^2 <= r^2 for t in [0, 1]: t^2 |d|^2 + 2 t d.(w0 - c) + |w0 - c|^2 - r^2 <=
        // 0.
        let f = w[0] - c;
        let (qa, qb, qc) = (d.norm_squared(), 2.0 * d.dot(&f), f.norm_squared() - r * r);
        if qa == 0.0 {
            if qc <= 0.0 {
                add(start);
            }
            continue;
        }
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let root = disc.sqrt();
            let (t0, t1) = ((-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa));
            let (t0, t1) = (t0.max(0.0), t1.min(1.0));
            if t0 <= t1 {
                // Widened by a relative 1e-12: rounding must not cut a point off.
                let slack = 1e-12 * (len + r);
                add((start + t0 * len - slack).max(0.0));
                add(start + t1 * len + slack);
            }
        }
        start += len;
    }
    range.map(|(a, b)| (a, b.min(start)))
}

/// The arc range holding every TCP of a stop that starts at `c`, stays within `r - tol` of
/// it and within `tol` of the polyline `points` (module doc, step 1), tighter than
/// [`arc_range`] where the polyline leaves the ball and comes back.
///
/// Every TCP of the stop is within `tol` of a point of the polyline in the ball of radius
/// `r`; those points form *runs*, arc intervals each inside the ball. The TCP's motion is a
/// connected set covered by the closed `tol`-neighbourhoods of the runs, so it can only
/// pass from one run's neighbourhood to another's where they meet, that is where the runs
/// come within `2 tol` of each other. The cover is therefore the runs that a chain of such
/// meetings joins to a run within `tol` of `c`; the range from the first to the last of them.
/// Falls back to [`arc_range`] beyond [`MAX_PATH_POINTS`] points.
pub fn arc_cover(points: &[Vec3], c: &Vec3, r: Real, tol: Real) -> Option<(Real, Real)> {
    if points.len() < 2 || points.len() > MAX_PATH_POINTS {
        return arc_range(points, c, r);
    }
    // Per segment, its part inside the ball: (segment, t0, t1, arc0, arc1).
    let mut parts = [(0usize, 0.0, 0.0, 0.0, 0.0); MAX_PATH_POINTS];
    let mut count = 0;
    let mut start = 0.0;
    for (k, w) in points.windows(2).enumerate() {
        let d = w[1] - w[0];
        let len = d.norm();
        let f = w[0] - c;
        let (qa, qb, qc) = (d.norm_squared(), 2.0 * d.dot(&f), f.norm_squared() - r * r);
        let inside = if qa == 0.0 {
            (qc <= 0.0).then_some((0.0, 1.0))
        } else {
            let disc = qb * qb - 4.0 * qa * qc;
            (disc >= 0.0).then(|| {
                let root = disc.sqrt();
                (((-qb - root) / (2.0 * qa)).max(0.0), ((-qb + root) / (2.0 * qa)).min(1.0))
            })
        };
        if let Some((t0, t1)) = inside.filter(|(t0, t1)| t0 <= t1) {
            // Widened as in `arc_range`: rounding must not cut a point off.
            let slack = 1e-12 * (len + r);
            let (t0, t1) = ((t0 - slack).max(0.0), (t1 + slack).min(1.0));
            parts[count] = (k, t0, t1, start + t0 * len, start + t1 * len);
            count += 1;
        }
        start += len;
    }
    let parts = &parts[..count];
    if parts.is_empty() {
        return None;
    }
    // Runs: parts that join end to start (a part ending at its segment's end, the next
    // starting at the next segment's start).
    let mut run_of = [0usize; MAX_PATH_POINTS];
    for i in 1..parts.len() {
        let (prev, this) = (parts[i - 1], parts[i]);
        let joined = this.0 == prev.0 + 1 && prev.2 >= 1.0 && this.1 <= 0.0;
        run_of[i] = run_of[i - 1] + usize::from(!joined);
    }
    let runs = run_of[parts.len() - 1] + 1;
    let segment = |i: usize| {
        let (k, t0, t1, _, _) = parts[i];
        let d = points[k + 1] - points[k];
        (points[k] + d * t0, points[k] + d * t1)
    };
    let near = |a: usize, b: usize, within: Real| {
        let limit = within * (1.0 + 1e-9) + 1e-9;
        (0..parts.len()).filter(|&i| run_of[i] == a).any(|i| {
            (0..parts.len()).filter(|&j| run_of[j] == b).any(|j| {
                let ((p0, p1), (q0, q1)) = (segment(i), segment(j));
                segment_distance(&p0, &p1, &q0, &q1) <= limit
            })
        })
    };
    let mut taken = [false; MAX_PATH_POINTS];
    for i in 0..parts.len() {
        let (p0, p1) = segment(i);
        if segment_distance(&p0, &p1, c, c) <= tol * (1.0 + 1e-9) + 1e-9 {
            taken[run_of[i]] = true;
        }
    }
    // The chain of meetings: at most one run joins per round.
    for _ in 0..runs {
        let joins =
            (0..runs).find(|&b| !taken[b] && (0..runs).any(|a| taken[a] && near(a, b, 2.0 * tol)));
        match joins {
            Some(b) => taken[b] = true,
            None => break,
        }
    }
    let mut range: Option<(Real, Real)> = None;
    for (_, p) in parts.iter().enumerate().filter(|(i, _)| taken[run_of[*i]]) {
        range = Some(range.map_or((p.3, p.4), |(a, b)| (a.min(p.3), b.max(p.4))));
    }
    // No run near the TCP (it is not within `tol` of the path): the whole range.
    range.or_else(|| arc_range(points, c, r))
}

/// The ball holding every point within `tol` of the polyline's arc range `[a, b]`.
pub fn piece_ball(points: &[Vec3], (a, b): (Real, Real), tol: Real) -> (Vec3, Real) {
    let centre = point_at(points, 0.5 * (a + b));
    // Widened as the stop's own ball is: rounding of the arc walk.
    (centre, (0.5 * (b - a) + tol) * (1.0 + 1e-12) + 1e-9)
}

/// Whether `path` is usable for a robot whose TCP is `tcp` (module doc, last paragraph).
pub fn path_is_valid(path: &StopPath, tcp: &Vec3) -> bool {
    let finite = path.points.iter().all(|p| p.iter().all(|x| x.is_finite()));
    finite
        && !path.points.is_empty()
        && path.tolerance_mm.is_finite()
        && path.tolerance_mm >= 0.0
        && length(path.points).is_finite()
        && distance_to(path.points, tcp) <= path.tolerance_mm * (1.0 + 1e-9) + 1e-9
}

/// A stop path of at most `out.len()` points through sampled TCPs ahead, for a controller
/// (or a replay) that knows its commanded path only as samples: `samples[0]` is the TCP now,
/// the rest the commanded TCPs that follow. Greedy: each segment runs from its start sample
/// as far as every sample in between stays within `tolerance_mm` of it; the path ends at the
/// first sample at least `length_mm` along it (or the last sample, where the robot holds).
/// Returns the number of points written, or `None` when `out` is too short for that: a path
/// cut short would break its promise.
pub fn path_through_samples(
    samples: &[Vec3],
    length_mm: Real,
    tolerance_mm: Real,
    out: &mut [Vec3],
) -> Option<usize> {
    *out.first_mut()? = *samples.first()?;
    let (mut n, mut start, mut arc) = (1, 0, 0.0);
    for i in 1..samples.len() {
        arc += (samples[i] - samples[i - 1]).norm();
        let last = arc >= length_mm || i + 1 == samples.len();
        // Does the segment from `samples[start]` to the next sample hold every sample between?
        let extend = !last && {
            let chord = [samples[start], samples[i + 1]];
            samples[start + 1..=i].iter().all(|p| distance_to(&chord, p) <= tolerance_mm)
        };
        if !extend {
            *out.get_mut(n)? = samples[i];
            (n, start) = (n + 1, i);
            if last {
                break;
            }
        }
    }
    Some(n)
}

/// A piece's halves, built when first needed (`None`: it has no range to halve).
pub(super) type Halves = core::cell::OnceCell<Option<(Piece, Piece)>>;

/// Pieces of a halving tree that are halved themselves (depths 0 to `MAX_DEPTH - 1`): node
/// `k`'s halves are nodes `2k + 1` and `2k + 2`.
pub(super) const TREE_NODES: usize = (1 << MAX_DEPTH) - 1;

/// Where a piece's halves are kept: in the tick's halving tree of a robot's whole stop (node
/// `k`: the verdict and every test of the speed limits read the same halves), or in the frame
/// of one proof.
#[derive(Clone, Copy)]
struct Slot<'s> {
    halves: &'s Halves,
    tree: Option<(&'s [Halves; TREE_NODES], usize)>,
}

impl<'s> Slot<'s> {
    /// The root of `tree`, or a slot of one proof when there is none.
    fn root(tree: Option<&'s [Halves; TREE_NODES]>, local: &'s Halves) -> Slot<'s> {
        match tree {
            Some(t) => Slot { halves: &t[0], tree: Some((t, 0)) },
            None => Slot { halves: local, tree: None },
        }
    }

    /// The slots of this piece's two halves: the tree's nodes below it, else `local`.
    fn children(self, local: &'s [Halves; 2]) -> [Slot<'s>; 2] {
        match self.tree {
            Some((t, k)) if 2 * k + 2 < TREE_NODES => {
                let node = |i: usize| Slot { halves: &t[i], tree: Some((t, i)) };
                [node(2 * k + 1), node(2 * k + 2)]
            }
            _ => [Slot { halves: &local[0], tree: None }, Slot { halves: &local[1], tree: None }],
        }
    }
}

/// One piece of a robot's stop: the ball holding its TCPs, its boxes at the ball's centre and
/// their sweeps over the ball.
#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    /// The arc range of the path (`None`: the ball of the verdict without paths).
    arc: Option<(Real, Real)>,
    ball: SweptBall,
}

impl ProtectiveChecker {
    /// The piece of robot `j` for the arc range `arc` of its path (module doc, steps 1, 3).
    fn piece(&self, j: usize, path: Option<&StopPath>, arc: Option<(Real, Real)>) -> Piece {
        let robot = &self.cell().robots[j];
        let rot = *self.exact.rotation(j);
        let reference = &self.robots[j].reference;
        let mut boxes = RobotBoxes::empty();
        let ball = match (path, arc) {
            (Some(p), Some(range)) => Some(piece_ball(p.points, range, p.tolerance_mm)),
            _ => None,
        };
        let ball = ball.filter(|&(c, r)| {
            r < reference.radius && self.exact.boxes_in_wcs(j, &c, &mut boxes).is_ok()
        });
        let (centre, radius, arc) = match ball {
            Some((c, r)) => (c, r, arc),
            None => {
                boxes = reference.boxes;
                (reference.centre, reference.radius, arc)
            }
        };
        let sweeps =
            stop_sweeps_wcs(&robot.model, &rot, &centre, radius, self.model.tables[j].as_deref());
        let faces = [[self.model.no_faces; MAX_BOXES]; 2];
        let graded = graded_radii(&robot.model, radius);
        let mut ball = SweptBall { centre, radius, boxes, sweeps, faces, graded };
        ball.set_faces();
        Piece { arc, ball }
    }

    /// The halves of `piece` of robot `j`, when it has a path range to split.
    /// `None` too when the work budget has not the two units left (`work.rs`).
    fn halves(&self, j: usize, path: Option<&StopPath>, piece: &Piece) -> Option<(Piece, Piece)> {
        let (a, b) = piece.arc?;
        if !self.work.spend(2) {
            return None;
        }
        let m = 0.5 * (a + b);
        Some((self.piece(j, path, Some((a, m))), self.piece(j, path, Some((m, b)))))
    }

    /// The first box pair of robots `a < b` not proved apart over pieces `pa`, `pb`, halving
    /// the larger piece (module doc, step 2) while `depth_a`, `depth_b` allow; a piece that is
    /// a robot's whole stop this tick takes its halves from that robot's tree (`trees`).
    fn prove_pieces(
        &self,
        ab: (usize, usize),
        paths: (Option<&StopPath>, Option<&StopPath>),
        (pa, pb): (&Piece, &Piece),
        trees: (Option<&[Halves; TREE_NODES]>, Option<&[Halves; TREE_NODES]>),
        depths: (u32, u32),
        extra: Real,
    ) -> Option<BoxPair> {
        let local = [Halves::new(), Halves::new()];
        let slots = [(pa, Slot::root(trees.0, &local[0])), (pb, Slot::root(trees.1, &local[1]))];
        self.prove_halving(ab, paths, slots, depths, extra)
    }

    /// [`ProtectiveChecker::prove_pieces`], with each piece's halves built at most once:
    /// a piece that stays while the other is halved is halved itself in both branches.
    fn prove_halving(
        &self,
        (a, b): (usize, usize),
        (path_a, path_b): (Option<&StopPath>, Option<&StopPath>),
        [(pa, slot_a), (pb, slot_b)]: [(&Piece, Slot); 2],
        (depth_a, depth_b): (u32, u32),
        extra: Real,
    ) -> Option<BoxPair> {
        if !self.work.spend(1) {
            return Some(self.out_of_work_pair(a, b));
        }
        let unproved = first_unproved_between(&pa.ball, &pb.ball, extra, &Vec3::zeros())
            .map(|(box_a, box_b)| BoxPair { a, b, box_a, box_b })?;
        let paths = (path_a, path_b);
        let span = |p: &Piece| p.arc.map_or(-1.0, |(s0, s1)| s1 - s0);
        let split_a = depth_a < MAX_DEPTH && (span(pa) >= span(pb) || depth_b >= MAX_DEPTH);
        if split_a {
            if let Some((h1, h2)) = slot_a.halves.get_or_init(|| self.halves(a, path_a, pa)) {
                let deeper = (depth_a + 1, depth_b);
                let local = [Halves::new(), Halves::new()];
                let [c1, c2] = slot_a.children(&local);
                return self
                    .prove_halving((a, b), paths, [(h1, c1), (pb, slot_b)], deeper, extra)
                    .or_else(|| {
                        self.prove_halving((a, b), paths, [(h2, c2), (pb, slot_b)], deeper, extra)
                    });
            }
        }
        if depth_b < MAX_DEPTH {
            if let Some((h1, h2)) = slot_b.halves.get_or_init(|| self.halves(b, path_b, pb)) {
                let deeper = (depth_a, depth_b + 1);
                let local = [Halves::new(), Halves::new()];
                let [c1, c2] = slot_b.children(&local);
                return self
                    .prove_halving((a, b), paths, [(pa, slot_a), (h1, c1)], deeper, extra)
                    .or_else(|| {
                        self.prove_halving((a, b), paths, [(pa, slot_a), (h2, c2)], deeper, extra)
                    });
            }
        }
        Some(unproved)
    }

    /// The box pair reported for robots `a < b` when the work budget leaves them unproved:
    /// the limiting pair of the verdict without paths when it is theirs, else their first.
    fn out_of_work_pair(&self, a: usize, b: usize) -> BoxPair {
        let first = BoxPair { a, b, box_a: 0, box_b: 0 };
        self.report.limiting.filter(|p| (p.a, p.b) == (a, b)).unwrap_or(first)
    }

    /// The piece of robot `j`'s whole stop of length `s` along its path (or its reference
    /// ball without a path).
    fn whole_piece(&self, j: usize, tcp_mcs: &Vec3, s: Real, path: Option<&StopPath>) -> Piece {
        let arc = path.and_then(|p| {
            let tol = p.tolerance_mm;
            arc_cover(p.points, tcp_mcs, s + tol, tol)
        });
        self.piece(j, path, arc)
    }

    /// Robot `j`'s motion over its stop (`slices.rs`) from TCP `tcp_mcs`, as this tick
    /// measured it (no velocity when its speed is unknown).
    fn stop_motion(&self, j: usize, tcp_mcs: &Vec3) -> StopMotion {
        let cell = self.cell();
        let stop = cell.stops[j];
        let v = self.report.robots[j].speed_mm_s;
        StopMotion {
            tcp: *tcp_mcs,
            velocity: v.is_finite().then_some(self.robots[j].velocity),
            speed_bound_mm_s: self.speed_bound(j, v),
            interval_s: self.calls.interval_s,
            reaction_s: (stop.reaction_ms + cell.tick_ms) * 1e-3,
            stop,
        }
    }

    /// Whether robots `a < b` are proved apart slice by slice (`slices.rs`, module doc step
    /// 4), their motions `motions` (a robot without a path is its reference ball in every
    /// slice).
    fn proved_in_slices(
        &self,
        (a, b): (usize, usize),
        motions: (&StopMotion, &StopMotion),
        paths: (Option<&StopPath>, Option<&StopPath>),
        extra: Real,
    ) -> bool {
        let end = stands_by(motions.0).max(stands_by(motions.1));
        let mut arcs = [[None; SLICES]; 2];
        for (side, (m, path)) in [(motions.0, paths.0), (motions.1, paths.1)].iter().enumerate() {
            let Some(path) = path else { continue };
            let mut ranges = [(0.0, 0.0); SLICES];
            if !slice_arcs(m, path, end, &mut ranges) {
                return false;
            }
            for (slot, range) in arcs[side].iter_mut().zip(ranges) {
                *slot = Some(range);
            }
        }
        // A piece is built again only where its range changed (a robot at rest keeps it), and
        // only with a unit of work left for it.
        let reuse = |last: Option<Piece>, j: usize, path, arc| match last {
            Some(p) if p.arc == arc => Some(p),
            _ => self.work.spend(1).then(|| self.piece(j, path, arc)),
        };
        let (mut last_a, mut last_b) = (None, None);
        for (&arc_a, &arc_b) in arcs[0].iter().zip(&arcs[1]) {
            let Some(pa) = reuse(last_a.take(), a, paths.0, arc_a) else { return false };
            let Some(pb) = reuse(last_b.take(), b, paths.1, arc_b) else { return false };
            if self.prove_pieces((a, b), paths, (&pa, &pb), (None, None), (0, 0), extra).is_some() {
                return false;
            }
            (last_a, last_b) = (Some(pa), Some(pb));
        }
        true
    }

    /// Each robot's piece of its whole stop at its measured speed (module doc, step 1), for
    /// the references of this tick: built once a tick, read by the verdict and by every test
    /// of the speed limits along the paths. `false`, with no piece built, when the work
    /// budget has not one unit per robot (`work.rs`).
    pub(super) fn set_whole_pieces(
        &mut self,
        tcps_mcs: &[Vec3],
        paths: &[Option<StopPath>],
    ) -> bool {
        if !self.work.spend(tcps_mcs.len() as u32) {
            return false;
        }
        for j in 0..tcps_mcs.len() {
            let s = self.report.robots[j].protective_mm;
            let piece = self.whole_piece(j, &tcps_mcs[j], s, paths[j].as_ref());
            self.whole_pieces[j] = Some(piece);
            self.whole_halves[j].iter_mut().for_each(|h| *h = Halves::new());
        }
        true
    }

    /// Robot `j`'s piece of [`ProtectiveChecker::set_whole_pieces`].
    fn whole_of(&self, j: usize) -> &Piece {
        self.whole_pieces[j].as_ref().expect("set_whole_pieces ran this tick")
    }

    /// Each robot's speed limit along the paths: the limit without paths is a speed the proof
    /// along the paths holds too (it is taken only where better). Up to [`PATH_LIMIT_TESTS`]
    /// speeds are tested, each for every pair involving the robot, over the robot's stop at
    /// that speed and two ticks of its motion: first the last tick's limit along the paths
    /// (the search goes on from there: a limit that must climb from the one without paths
    /// every tick stays within a few grid steps of it), then, above the highest speed proved,
    /// one grid step of the limits (`v_max / 2^LIMIT_STEPS`) and steps of doubling length;
    /// after a failed test, halfway between the highest speed proved and the lowest failed.
    /// A robot without a path keeps its limit.
    pub(super) fn path_limits(&mut self, tcps_mcs: &[Vec3], paths: &[Option<StopPath>]) {
        for j in 0..tcps_mcs.len() {
            let r = self.report.robots[j];
            let last = self.robots[j].history.path_limit;
            self.robots[j].history.path_limit = None;
            if paths[j].is_none() || r.speed_limit_mm_s.is_nan() {
                continue;
            }
            let v_max = self.cell().stops[j].max_speed_mm_s;
            let grid = v_max / Real::from(1u32 << super::LIMIT_STEPS);
            let (mut proved, mut failed) = (r.speed_limit_mm_s, Real::INFINITY);
            let mut next = last.filter(|&l| l > proved).unwrap_or(proved + grid).min(v_max);
            let mut step = grid;
            let saved = self.robots[j];
            let inside = self.kept.inside(j);
            for _ in 0..PATH_LIMIT_TESTS {
                if !(next > proved && next < failed) {
                    break;
                }
                if self.speed_proved_along(j, tcps_mcs, paths, next) {
                    proved = next;
                    next = (proved + step).min(v_max).min(0.5 * (proved + failed));
                    step *= 2.0;
                } else if self.work.ran_out() {
                    // Not a failed proof: no work left to finish it. The limit is the highest
                    // speed proved.
                    break;
                } else {
                    failed = next;
                    next = 0.5 * (proved + failed);
                }
            }
            self.robots[j] = saved;
            self.kept.restore_inside(j, inside);
            self.report.robots[j].speed_limit_mm_s = proved;
            self.robots[j].history.path_limit = Some(proved);
        }
    }

    /// Whether every pair involving robot `j` is proved along the paths with `j` at speed `v`:
    /// `j`'s stop at that speed and two ticks of its motion, one piece against each other
    /// robot's whole stop as it is. Replaces `j`'s reference.
    fn speed_proved_along(
        &mut self,
        j: usize,
        tcps_mcs: &[Vec3],
        paths: &[Option<StopPath>],
        v: Real,
    ) -> bool {
        if !self.work.spend(1) {
            return false;
        }
        let s = self.stop_reference(j, &tcps_mcs[j], v);
        // Two ticks more along the path: a limit the controller applies must still be proved
        // where the robot is when the next verdicts come.
        let ahead = s + 2.0 * v * self.cell().tick_ms * 1e-3;
        let piece_j = self.whole_piece(j, &tcps_mcs[j], ahead, paths[j].as_ref());
        self.exact.verdict().pairs.iter().filter(|p| p.a == j || p.b == j).all(|pair| {
            let (a, b) = (pair.a, pair.b);
            let o = if a == j { b } else { a };
            let (other, tree) = (self.whole_of(o), Some(&self.whole_halves[o]));
            let (pieces, trees) = if a == j {
                ((&piece_j, other), (None, tree))
            } else {
                ((other, &piece_j), (tree, None))
            };
            let paths_ab = (paths[a].as_ref(), paths[b].as_ref());
            self.prove_pieces((a, b), paths_ab, pieces, trees, (0, 0), 0.0).is_none()
        })
    }

    /// The verdict and limiting pair over the pieces of the paths (module doc), for the
    /// pieces of [`ProtectiveChecker::set_whole_pieces`]; and whether some pair needed its stop
    /// cut into time slices (step 4) for that verdict.
    pub(super) fn prove_with_paths(
        &self,
        tcps_mcs: &[Vec3],
        paths: &[Option<StopPath>],
    ) -> (Protective, Option<BoxPair>, bool) {
        let motion = |j: usize| self.stop_motion(j, &tcps_mcs[j]);
        // Whether the last pass proved a pair only in slices (the flag of the verdict it gave).
        let mut sliced_before = false;
        for (extra, verdict) in [(0.0, Protective::Stop), (self.model.warn_mm, Protective::Warn)] {
            if extra == 0.0 && verdict == Protective::Warn {
                break;
            }
            let mut sliced = false;
            for pair in &self.exact.verdict().pairs {
                let (a, b) = (pair.a, pair.b);
                let paths_ab = (paths[a].as_ref(), paths[b].as_ref());
                let wholes = (self.whole_of(a), self.whole_of(b));
                let trees = (Some(&self.whole_halves[a]), Some(&self.whole_halves[b]));
                let Some(found) = self.prove_pieces((a, b), paths_ab, wholes, trees, (0, 0), extra)
                else {
                    continue;
                };
                if !self.proved_in_slices((a, b), (&motion(a), &motion(b)), paths_ab, extra) {
                    return (verdict, Some(found), sliced_before);
                }
                sliced = true;
            }
            sliced_before = sliced;
        }
        (Protective::Free, None, sliced_before)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: Real, y: Real, z: Real) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn arc_range_of_a_line_through_a_ball_is_its_chord() {
        let line = [v(-100.0, 0.0, 0.0), v(100.0, 0.0, 0.0)];
        let (a, b) = arc_range(&line, &v(0.0, 30.0, 0.0), 50.0).unwrap();
        // The chord at height 30 of a radius-50 ball: x in [-40, 40], arc 60..140.
        assert!((a - 60.0).abs() < 1e-9 && (b - 140.0).abs() < 1e-9, "{a} {b}");
        assert_eq!(arc_range(&line, &v(0.0, 60.0, 0.0), 50.0), None);
    }

    #[test]
    fn arc_range_spans_every_segment_that_enters_the_ball() {
        // Out along x, back along x 10 mm higher: both legs pass the ball.
        let path = [v(0.0, 0.0, 0.0), v(200.0, 0.0, 0.0), v(200.0, 0.0, 10.0), v(0.0, 0.0, 10.0)];
        let (a, b) = arc_range(&path, &v(0.0, 0.0, 0.0), 20.0).unwrap();
        assert_eq!(a, 0.0);
        assert!(b > 400.0, "the return leg ends inside the ball: {b}");
    }

    #[test]
    fn the_cover_leaves_out_a_return_leg_only_where_no_motion_can_reach_it() {
        // Out 300 mm along x, up 40 mm, back: the return leg passes the ball around the start
        // again, 40 mm away from the out leg.
        let path = [v(0.0, 0.0, 0.0), v(300.0, 0.0, 0.0), v(300.0, 0.0, 40.0), v(0.0, 0.0, 40.0)];
        let c = v(0.0, 0.0, 0.0);
        let (a, b) = arc_range(&path, &c, 60.0).unwrap();
        assert!(b > 600.0, "{a} {b}");
        let (a, b) = arc_cover(&path, &c, 60.0, 0.5).unwrap();
        assert!(a == 0.0 && (b - 60.0).abs() < 1e-6, "only the out leg: {a} {b}");
        // The same with the return leg 0.8 mm from the out leg: within 2 tol, it is joined.
        let close = [v(0.0, 0.0, 0.0), v(300.0, 0.0, 0.0), v(300.0, 0.0, 0.8), v(0.0, 0.0, 0.8)];
        let (_, b) = arc_cover(&close, &c, 60.0, 0.5).unwrap();
        assert!(b > 600.0, "the legs meet: {b}");
        // A TCP within tol of the return leg only starts from it.
        let (a, _) = arc_cover(&path, &v(30.0, 0.0, 40.2), 60.0, 0.5).unwrap();
        assert!(a > 300.0, "{a}");
    }

    #[test]
    fn piece_balls_hold_the_points_of_their_range() {
        let path = [v(0.0, 0.0, 0.0), v(30.0, 0.0, 0.0), v(30.0, 40.0, 0.0), v(0.0, 40.0, -20.0)];
        let total = length(&path);
        for k in 0..50 {
            let (a, b) = (total * k as Real / 61.0, total * (k as Real + 11.0) / 61.0);
            let (c, r) = piece_ball(&path, (a, b), 2.0);
            for i in 0..=20 {
                let p = point_at(&path, a + (b - a) * i as Real / 20.0);
                assert!((p - c).norm() + 2.0 <= r, "range {a}..{b}: {p:?} outside ({c:?}, {r})");
            }
        }
    }

    #[test]
    fn a_path_through_samples_holds_every_sample_and_reaches_the_length() {
        // Samples along an L: 100 mm along x, then 100 mm along y, every 1 mm.
        let samples: Vec<Vec3> =
            (0..=200)
                .map(|i| {
                    if i <= 100 {
                        v(i as Real, 0.0, 0.0)
                    } else {
                        v(100.0, (i - 100) as Real, 0.0)
                    }
                })
                .collect();
        let mut out = [Vec3::zeros(); 8];
        let n = path_through_samples(&samples, 150.0, 0.5, &mut out).unwrap();
        let path = &out[..n];
        assert!(n <= 4, "a corner needs three points: {path:?}");
        // Every sample up to 150 mm along lies within the tolerance of the path.
        for p in &samples[..=150] {
            assert!(distance_to(path, p) <= 0.5, "{p:?} is off {path:?}");
        }
        assert!(length(path) >= 150.0 - 1e-9);
        // Too few points for the corner: no path rather than a short one.
        assert_eq!(path_through_samples(&samples, 150.0, 0.5, &mut out[..2]), None);
        // A path that ends: the robot holds its last sample.
        assert_eq!(path_through_samples(&samples[..50], 150.0, 0.5, &mut out), Some(2));
    }

    #[test]
    fn a_path_must_start_within_its_tolerance_of_the_tcp() {
        let pts = [v(0.0, 0.0, -400.0), v(100.0, 0.0, -400.0)];
        let path = StopPath { points: &pts, tolerance_mm: 1.0 };
        assert!(path_is_valid(&path, &v(50.0, 0.5, -400.0)));
        assert!(!path_is_valid(&path, &v(50.0, 2.0, -400.0)));
        assert!(!path_is_valid(&StopPath { points: &[], tolerance_mm: 1.0 }, &v(0.0, 0.0, -400.0)));
        assert!(!path_is_valid(
            &StopPath { tolerance_mm: Real::NAN, ..path },
            &v(50.0, 0.0, -400.0)
        ));
        assert!(!path_is_valid(&StopPath { tolerance_mm: -1.0, ..path }, &v(50.0, 0.0, -400.0)));
        let bad = [v(0.0, 0.0, -400.0), v(Real::INFINITY, 0.0, -400.0)];
        assert!(!path_is_valid(
            &StopPath { points: &bad, tolerance_mm: 1.0 },
            &v(0.0, 0.0, -400.0)
        ));
    }
}
