/*
 * main.c: the C harness of delta-collide (thesis appendix A.1 and section 3.1.5, SPEC section 5).
 *
 * For each reference cell T1, T2, T3 it runs the thesis's two trajectory cases from
 * c_harness/scenarios.txt through the mock robotics API and the POU, 6,000 ticks of 1 ms:
 *   - "practical": the robots move toward each other and never collide: FREE on every tick;
 *   - "collision": the POU stops both robots at the first tick reporting COLLISION; that tick
 *     lies after tick 3000 and equals the first tick at which the exact model (a second
 *     handle with DC_METHOD_SAT, run alongside DC_METHOD_SAT_CACHE over the unstopped
 *     trajectory) collides.
 * On every tick the mock's own C kinematics is cross-checked against the library's. Then a
 * bad-input scenario checks every documented error status and the fail-closed outputs.
 *
 * Usage: c_harness [TMP_DIR]   (run from the repository root; TMP_DIR for a scratch file)
 * Prints one line per failed check, a summary per scenario, and finally `N passed, N failed`;
 * exits 0 only when nothing failed.
 */
#include "delta_collide.h"
#include "mock_robotics.h"
#include "pou.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define SCENARIO_FILE "c_harness/scenarios.txt"
#define IK_TOLERANCE 1e-9      /* rad: C IK vs dc_delta3_inverse_kinematics */
#define FK_TOLERANCE 1e-6      /* mm: C FK vs library FK, and FK(IK(p)) vs p */
#define STOP_AFTER_TICK 3000L  /* the collision case collides only in the last part of the run */

static int g_passed;
static int g_failed;

/* Counts one check; prints the message when it fails. */
static void check(int ok, const char *fmt, ...)
{
    va_list args;
    if (ok) {
        g_passed++;
        return;
    }
    g_failed++;
    fputs("FAIL: ", stdout);
    va_start(args, fmt);
    vprintf(fmt, args);
    va_end(args);
    fputc('\n', stdout);
}

