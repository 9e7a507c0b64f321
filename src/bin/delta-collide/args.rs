//! The command line's definition (clap derive): every command and flag with its meaning,
//! unit and default, and the parsers that check values when the arguments are read. The
//! help, the shell completions and the man page are all generated from it.
//!
//! A value that is wrong on its own (a k the table format cannot hold, a coordinate that is
//! not three numbers, an unknown cell) is refused here with exit code 2; flags that
//! contradict each other are refused by [`Cli::parse_checked`], also with 2.

use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use delta_collide::cell::reference::{reference_cell, REFERENCE_CELL_FILES};
use delta_collide::cell::Cell;
use delta_collide::math::Vec3;
use delta_collide::table::code::MAX_LEVELS;
use delta_collide::table::{Confirmation, Labelling, Ladder, TableKind};
use std::path::PathBuf;
use std::sync::LazyLock;

/// `--version`: the crate's version and the table format version that `build` writes.
static VERSION_TEXT: LazyLock<String> = LazyLock::new(|| {
    format!(
        "{} (writes table format version {})",
        env!("CARGO_PKG_VERSION"),
        delta_collide::table::format::VERSION
    )
});

/// The largest width or height of a picture (pixels).
const MAX_SIDE: u32 = 8192;

/// Longest piece of a user's input that an error message echoes.
pub const ECHO_CHARS: usize = 40;

