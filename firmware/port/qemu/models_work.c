/* models_work.c - the model bench's workload and run (see models_work.h). */
#include "models_work.h"

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "bench_clock.h"
#include "rfs_app.h"
#include "rfs_gridmax.h"
#include "rfs_models.h"
#include "rfs_seek.h"
#include "rfs_target.h"

/* The maps, baked by scripts/map2c.py (mk/firmware_m4.mk): the firmware's 40 x 20 m box
 * at 0.125 m and scenarios/maps/office.yaml at the core's 0.1 m. */
extern const rfs_app_map_t rfs_mw_box_map;
extern const rfs_app_map_t rfs_mw_office_map;

/* Comparison budgets measured beside each model's registry budget (mcu_fit_budget, the
 * firmware's MCU configuration; not in the check run): the single budget every model had
 * before the per-model ones (2,500; the ridge's until its whole fit, 0), the MLP's
 * earlier budget (10 sample-updates: its heaviest slice near 0.5 M instructions) and
 * 300 wall counts for the pathloss model (a slice of about 50 ms). */
typedef struct mw_cmp {
    const char *model;
    uint32_t budget;
} mw_cmp_t;

static const mw_cmp_t k_cmp[] = {
    {"mlp", 10u}, {"mlp", 2500u}, {"pathloss", 300u}, {"pathloss", 2500u},
};

/* Prediction points of the cross-check sums: 11 x 6 over the field (every 4 m), 8 x 3
 * over the office floor (every 5 m and 4.5 m). */
#define FIELD_NX 11
#define FIELD_NY 6
#define FLOOR_NX 8
#define FLOOR_NY 3

/* --- small helpers (the image has no stdio) ------------------------------------------ */

/* "<a>_<b>" into buf (cap bytes), truncated. */
static const char *name2(char *buf, uint32_t cap, const char *a, const char *b)
{
    uint32_t k = 0;
    for (const char *p = a; *p != '\0' && k + 1u < cap; ++p) {
        buf[k++] = *p;
    }
    if (k + 1u < cap) {
        buf[k++] = '_';
    }
    for (const char *p = b; *p != '\0' && k + 1u < cap; ++p) {
        buf[k++] = *p;
    }
    buf[k] = '\0';
    return buf;
}

