/* bench_ridge.c - instruction counts of the data path (ridge fit and predict, RSSI window,
 * sample store), for callgrind (`make bench-data`, docs/PERFORMANCE.md "data").
 *
 *   bench_ridge fit N [spread_cm]   one ridge fit over N samples (default: all within 5 m)
 *   bench_ridge predict N           N predictions, one call each
 *   bench_ridge row N               N predictions in rows of 160 (predict_row)
 *   bench_ridge rssi N              N pushes + means at 400 packets/s
 *   bench_ridge store N             N measurements + poses at 400/s and 10 Hz
 * Collection is toggled on around the measured calls only (CALLGRIND_TOGGLE_COLLECT), so callgrind
 * with --collect-atstart=no counts exactly them. Prints a checksum so nothing is elided.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <valgrind/callgrind.h>

#include "rfs_ridge.h"
#include "rfs_rssi.h"
#include "rfs_store.h"

static int usage(FILE *f, int rc)
{
    fprintf(f, "usage: bench_ridge fit|predict|row|rssi|store N [spread_cm]\n"
               "  fit N [spread_cm]  one ridge fit over N samples within +-spread_cm (350)\n"
               "  predict N          N predictions of a fitted model, one call each\n"
               "  row N              N predictions in rows of 160 (predict_row)\n"
               "  rssi N             N pushes and means of one window (400 packets/s)\n"
               "  store N            N measurements with poses at 10 Hz\n");
    return rc;
}

static rfs_sample_t *make_samples(uint32_t n, int32_t spread, rfs_rng_t *g)
{
    rfs_sample_t *s = malloc(sizeof(rfs_sample_t) * (n ? n : 1));
    if (s == NULL) {
        fprintf(stderr, "bench_ridge: out of memory\n");
        exit(1);
    }
    for (uint32_t i = 0; i < n; ++i) {
        /* within a square of +-spread around (100 m, 50 m); spread 350 keeps all in 5 m */
        s[i].x_cm = (int16_t)(10000 - spread + (int32_t)rfs_rng_below(g, 2u * spread + 1u));
        s[i].y_cm = (int16_t)(5000 - spread + (int32_t)rfs_rng_below(g, 2u * spread + 1u));
        s[i].v_q6 = (int16_t)(-(int32_t)rfs_rng_below(g, 8193u));
    }
    return s;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        return usage(stdout, 0);
    }
    if (argc < 3) {
        return usage(stderr, 2);
    }
    char *end = NULL;
    long n = strtol(argv[2], &end, 10);
    if (*end != '\0' || n < 0 || n > 65535) {
        fprintf(stderr, "bench_ridge: N: '%s' is not an integer in 0..65535\n", argv[2]);
        return 2;
    }
    long spread = 350;
    if (argc >= 4) {
        spread = strtol(argv[3], &end, 10);
        if (*end != '\0' || spread < 1 || spread > 16000) {
            fprintf(stderr, "bench_ridge: spread_cm: '%s' is not an integer in 1..16000\n", argv[3]);
            return 2;
        }
    }
    rfs_rng_t g;
    rfs_rng_seed(&g, 42u);
    int64_t check = 0;
    if (strcmp(argv[1], "fit") == 0 || strcmp(argv[1], "predict") == 0 ||
        strcmp(argv[1], "row") == 0) {
        bool fit = strcmp(argv[1], "fit") == 0;
        bool row = strcmp(argv[1], "row") == 0;
        uint32_t ns = fit ? (uint32_t)n : 10000u;
        rfs_sample_t *s = make_samples(ns, (int32_t)spread, &g);
        rfs_ridge_t r;
        rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
        if (rfs_ridge_init(&r, &rc) != 0) {
            return 1;
        }
        rfs_model_fit_in_t in = {.samples = s, .n = (uint16_t)ns, .qx = RFS_Q16_INT(100),
                                 .qy = RFS_Q16_INT(50), .map = NULL};
        if (fit) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        rfs_fit_result_t res = rfs_ridge_ops.fit(&r, &in, 0u, &g);
        if (fit) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        check = res * 1000003 + r.icpt + r.wx_q24 + r.wy_q24;
        if (row) {
            /* rows of 160 points 0.25 m apart (a 40 m wide map), N points in all */
            static rfs_q16_t out[160];
            CALLGRIND_TOGGLE_COLLECT;
            for (long i = 0; i < n; i += 160) {
                uint16_t len = (uint16_t)(n - i < 160 ? n - i : 160);
                rfs_ridge_ops.predict_row(&r, 0, (rfs_q16_t)((i / 160) * 16384), 16384, len, out);
                check += out[0] + out[len - 1];
            }
            CALLGRIND_TOGGLE_COLLECT;
        } else if (!fit) {
            rfs_q16_t v = 0;
            CALLGRIND_TOGGLE_COLLECT;
            rfs_q16_t x = 0, y = 0;
            for (long i = 0; i < n; ++i) {
                /* a 40 x 20 m map at 0.25 m, walked row by row */
                rfs_ridge_ops.predict(&r, x, y, &v);
                check += v;
                x += 16384;
                if (x == RFS_Q16_INT(40)) {
                    x = 0;
                    y += 16384;
                }
            }
            CALLGRIND_TOGGLE_COLLECT;
        }
        free(s);
    } else if (strcmp(argv[1], "rssi") == 0) {
        rfs_rssi_t w;
        rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
        rfs_rssi_init(&w, &c);
        CALLGRIND_TOGGLE_COLLECT;
        for (long i = 0; i < n; ++i) {
            rfs_q16_t m = 0;
            rfs_rssi_push(&w, (int64_t)i * 2500, (int8_t)(-40 - (i & 63)));
            rfs_rssi_mean(&w, (int64_t)i * 2500, &m);
            check += m;
        }
        CALLGRIND_TOGGLE_COLLECT;
    } else if (strcmp(argv[1], "store") == 0) {
        static rfs_sample_t samples[10000];
        static rfs_pending_t pending[256];
        rfs_store_t s;
        rfs_store_cfg_t c = rfs_store_cfg_default();
        rfs_store_init(&s, &c, samples, pending, 256);
        CALLGRIND_TOGGLE_COLLECT;
        for (long i = 0; i < n; ++i) {
            int64_t t = (int64_t)i * 2500;
            if (i % 40 == 0) {
                rfs_pose_t p = {.t_us = t, .x = (rfs_q16_t)(i * 100), .y = (rfs_q16_t)(i * 50), .theta = 0};
                rfs_store_add_pose(&s, &p, &g);
            }
            rfs_store_add_value(&s, t, RFS_Q16_INT(-60), &g);
        }
        CALLGRIND_TOGGLE_COLLECT;
        check = s.count + (int64_t)s.seen;
    } else {
        return usage(stderr, 2);
    }
    printf("%lld\n", (long long)check);
    return 0;
}
