/* hs_scenario.c - scenario YAML loader (see hs_scenario.h). */
#include "hs_scenario.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lx_err.h"
#include "lx_yaml.h"
#include "rfs_models.h"

typedef struct pctx {
    const char *file;
    char *err;
    size_t errlen;
} pctx_t;

static int fail(pctx_t *p, const lx_yaml_node_t *n, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (n) {
        snprintf(p->err, p->errlen, "%s:%lu: %s", p->file, n->line,
                 msg);
    } else {
        snprintf(p->err, p->errlen, "%s: %s", p->file, msg);
    }
    lx_err_one_line(p->err); /* a key or value from the YAML can hold line breaks */
    return -1;
}

/// The mapping must be a mapping whose keys are unique scalars from `allowed`.
static int check_keys(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *const *allowed)
{
    if (!m || m->kind != LX_YAML_MAPPING) {
        return fail(p, m, "%s: expected a mapping", where);
    }
    for (size_t a = 0; a < m->n; a++) {
        const lx_yaml_node_t *k = m->child[2 * a];
        const char *ks = lx_yaml_scalar(k);
        if (!ks) {
            return fail(p, k, "%s: keys must be plain words", where);
        }
        bool ok = false;
        for (const char *const *w = allowed; *w; w++) {
            ok |= strcmp(*w, ks) == 0;
        }
        if (!ok) {
            return fail(p, k, "%s: unknown key '%s'", where, ks);
        }
        for (size_t b = 0; b < a; b++) {
            if (strcmp(lx_yaml_scalar(m->child[2 * b]), ks) == 0) {
                return fail(p, k, "%s: duplicate key '%s'", where, ks);
            }
        }
    }
    return 0;
}

static int to_num(pctx_t *p, const lx_yaml_node_t *n, const char *where, double lo, double hi, double *out)
{
    const char *s = lx_yaml_scalar(n);
    if (!s || !*s) {
        return fail(p, n, "%s: expected a number", where);
    }
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (*end != '\0' || errno != 0 || !isfinite(v)) {
        return fail(p, n, "%s: '%s' is not a number", where, s);
    }
    if (v < lo || v > hi) {
        return fail(p, n, "%s: %g is out of range [%g, %g]", where, v, lo, hi);
    }
    *out = v;
    return 0;
}

/// Optional number field `key` of mapping m.
static int num(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *key, double lo,
               double hi, double *out)
{
    const lx_yaml_node_t *n = lx_yaml_get(m, key);
    if (!n) {
        return 0;
    }
    char w[128];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return to_num(p, n, w, lo, hi, out);
}

/// Optional whole number field `key` of mapping m, in [0, hi] (*out untouched when absent).
static int whole(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *key, double hi,
                 double *out)
{
    double v = -1.0;
    if (num(p, m, where, key, 0, hi, &v) != 0) {
        return -1;
    }
    if (v != floor(v)) {
        return fail(p, lx_yaml_get(m, key), "%s.%s: %g is not a whole number", where, key, v);
    }
    if (v >= 0.0) {
        *out = v;
    }
    return 0;
}

static int boolean(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *key, bool *out)
{
    const lx_yaml_node_t *n = lx_yaml_get(m, key);
    if (!n) {
        return 0;
    }
    const char *s = lx_yaml_scalar(n);
    if (s && (strcmp(s, "true") == 0 || strcmp(s, "yes") == 0 || strcmp(s, "on") == 0)) {
        *out = true;
    } else if (s && (strcmp(s, "false") == 0 || strcmp(s, "no") == 0 || strcmp(s, "off") == 0)) {
        *out = false;
    } else {
        return fail(p, n, "%s.%s: expected true or false", where, key);
    }
    return 0;
}

/// seek.KEY as 0 / 1 when present; *out keeps -1 (the strategy's preset) when absent.
static int preset_bool(pctx_t *p, const lx_yaml_node_t *m, const char *key, int *out)
{
    bool v = false;
    if (lx_yaml_get(m, key) == NULL) {
        return 0;
    }
    if (boolean(p, m, "seek", key, &v) != 0) {
        return -1;
    }
    *out = v ? 1 : 0;
    return 0;
}

static int str(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *key, char *out,
               size_t cap)
{
    const lx_yaml_node_t *n = lx_yaml_get(m, key);
    if (!n) {
        return 0;
    }
    const char *s = lx_yaml_scalar(n);
    if (!s || !*s) {
        return fail(p, n, "%s.%s: expected a word", where, key);
    }
    if (strlen(s) >= cap) {
        return fail(p, n, "%s.%s: longer than %zu characters", where, key, cap - 1);
    }
    snprintf(out, cap, "%s", s);
    return 0;
}

