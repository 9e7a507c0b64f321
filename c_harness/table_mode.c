/*
 * table_mode.c: one trajectory scenario with the POU in table mode (thesis
 * 3.2 query phase, SPEC section 6).
 *
 * Start-up reads the cell's table file into memory, initialises the POU with
 * dc_init_with_table and frees the buffer before the first tick (the library keeps a copy);
 * a second table handle comes from dc_init_from_files. Both confirm a COLLISION lookup by
 * the exact check (DC_CONFIRMATION_EXACT, the default). On the unstopped trajectory run a
 * "shadow" with the confirmation off (the table's labels) and a confirmed handle. Beside
 * them run exact-mode handles (DC_METHOD_SAT) on the same TCPs. Per tick the harness
 * asserts that the shadow never says FREE where the exact model collides and that the
 * confirmed handles answer as exact mode, on the POU's (stopped) trajectory and on the
 * unstopped one; at the end, that each COLLISION lookup of the shadow was confirmed once.
 * The shadow may stop earlier (it is conservative): the number of such ticks is printed.
 */
#include "harness.h"
#include "pou.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Per-tick comparison of a table handle with an exact handle on the same TCPs. */
typedef struct Compare {
    unsigned long status_errors;   /* a query did not return OK */
    unsigned long false_free;      /* table FREE, exact COLLISION: must stay 0 */
    unsigned long table_only;      /* table COLLISION, exact FREE: allowed (conservative) */
    long first_false_free;
    long table_first;              /* first COLLISION tick of the table handle, -1 if none */
    long exact_first;              /* first COLLISION tick of the exact handle, -1 if none */
} Compare;

static void compare_init(Compare *c)
{
    memset(c, 0, sizeof *c);
    c->first_false_free = -1;
    c->table_first = -1;
    c->exact_first = -1;
}

static void compare_tick(Compare *c, long tick, DcStatus st, DcVerdict vt, DcStatus se, DcVerdict ve)
{
    if (st != DC_STATUS_OK || se != DC_STATUS_OK) {
        c->status_errors++;
    }
    if (vt == DC_VERDICT_FREE && ve != DC_VERDICT_FREE) {
        c->false_free++;
        if (c->first_false_free < 0) {
            c->first_false_free = tick;
        }
    } else if (vt == DC_VERDICT_COLLISION && ve == DC_VERDICT_FREE) {
        c->table_only++;
    }
    if (vt == DC_VERDICT_COLLISION && c->table_first < 0) {
        c->table_first = tick;
    }
    if (ve == DC_VERDICT_COLLISION && c->exact_first < 0) {
        c->exact_first = tick;
    }
}

/* At the stop tick of a COLLISION: the table reports robots 0 and 1 and one pair; the exact
 * check confirmed it, so the report and the pair result name the same colliding boxes. */
static void check_stop_report(const char *cell_name, const char *case_name, const Pou *pou)
{
    DcPairResult pairs[4];
    size_t n_pairs = 99;
    DcStatus sp = dc_pair_results(pou->handle, pairs, 4, &n_pairs);
    const DcQueryReport *r = &pou->last_report;
    check(sp == DC_STATUS_OK && n_pairs == 1 && pairs[0].robot_a == 0 && pairs[0].robot_b == 1
              && pairs[0].collides == 1 && pairs[0].box_a != DC_BOX_NONE && pairs[0].box_b != DC_BOX_NONE,
          "%s %s table: dc_pair_results at the stop tick: status %u, %lu pairs, collides %u", cell_name, case_name,
          (unsigned)sp, (unsigned long)n_pairs, (unsigned)pairs[0].collides);
    check(r->verdict == DC_VERDICT_COLLISION && r->colliding_pairs == 1 && r->first_robot_a == 0
              && r->first_robot_b == 1 && r->first_box_a == pairs[0].box_a && r->first_box_b == pairs[0].box_b
              && r->unreachable_mask == 0,
          "%s %s table: report at the stop tick is inconsistent", cell_name, case_name);
}

