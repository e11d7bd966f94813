/* test_plan_tree.c - rfs_plan's search tree (rfs_plan_tree_*: grown in slices from a root,
 * paths read back to any goal, moved, deferred, with and without the edge table) against
 * the double-precision references of plan_world.h and against rfs_plan_path's own paths.
 */
#include "plan_world.h"

typedef struct tree_stats {
    int goals, searched, reached, unreached, los, free_hits, illegal_roots;
    double worst_ratio;    /* tree path length / reference lattice optimum */
    double worst_diff_m;   /* |tree path - rfs_plan_path path|, metres */
    double worst_diff_rel; /* the same over the rfs_plan_path length */
    double sum_signed;     /* sum of tree path - rfs_plan_path path, metres */
    int longer, shorter;   /* tree paths longer / shorter than rfs_plan_path's */
} tree_stats_t;

#define TREE_GOALS 8

/* One tree of check_trees: its root, what kind of root it is, and its planners. */
typedef struct tree_run {
    rfs_plan_t *t, *f, *pp;  /* the tree, a fresh tree per goal, rfs_plan_path */
    int lw, lh, n;
    double g;                /* lattice spacing, Q16 */
    bool on_lattice, illegal;
    rfs_q16_t x0, y0;        /* the root */
    int c_max;               /* largest octile cost of a goal searched for so far */
    uint32_t total;          /* points the tree has expanded */
    tree_stats_t *st;
} tree_run_t;

/* The root of tree tr: a lattice point (every third; the references computed from it),
 * a point of the clearance zone (every third) or a legal point between lattice points. */
static void tree_root(tree_run_t *tr, int k, uint32_t *rs)
{
    const int lw = tr->lw, lh = tr->lh;
    const double g = tr->g;
    tr->on_lattice = k % 3 == 0;
    tr->illegal = k % 3 == 2;
    int si, sj;
    random_legal(rs, lw, lh, &si, &sj);
    tr->x0 = (rfs_q16_t)(g / 2 + si * g);
    tr->y0 = (rfs_q16_t)(g / 2 + sj * g);
    if (tr->illegal) {
        /* A point of the clearance zone: from lattice points next to it, 0.1 m steps
         * in a random direction until one is illegal (inside the map). */
        rfs_q16_t ox, oy;
        const rfs_q16_t dm = RFS_Q16_FRAC(1, 10);
        do {
            random_legal(rs, lw, lh, &si, &sj);
            const int dx = (int)(lcg(rs) % 3u) - 1, dy = (int)(lcg(rs) % 3u) - 1;
            ox = (rfs_q16_t)(g / 2 + si * g);
            oy = (rfs_q16_t)(g / 2 + sj * g);
            for (int a = 0; a < 5 && rfs_map_point_legal(&wd.m, ox, oy); a++) {
                ox += dx * dm;
                oy += dy * dm;
            }
        } while (ox <= 0 || oy <= 0 || ox >= W * RES || oy >= H * RES ||
                 rfs_map_point_legal(&wd.m, ox, oy));
        tr->x0 = ox;
        tr->y0 = oy;
        tr->st->illegal_roots++;
    } else if (!tr->on_lattice) {
        rfs_q16_t ox, oy;
        do {
            ox = tr->x0 + (rfs_q16_t)(lcg(rs) % (uint32_t)g) - (rfs_q16_t)(g / 2);
            oy = tr->y0 + (rfs_q16_t)(lcg(rs) % (uint32_t)g) - (rfs_q16_t)(g / 2);
        } while (!rfs_map_point_legal(&wd.m, ox, oy));
        tr->x0 = ox;
        tr->y0 = oy;
    } else {
        (void)ref_dijkstra(lw, lh, si, sj, -1, -1);
        ref_octile(lw, lh, si, sj);
        ref_component(lw, lh, si, sj);
    }
}

/* A lattice root, a goal gv out of line of sight: reached as the reference flood says;
 * no search when it was closed on the way to an earlier goal (e points expanded); the
 * tree holds every point cheaper than the farthest goal yet and none dearer. */
static void check_tree_search(tree_run_t *tr, int gv, bool ok, uint32_t e)
{
    const bool in = (comp_bits[gv >> 3] >> (gv & 7)) & 1;
    assert_int_equal(ok, in); /* the reference flood */
    assert_int_equal(in, oct_ref[gv] < INT32_MAX);
    assert_int_equal(in, !isinf(dist_ref[gv]));
    const int c = in ? oct_ref[gv] : INT32_MAX;
    if (c < tr->c_max) {
        /* Closed on the way to an earlier goal: no search. */
        assert_int_equal(e, 0);
        tr->st->free_hits++;
    }
    tr->c_max = c > tr->c_max ? c : tr->c_max;
    /* Every point cheaper than the farthest goal yet is closed, none dearer. */
    int below, upto;
    oct_count(tr->n, tr->c_max, &below, &upto);
    assert_true((int)tr->total >= below && (int)tr->total <= upto);
    tr->st->searched++;
}

/* The tree's path pt to (x1, y1), goal gv, found: its hops legal (the first one out of
 * the clearance zone from an illegal root), its length theirs, no shorter than the
 * straight line and within 6 % of the lattice optimum from a lattice root. */
