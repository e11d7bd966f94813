/* test_fmt.c - hs_fmt_fixed() against glibc's snprintf("%.*f"), byte for byte: random
 * values over every magnitude the logs write, exact halves (ties to even), values a few
 * ulps either side of a half, signed zeros and tiny negatives, and the snprintf cases. */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hs_fmt.h"
#include "rfs_fix.h"

static void same(double v, int prec)
{
    char want[HS_FMT_MAX + 8], got[HS_FMT_MAX];
    int n = snprintf(want, sizeof want, "%.*f", prec, v);
    size_t m = hs_fmt_fixed(got, v, prec);
    if ((size_t)n != m || strcmp(want, got) != 0) {
        fail_msg("%.17g at %d: printf \"%s\", hs_fmt_fixed \"%s\"", v, prec, want, got);
    }
}

static double uniform(rfs_rng_t *r)
{
    return (double)rfs_rng_u32(r) / 4294967296.0;
}

static void random_values_match_printf(void **state)
{
    (void)state;
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    for (uint32_t i = 0; i < 2000000u; ++i) {
        double mag = pow(10.0, -8.0 + 17.0 * uniform(&r)); /* 1e-8 .. 1e9 */
        double v = (rfs_rng_below(&r, 2) ? -1.0 : 1.0) * mag * uniform(&r);
        same(v, (int)rfs_rng_below(&r, 7));
    }
}

static void halves_and_their_neighbours_match_printf(void **state)
{
    (void)state;
    rfs_rng_t r;
    rfs_rng_seed(&r, 8);
    uint32_t exact = 0;
    for (uint32_t i = 0; i < 300000u; ++i) {
        int prec = (int)rfs_rng_below(&r, 7);
        /* (k + 1/2) / 10^prec: exact in binary for some k (0.125, 2.5 ...), else near */
        double k = (double)rfs_rng_below(&r, 2000000u) / (rfs_rng_below(&r, 2) ? 1.0 : 1000.0);
        double v = (floor(k) + 0.5) / pow(10.0, prec);
        exact += (v * pow(10.0, prec) - floor(v * pow(10.0, prec)) == 0.5) ? 1u : 0u;
        double w = v;
        for (int u = 0; u < 4; ++u) {
            w = nextafter(w, -INFINITY);
        }
        for (int u = 0; u < 9; ++u) {
            same(w, prec);
            same(-w, prec);
            w = nextafter(w, INFINITY);
        }
    }
    assert_true(exact > 1000u); /* exact ties were there to round to even */
}

static void specials_match_printf(void **state)
{
    (void)state;
    const double v[] = {0.0, -0.0, -1e-9, -0.0004, -0.0005, -0.0006, 0.0005, 0.0015, 0.0025,
                        2.5, 3.5, -2.5, 0.125, 1e9, -1e9, 999999999.9999, 1e15, -3.7e20,
                        NAN, -NAN, INFINITY, -INFINITY, 1.0 / 3.0, 2.0 / 3.0, 4503599627370495.5,
                        0.045, 0.055, 1.005, 1.015, 1.025, 16.4, 7.04, 123.4565, 123.4575};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i) {
        for (int prec = 0; prec <= 8; ++prec) {
            same(v[i], prec);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(random_values_match_printf),
        cmocka_unit_test(halves_and_their_neighbours_match_printf),
        cmocka_unit_test(specials_match_printf),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
