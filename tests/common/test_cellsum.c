/* test_cellsum.c - the cell sums of the sample store (docs/MODELS.md, "Cell sums"):
 * the nine disc sums against a one-by-one pass in double precision (exact: every sum is
 * an integer below 2^53), under reservoir replacement, samples off the box, discs across
 * cell edges and the box's edge, tiny and map-wide radii; and the local ridge fitted
 * from them equal, bit for bit, to the ridge fitted by visiting every sample.
 */
#include "rfs_test.h"

#include <math.h>
#include <string.h>

#include "rfs_cellsum.h"
#include "rfs_ridge.h"
#include "rfs_store.h"

#define CAP 3000u
#define BOX_X0 (-250)
#define BOX_Y0 120
#define BOX_W 2000
#define BOX_H 1300

typedef struct fixture {
    rfs_store_t store;
    rfs_sample_t samples[CAP];
    rfs_pending_t pending[8];
    rfs_cellsum_t cs;
    rfs_store_index_t ix;
    rfs_cellsum_cell_t cells[41000];
    uint16_t links[2 * CAP];
    rfs_rng_t rng;
} fixture_t;

static fixture_t *fixture_new(uint16_t cap, uint8_t shift)
{
    fixture_t *f = calloc(1, sizeof *f);
    assert_non_null(f);
    rfs_store_cfg_t c = rfs_store_cfg_default();
    c.capacity = cap;
    assert_int_equal(rfs_store_init(&f->store, &c, f->samples, f->pending, 8), 0);
    uint32_t n = rfs_cellsum_cells(BOX_W, BOX_H, shift);
    assert_true(n > 0u && n <= 41000u);
    assert_int_equal(rfs_cellsum_init(&f->cs, BOX_X0, BOX_Y0, BOX_W, BOX_H, shift, f->cells, n,
                                      f->links, CAP),
                     0);
    f->ix = rfs_cellsum_index(&f->cs);
    rfs_rng_seed(&f->rng, 99);
    return f;
}

/* A sample mostly on the box, some off it (up to 3 m beyond each edge). */
static rfs_sample_t draw(rfs_rng_t *r)
{
    rfs_sample_t s;
    s.x_cm = (int16_t)(BOX_X0 - 300 + (int32_t)rfs_rng_below(r, BOX_W + 600));
    s.y_cm = (int16_t)(BOX_Y0 - 300 + (int32_t)rfs_rng_below(r, BOX_H + 600));
    s.v_q6 = (int16_t)((int32_t)rfs_rng_below(r, 65536) - 32768);
    return s;
}

/* The disc sums one sample at a time, in double. */
static void reference(const rfs_store_t *st, int32_t qx, int32_t qy, int32_t r, double out[9])
{
    memset(out, 0, 9 * sizeof(double));
    for (uint16_t i = 0; i < st->count; ++i) {
        double u = (double)st->samples[i].x_cm - qx, v = (double)st->samples[i].y_cm - qy;
        double z = st->samples[i].v_q6;
        if (u * u + v * v > (double)r * r) {
            continue;
        }
        out[0] += 1;
        out[1] += u;
        out[2] += v;
        out[3] += z;
        out[4] += u * u;
        out[5] += u * v;
        out[6] += v * v;
        out[7] += u * z;
        out[8] += v * z;
    }
}

static void check_disc(const fixture_t *f, int32_t qx, int32_t qy, int32_t r)
{
    double want[9];
    reference(&f->store, qx, qy, r, want);
    rfs_cellsum_disc_t d;
    rfs_cellsum_disc(&f->cs, f->samples, qx, qy, r, &d);
    const int64_t got[9] = {d.n, d.su, d.sv, d.sz, d.suu, d.suv, d.svv, d.suz, d.svz};
    for (int k = 0; k < 9; ++k) {
        if ((double)got[k] != want[k]) {
            fail_msg("q (%d, %d) r %d: sum %d is %lld, want %.0f", qx, qy, r, k,
                     (long long)got[k], want[k]);
        }
    }
}

/* Random discs against the reference while the reservoir replaces samples. */
static void test_disc_sums_equal_one_by_one(void **state)
{
    (void)state;
    const uint8_t shifts[] = {3, 5, 6, 10};
    for (unsigned t = 0; t < sizeof shifts; ++t) {
        fixture_t *f = fixture_new(1000, shifts[t]);
        rfs_store_set_index(&f->store, &f->ix);
        rfs_rng_t r;
        rfs_rng_seed(&r, 17u + t);
        for (int round = 0; round < 6; ++round) {
            for (int k = 0; k < 700; ++k) { /* fills, then replaces */
                rfs_store_offer(&f->store, draw(&r), &f->rng);
            }
            for (int q = 0; q < 60; ++q) {
                int32_t qx = BOX_X0 - 600 + (int32_t)rfs_rng_below(&r, BOX_W + 1200);
                int32_t qy = BOX_Y0 - 600 + (int32_t)rfs_rng_below(&r, BOX_H + 1200);
                const int32_t radii[] = {0, 1, 37, 500, 1234, 30000};
                check_disc(f, qx, qy, radii[q % 6]);
            }
        }
        assert_int_equal(f->store.count, 1000);
        assert_true(f->store.seen == 4200u);
        free(f);
    }
}

/* Discs centred on cell corners and edges, where the inside / cut / outside tests are
 * tight, with samples stacked on the corners. */
