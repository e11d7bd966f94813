/* seek_world.h - the fixture shared by the seeker's tests: an open rectangle of free
 * cells with a one-cell border wall (optionally one inner wall), the core's map over it,
 * and a seeker with the local ridge and caller-owned memory, all on the heap. */
#ifndef SEEK_WORLD_H
#define SEEK_WORLD_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_ridge.h"
#include "rfs_seek.h"

#define RES 0.1
#define Q(v) ((rfs_q16_t)lround((v) * 65536.0))
#define D(q) ((double)(q) / 65536.0)

typedef struct world {
    uint16_t w, h;
    uint8_t *free_bits, *wall_bits, *legal_bits;
    rfs_map_t map;
    rfs_seek_mem_t mem;
    rfs_sample_t *samples;
    rfs_pending_t *pending;
    rfs_ridge_t ridge;
    rfs_seek_t seek;
    rfs_rng_t rng;
} world_t;

/* An open rectangle w_m x h_m metres with a one-cell border wall, plus an optional
 * vertical wall one cell thick spanning x in [wall_x, wall_x + RES), y in [0, wall_y_top). */
static inline void world_make(world_t *t, double w_m, double h_m, double wall_x, double wall_y_top)
{
    memset(t, 0, sizeof *t);
    t->w = (uint16_t)lround(w_m / RES);
    t->h = (uint16_t)lround(h_m / RES);
    uint32_t bytes = rfs_map_bytes(t->w, t->h);
    uint16_t stride = (uint16_t)((t->w + 7) / 8);
    t->free_bits = calloc(bytes, 1);
    t->wall_bits = calloc(bytes, 1);
    t->legal_bits = calloc(bytes, 1);
    for (uint16_t y = 0; y < t->h; ++y) {
        for (uint16_t x = 0; x < t->w; ++x) {
            double cy = (y + 0.5) * RES;
            bool wall = x == 0 || y == 0 || x == t->w - 1 || y == t->h - 1;
            if (wall_x > 0 && x == (uint16_t)lround(wall_x / RES) && cy < wall_y_top) {
                wall = true;
            }
            rfs_map_bit_set(t->free_bits, stride, x, y, !wall);
            rfs_map_bit_set(t->wall_bits, stride, x, y, wall);
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&t->map, &mc, t->w, t->h, Q(RES), 0, 0, t->free_bits,
                                  t->wall_bits, t->legal_bits), 0);
}

static inline void seek_make(world_t *t, rfs_seek_cfg_t cfg, uint64_t seed)
{
    uint32_t lpts = (uint32_t)t->map.lw * t->map.lh;
    t->samples = calloc(cfg.store.capacity, sizeof *t->samples);
    t->pending = calloc(256, sizeof *t->pending);
    t->mem.samples = t->samples;
    t->mem.pending = t->pending;
    t->mem.pending_cap = 256;
    t->mem.plan_work = calloc(lpts, 1);
    t->mem.plan_work_bytes = lpts;
    t->mem.plan_queue_cap = lpts;
    t->mem.plan_queue = calloc(lpts, sizeof(uint32_t));
    t->mem.visited_bytes = rfs_reach_bytes(&t->map);
    t->mem.visited = calloc(t->mem.visited_bytes, 1);
    t->mem.reach_bytes = t->mem.visited_bytes;
    t->mem.reach = calloc(t->mem.reach_bytes, 1);
    rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&t->ridge, &rc), 0);
    assert_int_equal(rfs_seek_init(&t->seek, &cfg, &t->map, rfs_ridge_model(&t->ridge),
                                   &rfs_target_rssi, &t->mem), 0);
    rfs_rng_seed(&t->rng, seed);
}

static inline void world_free(world_t *t)
{
    free(t->free_bits);
    free(t->wall_bits);
    free(t->legal_bits);
    free(t->samples);
    free(t->pending);
    free(t->mem.plan_work);
    free(t->mem.plan_queue);
    free(t->mem.visited);
    free(t->mem.reach);
}

static inline rfs_pose_t pose_at(int64_t t_us, double x, double y, double th)
{
    rfs_pose_t p = { t_us, Q(x), Q(y), Q(th) };
    return p;
}

/* Feed pose + one measurement at time t (both fresh), then step. */
static inline void feed(world_t *t, int64_t t_us, double x, double y, double th, int8_t dbm,
                        rfs_seek_out_t *out)
{
    rfs_pose_t p = pose_at(t_us, x, y, th);
    rfs_seek_on_pose(&t->seek, &p, &t->rng);
    rfs_seek_on_rssi(&t->seek, 0, t_us, dbm, &t->rng);
    rfs_seek_step(&t->seek, t_us, &t->rng, out);
}

#endif /* SEEK_WORLD_H */
