/* hs_ctrl_lcm.h - the controller in a separate process: an hs_ctrl_t that
 * publishes the simulated sensors on LCM and takes the wheel commands from CAN.
 *
 * on_pose / on_rssi / on_receiver publish RFS_POSE / RFS_RSSI / RFS_RSSI_STATUS (the
 * receiver heartbeat). step(now) publishes RFS_CLOCK(now) and
 * waits for the controller process (rfseekd --clock-lcm) to answer that step: the
 * WHEEL_CMD frame arrives as the simulated motor controller node would see it - from
 * SocketCAN when an interface is given, else from the clearly named LCM fallback channel
 * RFS_CAN_FALLBACK carrying raw CAN frames - and the decision record from
 * RFS_SEEKER_STATUS. Lock-step keeps the two-process run deterministic. When no answer
 * comes within reply_timeout_ms the step commands zero and counts a timeout.
 */
#ifndef HS_CTRL_LCM_H
#define HS_CTRL_LCM_H

#include <stddef.h>
#include <stdint.h>

#include "hs_ctrl.h"

/// Configuration of the two-process controller.
typedef struct hs_ctrl_lcm_cfg {
    const char *lcm_url;     ///< LCM provider (udpm://... in a private netns for tests)
    const char *can_iface;   ///< SocketCAN interface for wheel commands; NULL: RFS_CAN_FALLBACK
    int64_t period_us;       ///< control period, microseconds (50,000)
    int reply_timeout_ms;    ///< wait for the controller's answer to one step (5,000)
    /// Program name that starts this controller's stderr lines (a dropped message, the
    /// first unanswered step), as "PROG: ..."; NULL: the lines start with the text. Kept,
    /// not copied: it must outlive the controller (a string literal).
    const char *prog;
} hs_ctrl_lcm_cfg_t;

/// Defaults: LCM's default URL, the LCM fallback for CAN, 20 Hz, 5 s reply timeout, no
/// program name.
hs_ctrl_lcm_cfg_t hs_ctrl_lcm_cfg_default(void);

/// Open. Returns -1 with err = "lcm: ..." / "can: ..." (one line), or 0 with err = "" or
/// liblcm's warning "lcm: URL: liblcm: ..." (one line, to print; see lx_lcm_open()).
int hs_ctrl_lcm_open(hs_ctrl_t *c, const hs_ctrl_lcm_cfg_t *cfg, char *err, size_t errlen);

/// Steps that got no answer in time (the wheels were commanded to zero).
uint32_t hs_ctrl_lcm_timeouts(const hs_ctrl_t *c);

#endif /* HS_CTRL_LCM_H */
