/* rfs_pathloss_walls.c - the path-loss model's wall counts (docs/PATHLOSS.md, "A bin's
 * walls: the footprint" and "Work, the wall-count cache and slicing"): a bin's footprint
 * counts and the cache that keeps them across fits. */
#include "rfs_pathloss_internal.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_reach.h"

/// A cache cell not counted yet (counts are at most 4 x RFS_PATHLOSS_WALLS_MAX).
#define NOT_COUNTED 255u

static uint32_t cell_hash(uint16_t cx, uint16_t cy)
{
    return ((uint32_t)cx * 0x9E3779B1u + (uint32_t)cy * 0x85EBCA77u) >> 22; /* 10 bits */
}

/* The cache in use: the attached one, or the built-in arrays. */
static rfs_pathloss_xcache_t cache_of(rfs_pathloss_t *p)
{
    if (p->x.cells != 0) {
        return p->x;
    }
    _Static_assert(RFS_PATHLOSS_COL_HASH == 512u, "9 hash bits");
    rfs_pathloss_xcache_t c = {RFS_PATHLOSS_CACHE_COLS, 9u, p->col_hash, p->col_key,
                               (uint8_t *)(void *)p->walls};
    return c;
}

/* Rows the cache in use holds. */
static uint16_t cache_rows(const rfs_pathloss_t *p)
{
    return p->x.cells != 0 ? (uint16_t)RFS_PATHLOSS_CACHE_ROWS : (uint16_t)RFS_PATHLOSS_BUILTIN_ROWS;
}

/* The cache byte of (row, col). */
static uint8_t *cache_cell(rfs_pathloss_t *p, uint16_t row, uint32_t col)
{
    if (p->x.cells != 0) {
        return p->x.cells + (uint32_t)row * p->x.cols + col;
    }
    return &p->walls[row][col];
}

/* The hash slot a column key starts its probe at (bits: log2 of the slots). */
static uint32_t col_hash_of(uint32_t key, uint8_t bits)
{
    return ((key & 0xFFFFu) * 0x9E3779B1u + (key >> 16) * 0x85EBCA77u) >> (32u - bits);
}

static void cache_clear(rfs_pathloss_t *p)
{
    rfs_pathloss_xcache_t c = cache_of(p);
    p->nrows = 0u;
    p->ncols = 0u;
    p->cols_free = 0u;
    memset(p->row_hash, 0, sizeof(p->row_hash));
    memset(p->col_used, 0, sizeof(p->col_used));
    memset(p->col_live, 0, sizeof(p->col_live));
    memset(c.col_hash, 0, ((size_t)1 << c.hash_bits) * sizeof(c.col_hash[0]));
    memset(c.cells, (int)NOT_COUNTED, (size_t)cache_rows(p) * c.cols);
}

uint32_t rfs_pathloss_cache_bytes(uint16_t cols)
{
    uint32_t slots = 1u;
    while (slots < 2u * cols) {
        slots *= 2u;
    }
    return slots * 2u + (uint32_t)cols * 4u + RFS_PATHLOSS_CACHE_ROWS * (uint32_t)cols;
}

int rfs_pathloss_cache_attach(rfs_pathloss_t *p, void *buf, uint32_t bytes, uint16_t cols)
{
    if (p == 0 || buf == 0 || cols == 0u || cols > RFS_PATHLOSS_MAX_CACHE_COLS ||
        bytes < rfs_pathloss_cache_bytes(cols)) {
        return -1;
    }
    uint8_t bits = 1u;
    while ((1u << bits) < 2u * cols) {
        bits++;
    }
    /* The key words first (4-byte aligned with buf), then the hash, then the bytes. */
    uint8_t *b = (uint8_t *)buf;
    p->x.cols = cols;
    p->x.hash_bits = bits;
    p->x.col_key = (uint32_t *)(void *)b;
    p->x.col_hash = (uint16_t *)(void *)(b + (size_t)cols * 4u);
    p->x.cells = b + (size_t)cols * 4u + ((size_t)2u << bits);
    p->cache_map = 0; /* emptied before the next fit uses it */
    return 0;
}

/* The hash slot of origin (cx, cy): its row's, or the empty one where it would go. */
static uint32_t row_slot(const rfs_pathloss_t *p, uint16_t cx, uint16_t cy)
{
    uint32_t h = cell_hash(cx, cy);
    while (p->row_hash[h] != 0u) {
        const rfs_pathloss_row_t *r = &p->rows[p->row_hash[h] - 1u];
        if (r->cx == cx && r->cy == cy) {
            break;
        }
        h = (h + 1u) & (RFS_PATHLOSS_CACHE_HASH - 1u);
    }
    return h;
}