/// A [x, y] pair (required when `need`).
static int xy(pctx_t *p, const lx_yaml_node_t *m, const char *where, const char *key, bool need,
              double *x, double *y, bool *present)
{
    const lx_yaml_node_t *n = lx_yaml_get(m, key);
    if (present) {
        *present = n != NULL;
    }
    if (!n) {
        return need ? fail(p, m, "%s: missing '%s'", where, key) : 0;
    }
    if (n->kind != LX_YAML_SEQUENCE || n->n != 2) {
        return fail(p, n, "%s.%s: expected [x, y] in metres", where, key);
    }
    char w[128];
    snprintf(w, sizeof w, "%s.%s", where, key);
    if (to_num(p, n->child[0], w, -1e5, 1e5,
               x) != 0 ||
        to_num(p, n->child[1], w, -1e5, 1e5,
               y) != 0) {
        return -1;
    }
    return 0;
}

int hs_scenario_parse_mac(const char *s, uint8_t mac[6])
{
    unsigned v[6];
    char tail;
    // %2x alone would accept a sign or blanks ("-1:00:00:00:00:00"): check every character.
    for (int i = 0; s && i < 17; i++) {
        const char c = s[i];
        const bool hex = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
        if (i % 3 == 2 ? c != ':' : !hex) {
            return -1;
        }
    }
    // NOLINTNEXTLINE(cert-err34-c): every character was checked above, %2x cannot overflow
    if (!s || sscanf(s, "%2x:%2x:%2x:%2x:%2x:%2x%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                     &tail) != 6 || strlen(s) != 17) {
        return -1;
    }
    for (int i = 0; i < 6; i++) {
        mac[i] = (uint8_t)v[i];
    }
    return 0;
}

void hs_scenario_defaults(hs_scenario_t *sc)
{
    memset(sc, 0, sizeof *sc);
    sc->seed = 1;
    sc->seek_recheck_m = -1.0;
    sc->seek_refute_m = -1.0;
    sc->seek_silence_floor = -1;
    sc->seek_refute_reached = -1;
    sc->seek_recheck_silent = -1;
    sc->seek_local_m = -1.0;
    sc->seek_leg_m = -1.0;
    sc->seek_floor_db = -1.0;
    sc->seek_floor_max = -1.0;
    sc->seek_mean_t = -1.0;
    sc->seek_local_gap_m = -1.0;
    sc->seek_local_refute = -1;
    sc->seek_at_tol_m = -1.0;
    sc->seek_near_t = -1.0;
    sc->seek_near_m = -1.0;
    sc->seek_reach_min = -1.0;
    sc->seek_fit_slices = -1.0;
    sc->seek_fit_early = -1;
    sc->seek_fit_budget = -1.0;
    sc->seek_eps_by_travel = -1;
    sc->seek_eps_geodesic = -1;
    sc->seek_recheck_adapt = -1;
    sc->seek_eps_sample = -1;
    sc->seek_p0_min_dbm = NAN;
    sc->seek_coarse_footprint_m = NAN;
    sc->seek_coarse_snap = -1;
    sc->seek_p0_max_wall_db = NAN;
    sc->seek_eps_rate = -1.0;
    snprintf(sc->model, sizeof sc->model, "ridge");
    snprintf(sc->target, sizeof sc->target, "rssi");
    snprintf(sc->strategy, sizeof sc->strategy, "meta");
    sc->pose_rate_hz = 10.0;          // a localisation system's usual rate (amcl-like)
    sc->pose_sigma_xy_m = 0.05;
    sc->pose_sigma_theta_rad = 0.02;
    sc->pose_drift_m = 0.0;
    sc->pose_drift_tau_s = 10.0;
    sc->pose_jump_m = 0.3;
    sc->pose_jump_rate_hz = 1.0 / 60.0;
    sc->pose_jump_tau_s = 3.0;
    sc->radio = hs_radio_cfg_default();
    sc->rx_heartbeat = true;          // a listening receiver reports itself up
    sc->motor = hs_motor_cfg_default();
    sc->stop_radius_m = 1.5;          // the run ends within 1.5 m of the source
    sc->stop_distance_m = 150.0;
    sc->stop_time_s = 900.0;
    sc->physics_hz = 50.0;
    sc->core_res_m = 0.1;
    sc->clearance_m = 0.25;           // paper defaults (PREAMBLE): 0.25 m clearance
}

/// radio: the radio model, and radio.receiver.heartbeat (the controller's receiver
/// reports), which belongs to the run rather than to the radio model.
static int parse_radio(pctx_t *p, const lx_yaml_node_t *r, hs_radio_cfg_t *c, bool *heartbeat)
{
    static const char *const top[] = {"pathloss", "walls", "shadowing", "fading", "noise",
                                      "receiver", NULL};
    if (check_keys(p, r, "radio", top) != 0) {
        return -1;
    }
    const lx_yaml_node_t *n;
    if ((n = lx_yaml_get(r, "pathloss"))) {
        static const char *const k[] = {"enabled", "exponent", "ref_dist_m", "ref_loss_db", NULL};
        if (check_keys(p, n, "radio.pathloss", k) || boolean(p, n, "radio.pathloss", "enabled", &c->pathloss) ||
            num(p, n, "radio.pathloss", "exponent", 0, 10, &c->exponent) ||
            num(p, n, "radio.pathloss", "ref_dist_m", 1e-3, 100, &c->ref_dist_m) ||
            num(p, n, "radio.pathloss", "ref_loss_db", -200, 200, &c->ref_loss_db)) {
            return -1;
        }
    }
    if ((n = lx_yaml_get(r, "walls"))) {
        static const char *const k[] = {"enabled", "db_per_wall", "cache_m", NULL};
        if (check_keys(p, n, "radio.walls", k) || boolean(p, n, "radio.walls", "enabled", &c->walls) ||
            num(p, n, "radio.walls", "db_per_wall", 0, 100, &c->wall_db) ||
            num(p, n, "radio.walls", "cache_m", 0.01, 10, &c->wall_cache_m)) {
            return -1;
        }
    }
    if ((n = lx_yaml_get(r, "shadowing"))) {
        static const char *const k[] = {"enabled", "sigma_db", "dcorr_m", "grid_m", "waves", NULL};
        double waves = c->shadow_waves;
        if (check_keys(p, n, "radio.shadowing", k) ||
            boolean(p, n, "radio.shadowing", "enabled", &c->shadowing) ||
            num(p, n, "radio.shadowing", "sigma_db", 0, 30, &c->shadow_sigma_db) ||
            num(p, n, "radio.shadowing", "dcorr_m", 0.01, 1000, &c->shadow_dcorr_m) ||
            num(p, n, "radio.shadowing", "grid_m", 0.01, 10, &c->shadow_grid_m) ||
            num(p, n, "radio.shadowing", "waves", 1, 100000, &waves)) {
            return -1;
        }
        c->shadow_waves = (uint32_t)waves;
    }
    if ((n = lx_yaml_get(r, "fading"))) {
        static const char *const k[] = {"enabled", "wavelength_m", "rician_k_db", "waves", NULL};
        double waves = c->fading_waves;
        if (check_keys(p, n, "radio.fading", k) || boolean(p, n, "radio.fading", "enabled", &c->fading) ||
            num(p, n, "radio.fading", "wavelength_m", 0.001, 10, &c->wavelength_m) ||
            num(p, n, "radio.fading", "rician_k_db", -50, 50, &c->rician_k_db) ||
            num(p, n, "radio.fading", "waves", 1, 4096, &waves)) {
            return -1;
        }
        c->fading_waves = (uint32_t)waves;
    }
    if ((n = lx_yaml_get(r, "noise"))) {
        static const char *const k[] = {"enabled", "sigma_db", NULL};
        if (check_keys(p, n, "radio.noise", k) || boolean(p, n, "radio.noise", "enabled", &c->noise) ||
            num(p, n, "radio.noise", "sigma_db", 0, 30, &c->noise_sigma_db)) {
            return -1;
        }
    }
    if ((n = lx_yaml_get(r, "receiver"))) {
        static const char *const k[] = {"quantise", "clip", "min_dbm", "max_dbm", "loss",
                                        "sensitivity_dbm", "loss_width_db", "heartbeat", NULL};
        if (check_keys(p, n, "radio.receiver", k) ||
            boolean(p, n, "radio.receiver", "quantise", &c->quantise) ||
            boolean(p, n, "radio.receiver", "clip", &c->clip) ||
            num(p, n, "radio.receiver", "min_dbm", -127, 127, &c->rx_min_dbm) ||
            num(p, n, "radio.receiver", "max_dbm", -127, 127, &c->rx_max_dbm) ||
            boolean(p, n, "radio.receiver", "loss", &c->loss) ||
            num(p, n, "radio.receiver", "sensitivity_dbm", -200, 100, &c->sensitivity_dbm) ||
            num(p, n, "radio.receiver", "loss_width_db", 0.01, 50, &c->loss_width_db) ||
            boolean(p, n, "radio.receiver", "heartbeat", heartbeat)) {
            return -1;
        }
        if (c->rx_min_dbm >= c->rx_max_dbm) {
            return fail(p, n, "radio.receiver: min_dbm must be below max_dbm");
        }
    }
    return 0;
}

/// faults: a list of {kind, start_s, duration_s, ...} (hs_faults.h, docs/FAULTS.md).
static int parse_faults(pctx_t *p, const lx_yaml_node_t *n, hs_scenario_t *sc)
{
    if (n->kind != LX_YAML_SEQUENCE) {
        return fail(p, n, "faults: expected a list of faults");
    }
    long nf = (long)n->n;
    if (nf > (long)HS_FAULTS_MAX) {
        return fail(p, n, "faults: %ld given, at most %u", nf, HS_FAULTS_MAX);
    }
    static const char *const k[] = {"kind", "start_s", "duration_s", "offset", "position",
                                    "theta", "lag_s", "lead_s", "probability", "source", NULL};
    for (long i = 0; i < nf; i++) {
        const lx_yaml_node_t *f = n->child[i];
        char where[32], kind[32] = "";
        snprintf(where, sizeof where, "faults[%ld]", i);
        if (check_keys(p, f, where, k) || str(p, f, where, "kind", kind, sizeof kind)) {
            return -1;
        }
        hs_fault_kind_t fk;
        if (!hs_faults_kind_parse(kind, &fk)) {
            return fail(p, lx_yaml_get(f, "kind") ? lx_yaml_get(f, "kind") : f,
                        "%s.kind: '%s' is not a fault (rssi_silence, rssi_past, rssi_reorder, "
                        "rssi_future, pose_jump, pose_past, pose_reorder, pose_future, can_drop, "
                        "bus_off, source_move, kidnap)", where, kind);
        }
        // Parameters a kind does not use are errors, not silently ignored.
        static const struct {
            const char *key;
            unsigned kinds; // bit per hs_fault_kind_t
        } use[] = {
            {"offset", 1u << HS_FAULT_POSE_JUMP},
            {"lag_s", 1u << HS_FAULT_RSSI_PAST | 1u << HS_FAULT_POSE_PAST},
            {"lead_s", 1u << HS_FAULT_RSSI_FUTURE | 1u << HS_FAULT_POSE_FUTURE},
            {"probability", 1u << HS_FAULT_CAN_DROP},
            {"source", 1u << HS_FAULT_SOURCE_MOVE},
            {"position", 1u << HS_FAULT_SOURCE_MOVE | 1u << HS_FAULT_KIDNAP},
            {"theta", 1u << HS_FAULT_KIDNAP},
        };
        for (size_t u = 0; u < sizeof use / sizeof use[0]; u++) {
            if (lx_yaml_get(f, use[u].key) && !(use[u].kinds & (1u << fk))) {
                return fail(p, lx_yaml_get(f, use[u].key), "%s.%s: does not apply to %s", where,
                            use[u].key, kind);
            }
        }
        hs_fault_t *ft = &sc->faults.f[i];
        *ft = hs_faults_default(fk);
        double src = 0.0;
        bool need_pos = fk == HS_FAULT_SOURCE_MOVE || fk == HS_FAULT_KIDNAP;
        if (num(p, f, where, "start_s", 0, 1e6, &ft->start_s) ||
            num(p, f, where, "duration_s", 0, 1e6, &ft->duration_s) ||
            num(p, f, where, "theta", -7, 7, &ft->theta) ||
            num(p, f, where, "lag_s", 0, 3600, &ft->lag_s) ||
            num(p, f, where, "lead_s", 0, 3600, &ft->lag_s) ||
            num(p, f, where, "probability", 0, 1, &ft->probability) ||
            num(p, f, where, "source", 0, HS_SCN_MAX_SOURCES - 1, &src) ||
            (fk == HS_FAULT_POSE_JUMP && xy(p, f, where, "offset", false, &ft->x, &ft->y, NULL)) ||
            (need_pos && xy(p, f, where, "position", true, &ft->x, &ft->y, NULL))) {
            return -1;
        }
        ft->source = (unsigned)src;
        char ferr[256];
        if (src != (double)ft->source || hs_faults_check(ft, sc->nsources, ferr, sizeof ferr) != 0) {
            return fail(p, f, "%s.%s", where, src != (double)ft->source ? "source: expected an index" : ferr);
        }
    }
    sc->faults.n = (unsigned)nf;
    return 0;
}

/* map: the map_server YAML's path, relative to the scenario's folder unless absolute. */
static int parse_map_path(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "map");
    const char *mp = lx_yaml_scalar(n);
    if (!mp || !*mp) {
        return fail(p, n ? n : root, "map: missing (path of a map_server YAML)");
    }
    if (mp[0] == '/') {
        snprintf(sc->map_path, sizeof sc->map_path, "%s", mp);
    } else {
        const char *slash = strrchr(p->file, '/');
        int dl = slash ? (int)(slash - p->file + 1) : 0;
        if ((size_t)dl + strlen(mp) + 1 > sizeof sc->map_path) {
            return fail(p, n, "map: path too long");
        }
        snprintf(sc->map_path, sizeof sc->map_path, "%.*s%s", dl, p->file, mp);
    }
    return 0;
}

