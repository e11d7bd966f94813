/* rfs_seek_src.c - each source's own samples, for a model fitted per source (rfs_fields.h;
 * docs/STRATEGIES.md, "Bridging"): a store per source besides the target's, one sample
 * per src_spacing of travel holding the mean of the source's packets since the last, the
 * receiver's floor for a source not heard (src_floor), and the relearn check's mean
 * with that floor. rfs_seek.c calls these only when rfs_seek_mem_t.src is given.
 */
#include "rfs_seek_internal.h"

/* b - a when b > a, else 0, without signed overflow at extreme timestamps. */
static uint64_t after(int64_t a, int64_t b)
{
    return b > a ? (uint64_t)b - (uint64_t)a : 0u;
}

bool rfs_seek_src_init(rfs_seek_t *s, const rfs_seek_mem_t *mem)
{
    s->src = mem->src;
    for (uint8_t i = 0; s->src != 0 && i < s->target->nsources; ++i) {
        rfs_seek_src_t *c = &s->src[i];
        if (mem->src_samples[i] == 0 || mem->src_pending[i] == 0 ||
            rfs_store_init(&c->store, &s->cfg.store, mem->src_samples[i], mem->src_pending[i],
                           mem->pending_cap) != 0) {
            return false;
        }
        c->sum = 0;
        c->cnt = 0;
        c->at = false;
        c->heard = false;
    }
    return true;
}

/* Start source c's next sample at the robot's position (x, y). */
static void restart(rfs_seek_src_t *c, rfs_q16_t x, rfs_q16_t y)
{
    c->sum = 0;
    c->cnt = 0;
    c->at = true;
    c->x = x;
    c->y = y;
}

/* The robot is within src_spacing of source c's last sample. */
static bool near(const rfs_seek_t *s, const rfs_seek_src_t *c, rfs_q16_t x, rfs_q16_t y)
{
    return c->at && rfs_q16_dist(x, y, c->x, c->y) < s->cfg.src_spacing;
}

/* src_floor: a source silent for a window while another is heard is below the receiver's
 * floor where the robot is: a floor sample every src_spacing of travel, so that a fit
 * learns where a source cannot be heard (no bridge there) instead of never seeing the
 * place. A source never heard is silent a window after the first packet of another. */
static void add_floor_samples(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng)
{
    const uint64_t win = s->cfg.rssi.window_us;
    bool any_heard = false, first = false;
    int64_t first_us = 0;
    for (uint8_t i = 0; i < s->target->nsources; ++i) {
        const rfs_seek_src_t *c = &s->src[i];
        if (c->heard) {
            any_heard = any_heard || after(c->heard_us, pose->t_us) <= win;
            first_us = !first || c->first_us < first_us ? c->first_us : first_us;
            first = true;
        }
    }
    for (uint8_t i = 0; any_heard && i < s->target->nsources; ++i) {
        rfs_seek_src_t *c = &s->src[i];
        if (after(c->heard ? c->heard_us : first_us, pose->t_us) <= win ||
            near(s, c, pose->x, pose->y)) {
            continue;
        }
        /* Packets from before the silence are too old to place here. */
        rfs_store_add_value(&c->store, pose->t_us, s->cfg.src_floor, rng);
        restart(c, pose->x, pose->y);
    }
}

void rfs_seek_src_on_pose(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng)
{
    for (uint8_t i = 0; i < s->target->nsources; ++i) {
        (void)rfs_store_add_pose(&s->src[i].store, pose, rng);
    }
    if (s->cfg.src_spacing > 0 && s->cfg.src_floor != INT32_MIN) {
        add_floor_samples(s, pose, rng);
    }
}

/* Small-scale fading decorrelates within half a wavelength (6 cm at 2.4 GHz): samples
 * src_spacing apart see different fades, while a robot standing still would add the same
 * fade again and again and teach nothing. Scaling: at most 65,535 packets of |dBm| <= 128
 * sum below 2^23; their mean in Q16 by rfs_sdiv64_round. */
void rfs_seek_src_on_rssi(rfs_seek_t *s, uint8_t src, int64_t t_us, int8_t dbm,
                          rfs_rng_t *rng)
{
    rfs_seek_src_t *c = &s->src[src];
    if (s->cfg.src_spacing == 0) {
        rfs_store_add_value(&c->store, t_us, (rfs_q16_t)dbm * RFS_Q16_ONE, rng);
        return;
    }
    if (c->cnt == UINT16_MAX) {
        c->sum = 0; /* standing still this long: start the mean again */
        c->cnt = 0;
    }
    c->sum += dbm;
    c->cnt++;
    if (!c->heard) {
        c->first_us = t_us;
    }
    c->heard = true;
    c->heard_us = t_us;
    if (near(s, c, s->pose.x, s->pose.y)) {
        return;
    }
    int64_t v = rfs_sdiv64_round((int64_t)c->sum * RFS_Q16_ONE, c->cnt);
    rfs_store_add_value(&c->store, t_us, (rfs_q16_t)v, rng);
    restart(c, s->pose.x, s->pose.y);
}

bool rfs_seek_src_mean(rfs_seek_t *s, int64_t now_us, rfs_q16_t *mean)
{
    rfs_target_in_t in = { s->win, s->target->nsources, now_us };
    if (s->target->mean(&in, mean)) {
        return true;
    }
    if (s->src == 0 || s->cfg.src_floor == INT32_MIN) {
        return false;
    }
    rfs_q16_t r[RFS_SEEK_MAX_SOURCES];
    bool any = false;
    for (uint8_t i = 0; i < s->target->nsources; ++i) {
        bool have = rfs_rssi_mean(&s->win[i], now_us, &r[i]);
        r[i] = have ? r[i] : s->cfg.src_floor;
        any = any || have;
    }
    if (any) {
        *mean = s->target->combine(r);
    }
    return any;
}
