/* rfseekd.c - the Linux port of the firmware: the same application loop as the
 * microcontroller (firmware/rfs_app.h), with pose, RSSI and the receiver heartbeat
 * (RFS_RSSI_STATUS; docs/FAULTS.md, "The receiver heartbeat") from LCM, wheel commands to
 * SocketCAN (or the LCM fallback channel RFS_CAN_FALLBACK carrying raw CAN frames), the
 * status to LCM, and runs recorded as LCM logs and its frames as candump -L logs. See
 * docs/CAN.md.
 *
 * Clocks: live, the controller's time is CLOCK_REALTIME in microseconds (the LCM utime
 * convention: senders share the robot's synchronised clock), its 20 Hz steps scheduled on
 * CLOCK_MONOTONIC (a clock stepped back must not stop them). With --clock-lcm
 * it steps once per RFS_CLOCK message at that time (lock-step with a simulator). With
 * --replay LOG it reads the log instead of LCM: with --clock-lcm the recorded clock
 * messages drive the steps, otherwise a step runs at every 50 ms boundary of the event
 * timestamps - either way the same log gives the same decisions every time.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lx_can.h"
#include "lx_candump.h"
#include "lx_err.h"
#include "lx_lcm.h"
#include "lx_map.h"
#include "rfs_app.h"
#include "rfs_fields.h"
#include "rfs_pathloss.h"

static const char usage_text[] =
    "usage: rfseekd --map MAP.yaml [--lcm URL] [--can IFACE | --can-over-lcm] [options]\n"
    "       rfseekd --map MAP.yaml --replay LOG [--clock-lcm] [options]\n"
    "The rfseek controller as a Linux process: pose (RFS_POSE), RSSI (RFS_RSSI) and the\n"
    "receiver heartbeat (RFS_RSSI_STATUS: listening, packet or not) from LCM,\n"
    "wheel commands to CAN, status to RFS_SEEKER_STATUS (and a copy on RFS_WHEEL_CMD).\n"
    "  --map FILE        ROS map_server YAML (required)\n"
    "  --res M           core map cell size, metres (default 0.1)\n"
    "  --lcm URL         LCM provider (default: LCM's default udpm)\n"
    "  --can IFACE       send WHEEL_CMD and STATUS frames on this SocketCAN interface\n"
    "  --can-over-lcm    no SocketCAN: send the raw frames on LCM channel RFS_CAN_FALLBACK\n"
    "  --clock-lcm       step once per RFS_CLOCK message (lock-step with a simulator)\n"
    "  --replay LOG      read inputs from an LCM log instead of LCM (deterministic)\n"
    "  --log FILE        record every input and output as an LCM log (lcm-logplayer)\n"
    "  --candump FILE    write the frames sent as a candump -L log (interface: --can's,\n"
    "                    else can0; time: the controller's clock)\n"
    "  --decisions FILE  write one line per decision (default: stdout with --replay)\n"
    "  --target NAME     rssi (default) or bridge\n"
    "  --model NAME      internal model: ridge (default, the paper's), mlp, knn, radius,\n"
    "                    pathloss (docs/MODELS.md; one fit per node under --target bridge,\n"
    "                    docs/STRATEGIES.md; the STM32 image holds ridge and pathloss)\n"
    "  --strategy NAME   meta (default, the paper's Algorithm 1) or meta-path (greedy legs\n"
    "                    along the planned path, with its preset improvements; with\n"
    "                    --model pathloss: docs/STRATEGIES.md); also fd-gradient,\n"
    "                    plane-gradient, chemotaxis (the simulator's baselines)\n"
    "  --p0-min DBM      pathloss only: floor on the fitted signal at 1 m (default -45); the\n"
    "                    node's EIRP - 52 when its power is known (docs/PATHLOSS.md)\n"
    "  --fit-budget N    the model's work units a fit slice: one in each step, up to ten\n"
    "                    after it, as on the STM32 image (default 0: whole fits)\n"
    "  --fit-early on|off  relearns begun while the base brakes (default off; the STM32\n"
    "                    image's on); only with --fit-budget N > 0: whole fits ignore it\n"
    "  --seed N          seed of the controller's random source (default 1)\n"
    "  --duration S      stop after S seconds of controller time, live of the monotonic clock\n"
    "                    (default: run until signalled)\n"
    "  --idle-exit MS    stop when no LCM message arrived for MS milliseconds\n"
    "  -h, --help        this text\n";

typedef struct daemon {
    rfs_app_t *app;
    lx_lcm_t *lcm;
    lx_can_t *can;
    bool can_over_lcm;
    bool clock_lcm;
    bool replay;
    lx_lcm_log_t *rec;
    lx_candump_t *dump;     /* --candump: the frames sent, or NULL */
    FILE *decisions;
    int64_t next_step_us;   /* replay without clock: next 50 ms boundary */
    bool have_time;
    int64_t start_us;       /* first step's time */
    bool started;
    int64_t duration_us;    /* 0: unlimited */
    bool done;
    uint32_t steps;
    uint32_t decided;
    uint32_t bad_msgs;
    uint32_t can_fail;
    uint32_t clock_backwards;
    int64_t last_clock_us;
    int64_t last_now_us;    /* time of the latest step */
    lx_can_link_t link;
    lx_lcm_handlers_t handlers; /* the inputs' callbacks (ctx: this daemon) */
    lx_lcm_log_t *in;       /* --replay: the input log */
    char dec_tmp[4096];     /* --decisions: written here, renamed at a clean end */
    lx_map_t map;           /* --map, and the core's grids made from it */
    lx_core_map_t core;
    void *model_state;      /* --model: its state (heap, the model's size) */
    rfs_fields_t *fields;   /* --model pathloss --target bridge: one fit per node */
    rfs_fields_mem_t fmem;  /* ... its arrays */
    rfs_seek_src_t *src;    /* ... each node's own samples: state and arrays */
    rfs_sample_t *src_samples[RFS_TARGET_MAX_SOURCES];
    rfs_pending_t *src_pending[RFS_TARGET_MAX_SOURCES];
} daemon_t;

