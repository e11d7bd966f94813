/* bench.c - instruction counts of the control loop on the Cortex-M4 image (docs/FIRMWARE.md,
 * "Bench").
 *
 * Run under qemu-system-arm -M netduinoplus2 -icount shift=7 (tests/firmware/bench.sh):
 * SysTick counts instructions exactly (bench_clock.h: the method, the 1,000-NOP
 * calibration); the image prints raw tick counts, bench.sh converts.
 *
 * The worst case: a 40 x 20 m map (0.125 m cells, 0.25 m lattice: 160 x 80
 * points, all legal but a wall round the edge), 10,000 samples all inside the 5 m radius,
 * a relearn (the model is discarded), then a greedy step (epsilon set to 0 so the greedy
 * branch is certain): grid search over every reachable lattice point, step choice with
 * path planning, drive control. Then each phase alone on the same data. Last, an epsilon
 * decision that must plan round a wall: meta-path's geodesic draw (up to six plans), the
 * same without it, and the paper's, on the same map with one interior wall (geo_decision).
 * Then the paper's greedy decision next to that wall, whose line search plans every legal
 * candidate until one plans (ls_decision), and the same beside a closed room.
 *
 * Each step of main is a function of its own, kept out of line: a count includes the few
 * instructions the compiler schedules around the measured call, so the code of one step
 * does not move the counts of another.
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
/* The application's sample store, port-owned (rfs_app_cfg_t.samples; in RAM here: no CCM). */
static rfs_sample_t s_samples[RFS_APP_MAX_SAMPLES];
static rfs_rssi_t s_win;

/* A row name: base followed by suffix, kept for the rest of the run (a bump pool). */
static const char *row_name(const char *base, const char *suffix)
{
    static char pool[6144];
    static uint32_t used;
    char *out = &pool[used];
    for (const char *s = base; *s != '\0' && used + 2u < sizeof pool; s++) {
        pool[used++] = *s;
    }
    for (const char *s = suffix; *s != '\0' && used + 2u < sizeof pool; s++) {
        pool[used++] = *s;
    }
    pool[used++] = '\0';
    return out;
}

/* 10,000 samples inside 4.9 m of (cx, cy) cm, keeping only those with x >= xmin and
 * y <= ymax (cm: the side of a wall the robot was on); the field rises towards +x (-60 dBm
 * at the centre, +1 dB per metre, +-1 dB noise). The limits reject before the noise draw,
 * so limits that reject nothing give the same samples as no limits. */
static void fill_store_at(rfs_store_t *st, uint64_t seed, int32_t cx, int32_t cy, int32_t xmin,
                          int32_t ymax)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, seed);
    while (st->count < RFS_APP_MAX_SAMPLES) {
        const int32_t dx = (int32_t)rfs_rng_below(&rng, 981u) - 490; /* cm */
        const int32_t dy = (int32_t)rfs_rng_below(&rng, 981u) - 490;
        if (dx * dx + dy * dy > 490 * 490 || cx + dx < xmin || cy + dy > ymax) {
            continue;
        }
        const rfs_sample_t smp = {.x_cm = (int16_t)(cx + dx), .y_cm = (int16_t)(cy + dy),
                                  .v_q6 = (int16_t)((-60 * 64) + (dx * 64) / 100 +
                                                    (int32_t)rfs_rng_below(&rng, 128u) - 64)};
        rfs_store_offer(st, smp, &rng);
    }
}

/* The worst case's store: around (20, 10), so the maximum is at the east wall. */
static void fill_store(rfs_store_t *st, uint64_t seed)
{
    fill_store_at(st, seed, 2000, 1000, INT32_MIN, INT32_MAX);
}

/* The meta-path epsilon decision (RFS_SEEK_META_PATH's eps_geodesic; rfs_seek_meta.c
 * choose_epsilon and accept_detour): a goal is proposed with weight e^(-straight
 * distance), planned, and kept with probability e^(-(path length - straight distance));
 * up to GOAL_TRIES = 6 draws, the sixth kept whatever its detour, so one decision plans
 * up to six paths. Its worst case on the bench's 40 x 20 m map: an interior wall along
 * y = 10 m from the west wall to x = 36 m, the way round it a 4 m gap at the east end;
 * the robot at (1.125, 8.625) m just south of it, its side explored within the 8 m
 * epsilon radius (visited bits), so every candidate lies north of the wall, at most 8 m
 * away in a straight line and at least 35 + 27 = 62 m away by the gap: every detour
 * exceeds 13 m, where e^(-detour) is 0 in Q16 (rfs_q16_exp_neg), draws 1 to 5 are
 * rejected and the sixth is kept. The six plans share one search tree rooted at the
 * robot (rfs_plan_tree_path): its Dijkstra round the wall over nearly the whole lattice
 * is resumed for each goal, and each path is pulled only from where it leaves the
 * previous one. */
#define GEO_WALL_ROW 79u   /* cells: the wall is rows 79 and 80, y 9.875 .. 10.125 m */
#define GEO_WALL_END 288u  /* cells: it ends at x = 36 m */
#define GEO_RI 4u          /* the robot's lattice point: x = 0.125 + 4 x 0.25 m */
#define GEO_RJ 34u         /* y = 0.125 + 34 x 0.25 = 8.625 m */
#define GEO_SOUTH_J 39u    /* last lattice row south of the wall (y 9.875 m) */
#define GEO_TRIES 6        /* GOAL_TRIES of rfs_seek_meta.c */

static void geo_wall(void)
{
    for (uint16_t y = GEO_WALL_ROW; y <= GEO_WALL_ROW + 1u; y++) {
        for (uint16_t x = 0; x < GEO_WALL_END; x++) {
            rfs_map_bit_set(s_wall, MAP_STRIDE, x, y, true);
            rfs_map_bit_set(s_free, MAP_STRIDE, x, y, false);
        }
    }
}

/* The robot's history: every lattice point south of the wall within the epsilon radius
 * of it has been visited. */
static void geo_history(rfs_seek_t *s)
{
    const uint32_t lw = s->map->lw;
    for (uint32_t j = 0; j <= GEO_SOUTH_J; j++) {
        if (j + RFS_SEEK_EPS_RADIUS < GEO_RJ) {
            continue;
        }
        for (uint32_t i = 0; i <= GEO_RI + RFS_SEEK_EPS_RADIUS && i < lw; i++) {
            const uint32_t idx = j * lw + i;
            s->visited[idx >> 3] = (uint8_t)(s->visited[idx >> 3] | (1u << (idx & 7u)));
        }
    }
}

