/* hs_faults.h - fault injection in the simulator (docs/FAULTS.md).
 *
 * A scenario may carry a schedule of faults (`faults:` in the scenario YAML, parsed by
 * hs_scenario.c). Each fault has a kind, a start time and (for the faults that last) a
 * duration, in simulated seconds. The run loop (hs_sim.c) calls the hooks below at the
 * seams where a real robot would see the fault:
 *
 *   - between the sensors and the controller: every RSSI packet and every localisation
 *     pose passes hs_faults_rssi() / hs_faults_pose(), which may drop it (silence), delay
 *     its timestamp into the past (or the future), swap it with the next one (out of order) or offset the
 *     pose (a 3 m re-localisation jump);
 *   - between the controller and the motor model (where the CAN bus is on the robot):
 *     every wheel command passes hs_faults_cmd(), which may lose it (send failures, bus-off);
 *     the motor model's own 200 ms timeout then stops the wheels;
 *   - in the world: hs_faults_next_event() hands the run loop one-shot events: the source
 *     moves (the radio model is rebuilt for the new position and the goal follows it), or
 *     the robot is kidnapped (its Box2D body is placed elsewhere).
 *
 * Every delivered input, every command (delivered or not), motor timeouts and fault
 * begin/end are written to an optional TSV log, so that tests can measure from the
 * controller's own commands how fast the wheels stop while inputs are stale.
 * Randomness (which commands are lost) comes from the run seed only.
 */
#ifndef HS_FAULTS_H
#define HS_FAULTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "rfs_fix.h"
#include "rfs_seek.h"

/// Kinds of fault (YAML names in hs_faults_kind_name()).
typedef enum hs_fault_kind {
    HS_FAULT_RSSI_SILENCE = 0, ///< "rssi_silence": no packet reaches the controller
    HS_FAULT_RSSI_PAST,        ///< "rssi_past": packet timestamps lag_s in the past
    HS_FAULT_RSSI_REORDER,     ///< "rssi_reorder": consecutive packets delivered swapped
    HS_FAULT_POSE_JUMP,        ///< "pose_jump": the pose estimate is offset by offset [dx, dy]
    HS_FAULT_POSE_PAST,        ///< "pose_past": pose timestamps lag_s in the past
    HS_FAULT_POSE_REORDER,     ///< "pose_reorder": consecutive poses delivered swapped
    HS_FAULT_CAN_DROP,         ///< "can_drop": each wheel command lost with `probability`
    HS_FAULT_BUS_OFF,          ///< "bus_off": no wheel command delivered
    HS_FAULT_SOURCE_MOVE,      ///< "source_move": source `source` moves to `position` (one-shot)
    HS_FAULT_KIDNAP,           ///< "kidnap": the robot is carried to `position`, `theta` (one-shot)
    HS_FAULT_RSSI_FUTURE,      ///< "rssi_future": packet timestamps lead_s in the future
    HS_FAULT_POSE_FUTURE,      ///< "pose_future": pose timestamps lead_s in the future
    HS_FAULT_KIND_COUNT        ///< number of kinds (not a kind)
} hs_fault_kind_t;

/// Most faults one scenario may schedule.
#define HS_FAULTS_MAX 8u

/// One scheduled fault.
typedef struct hs_fault {
    hs_fault_kind_t kind;  ///< what goes wrong
    double start_s;        ///< simulated time it begins, seconds
    double duration_s;     ///< how long it lasts, seconds (0 for the one-shot kinds)
    double x, y;           ///< pose_jump: offset, metres; source_move, kidnap: position, metres
    double theta;          ///< kidnap: heading after the move, radians
    double lag_s;          ///< *_past: how far in the past timestamps are, seconds;
                           ///< *_future: how far in the future (YAML `lead_s`), seconds
    double probability;    ///< can_drop: probability a command is lost, [0, 1]
    unsigned source;       ///< source_move: index of the source (scenario order)
} hs_fault_t;

/// A scenario's fault schedule (n = 0: no faults).
typedef struct hs_faults_cfg {
    unsigned n;                    ///< faults scheduled
    hs_fault_t f[HS_FAULTS_MAX];   ///< the faults, any order
} hs_faults_cfg_t;

/// YAML name of a kind ("?" out of range).
const char *hs_faults_kind_name(hs_fault_kind_t k);

