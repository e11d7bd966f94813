/* hs_faults.c - fault injection in the simulator (see hs_faults.h, docs/FAULTS.md). */
#include "hs_faults.h"

#include <math.h>
#include <string.h>

#include "hs_radio.h"

static const char *const kind_names[HS_FAULT_KIND_COUNT] = {
    "rssi_silence", "rssi_past", "rssi_reorder", "pose_jump", "pose_past",
    "pose_reorder", "can_drop",  "bus_off",      "source_move", "kidnap",
    "rssi_future",  "pose_future",
};

const char *hs_faults_kind_name(hs_fault_kind_t k)
{
    return (unsigned)k < HS_FAULT_KIND_COUNT ? kind_names[k] : "?";
}

bool hs_faults_kind_parse(const char *name, hs_fault_kind_t *k)
{
    for (unsigned i = 0; name && i < HS_FAULT_KIND_COUNT; i++) {
        if (strcmp(name, kind_names[i]) == 0) {
            *k = (hs_fault_kind_t)i;
            return true;
        }
    }
    return false;
}

bool hs_faults_one_shot(hs_fault_kind_t k)
{
    return k == HS_FAULT_SOURCE_MOVE || k == HS_FAULT_KIDNAP;
}

hs_fault_t hs_faults_default(hs_fault_kind_t k)
{
    hs_fault_t f;
    memset(&f, 0, sizeof f);
    f.kind = k;
    f.start_s = 30.0;
    f.lag_s = 1.0;          // timestamps "from the past"; 1 s is 10 pose periods
    f.probability = 0.5;
    f.x = 3.0;              // pose jumps of 3 m
    switch (k) {
    case HS_FAULT_RSSI_SILENCE: f.duration_s = 30.0; break; // silence for 30 s
    case HS_FAULT_BUS_OFF: f.duration_s = 2.0; break;       // a 2 s bus-off
    case HS_FAULT_SOURCE_MOVE:
    case HS_FAULT_KIDNAP: f.duration_s = 0.0; break;
    default: f.duration_s = 30.0; break;
    }
    return f;
}

int hs_faults_check(const hs_fault_t *f, unsigned nsources, char *err, size_t errlen)
{
    if ((unsigned)f->kind >= HS_FAULT_KIND_COUNT) {
        snprintf(err, errlen, "kind: out of range");
        return -1;
    }
    if (!(f->start_s >= 0.0 && f->start_s <= 1e6)) {
        snprintf(err, errlen, "start_s: must be in [0, 1e6] seconds");
        return -1;
    }
    if (hs_faults_one_shot(f->kind)) {
        if (f->duration_s != 0.0) {
            snprintf(err, errlen, "duration_s: %s happens once, it has no duration",
                     hs_faults_kind_name(f->kind));
            return -1;
        }
    } else if (!(f->duration_s > 0.0 && f->duration_s <= 1e6)) {
        snprintf(err, errlen, "duration_s: must be in (0, 1e6] seconds");
        return -1;
    }
    if ((f->kind == HS_FAULT_RSSI_PAST || f->kind == HS_FAULT_POSE_PAST) &&
        !(f->lag_s > 0.0 && f->lag_s <= 3600.0)) {
        snprintf(err, errlen, "lag_s: must be in (0, 3600] seconds");
        return -1;
    }
    if ((f->kind == HS_FAULT_RSSI_FUTURE || f->kind == HS_FAULT_POSE_FUTURE) &&
        !(f->lag_s > 0.0 && f->lag_s <= 3600.0)) {
        snprintf(err, errlen, "lead_s: must be in (0, 3600] seconds");
        return -1;
    }
    if (f->kind == HS_FAULT_CAN_DROP && !(f->probability >= 0.0 && f->probability <= 1.0)) {
        snprintf(err, errlen, "probability: must be in [0, 1]");
        return -1;
    }
    if (f->kind == HS_FAULT_SOURCE_MOVE && f->source >= nsources) {
        snprintf(err, errlen, "source: %u is not a source index (the scenario has %u)",
                 f->source, nsources);
        return -1;
    }
    return 0;
}

/// Metres to Q16.16, saturated.
static rfs_q16_t dq16(double v)
{
    double s = v * 65536.0;
    return s >= 2147483647.0 ? INT32_MAX : (s <= -2147483648.0 ? INT32_MIN : (rfs_q16_t)lround(s));
}

static int64_t us_of(double s)
{
    return (int64_t)llround(s * 1e6);
}

/// true when lasting fault i covers t_us: [start, start + duration).
static bool in_window(const hs_fault_t *f, int64_t t_us)
{
    return !hs_faults_one_shot(f->kind) && t_us >= us_of(f->start_s) &&
           t_us < us_of(f->start_s + f->duration_s);
}

