/* rfs_can.h - the rfseek CAN protocol: frame layouts, ids, counters, checksums, time.
 *
 * Classic CAN 2.0A (11-bit ids, at most 8 data bytes). Every multi-byte field is
 * little-endian (Intel byte order); signed fields are two's complement. The full
 * layout, with bit positions, is in docs/CAN.md and can/rfseek.dbc.
 *
 * Rules common to every frame:
 *   - data[0] bits 0..3: a 4-bit rolling counter, +1 (mod 16) per frame of that id;
 *   - data[dlc-1]: CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF, not reflected)
 *     over the id (low byte, then high byte) followed by data[0 .. dlc-2]; covering
 *     the id means a frame copied to the wrong id fails its check (AUTOSAR E2E style);
 *   - the DLC is exact: a frame of a known id with another DLC is rejected.
 * A receiver rejects bad DLC and checksum, rejects a repeated counter (a duplicate),
 * and accepts but counts a counter jump (frames were lost).
 *
 * Time: frames that carry a timestamp carry the low 32 bits of the sender's time in
 * microseconds (wraps every 71.6 minutes). The senders share one epoch; by default the
 * receiver shares it too (one synchronised clock) and unwraps the field to the int64
 * time nearest its own current time, so the clocks may disagree by up to +-35 minutes
 * (rfs_can_unwrap_time). With follow_epoch (a microcontroller whose clock counts from
 * boot) the receiver keeps the offset between the senders' epoch and its clock instead
 * (docs/CAN.md, "Time on the bus"). Frames older than max_age_us, further than
 * max_future_us ahead, or older than the newest accepted frame of the same stream are
 * dropped and counted: the core then sees the inputs go stale and stops the wheels.
 *
 * Frames (id: sender -> receiver, DLC):
 *   0x100 WHEEL_CMD  controller -> motor controller, 6: wheel speeds mm/s
 *   0x110 POSE_XY    localisation -> controller, 8: x, y in mm (int24)
 *   0x111 POSE_TH    localisation -> controller, 8: heading (Q2.13 rad), time;
 *                    a pose is the POSE_XY + POSE_TH pair with the same counter,
 *                    XY sent first; it is complete when POSE_TH arrives
 *   0x120 RSSI       radio module -> controller, 8: source, dBm, sequence, time
 *   0x121 RX_STATUS  radio module -> controller, 6: capture time: the receiver was
 *                    listening up to then, packet or not (docs/FAULTS.md)
 *   0x130 CONFIG     operator -> controller, 8: target, fit_early, strategy, model, P0
 *                    floor, seed
 *                    (applied only before the mission's first decision)
 *   0x180 STATUS     controller -> anyone, 8: heartbeat with state, decision, faults
 * Lower ids win arbitration: wheel commands first, then inputs, then the heartbeat.
 */
#ifndef RFS_CAN_H
#define RFS_CAN_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_seek.h"
#include "rfs_store.h"

/// One classic CAN frame in our own type (no <linux/can.h> in the core).
typedef struct rfs_can_frame {
    uint32_t id;     ///< 11-bit standard identifier (0 .. 0x7FF)
    uint8_t dlc;     ///< data length, bytes (0 .. 8)
    uint8_t data[8]; ///< payload; bytes past dlc are zero in frames we encode
} rfs_can_frame_t;

#define RFS_CAN_ID_WHEEL_CMD 0x100u ///< wheel command, controller -> motor controller
#define RFS_CAN_ID_POSE_XY 0x110u   ///< pose, first half: position
#define RFS_CAN_ID_POSE_TH 0x111u   ///< pose, second half: heading and time
#define RFS_CAN_ID_RSSI 0x120u      ///< RSSI measurement from a radio module
#define RFS_CAN_ID_RX_STATUS 0x121u ///< receiver heartbeat from the radio module
#define RFS_CAN_ID_CONFIG 0x130u    ///< mission configuration, operator -> controller
#define RFS_CAN_ID_STATUS 0x180u    ///< controller status / heartbeat

#define RFS_CAN_DLC_WHEEL_CMD 6u ///< exact DLC of WHEEL_CMD
#define RFS_CAN_DLC_POSE_XY 8u   ///< exact DLC of POSE_XY
#define RFS_CAN_DLC_POSE_TH 8u   ///< exact DLC of POSE_TH
#define RFS_CAN_DLC_RSSI 8u      ///< exact DLC of RSSI
#define RFS_CAN_DLC_RX_STATUS 6u ///< exact DLC of RX_STATUS
#define RFS_CAN_DLC_CONFIG 8u    ///< exact DLC of CONFIG
#define RFS_CAN_DLC_STATUS 8u    ///< exact DLC of STATUS

