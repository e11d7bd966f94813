/* test_faults.c - fault injection (host_sim/hs_faults.h, docs/FAULTS.md).
 *
 * Two halves. The hooks alone: each fault is fed a regular stream and what comes out is
 * compared with what the schedule says (times and counts worked out by hand here). Whole
 * runs: the open-hall fault scenarios (scenarios/faults/open-*.yaml) run in-process with
 * the injector's log, and the log is read back here to measure, from the core's own wheel
 * commands, that the wheels are commanded to zero whenever the newest input the core was
 * given is more than 200 ms old (the bound), that the motor model stops the wheels
 * within 200 ms of the last delivered command on a bus-off, and that the run still reaches
 * the source. An input stamped more than 200 ms in the future counts as stale as well: it
 * freezes the controller's view just like an old one. Input age is computed here from the delivered timestamps, not taken from the
 * core's fault flags.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hs_faults.h"
#include "hs_scenario.h"
#include "hs_sim.h"

/* Append fault k (its defaults) over [start_s, start_s + duration_s) to c; returns it for
 * the fields a test sets besides. */
static hs_fault_t *add(hs_faults_cfg_t *c, hs_fault_kind_t k, double start_s, double duration_s)
{
    hs_fault_t *f = &c->f[c->n++];
    *f = hs_faults_default(k);
    f->start_s = start_s;
    f->duration_s = duration_s;
    return f;
}

static hs_faults_cfg_t one(hs_fault_kind_t k, double start_s, double duration_s)
{
    hs_faults_cfg_t c;
    memset(&c, 0, sizeof c);
    (void)add(&c, k, start_s, duration_s);
    return c;
}

// --- the hooks alone -------------------------------------------------------------------

static void test_silence_drops_exactly_the_window(void **state)
{
    (void)state;
    // Fixture: silence over [1 s, 2 s); packets every 5 ms over [0, 3 s).
    hs_faults_cfg_t c = one(HS_FAULT_RSSI_SILENCE, 1.0, 1.0);
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    unsigned delivered = 0, inside = 0;
    // Act.
    for (int64_t t = 0; t < 3000000; t += 5000) {
        hs_faults_msg_t m[2];
        unsigned n = hs_faults_rssi(&r, t, 0, -60, m);
        delivered += n;
        inside += (t >= 1000000 && t < 2000000) ? n : 0;
        if (n == 1) {
            assert_int_equal(m[0].t_us, t);
            assert_int_equal(m[0].dbm, -60);
        }
    }
    // Assert: 600 packets, the 200 inside the window withheld.
    assert_int_equal(delivered, 400);
    assert_int_equal(inside, 0);
    assert_int_equal(r.rssi_dropped, 200);
}

static void test_past_timestamps_lag(void **state)
{
    (void)state;
    hs_faults_cfg_t c = one(HS_FAULT_RSSI_PAST, 1.0, 1.0);
    c.f[0].lag_s = 0.5;
    hs_faults_cfg_t cp = one(HS_FAULT_POSE_PAST, 1.0, 1.0);
    cp.f[0].lag_s = 0.25;
    hs_faults_run_t r, rp;
    hs_faults_start(&r, &c, 7, NULL);
    hs_faults_start(&rp, &cp, 7, NULL);
    for (int64_t t = 0; t < 3000000; t += 100000) {
        hs_faults_msg_t m[2];
        assert_int_equal(hs_faults_rssi(&r, t, 1, -50, m), 1);
        bool in = t >= 1000000 && t < 2000000;
        assert_int_equal(m[0].t_us, in ? t - 500000 : t);
        assert_int_equal(m[0].src, 1);
        rfs_pose_t p = {t, RFS_Q16_INT(4), RFS_Q16_INT(5), 0};
        assert_int_equal(hs_faults_pose(&rp, &p, m), 1);
        assert_int_equal(m[0].pose.t_us, in ? t - 250000 : t);
        assert_int_equal(m[0].pose.x, RFS_Q16_INT(4));
    }
}

