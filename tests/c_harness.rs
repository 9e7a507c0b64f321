//! The C harness (thesis appendix A.1, SPEC §5): builds
//! `c_harness/*.c` with the system C compiler against the generated header
//! `include/delta_collide.h` and the static library, builds the table files of T1, T2 and T3
//! (k = 32, 6-D, certified labels), runs the harness from the repository root in exact and
//! table mode and checks its verdict line. The same harness runs clean under AddressSanitizer
//! with UndefinedBehaviorSanitizer (and LeakSanitizer where it can run) and, with `--quick`,
//! under valgrind memcheck. Also compiles the header into two C++ translation units (wasmtime's
//! double-include check) and records whether it is valid C89. The four-robot line runs in
//! exact mode and with the protective verdict (`c_harness/line.c`); the timed protective query
//! runs twice per cycle and under adversarial schedules (`c_harness/timing.c`); the
//! coordination keeps two robots whose programmes place at one point apart
//! (`c_harness/coordination.c`).
//!
//! The static library is the one cargo builds in the same run: the test executable is
//! `target/<profile>/deps/c_harness-HASH` and the library lies next to it in `deps/`.

use delta_collide::cell::parse_cell;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::ffi::{DC_STATUS_TIME_BACKWARDS, DC_VERDICT_STOP};
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::{build_tables, to_bytes, Labelling, Ladder, Variant};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

mod harness_build;
mod native_libs;
use harness_build::{in_ci, repo_root, run, scratch_dir, static_lib, text, C_FLAGS};
use native_libs::NATIVE_LIBS;

/// Sanitizer flags (gcc): every report aborts the run.
const SANITIZE_FLAGS: &[&str] =
    &["-g", "-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-fno-sanitize-recover=all"];

/// Resolution of the tables the harness runs on (SPEC §4: k = 32 gives r = 16.5625 mm).
const TABLE_K: u32 = 32;

/// The reference cells, in the order of the harness's `--table` arguments.
const CELLS: [&str; 3] = ["T1", "T2", "T3"];

/// Parses the last `N passed, M failed` line of the harness output.
fn verdict_line(stdout: &str) -> Option<(u64, u64)> {
    stdout.lines().rev().find_map(|line| {
        let (passed, failed) = line.trim().split_once(" passed, ")?;
        let failed = failed.strip_suffix(" failed")?;
        Some((passed.parse().ok()?, failed.parse().ok()?))
    })
}

/// Compiles the host harness with the strict flags plus `extra` into the scratch `name`.
fn compile_harness(name: &str, extra: &[&str]) -> PathBuf {
    let exe = scratch_dir("c_harness").join(name);
    harness_build::compile_harness("cc", extra, &static_lib(), NATIVE_LIBS, &exe);
    exe
}

/// The plain harness binary, compiled once per test process.
fn plain_harness() -> &'static Path {
    static EXE: OnceLock<PathBuf> = OnceLock::new();
    EXE.get_or_init(|| compile_harness("c_harness", &[]))
}

/// The table kinds the harness runs on: the thesis's 6-D linear quadtree and the shared 6-D
/// quadtree, both built from one certified labelling.
const KINDS: [(&str, Variant); 2] = [("6d", Variant::D6), ("shared", Variant::Shared)];

/// Resolution of the clearance tables of the protective verdict in table mode: their
/// labelling takes about 3 s per cell at k = 16 and a minute at k = 32.
const CLEARANCE_K: u32 = 16;

/// The certified clearance table (default levels) of `CELLS[c]` at [`CLEARANCE_K`]
/// (`delta-collide build --cell T1 --k 16 --variant clearance`), kept and reused as
/// [`table_files`] are.
fn clearance_table_file(c: usize) -> &'static Path {
    static FILES: [OnceLock<PathBuf>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    FILES[c].get_or_init(|| {
        let name = CELLS[c];
        let dir = scratch_dir("c_harness_tables");
        let path = dir.join(format!("{name}_k{CLEARANCE_K}_clearance.dct"));
        let stamp = dir.join(format!("{name}_k{CLEARANCE_K}_clearance.builder"));
        let exe = std::fs::metadata(std::env::current_exe().expect("test executable"))
            .expect("stat test executable");
        let modified =
            exe.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
        let builder = format!(
            "{} bytes, modified {:?}, k = {CLEARANCE_K}",
            exe.len(),
            modified.unwrap_or_default()
        );
        if path.is_file() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == builder) {
            return path;
        }
        let cell = reference_cell(name).expect("reference cell");
        let variant = Variant::Clearance(Ladder::default_ladder());
        let (header, tables, _) = build_tables(
            &cell,
            CLEARANCE_K,
            &Workspace::THESIS,
            &[variant],
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the {name} clearance table: {e}"));
        let _ = std::fs::remove_file(&stamp);
        std::fs::write(&path, to_bytes(&tables[0], &header))
            .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
        std::fs::write(&stamp, builder)
            .unwrap_or_else(|e| panic!("writing {}: {e}", stamp.display()));
        path
    })
}

