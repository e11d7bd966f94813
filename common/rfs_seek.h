/* rfs_seek.h - the meta-algorithm (paper section 2, Algorithm 1) as a control-loop core.
 *
 *   do random movement
 *   while not at source:
 *     parse messages
 *     if |mean RSSI over last second - model prediction at current position| > threshold:
 *       discard current model; learn new model on all available data
 *     if random() > epsilon: go min(dist to goal, step width) towards the model's maximum
 *     else: do random (novelty-driven) movement
 *
 * The application feeds poses and measurements as they arrive (rfs_seek_on_pose,
 * rfs_seek_on_rssi) and calls rfs_seek_step() at its control rate (e.g. 20 Hz) with the
 * current time and its randomness source; each call returns the wheel command. An
 * iteration of the algorithm is one goal: it is decided when the previous goal ends
 * (reached, timed out or blocked) and then driven to. The decision carries its reason.
 * Wheels are commanded to zero while pose or measurements are stale. A receiver that
 * reports itself up (rfs_seek_on_receiver) keeps the measurement stream fresh without
 * packets: in a radio dead zone "no packet here" is an observation, not a failed sensor.
 */
#ifndef RFS_SEEK_H
#define RFS_SEEK_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_drive.h"
#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_model.h"
#include "rfs_plan.h"
#include "rfs_reach.h"
#include "rfs_rssi.h"
#include "rfs_store.h"
#include "rfs_target.h"

/// How the seeker chooses its goals (docs/STRATEGIES.md). Every strategy uses the same sensors,
/// step width, map legality and path planner; only the decision rule differs.
typedef enum rfs_seek_strategy {
    RFS_SEEK_META = 0,       ///< the meta-algorithm, paper section 2 (default)
    RFS_SEEK_META_GLOBAL,    ///< the same; the caller gives the model a map-wide radius
    RFS_SEEK_FD_GRADIENT,    ///< finite differences: 1 s means at p, p + step x, p + step y
    RFS_SEEK_PLANE_GRADIENT, ///< refit every step, always a step along the model's gradient
    RFS_SEEK_CHEMOTAXIS,     ///< run-and-tumble on the change of the 1 s mean, no position
    RFS_SEEK_META_PATH,      ///< meta, but a greedy step walks `step` along the planned path
                             ///< to the maximum instead of a straight step + line search
    RFS_SEEK_STRATEGY_COUNT  ///< number of strategies (not a strategy)
} rfs_seek_strategy_t;

