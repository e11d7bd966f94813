/* test_pathloss_warm.c - the path-loss model's warming (rfs_pathloss_ops.warm): a relearn
 * after warming equals one without, bit for bit, and counts fewer walls; warming leaves the
 * model as it was; sliced at budget 1 it warms as a whole.
 *
 * The robot walks the test office's corridor: a first fit on 20 bins of it, then three new
 * bins along it (the robot in the last, whose samples are not complete), warmed, relearnt.
 */
#include <string.h>

#include "pathloss_office.h"
#include "rfs_fields.h"
#include "rfs_models.h"
#include "rfs_reach.h"
#include "rfs_seek.h"
#include "rfs_target.h"

#define Q16(v) ((rfs_q16_t)((v) * 65536 + 32768))

/* Samples per bin. */
#define PER_BIN 40

/* n samples at random legal points of the 1 m bin (bx, by), valued as make_samples does. */
static void bin_samples(rfs_sample_t *s, int n, const rfs_map_t *map, const truth_t *t, int bx,
                        int by, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    int tries = 0;
    for (int i = 0; i < n; ++tries) {
        assert_true(tries < 100000);
        int xc = bx * 100 + (int)rfs_rng_below(&r, 100), yc = by * 100 + (int)rfs_rng_below(&r, 100);
        rfs_q16_t qx = (rfs_q16_t)lround(xc / 100.0 * 65536.0);
        rfs_q16_t qy = (rfs_q16_t)lround(yc / 100.0 * 65536.0);
        if (!rfs_map_point_legal(map, qx, qy)) {
            continue;
        }
        truth_sample(map, t, xc, yc, t->noise, &r, &s[i]);
        ++i;
    }
}

/* The corridor's bins x = 2..11 at y = 7, 8 m, PER_BIN samples each from the start of
 * f->s; returns their count. */
static int corridor(fixture_t *f)
{
    int n = 0;
    for (int bx = 2; bx < 12; ++bx) {
        for (int by = 7; by < 9; ++by) {
            bin_samples(f->s + n, PER_BIN, &f->map, &k_office, bx, by, (uint64_t)(100 + bx * 10 + by));
            n += PER_BIN;
        }
    }
    return n;
}

/* The walk: bins x = 2..11 at y = 7, 8 m (the corridor), then the leg's x = 12, 13, 14 at
 * y = 7 m. Returns the samples of the first fit; *all: with the leg's. */
static int walk(fixture_t *f, int *all)
{
    int n = corridor(f);
    const int first = n;
    for (int bx = 12; bx < 15; ++bx) {
        bin_samples(f->s + n, PER_BIN, &f->map, &k_office, bx, 7, (uint64_t)(500 + bx));
        n += PER_BIN;
    }
    *all = n;
    return first;
}

/* The robot, in the leg's last bin. */
static const rfs_q16_t k_robot_x = 14 * 65536 + 32768, k_robot_y = 7 * 65536 + 39322;

static rfs_model_fit_in_t input(fixture_t *f, int n)
{
    rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = &f->map, .qx = k_robot_x,
                             .qy = k_robot_y};
    return in;
}

/* A whole fit (budget 0) or a sliced one; the estimate. */
static rfs_pathloss_est_t fit(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_fit_result_t r;
    int k = 0;
    do {
        r = rfs_pathloss_ops.fit(p, in, budget, &rng);
    } while (r == RFS_FIT_MORE && ++k < 100000);
    assert_int_equal(r, RFS_FIT_DONE);
    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(p, &e));
    return e;
}

/* Two estimates equal field by field (a struct's padding is not part of it). */
static void est_equal(const rfs_pathloss_est_t *a, const rfs_pathloss_est_t *b)
{
    assert_int_equal(a->sx, b->sx);
    assert_int_equal(a->sy, b->sy);
    assert_int_equal(a->p0, b->p0);
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->w, b->w);
    assert_int_equal(a->rms, b->rms);
    assert_int_equal(a->spread_m2, b->spread_m2);
    assert_int_equal(a->bins, b->bins);
    assert_int_equal(a->bin, b->bin);
    assert_int_equal(a->candidates, b->candidates);
    assert_int_equal(a->walls_counted, b->walls_counted);
    assert_int_equal(a->footprints, b->footprints);
    assert_int_equal(a->footprints_cached, b->footprints_cached);
    assert_int_equal(a->walls_warmed, b->walls_warmed);
}

/* Warm until there is nothing left; the calls it took. */
static int warm_all(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget)
{
    int calls = 1;
    while (rfs_pathloss_ops.warm(p, in, budget)) {
        assert_true(++calls < 1000000);
    }
    return calls;
}

