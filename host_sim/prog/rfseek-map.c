/* rfseek-map - inspect a ROS map_server map as the core will see it (docs/MAPS.md).
 *
 *   rfseek-map MAP.yaml [--res 0.1] [--clearance 0.25] [--grid 0.25] [--pgm OUT.pgm]
 *
 * Prints the image size, its free / occupied / unknown cells, the core grid at --res,
 * the share of legal cells, the bytes of the core's bit grids and of the planner, and
 * with --pgm writes the core grid as an image (written to OUT.pgm.tmp, then renamed).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lx_err.h"
#include "lx_map.h"
#include "rfs_plan.h"

static const char k_usage[] =
    "usage: rfseek-map MAP.yaml [--res M] [--clearance M] [--grid M] [--pgm OUT.pgm]\n"
    "                  [--bench N]\n"
    "Load a ROS map_server map (YAML + PGM) and report it as the rfseek core sees it.\n"
    "  --res M        core cell size in metres (default 0.1)\n"
    "  --clearance M  free space required around a legal point, metres (default 0.25)\n"
    "  --grid M       lattice spacing for search and planning, metres (default 0.25)\n"
    "  --pgm OUT.pgm  write the core grid as a PGM: legal 255, free but too close to a\n"
    "                 wall or the unknown 200, unknown 128, wall 0 (row 0 = top)\n"
    "  --bench N      plan between N random pairs of legal lattice points (seeded) and\n"
    "                 print the planner's median time, expansions and queue use, and the\n"
    "                 median time to derive the legal grid\n"
    "  --help         this text\n"
    "Exit 0 on success, 1 on a bad map or I/O error, 2 on bad options.\n";

static const char PROG[] = "rfseek-map"; /* the prefix of its error lines (lx_err_print) */

/* Option ranges, metres: the core's limits (rfs_map_init: clearance at most 64 m) and
 * lx_map_to_core's (resolution at most 1000 m); both far inside Q16.16's 32767 m, so the
 * conversion below cannot wrap. */
#define MAP_OPT_MAX_M 1000.0
#define MAP_CLEARANCE_MAX_M 64.0

/* A number of metres in [0, max]; one error line and -1 otherwise. */
static int parse_pos(const char *opt, const char *s, double max, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = s != NULL ? strtod(s, &end) : 0.0;
    if (s == NULL || end == s || *end != '\0' || errno != 0 || !isfinite(v) || v < 0) {
        lx_err_print(PROG, "%s: a non-negative number of metres expected, got '%s'", opt,
                 s != NULL ? s : "(nothing)");
        return -1;
    }
    if (v > max) {
        lx_err_print(PROG, "%s: %s m out of range (0 .. %g m)", opt, s, max);
        return -1;
    }
    *out = v;
    return 0;
}

