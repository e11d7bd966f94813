/* rfs_pathloss.h - a map-aware, physics-informed internal model (docs/PATHLOSS.md; paper section 3:
 * "representations of varying complexity ... depending on the available resources and
 * prior knowledge").
 *
 * The signal at position x from a source at s is modelled as
 *
 *   z(x) = P0 - 10 n log10(max(|x - s|, 1 m)) - W walls(x, s)          [dB]
 *
 * with walls() the wall runs the straight line crosses on the core grid
 * (rfs_map_walls_crossed: the rule the simulator's radio model uses). For a fixed s the
 * model is linear in (P0, n, W): fit() solves the weighted least-squares problem in
 * closed form for every candidate s, with n and W bounded to [n_min, n_max] and
 * [w_min, w_max] (exact box-constrained solution of the 2 x 2 quadratic after
 * eliminating P0) and a prior pulling them towards (n_prior, w_prior) with weights
 * prior_weight and w_prior_weight, which also keeps W defined when every bin sees the
 * same number of walls.
 * Each bin weighs min(samples, bin_cap). The estimate is the candidate with the least
 * weighted Huber loss of the bins' mean residuals.
 *
 * Samples are first aggregated into square bins (1 m; at most RFS_PATHLOSS_MAX_BINS,
 * the bin doubles when there are more): each bin is its sample count, mean value and
 * centroid (rounded to the centimetre), so the cost of a candidate does not grow with
 * the number of samples. Candidates are legal lattice points, searched coarse to fine:
 * every `coarse` (2 m), then the 8 neighbours of each of the best `top` (3) at half that
 * spacing (1 m), then the 8 neighbours of the best so far at half the spacing again,
 * down to the lattice spacing (0.5 m, 0.25 m). A point is evaluated once per fit, but
 * for the top points when the coarse pass counted walls with its own footprint
 * (`coarse_footprint`, the footprint by default; 0: one count a bin): its losses then only
 * rank, and the refinement evaluates the top points again with `footprint`.
 * Without a map (fit_in.map NULL) the candidates cover the samples' extent plus
 * `margin` on a 0.25 m lattice, and there are no walls.
 *
 * Uncertainty: the mean Huber loss of every coarse candidate is kept (the residual
 * surface, rfs_pathloss_residual_at(), for heat maps) and the estimate reports the area
 * of coarse candidates whose loss is within spread_k / bins of the best's (relative):
 * a likelihood-ratio region that counts each bin as one independent observation.
 *
 * A bin's walls are its footprint's: the mean of the counts from the four points
 * `footprint` (0.25 m) either side of the centre of the core cell that holds the bin's
 * centroid, along x and y (a point that is not legal counts as the centre), in quarter
 * walls. A bin's mean is an average over where its samples were taken, and on a
 * cluttered map one line's count jumps by several walls within centimetres of where it
 * starts (footprint 0: the centre's count alone; the coarse pass's: coarse_footprint,
 * cached apart). The counts are cached across fits, a byte per origin (row) and candidate
 * (column, as first evaluated; a count saturates at 15 walls): built in
 * RFS_PATHLOSS_BUILTIN_ROWS x RFS_PATHLOSS_CACHE_COLS, or RFS_PATHLOSS_CACHE_ROWS x as
 * many columns as a caller's buffer holds (rfs_pathloss_cache_attach(): every coarse,
 * refinement and hold candidate of a run). Bins are fixed cells, so a relearn counts
 * walls only for bins that are new or whose centroid moved to another core cell, and for
 * candidates without a column. The cache is emptied when the map or the lattice changes;
 * when its rows run out, those no bin of the fit holds are emptied and reused, and so
 * are the built-in columns the last fit did not use.
 *
 * Work: one unit is one computed wall count, RFS_PATHLOSS_BINS_PER_UNIT (8) bins gathered
 * from the cache, solved or set up, or RFS_PATHLOSS_SAMPLES_PER_UNIT (16) samples binned.
 * fit() with budget 0 does everything; with budget > 0 it stops before work that could
 * overrun the budget (a footprint: four units; at least one piece per call), resumes
 * there on the next call, and returns RFS_FIT_MORE until the search is done. The model is invalid while a fit is in progress; a sliced fit bins
 * the samples its first call saw (samples added meanwhile wait for the next relearn;
 * ones a full store replaces meanwhile may be binned new).
 *
 * Warming (rfs_pathloss_ops.warm, rfs_pathloss_warm.c): between fits, in the same units,
 * the counts the next fit will read from the cache: bins with a new wall origin (but the
 * robot's) against the last fit's columns, then every bin against the first points of
 * the next hold search. The model and the next fit's results are unchanged, bit for bit.
 */
