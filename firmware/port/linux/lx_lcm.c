/* lx_lcm.c - LCM behind firmware/port/linux/lx_lcm.h; the only file with LCM headers and the
 * lcm-gen types (generated from lcm/<type>.lcm into $(BUILD)/gen at build time). */
#include "lx_lcm.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#include "lx_err.h"
#include "rfseek_can_frame_t.h"
#include "rfseek_clock_t.h"
#include "rfseek_pose_t.h"
#include "rfseek_rssi_status_t.h"
#include "rfseek_rssi_t.h"
#include "rfseek_seeker_status_t.h"
#include "rfseek_wheel_cmd_t.h"

struct lx_lcm {
    lcm_t *lcm;             /* the connection */
    lx_lcm_handlers_t h;    /* callbacks */
    lx_lcm_stats_t stats;   /* counters */
    lx_lcm_log_t *rec;      /* recording target, or NULL */
};

struct lx_lcm_log {
    lcm_eventlog_t *ev;     /* the file */
    char *path;             /* final path (writing) */
    char *tmp;              /* temporary path while writing, or NULL when reading */
    int64_t last_us;        /* latest event timestamp written */
    bool failed;            /* a write failed (writing) */
    char err[160];          /* why reading stopped before the end ("" at the end) */
};

/* Largest encoded message we accept (a status with a short reason string). */
#define LX_LCM_MAX_MSG 4096

static void bad(lx_lcm_stats_t *s, const lx_lcm_handlers_t *h, const char *ch, const char *fmt, double v)
{
    char why[120];
    snprintf(why, sizeof why, fmt, v);
    if (s) {
        snprintf(s->last_error, sizeof s->last_error, "%s: %s", ch, why);
        if (s->bad < UINT32_MAX) {
            s->bad++;
        }
    }
    if (h->on_bad) {
        char line[200];
        snprintf(line, sizeof line, "%s: %s", ch, why);
        h->on_bad(h->ctx, line);
    }
}

static void good(lx_lcm_stats_t *s)
{
    if (s && s->received < UINT32_MAX) {
        s->received++;
    }
}

/* Metres (or radians) as double to Q16.16, rounded to nearest; false when not finite or
 * outside the Q16.16 range. Exact for doubles that came from Q16.16. */
static bool q16_of(double v, rfs_q16_t *q)
{
    if (!isfinite(v) || fabs(v) > 40000.0) {
        return false;
    }
    long long r = llround(v * 65536.0);
    if (r > INT32_MAX || r < INT32_MIN) {
        return false;
    }
    *q = (rfs_q16_t)r;
    return true;
}

static double dbl_of(rfs_q16_t q)
{
    return (double)q / 65536.0;
}

/* The estimates of a status: every field a Q16.16 value, areas and spreads not negative;
 * all zero when their valid flag is false. The path-loss estimate's into *est. */
static bool est_ok(const rfseek_seeker_status_t *m, rfs_pathloss_est_t *est)
{
    const double v[12] = {m->est_x, m->est_y, m->est_n, m->est_w, m->est_p0, m->est_rms,
                          m->est_area, m->bridge_x, m->bridge_y, m->bridge_f,
                          m->bridge_sigma, m->bridge_area};
    rfs_q16_t q[12];
    for (int i = 0; i < 12; i++) {
        if (!q16_of(v[i], &q[i]) || (!(i < 7 ? m->est_valid : m->bridge_valid) && q[i] != 0)) {
            return false;
        }
    }
    memset(est, 0, sizeof *est);
    est->sx = q[0];
    est->sy = q[1];
    est->n = q[2];
    est->w = q[3];
    est->p0 = q[4];
    est->rms = q[5];
    est->spread_m2 = q[6];
    return m->est_area >= 0.0 && m->est_rms >= 0.0 && m->bridge_sigma >= 0.0 &&
           m->bridge_area >= 0.0;
}

/* The decoders of dispatch(), one per channel: decode a message of `len` bytes, check its
 * fields, and deliver it, or count it bad with one line. The decoder's byte count must
 * equal the message length (no truncation, no trailing junk; the type fingerprint is
 * checked by the generated decoder). */

