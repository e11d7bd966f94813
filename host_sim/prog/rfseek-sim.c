/* rfseek-sim - run the seeker in the simulated world (docs/SIMULATOR.md).
 *
 *   rfseek-sim SCENARIO [--seed N] [--out DIR] [--samples] [--field] [--pcap FILE]
 *   rfseek-sim SCENARIO --seeds A..B [--jobs N] [--out DIR]
 *   rfseek-sim SCENARIO --seeds A..B --emit-jobs --out DIR
 *   rfseek-sim SCENARIO --placements N [--placement-seed S] --seeds A..B [--out DIR]
 *
 * Output directories are written under DIR.tmp-PID and renamed to DIR only when complete,
 * so an error never leaves a half-written DIR behind.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lx_err.h"
#include "lx_pcap.h"
#include "hs_place.h"
#include "hs_sim.h"

static const char *prog = "rfseek-sim";

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s SCENARIO [options]\n"
            "Run the seeker (core in-process) in the simulated world of SCENARIO (YAML).\n"
            "\n"
            "  --seed N        run seed (default: the scenario's seed)\n"
            "  --out DIR       write log.tsv, track.tsv, summary.json (and samples.tsv) to DIR\n"
            "                  (a single run prints one line: how it ended); without it a\n"
            "                  single run prints summary.json on stdout; with\n"
            "                  --model pathloss also residual.tsv (the fit's residual surface)\n"
            "  --samples       also write every received packet to DIR/samples.tsv\n"
            "                  (always written for a single run with --out)\n"
            "  --field         also write the simulated field of source 0 to DIR/field.tsv\n"
            "                  (and of a second source to DIR/field1.tsv)\n"
            "  --pcap FILE     write every received packet as a radiotap pcap (single run)\n"
            "  --seeds A..B    run seeds A to B (inclusive) and write one table\n"
            "                  (DIR/runs.tsv with --out, else stdout); per-seed logs in DIR/seed-N/\n"
            "  --jobs N        worker processes for --seeds (default: all cores)\n"
            "  --resume        with --seeds and --out: continue the interrupted batch in DIR\n"
            "                  (SIGINT or SIGTERM leave DIR with the finished seeds and\n"
            "                  DIR/batch.state; SIGKILL leaves them in DIR.tmp-PID, found\n"
            "                  when DIR is missing); the same scenario, seeds and options needed\n"
            "  --emit-jobs     print one command per seed (for GNU parallel or a Slurm array)\n"
            "                  instead of running; merge with scripts/merge_runs.py DIR\n"
            "  --strategy NAME seeking strategy, overriding the scenario's: meta, meta-global,\n"
            "                  fd-gradient, plane-gradient, chemotaxis, meta-path\n"
            "                  (docs/STRATEGIES.md, docs/RESULTS.md)\n"
            "  --model NAME    internal model, overriding the scenario's: ridge, mlp, knn,\n"
            "                  radius, pathloss\n"
            "  --p0-min DBM    pathloss only: floor on the fitted signal at 1 m, overriding\n"
            "                  the scenario's seek.p0_min_dbm (default -45; the node's EIRP\n"
            "                  - 52 when its power is known: docs/PATHLOSS.md)\n"
            "  --start X,Y[,THETA]  start here (metres, radians), overriding the scenario's\n"
            "  --source X,Y    put the first source here (and the goal, unless the scenario\n"
            "                  names one); both must be legal places on the map\n"
            "  --placements N  with --seeds: every seed at each of N drawn start/source pairs\n"
            "                  (or A..B: pairs A to B), the shortest path 10 to 40 m; per-run logs\n"
            "                  in DIR/place-K-seed-N/ (docs/SIMULATOR.md, \"Placements\")\n"
            "  --placement-seed S  the seed the pairs are drawn from (default 1)\n"
            "  --placement K   a single run at pair K\n"
            "  --list-placements  print the pairs of --placements (TSV) and stop\n"
            "  --no-faults     ignore the scenario's fault schedule (docs/FAULTS.md)\n"
            "  --quiet         no progress bar\n"
            "  --bench         with --seeds: run them one after another in this process without\n"
            "                  output files and print the real-time factor (make bench-sim)\n"
            "  --help          this text\n"
            "Errors: one line on stderr, exit status 1, no output directory left behind.\n",
            prog);
}

static int die(const char *fmt, const char *a, const char *b)
{
    char msg[1024];
    snprintf(msg, sizeof msg, fmt, a, b);
    lx_err_one_line(msg); /* an option's value can hold a line break */
    fprintf(stderr, "%s: %s\n", prog, msg);
    return 1;
}

static int parse_u64(const char *s, uint64_t *v)
{
    if (!s || !*s || *s == '-' || *s == '+') {
        return -1;
    }
    char *end;
    errno = 0;
    unsigned long long x = strtoull(s, &end, 10);
    if (*end != '\0' || errno != 0) {
        return -1;
    }
    *v = x;
    return 0;
}

static int parse_range(const char *s, uint64_t *a, uint64_t *b)
{
    const char *dots = s ? strstr(s, "..") : NULL;
    if (!dots || dots == s) {
        return -1;
    }
    char first[32];
    size_t n = (size_t)(dots - s);
    if (n >= sizeof first) {
        return -1;
    }
    memcpy(first, s, n);
    first[n] = '\0';
    if (parse_u64(first, a) != 0 || parse_u64(dots + 2, b) != 0 || *b < *a) {
        return -1;
    }
    return 0;
}

/// Remove a directory tree we created (only regular files and directories).
static void rm_tree(const char *path)
{
    char cmd[PATH_MAX + 32];
    // Our own temporary directory only; quoted for spaces.
    if (strchr(path, '\'') == NULL) {
        if (snprintf(cmd, sizeof cmd, "rm -rf -- '%s'", path) >= (int)sizeof cmd ||
            system(cmd) != 0) {
            fprintf(stderr, "%s: could not remove %s\n", prog, path);
        }
    }
}

static FILE *open_in(const char *dir, const char *name)
{
    char p[PATH_MAX + 64];
    if (snprintf(p, sizeof p, "%s/%s", dir, name) >= (int)sizeof p) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    return fopen(p, "w");
}

typedef struct pcap_ctx {
    lx_pcap_writer_t *w;
    const hs_scenario_t *sc;
    int failed;
} pcap_ctx_t;

static void on_packet(void *ctx, unsigned src, int64_t t_us, uint16_t seq, bool received,
                      int dbm)
{
    pcap_ctx_t *p = ctx;
    static const uint8_t bssid[6] = {0x02, 0x00, 0x00, 0x00, 0xbb, 0x01};
    if (received && p->w &&
        lx_pcap_writer_frame(p->w, t_us, p->sc->src[src].mac, bssid, seq, (int8_t)dbm, 2437) != 0) {
        p->failed = 1;
    }
}

/* The first failure of a run into msg (later ones are its echoes: a full disk fails
 * every file of the run alike): 1. */