/// `s` cut to [`ECHO_CHARS`] characters, with "..." when it was longer.
pub fn clip(s: &str) -> String {
    match s.char_indices().nth(ECHO_CHARS) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// Collision detection for Delta robots: exact checks, precomputed tables and their pictures.
#[derive(Parser, Debug)]
#[command(name = "delta-collide", version = VERSION_TEXT.as_str(), subcommand_required = true)]
#[command(arg_required_else_help = true, disable_help_subcommand = true)]
pub struct Cli {
    /// Draw no progress bars (they go to stderr only, and only when it is a terminal)
    #[arg(short, long, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run the practical and collision scenarios: exact check and protective verdict
    ///
    /// Runs the scenarios of c_harness/scenarios.txt for the chosen cells and prints the
    /// first collision tick and the per-tick query times of the exact check (SAT and
    /// SAT-cache); then, along the same runs, the protective verdict with the cell's stopping
    /// models: first WARN and STOP tick, WARN and STOP counts, and whether a stop simulated
    /// from the first STOP (reaction, then braking along the path) stays clear, checked with
    /// the exact model every 0.1 ms.
    Demo(DemoArgs),
    /// Run the closed-loop benchmark of coordination on seeded programmes
    ///
    /// Draws dense pick-and-place programmes for the cell (seeded; timed by an offline
    /// interlock), then runs them tick by tick: the controller applies the coordination's
    /// overrides (or the speed limits, or a zone interlock, or nothing: --mode), the
    /// protective verdict decides, a STOP is simulated (reaction, then braking along the
    /// path). Every tick and every 0.2 ms of every stop is checked for contact with the exact
    /// model. Prints per run the throughput kept, STOP events, deadlocks, contacts and the
    /// per-tick times beside the exact check's in the same loop.
    Simulate(SimulateArgs),
    /// Check configurations from a CSV file, exactly or with a table
    ///
    /// Reads rows x,y,z,x2,y2,z2,... (one TCP per robot, each in its own MCS, mm; a header
    /// naming x,y,z,x2,y2,z2,... picks those columns and ignores others, such as tick; without
    /// one, 3 numbers per robot) and writes one line `reachable,collide` per row;
    /// collide is NA when a TCP is unreachable. A malformed row is an error naming its line.
    /// --clearance adds the column clearance_mm: the exact signed clearance of the cell (mm;
    /// the gap when apart, minus the penetration depth when intersecting; SPEC section 8);
    /// with a clearance table, the table's certified lower bound (-inf: none proved).
    Check(CheckArgs),
    /// Replay a trajectory through the protective verdict
    ///
    /// Reads one row tick,x,y,z,x2,y2,z2,... per controller tick (one TCP per robot, each in
    /// its own MCS, mm; columns found by the header's names, others ignored; without a header,
    /// 3 numbers per robot and ticks counted from 0), with the cell's tick_ms and stopping
    /// models, and writes per tick
    /// `tick,verdict,clearance_mm,status,protective_mm_<robot>...,speed_limit_mm_s_<robot>...`
    /// (verdict free, warn or stop; SPEC section 8). The tick column is the controller's cycle
    /// counter: a skipped tick bounds the speeds over its real interval, a repeated tick with
    /// the same TCPs repeats its row, and a tick that goes back, repeats with other TCPs or
    /// comes more than 4 ticks later is stop (status `timing ...`). --plot draws the clearance,
    /// the protective distances and the verdict along the run.
    Replay(ReplayArgs),
    /// Sample, label and build a table file
    ///
    /// Samples both robots' workspaces on a k x k x k grid, labels every pair of grid cells
    /// (certified per-cell bounds by default) and writes the table. Memory grows as k^6: a k
    /// whose labels do not fit in the machine's memory is refused before anything is
    /// allocated. --shard I/N labels only part of the grid (every variant shards) into a shard
    /// file for merge; --shard auto takes I and N from a Slurm array, a Kubernetes Indexed
    /// Job or an AWS Batch array job (docs/CLUSTER.md).
    Build(BuildArgs),
    /// Merge a sharded build's files into its table
    ///
    /// Reads every shard file of one `build --shard I/N` run, in any order, and writes the
    /// table: byte for byte the one a one-shot build writes. A missing, repeated, truncated or
    /// corrupt shard, or one of another cell, k, variant, labelling or N, is an error naming
    /// the file. Needs the memory of a one-shot build (2 bits per pair of samples).
    Merge(MergeArgs),
    /// Print what a table file holds
    Inspect(InspectArgs),
    /// Compare a table with the exact model
    ///
    /// Compares the table with the exact physical model (margin 0) on the cell's scenarios and
    /// on N random reachable configurations: TP, TN, FP, FN, accuracy, query times; then, per
    /// scenario, the ticks a COLLISION lookup is confirmed by the exact check and the per-tick
    /// times of table mode with confirmation against exact mode, in the same run. --plot
    /// draws, per scenario and tick, the distance between the robots' boxes and the labels
    /// reported by the table and by the exact model.
    Eval(EvalArgs),
    /// Draw the cell at one configuration (PNG)
    ///
    /// Top and side view of the cell at one configuration: every box of the model, the
    /// colliding ones in red.
    Render(RenderArgs),
    /// Draw a table's 2-D slices (PNG)
    ///
    /// The table's 2-D slices as in the thesis's Figures 3.16-3.17: --axes yy puts yy'-slices
    /// in a quilt over (z, z'), zz puts zz'-slices in a quilt over (y, y'), xx puts xx'-slices
    /// over (z, z'). With --a, A's grid cell is fixed and each panel is an x'y'-slice of B's
    /// grid at one depth z'. Black: collision, white: free, orange: a cell proved unreachable
    /// (don't care), grey: outside the sampled grid.
    Quilt(QuiltArgs),
    /// Print a shell completion script
    Completions {
        /// The shell
        #[arg(value_parser = choice::<clap_complete::Shell>())]
        shell: clap_complete::Shell,
    },
    /// Print the man page(s)
    ///
    /// Prints the man page on stdout, or with --output writes one page per command into a
    /// directory.
    Man {
        /// Write delta-collide.1 and delta-collide-COMMAND.1 into this directory instead
        #[arg(long, value_name = "DIR")]
        output: Option<PathBuf>,
    },
}

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// The cell: T1, T2, T3, all (the three) or a .toml file
    #[arg(long, value_name = "CELL", default_value = "T1", value_parser = clipped(parse_cells))]
    pub cell: Cells,
}

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The cell: T1, T2, T3 or a .toml file
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// Answer from this table (built for the same cell; for more than two robots, the bundle
    /// build writes: one lookup per pair that can meet) instead of the exact check
    #[arg(long, value_name = "FILE.dct")]
    pub table: Option<PathBuf>,
    /// With --table: what a row the table says collides gets (exact: the exact check's
    /// answer, so the output is that of check without --table) [default: exact]
    #[arg(long, value_name = "CONFIRM", value_parser = choice::<ConfirmArg>())]
    pub confirm: Option<ConfirmArg>,
    /// Read the rows from this file [default: stdin]
    #[arg(long, value_name = "FILE.csv")]
    pub input: Option<PathBuf>,
    /// Write the answers to this file, replaced only once complete [default: stdout]
    #[arg(long, value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
    /// Add the column clearance_mm: the exact signed clearance (mm, negative when the boxes
    /// intersect; NA when a TCP is unreachable), also with --table; with a clearance table
    /// (build --variant clearance), the table's certified lower bound (-inf: no level)
    #[arg(long)]
    pub clearance: bool,
    /// Add one column per robot pair that can meet, collide_A_B (A, B the robots' names):
    /// 1 when that pair collides, 0 when not, NA when either TCP is unreachable
    #[arg(long)]
    pub pairs: bool,
    /// Write each number with N decimals [default: the shortest text that reads back as the
    /// same double]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=17))]
    pub decimals: Option<u8>,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The cell: T1, T2, T3 or a .toml file (its tick_ms and stop keys apply)
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// Runs, each with its own programmes
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub runs: u32,
    /// Seed of the first run's programmes (run i uses seed + i)
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Programme ticks of cycling per robot before it parks
    #[arg(long, value_name = "TICKS", default_value_t = 6000)]
    pub ticks: u32,
    /// What the override comes from: coordinate, limits, interlock, free, or all
    #[arg(long, value_name = "MODE", default_value = "all")]
    pub mode: String,
    /// Give the protective verdict each robot's programme ahead as its stop path
    #[arg(long)]
    pub paths: bool,
    /// The clearance the coordination's diagram keeps between programme samples (mm)
    #[arg(long, value_name = "MM", default_value_t = 40.0)]
    pub clearance_mm: f64,
    /// Who has the right of way at a conflict: the robot programmed there first (the
    /// programmes share one clock) or the one that arrives first
    #[arg(long, value_name = "RULE", default_value = "arrival")]
    #[arg(value_parser = ["programmed", "arrival"])]
    pub right_of_way: String,
    /// Clearance the programmes' offline interlock keeps, executed as programmed (mm)
    #[arg(long, value_name = "MM", default_value_t = 10.0)]
    pub gap_mm: f64,
    /// Units of work the protective verdict may spend per tick along the stop paths
    #[arg(long, value_name = "UNITS", default_value_t = delta_collide::cell::protective::DEFAULT_PATH_WORK)]
    pub path_work: u32,
    /// Draw the first run's coordination diagram of the first robot pair (the last mode
    /// run) to this PNG file
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Write the first run of the last mode, tick by tick, to this CSV file: each robot's
    /// progress, override followed, coordination's override and holder, the verdict, each
    /// speed limit and the exact clearance
    #[arg(long, value_name = "FILE.csv")]
    pub trace: Option<PathBuf>,
}

