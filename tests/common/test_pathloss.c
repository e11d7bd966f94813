/* test_pathloss.c - the map-aware path-loss model (common/rfs_pathloss).
 *
 * Data: an office built here (30 x 16 m, 0.1 m cells: a corridor between two rows of
 * rooms, doors 1 m wide) and samples at random legal positions whose values follow the
 * model with a known source, P0, n and W plus small Gaussian noise. Expected values come
 * from the truth that generated the data and from the double-precision reference of
 * the same search (ref_pathloss.h), never from the code under test.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ref_pathloss.h"
#include "rfs_models.h"
#include "rfs_pathloss.h"
#include "rfs_seek.h"

#define MW 300
#define MH 160
#define RES_Q16 6554 /* 0.1 m as the map loader rounds it */
#define NS 2000

typedef struct fixture {
    uint8_t free_bits[MH * ((MW + 7) / 8)];
    uint8_t wall_bits[MH * ((MW + 7) / 8)];
    uint8_t legal_bits[MH * ((MW + 7) / 8)];
    rfs_map_t map;
    rfs_sample_t s[NS];
    rfs_pathloss_t pl;
    ref_pl_t ref;
} fixture_t;

static bool is_wall(int i, int j)
{
    if (i == 0 || j == 0 || i == MW - 1 || j == MH - 1) {
        return true;
    }
    bool door = (i >= 40 && i < 50) || (i >= 140 && i < 150) || (i >= 240 && i < 250);
    if ((j == 70 || j == 90) && !door) {
        return true;
    }
    return (i == 100 || i == 200) && (j < 70 || j > 90);
}

static int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof(*f));
    assert_non_null(f);
    uint16_t stride = (MW + 7) / 8;
    for (int j = 0; j < MH; ++j) {
        for (int i = 0; i < MW; ++i) {
            rfs_map_bit_set(f->wall_bits, stride, (uint16_t)i, (uint16_t)j, is_wall(i, j));
            rfs_map_bit_set(f->free_bits, stride, (uint16_t)i, (uint16_t)j, !is_wall(i, j));
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&f->map, &mc, MW, MH, RES_Q16, 0, 0, f->free_bits,
                                  f->wall_bits, f->legal_bits), 0);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    free(*state);
    return 0;
}

static double gauss(rfs_rng_t *r)
{
    double u1 = ((double)rfs_rng_u32(r) + 1.0) / 4294967297.0;
    double u2 = (double)rfs_rng_u32(r) / 4294967296.0;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

typedef struct truth {
    double sx, sy, p0, n, w, noise;
} truth_t;

/* n samples at random legal points of the map (or anywhere in [0, 30] x [0, 16] m when
 * map is NULL), valued by the model with the truth's parameters; walls counted from the
 * sample's exact position to the source. */
static void make_samples(rfs_sample_t *s, int n, const rfs_map_t *map, const truth_t *t,
                         uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    rfs_q16_t qsx = (rfs_q16_t)lround(t->sx * 65536.0), qsy = (rfs_q16_t)lround(t->sy * 65536.0);
    for (int i = 0; i < n;) {
        int xc = (int)rfs_rng_below(&r, 3001), yc = (int)rfs_rng_below(&r, 1601);
        rfs_q16_t qx = (rfs_q16_t)lround(xc / 100.0 * 65536.0);
        rfs_q16_t qy = (rfs_q16_t)lround(yc / 100.0 * 65536.0);
        if (map != NULL && !rfs_map_point_legal(map, qx, qy)) {
            continue;
        }
        double d = hypot(xc / 100.0 - t->sx, yc / 100.0 - t->sy);
        int k = map != NULL ? rfs_map_walls_crossed(map, qx, qy, qsx, qsy) : 0;
        double v = t->p0 - 10.0 * t->n * log10(d < 1.0 ? 1.0 : d) - t->w * k + t->noise * gauss(&r);
        s[i].x_cm = (int16_t)xc;
        s[i].y_cm = (int16_t)yc;
        s[i].v_q6 = (int16_t)lround(v * 64.0);
        ++i;
    }
}

/* The estimator without its strong prior: a prior of weight 1 and every sample counted
 * (bin_cap at its maximum), for checks against the truth that generated the data. */
static rfs_pathloss_cfg_t weak_cfg(void)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    c.prior_weight = RFS_Q16_ONE;
    c.w_prior_weight = RFS_Q16_ONE;
    c.bin_cap = UINT16_MAX;
    return c;
}

static ref_pl_cfg_t weak_ref(void)
{
    ref_pl_cfg_t c = ref_pl_cfg_default();
    c.prior_weight = 1.0;
    c.w_prior_weight = 1.0;
    c.bin_cap = UINT16_MAX;
    return c;
}

static rfs_pathloss_est_t fit_in_with(fixture_t *f, const rfs_pathloss_cfg_t *c,
                                      const rfs_model_fit_in_t *in, uint32_t budget, int *calls);

static rfs_pathloss_est_t fit_with(fixture_t *f, const rfs_pathloss_cfg_t *c, int n,
                                   const rfs_map_t *map, uint32_t budget, int *calls)
{
    rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = map};
    return fit_in_with(f, c, &in, budget, calls);
}

/* A whole (budget 0) or sliced fit of `in` from a fresh model. */
static rfs_pathloss_est_t fit_in_with(fixture_t *f, const rfs_pathloss_cfg_t *c,
                                      const rfs_model_fit_in_t *in, uint32_t budget, int *calls)
{
    assert_int_equal(rfs_pathloss_init(&f->pl, c), 0);
    rfs_model_t m = rfs_pathloss_model(&f->pl);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_fit_result_t r;
    int k = 0;
    do {
        r = m.ops->fit(m.self, in, budget, &rng);
        ++k;
    } while (r == RFS_FIT_MORE && k < 100000);
    assert_int_equal(r, RFS_FIT_DONE);
    if (calls != NULL) {
        *calls = k;
    }
    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    return e;
}

static rfs_pathloss_est_t fit_default(fixture_t *f, int n, const rfs_map_t *map, uint32_t budget,
                                      int *calls)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    return fit_with(f, &c, n, map, budget, calls);
}

/* n and W away from the default prior (3, 5 dB), so that recovering them means something. */
static const truth_t k_office = {15.125, 3.375, -35.0, 2.6, 6.5, 0.3};

/* --- configuration --------------------------------------------------------------------- */

static void init_rejects_bad_configurations(void **state)
{
    fixture_t *f = *state;
    rfs_pathloss_cfg_t good = rfs_pathloss_cfg_default();
    rfs_pathloss_cfg_t bad[22];
    for (int i = 0; i < 22; ++i) {
        bad[i] = good;
    }
    bad[0].bin = RFS_Q16_FRAC(1, 20);
    bad[1].coarse = 0;
    bad[2].coarse = RFS_Q16_INT(65);
    bad[3].top = 0;
    bad[4].top = RFS_PATHLOSS_MAX_TOP + 1u;
    bad[5].n_min = 0;
    bad[6].n_max = RFS_Q16_INT(1);           /* below n_min */
    bad[7].w_min = -1;
    bad[8].n_prior = RFS_Q16_INT(6);         /* outside [n_min, n_max] */
    bad[9].prior_weight = 0;
    bad[10].huber = 0;
    bad[11].margin = RFS_Q16_INT(101);
    bad[12].bin_cap = 0;
    bad[13].w_prior_weight = 0;
    bad[14].footprint = -1;
    bad[15].footprint = good.bin / 2 + 1;      /* beyond the bin */
    bad[16].sample_t = RFS_Q16_FRAC(1, 16) - 1;
    bad[17].sample_t = RFS_Q16_INT(64) + 1;
    bad[18].coarse_footprint = -2;
    bad[19].coarse_footprint = good.bin / 2 + 1;
    bad[20].p0_max_wall = -1;
    bad[21].p0_max_wall = RFS_Q16_INT(60) + 1;

    assert_int_equal(rfs_pathloss_init(&f->pl, &good), 0);
    for (int i = 0; i < 22; ++i) {
        if (rfs_pathloss_init(&f->pl, &bad[i]) != -1) {
            fail_msg("bad configuration %d accepted", i);
        }
    }
    assert_int_equal(rfs_pathloss_init(NULL, &good), -1);
    assert_int_equal(rfs_pathloss_init(&f->pl, NULL), -1);
}

