/* hs_batch.h - rfseek-sim's runs (docs/SIMULATOR.md, "Outputs"): one run's output files
 * in a directory, and a --seeds batch (optionally at drawn placements) shared among worker
 * processes that report through a pipe, its state kept in DIR/batch.state so that an
 * interrupted batch resumes (--resume). Errors are one line on stderr starting
 * "rfseek-sim: ".
 */
#ifndef HS_BATCH_H
#define HS_BATCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hs_place.h"
#include "hs_sim.h"

/// The most runs one batch holds (its table is kept in memory, one row a run).
#define HS_BATCH_MAX_RUNS 1000000u

/// A batch's state file under its directory: a header line naming the runs (checked by
/// --resume), then each finished run's runs.tsv row.
#define HS_BATCH_STATE "batch.state"

/// One run of `seed` into dir (NULL: summary.json to stdout), with samples.tsv, the
/// true fields (field.tsv, field1.tsv) and a pcap when asked: 0, or 1 with the first
/// failure, one line, in msg.
int hs_batch_run_one(const hs_sim_env_t *env, uint64_t seed, const char *dir, bool samples,
                     bool field, const char *pcap, hs_sim_result_t *res, char *msg,
                     size_t msglen);

/// The state file's header for these runs: scenario (absolute path), seeds a..b, options
/// and placements pa..pb of seed ps (pa 0: none).
void hs_batch_state_header(char *buf, size_t n, const char *scenario, const hs_scenario_t *sc,
                           uint64_t a, uint64_t b, bool samples, uint64_t pa, uint64_t pb,
                           uint64_t ps);

/// Seeds a..b (at each of nplaces placements when places is not NULL; at most
/// HS_BATCH_MAX_RUNS runs) on `jobs` workers into dir (per-run directories, runs.tsv;
/// NULL: runs.tsv to stdout); resume: the runs listed in dir's state file under `header`
/// are kept, the others run. 0, or 1 after a message (or when interrupted).
int hs_batch_run(hs_sim_env_t *env, const char *header, uint64_t a, uint64_t b,
                 const hs_place_t *places, uint64_t nplaces, int jobs, const char *dir,
                 bool samples, bool quiet, bool resume);

/// SIGINT / SIGTERM handler of the batch's parent: the batch stops after the runs done.
void hs_batch_on_stop(int sig);

/// A signal stopped the batch.
bool hs_batch_stopped(void);

/// Remove a directory tree this program created (regular files and directories).
void hs_batch_rm_tree(const char *path);

#endif
