/*
 * timing.c: the timed protective query (dc_protective_query_timed) under the controller's
 * clock (SPEC section 8, docs/PROTECTIVE.md). Every robot has the stopping model of
 * timing_model() (reaction 3 ms, deceleration 40000 mm/s^2, the rest default).
 *
 * Twice per cycle: a function block that runs twice in one cycle hands the library the same
 * cycle and TCPs twice. On the collision scenario of T1, T2 and T3 the second timed call must
 * return the first call's status, verdict and report unchanged, and the first calls must
 * answer, tick for tick, as an untimed handle called once per tick. Beside them the untimed
 * dc_protective_query is called twice per tick: its second call reads a displacement of 0 as
 * a robot standing still, and the ticks where it answers better than the first call (STOP ->
 * WARN or FREE, WARN -> FREE) are counted, each with a stop simulated from the true motion
 * (below): on the whole runs some of those stops touch, the hazard the timed query removes.
 *
 * Schedules: on a window of the practical and of the collision scenario of each cell (a
 * whole cycle; the cycle in which the robots collide), the timed query is driven by
 * schedules a real controller can produce: repeated cycles (with the same TCPs, and with
 * other ones), skipped cycles (1-3: an interval the speeds are bounded over), longer gaps,
 * an older cycle sent again, a change of clock and untimed calls in between, timestamps
 * with +-30 % of a tick of jitter whose TCPs are those of the jittered moment, timestamps
 * less than half a tick apart, resets, and all of them mixed. Each call's status must be the
 * one the documented timing rules give (expect_status, a model of them written from the
 * header), every fault STOP, a repeat the last answer unchanged, and the first answered call
 * after a fault, an untimed call, a reset or the start must assume full speed (its
 * protective_mm equal to a fresh handle's). After every FREE or WARN a stop is simulated from
 * the true motion at the TCPs' moment: each robot keeps its programmed motion for its
 * reaction time plus one tick (the STOP comes at the next cycle at the latest), then brakes
 * along its path; every 0.1 ms of it is checked for contact with the exact model
 * (stop_substep, as protective.c), and every 1 ms and at its end its clearance is measured.
 *
 * Prints one line per cell for the twice-per-cycle runs and one per scenario and schedule.
 * --quick and --protective-quick (valgrind, qemu) run T1 collision only, on 200 ticks
 * around its first contact.
 */
#include "harness.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define TIMING_TICK_MS 1.0            /* the tick open_protective sets */
#define TICK_NS 1000000ull            /* that tick in ns */
#define CYCLE_ORIGIN 1000003ull       /* the cycle counter at tick 0: a controller's is not 0 */
#define NANOS_ORIGIN 86400000000123ull /* the monotonic clock at tick 0: a day after boot */
#define MAX_CALLS 4096                /* calls of one schedule at most */
#define MAX_STOP_MS 1000.0            /* a stop still moving after this long has stalled */
#define QUICK_FROM 3550L              /* --quick: ticks around T1 collision's first contact */
#define QUICK_TICKS 200L

/* The stopping model of every robot here. */
static DcStopConfig timing_model(void)
{
    DcStopConfig m = dc_stop_config_default();
    m.reaction_ms = 3.0;
    m.decel_mm_s2 = 40000.0;
    return m;
}

/* STOP < WARN < FREE. */
static int rank(DcVerdict v)
{
    return v == DC_VERDICT_FREE ? 2 : v == DC_VERDICT_WARN ? 1 : 0;
}

static const char *verdict_name(DcVerdict v)
{
    if (v == DC_VERDICT_FREE || v == DC_VERDICT_WARN) {
        return v == DC_VERDICT_FREE ? "FREE" : "WARN";
    }
    return v == DC_VERDICT_STOP ? "STOP" : "?";
}

/* Field by field, bit for bit: a NaN clearance equals itself, and padding is not compared. */
static int same_report(const DcProtectiveReport *a, const DcProtectiveReport *b)
{
    return a->verdict == b->verdict && a->unreachable_mask == b->unreachable_mask
           && memcmp(&a->clearance_mm, &b->clearance_mm, sizeof a->clearance_mm) == 0
           && a->closest_robot_a == b->closest_robot_a && a->closest_robot_b == b->closest_robot_b
           && a->closest_box_a == b->closest_box_a && a->closest_box_b == b->closest_box_b
           && a->limiting_robot_a == b->limiting_robot_a
           && a->limiting_robot_b == b->limiting_robot_b
           && a->limiting_box_a == b->limiting_box_a && a->limiting_box_b == b->limiting_box_b
           && a->n_robots == b->n_robots
           && memcmp(a->protective_mm, b->protective_mm, sizeof a->protective_mm) == 0
           && memcmp(a->speed_limit_mm_s, b->speed_limit_mm_s, sizeof a->speed_limit_mm_s) == 0;
}