static void check_tree_hops(tree_run_t *tr, const rfs_path_t *pt, rfs_q16_t x1, rfs_q16_t y1, int gv)
{
    const double g = tr->g;
    assert_true(pt->n >= 1);
    assert_int_equal(pt->x[pt->n - 1], x1);
    assert_int_equal(pt->y[pt->n - 1], y1);
    double len = 0, px = tr->x0, py = tr->y0;
    for (int w = 0; w < pt->n; w++) {
        if (tr->illegal && w == 0) {
            /* The hop out of the clearance zone: to a legal point 2 lattice
             * steps away at most (rfs_plan_path's escape join). */
            assert_true(rfs_map_point_legal(&wd.m, pt->x[0], pt->y[0]));
            assert_true(hypot(pt->x[0] - px, pt->y[0] - py) <= 2 * sqrt(2.0) * g + 2 * g);
        } else {
            assert_true(ref_seg(px, py, pt->x[w], pt->y[w]));
            assert_true(rfs_map_segment_legal(&wd.m, (rfs_q16_t)px, (rfs_q16_t)py,
                                              pt->x[w], pt->y[w]));
        }
        len += hypot(pt->x[w] - px, pt->y[w] - py) / 65536.0;
        px = pt->x[w];
        py = pt->y[w];
    }
    assert_true(fabs(pt->length / 65536.0 - len) < 1e-3 * (1 + pt->n));
    assert_true(len >= hypot(x1 - tr->x0, y1 - tr->y0) / 65536.0 - 1e-4);
    if (tr->on_lattice) {
        const double want = dist_ref[gv] / 65536.0;
        assert_true(len <= want * 1.06 + 1e-3);
        if (want > 0 && len / want > tr->st->worst_ratio) {
            tr->st->worst_ratio = len / want;
        }
    }
}

/* The tree's path pt against rfs_plan_path's pb from the same root (ties among
 * equal-cost lattice paths pull differently, either way), and against a fresh tree for
 * this goal alone (the same path). */
static void check_tree_against(tree_run_t *tr, const rfs_path_t *pt, const rfs_path_t *pb,
                               rfs_q16_t x1, rfs_q16_t y1)
{
    tree_stats_t *st = tr->st;
    const double diff = fabs((double)pt->length - pb->length) / 65536.0;
    assert_true(diff < 0.75);
    st->worst_diff_m = diff > st->worst_diff_m ? diff : st->worst_diff_m;
    st->sum_signed += ((double)pt->length - pb->length) / 65536.0;
    st->longer += pt->length > pb->length;
    st->shorter += pt->length < pb->length;
    if (pb->length > 0 && diff * 65536.0 / pb->length > st->worst_diff_rel) {
        st->worst_diff_rel = diff * 65536.0 / pb->length;
    }
    rfs_path_t pf;
    rfs_plan_tree_begin(tr->f, tr->x0, tr->y0);
    assert_true(rfs_plan_tree_path(tr->f, x1, y1, &pf));
    assert_same_path(pt, &pf);
}

/* Goal (gi, gj) on the tree: its result *ok and path *pt, checked. */
static void check_tree_goal(tree_run_t *tr, int gi, int gj, bool *ok, rfs_path_t *pt)
{
    const double g = tr->g;
    const int gv = gj * tr->lw + gi;
    const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
    *ok = rfs_plan_tree_path(tr->t, x1, y1, pt);
    const uint32_t e = tr->t->expanded;
    tr->total += e;
    const bool los = ref_seg(tr->x0, tr->y0, x1, y1);
    tr->st->goals++;
    /* rfs_plan_path from the same start: the same reachability. */
    rfs_path_t pb;
    const bool okp = rfs_plan_path(tr->pp, tr->x0, tr->y0, x1, y1, &pb);
    assert_int_equal(*ok, okp);
    if (los) {
        tr->st->los++;
        assert_true(*ok);
        assert_int_equal(pt->n, 1);
        assert_int_equal(e, 0);
    }
    if (tr->on_lattice && !los) {
        check_tree_search(tr, gv, *ok, e);
    }
    if (!*ok) {
        tr->st->unreached++;
        assert_int_equal(pt->n, 0);
        return;
    }
    tr->st->reached++;
    check_tree_hops(tr, pt, x1, y1, gv);
    check_tree_against(tr, pt, &pb, x1, y1);
}

/* Trees from several robot positions on one map, a sequence of goals each: every result
 * against the double-precision references (reachability: ref_flood; legality: ref_seg;
 * length: ref_dijkstra; expanded points: the integer octile Dijkstra), against
 * rfs_plan_path for the same start and goal, and against a fresh tree per goal and the
 * goals asked again in reverse order (same paths, bit for bit). Every third tree starts
 * off the lattice (a robot between lattice points) and every third inside the clearance
 * zone (a robot pushed there: its first hop is taken as it is, as rfs_plan_path takes
 * it); there the lattice references do not apply and rfs_plan_path is the comparison. */
