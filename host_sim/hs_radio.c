/* hs_radio.c - indoor radio model (see hs_radio.h and docs/RADIO_MODEL.md). */
#include "hs_radio.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/// Sine table size for the per-packet fading sum: phase error <= pi / 4096 rad.
#define SIN_N 4096u
#define SIN_MASK (SIN_N - 1u)

typedef struct fading_wave {
    double kx;  ///< x wavenumber in table steps per metre
    double ky;  ///< y wavenumber in table steps per metre
    double ph;  ///< phase in table steps
} fading_wave_t;

typedef struct radio_src {
    hs_radio_src_t s;
    float *shadow;         ///< gw * gh values, dB; NaN until first read (shadow_at)
    double *shadow_x;      ///< per grid column, every wave's cos and sin of kx x + phase
    double *shadow_y;      ///< per grid row, every wave's cos and sin of ky y
    double *shadow_k;      ///< per wave kx, ky, phase (rad/m, rad/m, rad)
    uint8_t *shadow_xy;    ///< per column, then per row: 1 once its cos and sin are tabulated
    fading_wave_t *waves;  ///< fading_waves plane waves
    int8_t *walls;         ///< cw * ch cached wall counts, -1 = not yet known
    bool walls_owned;      ///< walls was allocated here (not lent by the caller)
    int64_t memo_qx;       ///< receiver position of the memoised signal, memo_m units
    int64_t memo_qy;
    double memo_dbm;       ///< signal (before noise) there
    double memo_mean_dbm;  ///< local mean (no fading) there
    bool memo_valid;       ///< memo holds a value
} radio_src_t;

struct hs_radio {
    hs_radio_cfg_t cfg;
    unsigned nsrc;
    radio_src_t src[HS_RADIO_MAX_SOURCES];
    double x0, y0;            ///< lower-left of the area, metres
    uint32_t gw, gh;          ///< shadow grid points
    uint32_t cw, ch;          ///< wall cache cells
    double k_steps;           ///< wavenumber 2 pi / lambda in table steps per metre
    double sin_tab[SIN_N];    ///< sin(2 pi i / SIN_N) rounded to float precision, stored as
                              ///< double (no conversion per wave)
    hs_radio_walls_fn walls_fn;
    void *walls_ctx;
    double los_a, los_b;      ///< Rician amplitudes sqrt(K/(K+1)), sqrt(1/(K+1))
    double scat;              ///< 1 / sqrt(fading_waves)
    double spare;             ///< second normal variate of the last Box-Muller pair
    bool has_spare;           ///< spare is valid
};

hs_radio_cfg_t hs_radio_cfg_default(void)
{
    hs_radio_cfg_t c;
    memset(&c, 0, sizeof c);
    c.pathloss = true;
    c.exponent = 3.0;                          // ITU-R P.1238-12 table 2, office, 2.4 GHz: N = 30
    c.ref_dist_m = 1.0;                        // P.1238's reference distance
    c.ref_loss_db = 20.0 * log10(2400.0) - 28.0; // P.1238 eq. (1) at d = 1 m: 39.6 dB
    c.walls = true;
    c.wall_db = 5.0;                           // ns-3 buildings model, internal wall loss
    c.shadowing = true;
    c.shadow_sigma_db = 4.0;                   // indoor 3-6 dB
    c.shadow_dcorr_m = 5.0;                    // Gudmundson 1991 form, indoor scale
    c.shadow_grid_m = 0.5;                     // d_c / 10: bilinear error small at lags >= 0.5 m
    c.shadow_waves = 256;
    c.fading = true;
    c.wavelength_m = 0.125;                    // 2.4 GHz: c / f = 0.1249 m
    c.rician_k_db = 6.0;
    c.fading_waves = 32;
    c.noise = true;
    c.noise_sigma_db = 4.0;                    // paper section 5: measured 4 dB
    c.quantise = true;
    c.clip = true;
    c.rx_min_dbm = -100.0;
    c.rx_max_dbm = -10.0;
    c.loss = true;
    c.sensitivity_dbm = -95.0;
    c.loss_width_db = 1.5;
    c.wall_cache_m = 0.1;
    return c;
}

