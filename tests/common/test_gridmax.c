/* test_gridmax.c - the kNN / radius upper bound over a box (common/rfs_knn.c, bound op)
 * and the grid search (common/rfs_gridmax.c): the branch and bound and the row shortcut.
 *
 * The bound is checked against a brute-force nearest-neighbour computation in double
 * precision here (every sample, exact squared distances, the most favourable choice at a
 * tie), at many queries inside each box, and against predict() bit for bit. The pruned
 * search is checked against the full scan (rfs_gridmax_scan: same success, same
 * point, ties included) over many random sample sets, reachability patterns, both modes
 * and random holes (points without a prediction, which both searches skip), and both
 * against a brute force that skips such points: radius exactly, k-neighbours within the
 * range a tie allows; they fail only when no reachable point has a prediction.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_gridmax.h"
#include "rfs_knn.h"
#include "seek_world.h"

#define MAXN 3000u

static rfs_sample_t g_s[MAXN];
static rfs_knn_t g_knn;

static double urand(rfs_rng_t *r)
{
    return (double)rfs_rng_u32(r) / 4294967296.0;
}

/* Sample sets over [0, w] x [0, h] metres: 0 uniform, 1 a robot-like random walk, 2 a few
 * tight clusters, 3 few distinct positions (many equal distances). levels > 0 quantises
 * the targets to that many values (many equal predictions: the tie rule); else a smooth
 * field plus noise. */
static void make_samples(uint32_t n, uint32_t kind, double w, double h, uint32_t levels,
                         rfs_rng_t *r)
{
    double x = w / 2, y = h / 2, dx = 0.05, dy = 0;
    double cx[4], cy[4];
    for (int c = 0; c < 4; ++c) {
        cx[c] = urand(r) * w;
        cy[c] = urand(r) * h;
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (kind == 0) {
            x = urand(r) * w;
            y = urand(r) * h;
        } else if (kind == 1) {
            if (i % 20u == 0u) {
                double a = urand(r) * 6.283185307179586;
                dx = 0.05 * cos(a);
                dy = 0.05 * sin(a);
            }
            x = fmin(fmax(x + dx, 0.0), w);
            y = fmin(fmax(y + dy, 0.0), h);
        } else if (kind == 2) {
            uint32_t c = rfs_rng_below(r, 4);
            x = fmin(fmax(cx[c] + (urand(r) - 0.5) * 0.6, 0.0), w);
            y = fmin(fmax(cy[c] + (urand(r) - 0.5) * 0.6, 0.0), h);
        } else {
            x = (double)rfs_rng_below(r, (uint32_t)w + 1u);
            y = (double)rfs_rng_below(r, (uint32_t)h + 1u);
        }
        g_s[i].x_cm = (int16_t)lround(x * 100.0);
        g_s[i].y_cm = (int16_t)lround(y * 100.0);
        if (levels > 0u) {
            g_s[i].v_q6 = (int16_t)(-60 * 64 + 64 * (int32_t)rfs_rng_below(r, levels));
        } else {
            double d = hypot(x - 0.7 * w, y - 0.3 * h);
            g_s[i].v_q6 = (int16_t)lround((-40.0 - 2.0 * d + (urand(r) - 0.5) * 8.0) * 64.0);
        }
    }
}

static void fit(const rfs_knn_cfg_t *c, uint32_t n)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_model_fit_in_t in = {.samples = g_s, .n = (uint16_t)n};
    assert_int_equal(rfs_knn_init(&g_knn, c), 0);
    assert_int_equal(rfs_knn_model(&g_knn).ops->fit(&g_knn, &in, 0, &rng), RFS_FIT_DONE);
}

/* The query position the model uses (rfs_knn.h: rounded to 1/256 cm), in cm Q8. */
static double q8(rfs_q16_t v)
{
    return floor(((double)v * 100.0 + 128.0) / 256.0);
}

static int cmp_asc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

static int cmp_desc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? 1 : (x > y ? -1 : 0);
}

/* k-neighbours by brute force in double: the k nearest (all samples when fewer), with the
 * samples at the k-th distance chosen to make the mean as large (hi) or small (lo) as a
 * tie allows. Squared distances in (cm Q8)^2 are exact in double here (< 2^53). */