#ifndef RFS_PATHLOSS_H
#define RFS_PATHLOSS_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_model.h"

/// Most sample bins (the bin size doubles until the samples fit).
#define RFS_PATHLOSS_MAX_BINS 512u
/// Slots of the bin hash table (a power of two, twice the bins).
#define RFS_PATHLOSS_HASH (2u * RFS_PATHLOSS_MAX_BINS)
/// Most coarse candidates (the coarse spacing grows until the map fits).
#define RFS_PATHLOSS_MAX_COARSE 1024u
/// Most coarse candidates refined.
#define RFS_PATHLOSS_MAX_TOP 4u
/// Most refinement points remembered to evaluate each once (more are re-evaluated).
#define RFS_PATHLOSS_MAX_VISITED 128u
/// Wall-count origins cached (rows) and candidates per origin in the built-in cache
/// (columns).
#define RFS_PATHLOSS_CACHE_ROWS 512u
#define RFS_PATHLOSS_CACHE_COLS 256u
/// Origins (rows) of the built-in wall-count cache (an attached one: RFS_PATHLOSS_CACHE_ROWS).
#define RFS_PATHLOSS_BUILTIN_ROWS 120u
/// Slots of the cache's hash tables (powers of two, twice the rows; twice the columns).
#define RFS_PATHLOSS_CACHE_HASH (2u * RFS_PATHLOSS_CACHE_ROWS)
#define RFS_PATHLOSS_COL_HASH (2u * RFS_PATHLOSS_CACHE_COLS)
/// Bytes of the map's wall-block grid the wall counts use (rfs_map_wall_blocks(): blocks
/// of 8 cells up to 90 x 90 blocks, 720 x 720 cells; larger maps get larger blocks).
#define RFS_PATHLOSS_WALL_BLOCK_BYTES 1024u
/// Most columns of an attached cache (rfs_pathloss_cache_attach()).
#define RFS_PATHLOSS_MAX_CACHE_COLS 16384u
/// No cache row.
#define RFS_PATHLOSS_NO_ROW UINT16_MAX
/// Surface value of a coarse point that is not a candidate (illegal).
#define RFS_PATHLOSS_NO_LOSS UINT32_MAX
/// rfs_pathloss_t.snap: the coarse point's cell has no legal lattice point.
#define RFS_PATHLOSS_SNAP_NONE 0xFEu
/// rfs_pathloss_t.snap: not looked for yet on this lattice.
#define RFS_PATHLOSS_SNAP_UNKNOWN 0xFFu

/// Configuration; rfs_pathloss_cfg_default() gives the values in the comments.
/// rfs_pathloss_cfg_t.coarse_footprint: count the coarse pass with `footprint` (the default).
#define RFS_PATHLOSS_COARSE_AS_FOOTPRINT (-1)

/// A work unit of fit() and warm() budgets: one wall count, or this many bins gathered,
/// solved or set up, or samples binned (each about a count's instructions on the
/// Cortex-M4; docs/PATHLOSS.md, "Work, the wall-count cache and slicing").
#define RFS_PATHLOSS_BINS_PER_UNIT 8u
#define RFS_PATHLOSS_SAMPLES_PER_UNIT 16u

