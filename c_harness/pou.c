/*
 * pou.c: the Program Organizational Unit (init / query per tick / destroy) around the
 * delta-collide C ABI, as in thesis appendix A.1. See pou.h.
 */
#include "pou.h"

#include <string.h>

void pou_cell_config(const MrCell *cell, uint32_t method, DcRobotConfig robots[MR_MAX_ROBOTS],
                     DcCellConfig *out)
{
    size_t j;
    for (j = 0; j < cell->n_robots; ++j) {
        const MrRobot *r = &cell->robots[j];
        DcRobotConfig c = dc_robot_config_thesis();
        c.geometry.f = r->geometry.f;
        c.geometry.rf = r->geometry.rf;
        c.geometry.re = r->geometry.re;
        c.geometry.e = r->geometry.e;
        c.geometry.theta_min = r->geometry.theta_min;
        c.geometry.theta_max = r->geometry.theta_max;
        c.half_height = r->half_height;
        c.half_depth = r->half_depth;
        c.margin = r->margin;
        c.has_upper_links = 0;
        c.has_platform = 0;
        c.has_tool = 0;
        c.alpha = r->alpha;
        c.translation.x = r->translation[0];
        c.translation.y = r->translation[1];
        c.translation.z = r->translation[2];
        robots[j] = c;
    }
    out->robots = robots;
    out->n_robots = cell->n_robots;
    out->method = method;
}

static void pou_reset(Pou *pou)
{
    memset(pou, 0, sizeof *pou);
    pou->handle = NULL;
    pou->last_status = DC_STATUS_OK;
    pou->last_verdict = DC_VERDICT_STOP;
    pou->stop_tick = -1;
    pou->stop_verdict = DC_VERDICT_STOP;
}

DcStatus pou_init(Pou *pou, const DcCellConfig *config)
{
    pou_reset(pou);
    pou->last_status = dc_init(config, &pou->handle);
    pou->n_robots = dc_robot_count(pou->handle);
    return pou->last_status;
}

DcStatus pou_init_from_file(Pou *pou, const char *path)
{
    pou_reset(pou);
    pou->last_status = dc_init_from_cell_file(path, &pou->handle);
    pou->n_robots = dc_robot_count(pou->handle);
    return pou->last_status;
}

DcStatus pou_init_with_table(Pou *pou, const DcCellConfig *config, const uint8_t *table, size_t table_len)
{
    pou_reset(pou);
    pou->last_status = dc_init_with_table(config, table, table_len, &pou->handle);
    pou->n_robots = dc_robot_count(pou->handle);
    return pou->last_status;
}

DcStatus pou_init_from_files(Pou *pou, const char *cell_path, const char *table_path)
{
    pou_reset(pou);
    pou->last_status = dc_init_from_files(cell_path, table_path, &pou->handle);
    pou->n_robots = dc_robot_count(pou->handle);
    return pou->last_status;
}

DcVerdict pou_query(Pou *pou, long tick, const DcVec3 *tcps_mcs, size_t n_tcps)
{
    DcVerdict verdict = DC_VERDICT_STOP;
    pou->last_status = dc_query(pou->handle, tcps_mcs, n_tcps, &verdict, &pou->last_report);
    /* Fail closed: FREE counts only together with an OK status. */
    if (pou->last_status != DC_STATUS_OK && verdict == DC_VERDICT_FREE) {
        verdict = DC_VERDICT_STOP;
    }
    pou->last_verdict = verdict;
    pou->n_queries++;
    if (verdict == DC_VERDICT_FREE) {
        pou->n_free++;
    } else if (verdict == DC_VERDICT_COLLISION) {
        pou->n_collision++;
    } else {
        pou->n_stop++;
    }
    if (verdict != DC_VERDICT_FREE && !pou->stop_requested) {
        pou->stop_requested = 1;
        pou->stop_tick = tick;
        pou->stop_verdict = verdict;
    }
    return verdict;
}

void pou_destroy(Pou *pou)
{
    dc_destroy(pou->handle);
    pou->handle = NULL;
}

/* ------------------------------------------------------------ the function block */

void pou_fb_start(PouFb *fb)
{
    memset(fb, 0, sizeof *fb);
    fb->handle = NULL;
    fb->state = POU_FB_IDLE;
    fb->verdict = DC_VERDICT_STOP;
    fb->report.verdict = DC_VERDICT_STOP;
}

const char *pou_fb_state_name(PouFbState state)
{
    switch (state) {
    case POU_FB_IDLE:
        return "IDLE";
    case POU_FB_ACTIVE:
        return "ACTIVE";
    case POU_FB_ERROR:
        return "ERROR";
    }
    return "?";
}

/* F_DcKnownStatus / F_DcErrorID: the status number, or the block's code for one it does not know. */
static uint32_t fb_error_id(DcStatus status)
{
    return status <= DC_STATUS_PROGRESS_OUT_OF_RANGE ? status : POU_FB_ERR_UNKNOWN_STATUS;
}