static void on_pose_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    rfseek_pose_t m;
    int n = rfseek_pose_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.pose_t (%.0f bytes)", (double)len);
        return;
    }
    rfs_pose_t p;
    p.t_us = m.utime;
    if (!q16_of(m.x, &p.x) || !q16_of(m.y, &p.y)) {
        bad(s, h, ch, "x or y is not a finite position within +-32768 m (x = %g)", m.x);
        return;
    }
    if (!isfinite(m.theta) || fabs(m.theta) > 1e6) {
        bad(s, h, ch, "theta is not finite (%g)", m.theta);
        return;
    }
    /* Normalise to [-pi, pi]: localisers publish unwrapped headings. */
    double th = remainder(m.theta, 2.0 * M_PI);
    p.theta = (rfs_q16_t)llround(th * 65536.0);
    good(s);
    h->on_pose(h->ctx, &p);
}

static void on_rssi_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    rfseek_rssi_t m;
    int n = rfseek_rssi_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.rssi_t (%.0f bytes)", (double)len);
        return;
    }
    if (m.source < 0 || m.source >= (int)RFS_CAN_MAX_SOURCES) {
        bad(s, h, ch, "source %.0f out of range 0..15", m.source);
        return;
    }
    if (m.dbm < -128 || m.dbm > 127) {
        bad(s, h, ch, "dbm %.0f out of range -128..127", m.dbm);
        return;
    }
    good(s);
    h->on_rssi(h->ctx, (uint8_t)m.source, m.utime, (int8_t)m.dbm, (uint32_t)m.seq);
}

static void on_receiver_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data,
                            int len)
{
    rfseek_rssi_status_t m;
    int n = rfseek_rssi_status_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.rssi_status_t (%.0f bytes)", (double)len);
        return;
    }
    good(s);
    h->on_receiver(h->ctx, m.utime, (uint32_t)m.seq);
}

static void on_clock_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    rfseek_clock_t m;
    int n = rfseek_clock_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.clock_t (%.0f bytes)", (double)len);
        return;
    }
    good(s);
    h->on_clock(h->ctx, m.utime);
}

static void on_wheel_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    rfseek_wheel_cmd_t m;
    int n = rfseek_wheel_cmd_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.wheel_cmd_t (%.0f bytes)", (double)len);
        return;
    }
    rfs_can_wheel_t w = {m.left_mm_s, m.right_mm_s, (uint8_t)(m.stop ? RFS_CAN_WHEEL_STOP : 0)};
    good(s);
    h->on_wheel(h->ctx, m.utime, &w);
}

/* A decoded status's fields into *o and its path-loss estimate into *est (all zero unless
 * est_valid): false when one is out of range or not finite. */
static bool status_of(const rfseek_seeker_status_t *m, rfs_seek_out_t *o, rfs_pathloss_est_t *est)
{
    memset(o, 0, sizeof *o);
    rfs_seek_decision_t *d = &o->decision;
    bool ok = m->state >= 0 && m->state <= RFS_SEEK_DRIVING && m->kind >= 0 && m->kind <= RFS_SEEK_TUMBLE &&
              m->prev >= 0 && m->prev <= RFS_DRIVE_BLOCKED && m->faults >= 0 && m->faults <= 0xFFFF &&
              q16_of(m->prediction, &d->prediction) && q16_of(m->mean, &d->mean) &&
              q16_of(m->epsilon, &d->epsilon) && q16_of(m->x, &d->x) && q16_of(m->y, &d->y) &&
              q16_of(m->goal_x, &d->goal_x) && q16_of(m->goal_y, &d->goal_y) && q16_of(m->max_x, &d->max_x) &&
              q16_of(m->max_y, &d->max_y) && q16_of(m->path_len, &d->path_len) && m->samples >= 0 &&
              m->samples <= 0xFFFF && m->plan_wait >= 0 && m->plan_wait <= 0xFFFF && est_ok(m, est);
    if (!ok) {
        return false;
    }
    o->left_mm_s = m->left_mm_s;
    o->right_mm_s = m->right_mm_s;
    o->state = (rfs_seek_state_t)m->state;
    o->faults = (uint16_t)m->faults;
    o->decided = m->decided;
    d->iteration = (uint32_t)m->iteration;
    d->t_us = m->decision_utime;
    d->kind = (rfs_seek_kind_t)m->kind;
    d->relearned = m->model_updated;
    d->line_search = m->line_search;
    d->model_valid = m->model_valid;
    d->mean_valid = m->mean_valid;
    d->prev = (rfs_drive_status_t)m->prev;
    d->samples = (uint16_t)m->samples;
    d->sampled = m->sampled;
    d->near = m->near;
    d->hedged = m->hedged;
    d->pinned = m->pinned;
    d->refuted = m->refuted;
    d->plan_wait = (uint16_t)m->plan_wait;
    return true;
}

