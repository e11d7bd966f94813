/* hs_paths.c - shortest paths on the core's legal grid (see hs_paths.h). */
#include "hs_paths.h"

#include <math.h>
#include <stdlib.h>

#include "rfs_plan.h"
#include "rfs_reach.h"

// --- can the core's planner get into the stop radius? --------------------------------
// The cell-level distances below connect legal cells through gaps one cell wide; the
// controller plans on the 0.25 m lattice, whose edges need a legal straight segment
// between lattice points, so a door that narrow is shut for it. The start's component of
// the lattice (rfs_reach_fill) lets a plan to a point beyond a wall fail at once, without
// flooding the start's side (rfs_plan_set_component: the answers stay the same).
int hs_paths_lattice_reaches(const rfs_map_t *m, double sx, double sy, double gx, double gy,
                             double radius)
{
    uint32_t n = (uint32_t)m->lw * m->lh;
    uint8_t *work = malloc(n ? n : 1);
    uint32_t *queue = malloc(sizeof(uint32_t) * (n ? n : 1));
    uint8_t *reach = calloc(rfs_reach_bytes(m) + 1u, 1);
    rfs_path_t *path = malloc(sizeof *path);
    rfs_plan_t plan;
    int found = -1;
    if (work && queue && reach && path && rfs_plan_init(&plan, m, work, n, queue, n) == 0) {
        found = 0;
        rfs_plan_use_edges(&plan); /* the map's edge table, if the caller attached one */
        // The queue is the flood's work memory before it is the planner's.
        if (rfs_reach_fill(m, (rfs_q16_t)lround(sx * 65536.0), (rfs_q16_t)lround(sy * 65536.0),
                           reach, queue, n ? n : 1)) {
            rfs_plan_set_component(&plan, reach);
        }
        double g = m->cfg.grid / 65536.0;
        long r = (long)ceil(radius / g) + 1;
        uint16_t ci, cj;
        rfs_map_lattice_nearest(m, (rfs_q16_t)lround(gx * 65536.0), (rfs_q16_t)lround(gy * 65536.0),
                                &ci, &cj);
        for (long j = (long)cj - r; j <= (long)cj + r && !found; j++) {
            for (long i = (long)ci - r; i <= (long)ci + r && !found; i++) {
                if (i < 0 || j < 0 || i >= m->lw || j >= m->lh ||
                    !rfs_map_lattice_legal(m, (uint16_t)i, (uint16_t)j)) {
                    continue;
                }
                rfs_q16_t px, py;
                rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
                if (hypot(px / 65536.0 - gx, py / 65536.0 - gy) > radius) {
                    continue;
                }
                found = rfs_plan_path(&plan, (rfs_q16_t)lround(sx * 65536.0),
                                      (rfs_q16_t)lround(sy * 65536.0), px, py, path) ? 1 : 0;
            }
        }
    }
    free(work);
    free(queue);
    free(reach);
    free(path);
    return found;
}

// --- shortest path on the core's legal grid -----------------------------------------

typedef struct heap_item {
    double d;
    uint32_t i;
} heap_item_t;

typedef struct heap {
    heap_item_t *a;
    size_t n, cap;
} heap_t;

static int heap_push(heap_t *h, double d, uint32_t i)
{
    if (h->n == h->cap) {
        size_t nc = h->cap ? h->cap * 2 : 1024;
        heap_item_t *na = realloc(h->a, nc * sizeof *na);
        if (!na) {
            return -1;
        }
        h->a = na;
        h->cap = nc;
    }
    size_t k = h->n++;
    while (k > 0 && h->a[(k - 1) / 2].d > d) {
        h->a[k] = h->a[(k - 1) / 2];
        k = (k - 1) / 2;
    }
    h->a[k] = (heap_item_t){d, i};
    return 0;
}

static heap_item_t heap_pop(heap_t *h)
{
    heap_item_t top = h->a[0], last = h->a[--h->n];
    size_t k = 0;
    for (;;) {
        size_t c = 2 * k + 1;
        if (c >= h->n) {
            break;
        }
        if (c + 1 < h->n && h->a[c + 1].d < h->a[c].d) {
            c++;
        }
        if (h->a[c].d >= last.d) {
            break;
        }
        h->a[k] = h->a[c];
        k = c;
    }
    if (h->n > 0) {
        h->a[k] = last;
    }
    return top;
}

static bool legal_cell(const rfs_map_t *m, long x, long y)
{
    return x >= 0 && y >= 0 && x < m->w && y < m->h &&
           rfs_map_bit(m->legal, m->stride, (uint16_t)x, (uint16_t)y);
}

