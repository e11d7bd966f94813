/* map_dump - test helper: a map as lx_map reads it, for tests/linux/map_formats.py.
 *
 *   map_dump MAP.yaml     prints "W H", then H lines of W occupancy values (the image's
 *                         top row first; lx_map_load_values), then H lines of W cell
 *                         states (0 free, 1 occupied, 2 unknown; lx_map_load)
 * On a bad map: the one error line on stderr, exit 1.
 */
#include <stdio.h>

#include "lx_map.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fputs("usage: map_dump MAP.yaml\n", stderr);
        return 2;
    }
    lx_map_t v;
    lx_map_t c;
    char err[1024];
    if (lx_map_load_values(argv[1], &v, err, sizeof(err)) != 0 || lx_map_load(argv[1], &c, err, sizeof(err)) != 0) {
        fprintf(stderr, "map_dump: %s\n", err);
        lx_map_free(&v);
        return 1;
    }
    printf("%u %u\n", v.w, v.h);
    for (uint32_t r = 0; r < v.h; r++) {
        for (uint32_t x = 0; x < v.w; x++) {
            printf(x ? " %d" : "%d", v.value[(size_t)(v.h - 1 - r) * v.w + x]);
        }
        putchar('\n');
    }
    for (uint32_t r = 0; r < c.h; r++) {
        for (uint32_t x = 0; x < c.w; x++) {
            printf(x ? " %u" : "%u", c.cell[(size_t)(c.h - 1 - r) * c.w + x]);
        }
        putchar('\n');
    }
    lx_map_free(&v);
    lx_map_free(&c);
    return 0;
}