/* Where the reason string's int32 length lies in an encoded seeker_status_t: fingerprint
 * 8, utime 8, state 1, faults 4, left and right 2 + 2, decided 1, iteration 4,
 * decision_utime 8, kind 1 (tests/wire/test_lcm.c checks it against the encoder). */
#define LX_LCM_STATUS_REASON_AT 39

static void on_status_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    /* lcm-gen's decoder mallocs the string length the message states (up to 2 GiB) before
     * it checks it against the message, and frees nothing when a later field is cut short
     * (found by tests/fuzz/fuzz_lcm.c): the length is checked first, the struct zeroed so
     * a failed decode can be cleaned up. */
    const uint8_t *b = data;
    const int at = LX_LCM_STATUS_REASON_AT;
    const int64_t rl = len >= at + 4 ? (int64_t)((uint32_t)b[at] << 24 | (uint32_t)b[at + 1] << 16 |
                                                 (uint32_t)b[at + 2] << 8 | b[at + 3])
                                     : -1;
    rfseek_seeker_status_t m;
    memset(&m, 0, sizeof m);
    int n = rl >= 1 && rl <= len - at - 4 ? rfseek_seeker_status_t_decode(data, 0, len, &m) : -1;
    if (n < 0 || n != len) {
        rfseek_seeker_status_t_decode_cleanup(&m);
        bad(s, h, ch, "truncated, oversized or not an rfseek.seeker_status_t (%.0f bytes)", (double)len);
        return;
    }
    rfs_seek_out_t o;
    rfs_pathloss_est_t est;
    if (!status_of(&m, &o, &est)) {
        rfseek_seeker_status_t_decode_cleanup(&m);
        bad(s, h, ch, "a field is out of range or not finite (state %.0f)", m.state);
        return;
    }
    const bool have_est = m.est_valid;
    int64_t t = m.utime;
    rfseek_seeker_status_t_decode_cleanup(&m);
    good(s);
    h->on_status(h->ctx, t, &o);
    if (have_est && h->on_estimate) {
        h->on_estimate(h->ctx, t, &est);
    }
}

static void on_can_msg(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    rfseek_can_frame_t m;
    int n = rfseek_can_frame_t_decode(data, 0, len, &m);
    if (n < 0 || n != len) {
        bad(s, h, ch, "truncated, oversized or not an rfseek.can_frame_t (%.0f bytes)", (double)len);
        return;
    }
    if (m.id < 0 || m.id > (int32_t)RFS_CAN_ID_MAX || m.dlc < 0 || m.dlc > 8) {
        bad(s, h, ch, "id or dlc out of range (id %.0f)", m.id);
        return;
    }
    rfs_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = (uint32_t)m.id;
    f.dlc = (uint8_t)m.dlc;
    memcpy(f.data, m.data, (size_t)m.dlc);
    good(s);
    h->on_can(h->ctx, m.utime, &f);
}

/* Decode one message of a known channel and deliver it to its handler; bad ones are
 * counted. */
static void dispatch(const lx_lcm_handlers_t *h, lx_lcm_stats_t *s, const char *ch, const void *data, int len)
{
    if (len < 0 || len > LX_LCM_MAX_MSG) {
        bad(s, h, ch, "message of %.0f bytes is too long", (double)len);
        return;
    }
    if (strcmp(ch, LX_LCM_CH_POSE) == 0 && h->on_pose) {
        on_pose_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_RSSI) == 0 && h->on_rssi) {
        on_rssi_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_RSSI_STATUS) == 0 && h->on_receiver) {
        on_receiver_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_CLOCK) == 0 && h->on_clock) {
        on_clock_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_WHEEL) == 0 && h->on_wheel) {
        on_wheel_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_STATUS) == 0 && h->on_status) {
        on_status_msg(h, s, ch, data, len);
    } else if (strcmp(ch, LX_LCM_CH_CAN_FALLBACK) == 0 && h->on_can) {
        on_can_msg(h, s, ch, data, len);
    }
}

static void log_event(lx_lcm_log_t *log, int64_t t_us, const char *ch, const void *data, int len)
{
    if (log == NULL || log->tmp == NULL) {
        return;
    }
    lcm_eventlog_event_t ev;
    memset(&ev, 0, sizeof ev);
    ev.timestamp = t_us;
    ev.channellen = (int32_t)strlen(ch);
    ev.channel = (char *)ch;
    ev.datalen = len;
    ev.data = (void *)data;
    if (lcm_eventlog_write_event(log->ev, &ev) != 0) {
        log->failed = true;
    }
    log->last_us = t_us;
}

