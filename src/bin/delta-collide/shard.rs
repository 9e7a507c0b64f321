//! `build --shard I/N|auto` and `merge`: a table built in parts, by hand or by a batch
//! scheduler's array job (Slurm, Kubernetes Indexed Jobs, AWS Batch), then merged into the
//! one-shot build's bytes (`delta_collide::table::shard`).

use crate::args::{BuildArgs, MergeArgs, ShardArg};
use crate::files;
use crate::Failure;
use delta_collide::cspace::{PairLabels, Progress, Workspace};
use delta_collide::table::shard::{build_shard_of, merge_shards, read_shard_info, ShardIndex};
use delta_collide::table::{to_bytes, Labelling, TableKind, Variant};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where `--shard auto` finds the shard count when the scheduler does not set one.
pub const SHARDS_VAR: &str = "DELTA_COLLIDE_SHARDS";

/// Shard `(I, N)` from a scheduler's environment, `env` giving each variable's value:
/// - Slurm job arrays: `SLURM_ARRAY_TASK_ID` minus `SLURM_ARRAY_TASK_MIN` (0 when unset) of
///   `SLURM_ARRAY_TASK_COUNT`; a step other than 1 (`SLURM_ARRAY_TASK_STEP`) is refused;
/// - Kubernetes Indexed Jobs: `JOB_COMPLETION_INDEX`;
/// - AWS Batch array jobs: `AWS_BATCH_JOB_ARRAY_INDEX` of `AWS_BATCH_JOB_ARRAY_SIZE`;
///
/// with `N` from `shards` (`--shards`), else [`SHARDS_VAR`], where the scheduler does not
/// give it (Kubernetes; AWS Batch without the size); where it does, they must agree.
///
/// # Errors
/// No scheduler's variable, more than one scheduler's, a value that is not a number, no
/// count, or an index outside `0..N`: each message names the variable and the fix.
pub fn shard_from_env(
    env: &dyn Fn(&str) -> Option<String>,
    shards: Option<u32>,
) -> Result<(u32, u32), String> {
    let number = |name: &str| -> Result<Option<u32>, String> {
        match env(name) {
            None => Ok(None),
            Some(v) => v
                .trim()
                .parse()
                .map(Some)
                .map_err(|_| format!("{name} = {v:?} is not a whole number from 0")),
        }
    };
    let given = match (shards, number(SHARDS_VAR)?) {
        (Some(n), _) => Some((n, "--shards")),
        (None, Some(n)) => Some((n, SHARDS_VAR)),
        (None, None) => None,
    };
    let found: Vec<&str> =
        ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "AWS_BATCH_JOB_ARRAY_INDEX"]
            .into_iter()
            .filter(|v| env(v).is_some())
            .collect();
    let (index, count) = match found[..] {
        [] => {
            return Err("--shard auto: no scheduler's array index in the environment (SLURM_ARRAY_TASK_ID, \
                        JOB_COMPLETION_INDEX or AWS_BATCH_JOB_ARRAY_INDEX); run it as an array job or give \
                        --shard I/N"
                .into())
        }
        ["SLURM_ARRAY_TASK_ID"] => {
            let id = number("SLURM_ARRAY_TASK_ID")?.unwrap_or(0);
            let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            if number("SLURM_ARRAY_TASK_STEP")?.is_some_and(|s| s != 1) {
                return Err("--shard auto: the Slurm array has a step other than 1 (SLURM_ARRAY_TASK_STEP); \
                            submit --array=0-N-1 (or any contiguous range)"
                    .into());
            }
            let count = number("SLURM_ARRAY_TASK_COUNT")?.ok_or(
                "--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; \
                 submit with sbatch --array",
            )?;
            if let Some((n, from)) = given.filter(|(n, _)| *n != count) {
                return Err(format!(
                    "--shard auto: {from} = {n} but the Slurm array has SLURM_ARRAY_TASK_COUNT = {count} tasks"
                ));
            }
            let index = id
                .checked_sub(min)
                .ok_or(format!("--shard auto: SLURM_ARRAY_TASK_ID = {id} is below SLURM_ARRAY_TASK_MIN = {min}"))?;
            (index, count)
        }
        [name] => {
            let index = number(name)?.unwrap_or(0);
            // AWS Batch gives the array's size too; Kubernetes gives the index only.
            let size = if name == "AWS_BATCH_JOB_ARRAY_INDEX" { number("AWS_BATCH_JOB_ARRAY_SIZE")? } else { None };
            let count = match (size, given) {
                (Some(size), Some((n, from))) if n != size => {
                    return Err(format!(
                        "--shard auto: {from} = {n} but the AWS Batch array has AWS_BATCH_JOB_ARRAY_SIZE = {size}"
                    ))
                }
                (Some(size), _) => size,
                (None, Some((n, _))) => n,
                (None, None) => {
                    return Err(format!(
                        "--shard auto: {name} gives the shard's index but not the count; give --shards N or \
                         set {SHARDS_VAR} (the Job's completions, the array job's size)"
                    ))
                }
            };
            (index, count)
        }
        _ => {
            return Err(format!(
                "--shard auto: {} are all set; run under one scheduler or give --shard I/N",
                found.join(" and ")
            ))
        }
    };
    if count == 0 || index >= count {
        return Err(format!(
            "--shard auto: shard index {index} of {count}: the index must be below the count"
        ));
    }
    Ok((index, count))
}

