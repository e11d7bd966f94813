/* rfs_model.h - the internal model interface (paper sections 3 and 5.2).
 *
 * "The concept of internal models is agnostic to the actual representation": the seeker
 * sees a model only through these operations. A model learns from the stored samples
 * (possibly around a query point: the local ridge uses the robot's position), predicts
 * the target anywhere on the map, and may take several calls to learn so that a long
 * fit can be sliced across control periods (budget = work units per call).
 */
#ifndef RFS_MODEL_H
#define RFS_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_store.h"

/// Most sources whose own samples a fit sees (rfs_model_fit_in_t.src_samples).
#define RFS_MODEL_MAX_SOURCES 2u

/// Most places a fit can be told the source is not (rfs_model_fit_in_t.nexcl).
#define RFS_MODEL_MAX_EXCL 32u

/// The seeker's phase, for a model that ranks the places it measured once exploration is
/// over (rfs_fields_cfg_t.settle_k).
typedef enum rfs_model_settle {
    RFS_MODEL_EXPLORE = 0, ///< exploring (the paper's only phase)
    RFS_MODEL_TOUR,        ///< settled: the robot measures the candidates in turn
    RFS_MODEL_HOLD,        ///< ... and then holds the best measured
} rfs_model_settle_t;

/// What a model learns from.
typedef struct rfs_model_fit_in {
    const rfs_sample_t *samples; ///< the stored samples
    uint16_t n;                  ///< how many
    /// Their index (rfs_cellsum.h), kept by the store; NULL: none. The local ridge reads
    /// its disc sums in a whole fit instead of visiting every sample (the same result).
    const rfs_store_index_t *index;
    rfs_q16_t qx;                ///< query point (robot position) x, metres Q16.16
    rfs_q16_t qy;                ///< query point y, metres Q16.16
    const rfs_map_t *map;        ///< the map (for map-aware models); may be NULL
    /// One bit per lattice point of map (rfs_reach.h): reachable from the robot; NULL
    /// when unknown (every legal point counts)
    const uint8_t *reach;
    uint8_t nsources;            ///< sources with their own samples below (0: none kept)
    /// Each source's own samples (its RSSI, dBm Q9.6), for a model fitted per source
    /// (rfs_fields.h); src_n[i] of them.
    const rfs_sample_t *src_samples[RFS_MODEL_MAX_SOURCES];
    uint16_t src_n[RFS_MODEL_MAX_SOURCES]; ///< how many of each
    /// Samples each source's store was ever offered (rfs_store_t.seen): unchanged with
    /// src_n, the same samples as at the last fit.
    uint32_t src_seen[RFS_MODEL_MAX_SOURCES];
    /// Places ruled out as the source (rfs_seek_cfg_t.refute_r): a model that searches
    /// source positions skips every candidate within excl_r of (excl_x_cm[i],
    /// excl_y_cm[i]), i < nexcl (<= RFS_MODEL_MAX_EXCL; 0: none), centimetres (as
    /// rfs_sample_t).
    const int16_t *excl_x_cm;
    const int16_t *excl_y_cm; ///< their y, centimetres
    uint8_t nexcl;           ///< how many
    rfs_q16_t excl_r;        ///< radius ruled out round each, metres Q16.16
    /// The seeker's settle phase (rfs_seek_cfg_t.settle_dist; rfs_fields_cfg_t.settle_k).
    rfs_model_settle_t settle;
} rfs_model_fit_in_t;

/// Result of one fit call.
typedef enum rfs_fit_result {
    RFS_FIT_DONE = 0, ///< the model is ready
    RFS_FIT_MORE,     ///< call again with the same input (sliced learning)
    RFS_FIT_FAILED,   ///< no model could be learnt (e.g. no samples); the model is invalid
} rfs_fit_result_t;

/// A question to rfs_model_ops_t.near: of the places where the maximum may be, weighing
/// w = e^(-chi2 / 2 temp) against the argmax (w = 1), the one with the most weight per
/// metre, w / (d + d0), d its straight distance from (x, y), when that beats the argmax's
/// 1 / (d_argmax + d0); places refuse() refuses are passed over.
typedef struct rfs_model_near {
    rfs_q16_t x;    ///< from here (the robot), metres Q16.16
    rfs_q16_t y;    ///< metres Q16.16
    rfs_q16_t ax;   ///< the argmax, metres Q16.16
    rfs_q16_t ay;   ///< metres Q16.16
    rfs_q16_t temp; ///< temperature of the weights, Q16.16 (> 0)
    rfs_q16_t d0;   ///< added to every distance, metres Q16.16 (> 0)
    /// true refuses the place (x, y) (NULL: none refused).
    bool (*refuse)(const void *ctx, rfs_q16_t x, rfs_q16_t y);
    const void *ctx; ///< passed to refuse
} rfs_model_near_t;

