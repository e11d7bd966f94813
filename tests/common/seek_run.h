/* seek_run.h - the harness shared by the seeker's decision tests (test_seek.c,
 * test_seek_meta.c, test_seek_geodesic.c, test_seek_stall.c, test_seek_baseline.c): a
 * synthetic field in double precision, a "teleporting" robot, and a model that knows its
 * maximum.
 *
 * The robot is teleported: when the seeker decides a goal, the harness moves the
 * reported pose onto the goal after a hold time, so the drive reports it reached and the
 * seeker decides again. Measurements come from the double-precision field at the
 * reported position, dithered so that a 1 s mean of int8 dBm carries the field to
 * ~0.01 dB.
 */
#ifndef SEEK_RUN_H
#define SEEK_RUN_H

#include <math.h>

#include "seek_world.h"

#define PI 3.14159265358979323846

/* The synthetic field, dB, in double precision. */
typedef struct field {
    int kind;            /* 0: log-distance from (sx, sy); 1: plane a + bx x + by y; 2: scripted */
    double sx, sy;       /* source, metres */
    double a, bx, by;    /* plane, dB and dB per metre */
    double scripted;     /* kind 2: the value of the current leg, whatever the position */
} field_t;

static inline double field_at(const field_t *f, double x, double y)
{
    if (f->kind == 0) {
        double d = hypot(x - f->sx, y - f->sy);
        return -40.0 - 30.0 * log10(d < 1.0 ? 1.0 : d);
    }
    if (f->kind == 1) {
        return f->a + f->bx * x + f->by * y;
    }
    return f->scripted;
}

/* Simulated time and the teleporting robot. */
typedef struct run {
    int64_t t_us;
    double x, y;           /* reported position, metres */
    bool pending;          /* a goal is waiting to be reached */
    double gx, gy;         /* its position */
    int64_t arrive_us;     /* when the robot appears there */
    uint32_t pkt;          /* packets sent (dither phase) */
} run_t;

/* 10 ms on: the robot appears at a pending goal when due, and one packet arrives from the
 * field, dithered by a golden-ratio sequence so that 100 packets average to it. true when
 * a control period (20 Hz) falls here. */
static inline bool run_tick(world_t *t, run_t *r, const field_t *f)
{
    r->t_us += 10000;
    if (r->pending && r->t_us >= r->arrive_us) {
        r->x = r->gx;
        r->y = r->gy;
        r->pending = false;
    }
    const double u = fmod((double)r->pkt++ * 0.6180339887498949, 1.0);
    rfs_seek_on_rssi(&t->seek, 0, r->t_us, (int8_t)floor(field_at(f, r->x, r->y) + u), &t->rng);
    return r->t_us % 50000 == 0;
}

/* Advance until the next decision (or max_us); packets at 100 Hz, poses and control at
 * 20 Hz; a decided goal is reached hold_us later. Returns false on timeout. */
static inline bool next_decision(world_t *t, run_t *r, const field_t *f, int64_t hold_us,
                                 int64_t max_us, rfs_seek_out_t *out)
{
    int64_t end = r->t_us + max_us;
    while (r->t_us < end) {
        if (run_tick(t, r, f)) {
            rfs_pose_t p = { r->t_us, Q(r->x), Q(r->y), 0 };
            rfs_seek_on_pose(&t->seek, &p, &t->rng);
            rfs_seek_step(&t->seek, r->t_us, &t->rng, out);
            if (out->decided) {
                r->pending = true;
                r->gx = D(out->decision.goal_x);
                r->gy = D(out->decision.goal_y);
                r->arrive_us = r->t_us + hold_us;
                return true;
            }
        }
    }
    return false;
}

/* A model that knows its maximum (like the path-loss model's estimated source): a
 * constant prediction and a fixed argmax. */
typedef struct fixed_model {
    bool valid;
    rfs_q16_t mx, my;
} fixed_model_t;

static inline void fixed_reset(void *self)
{
    ((fixed_model_t *)self)->valid = false;
}

static inline rfs_fit_result_t fixed_fit(void *self, const rfs_model_fit_in_t *in,
                                         uint32_t budget, rfs_rng_t *rng)
{
    (void)in;
    (void)budget;
    (void)rng;
    ((fixed_model_t *)self)->valid = true;
    return RFS_FIT_DONE;
}

static inline bool fixed_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    (void)x;
    (void)y;
    *value = RFS_Q16_INT(-60);
    return ((const fixed_model_t *)self)->valid;
}

static inline bool fixed_argmax(const void *self, rfs_q16_t *x, rfs_q16_t *y)
{
    const fixed_model_t *m = self;
    *x = m->mx;
    *y = m->my;
    return m->valid;
}

/* The fixed model's operations (a function: a static table in a header would be unused
 * in some of the tests). */
static inline const rfs_model_ops_t *fixed_ops(void)
{
    static const rfs_model_ops_t ops = {
        .name = "fixed", .reset = fixed_reset, .fit = fixed_fit, .predict = fixed_predict,
        .argmax = fixed_argmax,
    };
    return &ops;
}

/* The local-search world (test_seek_meta.c, test_seek_stall.c): 20 x 10 m without walls,
 * the meta-path preset with epsilon off, and a fixed model whose estimate is
 * (LOCAL_EX, LOCAL_EY). */
#define LOCAL_EX 10.3
#define LOCAL_EY 5.2

static inline void local_world(world_t *t, rfs_seek_cfg_t *cfg, fixed_model_t *fm)
{
    world_make(t, 20.0, 10.0, 0.0, 0.0);
    *cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(cfg, RFS_SEEK_META_PATH);
    cfg->eps_amp = 0;
    cfg->eps_floor = 0;
    seek_make(t, *cfg, 5);
    *fm = (fixed_model_t){ false, Q(LOCAL_EX), Q(LOCAL_EY) };
}

#endif /* SEEK_RUN_H */