/// Arguments of `replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The cell: T1, T2, T3 or a .toml file (its tick_ms and stop keys apply)
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// Read the rows, one per tick, from this file [default: stdin]
    #[arg(long, value_name = "FILE.csv")]
    pub input: Option<PathBuf>,
    /// Write the verdicts to this file, replaced only once complete [default: stdout]
    #[arg(long, value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
    /// WARN when a stop is proved with less than this to spare (mm)
    #[arg(long, value_name = "MM", default_value_t = 10.0)]
    pub warn_mm: f64,
    /// Give each robot's stop path as the recorded rows ahead, this far along (mm): a
    /// path-maintaining stop that follows the recorded path (SPEC 8) [default: no paths]
    #[arg(long, value_name = "MM", value_parser = clipped(positive_mm))]
    pub stop_path_mm: Option<f64>,
    /// How far the TCP may leave its stop path (mm; only with --stop-path-mm)
    #[arg(long, value_name = "MM", default_value_t = 0.5, requires = "stop_path_mm")]
    #[arg(value_parser = clipped(non_negative_mm))]
    pub path_tolerance_mm: f64,
    /// Add one column per robot pair that can meet, clearance_mm_A_B (A, B the robots'
    /// names): that pair's exact signed clearance (mm), NA when the tick's status is not ok
    #[arg(long)]
    pub pairs: bool,
    /// Write each number with N decimals [default: the shortest text that reads back as the
    /// same double]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=17))]
    pub decimals: Option<u8>,
    /// Table mode: a tick this clearance table (build --variant clearance, same cell; for a
    /// line, its bundle) proves FREE is answered by its lookup alone; pairs it proves apart
    /// skip the exact protective check, which decides the others; the share answered by the
    /// lookups goes to stderr [default: exact mode]
    #[arg(long, value_name = "FILE.dct")]
    pub table: Option<PathBuf>,
    /// Also draw the clearance, each robot's protective distance and the verdict per tick
    /// into this PNG file
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Width of the plot in pixels, 500 to 8192 (only with --plot)
    #[arg(long, value_name = "W", default_value_t = 1400, requires = "plot")]
    #[arg(value_parser = clipped(pixels(500)))]
    pub width: u32,
    /// Height of the plot in pixels, 300 to 8192 (only with --plot)
    #[arg(long, value_name = "H", default_value_t = 600, requires = "plot")]
    #[arg(value_parser = clipped(pixels(300)))]
    pub height: u32,
}

