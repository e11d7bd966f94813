/* test_replay.c - the recorded stream format (firmware/rfs_replay.h): exact bytes worked
 * out by hand from the format description, round trips, every truncation, every
 * malformed field, the player's errors, and random bytes under ASan (never a read past
 * the buffer). */
#include "rfs_test.h"

#include <stdlib.h>
#include <string.h>

#include "rfs_replay.h"

static void test_header_bytes_and_checks(void **state)
{
    (void)state;
    uint8_t h[RFS_REPLAY_HEADER_LEN];
    const uint8_t want[8] = {'R', 'F', 'S', 'R', 0x01, 0x00, 0x00, 0x00};

    rfs_replay_header(h);

    assert_memory_equal(h, want, 8);
    assert_int_equal(rfs_replay_check_header(h, 8), 0);
    assert_int_equal(rfs_replay_check_header(h, 7), -1);
    h[4] = 2;
    assert_int_equal(rfs_replay_check_header(h, 8), -1);
    h[4] = 1;
    h[0] = 'X';
    assert_int_equal(rfs_replay_check_header(h, 8), -1);
}

/* A record of type TYPE at T_US (microseconds), every other field zero. */
static rfs_replay_rec_t rec_at(rfs_replay_type_t type, int64_t t_us)
{
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = type;
    r.t_us = t_us;
    return r;
}

/* R encodes to exactly the N bytes WANT (worked out by hand), and WANT parses back into
 * *BACK as one whole record of R's type. */
static void expect_exact_bytes(const rfs_replay_rec_t *r, const uint8_t *want, uint32_t n,
                               rfs_replay_rec_t *back)
{
    uint8_t buf[RFS_REPLAY_MAX_RECORD];
    uint32_t used = 0;

    assert_int_equal(rfs_replay_encode(r, buf, sizeof buf), n);

    assert_memory_equal(buf, want, n);
    assert_int_equal(rfs_replay_parse(want, n, &used, back), RFS_REPLAY_OK);
    assert_int_equal(used, n);
    assert_int_equal(back->type, r->type);
}

static void test_pose_record_exact_bytes(void **state)
{
    (void)state;
    rfs_replay_rec_t r = rec_at(RFS_REPLAY_POSE, 0x0102030405060708LL);
    r.u.pose.t_us = -1;
    r.u.pose.x = 65536;    /* 1 m */
    r.u.pose.y = -65536;   /* -1 m */
    r.u.pose.theta = 0xC90F;
    const uint8_t want[30] = {0x10, 28,
                              0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,
                              0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
                              0x00, 0x00, 0x01, 0x00,
                              0x00, 0x00, 0xFF, 0xFF,
                              0x0F, 0xC9, 0x00, 0x00};
    rfs_replay_rec_t back;

    expect_exact_bytes(&r, want, 30, &back);

    assert_int_equal(back.t_us, 0x0102030405060708LL);
    assert_int_equal(back.u.pose.t_us, -1);
    assert_int_equal(back.u.pose.x, 65536);
    assert_int_equal(back.u.pose.y, -65536);
    assert_int_equal(back.u.pose.theta, 0xC90F);
}

static void test_out_and_can_exact_bytes(void **state)
{
    (void)state;
    rfs_app_out_t o;
    memset(&o, 0, sizeof o);
    o.t_us = 50000; /* 0xC350 */
    o.left_mm_s = -2;
    o.right_mm_s = 700; /* 0x02BC */
    o.state = RFS_SEEK_DRIVING;
    o.faults = 0x0901;
    uint8_t buf[2 * RFS_REPLAY_MAX_RECORD];
    const uint8_t want[18] = {0x80, 16, 0x50, 0xC3, 0, 0, 0, 0, 0, 0,
                              0xFE, 0xFF, 0xBC, 0x02, 3, 0x01, 0x09, 0};

    assert_int_equal(rfs_replay_encode_out(&o, buf, sizeof buf), 18);
    assert_memory_equal(buf, want, 18);

    o.decided = true;
    o.decision.iteration = 7;
    o.decision.kind = RFS_SEEK_GREEDY;
    o.decision.relearned = true;
    o.decision.mean_valid = true;
    o.decision.samples = 10000; /* 0x2710 */
    const uint32_t n = rfs_replay_encode_out(&o, buf, sizeof buf);
    assert_int_equal(n, 18 + 59);
    assert_int_equal(buf[17], 1);       /* decided */
    assert_int_equal(buf[18], 0x81);    /* DECISION */
    assert_int_equal(buf[19], 57);
    assert_int_equal(buf[20], 7);       /* iteration, LE */
    assert_int_equal(buf[32], 2);       /* kind */
    assert_int_equal(buf[33], 1u | 8u); /* relearned | mean_valid */
    assert_int_equal(buf[75], 0x10);
    assert_int_equal(buf[76], 0x27);
}

