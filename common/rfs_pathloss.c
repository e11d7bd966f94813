/* rfs_pathloss.c - the map-aware path-loss model (see rfs_pathloss.h): binning, the
 * candidate search and the fit; the wall counts are in rfs_pathloss_walls.c.
 *
 * For a candidate source s every bin b has a distance term L_b = 10 log10(max(d, 1 m))
 * and a wall count k_b. With count weights c_b and bin means z_b, the least-squares fit
 * of z = P0 - n L - W k eliminates P0 by centring (P0 = mean z + n mean L + W mean k)
 * and leaves a 2 x 2 system in (n, W):
 *
 *   [ Sll + lam   Slk       ] [n]   [ -Slz + lam n_prior ]
 *   [ Slk         Skk + lam ] [W] = [ -Skz + lam w_prior ]
 *
 * (S.. the count-weighted centred sums, lam the prior's weight). The matrix is positive
 * definite (lam > 0), so the box-constrained minimum is the unconstrained one when it is
 * inside the box, else the best of the four edges' clamped 1-D minima (exact for a
 * convex quadratic). Centred values are rounded to Q8 (1/256 dB) so every sum fits
 * int64; the solve is in 128 bits.
 */
#include "rfs_pathloss.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_pathloss_internal.h"

/// 10 log10(2) / 2 in Q2.30 (1.50514998...): 10 log10(d) per log2(d^2).
#define DB_PER_LOG2_SQ_Q30 1616142483LL
/// What an evaluated candidate is for (rfs_pathloss_ev_t.kind).
enum { EV_COARSE = 0, EV_REFINE = 1, EV_HOLD = 2 };
#define BINS_PER_UNIT RFS_PATHLOSS_BINS_PER_UNIT
#define SAMPLES_PER_UNIT RFS_PATHLOSS_SAMPLES_PER_UNIT
/// Work units of tidying the built-in cache when its rows or columns run out (at most
/// 32 KB set and about 35,000 cells cleared).
#define TIDY_UNITS 40u

rfs_pathloss_cfg_t rfs_pathloss_cfg_default(void)
{
    rfs_pathloss_cfg_t c;
    c.bin = RFS_Q16_ONE;
    c.coarse = RFS_Q16_INT(2);
    c.top = 3u;
    c.n_min = RFS_Q16_FRAC(3, 2);
    c.n_max = RFS_Q16_INT(5);
    c.w_min = 0;
    c.w_max = RFS_Q16_INT(15);
    c.n_prior = RFS_Q16_INT(3);  /* ITU-R P.1238 office, 2.4 GHz */
    c.w_prior = RFS_Q16_INT(5);  /* ns-3 buildings model, per wall */
    c.bin_cap = 5u;
    /* Strong enough to hold n near physics when the robot has seen little: 3000 weight x
     * dB^2 is about 60 capped bins missing by a 3 dB RMS per unit of n. The loss per
     * wall varies far more between buildings (drywall 3 dB, concrete 10 dB and more),
     * and a SLAM map marks furniture and laser artefacts as walls, so a map's "wall" is
     * worth less: its prior is a hundred times weaker, and the data sets W after a few
     * metres (300 held W near 5 dB for 40 m on the Intel lab map, where a crossing
     * costs 3 dB; docs/PATHLOSS.md, "Fit", gives both weights' sources). */
    c.prior_weight = RFS_Q16_INT(3000);
    c.w_prior_weight = RFS_Q16_INT(30);
    c.huber = RFS_Q16_INT(6);    /* about 1.5 x the 4 dB shadowing of the paper's office */
    c.spread_k = RFS_Q16_INT(6); /* chi-square, 2 degrees of freedom, 95 %: 5.99 */
    c.margin = RFS_Q16_INT(20);
    /* A Wi-Fi node transmits at least about -5 dBm (0-20 dBm typical) and loses 40 dB in
     * its first metre at 2.4 GHz: a fit that puts the source where the robot hears it
     * weakly (a wrong room, seen from outside) needs P0 far below this. In the simulator
     * runs behind docs/STRATEGIES.md, estimates within 5 m of the source had P0 >= -45 dBm
     * in all but 1 of 3,479 fits, estimates farther away had it below in 1,176 of 5,553. */
    c.p0_min = RFS_Q16_INT(-45);
    /* 30 dBm EIRP (the most any 2.4 GHz rule allows indoors) less those 40 dB: a fit that
     * explains a flat stretch of data by a source tens of metres off needs P0 far above
     * it (docs/PATHLOSS.md, "The P0 floor"). */
    c.p0_max = RFS_Q16_INT(-10);
    /* Off: the ceiling charges each wall the fit's W. The fit's W stays near its 5 dB prior
     * until the data set it, so behind 10-15 SLAM-map "walls" (3 dB in the simulator) the
     * true source's fit needs P0 20-30 dB above the node's; 3 dB (drywall) lets it pass,
     * but the held-out placements' table fell (docs/PATHLOSS.md, "The P0 floor"). */
    c.p0_max_wall = INT32_MAX;
    c.hold_k = RFS_Q16_INT(6);
    /* The spread region's and hold_k's likelihood-ratio reading of the surface, untempered
     * (docs/PATHLOSS.md, "Epsilon steps that draw the source"). */
    c.sample_t = RFS_Q16_ONE;
    c.hold_search = true;
    /* A quarter of the 1 m bin: the four points sit at the centres of the bin's quarters
     * when its centroid is central (docs/PATHLOSS.md, "A bin's walls"). */
    c.footprint = RFS_Q16_FRAC(1, 4);
    /* The coarse pass counts as the refinement does, whatever footprint a caller sets (0:
     * one count a bin, the coarse points then only rank: a quarter of their counts,
     * docs/PATHLOSS.md, "A bin's walls"). */
    c.coarse_footprint = RFS_PATHLOSS_COARSE_AS_FOOTPRINT;
    /* A 2 m grid misses corridors whose legal band (about 1 m) lies between two of its
     * rows (docs/PATHLOSS.md, "Fit", step 4). */
    c.coarse_snap = true;
    return c;
}

