/* plan_world.h - the planner tests' world (test_plan.c, test_plan_tree.c): a 12 x 8 m map
 * of 0.1 m cells built from seeded wall strips or fixed layouts, its core map, and the
 * double-precision references: cell legality by brute-force geometry, segment legality,
 * Dijkstra over the lattice in double, its octile costs in integers and the connected
 * component of a point.
 *
 * The reference: the same lattice (points grid/2 + k*grid from the origin), 8-connected,
 * an edge exists when the straight segment is legal by the brute-force geometry below
 * (closed segment vs closed cell squares, cells legal when no non-free cell's square
 * comes closer than the clearance to theirs), edge cost the Euclidean length in double.
 */
#ifndef PLAN_WORLD_H
#define PLAN_WORLD_H

#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "rfs_plan.h"

#define W 120
#define H 80
#define STRIDE ((W + 7) / 8)
#define RES 6554 /* 0.1 m as the loader rounds it */
#define CLR RFS_Q16_FRAC(1, 4)

typedef struct world {
    int free_c[H][W];
    int legal_c[H][W];
    uint8_t free_bits[H * STRIDE];
    uint8_t legal_bits[H * STRIDE];
    rfs_map_t m;
} world_t;

static world_t wd;

static inline uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static inline int ref_free(int x, int y)
{
    return x >= 0 && y >= 0 && x < W && y < H && wd.free_c[y][x];
}

static inline void ref_legal_cells(void)
{
    double r = RES / 65536.0;
    double c = CLR / 65536.0;
    for (int cy = 0; cy < H; cy++) {
        for (int cx = 0; cx < W; cx++) {
            int ok = ref_free(cx, cy);
            for (int y = cy - 5; ok && y <= cy + 5; y++) {
                for (int x = cx - 5; ok && x <= cx + 5; x++) {
                    if (ref_free(x, y)) {
                        continue;
                    }
                    double ex = ref_cell_gap(x, cx) * r;
                    double ey = ref_cell_gap(y, cy) * r;
                    if (sqrt(ex * ex + ey * ey) < c) {
                        ok = 0;
                    }
                }
            }
            wd.legal_c[cy][cx] = ok;
        }
    }
}

/* Closed segment (Q16 units relative to the origin) vs closed cell square; exact. */
static inline int touch(double x0, double y0, double x1, double y1, int i, int j)
{
    return ref_touch(x0, y0, x1, y1, RES, i, j);
}

/* Reference segment legality for points given in Q16 map coordinates (origin 0). */
static inline int ref_seg(double x0, double y0, double x1, double y1)
{
    if (x0 < 0 || y0 < 0 || x1 < 0 || y1 < 0 || x0 >= W * (double)RES || x1 >= W * (double)RES ||
        y0 >= H * (double)RES || y1 >= H * (double)RES) {
        return 0;
    }
    int i0 = (int)floor(fmin(x0, x1) / RES) - 1, i1 = (int)floor(fmax(x0, x1) / RES) + 1;
    int j0 = (int)floor(fmin(y0, y1) / RES) - 1, j1 = (int)floor(fmax(y0, y1) / RES) + 1;
    for (int j = j0; j <= j1; j++) {
        for (int i = i0; i <= i1; i++) {
            if (touch(x0, y0, x1, y1, i, j)) {
                if (i < 0 || j < 0 || i >= W || j >= H || !wd.legal_c[j][i]) {
                    return 0;
                }
            }
        }
    }
    return 1;
}

static inline void build_finish(void);

static inline void build(uint32_t seed, int nrect, int enclose)
{
    memset(&wd, 0, sizeof(wd));
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            wd.free_c[y][x] = 1;
        }
    }
    for (int k = 0; k < nrect; k++) {
        int x0 = (int)(lcg(&seed) % W), y0 = (int)(lcg(&seed) % H);
        int horiz = (int)(lcg(&seed) & 1);
        int len = 10 + (int)(lcg(&seed) % 40);
        int th = 1 + (int)(lcg(&seed) % 3);
        for (int a = 0; a < len; a++) {
            for (int t = 0; t < th; t++) {
                int x = horiz ? x0 + a : x0 + t;
                int y = horiz ? y0 + t : y0 + a;
                if (x < W && y < H) {
                    wd.free_c[y][x] = 0;
                }
            }
        }
    }
    if (enclose) {
        /* A closed room: the square ring 80..100 x 20..40. */
        for (int a = 80; a <= 100; a++) {
            wd.free_c[20][a] = wd.free_c[40][a] = 0;
            wd.free_c[a - 60][80] = wd.free_c[a - 60][100] = 0;
        }
    }
    build_finish();
}

