/* rfs_fields.h - one path-loss fit per source, and the target evaluated on the predicted
 * fields (docs/PATHLOSS.md, "One fit per source").
 *
 * A target of several sources, such as the bridging f = -|R1 - R2| - |R1 + R2| (paper
 * section 6), is no path-loss field, but each source's RSSI is. This model fits the
 * map-aware path-loss model (rfs_pathloss.h) to each source's own samples
 * (rfs_model_fit_in_t.src_samples), corrects each predicted field by what the samples
 * say about the shadowing near a point, and evaluates the target
 * (rfs_target_ops_t.combine) on the corrected fields:
 *
 *   R_s(x) = PL_s(x) + sum_c w(x, c) S_sc / (prior_n + sum_c w(x, c) N_sc)
 *
 * PL_s is source s's path-loss prediction; S_sc and N_sc are the sum of the residuals
 * (sample minus PL_s, walls at the sample's nearest lattice point) and the number of
 * source s's samples in residual cell c (`cell` square, on the map's lattice); w is
 * 1 - d / radius for d between the centres of x's cell and c. Far from every sample a
 * field is its path-loss fit, where the robot has measured it is what it measured:
 * prior_n samples weigh as much as the prior that the shadowing there is 0.
 *
 * A fit ends with a pass over the legal lattice points (those reachable from the robot
 * when fit_in.reach is given): the target is predicted at every point within the kernel
 * of a sample, at every `coarse` spacing elsewhere, and then at full resolution round the
 * RFS_FIELDS_TOP best coarse points; each prediction is kept (16 bits a point), the best
 * is argmax() (the greedy goal) and the estimate (rfs_fields_est_t). Walls from a
 * lattice point to a source are kept, a byte each, until that source's estimate moves. A
 * relearn refits a source's path-loss model only after refit_min new samples of it
 * (else it bins that source's residuals again), and with no new sample at all keeps
 * the last fit: the samples are what the fit is a function of. Draws (sample()) pick a
 * predicted point with weight e^(-(best - f) / draw_t).
 *
 * Work (the fit budget): each source's fit in its own units (rfs_pathloss.h), then one
 * unit per wall count and per 32 samples or lattice points; fit() returns RFS_FIT_MORE
 * between the parts. The caller owns the large arrays (rfs_fields_mem_t).
 */
#ifndef RFS_FIELDS_H
#define RFS_FIELDS_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_model.h"
#include "rfs_pathloss.h"
#include "rfs_target.h"

/// Most residual cells the kernel reaches from a point's cell, each way.
#define RFS_FIELDS_KERNEL_MAX 4
/// Kernel weights tabulated by squared cell offset.
#define RFS_FIELDS_KERNEL_TABLE (2 * RFS_FIELDS_KERNEL_MAX * RFS_FIELDS_KERNEL_MAX + 1)
/// A lattice point that is no candidate (not legal, or out of reach): its value in f[].
#define RFS_FIELDS_NONE INT16_MIN
/// A candidate the last fit did not predict (between coarse points, far from samples).
#define RFS_FIELDS_SKIPPED (INT16_MIN + 1)
/// Best coarse points whose neighbourhoods are predicted at full resolution.
#define RFS_FIELDS_TOP 4u
/// Most candidates of the settle phase (rfs_fields_cfg_t.settle_k).
#define RFS_FIELDS_CAND 8u

