/* ref_pathloss.h - a double-precision reference of the path-loss model's search
 * (common/rfs_pathloss.h), for tests/common/test_pathloss*.c.
 *
 * The same definition computed another way: bins found by a linear search, centroids
 * rounded to the centimetre as the definition says (the store's unit), distances and
 * logarithms in double, the constrained least squares by direct minimisation of the sum
 * of squared residuals over the interior solution, the four edges and the four corners
 * of the (n, W) box, the Huber loss in double, and a bitmap of evaluated points. Only
 * the wall counts come from the core (rfs_map_walls_crossed and rfs_map_cell, tested in
 * test_map_walls.c), because they are the model's definition of a wall: a bin's walls are the
 * mean of the counts (each saturated at 15) from the four points `footprint` either side
 * of the centre of the core cell holding its centroid, along x and y, a point that is not
 * legal (rfs_map_point_legal) counting from the centre. The coarse points count with
 * `coarse_footprint` instead; when that differs from `footprint` (and there is a map) they
 * only choose the top points, all of which the refinement evaluates afresh. A candidate
 * within excl_r of a place ruled out is not legal. No cache.
 */
#ifndef REF_PATHLOSS_H
#define REF_PATHLOSS_H

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_map.h"
#include "rfs_store.h"

#define REF_PL_MAX_BINS 512
#define REF_PL_MAX_COARSE 1024

typedef struct ref_pl_cfg {
    double bin, coarse;
    int top;
    double n_min, n_max, w_min, w_max, n_prior, w_prior, prior_weight, huber, margin;
    long bin_cap;
    double w_prior_weight;
    double p0_min; /* weakest plausible P0; a fit below adds total x Huber(p0_min - P0) */
    double footprint; /* m: offsets of a bin's wall-count points from its cell's centre */
    int nexcl;        /* places ruled out: no candidate within excl_r of (ex[e], ey[e]) */
    double ex[8], ey[8], excl_r;
    double p0_max; /* strongest plausible P0; a fit above adds total x Huber(P0 - p0_max) */
    double coarse_footprint; /* m: the footprint of the coarse points' counts */
    double p0_max_wall; /* dB: the most a wall costs in the P0 held against p0_max (inf: W) */
    bool coarse_snap; /* a coarse grid point off the legal map stands for its cell's nearest
                         legal lattice point */
} ref_pl_cfg_t;

typedef struct ref_pl_bin {
    long kx, ky;
    double sx, sy, sv; /* sums, then centroid (m) and mean (dB) */
    double x, y, z;
    long count;
} ref_pl_bin_t;

typedef struct ref_pl {
    /* inputs */
    ref_pl_cfg_t cfg;
    const rfs_map_t *map;
    /* bins */
    ref_pl_bin_t bins[REF_PL_MAX_BINS];
    int nbins;
    double bin_m;
    long total;
    /* lattice */
    double ox, oy, grid;
    int lw, lh, cs, c0i, c0j, ncx, ncy;
    /* result */
    double sx, sy, p0, n, w, loss;
    int li, lj;
    double surface[REF_PL_MAX_COARSE]; /* sqrt(2 mean loss), dB; NAN: no candidate */
    int pi[REF_PL_MAX_COARSE], pj[REF_PL_MAX_COARSE]; /* each coarse point's lattice point */
    int candidates;
    unsigned char *seen; /* lattice points evaluated */
    double fp;           /* m: the footprint of the counts being made */
    double L[REF_PL_MAX_BINS];
    double K[REF_PL_MAX_BINS];
} ref_pl_t;

static inline ref_pl_cfg_t ref_pl_cfg_default(void)
{
    ref_pl_cfg_t c = {1.0, 2.0, 3, 1.5, 5.0, 0.0, 15.0, 3.0, 5.0, 3000.0, 6.0, 20.0, 5, 30.0, -45.0,
                      0.25, 0, {0}, {0}, 0.0, -10.0, 0.25, INFINITY, true};
    return c;
}

