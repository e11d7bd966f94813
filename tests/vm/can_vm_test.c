/* can_vm_test.c - our side of the SocketCAN test, run on vcan0 inside a qemu
 * VM with Debian's kernel (or natively where the host has vcan). Statically linked.
 *
 *   can_vm_test send IFACE EXPECT   encode and send a fixed scenario; write the frames to
 *                                   EXPECT as a candump -L log (lx_candump, our clock)
 *   can_vm_test recv IFACE NOW_US   receive every standard frame (no id filter) until
 *                                   1.5 s of silence, decode with rfs_can_rx at NOW_US and
 *                                   print one line per delivered frame, then STATS
 *   can_vm_test faults IFACE        interface down/up, injected bus-off and restart, a
 *                                   missing interface: PASS/FAIL lines
 * The shell side (tests/vm/can_inner.sh) compares candump's log and the printed lines
 * with references computed independently (tests/vm/vm_frames.py).
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lx_can.h"
#include "lx_candump.h"
#include "rfs_can.h"

static const uint32_t our_ids[] = {RFS_CAN_ID_WHEEL_CMD, RFS_CAN_ID_POSE_XY, RFS_CAN_ID_POSE_TH, RFS_CAN_ID_RSSI,
                                   RFS_CAN_ID_STATUS, RFS_CAN_ID_RX_STATUS};
#define N_OUR_IDS (sizeof our_ids / sizeof our_ids[0])

static void usage(FILE *o)
{
    fprintf(o, "usage: can_vm_test send IFACE EXPECT | recv IFACE NOW_US | faults IFACE\n"
               "SocketCAN test driver for rfseek's CAN protocol (see tests/vm/README in docs/CAN.md).\n");
}

static void nap_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static int do_send(const char *ifname, const char *expect)
{
    char err[256];
    lx_can_t *c = lx_can_open(ifname, our_ids, N_OUR_IDS, err, sizeof err);
    if (!c) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_can_frame_t fr[16];
    unsigned n = 0;
    const int64_t t0 = 4294967296LL - 150000; /* crosses the 32-bit wrap */
    for (int i = 0; i < 2; i++) {
        rfs_pose_t core = {t0 + i * 100000, 98304 * (i + 1), -163840 + 6554 * i, 102944 - 51472 * i};
        rfs_can_pose_t p = rfs_can_pose_from_core(&core);
        rfs_can_tx_pose(&tx, &p, &fr[n], &fr[n + 1]);
        n += 2;
    }
    for (int i = 0; i < 3; i++) {
        rfs_can_rssi_t r = {(uint8_t)i, (int8_t)(-40 - 20 * i), (uint8_t)(254 + i), rfs_can_wrap_time(t0 + 5000 * i)};
        rfs_can_tx_rssi(&tx, &r, &fr[n++]);
    }
    const int16_t sp[3][2] = {{-32768, 32767}, {700, -700}, {0, 0}};
    for (int i = 0; i < 3; i++) {
        rfs_can_wheel_t w = {sp[i][0], sp[i][1], (uint8_t)(i == 2 ? RFS_CAN_WHEEL_STOP : 0)};
        rfs_can_tx_wheel(&tx, &w, &fr[n++]);
    }
    for (int i = 0; i < 2; i++) {
        rfs_can_status_t s = {(uint8_t)(3 - i), (uint8_t)(2 + i), (uint8_t)(2 + 2 * i), i == 0, i == 1,
                              (uint8_t)(i ? 0x0F : 0), i ? 0xFFFFFFFFu : 7u, i == 1};
        rfs_can_tx_status(&tx, &s, &fr[n++]);
    }
    for (int i = 0; i < 2; i++) { /* receiver heartbeats, across the wrap */
        rfs_can_receiver_t r = {rfs_can_wrap_time(t0 + 100000 * i)};
        rfs_can_tx_receiver(&tx, &r, &fr[n++]);
    }
    char tmp[512];
    snprintf(tmp, sizeof tmp, "%s.tmp", expect);
    FILE *o = fopen(tmp, "w");
    if (!o) {
        fprintf(stderr, "can_vm_test: %s: cannot write\n", tmp);
        lx_can_close(c);
        return 1;
    }
    int bad = 0;
    for (unsigned i = 0; i < n; i++) {
        if (lx_can_send(c, &fr[i]) != 0) {
            lx_can_health_t h;
            lx_can_health(c, &h);
            fprintf(stderr, "can_vm_test: send %u failed (errno %d)\n", i, h.last_errno);
            bad = 1;
        }
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        char line[LX_CANDUMP_FMT_MAX];
        fputs(lx_candump_format(line, sizeof line, (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000, ifname, &fr[i])
                  ? line : "(format failed)\n", o);
        nap_ms(2); /* keep within vcan's default tx queue */
    }
    fclose(o);
    rename(tmp, expect);
    lx_can_close(c);
    return bad;
}