/// `output` with `{index}` and `{count}` replaced by the shard's index and count.
fn shard_path(output: &Path, shard: ShardIndex) -> PathBuf {
    let s = output.to_string_lossy();
    PathBuf::from(
        s.replace("{index}", &shard.index().to_string())
            .replace("{count}", &shard.count().to_string()),
    )
}

/// `build --shard`: labels one shard and writes its file.
pub fn build(args: &BuildArgs, shard: &ShardArg, progress: Progress) -> Result<(), Failure> {
    let (index, count) = match *shard {
        ShardArg::Fixed(i, n) => (i, n),
        ShardArg::Auto => shard_from_env(&|name| std::env::var(name).ok(), args.shards)?,
    };
    let shard = ShardIndex::new(index, count).map_err(|e| e.to_string())?;
    let (cell, k) = (&args.cell, args.k);
    crate::check_memory(cell, k, &Workspace::THESIS, count)?;
    let kind = (args.variant.0, args.t.unwrap_or(0));
    let variant = match (kind.0, args.levels) {
        (TableKind::Clearance, Some(ladder)) => Variant::Clearance(ladder),
        (kind, _) => kind.variant(args.t.unwrap_or(0)),
    };
    let labelling = Labelling::from(args.labelling);
    let (bytes, r) =
        build_shard_of(cell, k, &Workspace::THESIS, variant, labelling, shard, progress)?;
    let output = shard_path(&args.output, shard);
    files::write_file(&output, |w| {
        w.write_all(&bytes).map_err(|e| format!("{}: {e}", output.display()))
    })?;
    println!(
        "cell {} k {k} variant {}: shard {index}/{count}, rows {} of {}, {} pairs, labelling {:.2} s",
        cell.name, kind.0, r.rows, r.samples.0, r.pairs, r.label_secs
    );
    println!("{}: {} bytes", output.display(), bytes.len());
    Ok(())
}

