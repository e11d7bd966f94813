/* rfseek-replay - the host build of the firmware application loop on a recorded stream
 * (firmware/rfs_replay.h) or a CAN log (candump -L), and a printer for both.
 *
 *   rfseek-replay IN.rfsr -o OUT.rfso             play an input stream, write the output stream
 *   rfseek-replay IN.log --map MAP.yaml -o OUT.rfso   play a candump -L log (docs/CAN.md)
 *   rfseek-replay --print FILE                    print a stream or a log, one record per line
 *
 * Playing runs rfs_replay_play(), the driver loop the emulator image runs, so the output
 * must equal the emulator's byte for byte. A candump log becomes the records a stream
 * would hold: CFG and MAP from the options, a CAN record per frame of the bus, a STEP at
 * each of the controller's WHEEL_CMD frames (the controller ran then), END at its end.
 * Errors: one line naming the file and the byte offset or line, and the reason; exit 1;
 * no output file is left behind.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lx_candump.h"
#include "lx_err.h"
#include "lx_map.h"
#include "rfs_app.h"
#include "rfs_replay.h"

typedef struct sink_ctx {
    FILE *f;
    int failed;
} sink_ctx_t;

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    sink_ctx_t *s = ctx;
    if (fwrite(p, 1, n, s->f) != n) {
        s->failed = 1;
    }
}

static const char PROG[] = "rfseek-replay"; /* the prefix of its error lines (lx_err_print) */

/* The input read as it is parsed, through a window: memory stays RFS_REPLAY_WINDOW
 * whatever the file (/dev/zero, a stream of hours, an endless pipe), and reading stops at
 * the END record (a stream) or the end of the file (a log, line by line). */
#define RFS_REPLAY_WINDOW (1u << 16)
typedef struct in_stream {
    FILE *f;
    uint8_t buf[RFS_REPLAY_WINDOW];
    size_t pos, len; /* unparsed bytes: buf[pos .. len) */
    size_t base;     /* file offset of buf[0] */
    int eof;
} in_stream_t;

/* At least `want` (<= RFS_REPLAY_WINDOW) unparsed bytes unless the file ends first: the
 * count there is. */
static size_t in_fill(in_stream_t *s, size_t want)
{
    if (s->len - s->pos < want && !s->eof) {
        memmove(s->buf, s->buf + s->pos, s->len - s->pos);
        s->base += s->pos;
        s->len -= s->pos;
        s->pos = 0;
        const size_t n = fread(s->buf + s->len, 1, sizeof s->buf - s->len, s->f);
        s->len += n;
        s->eof = s->len < sizeof s->buf;
    }
    return s->len - s->pos;
}

/* 0, or 1 after a message when reading `in` failed. */
static int in_error(const in_stream_t *in, const char *in_path)
{
    if (ferror(in->f)) {
        lx_err_print(PROG, "%s: read error", in_path);
        return 1;
    }
    return 0;
}

static const char *type_name(rfs_replay_type_t t)
{
    switch (t) {
    case RFS_REPLAY_CFG: return "CFG";
    case RFS_REPLAY_MAP: return "MAP";
    case RFS_REPLAY_MAP_FREE: return "MAP_FREE";
    case RFS_REPLAY_MAP_WALL: return "MAP_WALL";
    case RFS_REPLAY_POSE: return "POSE";
    case RFS_REPLAY_RSSI: return "RSSI";
    case RFS_REPLAY_CAN: return "CAN";
    case RFS_REPLAY_RECEIVER: return "RECEIVER";
    case RFS_REPLAY_STEP: return "STEP";
    case RFS_REPLAY_BUS: return "BUS";
    case RFS_REPLAY_RESET: return "RESET";
    case RFS_REPLAY_END: return "END";
    case RFS_REPLAY_OUT: return "OUT";
    case RFS_REPLAY_DECISION: return "DECISION";
    case RFS_REPLAY_CAN_TX: return "CAN_TX";
    default: return "?";
    }
}