static void check_trees(int kind, uint32_t seed, int trees, tree_stats_t *st)
{
    build_kind(kind, seed);
    tree_run_t tr;
    memset(&tr, 0, sizeof(tr));
    tr.lw = wd.m.lw;
    tr.lh = wd.m.lh;
    tr.n = tr.lw * tr.lh;
    tr.g = (double)wd.m.cfg.grid;
    tr.st = st;
    assert_true(tr.n <= LMAX);
    static uint8_t work_f[LMAX], work_p[LMAX];
    static uint32_t queue_f[1024], queue_p[1024];
    rfs_plan_t t, f, pp;
    assert_int_equal(rfs_plan_init(&t, &wd.m, work, sizeof(work), queue, 1024), 0);
    assert_int_equal(rfs_plan_init(&f, &wd.m, work_f, sizeof(work_f), queue_f, 1024), 0);
    assert_int_equal(rfs_plan_init(&pp, &wd.m, work_p, sizeof(work_p), queue_p, 1024), 0);
    tr.t = &t;
    tr.f = &f;
    tr.pp = &pp;
    uint32_t rs = seed * 31u + (uint32_t)kind;
    for (int k = 0; k < trees; k++) {
        tree_root(&tr, k, &rs);
        int gi[TREE_GOALS], gj[TREE_GOALS];
        rfs_path_t pt[TREE_GOALS];
        bool okt[TREE_GOALS];
        tr.c_max = -1;
        tr.total = 0;
        rfs_plan_tree_begin(&t, tr.x0, tr.y0);
        for (int q = 0; q < TREE_GOALS; q++) {
            random_legal(&rs, tr.lw, tr.lh, &gi[q], &gj[q]);
            check_tree_goal(&tr, gi[q], gj[q], &okt[q], &pt[q]);
        }
        /* The same goals again, reversed, on a new tree: the same paths and results. */
        rfs_plan_tree_begin(&t, tr.x0, tr.y0);
        for (int q = TREE_GOALS - 1; q >= 0; q--) {
            const rfs_q16_t x1 = (rfs_q16_t)(tr.g / 2 + gi[q] * tr.g);
            const rfs_q16_t y1 = (rfs_q16_t)(tr.g / 2 + gj[q] * tr.g);
            rfs_path_t pr;
            assert_int_equal(rfs_plan_tree_path(&t, x1, y1, &pr), okt[q]);
            if (okt[q]) {
                assert_same_path(&pt[q], &pr);
            }
        }
    }
}

/* rfs_plan_tree_begin / rfs_plan_tree_path on five kinds of map. */
static void test_tree_paths(void **state)
{
    (void)state;
    tree_stats_t st;
    memset(&st, 0, sizeof(st));
    for (int kind = 0; kind <= 4; kind++) {
        for (uint32_t s = 1; s <= (kind <= 1 ? 3u : 2u); s++) {
            check_trees(kind, s, 12, &st);
        }
    }
    print_message("trees %d (%d rooted in the clearance zone), goals %d (line of sight %d, "
                  "searched from a lattice root %d, of them already closed %d), reached %d, "
                  "unreached %d; worst length / reference %.4f; largest |tree - "
                  "rfs_plan_path| %.4f m (%.2f %%)\n", 12 * 12, st.illegal_roots,
                  st.goals, st.los, st.searched, st.free_hits, st.reached, st.unreached,
                  st.worst_ratio, st.worst_diff_m, 100 * st.worst_diff_rel);
    print_message("tree paths longer than rfs_plan_path's %d, shorter %d, mean difference "
                  "%+.4f m\n", st.longer, st.shorter, st.sum_signed / st.reached);
    assert_true(st.searched >= 200 && st.free_hits >= 40 && st.unreached >= 10);
    assert_true(st.reached >= 300 && st.los >= 20 && st.illegal_roots >= 40);
    /* No bias: either direction's ties are as likely to be longer as shorter. */
    assert_true(fabs(st.sum_signed / st.reached) < 0.02);
}

/* The tree's edges: no tree, a tree ended by rfs_plan_path, a root that joins no lattice
 * point, a goal outside the root's component (refused without a search), an illegal goal,
 * and a queue too small (refused, never overrun, the tree void afterwards). */
static void test_tree_misuse_and_limits(void **state)
{
    (void)state;
    build_kind(4, 1); /* the wall map: (2, 2) m to (2, 6) m goes round the wall's end */
    rfs_plan_t p;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    const rfs_q16_t m1 = RFS_Q16_INT(1);
    rfs_path_t path;
    path.n = 7;
    assert_false(rfs_plan_tree_path(&p, 2 * m1, 6 * m1, &path)); /* never begun */
    assert_int_equal(path.n, 0);
    rfs_plan_tree_begin(&p, 2 * m1, 2 * m1);
    assert_true(rfs_plan_tree_path(&p, 2 * m1, 6 * m1, &path));
    /* Round the wall's end: the cells within 0.25 m of it reach x = 10.8 m, so the path
     * crosses y 4.0 .. 4.2 m east of that: at least hypot(8.8, 2) + 0.2 + hypot(8.8, 1.8)
     * m; its waypoints are lattice points (0.25 m apart) there, so at most 0.7 m more. */
    const double taut = hypot(8.8, 2.0) + 0.2 + hypot(8.8, 1.8);
    const double round = path.length / 65536.0;
    print_message("round the wall's end: %.4f m (at least %.4f m)\n", round, taut);
    assert_true(round >= taut && round < taut + 0.7);
    assert_true(p.expanded > 0);
    rfs_path_t again;
    assert_true(rfs_plan_tree_path(&p, 2 * m1, 6 * m1, &again));
    assert_int_equal(p.expanded, 0);
    assert_same_path(&path, &again);
    assert_false(rfs_plan_tree_path(&p, 2 * m1, 4 * m1, &again)); /* on the wall: illegal */
    assert_true(rfs_plan_path(&p, 2 * m1, 2 * m1, 3 * m1, 2 * m1, &again));
    again.n = 7;
    assert_false(rfs_plan_tree_path(&p, 2 * m1, 6 * m1, &again)); /* ended by rfs_plan_path */
    assert_int_equal(again.n, 0);

    /* A root inside the wall (illegal, no legal point within its 5 x 5): no path. */
    build(5, 0, 0);
    for (int y = 20; y < 60; y++) {
        for (int x = 20; x < 60; x++) {
            wd.free_c[y][x] = 0;
        }
    }
    build_finish();
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    rfs_plan_tree_begin(&p, 4 * m1, 4 * m1);
    assert_false(rfs_plan_tree_path(&p, 7 * m1, 7 * m1, &path));
    assert_false(rfs_plan_tree_path(&p, 8 * m1, 7 * m1, &path));
    assert_int_equal(p.expanded, 0);

    /* The closed room and its component marks: refused without a search from outside. */
    build(5, 0, 1);
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), queue, 1024), 0);
    const int lw = wd.m.lw, lh = wd.m.lh;
    ref_component(lw, lh, 8, 8); /* (2.125, 2.125) m, outside the room */
    rfs_plan_set_component(&p, comp_bits);
    rfs_plan_tree_begin(&p, 2 * m1, 2 * m1);
    assert_false(rfs_plan_tree_path(&p, 9 * m1, 3 * m1, &path));
    assert_int_equal(p.expanded, 0);
    rfs_plan_set_component(&p, NULL);
    assert_false(rfs_plan_tree_path(&p, 9 * m1, 3 * m1, &path)); /* floods the outside */
    assert_true(p.expanded > 1000);
    assert_true(rfs_plan_tree_path(&p, 7 * m1, 3 * m1, &path)); /* all closed by then */
    assert_int_equal(p.expanded, 0);

    /* A queue too small: refused, the guard words intact, later goals refused too. */
    build_kind(4, 1);
    static uint32_t small[8 + 4];
    small[8] = small[9] = small[10] = small[11] = 0xA5A5A5A5u;
    assert_int_equal(rfs_plan_init(&p, &wd.m, work, sizeof(work), small, 8), 0);
    rfs_plan_tree_begin(&p, 2 * m1, 2 * m1);
    assert_false(rfs_plan_tree_path(&p, 2 * m1, 6 * m1, &path));
    assert_false(rfs_plan_tree_path(&p, 3 * m1, 6 * m1, &path));
    assert_int_equal(small[8], 0xA5A5A5A5u);
    assert_int_equal(small[11], 0xA5A5A5A5u);
}


