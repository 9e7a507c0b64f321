//! The displacement sets of the certified labelling (module doc of `certify`): of every
//! sample's whole cell and of its octants and sub-octants, made mirror-symmetric so that a
//! symmetric cell gets symmetric labels (thesis 3.2.8), and which cells are proved
//! unreachable.

use super::OCTANT_SPLITS;
use crate::cspace::guarantee::box_sweeps;
use crate::cspace::label::Inflation;
use crate::cspace::sampler::SampleGrid;
use crate::cspace::symmetry::mirror_cell;
use crate::geometry::Sweep;
use crate::math::{Real, Vec3};
use crate::robot::motion_bound::{cube_box_sweeps, cube_unreachable, reference_point};
use crate::robot::MAX_BOXES;
use crate::robot::{BoxKind, RobotModel};
use rayon::prelude::*;

/// Per sample: whether its whole cell is proved unreachable ([`cube_unreachable`]; only
/// samples whose centre is unreachable are tried). Mirror-symmetric: a sample counts only
/// when its mirror is proved too.
pub(super) fn unreachable_cells(model: &RobotModel, grid: &SampleGrid) -> Vec<bool> {
    let raw: Vec<bool> = (0..grid.cells.len())
        .into_par_iter()
        .map(|s| {
            !grid.reachable[s]
                && cube_unreachable(&model.delta, &grid.sample_center(s), 0.5 * grid.r)
        })
        .collect();
    (0..raw.len())
        .map(|s| raw[s] && grid.index_of(mirror_cell(grid, grid.cells[s])).is_none_or(|m| raw[m]))
        .collect()
}

/// Box index of the mirror image under `y -> -y` (arms 1 and 2 swap).
pub(super) fn mirror_box(model: &RobotModel, j: usize) -> usize {
    match model.box_kind(j) {
        BoxKind::LowerLink(1) | BoxKind::UpperLink(1) => j + 1,
        BoxKind::LowerLink(2) | BoxKind::UpperLink(2) => j - 1,
        _ => j,
    }
}

/// A displacement set holding both `a` and its mirror entry's `b` (given in the mirror's box
/// order): every size the larger of the two. The directions are `a`'s; the mirror's are
/// their mirror images (the cube's axes map to themselves up to sign, and the elbow arcs of
/// arms 1 and 2 swap with equal motor angles, up to rounding: the table merges each label
/// with its mirror's anyway, [`crate::table`]), so each term of `b` lies in the same term of
/// the result.
pub(super) fn mirror_max(
    model: &RobotModel,
    a: &[Sweep; MAX_BOXES],
    b: &[Sweep; MAX_BOXES],
) -> [Sweep; MAX_BOXES] {
    std::array::from_fn(|j| {
        if j < model.box_count() {
            larger(&a[j], &b[mirror_box(model, j)])
        } else {
            a[j]
        }
    })
}

pub(super) fn larger(a: &Sweep, b: &Sweep) -> Sweep {
    // The cubes are axis-aligned in the MCS: half-edge `i` is `(amax) e_i`.
    let cube = std::array::from_fn(|i| {
        let mut w = Vec3::zeros();
        w[i] = a.cube[i].amax().max(b.cube[i].amax());
        w
    });
    let arc = std::array::from_fn(|i| {
        let (la, lb) = (a.arc[i].norm(), b.arc[i].norm());
        if la > 0.0 && lb > la {
            a.arc[i] * (lb / la)
        } else {
            a.arc[i]
        }
    });
    let ends =
        std::array::from_fn(|k| (a.ends[k].0.max(b.ends[k].0), a.ends[k].1.max(b.ends[k].1)));
    // A segment of either is held by the ball of its length (the table's sweeps have none).
    let ball = a.ball.max(b.ball) + a.line.norm().max(b.line.norm());
    Sweep { cube, round: a.round.max(b.round), arc, ends, ball, line: Vec3::zeros() }
}

/// The mirror image of `s` under `y -> -y` (the MCS cube maps to itself).
pub(super) fn mirrored(s: &Sweep) -> Sweep {
    let flip = |v: Vec3| Vec3::new(v.x, -v.y, v.z);
    Sweep { cube: s.cube.map(flip), arc: s.arc.map(flip), line: flip(s.line), ..*s }
}

