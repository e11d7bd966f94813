/* test_map.c - rfs_map against an independent double-precision geometry in the test.
 *
 * Reference rules (docs/MAPS.md), computed here by brute force in double:
 *  - a cell is legal when no non-free or off-map cell's square comes closer than the
 *    clearance to its square (the cell itself always counts);
 *  - a segment touches a cell when the closed segment and the closed square intersect
 *    (separating-axis test on the x, y and segment-normal axes, exact in double because
 *    coordinates are Q16 integers below 2^21).
 * Wall counts: test_map_walls.c.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "map_fixture.h"
#include "ref_geom.h"
#include "rfs_map.h"

static int ref_free(const fixture_t *f, int x, int y)
{
    return x >= 0 && y >= 0 && x < W && y < H && f->free_c[y][x];
}

/* Reference cell legality by brute force over every cell near the map. */
static int ref_cell_legal(const fixture_t *f, int cx, int cy)
{
    double r = f->res / 65536.0;
    double c = f->clr / 65536.0;
    if (!ref_free(f, cx, cy)) {
        return 0;
    }
    for (int y = -8; y < H + 8; y++) {
        for (int x = -8; x < W + 8; x++) {
            if (ref_free(f, x, y)) {
                continue;
            }
            double ex = ref_cell_gap(x, cx) * r;
            double ey = ref_cell_gap(y, cy) * r;
            if (sqrt(ex * ex + ey * ey) < c) {
                return 0;
            }
        }
    }
    return 1;
}

static int ref_legal_cell_grid(const fixture_t *f, int x, int y)
{
    if (x < 0 || y < 0 || x >= W || y >= H) {
        return 0;
    }
    return ref_cell_legal(f, x, y);
}

static int legal_cache[H][W];

static int ref_segment_legal(const fixture_t *f, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                             rfs_q16_t y1)
{
    double X0 = (double)x0 - f->ox;
    double Y0 = (double)y0 - f->oy;
    double X1 = (double)x1 - f->ox;
    double Y1 = (double)y1 - f->oy;
    double r = f->res;
    if (X0 < 0 || Y0 < 0 || X1 < 0 || Y1 < 0 || X0 >= W * r || X1 >= W * r || Y0 >= H * r ||
        Y1 >= H * r) {
        return 0;
    }
    for (int j = -1; j <= H; j++) {
        for (int i = -1; i <= W; i++) {
            if (ref_touch(X0, Y0, X1, Y1, f->res, i, j)) {
                int l = (i >= 0 && j >= 0 && i < W && j < H) ? legal_cache[j][i] : 0;
                if (!l) {
                    return 0;
                }
            }
        }
    }
    return 1;
}

static void fill_cache(const fixture_t *f)
{
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            legal_cache[y][x] = ref_cell_legal(f, x, y);
        }
    }
}

static fixture_t fx;

/* The derived legal grid equals the brute-force reference, for three resolutions. */
static void test_legal_grid_matches_reference(void **state)
{
    (void)state;
    const rfs_q16_t resolutions[3] = {RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 20), RFS_Q16_FRAC(1, 4)};
    const rfs_q16_t clearances[3] = {RFS_Q16_FRAC(1, 4), RFS_Q16_FRAC(1, 4), RFS_Q16_FRAC(3, 5)};
    for (int k = 0; k < 3; k++) {
        make_map(&fx, 11u + (uint32_t)k, resolutions[k], clearances[k]);
        fill_cache(&fx);
        int legal = 0;
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                assert_int_equal(rfs_map_bit(fx.legal_bits, fx.m.stride, (uint16_t)x, (uint16_t)y),
                                 legal_cache[y][x]);
                legal += legal_cache[y][x];
            }
        }
        /* The maps are mostly free: the test exercises both outcomes. */
        assert_true(legal > 100 && legal < W * H - 100);
    }
}

