/* lcm_tool.c - test helper for rfseekd and the LCM adapter.
 *
 *   lcm_tool mklog OUT.lcmlog   write a crafted input log: 3 s of poses (10 Hz) and RSSI
 *                               (100 Hz) at the office map's start, RFS_CLOCK at 20 Hz for
 *                               4 s (inputs stop at 3 s), and at 1 s a truncated pose, a
 *                               pose with a NaN x, an RSSI from source 99, a clock message
 *                               on the pose channel, 5 bytes of garbage on RFS_RSSI and a
 *                               pose older than the newest; at 2 s a clock going backwards
 *   lcm_tool mkdeadzone OUT.lcmlog on|off
 *                               a radio dead zone: 4 s of poses (10 Hz) at the
 *                               office map's start, RSSI (100 Hz) only for the first 1 s,
 *                               RFS_CLOCK at 20 Hz; with "on" a receiver heartbeat
 *                               (RFS_RSSI_STATUS) just before every clock tick (81) and
 *                               5 bytes of garbage on RFS_RSSI_STATUS at 2 s
 *   lcm_tool dump LOG           print each status in a log as
 *                               "STATUS t state left right faults decided"
 *   lcm_tool pose URL SECONDS   a live pose source: the office map's start (8 m, 6 m,
 *                               0 rad) on URL at 20 Hz for SECONDS, stamped with the
 *                               local clock (CLOCK_REALTIME, as rfseekd's live steps)
 */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lx_lcm.h"

static int mklog(const char *out)
{
    char err[256];
    char tmpl_path[600];
    snprintf(tmpl_path, sizeof tmpl_path, "%s.tmpl", out);
    /* 1. Valid encodings of each type, to corrupt below. */
    lx_lcm_log_t *tl = lx_lcm_log_open(tmpl_path, "w", err, sizeof err);
    lx_lcm_t *l = lx_lcm_open("memq://", NULL, err, sizeof err);
    if (!tl || !l) {
        fprintf(stderr, "lcm_tool: %s\n", err);
        return 1;
    }
    lx_lcm_record(l, tl);
    rfs_pose_t p0 = {1000000, 8 * 65536, 6 * 65536, 0};
    lx_lcm_pub_pose(l, &p0);
    lx_lcm_pub_rssi(l, 0, 1000000, -60, 7);
    lx_lcm_pub_clock(l, 1000000);
    lx_lcm_record(l, NULL);
    lx_lcm_log_close(tl);
    uint8_t pose[256], rssi[256], clk[256];
    size_t npose, nrssi, nclk;
    char ch[64];
    int64_t t;
    tl = lx_lcm_log_open(tmpl_path, "r", err, sizeof err);
    if (!tl || lx_lcm_log_next_raw(tl, &t, ch, sizeof ch, pose, sizeof pose, &npose) != 1 ||
        lx_lcm_log_next_raw(tl, &t, ch, sizeof ch, rssi, sizeof rssi, &nrssi) != 1 ||
        lx_lcm_log_next_raw(tl, &t, ch, sizeof ch, clk, sizeof clk, &nclk) != 1) {
        fprintf(stderr, "lcm_tool: %s: cannot read the templates back\n", tmpl_path);
        return 1;
    }
    lx_lcm_log_close(tl);
    remove(tmpl_path);

    /* 2. The crafted run. LCM encodes big-endian: 8-byte fingerprint, then the fields. */
    lx_lcm_log_t *ol = lx_lcm_log_open(out, "w", err, sizeof err);
    if (!ol) {
        fprintf(stderr, "lcm_tool: %s\n", err);
        return 1;
    }
    lx_lcm_record(l, ol);
    for (int64_t t_us = 0; t_us <= 4000000; t_us += 5000) {
        if (t_us < 3000000 && t_us % 10000 == 0) {
            int8_t dbm = (int8_t)(-60 - (int)((t_us / 10000) % 7));
            lx_lcm_pub_rssi(l, 0, t_us, dbm, (uint32_t)(t_us / 10000));
        }
        if (t_us < 3000000 && t_us % 100000 == 0) {
            rfs_pose_t p = {t_us, 8 * 65536, 6 * 65536, 0};
            lx_lcm_pub_pose(l, &p);
        }
        if (t_us == 1000000) {
            uint8_t b[256];
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_POSE, pose, npose - 3); /* truncated */
            memcpy(b, pose, npose);
            const uint8_t nan_be[8] = {0x7F, 0xF8, 0, 0, 0, 0, 0, 0};
            memcpy(b + 16, nan_be, 8); /* x after fingerprint and utime */
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_POSE, b, npose);
            memcpy(b, rssi, nrssi);
            b[16] = 0;
            b[17] = 99; /* source, int16 after fingerprint and utime */
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_RSSI, b, nrssi);
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_POSE, clk, nclk); /* wrong type */
            const uint8_t junk[5] = {1, 2, 3, 4, 5};
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_RSSI, junk, sizeof junk);
            rfs_pose_t old = {500000, 8 * 65536, 6 * 65536, 0}; /* out of order */
            lx_lcm_pub_pose(l, &old);
        }
        if (t_us % 50000 == 0) {
            lx_lcm_pub_clock(l, t_us);
        }
        if (t_us == 2000000) {
            lx_lcm_pub_clock(l, 1000000); /* backwards */
        }
    }
    lx_lcm_close(l);
    if (lx_lcm_log_close(ol) != 0) {
        fprintf(stderr, "lcm_tool: %s: cannot finish the log\n", out);
        return 1;
    }
    return 0;
}