/* A tree grown in slices (rfs_plan_tree_grow) against one searched on demand, from
 * lattice roots on the five kinds of map: a plan before the tree is done either finds
 * its goal closed (the same path, bit for bit) or fails with tree_more; a done tree has
 * closed exactly the reference's reachable points, and gives every goal the on-demand
 * tree's result. Moved to a legal point by its root (rfs_plan_tree_move), its paths
 * start there, legal by the reference geometry. */
static void test_tree_sliced(void **state)
{
    (void)state;
    static uint8_t work_f[LMAX];
    static uint32_t queue_f[1024];
    const uint32_t budgets[3] = {1, 97, 640};
    int before = 0, more = 0, moved = 0;
    for (int kind = 0; kind <= 4; kind++) {
        build_kind(kind, 2);
        const int lw = wd.m.lw, lh = wd.m.lh;
        const double g = (double)wd.m.cfg.grid;
        rfs_plan_t t, f;
        assert_int_equal(rfs_plan_init(&t, &wd.m, work, sizeof(work), queue, 1024), 0);
        assert_int_equal(rfs_plan_init(&f, &wd.m, work_f, sizeof(work_f), queue_f, 1024), 0);
        uint32_t rs = 77u + (uint32_t)kind;
        for (int k = 0; k < 3; k++) {
            int si, sj;
            random_legal(&rs, lw, lh, &si, &sj);
            ref_octile(lw, lh, si, sj);
            int below, upto;
            oct_count(lw * lh, INT32_MAX, &below, &upto);
            const rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
            rfs_plan_tree_begin(&t, x0, y0);
            rfs_plan_tree_begin(&f, x0, y0);
            uint32_t total = 0;
            bool done = false;
            for (int slice = 0; !done; slice++) {
                done = rfs_plan_tree_grow(&t, budgets[k]);
                total += t.expanded;
                assert_true(t.expanded <= budgets[k]);
                assert_true(slice < 20000);
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_path_t pt, pf;
                t.tree_more = false;
                const bool okt = rfs_plan_tree_path(&t, x1, y1, &pt);
                assert_int_equal(t.expanded, 0);
                const bool okf = rfs_plan_tree_path(&f, x1, y1, &pf);
                if (okt) {
                    assert_true(okf);
                    assert_same_path(&pt, &pf);
                } else if (okf) {
                    assert_true(t.tree_more && !done);
                    more++;
                } else {
                    assert_false(t.tree_more && done);
                }
                before += !done;
            }
            assert_int_equal((int)total, upto);
            for (int q = 0; q < 8; q++) {
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_path_t pt, pf;
                t.tree_more = false;
                const bool okt = rfs_plan_tree_path(&t, x1, y1, &pt);
                assert_int_equal(okt, rfs_plan_tree_path(&f, x1, y1, &pf));
                assert_false(t.tree_more);
                assert_int_equal(okt, oct_ref[gj * lw + gi] < INT32_MAX);
                if (okt) {
                    assert_same_path(&pt, &pf);
                }
            }
            /* A robot stopped 0.07 m from the root, or a lattice step away. */
            const rfs_q16_t mx = x0 + RFS_Q16_FRAC(7, 100), my = y0 - RFS_Q16_FRAC(3, 100);
            if (rfs_map_point_legal(&wd.m, mx, my) && ref_seg(mx, my, x0, y0)) {
                assert_true(rfs_plan_tree_move(&t, mx, my, RFS_Q16_ONE));
                moved++;
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_path_t pt;
                if (rfs_plan_tree_path(&t, x1, y1, &pt)) {
                    assert_int_equal(pt.x0, mx);
                    assert_int_equal(pt.y0, my);
                    assert_true(ref_seg(mx, my, pt.x[0], pt.y[0]));
                    for (int w = 1; w < pt.n; w++) {
                        assert_true(ref_seg(pt.x[w - 1], pt.y[w - 1], pt.x[w], pt.y[w]));
                    }
                }
            }
            assert_false(rfs_plan_tree_move(&t, x0 + (rfs_q16_t)(3 * g), y0, (rfs_q16_t)(2 * g)));
        }
    }
    print_message("sliced trees: %d plans before done, %d of them asked for more; %d moved\n",
                  before, more, moved);
    assert_true(before > 50 && more > 10 && moved >= 5);
}

