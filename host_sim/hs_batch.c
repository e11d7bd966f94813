/* hs_batch.c - rfseek-sim's runs: one run's output files, and a --seeds batch shared
 * among worker processes, resumable after an interruption (docs/SIMULATOR.md, "Outputs"). */
#include "hs_batch.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lx_err.h"
#include "lx_pcap.h"

static const char *prog = "rfseek-sim";

void hs_batch_rm_tree(const char *path)
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

int hs_batch_run_one(const hs_sim_env_t *env, uint64_t seed, const char *dir, bool samples,
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

static const char k_state[] = HS_BATCH_STATE;

static volatile sig_atomic_t g_stop; /* SIGINT or SIGTERM received (batch parent) */

void hs_batch_on_stop(int sig)
{
    g_stop = sig;
}

bool hs_batch_stopped(void)
{
    return g_stop != 0;
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

/* One --seeds batch: its runs not yet done shared among jobs worker processes (each takes
 * the next one not taken when it is free), each result sent to the parent through a pipe.
 * Without placements run i is seed a + i; with them, seed a + i % nseeds at placement
 * places[i / nseeds]. */
typedef struct batch {
    hs_sim_env_t *env;    /* each worker's copy is placed as its runs need */
    uint64_t a, nseeds;   /* seeds a .. a + nseeds - 1 */
    const hs_place_t *places; /* the drawn placements, or NULL */
    uint64_t nplaces;     /* their count (0 without) */
    uint64_t total;       /* runs: nseeds, or nseeds x nplaces */
    uint64_t *todo, ntodo; /* the runs to do (indices) */
    uint64_t *next;       /* shared by the workers (MAP_SHARED): the next todo to take */
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

/* A worker: the runs not yet taken, one at a time, each run and its result written to the
 * pipe; exits 1 after the first failure. */
static _Noreturn void batch_worker(const batch_t *bt)
{
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    /* The parent killed (SIGKILL): end too, rather than write on into a directory that a
     * --resume may already have taken over. */
    if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != bt->parent) {
        _exit(1);
    }
    close(bt->fds[0]);
    for (uint64_t k; (k = __atomic_fetch_add(bt->next, 1, __ATOMIC_RELAXED)) < bt->ntodo;) {
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
            if (hs_batch_run_one(bt->env, s, sd, bt->samples, false, NULL, &w.r, w.msg, sizeof w.msg) != 0) {
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
            batch_worker(bt);
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

void hs_batch_state_header(char *buf, size_t n, const char *scenario, const hs_scenario_t *sc,
                               uint64_t a, uint64_t b, bool samples, uint64_t pa, uint64_t pb,
                               uint64_t ps)
{
    char abs[PATH_MAX], places[96] = "";
    if (pa > 0) {
        snprintf(places, sizeof places, "\tplacements=%llu..%llu\tplacement_seed=%llu",
                 (unsigned long long)pa, (unsigned long long)pb, (unsigned long long)ps);
    }
    snprintf(buf, n, "# rfseek-sim batch\tscenario=%s\tseeds=%llu..%llu\tstrategy=%s\tmodel=%s"
             "\tfaults=%u\tp0_min=%.17g\tfit_budget=%.0f%s\tseek=%s\tsamples=%d"
             "\tstart=%.17g,%.17g,%.17g\tsource=%.17g,%.17g%s\n",
             realpath(scenario, abs) ? abs : scenario, (unsigned long long)a, (unsigned long long)b,
             sc->strategy, sc->model, sc->faults.n, sc->seek_p0_min_dbm, sc->seek_fit_budget,
             sc->fit_mcu ? " (mcu)" : "", sc->seek_cli, samples ? 1 : 0,
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
            hs_batch_rm_tree(path);
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

int hs_batch_run(hs_sim_env_t *env, const char *header, uint64_t a, uint64_t b,
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
    bt.total = bt.nseeds * (places ? nplaces : 1); /* at most BATCH_MAX_SEEDS (the caller checks) */
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
    void *shared = mmap(NULL, sizeof *bt.next, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS,
                        -1, 0);
    bt.next = shared == MAP_FAILED ? NULL : shared;
    if (rc == 0 && (!bt.pids || !bt.next || pipe(bt.fds) != 0)) {
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
    if (bt.next) {
        munmap(bt.next, sizeof *bt.next);
    }
    return rc;
}
