/* lx_can.h - SocketCAN transport in our own types (Linux only).
 *
 * Five functions; firmware/port/linux/lx_can.c is the only file that includes
 * <linux/can.h>. A CAN_RAW socket bound to an interface by name, kernel receive filters
 * for our standard ids (data frames only), non-blocking I/O with poll timeouts. Error
 * frames are decoded into lx_can_health_t; when the interface is down, gone or bus-off,
 * sends are refused and counted while the adapter retries (re-resolving the interface
 * and re-binding) with exponential backoff (10 ms doubling to 1 s; after bus-off the
 * first probe waits 100 ms, a typical restart-ms). Nothing is dropped
 * silently: every frame not sent or not delivered is counted.
 */
#ifndef LX_CAN_H
#define LX_CAN_H

#include <stddef.h>
#include <stdint.h>

#include "rfs_can.h"

/// An open CAN channel (opaque).
typedef struct lx_can lx_can_t;

/// Link condition as last observed.
typedef enum lx_can_link {
    LX_CAN_LINK_OK = 0,     ///< sending and receiving
    LX_CAN_LINK_PASSIVE,    ///< controller reported error-warning/passive (still works)
    LX_CAN_LINK_BUS_OFF,    ///< controller reported bus-off: waiting for recovery
    LX_CAN_LINK_DOWN,       ///< interface down or gone: retrying with backoff
} lx_can_link_t;

/// Health report and counters since open.
typedef struct lx_can_health {
    lx_can_link_t link;        ///< current condition
    uint32_t tx_frames;        ///< frames handed to the kernel
    uint32_t tx_failed;        ///< frames refused (down, bus-off, backoff, queue full)
    uint32_t rx_frames;        ///< data frames delivered to the caller
    uint32_t rx_foreign;       ///< frames discarded: extended/RTR/FD/ids outside the filter
    uint32_t err_frames;       ///< error frames received
    uint32_t bus_off;          ///< bus-off events
    uint32_t recoveries;       ///< times the link came back after being down or bus-off
    int last_errno;            ///< errno of the last failed system call (0 = none)
    int64_t backoff_us;        ///< current retry interval, microseconds (0 when healthy)
} lx_can_health_t;

/// Open a CAN_RAW socket on interface `ifname` receiving only the standard-id data
/// frames in ids[0..nids-1] (nids == 0: every standard data frame), plus error frames.
/// Returns NULL and writes one line "can: IFNAME: reason" into err (errlen bytes) when
/// the interface does not exist, is not CAN, or the socket cannot be made.
lx_can_t *lx_can_open(const char *ifname, const uint32_t *ids, size_t nids, char *err, size_t errlen);

/// Send one frame. Returns 0 when queued, -1 when refused (counted in tx_failed; see
/// lx_can_health for why). Never blocks; a refused send starts or continues recovery.
int lx_can_send(lx_can_t *c, const rfs_can_frame_t *f);

/// Wait up to timeout_ms (0 = poll once) for one of our data frames. Returns 1 with *f
/// filled, 0 on timeout, -1 when the link is down (counted; recovery is attempted).
/// Error frames are consumed into the health report, not returned.
int lx_can_recv(lx_can_t *c, rfs_can_frame_t *f, int timeout_ms);

/// Copy the health report; also attempts a due recovery. Returns the link condition.
lx_can_link_t lx_can_health(lx_can_t *c, lx_can_health_t *h);

/// Close the socket and free the channel (NULL is ignored).
void lx_can_close(lx_can_t *c);

#endif /* LX_CAN_H */