static void no_samples_no_model(void **state)
{
    fixture_t *f = *state;
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in = {.samples = f->s, .n = 0, .map = &f->map};
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_q16_t v, x, y;
    rfs_pathloss_est_t e;

    rfs_fit_result_t r = rfs_pathloss_ops.fit(&f->pl, &in, 0, &rng);

    assert_int_equal(r, RFS_FIT_FAILED);
    assert_false(rfs_pathloss_ops.predict(&f->pl, 0, 0, &v));
    assert_false(rfs_pathloss_ops.argmax(&f->pl, &x, &y));
    assert_false(rfs_pathloss_estimate(&f->pl, &e));
}

/* --- arithmetic ------------------------------------------------------------------------ */

static void db_dist_matches_double(void **state)
{
    (void)state;
    rfs_rng_t r;
    rfs_rng_seed(&r, 3);
    double worst = 0;
    for (int i = 0; i < 20000; ++i) {
        /* log-uniform squared distances from 2^-32 m^2 to (30 km)^2, Q32 */
        double e = (double)rfs_rng_u32(&r) / 4294967296.0 * 61.7;
        uint64_t d2 = (uint64_t)pow(2.0, e);
        double d = sqrt((double)d2 / 4294967296.0);
        double want = 10.0 * log10(d < 1.0 ? 1.0 : d);

        double got = rfs_pathloss_db_dist(d2) / 65536.0;

        worst = fmax(worst, fabs(got - want));
    }
    if (worst > 1e-4) {
        fail_msg("10 log10(d) off by %.2e dB", worst);
    }
    assert_int_equal(rfs_pathloss_db_dist(0), 0);
    assert_int_equal(rfs_pathloss_db_dist((uint64_t)1 << 32), 0);
    /* the largest input, (65536 m)^2: 10 log10(65536) = 48.16 dB */
    long want = lround(10.0 * log10(65536.0) * 65536.0);
    assert_true(labs(rfs_pathloss_db_dist(UINT64_MAX) - want) <= 2);
}

/* --- the fit against the truth and against the reference -------------------------------- */

static void fit_recovers_source_n_and_w(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = weak_cfg();

    rfs_pathloss_est_t e = fit_with(f, &c, NS, &f->map, 0, NULL);

    double ex = e.sx / 65536.0 - k_office.sx, ey = e.sy / 65536.0 - k_office.sy;
    if (fabs(ex) > 0.25 + 1e-4 || fabs(ey) > 0.25 + 1e-4) {
        fail_msg("source (%.3f, %.3f), truth (%.3f, %.3f)", e.sx / 65536.0, e.sy / 65536.0,
                 k_office.sx, k_office.sy);
    }
    if (fabs(e.n / 65536.0 - k_office.n) > 0.1 * k_office.n) {
        fail_msg("n %.3f, truth %.3f", e.n / 65536.0, k_office.n);
    }
    if (fabs(e.w / 65536.0 - k_office.w) > 0.1 * k_office.w) {
        fail_msg("W %.3f, truth %.3f", e.w / 65536.0, k_office.w);
    }
    assert_true(e.bins > 100 && e.bins <= RFS_PATHLOSS_MAX_BINS);
    assert_int_equal(e.bin, RFS_Q16_ONE);
    assert_true(e.rms < RFS_Q16_INT(2));
}

/* Compare everything the core reports with the double reference on the same data. */
static void expect_same_as_reference(fixture_t *f, const rfs_pathloss_cfg_t *c, int n,
                                     const rfs_map_t *map, const ref_pl_cfg_t *rc, double n_tol)
{
    /* The reference's places ruled out, to the model in Q16.16. */
    int16_t ex[8], ey[8];
    for (int k = 0; k < rc->nexcl; ++k) {
        ex[k] = (int16_t)lround(rc->ex[k] * 100.0);
        ey[k] = (int16_t)lround(rc->ey[k] * 100.0);
        assert_true(fabs(ex[k] / 100.0 - rc->ex[k]) < 1e-9); /* centimetres exactly */
    }
    rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = map, .excl_x_cm = ex,
                             .excl_y_cm = ey, .nexcl = (uint8_t)rc->nexcl,
                             .excl_r = (rfs_q16_t)lround(rc->excl_r * 65536.0)};
    rfs_pathloss_est_t e = fit_in_with(f, c, &in, 0, NULL);
    assert_true(ref_pl_fit(&f->ref, f->s, n, map, rc));
    const ref_pl_t *r = &f->ref;

    if (fabs(e.sx / 65536.0 - r->sx) > 1e-3 || fabs(e.sy / 65536.0 - r->sy) > 1e-3) {
        fail_msg("source (%.3f, %.3f), reference (%.3f, %.3f)", e.sx / 65536.0, e.sy / 65536.0,
                 r->sx, r->sy);
    }
    if (fabs(e.n / 65536.0 - r->n) > n_tol || fabs(e.w / 65536.0 - r->w) > 10 * n_tol ||
        fabs(e.p0 / 65536.0 - r->p0) > 20 * n_tol) {
        fail_msg("n %.4f W %.4f P0 %.4f, reference %.4f %.4f %.4f", e.n / 65536.0,
                 e.w / 65536.0, e.p0 / 65536.0, r->n, r->w, r->p0);
    }
    assert_int_equal(e.bins, r->nbins);
    assert_int_equal(e.candidates, (uint32_t)r->candidates);
    uint16_t ncx, ncy;
    rfs_pathloss_surface_size(&f->pl, &ncx, &ncy);
    assert_int_equal(ncx, r->ncx);
    assert_int_equal(ncy, r->ncy);
    double worst = 0;
    for (int cj = 0; cj < ncy; ++cj) {
        for (int ci = 0; ci < ncx; ++ci) {
            rfs_q16_t x, y, rms;
            bool ok = rfs_pathloss_residual_at(&f->pl, (uint16_t)ci, (uint16_t)cj, &x, &y, &rms);
            double want = r->surface[cj * ncx + ci];
            if (ok == isnan(want)) {
                fail_msg("coarse (%d, %d): candidate %d, reference %d", ci, cj, ok, !isnan(want));
            }
            assert_true(fabs(x / 65536.0 - (r->ox + (r->c0i + ci * r->cs) * r->grid)) < 1e-4);
            assert_true(fabs(y / 65536.0 - (r->oy + (r->c0j + cj * r->cs) * r->grid)) < 1e-4);
            if (ok) {
                worst = fmax(worst, fabs(rms / 65536.0 - want));
            }
        }
    }
    /* 0.03 dB: where the P0 floor or ceiling adds to a loss, P0's rounding moves the
     * surface by huber / rms per dB (0.027 dB at one coarse point of the ceiling tests). */
    if (worst > 0.03) {
        fail_msg("residual surface off by %.4f dB", worst);
    }
}