/* "<a>_<b>_<decimal v>". */
static const char *name3(char *buf, uint32_t cap, const char *a, const char *b, uint32_t v)
{
    char num[12];
    int i = 11;
    num[i] = '\0';
    do {
        num[--i] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    char ab[48];
    return name2(buf, cap, name2(ab, sizeof ab, a, b), &num[i]);
}

static void error(const char *why)
{
    rfs_bc_report(why, 0, 0);
}

/* FNV-1a, 32 bits, over little-endian bytes: the same on both ends of the cross-check. */
#define FNV_OFFSET 2166136261u
#define FNV_PRIME 16777619u

static uint32_t fnv_u32(uint32_t h, uint32_t v)
{
    for (int k = 0; k < 4; ++k) {
        h = (h ^ ((v >> (8 * k)) & 0xFFu)) * FNV_PRIME;
    }
    return h;
}

static uint32_t sum_samples(const rfs_sample_t *s, uint32_t n)
{
    uint32_t h = FNV_OFFSET;
    for (uint32_t i = 0; i < n; ++i) {
        h = fnv_u32(h, (uint32_t)(uint16_t)s[i].x_cm | ((uint32_t)(uint16_t)s[i].y_cm << 16));
        h = fnv_u32(h, (uint32_t)(uint16_t)s[i].v_q6);
    }
    return h;
}

/* --- the workloads ------------------------------------------------------------------ */

static double gauss(rfs_rng_t *r)
{
    double u1 = ((double)rfs_rng_u32(r) + 1.0) / 4294967297.0;
    double u2 = (double)rfs_rng_u32(r) / 4294967296.0;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* bench/bench_models.c make_samples(), the same expressions in the same order. */
static void field_samples(rfs_sample_t *s, uint32_t n)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    for (uint32_t i = 0; i < n; ++i) {
        s[i].x_cm = (int16_t)rfs_rng_below(&r, 4001);
        s[i].y_cm = (int16_t)rfs_rng_below(&r, 2001);
        double z = gauss(&r);
        double d = hypot(s[i].x_cm / 100.0 - 30.0, s[i].y_cm / 100.0 - 12.0);
        s[i].v_q6 = (int16_t)lround((-30.0 - 20.0 * log10(d + 1.0) + 4.0 * z) * 64.0);
    }
}

/* bench/bench_pathloss.c, "whole floor": legal points uniform over the map, the source at
 * (27.5, 10) m; r goes on to the fit, as there. */
static void floor_samples(rfs_sample_t *s, uint32_t n, const rfs_map_t *m, rfs_rng_t *r)
{
    const double sx = 27.5, sy = 10.0;
    const rfs_q16_t qsx = (rfs_q16_t)lround(sx * 65536.0), qsy = (rfs_q16_t)lround(sy * 65536.0);
    const double w_m = m->w * (m->res / 65536.0), h_m = m->h * (m->res / 65536.0);
    for (uint32_t i = 0; i < n;) {
        double x = m->origin_x / 65536.0 + w_m * (rfs_rng_u32(r) / 4294967296.0);
        double y = m->origin_y / 65536.0 + h_m * (rfs_rng_u32(r) / 4294967296.0);
        rfs_q16_t qx = (rfs_q16_t)lround(x * 65536.0), qy = (rfs_q16_t)lround(y * 65536.0);
        if (!rfs_map_point_legal(m, qx, qy)) {
            continue;
        }
        double d = hypot(x - sx, y - sy);
        int k = rfs_map_walls_crossed(m, qx, qy, qsx, qsy);
        double v = -40.0 - 30.0 * log10(d < 1.0 ? 1.0 : d) - 5.0 * k + 4.0 * gauss(r);
        s[i].x_cm = (int16_t)lround(x * 100.0);
        s[i].y_cm = (int16_t)lround(y * 100.0);
        s[i].v_q6 = (int16_t)lround(v * 64.0);
        ++i;
    }
}

/* Wall counts as the pathloss fit makes them on the floor (over the map's wall-block grid,
 * RFS_PATHLOSS_WALL_BLOCK_BYTES, as on the Cortex-M4): from the first (up to) 1,000
 * samples' points to 7 x 3 points every 5 m and 4.5 m from (2.5, 1.5) m; the counts' sum is
 * a cross-check line. */
#define WALLS_PTS 1000u
#define WALLS_NX 7
#define WALLS_NY 3
static void walls_bench(const rfs_map_t *m, const rfs_sample_t *s, uint32_t n)
{
    static uint8_t bits[RFS_PATHLOSS_WALL_BLOCK_BYTES];
    rfs_map_wall_blocks_t b;
    n = n < WALLS_PTS ? n : WALLS_PTS;
    if (rfs_map_wall_blocks(m, bits, sizeof bits, &b) != 0) {
        error("error_walls");
        return;
    }
    uint32_t sum = 0u;
    RFS_BC_MEASURE("walls_pathloss", n * WALLS_NX * WALLS_NY,
        for (uint32_t i = 0; i < n; ++i) {
            const rfs_q16_t x = (rfs_q16_t)s[i].x_cm * 65536 / 100;
            const rfs_q16_t y = (rfs_q16_t)s[i].y_cm * 65536 / 100;
            for (int32_t gy = 0; gy < WALLS_NY; ++gy) {
                for (int32_t gx = 0; gx < WALLS_NX; ++gx) {
                    sum += rfs_map_walls_crossed_blocks(m, &b, x, y,
                                                          RFS_Q16_INT(5 * gx) + RFS_Q16_FRAC(5, 2),
                                                          RFS_Q16_FRAC(9 * gy + 3, 2));
                }
            }
        });
    rfs_bc_report("sum_walls_pathloss", 0, sum);
}

static int map_init(rfs_mw_mem_t *mem, const rfs_app_map_t *am)
{
    const rfs_map_cfg_t mc = rfs_map_cfg_default();
    if (rfs_map_bytes(am->w, am->h) > sizeof mem->legal ||
        rfs_map_init(&mem->map, &mc, am->w, am->h, am->res, am->origin_x, am->origin_y,
                     am->free, am->wall, mem->legal) != 0 ||
        (uint32_t)mem->map.lw * mem->map.lh > RFS_MW_MAX_LATTICE) {
        return -1;
    }
    return 0;
}

/* The seeker around the model, for rfs_gridmax_find(): the paper's configuration; every
 * legal lattice point reachable. Returns the number of reachable points, 0 on failure. */
static uint32_t seek_init(rfs_mw_mem_t *mem, rfs_model_t model)
{
    const rfs_map_t *m = &mem->map;
    const rfs_seek_cfg_t sc = rfs_seek_cfg_default();
    const rfs_seek_mem_t sm = {
        .samples = mem->samples, .pending = mem->pending, .pending_cap = RFS_MW_PENDING,
        .plan_work = mem->plan_work, .plan_work_bytes = sizeof mem->plan_work,
        .plan_queue = mem->plan_queue, .plan_queue_cap = 8u,
        .visited = mem->visited, .visited_bytes = sizeof mem->visited,
        .reach = mem->reach, .reach_bytes = sizeof mem->reach,
    };
    if (sc.store.capacity > RFS_MW_MAX_SAMPLES ||
        rfs_seek_init(&mem->seek, &sc, m, model, &rfs_target_rssi, &sm) != 0) {
        return 0u;
    }
    uint32_t points = 0;
    for (uint16_t j = 0; j < m->lh; ++j) {
        for (uint16_t i = 0; i < m->lw; ++i) {
            if (rfs_map_lattice_legal(m, i, j)) {
                const uint32_t idx = (uint32_t)j * m->lw + i;
                mem->reach[idx >> 3] = (uint8_t)(mem->reach[idx >> 3] | (1u << (idx & 7u)));
                points++;
            }
        }
    }
    return points;
}

/* FNV-1a of the predictions at the check points (value and whether there was one). */
static uint32_t sum_predictions(const rfs_models_entry_t *e, const void *st, bool floor)
{
    uint32_t h = FNV_OFFSET;
    const int nx = floor ? FLOOR_NX : FIELD_NX, ny = floor ? FLOOR_NY : FIELD_NY;
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            /* field: (0.125 + 4 i, 0.125 + 4 j) m; floor: (1 + 5 i, 1.5 + 4.5 j) m */
            const rfs_q16_t x = floor ? RFS_Q16_INT(1 + 5 * i) : RFS_Q16_INT(4 * i) + 8192;
            const rfs_q16_t y = floor ? RFS_Q16_INT(1) + 32768 + j * RFS_Q16_INT(9) / 2
                                      : RFS_Q16_INT(4 * j) + 8192;
            rfs_q16_t v = 0;
            const bool ok = e->ops->predict(st, x, y, &v);
            h = fnv_u32(h, ok ? 1u : 0u);
            h = fnv_u32(h, ok ? (uint32_t)v : 0u);
        }
    }
    return h;
}

