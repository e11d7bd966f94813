/* test_lcm.c - the LCM adapter (firmware/port/linux/lx_lcm.h) over memq:// and log files. */
#include "rfs_test.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "lx_lcm.h"

typedef struct rx {
    rfs_pose_t pose;
    int poses;
    uint8_t src;
    int64_t rssi_t;
    int8_t dbm;
    uint32_t seq;
    int rssis;
    int64_t clock_t;
    int clocks;
    rfs_can_wheel_t wheel;
    int64_t wheel_t;
    rfs_seek_out_t status;
    int64_t status_t;
    int statuses;
    rfs_can_frame_t frame;
    int frames;
    char bad[200];
    int bads;
    int64_t rx_t;
    uint32_t rx_seq;
    int rxs;
    rfs_pathloss_est_t est;
    int64_t est_t;
    int ests;
} rx_t;

static void on_pose(void *c, const rfs_pose_t *p) { rx_t *r = c; r->pose = *p; r->poses++; }
static void on_rssi(void *c, uint8_t s, int64_t t, int8_t d, uint32_t q)
{
    rx_t *r = c;
    r->src = s, r->rssi_t = t, r->dbm = d, r->seq = q, r->rssis++;
}
static void on_clock(void *c, int64_t t) { rx_t *r = c; r->clock_t = t; r->clocks++; }
static void on_wheel(void *c, int64_t t, const rfs_can_wheel_t *w) { rx_t *r = c; r->wheel = *w; r->wheel_t = t; }
static void on_status(void *c, int64_t t, const rfs_seek_out_t *o) { rx_t *r = c; r->status = *o; r->status_t = t; r->statuses++; }
static void on_can(void *c, int64_t t, const rfs_can_frame_t *f) { (void)t; rx_t *r = c; r->frame = *f; r->frames++; }
static void on_bad(void *c, const char *why)
{
    rx_t *r = c;
    snprintf(r->bad, sizeof r->bad, "%s", why);
    r->bads++;
}

static void on_receiver(void *c, int64_t t, uint32_t q) { rx_t *r = c; r->rx_t = t; r->rx_seq = q; r->rxs++; }
static void on_estimate(void *c, int64_t t, const rfs_pathloss_est_t *e) { rx_t *r = c; r->est = *e; r->est_t = t; r->ests++; }

static lx_lcm_handlers_t handlers(rx_t *r)
{
    lx_lcm_handlers_t h = {r,      on_pose, on_rssi,     on_clock,   on_wheel,
                           on_status, on_can, on_bad, on_receiver, on_estimate};
    return h;
}

static lx_lcm_t *open_memq(rx_t *r)
{
    memset(r, 0, sizeof *r);
    lx_lcm_handlers_t h = handlers(r);
    char err[200];
    lx_lcm_t *l = lx_lcm_open("memq://", &h, err, sizeof err);
    assert_non_null(l);
    return l;
}

static void drain(lx_lcm_t *l)
{
    while (lx_lcm_handle(l, 0) == 1) {
    }
}

/* Record everything l publishes and receives into a new temporary log at path (a
 * mkstemp template, filled in). */
static lx_lcm_log_t *record_to_temp(lx_lcm_t *l, char *path)
{
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    char err[200];
    lx_lcm_log_t *log = lx_lcm_log_open(path, "w", err, sizeof err);
    assert_non_null(log);
    lx_lcm_record(l, log);
    return log;
}

static void pose_round_trips_exactly_and_heading_is_normalised(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    rfs_pose_t p = {-123456789012LL, -2147418112 /* -32767 m */, 98305, -205887};

    assert_int_equal(lx_lcm_pub_pose(l, &p), 0);
    drain(l);

    assert_int_equal(r.poses, 1);
    assert_int_equal(r.pose.t_us, -123456789012LL);
    assert_int_equal(r.pose.x, -2147418112);
    assert_int_equal(r.pose.y, 98305);
    assert_int_equal(r.pose.theta, -205887);
    /* 4 rad wraps to 4 - 2 pi (double-precision reference). */
    rfs_pose_t q = {1, 0, 0, 4 * 65536};
    lx_lcm_pub_pose(l, &q);
    drain(l);
    assert_int_equal(r.pose.theta, (int32_t)llround((4.0 - 2.0 * M_PI) * 65536.0));
    lx_lcm_close(l);
}

