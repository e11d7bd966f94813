/* rfs_target.c - the built-in target functions (paper sections 2 and 6; see rfs_target.h).
 *
 * Values are dB Q16.16. A packet's sample uses the packet's own dBm for its source and
 * the 1 s means of the other sources at in->now_us; the relearn check uses the 1 s
 * means of all sources.
 */
#include "rfs_target.h"

#include "rfs_assert.h"

/* The per-source inputs of one evaluation: the packet's value for src, means elsewhere. */
static bool gather(const rfs_target_in_t *in, uint8_t need, int src, int8_t dbm, rfs_q16_t *r)
{
    RFS_ASSERT(in != 0 && r != 0);
    if (in->win == 0 || in->nsources < need || src >= (int)need) {
        return false;
    }
    for (uint8_t i = 0u; i < need; ++i) {
        if ((int)i == src) {
            r[i] = (rfs_q16_t)dbm * RFS_Q16_ONE;
        } else if (!rfs_rssi_mean(&in->win[i], in->now_us, &r[i])) {
            return false;
        }
    }
    return true;
}

static rfs_q16_t rssi_combine(const rfs_q16_t *r)
{
    return r[0];
}

/* f = -|R1 - R2| - |R1 + R2| (paper section 6): maximal where both are equal and high.
 * Scaling and overflow: inputs are dB in [-128, 0] (Q16.16); every intermediate is
 * below 2^8 dB, far inside Q16.16; the saturating operations only guard misuse. */
static rfs_q16_t bridge_combine(const rfs_q16_t *r)
{
    rfs_q16_t d = rfs_q16_abs(rfs_q16_sub(r[0], r[1]));
    rfs_q16_t s = rfs_q16_abs(rfs_q16_add(r[0], r[1]));
    return rfs_q16_sub(rfs_q16_sub(0, d), s);
}

/* sample() and mean() of a target: its per-source inputs, then its combine(). */
static bool sample_of(const rfs_target_ops_t *t, const rfs_target_in_t *in, uint8_t src,
                      int8_t dbm, rfs_q16_t *value)
{
    rfs_q16_t r[RFS_TARGET_MAX_SOURCES];
    if (!gather(in, t->nsources, src, dbm, r)) {
        return false;
    }
    *value = t->combine(r);
    return true;
}

static bool mean_of(const rfs_target_ops_t *t, const rfs_target_in_t *in, rfs_q16_t *value)
{
    rfs_q16_t r[RFS_TARGET_MAX_SOURCES];
    if (!gather(in, t->nsources, -1, 0, r)) {
        return false;
    }
    *value = t->combine(r);
    return true;
}

static bool rssi_sample(const rfs_target_in_t *in, uint8_t src, int8_t dbm, rfs_q16_t *value)
{
    return sample_of(&rfs_target_rssi, in, src, dbm, value);
}

static bool rssi_mean(const rfs_target_in_t *in, rfs_q16_t *value)
{
    return mean_of(&rfs_target_rssi, in, value);
}

static bool bridge_sample(const rfs_target_in_t *in, uint8_t src, int8_t dbm, rfs_q16_t *value)
{
    return sample_of(&rfs_target_bridge, in, src, dbm, value);
}

static bool bridge_mean(const rfs_target_in_t *in, rfs_q16_t *value)
{
    return mean_of(&rfs_target_bridge, in, value);
}

const rfs_target_ops_t rfs_target_rssi = {
    .name = "rssi",
    .nsources = 1u,
    .sample = rssi_sample,
    .mean = rssi_mean,
    .combine = rssi_combine,
};

const rfs_target_ops_t rfs_target_bridge = {
    .name = "bridge",
    .nsources = 2u,
    .sample = bridge_sample,
    .mean = bridge_mean,
    .combine = bridge_combine,
};