static void ref_k(uint32_t n, uint32_t k, double qx, double qy, double *lo, double *hi)
{
    static double d2[MAXN], tie[MAXN];
    uint32_t kk = k < n ? k : n;
    for (uint32_t i = 0; i < n; ++i) {
        double dx = g_s[i].x_cm * 256.0 - qx, dy = g_s[i].y_cm * 256.0 - qy;
        d2[i] = dx * dx + dy * dy;
    }
    static double sorted[MAXN];
    memcpy(sorted, d2, n * sizeof d2[0]);
    qsort(sorted, n, sizeof sorted[0], cmp_asc);
    double kth = sorted[kk - 1u];
    double sum = 0;
    uint32_t taken = 0, nt = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (d2[i] < kth) {
            sum += g_s[i].v_q6;
            taken++;
        } else if (d2[i] == kth) {
            tie[nt++] = g_s[i].v_q6;
        }
    }
    qsort(tie, nt, sizeof tie[0], cmp_desc);
    double s_hi = sum, s_lo = sum;
    for (uint32_t i = 0; i < kk - taken; ++i) {
        s_hi += tie[i];
        s_lo += tie[nt - 1u - i];
    }
    *hi = s_hi / kk / 64.0;
    *lo = s_lo / kk / 64.0;
}

/* Radius by brute force: the mean of every sample within r8 (cm Q8); false when none. */
static bool ref_radius(uint32_t n, double r8, double qx, double qy, double *mean)
{
    double sum = 0;
    uint32_t c = 0;
    for (uint32_t i = 0; i < n; ++i) {
        double dx = g_s[i].x_cm * 256.0 - qx, dy = g_s[i].y_cm * 256.0 - qy;
        if (dx * dx + dy * dy <= r8 * r8) {
            sum += g_s[i].v_q6;
            c++;
        }
    }
    *mean = c ? sum / c / 64.0 : 0;
    return c > 0;
}

/* A point of [a, b] (Q16): the ends, the middle, or uniform. */
static rfs_q16_t pick(rfs_q16_t a, rfs_q16_t b, uint32_t which, rfs_rng_t *r)
{
    if (which == 0) {
        return a;
    }
    if (which == 1) {
        return b;
    }
    if (which == 2) {
        return (rfs_q16_t)(((int64_t)a + b) / 2);
    }
    return (rfs_q16_t)(a + (int64_t)(urand(r) * ((double)b - a)));
}

/* One random box for a field of w x h metres: sides from a point to 10 m, sometimes off
 * the samples' area. */
static void random_box(double w, double h, rfs_rng_t *r, rfs_q16_t *x0, rfs_q16_t *y0,
                       rfs_q16_t *x1, rfs_q16_t *y1)
{
    static const double sides[] = {0.0, 0.0, 0.25, 0.75, 1.75, 3.75, 10.0};
    double bw = sides[rfs_rng_below(r, 7)], bh = sides[rfs_rng_below(r, 7)];
    double x = -3.0 + urand(r) * (w + 6.0), y = -3.0 + urand(r) * (h + 6.0);
    *x0 = Q(x);
    *y0 = Q(y);
    *x1 = Q(x + bw);
    *y1 = Q(y + bh);
}

/* k-neighbours: the bound is at least the brute-force prediction (most favourable tie)
 * everywhere in the box and at least predict() bit for bit; for a single point with no
 * tie at the k-th distance it is the prediction itself. */