/// The table files of `CELLS[c]`, one per [`KINDS`] (the pipeline of `delta-collide build
/// --cell T1 --k 32 --variant 6d|shared`). Labelling T1, T2, T3 takes about 3 s, 10 s and
/// 3 s in release on two idle cores, so the files are kept in `CARGO_TARGET_TMPDIR` and reused
/// while this test executable (which holds the table builder) is unchanged: a rebuilt
/// executable rebuilds the tables. Each cell has its own lock, so a test that needs T1's
/// tables only does not wait for others.
fn table_files(c: usize) -> &'static [PathBuf] {
    static FILES: [OnceLock<Vec<PathBuf>>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    FILES[c].get_or_init(|| {
        let name = CELLS[c];
        let dir = scratch_dir("c_harness_tables");
        let paths: Vec<PathBuf> = KINDS
            .iter()
            .map(|(kind, _)| dir.join(format!("{name}_k{TABLE_K}_{kind}.dct")))
            .collect();
        let stamp = dir.join(format!("{name}_k{TABLE_K}.builder"));
        let exe = std::fs::metadata(std::env::current_exe().expect("test executable"))
            .expect("stat test executable");
        let modified =
            exe.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
        let builder = format!(
            "{} bytes, modified {:?}, k = {TABLE_K}",
            exe.len(),
            modified.unwrap_or_default()
        );
        if paths.iter().all(|p| p.is_file())
            && std::fs::read_to_string(&stamp).is_ok_and(|s| s == builder)
        {
            println!("{name}: tables reused from {} (same test executable)", dir.display());
            return paths;
        }
        let cell = reference_cell(name).expect("reference cell");
        let start = std::time::Instant::now();
        let variants: Vec<Variant> = KINDS.iter().map(|&(_, v)| v).collect();
        let (header, tables, _) = build_tables(
            &cell,
            TABLE_K,
            &Workspace::THESIS,
            &variants,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the {name} tables: {e}"));
        let _ = std::fs::remove_file(&stamp);
        for (path, table) in paths.iter().zip(&tables) {
            let bytes = to_bytes(table, &header);
            std::fs::write(path, &bytes)
                .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
            println!("{name}: {} table k = {TABLE_K}, {} bytes", table.name(), bytes.len());
        }
        std::fs::write(&stamp, builder)
            .unwrap_or_else(|e| panic!("writing {}: {e}", stamp.display()));
        println!("{name}: tables built in {:.1} s", start.elapsed().as_secs_f64());
        paths
    })
}

/// The bundle file of `cells/line4.toml` (the pipeline of `delta-collide build --cell
/// cells/line4.toml --k 16 --variant clearance`: one table per spacing that can meet), kept and
/// reused as [`table_files`] are.
fn line_bundle_file() -> &'static Path {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| {
        let dir = scratch_dir("c_harness_tables");
        let path = dir.join(format!("line4_k{CLEARANCE_K}_clearance.dcb"));
        let stamp = dir.join(format!("line4_k{CLEARANCE_K}.builder"));
        let exe = std::fs::metadata(std::env::current_exe().expect("test executable"))
            .expect("stat test executable");
        let modified =
            exe.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
        let builder = format!(
            "{} bytes, modified {:?}, k = {CLEARANCE_K}",
            exe.len(),
            modified.unwrap_or_default()
        );
        if path.is_file() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == builder) {
            return path;
        }
        let cell =
            parse_cell(&std::fs::read_to_string(repo_root().join("cells/line4.toml")).unwrap())
                .unwrap();
        let start = std::time::Instant::now();
        // Clearance tables: the POU's lookups read their labels, the protective verdict their
        // bounds.
        let variant = Variant::Clearance(Ladder::default_ladder());
        let built = build_bundle(
            &cell,
            CLEARANCE_K,
            &Workspace::THESIS,
            variant,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the line4 bundle: {e}"));
        let _ = std::fs::remove_file(&stamp);
        std::fs::write(&path, &built.bytes)
            .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
        std::fs::write(&stamp, builder)
            .unwrap_or_else(|e| panic!("writing {}: {e}", stamp.display()));
        println!(
            "line4: bundle of {} tables k = {CLEARANCE_K}, {} bytes, built in {:.1} s",
            built.tables.len(),
            built.bytes.len(),
            start.elapsed().as_secs_f64()
        );
        path
    })
}

/// The 6-D table file of `CELLS[c]`.
fn table_file(c: usize) -> &'static Path {
    &table_files(c)[0]
}

/// `--table T1=... --table T2=... --table T3=...` for the given cells, table kind `kind`
/// (an index into [`KINDS`]).
fn table_args_of(cells: &[usize], kind: usize) -> Vec<String> {
    cells
        .iter()
        .flat_map(|&c| {
            ["--table".to_string(), format!("{}={}", CELLS[c], table_files(c)[kind].display())]
        })
        .collect()
}

/// `--table` arguments of the 6-D tables.
fn table_args(cells: &[usize]) -> Vec<String> {
    table_args_of(cells, 0)
}

/// Checks the harness's verdict line and exit status; returns its stdout.
fn assert_harness_passed(what: &str, out: &Output) -> String {
    let stdout = text(&out.stdout);
    println!("{what}:\n{stdout}");
    eprintln!("{}", text(&out.stderr));
    let (passed, failed) =
        verdict_line(&stdout).unwrap_or_else(|| panic!("{what}: no `N passed, N failed` line"));
    assert!(passed > 0, "{what}: the harness ran no checks");
    assert_eq!(failed, 0, "{what}: the harness reported failures (see above)");
    assert!(out.status.success(), "{what}: exit status {:?} with 0 failures", out.status);
    stdout
}