/* rfs_plan_tree_length on the five kinds of map, lattice roots: false exactly where the
 * tree's plan fails; in line of sight the straight distance; else at least the pulled
 * path's length and at most the reference lattice optimum (double Euclidean Dijkstra)
 * times 1.0607 (octile costs) plus a millimetre of rounding. */
static void test_tree_length(void **state)
{
    (void)state;
    int checked = 0, searched = 0;
    for (int kind = 0; kind <= 4; kind++) {
        build_kind(kind, 3);
        const int lw = wd.m.lw, lh = wd.m.lh;
        const double g = (double)wd.m.cfg.grid;
        rfs_plan_t t;
        assert_int_equal(rfs_plan_init(&t, &wd.m, work, sizeof(work), queue, 1024), 0);
        uint32_t rs = 991u + (uint32_t)kind;
        for (int k = 0; k < 3; k++) {
            int si, sj;
            random_legal(&rs, lw, lh, &si, &sj);
            (void)ref_dijkstra(lw, lh, si, sj, -1, -1);
            const rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
            rfs_plan_tree_begin(&t, x0, y0);
            for (int q = 0; q < 12; q++) {
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_q16_t len = -1;
                const bool okl = rfs_plan_tree_length(&t, x1, y1, &len);
                rfs_path_t pt;
                const bool okp = rfs_plan_tree_path(&t, x1, y1, &pt);
                assert_int_equal(okl, okp);
                if (!okl) {
                    assert_int_equal(len, 0);
                    continue;
                }
                checked++;
                const double l = len / 65536.0;
                if (ref_seg(x0, y0, x1, y1)) {
                    assert_true(fabs(l - hypot(x1 - x0, y1 - y0) / 65536.0) < 1e-4);
                    continue;
                }
                searched++;
                assert_true(l >= pt.length / 65536.0 - 1e-3);
                assert_true(l <= dist_ref[gj * lw + gi] / 65536.0 * 1.0607 + 1e-3);
            }
        }
    }
    print_message("tree lengths: %d goals, %d round obstacles\n", checked, searched);
    assert_true(checked >= 100 && searched >= 40);
}

/* A done tree moved to a robot near its start (rfs_plan_tree_move: a leg cut short or a
 * base braked past the point the tree was begun at; docs/PERFORMANCE.md, "Planning in
 * slices"): starts off the lattice, robots up to 1.2 m away, hop 1 m (160 trees a map).
 * Moved, the robot sees its join point by a legal segment (the reference geometry) and
 * the hop plus the reference's lattice distance from there to the root is at most 1 m;
 * every path starts at the robot, is legal hop by hop, its length the double-precision
 * sum of its hops, at least the straight distance and at most the hop plus 1.0607 times
 * the reference's lattice distance from the root; the tree length bounds it from above;
 * reachability is the reference's; the tree is unchanged by them. Refused, the tree is
 * unchanged. */
