/* rfs_pathloss_cv.c - the path-loss fit's spatially blocked cross-validation (see
 * rfs_pathloss.h, cfg cv_block; docs/PATHLOSS.md, "Fit", step 3).
 *
 * Neighbouring bins share their shadowing (4-8 dB, correlated over about 5 m), so the
 * in-sample loss of a candidate rewards fits that bend to one stretch of data. With
 * cv_block the bins are grouped into squares of that side; each square's bins are scored
 * under the (P0, n, W) fitted, with the same priors and bounds, to every other square's
 * bins. The fit to all the bins stays the candidate's model (and its P0 term). Each
 * held-out fit is the closed-form solve of rfs_pathloss.c on the complement's sums (all
 * the bins' sums less the square's), centred on the complement's means: one pass over
 * the bins for the sums, one per square for its own sums and residuals, no more wall
 * counts.
 */
#include <string.h>

#include "rfs_assert.h"
#include "rfs_pathloss_internal.h"

/* cv_order: the first bin of a block. */
#define CV_FIRST 0x8000u

_Static_assert(RFS_PATHLOSS_MAX_BINS <= CV_FIRST, "bin indices below cv_order's marker");

/* floor(a / b) for b > 0. */
static int32_t cv_floor_div(int32_t a, int32_t b)
{
    int32_t q = a / b;
    return (a % b != 0 && a < 0) ? q - 1 : q;
}

/* Sift bin order[i] down the max-heap of order[0..n) by key. */
static void sift(uint16_t *order, const uint32_t *key, uint32_t i, uint32_t n)
{
    for (;;) {
        uint32_t c = 2u * i + 1u;
        if (c >= n) {
            return;
        }
        if (c + 1u < n && key[order[c + 1u]] > key[order[c]]) {
            c++;
        }
        if (key[order[i]] >= key[order[c]]) {
            return;
        }
        uint16_t t = order[i];
        order[i] = order[c];
        order[c] = t;
        i = c;
    }
}

void rfs_pathloss_cv_order(rfs_pathloss_t *p)
{
    p->cv_blocks = 0u;
    if (p->cfg.cv_block <= 0) {
        return;
    }
    /* Keys in the l_q16 scratch (each candidate overwrites it): the square's row, then
     * column, each offset into 16 bits (centroids are within +-327.67 m, squares >= 1 m). */
    const int32_t side_cm = (int32_t)(((int64_t)p->cfg.cv_block * 100 + 32768) >> 16);
    uint32_t *key = (uint32_t *)p->l_q16;
    const uint32_t n = p->nbins;
    for (uint32_t b = 0u; b < n; ++b) {
        uint32_t kx = (uint32_t)(cv_floor_div(p->bins[b].sx_cm, side_cm) + 32768);
        uint32_t ky = (uint32_t)(cv_floor_div(p->bins[b].sy_cm, side_cm) + 32768);
        key[b] = (ky << 16) | (kx & 0xFFFFu);
        p->cv_order[b] = (uint16_t)b;
    }
    for (uint32_t i = n / 2u; i-- > 0u;) {
        sift(p->cv_order, key, i, n);
    }
    for (uint32_t m = n; m > 1u; --m) {
        uint16_t t = p->cv_order[0];
        p->cv_order[0] = p->cv_order[m - 1u];
        p->cv_order[m - 1u] = t;
        sift(p->cv_order, key, 0u, m - 1u);
    }
    /* The first bin of each block is marked in cv_order's top bit (bins < 2^15). */
    uint32_t blocks = 0u;
    for (uint32_t i = n; i-- > 0u;) {
        if (i == 0u || key[p->cv_order[i]] != key[p->cv_order[i - 1u]]) {
            p->cv_order[i] |= CV_FIRST; /* read no more: the bins before it are unmarked */
            blocks++;
        }
    }
    p->cv_blocks = (uint16_t)blocks;
}

/* Weighted sums of a set of bins, the values centred on the fit's means and rounded to Q8
 * as rfs_pathloss.c's solve does: count, c l, c k, c z (Q8), c l^2, c l k, c k^2, c l z,
 * c k z (Q16). */
enum { S_C = 0, S_L, S_K, S_Z, S_LL, S_LK, S_KK, S_LZ, S_KZ, S_N };

/* Add bin b to s. Scaling (see solve): l < 2^15, k < 2^16, c z < 2^34 in Q8; the sums
 * of up to 2^16 weight stay below 2^50. */
