/* lx_lcm.h - LCM messaging and LCM log files in our own types (Linux only).
 *
 * firmware/port/linux/lx_lcm.c is the only file that includes the LCM headers and the
 * lcm-gen types of lcm/<type>.lcm; nothing of LCM crosses this header. Channels:
 *   RFS_POSE            rfseek.pose_t           localisation -> controller
 *   RFS_RSSI            rfseek.rssi_t           radio module -> controller
 *   RFS_RSSI_STATUS     rfseek.rssi_status_t    radio module -> controller: receiver
 *                                               heartbeat (docs/FAULTS.md)
 *   RFS_CLOCK           rfseek.clock_t          lock-step simulator -> controller
 *   RFS_WHEEL_CMD       rfseek.wheel_cmd_t      controller -> logs (copy of the CAN frame)
 *   RFS_SEEKER_STATUS   rfseek.seeker_status_t  controller -> anyone
 *   RFS_CAN_FALLBACK    rfseek.can_frame_t      raw CAN frames when there is no SocketCAN
 * Every received message is decoded and checked (type fingerprint, length, finite
 * numbers, field ranges); a bad one is dropped, counted, and described in one line
 * "CHANNEL: reason" (lx_lcm_stats_t.last_error) - never a crash, never a silent drop.
 */
#ifndef LX_LCM_H
#define LX_LCM_H

#include <stddef.h>
#include <stdint.h>

#include "rfs_can.h"
#include "rfs_fields.h"
#include "rfs_pathloss.h"
#include "rfs_seek.h"

#define LX_LCM_CH_POSE "RFS_POSE"                 ///< pose channel
#define LX_LCM_CH_RSSI "RFS_RSSI"                 ///< RSSI channel
#define LX_LCM_CH_RSSI_STATUS "RFS_RSSI_STATUS"   ///< receiver heartbeat channel
#define LX_LCM_CH_CLOCK "RFS_CLOCK"               ///< lock-step clock channel
#define LX_LCM_CH_WHEEL "RFS_WHEEL_CMD"           ///< wheel command copy
#define LX_LCM_CH_STATUS "RFS_SEEKER_STATUS"      ///< seeker status
#define LX_LCM_CH_CAN_FALLBACK "RFS_CAN_FALLBACK" ///< raw CAN frames, fallback transport

/// Callbacks for received messages; NULL ones are not subscribed. ctx is passed back.
typedef struct lx_lcm_handlers {
    void *ctx;                                                                  ///< user state
    void (*on_pose)(void *ctx, const rfs_pose_t *pose);                         ///< RFS_POSE
    void (*on_rssi)(void *ctx, uint8_t src, int64_t t_us, int8_t dbm, uint32_t seq); ///< RFS_RSSI
    void (*on_clock)(void *ctx, int64_t t_us);                                  ///< RFS_CLOCK
    void (*on_wheel)(void *ctx, int64_t t_us, const rfs_can_wheel_t *w);        ///< RFS_WHEEL_CMD
    void (*on_status)(void *ctx, int64_t t_us, const rfs_seek_out_t *out);      ///< RFS_SEEKER_STATUS
    void (*on_can)(void *ctx, int64_t t_us, const rfs_can_frame_t *f);          ///< RFS_CAN_FALLBACK
    /// A message was dropped; `why` is the one-line "CHANNEL: reason". May be NULL.
    void (*on_bad)(void *ctx, const char *why);
    /// RFS_RSSI_STATUS: the receiver was listening up to capture time t_us (a heartbeat;
    /// seq is the sender's heartbeat count).
    void (*on_receiver)(void *ctx, int64_t t_us, uint32_t seq);
    /// With on_status: the path-loss estimate a status carried (est_valid), delivered
    /// after on_status for the same message. May be NULL.
    void (*on_estimate)(void *ctx, int64_t t_us, const rfs_pathloss_est_t *est);
} lx_lcm_handlers_t;

/// Receive counters.
typedef struct lx_lcm_stats {
    uint32_t received;       ///< messages decoded and delivered
    uint32_t bad;            ///< messages dropped (undecodable, out of range)
    char last_error[160];    ///< the latest drop's "CHANNEL: reason" ("" when none)
} lx_lcm_stats_t;

/// An LCM connection (opaque).
typedef struct lx_lcm lx_lcm_t;

/// An LCM log file (lcm-logger / lcm-logplayer format), opaque.
typedef struct lx_lcm_log lx_lcm_log_t;