int rfs_pathloss_init(rfs_pathloss_t *p, const rfs_pathloss_cfg_t *cfg)
{
    if (p == 0 || cfg == 0) {
        return -1;
    }
    const rfs_pathloss_cfg_t *c = cfg;
    bool ok = c->bin >= RFS_Q16_FRAC(1, 10) && c->bin <= RFS_Q16_INT(16) && c->bin_cap > 0 &&
              c->coarse > 0 &&
              c->coarse <= RFS_Q16_INT(64) &&
              c->top >= 1u && c->top <= RFS_PATHLOSS_MAX_TOP && c->n_min > 0 &&
              c->n_min <= c->n_max && c->n_max <= RFS_Q16_INT(10) && c->w_min >= 0 &&
              c->w_min <= c->w_max && c->w_max <= RFS_Q16_INT(60) && c->n_prior >= c->n_min &&
              c->n_prior <= c->n_max && c->w_prior >= c->w_min && c->w_prior <= c->w_max &&
              c->prior_weight > 0 && c->prior_weight <= RFS_Q16_INT(10000) &&
              c->w_prior_weight > 0 && c->w_prior_weight <= RFS_Q16_INT(10000) && c->huber > 0 &&
              c->huber <= RFS_Q16_INT(100) && c->spread_k >= 0 &&
              c->spread_k <= RFS_Q16_INT(1000) && c->margin >= 0 && c->hold_k >= 0 &&
              c->hold_k <= RFS_Q16_INT(64) && c->footprint >= 0 && c->footprint <= c->bin / 2 &&
              (c->coarse_footprint == RFS_PATHLOSS_COARSE_AS_FOOTPRINT ||
               (c->coarse_footprint >= 0 && c->coarse_footprint <= c->bin / 2)) &&
              c->margin <= RFS_Q16_INT(100) && c->sample_t >= RFS_Q16_FRAC(1, 16) &&
              c->sample_t <= RFS_Q16_INT(64) &&
              ((c->p0_max_wall >= 0 && c->p0_max_wall <= RFS_Q16_INT(60)) ||
               c->p0_max_wall == INT32_MAX);
    if (!ok) {
        return -1;
    }
    memset(p, 0, sizeof(*p));
    p->cfg = *cfg;
    if (p->cfg.coarse_footprint == RFS_PATHLOSS_COARSE_AS_FOOTPRINT) {
        p->cfg.coarse_footprint = p->cfg.footprint;
    }
    return 0;
}

static void pathloss_reset(void *self)
{
    rfs_pathloss_t *p = (rfs_pathloss_t *)self;
    RFS_ASSERT(p != 0);
    p->valid = false;
    p->phase = RFS_PATHLOSS_IDLE;
}

/* rfs_pathloss_db_dist() with the mantissa's logarithm from tab (NULL: computed). */
static rfs_q16_t db_dist(const int32_t *tab, uint64_t d2_q32)
{
    const uint64_t one = (uint64_t)1 << 32; /* 1 m^2 */
    uint64_t v = d2_q32 < one ? one : d2_q32;
    /* floor(log2(v)) >= 32 from the high word's 32-bit clz (one CLZ on the Cortex-M4, no
     * libgcc helper); m: v's top 17 bits, 1.16. */
    uint32_t bl = 63u - (uint32_t)__builtin_clz((uint32_t)(v >> 32));
    uint32_t m = (uint32_t)(v >> (bl - 16u));
    int64_t lg = ((int64_t)bl - 32) * 65536 +
                 (tab != 0 ? tab[m - 65536u] : rfs_q16_log2((rfs_q16_t)m));
    return (rfs_q16_t)((lg * DB_PER_LOG2_SQ_Q30 + ((int64_t)1 << 29)) >> 30);
}

rfs_q16_t rfs_pathloss_db_dist(uint64_t d2_q32)
{
    return db_dist(0, d2_q32);
}

void rfs_pathloss_log2_fill(int32_t *tab)
{
    RFS_ASSERT(tab != 0);
    for (uint32_t k = 0u; k < RFS_PATHLOSS_LOG2_ENTRIES; ++k) {
        tab[k] = rfs_q16_log2((rfs_q16_t)(65536u + k));
    }
}

int rfs_pathloss_log2_attach(rfs_pathloss_t *p, const int32_t *tab)
{
    if (p == 0 || tab == 0) {
        return -1;
    }
    p->log2_tab = tab;
    return 0;
}

static uint32_t bin_hash(int16_t kx, int16_t ky)
{
    uint32_t h = (uint32_t)(uint16_t)kx * 0x9E3779B1u + (uint32_t)(uint16_t)ky * 0x85EBCA77u;
    return h >> 22; /* 10 bits: RFS_PATHLOSS_HASH = 1024 */
}

void rfs_pathloss_bin_reset(rfs_pathloss_t *p, int32_t bin_cm)
{
    memset(p->hash, 0, sizeof(p->hash));
    p->nbins = 0u;
    p->bin_cm = bin_cm;
    p->pos = 0u;
}

bool rfs_pathloss_bin_add(rfs_pathloss_t *p, const rfs_sample_t *smp, uint32_t end)
{
    _Static_assert(RFS_PATHLOSS_HASH == 1024u, "bin_hash yields 10 bits");
    const int32_t bin_cm = p->bin_cm;
    for (; p->pos < end; ++p->pos) {
        const rfs_sample_t *sm = &smp[p->pos];
        int16_t kx = (int16_t)rfs_pathloss_floor_div(sm->x_cm, bin_cm);
        int16_t ky = (int16_t)rfs_pathloss_floor_div(sm->y_cm, bin_cm);
        uint32_t h = bin_hash(kx, ky);
        while (p->hash[h] != 0u) {
            const rfs_pathloss_bin_t *b = &p->bins[p->hash[h] - 1u];
            if (b->kx == kx && b->ky == ky) {
                break;
            }
            h = (h + 1u) & (RFS_PATHLOSS_HASH - 1u);
        }
        if (p->hash[h] == 0u) {
            if (p->nbins == RFS_PATHLOSS_MAX_BINS) {
                return false;
            }
            rfs_pathloss_bin_t *nb = &p->bins[p->nbins];
            memset(nb, 0, sizeof(*nb));
            nb->kx = kx;
            nb->ky = ky;
            p->hash[h] = (uint16_t)(++p->nbins);
        }
        rfs_pathloss_bin_t *b = &p->bins[p->hash[h] - 1u];
        b->sx_cm += sm->x_cm;
        b->sy_cm += sm->y_cm;
        b->sv_q6 += sm->v_q6;
        b->count++;
    }
    return true;
}

