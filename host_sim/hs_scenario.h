/* hs_scenario.h - simulator scenario files (YAML, libyaml), docs/SIMULATOR.md.
 *
 *   map: maps/office.yaml          # ROS map_server YAML, relative to this file (required)
 *   seed: 1
 *   model: ridge                   # internal model (paper section 5.2)
 *   target: rssi                   # rssi (one source), bridge (two, paper section 6) or
 *                                  # pdr (one: packet delivery ratio, rfs_pdr.h)
 *   strategy: meta                 # meta (the paper), meta-global, fd-gradient,
 *                                  # plane-gradient, chemotaxis, meta-path
 *   seek: {recheck_m: 1.0, eps_by_travel: true, eps_rate: 0.162, eps_geodesic: true,
 *                                  #       recheck_adapt: true, eps_sample: true, refute_m: 1,
 *                                  #       silence_floor: true, refute_reached: false,
 *                                  #       recheck_silent: true,
 *                                  #       p0_min_dbm: -32, local_m: 0, leg_m: 0,
 *                                  #       coarse_footprint_m: 0.25,
 *                                  #       p0_max_wall_db: 3, local_gap_m: 0.5,
 *                                  #       at_tol_m: 0.03, near_t: 0, near_m: 30,
 *                                  #       coarse_snap: true, reach_min: 16,
 *                                  #       fit_budget: 30, floor_db: 1, floor_max: 2}
 *                                  # optional: override the strategy's
 *                                  # preset improvements (docs/STRATEGIES.md)
 *   sources:                       # required, 1 or 2
 *     - name: ap
 *       position: [30.0, 8.0]      # metres, map frame
 *       mac: "02:00:00:00:00:01"
 *       rate_hz: 200               # packets per second (paper section 5)
 *       tx_dbm: 20
 *   start: {position: [5.0, 2.0], theta: 0.0}   # required
 *   localisation: {rate_hz: 10, sigma_xy_m: 0.05, sigma_theta_rad: 0.02,
 *                  drift_m: 0, drift_tau_s: 10, jump_m: 0.3, jump_rate_hz: 0.0167,
 *                  jump_tau_s: 3}
 *   radio: {pathloss: {...}, walls: {...}, shadowing: {...}, fading: {...}, noise: {...},
 *           receiver: {...}}       # every part has `enabled`; see docs/RADIO_MODEL.md;
 *                                  # receiver: {heartbeat: true} reports the receiver up to
 *                                  # the controller every period (false: packets only)
 *   motor: {accel_m_s2: 1.0, timeout_ms: 200}
 *   stop: {radius_m: 1.5, max_distance_m: 150, max_time_s: 900, goal: [x, y]}
 *   sim: {physics_hz: 50, core_res_m: 0.1, clearance_m: 0.25}
 *   faults:                        # optional fault schedule (docs/FAULTS.md)
 *     - {kind: rssi_silence, start_s: 30, duration_s: 30}
 *
 * Unknown keys anywhere are errors. Errors are one line "file:line: field: reason".
 * Checks that need the map (positions inside walls, a stop condition that can never
 * trigger) are done by hs_sim_env_open().
 */
#ifndef HS_SCENARIO_H
#define HS_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hs_faults.h"
#include "hs_motor.h"
#include "hs_radio.h"

/// Most sources a scenario may have (the core's targets combine at most two).
#define HS_SCN_MAX_SOURCES 2u

/// One source.
typedef struct hs_scn_source {
    char name[32];       ///< label for logs
    double x, y;         ///< position, metres (map frame)
    uint8_t mac[6];      ///< MAC address (for pcap output)
    double rate_hz;      ///< packets per second (200)
    double tx_dbm;       ///< transmit power, dBm (20)
} hs_scn_source_t;