#[derive(Args, Debug)]
pub struct BuildArgs {
    /// The cell: T1, T2, T3 or a .toml file
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// The table file to write, replaced only once complete; for a cell of more than two
    /// robots, a bundle: one table per relative placement of the pairs that can meet
    #[arg(long, value_name = "FILE.dct")]
    pub output: PathBuf,
    /// Grid cells per axis and robot: a power of two from 2 to 256 (the table format's limit)
    #[arg(long, value_name = "K", default_value_t = 32, value_parser = clipped(parse_k))]
    pub k: u32,
    /// The table's kind
    #[arg(long, value_name = "VARIANT", default_value = "6d")]
    #[arg(value_parser = choice::<KindArg>())]
    pub variant: KindArg,
    /// Similarity threshold of the 4-D table's slice groups, in differing grid cells
    /// (0: lossless; only with --variant 4d-yy or 4d-zz) [default: 0]
    #[arg(long, value_name = "T", value_parser = clipped(parse_number::<u32>))]
    pub t: Option<u32>,
    /// The clearance levels a clearance table proves per grid cell, increasing, in mm (1 to
    /// 16 of them; only with --variant clearance) [default: 0,5,10,20,40,80,160]
    #[arg(long, value_name = "MM,MM,...", value_parser = clipped(parse_ladder))]
    pub levels: Option<Ladder>,
    /// How the samples are labelled
    #[arg(long, value_name = "LABELLING", default_value = "certified")]
    #[arg(value_parser = choice::<LabellingArg>())]
    pub labelling: LabellingArg,
    /// Label only shard I of N (I from 0 to N-1; every variant shards) into a shard file for
    /// merge, or `auto`: I and N from SLURM_ARRAY_TASK_ID/_COUNT/_MIN, JOB_COMPLETION_INDEX
    /// (Kubernetes) or AWS_BATCH_JOB_ARRAY_INDEX/_SIZE. In --output, {index} and {count}
    /// become I and N
    #[arg(long, value_name = "I/N|auto", value_parser = clipped(parse_shard))]
    pub shard: Option<ShardArg>,
    /// With --shard auto: the count N where the scheduler gives only the index (Kubernetes:
    /// the Job's completions) [default: env DELTA_COLLIDE_SHARDS]
    #[arg(long, value_name = "N", requires = "shard", value_parser = clipped(parse_number::<u32>))]
    pub shards: Option<u32>,
    /// The memory the build may use, in bytes or with K, M, G or T (powers of 1024), e.g. 8G: a
    /// shared-sub build finds its sub-cells by blocks of the quadtree sized to fit (the same
    /// table); a build whose fixed part (boxes, 2 bits of label per sample pair) does not fit
    /// is refused before it starts (one-shot builds; docs/CLUSTER.md) [default: 7G, or the
    /// machine's memory when it has less or when the fixed part alone needs more]
    #[arg(long, value_name = "BYTES", conflicts_with = "shard", value_parser = clipped(parse_bytes))]
    pub max_memory: Option<u64>,
}

/// Which part of a build `build --shard` does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    /// Shard I of N, given.
    Fixed(u32, u32),
    /// From the scheduler's environment.
    Auto,
}

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The table file to write, replaced only once complete
    #[arg(long, value_name = "FILE.dct")]
    pub output: PathBuf,
    /// Every shard file of the build, in any order
    #[arg(value_name = "SHARD", required = true)]
    pub shards: Vec<PathBuf>,
}

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// The table file, or a bundle (its tables and which table each pair uses)
    #[arg(value_name = "FILE.dct")]
    pub table: PathBuf,
}