static volatile sig_atomic_t g_stop;

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

static const char PROG[] = "rfseekd"; /* the prefix of its error lines (lx_err_print) */

static int64_t realtime_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* The live steps' schedule, --duration and --idle-exit: a clock that never jumps
 * (CLOCK_REALTIME, the controller's clock, may be stepped back by NTP: no step would run
 * until it caught up). */
static int64_t monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* One frame at time t_us out on SocketCAN or as LCM (--can-over-lcm), written to the
 * candump log when sent. 0, or non-zero when it could not be sent. */
static int send_frame(daemon_t *d, int64_t t_us, const rfs_can_frame_t *f)
{
    int r = 0;
    if (d->can) {
        r = lx_can_send(d->can, f);
    } else if (d->can_over_lcm && d->lcm) {
        r = lx_lcm_pub_can(d->lcm, t_us, f);
    }
    if (r == 0 && d->dump != NULL) {
        lx_candump_write(d->dump, t_us, f);
    }
    return r;
}

static void step(daemon_t *d, int64_t now_us)
{
    if (d->done) {
        return;
    }
    if (!d->started) {
        d->started = true;
        d->start_us = now_us;
    }
    /* Live, --duration runs on the monotonic clock (run_live): a stepped clock would
     * stretch or cut it. */
    if (d->duration_us > 0 && (d->clock_lcm || d->replay) && now_us - d->start_us >= d->duration_us) {
        d->done = true;
        return;
    }
    if (d->can) {
        lx_can_link_t link = lx_can_health(d->can, NULL);
        if (link != d->link) {
            fprintf(stderr, "rfseekd: CAN link %s\n",
                    link == LX_CAN_LINK_OK ? "ok" : link == LX_CAN_LINK_PASSIVE ? "error-passive"
                                                  : link == LX_CAN_LINK_BUS_OFF ? "bus-off: wheels stopped"
                                                                                : "down: wheels stopped");
            d->link = link;
        }
        rfs_app_set_bus_off(d->app, link == LX_CAN_LINK_BUS_OFF || link == LX_CAN_LINK_DOWN);
    }
    rfs_app_out_t out;
    d->last_now_us = now_us;
    rfs_app_step(d->app, now_us, &out);
    rfs_app_background_all(d->app);
    d->steps++;
    rfs_can_frame_t fr[2];
    uint8_t n = rfs_app_frames(d->app, &out, fr);
    for (uint8_t i = 0; i < n; i++) {
        if (send_frame(d, now_us, &fr[i]) != 0 && d->can_fail++ == 0) {
            fprintf(stderr, "rfseekd: a CAN frame could not be sent (counted; retrying with backoff)\n");
        }
    }
    rfs_seek_out_t so;
    memset(&so, 0, sizeof so);
    so.left_mm_s = out.left_mm_s;
    so.right_mm_s = out.right_mm_s;
    so.state = out.state;
    so.faults = out.faults;
    so.decided = out.decided;
    so.decision = out.decision;
    const rfs_can_wheel_t w = rfs_app_wheel(&out); /* the WHEEL_CMD frame's, Stop included */
    if (d->lcm) {
        (void)lx_lcm_pub_wheel(d->lcm, now_us, &w);
        // The path-loss model's estimate and uncertainty when that is the model
        // (docs/PATHLOSS.md, "Uncertainty").
        const rfs_model_t *mdl = &d->app->seek.model;
        rfs_pathloss_est_t est;
        bool pl = mdl->ops == &rfs_pathloss_ops && rfs_pathloss_estimate(mdl->self, &est);
        rfs_fields_est_t fe; // one fit per node: the predicted bridging point
        bool fl = d->fields != NULL && rfs_fields_estimate(d->fields, &fe);
        (void)lx_lcm_pub_status_est(d->lcm, now_us, &so, pl ? &est : NULL, fl ? &fe : NULL);
    }
    if (out.decided) {
        d->decided++;
    }
    if (out.decided && d->decisions) {
        const rfs_seek_decision_t *x = &out.decision;
        fprintf(d->decisions,
                "decision t=%" PRId64 " n=%" PRIu32 " kind=%s relearn=%d line_search=%d prev=%d pred_q16=%" PRId32
                " mean_q16=%" PRId32 " eps_q16=%" PRId32 " x_q16=%" PRId32 " y_q16=%" PRId32 " goal_q16=%" PRId32
                ",%" PRId32 " samples=%u sampled=%d near=%d hedged=%d pinned=%d refuted=%d plan_wait=%u\n",
                x->t_us, x->iteration, rfs_seek_kind_name(x->kind), x->relearned, x->line_search, (int)x->prev,
                x->prediction, x->mean, x->epsilon, x->x, x->y, x->goal_x, x->goal_y, (unsigned)x->samples,
                x->sampled, x->near, x->hedged, x->pinned, x->refuted, (unsigned)x->plan_wait);
    }
}