static void same_cell_as_double_reference_office(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default(), cw = weak_cfg();
    ref_pl_cfg_t rc = ref_pl_cfg_default(), rw = weak_ref();

    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    expect_same_as_reference(f, &cw, NS, &f->map, &rw, 0.01);
}

/* Places ruled out (rfs_model_fit_in_t.excl_x, the seeker's refute_r): no candidate
 * within the radius of one, against the reference's search without them. A disk round
 * the true source moves the estimate out of it; sliced = whole with the disks. */
static void places_ruled_out_same_as_reference(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    rc.nexcl = 2;
    rc.ex[0] = 15.13; /* the true source (15.125, 3.375) to the centimetre */
    rc.ey[0] = 3.38;
    rc.ex[1] = 4.0; /* another room: a hole in the coarse grid */
    rc.ey[1] = 12.0;
    rc.excl_r = 2.0;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    const double dx = f->ref.sx - k_office.sx, dy = f->ref.sy - k_office.sy;
    assert_true(sqrt(dx * dx + dy * dy) > 1.99);

    int16_t ex[2] = {1513, 400};
    int16_t ey[2] = {338, 1200};
    rfs_model_fit_in_t in = {.samples = f->s, .n = NS, .map = &f->map, .excl_x_cm = ex,
                             .excl_y_cm = ey, .nexcl = 2, .excl_r = RFS_Q16_INT(2)};
    rfs_pathloss_est_t whole = fit_in_with(f, &c, &in, 0, NULL);
    int calls = 0;
    rfs_pathloss_est_t sliced = fit_in_with(f, &c, &in, 7, &calls);
    assert_true(calls > 10);
    assert_int_equal(sliced.sx, whole.sx);
    assert_int_equal(sliced.sy, whole.sy);
    assert_int_equal(sliced.candidates, whole.candidates);
    assert_int_equal(sliced.spread_m2, whole.spread_m2);
}

/* hold_k: a relearn keeps the previous fit's source (with hold_search, the best point of
 * a local search round it) while its loss is within best x (1 + hold_k / bins), best
 * being the new search's least loss. Expected decisions from the double-precision
 * reference: its search on the new data gives the best, its hold search from the
 * previous source (or that source alone) the held point and its loss. Pairs of noisy
 * data sets from sources 0-2.7 m apart (0-10 m with the search) give both outcomes. */
static void check_hold(fixture_t *f, bool local)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    c.hold_search = local;
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    int kept = 0, replaced = 0, moved_hold = 0;
    for (int trial = 0; trial < 40; ++trial) {
        truth_t a = k_office, b = k_office;
        a.noise = b.noise = 6.0;
        /* The search climbs up to 1.75 m: sources up to 9 m apart for it. */
        double step = local ? 1.0 : 0.25;
        b.sx += step * (double)(trial % 10);
        b.sy += 2.0 * step * (double)(trial / 10);
        const int n = 80;
        make_samples(f->s, n, &f->map, &a, 100 + (uint64_t)trial);
        rfs_pathloss_est_t ea = fit_with(f, &c, n, &f->map, 0, NULL);
        make_samples(f->s, n, &f->map, &b, 200 + (uint64_t)trial);
        rfs_model_t m = rfs_pathloss_model(&f->pl);
        rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = &f->map};
        rfs_rng_t rng;
        rfs_rng_seed(&rng, 1);
        m.ops->reset(m.self);
        assert_int_equal(m.ops->fit(m.self, &in, 0, &rng), RFS_FIT_DONE);
        rfs_pathloss_est_t eb;
        assert_true(rfs_pathloss_estimate(&f->pl, &eb));
        assert_true(ref_pl_fit(&f->ref, f->s, n, &f->map, &rc));
        ref_pl_t *r = &f->ref;
        int ai = (int)lround((ea.sx / 65536.0 - r->ox) / r->grid);
        int aj = (int)lround((ea.sy / 65536.0 - r->oy) / r->grid);
        double best = r->loss, rsx = r->sx, rsy = r->sy;
        int hi, hj;
        double la = ref_pl_hold(r, ai, aj, local, &hi, &hj);
        bool moved = fabs(rsx - ea.sx / 65536.0) > 1e-3 || fabs(rsy - ea.sy / 65536.0) > 1e-3;
        if (!moved) {
            continue; /* the new search found the old source itself: nothing to hold */
        }
        double margin = best * 6.0 / r->nbins;
        if (fabs(la - (best + margin)) < 1e-3 * best) {
            continue; /* too close to the threshold to call in fixed point */
        }
        bool keep = la <= best + margin;
        double hx = r->ox + hi * r->grid, hy = r->oy + hj * r->grid;
        double wx = keep ? hx : rsx, wy = keep ? hy : rsy;
        moved_hold += keep && (hi != ai || hj != aj);
        if (fabs(eb.sx / 65536.0 - wx) > 1e-3 || fabs(eb.sy / 65536.0 - wy) > 1e-3) {
            fail_msg("trial %d: (%.3f, %.3f), expected (%.3f, %.3f) (%s)", trial,
                     eb.sx / 65536.0, eb.sy / 65536.0, wx, wy, keep ? "kept" : "replaced");
        }
        kept += keep;
        replaced += !keep;
    }
    print_message("hold (%s): %d kept (%d moved by the search), %d replaced\n",
                  local ? "search" : "point", kept, moved_hold, replaced);
    assert_true(kept >= 2);
    assert_true(replaced >= 2);
    if (local) {
        assert_true(moved_hold >= 1); /* the search is exercised, not just the point */
    }
}

static void relearn_holds_previous_source(void **state)
{
    check_hold(*state, false);
}

static void relearn_holds_best_point_round_previous_source(void **state)
{
    check_hold(*state, true);
}

/* p0_min: the fixed-point search equals the double reference with the floor off too. */
static void p0_floor_off_same_as_reference(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    c.p0_min = INT32_MIN;
    rc.p0_min = -INFINITY;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
}

/* p0_max below the truth's -35 dBm: the fixed-point search equals the double reference
 * with the ceiling biting, and the ceiling pulls the fitted P0 down. */
static void p0_ceiling_same_as_reference(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    c.p0_max = RFS_Q16_INT(-41);
    rc.p0_max = -41.0;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t on;
    assert_true(rfs_pathloss_estimate(&f->pl, &on));
    rfs_pathloss_est_t off = fit_default(f, NS, &f->map, 0, NULL);
    assert_true(fabs(off.p0 / 65536.0 - k_office.p0) < 1.5);
    assert_true(on.p0 / 65536.0 < off.p0 / 65536.0 - 2.0);
}

/* The default ceiling, -10 dBm (docs/PATHLOSS.md, "The P0 floor"): a node 15 dB above it
 * (P0 +5 dBm) is fitted as the double reference with the same ceiling fits it, with P0
 * pulled below the truth; without the ceiling the fit recovers the truth's P0. */