/* The binned samples' means: each bin's position and value, less their weighted mean. */
static void bin_means(rfs_pathloss_t *p)
{
    /* Bin means (Q16), then their weighted mean. Scaling and overflow: a bin sums at most
     * 65,535 values of |v| <= 2^15 (int32); times 2^10 in int64 is Q16; weights <= 65,535
     * times |mean| < 2^25 summed over <= 512 bins stay below 2^50. */
    int64_t sum = 0;
    uint32_t wsum = 0u;
    for (uint32_t b = 0u; b < p->nbins; ++b) {
        rfs_pathloss_bin_t *bb = &p->bins[b];
        uint32_t wt = bb->count < p->cfg.bin_cap ? bb->count : p->cfg.bin_cap;
        bb->dz_q16 = (int32_t)rfs_sdiv64_round((int64_t)bb->sv_q6 * 1024, bb->count);
        sum += (int64_t)wt * bb->dz_q16;
        wsum += wt;
    }
    p->total = wsum;
    p->mz_q16 = (int32_t)rfs_sdiv64_round(sum, (int64_t)wsum);
    for (uint32_t b = 0u; b < p->nbins; ++b) {
        rfs_pathloss_bin_t *bb = &p->bins[b];
        bb->sx_cm = (int32_t)rfs_sdiv64_round(bb->sx_cm, bb->count);
        bb->sy_cm = (int32_t)rfs_sdiv64_round(bb->sy_cm, bb->count);
        bb->dz_q16 -= p->mz_q16;
        bb->count = (uint16_t)(bb->count < p->cfg.bin_cap ? bb->count : p->cfg.bin_cap);
        bb->x = rfs_pathloss_cm_to_q16(bb->sx_cm);
        bb->y = rfs_pathloss_cm_to_q16(bb->sy_cm);
        bb->wx = bb->x;
        bb->wy = bb->y;
        bb->row = RFS_PATHLOSS_NO_ROW;
        uint16_t cx, cy;
        if (p->map != 0 && rfs_map_cell(p->map, bb->x, bb->y, &cx, &cy)) {
            /* Scaling: cell corner + half a cell is inside the map's Q16 extent. */
            const rfs_map_t *m = p->map;
            bb->wx = rfs_sat32((int64_t)m->origin_x + (int64_t)cx * m->res + m->res / 2);
            bb->wy = rfs_sat32((int64_t)m->origin_y + (int64_t)cy * m->res + m->res / 2);
        }
    }
}