/* seed (optional): a non-negative integer. */
static int parse_seed(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "seed");
    if (n) {
        const char *s = lx_yaml_scalar(n);
        char *end;
        errno = 0;
        unsigned long long v = s && *s && *s != '-' ? strtoull(s, &end, 10) : 0;
        if (!s || !*s || *s == '-' || *end != '\0' || errno != 0) {
            return fail(p, n, "seed: expected a non-negative integer");
        }
        sc->seed = v;
    }
    return 0;
}

/* seek (optional): the strategy's settings. */
static int parse_seek(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "seek");
    if (n) {
        static const char *const k[] = {"recheck_m", "eps_by_travel", "eps_rate",
                                        "eps_geodesic", "recheck_adapt", "p0_min_dbm",
                                        "eps_sample", "refute_m", "silence_floor",
                                        "refute_reached", "local_m", "leg_m", "recheck_silent",
                                        "coarse_footprint_m", "p0_max_wall_db", "local_gap_m",
                                        "at_tol_m", "local_refute", "near_t",
                                        "near_m", "coarse_snap", "reach_min", "fit_budget", "fit_slices", "fit_early",
                                        "floor_db", "floor_max", "mean_t", NULL};
        if (check_keys(p, n, "seek", k) ||
            num(p, n, "seek", "recheck_m", 0, 100, &sc->seek_recheck_m) ||
            num(p, n, "seek", "refute_m", 0, 100, &sc->seek_refute_m) ||
            num(p, n, "seek", "local_m", 0, 100, &sc->seek_local_m) ||
            num(p, n, "seek", "leg_m", 0, 1000, &sc->seek_leg_m) ||
            num(p, n, "seek", "floor_db", 0, 60, &sc->seek_floor_db) ||
            num(p, n, "seek", "mean_t", 0, 64, &sc->seek_mean_t) ||
            num(p, n, "seek", "local_gap_m", 0, 100, &sc->seek_local_gap_m) ||
            num(p, n, "seek", "at_tol_m", 0, 1, &sc->seek_at_tol_m) ||
            num(p, n, "seek", "near_t", 0, 64, &sc->seek_near_t) ||
            num(p, n, "seek", "near_m", 0, 1000, &sc->seek_near_m) ||
            whole(p, n, "seek", "reach_min", 1e6, &sc->seek_reach_min) ||
            whole(p, n, "seek", "fit_slices", 1000, &sc->seek_fit_slices) ||
            whole(p, n, "seek", "floor_max", 255, &sc->seek_floor_max) ||
            whole(p, n, "seek", "fit_budget", 1e6, &sc->seek_fit_budget) ||
            num(p, n, "seek", "eps_rate", 0, 100, &sc->seek_eps_rate) ||
            num(p, n, "seek", "p0_min_dbm", -200, 100, &sc->seek_p0_min_dbm) ||
            num(p, n, "seek", "coarse_footprint_m", 0, 0.5, &sc->seek_coarse_footprint_m) ||
            num(p, n, "seek", "p0_max_wall_db", 0, 60, &sc->seek_p0_max_wall_db) ||
            preset_bool(p, n, "eps_by_travel", &sc->seek_eps_by_travel) ||
            preset_bool(p, n, "eps_geodesic", &sc->seek_eps_geodesic) ||
            preset_bool(p, n, "recheck_adapt", &sc->seek_recheck_adapt) ||
            preset_bool(p, n, "eps_sample", &sc->seek_eps_sample) ||
            preset_bool(p, n, "silence_floor", &sc->seek_silence_floor) ||
            preset_bool(p, n, "refute_reached", &sc->seek_refute_reached) ||
            preset_bool(p, n, "local_refute", &sc->seek_local_refute) ||
            preset_bool(p, n, "coarse_snap", &sc->seek_coarse_snap) ||
            preset_bool(p, n, "fit_early", &sc->seek_fit_early) ||
            preset_bool(p, n, "recheck_silent", &sc->seek_recheck_silent)) {
            return -1;
        }
    }
    return 0;
}

