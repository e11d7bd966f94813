/* rfs_mlp.h - the multilayer perceptron internal model (paper section 5.2.2).
 *
 * Two inputs (x, y), one hidden layer of sigmoid units (100), one linear output, a bias
 * into every layer. Inputs and target are standardised with the mean and (population)
 * standard deviation of the training samples, as scikit-learn's StandardScaler does.
 * Training is PyBrain's BackpropTrainer as the paper used it: online backpropagation of
 * the squared error, one update per sample, learning rate 0.01, momentum 0.1
 * (m = 0.1 m + 0.01 (t - y) dy/dw; w += m), 3 epochs, the samples reshuffled at the
 * start of every epoch, initial weights of unit variance drawn from the rng.
 *
 * Everything is fixed point: weights and momenta Q8.24, standardised inputs,
 * activations and errors Q16.16, the sigmoid from a 513-entry Q30 table with linear
 * interpolation (max error 1.94e-5 = 1.27 LSB of Q16.16 over all inputs, tested).
 *
 * The random draws, in order, so that a reference implementation can repeat them:
 *   initial weights (first fit call): for each hidden unit j: w[j][0], w[j][1], b[j];
 *   then v[j] for each j; then c. Each weight takes two rfs_rng_u32() values, i.e. four
 *   16-bit uniforms u1..u4 (low half first), w = ((u1 + u2 + u3 + u4) / 65536 - 2) * sqrt(3)
 *   (Irwin-Hall: mean 0, variance 1, as PyBrain's randn initialisation);
 *   each epoch: four keys k0..k3 = rfs_rng_u32(); the epoch visits the samples in the
 *   order p = 0..n-1 -> perm(p), a keyed pseudo-random permutation (below).
 *
 * The shuffle is a permutation computed on the fly rather than a Fisher-Yates shuffle of
 * an index array, so that the state needs no 20 KB order array: a 4-round Feistel
 * network on 2h bits (h = smallest with 4^h >= n, h >= 1), halves L = i >> h and
 * R = i & (2^h - 1), each round (L, R) = (R, L ^ F(k_r, R)) with
 *   F(k, r) = mix(k ^ r) & (2^h - 1),  mix(x): x *= 0x9E3779B1; x ^= x >> 15;
 *                                      x *= 0x85EBCA6B; x ^= x >> 13   (uint32),
 * result (L << h) | R, applied again while the result is >= n (cycle walking; on average
 * fewer than 4 applications).
 *
 * Sliced learning: one work unit is one sample-update (forward, backward, weight update:
 * about 100 x 20 multiplications). fit(budget) performs at most `budget` of them per call
 * and returns RFS_FIT_MORE until the last epoch is done. The standardisation pass is
 * done whole inside the call that starts the fit (about 20 instructions per sample,
 * under 1/500 of an epoch).
 *
 * Upper bound over a box (the `bound` op, docs/MODELS.md): for the branch-and-bound grid
 * search, a bound of predict() over an axis-aligned box that holds bit for bit: the
 * smaller of interval arithmetic through the monotone steps of predict() and a linear
 * relaxation of each hidden unit with its second-order remainder charged (rfs_mlp.c).
 * A single point gets its prediction exactly; no model, no bound.
 */
#ifndef RFS_MLP_H
#define RFS_MLP_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_model.h"

/// Hidden units the state has room for (paper: 100).
#define RFS_MLP_MAX_HIDDEN 100u
/// Samples one fit learns from at most (paper section 5.2: 10,000).
#define RFS_MLP_MAX_SAMPLES 10000u

/// MLP configuration.
typedef struct rfs_mlp_cfg {
    uint16_t hidden;       ///< hidden sigmoid units, 1..RFS_MLP_MAX_HIDDEN (100)
    uint8_t epochs;        ///< passes over the shuffled samples, 1..255 (3)
    int32_t rate_q30;      ///< learning rate, Q2.30, (0, 1] (0.01)
    int32_t momentum_q30;  ///< momentum, Q2.30, [0, 1) (0.1)
    uint16_t max_samples;  ///< learn from the first this many samples, 1..RFS_MLP_MAX_SAMPLES
                           ///< (10,000; the store is a uniform random subset already)
} rfs_mlp_cfg_t;