#define RFS_CAN_ID_MAX 0x7FFu        ///< largest 11-bit id
#define RFS_CAN_POS_MM_MAX 8388607   ///< int24 position limit, mm (+-8.4 km)
#define RFS_CAN_POS_MM_MIN (-8388608) ///< int24 position limit, mm
#define RFS_CAN_MAX_SOURCES 16u      ///< source ids are 4 bits

/// WHEEL_CMD flags (data[0] bits 4..7).
#define RFS_CAN_WHEEL_STOP 0x1u ///< the controller is not driving (stale, learning, waiting): speeds are 0

/// Message index: one rolling counter and one set of statistics per frame id.
typedef enum rfs_can_msg_idx {
    RFS_CAN_IDX_WHEEL_CMD = 0,
    RFS_CAN_IDX_POSE_XY,
    RFS_CAN_IDX_POSE_TH,
    RFS_CAN_IDX_RSSI,
    RFS_CAN_IDX_STATUS,
    RFS_CAN_IDX_RX_STATUS,
    RFS_CAN_IDX_CONFIG,
    RFS_CAN_NMSG ///< number of message ids
} rfs_can_msg_idx_t;

/// Result of decoding a frame. Every non-OK result is a counted drop.
typedef enum rfs_can_err {
    RFS_CAN_OK = 0,        ///< accepted
    RFS_CAN_E_ID,          ///< not one of our ids (or not an 11-bit id)
    RFS_CAN_E_DLC,         ///< DLC differs from the layout's
    RFS_CAN_E_CHECKSUM,    ///< CRC-8 mismatch
    RFS_CAN_E_RANGE,       ///< a field is out of its documented range (enum value, reserved bits)
    RFS_CAN_E_REPEAT,      ///< counter equal to the previous frame's: a duplicate
    RFS_CAN_E_PAIR,        ///< POSE_TH without a POSE_XY of the same counter
    RFS_CAN_E_STALE,       ///< timestamp older than now - max_age_us
    RFS_CAN_E_FUTURE,      ///< timestamp later than now + max_future_us
    RFS_CAN_E_ORDER,       ///< timestamp older than the newest accepted of the same stream
    RFS_CAN_NERR           ///< number of results
} rfs_can_err_t;

/// Wheel command payload.
typedef struct rfs_can_wheel {
    int16_t left_mm_s;  ///< left wheel speed, mm/s (int16, +-32.7 m/s)
    int16_t right_mm_s; ///< right wheel speed, mm/s
    uint8_t flags;      ///< RFS_CAN_WHEEL_* bits (4 bits)
} rfs_can_wheel_t;

/// Pose as carried on the bus (both halves).
typedef struct rfs_can_pose {
    int32_t x_mm;       ///< x, millimetres, map frame, int24 range
    int32_t y_mm;       ///< y, millimetres, map frame, int24 range
    int16_t theta_q13;  ///< heading, radians Q2.13 (step 1.22e-4 rad), (-pi, pi]
    uint32_t t_us32;    ///< sender's time, low 32 bits of microseconds
} rfs_can_pose_t;

/// RSSI measurement as carried on the bus.
typedef struct rfs_can_rssi {
    uint8_t src;        ///< source id 0..15 (index into the target's sources)
    int8_t dbm;         ///< received signal strength, dBm
    uint8_t seq;        ///< radio module's packet sequence number, low 8 bits
    uint32_t t_us32;    ///< sender's time of reception, low 32 bits of microseconds
} rfs_can_rssi_t;

/// Receiver heartbeat (docs/CAN.md, "0x121 RX_STATUS"): sent by the radio module's capture
/// loop every 50-100 ms and at least once per the controller's rssi_timeout_us, only while
/// that loop runs.
typedef struct rfs_can_receiver {
    uint32_t t_us32;    ///< capture time the receiver was listening up to, low 32 bits of
                        ///< microseconds (the clock of the RSSI frames' t_us32)
} rfs_can_receiver_t;