int hs_radio_cfg_check(const hs_radio_cfg_t *c, char *err, size_t errlen)
{
#define BAD(field, why) do { snprintf(err, errlen, "%s: %s", field, why); return -1; } while (0)
    if (!(c->exponent >= 0.0 && c->exponent <= 10.0)) BAD("radio.pathloss.exponent", "must be in [0, 10]");
    if (!(c->ref_dist_m > 0.0 && c->ref_dist_m <= 100.0)) BAD("radio.pathloss.ref_dist_m", "must be in (0, 100]");
    if (!isfinite(c->ref_loss_db)) BAD("radio.pathloss.ref_loss_db", "must be a number");
    if (!(c->wall_db >= 0.0 && c->wall_db <= 100.0)) BAD("radio.walls.db_per_wall", "must be in [0, 100]");
    if (!(c->shadow_sigma_db >= 0.0 && c->shadow_sigma_db <= 30.0)) BAD("radio.shadowing.sigma_db", "must be in [0, 30]");
    if (!(c->shadow_dcorr_m > 0.0 && c->shadow_dcorr_m <= 1000.0)) BAD("radio.shadowing.dcorr_m", "must be in (0, 1000]");
    if (!(c->shadow_grid_m >= 0.01 && c->shadow_grid_m <= 10.0)) BAD("radio.shadowing.grid_m", "must be in [0.01, 10]");
    if (c->shadow_waves < 1 || c->shadow_waves > 100000) BAD("radio.shadowing.waves", "must be in [1, 100000]");
    if (!(c->wavelength_m >= 0.001 && c->wavelength_m <= 10.0)) BAD("radio.fading.wavelength_m", "must be in [0.001, 10]");
    if (!(c->rician_k_db >= -50.0 && c->rician_k_db <= 50.0)) BAD("radio.fading.rician_k_db", "must be in [-50, 50]");
    if (c->fading_waves < 1 || c->fading_waves > 4096) BAD("radio.fading.waves", "must be in [1, 4096]");
    if (!(c->noise_sigma_db >= 0.0 && c->noise_sigma_db <= 30.0)) BAD("radio.noise.sigma_db", "must be in [0, 30]");
    if (!(c->rx_min_dbm >= -127.0 && c->rx_max_dbm <= 127.0 && c->rx_min_dbm < c->rx_max_dbm))
        BAD("radio.receiver", "need -127 <= min_dbm < max_dbm <= 127");
    if (!(c->sensitivity_dbm >= -200.0 && c->sensitivity_dbm <= 100.0)) BAD("radio.receiver.sensitivity_dbm", "must be in [-200, 100]");
    if (!(c->loss_width_db > 0.0 && c->loss_width_db <= 50.0)) BAD("radio.receiver.loss_width_db", "must be in (0, 50]");
    if (!(c->wall_cache_m >= 0.01 && c->wall_cache_m <= 10.0)) BAD("radio.walls.cache_m", "must be in [0.01, 10]");
#undef BAD
    return 0;
}

double hs_radio_uniform(rfs_rng_t *rng)
{
    uint64_t hi = rfs_rng_u32(rng) >> 5, lo = rfs_rng_u32(rng) >> 6; // 27 + 26 bits
    return ((double)hi * 67108864.0 + (double)lo) * (1.0 / 9007199254740992.0);
}

double hs_radio_gauss(rfs_rng_t *rng)
{
    double u1 = hs_radio_uniform(rng), u2 = hs_radio_uniform(rng);
    return sqrt(-2.0 * log(1.0 - u1)) * cos(2.0 * M_PI * u2);
}

/// Seed of one field: the run seed mixed with a field tag and the source index, so each
/// field is independent of the per-packet stream and of the other sources.
static void field_rng(rfs_rng_t *rng, uint64_t seed, unsigned tag, unsigned s)
{
    rfs_rng_seed(rng, seed ^ (0x9E3779B97F4A7C15ull * (uint64_t)(tag * 64u + s + 1u)));
}