static void p0_default_ceiling_same_as_reference(void **state)
{
    fixture_t *f = *state;
    truth_t strong = k_office;
    strong.p0 = 5.0;
    make_samples(f->s, NS, &f->map, &strong, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    assert_int_equal(c.p0_max, RFS_Q16_INT(-10));
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t on;
    assert_true(rfs_pathloss_estimate(&f->pl, &on));
    c.p0_max = INT32_MAX;
    rfs_pathloss_est_t off = fit_with(f, &c, NS, &f->map, 0, NULL);
    assert_true(fabs(off.p0 / 65536.0 - strong.p0) < 1.5);
    assert_true(on.p0 / 65536.0 < off.p0 / 65536.0 - 2.0);
}

/* p0_max_wall 3 dB: the ceiling holds the P0 with each wall at 3 dB at most against -10
 * dBm, so a node at -4 dBm behind 8 dB walls is fitted with its P0, as the double reference
 * fits it; by default (each wall at the fit's W) the ceiling pulls P0 down, as in the
 * reference too. */
static void p0_ceiling_credits_walls(void **state)
{
    fixture_t *f = *state;
    truth_t t = k_office;
    t.p0 = -4.0;
    t.w = 8.0;
    make_samples(f->s, NS, &f->map, &t, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    assert_int_equal(c.p0_max_wall, INT32_MAX);
    c.p0_max_wall = RFS_Q16_INT(3);
    rc.p0_max_wall = 3.0;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t credited;
    assert_true(rfs_pathloss_estimate(&f->pl, &credited));
    c.p0_max_wall = INT32_MAX;
    rc.p0_max_wall = INFINITY;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t charged;
    assert_true(rfs_pathloss_estimate(&f->pl, &charged));
    print_message("P0 credited %.2f charged %.2f, W %.2f %.2f\n", credited.p0 / 65536.0,
                  charged.p0 / 65536.0, credited.w / 65536.0, charged.w / 65536.0);
    assert_true(fabs(credited.p0 / 65536.0 - t.p0) < 1.5);
    assert_true(charged.p0 / 65536.0 < t.p0 - 2.0);
}

/* footprint 0 (each bin's walls counted from its cell's centre alone, the model before
 * the footprint) equals the double reference too, and differs from the default: the
 * test's office has bins whose footprint straddles a wall's end. The coarse pass follows
 * the footprint set alone (coarse_footprint left at its default). */
static void footprint_off_same_as_reference(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    c.footprint = 0;
    rc.footprint = rc.coarse_footprint = 0.0;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t off;
    assert_true(rfs_pathloss_estimate(&f->pl, &off));
    assert_int_equal(off.walls_counted, off.footprints); /* one line per footprint */
    rfs_pathloss_est_t on = fit_default(f, NS, &f->map, 0, NULL);
    assert_true(on.walls_counted > 3u * on.footprints);
    assert_true(on.rms != off.rms);
}

/* The one-count coarse pass (coarse_footprint 0: the coarse points' losses only rank, the
 * refinement re-evaluates the top points with the footprint) equals the double reference,
 * and counts under half the default's lines (one a coarse footprint, four a refinement's)
 * on the same data. */
static void coarse_footprint_one_same_as_reference(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    assert_int_equal(c.coarse_footprint, RFS_PATHLOSS_COARSE_AS_FOOTPRINT);
    c.coarse_footprint = 0;
    rc.coarse_footprint = 0.0;
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    rfs_pathloss_est_t one;
    assert_true(rfs_pathloss_estimate(&f->pl, &one));
    rfs_pathloss_est_t full = fit_default(f, NS, &f->map, 0, NULL);
    assert_true(2u * one.walls_counted < full.walls_counted);
    assert_true(one.walls_counted > one.footprints); /* the refinement's four a footprint */
}

/* The default configuration on the same data: the prior (3, 5 dB) pulls n and W from
 * the truth (2.6, 6.5 dB) towards itself, the source stays within one lattice cell. */
static void default_prior_shrinks_towards_physics(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);

    rfs_pathloss_est_t e = fit_default(f, NS, &f->map, 0, NULL);

    assert_true(fabs(e.sx / 65536.0 - k_office.sx) <= 0.25 + 1e-4);
    assert_true(fabs(e.sy / 65536.0 - k_office.sy) <= 0.25 + 1e-4);
    double n = e.n / 65536.0, w = e.w / 65536.0;
    if (!(n > k_office.n && n < 3.0 && w < k_office.w && w > 5.0)) {
        fail_msg("n %.3f W %.3f: not between the truth (%.1f, %.1f) and the prior (3, 5)", n, w,
                 k_office.n, k_office.w);
    }
}

/* A weaker robot's view: few samples along the corridor and one room, 1.5 dB noise. */
static void same_cell_as_double_reference_sparse_noisy(void **state)
{
    fixture_t *f = *state;
    truth_t t = {24.875, 12.625, -40.0, 2.5, 7.0, 1.5};
    make_samples(f->s, 300, &f->map, &t, 5);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();

    expect_same_as_reference(f, &c, 300, &f->map, &rc, 0.01);
}

/* An exponent outside the bounds: the constrained solution sits on n = n_max. */
static void exponent_clamped_like_reference(void **state)
{
    fixture_t *f = *state;
    truth_t t = {5.125, 12.125, -20.0, 6.5, 4.0, 0.3};
    make_samples(f->s, 1000, &f->map, &t, 9);
    rfs_pathloss_cfg_t c = weak_cfg();
    ref_pl_cfg_t rc = weak_ref();

    expect_same_as_reference(f, &c, 1000, &f->map, &rc, 0.01);

    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    assert_int_equal(e.n, rfs_pathloss_cfg_default().n_max);
    assert_true(fabs(f->ref.n - 5.0) < 1e-12);
}

/* Without a map: free-space log-distance, candidates around the samples. */
static void no_map_recovers_source(void **state)
{
    fixture_t *f = *state;
    truth_t t = {21.0, 6.0, -30.0, 2.0, 0.0, 0.3};
    make_samples(f->s, 800, NULL, &t, 13);
    rfs_pathloss_cfg_t c = weak_cfg();
    ref_pl_cfg_t rc = weak_ref();

    expect_same_as_reference(f, &c, 800, NULL, &rc, 0.01);

    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    assert_true(fabs(e.sx / 65536.0 - t.sx) <= 0.25 && fabs(e.sy / 65536.0 - t.sy) <= 0.25);
    assert_true(fabs(e.n / 65536.0 - t.n) < 0.1 * t.n);
}

/* Samples over 300 x 300 m need more than 256 one-metre bins: the bin doubles. */
static void bins_grow_when_samples_spread(void **state)
{
    fixture_t *f = *state;
    rfs_rng_t r;
    rfs_rng_seed(&r, 17);
    for (int i = 0; i < NS; ++i) {
        f->s[i].x_cm = (int16_t)(rfs_rng_below(&r, 30001) - 15000);
        f->s[i].y_cm = (int16_t)(rfs_rng_below(&r, 30001) - 15000);
        double d = hypot(f->s[i].x_cm / 100.0 - 20.0, f->s[i].y_cm / 100.0 + 30.0);
        f->s[i].v_q6 = (int16_t)lround((-30.0 - 25.0 * log10(d < 1 ? 1 : d)) * 64.0);
    }
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();

    expect_same_as_reference(f, &c, NS, NULL, &rc, 0.01);

    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    assert_true(e.bins <= RFS_PATHLOSS_MAX_BINS);
    assert_true(fabs(e.bin / 65536.0 - f->ref.bin_m) < 1e-4);
    assert_true(f->ref.bin_m >= 16.0);
}

/* --- slicing, prediction, uncertainty -------------------------------------------------- */

static void sliced_fit_equals_whole_fit(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_est_t whole = fit_default(f, NS, &f->map, 0, NULL);
    rfs_pathloss_cand_t best = f->pl.best;
    int calls = 0;

    rfs_pathloss_est_t sliced = fit_default(f, NS, &f->map, 2000, &calls);

    assert_memory_equal(&f->pl.best, &best, sizeof(best));
    assert_int_equal(sliced.spread_m2, whole.spread_m2);
    assert_int_equal(sliced.candidates, whole.candidates);
    /* a fresh state: no cached wall counts, one footprint per (bin, candidate) pair of
     * one to four lines. Units (rfs_pathloss.h, "Work"): a line each; per candidate one
     * per 32 bins gathered and bins / 32 + 1 to solve; 64 samples binned each, and
     * bins / 32 + 1 to set them up */
    assert_int_equal(sliced.footprints_cached, 0);
    assert_int_equal(sliced.footprints, sliced.candidates * sliced.bins);
    assert_true(sliced.walls_counted >= sliced.footprints);
    assert_true(sliced.walls_counted <= 4u * sliced.footprints);
    assert_int_equal(sliced.walls_counted, whole.walls_counted);
    const uint32_t per32 = sliced.bins / 32u;
    const uint32_t units = sliced.walls_counted + sliced.candidates * (2u * per32 + 1u) +
                           (NS + 63u) / 64u + per32 + 1u;
    /* a call overruns 2000 by at most one unit (a footprint's four lines when at most
     * four are left, and a 32nd bin), and stops at worst when a solve (per32 + 1) or
     * a footprint (four lines and a 32nd bin) would overrun */
    assert_true((uint32_t)calls >= units / 2001u);
    assert_true((uint32_t)calls <= units / (2000u - (per32 + 1u > 5u ? per32 + 1u : 5u)) + 1u);

    /* The smallest budget: one piece of work a call, the same fit. */
    int tiny_calls = 0;
    rfs_pathloss_est_t tiny = fit_default(f, NS, &f->map, 1, &tiny_calls);
    assert_memory_equal(&f->pl.best, &best, sizeof(best));
    assert_int_equal(tiny.spread_m2, whole.spread_m2);
    assert_int_equal(tiny.walls_counted, whole.walls_counted);
    /* each binning unit, set-up, footprint and solve in a call of its own */
    assert_true((uint32_t)tiny_calls >= (NS + 63u) / 64u + 1u + tiny.footprints + tiny.candidates);

    /* A budget of one bin a call: candidates are resumed within their bins. */
    rfs_pathloss_est_t fine = fit_default(f, NS, &f->map, 4, &calls);
    assert_memory_equal(&f->pl.best, &best, sizeof(best));
    assert_int_equal(fine.spread_m2, whole.spread_m2);
    assert_int_equal(fine.walls_counted, whole.walls_counted);
    assert_true((uint32_t)calls >= fine.footprints);
}

static int by_x(const void *a, const void *b)
{
    return ((const rfs_sample_t *)a)->x_cm - ((const rfs_sample_t *)b)->x_cm;
}

/* The wall-count cache: a relearn with more samples reads the coarse candidates' counts
 * of the old bins and gives exactly what a fresh state gives. */
static void cached_relearn_equals_fresh(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    /* west half first: the relearn adds samples east of them, so most old bins keep
     * their samples and centroids */
    qsort(f->s, NS, sizeof(f->s[0]), by_x);
    (void)fit_default(f, NS / 2, &f->map, 0, NULL);   /* warms the cache */
    rfs_pathloss_t *warm = malloc(sizeof(*warm));
    assert_non_null(warm);
    memcpy(warm, &f->pl, sizeof(*warm));
    rfs_model_fit_in_t in = {.samples = f->s, .n = NS, .map = &f->map};
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_pathloss_est_t ew;

    rfs_fit_result_t r = rfs_pathloss_ops.fit(warm, &in, 0, &rng);
    rfs_pathloss_est_t ef = fit_default(f, NS, &f->map, 0, NULL); /* fresh */

    assert_int_equal(r, RFS_FIT_DONE);
    assert_true(rfs_pathloss_estimate(warm, &ew));
    assert_memory_equal(&warm->best, &f->pl.best, sizeof(f->pl.best));
    assert_memory_equal(warm->surface, f->pl.surface, sizeof(f->pl.surface));
    assert_int_equal(ew.candidates, ef.candidates);
    assert_int_equal(ew.footprints + ew.footprints_cached, ef.footprints + ef.footprints_cached);
    /* the coarse counts of the west half's bins came from the cache */
    assert_true(ew.footprints_cached > ef.footprints / 4u);
    free(warm);
}

/* A caller's wall-count cache (rfs_pathloss_cache_attach): over relearns on a growing
 * walk (so the hold phase runs too) the results equal the built-in cache's and a tiny
 * attached cache's bit for bit; the large one also keeps the refinement's counts, so it
 * counts fewer lines. The large one reads its distance terms' logarithms from a table
 * (rfs_pathloss_log2_attach), whose entries are log2 of the mantissas in [1, 2) in double
 * precision, to the Q16 unit. */
static void attached_cache_equals_builtin(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    qsort(f->s, NS, sizeof(f->s[0]), by_x);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_t *st[3];
    const uint16_t cols[3] = {0, 2048, 5}; /* built in, large, tiny */
    void *buf[3] = {NULL, NULL, NULL};
    for (int k = 0; k < 3; ++k) {
        st[k] = malloc(sizeof(rfs_pathloss_t));
        assert_non_null(st[k]);
        assert_int_equal(rfs_pathloss_init(st[k], &c), 0);
        if (cols[k] != 0u) {
            uint32_t bytes = rfs_pathloss_cache_bytes(cols[k]);
            buf[k] = malloc(bytes);
            assert_non_null(buf[k]);
            assert_int_equal(rfs_pathloss_cache_attach(st[k], buf[k], bytes - 1u, cols[k]), -1);
            assert_int_equal(rfs_pathloss_cache_attach(st[k], buf[k], bytes, cols[k]), 0);
        }
    }
    int32_t *tab = malloc(RFS_PATHLOSS_LOG2_ENTRIES * sizeof(int32_t));
    assert_non_null(tab);
    rfs_pathloss_log2_fill(tab);
    for (uint32_t k = 0; k < RFS_PATHLOSS_LOG2_ENTRIES; ++k) {
        assert_true(fabs(tab[k] - 65536.0 * log2(1.0 + k / 65536.0)) <= 1.0);
    }
    assert_int_equal(rfs_pathloss_log2_attach(st[1], NULL), -1);
    assert_int_equal(rfs_pathloss_log2_attach(NULL, tab), -1);
    assert_int_equal(rfs_pathloss_log2_attach(st[1], tab), 0);
    assert_int_equal(rfs_pathloss_cache_attach(st[1], buf[1], UINT32_MAX, 0), -1);
    assert_int_equal(rfs_pathloss_cache_attach(st[1], NULL, UINT32_MAX, 8), -1);
    assert_int_equal(rfs_pathloss_cache_attach(st[1], buf[1], UINT32_MAX,
                                               (uint16_t)(RFS_PATHLOSS_MAX_CACHE_COLS + 1u)), -1);
    assert_int_equal(rfs_pathloss_cache_bytes(2048), 8192u + 8192u + 512u * 2048u);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_pathloss_est_t e[3];
    uint32_t lines[3] = {0, 0, 0}, cached[3] = {0, 0, 0};
    for (int n = NS / 8; n <= NS; n += NS / 8) {
        rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = &f->map};
        for (int k = 0; k < 3; ++k) {
            assert_int_equal(rfs_pathloss_ops.fit(st[k], &in, 0, &rng), RFS_FIT_DONE);
            assert_true(rfs_pathloss_estimate(st[k], &e[k]));
            lines[k] += e[k].walls_counted;
        }
        for (int k = 1; k < 3; ++k) {
            assert_memory_equal(&st[k]->best, &st[0]->best, sizeof(st[0]->best));
            assert_memory_equal(st[k]->surface, st[0]->surface, sizeof(st[0]->surface));
            assert_int_equal(e[k].candidates, e[0].candidates);
            assert_int_equal(e[k].footprints + e[k].footprints_cached,
                             e[0].footprints + e[0].footprints_cached);
        }
        for (int k = 0; k < 3; ++k) {
            cached[k] += e[k].footprints_cached;
        }
    }
    /* the large cache keeps every candidate of the earlier fits until its origins run out
     * (the last fit starts it again) */
    assert_true(cached[1] > cached[0] && cached[0] > cached[2]);
    assert_true(lines[1] * 4u < lines[0] * 3u);
    assert_true(lines[2] > lines[0]);
    for (int k = 0; k < 3; ++k) {
        free(st[k]);
        free(buf[k]);
    }
    free(tab);
}