typedef struct rfs_pathloss_cfg {
    rfs_q16_t bin;          ///< metres Q16.16: side of a sample bin (1 m), 0.1..16 m
    rfs_q16_t coarse;       ///< metres Q16.16: coarse candidate spacing (2 m)
    uint8_t top;            ///< coarse candidates refined (3), 1..RFS_PATHLOSS_MAX_TOP
    rfs_q16_t n_min;        ///< path-loss exponent bounds, Q16.16 (1.5)
    rfs_q16_t n_max;        ///< (5.0)
    rfs_q16_t w_min;        ///< loss per wall bounds, dB Q16.16 (0)
    rfs_q16_t w_max;        ///< (15 dB)
    rfs_q16_t n_prior;      ///< prior exponent, Q16.16 (3.0: ITU-R P.1238 office)
    rfs_q16_t w_prior;      ///< prior loss per wall, dB Q16.16 (5 dB: ns-3 buildings)
    uint16_t bin_cap;       ///< a bin weighs min(samples, bin_cap) (5): shadowing makes a
                            ///< place one observation however long the robot stays
    rfs_q16_t prior_weight; ///< weight of the n prior, weight x dB^2, Q16.16 (3000), > 0
    rfs_q16_t w_prior_weight; ///< weight of the W prior, weight x dB^2, Q16.16 (30), > 0
    rfs_q16_t huber;        ///< Huber threshold on a bin's mean residual, dB Q16.16 (6 dB)
    rfs_q16_t spread_k;     ///< spread region: loss <= best (1 + spread_k / bins) (6.0)
    rfs_q16_t margin;       ///< metres Q16.16: candidates beyond the samples without a map (20 m)
    rfs_q16_t p0_min;       ///< target units Q16.16: weakest plausible signal at 1 m (-45 dBm;
                            ///< INT32_MIN: no floor). A candidate whose fit needs a weaker
                            ///< P0 adds total weight x Huber(p0_min - P0) to its loss
    rfs_q16_t p0_max;       ///< target units Q16.16: strongest plausible signal at 1 m
                            ///< (-10 dBm; INT32_MAX: no ceiling). A candidate whose fit
                            ///< needs a stronger P0 adds total weight x Huber(P0 - p0_max)
    rfs_q16_t p0_max_wall;  ///< dB Q16.16: the ceiling tests the P0 the fit would need with
                            ///< each wall costing at most this (3 dB: drywall), 0..60 dB
                            ///< (INT32_MAX: off, each wall costs the fit's W)
    rfs_q16_t footprint;    ///< metres Q16.16: a bin's wall counts start this far either
                            ///< side of its cell's centre, along x and y (0.25 m; 0: from
                            ///< the centre alone), 0..bin / 2
    rfs_q16_t coarse_footprint; ///< metres Q16.16: the footprint of the coarse candidates'
                            ///< counts (RFS_PATHLOSS_COARSE_AS_FOOTPRINT: footprint's,
                            ///< the default; 0: one count a bin, about
                            ///< half the counts of a fit). Unless equal to footprint the
                            ///< coarse pass only ranks: the refinement re-evaluates the
                            ///< top points with footprint (docs/PATHLOSS.md, "Fit")
    rfs_q16_t hold_k;       ///< a relearn keeps the previous fit's source when its loss is
                            ///< within best (1 + hold_k / bins) (6.0; 0: off, always the
                            ///< least loss): no jumping between sources the data cannot
                            ///< tell apart. Needs the same map as the previous fit
    bool hold_search;       ///< the source held against the new best is the best point of
                            ///< a local search round the previous one (3 x 3 steps of
                            ///< coarse / 2, halved to the lattice's: its optimum under the
                            ///< new data), not that point alone (true)
    rfs_q16_t sample_t;     ///< temperature of the model's draws (rfs_pathloss_ops.sample):
                            ///< coarse candidate c is drawn with weight e^(-chi2_c / 2T),
                            ///< chi2_c = (loss_c / best loss - 1) x bins (1.0), 1/16..64
    bool coarse_snap;       ///< a coarse point that is not legal stands for the legal
                            ///< lattice point of its cell nearest it (true; false: the
                            ///< grid point or nothing, so a corridor between two coarse
                            ///< rows has no candidate) (docs/PATHLOSS.md, "Fit")
} rfs_pathloss_cfg_t;