static void on_msg(const lcm_recv_buf_t *rbuf, const char *ch, void *user)
{
    lx_lcm_t *l = user;
    /* Record with the message's own utime when it decodes far enough, else the receive time. */
    int64_t t = rbuf->recv_utime;
    if (rbuf->data_size >= 16) {
        const uint8_t *p = rbuf->data;
        int64_t u = 0;
        for (int i = 0; i < 8; i++) {
            u = (int64_t)((uint64_t)u << 8 | p[8 + i]); /* after the 8-byte fingerprint, big-endian */
        }
        t = u;
    }
    log_event(l->rec, t, ch, rbuf->data, (int)rbuf->data_size);
    dispatch(&l->h, &l->stats, ch, rbuf->data, (int)rbuf->data_size);
}

/* liblcm reports a bad provider URL or option on stderr itself, in one or more lines with
 * the raw URL ("Error: LCM provider \"foo\" not found", "Warning: Invalid value for ttl",
 * glib's indented receive-buffer warning at the first udpm subscription). While the
 * provider opens and subscribes, stderr goes to a temporary file, so that text joins
 * our one-line error instead (the project's error rule). */
typedef struct stderr_capture {
    FILE *f;   /* the captured text, or NULL */
    int saved; /* the original stderr while capturing, else -1 */
} stderr_capture_t;

static void capture_start(stderr_capture_t *c)
{
    fflush(stderr);
    c->saved = -1;
    c->f = tmpfile();
    if (c->f != NULL && (c->saved = dup(STDERR_FILENO)) >= 0 && dup2(fileno(c->f), STDERR_FILENO) < 0) {
        close(c->saved);
        c->saved = -1;
    }
}

/* Restore stderr; the captured text into buf (at most n - 1 bytes, "" when none) as one
 * line: blanks at both ends dropped, control characters shown as '?', runs of spaces
 * (glib's indentation) made one. */
static void capture_stop(stderr_capture_t *c, char *buf, size_t n)
{
    buf[0] = '\0';
    if (c->saved >= 0) {
        fflush(stderr);
        (void)dup2(c->saved, STDERR_FILENO);
        close(c->saved);
        rewind(c->f);
        size_t k = fread(buf, 1, n - 1, c->f);
        while (k > 0 && (buf[k - 1] == '\n' || buf[k - 1] == ' ')) {
            k--;
        }
        buf[k] = '\0';
        size_t a = 0;
        while (buf[a] == '\n' || buf[a] == ' ') {
            a++;
        }
        lx_err_one_line(buf + a);
        size_t o = 0;
        for (size_t r = a; buf[r] != '\0'; r++) {
            if (buf[r] != ' ' || o == 0 || buf[o - 1] != ' ') {
                buf[o++] = buf[r];
            }
        }
        buf[o] = '\0';
    }
    if (c->f != NULL) {
        fclose(c->f);
    }
}

/* The provider and its subscriptions; NULL with err = "lcm: URL: reason". */
static lx_lcm_t *open_provider(const char *url, const lx_lcm_handlers_t *h, char *err, size_t errlen)
{
    lx_lcm_t *l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errlen, "lcm: %s: out of memory", url ? url : "(default)");
        return NULL;
    }
    l->lcm = lcm_create(url);
    if (!l->lcm) {
        snprintf(err, errlen, "lcm: %s: cannot open this provider (bad URL, no multicast route, or no file)",
                 url ? url : "(default)");
        free(l);
        return NULL;
    }
    if (h) {
        l->h = *h;
    }
    const struct {
        const char *ch;
        bool on;
    } subs[] = {
        {LX_LCM_CH_POSE, l->h.on_pose != NULL},   {LX_LCM_CH_RSSI, l->h.on_rssi != NULL},
        {LX_LCM_CH_CLOCK, l->h.on_clock != NULL}, {LX_LCM_CH_WHEEL, l->h.on_wheel != NULL},
        {LX_LCM_CH_STATUS, l->h.on_status != NULL}, {LX_LCM_CH_CAN_FALLBACK, l->h.on_can != NULL},
        {LX_LCM_CH_RSSI_STATUS, l->h.on_receiver != NULL},
    };
    for (size_t i = 0; i < sizeof subs / sizeof subs[0]; i++) {
        if (subs[i].on && lcm_subscribe(l->lcm, subs[i].ch, on_msg, l) == NULL) {
            snprintf(err, errlen, "lcm: %s: cannot subscribe to %s", url ? url : "(default)", subs[i].ch);
            lcm_destroy(l->lcm);
            free(l);
            return NULL;
        }
    }
    return l;
}

