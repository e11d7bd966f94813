/* lx_pgm.c - PGM reader (lx_pgm.h). */
#include "lx_pgm.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lx_err.h"

/* The image is read as a stream, one byte of look-ahead: never more than the header
 * declares, so a huge or endless file (/dev/zero, a sparse file) costs no memory. */
typedef struct pgm_in {
    FILE *f;
    int c;        /* the next byte, or EOF */
    uint64_t pos; /* bytes consumed before c */
} pgm_in_t;

static void pgm_next(pgm_in_t *in)
{
    if (in->c != EOF) {
        in->pos++;
    }
    in->c = getc(in->f);
}

static bool pgm_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skip whitespace and '#' comments in a PGM header. */
static void pgm_skip(pgm_in_t *in)
{
    while (in->c != EOF) {
        if (in->c == '#') {
            while (in->c != EOF && in->c != '\n' && in->c != '\r') {
                pgm_next(in);
            }
        } else if (pgm_space(in->c)) {
            pgm_next(in);
        } else {
            break;
        }
    }
}

/* A decimal unsigned integer; -1 when absent or above max. */
static long pgm_uint(pgm_in_t *in, long max)
{
    pgm_skip(in);
    if (in->c < '0' || in->c > '9') {
        return -1;
    }
    long v = 0;
    while (in->c >= '0' && in->c <= '9') {
        v = v * 10 + (in->c - '0');
        if (v > max) {
            return -1;
        }
        pgm_next(in);
    }
    return v;
}

/* What a read needs besides the stream. */
typedef struct pgm_job {
    const char *path;
    uint32_t w, h, maxval;
    lx_pgm_row_fn on_row;
    void *ctx;
} pgm_job_t;

/* The raster of a P5 image, row by row. */
static int pgm_raster_p5(pgm_in_t *in, const pgm_job_t *j, uint16_t *samples, char *err, size_t errlen)
{
    const uint32_t w = j->w;
    const uint32_t h = j->h;
    size_t bpp = j->maxval > 255 ? 2 : 1;
    uint8_t *row = malloc((size_t)w * bpp);
    if (row == NULL) {
        return lx_err_set(err, errlen, j->path, "out of memory");
    }
    for (uint32_t r = 0; r < h; r++) {
        size_t got = fread(row, bpp, w, in->f);
        if (got < w) {
            free(row);
            return lx_err_set(err, errlen, j->path, "truncated: %zu raster bytes, header says %u x %u needs %zu",
                              ((size_t)r * w + got) * bpp, w, h, (size_t)w * h * bpp);
        }
        for (uint32_t x = 0; x < w; x++) {
            uint16_t v = bpp == 2 ? (uint16_t)(row[2 * x] << 8 | row[2 * x + 1]) : row[x];
            if (v > j->maxval) {
                free(row);
                return lx_err_set(err, errlen, j->path, "pixel %zu value %u above maxval %u", (size_t)r * w + x, v,
                                  j->maxval);
            }
            samples[x] = v;
        }
        j->on_row(j->ctx, r, samples);
    }
    free(row);
    in->pos += 1 + (uint64_t)w * h * bpp; /* the whitespace byte held in c, then the raster */
    in->c = getc(in->f);
    return 0;
}

/* The raster of a P2 image, value by value. */
static int pgm_raster_p2(pgm_in_t *in, const pgm_job_t *j, uint16_t *samples, char *err, size_t errlen)
{
    size_t count = (size_t)j->w * j->h;
    for (size_t i = 0; i < count; i++) {
        long v = pgm_uint(in, (long)j->maxval);
        if (v < 0) {
            pgm_skip(in);
            if (in->c == EOF) {
                return lx_err_set(err, errlen, j->path, "truncated: %zu of %zu pixels (header says %u x %u)", i, count,
                                  j->w, j->h);
            }
            return lx_err_set(err, errlen, j->path, "bad pixel value at pixel %zu (0..%u expected)", i, j->maxval);
        }
        samples[i % j->w] = (uint16_t)v;
        if (i % j->w == j->w - 1) {
            j->on_row(j->ctx, (uint32_t)(i / j->w), samples);
        }
    }
    pgm_skip(in);
    return 0;
}

int lx_pgm_read(const char *path, uint64_t max_pixels, lx_pgm_info_fn on_info, lx_pgm_row_fn on_row, void *ctx,
                char *err, size_t errlen)
{
    pgm_in_t in = {fopen(path, "rb"), EOF, 0};
    if (in.f == NULL) {
        return lx_err_set(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    int c0 = getc(in.f);
    int c1 = getc(in.f);
    if (c0 != 'P' || (c1 != '5' && c1 != '2')) {
        int rc = ferror(in.f) ? lx_err_set(err, errlen, path, "read error")
                              : lx_err_set(err, errlen, path, "not a PGM or PNG image (magic P5, P2 or the PNG "
                                           "signature expected)");
        fclose(in.f);
        return rc;
    }
    bool ascii = c1 == '2';
    in.pos = 2;
    in.c = getc(in.f);
    long lw = pgm_uint(&in, 1L << 20);
    long lh = pgm_uint(&in, 1L << 20);
    long lm = pgm_uint(&in, 65535);
    int rc = 0;
    uint16_t *samples = NULL;
    pgm_job_t j = {path, (uint32_t)lw, (uint32_t)lh, (uint32_t)lm, on_row, ctx};
    if (lw < 0 || lh < 0 || lm < 0) {
        rc = lx_err_set(err, errlen, path, "malformed or truncated PGM header (width height maxval)");
    } else if (lw == 0 || lh == 0 || (uint64_t)lw * (uint64_t)lh > max_pixels) {
        rc = lx_err_set(err, errlen, path, "image size %ld x %ld out of range (1..%llu pixels)", lw, lh,
                        (unsigned long long)max_pixels);
    } else if (lm == 0) {
        rc = lx_err_set(err, errlen, path, "maxval 0 in PGM header");
    } else if (!ascii && !(in.c == ' ' || in.c == '\t' || in.c == '\n' || in.c == '\r')) {
        /* P5: exactly one whitespace byte after maxval (already read as in.c), then the raster. */
        rc = lx_err_set(err, errlen, path, "malformed or truncated PGM header (no raster)");
    } else if (on_info(ctx, j.w, j.h, j.maxval, ascii, err, errlen) != 0) {
        rc = -1;
    } else if ((samples = malloc((size_t)lw * sizeof(*samples))) == NULL) {
        rc = lx_err_set(err, errlen, path, "out of memory");
    } else {
        rc = ascii ? pgm_raster_p2(&in, &j, samples, err, errlen) : pgm_raster_p5(&in, &j, samples, err, errlen);
        if (rc == 0 && in.c != EOF) {
            rc = lx_err_set(err, errlen, path, "data after the %ld x %ld %s the header declares (at byte %llu)", lw, lh,
                            ascii ? "pixels" : "raster", (unsigned long long)in.pos);
        }
    }
    if (rc == 0 && ferror(in.f)) {
        rc = lx_err_set(err, errlen, path, "read error");
    }
    free(samples);
    fclose(in.f);
    return rc;
}