/// One sample bin. Scaling: sums of up to 65,535 samples of int16 fit int32.
typedef struct rfs_pathloss_bin {
    int32_t sx_cm;   ///< sum of x, centimetres; centroid x after binning
    int32_t sy_cm;   ///< sum of y, centimetres; centroid y after binning
    int32_t sv_q6;   ///< sum of values, Q9.6
    int32_t dz_q16;  ///< mean value minus the mean over all samples, target units Q16.16
    rfs_q16_t x;     ///< centroid x, metres Q16.16
    rfs_q16_t y;     ///< centroid y, metres Q16.16
    rfs_q16_t wx;    ///< wall-count origin x (centre of the centroid's core cell), metres Q16.16
    rfs_q16_t wy;    ///< wall-count origin y, metres Q16.16
    uint16_t row;    ///< its wall-count cache row, RFS_PATHLOSS_NO_ROW when none
    uint16_t count;  ///< samples in the bin; after binning its weight, min(samples, bin_cap)
    int16_t kx;      ///< bin index along x (floor(x / bin))
    int16_t ky;      ///< bin index along y
} rfs_pathloss_bin_t;

/// One evaluated candidate source and its fit.
typedef struct rfs_pathloss_cand {
    int64_t loss;    ///< sum over bins of count x Huber(mean residual), dB^2 Q16 (Q8 x Q8)
    rfs_q16_t sx;    ///< source x, metres Q16.16
    rfs_q16_t sy;    ///< source y, metres Q16.16
    uint16_t li;     ///< its lattice index along x
    uint16_t lj;     ///< its lattice index along y
    rfs_q16_t p0;    ///< signal at 1 m, target units Q16.16
    rfs_q16_t n;     ///< path-loss exponent, Q16.16
    rfs_q16_t w;     ///< loss per wall, dB Q16.16
} rfs_pathloss_cand_t;

/// The candidate lattice: the map's, or a virtual one without a map.
typedef struct rfs_pathloss_lat {
    rfs_q16_t ox;    ///< x of point (0, 0), metres Q16.16
    rfs_q16_t oy;    ///< y of point (0, 0), metres Q16.16
    rfs_q16_t grid;  ///< spacing, metres Q16.16
    uint16_t lw;     ///< points along x
    uint16_t lh;     ///< points along y
    uint16_t cs;     ///< coarse spacing, lattice steps
    uint16_t c0i;    ///< lattice index of coarse point (0, 0) along x
    uint16_t c0j;    ///< along y
    uint16_t ncx;    ///< coarse points along x
    uint16_t ncy;    ///< coarse points along y
} rfs_pathloss_lat_t;

/// One cached wall-count origin: a core cell.
typedef struct rfs_pathloss_row {
    uint16_t cx;     ///< core cell x
    uint16_t cy;     ///< core cell y
} rfs_pathloss_row_t;

/// Search phases of a (sliced) fit.
typedef enum rfs_pathloss_phase {
    RFS_PATHLOSS_IDLE = 0, ///< no fit in progress
    RFS_PATHLOSS_BIN,      ///< binning the samples
    RFS_PATHLOSS_COARSE,   ///< coarse candidates
    RFS_PATHLOSS_REFINE,   ///< around the best coarse candidates at half the coarse spacing
    RFS_PATHLOSS_FINE,     ///< around the best so far, halving the spacing to the lattice's
    RFS_PATHLOSS_HOLD,     ///< the previous fit's source (or the best point round it,
                           ///< hold_search), kept when still as good (hold_k)
} rfs_pathloss_phase_t;

/// A candidate being evaluated: its bins' wall counts are gathered across calls of a
/// sliced fit, then its (P0, n, W) solved.
typedef struct rfs_pathloss_ev {
    bool on;         ///< a candidate is being evaluated
    uint8_t kind;    ///< what its result is for (the phase that chose it)
    uint16_t li;     ///< its lattice index along x
    uint16_t lj;     ///< along y
    rfs_q16_t sx;    ///< its position, metres Q16.16
    rfs_q16_t sy;
    int32_t col;     ///< its wall-count cache column, -1 when none
    rfs_q16_t fp;    ///< its counts' footprint (cfg footprint or coarse_footprint), m Q16.16
    uint32_t c;      ///< its coarse surface index (coarse candidates)
    uint32_t b;      ///< next bin to gather
    int64_t sl;      ///< sum over the gathered bins of weight x 10 log10(d), dB Q16.16
    int64_t sk;      ///< sum of weight x walls, quarter walls
} rfs_pathloss_ev_t;