static void cv_add(const rfs_pathloss_t *p, uint32_t b, int32_t ml, int32_t mk, int64_t s[S_N])
{
    const rfs_pathloss_bin_t *bb = &p->bins[b];
    int64_t cnt = bb->count;
    int64_t l8 = ((int64_t)p->l_q16[b] - ml + 128) >> 8;
    int64_t k8 = ((int64_t)p->k[b] * 16384 - mk + 128) >> 8;
    int64_t e8 = (cnt * bb->dz_q16 + 128) >> 8;
    s[S_C] += cnt;
    s[S_L] += cnt * l8;
    s[S_K] += cnt * k8;
    s[S_Z] += e8;
    s[S_LL] += cnt * l8 * l8;
    s[S_LK] += cnt * l8 * k8;
    s[S_KK] += cnt * k8 * k8;
    s[S_LZ] += l8 * e8;
    s[S_KZ] += k8 * e8;
}

/* The fit to the bins whose sums are s (weight > 0): (n, w) Q16 and the intercept a, the
 * fitted value at the fit's means less the mean of every bin (target units Q16).
 * Scaling: the means m (Q8) are below 2^15 (l), 2^16 (k) and 2^18 (z); re-centring a
 * sum, m times a first sum < 2^34 and c m m' < 2^16 x 2^34 stay below 2^51 in int64; n, w
 * < 2^23 times m < 2^18 below 2^41. */
static void cv_fit(const rfs_pathloss_cfg_t *c, const int64_t s[S_N], int32_t *n, int32_t *w,
                   int64_t *a)
{
    const int64_t cnt = s[S_C];
    const int64_t ml = rfs_sdiv64_round(s[S_L], cnt);
    const int64_t mk = rfs_sdiv64_round(s[S_K], cnt);
    const int64_t mz = rfs_sdiv64_round(s[S_Z], cnt);
    /* sum c (u - mu)(v - mv) = S_uv - mu S_v - mv S_u + c mu mv */
    const int64_t all = s[S_LL] - 2 * ml * s[S_L] + cnt * ml * ml;
    const int64_t alk = s[S_LK] - ml * s[S_K] - mk * s[S_L] + cnt * ml * mk;
    const int64_t akk = s[S_KK] - 2 * mk * s[S_K] + cnt * mk * mk;
    const int64_t bl = s[S_LZ] - ml * s[S_Z] - mz * s[S_L] + cnt * ml * mz;
    const int64_t bk = s[S_KZ] - mk * s[S_Z] - mz * s[S_K] + cnt * mk * mz;
    const int64_t lam = c->prior_weight, lamw = c->w_prior_weight;
    const int64_t M[3] = {all + lam, alk, akk + lamw};
    const int64_t R[2] = {-bl + ((lam * c->n_prior + 32768) >> 16),
                          -bk + ((lamw * c->w_prior + 32768) >> 16)};
    rfs_pathloss_solve_nw(c, M, R, n, w);
    /* z - mz = a' - n l - W k through the means: a' = mz + n ml + W mk (Q8 -> Q16). */
    *a = mz * 256 + (((int64_t)*n * ml + (int64_t)*w * mk + 128) >> 8);
}

/* Scaling and overflow: see cv_add and cv_fit; residuals saturate at 2^24 (Q8) in the
 * Huber value, so the loss is below 2^16 weight x 2^39, as the fit's. */
int64_t rfs_pathloss_cv_loss(const rfs_pathloss_t *p, int32_t ml, int32_t mk, int32_t n,
                             int32_t w)
{
    const rfs_pathloss_cfg_t *c = &p->cfg;
    const int64_t d8 = ((int64_t)c->huber + 128) >> 8;
    int64_t all[S_N];
    memset(all, 0, sizeof(all));
    for (uint32_t b = 0u; b < p->nbins; ++b) {
        cv_add(p, b, ml, mk, all);
    }
    int64_t loss = 0;
    uint32_t i = 0u;
    while (i < p->nbins) {
        /* The block: bins cv_order[i..j). */
        uint32_t j = i;
        int64_t blk[S_N];
        memset(blk, 0, sizeof(blk));
        do {
            cv_add(p, p->cv_order[j] & ~CV_FIRST, ml, mk, blk);
            j++;
        } while (j < p->nbins && (p->cv_order[j] & CV_FIRST) == 0u);
        /* A block holding every bin's weight is scored under the fit to all of them. */
        int32_t bn = n, bw = w;
        int64_t a = 0;
        if (blk[S_C] < all[S_C]) {
            int64_t rest[S_N];
            for (uint32_t s = 0u; s < S_N; ++s) {
                rest[s] = all[s] - blk[s];
            }
            cv_fit(c, rest, &bn, &bw, &a);
        }
        for (; i < j; ++i) {
            const uint32_t b = p->cv_order[i] & ~CV_FIRST;
            loss += (int64_t)p->bins[b].count *
                    rfs_pathloss_huber(rfs_pathloss_residual(p, b, ml, mk, a, bn, bw), d8);
        }
    }
    return loss;
}
