/* test_app_models.c - the model chosen by configuration in the firmware:
 * rfs_app_cfg_t.model through the registry, the state-size check that keeps a model out
 * of an image that cannot hold it, the CFG record's optional model name (byte layout
 * written out by hand from the format in firmware/rfs_replay.h), and the MCU
 * configuration's per-model fit budget (its deadline is checked on the
 * Cortex-M4 by tests/firmware/bench_models.sh). */
#include "rfs_test.h"

#include <stdlib.h>
#include <string.h>

#include "app_fixture.h"
#include "rfs_app.h"
#include "rfs_knn.h"
#include "rfs_mlp.h"
#include "rfs_pathloss.h"
#include "rfs_replay.h"

static uint64_t s_state[(sizeof(rfs_mlp_t) + 7u) / 8u]; /* an image holding ridge and mlp */

static void test_built_in_state_holds_the_ridge_only(void **state)
{
    (void)state;
    const rfs_app_map_t m = room();
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    assert_null(c.model);
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_ptr_equal(s_app.seek.model.ops, &rfs_ridge_ops);
    assert_ptr_equal(s_app.seek.model.self, &s_app.ridge);
    assert_int_equal(rfs_app_model_capacity(&c), sizeof(rfs_ridge_t));

    c.model = rfs_models_lookup("ridge");
    assert_true(rfs_app_model_fits(&c));
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_ptr_equal(s_app.seek.model.ops, &rfs_ridge_ops);

    /* 3,292 bytes of MLP state do not fit the ridge's 120: init refuses. */
    c.model = rfs_models_lookup("mlp");
    assert_false(rfs_app_model_fits(&c));
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
    c.model = rfs_models_lookup("knn");
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
}

static void test_port_buffer_holds_what_fits(void **state)
{
    (void)state;
    const rfs_app_map_t m = room();
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    c.model_state = s_state;
    c.model_state_bytes = (uint32_t)sizeof s_state;
    c.model = rfs_models_lookup("mlp");
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_ptr_equal(s_app.seek.model.ops, &rfs_mlp_ops);
    assert_ptr_equal(s_app.seek.model.self, s_state);
    /* The ridge goes into the port's buffer too, with cfg.ridge. */
    c.model = NULL;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_ptr_equal(s_app.seek.model.ops, &rfs_ridge_ops);
    assert_ptr_equal(s_app.seek.model.self, s_state);
    /* knn (76 KB) does not fit 3.3 KB; a misaligned buffer is refused. */
    c.model = rfs_models_lookup("knn");
    assert_true(sizeof(rfs_knn_t) > sizeof s_state);
    assert_false(rfs_app_model_fits(&c));
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
    c.model = rfs_models_lookup("mlp");
    c.model_state = (uint8_t *)s_state + 4;
    c.model_state_bytes = (uint32_t)sizeof s_state - 8u;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
}

