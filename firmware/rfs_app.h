/* rfs_app.h - the application loop shared by every firmware port.
 *
 * One rfs_app_t holds everything the controller needs at run time: the seeker
 * (common/rfs_seek.h, paper section 2, Algorithm 1), the local ridge model (section
 * 5.2.1), the random source and every large array, all as fixed-size members sized by the
 * compile-time maxima below, so a port declares ONE static rfs_app_t and needs no heap;
 * only the 60 KB sample store (rfs_app_cfg_t.samples) and a larger model's state are the
 * port's, placed where they fit (docs/FIRMWARE.md, "What the STM32 image holds").
 *
 * A port feeds what arrives, in arrival order, and calls rfs_app_step() at the control
 * rate (RFS_APP_PERIOD_US):
 *   - decoded inputs: rfs_app_on_pose(), rfs_app_on_rssi(), rfs_app_on_receiver() (the
 *     receiver heartbeat; the Linux/LCM port), or
 *   - raw CAN frames: rfs_app_on_can() (the STM32 and emulator ports; decoding by
 *     common/rfs_can.h),
 *   - transport state: rfs_app_set_bus_off() (bxCAN bus-off, SocketCAN error state),
 *   - the mission configuration: a CONFIG frame (rfs_app_on_config()), applied only
 *     before the first decision.
 * rfs_app_step() returns the wheel command and the status; rfs_app_frames() encodes them
 * as the CAN frames of docs/CAN.md.
 *
 * Safety: besides the seeker's own staleness rule on input timestamps, the
 * application commands zero wheel speed whenever no pose or no RSSI input (a measurement
 * or a receiver heartbeat) has been RECEIVED for input_timeout_us of local time (150 ms <
 * the 200 ms requirement), and
 * while the bus is off. Zero output comes at once, without the drive's acceleration ramp.
 * After a watchdog reset the port calls rfs_app_init() again: the first step outputs zero
 * with RFS_APP_FAULT_RESET set. Driving resumes by itself when inputs return.
 *
 * Times: every *_us argument is int64 microseconds of ONE clock, the controller's. The
 * ports translate sender timestamps into it (rfs_can time unwrapping, and the senders'
 * epoch with cfg.follow_epoch); in a replay the recorded times are that clock.
 */
#ifndef RFS_APP_H
#define RFS_APP_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_can.h"
#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_models.h"
#include "rfs_pathloss.h"
#include "rfs_ridge.h"
#include "rfs_seek.h"
#include "rfs_store.h"

/// Samples held for learning (paper section 5.2: at most 10,000), 6 bytes each, in the
/// port's array (rfs_app_cfg_t.samples).
#define RFS_APP_MAX_SAMPLES 10000u
/// Largest bit grid, bytes (the derived legal grid lives in RAM): at 0.1 m cells e.g.
/// 40 x 12.8 m or 25.6 x 20 m; a 40 x 20 m map fits at 0.125 m cells (320 x 160).
/// Sized with the path-loss state to the STM32 image's budgets (docs/FIRMWARE.md).
#define RFS_APP_MAX_MAP_BYTES 6400u
/// Largest lattice, points: a 40 x 20 m map at 0.25 m is 160 x 80.
#define RFS_APP_MAX_LATTICE (160u * 80u)
/// Planner queue entries: 2 * (lw + lh) for the largest lattice (rfs_plan.h: "safe").
#define RFS_APP_PLAN_QUEUE 480u
/// Pending measurements waiting for a bracketing pose (>= 64 required by rfs_seek).
#define RFS_APP_PENDING 64u
/// Work units the MCU configuration learns per control period with the built-in local
/// ridge (the "ridge" registry entry's mcu_fit_budget, tested equal): 0, a whole fit: on
/// 10,000 samples about 323,000 instructions, under the 500,000 of a period, and the
/// choice comes the period after (rfs_seek_cfg_t.plan_budget), so a decision that relearns
/// takes two periods, 100 ms (docs/PERFORMANCE.md, "Decision latency"). Other models have
/// their own budget in the registry (rfs_models_entry_t.mcu_fit_budget; rfs_app_fit_budget()).
#define RFS_APP_MCU_FIT_BUDGET 0u
/// Model state built into rfs_app_t, bytes: the local ridge's; any other model's state is
/// the port's (rfs_app_cfg_t.model_state).
#define RFS_APP_MODEL_BYTES ((uint32_t)sizeof(rfs_ridge_t))
/// Control period, microseconds (20 Hz).
#define RFS_APP_PERIOD_US 50000
/// Fit slices (rfs_app_background()) a port runs in a control period's spare time, after
/// the period's step: a period at 168 MHz is 8.4 M cycles; the step's worst about 480,000
/// instructions and ten path-loss slices of at most 429,409 use 4.8 M, leaving 40 % for
/// cycles per instruction above one and the CAN polls between slices (docs/FIRMWARE.md,
/// "Learning between periods").
#define RFS_APP_BACKGROUND_SLICES 10u