static void test_reorder_swaps_pairs(void **state)
{
    (void)state;
    // Poses every 100 ms; reorder over [0.3 s, 0.7 s): 0.3 is held and follows 0.4, 0.5
    // is held and follows 0.6, then order returns.
    hs_faults_cfg_t c = one(HS_FAULT_POSE_REORDER, 0.3, 0.4);
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    int64_t got[16];
    unsigned ng = 0;
    for (int64_t t = 0; t <= 1000000; t += 100000) {
        rfs_pose_t p = {t, 0, 0, 0};
        hs_faults_msg_t m[2];
        unsigned n = hs_faults_pose(&r, &p, m);
        for (unsigned k = 0; k < n; k++) {
            got[ng++] = m[k].pose.t_us;
        }
    }
    static const int64_t want[] = {0, 100000, 200000, 400000, 300000, 600000, 500000,
                                   700000, 800000, 900000, 1000000};
    assert_int_equal(ng, sizeof want / sizeof want[0]);
    for (unsigned k = 0; k < ng; k++) {
        assert_int_equal(got[k], want[k]);
    }
}

static void test_reorder_flushes_the_held_message_when_the_window_ends(void **state)
{
    (void)state;
    // Window [0.1 s, 0.2 s) holds the 0.1 s packet only; at 0.2 s it goes first.
    hs_faults_cfg_t c = one(HS_FAULT_RSSI_REORDER, 0.1, 0.1);
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    hs_faults_msg_t m[2];
    assert_int_equal(hs_faults_rssi(&r, 0, 0, -40, m), 1);
    assert_int_equal(hs_faults_rssi(&r, 100000, 0, -41, m), 0);
    assert_int_equal(hs_faults_rssi(&r, 200000, 0, -42, m), 2);
    assert_int_equal(m[0].t_us, 100000);
    assert_int_equal(m[0].dbm, -41);
    assert_int_equal(m[1].t_us, 200000);
    assert_int_equal(m[1].dbm, -42);
}

static void test_pose_jump_offsets_only_inside_the_window(void **state)
{
    (void)state;
    hs_faults_cfg_t c = one(HS_FAULT_POSE_JUMP, 1.0, 2.0);
    c.f[0].x = 3.0;
    c.f[0].y = -1.5;
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    for (int64_t t = 0; t < 4000000; t += 500000) {
        rfs_pose_t p = {t, RFS_Q16_INT(10), RFS_Q16_INT(2), RFS_Q16_INT(1)};
        hs_faults_msg_t m[2];
        assert_int_equal(hs_faults_pose(&r, &p, m), 1);
        bool in = t >= 1000000 && t < 3000000;
        assert_int_equal(m[0].pose.x, in ? RFS_Q16_INT(13) : RFS_Q16_INT(10));
        assert_int_equal(m[0].pose.y, in ? RFS_Q16_INT(1) / 2 : RFS_Q16_INT(2));
        assert_int_equal(m[0].pose.theta, RFS_Q16_INT(1));
        assert_int_equal(m[0].pose.t_us, t);
    }
}

static void test_bus_off_loses_every_command_in_the_window(void **state)
{
    (void)state;
    hs_faults_cfg_t c = one(HS_FAULT_BUS_OFF, 2.0, 2.0);
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    rfs_seek_out_t out;
    memset(&out, 0, sizeof out);
    out.left_mm_s = 200;
    out.right_mm_s = 200;
    for (int64_t t = 50000; t <= 5000000; t += 50000) {
        bool in = t >= 2000000 && t < 4000000;
        assert_int_equal(hs_faults_cmd(&r, t, &out), !in);
    }
    assert_int_equal(r.cmds_lost, 40); // 2 s at 20 Hz
}

static void test_can_drop_rate_matches_probability(void **state)
{
    (void)state;
    rfs_seek_out_t out;
    memset(&out, 0, sizeof out);
    static const double ps[] = {0.0, 0.3, 1.0};
    for (unsigned i = 0; i < 3; i++) {
        hs_faults_cfg_t c = one(HS_FAULT_CAN_DROP, 0.0, 1000.0);
        c.f[0].probability = ps[i];
        hs_faults_run_t r;
        hs_faults_start(&r, &c, 11, NULL);
        const unsigned n = 10000;
        for (unsigned k = 0; k < n; k++) {
            (void)hs_faults_cmd(&r, (int64_t)k * 50000, &out);
        }
        // Binomial(n, p): mean n p, 5 standard deviations either side.
        double mean = n * ps[i], sd = sqrt(n * ps[i] * (1.0 - ps[i]));
        assert_true(fabs((double)r.cmds_lost - mean) <= 5.0 * sd + 1e-9);
    }
}