/* One sliced fit from a fresh state (init, not reset: the pathloss model keeps its
 * wall-count cache across a reset, and the figure is the cold relearn's): every call
 * timed, the heaviest, the total and the number of calls reported; the sum of the
 * predictions after it. */
static void sliced(const rfs_models_entry_t *e, void *st, const rfs_model_fit_in_t *in,
                   uint32_t budget, const rfs_rng_t *rng0, bool floor)
{
    char nb[64];
    rfs_rng_t rng = *rng0;
    (void)e->init_default(st);
    rfs_fit_result_t r = RFS_FIT_MORE;
    uint64_t worst = 0, total = 0, last = 0;
    uint32_t calls = 0;
    while (r == RFS_FIT_MORE && calls < 1000000u) {
        const uint64_t t0 = rfs_bc_ticks();
        r = e->ops->fit(st, in, budget, &rng);
        const uint64_t t1 = rfs_bc_ticks();
        last = t1 - t0;
        worst = last > worst ? last : worst;
        total += last;
        calls++;
    }
    rfs_bc_report(name3(nb, sizeof nb, "slice_worst", e->name, budget), worst, 1);
    /* The seeker decides in the period of the last slice (rfs_seek.c decide()): that
     * period also runs the grid search or argmax. */
    rfs_bc_report(name3(nb, sizeof nb, "slice_last", e->name, budget), last, 1);
    rfs_bc_report(name3(nb, sizeof nb, "slice_total", e->name, budget), total, calls);
    rfs_bc_report(name3(nb, sizeof nb, "slices", e->name, budget), 0, calls);
    rfs_bc_report(name3(nb, sizeof nb, "sum_sliced", e->name, budget), 0,
                  r == RFS_FIT_DONE ? sum_predictions(e, st, floor) : 0u);
}

/* Warming (rfs_model_ops_t.warm) at the seeker's slice of the registry budget
 * (RFS_SEEK_WARM_SLICE): a finished fit on the first tenth of the samples, then warming
 * for all of them (the robot at in's query point) until it has nothing left, every call
 * timed; then the relearn, whose predictions' sum the host twin must print too. */