static int write_pgm(const char *path, const lx_core_map_t *c)
{
    char tmp[4096];
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    if (f == NULL) {
        lx_err_print(PROG, "%s: cannot create: %s", tmp, strerror(errno));
        return -1;
    }
    const rfs_map_t *m = &c->map;
    fprintf(f, "P5\n# rfseek-map core grid: legal 255, free 200, unknown 128, wall 0\n%u %u\n255\n",
            m->w, m->h);
    for (int32_t y = (int32_t)m->h - 1; y >= 0; y--) {
        for (uint16_t x = 0; x < m->w; x++) {
            uint8_t v = 128;
            if (rfs_map_bit(m->legal, m->stride, x, (uint16_t)y)) {
                v = 255;
            } else if (rfs_map_bit(m->free, m->stride, x, (uint16_t)y)) {
                v = 200;
            } else if (rfs_map_bit(c->wall_bits, m->stride, x, (uint16_t)y)) {
                v = 0;
            }
            fputc(v, f);
        }
    }
    if (fflush(f) != 0 || ferror(f) || fclose(f) != 0) {
        lx_err_print(PROG, "%s: write error", tmp);
        remove(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        lx_err_print(PROG, "%s: cannot rename to %s: %s", tmp, path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
    double d = *(const double *)a - *(const double *)b;
    return d < 0 ? -1 : d > 0;
}

/* Planner and legal-grid figures for docs/PERFORMANCE.md. */
static void run_bench(const lx_core_map_t *c, long n)
{
    const rfs_map_t *m = &c->map;
    uint32_t lat = (uint32_t)m->lw * m->lh;
    uint32_t cap_big = 4u * lat + 64u;
    uint32_t cap_doc = 2u * ((uint32_t)m->lw + m->lh);
    uint8_t *work = malloc(lat); // NOLINT(clang-analyzer-optin.portability.UnixAPI): an initialised map has lw, lh >= 1
    uint32_t *queue = malloc(cap_big * sizeof(*queue));
    uint8_t *legal = malloc(rfs_map_bytes(m->w, m->h)); // NOLINT(clang-analyzer-optin.portability.UnixAPI): w, h >= 1
    double *t = malloc((size_t)n * sizeof(*t)); // NOLINT(clang-analyzer-optin.portability.UnixAPI): --bench N is 1..1000000
    double *e = malloc((size_t)n * sizeof(*e));
    if (work == NULL || queue == NULL || legal == NULL || t == NULL || e == NULL) {
        fprintf(stderr, "rfseek-map: out of memory for --bench\n");
        exit(1);
    }
    rfs_plan_t big;
    rfs_plan_t doc;
    rfs_plan_init(&big, m, work, lat, queue, cap_big);
    rfs_plan_init(&doc, m, work, lat, queue, cap_doc);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    uint32_t reach = 0;
    uint32_t peak = 0;
    uint32_t doc_fail = 0;
    double ratio_sum = 0;
    long k = 0;
    while (k < n) {
        uint16_t i0 = (uint16_t)rfs_rng_below(&rng, m->lw), j0 = (uint16_t)rfs_rng_below(&rng, m->lh);
        uint16_t i1 = (uint16_t)rfs_rng_below(&rng, m->lw), j1 = (uint16_t)rfs_rng_below(&rng, m->lh);
        if (!rfs_map_lattice_legal(m, i0, j0) || !rfs_map_lattice_legal(m, i1, j1)) {
            continue;
        }
        rfs_q16_t x0, y0, x1, y1;
        rfs_map_lattice_point(m, i0, j0, &x0, &y0);
        rfs_map_lattice_point(m, i1, j1, &x1, &y1);
        rfs_path_t path;
        double t0 = now_s();
        bool ok = rfs_plan_path(&big, x0, y0, x1, y1, &path);
        t[k] = now_s() - t0;
        e[k] = big.expanded;
        if (big.queue_peak > peak) {
            peak = big.queue_peak;
        }
        if (ok) {
            reach++;
            double straight = hypot(x1 - x0, y1 - y0) / 65536.0;
            ratio_sum += straight > 0 ? (path.length / 65536.0) / straight : 1.0;
            rfs_path_t p2;
            doc_fail += !rfs_plan_path(&doc, x0, y0, x1, y1, &p2);
        }
        k++;
    }
    qsort(t, (size_t)n, sizeof(*t), cmp_double);
    qsort(e, (size_t)n, sizeof(*e), cmp_double);
    double tl[7];
    for (int r = 0; r < 7; r++) {
        double t0 = now_s();
        rfs_map_t mm;
        rfs_map_init(&mm, &m->cfg, m->w, m->h, m->res, m->origin_x, m->origin_y, m->free, m->wall, legal);
        tl[r] = now_s() - t0;
    }
    qsort(tl, 7, sizeof(*tl), cmp_double);
    printf("bench        %ld plans between random legal lattice points: %u reachable\n", n, reach);
    printf("bench plan   median %.3f ms, max %.3f ms, median %.0f / max %.0f points expanded\n",
           t[n / 2] * 1e3, t[n - 1] * 1e3, e[n / 2], e[n - 1]);
    printf("bench queue  peak %u entries per quarter (%u for the whole queue); with the\n"
           "             documented 2 * (lw + lh) = %u entries: %u of %u reachable plans failed\n",
           peak, 4 * peak, cap_doc, doc_fail, reach);
    printf("bench path   mean planned length / straight line %.3f\n", reach ? ratio_sum / reach : 0.0);
    printf("bench legal  median %.2f ms to derive the legal grid (rfs_map_init)\n", tl[3] * 1e3);
    /* What planning buys over straight moves only: goals a greedy step (<= 1 m) or an
     * epsilon step (mostly within a few metres) away, from random legal points. */
    const double radii[3] = {1.0, 3.0, 10.0};
    for (int ri = 0; ri < 3; ri++) {
        int32_t rl = (int32_t)lround(radii[ri] / (m->cfg.grid / 65536.0));
        uint32_t los = 0;
        uint32_t planned = 0;
        uint32_t none = 0;
        long got = 0;
        while (got < n) {
            uint16_t i0 = (uint16_t)rfs_rng_below(&rng, m->lw), j0 = (uint16_t)rfs_rng_below(&rng, m->lh);
            int32_t i1 = i0 + (int32_t)rfs_rng_below(&rng, 2u * (uint32_t)rl + 1u) - rl;
            int32_t j1 = j0 + (int32_t)rfs_rng_below(&rng, 2u * (uint32_t)rl + 1u) - rl;
            if ((i1 - i0) * (i1 - i0) + (j1 - j0) * (j1 - j0) > rl * rl || (i1 == i0 && j1 == j0) ||
                i1 < 0 || j1 < 0 || i1 >= m->lw || j1 >= m->lh || !rfs_map_lattice_legal(m, i0, j0) ||
                !rfs_map_lattice_legal(m, (uint16_t)i1, (uint16_t)j1)) {
                continue;
            }
            rfs_q16_t x0, y0, x1, y1;
            rfs_map_lattice_point(m, i0, j0, &x0, &y0);
            rfs_map_lattice_point(m, (uint16_t)i1, (uint16_t)j1, &x1, &y1);
            rfs_path_t path;
            if (rfs_map_segment_legal(m, x0, y0, x1, y1)) {
                los++;
            } else if (rfs_plan_path(&big, x0, y0, x1, y1, &path)) {
                planned++;
            } else {
                none++;
            }
            got++;
        }
        printf("bench goals  within %4.1f m: %5.1f %% in line of sight, %5.1f %% need a planned path, "
               "%5.1f %% unreachable\n", radii[ri], 100.0 * los / n, 100.0 * planned / n, 100.0 * none / n);
    }
    free(work);
    free(queue);
    free(legal);
    free(t);
    free(e);
}

static int map_main(int argc, char **argv)
{
    const char *yaml = NULL;
    const char *pgm = NULL;
    double res = 0.1;
    double clearance = 0.25;
    double grid = 0.25;
    long bench = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(k_usage, stdout);
            return 0;
        } else if (strcmp(a, "--res") == 0 || strcmp(a, "--clearance") == 0 ||
                   strcmp(a, "--grid") == 0 || strcmp(a, "--pgm") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : NULL;
            if (strcmp(a, "--pgm") == 0) {
                if (v == NULL || *v == '\0') {
                    lx_err_print(PROG, "--pgm: an output file name expected");
                    return 2;
                }
                pgm = v;
            } else if (strcmp(a, "--clearance") == 0
                           ? parse_pos(a, v, MAP_CLEARANCE_MAX_M, &clearance) != 0
                           : parse_pos(a, v, MAP_OPT_MAX_M, strcmp(a, "--res") == 0 ? &res : &grid) != 0) {
                return 2;
            }
        } else if (strcmp(a, "--bench") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : NULL;
            char *end = NULL;
            bench = v != NULL ? strtol(v, &end, 10) : -1;
            if (v == NULL || *end != '\0' || bench < 1 || bench > 1000000) {
                lx_err_print(PROG, "--bench: a count 1..1000000 expected, got '%s'", v != NULL ? v : "(nothing)");
                return 2;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            lx_err_print(PROG, "%s: unknown option (see --help)", a);
            return 2;
        } else if (yaml == NULL) {
            yaml = a;
        } else {
            lx_err_print(PROG, "%s: only one map expected (see --help)", a);
            return 2;
        }
    }
    if (yaml == NULL) {
        lx_err_print(PROG, "no map given (see --help)");
        return 2;
    }
    if (!(res > 0) || !(grid > 0)) {
        lx_err_print(PROG, "--res and --grid must be > 0");
        return 2;
    }
    char err[1024];
    lx_map_t m;
    if (pgm != NULL && (lx_err_same_file(PROG, yaml, pgm) != 0 || lx_err_check_dest(PROG, pgm) != 0)) {
        return 1;
    }
    if (lx_map_load(yaml, &m, err, sizeof(err)) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = (rfs_q16_t)lround(clearance * 65536.0);
    cfg.grid = (rfs_q16_t)lround(grid * 65536.0);
    lx_core_map_t c;
    if (lx_map_to_core(&m, res, &cfg, &c, err, sizeof(err)) != 0) {
        lx_err_print(PROG, "%s: %s", yaml, err);
        lx_map_free(&m);
        return 1;
    }
    uint32_t nf;
    uint32_t no;
    uint32_t nu;
    lx_map_count(&m, &nf, &no, &nu);
    const rfs_map_t *cm = &c.map;
    uint32_t cfree = 0;
    uint32_t cwall = 0;
    uint32_t clegal = 0;
    for (uint16_t y = 0; y < cm->h; y++) {
        for (uint16_t x = 0; x < cm->w; x++) {
            cfree += rfs_map_bit(cm->free, cm->stride, x, y);
            cwall += rfs_map_bit(c.wall_bits, cm->stride, x, y);
            clegal += rfs_map_bit(cm->legal, cm->stride, x, y);
        }
    }
    uint32_t llegal = 0;
    for (uint16_t j = 0; j < cm->lh; j++) {
        for (uint16_t i = 0; i < cm->lw; i++) {
            llegal += rfs_map_lattice_legal(cm, i, j);
        }
    }
    uint32_t grid_bytes = rfs_map_bytes(cm->w, cm->h);
    uint32_t cells = (uint32_t)cm->w * cm->h;
    uint32_t lattice = (uint32_t)cm->lw * cm->lh;
    printf("map          %s\n", yaml);
    printf("image        %u x %u cells at %g m = %.2f x %.2f m, origin (%g, %g)\n", m.w, m.h, m.res,
           m.w * m.res, m.h * m.res, m.origin_x, m.origin_y);
    printf("image cells  free %u, occupied %u, unknown %u\n", nf, no, nu);
    printf("core grid    %u x %u cells at %g m (Q16 %.7f m)\n", cm->w, cm->h, res, cm->res / 65536.0);
    printf("core cells   free %u, wall %u, legal %u (clearance %g m)\n", cfree, cwall, clegal,
           clearance);
    printf("legal share  %.1f %% of the core cells, %.1f %% of the free ones\n",
           100.0 * clegal / cells, cfree ? 100.0 * clegal / cfree : 0.0);
    printf("core bytes   %u per bit grid: free + legal %u, with wall %u\n", grid_bytes,
           2 * grid_bytes, 3 * grid_bytes);
    printf("lattice      %u x %u points at %g m, %u legal (%.1f %%)\n", cm->lw, cm->lh, grid, lattice
           ? llegal : 0, lattice ? 100.0 * llegal / lattice : 0.0);
    printf("planner      %u bytes work (1 per lattice point) + queue\n", lattice);
    if (bench > 0) {
        run_bench(&c, bench);
    }
    int rc = 0;
    if (pgm != NULL && write_pgm(pgm, &c) != 0) {
        rc = 1;
    }
    lx_core_map_free(&c);
    lx_map_free(&m);
    return rc;
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, map_main(argc, argv));
}