/// Warming (rfs_pathloss_ops.warm) between fits: a pass bins the samples as a fit would
/// (in the fit's bin arrays, free between fits), counts the walls of each bin whose wall
/// origin has no cache row (but the robot's bin) against the columns the last fit
/// evaluated, then every bin's against the points round the last fit's source that the
/// next fit's hold search evaluates first. Emptied when a fit begins.
typedef struct rfs_pathloss_warm {
    uint8_t phase;     ///< 0: a pass may begin, 1 binning, 2 finding origins, 3 counting,
                       ///< 4 every bin against the hold search's first points
    bool tidied;       ///< the cache's rows were tidied for warming since the last fit
    bool passed;       ///< a pass was made since the last fit
    bool stopped;      ///< every row holds a bin: nothing more until the next fit
    int16_t rkx;       ///< bin the robot was in when the last pass began (x index, cfg bin)
    int16_t rky;       ///< its y index
    uint16_t b;        ///< next bin to look at
    uint16_t row;      ///< the cache row being counted
    uint16_t free_from; ///< rows below this hold an origin (after tidying)
    rfs_q16_t wx;      ///< its wall origin, metres Q16.16
    rfs_q16_t wy;      ///< metres Q16.16
    uint32_t col;      ///< next column: coarse point, then refinement points, then the best
    uint32_t seen;     ///< columns looked at (a work unit each RFS_PATHLOSS_BINS_PER_UNIT)
    int16_t hold_col[8]; ///< columns of the next hold search's first points (-1: none)
    uint8_t warmed[RFS_PATHLOSS_CACHE_ROWS / 8u]; ///< rows this pass gave an origin
    uint32_t lines;    ///< wall counts computed by warming since the last fit
    uint32_t footprints; ///< bin footprints it counted
} rfs_pathloss_warm_t;

/// What the model believes (rfs_pathloss_estimate()).
typedef struct rfs_pathloss_est {
    rfs_q16_t sx;         ///< estimated source x, metres Q16.16
    rfs_q16_t sy;         ///< estimated source y, metres Q16.16
    rfs_q16_t p0;         ///< signal at 1 m, target units Q16.16
    rfs_q16_t n;          ///< path-loss exponent, Q16.16
    rfs_q16_t w;          ///< loss per wall, dB Q16.16
    rfs_q16_t rms;        ///< sqrt(2 x mean Huber loss) (the RMS residual when all are
                          ///< below the Huber threshold), dB Q16.16
    rfs_q16_t spread_m2;  ///< area of coarse candidates in the spread region, m^2 Q16.16
    uint16_t bins;        ///< bins used
    rfs_q16_t bin;        ///< bin side used, metres Q16.16
    uint32_t candidates;  ///< candidates evaluated
    uint32_t walls_counted;     ///< wall counts (lines) computed by the last fit
    uint32_t footprints;        ///< bin footprints it counted (up to four lines each)
    uint32_t footprints_cached; ///< bin footprints it read from the cache
    uint32_t walls_warmed;      ///< wall counts warming computed before it began
} rfs_pathloss_est_t;

/// A wall-count cache in a caller's buffer (rfs_pathloss_cache_attach()).
typedef struct rfs_pathloss_xcache {
    uint16_t cols;       ///< columns (candidates per origin)
    uint8_t hash_bits;   ///< log2 of its column hash slots (>= twice the columns)
    uint16_t *col_hash;  ///< column + 1 by hashed lattice point, 0 = empty
    uint32_t *col_key;   ///< lattice point of each column, li | lj << 16
    uint8_t *cells;      ///< RFS_PATHLOSS_CACHE_ROWS x cols counts, row by row
} rfs_pathloss_xcache_t;