static void test_one_shot_events_fire_once_when_due(void **state)
{
    (void)state;
    hs_faults_cfg_t c = one(HS_FAULT_KIDNAP, 5.0, 0.0); /* one-shot: no duration */
    c.f[0].x = 3.0;
    c.f[0].y = 4.0;
    c.f[0].theta = 1.0;
    hs_fault_t *move = add(&c, HS_FAULT_SOURCE_MOVE, 2.0, 0.0);
    move->x = 7.0;
    move->y = 8.0;
    hs_faults_run_t r;
    hs_faults_start(&r, &c, 7, NULL);
    hs_faults_event_t ev;
    assert_false(hs_faults_next_event(&r, 1980000, &ev));
    assert_true(hs_faults_next_event(&r, 2000000, &ev));
    assert_int_equal(ev.kind, HS_FAULT_SOURCE_MOVE);
    assert_true(ev.x == 7.0 && ev.y == 8.0 && ev.source == 0);
    assert_false(hs_faults_next_event(&r, 4000000, &ev));
    assert_true(hs_faults_next_event(&r, 9000000, &ev));
    assert_int_equal(ev.kind, HS_FAULT_KIDNAP);
    assert_true(ev.x == 3.0 && ev.y == 4.0 && ev.theta == 1.0);
    assert_false(hs_faults_next_event(&r, 90000000, &ev));
}

static void test_check_rejects_bad_faults(void **state)
{
    (void)state;
    char err[256];
    hs_fault_t f = hs_faults_default(HS_FAULT_RSSI_SILENCE);
    assert_int_equal(hs_faults_check(&f, 1, err, sizeof err), 0);
    f.duration_s = 0.0;
    assert_int_equal(hs_faults_check(&f, 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "duration_s"));
    f = hs_faults_default(HS_FAULT_KIDNAP);
    f.duration_s = 3.0;
    assert_int_equal(hs_faults_check(&f, 1, err, sizeof err), -1);
    f = hs_faults_default(HS_FAULT_SOURCE_MOVE);
    f.source = 1;
    assert_int_equal(hs_faults_check(&f, 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "source"));
    assert_int_equal(hs_faults_check(&f, 2, err, sizeof err), 0);
    f = hs_faults_default(HS_FAULT_CAN_DROP);
    f.probability = 1.5;
    assert_int_equal(hs_faults_check(&f, 1, err, sizeof err), -1);
    hs_fault_kind_t k;
    assert_true(hs_faults_kind_parse("bus_off", &k));
    assert_int_equal(k, HS_FAULT_BUS_OFF);
    assert_false(hs_faults_kind_parse("bus-off", &k));
    assert_string_equal(hs_faults_kind_name(HS_FAULT_POSE_JUMP), "pose_jump");
}

// --- whole runs ------------------------------------------------------------------------

/// What the log of one run says, measured here.
typedef struct measured {
    unsigned cmds;          ///< wheel commands
    unsigned stale_cmds;    ///< commands while the newest input was more than 200 ms old
    unsigned stale_moving;  ///< of those, commands with a non-zero wheel speed (must be 0)
    unsigned moving_after;  ///< non-zero commands after the last fault window ended
    double fault_end_s;     ///< end of the last lasting fault window (-1: none)
    double last_delivered_before_s; ///< bus-off: last delivered command before the window
    double motor_stop_s;    ///< first motor timeout at or after that command (-1: none)
    double motor_go_s;      ///< first motor restart after that (-1: none)
    double kidnap_s;        ///< time of the kidnap event (-1: none)
    double pose_after_kidnap_x, pose_after_kidnap_y; ///< first pose delivered after it
} measured_t;

/// Split a TSV line in place into at most 7 fields.
static unsigned split(char *line, char *f[7])
{
    unsigned n = 0;
    char *p = line;
    while (n < 7) {
        f[n++] = p;
        char *tab = strchr(p, '\t');
        if (!tab) {
            break;
        }
        *tab = '\0';
        p = tab + 1;
    }
    char *nl = strchr(f[n - 1], '\n');
    if (nl) {
        *nl = '\0';
    }
    return n;
}

