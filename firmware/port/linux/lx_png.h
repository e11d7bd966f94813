/* lx_png.h - PNG images through libpng, which only lx_png.c includes: a row-by-row reader
 * with bounded memory for map images (lx_map.h) and a writer for rfseek-map's pictures.
 *
 * Reading expands every PNG to plain samples (libpng's transforms): a palette to RGB,
 * gray of 1, 2 or 4 bits to 8, a tRNS transparency to an alpha channel; 16-bit samples
 * stay 16-bit. No gamma or colour correction is applied (map_server applies none), and
 * text, ICC-profile and other metadata chunks are skipped unread.
 *
 * Memory: the header is checked before anything is allocated (at most 2^20 pixels a
 * side and max_pixels in all). A non-interlaced image is decoded one row at a time (at
 * most 8 bytes a pixel; libpng's two rows and ours: 24 MB); an interlaced one needs its
 * whole decoded image as well and is refused above LX_PNG_MAX_INTERLACED bytes.
 *
 * Errors: 0 / -1 with exactly one line "file: reason" in err (libpng's own message for a
 * damaged file); nothing stays allocated or open.
 */
#ifndef LX_PNG_H
#define LX_PNG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/// Most pixels along either side of an image read.
#define LX_PNG_MAX_SIDE (1u << 20)
/// Most bytes of decoded image an interlaced PNG may need (32 MB).
#define LX_PNG_MAX_INTERLACED (1u << 25)

/// A PNG's header once expanded.
typedef struct lx_png_info {
    uint32_t w;          ///< width, pixels
    uint32_t h;          ///< height, pixels
    uint8_t channels;    ///< samples per pixel: 1 gray, 2 gray + alpha, 3 RGB, 4 RGBA
    uint8_t depth;       ///< bits per sample: 8 or 16 (maximum sample 255 or 65535)
    uint8_t color_type;  ///< the file's PNG colour type: 0 gray, 2 RGB, 3 palette, 4 gray + alpha, 6 RGBA
    uint8_t bit_depth;   ///< the file's bits per sample (per index for a palette): 1 .. 16
    bool interlaced;     ///< Adam7 interlaced
} lx_png_info_t;

/// Called once with the header, before any row: 0 to read on, or -1 after writing one
/// line "file: reason" into err (the read stops and returns -1).
typedef int (*lx_png_info_fn)(void *ctx, const lx_png_info_t *info, char *err, size_t errlen);

/// Called for each row, top row first: samples holds w * channels values, 0 .. 2^depth - 1.
typedef void (*lx_png_row_fn)(void *ctx, uint32_t row, const uint16_t *samples);

/// Read the PNG at path through on_info, then on_row for every row. An image of more than
/// max_pixels pixels is refused before the rows are read, as is data after its IEND chunk.
/// Returns 0, or -1 with err = "path: reason".
int lx_png_read(const char *path, uint64_t max_pixels, lx_png_info_fn on_info, lx_png_row_fn on_row,
                void *ctx, char *err, size_t errlen);

/// Fill row y (top row first) of the image being written: w * channels bytes.
typedef void (*lx_png_fill_fn)(void *ctx, uint32_t y, uint8_t *row);

/// Write a non-interlaced 8-bit PNG of w x h pixels (channels 1: gray, 3: RGB) to f, row by
/// row through fill. Returns 0, or -1 with err = "reason" (the caller names the file);
/// the caller closes f and, on failure, removes what was written.
int lx_png_write(FILE *f, uint32_t w, uint32_t h, int channels, lx_png_fill_fn fill, void *ctx,
                 char *err, size_t errlen);

#endif /* LX_PNG_H */