static void kneighbors_bound_holds_in_box(void **state)
{
    (void)state;
    static const uint32_t ns[] = {1, 4, 37, 400, 2500};
    static const uint8_t ks[] = {1, 2, 5, 12, 32};
    rfs_rng_t r;
    rfs_rng_seed(&r, 2024);
    uint32_t exact = 0, checked = 0;
    for (uint32_t t = 0; t < 150; ++t) {
        uint32_t n = ns[t % 5u], kind = (t / 5u) % 4u;
        double w = 6.0 + urand(&r) * 30.0, h = 4.0 + urand(&r) * 12.0;
        make_samples(n, kind, w, h, (t % 3u == 0u) ? 3u : 0u, &r);
        rfs_knn_cfg_t c = rfs_knn_cfg_default();
        c.k = ks[rfs_rng_below(&r, 5)];
        fit(&c, n);
        for (uint32_t b = 0; b < 6; ++b) {
            rfs_q16_t x0, y0, x1, y1, ub;
            random_box(w, h, &r, &x0, &y0, &x1, &y1);

            assert_true(rfs_knn_ops.bound(&g_knn, x0, y0, x1, y1, &ub));

            for (uint32_t q = 0; q < 12; ++q) {
                rfs_q16_t qx = pick(x0, x1, q < 4 ? q : 3, &r);
                rfs_q16_t qy = pick(y0, y1, q < 4 ? (q + 1u) % 4u : 3, &r);
                double lo, hi;
                rfs_q16_t v;
                ref_k(n, c.k, q8(qx), q8(qy), &lo, &hi);
                assert_true(rfs_knn_ops.predict(&g_knn, qx, qy, &v));
                if (ub / 65536.0 < hi - 0.5 / 65536.0 - 1e-9 || ub < v) {
                    fail_msg("k=%u n=%u box [%.4f,%.4f]x[%.4f,%.4f] q (%.4f,%.4f): bound %.6f, "
                             "brute force %.6f, predict %.6f", c.k, n, D(x0), D(x1), D(y0),
                             D(y1), D(qx), D(qy), D(ub), hi, D(v));
                }
                checked++;
                if (x0 == x1 && y0 == y1 && q == 0u && lo == hi) {
                    assert_true(fabs(ub / 65536.0 - hi) <= 0.5 / 65536.0 + 1e-9);
                    exact++;
                }
            }
        }
    }
    assert_true(checked == 150u * 6u * 12u);
    assert_true(exact > 20u); /* point boxes occur (sides 0 twice in seven) */
}

/* Radius: when the bound promises, every query in the box has a sample within the radius
 * (brute force) and a prediction, and the bound is at least both. */
static void radius_bound_holds_in_box(void **state)
{
    (void)state;
    static const uint32_t ns[] = {3, 60, 800, 3000};
    static const double radii[] = {1.0, 1.5, 2.5, 6.0};
    rfs_rng_t r;
    rfs_rng_seed(&r, 77);
    uint32_t promised = 0, refused = 0;
    for (uint32_t t = 0; t < 160; ++t) {
        uint32_t n = ns[t % 4u], kind = (t / 4u) % 4u;
        double w = 5.0 + urand(&r) * 20.0, h = 4.0 + urand(&r) * 8.0;
        make_samples(n, kind, w, h, (t % 3u == 0u) ? 3u : 0u, &r);
        rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
        double rad = radii[rfs_rng_below(&r, 4)];
        c.radius = Q(rad);
        fit(&c, n);
        for (uint32_t b = 0; b < 8; ++b) {
            rfs_q16_t x0, y0, x1, y1, ub;
            random_box(w, h, &r, &x0, &y0, &x1, &y1);

            bool ok = rfs_knn_ops.bound(&g_knn, x0, y0, x1, y1, &ub);

            if (!ok) {
                refused++;
                continue;
            }
            promised++;
            for (uint32_t q = 0; q < 12; ++q) {
                rfs_q16_t qx = pick(x0, x1, q < 4 ? q : 3, &r);
                rfs_q16_t qy = pick(y0, y1, q < 4 ? (q + 1u) % 4u : 3, &r);
                double mean;
                rfs_q16_t v;
                assert_true(ref_radius(n, rad * 25600.0, q8(qx), q8(qy), &mean));
                assert_true(rfs_knn_ops.predict(&g_knn, qx, qy, &v));
                if (ub / 65536.0 < mean - 0.5 / 65536.0 - 1e-9 || ub < v) {
                    fail_msg("r=%.2f n=%u box [%.4f,%.4f]x[%.4f,%.4f]: bound %.6f, brute force "
                             "%.6f, predict %.6f", rad, n, D(x0), D(x1), D(y0), D(y1), D(ub),
                             mean, D(v));
                }
            }
        }
    }
    assert_true(promised > 100u && refused > 100u);
}

/* k-neighbours prediction with ties as rfs_knn.h defines them ("the sample found first"):
 * brute force over every sample of the model's sorted copy, ranked by (distance, ring of
 * its grid cell around the query's cell, position in the copy) - the order the ring
 * search visits them - then the mean rounded half away from zero, as Q16.16. Checks that
 * skipping cells (rfs_knn.c, scan_cell_k) keeps every tie decision, on samples in runs at
 * one position (a 10 Hz pose, 200 packets/s) with whole-dB targets, as the simulator
 * gives. */