/* Cache cells counted, by a scan of the built-in cache (not the model's counters). */
static uint32_t cells_counted(const rfs_pathloss_t *p)
{
    uint32_t n = 0u;
    for (uint32_t r = 0u; r < RFS_PATHLOSS_BUILTIN_ROWS; ++r) {
        for (uint32_t c = 0u; c < RFS_PATHLOSS_CACHE_COLS; ++c) {
            n += p->walls[r][c] != 255u ? 1u : 0u;
        }
    }
    return n;
}

static void same_fit(const rfs_pathloss_t *a, const rfs_pathloss_t *b)
{
    assert_memory_equal(&a->best, &b->best, sizeof(a->best));
    assert_memory_equal(a->top, b->top, sizeof(a->top));
    assert_memory_equal(a->surface, b->surface, sizeof(a->surface));
    assert_int_equal(a->spread_m2, b->spread_m2);
    assert_int_equal(a->candidates, b->candidates);
}

/* Relearn after warming (whole and sliced at the MCU budget) equals one without, bit for
 * bit, and counts fewer walls: at least the two bins the robot left times every coarse
 * candidate (the double reference's count), at most what warming counted. */
static void relearn_after_warm_equals_relearn_without(void **state)
{
    fixture_t *f = *state;
    int all;
    const int first = walk(f, &all);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_t *warmed = malloc(sizeof(rfs_pathloss_t));
    rfs_pathloss_t *sliced = malloc(sizeof(rfs_pathloss_t));
    rfs_pathloss_t *cold = malloc(sizeof(rfs_pathloss_t));
    assert_true(warmed != NULL && sliced != NULL && cold != NULL);
    assert_int_equal(rfs_pathloss_init(cold, &c), 0);
    rfs_model_fit_in_t in1 = input(f, first), in2 = input(f, all);
    (void)fit(cold, &in1, 0);
    memcpy(warmed, cold, sizeof(*cold));
    memcpy(sliced, cold, sizeof(*cold));

    const uint32_t before = cells_counted(warmed);
    (void)warm_all(warmed, &in2, 0);
    (void)warm_all(sliced, &in2, 26);
    const uint32_t filled = cells_counted(warmed) - before;
    rfs_pathloss_est_t ew = fit(warmed, &in2, 0), es = fit(sliced, &in2, 30), ec = fit(cold, &in2, 0);

    same_fit(warmed, cold);
    same_fit(sliced, cold);
    ref_pl_t *ref = malloc(sizeof(ref_pl_t));
    assert_non_null(ref);
    ref_pl_cfg_t rc = ref_pl_cfg_default();
    assert_true(ref_pl_fit(ref, f->s, all, &f->map, &rc));
    uint32_t coarse = 0u;
    for (int k = 0; k < ref->ncx * ref->ncy; ++k) {
        coarse += isnan(ref->surface[k]) ? 0u : 1u;
    }
    free(ref->seen);
    free(ref);
    assert_true(coarse > 50u);
    assert_int_equal(ew.footprints + ew.footprints_cached, ec.footprints + ec.footprints_cached);
    assert_int_equal(es.footprints, ew.footprints);
    assert_true(ec.footprints - ew.footprints >= 2u * coarse);
    assert_true(ec.footprints - ew.footprints <= filled);
    assert_int_equal(warmed->walls_warmed, ew.walls_warmed);
    assert_true(ew.walls_warmed >= 2u * coarse && ec.walls_warmed == 0u);
    free(warmed);
    free(sliced);
    free(cold);
}

/* Warming changes nothing the model publishes: predictions, the argmax, draws, the
 * estimate. */
static void warm_leaves_the_model_unchanged(void **state)
{
    fixture_t *f = *state;
    int all;
    const int first = walk(f, &all);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in1 = input(f, first), in2 = input(f, all);
    rfs_pathloss_est_t e0 = fit(&f->pl, &in1, 0);
    rfs_q16_t v0[30][16], x0, y0, dx0[8], dy0[8];
    for (int i = 0; i < 30; ++i) {
        for (int j = 0; j < 16; ++j) {
            assert_true(rfs_pathloss_ops.predict(&f->pl, i * 65536 + 32768, j * 65536 + 32768,
                                                 &v0[i][j]));
        }
    }
    assert_true(rfs_pathloss_ops.argmax(&f->pl, &x0, &y0));
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 7);
    for (int k = 0; k < 8; ++k) {
        assert_true(rfs_pathloss_ops.sample(&f->pl, &rng, &dx0[k], &dy0[k]));
    }

    assert_true(warm_all(&f->pl, &in2, 0) >= 1);
    assert_true(f->pl.warm.lines > 0u);

    for (int i = 0; i < 30; ++i) {
        for (int j = 0; j < 16; ++j) {
            rfs_q16_t v;
            assert_true(rfs_pathloss_ops.predict(&f->pl, i * 65536 + 32768, j * 65536 + 32768, &v));
            assert_int_equal(v, v0[i][j]);
        }
    }
    rfs_q16_t x, y;
    assert_true(rfs_pathloss_ops.argmax(&f->pl, &x, &y));
    assert_int_equal(x, x0);
    assert_int_equal(y, y0);
    rfs_rng_seed(&rng, 7);
    for (int k = 0; k < 8; ++k) {
        assert_true(rfs_pathloss_ops.sample(&f->pl, &rng, &x, &y));
        assert_int_equal(x, dx0[k]);
        assert_int_equal(y, dy0[k]);
    }
    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    est_equal(&e, &e0);
}