static int mkdeadzone(const char *out, bool heartbeat)
{
    char err[256];
    lx_lcm_t *l = lx_lcm_open("memq://", NULL, err, sizeof err);
    lx_lcm_log_t *ol = l ? lx_lcm_log_open(out, "w", err, sizeof err) : NULL;
    if (!ol) {
        fprintf(stderr, "lcm_tool: %s\n", err);
        lx_lcm_close(l);
        return 1;
    }
    lx_lcm_record(l, ol);
    for (int64_t t_us = 0; t_us <= 4000000; t_us += 5000) {
        if (t_us < 1000000 && t_us % 10000 == 0) {
            int8_t dbm = (int8_t)(-60 - (int)((t_us / 10000) % 7));
            lx_lcm_pub_rssi(l, 0, t_us, dbm, (uint32_t)(t_us / 10000));
        }
        if (t_us % 100000 == 0) {
            rfs_pose_t p = {t_us, 8 * 65536, 6 * 65536, 0};
            lx_lcm_pub_pose(l, &p);
        }
        if (heartbeat && t_us == 2000000) {
            const uint8_t junk[5] = {1, 2, 3, 4, 5};
            lx_lcm_pub_raw(l, t_us, LX_LCM_CH_RSSI_STATUS, junk, sizeof junk);
        }
        if (t_us % 50000 == 0) {
            if (heartbeat) {
                lx_lcm_pub_receiver(l, t_us, (uint32_t)(t_us / 50000));
            }
            lx_lcm_pub_clock(l, t_us);
        }
    }
    lx_lcm_close(l);
    if (lx_lcm_log_close(ol) != 0) {
        fprintf(stderr, "lcm_tool: %s: cannot finish the log\n", out);
        return 1;
    }
    return 0;
}

static void on_status(void *ctx, int64_t t_us, const rfs_seek_out_t *o)
{
    (void)ctx;
    printf("STATUS %" PRId64 " %d %d %d %u %d\n", t_us, (int)o->state, o->left_mm_s, o->right_mm_s, o->faults,
           o->decided);
}

static int dump(const char *path)
{
    char err[256];
    lx_lcm_log_t *lg = lx_lcm_log_open(path, "r", err, sizeof err);
    if (!lg) {
        fprintf(stderr, "lcm_tool: %s\n", err);
        return 1;
    }
    lx_lcm_handlers_t h;
    memset(&h, 0, sizeof h);
    h.on_status = on_status;
    lx_lcm_stats_t st;
    memset(&st, 0, sizeof st);
    int64_t t;
    while (lx_lcm_log_next(lg, &h, &st, &t) == 1) {
    }
    lx_lcm_log_close(lg);
    if (st.bad) {
        fprintf(stderr, "lcm_tool: %s: %u bad status messages (%s)\n", path, st.bad, st.last_error);
        return 1;
    }
    return 0;
}

static int64_t realtime_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static int pose_live(const char *url, const char *secs)
{
    char *end = NULL;
    const long n = strtol(secs, &end, 10);
    if (end == secs || *end != '\0' || n < 1 || n > 86400) {
        fprintf(stderr, "lcm_tool: pose: SECONDS '%s' is not 1..86400\n", secs);
        return 2;
    }
    char err[512];
    lx_lcm_t *l = lx_lcm_open(url, NULL, err, sizeof err);
    if (!l) {
        fprintf(stderr, "lcm_tool: %s\n", err);
        return 1;
    }
    for (long k = 0; k < n * 20; k++) {
        rfs_pose_t p = {realtime_us(), 8 * 65536, 6 * 65536, 0};
        if (lx_lcm_pub_pose(l, &p) != 0) {
            fprintf(stderr, "lcm_tool: pose: LCM refused a pose\n");
            lx_lcm_close(l);
            return 1;
        }
        const struct timespec tick = {0, 50000000};
        nanosleep(&tick, NULL);
    }
    lx_lcm_close(l);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "mklog") == 0) {
        return mklog(argv[2]);
    }
    if (argc == 4 && strcmp(argv[1], "mkdeadzone") == 0 &&
        (strcmp(argv[3], "on") == 0 || strcmp(argv[3], "off") == 0)) {
        return mkdeadzone(argv[2], strcmp(argv[3], "on") == 0);
    }
    if (argc == 3 && strcmp(argv[1], "dump") == 0) {
        return dump(argv[2]);
    }
    if (argc == 4 && strcmp(argv[1], "pose") == 0) {
        return pose_live(argv[2], argv[3]);
    }
    fprintf(argc == 2 && strcmp(argv[1], "--help") == 0 ? stdout : stderr,
            "usage: lcm_tool mklog OUT.lcmlog | lcm_tool mkdeadzone OUT.lcmlog on|off | lcm_tool dump LOG\n"
            "       lcm_tool pose URL SECONDS\n");
    return argc == 2 && strcmp(argv[1], "--help") == 0 ? 0 : 2;
}