/// CONFIG model codes: the internal models by registry name (rfs_models.h).
typedef enum rfs_can_model {
    RFS_CAN_MODEL_RIDGE = 0,    ///< "ridge", the paper's local ridge
    RFS_CAN_MODEL_MLP = 1,      ///< "mlp"
    RFS_CAN_MODEL_KNN = 2,      ///< "knn"
    RFS_CAN_MODEL_RADIUS = 3,   ///< "radius"
    RFS_CAN_MODEL_PATHLOSS = 4, ///< "pathloss", the map-aware path-loss model
    RFS_CAN_NMODELS             ///< number of codes (not a code)
} rfs_can_model_t;

/// CONFIG P0Min value meaning "no floor" (rfs_pathloss_cfg_t.p0_min INT32_MIN).
#define RFS_CAN_P0_NONE INT16_MIN
/// CONFIG P0Min limits, dBm / 128: [-200, 100] dBm, the simulator's --p0-min range.
#define RFS_CAN_P0_MIN (-200 * 128)
#define RFS_CAN_P0_MAX (100 * 128)

/// CONFIG FitEarly values (docs/CAN.md, "0x130 CONFIG"): seek.fit_early as the controller
/// had it (so a frame without the field means what it always meant), off or on; 3 is
/// reserved (refused).
typedef enum rfs_can_fit_early {
    RFS_CAN_FIT_EARLY_KEEP = 0, ///< the controller's own setting
    RFS_CAN_FIT_EARLY_OFF = 1,  ///< seek.fit_early false
    RFS_CAN_FIT_EARLY_ON = 2    ///< seek.fit_early true
} rfs_can_fit_early_t;

/// Mission configuration (docs/CAN.md, "0x130 CONFIG"): what the controller runs.
typedef struct rfs_can_config {
    uint8_t target;     ///< rfs_app target: 0 rssi, 1 bridge
    uint8_t strategy;   ///< rfs_seek_strategy_t, 0..RFS_SEEK_STRATEGY_COUNT-1
    uint8_t model;      ///< rfs_can_model_t
    int16_t p0_min;     ///< path-loss floor on the signal at 1 m, dBm / 128, in
                        ///< [RFS_CAN_P0_MIN, RFS_CAN_P0_MAX] or RFS_CAN_P0_NONE
    uint32_t seed;      ///< seed of the controller's random source, 24 bits
    uint8_t fit_early;  ///< rfs_can_fit_early_t, 0..2
} rfs_can_config_t;

/// Controller heartbeat.
typedef struct rfs_can_status {
    uint8_t state;       ///< rfs_seek_state_t, 0..3
    uint8_t kind;        ///< the latest decision's kind, 0..3 (rfs_can_status_kind)
    uint8_t prev;        ///< rfs_drive_status_t: how the previous goal ended, 0..4
    bool relearned;      ///< the latest decision relearnt the model
    bool line_search;    ///< the latest greedy goal came from the line search
    uint8_t faults;      ///< RFS_SEEK_FAULT_* bits (low 8)
    uint32_t iteration;  ///< iteration number of the latest decision
    bool configured;     ///< a CONFIG frame was applied (false: the controller's own, as after a reset)
} rfs_can_status_t;

/// CRC-8/SAE-J1850 of n bytes (poly 0x1D, init 0xFF, xorout 0xFF). Check value:
/// "123456789" gives 0x4B.
uint8_t rfs_can_crc8(const uint8_t *p, uint32_t n);

/// The checksum a frame with this id, dlc and data must carry in data[dlc-1].
/// dlc must be 1..8. Table-driven (256-byte const table).
uint8_t rfs_can_checksum(uint32_t id, uint8_t dlc, const uint8_t *data);

/// The same checksum computed bit by bit (no table: 256 bytes less flash, about 6x the
/// instructions; docs/PERFORMANCE.md). Identical results.
uint8_t rfs_can_checksum_bitwise(uint32_t id, uint8_t dlc, const uint8_t *data);

/// Encoders: fill f completely (id, exact DLC, payload, zero padding, checksum) with the
/// given 4-bit counter (only its low 4 bits are used). Values out of a field's range are
/// saturated (positions to int24) or masked (flags, enum values) - they cannot fail.
void rfs_can_pack_wheel(const rfs_can_wheel_t *w, uint8_t counter, rfs_can_frame_t *f);
/// Encode POSE_XY from p (x_mm, y_mm).
void rfs_can_pack_pose_xy(const rfs_can_pose_t *p, uint8_t counter, rfs_can_frame_t *f);
/// Encode POSE_TH from p (theta_q13, t_us32).
void rfs_can_pack_pose_th(const rfs_can_pose_t *p, uint8_t counter, rfs_can_frame_t *f);
/// Encode RSSI.
void rfs_can_pack_rssi(const rfs_can_rssi_t *r, uint8_t counter, rfs_can_frame_t *f);
/// Encode RX_STATUS.
void rfs_can_pack_receiver(const rfs_can_receiver_t *r, uint8_t counter, rfs_can_frame_t *f);
/// Encode CONFIG (target, fit_early, strategy and model masked to their fields, seed to
/// 24 bits).
void rfs_can_pack_config(const rfs_can_config_t *c, uint8_t counter, rfs_can_frame_t *f);
/// Encode STATUS.
void rfs_can_pack_status(const rfs_can_status_t *s, uint8_t counter, rfs_can_frame_t *f);

