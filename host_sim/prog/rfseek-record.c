/* rfseek-record - run a simulated mission with the firmware application loop as the
 * controller and record its input stream (and its live output) in the replay format of
 * firmware/rfs_replay.h (docs/FIRMWARE.md, "The emulator port and the bit-identical test").
 *
 * The controller is the firmware's: every pose and RSSI measurement of the simulator is
 * encoded as the CAN frames of docs/CAN.md, recorded, and played into rfs_app through
 * rfs_replay_play() - the very code path of the emulator image - so the recorded stream,
 * replayed anywhere, must reproduce the live outputs byte for byte.
 *
 * The simulated receiver's heartbeat (docs/FAULTS.md, "The receiver heartbeat"; the
 * scenario's radio.receiver.heartbeat, once per control period) is recorded as the radio
 * module's RX_STATUS frame (0x121, --heartbeat can, the default), as a RECEIVER record
 * (--heartbeat record: the decoded path of the Linux port), or not at all (--heartbeat
 * off: the packets-only rule). The drop windows below that stop the RSSI frames stop it
 * too: a silent radio module.
 *
 * Faults for the safety tests are injected live and recorded:
 *   --drop T0:T1    no pose or RSSI frame reaches the controller in [T0, T1) seconds
 *   --drop-pose T0:T1, --drop-rssi T0:T1   only the poses / only the RSSI frames stop
 *   --bus-off T0:T1 the controller's CAN is bus-off in [T0, T1): its frames do not leave
 *   --reset T       a watchdog reset at T: the application starts from scratch
 * --sender-ahead S stamps the frames' Time fields S seconds ahead of the controller's clock
 * (senders in an epoch of their own, docs/CAN.md "Time on the bus").
 *
 * --candump FILE also writes the bus as candump -L would log it on can0 (docs/CAN.md, "CAN
 * logs"): each input frame at its receive time and the controller's WHEEL_CMD and STATUS
 * at each step (none while bus-off), in simulated microseconds from the start (1970-01-01).
 */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lx_candump.h"
#include "lx_err.h"
#include "hs_scenario.h"
#include "hs_sim.h"
#include "rfs_app.h"
#include "rfs_can.h"
#include "rfs_pathloss.h"
#include "rfs_replay.h"

#define MAX_WINDOWS 8

typedef enum hb_mode { HB_CAN = 0, HB_RECORD, HB_OFF } hb_mode_t;

typedef struct window {
    int64_t t0_us, t1_us;
} window_t;

typedef struct recorder {
    FILE *in;                   /* the recorded input stream */
    FILE *out;                  /* the live output stream, or NULL */
    lx_candump_t *dump;         /* --candump: the bus as a candump -L log, or NULL */
    const char *in_path;
    const char *tmp_in, *tmp_out; /* the temporary files (tmp_out NULL without `out`) */
    int write_failed;           /* a write to `in` failed */
    int live_failed;            /* a write to `out` failed */
    rfs_app_t *app;
    rfs_replay_player_t *player;
    rfs_can_tx_t tx;            /* the senders' counters (localisation, radio module) */
    uint8_t rssi_seq[RFS_CAN_MAX_SOURCES];
    window_t drop[MAX_WINDOWS];
    unsigned ndrop;
    window_t drop_pose[MAX_WINDOWS];
    unsigned ndrop_pose;
    window_t drop_rssi[MAX_WINDOWS];
    unsigned ndrop_rssi;
    window_t busoff[MAX_WINDOWS];
    unsigned nbusoff;
    int64_t reset_us[MAX_WINDOWS];
    unsigned nreset;
    unsigned next_reset;
    bool bus_off;
    hb_mode_t heartbeat;
    int64_t ahead_us;           /* --sender-ahead: the senders' clock minus the controller's */
    uint32_t records;
} recorder_t;

static const char PROG[] = "rfseek-record"; /* the prefix of its error lines (lx_err_print) */

static void put(recorder_t *r, const rfs_replay_rec_t *rec)
{
    uint8_t buf[RFS_REPLAY_MAX_RECORD];
    const uint32_t n = rfs_replay_encode(rec, buf, sizeof buf);
    if (n == 0u || fwrite(buf, 1, n, r->in) != n) {
        r->write_failed = 1;
    }
    r->records++;
}