/// Seeker configuration; rfs_seek_cfg_default() is exactly the paper's.
typedef struct rfs_seek_cfg {
    rfs_q16_t step;             ///< step width, metres Q16.16 (paper: 1 m)
    rfs_q16_t initial_step_max; ///< longest initial random move, metres Q16.16 (2 x step)
    rfs_q16_t error_threshold;  ///< relearn when |mean - prediction| exceeds this (3 dB)
    rfs_q16_t eps_floor;        ///< epsilon = eps_amp * e^(-eps_rate * n) + eps_floor (0.1)
    rfs_q16_t eps_amp;          ///< (0.9)
    rfs_q16_t eps_rate;         ///< per iteration, Q16.16: ln(9/4)/5 so epsilon(5) = 0.5
    rfs_q16_t novelty_radius;   ///< epsilon goals keep this far from past positions (0.5 m)
    int64_t pose_timeout_us;    ///< pose older than this is stale: wheels stop (150 ms)
    int64_t rssi_timeout_us;    ///< no measurement and no receiver report for this long is
                                ///< stale: wheels stop (150 ms)
    uint32_t fit_budget;        ///< work units per control period for model learning (0 = all)
    bool fit_early;             ///< with fit_budget: the next decision's relearn begins on
                                ///< the samples so far, after a failed recheck (the base
                                ///< braking) or within RFS_SEEK_EARLY_GOAL of the goal once
                                ///< the 1 s mean fails the check (docs/FIRMWARE.md, "Learning
                                ///< between periods"); false: relearns at rest
    uint32_t plan_budget;       ///< lattice points a control period adds to the search tree
                                ///< of the next decision (docs/PERFORMANCE.md, "Planning in
                                ///< slices"; RFS_SEEK_PLAN_BUDGET); 0: every plan searches
                                ///< within the decision
    uint32_t reach_budget;      ///< lattice points the reachability flood expands a control
                                ///< period, wheels stopped (0: the whole flood in one period)
    rfs_rssi_cfg_t rssi;        ///< averaging window (1 s)
    rfs_store_cfg_t store;      ///< sample store (10,000 samples)
    rfs_drive_cfg_t drive;      ///< drive control (TurtleBot 2)
    rfs_seek_strategy_t strategy; ///< decision rule (RFS_SEEK_META: the paper's)
    rfs_q16_t tumble_better;    ///< chemotaxis: P(tumble) after the mean rose, Q16.16 (0.2)
    rfs_q16_t tumble_worse;     ///< chemotaxis: P(tumble) after it fell or stayed, Q16.16 (1.0)
    /* Improvements beside the paper (docs/STRATEGIES.md); 0 / false is the paper's rule. */
    rfs_q16_t recheck_dist;     ///< run the relearn check again after every this many metres
                                ///< of a greedy leg and decide anew when it fails, Q16.16
                                ///< (0: only when a goal ends, the paper's)
    bool eps_by_travel;         ///< epsilon's n = max(iteration, metres travelled / step):
                                ///< one long leg anneals as much as the 1 m steps it replaces
    bool recheck_adapt;         ///< an in-leg recheck fails only when the miss exceeds the
                                ///< larger of error_threshold and the RMS of the recent
                                ///< misses: a model that misses by 5 dB everywhere (SLAM
                                ///< clutter, shadowing) is not relearnt at every metre
    bool eps_geodesic;          ///< epsilon goals drawn with P proportional to e^(-path
                                ///< length) instead of e^(-straight distance): a point
                                ///< behind a wall is as far as the way round it
    bool eps_sample;            ///< an epsilon goal is a draw from the model's belief
                                ///< (rfs_model_ops_t.sample, when the model has one): a
                                ///< plausible source, driven to and rechecked like a
                                ///< greedy leg; the novelty draw instead when the draw is
                                ///< within 1.5 steps of the robot or where it has been, or
                                ///< the robot stands within 1.5 steps of the model's argmax
    rfs_q16_t refute_r;         ///< a decision at the model's argmax (within half a step)
                                ///< whose 1 s mean is weaker than the prediction by more
                                ///< than 2 error_threshold, or that has no mean while the
                                ///< receiver is up, rules out the source within this
                                ///< radius of the argmax for every later fit (Algorithm 1
                                ///< still runs: the source is not here), metres Q16.16 (0:
                                ///< off); keep it below the "at source" radius less half a
                                ///< step
    bool refute_reached;        ///< with refute_r: a decision at the argmax after a greedy
                                ///< null move there (the robot stood a window at it) rules
                                ///< it out whatever the 1 s mean (the mission goes on, so
                                ///< the source is not there): the fit's next best place is
                                ///< visited next, a local search round a near miss (off in
                                ///< every preset: docs/STRATEGIES.md, "Stalls")
    rfs_q16_t local_r;          ///< a greedy goal at a known argmax the robot has been to
                                ///< (its lattice point, or its reachable stand-in's, is
                                ///< visited) becomes the unvisited reachable lattice point
                                ///< within this radius of it nearest to the robot and to it
                                ///< (least sum of the straight distances): a local search
                                ///< round an estimate already stood at, metres Q16.16 (0:
                                ///< off, stand at it)
    rfs_q16_t local_gap;        ///< with local_r: a local search's goal also keeps this far
                                ///< from every visited lattice point (within the novelty
                                ///< radius of a past position), so its sweeps lie about
                                ///< novelty_radius + local_gap apart, metres Q16.16 (0: any
                                ///< unvisited point)
    bool local_refute;          ///< with local_r and refute_r: a greedy decision whose
                                ///< local search finds no goal left rules
                                ///< the estimate out as refute_r does and relearns at the
                                ///< next decision, instead of standing at it
    rfs_q16_t at_tol;           ///< the drive's goal tolerance (drive.goal_tol otherwise) on
                                ///< a whole greedy leg to a known argmax and on a local
                                ///< search's goal: the robot stands at the estimate, not
                                ///< half drive.goal_tol short of it, metres Q16.16 (0: off)
    rfs_q16_t near_t;           ///< with a model that answers near (the path-loss model)
                                ///< and a known argmax at least near_min from the robot: a
                                ///< greedy goal at the unvisited reachable place more than 4
                                ///< steps from it with the most weight e^(-chi2 / 2 near_t)
                                ///< per metre (straight, plus 5 steps) when that beats the
                                ///< argmax and its path is at most 1.3 x straight + 2 steps:
                                ///< a nearer plausible source first (docs/STRATEGIES.md,
                                ///< "Stalls"), Q16.16 (0: off)
    rfs_q16_t near_min;         ///< see near_t, metres Q16.16
    rfs_q16_t floor_gap;        ///< with a model that answers floor_gap (the path-loss
                                ///< model): a fit whose source power lies less than this
                                ///< above the model's floor (pinned: a weak source near the
                                ///< robot, seldom within 5 m of the real one) has its
                                ///< estimate ruled out as refute_r does, the next decision
                                ///< relearns, and this one explores (epsilon) instead of
                                ///< going greedy, dB Q16.16 (0: off)
    uint8_t floor_max;          ///< with floor_gap: at most this many estimates ruled out
                                ///< for the floor a mission, later pinned fits believed (a
                                ///< weak node's fit stays pinned, a wrong one seldom pins
                                ///< more than twice; docs/STRATEGIES.md, "Stalls"), 0: no limit
    rfs_q16_t mean_t;           ///< with a model that answers mean (the path-loss model): a
                                ///< greedy goal is the belief's mean at this temperature,
                                ///< not its argmax, when the mean lies 1.5 steps or more
                                ///< from the robot and no wall crosses the lines robot-mean
                                ///< and mean-argmax: early data leave bearing and distance
                                ///< open and the argmax flips between far guesses; in the
                                ///< open the mean hedges between them (a tight belief's
                                ///< mean is its argmax), Q16.16 (0: off)
    rfs_q16_t leg_max;          ///< a greedy leg to a known argmax ends after this much of
                                ///< its path (the next decision relearns and may explore),
                                ///< metres Q16.16 (0: the whole path)
    uint32_t reach_min;         ///< the robot's reachable component holding fewer lattice
                                ///< points than this is a pocket (sealed off in clutter,
                                ///< joined by a tie in the snap): the component of the
                                ///< nearest legal lattice point outside it is taken instead
                                ///< when larger (0: off, the robot's own)
    rfs_q16_t silence_floor;    ///< target rssi: while the receiver reports itself up and
                                ///< no packet came for a whole averaging window, every pose
                                ///< adds a sample of this value: the fit learns where the
                                ///< source is below the receiver's floor (a dead zone)
                                ///< instead of never seeing the place, dBm Q16.16
                                ///< (INT32_MIN: none, the paper's)
    bool recheck_silent;        ///< with recheck_dist and silence_floor: an in-leg check
                                ///< in a silent window (as for silence_floor) takes the
                                ///< floor as its mean and misses by how far the prediction
                                ///< lies above it: a leg planned from a dead zone is not
                                ///< driven blind
    rfs_q16_t settle_dist;      ///< after this much travel every choice is greedy (epsilon
                                ///< 0): the robot goes to the model's best point and stays
                                ///< there, metres Q16.16 (0: never, the paper's)
    rfs_q16_t settle_orbit;     ///< after settle_dist, at the best point (a greedy goal
                                ///< within half this): a move to a reachable lattice
                                ///< point about this far from it, to measure more fades
                                ///< round it, and a relearn at every decision, metres
                                ///< Q16.16 (0: none, stand still)
    rfs_q16_t settle_end;       ///< no orbit once this much has been travelled, metres
                                ///< Q16.16 (0: no end)
    rfs_q16_t src_spacing;      ///< per-source stores (rfs_seek_mem_t.src_samples): a
                                ///< source's sample is the mean of its packets since the
                                ///< robot last moved this far, metres Q16.16 (0: one sample
                                ///< per packet)
    rfs_q16_t src_floor;        ///< with src_spacing: a source not heard for one averaging
                                ///< window while another is gets a sample of this value at
                                ///< every src_spacing of travel, dBm Q16.16 (INT32_MIN: none)
} rfs_seek_cfg_t;