/* One line per record: type, time (us), then the fields. */
static void print_rec(const rfs_replay_rec_t *r)
{
    printf("%s\t%" PRId64, type_name(r->type), r->t_us);
    switch (r->type) {
    case RFS_REPLAY_CFG:
        printf("\tseed=%" PRIu64 "\ttarget=%u\tnode=%u", r->u.cfg.seed, r->u.cfg.target,
               r->u.cfg.node);
        if (r->u.cfg.fit_early) {
            printf("\tfit_early=1");
        }
        if (r->u.cfg.model[0] != '\0') {
            printf("\tmodel=%s", r->u.cfg.model);
        }
        if (r->u.cfg.chosen) {
            printf("\tstrategy=%s\tp0_min=%d", rfs_seek_strategy_name((rfs_seek_strategy_t)r->u.cfg.strategy),
                   r->u.cfg.p0_min);
        }
        break;
    case RFS_REPLAY_MAP:
        printf("\tw=%u\th=%u\tres_q16=%d\tox_q16=%d\toy_q16=%d\twall=%u", r->u.map.w,
               r->u.map.h, r->u.map.res, r->u.map.origin_x, r->u.map.origin_y,
               r->u.map.has_wall);
        break;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL:
        printf("\toffset=%" PRIu32 "\tn=%u", r->u.chunk.offset, r->u.chunk.n);
        break;
    case RFS_REPLAY_POSE:
        printf("\tt=%" PRId64 "\tx_q16=%d\ty_q16=%d\ttheta_q16=%d", r->u.pose.t_us, r->u.pose.x,
               r->u.pose.y, r->u.pose.theta);
        break;
    case RFS_REPLAY_RSSI:
        printf("\tt=%" PRId64 "\tsrc=%u\tdbm=%d", r->u.rssi.t_us, r->u.rssi.src, r->u.rssi.dbm);
        break;
    case RFS_REPLAY_RECEIVER:
        printf("\tt=%" PRId64, r->u.receiver_t_us);
        break;
    case RFS_REPLAY_CAN:
    case RFS_REPLAY_CAN_TX:
        printf("\tid=%03" PRIX32 "\tdlc=%u\tdata=", r->u.can.id, r->u.can.dlc);
        for (unsigned i = 0; i < r->u.can.dlc; i++) {
            printf("%02X", r->u.can.data[i]);
        }
        break;
    case RFS_REPLAY_BUS:
        printf("\toff=%u", r->u.bus_off);
        break;
    case RFS_REPLAY_OUT:
        printf("\tleft=%d\tright=%d\tstate=%d\tfaults=0x%04x\tdecided=%d", r->u.out.left_mm_s,
               r->u.out.right_mm_s, (int)r->u.out.state, r->u.out.faults, r->u.out.decided);
        break;
    case RFS_REPLAY_DECISION: {
        const rfs_seek_decision_t *d = &r->u.out.decision;
        printf("\titer=%" PRIu32 "\tkind=%d\trelearned=%d\tline_search=%d\tprev=%d"
               "\tprediction_q16=%d\tmean_q16=%d\teps_q16=%d\tx_q16=%d\ty_q16=%d"
               "\tgoal_x_q16=%d\tgoal_y_q16=%d\tsamples=%u",
               d->iteration, (int)d->kind, d->relearned, d->line_search, (int)d->prev,
               d->prediction, d->mean, d->epsilon, d->x, d->y, d->goal_x, d->goal_y,
               d->samples);
        break;
    }
    default:
        break;
    }
    printf("\n");
}

static void usage(FILE *f)
{
    fprintf(f, "usage: rfseek-replay IN.rfsr -o OUT.rfso\n"
               "       rfseek-replay IN.log --map MAP.yaml [options] -o OUT.rfso\n"
               "       rfseek-replay --print FILE\n"
               "Play a recorded input stream, or a candump -L log of the robot's CAN bus,\n"
               "through the host build of the firmware application loop (the emulator image\n"
               "runs the same code), or print a stream or a log.\n"
               "  -o FILE          output stream (written to a temporary file, then renamed)\n"
               "  --print          print every record of FILE as one TSV line (a log: the\n"
               "                   CAN and STEP records it is played as)\n"
               "A candump -L log (docs/CAN.md, \"CAN logs\") is played as a stream: its frames\n"
               "as CAN records, a control step at each WHEEL_CMD (100) frame; the controller:\n"
               "  --map FILE       ROS map_server YAML (required)\n"
               "  --res M          core map cell size, metres (default 0.1)\n"
               "  --seed N         seed of the controller's random source (default 1)\n"
               "  --target NAME    rssi (default) or bridge\n"
               "  --model NAME     ridge (default), mlp, knn, radius, pathloss\n"
               "  --fit-budget N   the model's work units a fit slice: one each step, up to ten\n"
               "                   after it (default 0: whole fits)\n"
               "  --fit-early on|off  relearns begun while the base brakes (the STM32\n"
               "                   configuration's; default off)\n"
               "  -h, --help       this text\n");
}