/// MLP state, caller-owned (about 3.3 KB: weights and momenta).
typedef struct rfs_mlp {
    rfs_mlp_cfg_t cfg;                           ///< configuration copied at init
    bool valid;                                  ///< a trained network exists
    bool fitting;                                ///< a sliced fit is in progress
    int32_t w_q24[RFS_MLP_MAX_HIDDEN][2];        ///< input -> hidden weights, Q8.24
    int32_t b_q24[RFS_MLP_MAX_HIDDEN];           ///< hidden biases, Q8.24
    int32_t v_q24[RFS_MLP_MAX_HIDDEN];           ///< hidden -> output weights, Q8.24
    int32_t c_q24;                               ///< output bias, Q8.24
    int32_t mw_q24[RFS_MLP_MAX_HIDDEN][2];       ///< momentum of w, Q8.24
    int32_t mb_q24[RFS_MLP_MAX_HIDDEN];          ///< momentum of b, Q8.24
    int32_t mv_q24[RFS_MLP_MAX_HIDDEN];          ///< momentum of v, Q8.24
    int32_t mc_q24;                              ///< momentum of c, Q8.24
    int32_t mean_x_q16;                          ///< mean sample x, centimetres Q16.16
    int32_t mean_y_q16;                          ///< mean sample y, centimetres Q16.16
    int32_t mean_v_q16;                          ///< mean target, Q9.6 units (1/64) Q16.16
    int32_t inv_sx_q24;                          ///< 1 / std of x, per centimetre, Q8.24
    int32_t inv_sy_q24;                          ///< 1 / std of y, per centimetre, Q8.24
    int32_t inv_sv_q24;                          ///< 1 / std of the target, per 1/64 unit, Q8.24
    rfs_q16_t out_mean;                          ///< target mean, target units Q16.16
    rfs_q16_t out_std;                           ///< target std, target units Q16.16
    uint16_t fit_n;                              ///< samples in the fit in progress / last fit
    uint16_t pos;                                ///< next position in the epoch
    uint8_t epoch;                               ///< current epoch, 0-based
    uint32_t updates;                            ///< sample-updates done by the last fit call
    uint32_t key[4];                             ///< permutation keys of the current epoch
    uint8_t half_bits;                           ///< h: bits of each Feistel half
} rfs_mlp_t;

/// Defaults: 100 hidden units, 3 epochs, rate 0.01, momentum 0.1, 10,000 samples
/// (paper section 5.2.2).
rfs_mlp_cfg_t rfs_mlp_cfg_default(void);

/// Initialise without a model. Returns 0, or -1 when a field is outside the ranges above.
int rfs_mlp_init(rfs_mlp_t *m, const rfs_mlp_cfg_t *cfg);

/// The model interface of an MLP state.
rfs_model_t rfs_mlp_model(rfs_mlp_t *m);

/// Operations (also reachable through rfs_mlp_model()).
extern const rfs_model_ops_t rfs_mlp_ops;

/// The logistic function 1 / (1 + e^-a), a in Q16.16, result in [0, 1] Q16.16.
/// Scaling and overflow: |a| >= 16 gives 0 or 1 (true error < 1.2e-7); otherwise a
/// 513-entry Q30 table of sigmoid(i/32), linearly interpolated on the low 11 bits of a
/// (Q30 x 11 bits fits int64), rounded to Q16.16; sigmoid(-a) = 1 - sigmoid(a).
/// Error <= 1.94e-5 (1.27 LSB) against the exact value.
rfs_q16_t rfs_mlp_sigmoid(rfs_q16_t a);

#endif /* RFS_MLP_H */