#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The cell: T1, T2, T3 or a .toml file
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// The table file, built for the same cell; or, for a line, its bundle
    #[arg(long, value_name = "FILE.dct")]
    pub table: PathBuf,
    /// Random reachable configurations to compare
    #[arg(long, value_name = "N", default_value_t = 1_000_000, value_parser = clipped(parse_number::<u64>))]
    pub random: u64,
    /// Seed of the random configurations (xorshift64*; not 0)
    #[arg(long, value_name = "S", default_value_t = 1, value_parser = clipped(parse_seed))]
    pub seed: u64,
    /// A line (more than two robots, or a bundle): add one line per robot pair that can meet
    #[arg(long)]
    pub pairs: bool,
    /// Draw the scenarios' box distances and labels into this PNG file (two robots)
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Width of the plot in pixels, 500 to 8192 (only with --plot)
    #[arg(long, value_name = "W", default_value_t = 1400, requires = "plot")]
    #[arg(value_parser = clipped(pixels(500)))]
    pub width: u32,
    /// Height of the plot in pixels, 400 to 8192 (only with --plot)
    #[arg(long, value_name = "H", default_value_t = 900, requires = "plot")]
    #[arg(value_parser = clipped(pixels(400)))]
    pub height: u32,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The cell: T1, T2, T3 or a .toml file
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// A robot's TCP as x,y,z in its own MCS (mm), e.g. 150,0,-450; once per robot, in order
    #[arg(long, value_name = "X,Y,Z", required = true, allow_hyphen_values = true)]
    #[arg(value_parser = clipped(parse_xyz))]
    pub tcp: Vec<Vec3>,
    /// The PNG file to write, replaced only once complete
    #[arg(long, value_name = "FILE.png", default_value = "render.png")]
    pub output: PathBuf,
    /// Width of the picture in pixels, 700 to 8192
    #[arg(long, value_name = "W", default_value_t = 1400, value_parser = clipped(pixels(700)))]
    pub width: u32,
    /// Height of the picture in pixels, 350 to 8192
    #[arg(long, value_name = "H", default_value_t = 700, value_parser = clipped(pixels(350)))]
    pub height: u32,
}

#[derive(Args, Debug)]
pub struct QuiltArgs {
    /// The cell: T1, T2, T3 or a .toml file
    #[arg(long, value_name = "CELL", value_parser = clipped(parse_cell))]
    pub cell: Cell,
    /// The table file, built for the same cell
    #[arg(long, value_name = "FILE.dct")]
    pub table: PathBuf,
    /// Which slices: yy (thesis Figure 3.16), zz (Figure 3.17) or xx
    #[arg(long, value_name = "AXES", default_value = "yy", conflicts_with = "a")]
    #[arg(value_parser = choice::<QuiltAxes>())]
    pub axes: QuiltAxes,
    /// Grid indices i,j of the remaining dimension pair (e.g. x and x' with --axes yy)
    /// [default: half the workspace radius toward the other robot]
    #[arg(long, value_name = "I,J", conflicts_with = "a", value_parser = clipped(parse_indices::<2>))]
    pub fix: Option<[u16; 2]>,
    /// Fix A's grid cell ix,iy,iz and show B's x'y'-slices, one per depth z'
    #[arg(long, value_name = "IX,IY,IZ", value_parser = clipped(parse_indices::<3>))]
    pub a: Option<[u16; 3]>,
    /// The PNG file to write, replaced only once complete
    #[arg(long, value_name = "FILE.png", default_value = "quilt.png")]
    pub output: PathBuf,
    /// Width of the picture in pixels, 200 to 8192
    #[arg(long, value_name = "W", default_value_t = 1200, value_parser = clipped(pixels(200)))]
    pub width: u32,
    /// Height of the picture in pixels, 200 to 8192
    #[arg(long, value_name = "H", default_value_t = 1200, value_parser = clipped(pixels(200)))]
    pub height: u32,
}

/// The table kinds `build` writes: the library's [`TableKind`], with its names and help.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KindArg(pub TableKind);

impl ValueEnum for KindArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [KindArg; 7] = {
            let k = TableKind::ALL;
            [
                KindArg(k[0]),
                KindArg(k[1]),
                KindArg(k[2]),
                KindArg(k[3]),
                KindArg(k[4]),
                KindArg(k[5]),
                KindArg(k[6]),
            ]
        };
        &ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.0.name()).help(self.0.description()))
    }
}

