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
 * On every tick the mock's own C kinematics is cross-checked against the library's. When a
 * table file is given for the cell, each scenario runs once more with the POU in table mode
 * (table_mode.c), and once with the protective verdict and a simulated stop (protective.c);
 * the practical ones once more with the speed limits applied as a speed override
 * (speed_override.c). The four-robot line (line.c) runs its two cases in exact mode and with
 * the protective verdict. The timed protective query (timing.c) is called twice per cycle and
 * driven by schedules that repeat, skip and go back in time. The coordination (coordination.c)
 * keeps two robots whose programmes place at the same point apart. Then the bad-input scenarios
 * (bad_input.c) check every documented error status and the fail-closed outputs, in both
 * modes, and the function block around the POU (pou_fb_call, plc/README.md's state machine)
 * goes through its lifecycle.
 *
 * Usage (from the repository root):
 *   c_harness [--quick] [--tmp DIR] [--table T1=PATH] [--table T2=PATH] [--table T3=PATH]
 * --quick runs only the T1 collision scenario and the line's (for valgrind); see harness.h.
 * Prints one line per failed check, a summary per scenario, and finally `N passed, N failed`;
 * exits 0 only when nothing failed.
 */
#include "harness.h"
#include "pou.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define IK_TOLERANCE 1e-9      /* rad: C IK vs dc_delta3_inverse_kinematics */
#define FK_TOLERANCE 1e-6      /* mm: C FK vs library FK, and FK(IK(p)) vs p */

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
    check(s == DC_STATUS_OK && pou.handle != NULL && dc_mode(pou.handle) == DC_MODE_EXACT, "%s: pou_init: %s",
          cell_name, dc_status_str(s));
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

/* ------------------------------------------------------------ the function block's lifecycle */

/* One step of the function block scenario: what one call must leave in the outputs. */
typedef struct FbExpect {
    int valid, error;
    uint32_t error_id;
    unsigned diag_code;
    DcVerdict verdict;
} FbExpect;

static FbExpect fb_expect(int valid, int error, uint32_t error_id, unsigned diag_code, DcVerdict verdict)
{
    FbExpect e;
    e.valid = valid;
    e.error = error;
    e.error_id = error_id;
    e.diag_code = diag_code;
    e.verdict = verdict;
    return e;
}

/* One call of the block, its transitions printed as `T<row> FROM -> TO` (tests/c_harness.rs
 * compares them with plc/README.md's table) and its outputs checked against want. */
static void fb_step(PouFb *fb, int step, const char *what, FbExpect w)
{
    const FbExpect *want = &w;
    char taken[96] = "";
    int k;
    pou_fb_call(fb);
    for (k = 0; k < fb->n_taken; ++k) {
        char one[40];
        sprintf(one, "%sT%d %s -> %s", k > 0 ? ", " : "", fb->taken[k].row, pou_fb_state_name(fb->taken[k].from),
                pou_fb_state_name(fb->taken[k].to));
        strcat(taken, one);
    }
    printf("pou fb step %d %s: %s; valid %d busy %d error %d error_id %lu diag 16#%04X verdict %lu\n", step, what,
           taken, fb->valid, fb->busy, fb->error, (unsigned long)fb->error_id, fb->diag_code,
           (unsigned long)fb->verdict);
    check(fb->n_taken >= 1, "pou fb step %d %s: no transition", step, what);
    check(fb->valid == want->valid && fb->busy == want->valid && fb->error == want->error,
          "pou fb step %d %s: valid %d busy %d error %d, expected valid %d error %d", step, what, fb->valid, fb->busy,
          fb->error, want->valid, want->error);
    check(fb->error_id == want->error_id && fb->diag_code == want->diag_code,
          "pou fb step %d %s: error_id %lu diag 16#%04X, expected %lu 16#%04X", step, what,
          (unsigned long)fb->error_id, fb->diag_code, (unsigned long)want->error_id, want->diag_code);
    check(fb->verdict == want->verdict && fb->report.verdict == want->verdict,
          "pou fb step %d %s: verdict %lu (report %lu), expected %lu", step, what, (unsigned long)fb->verdict,
          (unsigned long)fb->report.verdict, (unsigned long)want->verdict);
    /* The rule of both blocks, whatever the step: STOP whenever Valid is FALSE. */
    check(fb->valid || (fb->verdict == DC_VERDICT_STOP && !fb->free), "pou fb step %d %s: not valid but not STOP",
          step, what);
    check(fb->free == (fb->valid && fb->verdict == DC_VERDICT_FREE), "pou fb step %d %s: free %d", step, what,
          fb->free);
    check(fb->error || fb->state != POU_FB_ERROR, "pou fb step %d %s: error state without Error", step, what);
}

/* FB_DeltaCollide's lifecycle on T1, executed: enable with a table that fails validation, a
 * reset with Enable held (the restart interlock), re-enable, FREE and COLLISION ticks, NaN
 * TCPs, disable and reset in error, too many robots, and a plain disable. The table mode runs
 * on T1's table when it was given, else exact mode. */
static void pou_fb_scenario(const HarnessOptions *options)
{
    static const uint8_t zeros[4096];
    const HarnessTable *t1 = &options->tables[0];
    const uint8_t *bad = t1->bytes != NULL ? t1->bytes : zeros;
    const size_t bad_len = t1->bytes != NULL && t1->len > 4096 ? 4096 : sizeof zeros;
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcCollider *probe = NULL;
    MrCell cell;
    PouFb fb;
    DcStatus bad_status;
    int step = 0;
    const DcVerdict stop = DC_VERDICT_STOP;

    if (!check(mr_register_cell("T1", &cell) == MR_OK, "pou fb: registry has no cell T1")) {
        return;
    }
    pou_cell_config(&cell, DC_METHOD_SAT, robots, &config);
    /* The status the library gives these bytes directly: the block must report it unchanged. */
    bad_status = dc_init_with_table(&config, bad, bad_len, &probe);
    check(probe == NULL && bad_status >= DC_STATUS_TABLE_TRUNCATED && bad_status <= DC_STATUS_TABLE_WRONG_PAIR
              && bad_status != DC_STATUS_IMPLAUSIBLE_MOTION,
          "pou fb: the bad table's init gives %s, not a table status", dc_status_str(bad_status));
    check(t1->bytes == NULL || bad_status == DC_STATUS_TABLE_TRUNCATED, "pou fb: T1's table cut to 4096 bytes: %s",
          dc_status_str(bad_status));
    dc_destroy(probe);

    pou_fb_start(&fb);
    fb.config = &config;
    fb.n_robots = 2;
    fb.tcps[0] = vec3(-150.0, 0.0, -450.0); /* standing apart: FREE */
    fb.tcps[1] = vec3(150.0, 0.0, -450.0);

    fb_step(&fb, ++step, "idle", fb_expect(0, 0, 0, 0x0000u, stop));
    fb.enable = 1, fb.table = bad, fb.table_len = bad_len;
    fb_step(&fb, ++step, "enable with a table that fails validation",
            fb_expect(0, 1, bad_status, 0xC100u | bad_status, stop));
    check(fb.handle == NULL && fb.init_message[0] != '\0', "pou fb: no InitMessage after the failed init");
    check(t1->bytes == NULL || strstr(fb.init_message, "truncated") != NULL, "pou fb: InitMessage `%s`",
          fb.init_message);
    fb_step(&fb, ++step, "error held", fb_expect(0, 1, bad_status, 0xC100u | bad_status, stop));
    fb.reset = 1;
    fb_step(&fb, ++step, "reset with Enable held", fb_expect(0, 0, 0, 0x0001u, stop));
    fb.reset = 0;
    fb_step(&fb, ++step, "Enable held after the reset (restart interlock)", fb_expect(0, 0, 0, 0x0001u, stop));
    fb.enable = 0;
    fb_step(&fb, ++step, "disable", fb_expect(0, 0, 0, 0x0000u, stop));

    fb.enable = 1, fb.table = t1->bytes, fb.table_len = t1->len;
    fb_step(&fb, ++step, t1->bytes != NULL ? "re-enable (table mode), apart" : "re-enable (exact mode), apart",
            fb_expect(1, 0, 0, 0x8000u, DC_VERDICT_FREE));
    check(dc_mode(fb.handle) == (t1->bytes != NULL ? DC_MODE_TABLE : DC_MODE_EXACT), "pou fb: mode %lu",
          (unsigned long)dc_mode(fb.handle));
    fb.tcps[0] = vec3(180.0, 0.0, -450.0); /* the README's colliding configuration */
    fb.tcps[1] = vec3(-180.0, 0.0, -450.0);
    fb_step(&fb, ++step, "colliding TCPs", fb_expect(1, 0, 0, 0x8001u, DC_VERDICT_COLLISION));
    fb.tcps[0].x = NAN;
    fb_step(&fb, ++step, "NaN TCPs", fb_expect(0, 1, DC_STATUS_NON_FINITE, 0xC202u, stop));
    check(fb.report.unreachable_mask == 1u && fb.handle != NULL, "pou fb: NaN: mask %lu, handle kept %d",
          (unsigned long)fb.report.unreachable_mask, fb.handle != NULL);
    fb.tcps[0].x = 180.0; /* finite again: the error stays latched */
    fb_step(&fb, ++step, "finite TCPs, error latched", fb_expect(0, 1, DC_STATUS_NON_FINITE, 0xC202u, stop));
    fb.enable = 0;
    fb_step(&fb, ++step, "disable in error", fb_expect(0, 1, DC_STATUS_NON_FINITE, 0xC202u, stop));
    check(fb.handle == NULL, "pou fb: the handle outlived Enable FALSE in error");
    fb.reset = 1;
    fb_step(&fb, ++step, "reset", fb_expect(0, 0, 0, 0x0000u, stop));

    fb.reset = 0, fb.enable = 1, fb.table = NULL, fb.n_robots = DC_MAX_ROBOTS + 1;
    fb_step(&fb, ++step, "enable (exact mode) with too many robots",
            fb_expect(0, 1, POU_FB_ERR_TOO_MANY_ROBOTS, 0xC301u, stop));
    fb.enable = 0;
    fb_step(&fb, ++step, "disable in error", fb_expect(0, 1, POU_FB_ERR_TOO_MANY_ROBOTS, 0xC301u, stop));
    fb.reset = 1;
    fb_step(&fb, ++step, "reset", fb_expect(0, 0, 0, 0x0000u, stop));
    fb.reset = 0, fb.enable = 1, fb.n_robots = 2;
    fb_step(&fb, ++step, "enable (exact mode), colliding", fb_expect(1, 0, 0, 0x8001u, DC_VERDICT_COLLISION));
    fb.enable = 0;
    fb_step(&fb, ++step, "disable", fb_expect(0, 0, 0, 0x0000u, stop));
    check(fb.handle == NULL, "pou fb: the handle outlived the disable");
    printf("pou fb: %d steps\n", step);
}

int main(int argc, char **argv)
{
    static const char *cells[] = { "T1", "T2", "T3" };
    static const char *cases[] = { "practical", "collision" };
    HarnessOptions options;
    RunResult exact[3][2], table[3][2];
    int ran_table[3][2] = { { 0 } };
    size_t c, k;

    if (!parse_options(argc, argv, &options) || !load_tables(&options)) {
        free_tables(&options);
        printf("0 passed, 1 failed\n");
        return 2;
    }
    printf("delta-collide C harness, library %s%s\n", dc_version(),
           options.quick ? " (--quick: T1 collision, and the line's in exact mode, only)" : "");
    kinematics_grid();
    for (c = 0; c < 3; ++c) {
        for (k = 0; k < 2; ++k) {
            exact[c][k].stop_tick = exact[c][k].exact_first = -1;
            if (options.quick && (c != 0 || k != 1)) {
                continue;
            }
            run_scenario(cells[c], cases[k], &exact[c][k]);
            if (options.tables[c].path != NULL) {
                ran_table[c][k] = run_table_scenario(cells[c], cases[k], &options.tables[c], &table[c][k]);
                check(table[c][k].exact_first == exact[c][k].exact_first,
                      "%s %s: the exact first collision tick differs between the exact (%ld) and table (%ld) runs",
                      cells[c], cases[k], exact[c][k].exact_first, table[c][k].exact_first);
            }
        }
    }
    line_scenarios(&options);
    protective_scenarios(&options);
    speed_override_scenarios(&options);
    timing_scenarios(&options);
    coordination_scenarios(&options);
    bad_input(&options);
    pou_fb_scenario(&options);
    for (c = 0; c < 3; ++c) {
        for (k = 0; k < 2; ++k) {
            char t[24], e[24], x[24];
            if (!ran_table[c][k]) {
                continue;
            }
            tick_text(table[c][k].stop_tick, t);
            tick_text(exact[c][k].stop_tick, x);
            tick_text(exact[c][k].exact_first, e);
            printf("summary %s %-9s: stop tick table %s, exact POU %s, first exact collision %s\n", cells[c], cases[k],
                   t, x, e);
        }
    }
    free_tables(&options);
    printf("%d passed, %d failed\n", harness_passed(), harness_failed());
    return harness_failed() == 0 ? 0 : 1;
}
