/* test_pdr.c - packet delivery ratio window and the "pdr" target (common/rfs_pdr).
 *
 * References: (1) a simulated link whose generator knows which frames it dropped and
 * when every frame was sent: the ratio is recomputed here in double precision from
 * that truth (not from sequence arithmetic) and compared with the frames actually sent
 * in the window; (2) a real capture (tests/data/captures/ieee802.11_exthdr.pcap)
 * decoded by tshark, the ratio recomputed in double from tshark's sequence numbers.
 * Run from the repository root (as `make test` does).
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rfs_pdr.h"
#include "rfs_rssi.h"

#define W_US 1000000
#define PERIOD_US 5000
#define N_SENT 12000u

typedef struct frame {
    int64_t t_us;   /* send (= receive) time */
    uint16_t seq;   /* 12-bit sequence number */
    bool received;  /* the link let it through */
    bool dup;       /* a retransmitted copy follows 1 ms later */
} frame_t;

static frame_t g_f[N_SENT];
static rfs_pdr_t g_p;

static double q16_to_d(int32_t v)
{
    return v / 65536.0;
}

/* Loss probability over time: 10 % for 20 s, 50 % for 20 s, a 2 s outage at 45 s, 2 %. */
static double loss_at(int64_t t_us)
{
    double t = t_us / 1e6;
    if (t < 20.0) return 0.10;
    if (t < 40.0) return 0.50;
    if (t >= 45.0 && t < 47.0) return 1.0;
    return 0.02;
}

static void make_link(uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    for (uint32_t i = 0; i < N_SENT; ++i) {
        g_f[i].t_us = 1000 + (int64_t)i * PERIOD_US;
        g_f[i].seq = (uint16_t)((i + 4000u) % 4096u); /* wraps three times */
        g_f[i].received = (rfs_rng_u32(&r) / 4294967296.0) >= loss_at(g_f[i].t_us);
        g_f[i].dup = g_f[i].received && rfs_rng_below(&r, 10) == 0;
    }
    g_f[0].received = true;
}

/* The definition in double: received frames in (now - W, now]; frames lost before each
 * of them (from the generator); the oldest one's lost frames scaled by the share of its
 * gap inside the window. Returns NAN when no frame is in the window. */
static double ref_ratio(int64_t now)
{
    double start = (double)(now - W_US);
    int64_t prev_t = -1;
    uint32_t lost = 0, n = 0;
    double lost_eff = 0.0;
    for (uint32_t i = 0; i < N_SENT && g_f[i].t_us <= now; ++i) {
        if (!g_f[i].received) {
            lost++;
            continue;
        }
        if ((double)g_f[i].t_us > start) {
            if (n == 0 && prev_t >= 0) {
                double from = fmax((double)prev_t, start);
                lost_eff += lost * ((double)g_f[i].t_us - from) / (double)(g_f[i].t_us - prev_t);
            } else {
                lost_eff += lost;
            }
            n++;
        }
        prev_t = g_f[i].t_us;
        lost = 0;
    }
    return n == 0 ? NAN : 100.0 * n / (n + lost_eff);
}

/* What actually happened: received / sent among the frames sent in (now - W, now]. */
static double truth_ratio(int64_t now)
{
    uint32_t sent = 0, recv = 0;
    for (uint32_t i = 0; i < N_SENT && g_f[i].t_us <= now; ++i) {
        if (g_f[i].t_us > now - W_US) {
            sent++;
            recv += g_f[i].received ? 1u : 0u;
        }
    }
    return recv == 0 ? NAN : 100.0 * recv / sent;
}

/* Read when a frame arrives (as the seeker does): every frame up to now is known, so the
 * ratio can be held against the frames actually sent in the window. */
