//! `build` and `inspect` for a cell of more than two robots: one table per pair cell that a
//! pair that can meet needs, all in one bundle file (`delta_collide::table::bundle`).

use crate::{check_memory, describe, files, Failure};
use delta_collide::cell::Cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::bundle::{build_bundle as build_all, describe_pair, plan};
use delta_collide::table::{bundle_from_bytes, Labelling, Variant};
use std::io::Write;
use std::path::Path;

/// Builds every table `cell`'s pairs that can meet need, once per pair cell, into the bundle
/// `output`, and prints what each table and pair got.
///
/// # Errors
/// A build's error (naming the pair cell), or writing the file.
pub(crate) fn write_bundle(
    cell: &Cell,
    k: u32,
    variant: Variant,
    labelling: Labelling,
    output: &Path,
    progress: Progress,
) -> Result<(), Failure> {
    let (pair_cells, pairs) = plan(cell);
    println!(
        "cell {}: {} robots, {} pairs that can meet, {} tables (one per relative placement)",
        cell.name,
        cell.robots.len(),
        pairs.len(),
        pair_cells.len()
    );
    for pc in &pair_cells {
        check_memory(pc, k, &Workspace::THESIS, 1)?;
    }
    let built = build_all(cell, k, &Workspace::THESIS, variant, labelling, progress)?;
    for (i, (_, table, r, bytes)) in built.tables.iter().enumerate() {
        let first = pairs.iter().find(|p| p.table == i).expect("every table serves a pair");
        println!(
            "table {i} for {}: k {k}, {} x {} samples, {} collision labels, symmetric {}, labelling {:.2} s, \
             building {:.2} s, {}, {} bytes",
            describe_pair(cell, first.a, first.b),
            r.samples.0,
            r.samples.1,
            r.collisions,
            r.symmetric,
            r.label_secs,
            r.build_secs,
            describe(table),
            bytes.len()
        );
    }
    for p in &pairs {
        println!("pair {}: table {}", describe_pair(cell, p.a, p.b), p.table);
    }
    let bytes = &built.bytes;
    files::write_file(output, |w| {
        w.write_all(bytes).map_err(|e| format!("{}: {e}", output.display()))
    })?;
    let separate: usize = pairs.iter().map(|p| built.tables[p.table].3.len()).sum();
    println!(
        "{}: bundle of {} tables, {} bytes ({} bytes as one table file per pair)",
        output.display(),
        built.tables.len(),
        bytes.len(),
        separate
    );
    Ok(())
}

/// Prints a bundle: its cell, each table (kind, size, where the second robot of its pair cell
/// stands) and which table each pair uses.
///
/// # Errors
/// The bundle's [`delta_collide::table::TableError`], naming the file.
pub(crate) fn inspect_bundle(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    let b = bundle_from_bytes(bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{}: bundle, {} bytes", path.display(), bytes.len());
    println!(
        "built for cell {:#018x} of {} robots: {} tables, {} pairs that can meet",
        b.cell_fingerprint,
        b.robots,
        b.tables.len(),
        b.pairs.len()
    );
    for (i, (h, t)) in b.tables.iter().enumerate() {
        // A pair cell's last four parameters: its second robot's alpha and translation.
        let p = &h.cell_parameters[h.cell_parameters.len().saturating_sub(4)..];
        let at = match p {
            [alpha, x, y, z] => {
                format!("second robot at ({x}, {y}, {z}) mm, alpha {alpha} rad from the first")
            }
            _ => "placement not recorded".to_string(),
        };
        println!(
            "table {i}: pair cell {:#018x}, {at}; k {}, {}; {} bytes in memory",
            h.cell_fingerprint,
            1u32 << t.levels(),
            describe(t),
            t.memory_bytes()
        );
    }
    for p in &b.pairs {
        println!("pair robots {}-{}: table {}", p.a, p.b, p.table);
    }
    Ok(())
}