/// How to build an entry's boxes from its displacement sets: unknown when one is unbounded.
pub(super) fn inflation(s: [Sweep; MAX_BOXES]) -> Inflation {
    if s.iter().any(|w| !w.radius().is_finite()) {
        Inflation::Unknown
    } else {
        Inflation::Swept(s)
    }
}

/// The centre of octant `o` of a cube of centre `c` and half-side `2 d`: offset by `+/- d`
/// along x, y, z for bits 0, 1, 2 of `o`.
pub(super) fn octant_centre(c: &Vec3, o: usize, d: Real) -> Vec3 {
    c + Vec3::from_fn(|a, _| if o >> a & 1 == 1 { d } else { -d })
}

/// How far (mm) a point may lie outside an octant's cube, as computed, and still be counted
/// in it by [`octants_holding`].
///
/// An octant's displacement sets cover every reachable TCP of its cube widened by at least
/// 1e-12 mm (`cube_box_sweeps_with`: half-side `h (1 + 1e-12) + 1e-12`, about the computed
/// centre). For coordinates below [`HOLD_RANGE`] mm the cube's computed bounds are within
/// 6e-14 mm of the widened ones (half a unit in the last place below 1024), and the difference
/// of two coordinates is within 1.2e-13 mm of its exact value: a point whose computed distance
/// from the centre is within `h + HOLD_SLACK` on every axis lies within `h + 6.2e-13` mm, inside
/// the covered cube (`h + 9.4e-13` or more) with 3e-13 mm to spare. A cell's centre, a corner of
/// each of its octants (their centres are `c +/- h`, each rounded by at most 6e-14 mm), passes
/// for all 8; so does an octant's centre for its sub-octants.
pub(super) const HOLD_SLACK: Real = 5e-13;

/// Coordinates (mm, MCS) below which [`HOLD_SLACK`] holds; the workspace lies well within.
pub(super) const HOLD_RANGE: Real = 1024.0;

/// Which octants (bit `o`: centre [`octant_centre`]`(c, o, h)`, half-side `h`) of the cube
/// of centre `c` and half-side `2 h` hold `p`, counted as their displacement sets count it
/// ([`HOLD_SLACK`]); none when a coordinate is outside [`HOLD_RANGE`].
pub(super) fn octants_holding(c: &Vec3, h: Real, p: &Vec3) -> u8 {
    if !(c.amax() < HOLD_RANGE && p.amax() < HOLD_RANGE) {
        return 0;
    }
    (0..8)
        .filter(|&o| (p - octant_centre(c, o, h)).amax() <= h + HOLD_SLACK)
        .fold(0, |m, o| m | 1 << o)
}

/// Per sample: the octants holding its reference point `refs[s]` ([`octants_holding`]).
pub(super) fn reference_octants(grid: &SampleGrid, refs: &[Vec3]) -> Vec<u8> {
    refs.iter()
        .enumerate()
        .map(|(s, p)| octants_holding(&grid.sample_center(s), 0.25 * grid.r, p))
        .collect()
}

/// The box sweeps over the cube of centre `c` and half-side `h` (about `reference`, with
/// [`OCTANT_SPLITS`]), or `None` when the cube is proved to hold no reachable TCP or has no
/// bound: the octants and sub-octants of levels 2 and 3.
pub(super) fn octant_sweeps(
    model: &RobotModel,
    c: &Vec3,
    h: Real,
    reference: &Vec3,
) -> Option<[Sweep; MAX_BOXES]> {
    let vacuous = !model.delta.is_reachable(c) && cube_unreachable(&model.delta, c, h);
    if vacuous {
        return None;
    }
    cube_box_sweeps(model, c, h, reference, OCTANT_SPLITS)
}

/// Every sample's reference point ([`reference_point`]; its centre when none).
pub(super) fn references(model: &RobotModel, grid: &SampleGrid) -> Vec<Vec3> {
    let h = 0.5 * grid.r;
    (0..grid.cells.len())
        .into_par_iter()
        .map(|s| {
            let c = grid.sample_center(s);
            reference_point(&model.delta, &c, h).unwrap_or(c)
        })
        .collect()
}