static void model_invalid_while_slicing(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    (void)fit_default(f, NS, &f->map, 0, NULL);
    rfs_model_fit_in_t in = {.samples = f->s, .n = NS, .map = &f->map};
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_q16_t v;

    rfs_fit_result_t r = rfs_pathloss_ops.fit(&f->pl, &in, 100, &rng);
    bool during = rfs_pathloss_ops.predict(&f->pl, 0, 0, &v);
    rfs_pathloss_ops.reset(&f->pl);
    bool after_reset = rfs_pathloss_ops.predict(&f->pl, 0, 0, &v);
    rfs_fit_result_t r2 = rfs_pathloss_ops.fit(&f->pl, &in, 0, &rng);

    assert_int_equal(r, RFS_FIT_MORE);
    assert_false(during);
    assert_false(after_reset);
    assert_int_equal(r2, RFS_FIT_DONE);
}

static void predict_is_the_fitted_formula(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = weak_cfg();
    rfs_pathloss_est_t e = fit_with(f, &c, NS, &f->map, 0, NULL);
    const double px[5] = {1.3, 15.0, 28.4, 4.6, 15.125};
    const double py[5] = {1.2, 8.0, 14.7, 12.9, 3.375};
    rfs_q16_t ax, ay;

    assert_true(rfs_pathloss_ops.argmax(&f->pl, &ax, &ay));
    assert_int_equal(ax, e.sx);
    assert_int_equal(ay, e.sy);
    for (int i = 0; i < 5; ++i) {
        rfs_q16_t qx = (rfs_q16_t)lround(px[i] * 65536.0), qy = (rfs_q16_t)lround(py[i] * 65536.0);
        double d = hypot(px[i] - e.sx / 65536.0, py[i] - e.sy / 65536.0);
        int k = rfs_map_walls_crossed(&f->map, qx, qy, e.sx, e.sy);
        double want = e.p0 / 65536.0 - 10.0 * (e.n / 65536.0) * log10(d < 1 ? 1 : d) -
                      (e.w / 65536.0) * k;
        rfs_q16_t v;

        assert_true(rfs_pathloss_ops.predict(&f->pl, qx, qy, &v));

        if (fabs(v / 65536.0 - want) > 0.01) {
            fail_msg("predict (%.2f, %.2f) = %.4f, formula %.4f", px[i], py[i], v / 65536.0, want);
        }
        /* and close to the truth that made the data */
        double dt = hypot(px[i] - k_office.sx, py[i] - k_office.sy);
        int kt = rfs_map_walls_crossed(&f->map, qx, qy, (rfs_q16_t)lround(k_office.sx * 65536.0),
                                       (rfs_q16_t)lround(k_office.sy * 65536.0));
        double truth = k_office.p0 - 10.0 * k_office.n * log10(dt < 1 ? 1 : dt) - k_office.w * kt;
        if (fabs(v / 65536.0 - truth) > 1.5) {
            fail_msg("predict (%.2f, %.2f) = %.3f, truth %.3f", px[i], py[i], v / 65536.0, truth);
        }
    }
}