/* Record an input and play it into the application. */
static void feed(recorder_t *r, const rfs_replay_rec_t *rec)
{
    put(r, rec);
    if (!rfs_replay_play(r->player, rec)) {
        lx_err_print(PROG, "%s: %s", r->in_path, rfs_replay_err_str(r->player->error));
        /* Nothing half-written: the temporary outputs go. */
        fclose(r->in);
        remove(r->tmp_in);
        if (r->out != NULL) {
            fclose(r->out);
            remove(r->tmp_out);
        }
        (void)lx_candump_close(r->dump, false, NULL, 0);
        exit(1);
    }
}

/* feed() as an rfs_replay_rec_fn (it exits on a player error). */
static bool feed_rec(void *ctx, const rfs_replay_rec_t *rec)
{
    feed(ctx, rec);
    return true;
}

/* The player's output: to the live stream, and its CAN_TX records (the controller's
 * frames on the bus) to the candump log. */
static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    recorder_t *r = ctx;
    if (r->out != NULL && fwrite(p, 1, n, r->out) != n) {
        r->live_failed = 1;
    }
    if (n == RFS_REPLAY_HEADER_LEN && rfs_replay_check_header(p, n) == 0) {
        return; /* the stream's header, written once at the start */
    }
    rfs_replay_rec_t rec;
    uint32_t used = 0;
    for (uint32_t at = 0; r->dump != NULL && at < n; at += used) {
        if (rfs_replay_parse(p + at, n - at, &used, &rec) != RFS_REPLAY_OK) {
            r->write_failed = 1; /* the player writes whole records: cannot happen */
            return;
        }
        if (rec.type == RFS_REPLAY_CAN_TX) {
            rfs_can_frame_t f = {rec.u.can.id, rec.u.can.dlc, {0}};
            memcpy(f.data, rec.u.can.data, 8);
            lx_candump_write(r->dump, rec.t_us, &f);
        }
    }
}

static bool in_window(const window_t *w, unsigned n, int64_t t)
{
    for (unsigned i = 0; i < n; i++) {
        if (t >= w[i].t0_us && t < w[i].t1_us) {
            return true;
        }
    }
    return false;
}

static void feed_can(recorder_t *r, int64_t t_us, const rfs_can_frame_t *f)
{
    rfs_replay_rec_t rec;
    memset(&rec, 0, sizeof rec);
    rec.type = RFS_REPLAY_CAN;
    rec.t_us = t_us;
    rec.u.can.id = f->id;
    rec.u.can.dlc = f->dlc;
    memcpy(rec.u.can.data, f->data, 8);
    if (r->dump != NULL) {
        lx_candump_write(r->dump, t_us, f);
    }
    feed(r, &rec);
}

static void on_pose(void *self, const rfs_pose_t *pose)
{
    recorder_t *r = self;
    if (in_window(r->drop, r->ndrop, pose->t_us) ||
        in_window(r->drop_pose, r->ndrop_pose, pose->t_us)) {
        return;
    }
    rfs_can_pose_t p = rfs_can_pose_from_core(pose);
    p.t_us32 = rfs_can_wrap_time(pose->t_us + r->ahead_us);
    rfs_can_frame_t xy, th;
    rfs_can_tx_pose(&r->tx, &p, &xy, &th);
    feed_can(r, pose->t_us, &xy);
    feed_can(r, pose->t_us, &th);
}

static void on_rssi(void *self, uint8_t src, int64_t t_us, int8_t dbm)
{
    recorder_t *r = self;
    if (in_window(r->drop, r->ndrop, t_us) || in_window(r->drop_rssi, r->ndrop_rssi, t_us) ||
        src >= RFS_CAN_MAX_SOURCES) {
        return;
    }
    const rfs_can_rssi_t m = {.src = src, .dbm = dbm, .seq = r->rssi_seq[src]++,
                              .t_us32 = rfs_can_wrap_time(t_us + r->ahead_us)};
    rfs_can_frame_t f;
    rfs_can_tx_rssi(&r->tx, &m, &f);
    feed_can(r, t_us, &f);
}