/* A report no call writes: a field the library left alone would show. */
static void scribble(DcProtectiveReport *r, DcVerdict *v)
{
    memset(r, 0xa5, sizeof *r);
    *v = 0xa5a5a5a5u;
}

/* Every robot's commanded TCP at the fractional tick `tick`. */
static void tcps_at(const MrScenario *s, double tick, DcVec3 out[MR_MAX_ROBOTS])
{
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        double p[3];
        mr_trajectory_tcp_at(&s->robots[j], tick, p);
        out[j] = vec3(p[0], p[1], p[2]);
    }
}

/* ------------------------------------------------------------ one cell's handles */

/* The handles of one reference cell, made once: each dc_set_stop_model builds a table of motor
 * angles (about 0.3 s). dc_protective_reset forgets the motion and the last call's time, all the
 * timing rules read, so one handle serves every schedule; it keeps what only steers the search
 * (kept proofs, where the speed limits' bisection starts, the closest features), which can
 * change a report's last digits and speed limits, not its verdict. */
typedef struct TimingCell {
    const char *name;
    MrCell cell;
    DcStopConfig stops[MR_MAX_ROBOTS];
    DcCollider *h[3];     /* protective handles, every robot with timing_model() */
    DcCollider *exact;    /* the exact model for the stops' contact checks */
    double full_mm[MR_MAX_ROBOTS]; /* protective_mm of a fresh handle's first answer: full speed */
} TimingCell;

static void close_cell(TimingCell *tc)
{
    size_t i;
    for (i = 0; i < 3; ++i) {
        dc_destroy(tc->h[i]);
        tc->h[i] = NULL;
    }
    dc_destroy(tc->exact);
    tc->exact = NULL;
}

/* Opens the handles of `cell_name`; returns 0 after a failed check (nothing left open). */
static int open_cell(const char *cell_name, TimingCell *tc)
{
    DcStopConfig model = timing_model();
    MrScenario scenario;
    DcVec3 tcps[MR_MAX_ROBOTS];
    DcProtectiveReport rep;
    DcVerdict v;
    size_t i, j;
    memset(tc, 0, sizeof *tc);
    tc->name = cell_name;
    for (i = 0; i < 3; ++i) {
        DcCollider *exact = NULL;
        if (!open_protective("timing", cell_name, "collision", &model, NULL, &tc->cell, &scenario,
                             tc->stops, &tc->h[i], &exact)) {
            close_cell(tc);
            return 0;
        }
        if (tc->exact == NULL) {
            tc->exact = exact;
        } else {
            dc_destroy(exact);
        }
    }
    /* Full speed: a fresh handle's first answer (any reachable TCPs give the same S). */
    tcps_at(&scenario, 0.0, tcps);
    check(dc_protective_query(tc->h[2], tcps, tc->cell.n_robots, &v, &rep) == DC_STATUS_OK,
          "timing %s: the first call of a fresh handle", cell_name);
    for (j = 0; j < tc->cell.n_robots; ++j) {
        tc->full_mm[j] = rep.protective_mm[j];
    }
    return 1;
}

static int load_case(const TimingCell *tc, const char *case_name, MrScenario *scenario)
{
    MrStatus ms = mr_load_scenario(SCENARIO_FILE, tc->name, case_name, tc->cell.n_robots, scenario);
    return check(ms == MR_OK, "timing %s %s: cannot load the scenario: %s", tc->name, case_name,
                 mr_status_str(ms));
}

/* ------------------------------------------------------------ a stop from the true motion */

/* The clearance of the cell at the stop's TCPs, from a protective handle with no history
 * (its verdict does not matter here); -INFINITY when it cannot be computed. */
static double clearance_now(DcCollider *measure, const MrStop stop[MR_MAX_ROBOTS], size_t n)
{
    DcVec3 tcps[MR_MAX_ROBOTS];
    DcProtectiveReport rep;
    DcVerdict v;
    size_t j;
    for (j = 0; j < n; ++j) {
        tcps[j] = vec3(stop[j].o.tcp[0], stop[j].o.tcp[1], stop[j].o.tcp[2]);
    }
    dc_protective_reset(measure);
    if (dc_protective_query(measure, tcps, n, &v, &rep) != DC_STATUS_OK) {
        return -INFINITY;
    }
    return rep.clearance_mm;
}

