/* test_seek_sources.c - the seeker's per-source samples and settling (common/rfs_seek.c;
 * docs/STRATEGIES.md, "Bridging"): each source's own store, one sample per src_spacing
 * of travel holding the mean of that source's packets, the receiver's floor for a
 * source not heard, and greedy choices only after settle_dist of travel.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "seek_run.h"

/* A 10 x 10 m room and a seeker with the local ridge on the bridging target, each source
 * with its own store when `per_source`. */
typedef struct two {
    world_t w;
    rfs_seek_src_t src[2];
    rfs_sample_t *src_samples[2];
    rfs_pending_t *src_pending[2];
} two_t;

static int two_make(two_t *t, rfs_seek_cfg_t cfg, bool per_source, bool only_first)
{
    world_make(&t->w, 10, 10, 0, 0);
    seek_make(&t->w, cfg, 5); /* the rssi seeker: its memory, then a bridging one below */
    for (int k = 0; k < 2; ++k) {
        t->src_samples[k] = calloc(cfg.store.capacity, sizeof(rfs_sample_t));
        t->src_pending[k] = calloc(256, sizeof(rfs_pending_t));
        assert_true(t->src_samples[k] && t->src_pending[k]);
    }
    rfs_seek_mem_t mem = t->w.mem;
    mem.src = per_source ? t->src : NULL;
    for (int k = 0; per_source && k < (only_first ? 1 : 2); ++k) {
        mem.src_samples[k] = t->src_samples[k];
        mem.src_pending[k] = t->src_pending[k];
    }
    return rfs_seek_init(&t->w.seek, &cfg, &t->w.map, rfs_ridge_model(&t->w.ridge),
                         &rfs_target_bridge, &mem);
}

static void two_free(two_t *t)
{
    for (int k = 0; k < 2; ++k) {
        free(t->src_samples[k]);
        free(t->src_pending[k]);
    }
    world_free(&t->w);
}

static void pose(two_t *t, int64_t t_us, double x, double y)
{
    rfs_pose_t p = pose_at(t_us, x, y, 0);
    assert_true(rfs_seek_on_pose(&t->w.seek, &p, &t->w.rng));
}

static rfs_seek_cfg_t per_source_cfg(void)
{
    rfs_seek_cfg_t c = rfs_seek_cfg_default();
    rfs_seek_cfg_per_source(&c);
    return c;
}

/* Per-source samples: with rfs_seek_mem_t.src, every source's arrays are needed. */
static void test_stores_all_or_none(void **state)
{
    (void)state;
    two_t t;
    assert_int_equal(two_make(&t, per_source_cfg(), true, true), -1);
    two_free(&t);
    assert_int_equal(two_make(&t, per_source_cfg(), false, false), 0);
    assert_null(t.w.seek.src);
    two_free(&t);
    assert_int_equal(two_make(&t, per_source_cfg(), true, false), 0);
    assert_non_null(t.w.seek.src);
    rfs_seek_cfg_t c = rfs_seek_cfg_default();
    assert_int_equal(c.src_spacing, 0);
    assert_int_equal(c.settle_dist, 0);
    assert_int_equal(c.src_floor, INT32_MIN);
    c = per_source_cfg();
    assert_int_equal(c.src_spacing, 2621); /* 4 cm */
    assert_int_equal(c.settle_dist, 100 * 65536);
    assert_int_equal(c.src_floor, -100 * 65536);
    two_free(&t);
}

/* Standing still, a source's packets make one sample (the first); 4 cm further, the next
 * packet ends a sample holding the mean of the packets since. */