static int run_err(char *msg, size_t msglen, int rc, const char *what, const char *why)
{
    if (rc == 0 && snprintf(msg, msglen, "%s%s%s", what, why ? ": " : "", why ? why : "") < 0) {
        msg[0] = '\0';
    }
    return 1;
}

/// One run into dir (NULL: summary to stdout): 0, or 1 with the reason, one line, in msg.
static int run_one(const hs_sim_env_t *env, uint64_t seed, const char *dir, bool samples,
                   bool field, const char *pcap, hs_sim_result_t *res, char *msg, size_t msglen)
{
    char err[1024];
    hs_sim_io_t io = {0};
    pcap_ctx_t pc = {.sc = &env->sc};
    int rc = 0;
    if (dir) {
        io.log = open_in(dir, "log.tsv");
        io.track = open_in(dir, "track.tsv");
        if (samples) {
            io.samples = open_in(dir, "samples.tsv");
        }
        bool faults = env->sc.faults.n > 0; // docs/FAULTS.md: the injector's own log
        if (faults) {
            io.faults = open_in(dir, "faults.tsv");
        }
        if (strcmp(env->sc.model, "pathloss") == 0) { // the last fit's surface (docs/PATHLOSS.md, "Uncertainty")
            io.residual = open_in(dir, "residual.tsv");
        }
        if (!io.log || !io.track || (samples && !io.samples) || (faults && !io.faults) ||
            (strcmp(env->sc.model, "pathloss") == 0 && !io.residual)) {
            rc = run_err(msg, msglen, rc, dir, strerror(errno));
        }
    }
    if (rc == 0 && pcap) {
        pc.w = lx_pcap_writer_open(pcap, err, sizeof err);
        if (!pc.w) {
            rc = run_err(msg, msglen, rc, err, NULL);
        }
        io.on_packet = on_packet;
        io.packet_ctx = &pc;
    }
    if (rc == 0 && hs_sim_run_inproc(env, seed, &io, res, err, sizeof err) != 0) {
        rc = run_err(msg, msglen, rc, err, NULL);
    }
    // field.tsv for source 0 and field1.tsv for a second source (bridging: the "bridge" target).
    for (unsigned src = 0; rc == 0 && field && dir && src < env->sc.nsources; src++) {
        FILE *f = open_in(dir, src == 0 ? "field.tsv" : "field1.tsv");
        if (!f) {
            rc = run_err(msg, msglen, rc, dir, strerror(errno));
        } else if (hs_sim_field(env, seed, src, 0.1, f, err, sizeof err) != 0) {
            rc = run_err(msg, msglen, rc, err, NULL);
        }
        if (f && fclose(f) != 0) {
            rc = run_err(msg, msglen, rc, dir, strerror(errno));
        }
    }
    FILE *fs[5] = {io.log, io.track, io.samples, io.faults, io.residual};
    for (int i = 0; i < 5; i++) {
        if (fs[i] && fclose(fs[i]) != 0) {
            rc = run_err(msg, msglen, rc, dir, strerror(errno));
        }
    }
    if (pc.w) {
        if (lx_pcap_writer_close(pc.w) != 0 || pc.failed) {
            rc = run_err(msg, msglen, rc, pcap, "write failed");
        }
    }
    if (rc == 0) {
        FILE *s = dir ? open_in(dir, "summary.json") : stdout;
        if (!s) {
            rc = run_err(msg, msglen, rc, dir, strerror(errno));
        } else {
            hs_sim_write_summary(s, env, res);
            if (dir && fclose(s) != 0) {
                rc = run_err(msg, msglen, rc, dir, strerror(errno));
            }
        }
    }
    return rc;
}

/// Result record a worker sends to the parent (end encoded as an index); under PIPE_BUF
/// bytes, so a record is written to the pipe in one piece.
typedef struct wire_res {
    hs_sim_result_t r;
    int end;  ///< 0 reached, 1 distance, 2 time, -1 error
    char msg[512]; ///< the error (end -1), one line
} wire_res_t;

static const char *end_names[3] = {"reached", "distance", "time"};

/* The most seeds one batch runs (its table is held in memory, one row per seed). */
#define BATCH_MAX_SEEDS 1000000u

/* The state of a batch with --out while it runs and after an interruption: a header line
 * naming the runs (checked by --resume), then each finished seed's runs.tsv row. */
static const char k_state[] = "batch.state";

static volatile sig_atomic_t g_stop; /* SIGINT or SIGTERM received (batch parent) */

static void on_stop(int sig)
{
    g_stop = sig;
}

static void progress(uint64_t done, uint64_t total, uint64_t reached, bool placed)
{
    int width = 40, fill = (int)(width * done / (total ? total : 1));
    fprintf(stderr, "\r[%.*s%*s] %llu/%llu %s, %llu reached", fill,
            "########################################", width - fill, "",
            (unsigned long long)done, (unsigned long long)total, placed ? "runs" : "seeds",
            (unsigned long long)reached);
    fflush(stderr);
}

/* One --seeds batch: its runs not yet done shared among jobs worker processes, each
 * result sent to the parent through a pipe. Without placements run i is seed a + i; with
 * them, seed a + i % nseeds at placement places[i / nseeds]. */
typedef struct batch {
    hs_sim_env_t *env;    /* each worker's copy is placed as its runs need */
    uint64_t a, nseeds;   /* seeds a .. a + nseeds - 1 */
    const hs_place_t *places; /* the drawn placements, or NULL */
    uint64_t nplaces;     /* their count (0 without) */
    uint64_t total;       /* runs: nseeds, or nseeds x nplaces */
    uint64_t *todo, ntodo; /* the runs to do (indices) */
    int jobs;
    const char *dir;      /* per-run directories and runs.tsv in it, or NULL: stdout */
    bool samples, quiet;
    char **rows;          /* by run: the runs.tsv row (malloc'd), NULL until done */
    FILE *state;          /* dir/batch.state, appended as seeds finish, or NULL */
    pid_t *pids;
    pid_t parent;         /* this process, the workers' parent */
    int fds[2];           /* the workers' pipe */
    uint64_t done, reached;
    char msg[512];        /* the first worker's error */
} batch_t;

/* Run i's directory name under the batch directory: "seed-N" or "place-K-seed-N". */
static void run_name(const batch_t *bt, uint64_t i, char *buf, size_t n)
{
    const unsigned long long seed = bt->a + i % bt->nseeds;
    if (bt->places) {
        snprintf(buf, n, "place-%llu-seed-%llu", (unsigned long long)bt->places[i / bt->nseeds].index,
                 seed);
    } else {
        snprintf(buf, n, "seed-%llu", seed);
    }
}

/* Run i's directory made: 0, or -1 with errno. */
static int run_mkdir(const batch_t *bt, uint64_t i, char *sub, size_t n)
{
    char name[64];
    run_name(bt, i, name, sizeof name);
    if (snprintf(sub, n, "%s/%s", bt->dir, name) >= (int)n) {
        errno = ENAMETOOLONG;
        return -1;
    }
    return mkdir(sub, 0777);
}

