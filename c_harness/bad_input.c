/*
 * bad_input.c: the C harness's bad-input scenarios: every documented error
 * status of the C ABI, in exact and in table mode, and the fail-closed outputs: a query that
 * fails never reads FREE, a failed init leaves a NULL handle, which then queries as
 * DC_STATUS_NULL_POINTER with DC_VERDICT_STOP.
 */
#include "harness.h"
#include "pou.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A query that must fail: checks status, that the pre-set FREE verdict became STOP, and the report. */
static void expect_query(const char *mode, const char *what, DcCollider *h, const DcVec3 *tcps, size_t n,
                         DcStatus expected, int expect_mask, uint32_t mask)
{
    DcVerdict v = DC_VERDICT_FREE;
    DcQueryReport rep;
    DcStatus s;
    memset(&rep, 0, sizeof rep);
    rep.verdict = DC_VERDICT_FREE;
    s = dc_query(h, tcps, n, &v, &rep);
    check(s == expected, "bad input (%s), %s: status %u (%s), expected %u", mode, what, (unsigned)s,
          dc_status_str(s), (unsigned)expected);
    check(v == DC_VERDICT_STOP, "bad input (%s), %s: verdict %u, expected STOP", mode, what, (unsigned)v);
    check(rep.verdict == DC_VERDICT_STOP, "bad input (%s), %s: report verdict %u, expected STOP", mode, what,
          (unsigned)rep.verdict);
    if (expect_mask) {
        check(rep.unreachable_mask == mask, "bad input (%s), %s: unreachable_mask %u, expected %u", mode, what,
              (unsigned)rep.unreachable_mask, (unsigned)mask);
    }
    /* The same call without a report must give the same status and verdict. */
    v = DC_VERDICT_FREE;
    s = dc_query(h, tcps, n, &v, NULL);
    check(s == expected && v == DC_VERDICT_STOP, "bad input (%s), %s (no report): status %u verdict %u", mode, what,
          (unsigned)s, (unsigned)v);
}

/* The query-time bad inputs, the same for an exact-mode and a table-mode handle of T1. */
static void bad_queries(const char *mode, DcCollider *h)
{
    DcVec3 tcps[3];
    DcVerdict v;
    DcQueryReport rep;
    DcStatus s;
    DcPairResult pairs[2];
    size_t len;
    const double qnan = NAN;
    const double pinf = INFINITY;

    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    tcps[2] = vec3(0.0, 0.0, -450.0);

    /* A good query first: OK and a decided verdict. */
    v = DC_VERDICT_STOP;
    s = dc_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && (v == DC_VERDICT_FREE || v == DC_VERDICT_COLLISION),
          "bad input (%s): the good query gave status %u verdict %u", mode, (unsigned)s, (unsigned)v);

    expect_query(mode, "NULL handle", NULL, tcps, 2, DC_STATUS_NULL_POINTER, 0, 0);
    expect_query(mode, "NULL tcps", h, NULL, 2, DC_STATUS_NULL_POINTER, 0, 0);
    rep.verdict = DC_VERDICT_FREE;
    s = dc_query(h, tcps, 2, NULL, &rep);
    check(s == DC_STATUS_NULL_POINTER && rep.verdict == DC_VERDICT_STOP,
          "bad input (%s), NULL out_verdict: status %u, report verdict %u", mode, (unsigned)s, (unsigned)rep.verdict);
    s = dc_query(h, tcps, 2, NULL, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input (%s), NULL out_verdict and report: status %u", mode, (unsigned)s);

    tcps[0] = vec3(qnan, 0.0, -450.0);
    expect_query(mode, "NaN TCP of robot 0", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 1u);
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, pinf, -450.0);
    expect_query(mode, "infinite TCP of robot 1", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 2u);
    tcps[1] = vec3(0.0, 0.0, -pinf);
    expect_query(mode, "-infinite z of robot 1", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 2u);
    tcps[0] = vec3(qnan, qnan, qnan);
    expect_query(mode, "NaN TCPs of both robots", h, tcps, 2, DC_STATUS_NON_FINITE, 1, 3u);
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, 0.0, -900.0);
    expect_query(mode, "unreachable z = -900 of robot 1", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 2u);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    tcps[0] = vec3(0.0, 0.0, 100.0);
    expect_query(mode, "unreachable z = +100 of robot 0", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 1u);
    tcps[0] = vec3(600.0, 0.0, -450.0);
    expect_query(mode, "unreachable x = 600 of robot 0", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 1u);
    tcps[1] = vec3(0.0, 0.0, 100.0);
    expect_query(mode, "both unreachable", h, tcps, 2, DC_STATUS_UNREACHABLE, 1, 3u);
    tcps[0] = vec3(0.0, 0.0, -450.0);
    tcps[1] = vec3(0.0, 0.0, -450.0);
    expect_query(mode, "n_tcps = 1", h, tcps, 1, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);
    expect_query(mode, "n_tcps = 3", h, tcps, 3, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);
    expect_query(mode, "n_tcps = 0", h, tcps, 0, DC_STATUS_WRONG_ROBOT_COUNT, 0, 0);

    /* After all that the handle still answers good queries. */
    v = DC_VERDICT_STOP;
    s = dc_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && v != DC_VERDICT_STOP, "bad input (%s): handle unusable after errors (status %u)", mode,
          (unsigned)s);

    /* dc_pair_results */
    s = dc_pair_results(NULL, pairs, 2, &len);
    check(s == DC_STATUS_NULL_POINTER, "bad input (%s), dc_pair_results NULL handle: %u", mode, (unsigned)s);
    s = dc_pair_results(h, NULL, 2, &len);
    check(s == DC_STATUS_NULL_POINTER, "bad input (%s), dc_pair_results NULL out: %u", mode, (unsigned)s);
    s = dc_pair_results(h, pairs, 2, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input (%s), dc_pair_results NULL out_len: %u", mode, (unsigned)s);
    len = 99;
    s = dc_pair_results(h, pairs, 0, &len);
    check(s == DC_STATUS_INVALID_ARGUMENT && len == 1,
          "bad input (%s), dc_pair_results capacity 0: status %u, out_len %lu (expected the count needed, 1)", mode,
          (unsigned)s, (unsigned long)len);
}

