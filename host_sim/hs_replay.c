/* hs_replay.c - an experiment replayed through the controller (hs_replay.h; rfseek-feed
 * --pose, docs/FEEDER.md).
 */
#include "hs_replay.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hs_ctrl.h"
#include "hs_poses.h"
#include "hs_scenario.h"
#include "hs_sim.h"
#include "lx_feed.h"
#include "rfs_pdr.h"

/* The frames of the scenario's sources, in capture order. */
typedef struct rp_vec {
    hs_replay_frame_t *v;
    size_t n, cap;
} rp_vec_t;

/* Receiver heartbeat times (docs/FAULTS.md, "The receiver heartbeat"): every record the
 * capture loop reads proves it alive at that record's time, whoever sent it; heartbeats
 * spaced as the live feed spaces them (lx_feed_hb_due). */
typedef struct rp_times {
    int64_t *v;
    size_t n, cap;
    lx_feed_hb_t rule;
} rp_times_t;

static rfs_q16_t rp_q16(double v) { return (rfs_q16_t)llround(v * 65536.0); }

static FILE *rp_open(const char *dir, const char *name)
{
    char p[4096];
    if (snprintf(p, sizeof(p), "%s/%s", dir, name) >= (int)sizeof(p)) { return NULL; }
    return fopen(p, "w");
}

/* Every file a replay writes into its output directory. */
static const char *const k_rp_files[] = {"log.tsv", "samples.tsv", "track.tsv", "summary.json"};

static void rp_rmdir(const char *dir)
{
    const char *const *names = k_rp_files;
    char p[4096];
    for (size_t i = 0; i < sizeof(k_rp_files) / sizeof(k_rp_files[0]); i++) {
        if (snprintf(p, sizeof(p), "%s/%s", dir, names[i]) < (int)sizeof(p)) { (void)remove(p); }
    }
    (void)rmdir(dir);
}

/* One replay: the scenario, the recorded inputs, the controller and the outputs. */
struct hs_replay {
    hs_replay_opts_t o_copy;
    const hs_replay_opts_t *o;      /* &o_copy */
    hs_scenario_t sc;
    hs_sim_env_t env;
    bool env_open;
    hs_ctrl_t ctrl;
    bool ctrl_open;
    bool pdr_target;
    int n_macs;
    hs_pose_rec_t *poses;
    size_t n_poses;
    rp_vec_t pk;                    /* the matching frames */
    rp_times_t hb;                  /* the receiver heartbeats */
    char tmp[4096];                 /* the output directory until renamed */
    FILE *flog, *fsam, *ftrk;
    hs_sim_result_t res;
    uint64_t before, after;         /* frames not fed: before the first pose, after the end */
    /* Per-source sequence tracking: frames lost = gaps in the 12-bit numbers. */
    bool seen[HS_SCN_MAX_SOURCES];
    uint16_t last_seq[HS_SCN_MAX_SOURCES];
    uint64_t lost;
    /* Target "pdr": one delivery window (1 s) per source, fed from Sequence Control. */
    rfs_pdr_t pdr[HS_SCN_MAX_SOURCES];
};

/* The robot at an event: its recorded pose interpolated, and the distance travelled. */
typedef struct rp_at {
    int64_t te;            /* microseconds from the first pose */
    double ex, ey, eth;    /* metres, radians */
    double etr;            /* metres */
} rp_at_t;

/* The scenario with the options' overrides, and the MACs of its sources (unless given):
 * 0, or the exit status after a message. */
static int rp_scenario(hs_replay_t *rp, uint8_t (*macs)[6], int n_macs)
{
    const hs_replay_opts_t *o = rp->o;
    hs_scenario_t *sc = &rp->sc;
    char err[1200];
    if (hs_scenario_load(o->scenario, sc, err, sizeof(err)) != 0) {
        fprintf(stderr, "%s: %s\n", rp->o->prog, err);
        return 1;
    }
    if (o->model != NULL) { snprintf(sc->model, sizeof(sc->model), "%s", o->model); }
    if (o->target != NULL) {
        if (sc->nsources != 1) {
            fprintf(stderr, "%s: --target: %s needs exactly 1 source, scenario %s has %u\n", rp->o->prog,
                    o->target, o->scenario, sc->nsources);
            return 2;
        }
        snprintf(sc->target, sizeof(sc->target), "%s", o->target);
    }
    rp->pdr_target = strcmp(sc->target, "pdr") == 0;
    if (n_macs == 0) {
        for (unsigned i = 0; i < sc->nsources; i++) { memcpy(macs[i], sc->src[i].mac, 6); }
        n_macs = (int)sc->nsources;
    } else if ((unsigned)n_macs != sc->nsources) {
        fprintf(stderr, "%s: --mac: %d addresses given, scenario %s has %u sources\n", rp->o->prog, n_macs,
                o->scenario, sc->nsources);
        return 2;
    }
    rp->n_macs = n_macs;
    return 0;
}