static void test_tree_hop(void **state)
{
    (void)state;
    int moved = 0, off_root = 0, paths = 0, refused = 0;
    for (int kind = 0; kind <= 4; kind++) {
        build_kind(kind, 5);
        const int lw = wd.m.lw, lh = wd.m.lh;
        const double g = (double)wd.m.cfg.grid;
        rfs_plan_t t;
        assert_int_equal(rfs_plan_init(&t, &wd.m, work, sizeof(work), queue, 1024), 0);
        uint32_t rs = 4242u + (uint32_t)kind;
        for (int k = 0; k < 160; k++) {
            int si, sj;
            random_legal(&rs, lw, lh, &si, &sj);
            const rfs_q16_t ex = (rfs_q16_t)(g / 2 + si * g + ((int)(lcg(&rs) % 1001u) - 500) * g / 1000);
            const rfs_q16_t ey = (rfs_q16_t)(g / 2 + sj * g + ((int)(lcg(&rs) % 1001u) - 500) * g / 1000);
            const rfs_q16_t qx = ex + (rfs_q16_t)(((int)(lcg(&rs) % 2401u) - 1200) * 65536.0 / 1000);
            const rfs_q16_t qy = ey + (rfs_q16_t)(((int)(lcg(&rs) % 2401u) - 1200) * 65536.0 / 1000);
            if (!rfs_map_point_legal(&wd.m, ex, ey) || qx < 0 || qy < 0 ||
                !rfs_map_point_legal(&wd.m, qx, qy)) {
                continue;
            }
            rfs_plan_tree_begin(&t, ex, ey);
            for (int slice = 0; !rfs_plan_tree_grow(&t, 640u); slice++) {
                assert_true(slice < 100);
            }
            assert_int_equal(t.tree, 2);
            const int ri = (int)(t.tree_root % (uint32_t)lw), rj = (int)(t.tree_root / (uint32_t)lw);
            (void)ref_dijkstra(lw, lh, ri, rj, -1, -1);
            if (!rfs_plan_tree_move(&t, qx, qy, RFS_Q16_ONE)) {
                assert_int_equal(t.tree_x, ex);
                assert_int_equal(t.tree_y, ey);
                assert_int_equal(t.tree_from, t.tree_root);
                refused++;
                continue;
            }
            moved++;
            off_root += t.tree_from != t.tree_root;
            const double jx = g / 2 + (t.tree_from % (uint32_t)lw) * g;
            const double jy = g / 2 + (t.tree_from / (uint32_t)lw) * g;
            assert_int_equal(t.tree_x, qx);
            assert_int_equal(t.tree_y, qy);
            assert_true(ref_seg(qx, qy, jx, jy));
            assert_true((hypot(qx - jx, qy - jy) + dist_ref[t.tree_from]) / 65536.0 <= 1.0 + 1e-4);
            static uint8_t before[LMAX];
            memcpy(before, work, (size_t)(lw * lh));
            for (int q = 0; q < 6; q++) {
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_path_t pt;
                const bool ok = rfs_plan_tree_path(&t, x1, y1, &pt);
                rfs_q16_t len = -1;
                assert_int_equal(rfs_plan_tree_length(&t, x1, y1, &len), ok);
                const double d = dist_ref[gj * lw + gi];
                assert_int_equal(ok, !isinf(d) || ref_seg(qx, qy, x1, y1));
                if (!ok) {
                    continue;
                }
                paths++;
                assert_int_equal(pt.x0, qx);
                assert_int_equal(pt.y0, qy);
                double sum = ref_path_len(qx, qy, &pt);
                assert_int_equal(pt.x[pt.n - 1], x1);
                assert_int_equal(pt.y[pt.n - 1], y1);
                const double l = pt.length / 65536.0;
                assert_true(fabs(l - sum) < 1e-4 * pt.n + 1e-4);
                assert_true(l >= hypot(x1 - qx, y1 - qy) / 65536.0 - 1e-4);
                if (!isinf(d)) {
                    assert_true(l <= 1.0 + d / 65536.0 * 1.0607 + 1e-3);
                }
                assert_true(len / 65536.0 >= l - 1e-3);
            }
            assert_memory_equal(before, work, (size_t)(lw * lh)); /* the walks left the tree as it was */
        }
    }
    print_message("tree hops: %d moved (%d off the root), %d refused, %d paths\n", moved,
                  off_root, refused, paths);
    assert_true(moved >= 150 && off_root >= 100 && refused >= 40 && paths >= 800);
}

/* The map's edge table (rfs_map_edges_attach and rfs_plan_use_edges, with the lattice
 * memo as the simulator attaches both; the table filled as the searches read it) against
 * exact_edges, which tests positions and rfs_map_segment_legal for every edge: on the
 * five kinds of map, plans and trees give the same paths bit for bit after the same
 * number of expansions, reachability as the reference's octile Dijkstra, and a queue
 * too small overflows both alike. */
static void test_edge_table(void **state)
{
    (void)state;
    static uint8_t work_e[LMAX];
    static uint32_t queue_e[1024];
    static uint16_t memo[LMAX];
    static uint16_t table[LMAX];
    int reached = 0, unreached = 0;
    for (int kind = 0; kind <= 4; kind++) {
        build_kind(kind, 3);
        const int lw = wd.m.lw, lh = wd.m.lh;
        const double g = (double)wd.m.cfg.grid;
        assert_int_equal(rfs_map_memo_attach(&wd.m, memo, LMAX), 0);
        assert_int_equal(rfs_map_edges_attach(&wd.m, table, LMAX), 0);
        rfs_plan_t f, e;
        assert_int_equal(rfs_plan_init(&f, &wd.m, work, sizeof(work), queue, 1024), 0);
        assert_int_equal(rfs_plan_init(&e, &wd.m, work_e, sizeof(work_e), queue_e, 1024), 0);
        rfs_plan_use_edges(&f);
        e.exact_edges = true;
        uint32_t rs = 901u + (uint32_t)kind;
        for (int k = 0; k < 12; k++) {
            int si, sj;
            random_legal(&rs, lw, lh, &si, &sj);
            ref_octile(lw, lh, si, sj);
            const rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
            rfs_plan_tree_begin(&f, x0, y0);
            rfs_plan_tree_begin(&e, x0, y0);
            for (int q = 0; q < 4; q++) {
                int gi, gj;
                random_legal(&rs, lw, lh, &gi, &gj);
                const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
                rfs_path_t pf, pe;
                const bool ok = rfs_plan_tree_path(&f, x1, y1, &pf);
                assert_int_equal(ok, rfs_plan_tree_path(&e, x1, y1, &pe));
                assert_int_equal(f.expanded, e.expanded);
                assert_int_equal(ok, oct_ref[gj * lw + gi] < INT32_MAX || ref_seg(x0, y0, x1, y1));
                if (ok) {
                    assert_same_path(&pf, &pe);
                }
            }
            int gi, gj;
            random_legal(&rs, lw, lh, &gi, &gj);
            const rfs_q16_t x1 = (rfs_q16_t)(g / 2 + gi * g), y1 = (rfs_q16_t)(g / 2 + gj * g);
            rfs_path_t pf, pe;
            const bool ok = rfs_plan_path(&f, x0, y0, x1, y1, &pf);
            assert_int_equal(ok, rfs_plan_path(&e, x0, y0, x1, y1, &pe));
            assert_int_equal(f.expanded, e.expanded);
            assert_int_equal(ok, oct_ref[gj * lw + gi] < INT32_MAX || ref_seg(x0, y0, x1, y1));
            reached += ok;
            unreached += !ok;
            if (ok) {
                assert_same_path(&pf, &pe);
            }
        }
        int known = 0;
        for (int k = 0; k < lw * lh; k++) {
            known += (table[k] & RFS_MAP_EDGES_KNOWN) != 0u;
        }
        assert_true(known > lw * lh / 4);
        if (kind == 1) { /* into the closed room from outside: both fail */
            rfs_path_t pf, pe;
            const rfs_q16_t m1 = RFS_Q16_INT(1);
            assert_false(rfs_plan_path(&f, 2 * m1, 2 * m1, 9 * m1, 3 * m1, &pf));
            assert_false(rfs_plan_path(&e, 2 * m1, 2 * m1, 9 * m1, 3 * m1, &pe));
            assert_int_equal(f.expanded, e.expanded);
            unreached++;
        }
        if (kind == 4) { /* round the wall: an 8-entry queue (two a ring) overflows on both */
            rfs_path_t pf, pe;
            const rfs_q16_t m1 = RFS_Q16_INT(1);
            assert_true(rfs_plan_path(&f, 2 * m1, 2 * m1, 2 * m1, 6 * m1, &pf));
            assert_int_equal(rfs_plan_init(&f, &wd.m, work, sizeof(work), queue, 8), 0);
            rfs_plan_use_edges(&f);
            assert_int_equal(rfs_plan_init(&e, &wd.m, work_e, sizeof(work_e), queue_e, 8), 0);
            e.exact_edges = true;
            assert_false(rfs_plan_path(&f, 2 * m1, 2 * m1, 2 * m1, 6 * m1, &pf));
            assert_false(rfs_plan_path(&e, 2 * m1, 2 * m1, 2 * m1, 6 * m1, &pe));
            assert_int_equal(f.expanded, e.expanded);
        }
    }
    print_message("edge table: %d plans reached, %d not\n", reached, unreached);
    assert_true(reached >= 40 && unreached >= 1);
}

