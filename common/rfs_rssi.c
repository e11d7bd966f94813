/* rfs_rssi.c - the exact 1-second mean per source (paper section 2; see rfs_rssi.h).
 *
 * Timestamps are kept as their low 32 bits. Every push and query advances a clock (the
 * newest time seen) and drops the entries that left the window ending there, so kept
 * entries are younger than window_us (<= 60 s) relative to the clock; a clock more than a
 * window past the newest entry empties the ring, so every age computed is below
 * 2 * 60 s < 2^31 us and the 32-bit differences are exact, whatever the absolute time.
 * The running sum makes the usual query (now >= newest entry) O(1) amortised.
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
    w->clock_us = 0;
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

/* later - earlier >= window for later >= earlier, without overflow at any int64 times. */
static bool window_apart(int64_t later, int64_t earlier, uint32_t window_us)
{
    return (uint64_t)later - (uint64_t)earlier >= window_us;
}

/* Advance the clock to t_us (if later) and drop the entries with t <= clock - window.
 * Kept entries lie in (old clock - window, last_us], so when the clock has moved less
 * than a window past last_us every age below is < 2 * window < 2^31 us. */
static void advance(rfs_rssi_t *w, int64_t t_us)
{
    if (t_us <= w->clock_us) {
        return;
    }
    w->clock_us = t_us;
    if (window_apart(t_us, w->last_us, w->cfg.window_us)) { /* t_us > clock >= last_us */
        w->head = 0u;
        w->count = 0u;
        w->sum_dbm = 0;
        return;
    }
    uint32_t ref_lo = (uint32_t)t_us;
    while (w->count != 0u) {
        int32_t age = (int32_t)(ref_lo - w->t_lo[w->head]);
        if (age < (int32_t)w->cfg.window_us) {
            break;
        }
        drop_oldest(w);
    }
}

static void count_up(uint32_t *c)
{
    if (*c != UINT32_MAX) {
        (*c)++;
    }
}

bool rfs_rssi_push(rfs_rssi_t *w, int64_t t_us, int8_t dbm)
{
    RFS_ASSERT(w != 0);
    if (w->has_last && t_us < w->last_us) {
        count_up(&w->rejected_order);
        return false;
    }
    count_up(&w->accepted);
    if (!w->has_last) {
        w->has_last = true;
        w->clock_us = t_us;
    }
    advance(w, t_us);
    w->last_us = t_us;
    if (window_apart(w->clock_us, t_us, w->cfg.window_us)) { /* clock >= t_us here */
        return true; /* a query already moved the window past it */
    }
    if (w->count == RFS_RSSI_CAP) {
        /* Still inside the window: the mean loses it. */
        drop_oldest(w);
        count_up(&w->overflowed);
    }
    uint16_t idx = (uint16_t)((w->head + w->count) % RFS_RSSI_CAP);
    w->t_lo[idx] = (uint32_t)t_us;
    w->dbm[idx] = dbm;
    w->sum_dbm += dbm;
    w->count++;
    return true;
}

/* Sum and count of the kept entries in (now - window, now]. Every kept entry is newer
 * than clock - window >= now - window; when now_us >= last_us all of them count,
 * otherwise a scan (at most RFS_RSSI_CAP) skips the ones newer than now_us. */
static uint16_t window_sum(rfs_rssi_t *w, int64_t now_us, int32_t *sum)
{
    *sum = 0;
    if (!w->has_last) {
        return 0u;
    }
    advance(w, now_us);
    if (now_us >= w->last_us) {
        *sum = w->sum_dbm;
        return w->count;
    }
    if (window_apart(w->clock_us, now_us, w->cfg.window_us)) { /* clock >= now_us here */
        return 0u; /* every kept entry is newer than now_us */
    }
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
    /* Scaling and overflow: |sum| <= 512 * 128 = 2^16; |sum| = q n + r with r < n <= 512,
     * so the fraction r * 2^16 + n / 2 < 2^26 and q * 2^16 <= 2^23: 32-bit divisions
     * only (one instruction each on the Cortex-M4), rounded half away from zero. */
    uint32_t mag = (uint32_t)(sum < 0 ? -sum : sum);
    uint32_t q = mag / n, r = mag % n;
    uint32_t frac = (r * 65536u + n / 2u) / n;
    int32_t m = (int32_t)(q * 65536u + frac);
    *mean_db = sum < 0 ? -m : m;
    return true;
}

uint16_t rfs_rssi_count(rfs_rssi_t *w, int64_t now_us)
{
    RFS_ASSERT(w != 0);
    int32_t sum = 0;
    return window_sum(w, now_us, &sum);
}