static void warmed(const rfs_models_entry_t *e, void *st, const rfs_model_fit_in_t *in,
                   const rfs_rng_t *rng0, bool floor)
{
    char nb[64];
    const uint32_t budget = RFS_SEEK_WARM_SLICE(e->mcu_fit_budget);
    rfs_rng_t rng = *rng0;
    rfs_model_fit_in_t part = *in;
    part.n = (uint16_t)(in->n / 10u > 0u ? in->n / 10u : 1u);
    (void)e->init_default(st);
    if (e->ops->fit(st, &part, 0u, &rng) != RFS_FIT_DONE) {
        error("error_warm_fit");
        return;
    }
    uint64_t worst = 0, total = 0;
    uint32_t calls = 0;
    bool more = true;
    while (more && calls < 1000000u) {
        const uint64_t t0 = rfs_bc_ticks();
        more = e->ops->warm(st, in, budget);
        const uint64_t t1 = rfs_bc_ticks();
        worst = t1 - t0 > worst ? t1 - t0 : worst;
        total += t1 - t0;
        calls++;
    }
    rfs_bc_report(name3(nb, sizeof nb, "warm_worst", e->name, budget), worst, 1);
    rfs_bc_report(name3(nb, sizeof nb, "warm_total", e->name, budget), total, calls);
    rfs_fit_result_t r = e->ops->fit(st, in, 0u, &rng);
    rfs_bc_report(name2(nb, sizeof nb, "sum_warmed", e->name), 0,
                  r == RFS_FIT_DONE ? sum_predictions(e, st, floor) : 0u);
}

/* The 160 x 80 predictions of bench/bench_models.c's grid mode (no map, no reachability):
 * the figure to set beside the host's callgrind count. */
static void predict_loop(const rfs_models_entry_t *e, const void *st)
{
    char nb[64];
    rfs_q16_t best = RFS_Q16_MIN;
    RFS_BC_MEASURE(name2(nb, sizeof nb, "predict12800", e->name), 12800u, {
        for (int j = 0; j < 80; ++j) {
            for (int i = 0; i < 160; ++i) {
                rfs_q16_t v;
                if (e->ops->predict(st, i * 16384 + 8192, j * 16384 + 8192, &v) && v > best) {
                    best = v;
                }
            }
        }
    });
    rfs_bc_report(name2(nb, sizeof nb, "sum_predict12800", e->name), 0,
                  fnv_u32(FNV_OFFSET, (uint32_t)best));
}