static void residual_surface_and_spread(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_est_t e = fit_default(f, NS, &f->map, 0, NULL);
    uint16_t ncx, ncy;
    rfs_pathloss_surface_size(&f->pl, &ncx, &ncy);
    double best = INFINITY, bx = 0, by = 0;
    int walls = 0;

    for (uint16_t cj = 0; cj < ncy; ++cj) {
        for (uint16_t ci = 0; ci < ncx; ++ci) {
            rfs_q16_t x, y, rms;
            if (!rfs_pathloss_residual_at(&f->pl, ci, cj, &x, &y, &rms)) {
                walls += !rfs_map_point_legal(&f->map, x, y);
                continue;
            }
            if (rms / 65536.0 < best) {
                best = rms / 65536.0;
                bx = x / 65536.0;
                by = y / 65536.0;
            }
        }
    }
    rfs_q16_t x, y, rms;

    /* the least residual of the coarse grid is the coarse point nearest the truth */
    assert_true(fabs(bx - k_office.sx) <= 1.0 && fabs(by - k_office.sy) <= 1.0);
    assert_true(best >= e.rms / 65536.0 - 1e-4);
    assert_true(walls > 0);
    assert_false(rfs_pathloss_residual_at(&f->pl, ncx, 0, &x, &y, &rms));
    /* with 0.3 dB noise the region is one or two coarse cells of 4 m^2 */
    assert_true(e.spread_m2 >= RFS_Q16_INT(4) && e.spread_m2 <= RFS_Q16_INT(8));
}

/* rfs_pathloss_ops.near (rfs_model_near_t): of the coarse points, weight w = e^(-chi2 / 2T)
 * (chi2 = (m / m_best - 1) x bins against the estimate, m = rms^2 / 2 of the reported
 * surface, as the draws'), the one with the most w / (d + d0), d the straight distance
 * from the robot, when it beats the estimate's 1 / (d_est + d0); points the callback
 * refuses (here within 4 m of the estimate) are passed over; T 16, d0 2 m, 30 samples with
 * 6 dB noise (a broad belief). Recomputed in double over the
 * surface for robots in three rooms and at the estimate (nothing beats it there); scores
 * within 0.1 % of the double best are taken as ties. */
static bool refuse_near_estimate(const void *ctx, rfs_q16_t x, rfs_q16_t y)
{
    const rfs_pathloss_est_t *e = ctx;
    return hypot((x - e->sx) / 65536.0, (y - e->sy) / 65536.0) <= 4.0;
}