static void on_receiver(void *self, int64_t t_us)
{
    recorder_t *r = self;
    if (r->heartbeat == HB_OFF || in_window(r->drop, r->ndrop, t_us) ||
        in_window(r->drop_rssi, r->ndrop_rssi, t_us)) {
        return;
    }
    if (r->heartbeat == HB_CAN) {
        const rfs_can_receiver_t m = {.t_us32 = rfs_can_wrap_time(t_us + r->ahead_us)};
        rfs_can_frame_t f;
        rfs_can_tx_receiver(&r->tx, &m, &f);
        feed_can(r, t_us, &f);
        return;
    }
    rfs_replay_rec_t rec;
    memset(&rec, 0, sizeof rec);
    rec.type = RFS_REPLAY_RECEIVER;
    rec.t_us = t_us;
    rec.u.receiver_t_us = t_us;
    feed(r, &rec);
}

static void step(void *self, int64_t now_us, hs_ctrl_out_t *out)
{
    recorder_t *r = self;
    rfs_replay_rec_t rec;
    memset(&rec, 0, sizeof rec);
    while (r->next_reset < r->nreset && now_us >= r->reset_us[r->next_reset]) {
        rec.type = RFS_REPLAY_RESET;
        rec.t_us = now_us;
        feed(r, &rec);
        r->next_reset++;
        r->bus_off = false; /* a reset re-initialises the controller's CAN state */
    }
    const bool off = in_window(r->busoff, r->nbusoff, now_us);
    if (off != r->bus_off) {
        rec.type = RFS_REPLAY_BUS;
        rec.t_us = now_us;
        rec.u.bus_off = off ? 1u : 0u;
        feed(r, &rec);
        r->bus_off = off;
    }
    rec.type = RFS_REPLAY_STEP;
    rec.t_us = now_us;
    feed(r, &rec);

    const rfs_app_out_t *o = &r->app->last;
    memset(out, 0, sizeof *out);
    /* While bus-off the command does not reach the motors: the motor controller keeps
     * its last command until its own 200 ms timeout, which the simulator models; here
     * the controller has already commanded zero, so nothing stale is pending. */
    out->left_mm_s = r->bus_off ? 0 : o->left_mm_s;
    out->right_mm_s = r->bus_off ? 0 : o->right_mm_s;
    out->state = o->state;
    out->faults = (uint16_t)(o->faults & 0xFFu);
    out->decided = o->decided;
    out->decision = o->decision;
}

static int parse_window(const char *s, window_t *w)
{
    char *end;
    const double a = strtod(s, &end);
    if (end == s || *end != ':') {
        return -1;
    }
    const char *s2 = end + 1;
    const double b = strtod(s2, &end);
    if (end == s2 || *end != '\0' || !(a >= 0) || !(b > a) || b > 1e6) { /* NaN: refused */
        return -1;
    }
    w->t0_us = (int64_t)(a * 1e6 + 0.5);
    w->t1_us = (int64_t)(b * 1e6 + 0.5);
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rfseek-record SCENARIO.yaml -o IN.rfsr [options]\n"
            "Run a simulated mission with the firmware application loop as the controller\n"
            "and record its input stream (CAN frames, control steps, injected faults).\n"
            "  -o, --out FILE       recorded input stream (required)\n"
            "  --live-out FILE      also write the live output stream\n"
            "  --candump FILE       also write the bus as a candump -L log (interface can0)\n"
            "  --seed N             run seed (default: the scenario's)\n"
            "  --max-time S         stop after S simulated seconds (default: the scenario's)\n"
            "  --drop T0:T1         no pose/RSSI frames reach the controller in [T0, T1) s\n"
            "  --drop-pose T0:T1    only the pose frames stop in [T0, T1) s\n"
            "  --drop-rssi T0:T1    only the RSSI frames (and receiver heartbeats) stop in\n"
            "                       [T0, T1) s\n"
            "  --bus-off T0:T1      the controller's CAN is bus-off in [T0, T1) s\n"
            "  --reset T            watchdog reset at T s\n"
            "  --sender-ahead S     the senders stamp their frames S s ahead of the\n"
            "                       controller's clock (an epoch of their own; default 0)\n"
            "  --heartbeat MODE     the receiver heartbeat (when the scenario has it):\n"
            "                       can (RX_STATUS frames, default), record (RECEIVER\n"
            "                       records) or off (packets only)\n"
            "  --fit-budget N       the model's work units a fit slice (0: whole fits; the MCU\n"
            "                       configuration uses each model's, 0 for the ridge)\n"
            "  --fit-early on|off   with a fit budget, relearns begun while the base brakes\n"
            "                       (the MCU configuration's; default: the scenario's\n"
            "                       seek.fit_early, off; recorded in the CFG record)\n"
            "  --model NAME         internal model, overriding the scenario's: ridge, mlp, knn,\n"
            "                       radius, pathloss (recorded in the CFG record; the emulator\n"
            "                       image holds ridge, mlp and pathloss)\n"
            "  --strategy NAME      decision rule, overriding the scenario's: meta or meta-path\n"
            "  --p0-min DBM         path-loss floor at 1 m, overriding the scenario's\n"
            "                       seek.p0_min_dbm (the CFG record's choice, as a CONFIG\n"
            "                       frame's: docs/CAN.md)\n"
            "  --config-frame       send that choice (and the model) as a CONFIG frame at 0 s\n"
            "                       instead (seed: the run seed's low 24 bits)\n"
            "  -h, --help           this text\n");
}