static int dummy_object;

/* After a failed init: the handle must be NULL, and querying it gives NULL_POINTER and STOP. */
static void expect_failed_handle(const char *what, DcCollider *h)
{
    DcVerdict v = DC_VERDICT_FREE;
    DcVec3 tcps[2];
    DcStatus s;
    check(h == NULL, "bad input, %s: out_handle not NULL after a failed init", what);
    if (h == NULL) {
        tcps[0] = vec3(0.0, 0.0, -450.0);
        tcps[1] = vec3(0.0, 0.0, -450.0);
        s = dc_query(h, tcps, 2, &v, NULL);
        check(s == DC_STATUS_NULL_POINTER && v == DC_VERDICT_STOP,
              "bad input, query after failed %s: status %u verdict %u", what, (unsigned)s, (unsigned)v);
    } else if (h != (DcCollider *)(void *)&dummy_object) {
        dc_destroy(h);
    }
}

/* dc_init must fail with `expected` and leave *out_handle NULL (pre-set to a dangling value). */
static void expect_init(const char *what, const DcCellConfig *config, DcStatus expected)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init(config, &h);
    check(s == expected, "bad input, dc_init %s: status %u (%s), expected %u", what, (unsigned)s, dc_status_str(s),
          (unsigned)expected);
    expect_failed_handle(what, h);
}

static void expect_init_file(const char *what, const char *path, DcStatus expected)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init_from_cell_file(path, &h);
    check(s == expected, "bad input, dc_init_from_cell_file %s: status %u (%s), expected %u", what, (unsigned)s,
          dc_status_str(s), (unsigned)expected);
    expect_failed_handle(what, h);
}

/* dc_init_with_table must fail with `expected`, leave a NULL handle, and leave a message in
 * dc_last_init_error that contains `says`. */
