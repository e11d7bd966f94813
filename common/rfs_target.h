/* rfs_target.h - target functions: what the seeker maximises (paper sections 2 and 6).
 *
 * A target turns per-source measurements into one scalar. Each packet gives one sample
 * (the packet's own value for its source, the 1 s means for the others), and the relearn
 * check compares the model with the target of the 1 s means; combine() gives the target
 * of any per-source values (a model fitted per source predicts those). Built in: the
 * RSSI of one source, and the bridging target f = -|R1 - R2| - |R1 + R2| (paper section
 * 6). A new metric is one more rfs_target_ops_t.
 */
#ifndef RFS_TARGET_H
#define RFS_TARGET_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_rssi.h"

/// Most sources a target combines.
#define RFS_TARGET_MAX_SOURCES 2u

/// What a target sees: the per-source windows at time now_us.
typedef struct rfs_target_in {
    rfs_rssi_t *win;   ///< windows, one per source
    uint8_t nsources;  ///< how many
    int64_t now_us;    ///< current time, microseconds
} rfs_target_in_t;

/// Operations of one target function.
typedef struct rfs_target_ops {
    const char *name;     ///< short name ("rssi", "bridge")
    uint8_t nsources;     ///< sources it needs
    /// Value of one packet (source src, dbm) combined with the other sources' 1 s means.
    /// false when a needed mean is missing.
    bool (*sample)(const rfs_target_in_t *in, uint8_t src, int8_t dbm, rfs_q16_t *value);
    /// Value of the 1 s means (for the relearn check). false when a mean is missing.
    bool (*mean)(const rfs_target_in_t *in, rfs_q16_t *value);
    /// The target of one value per source, r[0..nsources-1] (dBm Q16.16): what sample and
    /// mean compute from their inputs, and what a model fitted per source evaluates on
    /// its predicted fields (rfs_fields.h).
    rfs_q16_t (*combine)(const rfs_q16_t *r);
} rfs_target_ops_t;

/// Single-source RSSI, dBm.
extern const rfs_target_ops_t rfs_target_rssi;
/// Bridging two sources: f = -|R1 - R2| - |R1 + R2| (paper section 6).
extern const rfs_target_ops_t rfs_target_bridge;

#endif /* RFS_TARGET_H */