/// The number that follows `before` in a harness output line.
fn number(line: &str, before: &str) -> f64 {
    let rest = line.split(before).nth(1).unwrap_or_else(|| panic!("no `{before}` in: {line}"));
    let field = rest.split([' ', ',', ')']).find(|f| !f.is_empty()).unwrap();
    field.parse().unwrap_or_else(|_| panic!("`{before}` is not followed by a number in: {line}"))
}

/// The protective runs in table mode on the clearance tables (`c_harness/protective.c`): for
/// each cell, case and model as in exact mode, no simulated stop touches, there are no more
/// STOP ticks than in exact mode, and the share of ticks answered by the lookup alone is
/// printed.
fn assert_protective_table_mode(stdout: &str) {
    let runs: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("protective T") && l.contains(" table mode: first"))
        .collect();
    assert_eq!(runs.len(), 18, "three table-mode protective runs per cell and case: {runs:?}");
    // `protective T1 practical stiff   with paths table mode: first ...` and its exact-mode
    // run `protective T1 practical stiff   with paths: first ...` have the same key.
    let key = |l: &str| {
        l.split(": first").next().unwrap().replace(" table mode", "").trim_end().to_string()
    };
    for l in &runs {
        assert_eq!(number(l, "contacts "), 0.0, "{l}");
        let exact = stdout
            .lines()
            .find(|e| {
                e.starts_with("protective T") && !e.contains(" table mode") && key(e) == key(l)
            })
            .unwrap_or_else(|| panic!("no exact-mode run for {l}"));
        assert!(
            number(l, ", STOP ") <= number(exact, ", STOP "),
            "table mode stops more often:\n{l}\n{exact}"
        );
    }
    let shares: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("protective T") && l.contains("answered by the lookup alone"))
        .collect();
    assert_eq!(shares.len(), 18, "{shares:?}");
}

/// The speed-override lines (`c_harness/speed_override.c`), one per practical scenario: the
/// boxes never touch (every tick, and every 0.1 ms of each stop simulated at a STOP), the
/// scaled run completes its cycle, no sooner than the unscaled one, with fewer STOP ticks.
fn assert_speed_override(stdout: &str) {
    for cell in ["T1", "T2", "T3"] {
        let prefix = format!("speed override {cell} practical: ");
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line"));
        assert!(!line.contains("NOT COMPLETED"), "{line}");
        let (cycle, unscaled) = (number(line, "cycle "), number(line, "unscaled "));
        assert!(cycle >= unscaled && unscaled > 1000.0, "{line}");
        assert_eq!(number(line, "ticks touching "), 0.0, "{line}");
        assert_eq!(number(line, "contacts "), 0.0, "{line}");
        let (stops, unscaled_stops) = (number(line, "STOP "), number(line, "(unscaled "));
        assert!(
            stops < unscaled_stops,
            "the override needs fewer stops than the unscaled run: {line}"
        );
        assert_eq!(
            number(line, "stops simulated "),
            stops,
            "a stop is simulated at every STOP: {line}"
        );
    }
}

/// The word (`yes` or `no`) that follows `before` in a harness output line.
fn yes_no(line: &str, before: &str) -> bool {
    let rest = line.split(before).nth(1).unwrap_or_else(|| panic!("no `{before}` in: {line}"));
    match rest.split([' ', ',']).next().unwrap() {
        "yes" => true,
        "no" => false,
        other => panic!("`{before}` is followed by `{other}`, not yes or no, in: {line}"),
    }
}