/* The worker's environment at run i's placement (when it differs from the last run's):
 * 0, or -1 with the reason in msg. */
static int run_place(const batch_t *bt, uint64_t i, char *msg, size_t msglen)
{
    const hs_place_t *pl = bt->places ? &bt->places[i / bt->nseeds] : NULL;
    if (pl == NULL || bt->env->placement == pl->index) {
        return 0;
    }
    return hs_sim_env_place(bt->env, pl->index, pl->seed, pl->start_x, pl->start_y,
                            pl->start_theta, pl->source_x, pl->source_y, msg, msglen);
}

/* Worker j: its runs (todo[j], todo[j + jobs], ...), each run and its result written to
 * the pipe; exits 1 after the first failure. */
static _Noreturn void batch_worker(const batch_t *bt, int j)
{
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    /* The parent killed (SIGKILL): end too, rather than write on into a directory that a
     * --resume may already have taken over. */
    if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != bt->parent) {
        _exit(1);
    }
    close(bt->fds[0]);
    for (uint64_t k = (uint64_t)j; k < bt->ntodo; k += (uint64_t)bt->jobs) {
        const uint64_t i = bt->todo[k], s = bt->a + i % bt->nseeds;
        wire_res_t w;
        memset(&w, 0, sizeof w);
        char sub[PATH_MAX + 64];
        const char *sd = NULL;
        if (bt->dir) {
            if (run_mkdir(bt, i, sub, sizeof sub) != 0) {
                w.end = run_err(w.msg, sizeof w.msg, 0, sub, strerror(errno)) ? -1 : 0;
            }
            sd = sub;
        }
        if (w.end == 0 && run_place(bt, i, w.msg, sizeof w.msg) != 0) {
            w.end = -1;
        }
        if (w.end == 0) {
            FILE *devnull = NULL;
            if (!sd) {
                devnull = freopen("/dev/null", "w", stdout); // no per-seed JSON on stdout
                (void)devnull;
            }
            if (run_one(bt->env, s, sd, bt->samples, false, NULL, &w.r, w.msg, sizeof w.msg) != 0) {
                w.end = -1;
            } else {
                w.end = w.r.reached ? 0 : (strcmp(w.r.end, "distance") == 0 ? 1 : 2);
            }
        }
        w.r.seed = s;
        w.r.placement = bt->places ? bt->places[i / bt->nseeds].index : 0;
        w.r.end = NULL;
        if (write(bt->fds[1], &w, sizeof w) != (ssize_t)sizeof w || w.end < 0) {
            _exit(1);
        }
    }
    _exit(0);
}

/* The workers forked: 0, or 1 after a message (the ones started are terminated). */
static int batch_fork(batch_t *bt)
{
    fflush(stdout);
    fflush(stderr);
    bt->parent = getpid();
    for (int j = 0; j < bt->jobs; j++) {
        pid_t pid = fork();
        if (pid < 0) {
            fprintf(stderr, "%s: fork: %s\n", prog, strerror(errno));
            for (int k = 0; k < j; k++) {
                kill(bt->pids[k], SIGTERM);
            }
            return 1;
        }
        if (pid == 0) {
            batch_worker(bt, j);
        }
        bt->pids[j] = pid;
    }
    close(bt->fds[1]);
    return 0;
}

/* The run index of a seed at a placement (0: none), or UINT64_MAX when outside the batch. */
static uint64_t run_index(const batch_t *bt, uint64_t placement, uint64_t seed)
{
    if (seed < bt->a || seed - bt->a >= bt->nseeds || (placement != 0) != (bt->places != NULL)) {
        return UINT64_MAX;
    }
    if (!bt->places) {
        return seed - bt->a;
    }
    const uint64_t first = bt->places[0].index;
    if (placement < first || placement - first >= bt->nplaces) {
        return UINT64_MAX;
    }
    return (placement - first) * bt->nseeds + (seed - bt->a);
}

/* A finished run's row kept (and appended to the state file): 0, or 1 after a message. */
static int batch_keep(batch_t *bt, const hs_sim_result_t *r)
{
    char *row = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&row, &len);
    if (m == NULL) {
        fprintf(stderr, "%s: out of memory\n", prog);
        return 1;
    }
    hs_sim_table_row(m, r, bt->places != NULL);
    if (fclose(m) != 0) {
        free(row);
        fprintf(stderr, "%s: out of memory\n", prog);
        return 1;
    }
    bt->rows[run_index(bt, r->placement, r->seed)] = row; /* a run of this batch */
    bt->done++;
    bt->reached += r->reached ? 1u : 0u;
    if (bt->state && (fputs(row, bt->state) == EOF || fflush(bt->state) != 0)) {
        fprintf(stderr, "%s: %s/%s: %s\n", prog, bt->dir, k_state, strerror(errno));
        return 1;
    }
    return 0;
}

/* The workers' results read until the pipe closes, one failed or a signal came, then the
 * workers reaped: 0, or 1 when a run or a worker failed or the batch was interrupted. */
static int batch_collect(batch_t *bt)
{
    int rc = 0;
    wire_res_t w;
    if (!bt->quiet) {
        progress(bt->done, bt->total, bt->reached, bt->places != NULL);
    }
    for (;;) {
        ssize_t n = read(bt->fds[0], &w, sizeof w);
        if (n < 0 && errno == EINTR && !g_stop) {
            continue;
        }
        if (n != (ssize_t)sizeof w) {
            break;
        }
        if (w.end < 0) {
            snprintf(bt->msg, sizeof bt->msg, "%s", w.msg);
            rc = 1;
            break;
        }
        w.r.end = end_names[w.end];
        if (batch_keep(bt, &w.r) != 0) {
            rc = 1;
            break;
        }
        if (!bt->quiet) {
            progress(bt->done, bt->total, bt->reached, bt->places != NULL);
        }
        if (g_stop) {
            break;
        }
    }
    if (g_stop || rc != 0) {
        for (int j = 0; j < bt->jobs; j++) {
            kill(bt->pids[j], SIGTERM);
        }
        // Results written before the workers ended are finished seeds: kept.
        while (rc == 0 && read(bt->fds[0], &w, sizeof w) == (ssize_t)sizeof w && w.end >= 0) {
            w.r.end = end_names[w.end];
            rc = batch_keep(bt, &w.r);
        }
    }
    if (!bt->quiet) {
        fputc('\n', stderr);
    }
    close(bt->fds[0]);
    for (int j = 0; j < bt->jobs; j++) {
        int st;
        while (waitpid(bt->pids[j], &st, 0) < 0 && errno == EINTR) {
        }
        if (!g_stop && (!WIFEXITED(st) || WEXITSTATUS(st) != 0)) {
            rc = 1;
        }
    }
    if (bt->msg[0] != '\0') {
        lx_err_print(prog, "%s", bt->msg);
    } else if (rc == 0 && !g_stop && bt->done != bt->total) {
        fprintf(stderr, "%s: a worker ended early (%llu of %llu runs)\n", prog,
                (unsigned long long)bt->done, (unsigned long long)bt->total);
        rc = 1;
    }
    return g_stop ? 1 : rc;
}