/* F_DcDiagError: 16#C1xx at init, 16#C2xx in a query, 16#C301 for too many robots. */
static unsigned fb_diag_error(uint32_t error_id, int at_init)
{
    if (error_id == POU_FB_ERR_TOO_MANY_ROBOTS) {
        return 0xC301u;
    }
    return (at_init ? 0xC100u : 0xC200u) | (error_id & 0xFFu);
}

/* F_DcInit: the init of the mode the inputs ask for. */
static DcStatus fb_init(PouFb *fb)
{
    if (fb->config != NULL && fb->table == NULL) {
        return dc_init(fb->config, &fb->handle);
    }
    if (fb->config != NULL) {
        return dc_init_with_table(fb->config, fb->table, fb->table_len, &fb->handle);
    }
    if (fb->table_file == NULL || fb->table_file[0] == '\0') {
        return dc_init_from_cell_file(fb->cell_file, &fb->handle);
    }
    return dc_init_from_files(fb->cell_file, fb->table_file, &fb->handle);
}

/* `State := to; Transition := row;` of the ST. */
static void fb_go(PouFb *fb, int row, PouFbState to)
{
    if (fb->n_taken < 2) {
        fb->taken[fb->n_taken].row = row;
        fb->taken[fb->n_taken].from = fb->state;
        fb->taken[fb->n_taken].to = to;
        fb->n_taken++;
    }
    fb->state = to;
}

static void fb_destroy(PouFb *fb)
{
    dc_destroy(fb->handle);
    fb->handle = NULL;
}

/* The row of the state the call starts in (T1-T4, T7-T9). */
static void fb_state_row(PouFb *fb)
{
    DcStatus s;
    switch (fb->state) {
    case POU_FB_IDLE:
        if (!(fb->enable && !fb->enable_prev)) {
            fb_go(fb, 3, POU_FB_IDLE);
            return;
        }
        fb->handle = NULL;
        s = fb_init(fb);
        if (s == DC_STATUS_OK) {
            fb->init_message[0] = '\0';
            fb_go(fb, 1, POU_FB_ACTIVE);
            return;
        }
        fb->handle = NULL;
        dc_last_init_error(fb->init_message, sizeof fb->init_message);
        fb->error_id = fb_error_id(s);
        fb->diag_code = fb_diag_error(fb->error_id, 1);
        fb_go(fb, 2, POU_FB_ERROR);
        return;
    case POU_FB_ACTIVE:
        if (!fb->enable) {
            fb_destroy(fb);
            fb_go(fb, 4, POU_FB_IDLE);
        }
        return;
    case POU_FB_ERROR:
        if (fb->reset && !fb->reset_prev) {
            fb_destroy(fb);
            fb->error_id = 0;
            fb_go(fb, 7, POU_FB_IDLE);
        } else if (!fb->enable && fb->handle != NULL) {
            fb_destroy(fb);
            fb_go(fb, 8, POU_FB_ERROR);
        } else {
            fb_go(fb, 9, POU_FB_ERROR);
        }
        return;
    }
}

/* The query of a call that is (still) ACTIVE (T5, T6). */
static void fb_query_row(PouFb *fb)
{
    uint32_t status;
    if (fb->n_robots > DC_MAX_ROBOTS) {
        status = POU_FB_ERR_TOO_MANY_ROBOTS;
    } else {
        status = dc_query(fb->handle, fb->tcps, fb->n_robots, &fb->verdict, &fb->report);
    }
    if (status == DC_STATUS_OK) {
        fb_go(fb, 5, POU_FB_ACTIVE);
        return;
    }
    fb->error_id = status == POU_FB_ERR_TOO_MANY_ROBOTS ? status : fb_error_id(status);
    fb->diag_code = fb_diag_error(fb->error_id, 0);
    fb_go(fb, 6, POU_FB_ERROR);
}

void pou_fb_call(PouFb *fb)
{
    fb->n_taken = 0;
    fb_state_row(fb);
    if (fb->state == POU_FB_ACTIVE) {
        fb_query_row(fb);
    }
    fb->enable_prev = fb->enable;
    fb->reset_prev = fb->reset;
    fb->valid = fb->state == POU_FB_ACTIVE;
    fb->busy = fb->valid;
    fb->error = fb->state == POU_FB_ERROR;
    if (!fb->valid) {
        /* Fail closed: nothing but a query that returned OK may say FREE. */
        fb->verdict = DC_VERDICT_STOP;
        fb->report.verdict = DC_VERDICT_STOP;
    }
    fb->free = fb->valid && fb->verdict == DC_VERDICT_FREE;
    if (fb->state == POU_FB_IDLE) {
        fb->error_id = 0;
        fb->diag_code = fb->enable ? 0x0001u : 0x0000u;
    } else if (fb->valid) {
        fb->diag_code = fb->free ? 0x8000u : 0x8001u;
    }
}