static int run_model(rfs_mw_mem_t *mem, const rfs_models_entry_t *e, uint32_t n, uint32_t flags)
{
    char nb[64];
    void *st = &mem->state;
    const bool floor = e->ops == &rfs_pathloss_ops;
    rfs_bc_report(name2(nb, sizeof nb, "state_bytes", e->name), 0, e->state_bytes);
    if (e->state_bytes > sizeof mem->state || e->init_default(st) != 0 ||
        map_init(mem, floor ? &rfs_mw_office_map : &rfs_mw_box_map) != 0) {
        error("error_setup");
        return -1;
    }
    rfs_rng_t rng;
    rfs_rng_seed(&rng, floor ? 7u : 42u);
    if (floor) {
        floor_samples(mem->samples, n, &mem->map, &rng);
    } else {
        field_samples(mem->samples, n);
    }
    rfs_bc_report(name2(nb, sizeof nb, "sum_samples", e->name), 0, sum_samples(mem->samples, n));
    if (floor) {
        walls_bench(&mem->map, mem->samples, n);
    }
    const rfs_model_fit_in_t in = {
        .samples = mem->samples, .n = (uint16_t)n,
        .qx = floor ? 0 : RFS_Q16_INT(20), .qy = floor ? 0 : RFS_Q16_INT(10),
        .map = floor ? &mem->map : NULL,
    };
    /* The sliced runs restart from the rng state the whole fit started with, so they
     * learn the same model. */
    const rfs_rng_t rng0 = rng;

    /* A full relearn (budget 0), and its stack. */
    rfs_fit_result_t r = RFS_FIT_FAILED;
    const uintptr_t sp = rfs_bc_stack_paint();
    RFS_BC_MEASURE(name2(nb, sizeof nb, "relearn", e->name), 1, r = e->ops->fit(st, &in, 0u, &rng));
    rfs_bc_report(name2(nb, sizeof nb, "stack_relearn", e->name), 0, rfs_bc_stack_depth(sp));
    if (r != RFS_FIT_DONE) {
        error("error_fit");
        return -1;
    }
    rfs_bc_report(name2(nb, sizeof nb, "sum_whole", e->name), 0, sum_predictions(e, st, floor));

    /* One prediction: bench_pathloss's point (8, 6) m on the floor, (20.125, 10.125) m on
     * the field. */
    rfs_q16_t v = 0;
    const rfs_q16_t px = floor ? RFS_Q16_INT(8) : RFS_Q16_INT(20) + 8192;
    const rfs_q16_t py = floor ? RFS_Q16_INT(6) : RFS_Q16_INT(10) + 8192;
    RFS_BC_MEASURE(name2(nb, sizeof nb, "predict", e->name), 1, (void)e->ops->predict(st, px, py, &v));

    /* The grid search as the seeker runs it; for a model that knows its maximum
     * (argmax: pathloss) choose_greedy asks that instead, measured too. */
    const rfs_model_t model = {e->ops, st};
    const uint32_t points = seek_init(mem, model);
    if (points == 0u) {
        error("error_seek_init");
        return -1;
    }
    rfs_bc_report(name2(nb, sizeof nb, "points", e->name), 0, points);
    rfs_q16_t gx = 0, gy = 0;
    bool found = false;
    if (e->ops->argmax != 0) {
        RFS_BC_MEASURE(name2(nb, sizeof nb, "argmax", e->name), 1,
                       found = e->ops->argmax(st, &gx, &gy));
        rfs_bc_report(name2(nb, sizeof nb, "sum_argmax", e->name), 0,
                      fnv_u32(fnv_u32(fnv_u32(FNV_OFFSET, found), (uint32_t)gx), (uint32_t)gy));
    }
    if (!floor || (flags & RFS_MW_QUICK) == 0u) {
        const uintptr_t sp2 = rfs_bc_stack_paint();
        RFS_BC_MEASURE(name2(nb, sizeof nb, "grid", e->name), 1,
                       found = rfs_gridmax_find(&mem->map, &mem->seek.model, mem->reach,
                                                 &gx, &gy));
        rfs_bc_report(name2(nb, sizeof nb, "stack_grid", e->name), 0, rfs_bc_stack_depth(sp2));
        rfs_bc_report(name2(nb, sizeof nb, "sum_grid", e->name), 0,
                      fnv_u32(fnv_u32(fnv_u32(FNV_OFFSET, found), (uint32_t)gx), (uint32_t)gy));
    }
    if (!floor && (flags & RFS_MW_QUICK) == 0u) {
        predict_loop(e, st);
    }

    /* Sliced at the registry budget (the firmware's), then the comparison budgets, then
     * the port's extra ones. */
    rfs_bc_report(name2(nb, sizeof nb, "mcu_budget", e->name), 0, e->mcu_fit_budget);
    sliced(e, st, &in, e->mcu_fit_budget, &rng0, floor);
    if (e->ops->warm != 0 && e->mcu_fit_budget != 0u) {
        warmed(e, st, &in, &rng0, floor);
    }
    for (uint32_t k = 0; (flags & RFS_MW_QUICK) == 0u && k < sizeof k_cmp / sizeof k_cmp[0]; ++k) {
        const char *a = k_cmp[k].model, *b = e->name;
        while (*a != '\0' && *a == *b) {
            ++a;
            ++b;
        }
        if (*a == '\0' && *b == '\0' && k_cmp[k].budget != e->mcu_fit_budget) {
            sliced(e, st, &in, k_cmp[k].budget, &rng0, floor);
        }
    }
    for (uint32_t k = 0; k < mem->n_extra && k < RFS_MW_MAX_EXTRA; ++k) {
        if (mem->extra[k].model == e && mem->extra[k].budget != 0u) {
            sliced(e, st, &in, mem->extra[k].budget, &rng0, floor);
        }
    }
    return 0;
}

int rfs_mw_run(rfs_mw_mem_t *mem, uint32_t n, uint32_t flags)
{
    if (n < 1u || n > RFS_MW_MAX_SAMPLES) {
        error("error_n");
        return -1;
    }
    if (rfs_models_max_state_bytes() > sizeof mem->state) {
        error("error_state_union");
        return -1;
    }
    rfs_bc_report("samples", 0, n);
    rfs_bc_report("state_bytes_max", 0, rfs_models_max_state_bytes());
    for (uint32_t i = 0; i < rfs_models_count(); ++i) {
        if (run_model(mem, rfs_models_at(i), n, flags) != 0) {
            return -1;
        }
    }
    return 0;
}