/* runs.tsv (stdout without a directory): 0, or 1 after a failure. */
static int batch_table(const batch_t *bt)
{
    FILE *t = bt->dir ? open_in(bt->dir, "runs.tsv") : stdout;
    if (!t) {
        fprintf(stderr, "%s: %s/runs.tsv: %s\n", prog, bt->dir, strerror(errno));
        return 1;
    }
    hs_sim_table_header(t, bt->places != NULL, strcmp(bt->env->sc.target, "bridge") == 0);
    for (uint64_t i = 0; i < bt->total; i++) {
        fputs(bt->rows[i], t);
    }
    if (bt->dir && fclose(t) != 0) {
        fprintf(stderr, "%s: %s/runs.tsv: %s\n", prog, bt->dir, strerror(errno));
        return 1;
    }
    return 0;
}

/* The state file's header: the runs a --resume must repeat (scenario, seeds, options,
 * and the placements when drawn: pa..pb of seed ps, else pa 0). */
static void batch_state_header(char *buf, size_t n, const char *scenario, const hs_scenario_t *sc,
                               uint64_t a, uint64_t b, bool samples, uint64_t pa, uint64_t pb,
                               uint64_t ps)
{
    char abs[PATH_MAX], places[96] = "";
    if (pa > 0) {
        snprintf(places, sizeof places, "\tplacements=%llu..%llu\tplacement_seed=%llu",
                 (unsigned long long)pa, (unsigned long long)pb, (unsigned long long)ps);
    }
    snprintf(buf, n, "# rfseek-sim batch\tscenario=%s\tseeds=%llu..%llu\tstrategy=%s\tmodel=%s"
             "\tfaults=%u\tp0_min=%.17g\tsamples=%d\tstart=%.17g,%.17g,%.17g\tsource=%.17g,%.17g%s\n",
             realpath(scenario, abs) ? abs : scenario, (unsigned long long)a, (unsigned long long)b,
             sc->strategy, sc->model, sc->faults.n, sc->seek_p0_min_dbm, samples ? 1 : 0,
             sc->start_x, sc->start_y, sc->start_theta, sc->src[0].x, sc->src[0].y, places);
}

/* dir/name into buf: true, or false when it does not fit. */
static bool join(char *buf, size_t n, const char *dir, const char *name)
{
    return snprintf(buf, n, "%s/%s", dir, name) < (int)n;
}

/* The directories of the runs not finished removed (a worker may have begun them). */
static void drop_unfinished(const batch_t *bt)
{
    for (uint64_t i = 0; i < bt->total; i++) {
        struct stat st;
        char name[64], path[PATH_MAX + 128];
        run_name(bt, i, name, sizeof name);
        if (bt->rows[i] == NULL && join(path, sizeof path, bt->dir, name) && lstat(path, &st) == 0) {
            rm_tree(path);
        }
    }
}

/* --resume: the finished seeds of dir/batch.state into bt->rows, the directories of the
 * unfinished ones removed: 0, or 1 after a message. */
static int batch_resume(batch_t *bt, const char *header)
{
    char path[PATH_MAX + 128], line[4096];
    FILE *f = join(path, sizeof path, bt->dir, k_state) ? fopen(path, "r") : NULL;
    if (f == NULL) {
        fprintf(stderr, "%s: %s: %s\n", prog, path, strerror(errno));
        return 1;
    }
    int rc = 0;
    if (!fgets(line, sizeof line, f) || strcmp(line, header) != 0) {
        lx_err_print(prog, "%s: another batch (its header differs from this command's: "
                     "same scenario, --seeds and options needed)", path);
        rc = 1;
    }
    long at = ftell(f), cut = -1;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        char *end = line;
        errno = 0;
        /* A placed batch's rows begin with the placement, then the seed. */
        unsigned long long pl = bt->places ? strtoull(line, &end, 10) : 0;
        bool ok = !bt->places || *end == '\t';
        unsigned long long s = ok ? strtoull(end + (bt->places ? 1 : 0), &end, 10) : 0;
        size_t len = strlen(line);
        if (!ok || errno != 0 || *end != '\t' || len == 0 || line[len - 1] != '\n') {
            cut = at; /* a row cut by SIGKILL: that run is redone, the rows go on from here */
            break;
        }
        const uint64_t i = run_index(bt, pl, s);
        if (i == UINT64_MAX || bt->rows[i] != NULL) {
            lx_err_print(prog, "%s: seed %llu (placement %llu) outside the batch or listed twice",
                         path, s, pl);
            rc = 1;
            break;
        }
        bt->rows[i] = strdup(line);
        if (bt->rows[i] == NULL) {
            fprintf(stderr, "%s: out of memory\n", prog);
            rc = 1;
            break;
        }
        bt->done++;
        bt->reached += strncmp(end, "\t1\t", 3) == 0 ? 1u : 0u;
        at = ftell(f);
    }
    fclose(f);
    if (rc == 0 && cut >= 0 && truncate(path, cut) != 0) {
        fprintf(stderr, "%s: %s: %s\n", prog, path, strerror(errno));
        rc = 1;
    }
    if (rc == 0) {
        drop_unfinished(bt);
    }
    return rc;
}

