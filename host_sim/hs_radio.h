/* hs_radio.h - the simulator's indoor radio model: RSSI of each packet at a position.
 *
 * Received signal of source s at receiver position x (docs/RADIO_MODEL.md has every
 * default and its source); each term can be switched off:
 *
 *   P(x) = P_tx - PL(d) - W * walls(x, s) + S_s(x) + F_s(x)          [dBm]
 *   PL(d) = L0 + 10 n log10(max(d, d0) / d0)      log-distance, ITU-R P.1238 office n = 3
 *   walls   wall runs crossed by the straight line (Box2D ray casts), W = 5 dB (ns-3)
 *   S_s     Gudmundson shadowing: a fixed Gaussian field per seed and source with
 *           covariance sigma^2 exp(-|dx| / d_c), sigma = 4 dB, d_c = 5 m
 *   F_s     small-scale fading, a fixed field per seed and source: 10 log10 |h|^2 with
 *           h = sqrt(K/(K+1)) e^{j k d} + sqrt(1/(K+1)) N^-1/2 sum_i e^{j(k u_i.x + phi_i)}
 *           (plane waves at wavelength 12.5 cm; Rician with K in line of sight, Rayleigh
 *           (K = 0) when a wall is crossed)
 *
 * Each packet: lost with probability 1 - PDR(M), PDR(M) = 1 / (1 + exp(-(M - S) / w))
 * with M the local mean (P without F: a 20 MHz frame does not fade with one frequency;
 * S = sensitivity, where half the packets arrive); else reported as
 * clip(round(P + N(0, sigma_noise)), rx_min, rx_max) whole dBm.
 *
 * Fields are generated once per (seed, source): returning to a place gives the same
 * shadowing and fading. Shadowing is tabulated on a grid and interpolated bilinearly;
 * wall counts are cached per receiver cell; fading is summed per packet from a sine table.
 */
#ifndef HS_RADIO_H
#define HS_RADIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rfs_fix.h"

/// Radio model configuration (defaults: hs_radio_cfg_default()).
typedef struct hs_radio_cfg {
    bool pathloss;           ///< log-distance path loss on
    double exponent;         ///< path loss exponent n (3.0, ITU-R P.1238 office, 2.4 GHz)
    double ref_dist_m;       ///< reference distance d0, metres (1.0)
    double ref_loss_db;      ///< loss at d0, dB (20 log10 f_MHz - 28 = 39.6 at 2.4 GHz)
    bool walls;              ///< wall attenuation on
    double wall_db;          ///< loss per wall crossed, dB (5, ns-3 buildings model)
    bool shadowing;          ///< Gudmundson shadowing on
    double shadow_sigma_db;  ///< its standard deviation, dB (4)
    double shadow_dcorr_m;   ///< its decorrelation distance, metres (5)
    double shadow_grid_m;    ///< tabulation grid, metres (0.5)
    uint32_t shadow_waves;   ///< plane waves summed for the field (256)
    bool fading;             ///< small-scale fading on
    double wavelength_m;     ///< carrier wavelength, metres (0.125: 2.4 GHz)
    double rician_k_db;      ///< Rician K in line of sight, dB (6)
    uint32_t fading_waves;   ///< plane waves of the scattered part (32)
    bool noise;              ///< per-packet measurement noise on
    double noise_sigma_db;   ///< its standard deviation, dB (4: the paper's measurement)
    bool quantise;           ///< report whole dBm (round to nearest)
    bool clip;               ///< clip to [rx_min_dbm, rx_max_dbm]
    double rx_min_dbm;       ///< lowest value the receiver reports (-100)
    double rx_max_dbm;       ///< highest value the receiver reports (-10)
    bool loss;               ///< packet loss near the sensitivity on
    double sensitivity_dbm;  ///< signal at which half the packets are lost (-95)
    double loss_width_db;    ///< logistic width of the loss curve, dB (1.5)
    double wall_cache_m;     ///< receiver cell size of the wall-count cache, metres (0.1)
} hs_radio_cfg_t;