/// The coordination's line (`c_harness/coordination.c`): on T1 two robots whose programmes
/// place at the same point at the same ticks, driven by `dc_coordinate` and stopped by the
/// timed protective query. The boxes never touch; whether the run finishes or deadlocks is a
/// property of the coordination under development, reported here, not asserted.
fn assert_coordination(stdout: &str) {
    let prefix = "coordination T1: ";
    let line = stdout
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` line"));
    let (programmed, taken) = (number(line, "programmed "), number(line, "taken "));
    let (stops, contacts) = (number(line, "STOP events "), number(line, "contact ticks "));
    let (finished, deadlock) = (yes_no(line, "finished "), yes_no(line, "deadlock "));
    assert_eq!(contacts, 0.0, "the boxes touch: {line}");
    assert!(programmed > 0.0 && taken > 0.0 && taken <= 4.0 * programmed, "{line}");
    assert!(!(finished && deadlock), "{line}");
    if finished {
        assert!(taken >= programmed, "finished sooner than programmed: {line}");
    }
    let not_ok = number(line, "protective statuses not OK ");
    println!(
        "coordination T1: programmed {programmed} ticks, taken {taken} ticks ({}), STOP events \
         {stops}, contact ticks {contacts}, deadlock {}, protective statuses not OK {not_ok}",
        if finished {
            format!("throughput kept {:.1} %", 100.0 * programmed / taken)
        } else {
            "not finished".to_string()
        },
        if deadlock { "yes" } else { "no" }
    );
}

/// The four-robot line's lines (`c_harness/line.c`): in exact mode the practical case is FREE on
/// every tick; the collision case stops after tick 3000, at the exact model's first colliding
/// tick, on the pair R3-R4 (robots 2-3, `tests/line_scenarios.rs`). With the protective verdict
/// (default and stiff models, the stiff one also with paths) no simulated stop touches, and in
/// the collision case every first STOP comes no later than that tick. In table mode on the
/// line's bundle (exact confirmation) the practical case is FREE on every tick and the
/// collision case stops at the same tick on the same pair. T1's table alone is refused.
fn assert_line(stdout: &str) {
    let line = |prefix: &str| -> &str {
        stdout
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line"))
    };
    let practical = line("line4 practical");
    assert!(
        practical.contains("POU stop tick none, first exact collision none, FREE ticks 6000/6000"),
        "{practical}"
    );
    let collision = line("line4 collision");
    let (stop, first) =
        (number(collision, "POU stop tick "), number(collision, "first exact collision "));
    assert!(stop > 3000.0 && stop == first, "{collision}");
    assert!(collision.ends_with("colliding pairs at the stop 2-3"), "{collision}");
    assert!(number(collision, "pairs that can meet ") >= 5.0, "{collision}");
    let t1_alone = line("line4 T1's table alone");
    assert!(
        t1_alone.contains("holds no table for R1-R3"),
        "T1's table refused for the line: {t1_alone}"
    );
    let table_practical = line("line4 table practical");
    assert!(
        table_practical
            .contains("POU stop tick none, first exact collision none, FREE ticks 6000/6000"),
        "{table_practical}"
    );
    let table_collision = line("line4 table collision");
    assert_eq!(number(table_collision, "POU stop tick "), stop, "{table_collision}");
    assert!(table_collision.contains("colliding pairs at the stop 2-3,"), "{table_collision}");
    // The lookups said COLLISION near the contact and the exact check confirmed them.
    assert!(number(table_collision, "lookups confirmed ") > 0.0, "{table_collision}");
    let protective: Vec<&str> = stdout
        .lines()
        .filter(|l| {
            l.starts_with("protective line4 ") && !l.contains("answered by the lookup alone")
        })
        .collect();
    assert_eq!(protective.len(), 8, "four protective runs per case: {protective:?}");
    assert_eq!(
        protective.iter().filter(|l| l.contains(" table mode:")).count(),
        2,
        "{protective:?}"
    );
    for l in protective {
        assert_eq!(number(l, "contacts "), 0.0, "{l}");
        assert_eq!(number(l, "statuses not OK "), 0.0, "{l}");
        assert!(number(l, "smallest clearance ") > 10.0, "{l}");
        if l.starts_with("protective line4 collision") {
            let first_stop = number(l, "first STOP ");
            assert!(
                first_stop >= 0.0 && first_stop <= first,
                "STOP after the first collision tick {first}: {l}"
            );
            assert!(number(l, ", stop ") > 0.0, "the stop was simulated: {l}");
        }
    }
}

/// The timed protective query's lines (`c_harness/timing.c`). Twice per cycle on each cell's
/// collision run: every second timed call answered as the first, and the first calls as an
/// untimed handle called once per tick; the untimed call twice per tick answered better the
/// second time on some tick where a stop from the true motion touches (the hazard). One line
/// per cell, case and schedule: every status as the timing rules say, no stop after FREE or
/// WARN touches, and over all schedules every timing fault was provoked.
fn assert_timing(stdout: &str) {
    let twice: Vec<&str> =
        stdout.lines().filter(|l| l.contains(" collision twice per cycle: ")).collect();
    assert_eq!(twice.len(), 3, "one twice-per-cycle line per cell: {twice:?}");
    let mut touching = 0.0;
    for l in &twice {
        assert_eq!(
            number(l, "twice per cycle: "),
            number(l, "second timed call unchanged on "),
            "{l}"
        );
        assert_eq!(number(l, "untimed once per tick differs on "), 0.0, "{l}");
        touching += number(l, "of which a stop from the true motion touches on ");
    }
    assert!(
        touching > 0.0,
        "the untimed call twice per tick never answered a touching FREE: {twice:?}"
    );
    let runs: Vec<&str> =
        stdout.lines().filter(|l| l.starts_with("timing T") && l.contains(" calls (")).collect();
    assert_eq!(runs.len(), 3 * 2 * 8, "eight schedules per cell and case: {runs:?}");
    for l in &runs {
        assert_eq!(number(l, "statuses not as the rules "), 0.0, "{l}");
        assert_eq!(number(l, "other statuses "), 0.0, "{l}");
        assert_eq!(number(l, "contacts "), 0.0, "{l}");
        assert!(number(l, "least clearance of the stops ") > 0.0, "{l}");
    }
    for fault in ["REPEATED ", "BACKWARDS ", "JUMP ", "EARLY ", "CLOCK_CHANGED "] {
        let n: f64 = runs.iter().map(|l| number(l, fault)).sum();
        assert!(n > 0.0, "no schedule provoked {fault}");
    }
}

/// The state machine of plc/README.md (`| Tn | FROM | when | TO | action |`): (row, from, to).
fn plc_transition_table() -> Vec<(u32, String, String)> {
    let readme = std::fs::read_to_string(repo_root().join("plc/README.md")).expect("plc/README.md");
    let section = readme.split("### State machine").nth(1).expect("a state machine section");
    let section = section.split("\n#").next().unwrap();
    section
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let row = cells.get(1)?.strip_prefix('T')?.parse().ok()?;
            Some((row, cells[2].to_string(), cells[4].to_string()))
        })
        .collect()
}

/// The function block's lifecycle (`pou_fb_call` in `c_harness/pou.c`, the C copy of
/// plc/src/FB_DeltaCollide.st): every transition it printed is a row of plc/README.md's
/// table, with that row's states, every row was taken, and no step left FREE or a verdict
/// other than STOP without `valid 1`.
fn assert_pou_fb(stdout: &str) {
    let table = plc_transition_table();
    assert!(table.len() >= 9, "plc/README.md's transition table: {table:?}");
    let steps: Vec<&str> = stdout.lines().filter(|l| l.starts_with("pou fb step ")).collect();
    let announced = stdout
        .lines()
        .find_map(|l| l.strip_prefix("pou fb: ")?.strip_suffix(" steps")?.parse::<usize>().ok())
        .expect("a `pou fb: N steps` line");
    assert_eq!(steps.len(), announced, "{steps:#?}");
    let mut taken = std::collections::BTreeSet::new();
    for line in &steps {
        let (_, rest) = line.split_once(": ").unwrap();
        let (transitions, outputs) = rest.split_once("; ").unwrap();
        for t in transitions.split(", ") {
            let (row, states) = t.split_once(' ').unwrap_or_else(|| panic!("{line}"));
            let row: u32 = row.strip_prefix('T').and_then(|r| r.parse().ok()).expect(line);
            let (from, to) = states.split_once(" -> ").expect(line);
            assert!(
                table.iter().any(|(r, f, t)| *r == row && f == from && t == to),
                "T{row} {from} -> {to} is not a row of plc/README.md's table: {line}"
            );
            taken.insert(row);
        }
        if outputs.contains("valid 0") {
            assert!(outputs.ends_with("verdict 0"), "not valid but not STOP: {line}");
        }
    }
    let rows: std::collections::BTreeSet<u32> = table.iter().map(|(r, _, _)| *r).collect();
    assert_eq!(taken, rows, "rows of plc/README.md's table the C POU never took");
}

/// The harness's `summary` lines: (cell, case, table stop tick, first exact collision tick).
fn summaries(stdout: &str) -> Vec<(String, String, Option<u64>, Option<u64>)> {
    let tick = |s: &str| s.trim_end_matches(',').parse().ok();
    stdout
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            // summary T1 collision: stop tick table 3691, exact POU 3711, first exact collision
            // 3711
            (w.len() == 14 && w[0] == "summary").then(|| {
                (w[1].to_string(), w[2].trim_end_matches(':').to_string(), tick(w[6]), tick(w[13]))
            })
        })
        .collect()
}

#[test]
fn c_harness_passes_in_exact_and_table_mode() {
    harness_passes_with_tables(0);
}

/// The same scenarios on the shared 6-D quadtree.
#[test]
fn c_harness_passes_on_the_shared_table() {
    harness_passes_with_tables(1);
}

fn harness_passes_with_tables(kind: usize) {
    let exe = plain_harness();
    let tmp = scratch_dir(&format!("c_harness_{}", KINDS[kind].0));
    let mut args = table_args_of(&[0, 1, 2], kind);
    if kind == 0 {
        for (c, cell) in CELLS.iter().enumerate() {
            args.extend([
                "--clearance-table".to_string(),
                format!("{cell}={}", clearance_table_file(c).display()),
            ]);
        }
    }
    args.extend(["--line-bundle".to_string(), line_bundle_file().display().to_string()]);
    let out = run(Command::new(exe).arg("--tmp").arg(&tmp).args(&args).current_dir(repo_root()));
    let stdout = assert_harness_passed(
        &format!("c_harness (exact and {} table mode, T1 T2 T3)", KINDS[kind].0),
        &out,
    );
    if kind == 0 {
        assert_protective_table_mode(&stdout);
    }
    assert!(
        stdout.contains("bad input: done (exact and table mode)"),
        "table-mode bad inputs did not run"
    );
    assert_speed_override(&stdout);
    assert_timing(&stdout);
    assert_coordination(&stdout);
    assert_line(&stdout);
    assert_pou_fb(&stdout);
    let runs = summaries(&stdout);
    assert_eq!(runs.len(), 6, "one table-mode summary per cell and case: {runs:?}");
    for (cell, case, table_stop, exact_first) in &runs {
        if case == "collision" {
            let (t, e) = (
                table_stop.expect("the table stops"),
                exact_first.expect("the exact model collides"),
            );
            assert!(t <= e, "{cell}: table stop tick {t} after the exact first collision tick {e}");
            assert!(
                t > 3000,
                "{cell}: table stop tick {t} in the collision-free first half of the run"
            );
        } else {
            assert_eq!(*exact_first, None, "{cell} practical: the exact model collides");
        }
    }
}

/// Whether LeakSanitizer can run here: it needs ptrace-like access that some containers deny.
/// Ok(()) when a leaking probe is reported; Err(why) when LSan reports it cannot run.
fn leak_sanitizer_works(dir: &Path) -> Result<(), String> {
    let out =
        run(Command::new(dir.join("probe")).arg("leak").env("ASAN_OPTIONS", "detect_leaks=1"));
    let stderr = text(&out.stderr);
    if stderr.contains("detected memory leaks") {
        assert!(!out.status.success(), "LSan found the probe's leak but the run succeeded");
        return Ok(());
    }
    assert!(
        stderr.contains("LeakSanitizer"),
        "LSan neither found the probe's leak nor said why it cannot run:\n{stderr}"
    );
    Err(stderr.lines().find(|l| l.contains("LeakSanitizer")).unwrap_or("").to_string())
}

/// A probe that leaks, overflows a heap buffer or overflows a signed int (argv[1]).
const PROBE_C: &str = r#"#include <limits.h>
#include <stdlib.h>
#include <string.h>
int main(int argc, char **argv) {
    char *volatile p = malloc(32);
    int big = INT_MAX;
    if (argc < 2) return 2;
    if (strcmp(argv[1], "overflow") == 0) p[32 + argc] = 1;
    if (strcmp(argv[1], "signed") == 0) big += argc;
    if (strcmp(argv[1], "leak") == 0) { p = NULL; return 0; }
    free(p);
    return big == INT_MAX ? 0 : 3;
}
"#;

/// Compiles the probe with `flags` into `dir/probe`.
fn compile_probe(dir: &Path, flags: &[&str]) {
    let src = dir.join("probe.c");
    std::fs::write(&src, PROBE_C).unwrap();
    let out = run(Command::new("cc")
        .args(["-std=c99", "-O0"])
        .args(flags)
        .arg(&src)
        .arg("-o")
        .arg(dir.join("probe")));
    assert!(out.status.success(), "cc probe failed:\n{}", text(&out.stderr));
}

#[test]
fn c_harness_is_clean_under_address_and_undefined_behavior_sanitizers() {
    let probe_dir = scratch_dir("c_harness_asan_probe");
    compile_probe(&probe_dir, SANITIZE_FLAGS);
    // The sanitizers are live: each probe's fault is reported and ends the run.
    for (arg, report) in
        [("overflow", "heap-buffer-overflow"), ("signed", "signed integer overflow")]
    {
        let out = run(Command::new(probe_dir.join("probe"))
            .arg(arg)
            .env("ASAN_OPTIONS", "detect_leaks=0"));
        assert!(
            !out.status.success() && text(&out.stderr).contains(report),
            "probe {arg}: {}",
            text(&out.stderr)
        );
    }
    let detect_leaks = match leak_sanitizer_works(&probe_dir) {
        Ok(()) => true,
        Err(why) => {
            println!(
                "NOTE: LeakSanitizer cannot run in this environment ({why}); the sanitizer run below checks \
                 ASan and UBSan only, leaks are checked by the valgrind test"
            );
            false
        }
    };
    let exe = compile_harness("c_harness_asan", SANITIZE_FLAGS);
    let tmp = scratch_dir("c_harness");
    let out = run(Command::new(&exe)
        .arg("--tmp")
        .arg(&tmp)
        .args(table_args(&[0, 1, 2]))
        .current_dir(repo_root())
        .env(
            "ASAN_OPTIONS",
            format!("detect_leaks={}:abort_on_error=0:exitcode=98", u8::from(detect_leaks)),
        )
        .env("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1"));
    let stderr = text(&out.stderr);
    for report in ["AddressSanitizer", "LeakSanitizer", "runtime error:"] {
        assert!(!stderr.contains(report), "{report} reported in the harness:\n{stderr}");
    }
    assert_harness_passed(
        &format!("c_harness under ASan + UBSan (LSan {})", if detect_leaks { "on" } else { "off" }),
        &out,
    );
}

#[test]
fn c_harness_is_clean_under_valgrind_memcheck() {
    let version = Command::new("valgrind").arg("--version").output();
    let Ok(version) = version.map(|o| text(&o.stdout)) else {
        assert!(
            !in_ci(),
            "valgrind is not installed: .ci/run installs it (apt-get install valgrind)"
        );
        println!("SKIPPED: valgrind is not installed (outside CI; under CI=true this test fails)");
        return;
    };
    let memcheck = [
        "--tool=memcheck",
        "--error-exitcode=99",
        "--leak-check=full",
        "--errors-for-leak-kinds=definite,possible",
    ];
    // The flags catch a leak: the probe's exit code becomes 99.
    let probe_dir = scratch_dir("c_harness_valgrind_probe");
    compile_probe(&probe_dir, &[]);
    let out = run(Command::new("valgrind").args(memcheck).arg(probe_dir.join("probe")).arg("leak"));
    assert_eq!(
        out.status.code(),
        Some(99),
        "valgrind missed the probe's leak:\n{}",
        text(&out.stderr)
    );
    // The harness: the T1 collision scenario in both modes, all bad inputs, T1's table, the
    // line's collision case in exact mode.
    let tmp = scratch_dir("c_harness");
    let out = run(Command::new("valgrind")
        .args(memcheck)
        .arg(plain_harness())
        .args(["--quick", "--tmp"])
        .arg(&tmp)
        .args(table_args(&[0]))
        .current_dir(repo_root()));
    let stderr = text(&out.stderr);
    assert_ne!(out.status.code(), Some(99), "valgrind {} found errors:\n{stderr}", version.trim());
    assert!(stderr.contains("ERROR SUMMARY: 0 errors"), "valgrind summary:\n{stderr}");
    let stdout =
        assert_harness_passed(&format!("c_harness --quick under {}", version.trim()), &out);
    assert!(
        stdout.contains("T1 collision table: stop tick"),
        "the table-mode scenario did not run under valgrind"
    );
    assert!(
        stdout.contains("bad input: done (exact and table mode)"),
        "bad inputs did not all run under valgrind"
    );
    assert!(
        stdout.contains("colliding pairs at the stop 2-3"),
        "the line's collision case did not run under valgrind"
    );
    assert!(
        stdout.contains("coordination T1 quick: "),
        "the coordination's first ticks did not run under valgrind"
    );
    assert_pou_fb(&stdout);
}

#[test]
fn header_compiles_in_two_cpp_translation_units() {
    let root = repo_root();
    let dir = scratch_dir("c_harness_cpp");
    let a = dir.join("a.cpp");
    let b = dir.join("b.cpp");
    let exe = dir.join("two_units");
    // Included twice in one unit (include guard) and once more in the other (no definitions
    // with external linkage in the header, or the link fails).
    std::fs::write(
        &a,
        "#include \"delta_collide.h\"\n#include \"delta_collide.h\"\n\
         const char *version_from_a() { DcVec3 v = {1.0, 2.0, 3.0}; (void)v; return dc_version(); }\n",
    )
    .unwrap();
    std::fs::write(
        &b,
        "#include <cstdio>\n#include <cstring>\n#include \"delta_collide.h\"\n\
         const char *version_from_a();\n\
         int main() {\n  const char *v = dc_version();\n\
           if (std::strcmp(v, version_from_a()) != 0) return 2;\n\
           std::printf(\"%s\\n\", v);\n  return dc_robot_count(NULL) == 0 ? 0 : 3;\n}\n",
    )
    .unwrap();
    let out = run(Command::new("c++")
        .args(["-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(root.join("include"))
        .arg(&a)
        .arg(&b)
        .arg(static_lib())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe));
    assert!(out.status.success(), "c++ failed:\n{}{}", text(&out.stdout), text(&out.stderr));
    let out = run(&mut Command::new(&exe));
    assert!(out.status.success(), "C++ program exit status {:?}", out.status);
    assert_eq!(text(&out.stdout).trim(), env!("CARGO_PKG_VERSION"), "dc_version() from C++");
}

/// Records whether the header is valid C89 (a controller's compiler may be strict ANSI C).
/// cbindgen's defaults write `// __cplusplus` after `#endif` (extra tokens, not comments, in
/// C89, as in rustls.h) and include `<stdint.h>` (C99, though gcc ships it in C89 mode too).
/// The test prints the outcome under `-pedantic` and `-pedantic-errors` and asserts that
/// every diagnostic is one of those known reasons, so a new C89 problem shows up here.
#[test]
fn header_as_c89_is_recorded() {
    let root = repo_root();
    let dir = scratch_dir("c_harness_c89");
    let src = dir.join("c89.c");
    std::fs::write(&src, "#include \"delta_collide.h\"\nint c89_unit_is_not_empty;\n").unwrap();
    let known = [
        "extra tokens at end of #endif",
        "C++ style comments",
        "stdint.h",
        "stdbool.h",
        "long long",
        "_Bool",
        "boolean",
    ];
    for strictness in ["-pedantic", "-pedantic-errors"] {
        let out = run(Command::new("cc")
            .args(["-std=c89", strictness, "-fsyntax-only", "-I"])
            .arg(root.join("include"))
            .arg(&src));
        let stderr = text(&out.stderr);
        let verdict = if out.status.success() { "compiles" } else { "does NOT compile" };
        println!("header {verdict} with cc -std=c89 {strictness}; diagnostics:\n{stderr}");
        for line in stderr.lines().filter(|l| l.contains("warning") || l.contains("error")) {
            assert!(
                known.iter().any(|k| line.contains(k)),
                "C89 diagnostic for a reason other than cbindgen's C99-isms: {line}"
            );
        }
    }
}

/// The C program `program` written to the scratch folder `name` and compiled with the strict
/// flags against the library; the executable's path.
fn compile_example(name: &str, program: &str) -> PathBuf {
    let dir = scratch_dir(&format!("c_harness_{name}"));
    let (src, exe) = (dir.join(format!("{name}.c")), dir.join(name));
    std::fs::write(&src, program).unwrap();
    let out = run(Command::new("cc")
        .args(C_FLAGS)
        .arg("-I")
        .arg(repo_root().join("include"))
        .arg(&src)
        .arg(static_lib())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe));
    assert!(out.status.success(), "the README example does not compile:\n{}", text(&out.stderr));
    exe
}