/// The kind named `name`; false when there is none.
bool hs_faults_kind_parse(const char *name, hs_fault_kind_t *k);

/// true for kinds that happen once at start_s (source_move, kidnap).
bool hs_faults_one_shot(hs_fault_kind_t k);

/// Defaults of a fault of kind k: the figures (30 s silence, 3 m jump along x,
/// 1 s lag, 2 s bus-off, 50 % command loss for 30 s), starting at 30 s.
hs_fault_t hs_faults_default(hs_fault_kind_t k);

/// Check one fault: 0, or -1 with err = "field: reason" (field without the list prefix).
int hs_faults_check(const hs_fault_t *f, unsigned nsources, char *err, size_t errlen);

/// One delivered input (the hooks may hand back none, one or two per call).
typedef struct hs_faults_msg {
    int64_t t_us;      ///< timestamp the controller sees, microseconds
    uint8_t src;       ///< RSSI: source index
    int8_t dbm;        ///< RSSI: value, dBm
    rfs_pose_t pose;   ///< pose (pose hooks)
} hs_faults_msg_t;

/// A one-shot event for the run loop.
typedef struct hs_faults_event {
    hs_fault_kind_t kind;  ///< HS_FAULT_SOURCE_MOVE or HS_FAULT_KIDNAP
    unsigned source;       ///< source_move: which source
    double x, y, theta;    ///< new position, metres; heading (kidnap), radians
} hs_faults_event_t;

/// Per-run state of the injector (caller-owned; no heap).
typedef struct hs_faults_run {
    const hs_faults_cfg_t *cfg;     ///< the schedule (outlives the run)
    rfs_rng_t rng;                  ///< command-loss draws, from the run seed
    FILE *log;                      ///< TSV log, or NULL
    bool active[HS_FAULTS_MAX];     ///< lasting fault is in its window (for begin/end rows)
    bool fired[HS_FAULTS_MAX];      ///< one-shot fault was handed out
    bool pose_held;                 ///< a pose waits to be delivered after the next one
    hs_faults_msg_t held_pose;      ///< that pose
    bool rssi_held;                 ///< a packet waits to be delivered after the next one
    hs_faults_msg_t held_rssi;      ///< that packet
    bool motor_stopped;             ///< the motor model's timeout was last seen active
    uint64_t rssi_dropped;          ///< packets withheld (silence)
    uint64_t cmds_lost;             ///< wheel commands not delivered
} hs_faults_run_t;

/// Start a run: the schedule, the run seed and an optional log (header written).
void hs_faults_start(hs_faults_run_t *r, const hs_faults_cfg_t *cfg, uint64_t seed, FILE *log);

/// A packet from source src at t_us with dbm was received by the radio. Writes the
/// packets to deliver now, in order, to out[0..1] and returns how many (0, 1 or 2).
unsigned hs_faults_rssi(hs_faults_run_t *r, int64_t t_us, uint8_t src, int8_t dbm,
                        hs_faults_msg_t out[2]);

/// The simulated receiver reports itself up at t_us (the controller's heartbeat).
/// true with *stamp_us = the timestamp the controller sees, as a packet's would be (lagged
/// by rssi_past, led by rssi_future); false during rssi_silence: a dead receiver or feed
/// sends no heartbeat either. Logged as a `receiver` row.
bool hs_faults_receiver(hs_faults_run_t *r, int64_t t_us, int64_t *stamp_us);

/// A localisation pose (time in pose->t_us) was produced. Writes the poses to deliver now,
/// in order, to out[0..1] and returns how many (0, 1 or 2).
unsigned hs_faults_pose(hs_faults_run_t *r, const rfs_pose_t *pose, hs_faults_msg_t out[2]);

/// The controller produced a wheel command at t_us; true when it reaches the motor model.
bool hs_faults_cmd(hs_faults_run_t *r, int64_t t_us, const rfs_seek_out_t *out);

/// After a physics tick ending at t_us: log the motor model's timeout state on a change.
void hs_faults_motor(hs_faults_run_t *r, int64_t t_us, bool timed_out);

/// The next one-shot event due at or before t_us, once each; false when there is none.
bool hs_faults_next_event(hs_faults_run_t *r, int64_t t_us, hs_faults_event_t *ev);

#endif /* HS_FAULTS_H */
