/* test_map_walls.c - rfs_map_walls_crossed() against an independent double-precision
 * geometry in the test (docs/MAPS.md, "The core's grids"): walls crossed = runs of wall
 * cells among the cells the closed segment touches, ordered by entry time; with the wall
 * blocks, the wall-distance and the forward grids attached, and against a 64-bit copy of
 * the column walk in every octant.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "map_fixture.h"
#include "ref_geom.h"
#include "rfs_map.h"

/* Entry parameter t of the closed square (Liang-Barsky). */
static double ref_entry(double x0, double y0, double x1, double y1, double bx0, double bx1,
                        double by0, double by1)
{
    double t0 = 0.0;
    double p[4] = {-(x1 - x0), x1 - x0, -(y1 - y0), y1 - y0};
    double q[4] = {x0 - bx0, bx1 - x0, y0 - by0, by1 - y0};
    for (int k = 0; k < 4; k++) {
        if (p[k] < 0) {
            double t = q[k] / p[k];
            if (t > t0) {
                t0 = t;
            }
        }
    }
    return t0;
}

typedef struct hit {
    double t;
    int wall;
} hit_t;

static int cmp_hit(const void *a, const void *b)
{
    double d = ((const hit_t *)a)->t - ((const hit_t *)b)->t;
    return d < 0 ? -1 : d > 0;
}

static int ref_walls(const fixture_t *f, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1)
{
    static hit_t hits[(W + 2) * (H + 2)];
    int n = 0;
    double X0 = (double)x0 - f->ox;
    double Y0 = (double)y0 - f->oy;
    double X1 = (double)x1 - f->ox;
    double Y1 = (double)y1 - f->oy;
    double r = f->res;
    for (int j = 0; j < H; j++) {
        for (int i = 0; i < W; i++) {
            if (ref_touch(X0, Y0, X1, Y1, f->res, i, j)) {
                hits[n].t = ref_entry(X0, Y0, X1, Y1, i * r, (i + 1) * r, j * r, (j + 1) * r);
                hits[n].wall = f->wall_c[j][i];
                n++;
            }
        }
    }
    qsort(hits, (size_t)n, sizeof(hits[0]), cmp_hit);
    int runs = 0;
    int in = 0;
    for (int k = 0; k < n; k++) {
        if (hits[k].wall && !in) {
            runs++;
        }
        in = hits[k].wall;
    }
    return runs;
}

static fixture_t fx;

/* Segment k of a wall-count sweep on fixture f: one in three random, the others between
 * cell corners (one in three of those along a row or column of them, one in nine on a
 * diagonal through corners, some off the map). */
static void draw_segment(uint32_t *s, const fixture_t *f, int k, rfs_q16_t *x0, rfs_q16_t *y0,
                         rfs_q16_t *x1, rfs_q16_t *y1)
{
    if (k % 3 == 0) {
        *x0 = rand_coord(s, f->ox, W, f->res);
        *y0 = rand_coord(s, f->oy, H, f->res);
        *x1 = rand_coord(s, f->ox, W, f->res);
        *y1 = rand_coord(s, f->oy, H, f->res);
        return;
    }
    int i0 = (int)(lcg(s) % (W + 5)) - 2, j0 = (int)(lcg(s) % (H + 5)) - 2;
    int i1 = (int)(lcg(s) % (W + 5)) - 2, j1 = (int)(lcg(s) % (H + 5)) - 2;
    if (k % 9 == 1) {
        j1 = j0 + (i1 - i0) * ((k & 2) ? 1 : -1);
    } else if (k % 3 == 1) {
        if (k & 4) { i1 = i0; } else { j1 = j0; }
    }
    *x0 = f->ox + i0 * f->res;
    *y0 = f->oy + j0 * f->res;
    *x1 = f->ox + i1 * f->res;
    *y1 = f->oy + j1 * f->res;
}

/* Walls crossed: runs of wall cells along random segments, against the reference, and
 * a hand-made case: two separate walls between the points. */
