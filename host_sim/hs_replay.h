/* hs_replay.h - an experiment replayed through the controller: a real run's recorded poses
 * (hs_poses.h) and the frames its capture holds from the scenario's sources, fed to the
 * in-process controller in time order, into the simulator's output files (rfseek-feed
 * --pose; docs/FEEDER.md, "Replaying a real experiment").
 *
 * Use: hs_replay_open() (the scenario and the poses), then every frame of a source with
 * hs_replay_frame() and, when hs_replay_heartbeats(), every record read with
 * hs_replay_alive(); then hs_replay_run(), which writes OUT and frees the replay (or
 * hs_replay_free() when reading the capture failed). Errors are one line on stderr
 * starting with the options' program name.
 */
#ifndef HS_REPLAY_H
#define HS_REPLAY_H

#include <stdbool.h>
#include <stdint.h>

/// What to replay and where.
typedef struct hs_replay_opts {
    const char *prog;                     ///< program name for messages
    const char *capture;                  ///< the capture (read by the caller)
    const char *poses, *scenario, *out;   ///< --pose CSV, --scenario YAML, --out directory
    const char *model, *target;           ///< overrides of the scenario's, or NULL
    bool has_seed;                        ///< seed overrides the scenario's
    uint64_t seed;
} hs_replay_opts_t;

/// One frame of a source, as the capture holds it.
typedef struct hs_replay_frame {
    int64_t t_us;      ///< capture clock, microseconds since the epoch
    uint8_t src;       ///< source index (scenario order)
    int8_t dbm;        ///< first (combined) dBm antenna signal
    uint16_t seq_ctrl; ///< 802.11 Sequence Control: number << 4 | fragment
} hs_replay_frame_t;

/// A replay being set up (opaque).
typedef struct hs_replay hs_replay_t;

/// Called with the temporary output directory and its files before any is written (the
/// caller's cleanup on signals).
typedef void (*hs_replay_guard_fn)(const char *dir, const char *const *names, int n);

/// Load the scenario (with the options' overrides) and the poses. macs: with n_macs 0 the
/// scenario's sources' MACs are written there (room for HS_SCN_MAX_SOURCES), else the
/// n_macs given must be one per source. 0 with *out set, or the exit status after a
/// message: 1 (a bad file), 2 (options that do not fit the scenario).
int hs_replay_open(const hs_replay_opts_t *o, uint8_t (*macs)[6], int n_macs, hs_replay_t **out);

/// How many sources (and MACs) the replay has.
int hs_replay_sources(const hs_replay_t *rp);

/// Whether the scenario feeds receiver heartbeats (radio.receiver.heartbeat).
bool hs_replay_heartbeats(const hs_replay_t *rp);

/// Keep one frame of a source (frames in capture order): 0, or 1 after a message.
int hs_replay_frame(hs_replay_t *rp, const hs_replay_frame_t *f);

/// A record of any transmitter read at t_us: a heartbeat time when one is due
/// (lx_feed_hb_due): 0, or 1 after a message.
int hs_replay_alive(hs_replay_t *rp, int64_t t_us);

/// Run the replay into o->out (written under a temporary name, renamed at the end, removed
/// on failure) and free rp. The matching frames before the first pose and after the end go
/// to *before, *after on success. 0, or 1 after a message.
int hs_replay_run(hs_replay_t *rp, hs_replay_guard_fn guard, uint64_t *before, uint64_t *after);

/// Free a replay that will not run (NULL is fine).
void hs_replay_free(hs_replay_t *rp);

#endif /* HS_REPLAY_H */