/* choose_epsilon's weighted scan: the candidates around (ci, cj) in its order (rows, then
 * columns), neither visited nor unreachable, weight eps_w[di^2 + dj^2]. Returns the sum
 * of the weights up to the first point where it exceeds pick (that point in *oi, *oj, *oq
 * and *found), or the total when none does (pick UINT32_MAX: the total).
 * Scaling: weights Q0.16 <= 65535, at most 65^2 candidates: the sum stays below 2^28. */
static uint32_t geo_scan(const rfs_seek_t *s, uint16_t ci, uint16_t cj, uint32_t pick,
                         uint16_t *oi, uint16_t *oj, uint32_t *oq, bool *found)
{
    const rfs_map_t *m = s->map;
    const int32_t r = RFS_SEEK_EPS_RADIUS;
    uint32_t acc = 0;
    *found = false;
    for (int32_t dj = -r; dj <= r; ++dj) {
        const int32_t j = (int32_t)cj + dj;
        if (j < 0 || j >= (int32_t)m->lh) {
            continue;
        }
        for (int32_t di = -r; di <= r; ++di) {
            const int32_t i = (int32_t)ci + di;
            const uint32_t q = (uint32_t)(di * di + dj * dj);
            if (i < 0 || i >= (int32_t)m->lw || q >= RFS_SEEK_EPS_TABLE) {
                continue;
            }
            const uint32_t idx = (uint32_t)j * m->lw + (uint32_t)i;
            if (((s->visited[idx >> 3] >> (idx & 7u)) & 1u) ||
                !((s->reach[idx >> 3] >> (idx & 7u)) & 1u)) {
                continue;
            }
            acc += s->eps_w[q];
            if (acc > pick) {
                *oi = (uint16_t)i;
                *oj = (uint16_t)j;
                *oq = q;
                *found = true;
                return acc;
            }
        }
    }
    return acc;
}

/* An independent count of the plans of that decision: its draws replayed from a copy of
 * the random source taken just before the step, on the step's own visited, reach and
 * weight tables (a draw changes them only when a plan fails, and then the replayed goal
 * differs): the epsilon coin (finish_decision), then per try one weighted pick, one plan
 * and, geodesic and not the last try, one detour test on the lattice path's length
 * (rfs_plan_tree_length on a search tree from the robot, searched on demand: the same
 * paths as the decision's grown tree). Returns the plans; the kept goal
 * in *gx, *gy; the smallest detour of a tested draw in *min_detour (metres Q16.16,
 * INT64_MAX when none was tested). Scaling: the straight distance grid * sqrt(q) as
 * rfs_seek_meta.c's offset_dist (Q16 x Q16 >> 16); path lengths <= 32 km, so the detour fits
 * int32 for rfs_q16_exp_neg. */
static uint32_t geo_replay(rfs_seek_t *s, rfs_rng_t rng, bool geodesic, rfs_q16_t *gx,
                           rfs_q16_t *gy, int64_t *min_detour)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj, gi = 0, gj = 0;
    uint32_t q = 0, plans = 0;
    bool found;
    rfs_map_lattice_nearest(m, s->pose.x, s->pose.y, &ci, &cj);
    *min_detour = INT64_MAX;
    *gx = 0; /* no goal when no candidate is left */
    *gy = 0;
    (void)rfs_rng_u32(&rng);
    rfs_plan_tree_begin(&s->plan, s->pose.x, s->pose.y); /* the decision's tree, searched on demand */
    for (int attempt = 0; attempt < GEO_TRIES; ++attempt) {
        const uint32_t total = geo_scan(s, ci, cj, UINT32_MAX, &gi, &gj, &q, &found);
        if (total == 0u) {
            return plans;
        }
        (void)geo_scan(s, ci, cj, rfs_rng_below(&rng, total), &gi, &gj, &q, &found);
        rfs_map_lattice_point(m, gi, gj, gx, gy);
        rfs_q16_t len;
        plans++;
        if (!geodesic || attempt == GEO_TRIES - 1 ||
            !rfs_plan_tree_length(&s->plan, *gx, *gy, &len)) {
            return plans;
        }
        const int64_t straight = ((int64_t)m->cfg.grid * rfs_isqrt64((uint64_t)q << 32)) >> 16;
        const int64_t detour = (int64_t)len - straight;
        if (detour <= 0) {
            return plans;
        }
        *min_detour = detour < *min_detour ? detour : *min_detour;
        if (rfs_rng_below(&rng, RFS_Q16_ONE) < (uint32_t)rfs_q16_exp_neg(rfs_sat32(detour))) {
            return plans;
        }
    }
    return plans;
}

/* The planner's search tree for the next decision grown while the last leg was driven
 * (rfs_seek.c, plan_budget): begun where the leg ends, here the robot's pose, and grown by
 * RFS_SEEK_DRIVE_SLICE(plan_budget) points a period as drive_on does, each slice measured; the worst as
 * `base`_slice, the number as `base`_slices. */
static void grow_on_leg(const char *base, rfs_q16_t rx, rfs_q16_t ry)
{
    rfs_plan_t *p = &s_app.seek.plan;
    rfs_plan_tree_begin(p, rx, ry);
    uint64_t worst = 0;
    uint32_t slices = 0;
    bool done = false;
    while (!done && slices < 1000u) {
        /* Start just after a SysTick wrap: a slice (under 2^24 ticks) then contains none,
         * and its count stays exact (tests/firmware/bench.sh). */
        while ((rfs_bc_ticks() & 0xFFFFFFu) > 0x1000u) {
        }
        const uint64_t a = rfs_bc_ticks();
        done = rfs_plan_tree_grow(p, RFS_SEEK_DRIVE_SLICE(s_app.seek.cfg.plan_budget));
        const uint64_t d = rfs_bc_ticks() - a;
        worst = d > worst ? d : worst;
        slices++;
    }
    rfs_bc_report(row_name(base, "_slice"), worst, 1);
    rfs_bc_report(row_name(base, "_slices"), 0, slices);
}

/* Periods with the robot standing at (rx, ry), a pose and a measurement each, *t
 * advanced by one period before each, until one decides (at most 100), each measured:
 * `base` the worst, `base`_first the first, `base`_periods how many (1: the first
 * decided), `base`_stack the deepest stack. *rng0: the random source just before the
 * period that decided (for the replays). */
