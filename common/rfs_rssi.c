/* rfs_rssi.c - the exact 1-second mean per source (paper section 2; see rfs_rssi.h).
 *
 * Timestamps are kept as their low 32 bits. Every push drops the entries that left the
 * window ending at the pushed (newest) time, so every kept entry is younger than
 * window_us (<= 60 s) relative to last_us; a query at now_us >= last_us + window_us
 * finds nothing, and any other query sees ages below 2 * 60 s < 2^31 us. The 32-bit
 * differences are therefore exact, whatever the absolute time.
 */
#include "rfs_rssi.h"

#include "rfs_assert.h"

/// Largest window accepted by init: keeps every age in the ring below 2^31 us.
#define RSSI_WINDOW_MAX_US 60000000u

rfs_rssi_cfg_t rfs_rssi_cfg_default(void)
{
    rfs_rssi_cfg_t c;
    c.window_us = 1000000u; /* paper section 2: "mean signal strength over the last second" */
    return c;
}

int rfs_rssi_init(rfs_rssi_t *w, const rfs_rssi_cfg_t *cfg)
{
    if (w == 0 || cfg == 0 || cfg->window_us == 0u || cfg->window_us > RSSI_WINDOW_MAX_US) {
        return -1;
    }
    w->cfg = *cfg;
    w->head = 0u;
    w->count = 0u;
    w->sum_dbm = 0;
    w->last_us = 0;
    w->has_last = false;
    w->accepted = 0u;
    w->rejected_order = 0u;
    w->overflowed = 0u;
    return 0;
}

static void drop_oldest(rfs_rssi_t *w)
{
    w->sum_dbm -= w->dbm[w->head];
    w->head = (uint16_t)((w->head + 1u) % RFS_RSSI_CAP);
    w->count--;
}

/* Drop entries with t <= ref - window. Needs ref >= last_us - window (true for every
 * caller) so that ages fit the 32-bit difference. */
static void expire(rfs_rssi_t *w, int64_t ref_us)
{
    if (!w->has_last) {
        return;
    }
    if (ref_us - w->last_us >= (int64_t)w->cfg.window_us) {
        w->head = 0u;
        w->count = 0u;
        w->sum_dbm = 0;
        return;
    }
    uint32_t ref_lo = (uint32_t)ref_us;
    while (w->count != 0u) {
        int32_t age = (int32_t)(ref_lo - w->t_lo[w->head]);
        if (age < (int32_t)w->cfg.window_us) {
            break;
        }
        drop_oldest(w);
    }
}

bool rfs_rssi_push(rfs_rssi_t *w, int64_t t_us, int8_t dbm)
{
    RFS_ASSERT(w != 0);
    if (w->has_last && t_us < w->last_us) {
        if (w->rejected_order != UINT32_MAX) {
            w->rejected_order++;
        }
        return false;
    }
    expire(w, t_us);
    if (w->count == RFS_RSSI_CAP) {
        /* Still inside the window (expire ran): the mean loses it. */
        drop_oldest(w);
        if (w->overflowed != UINT32_MAX) {
            w->overflowed++;
        }
    }
    uint16_t idx = (uint16_t)((w->head + w->count) % RFS_RSSI_CAP);
    w->t_lo[idx] = (uint32_t)t_us;
    w->dbm[idx] = dbm;
    w->sum_dbm += dbm;
    w->count++;
    w->last_us = t_us;
    w->has_last = true;
    if (w->accepted != UINT32_MAX) {
        w->accepted++;
    }
    return true;
}

/* Sum and count of the entries in (now - window, now]. When now_us >= last_us the kept
 * entries are exactly those (after expire); a query into the past also skips the
 * entries newer than now_us by a scan from the newest end (at most RFS_RSSI_CAP). */
static uint16_t window_sum(rfs_rssi_t *w, int64_t now_us, int32_t *sum)
{
    if (!w->has_last) {
        *sum = 0;
        return 0u;
    }
    if (now_us >= w->last_us) {
        expire(w, now_us);
        *sum = w->sum_dbm;
        return w->count;
    }
    if (now_us < w->last_us - (int64_t)w->cfg.window_us) {
        *sum = 0; /* the whole ring is newer than now_us */
        return 0u;
    }
    expire(w, now_us);
    uint32_t now_lo = (uint32_t)now_us;
    int32_t s = 0;
    uint16_t n = 0u;
    for (uint16_t i = 0u; i < w->count; ++i) {
        uint16_t idx = (uint16_t)((w->head + i) % RFS_RSSI_CAP);
        if ((int32_t)(now_lo - w->t_lo[idx]) >= 0) {
            s += w->dbm[idx];
            n++;
        }
    }
    *sum = s;
    return n;
}

bool rfs_rssi_mean(rfs_rssi_t *w, int64_t now_us, rfs_q16_t *mean_db)
{
    RFS_ASSERT(w != 0 && mean_db != 0);
    int32_t sum = 0;
    uint16_t n = window_sum(w, now_us, &sum);
    if (n == 0u) {
        return false;
    }
    /* |sum| <= 512 * 128 = 2^16, so sum * 2^16 <= 2^32: exact in int64. */
    *mean_db = rfs_sat32(rfs_sdiv64_round((int64_t)sum * 65536, n));
    return true;
}

uint16_t rfs_rssi_count(rfs_rssi_t *w, int64_t now_us)
{
    RFS_ASSERT(w != 0);
    int32_t sum = 0;
    return window_sum(w, now_us, &sum);
}