static void test_walls_crossed(void **state)
{
    (void)state;
    uint32_t s = 3;
    int nonzero = 0;
    for (int mapk = 0; mapk < 2; mapk++) {
        make_map(&fx, 200u + (uint32_t)mapk, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
        for (int k = 0; k < 600; k++) {
            rfs_q16_t x0 = rand_coord(&s, fx.ox, W, fx.res);
            rfs_q16_t y0 = rand_coord(&s, fx.oy, H, fx.res);
            rfs_q16_t x1 = rand_coord(&s, fx.ox, W, fx.res);
            rfs_q16_t y1 = rand_coord(&s, fx.oy, H, fx.res);
            int want = ref_walls(&fx, x0, y0, x1, y1);
            assert_int_equal(rfs_map_walls_crossed(&fx.m, x0, y0, x1, y1), want);
            nonzero += want > 0;
        }
    }
    assert_true(nonzero > 50);

    bits_t *b = all_free();
    uint16_t stride = (W + 7) / 8;
    for (int y = 0; y < H; y++) {
        /* Two walls: x = 10..11 (two cells thick, one run) and x = 30. */
        rfs_map_bit_set(b->wall, stride, 10, (uint16_t)y, true);
        rfs_map_bit_set(b->wall, stride, 11, (uint16_t)y, true);
        rfs_map_bit_set(b->wall, stride, 30, (uint16_t)y, true);
    }
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    const rfs_q16_t r = RFS_Q16_FRAC(1, 10);
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, r, 0, 0, b->free, b->wall, b->legal), 0);
    assert_int_equal(rfs_map_walls_crossed(&m, 5 * r, 5 * r, 40 * r, 20 * r), 2);
    assert_int_equal(rfs_map_walls_crossed(&m, 40 * r, 20 * r, 5 * r, 5 * r), 2);
    assert_int_equal(rfs_map_walls_crossed(&m, 5 * r, 5 * r, 20 * r, 20 * r), 1);
    assert_int_equal(rfs_map_walls_crossed(&m, 13 * r, 5 * r, 28 * r, 30 * r), 0);
    /* Endpoints far off the map are clamped: still both walls. */
    assert_int_equal(rfs_map_walls_crossed(&m, -RFS_Q16_INT(100), 5 * r, RFS_Q16_INT(100), 5 * r), 2);
}

typedef struct cell_hit {
    int i, j, wall;
} cell_hit_t;

static int cmp_cell(const void *a, const void *b)
{
    const cell_hit_t *p = a, *q = b;
    return p->i != q->i ? (p->i > q->i) - (p->i < q->i) : (p->j > q->j) - (p->j < q->j);
}

/* Walls crossed by the definition (docs/MAPS.md): endpoints clamped onto the map's edge,
 * every closed cell square the segment touches (those just off the map are not walls),
 * taken from the end with the smaller x (then y) column by column, each column in the
 * direction the segment runs in y; a run is consecutive wall cells. Unlike ref_walls it
 * orders the cells a segment touches at one instant (through a corner, along an edge). */
static int ref_walls_in_order(const fixture_t *f, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                              rfs_q16_t y1)
{
    static cell_hit_t hits[(W + 2) * (H + 2)];
    double r = f->res;
    double X0 = fmin(fmax((double)x0 - f->ox, 0.0), W * r), Y0 = fmin(fmax((double)y0 - f->oy, 0.0), H * r);
    double X1 = fmin(fmax((double)x1 - f->ox, 0.0), W * r), Y1 = fmin(fmax((double)y1 - f->oy, 0.0), H * r);
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        double t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    int up = Y1 >= Y0;
    int n = 0;
    for (int j = -1; j <= H; j++) {
        for (int i = -1; i <= W; i++) {
            if (ref_touch(X0, Y0, X1, Y1, f->res, i, j)) {
                int on = i >= 0 && j >= 0 && i < W && j < H;
                hits[n].i = i;
                hits[n].j = up ? j : -j;
                hits[n].wall = on && f->wall_c[j][i];
                n++;
            }
        }
    }
    qsort(hits, (size_t)n, sizeof(hits[0]), cmp_cell);
    int runs = 0, in = 0;
    for (int k = 0; k < n; k++) {
        runs += hits[k].wall && !in;
        in = hits[k].wall;
    }
    return runs;
}

/* Wall counts passing over wall-free blocks (rfs_map_walls_crossed_blocks) equal the
 * reference on maps whose walls leave whole blocks empty, for blocks of 8, 16 and
 * 32 cells, on random segments, on segments between cell corners (axis-parallel and
 * diagonal ones run along cell edges) and with endpoints off the map, against
 * ref_walls_in_order; the block grid marks exactly the blocks holding a wall cell. */
