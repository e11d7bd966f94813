/* lx_png.c - PNG read and write through libpng (lx_png.h). libpng reports errors by
 * longjmp to the setjmp of the function that called it, so each public function keeps
 * every allocation it makes in a struct that outlives the jump, and frees it in one
 * place whichever way it leaves.
 */
#include "lx_png.h"

#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

#include "lx_err.h"

/* What a read or write owns across libpng's longjmp, and libpng's last message. */
typedef struct png_job {
    FILE *f;
    char msg[256];
    uint16_t *samples;   /* one row as uint16 samples (read) */
    uint8_t *out;        /* one 8-bit row (write) */
    uint8_t *image;      /* an interlaced image, whole */
    png_bytep *rows;     /* its row pointers */
} png_job_t;

static void on_error(png_structp png, png_const_charp msg)
{
    png_job_t *j = png_get_error_ptr(png);
    snprintf(j->msg, sizeof(j->msg), "%s", msg);
    png_longjmp(png, 1);
}

/* Warnings (an ancillary chunk with a bad CRC, a sRGB profile libpng dislikes) do not
 * change the pixels: ignored, so a map that loads prints nothing. */
static void on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void on_read(png_structp png, png_bytep out, size_t n)
{
    png_job_t *j = png_get_io_ptr(png);
    if (fread(out, 1, n, j->f) != n) {
        png_error(png, ferror(j->f) ? "read error" : "truncated");
    }
}

/* One row of bytes (8-bit samples, or 16-bit big-endian) widened in place to uint16. */
static void widen(uint16_t *s, size_t n, int depth)
{
    const uint8_t *b = (const uint8_t *)s;
    if (depth == 16) {
        for (size_t i = 0; i < n; i++) {
            s[i] = (uint16_t)(b[2 * i] << 8 | b[2 * i + 1]);
        }
    } else {
        for (size_t i = n; i-- > 0;) { /* from the end: sample i's byte is never overwritten early */
            s[i] = b[i];
        }
    }
}

/* The chunks skipped unread: text, ICC profiles, suggested palettes, Exif. */
static const png_byte k_skip[] = "tEXt\0zTXt\0iTXt\0iCCP\0sPLT\0eXIf";

/* Read everything after the signature check, inside the setjmp of lx_png_read. */
static int read_body(png_structp png, png_infop info, png_job_t *j, const char *path, uint64_t max_pixels,
                     lx_png_info_fn on_info, lx_png_row_fn on_row, void *ctx, char *err, size_t errlen)
{
    png_set_user_limits(png, 0x7fffffffu, 0x7fffffffu); /* the sizes are checked below, with our message */
    png_set_chunk_malloc_max(png, 1u << 22);
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, k_skip, (int)(sizeof(k_skip) / 5));
    png_read_info(png, info);
    lx_png_info_t pi;
    memset(&pi, 0, sizeof(pi));
    pi.w = png_get_image_width(png, info);
    pi.h = png_get_image_height(png, info);
    pi.color_type = png_get_color_type(png, info);
    pi.bit_depth = png_get_bit_depth(png, info);
    pi.interlaced = png_get_interlace_type(png, info) != PNG_INTERLACE_NONE;
    if (pi.w > LX_PNG_MAX_SIDE || pi.h > LX_PNG_MAX_SIDE || (uint64_t)pi.w * pi.h > max_pixels) {
        return lx_err_set(err, errlen, path, "image size %u x %u out of range (1..%llu pixels, at most 2^20 a side)",
                          pi.w, pi.h, (unsigned long long)max_pixels);
    }
    if (pi.color_type == PNG_COLOR_TYPE_PALETTE) {
        png_set_palette_to_rgb(png);
    }
    if (pi.color_type == PNG_COLOR_TYPE_GRAY && pi.bit_depth < 8) {
        png_set_expand_gray_1_2_4_to_8(png);
    }
    if (png_get_valid(png, info, PNG_INFO_tRNS)) {
        png_set_tRNS_to_alpha(png);
    }
    int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    pi.channels = png_get_channels(png, info);
    pi.depth = png_get_bit_depth(png, info);
    size_t rowbytes = png_get_rowbytes(png, info);
    size_t nsamp = (size_t)pi.w * pi.channels;
    if (pi.channels < 1 || pi.channels > 4 || (pi.depth != 8 && pi.depth != 16) ||
        rowbytes != nsamp * (pi.depth / 8u)) {
        return lx_err_set(err, errlen, path, "unsupported PNG layout (%u channels of %u bits)", pi.channels, pi.depth);
    }
    if (passes > 1 && (uint64_t)rowbytes * pi.h > LX_PNG_MAX_INTERLACED) {
        return lx_err_set(err, errlen, path, "interlaced PNG of %u x %u needs %llu MB decoded, above %u MB (save it "
                          "non-interlaced)", pi.w, pi.h, (unsigned long long)((uint64_t)rowbytes * pi.h >> 20),
                          LX_PNG_MAX_INTERLACED >> 20);
    }
    if (on_info(ctx, &pi, err, errlen) != 0) {
        return -1;
    }
    j->samples = malloc(nsamp * sizeof(uint16_t));
    if (j->samples == NULL) {
        return lx_err_set(err, errlen, path, "out of memory");
    }
    if (passes > 1) {
        j->image = malloc(rowbytes * pi.h);
        j->rows = malloc(pi.h * sizeof(png_bytep));
        if (j->image == NULL || j->rows == NULL) {
            return lx_err_set(err, errlen, path, "out of memory");
        }
        for (uint32_t y = 0; y < pi.h; y++) {
            j->rows[y] = j->image + (size_t)y * rowbytes;
        }
        png_read_image(png, j->rows);
    }
    for (uint32_t y = 0; y < pi.h; y++) {
        if (passes > 1) {
            memcpy(j->samples, j->rows[y], rowbytes);
        } else {
            png_read_row(png, (png_bytep)j->samples, NULL);
        }
        widen(j->samples, nsamp, pi.depth);
        on_row(ctx, y, j->samples);
    }
    png_read_end(png, NULL);
    if (getc(j->f) != EOF) {
        return lx_err_set(err, errlen, path, "data after the IEND chunk");
    }
    return 0;
}

