/*
 * harness.h: what the C harness's translation units share (thesis appendix A.1): the check
 * counter behind the final `N passed, M failed` line, the command line, and small helpers.
 */
#ifndef HARNESS_H
#define HARNESS_H

#include "delta_collide.h"
#include "mock_robotics.h"

#include <stddef.h>

#define HARNESS_N_CELLS 3
#define SCENARIO_FILE "c_harness/scenarios.txt"
/* The four-robot line's cell and cases: a file of their own, since other tests and benches run
 * every case of SCENARIO_FILE on a two-robot reference cell. */
#define LINE_CELL_FILE "cells/line4.toml"
#define LINE_SCENARIO_FILE "c_harness/line_scenarios.txt"
#define STOP_AFTER_TICK 3000L /* the collision case collides only in the last part of the run */

/* One reference cell's table file (given on the command line) and its bytes, read once at
 * start-up (never during a tick). */
typedef struct HarnessTable {
    const char *path;      /* NULL when no table was given for the cell */
    unsigned char *bytes;  /* malloc'd copy of the file, NULL when not read */
    size_t len;
} HarnessTable;

/* The command line: c_harness [--quick] [--tmp DIR] [--table CELL=PATH]...
 *                  [--clearance-table CELL=PATH]... [--line-bundle PATH]
 *   --quick  runs the T1 collision scenario only (exact and table mode), for valgrind;
 *            the kinematics grid, every bad-input scenario and the line's collision case
 *            in exact mode still run;
 *   --protective-quick  the protective scenarios on T1 collision only (under qemu, where the
 *            interval arithmetic of every scenario would take many minutes);
 *   --tmp    a directory for scratch files (default ".");
 *   --table  the table file of reference cell CELL (T1, T2 or T3): enables table mode;
 *   --line-bundle  the bundle of cells/line4.toml (`delta-collide build --cell
 *            cells/line4.toml`): runs the line in table mode too;
 *   --clearance-table  a clearance table file (build --variant clearance) of CELL: the
 *            protective scenarios run once more in table mode on it. */
typedef struct HarnessOptions {
    int quick;
    int protective_quick; /* --protective-quick: the protective verdict on T1 collision only */
    const char *tmp_dir;
    HarnessTable tables[HARNESS_N_CELLS]; /* T1, T2, T3 */
    HarnessTable line_bundle;             /* cells/line4.toml's bundle */
    HarnessTable clearance_tables[HARNESS_N_CELLS]; /* T1, T2, T3 */
} HarnessOptions;

/* Counts one check; prints `FAIL: <message>` when it fails. Returns ok. */
int check(int ok, const char *fmt, ...);

/* The counts behind the verdict line. */
int harness_passed(void);
int harness_failed(void);

DcVec3 vec3(double x, double y, double z);
DcDelta3 dc_geometry(const MrGeometry *g);

/* "T1" -> 0, "T2" -> 1, "T3" -> 2, else -1. */
int cell_index(const char *cell);

/* The TOML file of a reference cell, relative to the repository root. */
const char *cell_file(const char *cell);

/* The scenario file holding the cases of cell `cell` (LINE_SCENARIO_FILE for "line4"). */
const char *scenario_file(const char *cell);

/* "none" for -1, else the tick number. */
void tick_text(long tick, char out[24]);

/* The TCPs the robotics API delivered this tick, as the C ABI takes them. */
void to_dc(const MrTickState *st, size_t n, DcVec3 out[MR_MAX_ROBOTS]);

/* Reads a whole file into a malloc'd buffer (start-up only); returns 0 when it cannot. */
int read_file(const char *path, unsigned char **out, size_t *out_len);

/* Parses argv into *out; returns 0 (after printing why) on a malformed command line. */
int parse_options(int argc, char **argv, HarnessOptions *out);

/* Reads every given table file into its bytes; returns 0 when one cannot be read. */
int load_tables(HarnessOptions *options);
void free_tables(HarnessOptions *options);

/* First ticks of one scenario run. */
typedef struct RunResult {
    long stop_tick;   /* POU stop tick, -1 if never stopped */
    long exact_first; /* first tick the plain SAT handle collides, unstopped, -1 if never */
} RunResult;

/* A trajectory scenario in table mode (table_mode.c): the POU runs on the table, the exact
 * model beside it; returns 0 when it could not start. */
int run_table_scenario(const char *cell_name, const char *case_name, const HarnessTable *table, RunResult *result);