/// Operations of one kind of internal model.
typedef struct rfs_model_ops {
    const char *name; ///< short name, as on the command line ("ridge")
    /// Discard the current model (it predicts nothing until the next fit is done).
    void (*reset)(void *self);
    /// Learn (or continue learning). budget: work units for this call, 0 = no limit.
    rfs_fit_result_t (*fit)(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                            rfs_rng_t *rng);
    /// Predict the target at (x, y) in target units Q16.16; false when there is no model.
    bool (*predict)(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value);
    /// Optional (may be NULL): where the model believes the maximum is, when it knows
    /// better than a grid search (e.g. an estimated source position).
    bool (*argmax)(const void *self, rfs_q16_t *x, rfs_q16_t *y);
    /// Optional (may be NULL): predict n points (x0 + k*dx, y), k = 0..n-1, into out[];
    /// false when there is no model. Lets the grid search run without a call per point
    /// (a plane is evaluated with one addition per point).
    bool (*predict_row)(const void *self, rfs_q16_t x0, rfs_q16_t y, rfs_q16_t dx, uint16_t n,
                        rfs_q16_t *out);
    /// Optional (may be NULL): for a model whose predictions along a line of constant y
    /// never decrease in one direction (a plane: the ridge), that direction: +1 towards
    /// larger x, -1 towards smaller x, 0 constant. The grid search then evaluates only the
    /// ends of each lattice row and finds exactly the maximum a full scan finds.
    int (*row_monotone)(const void *self);
    /// Optional (may be NULL): an upper bound of the model over the closed box
    /// [x0, x1] x [y0, y1] (metres Q16.16, x0 <= x1, y0 <= y1). true promises, bit for bit,
    /// that predict() (and predict_row()) succeeds at every point of the box and returns
    /// at most *ub there; false = no such promise (no model, or a point may have no
    /// prediction). Lets the grid search skip whole blocks of the lattice and still find
    /// exactly the full scan's maximum (branch and bound, rfs_gridmax.h).
    bool (*bound)(const void *self, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                  rfs_q16_t *ub);
    /// Optional (may be NULL): draw where the maximum may be from the model's belief (the
    /// path-loss model: a candidate source with probability falling with its misfit);
    /// false when there is no model. Epsilon steps go there (rfs_seek_cfg_t.eps_sample):
    /// exploration towards plausible sources rather than at random.
    bool (*sample)(const void *self, rfs_rng_t *rng, rfs_q16_t *x, rfs_q16_t *y);
    /// Optional (may be NULL): the plausible maximum worth visiting before the argmax
    /// (rfs_model_near_t); false when none beats the argmax or there is no model.
    bool (*near)(const void *self, const struct rfs_model_near *q, rfs_q16_t *x, rfs_q16_t *y);
    /// Optional (may be NULL): how far the fit's source power lies above the model's floor
    /// of plausible powers (the path-loss model: P0 - p0_min), dB Q16.16 (negative below
    /// it); false when there is no model or no floor (rfs_seek_cfg_t.floor_gap).
    bool (*floor_gap)(const void *self, rfs_q16_t *gap);
    /// Optional (may be NULL): the mean of the model's belief where the maximum is, at
    /// temperature temp (Q16.16, > 0; the path-loss model: its candidates' positions
    /// weighted e^(-chi2 / 2 temp), as sample() draws them at its own); false when there is
    /// no model (rfs_seek_cfg_t.mean_t).
    bool (*mean)(const void *self, rfs_q16_t temp, rfs_q16_t *x, rfs_q16_t *y);
    /// Optional (may be NULL): between fits (the robot driving a leg), do work the next
    /// fit would do, in fit()'s work units (budget > 0; 0 = no limit): the path-loss
    /// model counts walls of the bins the robot has left (in->qx, qy: the robot). The
    /// model, its predictions and the next fit's results stay bit for bit the same; the
    /// next fit only has less to do. true while more is left.
    bool (*warm)(void *self, const rfs_model_fit_in_t *in, uint32_t budget);
} rfs_model_ops_t;

/// A model: its operations and its caller-owned state.
typedef struct rfs_model {
    const rfs_model_ops_t *ops; ///< operations
    void *self;                 ///< state passed to every operation
} rfs_model_t;

#endif /* RFS_MODEL_H */