/// How `build` labels the samples (the library's [`Labelling`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LabellingArg {
    /// Per-cell proved displacement bounds: no false negative in a free cell
    Certified,
    /// The thesis's margin at the cell centre
    Thesis,
}

impl From<LabellingArg> for Labelling {
    fn from(l: LabellingArg) -> Labelling {
        match l {
            LabellingArg::Certified => Labelling::Certified,
            LabellingArg::Thesis => Labelling::ThesisMargin,
        }
    }
}

/// What `check --table` does with a row the table says collides (the library's
/// [`Confirmation`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ConfirmArg {
    /// Confirm by the exact check: the answers of check without --table
    Exact,
    /// The table's label: it may say collide where the robots are a little apart
    None,
}

impl From<ConfirmArg> for Confirmation {
    fn from(c: ConfirmArg) -> Confirmation {
        match c {
            ConfirmArg::Exact => Confirmation::Exact,
            ConfirmArg::None => Confirmation::None,
        }
    }
}

/// The slice pairs of `quilt`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QuiltAxes {
    /// yy'-slices in a quilt over (z, z'), x and x' fixed (Figure 3.16)
    Yy,
    /// zz'-slices in a quilt over (y, y'), x and x' fixed (Figure 3.17)
    Zz,
    /// xx'-slices in a quilt over (z, z'), y and y' fixed
    Xx,
}

/// The cells of `demo`.
#[derive(Clone, Debug)]
pub struct Cells(pub Vec<Cell>);

impl Cli {
    /// The parsed command line; on a usage error (unknown, repeated, contradictory or badly
    /// typed flags) prints clap's message and exits with 2, on `--help`/`--version` exits 0.
    pub fn parse_checked() -> Cli {
        // A negative number after a flag is its value, so that the flag's parser names it and
        // its valid values (`--k -1`), not an unexpected argument.
        let command = Cli::command().mut_subcommands(|c| c.allow_negative_numbers(true));
        let cli = command
            .try_get_matches()
            .and_then(|m| Cli::from_arg_matches(&m))
            .unwrap_or_else(|e| e.exit());
        if let Err(e) = cli.check() {
            e.exit();
        }
        cli
    }

    /// Refuses flags that contradict each other or the cell.
    fn check(&self) -> Result<(), clap::Error> {
        match &self.command {
            Command::Build(b) => {
                if let (Some(t), false) = (b.t, b.variant.0.has_threshold()) {
                    let v = b.variant.0;
                    return Err(usage_error(
                        "build",
                        ErrorKind::ArgumentConflict,
                        format!("--t {t} applies to --variant 4d-yy and 4d-zz only, not to --variant {v}"),
                    ));
                }
                if let (Some(n), Some(ShardArg::Fixed(..))) = (b.shards, b.shard) {
                    return Err(usage_error(
                        "build",
                        ErrorKind::ArgumentConflict,
                        format!("--shards {n} applies to --shard auto only; --shard I/N gives the count itself"),
                    ));
                }
                if b.levels.is_some() && b.variant.0 != TableKind::Clearance {
                    return Err(usage_error(
                        "build",
                        ErrorKind::ArgumentConflict,
                        format!(
                            "--levels applies to --variant clearance only, not to --variant {}",
                            b.variant.0
                        ),
                    ));
                }
                if b.variant.0 == TableKind::Clearance && b.labelling == LabellingArg::Thesis {
                    return Err(usage_error(
                        "build",
                        ErrorKind::ArgumentConflict,
                        "--variant clearance proves its levels: it needs --labelling certified"
                            .into(),
                    ));
                }
                if b.variant.0 == TableKind::SharedSub && b.labelling == LabellingArg::Thesis {
                    return Err(usage_error(
                        "build",
                        ErrorKind::ArgumentConflict,
                        "--variant shared-sub certifies sub-cells: it needs --labelling certified"
                            .into(),
                    ));
                }
            }
            Command::Check(c) if c.confirm.is_some() && c.table.is_none() => {
                return Err(usage_error(
                    "check",
                    ErrorKind::MissingRequiredArgument,
                    "--confirm applies to --table: without a table every row is answered by the exact check".into(),
                ));
            }
            Command::Replay(r) => {
                if let Some(plot) = &r.plot {
                    if !plot.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
                        return Err(usage_error(
                            "replay",
                            ErrorKind::InvalidValue,
                            format!(
                                "--plot {}: the plot is a PNG file; give a name ending in .png",
                                clip(&plot.display().to_string())
                            ),
                        ));
                    }
                    if r.output.as_ref() == Some(plot) {
                        return Err(usage_error(
                            "replay",
                            ErrorKind::ArgumentConflict,
                            "--plot and --output name the same file: the verdicts (CSV) and the plot (PNG) need two"
                                .into(),
                        ));
                    }
                }
            }
            Command::Render(r) if r.tcp.len() != r.cell.robots.len() => {
                return Err(usage_error(
                    "render",
                    ErrorKind::WrongNumberOfValues,
                    format!(
                        "cell {} has {} robots: give one --tcp x,y,z per robot (each in its own MCS, mm), got {}",
                        r.cell.name,
                        r.cell.robots.len(),
                        r.tcp.len()
                    ),
                ));
            }
            _ => {}
        }
        Ok(())
    }
}

