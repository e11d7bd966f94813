/* lx_map.h - ROS map_server maps (YAML + PGM or PNG) on the host, their conversion to the
 * core's bit grids (rfs_map.h), and the crop rfseek-map writes.
 *
 * The map_server convention (docs/MAPS.md, "The map_server convention"):
 *   image            a PGM (P5 binary or P2 ASCII) or a PNG (any colour type and depth,
 *                    lx_png.h), told apart by content, relative to the YAML file
 *   resolution       metres per pixel, LX_MAP_RES_MIN .. LX_MAP_RES_MAX
 *   origin           [x, y, yaw]: the map frame position of the lower-left pixel's
 *                    lower-left corner; yaw must be 0 (rotated maps are not supported)
 *   occupied_thresh  in [0, 1]
 *   free_thresh      in [0, 1], below occupied_thresh
 *   negate           0 or 1 (also true/false)
 *   mode             trinary (default), scale or raw
 * Each pixel becomes map_server's occupancy value (-1 unknown, 0..100) by the rules of
 * nav2's map_io.cpp, loadMapFromFile (lx_map_value), and that value a cell state as
 * nav2's costmap reads a map by default (lx_map_cell_of): -1 unknown, 100 occupied,
 * 0..99 free. Row 0 of the image is the TOP of the map; lx_map_t stores row 0 = BOTTOM
 * (y grows up), which is the core's convention too.
 *
 * Errors: every function that reads outside input returns 0 / -1 and writes exactly one
 * line "file: reason" (no newline) into err; nothing is left allocated on failure.
 */
#ifndef LX_MAP_H
#define LX_MAP_H

#include <stdbool.h>
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

/// The YAML's `mode`: how a pixel becomes an occupancy value (lx_map_value).
enum { LX_MAP_TRINARY = 0, LX_MAP_SCALE = 1, LX_MAP_RAW = 2 };

/// How pixels are read: the YAML's thresholds, negate and mode.
typedef struct lx_map_reading {
    double occ_th;     ///< occupied_thresh
    double free_th;    ///< free_thresh
    int negate;        ///< 0 or 1
    int mode;          ///< LX_MAP_TRINARY, LX_MAP_SCALE or LX_MAP_RAW
} lx_map_reading_t;

/// map_server's occupancy value of one pixel (nav2 map_io.cpp, loadMapFromFile): -1
/// unknown, or 0..100. ch holds n samples of at most maxval: gray (n 1), gray and alpha
/// (2), red, green, blue (3) or RGBA (4). mean = the colour samples' mean (gray counts
/// as three equal colours), with the alpha sample averaged in for trinary;
/// p = (maxval - mean) / maxval, or mean / maxval with negate. trinary: 100 when
/// p > occ_th, 0 when p < free_th, otherwise -1. scale: -1 when alpha < maxval, else as
/// trinary but rint(100 (p - free_th) / (occ_th - free_th)) between the thresholds.
/// raw: v = round(255 mean / maxval) (negate ignored), v when 0..100, otherwise -1.
int8_t lx_map_value(const lx_map_reading_t *r, const uint16_t *ch, int n, uint32_t maxval);

/// The cell state of an occupancy value, as nav2's costmap reads a map by default
/// (lethal_cost_threshold 100, trinary_costmap true): -1 unknown, 100 occupied, else free.
uint8_t lx_map_cell_of(int8_t value);

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
    int mode;           ///< mode as read: LX_MAP_TRINARY, LX_MAP_SCALE or LX_MAP_RAW
    char format[48];    ///< the image as read, e.g. "PGM P5, maxval 255" or "PNG RGBA, 8 bits"
    uint32_t n_partial; ///< cells of value 1..99 (scale and raw maps), read as free
    uint8_t *cell;      ///< w * h LX_CELL_* values, index y * w + x, row 0 = BOTTOM
    int8_t *value;      ///< w * h occupancy values, same layout: lx_map_load_values only
    char *image_path;   ///< the image's path as opened (heap; NULL for a crop)
} lx_map_t;

/// Load a map_server YAML and its image into cell (value NULL). Returns 0, or -1 with
/// err = "file: reason". At most 2^26 pixels, 2^20 a side, and under 100 MB of memory
/// whatever the files (docs/RELIABILITY.md).
int lx_map_load(const char *yaml_path, lx_map_t *m, char *err, size_t errlen);

/// Load as lx_map_load, but keep each pixel's occupancy value in value (cell NULL).
int lx_map_load_values(const char *yaml_path, lx_map_t *m, char *err, size_t errlen);

/// Release a loaded map (safe on a zeroed or already freed map).
void lx_map_free(lx_map_t *m);

/// The cell (cx, cy) holding the world point (x, y) metres (row 0 = bottom): false when the
/// point is off the map (or not a number).
bool lx_map_cell_at(const lx_map_t *m, double x, double y, uint32_t *cx, uint32_t *cy);

/// The smallest box holding every cell that is not unknown: columns x0..x1, rows y0..y1
/// (row 0 = bottom), inclusive. false when every cell is unknown.
bool lx_map_known_box(const lx_map_t *m, uint32_t *x0, uint32_t *y0, uint32_t *x1, uint32_t *y1);

/// Copy the w x h cells from column x0, row y0 (inside m) into out, with the origin moved
/// by (x0, y0) cells so that every cell keeps its world position. 0, or -1 with
/// err = "map: out of memory".
int lx_map_crop(const lx_map_t *m, uint32_t x0, uint32_t y0, uint32_t w, uint32_t h, lx_map_t *out,
                char *err, size_t errlen);

/// Write m's cells as a map_server pair: yaml_path and beside it the image (yaml_path
/// with .yaml or .yml replaced by .pgm, else .pgm appended), a trinary P5 PGM of free
/// 254, occupied 0, unknown 205 with occupied_thresh 0.65, free_thresh 0.1, negate 0, the
/// origin to 1 nm. Each file goes to NAME.tmp, then is renamed; the image first. 0, or -1
/// with err = "file: reason" and neither file written.
int lx_map_save(const lx_map_t *m, const char *yaml_path, char *err, size_t errlen);

/// The image name lx_map_save writes beside yaml_path, into out (size n). false when it
/// does not fit.
bool lx_map_save_image_path(const char *yaml_path, char *out, size_t n);

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
