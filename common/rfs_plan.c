/* rfs_plan.c - shortest paths on the map lattice: Dial's bucket-queue Dijkstra with
 * octile integer costs (straight 2, diagonal 3), then string pulling linear in the
 * path's length (docs/MAPS.md, "Planning").
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
 * A closed point keeps bits 0..3.
 * Every tentative cost lies in [d, d + 3] while the bucket of cost d is drained, so the
 * cost mod 4 identifies it exactly and four ring buffers (one per cost mod 4, a quarter
 * of the caller's queue each) are the whole priority queue.
 *
 * A search tree (rfs_plan_tree_begin) keeps that queue in rfs_plan_t between calls and
 * resumes it, so several goals from one start cost one search out to the farthest, and
 * rfs_plan_tree_grow builds it in slices of a bounded number of points.
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
static inline void ring_push(rings_t *r, uint32_t cost, uint32_t v)
{
    uint32_t b = cost & 3u;
    if (r->st.count[b] == r->cap) {
        r->st.overflow = true;
        return;
    }
    /* head < cap and count < cap: one wrap at most (no division in the hot loop). */
    uint32_t at = r->st.head[b] + r->st.count[b];
    at = at >= r->cap ? at - r->cap : at;
    r->q[b * r->cap + at] = v;
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
 * `steps` lattice legality and edges come from the map's lattice tests (the recorded
 * cells when the grid is a multiple of res; else positions and the traversal, each
 * computed once per map through its lattice memo); otherwise, or for the reference, from
 * positions and the traversal here. */
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

/* One edge of relax_edges: the push to v at cost nc (parent direction back, towards
 * u closed at cost d) unless v is closed or holds nc or less. false on overflow. */
static inline bool edge_to(uint8_t *w, rings_t *r, uint32_t v, uint32_t d, uint32_t nc,
                           uint32_t back)
{
    const uint8_t wv = w[v];
    if ((wv & W_CLOSED) ||
        ((wv & W_OPEN) && nc >= d + ((((wv & W_TMOD) >> W_TMOD_SHIFT) - d) & 3u))) {
        return true;
    }
    w[v] = (uint8_t)(W_OPEN | ((nc & 3u) << W_TMOD_SHIFT) | back);
    ring_push(r, nc, v);
    return !r->st.overflow;
}

/* relax() with the map's edge table (rfs_map_edges_attach): u's legal edges in one load,
 * the same answers as relax()'s lattice tests (which only skip the tests a closed or
 * cheaper neighbour makes moot), pushed in the same direction order (DIR_X, DIR_Y). */
__attribute__((always_inline)) static inline bool relax_edges(const rfs_map_t *m,
                                                             const uint16_t *edges,
                                                             uint32_t lw, uint8_t *w,
                                                             rings_t *r, uint32_t u, uint32_t d)
{
    uint32_t e = edges[u];
    if ((e & RFS_MAP_EDGES_KNOWN) == 0u) {
        e = rfs_map_lattice_edges(m, (uint16_t)(u % lw), (uint16_t)(u / lw));
    }
    return (!(e & 0x01u) || edge_to(w, r, u + 1u, d, d + 2u, 4u)) &&
           (!(e & 0x02u) || edge_to(w, r, u + lw + 1u, d, d + 3u, 5u)) &&
           (!(e & 0x04u) || edge_to(w, r, u + lw, d, d + 2u, 6u)) &&
           (!(e & 0x08u) || edge_to(w, r, u + lw - 1u, d, d + 3u, 7u)) &&
           (!(e & 0x10u) || edge_to(w, r, u - 1u, d, d + 2u, 0u)) &&
           (!(e & 0x20u) || edge_to(w, r, u - lw - 1u, d, d + 3u, 1u)) &&
           (!(e & 0x40u) || edge_to(w, r, u - lw, d, d + 2u, 2u)) &&
           (!(e & 0x80u) || edge_to(w, r, u - lw + 1u, d, d + 3u, 3u));
}

/* What search_until stopped at. */
typedef enum search_end {
    SEARCH_FOUND,    /* the target is closed */
    SEARCH_EMPTY,    /* the queue is empty (every reachable point closed) or overflowed */
    SEARCH_BUDGET    /* `budget` points were closed first */
} search_end_t;

