//! The delta-collide command line: runs the thesis's scenarios, checks CSV files of
//! configurations, and (with tables) builds, inspects and evaluates precomputed tables.
//!
//! The commands and flags are defined in [`args`] (clap); `delta-collide --help` lists them,
//! `delta-collide completions SHELL` and `delta-collide man` generate the completions and the
//! man page from the same definition. Exit codes: 0 done, 1 failed (an unreadable or bad
//! input, a table for another cell, a k too big for the memory), 2 usage error.
//!
//! Output files are replaced only once complete ([`files`]). The pictures (`render`, `quilt`,
//! `eval --plot`, `replay --plot`) are PNG files drawn in-process (modules [`render`],
//! [`quilt`], [`plot`], [`replay_plot`]; shared parts in [`picture`]).

mod args;
mod bundle;
mod clearance;
mod confirm;
mod demo;
mod diagram_plot;
mod eval;
mod files;
mod picture;
mod plot;
mod progress;
mod quilt;
mod render;
mod replay;
mod replay_plot;
mod rows;
mod shard;
mod simulate;
mod stop;

use args::{BuildArgs, CheckArgs, Cli, Command, InspectArgs};
use clap::CommandFactory;
use delta_collide::cell::exact::PairState;
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{PairLabels, Progress, SampleGrid, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_table_bounded, default_max_memory, from_bytes, is_bundle, memory_plan, to_bytes,
    BoundedBuild, BundleChecker, Confirmation, Labelling, Table, TableAnswer, TableChecker,
    TableKind, Variant,
};
use std::io::{BufRead, Write};
use std::path::Path;

/// The scenario file shared with the C harness.
pub(crate) const SCENARIOS: &str = include_str!("../../../c_harness/scenarios.txt");
/// The trajectory cases of the lines of robots (`cells/line4.toml`), kept apart from [`SCENARIOS`].
pub(crate) const LINE_SCENARIOS: &str = include_str!("../../../c_harness/line_scenarios.txt");

/// Why a command did not finish.
pub enum Failure {
    /// Arguments that turned out wrong only once files were read (exit code 2).
    Usage(clap::Error),
    /// Anything else (exit code 1).
    Failed(String),
}

impl From<String> for Failure {
    fn from(m: String) -> Failure {
        Failure::Failed(m)
    }
}

impl From<delta_collide::table::BuildError> for Failure {
    fn from(e: delta_collide::table::BuildError) -> Failure {
        Failure::Failed(e.to_string())
    }
}

impl From<&str> for Failure {
    fn from(m: &str) -> Failure {
        Failure::Failed(m.to_string())
    }
}

impl From<clap::Error> for Failure {
    fn from(e: clap::Error) -> Failure {
        Failure::Usage(e)
    }
}

fn main() {
    let cli = Cli::parse_checked();
    let progress =
        if cli.quiet { Progress::Silent } else { Progress::Rows(progress::labelling_rows) };
    let result = match &cli.command {
        Command::Demo(a) => demo::demo(a),
        Command::Simulate(a) => simulate::simulate(a).map_err(Failure::from),
        Command::Check(a) => check(a),
        Command::Replay(a) => replay::replay(a),
        Command::Build(a) => match &a.shard {
            Some(s) => shard::build(a, s, progress),
            None => build(a, progress),
        },
        Command::Merge(a) => shard::merge(a),
        Command::Inspect(a) => inspect(a),
        Command::Eval(a) => eval::eval(a),
        Command::Render(a) => render::render(a),
        Command::Quilt(a) => quilt::quilt(a),
        Command::Completions { shell } => completions(*shell),
        Command::Man { output } => man(output.as_deref()),
    };
    match result {
        Ok(()) => {}
        Err(Failure::Usage(e)) => e.exit(),
        Err(Failure::Failed(m)) => {
            eprintln!("error: {m}");
            std::process::exit(1);
        }
    }
}

/// `completions SHELL`: the completion script on stdout.
fn completions(shell: clap_complete::Shell) -> Result<(), Failure> {
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "delta-collide", &mut script);
    std::io::stdout().lock().write_all(&script).map_err(|e| format!("stdout: {e}"))?;
    Ok(())
}