static int do_recv(const char *ifname, int64_t now_us)
{
    char err[256];
    lx_can_t *c = lx_can_open(ifname, NULL, 0, err, sizeof err);
    if (!c) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    rfs_can_rx_t rx;
    rfs_can_rx_cfg_t cfg = rfs_can_rx_cfg_default();
    rfs_can_rx_init(&rx, &cfg);
    int timeout = 8000;
    unsigned delivered = 0;
    for (;;) {
        rfs_can_frame_t f;
        int r = lx_can_recv(c, &f, timeout);
        if (r <= 0) {
            break;
        }
        timeout = 1500;
        delivered++;
        rfs_can_msg_t m;
        rfs_can_err_t e = rfs_can_rx_frame(&rx, &f, now_us, &m);
        if (e != RFS_CAN_OK) {
            printf("DROP %s\n", rfs_can_err_str(e));
            continue;
        }
        switch (m.kind) {
        case RFS_CAN_MSG_NONE:
            printf("NONE\n");
            break;
        case RFS_CAN_MSG_POSE:
            printf("POSE t=%" PRId64 " x=%" PRId32 " y=%" PRId32 " th=%" PRId32 "\n", m.pose.t_us, m.pose.x, m.pose.y,
                   m.pose.theta);
            break;
        case RFS_CAN_MSG_RSSI:
            printf("RSSI src=%u dbm=%d seq=%u t=%" PRId64 "\n", m.rssi_src, m.rssi_dbm, m.rssi_seq, m.rssi_t_us);
            break;
        case RFS_CAN_MSG_WHEEL:
            printf("WHEEL left=%d right=%d flags=%u\n", m.wheel.left_mm_s, m.wheel.right_mm_s, m.wheel.flags);
            break;
        case RFS_CAN_MSG_RECEIVER:
            printf("RECEIVER t=%" PRId64 "\n", m.receiver_t_us);
            break;
        case RFS_CAN_MSG_STATUS:
            printf("STATUS state=%u kind=%u prev=%u relearned=%u line=%u configured=%u faults=%u iter=%" PRIu32 "\n",
                   m.status.state, m.status.kind, m.status.prev, m.status.relearned, m.status.line_search,
                   m.status.configured, m.status.faults, m.status.iteration);
            break;
        case RFS_CAN_MSG_CONFIG:
            printf("CONFIG target=%u fit_early=%u strategy=%u model=%u p0=%d seed=%" PRIu32 "\n", m.config.target,
                   m.config.fit_early, m.config.strategy, m.config.model, m.config.p0_min, m.config.seed);
            break;
        }
    }
    lx_can_health_t h;
    lx_can_health(c, &h);
    printf("STATS delivered=%u foreign=%" PRIu32 " dropped=%" PRIu32 " checksum=%" PRIu32 " rssi_jumps=%" PRIu32
           " seq_gaps=%" PRIu32 "\n",
           delivered, h.rx_foreign, rfs_can_rx_dropped_total(&rx), rx.dropped[RFS_CAN_E_CHECKSUM],
           rx.msg[RFS_CAN_IDX_RSSI].counter_jumps, rx.rssi_seq_gaps);
    lx_can_close(c);
    return 0;
}

static int check(int ok, const char *name, const char *detail)
{
    printf("%s %s%s%s\n", ok ? "PASS" : "FAIL", name, detail[0] ? ": " : "", detail);
    return ok ? 0 : 1;
}