static void run_until_decided(const char *base, rfs_q16_t rx, rfs_q16_t ry, int64_t *t,
                              rfs_app_out_t *out, rfs_rng_t *rng0)
{
    uint64_t worst = 0;
    uint32_t periods = 0;
    const uintptr_t sp0 = rfs_bc_stack_paint();
    out->decided = false;
    while (!out->decided && periods < 100u) {
        *t += RFS_APP_PERIOD_US;
        const rfs_pose_t p1 = {.t_us = *t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &p1, *t);
        rfs_app_on_rssi(&s_app, 0, *t, -60, *t);
        *rng0 = s_app.rng;
        const uint64_t a = rfs_bc_ticks();
        rfs_app_step(&s_app, *t, out);
        const uint64_t d = rfs_bc_ticks() - a;
        if (periods == 0u) {
            rfs_bc_report(row_name(base, "_first"), d, 1);
        }
        worst = d > worst ? d : worst;
        periods++;
    }
    rfs_bc_report(base, worst, 1);
    rfs_bc_report(row_name(base, "_periods"), 0, periods);
    rfs_bc_report(row_name(base, "_stack"), 0, rfs_bc_stack_depth(sp0));
}

/* Bring s_app (store already filled) to a decision at (rx, ry) and measure it: the boot
 * (periods at the pose until the initial move is decided), its goal dropped and its
 * model discarded (so the decision relearns), then `history` (may be NULL); with on_leg
 * the search tree grown as on a leg ending here (grow_on_leg), else none: the leg was cut
 * short and the decision waits for it. Then run_until_decided as `base`. */
static void measure_decision(rfs_q16_t rx, rfs_q16_t ry, void (*history)(rfs_seek_t *),
                             const char *base, bool on_leg, rfs_app_out_t *out, rfs_rng_t *rng0)
{
    int64_t t = 1000000;
    out->decided = false;
    for (uint32_t k = 0; k < 100u && !out->decided; k++, t += RFS_APP_PERIOD_US) {
        const rfs_pose_t p0 = {.t_us = t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &p0, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
        rfs_app_step(&s_app, t, out);
    }
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    if (history != 0) {
        history(&s_app.seek);
    }
    if (on_leg) {
        grow_on_leg(base, rx, ry);
    }
    run_until_decided(base, rx, ry, &t, out, rng0);
}

/* One epsilon decision in that worst case, of the meta-path preset (geodesic or not) or
 * of the paper's configuration (meta_path false: RFS_SEEK_META, whose epsilon draw is the
 * straight one): fresh init on the walled map, the store around the robot, a boot period (flood fill,
 * fit, initial move; not measured), then the model discarded and the history set, and
 * the next period measured: relearn on 10,000 samples + the epsilon decision. The kept
 * goal in *gx, *gy (for the plan measured alone). */
static void geo_decision(const rfs_app_map_t *map, bool meta_path, bool geodesic,
                         const char *base, bool on_leg, rfs_q16_t *gx, rfs_q16_t *gy)
{
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.samples = s_samples;
    if (meta_path) {
        rfs_seek_cfg_use_strategy(&cfg.seek, RFS_SEEK_META_PATH);
        cfg.seek.eps_geodesic = geodesic;
    }
    cfg.seek.eps_floor = RFS_Q16_ONE; /* epsilon = 1: the epsilon branch for certain */
    cfg.seek.eps_amp = 0;
    if (rfs_app_init(&s_app, &cfg, map) != 0) {
        rfs_sh_puts("bench: rfs_app_init failed on the walled map\n");
        rfs_sh_exit(1);
    }
    const rfs_q16_t rx = RFS_Q16_FRAC(9, 8), ry = RFS_Q16_FRAC(69, 8); /* (1.125, 8.625) m */
    fill_store_at(&s_app.seek.store, 42u, 112, 862, 30, 970);
    rfs_app_out_t out;
    rfs_rng_t rng0;
    measure_decision(rx, ry, geo_history, base, on_leg, &out, &rng0);
    rfs_bc_report(row_name(base, "_eps_relearn"), 0,
                  (uint32_t)(out.decided && out.decision.kind == RFS_SEEK_EPSILON &&
                             out.decision.relearned));
    int64_t min_detour;
    const uint32_t plans = geo_replay(&s_app.seek, rng0, geodesic, gx, gy, &min_detour);
    rfs_bc_report(row_name(base, "_plans"), 0, plans);
    rfs_bc_report(row_name(base, "_replay_goal_ok"), 0,
                  (uint32_t)(*gx == out.decision.goal_x && *gy == out.decision.goal_y));
    rfs_bc_report(row_name(base, "_path_cm"), 0, (uint32_t)((out.decision.path_len * 100) >> 16));
    if (geodesic) {
        rfs_bc_report(row_name(base, "_min_detour_cm"), 0,
                      min_detour == INT64_MAX ? 0u : (uint32_t)((min_detour * 100) >> 16));
    }
    rfs_bc_report(row_name(base, "_ridge_samples"), 0, s_app.ridge.n_used);
}

/* The paper's greedy decision behind a wall (RFS_SEEK_META; rfs_seek_meta.c choose_greedy):
 * the grid search's maximum, the point 1 m towards it, and when that point is illegal a
 * line search at the map resolution along the line to the maximum, alternating at random
 * between in front of the step point and beyond it, planning (go_to) every legal
 * candidate until one plans; the maximum itself last. Only a plan that fails lets the
 * search go on, so its cost is the failed plans plus the one that succeeds. */
#define LS_ROOM_NORTH 119u /* cells: a room's north wall, rows 119 and 120 (y 14.875 .. 15.125 m) */
#define LS_ROOM_EAST 286u  /* cells: its east wall, columns 286 and 287 (x 35.75 .. 36 m) */

/* A closed room north of the interior wall (its door shut when the map was made): walls
 * along y = 15 m from the west wall to x = 36 m and from there down to the interior
 * wall's east end, so the room's 141 x 17 legal lattice points are unreachable and the
 * north strip above it is reached only through the 4 m gap at the east end. */
static void ls_room(void)
{
    for (uint16_t y = GEO_WALL_ROW + 2u; y <= LS_ROOM_NORTH + 1u; y++) {
        for (uint16_t x = 0; x < GEO_WALL_END; x++) {
            const bool wall = y >= LS_ROOM_NORTH || x >= LS_ROOM_EAST;
            if (wall) {
                rfs_map_bit_set(s_wall, MAP_STRIDE, x, y, true);
                rfs_map_bit_set(s_free, MAP_STRIDE, x, y, false);
            }
        }
    }
}

/* 10,000 samples inside 4.9 m of (cx, cy) cm with y <= ymax cm (the robot's side of the
 * wall); the field rises northwards, +1 dB per metre, and westwards, +0.25 dB per metre
 * (so the maximum over the reachable lattice is its north-west corner, (0.625, 19.375) m,
 * nearly straight north of a robot near the west wall), +-1 dB noise. */
static void fill_store_north(rfs_store_t *st, uint64_t seed, int32_t cx, int32_t cy, int32_t ymax)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, seed);
    while (st->count < RFS_APP_MAX_SAMPLES) {
        const int32_t dx = (int32_t)rfs_rng_below(&rng, 981u) - 490; /* cm */
        const int32_t dy = (int32_t)rfs_rng_below(&rng, 981u) - 490;
        if (dx * dx + dy * dy > 490 * 490 || cx + dx < 30 || cy + dy > ymax) {
            continue;
        }
        const rfs_sample_t smp = {.x_cm = (int16_t)(cx + dx), .y_cm = (int16_t)(cy + dy),
                                  .v_q6 = (int16_t)((-60 * 64) + (dy * 64) / 100 - (dx * 16) / 100 +
                                                    (int32_t)rfs_rng_below(&rng, 128u) - 64)};
        rfs_store_offer(st, smp, &rng);
    }
}