/* Dijkstra over legal cells, 16-connected (hs_paths.h). */
int hs_paths_dist(const rfs_map_t *m, long sx, long sy, double *dist)
{
    static const int mv[16][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1},
                                  {-1, -1}, {2, 1}, {2, -1}, {-2, 1}, {-2, -1}, {1, 2},
                                  {1, -2}, {-1, 2}, {-1, -2}};
    size_t n = (size_t)m->w * m->h;
    double res = m->res / 65536.0;
    for (size_t i = 0; i < n; i++) {
        dist[i] = INFINITY;
    }
    if (!legal_cell(m, sx, sy)) {
        return 0;
    }
    heap_t h = {0};
    dist[(size_t)sy * m->w + sx] = 0.0;
    if (heap_push(&h, 0.0, (uint32_t)(sy * m->w + sx)) != 0) {
        return -1;
    }
    while (h.n > 0) {
        heap_item_t it = heap_pop(&h);
        if (it.d > dist[it.i]) {
            continue;
        }
        long x = it.i % m->w, y = it.i / m->w;
        for (int k = 0; k < 16; k++) {
            int dx = mv[k][0], dy = mv[k][1];
            long nx = x + dx, ny = y + dy;
            if (!legal_cell(m, nx, ny)) {
                continue;
            }
            // Cells the move passes through: both neighbours of a diagonal (no corner
            // cutting), the two cells beside the midpoint of a knight move.
            if (abs(dx) == 1 && abs(dy) == 1 &&
                (!legal_cell(m, x + dx, y) || !legal_cell(m, x, y + dy))) {
                continue;
            }
            if (abs(dx) == 2 && (!legal_cell(m, x + dx / 2, y) || !legal_cell(m, x + dx / 2, y + dy))) {
                continue;
            }
            if (abs(dy) == 2 && (!legal_cell(m, x, y + dy / 2) || !legal_cell(m, x + dx, y + dy / 2))) {
                continue;
            }
            double nd = it.d + res * sqrt((double)(dx * dx + dy * dy));
            size_t ni = (size_t)ny * m->w + (size_t)nx;
            if (nd < dist[ni]) {
                dist[ni] = nd;
                if (heap_push(&h, nd, (uint32_t)ni) != 0) {
                    free(h.a);
                    return -1;
                }
            }
        }
    }
    free(h.a);
    return 0;
}


bool hs_paths_cell(const rfs_map_t *m, double x0, double y0, double x, double y, long *cx,
                   long *cy)
{
    double res = m->res / 65536.0;
    double fx = (x - x0) / res, fy = (y - y0) / res;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < m->w && fy < m->h)) {
        return false;
    }
    *cx = (long)fx;
    *cy = (long)fy;
    return true;
}

void hs_paths_goal(const rfs_map_t *m, double x0, double y0, const double *dist, double gx,
                   double gy, double stop_radius, double reach, hs_paths_goal_t *out)
{
    double res = m->res / 65536.0;
    long xa = 0, ya = 0, xb = (long)m->w - 1, yb = (long)m->h - 1;
    if (reach >= 0.0) {
        // Cells whose centres can lie in the box, one more each side for rounding.
        xa = lround(floor((gx - reach - x0) / res - 0.5)) - 1;
        xb = lround(ceil((gx + reach - x0) / res - 0.5)) + 1;
        ya = lround(floor((gy - reach - y0) / res - 0.5)) - 1;
        yb = lround(ceil((gy + reach - y0) / res - 0.5)) + 1;
        xa = xa < 0 ? 0 : xa;
        ya = ya < 0 ? 0 : ya;
        xb = xb >= (long)m->w ? (long)m->w - 1 : xb;
        yb = yb >= (long)m->h ? (long)m->h - 1 : yb;
    }
    out->near_m = INFINITY;
    out->path_m = INFINITY;
    out->stop_m = INFINITY;
    for (long y = ya; y <= yb; y++) {
        for (long x = xa; x <= xb; x++) {
            double d = dist[(size_t)y * m->w + x];
            if (!isfinite(d)) {
                continue;
            }
            double dx = x0 + (x + 0.5) * res - gx;
            double dy = y0 + (y + 0.5) * res - gy;
            double gd = sqrt(dx * dx + dy * dy);
            // Nearest first; among cells as near (to 1 nm), the shortest path.
            if (gd < out->near_m - 1e-9 || (fabs(gd - out->near_m) <= 1e-9 && d < out->path_m)) {
                out->near_m = gd;
                out->path_m = d;
            }
            if (gd <= stop_radius && d < out->stop_m) {
                out->stop_m = d;
            }
        }
    }
}