/* The model a known one, the target rssi, bridge or pdr. */
static int check_model_target(pctx_t *p, const lx_yaml_node_t *root, const hs_scenario_t *sc)
{
    if (!rfs_models_lookup(sc->model)) {
        char names[256] = "";
        size_t used = 0;
        for (uint32_t i = 0; i < rfs_models_count() && used < sizeof names; i++) {
            int k = snprintf(names + used, sizeof names - used, "%s%s", i ? ", " : "",
                             rfs_models_at(i)->name);
            used += k > 0 ? (size_t)k : 0;
        }
        return fail(p, lx_yaml_get(root, "model"), "model: '%s' is not a known model (%s)", sc->model,
                    names);
    }
    if (strcmp(sc->target, "rssi") != 0 && strcmp(sc->target, "bridge") != 0 &&
        strcmp(sc->target, "pdr") != 0) {
        return fail(p, lx_yaml_get(root, "target"), "target: '%s' is not rssi, bridge or pdr",
                    sc->target);
    }
    return 0;
}

/* sources[i]: its defaults, then its keys. */
static int parse_source(pctx_t *p, const lx_yaml_node_t *s, long i, hs_scn_source_t *src)
{
    static const char *const k[] = {"name", "position", "mac", "rate_hz", "tx_dbm", NULL};
    char where[32];
    snprintf(where, sizeof where, "sources[%ld]", i);
    snprintf(src->name, sizeof src->name, "src%ld", i);
    src->rate_hz = 200.0; // paper section 5: about 200 packets/s
    src->tx_dbm = 20.0;   // a typical 2.4 GHz access point (100 mW)
    src->mac[0] = 0x02;   // locally administered, unique per index
    src->mac[5] = (uint8_t)(i + 1);
    if (check_keys(p, s, where, k) || str(p, s, where, "name", src->name, sizeof src->name) ||
        xy(p, s, where, "position", true, &src->x, &src->y, NULL) ||
        num(p, s, where, "rate_hz", 0.1, 10000, &src->rate_hz) ||
        num(p, s, where, "tx_dbm", -50, 50, &src->tx_dbm)) {
        return -1;
    }
    const lx_yaml_node_t *m = lx_yaml_get(s, "mac");
    if (m && hs_scenario_parse_mac(lx_yaml_scalar(m), src->mac) != 0) {
        return fail(p, m, "%s.mac: expected aa:bb:cc:dd:ee:ff", where);
    }
    return 0;
}