/* Budget 1 (at least a piece a call) warms what one unbounded call does, over many calls;
 * nothing is warmed without a finished fit, on another map, or while a fit is sliced. */
static void warm_resumes_at_budget_one(void **state)
{
    fixture_t *f = *state;
    int all;
    const int first = walk(f, &all);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_t *whole = malloc(sizeof(rfs_pathloss_t));
    assert_non_null(whole);
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in1 = input(f, first), in2 = input(f, all);
    assert_false(rfs_pathloss_ops.warm(&f->pl, &in2, 0)); /* no fit yet */
    (void)fit(&f->pl, &in1, 0);
    rfs_model_fit_in_t other = in2;
    other.map = NULL;
    assert_false(rfs_pathloss_ops.warm(&f->pl, &other, 0));
    assert_int_equal(f->pl.warm.lines, 0u);
    memcpy(whole, &f->pl, sizeof(*whole));

    assert_int_equal(warm_all(whole, &in2, 0), 1);
    const int calls = warm_all(&f->pl, &in2, 1);
    /* a footprint (up to four units) a call at most */
    assert_true(whole->warm.footprints > 300u && (uint32_t)calls > whole->warm.footprints);
    assert_int_equal(f->pl.warm.lines, whole->warm.lines);
    assert_int_equal(f->pl.nrows, whole->nrows);
    assert_int_equal(f->pl.ncols, whole->ncols);
    assert_memory_equal(f->pl.walls, whole->walls, sizeof(whole->walls));
    assert_memory_equal(f->pl.rows, whole->rows, sizeof(whole->rows));
    /* the robot in the same bin: no second pass */
    assert_false(rfs_pathloss_ops.warm(&f->pl, &in2, 1));
    assert_int_equal(f->pl.warm.lines, whole->warm.lines);

    /* a sliced fit in progress is not warmed */
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    assert_int_equal(rfs_pathloss_ops.fit(&f->pl, &in2, 30, &rng), RFS_FIT_MORE);
    assert_false(rfs_pathloss_ops.warm(&f->pl, &in2, 0));
    free(whole);
}

/* Rows the last fit's bins hold are never taken: with more bins than rows (the whole
 * office) warming finds none free for the bins whose centroids moved, stops, and leaves
 * every origin and count as it was (it may only add counts); the relearn equals one
 * without warming. */
static void warm_keeps_the_last_fits_rows(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS / 2, &f->map, &k_office, 11);
    make_samples(f->s + NS / 2, NS / 2, &f->map, &k_office, 12); /* centroids move */
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_t *cold = malloc(sizeof(rfs_pathloss_t));
    rfs_pathloss_t *before = malloc(sizeof(rfs_pathloss_t));
    assert_true(cold != NULL && before != NULL);
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in1 = input(f, NS / 2), in2 = input(f, NS);
    (void)fit(&f->pl, &in1, 0);
    assert_true(f->pl.nbins > RFS_PATHLOSS_BUILTIN_ROWS);
    assert_int_equal(f->pl.nrows, RFS_PATHLOSS_BUILTIN_ROWS);
    memcpy(cold, &f->pl, sizeof(*cold));
    memcpy(before, &f->pl, sizeof(*before));

    (void)warm_all(&f->pl, &in2, 1);
    assert_true(f->pl.warm.stopped);
    assert_memory_equal(f->pl.rows, before->rows, sizeof(before->rows));
    uint32_t kept = 0u;
    for (uint32_t r = 0u; r < RFS_PATHLOSS_BUILTIN_ROWS; ++r) {
        for (uint32_t k = 0u; k < RFS_PATHLOSS_CACHE_COLS; ++k) {
            if (before->walls[r][k] != 255u) {
                assert_int_equal(f->pl.walls[r][k], before->walls[r][k]);
                kept++;
            }
        }
    }
    assert_true(kept > 10000u);
    (void)fit(&f->pl, &in2, 0);
    (void)fit(cold, &in2, 0);
    same_fit(&f->pl, cold);
    free(cold);
    free(before);
}