static inline void ref_pl_bin_samples(ref_pl_t *r, const rfs_sample_t *s, int n)
{
    long bin_cm = lround(r->cfg.bin * 100.0);
    for (;;) {
        bool ok = true;
        r->nbins = 0;
        for (int i = 0; i < n && ok; ++i) {
            long kx = (long)floor((double)s[i].x_cm / (double)bin_cm);
            long ky = (long)floor((double)s[i].y_cm / (double)bin_cm);
            int b = 0;
            while (b < r->nbins && (r->bins[b].kx != kx || r->bins[b].ky != ky)) {
                ++b;
            }
            if (b == r->nbins) {
                if (r->nbins == REF_PL_MAX_BINS) {
                    ok = false;
                    break;
                }
                memset(&r->bins[b], 0, sizeof(r->bins[b]));
                r->bins[b].kx = kx;
                r->bins[b].ky = ky;
                r->nbins++;
            }
            r->bins[b].sx += s[i].x_cm / 100.0;
            r->bins[b].sy += s[i].y_cm / 100.0;
            r->bins[b].sv += s[i].v_q6 / 64.0;
            r->bins[b].count++;
        }
        if (ok) {
            break;
        }
        bin_cm *= 2;
    }
    r->bin_m = bin_cm / 100.0;
    r->total = 0;
    for (int b = 0; b < r->nbins; ++b) {
        ref_pl_bin_t *bb = &r->bins[b];
        bb->x = round(bb->sx * 100.0 / bb->count) / 100.0;
        bb->y = round(bb->sy * 100.0 / bb->count) / 100.0;
        bb->z = bb->sv / bb->count;
        /* from here on, count is the bin's weight */
        bb->count = bb->count < r->cfg.bin_cap ? bb->count : r->cfg.bin_cap;
        r->total += bb->count;
    }
}

static inline void ref_pl_lattice(ref_pl_t *r)
{
    if (r->map != NULL) {
        r->grid = r->map->cfg.grid / 65536.0;
        r->ox = r->map->origin_x / 65536.0 + r->grid / 2;
        r->oy = r->map->origin_y / 65536.0 + r->grid / 2;
        r->lw = r->map->lw;
        r->lh = r->map->lh;
    } else {
        double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
        for (int b = 0; b < r->nbins; ++b) {
            x0 = fmin(x0, r->bins[b].x);
            y0 = fmin(y0, r->bins[b].y);
            x1 = fmax(x1, r->bins[b].x);
            y1 = fmax(y1, r->bins[b].y);
        }
        r->grid = 0.25;
        r->ox = x0 - r->cfg.margin;
        r->oy = y0 - r->cfg.margin;
        r->lw = (int)floor((x1 - x0 + 2 * r->cfg.margin) / r->grid) + 1;
        r->lh = (int)floor((y1 - y0 + 2 * r->cfg.margin) / r->grid) + 1;
    }
    int cs = (int)lround(r->cfg.coarse / r->grid);
    cs = cs < 1 ? 1 : cs;
    for (;;) {
        r->ncx = (r->lw - 1) / cs + 1;
        r->ncy = (r->lh - 1) / cs + 1;
        if (r->ncx * r->ncy <= REF_PL_MAX_COARSE) {
            break;
        }
        cs++;
    }
    r->cs = cs;
    r->c0i = (r->lw - 1 - (r->ncx - 1) * cs) / 2;
    r->c0j = (r->lh - 1 - (r->ncy - 1) * cs) / 2;
}

static inline bool ref_pl_legal(const ref_pl_t *r, int i, int j)
{
    if (i < 0 || j < 0 || i >= r->lw || j >= r->lh) {
        return false;
    }
    for (int e = 0; e < r->cfg.nexcl; ++e) {
        if (hypot(r->ox + i * r->grid - r->cfg.ex[e], r->oy + j * r->grid - r->cfg.ey[e]) <=
            r->cfg.excl_r) {
            return false;
        }
    }
    return r->map == NULL || rfs_map_lattice_legal(r->map, (uint16_t)i, (uint16_t)j);
}

/* Coarse point c's lattice point: its grid point when that is legal on the map; else,
 * with coarse_snap, the map-legal lattice point nearest it in its cell (offsets -(cs - 1) /
 * 2 .. cs / 2 either way, at most 7; the first in row order among the nearest); false
 * when there is none. Places ruled out are tested after (ref_pl_try). */
