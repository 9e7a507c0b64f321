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

/* ------------------------------------------------------------ the function block */

/* The function block around the POU, as plc/src/FB_DeltaCollide.st: the same states and the
 * same transition table (plc/README.md, "State machine"; rows T1-T9), so that the harness
 * executes the lifecycle that the Structured Text only declares. Inputs are set before each
 * pou_fb_call (one PLC cycle); outputs are read after it. */
typedef enum PouFbState { POU_FB_IDLE = 0, POU_FB_ACTIVE = 1, POU_FB_ERROR = 2 } PouFbState;

/* The block's own ErrorIDs, above every library status (GVL_DeltaCollide's DCFB_ERR_*). */
#define POU_FB_ERR_TOO_MANY_ROBOTS 0x8001u
#define POU_FB_ERR_UNKNOWN_STATUS 0x80FFu

/* One transition a call took: its row of the table, and the states before and after. */
typedef struct PouFbTransition {
    int row;
    PouFbState from;
    PouFbState to;
} PouFbTransition;

typedef struct PouFb {
    /* inputs */
    int enable;
    int reset;
    const DcCellConfig *config; /* the cell (exact mode), or NULL to start from cell_file */
    const uint8_t *table;       /* with config: a table's bytes (table mode), or NULL */
    size_t table_len;
    const char *cell_file;      /* without config: a TOML cell file ... */
    const char *table_file;     /* ... and a table file, NULL or "" for exact mode */
    uint32_t n_robots;
    DcVec3 tcps[DC_MAX_ROBOTS]; /* robot j's TCP in its own MCS */
    /* outputs */
    int valid;
    int busy;
    int error;
    uint32_t error_id;
    unsigned diag_code;
    DcVerdict verdict;          /* DC_VERDICT_STOP whenever valid is 0 */
    int free;                   /* valid and verdict FREE */
    DcQueryReport report;
    char init_message[256];
    /* state */
    PouFbState state;
    DcCollider *handle;
    int enable_prev;
    int reset_prev;
    PouFbTransition taken[2];   /* the transitions of the last call */
    int n_taken;
} PouFb;

/* The block's initial values: IDLE, no handle, every output FALSE or 0 (verdict STOP). */
void pou_fb_start(PouFb *fb);

/* One call (one PLC cycle): the row of the state it starts in, then the query's row when it
 * is ACTIVE. Allocates nothing but in the init of a rising edge of enable. */
void pou_fb_call(PouFb *fb);

/* "IDLE", "ACTIVE" or "ERROR": the names of E_DcFbState and of the table. */
const char *pou_fb_state_name(PouFbState state);

#endif /* POU_H */