/* One step of test_tree_deferred: the same goal on the tree grown at once (t) and the
 * deferred one (d): path, length and tree_more alike. */
static void check_deferred_goal(rfs_plan_t *t, rfs_plan_t *d, rfs_q16_t x1, rfs_q16_t y1)
{
    rfs_path_t pt, pd;
    t->tree_more = d->tree_more = false;
    const bool ok = rfs_plan_tree_path(t, x1, y1, &pt);
    assert_int_equal(ok, rfs_plan_tree_path(d, x1, y1, &pd));
    assert_int_equal(t->tree_more, d->tree_more);
    if (ok) {
        assert_same_path(&pt, &pd);
    }
    rfs_q16_t lt = -1, ld = -2;
    t->tree_more = d->tree_more = false;
    assert_int_equal(rfs_plan_tree_length(t, x1, y1, &lt), rfs_plan_tree_length(d, x1, y1, &ld));
    assert_int_equal(lt, ld);
    assert_int_equal(t->tree_more, d->tree_more);
}

/* The closed room (kind 1) of test_tree_deferred: planners t (on work, queue) and d
 * (deferred, on work_d, queue_d), no tree begun; *x0, *y0 the lattice point nearest (2, 2)
 * m. Returns the points a root there reaches (the double reference's count). */
static int closed_room_trees(rfs_plan_t *t, rfs_plan_t *d, uint8_t *work_d, size_t nwork_d,
                             uint32_t *queue_d, rfs_q16_t *x0, rfs_q16_t *y0)
{
    build_kind(1, 4);
    const int lw = wd.m.lw, lh = wd.m.lh;
    uint16_t si, sj;
    rfs_map_lattice_nearest(&wd.m, RFS_Q16_INT(2), RFS_Q16_INT(2), &si, &sj);
    ref_octile(lw, lh, si, sj);
    int below, upto;
    oct_count(lw * lh, INT32_MAX, &below, &upto);
    assert_int_equal(rfs_plan_init(t, &wd.m, work, sizeof(work), queue, 1024), 0);
    assert_int_equal(rfs_plan_init(d, &wd.m, work_d, (uint32_t)nwork_d, queue_d, 1024), 0);
    rfs_plan_tree_defer(d, true);
    rfs_map_lattice_point(&wd.m, si, sj, x0, y0);
    return upto;
}

/* rfs_plan_tree_defer: grows of random budgets (0 to 300 points) on a tree searched at
 * once and on a deferred one, each followed by plans, lengths and a move near the root:
 * the same answers and tree_more flags all along, on the five kinds of map; the deferred
 * grows themselves expand nothing. Then the edge of "done": grows summing to exactly the
 * points the root reaches (the reference's count) leave both not done (a goal in the
 * closed room asks for more), one more point makes both done. */