/// One source's own samples, for a model fitted per source (rfs_seek_mem_t.src): its store
/// and the running mean src_spacing builds. Caller-owned.
typedef struct rfs_seek_src {
    rfs_store_t store;   ///< the source's RSSI samples, dBm
    int32_t sum;         ///< src_spacing: dBm summed since its last sample
    uint16_t cnt;        ///< packets in sum
    bool at;             ///< x and y are valid
    rfs_q16_t x;         ///< robot x at its last sample, metres Q16.16
    rfs_q16_t y;         ///< robot y there, metres Q16.16
    bool heard;          ///< heard_us and first_us are valid
    int64_t heard_us;    ///< its latest packet, microseconds
    int64_t first_us;    ///< its first packet, microseconds
} rfs_seek_src_t;

/// Caller-owned memory for the seeker's large arrays.
typedef struct rfs_seek_mem {
    rfs_sample_t *samples;     ///< cfg.store.capacity samples
    rfs_pending_t *pending;    ///< pending measurements ring
    uint16_t pending_cap;      ///< its capacity (>= 64; 256 for two 200 pkt/s sources)
    uint8_t *plan_work;        ///< one byte per lattice point
    uint32_t plan_work_bytes;  ///< its size
    uint32_t *plan_queue;      ///< planner queue
    uint32_t plan_queue_cap;   ///< its capacity
    uint8_t *visited;          ///< one bit per lattice point: within the novelty radius of a past position
    uint32_t visited_bytes;    ///< its size, rfs_reach_bytes(map) = (lw * lh + 7) / 8
    uint8_t *reach;            ///< one bit per lattice point: reachable from the robot's position
    uint32_t reach_bytes;      ///< its size, rfs_reach_bytes(map)
    /// Optional (NULL: none), for a model fitted per source (rfs_fields.h): one state per
    /// source of the target, whose store holds cfg.store.capacity samples in src_samples[i]
    /// and pending_cap pending measurements in src_pending[i]. The seeker then also keeps
    /// each source's RSSI as samples.
    rfs_seek_src_t *src;
    rfs_sample_t *src_samples[RFS_TARGET_MAX_SOURCES]; ///< the stores' sample arrays
    rfs_pending_t *src_pending[RFS_TARGET_MAX_SOURCES]; ///< their pending rings
    /// Optional (NULL: none): an empty index of cfg.store.capacity slots kept with the
    /// store (rfs_cellsum_index(); the local ridge's whole fits read it).
    const rfs_store_index_t *index;
} rfs_seek_mem_t;