/* Samples in every bin (bx, by), bx0 <= bx < bx1, by0 <= by < by1, from s; returns the
 * count. */
static int block(fixture_t *f, int at, int bx0, int bx1, int by0, int by1)
{
    for (int bx = bx0; bx < bx1; ++bx) {
        for (int by = by0; by < by1; ++by) {
            bin_samples(f->s + at, 8, &f->map, &k_office, bx, by, (uint64_t)(bx * 100 + by));
            at += 8;
        }
    }
    return at;
}

/* A full cache whose rows partly hold no bin of the last fit (an earlier fit's, emptied by
 * the last fit's tidy): warming takes those for the bins the robot left and keeps every
 * origin the last fit's bins hold, with its counts. */
static void warm_takes_rows_no_bin_holds(void **state)
{
    fixture_t *f = *state;
    const int a = block(f, 0, 1, 11, 1, 7);          /* 60 bins west */
    const int a2 = block(f, a, 1, 11, 10, 14);       /* 40 more */
    const int b = block(f, a2, 16, 26, 1, 7);        /* then 60 bins east */
    const int b2 = block(f, b, 16, 26, 10, 14);      /* 40 more */
    int n = b2;
    for (int bx = 16; bx < 19; ++bx) {               /* the leg, the robot in (18, 7) */
        bin_samples(f->s + n, PER_BIN, &f->map, &k_office, bx, 7, (uint64_t)(900 + bx));
        n += PER_BIN;
    }
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    rfs_pathloss_t *cold = malloc(sizeof(rfs_pathloss_t));
    rfs_pathloss_t *before = malloc(sizeof(rfs_pathloss_t));
    assert_true(cold != NULL && before != NULL);
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t west = input(f, a2), east = {.samples = f->s + a2, .n = (uint16_t)(b2 - a2),
                                                    .map = &f->map};
    rfs_model_fit_in_t leg = {.samples = f->s + a2, .n = (uint16_t)(n - a2), .map = &f->map,
                              .qx = 18 * 65536 + 32768, .qy = 7 * 65536 + 39322};
    (void)fit(&f->pl, &west, 0);
    (void)fit(&f->pl, &east, 0);
    assert_int_equal(f->pl.nrows, RFS_PATHLOSS_BUILTIN_ROWS);
    assert_true(f->pl.nbins < RFS_PATHLOSS_BUILTIN_ROWS);
    memcpy(cold, &f->pl, sizeof(*cold));
    memcpy(before, &f->pl, sizeof(*before));

    (void)warm_all(&f->pl, &leg, 0);
    assert_false(f->pl.warm.stopped);
    uint32_t held = 0u, taken = 0u;
    for (uint32_t r = 0u; r < RFS_PATHLOSS_BUILTIN_ROWS; ++r) {
        bool counted = false;
        for (uint32_t k = 0u; k < RFS_PATHLOSS_CACHE_COLS; ++k) {
            if (before->walls[r][k] != 255u) {
                assert_int_equal(f->pl.walls[r][k], before->walls[r][k]);
                counted = true;
            }
        }
        if (counted) { /* a row the last fit filled keeps its origin */
            assert_int_equal(f->pl.rows[r].cx, before->rows[r].cx);
            assert_int_equal(f->pl.rows[r].cy, before->rows[r].cy);
            held++;
        } else if (f->pl.walls[r][0] != 255u || f->pl.rows[r].cx != before->rows[r].cx ||
                   f->pl.rows[r].cy != before->rows[r].cy) {
            taken++;
        }
    }
    assert_int_equal(held, before->nbins);
    assert_int_equal(taken, 2u); /* the two bins left */
    rfs_pathloss_est_t ew = fit(&f->pl, &leg, 0), ec = fit(cold, &leg, 0);
    same_fit(&f->pl, cold);
    assert_true(ew.footprints < ec.footprints);
    free(cold);
    free(before);
}

/* The work units a warm call charged itself, at least: the wall counts it
 * computed (warm.lines) and a unit every RFS_PATHLOSS_BINS_PER_UNIT columns or bins looked
 * at (warm.seen); binning and tidying aside. */
static uint32_t wm_units(const rfs_pathloss_t *p, uint32_t lines0, uint32_t seen0)
{
    return (p->warm.lines - lines0) +
           (p->warm.seen / RFS_PATHLOSS_BINS_PER_UNIT - seen0 / RFS_PATHLOSS_BINS_PER_UNIT);
}

/* The first fit on the corridor's bins x = 2..11 (y = 7, 8 m), then `leg` more: x = 12 ..
 * 12 + leg - 1 at y = 7 m, and with `both` at y = 8 m too; the robot in the last. Coarse
 * spacing 1 m: 480 coarse points, more than the built-in cache's 256 columns, so most of
 * the last fit's coarse and every refinement point have no column. Warmed to the end at
 * `budget` a call; the most units a call charged. */