/// State, caller-owned (about 67 KB, 37 KB of it the wall-count cache).
typedef struct rfs_pathloss {
    rfs_pathloss_cfg_t cfg;                       ///< configuration copied at init
    bool valid;                                   ///< a model exists
    bool have_prev;                               ///< best holds a finished fit (for hold_k)
    const rfs_map_t *prev_map;                    ///< the map of that fit
    const rfs_map_t *map;                         ///< map of the last fit (NULL: no walls)
    rfs_pathloss_cand_t best;                     ///< the model: estimate and its fit
    rfs_q16_t spread_m2;                          ///< area of the spread region, m^2 Q16.16
    uint32_t candidates;                          ///< candidates evaluated (last or current fit)
    uint16_t used_bins;                           ///< bins of the last finished fit
    int32_t used_bin_cm;                          ///< their side, centimetres
    /* --- fit in progress (and its bins, which the estimate reports) --- */
    rfs_pathloss_phase_t phase;                   ///< search phase
    uint32_t pos;                                 ///< position within the phase
    rfs_pathloss_lat_t lat;                       ///< candidate lattice
    uint16_t nbins;                               ///< bins in use
    uint16_t bin_n;                               ///< samples the fit bins (its first call's)
    int32_t bin_cm;                               ///< bin side in use, centimetres
    uint32_t total;                               ///< weight of all bins (sum of min(count, cap))
    int32_t mz_q16;                               ///< mean of all samples, target units Q16.16
    uint8_t ntop;                                 ///< coarse candidates kept in top[]
    rfs_pathloss_cand_t top[RFS_PATHLOSS_MAX_TOP]; ///< best coarse candidates, best first
    rfs_pathloss_cand_t cur;                      ///< best so far
    rfs_pathloss_ev_t ev;                         ///< the candidate being evaluated
    uint16_t fc_i;                                ///< centre of the fine level, lattice x
    uint16_t fc_j;                                ///< lattice y
    uint16_t step;                                ///< spacing of the fine level, lattice steps
    uint16_t hold_i;                              ///< hold_search: centre, lattice x
    uint16_t hold_j;                              ///< lattice y
    uint16_t hold_step;                           ///< its spacing, lattice steps
    uint8_t hold_pos;                             ///< next of its 3 x 3 points (9: done;
                                                  ///< UINT8_MAX: the centre first)
    rfs_pathloss_cand_t hold_best;                ///< best point of the hold search so far
                                                  ///< (loss INT64_MAX before the first)
    uint8_t nexcl;                                ///< places ruled out for this fit
                                                  ///< (rfs_model_fit_in_t.nexcl)
    rfs_q16_t excl_r;                             ///< radius ruled out round each, metres Q16.16
    rfs_q16_t excl_x[RFS_MODEL_MAX_EXCL];         ///< their x, metres Q16.16
    rfs_q16_t excl_y[RFS_MODEL_MAX_EXCL];         ///< their y, metres Q16.16
    uint16_t nvis;                                ///< refinement points remembered
    uint16_t vis_i[RFS_PATHLOSS_MAX_VISITED];     ///< their lattice x
    uint16_t vis_j[RFS_PATHLOSS_MAX_VISITED];     ///< their lattice y
    rfs_pathloss_bin_t bins[RFS_PATHLOSS_MAX_BINS]; ///< sample bins
    uint16_t hash[RFS_PATHLOSS_HASH];             ///< bin index + 1 by hashed cell, 0 = empty
    int32_t l_q16[RFS_PATHLOSS_MAX_BINS];         ///< scratch: 10 log10(d) per bin, dB Q16.16
    uint8_t k[RFS_PATHLOSS_MAX_BINS];             ///< scratch: walls per bin, quarter walls
    uint32_t walls_counted;                       ///< wall counts (lines) computed by this fit
    uint32_t footprints;                          ///< bin footprints counted by this fit
    uint32_t footprints_cached;                   ///< bin footprints read from the cache
    rfs_pathloss_warm_t warm;                     ///< warming between fits
    uint32_t walls_warmed;                        ///< wall counts warming computed before
                                                  ///< this fit began
    const rfs_map_t *blocks_map;                  ///< map of wall_blocks (NULL: none)
    rfs_map_wall_blocks_t blocks;                 ///< its wall-free blocks, skipped by counts
                                                  ///< (bits: wall_blocks, even in a copy)
    uint8_t wall_blocks[RFS_PATHLOSS_WALL_BLOCK_BYTES]; ///< their bit grid
    const rfs_map_t *cache_map;                   ///< map the cache belongs to (NULL: empty)
    rfs_pathloss_lat_t cache_lat;                 ///< coarse lattice the cache belongs to
    uint16_t nrows;                               ///< cache rows in use
    uint16_t ncols;                               ///< cache columns in use
    uint16_t row_hash[RFS_PATHLOSS_CACHE_HASH];   ///< row + 1 by hashed core cell, 0 = empty
    rfs_pathloss_row_t rows[RFS_PATHLOSS_CACHE_ROWS]; ///< cached origins
    uint8_t row_used[RFS_PATHLOSS_CACHE_ROWS / 8u]; ///< scratch: rows a bin of this fit holds
    uint8_t col_used[RFS_PATHLOSS_CACHE_COLS / 8u]; ///< built-in columns looked up since the
                                                  ///< fit began (kept when the cache is full)
    uint8_t col_live[RFS_PATHLOSS_CACHE_COLS / 8u]; ///< built-in columns holding a point
    uint16_t cols_free;                           ///< built-in columns below ncols not live
    rfs_pathloss_xcache_t x;                      ///< an attached cache (cells NULL: none;
                                                  ///< then the three built-in arrays below)
    const int32_t *log2_tab;                      ///< attached log2 table (NULL: none)
    uint16_t col_hash[RFS_PATHLOSS_COL_HASH];     ///< column + 1 by hashed lattice point
    uint32_t col_key[RFS_PATHLOSS_CACHE_COLS];    ///< lattice point of each column
    uint8_t walls[RFS_PATHLOSS_BUILTIN_ROWS][RFS_PATHLOSS_CACHE_COLS]; ///< footprint wall
                                                  ///< counts, quarter walls; 255: not counted
    uint32_t surface[RFS_PATHLOSS_MAX_COARSE];    ///< mean Huber loss per unit weight of
                                                  ///< each coarse point, dB^2 Q16.16;
                                                  ///< NO_LOSS = no candidate
    const rfs_map_t *snap_map;                    ///< map of snap[] (NULL: not begun)
    rfs_pathloss_lat_t snap_lat;                  ///< lattice of snap[]
    uint8_t snap[RFS_PATHLOSS_MAX_COARSE];        ///< each coarse point's lattice point:
                                                  ///< offsets (di + 7) | (dj + 7) << 4;
                                                  ///< RFS_PATHLOSS_SNAP_NONE: no legal
                                                  ///< point; _UNKNOWN: not looked for
} rfs_pathloss_t;

