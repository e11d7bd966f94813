/* rfs_knn.h - nearest-neighbour regression internal models (paper section 5.2: "we also
 * tried ... k-Nearest Neighbors Regression and Radius Nearest Neighbor Regression").
 *
 * Two modes, both exactly scikit-learn's predictions (the paper used scikit-learn):
 *   k-neighbours: KNeighborsRegressor(n_neighbors=k, weights='uniform'): the mean target
 *                 of the k samples nearest (Euclidean) to the query; when fewer than k
 *                 samples exist, the mean of all of them (scikit-learn refuses to fit).
 *   radius:       RadiusNeighborsRegressor(radius=r): the mean target of every sample at
 *                 distance <= r; no prediction when there is none (scikit-learn: NaN).
 * The paper gives no parameters; the defaults are scikit-learn's (k = 5, r = 1.0 m).
 * Ties at the k-th distance keep the sample found first (scikit-learn leaves it open).
 *
 * fit() copies the samples (up to RFS_KNN_MAX_SAMPLES) into the state, because the
 * store keeps changing while the model is used, and sorts them into a uniform grid of
 * at most RFS_KNN_GRID x RFS_KNN_GRID cells over their bounding box (cell side at least
 * cfg.cell), so a query visits nearby cells only, and skips any cell too far to hold one
 * of its k nearest (which keeps every tie decision). Distances are exact integers: sample
 * positions in centimetres, the query rounded to 1/256 cm.
 *
 * Both modes give the model interface's `bound`: an upper bound of predict() over a box,
 * bit for bit (k-neighbours: the mean of the k largest targets among the samples that can
 * be a neighbour of some point of the box; radius: only when one sample covers the whole
 * box, else false), for the seeker's branch-and-bound grid search (docs/MODELS.md).
 *
 * A host may attach a finer index (rfs_knn_index.h): the same predictions, faster.
 *
 * Sliced learning: one work unit is one sample copied, counted or placed, or one grid
 * cell visited (exactly 3 n + 3 cells + 1 units per fit); fit(budget) does at most
 * `budget` units per call and returns RFS_FIT_MORE until the index is complete.
 */
#ifndef RFS_KNN_H
#define RFS_KNN_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_model.h"

/// Samples a model holds at most (paper section 5.2: 10,000).
#define RFS_KNN_MAX_SAMPLES 10000u
/// Largest k.
#define RFS_KNN_MAX_K 32u
/// Grid cells per side at most.
#define RFS_KNN_GRID 64u

/// Which regressor.
typedef enum rfs_knn_mode {
    RFS_KNN_KNEIGHBORS = 0, ///< mean of the k nearest samples
    RFS_KNN_RADIUS,         ///< mean of the samples within the radius
} rfs_knn_mode_t;

/// Nearest-neighbour configuration.
typedef struct rfs_knn_cfg {
    rfs_knn_mode_t mode;   ///< k-neighbours or radius
    uint8_t k;             ///< neighbours, 1..RFS_KNN_MAX_K (5); k-neighbours mode
    rfs_q16_t radius;      ///< metres Q16.16, (0, 300] (1.0); radius mode
    rfs_q16_t cell;        ///< smallest grid cell side, metres Q16.16, [0.05, 300] (1.0)
    uint16_t max_samples;  ///< learn from the first this many samples, 1..RFS_KNN_MAX_SAMPLES
} rfs_knn_cfg_t;

/// Nearest-neighbour state, caller-owned (about 77 KB: the sample copy and the grid).
typedef struct rfs_knn {
    rfs_knn_cfg_t cfg;                              ///< configuration copied at init
    bool valid;                                     ///< a model exists
    bool fitting;                                   ///< a sliced fit is in progress
    uint8_t phase;                                  ///< fit phase (copy, count, prefix, sort)
    uint16_t n;                                     ///< samples in the model
    uint32_t pos;                                   ///< progress inside the phase
    uint32_t updates;                               ///< work units done by the last fit call
    int16_t min_x_cm;                               ///< grid origin x (smallest sample x), cm
    int16_t min_y_cm;                               ///< grid origin y, cm
    int16_t max_x_cm;                               ///< largest sample x, cm
    int16_t max_y_cm;                               ///< largest sample y, cm
    uint16_t cell_cm;                               ///< grid cell side, cm
    uint8_t gw;                                     ///< grid cells along x, 1..RFS_KNN_GRID
    uint8_t gh;                                     ///< grid cells along y, 1..RFS_KNN_GRID
    rfs_sample_t pts[RFS_KNN_MAX_SAMPLES];          ///< the samples, sorted by cell
    uint16_t start[RFS_KNN_GRID * RFS_KNN_GRID + 1u]; ///< first sample of each cell (row-major)
    uint16_t cursor[RFS_KNN_GRID * RFS_KNN_GRID];   ///< fit scratch: next free slot per cell
    struct rfs_knn_index *index;                    ///< attached finer index (rfs_knn_index.h)
} rfs_knn_t;

/// Defaults for k-neighbours: k = 5, 1 m cells (scikit-learn's defaults).
rfs_knn_cfg_t rfs_knn_cfg_default(void);

/// Defaults for radius-neighbours: r = 1.0 m, 1 m cells (scikit-learn's defaults).
rfs_knn_cfg_t rfs_knn_cfg_radius_default(void);

/// Initialise without a model. Returns 0, or -1 when a field is outside the ranges above.
int rfs_knn_init(rfs_knn_t *s, const rfs_knn_cfg_t *cfg);

/// The model interface of a state (rfs_knn_ops or rfs_radius_ops by the configured mode).
rfs_model_t rfs_knn_model(rfs_knn_t *s);

/// Operations named "knn". Both tables hold the same functions: the state's configured
/// mode decides what predict() computes; the names let the registry tell them apart.
extern const rfs_model_ops_t rfs_knn_ops;
/// Operations named "radius" (same functions as rfs_knn_ops).
extern const rfs_model_ops_t rfs_radius_ops;

#endif /* RFS_KNN_H */