/* The end of a run that sent commands (signalled, --duration, --idle-exit, LCM failing):
 * one more WHEEL_CMD, zero with Stop, so that no driving command stands until the motor
 * controller's own timeout. */
static void stop_wheels(daemon_t *d)
{
    if (d->replay || d->steps == 0u) {
        return;
    }
    const rfs_can_wheel_t w = {0, 0, RFS_CAN_WHEEL_STOP};
    const int64_t t = d->clock_lcm ? d->last_now_us : realtime_us();
    rfs_can_frame_t f;
    rfs_can_tx_wheel(&d->app->can_tx, &w, &f);
    if (send_frame(d, t, &f) != 0) {
        fprintf(stderr, "rfseekd: the last wheel command (stop) could not be sent\n");
    }
    if (d->lcm) {
        (void)lx_lcm_pub_wheel(d->lcm, t, &w);
    }
}

/* Replay without clock messages: run every step whose time lies before t_us. */
static void advance_to(daemon_t *d, int64_t t_us)
{
    if (!d->replay || d->clock_lcm) {
        return;
    }
    if (!d->have_time) {
        d->have_time = true;
        d->next_step_us = t_us - (t_us % RFS_APP_PERIOD_US) + RFS_APP_PERIOD_US;
        return;
    }
    while (d->next_step_us <= t_us && !d->done) {
        step(d, d->next_step_us);
        d->next_step_us += RFS_APP_PERIOD_US;
    }
}

/* Receive time of an input: its own time in lock-step and replay (the simulated clock),
 * the local clock when live. */
static int64_t rx_time(const daemon_t *d, int64_t t_us)
{
    if (!d->clock_lcm && !d->replay) {
        return realtime_us();
    }
    /* A late (out-of-order) input arrives now, not at its stamp. */
    return d->started && t_us < d->last_now_us ? d->last_now_us : t_us;
}

static void on_pose(void *ctx, const rfs_pose_t *pose)
{
    daemon_t *d = ctx;
    advance_to(d, pose->t_us);
    (void)rfs_app_on_pose(d->app, pose, rx_time(d, pose->t_us));
}

static void on_rssi(void *ctx, uint8_t src, int64_t t_us, int8_t dbm, uint32_t seq)
{
    daemon_t *d = ctx;
    (void)seq;
    advance_to(d, t_us);
    (void)rfs_app_on_rssi(d->app, src, t_us, dbm, rx_time(d, t_us));
}

static void on_receiver(void *ctx, int64_t t_us, uint32_t seq)
{
    daemon_t *d = ctx;
    (void)seq;
    advance_to(d, t_us);
    (void)rfs_app_on_receiver(d->app, t_us, rx_time(d, t_us));
}