/* A stop from the true motion at `tick`: each robot keeps its programmed motion for its
 * reaction time plus one tick, then brakes along its path; every 0.1 ms checked for contact
 * (stop_substep). Returns the least clearance measured on `measure` every 1 ms and at the
 * end (INFINITY when `measure` is NULL). */
static double simulate_stop(DcCollider *exact, DcCollider *measure, const MrScenario *s,
                            double tick, StopStats *st)
{
    DcStopConfig model = timing_model();
    MrStop stop[MR_MAX_ROBOTS];
    double least = INFINITY;
    long n;
    int moving = 1;
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        MrOverride now;
        double b[3];
        now.path_tick = tick;
        mr_trajectory_tcp_at(&s->robots[j], tick, now.tcp);
        /* The speed now, should braking start within the first step: over the last 0.05 ms. */
        mr_trajectory_tcp_at(&s->robots[j], tick - 0.05, b);
        now.speed = sqrt((now.tcp[0] - b[0]) * (now.tcp[0] - b[0])
                         + (now.tcp[1] - b[1]) * (now.tcp[1] - b[1])
                         + (now.tcp[2] - b[2]) * (now.tcp[2] - b[2])) / 0.05e-3;
        now.cap = INFINITY;
        mr_stop_start(&now, model.reaction_ms + TIMING_TICK_MS, model.decel_mm_s2, &stop[j]);
    }
    st->stops++;
    for (n = 1; moving && n <= (long)(MAX_STOP_MS * STOP_SUBSTEPS); ++n) {
        moving = stop_substep(exact, s, stop, st);
        if (measure != NULL && (n % STOP_SUBSTEPS == 0 || !moving)) {
            least = fmin(least, clearance_now(measure, stop, s->n_robots));
        }
    }
    if (moving) {
        st->contacts++; /* a stop that never ends is no stop */
    }
    return least;
}

/* ------------------------------------------------------------ twice per cycle */

/* The collision scenario from tick `from`, `n_ticks` ticks, on the cell's three handles: the
 * first called timed twice per cycle, the second untimed once per tick, the third untimed
 * twice per tick. The first two must not have answered before: their reports are compared bit
 * for bit, and what a handle keeps beyond a reset reaches the last digits. Returns the ticks
 * where the third's second answer was the better. */
static unsigned long twice_per_cycle(TimingCell *tc, long from, long n_ticks,
                                     unsigned long *n_touching)
{
    MrScenario scenario;
    DcProtectiveRequest req = dc_protective_request_default();
    StopStats st = { 0, 0, 0, 0.0 };
    unsigned long differs = 0, once_differs = 0, better = 0, touching = 0, second_not_ok = 0;
    unsigned long n_verdict[3] = { 0, 0, 0 };
    long tick, first_better = -1, first_touching = -1, first_differs = -1;
    DcVerdict better_from = DC_VERDICT_STOP, better_to = DC_VERDICT_STOP;
    size_t n = tc->cell.n_robots;

    if (!load_case(tc, "collision", &scenario)) {
        return 0;
    }
    dc_protective_reset(tc->h[2]); /* its first answer was the full-speed one */
    for (tick = from; tick < from + n_ticks; ++tick) {
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcProtectiveReport r1, r2, ro, rt1, rt2;
        DcVerdict v1, v2, vo, vt1, vt2;
        DcStatus s1, s2, so, st2;
        tcps_at(&scenario, (double)tick, tcps);
        req.time = CYCLE_ORIGIN + (uint64_t)tick;
        req.tcps_mcs = tcps;
        req.n_tcps = n;
        scribble(&r1, &v1);
        scribble(&r2, &v2);
        s1 = dc_protective_query_timed(tc->h[0], &req, &v1, &r1);
        s2 = dc_protective_query_timed(tc->h[0], &req, &v2, &r2);
        if (s2 != s1 || v2 != v1 || !same_report(&r1, &r2)) {
            if (differs++ == 0) {
                first_differs = tick;
            }
        }
        n_verdict[rank(v1)]++;
        scribble(&ro, &vo);
        so = dc_protective_query(tc->h[1], tcps, n, &vo, &ro);
        once_differs += so != s1 || vo != v1 || !same_report(&ro, &r1);
        dc_protective_query(tc->h[2], tcps, n, &vt1, &rt1);
        st2 = dc_protective_query(tc->h[2], tcps, n, &vt2, &rt2);
        second_not_ok += st2 != DC_STATUS_OK;
        if (rank(vt2) > rank(vt1)) {
            unsigned long contacts = st.contacts;
            if (better++ == 0) {
                first_better = tick;
                better_from = vt1;
                better_to = vt2;
            }
            /* Would the second, better answer have been wrong? */
            simulate_stop(tc->exact, NULL, &scenario, (double)tick, &st);
            if (st.contacts > contacts && touching++ == 0) {
                first_touching = tick;
            }
        }
    }
    check(differs == 0,
          "timing %s collision: the second timed call of a cycle answered otherwise on %lu of %ld "
          "cycles (first %ld)", tc->name, differs, n_ticks, first_differs);
    check(once_differs == 0,
          "timing %s collision: timed twice per cycle, untimed once per tick: %lu ticks differ",
          tc->name, once_differs);
    check(n_verdict[0] > 0 && n_verdict[0] < (unsigned long)n_ticks,
          "timing %s collision: STOP on %lu of %ld ticks", tc->name, n_verdict[0], n_ticks);
    printf("timing %s collision twice per cycle: %ld cycles, second timed call unchanged on %lu, "
           "FREE %lu WARN %lu STOP %lu, untimed once per tick differs on %lu, untimed twice per "
           "tick: second call better on %lu ticks",
           tc->name, n_ticks, (unsigned long)n_ticks - differs, n_verdict[2], n_verdict[1],
           n_verdict[0], once_differs, better);
    if (better > 0) {
        printf(" (first at tick %ld: %s -> %s)", first_better, verdict_name(better_from),
               verdict_name(better_to));
    }
    printf(", of which a stop from the true motion touches on %lu", touching);
    if (touching > 0) {
        printf(" (first at tick %ld)", first_touching);
    }
    printf(", second call not OK on %lu\n", second_not_ok);
    *n_touching += touching;
    return better;
}