/* The mode a file:// URL opens its log in: the last "mode=" option, "r" when none. */
static bool file_url_reads(const char *opts)
{
    bool reads = true;
    for (const char *o = opts; o != NULL; o = strchr(o + 1, '&')) {
        if (strncmp(o + 1, "mode=", 5) == 0) {
            reads = o[6] == 'r' && (o[7] == '\0' || o[7] == '&');
        }
    }
    return reads;
}

/* A log played through file:// (read mode, LCM's default): liblcm stops without a word at
 * an event cut short, prints its own line for a channel name of 1000 bytes or more and
 * plays on, and callocs whatever data length a damaged header states (event_fits). So the
 * whole log is read first with the reader of rfseekd --replay; damage is one line "lcm:
 * URL: offset N: reason". A log that does not open is left to liblcm's own message. */
static int check_file_log(const char *url, char *err, size_t errlen)
{
    if (url == NULL || strncmp(url, "file://", 7) != 0) {
        return 0;
    }
    const char *opts = strchr(url + 7, '?');
    if (!file_url_reads(opts)) {
        return 0;
    }
    char *path = strndup(url + 7, opts != NULL ? (size_t)(opts - (url + 7)) : strlen(url + 7));
    struct stat st;
    char e2[8];
    if (path != NULL && stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        /* liblcm would scan /dev/zero or a FIFO for a sync word for ever */
        snprintf(err, errlen, "lcm: %s: not a regular file (an LCM log is read by its lengths)", url);
        lx_err_one_line(err);
        free(path);
        return -1;
    }
    lx_lcm_log_t *log = path != NULL ? lx_lcm_log_open(path, "r", e2, sizeof e2) : NULL;
    free(path);
    if (log == NULL) {
        return 0;
    }
    int64_t t_us;
    char ch[8];
    uint8_t data[8];
    size_t len;
    int r;
    while ((r = lx_lcm_log_next_raw(log, &t_us, ch, sizeof ch, data, sizeof data, &len)) > 0) {
        /* only the verdict on the whole log matters */
    }
    if (r < 0) {
        snprintf(err, errlen, "lcm: %s: %s", url, lx_lcm_log_error(log));
        lx_err_one_line(err);
    }
    lx_lcm_log_close(log);
    return r < 0 ? -1 : 0;
}

lx_lcm_t *lx_lcm_open(const char *url, const lx_lcm_handlers_t *h, char *err, size_t errlen)
{
    if (check_file_log(url, err, errlen) != 0) {
        return NULL;
    }
    stderr_capture_t cap;
    char said[256];
    capture_start(&cap);
    lx_lcm_t *l = open_provider(url, h, err, errlen);
    capture_stop(&cap, said, sizeof said);
    if (errlen == 0) {
        return l;
    }
    if (!l && said[0]) {
        size_t k = strlen(err);
        snprintf(err + k, errlen - k, " (liblcm: %s)", said);
    } else if (l && said[0]) {
        snprintf(err, errlen, "lcm: %s: liblcm: %s", url ? url : "(default)", said);
    } else if (l) {
        err[0] = '\0';
    }
    lx_err_one_line(err); /* the URL can hold line breaks */
    return l;
}

void lx_lcm_record(lx_lcm_t *l, lx_lcm_log_t *log)
{
    l->rec = log;
}

/* Encode with the generated encoder into a stack buffer, record, publish. */
#define LX_LCM_PUBLISH(l, ch, type, msgp, t_us)                                            \
    do {                                                                                   \
        uint8_t buf_[LX_LCM_MAX_MSG];                                                      \
        int n_ = type##_encoded_size(msgp);                                                \
        if (n_ <= 0 || n_ > (int)sizeof buf_ || type##_encode(buf_, 0, n_, msgp) != n_) { \
            return -1;                                                                     \
        }                                                                                  \
        log_event((l)->rec, (t_us), (ch), buf_, n_);                                       \
        return lcm_publish((l)->lcm, (ch), buf_, (unsigned)n_) == 0 ? 0 : -1;              \
    } while (0)

int lx_lcm_pub_pose(lx_lcm_t *l, const rfs_pose_t *pose)
{
    rfseek_pose_t m = {pose->t_us, dbl_of(pose->x), dbl_of(pose->y), dbl_of(pose->theta)};
    LX_LCM_PUBLISH(l, LX_LCM_CH_POSE, rfseek_pose_t, &m, pose->t_us);
}