static int run_batch(hs_sim_env_t *env, const char *header, uint64_t a, uint64_t b,
                     const hs_place_t *places, uint64_t nplaces, int jobs, const char *dir,
                     bool samples, bool quiet, bool resume)
{
    batch_t bt;
    memset(&bt, 0, sizeof bt);
    bt.env = env;
    bt.a = a;
    bt.nseeds = b - a + 1;
    bt.places = places;
    bt.nplaces = places ? nplaces : 0;
    bt.total = bt.nseeds * (places ? nplaces : 1); /* at most BATCH_MAX_SEEDS (check_options) */
    bt.dir = dir;
    bt.samples = samples;
    bt.quiet = quiet;
    bt.rows = calloc(bt.total, sizeof *bt.rows);
    bt.todo = calloc(bt.total, sizeof *bt.todo);
    int rc = 0;
    if (!bt.rows || !bt.todo) {
        fprintf(stderr, "%s: out of memory\n", prog);
        rc = 1;
    }
    if (rc == 0 && dir && resume) {
        rc = batch_resume(&bt, header);
    }
    if (rc == 0 && dir) {
        char path[PATH_MAX + 128];
        bt.state = join(path, sizeof path, dir, k_state) ? fopen(path, resume ? "a" : "w") : NULL;
        if (!bt.state || (!resume && (fputs(header, bt.state) == EOF || fflush(bt.state) != 0))) {
            fprintf(stderr, "%s: %s: %s\n", prog, path, strerror(errno));
            rc = 1;
        }
    }
    for (uint64_t i = 0; rc == 0 && i < bt.total; i++) {
        if (bt.rows[i] == NULL) {
            bt.todo[bt.ntodo++] = i;
        }
    }
    bt.jobs = (uint64_t)jobs > bt.ntodo ? (int)(bt.ntodo > 0 ? bt.ntodo : 1) : jobs;
    bt.pids = calloc((size_t)bt.jobs, sizeof *bt.pids);
    if (rc == 0 && (!bt.pids || pipe(bt.fds) != 0)) {
        fprintf(stderr, "%s: out of memory\n", prog);
        rc = 1;
    }
    if (rc == 0 && bt.ntodo > 0) {
        rc = batch_fork(&bt);
        if (rc == 0) {
            rc = batch_collect(&bt);
        }
    } else if (rc == 0) {
        close(bt.fds[0]);
        close(bt.fds[1]);
    }
    if (bt.state && fclose(bt.state) != 0 && rc == 0) {
        fprintf(stderr, "%s: %s/%s: %s\n", prog, dir, k_state, strerror(errno));
        rc = 1;
    }
    if (rc == 0) {
        rc = batch_table(&bt);
    }
    if (rc == 0 && dir) {
        char path[PATH_MAX + 128];
        if (!join(path, sizeof path, dir, k_state) || remove(path) != 0) {
            fprintf(stderr, "%s: %s: %s\n", prog, path, strerror(errno));
            rc = 1;
        }
    }
    if (g_stop && dir) {
        drop_unfinished(&bt); // the finished seeds and the state stay
    }
    for (uint64_t i = 0; bt.rows && i < bt.total; i++) {
        free(bt.rows[i]);
    }
    free(bt.rows); free(bt.todo); free(bt.pids);
    return rc;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/// Sequential runs in this process, no outputs: simulated time over host time of
/// hs_sim_run (world, radio and controller set-up included; map loading excluded).
static int run_bench(const hs_sim_env_t *env, uint64_t a, uint64_t b)
{
    uint64_t n = b - a + 1;
    double *rtf = calloc(n, sizeof *rtf), sim = 0.0, wall = 0.0, cpu = 0.0;
    uint64_t pkts = 0;
    if (!rtf) {
        return die("out of memory%s%s", "", "");
    }
    for (uint64_t i = 0; i < n; i++) {
        const uint64_t s = a + i;
        hs_sim_result_t r;
        char err[1024];
        if (hs_sim_run_inproc(env, s, NULL, &r, err, sizeof err) != 0) {
            free(rtf);
            fprintf(stderr, "%s: %s\n", prog, err);
            return 1;
        }
        rtf[i] = r.sim_time_s / r.wall_time_s;
        sim += r.sim_time_s;
        wall += r.wall_time_s;
        cpu += r.cpu_time_s;
        pkts += r.packets_sent;
    }
    qsort(rtf, n, sizeof *rtf, cmp_double);
    printf("runs %llu  simulated %.1f s  host %.3f s (cpu %.3f s)  packets %llu\n",
           (unsigned long long)n, sim, wall, cpu, (unsigned long long)pkts);
    printf("real-time factor by cpu time: %.0fx\n", sim / cpu);
    printf("real-time factor: overall %.0fx, median per run %.0fx (min %.0fx, max %.0fx)\n",
           sim / wall, n % 2 ? rtf[n / 2] : 0.5 * (rtf[n / 2 - 1] + rtf[n / 2]), rtf[0],
           rtf[n - 1]);
    free(rtf);
    return 0;
}

/* The command line. */
typedef struct sim_opts {
    const char *scenario, *out, *pcap, *seeds;
    const char *strategy, *model; /* overrides of the scenario's, or NULL */
    uint64_t seed;
    bool has_seed, samples, field, emit, quiet, bench, no_faults, resume;
    double p0_min;                /* --p0-min: NAN keeps the scenario's (or the model's default) */
    const char *start, *source;   /* --start X,Y[,THETA], --source X,Y: placement overrides */
    const char *placements;       /* --placements N or A..B: drawn pairs pa..pb */
    uint64_t pa, pb;
    uint64_t pseed;               /* --placement-seed (1) */
    uint64_t place_one;           /* --placement K (0: none) */
    bool has_pseed, list_places;
    long jobs;
    uint64_t sa, sb;              /* --seeds A..B */
    char from[PATH_MAX + 64];     /* --resume: the interrupted batch's directory */
} sim_opts_t;

enum { RUN = -1 }; /* parse_options: go on (else the exit status) */

/* The command line into *o: RUN, or the exit status (--help, a bad option). */
static int parse_options(int argc, char **argv, sim_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->p0_min = NAN;
    o->pseed = 1;
    o->jobs = sysconf(_SC_NPROCESSORS_ONLN);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool more = i + 1 < argc;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--seed") == 0) {
            if (!more || parse_u64(argv[++i], &o->seed) != 0) {
                return die("--seed: expected a non-negative integer%s%s", "", "");
            }
            o->has_seed = true;
        } else if (strcmp(a, "--out") == 0) {
            if (!more || !*argv[i + 1]) {
                return die("--out: expected a directory%s%s", "", "");
            }
            o->out = argv[++i];
        } else if (strcmp(a, "--pcap") == 0) {
            if (!more || !*argv[i + 1]) {
                return die("--pcap: expected a file name%s%s", "", "");
            }
            o->pcap = argv[++i];
        } else if (strcmp(a, "--seeds") == 0) {
            if (!more) {
                return die("--seeds: expected A..B%s%s", "", "");
            }
            o->seeds = argv[++i];
        } else if (strcmp(a, "--jobs") == 0) {
            uint64_t j;
            if (!more || parse_u64(argv[++i], &j) != 0 || j < 1 || j > 1024) {
                return die("--jobs: expected a number from 1 to 1024%s%s", "", "");
            }
            o->jobs = (long)j;
        } else if (strcmp(a, "--samples") == 0) {
            o->samples = true;
        } else if (strcmp(a, "--field") == 0) {
            o->field = true;
        } else if (strcmp(a, "--emit-jobs") == 0) {
            o->emit = true;
        } else if (strcmp(a, "--strategy") == 0 || strcmp(a, "--model") == 0) {
            if (!more || !*argv[i + 1]) {
                return die("%s: expected a name%s", a, "");
            }
            *(a[2] == 's' ? &o->strategy : &o->model) = argv[++i];
        } else if (strcmp(a, "--p0-min") == 0) {
            char *end = NULL;
            o->p0_min = more ? strtod(argv[i + 1], &end) : NAN;
            if (!more || !*argv[i + 1] || *end != '\0' || !(o->p0_min >= -200.0 && o->p0_min <= 100.0)) {
                return die("--p0-min: expected dBm in [-200, 100], got '%s'%s",
                           more ? argv[i + 1] : "", "");
            }
            i++;
        } else if (strcmp(a, "--start") == 0 || strcmp(a, "--source") == 0) {
            if (!more) {
                return die("%s: expected X,Y%s", a, a[3] == 't' ? "[,THETA] in metres, radians" : " in metres");
            }
            *(a[3] == 't' ? &o->start : &o->source) = argv[++i];
        } else if (strcmp(a, "--placements") == 0) {
            if (!more) {
                return die("--placements: expected N or A..B%s%s", "", "");
            }
            o->placements = argv[++i];
        } else if (strcmp(a, "--placement-seed") == 0) {
            if (!more || parse_u64(argv[++i], &o->pseed) != 0) {
                return die("--placement-seed: expected a non-negative integer%s%s", "", "");
            }
            o->has_pseed = true;
        } else if (strcmp(a, "--placement") == 0) {
            if (!more || parse_u64(argv[++i], &o->place_one) != 0 || o->place_one < 1 ||
                o->place_one > HS_PLACE_MAX_INDEX) {
                return die("--placement: expected a number from 1 to %s%s", "1000000000", "");
            }
        } else if (strcmp(a, "--list-placements") == 0) {
            o->list_places = true;
        } else if (strcmp(a, "--no-faults") == 0) {
            o->no_faults = true;
        } else if (strcmp(a, "--resume") == 0) {
            o->resume = true;
        } else if (strcmp(a, "--quiet") == 0) {
            o->quiet = true;
        } else if (strcmp(a, "--bench") == 0) {
            o->bench = true;
        } else if (a[0] == '-' && a[1] != '\0') {
            return die("unknown option '%s' (see --help)%s", a, "");
        } else if (!o->scenario) {
            o->scenario = a;
        } else {
            return die("unexpected argument '%s' (one scenario only)%s", a, "");
        }
    }
    return RUN;
}

