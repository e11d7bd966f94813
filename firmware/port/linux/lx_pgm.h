/* lx_pgm.h - PGM images (P5 binary, P2 ASCII; maxval 1..65535) read row by row for map
 * images (lx_map.h), with the same row callback as lx_png.h.
 *
 * Memory: only what the header declares is read, one byte of look-ahead, so a huge or
 * endless file (/dev/zero, a sparse file) costs nothing; the header is checked before
 * anything is allocated (at most 2^20 pixels a side and max_pixels in all), then one row
 * is held at a time.
 *
 * Errors: 0 / -1 with exactly one line "file: reason" in err; nothing stays allocated or
 * open.
 */
#ifndef LX_PGM_H
#define LX_PGM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/// Called once with the header, before any row: w x h pixels of 0 .. maxval, P2 when
/// ascii. 0 to read on, or -1 after writing one line "file: reason" into err.
typedef int (*lx_pgm_info_fn)(void *ctx, uint32_t w, uint32_t h, uint32_t maxval, bool ascii, char *err,
                              size_t errlen);

/// Called for each row, top row first: w samples, 0 .. maxval.
typedef void (*lx_pgm_row_fn)(void *ctx, uint32_t row, const uint16_t *samples);

/// Read the PGM at path through on_info, then on_row for every row; data after the
/// pixels the header declares is refused. Returns 0, or -1 with err = "path: reason".
int lx_pgm_read(const char *path, uint64_t max_pixels, lx_pgm_info_fn on_info, lx_pgm_row_fn on_row, void *ctx,
                char *err, size_t errlen);

#endif /* LX_PGM_H */
