//! The two-layer witness cache of thesis 3.1.4, and the plain all-pairs test (SPEC §3).
//!
//! Two robots collide when any box of one intersects any box of the other. The plain test
//! walks the pairs in row-major order and stops at the first intersecting one. The cache
//! exploits temporal coherence in two layers: layer 1 remembers the box pair that collided
//! last time and tests it first; layer 2 remembers, for every box pair, the axis that
//! separated it last time and tries it first. Both only reorder work: whether some pair
//! intersects is always the plain test's answer.
//!
//! Each box's world AABB is computed once per query and each pair first gets an AABB
//! pre-reject (exact-safe: AABBs enclose their boxes), then the 15-axis test.

use crate::geometry::obb::Obb;
use crate::geometry::sat::{
    aabb_half_rounded_up, aabbs_disjoint, separating_axis, separating_axis_hinted, Axis,
};
use crate::geometry::MAX_BOXES;
use crate::math::Real;

/// The rounded-up AABB half-extents of up to [`MAX_BOXES`] boxes, filled in place.
///
/// # Panics
/// When `boxes` holds more than [`MAX_BOXES`] boxes.
#[inline(always)]
fn aabbs(boxes: &[Obb]) -> [[Real; 3]; MAX_BOXES] {
    assert!(boxes.len() <= MAX_BOXES, "at most {MAX_BOXES} boxes per robot, got {}", boxes.len());
    let mut out = [[0.0; 3]; MAX_BOXES];
    for (e, b) in out.iter_mut().zip(boxes) {
        *e = aabb_half_rounded_up(b);
    }
    out
}

/// The first pair `(i, j)` in row-major order with `a[i]` intersecting `b[j]`, or `None`.
///
/// # Panics
/// When either slice holds more than [`MAX_BOXES`] boxes.
pub fn first_intersecting_pair(a: &[Obb], b: &[Obb]) -> Option<(usize, usize)> {
    let (ea, eb) = (aabbs(a), aabbs(b));
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            if !aabbs_disjoint(x, &ea[i], y, &eb[j]) && separating_axis(x, y).is_none() {
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

    /// Some intersecting pair `(i, j)`, or `None`: `None` exactly when
    /// [`first_intersecting_pair`] says `None`. Tries the last colliding pair first (layer 1)
    /// and each pair's last separating axis first (layer 2); when the last colliding pair no
    /// longer collides, the answer is the row-major first one.
    ///
    /// # Panics
    /// When either slice holds more than [`MAX_BOXES`] boxes.
    pub fn first_intersecting_pair(&mut self, a: &[Obb], b: &[Obb]) -> Option<(usize, usize)> {
        let (ea, eb) = (aabbs(a), aabbs(b));
        let collides = |axis: &mut Axis, i: usize, j: usize| -> bool {
            if aabbs_disjoint(&a[i], &ea[i], &b[j], &eb[j]) {
                return false;
            }
            // Layer 2: the pair's last separating axis first; remember the new witness.
            match separating_axis_hinted(&a[i], &b[j], *axis) {
                Some(found) => {
                    *axis = found;
                    false
                }
                None => true,
            }
        };
        // Layer 1: the pair that collided last time.
        let last = self.colliding_pair.map(|(i, j)| (i as usize, j as usize));
        if let Some((i, j)) = last {
            if i < a.len() && j < b.len() && collides(&mut self.axis[i][j], i, j) {
                return Some((i, j));
            }
        }
        for i in 0..a.len() {
            for j in 0..b.len() {
                if Some((i, j)) != last && collides(&mut self.axis[i][j], i, j) {
                    self.colliding_pair = Some((i as u8, j as u8));
                    return Some((i, j));
                }
            }
        }
        self.colliding_pair = None;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sat::obbs_intersect;
    use crate::math::Vec3;
    use nalgebra::Rotation3;

    use crate::test_rng::TestRng as Rng;

    fn link(center: Vec3, euler: Vec3) -> Obb {
        let rot = *Rotation3::from_euler_angles(euler.x, euler.y, euler.z).matrix();
        Obb::new(center, rot, Vec3::new(200.0, 70.0, 17.5))
    }

    /// Boxes drift slowly (random walk in position and angle); the cache must answer
    /// `Some`/`None` exactly as the plain test at every step, and a `Some` it returns must be
    /// an intersecting pair.
    #[test]
    fn cache_answers_as_the_plain_test_on_slowly_moving_boxes() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut hits, mut misses) = (0, 0);
        for run in 0..40 {
            let n_a = 1 + run % 4;
            let n_b = 1 + (run / 4) % 4;
            let mut pos: Vec<Vec3> = (0..n_a + n_b).map(|_| rng.vec(400.0)).collect();
            let mut ang: Vec<Vec3> = (0..n_a + n_b).map(|_| rng.vec(3.0)).collect();
            let mut cache = WitnessCache::new();
            for _ in 0..2_000 {
                for k in 0..pos.len() {
                    let pull = pos[k] * 0.002;
                    pos[k] += rng.vec(3.0) - pull;
                    ang[k] += rng.vec(0.01);
                }
                let boxes: Vec<Obb> = (0..pos.len()).map(|k| link(pos[k], ang[k])).collect();
                let (a, b) = boxes.split_at(n_a);
                let plain = first_intersecting_pair(a, b);
                let cached = cache.first_intersecting_pair(a, b);
                assert_eq!(plain.is_some(), cached.is_some(), "{a:?} {b:?}");
                if let Some((i, j)) = cached {
                    assert!(obbs_intersect(&a[i], &b[j]));
                    hits += 1;
                } else {
                    misses += 1;
                }
            }
        }
        assert!(
            hits > 5_000 && misses > 5_000,
            "both answers exercised: {hits} hits, {misses} misses"
        );
    }

    #[test]
    fn plain_pair_is_row_major_first_and_agrees_with_single_tests() {
        let mut rng = Rng(77);
        for _ in 0..5_000 {
            let a: Vec<Obb> = (0..3).map(|_| link(rng.vec(300.0), rng.vec(3.0))).collect();
            let b: Vec<Obb> = (0..3).map(|_| link(rng.vec(300.0), rng.vec(3.0))).collect();
            let expected =
                (0..9).map(|k| (k / 3, k % 3)).find(|&(i, j)| obbs_intersect(&a[i], &b[j]));
            assert_eq!(first_intersecting_pair(&a, &b), expected);
        }
    }

    #[test]
    fn empty_sets_never_collide() {
        let a = [link(Vec3::zeros(), Vec3::zeros())];
        assert_eq!(first_intersecting_pair(&a, &[]), None);
        assert_eq!(WitnessCache::new().first_intersecting_pair(&[], &a), None);
    }
}