/* dx^2 + dy^2 for differences of Q16 values (|d| < 2^32): Q32 in uint64, saturated. */
static uint64_t sq_sum(int64_t dx, int64_t dy)
{
    uint64_t ax = (uint64_t)(dx < 0 ? -dx : dx), ay = (uint64_t)(dy < 0 ? -dy : dy);
    uint64_t a = ax * ax, b = ay * ay;
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

/* Lattice point (i, j) is within excl_r of a place ruled out (docs/STRATEGIES.md,
 * "Stalls"). Scaling: Q16 differences squared in uint64 (sq_sum) against r^2 (Q32). */
static bool excluded(const rfs_pathloss_t *p, int32_t i, int32_t j)
{
    if (p->nexcl == 0u) {
        return false;
    }
    rfs_q16_t x, y;
    rfs_pathloss_lattice_xy(&p->lat, (uint16_t)i, (uint16_t)j, &x, &y);
    const uint64_t r2 = (uint64_t)((int64_t)p->excl_r * p->excl_r);
    for (uint32_t e = 0u; e < p->nexcl; ++e) {
        if (sq_sum((int64_t)x - p->excl_x[e], (int64_t)y - p->excl_y[e]) <= r2) {
            return true;
        }
    }
    return false;
}

bool rfs_pathloss_cand_legal(const rfs_pathloss_t *p, int32_t i, int32_t j)
{
    if (i < 0 || j < 0 || i >= (int32_t)p->lat.lw || j >= (int32_t)p->lat.lh) {
        return false;
    }
    return (p->map == 0 || rfs_map_lattice_legal(p->map, (uint16_t)i, (uint16_t)j)) &&
           !excluded(p, i, j);
}

/* Work units of one snap search (at most (2 SNAP_REACH + 1)^2 legality tests). */
#define SNAP_UNITS 4u

static rfs_i128_t i128_of(int64_t v)
{
    rfs_i128_t r;
    r.lo = (uint64_t)v;
    r.hi = v < 0 ? -1 : 0;
    return r;
}

/* F(n, W) = M11 n^2 + 2 M12 n W + M22 W^2 - 2 (R1 n + R2 W), Q48 in 128 bits: the LS
 * objective up to a constant. Scaling: M Q16 < 2^46, n, W Q16 < 2^23: n^2 < 2^46,
 * products < 2^92; R Q16 < 2^50 times n 2^17 < 2^90. */
static rfs_i128_t objective(const int64_t M[3], const int64_t R[2], int32_t n, int32_t w)
{
    rfs_i128_t f = rfs_i128_mul(M[0], (int64_t)n * n);
    f = rfs_i128_add(f, rfs_i128_mul(M[1], 2 * (int64_t)n * w));
    f = rfs_i128_add(f, rfs_i128_mul(M[2], (int64_t)w * w));
    f = rfs_i128_sub(f, rfs_i128_mul(R[0], (int64_t)n * 131072));
    return rfs_i128_sub(f, rfs_i128_mul(R[1], (int64_t)w * 131072));
}

/* Minimiser of the 1-D quadratic along one variable with the other fixed at v, clamped:
 * (r * 2^16 - m12 v) / m, Q16. Scaling: r < 2^50 times 2^16 and m12 v < 2^69: 128 bits. */
static int32_t edge_min(int64_t r, int64_t m12, int32_t v, int64_t m, int32_t lo, int32_t hi)
{
    rfs_i128_t num = rfs_i128_sub(rfs_i128_mul(r, 65536), rfs_i128_mul(m12, v));
    int64_t x = rfs_i128_div_shift(num, i128_of(m), 0u);
    return x < lo ? lo : (x > hi ? hi : (int32_t)x);
}

/* Box-constrained least squares in (n, W); M = {M11, M12, M22}, R = right-hand side,
 * both Q16 (see the file comment). M is positive definite. */
static void solve_nw(const rfs_pathloss_cfg_t *c, const int64_t M[3], const int64_t R[2],
                     int32_t *n_out, int32_t *w_out)
{
    rfs_i128_t det = rfs_i128_sub(rfs_i128_mul(M[0], M[2]), rfs_i128_mul(M[1], M[1]));
    rfs_i128_t nn = rfs_i128_sub(rfs_i128_mul(R[0], M[2]), rfs_i128_mul(M[1], R[1]));
    int64_t n = rfs_i128_div_shift(nn, det, 16u);
    if (n >= c->n_min && n <= c->n_max) { /* else W is moot: an edge's */
        rfs_i128_t nw = rfs_i128_sub(rfs_i128_mul(M[0], R[1]), rfs_i128_mul(M[1], R[0]));
        int64_t w = rfs_i128_div_shift(nw, det, 16u);
        if (w >= c->w_min && w <= c->w_max) {
            *n_out = (int32_t)n;
            *w_out = (int32_t)w;
            return;
        }
    }
    /* The four edges: n at a bound with W free, W at a bound with n free. */
    int32_t en[4], ew[4];
    en[0] = c->n_min;
    en[1] = c->n_max;
    ew[0] = edge_min(R[1], M[1], en[0], M[2], c->w_min, c->w_max);
    ew[1] = edge_min(R[1], M[1], en[1], M[2], c->w_min, c->w_max);
    ew[2] = c->w_min;
    ew[3] = c->w_max;
    en[2] = edge_min(R[0], M[1], ew[2], M[0], c->n_min, c->n_max);
    en[3] = edge_min(R[0], M[1], ew[3], M[0], c->n_min, c->n_max);
    uint32_t best = 0u;
    rfs_i128_t fb = objective(M, R, en[0], ew[0]);
    for (uint32_t e = 1u; e < 4u; ++e) {
        rfs_i128_t f = objective(M, R, en[e], ew[e]);
        if (rfs_i128_neg(rfs_i128_sub(f, fb))) {
            fb = f;
            best = e;
        }
    }
    *n_out = en[best];
    *w_out = ew[best];
}

/* Fit (P0, n, W) for the candidate in p->ev, whose bins gather_bin() has done, and its
 * Huber loss.
 * Scaling and overflow (|L| < 64 dB, so L Q16 < 2^22; counts sum to <= 65,535 = 2^16;
 * walls in quarters <= 60, Q16 / 4 < 2^20; |dz| < 2^10 dB, Q16 < 2^26): centred values in
 * Q8 are below 2^15 (l), 2^16 (k) and c dz < 2^34 (e); the sums c l^2, c l k, c k^2 stay
 * below 2^16 x 2^32 = 2^48 and l e, k e below 2^16 x 2^34 = 2^50, all in int64. */
static void solve(rfs_pathloss_t *p, rfs_pathloss_cand_t *out)
{
    const rfs_pathloss_cfg_t *c = &p->cfg;
    const rfs_q16_t sx = p->ev.sx, sy = p->ev.sy;
    const uint32_t nbins = p->nbins;
    const int64_t tot = (int64_t)p->total;
    const int32_t ml = (int32_t)rfs_sdiv64_round(p->ev.sl, tot);
    const int32_t mk = (int32_t)rfs_sdiv64_round(p->ev.sk * 16384, tot); /* walls Q16 */
    int64_t all = 0, alk = 0, akk = 0, bl = 0, bk = 0;
    for (uint32_t b = 0u; b < nbins; ++b) {
        const rfs_pathloss_bin_t *bb = &p->bins[b];
        int64_t cnt = bb->count;
        int64_t l8 = ((int64_t)p->l_q16[b] - ml + 128) >> 8;
        int64_t k8 = ((int64_t)p->k[b] * 16384 - mk + 128) >> 8;
        int64_t e8 = (cnt * bb->dz_q16 + 128) >> 8;
        all += cnt * l8 * l8;
        alk += cnt * l8 * k8;
        akk += cnt * k8 * k8;
        bl += l8 * e8;
        bk += k8 * e8;
    }
    /* The prior: lam (n - n_prior)^2 + lamw (W - w_prior)^2, in the units of M (Q16).
     * Scaling: lam, lamw < 2^30 times a prior < 2^22 (Q16 <= 60): < 2^52. */
    const int64_t lam = c->prior_weight, lamw = c->w_prior_weight;
    const int64_t M[3] = {all + lam, alk, akk + lamw};
    const int64_t R[2] = {-bl + ((lam * c->n_prior + 32768) >> 16),
                          -bk + ((lamw * c->w_prior + 32768) >> 16)};
    int32_t n, w;
    solve_nw(c, M, R, &n, &w);
    /* Huber loss of the bins' mean residuals z_b - P0 + n L_b + W k_b
     * = dz_b + n (L_b - mean L) + W (k_b - mean k), Q16, then Q8 (saturated to 2^24). */
    const int64_t d8 = ((int64_t)c->huber + 128) >> 8;
    int64_t loss = 0;
    for (uint32_t b = 0u; b < nbins; ++b) {
        const rfs_pathloss_bin_t *bb = &p->bins[b];
        int64_t r = (int64_t)bb->dz_q16 +
                    (((int64_t)n * ((int64_t)p->l_q16[b] - ml) +
                      (int64_t)w * ((int64_t)p->k[b] * 16384 - mk) + 32768) >> 16);
        int64_t a = (r < 0 ? -r : r);
        a = (a + 128) >> 8;
        a = a > ((int64_t)1 << 24) ? ((int64_t)1 << 24) : a;
        int64_t h = a <= d8 ? (a * a) >> 1 : d8 * a - ((d8 * d8) >> 1);
        loss += (int64_t)bb->count * h;
    }
    int64_t p0 = (int64_t)p->mz_q16 + (((int64_t)n * ml + (int64_t)w * mk + 32768) >> 16);
    /* Scaling: the shortfall or excess in Q8 saturates at 2^24 like a residual; total <=
     * 2^16 times the Huber value < 2^35 stays below 2^51. */
    /* The ceiling's P0: walls charged at most p0_max_wall each; (W - p0_max_wall) < 2^22
     * (Q16 dB <= 60) times mk < 2^20 (Q16 walls <= 15) stays below 2^42. */
    const int64_t p0c = w > c->p0_max_wall
                            ? p0 - ((((int64_t)w - c->p0_max_wall) * mk + 32768) >> 16)
                            : p0;
    int64_t a = p0 < c->p0_min ? (((int64_t)c->p0_min - p0) + 128) >> 8
              : c->p0_max != INT32_MAX && p0c > c->p0_max ? ((p0c - (int64_t)c->p0_max) + 128) >> 8
                                                          : 0;
    if (a > 0) {
        a = a > ((int64_t)1 << 24) ? ((int64_t)1 << 24) : a;
        int64_t h = a <= d8 ? (a * a) >> 1 : d8 * a - ((d8 * d8) >> 1);
        loss += (int64_t)p->total * h;
    }
    out->loss = loss;
    out->sx = sx;
    out->sy = sy;
    out->li = p->ev.li;
    out->lj = p->ev.lj;
    out->n = n;
    out->w = w;
    out->p0 = rfs_sat32(p0);
    p->candidates++;
}

/* Start evaluating candidate (li, lj) for phase step `kind` (surface index c for a
 * coarse candidate). */
static void ev_start(rfs_pathloss_t *p, uint16_t li, uint16_t lj, uint8_t kind, uint32_t c)
{
    p->ev.on = true;
    p->ev.kind = kind;
    p->ev.li = li;
    p->ev.lj = lj;
    rfs_pathloss_lattice_xy(&p->lat, li, lj, &p->ev.sx, &p->ev.sy);
    p->ev.col = rfs_pathloss_walls_col(p, li, lj, kind == EV_COARSE);
    p->ev.fp = kind == EV_COARSE ? p->cfg.coarse_footprint : p->cfg.footprint;
    p->ev.c = c;
    p->ev.b = 0u;
    p->ev.sl = 0;
    p->ev.sk = 0;
}

/* The coarse pass counts with its own footprint, so it only ranks (docs/PATHLOSS.md,
 * "Fit", step 4): its top points are evaluated again in the refinement. */
static bool coarse_ranks(const rfs_pathloss_t *p)
{
    return p->map != 0 && p->cfg.coarse_footprint != p->cfg.footprint;
}

static void consider(rfs_pathloss_t *p, const rfs_pathloss_cand_t *cd)
{
    if (cd->loss < p->cur.loss) {
        p->cur = *cd;
    }
}

/* Keep the best `top` coarse candidates, best first (ties: the earlier one). */
static void keep_top(rfs_pathloss_t *p, const rfs_pathloss_cand_t *cd)
{
    uint32_t k = p->ntop;
    if (k == p->cfg.top && cd->loss >= p->top[k - 1u].loss) {
        return;
    }
    if (k == p->cfg.top) {
        k--;
    }
    while (k > 0u && cd->loss < p->top[k - 1u].loss) {
        p->top[k] = p->top[k - 1u];
        k--;
    }
    p->top[k] = *cd;
    if (p->ntop < p->cfg.top) {
        p->ntop++;
    }
}

/* True when lattice point (i, j) was evaluated in this fit with the footprint: a coarse
 * point (unless the coarse pass only ranked), or one of the remembered refinement points
 * (remembered here when it was not). */
static bool seen_before(rfs_pathloss_t *p, int32_t i, int32_t j)
{
    if (!coarse_ranks(p) && rfs_pathloss_is_coarse(p, i, j)) {
        return true;
    }
    for (uint32_t k = 0u; k < p->nvis; ++k) {
        if (p->vis_i[k] == i && p->vis_j[k] == j) {
            return true;
        }
    }
    if (p->nvis < RFS_PATHLOSS_MAX_VISITED) {
        p->vis_i[p->nvis] = (uint16_t)i;
        p->vis_j[p->nvis] = (uint16_t)j;
        p->nvis++;
    }
    return false;
}

static void finish(rfs_pathloss_t *p)
{
    const rfs_pathloss_lat_t *l = &p->lat;
    p->best = p->cur;
    /* Spread region: mean loss <= best (1 + spread_k / bins). */
    uint64_t bm = rfs_pathloss_mean_loss(p, p->best.loss);
    uint64_t thr = bm + rfs_udiv64(bm * (uint64_t)p->cfg.spread_k, (uint64_t)p->nbins * 65536u);
    /* At least the best coarse point: the surface cannot resolve a smaller region. */
    uint64_t tc = rfs_pathloss_mean_loss(p, p->top[0].loss);
    thr = thr > tc ? thr : tc;
    uint32_t cnt = 0u;
    for (uint32_t c = 0u; c < (uint32_t)l->ncx * l->ncy; ++c) {
        cnt += (p->surface[c] != RFS_PATHLOSS_NO_LOSS && p->surface[c] <= thr) ? 1u : 0u;
    }
    /* Scaling: cell side cs * grid < 2^22 (Q16 <= 64 m); its square Q32 >> 16 fits. */
    int64_t side = (int64_t)l->cs * l->grid;
    int64_t cell = (side * side + 32768) >> 16;
    p->spread_m2 = rfs_sat32(cell * cnt);
    p->used_bins = p->nbins;
    p->used_bin_cm = p->bin_cm;
    p->phase = RFS_PATHLOSS_IDLE;
    p->valid = true;
    p->have_prev = true;
    p->prev_map = p->map;
}

/* Point rem (0..8, row by row; 4 is the centre) of the 3 x 3 neighbourhood of lattice
 * point (ci, cj) at spacing step. */
static void neighbour(int32_t ci, int32_t cj, uint32_t rem, int32_t step, int32_t *i, int32_t *j)
{
    *i = ci + ((int32_t)(rem % 3u) - 1) * step;
    *j = cj + ((int32_t)(rem / 3u) - 1) * step;
}

/* The hold phase: the previous source (p->best until finish()) and, with hold_search, a
 * 3 x 3 hill-climb round it at halving spacings; then its best point against the new
 * best. true: a candidate was started (evaluate it and call again); false: the phase is
 * over and p->cur is the fit's answer. Keeps the held point while its loss is within the
 * likelihood-ratio margin cur (1 + hold_k / bins). Scaling: the loss is below 2^53
 * (weights <= 2^16 times Huber values < 2^36, plus the P0 term); (loss / bins) * hold_k
 * (Q16 <= 2^22) saturates rather than wrap. */
static bool hold_next(rfs_pathloss_t *p)
{
    if (p->hold_pos == UINT8_MAX) {
        p->hold_pos = 0u;
        ev_start(p, p->hold_i, p->hold_j, EV_HOLD, 0u);
        return true;
    }
    while (p->cfg.hold_search) {
        while (p->hold_pos < 9u) {
            uint32_t rem = p->hold_pos++;
            int32_t i, j;
            neighbour(p->hold_i, p->hold_j, rem, p->hold_step, &i, &j);
            if (rem != 4u && rfs_pathloss_cand_legal(p, i, j)) {
                ev_start(p, (uint16_t)i, (uint16_t)j, EV_HOLD, 0u);
                return true;
            }
        }
        if (p->hold_step <= 1u) {
            break;
        }
        p->hold_step = (uint16_t)(p->hold_step / 2u);
        p->hold_i = p->hold_best.li;
        p->hold_j = p->hold_best.lj;
        p->hold_pos = 0u;
    }
    uint64_t per = rfs_udiv64((uint64_t)p->cur.loss, p->nbins);
    uint64_t thr = per >= ((uint64_t)1 << 41)
                       ? UINT64_MAX
                       : (uint64_t)p->cur.loss + ((per * (uint64_t)p->cfg.hold_k) >> 16);
    if ((uint64_t)p->hold_best.loss <= thr) {
        p->cur = p->hold_best;
    }
    return false;
}

/* A fit begins (binning comes next, bin_run()). false when there is nothing to fit. */
static bool fit_begin(rfs_pathloss_t *p, const rfs_model_fit_in_t *in)
{
    p->valid = false;
    if (in->n == 0u) {
        return false;
    }
    p->map = in->map;
    /* The places ruled out are copied: a sliced fit sees the same ones to the end. */
    p->nexcl = in->excl_r > 0 && in->excl_x_cm != 0 && in->excl_y_cm != 0
                   ? (uint8_t)(in->nexcl < RFS_MODEL_MAX_EXCL ? in->nexcl : RFS_MODEL_MAX_EXCL)
                   : 0u;
    p->excl_r = in->excl_r;
    for (uint32_t e = 0u; e < p->nexcl; ++e) {
        p->excl_x[e] = rfs_pathloss_cm_to_q16(in->excl_x_cm[e]); /* once a fit, not per candidate */
        p->excl_y[e] = rfs_pathloss_cm_to_q16(in->excl_y_cm[e]);
    }
    rfs_pathloss_bin_reset(p, (int32_t)(((int64_t)p->cfg.bin * 100 + 32768) >> 16));
    p->bin_n = in->n;
    p->walls_counted = 0u;
    p->footprints = 0u;
    p->footprints_cached = 0u;
    p->walls_warmed = p->warm.lines;
    memset(&p->warm, 0, sizeof(p->warm)); /* the bins warming used are the fit's now */
    p->phase = RFS_PATHLOSS_BIN;
    p->ntop = 0u;
    p->nvis = 0u;
    p->candidates = 0u;
    p->cur.loss = INT64_MAX;
    p->ev.on = false;
    return true;
}

/* Bin the samples, SAMPLES_PER_UNIT a work unit, doubling the bin side until at most
 * MAX_BINS are used (100 cm doubled 10 times covers the whole +-327 m sample range); then
 * the bins' means, the candidate lattice and the cache rows (BINS_PER_UNIT bins a unit),
 * and on to the coarse phase. Stops before a unit would overrun the budget, doing at
 * least one per call. true when the call must return *res: MORE (budget spent) or
 * FAILED (no sample left to fit). */
static bool bin_run(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget,
                    uint32_t *used, rfs_fit_result_t *res)
{
    *res = RFS_FIT_MORE;
    const uint32_t n = p->bin_n < in->n ? p->bin_n : in->n;
    while (p->pos < n) {
        if (budget != 0u && *used != 0u && *used >= budget) {
            return true;
        }
        const uint32_t end = n - p->pos > SAMPLES_PER_UNIT ? p->pos + SAMPLES_PER_UNIT : n;
        (*used)++;
        if (!rfs_pathloss_bin_add(p, in->samples, end)) {
            rfs_pathloss_bin_reset(p, p->bin_cm * 2);
        }
    }
    /* With the built-in cache, the rows' and columns' tidying too (rfs_pathloss_walls.c). */
    const uint32_t finish_units = p->nbins / BINS_PER_UNIT + 1u + (p->x.cells == 0 ? TIDY_UNITS : 0u);
    if (budget != 0u && *used != 0u && *used + finish_units > budget) {
        return true;
    }
    *used += finish_units;
    if (p->nbins == 0u) { /* the samples went while the fit was sliced */
        p->phase = RFS_PATHLOSS_IDLE;
        *res = RFS_FIT_FAILED;
        return true;
    }
    bin_means(p);
    rfs_pathloss_lattice_setup(p, in->map);
    rfs_pathloss_walls_assign(p);
    p->phase = RFS_PATHLOSS_COARSE;
    p->pos = 0u;
    return false;
}

/* Evaluate the started candidate: gather its bins, stopping before a bin that could
 * overrun the budget (at most four wall counts) but gathering at least one per call
 * (false: call again), then solve it and record the result for its phase. *used counts
 * the work units of this call. */
static bool ev_run(rfs_pathloss_t *p, uint32_t budget, uint32_t *used)
{
    /* Each bin's 10 log10(d) in l_q16[b] and walls in k[b], their weighted sums in ev.sl,
     * ev.sk. Scaling: weight < 2^16 times |L| < 2^22 or k <= 60, over <= 512 bins: int64. */
    const rfs_pathloss_bin_t *bins = p->bins;
    const int32_t *tab = p->log2_tab;
    const bool walls = p->map != 0;
    const uint32_t nbins = p->nbins;
    const rfs_q16_t sx = p->ev.sx, sy = p->ev.sy;
    uint32_t b = p->ev.b, u = *used;
    int64_t sl = p->ev.sl, sk = p->ev.sk;
    while (b < nbins) {
        if (budget != 0u && u != 0u && u + RFS_PATHLOSS_FOOTPRINT_RAYS > budget) {
            break;
        }
        const rfs_pathloss_bin_t *bb = &bins[b];
        const rfs_q16_t l = db_dist(tab, sq_sum((int64_t)bb->x - sx, (int64_t)bb->y - sy));
        uint32_t lines = 0u;
        const uint32_t k = walls ? rfs_pathloss_walls_bin(p, bb, &lines) : 0u;
        p->l_q16[b] = l;
        p->k[b] = (uint8_t)k;
        sl += (int64_t)bb->count * l;
        sk += (int64_t)bb->count * k;
        b++;
        u += lines + (b % BINS_PER_UNIT == 0u ? 1u : 0u);
    }
    p->ev.b = b;
    p->ev.sl = sl;
    p->ev.sk = sk;
    *used = u;
    if (b < nbins) {
        return false;
    }
    const uint32_t solve_units = p->nbins / BINS_PER_UNIT + 1u;
    if (budget != 0u && *used != 0u && *used + solve_units > budget) {
        return false;
    }
    *used += solve_units;
    rfs_pathloss_cand_t cd;
    solve(p, &cd);
    p->ev.on = false;
    if (p->ev.kind == EV_HOLD) {
        if (cd.loss < p->hold_best.loss) {
            p->hold_best = cd;
        }
        return true;
    }
    if (p->ev.kind == EV_COARSE) {
        p->surface[p->ev.c] = rfs_pathloss_mean_loss(p, cd.loss);
        keep_top(p, &cd);
        if (coarse_ranks(p)) {
            return true;
        }
    }
    consider(p, &cd);
    return true;
}

/* The coarse phase's next point: start it when legal; at the end, on to the refinement.
 * A point's first snap search (coarse_snap) is a work unit: none when it would overrun the
 * budget (*res MORE). true when the call must return *res (FAILED: no legal candidate on
 * the map). */
static bool coarse_next(rfs_pathloss_t *p, uint32_t budget, uint32_t *used, rfs_fit_result_t *res)
{
    const rfs_pathloss_lat_t *l = &p->lat;
    uint32_t nc = (uint32_t)l->ncx * l->ncy;
    if (p->pos >= nc) {
        if (p->ntop == 0u) {
            p->phase = RFS_PATHLOSS_IDLE;
            *res = RFS_FIT_FAILED;
            return true;
        }
        p->phase = RFS_PATHLOSS_REFINE;
        p->step = (uint16_t)(l->cs / 2u < 1u ? 1u : l->cs / 2u);
        p->pos = 0u;
        return false;
    }
    const uint32_t c = p->pos;
    if (p->snap[c] == RFS_PATHLOSS_SNAP_UNKNOWN) {
        if (budget != 0u && *used != 0u && *used + SNAP_UNITS > budget && p->cfg.coarse_snap) {
            *res = RFS_FIT_MORE;
            return true;
        }
        bool searched;
        p->snap[c] = rfs_pathloss_snap_find(p, c, &searched);
        *used += searched ? SNAP_UNITS : 0u;
    }
    p->pos++;
    p->surface[c] = RFS_PATHLOSS_NO_LOSS;
    int32_t i, j;
    if (rfs_pathloss_coarse_ij(p, c, &i, &j) && rfs_pathloss_cand_legal(p, i, j)) {
        ev_start(p, (uint16_t)i, (uint16_t)j, EV_COARSE, c);
    }
    return false;
}

/* After the finest refinement: hold the previous source (docs/PATHLOSS.md, "Fit", step
 * 6 "Hold") when the fit moved away from it on the same map
 * and it is still a legal candidate. true when the hold phase began. */
static bool hold_begin(rfs_pathloss_t *p)
{
    if (p->cfg.hold_k <= 0 || !p->have_prev || p->map == 0 || p->prev_map != p->map ||
        (p->best.li == p->cur.li && p->best.lj == p->cur.lj) ||
        !rfs_pathloss_cand_legal(p, p->best.li, p->best.lj)) {
        return false;
    }
    const rfs_pathloss_lat_t *l = &p->lat;
    p->phase = RFS_PATHLOSS_HOLD;
    p->hold_i = p->best.li;
    p->hold_j = p->best.lj;
    p->hold_step = (uint16_t)(l->cs / 2u < 1u ? 1u : l->cs / 2u);
    p->hold_pos = UINT8_MAX; /* the previous source itself first */
    p->hold_best.loss = INT64_MAX;
    return true;
}

/* The refinement's next point: the 3 x 3 neighbourhood at p->step around each top
 * candidate (REFINE) or around the best so far (FINE), row by row, at halving steps;
 * then the hold phase. true when the fit is over (*res DONE). */
static bool refine_next(rfs_pathloss_t *p, rfs_fit_result_t *res)
{
    if (p->phase == RFS_PATHLOSS_REFINE && p->pos >= 9u * p->ntop) {
        p->phase = RFS_PATHLOSS_FINE;
        p->pos = 9u;
    }
    if (p->phase == RFS_PATHLOSS_HOLD) {
        if (hold_next(p)) {
            return false;
        }
        finish(p);
        *res = RFS_FIT_DONE;
        return true;
    }
    if (p->phase == RFS_PATHLOSS_FINE && p->pos >= 9u) {
        if (p->step <= 1u) {
            if (hold_begin(p)) {
                return false;
            }
            finish(p);
            *res = RFS_FIT_DONE;
            return true;
        }
        p->step = (uint16_t)(p->step / 2u);
        p->fc_i = p->cur.li;
        p->fc_j = p->cur.lj;
        p->pos = 0u;
    }
    uint32_t k = p->pos / 9u, rem = p->pos % 9u;
    p->pos++;
    int32_t ci = p->phase == RFS_PATHLOSS_REFINE ? p->top[k].li : p->fc_i;
    int32_t cj = p->phase == RFS_PATHLOSS_REFINE ? p->top[k].lj : p->fc_j;
    int32_t i, j;
    neighbour(ci, cj, rem, p->step, &i, &j);
    /* A top point itself (rem 4) when the coarse pass only ranked it. */
    const bool centre = rem == 4u && !(p->phase == RFS_PATHLOSS_REFINE && coarse_ranks(p));
    if (!centre && rfs_pathloss_cand_legal(p, i, j) && !seen_before(p, i, j)) {
        ev_start(p, (uint16_t)i, (uint16_t)j, EV_REFINE, 0u);
    }
    return false;
}

static rfs_fit_result_t pathloss_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                     rfs_rng_t *rng)
{
    rfs_pathloss_t *p = (rfs_pathloss_t *)self;
    (void)rng;
    RFS_ASSERT(p != 0 && in != 0 && (in->samples != 0 || in->n == 0u));
    if (p->phase == RFS_PATHLOSS_IDLE && !fit_begin(p, in)) {
        return RFS_FIT_FAILED;
    }
    uint32_t used = 0u;
    rfs_fit_result_t res = RFS_FIT_DONE;
    for (;;) {
        if (p->phase == RFS_PATHLOSS_BIN) {
            if (bin_run(p, in, budget, &used, &res)) {
                return res;
            }
        } else if (p->ev.on) {
            if (!ev_run(p, budget, &used)) {
                return RFS_FIT_MORE;
            }
        } else if (p->phase == RFS_PATHLOSS_COARSE ? coarse_next(p, budget, &used, &res)
                                                   : refine_next(p, &res)) {
            return res;
        }
    }
}

