/* rfs_ridge.h - the local ridge regression internal model (paper section 5.2.1).
 *
 * Ridge regression of value on (x, y) with an unpenalised intercept and alpha = 1.0
 * (features in metres), on the stored samples within `radius` (5 m) of the query point:
 * exactly what scikit-learn's Ridge(alpha=1.0).fit(X, y) computes on that subset.
 * Sums are accumulated exactly in int64 with coordinates in centimetres centred on the
 * query point, the 2 x 2 system is solved exactly in 128-bit integers (Cramer's rule),
 * and the plane predicts anywhere on the map.
 */
#ifndef RFS_RIDGE_H
#define RFS_RIDGE_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_model.h"

/// Ridge configuration.
typedef struct rfs_ridge_cfg {
    rfs_q16_t radius; ///< metres Q16.16: samples within this distance of the query (5 m)
    rfs_q16_t alpha;  ///< ridge penalty Q16.16, features in metres (1.0)
} rfs_ridge_cfg_t;

/// Ridge state, caller-owned.
typedef struct rfs_ridge {
    rfs_ridge_cfg_t cfg;   ///< configuration copied at init
    bool valid;            ///< a model exists
    rfs_q16_t qx;          ///< centre of the fit (query point) x, metres Q16.16
    rfs_q16_t qy;          ///< centre y, metres Q16.16
    rfs_q16_t icpt;        ///< prediction at the centre, target units Q16.16
    int64_t wx_q24;        ///< slope along x, target units per metre, Q40.24
    int64_t wy_q24;        ///< slope along y, target units per metre, Q40.24
    uint16_t n_used;       ///< samples inside the radius at the last fit
} rfs_ridge_t;

/// Defaults: 5 m radius, alpha 1.0 (paper section 5.2.1).
rfs_ridge_cfg_t rfs_ridge_cfg_default(void);

/// Initialise without a model. Returns 0, or -1 on radius <= 0, a radius over 300 m, or
/// alpha < 0.
int rfs_ridge_init(rfs_ridge_t *r, const rfs_ridge_cfg_t *cfg);

/// The model interface of a ridge state.
rfs_model_t rfs_ridge_model(rfs_ridge_t *r);

/// Operations (also reachable through rfs_ridge_model()).
extern const rfs_model_ops_t rfs_ridge_ops;

#endif /* RFS_RIDGE_H */