static void every_type_round_trips(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    rfs_can_wheel_t w = {-32768, 32767, RFS_CAN_WHEEL_STOP};
    rfs_seek_out_t o;
    memset(&o, 0, sizeof o);
    o.left_mm_s = -5;
    o.right_mm_s = 7;
    o.state = RFS_SEEK_DRIVING;
    o.faults = 0x0301;
    o.decided = true;
    o.decision.iteration = 12;
    o.decision.t_us = 987654321;
    o.decision.kind = RFS_SEEK_GREEDY;
    o.decision.relearned = true;
    o.decision.mean_valid = true;
    o.decision.prev = RFS_DRIVE_TIMEOUT;
    o.decision.prediction = -3932161;
    o.decision.mean = -4000000;
    o.decision.epsilon = 32768;
    o.decision.goal_x = 1;
    o.decision.max_y = -1;
    o.decision.path_len = 655360;
    o.decision.samples = 10000;
    rfs_can_frame_t f = {0x120, 8, {1, 2, 3, 4, 5, 6, 7, 8}};

    lx_lcm_pub_rssi(l, 15, 42, -128, 0xFFFFFFFFu);
    lx_lcm_pub_clock(l, 50000);
    lx_lcm_pub_wheel(l, 60000, &w);
    lx_lcm_pub_status(l, 70000, &o);
    lx_lcm_pub_can(l, 80000, &f);
    drain(l);

    assert_int_equal(r.src, 15);
    assert_int_equal(r.rssi_t, 42);
    assert_int_equal(r.dbm, -128);
    assert_int_equal(r.seq, 0xFFFFFFFFu);
    assert_int_equal(r.clock_t, 50000);
    assert_int_equal(r.wheel.left_mm_s, -32768);
    assert_int_equal(r.wheel.right_mm_s, 32767);
    assert_int_equal(r.wheel.flags, RFS_CAN_WHEEL_STOP);
    assert_int_equal(r.status_t, 70000);
    const rfs_seek_decision_t *a = &r.status.decision, *b = &o.decision;
    assert_int_equal(a->iteration, b->iteration);
    assert_int_equal(a->t_us, b->t_us);
    assert_int_equal(a->kind, b->kind);
    assert_int_equal(a->relearned, b->relearned);
    assert_int_equal(a->line_search, b->line_search);
    assert_int_equal(a->model_valid, b->model_valid);
    assert_int_equal(a->mean_valid, b->mean_valid);
    assert_int_equal(a->prev, b->prev);
    assert_int_equal(a->prediction, b->prediction);
    assert_int_equal(a->mean, b->mean);
    assert_int_equal(a->epsilon, b->epsilon);
    assert_int_equal(a->x, b->x);
    assert_int_equal(a->y, b->y);
    assert_int_equal(a->goal_x, b->goal_x);
    assert_int_equal(a->goal_y, b->goal_y);
    assert_int_equal(a->max_x, b->max_x);
    assert_int_equal(a->max_y, b->max_y);
    assert_int_equal(a->path_len, b->path_len);
    assert_int_equal(a->samples, b->samples);
    assert_int_equal(r.status.faults, 0x0301);
    assert_int_equal(r.status.state, RFS_SEEK_DRIVING);
    assert_true(r.status.decided);
    assert_int_equal(r.frames, 1);
    assert_int_equal(r.frame.id, 0x120);
    assert_int_equal(r.frame.dlc, 8);
    assert_memory_equal(r.frame.data, f.data, 8);
    lx_lcm_stats_t st;
    lx_lcm_get_stats(l, &st);
    assert_int_equal(st.received, 5);
    assert_int_equal(st.bad, 0);
    lx_lcm_close(l);
}

