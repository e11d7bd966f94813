/* hs_sim.h - the simulator's run loop: world, radio, motor and localisation around a
 * controller (hs_ctrl.h), in simulated time (docs/SIMULATOR.md). The loop is hs_sim.c;
 * what the runs of a scenario share (hs_sim_env_t) hs_sim_env.c; the written results
 * (summary.json, runs.tsv rows) hs_sim_out.c.
 *
 * Time advances in physics ticks (default 20 ms). Each tick: the motor model turns the
 * commands received so far into a body velocity, Box2D moves the robot, and then every
 * sensor and control event inside the tick is delivered in time order at the robot
 * position interpolated to its timestamp: packets (each source at its rate), poses at
 * 10 Hz with Gaussian noise, and control periods; a control period's wheel command
 * reaches the motor model at once and takes effect from the next tick (<= 20 ms
 * latency, like a CAN round trip). Equal times: packets, then poses, then control.
 *
 * Everything random comes from the run seed: radio fields, packet loss and noise, pose
 * noise, and the controller's own seed. Same seed, same bytes.
 */
#ifndef HS_SIM_H
#define HS_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "hs_box2d.h"
#include "hs_ctrl.h"
#include "lx_map.h"
#include "hs_scenario.h"

/// What stays the same for every seed of a scenario: the map, its core grids, and the
/// shortest path from the start to the goal.
typedef struct hs_sim_env {
    hs_scenario_t sc;          ///< the scenario
    lx_map_t map;              ///< the map at its own resolution
    lx_core_map_t core;        ///< the core's grids (core_res_m, clearance_m)
    double shortest_path_m;    ///< start to the legal point nearest the goal, around walls (NaN: no goal)
    double shortest_to_stop_m; ///< start to the first legal point within stop_radius_m (NaN: no goal)
    double x0, y0, x1, y1;     ///< the map's extent, metres
    int8_t *wall_cache[HS_SCN_MAX_SOURCES]; ///< wall counts per receiver cell, shared by runs
    uint16_t *lattice_memo;    ///< the core map's lattice memo (rfs_map_memo_attach), shared by runs
    uint16_t *lattice_edges;   ///< the core map's edge table (rfs_map_edges_attach), shared by runs
    uint8_t *wall_dist;        ///< the core map's wall distances (rfs_map_wall_dist_attach), or NULL
    uint8_t *wall_fwd;         ///< the core map's forward free squares (rfs_map_wall_fwd_attach), or NULL
    uint8_t *wall_cols;        ///< the core map's walls by columns (rfs_map_wall_cols_attach), or NULL
    int32_t *pathloss_log2;    ///< the path-loss model's log2 table (rfs_pathloss_log2_fill), or NULL
    hs_box2d_walls_t walls;    ///< the map's merged wall rectangles, shared by runs' worlds
    hs_box2d_t **world;        ///< the runs' world: made by the first, reset by the next
                               ///< (hs_box2d_reset); one slot, NULL until then
    uint64_t placement;        ///< the drawn placement the start and source are (hs_place.h;
                               ///< hs_sim_env_place), 0: the scenario's own
    uint64_t placement_seed;   ///< the seed it was drawn from
} hs_sim_env_t;

/// Per-run outputs; any may be NULL.
typedef struct hs_sim_io {
    FILE *log;       ///< per-iteration decisions (TSV)
    FILE *samples;   ///< every received packet (TSV)
    FILE *track;     ///< robot pose at each localisation message (TSV)
    /// Every simulated packet (received or lost), e.g. for a pcap writer. May be NULL.
    void (*on_packet)(void *ctx, unsigned src, int64_t t_us, uint16_t seq, bool received,
                      int dbm);
    void *packet_ctx;  ///< passed to on_packet
    FILE *faults;      ///< fault-injection log (hs_faults.h: inputs, commands, events) or NULL
    /// Residual surface of the path-loss model's last fit (TSV: x_m, y_m, residual_db per
    /// coarse candidate), written at the end of the run; only a header for other models.
    FILE *residual;
} hs_sim_io_t;