static void kneighbors_ties_as_ring_scan(void **state)
{
    (void)state;
    static int64_t key_d2[MAXN];
    static int32_t key_r[MAXN];
    static uint32_t order[MAXN];
    rfs_rng_t r;
    rfs_rng_seed(&r, 99);
    uint32_t checked = 0, tied = 0;
    for (uint32_t t = 0; t < 24; ++t) {
        uint32_t n = 200u + rfs_rng_below(&r, 2800);
        make_samples(n, 1, 30.0, 12.0, 40, &r);
        for (uint32_t i = 0; i < n; ++i) { /* runs of 20 at one position */
            g_s[i].x_cm = g_s[i - i % 20u].x_cm;
            g_s[i].y_cm = g_s[i - i % 20u].y_cm;
        }
        rfs_knn_cfg_t c = rfs_knn_cfg_default();
        c.k = (uint8_t)(1u + rfs_rng_below(&r, 12));
        c.cell = t % 2u ? Q(0.25) : Q(1.0);
        fit(&c, n);
        const rfs_knn_t *s = &g_knn;
        int64_t c8 = (int64_t)s->cell_cm * 256;
        for (uint32_t q = 0; q < 40; ++q) {
            rfs_q16_t qx = Q(-2.0 + 0.25 * rfs_rng_below(&r, 137));
            rfs_q16_t qy = Q(-2.0 + 0.25 * rfs_rng_below(&r, 65));
            double x8 = q8(qx), y8 = q8(qy);
            int64_t cx = (int64_t)floor((x8 - s->min_x_cm * 256.0) / (double)c8);
            int64_t cy = (int64_t)floor((y8 - s->min_y_cm * 256.0) / (double)c8);
            cx = cx < 0 ? 0 : (cx >= s->gw ? s->gw - 1 : cx);
            cy = cy < 0 ? 0 : (cy >= s->gh ? s->gh - 1 : cy);
            for (uint32_t i = 0; i < n; ++i) {
                double dx = s->pts[i].x_cm * 256.0 - x8, dy = s->pts[i].y_cm * 256.0 - y8;
                key_d2[i] = (int64_t)(dx * dx + dy * dy);
                int64_t ci = (s->pts[i].x_cm - s->min_x_cm) / s->cell_cm;
                int64_t cj = (s->pts[i].y_cm - s->min_y_cm) / s->cell_cm;
                key_r[i] = (int32_t)fmax(llabs(ci - cx), llabs(cj - cy));
                order[i] = i;
            }
            /* selection of the k + 1 smallest keys (k <= 12) */
            uint32_t kk = c.k < n ? c.k : n;
            for (uint32_t a = 0; a < kk + 1u && a < n; ++a) {
                for (uint32_t b = a + 1u; b < n; ++b) {
                    uint32_t x = order[a], y = order[b];
                    bool less = key_d2[y] < key_d2[x] ||
                                (key_d2[y] == key_d2[x] &&
                                 (key_r[y] < key_r[x] || (key_r[y] == key_r[x] && y < x)));
                    if (less) {
                        order[a] = y;
                        order[b] = x;
                    }
                }
            }
            int64_t sum = 0;
            for (uint32_t a = 0; a < kk; ++a) {
                sum += s->pts[order[a]].v_q6;
            }
            tied += kk < n && key_d2[order[kk - 1u]] == key_d2[order[kk]];
            double want = (double)sum * 1024.0 / kk;
            want = want < 0 ? -floor(-want + 0.5) : floor(want + 0.5);
            rfs_q16_t v;

            assert_true(rfs_knn_ops.predict(s, qx, qy, &v));

            if ((double)v != want) {
                fail_msg("k=%u n=%u q (%.2f, %.2f): predict %d, ring order %.0f", c.k, n,
                         D(qx), D(qy), v, want);
            }
            checked++;
        }
    }
    assert_true(checked == 24u * 40u && tied > 100u);
}

/* Without a model there is no bound. */
static void bound_refused_without_model(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    rfs_q16_t ub;
    assert_int_equal(rfs_knn_init(&g_knn, &c), 0);

    assert_false(rfs_knn_ops.bound(&g_knn, 0, 0, Q(1), Q(1), &ub));
}

/* Reachability patterns over the lattice: 0 every point, 1 random points (chunks partly
 * reachable), 2 random rectangles, 3 a single point. */