int hs_replay_open(const hs_replay_opts_t *o, uint8_t (*macs)[6], int n_macs, hs_replay_t **out)
{
    *out = NULL;
    hs_replay_t *rp = calloc(1, sizeof(*rp));
    if (rp == NULL) {
        fprintf(stderr, "%s: out of memory\n", o->prog);
        return 1;
    }
    rp->o_copy = *o;
    rp->o = &rp->o_copy;
    int rc = rp_scenario(rp, macs, n_macs);
    char err[1200];
    if (rc == 0 && hs_poses_load(o->poses, &rp->poses, &rp->n_poses, err, sizeof(err)) != 0) {
        fprintf(stderr, "%s: %s\n", o->prog, err);
        rc = 1;
    }
    if (rc != 0) {
        hs_replay_free(rp);
        return rc;
    }
    *out = rp;
    return 0;
}

int hs_replay_sources(const hs_replay_t *rp)
{
    return rp->n_macs;
}

bool hs_replay_heartbeats(const hs_replay_t *rp)
{
    return rp->sc.rx_heartbeat;
}

/* Room for one more element in *v (n used of *cap, each size bytes; doubled when full):
 * 0, or 1 after a message. */
static int grow(const hs_replay_t *rp, void **v, size_t *cap, size_t n, size_t size)
{
    if (n < *cap) {
        return 0;
    }
    const size_t c = *cap ? *cap * 2 : 1024;
    void *nv = realloc(*v, c * size);
    if (nv == NULL) {
        fprintf(stderr, "%s: out of memory\n", rp->o->prog);
        return 1;
    }
    *v = nv;
    *cap = c;
    return 0;
}

int hs_replay_frame(hs_replay_t *rp, const hs_replay_frame_t *f)
{
    rp_vec_t *vec = &rp->pk;
    if (grow(rp, (void **)&vec->v, &vec->cap, vec->n, sizeof(*vec->v)) != 0) {
        return 1;
    }
    vec->v[vec->n++] = *f;
    return 0;
}

int hs_replay_alive(hs_replay_t *rp, int64_t t_us)
{
    rp_times_t *hb = &rp->hb;
    if (!lx_feed_hb_due(&hb->rule, t_us)) {
        return 0;
    }
    if (grow(rp, (void **)&hb->v, &hb->cap, hb->n, sizeof(*hb->v)) != 0) {
        return 1;
    }
    hb->v[hb->n++] = t_us;
    return 0;
}

/* The environment and the controller: 0, or 1 after a message. */
static int rp_open_world(hs_replay_t *rp)
{
    const hs_replay_opts_t *o = rp->o;
    char err[1200];
    if (hs_sim_env_open(&rp->env, &rp->sc, err, sizeof(err)) != 0) {
        fprintf(stderr, "%s: %s\n", o->prog, err);
        return 1;
    }
    rp->env_open = true;
    hs_ctrl_inproc_cfg_t cc = hs_ctrl_inproc_cfg_default();
    cc.model = rp->sc.model;
    cc.target = rp->sc.target;
    cc.seed = o->has_seed ? o->seed : rp->sc.seed;
    char cerr[256];
    if (hs_ctrl_inproc_open(&rp->ctrl, &cc, &rp->env.core.map, cerr, sizeof(cerr)) != 0) {
        fprintf(stderr, "%s: %s: %s\n", o->prog, o->scenario, cerr);
        return 1;
    }
    rp->ctrl_open = true;
    memset(&rp->res, 0, sizeof(rp->res));
    rp->res.seed = cc.seed;
    return 0;
}

