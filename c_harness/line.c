/*
 * line.c: a packaging line of four robots on one conveyor (cells/line4.toml: bases 450 mm
 * apart as in T1; SPEC section 5's two cases, c_harness/line_scenarios.txt), 6,000 ticks of 1 ms:
 *   - exact mode: the POU runs on a handle from the cell file (dc_init_from_cell_file), a
 *     handle from the mock's configuration (DC_METHOD_SAT) runs the unstopped trajectory
 *     beside it. Practical: FREE on every tick. Collision: the POU stops every robot at the
 *     first COLLISION, after tick 3000 and at the exact model's first colliding tick, and
 *     dc_pair_results names the same colliding pair as the exact model does there;
 *   - the protective verdict for every pair that can meet (protective.c's run_protective): at
 *     the first STOP every robot stops as its stopping model says, and every 0.1 ms of the stop
 *     the exact model checks that no box of any pair touches; in the collision case the first
 *     STOP comes no later than the exact model's first colliding tick.
 *   - table mode (--line-bundle: the line's bundle, one table per spacing that can meet): the
 *     POU runs on a handle from the mock's configuration and the bundle's bytes
 *     (dc_init_with_table, exact confirmation of COLLISION lookups, the default), with the same
 *     checks as exact mode: FREE on every practical tick, the collision case stopped at the
 *     exact model's first colliding tick naming the same pairs; dc_init_from_files takes the
 *     cell file and the bundle file alike. With a bundle of clearance tables, the protective
 *     verdict (stiff model) runs in table mode too, with the same stop checks. T1's table alone is refused for the line: it has
 *     no table for the robots 900 and 1350 mm apart.
 */
#include "harness.h"
#include "pou.h"

#include <stdio.h>
#include <string.h>

#define LINE_ROBOTS 4
#define LINE_MAX_PAIRS 6 /* every pair of four robots */

/* The colliding pairs of a handle's last query, as "a-b a-b"; returns how many collide. */
static size_t colliding_pairs(const DcCollider *h, char out[64])
{
    DcPairResult pairs[LINE_MAX_PAIRS];
    size_t n = 0, i, hits = 0;
    out[0] = '\0';
    if (dc_pair_results(h, pairs, LINE_MAX_PAIRS, &n) != DC_STATUS_OK) {
        strcpy(out, "(dc_pair_results failed)");
        return 0;
    }
    for (i = 0; i < n; ++i) {
        if (pairs[i].collides) {
            sprintf(out + strlen(out), "%s%u-%u", hits == 0 ? "" : " ", (unsigned)pairs[i].robot_a,
                    (unsigned)pairs[i].robot_b);
            hits++;
        }
    }
    if (hits == 0) {
        strcpy(out, "none");
    }
    return hits;
}

/* Both handles of the line: the POU's from the cell file (exact mode) or, given `bundle`,
 * from the mock's configuration and the bundle's bytes (table mode); the exact one from the
 * mock's configuration; the robot and pair counts must agree. Returns 0 after a failed check. */