int lx_lcm_pub_rssi(lx_lcm_t *l, uint8_t src, int64_t t_us, int8_t dbm, uint32_t seq)
{
    rfseek_rssi_t m = {t_us, src, dbm, (int32_t)seq};
    LX_LCM_PUBLISH(l, LX_LCM_CH_RSSI, rfseek_rssi_t, &m, t_us);
}

int lx_lcm_pub_receiver(lx_lcm_t *l, int64_t t_us, uint32_t seq)
{
    rfseek_rssi_status_t m = {t_us, (int32_t)seq};
    LX_LCM_PUBLISH(l, LX_LCM_CH_RSSI_STATUS, rfseek_rssi_status_t, &m, t_us);
}

int lx_lcm_pub_clock(lx_lcm_t *l, int64_t t_us)
{
    rfseek_clock_t m = {t_us};
    LX_LCM_PUBLISH(l, LX_LCM_CH_CLOCK, rfseek_clock_t, &m, t_us);
}

int lx_lcm_pub_wheel(lx_lcm_t *l, int64_t t_us, const rfs_can_wheel_t *w)
{
    rfseek_wheel_cmd_t m = {t_us, w->left_mm_s, w->right_mm_s, (w->flags & RFS_CAN_WHEEL_STOP) != 0};
    LX_LCM_PUBLISH(l, LX_LCM_CH_WHEEL, rfseek_wheel_cmd_t, &m, t_us);
}

static const char *reason_of(const rfs_seek_decision_t *d)
{
#define REASONS(k) {{k, k "+line-search"}, {k "+relearn", k "+relearn+line-search"}}
    /* rfs_seek_kind_t's order (rfs_seek_kind_name) */
    static const char *const names[8][2][2] = {
        REASONS("none"),  REASONS("initial"),  REASONS("greedy"), REASONS("epsilon"),
        REASONS("probe"), REASONS("gradient"), REASONS("run"),    REASONS("tumble"),
    };
#undef REASONS
    unsigned k = (unsigned)d->kind <= (unsigned)RFS_SEEK_TUMBLE ? (unsigned)d->kind : 0;
    return names[k][d->relearned ? 1 : 0][d->line_search ? 1 : 0];
}

int lx_lcm_pub_status(lx_lcm_t *l, int64_t t_us, const rfs_seek_out_t *out)
{
    return lx_lcm_pub_status_est(l, t_us, out, NULL, NULL);
}

int lx_lcm_pub_status_est(lx_lcm_t *l, int64_t t_us, const rfs_seek_out_t *out,
                          const rfs_pathloss_est_t *est, const rfs_fields_est_t *bridge)
{
    const rfs_seek_decision_t *d = &out->decision;
    rfseek_seeker_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = t_us;
    m.state = (int8_t)out->state;
    m.faults = out->faults;
    m.left_mm_s = out->left_mm_s;
    m.right_mm_s = out->right_mm_s;
    m.decided = out->decided;
    m.iteration = (int32_t)d->iteration;
    m.decision_utime = d->t_us;
    m.kind = (int8_t)d->kind;
    m.reason = (char *)reason_of(d);
    m.model_updated = d->relearned;
    m.line_search = d->line_search;
    m.model_valid = d->model_valid;
    m.mean_valid = d->mean_valid;
    m.prev = (int8_t)d->prev;
    m.prediction = dbl_of(d->prediction);
    m.mean = dbl_of(d->mean);
    m.epsilon = dbl_of(d->epsilon);
    m.x = dbl_of(d->x);
    m.y = dbl_of(d->y);
    m.goal_x = dbl_of(d->goal_x);
    m.goal_y = dbl_of(d->goal_y);
    m.max_x = dbl_of(d->max_x);
    m.max_y = dbl_of(d->max_y);
    m.path_len = dbl_of(d->path_len);
    m.samples = d->samples;
    m.sampled = d->sampled;
    m.near = d->near;
    m.hedged = d->hedged;
    m.pinned = d->pinned;
    m.refuted = d->refuted;
    m.plan_wait = d->plan_wait;
    if (est) { // the path-loss model's estimate (memset left them 0 otherwise)
        m.est_valid = true;
        m.est_x = dbl_of(est->sx);
        m.est_y = dbl_of(est->sy);
        m.est_n = dbl_of(est->n);
        m.est_w = dbl_of(est->w);
        m.est_p0 = dbl_of(est->p0);
        m.est_rms = dbl_of(est->rms);
        m.est_area = dbl_of(est->spread_m2);
    }
    if (bridge) { // the per-node model's predicted bridging point (left 0 otherwise)
        m.bridge_valid = true;
        m.bridge_x = dbl_of(bridge->x);
        m.bridge_y = dbl_of(bridge->y);
        m.bridge_f = dbl_of(bridge->value);
        m.bridge_sigma = dbl_of(bridge->sigma);
        m.bridge_area = dbl_of(bridge->area_m2);
    }
    LX_LCM_PUBLISH(l, LX_LCM_CH_STATUS, rfseek_seeker_status_t, &m, t_us);
}