/// Tabulate sigma * sqrt(2/M) * sum_i cos(k_i . x + phi_i) with the k_i drawn from the
/// normalised spectrum of sigma^2 exp(-r / d_c) in 2-D, whose radial CDF is
/// F(k) = 1 - (1 + (k d_c)^2)^-1/2 (inverted in closed form). Covariance of the sum:
/// sigma^2 E[cos(k . r)] = sigma^2 exp(-|r| / d_c). Rows and columns are separable:
/// e^{j k.x} = e^{j kx x} e^{j ky y}. Here the waves are drawn; a column's or row's cos
/// and sin are tabulated on its first read (shadow_line), the same values as all at once.
static int make_shadow(hs_radio_t *r, radio_src_t *rs, uint64_t seed, unsigned s)
{
    const hs_radio_cfg_t *c = &r->cfg;
    size_t n = (size_t)r->gw * r->gh;
    const size_t nw = c->shadow_waves;
    rs->shadow = malloc(n * sizeof(float));
    rs->shadow_x = malloc(sizeof(double) * r->gw * 2 * nw);
    rs->shadow_y = malloc(sizeof(double) * r->gh * 2 * nw);
    rs->shadow_k = malloc(sizeof(double) * 3 * nw);
    rs->shadow_xy = calloc((size_t)r->gw + r->gh, 1);
    if (!rs->shadow || !rs->shadow_x || !rs->shadow_y || !rs->shadow_k || !rs->shadow_xy) {
        return -1; // hs_radio_destroy frees them
    }
    for (size_t i = 0; i < n; i++) {
        rs->shadow[i] = NAN;
    }
    rfs_rng_t rng;
    field_rng(&rng, seed, 1, s);
    for (uint32_t i = 0; i < c->shadow_waves; i++) {
        double u = hs_radio_uniform(&rng);
        double k = sqrt(1.0 / ((1.0 - u) * (1.0 - u)) - 1.0) / c->shadow_dcorr_m;
        double a = 2.0 * M_PI * hs_radio_uniform(&rng);
        double ph = 2.0 * M_PI * hs_radio_uniform(&rng);
        rs->shadow_k[3 * i] = k * cos(a);
        rs->shadow_k[3 * i + 1] = k * sin(a);
        rs->shadow_k[3 * i + 2] = ph;
    }
    return 0;
}

/* Column gx's (y: row gy's) cos and sin of every wave, tabulated on first use: most of a
 * grid is never read, a table of all of it costs (gw + gh) x waves sincos a run. */
static const double *shadow_line(const hs_radio_t *r, const radio_src_t *rs, bool y, uint32_t g)
{
    const size_t nw = r->cfg.shadow_waves;
    double *t = (y ? rs->shadow_y : rs->shadow_x) + (size_t)g * nw * 2;
    uint8_t *done = &rs->shadow_xy[y ? r->gw + g : g];
    if (!*done) {
        for (size_t i = 0; i < nw; i++) {
            double p = y ? rs->shadow_k[3 * i + 1] * (g * r->cfg.shadow_grid_m)
                         : rs->shadow_k[3 * i] * (g * r->cfg.shadow_grid_m) + rs->shadow_k[3 * i + 2];
            t[2 * i] = cos(p);
            t[2 * i + 1] = sin(p);
        }
        *done = 1;
    }
    return t;
}

/* Grid point (gx, gy) of source rs's shadowing, summed over the waves on its first read
 * (a run reads a few hundred of the grid's points): the sum in wave order, each term
 * cos(px + py) = cos px cos py - sin px sin py, so the value of summing the whole grid. */
static float shadow_at(const hs_radio_t *r, const radio_src_t *rs, uint32_t gx, uint32_t gy)
{
    float *v = &rs->shadow[(size_t)gy * r->gw + gx];
    if (isnan(*v)) {
        const size_t nw = r->cfg.shadow_waves;
        const double *cx = shadow_line(r, rs, false, gx), *cy = shadow_line(r, rs, true, gy);
        double acc = 0.0;
        for (size_t i = 0; i < nw; i++) {
            acc += cx[2 * i] * cy[2 * i] - cx[2 * i + 1] * cy[2 * i + 1];
        }
        *v = (float)(acc * (r->cfg.shadow_sigma_db * sqrt(2.0 / r->cfg.shadow_waves)));
    }
    return *v;
}

static int make_fading(hs_radio_t *r, radio_src_t *rs, uint64_t seed, unsigned s)
{
    const hs_radio_cfg_t *c = &r->cfg;
    rs->waves = malloc(sizeof(fading_wave_t) * c->fading_waves);
    if (!rs->waves) {
        return -1;
    }
    rfs_rng_t rng;
    field_rng(&rng, seed, 2, s);
    for (uint32_t i = 0; i < c->fading_waves; i++) {
        double a = 2.0 * M_PI * hs_radio_uniform(&rng);
        rs->waves[i].kx = r->k_steps * cos(a);
        rs->waves[i].ky = r->k_steps * sin(a);
        rs->waves[i].ph = SIN_N * hs_radio_uniform(&rng);
    }
    return 0;
}

