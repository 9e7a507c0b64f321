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