/* The output directory (a temporary one) and its three logs: 0, or 1 after a message. */
static int rp_open_outputs(hs_replay_t *rp, hs_replay_guard_fn guard)
{
    snprintf(rp->tmp, sizeof(rp->tmp), "%s.tmp-%ld", rp->o->out, (long)getpid());
    if (guard != NULL) {
        guard(rp->tmp, k_rp_files, (int)(sizeof(k_rp_files) / sizeof(k_rp_files[0])));
    }
    if (mkdir(rp->tmp, 0777) != 0) {
        fprintf(stderr, "%s: %s: cannot create: %s\n", rp->o->prog, rp->tmp, strerror(errno));
        return 1;
    }
    rp->flog = rp_open(rp->tmp, "log.tsv");
    rp->fsam = rp_open(rp->tmp, "samples.tsv");
    rp->ftrk = rp_open(rp->tmp, "track.tsv");
    if (rp->flog == NULL || rp->fsam == NULL || rp->ftrk == NULL) {
        fprintf(stderr, "%s: %s: cannot create the logs: %s\n", rp->o->prog, rp->tmp, strerror(errno));
        return 1;
    }
    return 0;
}

/* A matching frame: counted (sequence gaps), and fed to the controller (as its PDR with
 * target pdr) and to samples.tsv. */
static void rp_packet(hs_replay_t *rp, const hs_replay_frame_t *p, const rp_at_t *at)
{
    const uint16_t seq = (uint16_t)(p->seq_ctrl >> 4);
    if (rp->seen[p->src]) {
        const unsigned d = (unsigned)(seq - rp->last_seq[p->src]) & 0x0fffu;
        if (d >= 2u && d <= 2048u) { rp->lost += d - 1u; }
    }
    rp->seen[p->src] = true;
    rp->last_seq[p->src] = seq;
    rp->res.packets_received++;
    int8_t meas = p->dbm;
    /* A retransmission or later fragment is not a new frame: no new ratio. */
    const bool fed = !rp->pdr_target || (rfs_pdr_push_seq_ctrl(&rp->pdr[p->src], at->te, p->seq_ctrl) &&
                                         rfs_pdr_value(&rp->pdr[p->src], at->te, &meas));
    if (fed) {
        rp->ctrl.on_rssi(rp->ctrl.self, p->src, at->te, meas);
        fprintf(rp->fsam, "%.6f\t%u\t%.3f\t%.3f\t%.3f\t%d\n", at->te * 1e-6, (unsigned)p->src, at->ex,
                at->ey, at->etr, (int)meas);
    }
}

/* A recorded pose: to the controller and to track.tsv. */
static void rp_pose(hs_replay_t *rp, const hs_pose_rec_t *q, int64_t te)
{
    rfs_pose_t pose = {te, rp_q16(q->x), rp_q16(q->y), rp_q16(hs_poses_wrap(q->theta))};
    rp->ctrl.on_pose(rp->ctrl.self, &pose);
    fprintf(rp->ftrk, "%.3f\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%.4f\t0\n", te * 1e-6, q->x, q->y,
            hs_poses_wrap(q->theta), q->x, q->y, hs_poses_wrap(q->theta));
}

/* A control period: the controller's step, its decision counted and logged (the wheel
 * commands go nowhere). */
static void rp_step(hs_replay_t *rp, const rp_at_t *at)
{
    hs_ctrl_out_t out;
    memset(&out, 0, sizeof(out));
    rp->ctrl.step(rp->ctrl.self, at->te, &out);
    if (!out.decided) {
        return;
    }
    const rfs_seek_decision_t *d = &out.decision;
    hs_sim_count_decision(&rp->res, d, at->te, rp->ctrl.period_us);
    hs_sim_log_decision(rp->flog, &rp->ctrl, d, at->te * 1e-6, at->ex, at->ey, at->eth, at->etr);
}

