/* hs_sim.c - the simulator's run loop (see hs_sim.h). */
#include "hs_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hs_bridge.h"
#include "hs_fmt.h"
#include "hs_motor.h"
#include "hs_radio.h"
#include "hs_box2d.h"
#include "rfs_pdr.h"

/* Append v[0..n) to line at n, each as printf("%.*f", prec[i]) and followed by a tab,
 * through hs_fmt_fixed() (a run log's rows; its text is printf's). Returns the length. */
static size_t put_fields(char *line, size_t n, const double *v, const int *prec, int count)
{
    for (int i = 0; i < count; i++) {
        n += hs_fmt_fixed(line + n, v[i], prec[i]);
        line[n++] = '\t';
    }
    return n;
}

// --- the run loop -------------------------------------------------------------------------

static unsigned walls_cb(void *ctx, double x0, double y0, double x1, double y1)
{
    return hs_box2d_walls_crossed(ctx, x0, y0, x1, y1);
}

const char *hs_sim_kind_name(rfs_seek_kind_t k)
{
    switch (k) {
    case RFS_SEEK_INITIAL: return "initial";
    case RFS_SEEK_GREEDY: return "greedy";
    case RFS_SEEK_EPSILON: return "epsilon";
    default: return rfs_seek_kind_name(k); // baseline strategies (docs/STRATEGIES.md)
    }
}

const char *hs_sim_prev_name(rfs_drive_status_t s)
{
    switch (s) {
    case RFS_DRIVE_REACHED: return "reached";
    case RFS_DRIVE_TIMEOUT: return "timeout";
    case RFS_DRIVE_BLOCKED: return "blocked";
    case RFS_DRIVE_RUNNING: return "running";
    default: return "start";
    }
}

static double q16d(rfs_q16_t v)
{
    return v / 65536.0;
}

static rfs_q16_t dq16(double v)
{
    double s = v * 65536.0;
    return s >= 2147483647.0 ? INT32_MAX : (s <= -2147483648.0 ? INT32_MIN : (rfs_q16_t)lround(s));
}