static void expect_init_table(const char *what, const DcCellConfig *config, const unsigned char *table, size_t len,
                              DcStatus expected, const char *says)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init_with_table(config, table, len, &h);
    char message[512];
    size_t n;
    check(s == expected, "bad input, dc_init_with_table %s: status %u (%s), expected %u (%s)", what, (unsigned)s,
          dc_status_str(s), (unsigned)expected, dc_status_str(expected));
    n = dc_last_init_error(message, sizeof message);
    check(n > 0 && strstr(message, says) != NULL, "bad input, dc_init_with_table %s: message \"%s\" lacks \"%s\"",
          what, message, says);
    expect_failed_handle(what, h);
}

static void expect_init_files(const char *what, const char *cell_path, const char *table_path, DcStatus expected)
{
    DcCollider *h = (DcCollider *)(void *)&dummy_object;
    DcStatus s = dc_init_from_files(cell_path, table_path, &h);
    check(s == expected, "bad input, dc_init_from_files %s: status %u (%s), expected %u (%s)", what, (unsigned)s,
          dc_status_str(s), (unsigned)expected, dc_status_str(expected));
    expect_failed_handle(what, h);
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

/* Bad configurations and cell files (exact mode). */
static void bad_configs(const HarnessOptions *options, const DcCellConfig *config, const DcRobotConfig *robots)
{
    DcRobotConfig bad[MR_MAX_ROBOTS];
    DcCellConfig broken;
    DcStatus s;
    char path[512];
    const double qnan = NAN;

    expect_init("NULL config", NULL, DC_STATUS_NULL_POINTER);
    s = dc_init(config, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init NULL out_handle: %u", (unsigned)s);
    broken = *config;
    broken.n_robots = 0;
    expect_init("zero robots", &broken, DC_STATUS_INVALID_CONFIG);
    broken = *config;
    broken.robots = NULL;
    expect_init("NULL robots", &broken, DC_STATUS_NULL_POINTER);
    memcpy(bad, robots, sizeof bad);
    broken = *config;
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
    bad[0].translation.x = qnan; /* NaN in a configuration: documented as INVALID_CONFIG */
    expect_init("NaN translation", &broken, DC_STATUS_INVALID_CONFIG);
    bad[0].translation.x = 0.0;
    broken = *config;
    broken.method = 7;
    expect_init("unknown method", &broken, DC_STATUS_INVALID_CONFIG);
    {
        size_t i;
        for (i = 0; i < 33; ++i) {
            many_robots[i] = robots[0];
            many_robots[i].translation.x = 450.0 * (double)i;
        }
        broken = *config;
        broken.robots = many_robots;
        broken.n_robots = 33;
        expect_init("33 robots", &broken, DC_STATUS_INVALID_CONFIG);
    }

    /* dc_init_from_cell_file */
    expect_init_file("NULL path", NULL, DC_STATUS_NULL_POINTER);
    s = dc_init_from_cell_file("cells/t1.toml", NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init_from_cell_file NULL out_handle: %u", (unsigned)s);
    expect_init_file("missing path", "cells/no_such_cell_file.toml", DC_STATUS_IO);
    sprintf(path, "%.400s/c_harness_malformed_cell.toml", options->tmp_dir);
    check(write_file(path, "[[robot]\nname = \"A\"\nf = 100.0 = 3\n"), "cannot write %s", path);
    expect_init_file("malformed TOML", path, DC_STATUS_PARSE);
    check(write_file(path, "name = \"bad\"\n[[robot]]\nname = \"A\"\n"
                           "placement = { alpha_deg = 30.0, t = [1.0, 2.0] }\n"),
          "cannot write %s", path);
    expect_init_file("wrong schema", path, DC_STATUS_PARSE);
    check(write_file(path, "[[robot]]\nname = \"A\"\ngeometry = { f = -100.0, rf = 150.0, re = 400.0, e = 40.0, "
                           "theta_min_deg = -90.0, theta_max_deg = 120.0 }\n"),
          "cannot write %s", path);
    expect_init_file("negative f in the file", path, DC_STATUS_INVALID_CONFIG);
    remove(path);
    expect_init_file("path not UTF-8", "cells/\xff\xfe.toml", DC_STATUS_INVALID_ARGUMENT);
}

/* Flips one bit of the table at `at`, expects DC_STATUS_TABLE_CORRUPT, and restores it. */
static void expect_flipped_bit(const DcCellConfig *config, unsigned char *table, size_t len, size_t at,
                               unsigned bit)
{
    char what[96];
    sprintf(what, "bit %u flipped at byte %lu of %lu", bit, (unsigned long)at, (unsigned long)len);
    table[at] ^= (unsigned char)(1u << bit);
    expect_init_table(what, config, table, len, DC_STATUS_TABLE_CORRUPT, "corrupt");
    table[at] ^= (unsigned char)(1u << bit);
}

/* Table-mode init errors on T1's table (and T2's when given), then the query-time bad inputs
 * on a good table-mode handle. */
static void bad_tables(const HarnessOptions *options, const DcCellConfig *t1_config)
{
    HarnessTable t1 = options->tables[0];
    const HarnessTable *t2 = &options->tables[1];
    MrCell cell;
    DcRobotConfig robots_t2[MR_MAX_ROBOTS], three[3];
    DcCellConfig config_t2, broken;
    DcCollider *h = NULL;
    DcStatus s;
    unsigned char saved[8];
    size_t lengths[9], i;
    char what[96], message[256];

    /* Truncated: several lengths, 0 included. */
    lengths[0] = 0;
    lengths[1] = 1;
    lengths[2] = 8;
    lengths[3] = 183;
    lengths[4] = 184;
    lengths[5] = 1000;
    lengths[6] = t1.len / 2;
    lengths[7] = t1.len - 8;
    lengths[8] = t1.len - 1;
    for (i = 0; i < sizeof lengths / sizeof lengths[0]; ++i) {
        sprintf(what, "T1 table truncated to %lu of %lu bytes", (unsigned long)lengths[i], (unsigned long)t1.len);
        expect_init_table(what, t1_config, t1.bytes, lengths[i], DC_STATUS_TABLE_TRUNCATED, "truncated");
    }
    /* One flipped bit: in the first codes, in the middle, in the last code, in the checksum. */
    expect_flipped_bit(t1_config, t1.bytes, t1.len, 300, 0);
    expect_flipped_bit(t1_config, t1.bytes, t1.len, t1.len / 2, 5);
    expect_flipped_bit(t1_config, t1.bytes, t1.len, t1.len - 9, 7);
    expect_flipped_bit(t1_config, t1.bytes, t1.len, t1.len - 1, 3);
    /* The header's identity fields. */
    memcpy(saved, t1.bytes, sizeof saved);
    t1.bytes[0] = 'X';
    expect_init_table("bad magic", t1_config, t1.bytes, t1.len, DC_STATUS_TABLE_BAD_MAGIC, "magic");
    memcpy(t1.bytes, saved, sizeof saved);
    memcpy(saved, t1.bytes + 8, 4);
    for (i = 0; i < 4; ++i) {
        t1.bytes[8 + i] = saved[3 - i];
    }
    expect_init_table("byte-swapped endianness marker", t1_config, t1.bytes, t1.len, DC_STATUS_TABLE_WRONG_ENDIANNESS,
                      "big-endian");
    memcpy(t1.bytes + 8, saved, 4);
    t1.bytes[12] ^= 0x40;
    expect_init_table("format version + 64", t1_config, t1.bytes, t1.len, DC_STATUS_TABLE_UNSUPPORTED_VERSION,
                      "version");
    t1.bytes[12] ^= 0x40;

    /* A table built for another cell. */
    mr_register_cell("T2", &cell);
    pou_cell_config(&cell, DC_METHOD_SAT, robots_t2, &config_t2);
    expect_init_table("T1's table for T2's config", &config_t2, t1.bytes, t1.len, DC_STATUS_TABLE_WRONG_CELL,
                      "built for cell");
    if (t2->bytes != NULL) {
        expect_init_table("T2's table for T1's config", t1_config, t2->bytes, t2->len, DC_STATUS_TABLE_WRONG_CELL,
                          "built for cell");
    }
    /* Three robots 450 mm apart also need the pair 900 mm apart, which T1's table is not; one
     * robot has no pair; bad configs are reported before the table is read. */
    three[0] = t1_config->robots[0];
    three[1] = t1_config->robots[1];
    three[2] = t1_config->robots[1];
    three[2].translation.x = 900.0;
    broken = *t1_config;
    broken.robots = three;
    broken.n_robots = 3;
    expect_init_table("three robots", &broken, t1.bytes, t1.len, DC_STATUS_TABLE_MISSING_PAIR, "no table for robot 0-robot 2");
    broken.n_robots = 1;
    expect_init_table("one robot", &broken, t1.bytes, t1.len, DC_STATUS_TABLE_NOT_TWO_ROBOTS, "two-robot");
    broken.n_robots = 0;
    expect_init_table("zero robots", &broken, t1.bytes, t1.len, DC_STATUS_INVALID_CONFIG, "n_robots");
    expect_init_table("NULL config", NULL, t1.bytes, t1.len, DC_STATUS_NULL_POINTER, "config");
    expect_init_table("NULL table", t1_config, NULL, t1.len, DC_STATUS_NULL_POINTER, "table");
    s = dc_init_with_table(t1_config, t1.bytes, t1.len, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init_with_table NULL out_handle: %u", (unsigned)s);

    /* From files. */
    expect_init_files("NULL cell path", NULL, t1.path, DC_STATUS_NULL_POINTER);
    expect_init_files("NULL table path", "cells/t1.toml", NULL, DC_STATUS_NULL_POINTER);
    expect_init_files("missing table file", "cells/t1.toml", "c_harness/no_such_table.dct", DC_STATUS_IO);
    expect_init_files("missing cell file", "cells/no_such_cell.toml", t1.path, DC_STATUS_IO);
    expect_init_files("not a table (the scenario file)", "cells/t1.toml", "c_harness/scenarios.txt",
                      DC_STATUS_TABLE_BAD_MAGIC);
    expect_init_files("T1's table with cells/t2.toml", "cells/t2.toml", t1.path, DC_STATUS_TABLE_WRONG_CELL);
    s = dc_init_from_files("cells/t1.toml", t1.path, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_init_from_files NULL out_handle: %u", (unsigned)s);

    /* The buffer is intact again: a good table-mode handle, then the query-time bad inputs. */
    s = dc_init_with_table(t1_config, t1.bytes, t1.len, &h);
    check(s == DC_STATUS_OK && h != NULL && dc_mode(h) == DC_MODE_TABLE, "bad input: table-mode init of T1: %s",
          dc_status_str(s));
    check(dc_last_init_error(message, sizeof message) == 0 && message[0] == '\0',
          "bad input: dc_last_init_error after a successful init: \"%s\"", message);
    if (h != NULL) {
        check(dc_robot_count(h) == 2 && dc_pair_count(h) == 1, "bad input: table-mode counts %lu robots, %lu pairs",
              (unsigned long)dc_robot_count(h), (unsigned long)dc_pair_count(h));
        bad_queries("table mode", h);
        dc_destroy(h);
    }
}

/* Expects dc_init to refuse `config` with INVALID_CONFIG and a message naming `field`. */
static void expect_init_naming(const char *what, const DcCellConfig *config, const char *field)
{
    char message[512];
    expect_init(what, config, DC_STATUS_INVALID_CONFIG);
    check(dc_last_init_error(message, sizeof message) > 0 && strstr(message, field) != NULL,
          "fail closed, %s: message \"%s\" does not name %s", what, message, field);
}

/* One query that must answer OK and COLLISION. */
static void expect_collision(const char *what, DcCollider *h, const DcVec3 *tcps)
{
    DcVerdict v = DC_VERDICT_FREE;
    DcStatus s = dc_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && v == DC_VERDICT_COLLISION, "fail closed, %s: status %u (%s), verdict %u, expected OK and "
          "COLLISION", what, (unsigned)s, dc_status_str(s), (unsigned)v);
}

/* The cases of an adversarial review that answered FREE, or took a bad input, where they must
 * not: a singular pose (lower link 0 along its motor axis), huge finite configuration values,
 * -0.0 as another cell, and a binary file given as a cell file. */
static void fail_closed(const HarnessOptions *options, const DcCellConfig *config, const DcRobotConfig *robots)
{
    DcRobotConfig r[MR_MAX_ROBOTS];
    DcCellConfig c = *config;
    DcCollider *h = NULL;
    DcStatus s;
    DcVec3 t[2];
    char path[512];
    FILE *f;
    static const unsigned char binary[] = { 0x7f, 'E', 'L', 'F', 0xff, 0xfe, 0x00, 0x01, 0xc3, 0x28 };

    /* (60, 400, -150): y = re exactly and hypot(a, c) = rf, reachable with link 0 along t_0. */
    t[0] = vec3(60.0, 400.0, -150.0);
    t[1] = vec3(-258.41263562619667, 256.22158467793497, -152.07408585805371);
    s = dc_init(config, &h);
    check(s == DC_STATUS_OK, "fail closed: dc_init T1: %s", dc_status_str(s));
    if (h != NULL) {
        expect_collision("singular pose, exact mode", h, t);
        t[0].z = -150.000001;
        expect_collision("next to the singular pose, exact mode", h, t);
        t[0].z = -150.0;
        dc_destroy(h);
        h = NULL;
    }
    if (options->tables[0].bytes != NULL) {
        s = dc_init_with_table(config, options->tables[0].bytes, options->tables[0].len, &h);
        check(s == DC_STATUS_OK, "fail closed: dc_init_with_table T1: %s", dc_status_str(s));
        if (h != NULL) {
            /* Outside the table's grid: the exact fallback answers. */
            expect_collision("singular pose, table mode", h, t);
            dc_destroy(h);
            h = NULL;
        }
        /* -0.0 is the same cell as 0.0. */
        memcpy(r, robots, sizeof r);
        r[1].translation.y = -0.0;
        r[0].translation.x = -0.0;
        c.robots = r;
        s = dc_init_with_table(&c, options->tables[0].bytes, options->tables[0].len, &h);
        check(s == DC_STATUS_OK, "fail closed: T1 with translation.y = -0.0 refused its table: %s",
              dc_status_str(s));
        dc_destroy(h);
        h = NULL;
    }

    /* Huge finite values overflowed the bounding boxes into NaN: refused, the field named. */
    memcpy(r, robots, sizeof r);
    c.robots = r;
    r[0].translation.x = 1e308;
    r[1].translation.x = 1e308;
    expect_init_naming("translation.x = 1e308", &c, "translation.x");
    memcpy(r, robots, sizeof r);
    r[0].margin = 1.5e308;
    expect_init_naming("margin = 1.5e308", &c, "margin");
    memcpy(r, robots, sizeof r);
    r[1].geometry.re = 1e300;
    expect_init_naming("re = 1e300", &c, "parameter re = ");
    memcpy(r, robots, sizeof r);
    r[1].half_height = 2e6;
    expect_init_naming("half_height = 2e6", &c, "half_height");

    /* A file that is not text is not TOML: DC_STATUS_PARSE, as documented, not DC_STATUS_IO. */
    sprintf(path, "%.400s/c_harness_binary_cell.toml", options->tmp_dir);
    f = fopen(path, "wb");
    check(f != NULL && fwrite(binary, 1, sizeof binary, f) == sizeof binary && fclose(f) == 0, "cannot write %s",
          path);
    expect_init_file("binary cell file", path, DC_STATUS_PARSE);
    remove(path);
    printf("fail closed: done\n");
}

/* A protective query that must fail: the status, a STOP verdict over the pre-set FREE, and the report. */
static void expect_protective(const char *what, DcCollider *h, const DcVec3 *tcps, size_t n, DcStatus expected,
                              uint32_t mask)
{
    DcVerdict v = DC_VERDICT_FREE;
    DcProtectiveReport rep;
    DcStatus s;
    memset(&rep, 0, sizeof rep);
    rep.verdict = DC_VERDICT_FREE;
    s = dc_protective_query(h, tcps, n, &v, &rep);
    check(s == expected, "bad input (protective), %s: status %u (%s), expected %u", what, (unsigned)s,
          dc_status_str(s), (unsigned)expected);
    check(v == DC_VERDICT_STOP && rep.verdict == DC_VERDICT_STOP, "bad input (protective), %s: verdict %u / %u", what,
          (unsigned)v, (unsigned)rep.verdict);
    check(rep.unreachable_mask == mask, "bad input (protective), %s: unreachable_mask %u, expected %u", what,
          (unsigned)rep.unreachable_mask, (unsigned)mask);
}

/* dc_protective_query and dc_set_stop_model: every documented status, fail-closed outputs. */
static void bad_protective(DcCollider *h)
{
    DcVec3 tcps[2];
    DcStopConfig stops[2];
    DcVerdict v = DC_VERDICT_FREE;
    DcStatus s;
    char message[256];
    const double qnan = NAN;

    tcps[0] = vec3(-150.0, 0.0, -450.0);
    tcps[1] = vec3(150.0, 0.0, -450.0);
    stops[0] = dc_stop_config_default();
    stops[1] = dc_stop_config_default();
    check(stops[0].struct_size == sizeof(DcStopConfig) && stops[0].reaction_ms == 4.0
              && stops[0].decel_mm_s2 == 40000.0 && stops[0].max_accel_mm_s2 == 130000.0
              && stops[0].max_speed_mm_s == 4600.0,
          "bad input (protective): dc_stop_config_default is not the documented default");
    /* First query: no previous TCP, full speed assumed; standing still afterwards: FREE. */
    s = dc_protective_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK, "bad input (protective): first query status %u", (unsigned)s);
    s = dc_protective_query(h, tcps, 2, &v, NULL);
    check(s == DC_STATUS_OK && v == DC_VERDICT_FREE, "bad input (protective): still robots apart: status %u verdict %u",
          (unsigned)s, (unsigned)v);
    expect_protective("NULL handle", NULL, tcps, 2, DC_STATUS_NULL_POINTER, 0);
    expect_protective("NULL tcps", h, NULL, 2, DC_STATUS_NULL_POINTER, 0);
    expect_protective("one TCP for two robots", h, tcps, 1, DC_STATUS_WRONG_ROBOT_COUNT, 0);
    s = dc_protective_query(h, tcps, 2, NULL, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input (protective), NULL out_verdict: %u", (unsigned)s);
    tcps[1].y = qnan;
    expect_protective("NaN TCP", h, tcps, 2, DC_STATUS_NON_FINITE, 2u);
    tcps[1] = vec3(0.0, 0.0, -900.0);
    expect_protective("unreachable TCP", h, tcps, 2, DC_STATUS_UNREACHABLE, 2u);
    tcps[1] = vec3(150.0, 0.0, -450.0);
    dc_protective_query(h, tcps, 2, &v, NULL);
    tcps[0].x += 10.0; /* 10 mm in 1 ms: 10 m/s */
    expect_protective("a 10 mm jump", h, tcps, 2, DC_STATUS_IMPLAUSIBLE_MOTION, 1u);

    s = dc_set_stop_model(NULL, 1.0, 10.0, stops, 2);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_set_stop_model NULL handle: %u", (unsigned)s);
    s = dc_set_stop_model(h, 1.0, 10.0, NULL, 2);
    check(s == DC_STATUS_NULL_POINTER, "bad input, dc_set_stop_model NULL stops: %u", (unsigned)s);
    s = dc_set_stop_model(h, 1.0, 10.0, stops, 1);
    check(s == DC_STATUS_WRONG_ROBOT_COUNT, "bad input, dc_set_stop_model one model: %u", (unsigned)s);
    s = dc_set_stop_model(h, 0.0, 10.0, stops, 2);
    dc_last_init_error(message, sizeof message);
    check(s == DC_STATUS_INVALID_CONFIG && strstr(message, "tick_ms") != NULL,
          "bad input, dc_set_stop_model tick 0: %u (%s)", (unsigned)s, message);
    s = dc_set_stop_model(h, 1.0, -1.0, stops, 2);
    check(s == DC_STATUS_INVALID_CONFIG, "bad input, dc_set_stop_model warn -1: %u", (unsigned)s);
    stops[1].struct_size = 8;
    s = dc_set_stop_model(h, 1.0, 10.0, stops, 2);
    dc_last_init_error(message, sizeof message);
    check(s == DC_STATUS_INVALID_ARGUMENT && strstr(message, "struct_size") != NULL,
          "bad input, dc_set_stop_model struct_size 8: %u (%s)", (unsigned)s, message);
    stops[1] = dc_stop_config_default();
    stops[1].decel_mm_s2 = 200000.0;
    s = dc_set_stop_model(h, 1.0, 10.0, stops, 2);
    dc_last_init_error(message, sizeof message);
    check(s == DC_STATUS_INVALID_CONFIG && strstr(message, "decel_mm_s2") != NULL,
          "bad input, dc_set_stop_model decel above max accel: %u (%s)", (unsigned)s, message);
    stops[1] = dc_stop_config_default();
    stops[1].max_speed_mm_s = qnan;
    s = dc_set_stop_model(h, 1.0, 10.0, stops, 2);
    check(s == DC_STATUS_INVALID_CONFIG, "bad input, dc_set_stop_model NaN speed: %u", (unsigned)s);
    stops[1] = dc_stop_config_default();
    s = dc_set_stop_model(h, 1.0, 10.0, stops, 2);
    check(s == DC_STATUS_OK, "bad input, dc_set_stop_model defaults: %u", (unsigned)s);
    dc_protective_reset(NULL); /* a no-op */
    dc_protective_reset(h);
}

void bad_input(const HarnessOptions *options)
{
    MrCell cell;
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcCollider *h = NULL;
    DcStatus s;
    DcDelta3 g;
    DcVec3 tcp;
    double theta[3];
    unsigned code;
    const double qnan = NAN;

    mr_register_cell("T1", &cell);
    pou_cell_config(&cell, DC_METHOD_SAT_CACHE, robots, &config);
    s = dc_init(&config, &h);
    check(s == DC_STATUS_OK && h != NULL && dc_mode(h) == DC_MODE_EXACT, "bad input: dc_init T1: %s",
          dc_status_str(s));
    if (h != NULL) {
        bad_queries("exact mode", h);
        bad_protective(h);
        dc_destroy(h);
        h = NULL;
    }
    check(dc_robot_count(NULL) == 0 && dc_pair_count(NULL) == 0 && dc_mode(NULL) == DC_MODE_NONE
              && dc_table_fallbacks(NULL) == 0,
          "bad input: counts and mode of a NULL handle are not 0 / DC_MODE_NONE");
    bad_configs(options, &config, robots);
    fail_closed(options, &config, robots);
    if (options->tables[0].bytes != NULL) {
        bad_tables(options, &config);
    } else {
        printf("bad input: no T1 table given (--table T1=PATH): table-mode bad inputs skipped\n");
    }

    /* Teardown and strings. */
    dc_destroy(NULL); /* a no-op: reaching the next line is the test */
    for (code = 0; code <= DC_STATUS_IMPLAUSIBLE_MOTION; ++code) {
        const char *text = dc_status_str(code);
        check(text != NULL && text[0] != '\0' && strcmp(text, dc_status_str(12345u)) != 0,
              "dc_status_str(%u) is empty or unknown", code);
    }
    {
        const char *unknown = dc_status_str(12345u);
        check(unknown != NULL && strstr(unknown, "unknown") != NULL, "dc_status_str(12345) does not say unknown");
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
    s = dc_delta3_forward_kinematics(&g, NULL, &tcp);
    check(s == DC_STATUS_NULL_POINTER, "bad input, FK NULL theta: %u", (unsigned)s);
    g.rf = -150.0;
    s = dc_delta3_inverse_kinematics(&g, vec3(0.0, 0.0, -450.0), theta);
    check(s == DC_STATUS_INVALID_CONFIG, "bad input, IK negative rf: %u", (unsigned)s);
    g.rf = 150.0;
    theta[0] = theta[1] = theta[2] = 0.3;
    s = dc_delta3_forward_kinematics(&g, theta, NULL);
    check(s == DC_STATUS_NULL_POINTER, "bad input, FK NULL out_tcp: %u", (unsigned)s);
    theta[1] = qnan;
    s = dc_delta3_forward_kinematics(&g, theta, &tcp);
    check(s == DC_STATUS_NON_FINITE, "bad input, FK NaN angle: %u", (unsigned)s);
    printf("bad input: done (%s)\n", options->tables[0].bytes != NULL ? "exact and table mode" : "exact mode only");
}