static void roundtrip(const rfs_replay_rec_t *r)
{
    uint8_t buf[RFS_REPLAY_MAX_RECORD];
    const uint32_t n = rfs_replay_encode(r, buf, sizeof buf);
    assert_true(n >= 2);
    rfs_replay_rec_t back;
    uint32_t used = 0;
    assert_int_equal(rfs_replay_parse(buf, n, &used, &back), RFS_REPLAY_OK);
    assert_int_equal(used, n);
    assert_int_equal(back.type, r->type);
    uint8_t again[RFS_REPLAY_MAX_RECORD];
    assert_int_equal(rfs_replay_encode(&back, again, sizeof again), n);
    assert_memory_equal(buf, again, n);
    /* Every shorter prefix needs more bytes; nothing is read past it (ASan). */
    for (uint32_t k = 0; k < n; k++) {
        uint8_t *p = malloc(k ? k : 1);
        memcpy(p, buf, k);
        assert_int_equal(rfs_replay_parse(p, k, &used, &back), RFS_REPLAY_NEED_MORE);
        free(p);
    }
}

static void test_every_type_round_trips(void **state)
{
    (void)state;
    rfs_replay_rec_t r = rec_at(RFS_REPLAY_CFG, 0);
    r.u.cfg.seed = 0x1122334455667788ULL;
    r.u.cfg.target = 1;
    r.u.cfg.node = 9;
    r.u.cfg.fit_budget = 2500;
    roundtrip(&r);
    r = rec_at(RFS_REPLAY_MAP, 0);
    r.u.map.w = 350;
    r.u.map.h = 120;
    r.u.map.res = 6554;
    r.u.map.origin_x = -3 * 65536;
    r.u.map.has_wall = 1;
    roundtrip(&r);
    r = rec_at(RFS_REPLAY_MAP_WALL, 0);
    r.u.chunk.offset = 480;
    r.u.chunk.n = RFS_REPLAY_CHUNK;
    for (unsigned i = 0; i < RFS_REPLAY_CHUNK; i++) {
        r.u.chunk.bytes[i] = (uint8_t)(i * 7);
    }
    roundtrip(&r);
    r = rec_at(RFS_REPLAY_RSSI, 123);
    r.u.rssi.t_us = 120;
    r.u.rssi.src = 1;
    r.u.rssi.dbm = -97;
    roundtrip(&r);
    r = rec_at(RFS_REPLAY_CAN, 0);
    r.u.can.id = 0x7FF;
    r.u.can.dlc = 8;
    r.u.can.data[7] = 0xAB;
    roundtrip(&r);
    r.type = RFS_REPLAY_CAN_TX;
    roundtrip(&r);
    memset(&r, 0, sizeof r);
    const rfs_replay_type_t plain[] = {RFS_REPLAY_STEP, RFS_REPLAY_RESET, RFS_REPLAY_END};
    for (unsigned i = 0; i < 3; i++) {
        r.type = plain[i];
        r.t_us = plain[i] == RFS_REPLAY_END ? 0 : -5;
        roundtrip(&r);
    }
    r.type = RFS_REPLAY_BUS;
    r.u.bus_off = 1;
    roundtrip(&r);
    r = rec_at(RFS_REPLAY_DECISION, 0);
    r.u.out.decision.t_us = 99;
    r.u.out.decision.kind = RFS_SEEK_EPSILON;
    r.u.out.decision.prev = RFS_DRIVE_BLOCKED;
    r.u.out.decision.line_search = true;
    r.u.out.decision.path_len = -1;
    roundtrip(&r);
}

static void expect_bad(const uint8_t *b, uint32_t n)
{
    rfs_replay_rec_t r;
    uint32_t used = 0;
    assert_int_equal(rfs_replay_parse(b, n, &used, &r), RFS_REPLAY_BAD);
    assert_non_null(r.error);
}