/// Angle into (-pi, pi]; the inputs here are within a few turns of it.
static double wrap_pi(double a)
{
    while (a > M_PI) {
        a -= 2.0 * M_PI;
    }
    while (a <= -M_PI) {
        a += 2.0 * M_PI;
    }
    return a;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/// The path-loss model's estimate (docs/PATHLOSS.md, "Uncertainty"), when the controller's
/// model is "pathloss" and has one.
static bool pathloss_estimate(const hs_ctrl_t *ctrl, rfs_pathloss_est_t *est)
{
    if (ctrl->estimate) {
        return ctrl->estimate(ctrl->self, est);
    }
    const rfs_pathloss_t *pl = ctrl->pathloss ? ctrl->pathloss(ctrl->self) : NULL;
    return pl && rfs_pathloss_estimate(pl, est);
}

void hs_sim_log_estimate(FILE *f, const hs_ctrl_t *ctrl)
{
    rfs_pathloss_est_t est;
    if (pathloss_estimate(ctrl, &est)) {
        fprintf(f, "\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%.3f\n", q16d(est.sx), q16d(est.sy),
                q16d(est.n), q16d(est.w), q16d(est.p0), q16d(est.spread_m2));
    } else {
        fprintf(f, "\tnan\tnan\tnan\tnan\tnan\tnan\n");
    }
}

void hs_sim_result_estimate(hs_sim_result_t *r, const hs_ctrl_t *ctrl, double src_x,
                            double src_y)
{
    rfs_pathloss_est_t est;
    r->est_valid = pathloss_estimate(ctrl, &est);
    if (r->est_valid) {
        r->est_x = q16d(est.sx);
        r->est_y = q16d(est.sy);
        r->est_n = q16d(est.n);
        r->est_w_db = q16d(est.w);
        r->est_p0 = q16d(est.p0);
        r->est_area_m2 = q16d(est.spread_m2);
        r->est_error_m = hypot(r->est_x - src_x, r->est_y - src_y);
    } else {
        r->est_x = r->est_y = r->est_n = r->est_w_db = NAN;
        r->est_p0 = r->est_area_m2 = r->est_error_m = NAN;
    }
}

/// residual.tsv: every coarse candidate of the last fit with its residual
/// sqrt(2 x mean Huber loss) in dB (rfs_pathloss_residual_at()) and its cell's grid point
/// (the candidate itself unless snapped, docs/PATHLOSS.md "Fit"); header only without one.
static void write_residual(FILE *f, const hs_ctrl_t *ctrl)
{
    fprintf(f, "x_m\ty_m\tresidual_db\tcell_x_m\tcell_y_m\n");
    const rfs_pathloss_t *pl = ctrl->pathloss ? ctrl->pathloss(ctrl->self) : NULL;
    if (!pl) {
        return;
    }
    uint16_t ncx, ncy;
    rfs_pathloss_surface_size(pl, &ncx, &ncy);
    for (uint16_t cj = 0; cj < ncy; cj++) {
        for (uint16_t ci = 0; ci < ncx; ci++) {
            rfs_q16_t x, y, r;
            if (rfs_pathloss_residual_at(pl, ci, cj, &x, &y, &r)) {
                const rfs_pathloss_lat_t *l = &pl->lat;
                fprintf(f, "%.3f\t%.3f\t%.3f\t%.3f\t%.3f\n", q16d(x), q16d(y), q16d(r),
                        q16d(l->ox) + (l->c0i + ci * l->cs) * q16d(l->grid),
                        q16d(l->oy) + (l->c0j + cj * l->cs) * q16d(l->grid));
            }
        }
    }
}

/* The Box2D world (with the robot at its start pose when place_robot) and the radio model
 * over it, sharing the environment's wall-count caches. rs receives the radio's sources
 * (the run edits it when a fault moves a source). NULL with err set on failure. */
static hs_radio_t *world_radio_open(const hs_sim_env_t *e, uint64_t seed, bool place_robot,
                                    hs_radio_src_t rs[HS_SCN_MAX_SOURCES],
                                    hs_box2d_t **world_out, char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    char werr[256];
    // The walls are the map's: the first run builds the world, the next reset it.
    hs_box2d_t *world = *e->world;
    if (world == NULL) {
        world = hs_box2d_create_walls(&e->map, NULL, &e->walls, werr, sizeof werr);
        if (!world) {
            snprintf(err, errlen, "%s: %s", sc->path, werr);
            return NULL;
        }
        *e->world = world;
    } else {
        (void)hs_box2d_reset(world); // the default configuration: no wall pairs
    }
    if (place_robot) {
        hs_box2d_place_robot(world, sc->start_x, sc->start_y, sc->start_theta);
    }
    for (unsigned s = 0; s < sc->nsources; s++) {
        rs[s] = (hs_radio_src_t){sc->src[s].x, sc->src[s].y, sc->src[s].tx_dbm};
    }
    hs_radio_t *radio = hs_radio_create(&sc->radio, rs, sc->nsources, e->x0, e->y0, e->x1, e->y1,
                                        seed, walls_cb, world, werr, sizeof werr);
    if (!radio) {
        snprintf(err, errlen, "%s: %s", sc->path, werr);
        return NULL;
    }
    for (unsigned s = 0; s < sc->nsources; s++) {
        hs_radio_use_wall_cache(radio, s, e->wall_cache[s]);
    }
    *world_out = world;
    return radio;
}

/* One run of hs_sim_run: the world, its radio, the motor and the fault injection, the
 * event clocks, and where the robot is. */
typedef struct sim_run {
    const hs_sim_env_t *e;
    const hs_scenario_t *sc;
    uint64_t seed;
    hs_ctrl_t *ctrl;
    const hs_sim_io_t *io;
    hs_sim_result_t *res;
    hs_radio_src_t rs[HS_SCN_MAX_SOURCES]; /* the radio's sources (a fault may move one) */
    hs_box2d_t *world;
    hs_radio_t *radio;
    hs_motor_t motor;
    rfs_rng_t rng_pkt, rng_pose; /* independent streams: packets (loss and noise), localisation noise */
    hs_faults_run_t fr;
    hs_faults_msg_t fm[2];
    double goal_x, goal_y;       /* a moved source takes its goal along */
    rfs_pdr_t *pdr;              /* target "pdr": one counter per source, else NULL */
    int64_t dt_us;               /* physics tick */
    double dt_s;
    double pose_period_us;
    double pkt_period_us[HS_SCN_MAX_SOURCES];
    uint64_t pkt_k[HS_SCN_MAX_SOURCES];
    double pkt_off_us[HS_SCN_MAX_SOURCES];
    uint16_t seq[HS_SCN_MAX_SOURCES];
    uint64_t pose_k, ctrl_k;
    // Next event times, microseconds: k-th event of a stream at round(offset + k * period)
    // (no drift), recomputed only when the event is consumed.
    int64_t next_pkt[HS_SCN_MAX_SOURCES];
    int64_t next_pose, next_ctrl;
    int64_t stop_t_us;
    bool has_goal;
    double px, py, pth;          /* the robot at t: metres, radians */
    int64_t t;                   /* microseconds */
    double travelled;            /* metres */
    double belief_x, belief_y;   /* the model maximum of the last greedy decision, metres */
    bool belief_valid;
    double *trail;               /* the robot at every whole second of the run (x, y pairs) */
    size_t ntrail, trail_cap;    /* seconds recorded, room (0 after a failed allocation) */
    double drift_x, drift_y;     /* AMCL-like localisation error: bounded drift, metres */
    double jump_x, jump_y;       /* ... and the decaying rest of the last jump, metres */
    hs_bridge_track_t track;     /* target bridge: positions along the travel */
} sim_run_t;

/* The robot's motion over one physics tick (t, t1], interpolated for the events in it. */
typedef struct tick {
    int64_t t1;
    double nx, ny, nth; /* the pose at t1 */
    double seg;         /* distance travelled in the tick */
    double dth;         /* heading change, wrapped */
} tick_t;

/* An event at te, a fraction a into the tick: the robot's true position and distance. */
typedef struct event {
    int64_t te;
    double a;
    double ex, ey, etr;
} event_t;

enum { EV_PACKET = 0, EV_POSE = 1, EV_CTRL = 2 };

/* Free what run_open made (the radio: the latest, when a source moved). */
static void run_close(sim_run_t *r)
{
    free(r->trail);
    hs_bridge_track_free(&r->track);
    free(r->pdr);
    hs_radio_destroy(r->radio);
}

/* Set up a run: 0, or -1 with err set (nothing left open). */
static int run_open(sim_run_t *r, char *err, size_t errlen)
{
    const hs_scenario_t *sc = r->sc;
    r->radio = world_radio_open(r->e, r->seed, true, r->rs, &r->world, err, errlen);
    if (!r->radio) {
        return -1;
    }
    if (hs_motor_init(&r->motor, &sc->motor) != 0) {
        run_close(r);
        snprintf(err, errlen, "%s: motor: parameters must be positive", sc->path);
        return -1;
    }
    rfs_rng_seed(&r->rng_pkt, r->seed ^ 0x5A17C0FFEE000001ull);
    rfs_rng_seed(&r->rng_pose, r->seed ^ 0x5A17C0FFEE000002ull);
    // Fault injection (hs_faults.h): inputs, commands and world events pass its hooks.
    hs_faults_start(&r->fr, &sc->faults, r->seed, r->io ? r->io->faults : NULL);
    r->goal_x = sc->goal_x;
    r->goal_y = sc->goal_y;
    r->dt_us = (int64_t)llround(1e6 / sc->physics_hz);
    r->dt_s = r->dt_us * 1e-6;
    r->pose_period_us = 1e6 / sc->pose_rate_hz;
    // Target "pdr" (rfs_pdr.h): the receiver counts the sequence numbers that arrive and
    // hands the controller rfs_pdr_value() percentages instead of dBm.
    if (strcmp(sc->target, "pdr") == 0) {
        rfs_pdr_cfg_t pc = rfs_pdr_cfg_default();
        r->pdr = calloc(sc->nsources, sizeof *r->pdr); // NOLINT(clang-analyzer-optin.portability.UnixAPI): nsources >= 1 (hs_scenario_load)
        for (unsigned s = 0; r->pdr && s < sc->nsources; s++) {
            (void)rfs_pdr_init(&r->pdr[s], &pc); // the default window is valid
        }
        if (!r->pdr) {
            run_close(r);
            snprintf(err, errlen, "%s: out of memory", sc->path);
            return -1;
        }
    }
    for (unsigned s = 0; s < sc->nsources; s++) {
        r->pkt_period_us[s] = 1e6 / sc->src[s].rate_hz;
        r->pkt_off_us[s] = r->pkt_period_us[s] * (s + 0.5) / sc->nsources; // sources interleave
    }
    r->pose_k = 1;
    r->ctrl_k = 1;
    for (unsigned s = 0; s < sc->nsources; s++) {
        r->next_pkt[s] = (int64_t)llround(r->pkt_off_us[s]);
    }
    r->next_pose = (int64_t)llround(r->pose_period_us);
    r->next_ctrl = r->ctrl->period_us;
    r->stop_t_us = sc->stop_time_s > 0.0 ? (int64_t)llround(sc->stop_time_s * 1e6) : INT64_MAX;
    r->has_goal = sc->has_goal || sc->nsources == 1;
    return 0;
}

/* The header lines of the per-run tables that are written. */
static void write_headers(const hs_sim_io_t *io)
{
    if (io && io->log) {
        fprintf(io->log, "iteration\tt_s\tx_m\ty_m\ttheta_rad\test_x_m\test_y_m\tkind\treason\t"
                         "relearned\tprediction_db\tmean_db\tepsilon\tgoal_x_m\tgoal_y_m\t"
                         "max_x_m\tmax_y_m\tpath_m\tsamples\ttravelled_m\t"
                         HS_SIM_LOG_EST_COLUMNS "\n");
    }
    if (io && io->samples) {
        fprintf(io->samples, "t_s\tsrc\tx_m\ty_m\ttravelled_m\tdbm\n");
    }
    if (io && io->track) {
        fprintf(io->track, "t_s\tx_m\ty_m\ttheta_rad\test_x_m\test_y_m\test_theta_rad\ttouching\n");
    }
}

/* Turning on the spot, for turn_time_s: forward speed below 2 cm/s while turning faster
 * than 0.05 rad/s (3 degrees per second). */
#define TURN_V_M_S 0.02
#define TURN_W_RAD_S 0.05

/* The motor and the world advanced by one tick from r->t. */
static void tick_motion(sim_run_t *r, tick_t *k)
{
    double v, w;
    hs_motor_update(&r->motor, r->t + r->dt_us, r->dt_s, &v, &w);
    hs_faults_motor(&r->fr, r->t, r->motor.timed_out); // the target this tick, [t, t + dt]
    hs_box2d_step(r->world, v, w, r->dt_s);
    if (fabs(v) < TURN_V_M_S && fabs(w) > TURN_W_RAD_S) {
        r->res->turn_time_s += r->dt_s;
    }
    hs_box2d_robot_pose(r->world, &k->nx, &k->ny, &k->nth);
    k->seg = sqrt((k->nx - r->px) * (k->nx - r->px) + (k->ny - r->py) * (k->ny - r->py));
    k->t1 = r->t + r->dt_us;
    k->dth = wrap_pi(k->nth - r->pth);
}

/* The next event: its kind (EV_*) and time in *te, the source of a packet in *which. */
static int next_event(const sim_run_t *r, int64_t *te, unsigned *which)
{
    // Packets, then poses, then control at equal times.
    int kind = -1;
    *te = INT64_MAX;
    *which = 0;
    for (unsigned s = 0; s < r->sc->nsources; s++) {
        if (r->next_pkt[s] < *te) { // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult): set for s < nsources in run_open
            *te = r->next_pkt[s];
            kind = EV_PACKET;
            *which = s;
        }
    }
    if (r->next_pose < *te) {
        *te = r->next_pose;
        kind = EV_POSE;
    }
    if (r->next_ctrl < *te) {
        *te = r->next_ctrl;
        kind = EV_CTRL;
    }
    return kind;
}

/* A packet of source s: received or lost, through the faults to the controller. */
static void packet_event(sim_run_t *r, const event_t *ev, unsigned s)
{
    const hs_sim_io_t *io = r->io;
    r->pkt_k[s]++;
    r->next_pkt[s] = (int64_t)llround(r->pkt_off_us[s] + r->pkt_k[s] * r->pkt_period_us[s]);
    int dbm = 0;
    bool got = hs_radio_packet(r->radio, s, ev->ex, ev->ey, &r->rng_pkt, &dbm);
    r->res->packets_sent++;
    if (io && io->on_packet) {
        io->on_packet(io->packet_ctx, s, ev->te, r->seq[s], got, dbm);
    }
    r->seq[s] = (uint16_t)((r->seq[s] + 1u) & 0x0FFFu); // 802.11 sequence numbers: 12 bits
    int8_t meas = (int8_t)dbm;
    if (got && r->pdr) {
        // The packet's own number: seq[] already points at the next one.
        (void)rfs_pdr_push(&r->pdr[s], ev->te, (uint16_t)((r->seq[s] - 1u) & 0x0FFFu));
        got = rfs_pdr_value(&r->pdr[s], ev->te, &meas); // always true after a push
    }
    if (got) {
        r->res->packets_received++;
        unsigned nm = hs_faults_rssi(&r->fr, ev->te, (uint8_t)s, meas, r->fm);
        for (unsigned k = 0; k < nm; k++) {
            r->ctrl->on_rssi(r->ctrl->self, r->fm[k].src, r->fm[k].t_us, r->fm[k].dbm);
        }
        if (io && io->samples) {
            char line[6 * HS_FMT_MAX];
            size_t n = hs_fmt_fixed(line, ev->te * 1e-6, 6);
            n += (size_t)snprintf(line + n, sizeof line - n, "\t%u\t", s);
            n = put_fields(line, n, (const double[]){ev->ex, ev->ey, ev->etr}, (const int[]){3, 3, 3}, 3);
            n += (size_t)snprintf(line + n, sizeof line - n, "%d\n", dbm);
            fwrite(line, 1, n, io->samples);
        }
    }
}

/* The AMCL-like part of the localisation error, advanced by one pose period
 * (docs/SIMULATOR.md, "Localisation"): a drift per axis (Ornstein-Uhlenbeck, standard
 * deviation drift_m / 2, correlation time drift_tau_s) held within drift_m of the truth,
 * plus jumps of jump_m in a random direction (Poisson, jump_rate_hz) that decay back with
 * jump_tau_s, as a particle filter's estimate snaps to a wrong hypothesis and recovers. */
static void pose_drift(sim_run_t *r)
{
    const hs_scenario_t *sc = r->sc;
    double dt = 1.0 / sc->pose_rate_hz;
    double a = exp(-dt / sc->pose_drift_tau_s);
    double sd = 0.5 * sc->pose_drift_m * sqrt(1.0 - a * a);
    r->drift_x = a * r->drift_x + sd * hs_radio_gauss(&r->rng_pose);
    r->drift_y = a * r->drift_y + sd * hs_radio_gauss(&r->rng_pose);
    double m = hypot(r->drift_x, r->drift_y);
    if (m > sc->pose_drift_m) {
        r->drift_x *= sc->pose_drift_m / m;
        r->drift_y *= sc->pose_drift_m / m;
    }
    double aj = exp(-dt / sc->pose_jump_tau_s);
    r->jump_x *= aj;
    r->jump_y *= aj;
    if (hs_radio_uniform(&r->rng_pose) < 1.0 - exp(-dt * sc->pose_jump_rate_hz)) {
        double phi = 2.0 * M_PI * hs_radio_uniform(&r->rng_pose);
        r->jump_x += sc->pose_jump_m * cos(phi);
        r->jump_y += sc->pose_jump_m * sin(phi);
    }
}

/* A localisation pose: the true pose plus noise, through the faults to the controller. */
static void pose_event(sim_run_t *r, const event_t *ev, const tick_t *k)
{
    const hs_scenario_t *sc = r->sc;
    r->pose_k++;
    r->next_pose = (int64_t)llround(r->pose_k * r->pose_period_us);
    double eth = wrap_pi(r->pth + ev->a * k->dth);
    double mx = ev->ex + sc->pose_sigma_xy_m * hs_radio_gauss(&r->rng_pose);
    double my = ev->ey + sc->pose_sigma_xy_m * hs_radio_gauss(&r->rng_pose);
    if (sc->pose_drift_m > 0.0) {
        pose_drift(r);
        mx += r->drift_x + r->jump_x;
        my += r->drift_y + r->jump_y;
    }
    double mth = wrap_pi(eth + sc->pose_sigma_theta_rad * hs_radio_gauss(&r->rng_pose));
    rfs_pose_t pose = {ev->te, dq16(mx), dq16(my), dq16(mth)};
    unsigned nm = hs_faults_pose(&r->fr, &pose, r->fm);
    for (unsigned i = 0; i < nm; i++) {
        r->ctrl->on_pose(r->ctrl->self, &r->fm[i].pose);
    }
    if (r->io && r->io->track) {
        char line[8 * HS_FMT_MAX];
        size_t n = put_fields(line, 0, (const double[]){ev->te * 1e-6, ev->ex, ev->ey, eth, mx, my, mth},
                              (const int[]){3, 3, 3, 4, 3, 3, 4}, 7);
        line[n++] = hs_box2d_robot_touching(r->world) ? '1' : '0';
        line[n++] = '\n';
        fwrite(line, 1, n, r->io->track);
    }
}

void hs_sim_log_decision(FILE *f, const hs_ctrl_t *ctrl, const rfs_seek_decision_t *d, double t_s,
                         double x_m, double y_m, double theta, double travelled_m)
{
    char reason[96];
    snprintf(reason, sizeof reason, "prev=%s%s%s%s%s%s%s", hs_sim_prev_name(d->prev),
             d->line_search ? ",line_search" : "",
             d->sampled ? ",sampled" : d->near ? ",near" : d->hedged ? ",hedged" : "",
             d->refuted ? ",refuted" : "",
             d->pinned ? ",pinned" : "", d->model_valid ? "" : ",no_model",
             d->mean_valid ? "" : ",no_mean");
    double pred = d->model_valid ? q16d(d->prediction) : NAN;
    double mean = d->mean_valid ? q16d(d->mean) : NAN;
    fprintf(f,
            "%u\t%.3f\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%s\t%s\t%d\t%.3f\t%.3f\t"
            "%.4f\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%u\t%.3f",
            d->iteration, t_s, x_m, y_m, theta,
            q16d(d->x), q16d(d->y), hs_sim_kind_name(d->kind), reason,
            d->relearned ? 1 : 0, pred, mean, q16d(d->epsilon),
            q16d(d->goal_x), q16d(d->goal_y), q16d(d->max_x), q16d(d->max_y),
            q16d(d->path_len), d->samples, travelled_m);
    hs_sim_log_estimate(f, ctrl);
}

void hs_sim_count_decision(hs_sim_result_t *res, const rfs_seek_decision_t *d, int64_t now_us,
                           int64_t period_us)
{
    res->iterations++;
    res->model_updates += d->relearned ? 1u : 0u;
    res->greedy += d->kind == RFS_SEEK_GREEDY ? 1u : 0u;
    res->epsilon += d->kind == RFS_SEEK_EPSILON ? 1u : 0u;
    res->goal_timeouts += d->prev == RFS_DRIVE_TIMEOUT ? 1u : 0u;
    res->goal_blocked += d->prev == RFS_DRIVE_BLOCKED ? 1u : 0u;
    res->slow_decisions += d->plan_wait >= 2u ? 1u : 0u;
    res->plan_wait_max = d->plan_wait > res->plan_wait_max ? d->plan_wait : res->plan_wait_max;
    const int64_t wait_us = now_us - d->t_us + period_us; /* the deciding period too */
    res->decisions_over_100ms += wait_us > 100000 ? 1u : 0u;
    res->decision_wait_max_s = fmax(res->decision_wait_max_s, (double)wait_us * 1e-6);
    res->decision_wait_sum_s += (double)wait_us * 1e-6;
}

/* A control period: the receiver heartbeat, the controller's step, its command through
 * the faults to the motor, and its decision counted and logged. */
static void ctrl_event(sim_run_t *r, const event_t *ev, const tick_t *k)
{
    hs_ctrl_t *ctrl = r->ctrl;
    r->ctrl_k++;
    r->next_ctrl = (int64_t)r->ctrl_k * ctrl->period_us;
    // The receiver is up unless a fault silenced it (docs/FAULTS.md, "The receiver
    // heartbeat"): in a dead zone the controller hears "listening, nothing heard", not a
    // failed sensor.
    int64_t rx_us;
    if (r->sc->rx_heartbeat && ctrl->on_receiver && hs_faults_receiver(&r->fr, ev->te, &rx_us)) {
        ctrl->on_receiver(ctrl->self, rx_us);
    }
    hs_ctrl_out_t out;
    memset(&out, 0, sizeof out);
    ctrl->step(ctrl->self, ev->te, &out);
    if (hs_faults_cmd(&r->fr, ev->te, &out)) {
        hs_motor_command(&r->motor, ev->te, out.left_mm_s, out.right_mm_s);
    }
    if (out.decided) {
        const rfs_seek_decision_t *d = &out.decision;
        hs_sim_count_decision(r->res, d, ev->te, ctrl->period_us);
        if (d->kind == RFS_SEEK_GREEDY && d->model_valid) {
            r->belief_x = q16d(d->max_x);
            r->belief_y = q16d(d->max_y);
            r->belief_valid = true;
        }
        if (r->io && r->io->log) {
            hs_sim_log_decision(r->io->log, ctrl, d, ev->te * 1e-6, ev->ex, ev->ey,
                                wrap_pi(r->pth + ev->a * k->dth), ev->etr);
        }
    }
}

/* Every event in (t, t1], in time order. */
static void tick_events(sim_run_t *r, const tick_t *k)
{
    for (;;) {
        event_t ev;
        unsigned which;
        const int kind = next_event(r, &ev.te, &which);
        if (ev.te > k->t1) {
            break;
        }
        ev.a = (double)(ev.te - r->t) / (double)r->dt_us;
        ev.ex = r->px + ev.a * (k->nx - r->px);
        ev.ey = r->py + ev.a * (k->ny - r->py);
        ev.etr = r->travelled + ev.a * k->seg;
        if (kind == EV_PACKET) {
            packet_event(r, &ev, which);
        } else if (kind == EV_POSE) {
            pose_event(r, &ev, k);
        } else {
            ctrl_event(r, &ev, k);
        }
    }
}

/* The fault schedule's world events due at r->t: a kidnap or a moved source. 0, or -1
 * with err set (the moved radio could not be made). */
static int world_events(sim_run_t *r, char *err, size_t errlen)
{
    const hs_scenario_t *sc = r->sc;
    const hs_sim_env_t *e = r->e;
    char werr[256];
    hs_faults_event_t fev;
    while (hs_faults_next_event(&r->fr, r->t, &fev)) {
        if (fev.kind == HS_FAULT_KIDNAP) {
            // Carried away between two ticks: no travel, the wheels keep their command.
            hs_box2d_place_robot(r->world, fev.x, fev.y, fev.theta);
            hs_box2d_robot_pose(r->world, &r->px, &r->py, &r->pth);
            continue;
        }
        r->rs[fev.source].x = fev.x;
        r->rs[fev.source].y = fev.y;
        hs_radio_t *moved = hs_radio_create(&sc->radio, r->rs, sc->nsources, e->x0, e->y0,
                                            e->x1, e->y1, r->seed, walls_cb, r->world, werr,
                                            sizeof werr);
        if (!moved) {
            snprintf(err, errlen, "%s: %s", sc->path, werr);
            return -1;
        }
        // Same seed, same fields; the shared wall caches hold only unmoved sources.
        for (unsigned k = 0; k < sc->nsources; k++) {
            if (sc->src[k].x == r->rs[k].x && sc->src[k].y == r->rs[k].y) {
                hs_radio_use_wall_cache(moved, k, e->wall_cache[k]);
            }
        }
        hs_radio_destroy(r->radio);
        r->radio = moved;
        if (fev.source == 0 && !sc->has_goal) {
            r->goal_x = fev.x;
            r->goal_y = fev.y;
        }
    }
    return 0;
}

/* Why the run ends after this tick ("reached", "distance", "time"), or NULL. */
static const char *run_end(sim_run_t *r)
{
    const hs_scenario_t *sc = r->sc;
    if (r->has_goal && sc->stop_radius_m > 0.0 &&
        hypot(r->px - r->goal_x, r->py - r->goal_y) <= sc->stop_radius_m) {
        r->res->reached = true;
        return "reached";
    }
    if (sc->stop_distance_m > 0.0 && r->travelled >= sc->stop_distance_m) {
        return "distance";
    }
    if (r->t >= r->stop_t_us) {
        return "time";
    }
    return NULL;
}

/* The robot's position recorded at the first tick of every whole second (entry k: second
 * k), for still_s. Without memory the record stops and still_s counts from its end. */
static void trail_add(sim_run_t *r)
{
    if (r->ntrail == r->trail_cap) {
        size_t cap = r->trail_cap ? 2 * r->trail_cap : 1024;
        double *t = realloc(r->trail, cap * 2 * sizeof *t);
        if (!t) {
            return;
        }
        r->trail = t;
        r->trail_cap = cap;
    }
    r->trail[2 * r->ntrail] = r->px;
    r->trail[2 * r->ntrail + 1] = r->py;
    r->ntrail++;
}

/* Seconds the robot has stayed within HS_SIM_STILL_RADIUS_M of where it is now: from the
 * whole second after the last recorded position outside that circle (none: the run). */
static double still_s(const sim_run_t *r)
{
    double end_s = r->t * 1e-6;
    for (size_t k = r->ntrail; k-- > 0;) {
        if (hypot(r->trail[2 * k] - r->px, r->trail[2 * k + 1] - r->py) > HS_SIM_STILL_RADIUS_M) {
            return fmax(0.0, end_s - (double)(k + 1));
        }
    }
    return end_s;
}

/* The bridging figures (hs_bridge.h) and the model's predicted best point. */
static void bridge_result(sim_run_t *r)
{
    hs_sim_result_t *res = r->res;
    const hs_sim_env_t *e = r->e;
    if (!hs_bridge_best(r->radio, &e->core.map, r->sc->start_x, r->sc->start_y, e->x0, e->y0,
                        e->x1, e->y1, &res->best_x, &res->best_y, &res->best_f_db,
                        &res->far_f_db)) {
        res->best_x = res->best_y = res->best_f_db = res->far_f_db = NAN;
    }
    res->settle_f_db = hs_bridge_f(r->radio, r->px, r->py);
    res->settle_error_m = hypot(r->px - res->best_x, r->py - res->best_y);
    res->settle_travel_m = hs_bridge_settle_travel(&r->track, r->px, r->py);
    const rfs_fields_t *fl = r->ctrl->fields ? r->ctrl->fields(r->ctrl->self) : NULL;
    rfs_fields_est_t est;
    res->pred_valid = fl && rfs_fields_estimate(fl, &est);
    if (res->pred_valid) {
        res->pred_x = q16d(est.x);
        res->pred_y = q16d(est.y);
        res->pred_f_db = q16d(est.value);
        res->pred_sigma_db = q16d(est.sigma);
        res->pred_area_m2 = q16d(est.area_m2);
        for (unsigned k = 0; k < 2; k++) {
            const rfs_pathloss_est_t *p = &est.src[k];
            bool ok = k < est.nsources;
            double v[6] = {q16d(p->sx), q16d(p->sy), q16d(p->p0), q16d(p->n), q16d(p->w),
                           q16d(p->rms)};
            for (unsigned i = 0; i < 6; i++) {
                res->pred_src[k][i] = ok ? v[i] : NAN;
            }
        }
    } else {
        res->pred_x = res->pred_y = res->pred_f_db = res->pred_sigma_db = NAN;
        res->pred_area_m2 = NAN;
    }
}

/* The result of a run that ended for reason end. */
static void run_result(sim_run_t *r, const char *end)
{
    hs_sim_result_t *res = r->res;
    res->end = end;
    res->sim_time_s = r->t * 1e-6;
    res->distance_travelled_m = r->travelled;
    res->shortest_path_m = r->e->shortest_path_m;
    res->shortest_to_stop_m = r->e->shortest_to_stop_m;
    res->final_x = r->px;
    res->final_y = r->py;
    res->final_distance_m = r->has_goal ? hypot(r->px - r->goal_x, r->py - r->goal_y) : NAN;
    res->motor_timeouts = r->motor.timeouts;
    res->wall_contacts = hs_box2d_wall_contacts(r->world);
    // Against source 0 where it is now (a moved source takes its error along).
    hs_sim_result_estimate(res, r->ctrl, r->rs[0].x, r->rs[0].y);
    res->belief_x = res->est_valid ? res->est_x : (r->belief_valid ? r->belief_x : NAN);
    res->belief_y = res->est_valid ? res->est_y : (r->belief_valid ? r->belief_y : NAN);
    res->belief_error_m = hypot(res->belief_x - r->rs[0].x, res->belief_y - r->rs[0].y);
    res->still_s = still_s(r);
    res->placement = r->e->placement;
    res->start_x = r->sc->start_x;
    res->start_y = r->sc->start_y;
    res->start_theta = r->sc->start_theta;
    res->source_x = r->sc->src[0].x;
    res->source_y = r->sc->src[0].y;
    if (res->bridge) {
        bridge_result(r);
    }
    if (r->io && r->io->residual) {
        write_residual(r->io->residual, r->ctrl);
    }
}

int hs_sim_run(const hs_sim_env_t *e, uint64_t seed, hs_ctrl_t *ctrl, const hs_sim_io_t *io,
               hs_sim_result_t *res, char *err, size_t errlen)
{
    double t_wall0 = now_s(), t_cpu0 = cpu_s();
    memset(res, 0, sizeof *res);
    res->seed = seed;
    res->bridge = strcmp(e->sc.target, "bridge") == 0;
    sim_run_t r;
    memset(&r, 0, sizeof r);
    r.e = e;
    r.sc = &e->sc;
    r.seed = seed;
    r.ctrl = ctrl;
    r.io = io;
    r.res = res;
    if (run_open(&r, err, errlen) != 0) {
        return -1;
    }
    write_headers(io);
    hs_box2d_robot_pose(r.world, &r.px, &r.py, &r.pth);
    trail_add(&r);
    const char *end;
    do {
        tick_t k;
        tick_motion(&r, &k);
        tick_events(&r, &k);
        r.travelled += k.seg;
        r.px = k.nx;
        r.py = k.ny;
        if (res->bridge && !hs_bridge_track_add(&r.track, r.px, r.py, r.travelled)) {
            run_close(&r);
            snprintf(err, errlen, "%s: out of memory", e->sc.path);
            return -1;
        }
        r.pth = k.nth;
        r.t = k.t1;
        if (r.t >= (int64_t)r.ntrail * 1000000) {
            trail_add(&r);
        }
        if (world_events(&r, err, errlen) != 0) {
            run_close(&r);
            return -1;
        }
        end = run_end(&r);
    } while (end == NULL);
    run_result(&r, end);
    run_close(&r);
    res->wall_time_s = now_s() - t_wall0;
    res->cpu_time_s = cpu_s() - t_cpu0;
    return 0;
}

int hs_sim_run_inproc(const hs_sim_env_t *e, uint64_t seed, const hs_sim_io_t *io,
                      hs_sim_result_t *res, char *err, size_t errlen)
{
    hs_ctrl_inproc_cfg_t cc = hs_ctrl_inproc_cfg_default();
    cc.model = e->sc.model;
    cc.target = e->sc.target;
    if (strcmp(e->sc.target, "bridge") == 0) {
        cc.seek.error_threshold = RFS_Q16_INT(7); // paper section 6: 7 for the noisier target
    }
    rfs_seek_strategy_t st;
    if (!rfs_seek_strategy_parse(e->sc.strategy, &st)) {
        snprintf(err, errlen, "%s: strategy: unknown '%s' (meta, meta-global, fd-gradient, "
                 "plane-gradient, chemotaxis, meta-path)", e->sc.path, e->sc.strategy);
        return -1;
    }
    rfs_seek_cfg_use_strategy(&cc.seek, st);
    if (e->sc.seek_recheck_m >= 0.0) {
        cc.seek.recheck_dist = (rfs_q16_t)lround(e->sc.seek_recheck_m * 65536.0);
    }
    if (e->sc.seek_refute_m >= 0.0) {
        cc.seek.refute_r = (rfs_q16_t)lround(e->sc.seek_refute_m * 65536.0);
    }
    if (e->sc.seek_local_m >= 0.0) {
        cc.seek.local_r = (rfs_q16_t)lround(e->sc.seek_local_m * 65536.0);
    }
    if (e->sc.seek_local_gap_m >= 0.0) {
        cc.seek.local_gap = (rfs_q16_t)lround(e->sc.seek_local_gap_m * 65536.0);
    }
    if (e->sc.seek_at_tol_m >= 0.0) {
        cc.seek.at_tol = (rfs_q16_t)lround(e->sc.seek_at_tol_m * 65536.0);
    }
    if (e->sc.seek_leg_m >= 0.0) {
        cc.seek.leg_max = (rfs_q16_t)lround(e->sc.seek_leg_m * 65536.0);
    }
    if (e->sc.seek_mean_t >= 0.0) {
        cc.seek.mean_t = (rfs_q16_t)lround(e->sc.seek_mean_t * 65536.0);
    }
    if (e->sc.seek_floor_db >= 0.0) {
        cc.seek.floor_gap = (rfs_q16_t)lround(e->sc.seek_floor_db * 65536.0);
    }
    if (e->sc.seek_silence_floor >= 0) {
        cc.seek.silence_floor = e->sc.seek_silence_floor != 0 ? RFS_Q16_INT(-100) : INT32_MIN;
    }
    if (e->sc.seek_eps_rate >= 0.0) {
        cc.seek.eps_rate = (rfs_q16_t)lround(e->sc.seek_eps_rate * 65536.0);
    }
    if (e->sc.seek_eps_by_travel >= 0) {
        cc.seek.eps_by_travel = e->sc.seek_eps_by_travel != 0;
    }
    if (e->sc.seek_eps_geodesic >= 0) {
        cc.seek.eps_geodesic = e->sc.seek_eps_geodesic != 0;
    }
    if (e->sc.seek_recheck_adapt >= 0) {
        cc.seek.recheck_adapt = e->sc.seek_recheck_adapt != 0;
    }
    if (e->sc.seek_eps_sample >= 0) {
        cc.seek.eps_sample = e->sc.seek_eps_sample != 0;
    }
    cc.p0_min_dbm = e->sc.seek_p0_min_dbm;
    cc.coarse_footprint_m = e->sc.seek_coarse_footprint_m;
    cc.p0_max_wall_db = e->sc.seek_p0_max_wall_db;
    cc.coarse_snap = e->sc.seek_coarse_snap;
    cc.pathloss_log2 = e->pathloss_log2;
    cc.pathloss_builtin_cache = e->sc.fit_mcu;
    if (e->sc.seek_local_refute >= 0) {
        cc.seek.local_refute = e->sc.seek_local_refute != 0;
    }
    if (e->sc.seek_refute_reached >= 0) {
        cc.seek.refute_reached = e->sc.seek_refute_reached != 0;
    }
    if (e->sc.seek_recheck_silent >= 0) {
        cc.seek.recheck_silent = e->sc.seek_recheck_silent != 0;
    }
    if (e->sc.seek_near_t >= 0.0) {
        cc.seek.near_t = (rfs_q16_t)lround(e->sc.seek_near_t * 65536.0);
    }
    if (e->sc.seek_near_m >= 0.0) {
        cc.seek.near_min = (rfs_q16_t)lround(e->sc.seek_near_m * 65536.0);
    }
    if (e->sc.seek_floor_max >= 0.0) {
        cc.seek.floor_max = (uint8_t)e->sc.seek_floor_max;
    }
    if (e->sc.seek_fit_early >= 0) {
        cc.seek.fit_early = e->sc.seek_fit_early != 0;
    }
    if (e->sc.seek_fit_slices >= 0.0) {
        cc.fit_slices = (uint32_t)e->sc.seek_fit_slices;
    }
    if (e->sc.seek_reach_min >= 0.0) {
        cc.seek.reach_min = (uint32_t)e->sc.seek_reach_min;
    }
    if (e->sc.seek_fit_budget >= 0.0) {
        cc.seek.fit_budget = (uint32_t)e->sc.seek_fit_budget;
    }
    cc.seed = seed ^ 0x5A17C0FFEE000003ull;
    hs_ctrl_t ctrl;
    char cerr[256];
    if (hs_ctrl_inproc_open(&ctrl, &cc, &e->core.map, cerr, sizeof cerr) != 0) {
        snprintf(err, errlen, "%s: %s", e->sc.path, cerr);
        return -1;
    }
    int rc = hs_sim_run(e, seed, &ctrl, io, res, err, errlen);
    hs_ctrl_close(&ctrl);
    return rc;
}

int hs_sim_field(const hs_sim_env_t *e, uint64_t seed, unsigned src, double step_m, FILE *f,
                 char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    if (src >= sc->nsources || !(step_m > 0.0)) {
        snprintf(err, errlen, "field: bad source or step");
        return -1;
    }
    hs_radio_src_t rs[HS_SCN_MAX_SOURCES];
    hs_box2d_t *world;
    hs_radio_t *radio = world_radio_open(e, seed, false, rs, &world, err, errlen);
    if (!radio) {
        return -1;
    }
    rfs_rng_t rng;
    rfs_rng_seed(&rng, seed ^ 0x5A17C0FFEE000004ull);
    fprintf(f, "x_m\ty_m\twalls\tmean_dbm\tsignal_dbm\tdbm\n");
    // NOLINTBEGIN(cert-flp30-c,clang-analyzer-security.FloatLoopCounter): a field dump; ulp drift is harmless
    for (double y = e->y0 + 0.5 * step_m; y < e->y1; y += step_m) {
        for (double x = e->x0 + 0.5 * step_m; x < e->x1; x += step_m) {
            // NOLINTEND(cert-flp30-c,clang-analyzer-security.FloatLoopCounter)
            uint32_t cx, cy;
            if (!lx_map_cell_at(&e->map, x, y, &cx, &cy) ||
                e->map.cell[(size_t)cy * e->map.w + cx] != LX_CELL_FREE) {
                continue;
            }
            int dbm;
            bool got = hs_radio_packet(radio, src, x, y, &rng, &dbm);
            fprintf(f, "%.3f\t%.3f\t%u\t%.2f\t%.2f\t", x, y, hs_radio_walls(radio, src, x, y),
                    hs_radio_mean_dbm(radio, src, x, y), hs_radio_signal_dbm(radio, src, x, y));
            if (got) {
                fprintf(f, "%d\n", dbm);
            } else {
                fprintf(f, "\n");
            }
        }
    }
    hs_radio_destroy(radio);
    return 0;
}