/* Continue the Dijkstra in p->dial until `target` is closed (NO_POINT: none), the queue
 * is empty or overflowed, or `budget` points have been closed. It stops as soon as a
 * point is closed, before its neighbours are relaxed; they are relaxed first by the next
 * call (dial.pending), so a resumed search closes the points in exactly the order one
 * uninterrupted search would, whatever targets or budgets it stopped at. Buckets are
 * drained in cost order; four empty rings in a row are an empty queue (pushes go to
 * d + 2 and d + 3, never to the ring being drained). */
__attribute__((always_inline)) static inline search_end_t search_loop(rfs_plan_t *p,
                                                                      uint32_t target,
                                                                      uint32_t budget,
                                                                      bool table)
{
    rings_t r;
    r.q = p->queue;
    r.cap = p->queue_cap / 4u;
    r.st = p->dial;
    uint8_t *w = p->work;
    const rfs_map_t *m = p->map;
    /* The memo's answers are the traversal's (rfs_map_memo_attach). */
    const bool steps = m->step_n != 0 ? !p->exact_edges : m->memo != 0;
    /* The edge table and lattice width in locals: stores to the work bytes may alias m. */
    const uint16_t *const edges = table && steps && !p->exact_edges ? m->edges : 0;
    const uint32_t lw = m->lw;
    uint32_t d = r.st.cost;
    uint32_t u = r.st.pending; /* closed, neighbours not yet relaxed */
    uint32_t empty_run = 0;
    uint32_t closed = 0;
    uint32_t peak = 0; /* the rings' peak at the last point closed */
    search_end_t end = SEARCH_EMPTY;
    bool ok = !r.st.overflow;
    if (ok && u != NO_POINT) {
        ok = edges ? relax_edges(m, edges, lw, w, &r, u, d) : relax(m, w, steps, &r, u, d);
        u = NO_POINT;
    }
    while (ok && end == SEARCH_EMPTY) {
        if (closed == budget) {
            end = SEARCH_BUDGET;
            break;
        }
        const uint32_t b = d & 3u;
        uint32_t n = r.st.count[b];
        if (n == 0u) {
            if (++empty_run == 4u) {
                break;
            }
            d++;
            continue;
        }
        empty_run = 0;
        /* Drain ring b: relaxing pushes to d + 2 and d + 3 only, never to it, so its head
         * and count stay local until it is empty or the search stops. */
        const uint32_t *ring = r.q + b * r.cap;
        uint32_t head = r.st.head[b];
        while (n != 0u) {
            const uint32_t v = ring[head];
            head = head + 1u == r.cap ? 0u : head + 1u;
            n--;
            const uint8_t wv = w[v];
            if ((wv & W_CLOSED) || ((wv & W_TMOD) >> W_TMOD_SHIFT) != b) {
                continue; /* stale entry */
            }
            w[v] = (uint8_t)((wv & W_DIR) | W_CLOSED);
            closed++;
            peak = r.st.peak;
            if (v == target) {
                end = SEARCH_FOUND;
                u = v;
                break;
            }
            ok = edges ? relax_edges(m, edges, lw, w, &r, v, d) : relax(m, w, steps, &r, v, d);
            if (!ok) {
                break;
            }
            if (closed == budget) {
                end = SEARCH_BUDGET;
                break;
            }
        }
        r.st.head[b] = head;
        r.st.count[b] = n;
    }
    if (closed != 0u) {
        p->expanded += closed;
        p->queue_peak = peak;
    }
    r.st.cost = d;
    r.st.pending = end == SEARCH_EMPTY ? NO_POINT : u;
    p->dial = r.st;
    return end;
}

/* search_loop with the lattice tests, and with the map's edge table: the second is
 * reached only through rfs_plan_use_edges, so an image that never calls it links none
 * of its code (-ffunction-sections, --gc-sections). */
static search_end_t search_plain(rfs_plan_t *p, uint32_t target, uint32_t budget)
{
    return search_loop(p, target, budget, false);
}

static uint8_t search_table(rfs_plan_t *p, uint32_t target, uint32_t budget)
{
    return (uint8_t)search_loop(p, target, budget, true);
}