/* Map edges: with everything free, the border cells within the clearance are illegal. */
static void test_map_edges(void **state)
{
    (void)state;
    bits_t *b = all_free();
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    /* res 0.1 as the loader rounds it (Q16 6554 = 0.100006 m), clearance 0.25 m: cell k's
     * square is k * 0.100006 m from the edge, so cells 0, 1 and 2 of each border are
     * illegal and cell 3 is legal. */
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, 6554, 0, 0, b->free, NULL, b->legal), 0);
    for (int x = 0; x < W; x++) {
        for (int y = 0; y < H; y++) {
            int inside = x >= 3 && y >= 3 && x < W - 3 && y < H - 3;
            assert_int_equal(rfs_map_bit(b->legal, m.stride, (uint16_t)x, (uint16_t)y), inside);
        }
    }
    /* Points: on the map and legal; just off the map: illegal. */
    assert_true(rfs_map_point_legal(&m, RFS_Q16_FRAC(5, 2), RFS_Q16_FRAC(5, 2)));
    assert_false(rfs_map_point_legal(&m, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(5, 2)));
    assert_false(rfs_map_point_legal(&m, -1, RFS_Q16_FRAC(5, 2)));
    assert_false(rfs_map_point_legal(&m, RFS_Q16_INT(100), RFS_Q16_FRAC(5, 2)));
    /* Walls crossed with no wall grid is 0. */
    assert_int_equal(rfs_map_walls_crossed(&m, 0, 0, RFS_Q16_INT(4), RFS_Q16_INT(3)), 0);
}

/* An unknown cell (not free) makes its surroundings illegal like a wall. */
static void test_unknown_cell(void **state)
{
    (void)state;
    bits_t *b = all_free();
    uint16_t stride = (W + 7) / 8;
    rfs_map_bit_set(b->free, stride, 20, 20, false);
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    /* res 0.25 exactly, clearance 0.25: the cell's own 8 neighbours touch its square;
     * the next ring is exactly 0.25 m away, not closer. */
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, RFS_Q16_FRAC(1, 4), 0, 0, b->free, NULL, b->legal),
                     0);
    for (int y = 15; y <= 25; y++) {
        for (int x = 15; x <= 25; x++) {
            int near = abs(x - 20) <= 1 && abs(y - 20) <= 1;
            assert_int_equal(rfs_map_bit(b->legal, m.stride, (uint16_t)x, (uint16_t)y), !near);
        }
    }
}

/* Point legality, random points, against the reference. */
static void test_points_match_reference(void **state)
{
    (void)state;
    make_map(&fx, 5u, RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 4));
    fill_cache(&fx);
    uint32_t s = 99;
    for (int k = 0; k < 5000; k++) {
        rfs_q16_t x = fx.ox - fx.res + (rfs_q16_t)(lcg(&s) % (uint32_t)((W + 2) * fx.res));
        rfs_q16_t y = fx.oy - fx.res + (rfs_q16_t)(lcg(&s) % (uint32_t)((H + 2) * fx.res));
        double rx = ((double)x - fx.ox) / fx.res;
        double ry = ((double)y - fx.oy) / fx.res;
        int cx = (int)floor(rx);
        int cy = (int)floor(ry);
        assert_int_equal(rfs_map_point_legal(&fx.m, x, y), ref_legal_cell_grid(&fx, cx, cy));
    }
}