static void die_opt(const char *opt, const char *val)
{
    lx_err_print(PROG, "%s: bad value '%s'", opt, val);
    exit(2);
}

/* The command line (the fault windows and the heartbeat mode go to the recorder). */
typedef struct options {
    const char *out_path, *live_path;
    const char *candump_path; /* --candump, or NULL */
    const char *scn_path;
    bool have_seed;
    unsigned long long seed;
    double max_time;       /* seconds; <= 0: the scenario's */
    uint32_t fit_budget;
    int fit_early;          /* --fit-early: 0 / 1, -1: the scenario's */
    const char *model_name; /* NULL: the scenario's */
    const char *strategy;   /* NULL: the scenario's */
    double p0_min;          /* dBm; NAN: the scenario's */
    bool config_frame;      /* --config-frame: the choice as a CONFIG frame */
} options_t;

/* One recording: the recorder, the simulator and the application it plays into (static
 * in main: the scenario, the environment and the application are large). */
typedef struct recording {
    recorder_t rec;
    hs_scenario_t sc;
    hs_sim_env_t env;
    rfs_app_t app;
    rfs_sample_t samples[RFS_APP_MAX_SAMPLES];
    rfs_replay_player_t player;
    uint64_t *model_state;
    char tmp_in[4096], tmp_out[4096]; /* the outputs until renamed */
} recording_t;

enum { RUN = -1 }; /* parse_options: go on (else the exit status) */

/* A fault window [T0, T1) of option opt into w[*n]; exits on a bad value. */
static void add_window(window_t *w, unsigned *n, const char *opt, const char *val)
{
    if (*n == MAX_WINDOWS || parse_window(val, &w[(*n)++]) != 0) {
        die_opt(opt, val);
    }
}

