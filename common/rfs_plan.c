/* rfs_plan.c - shortest paths on the map lattice: Dial's bucket-queue Dijkstra with
 * octile integer costs (straight 2, diagonal 3), then string pulling (docs/MAPS.md).
 *
 * The paper's robot used the ROS navigation stack to reach goals that are not in line
 * of sight (section 5.1); the core plans for itself within a microcontroller's RAM.
 *
 * Work memory: one byte per lattice point,
 *   bits 0..2  direction to the parent (the neighbour one step closer to the search's
 *              root: rfs_plan_path's goal, or a tree's start)
 *   bit  3     closed (final cost known)
 *   bit  4     open (has a tentative cost)
 *   bits 5..6  tentative cost mod 4
 *   bit  7     lattice point known to be illegal
 * A closed point keeps bits 0..3; a search tree marks paths in its bits 4..6.
 * Every tentative cost lies in [d, d + 3] while the bucket of cost d is drained, so the
 * cost mod 4 identifies it exactly and four ring buffers (one per cost mod 4, a quarter
 * of the caller's queue each) are the whole priority queue.
 *
 * A search tree (rfs_plan_tree_begin) keeps that queue in rfs_plan_t between calls and
 * resumes it, so several goals from one start cost one search out to the farthest.
 */
#include "rfs_plan.h"

#include <string.h>

#define W_DIR 0x07u
#define W_CLOSED 0x08u
#define W_OPEN 0x10u
#define W_TMOD_SHIFT 5u
#define W_TMOD 0x60u
#define W_ILLEGAL 0x80u
/* Bits 4..6 of a closed point (open and cost are dead once closed; cleared at closing):
 * the search tree's marks of its last pulled path (tree_extract). */
#define W_PATH 0x10u
#define W_WAYPT 0x20u
#define W_NEW 0x40u

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

#define NO_POINT UINT32_MAX

/* The queue during a search: the caller's array and a working copy of p->dial (kept in
 * a local so that stores into the queue need not reload it). */
typedef struct rings {
    uint32_t *q;
    uint32_t cap; /* entries per ring: a quarter of the queue */
    rfs_plan_dial_t st;
} rings_t;

/* Scaling and overflow: costs are half lattice steps (straight 2, diagonal 3), below
 * 3 * lw * lh < 2^32 for any lattice the uint16_t sizes allow; only cost mod 4 is stored. */
static void ring_push(rings_t *r, uint32_t cost, uint32_t v)
{
    uint32_t b = cost & 3u;
    if (r->st.count[b] == r->cap) {
        r->st.overflow = true;
        return;
    }
    r->q[b * r->cap + (r->st.head[b] + r->st.count[b]) % r->cap] = v;
    r->st.count[b]++;
    if (r->st.count[b] > r->st.peak) {
        r->st.peak = r->st.count[b];
    }
}

/* Start a Dijkstra at `root`: work cleared, queue holding the root at cost 0. */
static void seed(rfs_plan_t *p, uint32_t root)
{
    memset(p->work, 0, (size_t)p->map->lw * p->map->lh);
    rings_t r;
    memset(&r, 0, sizeof(r));
    r.q = p->queue;
    r.cap = p->queue_cap / 4u;
    r.st.pending = NO_POINT;
    p->work[root] = W_OPEN;
    ring_push(&r, 0, root);
    p->dial = r.st;
}

/* Relax the neighbours of the point u just closed at cost d. false when the queue
 * overflowed (r->st.overflow; the search is then void). The map, work array and edge test come
 * in as arguments: loaded once per search, not after every byte store to the work. With
 * `steps` (grid a multiple of res) lattice legality and edges come from the recorded
 * cells; otherwise, or for the reference, from positions and the traversal. */
static bool relax(const rfs_map_t *m, uint8_t *w, bool steps, rings_t *r, uint32_t u,
                  uint32_t d)
{
    const uint32_t lw = m->lw;
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
        ring_push(r, nc, v);
        if (r->st.overflow) {
            return false;
        }
    }
    return true;
}

