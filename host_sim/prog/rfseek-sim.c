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
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "lx_err.h"
#include "hs_batch.h"
#include "hs_place.h"
#include "hs_sim.h"
#include "rfs_app.h"
#include "rfs_models.h"

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
            "  --seek 'KEY: VALUE, ...'  override the scenario's seek: keys (docs/SIMULATOR.md),\n"
            "                  checked as in the file\n"
            "  --fit-budget N|mcu  the model's work units a control period, overriding the\n"
            "                  scenario's seek.fit_budget (0, the default: each fit whole;\n"
            "                  mcu: the model's Cortex-M4 budget and wall-count cache,\n"
            "                  10 more slices after each period and relearns begun while\n"
            "                  braking (seek.fit_slices, fit_early),\n"
            "                  docs/PERFORMANCE.md); the wheels wait while a fit runs\n"
            "                  (summary.json decision_wait_max_s)\n"
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
            "  -h, --help      this text\n"
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
    long fit_budget;              /* --fit-budget: -1 keeps the scenario's, FIT_MCU the model's */
    const char *seek;             /* --seek KEY: VALUE, ...: seek: keys overridden, or NULL */
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
enum { FIT_MCU = -2 }; /* --fit-budget mcu */

/* The command line into *o: RUN, or the exit status (--help, a bad option). */
static int parse_options(int argc, char **argv, sim_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->p0_min = NAN;
    o->fit_budget = -1;
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
            if (lx_err_path_opt(prog, a, argv[i + 1]) != 0) {
                return 1;
            }
            o->out = argv[++i];
        } else if (strcmp(a, "--pcap") == 0) {
            if (!more || !*argv[i + 1]) {
                return die("--pcap: expected a file name%s%s", "", "");
            }
            if (lx_err_path_opt(prog, a, argv[i + 1]) != 0) {
                return 1;
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
        } else if (strcmp(a, "--seek") == 0) {
            if (!more || !*argv[i + 1] || strpbrk(argv[i + 1], "'{}\t\n") != NULL) {
                return die("--seek: expected KEY: VALUE[, KEY: VALUE...] (no quote, brace, tab "
                           "or line break)%s%s", "", "");
            }
            o->seek = argv[++i];
        } else if (strcmp(a, "--fit-budget") == 0) {
            uint64_t v;
            if (more && strcmp(argv[i + 1], "mcu") == 0) {
                o->fit_budget = FIT_MCU;
            } else if (!more || parse_u64(argv[i + 1], &v) != 0 || v > 1000000u) {
                return die("--fit-budget: expected work units from 0 to 1000000 or 'mcu', got '%s'%s",
                           more ? argv[i + 1] : "", "");
            } else {
                o->fit_budget = (long)v;
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
            snprintf(state, sizeof state, "%s/%s", dir, HS_BATCH_STATE) >= (int)sizeof state || stat(state, &st) != 0 || !S_ISREG(st.st_mode)) {
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
    if (o->placements && o->seeds && (o->pb - o->pa + 1) * (o->sb - o->sa + 1) > HS_BATCH_MAX_RUNS) {
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
    if (o->seeds && o->sb - o->sa >= HS_BATCH_MAX_RUNS) {
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
        snprintf(state, sizeof state, "%s/%s", o->out, HS_BATCH_STATE);
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
    char *end = NULL;
    while (n < 3) {
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
    return (n == 2 || (theta && n == 3)) && *end == '\0' ? n : 0; /* "1,2,3,4": not 1,2,3 */
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
    if (o->seek) {
        char err[512];
        if (hs_scenario_seek(sc, o->seek, err, sizeof err) != 0) {
            return die("%s%s", err, "");
        }
    }
    if (o->fit_budget != -1) {
        const rfs_models_entry_t *m = rfs_models_lookup(sc->model);
        sc->seek_fit_budget = o->fit_budget == FIT_MCU ? (double)(m ? m->mcu_fit_budget : 0u)
                                                       : (double)o->fit_budget;
        sc->fit_mcu = o->fit_budget == FIT_MCU;
        if (sc->fit_mcu && sc->seek_fit_slices < 0.0) {
            sc->seek_fit_slices = (double)RFS_APP_BACKGROUND_SLICES;
        }
        if (sc->fit_mcu && sc->seek_fit_early < 0) {
            sc->seek_fit_early = rfs_app_cfg_mcu().seek.fit_early ? 1 : 0;
        }
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
        char p0[96 + sizeof sc->seek_cli] = "", place[96] = "", dir[64];
        if (!isnan(o->p0_min)) {
            snprintf(p0, sizeof p0, " --p0-min %.17g", o->p0_min);
        }
        if (o->seek) {
            size_t l = strlen(p0);
            snprintf(p0 + l, sizeof p0 - l, " --seek '%s'", o->seek);
        }
        if (o->fit_budget != -1) {
            size_t l = strlen(p0);
            if (sc->fit_mcu) {
                snprintf(p0 + l, sizeof p0 - l, " --fit-budget mcu");
            } else {
                snprintf(p0 + l, sizeof p0 - l, " --fit-budget %.0f", sc->seek_fit_budget);
            }
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
        hs_batch_state_header(header, sizeof header, o->scenario, sc, o->sa, o->sb, o->samples,
                           o->placements ? o->pa : 0, o->pb, o->pseed);
        if (o->out) {
            // Interrupted, the batch leaves a directory --resume continues.
            struct sigaction sa;
            memset(&sa, 0, sizeof sa);
            sa.sa_handler = hs_batch_on_stop;
            sigaction(SIGINT, &sa, NULL);
            sigaction(SIGTERM, &sa, NULL);
        }
        rc = hs_batch_run(&env, header, o->sa, o->sb, places, o->pb - o->pa + 1, (int)o->jobs,
                       o->out ? tmp : NULL, o->samples, o->quiet, o->resume);
    } else {
        char msg[1024];
        rc = hs_batch_run_one(&env, o->has_seed ? o->seed : sc->seed, o->out ? tmp : NULL, o->out != NULL,
                     o->field, o->pcap, &res, msg, sizeof msg);
        if (rc != 0) {
            lx_err_print(prog, "%s", msg);
        }
    }
    free(places);
    hs_sim_env_close(&env);
    if (o->out) {
        const bool keep = rc != 0 && o->seeds && (hs_batch_stopped() || o->resume);
        if ((rc == 0 || keep) && rename(tmp, o->out) != 0) {
            fprintf(stderr, "%s: %s: %s\n", prog, o->out, strerror(errno));
            rc = 1;
        } else if (keep && hs_batch_stopped()) {
            lx_err_print(prog, "%s: interrupted; the finished seeds are kept there, "
                         "continue with --resume", o->out);
        } else if (rc != 0) {
            hs_batch_rm_tree(tmp);
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
