/* hs_ctrl.h - the controller seam of the simulator: what drives the simulated robot.
 *
 * The simulator (hs_sim) knows a controller only through these callbacks. It feeds the
 * simulated sensors in simulated time order and calls step() at the controller's own
 * period; step() answers with the wheel command and, when an iteration of the
 * meta-algorithm (paper section 2) was decided in that period, the decision record.
 *
 * Implementations:
 *   - in-process over the core's rfs_seek (hs_ctrl_inproc_open() below, hs_ctrl.c);
 *   - two-process: an implementation that publishes on_pose/on_rssi on LCM and
 *     returns the wheel command received over CAN (its own file, same interface);
 *   - baseline strategies: other implementations of the same interface.
 * Ordering contract: calls arrive with non-decreasing time: every on_pose/on_rssi with a
 * timestamp <= now_us is delivered before step(now_us). A controller that receives its
 * inputs late (over a wire) simply answers with the newest command it has.
 */
#ifndef HS_CTRL_H
#define HS_CTRL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rfs_fields.h"
#include "rfs_pathloss.h"
#include "rfs_seek.h"

/// What one control period produces: the core's own output record (wheel command in
/// mm/s, state, faults, and the decision when `decided`).
typedef rfs_seek_out_t hs_ctrl_out_t;

/// A controller: callbacks plus the implementation's state.
typedef struct hs_ctrl {
    const char *name;   ///< short name for logs ("meta", "lcm", ...)
    void *self;         ///< implementation state, passed to every callback
    int64_t period_us;  ///< control period, microseconds (in-process default 50 ms, 20 Hz)
    /// A localisation pose (map frame, metres Q16.16, time in pose->t_us).
    void (*on_pose)(void *self, const rfs_pose_t *pose);
    /// A received packet from source `src` (index in scenario order) at t_us with dbm.
    void (*on_rssi)(void *self, uint8_t src, int64_t t_us, int8_t dbm);
    /// Optional (may be NULL): the receiver is up and listening at t_us, packet or not
    /// (a heartbeat keeps a radio dead zone from reading as a failed sensor).
    void (*on_receiver)(void *self, int64_t t_us);
    /// One control period at now_us: the wheel command and the latest decision.
    void (*step)(void *self, int64_t now_us, hs_ctrl_out_t *out);
    /// Optional (may be NULL): the model's prediction at (x, y) in target units Q16.16,
    /// for logs and plots; false when there is no model.
    bool (*predict)(void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value);
    /// Release everything the controller holds (self included). May be NULL.
    void (*close)(void *self);
    /// Optional (may be NULL): the path-loss model's state when the controller's model is
    /// "pathloss" (estimate and residual surface for logs and plots), else NULL.
    const rfs_pathloss_t *(*pathloss)(void *self);
    /// Optional (may be NULL): the per-source fits when the controller's model runs as one
    /// fit per source (rfs_models_per_source(): pathloss under bridge), else NULL.
    const rfs_fields_t *(*fields)(void *self);
    /// Optional (may be NULL): the path-loss estimate of a controller that reports it
    /// without its model's state (over LCM); false when it has none. Else `pathloss`'s.
    bool (*estimate)(void *self, rfs_pathloss_est_t *est);
} hs_ctrl_t;

/// Configuration of the in-process controller over rfs_seek.
typedef struct hs_ctrl_inproc_cfg {
    rfs_seek_cfg_t seek;    ///< seeker configuration (rfs_seek_cfg_default(): the paper's)
    const char *model;      ///< internal model by name (rfs_models.h): "ridge" is the paper's
    const char *target;     ///< target by name: "rssi" (one source), "bridge" (two) or
                            ///< "pdr" (one; measurements are rfs_pdr_value() percentages)
    uint64_t seed;          ///< seed of the controller's own randomness (epsilon moves)
    int64_t period_us;      ///< control period, microseconds (50,000)
    double p0_min_dbm;      ///< pathloss model only: floor on the signal at 1 m, dBm, in
                            ///< [-200, 100] (NAN: the model's default, -45)
    double coarse_footprint_m; ///< pathloss model only: its coarse pass's footprint,
                            ///< metres, in [0, 0.5] (NAN: the model's default, 0.25)
    int coarse_snap;        ///< pathloss model only: 0 / 1 its coarse points snapped to
                            ///< legal ones in their cells (-1: the model's default, on)
    double p0_max_wall_db;  ///< pathloss model only: the most a wall costs in the P0 held
                            ///< against the ceiling, dB, in [0, 60] (NAN: off)
    const int32_t *pathloss_log2; ///< pathloss model only: a log2 table to attach
                            ///< (rfs_pathloss_log2_fill(), outliving the controller) or NULL
    bool pathloss_builtin_cache; ///< pathloss model only: keep the built-in wall-count cache
                            ///< (the Cortex-M4's) instead of attaching the host's
    uint32_t fit_slices;    ///< rfs_seek_background() calls after each period (the
                            ///< firmware's spare time; 0: none)
} hs_ctrl_inproc_cfg_t;

/// Defaults: the paper's seeker, local ridge, RSSI of one source, 20 Hz.
hs_ctrl_inproc_cfg_t hs_ctrl_inproc_cfg_default(void);

/// Open the in-process controller on a core map (which must outlive it). Returns 0, or -1
/// with err = "reason" (unknown model or target, core init failed, out of memory).
int hs_ctrl_inproc_open(hs_ctrl_t *c, const hs_ctrl_inproc_cfg_t *cfg, const rfs_map_t *map,
                        char *err, size_t errlen);

/// true when `name` is a model hs_ctrl_inproc_open() knows (the rfs_models registry).
bool hs_ctrl_model_known(const char *name);

/// Close any controller (calls its close callback; safe on a zeroed one).
void hs_ctrl_close(hs_ctrl_t *c);

#endif /* HS_CTRL_H */