/// Stateless decoders: check id, DLC, checksum and field ranges, then fill the payload
/// and *counter. On error the outputs are untouched.
rfs_can_err_t rfs_can_unpack_wheel(const rfs_can_frame_t *f, rfs_can_wheel_t *w, uint8_t *counter);
/// Decode POSE_XY into p->x_mm, p->y_mm.
rfs_can_err_t rfs_can_unpack_pose_xy(const rfs_can_frame_t *f, rfs_can_pose_t *p, uint8_t *counter);
/// Decode POSE_TH into p->theta_q13, p->t_us32.
rfs_can_err_t rfs_can_unpack_pose_th(const rfs_can_frame_t *f, rfs_can_pose_t *p, uint8_t *counter);
/// Decode RSSI.
rfs_can_err_t rfs_can_unpack_rssi(const rfs_can_frame_t *f, rfs_can_rssi_t *r, uint8_t *counter);
/// Decode RX_STATUS (data[0] bits 4..7 are reserved, zero).
rfs_can_err_t rfs_can_unpack_receiver(const rfs_can_frame_t *f, rfs_can_receiver_t *r, uint8_t *counter);
/// Decode CONFIG: target above 1, FitEarly 3, strategy or model without a value, P0Min
/// outside its limits (and not RFS_CAN_P0_NONE) are RFS_CAN_E_RANGE.
rfs_can_err_t rfs_can_unpack_config(const rfs_can_frame_t *f, rfs_can_config_t *c, uint8_t *counter);
/// Decode STATUS.
rfs_can_err_t rfs_can_unpack_status(const rfs_can_frame_t *f, rfs_can_status_t *s, uint8_t *counter);

/// Low 32 bits of a time in microseconds, as carried on the bus.
static inline uint32_t rfs_can_wrap_time(int64_t t_us) { return (uint32_t)(uint64_t)t_us; }

/// The int64 time t (microseconds) with (uint32)t == raw that is nearest ref_us:
/// t - ref_us lies in [-2^31, 2^31). Saturates instead of overflowing near INT64 limits.
int64_t rfs_can_unwrap_time(int64_t ref_us, uint32_t raw);

/// Millimetres to metres Q16.16, rounded to nearest.
/// Scaling and overflow: mm * 65536 in int64 (exact for int32 mm), / 1000 rounded;
/// saturated to Q16.16 (+-32767 m; int24 mm input never saturates).
rfs_q16_t rfs_can_mm_to_q16(int32_t mm);

/// Metres Q16.16 to millimetres, rounded to nearest, saturated to the int24 range.
/// Scaling and overflow: q * 1000 in int64 (exact), / 65536 rounded; int24-saturated.
int32_t rfs_can_q16_to_mm(rfs_q16_t q);

/// Heading Q16.16 radians to the bus's Q2.13, rounded to nearest, saturated to int16.
/// Scaling and overflow: (q + 4) >> 3 in int64; |theta| <= pi gives |raw| <= 25736.
int16_t rfs_can_q16_to_theta(rfs_q16_t q);

/// Heading Q2.13 to Q16.16 (exact: << 3). Scaling and overflow: int16 << 3 fits int32.
static inline rfs_q16_t rfs_can_theta_to_q16(int16_t theta_q13) { return (rfs_q16_t)theta_q13 * 8; }

/// Bus pose to the core's pose; t_us is the unwrapped time (rfs_can_unwrap_time).
rfs_pose_t rfs_can_pose_to_core(const rfs_can_pose_t *p, int64_t t_us);

/// Core pose to the bus pose (rounded, saturated).
rfs_can_pose_t rfs_can_pose_from_core(const rfs_pose_t *pose);

