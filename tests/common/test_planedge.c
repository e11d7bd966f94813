/* test_planedge.c - the planner's cheap lattice edge test (rfs_map_lattice_step_legal)
 * against the exact traversal (rfs_map_segment_legal) and the planner with it against
 * the planner with the traversal on every edge (rfs_plan_t.exact_edges).
 *
 * Maps are built here with walls at random (rectangles and single cells) at the grid /
 * res ratios the project uses: a 0.25 m lattice over 0.125 m cells (the firmware bench
 * map: lattice points on cell corners), 0.1 m cells (host simulator default, as the loader
 * rounds it: 6554) and 0.05 m cells (3277), plus whole ratios 1 to 6 with lattice points
 * at cell centres, corners and in between, and clearance 0 so legal cells reach the map
 * edge. The recorded step cells are also checked against double-precision geometry
 * (closed segment against closed cell square), independent of the traversal.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "rfs_plan.h"

#define WMAX 240
#define HMAX 160
#define STRIDE_MAX ((WMAX + 7) / 8)
#define LMAX (WMAX * HMAX)
#define QCAP 16384

typedef struct map_case {
    const char *name;
    rfs_q16_t res;       /* metres per cell, Q16.16 */
    rfs_q16_t grid;      /* lattice spacing, Q16.16 */
    rfs_q16_t clearance; /* Q16.16 */
    uint16_t w, h;       /* cells */
    uint32_t speckle;    /* single occupied cells per 10,000 */
    int step_n;          /* expected cells per step, 0 = no patterns (traversal) */
} map_case_t;

static const map_case_t CASES[] = {
    {"0.25 m lattice over 0.125 m cells (firmware)", 8192, 16384, 16384, 200, 120, 20, 2},
    {"the same, clearance 0", 8192, 16384, 0, 200, 120, 300, 2},
    {"0.25 m lattice over 0.1 m cells (sim)", 6554, 16384, 16384, 240, 160, 20, 0},
    {"0.25 m lattice over 0.05 m cells", 3277, 16384, 16384, 240, 160, 5, 0},
    {"0.25 m lattice over 0.25 m cells (centres)", 16384, 16384, 0, 120, 80, 300, 1},
    {"0.25 m lattice over 0.0625 m cells (corners)", 4096, 16384, 0, 240, 160, 400, 4},
    {"ratio 3 (centres)", 6554, 3 * 6554, 0, 240, 160, 200, 3},
    {"ratio 5, odd grid", 3277, 5 * 3277, 16384, 240, 160, 5, 5},
    {"ratio 6", 2731, 6 * 2731, 0, 240, 160, 150, 6},
};
#define NCASES (sizeof(CASES) / sizeof(CASES[0]))

static uint8_t free_bits[HMAX * STRIDE_MAX];
static uint8_t legal_bits[HMAX * STRIDE_MAX];
static uint8_t work[LMAX];
static uint32_t queue[QCAP];
static rfs_map_t map;

