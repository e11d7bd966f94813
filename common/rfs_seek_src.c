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

/* The robot is within src_spacing of source c's last sample, or at rest since it: a
 * robot standing still sees one fade however its localised pose jitters (5-10 cm in the
 * simulator: else hundreds of samples of that one fade where the robot stood). */
static bool near(const rfs_seek_t *s, const rfs_seek_src_t *c, rfs_q16_t x, rfs_q16_t y)
{
    return c->at && (rfs_q16_dist(x, y, c->x, c->y) < s->cfg.src_spacing ||
                     rfs_drive_at_rest(&s->drive));
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

bool rfs_seek_src_settled(const rfs_seek_t *s)
{
    return s->cfg.settle_dist > 0 && s->travel >= (int64_t)s->cfg.settle_dist;
}

bool rfs_seek_src_orbiting(const rfs_seek_t *s)
{
    return s->cfg.settle_orbit > 0 && rfs_seek_src_settled(s) &&
           (s->cfg.settle_end == 0 || s->travel < (int64_t)s->cfg.settle_end);
}

/* settle_orbit: the robot stands at the best point, where it adds no sample (one fade,
 * src_spacing), so the best point's measured f rests on the pass that found it, and a
 * lucky fade there holds the robot for good. A move to a reachable lattice point between
 * half the orbit and the orbit from it adds samples of new fades round it; the next
 * greedy decision returns, relearnt, to the best point of the more measured field.
 * Uniform over the ring without a list: count, then take the k-th. Scaling: offsets Q16
 * squared in int64 (Q32) against the radii squared. */
bool rfs_seek_src_orbit(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    rfs_q16_t mx, my;
    if (!rfs_seek_src_orbiting(s) || s->model.ops->argmax == 0 ||
        !s->model.ops->argmax(s->model.self, &mx, &my) ||
        rfs_q16_dist(s->pose.x, s->pose.y, mx, my) >= s->cfg.settle_orbit / 2) {
        return false;
    }
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, mx, my, &ci, &cj);
    const int32_t r = s->cfg.settle_orbit / m->cfg.grid + 1;
    const int64_t hi = (int64_t)s->cfg.settle_orbit * s->cfg.settle_orbit, lo = hi / 4;
    uint32_t n = 0u;
    for (int pass = 0; pass < 2; ++pass) {
        const uint32_t pick = pass ? rfs_rng_below(rng, n) : 0u;
        uint32_t seen = 0u;
        for (int32_t j = (int32_t)cj - r; j <= (int32_t)cj + r; ++j) {
            for (int32_t i = (int32_t)ci - r; i <= (int32_t)ci + r; ++i) {
                if (i < 0 || j < 0 || i >= (int32_t)m->lw || j >= (int32_t)m->lh ||
                    !rfs_reach_at(m, s->reach, (uint16_t)i, (uint16_t)j)) {
                    continue;
                }
                rfs_q16_t px, py;
                rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
                const int64_t dx = (int64_t)px - mx, dy = (int64_t)py - my;
                const int64_t d2 = dx * dx + dy * dy;
                if (d2 < lo || d2 > hi) {
                    continue;
                }
                if (pass == 0) {
                    n++;
                } else if (seen++ == pick) {
                    s->decision.max_x = mx;
                    s->decision.max_y = my;
                    s->decision.goal_x = px;
                    s->decision.goal_y = py;
                    return rfs_seek_go_to(s, px, py, now_us);
                }
            }
        }
        if (n == 0u) {
            return false;
        }
    }
    return false;
}