/* --resume when DIR is missing: the DIR.tmp-PID a batch killed by SIGKILL left (its
 * batch.state written as the batch began, a row per finished seed), PID no longer running,
 * into o->from. RUN, or the exit status after a message (none, several, or still running). */
static int find_killed_batch(sim_opts_t *o)
{
    const char *slash = strrchr(o->out, '/');
    const int plen = slash ? (int)(slash - o->out) + 1 : 0; /* "folder/" or "" */
    const char *base = o->out + plen;
    const size_t bl = strlen(base);
    char parent[PATH_MAX];
    snprintf(parent, sizeof parent, "%.*s", plen > 0 ? plen : 1, plen > 0 ? o->out : ".");
    DIR *d = bl > 0 ? opendir(parent) : NULL;
    const struct dirent *e;
    long running = 0;
    o->from[0] = '\0';
    while (d != NULL && (e = readdir(d)) != NULL) {
        char *end, dir[PATH_MAX + 64], state[PATH_MAX + 128];
        struct stat st;
        if (strncmp(e->d_name, base, bl) != 0 || strncmp(e->d_name + bl, ".tmp-", 5) != 0) {
            continue;
        }
        errno = 0;
        const long pid = strtol(e->d_name + bl + 5, &end, 10);
        if (errno != 0 || *end != '\0' || pid <= 0 || pid > INT_MAX ||
            snprintf(dir, sizeof dir, "%.*s%s", plen, o->out, e->d_name) >= (int)sizeof dir ||
            !join(state, sizeof state, dir, k_state) || stat(state, &st) != 0 || !S_ISREG(st.st_mode)) {
            continue;
        }
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) {
            running = pid;
        } else if (o->from[0] != '\0') {
            closedir(d);
            return die("%s: two killed batches (%s and another): keep one (rename it to the --out "
                       "name) and --resume it", o->out, o->from);
        } else {
            snprintf(o->from, sizeof o->from, "%s", dir);
        }
    }
    if (d != NULL) {
        closedir(d);
    }
    if (o->from[0] == '\0') {
        char pid[32];
        snprintf(pid, sizeof pid, "%ld", running);
        return running ? die("%s: its batch is still running (process %s): nothing to resume", o->out, pid)
                       : die("%s: not an interrupted batch (no batch.state): nothing to resume%s", o->out, "");
    }
    return RUN;
}

/* The most placements one --placements draws. */
#define MAX_PLACEMENTS 10000u

/* The placement options that go together, checked: RUN, or the exit status after a message. */
static int check_placements(sim_opts_t *o)
{
    if (o->placements) {
        const bool range = strstr(o->placements, "..") != NULL;
        if (range ? parse_range(o->placements, &o->pa, &o->pb) != 0
                  : parse_u64(o->placements, &o->pb) != 0) {
            o->pb = 0;
        }
        o->pa = range ? o->pa : 1;
        if (o->pa < 1 || o->pb < o->pa || o->pb > HS_PLACE_MAX_INDEX ||
            o->pb - o->pa >= MAX_PLACEMENTS) {
            return die("--placements: expected N or A..B with 1 <= A <= B <= 1000000000 and at "
                       "most 10000 placements, got '%s'%s", o->placements, "");
        }
    }
    const bool drawn = o->placements || o->place_one;
    if (drawn && (o->start || o->source)) {
        return die("--placements and --placement draw the start and source: not with --start "
                   "or --source%s%s", "", "");
    }
    if (o->placements && o->place_one) {
        return die("--placement K is one run, --placements a batch: not both%s%s", "", "");
    }
    if (o->has_pseed && !drawn) {
        return die("--placement-seed needs --placements or --placement%s%s", "", "");
    }
    if (o->list_places && (!o->placements || o->seeds || o->out || o->emit || o->bench)) {
        return die("--list-placements needs --placements and prints them only (no --seeds, "
                   "--out, --emit-jobs or --bench)%s%s", "", "");
    }
    if (o->placements && !o->list_places && !o->seeds) {
        return die("--placements needs --seeds A..B (every seed at every placement) or "
                   "--list-placements%s%s", "", "");
    }
    if (o->place_one && o->seeds) {
        return die("--placement K is for a single run (a batch at one placement: --placements "
                   "K..K)%s%s", "", "");
    }
    if (drawn && o->bench) {
        return die("--bench runs the scenario's own placement (no --placements)%s%s", "", "");
    }
    if (o->placements && o->seeds && (o->pb - o->pa + 1) * (o->sb - o->sa + 1) > BATCH_MAX_SEEDS) {
        return die("--placements x --seeds: more than %s runs in one batch%s", "1000000", "");
    }
    return RUN;
}

