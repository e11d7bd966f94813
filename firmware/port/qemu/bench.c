/* bench.c - instruction counts of the control loop on the Cortex-M4 image (issue 6).
 *
 * Run under qemu-system-arm -M netduinoplus2 -icount shift=7 (tests/firmware/bench.sh):
 * SysTick counts instructions exactly (bench_clock.h: the method, the 1,000-NOP
 * calibration); the image prints raw tick counts, bench.sh converts.
 *
 * The worst case of issue 6: a 40 x 20 m map (0.125 m cells, 0.25 m lattice: 160 x 80
 * points, all legal but a wall round the edge), 10,000 samples all inside the 5 m radius,
 * a relearn (the model is discarded), then a greedy step (epsilon set to 0 so the greedy
 * branch is certain): grid search over every reachable lattice point, step choice with
 * path planning, drive control. Then each phase alone on the same data.
 */
#include <stdint.h>
#include <string.h>

#include "bench_clock.h"
#include "rfs_app.h"
#include "rfs_drive.h"
#include "rfs_plan.h"
#include "rfs_ridge.h"
#include "rfs_rssi.h"
#include "rfs_store.h"
#include "semihost.h"

#define MAP_W 320u
#define MAP_H 160u
#define MAP_STRIDE ((MAP_W + 7u) / 8u)

static rfs_app_t s_app;
static uint8_t s_free[MAP_STRIDE * MAP_H];
static uint8_t s_wall[MAP_STRIDE * MAP_H];
static rfs_rssi_t s_win;

/* 10,000 samples inside 4.9 m of (20, 10); the field rises towards +x (-60 dBm at the
 * robot, +1 dB per metre, +-1 dB noise), so the maximum is at the east wall. */
static void fill_store(rfs_store_t *st, uint64_t seed)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, seed);
    while (st->count < RFS_APP_MAX_SAMPLES) {
        const int32_t dx = (int32_t)rfs_rng_below(&rng, 981u) - 490; /* cm */
        const int32_t dy = (int32_t)rfs_rng_below(&rng, 981u) - 490;
        if (dx * dx + dy * dy > 490 * 490) {
            continue;
        }
        const rfs_sample_t smp = {.x_cm = (int16_t)(2000 + dx), .y_cm = (int16_t)(1000 + dy),
                                  .v_q6 = (int16_t)((-60 * 64) + (dx * 64) / 100 +
                                                    (int32_t)rfs_rng_below(&rng, 128u) - 64)};
        rfs_store_offer(st, smp, &rng);
    }
}

