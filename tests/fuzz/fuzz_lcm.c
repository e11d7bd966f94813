/* fuzz_lcm - libFuzzer target for LCM message decoding (the lcm-gen decoders of the lcm/ types
 * and our checks in firmware/port/linux/lx_lcm.c). LCM on a robot is UDP multicast:
 * anyone on the network can publish any bytes on our channels, and logs are files.
 *
 * Input: byte 0 selects the path, the rest is the payload.
 *   byte 0 < 0x80: a message on channel (byte 0 mod 7), published on an in-process
 *                  memq:// connection and received through lx_lcm_handle() - the same
 *                  code path as a UDP message;
 *   byte 0 >= 0x80: the payload is an LCM log file, read with lx_lcm_log_next() (channel
 *                  names, lengths and times from the file).
 *
 * Beyond ASan/UBSan it checks what lx_lcm.h promises: every delivered message is in
 * range (pose heading in [-pi, pi], source 0..15, CAN id 11-bit and DLC 0..8, status
 * enums valid) and every drop is reported as one non-empty line.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_tmp.h"
#include "lx_lcm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void on_pose(void *ctx, const rfs_pose_t *p)
{
    (void)ctx;
    /* pi in Q16.16 is 205887.4; rounding may give 205888. */
    if (p->theta > 205888 || p->theta < -205888) { abort(); }
}

static void on_rssi(void *ctx, uint8_t src, int64_t t_us, int8_t dbm, uint32_t seq)
{
    (void)ctx;
    (void)t_us;
    (void)dbm;
    (void)seq;
    if (src >= RFS_CAN_MAX_SOURCES) { abort(); }
}

static void on_clock(void *ctx, int64_t t_us)
{
    (void)ctx;
    (void)t_us;
}

static void on_wheel(void *ctx, int64_t t_us, const rfs_can_wheel_t *w)
{
    (void)ctx;
    (void)t_us;
    if (w->flags & ~RFS_CAN_WHEEL_STOP) { abort(); }
}

static void on_status(void *ctx, int64_t t_us, const rfs_seek_out_t *o)
{
    (void)ctx;
    (void)t_us;
    if ((unsigned)o->state > RFS_SEEK_DRIVING || (unsigned)o->decision.kind > RFS_SEEK_TUMBLE ||
        (unsigned)o->decision.prev > RFS_DRIVE_BLOCKED) {
        abort();
    }
}

static void on_can(void *ctx, int64_t t_us, const rfs_can_frame_t *f)
{
    (void)ctx;
    (void)t_us;
    if (f->id > RFS_CAN_ID_MAX || f->dlc > 8u) { abort(); }
}

static void on_receiver(void *ctx, int64_t t_us, uint32_t seq)
{
    (void)ctx;
    (void)t_us;
    (void)seq;
}

static void on_bad(void *ctx, const char *why)
{
    (void)ctx;
    fuzz_check_err_line(why);
}

/* A delivered estimate passed the decoder's checks: residual and area not negative. */
static void on_estimate(void *ctx, int64_t t_us, const rfs_pathloss_est_t *est)
{
    (void)ctx;
    (void)t_us;
    if (est->rms < 0 || est->spread_m2 < 0) { abort(); }
}

static const lx_lcm_handlers_t k_h = {NULL,      on_pose, on_rssi, on_clock,    on_wheel,
                                      on_status, on_can,  on_bad,  on_receiver, on_estimate};
static lx_lcm_t *g_lcm;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const ch[7] = {LX_LCM_CH_POSE,   LX_LCM_CH_RSSI,         LX_LCM_CH_CLOCK,
                                      LX_LCM_CH_WHEEL,  LX_LCM_CH_STATUS,       LX_LCM_CH_CAN_FALLBACK,
                                      LX_LCM_CH_RSSI_STATUS};
    if (size < 1u) { return 0; }
    char err[256] = "";
    if (data[0] < 0x80u) {
        if (g_lcm == NULL) {
            g_lcm = lx_lcm_open("memq://", &k_h, err, sizeof err);
            if (g_lcm == NULL) {
                fprintf(stderr, "%s\n", err);
                abort();
            }
        }
        lx_lcm_stats_t before, after;
        lx_lcm_get_stats(g_lcm, &before);
        if (lx_lcm_pub_raw(g_lcm, 0, ch[data[0] % 7u], data + 1, size - 1u) != 0) { return 0; }
        int handled = 0;
        while (lx_lcm_handle(g_lcm, 0) == 1) { handled++; }
        lx_lcm_get_stats(g_lcm, &after);
        /* One message in, exactly one verdict out: delivered or dropped. */
        if (handled != 1 || (after.received - before.received) + (after.bad - before.bad) != 1u) { abort(); }
        if (after.bad != before.bad) { fuzz_check_err_line(after.last_error); }
        return 0;
    }
    const char *path = fuzz_tmp_write(0, "in.lcmlog", data + 1, size - 1u);
    lx_lcm_log_t *log = lx_lcm_log_open(path, "r", err, sizeof err);
    if (log == NULL) {
        fuzz_check_err_line(err);
        return 0;
    }
    lx_lcm_stats_t st;
    memset(&st, 0, sizeof st);
    int64_t t = 0;
    for (int i = 0; i < 64 && lx_lcm_log_next(log, &k_h, &st, &t) == 1; i++) {
    }
    (void)lx_lcm_log_close(log);
    return 0;
}
