/*
 * harness.c: the C harness's shared helpers: check counting, the command line, table files.
 * See harness.h.
 */
#include "harness.h"
#include "pou.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_passed;
static int g_failed;

int check(int ok, const char *fmt, ...)
{
    va_list args;
    if (ok) {
        g_passed++;
        return 1;
    }
    g_failed++;
    fputs("FAIL: ", stdout);
    va_start(args, fmt);
    vprintf(fmt, args);
    va_end(args);
    fputc('\n', stdout);
    return 0;
}

int harness_passed(void)
{
    return g_passed;
}

int harness_failed(void)
{
    return g_failed;
}

DcVec3 vec3(double x, double y, double z)
{
    DcVec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

DcDelta3 dc_geometry(const MrGeometry *g)
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

int cell_index(const char *cell)
{
    static const char *names[HARNESS_N_CELLS] = { "T1", "T2", "T3" };
    int i;
    for (i = 0; i < HARNESS_N_CELLS; ++i) {
        if (strcmp(cell, names[i]) == 0) {
            return i;
        }
    }
    return -1;
}

const char *cell_file(const char *cell)
{
    static const char *files[HARNESS_N_CELLS] = { "cells/t1.toml", "cells/t2.toml", "cells/t3.toml" };
    int i = cell_index(cell);
    return i < 0 ? "cells/unknown.toml" : files[i];
}

const char *scenario_file(const char *cell)
{
    return strcmp(cell, "line4") == 0 ? LINE_SCENARIO_FILE : SCENARIO_FILE;
}

void tick_text(long tick, char out[24])
{
    if (tick < 0) {
        strcpy(out, "none");
    } else {
        sprintf(out, "%ld", tick);
    }
}

void to_dc(const MrTickState *st, size_t n, DcVec3 out[MR_MAX_ROBOTS])
{
    size_t j;
    for (j = 0; j < n; ++j) {
        out[j] = vec3(st->tcp[j][0], st->tcp[j][1], st->tcp[j][2]);
    }
}

int read_file(const char *path, unsigned char **out, size_t *out_len)
{
    FILE *f = fopen(path, "rb");
    long size;
    unsigned char *buf;
    *out = NULL;
    *out_len = 0;
    if (f == NULL) {
        return 0;
    }
    if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return 0;
    }
    buf = (unsigned char *)malloc(size > 0 ? (size_t)size : 1u);
    if (buf == NULL || fread(buf, 1, (size_t)size, f) != (size_t)size) {
        free(buf);
        fclose(f);
        return 0;
    }
    fclose(f);
    *out = buf;
    *out_len = (size_t)size;
    return 1;
}

int parse_options(int argc, char **argv, HarnessOptions *out)
{
    int i;
    memset(out, 0, sizeof *out);
    out->tmp_dir = ".";
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--protective-quick") == 0) {
            out->protective_quick = 1;
            continue;
        }
        if (strcmp(argv[i], "--quick") == 0) {
            out->quick = 1;
        } else if (strcmp(argv[i], "--tmp") == 0 && i + 1 < argc) {
            out->tmp_dir = argv[++i];
        } else if (strcmp(argv[i], "--line-bundle") == 0 && i + 1 < argc) {
            out->line_bundle.path = argv[++i];
        } else if ((strcmp(argv[i], "--table") == 0 || strcmp(argv[i], "--clearance-table") == 0) && i + 1 < argc) {
            HarnessTable *tables = strcmp(argv[i], "--table") == 0 ? out->tables : out->clearance_tables;
            const char *arg = argv[++i];
            const char *eq = strchr(arg, '=');
            char cell[8];
            int c;
            if (eq == NULL || (size_t)(eq - arg) >= sizeof cell) {
                printf("bad %s %s: expected CELL=PATH\n", argv[i - 1], arg);
                return 0;
            }
            memcpy(cell, arg, (size_t)(eq - arg));
            cell[eq - arg] = '\0';
            c = cell_index(cell);
            if (c < 0) {
                printf("bad %s %s: CELL must be T1, T2 or T3\n", argv[i - 1], arg);
                return 0;
            }
            tables[c].path = eq + 1;
        } else {
            printf("unknown argument %s\nusage: c_harness [--quick] [--tmp DIR] [--table CELL=PATH]... "
                   "[--clearance-table CELL=PATH]... [--line-bundle PATH]\n",
                   argv[i]);
            return 0;
        }
    }
    return 1;
}