static void simulated_link_matches_double_and_truth(void **state)
{
    (void)state;
    rfs_pdr_cfg_t c = rfs_pdr_cfg_default();
    make_link(7);
    assert_int_equal(rfs_pdr_init(&g_p, &c), 0);
    uint32_t checked = 0, sent_lost = 0, dups = 0, gaps_seen = 0;
    double worst_ref = 0.0, worst_truth = 0.0;

    for (uint32_t i = 0; i < N_SENT; ++i) {
        if (!g_f[i].received) {
            sent_lost++;
            continue;
        }
        int64_t now = g_f[i].t_us;
        assert_true(rfs_pdr_push(&g_p, now, g_f[i].seq));
        if (i % 7u == 0u) {
            rfs_q16_t got;
            assert_true(rfs_pdr_ratio(&g_p, now, &got));
            double want = ref_ratio(now), truth = truth_ratio(now);
            worst_ref = fmax(worst_ref, fabs(q16_to_d(got) - want));
            worst_truth = fmax(worst_truth, fabs(q16_to_d(got) - truth));
            gaps_seen += truth < 30.0 ? 1u : 0u;
            checked++;
        }
        if (g_f[i].dup) {
            assert_false(rfs_pdr_push(&g_p, now + 1000, g_f[i].seq));
            dups++;
        }
    }
    rfs_q16_t after;
    bool stale = rfs_pdr_ratio(&g_p, g_f[N_SENT - 1].t_us + 1000 + W_US, &after);

    print_message("PDR: worst |fixed - double| %.6f %%, |fixed - truth| %.3f %%\n", worst_ref,
                  worst_truth);
    assert_true(checked > 1000);
    assert_true(gaps_seen > 0); /* windows right after the outage were checked */
    assert_true(worst_ref < 1e-3);
    assert_true(worst_truth < 1.0);
    assert_false(stale);
    assert_int_equal(g_p.lost_total, sent_lost);
    assert_int_equal(g_p.duplicates, dups);
    assert_int_equal(g_p.resyncs, 0);
}

static void wrap_backwards_step_and_order_rules(void **state)
{
    (void)state;
    rfs_pdr_cfg_t c = rfs_pdr_cfg_default();
    rfs_q16_t pct;
    assert_int_equal(rfs_pdr_init(&g_p, &c), 0);

    assert_true(rfs_pdr_push(&g_p, 1000, 4094));
    assert_true(rfs_pdr_push(&g_p, 2000, 4095));
    assert_true(rfs_pdr_push(&g_p, 4000, 1));      /* 0 lost across the wrap */
    assert_false(rfs_pdr_push(&g_p, 3000, 2));     /* older than the newest */
    assert_false(rfs_pdr_push(&g_p, 4500, 1));     /* retransmission */
    assert_true(rfs_pdr_push(&g_p, 5000, 4000));   /* backwards: restart */
    assert_true(rfs_pdr_push(&g_p, 6000, 4001 + 4096)); /* high bits ignored */

    assert_int_equal(g_p.lost_total, 1);
    assert_int_equal(g_p.rejected_order, 1);
    assert_int_equal(g_p.duplicates, 1);
    assert_int_equal(g_p.resyncs, 1);
    assert_true(rfs_pdr_ratio(&g_p, 6000, &pct));
    /* 5 received, 1 lost (fully inside the window): 5/6 */
    assert_true(fabs(q16_to_d(pct) - 500.0 / 6.0) < 1e-4);
    assert_false(rfs_pdr_ratio(&g_p, 6000 + W_US, &pct));
}

static void seq_ctrl_takes_fragment_zero_only(void **state)
{
    (void)state;
    rfs_pdr_cfg_t c = rfs_pdr_cfg_default();
    rfs_q16_t pct;
    int8_t v;
    assert_int_equal(rfs_pdr_init(&g_p, &c), 0);

    assert_true(rfs_pdr_push_seq_ctrl(&g_p, 1000, (uint16_t)(10u << 4)));
    assert_false(rfs_pdr_push_seq_ctrl(&g_p, 2000, (uint16_t)((11u << 4) | 1u)));
    assert_true(rfs_pdr_push_seq_ctrl(&g_p, 3000, (uint16_t)(13u << 4)));

    assert_int_equal(g_p.lost_total, 2);
    assert_true(rfs_pdr_ratio(&g_p, 3000, &pct));
    assert_true(fabs(q16_to_d(pct) - 50.0) < 1e-4);
    assert_true(rfs_pdr_value(&g_p, 3000, &v));
    assert_int_equal(v, 50);
}

static void init_rejects_bad_window(void **state)
{
    (void)state;
    rfs_pdr_cfg_t c = rfs_pdr_cfg_default();
    assert_int_equal(c.window_us, 1000000);
    c.window_us = 0;
    assert_int_equal(rfs_pdr_init(&g_p, &c), -1);
    c.window_us = 60000001u;
    assert_int_equal(rfs_pdr_init(&g_p, &c), -1);
}