static int open_line(const MrCell *cell, Pou *pou, DcCollider **exact, const HarnessTable *bundle)
{
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcStatus s;
    *exact = NULL;
    pou_cell_config(cell, DC_METHOD_SAT, robots, &config);
    if (bundle == NULL) {
        s = pou_init_from_file(pou, LINE_CELL_FILE);
        check(s == DC_STATUS_OK && pou->handle != NULL && dc_mode(pou->handle) == DC_MODE_EXACT,
              "line4: dc_init_from_cell_file(%s): %s", LINE_CELL_FILE, dc_status_str(s));
    } else {
        s = pou_init_with_table(pou, &config, bundle->bytes, bundle->len);
        check(s == DC_STATUS_OK && pou->handle != NULL && dc_mode(pou->handle) == DC_MODE_TABLE,
              "line4: dc_init_with_table(the bundle %s): %s", bundle->path, dc_status_str(s));
    }
    s = dc_init(&config, exact);
    check(s == DC_STATUS_OK, "line4: dc_init SAT: %s", dc_status_str(s));
    if (pou->handle == NULL || *exact == NULL) {
        return 0;
    }
    /* Neighbours (450 mm) and robots two apart (900 mm) can meet; the library's reach bound
     * may keep the pair three apart too, so only the count's agreement and floor are fixed. */
    return check(dc_robot_count(pou->handle) == LINE_ROBOTS && dc_robot_count(*exact) == LINE_ROBOTS
                     && dc_pair_count(pou->handle) == dc_pair_count(*exact) && dc_pair_count(*exact) >= 5
                     && dc_pair_count(*exact) <= LINE_MAX_PAIRS,
                 "line4: robots %lu (file) / %lu (config), pairs that can meet %lu / %lu, expected 4 robots and "
                 "5 or 6 pairs",
                 (unsigned long)dc_robot_count(pou->handle), (unsigned long)dc_robot_count(*exact),
                 (unsigned long)dc_pair_count(pou->handle), (unsigned long)dc_pair_count(*exact));
}

/* One case, in exact mode (`bundle` NULL) or table mode on the bundle; returns the first
 * exact colliding tick of the unstopped run (-1 if none, -2 when the case could not run). */