static void on_clock(void *ctx, int64_t t_us)
{
    daemon_t *d = ctx;
    if (d->steps > 0 && t_us <= d->last_clock_us) {
        if (d->clock_backwards++ == 0) {
            fprintf(stderr, "rfseekd: RFS_CLOCK: time %" PRId64 " not after %" PRId64 " (dropped, counted)\n", t_us,
                    d->last_clock_us);
        }
        return;
    }
    d->last_clock_us = t_us;
    step(d, t_us);
}

static void on_bad(void *ctx, const char *why)
{
    daemon_t *d = ctx;
    d->bad_msgs++;
    lx_err_print(PROG, "dropped LCM message: %s", why);
}

static int die(const char *msg, const char *arg)
{
    lx_err_print(PROG, "%s%s", msg, arg ? arg : "");
    return 2;
}

static bool parse_i64(const char *s, int64_t lo, int64_t hi, int64_t *v)
{
    char *end;
    errno = 0;
    long long x = strtoll(s, &end, 10);
    if (errno || end == s || *end != '\0' || x < lo || x > hi) {
        return false;
    }
    *v = x;
    return true;
}

static bool is_value_option(const char *a)
{
    static const char *const opts[] = {"--map", "--lcm", "--can", "--replay", "--log", "--decisions", "--candump",
                                       "--target", "--res", "--seed", "--duration", "--idle-exit",
                                       "--model", "--p0-min", "--strategy", "--fit-budget", "--fit-early"};
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++) {
        if (strcmp(a, opts[i]) == 0) {
            return true;
        }
    }
    return false;
}

/* The command line. */
typedef struct options {
    const char *map_path, *url, *can_if, *replay, *log_path, *dec_path, *candump;
    const char *target;
    const rfs_models_entry_t *model; /* NULL: the application's built-in ridge */
    double p0_min;                   /* --p0-min: NAN keeps the model's default */
    rfs_seek_strategy_t strategy;    /* --strategy: the paper's by default */
    double res;
    int64_t seed, duration_s, idle_ms;
    int64_t fit_budget;              /* --fit-budget: 0, whole fits */
    bool fit_early;                  /* --fit-early */
    bool can_over_lcm, clock_lcm;
} options_t;

enum { RUN = -1 }; /* parse_options: go on (else the exit status) */

/* One option that takes a value v: RUN, or the exit status of a bad value. */
static int parse_value(options_t *o, const char *a, const char *v)
{
    static const char *const paths[] = {"--map", "--replay", "--log", "--decisions", "--candump"};
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; i++) {
        if (strcmp(a, paths[i]) == 0 && lx_err_path_opt(PROG, a, v) != 0) {
            return 2;
        }
    }
    if (strcmp(a, "--map") == 0) {
        o->map_path = v;
    } else if (strcmp(a, "--lcm") == 0) {
        o->url = v;
    } else if (strcmp(a, "--can") == 0) {
        o->can_if = v;
    } else if (strcmp(a, "--replay") == 0) {
        o->replay = v;
    } else if (strcmp(a, "--log") == 0) {
        o->log_path = v;
    } else if (strcmp(a, "--decisions") == 0) {
        o->dec_path = v;
    } else if (strcmp(a, "--candump") == 0) {
        o->candump = v;
    } else if (strcmp(a, "--target") == 0) {
        o->target = v;
        if (strcmp(o->target, "rssi") != 0 && strcmp(o->target, "bridge") != 0) {
            return die("--target: expected rssi or bridge, got ", o->target);
        }
    } else if (strcmp(a, "--model") == 0) {
        o->model = rfs_models_lookup(v);
        if (o->model == NULL) {
            return die("--model: expected ridge, mlp, knn, radius or pathloss, got ", v);
        }
    } else if (strcmp(a, "--strategy") == 0) {
        // meta-global needs the ridge's radius widened to the map (rfseek-sim does it):
        // not offered here rather than run as plain meta under its name.
        if (!rfs_seek_strategy_parse(v, &o->strategy) || o->strategy == RFS_SEEK_META_GLOBAL) {
            return die("--strategy: expected meta, meta-path, fd-gradient, plane-gradient or "
                       "chemotaxis, got ", v);
        }
    } else if (strcmp(a, "--p0-min") == 0) {
        char *end;
        o->p0_min = strtod(v, &end);
        if (*v == '\0' || *end != '\0' || !(o->p0_min >= -200.0 && o->p0_min <= 100.0)) {
            return die("--p0-min: expected dBm in [-200, 100], got ", v);
        }
    } else if (strcmp(a, "--res") == 0) {
        char *end;
        o->res = strtod(v, &end);
        if (*end != '\0' || !(o->res >= 0.01 && o->res <= 1.0)) {
            return die("--res: expected metres in [0.01, 1], got ", v);
        }
    } else if (strcmp(a, "--seed") == 0) {
        if (!parse_i64(v, 0, INT64_MAX, &o->seed)) {
            return die("--seed: expected a non-negative integer, got ", v);
        }
    } else if (strcmp(a, "--fit-budget") == 0) {
        if (!parse_i64(v, 0, 100000, &o->fit_budget)) {
            return die("--fit-budget: expected work units in [0, 100000], got ", v);
        }
    } else if (strcmp(a, "--fit-early") == 0) {
        if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0) {
            return die("--fit-early: expected on or off, got ", v);
        }
        o->fit_early = strcmp(v, "on") == 0;
    } else if (strcmp(a, "--duration") == 0) {
        if (!parse_i64(v, 1, 86400 * 365, &o->duration_s)) {
            return die("--duration: expected whole seconds >= 1, got ", v);
        }
    } else if (strcmp(a, "--idle-exit") == 0) {
        if (!parse_i64(v, 1, 86400000, &o->idle_ms)) {
            return die("--idle-exit: expected milliseconds >= 1, got ", v);
        }
    } else {
        return die("unknown option (see --help): ", a);
    }
    return RUN;
}