/// Configuration; rfs_fields_cfg_default() gives the values in the comments.
typedef struct rfs_fields_cfg {
    rfs_pathloss_cfg_t pathloss; ///< every source's fit (rfs_pathloss_cfg_default())
    rfs_q16_t cell;              ///< residual cell side, metres Q16.16 (0.25 m), rounded to
                                 ///< whole lattice steps (at least one), <= 8 m
    rfs_q16_t radius;            ///< kernel radius, metres Q16.16 (0.5 m), at most
                                 ///< RFS_FIELDS_KERNEL_MAX cells
    uint16_t prior_n;            ///< samples that weigh as much as the prior (3), >= 1
    rfs_q16_t draw_t;            ///< temperature of draws, target units Q16.16 (3 dB), > 0
    uint32_t refit_min;          ///< a relearn refits a source's path-loss model after this
                                 ///< many new samples of it (100; fewer: only its residuals
                                 ///< are binned again), >= 1
    rfs_q16_t coarse;            ///< spacing of the points predicted away from the samples,
                                 ///< metres Q16.16 (1 m), rounded to lattice steps (>= 1)
    rfs_q16_t lcb;               ///< the best point has the highest prediction less lcb
                                 ///< times its sigma (rfs_fields_est_t), Q16.16 (0), 0..8
    uint8_t settle_k;            ///< once settled (rfs_model_fit_in_t.settle): the
                                 ///< candidates, the best measured places, at most
                                 ///< RFS_FIELDS_CAND (6; 0: off, the best prediction)
    uint16_t settle_n;           ///< a candidate has this many samples of every source in
                                 ///< its cell (8), >= 1
    uint16_t settle_conf;        ///< ... and is measured enough with this many (64)
    uint8_t settle_sep;          ///< candidates lie this many lattice steps apart (2), >= 1
} rfs_fields_cfg_t;

/// Caller-owned arrays, sized with rfs_fields_mem_size() for the map.
typedef struct rfs_fields_mem {
    uint8_t *walls[RFS_MODEL_MAX_SOURCES];  ///< per source: walls to it per lattice point
    int32_t *rsum[RFS_MODEL_MAX_SOURCES];   ///< per source: residual sums per cell, dB Q8
    uint16_t *rcount[RFS_MODEL_MAX_SOURCES]; ///< per source: samples per cell
    int16_t *f;                             ///< predicted target per lattice point, Q9.6
    uint32_t points;                        ///< lattice points each per-point array holds
    uint32_t cells;                         ///< cells each per-cell array holds
} rfs_fields_mem_t;

/// Fit phases.
typedef enum rfs_fields_phase {
    RFS_FIELDS_IDLE = 0, ///< no fit in progress
    RFS_FIELDS_SOURCE,   ///< fitting source k's path-loss model
    RFS_FIELDS_RESIDUAL, ///< binning source k's residuals
    RFS_FIELDS_LATTICE,  ///< predicting the target on the lattice
    RFS_FIELDS_REFINE,   ///< ... and round the best coarse points at full resolution
} rfs_fields_phase_t;

/// The model's estimate (rfs_fields_estimate()).
typedef struct rfs_fields_est {
    rfs_q16_t x;        ///< predicted best point x, metres Q16.16
    rfs_q16_t y;        ///< predicted best point y, metres Q16.16
    rfs_q16_t value;    ///< predicted target there, target units Q16.16
    rfs_q16_t sigma;    ///< its uncertainty, target units Q16.16: sqrt(2 sum s_i^2), s_i =
                        ///< rms_i sqrt(prior_n / (prior_n + n_i)) (docs/PATHLOSS.md)
    rfs_q16_t area_m2;  ///< lattice area predicted within sigma of the best, m^2 Q16.16
    uint8_t nsources;   ///< sources fitted
    rfs_pathloss_est_t src[RFS_MODEL_MAX_SOURCES]; ///< each source's path-loss fit
} rfs_fields_est_t;