/// Defaults (see rfs_pathloss_cfg_t).
rfs_pathloss_cfg_t rfs_pathloss_cfg_default(void);

/// Initialise without a model. Returns 0, or -1 on bin outside [0.1, 16] m, coarse
/// outside (0, 64] m, bin_cap 0, top outside 1..RFS_PATHLOSS_MAX_TOP, n bounds not
/// 0 < n_min <= n_max <= 10, W bounds not 0 <= w_min <= w_max <= 60 dB, priors outside
/// their bounds, prior_weight or w_prior_weight outside (0, 10^4], huber outside (0, 100] dB, spread_k
/// outside [0, 1000], or margin outside [0, 100] m.
int rfs_pathloss_init(rfs_pathloss_t *p, const rfs_pathloss_cfg_t *cfg);

/// Bytes of a caller buffer for a wall-count cache of `cols` candidates per origin.
uint32_t rfs_pathloss_cache_bytes(uint16_t cols);

/// Keep the wall counts in buf (rfs_pathloss_cache_bytes(cols) bytes, 4-byte aligned,
/// outliving p and every copy of it) instead of the built-in cache: cols candidates per
/// origin instead of RFS_PATHLOSS_CACHE_COLS. Fits give the same results with less work.
/// Empties the cache. Returns 0, or -1 on a null p or buf, cols 0 or above
/// RFS_PATHLOSS_MAX_CACHE_COLS, or too few bytes.
int rfs_pathloss_cache_attach(rfs_pathloss_t *p, void *buf, uint32_t bytes, uint16_t cols);