/// Application fault bits, in the high byte of rfs_app_out_t.faults (the low byte holds
/// the seeker's RFS_SEEK_FAULT_* bits).
enum {
    RFS_APP_FAULT_POSE_LOST = 1u << 8,  ///< no pose received for input_timeout_us
    RFS_APP_FAULT_RSSI_LOST = 1u << 9,  ///< no RSSI nor receiver heartbeat received for input_timeout_us
    RFS_APP_FAULT_BUS_OFF = 1u << 10,   ///< the CAN controller is bus-off
    RFS_APP_FAULT_RESET = 1u << 11,     ///< first step after a (watchdog) reset
    RFS_APP_FAULT_BAD_FRAME = 1u << 12, ///< a frame failed to decode since the last step
};

/// Which target function the seeker maximises (rfs_target.h).
typedef enum rfs_app_target {
    RFS_APP_TARGET_RSSI = 0,   ///< one source's RSSI (paper section 2)
    RFS_APP_TARGET_BRIDGE = 1, ///< two sources, f = -|R1 - R2| - |R1 + R2| (section 6)
} rfs_app_target_t;

/// A map as the port holds it: bit grids at the core's resolution (rfs_map.h), e.g.
/// const arrays in flash. free/wall must outlive the application.
typedef struct rfs_app_map {
    uint16_t w;            ///< width, cells
    uint16_t h;            ///< height, cells
    rfs_q16_t res;         ///< metres per cell, Q16.16
    rfs_q16_t origin_x;    ///< x of the lower-left corner of cell (0, 0), metres Q16.16
    rfs_q16_t origin_y;    ///< y of that corner, metres Q16.16
    const uint8_t *free;   ///< 1 = free, rfs_map_bytes(w, h) bytes
    const uint8_t *wall;   ///< 1 = occupied, same size; may be NULL
} rfs_app_map_t;