static void test_tree_deferred(void **state)
{
    (void)state;
    static uint8_t work_d[LMAX];
    static uint32_t queue_d[1024];
    const uint32_t budgets[5] = {0, 1, 5, 37, 300};
    int more = 0, moved = 0, grows = 0;
    for (int kind = 0; kind <= 4; kind++) {
        build_kind(kind, 4);
        const int lw = wd.m.lw, lh = wd.m.lh;
        const double g = (double)wd.m.cfg.grid;
        rfs_plan_t t, d;
        assert_int_equal(rfs_plan_init(&t, &wd.m, work, sizeof(work), queue, 1024), 0);
        assert_int_equal(rfs_plan_init(&d, &wd.m, work_d, sizeof(work_d), queue_d, 1024), 0);
        rfs_plan_tree_defer(&d, true);
        uint32_t rs = 313u + (uint32_t)kind;
        for (int k = 0; k < 3; k++) {
            int si, sj;
            random_legal(&rs, lw, lh, &si, &sj);
            const rfs_q16_t x0 = (rfs_q16_t)(g / 2 + si * g), y0 = (rfs_q16_t)(g / 2 + sj * g);
            rfs_plan_tree_begin(&t, x0, y0);
            rfs_plan_tree_begin(&d, x0, y0);
            int after = 0;
            for (int slice = 0; after < 3; slice++) {
                assert_true(slice < 5000);
                const uint32_t b = budgets[lcg(&rs) % 5u];
                after += rfs_plan_tree_grow(&t, b);
                (void)rfs_plan_tree_grow(&d, b);
                assert_int_equal(d.expanded, 0);
                grows++;
                for (int q = 0; q < 2; q++) {
                    int gi, gj;
                    random_legal(&rs, lw, lh, &gi, &gj);
                    check_deferred_goal(&t, &d, (rfs_q16_t)(g / 2 + gi * g), (rfs_q16_t)(g / 2 + gj * g));
                    more += t.tree_more;
                }
                if (lcg(&rs) % 8u == 0u) {
                    const rfs_q16_t mx = x0 + (rfs_q16_t)(lcg(&rs) % 20000u) - 10000;
                    const rfs_q16_t my = y0 + (rfs_q16_t)(lcg(&rs) % 20000u) - 10000;
                    const bool ok = rfs_plan_tree_move(&t, mx, my, RFS_Q16_ONE);
                    assert_int_equal(ok, rfs_plan_tree_move(&d, mx, my, RFS_Q16_ONE));
                    assert_int_equal(t.tree_from, d.tree_from);
                    moved += ok;
                }
            }
        }
    }
    /* The closed room (kind 1): a root outside reaches `upto` points, none inside. */
    const rfs_q16_t m1 = RFS_Q16_INT(1);
    rfs_plan_t t, d;
    rfs_q16_t x0, y0;
    const int upto = closed_room_trees(&t, &d, work_d, sizeof(work_d), queue_d, &x0, &y0);
    rfs_plan_tree_begin(&t, x0, y0);
    rfs_plan_tree_begin(&d, x0, y0);
    assert_false(rfs_plan_tree_grow(&t, (uint32_t)upto - 100u));
    assert_false(rfs_plan_tree_grow(&d, (uint32_t)upto - 100u));
    assert_false(rfs_plan_tree_grow(&t, 100u));
    assert_false(rfs_plan_tree_grow(&d, 100u));
    check_deferred_goal(&t, &d, 9 * m1, 3 * m1);
    assert_true(t.tree_more);
    assert_false(rfs_plan_tree_grow(&t, 1u) == false);
    (void)rfs_plan_tree_grow(&d, 1u);
    check_deferred_goal(&t, &d, 9 * m1, 3 * m1);
    assert_false(t.tree_more);
    assert_true(rfs_plan_tree_grow(&d, 0u)); /* the plan found it done */
    print_message("deferred trees: %d grows, %d plans asked for more, %d moves\n", grows, more,
                  moved);
    assert_true(grows > 250 && more > 50 && moved > 10);
}
/* rfs_plan_tree_grown: true with no tree, false for a tree begun and while its search has
 * points left; a deferred tree pays its debt and answers as the undeferred one, at the edge
 * of "done" (the closed room of test_tree_deferred: grows summing to the points the root
 * reaches are not done, one more point is). */
static void test_tree_grown(void **state)
{
    (void)state;
    static uint8_t work_d[LMAX];
    static uint32_t queue_d[1024];
    const rfs_q16_t m1 = RFS_Q16_INT(1);
    rfs_plan_t t, d;
    rfs_q16_t x0, y0;
    const int upto = closed_room_trees(&t, &d, work_d, sizeof(work_d), queue_d, &x0, &y0);
    assert_true(rfs_plan_tree_grown(&t));
    rfs_plan_tree_begin(&t, x0, y0);
    rfs_plan_tree_begin(&d, x0, y0);
    assert_false(rfs_plan_tree_grown(&t));
    assert_false(rfs_plan_tree_grown(&d));
    (void)rfs_plan_tree_grow(&t, (uint32_t)upto - 100u);
    (void)rfs_plan_tree_grow(&d, (uint32_t)upto - 100u);
    assert_false(rfs_plan_tree_grown(&t));
    assert_false(rfs_plan_tree_grown(&d));
    assert_int_equal(d.expanded, upto - 100); /* the debt paid here */
    (void)rfs_plan_tree_grow(&t, 100u);
    (void)rfs_plan_tree_grow(&d, 100u);
    assert_false(rfs_plan_tree_grown(&t));
    assert_false(rfs_plan_tree_grown(&d));
    (void)rfs_plan_tree_grow(&t, 1u);
    (void)rfs_plan_tree_grow(&d, 1u);
    assert_true(rfs_plan_tree_grown(&t));
    assert_true(rfs_plan_tree_grown(&d));
    check_deferred_goal(&t, &d, 9 * m1, 3 * m1);
    assert_false(t.tree_more);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tree_paths),
        cmocka_unit_test(test_tree_misuse_and_limits),
        cmocka_unit_test(test_tree_sliced),
        cmocka_unit_test(test_tree_length),
        cmocka_unit_test(test_tree_hop),
        cmocka_unit_test(test_edge_table),
        cmocka_unit_test(test_tree_deferred),
        cmocka_unit_test(test_tree_grown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