/* One option c of getopt_long with its optarg: RUN, or the exit status. */
static int parse_option(int c, char **argv, options_t *o, recorder_t *rec)
{
    char *end;
    switch (c) {
    case 'o':
    case 'l':
    case 'c': {
        const char *name = c == 'o' ? "-o/--out" : c == 'l' ? "--live-out" : "--candump";
        if (*optarg == '\0') {
            die_opt(name, optarg);
        }
        if (lx_err_path_opt(PROG, name, optarg) != 0) {
            return 2;
        }
        *(c == 'o' ? &o->out_path : c == 'l' ? &o->live_path : &o->candump_path) = optarg;
        break;
    }
    case 's':
        errno = 0;
        o->seed = strtoull(optarg, &end, 10); /* "-1" would wrap, "010" be octal */
        if (errno != 0 || end == optarg || *end != '\0' || optarg[0] == '-') {
            die_opt("--seed", optarg);
        }
        o->have_seed = true;
        break;
    case 't':
        o->max_time = strtod(optarg, &end);
        if (end == optarg || *end != '\0' || !(o->max_time > 0) || o->max_time > 1e5) {
            die_opt("--max-time", optarg);
        }
        break;
    case 'd': add_window(rec->drop, &rec->ndrop, "--drop", optarg); break;
    case 'P': add_window(rec->drop_pose, &rec->ndrop_pose, "--drop-pose", optarg); break;
    case 'R': add_window(rec->drop_rssi, &rec->ndrop_rssi, "--drop-rssi", optarg); break;
    case 'b': add_window(rec->busoff, &rec->nbusoff, "--bus-off", optarg); break;
    case 'f': {
        errno = 0;
        const unsigned long v = strtoul(optarg, &end, 10);
        if (errno != 0 || end == optarg || *end != '\0' || v > 100000ul) {
            die_opt("--fit-budget", optarg);
        }
        o->fit_budget = (uint32_t)v;
        break;
    }
    case 'A': {
        const double a = strtod(optarg, &end);
        if (end == optarg || *end != '\0' || !(a >= -1e6 && a <= 1e6)) {
            die_opt("--sender-ahead (seconds in [-1e6, 1e6])", optarg);
        }
        rec->ahead_us = (int64_t)llround(a * 1e6);
        break;
    }
    case 'r': {
        const double t = strtod(optarg, &end);
        if (rec->nreset == MAX_WINDOWS || end == optarg || *end != '\0' || !(t >= 0 && t <= 1e6)) {
            die_opt("--reset", optarg);
        }
        rec->reset_us[rec->nreset++] = (int64_t)(t * 1e6 + 0.5);
        break;
    }
    case 'm':
        if (rfs_models_lookup(optarg) == NULL ||
            strlen(optarg) > RFS_REPLAY_MODEL_NAME_MAX) {
            lx_err_print(PROG, "--model: unknown '%s' (ridge, mlp, knn, radius, pathloss)", optarg);
            return 2;
        }
        o->model_name = optarg;
        break;
    case 'S': {
        rfs_seek_strategy_t st;
        if (!rfs_seek_strategy_parse(optarg, &st) || (st != RFS_SEEK_META && st != RFS_SEEK_META_PATH)) {
            lx_err_print(PROG, "--strategy: expected meta or meta-path (the firmware's), got '%s'", optarg);
            return 2;
        }
        o->strategy = optarg;
        break;
    }
    case 'p':
        o->p0_min = strtod(optarg, &end);
        if (end == optarg || *end != '\0' || !(o->p0_min >= -200.0 && o->p0_min <= 100.0)) {
            die_opt("--p0-min (dBm in [-200, 100])", optarg);
        }
        break;
    case 'C': o->config_frame = true; break;
    case 'E':
        if (strcmp(optarg, "on") != 0 && strcmp(optarg, "off") != 0) {
            die_opt("--fit-early (on or off)", optarg);
        }
        o->fit_early = strcmp(optarg, "on") == 0;
        break;
    case 'H':
        if (strcmp(optarg, "can") == 0) {
            rec->heartbeat = HB_CAN;
        } else if (strcmp(optarg, "record") == 0) {
            rec->heartbeat = HB_RECORD;
        } else if (strcmp(optarg, "off") == 0) {
            rec->heartbeat = HB_OFF;
        } else {
            die_opt("--heartbeat (can, record or off)", optarg);
        }
        break;
    case 'h': usage(stdout); return 0;
    case ':': lx_err_print(PROG, "missing value for '%s' (see --help)", argv[optind - 1]); return 2;
    default:
        /* An unknown short option is optopt (its word may hold more options); an
         * unknown or ambiguous long one (optopt 0), or --help given a value (optopt
         * 'h'), is the word just passed. */
        if (optopt != 0 && optopt != 'h') {
            lx_err_print(PROG, "unknown option '-%c' (see --help)", optopt);
        } else {
            lx_err_print(PROG, "unknown option '%s' (see --help)", argv[optind - 1]);
        }
        return 2;
    }
    return RUN;
}