static DcVec3 vec3(double x, double y, double z)
{
    DcVec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

static DcDelta3 dc_geometry(const MrGeometry *g)
{
    DcDelta3 d;
    d.f = g->f;
    d.rf = g->rf;
    d.re = g->re;
    d.e = g->e;
    d.theta_min = g->theta_min;
    d.theta_max = g->theta_max;
    return d;
}

static const char *cell_file(const char *cell)
{
    if (strcmp(cell, "T1") == 0) {
        return "cells/t1.toml";
    }
    if (strcmp(cell, "T2") == 0) {
        return "cells/t2.toml";
    }
    return "cells/t3.toml";
}

/* ------------------------------------------------------------ kinematics cross-check */

typedef struct KinStats {
    unsigned long ik_mismatch;   /* ticks where C and library IK disagree (status or > tolerance) */
    unsigned long fk_mismatch;
    long first_bad_tick;
    double max_dtheta;
    double max_fk_diff;
    double max_round_trip;
} KinStats;

/* Cross-checks the mock's IK/FK of one commanded TCP against the library's. */
static void cross_check_kinematics(const MrRobot *robot, const double commanded[3], MrStatus c_status,
                                   const double c_theta[3], const double c_tcp[3], long tick,
                                   KinStats *st)
{
    DcDelta3 g = dc_geometry(&robot->geometry);
    double lib_theta[3] = { 0.0, 0.0, 0.0 };
    DcVec3 lib_tcp = vec3(0.0, 0.0, 0.0);
    DcStatus s = dc_delta3_inverse_kinematics(&g, vec3(commanded[0], commanded[1], commanded[2]), lib_theta);
    int k, ok = (s == DC_STATUS_OK) == (c_status == MR_OK);
    if (ok && s == DC_STATUS_OK) {
        double dp = 0.0, rt = 0.0;
        for (k = 0; k < 3; ++k) {
            double d = fabs(lib_theta[k] - c_theta[k]);
            if (!(d <= IK_TOLERANCE)) {
                ok = 0;
            }
            if (d > st->max_dtheta) {
                st->max_dtheta = d;
            }
        }
        if (dc_delta3_forward_kinematics(&g, c_theta, &lib_tcp) != DC_STATUS_OK) {
            st->fk_mismatch++;
        } else {
            dp = fmax(fabs(lib_tcp.x - c_tcp[0]), fmax(fabs(lib_tcp.y - c_tcp[1]), fabs(lib_tcp.z - c_tcp[2])));
            for (k = 0; k < 3; ++k) {
                rt = fmax(rt, fabs(c_tcp[k] - commanded[k]));
            }
            st->max_fk_diff = fmax(st->max_fk_diff, dp);
            st->max_round_trip = fmax(st->max_round_trip, rt);
            if (!(dp <= FK_TOLERANCE) || !(rt <= FK_TOLERANCE)) {
                st->fk_mismatch++;
                if (st->first_bad_tick < 0) {
                    st->first_bad_tick = tick;
                }
            }
        }
    }
    if (!ok) {
        st->ik_mismatch++;
        if (st->first_bad_tick < 0) {
            st->first_bad_tick = tick;
        }
    }
}

/* ------------------------------------------------------------ one trajectory scenario */

typedef struct RunResult {
    long stop_tick;        /* POU stop tick, -1 if never stopped */
    long exact_first;      /* first tick the plain SAT handle collides, unstopped, -1 if never */
} RunResult;

/* "none" for -1, else the tick number. */
static void tick_text(long tick, char out[24])
{
    if (tick < 0) {
        strcpy(out, "none");
    } else {
        sprintf(out, "%ld", tick);
    }
}

static void to_dc(const MrTickState *st, size_t n, DcVec3 out[MR_MAX_ROBOTS])
{
    size_t j;
    for (j = 0; j < n; ++j) {
        out[j] = vec3(st->tcp[j][0], st->tcp[j][1], st->tcp[j][2]);
    }
}

static int run_scenario(const char *cell_name, const char *case_name, RunResult *result)
{
    MrCell cell;
    MrScenario scenario;
    MrClock clock;
    DcRobotConfig robots_cache[MR_MAX_ROBOTS], robots_plain[MR_MAX_ROBOTS];
    DcCellConfig config_cache, config_plain;
    Pou pou;
    DcCollider *from_file = NULL, *exact = NULL, *shadow = NULL;
    KinStats kin;
    int stopped[MR_MAX_ROBOTS] = { 0 };
    double held[MR_MAX_ROBOTS][3];
    unsigned long mock_errors = 0, status_errors = 0, file_disagree = 0, method_disagree = 0;
    unsigned long free_ticks = 0, not_held = 0;
    long first_file_disagree = -1, first_method_disagree = -1, first_not_free = -1;
    int practical = strcmp(case_name, "practical") == 0;
    MrStatus ms;
    size_t j;
    DcStatus s;

    result->stop_tick = -1;
    result->exact_first = -1;
    memset(&kin, 0, sizeof kin);
    kin.first_bad_tick = -1;
    memset(held, 0, sizeof held);

    ms = mr_register_cell(cell_name, &cell);
    check(ms == MR_OK, "%s: registry has no cell", cell_name);
    if (ms != MR_OK) {
        return -1;
    }
    ms = mr_load_scenario(SCENARIO_FILE, cell_name, case_name, cell.n_robots, &scenario);
    check(ms == MR_OK, "%s %s: cannot load %s: %s", cell_name, case_name, SCENARIO_FILE, mr_status_str(ms));
    if (ms != MR_OK) {
        return -1;
    }

    /* Start-up: the POU from the mock's configuration, a second handle from the TOML file. */
    pou_cell_config(&cell, DC_METHOD_SAT_CACHE, robots_cache, &config_cache);
    pou_cell_config(&cell, DC_METHOD_SAT, robots_plain, &config_plain);
    s = pou_init(&pou, &config_cache);
    check(s == DC_STATUS_OK && pou.handle != NULL, "%s: pou_init: %s", cell_name, dc_status_str(s));
    s = dc_init_from_cell_file(cell_file(cell_name), &from_file);
    check(s == DC_STATUS_OK && from_file != NULL, "%s: dc_init_from_cell_file(%s): %s", cell_name,
          cell_file(cell_name), dc_status_str(s));
    s = dc_init(&config_plain, &exact);
    check(s == DC_STATUS_OK, "%s: dc_init SAT: %s", cell_name, dc_status_str(s));
    s = dc_init(&config_cache, &shadow);
    check(s == DC_STATUS_OK, "%s: dc_init SAT_CACHE: %s", cell_name, dc_status_str(s));
    if (pou.handle == NULL || from_file == NULL || exact == NULL || shadow == NULL) {
        pou_destroy(&pou);
        dc_destroy(from_file);
        dc_destroy(exact);
        dc_destroy(shadow);
        return -1;
    }
    check(dc_robot_count(pou.handle) == cell.n_robots && dc_robot_count(from_file) == cell.n_robots,
          "%s: robot count %lu (config) / %lu (file), expected %lu", cell_name,
          (unsigned long)dc_robot_count(pou.handle), (unsigned long)dc_robot_count(from_file),
          (unsigned long)cell.n_robots);
    check(dc_pair_count(pou.handle) == 1 && dc_pair_count(from_file) == 1,
          "%s: pair count %lu (config) / %lu (file), expected 1 (the reach disks overlap)", cell_name,
          (unsigned long)dc_pair_count(pou.handle), (unsigned long)dc_pair_count(from_file));

    /* The 1 ms tick loop: no allocation in here. */
    for (mr_clock_start(&clock); clock.tick < MR_TICKS_PER_RUN; mr_clock_advance(&clock)) {
        MrTickState free_run, pou_run;
        DcVec3 tcps_free[MR_MAX_ROBOTS], tcps_pou[MR_MAX_ROBOTS];
        DcVerdict v_pou, v_file = DC_VERDICT_STOP, v_exact = DC_VERDICT_STOP, v_shadow = DC_VERDICT_STOP;
        DcQueryReport r_file, r_exact, r_shadow;
        DcStatus s_file, s_exact, s_shadow;
        long tick = clock.tick;

        /* The unstopped trajectory: kinematics cross-check and the exact model. */
        if (mr_robot_state(&cell, &scenario, tick, NULL, NULL, &free_run) != MR_OK) {
            mock_errors++;
        }
        for (j = 0; j < cell.n_robots; ++j) {
            cross_check_kinematics(&cell.robots[j], free_run.commanded[j], free_run.status[j], free_run.theta[j],
                                   free_run.tcp[j], tick, &kin);
        }
        to_dc(&free_run, cell.n_robots, tcps_free);
        s_exact = dc_query(exact, tcps_free, cell.n_robots, &v_exact, &r_exact);
        s_shadow = dc_query(shadow, tcps_free, cell.n_robots, &v_shadow, &r_shadow);
        if (s_exact != DC_STATUS_OK || s_shadow != DC_STATUS_OK) {
            status_errors++;
        }
        if (v_exact != v_shadow || r_exact.colliding_pairs != r_shadow.colliding_pairs) {
            method_disagree++;
            if (first_method_disagree < 0) {
                first_method_disagree = tick;
            }
        }
        if (v_exact == DC_VERDICT_COLLISION && result->exact_first < 0) {
            result->exact_first = tick;
        }

        /* What the controller runs: robots stop when the POU says so. */
        if (mr_robot_state(&cell, &scenario, tick, stopped, (const double(*)[3])held, &pou_run) != MR_OK) {
            mock_errors++;
        }
        to_dc(&pou_run, cell.n_robots, tcps_pou);
        v_pou = pou_query(&pou, tick, tcps_pou, cell.n_robots);
        if (pou.last_status != DC_STATUS_OK) {
            status_errors++;
        }
        if (v_pou == DC_VERDICT_FREE) {
            free_ticks++;
        } else if (first_not_free < 0) {
            first_not_free = tick;
        }
        s_file = dc_query(from_file, tcps_pou, cell.n_robots, &v_file, &r_file);
        if (s_file != pou.last_status || v_file != v_pou
            || r_file.colliding_pairs != pou.last_report.colliding_pairs) {
            file_disagree++;
            if (first_file_disagree < 0) {
                first_file_disagree = tick;
            }
        }
        if (pou.stop_requested && tick > pou.stop_tick && v_pou != DC_VERDICT_COLLISION) {
            not_held++; /* held at the colliding pose, it must keep colliding */
        }
        if (pou.stop_requested && !stopped[0]) {
            /* Stop both robots where they are: they hold this tick's commanded TCP. */
            for (j = 0; j < cell.n_robots; ++j) {
                stopped[j] = 1;
                memcpy(held[j], pou_run.commanded[j], sizeof held[j]);
            }
            if (pou.stop_verdict == DC_VERDICT_COLLISION) {
                DcPairResult pairs[4];
                size_t n_pairs = 99;
                DcStatus sp = dc_pair_results(pou.handle, pairs, 4, &n_pairs);
                check(sp == DC_STATUS_OK && n_pairs == 1 && pairs[0].robot_a == 0 && pairs[0].robot_b == 1
                          && pairs[0].collides == 1 && pairs[0].box_a == pou.last_report.first_box_a
                          && pairs[0].box_b == pou.last_report.first_box_b && pairs[0].box_a != DC_BOX_NONE,
                      "%s %s: dc_pair_results at the stop tick disagree with the report", cell_name, case_name);
                check(pou.last_report.verdict == DC_VERDICT_COLLISION && pou.last_report.colliding_pairs == 1
                          && pou.last_report.first_robot_a == 0 && pou.last_report.first_robot_b == 1
                          && pou.last_report.unreachable_mask == 0,
                      "%s %s: report at the stop tick is inconsistent", cell_name, case_name);
            }
        }
    }
    result->stop_tick = pou.stop_tick;

    check(mock_errors == 0, "%s %s: %lu mock kinematics errors (a waypoint is unreachable?)", cell_name, case_name,
          mock_errors);
    check(kin.ik_mismatch == 0, "%s %s: C IK disagrees with dc_delta3_inverse_kinematics on %lu ticks (first %ld)",
          cell_name, case_name, kin.ik_mismatch, kin.first_bad_tick);
    check(kin.fk_mismatch == 0, "%s %s: C FK disagrees with the library or the round trip on %lu ticks", cell_name,
          case_name, kin.fk_mismatch);
    check(status_errors == 0, "%s %s: %lu queries did not return OK", cell_name, case_name, status_errors);
    check(method_disagree == 0, "%s %s: SAT and SAT_CACHE disagree on %lu ticks (first %ld)", cell_name, case_name,
          method_disagree, first_method_disagree);
    check(file_disagree == 0, "%s %s: handle from %s disagrees with the mock's config on %lu ticks (first %ld)",
          cell_name, case_name, cell_file(cell_name), file_disagree, first_file_disagree);
    if (practical) {
        check(free_ticks == MR_TICKS_PER_RUN, "%s practical: FREE on %lu of %d ticks (first other verdict at %ld)",
              cell_name, free_ticks, MR_TICKS_PER_RUN, first_not_free);
        check(result->exact_first < 0, "%s practical: the exact model collides at tick %ld", cell_name,
              result->exact_first);
    } else {
        check(pou.stop_tick >= 0 && pou.stop_verdict == DC_VERDICT_COLLISION,
              "%s collision: the POU never reported a collision", cell_name);
        check(pou.stop_tick > STOP_AFTER_TICK, "%s collision: stop tick %ld is not after tick %ld", cell_name,
              pou.stop_tick, STOP_AFTER_TICK);
        check(result->exact_first >= 0 && pou.stop_tick <= result->exact_first,
              "%s collision: stop tick %ld is later than the first exact collision tick %ld", cell_name,
              pou.stop_tick, result->exact_first);
        check(pou.stop_tick == result->exact_first, "%s collision: stop tick %ld != first exact collision tick %ld",
              cell_name, pou.stop_tick, result->exact_first);
        check(not_held == 0, "%s collision: %lu ticks after the stop were not COLLISION at the held pose",
              cell_name, not_held);
    }
    {
        char stop_text[24], exact_text[24];
        tick_text(pou.stop_tick, stop_text);
        tick_text(result->exact_first, exact_text);
        printf("%s %-9s: first collision tick %s (POU stop), %s (exact SAT, unstopped); FREE ticks %lu/%d; "
               "max |dtheta| %.2e rad, max |FK C - FK lib| %.2e mm, max |FK(IK(p)) - p| %.2e mm\n",
               cell_name, case_name, stop_text, exact_text, free_ticks, MR_TICKS_PER_RUN, kin.max_dtheta,
               kin.max_fk_diff, kin.max_round_trip);
    }

    pou_destroy(&pou);
    pou_destroy(&pou); /* twice: the POU must tolerate it */
    dc_destroy(from_file);
    dc_destroy(exact);
    dc_destroy(shadow);
    return 0;
}

/* ------------------------------------------------------------ kinematics grid */

/* C IK vs library IK on a grid through and beyond the workspace: same reachability, same angles. */
static void kinematics_grid(void)
{
    MrRobot robot = mr_thesis_robot("A", 0.0, 0.0, 0.0, 0.0);
    DcDelta3 g = dc_geometry(&robot.geometry);
    unsigned long n = 0, reach = 0, disagree = 0;
    double max_d = 0.0;
    int ix, iy, iz, k;
    for (iz = 0; iz <= 24; ++iz) {
        for (iy = -12; iy <= 12; ++iy) {
            for (ix = -12; ix <= 12; ++ix) {
                double p[3], th_c[3] = { 0.0, 0.0, 0.0 }, th_l[3] = { 0.0, 0.0, 0.0 };
                MrStatus sc;
                DcStatus sl;
                p[0] = 23.7 * ix + 0.31;
                p[1] = 23.3 * iy - 0.17;
                p[2] = -250.0 - 17.9 * iz;
                sc = mr_inverse_kinematics(&robot.geometry, p, th_c);
                sl = dc_delta3_inverse_kinematics(&g, vec3(p[0], p[1], p[2]), th_l);
                n++;
                if ((sc == MR_OK) != (sl == DC_STATUS_OK)
                    || (sl != DC_STATUS_OK && sl != DC_STATUS_UNREACHABLE)) {
                    disagree++;
                    continue;
                }
                if (sc == MR_OK) {
                    reach++;
                    for (k = 0; k < 3; ++k) {
                        double d = fabs(th_c[k] - th_l[k]);
                        max_d = fmax(max_d, d);
                        if (!(d <= IK_TOLERANCE)) {
                            disagree++;
                        }
                    }
                }
            }
        }
    }
    check(disagree == 0, "kinematics grid: %lu disagreements between C IK and the library", disagree);
    check(reach > n / 4 && reach < n, "kinematics grid: %lu of %lu reachable (expected a mix)", reach, n);
    printf("kinematics grid: %lu TCPs, %lu reachable, max |dtheta| %.2e rad\n", n, reach, max_d);
}

/* ------------------------------------------------------------ bad input */

/* A query that must fail: checks status, that the pre-set FREE verdict became STOP, and the report. */
static void expect_query(const char *what, DcCollider *h, const DcVec3 *tcps, size_t n, DcStatus expected,
                         int expect_mask, uint32_t mask)
{
    DcVerdict v = DC_VERDICT_FREE;
    DcQueryReport rep;
    DcStatus s;
    memset(&rep, 0, sizeof rep);
    rep.verdict = DC_VERDICT_FREE;
    s = dc_query(h, tcps, n, &v, &rep);
    check(s == expected, "bad input, %s: status %u (%s), expected %u", what, (unsigned)s, dc_status_str(s),
          (unsigned)expected);
    check(v == DC_VERDICT_STOP, "bad input, %s: verdict %u, expected STOP", what, (unsigned)v);
    check(rep.verdict == DC_VERDICT_STOP, "bad input, %s: report verdict %u, expected STOP", what,
          (unsigned)rep.verdict);
    if (expect_mask) {
        check(rep.unreachable_mask == mask, "bad input, %s: unreachable_mask %u, expected %u", what,
              (unsigned)rep.unreachable_mask, (unsigned)mask);
    }
    /* The same call without a report must give the same status and verdict. */
    v = DC_VERDICT_FREE;
    s = dc_query(h, tcps, n, &v, NULL);
    check(s == expected && v == DC_VERDICT_STOP, "bad input, %s (no report): status %u verdict %u", what,
          (unsigned)s, (unsigned)v);
}

static int dummy_object;

/* dc_init must fail with `expected` and leave *out_handle NULL (pre-set to a dangling value). */
static void expect_init(const char *what, const DcCellConfig *config, DcStatus expected)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init(config, &h);
    DcVerdict v = DC_VERDICT_FREE;
    DcVec3 tcps[2];
    check(s == expected, "bad input, dc_init %s: status %u (%s), expected %u", what, (unsigned)s, dc_status_str(s),
          (unsigned)expected);
    check(h == NULL, "bad input, dc_init %s: out_handle not NULL after a failed init", what);
    if (h == NULL) {
        tcps[0] = vec3(0.0, 0.0, -450.0);
        tcps[1] = vec3(0.0, 0.0, -450.0);
        s = dc_query(h, tcps, 2, &v, NULL);
        check(s == DC_STATUS_NULL_POINTER && v == DC_VERDICT_STOP,
              "bad input, query after failed dc_init %s: status %u verdict %u", what, (unsigned)s, (unsigned)v);
    } else if (h != (DcCollider *)(void *)&dummy_object) {
        dc_destroy(h);
    }
}

