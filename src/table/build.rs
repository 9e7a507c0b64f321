//! Building a table for a two-robot cell: sample, label, make the labels safe, build the
//! chosen linear quadtree (thesis 3.2.1's pipeline, Figure 3.4; SPEC §4, §6), in one go or,
//! for the subdivided table, within a memory bound ([`build_table_bounded`]: the sub-cells
//! found by blocks of the quadtree while it is built, [`crate::table::memory`]).
//!
//! # Safety of the labels
//! The quadtrees treat `Unreachable` as "don't care" and may store it as free, which is safe
//! only where no reachable TCP can be queried. The certified labelling marks a sample
//! `Unreachable` only when its whole cell is proved unreachable
//! ([`crate::robot::motion_bound::cube_unreachable`]), and stores a cell whose centre is
//! unreachable but which holds reachable TCPs as collision. The thesis-style labelling marks
//! cells by their *centre* (2.7 % of random reachable configurations of T1 fall into such a
//! cell), so for it the builder turns every `Unreachable` into `Collision` first.

use crate::cell::Cell;
use crate::cspace::certify::clearance::clearance_counts;
use crate::cspace::certify::{certify_rows, certify_rows_then, SubCellSource};
use crate::cspace::label::label_space_thesis_rows;
use crate::cspace::symmetry::Symmetry;
use crate::cspace::{
    CertifyConfig, Label, LabelledSpace, PairLabels, Progress, Refinement, Rows, SubCells,
    Workspace,
};
use crate::table::memory::{plan_memory, MemoryPlan};
use crate::table::shared6d::SubCellBlocks;
use crate::table::{BuildError, Variant};
use crate::table::{
    Certification, ClearanceTable, Header, Ladder, LinearQuadtree4d, LinearQuadtree5d,
    LinearQuadtree6d, SharedQuadtree6d, Table, TableError,
};
use rayon::prelude::*;
use std::time::Instant;

/// How the samples are labelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Labelling {
    /// Every box enlarged by its own proved displacement bound over the cell: no false
    /// negatives anywhere in a free cell (SPEC §6).
    Certified,
    /// The thesis's global blow-up by `r / sqrt 2` (3.2.7): not a proof.
    ThesisMargin,
}

/// What a build did, for the CLI's summary.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildReport {
    /// Samples per robot (A, B).
    pub samples: (usize, usize),
    /// Two-robot samples.
    pub pairs: usize,
    /// Samples labelled collision (before thesis-style unreachable ones are added).
    pub collisions: usize,
    /// Samples labelled unreachable: certified, whole cell proved unreachable (stored as
    /// "don't care"); thesis-style, centre unreachable (stored as collision).
    pub unreachable: usize,
    /// Whether the cell is mirror-symmetric (only half is stored).
    pub symmetric: bool,
    /// Seconds spent labelling.
    pub label_secs: f64,
    /// Subdivided tables only: the collision pairs cut into sub-cells and the seconds, of
    /// `label_secs`, spent on them (the CLI shows it with its progress).
    pub sub_cells: Option<(usize, f64)>,
    /// Seconds spent building the quadtree. A subdivided build within bounded memory finds
    /// the sub-cells of the blocks ahead while the tree is built, so that this and
    /// `label_secs` overlap: here the tree's own time, less its waits for sub-cells.
    pub build_secs: f64,
}

/// Samples and labels `cell` (two robots) at resolution `k`, then builds `variant`.
///
/// # Errors
/// [`BuildError`]: the cell does not have two robots, `k` is not a power of two or too small
/// for the workspace, sub-cells with the thesis labelling, or a builder refused the labels.
pub fn build_table(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    variant: Variant,
    labelling: Labelling,
    progress: Progress,
) -> Result<(Header, Table, BuildReport), BuildError> {
    let (header, mut tables, report) = build_tables(cell, k, ws, &[variant], labelling, progress)?;
    let table = tables
        .pop()
        .ok_or(BuildError::Table(TableError::BadInput { what: "no table built".into() }))?;
    Ok((header, table, report))
}

/// What [`build_table_bounded`] builds, and within how much memory.
#[derive(Clone, Copy, Debug)]
pub struct BoundedBuild {
    /// Cells per axis of each robot's grid (a power of two).
    pub k: u32,
    /// The sampled workspace.
    pub ws: Workspace,
    /// The table built.
    pub variant: Variant,
    /// How the sample pairs are labelled.
    pub labelling: Labelling,
    /// Progress reports of the labelling.
    pub progress: Progress,
    /// About how many bytes the build may use ([`crate::table::memory`]).
    pub max_memory: u64,
}

/// As [`build_table`] within about `build.max_memory` bytes ([`crate::table::memory`]): the
/// same table; a subdivided table is built streaming its sub-cells by blocks of the quadtree,
/// found as each block is built and dropped after it.
///
/// # Errors
/// As [`build_table`], and [`BuildError::Memory`] when the fixed part of the build alone
/// needs more than `build.max_memory`, before anything big is allocated.
pub fn build_table_bounded(
    cell: &Cell,
    build: &BoundedBuild,
) -> Result<(Header, Table, BuildReport), BuildError> {
    let BoundedBuild { k, ref ws, variant, labelling, progress, max_memory } = *build;
    let plan = memory_plan(cell, k, ws, variant, max_memory)?;
    if variant != Variant::SharedSubdivided || labelling != Labelling::Certified {
        return build_table(cell, k, ws, variant, labelling, progress);
    }
    build_streamed(cell, k, ws, progress, &plan)
}