/* sources: 1 or 2, as many as the target needs. */
static int parse_sources(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "sources");
    if (!n || n->kind != LX_YAML_SEQUENCE) {
        return fail(p, n ? n : root, "sources: missing (a list of 1 or 2 sources)");
    }
    long ns = (long)n->n;
    if (ns < 1 || ns > (long)HS_SCN_MAX_SOURCES) {
        return fail(p, n, "sources: %ld given, need 1 or %u", ns, HS_SCN_MAX_SOURCES);
    }
    sc->nsources = (unsigned)ns;
    for (long i = 0; i < ns; i++) {
        const lx_yaml_node_t *s = n->child[i];
        if (parse_source(p, s, i, &sc->src[i]) != 0) {
            return -1;
        }
    }
    if (strcmp(sc->target, "bridge") == 0 && sc->nsources != 2) {
        return fail(p, lx_yaml_get(root, "target"), "target: bridge needs exactly 2 sources");
    }
    if (strcmp(sc->target, "bridge") != 0 && sc->nsources != 1) {
        return fail(p, lx_yaml_get(root, "target"), "target: %s needs exactly 1 source", sc->target);
    }
    return 0;
}

/* start (required) and localisation (optional). */
static int parse_start(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "start");
    if (!n) {
        return fail(p, root, "start: missing ({position: [x, y], theta: radians})");
    }
    {
        static const char *const k[] = {"position", "theta", NULL};
        if (check_keys(p, n, "start", k) ||
            xy(p, n, "start", "position", true, &sc->start_x, &sc->start_y, NULL) ||
            num(p, n, "start", "theta", -7, 7, &sc->start_theta)) {
            return -1;
        }
    }
    if ((n = lx_yaml_get(root, "localisation"))) {
        static const char *const k[] = {"rate_hz",     "sigma_xy_m", "sigma_theta_rad",
                                        "drift_m",     "drift_tau_s", "jump_m",
                                        "jump_rate_hz", "jump_tau_s", NULL};
        if (check_keys(p, n, "localisation", k) ||
            num(p, n, "localisation", "rate_hz", 1, 1000, &sc->pose_rate_hz) ||
            num(p, n, "localisation", "sigma_xy_m", 0, 10, &sc->pose_sigma_xy_m) ||
            num(p, n, "localisation", "sigma_theta_rad", 0, 3, &sc->pose_sigma_theta_rad) ||
            num(p, n, "localisation", "drift_m", 0, 10, &sc->pose_drift_m) ||
            num(p, n, "localisation", "drift_tau_s", 0.1, 1000, &sc->pose_drift_tau_s) ||
            num(p, n, "localisation", "jump_m", 0, 10, &sc->pose_jump_m) ||
            num(p, n, "localisation", "jump_rate_hz", 0, 10, &sc->pose_jump_rate_hz) ||
            num(p, n, "localisation", "jump_tau_s", 0.1, 1000, &sc->pose_jump_tau_s)) {
            return -1;
        }
    }
    return 0;
}

