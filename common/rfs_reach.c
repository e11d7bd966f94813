/* rfs_reach.c - reachability on the map's lattice (see rfs_reach.h). */
#include "rfs_reach.h"

#include <string.h>

uint32_t rfs_reach_bytes(const rfs_map_t *map)
{
    return ((uint32_t)map->lw * map->lh + 7u) / 8u;
}

/* The snap's ring search; with `reach`, only points whose bit there is `in`. */
static bool snap(const rfs_map_t *map, const uint8_t *reach, bool in, rfs_q16_t x, rfs_q16_t y,
                 uint16_t *oi, uint16_t *oj)
{
    const rfs_map_t *m = map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    for (int32_t r = 0; r <= RFS_REACH_SNAP_RADIUS; ++r) {
        int64_t best = INT64_MAX;
        for (int32_t dj = -r; dj <= r; ++dj) {
            for (int32_t di = -r; di <= r; ++di) {
                if (di != -r && di != r && dj != -r && dj != r) {
                    continue; /* ring only */
                }
                int32_t i = (int32_t)ci + di, j = (int32_t)cj + dj;
                if (i < 0 || j < 0 || i >= (int32_t)m->lw || j >= (int32_t)m->lh) {
                    continue;
                }
                if (!rfs_map_lattice_legal(m, (uint16_t)i, (uint16_t)j)) {
                    continue;
                }
                if (reach != 0 && rfs_reach_at(m, reach, (uint16_t)i, (uint16_t)j) != in) {
                    continue;
                }
                int64_t d = (int64_t)di * di + (int64_t)dj * dj;
                if (d < best) {
                    best = d;
                    *oi = (uint16_t)i;
                    *oj = (uint16_t)j;
                }
            }
        }
        if (best != INT64_MAX) {
            return true;
        }
    }
    return false;
}

bool rfs_reach_snap(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x, rfs_q16_t y,
                    uint16_t *oi, uint16_t *oj)
{
    return snap(map, reach, true, x, y, oi, oj);
}

bool rfs_reach_snap_outside(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x,
                            rfs_q16_t y, uint16_t *oi, uint16_t *oj)
{
    return snap(map, reach, false, x, y, oi, oj);
}

/* Mark every legal lattice point: the answer when the flood's queue is too small for
 * this map's frontier, rather than a wrong partial set; the planner still checks goals. */
static void mark_all_legal(const rfs_map_t *m, uint8_t *reach)
{
    for (uint16_t j = 0; j < m->lh; ++j) {
        for (uint16_t i = 0; i < m->lw; ++i) {
            if (rfs_map_lattice_legal(m, i, j)) {
                rfs_reach_bit_set(reach, (uint32_t)j * m->lw + i);
            }
        }
    }
}

bool rfs_reach_flood_begin(rfs_reach_flood_t *f, const rfs_map_t *map, rfs_q16_t x,
                           rfs_q16_t y, uint8_t *reach, uint32_t *queue)
{
    memset(reach, 0, rfs_reach_bytes(map));
    f->head = 0u;
    f->count = 0u;
    f->overflow = false;
    f->marked = 0u;
    uint16_t si, sj;
    if (!rfs_reach_snap(map, 0, x, y, &si, &sj)) {
        return false;
    }
    const uint32_t start = (uint32_t)sj * map->lw + si;
    rfs_reach_bit_set(reach, start);
    queue[0] = start;
    f->count = 1u;
    f->marked = 1u;
    return true;
}

bool rfs_reach_flood_run(rfs_reach_flood_t *f, const rfs_map_t *map, uint8_t *reach,
                         uint32_t *queue, uint32_t cap, uint32_t budget)
{
    const rfs_map_t *m = map;
    static const int8_t k_di[8] = { 1, -1, 0, 0, 1, 1, -1, -1 };
    static const int8_t k_dj[8] = { 0, 0, 1, -1, 1, -1, 1, -1 };
    for (uint32_t done = 0u; f->count > 0u; ++done) {
        if (budget != 0u && done == budget) {
            return false;
        }
        uint32_t idx = queue[f->head];
        f->head = (f->head + 1u) % cap;
        f->count--;
        uint16_t i = (uint16_t)(idx % m->lw), j = (uint16_t)(idx / m->lw);
        for (int k = 0; k < 8; ++k) {
            int32_t ni = (int32_t)i + k_di[k], nj = (int32_t)j + k_dj[k];
            if (ni < 0 || nj < 0 || ni >= (int32_t)m->lw || nj >= (int32_t)m->lh) {
                continue;
            }
            uint32_t nidx = (uint32_t)nj * m->lw + (uint32_t)ni;
            if (rfs_reach_bit(reach, nidx) ||
                !rfs_map_lattice_legal(m, (uint16_t)ni, (uint16_t)nj)) {
                continue;
            }
            /* The recorded step cells when the map has them, else the traversal: the
             * same answer as rfs_map_segment_legal between the two lattice points. */
            if (!rfs_map_lattice_step_legal(m, i, j, k_di[k], k_dj[k])) {
                continue;
            }
            rfs_reach_bit_set(reach, nidx);
            f->marked++;
            if (f->count == cap) {
                f->overflow = true; /* marked but not expanded: handled below */
                continue;
            }
            queue[(f->head + f->count) % cap] = nidx;
            f->count++;
        }
    }
    if (f->overflow) {
        mark_all_legal(m, reach);
        f->overflow = false;
        f->marked = UINT32_MAX;
    }
    return true;
}

bool rfs_reach_fill(const rfs_map_t *map, rfs_q16_t x, rfs_q16_t y, uint8_t *reach,
                    uint32_t *queue, uint32_t cap)
{
    rfs_reach_flood_t f;
    if (!rfs_reach_flood_begin(&f, map, x, y, reach, queue)) {
        return false;
    }
    (void)rfs_reach_flood_run(&f, map, reach, queue, cap, 0u);
    return true;
}

bool rfs_reach_nearest(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x, rfs_q16_t y,
                       rfs_q16_t *ox, rfs_q16_t *oy)
{
    const rfs_map_t *m = map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    int64_t best = INT64_MAX;
    uint16_t bi = 0, bj = 0;
    for (uint16_t j = 0; j < m->lh; ++j) {
        for (uint16_t i = 0; i < m->lw; ++i) {
            if (!rfs_reach_at(m, reach, i, j)) {
                continue;
            }
            int64_t di = (int64_t)i - ci, dj = (int64_t)j - cj;
            int64_t d = di * di + dj * dj;
            if (d < best) {
                best = d;
                bi = i;
                bj = j;
            }
        }
    }
    if (best == INT64_MAX) {
        return false;
    }
    rfs_map_lattice_point(m, bi, bj, ox, oy);
    return true;
}
