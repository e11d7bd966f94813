/* rfs_models.c - the registry of internal models (see rfs_models.h). */
#include "rfs_models.h"

#include <stdbool.h>
#include <stddef.h>

#include "rfs_knn.h"
#include "rfs_mlp.h"
#include "rfs_pathloss.h"
#include "rfs_ridge.h"

static int ridge_init_default(void *state)
{
    rfs_ridge_cfg_t c = rfs_ridge_cfg_default();
    return rfs_ridge_init(state, &c);
}

static int mlp_init_default(void *state)
{
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    return rfs_mlp_init(state, &c);
}

static int knn_init_default(void *state)
{
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    return rfs_knn_init(state, &c);
}

static int radius_init_default(void *state)
{
    rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
    return rfs_knn_init(state, &c);
}

static int pathloss_init_default(void *state)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    return rfs_pathloss_init(state, &c);
}

/* The first row is the default model (the paper's main configuration).
 *
 * The last column, mcu_fit_budget, is measured (make bench-models-m4, 10,000 samples;
 * docs/PERFORMANCE.md, "Models on the Cortex-M4"): the largest round budget whose
 * heaviest slice stays under 16,800,000 Cortex-M4 instructions, half the 200 ms deadline
 * at 168 MHz, the other half left for the rest of the period and cycles > instructions.
 * - ridge: 0, a whole fit (10,000 samples: 323,163 instructions, inside a period's
 *   500,000; the choice waits a period), so a relearn delays a decision by 50 ms.
 * - knn, radius: 2,500 samples, 147 k instructions: also inside the firmware's 500,000
 *   per period (docs/FIRMWARE.md).
 * - mlp: 700 sample-updates, 16.3 M (about 23,000 per update; the first slice also
 *   standardises the samples); 800 would be 18.6 M.
 * - pathloss: 150 work units (about a wall count each, rfs_pathloss.h "Work"), 425,333:
 *   inside the 500,000 of a control period, the rule for this model (the firmware
 *   bench's 1,000-sample slice: 429,409, at most 174 units); 175 would be 495,709 here.
 *   A call stops before work that could overrun the budget and resumes there. */
const rfs_models_entry_t rfs_models_ridge = {
    "ridge", &rfs_ridge_ops, (uint32_t)sizeof(rfs_ridge_t), ridge_init_default,
    "local ridge regression, 5 m radius, alpha 1 (paper 5.2.1)", 0u, false};
const rfs_models_entry_t rfs_models_mlp = {
    "mlp", &rfs_mlp_ops, (uint32_t)sizeof(rfs_mlp_t), mlp_init_default,
    "MLP 2-100-1, sigmoid, backprop rate 0.01 momentum 0.1, 3 epochs (paper 5.2.2)", 700u, false};
const rfs_models_entry_t rfs_models_knn = {
    "knn", &rfs_knn_ops, (uint32_t)sizeof(rfs_knn_t), knn_init_default,
    "k-nearest-neighbours regression, k = 5 (paper 5.2)", 2500u, false};
const rfs_models_entry_t rfs_models_radius = {
    "radius", &rfs_radius_ops, (uint32_t)sizeof(rfs_knn_t), radius_init_default,
    "radius-neighbours regression, r = 1 m (paper 5.2)", 2500u, false};
const rfs_models_entry_t rfs_models_pathloss = {
    "pathloss", &rfs_pathloss_ops, (uint32_t)sizeof(rfs_pathloss_t), pathloss_init_default,
    "map-aware log-distance + walls fit, source search; one per source under bridge "
    "(beyond the paper)", 150u, true};

static const rfs_models_entry_t *const k_models[] = {
    &rfs_models_ridge, &rfs_models_mlp, &rfs_models_knn, &rfs_models_radius, &rfs_models_pathloss,
};

#define N_MODELS (sizeof(k_models) / sizeof(k_models[0]))

static bool same_name(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

const rfs_models_entry_t *rfs_models_lookup(const char *name)
{
    if (name == NULL) {
        return NULL;
    }
    for (uint32_t i = 0u; i < N_MODELS; ++i) {
        if (same_name(k_models[i]->name, name)) {
            return k_models[i];
        }
    }
    return NULL;
}

const rfs_model_ops_t *rfs_models_find(const char *name)
{
    const rfs_models_entry_t *e = rfs_models_lookup(name);
    return e == NULL ? NULL : e->ops;
}

uint32_t rfs_models_count(void)
{
    return (uint32_t)N_MODELS;
}

const rfs_models_entry_t *rfs_models_at(uint32_t i)
{
    return i < N_MODELS ? k_models[i] : NULL;
}

uint32_t rfs_models_max_state_bytes(void)
{
    uint32_t m = 0u;
    for (uint32_t i = 0u; i < N_MODELS; ++i) {
        m = k_models[i]->state_bytes > m ? k_models[i]->state_bytes : m;
    }
    return m;
}

bool rfs_models_per_source(const rfs_models_entry_t *e, const rfs_target_ops_t *t)
{
    return e != NULL && t != NULL && e->per_source && t->nsources > 1u;
}
