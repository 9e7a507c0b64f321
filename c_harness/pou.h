/*
 * pou.h: the Program Organizational Unit around the delta-collide C ABI (thesis appendix A.1).
 *
 * On the NJ-controller the collision project lives in a POU: it is initialised at system
 * start-up, queried once per 1 ms tick with the TCPs the robotics API delivers, and destroyed
 * at termination. This POU does the same: pou_init* (exact mode: dc_init or
 * dc_init_from_cell_file; table mode: dc_init_with_table or dc_init_from_files), pou_query
 * (dc_query, the same in both modes; anything but FREE requests a stop of all robots) and
 * pou_destroy (dc_destroy). It allocates nothing per tick.
 */
#ifndef POU_H
#define POU_H

#include "delta_collide.h"
#include "mock_robotics.h"

typedef struct Pou {
    DcCollider *handle;
    size_t n_robots;
    DcStatus last_status;
    DcVerdict last_verdict;
    DcQueryReport last_report;
    int stop_requested;       /* latched: set by the first query that is not FREE */
    long stop_tick;           /* tick of that query, -1 while none */
    DcVerdict stop_verdict;   /* its verdict (COLLISION, or STOP on an error) */
    unsigned long n_queries;
    unsigned long n_free;
    unsigned long n_collision;
    unsigned long n_stop;
} Pou;

/* Builds the C ABI configuration of a registered cell into robots[] (MR_MAX_ROBOTS long). */
void pou_cell_config(const MrCell *cell, uint32_t method, DcRobotConfig robots[MR_MAX_ROBOTS],
                     DcCellConfig *out);

/* Start-up: creates the collider from a configuration; returns the dc_init status. */
DcStatus pou_init(Pou *pou, const DcCellConfig *config);

/* Start-up from a TOML cell file; returns the dc_init_from_cell_file status. */
DcStatus pou_init_from_file(Pou *pou, const char *path);

/* Start-up in table mode from a table file's bytes (copied by the library: the caller may
 * free them afterwards); returns the dc_init_with_table status. */
DcStatus pou_init_with_table(Pou *pou, const DcCellConfig *config, const uint8_t *table, size_t table_len);

/* Start-up in table mode from a TOML cell file and a table file; returns the
 * dc_init_from_files status. */
DcStatus pou_init_from_files(Pou *pou, const char *cell_path, const char *table_path);

/* One tick: queries the TCPs (each in its robot's MCS) and returns the verdict. The first
 * verdict that is not FREE latches stop_requested and stop_tick. */
DcVerdict pou_query(Pou *pou, long tick, const DcVec3 *tcps_mcs, size_t n_tcps);

/* Termination: destroys the collider (safe to call twice). */
void pou_destroy(Pou *pou);

#endif /* POU_H */