static void test_walls_crossed_blocks(void **state)
{
    (void)state;
    uint32_t s = 5;
    int nonzero = 0;
    const uint32_t bytes[3] = {64, 4, 2}; /* blocks of 8 (6 x 5), 16 (3 x 3), 32 (2 x 2) */
    for (int mapk = 0; mapk < 6; mapk++) {
        make_map(&fx, 300u + (uint32_t)mapk, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
        uint16_t stride = (W + 7) / 8;
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                /* blocks of 8 on a diagonal band keep their walls, the rest are empty */
                fx.wall_c[y][x] = fx.wall_c[y][x] && ((x / 8 + y / 8 + mapk) % 3 == 0);
                rfs_map_bit_set(fx.wall_bits, stride, (uint16_t)x, (uint16_t)y, fx.wall_c[y][x]);
            }
        }
        rfs_map_cfg_t cfg = rfs_map_cfg_default();
        assert_int_equal(rfs_map_init(&fx.m, &cfg, W, H, fx.res, fx.ox, fx.oy, fx.free_bits,
                                      fx.wall_bits, fx.legal_bits), 0);
        for (int bk = 0; bk < 3; bk++) {
            uint8_t buf[64];
            rfs_map_wall_blocks_t b;
            assert_int_equal(rfs_map_wall_blocks(&fx.m, buf, bytes[bk], &b), 0);
            assert_int_equal(b.shift, 3 + bk);
            for (int bj = 0; bj < b.bh; bj++) {
                for (int bi = 0; bi < b.bw; bi++) {
                    int any = 0;
                    for (int y = bj << b.shift; y < ((bj + 1) << b.shift) && y < H; y++) {
                        for (int x = bi << b.shift; x < ((bi + 1) << b.shift) && x < W; x++) {
                            any |= fx.wall_c[y][x];
                        }
                    }
                    assert_int_equal(rfs_map_bit(b.bits, b.stride, (uint16_t)bi, (uint16_t)bj), any);
                }
            }
            for (int k = 0; k < 900; k++) {
                rfs_q16_t x0, y0, x1, y1;
                draw_segment(&s, &fx, k, &x0, &y0, &x1, &y1);
                int want = ref_walls_in_order(&fx, x0, y0, x1, y1);
                assert_int_equal(rfs_map_walls_crossed_blocks(&fx.m, &b, x0, y0, x1, y1), want);
                assert_int_equal(rfs_map_walls_crossed(&fx.m, x0, y0, x1, y1), want);
                nonzero += want > 0;
            }
        }
    }
    assert_true(nonzero > 1000);
    uint8_t buf[8];
    rfs_map_wall_blocks_t b;
    assert_int_equal(rfs_map_wall_blocks(&fx.m, buf, 0, &b), -1);
    rfs_map_t nowall = fx.m;
    nowall.wall = NULL;
    assert_int_equal(rfs_map_wall_blocks(&nowall, buf, sizeof buf, &b), -1);
}

/* A wall-distance grid (rfs_map_wall_dist_attach) holds each cell's Chebyshev distance to
 * the nearest wall cell (brute force here), and wall counts passing over the free squares
 * it promises equal ref_walls_in_order, with or without blocks passed in: on maps with
 * walls scattered, thinned to a few, and none, for random segments, segments between cell
 * corners (along rows, columns and diagonals of them) and ends off the map. */
static void test_walls_crossed_wall_dist(void **state)
{
    (void)state;
    uint32_t s = 11;
    int nonzero = 0;
    static uint8_t dist[H * W];
    for (int mapk = 0; mapk < 6; mapk++) {
        make_map(&fx, 500u + (uint32_t)mapk, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
        uint16_t stride = (W + 7) / 8;
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                /* 0, 1: as drawn; 2, 3: every seventh wall cell; 4: one cell; 5: none */
                int keep = mapk < 2 || (mapk < 4 && (x * 5 + y * 3) % 7 == 0) ||
                           (mapk == 4 && x == W / 2 && y == H / 3);
                fx.wall_c[y][x] = fx.wall_c[y][x] && keep;
                if (mapk == 4) {
                    fx.wall_c[y][x] = keep;
                }
                rfs_map_bit_set(fx.wall_bits, stride, (uint16_t)x, (uint16_t)y, fx.wall_c[y][x]);
            }
        }
        rfs_map_cfg_t cfg = rfs_map_cfg_default();
        assert_int_equal(rfs_map_init(&fx.m, &cfg, W, H, fx.res, fx.ox, fx.oy, fx.free_bits,
                                      fx.wall_bits, fx.legal_bits), 0);
        assert_int_equal(rfs_map_wall_dist_bytes(&fx.m), W * H);
        assert_int_equal(rfs_map_wall_dist_attach(&fx.m, dist, W * H - 1), -1);
        assert_null(fx.m.wall_dist);
        assert_int_equal(rfs_map_wall_dist_attach(&fx.m, dist, W * H), 0);
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                int best = 255;
                for (int v = 0; v < H; v++) {
                    for (int u = 0; u < W; u++) {
                        int d = abs(u - x) > abs(v - y) ? abs(u - x) : abs(v - y);
                        best = fx.wall_c[v][u] && d < best ? d : best;
                    }
                }
                assert_int_equal(dist[y * W + x], best);
            }
        }
        uint8_t buf[64];
        rfs_map_wall_blocks_t b;
        assert_int_equal(rfs_map_wall_blocks(&fx.m, buf, sizeof buf, &b), 0);
        for (int k = 0; k < 1500; k++) {
            rfs_q16_t x0, y0, x1, y1;
            draw_segment(&s, &fx, k, &x0, &y0, &x1, &y1);
            int want = ref_walls_in_order(&fx, x0, y0, x1, y1);
            assert_int_equal(rfs_map_walls_crossed(&fx.m, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed_blocks(&fx.m, &b, x0, y0, x1, y1), want);
            nonzero += want > 0;
        }
    }
    assert_true(nonzero > 1000);
    rfs_map_t nowall = fx.m;
    nowall.wall = NULL;
    assert_int_equal(rfs_map_wall_dist_attach(&nowall, dist, sizeof dist), -1);
    assert_int_equal(rfs_map_wall_dist_attach(&fx.m, NULL, sizeof dist), -1);
}