/* Segment legality, random segments of all lengths, against the reference. */
static void test_segments_match_reference(void **state)
{
    (void)state;
    uint32_t s = 7;
    int legal = 0;
    int total = 0;
    for (int mapk = 0; mapk < 3; mapk++) {
        make_map(&fx, 100u + (uint32_t)mapk, mapk == 1 ? RFS_Q16_FRAC(1, 4) : RFS_Q16_FRAC(1, 10),
                 RFS_Q16_FRAC(1, 4));
        fill_cache(&fx);
        for (int k = 0; k < 1500; k++) {
            rfs_q16_t x0 = rand_coord(&s, fx.ox, W, fx.res);
            rfs_q16_t y0 = rand_coord(&s, fx.oy, H, fx.res);
            int len = (int)(lcg(&s) % 4);
            int span = len == 0 ? 2 : (len == 1 ? 8 : (len == 2 ? 20 : W));
            rfs_q16_t x1 = x0 + (rfs_q16_t)((int32_t)(lcg(&s) % (uint32_t)(2 * span * fx.res)) - span * fx.res);
            rfs_q16_t y1 = y0 + (rfs_q16_t)((int32_t)(lcg(&s) % (uint32_t)(2 * span * fx.res)) - span * fx.res);
            if (k % 10 == 0) {
                y1 = y0; /* horizontal */
            } else if (k % 10 == 1) {
                x1 = x0; /* vertical */
            } else if (k % 10 == 2) {
                /* exact diagonal through cell corners: start on a corner */
                x0 = fx.ox + (rfs_q16_t)(lcg(&s) % W) * fx.res;
                y0 = fx.oy + (rfs_q16_t)(lcg(&s) % H) * fx.res;
                int d = (int)(lcg(&s) % 10) - 5;
                x1 = x0 + d * fx.res;
                y1 = y0 + ((k & 1) ? d : -d) * fx.res;
            }
            int want = ref_segment_legal(&fx, x0, y0, x1, y1);
            int got = rfs_map_segment_legal(&fx.m, x0, y0, x1, y1);
            if (got != want) {
                print_error("segment (%d,%d)-(%d,%d) map %d: got %d want %d\n", x0, y0, x1, y1, mapk, got, want);
            }
            assert_int_equal(got, want);
            legal += want;
            total++;
        }
    }
    assert_true(legal > total / 10 && legal < total - total / 10);
}

/* Segments grazing a corner: closed squares, so touching a corner is passing through. */
static void test_segment_grazing_corner(void **state)
{
    (void)state;
    bits_t *b = all_free();
    uint16_t stride = (W + 7) / 8;
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = 0; /* legal = free: the geometry is the cells themselves */
    const rfs_q16_t r = RFS_Q16_FRAC(1, 4);
    rfs_map_bit_set(b->free, stride, 10, 10, false);
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, r, 0, 0, b->free, NULL, b->legal), 0);
    /* The line x + y = 20r touches cell (10, 10) = [10r, 11r]^2 only at its corner. */
    assert_false(rfs_map_segment_legal(&m, 9 * r, 11 * r, 11 * r, 9 * r));
    /* One Q16 step lower-left, it misses the cell. */
    assert_true(rfs_map_segment_legal(&m, 9 * r - 1, 11 * r - 1, 11 * r - 1, 9 * r - 1));
    /* Along the cell's bottom edge y = 10r: touches it. One step below: clear. */
    assert_false(rfs_map_segment_legal(&m, 5 * r, 10 * r, 15 * r, 10 * r));
    assert_true(rfs_map_segment_legal(&m, 5 * r, 10 * r - 1, 15 * r, 10 * r - 1));
    /* Between two diagonal obstacles through their shared corner: blocked. */
    rfs_map_bit_set(b->free, stride, 10, 10, true);
    rfs_map_bit_set(b->free, stride, 21, 20, false);
    rfs_map_bit_set(b->free, stride, 20, 21, false);
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, r, 0, 0, b->free, NULL, b->legal), 0);
    assert_false(rfs_map_segment_legal(&m, 20 * r + r / 2, 20 * r + r / 2, 21 * r + r / 2,
                                       21 * r + r / 2));
    /* The same move through a corner of four free cells: clear. */
    assert_true(rfs_map_segment_legal(&m, 10 * r + r / 2, 20 * r + r / 2, 11 * r + r / 2,
                                      21 * r + r / 2));
    /* Ending on the left edge of obstacle (20, 21) touches it. */
    assert_false(rfs_map_segment_legal(&m, 18 * r, 20 * r, 20 * r, 22 * r - r / 2));
}

/* Along one axis, lattice lines at o + g/2 + k g (k < n; o Q16.16, g metres): is line idx
 * as near to p (Q16.16) as the nearest of all n, by brute force in double? */
static int nearest_on_axis(rfs_q16_t p, rfs_q16_t o, double g, int n, int idx)
{
    double best = 1e30;
    for (int k = 0; k < n; k++) {
        best = fmin(best, fabs(((double)p - o) / 65536.0 - (g / 2 + k * g)));
    }
    return fabs(((double)p - o) / 65536.0 - (g / 2 + idx * g)) <= best + 1e-9;
}

