/* hs_sim_env.c - what every run of a scenario shares (hs_sim.h, hs_sim_env_t): the map, the
 * core's grids and attached tables, the checks of the start, sources and faults against
 * them, and the shortest paths. */
#include "hs_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hs_box2d.h"
#include "hs_faults.h"
#include "hs_paths.h"
#include "hs_radio.h"
#include "rfs_pathloss.h"


static int check_point(const hs_sim_env_t *e, const char *field, double x, double y, char *err,
                       size_t errlen)
{
    uint32_t cx, cy;
    if (!lx_map_cell_at(&e->map, x, y, &cx, &cy)) {
        snprintf(err, errlen, "%s: %s: (%.2f, %.2f) is off the map", e->sc.path, field, x, y);
        return -1;
    }
    uint8_t c = e->map.cell[(size_t)cy * e->map.w + cx];
    if (c != LX_CELL_FREE) {
        snprintf(err, errlen, "%s: %s: (%.2f, %.2f) is inside a wall (%s cell)", e->sc.path,
                 field, x, y, c == LX_CELL_OCC ? "occupied" : "unknown");
        return -1;
    }
    return 0;
}

/* The scenario's positions: sources, start and one-shot faults on free cells, the start
 * legal for the core (clearance). 0, or -1 with err set. */
static int check_positions(const hs_sim_env_t *e, char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    for (unsigned s = 0; s < sc->nsources; s++) {
        char f[48];
        snprintf(f, sizeof f, "sources[%u].position", s);
        if (check_point(e, f, sc->src[s].x, sc->src[s].y, err, errlen) != 0) {
            return -1;
        }
    }
    if (check_point(e, "start.position", sc->start_x, sc->start_y, err, errlen) != 0) {
        return -1;
    }
    for (unsigned i = 0; i < sc->faults.n; i++) {
        char f[48];
        snprintf(f, sizeof f, "faults[%u].position", i);
        if (hs_faults_one_shot(sc->faults.f[i].kind) &&
            check_point(e, f, sc->faults.f[i].x, sc->faults.f[i].y, err, errlen) != 0) {
            return -1;
        }
    }
    rfs_q16_t qx = (rfs_q16_t)lround(sc->start_x * 65536.0);
    rfs_q16_t qy = (rfs_q16_t)lround(sc->start_y * 65536.0);
    if (!rfs_map_point_legal(&e->core.map, qx, qy)) {
        snprintf(err, errlen,
                 "%s: start.position: (%.2f, %.2f) is closer than the clearance (%.2f m) to a "
                 "wall or unknown cell",
                 sc->path, sc->start_x, sc->start_y, sc->clearance_m);
        return -1;
    }
    return 0;
}

/* The shortest paths from the start to the goal and into the stop radius, checked to
 * exist for the cells and for the controller's lattice. 0, or -1 with err set. */
static int shortest_paths(hs_sim_env_t *e, char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    const rfs_map_t *cm = &e->core.map;
    double *dist = calloc((size_t)cm->w * cm->h, sizeof(double)); // all set by hs_paths_dist
    if (!dist) {
        snprintf(err, errlen, "%s: out of memory", sc->path);
        return -1;
    }
    double res = cm->res / 65536.0;
    long sx = (long)((sc->start_x - e->x0) / res), sy = (long)((sc->start_y - e->y0) / res);
    if (hs_paths_dist(cm, sx, sy, dist) != 0) {
        free(dist);
        snprintf(err, errlen, "%s: out of memory", sc->path);
        return -1;
    }
    // Nearest reachable cell to the goal, and the shortest path into the stop radius.
    hs_paths_goal_t gp;
    hs_paths_goal(cm, e->x0, e->y0, dist, sc->goal_x, sc->goal_y, sc->stop_radius_m, -1.0, &gp);
    free(dist);
    if (!isfinite(gp.stop_m)) {
        snprintf(err, errlen,
                 "%s: stop.radius_m: the robot can never get within %.2f m of the goal "
                 "(%.2f, %.2f): the nearest point it can reach is %.2f m away",
                 sc->path, sc->stop_radius_m, sc->goal_x, sc->goal_y, gp.near_m);
        return -1;
    }
    int lr = hs_paths_lattice_reaches(cm, sc->start_x, sc->start_y, sc->goal_x, sc->goal_y,
                             sc->stop_radius_m);
    if (lr <= 0) {
        if (lr < 0) {
            snprintf(err, errlen, "%s: out of memory", sc->path);
        } else {
            snprintf(err, errlen,
                     "%s: stop.radius_m: the controller's planner (0.25 m lattice) cannot get "
                     "within %.2f m of the goal (%.2f, %.2f): a door on the way is too narrow "
                     "for the clearance on the core grid",
                     sc->path, sc->stop_radius_m, sc->goal_x, sc->goal_y);
        }
        return -1;
    }
    e->shortest_path_m = gp.path_m;
    e->shortest_to_stop_m = gp.stop_m;
    return 0;
}