/* The options that go together, checked: RUN, or the exit status after a message. */
static int check_options(sim_opts_t *o)
{
    if (!o->scenario) {
        usage(stderr);
        return 1;
    }
    if (o->seeds && parse_range(o->seeds, &o->sa, &o->sb) != 0) {
        return die("--seeds: '%s' is not A..B with A <= B%s", o->seeds, "");
    }
    if (o->seeds && o->sb - o->sa >= BATCH_MAX_SEEDS) {
        return die("--seeds: '%s' is more than %s seeds in one batch", o->seeds, "1000000");
    }
    if (o->seeds && o->has_seed) {
        return die("--seed and --seeds exclude each other%s%s", "", "");
    }
    if (o->emit && (!o->seeds || !o->out)) {
        return die("--emit-jobs needs --seeds A..B and --out DIR%s%s", "", "");
    }
    if (o->bench && (!o->seeds || o->out || o->emit)) {
        return die("--bench needs --seeds A..B and no --out or --emit-jobs%s%s", "", "");
    }
    if (o->pcap && o->seeds) {
        return die("--pcap is for a single run, not --seeds%s%s", "", "");
    }
    if (check_placements(o) != RUN) {
        return 1;
    }
    if (o->jobs < 1) {
        o->jobs = 1;
    }
    if (o->resume && (!o->seeds || !o->out || o->emit || o->bench)) {
        return die("--resume needs --seeds A..B and --out DIR (no --emit-jobs or --bench)%s%s", "", "");
    }
    if (o->out) {
        struct stat st;
        char state[PATH_MAX + 64];
        snprintf(state, sizeof state, "%s/%s", o->out, k_state);
        if (o->resume && stat(state, &st) == 0) {
            snprintf(o->from, sizeof o->from, "%s", o->out);
        } else if (o->resume && stat(o->out, &st) == 0) {
            return die("%s: not an interrupted batch (no batch.state): nothing to resume%s", o->out, "");
        } else if (o->resume && find_killed_batch(o) != RUN) {
            return 1;
        }
        if (!o->resume && stat(o->out, &st) == 0) {
            return die("%s: already exists (choose a new --out directory)%s", o->out, "");
        }
        if (!o->emit && !o->resume && lx_err_check_dest(prog, o->out) != 0) {
            return 1;
        }
    }
    if (o->pcap && (lx_err_same_file(prog, o->scenario, o->pcap) != 0 ||
                    lx_err_check_dest(prog, o->pcap) != 0)) {
        return 1;
    }
    return RUN;
}

/* The scenario with the options' overrides: RUN, or the exit status after a message. */
/* "X,Y" or, with theta, "X,Y[,THETA]" into v[0..2]: the count read (2 or 3), 0 when the
 * text is not that (numbers finite, within +-1e6 m and +-7 rad). */
static int parse_xy(const char *t, bool theta, double v[3])
{
    int n = 0;
    while (n < 3) {
        char *end;
        errno = 0;
        v[n] = strtod(t, &end);
        if (end == t || errno != 0 || !isfinite(v[n]) || fabs(v[n]) > (n == 2 ? 7.0 : 1e6)) {
            return 0;
        }
        n++;
        if (*end == '\0') {
            break;
        }
        if (*end != ',') {
            return 0;
        }
        t = end + 1;
    }
    return (n == 2 || (theta && n == 3)) && (n < 3 || strchr(t, ',') == NULL) ? n : 0;
}

/* --start and --source into the scenario (the goal follows the first source unless the
 * scenario names one); legality is checked when the environment opens. RUN or 1. */
static int placement(const sim_opts_t *o, hs_scenario_t *sc)
{
    double v[3];
    int n;
    if (o->start) {
        if ((n = parse_xy(o->start, true, v)) == 0) {
            return die("--start: expected X,Y[,THETA] (metres, radians), got '%s'%s", o->start, "");
        }
        sc->start_x = v[0];
        sc->start_y = v[1];
        sc->start_theta = n == 3 ? v[2] : sc->start_theta;
    }
    if (o->source) {
        if (parse_xy(o->source, false, v) != 2) {
            return die("--source: expected X,Y (metres), got '%s'%s", o->source, "");
        }
        sc->src[0].x = v[0];
        sc->src[0].y = v[1];
        if (!sc->has_goal) {
            sc->goal_x = v[0];
            sc->goal_y = v[1];
        }
    }
    return RUN;
}