/* The command line into *o: RUN, or the exit status (--help, a bad option). */
static int parse_options(int argc, char **argv, options_t *o)
{
    memset(o, 0, sizeof *o);
    o->target = "rssi";
    o->p0_min = NAN;
    o->strategy = RFS_SEEK_META;
    o->res = 0.1;
    o->seed = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            return 0;
        } else if (strcmp(a, "--can-over-lcm") == 0) {
            o->can_over_lcm = true;
        } else if (strcmp(a, "--clock-lcm") == 0) {
            o->clock_lcm = true;
        } else if (!is_value_option(a)) {
            return die("unknown option (see --help): ", a);
        } else if (v == NULL) {
            return die("missing value for option ", a);
        } else if (*v == '\0') { /* "" for --lcm would be liblcm's default provider */
            return die("empty value for option ", a);
        } else {
            const int rc = parse_value(o, a, v);
            if (rc != RUN) {
                return rc;
            }
            i++;
        }
    }
    if (!o->map_path) {
        return die("--map MAP.yaml is required (see --help)", NULL);
    }
    if (!isnan(o->p0_min) && (o->model == NULL || o->model->ops != &rfs_pathloss_ops)) {
        return die("--p0-min: only with --model pathloss", NULL);
    }
    if (o->can_if && o->can_over_lcm) {
        return die("--can and --can-over-lcm exclude each other", NULL);
    }
    if (o->replay && (o->can_if || o->can_over_lcm)) {
        return die("--replay sends no CAN frames: drop --can / --can-over-lcm", NULL);
    }
    return RUN;
}

/* One path-loss fit per node (rfs_fields.h) on heap memory sized for the map, each node's
 * own store, and the seeker's settings for it: 0, or -1 when out of memory. */
static int open_fields(daemon_t *d, const options_t *o, rfs_app_cfg_t *cfg,
                       const rfs_target_ops_t *target)
{
    rfs_fields_cfg_t fc = rfs_fields_cfg_default();
    if (!isnan(o->p0_min)) {
        fc.pathloss.p0_min = (rfs_q16_t)lround(o->p0_min * 65536.0); // docs/PATHLOSS.md
    }
    rfs_fields_mem_size(&d->core.map, &fc, &d->fmem.points, &d->fmem.cells);
    d->fmem.f = calloc(d->fmem.points, sizeof(int16_t));
    d->src = calloc(target->nsources, sizeof(rfs_seek_src_t));
    cfg->src = d->src;
    if (d->fmem.f == NULL || d->src == NULL) {
        return -1;
    }
    // Everything allocated here is freed by free_fields() at the daemon's end.
    for (unsigned k = 0; k < target->nsources && k < RFS_TARGET_MAX_SOURCES; k++) {
        if ((d->fmem.walls[k] = calloc(d->fmem.points, 1)) == NULL ||
            (d->fmem.rsum[k] = calloc(d->fmem.cells, sizeof(int32_t))) == NULL ||
            (d->fmem.rcount[k] = calloc(d->fmem.cells, sizeof(uint16_t))) == NULL ||
            (d->src_samples[k] = calloc(cfg->seek.store.capacity, sizeof(rfs_sample_t))) == NULL ||
            (d->src_pending[k] = calloc(RFS_APP_PENDING, sizeof(rfs_pending_t))) == NULL) {
            return -1;
        }
        cfg->src_samples[k] = d->src_samples[k];
        cfg->src_pending[k] = d->src_pending[k];
    }
    d->fields = aligned_alloc(RFS_MODELS_STATE_ALIGN,
                              (sizeof(rfs_fields_t) + RFS_MODELS_STATE_ALIGN - 1u) /
                                  RFS_MODELS_STATE_ALIGN * RFS_MODELS_STATE_ALIGN);
    if (d->fields == NULL || rfs_fields_init(d->fields, &fc, target, &d->fmem) != 0) {
        return -1;
    }
    cfg->built = rfs_fields_model(d->fields);
    rfs_seek_cfg_per_source(&cfg->seek);
    return 0;
}