/* Replay: packets, poses, receiver heartbeats and control periods in time order (equal
 * times: packets, then poses, then heartbeats, then control, as the simulator), time
 * counted from the first pose. With the scenario's radio.receiver.heartbeat (the
 * default) every record of the capture, from any transmitter, proves the capture loop
 * alive at its time: the controller is told so at most once per 50 ms of capture time
 * (rfs_seek_on_receiver; docs/FAULTS.md, "The receiver heartbeat"), so a stretch where
 * the source is not heard but the channel is is a dead zone, not a dead sensor. The
 * robot's position at any instant is the recorded pose interpolated linearly (theta
 * along the shorter arc); the controller's wheel commands go nowhere. Ends at the last
 * pose, or when the robot comes within the stop radius of the goal. */
static void rp_run(hs_replay_t *rp)
{
    const hs_scenario_t *sc = &rp->sc;
    const hs_pose_rec_t *poses = rp->poses;
    const size_t n_poses = rp->n_poses;
    const rp_vec_t *pk = &rp->pk;
    const rp_times_t *hb = &rp->hb;
    hs_sim_result_t *res = &rp->res;
    const int64_t t0 = poses[0].t_us;
    const int64_t t_end = poses[n_poses - 1].t_us - t0;
    const bool has_goal = sc->has_goal || sc->nsources == 1;
    fprintf(rp->flog, "iteration\tt_s\tx_m\ty_m\ttheta_rad\test_x_m\test_y_m\tkind\treason\t"
                      "relearned\tprediction_db\tmean_db\tepsilon\tgoal_x_m\tgoal_y_m\t"
                      "max_x_m\tmax_y_m\tpath_m\tsamples\ttravelled_m\t" HS_SIM_LOG_EST_COLUMNS "\n");
    fprintf(rp->fsam, "t_s\tsrc\tx_m\ty_m\ttravelled_m\t%s\n", rp->pdr_target ? "pdr_pct" : "dbm");
    fprintf(rp->ftrk, "t_s\tx_m\ty_m\ttheta_rad\test_x_m\test_y_m\test_theta_rad\ttouching\n");
    const rfs_pdr_cfg_t pdr_cfg = rfs_pdr_cfg_default();
    for (int k = 0; k < rp->n_macs; k++) { (void)rfs_pdr_init(&rp->pdr[k], &pdr_cfg); }
    size_t pi = 0, qi = 0, hi = 0; /* next packet, next pose, next heartbeat */
    size_t seg = 0;        /* poses[seg], poses[seg + 1] bracket the current time */
    double travelled_at_seg = 0.0;
    uint64_t ctrl_k = 1;
    const char *end = "time";
    double fx = poses[0].x, fy = poses[0].y;
    int64_t t_last = 0;
    while (pi < pk->n && pk->v[pi].t_us < t0) { pi++; rp->before++; }
    while (hi < hb->n && hb->v[hi] < t0) { hi++; }
    for (;;) {
        int64_t te = INT64_MAX;
        int kind = -1;
        if (pi < pk->n) { te = pk->v[pi].t_us - t0; kind = 0; }
        if (qi < n_poses && poses[qi].t_us - t0 < te) { te = poses[qi].t_us - t0; kind = 1; }
        if (hi < hb->n && hb->v[hi] - t0 < te) { te = hb->v[hi] - t0; kind = 3; }
        const int64_t tc = (int64_t)ctrl_k * rp->ctrl.period_us;
        if (tc < te) { te = tc; kind = 2; }
        if (te > t_end || kind < 0) { break; }
        t_last = te;
        /* The recorded robot position at te. */
        while (seg + 2 < n_poses && poses[seg + 1].t_us - t0 <= te) {
            travelled_at_seg += hypot(poses[seg + 1].x - poses[seg].x, poses[seg + 1].y - poses[seg].y);
            seg++;
        }
        const hs_pose_rec_t *pa = &poses[seg], *pb = &poses[seg + 1];
        const double a = (double)(te - (pa->t_us - t0)) / (double)(pb->t_us - pa->t_us);
        rp_at_t at;
        at.te = te;
        at.ex = pa->x + a * (pb->x - pa->x);
        at.ey = pa->y + a * (pb->y - pa->y);
        at.eth = hs_poses_wrap(pa->theta + a * hs_poses_wrap(pb->theta - pa->theta));
        at.etr = travelled_at_seg + a * hypot(pb->x - pa->x, pb->y - pa->y);
        fx = at.ex;
        fy = at.ey;
        if (kind == 0) {
            rp_packet(rp, &pk->v[pi++], &at);
        } else if (kind == 3) {
            hi++;
            if (rp->ctrl.on_receiver != NULL) {
                rp->ctrl.on_receiver(rp->ctrl.self, te);
            }
        } else if (kind == 1) {
            rp_pose(rp, &poses[qi++], te);
        } else {
            ctrl_k++;
            rp_step(rp, &at);
        }
        if (has_goal && sc->stop_radius_m > 0.0 &&
            hypot(at.ex - sc->goal_x, at.ey - sc->goal_y) <= sc->stop_radius_m) {
            end = "reached";
            res->reached = true;
            res->distance_travelled_m = at.etr;
            break;
        }
        res->distance_travelled_m = at.etr;
    }
    rp->after = pk->n - pi;
    res->end = end;
    res->sim_time_s = t_last * 1e-6;
    res->shortest_path_m = rp->env.shortest_path_m;
    res->shortest_to_stop_m = rp->env.shortest_to_stop_m;
    res->final_x = fx;
    res->final_y = fy;
    res->final_distance_m = has_goal ? hypot(fx - sc->goal_x, fy - sc->goal_y) : NAN;
    res->packets_sent = res->packets_received + rp->lost; /* from the sequence-number gaps */
    hs_sim_result_estimate(res, &rp->ctrl, sc->src[0].x, sc->src[0].y); /* the path-loss estimate */
}