/* An input stream ends with its END record (an output stream has none); without it the
 * recording was cut and a replay would stop early with exit 0. 0, or 1 after a message. */
static int check_end(const char *in_path, size_t pos, int ended, int inputs)
{
    if (!ended && (inputs || pos == RFS_REPLAY_HEADER_LEN)) {
        lx_err_print(PROG, "%s: offset %zu: truncated (%s)", in_path, pos,
                     pos == RFS_REPLAY_HEADER_LEN ? "only the header" : "no END record");
        return 1;
    }
    return 0;
}

/* The command line. */
typedef struct options {
    const char *in_path, *out_path;
    bool print;
    /* A candump log's controller: what its CFG and MAP records would say. */
    const char *map_path;   /* --map */
    double res;             /* --res, metres per core cell */
    uint64_t seed;          /* --seed */
    uint8_t target;         /* --target: rfs_app_target_t */
    const char *model;      /* --model, NULL: the ridge */
    uint32_t fit_budget;    /* --fit-budget */
    bool fit_early;         /* --fit-early */
    const char *ctl_opt;    /* the first of these options given, or NULL */
} options_t;

enum { RUN = -1 }; /* parse_options: go on (else the exit status) */

/* Option a with value v (one of the controller's): RUN, or 2 after a message. */
static int parse_ctl(options_t *o, const char *a, const char *v)
{
    char *end;
    errno = 0;
    if (o->ctl_opt == NULL) {
        o->ctl_opt = a;
    }
    if (strcmp(a, "--map") == 0) {
        o->map_path = v;
    } else if (strcmp(a, "--res") == 0) {
        o->res = strtod(v, &end);
        if (*v == '\0' || *end != '\0' || !(o->res >= 0.01 && o->res <= 1.0)) {
            lx_err_print(PROG, "--res: expected metres in [0.01, 1], got '%s'", v);
            return 2;
        }
    } else if (strcmp(a, "--seed") == 0) {
        o->seed = strtoull(v, &end, 10);
        if (*v == '\0' || *v == '-' || *end != '\0' || errno != 0) {
            lx_err_print(PROG, "--seed: expected a non-negative integer, got '%s'", v);
            return 2;
        }
    } else if (strcmp(a, "--target") == 0) {
        if (strcmp(v, "rssi") != 0 && strcmp(v, "bridge") != 0) {
            lx_err_print(PROG, "--target: expected rssi or bridge, got '%s'", v);
            return 2;
        }
        o->target = strcmp(v, "bridge") == 0 ? RFS_APP_TARGET_BRIDGE : RFS_APP_TARGET_RSSI;
    } else if (strcmp(a, "--model") == 0) {
        if (rfs_models_lookup(v) == NULL || strlen(v) > RFS_REPLAY_MODEL_NAME_MAX) {
            lx_err_print(PROG, "--model: expected ridge, mlp, knn, radius or pathloss, got '%s'", v);
            return 2;
        }
        o->model = strcmp(v, "ridge") == 0 ? NULL : v;
    } else if (strcmp(a, "--fit-early") == 0) {
        if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0) {
            lx_err_print(PROG, "--fit-early: expected on or off, got '%s'", v);
            return 2;
        }
        o->fit_early = strcmp(v, "on") == 0;
    } else {
        const unsigned long n = strtoul(v, &end, 10);
        if (*v == '\0' || *v == '-' || *end != '\0' || errno != 0 || n > 100000ul) {
            lx_err_print(PROG, "--fit-budget: expected work units in [0, 100000], got '%s'", v);
            return 2;
        }
        o->fit_budget = (uint32_t)n;
    }
    return RUN;
}

