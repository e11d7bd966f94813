/* test_reach.c - reachability (common/rfs_reach.c): the seeker's reach bits after its
 * first period are exactly the robot's component of the lattice graph, compared with a
 * double-precision flood fill (ref_geom.h).
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "seek_world.h"

/* Reference lattice legality: the legal bit of the point's cell (double geometry). */
static int ref_lat_legal(const rfs_map_t *m, int i, int j)
{
    double g = m->cfg.grid, r = m->res;
    double x = floor(g / 2) + i * g, y = floor(g / 2) + j * g;
    return rfs_map_bit(m->legal, m->stride, (uint16_t)floor(x / r), (uint16_t)floor(y / r));
}

/* Reference edge legality: every cell the closed segment touches is legal and on the map. */
static int ref_step_legal(const rfs_map_t *m, int i0, int j0, int i1, int j1)
{
    double g = m->cfg.grid, r = m->res;
    double x0 = floor(g / 2) + i0 * g, y0 = floor(g / 2) + j0 * g;
    double x1 = floor(g / 2) + i1 * g, y1 = floor(g / 2) + j1 * g;
    int clo = (int)floor(fmin(x0, x1) / r) - 1, chi = (int)floor(fmax(x0, x1) / r) + 1;
    int rlo = (int)floor(fmin(y0, y1) / r) - 1, rhi = (int)floor(fmax(y0, y1) / r) + 1;
    for (int cj = rlo; cj <= rhi; cj++) {
        for (int ci = clo; ci <= chi; ci++) {
            if (ref_touch(x0, y0, x1, y1, r, ci, cj) &&
                (ci < 0 || cj < 0 || ci >= m->w || cj >= m->h ||
                 !rfs_map_bit(m->legal, m->stride, (uint16_t)ci, (uint16_t)cj))) {
                return 0;
            }
        }
    }
    return 1;
}

static int bit_of(const uint8_t *bits, int v)
{
    return (bits[v >> 3] >> (v & 7)) & 1;
}

static int ref_map_step(void *ctx, int ui, int uj, int vi, int vj)
{
    const rfs_map_t *m = ctx;
    return ref_lat_legal(m, vi, vj) && ref_step_legal(m, ui, uj, vi, vj);
}

/* t emptied, 8 x 6 m at cell size res, its three bit grids allocated and clear; returns
 * the grids' row stride in bytes. */
static uint16_t blank_8x6(world_t *t, double res)
{
    memset(t, 0, sizeof *t);
    t->w = (uint16_t)lround(8.0 / res);
    t->h = (uint16_t)lround(6.0 / res);
    uint32_t bytes = rfs_map_bytes(t->w, t->h);
    t->free_bits = calloc(bytes, 1);
    t->wall_bits = calloc(bytes, 1);
    t->legal_bits = calloc(bytes, 1);
    return (uint16_t)((t->w + 7) / 8);
}

/* t's robot at lattice point (si, sj) with one pose and one 1 s mean, and its first
 * period (the reach flood begins there). */
static void first_step(world_t *t, int si, int sj, rfs_seek_out_t *out)
{
    double g = D(t->map.cfg.grid);
    rfs_pose_t p = pose_at(100000, g / 2 + si * g, g / 2 + sj * g, 0);
    rfs_seek_on_pose(&t->seek, &p, &t->rng);
    rfs_seek_on_rssi(&t->seek, 0, 100000, -50, &t->rng);
    rfs_seek_step(&t->seek, 100000, &t->rng, out);
}

/* t's map: 8 x 6 m at cell size res, 2.5 % of the cells occupied at random (seed), no
 * clearance, the 0.25 m lattice. Returns the random state after the map. */