static int do_faults(const char *ifname)
{
    int fails = 0;
    char err[256], cmd[256], d[256];
    lx_can_t *gone = lx_can_open("rfsnope0", our_ids, N_OUR_IDS, err, sizeof err);
    fails += check(gone == NULL && strstr(err, "rfsnope0: no such interface") != NULL, "can-missing-iface", err);
    lx_can_t *c = lx_can_open(ifname, our_ids, N_OUR_IDS, err, sizeof err);
    if (!c) {
        return check(0, "can-open", err);
    }
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_can_wheel_t w = {100, 100, 0};
    rfs_can_frame_t f;
    lx_can_health_t h;
    rfs_can_tx_wheel(&tx, &w, &f);
    fails += check(lx_can_send(c, &f) == 0, "can-send-up", "");

    snprintf(cmd, sizeof cmd, "ip link set %s down", ifname);
    if (system(cmd) != 0) {
        fails += check(0, "can-down", "ip link set down failed");
    }
    int r = lx_can_send(c, &f);
    lx_can_health(c, &h);
    snprintf(d, sizeof d, "send=%d link=%d errno=%d tx_failed=%" PRIu32, r, h.link, h.last_errno, h.tx_failed);
    fails += check(r == -1 && h.link == LX_CAN_LINK_DOWN && h.tx_failed == 1, "can-send-down-refused", d);
    r = lx_can_recv(c, &f, 50);
    fails += check(r == -1, "can-recv-down-reports", "");

    snprintf(cmd, sizeof cmd, "ip link set %s up", ifname);
    if (system(cmd) != 0) {
        fails += check(0, "can-up", "ip link set up failed");
    }
    nap_ms(1100); /* longer than the largest backoff */
    rfs_can_tx_wheel(&tx, &w, &f);
    r = lx_can_send(c, &f);
    lx_can_health(c, &h);
    snprintf(d, sizeof d, "send=%d link=%d recoveries=%" PRIu32, r, h.link, h.recoveries);
    fails += check(r == 0 && h.link == LX_CAN_LINK_OK && h.recoveries == 1, "can-recovers-after-up", d);

    /* Bus-off as a controller reports it: an error frame with CAN_ERR_BUSOFF (0x40). */
    snprintf(cmd, sizeof cmd, "cansend %s 20000040#0000000000000000", ifname);
    if (system(cmd) != 0) {
        fails += check(0, "can-inject-busoff", "cansend failed");
    }
    r = lx_can_recv(c, &f, 1); /* the error frame is already queued */
    lx_can_health(c, &h);
    snprintf(d, sizeof d, "recv=%d link=%d bus_off=%" PRIu32 " err_frames=%" PRIu32, r, h.link, h.bus_off, h.err_frames);
    fails += check(r == 0 && h.link == LX_CAN_LINK_BUS_OFF && h.bus_off == 1, "can-busoff-reported", d);
    rfs_can_tx_wheel(&tx, &w, &f);
    r = lx_can_send(c, &f);
    fails += check(r == -1, "can-busoff-send-backs-off", "");
    nap_ms(150);
    r = lx_can_send(c, &f);
    lx_can_health(c, &h);
    snprintf(d, sizeof d, "send=%d link=%d recoveries=%" PRIu32, r, h.link, h.recoveries);
    fails += check(r == 0 && h.link == LX_CAN_LINK_OK && h.recoveries == 2, "can-busoff-recovers", d);
    lx_can_close(c);
    return fails ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        usage(stdout);
        return 0;
    }
    if (argc == 4 && strcmp(argv[1], "send") == 0) {
        return do_send(argv[2], argv[3]);
    }
    if (argc == 4 && strcmp(argv[1], "recv") == 0) {
        char *end;
        long long now = strtoll(argv[3], &end, 10);
        if (*end != '\0') {
            fprintf(stderr, "can_vm_test: NOW_US '%s' is not an integer\n", argv[3]);
            return 2;
        }
        return do_recv(argv[2], now);
    }
    if (argc == 3 && strcmp(argv[1], "faults") == 0) {
        return do_faults(argv[2]);
    }
    usage(stderr);
    return 2;
}
