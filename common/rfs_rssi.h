/* rfs_rssi.h - the 1-second mean of received signal strength, per source (paper section 2).
 *
 * "the model prediction error at the current location is calculated against the mean
 * signal strength over the last second": each source keeps a ring of its most recent
 * measurements and reports the exact mean of those whose timestamp lies in
 * (now - window, now]. A measurement older than the newest accepted one of the same
 * source is rejected and counted (out of order); equal timestamps are accepted.
 * Time only moves forward: entries are kept while inside the window ending at the newest
 * time seen by a push or a query, so a query into the past covers (now - window, now]
 * without what had already left that window, and a measurement that arrives after the
 * window has passed it is accepted but not averaged.
 */
#ifndef RFS_RSSI_H
#define RFS_RSSI_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"

/// Ring capacity per source: the exact 1 s mean holds up to this many packets per second;
/// above that the mean covers the newest RFS_RSSI_CAP packets (counted in `overflowed`).
#define RFS_RSSI_CAP 512u

/// Configuration of the averaging window.
typedef struct rfs_rssi_cfg {
    uint32_t window_us; ///< averaging window, microseconds (paper: 1 s)
} rfs_rssi_cfg_t;

/// One source's averaging window; caller-owned, about 2.6 KB.
typedef struct rfs_rssi {
    rfs_rssi_cfg_t cfg;            ///< configuration copied at init
    uint32_t t_lo[RFS_RSSI_CAP];   ///< low 32 bits of each timestamp, microseconds
    int8_t dbm[RFS_RSSI_CAP];      ///< each measurement, dBm
    uint16_t head;                 ///< index of the oldest kept entry
    uint16_t count;                ///< entries kept
    int32_t sum_dbm;               ///< sum of the kept entries, dBm
    int64_t last_us;               ///< newest accepted timestamp, microseconds
    bool has_last;                 ///< last_us is valid
    int64_t clock_us;              ///< newest time seen by a push or query (valid with has_last)
    uint32_t accepted;             ///< measurements accepted
    uint32_t rejected_order;       ///< measurements rejected as out of order
    uint32_t overflowed;           ///< entries pushed out while still inside the window
} rfs_rssi_t;

/// Defaults: a 1 s window (paper section 2).
rfs_rssi_cfg_t rfs_rssi_cfg_default(void);

/// Initialise an empty window. Returns 0, or -1 when cfg->window_us is 0 or > 60 s.
int rfs_rssi_init(rfs_rssi_t *w, const rfs_rssi_cfg_t *cfg);

/// Add one measurement. Returns false (and counts it) when t_us is older than the newest
/// accepted measurement.
bool rfs_rssi_push(rfs_rssi_t *w, int64_t t_us, int8_t dbm);

/// Mean of the measurements in (now_us - window, now_us], in dB Q16.16, rounded to
/// nearest. Drops expired entries. Returns false (mean untouched) when there are none.
/// Scaling and overflow: sum of <= 512 int8 fits int32; (sum << 16) / n in int64.
bool rfs_rssi_mean(rfs_rssi_t *w, int64_t now_us, rfs_q16_t *mean_db);

/// Number of measurements in (now_us - window, now_us] (drops expired entries).
uint16_t rfs_rssi_count(rfs_rssi_t *w, int64_t now_us);

#endif /* RFS_RSSI_H */