/* Each decision flag alone, and plan_wait at its ends: a dropped or swapped field shows. */
static void decision_flags_round_trip_one_at_a_time(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    for (int k = 0; k < 7; k++) {
        rfs_seek_out_t o;
        memset(&o, 0, sizeof o);
        o.decided = true;
        o.decision.kind = k == 0 ? RFS_SEEK_EPSILON : RFS_SEEK_GREEDY;
        o.decision.sampled = k == 0;
        o.decision.near = k == 1;
        o.decision.hedged = k == 2;
        o.decision.pinned = k == 3;
        o.decision.refuted = k == 4;
        o.decision.plan_wait = k == 5 ? 65535u : k == 6 ? 1u : 0u;
        assert_int_equal(lx_lcm_pub_status(l, 1000 + k, &o), 0);
        drain(l);
        assert_int_equal(r.statuses, k + 1);
        const rfs_seek_decision_t *a = &r.status.decision;
        assert_int_equal(a->sampled, k == 0);
        assert_int_equal(a->near, k == 1);
        assert_int_equal(a->hedged, k == 2);
        assert_int_equal(a->pinned, k == 3);
        assert_int_equal(a->refuted, k == 4);
        assert_int_equal(a->plan_wait, k == 5 ? 65535u : k == 6 ? 1u : 0u);
    }
    assert_int_equal(r.bads, 0);
    lx_lcm_close(l);
}

static void malformed_messages_are_dropped_and_described(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    const uint8_t junk[7] = {0xDE, 0xAD, 0xBE, 0xEF, 0, 1, 2};

    lx_lcm_pub_raw(l, 0, LX_LCM_CH_POSE, junk, sizeof junk);
    lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, junk, 0);
    drain(l);

    assert_int_equal(r.poses, 0);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 2);
    assert_string_equal(r.bad, "RFS_SEEKER_STATUS: truncated, oversized or not an rfseek.seeker_status_t (0 bytes)");
    lx_lcm_stats_t st;
    lx_lcm_get_stats(l, &st);
    assert_int_equal(st.bad, 2);
    assert_string_equal(st.last_error, r.bad);
    lx_lcm_close(l);
}

static void log_is_written_atomically_and_reads_back(void **state)
{
    (void)state;
    char path[] = "/tmp/rfs_test_lcm_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path);
    char err[200];
    lx_lcm_log_t *log = lx_lcm_log_open(path, "w", err, sizeof err);
    assert_non_null(log);
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    lx_lcm_record(l, log);
    rfs_pose_t p = {1000, 65536, -65536, 0};
    lx_lcm_pub_pose(l, &p);
    lx_lcm_pub_clock(l, 2000);
    drain(l); /* received messages are recorded too */
    lx_lcm_record(l, NULL);

    assert_int_equal(access(path, F_OK), -1); /* nothing at PATH before close */
    assert_int_equal(lx_lcm_log_close(log), 0);
    assert_int_equal(access(path, F_OK), 0);

    log = lx_lcm_log_open(path, "r", err, sizeof err);
    assert_non_null(log);
    rx_t back;
    memset(&back, 0, sizeof back);
    lx_lcm_handlers_t h = handlers(&back);
    int64_t t;
    int n = 0;
    while (lx_lcm_log_next(log, &h, NULL, &t) == 1) {
        n++;
    }
    lx_lcm_log_close(log);
    unlink(path);
    lx_lcm_close(l);
    assert_int_equal(n, 4); /* 2 published + 2 received */
    assert_int_equal(back.poses, 2);
    assert_int_equal(back.pose.x, 65536);
    assert_int_equal(back.pose.y, -65536);
    assert_int_equal(back.clocks, 2);
    assert_int_equal(back.clock_t, 2000);
}