static void expect_init_file(const char *what, const char *path, DcStatus expected)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init_from_cell_file(path, &h);
    check(s == expected, "bad input, dc_init_from_cell_file %s: status %u (%s), expected %u", what, (unsigned)s,
          dc_status_str(s), (unsigned)expected);
    check(h == NULL, "bad input, dc_init_from_cell_file %s: out_handle not NULL after a failed init", what);
    if (h != NULL && h != (DcCollider *)(void *)&dummy_object) {
        dc_destroy(h);
    }
}

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return 0;
    }
    fputs(text, f);
    return fclose(f) == 0;
}

static DcRobotConfig many_robots[33];

static void bad_input(const char *tmp_dir)
{
    MrCell cell;
    DcRobotConfig robots[MR_MAX_ROBOTS], bad[MR_MAX_ROBOTS];
    DcCellConfig config, broken;
    DcCollider *h = NULL;
    DcVec3 tcps[3];
    DcVerdict v;
    DcQueryReport rep;
    DcStatus s;
    DcDelta3 g;
    DcPairResult pairs[2];
    double theta[3];
    char path[512];
    unsigned code;
    size_t len;
    const double qnan = NAN;
    const double pinf = INFINITY;

    mr_register_cell("T1", &cell);
    pou_cell_config(&cell, DC_METHOD_SAT_CACHE, robots, &config);
    s = dc_init(&config, &h);
    check(s == DC_STATUS_OK && h != NULL, "bad input: dc_init T1: %s", dc_status_str(s));
    if (h == NULL) {
        return;
    }
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    tcps[2] = vec3(0.0, 0.0, -450.0);

    /* A good query first: OK and a decided verdict. */
    v = DC_VERDICT_STOP;
    s = dc_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && (v == DC_VERDICT_FREE || v == DC_VERDICT_COLLISION),
          "bad input: the good query gave status %u verdict %u", (unsigned)s, (unsigned)v);

    expect_query("NULL handle", NULL, tcps, 2, DC_STATUS_NULL_POINTER, 0, 0);
    expect_query("NULL tcps", h, NULL, 2, DC_STATUS_NULL_POINTER, 0, 0);
    rep.verdict = DC_VERDICT_FREE;
    s = dc_query(h, tcps, 2, NULL, &rep);
    check(s == DC_STATUS_NULL_POINTER && rep.verdict == DC_VERDICT_STOP,
          "bad input, NULL out_verdict: status %u, report verdict %u", (unsigned)s, (unsigned)rep.verdict);

    tcps[0] = vec3(qnan, 0.0, -450.0);
    expect_query("NaN TCP of robot 0", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 1u);
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, pinf, -450.0);
    expect_query("infinite TCP of robot 1", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 2u);
    tcps[1] = vec3(0.0, 0.0, -pinf);
    expect_query("-infinite z of robot 1", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 2u);
    tcps[1] = vec3(0.0, 0.0, -900.0);
    expect_query("unreachable z = -900 of robot 1", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 2u);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    tcps[0] = vec3(0.0, 0.0, 100.0);
    expect_query("unreachable z = +100 of robot 0", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 1u);
    tcps[1] = vec3(0.0, 0.0, 100.0);
    expect_query("both unreachable", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 3u);
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    expect_query("n_tcps = 1", h, tcps, 1, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);
    expect_query("n_tcps = 3", h, tcps, 3, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);
    expect_query("n_tcps = 0", h, tcps, 0, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);

    /* After all that the handle still answers good queries. */
    v = DC_VERDICT_STOP;
    s = dc_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && v != DC_VERDICT_STOP, "bad input: handle unusable after errors (status %u)",
          (unsigned)s);

    /* dc_pair_results */
    s = dc_pair_results(NULL, pairs, 2, &len);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_pair_results NULL handle: %u", (unsigned)s);
    s = dc_pair_results(h, NULL, 2, &len);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_pair_results NULL out: %u", (unsigned)s);
    s = dc_pair_results(h, pairs, 2, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_pair_results NULL out_len: %u", (unsigned)s);
    len = 99;
    s = dc_pair_results(h, pairs, 0, &len);
    check(s == DC_STATUS_INVALID_ARGUMENT && len == 1,
          "bad input, dc_pair_results capacity 0: status %u, out_len %lu (expected the count needed, 1)", (unsigned)s,
          (unsigned long)len);
    check(dc_robot_count(NULL) == 0 && dc_pair_count(NULL) == 0, "bad input: counts of a NULL handle are not 0");
    dc_destroy(h);
    h = NULL;

    /* dc_init */
    expect_init("NULL config", NULL, DC_STATUS_NULL_POINTER);
    s = dc_init(&config, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init NULL out_handle: %u", (unsigned)s);
    broken = config;
    broken.n_robots = 0;
    expect_init("zero robots", &broken, DC_STATUS_INVALID_CONFIG);
    broken = config;
    broken.robots = NULL;
    expect_init("NULL robots", &broken, DC_STATUS_NULL_POINTER);
    memcpy(bad, robots, sizeof bad);
    broken = config;
    broken.robots = bad;
    bad[1].geometry.rf = -150.0;
    expect_init("negative rf", &broken, DC_STATUS_INVALID_CONFIG);
    bad[1].geometry.rf = 150.0;
    bad[0].half_depth = -17.5;
    expect_init("negative half_depth", &broken, DC_STATUS_INVALID_CONFIG);
    bad[0].half_depth = 17.5;
    bad[0].margin = -1.0;
    expect_init("negative margin", &broken, DC_STATUS_INVALID_CONFIG);
    bad[0].margin = 0.0;
    bad[1].geometry.theta_min = 1.0;
    bad[1].geometry.theta_max = -1.0;
    expect_init("empty motor range", &broken, DC_STATUS_INVALID_CONFIG);
    bad[1].geometry.theta_min = robots[1].geometry.theta_min;
    bad[1].geometry.theta_max = robots[1].geometry.theta_max;
    {
        /* NaN in a configuration: documented as INVALID_CONFIG. */
        DcCollider *hn = (DcCollider *)(void *)&dummy_object;
        bad[0].translation.x = qnan;
        s = dc_init(&broken, &hn);
        check(s == DC_STATUS_INVALID_CONFIG && hn == NULL,
              "bad input, dc_init NaN translation: status %u, handle %s", (unsigned)s, hn == NULL ? "NULL" : "set");
        bad[0].translation.x = 0.0;
    }
    broken = config;
    broken.method = 7;
    expect_init("unknown method", &broken, DC_STATUS_INVALID_CONFIG);
    {
        size_t i;
        for (i = 0; i < 33; ++i) {
            many_robots[i] = robots[0];
            many_robots[i].translation.x = 450.0 * (double)i;
        }
        broken = config;
        broken.robots = many_robots;
        broken.n_robots = 33;
        expect_init("33 robots", &broken, DC_STATUS_INVALID_CONFIG);
    }

    /* dc_init_from_cell_file */
    expect_init_file("NULL path", NULL, DC_STATUS_NULL_POINTER);
    s = dc_init_from_cell_file("cells/t1.toml", NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init_from_cell_file NULL out_handle: %u", (unsigned)s);
    expect_init_file("missing path", "cells/no_such_cell_file.toml", DC_STATUS_IO);
    sprintf(path, "%.400s/c_harness_malformed_cell.toml", tmp_dir);
    check(write_file(path, "[[robot]\nname = \"A\"\nf = 100.0 = 3\n"), "cannot write %s", path);
    expect_init_file("malformed TOML", path, DC_STATUS_PARSE);
    check(write_file(path, "name = \"bad\"\n[[robot]]\nname = \"A\"\nplacement = { alpha_deg = 30.0, t = [1.0, 2.0] }\n"), "cannot write %s",
          path);
    expect_init_file("wrong schema", path, DC_STATUS_PARSE);
    check(write_file(path, "[[robot]]\nname = \"A\"\ngeometry = { f = -100.0, rf = 150.0, re = 400.0, e = 40.0, "
                           "theta_min_deg = -90.0, theta_max_deg = 120.0 }\n"),
          "cannot write %s", path);
    expect_init_file("negative f in the file", path, DC_STATUS_INVALID_CONFIG);
    remove(path);
    expect_init_file("path not UTF-8", "cells/\xff\xfe.toml", DC_STATUS_INVALID_ARGUMENT);

    /* Teardown and strings. */
    dc_destroy(NULL); /* a no-op: reaching the next line is the test */
    for (code = 0; code <= 9; ++code) {
        const char *text = dc_status_str(code);
        check(text != NULL && text[0] != '\0', "dc_status_str(%u) is empty", code);
    }
    {
        const char *unknown = dc_status_str(12345u);
        check(unknown != NULL && unknown[0] != '\0' && strcmp(unknown, dc_status_str(DC_STATUS_OK)) != 0,
              "dc_status_str(12345) does not say unknown");
    }
    check(dc_version() != NULL && dc_version()[0] != '\0', "dc_version is empty");

    /* Kinematics entry points. */
    g = dc_geometry(&cell.robots[0].geometry);
    s = dc_delta3_inverse_kinematics(NULL, vec3(0.0, 0.0, -450.0), theta);
    check(s == DC_STATUS_NULL_POINTER, "bad input, IK NULL geometry: %u", (unsigned)s);
    s = dc_delta3_inverse_kinematics(&g, vec3(0.0, 0.0, -450.0), NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, IK NULL out_theta: %u", (unsigned)s);
    s = dc_delta3_inverse_kinematics(&g, vec3(qnan, 0.0, -450.0), theta);
    check(s == DC_STATUS_NON_FINITE, "bad input, IK NaN: %u", (unsigned)s);
    s = dc_delta3_inverse_kinematics(&g, vec3(0.0, 0.0, -900.0), theta);
    check(s == DC_STATUS_UNREACHABLE, "bad input, IK z = -900: %u", (unsigned)s);
    s = dc_delta3_forward_kinematics(&g, NULL, &tcps[0]);
    check(s == DC_STATUS_NULL_POINTER, "bad input, FK NULL theta: %u", (unsigned)s);
    g.rf = -150.0;
    s = dc_delta3_inverse_kinematics(&g, vec3(0.0, 0.0, -450.0), theta);
    check(s == DC_STATUS_INVALID_CONFIG, "bad input, IK negative rf: %u", (unsigned)s);
    g.rf = 150.0;
    theta[0] = theta[1] = theta[2] = 0.3;
    s = dc_delta3_forward_kinematics(&g, theta, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, FK NULL out_tcp: %u", (unsigned)s);
    theta[1] = qnan;
    s = dc_delta3_forward_kinematics(&g, theta, &tcps[0]);
    check(s == DC_STATUS_NON_FINITE, "bad input, FK NaN angle: %u", (unsigned)s);
    printf("bad input: done\n");
}

int main(int argc, char **argv)
{
    static const char *cells[] = { "T1", "T2", "T3" };
    static const char *cases[] = { "practical", "collision" };
    const char *tmp_dir = argc > 1 ? argv[1] : ".";
    size_t c, k;
    printf("delta-collide C harness, library %s\n", dc_version());
    kinematics_grid();
    for (c = 0; c < 3; ++c) {
        for (k = 0; k < 2; ++k) {
            RunResult result;
            run_scenario(cells[c], cases[k], &result);
        }
    }
    bad_input(tmp_dir);
    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}