static void measure(FILE *log, double bus_off_start_s, measured_t *m)
{
    memset(m, 0, sizeof *m);
    m->fault_end_s = -1.0;
    m->last_delivered_before_s = -1.0;
    m->motor_stop_s = -1.0;
    m->motor_go_s = -1.0;
    m->kidnap_s = -1.0;
    double pose_max = -INFINITY, rssi_max = -INFINITY;
    bool want_pose_after_kidnap = false;
    char line[512];
    rewind(log);
    assert_non_null(fgets(line, sizeof line, log)); // header
    while (fgets(line, sizeof line, log)) {
        char *f[7];
        unsigned n = split(line, f);
        assert_int_equal(n, 7);
        double t = strtod(f[0], NULL);
        if (strcmp(f[1], "pose") == 0) {
            pose_max = fmax(pose_max, strtod(f[2], NULL));
            if (want_pose_after_kidnap) {
                m->pose_after_kidnap_x = strtod(f[3], NULL);
                m->pose_after_kidnap_y = strtod(f[4], NULL);
                want_pose_after_kidnap = false;
            }
        } else if (strcmp(f[1], "rssi") == 0) {
            rssi_max = fmax(rssi_max, strtod(f[2], NULL));
        } else if (strcmp(f[1], "cmd") == 0) {
            int l = atoi(f[2]), r = atoi(f[3]);
            bool delivered = atoi(f[4]) != 0;
            m->cmds++;
            // Stale: the newest stamp is more than 200 ms from now, either way (a stamp
            // from the future freezes the input just as well). 1 us of slack for the
            // 6-decimal timestamps in the log.
            if (fabs(t - pose_max) > 0.2 + 1e-6 || fabs(t - rssi_max) > 0.2 + 1e-6) {
                m->stale_cmds++;
                m->stale_moving += (l != 0 || r != 0) ? 1u : 0u;
            }
            if (m->fault_end_s >= 0.0 && t > m->fault_end_s && (l != 0 || r != 0)) {
                m->moving_after++;
            }
            if (delivered && t < bus_off_start_s) {
                m->last_delivered_before_s = t;
            }
        } else if (strcmp(f[1], "motor") == 0) {
            bool stopped = atoi(f[2]) != 0;
            if (stopped && m->motor_stop_s < 0.0 && m->last_delivered_before_s >= 0.0 &&
                t >= bus_off_start_s - 0.5) {
                m->motor_stop_s = t;
            } else if (!stopped && m->motor_stop_s >= 0.0 && m->motor_go_s < 0.0) {
                m->motor_go_s = t;
            }
        } else if (strcmp(f[1], "fault_end") == 0) {
            m->fault_end_s = t;
        } else if (strcmp(f[1], "kidnap") == 0) {
            m->kidnap_s = t;
            want_pose_after_kidnap = true;
        }
    }
}

/// Run scenarios/faults/open-NAME.yaml with `seed`, logging into a temporary file.
static void run_fault(const char *name, uint64_t seed, hs_sim_result_t *res, FILE **log,
                         hs_scenario_t *sc_out, FILE *decisions)
{
    char path[256], err[1024];
    snprintf(path, sizeof path, "scenarios/faults/open-%s.yaml", name);
    hs_scenario_t sc;
    if (hs_scenario_load(path, &sc, err, sizeof err) != 0) {
        fail_msg("%s", err);
    }
    assert_int_equal(sc.faults.n, 1);
    hs_sim_env_t env;
    if (hs_sim_env_open(&env, &sc, err, sizeof err) != 0) {
        fail_msg("%s", err);
    }
    *log = tmpfile();
    assert_non_null(*log);
    hs_sim_io_t io;
    memset(&io, 0, sizeof io);
    io.faults = *log;
    io.log = decisions;
    if (hs_sim_run_inproc(&env, seed, &io, res, err, sizeof err) != 0) {
        fail_msg("%s", err);
    }
    hs_sim_env_close(&env);
    fflush(*log);
    *sc_out = sc;
}