static void bad_url_and_unreadable_log_give_one_line(void **state)
{
    (void)state;
    char err[200];
    lx_lcm_t *l = lx_lcm_open("nosuch://x", NULL, err, sizeof err);
    assert_null(l);
    assert_string_equal(err, "lcm: nosuch://x: cannot open this provider (bad URL, no multicast route, or no file)"
                             " (liblcm: Error: LCM provider \"nosuch\" not found)");
    lx_lcm_log_t *g = lx_lcm_log_open("/nonexistent/dir/x.lcmlog", "r", err, sizeof err);
    assert_null(g);
    assert_string_equal(err, "/nonexistent/dir/x.lcmlog: cannot open for reading");
}

/* A file:// log is read whole before liblcm plays it (read mode: the default, or mode=r):
 * garbage is one line naming the offset; a log opened for writing is not read. */
static void damaged_file_url_is_one_line(void **state)
{
    (void)state;
    char path[] = "/tmp/rfs_test_lcm_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "hello", 5), 5);
    close(fd);
    char url[128], want[256], err[256];
    const char *opts[2] = {"?speed=0", "?mode=r&speed=0"};
    for (int k = 0; k < 2; k++) {
        snprintf(url, sizeof url, "file://%s%s", path, opts[k]);
        assert_null(lx_lcm_open(url, NULL, err, sizeof err));
        snprintf(want, sizeof want, "lcm: %s: offset 0: not an LCM event (no sync word)", url);
        assert_string_equal(err, want);
    }
    snprintf(url, sizeof url, "file://%s?speed=0&mode=w", path);
    lx_lcm_t *l = lx_lcm_open(url, NULL, err, sizeof err);
    assert_non_null(l);
    assert_string_equal(err, "");
    lx_lcm_close(l);
    remove(path);
}

/* The reason string's length in a seeker_status_t lies at byte 39 (the .lcm's field order:
 * fingerprint 8, utime 8, state 1, faults 4, left 2, right 2, decided 1, iteration 4,
 * decision_utime 8, kind 1). A message stating 2^31 - 1 bytes there, or cut after the
 * string, is dropped with one line: lcm-gen's decoder malloc'd the stated length and leaked
 * the string when a later field was cut (found by fuzz_lcm; the ASan build sees leaks). */
static void status_string_length_checked_before_decoding(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    char path[] = "/tmp/rfs_test_lcm_XXXXXX";
    char err[200];
    lx_lcm_log_t *log = record_to_temp(l, path);
    rfs_seek_out_t o;
    memset(&o, 0, sizeof o);
    o.decision.kind = RFS_SEEK_GREEDY;
    assert_int_equal(lx_lcm_pub_status(l, 1000, &o), 0);
    drain(l);
    lx_lcm_record(l, NULL);
    assert_int_equal(lx_lcm_log_close(log), 0);
    assert_int_equal(r.statuses, 1);

    log = lx_lcm_log_open(path, "r", err, sizeof err);
    assert_non_null(log);
    int64_t t;
    char ch[32];
    uint8_t msg[512];
    size_t len = 0;
    assert_int_equal(lx_lcm_log_next_raw(log, &t, ch, sizeof ch, msg, sizeof msg, &len), 1);
    assert_int_equal(lx_lcm_log_close(log), 0);
    remove(path);
    assert_string_equal(ch, LX_LCM_CH_STATUS);
    assert_true(len > 50 && len < sizeof msg);
    assert_memory_equal(msg + 39, "\0\0\0\7greedy", 11);

    char want[160];
    snprintf(want, sizeof want, "RFS_SEEKER_STATUS: truncated, oversized or not an rfseek.seeker_status_t (%zu bytes)", len);
    memcpy(msg + 39, "\x7f\xff\xff\xff", 4);
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, msg, len), 0);
    drain(l);
    assert_int_equal(r.bads, 1);
    assert_string_equal(r.bad, want);
    memcpy(msg + 39, "\0\0\0\7", 4);
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, msg, 39 + 4 + 7 + 1), 0);
    drain(l);
    assert_int_equal(r.bads, 2);
    assert_int_equal(r.statuses, 1);
    lx_lcm_close(l);
}