/* The cache is full of origins: keep those a bin of this fit holds (row_used), empty
 * the others' counts and drop them from the hash. */
static void rows_tidy(rfs_pathloss_t *p)
{
    rfs_pathloss_xcache_t c = cache_of(p);
    memset(p->row_hash, 0, sizeof(p->row_hash));
    for (uint16_t r = 0u; r < p->nrows; ++r) {
        if (rfs_reach_bit(p->row_used, r)) {
            p->row_hash[row_slot(p, p->rows[r].cx, p->rows[r].cy)] = (uint16_t)(r + 1u);
        } else {
            memset(cache_cell(p, r, 0u), (int)NOT_COUNTED, c.cols);
        }
    }
}

/* The built-in columns are all taken: keep those the last fit looked up (col_used), empty
 * the others (a row at a time, skipping bytes of the bitmap with none: at most 32,768
 * cells), drop
 * them from the hash; col_used starts again for this fit. */
static void cols_tidy(rfs_pathloss_t *p)
{
    _Static_assert(RFS_PATHLOSS_CACHE_COLS % 8u == 0u, "whole bitmap bytes");
    rfs_pathloss_xcache_t c = cache_of(p);
    const uint32_t mask = (1u << c.hash_bits) - 1u;
    memset(c.col_hash, 0, ((size_t)1 << c.hash_bits) * sizeof(c.col_hash[0]));
    for (uint32_t k = 0u; k < RFS_PATHLOSS_CACHE_COLS; ++k) {
        if (!rfs_reach_bit(p->col_live, k) || !rfs_reach_bit(p->col_used, k)) {
            continue;
        }
        uint32_t h = col_hash_of(c.col_key[k], c.hash_bits);
        while (c.col_hash[h] != 0u) {
            h = (h + 1u) & mask;
        }
        c.col_hash[h] = (uint16_t)(k + 1u);
    }
    /* col_used becomes the columns dropped (live, not used); live keeps the used ones */
    for (uint32_t b = 0u; b < sizeof(p->col_used); ++b) {
        const uint8_t used = p->col_used[b];
        p->col_used[b] = (uint8_t)(p->col_live[b] & ~used);
        p->col_live[b] &= used;
        for (uint32_t d = p->col_used[b]; d != 0u; d &= d - 1u) {
            p->cols_free++; /* no __builtin_popcount: the core links no library */
        }
    }
    for (uint32_t r = 0u; r < RFS_PATHLOSS_BUILTIN_ROWS; ++r) {
        uint8_t *row = p->walls[r];
        for (uint32_t b = 0u; b < sizeof(p->col_used); ++b) {
            for (uint32_t d = p->col_used[b]; d != 0u; d &= d - 1u) {
                row[8u * b + (uint32_t)__builtin_ctz(d)] = NOT_COUNTED;
            }
        }
    }
    memset(p->col_used, 0, sizeof(p->col_used));
}

void rfs_pathloss_walls_assign(rfs_pathloss_t *p)
{
    _Static_assert(RFS_PATHLOSS_CACHE_HASH == 1024u, "cell_hash yields 10 bits");
    _Static_assert(RFS_PATHLOSS_CACHE_ROWS <= 0xFFFFu && RFS_PATHLOSS_CACHE_COLS <= 0xFFFFu,
                   "uint16 row and column numbers");
    if (p->map == 0) {
        return;
    }
    if (p->blocks_map != p->map) {
        p->blocks_map = rfs_map_wall_blocks(p->map, p->wall_blocks, sizeof(p->wall_blocks),
                                            &p->blocks) == 0 ? p->map : 0;
    }
    if (p->cache_map != p->map || !rfs_pathloss_same_lattice(&p->cache_lat, &p->lat)) {
        cache_clear(p);
        p->cache_map = p->map;
        p->cache_lat = p->lat;
    } else if (p->x.cells == 0 && p->ncols == RFS_PATHLOSS_CACHE_COLS) {
        cols_tidy(p);
    } else if (p->x.cells == 0) {
        memset(p->col_used, 0, sizeof(p->col_used));
    }
    /* The bins' origins cached already, then the others in rows free or freed (a bin
     * beyond the rows counts uncached). */
    memset(p->row_used, 0, sizeof(p->row_used));
    for (uint32_t b = 0u; b < p->nbins; ++b) {
        rfs_pathloss_bin_t *bb = &p->bins[b];
        uint16_t cx, cy;
        bb->row = RFS_PATHLOSS_NO_ROW;
        if (rfs_map_cell(p->map, bb->x, bb->y, &cx, &cy)) {
            const uint32_t h = row_slot(p, cx, cy);
            if (p->row_hash[h] != 0u) {
                bb->row = (uint16_t)(p->row_hash[h] - 1u);
                rfs_reach_bit_set(p->row_used, bb->row);
            }
        }
    }
    const uint16_t nrows_max = cache_rows(p);
    bool tidied = false;
    uint16_t free_from = 0u;
    for (uint32_t b = 0u; b < p->nbins; ++b) {
        rfs_pathloss_bin_t *bb = &p->bins[b];
        uint16_t cx, cy;
        if (bb->row != RFS_PATHLOSS_NO_ROW || !rfs_map_cell(p->map, bb->x, bb->y, &cx, &cy)) {
            continue;
        }
        uint16_t r;
        if (p->nrows < nrows_max) {
            r = p->nrows++;
        } else {
            if (!tidied) {
                rows_tidy(p);
                tidied = true;
            }
            while (free_from < p->nrows && rfs_reach_bit(p->row_used, free_from)) {
                free_from++;
            }
            if (free_from == p->nrows) {
                continue; /* every row holds a bin of this fit */
            }
            r = free_from;
        }
        p->rows[r].cx = cx;
        p->rows[r].cy = cy;
        p->row_hash[row_slot(p, cx, cy)] = (uint16_t)(r + 1u);
        rfs_reach_bit_set(p->row_used, r);
        bb->row = r;
    }
}