static void test_one_sample_per_spacing(void **state)
{
    (void)state;
    two_t t;
    assert_int_equal(two_make(&t, per_source_cfg(), true, false), 0);
    rfs_seek_t *s = &t.w.seek;
    int64_t now = 0;
    pose(&t, now, 5.0, 5.0);
    const int8_t pk[] = {-60, -61, -65, -58, -70, -66, -59};
    for (int k = 0; k < 7; ++k) {
        now += 10000;
        assert_true(rfs_seek_on_rssi(s, 0, now, pk[k], &t.w.rng));
        pose(&t, now + 1, 5.0, 5.0);
        now += 1;
    }
    assert_int_equal(s->src[0].store.count, 1);
    assert_int_equal(s->src[0].store.samples[0].v_q6, -60 * 64);
    assert_int_equal(s->src[1].store.count, 0);
    assert_int_equal(s->store.count, 0); /* no bridging sample without source 1's mean */
    s->drive.base_left = s->drive.base_right = 100; /* the base rolls */
    /* 3.9 cm: still the same place. */
    pose(&t, now + 10000, 5.039, 5.0);
    now += 10000;
    assert_true(rfs_seek_on_rssi(s, 0, now + 1, -62, &t.w.rng));
    pose(&t, now + 2, 5.039, 5.0);
    assert_int_equal(s->src[0].store.count, 1);
    /* 4.1 cm from the first sample: the mean of the seven packets since it. */
    pose(&t, now + 10000, 5.041, 5.0);
    now += 10000;
    assert_true(rfs_seek_on_rssi(s, 0, now + 1, -64, &t.w.rng));
    pose(&t, now + 2, 5.041, 5.0);
    assert_int_equal(s->src[0].store.count, 2);
    double mean = (-61 - 65 - 58 - 70 - 66 - 59 - 62 - 64) / 8.0;
    assert_int_equal(s->src[0].store.samples[1].v_q6, (int16_t)lround(mean * 64.0));
    assert_int_equal(s->src[0].store.samples[1].x_cm, 504);
    two_free(&t);
}

/* At rest the localised pose jitters (here 8 cm each way) but the robot sees one fade:
 * no sample after the first; rolling, one per 4 cm. */
static void test_no_sample_at_rest(void **state)
{
    (void)state;
    two_t t;
    assert_int_equal(two_make(&t, per_source_cfg(), true, false), 0);
    rfs_seek_t *s = &t.w.seek;
    int64_t now = 0;
    for (int k = 0; k < 40; ++k) {
        now += 10000;
        pose(&t, now, 5.0 + (k % 2 ? 0.08 : 0.0), 5.0 + (k % 4 < 2 ? 0.08 : 0.0));
        assert_true(rfs_seek_on_rssi(s, 0, now + 1, -60, &t.w.rng));
    }
    assert_int_equal(s->src[0].store.count, 1);
    s->drive.base_left = s->drive.base_right = 100;
    for (int k = 0; k < 40; ++k) {
        now += 10000;
        pose(&t, now, 5.0 + (k % 2 ? 0.08 : 0.0), 5.0 + (k % 4 < 2 ? 0.08 : 0.0));
        assert_true(rfs_seek_on_rssi(s, 0, now + 1, -60, &t.w.rng));
    }
    assert_true(s->src[0].store.count >= 30);
    two_free(&t);
}

/* Source 1 silent for over a window while source 0 is heard: a floor sample every 4 cm
 * of travel, and the decision's mean is f(mean 0, floor). */
static void test_silent_source_reads_floor(void **state)
{
    (void)state;
    two_t t;
    assert_int_equal(two_make(&t, per_source_cfg(), true, false), 0);
    rfs_seek_t *s = &t.w.seek;
    int64_t now = 0;
    double x = 2.0;
    rfs_seek_out_t out;
    int decisions = 0;
    double mean0 = 0.0;
    s->drive.base_left = s->drive.base_right = 100; /* the base rolls */
    for (int k = 0; k < 60; ++k) { /* 3 s at 20 Hz, 1 cm a period */
        now += 50000;
        x += 0.01;
        pose(&t, now, x, 5.0);
        int8_t dbm = (int8_t)(-50 - k % 3);
        assert_true(rfs_seek_on_rssi(s, 0, now + 1, dbm, &t.w.rng));
        if (k >= 40) {
            mean0 += dbm / 20.0; /* the last second's packets */
        }
        if (k == 0) {
            assert_true(rfs_seek_on_rssi(s, 1, now + 2, -80, &t.w.rng));
        }
        if (k >= 45) { /* the first decision after 2.25 s, the silence over a window old */
            rfs_seek_step(s, now + 3, &t.w.rng, &out);
            decisions += out.decided;
        }
    }
    assert_true(decisions >= 1);
    /* Source 1 was last heard at 50 ms; from 1.05 s on it is silent: one floor sample per
     * 4 cm of the 1.95 s (39 cm) after that (a 1 cm step each: every fourth pose). */
    int floors = 0;
    for (uint16_t i = 0; i < s->src[1].store.count; ++i) {
        floors += s->src[1].store.samples[i].v_q6 == -100 * 64;
    }
    assert_int_equal(s->src[1].store.samples[0].v_q6, -80 * 64);
    assert_true(floors >= 8 && floors <= 10);
    /* The relearn check's mean with the floor for source 1: f = 2 min(R0, -100). */
    rfs_q16_t m = 0;
    rfs_target_in_t in = {s->win, 2, now + 3};
    assert_false(rfs_target_bridge.mean(&in, &m));
    assert_true(s->decision.mean_valid);
    (void)mean0;
    assert_int_equal(s->decision.mean, -200 * 65536);
    two_free(&t);
}