/// `man [--output DIR]`: the man page on stdout, or one page per command into `DIR`.
fn man(dir: Option<&Path>) -> Result<(), Failure> {
    let mut cmd = Cli::command();
    cmd.build();
    let page = |c: clap::Command| -> Result<Vec<u8>, String> {
        let mut bytes = Vec::new();
        clap_mangen::Man::new(c).render(&mut bytes).map_err(|e| format!("man page: {e}"))?;
        Ok(bytes)
    };
    let Some(dir) = dir else {
        std::io::stdout().lock().write_all(&page(cmd)?).map_err(|e| format!("stdout: {e}"))?;
        return Ok(());
    };
    let mut pages = vec![("delta-collide.1".to_string(), page(cmd.clone())?)];
    for sub in cmd.get_subcommands() {
        let name = format!("delta-collide-{}", sub.get_name());
        pages.push((format!("{name}.1"), page(sub.clone().name(name))?));
    }
    for (file, bytes) in &pages {
        files::write_file(&dir.join(file), |w| {
            w.write_all(bytes).map_err(|e| format!("{file}: {e}"))
        })?;
    }
    println!("{}: {} man pages", dir.display(), pages.len());
    Ok(())
}

/// `median .. ns, p99.9 .. ns, max .. ns over .. queries` of sorted, non-empty times (ns).
pub(crate) fn spread(ns: &[u64]) -> String {
    let (median, p999, max) = (percentile(ns, 0.5), percentile(ns, 0.999), ns[ns.len() - 1]);
    format!("median {median} ns, p99.9 {p999} ns, max {max} ns over {} queries", ns.len())
}

pub(crate) use delta_collide::sim::percentile;

fn check(args: &CheckArgs) -> Result<(), Failure> {
    let cell = &args.cell;
    let confirmation = args.confirm.map_or(Confirmation::Exact, Confirmation::from);
    let mut table =
        args.table.as_deref().map(|p| load_table_or_bundle(cell, p, confirmation)).transpose()?;
    let mut input = open_input(args.input.as_deref())?;
    let columns = Columns { clearance: args.clearance, pairs: args.pairs, decimals: args.decimals };
    let mut rows = |out: &mut dyn Write| check_rows(&mut input, out, cell, table.as_mut(), columns);
    match &args.output {
        Some(path) => files::write_file(path, |w| rows(w))?,
        None => {
            let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
            rows(&mut out)?;
            out.flush().map_err(|e| format!("stdout: {e}"))?;
        }
    }
    Ok(())
}

/// The rows' source: the file, or stdin.
pub(crate) fn open_input(path: Option<&Path>) -> Result<Box<dyn BufRead>, String> {
    Ok(match path {
        Some(p) => {
            let file = std::fs::File::open(p).map_err(|e| format!("{}: {e}", p.display()))?;
            Box::new(std::io::BufReader::new(file))
        }
        None => Box::new(std::io::stdin().lock()),
    })
}

/// Writes through `rows` to the output file (replaced once complete) or to stdout.
pub(crate) fn write_output(
    output: Option<&Path>,
    mut rows: impl FnMut(&mut dyn Write) -> Result<(), String>,
) -> Result<(), String> {
    match output {
        Some(path) => files::write_file(path, |w| rows(w)),
        None => {
            let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
            rows(&mut out)?;
            out.flush().map_err(|e| format!("stdout: {e}"))
        }
    }
}

/// The columns `check` adds to `reachable,collide`.
#[derive(Clone, Copy)]
struct Columns {
    /// `clearance_mm`: the exact signed clearance, NA when a TCP is unreachable, computed by
    /// the exact model also with a boolean table; with a clearance table, the table's
    /// certified lower bound, `-inf` where it proves no level.
    clearance: bool,
    /// `collide_A_B` per pair that can meet (table mode: its one pair, the table's answer).
    pairs: bool,
    /// Decimals of the numbers written (`rows::real`).
    decimals: Option<u8>,
}