/* Start-up of the table-mode handles; returns 0 (after destroying what was made) on failure. */
static int start_up(const char *cell_name, const DcCellConfig *config, const HarnessTable *table, Pou *pou,
                    DcCollider **shadow, DcCollider **confirmed, DcCollider **from_files, DcCollider **exact_pou,
                    DcCollider **exact_free)
{
    unsigned char *bytes = NULL;
    size_t len = 0;
    DcStatus s;
    int ok = check(read_file(table->path, &bytes, &len), "%s table: cannot read %s", cell_name, table->path);
    s = pou_init_with_table(pou, config, bytes, len);
    ok &= check(s == DC_STATUS_OK && dc_mode(pou->handle) == DC_MODE_TABLE, "%s table: pou_init_with_table: %s",
                cell_name, dc_status_str(s));
    s = dc_init_with_table(config, bytes, len, shadow);
    ok &= check(s == DC_STATUS_OK, "%s table: dc_init_with_table (shadow): %s", cell_name, dc_status_str(s));
    s = dc_set_table_confirmation(*shadow, DC_CONFIRMATION_NONE);
    ok &= check(s == DC_STATUS_OK, "%s table: dc_set_table_confirmation: %s", cell_name, dc_status_str(s));
    s = dc_init_with_table(config, bytes, len, confirmed);
    ok &= check(s == DC_STATUS_OK, "%s table: dc_init_with_table (confirmed): %s", cell_name, dc_status_str(s));
    /* The library copied what it needs: scribble over the buffer and free it before any tick. */
    if (bytes != NULL) {
        memset(bytes, 0xA5, len);
    }
    free(bytes);
    s = dc_init_from_files(cell_file(cell_name), table->path, from_files);
    ok &= check(s == DC_STATUS_OK && dc_mode(*from_files) == DC_MODE_TABLE, "%s table: dc_init_from_files(%s, %s): %s",
                cell_name, cell_file(cell_name), table->path, dc_status_str(s));
    s = dc_init(config, exact_pou);
    ok &= check(s == DC_STATUS_OK && dc_mode(*exact_pou) == DC_MODE_EXACT, "%s table: dc_init: %s", cell_name,
                dc_status_str(s));
    s = dc_init(config, exact_free);
    ok &= check(s == DC_STATUS_OK, "%s table: dc_init: %s", cell_name, dc_status_str(s));
    if (!ok) {
        pou_destroy(pou);
        dc_destroy(*shadow);
        dc_destroy(*confirmed);
        dc_destroy(*from_files);
        dc_destroy(*exact_pou);
        dc_destroy(*exact_free);
    }
    return ok;
}