static search_end_t search_until(rfs_plan_t *p, uint32_t target, uint32_t budget)
{
    return p->search != 0 ? (search_end_t)p->search(p, target, budget)
                          : search_plain(p, target, budget);
}

void rfs_plan_use_edges(rfs_plan_t *p)
{
    p->search = search_table;
}

void rfs_plan_set_component(rfs_plan_t *p, const uint8_t *bits)
{
    p->component = bits;
}

static bool component_bit(const uint8_t *bits, uint32_t idx)
{
    return ((bits[idx >> 3] >> (idx & 7u)) & 1u) != 0u;
}

/* false when no lattice point of the 3 x 3 that connect() joins (x, y) to has component
 * bit `bit`: a goal there joins the lattice in another component than the start's, so
 * the plan fails, known before connect()'s nine segment tests (a line search beside a
 * closed room tries dozens of such goals, docs/PERFORMANCE.md). true without marks. */
static bool near_component(const rfs_plan_t *p, rfs_q16_t x, rfs_q16_t y, bool bit)
{
    if (p->component == 0) {
        return true;
    }
    const rfs_map_t *m = p->map;
    uint16_t ci;
    uint16_t cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    for (int32_t j = (int32_t)cj - 1; j <= (int32_t)cj + 1; j++) {
        for (int32_t i = (int32_t)ci - 1; i <= (int32_t)ci + 1; i++) {
            if (i >= 0 && j >= 0 && i < (int32_t)m->lw && j < (int32_t)m->lh &&
                component_bit(p->component, (uint32_t)j * m->lw + (uint32_t)i) == bit) {
                return true;
            }
        }
    }
    return false;
}

/* The lattice point one step from u in direction k. */
static uint32_t step_from(uint32_t u, uint32_t k, uint32_t lw)
{
    return (uint32_t)((int32_t)(u / lw) + DIR_Y[k]) * lw + (uint32_t)((int32_t)(u % lw) + DIR_X[k]);
}

static void point_of(const rfs_map_t *m, uint32_t u, rfs_q16_t *x, rfs_q16_t *y)
{
    rfs_map_lattice_point(m, (uint16_t)(u % m->lw), (uint16_t)(u / m->lw), x, y);
}

/* String pulling, linear in the path's length (docs/MAPS.md, "Planning").
 *
 * The path is the sequence P_0 .. P_n: the lattice points from the start's join point
 * (walked by the work bytes' direction bits, which lead towards the goal) and last the
 * goal itself. From each waypoint (the anchor; first the start) the next one is found
 * by galloping: P at anchor + 2, + 4, + 8 ... points is tested by a straight legal
 * segment from the anchor until a test fails or the goal is reached; between the last
 * point that passed and the one that failed, PULL_REFINE halvings narrow the cut; the
 * last point that passed is the waypoint. The tests of one waypoint cover at most
 * (4 + 2 PULL_REFINE) times the points it advances, so a path of n points costs
 * O(n) cells of segment traversal (testing every point from the anchor, as a greedy
 * puller does, costs O(n^2): 5 M instructions on the Cortex-M4 round a 35 m wall).
 * Every waypoint is reached from the one before by a tested segment, and adjacent path
 * points by a lattice edge, so the path is legal; it is never longer than the lattice
 * path. A start in the clearance zone (joined without a segment test) takes its first
 * hop to P_0 as it is. */
#define PULL_REFINE 3u

/* The path's points by index: a cursor walked forwards from the anchor's point. */
typedef struct pull_path {
    const rfs_map_t *m;
    const uint8_t *w;
    uint32_t n;            /* index of the goal: lattice points are 0 .. n - 1 */
    rfs_q16_t gx, gy;      /* the goal */
    uint32_t ak, au;       /* the anchor's index and lattice point (au: when ak < n) */
    uint32_t ck, cu;       /* a cursor at or after the anchor */
    uint32_t spanned;      /* points the segment tests spanned, summed */
} pull_path_t;

static void pull_at(pull_path_t *pp, uint32_t k, rfs_q16_t *x, rfs_q16_t *y);

/* A straight legal segment from the anchor (ax, ay) at index a (+ 1) to point t (+ 1). */
static bool pull_test(pull_path_t *pp, rfs_q16_t ax, rfs_q16_t ay, uint32_t a, uint32_t t,
                      rfs_q16_t *x, rfs_q16_t *y)
{
    pull_at(pp, t - 1u, x, y);
    pp->spanned += t - a;
    return rfs_map_segment_legal(pp->m, ax, ay, *x, *y);
}