/* The command line into *o: RUN, or the exit status (--help, a bad option). */
static int parse_options(int argc, char **argv, options_t *o)
{
    static const char *const ctl[] = {"--map", "--res", "--seed", "--target", "--model", "--fit-budget",
                                      "--fit-early"};
    memset(o, 0, sizeof *o);
    o->res = 0.1;
    o->seed = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool is_ctl = false;
        for (size_t k = 0; k < sizeof ctl / sizeof ctl[0]; k++) {
            is_ctl = is_ctl || strcmp(a, ctl[k]) == 0;
        }
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--print") == 0) {
            o->print = true;
        } else if (strcmp(a, "-o") == 0 || is_ctl) {
            if (i + 1 == argc) {
                lx_err_print(PROG, "%s: missing value (see --help)", a);
                return 2;
            }
            const char *v = argv[++i];
            if (*v == '\0' && (a[1] == 'o' || strcmp(a, "--map") == 0)) {
                lx_err_print(PROG, "%s: empty value (see --help)", a);
                return 2;
            }
            if ((a[1] == 'o' || strcmp(a, "--map") == 0) && lx_err_path_opt(PROG, a, v) != 0) {
                return 2;
            }
            if (a[1] == 'o') {
                o->out_path = v;
            } else if (parse_ctl(o, a, v) != RUN) {
                return 2;
            }
        } else if (a[0] == '-') {
            lx_err_print(PROG, "%s: unknown option (see --help)", a);
            return 2;
        } else if (o->in_path == NULL) {
            o->in_path = a;
        } else {
            lx_err_print(PROG, "%s: only one input stream expected (see --help)", a);
            return 2;
        }
    }
    if (o->in_path == NULL || !o->print == (o->out_path == NULL)) {
        lx_err_print(PROG, "%s (see --help)", o->in_path == NULL ? "an input stream is required"
                                    : o->print ? "--print and -o exclude each other"
                                               : "-o OUT.rfso or --print is required");
        return 2;
    }
    if (!o->print && (lx_err_same_file(PROG, o->in_path, o->out_path) != 0 ||
                      lx_err_check_dest(PROG, o->out_path) != 0)) {
        return 1;
    }
    return RUN;
}

/* Where the records go: printed, or played into the application. */
typedef struct run {
    bool print;
    rfs_replay_player_t *player;
} run_t;

/* One record to the run (an rfs_replay_rec_fn): false when the player stopped. */
static bool take(void *ctx, const rfs_replay_rec_t *rec)
{
    run_t *r = ctx;
    if (r->print) {
        print_rec(rec);
        return true;
    }
    return rfs_replay_play(r->player, rec);
}

/* The records of an rfseek stream after its header, until END or the end of the file:
 * 0, or 1 after a message naming the offset. */
static int play_stream(const char *in_path, in_stream_t *in, run_t *r)
{
    int ended = 0, inputs = 0;
    size_t left;
    while ((left = in_fill(in, RFS_REPLAY_MAX_RECORD)) > 0) {
        rfs_replay_rec_t rec;
        uint32_t used = 0;
        const size_t pos = in->base + in->pos;
        const rfs_replay_status_t st = rfs_replay_parse(in->buf + in->pos, (uint32_t)left, &used, &rec);
        if (st != RFS_REPLAY_OK) {
            lx_err_print(PROG, "%s: offset %zu: %s", in_path, pos,
                     st == RFS_REPLAY_NEED_MORE ? "truncated record" : rec.error);
            return 1;
        }
        if (!take(r, &rec)) {
            lx_err_print(PROG, "%s: offset %zu: %s", in_path, pos, rfs_replay_err_str(r->player->error));
            return 1;
        }
        in->pos += used;
        inputs |= rec.type < RFS_REPLAY_END;
        if (rec.type == RFS_REPLAY_END) {
            ended = 1;
            break;
        }
    }
    if (in_error(in, in_path) != 0) {
        return 1;
    }
    return check_end(in_path, in->base + in->pos, ended, inputs);
}

