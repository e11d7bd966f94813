/* test_plan.c - rfs_plan's lattice search and string pulling against a double-precision
 * Dijkstra (plan_world.h): the planner's any-angle path must be legal segment by segment,
 * never shorter than the straight line, and within 6 % of the reference's lattice optimum;
 * reachability must agree exactly. The search tree: test_plan_tree.c.
 */
#include "plan_world.h"

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
        double len = ref_path_len(x0, y0, &path);
        double straight = hypot(x1 - x0, y1 - y0) / 65536.0;
        assert_true(len >= straight - 1e-4);
        assert_true(len <= want * 1.06 + 1e-3);
        assert_true(fabs(path.length / 65536.0 - len) < 1e-3 * (1 + path.n));
        if (want > 0 && len / want > *worst) {
            *worst = len / want;
        }
        /* Linear string pulling: its tests span at most 10 points per point of the
         * lattice path, whose points number at most 1.061 x the reference length over
         * the spacing (octile steps, diagonal 1.5 for sqrt 2) plus the two ends. */
        assert_true(p.pulled <= 10.0 * (1.0607 * want * 65536.0 / g + 3.0));
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
            int ri = 33, rj = 9; /* inside the room, 8..10 m x 2..4 m */
            while (!legal_lattice(ri, rj) && rj <= 14) {
                if (++ri > 38) {
                    ri = 33;
                    rj++;
                }
            }
            assert_true(rj <= 14);
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

/* A serpentine (walls at x = 2, 4 ... 10 m from alternate edges, 1 m passages): a path
 * of some 45 m round five walls from (1, 1) m to (11, 1) m. String pulling is linear (its
 * tests span at most 10 points per lattice point, the greedy puller's about 60), the
 * path legal (the reference geometry), within 6 % of the lattice optimum. */
static void test_pull_linear(void **state)
{
    (void)state;
    memset(&wd, 0, sizeof(wd));
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            wd.free_c[y][x] = 1;
        }
    }
    for (int k = 1; k <= 5; k++) {
        const int x = 20 * k;
        for (int y = 0; y < H - 10; y++) {
            wd.free_c[k % 2 ? y : H - 1 - y][x] = 0;
        }
    }
    build_finish();
    rfs_plan_t p;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    const double g = (double)wd.m.cfg.grid;
    const int lw = wd.m.lw, lh = wd.m.lh;
    const int si = 3, sj = 3, gi = 43, gj = 3;
    const double want = ref_dijkstra(lw, lh, si, sj, gi, gj);
    const rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
    const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
    rfs_path_t path;
    assert_true(rfs_plan_path(&p, x0, y0, x1, y1, &path));
    double len = ref_path_len(x0, y0, &path);
    const double points = 1.0607 * want * 65536.0 / g + 3.0;
    print_message("serpentine: %.2f m (lattice optimum %.2f m), %d waypoints, tests spanned "
                  "%u points, %.2f per lattice point\n", len, want, path.n, p.pulled,
                  p.pulled / (want * 65536.0 / g));
    assert_true(want > 40.0);
    assert_true(len <= want * 1.06 + 1e-3);
    assert_true(path.n >= 6);
    assert_true(p.pulled <= 10.0 * points);
    assert_true(p.pulled >= want * 65536.0 / g); /* every point was passed by a test */
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
        cmocka_unit_test(test_pull_linear),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