static void test_malformed_records_are_rejected(void **state)
{
    (void)state;
    const uint8_t unknown[2] = {0x55, 0};
    const uint8_t step7[9] = {0x20, 7, 0, 0, 0, 0, 0, 0, 0};
    const uint8_t chunk_empty[6] = {0x03, 4, 0, 0, 0, 0};
    const uint8_t chunk_long[2] = {0x03, 4 + RFS_REPLAY_CHUNK + 1};
    uint8_t can[23] = {0x12, 21};
    uint8_t bus[11] = {0x21, 9};
    uint8_t out[18] = {0x80, 16};
    uint8_t dec[59] = {0x81, 57};
    uint8_t map[19] = {0x02, 17, 0, 0, 10, 0, 0, 0x10, 0, 0};
    uint8_t cfg[16] = {0x01, 14};

    expect_bad(unknown, 2);
    expect_bad(step7, 9);
    expect_bad(chunk_empty, 6);
    expect_bad(chunk_long, 2);
    can[2 + 12] = 9; /* dlc 9 */
    expect_bad(can, 23);
    can[2 + 12] = 8;
    can[2 + 9] = 0x08; /* id 0x800 */
    expect_bad(can, 23);
    bus[2 + 8] = 2;
    expect_bad(bus, 11);
    out[2 + 12] = 4; /* state */
    expect_bad(out, 18);
    out[2 + 12] = 0;
    out[2 + 15] = 2; /* decided */
    expect_bad(out, 18);
    dec[2 + 12] = 4; /* kind */
    expect_bad(dec, 59);
    dec[2 + 12] = 0;
    dec[2 + 13] = 16; /* flags */
    expect_bad(dec, 59);
    expect_bad(map, 19); /* w = 0 */
    map[2] = 10;
    map[6] = 0; map[7] = 0; /* res 0 */
    expect_bad(map, 19);
    map[7] = 0x10;
    map[2 + 16] = 2; /* has_wall */
    expect_bad(map, 19);
    cfg[2 + 8] = 2; /* target */
    expect_bad(cfg, 16);
}

/* The CFG target byte's flag: bit 7 is seek.fit_early, the target in bits 0-1, bits 2-6
 * refused (rfs_replay.h). Bytes worked out by hand. */
static void test_cfg_fit_early_flag(void **state)
{
    (void)state;
    rfs_replay_rec_t r = rec_at(RFS_REPLAY_CFG, 0);
    r.u.cfg.seed = 0x0102030405060708ULL;
    r.u.cfg.target = 1;
    r.u.cfg.node = 9;
    r.u.cfg.fit_budget = 600;
    r.u.cfg.fit_early = true;
    const uint8_t want[16] = {0x01, 14, 0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,
                              0x81, 9, 0x58, 0x02, 0x00, 0x00};
    rfs_replay_rec_t back;

    expect_exact_bytes(&r, want, 16, &back);

    assert_true(back.u.cfg.fit_early);
    assert_int_equal(back.u.cfg.target, 1);
    assert_int_equal(back.u.cfg.node, 9);
    assert_int_equal(back.u.cfg.fit_budget, 600);

    /* A CFG written before the flag (target byte 0 or 1) reads with fit_early off. */
    uint8_t old[16];
    memcpy(old, want, sizeof old);
    old[2 + 8] = 0x01;
    uint32_t used = 0;
    assert_int_equal(rfs_replay_parse(old, 16, &used, &back), RFS_REPLAY_OK);
    assert_false(back.u.cfg.fit_early);
    assert_int_equal(back.u.cfg.target, 1);
    r.u.cfg.fit_early = false;
    uint8_t buf[RFS_REPLAY_MAX_RECORD];
    assert_int_equal(rfs_replay_encode(&r, buf, sizeof buf), 16);
    assert_memory_equal(buf, old, 16);

    /* Any of bits 2-6 set, with or without the flag: refused, one reason. */
    const uint8_t unknown[] = {0x04, 0x08, 0x10, 0x20, 0x40, 0x84, 0xC0, 0xFF};
    for (unsigned i = 0; i < sizeof unknown; i++) {
        old[2 + 8] = unknown[i];
        assert_int_equal(rfs_replay_parse(old, 16, &used, &back), RFS_REPLAY_BAD);
        assert_string_equal(back.error, "CFG target byte has an unknown flag bit");
    }
    const uint8_t range[] = {0x02, 0x03, 0x82}; /* targets 2, 3; 2 with the flag */
    for (unsigned i = 0; i < sizeof range; i++) {
        old[2 + 8] = range[i];
        assert_int_equal(rfs_replay_parse(old, 16, &used, &back), RFS_REPLAY_BAD);
        assert_string_equal(back.error, "CFG target out of range");
    }
    /* A target whose bits would read as the flag is not encoded. */
    r.u.cfg.target = 0x80;
    assert_int_equal(rfs_replay_encode(&r, buf, sizeof buf), 0);
}