/* The command line into *o and *rec: RUN, or the exit status. */
static int parse_options(int argc, char **argv, options_t *o, recorder_t *rec)
{
    static const struct option opts[] = {
        {"out", required_argument, 0, 'o'},     {"live-out", required_argument, 0, 'l'},
        {"seed", required_argument, 0, 's'},    {"max-time", required_argument, 0, 't'},
        {"drop", required_argument, 0, 'd'},    {"bus-off", required_argument, 0, 'b'},
        {"reset", required_argument, 0, 'r'},   {"help", no_argument, 0, 'h'},
        {"drop-pose", required_argument, 0, 'P'}, {"drop-rssi", required_argument, 0, 'R'},
        {"fit-budget", required_argument, 0, 'f'}, {"model", required_argument, 0, 'm'},
        {"heartbeat", required_argument, 0, 'H'},  {"candump", required_argument, 0, 'c'},
        {"strategy", required_argument, 0, 'S'},   {"p0-min", required_argument, 0, 'p'},
        {"config-frame", no_argument, 0, 'C'},     {"fit-early", required_argument, 0, 'E'},
        {"sender-ahead", required_argument, 0, 'A'},
        {0, 0, 0, 0}};
    memset(o, 0, sizeof *o);
    o->max_time = -1;
    o->fit_early = -1;
    o->p0_min = NAN;
    /* getopt's own messages would echo a bad option raw (and the usage follows on stderr):
     * it stays quiet and the one line is ours. A leading ':' tells a missing value (':')
     * from an unknown option ('?'). */
    static const char shortopts[] = ":o:h";
    /* getopt_long takes any unambiguous prefix ("--se 3" for --seed): only the names
     * --help lists are options. A value given apart (-o X, --seed X) is skipped. */
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; i++) {
        const char *a = argv[i];
        const size_t n = strncmp(a, "--", 2) == 0 ? strcspn(a + 2, "=") : 0;
        const struct option *m = NULL;
        for (size_t k = 0; n > 0 && opts[k].name != NULL; k++) {
            m = strlen(opts[k].name) == n && strncmp(opts[k].name, a + 2, n) == 0 ? &opts[k] : m;
        }
        if (n > 0 && m == NULL) {
            lx_err_print(PROG, "unknown option '%s' (see --help)", a);
            return 2;
        }
        i += (strcmp(a, "-o") == 0 || (m != NULL && m->has_arg == required_argument && a[2 + n] == '\0'));
    }
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, shortopts, opts, NULL)) != -1) {
        const int rc = parse_option(c, argv, o, rec);
        if (rc != RUN) {
            return rc;
        }
    }
    if (optind >= argc || o->out_path == NULL) {
        lx_err_print(PROG, "%s (see --help)", o->out_path == NULL ? "-o IN.rfsr is required" : "a SCENARIO is required");
        return 2;
    }
    if (optind + 1 != argc) {
        lx_err_print(PROG, "'%s': only one SCENARIO expected (see --help)", argv[optind + 1]);
        return 2;
    }
    o->scn_path = argv[optind];
    /* Outputs checked before any work: neither may be the scenario or the other. */
    if (lx_err_same_file(PROG, o->scn_path, o->out_path) != 0 ||
        lx_err_check_dest(PROG, o->out_path) != 0) {
        return 1;
    }
    if (o->live_path != NULL && (lx_err_same_file(PROG, o->scn_path, o->live_path) != 0 ||
                                 lx_err_check_dest(PROG, o->live_path) != 0 ||
                                 lx_err_same_dest(PROG, o->out_path, o->live_path) != 0)) {
        return 1;
    }
    if (o->candump_path != NULL &&
        (lx_err_same_file(PROG, o->scn_path, o->candump_path) != 0 ||
         lx_err_check_dest(PROG, o->candump_path) != 0 ||
         lx_err_same_dest(PROG, o->out_path, o->candump_path) != 0 ||
         (o->live_path != NULL && lx_err_same_dest(PROG, o->live_path, o->candump_path) != 0))) {
        return 1;
    }
    return RUN;
}

/* The scenario and its environment, checked against what the image holds: 0, or 1 after
 * an error line. */
