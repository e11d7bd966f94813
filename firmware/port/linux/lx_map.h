/* lx_map.h - ROS map_server maps (YAML + PGM) on the host, and their conversion to the
 * core's bit grids (rfs_map.h).
 *
 * The ROS map_server convention, exactly (docs/MAPS.md):
 *   image            path of a PGM (P5 binary or P2 ASCII), relative to the YAML file
 *   resolution       metres per pixel, LX_MAP_RES_MIN .. LX_MAP_RES_MAX
 *   origin           [x, y, yaw]: the map frame position of the lower-left pixel's
 *                    lower-left corner; yaw must be 0 (rotated maps are not supported)
 *   occupied_thresh  in [0, 1]
 *   free_thresh      in [0, 1], below occupied_thresh
 *   negate           0 or 1 (also true/false)
 *   mode             trinary (default); scale and raw are rejected
 * A pixel value v (maxval M) gives p = (M - v) / M, or v / M when negate is set;
 * occupied when p > occupied_thresh, free when p < free_thresh, otherwise unknown.
 * Row 0 of the PGM is the TOP of the map; lx_map_t stores row 0 = BOTTOM (y grows up),
 * which is the core's convention too.
 *
 * Errors: every function that reads outside input returns 0 / -1 and writes exactly one
 * line "file: reason" (no newline) into err; nothing is left allocated on failure.
 */
#ifndef LX_MAP_H
#define LX_MAP_H

#include <stddef.h>
#include <stdint.h>

#include "rfs_map.h"

/// Finest map resolution accepted, metres per pixel (finer is a typo, and would make the
/// resampling to the core's cells loop over billions of pixels).
#define LX_MAP_RES_MIN 0.001
/// Coarsest map resolution accepted, metres per pixel.
#define LX_MAP_RES_MAX 10.0

/// Cell states of lx_map_t.cell.
enum { LX_CELL_FREE = 0, LX_CELL_OCC = 1, LX_CELL_UNKNOWN = 2 };

/// A loaded map at its own resolution.
typedef struct lx_map {
    uint32_t w;        ///< width, pixels (cells)
    uint32_t h;        ///< height, pixels (cells)
    double res;        ///< metres per cell
    double origin_x;   ///< map frame x of the lower-left corner of cell (0, 0), metres
    double origin_y;   ///< map frame y of that corner, metres
    double occ_th;     ///< occupied_thresh as read
    double free_th;    ///< free_thresh as read
    int negate;        ///< negate as read (0 or 1)
    uint8_t *cell;     ///< w * h LX_CELL_* values, index y * w + x, row 0 = BOTTOM
} lx_map_t;

/// Load a map_server YAML and its image. Returns 0, or -1 with err = "file: reason".
int lx_map_load(const char *yaml_path, lx_map_t *m, char *err, size_t errlen);

/// Release a loaded map (safe on a zeroed or already freed map).
void lx_map_free(lx_map_t *m);

/// Count the cells of each state; any pointer may be NULL.
void lx_map_count(const lx_map_t *m, uint32_t *n_free, uint32_t *n_occ, uint32_t *n_unknown);

/// A map converted for the core: rfs_map_t plus the three heap bit grids it points to.
typedef struct lx_core_map {
    rfs_map_t map;         ///< initialised core map (legal grid derived)
    uint8_t *free_bits;    ///< rfs_map_bytes(w, h) bytes
    uint8_t *wall_bits;    ///< rfs_map_bytes(w, h) bytes
    uint8_t *legal_bits;   ///< rfs_map_bytes(w, h) bytes
} lx_core_map_t;

/// Resample a loaded map to the core's resolution core_res (metres, > 0) and initialise
/// the core map with cfg (NULL: rfs_map_cfg_default()). Conservative: a coarse cell is
/// free only if every fine cell it overlaps is free (fine cells beyond the image count
/// as unknown), and a wall if any fine cell it overlaps is occupied. The core grid keeps
/// the same origin and covers the whole image (ceil). Returns 0, or -1 with
/// err = "map: reason" (too large for the core's 16-bit sizes, bad resolution, ...).
int lx_map_to_core(const lx_map_t *m, double core_res, const rfs_map_cfg_t *cfg,
                   lx_core_map_t *out, char *err, size_t errlen);

/// Release a converted map (safe on a zeroed or already freed one).
void lx_core_map_free(lx_core_map_t *c);

#endif /* LX_MAP_H */