static void test_cfg_model_name_bytes(void **state)
{
    (void)state;
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_CFG;
    r.u.cfg.seed = 7;
    r.u.cfg.target = 0;
    r.u.cfg.node = 1;
    r.u.cfg.fit_budget = 2500;
    memcpy(r.u.cfg.model, "mlp", 3);
    /* type 0x01, len 17: seed u64 LE, target, node, fit_budget u32 LE (2500 = 0x09C4), "mlp" */
    static const uint8_t want[] = {0x01, 17, 7, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0xC4, 0x09, 0, 0,
                                   'm', 'l', 'p'};
    uint8_t buf[64];
    assert_int_equal(rfs_replay_encode(&r, buf, sizeof buf), sizeof want);
    assert_memory_equal(buf, want, sizeof want);
    rfs_replay_rec_t back;
    uint32_t used = 0;
    assert_int_equal(rfs_replay_parse(want, sizeof want, &used, &back), RFS_REPLAY_OK);
    assert_int_equal(used, sizeof want);
    assert_string_equal(back.u.cfg.model, "mlp");
    assert_int_equal(back.u.cfg.fit_budget, 2500);

    /* Without a name: the 14-byte CFG of format version 1, name empty. */
    static const uint8_t v1[] = {0x01, 14, 7, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0xC4, 0x09, 0, 0};
    assert_int_equal(rfs_replay_parse(v1, sizeof v1, &used, &back), RFS_REPLAY_OK);
    assert_string_equal(back.u.cfg.model, "");
    memset(r.u.cfg.model, 0, sizeof r.u.cfg.model);
    assert_int_equal(rfs_replay_encode(&r, buf, sizeof buf), sizeof v1);
    assert_memory_equal(buf, v1, sizeof v1);

    /* With a CONFIG frame's choice after the name: NUL, strategy 5 (meta-path), p0_min
     * -5120 (-40 dBm x 128 = 0xEC00 LE). */
    memcpy(r.u.cfg.model, "pathloss", 8);
    r.u.cfg.chosen = true;
    r.u.cfg.strategy = 5;
    r.u.cfg.p0_min = -5120;
    static const uint8_t ch[] = {0x01, 26, 7, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0xC4, 0x09, 0, 0,
                                 'p', 'a', 't', 'h', 'l', 'o', 's', 's', 0, 5, 0x00, 0xEC};
    assert_int_equal(rfs_replay_encode(&r, buf, sizeof buf), sizeof ch);
    assert_memory_equal(buf, ch, sizeof ch);
    assert_int_equal(rfs_replay_parse(ch, sizeof ch, &used, &back), RFS_REPLAY_OK);
    assert_true(back.u.cfg.chosen);
    assert_string_equal(back.u.cfg.model, "pathloss");
    assert_int_equal(back.u.cfg.strategy, 5);
    assert_int_equal(back.u.cfg.p0_min, -5120);

    /* Bad: length 34, a name of 16 bytes, a control byte in the name, a choice of 3
     * bytes, strategy 6, p0_min beyond 100 dBm (12801). */
    uint8_t big[36] = {0x01, 34};
    memset(big + 2, 'a', 34);
    big[10] = 0; /* target */
    assert_int_equal(rfs_replay_parse(big, sizeof big, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "CFG length out of range");
    big[1] = 30;
    assert_int_equal(rfs_replay_parse(big, 32, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "CFG model name not printable or too long");
    uint8_t ctl[sizeof want];
    memcpy(ctl, want, sizeof want);
    ctl[17] = 0x01;
    assert_int_equal(rfs_replay_parse(ctl, sizeof ctl, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "CFG model name not printable or too long");
    uint8_t bad[sizeof ch];
    memcpy(bad, ch, sizeof ch);
    bad[1] = 25;
    assert_int_equal(rfs_replay_parse(bad, sizeof ch - 1u, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "CFG choice malformed or out of range");
    memcpy(bad, ch, sizeof ch);
    bad[25] = 6;
    assert_int_equal(rfs_replay_parse(bad, sizeof bad, &used, &back), RFS_REPLAY_BAD);
    memcpy(bad, ch, sizeof ch);
    bad[26] = 0x01; /* 12801 = 0x3201 */
    bad[27] = 0x32;
    assert_int_equal(rfs_replay_parse(bad, sizeof bad, &used, &back), RFS_REPLAY_BAD);
    bad[26] = 0x00; /* 12800: 100 dBm, the limit */
    assert_int_equal(rfs_replay_parse(bad, sizeof bad, &used, &back), RFS_REPLAY_OK);
    /* The NUL the record's last byte (a choice of one byte), the record the buffer's end:
     * refused without reading past it (a heap copy of exactly its size, for ASan). */
    uint8_t *end = malloc(sizeof ch - 3u);
    assert_non_null(end);
    memcpy(end, ch, sizeof ch - 3u);
    end[1] = 23;
    assert_int_equal(rfs_replay_parse(end, sizeof ch - 3u, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "CFG choice malformed or out of range");
    free(end);
}

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    (void)p;
    (void)n;
}

static void test_player_applies_or_refuses_the_model(void **state)
{
    (void)state;
    static rfs_replay_player_t p;
    rfs_app_cfg_t cfg = fx_cfg(rfs_app_cfg_default());
    cfg.model_state = s_state;
    cfg.model_state_bytes = (uint32_t)sizeof s_state;
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_CFG;
    static const char *const names[3] = {"mlp", "svm", "knn"};
    static const rfs_replay_err_t want[3] = {RFS_REPLAY_E_NONE, RFS_REPLAY_E_MODEL,
                                             RFS_REPLAY_E_MODEL_SIZE};
    for (int i = 0; i < 3; i++) {
        rfs_replay_player_init(&p, &s_app, &cfg, sink, NULL);
        memset(r.u.cfg.model, 0, sizeof r.u.cfg.model);
        memcpy(r.u.cfg.model, names[i], 3);
        assert_int_equal(rfs_replay_play(&p, &r), want[i] == RFS_REPLAY_E_NONE);
        assert_int_equal(p.error, want[i]);
    }
    rfs_replay_player_init(&p, &s_app, &cfg, sink, NULL);
    memcpy(r.u.cfg.model, "mlp", 3);
    assert_true(rfs_replay_play(&p, &r));
    assert_ptr_equal(p.cfg.model, rfs_models_lookup("mlp"));
    assert_string_equal(rfs_replay_err_str(RFS_REPLAY_E_MODEL_SIZE),
                        "CFG model's state is larger than the image holds");
}

/* CONFIG frames (docs/CAN.md, "0x130 CONFIG") choose the mission before its first decision
 * (as the STM32 image offers them: the ridge built in, the path-loss model in the port's
 * buffer); what the image does not hold, or a frame after the first decision, is refused
 * and counted, leaving the configuration in force. */
static uint64_t s_pl[(sizeof(rfs_pathloss_t) + 7u) / 8u];

static void test_config_frame_chooses_before_the_first_decision(void **state)
{
    (void)state;
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_mcu());
    c.model_state = s_pl;
    c.model_state_bytes = (uint32_t)sizeof s_pl;
    c.models[RFS_CAN_MODEL_PATHLOSS] = &rfs_models_pathloss;
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_can_tx_t op;
    rfs_can_tx_init(&op);
    rfs_can_frame_t f, out[2];
    rfs_app_out_t o;
    rfs_app_step(&s_app, 0, &o);
    rfs_app_frames(&s_app, &o, out); /* STATUS counter 0 */
    rfs_can_status_t st;
    uint8_t ctr;
    assert_int_equal(rfs_can_unpack_status(&out[1], &st, &ctr), RFS_CAN_OK);
    assert_false(st.configured); /* the image's own configuration */

    /* knn: not offered; bridge + pathloss: one fit per node, no room; meta-global and a
     * baseline (chemotaxis: its decision kinds have no code on the wire). */
    const rfs_can_config_t refused[4] = {
        {0, RFS_SEEK_META, RFS_CAN_MODEL_KNN, -5760, 3u, 0},
        {1, RFS_SEEK_META_PATH, RFS_CAN_MODEL_PATHLOSS, -5760, 3u, 0},
        {0, RFS_SEEK_META_GLOBAL, RFS_CAN_MODEL_RIDGE, -5760, 3u, 0},
        {0, RFS_SEEK_CHEMOTAXIS, RFS_CAN_MODEL_RIDGE, -5760, 3u, 0},
    };
    for (int i = 0; i < 4; i++) {
        rfs_can_tx_config(&op, &refused[i], &f);
        assert_int_equal(rfs_app_on_can(&s_app, &f, 1000), RFS_CAN_OK);
    }
    assert_int_equal(s_app.stats.configs_rejected, 4u);
    assert_int_equal(s_app.stats.configs, 0u);
    assert_ptr_equal(s_app.seek.model.ops, &rfs_ridge_ops);
    assert_int_equal(s_app.cfg.seed, 1u);

    const rfs_can_config_t mp = {0, RFS_SEEK_META_PATH, RFS_CAN_MODEL_PATHLOSS, -5120, 0x123456u, 0};
    rfs_can_tx_config(&op, &mp, &f);
    assert_int_equal(rfs_app_on_can(&s_app, &f, 2000), RFS_CAN_OK);

    assert_int_equal(s_app.stats.configs, 1u);
    assert_int_equal(s_app.stats.configs_rejected, 4u); /* kept across the re-initialisation */
    assert_int_equal(s_app.seek.cfg.strategy, RFS_SEEK_META_PATH);
    assert_int_equal(s_app.seek.cfg.recheck_dist, s_app.seek.cfg.step); /* meta-path's preset */
    assert_ptr_equal(s_app.seek.model.ops, &rfs_pathloss_ops);
    assert_ptr_equal(s_app.seek.model.self, s_pl);
    assert_int_equal(((rfs_pathloss_t *)s_pl)->cfg.p0_min, -40 * 65536);
    assert_int_equal(s_app.cfg.seed, 0x123456u);
    assert_int_equal(s_app.seek.cfg.fit_budget, rfs_models_pathloss.mcu_fit_budget); /* its MCU slice */
    rfs_app_step(&s_app, 50000, &o);
    rfs_app_frames(&s_app, &o, out);
    assert_int_equal(out[1].data[0] & 0x0Fu, 1u); /* the STATUS counter runs on */
    assert_int_equal(rfs_can_unpack_status(&out[1], &st, &ctr), RFS_CAN_OK);
    assert_true(st.configured);
    assert_false(o.faults & RFS_APP_FAULT_RESET);

    /* The mission starts: a decision (after the boot's flood fill in slices), then a
     * CONFIG is refused. */
    int64_t t_end = 100000;
    for (int64_t t = 100000; t <= 5000000 && s_app.seek.iteration == 0u; t += 50000) {
        t_end = t;
        const rfs_pose_t p = {.t_us = t, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
        rfs_app_on_pose(&s_app, &p, t);
        rfs_app_on_rssi(&s_app, 0, t, -60, t);
        rfs_app_step(&s_app, t, &o);
    }
    assert_true(s_app.seek.iteration > 0u);
    const rfs_can_config_t back = {0, RFS_SEEK_META, RFS_CAN_MODEL_RIDGE, -5760, 1u, 0};
    rfs_can_tx_config(&op, &back, &f);
    assert_int_equal(rfs_app_on_can(&s_app, &f, t_end + 10000), RFS_CAN_OK);
    assert_int_equal(s_app.stats.configs_rejected, 5u);
    assert_int_equal(s_app.seek.cfg.strategy, RFS_SEEK_META_PATH);
    /* The codes name the registry's entries, the named entries are the table's. */
    for (uint8_t k = 0; k < RFS_CAN_NMODELS; k++) {
        assert_non_null(rfs_models_lookup(rfs_can_model_name(k)));
    }
    assert_ptr_equal(rfs_models_lookup("pathloss"), &rfs_models_pathloss);
    assert_ptr_equal(rfs_models_lookup("ridge"), &rfs_models_ridge);
}

/* The MCU configuration slices each model's relearn by that model's registry budget
 * (a work unit is a sample for the ridge, a sample-update for the MLP, a
 * work unit for pathloss); the other configurations keep the budget they are given. */
static void test_mcu_fit_budget_is_the_model_s(void **state)
{
    (void)state;
    const rfs_app_map_t m = room();
    const rfs_models_entry_t *mlp = rfs_models_lookup("mlp");
    assert_non_null(mlp);
    /* The ridge's registry budget is the firmware's long-standing one. */
    assert_int_equal(rfs_models_lookup("ridge")->mcu_fit_budget, RFS_APP_MCU_FIT_BUDGET);
    /* 0 is one whole fit: only the ridge's fits a control period (make bench-firmware). */
    for (uint32_t i = 0; i < rfs_models_count(); i++) {
        const rfs_models_entry_t *e = rfs_models_at(i);
        assert_true((e->mcu_fit_budget == 0u) == (e == &rfs_models_ridge));
    }

    /* The MCU defaults, the model chosen afterwards (the ports' order). */
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_mcu());
    c.model_state = s_state;
    c.model_state_bytes = (uint32_t)sizeof s_state;
    c.model = mlp;
    assert_int_equal(rfs_app_fit_budget(&c), mlp->mcu_fit_budget);
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(s_app.seek.cfg.fit_budget, mlp->mcu_fit_budget);
    assert_int_equal(s_app.cfg.seek.fit_budget, mlp->mcu_fit_budget);

    /* The built-in ridge (NULL) and its registry entry: a whole fit. */
    c.model = NULL;
    c.seek.fit_budget = 77u;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(s_app.seek.cfg.fit_budget, 0u);
    c.model = rfs_models_lookup("ridge");
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(s_app.seek.cfg.fit_budget, 0u);

    /* Without fit_budget_by_model the given budget stands (host defaults: 0, whole fit;
     * a replay's recorded budget). */
    c.fit_budget_by_model = false;
    c.model = mlp;
    c.seek.fit_budget = 123u;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(s_app.seek.cfg.fit_budget, 123u);
    rfs_app_cfg_t d = fx_cfg(rfs_app_cfg_default());
    assert_false(d.fit_budget_by_model);
    d.model_state = s_state;
    d.model_state_bytes = (uint32_t)sizeof s_state;
    d.model = mlp;
    assert_int_equal(rfs_app_init(&s_app, &d, &m), 0);
    assert_int_equal(s_app.seek.cfg.fit_budget, 0u);
}

/* At its registry budget the MLP's relearn takes ceil(epochs n / budget) calls: the budget
 * counts sample-updates (3 epochs, paper 5.2.2), so no call does more than budget. */
static void test_mlp_budget_counts_sample_updates(void **state)
{
    (void)state;
    const rfs_models_entry_t *e = rfs_models_lookup("mlp");
    static rfs_sample_t smp[1000];
    rfs_rng_t r;
    rfs_rng_seed(&r, 3);
    for (uint32_t i = 0; i < 1000u; i++) {
        smp[i].x_cm = (int16_t)rfs_rng_below(&r, 2001);
        smp[i].y_cm = (int16_t)rfs_rng_below(&r, 1001);
        smp[i].v_q6 = (int16_t)(-64 * 40 - (int32_t)rfs_rng_below(&r, 64 * 20));
    }
    const uint32_t ns[3] = {100u, 700u, 1000u};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(e->init_default(s_state), 0);
        const rfs_model_fit_in_t in = {.samples = smp, .n = (uint16_t)ns[k]};
        uint32_t calls = 0;
        rfs_fit_result_t res;
        do {
            res = e->ops->fit(s_state, &in, e->mcu_fit_budget, &r);
            calls++;
        } while (res == RFS_FIT_MORE && calls < 100u);
        assert_int_equal(res, RFS_FIT_DONE);
        const uint32_t updates = 3u * ns[k];
        assert_int_equal(calls, (updates + e->mcu_fit_budget - 1u) / e->mcu_fit_budget);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_built_in_state_holds_the_ridge_only),
        cmocka_unit_test(test_port_buffer_holds_what_fits),
        cmocka_unit_test(test_cfg_model_name_bytes),
        cmocka_unit_test(test_player_applies_or_refuses_the_model),
        cmocka_unit_test(test_mcu_fit_budget_is_the_model_s),
        cmocka_unit_test(test_config_frame_chooses_before_the_first_decision),
        cmocka_unit_test(test_mlp_budget_counts_sample_updates),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