int lx_png_read(const char *path, uint64_t max_pixels, lx_png_info_fn on_info, lx_png_row_fn on_row,
                void *ctx, char *err, size_t errlen)
{
    /* On the heap: what changes between setjmp and longjmp must not be a local. */
    png_job_t *job = calloc(1, sizeof(*job));
    if (job == NULL) {
        return lx_err_set(err, errlen, path, "out of memory");
    }
    job->f = fopen(path, "rb");
    if (job->f == NULL) {
        free(job);
        return lx_err_set(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    png_byte sig[8];
    size_t n = fread(sig, 1, sizeof(sig), job->f);
    png_structp png = NULL;
    png_infop info = NULL;
    int rc = -1;
    if (n != sizeof(sig) || png_sig_cmp(sig, 0, sizeof(sig)) != 0) {
        rc = ferror(job->f) ? lx_err_set(err, errlen, path, "read error")
                            : lx_err_set(err, errlen, path, "not a PNG image (bad signature)");
    } else if ((png = png_create_read_struct(PNG_LIBPNG_VER_STRING, job, on_error, on_warning)) == NULL ||
               (info = png_create_info_struct(png)) == NULL) {
        rc = lx_err_set(err, errlen, path, "out of memory");
    } else if (setjmp(png_jmpbuf(png)) != 0) {
        rc = lx_err_set(err, errlen, path, "damaged PNG: %s", job->msg);
    } else {
        png_set_read_fn(png, job, on_read);
        png_set_sig_bytes(png, (int)sizeof(sig));
        rc = read_body(png, info, job, path, max_pixels, on_info, on_row, ctx, err, errlen);
    }
    png_destroy_read_struct(&png, &info, NULL);
    if (rc == 0 && ferror(job->f)) {
        rc = lx_err_set(err, errlen, path, "read error");
    }
    fclose(job->f);
    free(job->samples);
    free(job->image);
    free(job->rows);
    free(job);
    return rc;
}

static void write_body(png_structp png, png_infop info, png_job_t *j, uint32_t w, uint32_t h, int channels,
                       lx_png_fill_fn fill, void *ctx)
{
    png_init_io(png, j->f);
    png_set_IHDR(png, info, w, h, 8, channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    uint8_t *row = j->out;
    for (uint32_t y = 0; y < h; y++) {
        fill(ctx, y, row);
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
}

int lx_png_write(FILE *f, uint32_t w, uint32_t h, int channels, lx_png_fill_fn fill, void *ctx,
                 char *err, size_t errlen)
{
    if (w == 0 || h == 0 || w > 0x7fffffffu || h > 0x7fffffffu || (channels != 1 && channels != 3)) {
        return lx_err_set(err, errlen, NULL, "cannot write a %u x %u PNG of %d channels", w, h, channels);
    }
    png_job_t *job = calloc(1, sizeof(*job));
    if (job != NULL) {
        job->f = f;
        job->out = malloc((size_t)w * (size_t)channels);
    }
    png_structp png = NULL;
    png_infop info = NULL;
    int rc = 0;
    if (job == NULL || job->out == NULL ||
        (png = png_create_write_struct(PNG_LIBPNG_VER_STRING, job, on_error, on_warning)) == NULL ||
        (info = png_create_info_struct(png)) == NULL) {
        rc = lx_err_set(err, errlen, NULL, "out of memory");
    } else if (setjmp(png_jmpbuf(png)) != 0) {
        rc = lx_err_set(err, errlen, NULL, "%s", job->msg);
    } else {
        write_body(png, info, job, w, h, channels, fill, ctx);
    }
    png_destroy_write_struct(&png, &info);
    if (job != NULL) {
        free(job->out);
    }
    free(job);
    return rc;
}