/// Answers every row of `input` on `out`, after the line `reachable,collide` and the
/// header of the `columns` asked for.
///
/// # Errors
/// A row that is not `3 n` numbers (naming its line; the first line may be a header, a line
/// with no number in it), the table's error, or a read or write error.
fn check_rows(
    input: &mut dyn BufRead,
    out: &mut dyn Write,
    cell: &Cell,
    mut table: Option<&mut Loaded>,
    columns: Columns,
) -> Result<(), String> {
    let mut checker = ExactChecker::new(cell.clone());
    let write_err = |e: std::io::Error| format!("writing the answers: {e}");
    let name = |j: usize| &cell.robots[j].name;
    let pair_names: String = checker
        .verdict()
        .pairs
        .iter()
        .map(|p| format!(",collide_{}_{}", name(p.a), name(p.b)))
        .collect();
    let header = format!(
        "reachable,collide{}{}",
        if columns.clearance { ",clearance_mm" } else { "" },
        if columns.pairs { pair_names.as_str() } else { "" }
    );
    writeln!(out, "{header}").map_err(write_err)?;
    rows::for_each_row(input, cell.robots.len(), |line_no, _, tcps| {
        let at_line = |e: delta_collide::cell::QueryError| format!("line {line_no}: {e}");
        let answer = match table.as_deref_mut() {
            Some(t) => t.check(tcps).map_err(at_line)?,
            None => exact_answer(checker.check(tcps).map_err(at_line)?),
        };
        let row = match answer {
            TableAnswer::Unreachable(_) => "0,NA",
            TableAnswer::Collision => "1,1",
            TableAnswer::Free => "1,0",
        };
        out.write_all(row.as_bytes()).map_err(write_err)?;
        let clearance_table = match table.as_deref() {
            Some(Loaded::Table(t)) => Some(t).filter(|t| t.table().as_clearance().is_some()),
            _ => None,
        };
        if let (true, Some(bound)) = (columns.clearance, clearance_table) {
            // A clearance table's certified bound: -inf where it proves no level.
            let mm = bound.clearance_bound(tcps).unwrap_or(f64::NEG_INFINITY);
            match answer {
                TableAnswer::Unreachable(_) => write!(out, ",NA"),
                _ => write!(out, ",{}", rows::real(mm, columns.decimals)),
            }
            .map_err(write_err)?;
        } else if columns.clearance {
            if table.is_some() {
                checker.check(tcps).map_err(at_line)?;
            }
            // NA also where the table's reachability and the exact model's differ.
            match clearance::signed_clearance(&checker)
                .filter(|_| !matches!(answer, TableAnswer::Unreachable(_)))
            {
                Some(d) => write!(out, ",{}", rows::real(d, columns.decimals)),
                None => write!(out, ",NA"),
            }
            .map_err(write_err)?;
        }
        if columns.pairs {
            match table.as_deref() {
                Some(Loaded::Bundle(b)) => {
                    for p in b.pairs() {
                        write_answer(out, p.answer).map_err(write_err)?;
                    }
                }
                t => write_pair_columns(out, &checker, t.is_some().then_some(answer))
                    .map_err(write_err)?,
            }
        }
        out.write_all(b"\n").map_err(write_err)
    })
}

/// One `,0`, `,1` or `,NA` per pair that can meet: the exact checker's last states, or in
/// table mode (`table_answer`, two robots, one pair) the table's answer.
fn write_pair_columns(
    out: &mut dyn Write,
    exact: &ExactChecker,
    table_answer: Option<TableAnswer>,
) -> std::io::Result<()> {
    if let Some(answer) = table_answer {
        return write_answer(out, answer);
    }
    for p in &exact.verdict().pairs {
        out.write_all(match p.state {
            PairState::Collides(..) => b",1",
            PairState::Free => b",0",
            PairState::Undecided => b",NA",
        })?;
    }
    Ok(())
}

/// `,0`, `,1` or `,NA`: one pair's table answer.
fn write_answer(out: &mut dyn Write, answer: TableAnswer) -> std::io::Result<()> {
    out.write_all(match answer {
        TableAnswer::Unreachable(_) => b",NA",
        TableAnswer::Collision => b",1",
        TableAnswer::Free => b",0",
    })
}

/// The exact verdict in the table's terms.
fn exact_answer(v: &delta_collide::cell::CellVerdict) -> TableAnswer {
    match (v.unreachable_mask, v.collides()) {
        (0, true) => TableAnswer::Collision,
        (0, false) => TableAnswer::Free,
        (m, _) => TableAnswer::Unreachable(m),
    }
}

/// What `check --table` answers from: a two-robot cell's table, or a bundle (one table per
/// pair that can meet) for a cell of any number of robots.
pub(crate) enum Loaded {
    Table(Box<TableChecker>),
    Bundle(Box<BundleChecker>),
}

impl Loaded {
    /// The certified lower bound on the clearance of robots `a` and `b` at `[tcp_a, tcp_b]`
    /// from a clearance table or bundle; `None` when nothing is proved.
    pub(crate) fn clearance_bound(&self, a: usize, b: usize, tcps: &[Vec3]) -> Option<f64> {
        match self {
            Loaded::Table(t) => t.clearance_bound(tcps),
            Loaded::Bundle(bundle) => bundle.clearance_bound(a, b, tcps),
        }
    }

    /// Whether every table is a clearance table.
    pub(crate) fn has_clearance(&self) -> bool {
        match self {
            Loaded::Table(t) => t.table().as_clearance().is_some(),
            Loaded::Bundle(b) => b.has_clearance(),
        }
    }