/* Every decision kind, the baseline strategies' too (rfseekd runs them), round trips with
 * its name in the reason string (byte 38 holds the kind, 39 the reason's length); one past
 * the last kind is dropped as out of range. */
static void every_decision_kind_round_trips_with_its_reason(void **state)
{
    (void)state;
    static const char *const names[] = {"none", "initial", "greedy", "epsilon",
                                        "probe", "gradient", "run", "tumble"};
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    char path[] = "/tmp/rfs_test_lcm_XXXXXX";
    char err[200];
    lx_lcm_log_t *log = record_to_temp(l, path);
    for (int k = 0; k < 8; k++) {
        rfs_seek_out_t o;
        memset(&o, 0, sizeof o);
        o.decision.kind = (rfs_seek_kind_t)k;
        o.decision.relearned = true;
        assert_int_equal(lx_lcm_pub_status(l, 1000 + k, &o), 0);
        drain(l);
        assert_int_equal(r.statuses, k + 1);
        assert_int_equal(r.status.decision.kind, k);
        assert_true(r.status.decision.relearned);
    }
    lx_lcm_record(l, NULL);
    assert_int_equal(lx_lcm_log_close(log), 0);
    assert_int_equal(r.bads, 0);

    log = lx_lcm_log_open(path, "r", err, sizeof err);
    assert_non_null(log);
    uint8_t last[512];
    size_t last_len = 0;
    int k = 0;
    int64_t t, prev_t = -1;
    char ch[32];
    size_t len = 0;
    /* The log holds each message as published and as received: one of each time. */
    while (lx_lcm_log_next_raw(log, &t, ch, sizeof ch, last, sizeof last, &len) == 1) {
        if (t == prev_t) {
            continue;
        }
        prev_t = t;
        assert_string_equal(ch, LX_LCM_CH_STATUS);
        assert_int_equal(t, 1000 + k);
        char want[40];
        const int n = snprintf(want, sizeof want, "%s+relearn", names[k]);
        assert_int_equal(last[38], k);
        assert_memory_equal(last + 39, "\0\0\0", 3); /* the reason's big-endian length */
        assert_int_equal(last[42], n + 1);          /* with its terminating zero */
        assert_memory_equal(last + 43, want, (size_t)n + 1u);
        last_len = len;
        k++;
    }
    assert_int_equal(k, 8);
    assert_int_equal(lx_lcm_log_close(log), 0);
    remove(path);
    last[38] = 8; /* one past RFS_SEEK_TUMBLE */
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, last, last_len), 0);
    drain(l);
    assert_int_equal(r.statuses, 8);
    assert_int_equal(r.bads, 1);
    assert_string_equal(r.bad, "RFS_SEEKER_STATUS: a field is out of range or not finite (state 0)");
    lx_lcm_close(l);
}

/* plan_wait outside 0..65535 on the wire (the decoder's range, the field's uint16) is
 * dropped as out of range: the field is found in the published bytes by its neighbours
 * (flags 1 0 1 0 1, then big-endian 0x1234) and rewritten. */