/* ------------------------------------------------------------ schedules */

typedef enum Schedule {
    SCHEDULE_REPEAT,    /* 20 % of cycles sent twice with the same TCPs, 10 % with newer ones */
    SCHEDULE_SKIP,      /* gaps of 1 to 4 cycles: 0 to 3 skipped */
    SCHEDULE_JUMP,      /* every cycle, and 5 % of gaps of 5 to 10 cycles */
    SCHEDULE_BACKWARDS, /* every cycle, and 5 % of the time an older one (1 to 8 back) again */
    SCHEDULE_CLOCKS,    /* every cycle, the clock changed 3 % of the time, 3 % untimed calls */
    SCHEDULE_JITTER,    /* timestamps at each tick +-30 % of a tick */
    SCHEDULE_EARLY,     /* timestamps +-10 %, 5 % of calls again within half a tick (or at it) */
    SCHEDULE_MIXED,     /* every event above on the cycle counter, and resets */
    N_SCHEDULES
} Schedule;

static const char *const schedule_names[N_SCHEDULES] = { "repeat", "skip",   "jump",  "backwards",
                                                         "clocks", "jitter", "early", "mixed" };

/* One call of a schedule. */
typedef struct Call {
    int untimed;   /* dc_protective_query instead */
    int reset;     /* dc_protective_reset before the call */
    DcClock clock;
    uint64_t time; /* cycle or timestamp */
    double tick;   /* the moment the TCPs hold (scenario ticks) */
} Call;

/* A generator of deterministic numbers (xorshift64*): the same schedules on every machine. */
typedef struct Rng {
    uint64_t state;
} Rng;