static uint32_t speckled_map(world_t *t, uint32_t seed, double res)
{
    const uint16_t stride = blank_8x6(t, res);
    uint32_t s = seed * 2654435761u;
    for (uint16_t y = 0; y < t->h; ++y) {
        for (uint16_t x = 0; x < t->w; ++x) {
            s = s * 1664525u + 1013904223u;
            rfs_map_bit_set(t->free_bits, stride, x, y, (s >> 8) % 1000u >= 25u);
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    mc.clearance = 0;
    assert_int_equal(rfs_map_init(&t->map, &mc, t->w, t->h, Q(res), 0, 0, t->free_bits,
                                  t->wall_bits, t->legal_bits), 0);
    return s;
}

/* A speckled 8 x 6 m map (2.5 % of the cells occupied, no clearance: many small pockets)
 * at cell size res, and the seeker's reach bits after its first period at a random legal
 * lattice point. They decide which plans the planner refuses without a search
 * (rfs_plan_set_component), so they must be exactly the robot's component: compared with
 * a double-precision flood. With an 8-entry queue the fill overflows and marks every legal
 * point instead (still a union of whole components). With reach_budget, the flood is
 * sliced over periods (the wheels stopped meanwhile), one per `budget` points of the
 * component, and ends with the same bits. */
static void reach_case(uint32_t seed, double res, bool small_queue, uint32_t budget,
                       int *in_component, int *legal)
{
    world_t t;
    uint32_t s = speckled_map(&t, seed, res);
    int si, sj;
    do {
        s = s * 1664525u + 1013904223u;
        si = (int)((s >> 8) % t.map.lw);
        s = s * 1664525u + 1013904223u;
        sj = (int)((s >> 8) % t.map.lh);
    } while (!ref_lat_legal(&t.map, si, sj));
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.reach_budget = budget;
    seek_make(&t, cfg, seed);
    if (small_queue) {
        t.mem.plan_queue_cap = 8;
        assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, rfs_ridge_model(&t.ridge),
                                       &rfs_target_rssi, &t.mem), 0);
    }
    rfs_seek_out_t out;
    first_step(&t, si, sj, &out);
    int waits = 0;
    while (t.seek.flooding) {
        assert_false(t.seek.reach_valid);
        assert_int_equal(out.left_mm_s, 0);
        assert_int_equal(out.right_mm_s, 0);
        waits++;
        rfs_seek_step(&t.seek, 100000, &t.rng, &out);
    }
    assert_true(t.seek.reach_valid);
    uint8_t *ref = calloc(t.mem.reach_bytes, 1);
    ref_flood(t.map.lw, t.map.lh, si, sj, ref_map_step, &t.map, ref);
    int comp = 0;
    for (int v = 0; v < t.map.lw * t.map.lh; v++) {
        comp += bit_of(ref, v);
    }
    if (!small_queue) { /* every point of the component expanded once */
        assert_int_equal(waits, budget == 0u ? 0 : (comp + (int)budget - 1) / (int)budget - 1);
    }
    for (int j = 0; j < t.map.lh; j++) {
        for (int i = 0; i < t.map.lw; i++) {
            int v = j * t.map.lw + i;
            int want = small_queue ? ref_lat_legal(&t.map, i, j) : bit_of(ref, v);
            if (bit_of(t.mem.reach, v) != want) {
                fail_msg("seed %u, %.3f m cells%s: point (%d, %d) reach %d, reference %d", seed,
                         res, small_queue ? ", 8-entry queue" : "", i, j, !want, want);
            }
            *in_component += bit_of(ref, v);
            *legal += ref_lat_legal(&t.map, i, j);
        }
    }
    free(ref);
    world_free(&t);
}

static void test_reach_is_the_component(void **state)
{
    (void)state;
    int comp = 0, legal = 0;
    for (uint32_t seed = 1; seed <= 12; seed++) {
        reach_case(seed, 0.125, false, 0u, &comp, &legal); /* step patterns */
        reach_case(seed, 0.1, false, 0u, &comp, &legal);   /* the exact traversal */
    }
    print_message("robot's components %d of %d legal lattice points\n", comp, legal);
    assert_true(comp > legal / 10 && comp < legal); /* pockets exist, the fill is not trivial */
    int c2 = 0, l2 = 0;
    reach_case(3, 0.125, true, 0u, &c2, &l2);
    reach_case(4, 0.1, true, 0u, &c2, &l2);
}

/* t's map: 8 x 6 m at cell size res, no clearance, the 0.25 m lattice, 14 rectangular
 * rings of one-cell walls 0.4 to 2.4 m a side at random (seed), overlapping: closed
 * pockets of many sizes. Returns the random state after the map. */