static uint32_t wm_worst_call(fixture_t *f, int leg, bool both, uint32_t budget)
{
    int n = corridor(f);
    const int first = n;
    for (int bx = 12; bx < 12 + leg; ++bx) {
        for (int by = 7; by < (both ? 9 : 8); ++by) {
            bin_samples(f->s + n, PER_BIN, &f->map, &k_office, bx, by, (uint64_t)(700 + bx * 10 + by));
            n += PER_BIN;
        }
    }
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    c.coarse = RFS_Q16_INT(1);
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in1 = input(f, first), in2 = input(f, n);
    in1.qx = in2.qx = (11 + leg) * 65536 + 32768;
    (void)fit(&f->pl, &in1, 0);
    assert_int_equal(f->pl.ncols, RFS_PATHLOSS_CACHE_COLS);
    uint32_t worst = 0u, calls = 0u;
    bool more = true;
    while (more && calls < 100000u) {
        const uint32_t l0 = f->pl.warm.lines, s0 = f->pl.warm.seen;
        more = rfs_pathloss_ops.warm(&f->pl, &in2, budget);
        const uint32_t u = wm_units(&f->pl, l0, s0);
        worst = u > worst ? u : worst;
        calls++;
    }
    print_message("rv: leg %d%s, budget %u: %u calls, worst call charged >= %u units\n", leg,
                  both ? " x 2" : "", budget, calls, worst);
    return worst;
}

/* Every call within its budget (the first piece aside, at most 40 units): looks at columns
 * without a cache column are charged but not checked against the budget (warm_count), nor
 * are the rows of the refinement pass (WARM_REFINE). */
static void wm_warm_call_within_budget(void **state)
{
    fixture_t *f = *state;
    const uint32_t w1 = wm_worst_call(f, 16, false, 113u); /* RFS_SEEK_WARM_SLICE(150) */
    const uint32_t w2 = wm_worst_call(f, 16, false, 40u);
    const uint32_t w3 = wm_worst_call(f, 17, true, 113u);
    assert_true(w1 <= 113u);
    assert_true(w2 <= 40u);
    assert_true(w3 <= 113u);
}

/* The whole office (more bins than rows), 40 units a call: warming finds no row, stops,
 * then looks at every bin for the hold search's first points (which have no column,
 * coarse 1 m) and at every row for the refinement pass: those looks are charged but never
 * checked against the budget (warm_hold, WARM_REFINE), and bins with a row are not even
 * charged. */
static void wm_hold_pass_within_budget(void **state)
{
    fixture_t *f = *state;
    make_samples(f->s, NS / 2, &f->map, &k_office, 11);
    make_samples(f->s + NS / 2, NS / 2, &f->map, &k_office, 12);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    c.coarse = RFS_Q16_INT(1);
    assert_int_equal(rfs_pathloss_init(&f->pl, &c), 0);
    rfs_model_fit_in_t in1 = input(f, NS / 2), in2 = input(f, NS);
    (void)fit(&f->pl, &in1, 0);
    uint32_t worst = 0u, calls = 0u;
    bool more = true;
    while (more && calls < 100000u) {
        const uint32_t l0 = f->pl.warm.lines, s0 = f->pl.warm.seen;
        more = rfs_pathloss_ops.warm(&f->pl, &in2, 40u);
        const uint32_t u = wm_units(&f->pl, l0, s0);
        worst = u > worst ? u : worst;
        calls++;
    }
    print_message("rv: office, %u bins, %u rows, stopped %d: %u calls, worst call charged >= %u "
                  "units\n", f->pl.nbins, f->pl.nrows, f->pl.warm.stopped, calls, worst);
    assert_true(worst <= 40u);
}

/* A randomised differential run: model A warms between fits (random budgets, the robot
 * moving between calls, samples added and, the store full, replaced), model B never does.
 * After every fit (A's sliced at a random budget, B's whole) their results are equal, and
 * warming never changes what A publishes. Variants: coarse spacing, one-count coarse pass,
 * hold off or without search, footprint 0, 0.5 m bins, places ruled out, an attached
 * cache, a fit without the map in between. */
#define WM_CAP 900

static void wm_sample(fixture_t *f, rfs_rng_t *r, int *x, int *y, rfs_sample_t *s)
{
    for (int tries = 0; tries < 1000; ++tries) {
        const int nx = *x + (int)rfs_rng_below(r, 81) - 40, ny = *y + (int)rfs_rng_below(r, 81) - 40;
        if (nx >= 10 && ny >= 10 && nx <= 2990 && ny <= 1590 &&
            rfs_map_point_legal(&f->map, (rfs_q16_t)lround(nx / 100.0 * 65536.0),
                                (rfs_q16_t)lround(ny / 100.0 * 65536.0))) {
            *x = nx;
            *y = ny;
            break;
        }
    }
    truth_sample(&f->map, &k_office, *x, *y, 3.0, r, s);
}