int run_table_scenario(const char *cell_name, const char *case_name, const HarnessTable *table, RunResult *result)
{
    MrCell cell;
    MrScenario scenario;
    MrClock clock;
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    Pou pou;
    DcCollider *shadow = NULL, *confirmed = NULL, *from_files = NULL, *exact_pou = NULL, *exact_free = NULL;
    Compare on_pou, on_free, on_confirmed;
    unsigned long lookup_hits = 0;
    int stopped[MR_MAX_ROBOTS] = { 0 };
    double held[MR_MAX_ROBOTS][3];
    unsigned long mock_errors = 0, file_disagree = 0, not_held = 0;
    char stop_text[24], exact_text[24], shadow_text[24];
    size_t j;

    result->stop_tick = -1;
    result->exact_first = -1;
    memset(held, 0, sizeof held);
    compare_init(&on_pou);
    compare_init(&on_free);
    compare_init(&on_confirmed);
    if (!check(mr_register_cell(cell_name, &cell) == MR_OK, "%s: registry has no cell", cell_name)
        || !check(mr_load_scenario(SCENARIO_FILE, cell_name, case_name, cell.n_robots, &scenario) == MR_OK,
                  "%s %s: cannot load %s", cell_name, case_name, SCENARIO_FILE)) {
        return 0;
    }
    pou_cell_config(&cell, DC_METHOD_SAT, robots, &config);
    if (!start_up(cell_name, &config, table, &pou, &shadow, &confirmed, &from_files, &exact_pou, &exact_free)) {
        return 0;
    }

    /* The 1 ms tick loop: no allocation in here. */
    for (mr_clock_start(&clock); clock.tick < MR_TICKS_PER_RUN; mr_clock_advance(&clock)) {
        MrTickState free_run, pou_run;
        DcVec3 tcps_free[MR_MAX_ROBOTS], tcps_pou[MR_MAX_ROBOTS];
        DcVerdict v_pou, vt = DC_VERDICT_STOP, ve = DC_VERDICT_STOP, v_file = DC_VERDICT_STOP, vc = DC_VERDICT_STOP;
        DcStatus st, se, s_file, sc;
        long tick = clock.tick;
        uint64_t fallbacks = dc_table_fallbacks(shadow);

        /* The unstopped trajectory: table and exact side by side. */
        if (mr_robot_state(&cell, &scenario, tick, NULL, NULL, &free_run) != MR_OK) {
            mock_errors++;
        }
        to_dc(&free_run, cell.n_robots, tcps_free);
        st = dc_query(shadow, tcps_free, cell.n_robots, &vt, NULL);
        se = dc_query(exact_free, tcps_free, cell.n_robots, &ve, NULL);
        sc = dc_query(confirmed, tcps_free, cell.n_robots, &vc, NULL);
        compare_tick(&on_free, tick, st, vt, se, ve);
        compare_tick(&on_confirmed, tick, sc, vc, se, ve);
        if (vt == DC_VERDICT_COLLISION && dc_table_fallbacks(shadow) == fallbacks) {
            lookup_hits++; /* a COLLISION lookup, which the confirmed handle checked exactly */
        }

        /* What the controller runs: the table POU stops the robots. */
        if (mr_robot_state(&cell, &scenario, tick, stopped, (const double(*)[3])held, &pou_run) != MR_OK) {
            mock_errors++;
        }
        to_dc(&pou_run, cell.n_robots, tcps_pou);
        v_pou = pou_query(&pou, tick, tcps_pou, cell.n_robots);
        se = dc_query(exact_pou, tcps_pou, cell.n_robots, &ve, NULL);
        compare_tick(&on_pou, tick, pou.last_status, v_pou, se, ve);
        s_file = dc_query(from_files, tcps_pou, cell.n_robots, &v_file, NULL);
        if (s_file != pou.last_status || v_file != v_pou) {
            file_disagree++;
        }
        if (pou.stop_requested && tick > pou.stop_tick && v_pou != DC_VERDICT_COLLISION) {
            not_held++; /* held at the pose the table flagged, it must keep flagging it */
        }
        if (pou.stop_requested && !stopped[0]) {
            for (j = 0; j < cell.n_robots; ++j) {
                stopped[j] = 1;
                memcpy(held[j], pou_run.commanded[j], sizeof held[j]);
            }
            if (pou.stop_verdict == DC_VERDICT_COLLISION) {
                check_stop_report(cell_name, case_name, &pou);
            }
        }
    }
    result->stop_tick = pou.stop_tick;
    result->exact_first = on_free.exact_first;

    check(mock_errors == 0, "%s %s table: %lu mock kinematics errors", cell_name, case_name, mock_errors);
    check(on_pou.status_errors == 0 && on_free.status_errors == 0, "%s %s table: %lu + %lu queries did not return OK",
          cell_name, case_name, on_pou.status_errors, on_free.status_errors);
    check(on_pou.false_free == 0, "%s %s table: FREE where the exact model collides on %lu POU ticks (first %ld)",
          cell_name, case_name, on_pou.false_free, on_pou.first_false_free);
    check(on_free.false_free == 0, "%s %s table: FREE where the exact model collides on %lu unstopped ticks (first %ld)",
          cell_name, case_name, on_free.false_free, on_free.first_false_free);
    check(on_confirmed.false_free + on_confirmed.table_only + on_pou.table_only == 0,
          "%s %s table: the confirmed handles differ from exact mode on %lu unstopped, %lu POU ticks", cell_name,
          case_name, on_confirmed.false_free + on_confirmed.table_only, on_pou.table_only);
    check(dc_table_confirmations(confirmed) == lookup_hits && dc_table_confirmations(shadow) == 0,
          "%s %s table: %lu confirmations for %lu COLLISION lookups", cell_name, case_name,
          (unsigned long)dc_table_confirmations(confirmed), lookup_hits);
    check(file_disagree == 0, "%s %s table: dc_init_from_files handle disagrees with the POU on %lu ticks", cell_name,
          case_name, file_disagree);
    check(not_held == 0, "%s %s table: %lu ticks after the stop were not COLLISION at the held pose", cell_name,
          case_name, not_held);
    check(pou.stop_tick < 0 || pou.stop_verdict == DC_VERDICT_COLLISION,
          "%s %s table: the POU stopped with verdict %u (an error), not COLLISION", cell_name, case_name,
          (unsigned)pou.stop_verdict);
    check(pou.stop_tick == on_confirmed.table_first, "%s %s table: POU stop tick %ld != first COLLISION tick %ld",
          cell_name, case_name, pou.stop_tick, on_confirmed.table_first);
    if (strcmp(case_name, "practical") == 0) {
        check(on_free.exact_first < 0, "%s practical table: the exact model collides at tick %ld", cell_name,
              on_free.exact_first);
    } else {
        check(on_free.exact_first >= 0 && on_free.table_first >= 0 && on_free.table_first <= on_free.exact_first,
              "%s collision table: the shadow's first COLLISION %ld is not <= the exact first collision tick %ld",
              cell_name, on_free.table_first, on_free.exact_first);
    }
    tick_text(pou.stop_tick, stop_text);
    tick_text(on_free.exact_first, exact_text);
    tick_text(on_free.table_first, shadow_text);
    printf("%s %-9s table: stop tick %s (table POU), first collision tick %s (exact, unstopped); "
           "FREE ticks %lu/%d; unstopped: %lu table-only COLLISION ticks (first %s) with confirmation off, "
           "%lu FREE where exact collides; confirmed ticks %lu; exact fallbacks %lu\n",
           cell_name, case_name, stop_text, exact_text, pou.n_free, MR_TICKS_PER_RUN, on_free.table_only,
           shadow_text, on_free.false_free + on_pou.false_free, (unsigned long)dc_table_confirmations(confirmed),
           (unsigned long)dc_table_fallbacks(shadow));

    pou_destroy(&pou);
    dc_destroy(shadow);
    dc_destroy(confirmed);
    dc_destroy(from_files);
    dc_destroy(exact_pou);
    dc_destroy(exact_free);
    return 1;
}