/* The bad-input scenarios (bad_input.c): every documented error status, fail-closed outputs;
 * table-mode ones when T1's table is loaded. */
void bad_input(const HarnessOptions *options);

/* Two handles on reference cell `cell_name` for a protective scenario: *h with every robot's
 * stopping model `model` (warn_mm 10), in table mode on `table` when not NULL, *exact for the
 * exact model beside it; and the scenario (cell_name, case_name). Returns 0 after a failed
 * check naming `who` when one cannot be made (both handles are then destroyed and NULL). */
int open_protective(const char *who, const char *cell_name, const char *case_name, const DcStopConfig *model,
                    const HarnessTable *table, MrCell *cell, MrScenario *scenario, DcStopConfig stops[MR_MAX_ROBOTS],
                    DcCollider **h, DcCollider **exact);

#define STOP_SUBSTEPS 10 /* 0.1 ms steps per 1 ms tick of a simulated stop */

/* What simulated stops found. */
typedef struct StopStats {
    unsigned long stops;    /* stops simulated */
    unsigned long samples;  /* 0.1 ms steps checked with the exact model */
    unsigned long contacts; /* of those, steps where boxes touch (or the check failed) */
    double moving_ms;       /* time some robot was still moving */
} StopStats;

/* Advances every robot's stop by 0.1 ms and checks the TCPs with the exact handle; returns
 * nonzero while some robot still moves. */
int stop_substep(DcCollider *exact, const MrScenario *s, MrStop stop[MR_MAX_ROBOTS], StopStats *st);

/* The protective verdicts of a run, tick by tick. */
typedef struct VerdictTally {
    long first_warn, first_stop; /* -1: none */
    unsigned long n_warn, n_stop, n_bad_status;
    double min_clear; /* the smallest clearance reported (mm) */
    uint32_t stop_robot_a, stop_robot_b; /* the pair that limited the first STOP, DC_BOX_NONE if none */
} VerdictTally;

/* A tally of no ticks. */
VerdictTally tally_start(void);

/* Counts tick `tick`'s status, verdict and report; returns nonzero when the verdict is STOP. */
int tally_verdict(VerdictTally *t, long tick, DcStatus s, DcVerdict v, const DcProtectiveReport *rep);

/* The trajectory scenarios with the protective verdict (protective.c): at the first STOP the
 * robots stop as their stopping models say, and every 0.1 ms of the stop is checked for
 * contact with the exact model. --quick runs T1 collision only. */
void protective_scenarios(const HarnessOptions *options);

/* One scenario with the protective verdict, every robot with stopping model `model` (warn_mm
 * 10), in exact mode (`table` NULL) or table mode on a clearance table, with or without each
 * robot's programmed path ahead as its stop path, for n_ticks; the stop simulated at the
 * first STOP is checked every 0.1 ms for contact (protective.c). Prints one line (and in
 * table mode one more: the ticks answered by the lookup alone) and returns the tally. */
VerdictTally run_protective(const char *cell_name, const char *case_name, const char *model_name,
                            const DcStopConfig *model, const HarnessTable *table, int with_paths, long n_ticks);

/* The four-robot line (line.c): both cases in exact mode through the POU, and with the
 * protective verdict and a simulated stop. --quick runs the collision case in exact mode
 * only, --protective-quick both cases in exact mode only. */
void line_scenarios(const HarnessOptions *options);

/* The practical scenarios with the speed limits of the protective verdict applied as a speed
 * override (speed_override.c): cycle time against the unscaled cycle, STOP ticks, contacts.
 * Skipped with --quick and --protective-quick. */
void speed_override_scenarios(const HarnessOptions *options);

/* The timed protective query under the controller's clock (timing.c): called twice per cycle
 * on the collision scenarios (the second answer unchanged; the untimed call's second answer
 * compared with its first), and driven by schedules that repeat, skip, jump back and change
 * clocks, with a stop simulated after every FREE and WARN. --quick and --protective-quick run
 * T1 collision only, on 200 ticks. */
void timing_scenarios(const HarnessOptions *options);

/* The coordination in the tick loop (coordination.c): on T1 two robots whose programmes place
 * at the same point at the same ticks, every tick dc_coordinate's overrides applied to their
 * progress and the timed protective query with its cycle, a STOP carried out as a stop along
 * the paths; contact checked with the exact model every tick. --quick and --protective-quick
 * run its first ticks only. */
void coordination_scenarios(const HarnessOptions *options);

#endif /* HARNESS_H */
