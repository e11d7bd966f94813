/* rfs_ridge.c - local ridge regression, exactly scikit-learn's Ridge (paper section 5.2.1).
 *
 * scikit-learn's Ridge(alpha, fit_intercept=True) centres X and y on their means and
 * solves (Xc'Xc + alpha I) w = Xc'yc; the intercept is mean(y) - mean(X) w. With
 * positions in centimetres (u, v, centred on the query point) and values in Q9.6 (z),
 * multiplying that system by n * 10^4 turns every entry into an exact integer:
 *
 *   [ n Suu - Su^2 + n lam    n Suv - Su Sv       ] [wx]         [ n Suz - Su Sz ]
 *   [ n Suv - Su Sv           n Svv - Sv^2 + n lam] [wy] = 100 * [ n Svz - Sv Sz ] / 64
 *
 * with w in dB per metre and lam = alpha * 10^4 (alpha in m^2, lam in cm^2; rounded to
 * an integer, exact for alpha = 1.0 and any multiple of 1/16). Cramer's rule in 128 bits
 * gives the slopes rounded once to Q40.24 (twice, < 1 LSB, for numerators beyond 2^121,
 * which only 65,535 samples at the largest radius reach); the intercept at the centre is
 * rounded once to Q16.16. Those roundings are the only inexactness against double.
 */
#include "rfs_ridge.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_cellsum.h"

/// Largest radius init accepts, metres: keeps every product of the sums in int32/int64.
#define RIDGE_RADIUS_MAX_M 300

rfs_ridge_cfg_t rfs_ridge_cfg_default(void)
{
    rfs_ridge_cfg_t c;
    c.radius = RFS_Q16_INT(5); /* paper section 5.2.1: "a local radius of 5 m" */
    c.alpha = RFS_Q16_ONE;     /* "regularization parameter alpha = 1.0" */
    return c;
}

int rfs_ridge_init(rfs_ridge_t *r, const rfs_ridge_cfg_t *cfg)
{
    if (r == 0 || cfg == 0 || cfg->radius <= 0 || cfg->radius > RFS_Q16_INT(RIDGE_RADIUS_MAX_M) ||
        cfg->alpha < 0) {
        return -1;
    }
    memset(r, 0, sizeof(*r));
    r->cfg = *cfg;
    return 0;
}

static void ridge_reset(void *self)
{
    rfs_ridge_t *r = (rfs_ridge_t *)self;
    RFS_ASSERT(r != 0);
    r->valid = false;
    r->fitting = false;
}

/* Metres Q16.16 to centimetres, rounded to nearest (ties up).
 * Scaling and overflow: |x| * 100 < 2^39 in int64; the result is below 2^22. */
static int32_t q16_to_cm(rfs_q16_t x)
{
    return (int32_t)(((int64_t)x * 100 + 32768) >> 16);
}

/* Centimetres to metres Q16.16, rounded to nearest. |cm| < 2^22, product < 2^38. */
static rfs_q16_t cm_to_q16(int32_t cm)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)cm * 65536, 100));
}

static void acc_start(rfs_ridge_t *r, const rfs_model_fit_in_t *in)
{
    memset(&r->acc, 0, sizeof(r->acc));
    r->acc.qx = in->qx;
    r->acc.qy = in->qy;
    r->acc.qx_cm = q16_to_cm(in->qx);
    r->acc.qy_cm = q16_to_cm(in->qy);
    r->fitting = true;
    r->valid = false;
}

/* The general pass, for a query outside the int16 centimetre box (|q| > 327.67 m): every
 * product is 32 x 32 bits (u, v within the radius <= 30,000 cm, z within 2^15)
 * accumulated into 64 bits (one SMLAL on the Cortex-M4). The box test first keeps
 * u*u + v*v below 2 * 30,000^2 < 2^31. Scaling and overflow: see rfs_ridge_acc_t. */