/// One transmitter.
typedef struct hs_radio_src {
    double x;       ///< position, metres (map frame)
    double y;       ///< position, metres
    double tx_dbm;  ///< transmit power (EIRP), dBm
} hs_radio_src_t;

/// Walls crossed by a segment (the world's ray casts); ctx is passed through.
typedef unsigned (*hs_radio_walls_fn)(void *ctx, double x0, double y0, double x1, double y1);

/// Most sources one radio model holds.
#define HS_RADIO_MAX_SOURCES 8u

/// Opaque radio model (owns its tables).
typedef struct hs_radio hs_radio_t;

/// Defaults, each with its source in docs/RADIO_MODEL.md.
hs_radio_cfg_t hs_radio_cfg_default(void);

/// Check a configuration; 0, or -1 with err = "field: reason".
int hs_radio_cfg_check(const hs_radio_cfg_t *cfg, char *err, size_t errlen);

/// Build the model for the sources over the area [x0, x1] x [y0, y1] (metres), with the
/// fields drawn from `seed`. walls may be NULL (no walls). NULL with err on failure.
hs_radio_t *hs_radio_create(const hs_radio_cfg_t *cfg, const hs_radio_src_t *src,
                            unsigned nsrc, double x0, double y0, double x1, double y1,
                            uint64_t seed, hs_radio_walls_fn walls, void *walls_ctx,
                            char *err, size_t errlen);

/// Release (NULL is fine).
void hs_radio_destroy(hs_radio_t *r);

/// Walls between the receiver at (x, y) and source s (cached per receiver cell).
unsigned hs_radio_walls(hs_radio_t *r, unsigned s, double x, double y);

/// Bytes of one source's wall-count cache for an area (hs_radio_use_wall_cache).
size_t hs_radio_wall_cache_bytes(const hs_radio_cfg_t *cfg, double x0, double y0, double x1,
                                 double y1);

/// Use a caller-owned wall-count cache for source s (hs_radio_wall_cache_bytes() bytes,
/// initialised to -1 = unknown), so that runs of the same geometry share the ray casts:
/// the caller guarantees the same walls, area, wall_cache_m and source position.
void hs_radio_use_wall_cache(hs_radio_t *r, unsigned s, int8_t *cache);

/// Shadowing of source s at (x, y), dB (0 when off).
double hs_radio_shadow_db(const hs_radio_t *r, unsigned s, double x, double y);

/// Small-scale fading gain of source s at (x, y), dB (0 when off); los selects Rician.
double hs_radio_fading_db(const hs_radio_t *r, unsigned s, double x, double y, bool los);

/// Large-scale mean signal (path loss, walls, shadowing; no fading), dBm.
double hs_radio_mean_dbm(hs_radio_t *r, unsigned s, double x, double y);

/// Signal before measurement noise (mean plus fading), dBm, evaluated at the corner of the
/// 5 mm cell (x, y) lies in (a receiver moving a few mm between packets reuses it).
double hs_radio_signal_dbm(hs_radio_t *r, unsigned s, double x, double y);

/// Packet delivery probability at local mean signal p_dbm (1 when loss is off).
double hs_radio_pdr(const hs_radio_cfg_t *cfg, double p_dbm);

/// One packet of source s received at (x, y): false when lost; else *dbm is the reported
/// value. Draws from rng (the simulator's per-run stream).
bool hs_radio_packet(hs_radio_t *r, unsigned s, double x, double y, rfs_rng_t *rng,
                     int *dbm);

/// Standard normal variate from rng (Box-Muller), double precision.
double hs_radio_gauss(rfs_rng_t *rng);

/// Uniform in [0, 1) with 53 random bits.
double hs_radio_uniform(rfs_rng_t *rng);

#endif /* HS_RADIO_H */