static void test_disc_on_cell_edges(void **state)
{
    (void)state;
    fixture_t *f = fixture_new(CAP, 5);
    rfs_store_set_index(&f->store, &f->ix);
    rfs_rng_t r;
    rfs_rng_seed(&r, 5);
    for (uint32_t k = 0; k < CAP; ++k) {
        rfs_sample_t s;
        s.x_cm = (int16_t)(BOX_X0 + 32 * (int32_t)rfs_rng_below(&r, 20) - (int32_t)rfs_rng_below(&r, 2));
        s.y_cm = (int16_t)(BOX_Y0 + 32 * (int32_t)rfs_rng_below(&r, 20) - (int32_t)rfs_rng_below(&r, 2));
        s.v_q6 = (int16_t)((int32_t)rfs_rng_below(&r, 8192) - 8192);
        rfs_store_offer(&f->store, s, &f->rng);
    }
    for (int32_t i = 0; i < 12; ++i) {
        for (int32_t j = 0; j < 12; ++j) {
            for (int32_t r2 = 0; r2 < 200; r2 += 31) {
                check_disc(f, BOX_X0 + 32 * i + (i % 3) - 1, BOX_Y0 + 32 * j + (j % 3) - 1, r2);
            }
        }
    }
    free(f);
}

/* An index attached to a store that already holds samples takes them in. */
static void test_index_attached_late(void **state)
{
    (void)state;
    fixture_t *f = fixture_new(500, 6);
    rfs_rng_t r;
    rfs_rng_seed(&r, 8);
    for (int k = 0; k < 800; ++k) {
        rfs_store_offer(&f->store, draw(&r), &f->rng);
    }
    rfs_store_set_index(&f->store, &f->ix);
    for (int k = 0; k < 300; ++k) {
        rfs_store_offer(&f->store, draw(&r), &f->rng);
    }
    for (int q = 0; q < 50; ++q) {
        check_disc(f, BOX_X0 + (int32_t)rfs_rng_below(&r, BOX_W),
                   BOX_Y0 + (int32_t)rfs_rng_below(&r, BOX_H), 400 + 20 * q);
    }
    free(f);
}

/* The ridge from cell sums is the ridge from every sample, field for field. */
static void test_ridge_from_cell_sums_is_identical(void **state)
{
    (void)state;
    fixture_t *f = fixture_new(CAP, 5);
    rfs_store_set_index(&f->store, &f->ix);
    rfs_rng_t r;
    rfs_rng_seed(&r, 23);
    for (uint32_t k = 0; k < 2 * CAP; ++k) {
        rfs_sample_t s = draw(&r);
        s.v_q6 = (int16_t)(-4000 + s.x_cm / 4 - s.y_cm / 7 + (int32_t)rfs_rng_below(&r, 512));
        rfs_store_offer(&f->store, s, &f->rng);
    }
    rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
    for (int q = 0; q < 200; ++q) {
        rfs_ridge_t a, b;
        assert_int_equal(rfs_ridge_init(&a, &rc), 0);
        assert_int_equal(rfs_ridge_init(&b, &rc), 0);
        rfs_model_fit_in_t in = {.samples = f->samples, .n = f->store.count,
                                 .qx = (rfs_q16_t)((BOX_X0 + (int32_t)rfs_rng_below(&r, BOX_W)) * 65536 / 100),
                                 .qy = (rfs_q16_t)((BOX_Y0 + (int32_t)rfs_rng_below(&r, BOX_H)) * 65536 / 100)};
        rfs_fit_result_t ra = rfs_ridge_ops.fit(&a, &in, 0u, &f->rng);
        in.index = &f->ix;
        rfs_fit_result_t rb = rfs_ridge_ops.fit(&b, &in, 0u, &f->rng);
        assert_int_equal(ra, rb);
        assert_int_equal(a.acc.n, b.acc.n);
        assert_true(a.acc.suu == b.acc.suu && a.acc.svz == b.acc.svz && a.acc.sz == b.acc.sz);
        assert_true(a.wx_q24 == b.wx_q24 && a.wy_q24 == b.wy_q24 && a.icpt == b.icpt);
        if (ra == RFS_FIT_DONE) {
            rfs_q16_t va, vb;
            assert_true(rfs_ridge_ops.predict(&a, in.qx + 65536, in.qy - 30000, &va));
            assert_true(rfs_ridge_ops.predict(&b, in.qx + 65536, in.qy - 30000, &vb));
            assert_int_equal(va, vb);
        }
    }
    free(f);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    rfs_cellsum_t c;
    rfs_cellsum_cell_t cells[4];
    uint16_t links[8];
    assert_int_equal(rfs_cellsum_cells(0, 10, 5), 0);
    assert_int_equal(rfs_cellsum_cells(65536, 10, 5), 0);
    assert_int_equal(rfs_cellsum_cells(100, 100, 2), 0);
    assert_int_equal(rfs_cellsum_cells(100, 100, 11), 0);
    assert_int_equal(rfs_cellsum_cells(64, 65, 5), 2 * 3);
    assert_int_equal(rfs_cellsum_init(&c, 0, 0, 64, 65, 5, cells, 5, links, 4), -1);
    assert_int_equal(rfs_cellsum_init(&c, 0, 0, 64, 65, 5, NULL, 6, links, 4), -1);
    assert_int_equal(rfs_cellsum_init(&c, 0, 0, 64, 64, 5, cells, 4, links, 0), -1);
    assert_int_equal(rfs_cellsum_init(&c, 0, 0, 64, 64, 5, cells, 4, links, 4), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disc_sums_equal_one_by_one),
        cmocka_unit_test(test_disc_on_cell_edges),
        cmocka_unit_test(test_index_attached_late),
        cmocka_unit_test(test_ridge_from_cell_sums_is_identical),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