/// Begin/end rows for the lasting faults whose state changed by t_us.
static void windows(hs_faults_run_t *r, int64_t t_us)
{
    for (unsigned i = 0; i < r->cfg->n; i++) {
        const hs_fault_t *f = &r->cfg->f[i];
        if (hs_faults_one_shot(f->kind)) {
            continue;
        }
        bool on = in_window(f, t_us);
        if (on != r->active[i]) {
            r->active[i] = on;
            if (r->log) {
                int64_t te = on ? us_of(f->start_s) : us_of(f->start_s + f->duration_s);
                fprintf(r->log, "%.6f\t%s\t%s\t%u\t\t\t\n", te * 1e-6,
                        on ? "fault_begin" : "fault_end", hs_faults_kind_name(f->kind), i);
            }
        }
    }
}

/// The first lasting fault of kind k active at t_us, or NULL.
static const hs_fault_t *active(const hs_faults_run_t *r, hs_fault_kind_t k, int64_t t_us)
{
    for (unsigned i = 0; i < r->cfg->n; i++) {
        if (r->cfg->f[i].kind == k && in_window(&r->cfg->f[i], t_us)) {
            return &r->cfg->f[i];
        }
    }
    return NULL;
}

void hs_faults_start(hs_faults_run_t *r, const hs_faults_cfg_t *cfg, uint64_t seed, FILE *log)
{
    memset(r, 0, sizeof *r);
    r->cfg = cfg;
    r->log = log;
    rfs_rng_seed(&r->rng, seed ^ 0x5A17C0FFEE000005ull);
    if (log) {
        // Columns by event: rssi t_stamp src dbm; pose t_stamp x y theta; receiver t_stamp;
        // cmd left right delivered state faults; motor stopped; fault_begin/fault_end kind index;
        // kidnap/source_move x y theta|source.
        fprintf(log, "t_s\tevent\ta\tb\tc\td\te\n");
    }
}

static void log_rssi(hs_faults_run_t *r, int64_t t_us, const hs_faults_msg_t *m)
{
    if (r->log) {
        fprintf(r->log, "%.6f\trssi\t%.6f\t%u\t%d\t\t\n", t_us * 1e-6, m->t_us * 1e-6,
                (unsigned)m->src, (int)m->dbm);
    }
}

static void log_pose(hs_faults_run_t *r, int64_t t_us, const hs_faults_msg_t *m)
{
    if (r->log) {
        fprintf(r->log, "%.6f\tpose\t%.6f\t%.4f\t%.4f\t%.4f\t\n", t_us * 1e-6, m->t_us * 1e-6,
                m->pose.x / 65536.0, m->pose.y / 65536.0, m->pose.theta / 65536.0);
    }
}

/// Reordering shared by both streams: hold one message, hand it out after the next.
/// When the window ends with a message held, it goes out first, then the new one.
static unsigned reorder(bool on, bool *held, hs_faults_msg_t *h, const hs_faults_msg_t *m,
                        hs_faults_msg_t out[2])
{
    if (on && !*held) {
        *h = *m;
        *held = true;
        return 0;
    }
    if (*held) {
        // Swapped: the newer first, then the older (the older arrives late).
        out[0] = on ? *m : *h;
        out[1] = on ? *h : *m;
        *held = false;
        return 2;
    }
    out[0] = *m;
    return 1;
}

unsigned hs_faults_rssi(hs_faults_run_t *r, int64_t t_us, uint8_t src, int8_t dbm,
                        hs_faults_msg_t out[2])
{
    windows(r, t_us);
    hs_faults_msg_t m;
    memset(&m, 0, sizeof m);
    m.t_us = t_us;
    m.src = src;
    m.dbm = dbm;
    if (active(r, HS_FAULT_RSSI_SILENCE, t_us)) {
        r->rssi_dropped++;
        return 0;
    }
    const hs_fault_t *past = active(r, HS_FAULT_RSSI_PAST, t_us);
    if (past) {
        m.t_us -= us_of(past->lag_s);
    }
    const hs_fault_t *future = active(r, HS_FAULT_RSSI_FUTURE, t_us);
    if (future) {
        m.t_us += us_of(future->lag_s);
    }
    unsigned n = reorder(active(r, HS_FAULT_RSSI_REORDER, t_us) != NULL, &r->rssi_held,
                         &r->held_rssi, &m, out);
    for (unsigned i = 0; i < n; i++) {
        log_rssi(r, t_us, &out[i]);
    }
    return n;
}

