/* models_work.h - the workload of the model bench and its run, shared
 * by the Cortex-M4 image (bench_models.c: timed by SysTick under qemu -icount) and its
 * host twin (tests/firmware/bench_models_host.c: the same calls on the host build of the
 * core, the cross-check of tests/firmware/bench_models.sh). Both link their own
 * bench_clock implementation; this file only calls rfs_bc_*.
 *
 * Workloads, the same as the host benches (docs/PERFORMANCE.md):
 * - "field" (bench/bench_models.c, scripts/bench_models.sh): n samples uniform over
 *   40 x 20 m, -30 - 20 log10(d + 1) dB from (30, 12) m plus 4 dB Gaussian noise, rng
 *   seed 7; fit with the query point (20, 10) m, no map, rng seed 42. The grid search
 *   runs on the firmware's 40 x 20 m box map (0.125 m cells, a wall round the edge,
 *   0.25 m lattice); beside it the 160 x 80 predictions of bench_models.c's loop.
 * - "floor" (bench/bench_pathloss.c, "whole floor"): the office map at 0.1 m, n samples at
 *   random legal points, -40 - 30 log10(d) - 5 dB per wall from (27.5, 10) m plus 4 dB
 *   noise, one rng (seed 7) for the samples and the fit. The pathloss model only.
 * Reachability for rfs_gridmax_find: every legal lattice point (both maps are one
 * connected floor; the seeker's flood fill is internal to rfs_seek).
 *
 * Sliced relearns: at each model's registry budget (rfs_models_entry_t.mcu_fit_budget,
 * the firmware's MCU configuration; also in the check run), then, without RFS_MW_QUICK,
 * the fixed comparison budgets of models_work.c, then the port's extra[] pairs.
 *
 * Lines printed (rfs_bc_report): measurements "<what>_<model>" with ticks (a sliced
 * relearn: "slice_worst_", "slice_last_", "slice_total_<model>_<budget>"); values with
 * ticks 0: "state_bytes_<model>", "slices_<model>_<budget>", "points_<model>",
 * "mcu_budget_<model>" (the registry budget; its slice lines follow), and the
 * cross-check sums "sum_*" (FNV-1a 32 of the samples, of predictions after a whole fit
 * and after a sliced one, of the grid maximum), which host and Cortex-M4 must print alike.
 */
#ifndef RFS_MODELS_WORK_H
#define RFS_MODELS_WORK_H

#include <stdint.h>

#include "rfs_knn.h"
#include "rfs_map.h"
#include "rfs_mlp.h"
#include "rfs_models.h"
#include "rfs_pathloss.h"
#include "rfs_ridge.h"
#include "rfs_seek.h"

/// Most samples of a workload (the paper's maximum).
#define RFS_MW_MAX_SAMPLES 10000u
/// Largest bit grid of the two maps, bytes (box: 320 x 160 cells).
#define RFS_MW_MAX_MAP_BYTES 6400u
/// Largest lattice of the two maps, points (box: 160 x 80).
#define RFS_MW_MAX_LATTICE 12800u
/// Pending measurements ring of the seeker (unused: the bench fits models directly).
#define RFS_MW_PENDING 64u

/// One model state at a time: the union of every registered model's state type.
typedef union rfs_mw_state {
    rfs_ridge_t ridge;       ///< local ridge
    rfs_mlp_t mlp;           ///< MLP
    rfs_knn_t knn;           ///< k- and radius-neighbours
    rfs_pathloss_t pathloss; ///< path-loss model
    uint64_t align;          ///< RFS_MODELS_STATE_ALIGN
} rfs_mw_state_t;

/// Most extra (model, budget) pairs a run measures beside the registry's budgets.
#define RFS_MW_MAX_EXTRA 8u

/// One extra sliced relearn: `model`'s fit at `budget` work units per call.
typedef struct rfs_mw_extra {
    const rfs_models_entry_t *model; ///< registry entry
    uint32_t budget;                 ///< work units per call (> 0)
} rfs_mw_extra_t;

/// Everything the run needs, in one object the port places (static RAM on the M4).
typedef struct rfs_mw_mem {
    rfs_mw_extra_t extra[RFS_MW_MAX_EXTRA];    ///< extra budgets to measure (the port's options)
    uint32_t n_extra;                          ///< how many of extra[] are set
    rfs_mw_state_t state;                      ///< the model being measured
    rfs_sample_t samples[RFS_MW_MAX_SAMPLES];  ///< the workload's samples
    uint8_t legal[RFS_MW_MAX_MAP_BYTES];       ///< the map's derived legal grid
    rfs_map_t map;                             ///< the workload's map
    rfs_seek_t seek;                           ///< seeker, for rfs_gridmax_find only
    rfs_pending_t pending[RFS_MW_PENDING];     ///< its pending ring
    uint8_t plan_work[RFS_MW_MAX_LATTICE];     ///< its planner's work array
    uint32_t plan_queue[8];                    ///< its planner's queue (the minimum)
    uint8_t visited[RFS_MW_MAX_LATTICE / 8u];  ///< novelty bits
    uint8_t reach[RFS_MW_MAX_LATTICE / 8u];    ///< reachability bits (set to the legal points)
} rfs_mw_mem_t;

/// Run flags.
#define RFS_MW_QUICK 1u ///< skip the timing-only extras (the 160 x 80 loop, the pathloss
                        ///< full grid scan, the fixed comparison budgets): the check run

/// Run every registered model on its workload with n samples (1..RFS_MW_MAX_SAMPLES),
/// printing the lines above. Returns 0, or -1 after printing "error <reason>" (n out of
/// range, a map or model rejected, a state larger than rfs_mw_state_t).
int rfs_mw_run(rfs_mw_mem_t *mem, uint32_t n, uint32_t flags);

#endif /* RFS_MODELS_WORK_H */