/// The memory plan of a build of `variant` of `cell` at `k` within `max_memory` bytes.
///
/// # Errors
/// Not two robots, a bad `k`, or [`BuildError::Memory`].
pub fn memory_plan(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    variant: Variant,
    max_memory: u64,
) -> Result<MemoryPlan, BuildError> {
    if cell.robots.len() != 2 {
        return Err(BuildError::NotTwoRobots {
            cell: cell.name.clone(),
            robots: cell.robots.len(),
        });
    }
    let (ga, gb) =
        crate::cspace::label::two_robot_grids(cell, k, ws).map_err(BuildError::Labelling)?;
    plan_memory(ga.cells.len() as u64, gb.cells.len() as u64, k, variant, max_memory)
}

/// The certified subdivided table, its sub-cells found block by block as `plan` says.
fn build_streamed(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    progress: Progress,
    plan: &MemoryPlan,
) -> Result<(Header, Table, BuildReport), BuildError> {
    let start = Instant::now();
    let config = CertifyConfig { refinement: Refinement::SubCells, progress };
    let symmetry = Symmetry::of(cell);
    let built = certify_rows_then(cell, k, ws, &config, Rows::ALL, true, |c, source| {
        let label_secs = start.elapsed().as_secs_f64();
        let no_sub = || {
            BuildError::Table(TableError::BadInput { what: "no sub-cells were labelled".into() })
        };
        let source = source.ok_or_else(no_sub)?;
        let space = &c.space;
        let header = Header::for_cell(space, cell, *ws, Certification::SweptBound);
        let mut blocks = Blocks { source, cache: plan.cache, secs: 0.0 };
        let built = Instant::now();
        let (table, waited) =
            SharedQuadtree6d::build_streamed(space, &mut blocks, plan.block_depth, symmetry)?;
        let (collisions, unreachable) = collisions_and_unreachable(&space.labels);
        let report = BuildReport {
            samples: (space.grid_a.cells.len(), space.grid_b.cells.len()),
            pairs: space.labels.len(),
            collisions,
            unreachable,
            symmetric: symmetry.is_mirrored(),
            label_secs: label_secs + blocks.secs,
            sub_cells: Some((collisions, blocks.secs)),
            build_secs: (built.elapsed() - waited).as_secs_f64(),
        };
        Ok((header, Table::Shared(table), report))
    });
    built.map_err(BuildError::Labelling)?
}

/// How many of `labels` are collisions and how many unreachable, counted in parallel (a
/// billion labels at k = 64).
fn collisions_and_unreachable(labels: &PairLabels) -> (usize, usize) {
    (labels.count(Label::Collision), labels.count(Label::Unreachable))
}

/// The sub-cells of a streamed build's blocks, found in parallel; the sub-octant boxes made
/// for them are dropped after a block once they hold more than `cache` bytes.
struct Blocks<'s, 't> {
    source: &'t mut SubCellSource<'s>,
    cache: u64,
    /// Seconds spent finding sub-cells.
    secs: f64,
}

impl SubCellBlocks for Blocks<'_, '_> {
    fn masks(&mut self, pairs: &[u64], nb: usize) -> Vec<(u64, u64)> {
        let start = Instant::now();
        let source = &*self.source;
        let nb = nb as u64;
        let masks =
            pairs.par_iter().map(|&p| source.masks((p / nb) as usize, (p % nb) as usize)).collect();
        if source.cached_bytes() as u64 > self.cache {
            self.source.clear_cache();
        }
        self.secs += start.elapsed().as_secs_f64();
        masks
    }
}

/// As [`build_table`] for several variants from one labelling (the tables in `variants`'
/// order; `build_secs` is their sum).
///
/// # Errors
/// As [`build_table`].
pub fn build_tables(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    variants: &[Variant],
    labelling: Labelling,
    progress: Progress,
) -> Result<(Header, Vec<Table>, BuildReport), BuildError> {
    let start = Instant::now();
    let subdivide = variants.contains(&Variant::SharedSubdivided);
    let mut labels = label_rows(cell, k, ws, subdivide, labelling, Rows::ALL, progress)?;
    for &variant in variants {
        if let Variant::Clearance(ladder) = variant {
            if labelling != Labelling::Certified {
                return Err(BuildError::ClearanceNeedsCertified);
            }
            let counts =
                clearance_counts(cell, k, ws, &labels.space.labels, ladder.mm(), Rows::ALL)
                    .map_err(BuildError::Labelling)?;
            labels.clearance.push((ladder, counts));
        }
    }
    let label_secs = start.elapsed().as_secs_f64();
    let header = Header::for_cell(&labels.space, cell, *ws, labels.certification);
    let (tables, report) = assemble(labels, Symmetry::of(cell), variants, label_secs)?;
    Ok((header, tables, report))
}