static int open_scenario(recording_t *s, options_t *o)
{
    char err[512];
    if (hs_scenario_load(o->scn_path, &s->sc, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    if (o->max_time > 0) {
        s->sc.stop_time_s = o->max_time;
    }
    if (strcmp(s->sc.target, "pdr") == 0) {
        lx_err_print(PROG, "%s: target: pdr is not available on the firmware (the CAN RSSI frame carries no "
                 "sequence number; docs/MODELS.md)", o->scn_path);
        return 1;
    }
    if (o->model_name == NULL) {
        o->model_name = s->sc.model; // checked against the registry by the scenario loader
    }
    if (o->strategy == NULL) {
        o->strategy = s->sc.strategy;
    }
    if (isnan(o->p0_min)) {
        o->p0_min = s->sc.seek_p0_min_dbm;
    }
    if (o->fit_early < 0) {
        o->fit_early = s->sc.seek_fit_early > 0;
    }
    if (hs_sim_env_open(&s->env, &s->sc, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    const rfs_map_t *m = &s->env.core.map;
    if (rfs_map_bytes(m->w, m->h) > RFS_APP_MAX_MAP_BYTES) {
        lx_err_print(PROG, "%s: map of %u x %u cells is larger than the image holds (%u bytes per grid)",
                 o->scn_path, m->w, m->h, RFS_APP_MAX_MAP_BYTES);
        return 1;
    }
    return 0;
}

/* The output streams, as temporary files renamed at the end (nothing half-written): 0,
 * or 1 after an error line. */
static int open_outputs(recording_t *s, const options_t *o)
{
    recorder_t *rec = &s->rec;
    snprintf(s->tmp_in, sizeof s->tmp_in, "%s.tmp.%ld", o->out_path, (long)getpid());
    snprintf(s->tmp_out, sizeof s->tmp_out, "%s.tmp.%ld", o->live_path ? o->live_path : "", (long)getpid());
    rec->in = fopen(s->tmp_in, "wb");
    if (rec->in == NULL) {
        lx_err_print(PROG, "%s: %s", o->out_path, strerror(errno));
        return 1;
    }
    if (o->live_path != NULL && (rec->out = fopen(s->tmp_out, "wb")) == NULL) {
        lx_err_print(PROG, "%s: %s", o->live_path, strerror(errno));
        fclose(rec->in);
        remove(s->tmp_in);
        return 1;
    }
    char err[512];
    if (o->candump_path != NULL &&
        (rec->dump = lx_candump_open(o->candump_path, LX_CANDUMP_DEFAULT_IF, err, sizeof err)) == NULL) {
        lx_err_print(PROG, "%s", err);
        fclose(rec->in);
        remove(s->tmp_in);
        if (rec->out != NULL) {
            fclose(rec->out);
            remove(s->tmp_out);
        }
        return 1;
    }
    rec->in_path = o->out_path;
    rec->tmp_in = s->tmp_in;
    rec->tmp_out = s->tmp_out;
    return 0;
}

/* The stream's header and the player over the application: 0, or 1 after an error line. */
static int start_player(recording_t *s)
{
    recorder_t *rec = &s->rec;
    rec->app = &s->app;
    rec->player = &s->player;
    rfs_can_tx_init(&rec->tx);
    uint8_t hdr[RFS_REPLAY_HEADER_LEN];
    rfs_replay_header(hdr);
    if (fwrite(hdr, 1, sizeof hdr, rec->in) != sizeof hdr) {
        rec->write_failed = 1;
    }
    // The host holds every model (the CFG record names it; the emulator may refuse it).
    const uint32_t model_bytes = (rfs_models_max_state_bytes() + 7u) & ~7u;
    s->model_state = aligned_alloc(RFS_MODELS_STATE_ALIGN, model_bytes);
    if (s->model_state == NULL) {
        fprintf(stderr, "rfseek-record: out of memory\n");
        return 1;
    }
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.follow_epoch = true; /* as the STM32 image (rfs_app_cfg_mcu) */
    cfg.samples = s->samples;
    cfg.model_state = s->model_state;
    cfg.model_state_bytes = model_bytes;
    rfs_replay_player_init(&s->player, &s->app, &cfg, sink, rec);
    return 0;
}

/* The configuration records: CFG, MAP and the map's grids in chunks; the choice of
 * strategy, model and P0 floor in the CFG or, with --config-frame, in a CONFIG frame on the
 * bus before any input (docs/CAN.md, "0x130 CONFIG"). */
static void record_config(recording_t *s, const options_t *o, uint64_t run_seed)
{
    recorder_t *rec = &s->rec;
    const rfs_map_t *m = &s->env.core.map;
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_CFG;
    r.u.cfg.seed = run_seed;
    r.u.cfg.target = s->sc.nsources == 2u ? RFS_APP_TARGET_BRIDGE : RFS_APP_TARGET_RSSI;
    r.u.cfg.node = 1u;
    r.u.cfg.fit_budget = o->fit_budget;
    r.u.cfg.fit_early = o->fit_early > 0;
    rfs_seek_strategy_t st = RFS_SEEK_META;
    (void)rfs_seek_strategy_parse(o->strategy, &st);
    const int16_t p0 = isnan(o->p0_min) ? (int16_t)(rfs_pathloss_cfg_default().p0_min / 512)
                                        : (int16_t)lround(o->p0_min * 128.0);
    // The ridge is every player's base (a v1 CFG); the paper's meta with the model's own
    // floor too: no choice then.
    if (!o->config_frame && strcmp(o->model_name, "ridge") != 0) {
        const size_t n = strlen(o->model_name); // registry names are <= 15 bytes (checked above)
        memcpy(r.u.cfg.model, o->model_name, n < RFS_REPLAY_MODEL_NAME_MAX ? n : RFS_REPLAY_MODEL_NAME_MAX);
    }
    if (!o->config_frame && (st != RFS_SEEK_META || !isnan(o->p0_min))) {
        r.u.cfg.chosen = true;
        r.u.cfg.strategy = (uint8_t)st;
        r.u.cfg.p0_min = p0;
    }
    feed(rec, &r);
    const rfs_app_map_t am = {m->w, m->h, m->res, m->origin_x, m->origin_y, s->env.core.free_bits,
                              s->env.core.wall_bits};
    (void)rfs_replay_map_records(&am, feed_rec, rec);
    if (o->config_frame) {
        // fit_early: the CFG record's, kept (a frame with the field would not change the stream's
        // meaning but would its bytes).
        rfs_can_config_t k = {r.u.cfg.target, (uint8_t)st, 0, p0, (uint32_t)(run_seed & 0xFFFFFFu),
                              RFS_CAN_FIT_EARLY_KEEP};
        for (uint8_t c = 0; c < (uint8_t)RFS_CAN_NMODELS; c++) {
            k.model = strcmp(rfs_can_model_name(c), o->model_name) == 0 ? c : k.model;
        }
        rfs_can_frame_t f;
        rfs_can_tx_config(&rec->tx, &k, &f);
        feed_can(rec, 0, &f);
    }
}

/* The mission with the recorder as the controller, the END record, and the outputs
 * renamed into place: the exit status. */
static int run_mission(recording_t *s, const options_t *o, uint64_t run_seed)
{
    recorder_t *rec = &s->rec;
    char err[512];
    hs_ctrl_t ctrl;
    memset(&ctrl, 0, sizeof ctrl);
    ctrl.name = "firmware";
    ctrl.self = rec;
    ctrl.period_us = RFS_APP_PERIOD_US;
    ctrl.on_pose = on_pose;
    ctrl.on_rssi = on_rssi;
    ctrl.on_receiver = on_receiver;
    ctrl.step = step;
    hs_sim_result_t res;
    const int rc = hs_sim_run(&s->env, run_seed, &ctrl, NULL, &res, err, sizeof err);
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_END;
    put(rec, &r);
    const bool in_failed = fclose(rec->in) != 0 || rec->write_failed;
    const bool out_failed = (rec->out != NULL && fclose(rec->out) != 0) || rec->live_failed;
    const bool ok = rc == 0 && !in_failed && !out_failed;
    char derr[512];
    if (ok && lx_candump_close(rec->dump, true, derr, sizeof derr) != 0) {
        lx_err_print(PROG, "%s", derr);
        remove(s->tmp_in);
        if (o->live_path != NULL) {
            remove(s->tmp_out);
        }
        return 1;
    }
    if (!ok) {
        (void)lx_candump_close(rec->dump, false, NULL, 0);
        lx_err_print(PROG, "%s: %s", rc != 0 ? o->scn_path : in_failed ? o->out_path : o->live_path,
                     rc != 0 ? err : "write failed");
        remove(s->tmp_in);
        if (o->live_path != NULL) {
            remove(s->tmp_out);
        }
        return 1;
    }
    const bool in_moved = rename(s->tmp_in, o->out_path) == 0;
    if (!in_moved || (o->live_path != NULL && rename(s->tmp_out, o->live_path) != 0)) {
        lx_err_print(PROG, "%s: %s", in_moved ? o->live_path : o->out_path, strerror(errno));
        remove(s->tmp_in);
        if (o->live_path != NULL) {
            remove(s->tmp_out);
        }
        return 1;
    }
    printf("recorded %" PRIu32 " records, %" PRIu32 " steps, %.1f s simulated, %s, "
           "%u decisions, final distance %.2f m\n",
           rec->records, s->player.steps, res.sim_time_s, res.end, res.iterations,
           res.final_distance_m);
    hs_sim_env_close(&s->env);
    return 0;
}

static int record_main(int argc, char **argv)
{
    static recording_t s;
    options_t o;
    int rc = parse_options(argc, argv, &o, &s.rec);
    if (rc != RUN) {
        return rc;
    }
    if (open_scenario(&s, &o) != 0 || open_outputs(&s, &o) != 0 || start_player(&s) != 0) {
        return 1;
    }
    const uint64_t run_seed = o.have_seed ? o.seed : s.sc.seed;
    record_config(&s, &o, run_seed);
    return run_mission(&s, &o, run_seed);
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, record_main(argc, argv));
}