static int load_scenario(const sim_opts_t *o, hs_scenario_t *sc)
{
    char err[1024];
    if (hs_scenario_load(o->scenario, sc, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", prog, err);
        return 1;
    }
    rfs_seek_strategy_t st_check;
    if (o->strategy && (strlen(o->strategy) >= sizeof sc->strategy ||
                        !rfs_seek_strategy_parse(o->strategy, &st_check))) {
        return die("--strategy: unknown '%s' (meta, meta-global, fd-gradient, plane-gradient, "
                   "chemotaxis, meta-path)%s", o->strategy, "");
    }
    if (o->model && (strlen(o->model) >= sizeof sc->model || !hs_ctrl_model_known(o->model))) {
        return die("--model: unknown '%s' (ridge, mlp, knn, radius, pathloss)%s", o->model, "");
    }
    if (o->strategy) {
        snprintf(sc->strategy, sizeof sc->strategy, "%s", o->strategy);
    }
    if (o->model) {
        snprintf(sc->model, sizeof sc->model, "%s", o->model);
    }
    if (o->no_faults) {
        sc->faults.n = 0;
    }
    if (!isnan(o->p0_min)) {
        if (strcmp(sc->model, "pathloss") != 0) {
            return die("--p0-min: only with model pathloss (this run's is %s)%s", sc->model, "");
        }
        sc->seek_p0_min_dbm = o->p0_min;
    }
    return placement(o, sc);
}

/* --emit-jobs: the same runs, one command per seed; scripts/merge_runs.py DIR merges
 * them. The exit status. */
static int emit_jobs(const sim_opts_t *o, const hs_scenario_t *sc)
{
    char self[PATH_MAX], scn[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0 || !realpath(o->scenario, scn)) {
        return die("cannot resolve the program or scenario path%s%s", "", "");
    }
    self[n] = '\0';
    const uint64_t np = o->placements ? o->pb - o->pa + 1 : 1, ns = o->sb - o->sa + 1;
    for (uint64_t i = 0; i < np * ns; i++) {
        const uint64_t s = o->sa + i % ns, k = o->pa + i / ns; /* a batch's order */
        char p0[48] = "", place[96] = "", dir[64];
        if (!isnan(o->p0_min)) {
            snprintf(p0, sizeof p0, " --p0-min %.17g", o->p0_min);
        }
        snprintf(dir, sizeof dir, "seed-%llu", (unsigned long long)s);
        if (o->placements) {
            snprintf(place, sizeof place, " --placement %llu --placement-seed %llu",
                     (unsigned long long)k, (unsigned long long)o->pseed);
            snprintf(dir, sizeof dir, "place-%llu-seed-%llu", (unsigned long long)k,
                     (unsigned long long)s);
        }
        printf("%s %s --seed %llu --out %s/%s --strategy %s --model %s%s%s%s", self,
               scn, (unsigned long long)s, o->out, dir, sc->strategy, sc->model,
               o->no_faults ? " --no-faults" : "", p0, place);
        printf("%s%s%s%s\n", o->start ? " --start " : "", o->start ? o->start : "",
               o->source ? " --source " : "", o->source ? o->source : "");
    }
    return 0;
}

/* Placements a..b of seed into *out (malloc'd; every draw checked): 0, or 1 after a message. */
static int draw_places(const hs_sim_env_t *env, uint64_t seed, uint64_t a, uint64_t b,
                       hs_place_t **out)
{
    char err[1024];
    hs_placer_t pl;
    *out = calloc((size_t)(b - a + 1), sizeof **out);
    if (!*out) {
        return die("out of memory%s%s", "", "");
    }
    int rc = hs_placer_open(&pl, env, err, sizeof err);
    for (uint64_t k = a; rc == 0 && k <= b; k++) {
        rc = hs_placer_draw(&pl, seed, k, &(*out)[k - a], err, sizeof err);
    }
    hs_placer_close(&pl);
    if (rc != 0) {
        free(*out);
        *out = NULL;
        lx_err_print(prog, "%s", err);
        return 1;
    }
    return 0;
}

/* --list-placements: the drawn pairs as a table on stdout. */
static void list_places(const hs_place_t *pl, uint64_t n)
{
    printf("placement\tstart_x_m\tstart_y_m\tstart_theta_rad\tsource_x_m\tsource_y_m\t"
           "shortest_path_m\tshortest_to_stop_m\n");
    for (uint64_t i = 0; i < n; i++) {
        printf("%llu\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%.3f\t%.3f\n", (unsigned long long)pl[i].index,
               pl[i].start_x, pl[i].start_y, pl[i].start_theta, pl[i].source_x, pl[i].source_y,
               pl[i].shortest_path_m, pl[i].shortest_to_stop_m);
    }
}

/* The environment at placement --placement K (drawn from --placement-seed): RUN, or the
 * exit status after a message. */
static int place_env(const sim_opts_t *o, hs_sim_env_t *env)
{
    hs_place_t *pl;
    char err[1024];
    if (draw_places(env, o->pseed, o->place_one, o->place_one, &pl) != 0) {
        return 1;
    }
    int rc = hs_sim_env_place(env, pl->index, pl->seed, pl->start_x, pl->start_y, pl->start_theta,
                              pl->source_x, pl->source_y, err, sizeof err);
    free(pl);
    if (rc != 0) {
        lx_err_print(prog, "%s", err);
        return 1;
    }
    return RUN;
}

/* The runs (one, a batch, or the bench) into a temporary --out directory renamed into
 * place when complete: the exit status. */
static int run_scenario(const sim_opts_t *o, const hs_scenario_t *sc)
{
    hs_sim_result_t res;
    memset(&res, 0, sizeof res);
    char err[1024];
    hs_sim_env_t env;
    if (hs_sim_env_open(&env, sc, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", prog, err);
        return 1;
    }
    hs_place_t *places = NULL;
    if ((o->placements && draw_places(&env, o->pseed, o->pa, o->pb, &places) != 0) ||
        (o->place_one && place_env(o, &env) != RUN)) {
        hs_sim_env_close(&env);
        return 1;
    }
    if (o->list_places || o->emit) { /* with placements (without them no environment opens) */
        if (o->list_places) {
            list_places(places, o->pb - o->pa + 1);
        }
        int erc = o->emit ? emit_jobs(o, sc) : 0;
        free(places);
        hs_sim_env_close(&env);
        return erc;
    }
    if (o->bench) { /* never with placements (check_placements) */
        int brc = run_bench(&env, o->sa, o->sb);
        hs_sim_env_close(&env);
        return brc;
    }
    char tmp[PATH_MAX + 64];
    if (o->out) {
        // A resumed batch goes on in the temporary directory like a new one.
        if (snprintf(tmp, sizeof tmp, "%s.tmp-%ld", o->out, (long)getpid()) >= (int)sizeof tmp ||
            (o->resume ? rename(o->from, tmp) : mkdir(tmp, 0777)) != 0) {
            fprintf(stderr, "%s: %s: %s\n", prog, o->resume ? o->from : tmp, strerror(errno));
            free(places);
            hs_sim_env_close(&env);
            return 1;
        }
    }
    int rc;
    if (o->seeds) {
        char header[PATH_MAX + 512];
        batch_state_header(header, sizeof header, o->scenario, sc, o->sa, o->sb, o->samples,
                           o->placements ? o->pa : 0, o->pb, o->pseed);
        if (o->out) {
            // Interrupted, the batch leaves a directory --resume continues.
            struct sigaction sa;
            memset(&sa, 0, sizeof sa);
            sa.sa_handler = on_stop;
            sigaction(SIGINT, &sa, NULL);
            sigaction(SIGTERM, &sa, NULL);
        }
        rc = run_batch(&env, header, o->sa, o->sb, places, o->pb - o->pa + 1, (int)o->jobs,
                       o->out ? tmp : NULL, o->samples, o->quiet, o->resume);
    } else {
        char msg[1024];
        rc = run_one(&env, o->has_seed ? o->seed : sc->seed, o->out ? tmp : NULL, o->out != NULL,
                     o->field, o->pcap, &res, msg, sizeof msg);
        if (rc != 0) {
            lx_err_print(prog, "%s", msg);
        }
    }
    free(places);
    hs_sim_env_close(&env);
    if (o->out) {
        const bool keep = rc != 0 && o->seeds && (g_stop || o->resume);
        if ((rc == 0 || keep) && rename(tmp, o->out) != 0) {
            fprintf(stderr, "%s: %s: %s\n", prog, o->out, strerror(errno));
            rc = 1;
        } else if (keep && g_stop) {
            lx_err_print(prog, "%s: interrupted; the finished seeds are kept there, "
                         "continue with --resume", o->out);
        } else if (rc != 0) {
            rm_tree(tmp);
        }
    }
    if (rc == 0 && o->out && !o->seeds) {
        // A single run into DIR: one line to say how it went (summary.json has the rest).
        printf("seed %llu: %s after %.1f s and %.1f m (shortest path %.1f m), %u decisions, "
               "%.1f m from the goal; %s/summary.json\n", (unsigned long long)res.seed,
               res.end, res.sim_time_s, res.distance_travelled_m, res.shortest_path_m,
               res.iterations, res.final_distance_m, o->out);
    }
    return rc;
}

static int sim_main(int argc, char **argv)
{
    sim_opts_t o;
    int rc = parse_options(argc, argv, &o);
    if (rc == RUN) {
        rc = check_options(&o);
    }
    if (rc != RUN) {
        return rc;
    }
    static hs_scenario_t sc;
    rc = load_scenario(&o, &sc);
    if (rc != RUN) {
        return rc;
    }
    return o.emit && !o.placements ? emit_jobs(&o, &sc) : run_scenario(&o, &sc);
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(prog, sim_main(argc, argv));
}
