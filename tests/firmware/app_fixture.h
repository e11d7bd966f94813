/* app_fixture.h - the fixture shared by the application loop's tests (test_app.c,
 * test_app_models.c): a 20 x 10 m room at 0.1 m, free inside a one-cell border wall, and
 * the application state and sample store it is given to. One translation unit each: the storage is static. */
#ifndef APP_FIXTURE_H
#define APP_FIXTURE_H

#include <stdint.h>
#include <string.h>

#include "rfs_app.h"

#define W 200u /* 20 x 10 m at 0.1 m */
#define H 100u
static uint8_t s_free[(W + 7u) / 8u * H];
static rfs_app_t s_app;
static rfs_sample_t s_samples[RFS_APP_MAX_SAMPLES];

/* c with the fixture's sample store. */
static inline rfs_app_cfg_t fx_cfg(rfs_app_cfg_t c)
{
    c.samples = s_samples;
    return c;
}

/* The room's map over s_free (rebuilt at each call). */
static inline rfs_app_map_t room(void)
{
    memset(s_free, 0, sizeof s_free);
    for (uint16_t y = 1; y < H - 1u; y++) {
        for (uint16_t x = 1; x < W - 1u; x++) {
            rfs_map_bit_set(s_free, (W + 7u) / 8u, x, y, true);
        }
    }
    const rfs_app_map_t m = {.w = W, .h = H, .res = RFS_Q16_FRAC(1, 10), .origin_x = 0,
                             .origin_y = 0, .free = s_free, .wall = NULL};
    return m;
}

#endif /* APP_FIXTURE_H */