/* A candump log's CFG and MAP records, from the options: 0, or 1 after a message. */
static int candump_config(const options_t *o, run_t *r)
{
    char err[512];
    lx_map_t m;
    lx_core_map_t core;
    memset(&m, 0, sizeof m);
    memset(&core, 0, sizeof core);
    int rc = 0;
    if (lx_map_load(o->map_path, &m, err, sizeof err) != 0 || lx_map_to_core(&m, o->res, NULL, &core, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        rc = 1;
    } else {
        rfs_replay_rec_t cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.type = RFS_REPLAY_CFG;
        cfg.u.cfg.seed = o->seed;
        cfg.u.cfg.target = o->target;
        cfg.u.cfg.node = 1u; /* the default node id, as rfseek-record's */
        cfg.u.cfg.fit_budget = o->fit_budget;
        cfg.u.cfg.fit_early = o->fit_early;
        if (o->model != NULL) {
            memcpy(cfg.u.cfg.model, o->model, strlen(o->model)); /* <= 15 bytes: checked */
        }
        const rfs_app_map_t am = {core.map.w, core.map.h, core.map.res, core.map.origin_x,
                                  core.map.origin_y, core.free_bits, core.wall_bits};
        if (!take(r, &cfg) || !rfs_replay_map_records(&am, take, r)) {
            lx_err_print(PROG, "%s: %s", o->map_path, rfs_replay_err_str(r->player->error));
            rc = 1;
        }
    }
    lx_core_map_free(&core);
    lx_map_free(&m);
    return rc;
}

/* A candump -L log, read line by line, as the records of a stream: each classic 11-bit
 * data frame a CAN record at its time, but the controller's own: its WHEEL_CMD is a STEP
 * (the controller ran then), its STATUS nothing; END at the end. Remote, error and 29-bit
 * frames are not on our protocol and are passed over. 0, or 1 after a message. */
static int play_candump(const options_t *o, in_stream_t *in, run_t *r)
{
    if (!r->print && candump_config(o, r) != 0) {
        return 1;
    }
    char bus[LX_CANDUMP_IFNAME_MAX + 1u] = "";
    unsigned long line = 0, steps = 0;
    size_t left;
    /* The longest line, its '\r' and '\n': a line not ended within is too long. */
    while ((left = in_fill(in, LX_CANDUMP_LINE_MAX + 2u)) > 0) {
        line++;
        const uint8_t *at = in->buf + in->pos;
        const uint8_t *nl = memchr(at, '\n', left);
        const size_t n = nl != NULL ? (size_t)(nl - at) : left;
        lx_candump_rec_t c;
        const char *why = NULL;
        if (lx_candump_parse((const char *)at, n, &c, &why) != 0) {
            lx_err_print(PROG, "%s:%lu: %s", o->in_path, line, why);
            return 1;
        }
        in->pos += n + (nl != NULL ? 1u : 0u);
        if (bus[0] == '\0') {
            memcpy(bus, c.ifname, sizeof bus);
        } else if (strcmp(bus, c.ifname) != 0) {
            lx_err_print(PROG, "%s:%lu: interface %s after %s: a log of one bus is played (keep its lines only)",
                         o->in_path, line, c.ifname, bus);
            return 1;
        }
        if (c.kind != LX_CANDUMP_DATA || c.ext || c.id == RFS_CAN_ID_STATUS) {
            continue;
        }
        rfs_replay_rec_t rec;
        memset(&rec, 0, sizeof rec);
        rec.t_us = c.t_us;
        if (c.id == RFS_CAN_ID_WHEEL_CMD) {
            rec.type = RFS_REPLAY_STEP;
            steps++;
        } else {
            rec.type = RFS_REPLAY_CAN;
            rec.u.can.id = c.id;
            rec.u.can.dlc = c.dlc;
            memcpy(rec.u.can.data, c.data, sizeof c.data);
        }
        if (!take(r, &rec)) {
            lx_err_print(PROG, "%s:%lu: %s", o->in_path, line, rfs_replay_err_str(r->player->error));
            return 1;
        }
    }
    if (in_error(in, o->in_path) != 0) {
        return 1;
    }
    if (!r->print && steps == 0) {
        lx_err_print(PROG, "%s: no WHEEL_CMD (100) frame: the controller never ran", o->in_path);
        return 1;
    }
    rfs_replay_rec_t end;
    memset(&end, 0, sizeof end);
    end.type = RFS_REPLAY_END;
    (void)take(r, &end);
    return 0;
}

/* The player over the application writing to sc (model state for any model a CFG record
 * may name, rfs_models.h): 0, or 1 after a message. */
static int start_player(rfs_replay_player_t *player, sink_ctx_t *sc)
{
    static rfs_app_t app;
    static uint64_t *model_state;
    const uint32_t mb = (rfs_models_max_state_bytes() + 7u) & ~7u;
    model_state = aligned_alloc(RFS_MODELS_STATE_ALIGN, mb);
    if (model_state == NULL) {
        fprintf(stderr, "rfseek-replay: out of memory\n");
        return 1;
    }
    static rfs_sample_t samples[RFS_APP_MAX_SAMPLES];
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.follow_epoch = true; /* as the STM32 image (rfs_app_cfg_mcu) */
    cfg.samples = samples;
    cfg.model_state = model_state;
    cfg.model_state_bytes = mb;
    rfs_replay_player_init(player, &app, &cfg, sink, sc);
    return 0;
}

static int replay_main(int argc, char **argv)
{
    options_t o;
    int rc = parse_options(argc, argv, &o);
    if (rc != RUN) {
        return rc;
    }
    static in_stream_t in;
    memset(&in, 0, sizeof in);
    in.f = fopen(o.in_path, "rb");
    if (in.f == NULL) {
        lx_err_print(PROG, "%s: %s", o.in_path, strerror(errno));
        return 1;
    }
    const size_t head = in_fill(&in, RFS_REPLAY_HEADER_LEN);
    const bool candump = head > 0 && in.buf[0] == '(';
    if (in_error(&in, o.in_path) != 0 ||
        (!candump && rfs_replay_check_header(in.buf, (uint32_t)(head < 8 ? head : 8)) != 0)) {
        if (!ferror(in.f)) {
            lx_err_print(PROG, "%s: offset 0: not an rfseek stream (bad header) nor a candump -L log", o.in_path);
        }
        fclose(in.f);
        return 1;
    }
    if (o.ctl_opt != NULL && (o.print || !candump)) {
        lx_err_print(PROG, "%s: only for playing a candump -L log (see --help)", o.ctl_opt);
        fclose(in.f);
        return 2;
    }
    if (candump && !o.print && o.map_path == NULL) {
        lx_err_print(PROG, "%s: a candump -L log is played with --map MAP.yaml (see --help)", o.in_path);
        fclose(in.f);
        return 2;
    }
    static rfs_replay_player_t player;
    sink_ctx_t sc = {0};
    run_t run = {o.print, &player};
    char tmp[4096];
    if (!o.print) {
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", o.out_path, (long)getpid());
        sc.f = fopen(tmp, "wb");
        if (sc.f == NULL) {
            lx_err_print(PROG, "%s: %s", o.out_path, strerror(errno));
            fclose(in.f);
            return 1;
        }
        if (start_player(&player, &sc) != 0) {
            fclose(sc.f);
            remove(tmp);
            fclose(in.f);
            return 1;
        }
    }
    if (!candump) {
        in.pos = RFS_REPLAY_HEADER_LEN;
    }
    rc = candump ? play_candump(&o, &in, &run) : play_stream(o.in_path, &in, &run);
    fclose(in.f);
    if (!o.print) {
        if (fclose(sc.f) != 0 || sc.failed) {
            lx_err_print(PROG, "%s: write failed", o.out_path);
            rc = 1;
        }
        if (rc != 0) {
            remove(tmp);
        } else if (rename(tmp, o.out_path) != 0) {
            lx_err_print(PROG, "%s: %s", o.out_path, strerror(errno));
            remove(tmp);
            rc = 1;
        }
    }
    return rc;
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, replay_main(argc, argv));
}