/// The README's table-mode example, compiled with the strict flags and run on T1's table: a
/// colliding configuration stops the robots; a truncated table is reported with the field at
/// fault and fails closed.
#[test]
fn readme_table_mode_example_compiles_and_runs() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    let section =
        readme.split("### Table mode").nth(1).expect("README has a `### Table mode` section");
    let snippet =
        section.split("```c\n").nth(1).and_then(|s| s.split("```").next()).expect("a ```c block");
    let program = format!(
        r#"#include <stdio.h>
#include <stdlib.h>
#include "delta_collide.h"
static int stops;
static void stop_all_robots(void) {{ stops++; }}
#define log_error(...) (fprintf(stdout, __VA_ARGS__), fputc('\n', stdout))
static DcStatus example(const uint8_t *table_bytes, size_t table_len, const DcVec3 *tcps_mcs)
{{
{snippet}    return s;
}}
int main(int argc, char **argv)
{{
    DcVec3 tcps[2] = {{ {{ 180.0, 0.0, -450.0 }}, {{ -180.0, 0.0, -450.0 }} }};
    FILE *f = fopen(argv[1], "rb");
    static uint8_t table[64 << 20];
    size_t len = f == NULL ? 0 : fread(table, 1, sizeof table, f);
    DcStatus whole, cut;
    (void)argc;
    whole = example(table, len, tcps);
    cut = example(table, 4096, tcps);
    printf("whole %u, cut %u, stops %d\n", (unsigned)whole, (unsigned)cut, stops);
    return f == NULL;
}}
"#
    );
    let exe = compile_example("readme_example", &program);
    let out = run(Command::new(&exe).arg(table_file(0)));
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "README example failed: {stdout}");
    assert!(stdout.contains("delta-collide: the table is truncated"), "error line: {stdout}");
    assert!(
        stdout.contains("section 0 (codes) needs"),
        "dc_last_init_error names the field: {stdout}"
    );
    assert!(
        stdout.contains("bytes, the buffer has 4096; copy the whole table file again"),
        "{stdout}"
    );
    // The failed init leaves h NULL, so the example's query returns DC_STATUS_NULL_POINTER (1)
    // with STOP: the collision and the failed init both stop the robots.
    assert!(
        stdout.contains("whole 0, cut 1, stops 2"),
        "a collision and an error both stop: {stdout}"
    );
}