/// Whole-cell displacement sets of every sample, made mirror-symmetric.
pub(super) fn cell_sweeps(model: &RobotModel, grid: &SampleGrid) -> Vec<[Sweep; MAX_BOXES]> {
    let raw: Vec<_> =
        (0..grid.cells.len()).into_par_iter().map(|s| box_sweeps(model, grid, s)).collect();
    (0..raw.len())
        .map(|s| match grid.index_of(mirror_cell(grid, grid.cells[s])) {
            Some(m) => mirror_max(model, &raw[s], &raw[m]),
            None => raw[s],
        })
        .collect()
}

/// Reference points and enlargements of the 8 octants of every sample (entry `8 s + i`,
/// octant `i` offset by `+/- r/4` along x, y, z for bits 0, 1, 2 of `i`), made
/// mirror-symmetric.
pub(super) fn octants(model: &RobotModel, grid: &SampleGrid) -> (Vec<Vec3>, Vec<Inflation>) {
    let q = 0.25 * grid.r;
    let n = grid.cells.len() * 8;
    let cs: Vec<Vec3> =
        (0..n).map(|e| octant_centre(&grid.sample_center(e / 8), e % 8, q)).collect();
    let refs: Vec<Vec3> =
        cs.par_iter().map(|c| reference_point(&model.delta, c, q).unwrap_or(*c)).collect();
    let raw: Vec<Option<[Sweep; MAX_BOXES]>> =
        (0..n).into_par_iter().map(|e| octant_sweeps(model, &cs[e], q, &refs[e])).collect();
    let inflation = (0..n)
        .map(|e| {
            let mirror =
                grid.index_of(mirror_cell(grid, grid.cells[e / 8])).map(|m| 8 * m + ((e % 8) ^ 2));
            let b = match (raw[e], mirror.and_then(|m| raw[m])) {
                (None, None) => return Inflation::Vacuous,
                (Some(a), Some(b)) => mirror_max(model, &a, &b),
                (Some(a), None) => a,
                (None, Some(b)) => std::array::from_fn(|j| {
                    if j < model.box_count() {
                        mirrored(&b[mirror_box(model, j)])
                    } else {
                        Sweep::ZERO
                    }
                }),
            };
            inflation(b)
        })
        .collect();
    (refs, inflation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// A cube's centre is held by all 8 octants; a point inside an octant, away from the
    /// others, by that one only; a point farther out than the slack by none. Random points of
    /// the cube (and of its faces and edges) are held by at least one octant, and every holding
    /// octant has them within `h + 1e-12` mm of its centre on each axis, inside the cube its
    /// displacement sets cover.
    #[test]
    fn octants_holding_counts_what_the_sweeps_cover() {
        let mut rng = TestRng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..20_000 {
            let c = rng.vec(600.0);
            let h = 0.5 + 40.0 * (rng.unit() + 1.0);
            assert_eq!(octants_holding(&c, h, &c), 0xff, "centre {c:?} h {h}");
            let o = (rng.next_u64() % 8) as usize;
            let inside = octant_centre(&c, o, h) + rng.vec(0.9 * h);
            assert_eq!(octants_holding(&c, h, &inside), 1 << o);
            let mut out = c;
            out[(rng.next_u64() % 3) as usize] += 2.0 * h * (1.0 + 1e-9);
            assert_eq!(octants_holding(&c, h, &out), 0);
            // A point of the cube, snapped to a face, edge or the centre's planes at random.
            let mut p = c + rng.vec(2.0 * h);
            for a in 0..3 {
                match rng.next_u64() % 4 {
                    0 => p[a] = c[a],
                    1 => p[a] = c[a] + 2.0 * h,
                    _ => {}
                }
            }
            let held = octants_holding(&c, h, &p);
            assert_ne!(held, 0, "{p:?} in the cube of {c:?}, h {h}");
            for o in (0..8).filter(|o| held >> o & 1 == 1) {
                assert!(
                    (p - octant_centre(&c, o, h)).amax() <= h + 1e-12,
                    "octant {o} of {c:?} holds {p:?}"
                );
            }
        }
        assert_eq!(
            octants_holding(&Vec3::new(2000.0, 0.0, 0.0), 1.0, &Vec3::new(2000.0, 0.0, 0.0)),
            0
        );
    }
}