/* What the replay of one greedy decision found. */
typedef struct ls_replay_out {
    uint32_t plans;        /* rfs_plan_path calls */
    uint32_t failed;       /* of which returned false */
    uint32_t expanded;     /* lattice points expanded by all of them */
    uint32_t candidates;   /* line-search points looked at (legal or not) */
    bool line_search;      /* the step point was illegal or did not plan */
    bool ok;               /* a goal planned */
    rfs_q16_t gx, gy;      /* the goal kept, metres Q16.16 */
    rfs_q16_t path;        /* its path length, metres Q16.16 */
} ls_replay_out_t;

/* One plan of the replay, counted. */
static bool ls_plan(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, ls_replay_out_t *o)
{
    rfs_path_t path;
    o->plans++;
    const bool ok = rfs_plan_tree_path(&s->plan, gx, gy, &path);
    o->expanded += s->plan.expanded;
    if (!ok) {
        o->failed++;
        return false;
    }
    o->ok = true;
    o->gx = gx;
    o->gy = gy;
    o->path = path.length;
    return true;
}

/* An independent count of the plans of that decision: choose_greedy's step and line
 * search replayed from a copy of the random source taken just before the step, from
 * the robot's pose (legal here, so plan_to plans from it unsnapped) to the maximum the
 * decision reports (its grid search is not random): the epsilon coin (finish_decision),
 * then the step point and per line-search index k one coin for the side taken first.
 * Scaling: as choose_greedy's: t (Q16 fraction of the way, 0 < t <= 1) times the offset
 * to the maximum (a Q16 difference, |.| < 2^32) stays below 2^48 in int64; dt = res /
 * distance (Q16), at least 1. */
static void ls_replay(rfs_seek_t *s, rfs_rng_t rng, rfs_q16_t mx, rfs_q16_t my, ls_replay_out_t *o)
{
    const rfs_map_t *m = s->map;
    const rfs_q16_t x0 = s->pose.x, y0 = s->pose.y;
    memset(o, 0, sizeof *o);
    rfs_plan_tree_begin(&s->plan, x0, y0); /* the decision's tree, searched on demand */
    (void)rfs_rng_u32(&rng);
    const int64_t dx = (int64_t)mx - x0, dy = (int64_t)my - y0;
    const rfs_q16_t dist = rfs_q16_dist(x0, y0, mx, my);
    if (dist <= s->cfg.step) {
        (void)ls_plan(s, mx, my, o);
        return;
    }
    const rfs_q16_t t_step = rfs_q16_div(s->cfg.step, dist);
    rfs_q16_t gx = rfs_sat32(x0 + ((dx * t_step) >> 16));
    rfs_q16_t gy = rfs_sat32(y0 + ((dy * t_step) >> 16));
    if (rfs_map_point_legal(m, gx, gy) && ls_plan(s, gx, gy, o)) {
        return;
    }
    o->line_search = true;
    rfs_q16_t dt = rfs_q16_div(m->res, dist);
    dt = dt <= 0 ? 1 : dt;
    for (int32_t k = 1; k < 65536; ++k) {
        bool any = false;
        const bool beyond_first = (rfs_rng_u32(&rng) & 1u) != 0u;
        for (int side = 0; side < 2; ++side) {
            const bool beyond = (side == 0) == beyond_first;
            const int64_t t = (int64_t)t_step + (beyond ? (int64_t)k * dt : -(int64_t)k * dt);
            if (t <= 0 || t > RFS_Q16_ONE) {
                continue;
            }
            any = true;
            o->candidates++;
            gx = rfs_sat32(x0 + ((dx * t) >> 16));
            gy = rfs_sat32(y0 + ((dy * t) >> 16));
            if (rfs_map_point_legal(m, gx, gy) && ls_plan(s, gx, gy, o)) {
                return;
            }
        }
        if (!any) {
            break;
        }
    }
    (void)ls_plan(s, mx, my, o);
}

/* One greedy decision of the paper's configuration (epsilon forced to 0 so the greedy
 * branch is certain, as for worst_iteration) with the robot at (rx, ry): fresh init on
 * the map as it stands, the store on the robot's side of the wall, a boot period (not
 * measured), the model discarded, and the next period measured: relearn on 10,000
 * samples + the greedy decision. */
static void ls_decision(const rfs_app_map_t *map, rfs_q16_t rx, rfs_q16_t ry, const char *base,
                        bool on_leg, rfs_q16_t *gx, rfs_q16_t *gy)
{
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.samples = s_samples;
    cfg.seek.eps_amp = 0;
    cfg.seek.eps_floor = 0;
    if (rfs_app_init(&s_app, &cfg, map) != 0) {
        rfs_sh_puts("bench: rfs_app_init failed on the walled map\n");
        rfs_sh_exit(1);
    }
    fill_store_north(&s_app.seek.store, 44u, (int32_t)((rx * 100) >> 16),
                     (int32_t)((ry * 100) >> 16), 960);
    rfs_app_out_t out;
    rfs_rng_t rng0;
    measure_decision(rx, ry, 0, base, on_leg, &out, &rng0);
    rfs_bc_report(row_name(base, "_greedy"), 0,
                  (uint32_t)(out.decided && out.decision.kind == RFS_SEEK_GREEDY &&
                             out.decision.relearned && out.decision.line_search &&
                             rfs_map_point_legal(&s_app.map, rx, ry)));
    ls_replay_out_t o;
    ls_replay(&s_app.seek, rng0, out.decision.max_x, out.decision.max_y, &o);
    rfs_bc_report(row_name(base, "_plans"), 0, o.plans);
    rfs_bc_report(row_name(base, "_failed"), 0, o.failed);
    rfs_bc_report(row_name(base, "_expanded"), 0, o.expanded);
    rfs_bc_report(row_name(base, "_candidates"), 0, o.candidates);
    rfs_bc_report(row_name(base, "_replay_goal_ok"), 0,
                  (uint32_t)(o.ok && o.line_search && (out.faults & RFS_SEEK_FAULT_NO_GOAL) == 0u &&
                             o.gx == out.decision.goal_x && o.gy == out.decision.goal_y &&
                             o.path == out.decision.path_len));
    rfs_bc_report(row_name(base, "_path_cm"), 0, (uint32_t)((out.decision.path_len * 100) >> 16));
    rfs_bc_report(row_name(base, "_ridge_samples"), 0, s_app.ridge.n_used);
    *gx = out.decision.goal_x;
    *gy = out.decision.goal_y;
}

