/* hs_ctrl_lcm.c - the simulator's separate-process controller (see hs_ctrl_lcm.h). */
#include "hs_ctrl_lcm.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lx_can.h"
#include "lx_err.h"
#include "lx_lcm.h"
#include "rfs_can.h"

typedef struct ctrl_lcm {
    hs_ctrl_lcm_cfg_t cfg;
    lx_lcm_t *lcm;
    lx_can_t *can;               /* NULL: wheel frames come over RFS_CAN_FALLBACK */
    rfs_can_rx_t rx;             /* the motor controller node's CAN receiver */
    uint32_t seq[RFS_CAN_MAX_SOURCES]; /* packet sequence numbers per source */
    uint32_t rx_seq;             /* receiver heartbeats published */
    rfs_can_wheel_t wheel;       /* newest wheel command */
    uint32_t wheels_rx;          /* wheel frames accepted */
    rfs_seek_out_t status;       /* newest status */
    int64_t status_t_us;         /* its step time */
    bool have_status;
    rfs_pathloss_est_t est;      /* the path-loss estimate the newest status carried */
    bool have_est;
    uint32_t timeouts;
} ctrl_lcm_t;

hs_ctrl_lcm_cfg_t hs_ctrl_lcm_cfg_default(void)
{
    hs_ctrl_lcm_cfg_t c = {NULL, NULL, 50000, 5000, NULL};
    return c;
}

static int64_t mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void on_frame(ctrl_lcm_t *s, const rfs_can_frame_t *f)
{
    rfs_can_msg_t m;
    /* Wheel frames carry no time: `now` only matters for timestamped ids. */
    if (rfs_can_rx_frame(&s->rx, f, 0, &m) == RFS_CAN_OK && m.kind == RFS_CAN_MSG_WHEEL) {
        s->wheel = m.wheel;
        s->wheels_rx++;
    }
}

static void on_can(void *ctx, int64_t t_us, const rfs_can_frame_t *f)
{
    (void)t_us;
    on_frame(ctx, f);
}

static void on_status(void *ctx, int64_t t_us, const rfs_seek_out_t *out)
{
    ctrl_lcm_t *s = ctx;
    s->status = *out;
    s->status_t_us = t_us;
    s->have_status = true;
    s->have_est = false; /* until on_estimate: this status may carry none */
}

static void on_estimate(void *ctx, int64_t t_us, const rfs_pathloss_est_t *est)
{
    (void)t_us;
    ctrl_lcm_t *s = ctx;
    s->est = *est;
    s->have_est = true;
}

static bool lcm_estimate(void *self, rfs_pathloss_est_t *est)
{
    const ctrl_lcm_t *s = self;
    if (s->have_est) {
        *est = s->est;
    }
    return s->have_est;
}

/* One stderr line, "PROG: " first when the program gave its name (hs_ctrl_lcm_cfg_t). */
static void say(const ctrl_lcm_t *s, const char *msg)
{
    char line[256];
    snprintf(line, sizeof line, "%s", msg);
    lx_err_one_line(line);
    fprintf(stderr, "%s%s%s\n", s->cfg.prog ? s->cfg.prog : "", s->cfg.prog ? ": " : "", line);
}

static void on_bad(void *ctx, const char *why)
{
    char msg[256];
    snprintf(msg, sizeof msg, "dropped LCM message: %s", why);
    say(ctx, msg);
}

static void cb_pose(void *self, const rfs_pose_t *pose)
{
    ctrl_lcm_t *s = self;
    (void)lx_lcm_pub_pose(s->lcm, pose);
}

static void cb_rssi(void *self, uint8_t src, int64_t t_us, int8_t dbm)
{
    ctrl_lcm_t *s = self;
    uint32_t q = src < RFS_CAN_MAX_SOURCES ? s->seq[src]++ : 0;
    (void)lx_lcm_pub_rssi(s->lcm, src, t_us, dbm, q);
}

/* The simulated receiver's heartbeat, as the sniffer's capture loop sends it:
 * published before the clock tick of the step it precedes, so the controller has it
 * when it steps. */
static void cb_receiver(void *self, int64_t t_us)
{
    ctrl_lcm_t *s = self;
    (void)lx_lcm_pub_receiver(s->lcm, t_us, s->rx_seq++);
}