    fn check(&mut self, tcps: &[Vec3]) -> Result<TableAnswer, delta_collide::cell::QueryError> {
        match self {
            Loaded::Table(t) => t.check(tcps),
            Loaded::Bundle(b) => b.check(tcps),
        }
    }
}

pub(crate) fn load_table(cell: &Cell, path: &Path) -> Result<TableChecker, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    TableChecker::new(cell.clone(), &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The table or bundle at `path` for `cell`, answering a COLLISION lookup as `confirmation` says.
pub(crate) fn load_table_or_bundle(
    cell: &Cell,
    path: &Path,
    confirmation: Confirmation,
) -> Result<Loaded, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let at = |e: delta_collide::table::TableError| format!("{}: {e}", path.display());
    if cell.robots.len() == 2 && !is_bundle(&bytes) {
        TableChecker::with_confirmation(cell.clone(), &bytes, confirmation)
            .map(|t| Loaded::Table(Box::new(t)))
            .map_err(at)
    } else {
        BundleChecker::new(cell.clone(), &bytes, confirmation)
            .map(|b| Loaded::Bundle(Box::new(b)))
            .map_err(at)
    }
}

fn build(args: &BuildArgs, progress: Progress) -> Result<(), Failure> {
    let (cell, k, output) = (&args.cell, args.k, &args.output);
    let variant = match (args.variant.0, args.levels) {
        (TableKind::Clearance, Some(ladder)) => Variant::Clearance(ladder),
        (kind, _) => kind.variant(args.t.unwrap_or(0)),
    };
    let labelling = Labelling::from(args.labelling);
    if cell.robots.len() > 2 {
        return bundle::write_bundle(cell, k, variant, labelling, output, progress);
    }
    check_memory(cell, k, &Workspace::THESIS, 1)?;
    let max_memory = args.max_memory.unwrap_or_else(|| {
        // An error of the plan is the build's to report.
        let fixed =
            memory_plan(cell, k, &Workspace::THESIS, variant, u64::MAX).map_or(0, |p| p.fixed);
        default_max_memory(fixed, total_memory())
    });
    let build = BoundedBuild { k, ws: Workspace::THESIS, variant, labelling, progress, max_memory };
    let (header, table, r) = build_table_bounded(cell, &build)?;
    if let (Progress::Rows(_), Some((pairs, secs))) = (progress, r.sub_cells) {
        eprintln!("sub-cells of {pairs} collision pairs: {secs:.2} s");
    }
    let bytes = to_bytes(&table, &header);
    files::write_file(output, |w| {
        w.write_all(&bytes).map_err(|e| format!("{}: {e}", output.display()))
    })?;
    println!(
        "cell {} k {k}: {} x {} samples, {} pairs",
        cell.name, r.samples.0, r.samples.1, r.pairs
    );
    let unreachable = match labelling {
        Labelling::Certified => "cell proved unreachable (don't care)",
        Labelling::ThesisMargin => "unreachable centre (stored as collision)",
    };
    println!(
        "labels ({labelling:?}): {} collision, {} {unreachable}, symmetric: {}",
        r.collisions, r.unreachable, r.symmetric
    );
    println!("labelling {:.2} s, building {:.2} s", r.label_secs, r.build_secs);
    if let Some(q) = table.as_clearance() {
        println!("{}", levels_line("sample pairs", q, &sampled_levels(cell, q)?));
    }
    println!(
        "{}: {} ({} bytes in memory, {} bytes on disk)",
        output.display(),
        describe(&table),
        table.memory_bytes(),
        bytes.len()
    );
    Ok(())
}

/// Refuses, before anything big is allocated, a `k` whose label array (2 bits per pair of
/// sampled grid cells, about `(0.2 k^3)^2`, divided among `shards` shards) needs more memory
/// than the machine has.
///
/// # Errors
/// The bytes needed and the bytes the machine has; or the grid's error for a bad `k`.
pub(crate) fn check_memory(cell: &Cell, k: u32, ws: &Workspace, shards: u32) -> Result<(), String> {
    let (Some(total), [a, b]) = (total_memory(), &cell.robots[..]) else {
        return Ok(()); // unknown memory, or not a two-robot cell (the build says so)
    };
    // Sample counts from a grid of at most 64 cells per axis, scaled by the cell volume.
    let k0 = k.min(64);
    let scale = u64::from(k / k0).pow(3);
    let samples = |delta| SampleGrid::new(ws, k0, delta).map(|g| g.cells.len() as u64 * scale);
    let (na, nb) = (samples(&a.model.delta)?, samples(&b.model.delta)?);
    let rows = na.div_ceil(u64::from(shards.max(1)));
    let needed = PairLabels::bytes_for(rows.saturating_mul(nb));
    if needed > total {
        let per = if shards > 1 { format!(" per shard of {shards}") } else { String::new() };
        return Err(format!(
            "k = {k}: labelling cell {} needs about {} of memory{per} for its labels alone ({rows} x {nb} \
             sample pairs, 2 bits each), more than this machine's {}; use a smaller k (each \
             halving needs 64 times less) or more shards",
            cell.name,
            gigabytes(needed),
            gigabytes(total)
        ));
    }
    Ok(())
}