/// A loaded scenario.
typedef struct hs_scenario {
    char path[1024];              ///< the scenario file
    char seek_cli[256];           ///< rfseek-sim --seek: the keys overriding seek: ("" none)
    char map_path[1024];          ///< the map YAML, resolved against the scenario's folder
    uint64_t seed;                ///< default seed (1)
    char model[32];               ///< internal model name ("ridge")
    char target[16];              ///< target name ("rssi"; "bridge" with two sources; "pdr")
    char strategy[32];            ///< strategy name ("meta")
    double seek_recheck_m;        ///< seek.recheck_m: relearn check every this many metres
                                  ///< of a greedy leg (-1 = the strategy's preset)
    double seek_refute_m;         ///< seek.refute_m: radius ruled out round a refuted argmax
                                  ///< (rfs_seek_cfg_t.refute_r; 0: off; -1 = the preset)
    double seek_local_m;          ///< seek.local_m: local search radius round an estimate
                                  ///< stood at (rfs_seek_cfg_t.local_r; 0: off; -1 = preset)
    int seek_local_refute;        ///< seek.local_refute: 0 / 1 (rfs_seek_cfg_t; -1 = preset)
    double seek_local_gap_m;      ///< seek.local_gap_m: a local search goal's distance from
                                  ///< visited points (rfs_seek_cfg_t.local_gap; -1 = preset)
    double seek_at_tol_m;         ///< seek.at_tol_m: goal tolerance at the estimate
                                  ///< (rfs_seek_cfg_t.at_tol; 0: off; -1 = the preset)
    double seek_near_t;           ///< seek.near_t: a nearer plausible source first
                                  ///< (rfs_seek_cfg_t.near_t; 0: off; -1 = the preset)
    double seek_near_m;           ///< seek.near_m: rfs_seek_cfg_t.near_min (-1 = the preset)
    double seek_fit_slices;       ///< seek.fit_slices: fit slices in each period's spare time
                                  ///< (hs_ctrl_inproc_cfg_t.fit_slices; -1 = 0)
    int seek_fit_early;           ///< seek.fit_early: 0 / 1, a failed recheck's relearn
                                  ///< begins as the base brakes (-1 = off)
    double seek_reach_min;        ///< seek.reach_min: lattice points of the smallest component
                                  ///< kept (rfs_seek_cfg_t.reach_min; 0: off; -1 = preset)
    double seek_fit_budget;       ///< seek.fit_budget: the model's work units a control period
                                  ///< (rfs_seek_cfg_t.fit_budget; 0: a whole fit; -1 = 0)
    bool fit_mcu;                 ///< rfseek-sim --fit-budget mcu: also the path-loss model's
                                  ///< built-in wall-count cache, as on the Cortex-M4
    double seek_leg_m;            ///< seek.leg_m: longest greedy leg to a known argmax
                                  ///< (rfs_seek_cfg_t.leg_max; 0: whole; -1 = the preset)
    double seek_floor_db;         ///< seek.floor_db: rfs_seek_cfg_t.floor_gap, dB (0: off;
                                  ///< -1 = the preset)
    double seek_floor_max;        ///< seek.floor_max: rfs_seek_cfg_t.floor_max, 0..255 (0: no
                                  ///< limit; -1 = the preset)
    double seek_mean_t;           ///< seek.mean_t: rfs_seek_cfg_t.mean_t (0: off; -1 = the
                                  ///< preset)
    int seek_refute_reached;      ///< seek.refute_reached: 0 / 1 (rfs_seek_cfg_t; -1 = the
                                  ///< strategy's preset)
    int seek_silence_floor;       ///< seek.silence_floor: 0 / 1, floor samples (-100 dBm) in
                                  ///< silence (rfs_seek_cfg_t; -1 = the strategy's preset)
    int seek_recheck_silent;      ///< seek.recheck_silent: 0 / 1 (-1 = the strategy's preset)
    int seek_eps_by_travel;       ///< seek.eps_by_travel: 0 / 1 (-1 = the strategy's preset)
    int seek_eps_geodesic;        ///< seek.eps_geodesic: 0 / 1 (-1 = the strategy's preset)
    int seek_recheck_adapt;       ///< seek.recheck_adapt: 0 / 1 (-1 = the strategy's preset)
    int seek_eps_sample;          ///< seek.eps_sample: 0 / 1 (-1 = the strategy's preset)
    double seek_eps_rate;         ///< seek.eps_rate: epsilon's decay per iteration (-1 = the
                                  ///< paper's ln(9/4)/5, epsilon(5) = 0.5)
    double seek_p0_min_dbm;       ///< seek.p0_min_dbm: the pathloss model's floor on the
                                  ///< signal at 1 m, dBm (NAN = its default, -45; other
                                  ///< models ignore it; docs/PATHLOSS.md "The P0 floor")
    double seek_coarse_footprint_m; ///< seek.coarse_footprint_m: the pathloss model's
                                  ///< coarse-pass footprint, metres (NAN = its default, 0.25;
                                  ///< 0: one count a coarse bin, docs/PATHLOSS.md)
    int seek_coarse_snap;         ///< seek.coarse_snap: 0 / 1, the pathloss model's coarse
                                  ///< points in corridors off the 2 m grid (-1 = its
                                  ///< default, on; docs/PATHLOSS.md "Fit")
    double seek_p0_max_wall_db;   ///< seek.p0_max_wall_db: the most a wall costs in the P0 the
                                  ///< pathloss model holds against its ceiling, dB (NAN = off;
                                  ///< docs/PATHLOSS.md "The P0 floor")
    unsigned nsources;            ///< sources
    hs_scn_source_t src[HS_SCN_MAX_SOURCES]; ///< the sources
    double start_x, start_y;      ///< robot start, metres
    double start_theta;           ///< robot start heading, radians
    double pose_rate_hz;          ///< localisation rate (10)
    double pose_sigma_xy_m;       ///< localisation noise per axis, metres (0.05)
    double pose_sigma_theta_rad;  ///< heading noise, radians (0.02)
    double pose_drift_m;          ///< AMCL-like drift: bound of a correlated position error,
                                  ///< metres (0 = off; docs/SIMULATOR.md, "Localisation")
    double pose_drift_tau_s;      ///< its correlation time, seconds (10)
    double pose_jump_m;           ///< size of an occasional jump of the estimate, metres (0.3)
    double pose_jump_rate_hz;     ///< jumps per second (1/60)
    double pose_jump_tau_s;       ///< a jump decays back with this time constant, seconds (3)
    hs_radio_cfg_t radio;         ///< radio model
    bool rx_heartbeat;            ///< radio.receiver.heartbeat: the controller is told the
                                  ///< receiver is up every control period (true)
    hs_motor_cfg_t motor;         ///< motor-controller model
    double stop_radius_m;         ///< reached within this of the goal (1.5; 0 = off)
    double stop_distance_m;       ///< stop after this much travel (150; 0 = off)
    double stop_time_s;           ///< stop after this much simulated time (900; 0 = off)
    bool has_goal;                ///< goal given explicitly
    double goal_x, goal_y;        ///< goal for stop_radius_m (default: the first source)
    double physics_hz;            ///< physics steps per second (50)
    double core_res_m;            ///< core map resolution, metres (0.1)
    double clearance_m;           ///< core legality clearance, metres (0.25)
    hs_faults_cfg_t faults;       ///< fault schedule (none by default; docs/FAULTS.md)
} hs_scenario_t;

/// Defaults for everything optional (map, sources and start still missing).
void hs_scenario_defaults(hs_scenario_t *sc);

/// Load and check a scenario file. Returns 0, or -1 with err = "file:line: reason".
int hs_scenario_load(const char *path, hs_scenario_t *sc, char *err, size_t errlen);

/// Override seek: keys with text "KEY: VALUE[, KEY: VALUE...]" (rfseek-sim --seek), checked
/// as the file's; kept in sc->seek_cli. Returns 0, or -1 with err = one line.
int hs_scenario_seek(hs_scenario_t *sc, const char *text, char *err, size_t errlen);

/// Parse "aa:bb:cc:dd:ee:ff"; 0 or -1.
int hs_scenario_parse_mac(const char *s, uint8_t mac[6]);

#endif /* HS_SCENARIO_H */