/* Everything after the map: positions, wall-count caches, shortest paths. 0, or -1 with
 * err set. */
static int env_prepare(hs_sim_env_t *e, char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    if (check_positions(e, err, errlen) != 0) {
        return -1;
    }
    // Wall counts depend on the geometry only, not on the seed: one cache for all runs.
    size_t wcb = hs_radio_wall_cache_bytes(&sc->radio, e->x0, e->y0, e->x1, e->y1);
    for (unsigned s = 0; s < sc->nsources; s++) {
        e->wall_cache[s] = e->wall_cache[s] ? e->wall_cache[s] : malloc(wcb); // placed again: same size
        if (!e->wall_cache[s]) {
            snprintf(err, errlen, "%s: out of memory", sc->path);
            return -1;
        }
        memset(e->wall_cache[s], -1, wcb);
    }
    e->shortest_path_m = NAN;
    e->shortest_to_stop_m = NAN;
    bool has_goal = sc->has_goal || sc->nsources == 1;
    if (has_goal && sc->stop_radius_m > 0.0) {
        return shortest_paths(e, err, errlen);
    }
    return 0;
}

int hs_sim_env_open(hs_sim_env_t *e, const hs_scenario_t *sc, char *err, size_t errlen)
{
    memset(e, 0, sizeof *e);
    e->sc = *sc;
    char merr[512];
    if (lx_map_load(sc->map_path, &e->map, merr, sizeof merr) != 0) {
        snprintf(err, errlen, "%s: map: %s", sc->path, merr);
        return -1;
    }
    e->x0 = e->map.origin_x;
    e->y0 = e->map.origin_y;
    e->x1 = e->map.origin_x + e->map.w * e->map.res;
    e->y1 = e->map.origin_y + e->map.h * e->map.res;
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    mc.clearance = (rfs_q16_t)lround(sc->clearance_m * 65536.0);
    if (lx_map_to_core(&e->map, sc->core_res_m, &mc, &e->core, merr, sizeof merr) != 0) {
        snprintf(err, errlen, "%s: map: %s: %s", sc->path, sc->map_path, merr);
        hs_sim_env_close(e);
        return -1;
    }
    /* Planning without step patterns (the lattice not a multiple of the core grid) tests
     * each lattice edge once per map instead of once per search. */
    const uint32_t ne = rfs_map_memo_entries(&e->core.map);
    e->lattice_memo = malloc((size_t)ne * sizeof(e->lattice_memo[0]));
    if (e->lattice_memo == NULL || rfs_map_memo_attach(&e->core.map, e->lattice_memo, ne) != 0) {
        snprintf(err, errlen, "%s: map: out of memory", sc->path);
        hs_sim_env_close(e);
        return -1;
    }
    /* Each lattice point's legal edges once per map: a search reads them in one load. */
    e->lattice_edges = malloc((size_t)ne * sizeof(e->lattice_edges[0]));
    if (e->lattice_edges == NULL ||
        rfs_map_edges_attach(&e->core.map, e->lattice_edges, ne) != 0) {
        snprintf(err, errlen, "%s: map: out of memory", sc->path);
        hs_sim_env_close(e);
        return -1;
    }
    /* Every run's world from the same merged walls, the first run's reset for the next. */
    e->world = calloc(1, sizeof(hs_box2d_t *));
    if (e->world == NULL || hs_box2d_walls_make(&e->map, &e->walls) != 0) {
        snprintf(err, errlen, "%s: map: out of memory", sc->path);
        hs_sim_env_close(e);
        return -1;
    }
    /* The path-loss model's wall counts pass over free squares (rfs_map_wall_dist_attach)
     * and the free squares ahead of the walk (rfs_map_wall_fwd_attach), and read steep
     * walks' columns a word at a time (rfs_map_wall_cols_attach). */
    if (e->core.map.wall != NULL) {
        const uint32_t nd = rfs_map_wall_dist_bytes(&e->core.map);
        const uint32_t nf = rfs_map_wall_fwd_bytes(&e->core.map);
        const uint32_t nc = rfs_map_wall_cols_bytes(&e->core.map);
        e->wall_dist = malloc(nd);
        e->wall_fwd = malloc(nf);
        e->wall_cols = malloc(nc);
        if (e->wall_dist == NULL || e->wall_fwd == NULL || e->wall_cols == NULL ||
            rfs_map_wall_dist_attach(&e->core.map, e->wall_dist, nd) != 0 ||
            rfs_map_wall_fwd_attach(&e->core.map, e->wall_fwd, nf) != 0 ||
            rfs_map_wall_cols_attach(&e->core.map, e->wall_cols, nc) != 0) {
            snprintf(err, errlen, "%s: map: out of memory", sc->path);
            hs_sim_env_close(e);
            return -1;
        }
    }
    /* The path-loss model's distance terms read their logarithms from one table. */
    if (strcmp(sc->model, "pathloss") == 0) {
        e->pathloss_log2 = malloc(RFS_PATHLOSS_LOG2_ENTRIES * sizeof(e->pathloss_log2[0]));
        if (e->pathloss_log2 == NULL) {
            snprintf(err, errlen, "%s: map: out of memory", sc->path);
            hs_sim_env_close(e);
            return -1;
        }
        rfs_pathloss_log2_fill(e->pathloss_log2);
    }
    if (env_prepare(e, err, errlen) != 0) {
        hs_sim_env_close(e);
        return -1;
    }
    return 0;
}