uint32_t rfs_pathloss_walls_to_source(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y)
{
    RFS_ASSERT(p != 0);
    if (!p->valid || p->map == 0) {
        return 0u;
    }
    return rfs_pathloss_walls_line(p, x, y, p->best.sx, p->best.sy);
}

/* Prediction P0 - n 10 log10(max(d, 1 m)) - W walls at (x, y).
 * Scaling and overflow: Q16 differences < 2^32, their squares (Q32 m^2) summed in
 * uint64, saturated (sq_sum); n L and W k products < 2^45 in int64, saturated. */
bool rfs_pathloss_predict_walls(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y,
                                uint32_t walls, rfs_q16_t *value)
{
    RFS_ASSERT(p != 0 && value != 0);
    if (!p->valid) {
        return false;
    }
    int64_t dx = (int64_t)x - p->best.sx, dy = (int64_t)y - p->best.sy;
    int64_t L = rfs_pathloss_db_dist(sq_sum(dx, dy));
    int64_t k = p->map != 0 ? (int64_t)walls : 0;
    int64_t v = (int64_t)p->best.p0 - (((int64_t)p->best.n * L + 32768) >> 16) - p->best.w * k;
    *value = rfs_sat32(v);
    return true;
}

/* One logarithm and one wall count. */
static bool pathloss_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    return rfs_pathloss_predict_walls(p, x, y, rfs_pathloss_walls_to_source(p, x, y), value);
}

