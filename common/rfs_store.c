/* rfs_store.c - samples with interpolated positions and a uniform reservoir
 * (paper sections 2 and 5.2; see rfs_store.h).
 */
#include "rfs_store.h"

#include <string.h>

#include "rfs_assert.h"

/// Largest bracketing gap init accepts: keeps the interpolation product
/// (|dx| < 2^32 Q16) x (dt <= 6e7 us < 2^26) below 2^58, exact in int64.
#define STORE_MAX_GAP_US 60000000

rfs_store_cfg_t rfs_store_cfg_default(void)
{
    rfs_store_cfg_t c;
    c.capacity = 10000u;    /* paper section 5.2: "a maximum of randomly drawn 10,000 samples" */
    c.max_gap_us = 500000;  /* 5 poses missed at 10 Hz */
    return c;
}

int rfs_store_init(rfs_store_t *s, const rfs_store_cfg_t *cfg, rfs_sample_t *samples,
                   rfs_pending_t *pending, uint16_t pending_cap)
{
    if (s == 0 || cfg == 0 || samples == 0 || pending == 0 || pending_cap == 0u ||
        cfg->capacity == 0u || cfg->max_gap_us <= 0 || cfg->max_gap_us > STORE_MAX_GAP_US) {
        return -1;
    }
    memset(s, 0, sizeof(*s));
    s->cfg = *cfg;
    s->samples = samples;
    s->pending = pending;
    s->pending_cap = pending_cap;
    return 0;
}

static void count_up(uint32_t *c)
{
    if (*c != UINT32_MAX) {
        (*c)++;
    }
}

void rfs_store_offer(rfs_store_t *s, rfs_sample_t sample, rfs_rng_t *rng)
{
    RFS_ASSERT(s != 0 && rng != 0);
    /* Algorithm R: the k-th sample seen replaces a uniformly chosen slot with probability
     * capacity / k, so every sample seen so far is kept with equal probability. `seen`
     * saturates after 2^32 - 1 samples (124 days at 400 per second). */
    count_up(&s->seen);
    if (s->count < s->cfg.capacity) {
        if (s->index != 0) {
            s->index->put(s->index->self, s->count, 0, &sample);
        }
        s->samples[s->count++] = sample;
        return;
    }
    uint32_t j = rfs_rng_below(rng, s->seen);
    if (j < s->cfg.capacity) {
        if (s->index != 0) {
            s->index->put(s->index->self, (uint16_t)j, &s->samples[j], &sample);
        }
        s->samples[j] = sample;
    }
}

void rfs_store_set_index(rfs_store_t *s, const rfs_store_index_t *index)
{
    RFS_ASSERT(s != 0 && (index == 0 || index->cap >= s->cfg.capacity));
    s->index = index;
    for (uint16_t i = 0; index != 0 && i < s->count; ++i) {
        index->put(index->self, i, 0, &s->samples[i]);
    }
}

static const rfs_pose_t *pose_at(const rfs_store_t *s, uint8_t i)
{
    return &s->poses[(s->pose_head + i) % RFS_STORE_POSE_HISTORY];
}

typedef enum {
    BRACKET_OK = 0,
    BRACKET_EARLY, ///< older than the oldest pose kept
    BRACKET_LATE,  ///< newer than the newest pose
    BRACKET_GAP,   ///< the bracketing poses are more than max_gap_us apart
} bracket_t;

/* Scaling and overflow: a + (b - a) * dt / span with |b - a| < 2^32 (Q16.16) and
 * dt <= span <= STORE_MAX_GAP_US < 2^26: product < 2^58 in int64, rounded to nearest
 * once; the divisor fits 32 bits, so rfs_udiv64 divides in hardware 32-bit steps. The
 * result lies between a and b, so it fits Q16.16. */
static rfs_q16_t lerp(rfs_q16_t a, rfs_q16_t b, int64_t dt, int64_t span)
{
    return (rfs_q16_t)(a + rfs_sdiv64_round(((int64_t)b - a) * dt, span));
}