typedef struct wm_pub {
    rfs_q16_t v[60];
    rfs_q16_t ax, ay;
    rfs_pathloss_est_t e;
    uint32_t surface[RFS_PATHLOSS_MAX_COARSE];
} wm_pub_t;

static void wm_publish(const rfs_pathloss_t *a, wm_pub_t *o)
{
    memset(o, 0, sizeof(*o));
    int q = 0;
    for (int i = 0; i < 30; i += 3) {
        for (int j = 0; j < 16; j += 3) {
            assert_true(rfs_pathloss_ops.predict(a, i * 65536 + 32768, j * 65536 + 32768, &o->v[q++]));
        }
    }
    assert_true(rfs_pathloss_ops.argmax(a, &o->ax, &o->ay));
    assert_true(rfs_pathloss_estimate(a, &o->e));
    memcpy(o->surface, a->surface, sizeof(o->surface));
}

static void wm_run(fixture_t *f, const rfs_pathloss_cfg_t *c, bool attach, bool excl, uint64_t seed)
{
    rfs_pathloss_t *a = malloc(sizeof(*a)), *b = malloc(sizeof(*b));
    rfs_sample_t *s = malloc(sizeof(rfs_sample_t) * WM_CAP);
    wm_pub_t *p0 = malloc(sizeof(*p0)), *p1 = malloc(sizeof(*p1));
    const uint32_t bytes = rfs_pathloss_cache_bytes(300);
    void *bufa = attach ? malloc(bytes) : NULL, *bufb = attach ? malloc(bytes) : NULL;
    assert_true(a != NULL && b != NULL && s != NULL && p0 != NULL && p1 != NULL);
    assert_int_equal(rfs_pathloss_init(a, c), 0);
    assert_int_equal(rfs_pathloss_init(b, c), 0);
    if (attach) {
        assert_int_equal(rfs_pathloss_cache_attach(a, bufa, bytes, 300), 0);
        assert_int_equal(rfs_pathloss_cache_attach(b, bufb, bytes, 300), 0);
    }
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    int x = 300, y = 800, n = 0;
    uint32_t seen = 0u;
    int16_t ex[4] = {0}, ey[4] = {0};
    uint8_t nexcl = 0u;
    for (int fitno = 0; fitno < 14; ++fitno) {
        rfs_model_fit_in_t in = {.samples = s, .n = (uint16_t)n, .map = fitno == 7 ? NULL : &f->map,
                                 .qx = (rfs_q16_t)(x * 65536 / 100), .qy = (rfs_q16_t)(y * 65536 / 100),
                                 .excl_x_cm = ex, .excl_y_cm = ey, .nexcl = nexcl,
                                 .excl_r = excl ? RFS_Q16_INT(2) : 0};
        if (n > 0) {
            rfs_pathloss_ops.reset(a);
            rfs_pathloss_ops.reset(b);
            (void)fit(a, &in, 1u + rfs_rng_below(&r, 200));
            (void)fit(b, &in, 0);
            assert_memory_equal(&a->best, &b->best, sizeof(a->best));
            assert_memory_equal(a->top, b->top, sizeof(a->top));
            assert_memory_equal(a->surface, b->surface, sizeof(a->surface));
            assert_int_equal(a->spread_m2, b->spread_m2);
            assert_int_equal(a->candidates, b->candidates);
            assert_int_equal(a->used_bins, b->used_bins);
        }
        if (excl && rfs_rng_below(&r, 2) == 0u && nexcl < 4u) {
            ex[nexcl] = (int16_t)x;
            ey[nexcl] = (int16_t)y;
            nexcl++;
        }
        const bool valid = a->valid;
        if (valid) {
            wm_publish(a, p0);
        }
        const int steps = 20 + (int)rfs_rng_below(&r, 120);
        for (int t = 0; t < steps; ++t) {
            for (int k = 0; k < 3; ++k) {
                rfs_sample_t sm;
                wm_sample(f, &r, &x, &y, &sm);
                seen++;
                if (n < WM_CAP) {
                    s[n++] = sm;
                } else if (rfs_rng_below(&r, seen) < WM_CAP) {
                    s[rfs_rng_below(&r, WM_CAP)] = sm;
                }
            }
            rfs_model_fit_in_t wi = in;
            wi.n = (uint16_t)n;
            wi.map = &f->map;
            wi.qx = (rfs_q16_t)(x * 65536 / 100);
            wi.qy = (rfs_q16_t)(y * 65536 / 100);
            wi.nexcl = nexcl;
            (void)rfs_pathloss_ops.warm(a, &wi, 1u + rfs_rng_below(&r, 150));
            if (valid) {
                wm_publish(a, p1);
                assert_memory_equal(p1, p0, sizeof(*p0));
            }
        }
    }
    free(a);
    free(b);
    free(s);
    free(p0);
    free(p1);
    free(bufa);
    free(bufb);
}

