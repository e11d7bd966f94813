/* test_pathloss.c - the map-aware path-loss model's fit (common/rfs_pathloss): its
 * configuration, recovery of the truth, and every option against the double reference;
 * what the seeker calls of it: test_pathloss_use.c.
 *
 * Data (pathloss_office.h): an office (30 x 16 m, 0.1 m cells: a corridor between two rows
 * of rooms, doors 1 m wide) and samples at random legal positions whose values follow the
 * model with a known source, P0, n and W plus small Gaussian noise. Expected values come
 * from the truth that generated the data and from the double-precision reference of
 * the same search (ref_pathloss.h), never from the code under test.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pathloss_office.h"
#include "ref_pathloss.h"
#include "rfs_models.h"
#include "rfs_pathloss.h"
#include "rfs_seek.h"

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
            assert_true(fabs(x / 65536.0 - (r->ox + r->pi[cj * ncx + ci] * r->grid)) < 1e-4);
            assert_true(fabs(y / 65536.0 - (r->oy + r->pj[cj * ncx + ci] * r->grid)) < 1e-4);
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

/* floor_gap (the seeker's floor_gap rule): the fit's P0 above the -45 dBm floor, the
 * double reference's P0 + 45 for the office truth (P0 -35 dBm); no answer without a
 * floor or before a fit. */
static void floor_gap_is_p0_above_the_floor(void **state)
{
    fixture_t *f = *state;
    rfs_q16_t gap = 0;
    rfs_pathloss_ops.reset(&f->pl);
    assert_false(rfs_pathloss_ops.floor_gap(&f->pl, &gap));
    make_samples(f->s, NS, &f->map, &k_office, 11);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    assert_int_equal(c.p0_min, RFS_Q16_INT(-45));
    expect_same_as_reference(f, &c, NS, &f->map, &rc, 0.01);
    assert_true(rfs_pathloss_ops.floor_gap(&f->pl, &gap));
    assert_true(fabs(gap / 65536.0 - (f->ref.p0 + 45.0)) < 0.2);
    assert_true(gap / 65536.0 > 5.0);
    c.p0_min = INT32_MIN;
    (void)fit_with(f, &c, NS, &f->map, 0, NULL);
    assert_false(rfs_pathloss_ops.floor_gap(&f->pl, &gap));
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

/* A floor whose corridor lies between two coarse rows (the rows every 2 m fall at y =
 * 10.875 and 12.875 m, its legal band is about 11.35-12.25 m): a room (y < 6 m), a 5 m block
 * of wall above it with a 1.5 m passage at its west end, the corridor (y 11-12.6 m) and wall
 * above. */
static bool corridor_is_wall(int i, int j)
{
    if (i == 0 || j == 0 || i == MW - 1 || j >= 126) {
        return true;
    }
    return j >= 60 && j <= 109 && !(i >= 10 && i < 25);
}

/* coarse_snap: the coarse point of a cell whose grid point is not legal stands for the
 * cell's legal lattice point nearest it, so the corridor between two coarse rows has
 * candidates. A source at its east end, samples all over the floor: with the snap the
 * estimate lies within 0.5 m of it (and equals the double reference, which snaps the same
 * way); without it no candidate lies in the corridor's east part, the estimate stays over
 * 4 m off (the reference agrees there too). */
static void coarse_snap_finds_corridor_off_the_grid(void **state)
{
    fixture_t *f = *state;
    static uint8_t fb[MH * ((MW + 7) / 8)], wb[MH * ((MW + 7) / 8)], lb[MH * ((MW + 7) / 8)];
    const uint16_t stride = (MW + 7) / 8;
    for (int j = 0; j < MH; ++j) {
        for (int i = 0; i < MW; ++i) {
            rfs_map_bit_set(wb, stride, (uint16_t)i, (uint16_t)j, corridor_is_wall(i, j));
            rfs_map_bit_set(fb, stride, (uint16_t)i, (uint16_t)j, !corridor_is_wall(i, j));
        }
    }
    rfs_map_t map;
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(&map, &mc, MW, MH, RES_Q16, 0, 0, fb, wb, lb), 0);
    const truth_t t = {28.0, 11.8, -30.0, 2.6, 6.5, 0.3};
    make_samples(f->s, NS, &map, &t, 5);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default(), off = rfs_pathloss_cfg_default();
    ref_pl_cfg_t rc = ref_pl_cfg_default(), roff = ref_pl_cfg_default();
    off.coarse_snap = false;
    roff.coarse_snap = false;

    expect_same_as_reference(f, &c, NS, &map, &rc, 0.01);
    assert_true(hypot(f->ref.sx - t.sx, f->ref.sy - t.sy) <= 0.5);
    expect_same_as_reference(f, &off, NS, &map, &roff, 0.01);
    assert_true(hypot(f->ref.sx - t.sx, f->ref.sy - t.sy) > 4.0);
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
        cmocka_unit_test_setup_teardown(relearn_holds_previous_source, setup, teardown),
        cmocka_unit_test_setup_teardown(relearn_holds_best_point_round_previous_source, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(places_ruled_out_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(footprint_off_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_floor_off_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(floor_gap_is_p0_above_the_floor, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_ceiling_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(coarse_footprint_one_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(coarse_snap_finds_corridor_off_the_grid, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_default_ceiling_same_as_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(p0_ceiling_credits_walls, setup, teardown),
        cmocka_unit_test(registered_as_pathloss),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