static void set_reach(world_t *t, uint32_t kind, rfs_rng_t *r)
{
    uint32_t lw = t->map.lw, lh = t->map.lh;
    memset(t->mem.reach, 0, t->mem.reach_bytes);
    for (uint32_t j = 0; j < lh; ++j) {
        for (uint32_t i = 0; i < lw; ++i) {
            bool on = kind == 0 || (kind == 1 && rfs_rng_below(r, 10) < 3u);
            if (on) {
                uint32_t idx = j * lw + i;
                t->mem.reach[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
            }
        }
    }
    if (kind == 2) {
        for (int k = 0; k < 3; ++k) {
            uint32_t i0 = rfs_rng_below(r, lw), j0 = rfs_rng_below(r, lh);
            uint32_t i1 = i0 + rfs_rng_below(r, 20), j1 = j0 + rfs_rng_below(r, 20);
            for (uint32_t j = j0; j <= j1 && j < lh; ++j) {
                for (uint32_t i = i0; i <= i1 && i < lw; ++i) {
                    uint32_t idx = j * lw + i;
                    t->mem.reach[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
                }
            }
        }
    }
    if (kind == 3) {
        uint32_t idx = rfs_rng_below(r, lw * lh);
        t->mem.reach[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
    }
}

/* A model with holes: the kNN / radius model with a prediction removed at chosen lattice
 * points (as radius loses it where no sample lies within the radius), and a bound that
 * refuses any box holding a hole (it could not promise a prediction there). Lets the
 * search meet holes where the model itself would predict, in both modes. */
typedef struct holey {
    const rfs_knn_t *knn;
    const uint8_t *holes; /* one bit per lattice point, row-major; set = no prediction */
    uint16_t lw, lh;
    rfs_q16_t x0, y0, grid; /* lattice point (0, 0) and spacing, metres Q16.16 */
} holey_t;

static holey_t g_holey;
static uint8_t g_holes[(MAXN * 64u) / 8u];

static bool holey_at(const holey_t *h, rfs_q16_t x, rfs_q16_t y)
{
    int64_t i = ((int64_t)x - h->x0) / h->grid, j = ((int64_t)y - h->y0) / h->grid;
    assert_true(i >= 0 && j >= 0 && i < h->lw && j < h->lh);
    assert_true(h->x0 + i * h->grid == x && h->y0 + j * h->grid == y); /* a lattice point */
    uint32_t idx = (uint32_t)(j * h->lw + i);
    return (h->holes[idx >> 3] >> (idx & 7u)) & 1u;
}

static bool holey_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const holey_t *h = self;
    return !holey_at(h, x, y) && rfs_knn_ops.predict(h->knn, x, y, value);
}

static bool holey_bound(const void *self, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                        rfs_q16_t y1, rfs_q16_t *ub)
{
    const holey_t *h = self;
    for (rfs_q16_t y = y0; y <= y1; y += h->grid) {
        for (rfs_q16_t x = x0; x <= x1; x += h->grid) {
            if (holey_at(h, x, y)) {
                return false;
            }
        }
    }
    return rfs_knn_ops.bound(h->knn, x0, y0, x1, y1, ub);
}

static const rfs_model_ops_t holey_ops = {
    .name = "holey",
    .predict = holey_predict,
    .bound = holey_bound,
};

/* Random holes: each lattice point with probability pct %. */
static void make_holes(const world_t *t, uint32_t pct, rfs_rng_t *r)
{
    uint32_t n = (uint32_t)t->map.lw * t->map.lh;
    assert_true(n <= sizeof g_holes * 8u);
    memset(g_holes, 0, sizeof g_holes);
    for (uint32_t idx = 0; idx < n; ++idx) {
        if (rfs_rng_below(r, 100) < pct) {
            g_holes[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
        }
    }
    rfs_q16_t x1, y1;
    g_holey = (holey_t){.knn = &g_knn, .holes = g_holes, .lw = t->map.lw, .lh = t->map.lh,
                        .grid = t->map.cfg.grid};
    rfs_map_lattice_point(&t->map, 0, 0, &g_holey.x0, &g_holey.y0);
    rfs_map_lattice_point(&t->map, (uint16_t)(t->map.lw - 1u), (uint16_t)(t->map.lh - 1u), &x1,
                          &y1);
    assert_true(x1 == g_holey.x0 + (t->map.lw - 1) * g_holey.grid);
    assert_true(y1 == g_holey.y0 + (t->map.lh - 1) * g_holey.grid);
}

static bool hole_bit(uint32_t idx)
{
    return (g_holes[idx >> 3] >> (idx & 7u)) & 1u;
}

static bool reach_at(const world_t *t, uint32_t idx)
{
    return (t->mem.reach[idx >> 3] >> (idx & 7u)) & 1u;
}

/* How many samples lie within r8 (cm Q8) of the query, by brute force. */
static double ref_radius_count(uint32_t n, double r8, double qx, double qy)
{
    double c = 0;
    for (uint32_t i = 0; i < n; ++i) {
        double dx = g_s[i].x_cm * 256.0 - qx, dy = g_s[i].y_cm * 256.0 - qy;
        c += dx * dx + dy * dy <= r8 * r8;
    }
    return c;
}

/* The brute-force maximum over reachable lattice points with a prediction (not a hole;
 * radius: a sample within the radius): k-neighbours, the largest "lo" (a value the model
 * must reach there whatever its tie choice) and the largest "hi"; radius, the exact
 * Q16.16 value (the mean rounded half away from zero, rfs_knn.h) and the first point in
 * row-major order that has it. false when no reachable point has a prediction. */
static bool ref_grid_max(const world_t *t, const rfs_knn_cfg_t *c, uint32_t n, bool holes,
                         double *lo_max, double *hi_max, rfs_q16_t *rx, rfs_q16_t *ry)
{
    bool any = false;
    *lo_max = -INFINITY;
    *hi_max = -INFINITY;
    for (uint16_t j = 0; j < t->map.lh; ++j) {
        for (uint16_t i = 0; i < t->map.lw; ++i) {
            uint32_t idx = (uint32_t)j * t->map.lw + i;
            if (!reach_at(t, idx) || (holes && hole_bit(idx))) {
                continue;
            }
            rfs_q16_t x, y;
            rfs_map_lattice_point(&t->map, i, j, &x, &y);
            double lo, hi;
            if (c->mode == RFS_KNN_RADIUS) {
                double mean, count;
                if (!ref_radius(n, D(c->radius) * 25600.0, q8(x), q8(y), &mean)) {
                    continue;
                }
                count = ref_radius_count(n, D(c->radius) * 25600.0, q8(x), q8(y));
                double v = round(mean * count * 64.0) * 1024.0 / count; /* sum: integer */
                lo = hi = (v < 0 ? -floor(-v + 0.5) : floor(v + 0.5)) / 65536.0;
            } else {
                ref_k(n, c->k, q8(x), q8(y), &lo, &hi);
            }
            if (!any || hi > *hi_max) {
                *rx = x;
                *ry = y;
            }
            *lo_max = fmax(*lo_max, lo);
            *hi_max = fmax(*hi_max, hi);
            any = true;
        }
    }
    return any;
}

/* The pruned search finds exactly the full scan's point (or fails exactly when it does),
 * over maps whose lattice is and is not a multiple of the tile, sample sets with and
 * without many equal predictions, every reachability pattern, both modes and random holes
 * (none, 3 %, 40 %); both are checked against the brute force: radius exactly (the first
 * point of greatest prediction, skipping points without one), k-neighbours within the
 * range a tie allows. */
static void pruned_search_equals_full_scan(void **state)
{
    (void)state;
    static const double sizes[][2] = {{12.0, 8.0}, {9.3, 7.1}, {20.0, 5.0}};
    static const uint32_t hole_pct[] = {0, 3, 40};
    rfs_rng_t r;
    rfs_rng_seed(&r, 4242);
    uint32_t found = 0, failed = 0, radius_found = 0, holes_found = 0, brute = 0;
    for (uint32_t m = 0; m < 3; ++m) {
        world_t t;
        world_make(&t, sizes[m][0], sizes[m][1], m == 0 ? 6.0 : 0.0, 6.0);
        seek_make(&t, rfs_seek_cfg_default(), 5);
        for (uint32_t trial = 0; trial < 90; ++trial) {
            bool radius = trial % 3u == 2u;
            uint32_t pct = hole_pct[(trial / 4u) % 3u];
            uint32_t n = radius ? (trial % 2u ? 2500u : 300u) : 20u + rfs_rng_below(&r, 1500);
            if (radius && trial % 8u == 2u) {
                n = 5u + rfs_rng_below(&r, 40); /* sparse: most points without a sample */
            }
            make_samples(n, trial % 4u, sizes[m][0], sizes[m][1], trial % 2u ? 2u : 0u, &r);
            rfs_knn_cfg_t c = radius ? rfs_knn_cfg_radius_default() : rfs_knn_cfg_default();
            c.k = (uint8_t)(1u + rfs_rng_below(&r, 12));
            c.radius = trial % 4u == 2u ? Q(2.5) : Q(1.0);
            fit(&c, n);
            make_holes(&t, pct, &r);
            t.seek.model = pct ? (rfs_model_t){.ops = &holey_ops, .self = &g_holey}
                               : rfs_knn_model(&g_knn);
            set_reach(&t, trial % 4u, &r);
            bool check = radius || (trial % 5u == 0u && n <= 600u);
            double lo_max = 0, hi_max = 0;
            rfs_q16_t ax = 0, ay = 0, bx = 0, by = 0, rx = 0, ry = 0;
            bool want = check && ref_grid_max(&t, &c, n, pct > 0u, &lo_max, &hi_max, &rx, &ry);

            bool a = rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &ax, &ay);
            bool b = rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &bx, &by);

            assert_int_equal(a, b);
            if (check) {
                assert_int_equal(a, want);
            }
            if (!a) {
                failed++;
                continue;
            }
            found++;
            radius_found += radius;
            holes_found += pct > 0u;
            if (ax != bx || ay != by) {
                fail_msg("map %u trial %u: pruned (%.3f, %.3f), full scan (%.3f, %.3f)", m,
                         trial, D(ax), D(ay), D(bx), D(by));
            }
            if (!check) {
                continue;
            }
            rfs_q16_t v;
            assert_true(t.seek.model.ops->predict(t.seek.model.self, ax, ay, &v));
            if (radius && (ax != rx || ay != ry || D(v) != hi_max)) {
                fail_msg("map %u trial %u: search (%.3f, %.3f) = %.6f, brute force (%.3f, "
                         "%.3f) = %.6f", m, trial, D(ax), D(ay), D(v), D(rx), D(ry), hi_max);
            }
            assert_true(v / 65536.0 >= lo_max - 0.5 / 65536.0 - 1e-9);
            assert_true(v / 65536.0 <= hi_max + 0.5 / 65536.0 + 1e-9);
            brute++;
        }
        world_free(&t);
    }
    assert_true(found > 150u && failed > 5u && radius_found > 40u && holes_found > 80u &&
                brute > 60u);
}

/* Radius samples along a short robot walk in one corner of an open map: most reachable
 * points have no sample within 1 m, yet the search yields the brute-force maximum (the
 * greedy step of the paper, section 2, over the points the model predicts at). */
static void radius_with_holes_still_has_maximum(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 12.0, 8.0, 0.0, 0.0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    rfs_rng_t r;
    rfs_rng_seed(&r, 8);
    make_samples(400, 1, 3.0, 2.0, 0, &r); /* a walk over [0, 3] x [0, 2] m */
    rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
    fit(&c, 400);
    t.seek.model = rfs_knn_model(&g_knn);
    set_reach(&t, 0, &r);
    uint32_t holes = 0, points = (uint32_t)t.map.lw * t.map.lh;
    for (uint16_t j = 0; j < t.map.lh; ++j) {
        for (uint16_t i = 0; i < t.map.lw; ++i) {
            rfs_q16_t x, y;
            double mean;
            rfs_map_lattice_point(&t.map, i, j, &x, &y);
            holes += !ref_radius(400, 25600.0, q8(x), q8(y), &mean);
        }
    }
    assert_true(holes > points / 2u); /* every chunk of the lattice's upper rows is empty */
    double lo_max, hi_max;
    rfs_q16_t rx = 0, ry = 0, ax = 0, ay = 0, bx = 0, by = 0;
    assert_true(ref_grid_max(&t, &c, 400, false, &lo_max, &hi_max, &rx, &ry));

    bool a = rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &ax, &ay);
    bool b = rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &bx, &by);

    assert_true(a);
    assert_true(b);
    assert_int_equal(ax, rx);
    assert_int_equal(ay, ry);
    assert_int_equal(bx, rx);
    assert_int_equal(by, ry);
    world_free(&t);
}