static inline bool ref_pl_snap(const ref_pl_t *r, int c, int *pi, int *pj)
{
    const rfs_map_t *m = r->map;
    int i0 = r->c0i + (c % r->ncx) * r->cs, j0 = r->c0j + (c / r->ncx) * r->cs;
    *pi = i0;
    *pj = j0;
#define REF_PL_ON_MAP(i, j) ((i) >= 0 && (j) >= 0 && (i) < r->lw && (j) < r->lh && \
                             (m == NULL || rfs_map_lattice_legal(m, (uint16_t)(i), (uint16_t)(j))))
    if (REF_PL_ON_MAP(i0, j0)) {
        return true;
    }
    if (!r->cfg.coarse_snap) {
        return false;
    }
    int lo = (r->cs - 1) / 2 > 7 ? 7 : (r->cs - 1) / 2, hi = r->cs / 2 > 7 ? 7 : r->cs / 2;
    double best = INFINITY;
    for (int dj = -lo; dj <= hi; ++dj) {
        for (int di = -lo; di <= hi; ++di) {
            double d = hypot(di, dj);
            if (d < best && REF_PL_ON_MAP(i0 + di, j0 + dj)) {
                best = d;
                *pi = i0 + di;
                *pj = j0 + dj;
            }
        }
    }
#undef REF_PL_ON_MAP
    return !isinf(best);
}

/* Sum of count-weighted squared residuals plus the prior, at (n, w), P0 optimal. */
static inline double ref_pl_sse(const ref_pl_t *r, double n, double w, double *p0)
{
    double sc = 0, sr = 0;
    for (int b = 0; b < r->nbins; ++b) {
        sc += r->bins[b].count;
        sr += r->bins[b].count * (r->bins[b].z + n * r->L[b] + w * r->K[b]);
    }
    double P0 = sr / sc;
    double e = 0;
    for (int b = 0; b < r->nbins; ++b) {
        double d = r->bins[b].z - (P0 - n * r->L[b] - w * r->K[b]);
        e += r->bins[b].count * d * d;
    }
    e += r->cfg.prior_weight * (n - r->cfg.n_prior) * (n - r->cfg.n_prior) +
         r->cfg.w_prior_weight * (w - r->cfg.w_prior) * (w - r->cfg.w_prior);
    *p0 = P0;
    return e;
}

