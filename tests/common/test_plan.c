/* test_plan.c - rfs_plan against a double-precision Dijkstra written here.
 *
 * The reference: the same lattice (points grid/2 + k*grid from the origin), 8-connected,
 * an edge exists when the straight segment is legal by the brute-force geometry below
 * (closed segment vs closed cell squares, cells legal when no non-free cell comes
 * closer than the clearance to their centre), edge cost the Euclidean length in double.
 * The planner's any-angle path (string pulled) must be legal segment by segment, never
 * shorter than the straight line, and within 6 % of the reference's lattice optimum;
 * reachability must agree exactly.
 */
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

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static int ref_free(int x, int y)
{
    return x >= 0 && y >= 0 && x < W && y < H && wd.free_c[y][x];
}

static void ref_legal_cells(void)
{
    double r = RES / 65536.0;
    double c = CLR / 65536.0;
    for (int cy = 0; cy < H; cy++) {
        for (int cx = 0; cx < W; cx++) {
            int ok = ref_free(cx, cy);
            double px = (cx + 0.5) * r;
            double py = (cy + 0.5) * r;
            for (int y = cy - 5; ok && y <= cy + 5; y++) {
                for (int x = cx - 5; ok && x <= cx + 5; x++) {
                    if (ref_free(x, y)) {
                        continue;
                    }
                    double ex = fmax(0.0, fmax(x * r - px, px - (x + 1) * r));
                    double ey = fmax(0.0, fmax(y * r - py, py - (y + 1) * r));
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
static int touch(double x0, double y0, double x1, double y1, int i, int j)
{
    return ref_touch(x0, y0, x1, y1, RES, i, j);
}

/* Reference segment legality for points given in Q16 map coordinates (origin 0). */
static int ref_seg(double x0, double y0, double x1, double y1)
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

static void build(uint32_t seed, int nrect, int enclose)
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
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            rfs_map_bit_set(wd.free_bits, STRIDE, (uint16_t)x, (uint16_t)y, wd.free_c[y][x]);
        }
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&wd.m, &cfg, W, H, RES, 0, 0, wd.free_bits, NULL, wd.legal_bits), 0);
    ref_legal_cells();
}

/* Reference Dijkstra over the lattice in double; returns the distance or INFINITY. */
#define LMAX 4096
static double dist_ref[LMAX];
static int done_ref[LMAX];

static double ref_dijkstra(int lw, int lh, int si, int sj, int gi, int gj)
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
        if (u == gj * lw + gi) {
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

static int legal_lattice(int i, int j)
{
    double g = (double)wd.m.cfg.grid;
    double x = g / 2 + i * g, y = g / 2 + j * g;
    return wd.legal_c[(int)floor(y / RES)][(int)floor(x / RES)];
}

/* A legal lattice point drawn uniformly (by rejection) from the seeded generator. */
static void random_legal(uint32_t *seed, int lw, int lh, int *i, int *j)
{
    do {
        *i = (int)(lcg(seed) % (uint32_t)lw);
        *j = (int)(lcg(seed) % (uint32_t)lh);
    } while (!legal_lattice(*i, *j));
}

static void run_random_pairs(uint32_t seed, int pairs, int *n_reach, int *n_unreach, double *worst)
{
    rfs_plan_t p;
    int lw = wd.m.lw, lh = wd.m.lh;
    assert_true(lw * lh <= LMAX);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    double g = (double)wd.m.cfg.grid;
    for (int k = 0; k < pairs; k++) {
        int si, sj, gi, gj;
        random_legal(&seed, lw, lh, &si, &sj);
        random_legal(&seed, lw, lh, &gi, &gj);
        double want = ref_dijkstra(lw, lh, si, sj, gi, gj);
        rfs_path_t path;
        rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
        rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
        bool ok = rfs_plan_path(&p, x0, y0, x1, y1, &path);
        assert_int_equal(ok, !isinf(want));
        if (!ok) {
            (*n_unreach)++;
            continue;
        }
        (*n_reach)++;
        assert_true(path.n >= 1);
        assert_int_equal(path.x[path.n - 1], x1);
        assert_int_equal(path.y[path.n - 1], y1);
        double len = 0;
        double px = x0, py = y0;
        for (int w = 0; w < path.n; w++) {
            assert_true(ref_seg(px, py, path.x[w], path.y[w]));
            len += hypot(path.x[w] - px, path.y[w] - py) / 65536.0;
            px = path.x[w];
            py = path.y[w];
        }
        double straight = hypot(x1 - x0, y1 - y0) / 65536.0;
        assert_true(len >= straight - 1e-4);
        assert_true(len <= want * 1.06 + 1e-3);
        assert_true(fabs(path.length / 65536.0 - len) < 1e-3 * (1 + path.n));
        if (want > 0 && len / want > *worst) {
            *worst = len / want;
        }
    }
}

/* Random maps of wall segments: reachability, legality and length vs the reference. */
static void test_random_maps(void **state)
{
    (void)state;
    int reach = 0, unreach = 0;
    double worst = 0;
    for (uint32_t s = 1; s <= 6; s++) {
        build(s * 7919u, 14, s == 3);
        run_random_pairs(s, 25, &reach, &unreach, &worst);
    }
    print_message("reachable %d, unreachable %d, worst length / reference %.4f\n", reach, unreach, worst);
    assert_true(reach > 100);
}

/* A closed room: goals inside are reported unreachable from outside and vice versa. */
static void test_unreachable(void **state)
{
    (void)state;
    build(5, 0, 1);
    rfs_plan_t p;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    rfs_path_t path;
    const rfs_q16_t m1 = RFS_Q16_INT(1);
    /* Inside the room (8..10 m x 2..4 m): centre (9, 3). Outside: (2, 2). */
    assert_true(rfs_map_point_legal(&wd.m, 9 * m1, 3 * m1));
    assert_true(rfs_map_point_legal(&wd.m, 2 * m1, 2 * m1));
    assert_false(rfs_plan_path(&p, 2 * m1, 2 * m1, 9 * m1, 3 * m1, &path));
    assert_int_equal(path.n, 0);
    assert_false(rfs_plan_path(&p, 9 * m1, 3 * m1, 2 * m1, 2 * m1, &path));
    /* An illegal goal (inside the clearance of the ring) is refused. */
    assert_false(rfs_plan_path(&p, 2 * m1, 2 * m1, 8 * m1 + RFS_Q16_FRAC(1, 20), 3 * m1, &path));
    /* Around the room from its left to its right: reachable, longer than straight. */
    assert_true(rfs_plan_path(&p, 7 * m1, 3 * m1, 11 * m1, 3 * m1, &path));
    double len = path.length / 65536.0;
    assert_true(len > 4.0 + 0.5 && len < 4.0 + 2 * 1.6 + 0.5);
}

/* Reference component (double precision), one bit per point as rfs_plan_set_component
 * takes it. */
static uint8_t comp_bits[LMAX / 8];

static int ref_step(void *ctx, int ui, int uj, int vi, int vj)
{
    (void)ctx;
    double g = (double)wd.m.cfg.grid;
    return legal_lattice(vi, vj) &&
           ref_seg(g / 2 + ui * g, g / 2 + uj * g, g / 2 + vi * g, g / 2 + vj * g);
}

static void ref_component(int lw, int lh, int si, int sj)
{
    ref_flood(lw, lh, si, sj, ref_step, NULL, comp_bits);
}

/* rfs_plan_set_component: with the start's component (from the reference flood) plans are
 * bit-identical to plans without it, and a goal outside it fails at once (no point
 * expanded) where the plain search floods the goal's side first. */
static void test_component(void **state)
{
    (void)state;
    int skipped = 0, same = 0, other = 0;
    for (uint32_t s = 1; s <= 6; s++) {
        build(s * 7919u, 14, 1); /* a closed room on every map: unreachable goals */
        int lw = wd.m.lw, lh = wd.m.lh;
        double g = (double)wd.m.cfg.grid;
        rfs_plan_t a, b;
        static uint8_t work_b[LMAX];
        static uint32_t queue_b[1024];
        assert_int_equal(rfs_plan_init(&a, &wd.m, work, sizeof(work), queue, 1024), 0);
        assert_int_equal(rfs_plan_init(&b, &wd.m, work_b, sizeof(work_b), queue_b, 1024), 0);
        assert_null(b.component);
        uint32_t seed = s;
        for (int k = 0; k < 40; k++) {
            int si, sj, gi, gj;
            random_legal(&seed, lw, lh, &si, &sj);
            random_legal(&seed, lw, lh, &gi, &gj);
            ref_component(lw, lh, si, sj);
            rfs_plan_set_component(&b, comp_bits);
            rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
            rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
            rfs_path_t pa, pb;
            bool oka = rfs_plan_path(&a, x0, y0, x1, y1, &pa);
            bool okb = rfs_plan_path(&b, x0, y0, x1, y1, &pb);
            uint32_t exp_a = a.expanded, exp_b = b.expanded;
            assert_int_equal(oka, okb);
            assert_int_equal(pa.n, pb.n);
            assert_int_equal(pa.length, pb.length);
            assert_memory_equal(pa.x, pb.x, pa.n * sizeof(pa.x[0]));
            assert_memory_equal(pa.y, pb.y, pa.n * sizeof(pa.y[0]));
            /* Marks that are a union of components but not the start's (the closed
             * room's): nothing may be refused, results the same. */
            int ri = 34, rj = 10;
            while (!legal_lattice(ri, rj) && ++ri <= 38) {
            }
            assert_true(ri <= 38); /* inside the room, 8..10 m x 2..4 m */
            ref_component(lw, lh, ri, rj);
            if (!(comp_bits[(sj * lw + si) >> 3] >> ((sj * lw + si) & 7) & 1)) {
                rfs_path_t pc;
                bool okc = rfs_plan_path(&b, x0, y0, x1, y1, &pc);
                assert_int_equal(oka, okc);
                assert_int_equal(pa.n, pc.n);
                assert_int_equal(pa.length, pc.length);
                other += oka;
            }
            ref_component(lw, lh, si, sj);
            int gin = comp_bits[(gj * lw + gi) >> 3] >> ((gj * lw + gi) & 7) & 1;
            if (!gin) {
                assert_false(oka); /* outside the start's component: unreachable */
                if (!ref_seg(x0, y0, x1, y1)) {
                    assert_int_equal(exp_b, 0); /* refused without a search */
                    assert_true(exp_a > 0);
                    skipped++;
                }
            } else {
                same++;
            }
        }
    }
    print_message("goals in the start's component %d, refused without a search %d, planned "
                  "with another component marked %d\n", same, skipped, other);
    assert_true(skipped >= 20 && same >= 100 && other >= 100);
}

/* A queue too small for the wavefront is reported (as unreachable), never overrun. */
static void test_queue_overflow(void **state)
{
    (void)state;
    build(9, 0, 0);
    rfs_plan_t p;
    static uint32_t small[8 + 4];
    small[8] = small[9] = small[10] = small[11] = 0xA5A5A5A5u;
    /* A wall with a gap forces a search. */
    for (int y = 0; y < 70; y++) {
        wd.free_c[y][60] = 0;
        rfs_map_bit_set(wd.free_bits, STRIDE, 60, (uint16_t)y, false);
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&wd.m, &cfg, W, H, RES, 0, 0, wd.free_bits, NULL, wd.legal_bits), 0);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), small, 8), 0);
    rfs_path_t path;
    const rfs_q16_t m1 = RFS_Q16_INT(1);
    assert_false(rfs_plan_path(&p, 2 * m1, 2 * m1, 10 * m1, 2 * m1, &path));
    assert_int_equal(small[8], 0xA5A5A5A5u);
    assert_int_equal(small[11], 0xA5A5A5A5u);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    assert_true(rfs_plan_path(&p, 2 * m1, 2 * m1, 10 * m1, 2 * m1, &path));
    assert_true(path.n >= 2);
}

/* Line of sight: one waypoint, the goal, and the exact length. */
static void test_line_of_sight(void **state)
{
    (void)state;
    build(1, 0, 0);
    rfs_plan_t p;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    rfs_path_t path;
    assert_true(rfs_plan_path(&p, RFS_Q16_INT(1), RFS_Q16_INT(1), RFS_Q16_INT(4), RFS_Q16_INT(5), &path));
    assert_int_equal(path.n, 1);
    assert_true(abs(path.length - RFS_Q16_INT(5)) <= 1);
    assert_int_equal(p.expanded, 0);
}

static void test_init_rejects(void **state)
{
    (void)state;
    build(1, 0, 0);
    rfs_plan_t p;
    uint32_t need = (uint32_t)wd.m.lw * wd.m.lh;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, need - 1, queue, 1024), -1);
    assert_int_equal(rfs_plan_init(&p, &wd.m, NULL, need, queue, 1024), -1);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, need, queue, 7), -1);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, need, queue, 8), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_maps),
        cmocka_unit_test(test_unreachable),
        cmocka_unit_test(test_component),
        cmocka_unit_test(test_queue_overflow),
        cmocka_unit_test(test_line_of_sight),
        cmocka_unit_test(test_init_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