static void accumulate_wide(rfs_ridge_acc_t *a, const rfs_sample_t *smp, uint32_t from,
                            uint32_t to, int32_t r_cm)
{
    const int32_t qx = a->qx_cm, qy = a->qy_cm;
    const int32_t r2 = r_cm * r_cm;
    const uint32_t box = 2u * (uint32_t)r_cm;
    for (uint32_t i = from; i < to; ++i) {
        int32_t u = (int32_t)smp[i].x_cm - qx;
        int32_t v = (int32_t)smp[i].y_cm - qy;
        if ((uint32_t)(u + r_cm) > box || (uint32_t)(v + r_cm) > box || u * u + v * v > r2) {
            continue;
        }
        int32_t z = smp[i].v_q6;
        a->n++;
        a->su += u;
        a->sv += v;
        a->sz += z;
        a->suu += (int64_t)u * u;
        a->suv += (int64_t)u * v;
        a->svv += (int64_t)v * v;
        a->suz += (int64_t)u * z;
        a->svz += (int64_t)v * z;
    }
}

/// Block sums of the fast pass; each fits int32 by the choice of the block length.
typedef struct ridge_blk {
    int32_t su, sv;   ///< cm
    int32_t szn;      ///< sum of (z + 2^24): the count in the top bits, the sum of z below
    int32_t suu, suv, svv; ///< cm^2
    int32_t suz, svz; ///< cm x Q9.6
} ridge_blk_t;

/// Bias added to each value so the block's count rides in the top bits of its value sum.
#define RIDGE_N_BIAS ((int32_t)1 << 24)
/// Longest block: n * 2^24 + |sum z| < 127 * 2^24 + 127 * 2^15 < 2^31.
#define RIDGE_BLOCK_MAX 127u

/* The hot loop of the common case (query within the int16 centimetre box, so |u|, |v| <=
 * 65,535 and their squares fit uint32): one block of samples with every sum in 32 bits
 * (one MLA or ADD each on the Cortex-M4, few enough accumulators to stay in registers).
 * The radius test uses the squares it needs anyway: their uint32 sum wraps only for far
 * samples (then it is below uu), otherwise it is compared with r2 < 2^31, which also
 * bounds uu and vv for the int32 sums. Scaling and overflow: the caller
 * bounds the block length so that K * r^2 and K * r * 2^15 stay below 2^31. */
__attribute__((noinline)) static void accumulate_block(ridge_blk_t *b, const rfs_sample_t *p,
                                                       const rfs_sample_t *end, int32_t qx,
                                                       int32_t qy, uint32_t r2)
{
    int32_t su = 0, sv = 0, szn = 0, suu = 0, suv = 0, svv = 0, suz = 0, svz = 0;
    for (; p != end; ++p) {
        int32_t u = (int32_t)p->x_cm - qx;
        int32_t v = (int32_t)p->y_cm - qy;
        uint32_t uu = (uint32_t)u * (uint32_t)u, vv = (uint32_t)v * (uint32_t)v;
        uint32_t d2 = uu + vv;
        if (d2 < uu || d2 > r2) { /* wrapped (far away), or outside the radius */
            continue;
        }
        int32_t z = p->v_q6;
        su += u;
        sv += v;
        szn += z + RIDGE_N_BIAS;
        suu += (int32_t)uu;
        suv += u * v;
        svv += (int32_t)vv;
        suz += u * z;
        svz += v * z;
    }
    b->su = su;
    b->sv = sv;
    b->szn = szn;
    b->suu = suu;
    b->suv = suv;
    b->svv = svv;
    b->suz = suz;
    b->svz = svz;
}

/* One pass over samples [from, to) into the running sums. */
static void accumulate(rfs_ridge_acc_t *a, const rfs_sample_t *smp, uint32_t from,
                       uint32_t to, int32_t r_cm)
{
    if (a->qx_cm < -32767 || a->qx_cm > 32767 || a->qy_cm < -32767 || a->qy_cm > 32767) {
        accumulate_wide(a, smp, from, to, r_cm);
        return;
    }
    /* Block length: K r^2 < 2^31 (squares and u v) and K r 2^15 < 2^31 (u z). r <= 30,000
     * gives K >= 2; the paper's 5 m gives K = 127. A radius below half a centimetre rounds
     * to r = 0: only samples exactly at the query count, every product is 0. */
    const uint32_t r = (uint32_t)r_cm;
    uint32_t k = RIDGE_BLOCK_MAX;
    if (r != 0u && k > 0x7FFFFFFFu / (r * r)) {
        k = 0x7FFFFFFFu / (r * r);
    }
    if (r != 0u && k > 0xFFFFu / r) {
        k = 0xFFFFu / r;
    }
    while (from < to) {
        uint32_t len = to - from < k ? to - from : k;
        ridge_blk_t b;
        accumulate_block(&b, smp + from, smp + from + len, a->qx_cm, a->qy_cm, r * r);
        /* |sum z| < 127 * 2^15 < 2^23, so the count is the rounded top byte. */
        int32_t n = (b.szn + ((int32_t)1 << 23)) >> 24;
        a->n = (uint16_t)(a->n + n);
        a->su += b.su;
        a->sv += b.sv;
        a->sz += b.szn - n * RIDGE_N_BIAS;
        a->suu += b.suu;
        a->suv += b.suv;
        a->svv += b.svv;
        a->suz += b.suz;
        a->svz += b.svz;
        from += len;
    }
}