/// The STATUS frame's 2-bit Kind of a decision kind: none, initial, greedy and epsilon as
/// themselves, a baseline strategy's gradient and run as greedy, probe and tumble as
/// epsilon (docs/CAN.md, "0x180 STATUS"); a value beyond the kinds as none.
uint8_t rfs_can_status_kind(rfs_seek_kind_t k);

/// Heartbeat and wheel command from one control period's output (a baseline strategy's
/// decision kinds as greedy or epsilon: docs/CAN.md, "0x180 STATUS"); every field is
/// written, configured false (the application knows whether a CONFIG was applied).
void rfs_can_from_seek_out(const rfs_seek_out_t *out, rfs_can_status_t *status, rfs_can_wheel_t *wheel);

/// Sender side: one rolling counter per message id.
typedef struct rfs_can_tx {
    uint8_t counter[RFS_CAN_NMSG]; ///< next counter to send per message, 0..15
} rfs_can_tx_t;

/// Start every counter at 0.
void rfs_can_tx_init(rfs_can_tx_t *tx);

/// Encode with the next counter of that message and advance it.
void rfs_can_tx_wheel(rfs_can_tx_t *tx, const rfs_can_wheel_t *w, rfs_can_frame_t *f);
/// Encode one pose as its two frames (XY then TH) with the same counter; advances both.
void rfs_can_tx_pose(rfs_can_tx_t *tx, const rfs_can_pose_t *p, rfs_can_frame_t *xy, rfs_can_frame_t *th);
/// Encode an RSSI measurement with the next counter.
void rfs_can_tx_rssi(rfs_can_tx_t *tx, const rfs_can_rssi_t *r, rfs_can_frame_t *f);
/// Encode a receiver heartbeat with the next counter.
void rfs_can_tx_receiver(rfs_can_tx_t *tx, const rfs_can_receiver_t *r, rfs_can_frame_t *f);
/// Encode a configuration with the next counter.
void rfs_can_tx_config(rfs_can_tx_t *tx, const rfs_can_config_t *c, rfs_can_frame_t *f);
/// Encode a heartbeat with the next counter.
void rfs_can_tx_status(rfs_can_tx_t *tx, const rfs_can_status_t *s, rfs_can_frame_t *f);

/// Receiver configuration.
typedef struct rfs_can_rx_cfg {
    int64_t max_age_us;     ///< drop timestamped frames older than now - this (1 s: the RSSI window)
    int64_t max_future_us;  ///< drop timestamped frames later than now + this (100 ms of clock skew)
    /// false (default): the senders' stamps are in the receiver's own clock. true: in an
    /// epoch of their own, followed as an offset to the receiver's clock: set by the first
    /// time-bearing frame (its age 0), moved at once by a frame from the future (its age
    /// made 0), back by at most 1/2048 of the elapsed time (about 490 ppm) towards an
    /// older one, re-set after resync_us without a fresh frame (docs/CAN.md).
    bool follow_epoch;
    int64_t resync_us;      ///< follow_epoch: re-set the offset when every time-bearing frame
                            ///< has missed the window (stale, future, order, or accepted
                            ///< more than max_future_us old) for this long (2 s)
} rfs_can_rx_cfg_t;

/// Per-message receive statistics.
typedef struct rfs_can_rx_stats {
    uint32_t accepted;      ///< frames accepted
    uint32_t counter_jumps; ///< accepted frames whose counter was not previous + 1
    uint32_t lost;          ///< frames missing according to the counter jumps (sum of gaps)
} rfs_can_rx_stats_t;

/// Receiver state: caller-owned, no pointers.
typedef struct rfs_can_rx {
    rfs_can_rx_cfg_t cfg;                      ///< configuration copied at init
    rfs_can_rx_stats_t msg[RFS_CAN_NMSG];      ///< statistics per message id
    uint32_t dropped[RFS_CAN_NERR];            ///< drops per reason (index 0 unused)
    uint8_t last_counter[RFS_CAN_NMSG];        ///< last accepted counter per message
    bool have_counter[RFS_CAN_NMSG];           ///< last_counter is valid
    rfs_can_pose_t pending;                    ///< POSE_XY waiting for its POSE_TH
    uint8_t pending_counter;                   ///< its counter
    bool have_pending;                         ///< pending is valid
    int64_t last_pose_us;                      ///< newest accepted pose time, microseconds
    bool have_pose;                            ///< last_pose_us is valid
    int64_t last_rssi_us[RFS_CAN_MAX_SOURCES]; ///< newest accepted RSSI time per source
    uint16_t have_rssi;                        ///< bit per source: last_rssi_us valid
    uint8_t last_seq[RFS_CAN_MAX_SOURCES];     ///< last RSSI sequence number per source
    uint32_t rssi_seq_gaps;                    ///< radio packets missing by sequence number
    int64_t last_receiver_us;                  ///< newest accepted RX_STATUS time, microseconds
    bool have_receiver;                        ///< last_receiver_us is valid
    uint32_t epoch_off;                        ///< follow_epoch: senders' minus local time, us mod 2^32
    bool have_epoch;                           ///< follow_epoch: epoch_off is set
    bool have_late;                            ///< a time-bearing frame missed the window since
                                               ///< the last fresh one (late_us is valid)
    int64_t late_us;                           ///< local time of the first such frame
    int64_t pull_us;                           ///< local time the offset's pull-back allowance runs from
    uint32_t resyncs;                          ///< offset re-set after resync_us of missed frames
} rfs_can_rx_t;