static void wm_differential(void **state)
{
    fixture_t *f = *state;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
        wm_run(f, &c, false, false, seed);
        c.coarse = RFS_Q16_INT(1);
        wm_run(f, &c, false, true, seed + 100);
        c.coarse_footprint = 0;
        wm_run(f, &c, false, true, seed + 200);
        c = rfs_pathloss_cfg_default();
        c.coarse_footprint = 0;
        c.hold_search = false;
        wm_run(f, &c, true, true, seed + 300);
        c = rfs_pathloss_cfg_default();
        c.footprint = 0;
        c.hold_k = 0;
        wm_run(f, &c, false, false, seed + 400);
        c = rfs_pathloss_cfg_default();
        c.bin = RFS_Q16_FRAC(1, 2);
        wm_run(f, &c, true, true, seed + 500);
    }
}

/* The seeker's warming (rfs_seek.c warm_next) in a closed loop. The
 * path-loss model's operations are wrapped: warm is asserted to run only between fits
 * (no fit or decision in progress) and to leave predictions, argmax and estimate as they
 * were; every fit call is repeated on a shadow model that never warms (the same inputs and
 * budget: binning, the only part that reads the samples, is sliced alike), and when both are
 * done their results must be equal. meta-path, the MCU budget (150 units) and a sliced
 * search tree, the office and its double world of closed_loop_run. */
typedef struct wm_loop {
    rfs_seek_t *sk;
    rfs_pathloss_t *a;      /* the seeker's model */
    rfs_pathloss_t *b;      /* the shadow */
    bool b_done;
    uint32_t warms, warmed_lines, fits, compared;
} wm_loop_t;

static wm_loop_t wm_lp;
static rfs_model_ops_t wm_ops;

static void wm_snap(const rfs_pathloss_t *p, rfs_q16_t v[40], rfs_q16_t *ax, rfs_q16_t *ay)
{
    memset(v, 0, 40 * sizeof(v[0]));
    int q = 0;
    for (int i = 1; i < 30; i += 4) {
        for (int j = 1; j < 16; j += 4) {
            v[q] = 0;
            (void)rfs_pathloss_ops.predict(p, Q16(i), Q16(j), &v[q]);
            q++;
        }
    }
    *ax = *ay = 0;
    (void)rfs_pathloss_ops.argmax(p, ax, ay);
}

static bool wm_warm(void *self, const rfs_model_fit_in_t *in, uint32_t budget)
{
    assert_ptr_equal(self, wm_lp.a);
    assert_false(wm_lp.sk->fitting);
    assert_false(wm_lp.sk->planning);
    rfs_q16_t v0[40], v1[40], x0, y0, x1, y1;
    rfs_pathloss_est_t e0, e1;
    memset(&e0, 0, sizeof(e0)); /* the padding after .bins */
    memset(&e1, 0, sizeof(e1));
    const bool ok0 = rfs_pathloss_estimate(wm_lp.a, &e0);
    wm_snap(wm_lp.a, v0, &x0, &y0);
    const uint32_t l0 = wm_lp.a->warm.lines;
    const bool more = rfs_pathloss_ops.warm(self, in, budget);
    wm_lp.warms++;
    wm_lp.warmed_lines += wm_lp.a->warm.lines - l0;
    wm_snap(wm_lp.a, v1, &x1, &y1);
    assert_memory_equal(v0, v1, sizeof(v0));
    assert_int_equal(x0, x1);
    assert_int_equal(y0, y1);
    assert_int_equal(rfs_pathloss_estimate(wm_lp.a, &e1), ok0);
    if (ok0) {
        est_equal(&e0, &e1);
    }
    return more;
}

static void wm_reset(void *self)
{
    rfs_pathloss_ops.reset(self);
    rfs_pathloss_ops.reset(wm_lp.b);
    wm_lp.b_done = false;
}

