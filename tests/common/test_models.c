/* test_models.c - the model registry (common/rfs_models).
 *
 * The expected names are the command line's (docs/MODELS.md, "Choosing a model")
 * (`--model ridge|mlp|knn|radius`); each of them must come up with its default
 * configuration and learn a plane z = 0.5 x - 40 dB closely enough to predict it
 * (checked against the plane, computed here). Rows added later are checked for
 * consistency only.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_models.h"

static rfs_sample_t g_s[400];

static void every_command_line_name_is_registered(void **state)
{
    (void)state;
    const char *names[] = {"ridge", "mlp", "knn", "radius"};

    for (unsigned i = 0; i < 4; ++i) {
        const rfs_models_entry_t *e = rfs_models_lookup(names[i]);
        assert_non_null(e);
        assert_string_equal(e->name, names[i]);
        assert_string_equal(e->ops->name, names[i]);
        assert_ptr_equal(rfs_models_find(names[i]), e->ops);
        assert_true(e->state_bytes > 0);
        assert_true(e->state_bytes <= rfs_models_max_state_bytes());
        assert_non_null(e->summary);
    }
    assert_string_equal(rfs_models_at(0)->name, "ridge");
    assert_true(rfs_models_count() >= 4);
    assert_null(rfs_models_at(rfs_models_count()));
}

/* Every row, including ones added later: consistent names, an init that accepts its own
 * defaults, and a size that fits the largest. */
static void every_entry_is_consistent(void **state)
{
    (void)state;
    void *buf = aligned_alloc(RFS_MODELS_STATE_ALIGN,
                              (rfs_models_max_state_bytes() + 7u) & ~7u);
    assert_non_null(buf);

    for (uint32_t i = 0; i < rfs_models_count(); ++i) {
        const rfs_models_entry_t *e = rfs_models_at(i);
        assert_string_equal(e->name, e->ops->name);
        assert_ptr_equal(rfs_models_lookup(e->name), e);
        assert_non_null(e->ops->fit);
        assert_non_null(e->ops->predict);
        assert_non_null(e->ops->reset);
        assert_int_equal(e->init_default(buf), 0);
        rfs_q16_t v;
        assert_false(e->ops->predict(buf, 0, 0, &v)); /* no model before a fit */
    }
    free(buf);
}

static void unknown_names_are_not_found(void **state)
{
    (void)state;
    assert_null(rfs_models_find("ridg"));
    assert_null(rfs_models_find("ridge2"));
    assert_null(rfs_models_find(""));
    assert_null(rfs_models_find("MLP"));
    assert_null(rfs_models_lookup(NULL));
}

/* Samples of the plane on a 20 x 20 grid 0.5 m apart, from (0, 0) to (9.5, 9.5) m. */
static void make_plane(void)
{
    for (int i = 0; i < 400; ++i) {
        int x = (i % 20) * 50, y = (i / 20) * 50;
        g_s[i].x_cm = (int16_t)x;
        g_s[i].y_cm = (int16_t)y;
        g_s[i].v_q6 = (int16_t)lround((0.5 * x / 100.0 - 40.0) * 64.0);
    }
}

static void every_model_learns_a_plane_with_defaults(void **state)
{
    (void)state;
    make_plane();
    void *buf = aligned_alloc(RFS_MODELS_STATE_ALIGN,
                              (rfs_models_max_state_bytes() + 7u) & ~7u);
    assert_non_null(buf);
    const char *names[] = {"ridge", "mlp", "knn", "radius"};
    for (uint32_t i = 0; i < 4; ++i) {
        const rfs_models_entry_t *e = rfs_models_lookup(names[i]);
        rfs_rng_t rng;
        rfs_rng_seed(&rng, 5);
        rfs_model_fit_in_t in = {.samples = g_s, .n = 400,
                                 .qx = RFS_Q16_INT(5), .qy = RFS_Q16_INT(5), .map = NULL};
        rfs_q16_t v;
        memset(buf, 0xA5, e->state_bytes);

        int rc = e->init_default(buf);
        rfs_fit_result_t r = e->ops->fit(buf, &in, 0, &rng);
        bool ok = e->ops->predict(buf, RFS_Q16_INT(5), RFS_Q16_INT(4), &v);

        assert_int_equal(rc, 0);
        assert_int_equal(r, RFS_FIT_DONE);
        assert_true(ok);
        /* the plane at (5, 4) is -37.5 dB; the MLP learns for only 3 epochs */
        if (fabs(v / 65536.0 + 37.5) > 1.5) {
            fail_msg("model %s predicts %.3f at (5, 4), plane -37.5", e->name, v / 65536.0);
        }
    }
    free(buf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_command_line_name_is_registered),
        cmocka_unit_test(every_entry_is_consistent),
        cmocka_unit_test(unknown_names_are_not_found),
        cmocka_unit_test(every_model_learns_a_plane_with_defaults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
