/*
 * harness.c: the C harness's shared helpers: check counting, the command line, table files.
 * See harness.h.
 */
#include "harness.h"

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
        } else if (strcmp(argv[i], "--table") == 0 && i + 1 < argc) {
            const char *arg = argv[++i];
            const char *eq = strchr(arg, '=');
            char cell[8];
            int c;
            if (eq == NULL || (size_t)(eq - arg) >= sizeof cell) {
                printf("bad --table %s: expected CELL=PATH\n", arg);
                return 0;
            }
            memcpy(cell, arg, (size_t)(eq - arg));
            cell[eq - arg] = '\0';
            c = cell_index(cell);
            if (c < 0) {
                printf("bad --table %s: CELL must be T1, T2 or T3\n", arg);
                return 0;
            }
            out->tables[c].path = eq + 1;
        } else {
            printf("unknown argument %s\nusage: c_harness [--quick] [--tmp DIR] [--table CELL=PATH]...\n", argv[i]);
            return 0;
        }
    }
    return 1;
}

int load_tables(HarnessOptions *options)
{
    int c, ok = 1;
    for (c = 0; c < HARNESS_N_CELLS; ++c) {
        HarnessTable *t = &options->tables[c];
        if (t->path != NULL && !read_file(t->path, &t->bytes, &t->len)) {
            printf("cannot read table file %s\n", t->path);
            ok = 0;
        }
    }
    return ok;
}

void free_tables(HarnessOptions *options)
{
    int c;
    for (c = 0; c < HARNESS_N_CELLS; ++c) {
        free(options->tables[c].bytes);
        options->tables[c].bytes = NULL;
        options->tables[c].len = 0;
    }
}