int32_t rfs_pathloss_walls_col(rfs_pathloss_t *p, uint16_t li, uint16_t lj, bool coarse)
{
    const bool two = p->cfg.coarse_footprint != p->cfg.footprint;
    if (p->map == 0 || (two && lj >= 0x8000u)) {
        return -1;
    }
    rfs_pathloss_xcache_t c = cache_of(p);
    const bool builtin = p->x.cells == 0;
    /* The coarse footprint's column of a point is keyed apart (bit 31). */
    const uint32_t key = (uint32_t)li | (uint32_t)lj << 16 | (two && coarse ? 1u << 31 : 0u);
    const uint32_t mask = (1u << c.hash_bits) - 1u;
    uint32_t h = col_hash_of(key, c.hash_bits);
    while (c.col_hash[h] != 0u) {
        const uint32_t k = c.col_hash[h] - 1u;
        if (c.col_key[k] == key) {
            if (builtin) {
                rfs_reach_bit_set(p->col_used, k);
            }
            return (int32_t)k;
        }
        h = (h + 1u) & mask;
    }
    uint32_t k = p->ncols;
    if (k == c.cols) {
        if (!builtin) {
            return -1; /* full: the first candidates keep their columns until a clear */
        }
        if (p->cols_free == 0u) {
            return -1; /* every column live: this point is counted uncached */
        }
        uint32_t b = 0u;
        while (b < sizeof(p->col_live) && p->col_live[b] == 0xFFu) {
            b++;
        }
        RFS_ASSERT(b < sizeof(p->col_live)); /* cols_free counts the columns not live */
        k = 8u * b + (uint32_t)__builtin_ctz(~(uint32_t)p->col_live[b]);
        p->cols_free--;
    } else {
        p->ncols++;
    }
    c.col_key[k] = key;
    c.col_hash[h] = (uint16_t)(k + 1u);
    if (builtin) {
        rfs_reach_bit_set(p->col_live, k);
        rfs_reach_bit_set(p->col_used, k);
    }
    return (int32_t)k;
}

uint32_t rfs_pathloss_walls_line(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y, rfs_q16_t sx,
                                 rfs_q16_t sy)
{
    rfs_map_wall_blocks_t b = p->blocks;
    b.bits = p->wall_blocks; /* this state's own grid, also in a copy of it */
    uint32_t k = rfs_map_walls_crossed_blocks(p->map, p->blocks_map == p->map ? &b : 0, x, y,
                                              sx, sy);
    return k > RFS_PATHLOSS_WALLS_MAX ? RFS_PATHLOSS_WALLS_MAX : k;
}

/* A wall origin's walls to the candidate (sx, sy) in quarter walls (0..4 x
 * RFS_PATHLOSS_WALLS_MAX): the sum of the counts from its footprint's four points
 * (wx +- f, wy +- f), a point that is not legal counting as the centre (wx, wy); with
 * footprint 0, four times the centre's. At most four counts (added to *lines): the centre
 * is counted only in place of an illegal point. */