/* motor (optional). */
static int parse_motor(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "motor");
    if (n) {
        static const char *const k[] = {"accel_m_s2", "timeout_ms", "v_max_m_s", "wheel_base_m",
                                        NULL};
        double to_ms = sc->motor.timeout_us / 1000.0;
        if (check_keys(p, n, "motor", k) ||
            num(p, n, "motor", "accel_m_s2", 0.01, 100, &sc->motor.accel_m_s2) ||
            num(p, n, "motor", "timeout_ms", 1, 100000, &to_ms) ||
            num(p, n, "motor", "v_max_m_s", 0.01, 10, &sc->motor.v_max_m_s) ||
            num(p, n, "motor", "wheel_base_m", 0.01, 10, &sc->motor.wheel_base_m)) {
            return -1;
        }
        sc->motor.timeout_us = (int64_t)llround(to_ms * 1000.0);
    }
    return 0;
}

/* stop (optional; a run must end), and the goal: the source's unless given. */
static int parse_stop(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "stop");
    if (n) {
        static const char *const k[] = {"radius_m", "max_distance_m", "max_time_s", "goal", NULL};
        if (check_keys(p, n, "stop", k) || num(p, n, "stop", "radius_m", 0, 1e4, &sc->stop_radius_m) ||
            num(p, n, "stop", "max_distance_m", 0, 1e6, &sc->stop_distance_m) ||
            num(p, n, "stop", "max_time_s", 0, 1e7, &sc->stop_time_s) ||
            xy(p, n, "stop", "goal", false, &sc->goal_x, &sc->goal_y, &sc->has_goal)) {
            return -1;
        }
        if (sc->stop_distance_m == 0.0 && sc->stop_time_s == 0.0) {
            return fail(p, n, "stop: max_distance_m and max_time_s are both off: a run that "
                              "never reaches the goal would never end");
        }
    }
    if (!sc->has_goal && sc->nsources == 1) {
        sc->goal_x = sc->src[0].x;
        sc->goal_y = sc->src[0].y;
    }
    return 0;
}