/* The line-search rows, after every other. */
static void __attribute__((noinline)) ls_measure(const rfs_app_map_t *map)
{
    rfs_q16_t gx, gy;
    /* The paper's greedy decision next to that wall (ls_decision). The robot at
     * (1.125, 9.25) m, 0.375 m short of the wall's clearance zone (y 9.625 .. 10.375 m);
     * the maximum at the north-west corner, so the 1 m step point (y ~10.25 m) lies in
     * the zone and the line search runs: its first legal candidate beyond the zone is
     * two indices out, in front of the step point five, so it plans round the wall. */
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(37, 4), "worst_greedy_ls_wall", true, &gx, &gy);
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(37, 4), "worst_greedy_ls_wall_cut", false, &gx,
                &gy);
    /* The worst constructed: a closed room north of the wall (ls_room). From
     * (1.125, 9.5) m, at the edge of the clearance zone, the step point (y ~10.5 m) is
     * legal, in the room: it and the room's candidates plan and fail until the search
     * in front of the step point reaches the robot's side, 0.12 m ahead. The next
     * decision, from that goal (in the last 0.005 m before the zone), finds no legal
     * candidate in front but the robot's own point (index 8, t = t_step - 8 dt = 1 by
     * rounding): the room candidates beyond plan and fail until then, and the goal is a
     * null move, decided again every second (rfs_seek.c end_decision). */
    ls_room();
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(19, 2), "worst_greedy_ls_room_first", true,
                &gx, &gy);
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(19, 2), "worst_greedy_ls_room_first_cut",
                false, &gx, &gy);
    const rfs_q16_t nx = gx, ny = gy;
    ls_decision(map, nx, ny, "worst_greedy_ls_room", true, &gx, &gy);
    ls_decision(map, nx, ny, "worst_greedy_ls_room_cut", false, &gx, &gy);
    /* The same from (1.125, 9.6) m, 2 cm short of that goal (the drive stops within
     * 0.1 m of it): there index 8 in front gives t = 0 (skipped), so no candidate in
     * front is legal, and every room candidate beyond plans and fails until the north
     * strip's first one plans round both walls. */
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(48, 5), "worst_greedy_ls_room_worst", true,
                &gx, &gy);
    ls_decision(map, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(48, 5), "worst_greedy_ls_room_worst_cut",
                false, &gx, &gy);
}

/* The bench's map: free inside, a one-cell wall round the edge. */
static void __attribute__((noinline)) edge_map(void)
{
    for (uint16_t y = 0; y < MAP_H; y++) {
        for (uint16_t x = 0; x < MAP_W; x++) {
            const bool edge = x == 0u || y == 0u || x == MAP_W - 1u || y == MAP_H - 1u;
            rfs_map_bit_set(edge ? s_wall : s_free, MAP_STRIDE, x, y, true);
        }
    }
}

/* rfs_app_init on the whole map, then a boot with an empty store: the reachability flood
 * fill and the initial move only; s_app initialised again afterwards. */
static void __attribute__((noinline)) measure_init(const rfs_app_map_t *map, const rfs_app_cfg_t *cfg)
{
    int rc = -1;
    uintptr_t sp0 = rfs_bc_stack_paint();
    RFS_BC_MEASURE("app_init", 1, rc = rfs_app_init(&s_app, cfg, map));
    rfs_bc_report("stack_bytes_app_init", 0, rfs_bc_stack_depth(sp0));
    if (rc != 0) {
        rfs_sh_puts("bench: rfs_app_init failed\n");
        rfs_sh_exit(1);
    }
    rfs_bc_report("lattice_points", 0, (uint32_t)s_app.map.lw * s_app.map.lh);

    int64_t tb = 500000;
    const rfs_pose_t pb = {.t_us = tb, .x = RFS_Q16_INT(20), .y = RFS_Q16_INT(10), .theta = 0};
    rfs_app_on_pose(&s_app, &pb, tb);
    rfs_app_on_rssi(&s_app, 0, tb, -60, tb);
    rfs_app_out_t ob;
    RFS_BC_MEASURE("boot_iteration_no_samples", 1, rfs_app_step(&s_app, tb, &ob));
    if (rfs_app_init(&s_app, cfg, map) != 0) {
        rfs_sh_exit(1);
    }
}

/* The periods on the full store with the robot at (rx, ry): the boot, the worst case and
 * an ordinary period while driving. Returns the time of the last; its output in *out. */