hs_radio_t *hs_radio_create(const hs_radio_cfg_t *cfg, const hs_radio_src_t *src,
                            unsigned nsrc, double x0, double y0, double x1, double y1,
                            uint64_t seed, hs_radio_walls_fn walls, void *walls_ctx,
                            char *err, size_t errlen)
{
    if (hs_radio_cfg_check(cfg, err, errlen) != 0) {
        return NULL;
    }
    if (nsrc == 0 || nsrc > HS_RADIO_MAX_SOURCES) {
        snprintf(err, errlen, "sources: need 1 to %u", HS_RADIO_MAX_SOURCES);
        return NULL;
    }
    if (!(x1 > x0 && y1 > y0) || x1 - x0 > 10000.0 || y1 - y0 > 10000.0) {
        snprintf(err, errlen, "radio: area must be non-empty and under 10 km");
        return NULL;
    }
    hs_radio_t *r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, errlen, "radio: out of memory");
        return NULL;
    }
    r->cfg = *cfg;
    r->nsrc = nsrc;
    r->x0 = x0;
    r->y0 = y0;
    r->gw = (uint32_t)ceil((x1 - x0) / cfg->shadow_grid_m) + 2;
    r->gh = (uint32_t)ceil((y1 - y0) / cfg->shadow_grid_m) + 2;
    r->cw = (uint32_t)ceil((x1 - x0) / cfg->wall_cache_m) + 1;
    r->ch = (uint32_t)ceil((y1 - y0) / cfg->wall_cache_m) + 1;
    r->k_steps = SIN_N / cfg->wavelength_m; // 2 pi / lambda rad/m = SIN_N / lambda steps/m
    r->walls_fn = walls;
    r->walls_ctx = walls_ctx;
    double k = pow(10.0, cfg->rician_k_db / 10.0);
    r->los_a = sqrt(k / (k + 1.0));
    r->los_b = sqrt(1.0 / (k + 1.0));
    r->scat = 1.0 / sqrt((double)cfg->fading_waves);
    for (unsigned i = 0; i < SIN_N; i++) {
        r->sin_tab[i] = (double)(float)sin(2.0 * M_PI * i / SIN_N);
    }
    for (unsigned s = 0; s < nsrc; s++) {
        radio_src_t *rs = &r->src[s];
        rs->s = src[s];
        int bad = 0;
        if (cfg->shadowing) {
            bad |= make_shadow(r, rs, seed, s);
        }
        if (cfg->fading) {
            bad |= make_fading(r, rs, seed, s);
        }
        if (cfg->walls && walls) {
            rs->walls = malloc((size_t)r->cw * r->ch);
            rs->walls_owned = true;
            if (rs->walls) {
                memset(rs->walls, -1, (size_t)r->cw * r->ch);
            } else {
                bad = -1;
            }
        }
        if (bad) {
            hs_radio_destroy(r);
            snprintf(err, errlen, "radio: out of memory");
            return NULL;
        }
    }
    return r;
}

void hs_radio_destroy(hs_radio_t *r)
{
    if (!r) {
        return;
    }
    for (unsigned s = 0; s < r->nsrc; s++) {
        free(r->src[s].shadow);
        free(r->src[s].shadow_x);
        free(r->src[s].shadow_y);
        free(r->src[s].shadow_k);
        free(r->src[s].shadow_xy);
        free(r->src[s].waves);
        if (r->src[s].walls_owned) {
            free(r->src[s].walls);
        }
    }
    free(r);
}