/// `merge --output FILE SHARD...`: the table of all shards, as a one-shot build writes it.
pub fn merge(args: &MergeArgs) -> Result<(), Failure> {
    let names: Vec<String> = args.shards.iter().map(|p| p.display().to_string()).collect();
    let mut read = |name: &str| std::fs::read(name).map_err(|e| e.to_string());
    // The merge holds 2 bits per pair: refuse, before allocating, what the memory cannot hold.
    if let (Some(first), Some(total)) = (names.first(), crate::total_memory()) {
        if let Ok((na, nb)) = read(first)
            .and_then(|b| read_shard_info(&b).map_err(|e| e.to_string()))
            .map(|i| i.samples)
        {
            let needed = PairLabels::bytes_for((na as u64).saturating_mul(nb as u64));
            if needed > total {
                return Err(Failure::Failed(format!(
                    "merging needs about {} of memory for the labels alone ({na} x {nb} pairs, 2 bits \
                     each), more than this machine's {}; merge on a larger machine",
                    crate::gigabytes(needed),
                    crate::gigabytes(total)
                )));
            }
        }
    }
    let (header, table, r) = merge_shards(&names, &mut read).map_err(|e| e.to_string())?;
    let bytes = to_bytes(&table, &header);
    let output = &args.output;
    files::write_file(output, |w| {
        w.write_all(&bytes).map_err(|e| format!("{}: {e}", output.display()))
    })?;
    println!(
        "{} shards: {} x {} samples, {} pairs, {} collision, {} unreachable, symmetric: {}",
        args.shards.len(),
        r.samples.0,
        r.samples.1,
        r.pairs,
        r.collisions,
        r.unreachable,
        r.symmetric
    );
    println!("labelling {:.2} s (the shards' sum), building {:.2} s", r.label_secs, r.build_secs);
    println!("{}: {} ({} bytes on disk)", output.display(), table.name(), bytes.len());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn from(vars: &[(&str, &str)], shards: Option<u32>) -> Result<(u32, u32), String> {
        let env: HashMap<String, String> =
            vars.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        shard_from_env(&|name| env.get(name).cloned(), shards)
    }

    #[test]
    fn slurm_arrays_give_index_and_count_with_the_minimum_subtracted() {
        assert_eq!(
            from(&[("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_COUNT", "5")], None),
            Ok((2, 5))
        );
        let one_based = [
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
        ];
        assert_eq!(from(&one_based, None), Ok((2, 3)));
        assert_eq!(from(&one_based, Some(3)), Ok((2, 3)));
        let e = from(&one_based, Some(4)).unwrap_err();
        assert!(e.contains("--shards = 4") && e.contains("SLURM_ARRAY_TASK_COUNT = 3"), "{e}");
        let e = from(&[("SLURM_ARRAY_TASK_ID", "1")], None).unwrap_err();
        assert!(e.contains("SLURM_ARRAY_TASK_COUNT"), "{e}");
        let stepped = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ];
        assert!(from(&stepped, None).unwrap_err().contains("SLURM_ARRAY_TASK_STEP"));
        let beyond = [
            ("SLURM_ARRAY_TASK_ID", "7"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_MIN", "4"),
        ];
        assert!(from(&beyond, None).unwrap_err().contains("index 3 of 3"));
        let below = [
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
        ];
        assert!(from(&below, None).unwrap_err().contains("below SLURM_ARRAY_TASK_MIN"));
    }

    #[test]
    fn kubernetes_and_aws_take_the_count_from_the_flag_or_the_variable() {
        assert_eq!(from(&[("JOB_COMPLETION_INDEX", "4")], Some(5)), Ok((4, 5)));
        assert_eq!(from(&[("JOB_COMPLETION_INDEX", "0"), (SHARDS_VAR, "2")], None), Ok((0, 2)));
        assert_eq!(
            from(&[("JOB_COMPLETION_INDEX", "1"), (SHARDS_VAR, "2")], Some(3)),
            Ok((1, 3)),
            "the flag wins"
        );
        assert_eq!(from(&[("AWS_BATCH_JOB_ARRAY_INDEX", "9")], Some(10)), Ok((9, 10)));
        let aws = [("AWS_BATCH_JOB_ARRAY_INDEX", "2"), ("AWS_BATCH_JOB_ARRAY_SIZE", "6")];
        assert_eq!(from(&aws, None), Ok((2, 6)));
        assert_eq!(from(&aws, Some(6)), Ok((2, 6)));
        assert!(from(&aws, Some(5)).unwrap_err().contains("AWS_BATCH_JOB_ARRAY_SIZE = 6"));
        let e = from(&[("AWS_BATCH_JOB_ARRAY_INDEX", "9")], None).unwrap_err();
        assert!(e.contains("--shards N") && e.contains(SHARDS_VAR), "{e}");
        assert!(from(&[("JOB_COMPLETION_INDEX", "5")], Some(5))
            .unwrap_err()
            .contains("index 5 of 5"));
        assert!(from(&[("JOB_COMPLETION_INDEX", "x")], Some(5))
            .unwrap_err()
            .contains("JOB_COMPLETION_INDEX"));
        assert!(from(&[("JOB_COMPLETION_INDEX", "1"), (SHARDS_VAR, "two")], None)
            .unwrap_err()
            .contains(SHARDS_VAR));
    }

    #[test]
    fn no_scheduler_or_two_schedulers_is_an_error() {
        assert!(from(&[], Some(3)).unwrap_err().contains("no scheduler"));
        let both = [("JOB_COMPLETION_INDEX", "1"), ("AWS_BATCH_JOB_ARRAY_INDEX", "1")];
        let e = from(&both, Some(3)).unwrap_err();
        assert!(e.contains("JOB_COMPLETION_INDEX and AWS_BATCH_JOB_ARRAY_INDEX"), "{e}");
    }

    #[test]
    fn output_names_take_the_shard_index_and_count() {
        let s = ShardIndex::new(3, 8).unwrap();
        assert_eq!(
            shard_path(Path::new("out/t1-{index}-of-{count}.dcs"), s),
            PathBuf::from("out/t1-3-of-8.dcs")
        );
        assert_eq!(shard_path(Path::new("plain.dcs"), s), PathBuf::from("plain.dcs"));
    }
}