int main(void)
{
    rfs_bc_start(); /* SysTick, and the calibration lines */

    /* The map: free inside, a one-cell wall round the edge. */
    for (uint16_t y = 0; y < MAP_H; y++) {
        for (uint16_t x = 0; x < MAP_W; x++) {
            const bool edge = x == 0u || y == 0u || x == MAP_W - 1u || y == MAP_H - 1u;
            rfs_map_bit_set(edge ? s_wall : s_free, MAP_STRIDE, x, y, true);
        }
    }
    const rfs_app_map_t map = {.w = MAP_W, .h = MAP_H, .res = RFS_Q16_FRAC(1, 8),
                               .origin_x = 0, .origin_y = 0, .free = s_free, .wall = s_wall};
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.seek.eps_amp = 0; /* epsilon = 0: the greedy branch, the expensive one, for certain */
    cfg.seek.eps_floor = 0;
    int rc = -1;
    uintptr_t sp0 = rfs_bc_stack_paint();
    RFS_BC_MEASURE("app_init", 1, rc = rfs_app_init(&s_app, &cfg, &map));
    rfs_bc_report("stack_bytes_app_init", 0, rfs_bc_stack_depth(sp0));
    if (rc != 0) {
        rfs_sh_puts("bench: rfs_app_init failed\n");
        rfs_sh_exit(1);
    }
    rfs_bc_report("lattice_points", 0, (uint32_t)s_app.map.lw * s_app.map.lh);

    /* Boot with an empty store: the reachability flood fill and the initial move only. */
    {
        int64_t tb = 500000;
        const rfs_pose_t pb = {.t_us = tb, .x = RFS_Q16_INT(20), .y = RFS_Q16_INT(10), .theta = 0};
        rfs_app_on_pose(&s_app, &pb, tb);
        rfs_app_on_rssi(&s_app, 0, tb, -60, tb);
        rfs_app_out_t ob;
        RFS_BC_MEASURE("boot_iteration_no_samples", 1, rfs_app_step(&s_app, tb, &ob));
        if (rfs_app_init(&s_app, &cfg, &map) != 0) {
            rfs_sh_exit(1);
        }
    }

    const rfs_q16_t rx = RFS_Q16_INT(20), ry = RFS_Q16_INT(10);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 43u);
    fill_store(&s_app.seek.store, 42u);
    rfs_bc_report("samples", 0, s_app.seek.store.count);

    /* Boot: the first period with a pose and a measurement: reachability flood fill,
     * first fit, the initial move. */
    int64_t t = 1000000;
    const rfs_pose_t pose0 = {.t_us = t, .x = rx, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pose0, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    rfs_app_out_t out;
    sp0 = rfs_bc_stack_paint();
    RFS_BC_MEASURE("first_iteration", 1, rfs_app_step(&s_app, t, &out));
    rfs_bc_report("stack_bytes_first_iteration", 0, rfs_bc_stack_depth(sp0));

    /* The worst case: the goal ended, the model no longer fits (discarded), iteration 1. */
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    t += RFS_APP_PERIOD_US;
    const rfs_pose_t pose1 = {.t_us = t, .x = rx, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pose1, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    sp0 = rfs_bc_stack_paint();
    RFS_BC_MEASURE("worst_iteration", 1, rfs_app_step(&s_app, t, &out));
    rfs_bc_report("stack_bytes_worst_iteration", 0, rfs_bc_stack_depth(sp0));
    rfs_bc_report("worst_decided_greedy_relearned", 0,
                  (uint32_t)(out.decided && out.decision.kind == RFS_SEEK_GREEDY &&
                             out.decision.relearned));
    rfs_bc_report("worst_goal_x_cm", 0, (uint32_t)((out.decision.goal_x * 100) >> 16));
    rfs_bc_report("worst_samples", 0, out.decision.samples);

    /* An ordinary period while driving the goal just chosen. */
    t += RFS_APP_PERIOD_US;
    const rfs_pose_t pose2 = {.t_us = t, .x = rx + 1000, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pose2, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    RFS_BC_MEASURE("driving_iteration", 1, rfs_app_step(&s_app, t, &out));

    /* Phases alone. Averaging: one packet into a full 1 s window (200 packets/s), then
     * the 1 s mean. */
    const rfs_rssi_cfg_t wcfg = rfs_rssi_cfg_default();
    (void)rfs_rssi_init(&s_win, &wcfg);
    for (int i = 0; i < 200; i++) {
        (void)rfs_rssi_push(&s_win, 5000 * i, (int8_t)(-60 - (i & 7)));
    }
    rfs_q16_t mean;
    RFS_BC_MEASURE("phase_averaging_push", 1, (void)rfs_rssi_push(&s_win, 1000000, -61));
    RFS_BC_MEASURE("phase_averaging_mean", 1, (void)rfs_rssi_mean(&s_win, 1000000, &mean));

    /* Sample store: 20 measurements (0.1 s at 200 packets/s) wait for the next pose, which
     * turns them into samples of the full reservoir. */
    rfs_store_t *st = &s_app.seek.store;
    int64_t ts = t + 5000;
    RFS_BC_MEASURE("phase_store_value", 1, rfs_store_add_value(st, ts, RFS_Q16_INT(-60), &rng));
    for (int i = 1; i < 20; i++) {
        rfs_store_add_value(st, ts + 5000 * i, RFS_Q16_INT(-60), &rng);
    }
    const rfs_pose_t pose3 = {.t_us = t + 100000, .x = rx, .y = ry, .theta = 0};
    RFS_BC_MEASURE("phase_store_pose_20", 20, (void)rfs_store_add_pose(st, &pose3, &rng));

    /* Relearn: the local ridge on 10,000 samples, all inside the radius. */
    rfs_ridge_t *ridge = &s_app.ridge;
    const rfs_model_fit_in_t fin = {st->samples, st->count, rx, ry, &s_app.map};
    rfs_ridge_ops.reset(ridge);
    RFS_BC_MEASURE("phase_relearn", 1, (void)rfs_ridge_ops.fit(ridge, &fin, 0, &rng));
    rfs_bc_report("ridge_samples_used", 0, ridge->n_used);

    /* Grid search: the model at every reachable lattice point, as choose_greedy does it
     * (rfs_seek.c: rows in chunks of 64, one predict_row call per chunk when the model
     * has it, else one predict per point). */
    const rfs_map_t *m = &s_app.map;
    rfs_q16_t best = RFS_Q16_MIN, bx = 0, by = 0;
    uint32_t points = 0;
    static rfs_q16_t row[64];
    RFS_BC_MEASURE("phase_grid_search", 1, {
        for (uint16_t j = 0; j < m->lh; ++j) {
            rfs_q16_t x0, py;
            rfs_map_lattice_point(m, 0, j, &x0, &py);
            const uint32_t base = (uint32_t)j * m->lw;
            for (uint16_t i0 = 0; i0 < m->lw; i0 = (uint16_t)(i0 + 64u)) {
                const uint16_t cn = (uint16_t)((uint32_t)(m->lw - i0) < 64u ? (uint32_t)(m->lw - i0) : 64u);
                const rfs_q16_t cx0 = x0 + (rfs_q16_t)i0 * m->cfg.grid;
                if (rfs_ridge_ops.predict_row != 0) {
                    (void)rfs_ridge_ops.predict_row(ridge, cx0, py, m->cfg.grid, cn, row);
                } else {
                    for (uint16_t k = 0; k < cn; ++k) {
                        (void)rfs_ridge_ops.predict(ridge, cx0 + (rfs_q16_t)k * m->cfg.grid, py,
                                                    &row[k]);
                    }
                }
                for (uint16_t k = 0; k < cn; ++k) {
                    const uint32_t idx = base + i0 + k;
                    if (((s_app.reach[idx >> 3] >> (idx & 7u)) & 1u) && row[k] > best) {
                        best = row[k];
                        bx = cx0 + (rfs_q16_t)k * m->cfg.grid;
                        by = py;
                    }
                    points += (s_app.reach[idx >> 3] >> (idx & 7u)) & 1u;
                }
            }
        }
    });
    rfs_bc_report("grid_points_searched", 0, points);
    rfs_bc_report("grid_max_x_cm", 0, (uint32_t)((bx * 100) >> 16));
    (void)by;

    /* A proposal, measured beside the faithful search: for a model that is affine in
     * (x, y) - the local ridge is a plane - the prediction along one lattice row is
     * monotone, so the row's maximum over reachable points is at its leftmost or
     * rightmost reachable point: 2 predictions per row instead of one per point, the
     * same maximum value exactly. */
    rfs_q16_t best2 = RFS_Q16_MIN;
    RFS_BC_MEASURE("proposal_grid_search_row_ends", 1, {
        for (uint16_t j = 0; j < m->lh; ++j) {
            const uint32_t row = (uint32_t)j * m->lw;
            int32_t lo = -1, hi = -1;
            for (uint16_t i = 0; i < m->lw; ++i) {
                const uint32_t idx = row + i;
                if ((s_app.reach[idx >> 3] >> (idx & 7u)) & 1u) {
                    lo = i;
                    break;
                }
            }
            if (lo < 0) {
                continue;
            }
            for (int32_t i = (int32_t)m->lw - 1; i >= lo; --i) {
                const uint32_t idx = row + (uint32_t)i;
                if ((s_app.reach[idx >> 3] >> (idx & 7u)) & 1u) {
                    hi = i;
                    break;
                }
            }
            const int32_t ends[2] = {lo, hi};
            for (int k = 0; k < 2; k++) {
                rfs_q16_t px, py, v;
                rfs_map_lattice_point(m, (uint16_t)ends[k], j, &px, &py);
                if (rfs_ridge_ops.predict(ridge, px, py, &v) && v > best2) {
                    best2 = v;
                }
            }
        }
    });
    rfs_bc_report("proposal_same_max_value", 0, best2 == best ? 1u : 0u);

    /* A proposal: the fit sliced over control periods (cfg.seek.fit_budget samples per
     * period, here 2,500: four periods). */
    rfs_ridge_ops.reset(ridge);
    rfs_fit_result_t fres = RFS_FIT_MORE;
    uint32_t slices = 0;
    while (fres == RFS_FIT_MORE && slices < 100u) {
        RFS_BC_MEASURE("proposal_relearn_slice_2500", 1, fres = rfs_ridge_ops.fit(ridge, &fin, 2500u, &rng));
        slices++;
    }

    /* Step choice: the point 1 m towards the maximum, its legality, the path to it. */
    rfs_path_t path;
    bool ok = false;
    RFS_BC_MEASURE("phase_step_choice", 1, {
        const rfs_q16_t gx = rx + RFS_Q16_ONE;
        ok = rfs_map_point_legal(m, gx, ry) && rfs_plan_path(&s_app.seek.plan, rx, ry, gx, ry, &path);
    });
    rfs_bc_report("step_path_ok", 0, ok ? 1u : 0u);

    /* Drive control: one update following that path. */
    rfs_drive_t *dr = &s_app.seek.drive;
    rfs_drive_set_path(dr, &path, t);
    const rfs_pose_t pose4 = {.t_us = t + 50000, .x = rx, .y = ry, .theta = 0};
    int16_t l, r;
    RFS_BC_MEASURE("phase_drive_control", 1, (void)rfs_drive_update(dr, &pose4, t + 50000, &l, &r));

    /* The CAN side of a period: decode one RSSI frame, encode the two output frames. */
    rfs_can_frame_t fr[2];
    RFS_BC_MEASURE("phase_can_out_frames", 1, (void)rfs_app_frames(&s_app, &out, fr));

    /* Beside the faithful configuration: the same worst case with the fit sliced over
     * control periods (cfg.seek.fit_budget = 2,500 samples per period; the wheels stay
     * stopped while learning). Every period until the decision is measured; the largest
     * is the worst-case period of this configuration. */
    cfg.seek.fit_budget = 2500u;
    if (rfs_app_init(&s_app, &cfg, &map) != 0) {
        rfs_sh_exit(1);
    }
    fill_store(&s_app.seek.store, 42u);
    t = 1000000;
    rfs_app_on_pose(&s_app, &pose0, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    for (int k = 0; k < 20 && !(k > 0 && out.decided); k++) {
        rfs_app_step(&s_app, t, &out); /* boot: flood fill, first (sliced) fit, initial move */
        t += RFS_APP_PERIOD_US;
        const rfs_pose_t pk = {.t_us = t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &pk, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
    }
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    uint64_t worst_slice = 0;
    uint32_t periods = 0;
    out.decided = false;
    while (!out.decided && periods < 20u) {
        t += RFS_APP_PERIOD_US;
        const rfs_pose_t pk = {.t_us = t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &pk, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
        const uint64_t a = rfs_bc_ticks();
        rfs_app_step(&s_app, t, &out);
        const uint64_t b = rfs_bc_ticks();
        rfs_bc_report("sliced_fit_period", b - a, 1);
        if (b - a > worst_slice) {
            worst_slice = b - a;
        }
        periods++;
    }
    rfs_bc_report("sliced_worst_period", worst_slice, 1);
    rfs_bc_report("sliced_decided_greedy_relearned", 0,
                  (uint32_t)(out.decided && out.decision.kind == RFS_SEEK_GREEDY &&
                             out.decision.relearned));
    rfs_bc_report("sliced_goal_x_cm", 0, (uint32_t)((out.decision.goal_x * 100) >> 16));
    rfs_sh_exit(0);
}