int load_tables(HarnessOptions *options)
{
    int c, ok = 1;
    for (c = 0; c < 2 * HARNESS_N_CELLS; ++c) {
        HarnessTable *t = c < HARNESS_N_CELLS ? &options->tables[c] : &options->clearance_tables[c - HARNESS_N_CELLS];
        if (t->path != NULL && !read_file(t->path, &t->bytes, &t->len)) {
            printf("cannot read table file %s\n", t->path);
            ok = 0;
        }
    }
    if (options->line_bundle.path != NULL
        && !read_file(options->line_bundle.path, &options->line_bundle.bytes, &options->line_bundle.len)) {
        printf("cannot read bundle file %s\n", options->line_bundle.path);
        ok = 0;
    }
    return ok;
}

void free_tables(HarnessOptions *options)
{
    int c;
    for (c = 0; c < 2 * HARNESS_N_CELLS; ++c) {
        HarnessTable *t = c < HARNESS_N_CELLS ? &options->tables[c] : &options->clearance_tables[c - HARNESS_N_CELLS];
        free(t->bytes);
        t->bytes = NULL;
        t->len = 0;
    }
    free(options->line_bundle.bytes);
    options->line_bundle.bytes = NULL;
    options->line_bundle.len = 0;
}

int open_protective(const char *who, const char *cell_name, const char *case_name, const DcStopConfig *model,
                    const HarnessTable *table, MrCell *cell, MrScenario *scenario, DcStopConfig stops[MR_MAX_ROBOTS],
                    DcCollider **h, DcCollider **exact)
{
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcStatus s;
    size_t j;
    *h = *exact = NULL;
    if (mr_register_cell(cell_name, cell) != MR_OK
        || mr_load_scenario(scenario_file(cell_name), cell_name, case_name, cell->n_robots, scenario) != MR_OK) {
        return check(0, "%s %s %s: cannot load the scenario", who, cell_name, case_name);
    }
    pou_cell_config(cell, DC_METHOD_SAT_CACHE, robots, &config);
    s = table == NULL ? dc_init(&config, h) : dc_init_with_table(&config, table->bytes, table->len, h);
    check(s == DC_STATUS_OK, "%s %s: dc_init%s: %s", who, cell_name, table == NULL ? "" : "_with_table",
          dc_status_str(s));
    s = dc_init(&config, exact);
    check(s == DC_STATUS_OK, "%s %s: dc_init (exact): %s", who, cell_name, dc_status_str(s));
    for (j = 0; j < cell->n_robots; ++j) {
        stops[j] = *model;
    }
    s = *h == NULL ? DC_STATUS_NULL_POINTER : dc_set_stop_model(*h, 1.0, 10.0, stops, cell->n_robots);
    if (!check(s == DC_STATUS_OK && *exact != NULL, "%s %s: dc_set_stop_model: %s", who, cell_name,
               dc_status_str(s))) {
        dc_destroy(*h);
        dc_destroy(*exact);
        *h = *exact = NULL;
        return 0;
    }
    return 1;
}

int stop_substep(DcCollider *exact, const MrScenario *s, MrStop stop[MR_MAX_ROBOTS], StopStats *st)
{
    const double dt_ms = 1.0 / STOP_SUBSTEPS;
    DcVec3 tcps[MR_MAX_ROBOTS];
    DcVerdict v = DC_VERDICT_STOP;
    DcStatus status;
    int moving = 0;
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        moving |= mr_stop_step(&s->robots[j], &stop[j], dt_ms);
        tcps[j] = vec3(stop[j].o.tcp[0], stop[j].o.tcp[1], stop[j].o.tcp[2]);
    }
    if (moving) {
        st->moving_ms += dt_ms;
    }
    status = dc_query(exact, tcps, s->n_robots, &v, NULL);
    st->samples++;
    if (status != DC_STATUS_OK || v != DC_VERDICT_FREE) {
        st->contacts++;
    }
    return moving;
}

VerdictTally tally_start(void)
{
    VerdictTally t = { -1, -1, 0, 0, 0, INFINITY, DC_BOX_NONE, DC_BOX_NONE };
    return t;
}

int tally_verdict(VerdictTally *t, long tick, DcStatus s, DcVerdict v, const DcProtectiveReport *rep)
{
    if (s != DC_STATUS_OK) {
        t->n_bad_status++;
    }
    if (rep->clearance_mm < t->min_clear) {
        t->min_clear = rep->clearance_mm;
    }
    if (v == DC_VERDICT_WARN) {
        t->n_warn++;
        if (t->first_warn < 0) {
            t->first_warn = tick;
        }
        return 0;
    }
    if (v == DC_VERDICT_FREE) {
        return 0;
    }
    t->n_stop++;
    if (t->first_stop < 0) {
        t->first_stop = tick;
        t->stop_robot_a = rep->limiting_robot_a;
        t->stop_robot_b = rep->limiting_robot_b;
    }
    return 1;
}
