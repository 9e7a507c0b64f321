//! `build` and `inspect` for a cell of more than two robots: one table per pair cell that a
//! pair that can meet needs, all in one bundle file (`delta_collide::table::bundle`).

use crate::{check_memory, describe, files, Failure};
use delta_collide::cell::Cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::table::bundle::{describe_pair, plan};
use delta_collide::table::{build_table, bundle_from_bytes, bundle_to_bytes, to_bytes, Labelling, Variant};
use std::io::Write;
use std::path::Path;

/// Builds every table `cell`'s pairs that can meet need, once per pair cell, into the bundle
/// `output`, and prints what each table and pair got.
///
/// # Errors
/// A build's error (naming the pair cell), or writing the file.
pub(crate) fn build_bundle(
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
    let mut tables = Vec::with_capacity(pair_cells.len());
    for (i, pc) in pair_cells.iter().enumerate() {
        let first = pairs.iter().find(|p| p.table == i).expect("every pair cell comes from a pair");
        let what = describe_pair(cell, first.a, first.b);
        check_memory(pc, k, &Workspace::THESIS, 1)?;
        let (header, table, r) = build_table(pc, k, &Workspace::THESIS, variant, labelling, progress)
            .map_err(|e| format!("table {i} for {what}: {e}"))?;
        let bytes = to_bytes(&table, &header);
        println!(
            "table {i} for {what}: k {k}, {} x {} samples, {} collision labels, symmetric {}, labelling {:.2} s, \
             building {:.2} s, {}, {} bytes",
            r.samples.0,
            r.samples.1,
            r.collisions,
            r.symmetric,
            r.label_secs,
            r.build_secs,
            describe(&table),
            bytes.len()
        );
        tables.push(bytes);
    }
    for p in &pairs {
        println!("pair {}: table {}", describe_pair(cell, p.a, p.b), p.table);
    }
    let bytes = bundle_to_bytes(cell.fingerprint(), cell.robots.len(), &tables, &pairs)
        .map_err(|e| format!("{}: {e}", output.display()))?;
    files::write_file(output, |w| w.write_all(&bytes).map_err(|e| format!("{}: {e}", output.display())))?;
    let separate: usize = pairs.iter().map(|p| tables[p.table].len()).sum();
    println!(
        "{}: bundle of {} tables, {} bytes ({} bytes as one table file per pair)",
        output.display(),
        tables.len(),
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
            [alpha, x, y, z] => format!("second robot at ({x}, {y}, {z}) mm, alpha {alpha} rad from the first"),
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