/// Open an LCM provider URL (memq://, file://..., udpm://...; NULL = LCM's default) and
/// subscribe to the channels whose handler is set. What liblcm itself prints on stderr
/// meanwhile (a bad provider or option, multicast set-up) is captured, not shown: err
/// always ends as one line (control characters of the URL or of liblcm's text as '?').
/// Failure: NULL, err = "lcm: URL: reason" plus " (liblcm: TEXT)" when liblcm said why.
/// Success: the connection, err = "" - or, when liblcm warned (e.g. "Warning: Invalid
/// value for ttl"), err = "lcm: URL: liblcm: TEXT", a warning for the caller to print.
lx_lcm_t *lx_lcm_open(const char *url, const lx_lcm_handlers_t *h, char *err, size_t errlen);

/// Also write every message published or delivered to this log (NULL stops recording).
/// Event timestamps are the messages' own utime.
void lx_lcm_record(lx_lcm_t *l, lx_lcm_log_t *log);

/// Publishers; each returns 0, or -1 when LCM refused the message.
int lx_lcm_pub_pose(lx_lcm_t *l, const rfs_pose_t *pose);
/// Publish an RSSI measurement.
int lx_lcm_pub_rssi(lx_lcm_t *l, uint8_t src, int64_t t_us, int8_t dbm, uint32_t seq);
/// Publish a receiver heartbeat: the capture loop was listening up to t_us (the
/// packets' clock); seq counts the sender's heartbeats.
int lx_lcm_pub_receiver(lx_lcm_t *l, int64_t t_us, uint32_t seq);
/// Publish a lock-step clock tick.
int lx_lcm_pub_clock(lx_lcm_t *l, int64_t t_us);
/// Publish the wheel command copy.
int lx_lcm_pub_wheel(lx_lcm_t *l, int64_t t_us, const rfs_can_wheel_t *w);
/// Publish a status (decision record and command of one control step).
int lx_lcm_pub_status(lx_lcm_t *l, int64_t t_us, const rfs_seek_out_t *out);
/// Publish a status with the path-loss model's estimate (est) and the per-node model's
/// predicted bridging point (bridge, rfs_fields.h); a NULL one publishes its valid flag
/// false and zero fields, like lx_lcm_pub_status().
int lx_lcm_pub_status_est(lx_lcm_t *l, int64_t t_us, const rfs_seek_out_t *out,
                          const rfs_pathloss_est_t *est, const rfs_fields_est_t *bridge);
/// Publish a raw CAN frame on the fallback channel.
int lx_lcm_pub_can(lx_lcm_t *l, int64_t t_us, const rfs_can_frame_t *f);

/// Publish raw bytes on a channel (tools and tests: malformed-input checks, fuzzing);
/// recorded like the typed publishers with event time t_us. Returns 0 or -1.
int lx_lcm_pub_raw(lx_lcm_t *l, int64_t t_us, const char *channel, const void *data, size_t len);

/// Wait up to timeout_ms for one message and dispatch it. Returns 1 when one was
/// handled, 0 on timeout or when a signal interrupted the wait, -1 on an LCM error.
int lx_lcm_handle(lx_lcm_t *l, int timeout_ms);

/// Copy the receive counters.
void lx_lcm_get_stats(const lx_lcm_t *l, lx_lcm_stats_t *s);

/// Close (NULL is ignored).
void lx_lcm_close(lx_lcm_t *l);

/// Open a log for reading ("r") or writing ("w"). Writing goes to PATH.tmp and is
/// renamed to PATH by lx_lcm_log_close(); a log that is never closed leaves no PATH.
/// Returns NULL with err = "PATH: reason".
lx_lcm_log_t *lx_lcm_log_open(const char *path, const char *mode, char *err, size_t errlen);

/// Read the next event and dispatch it through h like a received message (same checks
/// and counters in *stats, which may be NULL). *t_us is the event's timestamp.
/// Returns 1 per event (delivered or dropped), 0 at the end of the log, -1 when the rest
/// is not a log (garbage, an event cut short, a channel name of 1000 bytes or more; the
/// reason from lx_lcm_log_error()).
int lx_lcm_log_next(lx_lcm_log_t *log, const lx_lcm_handlers_t *h, lx_lcm_stats_t *stats, int64_t *t_us);

/// Read the next event without decoding it: its time, channel (NUL-terminated, cut to
/// chcap - 1) and up to cap bytes of data (*len is the full length). Returns 1, 0 at the
/// end of the log, or -1 as lx_lcm_log_next().
int lx_lcm_log_next_raw(lx_lcm_log_t *log, int64_t *t_us, char *channel, size_t chcap, void *data, size_t cap,
                        size_t *len);

/// Why reading stopped early ("offset N: reason"), after lx_lcm_log_next() returned -1.
const char *lx_lcm_log_error(const lx_lcm_log_t *log);

/// Close; for a written log, flush and rename PATH.tmp to PATH. Returns 0, or -1 when a
/// write failed (PATH.tmp removed: nothing half-written is left).
int lx_lcm_log_close(lx_lcm_log_t *log);

#endif /* LX_LCM_H */