static long run_line(const char *case_name, const HarnessTable *bundle)
{
    const char *mode = bundle == NULL ? "" : "table ";
    MrCell cell;
    MrScenario scenario;
    Pou pou;
    DcCollider *exact = NULL;
    int stopped[MR_MAX_ROBOTS] = { 0 };
    double held[MR_MAX_ROBOTS][3];
    unsigned long mock_errors = 0, status_errors = 0, disagree = 0, free_ticks = 0, not_held = 0;
    long exact_first = -1, first_disagree = -1;
    char exact_pairs[64] = "none", stop_pairs[64] = "none", stop_text[24], exact_text[24];
    int practical = strcmp(case_name, "practical") == 0;
    MrClock clock;
    size_t j;

    memset(held, 0, sizeof held);
    memset(&pou, 0, sizeof pou);
    if (!check(mr_register_cell("line4", &cell) == MR_OK
                   && mr_load_scenario(LINE_SCENARIO_FILE, "line4", case_name, LINE_ROBOTS, &scenario) == MR_OK,
               "line4 %s%s: cannot load %s", mode, case_name, LINE_SCENARIO_FILE)
        || !open_line(&cell, &pou, &exact, bundle)) {
        pou_destroy(&pou);
        dc_destroy(exact);
        return -2;
    }
    for (mr_clock_start(&clock); clock.tick < MR_TICKS_PER_RUN; mr_clock_advance(&clock)) {
        MrTickState free_run, pou_run;
        DcVec3 tcps_free[MR_MAX_ROBOTS], tcps_pou[MR_MAX_ROBOTS];
        DcVerdict v_exact = DC_VERDICT_STOP, v_pou;
        long tick = clock.tick;

        /* The unstopped trajectory through the exact model. */
        if (mr_robot_state(&cell, &scenario, tick, NULL, NULL, &free_run) != MR_OK) {
            mock_errors++;
        }
        to_dc(&free_run, cell.n_robots, tcps_free);
        if (dc_query(exact, tcps_free, cell.n_robots, &v_exact, NULL) != DC_STATUS_OK) {
            status_errors++;
        }
        if (v_exact == DC_VERDICT_COLLISION && exact_first < 0) {
            exact_first = tick;
            colliding_pairs(exact, exact_pairs);
        }

        /* What the controller runs: every robot holds its pose once the POU asks for a stop. */
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
        }
        /* Until the stop both handles see the same TCPs: the cell file and the mock's
         * configuration, SAT_CACHE and SAT, must answer alike. */
        if (!pou.stop_requested && v_pou != v_exact) {
            disagree++;
            if (first_disagree < 0) {
                first_disagree = tick;
            }
        }
        if (pou.stop_requested && tick > pou.stop_tick && v_pou != DC_VERDICT_COLLISION) {
            not_held++;
        }
        if (pou.stop_requested && !stopped[0]) {
            size_t hits = colliding_pairs(pou.handle, stop_pairs);
            check(hits > 0 && pou.last_report.colliding_pairs == hits,
                  "line4 %s%s: dc_pair_results names %lu colliding pairs at the stop tick, the report %u", mode, case_name,
                  (unsigned long)hits, (unsigned)pou.last_report.colliding_pairs);
            for (j = 0; j < cell.n_robots; ++j) {
                stopped[j] = 1;
                memcpy(held[j], pou_run.commanded[j], sizeof held[j]);
            }
        }
    }

    check(mock_errors == 0, "line4 %s%s: %lu mock kinematics errors (a waypoint is unreachable?)", mode, case_name,
          mock_errors);
    check(status_errors == 0, "line4 %s%s: %lu queries did not return OK", mode, case_name, status_errors);
    check(disagree == 0, "line4 %s%s: the POU's handle (%s) and the exact one disagree on %lu ticks (first %ld)",
          mode, case_name, bundle == NULL ? LINE_CELL_FILE : bundle->path, disagree, first_disagree);
    if (practical) {
        check(free_ticks == MR_TICKS_PER_RUN && pou.stop_tick < 0,
              "line4 %spractical: FREE on %lu of %d ticks (POU stop tick %ld)", mode, free_ticks, MR_TICKS_PER_RUN,
              pou.stop_tick);
        check(exact_first < 0, "line4 %spractical: the exact model collides at tick %ld", mode, exact_first);
    } else {
        check(pou.stop_tick > STOP_AFTER_TICK && pou.stop_verdict == DC_VERDICT_COLLISION,
              "line4 %scollision: POU stop tick %ld (verdict %u), expected a COLLISION after tick %ld", mode,
              pou.stop_tick, (unsigned)pou.stop_verdict, STOP_AFTER_TICK);
        check(exact_first >= 0 && pou.stop_tick == exact_first,
              "line4 %scollision: POU stop tick %ld, first exact collision tick %ld", mode, pou.stop_tick, exact_first);
        check(strcmp(stop_pairs, exact_pairs) == 0,
              "line4 %scollision: the POU names pairs %s at its stop, the exact model %s at its first collision", mode,
              stop_pairs, exact_pairs);
        check(not_held == 0, "line4 %scollision: %lu ticks after the stop were not COLLISION at the held pose", mode,
              not_held);
    }
    tick_text(pou.stop_tick, stop_text);
    tick_text(exact_first, exact_text);
    printf("line4 %s%-9s: POU stop tick %s, first exact collision %s, FREE ticks %lu/%d, pairs that can meet %lu, "
           "colliding pairs at the stop %s",
           mode, case_name, stop_text, exact_text, free_ticks, MR_TICKS_PER_RUN, (unsigned long)dc_pair_count(exact),
           stop_pairs);
    if (bundle != NULL) {
        printf(", lookups confirmed %llu, fallbacks %llu", (unsigned long long)dc_table_confirmations(pou.handle),
               (unsigned long long)dc_table_fallbacks(pou.handle));
    }
    printf("\n");
    pou_destroy(&pou);
    dc_destroy(exact);
    return exact_first;
}

/* The line's bundle file with the cell file: dc_init_from_files gives a table-mode handle of
 * four robots and every pair that can meet. */
static void line_bundle_from_files(const char *bundle_path)
{
    DcCollider *h = NULL;
    DcStatus s = dc_init_from_files(LINE_CELL_FILE, bundle_path, &h);
    check(s == DC_STATUS_OK && h != NULL && dc_mode(h) == DC_MODE_TABLE && dc_robot_count(h) == LINE_ROBOTS
              && dc_pair_count(h) >= 5,
          "line4: dc_init_from_files(%s, %s): %s", LINE_CELL_FILE, bundle_path, dc_status_str(s));
    dc_destroy(h);
}

