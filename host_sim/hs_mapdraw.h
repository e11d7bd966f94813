/* hs_mapdraw.h - a map drawn for placing things by eye (rfseek-map --png): its cells, the
 * core's legal points, a grid line at every whole metre and world-coordinate labels, as
 * an 8-bit RGB PNG (lx_png.h). Layout and colours: docs/MAPS.md, "rfseek-map".
 *
 * Each map cell is an S x S block of pixels, S = ceil(20 x resolution) so that a metre
 * spans at least 20 pixels, lowered (to 1 at least) while a side of the map would pass
 * HS_MAPDRAW_MAX_SIDE pixels. The map area starts at column HS_MAPDRAW_LEFT, row
 * HS_MAPDRAW_TOP; the picture is LEFT + S w + RIGHT by TOP + S h + BOTTOM pixels. The
 * whole metre x = k is drawn at column LEFT + round((k - origin_x) S / res), y = k at row
 * TOP + round((origin_y + h res - k) S / res), over free and unknown cells (walls stay
 * black); x = 0 and y = 0 are drawn in red over everything.
 */
#ifndef HS_MAPDRAW_H
#define HS_MAPDRAW_H

#include <stdint.h>
#include <stdio.h>

#include "lx_map.h"
#include "rfs_map.h"

/// Left margin (the y labels), pixels.
#define HS_MAPDRAW_LEFT 88u
/// Right margin, pixels.
#define HS_MAPDRAW_RIGHT 16u
/// Top margin (the y axis title), pixels.
#define HS_MAPDRAW_TOP 24u
/// Bottom margin (the x labels and axis title), pixels.
#define HS_MAPDRAW_BOTTOM 44u
/// Most pixels a side of the map area may take.
#define HS_MAPDRAW_MAX_SIDE 16384u

/// Colours, RGB.
#define HS_MAPDRAW_LEGAL 0xffffffu     ///< free and legal for the core: a start may go there
#define HS_MAPDRAW_FREE 0xffe9a8u      ///< free, but within the clearance of a wall or the unknown
#define HS_MAPDRAW_UNKNOWN 0xb4b4b4u   ///< unknown
#define HS_MAPDRAW_WALL 0x000000u      ///< occupied
#define HS_MAPDRAW_GRID 0x8cb4ebu      ///< a whole metre
#define HS_MAPDRAW_AXIS 0xdc2828u      ///< x = 0 or y = 0

/// The picture's geometry.
typedef struct hs_mapdraw_layout {
    uint32_t scale;   ///< S, pixels per map cell
    uint32_t width;   ///< picture width, pixels
    uint32_t height;  ///< picture height, pixels
    uint32_t label_m; ///< metres between labels: 1, 2, 5, 10, 20, 50, ...
} hs_mapdraw_layout_t;

/// The layout of m's picture. 0, or -1 with err = "reason" when m is wider or taller than
/// HS_MAPDRAW_MAX_SIDE cells.
int hs_mapdraw_layout(const lx_map_t *m, hs_mapdraw_layout_t *out, char *err, size_t errlen);

/// Draw m (cells in m->cell) to f as a PNG; a free cell's pixel is HS_MAPDRAW_LEGAL when
/// the core map says its centre is legal (rfs_map_point_legal), HS_MAPDRAW_FREE otherwise.
/// 0, or -1 with err = "reason"; the caller closes f.
int hs_mapdraw_png(const lx_map_t *m, const rfs_map_t *core, FILE *f, char *err, size_t errlen);

#endif /* HS_MAPDRAW_H */