static rfs_fit_result_t wm_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                               rfs_rng_t *rng)
{
    const rfs_fit_result_t r = rfs_pathloss_ops.fit(self, in, budget, rng);
    rfs_fit_result_t rb = RFS_FIT_DONE;
    if (!wm_lp.b_done) {
        rb = rfs_pathloss_ops.fit(wm_lp.b, in, budget, rng);
        wm_lp.b_done = rb != RFS_FIT_MORE;
    }
    if (r != RFS_FIT_MORE) {
        for (int k = 0; !wm_lp.b_done && k < 100000; ++k) {
            rb = rfs_pathloss_ops.fit(wm_lp.b, in, budget, rng);
            wm_lp.b_done = rb != RFS_FIT_MORE;
        }
        assert_true(wm_lp.b_done);
        assert_int_equal(wm_lp.a->valid, wm_lp.b->valid);
        if (r == RFS_FIT_DONE) {
            assert_memory_equal(&wm_lp.a->best, &wm_lp.b->best, sizeof(wm_lp.a->best));
            assert_memory_equal(wm_lp.a->surface, wm_lp.b->surface, sizeof(wm_lp.a->surface));
            assert_int_equal(wm_lp.a->spread_m2, wm_lp.b->spread_m2);
            wm_lp.compared++;
        }
        wm_lp.fits++;
    }
    return r;
}

static void wm_seek_run(fixture_t *f, uint64_t seed, uint32_t plan_budget)
{
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.fit_budget = 150u;
    cfg.plan_budget = plan_budget;
    rfs_seek_mem_t mem;
    office_seek_mem(&f->map, cfg.store.capacity, &mem);
    rfs_seek_t *sk = calloc(1, sizeof(*sk));
    rfs_pathloss_t *shadow = malloc(sizeof(*shadow));
    assert_true(sk != NULL && shadow != NULL);
    rfs_pathloss_cfg_t pc = rfs_pathloss_cfg_default();
    assert_int_equal(rfs_pathloss_init(&f->pl, &pc), 0);
    assert_int_equal(rfs_pathloss_init(shadow, &pc), 0);
    memset(&wm_lp, 0, sizeof(wm_lp));
    wm_lp.sk = sk;
    wm_lp.a = &f->pl;
    wm_lp.b = shadow;
    wm_ops = rfs_pathloss_ops;
    wm_ops.warm = wm_warm;
    wm_ops.fit = wm_fit;
    wm_ops.reset = wm_reset;
    rfs_model_t model = {&wm_ops, &f->pl};
    assert_int_equal(rfs_seek_init(sk, &cfg, &f->map, model, &rfs_target_rssi, &mem), 0);
    rfs_rng_t rng, noise;
    rfs_rng_seed(&rng, seed);
    rfs_rng_seed(&noise, 1000u + seed);
    const bool reached = office_seek_run(&f->map, sk, &rng, &noise, NULL) >= 0.0;
    print_message("warming seeker seed %u plan %u: %s, %u warm calls (%u counts), %u fits, %u compared\n",
                  (unsigned)seed, plan_budget, reached ? "reached" : "not reached", wm_lp.warms,
                  wm_lp.warmed_lines, wm_lp.fits, wm_lp.compared);
    assert_true(wm_lp.warms > 0u && wm_lp.warmed_lines > 0u && wm_lp.compared > 1u);
    free(sk);
    free(shadow);
    office_seek_mem_free(&mem);
}

static void wm_seek_warms_between_fits_only(void **state)
{
    fixture_t *f = *state;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        wm_seek_run(f, seed, 0u);
        wm_seek_run(f, seed, RFS_SEEK_PLAN_BUDGET);
    }
}

static void only_pathloss_warms(void **state)
{
    (void)state;
    assert_true(rfs_models_find("pathloss")->warm == rfs_pathloss_ops.warm);
    assert_non_null(rfs_pathloss_ops.warm);
    assert_null(rfs_fields_ops.warm);
    const char *others[] = {"ridge", "mlp", "knn", "radius"};
    for (int k = 0; k < 4; ++k) {
        assert_non_null(rfs_models_find(others[k]));
        assert_null(rfs_models_find(others[k])->warm);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(relearn_after_warm_equals_relearn_without, setup, teardown),
        cmocka_unit_test_setup_teardown(warm_leaves_the_model_unchanged, setup, teardown),
        cmocka_unit_test_setup_teardown(warm_resumes_at_budget_one, setup, teardown),
        cmocka_unit_test_setup_teardown(warm_keeps_the_last_fits_rows, setup, teardown),
        cmocka_unit_test_setup_teardown(warm_takes_rows_no_bin_holds, setup, teardown),
        cmocka_unit_test_setup_teardown(wm_warm_call_within_budget, setup, teardown),
        cmocka_unit_test_setup_teardown(wm_hold_pass_within_budget, setup, teardown),
        cmocka_unit_test_setup_teardown(wm_differential, setup, teardown),
        cmocka_unit_test_setup_teardown(wm_seek_warms_between_fits_only, setup, teardown),
        cmocka_unit_test(only_pathloss_warms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
