/* rfs_pdr.h - packet delivery ratio over a sliding time window, and the "pdr" target.
 *
 * The ratio of packets received to packets sent in (now - window, now], in percent,
 * from the 12-bit 802.11 sequence numbers of the received frames (captures, monitor
 * mode) or of the frames a simulated link let through. Every received frame records how
 * many sequence numbers were skipped before it (the lost frames); those were sent, at
 * an even pace, between the previous received frame and this one, so only the part of
 * that gap inside the window counts for the oldest frame in the window.
 *
 * Sequence rules (per transmitter; the caller keeps one rfs_pdr_t per source):
 *   d = (seq - previous seq) mod 4096
 *   d == 0              a retransmission of the same frame: not counted again;
 *   1 <= d <= 2048      d - 1 frames were lost;
 *   d > 2048            a step backwards (sender restart, reordering): a resync,
 *                       nothing counted as lost.
 * An outage of 4096 frames or more cannot be seen in 12 bits (20 s at 200 frames/s).
 * Frames lost after the newest received one are unknown until the next one arrives, so
 * the ratio is meant to be read when a frame arrives (as the seeker does).
 *
 * As a target (paper section 2: the seeker maximises a scalar of position), the PDR
 * uses the RSSI path of the seeker: for each received frame the application computes
 * rfs_pdr_value() and passes it as the measurement (an int8 percentage, 0..100) to
 * rfs_seek_on_rssi(); rfs_target_pdr then learns those values and checks the model
 * against their 1 s mean. Target units are percent; the relearn threshold (3) reads as
 * 3 percentage points.
 */
#ifndef RFS_PDR_H
#define RFS_PDR_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_target.h"

/// Received frames kept per window; more than this many in a window and the ratio
/// covers the newest RFS_PDR_CAP (counted in `overflowed`).
#define RFS_PDR_CAP 512u
/// Sequence numbers wrap at 4096 (802.11 Sequence Control, 12 bits).
#define RFS_PDR_SEQ_MOD 4096u

/// Configuration of the window.
typedef struct rfs_pdr_cfg {
    uint32_t window_us; ///< window length, microseconds (1 s, as the RSSI mean)
} rfs_pdr_cfg_t;

/// One transmitter's delivery window; caller-owned, about 3 KB.
typedef struct rfs_pdr {
    rfs_pdr_cfg_t cfg;             ///< configuration copied at init
    uint32_t t_lo[RFS_PDR_CAP];    ///< low 32 bits of each received frame's time, microseconds
    uint16_t lost[RFS_PDR_CAP];    ///< frames lost just before each received frame
    uint16_t head;                 ///< index of the oldest kept frame
    uint16_t count;                ///< frames kept
    uint32_t sum_lost;             ///< sum of lost[] over the kept frames
    int64_t prev_us;               ///< time of the frame before the oldest kept one, microseconds
    bool has_prev;                 ///< prev_us is valid
    int64_t last_us;               ///< newest accepted time, microseconds
    uint16_t last_seq;             ///< newest accepted sequence number, 0..4095
    bool has_last;                 ///< last_us / last_seq are valid
    uint32_t accepted;             ///< frames counted as received
    uint32_t lost_total;           ///< frames counted as lost since init
    uint32_t duplicates;           ///< retransmissions (same sequence number) ignored
    uint32_t resyncs;              ///< steps backwards treated as a restart
    uint32_t rejected_order;       ///< frames older than the newest, rejected
    uint32_t overflowed;           ///< frames pushed out while still inside the window
} rfs_pdr_t;

/// Defaults: a 1 s window.
rfs_pdr_cfg_t rfs_pdr_cfg_default(void);

/// Initialise an empty window. Returns 0, or -1 when window_us is 0 or over 60 s.
int rfs_pdr_init(rfs_pdr_t *p, const rfs_pdr_cfg_t *cfg);

/// A frame with sequence number seq (0..4095; higher bits are ignored) was received at
/// t_us. Returns false when it is not counted: a retransmission, or older than the newest.
bool rfs_pdr_push(rfs_pdr_t *p, int64_t t_us, uint16_t seq);

/// Same, from the 16-bit 802.11 Sequence Control field (fragment number in bits 0..3,
/// sequence number in bits 4..15). Only fragment 0 counts (one MSDU, one frame).
bool rfs_pdr_push_seq_ctrl(rfs_pdr_t *p, int64_t t_us, uint16_t seq_ctrl);

/// Delivery ratio over (now_us - window, now_us], percent Q16.16 in [0, 100], rounded.
/// now_us must not be older than the newest push. Drops expired frames. Returns false
/// (ratio untouched) when no frame is in the window.
/// Scaling and overflow: lost frames before the oldest kept frame count by the fraction
/// of their gap inside the window, in Q16 (lost < 2^12 x gap < 2^31 x 2^16 in uint64);
/// 100 x received (< 2^16) << 32 over (received + lost) in Q16, in int64.
bool rfs_pdr_ratio(rfs_pdr_t *p, int64_t now_us, rfs_q16_t *pct);

/// The ratio rounded to a whole percentage (0..100), the measurement to hand to the
/// seeker with the "pdr" target. false when no frame is in the window.
bool rfs_pdr_value(rfs_pdr_t *p, int64_t now_us, int8_t *pct);

/// Packet delivery ratio, percent: one source; the measurements are rfs_pdr_value()s.
extern const rfs_target_ops_t rfs_target_pdr;

#endif /* RFS_PDR_H */