static uint32_t boxed_map(world_t *t, uint32_t seed, double res)
{
    const uint16_t stride = blank_8x6(t, res);
    for (uint16_t y = 0; y < t->h; ++y) {
        for (uint16_t x = 0; x < t->w; ++x) {
            rfs_map_bit_set(t->free_bits, stride, x, y, true);
        }
    }
    uint32_t s = seed * 2654435761u;
    for (int b = 0; b < 14; b++) {
        int xy[4];
        for (int k = 0; k < 4; k++) {
            s = s * 1664525u + 1013904223u;
            xy[k] = (int)((s >> 8) % 1000u);
        }
        int x0 = xy[0] * (t->w - 1) / 1000, y0 = xy[1] * (t->h - 1) / 1000;
        int x1 = x0 + (int)lround((0.4 + 2.0 * xy[2] / 1000.0) / res);
        int y1 = y0 + (int)lround((0.4 + 2.0 * xy[3] / 1000.0) / res);
        for (int y = y0; y <= y1 && y < t->h; y++) {
            for (int x = x0; x <= x1 && x < t->w; x++) {
                if (x == x0 || x == x1 || y == y0 || y == y1) {
                    rfs_map_bit_set(t->free_bits, stride, (uint16_t)x, (uint16_t)y, false);
                }
            }
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    mc.clearance = 0;
    assert_int_equal(rfs_map_init(&t->map, &mc, t->w, t->h, Q(res), 0, 0, t->free_bits,
                                  t->wall_bits, t->legal_bits), 0);
    return s;
}

/* Points set in a reference flood's bits. */
static int bits_count(const uint8_t *bits, int n)
{
    int c = 0;
    for (int v = 0; v < n; v++) {
        c += bit_of(bits, v);
    }
    return c;
}

/* reach_min (rfs_seek_cfg_t): a robot on a legal lattice point of a pocket (a component
 * of fewer than reach_min points) of a boxed map gets the component of the nearest
 * legal lattice point outside it (squared lattice offset, rings of up to
 * RFS_REACH_SNAP_RADIUS, row-major at a tie) when that is larger, else its own: both from
 * double-precision floods. Counts the pockets left and kept. */
static void pocket_case(uint32_t seed, double res, uint32_t budget, int *left, int *kept)
{
    world_t t;
    uint32_t s = boxed_map(&t, seed, res);
    const int lw = t.map.lw, lh = t.map.lh, n = lw * lh;
    uint8_t *own = calloc(t.map.lw * (size_t)t.map.lh / 8 + 1, 1);
    uint8_t *other = calloc(t.map.lw * (size_t)t.map.lh / 8 + 1, 1);
    int si, sj, size, tries = 0;
    do { /* a random legal lattice point in a pocket (under 64 points) */
        s = s * 1664525u + 1013904223u;
        si = (int)((s >> 8) % (uint32_t)lw);
        s = s * 1664525u + 1013904223u;
        sj = (int)((s >> 8) % (uint32_t)lh);
        size = 0;
        if (ref_lat_legal(&t.map, si, sj)) {
            ref_flood(lw, lh, si, sj, ref_map_step, &t.map, own);
            size = bits_count(own, n);
        }
    } while ((size < 1 || size >= 64) && ++tries < 5000);
    assert_true(size >= 1 && size < 64);
    int oi = -1, oj = -1;
    for (int r = 1; r <= RFS_REACH_SNAP_RADIUS && oi < 0; r++) {
        int best = INT32_MAX;
        for (int dj = -r; dj <= r; dj++) {
            for (int di = -r; di <= r; di++) {
                int i = si + di, j = sj + dj;
                if ((abs(di) != r && abs(dj) != r) || i < 0 || j < 0 || i >= lw || j >= lh ||
                    !ref_lat_legal(&t.map, i, j) || bit_of(own, j * lw + i) ||
                    di * di + dj * dj >= best) {
                    continue;
                }
                best = di * di + dj * dj;
                oi = i;
                oj = j;
            }
        }
    }
    const uint8_t *want = own;
    if (oi >= 0) {
        ref_flood(lw, lh, oi, oj, ref_map_step, &t.map, other);
        want = bits_count(other, n) > size ? other : own;
    }
    *left += want == other;
    *kept += want == own;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.reach_budget = budget;
    cfg.reach_min = 64;
    seek_make(&t, cfg, seed);
    rfs_seek_out_t out;
    first_step(&t, si, sj, &out);
    while (t.seek.flooding) {
        assert_int_equal(out.left_mm_s, 0);
        rfs_seek_step(&t.seek, 100000, &t.rng, &out);
    }
    assert_true(t.seek.reach_valid);
    for (int v = 0; v < n; v++) {
        if (bit_of(t.mem.reach, v) != bit_of(want, v)) {
            fail_msg("seed %u, %.3f m cells, pocket of %d at (%d, %d): point (%d, %d) reach %d",
                     seed, res, size, si, sj, v % lw, v / lw, !bit_of(want, v));
        }
    }
    free(own);
    free(other);
    world_free(&t);
}

static void test_reach_min_leaves_a_pocket(void **state)
{
    (void)state;
    rfs_seek_cfg_t c = rfs_seek_cfg_default();
    assert_int_equal(c.reach_min, 0); /* the paper's: the robot's component */
    rfs_seek_cfg_use_strategy(&c, RFS_SEEK_META_PATH);
    assert_int_equal(c.reach_min, 16);
    rfs_seek_cfg_use_strategy(&c, RFS_SEEK_META);
    assert_int_equal(c.reach_min, 0);
    int left = 0, kept = 0;
    for (uint32_t seed = 1; seed <= 12; seed++) {
        pocket_case(seed, 0.125, 0u, &left, &kept);
        pocket_case(seed, 0.1, seed % 2 ? 0u : 7u, &left, &kept);
    }
    print_message("pockets left %d, kept %d\n", left, kept);
    assert_true(left > 0 && kept > 0);
}

/* reach_budget: the flood sliced over periods gives the whole flood's bits. */
static void test_sliced_reach_is_the_component(void **state)
{
    (void)state;
    int comp = 0, legal = 0;
    for (uint32_t seed = 1; seed <= 6; seed++) {
        reach_case(seed, 0.125, false, 1u, &comp, &legal);
        reach_case(seed, 0.1, false, 37u, &comp, &legal);
    }
    reach_case(3, 0.125, true, 5u, &comp, &legal);
}

/* The lattice memo (rfs_map_memo_attach) answers as the double-precision references, on
 * the first call (computed) and the second (remembered), for every lattice point and
 * direction of a map without step patterns (0.1 m cells, 0.25 m lattice). */
static void test_memo_matches_reference(void **state)
{
    (void)state;
    static const int8_t k_di[8] = {1, 1, 0, -1, -1, -1, 0, 1};
    static const int8_t k_dj[8] = {0, 1, 1, 1, 0, -1, -1, -1};
    world_t t;
    (void)speckled_map(&t, 5, 0.1);
    assert_int_equal(t.map.step_n, 0);
    const uint32_t n = rfs_map_memo_entries(&t.map);
    assert_int_equal(n, (uint32_t)t.map.lw * t.map.lh);
    uint16_t *memo = malloc(n * sizeof(memo[0]));
    assert_non_null(memo);
    assert_int_equal(rfs_map_memo_attach(&t.map, memo, n - 1), -1);
    assert_null(t.map.memo);
    assert_int_equal(rfs_map_memo_attach(&t.map, memo, n), 0);
    int legal = 0, steps = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (int j = 0; j < t.map.lh; j++) {
            for (int i = 0; i < t.map.lw; i++) {
                const int want = ref_lat_legal(&t.map, i, j);
                assert_int_equal(rfs_map_lattice_legal(&t.map, (uint16_t)i, (uint16_t)j), want);
                legal += pass == 0 ? want : 0;
                for (int k = 0; k < 8; k++) {
                    const int vi = i + k_di[k], vj = j + k_dj[k];
                    const int on = vi >= 0 && vj >= 0 && vi < t.map.lw && vj < t.map.lh;
                    const int ws = on && ref_step_legal(&t.map, i, j, vi, vj);
                    if (rfs_map_lattice_step_legal(&t.map, (uint16_t)i, (uint16_t)j, k_di[k],
                                                   k_dj[k]) != ws) {
                        fail_msg("pass %d: step (%d, %d) -> (%d, %d): reference %d", pass, i, j,
                                 vi, vj, ws);
                    }
                    steps += pass == 0 ? ws : 0;
                }
            }
        }
    }
    /* every point's legality and its four upper steps (those on the lattice) known */
    for (int j = 0; j < t.map.lh; j++) {
        for (int i = 0; i < t.map.lw; i++) {
            const uint16_t e = memo[j * t.map.lw + i];
            assert_true(e & 0x200u);
            assert_int_equal((e & 0x10u) != 0, i + 1 < t.map.lw);
            assert_int_equal((e & 0x40u) != 0, j + 1 < t.map.lh);
        }
    }
    assert_true(legal > 0 && steps > 0 && steps < 8 * legal); /* walls cut some steps */
    free(memo);
    world_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reach_is_the_component),
        cmocka_unit_test(test_sliced_reach_is_the_component),
        cmocka_unit_test(test_reach_min_leaves_a_pocket),
        cmocka_unit_test(test_memo_matches_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