static void near_weighs_plausibility_per_metre(void **state)
{
    fixture_t *f = *state;
    truth_t t = k_office;
    t.noise = 6.0;
    make_samples(f->s, 30, &f->map, &t, 21);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_est_t e = fit_with(f, &c, 30, &f->map, 0, NULL);
    uint16_t ncx, ncy;
    rfs_pathloss_surface_size(&f->pl, &ncx, &ncy);
    const double temp = 16.0, d0 = 2.0, bm = pow(e.rms / 65536.0, 2) / 2.0;
    const double ex = e.sx / 65536.0, ey = e.sy / 65536.0;
    const double robots[4][2] = {{3.0, 12.0}, {27.0, 12.0}, {15.0, 13.0}, {ex, ey}};
    int found = 0;
    for (int k = 0; k < 8; ++k) {
        const double rx = robots[k % 4][0], ry = robots[k % 4][1];
        const bool refusing = k >= 4;
        double best = 1.0 / (hypot(ex - rx, ey - ry) + d0), bx = NAN, by = NAN, second = best;
        for (int ci = 0; ci < ncx * ncy; ++ci) {
            rfs_q16_t x, y, rms;
            if (!rfs_pathloss_residual_at(&f->pl, (uint16_t)(ci % ncx), (uint16_t)(ci / ncx), &x, &y,
                                          &rms) ||
                (refusing && refuse_near_estimate(&e, x, y))) {
                continue;
            }
            const double m = pow(rms / 65536.0, 2) / 2.0;
            const double chi = m > bm ? (m - bm) * e.bins / (2.0 * temp * bm) : 0.0;
            const double score = (chi >= 16.0 ? 0.0 : exp(-chi)) /
                                 (hypot(x / 65536.0 - rx, y / 65536.0 - ry) + d0);
            if (score > best) {
                second = best;
                best = score;
                bx = x / 65536.0;
                by = y / 65536.0;
            } else if (score > second) {
                second = score;
            }
        }
        rfs_model_near_t q = { (rfs_q16_t)lround(rx * 65536.0), (rfs_q16_t)lround(ry * 65536.0),
                               e.sx, e.sy, (rfs_q16_t)lround(temp * 65536.0),
                               (rfs_q16_t)lround(d0 * 65536.0),
                               refusing ? refuse_near_estimate : NULL, &e };
        rfs_q16_t gx = 0, gy = 0;
        const bool got = rfs_pathloss_ops.near(&f->pl, &q, &gx, &gy);
        const bool tie = best - second < 1e-3 * best;
        if (!tie) {
            assert_int_equal(got, !isnan(bx));
        }
        if (got && !tie) {
            assert_true(fabs(gx / 65536.0 - bx) < 1e-4 && fabs(gy / 65536.0 - by) < 1e-4);
        }
        found += got;
        print_message("robot (%.1f, %.1f)%s: %s (%.2f, %.2f)\n", rx, ry,
                      refusing ? ", refusing" : "", got ? "near" : "the estimate",
                      got ? gx / 65536.0 : ex, got ? gy / 65536.0 : ey);
    }
    assert_true(found >= 3); /* the question is not trivial */
    rfs_pathloss_ops.reset(&f->pl);
    rfs_q16_t gx, gy;
    rfs_model_near_t q = { 0, 0, e.sx, e.sy, RFS_Q16_ONE, RFS_Q16_ONE, NULL, NULL };
    assert_false(rfs_pathloss_ops.near(&f->pl, &q, &gx, &gy));
}

/* The model's draw (rfs_pathloss_ops.sample, eps_sample): coarse point c is drawn with
 * probability proportional to e^(-chi2_c / 2T), chi2_c = (m_c / m_best - 1) x bins, m
 * the mean loss per unit weight (rms^2 / 2 of the reported surface). Weights recomputed
 * in double from the reported surface and estimate; draw frequencies within 4.5
 * binomial sigma of them over 40,000 draws. Few, noisy samples: a broad belief. */
static void draws_follow_the_residual_surface(void **state)
{
    fixture_t *f = *state;
    truth_t t = k_office;
    t.noise = 6.0;
    const int n = 60;
    const int ndraw = 40000;
    make_samples(f->s, n, &f->map, &t, 21);
    static const double temps[2] = {1.0, 4.0};
    for (int k = 0; k < 2; ++k) {
        rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
        c.sample_t = (rfs_q16_t)lround(temps[k] * 65536.0);
        rfs_pathloss_est_t e = fit_with(f, &c, n, &f->map, 0, NULL);
        uint16_t ncx, ncy;
        rfs_pathloss_surface_size(&f->pl, &ncx, &ncy);
        int nc = ncx * ncy;
        double *m = calloc((size_t)nc, sizeof *m), *want = calloc((size_t)nc, sizeof *want);
        int *count = calloc((size_t)nc, sizeof *count);
        assert_true(m != NULL && want != NULL && count != NULL);
        double m0 = INFINITY, bm = pow(e.rms / 65536.0, 2) / 2.0, sum = 0;
        for (int ci = 0; ci < nc; ++ci) {
            rfs_q16_t x, y, rms;
            m[ci] = rfs_pathloss_residual_at(&f->pl, (uint16_t)(ci % ncx), (uint16_t)(ci / ncx),
                                             &x, &y, &rms)
                        ? pow(rms / 65536.0, 2) / 2.0
                        : NAN;
            m0 = isnan(m[ci]) ? m0 : fmin(m0, m[ci]);
        }
        for (int ci = 0; ci < nc; ++ci) {
            double ex = isnan(m[ci]) ? INFINITY : (m[ci] - m0) * e.bins / (2.0 * temps[k] * bm);
            want[ci] = ex >= 16.0 ? 0.0 : exp(-ex);
            double got = rfs_pathloss_draw_weight(&f->pl, (uint16_t)(ci % ncx),
                                                  (uint16_t)(ci / ncx)) / 65536.0;
            if (fabs(ex - 16.0) > 0.01 && fabs(got - want[ci]) > 2e-3) {
                fail_msg("T %.0f, point %d: weight %.5f, double %.5f", temps[k], ci, got,
                         want[ci]);
            }
            sum += want[ci];
        }
        rfs_rng_t rng;
        rfs_rng_seed(&rng, 5 + (uint64_t)k);
        for (int d = 0; d < ndraw; ++d) {
            rfs_q16_t x, y;
            assert_true(rfs_pathloss_ops.sample(&f->pl, &rng, &x, &y));
            int ci = -1;
            for (int q = 0; q < nc && ci < 0; ++q) {
                rfs_q16_t px, py, rms;
                if (rfs_pathloss_residual_at(&f->pl, (uint16_t)(q % ncx), (uint16_t)(q / ncx),
                                             &px, &py, &rms) &&
                    px == x && py == y) {
                    ci = q;
                }
            }
            assert_true(ci >= 0 && want[ci] > 0.0); /* a candidate, of weight */
            count[ci]++;
        }
        int wide = 0;
        for (int ci = 0; ci < nc; ++ci) {
            double p = want[ci] / sum, got = (double)count[ci] / ndraw;
            if (fabs(got - p) > 4.5 * sqrt(p * (1.0 - p) / ndraw) + 1e-9) {
                fail_msg("T %.0f, point %d: drawn %.4f, expected %.4f", temps[k], ci, got, p);
            }
            wide += p >= 0.01;
        }
        print_message("draws at T %.0f: %d points of probability >= 1 %%\n", temps[k], wide);
        assert_true(wide >= 3);
        free(m);
        free(want);
        free(count);
    }
    rfs_q16_t x, y;
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_pathloss_ops.reset(&f->pl);
    assert_false(rfs_pathloss_ops.sample(&f->pl, &rng, &x, &y));
    assert_int_equal(rfs_pathloss_draw_weight(&f->pl, 0, 0), 0u);
}