/* Without a model both searches fail (also through predict_row: the unfitted ridge); with
 * holes at every reachable point too; one point with a prediction is the answer. */
static void pruned_search_fails_without_model(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 6.0, 4.0, 0.0, 0.0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    rfs_rng_t r;
    rfs_rng_seed(&r, 1);
    set_reach(&t, 0, &r);
    rfs_q16_t x, y;
    assert_true(t.seek.model.ops->predict_row != 0);
    assert_false(rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    assert_int_equal(rfs_knn_init(&g_knn, &c), 0);
    t.seek.model = rfs_knn_model(&g_knn);

    bool a = rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &x, &y);

    assert_false(a);
    assert_false(rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));

    make_samples(50, 0, 6.0, 4.0, 0, &r);
    fit(&c, 50);
    make_holes(&t, 100, &r);
    t.seek.model = (rfs_model_t){.ops = &holey_ops, .self = &g_holey};
    assert_false(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));
    assert_false(rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));
    g_holes[0] &= (uint8_t)~1u; /* lattice point (0, 0) has a prediction again */
    assert_true(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));
    assert_int_equal(x, g_holey.x0);
    assert_int_equal(y, g_holey.y0);
    assert_true(rfs_gridmax_scan(t.seek.map, &t.seek.model, t.seek.reach, &x, &y));
    assert_int_equal(x, g_holey.x0);
    assert_int_equal(y, g_holey.y0);
    world_free(&t);
}

