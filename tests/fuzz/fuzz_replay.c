/* fuzz_replay.c - libFuzzer target over the recorded stream parser and player
 * (firmware/rfs_replay.h): arbitrary bytes as the records after the map, played into the
 * application loop (CAN decoding, seeker, drive). The harness supplies a fixed map (an
 * empty 40 x 20 m room at 0.5 m cells, 1 m lattice, so a control period stays cheap) unless
 * the input replaces it. Any crash, sanitizer report or overrun is a bug. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rfs_app.h"
#include "rfs_replay.h"

static rfs_app_t s_app;
static rfs_replay_player_t s_player;

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    (void)p;
    (void)n;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.map.grid = RFS_Q16_ONE;
    rfs_replay_player_init(&s_player, &s_app, &cfg, sink, NULL);
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_MAP;
    r.u.map.w = 80;
    r.u.map.h = 40;
    r.u.map.res = RFS_Q16_HALF;
    r.u.map.has_wall = 1;
    (void)rfs_replay_play(&s_player, &r);
    for (uint16_t y = 0; y < 40; y++) {
        memset(&r, 0, sizeof r);
        r.type = RFS_REPLAY_MAP_FREE;
        r.u.chunk.offset = (uint32_t)y * 10u;
        r.u.chunk.n = 10;
        memset(r.u.chunk.bytes, (y == 0 || y == 39) ? 0x00 : 0xFF, 10);
        if (y != 0 && y != 39) {
            r.u.chunk.bytes[0] = 0xFE;
            r.u.chunk.bytes[9] = 0x7F;
        }
        (void)rfs_replay_play(&s_player, &r);
    }
    size_t pos = 0;
    unsigned steps = 0;
    while (pos < size) {
        uint32_t used = 0;
        if (rfs_replay_parse(data + pos, (uint32_t)(size - pos), &used, &r) != RFS_REPLAY_OK) {
            break;
        }
        if (used < 2u || used > size - pos) {
            __builtin_trap();
        }
        pos += used;
        if (r.type == RFS_REPLAY_STEP && ++steps > 200u) {
            break;
        }
        if (!rfs_replay_play(&s_player, &r)) {
            break;
        }
    }
    return 0;
}