/* Lattice: counts, positions and nearest points from the definitions in double. */
static void test_lattice(void **state)
{
    (void)state;
    bits_t *b = all_free();
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    const rfs_q16_t r = RFS_Q16_FRAC(1, 10);
    const rfs_q16_t ox = -RFS_Q16_INT(3) - 12345;
    const rfs_q16_t oy = RFS_Q16_INT(7) + 999;
    assert_int_equal(rfs_map_init(&m, &cfg, W, H, r, ox, oy, b->free, NULL, b->legal), 0);
    double g = cfg.grid / 65536.0;
    /* Points at g/2 + i*g strictly inside W*r and H*r metres. */
    int lw = 0;
    while (g / 2 + lw * g < W * (r / 65536.0)) {
        lw++;
    }
    int lh = 0;
    while (g / 2 + lh * g < H * (r / 65536.0)) {
        lh++;
    }
    assert_int_equal(m.lw, lw);
    assert_int_equal(m.lh, lh);
    rfs_q16_t x;
    rfs_q16_t y;
    rfs_map_lattice_point(&m, 3, 5, &x, &y);
    assert_int_equal(x, ox + cfg.grid / 2 + 3 * cfg.grid);
    assert_int_equal(y, oy + cfg.grid / 2 + 5 * cfg.grid);
    uint32_t s = 1;
    for (int k = 0; k < 2000; k++) {
        rfs_q16_t px = ox - RFS_Q16_INT(1) + (rfs_q16_t)(lcg(&s) % (uint32_t)RFS_Q16_INT(7));
        rfs_q16_t py = oy - RFS_Q16_INT(1) + (rfs_q16_t)(lcg(&s) % (uint32_t)RFS_Q16_INT(6));
        uint16_t i;
        uint16_t j;
        rfs_map_lattice_nearest(&m, px, py, &i, &j);
        /* Reference: the nearest of all lattice points by brute force (ties are
         * measure-zero for random Q16 points; accept either side of a tie). */
        assert_true(nearest_on_axis(px, ox, g, lw, i));
        assert_true(nearest_on_axis(py, oy, g, lh, j));
    }
    /* Lattice legality = legality of the point; off the lattice is illegal. */
    rfs_map_lattice_point(&m, 0, 0, &x, &y);
    assert_int_equal(rfs_map_lattice_legal(&m, 0, 0), rfs_map_point_legal(&m, x, y));
    assert_true(rfs_map_lattice_legal(&m, 5, 5));
    assert_false(rfs_map_lattice_legal(&m, (uint16_t)lw, 0));
}

/* rfs_map_lattice_edges against the brute-force geometry: bit k set exactly when the
 * neighbour towards k is on the lattice, its point's cell legal and the segment to it
 * legal; the same with an edge table attached (filled, then read back), with the lattice
 * memo, with step patterns (0.0625 m and 0.125 m cells) and without (0.1 m). */
