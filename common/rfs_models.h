/* rfs_models.h - the registry of internal models: one name -> operations, state size
 * and default initialisation, so that the simulator, the feeder and the firmware pick
 * a model the same way (`--model ridge|mlp|knn|radius`, `model:` in a scenario).
 *
 * The caller owns the state: it provides `state_bytes` bytes aligned to 8 (e.g. a
 * static buffer or a union of the state types), calls init_default() on them, and
 * builds the rfs_model_t from `ops` and that buffer. A new model is one more row in
 * the table in rfs_models.c. A model of one source's signal under a target of several
 * sources is fitted per source instead (rfs_models_per_source(), rfs_fields.h).
 */
#ifndef RFS_MODELS_H
#define RFS_MODELS_H

#include <stdint.h>

#include "rfs_model.h"
#include "rfs_target.h"

/// Alignment the state buffer needs, bytes (states hold int64_t fields).
#define RFS_MODELS_STATE_ALIGN 8u

/// One registered model.
typedef struct rfs_models_entry {
    const char *name;            ///< command-line name ("ridge"), same as ops->name
    const rfs_model_ops_t *ops;  ///< its operations
    uint32_t state_bytes;        ///< size of its state, bytes
    /// Initialise a state of state_bytes bytes with the default (paper) configuration.
    /// Returns 0 (the defaults are always valid).
    int (*init_default)(void *state);
    const char *summary;         ///< one line for --help
    /// Work units per control period (rfs_seek_cfg_t.fit_budget) for the microcontroller
    /// (rfs_app_cfg_mcu()): the largest round budget whose heaviest fit slice stays under
    /// half the 200 ms safety deadline (docs/FIRMWARE.md, "Safety") on a 168 MHz
    /// Cortex-M4, measured with make bench-models-m4 (docs/PERFORMANCE.md, "Models on the
    /// Cortex-M4"). A work unit is the model's own (ridge and knn: a sample, mlp: a
    /// sample-update, pathloss: a wall count), so each model has its number. Never 0 (0
    /// would be the whole fit at once).
    uint32_t mcu_fit_budget;
    /// The model describes one source's signal (a path-loss field): under a target of
    /// several sources it runs as one fit per source (rfs_models_per_source()).
    bool per_source;
} rfs_models_entry_t;

/// The entries by name, in --help order: an image that names one of them instead of
/// looking models up links that model's code alone.
extern const rfs_models_entry_t rfs_models_ridge;
extern const rfs_models_entry_t rfs_models_mlp;    ///< "mlp"
extern const rfs_models_entry_t rfs_models_knn;    ///< "knn"
extern const rfs_models_entry_t rfs_models_radius; ///< "radius"
extern const rfs_models_entry_t rfs_models_pathloss; ///< "pathloss"

/// The entry named `name` (NUL-terminated, exact match), or NULL when there is none.
const rfs_models_entry_t *rfs_models_lookup(const char *name);

/// The operations of the model named `name`, or NULL when there is none.
const rfs_model_ops_t *rfs_models_find(const char *name);

/// Number of registered models.
uint32_t rfs_models_count(void);

/// Entry i (0 <= i < rfs_models_count()), in the order --help lists them; NULL beyond.
const rfs_models_entry_t *rfs_models_at(uint32_t i);

/// The largest state_bytes of all entries (to size one buffer for any model).
uint32_t rfs_models_max_state_bytes(void);

/// true when entry e under target t runs as one fit per source: e is per_source and t
/// combines several sources. The caller then builds an rfs_fields_t (rfs_fields.h: each
/// source's own fit, the target on the predicted fields) instead of e's own state.
bool rfs_models_per_source(const rfs_models_entry_t *e, const rfs_target_ops_t *t);

#endif /* RFS_MODELS_H */