/* A forward grid (rfs_map_wall_fwd_attach) holds each cell's largest wall-free square
 * ahead towards +x and +y, and +x and -y (brute force here), and wall counts passing over
 * those squares equal ref_walls_in_order and the plain walk's, alone and with the
 * wall-distance grid, the column grid (rfs_map_wall_cols_attach) or blocks beside it: on
 * maps with walls scattered, in rows with gaps, thinned, one cell and none, for random
 * segments, shallow ones, steep ones through cell corners, segments between cell corners
 * and ends off the map. */
static void test_walls_crossed_wall_fwd(void **state)
{
    (void)state;
    uint32_t s = 23;
    int nonzero = 0;
    static uint8_t fwd[2 * H * W];
    static uint8_t dist[H * W];
    static uint8_t cols[2 * W * ((H + 7) / 8 + 4)];
    for (int mapk = 0; mapk < 7; mapk++) {
        make_map(&fx, 700u + (uint32_t)mapk, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
        uint16_t stride = (W + 7) / 8;
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                /* 0, 1: as drawn; 2: rows of wall with gaps; 3, 4: every seventh wall cell;
                 * 5: one cell; 6: none */
                int keep = mapk < 2 || (mapk < 5 && (x * 5 + y * 3) % 7 == 0) ||
                           (mapk == 5 && x == W / 2 && y == H / 3);
                fx.wall_c[y][x] = fx.wall_c[y][x] && keep;
                if (mapk == 2) {
                    fx.wall_c[y][x] = y % 4 == 1 && (x * 7 + y) % 11 > 2;
                }
                if (mapk == 5) {
                    fx.wall_c[y][x] = keep;
                }
                rfs_map_bit_set(fx.wall_bits, stride, (uint16_t)x, (uint16_t)y, fx.wall_c[y][x]);
            }
        }
        rfs_map_cfg_t cfg = rfs_map_cfg_default();
        assert_int_equal(rfs_map_init(&fx.m, &cfg, W, H, fx.res, fx.ox, fx.oy, fx.free_bits,
                                      fx.wall_bits, fx.legal_bits), 0);
        rfs_map_t plain = fx.m;
        assert_int_equal(rfs_map_wall_fwd_bytes(&fx.m), 2 * W * H);
        assert_int_equal(rfs_map_wall_fwd_attach(&fx.m, fwd, 2 * W * H - 1), -1);
        assert_null(fx.m.wall_fwd);
        assert_int_equal(rfs_map_wall_fwd_attach(&fx.m, fwd, 2 * W * H), 0);
        for (int dir = 0; dir < 2; dir++) {
            for (int y = 0; y < H; y++) {
                for (int x = 0; x < W; x++) {
                    int side = 0; /* grow the square while it stays on the map and free */
                    for (int free = 1; free; ) {
                        int n = side + 1;
                        int y1 = dir == 0 ? y + n - 1 : y - n + 1;
                        free = x + n <= W && y1 >= 0 && y1 < H;
                        for (int v = 0; free && v < n; v++) {
                            for (int u = 0; free && u < n; u++) {
                                free = !fx.wall_c[dir == 0 ? y + v : y - v][x + u];
                            }
                        }
                        side += free;
                    }
                    assert_int_equal(fwd[dir * W * H + y * W + x], side);
                }
            }
        }
        rfs_map_t with_dist = fx.m;
        assert_int_equal(rfs_map_wall_dist_attach(&with_dist, dist, W * H), 0);
        /* The column grid beside the forward grid, and beside the wall-distance grid: bit
         * j of column i is cell (i, j), and of the top-down half cell (i, H - 1 - j). */
        rfs_map_t with_cols = fx.m, dist_cols = with_dist;
        const uint32_t cs = (H + 7) / 8 + 4;
        assert_int_equal(rfs_map_wall_cols_bytes(&fx.m), 2 * W * cs);
        assert_int_equal(rfs_map_wall_cols_attach(&with_cols, cols, 2 * W * cs - 1), -1);
        assert_null(with_cols.wall_cols);
        assert_int_equal(rfs_map_wall_cols_attach(&with_cols, cols, 2 * W * cs), 0);
        assert_int_equal(rfs_map_wall_cols_attach(&dist_cols, cols, 2 * W * cs), 0);
        for (int x = 0; x < W; x++) {
            for (int y = 0; y < H; y++) {
                assert_int_equal((cols[x * cs + y / 8] >> (y % 8)) & 1, fx.wall_c[y][x]);
                assert_int_equal((cols[(W + x) * cs + y / 8] >> (y % 8)) & 1,
                                 fx.wall_c[H - 1 - y][x]);
            }
        }
        uint8_t buf[64];
        rfs_map_wall_blocks_t b;
        assert_int_equal(rfs_map_wall_blocks(&fx.m, buf, sizeof buf, &b), 0);
        for (int k = 0; k < 3000; k++) {
            rfs_q16_t x0, y0, x1, y1;
            draw_segment(&s, &fx, k, &x0, &y0, &x1, &y1);
            if (k % 6 == 5) { /* shallow: within a few rows over the width */
                y1 = y0 + (rfs_q16_t)((int32_t)(lcg(&s) % 8u) - 4) * fx.res / 3;
            } else if (k % 6 == 4) { /* steep through cell corners: slope +-2, +-3 */
                int32_t d = (int32_t)(lcg(&s) % 17u) - 8, sl = 2 + (int32_t)(lcg(&s) % 2u);
                x1 = x0 + d * fx.res;
                y1 = y0 + ((k & 8) ? sl : -sl) * d * fx.res;
            }
            int want = ref_walls_in_order(&fx, x0, y0, x1, y1);
            assert_int_equal(rfs_map_walls_crossed(&plain, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed(&fx.m, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed(&with_dist, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed(&with_cols, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed(&dist_cols, x0, y0, x1, y1), want);
            assert_int_equal(rfs_map_walls_crossed_blocks(&fx.m, &b, x0, y0, x1, y1), want);
            nonzero += want > 0;
        }
    }
    assert_true(nonzero > 3000);
    rfs_map_t nowall = fx.m;
    nowall.wall = NULL;
    assert_int_equal(rfs_map_wall_fwd_attach(&nowall, fwd, 2 * W * H), -1);
    assert_int_equal(rfs_map_wall_fwd_attach(&fx.m, NULL, 2 * W * H), -1);
    assert_int_equal(rfs_map_wall_cols_attach(&nowall, cols, sizeof cols), -1);
    assert_int_equal(rfs_map_wall_cols_attach(&fx.m, NULL, sizeof cols), -1);
    /* A map of 2^31 cells or more: two bytes a cell exceed 32 bits; the size saturates and
     * no 32-bit buffer size is enough (the check runs before the grid is touched). */
    rfs_map_t big = fx.m;
    big.w = 65535u;
    big.h = 32769u;
    big.wall_fwd = NULL;
    assert_int_equal(rfs_map_wall_fwd_bytes(&big), UINT32_MAX);
    assert_int_equal(rfs_map_wall_fwd_attach(&big, fwd, UINT32_MAX), -1);
    assert_null(big.wall_fwd);
}

/* The host grids (forward, wall-distance, column grid, alone and together) on maps of
 * every shape, widths and heights not multiples of 8 among them (partial last bytes of
 * rows and of the column grid's columns), 1 to 70 cells a side, each grid in a heap
 * buffer of exactly its size (ASan: no read past any): every count equals the plain
 * walk's, the Cortex-M4's, for random segments, segments between cell corners, steep and
 * shallow ones, ends on and off the map. */
static void test_walls_crossed_host_grids_any_size(void **state)
{
    (void)state;
    uint32_t s = 91;
    int nonzero = 0;
    for (int mapk = 0; mapk < 60; mapk++) {
        const uint32_t w = 1u + lcg(&s) % 70u, h = 1u + lcg(&s) % 70u;
        const uint32_t stride = (w + 7u) / 8u, cells = h * stride;
        const rfs_q16_t res = mapk % 2 ? RFS_Q16_FRAC(1, 10) : RFS_Q16_FRAC(1, 20);
        uint8_t *fr = malloc(cells), *wl = malloc(cells), *lg = malloc(cells);
        assert_non_null(fr);
        assert_non_null(wl);
        assert_non_null(lg);
        memset(wl, 0, cells);
        memset(fr, 0xFF, cells);
        const uint32_t dens = (uint32_t)mapk % 5u; /* none, sparse .. half the cells */
        for (uint32_t j = 0; j < h; j++) {
            for (uint32_t i = 0; i < w; i++) {
                const bool wall = dens != 0u && lcg(&s) % (12u - 2u * dens) == 0u;
                rfs_map_bit_set(wl, (uint16_t)stride, (uint16_t)i, (uint16_t)j, wall);
                rfs_map_bit_set(fr, (uint16_t)stride, (uint16_t)i, (uint16_t)j, !wall);
            }
        }
        rfs_map_cfg_t cfg = rfs_map_cfg_default();
        cfg.clearance = 0;
        cfg.grid = res;
        rfs_map_t plain;
        const rfs_q16_t ox = RFS_Q16_INT(3), oy = -RFS_Q16_INT(2);
        assert_int_equal(rfs_map_init(&plain, &cfg, (uint16_t)w, (uint16_t)h, res, ox, oy, fr,
                                      wl, lg), 0);
        const uint32_t nf = rfs_map_wall_fwd_bytes(&plain), nd = rfs_map_wall_dist_bytes(&plain);
        const uint32_t nc = rfs_map_wall_cols_bytes(&plain);
        uint8_t *fwd = malloc(nf), *dist = malloc(nd), *cols = malloc(nc);
        assert_non_null(fwd);
        assert_non_null(dist);
        assert_non_null(cols);
        rfs_map_t v[6] = {plain, plain, plain, plain, plain, plain};
        assert_int_equal(rfs_map_wall_fwd_attach(&v[0], fwd, nf), 0);  /* fwd */
        assert_int_equal(rfs_map_wall_dist_attach(&v[1], dist, nd), 0); /* dist */
        v[2] = v[0];
        assert_int_equal(rfs_map_wall_cols_attach(&v[2], cols, nc), 0); /* fwd + cols */
        v[3] = v[1];
        v[3].wall_cols = v[2].wall_cols;                                 /* dist + cols */
        v[4] = v[0];
        v[4].wall_dist = v[1].wall_dist;                                 /* fwd + dist */
        v[5] = v[4];
        v[5].wall_cols = v[2].wall_cols;                                 /* all three */
        const int64_t we = (int64_t)w * res, he = (int64_t)h * res;
        for (int k = 0; k < 400; k++) {
            int64_t x0, y0, x1, y1;
            const int kind = k % 4;
            if (kind == 0) { /* anywhere, ends up to a map's size off it */
                x0 = (int64_t)(lcg(&s) % (uint32_t)(3 * we + 1)) - we;
                y0 = (int64_t)(lcg(&s) % (uint32_t)(3 * he + 1)) - he;
                x1 = (int64_t)(lcg(&s) % (uint32_t)(3 * we + 1)) - we;
                y1 = (int64_t)(lcg(&s) % (uint32_t)(3 * he + 1)) - he;
            } else if (kind == 1) { /* cell corners, the map's edges among them */
                x0 = (int64_t)(lcg(&s) % (w + 1u)) * res;
                y0 = (int64_t)(lcg(&s) % (h + 1u)) * res;
                x1 = (int64_t)(lcg(&s) % (w + 1u)) * res;
                y1 = (int64_t)(lcg(&s) % (h + 1u)) * res;
            } else { /* inside: steep (kind 2) or shallow (kind 3), a few cells across */
                x0 = 1 + (int64_t)(lcg(&s) % (uint32_t)(we - 1 > 0 ? we - 1 : 1));
                y0 = 1 + (int64_t)(lcg(&s) % (uint32_t)(he - 1 > 0 ? he - 1 : 1));
                x1 = 1 + (int64_t)(lcg(&s) % (uint32_t)(we - 1 > 0 ? we - 1 : 1));
                y1 = 1 + (int64_t)(lcg(&s) % (uint32_t)(he - 1 > 0 ? he - 1 : 1));
                if (kind == 2) {
                    x1 = x0 + (int64_t)(lcg(&s) % (uint32_t)(3 * res)) - res;
                } else {
                    y1 = y0 + (int64_t)(lcg(&s) % (uint32_t)(3 * res)) - res;
                }
            }
            const rfs_q16_t X0 = (rfs_q16_t)(x0 + ox), Y0 = (rfs_q16_t)(y0 + oy);
            const rfs_q16_t X1 = (rfs_q16_t)(x1 + ox), Y1 = (rfs_q16_t)(y1 + oy);
            const uint16_t want = rfs_map_walls_crossed(&plain, X0, Y0, X1, Y1);
            for (int q = 0; q < 6; q++) {
                assert_int_equal(rfs_map_walls_crossed(&v[q], X0, Y0, X1, Y1), want);
            }
            nonzero += want > 0u;
        }
        free(fwd);
        free(dist);
        free(cols);
        free(fr);
        free(wl);
        free(lg);
    }
    assert_true(nonzero > 4000);
}

/* floor(a / r), r > 0. */
static int64_t floor_div(int64_t a, int64_t r)
{
    return a >= 0 ? a / r : -((-a + r - 1) / r);
}

/* traverse() of rfs_map.c with a run counter, written out again: the 64-bit column walk
 * (y(x) dx against row bounds) the wall count used to run, for more segments than
 * ref_walls_in_order's brute force affords. Endpoints clamped onto the map's edge; cells
 * off the map are not walls. */
static int ref_walk64(const fixture_t *f, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1)
{
    const int64_t r = f->res;
    int64_t X0 = (int64_t)x0 - f->ox, Y0 = (int64_t)y0 - f->oy;
    int64_t X1 = (int64_t)x1 - f->ox, Y1 = (int64_t)y1 - f->oy;
    X0 = X0 < 0 ? 0 : (X0 > W * r ? W * r : X0);
    X1 = X1 < 0 ? 0 : (X1 > W * r ? W * r : X1);
    Y0 = Y0 < 0 ? 0 : (Y0 > H * r ? H * r : Y0);
    Y1 = Y1 < 0 ? 0 : (Y1 > H * r ? H * r : Y1);
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        int64_t t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    const int flip = Y1 < Y0;
    if (flip) {
        Y0 = -Y0;
        Y1 = -Y1;
    }
    const int64_t dx = X1 - X0, dy = Y1 - Y0;
    const int64_t ia = -floor_div(-X0, r) - 1, ib = floor_div(X1, r);
    int64_t jlo = -floor_div(-Y0, r) - 1, jhi = jlo;
    int64_t blo = (jlo + 1) * r * dx, bhi = blo;
    int runs = 0, in = 0;
    for (int64_t i = ia; i <= ib; i++) {
        if (dx == 0) {
            jhi = floor_div(Y1, r);
        } else {
            const int64_t xl = i * r < X0 ? X0 : i * r, xr = (i + 1) * r > X1 ? X1 : (i + 1) * r;
            const int64_t nl = Y0 * dx + (xl - X0) * dy, nr = Y0 * dx + (xr - X0) * dy;
            for (; blo < nl; blo += r * dx) {
                jlo++;
            }
            if (jhi < jlo) {
                jhi = jlo;
                bhi = blo;
            }
            for (; bhi <= nr; bhi += r * dx) {
                jhi++;
            }
        }
        for (int64_t j = jlo; j <= jhi; j++) {
            const int64_t jr = flip ? -1 - j : j;
            const int wall = i >= 0 && i < W && jr >= 0 && jr < H && f->wall_c[jr][i];
            runs += wall && !in;
            in = wall;
        }
    }
    return runs;
}

/* The map of f again at resolution res (lattice spacing res, no clearance): resolutions
 * far from the core's 0.1 m. */
static void remap(fixture_t *f, rfs_q16_t res)
{
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = 0;
    cfg.grid = res;
    f->res = res;
    assert_int_equal(rfs_map_init(&f->m, &cfg, W, H, res, f->ox, f->oy, f->free_bits,
                                  f->wall_bits, f->legal_bits), 0);
}

/* Wall counts in every octant and both directions equal the 64-bit column walk
 * (ref_walk64, itself checked against ref_walls_in_order on every tenth segment), with no
 * grid, blocks, the wall-distance grid, the forward grid, both, and forward grid with
 * blocks: at 0.1 m, 1.5 m (above 2^16 Q16 units a cell) and 7 Q16 units a cell; on maps
 * of rectangles and of scattered cells; for random segments, segments between cell
 * corners at slopes p / q (p, q <= 7: through corners every q columns), along cell edges
 * (rows and columns of corners), nearly flat ones (dy of a few Q16 units: long rows of
 * bits), ones ending on the map's edge and ones far off it. */
static void test_walls_crossed_octants(void **state)
{
    (void)state;
    static uint8_t dist[H * W], fwd[2 * H * W];
    const rfs_q16_t res[3] = {RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(3, 2), 7};
    uint32_t s = 29;
    int checked = 0, nonzero = 0;
    for (int mapk = 0; mapk < 6; mapk++) {
        make_map(&fx, 900u + (uint32_t)mapk, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
        if (mapk % 2 == 1) { /* scattered: every cell a wall with odds 3 in 10 */
            for (int y = 0; y < H; y++) {
                for (int x = 0; x < W; x++) {
                    fx.wall_c[y][x] = lcg(&s) % 10u < 3u;
                    rfs_map_bit_set(fx.wall_bits, (W + 7) / 8, (uint16_t)x, (uint16_t)y,
                                    fx.wall_c[y][x]);
                }
            }
        }
        remap(&fx, res[mapk / 2]);
        const rfs_q16_t r = fx.res;
        rfs_map_t m[5] = {fx.m, fx.m, fx.m, fx.m, fx.m}; /* none, dist, fwd, both, fwd */
        assert_int_equal(rfs_map_wall_dist_attach(&m[1], dist, sizeof dist), 0);
        assert_int_equal(rfs_map_wall_fwd_attach(&m[2], fwd, sizeof fwd), 0);
        m[3] = m[2];
        m[3].wall_dist = m[1].wall_dist;
        m[4] = m[2];
        uint8_t buf[64];
        rfs_map_wall_blocks_t b;
        assert_int_equal(rfs_map_wall_blocks(&fx.m, buf, sizeof buf, &b), 0);
        for (int k = 0; k < 3000; k++) {
            const int kind = k % 6;
            int32_t i0 = (int32_t)(lcg(&s) % (W + 7)) - 3, j0 = (int32_t)(lcg(&s) % (H + 7)) - 3;
            int64_t X0 = (int64_t)i0 * r, Y0 = (int64_t)j0 * r, X1, Y1;
            if (kind == 0) { /* anywhere, ends up to 3 cells off the map */
                X0 += lcg(&s) % (uint32_t)r;
                Y0 += lcg(&s) % (uint32_t)r;
                X1 = (int64_t)(lcg(&s) % (uint32_t)((W + 6) * r)) - 3 * r;
                Y1 = (int64_t)(lcg(&s) % (uint32_t)((H + 6) * r)) - 3 * r;
            } else if (kind <= 2) { /* corner to corner at slope +-p / q or +-q / p */
                const int32_t p = 1 + (int32_t)(lcg(&s) % 7u), q = 1 + (int32_t)(lcg(&s) % 7u);
                const int32_t t = 1 + (int32_t)(lcg(&s) % 12u), sx = (k & 8) ? -1 : 1;
                const int32_t sy = (k & 16) ? -1 : 1;
                X1 = X0 + (int64_t)sx * (kind == 1 ? q : p) * t * r;
                Y1 = Y0 + (int64_t)sy * (kind == 1 ? p : q) * t * r;
                if (k & 32) { /* from inside a cell, through corners all the same */
                    X0 -= (k & 64) ? r / 3 * sx * (kind == 1 ? q : p) : 0;
                    Y0 -= (k & 64) ? r / 3 * sy * (kind == 1 ? p : q) : 0;
                }
            } else if (kind == 3) { /* along a row or column of cell edges */
                X1 = (int64_t)((int32_t)(lcg(&s) % (W + 7)) - 3) * r;
                Y1 = (int64_t)((int32_t)(lcg(&s) % (H + 7)) - 3) * r;
                if (k & 8) { X1 = X0; } else { Y1 = Y0; }
            } else if (kind == 4) { /* nearly flat or nearly upright: dy or dx a few units */
                X0 += lcg(&s) % (uint32_t)r;
                Y0 += lcg(&s) % (uint32_t)r;
                const int64_t d = (int64_t)(lcg(&s) % 9u) - 4, len = (int64_t)(lcg(&s) % (W + 6)) * r;
                X1 = (k & 8) ? X0 + d : X0 + ((k & 16) ? len : -len);
                Y1 = (k & 8) ? Y0 + ((k & 16) ? len : -len) : Y0 + d;
            } else { /* from the map's edge, or far off it */
                X1 = (int64_t)(lcg(&s) % (uint32_t)(W * r));
                Y1 = (int64_t)(lcg(&s) % (uint32_t)(H * r));
                X0 = (k & 8) ? ((k & 16) ? W * r : 0) : ((k & 16) ? 1000 * r : -1000 * r);
                Y0 = (k & 32) ? (int64_t)(lcg(&s) % (uint32_t)(H * r)) : ((k & 16) ? H * r : 0);
            }
            const rfs_q16_t x0 = (rfs_q16_t)(fx.ox + X0), y0 = (rfs_q16_t)(fx.oy + Y0);
            const rfs_q16_t x1 = (rfs_q16_t)(fx.ox + X1), y1 = (rfs_q16_t)(fx.oy + Y1);
            const int want = ref_walk64(&fx, x0, y0, x1, y1);
            if (k % 10 == 0) {
                assert_int_equal(ref_walls_in_order(&fx, x0, y0, x1, y1), want);
                checked++;
            }
            for (int dir = 0; dir < 2; dir++) {
                const rfs_q16_t a = dir ? x1 : x0, c = dir ? y1 : y0;
                const rfs_q16_t e = dir ? x0 : x1, g = dir ? y0 : y1;
                for (int v = 0; v < 4; v++) {
                    assert_int_equal(rfs_map_walls_crossed(&m[v], a, c, e, g), want);
                }
                assert_int_equal(rfs_map_walls_crossed_blocks(&fx.m, &b, a, c, e, g), want);
                assert_int_equal(rfs_map_walls_crossed_blocks(&m[4], &b, a, c, e, g), want);
            }
            nonzero += want > 0;
        }
    }
    assert_true(checked == 1800 && nonzero > 6000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walls_crossed),
        cmocka_unit_test(test_walls_crossed_blocks),
        cmocka_unit_test(test_walls_crossed_wall_dist),
        cmocka_unit_test(test_walls_crossed_wall_fwd),
        cmocka_unit_test(test_walls_crossed_host_grids_any_size),
        cmocka_unit_test(test_walls_crossed_octants),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