static double uniform(Rng *r)
{
    r->state ^= r->state >> 12;
    r->state ^= r->state << 25;
    r->state ^= r->state >> 27;
    return (double)((r->state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* An integer in [lo, hi]. */
static long between(Rng *r, long lo, long hi)
{
    long k = lo + (long)(uniform(r) * (double)(hi - lo + 1));
    return k > hi ? hi : k;
}

typedef struct Calls {
    Call call[MAX_CALLS];
    size_t n;
} Calls;

static void add(Calls *c, int untimed, DcClock clock, uint64_t time, double tick)
{
    if (c->n < MAX_CALLS) {
        Call *k = &c->call[c->n++];
        k->untimed = untimed;
        k->reset = 0;
        k->clock = clock;
        k->time = time;
        k->tick = tick;
    }
}

static void add_cycle(Calls *c, long cycle, double tcps_tick)
{
    add(c, 0, DC_CLOCK_CYCLE, CYCLE_ORIGIN + (uint64_t)cycle, tcps_tick);
}

/* A timestamp at `tick` (rounded to the ns), the TCPs of that very ns. */
static void add_nanos(Calls *c, double tick)
{
    long long ns = llround(tick * (double)TICK_NS);
    add(c, 0, DC_CLOCK_NANOS, NANOS_ORIGIN + (uint64_t)ns, (double)ns / (double)TICK_NS);
}

static void make_schedule(Schedule schedule, long from, long to, Calls *c)
{
    Rng rng;
    long t;
    int nanos = 0;
    rng.state = 0x9e3779b97f4a7c15ull ^ ((uint64_t)schedule << 32) ^ (uint64_t)from;
    c->n = 0;
    switch (schedule) {
    case SCHEDULE_REPEAT:
        for (t = from; t < to; ++t) {
            double u = uniform(&rng);
            add_cycle(c, t, (double)t);
            if (u < 0.2) {
                add_cycle(c, t, (double)t);
            } else if (u < 0.3) {
                add_cycle(c, t, (double)t + 0.5); /* a newer measurement under the same cycle */
            }
        }
        break;
    case SCHEDULE_SKIP:
        for (t = from; t < to; t += between(&rng, 1, 4)) {
            add_cycle(c, t, (double)t);
        }
        break;
    case SCHEDULE_JUMP:
        for (t = from; t < to; t += uniform(&rng) < 0.05 ? between(&rng, 5, 10) : 1) {
            add_cycle(c, t, (double)t);
        }
        break;
    case SCHEDULE_BACKWARDS:
        for (t = from; t < to; ++t) {
            add_cycle(c, t, (double)t);
            if (t - from >= 8 && uniform(&rng) < 0.05) {
                long back = between(&rng, 1, 8);
                add_cycle(c, t - back, (double)(t - back)); /* an older cycle's message again */
            }
        }
        break;
    case SCHEDULE_CLOCKS:
        for (t = from; t < to; ++t) {
            double u = uniform(&rng);
            if (u < 0.03) {
                nanos = !nanos;
            }
            if (u >= 0.03 && u < 0.06) {
                add(c, 1, DC_CLOCK_CYCLE, 0, (double)t); /* one tick after the last call */
            } else if (nanos) {
                add_nanos(c, (double)t);
            } else {
                add_cycle(c, t, (double)t);
            }
        }
        break;
    case SCHEDULE_JITTER:
        for (t = from; t < to; ++t) {
            add_nanos(c, (double)t + 0.6 * (uniform(&rng) - 0.5));
        }
        break;
    case SCHEDULE_EARLY:
        for (t = from; t < to; ++t) {
            add_nanos(c, (double)t + 0.2 * (uniform(&rng) - 0.5));
            if (uniform(&rng) < 0.05) {
                double last = c->call[c->n - 1].tick;
                add_nanos(c, last + (uniform(&rng) < 0.25 ? 0.5 : 0.02 + 0.43 * uniform(&rng)));
            }
        }
        break;
    case SCHEDULE_MIXED:
        for (t = from; t < to;) {
            double u = uniform(&rng);
            add_cycle(c, t, (double)t);
            if (u < 0.05) {
                add_cycle(c, t, (double)t);
            } else if (u < 0.08) {
                add_cycle(c, t, (double)t + 0.25);
            } else if (u < 0.10 && t - from >= 8) {
                long back = between(&rng, 1, 8);
                add_cycle(c, t - back, (double)(t - back));
            } else if (u < 0.12) {
                add(c, 1, DC_CLOCK_CYCLE, 0, (double)(t + 1));
                t += 1;
            } else if (u < 0.13) {
                add_cycle(c, t + 1, (double)(t + 1));
                c->call[c->n - 1].reset = 1;
                t += 1;
            }
            t += u > 0.97 ? between(&rng, 5, 8) : u > 0.85 ? between(&rng, 2, 4) : 1;
        }
        break;
    default:
        break;
    }
}

/* ------------------------------------------------------------ the documented timing rules */

/* What the rules remember of the last call. */
typedef struct Rules {
    int timed;       /* the last call was timed (0: none yet, a reset or an untimed call) */
    int full_speed;  /* the next computed call has no previous TCP */
    DcClock clock;
    uint64_t time;
    DcVec3 tcps[MR_MAX_ROBOTS];
    DcStatus status; /* the last answer */
    DcVerdict verdict;
    DcProtectiveReport report;
} Rules;

static void rules_reset(Rules *r)
{
    r->timed = 0;
    r->full_speed = 1;
}

/* The status of call `c` with TCPs `tcps` by the header's rules (the motion itself is the
 * scenario's, never implausible); *repeat set when the call repeats the last one exactly. */
static DcStatus expect_status(const Rules *r, const Call *c, const DcVec3 *tcps, size_t n,
                              int *repeat)
{
    uint64_t dt;
    *repeat = 0;
    if (c->untimed || !r->timed) {
        return DC_STATUS_OK;
    }
    if (c->clock != r->clock) {
        return DC_STATUS_CLOCK_CHANGED;
    }
    if (c->time < r->time) {
        return DC_STATUS_TIME_BACKWARDS;
    }
    if (c->time == r->time) {
        if (memcmp(tcps, r->tcps, n * sizeof *tcps) == 0) {
            *repeat = 1;
            return r->status;
        }
        return DC_STATUS_TIME_REPEATED;
    }
    dt = c->time - r->time;
    if (c->clock == DC_CLOCK_CYCLE) {
        return dt > DC_MAX_INTERVAL_TICKS ? DC_STATUS_TIME_JUMP : DC_STATUS_OK;
    }
    if (dt < TICK_NS / 2) {
        return DC_STATUS_TIME_EARLY;
    }
    return dt > DC_MAX_INTERVAL_TICKS * TICK_NS ? DC_STATUS_TIME_JUMP : DC_STATUS_OK;
}

/* Whether the rules say call `c` (not a repeat) assumes full speed. */
static int expect_full_speed(const Rules *r, const Call *c)
{
    return r->full_speed || (!c->untimed && !r->timed);
}

static void rules_after(Rules *r, const Call *c, const DcVec3 *tcps, size_t n, DcStatus s,
                        DcVerdict v, const DcProtectiveReport *rep)
{
    r->timed = !c->untimed;
    r->full_speed = s != DC_STATUS_OK;
    r->clock = c->clock;
    r->time = c->time;
    memcpy(r->tcps, tcps, n * sizeof *tcps);
    r->status = s;
    r->verdict = v;
    r->report = *rep;
}

/* ------------------------------------------------------------ one schedule */

/* What one schedule's calls gave. */
typedef struct ScheduleTally {
    unsigned long calls, repeats, n_verdict[3];
    unsigned long faults[5];     /* DC_STATUS_TIME_REPEATED .. DC_STATUS_CLOCK_CHANGED */
    unsigned long other_status;  /* a status neither OK nor a timing fault */
    unsigned long mismatches;    /* status other than the rules' */
    unsigned long open_faults;   /* a status not OK without STOP */
    unsigned long repeat_differs, full_checked, not_full, above_full;
    long first_mismatch;         /* call index */
    DcStatus mismatch_got, mismatch_expected;
    double least_clearance;      /* of the simulated stops */
} ScheduleTally;

/* The fault a schedule is made to provoke (DC_STATUS_OK: none in particular). */
static DcStatus provoked(Schedule schedule)
{
    switch (schedule) {
    case SCHEDULE_REPEAT:
        return DC_STATUS_TIME_REPEATED;
    case SCHEDULE_JUMP:
        return DC_STATUS_TIME_JUMP;
    case SCHEDULE_BACKWARDS:
        return DC_STATUS_TIME_BACKWARDS;
    case SCHEDULE_CLOCKS:
        return DC_STATUS_CLOCK_CHANGED;
    case SCHEDULE_EARLY:
        return DC_STATUS_TIME_EARLY;
    default:
        return DC_STATUS_OK;
    }
}

/* One schedule on the case `case_name` of the cell, from tick `from` to `to`: the timed
 * handle is the cell's first, the clearances are measured on its third (speed limits off). */
static void run_schedule(TimingCell *tc, const char *case_name, Schedule schedule, long from,
                         long to)
{
    static Calls calls; /* too large for the stack of some targets */
    const char *cell_name = tc->name, *name;
    MrScenario scenario;
    DcCollider *h = tc->h[0], *measure = tc->h[2];
    StopStats st = { 0, 0, 0, 0.0 };
    ScheduleTally t;
    Rules rules;
    const double *full_mm = tc->full_mm;
    size_t i, j, n = tc->cell.n_robots;
    DcStatus wanted = provoked(schedule);

    memset(&t, 0, sizeof t);
    t.first_mismatch = -1;
    t.least_clearance = INFINITY;
    if (!load_case(tc, case_name, &scenario)) {
        return;
    }
    dc_protective_reset(h);
    make_schedule(schedule, from, to, &calls);
    rules_reset(&rules);
    for (i = 0; i < calls.n; ++i) {
        const Call *c = &calls.call[i];
        DcProtectiveRequest req = dc_protective_request_default();
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcProtectiveReport rep;
        DcVerdict v;
        DcStatus s, expected;
        int repeat, full;
        tcps_at(&scenario, c->tick, tcps);
        if (c->reset) {
            dc_protective_reset(h);
            rules_reset(&rules);
        }
        expected = expect_status(&rules, c, tcps, n, &repeat);
        full = !repeat && expect_full_speed(&rules, c);
        scribble(&rep, &v);
        if (c->untimed) {
            s = dc_protective_query(h, tcps, n, &v, &rep);
        } else {
            req.clock = c->clock;
            req.time = c->time;
            req.tcps_mcs = tcps;
            req.n_tcps = n;
            s = dc_protective_query_timed(h, &req, &v, &rep);
        }
        t.calls++;
        if (s != expected) {
            if (t.mismatches++ == 0) {
                t.first_mismatch = (long)i;
                t.mismatch_got = s;
                t.mismatch_expected = expected;
            }
        }
        if (s >= DC_STATUS_TIME_REPEATED && s <= DC_STATUS_CLOCK_CHANGED) {
            t.faults[s - DC_STATUS_TIME_REPEATED] += !repeat;
        } else if (s != DC_STATUS_OK) {
            t.other_status++;
        }
        if (s != DC_STATUS_OK && (v != DC_VERDICT_STOP || rep.verdict != DC_VERDICT_STOP)) {
            t.open_faults++;
        }
        t.n_verdict[rank(v)]++;
        if (repeat) {
            t.repeats++;
            if (s != rules.status || v != rules.verdict || !same_report(&rep, &rules.report)) {
                t.repeat_differs++;
            }
            continue;
        }
        if (s == DC_STATUS_OK) {
            for (j = 0; j < n; ++j) {
                if (full) {
                    t.not_full += memcmp(&rep.protective_mm[j], &full_mm[j], sizeof *full_mm) != 0;
                } else {
                    t.above_full += !(rep.protective_mm[j] <= full_mm[j]);
                }
            }
            t.full_checked += full;
            if (v == DC_VERDICT_FREE || v == DC_VERDICT_WARN) {
                double least = simulate_stop(tc->exact, measure, &scenario, c->tick, &st);
                t.least_clearance = fmin(t.least_clearance, least);
            }
        }
        rules_after(&rules, c, tcps, n, s, v, &rep);
    }
    name = schedule_names[schedule];
    check(t.mismatches == 0,
          "timing %s %s %s: %lu statuses differ from the rules (first call %ld: %s, expected %s)",
          cell_name, case_name, name, t.mismatches, t.first_mismatch,
          t.mismatches ? dc_status_str(t.mismatch_got) : "",
          t.mismatches ? dc_status_str(t.mismatch_expected) : "");
    check(t.open_faults == 0, "timing %s %s %s: %lu calls failed without STOP", cell_name,
          case_name, name, t.open_faults);
    check(t.repeat_differs == 0,
          "timing %s %s %s: %lu repeated calls answered otherwise than the call they repeat",
          cell_name, case_name, name, t.repeat_differs);
    check(t.not_full == 0 && t.above_full == 0,
          "timing %s %s %s: protective_mm not of full speed on %lu of %lu calls that assume it, "
          "above it on %lu", cell_name, case_name, name, t.not_full, t.full_checked, t.above_full);
    check(st.contacts == 0,
          "timing %s %s %s: %lu of %lu samples of the stops after FREE or WARN touch", cell_name,
          case_name, name, st.contacts, st.samples);
    check(t.least_clearance > 0.0,
          "timing %s %s %s: the stops after FREE or WARN come within %.2f mm", cell_name,
          case_name, name, t.least_clearance);
    check(wanted == DC_STATUS_OK || t.faults[wanted - DC_STATUS_TIME_REPEATED] > 0,
          "timing %s %s %s: no %s", cell_name, case_name, name, dc_status_str(wanted));
    printf("timing %s %-9s %-9s: %lu calls (%lu repeats), FREE %lu WARN %lu STOP %lu, faults "
           "REPEATED %lu BACKWARDS %lu JUMP %lu EARLY %lu CLOCK_CHANGED %lu, other statuses %lu, "
           "statuses not as the rules %lu, full speed after %lu, stops simulated %lu (%lu exact "
           "samples, contacts %lu), least clearance of the stops %.1f mm\n",
           cell_name, case_name, name, t.calls, t.repeats, t.n_verdict[2], t.n_verdict[1],
           t.n_verdict[0], t.faults[0], t.faults[1], t.faults[2], t.faults[3], t.faults[4],
           t.other_status, t.mismatches, t.full_checked, st.stops, st.samples, st.contacts,
           t.least_clearance);
}

/* ------------------------------------------------------------ malformed requests */

/* Requests the timed query refuses, on the cell's first handle: a wrong struct_size, an
 * unknown clock, NULL. */
static void bad_requests(TimingCell *tc)
{
    MrScenario scenario;
    DcProtectiveRequest req = dc_protective_request_default();
    DcVec3 tcps[MR_MAX_ROBOTS];
    DcProtectiveReport rep;
    DcVerdict v;
    DcStatus s;
    if (!load_case(tc, "practical", &scenario)) {
        return;
    }
    dc_protective_reset(tc->h[0]);
    check(req.struct_size == sizeof req && req.clock == DC_CLOCK_CYCLE && req.time == 0
              && req.tcps_mcs == NULL && req.n_tcps == 0 && req.paths == NULL && req.n_paths == 0,
          "timing: dc_protective_request_default");
    tcps_at(&scenario, 0.0, tcps);
    req.tcps_mcs = tcps;
    req.n_tcps = tc->cell.n_robots;
    req.struct_size = sizeof req - 1;
    scribble(&rep, &v);
    s = dc_protective_query_timed(tc->h[0], &req, &v, &rep);
    check(s == DC_STATUS_INVALID_ARGUMENT && v == DC_VERDICT_STOP && rep.verdict == DC_VERDICT_STOP,
          "timing: a struct_size one short: %s, %s", dc_status_str(s), verdict_name(v));
    req.struct_size = sizeof req;
    req.clock = 2;
    scribble(&rep, &v);
    s = dc_protective_query_timed(tc->h[0], &req, &v, &rep);
    check(s == DC_STATUS_INVALID_ARGUMENT && v == DC_VERDICT_STOP && rep.verdict == DC_VERDICT_STOP,
          "timing: clock 2: %s, %s", dc_status_str(s), verdict_name(v));
    scribble(&rep, &v);
    s = dc_protective_query_timed(tc->h[0], NULL, &v, &rep);
    check(s == DC_STATUS_NULL_POINTER && v == DC_VERDICT_STOP && rep.verdict == DC_VERDICT_STOP,
          "timing: a NULL request: %s, %s", dc_status_str(s), verdict_name(v));
    req.clock = DC_CLOCK_NANOS;
    s = dc_protective_query_timed(tc->h[0], &req, &v, NULL);
    check(s == DC_STATUS_OK, "timing: a well-formed request after the refused ones: %s",
          dc_status_str(s));
}

void timing_scenarios(const HarnessOptions *options)
{
    static const char *cells[] = { "T1", "T2", "T3" };
    static const char *cases[] = { "practical", "collision" };
    /* A whole cycle of the practical runs; the cycle of the collision runs in which the
     * robots first collide (about tick 3700). */
    static const long from[] = { 0L, 3000L };
    static const long length = 1500L;
    int quick = options->quick || options->protective_quick;
    unsigned long better = 0, touching = 0;
    TimingCell tc;
    size_t c, k;
    int sc;
    for (c = 0; c < (quick ? 1u : 3u); ++c) {
        if (!open_cell(cells[c], &tc)) {
            continue;
        }
        better += twice_per_cycle(&tc, quick ? QUICK_FROM : 0L,
                                  quick ? QUICK_TICKS : (long)MR_TICKS_PER_RUN, &touching);
        if (c == 0) {
            bad_requests(&tc);
        }
        check(dc_set_speed_limits(tc.h[2], 0) == DC_STATUS_OK, "timing %s: dc_set_speed_limits",
              cells[c]);
        for (k = quick ? 1u : 0u; k < 2; ++k) {
            for (sc = 0; sc < N_SCHEDULES; ++sc) {
                long start = quick ? QUICK_FROM : from[k];
                long end = start + (quick ? QUICK_TICKS : length);
                run_schedule(&tc, cases[k], (Schedule)sc, start, end);
            }
        }
        close_cell(&tc);
    }
    printf("timing: the untimed call twice per tick answered better the second time on %lu ticks "
           "of %s, %lu of them where a stop from the true motion touches\n",
           better, quick ? "T1 (quick)" : "T1-T3", touching);
    /* The hazard the timed query is for: shown on the whole runs (the quick window is too
     * short to be sure of it). */
    check(quick || (better > 0 && touching > 0),
          "timing: the untimed call twice per tick never answered better the second time where "
          "a stop touches (%lu better, %lu touching)", better, touching);
}