/// Why an iteration chose its goal.
typedef enum rfs_seek_kind {
    RFS_SEEK_NONE = 0, ///< no decision
    RFS_SEEK_INITIAL,  ///< the initial random move (up to initial_step_max)
    RFS_SEEK_GREEDY,   ///< towards the model's maximum
    RFS_SEEK_EPSILON,  ///< novelty-driven random move
    RFS_SEEK_PROBE,    ///< fd-gradient: to p + step along one axis, to measure there
    RFS_SEEK_GRADIENT, ///< fd- or plane-gradient: a step along the estimated gradient
    RFS_SEEK_RUN,      ///< chemotaxis: a step on in the same heading
    RFS_SEEK_TUMBLE,   ///< chemotaxis (or a gradient without direction): a new random heading
} rfs_seek_kind_t;

/// Controller state.
typedef enum rfs_seek_state {
    RFS_SEEK_WAITING = 0, ///< no pose, or neither a measurement nor a receiver report yet
    RFS_SEEK_STALE,       ///< inputs went stale: wheels stopped
    RFS_SEEK_LEARNING,    ///< a sliced fit or search tree is in progress: wheels stopped
    RFS_SEEK_DRIVING,     ///< following the current goal
} rfs_seek_state_t;

/// reach_min's flood stages (rfs_seek_t.reach_pocket).
typedef enum rfs_seek_pocket {
    RFS_SEEK_POCKET_OWN = 0, ///< the flood of the robot's own component
    RFS_SEEK_POCKET_BESIDE,  ///< it was a pocket: the flood from the nearest point outside it
    RFS_SEEK_POCKET_AGAIN,   ///< that one was no larger: the pocket flooded again, kept
} rfs_seek_pocket_t;