/// Application configuration.
///
/// The internal model (docs/MODELS.md, "Choosing a model") is chosen by a registry entry,
/// `model = rfs_models_lookup(name)`, the same names as the simulator and the feeder;
/// NULL is the paper's local ridge. Its state lives in the application's own
/// RFS_APP_MODEL_BYTES (the ridge's) or in a buffer the port provides (model_state,
/// aligned to RFS_MODELS_STATE_ALIGN); rfs_app_init() rejects a model whose state does
/// not fit (rfs_app_model_fits() says which). The ridge uses `ridge`, the path-loss model
/// `pathloss`, every other model its registry defaults. Registry lookups stay in the
/// ports, so an image links only the models it names.
typedef struct rfs_app_cfg {
    rfs_seek_cfg_t seek;        ///< seeker (rfs_seek_cfg_default(): the paper's numbers)
    const rfs_models_entry_t *model; ///< internal model (rfs_models_lookup()); NULL = ridge
    void *model_state;          ///< port's buffer for the model state; NULL = the built-in one
    uint32_t model_state_bytes; ///< its size, bytes (0 with model_state NULL)
    rfs_ridge_cfg_t ridge;      ///< local ridge (5 m radius, alpha 1)
    rfs_pathloss_cfg_t pathloss; ///< path-loss model (rfs_pathloss_cfg_default(); CONFIG
                                ///< sets p0_min)
    rfs_sample_t *samples;      ///< the sample store: seek.store.capacity samples the port
                                ///< owns (required; e.g. CCM on the STM32)
    /// The models a CONFIG frame may choose, by its model code (RFS_CAN_MODEL_*): NULL is
    /// not offered (rejected), except the ridge's code, whose NULL is the built-in ridge.
    const rfs_models_entry_t *models[RFS_CAN_NMODELS];
    rfs_map_cfg_t map;          ///< clearance and lattice (0.25 m, 0.25 m)
    rfs_app_target_t target;    ///< target function
    uint64_t seed;              ///< seed of the random source (epsilon moves, reservoir)
    int64_t input_timeout_us;   ///< zero wheels when nothing was received for this long (150 ms)
    uint8_t node_id;            ///< this controller's id in the status frame
    /// Optional (ops NULL: none): a model the port built on its own memory, used instead
    /// of `model` and its state: one fit per source (rfs_fields.h, the `pathloss` entry
    /// under the bridging target), with each source's own store below (the Linux port;
    /// the STM32 image has the memory for none, docs/FIRMWARE.md).
    rfs_model_t built;
    /// With `built`: each source's own samples (rfs_seek_mem_t.src), its store of
    /// seek.store.capacity samples and RFS_APP_PENDING pending measurements; NULL: none.
    rfs_seek_src_t *src;
    rfs_sample_t *src_samples[RFS_TARGET_MAX_SOURCES]; ///< the stores' sample arrays
    rfs_pending_t *src_pending[RFS_TARGET_MAX_SOURCES]; ///< their pending rings
    /// true (rfs_app_cfg_mcu()): rfs_app_init() replaces seek.fit_budget by the configured
    /// model's registry budget (mcu_fit_budget; RFS_APP_MCU_FIT_BUDGET for a NULL model),
    /// so a port that sets `model` after taking the MCU defaults gets that model's slice
    /// size. false (rfs_app_cfg_default(), replays): seek.fit_budget is used as given.
    bool fit_budget_by_model;
    /// The CAN receiver follows the senders' epoch (rfs_can_rx_cfg_t.follow_epoch): true in
    /// rfs_app_cfg_mcu() and the replays of its image, whose clock counts from boot; false
    /// (rfs_app_cfg_default(), rfseekd): the senders stamp in the controller's own clock.
    bool follow_epoch;
} rfs_app_cfg_t;

/// What one control period produces (the content of the wheel command and status frames).
typedef struct rfs_app_out {
    int64_t t_us;               ///< time of the step, microseconds
    int16_t left_mm_s;          ///< left wheel speed command, mm/s
    int16_t right_mm_s;         ///< right wheel speed command, mm/s
    rfs_seek_state_t state;     ///< seeker state (RFS_SEEK_STALE while any stop holds the wheels:
                                ///< the seeker's own stale inputs or the application's stops)
    uint16_t faults;            ///< RFS_SEEK_FAULT_* | RFS_APP_FAULT_*
    bool decided;               ///< a new decision was made this period
    rfs_seek_decision_t decision; ///< the latest decision (new when `decided`)
} rfs_app_out_t;

/// Input and transport counters (for the status frame and the logs).
typedef struct rfs_app_stats {
    uint32_t poses;             ///< poses accepted by the seeker
    uint32_t rssi;              ///< measurements accepted by the seeker
    uint32_t receiver;          ///< receiver heartbeats accepted by the seeker
    uint32_t rejected;          ///< inputs the seeker rejected (order, bad source)
    uint32_t bad_frames;        ///< CAN frames that failed to decode (DLC, checksum)
    uint32_t unknown_frames;    ///< CAN frames with ids that are not ours
    uint32_t steps;             ///< control periods run
    uint32_t configs;           ///< CONFIG frames applied
    uint32_t configs_rejected;  ///< CONFIG frames rejected (not idle, or not held)
} rfs_app_stats_t;

