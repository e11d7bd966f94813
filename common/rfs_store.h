/* rfs_store.h - the sample store: (x, y, value) samples for learning (paper sections 2, 5.2).
 *
 * Each measurement is paired with the robot position linearly interpolated to its
 * timestamp between the two bracketing pose messages. A measurement older than the
 * oldest pose kept is dropped and counted; one newer than the newest pose waits in a
 * small pending queue until the next pose brackets it. At most `capacity` samples are
 * kept (paper: 10,000), a uniform random subset of all samples seen (reservoir
 * sampling, Algorithm R), 6 bytes a sample.
 */
#ifndef RFS_STORE_H
#define RFS_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"

/// One stored sample: 6 bytes.
typedef struct rfs_sample {
    int16_t x_cm; ///< position x, centimetres (map frame), +-327 m
    int16_t y_cm; ///< position y, centimetres (map frame)
    int16_t v_q6; ///< target value, dB (or target units) in Q9.6: +-512, step 1/64
} rfs_sample_t;

/// A robot pose as published by localisation.
typedef struct rfs_pose {
    int64_t t_us;        ///< timestamp, microseconds
    rfs_q16_t x;         ///< metres, Q16.16, map frame
    rfs_q16_t y;         ///< metres, Q16.16, map frame
    rfs_q16_t theta;     ///< heading, radians Q16.16, (-pi, pi], 0 = +x, counter-clockwise
} rfs_pose_t;

/// A measurement waiting for a pose that brackets it.
typedef struct rfs_pending {
    int64_t t_us;  ///< timestamp, microseconds
    int16_t v_q6;  ///< value, Q9.6
} rfs_pending_t;

/// Number of poses kept to interpolate late measurements (0.8 s at 10 Hz).
#define RFS_STORE_POSE_HISTORY 8u

/// Store configuration.
typedef struct rfs_store_cfg {
    uint16_t capacity;     ///< samples kept for learning (paper: 10,000)
    int64_t max_gap_us;    ///< poses further apart than this do not bracket (0.5 s; <= 60 s)
} rfs_store_cfg_t;

struct rfs_cellsum_disc;

/// An index kept with the store (rfs_cellsum_index()): told of every slot written, it
/// answers the local ridge's disc sums. Through pointers, so an image without one links
/// none of its code.
typedef struct rfs_store_index {
    /// Slot `slot` now holds `s`; `old` is what it held (NULL: it was empty).
    void (*put)(void *self, uint16_t slot, const rfs_sample_t *old, const rfs_sample_t *s);
    /// The sums over the samples within r_cm of (qx_cm, qy_cm) (rfs_cellsum_disc()).
    void (*disc)(const void *self, const rfs_sample_t *samples, int32_t qx_cm, int32_t qy_cm,
                 int32_t r_cm, struct rfs_cellsum_disc *out);
    void *self;   ///< the index
    uint16_t cap; ///< store slots it covers
} rfs_store_index_t;

/// The sample store; samples and pending queue live in caller-owned arrays.
typedef struct rfs_store {
    rfs_store_cfg_t cfg;                           ///< configuration copied at init
    rfs_sample_t *samples;                         ///< caller's array of cfg.capacity
    uint16_t count;                                ///< samples held
    const rfs_store_index_t *index;                ///< kept with it; NULL: none
    uint32_t seen;                                 ///< samples offered to the reservoir
    rfs_pending_t *pending;                        ///< caller's pending ring
    uint16_t pending_cap;                          ///< its capacity
    uint16_t pending_head;                         ///< oldest pending index
    uint16_t pending_count;                        ///< pending measurements
    rfs_pose_t poses[RFS_STORE_POSE_HISTORY];      ///< recent poses, ring
    uint8_t pose_head;                             ///< index of the oldest pose
    uint8_t pose_count;                            ///< poses held
    uint32_t dropped_early;                        ///< measurements older than the pose history
    uint32_t dropped_pending;                      ///< measurements lost to a full pending queue
    uint32_t dropped_gap;                          ///< measurements between poses too far apart
    uint32_t rejected_pose_order;                  ///< poses older than the newest, rejected
} rfs_store_t;

/// Defaults: 10,000 samples (paper section 5.2), 0.5 s bracketing gap.
rfs_store_cfg_t rfs_store_cfg_default(void);

/// Initialise an empty store over caller arrays. Returns 0, or -1 on a null array,
/// zero capacity or pending_cap, or max_gap_us outside (0, 60 s].
int rfs_store_init(rfs_store_t *s, const rfs_store_cfg_t *cfg, rfs_sample_t *samples,
                   rfs_pending_t *pending, uint16_t pending_cap);

/// Add a pose (strictly newer than the last, else rejected and counted) and turn every
/// pending measurement it brackets into a sample. Returns false when rejected.
bool rfs_store_add_pose(rfs_store_t *s, const rfs_pose_t *pose, rfs_rng_t *rng);

/// Add a measurement of value v (Q16.16, rounded and saturated to Q9.6) taken at t_us.
/// Bracketed: a sample now (position interpolated, rounded to the centimetre, saturated
/// to +-327.67 m). Older than the oldest pose kept: dropped_early. Newer than the newest
/// pose (or no pose yet): queued until a pose brackets it (dropped_pending when the
/// queue is full). Between poses more than max_gap_us apart: dropped_gap.
void rfs_store_add_value(rfs_store_t *s, int64_t t_us, rfs_q16_t v, rfs_rng_t *rng);

/// Interpolate the position at t_us from the pose history. false when not bracketed.
bool rfs_store_position_at(const rfs_store_t *s, int64_t t_us, rfs_q16_t *x, rfs_q16_t *y);

/// Offer one complete sample to the reservoir (used by the store itself and by replay).
void rfs_store_offer(rfs_store_t *s, rfs_sample_t sample, rfs_rng_t *rng);

/// Keep `index` (an empty one covering at least cfg.capacity slots; NULL: none) up to
/// date with every sample written from now on; the samples held are put in now.
void rfs_store_set_index(rfs_store_t *s, const rfs_store_index_t *index);

#endif /* RFS_STORE_H */
