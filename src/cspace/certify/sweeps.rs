//! The displacement sets of the certified labelling (module doc of `certify`): of every
//! sample's whole cell and of its octants and sub-octants, made mirror-symmetric so that a
//! symmetric cell gets symmetric labels (thesis 3.2.8), and which cells are proved
//! unreachable.

use crate::cspace::guarantee::{box_sweeps, cube_box_sweeps, cube_unreachable, reference_point};
use crate::cspace::label::Inflation;
use crate::cspace::sampler::SampleGrid;
use crate::cspace::symmetry::mirror_cell;
use crate::robot::MAX_BOXES;
use crate::geometry::Sweep;
use crate::math::{Real, Vec3};
use crate::robot::{BoxKind, RobotModel};
use rayon::prelude::*;
use super::OCTANT_SPLITS;


/// Per sample: whether its whole cell is proved unreachable ([`cube_unreachable`]; only
/// samples whose centre is unreachable are tried). Mirror-symmetric: a sample counts only
/// when its mirror is proved too.
pub(super) fn unreachable_cells(model: &RobotModel, grid: &SampleGrid) -> Vec<bool> {
    let raw: Vec<bool> = (0..grid.cells.len())
        .into_par_iter()
        .map(|s| !grid.reachable[s] && cube_unreachable(&model.delta, &grid.sample_center(s), 0.5 * grid.r))
        .collect();
    (0..raw.len()).map(|s| raw[s] && grid.index_of(mirror_cell(grid, grid.cells[s])).is_none_or(|m| raw[m])).collect()
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
pub(super) fn mirror_max(model: &RobotModel, a: &[Sweep; MAX_BOXES], b: &[Sweep; MAX_BOXES]) -> [Sweep; MAX_BOXES] {
    std::array::from_fn(|j| if j < model.box_count() { larger(&a[j], &b[mirror_box(model, j)]) } else { a[j] })
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
    let ends = std::array::from_fn(|k| (a.ends[k].0.max(b.ends[k].0), a.ends[k].1.max(b.ends[k].1)));
    Sweep { cube, arc, ends, ball: a.ball.max(b.ball) }
}

/// The mirror image of `s` under `y -> -y` (the MCS cube maps to itself).
pub(super) fn mirrored(s: &Sweep) -> Sweep {
    let flip = |v: Vec3| Vec3::new(v.x, -v.y, v.z);
    Sweep { cube: s.cube.map(flip), arc: s.arc.map(flip), ..*s }
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

/// The box sweeps over the cube of centre `c` and half-side `h` (about `reference`, with
/// [`OCTANT_SPLITS`]), or `None` when the cube is proved to hold no reachable TCP or has no
/// bound: the octants and sub-octants of levels 2 and 3.
pub(super) fn octant_sweeps(model: &RobotModel, c: &Vec3, h: Real, reference: &Vec3) -> Option<[Sweep; MAX_BOXES]> {
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
    let raw: Vec<_> = (0..grid.cells.len()).into_par_iter().map(|s| box_sweeps(model, grid, s)).collect();
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
    let cs: Vec<Vec3> = (0..n).map(|e| octant_centre(&grid.sample_center(e / 8), e % 8, q)).collect();
    let refs: Vec<Vec3> = cs.par_iter().map(|c| reference_point(&model.delta, c, q).unwrap_or(*c)).collect();
    let raw: Vec<Option<[Sweep; MAX_BOXES]>> =
        (0..n).into_par_iter().map(|e| octant_sweeps(model, &cs[e], q, &refs[e])).collect();
    let inflation = (0..n)
        .map(|e| {
            let mirror = grid.index_of(mirror_cell(grid, grid.cells[e / 8])).map(|m| 8 * m + ((e % 8) ^ 2));
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