/// The application: every byte the controller uses at run time but the sample store and
/// a port's model state (about 35 KB with the maxima above). Declare one static instance
/// per port.
typedef struct rfs_app {
    rfs_app_cfg_t cfg;                              ///< configuration copied at init
    rfs_seek_t seek;                                ///< the meta-algorithm
    rfs_ridge_t ridge;                              ///< built-in model state (the local ridge's)
    rfs_map_t map;                                  ///< the map (grids owned by the port)
    rfs_app_map_t map_in;                           ///< the port's map (a CONFIG re-initialises on it)
    rfs_rng_t rng;                                  ///< the random source
    int64_t pose_rx_us;                             ///< local time the last pose arrived
    int64_t rssi_rx_us;                             ///< local time the last RSSI or heartbeat arrived
    bool have_pose_rx;                              ///< a pose has arrived since init
    bool have_rssi_rx;                              ///< an RSSI or heartbeat has arrived since init
    bool bus_off;                                   ///< the transport reports bus-off
    bool after_reset;                               ///< no step has run since init
    bool bad_frame;                                 ///< a frame failed since the last step
    rfs_can_rx_t can_rx;                            ///< CAN receiver: counters, pose pairing
    rfs_can_tx_t can_tx;                            ///< CAN sender: rolling counters
    rfs_app_stats_t stats;                          ///< counters
    rfs_app_out_t last;                             ///< output of the latest step
    rfs_pending_t pending[RFS_APP_PENDING];         ///< measurements awaiting a pose
    uint8_t legal[RFS_APP_MAX_MAP_BYTES];           ///< derived legal bits
    uint8_t plan_work[RFS_APP_MAX_LATTICE];         ///< planner marks, one byte per point
    uint32_t plan_queue[RFS_APP_PLAN_QUEUE];        ///< planner queue
    uint8_t visited[(RFS_APP_MAX_LATTICE + 7u) / 8u]; ///< novelty bits, one per point
    uint8_t reach[(RFS_APP_MAX_LATTICE + 7u) / 8u];   ///< reachability bits, one per point
} rfs_app_t;

/// Defaults: the paper's configuration (rfs_seek_cfg_default, rfs_ridge_cfg_default,
/// rfs_map_cfg_default), RSSI target, seed 1, 150 ms input timeout, node 1.
rfs_app_cfg_t rfs_app_cfg_default(void);

/// The microcontroller configuration: the defaults with each model's fit sliced over
/// control periods as the registry says, so that no period comes near the 200 ms safety
/// deadline: fit_budget_by_model set, and seek.fit_budget = RFS_APP_MCU_FIT_BUDGET (the
/// ridge's, a whole fit; rfs_app_init() takes another model's from the registry), and the
/// boot's flood fill in slices. Decisions are the same; the wheels wait while a fit runs.
/// The CAN receiver follows the senders' epoch (follow_epoch).
rfs_app_cfg_t rfs_app_cfg_mcu(void);

/// The fit budget (work units per control period) rfs_app_init() gives the seeker for
/// cfg: with fit_budget_by_model, cfg->model's mcu_fit_budget (RFS_APP_MCU_FIT_BUDGET for
/// NULL, the built-in ridge); otherwise cfg->seek.fit_budget.
uint32_t rfs_app_fit_budget(const rfs_app_cfg_t *cfg);

/// Bytes of model state the configuration provides (model_state_bytes, or
/// RFS_APP_MODEL_BYTES without a port buffer).
uint32_t rfs_app_model_capacity(const rfs_app_cfg_t *cfg);

/// true when cfg->model's state fits the configured state buffer (NULL: the ridge, fits).
bool rfs_app_model_fits(const rfs_app_cfg_t *cfg);

/// Set what a CONFIG frame or a replay's CFG record chooses: target, strategy (its preset,
/// rfs_seek_cfg_use_strategy()), model (NULL: the built-in ridge) and the path-loss
/// p0_min (dBm Q16.16, INT32_MIN: no floor). Returns 0, or -1 leaving cfg unchanged when
/// the image does not hold that choice: target out of range, a strategy other than meta
/// and meta-path, a state larger than the model buffer, a model
/// fitted per source under a target of several sources without a port-built model
/// (`built`: the STM32 image has no room for two path-loss states), or a port-built
/// model in place.
int rfs_app_cfg_choose(rfs_app_cfg_t *cfg, rfs_app_target_t target, rfs_seek_strategy_t strategy,
                       const rfs_models_entry_t *model, rfs_q16_t p0_min);

