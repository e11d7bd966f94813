/* map_fixture.h - the random W x H maps and hand-made bit grids of test_map.c and
 * test_map_walls.c (rfs_map against an independent double-precision geometry). */
#ifndef MAP_FIXTURE_H
#define MAP_FIXTURE_H

#include <string.h>

#include "rfs_map.h"
#include "rfs_test.h"

#define W 48
#define H 36

typedef struct fixture {
    uint8_t free_bits[H * ((W + 7) / 8)];
    uint8_t wall_bits[H * ((W + 7) / 8)];
    uint8_t legal_bits[H * ((W + 7) / 8)];
    int free_c[H][W]; /* 1 free */
    int wall_c[H][W]; /* 1 wall */
    rfs_map_t m;
    rfs_q16_t res;
    rfs_q16_t ox;
    rfs_q16_t oy;
    rfs_q16_t clr;
} fixture_t;

static inline uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

/* Random map: free with rectangles of wall and of unknown. */
static inline void make_map(fixture_t *f, uint32_t seed, rfs_q16_t res, rfs_q16_t clr)
{
    memset(f, 0, sizeof(*f));
    f->res = res;
    f->clr = clr;
    f->ox = (rfs_q16_t)((int32_t)(lcg(&seed) % 200000) - 100000);
    f->oy = (rfs_q16_t)((int32_t)(lcg(&seed) % 200000) - 100000);
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            f->free_c[y][x] = 1;
        }
    }
    for (int k = 0; k < 10; k++) {
        int x0 = (int)(lcg(&seed) % W);
        int y0 = (int)(lcg(&seed) % H);
        int ww = 1 + (int)(lcg(&seed) % 6);
        int hh = 1 + (int)(lcg(&seed) % 6);
        int wall = (int)(lcg(&seed) % 3) != 0;
        for (int y = y0; y < y0 + hh && y < H; y++) {
            for (int x = x0; x < x0 + ww && x < W; x++) {
                f->free_c[y][x] = 0;
                f->wall_c[y][x] = wall;
            }
        }
    }
    uint16_t stride = (W + 7) / 8;
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            rfs_map_bit_set(f->free_bits, stride, (uint16_t)x, (uint16_t)y, f->free_c[y][x]);
            rfs_map_bit_set(f->wall_bits, stride, (uint16_t)x, (uint16_t)y, f->wall_c[y][x]);
        }
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = clr;
    assert_int_equal(rfs_map_init(&f->m, &cfg, W, H, res, f->ox, f->oy, f->free_bits,
                                  f->wall_bits, f->legal_bits), 0);
}

static inline rfs_q16_t rand_coord(uint32_t *s, rfs_q16_t o, int cells, rfs_q16_t res)
{
    return o + (rfs_q16_t)(lcg(s) % (uint32_t)(cells * res));
}

/* The bit grids of a hand-made W x H map: every cell free and no wall until a test says
 * otherwise; init writes the legal bits. One set, reset by each call. */
typedef struct bits {
    uint8_t free[H * ((W + 7) / 8)];
    uint8_t wall[H * ((W + 7) / 8)];
    uint8_t legal[H * ((W + 7) / 8)];
} bits_t;

static inline bits_t *all_free(void)
{
    static bits_t b;
    memset(&b, 0, sizeof(b));
    memset(b.free, 0xFF, sizeof(b.free));
    return &b;
}

#endif