static void test_random_bytes_never_overrun(void **state)
{
    (void)state;
    srand(12345);
    unsigned ok = 0, bad = 0, more = 0;
    for (int it = 0; it < 20000; it++) {
        const uint32_t n = (uint32_t)(rand() % 64);
        uint8_t *p = malloc(n ? n : 1);
        for (uint32_t i = 0; i < n; i++) {
            p[i] = (uint8_t)rand();
        }
        if (n > 0 && (it & 1)) {
            p[0] = (uint8_t)(0x10 + rand() % 3); /* steer towards real types */
            if (n > 1) {
                p[1] = (uint8_t)(rand() % 32);
            }
        }
        rfs_replay_rec_t r;
        uint32_t used = 0;
        const rfs_replay_status_t st = rfs_replay_parse(p, n, &used, &r);
        if (st == RFS_REPLAY_OK) {
            assert_true(used >= 2 && used <= n);
            ok++;
        } else if (st == RFS_REPLAY_BAD) {
            bad++;
        } else {
            more++;
        }
        free(p);
    }
    assert_true(ok > 100 && bad > 100 && more > 100);
}

typedef struct buf_sink {
    uint8_t b[4096];
    uint32_t n;
} buf_sink_t;

/* The default configuration over this file's sample store. */
static rfs_app_cfg_t store_cfg(void)
{
    static rfs_sample_t samples[RFS_APP_MAX_SAMPLES];
    rfs_app_cfg_t c = rfs_app_cfg_default();
    c.samples = samples;
    return c;
}

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    buf_sink_t *s = ctx;
    if (s->n + n <= sizeof s->b) {
        memcpy(s->b + s->n, p, n);
    }
    s->n += n;
}

static void test_player_errors(void **state)
{
    (void)state;
    static rfs_app_t app;
    static rfs_replay_player_t p;
    static buf_sink_t out;
    const rfs_app_cfg_t cfg = store_cfg();
    rfs_replay_rec_t r;

    memset(&out, 0, sizeof out);
    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    assert_int_equal(out.n, 8);
    assert_memory_equal(out.b, "RFSR\x01\0\0\0", 8);
    r = rec_at(RFS_REPLAY_STEP, 0);
    assert_false(rfs_replay_play(&p, &r));
    assert_int_equal(p.error, RFS_REPLAY_E_NO_MAP);
    assert_false(rfs_replay_play(&p, &r)); /* stays stopped */

    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    r = rec_at(RFS_REPLAY_MAP, 0);
    r.u.map.w = 1000;
    r.u.map.h = 1000;
    r.u.map.res = 6554;
    assert_false(rfs_replay_play(&p, &r));
    assert_int_equal(p.error, RFS_REPLAY_E_MAP_SIZE);

    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    r.u.map.w = 80; /* 10 bytes per row */
    r.u.map.h = 40; /* 400 bytes */
    assert_true(rfs_replay_play(&p, &r));
    rfs_replay_rec_t c = rec_at(RFS_REPLAY_MAP_FREE, 0);
    c.u.chunk.offset = 399;
    c.u.chunk.n = 2;
    assert_false(rfs_replay_play(&p, &c));
    assert_int_equal(p.error, RFS_REPLAY_E_CHUNK);

    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    assert_true(rfs_replay_play(&p, &r));
    c.u.chunk.offset = 0;
    c.u.chunk.n = 200;
    memset(c.u.chunk.bytes, 0xFF, 200);
    assert_true(rfs_replay_play(&p, &c));
    c.u.chunk.offset = 200;
    assert_true(rfs_replay_play(&p, &c));
    r = rec_at(RFS_REPLAY_STEP, 50000);
    out.n = 0;
    assert_true(rfs_replay_play(&p, &r));
    assert_true(p.started);
    /* OUT (18 bytes) + WHEEL_CMD and STATUS as CAN_TX (23 bytes each). */
    assert_int_equal(out.n, 18 + 23 + 23);
    assert_int_equal(out.b[0], 0x80);
    assert_int_equal(out.b[18], 0x82);
    assert_int_equal(out.b[18 + 10], 0x00); /* id 0x100 LE */
    assert_int_equal(out.b[18 + 11], 0x01);
    r = rec_at(RFS_REPLAY_CFG, 0);
    assert_false(rfs_replay_play(&p, &r));
    assert_int_equal(p.error, RFS_REPLAY_E_ORDER);

    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    r.type = RFS_REPLAY_OUT;
    assert_false(rfs_replay_play(&p, &r));
    assert_int_equal(p.error, RFS_REPLAY_E_ORDER);
}