static inline void build_finish(void)
{
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            rfs_map_bit_set(wd.free_bits, STRIDE, (uint16_t)x, (uint16_t)y, wd.free_c[y][x]);
        }
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&wd.m, &cfg, W, H, RES, 0, 0, wd.free_bits, NULL, wd.legal_bits), 0);
    ref_legal_cells();
}

/* Reference Dijkstra over the lattice in double; returns the distance or INFINITY. With
 * gi < 0 it runs to the end: dist_ref then holds every point's distance (Q16 units). */
#define LMAX 4096
static double dist_ref[LMAX];
static int done_ref[LMAX];

static inline double ref_dijkstra(int lw, int lh, int si, int sj, int gi, int gj)
{
    double g = (double)wd.m.cfg.grid;
    for (int k = 0; k < lw * lh; k++) {
        dist_ref[k] = INFINITY;
        done_ref[k] = 0;
    }
    dist_ref[sj * lw + si] = 0;
    for (;;) {
        int u = -1;
        for (int k = 0; k < lw * lh; k++) {
            if (!done_ref[k] && (u < 0 || dist_ref[k] < dist_ref[u])) {
                u = k;
            }
        }
        if (u < 0 || isinf(dist_ref[u])) {
            return INFINITY;
        }
        if (gi >= 0 && u == gj * lw + gi) {
            return dist_ref[u] / 65536.0;
        }
        done_ref[u] = 1;
        int ui = u % lw, uj = u / lw;
        double ux = g / 2 + ui * g, uy = g / 2 + uj * g;
        for (int dj = -1; dj <= 1; dj++) {
            for (int di = -1; di <= 1; di++) {
                int vi = ui + di, vj = uj + dj;
                if ((di == 0 && dj == 0) || vi < 0 || vj < 0 || vi >= lw || vj >= lh) {
                    continue;
                }
                int v = vj * lw + vi;
                double c = dist_ref[u] + hypot(di * g, dj * g);
                if (done_ref[v] || c >= dist_ref[v]) {
                    continue;
                }
                if (ref_seg(ux, uy, g / 2 + vi * g, g / 2 + vj * g)) {
                    dist_ref[v] = c;
                }
            }
        }
    }
}

static uint8_t work[LMAX];
static uint32_t queue[1024];

static inline int legal_lattice(int i, int j)
{
    double g = (double)wd.m.cfg.grid;
    double x = g / 2 + i * g, y = g / 2 + j * g;
    return wd.legal_c[(int)floor(y / RES)][(int)floor(x / RES)];
}

/* A legal lattice point drawn uniformly (by rejection) from the seeded generator. */
static inline void random_legal(uint32_t *seed, int lw, int lh, int *i, int *j)
{
    do {
        *i = (int)(lcg(seed) % (uint32_t)lw);
        *j = (int)(lcg(seed) % (uint32_t)lh);
    } while (!legal_lattice(*i, *j));
}

/* Reference component (double precision), one bit per point as rfs_plan_set_component
 * takes it. */
static uint8_t comp_bits[LMAX / 8];

static inline int ref_step(void *ctx, int ui, int uj, int vi, int vj)
{
    (void)ctx;
    double g = (double)wd.m.cfg.grid;
    return legal_lattice(vi, vj) &&
           ref_seg(g / 2 + ui * g, g / 2 + uj * g, g / 2 + vi * g, g / 2 + vj * g);
}

static inline void ref_component(int lw, int lh, int si, int sj)
{
    ref_flood(lw, lh, si, sj, ref_step, NULL, comp_bits);
}

/* Maps for the search-tree tests: 0 random walls (14 strips), 1 the same with the closed
 * room, 2 speckled (about 0.4 % of the cells single obstacles), 3 rooms (walls at x = 4 m
 * and 8 m and y = 4 m, each stretch with a 1 m door at random), 4 the wall map (one wall
 * along y = 4 m from the west edge, the way round a 1.5 m gap at the east end). */