/* sim (optional). */
static int parse_sim(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    const lx_yaml_node_t *n = lx_yaml_get(root, "sim");
    if (n) {
        static const char *const k[] = {"physics_hz", "core_res_m", "clearance_m", NULL};
        if (check_keys(p, n, "sim", k) || num(p, n, "sim", "physics_hz", 10, 1000, &sc->physics_hz) ||
            num(p, n, "sim", "core_res_m", 0.02, 1, &sc->core_res_m) ||
            num(p, n, "sim", "clearance_m", 0, 5, &sc->clearance_m)) {
            return -1;
        }
    }
    return 0;
}

static int parse_root(pctx_t *p, const lx_yaml_node_t *root, hs_scenario_t *sc)
{
    static const char *const top[] = {"map", "seed", "model", "target", "strategy", "sources",
                                      "start", "localisation", "radio", "motor", "stop", "sim",
                                      "faults", "seek", NULL};
    if (check_keys(p, root, "scenario", top) != 0 || parse_map_path(p, root, sc) != 0 ||
        parse_seed(p, root, sc) != 0) {
        return -1;
    }
    if (str(p, root, "scenario", "model", sc->model, sizeof sc->model) ||
        str(p, root, "scenario", "target", sc->target, sizeof sc->target) ||
        str(p, root, "scenario", "strategy", sc->strategy, sizeof sc->strategy)) {
        return -1;
    }
    if (parse_seek(p, root, sc) != 0 || check_model_target(p, root, sc) != 0 ||
        parse_sources(p, root, sc) != 0 || parse_start(p, root, sc) != 0) {
        return -1;
    }
    const lx_yaml_node_t *n;
    if ((n = lx_yaml_get(root, "radio")) && parse_radio(p, n, &sc->radio, &sc->rx_heartbeat) != 0) {
        return -1;
    }
    if (parse_motor(p, root, sc) != 0 || parse_stop(p, root, sc) != 0 || parse_sim(p, root, sc) != 0) {
        return -1;
    }
    if ((n = lx_yaml_get(root, "faults")) && parse_faults(p, n, sc) != 0) {
        return -1;
    }
    char rerr[256];
    if (hs_radio_cfg_check(&sc->radio, rerr, sizeof rerr) != 0) {
        return fail(p, lx_yaml_get(root, "radio"), "%s", rerr);
    }
    return 0;
}