unsigned hs_radio_walls(hs_radio_t *r, unsigned s, double x, double y)
{
    radio_src_t *rs = &r->src[s];
    if (!r->cfg.walls || !r->walls_fn) {
        return 0;
    }
    double fx = (x - r->x0) / r->cfg.wall_cache_m + 0.5, fy = (y - r->y0) / r->cfg.wall_cache_m + 0.5;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < (double)r->cw && fy < (double)r->ch)) {
        return r->walls_fn(r->walls_ctx, x, y, rs->s.x, rs->s.y);
    }
    size_t cx = (size_t)fx, cy = (size_t)fy; // nearest cache point (x, y >= 0: truncation floors)
    int8_t *slot = &rs->walls[cy * r->cw + cx];
    if (*slot < 0) {
        // The count from the cache cell's centre stands for the whole cell.
        unsigned n = r->walls_fn(r->walls_ctx, r->x0 + cx * r->cfg.wall_cache_m,
                                 r->y0 + cy * r->cfg.wall_cache_m, rs->s.x, rs->s.y);
        *slot = (int8_t)(n > 127 ? 127 : n);
    }
    return (unsigned)*slot;
}

size_t hs_radio_wall_cache_bytes(const hs_radio_cfg_t *cfg, double x0, double y0, double x1,
                                 double y1)
{
    size_t cw = (size_t)ceil((x1 - x0) / cfg->wall_cache_m) + 1;
    size_t ch = (size_t)ceil((y1 - y0) / cfg->wall_cache_m) + 1;
    return cw * ch;
}

void hs_radio_use_wall_cache(hs_radio_t *r, unsigned s, int8_t *cache)
{
    radio_src_t *rs = &r->src[s];
    if (!r->cfg.walls || !r->walls_fn) {
        return;
    }
    if (rs->walls_owned) {
        free(rs->walls);
    }
    rs->walls = cache;
    rs->walls_owned = false;
}

double hs_radio_shadow_db(const hs_radio_t *r, unsigned s, double x, double y)
{
    const radio_src_t *rs = &r->src[s];
    if (!r->cfg.shadowing) {
        return 0.0;
    }
    double fx = (x - r->x0) / r->cfg.shadow_grid_m, fy = (y - r->y0) / r->cfg.shadow_grid_m;
    double maxx = r->gw - 1.001, maxy = r->gh - 1.001;
    fx = fx < 0.0 ? 0.0 : (fx > maxx ? maxx : fx);
    fy = fy < 0.0 ? 0.0 : (fy > maxy ? maxy : fy);
    uint32_t ix = (uint32_t)fx, iy = (uint32_t)fy;
    double ax = fx - ix, ay = fy - iy;
    const double p00 = shadow_at(r, rs, ix, iy), p10 = shadow_at(r, rs, ix + 1, iy);
    const double p01 = shadow_at(r, rs, ix, iy + 1), p11 = shadow_at(r, rs, ix + 1, iy + 1);
    double a = p00 + ax * (p10 - p00);
    double b = p01 + ax * (p11 - p01);
    return a + ay * (b - a);
}

double hs_radio_fading_db(const hs_radio_t *r, unsigned s, double x, double y, bool los)
{
    const radio_src_t *rs = &r->src[s];
    const hs_radio_cfg_t *c = &r->cfg;
    if (!c->fading) {
        return 0.0;
    }
    double re = 0.0, im = 0.0;
    for (uint32_t i = 0; i < c->fading_waves; i++) {
        const fading_wave_t *w = &rs->waves[i];
        uint32_t idx = (uint32_t)(int64_t)(w->kx * x + w->ky * y + w->ph);
        re += r->sin_tab[(idx + SIN_N / 4u) & SIN_MASK];
        im += r->sin_tab[idx & SIN_MASK];
    }
    re *= r->scat;
    im *= r->scat;
    if (los) {
        double a = r->los_a, b = r->los_b;
        double d = hypot(x - rs->s.x, y - rs->s.y);
        uint32_t idx = (uint32_t)(int64_t)(r->k_steps * d);
        re = a * r->sin_tab[(idx + SIN_N / 4u) & SIN_MASK] + b * re;
        im = a * r->sin_tab[idx & SIN_MASK] + b * im;
    }
    double p = re * re + im * im;
    return 10.0 * log10(p > 1e-6 ? p : 1e-6); // deepest fade -60 dB
}