/// What a received frame produced.
typedef enum rfs_can_msg_kind {
    RFS_CAN_MSG_NONE = 0, ///< nothing complete (a dropped frame, or the first pose half)
    RFS_CAN_MSG_WHEEL,    ///< a wheel command
    RFS_CAN_MSG_POSE,     ///< a complete pose (in the core's units)
    RFS_CAN_MSG_RSSI,     ///< an RSSI measurement with an unwrapped time
    RFS_CAN_MSG_STATUS,   ///< a controller heartbeat
    RFS_CAN_MSG_RECEIVER, ///< a receiver heartbeat with an unwrapped time
    RFS_CAN_MSG_CONFIG,   ///< a mission configuration
} rfs_can_msg_kind_t;

/// A decoded message, ready for the core.
typedef struct rfs_can_msg {
    rfs_can_msg_kind_t kind; ///< which member is valid
    rfs_can_wheel_t wheel;   ///< RFS_CAN_MSG_WHEEL
    rfs_pose_t pose;         ///< RFS_CAN_MSG_POSE: Q16.16 metres/radians, int64 us
    rfs_can_status_t status; ///< RFS_CAN_MSG_STATUS
    uint8_t rssi_src;        ///< RFS_CAN_MSG_RSSI: source id
    int8_t rssi_dbm;         ///< RFS_CAN_MSG_RSSI: dBm
    uint8_t rssi_seq;        ///< RFS_CAN_MSG_RSSI: sequence number
    int64_t rssi_t_us;       ///< RFS_CAN_MSG_RSSI: unwrapped time, microseconds
    int64_t receiver_t_us;   ///< RFS_CAN_MSG_RECEIVER: unwrapped capture time, microseconds
    rfs_can_config_t config; ///< RFS_CAN_MSG_CONFIG
} rfs_can_msg_t;

/// Defaults: max_age 1 s, max_future 100 ms, follow_epoch off, resync 2 s.
rfs_can_rx_cfg_t rfs_can_rx_cfg_default(void);

/// Initialise. Returns 0, or -1 when max_age_us or resync_us is not in (0, 1 h] or
/// max_future_us is not in [0, 1 h] (unwrapping is unambiguous only within +-35 minutes).
int rfs_can_rx_init(rfs_can_rx_t *rx, const rfs_can_rx_cfg_t *cfg);

/// Decode one received frame at receiver time now_us (microseconds). Cannot fail: every
/// rejection is returned and counted in rx->dropped[]; msg->kind says what is complete.
rfs_can_err_t rfs_can_rx_frame(rfs_can_rx_t *rx, const rfs_can_frame_t *f, int64_t now_us,
                               rfs_can_msg_t *msg);

/// Total frames dropped for any reason.
uint32_t rfs_can_rx_dropped_total(const rfs_can_rx_t *rx);

/// Registry name of a CONFIG model code ("ridge", ... "pathloss"); NULL beyond the codes.
const char *rfs_can_model_name(uint8_t code);

/// CONFIG P0Min (dBm / 128) as the path-loss model's p0_min, dBm Q16.16 (INT32_MIN for
/// RFS_CAN_P0_NONE). Scaling and overflow: raw x 512, exact; |raw| <= 2^15 fits int32.
rfs_q16_t rfs_can_p0_to_q16(int16_t raw);

/// Short constant name of a result ("ok", "id", "dlc", "checksum", ...).
const char *rfs_can_err_str(rfs_can_err_t e);

#endif /* RFS_CAN_H */