/// Fault flags (bits of rfs_seek_out_t.faults).
enum {
    RFS_SEEK_FAULT_POSE_STALE = 1u << 0, ///< no pose within pose_timeout_us
    RFS_SEEK_FAULT_RSSI_STALE = 1u << 1, ///< no measurement nor receiver report within
                                         ///< rssi_timeout_us (or one stamped beyond it ahead)
    RFS_SEEK_FAULT_NO_GOAL = 1u << 2,    ///< no legal, reachable goal was found
    RFS_SEEK_FAULT_OFF_MAP = 1u << 3,    ///< the robot's position is not on the known map
};

/// One iteration's decision and its reasons (for logs, status messages and plots).
typedef struct rfs_seek_decision {
    uint32_t iteration;        ///< n, counted from 0 (the initial move)
    int64_t t_us;              ///< when it was decided, microseconds
    rfs_seek_kind_t kind;      ///< initial, greedy or epsilon
    bool relearned;            ///< the model was discarded and learnt again this iteration
    bool line_search;          ///< the greedy step was illegal; the line search chose the goal
    bool model_valid;          ///< a model existed for the check
    bool mean_valid;           ///< a 1 s mean existed for the check
    rfs_drive_status_t prev;   ///< how the previous goal ended
    rfs_q16_t prediction;      ///< model prediction at the position (before relearning), target units
    rfs_q16_t mean;            ///< 1 s mean of the target at decision time
    rfs_q16_t epsilon;         ///< epsilon for this iteration, Q16.16
    rfs_q16_t x, y;            ///< position at decision time, metres Q16.16
    rfs_q16_t goal_x, goal_y;  ///< chosen goal, metres Q16.16
    rfs_q16_t max_x, max_y;    ///< model maximum found by the grid search (greedy), or the
                               ///< model's draw (a sampled epsilon step)
    bool sampled;              ///< epsilon: the goal is the model's draw (cfg.eps_sample)
    bool near;                 ///< greedy: the goal is a nearer plausible source (cfg.near_t)
    bool hedged;               ///< greedy: the goal is the belief's mean (cfg.mean_t)
    bool pinned;               ///< greedy drawn, but the fit's power lay within
                               ///< cfg.floor_gap of its floor: ruled out, epsilon instead
    bool refuted;              ///< the argmax was ruled out before this decision's fit
                               ///< (cfg.refute_r)
    rfs_q16_t path_len;        ///< planned path length, metres Q16.16
    uint16_t plan_wait;        ///< control periods the robot stood for the search tree
                               ///< (plan_budget; 0: the tree grown on the leg served)
    uint16_t samples;          ///< samples in the store
} rfs_seek_decision_t;

/// What one control period produces.
typedef struct rfs_seek_out {
    int16_t left_mm_s;          ///< left wheel speed command, mm/s
    int16_t right_mm_s;         ///< right wheel speed command, mm/s
    rfs_seek_state_t state;     ///< controller state
    uint16_t faults;            ///< RFS_SEEK_FAULT_* bits
    bool decided;               ///< a new decision was made this period
    rfs_seek_decision_t decision; ///< the latest decision (new when `decided`)
} rfs_seek_out_t;

/// fit_early: the relearn begins within this distance of the goal, metres Q16.16 (0.15 m,
/// about 0.5 s before rest on the Kobuki; farther costs more travel, docs/FIRMWARE.md).
#define RFS_SEEK_EARLY_GOAL ((rfs_q16_t)9830)
/// Default plan_budget: 640 lattice points a period (about 330,000 instructions on the
/// Cortex-M4), the 12,800-point lattice of a 40 x 20 m map in 20 periods (1 s).
#define RFS_SEEK_PLAN_BUDGET 640u

/// Search-tree points a control period that drives (or stands) without choosing adds:
/// 5/4 plan_budget, the choice's room (800 by default, about 440,000 instructions).
#define RFS_SEEK_DRIVE_SLICE(budget) ((budget) + (budget) / 4u)

/// Work units (3/4 of the fit budget) a driving period the search tree leaves free gives the model's warming
/// (rfs_model_ops_t.warm), of its fit budget: a leg's drive work beside it keeps the
/// period within the fit slice's (docs/PERFORMANCE.md, "Decision latency").
#define RFS_SEEK_WARM_SLICE(budget) ((budget) - (budget) / 4u)

/// reach_budget for the microcontroller: 1,000 lattice points a period (docs/PERFORMANCE.md,
/// "Firmware"); rfs_seek_cfg_default() keeps 0, the whole flood in one period.
#define RFS_SEEK_REACH_BUDGET 1000u