/* 25 * a, exact when |a| < 2^122 (true for every numerator the bounds allow in the
 * default configuration); returns false when it might not fit. */
static bool i128_times25(rfs_i128_t a, rfs_i128_t *out)
{
    if (a.hi >= ((int64_t)1 << 57) || a.hi < -((int64_t)1 << 57)) {
        return false;
    }
    rfs_i128_t a2 = rfs_i128_add(a, a);
    rfs_i128_t a4 = rfs_i128_add(a2, a2);
    rfs_i128_t a8 = rfs_i128_add(a4, a4);
    rfs_i128_t a16 = rfs_i128_add(a8, a8);
    *out = rfs_i128_add(rfs_i128_add(a16, a8), a);
    return true;
}

/* Slope in Q40.24 dB per metre from the Cramer numerator num and determinant det:
 * w = 100 * num / (64 * det) = 25 * num * 2^20 / det. */
static int64_t slope_q24(rfs_i128_t num, rfs_i128_t det)
{
    rfs_i128_t n25;
    if (i128_times25(num, &n25)) {
        return rfs_i128_div_shift(n25, det, 20u);
    }
    /* Numerators near 2^127 (65,535 samples at 300 m): round num * 2^26 / det first,
     * then scale by 25/64; total error < 1 LSB of Q24. */
    int64_t t = rfs_i128_div_shift(num, det, 26u);
    const int64_t lim = INT64_MAX / 25;
    if (t > lim) {
        return INT64_MAX;
    }
    if (t < -lim) {
        return INT64_MIN;
    }
    return rfs_sdiv64_round(t * 25, 64);
}

static rfs_fit_result_t solve(rfs_ridge_t *r)
{
    const rfs_ridge_acc_t *a = &r->acc;
    r->fitting = false;
    r->n_used = a->n;
    if (a->n == 0u) {
        r->valid = false;
        return RFS_FIT_FAILED;
    }
    const int64_t n = a->n;
    /* lam = alpha * 10^4 cm^2, alpha Q16.16: alpha * 10^4 < 2^45. */
    const int64_t lam = ((int64_t)r->cfg.alpha * 10000 + 32768) >> 16;
    /* Scaling and overflow (n <= 65,535, |u| <= 30,000, |z| <= 2^15): n Suu and Su^2
     * < 2^62, the centred products are bounded by Cauchy-Schwarz, so every entry fits
     * int64; Cramer products < 2^125 fit 128 bits. */
    const int64_t m11 = n * a->suu - (int64_t)a->su * a->su + n * lam;
    const int64_t m22 = n * a->svv - (int64_t)a->sv * a->sv + n * lam;
    const int64_t m12 = n * a->suv - (int64_t)a->su * a->sv;
    const int64_t bu = n * a->suz - (int64_t)a->su * a->sz;
    const int64_t bv = n * a->svz - (int64_t)a->sv * a->sz;
    rfs_i128_t det = rfs_i128_sub(rfs_i128_mul(m11, m22), rfs_i128_mul(m12, m12));
    int64_t wx = 0, wy = 0;
    if (det.hi != 0 || det.lo != 0u) {
        rfs_i128_t nx = rfs_i128_sub(rfs_i128_mul(m22, bu), rfs_i128_mul(m12, bv));
        rfs_i128_t ny = rfs_i128_sub(rfs_i128_mul(m11, bv), rfs_i128_mul(m12, bu));
        wx = slope_q24(nx, det);
        wy = slope_q24(ny, det);
    }
    /* det == 0 only with alpha = 0 and degenerate positions: slopes stay 0 (a flat
     * model at the mean) where scikit-learn would return a minimum-norm solution. */
    r->wx_q24 = wx;
    r->wy_q24 = wy;
    /* Intercept at the centre: mean(z) - w . mean(u, v), in Q16.16:
     *   (100 * Sz * 2^18 - (wx Su + wy Sv)) / (100 * 2^8 * n)
     * Sz * 2^18 * 100 < 2^57; w * S < 2^94 in 128 bits. */
    rfs_i128_t num = rfs_i128_mul((int64_t)a->sz * 100, (int64_t)1 << 18);
    num = rfs_i128_sub(num, rfs_i128_mul(wx, a->su));
    num = rfs_i128_sub(num, rfs_i128_mul(wy, a->sv));
    rfs_i128_t den = rfs_i128_mul(25600, n);
    r->icpt = rfs_sat32(rfs_i128_div_shift(num, den, 0u));
    r->qx = cm_to_q16(a->qx_cm);
    r->qy = cm_to_q16(a->qy_cm);
    const int32_t lim = (int32_t)1 << 30;
    r->fast_predict = wx >= INT32_MIN && wx <= INT32_MAX && wy >= INT32_MIN && wy <= INT32_MAX &&
                      r->qx >= -lim && r->qx < lim && r->qy >= -lim && r->qy < lim;
    r->valid = true;
    return RFS_FIT_DONE;
}