static uint32_t footprint_walls(const rfs_pathloss_t *p, rfs_q16_t wx, rfs_q16_t wy, rfs_q16_t f,
                                rfs_q16_t sx, rfs_q16_t sy, uint32_t *lines)
{
    if (f == 0) {
        (*lines)++;
        return RFS_PATHLOSS_FOOTPRINT_RAYS * rfs_pathloss_walls_line(p, wx, wy, sx, sy);
    }
    uint32_t sum = 0u, centre = UINT32_MAX;
    for (uint32_t q = 0u; q < RFS_PATHLOSS_FOOTPRINT_RAYS; ++q) {
        rfs_q16_t x = rfs_sat32((int64_t)wx + ((q & 1u) != 0u ? f : -f));
        rfs_q16_t y = rfs_sat32((int64_t)wy + ((q & 2u) != 0u ? f : -f));
        if (rfs_map_point_legal(p->map, x, y)) {
            (*lines)++;
            sum += rfs_pathloss_walls_line(p, x, y, sx, sy);
        } else {
            if (centre == UINT32_MAX) {
                (*lines)++;
                centre = rfs_pathloss_walls_line(p, wx, wy, sx, sy);
            }
            sum += centre;
        }
    }
    return sum;
}

uint32_t rfs_pathloss_walls_bin(rfs_pathloss_t *p, const rfs_pathloss_bin_t *bb, uint32_t *lines)
{
    uint8_t *cell = bb->row != RFS_PATHLOSS_NO_ROW && p->ev.col >= 0
                        ? cache_cell(p, bb->row, (uint32_t)p->ev.col)
                        : 0;
    if (cell != 0 && *cell != NOT_COUNTED) {
        p->footprints_cached++;
        return *cell;
    }
    uint32_t n = 0u;
    uint32_t k = footprint_walls(p, bb->wx, bb->wy, p->ev.fp, p->ev.sx, p->ev.sy, &n);
    *lines = n;
    p->walls_counted += n;
    p->footprints++;
    if (cell != 0) {
        *cell = (uint8_t)k;
    }
    return k;
}

uint16_t rfs_pathloss_walls_row_find(const rfs_pathloss_t *p, uint16_t cx, uint16_t cy)
{
    const uint32_t h = row_slot(p, cx, cy);
    return p->row_hash[h] != 0u ? (uint16_t)(p->row_hash[h] - 1u) : RFS_PATHLOSS_NO_ROW;
}

uint16_t rfs_pathloss_walls_row_warm(rfs_pathloss_t *p, uint16_t cx, uint16_t cy, bool *tidied)
{
    uint16_t r;
    if (p->nrows < cache_rows(p)) {
        r = p->nrows++;
    } else {
        /* row_used: the rows the last fit's bins hold (rfs_pathloss_walls_assign), and the
         * ones warming gave origins since */
        if (!p->warm.tidied) {
            rows_tidy(p);
            p->warm.tidied = true;
            p->warm.free_from = 0u;
            *tidied = true;
        }
        while (p->warm.free_from < p->nrows && rfs_reach_bit(p->row_used, p->warm.free_from)) {
            p->warm.free_from++;
        }
        if (p->warm.free_from == p->nrows) {
            return RFS_PATHLOSS_NO_ROW;
        }
        r = p->warm.free_from;
    }
    p->rows[r].cx = cx;
    p->rows[r].cy = cy;
    p->row_hash[row_slot(p, cx, cy)] = (uint16_t)(r + 1u);
    rfs_reach_bit_set(p->row_used, r);
    return r;
}

int32_t rfs_pathloss_walls_col_find(const rfs_pathloss_t *p, uint16_t li, uint16_t lj, bool coarse)
{
    const bool two = p->cfg.coarse_footprint != p->cfg.footprint;
    if (p->map == 0 || (two && lj >= 0x8000u)) {
        return -1;
    }
    const bool builtin = p->x.cells == 0;
    const uint8_t bits = builtin ? 9u : p->x.hash_bits;
    const uint16_t *hash = builtin ? p->col_hash : p->x.col_hash;
    const uint32_t *keys = builtin ? p->col_key : p->x.col_key;
    const uint32_t key = (uint32_t)li | (uint32_t)lj << 16 | (two && coarse ? 1u << 31 : 0u);
    const uint32_t mask = (1u << bits) - 1u;
    for (uint32_t h = col_hash_of(key, bits); hash[h] != 0u; h = (h + 1u) & mask) {
        if (keys[hash[h] - 1u] == key) {
            return (int32_t)(hash[h] - 1u);
        }
    }
    return -1;
}

uint32_t rfs_pathloss_walls_warm(rfs_pathloss_t *p, uint16_t row, rfs_q16_t wx, rfs_q16_t wy,
                                 int32_t col, uint16_t li, uint16_t lj, rfs_q16_t fp)
{
    uint8_t *cell = cache_cell(p, row, (uint32_t)col);
    if (*cell != NOT_COUNTED) {
        return 0u;
    }
    rfs_q16_t sx, sy;
    rfs_pathloss_lattice_xy(&p->lat, li, lj, &sx, &sy);
    uint32_t n = 0u;
    *cell = (uint8_t)footprint_walls(p, wx, wy, fp, sx, sy, &n);
    return n;
}
