/* rfs_seek_fit.c - the model's learning for the loop in rfs_seek.c: what a fit learns
 * from, a relearn begun as the base brakes (fit_early) and the slices a port runs between
 * control periods (docs/FIRMWARE.md, "Learning between periods"). */
#include "rfs_assert.h"
#include "rfs_seek_internal.h"

/* The settle phase a fit learns in (rfs_model_fit_in_t.settle). */
static rfs_model_settle_t settle_phase(const rfs_seek_t *s)
{
    return !rfs_seek_src_settled(s) ? RFS_MODEL_EXPLORE
           : rfs_seek_src_orbiting(s) ? RFS_MODEL_TOUR
                                      : RFS_MODEL_HOLD;
}

void rfs_seek_fit_input(const rfs_seek_t *s, rfs_q16_t qx, rfs_q16_t qy,
                        rfs_model_fit_in_t *fin)
{
    *fin = (rfs_model_fit_in_t){ .samples = s->store.samples, .n = s->store.count,
                                 .index = s->store.index, .qx = qx, .qy = qy, .map = s->map,
                                 .reach = s->reach_valid ? s->reach : 0,
                                 .excl_x_cm = s->excl_x_cm, .excl_y_cm = s->excl_y_cm,
                                 .nexcl = s->nexcl,
                                 .excl_r = s->cfg.refute_r,
                                 .settle = settle_phase(s) };
    for (uint8_t i = 0; s->src != 0 && i < s->target->nsources; ++i) {
        fin->src_samples[i] = s->src[i].store.samples;
        fin->src_n[i] = s->src[i].store.count;
        fin->src_seen[i] = s->src[i].store.seen;
        fin->nsources = (uint8_t)(i + 1u);
    }
}

/* |v| of a modelled wheel speed, mm/s. */
static uint32_t speed_abs(int32_t v)
{
    return v >= 0 ? (uint32_t)v : 0u - (uint32_t)v;
}

/* How far the base rolls on from its modelled wheel speeds (rfs_drive_t.base_*), braking
 * at the drive's acceleration limit, plus its goal tolerance (pose lag and noise), metres
 * Q16.16. Scaling: v <= 2^31 mm/s, v^2 <= 2^62 in uint64, divided by 2a (a > 0, drive
 * init) and clamped to 2^40 mm, times 2^16 (< 2^56) / 1000, saturated. */
static rfs_q16_t braking(const rfs_seek_t *s)
{
    const uint32_t l = speed_abs(s->drive.base_left), r = speed_abs(s->drive.base_right);
    const uint64_t v = l > r ? l : r;
    const uint64_t a2 = 2u * (uint64_t)(uint32_t)s->drive.cfg.accel_mm_s2;
    const uint64_t mm = rfs_udiv64(v * v, a2 != 0u ? a2 : 1u);
    const uint64_t q16 = mm > ((uint64_t)1 << 40) ? ((uint64_t)1 << 40) : mm;
    return rfs_sat32((int64_t)rfs_udiv64(q16 << 16, 1000u) + s->drive.cfg.goal_tol);
}

/* fit_early (docs/FIRMWARE.md, "Learning between periods"): a failed recheck makes the next
 * decision relearn, so with sliced fits the relearn begins now, as the base brakes, on the
 * samples so far (the braking's come with the next relearn). */
void rfs_seek_fit_early_begin(rfs_seek_t *s, int64_t now_us)
{
    if (!s->cfg.fit_early || s->cfg.fit_budget == 0u || !rfs_seek_ops(s)->learns ||
        s->store.count == 0u || s->fitting) {
        return;
    }
    /* The refutation (rfs_seek_meta_refute) asks the model this leg was driven on, so it
     * is made now, where the base may stop within the rule's half step of that model's
     * maximum: on the mean and the prediction here, not at rest. */
    const rfs_q16_t margin = braking(s);
    rfs_q16_t mx, my, pred, mean;
    bool refuted = false;
    if (rfs_seek_meta_refute_near(s, margin, &mx, &my)) {
        const bool have_pred = s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &pred);
        const bool mean_valid = rfs_seek_src_mean(s, now_us, &mean);
        refuted = rfs_seek_meta_refute_with(s, now_us, margin, have_pred, pred, mean_valid, mean);
    }
    s->model.ops->reset(s->model.self);
    s->fitting = true;
    s->early = true;
    s->fit_qx = s->pose.x;
    s->fit_qy = s->pose.y;
    s->early_nexcl = s->nexcl;
    s->early_excl_next = s->excl_next;
    s->early_settle = settle_phase(s);
    s->early_refuted = refuted;
}

bool rfs_seek_fit_early_asks(rfs_seek_t *s, int64_t now_us)
{
    rfs_q16_t mean, pred;
    if (!s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &pred)) {
        return true;
    }
    return rfs_seek_src_mean(s, now_us, &mean) &&
           rfs_q16_abs(rfs_q16_sub(mean, pred)) > s->cfg.error_threshold;
}

/* fit_early: the fit begun as the base braked learns what the decision's would: no place
 * ruled out since, the same settle phase. */
bool rfs_seek_fit_early_holds(const rfs_seek_t *s)
{
    return s->nexcl == s->early_nexcl && s->excl_next == s->early_excl_next &&
           settle_phase(s) == s->early_settle;
}

bool rfs_seek_background(rfs_seek_t *s, rfs_rng_t *rng)
{
    RFS_ASSERT(s != 0 && rng != 0);
    /* Not while a sliced flood rewrites the reach bits (reach_valid false): a fit reading
     * them (rfs_fields.c) waits for the flood, as the periods' slices do (control()). */
    if (!s->fitting || s->fit_ended || s->cfg.fit_budget == 0u || s->flooding) {
        return false;
    }
    rfs_model_fit_in_t fin;
    rfs_seek_fit_input(s, s->fit_qx, s->fit_qy, &fin);
    if (s->model.ops->fit(s->model.self, &fin, s->cfg.fit_budget, rng) == RFS_FIT_MORE) {
        return true;
    }
    s->fit_ended = true;
    return false;
}

uint32_t rfs_seek_background_n(rfs_seek_t *s, rfs_rng_t *rng, uint32_t n)
{
    uint32_t k = 0u;
    while (k < n && rfs_seek_background(s, rng)) {
        ++k;
    }
    return k;
}