static double mean_walls(hs_radio_t *r, unsigned s, double x, double y, unsigned *nw)
{
    const radio_src_t *rs = &r->src[s];
    const hs_radio_cfg_t *c = &r->cfg;
    double p = rs->s.tx_dbm;
    if (c->pathloss) {
        double d = sqrt((x - rs->s.x) * (x - rs->s.x) + (y - rs->s.y) * (y - rs->s.y));
        if (d < c->ref_dist_m) {
            d = c->ref_dist_m;
        }
        p -= c->ref_loss_db + 10.0 * c->exponent * log10(d / c->ref_dist_m);
    }
    *nw = hs_radio_walls(r, s, x, y);
    p -= c->wall_db * *nw;
    p += hs_radio_shadow_db(r, s, x, y);
    return p;
}

double hs_radio_mean_dbm(hs_radio_t *r, unsigned s, double x, double y)
{
    unsigned nw;
    return mean_walls(r, s, x, y, &nw);
}

/// Receiver positions closer than this share one signal value (lambda / 25 at 2.4 GHz):
/// the robot stands still or moves a few mm between packets at 200 pkt/s, so most
/// packets reuse the last value instead of summing the fading waves again.
#define MEMO_M 0.005

double hs_radio_signal_dbm(hs_radio_t *r, unsigned s, double x, double y)
{
    radio_src_t *rs = &r->src[s];
    int64_t qx = (int64_t)floor(x * (1.0 / MEMO_M)), qy = (int64_t)floor(y * (1.0 / MEMO_M));
    if (rs->memo_valid && qx == rs->memo_qx && qy == rs->memo_qy) {
        return rs->memo_dbm;
    }
    // The value of the whole memo cell is the one at its corner, so it does not depend on
    // where in the cell the first packet happened to be.
    x = qx * MEMO_M;
    y = qy * MEMO_M;
    unsigned nw;
    double p = mean_walls(r, s, x, y, &nw);
    bool los = !(r->cfg.walls && r->walls_fn) ? true : nw == 0;
    rs->memo_qx = qx;
    rs->memo_qy = qy;
    rs->memo_mean_dbm = p;
    rs->memo_dbm = p + hs_radio_fading_db(r, s, x, y, los);
    rs->memo_valid = true;
    return rs->memo_dbm;
}

double hs_radio_pdr(const hs_radio_cfg_t *cfg, double p_dbm)
{
    if (!cfg->loss) {
        return 1.0;
    }
    return 1.0 / (1.0 + exp(-(p_dbm - cfg->sensitivity_dbm) / cfg->loss_width_db));
}

bool hs_radio_packet(hs_radio_t *r, unsigned s, double x, double y, rfs_rng_t *rng, int *dbm)
{
    const hs_radio_cfg_t *c = &r->cfg;
    double p = hs_radio_signal_dbm(r, s, x, y);
    // Reception follows the local mean (path loss, walls, shadowing), not the narrowband
    // fade: an 802.11 frame spans 20 MHz, far more than the few-MHz coherence bandwidth
    // of an indoor channel, so a fade at one frequency does not stop it. (With fades in
    // the loss decision a robot that stops in a deep fade never hears another packet.)
    double p_rx = c->fading ? r->src[s].memo_mean_dbm : p;
    // 32 random bits are plenty for a delivery probability; 30 widths above the
    // sensitivity the loss probability (1e-13) is below their resolution: no draw.
    if (c->loss && p_rx < c->sensitivity_dbm + 30.0 * c->loss_width_db &&
        rfs_rng_u32(rng) * (1.0 / 4294967296.0) >= hs_radio_pdr(c, p_rx)) {
        return false;
    }
    if (c->noise) {
        double g;
        if (r->has_spare) {
            g = r->spare;
            r->has_spare = false;
        } else {
            // Box-Muller gives two independent normals; keep the second for the next packet.
            double u1 = hs_radio_uniform(rng), u2 = hs_radio_uniform(rng);
            double rad = sqrt(-2.0 * log(1.0 - u1));
            g = rad * cos(2.0 * M_PI * u2);
            r->spare = rad * sin(2.0 * M_PI * u2);
            r->has_spare = true;
        }
        p += c->noise_sigma_db * g;
    }
    if (c->clip) {
        p = p < c->rx_min_dbm ? c->rx_min_dbm : (p > c->rx_max_dbm ? c->rx_max_dbm : p);
    }
    if (c->quantise) {
        p = floor(p + 0.5);
    }
    // int8 range whatever the switches: the core takes int8_t dBm.
    p = p < -127.0 ? -127.0 : (p > 127.0 ? 127.0 : p);
    *dbm = (int)lrint(p);
    return true;
}