static bool pathloss_argmax(const void *self, rfs_q16_t *x, rfs_q16_t *y)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    if (!p->valid) {
        return false;
    }
    *x = p->best.sx;
    *y = p->best.sy;
    return true;
}

/* Scaling: P0 and p0_min Q16.16 dB (|.| < 2^31), the difference in int64, saturated. */
static bool pathloss_floor_gap(const void *self, rfs_q16_t *gap)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    if (!p->valid || p->cfg.p0_min == INT32_MIN) {
        return false;
    }
    *gap = rfs_sat32((int64_t)p->best.p0 - p->cfg.p0_min);
    return true;
}

const rfs_model_ops_t rfs_pathloss_ops = {
    .name = "pathloss",
    .reset = pathloss_reset,
    .fit = pathloss_fit,
    .predict = pathloss_predict,
    .argmax = pathloss_argmax,
    .predict_row = 0,
    .sample = rfs_pathloss_sample_op,
    .near = rfs_pathloss_near_op,
    .floor_gap = pathloss_floor_gap,
    .mean = rfs_pathloss_mean_op,
    .warm = rfs_pathloss_warm_op,
};

rfs_model_t rfs_pathloss_model(rfs_pathloss_t *p)
{
    rfs_model_t m;
    m.ops = &rfs_pathloss_ops;
    m.self = p;
    return m;
}