/// Epsilon candidates lie within this many lattice steps (32 x 0.25 m = 8 m: e^-8 = 3e-4,
/// the mass beyond is 0.3 % of the distribution); the weight table is indexed by di^2+dj^2.
#define RFS_SEEK_EPS_RADIUS 32
#define RFS_SEEK_EPS_TABLE (RFS_SEEK_EPS_RADIUS * RFS_SEEK_EPS_RADIUS + 1)

/// Number of sources the seeker keeps windows for.
#define RFS_SEEK_MAX_SOURCES RFS_TARGET_MAX_SOURCES

/// The seeker: every piece of state the meta-algorithm needs, caller-owned (~6 KB plus
/// the arrays of rfs_seek_mem_t).
typedef struct rfs_seek {
    rfs_seek_cfg_t cfg;                       ///< configuration copied at init
    const rfs_map_t *map;                     ///< the map
    rfs_model_t model;                        ///< the internal model
    const rfs_target_ops_t *target;           ///< the target function
    rfs_rssi_t win[RFS_SEEK_MAX_SOURCES];     ///< 1 s windows per source
    rfs_store_t store;                        ///< samples
    rfs_seek_src_t *src;                      ///< each source's own samples (rfs_seek_mem_t.src),
                                              ///< NULL: none
    rfs_plan_t plan;                          ///< planner
    rfs_drive_t drive;                        ///< drive control
    uint8_t *visited;                         ///< novelty bits, one per lattice point
    uint8_t *reach;                           ///< reachability bits, one per lattice point
    uint32_t *queue;                          ///< flood-fill queue (shared with the planner)
    uint32_t queue_cap;                       ///< its capacity
    bool reach_valid;                         ///< reach holds the robot's component
    bool flooding;                            ///< reach_budget: a sliced flood is under way
    rfs_reach_flood_t flood;                  ///< its state
    rfs_seek_pocket_t reach_pocket;           ///< reach_min: the flood stage
    uint32_t reach_own;                       ///< reach_min: the pocket's lattice points
    uint16_t eps_w[RFS_SEEK_EPS_TABLE];       ///< e^(-d) by squared lattice offset, Q0.16
    rfs_pose_t pose;                          ///< latest pose
    bool have_pose;                           ///< pose is valid
    int64_t last_meas_us;                     ///< time of the latest accepted measurement
    bool have_meas;                           ///< a measurement has been accepted
    int64_t last_rx_us;                       ///< latest accepted receiver report, microseconds
    bool have_rx;                             ///< a receiver report has been accepted
    uint32_t rx_rejected;                     ///< receiver reports older than the latest
    rfs_seek_state_t state;                   ///< controller state
    uint32_t iteration;                       ///< next iteration number
    bool fitting;                             ///< a sliced fit is in progress
    bool fit_ended;                           ///< rfs_seek_background() ended it: the next
                                              ///< period finishes the decision
    bool early;                               ///< fit_early: the fit began as the base braked
    rfs_q16_t fit_qx, fit_qy;                 ///< the fit's query point, metres Q16.16
    uint8_t early_nexcl, early_excl_next;     ///< fit_early: places ruled out as it began
    rfs_model_settle_t early_settle;          ///< fit_early: the settle phase as it began
    bool early_refuted;                       ///< fit_early: the leg's maximum ruled out as
                                              ///< it began (refute_r)
    bool planning;                            ///< plan_budget: a decision waits for its
                                              ///< search tree (grown from the robot)
    bool plan_ready;                          ///< the decision's plans walk that tree
    uint16_t plan_wait;                       ///< periods the decision has waited for it
    rfs_seek_decision_t decision;             ///< latest decision
    rfs_drive_status_t prev_status;           ///< how the last goal ended
    uint32_t meas_rejected;                   ///< measurements with a bad source index
    bool resume;                              ///< a goal was interrupted by stale inputs
    rfs_path_t resume_path;                   ///< the path to resume
    uint16_t resume_next;                     ///< the waypoint it was approaching
    int64_t resume_start_us;                  ///< how long the interrupted goal had been driven, microseconds
    uint16_t last_li, last_lj;                ///< lattice point of the last novelty update
    bool have_last_l;                         ///< last_li/last_lj are valid
    /* Baseline strategies (rfs_seek_baseline.c). */
    bool dwell_done;                          ///< fd: the robot has stood one window here
    int64_t dwell_until_us;                   ///< fd: wheels stay stopped until then, microseconds
    uint8_t fd_phase;                         ///< fd: 0 at p, 1 at the x probe, 2 at the y probe
    int8_t fd_sx, fd_sy;                      ///< fd: probe direction per axis (+1, -1; 0 = none)
    rfs_q16_t fd_px, fd_py;                   ///< fd: the point p, metres Q16.16
    rfs_q16_t fd_m0, fd_mx;                   ///< fd: 1 s means at p and at the x probe, target units
    uint8_t heading;                          ///< chemotaxis: heading, sixteenths of a turn
    bool have_prev_mean;                      ///< chemotaxis: prev_mean is valid
    rfs_q16_t prev_mean;                      ///< chemotaxis: 1 s mean at the last decision
    int64_t retry_after_us;                   ///< no goal, or a null move: next decision not before, us
    bool retry_no_goal;                       ///< the wait is for no goal (RFS_SEEK_FAULT_NO_GOAL)
    bool parked;                              ///< refute_reached: the last decision was
                                              ///< a greedy null move (goal where it stood)
    /* Improvements (cfg.recheck_dist, cfg.eps_by_travel). */
    bool have_chk;                            ///< chk_x/chk_y are valid
    rfs_q16_t chk_x, chk_y;                   ///< position of the last check, metres Q16.16
    int64_t travel;                           ///< straight distance summed over checks, metres Q16.16
    bool replan;                              ///< a recheck failed: relearn and go greedy again
    int64_t miss_ms;                          ///< recheck_adapt: running mean of the squared
                                              ///< recheck misses |mean - prediction|, dB^2 Q16.16
    uint8_t nexcl;                            ///< refute_r: places ruled out so far (at most
                                              ///< RFS_MODEL_MAX_EXCL; then the oldest goes)
    uint8_t excl_next;                        ///< refute_r: the slot the next one takes
    int16_t excl_x_cm[RFS_MODEL_MAX_EXCL];    ///< refute_r: their x, centimetres
    int16_t excl_y_cm[RFS_MODEL_MAX_EXCL];    ///< refute_r: their y, centimetres
    uint8_t nfloor;                           ///< floor_gap: estimates ruled out for the
                                              ///< floor so far (saturates at 255)
    bool have_sub;                            ///< sub_* hold the latest unreachable maximum
    rfs_q16_t sub_mx, sub_my;                 ///< an unreachable greedy maximum, metres Q16.16
    rfs_q16_t sub_x, sub_y;                   ///< the reachable point driven to instead
} rfs_seek_t;