static void status_plan_wait_out_of_range_is_dropped(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    char path[] = "/tmp/rfs_test_lcm_XXXXXX";
    char err[200];
    lx_lcm_log_t *log = record_to_temp(l, path);
    rfs_seek_out_t o;
    memset(&o, 0, sizeof o);
    o.decision.sampled = true;
    o.decision.hedged = true;
    o.decision.refuted = true;
    o.decision.plan_wait = 0x1234u;
    assert_int_equal(lx_lcm_pub_status(l, 5000, &o), 0);
    drain(l);
    lx_lcm_record(l, NULL);
    assert_int_equal(lx_lcm_log_close(log), 0);
    assert_int_equal(r.statuses, 1);
    log = lx_lcm_log_open(path, "r", err, sizeof err);
    assert_non_null(log);
    uint8_t msg[512];
    size_t len = 0;
    int64_t t;
    char ch[32];
    assert_int_equal(lx_lcm_log_next_raw(log, &t, ch, sizeof ch, msg, sizeof msg, &len), 1);
    assert_int_equal(lx_lcm_log_close(log), 0);
    remove(path);
    static const uint8_t mark[] = {1, 0, 1, 0, 1, 0x00, 0x00, 0x12, 0x34};
    size_t at = SIZE_MAX;
    for (size_t i = 0; i + sizeof mark <= len; i++) {
        if (memcmp(msg + i, mark, sizeof mark) == 0) {
            assert_int_equal(at, SIZE_MAX); /* found once */
            at = i + 5u;
        }
    }
    assert_true(at != SIZE_MAX);
    static const uint8_t bad[2][4] = {{0x00, 0x01, 0x00, 0x00}, {0xFF, 0xFF, 0xFF, 0xFF}}; /* 65536, -1 */
    for (int k = 0; k < 2; k++) {
        memcpy(msg + at, bad[k], 4);
        assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, msg, len), 0);
        drain(l);
        assert_int_equal(r.statuses, 1);
        assert_int_equal(r.bads, k + 1);
        assert_string_equal(r.bad, "RFS_SEEKER_STATUS: a field is out of range or not finite (state 0)");
    }
    lx_lcm_close(l);
}

/* A status's path-loss estimate reaches on_estimate after on_status, value for value
 * (Q16.16 through the message's doubles exactly); a status without one calls only
 * on_status. */
static void status_estimate_reaches_its_handler(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    rfs_seek_out_t o;
    memset(&o, 0, sizeof o);
    o.decision.kind = RFS_SEEK_GREEDY;
    rfs_pathloss_est_t e;
    memset(&e, 0, sizeof e);
    e.sx = 1802240;   /* 27.5 m */
    e.sy = -745472;   /* -11.375 m */
    e.n = 196609;     /* 3 + 2^-16 */
    e.w = 327680;     /* 5 dB */
    e.p0 = -2621441;  /* -40 dB - 2^-16 */
    e.rms = 65536 * 3 + 1;
    e.spread_m2 = 65536 * 12;
    assert_int_equal(lx_lcm_pub_status_est(l, 5000, &o, &e, NULL), 0);
    drain(l);
    assert_int_equal(r.statuses, 1);
    assert_int_equal(r.ests, 1);
    assert_int_equal(r.est_t, 5000);
    assert_int_equal(r.est.sx, e.sx);
    assert_int_equal(r.est.sy, e.sy);
    assert_int_equal(r.est.n, e.n);
    assert_int_equal(r.est.w, e.w);
    assert_int_equal(r.est.p0, e.p0);
    assert_int_equal(r.est.rms, e.rms);
    assert_int_equal(r.est.spread_m2, e.spread_m2);
    assert_int_equal(lx_lcm_pub_status(l, 6000, &o), 0);
    drain(l);
    assert_int_equal(r.statuses, 2);
    assert_int_equal(r.ests, 1);
    lx_lcm_close(l);
}

/* RFS_RSSI_STATUS. Reference bytes from the LCM wire format computed in Python
 * (tests/fuzz/make_corpus.py's lcm_hash of {int64_t utime, int32_t seq} = 0xc77a89abfd4c5ba6,
 * then utime and seq big-endian): utime -5,000,000,123, seq -7. */