/// The labels of the rows `rows` of A (all of them for a one-shot build, one shard's
/// otherwise), with the sub-cells when `subdivide`: what [`assemble`] builds from.
pub(crate) struct RowLabels {
    /// Grids, margin and the labels of the rows (`space.labels`, row `j` at `j * nb`).
    pub space: LabelledSpace,
    /// The sub-cells of the rows' collision pairs (pairs numbered `ia * nb + ib`).
    pub sub: Option<SubCells>,
    /// Seconds of the labelling spent on the sub-cells.
    pub sub_secs: f64,
    /// What the labelling proves.
    pub certification: Certification,
    /// How it labelled.
    pub labelling: Labelling,
    /// Per clearance ladder asked for: how many of its levels each pair proves (one-shot
    /// builds only).
    pub clearance: Vec<(Ladder, Vec<u8>)>,
}

/// Labels the rows `rows` of A of `cell` (two robots) at `k`, with the sub-cells when
/// `subdivide`.
///
/// # Errors
/// As [`build_table`].
pub(crate) fn label_rows(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    subdivide: bool,
    labelling: Labelling,
    rows: Rows,
    progress: Progress,
) -> Result<RowLabels, BuildError> {
    if cell.robots.len() != 2 {
        return Err(BuildError::NotTwoRobots {
            cell: cell.name.clone(),
            robots: cell.robots.len(),
        });
    }
    let refinement = if subdivide { Refinement::SubCells } else { Refinement::Octants };
    Ok(match labelling {
        Labelling::Certified => {
            let c = certify_rows(cell, k, ws, &CertifyConfig { refinement, progress }, rows)
                .map_err(BuildError::Labelling)?;
            let certification = Certification::SweptBound;
            RowLabels {
                space: c.space,
                sub: c.sub,
                sub_secs: c.sub_secs,
                certification,
                labelling,
                clearance: vec![],
            }
        }
        Labelling::ThesisMargin if subdivide => return Err(BuildError::SubCellsNeedCertified),
        Labelling::ThesisMargin => {
            let space = label_space_thesis_rows(cell, k, ws, rows, progress)
                .map_err(BuildError::Labelling)?;
            let certification = Certification::ThesisBlowUp;
            RowLabels {
                space,
                sub: None,
                sub_secs: 0.0,
                certification,
                labelling,
                clearance: vec![],
            }
        }
    })
}

/// Builds `variants` from the labels of every row (`labels.space.labels` whole): the
/// tables in `variants`' order and the report, with `label_secs` as the labelling's time.
///
/// # Errors
/// A builder refused the labels, or a subdivided table without sub-cells.
pub(crate) fn assemble(
    labels: RowLabels,
    symmetry: Symmetry,
    variants: &[Variant],
    label_secs: f64,
) -> Result<(Vec<Table>, BuildReport), BuildError> {
    let RowLabels { mut space, sub, sub_secs, labelling, clearance, .. } = labels;
    let (collisions, unreachable) = collisions_and_unreachable(&space.labels);
    let mut report = BuildReport {
        samples: (space.grid_a.cells.len(), space.grid_b.cells.len()),
        pairs: space.labels.len(),
        collisions,
        unreachable,
        symmetric: symmetry.is_mirrored(),
        label_secs,
        sub_cells: sub.as_ref().map(|s| (s.pairs.len(), sub_secs)),
        build_secs: 0.0,
    };
    if labelling == Labelling::ThesisMargin {
        space.labels.replace(Label::Unreachable, Label::Collision);
    }
    let start = Instant::now();
    let tables = variants
        .iter()
        .map(|&variant| {
            let table = match variant {
                Variant::D6 => LinearQuadtree6d::build(&space, symmetry).map(Table::D6),
                Variant::D5 => LinearQuadtree5d::build(&space, symmetry).map(Table::D5),
                Variant::D4 { axes, t } => LinearQuadtree4d::build(&space, symmetry, axes, t).map(Table::D4),
                Variant::Shared => SharedQuadtree6d::build(&space, symmetry).map(Table::Shared),
                Variant::SharedSubdivided => match &sub {
                    Some(sub) => SharedQuadtree6d::build_subdivided(&space, sub, symmetry).map(Table::Shared),
                    None => Err(TableError::BadInput { what: "no sub-cells were labelled".into() }),
                },
                Variant::Clearance(ladder) => match clearance.iter().find(|(l, _)| *l == ladder) {
                    Some((_, counts)) => ClearanceTable::build(&space, counts, ladder, symmetry).map(|t| Table::Clearance(Box::new(t))),
                    None => Err(TableError::BadInput {
                        what: "no clearance levels were labelled (clearance tables are built in one run)".into(),
                    }),
                },
            };
            table.map_err(BuildError::Table)
        })
        .collect::<Result<Vec<_>, _>>()?;
    report.build_secs = start.elapsed().as_secs_f64();
    Ok((tables, report))
}