/* Closed loop with the paper's meta-algorithm (rfs_seek, paper defaults) and this model:
 * the office of this file, the source in a room, the robot starting in the corridor
 * 17 m away; a double-precision world (unicycle kinematics) with -40 - 30 log10(d)
 * - 5 dB per wall and 4 dB Gaussian noise per packet, 200 packets/s, 10 Hz poses,
 * 20 Hz control. The seeker must come within 1.5 m of the source in 10 simulated
 * minutes. */
static double closed_loop_run(fixture_t *f, uint64_t seed, double *travel)
{
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    uint32_t lpts = (uint32_t)f->map.lw * f->map.lh;
    rfs_seek_mem_t mem;
    memset(&mem, 0, sizeof(mem));
    mem.samples = calloc(cfg.store.capacity, sizeof(rfs_sample_t));
    mem.pending = calloc(256, sizeof(rfs_pending_t));
    mem.pending_cap = 256;
    mem.plan_work = calloc(lpts, 1);
    mem.plan_work_bytes = lpts;
    mem.plan_queue_cap = lpts;
    mem.plan_queue = calloc(lpts, sizeof(uint32_t));
    mem.visited_bytes = rfs_reach_bytes(&f->map);
    mem.visited = calloc(mem.visited_bytes, 1);
    mem.reach_bytes = mem.visited_bytes;
    mem.reach = calloc(mem.reach_bytes, 1);
    rfs_seek_t *sk = calloc(1, sizeof(*sk));
    assert_non_null(sk);
    rfs_pathloss_cfg_t pc = rfs_pathloss_cfg_default();
    assert_int_equal(rfs_pathloss_init(&f->pl, &pc), 0);
    assert_int_equal(rfs_seek_init(sk, &cfg, &f->map, rfs_pathloss_model(&f->pl),
                                   &rfs_target_rssi, &mem), 0);
    rfs_rng_t rng, noise;
    rfs_rng_seed(&rng, seed);
    rfs_rng_seed(&noise, 1000u + seed);
    const double sx = 15.125, sy = 3.375;
    const rfs_q16_t qsx = (rfs_q16_t)lround(sx * 65536.0), qsy = (rfs_q16_t)lround(sy * 65536.0);
    double x = 2.0, y = 8.0, th = 0, vl = 0, vr = 0, dist = -1.0;
    *travel = 0;
    for (int ms = 0; ms < 600000; ms += 5) {
        int64_t now = (int64_t)ms * 1000;
        double v = (vl + vr) / 2e3, w = (vr - vl) / 1e3 / 0.23;
        x += v * cos(th) * 0.005;
        y += v * sin(th) * 0.005;
        *travel += fabs(v) * 0.005;
        th = atan2(sin(th + w * 0.005), cos(th + w * 0.005));
        double d = fmax(hypot(x - sx, y - sy), 1.0);
        int k = rfs_map_walls_crossed(&f->map, (rfs_q16_t)lround(x * 65536.0),
                                      (rfs_q16_t)lround(y * 65536.0), qsx, qsy);
        double dbm = -40 - 30 * log10(d) - 5.0 * k + 4 * gauss(&noise);
        rfs_seek_on_rssi(sk, 0, now, (int8_t)lround(fmax(dbm, -127)), &rng);
        if (ms % 100 == 0) {
            rfs_pose_t p = {now, (rfs_q16_t)lround(x * 65536.0), (rfs_q16_t)lround(y * 65536.0),
                            (rfs_q16_t)lround(th * 65536.0)};
            rfs_seek_on_pose(sk, &p, &rng);
        }
        if (ms % 50 == 0) {
            rfs_seek_out_t out;
            rfs_seek_step(sk, now, &rng, &out);
            vl = out.left_mm_s;
            vr = out.right_mm_s;
        }
        if (hypot(x - sx, y - sy) < 1.5) {
            dist = hypot(x - sx, y - sy);
            break;
        }
    }
    free(sk);
    free(mem.samples);
    free(mem.pending);
    free(mem.plan_work);
    free(mem.plan_queue);
    free(mem.visited);
    free(mem.reach);
    return dist;
}

static void closed_loop_finds_the_room(void **state)
{
    fixture_t *f = *state;
    int reached = 0;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        double travel;

        double d = closed_loop_run(f, seed, &travel);

        reached += d >= 0;
        print_message("closed loop seed %u: %s, travel %.1f m (shortest path about 17 m)\n",
                      (unsigned)seed, d >= 0 ? "reached" : "NOT reached", travel);
    }
    assert_int_equal(reached, 3);
}

/* The registry knows the model by its command-line name. */
static void registered_as_pathloss(void **state)
{
    (void)state;
    const rfs_models_entry_t *e = rfs_models_lookup("pathloss");

    assert_non_null(e);
    assert_ptr_equal(e->ops, &rfs_pathloss_ops);
    assert_int_equal(e->state_bytes, sizeof(rfs_pathloss_t));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(init_rejects_bad_configurations, setup, teardown),
        cmocka_unit_test_setup_teardown(no_samples_no_model, setup, teardown),
        cmocka_unit_test(db_dist_matches_double),
        cmocka_unit_test_setup_teardown(fit_recovers_source_n_and_w, setup, teardown),
        cmocka_unit_test_setup_teardown(same_cell_as_double_reference_office, setup, teardown),
        cmocka_unit_test_setup_teardown(default_prior_shrinks_towards_physics, setup, teardown),
        cmocka_unit_test_setup_teardown(same_cell_as_double_reference_sparse_noisy, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(exponent_clamped_like_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(no_map_recovers_source, setup, teardown),
        cmocka_unit_test_setup_teardown(bins_grow_when_samples_spread, setup, teardown),
        cmocka_unit_test_setup_teardown(sliced_fit_equals_whole_fit, setup, teardown),
        cmocka_unit_test_setup_teardown(cached_relearn_equals_fresh, setup, teardown),
        cmocka_unit_test_setup_teardown(attached_cache_equals_builtin, setup, teardown),
        cmocka_unit_test_setup_teardown(model_invalid_while_slicing, setup, teardown),
        cmocka_unit_test_setup_teardown(predict_is_the_fitted_formula, setup, teardown),
        cmocka_unit_test_setup_teardown(residual_surface_and_spread, setup, teardown),
        cmocka_unit_test_setup_teardown(closed_loop_finds_the_room, setup, teardown),
        cmocka_unit_test_setup_teardown(draws_follow_the_residual_surface, setup, teardown),
        cmocka_unit_test_setup_teardown(near_weighs_plausibility_per_metre, setup, teardown),
        cmocka_unit_test_setup_teardown(relearn_holds_previous_source, setup, teardown),
        cmocka_unit_test_setup_teardown(relearn_holds_best_point_round_previous_source, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(places_ruled_out_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(footprint_off_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_floor_off_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_ceiling_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(coarse_footprint_one_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_default_ceiling_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_ceiling_credits_walls, setup, teardown),
        cmocka_unit_test(registered_as_pathloss),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