/* The player sets cfg.seek.fit_early from every CFG: on with the flag, off without it
 * (a recording from before the flag, played over a base configuration with it on). */
static void test_player_applies_fit_early(void **state)
{
    (void)state;
    static rfs_app_t app;
    static rfs_replay_player_t p;
    static buf_sink_t out;
    rfs_app_cfg_t cfg = store_cfg();
    rfs_replay_rec_t c = rec_at(RFS_REPLAY_CFG, 0);
    c.u.cfg.fit_budget = 600;
    c.u.cfg.fit_early = true;
    rfs_replay_rec_t m = rec_at(RFS_REPLAY_MAP, 0);
    m.u.map.w = 80;
    m.u.map.h = 40;
    m.u.map.res = 6554;
    rfs_replay_rec_t f = rec_at(RFS_REPLAY_MAP_FREE, 0);
    f.u.chunk.n = 200;
    memset(f.u.chunk.bytes, 0xFF, 200);
    const rfs_replay_rec_t step = rec_at(RFS_REPLAY_STEP, 50000);

    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    assert_true(rfs_replay_play(&p, &c));
    assert_true(rfs_replay_play(&p, &m));
    assert_true(rfs_replay_play(&p, &f));
    f.u.chunk.offset = 200;
    assert_true(rfs_replay_play(&p, &f));
    assert_true(rfs_replay_play(&p, &step));

    assert_true(p.started);
    assert_true(app.cfg.seek.fit_early);
    assert_int_equal(app.cfg.seek.fit_budget, 600);

    cfg.seek.fit_early = true;
    c.u.cfg.fit_early = false;
    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    assert_true(p.cfg.seek.fit_early);
    assert_true(rfs_replay_play(&p, &c));
    assert_false(p.cfg.seek.fit_early);
}

