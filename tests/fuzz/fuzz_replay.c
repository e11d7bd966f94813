/* fuzz_replay.c - libFuzzer target over the recorded stream parser and player
 * (firmware/rfs_replay.h): arbitrary bytes as the records after the map, played into the
 * application loop (CAN decoding, seeker, drive). The harness supplies a fixed map (an
 * empty 40 x 20 m room at 0.5 m cells, 1 m lattice, so a control period stays cheap) unless
 * the input replaces it. Any crash, sanitizer report or overrun is a bug.
 *
 * Speed: loading the map and rfs_app_init() on it cost as much as 200 steps, and are the
 * same for every input that does not bring its own CFG or map. They are done once: each
 * input starts from a copy of the player and application as they stand after the map
 * (or after the map and the start its first record would trigger), byte for byte what
 * playing those records again would give (both are static, so inner pointers stay valid). */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rfs_app.h"
#include "rfs_replay.h"

static rfs_app_t s_app;
static rfs_replay_player_t s_player;
/* [0]: the map loaded, not started; [1]: started on it with the default configuration. */
static rfs_app_t s_app_saved[2];
static rfs_replay_player_t s_player_saved[2];
static int s_ready;

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    (void)p;
    (void)n;
}

static void load_map(void)
{
    static rfs_sample_t samples[RFS_APP_MAX_SAMPLES];
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.follow_epoch = true; /* as the emulator image and rfseek-replay play streams */
    cfg.samples = samples;
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
}

/* Records whose playing begins with the player's start() (rfs_replay.c): init on the map. */
static int starts(uint8_t type)
{
    return type == RFS_REPLAY_POSE || type == RFS_REPLAY_RSSI || type == RFS_REPLAY_RECEIVER ||
           type == RFS_REPLAY_CAN || type == RFS_REPLAY_STEP || type == RFS_REPLAY_BUS;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!s_ready) {
        load_map();
        s_app_saved[0] = s_app;
        s_player_saved[0] = s_player;
        /* What start() does: rfs_app_init() with the player's configuration and map. */
        if (rfs_app_init(&s_app, &s_player.cfg, &s_player.map) != 0) {
            __builtin_trap();
        }
        s_player.started = true;
        s_app_saved[1] = s_app;
        s_player_saved[1] = s_player;
        s_ready = 1;
    }
    rfs_replay_rec_t r;
    uint32_t used = 0;
    const int k = size > 0 && rfs_replay_parse(data, (uint32_t)size, &used, &r) == RFS_REPLAY_OK &&
                  starts((uint8_t)r.type);
    s_app = s_app_saved[k];
    s_player = s_player_saved[k];

    size_t pos = 0;
    unsigned steps = 0;
    while (pos < size) {
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