/// A usage error of subcommand `name`, formatted by clap (with that command's usage line);
/// it exits with 2.
pub fn usage_error(name: &str, kind: ErrorKind, message: String) -> clap::Error {
    let mut cmd = Cli::command();
    cmd.build();
    match cmd.find_subcommand_mut(name) {
        Some(sub) => sub.error(kind, message),
        None => cmd.error(kind, message),
    }
}

/// Wraps a value parser so that its errors echo at most [`ECHO_CHARS`] characters of the value.
pub fn clipped<P: TypedValueParser>(inner: P) -> Clipped<P> {
    Clipped(inner)
}

#[derive(Clone)]
pub struct Clipped<P>(P);

impl<P: TypedValueParser> TypedValueParser for Clipped<P> {
    type Value = P::Value;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<Self::Value, clap::Error> {
        let mut err = match self.0.parse_ref(cmd, arg, value) {
            Ok(v) => return Ok(v),
            Err(e) => e,
        };
        let text = value.to_string_lossy();
        if text.chars().count() > ECHO_CHARS {
            // The error's context names the value in full; put the clipped one in its place.
            err.insert(ContextKind::InvalidValue, ContextValue::String(clip(&text)));
        }
        Err(err)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        self.0.possible_values()
    }
}

/// A value of `E`, refused with the list of its values ("use a, b or c").
pub fn choice<E: ValueEnum + Clone + Send + Sync + 'static>() -> Choice<E> {
    Choice(std::marker::PhantomData)
}

#[derive(Clone)]
pub struct Choice<E>(std::marker::PhantomData<E>);

impl<E: ValueEnum + Clone + Send + Sync + 'static> TypedValueParser for Choice<E> {
    type Value = E;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<E, clap::Error> {
        if let Some(v) = value.to_str().and_then(|s| E::from_str(s, false).ok()) {
            return Ok(v);
        }
        let names: Vec<String> = E::value_variants()
            .iter()
            .filter_map(ValueEnum::to_possible_value)
            .map(|p| p.get_name().to_string())
            .collect();
        let list = match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => names.concat(),
        };
        let arg = arg.map_or_else(|| "the value".to_string(), |a| format!("'{a}'"));
        let message =
            format!("invalid value '{}' for {arg}: use {list}\n", clip(&value.to_string_lossy()));
        Err(clap::Error::raw(ErrorKind::InvalidValue, message).with_cmd(cmd))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(E::value_variants().iter().filter_map(ValueEnum::to_possible_value)))
    }
}

/// The built-in cell names, for messages.
fn builtin_names() -> String {
    let names: Vec<&str> = REFERENCE_CELL_FILES.iter().map(|(n, _)| *n).collect();
    names.join(", ")
}

/// A built-in cell by name (any case), or a cell file ending in `.toml`.
fn parse_cell(s: &str) -> Result<Cell, String> {
    if let Some(cell) = reference_cell(s) {
        return Ok(cell);
    }
    if !s.to_ascii_lowercase().ends_with(".toml") {
        return Err(format!("not a built-in cell ({}) nor a .toml cell file", builtin_names()));
    }
    Cell::from_file(std::path::Path::new(s)).map_err(|e| e.to_string())
}