/* The real capture: station 90:a4:de:c0:46:11 sends sequence numbers 1, 2, 5..8, 27..30
 * over 3.4 s (tshark decodes them); the ratio after each frame, recomputed in double. */
static void capture_sequence_numbers_from_tshark(void **state)
{
    (void)state;
    FILE *f = popen("tshark -r tests/data/captures/ieee802.11_exthdr.pcap "
                    "-Y 'wlan.ta == 90:a4:de:c0:46:11' -T fields -e frame.time_epoch "
                    "-e wlan.seq -e wlan.frag 2>/dev/null", "r");
    assert_non_null(f);
    double t[64];
    int seq[64], frag[64], n = 0;
    while (n < 64 && fscanf(f, "%lf %d %d", &t[n], &seq[n], &frag[n]) == 3) {
        n++;
    }
    assert_int_equal(pclose(f), 0);
    assert_int_equal(n, 10);
    rfs_pdr_cfg_t c = rfs_pdr_cfg_default();
    assert_int_equal(rfs_pdr_init(&g_p, &c), 0);
    int64_t t0 = (int64_t)llround(t[0] * 1e6);

    for (int i = 0; i < n; ++i) {
        int64_t now = (int64_t)llround(t[i] * 1e6) - t0;
        assert_true(rfs_pdr_push_seq_ctrl(&g_p, now, (uint16_t)(seq[i] << 4 | frag[i])));
        rfs_q16_t got;
        assert_true(rfs_pdr_ratio(&g_p, now, &got));
        /* double: frames within 1 s, lost = sequence gaps, the oldest gap scaled */
        double start = now - 1e6, lost = 0.0;
        int in = 0;
        for (int k = 0; k <= i; ++k) {
            double tk = (double)((int64_t)llround(t[k] * 1e6) - t0);
            if (tk <= start) continue;
            double gap = k == 0 ? 0.0 : seq[k] - seq[k - 1] - 1;
            if (in == 0 && k > 0) {
                double tp = (double)((int64_t)llround(t[k - 1] * 1e6) - t0);
                gap *= (tk - fmax(tp, start)) / (tk - tp);
            }
            lost += gap;
            in++;
        }
        double want = 100.0 * in / (in + lost);
        assert_true(fabs(q16_to_d(got) - want) < 1e-3);
    }
    assert_int_equal(g_p.lost_total, 20); /* 3, 4 and 9..26 */
}

static void target_learns_the_percentages(void **state)
{
    (void)state;
    rfs_rssi_cfg_t wc = rfs_rssi_cfg_default();
    rfs_rssi_t win;
    assert_int_equal(rfs_rssi_init(&win, &wc), 0);
    assert_true(rfs_rssi_push(&win, 100000, 80));
    assert_true(rfs_rssi_push(&win, 200000, 90));
    assert_true(rfs_rssi_push(&win, 300000, 97));
    rfs_target_in_t in = {.win = &win, .nsources = 1, .now_us = 300000};
    rfs_q16_t v = 0, mean = 0;

    bool s_ok = rfs_target_pdr.sample(&in, 0, 97, &v);
    bool m_ok = rfs_target_pdr.mean(&in, &mean);
    bool bad_src = rfs_target_pdr.sample(&in, 1, 97, &v);
    bool bad_val = rfs_target_pdr.sample(&in, 0, 101, &v);

    assert_true(s_ok && m_ok);
    assert_false(bad_src || bad_val);
    assert_int_equal(v, 97 * 65536);
    assert_true(fabs(q16_to_d(mean) - (80.0 + 90.0 + 97.0) / 3.0) < 1e-4);
    assert_string_equal(rfs_target_pdr.name, "pdr");
    assert_int_equal(rfs_target_pdr.nsources, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(simulated_link_matches_double_and_truth),
        cmocka_unit_test(wrap_backwards_step_and_order_rules),
        cmocka_unit_test(seq_ctrl_takes_fragment_zero_only),
        cmocka_unit_test(init_rejects_bad_window),
        cmocka_unit_test(capture_sequence_numbers_from_tshark),
        cmocka_unit_test(target_learns_the_percentages),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