static rfs_fit_result_t ridge_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                  rfs_rng_t *rng)
{
    rfs_ridge_t *r = (rfs_ridge_t *)self;
    (void)rng;
    RFS_ASSERT(r != 0 && in != 0 && (in->samples != 0 || in->n == 0u));
    /* A new query point, or a store that shrank under a sliced fit, restarts it. */
    if (!r->fitting || r->acc.qx != in->qx || r->acc.qy != in->qy || r->acc.next > in->n) {
        acc_start(r, in);
    }
    uint32_t from = r->acc.next;
    uint32_t to = in->n;
    if (in->index != 0 && budget == 0u && from == 0u) {
        /* Cell sums: the same integers as the pass below (docs/MODELS.md, "Cell sums"). */
        rfs_cellsum_disc_t d;
        in->index->disc(in->index->self, in->samples, r->acc.qx_cm, r->acc.qy_cm,
                        q16_to_cm(r->cfg.radius), &d);
        r->acc.n = (uint16_t)d.n;
        r->acc.su = (int32_t)d.su;
        r->acc.sv = (int32_t)d.sv;
        r->acc.sz = (int32_t)d.sz;
        r->acc.suu = d.suu;
        r->acc.suv = d.suv;
        r->acc.svv = d.svv;
        r->acc.suz = d.suz;
        r->acc.svz = d.svz;
        r->acc.next = in->n;
        return solve(r);
    }
    if (budget != 0u && to - from > budget) {
        to = from + budget;
    }
    accumulate(&r->acc, in->samples, from, to, q16_to_cm(r->cfg.radius));
    r->acc.next = (uint16_t)to;
    if (to < in->n) {
        return RFS_FIT_MORE;
    }
    return solve(r);
}

/* The prediction in 128 bits, for steep models far from their centre; kept out of line
 * so the common path stays a leaf with few registers. */
__attribute__((noinline)) static bool predict_wide(const rfs_ridge_t *r, int64_t dx, int64_t dy,
                                                   rfs_q16_t *value)
{
    rfs_i128_t acc = rfs_i128_add(rfs_i128_mul(r->wx_q24, dx), rfs_i128_mul(r->wy_q24, dy));
    acc = rfs_i128_add(acc, rfs_i128_mul(r->icpt, (int64_t)1 << 24));
    rfs_i128_t one = {(uint64_t)1 << 24, 0};
    *value = rfs_sat32(rfs_i128_div_shift(acc, one, 0u));
    return true;
}

/* Prediction: icpt + wx (x - qx) + wy (y - qy), Q16.16, saturated. The grid search calls
 * this at every lattice point, so the common case is a short leaf: no assert (the
 * pointers were checked when the model was made), no 64-bit difference.
 * Scaling and overflow: fast path when the slopes fit int32 and x, y and the centre lie
 * within +-16,384 m (|Q16| < 2^30), so x - qx fits int32: two 32 x 32 products (Q40 each,
 * < 2^62) summed in int64 (< 2^63), rounded >> 24 to Q16, plus the intercept, saturated.
 * Otherwise the same sum in 128 bits. */