/// The checks every fault shares: the run reached the source, no command moved the
/// wheels while the newest input was more than 200 ms old, and the log is not empty.
static void common_checks(const char *name, const hs_sim_result_t *res, const measured_t *m)
{
    if (!res->reached) {
        fail_msg("%s: not reached (end %s, %.1f m from the goal)", name, res->end,
                 res->final_distance_m);
    }
    assert_true(m->cmds > 100);
    if (m->stale_moving != 0) {
        fail_msg("%s: %u wheel commands non-zero with an input stamp over 200 ms from now", name,
                 m->stale_moving);
    }
}

/// Run open-NAME.yaml with seed 1, measure its log (around the window when the fault is a
/// bus-off) and make the common checks.
static void run_checked(const char *name, hs_sim_result_t *res, hs_scenario_t *sc, measured_t *m)
{
    FILE *log = NULL;
    /* The first seed whose run outlives the fault's window by a second (a run that
     * reaches the source during the fault shows nothing of the recovery). */
    for (uint64_t seed = 1; seed <= 8; seed++) {
        if (log != NULL) {
            fclose(log);
        }
        run_fault(name, seed, res, &log, sc, NULL);
        const hs_fault_t *f = &sc->faults.f[0];
        if (res->sim_time_s > f->start_s + f->duration_s + 1.0) {
            break;
        }
    }
    const hs_fault_t *f = &sc->faults.f[0];
    measure(log, f->kind == HS_FAULT_BUS_OFF ? f->start_s : INFINITY, m);
    fclose(log);
    common_checks(name, res, m);
}

static void test_stale_input_faults_stop_the_wheels_and_recover(void **state)
{
    (void)state;
    // Each fault and the least number of commands it must leave with stale inputs (the
    // start, before the first inputs, counts too: at least the first period).
    static const struct {
        const char *name;
        unsigned min_stale;
    } cases[] = {
        {"rssi_silence", 590}, // 30 s at 20 Hz, less the 200 ms grace
        {"pose_past", 150},    // 10 s window, 1 s lag: 9 s of old poses at least
        {"rssi_past", 150},
        {"pose_reorder", 1},   // 100 ms poses stay within 200 ms even when swapped
        {"rssi_reorder", 1},
        {"pose_jump", 1},
        {"pose_future", 90},   // one pose 5 s ahead: stale until its stamp, 4.8 s at least
        {"rssi_future", 90},
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        hs_sim_result_t res;
        hs_scenario_t sc;
        measured_t m;
        run_checked(cases[i].name, &res, &sc, &m);
        if (m.stale_cmds < cases[i].min_stale) {
            fail_msg("%s: only %u commands with stale inputs (want >= %u)", cases[i].name,
                     m.stale_cmds, cases[i].min_stale);
        }
        // The fault ended while the run went on, and the robot drove again afterwards.
        double end_s = sc.faults.f[0].start_s + sc.faults.f[0].duration_s;
        assert_true(fabs(m.fault_end_s - end_s) < 1e-3);
        assert_true(res.sim_time_s > end_s);
        if (m.moving_after == 0) {
            fail_msg("%s: no wheel command after the fault", cases[i].name);
        }
    }
}

static void test_bus_off_stops_the_wheels_within_200_ms(void **state)
{
    (void)state;
    hs_sim_result_t res;
    hs_scenario_t sc;
    measured_t m;
    run_checked("bus_off", &res, &sc, &m);
    const hs_fault_t *f = &sc.faults.f[0];
    // The last command that got through came in the control period before the window.
    assert_true(m.last_delivered_before_s >= f->start_s - 0.05 - 1e-6);
    // The motor controller's 200 ms timeout set the wheels' target to zero from the first
    // physics tick that began more than 200 ms after it.
    assert_true(m.motor_stop_s > m.last_delivered_before_s);
    assert_true(m.motor_stop_s - m.last_delivered_before_s <= 0.2 + 1e-6);
    // ... and they start again once the bus is back (the first command after 2 s).
    assert_true(m.motor_go_s >= f->start_s + f->duration_s - 1e-6);
    assert_true(m.motor_go_s <= f->start_s + f->duration_s + 0.05 + 0.02 + 1e-6);
    assert_true(res.motor_timeouts >= 1);
}

static void test_can_send_failures_are_survived(void **state)
{
    (void)state;
    hs_sim_result_t res;
    hs_scenario_t sc;
    measured_t m;
    run_checked("can_drop", &res, &sc, &m);
    assert_true(m.moving_after > 0);
}