/// The paper's parameters (section 2 and 5.2): the `meta` configuration.
rfs_seek_cfg_t rfs_seek_cfg_default(void);

/// Choose a strategy with its named preset: sets cfg->strategy and the improvement
/// fields, on for RFS_SEEK_META_PATH (recheck_dist = cfg->step, eps_by_travel,
/// recheck_adapt, eps_geodesic, eps_sample, refute_r = cfg->step, silence_floor = -100
/// dBm, recheck_silent, local_r = 4 cfg->step, local_gap = cfg->step / 2, at_tol = 3 cm,
/// local_refute, reach_min = 16; floor_gap stays 0),
/// the paper's (0, false) for every other strategy.
void rfs_seek_cfg_use_strategy(rfs_seek_cfg_t *cfg, rfs_seek_strategy_t strategy);

/// The settings for a model fitted per source (rfs_fields.h; docs/STRATEGIES.md,
/// "Bridging"): src_spacing 4 cm, src_floor -100 dBm, settle_dist 100 m, settle_orbit
/// 0.25 m, settle_end 125 m, refute_r 0, local_r 0, at_tol 0, silence_floor none (src_floor
/// instead).
void rfs_seek_cfg_per_source(rfs_seek_cfg_t *cfg);

/// Initialise. Returns 0, or -1 when the configuration is out of range, a memory array
/// is missing or too small for the map's lattice, the target needs more sources than
/// RFS_SEEK_MAX_SOURCES, or per-source stores are given for some of its sources only.
int rfs_seek_init(rfs_seek_t *s, const rfs_seek_cfg_t *cfg, const rfs_map_t *map,
                  rfs_model_t model, const rfs_target_ops_t *target, const rfs_seek_mem_t *mem);