/* Position of point k (>= the anchor's index), by walking from the cursor or the anchor. */
static void pull_at(pull_path_t *pp, uint32_t k, rfs_q16_t *x, rfs_q16_t *y)
{
    if (k >= pp->n) {
        *x = pp->gx;
        *y = pp->gy;
        return;
    }
    if (k < pp->ck) {
        pp->ck = pp->ak;
        pp->cu = pp->au;
    }
    const uint32_t lw = pp->m->lw;
    while (pp->ck < k) {
        pp->cu = step_from(pp->cu, pp->w[pp->cu] & W_DIR, lw);
        pp->ck++;
    }
    point_of(pp->m, pp->cu, x, y);
}

/* Pull the path of n lattice points from s_idx (then the goal (x1, y1)) as seen from
 * (x0, y0) into out; *spanned: the points its segment tests spanned. false when it needs
 * more than RFS_PLAN_MAX_WAYPOINTS waypoints. Indices below count from 1 (0: the start). */
static bool pull_path(const rfs_map_t *m, const uint8_t *w, uint32_t s_idx, uint32_t n,
                      rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1, rfs_path_t *out,
                      uint32_t *spanned)
{
    pull_path_t pp = {m, w, n, x1, y1, 0, s_idx, 0, s_idx, 0};
    int64_t len = 0;
    rfs_q16_t ax = x0, ay = y0; /* the anchor */
    rfs_q16_t px, py;
    uint32_t a = 0;             /* the anchor's index */
    bool ok = true;
    out->n = 0;
    for (;;) {
        uint32_t good = a + 1u; /* the farthest point known reachable: the next one */
        if (a == 0 && !pull_test(&pp, ax, ay, 0, 1, &px, &py)) {
            goto emit;          /* out of the clearance zone: the first hop as it is */
        }
        uint32_t bad = 0;
        for (uint32_t h = 2; good <= n; h *= 2u) {
            const uint32_t t = h > n + 1u - a ? n + 1u : a + h;
            if (!pull_test(&pp, ax, ay, a, t, &px, &py)) {
                bad = t;
                break;
            }
            good = t;
        }
        for (uint32_t r = 0; bad != 0 && r < PULL_REFINE && bad - good > 1u; r++) {
            const uint32_t mid = good + (bad - good) / 2u;
            if (pull_test(&pp, ax, ay, a, mid, &px, &py)) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        pull_at(&pp, good - 1u, &px, &py);
    emit:
        if (out->n >= RFS_PLAN_MAX_WAYPOINTS) {
            out->n = 0;
            ok = false;
            break;
        }
        out->x[out->n] = px;
        out->y[out->n] = py;
        out->n++;
        len += rfs_q16_dist(ax, ay, px, py);
        ax = px;
        ay = py;
        if (good == n + 1u) {
            out->length = len > INT32_MAX ? INT32_MAX : (rfs_q16_t)len;
            break;
        }
        pp.ak = pp.ck; /* the cursor is on the new anchor, point good */
        pp.au = pp.cu;
        a = good;
    }
    *spanned = pp.spanned;
    return ok;
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

/* Lattice points from u to g_idx along the direction bits, both counted; 0 when the
 * walk does not reach g_idx within the lattice's points (cannot happen: a closed
 * point's bits lead to the search's root). */
static uint32_t path_points(const rfs_plan_t *p, uint32_t u, uint32_t g_idx)
{
    const uint32_t lw = p->map->lw;
    const uint32_t n = lw * p->map->lh;
    uint32_t k = 1;
    while (u != g_idx) {
        if (k++ > n) {
            return 0;
        }
        u = step_from(u, p->work[u] & W_DIR, lw);
    }
    return k;
}

bool rfs_plan_path(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                   rfs_path_t *out)
{
    const rfs_map_t *m = p->map;
    out->n = 0;
    out->length = 0;
    p->expanded = 0;
    p->pulled = 0;
    p->queue_peak = 0;
    p->tree = 0; /* the work memory is about to be reused */
    const int settled = settle(m, x0, y0, x1, y1, out);
    if (settled != 0) {
        return settled > 0;
    }
    uint32_t s_idx;
    uint32_t g_idx;
    if (!connect(m, x0, y0, true, &s_idx) ||
        !near_component(p, x1, y1, p->component != 0 && component_bit(p->component, s_idx)) ||
        !connect(m, x1, y1, false, &g_idx)) {
        return false;
    }
    if (p->component != 0 &&
        component_bit(p->component, s_idx) != component_bit(p->component, g_idx)) {
        return false; /* different components: the search cannot succeed */
    }
    /* From the goal outward: the back-pointers then lead from the start to the goal,
     * the order string pulling needs. */
    seed(p, g_idx);
    if (search_until(p, s_idx, UINT32_MAX) != SEARCH_FOUND) {
        return false;
    }
    const uint32_t n = path_points(p, s_idx, g_idx);
    return n != 0 && pull_path(m, p->work, s_idx, n, x0, y0, x1, y1, out, &p->pulled);
}

void rfs_plan_tree_begin(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0)
{
    p->tree_x = x0;
    p->tree_y = y0;
    p->tree = 1;
    p->tree_done = false;
    p->tree_sliced = false;
    p->tree_owed = 0;
}

void rfs_plan_tree_defer(rfs_plan_t *p, bool on)
{
    p->tree_defer = on;
}

/* Pay the deferred grows' debt until lattice point `idx` is closed (rfs_plan_tree_defer):
 * the search the grows would have run, stopped early at idx. A grow that closes fewer
 * points than its budget finds the tree done, as the search stopping short of the debt
 * does (all the grows' budgets, S, exceed the points the root reaches, R, in both). When
 * idx is the debt's last point, its neighbours are relaxed as that grow would have (an
 * overflow there ends the search). */
static void tree_settle(rfs_plan_t *p, uint32_t idx)
{
    if (p->tree != 2 || p->tree_done || p->tree_owed == 0u || (p->work[idx] & W_CLOSED)) {
        return;
    }
    const uint32_t before = p->expanded;
    search_end_t end = search_until(p, idx, p->tree_owed);
    p->tree_owed -= p->expanded - before;
    if (end == SEARCH_FOUND && p->tree_owed == 0u) {
        end = search_until(p, NO_POINT, 0u);
    }
    p->tree_done = end == SEARCH_EMPTY;
}

static void set_dir(uint8_t *w, uint32_t u, uint32_t k)
{
    w[u] = (uint8_t)((w[u] & (uint8_t)~W_DIR) | k);
}

/* Walk the direction bits from u until `end` (at most the lattice's points), counting
 * straight and diagonal steps; false when it does not get there. */
static bool walk_steps(const rfs_plan_t *p, uint32_t u, uint32_t end, uint64_t *straight,
                       uint64_t *diagonal)
{
    const uint32_t lw = p->map->lw;
    const uint32_t n = lw * p->map->lh;
    for (uint32_t k = 0; u != end && k <= n; k++) {
        const uint32_t dir = p->work[u] & W_DIR;
        *straight += (dir & 1u) == 0u;
        *diagonal += dir & 1u;
        u = step_from(u, dir, lw);
    }
    return u == end;
}

/* Metres Q16.16 (saturated) of a walk's steps: straight ones grid, diagonal ones grid
 * sqrt 2. Scaling: at most lw * lh < 2^32 steps of grid < 2^31 (Q16) each in uint64;
 * sqrt 2 in Q16 (92682) times that stays below 2^64 for any lattice whose path
 * saturates the result (32 km) long before. */
static uint64_t steps_length(const rfs_map_t *m, uint64_t straight, uint64_t diagonal)
{
    const uint64_t g = (uint64_t)m->cfg.grid;
    return straight * g + ((diagonal * g * 92682u) >> 16);
}

/* Turn the back-pointers of the chain from the closed point g_idx to the root round,
 * each then pointing at its child: a walk by the direction bits from any closed point
 * then reaches g_idx (up its own branch to the chain, then along it). *root_dir keeps
 * the root's own bits for turn_back. The chain's points (both ends), 0 when it does not
 * reach the root (cannot happen: a closed point's pointers lead to the root). */
static uint32_t turn_chain(rfs_plan_t *p, uint32_t g_idx, uint32_t *root_dir)
{
    uint8_t *w = p->work;
    const uint32_t lw = p->map->lw;
    const uint32_t n = lw * p->map->lh;
    uint32_t u = g_idx;
    uint32_t k = w[u] & W_DIR; /* from u to its parent */
    uint32_t pts = 1;
    while (u != p->tree_root && pts <= n) {
        uint32_t v = step_from(u, k, lw);
        uint32_t kv = w[v] & W_DIR;
        set_dir(w, v, (k + 4u) & 7u); /* v now points at its child u */
        u = v;
        k = kv;
        pts++;
    }
    *root_dir = k;
    return u == p->tree_root ? pts : 0u;
}

/* Undo turn_chain: each chain point's parent is the one before it again. */
static void turn_back(rfs_plan_t *p, uint32_t g_idx, uint32_t root_dir)
{
    uint8_t *w = p->work;
    const uint32_t lw = p->map->lw;
    uint32_t back = root_dir;
    for (uint32_t u = p->tree_root; u != g_idx;) {
        const uint32_t fwd = w[u] & W_DIR;
        set_dir(w, u, back);
        back = (fwd + 4u) & 7u;
        u = step_from(u, fwd, lw);
    }
    set_dir(w, g_idx, back);
}

/* The path from the tree's start (tree_from: the root, or a moved start's join point) to
 * the closed point g_idx, pulled, into out.
 *
 * The back-pointers lead from the goal to the root. Turn those of the chain round
 * (turn_chain), pull the path from the start forwards as rfs_plan_path does (from the
 * root: the chain; from another start: up its branch to the chain, then along it), and
 * turn them back, so the tree is unchanged for the next goal: no memory beyond the work
 * byte. */
static bool tree_extract(rfs_plan_t *p, uint32_t g_idx, rfs_q16_t x1, rfs_q16_t y1,
                         rfs_path_t *out)
{
    uint32_t root_dir;
    uint32_t pts = turn_chain(p, g_idx, &root_dir);
    if (pts == 0u) {
        return false;
    }
    if (p->tree_from != p->tree_root) {
        pts = path_points(p, p->tree_from, g_idx);
    }
    const bool ok = pts != 0u && pull_path(p->map, p->work, p->tree_from, pts, p->tree_x,
                                           p->tree_y, x1, y1, out, &p->pulled);
    turn_back(p, g_idx, root_dir);
    return ok;
}

/* Seed the begun tree at its root's join point: state 2, or 3 when it joins none. */
static void tree_seed(rfs_plan_t *p)
{
    if (p->tree != 1) {
        return;
    }
    if (!connect(p->map, p->tree_x, p->tree_y, true, &p->tree_root)) {
        p->tree = 3;
        return;
    }
    p->tree_from = p->tree_root;
    p->queue_peak = 0;
    seed(p, p->tree_root);
    p->tree = 2;
}

bool rfs_plan_tree_grow(rfs_plan_t *p, uint32_t budget)
{
    p->expanded = 0;
    if (p->tree == 0) {
        return false;
    }
    tree_seed(p);
    p->tree_sliced = true;
    if (p->tree == 2 && !p->tree_done) {
        if (p->tree_defer) {
            p->tree_owed = budget > UINT32_MAX - p->tree_owed ? UINT32_MAX : p->tree_owed + budget;
        } else {
            p->tree_done = search_until(p, NO_POINT, budget) == SEARCH_EMPTY;
        }
    }
    return p->tree != 2 || p->tree_done;
}

bool rfs_plan_tree_grown(rfs_plan_t *p)
{
    if (p->tree != 2) {
        return p->tree != 1;
    }
    if (!p->tree_done && p->tree_defer && p->tree_owed != 0u) {
        const uint32_t before = p->expanded;
        const search_end_t end = search_until(p, NO_POINT, p->tree_owed);
        p->tree_owed -= p->expanded - before;
        p->tree_done = end == SEARCH_EMPTY;
    }
    return p->tree_done;
}

bool rfs_plan_tree_move(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t max_hop)
{
    uint32_t idx;
    if (p->tree != 2 || !connect(p->map, x0, y0, true, &idx)) {
        return false;
    }
    tree_settle(p, idx);
    if (!(p->work[idx] & W_CLOSED)) {
        return false;
    }
    uint64_t straight = 0;
    uint64_t diagonal = 0;
    if (!walk_steps(p, idx, p->tree_root, &straight, &diagonal)) {
        return false;
    }
    rfs_q16_t jx;
    rfs_q16_t jy;
    point_of(p->map, idx, &jx, &jy);
    if ((uint64_t)rfs_q16_dist(x0, y0, jx, jy) + steps_length(p->map, straight, diagonal) >
        (uint64_t)(max_hop < 0 ? 0 : max_hop)) {
        return false;
    }
    p->tree_x = x0;
    p->tree_y = y0;
    p->tree_from = idx;
    return true;
}

/* The goal (x1, y1) on the tree: -1 no path (illegal, unreachable, not closed yet on a
 * sliced tree: tree_more), 1 in line of sight from the root's position, 0 its lattice
 * point *g_idx closed (searched for on a tree that is not sliced). */
static int tree_goal(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, uint32_t *g_idx)
{
    const rfs_map_t *m = p->map;
    p->expanded = 0;
    p->pulled = 0;
    if (p->tree == 0 || !rfs_map_point_legal(m, x1, y1)) {
        return -1;
    }
    if (rfs_map_segment_legal(m, p->tree_x, p->tree_y, x1, y1)) {
        return 1;
    }
    tree_seed(p);
    if (p->tree != 2) {
        return -1; /* the root joins no lattice point */
    }
    if (!near_component(p, x1, y1, p->component != 0 && component_bit(p->component, p->tree_root)) ||
        !connect(m, x1, y1, false, g_idx)) {
        return -1;
    }
    if (p->component != 0 &&
        component_bit(p->component, p->tree_root) != component_bit(p->component, *g_idx)) {
        return -1; /* different components: the search cannot succeed */
    }
    tree_settle(p, *g_idx);
    if (!(p->work[*g_idx] & W_CLOSED)) {
        if (p->tree_sliced) {
            p->tree_more = p->tree_more || !p->tree_done;
            return -1;
        }
        if (p->tree_done || search_until(p, *g_idx, UINT32_MAX) != SEARCH_FOUND) {
            return -1;
        }
    }
    return 0;
}

bool rfs_plan_tree_path(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, rfs_path_t *out)
{
    out->n = 0;
    out->length = 0;
    out->x0 = p->tree_x;
    out->y0 = p->tree_y;
    out->has_start = true;
    uint32_t g_idx = 0;
    const int at = tree_goal(p, x1, y1, &g_idx);
    if (at > 0) {
        out->x[0] = x1;
        out->y[0] = y1;
        out->n = 1;
        out->length = rfs_q16_dist(p->tree_x, p->tree_y, x1, y1);
    }
    return at == 0 ? tree_extract(p, g_idx, x1, y1, out) : at > 0;
}

bool rfs_plan_tree_length(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, rfs_q16_t *len)
{
    const rfs_map_t *m = p->map;
    uint32_t g_idx = 0;
    const int at = tree_goal(p, x1, y1, &g_idx);
    if (at != 0) {
        *len = at > 0 ? rfs_q16_dist(p->tree_x, p->tree_y, x1, y1) : 0;
        return at > 0;
    }
    /* The goal's chain up to the root, and a moved start's (short: within the move's
     * hop) also up to the root, not to where they meet: one walk, an upper bound of
     * tree_extract's lattice path by at most twice the start's. */
    uint64_t straight = 0;
    uint64_t diagonal = 0;
    bool ok = walk_steps(p, g_idx, p->tree_root, &straight, &diagonal);
    if (ok && p->tree_from != p->tree_root) {
        ok = walk_steps(p, p->tree_from, p->tree_root, &straight, &diagonal);
    }
    rfs_q16_t fx, fy, gx, gy;
    point_of(m, p->tree_from, &fx, &fy);
    point_of(m, g_idx, &gx, &gy);
    uint64_t l = (uint64_t)rfs_q16_dist(p->tree_x, p->tree_y, fx, fy) +
                 (uint64_t)rfs_q16_dist(gx, gy, x1, y1) + steps_length(m, straight, diagonal);
    *len = l > (uint64_t)INT32_MAX ? INT32_MAX : (rfs_q16_t)l;
    return ok;
}