static void test_kidnapped_robot_still_reaches_the_source(void **state)
{
    (void)state;
    hs_sim_result_t res;
    hs_scenario_t sc;
    measured_t m;
    run_checked("kidnap", &res, &sc, &m);
    const hs_fault_t *f = &sc.faults.f[0];
    assert_true(fabs(m.kidnap_s - f->start_s) <= 0.02 + 1e-6);
    // The next localisation pose is where the robot was put down (pose noise 5 cm, and at
    // most 100 ms of driving at 0.7 m/s).
    assert_true(hypot(m.pose_after_kidnap_x - f->x, m.pose_after_kidnap_y - f->y) < 0.3);
}

static void test_moved_source_is_found_at_its_new_place(void **state)
{
    (void)state;
    hs_sim_result_t res;
    hs_scenario_t sc;
    measured_t m;
    run_checked("source_move", &res, &sc, &m);
    const hs_fault_t *f = &sc.faults.f[0];
    assert_true(res.sim_time_s > f->start_s); // the move happened during the run
    assert_true(hypot(res.final_x - f->x, res.final_y - f->y) <= sc.stop_radius_m + 1e-9);
}

/* After a 30 s RSSI silence the core resumes the goal it was driving (rfs_seek.c
 * `resume`). The goal's 30 s timeout (rfs_drive_cfg_default) counts driving time only:
 * in seed 1 the goal was set 3 s before the silence, so when inputs return it must end
 * as reached (or blocked), not be abandoned as timed out (33 s after it was set). */
static void test_goal_resumes_after_silence(void **state)
{
    (void)state;
    FILE *dec = tmpfile();
    assert_non_null(dec);
    hs_sim_result_t res;
    FILE *log;
    hs_scenario_t sc;
    run_fault("rssi_silence", 1, &res, &log, &sc, dec);
    fclose(log);
    const double t0 = sc.faults.f[0].start_s, t1 = t0 + sc.faults.f[0].duration_s;
    rewind(dec);
    char line[1024];
    assert_non_null(fgets(line, sizeof line, dec)); // header
    double last_before = -1.0, first_after = -1.0;
    char reason_after[128] = "";
    while (fgets(line, sizeof line, dec)) {
        // Columns: iteration, t_s, x_m, y_m, theta_rad, est_x_m, est_y_m, kind, reason, ...
        char *f[10];
        unsigned n = 0;
        for (char *p = line; n < 10 && p; n++) {
            f[n] = p;
            p = strchr(p, '\t');
            if (p) {
                *p++ = '\0';
            }
        }
        assert_true(n == 10);
        double t = strtod(f[1], NULL);
        if (t < t0) {
            last_before = t;
        } else if (t >= t1 && first_after < 0.0) {
            first_after = t;
            snprintf(reason_after, sizeof reason_after, "%s", f[8]);
        }
    }
    fclose(dec);
    // The goal before the silence was young (set less than 30 s of driving before).
    assert_true(last_before > t0 - 30.0 && last_before < t0);
    assert_true(first_after >= t1);
    if (strstr(reason_after, "prev=timeout")) {
        fail_msg("resumed goal abandoned at once: first decision at %.2f s (%s)", first_after,
                 reason_after);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_silence_drops_exactly_the_window),
        cmocka_unit_test(test_past_timestamps_lag),
        cmocka_unit_test(test_reorder_swaps_pairs),
        cmocka_unit_test(test_reorder_flushes_the_held_message_when_the_window_ends),
        cmocka_unit_test(test_pose_jump_offsets_only_inside_the_window),
        cmocka_unit_test(test_bus_off_loses_every_command_in_the_window),
        cmocka_unit_test(test_can_drop_rate_matches_probability),
        cmocka_unit_test(test_one_shot_events_fire_once_when_due),
        cmocka_unit_test(test_check_rejects_bad_faults),
        cmocka_unit_test(test_stale_input_faults_stop_the_wheels_and_recover),
        cmocka_unit_test(test_bus_off_stops_the_wheels_within_200_ms),
        cmocka_unit_test(test_can_send_failures_are_survived),
        cmocka_unit_test(test_kidnapped_robot_still_reaches_the_source),
        cmocka_unit_test(test_moved_source_is_found_at_its_new_place),
        cmocka_unit_test(test_goal_resumes_after_silence),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