/* A plane c + gx x + gy y rounded to Q16 (monotone along rows), for the row shortcut. */
typedef struct plane_model {
    double c, gx, gy;
} plane_model_t;

static bool pm_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    const plane_model_t *m = self;
    *v = Q(m->c + m->gx * D(x) + m->gy * D(y));
    return true;
}

static int pm_monotone(const void *self)
{
    const plane_model_t *m = self;
    return m->gx > 0 ? 1 : (m->gx < 0 ? -1 : 0);
}

static const rfs_model_ops_t pm_ops = {
    .name = "plane", .predict = pm_predict, .row_monotone = pm_monotone,
};

static const rfs_model_ops_t pm_scan_ops = {
    .name = "plane-scan", .predict = pm_predict,
};

/* The row shortcut finds exactly the maximum the full scan finds, ties included (slopes
 * so small that whole rows round to one value), on a map with a wall; and the scan's
 * answer is the brute-force maximum computed in double here. */
static void test_grid_max_row_shortcut(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 12, 8, 6.0, 6.0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    rfs_seek_out_t out;
    feed(&t, 100000, 3.0, 3.0, 0, -50, &out); /* first step computes reachability */
    rfs_rng_t r;
    rfs_rng_seed(&r, 99);
    for (int k = 0; k < 300; ++k) {
        plane_model_t pm;
        double scale = k % 3 == 0 ? 1e-7 : (k % 3 == 1 ? 1e-3 : 3.0);
        pm.c = -60;
        pm.gx = ((double)rfs_rng_u32(&r) / 4294967296.0 - 0.5) * scale;
        pm.gy = ((double)rfs_rng_u32(&r) / 4294967296.0 - 0.5) * scale;
        if (k % 10 == 0) {
            pm.gx = 0;
        }
        t.seek.model.self = &pm;
        rfs_q16_t ax, ay, bx, by;
        t.seek.model.ops = &pm_ops;
        assert_true(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &ax, &ay));
        t.seek.model.ops = &pm_scan_ops;
        assert_true(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &bx, &by));
        assert_int_equal(ax, bx);
        assert_int_equal(ay, by);
        /* Brute force in double over reachable lattice points: the value at the found
         * point is the maximum (up to the Q16 rounding of the model). */
        double best = -1e300;
        for (uint16_t j = 0; j < t.map.lh; ++j) {
            for (uint16_t i = 0; i < t.map.lw; ++i) {
                uint32_t idx = (uint32_t)j * t.map.lw + i;
                if (!((t.mem.reach[idx >> 3] >> (idx & 7)) & 1)) {
                    continue;
                }
                double x = (i + 0.5) * 0.25, y = (j + 0.5) * 0.25;
                best = fmax(best, pm.c + pm.gx * x + pm.gy * y);
            }
        }
        assert_true(pm.c + pm.gx * D(ax) + pm.gy * D(ay) >= best - 2.0 / 65536);
    }
    world_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(kneighbors_bound_holds_in_box),
        cmocka_unit_test(radius_bound_holds_in_box),
        cmocka_unit_test(bound_refused_without_model),
        cmocka_unit_test(kneighbors_ties_as_ring_scan),
        cmocka_unit_test(pruned_search_equals_full_scan),
        cmocka_unit_test(radius_with_holes_still_has_maximum),
        cmocka_unit_test(pruned_search_fails_without_model),
        cmocka_unit_test(test_grid_max_row_shortcut),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