/// Outcome of one run (summary.json).
typedef struct hs_sim_result {
    uint64_t seed;               ///< the run's seed
    bool reached;                ///< ended within stop_radius_m of the goal
    const char *end;             ///< "reached", "distance", "time"
    double sim_time_s;           ///< simulated time, seconds
    double distance_travelled_m; ///< path length of the true robot position, metres
    double shortest_path_m;      ///< from hs_sim_env_t
    double shortest_to_stop_m;   ///< from hs_sim_env_t
    double final_distance_m;     ///< from the goal at the end (NaN: no goal)
    double final_x, final_y;     ///< final true position, metres
    uint32_t iterations;         ///< decisions made
    uint32_t model_updates;      ///< decisions with the model relearnt
    uint32_t greedy, epsilon;    ///< decisions of each kind
    uint64_t packets_sent;       ///< packets simulated
    uint64_t packets_received;   ///< packets delivered to the controller
    uint32_t motor_timeouts;     ///< times the motor model stopped on a missing command
    uint32_t goal_timeouts;      ///< goals the drive abandoned after its timeout
    uint32_t goal_blocked;       ///< goals the drive abandoned as blocked (no progress)
    uint32_t slow_decisions;     ///< decisions that waited 2 or more control periods for
                                 ///< their search tree (rfs_seek_decision_t.plan_wait):
                                 ///< over 100 ms from the leg's end at 20 Hz
    uint32_t plan_wait_max;      ///< the longest such wait, control periods
    uint32_t decisions_over_100ms; ///< decisions whose latency (below) exceeded 100 ms
    double decision_wait_max_s;  ///< the longest decision latency: from the period a decision
                                 ///< began (a leg's end) to its wheel command, that period
                                 ///< included (a sliced fit's and the search tree's waits)
    double decision_wait_sum_s;  ///< the decisions' latencies summed (summary.json: their mean)
    double turn_time_s;          ///< time turning on the spot (|v| < 2 cm/s, |w| > 0.05 rad/s)
    long wall_contacts;          ///< wall contacts (hs_box2d_wall_contacts)
    double wall_time_s;          ///< host time the run took (not part of determinism)
    double cpu_time_s;           ///< CPU time of this process during the run
    /// The path-loss model's final estimate; false for other models or no fit.
    bool est_valid;
    double est_x, est_y;         ///< estimated source, metres
    double est_n;                ///< path-loss exponent
    double est_w_db;             ///< loss per wall, dB
    double est_p0;               ///< signal at 1 m, target units (dBm for rssi)
    double est_area_m2;          ///< uncertainty: area of the spread region, m^2
    double est_error_m;          ///< distance from the first source's true position, metres
    /// Where the seeker believed the source was at the end: the path-loss estimate when
    /// there is one, else the model maximum of the last greedy decision (NaN: none).
    double belief_x, belief_y;   ///< metres
    double belief_error_m;       ///< its distance from the first source, metres (NaN: none)
    /// How long the robot had stayed within HS_SIM_STILL_RADIUS_M of its final position
    /// when the run ended (whole seconds of simulated time, the run's length at most).
    double still_s;
    uint64_t placement;          ///< from hs_sim_env_t (0: the scenario's own start and source)
    double start_x, start_y, start_theta; ///< the run's start, metres, radians
    double source_x, source_y;   ///< the first source, metres
    /// A bridging run (target bridge; hs_bridge.h): the fields below, else they are unset.
    bool bridge;
    double best_x, best_y;       ///< best point of the true f the robot can reach, metres
    double best_f_db;            ///< the true f there, dB (NaN: no such point)
    double settle_f_db;          ///< the true f at the final position, dB
    double settle_error_m;       ///< final position to the best point, metres
    double settle_travel_m;      ///< travel to settle (hs_bridge_settle_travel), metres
    double far_f_db;             ///< the runner-up's true f (hs_bridge_best), dB (NaN: none)
    /// The model's predicted best point (rfs_fields_estimate); false for other models.
    bool pred_valid;
    double pred_x, pred_y;       ///< predicted best point, metres
    double pred_f_db;            ///< predicted f there, dB
    double pred_sigma_db;        ///< its uncertainty (rfs_fields_est_t.sigma), dB
    double pred_area_m2;         ///< area predicted within sigma of the best, m^2
    /// Each node's path-loss fit then (rfs_pathloss_est_t): x, y (metres), P0 (dBm at
    /// 1 m), n, W (dB a wall), rms residual (dB); NaN without a fit.
    double pred_src[2][6];
} hs_sim_result_t;

/// The radius of hs_sim_result_t.still_s, metres: the robot "parked" at its end point.
#define HS_SIM_STILL_RADIUS_M 2.0

/// Load the map, build the core grids and check the scenario against them (sources and
/// start in free space, start legal, goal reachable within the stop radius). Returns 0, or
/// -1 with err = "file: field: reason".
int hs_sim_env_open(hs_sim_env_t *e, const hs_scenario_t *sc, char *err, size_t errlen);