static uint32_t xs(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

/* Fixture: a map of case c with walls at random, origin off zero. */
static void build(const map_case_t *c, uint32_t seed)
{
    uint16_t stride = (uint16_t)((c->w + 7) / 8);
    memset(free_bits, 0, sizeof(free_bits));
    for (uint16_t y = 0; y < c->h; y++) {
        for (uint16_t x = 0; x < c->w; x++) {
            rfs_map_bit_set(free_bits, stride, x, y, true);
        }
    }
    uint32_t s = seed;
    for (int k = 0; k < 12; k++) {
        bool horiz = xs(&s) & 1u;
        uint32_t len = 10u + xs(&s) % (c->w / 2u);
        uint32_t thick = 1u + xs(&s) % 3u;
        uint32_t x0 = xs(&s) % c->w;
        uint32_t y0 = xs(&s) % c->h;
        for (uint32_t a = 0; a < len; a++) {
            for (uint32_t b = 0; b < thick; b++) {
                uint32_t x = horiz ? x0 + a : x0 + b;
                uint32_t y = horiz ? y0 + b : y0 + a;
                if (x < c->w && y < c->h) {
                    rfs_map_bit_set(free_bits, stride, (uint16_t)x, (uint16_t)y, false);
                }
            }
        }
    }
    for (uint16_t y = 0; y < c->h; y++) {
        for (uint16_t x = 0; x < c->w; x++) {
            if (xs(&s) % 10000u < c->speckle) {
                rfs_map_bit_set(free_bits, stride, x, y, false);
            }
        }
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = c->clearance;
    cfg.grid = c->grid;
    assert_int_equal(rfs_map_init(&map, &cfg, c->w, c->h, c->res, -RFS_Q16_FRAC(33, 10),
                                  RFS_Q16_FRAC(17, 10), free_bits, 0, legal_bits),
                     0);
}

/* The recorded step cells are the cells a closed lattice step touches (double geometry
 * on the step from lattice point (5, 5)), and step_n / step_c0 are grid / res and
 * (grid / 2) / res where grid is a whole multiple of res, 0 elsewhere. */
static void test_step_patterns(void **state)
{
    (void)state;
    static const int DX[4] = {1, 1, 0, -1};
    static const int DY[4] = {0, 1, 1, 1};
    for (size_t c = 0; c < NCASES; c++) {
        build(&CASES[c], 1u + (uint32_t)c);
        assert_int_equal(map.step_n, CASES[c].step_n);
        if (CASES[c].step_n == 0) {
            continue;
        }
        double r = CASES[c].res, g = CASES[c].grid;
        double x0 = floor(g / 2) + 5 * g;
        int s = (int)floor(x0 / r);
        assert_int_equal(map.step_c0, (int)floor(floor(g / 2) / r));
        for (int k = 0; k < 4; k++) {
            const rfs_map_step_t *st = &map.step[k];
            int n_cells = 0;
            for (int dj = -10; dj <= 10; dj++) {
                for (int di = -10; di <= 10; di++) {
                    int want = ref_touch(x0, x0, x0 + DX[k] * g, x0 + DY[k] * g, r, s + di, s + dj);
                    int bc = di - st->cx, bk = dj - st->cy;
                    int got = bc >= 0 && bk >= 0 && bc < st->cols && bk < st->rows &&
                              ((st->mask[bk] >> bc) & 1);
                    if (want != got) {
                        print_error("%s: direction %d cell (%d, %d): geometry %d, pattern %d\n",
                                    CASES[c].name, k, di, dj, want, got);
                    }
                    assert_int_equal(got, want);
                    n_cells += want;
                }
            }
            assert_true(n_cells >= 2);
        }
    }
}

/* Every lattice edge of every map, all 8 directions: the step test equals the traversal;
 * and every lattice point: rfs_map_lattice_legal equals the point test at its position. */
static void test_every_edge(void **state)
{
    (void)state;
    static const int DX[8] = {1, 1, 0, -1, -1, -1, 0, 1};
    static const int DY[8] = {0, 1, 1, 1, 0, -1, -1, -1};
    for (size_t c = 0; c < NCASES; c++) {
        for (uint32_t seed = 1; seed <= 2; seed++) {
            build(&CASES[c], seed * 7919u + (uint32_t)c);
            uint32_t n_legal = 0, n_illegal = 0, n_points_legal = 0;
            for (int j = 0; j < map.lh; j++) {
                for (int i = 0; i < map.lw; i++) {
                    rfs_q16_t x0, y0;
                    rfs_map_lattice_point(&map, (uint16_t)i, (uint16_t)j, &x0, &y0);
                    bool pl = rfs_map_point_legal(&map, x0, y0);
                    assert_int_equal(rfs_map_lattice_legal(&map, (uint16_t)i, (uint16_t)j), pl);
                    n_points_legal += pl;
                    for (int k = 0; k < 8; k++) {
                        int ti = i + DX[k], tj = j + DY[k];
                        bool want = false;
                        if (ti >= 0 && tj >= 0 && ti < map.lw && tj < map.lh) {
                            rfs_q16_t x1, y1;
                            rfs_map_lattice_point(&map, (uint16_t)ti, (uint16_t)tj, &x1, &y1);
                            want = rfs_map_segment_legal(&map, x0, y0, x1, y1);
                        }
                        bool got = rfs_map_lattice_step_legal(&map, (uint16_t)i, (uint16_t)j,
                                                              DX[k], DY[k]);
                        if (got != want) {
                            print_error("%s seed %u: edge (%d, %d) dir %d: traversal %d, step %d\n",
                                        CASES[c].name, seed, i, j, k, want, got);
                        }
                        assert_int_equal(got, want);
                        n_legal += want;
                        n_illegal += !want;
                    }
                }
            }
            /* Both outcomes well represented, so the comparison can fail. */
            print_message("%s seed %u: %u of %u points legal, edges %u legal %u not\n",
                          CASES[c].name, seed, n_points_legal, (uint32_t)map.lw * map.lh,
                          n_legal, n_illegal);
            assert_true(n_legal > 2000u);
            assert_true(n_illegal > 2000u);
            uint32_t n_points = (uint32_t)map.lw * map.lh;
            assert_true(n_points_legal > n_points / 50u);
            assert_true(n_points_legal < n_points - n_points / 50u);
        }
    }
}

/* Random start/goal pairs: plans with the step test and with the traversal on every edge
 * are identical (result, waypoints, length, expanded points, queue peak). */
static void test_plans_identical(void **state)
{
    (void)state;
    uint32_t searched = 0, reached = 0, unreached = 0;
    for (size_t c = 0; c < NCASES; c++) {
        build(&CASES[c], 4242u + (uint32_t)c);
        rfs_plan_t fast, ref;
        assert_int_equal(rfs_plan_init(&fast, &map, work, sizeof(work), queue, QCAP), 0);
        assert_int_equal(rfs_plan_init(&ref, &map, work, sizeof(work), queue, QCAP), 0);
        assert_false(fast.exact_edges);
        ref.exact_edges = true;
        uint32_t s = 99u + (uint32_t)c;
        int64_t wext = (int64_t)map.w * map.res, hext = (int64_t)map.h * map.res;
        for (int k = 0; k < 60; k++) {
            rfs_q16_t x0 = map.origin_x + (rfs_q16_t)(xs(&s) % (uint32_t)wext);
            rfs_q16_t y0 = map.origin_y + (rfs_q16_t)(xs(&s) % (uint32_t)hext);
            rfs_q16_t x1, y1;
            do {
                x1 = map.origin_x + (rfs_q16_t)(xs(&s) % (uint32_t)wext);
                y1 = map.origin_y + (rfs_q16_t)(xs(&s) % (uint32_t)hext);
            } while (!rfs_map_point_legal(&map, x1, y1));
            rfs_path_t pf, pr;
            memset(&pf, 0x5A, sizeof(pf));
            memset(&pr, 0xA5, sizeof(pr));
            bool of = rfs_plan_path(&fast, x0, y0, x1, y1, &pf);
            bool orf = rfs_plan_path(&ref, x0, y0, x1, y1, &pr);
            assert_int_equal(of, orf);
            assert_int_equal(fast.expanded, ref.expanded);
            assert_int_equal(fast.queue_peak, ref.queue_peak);
            assert_int_equal(pf.n, pr.n);
            assert_int_equal(pf.length, pr.length);
            for (uint16_t w = 0; w < pf.n; w++) {
                assert_int_equal(pf.x[w], pr.x[w]);
                assert_int_equal(pf.y[w], pr.y[w]);
            }
            searched += ref.expanded > 0;
            reached += orf && ref.expanded > 0;
            unreached += !orf;
        }
    }
    print_message("pairs with a search %u (reached %u), unreachable %u\n", searched, reached,
                  unreached);
    assert_true(searched > 200u);
    assert_true(reached > 150u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_step_patterns),
        cmocka_unit_test(test_every_edge),
        cmocka_unit_test(test_plans_identical),
    };
    return cmocka_run_group_tests(tests, 0, 0);
}