static inline double ref_pl_clamp(double v, double lo, double hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* Fit and Huber loss of candidate (i, j). */
static inline double ref_pl_eval(ref_pl_t *r, int i, int j, double *pn, double *pw, double *pp0)
{
    double sx = r->ox + i * r->grid, sy = r->oy + j * r->grid;
    rfs_q16_t qx = (rfs_q16_t)lround(sx * 65536.0), qy = (rfs_q16_t)lround(sy * 65536.0);
    for (int b = 0; b < r->nbins; ++b) {
        double d = hypot(r->bins[b].x - sx, r->bins[b].y - sy);
        r->L[b] = 10.0 * log10(d < 1.0 ? 1.0 : d);
        double k = 0.0;
        if (r->map != NULL) {
            rfs_q16_t bx = (rfs_q16_t)lround(r->bins[b].x * 65536.0);
            rfs_q16_t by = (rfs_q16_t)lround(r->bins[b].y * 65536.0);
            uint16_t cx, cy;
            if (rfs_map_cell(r->map, bx, by, &cx, &cy)) {
                double res = r->map->res / 65536.0;
                bx = (rfs_q16_t)lround((r->map->origin_x / 65536.0 + (cx + 0.5) * res) * 65536.0);
                by = (rfs_q16_t)lround((r->map->origin_y / 65536.0 + (cy + 0.5) * res) * 65536.0);
            }
            int c0 = rfs_map_walls_crossed(r->map, bx, by, qx, qy);
            c0 = c0 > 15 ? 15 : c0;
            rfs_q16_t f = (rfs_q16_t)lround(r->fp * 65536.0);
            for (int q = 0; q < 4; ++q) {
                rfs_q16_t px = bx + ((q & 1) ? f : -f), py = by + ((q & 2) ? f : -f);
                int c = c0;
                if (f != 0 && rfs_map_point_legal(r->map, px, py)) {
                    c = rfs_map_walls_crossed(r->map, px, py, qx, qy);
                    c = c > 15 ? 15 : c;
                }
                k += c / 4.0;
            }
        }
        r->K[b] = k;
    }
    /* Normal equations of the centred problem with the prior, solved directly. */
    double sc = 0, ml = 0, mk = 0, mz = 0;
    for (int b = 0; b < r->nbins; ++b) {
        double c = r->bins[b].count;
        sc += c;
        ml += c * r->L[b];
        mk += c * r->K[b];
        mz += c * r->bins[b].z;
    }
    ml /= sc;
    mk /= sc;
    mz /= sc;
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    for (int b = 0; b < r->nbins; ++b) {
        double c = r->bins[b].count, l = r->L[b] - ml, k = r->K[b] - mk, z = r->bins[b].z - mz;
        a11 += c * l * l;
        a12 += c * l * k;
        a22 += c * k * k;
        b1 -= c * l * z;
        b2 -= c * k * z;
    }
    const ref_pl_cfg_t *cf = &r->cfg;
    a11 += cf->prior_weight;
    a22 += cf->w_prior_weight;
    b1 += cf->prior_weight * cf->n_prior;
    b2 += cf->w_prior_weight * cf->w_prior;
    double det = a11 * a22 - a12 * a12;
    double n = (b1 * a22 - a12 * b2) / det, w = (a11 * b2 - a12 * b1) / det;
    if (!(n >= cf->n_min && n <= cf->n_max && w >= cf->w_min && w <= cf->w_max)) {
        /* Edges and corners; the least SSE wins. */
        double cn[8], cw[8];
        cn[0] = cf->n_min;
        cw[0] = ref_pl_clamp((b2 - a12 * cn[0]) / a22, cf->w_min, cf->w_max);
        cn[1] = cf->n_max;
        cw[1] = ref_pl_clamp((b2 - a12 * cn[1]) / a22, cf->w_min, cf->w_max);
        cw[2] = cf->w_min;
        cn[2] = ref_pl_clamp((b1 - a12 * cw[2]) / a11, cf->n_min, cf->n_max);
        cw[3] = cf->w_max;
        cn[3] = ref_pl_clamp((b1 - a12 * cw[3]) / a11, cf->n_min, cf->n_max);
        cn[4] = cf->n_min; cw[4] = cf->w_min;
        cn[5] = cf->n_min; cw[5] = cf->w_max;
        cn[6] = cf->n_max; cw[6] = cf->w_min;
        cn[7] = cf->n_max; cw[7] = cf->w_max;
        double best = INFINITY, p0;
        for (int e = 0; e < 8; ++e) {
            double s = ref_pl_sse(r, cn[e], cw[e], &p0);
            if (s < best) {
                best = s;
                n = cn[e];
                w = cw[e];
            }
        }
    }
    double p0 = mz + n * ml + w * mk;
    double loss = 0;
    for (int b = 0; b < r->nbins; ++b) {
        double res = fabs(r->bins[b].z - (p0 - n * r->L[b] - w * r->K[b]));
        double h = res <= cf->huber ? 0.5 * res * res : cf->huber * (res - 0.5 * cf->huber);
        loss += r->bins[b].count * h;
    }
    /* The ceiling holds the P0 with each wall at p0_max_wall at most against p0_max. */
    double p0c = p0 - fmax(w - cf->p0_max_wall, 0.0) * mk;
    double a = p0 < cf->p0_min ? cf->p0_min - p0 : p0c > cf->p0_max ? p0c - cf->p0_max : 0.0;
    loss += (double)r->total * (a <= cf->huber ? 0.5 * a * a : cf->huber * (a - 0.5 * cf->huber));
    *pn = n;
    *pw = w;
    *pp0 = p0;
    r->candidates++;
    r->seen[(size_t)j * r->lw + i] = 1;
    return loss;
}

/* Evaluate (i, j) unless it was evaluated or is not legal; keep the best (strictly less). */
static inline double ref_pl_try(ref_pl_t *r, int i, int j)
{
    if (!ref_pl_legal(r, i, j) || r->seen[(size_t)j * r->lw + i]) {
        return INFINITY;
    }
    double n, w, p0;
    double loss = ref_pl_eval(r, i, j, &n, &w, &p0);
    if (loss < r->loss) {
        r->loss = loss;
        r->n = n;
        r->w = w;
        r->p0 = p0;
        r->li = i;
        r->lj = j;
        r->sx = r->ox + i * r->grid;
        r->sy = r->oy + j * r->grid;
    }
    return loss;
}

/* The whole search; false when there are no samples or no legal candidate. */
static inline bool ref_pl_fit(ref_pl_t *r, const rfs_sample_t *s, int n, const rfs_map_t *map,
                              const ref_pl_cfg_t *cfg)
{
    memset(r, 0, sizeof(*r));
    r->cfg = *cfg;
    r->map = map;
    r->loss = INFINITY;
    if (n <= 0) {
        return false;
    }
    ref_pl_bin_samples(r, s, n);
    ref_pl_lattice(r);
    r->seen = calloc((size_t)r->lw * r->lh, 1);
    r->fp = cfg->coarse_footprint;
    int ti[8], tj[8];
    double tl[8];
    int nt = 0;
    for (int c = 0; c < r->ncx * r->ncy; ++c) {
        int i, j;
        bool some = ref_pl_snap(r, c, &i, &j);
        r->pi[c] = i;
        r->pj[c] = j;
        double loss = some ? ref_pl_try(r, i, j) : INFINITY;
        r->surface[c] = isinf(loss) ? NAN : sqrt(2.0 * loss / (double)r->total);
        if (isinf(loss)) {
            continue;
        }
        /* insertion into the top list, ties keep the earlier */
        int k = nt < cfg->top ? nt : cfg->top - 1;
        if (nt == cfg->top && loss >= tl[k]) {
            continue;
        }
        while (k > 0 && loss < tl[k - 1]) {
            tl[k] = tl[k - 1];
            ti[k] = ti[k - 1];
            tj[k] = tj[k - 1];
            k--;
        }
        tl[k] = loss;
        ti[k] = i;
        tj[k] = j;
        nt = nt < cfg->top ? nt + 1 : nt;
    }
    if (nt == 0) {
        free(r->seen);
        return false;
    }
    /* 8 neighbours of each top candidate at half the coarse spacing, then of the best so
     * far at half the spacing again, down to one lattice step */
    int h = r->cs / 2 < 1 ? 1 : r->cs / 2;
    if (map != NULL && cfg->coarse_footprint != cfg->footprint) {
        /* The coarse losses only ranked: start afresh (the top points included). */
        memset(r->seen, 0, (size_t)r->lw * r->lh);
        r->loss = INFINITY;
    }
    r->fp = cfg->footprint;
    for (int k = 0; k < nt; ++k) {
        for (int b = -1; b <= 1; ++b) {
            for (int a = -1; a <= 1; ++a) {
                ref_pl_try(r, ti[k] + a * h, tj[k] + b * h);
            }
        }
    }
    while (h > 1) {
        h /= 2;
        int ci = r->li, cj = r->lj;
        for (int b = -1; b <= 1; ++b) {
            for (int a = -1; a <= 1; ++a) {
                ref_pl_try(r, ci + a * h, cj + b * h);
            }
        }
    }
    free(r->seen);
    r->seen = NULL;
    return true;
}

/* The hold search after ref_pl_fit: from lattice point (i, j), a 3 x 3 hill-climb at
 * half the coarse spacing, halved down to one step (the centre first, then row by row;
 * ties keep the earlier). Returns the least loss found and its point; with local false,
 * the loss of (i, j) alone. */
static inline double ref_pl_hold(ref_pl_t *r, int i, int j, bool local, int *bi, int *bj)
{
    r->seen = calloc((size_t)r->lw * r->lh, 1);
    r->fp = r->cfg.footprint;
    double n, w, p0;
    double best = ref_pl_eval(r, i, j, &n, &w, &p0);
    *bi = i;
    *bj = j;
    for (int h = r->cs / 2 < 1 ? 1 : r->cs / 2; local; h /= 2) {
        int ci = *bi, cj = *bj;
        for (int b = -1; b <= 1; ++b) {
            for (int a = -1; a <= 1; ++a) {
                if ((a != 0 || b != 0) && ref_pl_legal(r, ci + a * h, cj + b * h)) {
                    double l = ref_pl_eval(r, ci + a * h, cj + b * h, &n, &w, &p0);
                    if (l < best) {
                        best = l;
                        *bi = ci + a * h;
                        *bj = cj + b * h;
                    }
                }
            }
        }
        if (h <= 1) {
            break;
        }
    }
    free(r->seen);
    r->seen = NULL;
    return best;
}

#endif /* REF_PATHLOSS_H */