/* With settle_dist every choice after that much travel is greedy; without it epsilon
 * steps go on (the paper's floor of 0.1). */
static void run_settle(rfs_q16_t settle, int *eps_after, int *eps_before)
{
    world_t t;
    world_make(&t, 20, 20, 0, 0);
    rfs_seek_cfg_t c = rfs_seek_cfg_default();
    c.settle_dist = settle;
    seek_make(&t, c, 17);
    field_t f = {.kind = 0, .sx = 15.0, .sy = 15.0};
    run_t r = {.t_us = 0, .x = 3.0, .y = 3.0};
    rfs_seek_out_t out;
    *eps_after = *eps_before = 0;
    for (int k = 0; k < 150 && next_decision(&t, &r, &f, 300000, 10000000, &out); ++k) {
        bool past = t.seek.travel >= RFS_Q16_INT(4);
        if (out.decision.kind == RFS_SEEK_EPSILON && out.decision.model_valid) {
            *(past ? eps_after : eps_before) += 1;
        }
    }
    world_free(&t);
}

static void test_settle_dist(void **state)
{
    (void)state;
    int after, before;
    run_settle(RFS_Q16_INT(4), &after, &before);
    assert_int_equal(after, 0);
    assert_true(before >= 1);
    run_settle(0, &after, &before);
    assert_true(after >= 3);
}

/* settle_orbit: once settled, a decision at the model's best point goes to a reachable
 * lattice point 0.25-0.5 m from it (distances in double), the next one back, each
 * relearnt; after settle_end, and without settle_orbit, the robot holds the point. */
static void run_orbit(rfs_q16_t orbit, rfs_q16_t end, int *ring, int *held, int *other)
{
    world_t t;
    world_make(&t, 10.0, 10.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.local_r = 0; /* as rfs_seek_cfg_per_source */
    cfg.settle_dist = RFS_Q16_INT(2);
    cfg.settle_orbit = orbit;
    cfg.settle_end = end;
    seek_make(&t, cfg, 9);
    fixed_model_t fm = { false, Q(5.125), Q(5.125) };
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 2.0, .y = 2.0 };
    rfs_seek_out_t out;
    *ring = *held = *other = 0;
    double gx0 = -1.0;
    int distinct = 0;
    for (int k = 0; k < 40 && next_decision(&t, &r, &f, 500000, 5000000, &out); ++k) {
        if (t.seek.travel < cfg.settle_dist || k < 2) {
            continue;
        }
        const double d = hypot(D(out.decision.goal_x) - 5.125, D(out.decision.goal_y) - 5.125);
        const bool at = hypot(D(out.decision.x) - 5.125, D(out.decision.y) - 5.125) < 0.01;
        assert_true(out.decision.relearned || orbit == 0 || t.seek.travel >= end);
        if (at && d >= 0.25 - 1e-9 && d <= 0.5 + 1e-9) {
            *ring += 1;
            distinct += fabs(D(out.decision.goal_x) - gx0) > 1e-6;
            gx0 = D(out.decision.goal_x);
        } else if (d < 1e-6) {
            *held += 1;
        } else {
            *other += 1;
        }
    }
    if (*ring >= 10) { /* round the point, not to one side */
        assert_true(distinct >= 3);
    }
    world_free(&t);
}

static void test_settle_orbit(void **state)
{
    (void)state;
    int ring, held, other;
    run_orbit(RFS_Q16_HALF, 0, &ring, &held, &other);
    assert_true(ring >= 10);
    assert_true(held >= 10); /* the way back */
    assert_int_equal(other, 0);
    run_orbit(0, 0, &ring, &held, &other);
    assert_int_equal(ring, 0);
    assert_int_equal(other, 0);
    run_orbit(RFS_Q16_HALF, RFS_Q16_INT(10), &ring, &held, &other);
    assert_true(ring >= 2 && ring <= 8); /* about 0.75 m a round */
    assert_true(held >= 15);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stores_all_or_none),
        cmocka_unit_test(test_one_sample_per_spacing),
        cmocka_unit_test(test_no_sample_at_rest),
        cmocka_unit_test(test_silent_source_reads_floor),
        cmocka_unit_test(test_settle_dist),
        cmocka_unit_test(test_settle_orbit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
