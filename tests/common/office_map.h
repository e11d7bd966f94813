/* office_map.h - the office built by the path-loss and fields tests (test_pathloss*.c,
 * test_fields.c): 30 x 16 m at 0.1 m cells, a corridor (y 7-9 m) between two rows of three
 * rooms, doors 1 m wide, a wall round the edge.
 */
#ifndef OFFICE_MAP_H
#define OFFICE_MAP_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_map.h"
#include "rfs_test.h"

#define MW 300
#define MH 160
#define RES_Q16 6554 /* 0.1 m as the map loader rounds it */

static inline bool office_is_wall(int i, int j)
{
    if (i == 0 || j == 0 || i == MW - 1 || j == MH - 1) {
        return true;
    }
    bool door = (i >= 40 && i < 50) || (i >= 140 && i < 150) || (i >= 240 && i < 250);
    if ((j == 70 || j == 90) && !door) {
        return true;
    }
    return (i == 100 || i == 200) && (j < 70 || j > 90);
}

/* The office's bit grids (each MH * ((MW + 7) / 8) bytes) and its core map. */
static inline void office_map_init(uint8_t *free_bits, uint8_t *wall_bits, uint8_t *legal_bits,
                                   rfs_map_t *map)
{
    uint16_t stride = (MW + 7) / 8;
    for (int j = 0; j < MH; ++j) {
        for (int i = 0; i < MW; ++i) {
            rfs_map_bit_set(wall_bits, stride, (uint16_t)i, (uint16_t)j, office_is_wall(i, j));
            rfs_map_bit_set(free_bits, stride, (uint16_t)i, (uint16_t)j, !office_is_wall(i, j));
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    assert_int_equal(rfs_map_init(map, &mc, MW, MH, RES_Q16, 0, 0, free_bits, wall_bits,
                                  legal_bits), 0);
}

#endif /* OFFICE_MAP_H */
