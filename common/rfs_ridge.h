/* rfs_ridge.h - the local ridge regression internal model (paper section 5.2.1).
 *
 * Ridge regression of value on (x, y) with an unpenalised intercept and alpha = 1.0
 * (features in metres), on the stored samples within `radius` (5 m) of the query point:
 * exactly what scikit-learn's Ridge(alpha=1.0).fit(X, y) computes on that subset.
 * Sums are accumulated exactly in int64 with coordinates in centimetres centred on the
 * query point, the 2 x 2 system is solved exactly in 128-bit integers (Cramer's rule),
 * and the plane predicts anywhere on the map.
 *
 * Exactness: the samples are what the store holds (cm, Q9.6), the query is rounded to
 * the nearest centimetre, a sample is used when its distance is <= radius (integer test
 * in cm^2), and alpha * 10^4 cm^2 is rounded to an integer (exact for alpha = 1.0 and any
 * multiple of 1/16). On that data the only differences from scikit-learn's double
 * solution are the rounding of the slopes to Q40.24 and of the centre value to Q16.16:
 * tested on 120 random data sets to within 3e-4 dB everywhere on a +-300 m map
 * (tests/common/test_ridge.c; docs/FIXED_POINT.md, "Local ridge model", gives the
 * bound the test asserts).
 *
 * Work: fit() with budget 0 visits every sample; with budget > 0 it visits at most
 * `budget` samples per call and returns RFS_FIT_MORE until the last call, which solves
 * (a few thousand instructions). A call with a different query point, or with fewer
 * samples than already visited, restarts the fit. The model is invalid while fitting.
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

/// Running sums of a fit in progress, so a fit can be sliced across calls.
/// u, v: sample position minus the fit centre, centimetres; z: sample value, Q9.6.
/// Scaling and overflow: |u|, |v| <= radius <= 30,000 cm and |z| <= 2^15, so each
/// product fits int32 and each sum of up to 65,535 of them fits its type (int32 for
/// the first-order sums: 65,535 x 30,000 < 2^31).
typedef struct rfs_ridge_acc {
    rfs_q16_t qx;          ///< query x the sums belong to, metres Q16.16 (as passed to fit)
    rfs_q16_t qy;          ///< query y, metres Q16.16
    int32_t qx_cm;         ///< fit centre x, centimetres (query rounded to the sample grid)
    int32_t qy_cm;         ///< fit centre y, centimetres
    uint16_t next;         ///< index of the next sample to visit
    uint16_t n;            ///< samples inside the radius so far
    int32_t su;            ///< sum of u, cm
    int32_t sv;            ///< sum of v, cm
    int32_t sz;            ///< sum of z, Q9.6
    int64_t suu;           ///< sum of u*u, cm^2
    int64_t suv;           ///< sum of u*v, cm^2
    int64_t svv;           ///< sum of v*v, cm^2
    int64_t suz;           ///< sum of u*z, cm x Q9.6
    int64_t svz;           ///< sum of v*z, cm x Q9.6
} rfs_ridge_acc_t;

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
    bool fast_predict;     ///< slopes fit int32 and the centre is within +-16 km (fast path)
    bool fitting;          ///< a sliced fit is in progress (acc is live)
    rfs_ridge_acc_t acc;   ///< sums of the fit in progress
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