/// The README's protective example ("Stopping before contact"), compiled with the strict flags
/// and run on T1 with robots standing apart and then one at full speed toward the other: the
/// timed call answers the same cycle twice alike, and a cycle that goes back is STOP with its
/// status.
#[test]
fn readme_protective_example_compiles_and_runs() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    let section =
        readme.split("## Stopping before contact").nth(1).expect("the protective section");
    let snippet =
        section.split("```c\n").nth(1).and_then(|s| s.split("```").next()).expect("a ```c block");
    // The snippet's start-up lines run once; the rest is the tick, run per cycle.
    let (startup, tick) =
        snippet.split_once("/* every tick */\n").expect("a `/* every tick */` line");
    let program = format!(
        r#"#include <stdio.h>
#include <string.h>
#include "delta_collide.h"
static int stop_calls, overrides;
static void stop_all_robots(void) {{ stop_calls++; }}
static void override_speed(const double *limits) {{ overrides += limits[0] >= 0.0; }}
int main(void)
{{
    DcRobotConfig robots[2];
    DcCellConfig config;
    DcCollider *h = NULL;
    DcVerdict verdict = DC_VERDICT_STOP, first = DC_VERDICT_STOP;
    DcStatus s;
    DcVec3 tcps_mcs[2] = {{ {{ -150.0, 0.0, -450.0 }}, {{ 150.0, 0.0, -450.0 }} }};
    unsigned long long cycle_counter;
    int free_ticks = 0, same = 1;
    robots[0] = robots[1] = dc_robot_config_thesis();
    robots[1].translation.x = 450.0;
    config.robots = robots; config.n_robots = 2; config.method = DC_METHOD_SAT;
    if (dc_init(&config, &h) != DC_STATUS_OK) return 2;
    {{
{startup}
    for (cycle_counter = 0; cycle_counter < 20; cycle_counter++) {{
        int again;
        for (again = 0; again < 2; again++) {{
{tick}
            if (again == 0) first = verdict; else same &= first == verdict;
        }}
        free_ticks += verdict == DC_VERDICT_FREE;
    }}
    req.time = 3;
    s = dc_protective_query_timed(h, &req, &verdict, NULL);
    printf("free %d same %d back %u %u stops %d overrides %d\n", free_ticks, same, (unsigned)s,
           (unsigned)verdict, stop_calls, overrides);
    }}
    dc_destroy(h);
    return 0;
}}
"#
    );
    let exe = compile_example("readme_protective", &program);
    let out = run(&mut Command::new(&exe));
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "README example failed: {stdout}");
    // Standing apart: FREE after the first cycles (the first assumes full speed); the same
    // cycle twice answers alike; cycle 3 after 19 goes back: DC_STATUS_TIME_BACKWARDS, STOP.
    let back = format!("back {} {}", DC_STATUS_TIME_BACKWARDS, DC_VERDICT_STOP);
    assert!(stdout.contains("same 1") && stdout.contains(&back), "{stdout}");
    let free: u32 =
        stdout.split("free ").nth(1).and_then(|s| s.split(' ').next()).unwrap().parse().unwrap();
    assert!(free >= 15, "{stdout}");
}