static void receiver_status_matches_reference_bytes_and_rejects_others(void **state)
{
    (void)state;
    const uint8_t ref[20] = {0xc7, 0x7a, 0x89, 0xab, 0xfd, 0x4c, 0x5b, 0xa6, 0xff, 0xff,
                             0xff, 0xfe, 0xd5, 0xfa, 0x0d, 0x85, 0xff, 0xff, 0xff, 0xf9};
    rx_t r;
    lx_lcm_t *l = open_memq(&r);

    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_RSSI_STATUS, ref, sizeof ref), 0);
    drain(l);
    assert_int_equal(r.rxs, 1);
    assert_true(r.rx_t == -5000000123LL);
    assert_int_equal(r.rx_seq, 0xFFFFFFF9u);
    assert_int_equal(lx_lcm_pub_receiver(l, 1700000000123456LL, 41u), 0);
    drain(l);
    assert_int_equal(r.rxs, 2);
    assert_true(r.rx_t == 1700000000123456LL);
    assert_int_equal(r.rx_seq, 41u);

    /* A clock_t (fingerprint 0x4d0d41c1f105b12f, one int64) on the heartbeat channel, a
     * truncated and an over-long heartbeat: dropped with one line each, nothing delivered. */
    const uint8_t clk[16] = {0x4d, 0x0d, 0x41, 0xc1, 0xf1, 0x05, 0xb1, 0x2f, 0, 0, 0, 0, 0, 0, 0, 1};
    uint8_t longer[21];
    memcpy(longer, ref, sizeof ref);
    longer[20] = 0;
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_RSSI_STATUS, clk, sizeof clk), 0);
    drain(l);
    assert_string_equal(r.bad, "RFS_RSSI_STATUS: truncated, oversized or not an rfseek.rssi_status_t (16 bytes)");
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_RSSI_STATUS, ref, 19), 0);
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_RSSI_STATUS, longer, sizeof longer), 0);
    drain(l);
    assert_string_equal(r.bad, "RFS_RSSI_STATUS: truncated, oversized or not an rfseek.rssi_status_t (21 bytes)");
    assert_int_equal(r.bads, 3);
    assert_int_equal(r.rxs, 2);
    lx_lcm_stats_t st;
    lx_lcm_get_stats(l, &st);
    assert_int_equal(st.received, 2);
    assert_int_equal(st.bad, 3);
    lx_lcm_close(l);
}

static volatile sig_atomic_t g_alarms;

static void on_alarm(int sig)
{
    (void)sig;
    g_alarms++;
}

/* A signal during the wait (SIGTERM to rfseekd) is a timeout, not an LCM error: the
 * caller's loop then sees its stop flag. The handler is installed without SA_RESTART, as
 * signal handlers that set a stop flag are. */
static void signal_during_wait_is_a_timeout(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigemptyset(&sa.sa_mask);
    assert_int_equal(sigaction(SIGALRM, &sa, &old), 0);
    const struct itimerval it = {{0, 0}, {0, 20000}}; /* once, after 20 ms */
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(setitimer(ITIMER_REAL, &it, NULL), 0);

    const int rc = lx_lcm_handle(l, 2000);

    clock_gettime(CLOCK_MONOTONIC, &t1);
    const double waited = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    assert_int_equal(rc, 0);
    assert_int_equal(g_alarms, 1);
    assert_true(waited < 1.0); /* returned at the signal, not at the 2 s timeout */
    assert_int_equal(sigaction(SIGALRM, &old, NULL), 0);
    lx_lcm_close(l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pose_round_trips_exactly_and_heading_is_normalised),
        cmocka_unit_test(every_type_round_trips),
        cmocka_unit_test(decision_flags_round_trip_one_at_a_time),
        cmocka_unit_test(malformed_messages_are_dropped_and_described),
        cmocka_unit_test(log_is_written_atomically_and_reads_back),
        cmocka_unit_test(bad_url_and_unreadable_log_give_one_line),
        cmocka_unit_test(damaged_file_url_is_one_line),
        cmocka_unit_test(status_string_length_checked_before_decoding),
        cmocka_unit_test(every_decision_kind_round_trips_with_its_reason),
        cmocka_unit_test(status_plan_wait_out_of_range_is_dropped),
        cmocka_unit_test(status_estimate_reaches_its_handler),
        cmocka_unit_test(receiver_status_matches_reference_bytes_and_rejects_others),
        cmocka_unit_test(signal_during_wait_is_a_timeout),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