static void cb_step(void *self, int64_t now_us, hs_ctrl_out_t *out)
{
    ctrl_lcm_t *s = self;
    uint32_t wheels0 = s->wheels_rx;
    (void)lx_lcm_pub_clock(s->lcm, now_us);
    int64_t deadline = mono_ms() + s->cfg.reply_timeout_ms;
    bool answered = false;
    while (!answered) {
        int64_t left = deadline - mono_ms();
        if (left <= 0) {
            break;
        }
        if (s->can) {
            /* Two sources: take what CAN holds, then wait briefly on LCM; the status
             * normally arrives just after the wheel frame. */
            rfs_can_frame_t f;
            while (lx_can_recv(s->can, &f, 0) == 1) {
                on_frame(s, &f);
            }
            answered = s->have_status && s->status_t_us == now_us && s->wheels_rx != wheels0;
            if (answered) {
                break;
            }
            if (s->wheels_rx == wheels0) {
                if (lx_can_recv(s->can, &f, 1) == 1) {
                    on_frame(s, &f);
                }
            } else {
                (void)lx_lcm_handle(s->lcm, 1);
            }
        } else {
            (void)lx_lcm_handle(s->lcm, (int)(left > 100 ? 100 : left));
        }
        answered = s->have_status && s->status_t_us == now_us && s->wheels_rx != wheels0;
    }
    if (!answered) {
        if (s->timeouts++ == 0) {
            char msg[160];
            snprintf(msg, sizeof msg, "no answer from the controller for step t=%lld us within %d ms; wheels stopped",
                     (long long)now_us, s->cfg.reply_timeout_ms);
            say(s, msg);
        }
        memset(out, 0, sizeof *out);
        out->state = RFS_SEEK_STALE;
        if (s->have_status) {
            out->decision = s->status.decision;
        }
        return;
    }
    *out = s->status;
    /* The motor controller obeys the CAN frame, not the status copy. */
    out->left_mm_s = s->wheel.left_mm_s;
    out->right_mm_s = s->wheel.right_mm_s;
}

static void cb_close(void *self)
{
    ctrl_lcm_t *s = self;
    if (!s) {
        return;
    }
    lx_can_close(s->can);
    lx_lcm_close(s->lcm);
    free(s);
}

int hs_ctrl_lcm_open(hs_ctrl_t *c, const hs_ctrl_lcm_cfg_t *cfg, char *err, size_t errlen)
{
    if (cfg->period_us <= 0 || cfg->reply_timeout_ms <= 0) {
        snprintf(err, errlen, "lcm: period and reply timeout must be positive");
        return -1;
    }
    ctrl_lcm_t *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "lcm: out of memory");
        return -1;
    }
    s->cfg = *cfg;
    rfs_can_rx_cfg_t rc = rfs_can_rx_cfg_default();
    (void)rfs_can_rx_init(&s->rx, &rc);
    lx_lcm_handlers_t h;
    memset(&h, 0, sizeof h);
    h.ctx = s;
    h.on_status = on_status;
    h.on_estimate = on_estimate;
    h.on_can = cfg->can_iface ? NULL : on_can;
    h.on_bad = on_bad;
    s->lcm = lx_lcm_open(cfg->lcm_url, &h, err, errlen);
    if (!s->lcm) {
        free(s);
        return -1;
    }
    if (cfg->can_iface) {
        const uint32_t ids[] = {RFS_CAN_ID_WHEEL_CMD};
        s->can = lx_can_open(cfg->can_iface, ids, 1, err, errlen);
        if (!s->can) {
            lx_lcm_close(s->lcm);
            free(s);
            return -1;
        }
    }
    memset(c, 0, sizeof *c);
    c->name = cfg->can_iface ? "lcm+socketcan" : "lcm+can-over-lcm";
    c->self = s;
    c->period_us = cfg->period_us;
    c->on_pose = cb_pose;
    c->on_rssi = cb_rssi;
    c->on_receiver = cb_receiver;
    c->step = cb_step;
    c->predict = NULL;
    c->close = cb_close;
    c->estimate = lcm_estimate; /* the status's; the model stays in the controller */
    return 0;
}

uint32_t hs_ctrl_lcm_timeouts(const hs_ctrl_t *c)
{
    const ctrl_lcm_t *s = c->self;
    return s ? s->timeouts : 0;
}