/// State, caller-owned (two path-loss states and a few hundred bytes).
typedef struct rfs_fields {
    rfs_fields_cfg_t cfg;                        ///< configuration copied at init
    const rfs_target_ops_t *target;              ///< evaluated on the fields
    rfs_fields_mem_t mem;                        ///< the caller's arrays
    rfs_pathloss_t src[RFS_MODEL_MAX_SOURCES];   ///< each source's path-loss model
    bool valid;                                  ///< a model exists
    rfs_fields_phase_t phase;                    ///< fit phase
    uint8_t k;                                   ///< source of the phase
    uint32_t pos;                                ///< position within the phase
    const rfs_map_t *map;                        ///< map of the last fit
    uint16_t cs;                                 ///< cell side, lattice steps
    uint16_t cw;                                 ///< cells along x
    uint16_t ch;                                 ///< cells along y
    uint8_t kr;                                  ///< kernel reach, cells
    uint16_t cstep;                              ///< coarse spacing, lattice steps
    uint8_t ntop;                                ///< best coarse points kept in top[]
    uint32_t top[RFS_FIELDS_TOP];                ///< their lattice indices, best first
    int16_t top_v[RFS_FIELDS_TOP];               ///< their predictions, Q9.6
    uint16_t kw[RFS_FIELDS_KERNEL_TABLE];        ///< kernel weight by squared offset, Q0.16
    bool wvalid[RFS_MODEL_MAX_SOURCES];          ///< walls[k] belong to wsx/wsy on map wmap
    rfs_q16_t wsx[RFS_MODEL_MAX_SOURCES];        ///< source position walls[k] count to, Q16.16
    rfs_q16_t wsy[RFS_MODEL_MAX_SOURCES];        ///< (metres)
    const rfs_map_t *wmap;                       ///< map the walls belong to
    uint32_t best;                               ///< lattice index of the best point (lcb)
    int32_t best_v;                              ///< the highest prediction, Q9.6 (RFS_FIELDS_NONE: none)
    rfs_q16_t bx;                                ///< best point x, metres Q16.16
    rfs_q16_t by;                                ///< best point y, metres Q16.16
    rfs_q16_t bf;                                ///< prediction there, target units Q16.16
    rfs_q16_t sigma;                             ///< its uncertainty, target units Q16.16
    rfs_q16_t area_m2;                           ///< area within sigma of the best, m^2 Q16.16
    int64_t rms2[RFS_MODEL_MAX_SOURCES];         ///< each fit's rms^2, dB^2 Q16 (this lattice)
    bool scored;                                 ///< best_s holds a point's score
    int64_t best_s;                              ///< the best point's score, Q16.16
    uint32_t walls_counted;                      ///< wall counts of the last fit's own passes
    bool fitted[RFS_MODEL_MAX_SOURCES];          ///< src[k] holds a fit of fit_n/fit_seen
    uint16_t fit_n[RFS_MODEL_MAX_SOURCES];       ///< samples of that fit
    uint32_t fit_seen[RFS_MODEL_MAX_SOURCES];    ///< the store's seen count then
    bool changed[RFS_MODEL_MAX_SOURCES];         ///< this fit bins source k's residuals
    bool refit[RFS_MODEL_MAX_SOURCES];           ///< ... and refits its path-loss model
    bool lattice_done;                           ///< f[] and the best point are complete
    rfs_model_settle_t settle;                   ///< the last fit's rfs_model_fit_in_t.settle
    uint8_t ncand;                               ///< settle phase: candidates in cand[]
    bool frozen;                                 ///< cand[] is chosen
    uint32_t cand[RFS_FIELDS_CAND];              ///< their lattice indices, best first
    int64_t cand_s[RFS_FIELDS_CAND];             ///< their measured target, Q16.16
} rfs_fields_t;

/// Defaults (see rfs_fields_cfg_t).
rfs_fields_cfg_t rfs_fields_cfg_default(void);

/// Sizes rfs_fields_mem_t needs for map m under cfg: lattice points and residual cells.
void rfs_fields_mem_size(const rfs_map_t *m, const rfs_fields_cfg_t *cfg, uint32_t *points,
                         uint32_t *cells);

/// Initialise without a model for target t (1..RFS_MODEL_MAX_SOURCES sources). Returns
/// 0, or -1 on a bad configuration (rfs_pathloss_init's rules; cell outside (0, 8 m],
/// radius outside [0, RFS_FIELDS_KERNEL_MAX cells], prior_n 0, draw_t <= 0, settle_k
/// above RFS_FIELDS_CAND, settle_n or settle_sep 0), a target
/// without combine(), or a missing array. Fits fail on a map larger than the arrays.
int rfs_fields_init(rfs_fields_t *f, const rfs_fields_cfg_t *cfg, const rfs_target_ops_t *t,
                    const rfs_fields_mem_t *mem);

/// Operations (rfs_fields_model() builds the model).
extern const rfs_model_ops_t rfs_fields_ops;

/// The model interface of a fields state.
rfs_model_t rfs_fields_model(rfs_fields_t *f);

/// The current estimate; false when there is no model.
bool rfs_fields_estimate(const rfs_fields_t *f, rfs_fields_est_t *est);

/// The prediction the last fit kept for lattice point (i, j), target units Q16.16; false
/// when there is no model or the point had none (not legal, out of reach).
bool rfs_fields_at(const rfs_fields_t *f, uint16_t i, uint16_t j, rfs_q16_t *value);

#endif /* RFS_FIELDS_H */
