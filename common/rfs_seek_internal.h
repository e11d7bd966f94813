/* rfs_seek_internal.h - private to the rfs_seek*.c files: the strategy table's entry and
 * the functions the loop (rfs_seek.c), the paper's choices (rfs_seek_meta.c) and the
 * baselines (rfs_seek_baseline.c) share. Not part of the core's API.
 */
#ifndef RFS_SEEK_INTERNAL_H
#define RFS_SEEK_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_seek.h"

/* One strategy's decision rule (docs/STRATEGIES.md, "Choosing a strategy"): the loop in
 * rfs_seek.c calls these and nothing else that depends on the strategy. A choose or
 * to_max function sets decision.kind and the goal, plans and starts the drive, and
 * returns false when it found no goal. */
typedef struct rfs_seek_strategy_ops {
    const char *name; /* as on the command line */
    /* The iteration's goal; after the relearn check, the fit and the initial move when
     * `learns`. model_ok: the model predicts at the robot (false unless `learns`). */
    bool (*choose)(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us);
    /* The greedy step towards the model's maximum (mx, my), metres Q16.16; known: it is
     * the model's own argmax, not a grid search's. NULL without a greedy step. */
    bool (*to_max)(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool known, rfs_rng_t *rng,
                   int64_t now_us);
    bool learns;       /* an iteration checks the model, relearns it and begins with the
                        * initial move (false: the rule needs only the 1 s means) */
    bool refit;        /* the model is relearnt at every iteration, not only on a miss */
    bool dwell;        /* stand still one averaging window before every decision */
    bool improvements; /* rfs_seek_cfg_use_strategy turns the improvements beside the
                        * paper on (rfs_seek_cfg_t, docs/STRATEGIES.md) */
} rfs_seek_strategy_ops_t;

/* The configured strategy's entry of the table. */
const rfs_seek_strategy_ops_t *rfs_seek_ops(const rfs_seek_t *s);

/* ---- rfs_seek.c: planning for every strategy --------------------------------------- */

/* Where plans start: the robot (the drive's filtered pose, rfs_drive_estimate), or the
 * closest legal lattice point when it stands in the
 * clearance zone. false when there is none. */
bool rfs_seek_plan_start(const rfs_seek_t *s, rfs_q16_t *sx, rfs_q16_t *sy);

/* Plan from the robot to (gx, gy) into the drive's path (not yet driven) and set
 * decision.path_len. false when there is no path. With `tree`, from the search tree
 * begun at rfs_seek_plan_start (rfs_plan_tree_path: same contract). */
bool rfs_seek_plan_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, bool tree);

/* Plan to (gx, gy) and drive the path. */
bool rfs_seek_go_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, int64_t now_us);

/* ---- rfs_seek_fit.c: learning ------------------------------------------------------ */

/* What a fit learns from (the store, the map, the places ruled out, each source's
 * samples), asked about (qx, qy). */
void rfs_seek_fit_input(const rfs_seek_t *s, rfs_q16_t qx, rfs_q16_t qy,
                        rfs_model_fit_in_t *fin);

/* fit_early: a failed recheck's relearn begins now (s->early), unless off or one runs. */
void rfs_seek_fit_early_begin(rfs_seek_t *s, int64_t now_us);

/* fit_early near a goal: the decision's relearn check (Algorithm 1) fails already, on
 * the 1 s mean here (or there is no model). */
bool rfs_seek_fit_early_asks(rfs_seek_t *s, int64_t now_us);

/* fit_early: the fit begun as the base braked still learns what the decision's would. */
bool rfs_seek_fit_early_holds(const rfs_seek_t *s);

/* ---- rfs_seek_meta.c: the paper's choices (section 2) and their variants ----------- */

/* Tabulate the epsilon weights e^(-d) by squared lattice offset (s->eps_w). */
void rfs_seek_meta_init(rfs_seek_t *s);

/* The initial random move: a uniformly chosen reachable lattice point within
 * initial_step_max of the robot. */
bool rfs_seek_meta_initial(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us);

