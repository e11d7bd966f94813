/* lx_feed.h - the radio module's side of LCM: a capture's RSSI and the receiver heartbeat,
 * published as rfseekd reads them (docs/FEEDER.md, "Live to the controller").
 *
 * The capture loop calls lx_feed_frame() for every frame from a chosen source that carries
 * a dBm signal (RFS_RSSI), and lx_feed_alive() whenever it knows itself alive: after every
 * record it reads, from any transmitter, and after every read that timed out. A heartbeat
 * (RFS_RSSI_STATUS) goes out when that time has moved LX_FEED_HEARTBEAT_US past the last
 * one: with the live reader's 25 ms wait (LX_PCAP_LIVE_TIMEOUT_MS) one every 50 to 75 ms
 * plus scheduling delays, inside the controller's 150 ms RSSI timeout, whether or not a
 * source is heard; a loop that hangs or dies sends none (docs/FAULTS.md, "The receiver
 * heartbeat").
 */
#ifndef LX_FEED_H
#define LX_FEED_H

#include <stdbool.h>
#include <stdint.h>

#include "lx_lcm.h"

/// Shortest spacing of two heartbeats, microseconds of the capture clock.
#define LX_FEED_HEARTBEAT_US 50000

/// The heartbeat rule's state: the time of the last heartbeat due.
typedef struct lx_feed_hb {
    int64_t last_us; ///< capture clock, microseconds
    bool have;       ///< a heartbeat was due before
} lx_feed_hb_t;

/// Whether a heartbeat is due at t_us: the first call, or t_us at least
/// LX_FEED_HEARTBEAT_US after the last due one (an earlier t_us never). Remembers t_us
/// when due.
bool lx_feed_hb_due(lx_feed_hb_t *hb, int64_t t_us);

/// What a feed published.
typedef struct lx_feed_stats {
    uint64_t rssi;       ///< RFS_RSSI messages published
    uint64_t heartbeats; ///< RFS_RSSI_STATUS messages published
    uint64_t refused;    ///< messages LCM refused (not sent)
} lx_feed_stats_t;

/// A feed publishing on one LCM connection (caller-owned; lx_feed_init fills it).
typedef struct lx_feed {
    lx_lcm_t *lcm;      ///< the connection (not owned)
    lx_feed_hb_t hb;    ///< the heartbeat rule
    uint32_t hb_seq;    ///< the next heartbeat's count (rssi_status_t.seq)
    lx_feed_stats_t st; ///< counters
} lx_feed_t;

/// Start a feed on `lcm`: no heartbeat sent yet, counters zero.
void lx_feed_init(lx_feed_t *f, lx_lcm_t *lcm);

/// Publish one frame's RSSI: source index src (the --mac's position), capture time t_us,
/// the dBm antenna signal and the 802.11 sequence number. 0, or -1 when LCM refused it
/// (counted).
int lx_feed_frame(lx_feed_t *f, uint8_t src, int64_t t_us, int8_t dbm, uint16_t seq);

/// The capture loop is alive at capture time t_us: publish a heartbeat when one is due
/// (lx_feed_hb_due). 1 when one was sent, 0 when none was due, -1 when LCM refused it
/// (counted; the next call tries again).
int lx_feed_alive(lx_feed_t *f, int64_t t_us);

#endif /* LX_FEED_H */
