//! The two-layer witness cache of thesis 3.1.4, and the plain all-pairs test.
//!
//! Layer 1 remembers the box pair that collided last time and tests it first; layer 2
//! remembers, for every box pair, the axis that separated it last time and tries it first.
//! Both only reorder work: the answer is always the one of the plain test.

use crate::geometry::obb::Obb;
use crate::geometry::sat::{separating_axis, separating_axis_hinted, Axis};

/// Most boxes one robot model may have (3 lower links, 3 upper links, platform, tool).
pub const MAX_BOXES: usize = 8;

/// The first pair `(i, j)` with `a[i]` intersecting `b[j]`, in row-major order, or `None`.
pub fn first_intersecting_pair(a: &[Obb], b: &[Obb]) -> Option<(usize, usize)> {
    for (i, ba) in a.iter().enumerate() {
        for (j, bb) in b.iter().enumerate() {
            if separating_axis(ba, bb).is_none() {
                return Some((i, j));
            }
        }
    }
    None
}

/// Per robot pair state of the two-layer witness cache (thesis 3.1.4).
#[derive(Clone, Debug)]
pub struct WitnessCache {
    colliding_pair: Option<(u8, u8)>,
    axis: [[Axis; MAX_BOXES]; MAX_BOXES],
}

impl Default for WitnessCache {
    fn default() -> Self {
        WitnessCache { colliding_pair: None, axis: [[Axis(0); MAX_BOXES]; MAX_BOXES] }
    }
}

impl WitnessCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// As [`first_intersecting_pair`] (same answer when any pair collides: some colliding
    /// pair), trying the last colliding pair first and each pair's last separating axis first.
    ///
    /// `a` and `b` hold at most [`MAX_BOXES`] boxes each.
    pub fn first_intersecting_pair(&mut self, a: &[Obb], b: &[Obb]) -> Option<(usize, usize)> {
        if let Some((i, j)) = self.colliding_pair {
            let (i, j) = (i as usize, j as usize);
            if i < a.len() && j < b.len() && self.pair_collides(a, b, i, j) {
                return Some((i, j));
            }
        }
        for i in 0..a.len() {
            for j in 0..b.len() {
                if self.pair_collides(a, b, i, j) {
                    self.colliding_pair = Some((i as u8, j as u8));
                    return Some((i, j));
                }
            }
        }
        self.colliding_pair = None;
        None
    }

    fn pair_collides(&mut self, a: &[Obb], b: &[Obb], i: usize, j: usize) -> bool {
        match separating_axis_hinted(&a[i], &b[j], self.axis[i][j]) {
            Some(axis) => {
                self.axis[i][j] = axis;
                false
            }
            None => true,
        }
    }
}