/// Entries of a log2 table (rfs_pathloss_log2_fill()): one per 17-bit mantissa.
#define RFS_PATHLOSS_LOG2_ENTRIES 65536u

/// Fill tab (RFS_PATHLOSS_LOG2_ENTRIES entries) with rfs_q16_log2(65536 + k) at k: the
/// logarithms of the distance terms' mantissas (rfs_pathloss_db_dist()), once for many
/// states (a host index, 256 KB).
void rfs_pathloss_log2_fill(int32_t *tab);

/// Read the distance terms' logarithms from tab (filled by rfs_pathloss_log2_fill(),
/// outliving p) instead of computing them: the same fits with less work. Returns 0, or -1
/// on a null p or tab.
int rfs_pathloss_log2_attach(rfs_pathloss_t *p, const int32_t *tab);

/// The model interface of a path-loss state.
rfs_model_t rfs_pathloss_model(rfs_pathloss_t *p);

/// Operations (also reachable through rfs_pathloss_model()).
extern const rfs_model_ops_t rfs_pathloss_ops;

/// Walls on the straight line from (x, y) to the estimated source, as predictions count
/// them (rfs_map_walls_crossed, saturated at 15); 0 without a model or a map. A caller
/// predicting many points against one source may keep them (rfs_fields.h).
uint32_t rfs_pathloss_walls_to_source(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y);

/// The prediction at (x, y), target units Q16.16, given its walls to the estimated source
/// (rfs_pathloss_walls_to_source(); ignored without a map): bit for bit the model's
/// predict() there. false when there is no model.
/// Scaling and overflow: Q16 differences squared in uint64 (saturated), n L and W k
/// products < 2^45 in int64, the sum saturated to Q16.16.
bool rfs_pathloss_predict_walls(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y,
                                uint32_t walls, rfs_q16_t *value);

/// The current estimate; false when there is no model.
bool rfs_pathloss_estimate(const rfs_pathloss_t *p, rfs_pathloss_est_t *est);

/// Size of the residual surface (coarse candidate grid) of the last fit; 0 x 0 when none.
void rfs_pathloss_surface_size(const rfs_pathloss_t *p, uint16_t *ncx, uint16_t *ncy);

/// Coarse point (ci, cj): its position (metres Q16.16) and residual sqrt(2 x mean Huber
/// loss) in dB Q16.16. false when there is no model, (ci, cj) is outside the surface or
/// the point was not a candidate (not legal); the position is set whenever in range.
bool rfs_pathloss_residual_at(const rfs_pathloss_t *p, uint16_t ci, uint16_t cj, rfs_q16_t *x,
                              rfs_q16_t *y, rfs_q16_t *rms);

/// Weight, Q0.16 (65536 = 1), with which the model's draw (rfs_pathloss_ops.sample) picks
/// coarse point (ci, cj) of the last fit: e^(-(m - m0) x bins / (2 T m_best)), m its mean
/// loss per unit weight (the surface), m0 the best coarse point's (which weighs 1), m_best
/// the chosen source's, T cfg.sample_t: proportional to e^(-chi2 / 2T) with chi2 =
/// (m / m_best - 1) x bins, the spread region's and hold_k's reading of the surface. 0
/// when there is no model, (ci, cj) is off the surface or not a candidate, or the
/// exponent is 16 or more (a weight below 2^-23).
/// Scaling: (m - m0) x bins < 2^32 x 2^9 and m_best x 2T < 2^32 x 2^23 in uint64; the
/// exponent in Q16 < 16 x 2^16 (rfs_q16_exp_neg).
uint32_t rfs_pathloss_draw_weight(const rfs_pathloss_t *p, uint16_t ci, uint16_t cj);

/// 10 log10(max(d, 1 m)) for a squared distance d2 in m^2 Q32.32 (the square of a Q16.16
/// difference), dB Q16.16, error < 1e-4 dB.
/// Scaling and overflow: log2 of d2 from its bit length and a Q16 mantissa in [1, 2)
/// (rfs_q16_log2), minus 32 (Q32), times 10 log10(2) / 2 in Q30: < 2^53 in int64.
rfs_q16_t rfs_pathloss_db_dist(uint64_t d2_q32);

#endif /* RFS_PATHLOSS_H */