static int64_t __attribute__((noinline)) measure_periods(rfs_q16_t rx, rfs_q16_t ry, rfs_app_out_t *out)
{
    /* Boot: the first periods with a pose and a measurement: reachability flood fill
     * (sliced, reach_budget), first fit, the initial move. */
    s_app.seek.cfg.reach_budget = RFS_SEEK_REACH_BUDGET;
    int64_t t = 1000000 - RFS_APP_PERIOD_US;
    rfs_rng_t rng0;
    run_until_decided("first_iteration", rx, ry, &t, out, &rng0);

    /* The worst case: the goal ended, the model no longer fits (discarded), iteration 1. */
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    run_until_decided("worst_iteration", rx, ry, &t, out, &rng0);
    rfs_bc_report("worst_decided_greedy_relearned", 0,
                  (uint32_t)(out->decided && out->decision.kind == RFS_SEEK_GREEDY &&
                             out->decision.relearned));
    rfs_bc_report("worst_goal_x_cm", 0, (uint32_t)((out->decision.goal_x * 100) >> 16));
    rfs_bc_report("worst_samples", 0, out->decision.samples);

    /* An ordinary period while driving the goal just chosen. */
    t += RFS_APP_PERIOD_US;
    const rfs_pose_t pose2 = {.t_us = t, .x = rx + 1000, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pose2, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    RFS_BC_MEASURE("driving_iteration", 1, rfs_app_step(&s_app, t, out));
    return t;
}

/* The input phases alone, at time t. Averaging: one packet into a full 1 s window (200
 * packets/s), then the 1 s mean (and asked from just before the newest packet). Sample store: 20 measurements (0.1 s at 200 packets/s)
 * wait for the next pose, which turns them into samples of the full reservoir. */
static void __attribute__((noinline)) measure_inputs(rfs_q16_t rx, rfs_q16_t ry, int64_t t, rfs_rng_t *rng)
{
    const rfs_rssi_cfg_t wcfg = rfs_rssi_cfg_default();
    (void)rfs_rssi_init(&s_win, &wcfg);
    for (int i = 0; i < 200; i++) {
        (void)rfs_rssi_push(&s_win, 5000 * i, (int8_t)(-60 - (i & 7)));
    }
    rfs_q16_t mean;
    RFS_BC_MEASURE("phase_averaging_push", 1, (void)rfs_rssi_push(&s_win, 1000000, -61));
    RFS_BC_MEASURE("phase_averaging_mean", 1, (void)rfs_rssi_mean(&s_win, 1000000, &mean));
    /* Asked a microsecond before the newest packet's stamp (the feed's clock a little
     * ahead of the controller's), the mean scans the window's 200 entries. */
    RFS_BC_MEASURE("phase_averaging_mean_scan", 1, (void)rfs_rssi_mean(&s_win, 999999, &mean));

    rfs_store_t *st = &s_app.seek.store;
    int64_t ts = t + 5000;
    RFS_BC_MEASURE("phase_store_value", 1, rfs_store_add_value(st, ts, RFS_Q16_INT(-60), rng));
    for (int i = 1; i < 20; i++) {
        rfs_store_add_value(st, ts + 5000 * i, RFS_Q16_INT(-60), rng);
    }
    const rfs_pose_t pose3 = {.t_us = t + 100000, .x = rx, .y = ry, .theta = 0};
    RFS_BC_MEASURE("phase_store_pose_20", 20, (void)rfs_store_add_pose(st, &pose3, rng));
}

/* Grid search: the model at every reachable lattice point, as choose_greedy does it
 * (rfs_gridmax.c: rows in chunks, one predict_row call per chunk when the model has it,
 * else one predict per point). Returns the maximum. */
static rfs_q16_t __attribute__((noinline)) measure_grid_search(void)
{
    const rfs_map_t *m = &s_app.map;
    rfs_ridge_t *ridge = &s_app.ridge;
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
    return best;
}

/* A proposal, measured beside the faithful search: for a model that is affine in
 * (x, y) - the local ridge is a plane - the prediction along one lattice row is
 * monotone, so the row's maximum over reachable points is at its leftmost or
 * rightmost reachable point: 2 predictions per row instead of one per point, the
 * same maximum value exactly (best: the faithful search's). */
static void __attribute__((noinline)) measure_row_ends(rfs_q16_t best)
{
    const rfs_map_t *m = &s_app.map;
    rfs_ridge_t *ridge = &s_app.ridge;
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
}

/* The decision's phases alone with the robot at (rx, ry): relearn (the local ridge on
 * 10,000 samples, all inside the radius), grid search, the sliced fit, the step choice
 * (its path in *path), drive control and the CAN side of a period (out: the period's
 * output). */
static void __attribute__((noinline)) measure_decision_phases(rfs_q16_t rx, rfs_q16_t ry, int64_t t,
                                                              rfs_rng_t *rng,
                                                              const rfs_app_out_t *out,
                                                              rfs_path_t *path)
{
    rfs_store_t *st = &s_app.seek.store;
    rfs_ridge_t *ridge = &s_app.ridge;
    const rfs_model_fit_in_t fin = {.samples = st->samples, .n = st->count, .qx = rx, .qy = ry,
                                    .map = &s_app.map};
    rfs_ridge_ops.reset(ridge);
    RFS_BC_MEASURE("phase_relearn", 1, (void)rfs_ridge_ops.fit(ridge, &fin, 0, rng));
    rfs_bc_report("ridge_samples_used", 0, ridge->n_used);

    const rfs_q16_t best = measure_grid_search();
    measure_row_ends(best);
    const rfs_map_t *m = &s_app.map;

    /* A proposal: the fit sliced over control periods (cfg.seek.fit_budget samples per
     * period, here 2,500: four periods). */
    rfs_ridge_ops.reset(ridge);
    rfs_fit_result_t fres = RFS_FIT_MORE;
    uint32_t slices = 0;
    while (fres == RFS_FIT_MORE && slices < 100u) {
        RFS_BC_MEASURE("proposal_relearn_slice_2500", 1, fres = rfs_ridge_ops.fit(ridge, &fin, 2500u, rng));
        slices++;
    }

    /* Step choice: the point 1 m towards the maximum, its legality, the path to it. */
    bool ok = false;
    RFS_BC_MEASURE("phase_step_choice", 1, {
        const rfs_q16_t gx = rx + RFS_Q16_ONE;
        ok = rfs_map_point_legal(m, gx, ry) && rfs_plan_path(&s_app.seek.plan, rx, ry, gx, ry, path);
    });
    rfs_bc_report("step_path_ok", 0, ok ? 1u : 0u);

    /* Drive control: one update following that path. */
    rfs_drive_t *dr = &s_app.seek.drive;
    rfs_drive_set_path(dr, path, t);
    const rfs_pose_t pose4 = {.t_us = t + 50000, .x = rx, .y = ry, .theta = 0};
    int16_t l, r;
    RFS_BC_MEASURE("phase_drive_control", 1, (void)rfs_drive_update(dr, &pose4, t + 50000, &l, &r));

    /* The CAN side of a period: decode one RSSI frame, encode the two output frames. */
    rfs_can_frame_t fr[2];
    RFS_BC_MEASURE("phase_can_out_frames", 1, (void)rfs_app_frames(&s_app, out, fr));
}

/* Beside the faithful configuration: the same worst case with the fit sliced over
 * control periods (cfg.seek.fit_budget = 2,500 samples per period; the wheels stay
 * stopped while learning). Every period until the decision is measured; the largest
 * is the worst-case period of this configuration. out: the last period's output. */
static void __attribute__((noinline)) measure_sliced(const rfs_app_map_t *map, rfs_app_cfg_t *cfg,
                                                     rfs_q16_t rx, rfs_q16_t ry, rfs_app_out_t *out)
{
    cfg->seek.fit_budget = 2500u;
    if (rfs_app_init(&s_app, cfg, map) != 0) {
        rfs_sh_exit(1);
    }
    fill_store(&s_app.seek.store, 42u);
    int64_t t = 1000000;
    const rfs_pose_t pose0 = {.t_us = t, .x = rx, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pose0, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    for (int k = 0; k < 20 && !(k > 0 && out->decided); k++) {
        rfs_app_step(&s_app, t, out); /* boot: flood fill, first (sliced) fit, initial move */
        t += RFS_APP_PERIOD_US;
        const rfs_pose_t pk = {.t_us = t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &pk, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
    }
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    uint64_t worst_slice = 0;
    uint32_t periods = 0;
    out->decided = false;
    while (!out->decided && periods < 20u) {
        t += RFS_APP_PERIOD_US;
        const rfs_pose_t pk = {.t_us = t, .x = rx, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &pk, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
        const uint64_t a = rfs_bc_ticks();
        rfs_app_step(&s_app, t, out);
        const uint64_t b = rfs_bc_ticks();
        rfs_bc_report("sliced_fit_period", b - a, 1);
        if (b - a > worst_slice) {
            worst_slice = b - a;
        }
        periods++;
    }
    rfs_bc_report("sliced_worst_period", worst_slice, 1);
    rfs_bc_report("sliced_decided_greedy_relearned", 0,
                  (uint32_t)(out->decided && out->decision.kind == RFS_SEEK_GREEDY &&
                             out->decision.relearned));
    rfs_bc_report("sliced_goal_x_cm", 0, (uint32_t)((out->decision.goal_x * 100) >> 16));
}

/* The meta-path epsilon decision behind a wall (geo_decision), geodesic and not, and
 * the paper's configuration's, side by side; then one of its plans alone: from the
 * robot to the geodesic decision's kept goal, by rfs_plan_path and by a search tree. */
static void __attribute__((noinline)) measure_behind_wall(const rfs_app_map_t *map, rfs_path_t *path)
{
    geo_wall();
    rfs_q16_t gx, gy, sx, sy; /* the kept goals; the plan alone goes to the geodesic one */
    geo_decision(map, true, true, "worst_eps_geodesic", true, &gx, &gy);
    rfs_q16_t cx, cy; /* the cut-short decision's goal: its draws differ (it waited) */
    geo_decision(map, true, true, "worst_eps_geodesic_cut", false, &cx, &cy);
    geo_decision(map, true, false, "worst_eps_straight", true, &sx, &sy);
    geo_decision(map, false, false, "worst_eps_paper", true, &sx, &sy);
    geo_decision(map, false, false, "worst_eps_paper_cut", false, &cx, &cy);
    bool geo_ok = false;
    RFS_BC_MEASURE("phase_plan_behind_wall", 1,
                   geo_ok = rfs_plan_path(&s_app.seek.plan, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(69, 8),
                                          gx, gy, path));
    rfs_bc_report("plan_behind_wall_ok", 0, geo_ok ? 1u : 0u);
    rfs_bc_report("plan_behind_wall_expanded", 0, s_app.seek.plan.expanded);
    rfs_bc_report("plan_behind_wall_pulled", 0, s_app.seek.plan.pulled);
    rfs_bc_report("plan_behind_wall_path_cm", 0, (uint32_t)((path->length * 100) >> 16));
    /* The same goal by a fresh search tree from the robot (the geodesic decision's first
     * try), then a second goal on that tree (the straight decision's kept goal, also
     * north of the wall: the search resumed, the path pulled from where it parts). */
    RFS_BC_MEASURE("phase_tree_behind_wall", 1, {
        rfs_plan_tree_begin(&s_app.seek.plan, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(69, 8));
        geo_ok = rfs_plan_tree_path(&s_app.seek.plan, gx, gy, path);
    });
    rfs_bc_report("tree_behind_wall_ok", 0, geo_ok ? 1u : 0u);
    rfs_bc_report("tree_behind_wall_expanded", 0, s_app.seek.plan.expanded);
    rfs_bc_report("tree_behind_wall_path_cm", 0, (uint32_t)((path->length * 100) >> 16));
    RFS_BC_MEASURE("phase_tree_second_goal", 1,
                   geo_ok = rfs_plan_tree_path(&s_app.seek.plan, sx, sy, path));
    rfs_bc_report("tree_second_goal_ok", 0, geo_ok ? 1u : 0u);
    rfs_bc_report("tree_second_goal_expanded", 0, s_app.seek.plan.expanded);
    /* The decision's plan on a grown tree (plan_budget): a walk along the back-pointers
     * and the linear pull, no search. */
    rfs_plan_tree_begin(&s_app.seek.plan, RFS_Q16_FRAC(9, 8), RFS_Q16_FRAC(69, 8));
    while (!rfs_plan_tree_grow(&s_app.seek.plan, UINT32_MAX)) {
    }
    RFS_BC_MEASURE("phase_walk_behind_wall", 1,
                   geo_ok = rfs_plan_tree_path(&s_app.seek.plan, gx, gy, path));
    rfs_bc_report("walk_behind_wall_ok", 0, geo_ok ? 1u : 0u);
    rfs_bc_report("walk_behind_wall_pulled", 0, s_app.seek.plan.pulled);
    rfs_bc_report("walk_behind_wall_path_cm", 0, (uint32_t)((path->length * 100) >> 16));
    rfs_q16_t len = 0;
    RFS_BC_MEASURE("phase_length_behind_wall", 1,
                   geo_ok = rfs_plan_tree_length(&s_app.seek.plan, gx, gy, &len));
    /* The same tree serving a robot 0.5 m off its root (braked past it): joined at its
     * own lattice point, paths up its branch (rfs_plan_tree_move). */
    RFS_BC_MEASURE("phase_tree_move", 1,
                   geo_ok = rfs_plan_tree_move(&s_app.seek.plan, RFS_Q16_FRAC(13, 8),
                                               RFS_Q16_FRAC(69, 8), s_app.seek.cfg.step));
    rfs_bc_report("tree_move_ok", 0, geo_ok ? 1u : 0u);
    RFS_BC_MEASURE("phase_walk_moved", 1,
                   geo_ok = rfs_plan_tree_path(&s_app.seek.plan, gx, gy, path));
    rfs_bc_report("walk_moved_ok", 0, geo_ok ? 1u : 0u);
    rfs_bc_report("walk_moved_path_cm", 0, (uint32_t)((path->length * 100) >> 16));
    RFS_BC_MEASURE("phase_length_moved", 1,
                   geo_ok = rfs_plan_tree_length(&s_app.seek.plan, gx, gy, &len));
    rfs_bc_report("tree_second_goal_path_cm", 0, (uint32_t)((path->length * 100) >> 16));
}

/* local_r (docs/STRATEGIES.md, "Stalls"): a meta-path greedy decision at an estimate the
 * robot stands at, on the open south half of the map: a model whose argmax is the robot's
 * position and whose prediction is the measured -60 dBm, so the decision scans the
 * 35 x 35 lattice points round it (every one within 4 m unvisited and reachable but those
 * the robot's own poses marked: the scan's worst case) and plans to the nearest ring. */
static rfs_q16_t s_local_x, s_local_y;
static void local_reset(void *self)
{
    (void)self;
}
static rfs_fit_result_t local_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                  rfs_rng_t *rng)
{
    (void)self;
    (void)in;
    (void)budget;
    (void)rng;
    return RFS_FIT_DONE;
}
static bool local_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    (void)self;
    (void)x;
    (void)y;
    *v = RFS_Q16_INT(-60);
    return true;
}
static bool local_argmax(const void *self, rfs_q16_t *x, rfs_q16_t *y)
{
    (void)self;
    *x = s_local_x;
    *y = s_local_y;
    return true;
}
static void __attribute__((noinline)) measure_local_scan(const rfs_app_map_t *map)
{
    static const rfs_model_ops_t ops = {.name = "local", .reset = local_reset, .fit = local_fit,
                                        .predict = local_predict, .argmax = local_argmax};
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.samples = s_samples;
    rfs_seek_cfg_use_strategy(&cfg.seek, RFS_SEEK_META_PATH);
    cfg.seek.eps_amp = 0; /* epsilon = 0: every decision greedy */
    cfg.seek.eps_floor = 0;
    if (rfs_app_init(&s_app, &cfg, map) != 0) {
        rfs_sh_puts("bench: rfs_app_init failed for the local scan\n");
        rfs_sh_exit(1);
    }
    s_local_x = RFS_Q16_INT(30);
    s_local_y = RFS_Q16_INT(5);
    s_app.seek.model.ops = &ops;
    rfs_app_out_t out;
    rfs_rng_t rng0;
    measure_decision(s_local_x, s_local_y, NULL, "local_scan", false, &out, &rng0);
    const rfs_q16_t d = rfs_q16_dist(s_local_x, s_local_y, out.decision.goal_x, out.decision.goal_y);
    rfs_bc_report("local_scan_greedy", 0, (uint32_t)(out.decided && out.decision.kind == RFS_SEEK_GREEDY));
    rfs_bc_report("local_scan_goal_cm", 0, (uint32_t)((d * 100) >> 16));
}

/* A driving period whose next-decision tree is grown (rfs_plan_tree_grown): the drive's
 * own work, beside which a model's warming slice runs (docs/PERFORMANCE.md, "Decision
 * latency"; bench.sh adds the path-loss slice and prediction from the models image). */
static void __attribute__((noinline)) measure_drive_grown(const rfs_app_map_t *map,
                                                          rfs_app_cfg_t *cfg, rfs_q16_t rx,
                                                          rfs_q16_t ry, rfs_app_out_t *out)
{
    cfg->seek.fit_budget = 0u;
    if (rfs_app_init(&s_app, cfg, map) != 0) {
        rfs_sh_exit(1);
    }
    fill_store(&s_app.seek.store, 42u);
    int64_t t = 1000000 - RFS_APP_PERIOD_US;
    rfs_rng_t rng0;
    run_until_decided("grown_boot", rx, ry, &t, out, &rng0);
    rfs_drive_stop(&s_app.seek.drive, t);
    s_app.seek.model.ops->reset(s_app.seek.model.self);
    run_until_decided("grown_decision", rx, ry, &t, out, &rng0);
    /* A goal 3 m on, driven from here; the next decision's tree begun at it and grown. */
    rfs_path_t leg;
    memset(&leg, 0, sizeof leg);
    leg.x[0] = rx + RFS_Q16_INT(3);
    leg.y[0] = ry;
    leg.n = 1;
    leg.length = RFS_Q16_INT(3);
    rfs_drive_set_path(&s_app.seek.drive, &leg, t);
    s_app.seek.state = RFS_SEEK_DRIVING;
    rfs_plan_tree_begin(&s_app.seek.plan, leg.x[0], leg.y[0]);
    uint32_t k = 0;
    for (; k < 200u && !rfs_plan_tree_grown(&s_app.seek.plan); k++) {
        t += RFS_APP_PERIOD_US;
        const rfs_pose_t pk = {.t_us = t, .x = rx + (rfs_q16_t)k * 1000, .y = ry, .theta = 0};
        rfs_app_on_pose(&s_app, &pk, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
        rfs_app_step(&s_app, t, out);
    }
    t += RFS_APP_PERIOD_US;
    const rfs_pose_t pg = {.t_us = t, .x = rx + (rfs_q16_t)k * 1000, .y = ry, .theta = 0};
    rfs_app_on_pose(&s_app, &pg, t);
    rfs_app_on_rssi(&s_app, 0, t, -60, t);
    RFS_BC_MEASURE("driving_grown_iteration", 1, rfs_app_step(&s_app, t, out));
    rfs_bc_report("driving_grown_periods", 0, k);
    rfs_bc_report("driving_grown_running", 0,
                  (uint32_t)(s_app.seek.state == RFS_SEEK_DRIVING &&
                             s_app.seek.drive.status == RFS_DRIVE_RUNNING));
}

int main(void)
{
    rfs_bc_start(); /* SysTick, and the calibration lines */
    edge_map();
    const rfs_app_map_t map = {.w = MAP_W, .h = MAP_H, .res = RFS_Q16_FRAC(1, 8),
                               .origin_x = 0, .origin_y = 0, .free = s_free, .wall = s_wall};
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.samples = s_samples;
    cfg.seek.eps_amp = 0; /* epsilon = 0: the greedy branch, the expensive one, for certain */
    cfg.seek.eps_floor = 0;
    measure_init(&map, &cfg);

    const rfs_q16_t rx = RFS_Q16_INT(20), ry = RFS_Q16_INT(10);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 43u);
    fill_store(&s_app.seek.store, 42u);
    rfs_bc_report("samples", 0, s_app.seek.store.count);
    rfs_app_out_t out;
    const int64_t t = measure_periods(rx, ry, &out);
    measure_inputs(rx, ry, t, &rng);
    rfs_path_t path;
    measure_decision_phases(rx, ry, t, &rng, &out, &path);
    measure_sliced(&map, &cfg, rx, ry, &out);
    measure_behind_wall(&map, &path);
    ls_measure(&map);
    measure_local_scan(&map);
    measure_drive_grown(&map, &cfg, rx, ry, &out);
    rfs_sh_exit(0);
}
