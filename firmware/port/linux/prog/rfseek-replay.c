/* rfseek-replay - the host build of the firmware application loop on a recorded stream
 * (firmware/rfs_replay.h), and a printer for streams.
 *
 *   rfseek-replay IN.rfsr -o OUT.rfso   play an input stream, write the output stream
 *   rfseek-replay --print FILE          print any stream, one record per line (TSV)
 *
 * Playing runs rfs_replay_play(), the driver loop the emulator image runs, so the output
 * must equal the emulator's byte for byte. Errors: one line naming the file, the byte
 * offset and the reason; exit 1; no output file is left behind.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lx_err.h"
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
 * whatever the file (/dev/zero, a stream of hours), and reading stops at the END record. */
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
        if (r->u.cfg.model[0] != '\0') {
            printf("\tmodel=%s", r->u.cfg.model);
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
               "       rfseek-replay --print FILE\n"
               "Play a recorded input stream through the host build of the firmware\n"
               "application loop (the emulator image runs the same code), or print a stream.\n"
               "  -o FILE      output stream (written to a temporary file, then renamed)\n"
               "  --print      print every record of FILE as one TSV line\n"
               "  -h, --help   this text\n");
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

/* The records after the header, printed (player NULL) or played, until END or the end of
 * the file: 0, or 1 after a message naming the offset. */
static int play_records(in_stream_t *in, const char *in_path, rfs_replay_player_t *player)
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
        if (player == NULL) {
            print_rec(&rec);
        } else if (!rfs_replay_play(player, &rec)) {
            lx_err_print(PROG, "%s: offset %zu: %s", in_path, pos, rfs_replay_err_str(player->error));
            return 1;
        }
        in->pos += used;
        inputs |= rec.type < RFS_REPLAY_END;
        if (rec.type == RFS_REPLAY_END) {
            ended = 1;
            break;
        }
    }
    if (ferror(in->f)) {
        lx_err_print(PROG, "%s: read error", in_path);
        return 1;
    }
    return check_end(in_path, in->base + in->pos, ended, inputs);
}

static int replay_main(int argc, char **argv)
{
    const char *in_path = NULL, *out_path = NULL;
    int print = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--print") == 0) {
            print = 1;
        } else if (strcmp(argv[i], "-o") == 0) {
            if (i + 1 == argc) {
                lx_err_print(PROG, "-o: missing value (see --help)");
                return 2;
            }
            out_path = argv[++i];
        } else if (argv[i][0] == '-') {
            lx_err_print(PROG, "%s: unknown option (see --help)", argv[i]);
            return 2;
        } else if (in_path == NULL) {
            in_path = argv[i];
        } else {
            lx_err_print(PROG, "%s: only one input stream expected (see --help)", argv[i]);
            return 2;
        }
    }
    if (in_path == NULL || (print == 0) == (out_path == NULL)) {
        lx_err_print(PROG, "%s (see --help)", in_path == NULL ? "an input stream is required"
                                    : print ? "--print and -o exclude each other"
                                            : "-o OUT.rfso or --print is required");
        return 2;
    }
    if (!print && (lx_err_same_file(PROG, in_path, out_path) != 0 || lx_err_check_dest(PROG, out_path) != 0)) {
        return 1;
    }
    static in_stream_t in;
    memset(&in, 0, sizeof in);
    in.f = fopen(in_path, "rb");
    if (in.f == NULL) {
        lx_err_print(PROG, "%s: %s", in_path, strerror(errno));
        return 1;
    }
    const size_t head = in_fill(&in, RFS_REPLAY_HEADER_LEN);
    if (ferror(in.f) || rfs_replay_check_header(in.buf, (uint32_t)(head < 8 ? head : 8)) != 0) {
        lx_err_print(PROG, "%s: %s", in_path, ferror(in.f) ? "read error" : "offset 0: not an rfseek stream (bad header)");
        fclose(in.f);
        return 1;
    }
    static rfs_app_t app;
    static rfs_replay_player_t player;
    sink_ctx_t sc = {0};
    char tmp[4096];
    if (!print) {
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", out_path, (long)getpid());
        sc.f = fopen(tmp, "wb");
        if (sc.f == NULL) {
            lx_err_print(PROG, "%s: %s", out_path, strerror(errno));
            fclose(in.f);
            return 1;
        }
        // The host holds every model a CFG record may name (rfs_models.h).
        static uint64_t *model_state;
        const uint32_t mb = (rfs_models_max_state_bytes() + 7u) & ~7u;
        model_state = aligned_alloc(RFS_MODELS_STATE_ALIGN, mb);
        if (model_state == NULL) {
            fprintf(stderr, "rfseek-replay: out of memory\n");
            fclose(sc.f);
            remove(tmp);
            fclose(in.f);
            return 1;
        }
        rfs_app_cfg_t cfg = rfs_app_cfg_default();
        cfg.model_state = model_state;
        cfg.model_state_bytes = mb;
        rfs_replay_player_init(&player, &app, &cfg, sink, &sc);
    }
    in.pos = RFS_REPLAY_HEADER_LEN;
    int rc = play_records(&in, in_path, print ? NULL : &player);
    fclose(in.f);
    if (!print) {
        if (fclose(sc.f) != 0 || sc.failed) {
            lx_err_print(PROG, "%s: write failed", out_path);
            rc = 1;
        }
        if (rc != 0) {
            remove(tmp);
        } else if (rename(tmp, out_path) != 0) {
            lx_err_print(PROG, "%s: %s", out_path, strerror(errno));
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
