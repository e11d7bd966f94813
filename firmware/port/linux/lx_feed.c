/* lx_feed.c - a capture's RSSI and the receiver heartbeat on LCM (lx_feed.h). */
#include "lx_feed.h"

#include <string.h>

bool lx_feed_hb_due(lx_feed_hb_t *hb, int64_t t_us)
{
    /* Both times are capture times (>= 0): the difference cannot overflow. */
    if (hb->have && t_us - hb->last_us < LX_FEED_HEARTBEAT_US) {
        return false;
    }
    hb->have = true;
    hb->last_us = t_us;
    return true;
}

void lx_feed_init(lx_feed_t *f, lx_lcm_t *lcm)
{
    memset(f, 0, sizeof(*f));
    f->lcm = lcm;
}

int lx_feed_frame(lx_feed_t *f, uint8_t src, int64_t t_us, int8_t dbm, uint16_t seq)
{
    if (lx_lcm_pub_rssi(f->lcm, src, t_us, dbm, seq) != 0) {
        f->st.refused++;
        return -1;
    }
    f->st.rssi++;
    return 0;
}

int lx_feed_alive(lx_feed_t *f, int64_t t_us)
{
    const lx_feed_hb_t before = f->hb;
    if (!lx_feed_hb_due(&f->hb, t_us)) {
        return 0;
    }
    if (lx_lcm_pub_receiver(f->lcm, t_us, f->hb_seq) != 0) {
        f->hb = before; /* not sent: due again at the next call */
        f->st.refused++;
        return -1;
    }
    f->hb_seq++;
    f->st.heartbeats++;
    return 1;
}