static inline void build_kind(int kind, uint32_t seed)
{
    if (kind <= 1) {
        build(seed * 7919u, 14, kind);
        return;
    }
    memset(&wd, 0, sizeof(wd));
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            wd.free_c[y][x] = kind != 2 || lcg(&seed) % 1000u >= 4u;
        }
    }
    if (kind == 3) {
        for (int a = 0; a < H; a++) {
            wd.free_c[a][40] = wd.free_c[a][80] = 0;
        }
        for (int a = 0; a < W; a++) {
            wd.free_c[40][a] = 0;
        }
        /* Doors: two per vertical wall (below and above y = 4 m), three in the other. */
        for (int k = 0; k < 2; k++) {
            for (int h = 0; h < 2; h++) {
                int y0 = h * 40 + 2 + (int)(lcg(&seed) % 26u);
                for (int t = 0; t < 10; t++) {
                    wd.free_c[y0 + t][40 + 40 * k] = 1;
                }
            }
        }
        for (int k = 0; k < 3; k++) {
            int x0 = k * 40 + 2 + (int)(lcg(&seed) % 26u);
            for (int t = 0; t < 10; t++) {
                wd.free_c[40][x0 + t] = 1;
            }
        }
    } else if (kind == 4) {
        for (int a = 0; a < W - 15; a++) {
            wd.free_c[40][a] = wd.free_c[41][a] = 0;
        }
    }
    build_finish();
}

/* Independent reference of the planner's own lattice costs: Dijkstra in integers with
 * straight steps 2 and diagonal steps 3 over the reference's edges (ref_step). */
static int oct_ref[LMAX];

static inline void ref_octile(int lw, int lh, int si, int sj)
{
    static int done[LMAX];
    for (int k = 0; k < lw * lh; k++) {
        oct_ref[k] = INT32_MAX;
        done[k] = 0;
    }
    oct_ref[sj * lw + si] = 0;
    for (;;) {
        int u = -1;
        for (int k = 0; k < lw * lh; k++) {
            if (!done[k] && oct_ref[k] < INT32_MAX && (u < 0 || oct_ref[k] < oct_ref[u])) {
                u = k;
            }
        }
        if (u < 0) {
            return;
        }
        done[u] = 1;
        int ui = u % lw, uj = u / lw;
        for (int dj = -1; dj <= 1; dj++) {
            for (int di = -1; di <= 1; di++) {
                int vi = ui + di, vj = uj + dj;
                if ((di == 0 && dj == 0) || vi < 0 || vj < 0 || vi >= lw || vj >= lh) {
                    continue;
                }
                int v = vj * lw + vi, c = oct_ref[u] + (di != 0 && dj != 0 ? 3 : 2);
                if (!done[v] && c < oct_ref[v] && ref_step(NULL, ui, uj, vi, vj)) {
                    oct_ref[v] = c;
                }
            }
        }
    }
}

/* Reference points of octile cost below / at most c (c INT32_MAX: every reachable one). */
static inline void oct_count(int n, int c, int *below, int *upto)
{
    *below = *upto = 0;
    for (int k = 0; k < n; k++) {
        *below += oct_ref[k] < c || (c == INT32_MAX && oct_ref[k] < INT32_MAX);
        *upto += oct_ref[k] <= c && oct_ref[k] < INT32_MAX;
    }
}

/* The length of path from (x0, y0) (Q16 map units), metres, each segment asserted legal by
 * the reference geometry. */
static inline double ref_path_len(double x0, double y0, const rfs_path_t *path)
{
    double len = 0, px = x0, py = y0;
    for (int w = 0; w < path->n; w++) {
        assert_true(ref_seg(px, py, path->x[w], path->y[w]));
        len += hypot(path->x[w] - px, path->y[w] - py) / 65536.0;
        px = path->x[w];
        py = path->y[w];
    }
    return len;
}

static inline void assert_same_path(const rfs_path_t *a, const rfs_path_t *b)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->length, b->length);
    assert_memory_equal(a->x, b->x, a->n * sizeof(a->x[0]));
    assert_memory_equal(a->y, b->y, a->n * sizeof(a->y[0]));
}

#endif