static bracket_t interpolate(const rfs_store_t *s, int64_t t_us, rfs_q16_t *x, rfs_q16_t *y)
{
    if (s->pose_count == 0u) {
        return BRACKET_LATE;
    }
    const rfs_pose_t *newest = pose_at(s, (uint8_t)(s->pose_count - 1u));
    if (t_us > newest->t_us) {
        return BRACKET_LATE;
    }
    if (t_us < pose_at(s, 0u)->t_us) {
        return BRACKET_EARLY;
    }
    /* Newest first: a measurement is usually bracketed by the last two poses. */
    for (int i = (int)s->pose_count - 1; i >= 0; --i) {
        const rfs_pose_t *p0 = pose_at(s, (uint8_t)i);
        if (p0->t_us > t_us) {
            continue;
        }
        if (p0->t_us == t_us) {
            *x = p0->x;
            *y = p0->y;
            return BRACKET_OK;
        }
        const rfs_pose_t *p1 = pose_at(s, (uint8_t)(i + 1));
        /* p1 is newer than p0: the unsigned difference is exact at any int64 times */
        if ((uint64_t)p1->t_us - (uint64_t)p0->t_us > (uint64_t)s->cfg.max_gap_us) {
            return BRACKET_GAP;
        }
        int64_t span = p1->t_us - p0->t_us;
        int64_t dt = t_us - p0->t_us;
        *x = lerp(p0->x, p1->x, dt, span);
        *y = lerp(p0->y, p1->y, dt, span);
        return BRACKET_OK;
    }
    return BRACKET_EARLY; /* unreachable: t_us >= the oldest pose */
}

bool rfs_store_position_at(const rfs_store_t *s, int64_t t_us, rfs_q16_t *x, rfs_q16_t *y)
{
    RFS_ASSERT(s != 0 && x != 0 && y != 0);
    return interpolate(s, t_us, x, y) == BRACKET_OK;
}

/* Metres Q16.16 to centimetres, rounded to nearest, saturated to +-327.67 m.
 * Scaling and overflow: x * 100 < 2^39 in int64, + 2^15, >> 16. */
static int16_t q16_to_cm(rfs_q16_t x)
{
    return rfs_sat16(((int64_t)x * 100 + 32768) >> 16);
}

/* Q16.16 to Q9.6, rounded to nearest, saturated to [-512, 512). */
static int16_t q16_to_q6(rfs_q16_t v)
{
    return rfs_sat16(((int64_t)v + 512) >> 10);
}

/* Turn a bracketed measurement into a sample, or count why it cannot be one.
 * Returns false only when it must keep waiting (newer than the newest pose). */
static bool place(rfs_store_t *s, int64_t t_us, int16_t v_q6, rfs_rng_t *rng)
{
    rfs_q16_t x = 0, y = 0;
    switch (interpolate(s, t_us, &x, &y)) {
    case BRACKET_OK: {
        rfs_sample_t smp;
        smp.x_cm = q16_to_cm(x);
        smp.y_cm = q16_to_cm(y);
        smp.v_q6 = v_q6;
        rfs_store_offer(s, smp, rng);
        return true;
    }
    case BRACKET_EARLY:
        count_up(&s->dropped_early);
        return true;
    case BRACKET_GAP:
        count_up(&s->dropped_gap);
        return true;
    case BRACKET_LATE:
    default:
        return false;
    }
}

bool rfs_store_add_pose(rfs_store_t *s, const rfs_pose_t *pose, rfs_rng_t *rng)
{
    RFS_ASSERT(s != 0 && pose != 0 && rng != 0);
    if (s->pose_count != 0u &&
        pose->t_us <= pose_at(s, (uint8_t)(s->pose_count - 1u))->t_us) {
        count_up(&s->rejected_pose_order);
        return false;
    }
    if (s->pose_count == RFS_STORE_POSE_HISTORY) {
        s->poses[s->pose_head] = *pose;
        s->pose_head = (uint8_t)((s->pose_head + 1u) % RFS_STORE_POSE_HISTORY);
    } else {
        s->poses[(s->pose_head + s->pose_count) % RFS_STORE_POSE_HISTORY] = *pose;
        s->pose_count++;
    }
    /* Place every pending measurement the new pose brackets; compact the others in
     * order (two sources may interleave, so the queue is not sorted by time). */
    uint16_t kept = 0u;
    for (uint16_t i = 0u; i < s->pending_count; ++i) {
        rfs_pending_t p = s->pending[(s->pending_head + i) % s->pending_cap];
        if (!place(s, p.t_us, p.v_q6, rng)) {
            s->pending[(s->pending_head + kept) % s->pending_cap] = p;
            kept++;
        }
    }
    s->pending_count = kept;
    return true;
}

void rfs_store_add_value(rfs_store_t *s, int64_t t_us, rfs_q16_t v, rfs_rng_t *rng)
{
    RFS_ASSERT(s != 0 && rng != 0);
    int16_t v_q6 = q16_to_q6(v);
    if (place(s, t_us, v_q6, rng)) {
        return;
    }
    if (s->pending_count == s->pending_cap) {
        count_up(&s->dropped_pending);
        return;
    }
    rfs_pending_t p;
    p.t_us = t_us;
    p.v_q6 = v_q6;
    s->pending[(s->pending_head + s->pending_count) % s->pending_cap] = p;
    s->pending_count++;
}