/* refute_r: at a decision with a model (decision.prediction valid), rule out the model's
 * argmax when the robot stands within half a step of it and the 1 s mean is weaker than
 * the prediction by more than 2 error_threshold, or there is no mean while the receiver is
 * up (a dead zone). true when it did: the model must be relearnt. */
bool rfs_seek_meta_refute(rfs_seek_t *s, int64_t now_us);

/* The refutation rule on given values: the model's prediction at the robot (have_pred),
 * the 1 s mean (mean_valid), the robot within half a step and margin of the maximum
 * (rfs_seek_meta_refute_near). true when it ruled the maximum out. */
bool rfs_seek_meta_refute_with(rfs_seek_t *s, int64_t now_us, rfs_q16_t margin, bool have_pred,
                               rfs_q16_t pred, bool mean_valid, rfs_q16_t mean);

/* refute_r: the robot within half a step and margin (metres Q16.16, >= 0) of the model's
 * argmax (*mx, *my), or of the reachable point driven to instead: where a refutation
 * may rule it out. false without refute_r or an argmax. */
bool rfs_seek_meta_refute_near(const rfs_seek_t *s, rfs_q16_t margin, rfs_q16_t *mx,
                               rfs_q16_t *my);

/* Mark the lattice points within the novelty radius of (x, y) as visited. */
void rfs_seek_meta_visit(rfs_seek_t *s, rfs_q16_t x, rfs_q16_t y);

/* choose of the meta strategies: "if random() > epsilon: greedy, else epsilon"; greedy is
 * the model's maximum (its argmax, else the grid search) and the strategy's to_max step,
 * epsilon a novel reachable point drawn with P proportional to e^(-distance) (with
 * eps_sample the model's draw first). */
bool rfs_seek_meta_choose(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us);

/* to_max of meta and meta-global: min(distance, step) straight towards the maximum,
 * with the line search when that point is illegal. */
bool rfs_seek_meta_step(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool known,
                        rfs_rng_t *rng, int64_t now_us);

/* to_max of meta-path: `step` along the planned path (the whole path to a known
 * maximum). */
bool rfs_seek_meta_path_step(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool known,
                             rfs_rng_t *rng, int64_t now_us);

/* ---- rfs_seek_src.c: each source's own samples, for a model fitted per source ------ */

/* Take mem->src (every source's state and arrays, or none): false when only some are given
 * or a store is rejected. */
bool rfs_seek_src_init(rfs_seek_t *s, const rfs_seek_mem_t *mem);

/* A pose: into every source's store, and src_floor's samples for silent sources. */
void rfs_seek_src_on_pose(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng);

/* A packet of source src: into its running mean and, every src_spacing, its store. */
void rfs_seek_src_on_rssi(rfs_seek_t *s, uint8_t src, int64_t t_us, int8_t dbm,
                          rfs_rng_t *rng);

/* The target of the 1 s means (the relearn check's); with per-source samples and
 * src_floor, a source without a mean while another has one counts as the floor. */
bool rfs_seek_src_mean(rfs_seek_t *s, int64_t now_us, rfs_q16_t *mean);

/* Exploration is over: settle_dist (> 0) travelled. */
bool rfs_seek_src_settled(const rfs_seek_t *s);

/* Settled, with settle_orbit, before settle_end. */
bool rfs_seek_src_orbiting(const rfs_seek_t *s);

/* settle_orbit: when settled and the robot stands within half the orbit of the model's
 * best point, go to a random reachable lattice point round it (docs/STRATEGIES.md,
 * "Bridging"); false (the usual choice follows) otherwise or when there is none. */
bool rfs_seek_src_orbit(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us);

/* ---- rfs_seek_baseline.c: the baselines' choose functions -------------------------- */

/* fd-gradient: probes at p + step x and p + step y, then a step along the difference. */
bool rfs_seek_baseline_fd(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us);

/* plane-gradient: a step along the refit model's gradient. */
bool rfs_seek_baseline_plane(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us);

/* chemotaxis: run on or tumble by the change of the 1 s mean. */
bool rfs_seek_baseline_chemo(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us);

#endif /* RFS_SEEK_INTERNAL_H */