/* Close one output file of the replay: rc, or 1 after a line naming it when a write or
 * the close failed (no second line after an earlier error). */
static int rp_close(const hs_replay_t *rp, FILE *f, const char *name, int rc)
{
    errno = 0;
    const bool bad = ferror(f) != 0;
    if ((fclose(f) != 0 || bad) && rc == 0) {
        fprintf(stderr, "%s: %s/%s: write error: %s\n", rp->o->prog, rp->tmp, name,
                errno != 0 ? strerror(errno) : "write failed");
        rc = 1;
    }
    return rc;
}

/* summary.json, the logs closed, the directory renamed into place (removed on failure),
 * and the replay freed: the exit status (rc: so far). */
static int rp_finish(hs_replay_t *rp, uint64_t *before, uint64_t *after, int rc, bool ran)
{
    if (ran) {
        FILE *fsum = rp_open(rp->tmp, "summary.json");
        if (fsum == NULL) {
            fprintf(stderr, "%s: %s/summary.json: %s\n", rp->o->prog, rp->tmp, strerror(errno));
            rc = 1;
        } else {
            hs_sim_write_summary(fsum, &rp->env, &rp->res);
            rc = rp_close(rp, fsum, "summary.json", rc);
        }
    }
    FILE *const logs[3] = {rp->flog, rp->fsam, rp->ftrk};
    for (int i = 0; i < 3; i++) {
        if (logs[i] != NULL) {
            rc = rp_close(rp, logs[i], k_rp_files[i], rc);
        }
    }
    rp->flog = rp->fsam = rp->ftrk = NULL;
    if (rp->tmp[0] != '\0') {
        if (rc == 0 && rename(rp->tmp, rp->o->out) != 0) {
            fprintf(stderr, "%s: %s: cannot rename to %s: %s\n", rp->o->prog, rp->tmp, rp->o->out, strerror(errno));
            rc = 1;
        }
        if (rc != 0) { rp_rmdir(rp->tmp); }
        if (rc == 0) {
            *before = rp->before;
            *after = rp->after;
        }
    }
    hs_replay_free(rp);
    return rc;
}


int hs_replay_run(hs_replay_t *rp, hs_replay_guard_fn guard, uint64_t *before, uint64_t *after)
{
    if (rp_open_world(rp) != 0) {
        return rp_finish(rp, before, after, 1, false);
    }
    int rc = rp_open_outputs(rp, guard);
    if (rc == 0) {
        rp_run(rp);
    }
    return rp_finish(rp, before, after, rc, rc == 0);
}

void hs_replay_free(hs_replay_t *rp)
{
    if (rp == NULL) {
        return;
    }
    if (rp->ctrl_open) { hs_ctrl_close(&rp->ctrl); }
    if (rp->env_open) { hs_sim_env_close(&rp->env); }
    free(rp->poses);
    free(rp->pk.v);
    free(rp->hb.v);
    free(rp);
}