/// Initialise (also after a watchdog reset). Returns 0, or -1 when the map is larger
/// than the compile-time maxima or invalid, the sample store is missing, the model's state
/// does not fit (or the buffer is misaligned), or the seeker rejects the configuration.
int rfs_app_init(rfs_app_t *a, const rfs_app_cfg_t *cfg, const rfs_app_map_t *map);

/// A decoded pose arrived at local time rx_us. false when the seeker rejected it.
bool rfs_app_on_pose(rfs_app_t *a, const rfs_pose_t *pose, int64_t rx_us);

/// A decoded RSSI measurement (source index src, taken at t_us, dbm) arrived at local
/// time rx_us. false when the seeker rejected it.
bool rfs_app_on_rssi(rfs_app_t *a, uint8_t src, int64_t t_us, int8_t dbm, int64_t rx_us);

/// A receiver heartbeat (docs/FAULTS.md): the radio's capture loop was
/// listening up to t_us (its own capture clock, the packets' clock), heard or not; it
/// arrived at local time rx_us. Refreshes the RSSI input's receive-time watchdog like a
/// packet and calls rfs_seek_on_receiver(), which judges the stamp as it judges a
/// packet's: older than the newest heartbeat is rejected, one further ahead of now than
/// rssi_timeout_us makes the stream stale (a clock jump). false when rejected.
bool rfs_app_on_receiver(rfs_app_t *a, int64_t t_us, int64_t rx_us);

/// A CONFIG frame (docs/CAN.md, "0x130 CONFIG"): while no decision has been made since
/// init, re-initialises with its seed, its fit_early (RFS_CAN_FIT_EARLY_KEEP: the one in
/// force) and rfs_app_cfg_choose() of its target, strategy, model (cfg.models[code]) and
/// p0_min, keeping the counters and the CAN state. false,
/// counted in stats.configs_rejected, when a decision was made or the image does not
/// hold the choice; the configuration in force is unchanged then.
bool rfs_app_on_config(rfs_app_t *a, const rfs_can_config_t *c);

/// The transport went bus-off (true) or recovered (false).
void rfs_app_set_bus_off(rfs_app_t *a, bool off);

/// One control period at local time now_us. Cannot fail.
void rfs_app_step(rfs_app_t *a, int64_t now_us, rfs_app_out_t *out);

/// After a step, in the period's spare time: one more slice of a fit the wheels wait for
/// (rfs_seek_background()); true when another call would do more. Ports call it up to
/// RFS_APP_BACKGROUND_SLICES times a period (none when the next step is due).
bool rfs_app_background(rfs_app_t *a);

/// rfs_app_background() up to RFS_APP_BACKGROUND_SLICES times (rfs_seek_background_n()):
/// the ports that run a period's slices without a clock to watch (replays, rfseekd).
void rfs_app_background_all(rfs_app_t *a);

/// A raw CAN frame arrived at local time rx_us: decoded with rfs_can (pose pairs, RSSI,
/// receiver heartbeat, CONFIG; other ids counted as unknown) and fed to the seeker. Returns
/// the decode result.
rfs_can_err_t rfs_app_on_can(rfs_app_t *a, const rfs_can_frame_t *f, int64_t rx_us);

/// A step's wheel command as WHEEL_CMD carries it: the speeds, and Stop whenever the
/// seeker is not driving or a safety stop holds (lost inputs, bus-off, reset; a bad frame
/// alone stops nothing). rfs_app_frames() and rfseekd's RFS_WHEEL_CMD copy both use it.
rfs_can_wheel_t rfs_app_wheel(const rfs_app_out_t *out);

/// Encode a step's output as its CAN frames, in sending order: frames[0] = WHEEL_CMD,
/// frames[1] = STATUS. Advances the rolling counters. Returns 2.
uint8_t rfs_app_frames(rfs_app_t *a, const rfs_app_out_t *out, rfs_can_frame_t frames[2]);

#endif /* RFS_APP_H */