int lx_lcm_pub_can(lx_lcm_t *l, int64_t t_us, const rfs_can_frame_t *f)
{
    rfseek_can_frame_t m;
    memset(&m, 0, sizeof m);
    m.utime = t_us;
    m.id = (int32_t)f->id;
    m.dlc = (int8_t)(f->dlc > 8 ? 8 : f->dlc);
    memcpy(m.data, f->data, 8);
    LX_LCM_PUBLISH(l, LX_LCM_CH_CAN_FALLBACK, rfseek_can_frame_t, &m, t_us);
}

int lx_lcm_pub_raw(lx_lcm_t *l, int64_t t_us, const char *channel, const void *data, size_t len)
{
    if (len > (size_t)LX_LCM_MAX_MSG * 16) {
        return -1;
    }
    log_event(l->rec, t_us, channel, data, (int)len);
    return lcm_publish(l->lcm, channel, data, (unsigned)len) == 0 ? 0 : -1;
}

int lx_lcm_handle(lx_lcm_t *l, int timeout_ms)
{
    errno = 0;
    int r = lcm_handle_timeout(l->lcm, timeout_ms < 0 ? 0 : timeout_ms);
    /* liblcm returns select()'s -1 when a signal interrupts the wait: no error, the
     * caller's loop looks at its stop flag (SIGTERM ends rfseekd cleanly). */
    if (r < 0 && errno == EINTR) {
        return 0;
    }
    return r > 0 ? 1 : (r == 0 ? 0 : -1);
}

void lx_lcm_get_stats(const lx_lcm_t *l, lx_lcm_stats_t *s)
{
    *s = l->stats;
}

void lx_lcm_close(lx_lcm_t *l)
{
    if (!l) {
        return;
    }
    lcm_destroy(l->lcm);
    free(l);
}

lx_lcm_log_t *lx_lcm_log_open(const char *path, const char *mode, char *err, size_t errlen)
{
    bool w = strcmp(mode, "w") == 0;
    if (!w && strcmp(mode, "r") != 0) {
        snprintf(err, errlen, "%s: mode must be r or w", path);
        return NULL;
    }
    lx_lcm_log_t *log = calloc(1, sizeof *log);
    if (!log) {
        snprintf(err, errlen, "%s: out of memory", path);
        return NULL;
    }
    log->path = strdup(path);
    if (w) {
        size_t n = strlen(path) + 5;
        log->tmp = malloc(n);
        if (log->tmp) {
            snprintf(log->tmp, n, "%s.tmp", path);
        }
    }
    if (!log->path || (w && !log->tmp)) {
        snprintf(err, errlen, "%s: out of memory", path);
        free(log->path);
        free(log->tmp);
        free(log);
        return NULL;
    }
    struct stat st;
    if (!w && stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        /* event_fits measures events against the file's size: /dev/zero has none */
        snprintf(err, errlen, "%s: not a regular file (an LCM log is read by its lengths)", path);
        free(log->path);
        free(log);
        return NULL;
    }
    log->ev = lcm_eventlog_create(w ? log->tmp : path, w ? "w" : "r");
    if (!log->ev) {
        snprintf(err, errlen, "%s: cannot open for %s", w ? log->tmp : path, w ? "writing" : "reading");
        free(log->path);
        free(log->tmp);
        free(log);
        return NULL;
    }
    return log;
}

/* LCM's reader callocs the event's data length as read from the file (up to 2 GiB) before
 * reading it: a corrupt or truncated log costs that much memory, or crashes where calloc
 * fails (found by tests/fuzz/fuzz_lcm.c). The next header is checked first: its sync word
 * right here (LCM would skip any bytes to the next one), a channel name LCM accepts and
 * lengths within the file. 1: an event follows; 0: the clean end of the log; -1: not an
 * event, the reason in log->err. */