/* Continue the Dijkstra in p->dial until `target` is closed (true), or the queue is
 * empty or overflowed (false). It stops as soon as the target is closed, before its
 * neighbours are relaxed (a single search needs no more); they are relaxed first by the
 * next call (dial.pending), so a resumed search closes the points in exactly the order
 * one uninterrupted search would, whatever targets it stopped at. Buckets are drained in
 * cost order; four empty rings in a row are an empty queue (pushes go to d + 2 and
 * d + 3, never to the ring being drained). */
static bool search_until(rfs_plan_t *p, uint32_t target)
{
    rings_t r;
    r.q = p->queue;
    r.cap = p->queue_cap / 4u;
    r.st = p->dial;
    uint8_t *w = p->work;
    const rfs_map_t *m = p->map;
    const bool steps = m->step_n != 0 && !p->exact_edges;
    uint32_t d = r.st.cost;
    uint32_t u = r.st.pending; /* closed, neighbours not yet relaxed */
    uint32_t empty_run = 0;
    bool found = false;
    bool ok = !r.st.overflow;
    while (ok) {
        if (u != NO_POINT) {
            ok = relax(m, w, steps, &r, u, d);
            u = NO_POINT;
            continue;
        }
        const uint32_t b = d & 3u;
        if (r.st.count[b] == 0) {
            if (++empty_run == 4u) {
                break;
            }
            d++;
            continue;
        }
        empty_run = 0;
        const uint32_t v = r.q[b * r.cap + r.st.head[b]];
        r.st.head[b] = (r.st.head[b] + 1u) % r.cap;
        r.st.count[b]--;
        const uint8_t wv = w[v];
        if ((wv & W_CLOSED) || ((wv & W_TMOD) >> W_TMOD_SHIFT) != b) {
            continue; /* stale entry */
        }
        w[v] = (uint8_t)((wv & W_DIR) | W_CLOSED);
        p->expanded++;
        p->queue_peak = r.st.peak;
        if (v == target) {
            found = true;
            break;
        }
        u = v;
    }
    r.st.cost = d;
    r.st.pending = found ? target : NO_POINT;
    p->dial = r.st;
    return found;
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

/* The lattice point one step from u in direction k. */
static uint32_t step_from(uint32_t u, uint32_t k, uint32_t lw)
{
    return (uint32_t)((int32_t)(u / lw) + DIR_Y[k]) * lw + (uint32_t)((int32_t)(u % lw) + DIR_X[k]);
}

static void pull_point(puller_t *pl, uint32_t u, uint32_t lw)
{
    rfs_q16_t ux;
    rfs_q16_t uy;
    rfs_map_lattice_point(pl->m, (uint16_t)(u % lw), (uint16_t)(u / lw), &ux, &uy);
    pull(pl, ux, uy);
}

/* The goal's join point, the last waypoint and the length: the end every plan shares. */
static bool finish(puller_t *pl, rfs_q16_t x1, rfs_q16_t y1, bool lost)
{
    pull(pl, x1, y1);
    emit(pl, pl->lx, pl->ly);
    if (pl->full || lost) {
        pl->out->n = 0;
        return false;
    }
    pl->out->length = pl->len > INT32_MAX ? INT32_MAX : (rfs_q16_t)pl->len;
    return true;
}

static void puller_start(puller_t *pl, const rfs_map_t *m, rfs_path_t *out, rfs_q16_t x0,
                         rfs_q16_t y0)
{
    memset(pl, 0, sizeof(*pl));
    pl->m = m;
    pl->out = out;
    pl->ax = x0;
    pl->ay = y0;
}

/* The cases every plan settles before a search: -1 an illegal goal (no path), 1 a
 * straight legal segment (out holds its one waypoint), 0 the plan needs the lattice. */
static int settle(const rfs_map_t *m, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                  rfs_q16_t y1, rfs_path_t *out)
{
    out->x0 = x0;
    out->y0 = y0;
    out->has_start = true;
    if (!rfs_map_point_legal(m, x1, y1)) {
        return -1;
    }
    if (rfs_map_segment_legal(m, x0, y0, x1, y1)) {
        out->x[0] = x1;
        out->y[0] = y1;
        out->n = 1;
        out->length = rfs_q16_dist(x0, y0, x1, y1);
        return 1;
    }
    return 0;
}

bool rfs_plan_path(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                   rfs_path_t *out)
{
    const rfs_map_t *m = p->map;
    out->n = 0;
    out->length = 0;
    p->expanded = 0;
    p->queue_peak = 0;
    p->tree = 0; /* the work memory is about to be reused */
    const int settled = settle(m, x0, y0, x1, y1, out);
    if (settled != 0) {
        return settled > 0;
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
    /* From the goal outward: the back-pointers then lead from the start to the goal,
     * the order string pulling needs. */
    seed(p, g_idx);
    if (!search_until(p, s_idx)) {
        return false;
    }
    puller_t pl;
    puller_start(&pl, m, out, x0, y0);
    const uint32_t lw = m->lw;
    const uint32_t n = lw * m->lh;
    uint32_t u = s_idx;
    uint32_t steps = 0;
    for (;;) {
        pull_point(&pl, u, lw);
        if (u == g_idx || pl.full || ++steps > n) {
            break;
        }
        u = step_from(u, p->work[u] & W_DIR, lw);
    }
    return finish(&pl, x1, y1, steps > n);
}

void rfs_plan_tree_begin(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0)
{
    p->tree_x = x0;
    p->tree_y = y0;
    p->tree = 1;
}

static void set_dir(uint8_t *w, uint32_t u, uint32_t k)
{
    w[u] = (uint8_t)((w[u] & (uint8_t)~W_DIR) | k);
}

static void point_of(const rfs_map_t *m, uint32_t u, rfs_q16_t *x, rfs_q16_t *y)
{
    rfs_map_lattice_point(m, (uint16_t)(u % m->lw), (uint16_t)(u / m->lw), x, y);
}

/* The path from the tree's root to the closed point g_idx, pulled, into out.
 *
 * The back-pointers lead from the goal to the root. Turn those of the path round (each
 * point then points at its successor towards the goal), pull the path from the root
 * forwards as rfs_plan_path does, and turn them back on the way, so the tree is
 * unchanged for the next goal: no memory beyond the work byte.
 *
 * Paths to several goals share the path from the root to where they part, and string
 * pulling is greedy: its state after a point (waypoints so far, the anchor, that point
 * as the last one seen) depends on the path up to that point only. So the last pulled
 * path stays marked in the work bytes of its points (W_PATH), with W_WAYPT on each point
 * it emitted as a waypoint while pulling the path's next point; the next path takes the
 * shared part's waypoints from the marks and pulls only from where the paths part, with
 * the same results (the same emit() calls in the same order). Not when the root is
 * illegal (its first hop is taken unpulled), nor after a path overflowed the waypoints.
 * The walks are bounded by the points (a closed point's pointers always reach the
 * root). */
static bool tree_extract(rfs_plan_t *p, uint32_t g_idx, rfs_q16_t x1, rfs_q16_t y1,
                         rfs_path_t *out)
{
    const rfs_map_t *m = p->map;
    uint8_t *w = p->work;
    const uint32_t root = p->tree_root;
    const uint32_t lw = m->lw;
    const uint32_t n = lw * m->lh;
    uint32_t u = g_idx;
    uint32_t k = w[u] & W_DIR; /* from u to its parent */
    uint32_t steps = 0;
    w[u] = (uint8_t)(w[u] | W_NEW);
    while (u != root && steps++ <= n) {
        uint32_t v = step_from(u, k, lw);
        uint32_t kv = w[v] & W_DIR;
        set_dir(w, v, (k + 4u) & 7u); /* v now points at its child u */
        w[v] = (uint8_t)(w[v] | W_NEW);
        u = v;
        k = kv;
    }
    if (u != root) {
        return false; /* unreachable: a closed point's pointers lead to the root */
    }
    /* Unmark the last path where it is not this one's (its pointers there are intact;
     * from the first point on this path up, both paths are one). */
    for (u = p->tree_last, steps = 0; u != NO_POINT && !(w[u] & W_NEW) && steps++ <= n;) {
        w[u] = (uint8_t)(w[u] & (uint8_t)~(W_PATH | W_WAYPT));
        u = step_from(u, w[u] & W_DIR, lw);
    }
    const bool marks = p->tree_marks;
    puller_t pl;
    puller_start(&pl, m, out, p->tree_x, p->tree_y);
    uint32_t back = k; /* the root's own direction bits, restored as they were */
    uint32_t prev = NO_POINT;
    bool shared = marks;
    u = root;
    for (;;) {
        uint32_t wu = w[u];
        const uint32_t fwd = wu & W_DIR;
        const uint32_t next = u == g_idx ? NO_POINT : step_from(u, fwd, lw);
        if (shared && (wu & W_PATH)) {
            rfs_q16_t ux;
            rfs_q16_t uy;
            point_of(m, u, &ux, &uy);
            if (next != NO_POINT && (w[next] & W_PATH)) {
                if (wu & W_WAYPT) {
                    emit(&pl, ux, uy); /* as pulling `next` did for the last path */
                }
            } else {
                /* Where the paths part: this point was the last one seen. */
                pl.lx = ux;
                pl.ly = uy;
                pl.has_last = true;
                wu &= ~W_WAYPT;
                shared = false;
            }
        } else {
            shared = false;
            const uint16_t before = out->n;
            if (!pl.full) {
                pull_point(&pl, u, lw);
            }
            if (marks && out->n != before && prev != NO_POINT) {
                w[prev] = (uint8_t)(w[prev] | W_WAYPT); /* prev emitted while pulling u */
            }
            wu = marks ? ((wu & ~W_WAYPT) | W_PATH) : wu;
        }
        wu &= ~W_NEW;
        if (u == g_idx) {
            w[u] = (uint8_t)wu;
            break;
        }
        w[u] = (uint8_t)((wu & ~W_DIR) | back);
        back = (fwd + 4u) & 7u;
        prev = u;
        u = next;
    }
    p->tree_last = marks ? g_idx : NO_POINT;
    if (pl.full && marks) {
        /* Waypoints overflowed: the marks may be incomplete; drop them. */
        for (u = g_idx, steps = 0; steps++ <= n; u = step_from(u, w[u] & W_DIR, lw)) {
            w[u] = (uint8_t)(w[u] & (uint8_t)~(W_PATH | W_WAYPT));
            if (u == root) {
                break;
            }
        }
        p->tree_last = NO_POINT;
        p->tree_marks = false;
    }
    return finish(&pl, x1, y1, false);
}

bool rfs_plan_tree_path(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, rfs_path_t *out)
{
    const rfs_map_t *m = p->map;
    const rfs_q16_t x0 = p->tree_x;
    const rfs_q16_t y0 = p->tree_y;
    out->n = 0;
    out->length = 0;
    p->expanded = 0;
    if (p->tree == 0) {
        return false;
    }
    const int settled = settle(m, x0, y0, x1, y1, out);
    if (settled != 0) {
        return settled > 0;
    }
    uint32_t g_idx;
    if (!connect(m, x1, y1, false, &g_idx)) {
        return false;
    }
    if (p->tree == 1) {
        if (!connect(m, x0, y0, true, &p->tree_root)) {
            p->tree = 3;
            return false;
        }
        p->queue_peak = 0;
        seed(p, p->tree_root);
        p->tree = 2;
        p->tree_last = NO_POINT;
        p->tree_marks = rfs_map_point_legal(m, x0, y0);
    }
    if (p->tree != 2) {
        return false; /* the root joins no lattice point */
    }
    const uint32_t root = p->tree_root;
    if (p->component != 0 &&
        component_bit(p->component, root) != component_bit(p->component, g_idx)) {
        return false; /* different components: the search cannot succeed */
    }
    uint8_t *w = p->work;
    if (!(w[g_idx] & W_CLOSED) && !search_until(p, g_idx)) {
        return false;
    }
    return tree_extract(p, g_idx, x1, y1, out);
}
