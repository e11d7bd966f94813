/* rfs_plan.c - shortest paths on the map lattice: Dial's bucket-queue Dijkstra with
 * octile integer costs (straight 2, diagonal 3), then string pulling (docs/MAPS.md).
 *
 * The paper's robot used the ROS navigation stack to reach goals that are not in line
 * of sight (section 5.1); the core plans for itself within a microcontroller's RAM.
 *
 * Work memory: one byte per lattice point,
 *   bits 0..2  direction to the parent (the neighbour one step closer to the goal)
 *   bit  3     closed (final cost known)
 *   bit  4     open (has a tentative cost)
 *   bits 5..6  tentative cost mod 4
 *   bit  7     lattice point known to be illegal
 * Every tentative cost lies in [d, d + 3] while the bucket of cost d is drained, so the
 * cost mod 4 identifies it exactly and four ring buffers (one per cost mod 4, a quarter
 * of the caller's queue each) are the whole priority queue.
 */
#include "rfs_plan.h"

#include <string.h>

#define W_DIR 0x07u
#define W_CLOSED 0x08u
#define W_OPEN 0x10u
#define W_TMOD_SHIFT 5u
#define W_TMOD 0x60u
#define W_ILLEGAL 0x80u

static const int8_t DIR_X[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int8_t DIR_Y[8] = {0, 1, 1, 1, 0, -1, -1, -1};

int rfs_plan_init(rfs_plan_t *p, const rfs_map_t *map, uint8_t *work, uint32_t work_bytes,
                  uint32_t *queue, uint32_t queue_cap)
{
    if (p == 0 || map == 0 || work == 0 || queue == 0 || queue_cap < 8u ||
        work_bytes < (uint32_t)map->lw * map->lh) {
        return -1;
    }
    memset(p, 0, sizeof(*p));
    p->map = map;
    p->work = work;
    p->queue = queue;
    p->queue_cap = queue_cap;
    return 0;
}


/* Choose the lattice point that connects (x, y) to the lattice: among the 3 x 3 points
 * around the nearest one, the closest legal point joined by a legal segment. When the
 * point itself is illegal (a robot pushed into the clearance zone), the closest legal
 * point of the 5 x 5 neighbourhood, without the segment check, so the robot can leave. */
static bool connect(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y, bool allow_escape,
                    uint32_t *idx)
{
    uint16_t ci;
    uint16_t cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    bool escape = allow_escape && !rfs_map_point_legal(m, x, y);
    int32_t rad = escape ? 2 : 1;
    bool found = false;
    rfs_q16_t best = RFS_Q16_MAX;
    for (int32_t dj = -rad; dj <= rad; dj++) {
        for (int32_t di = -rad; di <= rad; di++) {
            int32_t i = (int32_t)ci + di;
            int32_t j = (int32_t)cj + dj;
            if (i < 0 || j < 0 || i >= (int32_t)m->lw || j >= (int32_t)m->lh) {
                continue;
            }
            rfs_q16_t px;
            rfs_q16_t py;
            rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
            if (!rfs_map_point_legal(m, px, py)) {
                continue;
            }
            if (!escape && !rfs_map_segment_legal(m, x, y, px, py)) {
                continue;
            }
            rfs_q16_t d = rfs_q16_dist(x, y, px, py);
            if (d < best) {
                best = d;
                *idx = (uint32_t)j * m->lw + (uint32_t)i;
                found = true;
            }
        }
    }
    return found;
}

typedef struct rings {
    uint32_t *q;
    uint32_t cap;      /* per ring */
    uint32_t head[4];
    uint32_t count[4];
    uint32_t peak;
    bool overflow;
} rings_t;

static void ring_push(rings_t *r, uint32_t cost, uint32_t v)
{
    uint32_t b = cost & 3u;
    if (r->count[b] == r->cap) {
        r->overflow = true;
        return;
    }
    r->q[b * r->cap + (r->head[b] + r->count[b]) % r->cap] = v;
    r->count[b]++;
    if (r->count[b] > r->peak) {
        r->peak = r->count[b];
    }
}

/* Dijkstra from the goal's lattice point until the start's is closed. */
static bool search(rfs_plan_t *p, uint32_t s_idx, uint32_t g_idx)
{
    const rfs_map_t *m = p->map;
    const uint32_t lw = m->lw;
    const uint32_t n = lw * m->lh;
    uint8_t *w = p->work;
    /* Step patterns (grid a multiple of res): lattice legality and edges from the
     * recorded cells; otherwise, or for the reference, positions and the traversal. */
    const bool steps = m->step_n != 0 && !p->exact_edges;
    memset(w, 0, n);
    rings_t r;
    memset(&r, 0, sizeof(r));
    r.q = p->queue;
    r.cap = p->queue_cap / 4u;
    w[g_idx] = W_OPEN;
    ring_push(&r, 0, g_idx);
    uint32_t d = 0;
    uint32_t empty_run = 0;
    while (empty_run < 4u) {
        uint32_t b = d & 3u;
        if (r.count[b] == 0) {
            empty_run++;
            d++;
            continue;
        }
        empty_run = 0;
        while (r.count[b] > 0) {
            uint32_t u = r.q[b * r.cap + r.head[b]];
            r.head[b] = (r.head[b] + 1u) % r.cap;
            r.count[b]--;
            uint8_t wu = w[u];
            if ((wu & W_CLOSED) || ((wu & W_TMOD) >> W_TMOD_SHIFT) != b) {
                continue; /* stale entry */
            }
            w[u] = (uint8_t)(wu | W_CLOSED);
            p->expanded++;
            p->queue_peak = r.peak;
            if (u == s_idx) {
                return true;
            }
            uint16_t ui = (uint16_t)(u % lw);
            uint16_t uj = (uint16_t)(u / lw);
            rfs_q16_t ux = 0;
            rfs_q16_t uy = 0;
            if (!steps) {
                rfs_map_lattice_point(m, ui, uj, &ux, &uy);
            }
            for (uint32_t k = 0; k < 8u; k++) {
                int32_t vi = (int32_t)ui + DIR_X[k];
                int32_t vj = (int32_t)uj + DIR_Y[k];
                if (vi < 0 || vj < 0 || vi >= (int32_t)lw || vj >= (int32_t)m->lh) {
                    continue;
                }
                uint32_t v = (uint32_t)vj * lw + (uint32_t)vi;
                uint8_t wv = w[v];
                if (wv & (W_CLOSED | W_ILLEGAL)) {
                    continue;
                }
                uint32_t nc = d + ((k & 1u) ? 3u : 2u);
                if (wv & W_OPEN) {
                    uint32_t old = d + ((((wv & W_TMOD) >> W_TMOD_SHIFT) - d) & 3u);
                    if (nc >= old) {
                        continue;
                    }
                }
                if (steps) {
                    if (!(wv & W_OPEN) && !rfs_map_lattice_legal(m, (uint16_t)vi, (uint16_t)vj)) {
                        w[v] = (uint8_t)(wv | W_ILLEGAL);
                        continue;
                    }
                    if (!rfs_map_lattice_step_legal(m, ui, uj, DIR_X[k], DIR_Y[k])) {
                        continue;
                    }
                } else {
                    rfs_q16_t vx;
                    rfs_q16_t vy;
                    rfs_map_lattice_point(m, (uint16_t)vi, (uint16_t)vj, &vx, &vy);
                    if (!(wv & W_OPEN) && !rfs_map_point_legal(m, vx, vy)) {
                        w[v] = (uint8_t)(wv | W_ILLEGAL);
                        continue;
                    }
                    if (!rfs_map_segment_legal(m, ux, uy, vx, vy)) {
                        continue;
                    }
                }
                /* Parent direction points from v back to u. */
                w[v] = (uint8_t)(W_OPEN | ((nc & 3u) << W_TMOD_SHIFT) | ((k + 4u) & 7u));
                ring_push(&r, nc, v);
                if (r.overflow) {
                    return false;
                }
            }
        }
        d++;
    }
    return false;
}

/* String pulling state: the last emitted waypoint (anchor) and the farthest point seen
 * since that is reachable from it in a straight legal line. */
typedef struct puller {
    const rfs_map_t *m;
    rfs_path_t *out;
    rfs_q16_t ax, ay;   /* anchor */
    rfs_q16_t lx, ly;   /* last reachable point */
    bool has_last;
    bool full;
    int64_t len;        /* metres Q16.16, accumulated */
} puller_t;

static void emit(puller_t *pl, rfs_q16_t x, rfs_q16_t y)
{
    if (pl->out->n >= RFS_PLAN_MAX_WAYPOINTS) {
        pl->full = true;
        return;
    }
    pl->out->x[pl->out->n] = x;
    pl->out->y[pl->out->n] = y;
    pl->out->n++;
    pl->len += rfs_q16_dist(pl->ax, pl->ay, x, y);
    pl->ax = x;
    pl->ay = y;
}

static void pull(puller_t *pl, rfs_q16_t x, rfs_q16_t y)
{
    if (rfs_map_segment_legal(pl->m, pl->ax, pl->ay, x, y)) {
        pl->lx = x;
        pl->ly = y;
        pl->has_last = true;
        return;
    }
    if (pl->has_last) {
        emit(pl, pl->lx, pl->ly);
    } else {
        /* First hop out of an illegal start: take it as it is. */
        emit(pl, x, y);
        return;
    }
    pl->lx = x;
    pl->ly = y;
    pl->has_last = true;
}

void rfs_plan_set_component(rfs_plan_t *p, const uint8_t *bits)
{
    p->component = bits;
}

static bool component_bit(const uint8_t *bits, uint32_t idx)
{
    return ((bits[idx >> 3] >> (idx & 7u)) & 1u) != 0u;
}

bool rfs_plan_path(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                   rfs_path_t *out)
{
    const rfs_map_t *m = p->map;
    out->n = 0;
    out->length = 0;
    p->expanded = 0;
    p->queue_peak = 0;
    if (!rfs_map_point_legal(m, x1, y1)) {
        return false;
    }
    if (rfs_map_segment_legal(m, x0, y0, x1, y1)) {
        out->x[0] = x1;
        out->y[0] = y1;
        out->n = 1;
        out->length = rfs_q16_dist(x0, y0, x1, y1);
        return true;
    }
    uint32_t s_idx;
    uint32_t g_idx;
    if (!connect(m, x1, y1, false, &g_idx) || !connect(m, x0, y0, true, &s_idx)) {
        return false;
    }
    if (p->component != 0 &&
        component_bit(p->component, s_idx) != component_bit(p->component, g_idx)) {
        return false; /* different components: the search cannot succeed */
    }
    if (!search(p, s_idx, g_idx)) {
        return false;
    }
    puller_t pl;
    memset(&pl, 0, sizeof(pl));
    pl.m = m;
    pl.out = out;
    pl.ax = x0;
    pl.ay = y0;
    const uint32_t lw = m->lw;
    uint32_t u = s_idx;
    uint32_t steps = 0;
    const uint32_t n = lw * m->lh;
    for (;;) {
        rfs_q16_t ux;
        rfs_q16_t uy;
        rfs_map_lattice_point(m, (uint16_t)(u % lw), (uint16_t)(u / lw), &ux, &uy);
        pull(&pl, ux, uy);
        if (u == g_idx || pl.full || ++steps > n) {
            break;
        }
        uint32_t k = p->work[u] & W_DIR;
        u = (uint32_t)((int32_t)(u / lw) + DIR_Y[k]) * lw + (uint32_t)((int32_t)(u % lw) + DIR_X[k]);
    }
    pull(&pl, x1, y1);
    emit(&pl, pl.lx, pl.ly);
    if (pl.full || steps > n) {
        out->n = 0;
        return false;
    }
    out->length = pl.len > INT32_MAX ? INT32_MAX : (rfs_q16_t)pl.len;
    return true;
}