static int event_fits(lx_lcm_log_t *log)
{
    FILE *f = log->ev->f;
    off_t pos = ftello(f);
    if (pos < 0 || fseeko(f, 0, SEEK_END) != 0) {
        snprintf(log->err, sizeof log->err, "cannot seek");
        return -1;
    }
    off_t end = ftello(f);
    uint8_t b[28] = {0};
    size_t n = fseeko(f, pos, SEEK_SET) == 0 ? fread(b, 1, sizeof b, f) : 0;
    if (fseeko(f, pos, SEEK_SET) != 0) {
        snprintf(log->err, sizeof log->err, "cannot seek");
        return -1;
    }
    if (pos == end) {
        return 0;
    }
    uint32_t magic = (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3];
    if (n < 4 || magic != 0xEDA1DA01u) {
        snprintf(log->err, sizeof log->err, "offset %lld: not an LCM event (no sync word)", (long long)pos);
        return -1;
    }
    if (n < sizeof b) {
        snprintf(log->err, sizeof log->err, "offset %lld: truncated event header", (long long)pos);
        return -1;
    }
    uint32_t cl = (uint32_t)b[20] << 24 | (uint32_t)b[21] << 16 | (uint32_t)b[22] << 8 | b[23];
    uint32_t dl = (uint32_t)b[24] << 24 | (uint32_t)b[25] << 16 | (uint32_t)b[26] << 8 | b[27];
    if (cl >= 1000u) {
        snprintf(log->err, sizeof log->err, "offset %lld: channel name of %" PRIu32 " bytes (at most 999)",
                 (long long)pos, cl);
        return -1;
    }
    if (dl > INT32_MAX || (uint64_t)cl + dl > (uint64_t)(end - pos) - sizeof b) {
        snprintf(log->err, sizeof log->err, "offset %lld: event cut short (%" PRIu32 " + %" PRIu32
                 " bytes announced, %lld in the file)", (long long)pos, cl, dl,
                 (long long)(end - pos) - (long long)sizeof b);
        return -1;
    }
    return 1;
}

const char *lx_lcm_log_error(const lx_lcm_log_t *log)
{
    return log->err;
}

int lx_lcm_log_next(lx_lcm_log_t *log, const lx_lcm_handlers_t *h, lx_lcm_stats_t *stats, int64_t *t_us)
{
    const int fits = event_fits(log);
    lcm_eventlog_event_t *ev = fits > 0 ? lcm_eventlog_read_next_event(log->ev) : NULL;
    if (!ev) {
        return fits < 0 ? -1 : 0;
    }
    if (t_us) {
        *t_us = ev->timestamp;
    }
    char ch[64];
    size_t cl = ev->channellen > 0 && (size_t)ev->channellen < sizeof ch ? (size_t)ev->channellen : 0;
    memcpy(ch, ev->channel, cl);
    ch[cl] = '\0';
    dispatch(h, stats, ch, ev->data, ev->datalen);
    lcm_eventlog_free_event(ev);
    return 1;
}

int lx_lcm_log_next_raw(lx_lcm_log_t *log, int64_t *t_us, char *channel, size_t chcap, void *data, size_t cap,
                        size_t *len)
{
    const int fits = event_fits(log);
    lcm_eventlog_event_t *ev = fits > 0 ? lcm_eventlog_read_next_event(log->ev) : NULL;
    if (!ev) {
        return fits < 0 ? -1 : 0;
    }
    *t_us = ev->timestamp;
    size_t cl = ev->channellen > 0 ? (size_t)ev->channellen : 0;
    if (chcap > 0) {
        cl = cl < chcap - 1 ? cl : chcap - 1;
        memcpy(channel, ev->channel, cl);
        channel[cl] = '\0';
    }
    size_t dl = ev->datalen > 0 ? (size_t)ev->datalen : 0;
    memcpy(data, ev->data, dl < cap ? dl : cap);
    *len = dl;
    lcm_eventlog_free_event(ev);
    return 1;
}

int lx_lcm_log_close(lx_lcm_log_t *log)
{
    if (!log) {
        return 0;
    }
    int rc = 0;
    if (log->tmp) {
        rc = !log->failed && fflush(log->ev->f) == 0 ? 0 : -1;
    }
    lcm_eventlog_destroy(log->ev);
    if (log->tmp && rc == 0 && rename(log->tmp, log->path) != 0) {
        rc = -1;
    }
    if (log->tmp && rc != 0) {
        (void)remove(log->tmp); /* a log that could not be finished leaves nothing */
    }
    free(log->path);
    free(log->tmp);
    free(log);
    return rc;
}