/// As [`parse_cell`], or `all` for the three built-in cells.
fn parse_cells(s: &str) -> Result<Cells, String> {
    if s.eq_ignore_ascii_case("all") {
        return Ok(Cells(
            REFERENCE_CELL_FILES.iter().filter_map(|(n, _)| reference_cell(n)).collect(),
        ));
    }
    parse_cell(s).map(|c| Cells(vec![c])).map_err(|e| format!("{e}; or all"))
}

/// A number of type `T`.
fn parse_bytes(s: &str) -> Result<u64, String> {
    delta_collide::table::parse_bytes(s)
}

fn parse_number<T: std::str::FromStr>(s: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    s.trim().parse().map_err(|e| format!("not a number of the expected kind ({e})"))
}

/// The seed of xorshift64*, which stays at 0 forever from 0.
fn parse_seed(s: &str) -> Result<u64, String> {
    match parse_number::<u64>(s)? {
        0 => Err("the seed must not be 0 (the generator would stay at 0)".into()),
        v => Ok(v),
    }
}

/// `I/N` with `I < N`, or `auto`.
fn parse_shard(s: &str) -> Result<ShardArg, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(ShardArg::Auto);
    }
    let fix = "expected I/N (shard I of N, I from 0 to N-1, e.g. 0/4) or auto";
    let (i, n) = s.split_once('/').ok_or(fix)?;
    match (i.trim().parse::<u32>(), n.trim().parse::<u32>()) {
        (Ok(i), Ok(n)) if i < n => Ok(ShardArg::Fixed(i, n)),
        (Ok(i), Ok(n)) => Err(format!("shard {i} of {n}: {fix}")),
        _ => Err(fix.into()),
    }
}

/// A k that the table format holds: a power of two from 2 to `2^MAX_LEVELS`.
fn parse_k(s: &str) -> Result<u32, String> {
    let max = 1u32 << MAX_LEVELS;
    let fix = format!("k must be a power of two from 2 to {max} (the table format holds at most {MAX_LEVELS} levels)");
    match s.trim().parse::<u32>() {
        Ok(k) if k >= 2 && k <= max && k.is_power_of_two() => Ok(k),
        _ => Err(fix),
    }
}

/// A clearance ladder: comma-separated lengths in mm, increasing.
fn parse_ladder(s: &str) -> Result<Ladder, String> {
    let mm = s.split(',').map(parse_number::<f64>).collect::<Result<Vec<_>, _>>()?;
    Ladder::new(&mm).map_err(|e| e.to_string())
}

/// A finite length above 0 (mm).
fn positive_mm(s: &str) -> Result<f64, String> {
    match parse_number::<f64>(s)? {
        v if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("expected a finite length above 0 mm".into()),
    }
}

/// A finite length of at least 0 (mm).
fn non_negative_mm(s: &str) -> Result<f64, String> {
    match parse_number::<f64>(s)? {
        v if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err("expected a finite length of at least 0 mm".into()),
    }
}

/// A side of a picture in pixels, from `min` to 8192.
fn pixels(min: u32) -> impl TypedValueParser<Value = u32> {
    move |s: &str| -> Result<u32, String> {
        match parse_number::<u32>(s)? {
            v if (min..=MAX_SIDE).contains(&v) => Ok(v),
            _ => Err(format!("this picture needs at least {min} and at most {MAX_SIDE} pixels")),
        }
    }
}

/// Three comma-separated numbers `x,y,z`.
fn parse_xyz(s: &str) -> Result<Vec3, String> {
    let v: Vec<f64> =
        s.split(',').map(|f| f.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|_| {
            "expected three numbers x,y,z (mm, the robot's own MCS), e.g. 150,0,-450".to_string()
        })?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        [_, _, _] => Err("the coordinates must be finite".into()),
        _ => Err(format!("expected three numbers x,y,z, got {}", v.len())),
    }
}

/// `N` comma-separated grid indices.
fn parse_indices<const N: usize>(s: &str) -> Result<[u16; N], String> {
    let v: Vec<u16> =
        s.split(',').map(|f| f.trim().parse::<u16>()).collect::<Result<_, _>>().unwrap_or_default();
    <[u16; N]>::try_from(v).map_err(|_| {
        format!("expected {N} grid indices (whole numbers from 0) separated by commas")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn clip_cuts_long_input_on_a_char_boundary() {
        assert_eq!(clip("1,2,3"), "1,2,3");
        let long = "é".repeat(100);
        assert_eq!(clip(&long), format!("{}...", "é".repeat(ECHO_CHARS)));
    }
}