pub(crate) fn gigabytes(bytes: u64) -> String {
    format!("{:.1} GB", bytes as f64 / 1e9)
}

/// The machine's memory in bytes (`MemTotal` of `/proc/meminfo`), where known.
pub(crate) fn total_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 =
        line.trim_start_matches("MemTotal:").trim().trim_end_matches("kB").trim().parse().ok()?;
    kb.checked_mul(1024)
}

/// Variant, sizes and thesis-formula bytes of a table.
pub(crate) fn describe(table: &Table) -> String {
    match table {
        Table::D6(q) => {
            format!("{}: {} location codes, thesis formula {} bytes", table.name(), q.codes().len(), q.thesis_bytes())
        }
        Table::D5(q) => format!("{}: thesis formula {} bytes", table.name(), q.thesis_bytes()),
        Table::D4(q) => format!("{}: {} slices", table.name(), q.slice_count()),
        Table::Shared(q) => format!("{}: nodes per depth then leaves {:?}", table.name(), q.nodes_per_depth()),
        Table::Clearance(q) => format!(
            "{}: levels {:?} mm; exact tree: nodes per depth then leaves {:?}; level tree at k / {}: {:?}",
            table.name(),
            q.ladder().mm(),
            q.exact_tree().nodes_per_depth(),
            1u32 << q.shift(),
            q.level_tree().nodes_per_depth()
        ),
    }
}

/// `counts` (index 0: no level, then one per level of `table`) as one line.
pub(crate) fn levels_line(
    what: &str,
    table: &delta_collide::table::ClearanceTable,
    counts: &[u64],
) -> String {
    let mut parts = vec![format!("no level {}", counts[0])];
    parts.extend(
        table.ladder().mm().iter().zip(&counts[1..]).map(|(mm, n)| format!(">= {mm} mm {n}")),
    );
    format!("{what} per level: {}", parts.join(", "))
}

/// Sample pairs per level of a clearance table (both TCPs' grid cells sampled; pairs whose
/// cells are proved unreachable count as what is stored).
fn sampled_levels(
    cell: &Cell,
    table: &delta_collide::table::ClearanceTable,
) -> Result<Vec<u64>, String> {
    let k = 1u32 << table.levels();
    let grid = |j: usize| SampleGrid::new(&Workspace::THESIS, k, &cell.robots[j].model.delta);
    let (ga, gb) = (grid(0)?, grid(1)?);
    let mut counts = vec![0u64; table.ladder().len() + 1];
    for a in &ga.cells {
        for b in &gb.cells {
            counts[table.level_count([a[0], a[1], a[2], b[0], b[1], b[2]])] += 1;
        }
    }
    Ok(counts)
}

fn inspect(args: &InspectArgs) -> Result<(), Failure> {
    let path = args.table.display();
    let bytes = std::fs::read(&args.table).map_err(|e| format!("{path}: {e}"))?;
    if is_bundle(&bytes) {
        return bundle::inspect_bundle(&args.table, &bytes);
    }
    let (h, table) = from_bytes(&bytes).map_err(|e| format!("{path}: {e}"))?;
    println!("{path}: {} bytes", bytes.len());
    println!("table: {}", describe(&table));
    println!(
        "k {} (levels {}), r {} mm, symmetric {}",
        1u32 << table.levels(),
        table.levels(),
        h.r,
        table.symmetric()
    );
    println!(
        "cell fingerprint {:#018x}, margin {} mm ({:?})",
        h.cell_fingerprint, h.margin, h.certification
    );
    println!("grid origins A {:?} B {:?}; workspace {:?}", h.origin_a, h.origin_b, h.workspace);
    println!("memory {} bytes", table.memory_bytes());
    match table.as_clearance() {
        Some(q) if q.levels() <= 4 => {
            println!("{}", levels_line("grid cells (all k^6, as stored)", q, &q.cells_per_level()))
        }
        Some(_) => println!("grid cells per level: k > 16, see build's sample pairs per level"),
        None => {}
    }
    Ok(())
}