/* RECEIVER: type 0x13, length 16, rx then the capture time, both i64 LE. */
static void test_receiver_record_exact_bytes_and_lengths(void **state)
{
    (void)state;
    rfs_replay_rec_t r = rec_at(RFS_REPLAY_RECEIVER, 0x0102030405060708LL);
    r.u.receiver_t_us = -2;
    const uint8_t want[18] = {0x13, 16,
                              0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,
                              0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
    rfs_replay_rec_t back;
    uint32_t used = 0;

    expect_exact_bytes(&r, want, 18, &back);

    assert_int_equal(back.type, RFS_REPLAY_RECEIVER);
    assert_true(back.t_us == 0x0102030405060708LL);
    assert_true(back.u.receiver_t_us == -2);
    roundtrip(&r);
    uint8_t shorter[17], longer[19];
    memcpy(shorter, want, 17);
    shorter[1] = 15;
    memcpy(longer, want, 18);
    longer[1] = 17;
    longer[18] = 0;
    assert_int_equal(rfs_replay_parse(shorter, 17, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "wrong record length for its type");
    assert_int_equal(rfs_replay_parse(longer, 19, &used, &back), RFS_REPLAY_BAD);
    assert_string_equal(back.error, "wrong record length for its type");
}

/* Play a dead zone: a 20 x 10 m room, 10 Hz poses at (5, 5) throughout, packets for the
 * first 2 s, then none; with `heartbeat` a RECEIVER record before every STEP. Returns the
 * STEPs from 2.2 s to 4 s whose output drives. */
static int play_dead_zone(bool heartbeat, rfs_replay_player_t *p, rfs_app_t *app, buf_sink_t *out)
{
    const rfs_app_cfg_t cfg = store_cfg();
    rfs_replay_rec_t r;
    rfs_replay_player_init(p, app, &cfg, sink, out);
    r = rec_at(RFS_REPLAY_MAP, 0);
    r.u.map.w = 200;
    r.u.map.h = 100;
    r.u.map.res = 6554; /* 0.1 m */
    assert_true(rfs_replay_play(p, &r));
    for (uint32_t off = 0; off < 25u * 100u; off += RFS_REPLAY_CHUNK) {
        r = rec_at(RFS_REPLAY_MAP_FREE, 0);
        r.u.chunk.offset = off;
        r.u.chunk.n = (uint8_t)(2500u - off < RFS_REPLAY_CHUNK ? 2500u - off : RFS_REPLAY_CHUNK);
        for (uint32_t i = 0; i < r.u.chunk.n; i++) {
            const uint32_t row = (off + i) / 25u, col = (off + i) % 25u;
            /* Free inside a one-cell border. */
            uint8_t v = 0xFF;
            if (row == 0u || row == 99u) {
                v = 0;
            } else if (col == 0u) {
                v = 0xFE;
            } else if (col == 24u) {
                v = 0x7F;
            }
            r.u.chunk.bytes[i] = v;
        }
        assert_true(rfs_replay_play(p, &r));
    }
    int moving = 0;
    for (int64_t t = 0; t < 4000000; t += 5000) {
        memset(&r, 0, sizeof r);
        if (t % 100000 == 0) {
            r.type = RFS_REPLAY_POSE;
            r.t_us = t;
            r.u.pose.t_us = t;
            r.u.pose.x = 5 * 65536;
            r.u.pose.y = 5 * 65536;
            assert_true(rfs_replay_play(p, &r));
        }
        if (t < 2000000) {
            r.type = RFS_REPLAY_RSSI;
            r.t_us = t;
            r.u.rssi.t_us = t;
            r.u.rssi.dbm = (int8_t)(-60 - (t / 5000) % 3);
            assert_true(rfs_replay_play(p, &r));
        }
        if (t % RFS_APP_PERIOD_US == 0) {
            if (heartbeat) {
                r.type = RFS_REPLAY_RECEIVER;
                r.t_us = t;
                r.u.receiver_t_us = t;
                assert_true(rfs_replay_play(p, &r));
            }
            r.type = RFS_REPLAY_STEP;
            r.t_us = t;
            out->n = 0;
            assert_true(rfs_replay_play(p, &r));
            if (t >= 2200000 && (app->last.left_mm_s != 0 || app->last.right_mm_s != 0)) {
                moving++;
            }
        }
    }
    return moving;
}

static void test_receiver_records_drive_through_a_dead_zone(void **state)
{
    (void)state;
    static rfs_app_t app;
    static rfs_replay_player_t p;
    static buf_sink_t out;

    const int with = play_dead_zone(true, &p, &app, &out);
    const uint32_t heard = app.stats.receiver;
    const int without = play_dead_zone(false, &p, &app, &out);

    /* 36 steps in [2.2, 4.0) s; the robot is held in place and never reaches its goal. */
    assert_int_equal(with, 36);
    assert_int_equal(heard, 80u);
    assert_int_equal(without, 0);
    assert_int_equal(app.stats.receiver, 0u);
    /* A RECEIVER record before the map is an input before the map. */
    const rfs_app_cfg_t cfg = store_cfg();
    rfs_replay_player_init(&p, &app, &cfg, sink, &out);
    rfs_replay_rec_t r = rec_at(RFS_REPLAY_RECEIVER, 0);
    assert_false(rfs_replay_play(&p, &r));
    assert_int_equal(p.error, RFS_REPLAY_E_NO_MAP);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_header_bytes_and_checks),
        cmocka_unit_test(test_pose_record_exact_bytes),
        cmocka_unit_test(test_out_and_can_exact_bytes),
        cmocka_unit_test(test_every_type_round_trips),
        cmocka_unit_test(test_malformed_records_are_rejected),
        cmocka_unit_test(test_cfg_fit_early_flag),
        cmocka_unit_test(test_random_bytes_never_overrun),
        cmocka_unit_test(test_player_errors),
        cmocka_unit_test(test_player_applies_fit_early),
        cmocka_unit_test(test_receiver_record_exact_bytes_and_lengths),
        cmocka_unit_test(test_receiver_records_drive_through_a_dead_zone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