static bool ridge_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const rfs_ridge_t *r = (const rfs_ridge_t *)self;
    if (!r->valid) {
        return false;
    }
    const uint32_t lim = (uint32_t)1 << 30;
    if (r->fast_predict && (uint32_t)x + lim < 2u * lim && (uint32_t)y + lim < 2u * lim) {
        int32_t dx = x - r->qx, dy = y - r->qy;
        int64_t acc = (int64_t)(int32_t)r->wx_q24 * dx + (int64_t)(int32_t)r->wy_q24 * dy;
        *value = rfs_sat32((int64_t)r->icpt + ((acc + ((int64_t)1 << 23)) >> 24));
        return true;
    }
    return predict_wide(r, (int64_t)x - r->qx, (int64_t)y - r->qy, value);
}

/* A row of predictions (x0 + k dx, y), k = 0..n-1, for the grid search: the same values
 * as ridge_predict() point by point, with the x term advanced by one exact 64-bit
 * addition per point. Scaling and overflow: when both ends of the row (and y) are inside
 * the fast path's +-16,384 m, every x in between is too, so each running sum equals the
 * fast path's exact sum (< 2^63); otherwise every point goes through ridge_predict(). */
static bool ridge_predict_row(const void *self, rfs_q16_t x0, rfs_q16_t y, rfs_q16_t dx,
                              uint16_t n, rfs_q16_t *out)
{
    const rfs_ridge_t *r = (const rfs_ridge_t *)self;
    if (!r->valid) {
        return false;
    }
    if (n == 0u) {
        return true;
    }
    const int64_t lim = (int64_t)1 << 30;
    const int64_t xl = (int64_t)x0 + (int64_t)(n - 1u) * dx;
    if (!r->fast_predict || x0 < -lim || x0 >= lim || xl < -lim || xl >= lim || y < -lim ||
        y >= lim) {
        for (uint16_t k = 0u; k < n; ++k) {
            (void)ridge_predict(r, (rfs_q16_t)(x0 + (int64_t)k * dx), y, &out[k]);
        }
        return true;
    }
    const int32_t wx = (int32_t)r->wx_q24, wy = (int32_t)r->wy_q24;
    int64_t acc = (int64_t)wx * (x0 - r->qx) + (int64_t)wy * (y - r->qy) + ((int64_t)1 << 23);
    const int64_t step = (int64_t)wx * dx;
    /* The row is linear, so when neither end saturates no point does: then the loop
     * is one 64-bit addition, a shift and an addition per point. */
    const int64_t v0 = (int64_t)r->icpt + (acc >> 24);
    const int64_t vl = (int64_t)r->icpt + ((acc + step * (int64_t)(n - 1u)) >> 24);
    if (v0 >= INT32_MIN && v0 <= INT32_MAX && vl >= INT32_MIN && vl <= INT32_MAX) {
        const int64_t icpt = r->icpt;
        out[0] = (rfs_q16_t)v0;
        for (uint16_t k = 1u; k < n; ++k) { /* never steps past the last point */
            acc += step;
            out[k] = (rfs_q16_t)(icpt + (acc >> 24)); /* between v0 and vl: fits */
        }
        return true;
    }
    out[0] = rfs_sat32(v0);
    for (uint16_t k = 1u; k < n; ++k) {
        acc += step;
        out[k] = rfs_sat32((int64_t)r->icpt + (acc >> 24));
    }
    return true;
}

/* A plane's predictions along a row never decrease towards the sign of its x slope: one
 * rounding of an affine function of x, then saturation, both monotone. */
static int ridge_row_monotone(const void *self)
{
    const rfs_ridge_t *r = (const rfs_ridge_t *)self;
    return r->wx_q24 > 0 ? 1 : (r->wx_q24 < 0 ? -1 : 0);
}

const rfs_model_ops_t rfs_ridge_ops = {
    .name = "ridge",
    .reset = ridge_reset,
    .fit = ridge_fit,
    .predict = ridge_predict,
    .argmax = 0,
    .predict_row = ridge_predict_row,
    .row_monotone = ridge_row_monotone,
};

rfs_model_t rfs_ridge_model(rfs_ridge_t *r)
{
    rfs_model_t m;
    m.ops = &rfs_ridge_ops;
    m.self = r;
    return m;
}