bool hs_faults_receiver(hs_faults_run_t *r, int64_t t_us, int64_t *stamp_us)
{
    windows(r, t_us);
    if (active(r, HS_FAULT_RSSI_SILENCE, t_us)) {
        return false;
    }
    // The same feed and clock as the packets; reordering swaps packets, not the feed's
    // own liveness, so a heartbeat is never held back.
    int64_t ts = t_us;
    const hs_fault_t *past = active(r, HS_FAULT_RSSI_PAST, t_us);
    if (past) {
        ts -= us_of(past->lag_s);
    }
    const hs_fault_t *future = active(r, HS_FAULT_RSSI_FUTURE, t_us);
    if (future) {
        ts += us_of(future->lag_s);
    }
    if (r->log) {
        fprintf(r->log, "%.6f\treceiver\t%.6f\t\t\t\t\n", t_us * 1e-6, ts * 1e-6);
    }
    *stamp_us = ts;
    return true;
}

unsigned hs_faults_pose(hs_faults_run_t *r, const rfs_pose_t *pose, hs_faults_msg_t out[2])
{
    int64_t t_us = pose->t_us;
    windows(r, t_us);
    hs_faults_msg_t m;
    memset(&m, 0, sizeof m);
    m.pose = *pose;
    const hs_fault_t *jump = active(r, HS_FAULT_POSE_JUMP, t_us);
    if (jump) {
        // A wrong re-localisation: the estimate is off by the offset while it lasts.
        m.pose.x = dq16(pose->x / 65536.0 + jump->x);
        m.pose.y = dq16(pose->y / 65536.0 + jump->y);
    }
    const hs_fault_t *past = active(r, HS_FAULT_POSE_PAST, t_us);
    if (past) {
        m.pose.t_us -= us_of(past->lag_s);
    }
    const hs_fault_t *future = active(r, HS_FAULT_POSE_FUTURE, t_us);
    if (future) {
        m.pose.t_us += us_of(future->lag_s);
    }
    m.t_us = m.pose.t_us;
    unsigned n = reorder(active(r, HS_FAULT_POSE_REORDER, t_us) != NULL, &r->pose_held,
                         &r->held_pose, &m, out);
    for (unsigned i = 0; i < n; i++) {
        log_pose(r, t_us, &out[i]);
    }
    return n;
}

bool hs_faults_cmd(hs_faults_run_t *r, int64_t t_us, const rfs_seek_out_t *out)
{
    windows(r, t_us);
    bool delivered = true;
    if (active(r, HS_FAULT_BUS_OFF, t_us)) {
        delivered = false;
    } else {
        const hs_fault_t *drop = active(r, HS_FAULT_CAN_DROP, t_us);
        // Draw only inside the window: the rest of the run is the same with or without it.
        if (drop && hs_radio_uniform(&r->rng) < drop->probability) {
            delivered = false;
        }
    }
    if (!delivered) {
        r->cmds_lost++;
    }
    if (r->log) {
        fprintf(r->log, "%.6f\tcmd\t%d\t%d\t%d\t%d\t%u\n", t_us * 1e-6, out->left_mm_s,
                out->right_mm_s, delivered ? 1 : 0, (int)out->state, (unsigned)out->faults);
    }
    return delivered;
}

void hs_faults_motor(hs_faults_run_t *r, int64_t t_us, bool timed_out)
{
    if (timed_out != r->motor_stopped) {
        r->motor_stopped = timed_out;
        if (r->log) {
            fprintf(r->log, "%.6f\tmotor\t%d\t\t\t\t\n", t_us * 1e-6, timed_out ? 1 : 0);
        }
    }
}

bool hs_faults_next_event(hs_faults_run_t *r, int64_t t_us, hs_faults_event_t *ev)
{
    for (unsigned i = 0; i < r->cfg->n; i++) {
        const hs_fault_t *f = &r->cfg->f[i];
        if (!hs_faults_one_shot(f->kind) || r->fired[i] || us_of(f->start_s) > t_us) {
            continue;
        }
        r->fired[i] = true;
        ev->kind = f->kind;
        ev->source = f->source;
        ev->x = f->x;
        ev->y = f->y;
        ev->theta = f->theta;
        if (r->log) {
            if (f->kind == HS_FAULT_KIDNAP) {
                fprintf(r->log, "%.6f\tkidnap\t%.4f\t%.4f\t%.4f\t\t\n", t_us * 1e-6, f->x, f->y,
                        f->theta);
            } else {
                fprintf(r->log, "%.6f\tsource_move\t%.4f\t%.4f\t%u\t\t\n", t_us * 1e-6, f->x,
                        f->y, f->source);
            }
        }
        return true;
    }
    return false;
}
