/* rfs_pdr.c - packet delivery ratio over a sliding window (see rfs_pdr.h). */
#include "rfs_pdr.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_rssi.h"

/* Half the sequence space: a larger forward distance is a step backwards. */
#define PDR_HALF (RFS_PDR_SEQ_MOD / 2u)

rfs_pdr_cfg_t rfs_pdr_cfg_default(void)
{
    rfs_pdr_cfg_t c = {.window_us = 1000000u};
    return c;
}

int rfs_pdr_init(rfs_pdr_t *p, const rfs_pdr_cfg_t *cfg)
{
    RFS_ASSERT(p != NULL && cfg != NULL);
    if (cfg->window_us == 0u || cfg->window_us > 60000000u) {
        return -1;
    }
    memset(p, 0, sizeof(*p));
    p->cfg = *cfg;
    return 0;
}

/* Full time of kept entry i: every kept entry is within the window (<= 60 s) of the
 * newest, so the low 32 bits place it exactly. */
static int64_t entry_us(const rfs_pdr_t *p, uint16_t i)
{
    return p->last_us - (int64_t)(uint32_t)((uint32_t)p->last_us - p->t_lo[i]);
}

static void drop_oldest(rfs_pdr_t *p)
{
    p->prev_us = entry_us(p, p->head);
    p->has_prev = true;
    p->sum_lost -= p->lost[p->head];
    p->head = (uint16_t)((p->head + 1u) % RFS_PDR_CAP);
    p->count--;
}

/* Drop entries at or before now_us - window. */
static void expire(rfs_pdr_t *p, int64_t now_us)
{
    int64_t edge = now_us - (int64_t)p->cfg.window_us;
    while (p->count > 0u && entry_us(p, p->head) <= edge) {
        drop_oldest(p);
    }
}

bool rfs_pdr_push(rfs_pdr_t *p, int64_t t_us, uint16_t seq)
{
    RFS_ASSERT(p != NULL);
    seq = (uint16_t)(seq & (RFS_PDR_SEQ_MOD - 1u));
    uint16_t lost = 0u;
    if (p->has_last) {
        if (t_us < p->last_us) {
            p->rejected_order++;
            return false;
        }
        uint16_t d = (uint16_t)((uint16_t)(seq - p->last_seq) & (RFS_PDR_SEQ_MOD - 1u));
        if (d == 0u) {
            p->duplicates++;
            return false;
        }
        if (d > PDR_HALF) {
            p->resyncs++;
        } else {
            lost = (uint16_t)(d - 1u);
        }
        expire(p, t_us);
    }
    if (p->count == RFS_PDR_CAP) {
        p->overflowed++;
        drop_oldest(p);
    }
    uint16_t at = (uint16_t)((p->head + p->count) % RFS_PDR_CAP);
    p->t_lo[at] = (uint32_t)t_us;
    p->lost[at] = lost;
    p->count++;
    p->sum_lost += lost;
    p->accepted++;
    p->lost_total += lost;
    p->last_us = t_us;
    p->last_seq = seq;
    p->has_last = true;
    return true;
}

bool rfs_pdr_push_seq_ctrl(rfs_pdr_t *p, int64_t t_us, uint16_t seq_ctrl)
{
    if ((seq_ctrl & 0xFu) != 0u) {
        return false;
    }
    return rfs_pdr_push(p, t_us, (uint16_t)(seq_ctrl >> 4));
}

bool rfs_pdr_ratio(rfs_pdr_t *p, int64_t now_us, rfs_q16_t *pct)
{
    RFS_ASSERT(p != NULL && pct != NULL);
    expire(p, now_us);
    if (p->count == 0u) {
        return false;
    }
    uint16_t head_lost = p->lost[p->head];
    uint64_t lost_q16 = (uint64_t)(p->sum_lost - head_lost) << 16;
    if (head_lost != 0u && p->has_prev) {
        /* The frames lost before the oldest kept frame were sent evenly over
         * (prev, t_head]; count the part after the window's start. */
        int64_t th = entry_us(p, p->head);
        int64_t start = now_us - (int64_t)p->cfg.window_us;
        int64_t from = p->prev_us > start ? p->prev_us : start;
        uint64_t gap = (uint64_t)(th - p->prev_us);
        uint64_t inside = th > from ? (uint64_t)(th - from) : 0u;
        while (gap >= ((uint64_t)1 << 31)) {
            gap >>= 1;
            inside >>= 1;
        }
        lost_q16 += gap == 0u ? (uint64_t)head_lost << 16
                              : rfs_udiv64(((uint64_t)head_lost * inside << 16) + (gap >> 1), gap);
    } else {
        lost_q16 += (uint64_t)head_lost << 16;
    }
    uint64_t denom_q16 = ((uint64_t)p->count << 16) + lost_q16;
    *pct = rfs_sat32(rfs_sdiv64_round((int64_t)p->count * 100 * ((int64_t)1 << 32),
                                      (int64_t)denom_q16));
    return true;
}

bool rfs_pdr_value(rfs_pdr_t *p, int64_t now_us, int8_t *pct)
{
    rfs_q16_t r;
    if (!rfs_pdr_ratio(p, now_us, &r)) {
        return false;
    }
    *pct = (int8_t)((r + RFS_Q16_HALF) >> 16);
    return true;
}

/* The measurement is already the percentage; the sample is that value. */
static bool pdr_sample(const rfs_target_in_t *in, uint8_t src, int8_t dbm, rfs_q16_t *value)
{
    RFS_ASSERT(in != NULL && value != NULL);
    if (in->win == NULL || in->nsources < 1u || src != 0u || dbm < 0 || dbm > 100) {
        return false;
    }
    *value = (rfs_q16_t)dbm * RFS_Q16_ONE;
    return true;
}

static bool pdr_mean(const rfs_target_in_t *in, rfs_q16_t *value)
{
    RFS_ASSERT(in != NULL && value != NULL);
    if (in->win == NULL || in->nsources < 1u) {
        return false;
    }
    return rfs_rssi_mean(&in->win[0], in->now_us, value);
}

static rfs_q16_t pdr_combine(const rfs_q16_t *r)
{
    return r[0];
}

const rfs_target_ops_t rfs_target_pdr = {
    .name = "pdr",
    .nsources = 1u,
    .sample = pdr_sample,
    .mean = pdr_mean,
    .combine = pdr_combine,
};