/// Put the start at (sx, sy, stheta) and the first source, and the goal with it, at
/// (gx, gy) (metres, radians), as drawn placement `index` of `seed` (hs_place.h): checked
/// and the shortest paths redone as hs_sim_env_open does. The scenario must have one
/// source and no goal of its own. 0, or -1 with err (the environment is then unusable).
int hs_sim_env_place(hs_sim_env_t *e, uint64_t index, uint64_t seed, double sx, double sy,
                     double stheta, double gx, double gy, char *err, size_t errlen);

/// Release (safe on a zeroed env).
void hs_sim_env_close(hs_sim_env_t *e);

/// Run one mission with a controller. Returns 0, or -1 with err (world or radio setup).
int hs_sim_run(const hs_sim_env_t *e, uint64_t seed, hs_ctrl_t *ctrl, const hs_sim_io_t *io,
               hs_sim_result_t *res, char *err, size_t errlen);

/// Run one mission with the in-process controller (the scenario's model and target,
/// controller seeded from `seed`).
int hs_sim_run_inproc(const hs_sim_env_t *e, uint64_t seed, const hs_sim_io_t *io,
                      hs_sim_result_t *res, char *err, size_t errlen);

/// Write the simulated field of source `src` for `seed` (the same fields as a run with
/// that seed) on every free point of a grid `step_m` apart, as TSV: x_m, y_m, walls,
/// mean_dbm (no fading), signal_dbm (with fading), dbm of one packet (empty when lost).
/// Returns 0, or -1 with err.
int hs_sim_field(const hs_sim_env_t *e, uint64_t seed, unsigned src, double step_m, FILE *f,
                 char *err, size_t errlen);

/// The last columns of log.tsv: the path-loss model's estimate at a decision.
#define HS_SIM_LOG_EST_COLUMNS "est_src_x_m\test_src_y_m\test_n\test_w_db\test_p0\test_area_m2"

/// A decision's kind as log.tsv names it: initial, greedy, epsilon, or the baseline's.
const char *hs_sim_kind_name(rfs_seek_kind_t k);

/// How the goal before a decision ended, as log.tsv's reason names it (prev=...).
const char *hs_sim_prev_name(rfs_drive_status_t s);

/// One log.tsv row (newline included): decision d made at t_s, the robot's true pose
/// (x_m, y_m, theta) and distance travelled then; its reason column names the decision's
/// flags (docs/SIMULATOR.md, "Outputs"). rfseek-sim's and rfseek-feed's logs alike.
void hs_sim_log_decision(FILE *f, const hs_ctrl_t *ctrl, const rfs_seek_decision_t *d, double t_s,
                         double x_m, double y_m, double theta, double travelled_m);

/// Decision d, made in the control period at now_us (period_us long), into r's counts:
/// iterations, relearns, kinds, goals timed out or blocked, slow decisions and the
/// decision waits (rfseek-sim's and rfseek-feed --pose's summary.json alike).
void hs_sim_count_decision(hs_sim_result_t *r, const rfs_seek_decision_t *d, int64_t now_us,
                           int64_t period_us);

/// End a log.tsv decision row: a tab, the HS_SIM_LOG_EST_COLUMNS values (source m, n,
/// W dB, P0, spread area m^2) and a newline; "nan" unless the controller's model is
/// "pathloss" and has a fit.
void hs_sim_log_estimate(FILE *f, const hs_ctrl_t *ctrl);

/// Fill r->est_* from the controller's path-loss estimate (est_valid false and NaN for
/// other models), the error against the true source position (src_x, src_y), metres.
void hs_sim_result_estimate(hs_sim_result_t *r, const hs_ctrl_t *ctrl, double src_x,
                            double src_y);

/// Write summary.json of a run to f.
void hs_sim_write_summary(FILE *f, const hs_sim_env_t *e, const hs_sim_result_t *r);

/// Header line of the batch table (TSV; scripts/merge_runs.py writes the same); `placed`:
/// the table of a batch over drawn placements (a placement column first, the start, the
/// source and the end-of-run belief and parking columns after the others); `bridge`: the
/// bridging columns (HS_SIM_BRIDGE_COLUMNS) last.
void hs_sim_table_header(FILE *f, bool placed, bool bridge);

/// One row of the batch table ("nan" where a value does not exist), with the bridging
/// columns for a bridging run.
void hs_sim_table_row(FILE *f, const hs_sim_result_t *r, bool placed);

/// The batch table's columns of a bridging run, after the others.
#define HS_SIM_BRIDGE_COLUMNS "best_x_m\tbest_y_m\tbest_f_db\tsettle_f_db\tsettle_error_m\t" \
    "settle_travel_m\tpred_x_m\tpred_y_m\tpred_f_db\tpred_sigma_db\tpred_area_m2\tfar_f_db"


#endif /* HS_SIM_H */