static int load(const char *path, hs_scenario_t *sc, char *err, size_t errlen)
{
    hs_scenario_defaults(sc);
    if (strlen(path) >= sizeof sc->path) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    snprintf(sc->path, sizeof sc->path, "%s", path);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    pctx_t p = {.file = path, .err = err, .errlen = errlen};
    lx_yaml_doc_t doc;
    lx_yaml_error_t ye;
    const lx_yaml_rc_t yrc = lx_yaml_load_file(f, &doc, &ye);
    int rc = -1;
    if (yrc == LX_YAML_NOMEM) {
        snprintf(err, errlen, "%s: out of memory", path);
    } else if (yrc == LX_YAML_TOO_BIG) {
        snprintf(err, errlen, "%s: more than %u YAML nodes or %u bytes", path, LX_YAML_MAX_NODES,
                 LX_YAML_MAX_BYTES);
    } else if (yrc != LX_YAML_OK) {
        snprintf(err, errlen, "%s:%lu: YAML syntax error: %s", path, ye.line,
                 ye.problem ? ye.problem : "unknown");
    } else if (!doc.root) {
        snprintf(err, errlen, "%s: empty file", path);
    } else {
        rc = parse_root(&p, doc.root, sc);
    }
    lx_yaml_free(&doc);
    fclose(f);
    return rc;
}

int hs_scenario_seek(hs_scenario_t *sc, const char *text, char *err, size_t errlen)
{
    char buf[sizeof sc->seek_cli + 16];
    const int n = snprintf(buf, sizeof buf, "seek: {%s}\n", text);
    if (n < 0 || (size_t)n >= sizeof buf || strlen(text) >= sizeof sc->seek_cli) {
        snprintf(err, errlen, "--seek: longer than %zu characters", sizeof sc->seek_cli - 1);
        return -1;
    }
    const char *colon = strchr(text, ':');
    while (colon && colon[1] == ' ') {
        colon = strchr(colon + 1, ':');
    }
    if (colon) { /* YAML would read "key:1" as one key: say what is wrong instead */
        snprintf(err, errlen, "--seek: a space after each colon ('KEY: VALUE'), got '%s'", text);
        lx_err_one_line(err);
        return -1;
    }
    pctx_t p = {.file = "--seek", .err = err, .errlen = errlen};
    lx_yaml_doc_t doc;
    lx_yaml_error_t ye;
    int rc = -1;
    if (lx_yaml_load_string((const uint8_t *)buf, (size_t)n, &doc, &ye) != LX_YAML_OK ||
        !doc.root || !lx_yaml_get(doc.root, "seek")) {
        snprintf(err, errlen, "--seek: expected KEY: VALUE[, KEY: VALUE...], got '%s'", text);
        lx_err_one_line(err);
    } else {
        rc = parse_seek(&p, doc.root, sc);
    }
    lx_yaml_free(&doc);
    if (rc == 0) {
        snprintf(sc->seek_cli, sizeof sc->seek_cli, "%s", text);
    }
    return rc;
}

int hs_scenario_load(const char *path, hs_scenario_t *sc, char *err, size_t errlen)
{
    const int rc = load(path, sc, err, errlen);
    if (rc != 0 && errlen > 0) {
        lx_err_one_line(err); /* the file name can hold line breaks (an unopenable path too) */
    }
    return rc;
}