/* A two-robot table is no bundle for the line: dc_init_from_files must refuse it and say why. */
static void line_refuses_a_pair_table(const char *table_path)
{
    DcCollider *h = NULL;
    DcStatus s = dc_init_from_files(LINE_CELL_FILE, table_path, &h);
    char why[512];
    size_t len = dc_last_init_error(why, sizeof why);
    check(s != DC_STATUS_OK && h == NULL && len > 0,
          "line4: dc_init_from_files(%s, T1's table) returned %s with no refusal", LINE_CELL_FILE, dc_status_str(s));
    check(s == DC_STATUS_TABLE_MISSING_PAIR, "line4: T1's table refused with %s, expected a missing pair",
          dc_status_str(s));
    printf("line4 T1's table alone: refused (a line needs its bundle): %s: %s\n", dc_status_str(s),
           len > 0 ? why : "(no message)");
    dc_destroy(h);
}

void line_scenarios(const HarnessOptions *options)
{
    static const char *cases[] = { "practical", "collision" };
    /* The default model STOPs in the first 100 ticks, as on T1-T3, and holds the robots still
     * from then on; the stiff one (short reaction, hard braking) stops later and closer, where
     * a wrong bound would show. */
    DcStopConfig standard = dc_stop_config_default(), stiff = dc_stop_config_default();
    VerdictTally d, t, p, b;
    size_t k;
    stiff.reaction_ms = 2.0;
    stiff.decel_mm_s2 = 120000.0;
    if (options->quick) {
        /* Valgrind: the handles of four robots and their pair results, once. */
        run_line("collision", NULL);
        return;
    }
    if (options->tables[0].path != NULL) {
        line_refuses_a_pair_table(options->tables[0].path);
    }
    if (options->line_bundle.path != NULL) {
        line_bundle_from_files(options->line_bundle.path);
    }
    for (k = 0; k < 2; ++k) {
        long exact_first = run_line(cases[k], NULL);
        if (options->line_bundle.bytes != NULL) {
            long table_first = run_line(cases[k], &options->line_bundle);
            check(table_first == exact_first, "line4 %s: the unstopped run's first collision differs between runs",
                  cases[k]);
        }
        if (options->protective_quick) {
            continue; /* under qemu the interval arithmetic of the verdict takes minutes */
        }
        d = run_protective("line4", cases[k], "default", &standard, NULL, 0, MR_TICKS_PER_RUN);
        t = run_protective("line4", cases[k], "stiff", &stiff, NULL, 0, MR_TICKS_PER_RUN);
        p = run_protective("line4", cases[k], "stiff", &stiff, NULL, 1, MR_TICKS_PER_RUN);
        /* Table mode: with a bundle of clearance tables each pair's bound comes from its table,
         * and the pairs it proves apart skip the box-pair proof of the others. */
        b = options->line_bundle.bytes == NULL
                ? p
                : run_protective("line4", cases[k], "stiff", &stiff, &options->line_bundle, 0, MR_TICKS_PER_RUN);
        if (exact_first >= 0) {
            check(b.first_stop >= 0 && b.first_stop <= exact_first,
                  "line4 %s: first protective STOP in table mode %ld after the first exact collision tick %ld",
                  cases[k], b.first_stop, exact_first);
            check(d.first_stop >= 0 && d.first_stop <= exact_first && t.first_stop >= 0
                      && t.first_stop <= exact_first && p.first_stop >= 0 && p.first_stop <= exact_first,
                  "line4 %s: first protective STOP %ld (stiff %ld, with paths %ld) after the first exact "
                  "collision tick %ld", cases[k], d.first_stop, t.first_stop, p.first_stop, exact_first);
        }
    }
}