/// A pose arrived. false when rejected (not newer than the latest).
bool rfs_seek_on_pose(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng);

/// A measurement from source `src` (index into the target's sources) arrived.
/// false when rejected (bad source, out of order).
bool rfs_seek_on_rssi(rfs_seek_t *s, uint8_t src, int64_t t_us, int8_t dbm, rfs_rng_t *rng);

/// The receiver is up and listening at t_us, whether or not it heard a packet (a
/// heartbeat, e.g. once per control period). Keeps the measurement stream fresh like a
/// measurement does, but adds no sample and never makes a 1 s mean valid: in a radio
/// dead zone the current goal is driven on and decisions are made without a mean.
/// false when rejected (older than the latest report; equal stamps are accepted, as for
/// measurements). A caller that never calls it gets the measurement-only rule.
bool rfs_seek_on_receiver(rfs_seek_t *s, int64_t t_us);

/// One control period at now_us: decide when the current goal has ended, drive, and
/// report. Cannot fail.
void rfs_seek_step(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out);

/// After rfs_seek_step(): the wheels are held at zero from outside this period (a safety
/// stop of the caller's: bus-off, a receive-time watchdog). As for stale inputs, the drive
/// stops (its next command ramps up from rest), a goal being driven is resumed at the
/// next step that finds the inputs fresh, and *out (that step's output) says so: wheels
/// zero, state as the seeker's own stale period reports it.
void rfs_seek_hold(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out);

/// Spare time after a control period (docs/FIRMWARE.md, "Learning between periods"): one
/// more fit_budget slice of a fit the wheels wait for, so that the decision it holds up is
/// made at the next period. Touches nothing else (no wheel command, no decision). true
/// when another call would do more; false with no such fit (fit_budget 0, or none running).
bool rfs_seek_background(rfs_seek_t *s, rfs_rng_t *rng);

/// rfs_seek_background() up to n times, while it has more to do (a port without a clock to
/// guard the next period: replays, rfseekd, the simulator). Returns the calls that left
/// more to do.
uint32_t rfs_seek_background_n(rfs_seek_t *s, rfs_rng_t *rng, uint32_t n);

/// The in-leg relearn check on one miss |1 s mean - prediction| (target units Q16.16, >= 0):
/// true when it fails, i.e. the miss exceeds error_threshold, or with recheck_adapt the
/// larger of error_threshold and the RMS of the recent misses; *miss_ms (dB^2 Q16.16,
/// start at 0) is the running mean of the squared misses, moved 1/8 of the way (C
/// integer division) towards this miss squared (clamped to 128 dB) at every call.
bool rfs_seek_recheck_miss(const rfs_seek_cfg_t *cfg, int64_t *miss_ms, rfs_q16_t miss);

/// epsilon(n) = eps_amp * e^(-eps_rate * n) + eps_floor, Q16.16.
rfs_q16_t rfs_seek_epsilon(const rfs_seek_cfg_t *cfg, uint32_t n);

/// Name of a strategy as on the command line ("meta", "meta-global", "fd-gradient",
/// "plane-gradient", "chemotaxis", "meta-path"); "?" for a value out of range.
const char *rfs_seek_strategy_name(rfs_seek_strategy_t st);

/// The strategy named `name` (NUL-terminated, exact). false when there is none.
bool rfs_seek_strategy_parse(const char *name, rfs_seek_strategy_t *st);

/// Name of a decision kind for logs ("initial", "greedy", "epsilon", "probe", "gradient",
/// "run", "tumble"; "none").
const char *rfs_seek_kind_name(rfs_seek_kind_t k);

/// Unit vector along (gx, gy) (any common scale), Q16.16; false when g = 0.
/// Scaling and overflow: g is doubled until max(|gx|, |gy|) >= 2^29 (< 2^31 after), so
/// the squares sum below 2^63 in uint64 and the root keeps 29 bits; (g << 16) / |g| in
/// int64; components clamped to [-1, 1].
bool rfs_seek_unit(rfs_q16_t gx, rfs_q16_t gy, rfs_q16_t *ux, rfs_q16_t *uy);

#endif /* RFS_SEEK_H */
