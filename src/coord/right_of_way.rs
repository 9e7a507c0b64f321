//! The right of way of a line (coordination, steps 3 and 4 of the module doc): per pair in
//! conflict the winner it wants (forced when one robot cannot yield, else kept or the sooner
//! to arrive), then one ranking of the robots that honours those wants where they form no
//! cycle (Kahn's topological order, the most urgent robot first among those free to go), so
//! that the robot ranked first yields to no one.

use crate::math::Real;
use alloc::vec;
use alloc::vec::Vec;

/// What one pair in conflict asks of the ranking.
#[derive(Clone, Copy, Debug, Default)]
struct Want {
    /// Whether the pair is in conflict this tick.
    conflict: bool,
    /// The robot that cannot yield, if one cannot.
    forced: Option<usize>,
    /// The winner of the last tick.
    previous: Option<usize>,
    /// Programme ticks each robot (`a`, then `b`) needs to reach its hold point.
    ticks: [Real; 2],
}

/// The ranking's inputs and result, in buffers sized once.
#[derive(Clone, Debug)]
pub struct Ranking {
    wants: Vec<Want>,
    /// `order[r]`: the robot ranked `r`.
    order: Vec<usize>,
    /// `rank[j]`: robot `j`'s rank.
    rank: Vec<usize>,
    /// Per robot: whether ranked yet, incoming wanted edges left, urgency.
    placed: Vec<bool>,
    incoming: Vec<u32>,
    urgency: Vec<Real>,
}

impl Ranking {
    /// Buffers for `robots` robots and `pairs` pairs; the ranking is by index.
    pub fn new(robots: usize, pairs: usize) -> Self {
        Ranking {
            wants: vec![Want::default(); pairs],
            order: (0..robots).collect(),
            rank: (0..robots).collect(),
            placed: vec![false; robots],
            incoming: vec![0; robots],
            urgency: vec![Real::INFINITY; robots],
        }
    }

    /// Back to the ranking by index with no pair in conflict (in place: no allocation).
    pub fn reset(&mut self) {
        self.clear();
        for (r, (o, k)) in self.order.iter_mut().zip(self.rank.iter_mut()).enumerate() {
            (*o, *k) = (r, r);
        }
    }

    /// Marks every pair free of conflict.
    pub fn clear(&mut self) {
        self.wants.iter_mut().for_each(|w| w.conflict = false);
    }

    /// Pair `k` is in conflict this tick: the robot that cannot yield (if one), the last
    /// winner, and each robot's programme ticks to its hold point.
    pub fn set_pair(
        &mut self,
        k: usize,
        forced: Option<usize>,
        previous: Option<usize>,
        ticks: [Real; 2],
    ) {
        self.wants[k] = Want { conflict: true, forced, previous, ticks };
    }

    /// The winner pair `k` = `(a, b)` wants: the forced one; else the last winner unless the
    /// other reaches its hold point `hysteresis` ticks sooner; else the sooner (ties: `a`).
    fn wanted(want: &Want, (a, b): (usize, usize), hysteresis: Real) -> usize {
        if let Some(f) = want.forced {
            return f;
        }
        let [ta, tb] = want.ticks;
        match want.previous {
            Some(w) if w == a => {
                if tb + hysteresis < ta {
                    b
                } else {
                    a
                }
            }
            Some(_) => {
                if ta + hysteresis < tb {
                    a
                } else {
                    b
                }
            }
            None if tb < ta => b,
            None => a,
        }
    }

    /// Ranks the robots (module doc). Bounded: one robot placed per round, each round reading
    /// every robot and pair once.
    pub fn rank(&mut self, pairs: &[(usize, usize)], hysteresis: Real) {
        let n = self.order.len();
        self.placed.iter_mut().for_each(|p| *p = false);
        self.incoming.iter_mut().for_each(|c| *c = 0);
        self.urgency.iter_mut().for_each(|u| *u = Real::INFINITY);
        for (want, &(a, b)) in self.wants.iter().zip(pairs) {
            if want.conflict {
                let w = Self::wanted(want, (a, b), hysteresis);
                self.incoming[if w == a { b } else { a }] += 1;
                self.urgency[a] = self.urgency[a].min(want.ticks[0]);
                self.urgency[b] = self.urgency[b].min(want.ticks[1]);
            }
        }
        for r in 0..n {
            // The most urgent robot no unplaced robot is wanted over; when every one is (a
            // cycle of wants), the most urgent of all, whose wants against it are dropped.
            let better = |j: usize, best: Option<usize>| {
                best.is_none_or(|b| self.urgency[j] < self.urgency[b])
            };
            let mut free = None;
            let mut any = None;
            for j in (0..n).filter(|&j| !self.placed[j]) {
                if self.incoming[j] == 0 && better(j, free) {
                    free = Some(j);
                }
                if better(j, any) {
                    any = Some(j);
                }
            }
            let Some(next) = free.or(any) else { break };
            self.placed[next] = true;
            self.order[r] = next;
            self.rank[next] = r;
            for (want, &(a, b)) in self.wants.iter().zip(pairs) {
                if want.conflict && (a == next || b == next) {
                    let w = Self::wanted(want, (a, b), hysteresis);
                    let y = if w == a { b } else { a };
                    if w == next && !self.placed[y] {
                        self.incoming[y] -= 1;
                    }
                }
            }
        }
    }

    /// Robot `j`'s rank (0: first).
    pub fn rank_of(&self, j: usize) -> usize {
        self.rank[j]
    }

    /// Which of `a` and `b` has the right of way: the one ranked first.
    pub fn winner(&self, a: usize, b: usize) -> usize {
        if self.rank[a] < self.rank[b] {
            a
        } else {
            b
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cycle_of_wants_still_ranks_every_robot_once() {
        // Three robots in a row that each want to go before the next: 0 > 1 > 2 > 0.
        let pairs = [(0, 1), (1, 2), (0, 2)];
        let mut r = Ranking::new(3, 3);
        r.set_pair(0, Some(0), None, [1.0, 2.0]);
        r.set_pair(1, Some(1), None, [1.0, 2.0]);
        r.set_pair(2, Some(2), None, [3.0, 0.5]);
        r.rank(&pairs, 0.0);
        let mut ranks: Vec<usize> = (0..3).map(|j| r.rank_of(j)).collect();
        ranks.sort();
        assert_eq!(ranks, [0, 1, 2]);
    }

    #[test]
    fn wants_without_a_cycle_are_all_honoured() {
        let pairs = [(0, 1), (1, 2)];
        let mut r = Ranking::new(3, 2);
        // 1 must go before 0 (forced), 2 arrives sooner than 1.
        r.set_pair(0, Some(1), None, [5.0, 9.0]);
        r.set_pair(1, None, None, [9.0, 1.0]);
        r.rank(&pairs, 0.0);
        assert_eq!(r.winner(0, 1), 1);
        assert_eq!(r.winner(1, 2), 2);
        // The last winner keeps its right of way within the hysteresis.
        r.set_pair(1, None, Some(2), [3.0, 4.0]);
        r.rank(&pairs, 5.0);
        assert_eq!(r.winner(1, 2), 2);
        r.rank(&pairs, 0.5);
        assert_eq!(r.winner(1, 2), 1);
    }
}
