/* test_radio.c - the radio model's statistics, measured from samples, against the
 * configured values (hs_radio.h). Every reference is computed here in double precision
 * from the model's definition (least squares, the logistic curve, the exponential and
 * non-central chi-square distributions, Bessel J0), never taken from hs_radio itself.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hs_radio.h"

/// Everything off: each test switches on the part it measures.
static hs_radio_cfg_t cfg_none(void)
{
    hs_radio_cfg_t c = hs_radio_cfg_default();
    c.pathloss = c.walls = c.shadowing = c.fading = c.noise = false;
    c.quantise = c.clip = c.loss = false;
    return c;
}

static hs_radio_t *make(const hs_radio_cfg_t *c, double w, double h, uint64_t seed)
{
    hs_radio_src_t src = {0.0, 0.0, 20.0};
    char err[256];
    hs_radio_t *r = hs_radio_create(c, &src, 1, -w / 2, -h / 2, w / 2, h / 2, seed, NULL, NULL,
                                    err, sizeof err);
    assert_non_null(r);
    return r;
}

/// Path loss slope and intercept by least squares on noisy whole-dBm packets.
static void test_pathloss_slope(void **state)
{
    (void)state;
    // Fixture: path loss + 4 dB noise + quantisation, log-uniform distances 1..40 m.
    hs_radio_cfg_t c = cfg_none();
    c.pathloss = true;
    c.noise = true;
    c.quantise = true;
    hs_radio_t *r = make(&c, 100, 100, 7);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 11);
    // Act
    double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
    for (int i = 0; i < 40000; i++) {
        double d = pow(10.0, hs_radio_uniform(&rng) * log10(40.0));
        double a = 2.0 * M_PI * hs_radio_uniform(&rng);
        int dbm;
        assert_true(hs_radio_packet(r, 0, d * cos(a), d * sin(a), &rng, &dbm));
        double x = 10.0 * log10(d);
        sx += x; sy += dbm; sxx += x * x; sxy += x * dbm; n++;
    }
    double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    double icpt = (sy - slope * sx) / n;
    // Assert: slope -n = -3.0; intercept P_tx - L0 = 20 - (20 log10 2400 - 28) = -19.6 dBm.
    assert_true(fabs(slope - (-3.0)) < 0.03);
    assert_true(fabs(icpt - (20.0 - (20.0 * log10(2400.0) - 28.0))) < 0.3);
    hs_radio_destroy(r);
}

/// Shadowing: standard deviation and Gudmundson decorrelation distance of the field.
static void test_shadowing_sigma_and_correlation(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.shadowing = true;
    const double L = 160.0, step = 0.5;
    const int n = (int)(L / step);
    const int maxlag = 24; // 12 m
    double s1 = 0, s2 = 0, cnt = 0;
    double lag_xy[25] = {0}, lag_n[25] = {0};
    float *f = malloc(sizeof(float) * n * n);
    assert_non_null(f);
    for (uint64_t seed = 1; seed <= 8; seed++) {
        hs_radio_t *r = make(&c, L + 2, L + 2, seed);
        for (int j = 0; j < n; j++) {
            for (int i = 0; i < n; i++) {
                f[j * n + i] = (float)hs_radio_shadow_db(r, 0, -L / 2 + i * step, -L / 2 + j * step);
            }
        }
        hs_radio_destroy(r);
        double m = 0;
        for (int k = 0; k < n * n; k++) {
            m += f[k];
        }
        m /= (double)n * n;
        for (int k = 0; k < n * n; k++) {
            s1 += f[k] - m;
            s2 += (f[k] - m) * (f[k] - m);
            cnt++;
        }
        // Covariance at lags along x and y, pooled.
        for (int j = 0; j < n; j += 3) {
            for (int i = 0; i + maxlag < n; i += 3) {
                double a = f[j * n + i] - m;
                for (int l = 0; l <= maxlag; l++) {
                    lag_xy[l] += a * (f[j * n + i + l] - m);
                    lag_n[l]++;
                }
            }
        }
        for (int j = 0; j + maxlag < n; j += 3) {
            for (int i = 0; i < n; i += 3) {
                double a = f[j * n + i] - m;
                for (int l = 0; l <= maxlag; l++) {
                    lag_xy[l] += a * (f[(j + l) * n + i] - m);
                    lag_n[l]++;
                }
            }
        }
    }
    free(f);
    double sigma = sqrt(s2 / cnt - (s1 / cnt) * (s1 / cnt));
    // Decorrelation distance: least squares of -ln rho(r) = r / d_c through the origin,
    // lags 1..8 m (rho from the pooled covariances).
    double c0 = lag_xy[0] / lag_n[0], num = 0, den = 0;
    for (int l = 2; l <= 16; l++) {
        double rho = (lag_xy[l] / lag_n[l]) / c0;
        double rr = l * step;
        assert_true(rho > 0.0);
        num += rr * -log(rho);
        den += rr * rr;
    }
    double dcorr = den / num;
    // Assert: sigma 4 dB, d_c 5 m (the field's expectation; sampling error a few %).
    assert_true(fabs(sigma - 4.0) < 0.4);
    assert_true(fabs(dcorr - 5.0) < 0.75);
}

/// Shadowing grid points are summed, and their columns and rows tabulated, on first
/// read: two radios of one seed read in opposite orders (one from the far corner back,
/// one point by point forward) agree bit for bit everywhere, so a value does not depend
/// on what was read before.
static void test_shadowing_lazy_order_free(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.shadowing = true;
    hs_radio_t *a = make(&c, 30, 20, 7), *b = make(&c, 30, 20, 7);
    const int n = 61, m = 41; // 0.5 m grid points over the 30 x 20 m area
    for (int k = n * m - 1; k >= 0; k--) {
        (void)hs_radio_shadow_db(a, 0, -15.0 + 0.5 * (k % n), -10.0 + 0.5 * (k / n));
    }
    int nonzero = 0;
    for (int k = 0; k < n * m; k++) {
        double x = -15.0 + 0.5 * (k % n) + 0.13, y = -10.0 + 0.5 * (k / n) + 0.31;
        double va = hs_radio_shadow_db(a, 0, x, y), vb = hs_radio_shadow_db(b, 0, x, y);
        assert_memory_equal(&va, &vb, sizeof va);
        nonzero += va != 0.0;
    }
    assert_true(nonzero > n * m / 2);
    hs_radio_destroy(a);
    hs_radio_destroy(b);
}

/// The shadowing field is fixed per seed (returning gives the same value) and differs
/// between seeds.
static void test_fields_fixed_per_seed(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.shadowing = c.fading = true;
    hs_radio_t *a = make(&c, 50, 50, 3), *b = make(&c, 50, 50, 3), *d = make(&c, 50, 50, 4);
    int differ = 0;
    for (int i = 0; i < 100; i++) {
        double x = -20 + 0.37 * i, y = 10 - 0.21 * i;
        assert_true(hs_radio_shadow_db(a, 0, x, y) == hs_radio_shadow_db(b, 0, x, y));
        assert_true(hs_radio_fading_db(a, 0, x, y, false) == hs_radio_fading_db(b, 0, x, y, false));
        assert_true(hs_radio_shadow_db(a, 0, x, y) == hs_radio_shadow_db(a, 0, x, y));
        differ += hs_radio_shadow_db(a, 0, x, y) != hs_radio_shadow_db(d, 0, x, y);
    }
    assert_true(differ > 90);
    hs_radio_destroy(a);
    hs_radio_destroy(b);
    hs_radio_destroy(d);
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/// CDF of the power |a e^{j phi} + b z|^2, z unit complex Gaussian: P * 2 / b^2 is
/// non-central chi-square with 2 degrees of freedom and lambda = 2 a^2 / b^2 (Poisson
/// mixture of central chi-square CDFs with even degrees of freedom).
static double rician_power_cdf(double p, double k)
{
    double a2 = k / (k + 1.0), b2 = 1.0 / (k + 1.0);
    double x = 2.0 * p / b2, lam = 2.0 * a2 / b2;
    double sum = 0.0, pois = exp(-lam / 2.0);
    for (int j = 0; j < 200; j++) {
        // P(chi2_{2+2j} <= x) = 1 - e^{-x/2} sum_{i<=j} (x/2)^i / i!
        double term = 1.0, tail = 1.0;
        for (int i = 1; i <= j; i++) {
            term *= (x / 2.0) / i;
            tail += term;
        }
        sum += pois * (1.0 - exp(-x / 2.0) * tail);
        pois *= (lam / 2.0) / (j + 1);
    }
    return sum;
}

/// Kolmogorov-Smirnov distance of the fading power samples from a CDF.
static double ks(double *p, int n, double (*cdf)(double, double), double k)
{
    qsort(p, (size_t)n, sizeof *p, cmp_d);
    double d = 0.0;
    for (int i = 0; i < n; i++) {
        double f = cdf(p[i], k);
        d = fmax(d, fmax(fabs(f - (double)i / n), fabs(f - (double)(i + 1) / n)));
    }
    return d;
}

static double exp_cdf(double p, double unused)
{
    (void)unused;
    return 1.0 - exp(-p);
}

/// Rayleigh behind walls: power exponential with mean 1; Rician in line of sight.
static void test_fading_distribution(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.fading = true;
    enum { N = 4000 };
    static double p[N];
    // NLOS: positions on a 0.7 m lattice (well beyond the coherence distance), 4 seeds.
    int n = 0;
    double mean = 0;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        hs_radio_t *r = make(&c, 100, 100, seed);
        for (int i = 0; i < N / 4; i++) {
            double x = -20 + 0.7 * (i % 40), y = -20 + 0.7 * (i / 40);
            p[n] = pow(10.0, hs_radio_fading_db(r, 0, x, y, false) / 10.0);
            mean += p[n++];
        }
        hs_radio_destroy(r);
    }
    mean /= N;
    assert_true(fabs(mean - 1.0) < 0.06);
    // KS critical value at alpha = 0.01 is 1.63 / sqrt(N) = 0.026.
    assert_true(ks(p, N, exp_cdf, 0) < 0.026);

    // LOS: Rician with K = 6 dB.
    n = 0;
    mean = 0;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        hs_radio_t *r = make(&c, 100, 100, seed + 10);
        for (int i = 0; i < N / 4; i++) {
            double x = -20 + 0.7 * (i % 40), y = -20 + 0.7 * (i / 40);
            p[n] = pow(10.0, hs_radio_fading_db(r, 0, x, y, true) / 10.0);
            mean += p[n++];
        }
        hs_radio_destroy(r);
    }
    mean /= N;
    assert_true(fabs(mean - 1.0) < 0.04);
    assert_true(ks(p, N, rician_power_cdf, pow(10.0, 0.6)) < 0.026);
    // And it is not Rayleigh: the exponential CDF is far off.
    assert_true(ks(p, N, exp_cdf, 0) > 0.1);
}

/// The fading field varies on the wavelength scale: power correlation J0^2(k r) (Clarke's
/// isotropic scattering), near 0.88 at 1 cm and near 0 at 0.383 lambda (4.8 cm).
static void test_fading_spatial_scale(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.fading = true;
    const double lags[2] = {0.01, 0.383 * 0.125};
    for (int li = 0; li < 2; li++) {
        double s0 = 0, s1 = 0, s00 = 0, s11 = 0, s01 = 0, n = 0;
        for (uint64_t seed = 1; seed <= 8; seed++) {
            hs_radio_t *r = make(&c, 100, 100, seed);
            for (int i = 0; i < 1000; i++) {
                double x = -20 + 0.7 * (i % 40), y = -20 + 0.7 * (i / 40);
                double dir = 2.0 * M_PI * (i * 0.618034 - floor(i * 0.618034));
                double a = pow(10.0, hs_radio_fading_db(r, 0, x, y, false) / 10.0);
                double b = pow(10.0, hs_radio_fading_db(r, 0, x + lags[li] * cos(dir),
                                                        y + lags[li] * sin(dir), false) / 10.0);
                s0 += a; s1 += b; s00 += a * a; s11 += b * b; s01 += a * b; n++;
            }
            hs_radio_destroy(r);
        }
        double cov = s01 / n - (s0 / n) * (s1 / n);
        double rho = cov / sqrt((s00 / n - (s0 / n) * (s0 / n)) * (s11 / n - (s1 / n) * (s1 / n)));
        double k = 2.0 * M_PI / 0.125;
        double ref = j0(k * lags[li]) * j0(k * lags[li]);
        assert_true(fabs(rho - ref) < 0.06);
    }
}

/// Packet delivery along the logistic loss curve, 50 % at the sensitivity.
static void test_loss_curve(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.pathloss = true;
    c.loss = true;
    hs_radio_t *r = make(&c, 400, 400, 1);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 5);
    for (double p_target = -100.0; p_target <= -88.0; p_target += 1.5) {
        // Distance with this mean signal: 20 - (39.59 + 30 log10 d) = p_target.
        double l0 = 20.0 * log10(2400.0) - 28.0;
        double d = pow(10.0, (20.0 - l0 - p_target) / 30.0);
        int got = 0, n = 20000;
        for (int i = 0; i < n; i++) {
            int dbm;
            got += hs_radio_packet(r, 0, d, 0.0, &rng, &dbm);
        }
        double pdr = 1.0 / (1.0 + exp(-(p_target - (-95.0)) / 1.5));
        double sd = sqrt(pdr * (1.0 - pdr) / n);
        assert_true(fabs((double)got / n - pdr) < 4.0 * sd + 1e-3);
    }
    hs_radio_destroy(r);
}

/// Whole dBm, clipped to the receiver's range.
static void test_quantise_and_clip(void **state)
{
    (void)state;
    hs_radio_cfg_t c = cfg_none();
    c.pathloss = c.noise = c.quantise = c.clip = true;
    hs_radio_t *r = make(&c, 100, 100, 1);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 9);
    int at_max = 0, at_min = 0, n = 4000;
    // Near: 0.05 m (held at the 1 m reference); far: 800 m.
    double l0 = 20.0 * log10(2400.0) - 28.0;
    double m_near = 20.0 - l0, m_far = 20.0 - l0 - 30.0 * log10(800.0);
    for (int i = 0; i < n; i++) {
        int dbm;
        hs_radio_packet(r, 0, 0.05, 0.0, &rng, &dbm);
        assert_true(dbm <= -10);
        at_max += dbm == -10;
        hs_radio_packet(r, 0, 800.0, 0.0, &rng, &dbm);
        assert_true(dbm >= -100);
        at_min += dbm == -100;
    }
    // Reported -10 when the noisy value is above -10.5 (rounding), -100 when below -99.5.
    double p_max = 0.5 * erfc((-10.5 - m_near) / (4.0 * sqrt(2.0)));
    double p_min = 1.0 - 0.5 * erfc((-99.5 - m_far) / (4.0 * sqrt(2.0)));
    assert_true(fabs((double)at_max / n - p_max) < 4.0 * sqrt(p_max * (1 - p_max) / n));
    assert_true(fabs((double)at_min / n - p_min) < 4.0 * sqrt(p_min * (1 - p_min) / n));
    hs_radio_destroy(r);
}

static void test_bad_config(void **state)
{
    (void)state;
    char err[256];
    hs_radio_cfg_t c = hs_radio_cfg_default();
    assert_int_equal(hs_radio_cfg_check(&c, err, sizeof err), 0);
    c.shadow_dcorr_m = 0.0;
    assert_int_equal(hs_radio_cfg_check(&c, err, sizeof err), -1);
    assert_non_null(strstr(err, "dcorr"));
    c = hs_radio_cfg_default();
    c.rx_min_dbm = -10;
    c.rx_max_dbm = -20;
    assert_int_equal(hs_radio_cfg_check(&c, err, sizeof err), -1);
    hs_radio_src_t s = {0, 0, 0};
    c = hs_radio_cfg_default();
    assert_null(hs_radio_create(&c, &s, 0, 0, 0, 1, 1, 1, NULL, NULL, err, sizeof err));
    assert_null(hs_radio_create(&c, &s, 1, 0, 0, 0, 1, 1, NULL, NULL, err, sizeof err));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pathloss_slope),
        cmocka_unit_test(test_shadowing_sigma_and_correlation),
        cmocka_unit_test(test_fields_fixed_per_seed),
        cmocka_unit_test(test_shadowing_lazy_order_free),
        cmocka_unit_test(test_fading_distribution),
        cmocka_unit_test(test_fading_spatial_scale),
        cmocka_unit_test(test_loss_curve),
        cmocka_unit_test(test_quantise_and_clip),
        cmocka_unit_test(test_bad_config),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