int hs_sim_env_place(hs_sim_env_t *e, uint64_t index, uint64_t seed, double sx, double sy,
                     double stheta, double gx, double gy, char *err, size_t errlen)
{
    hs_scenario_t *sc = &e->sc;
    if (sc->nsources != 1 || sc->has_goal || !(sc->stop_radius_m > 0.0)) {
        snprintf(err, errlen, "%s: placements need one source, no stop.goal and a stop radius",
                 sc->path);
        return -1;
    }
    sc->start_x = sx;
    sc->start_y = sy;
    sc->start_theta = stheta;
    sc->src[0].x = gx;
    sc->src[0].y = gy;
    sc->goal_x = gx;
    sc->goal_y = gy;
    e->placement = index;
    e->placement_seed = seed;
    return env_prepare(e, err, errlen);
}

void hs_sim_env_close(hs_sim_env_t *e)
{
    for (unsigned s = 0; s < HS_SCN_MAX_SOURCES; s++) {
        free(e->wall_cache[s]);
        e->wall_cache[s] = NULL;
    }
    lx_core_map_free(&e->core);
    free(e->lattice_memo);
    e->lattice_memo = NULL;
    free(e->lattice_edges);
    e->lattice_edges = NULL;
    free(e->wall_dist);
    e->wall_dist = NULL;
    free(e->wall_fwd);
    e->wall_fwd = NULL;
    free(e->wall_cols);
    e->wall_cols = NULL;
    free(e->pathloss_log2);
    e->pathloss_log2 = NULL;
    hs_box2d_walls_free(&e->walls);
    if (e->world != NULL) {
        hs_box2d_destroy(*e->world);
        free(e->world);
        e->world = NULL;
    }
    lx_map_free(&e->map);
}