static void free_fields(daemon_t *d)
{
    free(d->src);
    for (unsigned k = 0; k < RFS_TARGET_MAX_SOURCES; k++) {
        free(d->fmem.walls[k]);
        free(d->fmem.rsum[k]);
        free(d->fmem.rcount[k]);
        free(d->src_samples[k]);
        free(d->src_pending[k]);
    }
    free(d->fmem.f);
    free(d->fields);
}

/* The map, the model's state and the application: 0, or 1 after an error line. */
static int open_controller(daemon_t *d, const options_t *o)
{
    char err[512];
    static rfs_sample_t samples[RFS_APP_MAX_SAMPLES];
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.samples = samples;
    rfs_seek_cfg_use_strategy(&cfg.seek, o->strategy);
    cfg.seek.fit_budget = (uint32_t)o->fit_budget;
    cfg.seek.fit_early = o->fit_early;
    cfg.seed = (uint64_t)o->seed;
    cfg.target = strcmp(o->target, "bridge") == 0 ? RFS_APP_TARGET_BRIDGE : RFS_APP_TARGET_RSSI;
    if (lx_map_load(o->map_path, &d->map, err, sizeof err) != 0 ||
        lx_map_to_core(&d->map, o->res, &cfg.map, &d->core, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    const rfs_target_ops_t *target = cfg.target == RFS_APP_TARGET_BRIDGE ? &rfs_target_bridge
                                                                          : &rfs_target_rssi;
    if (rfs_models_per_source(o->model, target)) {
        if (open_fields(d, o, &cfg, target) != 0) {
            fprintf(stderr, "rfseekd: --model %s: out of memory\n", o->model->name);
            return 1;
        }
    } else if (o->model != NULL) {
        // The Linux port holds any model: its state in a heap buffer of the model's size.
        size_t mb = (o->model->state_bytes + RFS_MODELS_STATE_ALIGN - 1u) / RFS_MODELS_STATE_ALIGN *
                    RFS_MODELS_STATE_ALIGN;
        d->model_state = aligned_alloc(RFS_MODELS_STATE_ALIGN, mb);
        if (d->model_state == NULL) {
            fprintf(stderr, "rfseekd: --model %s: out of memory\n", o->model->name);
            return 1;
        }
        cfg.model = o->model;
        cfg.model_state = d->model_state;
        cfg.model_state_bytes = (uint32_t)mb;
    }
    if (!isnan(o->p0_min)) {
        /* The node's power known: a floor on the fitted signal at 1 m (docs/PATHLOSS.md
         * "The P0 floor"). */
        cfg.pathloss.p0_min = (rfs_q16_t)lround(o->p0_min * 65536.0);
    }
    const lx_core_map_t *core = &d->core;
    rfs_app_map_t am = {core->map.w, core->map.h, core->map.res, core->map.origin_x, core->map.origin_y,
                        core->free_bits, core->wall_bits};
    d->app = malloc(sizeof *d->app);
    if (!d->app || rfs_app_init(d->app, &cfg, &am) != 0) {
        lx_err_print(PROG, "%s: the map (%u x %u cells at %.2f m) exceeds the controller's limits (%u bytes per "
                 "grid, %u lattice points)",
                 o->map_path, core->map.w, core->map.h, o->res, RFS_APP_MAX_MAP_BYTES, RFS_APP_MAX_LATTICE);
        return 1;
    }
    return 0;
}

/* The decisions file, the log, LCM and CAN: 0, or 1 after an error line. */
static int open_io(daemon_t *d, const options_t *o)
{
    char err[512];
    d->can_over_lcm = o->can_over_lcm;
    d->clock_lcm = o->clock_lcm;
    d->replay = o->replay != NULL;
    d->duration_us = o->duration_s * 1000000;
    d->decisions = o->replay ? stdout : NULL;
    /* The decisions go to a temporary file renamed at a clean end: nothing half-written. */
    snprintf(d->dec_tmp, sizeof d->dec_tmp, "%s.tmp.%ld", o->dec_path ? o->dec_path : "", (long)getpid());
    if (o->dec_path && !(d->decisions = fopen(d->dec_tmp, "w"))) {
        lx_err_print(PROG, "%s: cannot write: %s", o->dec_path, strerror(errno));
        return 1;
    }
    lx_lcm_handlers_t *h = &d->handlers;
    memset(h, 0, sizeof *h);
    h->ctx = d;
    h->on_pose = on_pose;
    h->on_rssi = on_rssi;
    h->on_receiver = on_receiver;
    h->on_clock = o->clock_lcm ? on_clock : NULL;
    h->on_bad = on_bad;
    if (o->log_path && !(d->rec = lx_lcm_log_open(o->log_path, "w", err, sizeof err))) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    if (o->candump && !(d->dump = lx_candump_open(o->candump, o->can_if ? o->can_if : LX_CANDUMP_DEFAULT_IF, err,
                                                  sizeof err))) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    if (!o->replay || o->url) {
        /* In replay, LCM (when given) only carries the outputs. */
        lx_lcm_handlers_t none;
        memset(&none, 0, sizeof none);
        d->lcm = lx_lcm_open(o->url, o->replay ? &none : h, err, sizeof err);
        if (!d->lcm) {
            lx_err_print(PROG, "%s", err);
            return 1;
        }
        if (err[0]) { /* liblcm's warning, as one line (lx_lcm.h) */
            lx_err_print(PROG, "%s", err);
        }
        lx_lcm_record(d->lcm, d->rec);
    }
    if (o->can_if) {
        const uint32_t ids[] = {RFS_CAN_ID_WHEEL_CMD, RFS_CAN_ID_STATUS};
        d->can = lx_can_open(o->can_if, ids, 2, err, sizeof err);
        if (!d->can) {
            lx_err_print(PROG, "%s", err);
            return 1;
        }
    }
    return 0;
}

/* --replay: the log's messages in order (the handlers step). 0, or 1 after an error line. */
static int run_replay(daemon_t *d, const options_t *o)
{
    char err[512];
    d->in = lx_lcm_log_open(o->replay, "r", err, sizeof err);
    if (!d->in) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    lx_lcm_stats_t st;
    memset(&st, 0, sizeof st);
    int64_t t;
    int r = 1;
    while (!g_stop && !d->done && (r = lx_lcm_log_next(d->in, &d->handlers, &st, &t)) == 1) {
    }
    if (r < 0) {
        lx_err_print(PROG, "%s: %s", o->replay, lx_lcm_log_error(d->in));
        return 1;
    }
    return 0;
}

/* A failed LCM receive: the end of a file:// provider's log (0), else an error (1). */
static int lcm_failed(const options_t *o)
{
    /* LCM's file:// provider reports the end of its log this way. */
    if (o->url && strncmp(o->url, "file://", 7) == 0) {
        return 0;
    }
    lx_err_print(PROG, "%s: LCM receive failed", o->url ? o->url : "(default URL)");
    return 1;
}

/* --clock-lcm: LCM's messages until signalled, done or idle (RFS_CLOCK steps). */
static int run_lockstep(daemon_t *d, const options_t *o)
{
    int64_t idle_since = monotonic_us();
    while (!g_stop && !d->done) {
        int r = lx_lcm_handle(d->lcm, 100);
        if (r < 0) {
            return lcm_failed(o);
        }
        int64_t now = monotonic_us();
        if (r > 0) {
            idle_since = now;
        } else if (o->idle_ms > 0 && now - idle_since >= o->idle_ms * 1000) {
            break;
        }
    }
    return 0;
}

/* Live: a step every period (monotonic schedule, at the local real-time clock's time),
 * LCM's messages in between. After the real-time clock is stepped back the steps go on:
 * the inputs' stamps lie ahead of now, stale, and the wheels stop (docs/FAULTS.md). */
static int run_live(daemon_t *d, const options_t *o)
{
    const int64_t start = monotonic_us();
    int64_t next = start;
    int64_t idle_since = next;
    while (!g_stop && !d->done) {
        int64_t now = monotonic_us();
        if (d->duration_us > 0 && now - start >= d->duration_us) {
            break;
        }
        if (now >= next) {
            step(d, realtime_us());
            next += RFS_APP_PERIOD_US;
            if (next < now) {
                next = now + RFS_APP_PERIOD_US; /* overrun: skip, do not burst */
            }
            continue;
        }
        int r = lx_lcm_handle(d->lcm, (int)((next - now + 999) / 1000));
        if (r < 0) {
            return lcm_failed(o);
        }
        if (r > 0) {
            idle_since = monotonic_us();
        } else if (o->idle_ms > 0 && monotonic_us() - idle_since >= o->idle_ms * 1000) {
            break;
        }
    }
    return 0;
}

/* Close the log and the decisions (renamed into place when rc is 0) and free everything:
 * the exit status, 1 when finishing an output failed. */
static int finish(daemon_t *d, const options_t *o, int rc)
{
    if (d->in) {
        lx_lcm_log_close(d->in);
    }
    if (d->rec && lx_lcm_log_close(d->rec) != 0 && rc == 0) {
        lx_err_print(PROG, "%s: could not finish the log (write failed)", o->log_path);
        rc = 1;
    }
    char err[512];
    if (lx_candump_close(d->dump, rc == 0, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        rc = 1;
    }
    if (d->decisions && d->decisions != stdout) {
        if (fclose(d->decisions) != 0 && rc == 0) {
            lx_err_print(PROG, "%s: write failed", o->dec_path);
            rc = 1;
        }
        if (rc == 0 && rename(d->dec_tmp, o->dec_path) != 0) {
            lx_err_print(PROG, "%s: %s", o->dec_path, strerror(errno));
            rc = 1;
        }
        if (rc != 0) {
            remove(d->dec_tmp);
        }
    }
    lx_can_close(d->can);
    lx_lcm_close(d->lcm);
    free(d->app);
    free(d->model_state);
    free_fields(d);
    lx_core_map_free(&d->core);
    lx_map_free(&d->map);
    return rc;
}

/* No output may be the input, and each output's directory must exist: 0, or 1 after a
 * message - before any work. */
static int check_paths(const options_t *o)
{
    const char *outs[3] = {o->log_path, o->dec_path, o->candump}, *ins[2] = {o->map_path, o->replay};
    for (int i = 0; i < 3; i++) {
        if (outs[i] == NULL) {
            continue;
        }
        if (lx_err_same_file(PROG, ins[0], outs[i]) != 0 || lx_err_same_file(PROG, ins[1], outs[i]) != 0 ||
            lx_err_check_dest(PROG, outs[i]) != 0) {
            return 1;
        }
    }
    if (lx_err_same_dest(PROG, o->log_path, o->dec_path) != 0 || lx_err_same_dest(PROG, o->log_path, o->candump) != 0 ||
        lx_err_same_dest(PROG, o->dec_path, o->candump) != 0) {
        return 1;
    }
    return 0;
}

static int daemon_main(int argc, char **argv)
{
    options_t o;
    int rc = parse_options(argc, argv, &o);
    if (rc != RUN) {
        return rc;
    }
    if (check_paths(&o) != 0) {
        return 1;
    }
    daemon_t d;
    memset(&d, 0, sizeof d);
    rc = open_controller(&d, &o);
    if (rc == 0) {
        rc = open_io(&d, &o);
    }
    if (rc == 0) {
        signal(SIGINT, on_signal);
        signal(SIGTERM, on_signal);
        rc = o.replay ? run_replay(&d, &o) : o.clock_lcm ? run_lockstep(&d, &o) : run_live(&d, &o);
        stop_wheels(&d);
        if (rc == 0) { /* the counts of a run that went through; else its one error line */
            fprintf(stderr, "rfseekd: %" PRIu32 " steps, %" PRIu32 " decisions, %" PRIu32 " bad messages, %" PRIu32
                            " CAN send failures, %" PRIu32 " receiver heartbeats, seeker rejected %" PRIu32
                            " inputs (strategy %s, model %s, fit budget %" PRIu32 ", fit_early %s)\n",
                    d.steps, d.decided, d.bad_msgs, d.can_fail, d.app->stats.receiver, d.app->stats.rejected,
                    rfs_seek_strategy_name(d.app->seek.cfg.strategy), d.app->seek.model.ops->name,
                    d.app->seek.cfg.fit_budget, d.app->seek.cfg.fit_early ? "on" : "off");
        }
    }
    return finish(&d, &o, rc);
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, daemon_main(argc, argv));
}