static void test_lattice_edges(void **state)
{
    (void)state;
    static const int dx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
    static const int dy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
    const rfs_q16_t resolutions[3] = {RFS_Q16_FRAC(1, 10), RFS_Q16_FRAC(1, 16), RFS_Q16_FRAC(1, 8)};
    static uint16_t table[W * H];
    static uint16_t memo[W * H];
    int set = 0, clear = 0;
    for (int k = 0; k < 3; k++) {
        make_map(&fx, 41u + (uint32_t)k, resolutions[k], RFS_Q16_FRAC(1, 4));
        fill_cache(&fx);
        const int lw = fx.m.lw, lh = fx.m.lh;
        const int64_t g = fx.m.cfg.grid;
        assert_true(lw * lh <= W * H);
        assert_int_equal(fx.m.step_n, k == 0 ? 0 : 4 / k);
        assert_int_equal(rfs_map_edges_attach(&fx.m, NULL, W * H), -1);
        assert_int_equal(rfs_map_edges_attach(&fx.m, table, (uint32_t)(lw * lh - 1)), -1);
        for (int pass = 0; pass < 4; pass++) {
            if (pass == 1) {
                assert_int_equal(rfs_map_edges_attach(&fx.m, table, W * H), 0);
            } else if (pass == 3) {
                assert_int_equal(rfs_map_memo_attach(&fx.m, memo, W * H), 0);
                assert_int_equal(rfs_map_edges_attach(&fx.m, table, W * H), 0);
            }
            for (int j = 0; j < lh; j++) {
                for (int i = 0; i < lw; i++) {
                    const rfs_q16_t x0 = (rfs_q16_t)(fx.ox + g / 2 + i * g);
                    const rfs_q16_t y0 = (rfs_q16_t)(fx.oy + g / 2 + j * g);
                    int want = 0;
                    for (int d = 0; d < 8; d++) {
                        const int ti = i + dx[d], tj = j + dy[d];
                        if (ti < 0 || tj < 0 || ti >= lw || tj >= lh) {
                            continue;
                        }
                        const int64_t ux = g / 2 + ti * g, uy = g / 2 + tj * g;
                        const rfs_q16_t x1 = (rfs_q16_t)(fx.ox + ux), y1 = (rfs_q16_t)(fx.oy + uy);
                        if (legal_cache[uy / fx.res][ux / fx.res] &&
                            ref_segment_legal(&fx, x0, y0, x1, y1)) {
                            want |= 1 << d;
                        }
                    }
                    assert_int_equal(rfs_map_lattice_edges(&fx.m, (uint16_t)i, (uint16_t)j), want);
                    if (pass == 0) {
                        set += __builtin_popcount((unsigned)want);
                        clear += 8 - __builtin_popcount((unsigned)want);
                    }
                }
            }
        }
        assert_int_equal(rfs_map_lattice_edges(&fx.m, (uint16_t)lw, 0), 0);
        assert_int_equal(rfs_map_lattice_edges(&fx.m, 0, (uint16_t)lh), 0);
    }
    print_message("lattice edges: %d legal, %d not\n", set, clear);
    assert_true(set > 1000 && clear > 500);
}

/* init rejects bad configurations. */
static void test_init_rejects(void **state)
{
    (void)state;
    static uint8_t fb[64];
    static uint8_t lb[64];
    rfs_map_t m;
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    const rfs_q16_t r = RFS_Q16_FRAC(1, 10);
    assert_int_equal(rfs_map_init(&m, &cfg, 0, 8, r, 0, 0, fb, NULL, lb), -1);
    assert_int_equal(rfs_map_init(&m, &cfg, 8, 8, 0, 0, 0, fb, NULL, lb), -1);
    assert_int_equal(rfs_map_init(&m, &cfg, 8, 8, r, 0, 0, NULL, NULL, lb), -1);
    assert_int_equal(rfs_map_init(&m, &cfg, 8, 8, r, 0, 0, fb, NULL, NULL), -1);
    /* A map wider than 16384 m. */
    assert_int_equal(rfs_map_init(&m, &cfg, 60000, 1, RFS_Q16_INT(1), 0, 0, fb, NULL, lb), -1);
    rfs_map_cfg_t bad = cfg;
    bad.clearance = -1;
    assert_int_equal(rfs_map_init(&m, &bad, 8, 8, r, 0, 0, fb, NULL, lb), -1);
    bad = cfg;
    bad.grid = 0;
    assert_int_equal(rfs_map_init(&m, &bad, 8, 8, r, 0, 0, fb, NULL, lb), -1);
    assert_int_equal(rfs_map_init(&m, &cfg, 8, 8, r, 0, 0, fb, NULL, lb), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_legal_grid_matches_reference),
        cmocka_unit_test(test_map_edges),
        cmocka_unit_test(test_unknown_cell),
        cmocka_unit_test(test_points_match_reference),
        cmocka_unit_test(test_segments_match_reference),
        cmocka_unit_test(test_segment_grazing_corner),
        cmocka_unit_test(test_lattice),
        cmocka_unit_test(test_lattice_edges),
        cmocka_unit_test(test_init_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
