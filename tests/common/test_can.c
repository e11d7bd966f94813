/* test_can.c - the CAN protocol codec (common/rfs_can).
 *
 * Reference bytes come from the layout in docs/CAN.md computed by an independent Python
 * implementation (struct packing + its own CRC-8/SAE-J1850, scripts/check_dbc.py's
 * crc8_j1850); conversion references are computed here in double precision.
 */
#include "rfs_test.h"

#include <math.h>
#include <string.h>

#include "rfs_can.h"

static rfs_can_frame_t frame_of(uint32_t id, const uint8_t *bytes, uint8_t dlc)
{
    rfs_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.dlc = dlc;
    memcpy(f.data, bytes, dlc);
    return f;
}

static void crc8_matches_catalogue_check_value(void **state)
{
    (void)state;
    /* CRC-8/SAE-J1850 in the reveng catalogue: check = 0x4B, residue irrelevant. */
    const uint8_t msg[] = "123456789";

    uint8_t crc = rfs_can_crc8(msg, 9);

    assert_int_equal(crc, 0x4B);
}

static void table_and_bitwise_checksums_agree(void **state)
{
    (void)state;
    /* Every single-byte payload under two ids, and a walking pattern at every DLC. */
    for (unsigned v = 0; v < 256; v++) {
        uint8_t d[2] = {(uint8_t)v, 0};
        assert_int_equal(rfs_can_checksum(0x100, 2, d), rfs_can_checksum_bitwise(0x100, 2, d));
        assert_int_equal(rfs_can_checksum(0x7FF, 2, d), rfs_can_checksum_bitwise(0x7FF, 2, d));
    }
    uint8_t d[8] = {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF};
    for (uint8_t dlc = 1; dlc <= 8; dlc++) {
        assert_int_equal(rfs_can_checksum(0x120, dlc, d), rfs_can_checksum_bitwise(0x120, dlc, d));
    }
    /* An id-only frame (DLC 1) is the CRC of the two id bytes: 0x20 0x01 (Python reference). */
    assert_int_equal(rfs_can_checksum(0x120, 1, d), 0xD6);
}

static void wheel_bytes_match_python_reference(void **state)
{
    (void)state;
    rfs_can_wheel_t w = {-1000, 1000, RFS_CAN_WHEEL_STOP};
    const uint8_t want[] = {0x11, 0x18, 0xFC, 0xE8, 0x03, 0xD8};
    rfs_can_frame_t f;

    rfs_can_pack_wheel(&w, 1, &f);

    assert_int_equal(f.id, 0x100);
    assert_int_equal(f.dlc, 6);
    assert_memory_equal(f.data, want, 6);
    assert_int_equal(f.data[6], 0);
    assert_int_equal(f.data[7], 0);
}

static void pose_bytes_match_python_reference(void **state)
{
    (void)state;
    rfs_can_pose_t p = {1500, -2500, -12868, 0xFFFFFF00u};
    const uint8_t want_xy[] = {0x03, 0xDC, 0x05, 0x00, 0x3C, 0xF6, 0xFF, 0x5F};
    const uint8_t want_th[] = {0x03, 0xBC, 0xCD, 0x00, 0xFF, 0xFF, 0xFF, 0xB3};
    rfs_can_frame_t xy, th;

    rfs_can_pack_pose_xy(&p, 3, &xy);
    rfs_can_pack_pose_th(&p, 3, &th);

    assert_int_equal(xy.id, 0x110);
    assert_int_equal(th.id, 0x111);
    assert_memory_equal(xy.data, want_xy, 8);
    assert_memory_equal(th.data, want_th, 8);
}

static void rssi_and_status_bytes_match_python_reference(void **state)
{
    (void)state;
    rfs_can_rssi_t r = {1, -67, 200, 1000000u};
    rfs_can_status_t s = {3, 2, 2, true, false, 5, 300, false};
    const uint8_t want_r[] = {0x17, 0xBD, 0xC8, 0x40, 0x42, 0x0F, 0x00, 0x62};
    const uint8_t want_s[] = {0x32, 0x26, 0x05, 0x2C, 0x01, 0x00, 0x00, 0xD6};
    rfs_can_frame_t fr, fs;

    rfs_can_pack_rssi(&r, 7, &fr);
    rfs_can_pack_status(&s, 2, &fs);

    assert_memory_equal(fr.data, want_r, 8);
    assert_memory_equal(fs.data, want_s, 8);

    /* Configured is bit 15 (byte 1 bit 7); the checksum from the Python reference too. */
    const uint8_t want_c[] = {0x32, 0xA6, 0x05, 0x2C, 0x01, 0x00, 0x00, 0x76};
    s.configured = true;
    rfs_can_pack_status(&s, 2, &fs);
    assert_memory_equal(fs.data, want_c, 8);
}

static void wheel_every_speed_round_trips(void **state)
{
    (void)state;
    for (int32_t v = INT16_MIN; v <= INT16_MAX; v += 7) {
        rfs_can_wheel_t w = {(int16_t)v, (int16_t)(-1 - v), 0}, out;
        rfs_can_frame_t f;
        uint8_t c = 99;

        rfs_can_pack_wheel(&w, (uint8_t)v, &f);
        rfs_can_err_t e = rfs_can_unpack_wheel(&f, &out, &c);

        assert_int_equal(e, RFS_CAN_OK);
        assert_int_equal(out.left_mm_s, v);
        assert_int_equal(out.right_mm_s, -1 - v);
        assert_int_equal(c, (uint8_t)v & 0x0F);
        /* Little-endian: the low byte first. */
        assert_int_equal(f.data[1], (uint8_t)((uint32_t)v & 0xFF));
        assert_int_equal(f.data[2], (uint8_t)(((uint32_t)v >> 8) & 0xFF));
    }
}

static void pose_extremes_round_trip_and_saturate(void **state)
{
    (void)state;
    const int32_t xs[] = {RFS_CAN_POS_MM_MIN, -1, 0, 1, RFS_CAN_POS_MM_MAX};
    const int16_t ths[] = {-25736, -1, 0, 1, 25736};
    for (unsigned i = 0; i < 5; i++) {
        rfs_can_pose_t p = {xs[i], xs[4 - i], ths[i], (uint32_t)i * 0x40000000u}, out;
        rfs_can_frame_t xy, th;
        uint8_t c1, c2;

        rfs_can_pack_pose_xy(&p, 5, &xy);
        rfs_can_pack_pose_th(&p, 5, &th);

        assert_int_equal(rfs_can_unpack_pose_xy(&xy, &out, &c1), RFS_CAN_OK);
        assert_int_equal(rfs_can_unpack_pose_th(&th, &out, &c2), RFS_CAN_OK);
        assert_int_equal(out.x_mm, xs[i]);
        assert_int_equal(out.y_mm, xs[4 - i]);
        assert_int_equal(out.theta_q13, ths[i]);
        assert_int_equal(out.t_us32, (uint32_t)i * 0x40000000u);
    }
    /* Out of the int24 range: saturated, not wrapped. */
    rfs_can_pose_t big = {20000000, -20000000, 0, 0}, out;
    rfs_can_frame_t f;
    uint8_t c;
    rfs_can_pack_pose_xy(&big, 0, &f);
    assert_int_equal(rfs_can_unpack_pose_xy(&f, &out, &c), RFS_CAN_OK);
    assert_int_equal(out.x_mm, 8388607);
    assert_int_equal(out.y_mm, -8388608);
}

static void rssi_and_status_every_field_value_round_trips(void **state)
{
    (void)state;
    for (int v = 0; v < 256; v++) {
        rfs_can_rssi_t r = {(uint8_t)(v & 15), (int8_t)(v - 128), (uint8_t)(255 - v), 0x9E3779B9u * (uint32_t)v}, ro;
        rfs_can_status_t s = {(uint8_t)(v & 3), (uint8_t)((v >> 2) & 3), (uint8_t)(v % 5), (v & 16) != 0,
                              (v & 32) != 0, (uint8_t)v, 0x01000193u * (uint32_t)v, (v & 64) != 0}, so;
        rfs_can_frame_t fr, fs;
        uint8_t c;

        rfs_can_pack_rssi(&r, (uint8_t)v, &fr);
        rfs_can_pack_status(&s, (uint8_t)v, &fs);

        assert_int_equal(rfs_can_unpack_rssi(&fr, &ro, &c), RFS_CAN_OK);
        assert_int_equal(ro.src, v & 15);
        assert_int_equal(ro.dbm, v - 128);
        assert_int_equal(ro.seq, 255 - v);
        assert_int_equal(ro.t_us32, 0x9E3779B9u * (uint32_t)v);
        assert_int_equal(rfs_can_unpack_status(&fs, &so, &c), RFS_CAN_OK);
        assert_int_equal(so.state, v & 3);
        assert_int_equal(so.kind, (v >> 2) & 3);
        assert_int_equal(so.prev, v % 5);
        assert_int_equal(so.relearned, (v & 16) != 0);
        assert_int_equal(so.line_search, (v & 32) != 0);
        assert_int_equal(so.faults, v);
        assert_int_equal(so.iteration, 0x01000193u * (uint32_t)v);
        assert_int_equal(so.configured, (v & 64) != 0);
    }
}

static void bad_dlc_is_rejected(void **state)
{
    (void)state;
    rfs_can_wheel_t w = {10, 20, 0}, out = {0, 0, 0};
    rfs_can_frame_t f;
    uint8_t c = 0;
    rfs_can_pack_wheel(&w, 0, &f);
    for (uint8_t dlc = 0; dlc <= 8; dlc++) {
        if (dlc == RFS_CAN_DLC_WHEEL_CMD) {
            continue;
        }
        rfs_can_frame_t g = f;
        g.dlc = dlc;

        rfs_can_err_t e = rfs_can_unpack_wheel(&g, &out, &c);

        assert_int_equal(e, RFS_CAN_E_DLC);
        assert_int_equal(out.left_mm_s, 0);
    }
    /* A DLC above 8 (a corrupt driver value) is rejected before any byte is read. */
    rfs_can_frame_t g = f;
    g.dlc = 200;
    assert_int_equal(rfs_can_unpack_wheel(&g, &out, &c), RFS_CAN_E_DLC);
}

static void every_single_bit_error_is_rejected(void **state)
{
    (void)state;
    rfs_can_rssi_t r = {2, -70, 9, 123456u}, out;
    rfs_can_frame_t f;
    uint8_t c;
    rfs_can_pack_rssi(&r, 4, &f);
    for (unsigned bit = 0; bit < 64; bit++) {
        rfs_can_frame_t g = f;
        g.data[bit / 8] ^= (uint8_t)(1u << (bit % 8));

        rfs_can_err_t e = rfs_can_unpack_rssi(&g, &out, &c);

        assert_int_equal(e, RFS_CAN_E_CHECKSUM);
    }
    /* The id is covered too: the same payload under another of our ids fails. */
    rfs_can_frame_t g = f;
    g.id = RFS_CAN_ID_POSE_XY;
    rfs_can_pose_t p;
    assert_int_equal(rfs_can_unpack_pose_xy(&g, &p, &c), RFS_CAN_E_CHECKSUM);
}

static void reserved_bits_and_enum_ranges_are_rejected(void **state)
{
    (void)state;
    /* STATUS with PrevGoal = 5 (undefined) but a valid checksum. */
    uint8_t d[8] = {0x00, 0x50, 0, 0, 0, 0, 0, 0};
    d[7] = rfs_can_checksum(RFS_CAN_ID_STATUS, 8, d);
    rfs_can_frame_t f = frame_of(RFS_CAN_ID_STATUS, d, 8);
    rfs_can_status_t s;
    uint8_t c;
    assert_int_equal(rfs_can_unpack_status(&f, &s, &c), RFS_CAN_E_RANGE);
    /* POSE_TH heading beyond pi. */
    uint8_t t[8] = {0x00, 0x89, 0x64, 0, 0, 0, 0, 0}; /* 25737 */
    t[7] = rfs_can_checksum(RFS_CAN_ID_POSE_TH, 8, t);
    f = frame_of(RFS_CAN_ID_POSE_TH, t, 8);
    rfs_can_pose_t p;
    assert_int_equal(rfs_can_unpack_pose_th(&f, &p, &c), RFS_CAN_E_RANGE);
    /* WHEEL_CMD with an undefined flag bit. */
    uint8_t w[6] = {0x20, 0, 0, 0, 0, 0};
    w[5] = rfs_can_checksum(RFS_CAN_ID_WHEEL_CMD, 6, w);
    f = frame_of(RFS_CAN_ID_WHEEL_CMD, w, 6);
    rfs_can_wheel_t wo;
    assert_int_equal(rfs_can_unpack_wheel(&f, &wo, &c), RFS_CAN_E_RANGE);
}

/* Expected unwrap by exhaustive search over the three candidates, in double-free int64. */
static int64_t unwrap_ref(int64_t ref, uint32_t raw)
{
    int64_t base = ref - (int64_t)((uint64_t)ref & 0xFFFFFFFFu) + raw;
    int64_t best = base;
    for (int k = -1; k <= 1; k++) {
        int64_t cand = base + (int64_t)k * 4294967296LL;
        int64_t d = cand - ref;
        if (d >= -2147483648LL && d < 2147483648LL) {
            best = cand;
        }
    }
    return best;
}

static void unwrap_time_handles_the_32_bit_wrap(void **state)
{
    (void)state;
    /* The receiver is just past a wrap (2^32 + 5 us); the sender stamped just before. */
    assert_int_equal(rfs_can_unwrap_time(4294967301LL, 0xFFFFFFF0u), 4294967280LL);
    /* The receiver is just before a wrap; the sender's time already wrapped. */
    assert_int_equal(rfs_can_unwrap_time(4294967280LL, 0x10u), 4294967312LL);
    /* Negative times (before the epoch) unwrap too. */
    assert_int_equal(rfs_can_unwrap_time(-10, 0xFFFFFFF6u), -10);
    assert_int_equal(rfs_can_unwrap_time(0, 0xFFFFFFFFu), -1);
    /* Half a period away is the boundary: [-2^31, 2^31). */
    assert_int_equal(rfs_can_unwrap_time(0, 0x80000000u), -2147483648LL);
    assert_int_equal(rfs_can_unwrap_time(0, 0x7FFFFFFFu), 2147483647LL);
    const int64_t refs[] = {0, 1, 4294967295LL, 4294967296LL, 123456789012345LL, -987654321098LL};
    for (unsigned i = 0; i < sizeof refs / sizeof refs[0]; i++) {
        for (int64_t d = -3000000000LL; d <= 3000000000LL; d += 99999989LL) {
            uint32_t raw = rfs_can_wrap_time(refs[i] + d);

            int64_t t = rfs_can_unwrap_time(refs[i], raw);

            assert_int_equal(t, unwrap_ref(refs[i], raw));
            assert_int_equal((uint32_t)(uint64_t)t, raw);
        }
    }
    /* Saturates at the int64 limits instead of overflowing. */
    assert_int_equal(rfs_can_unwrap_time(INT64_MAX, (uint32_t)(uint64_t)INT64_MAX + 100u), INT64_MAX);
}

static void unit_conversions_match_double_reference(void **state)
{
    (void)state;
    for (int32_t mm = RFS_CAN_POS_MM_MIN; mm <= RFS_CAN_POS_MM_MAX; mm += 997) {
        double want = round((double)mm * 65536.0 / 1000.0);

        assert_int_equal(rfs_can_mm_to_q16(mm), (int32_t)want);
    }
    for (int64_t q = -2147483648LL; q <= 2147483647LL; q += 65537 * 31) {
        double want = round((double)q * 1000.0 / 65536.0);
        if (want > 8388607.0) want = 8388607.0;
        if (want < -8388608.0) want = -8388608.0;

        assert_int_equal(rfs_can_q16_to_mm((rfs_q16_t)q), (int32_t)want);
    }
    /* Heading: pi in Q16.16 is 205887; in Q2.13, 25736 (floor(pi * 8192 + 0.5)). */
    assert_int_equal(rfs_can_q16_to_theta(205887), (int16_t)floor(M_PI * 8192.0 + 0.5));
    assert_int_equal(rfs_can_q16_to_theta(-205887), (int16_t)floor(-M_PI * 8192.0 + 0.5));
    assert_int_equal(rfs_can_theta_to_q16(25736), 205888);
    assert_int_equal(rfs_can_q16_to_theta(INT32_MAX), INT16_MAX);
}

static rfs_can_rx_t rx_fixture(void)
{
    rfs_can_rx_t rx;
    rfs_can_rx_cfg_t cfg = rfs_can_rx_cfg_default();
    assert_int_equal(rfs_can_rx_init(&rx, &cfg), 0);
    return rx;
}

static void rx_counts_jumps_and_rejects_repeats(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_msg_t m;
    rfs_can_wheel_t w = {1, 2, 0};
    rfs_can_frame_t f;
    /* 14, 15, 0 (wrap: no jump), 3 (jump over 1, 2), 3 again (duplicate). */
    const uint8_t seq[] = {14, 15, 0, 3, 3};
    const rfs_can_err_t want[] = {RFS_CAN_OK, RFS_CAN_OK, RFS_CAN_OK, RFS_CAN_OK, RFS_CAN_E_REPEAT};
    for (unsigned i = 0; i < 5; i++) {
        rfs_can_pack_wheel(&w, seq[i], &f);

        rfs_can_err_t e = rfs_can_rx_frame(&rx, &f, 0, &m);

        assert_int_equal(e, want[i]);
        assert_int_equal(m.kind, e == RFS_CAN_OK ? RFS_CAN_MSG_WHEEL : RFS_CAN_MSG_NONE);
    }
    assert_int_equal(rx.msg[RFS_CAN_IDX_WHEEL_CMD].accepted, 4);
    assert_int_equal(rx.msg[RFS_CAN_IDX_WHEEL_CMD].counter_jumps, 1);
    assert_int_equal(rx.msg[RFS_CAN_IDX_WHEEL_CMD].lost, 2);
    assert_int_equal(rx.dropped[RFS_CAN_E_REPEAT], 1);
    assert_int_equal(rfs_can_rx_dropped_total(&rx), 1);
}

static void rx_pairs_pose_halves_into_core_units(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_can_msg_t m;
    const int64_t now = 5000000000LL; /* 5000 s: beyond the 32-bit wrap at 4295 s */
    rfs_pose_t core = {now - 20000, 98304 /* 1.5 m */, -163840 /* -2.5 m */, 102944 /* ~pi/2 */};
    rfs_can_pose_t p = rfs_can_pose_from_core(&core);
    rfs_can_frame_t xy, th;
    rfs_can_tx_pose(&tx, &p, &xy, &th);

    rfs_can_err_t e1 = rfs_can_rx_frame(&rx, &xy, now, &m);
    rfs_can_msg_kind_t k1 = m.kind;
    rfs_can_err_t e2 = rfs_can_rx_frame(&rx, &th, now, &m);

    assert_int_equal(e1, RFS_CAN_OK);
    assert_int_equal(k1, RFS_CAN_MSG_NONE);
    assert_int_equal(e2, RFS_CAN_OK);
    assert_int_equal(m.kind, RFS_CAN_MSG_POSE);
    assert_int_equal(m.pose.t_us, now - 20000);
    assert_int_equal(m.pose.x, 98304);
    assert_int_equal(m.pose.y, -163840);
    /* 102944 / 8 = 12868 exactly, back to 102944. */
    assert_int_equal(m.pose.theta, 102944);
    assert_int_equal(xy.data[0] & 0x0F, th.data[0] & 0x0F);
}

static void rx_rejects_unpaired_pose_halves(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_msg_t m;
    rfs_can_pose_t p = {100, 200, 0, 1000};
    rfs_can_frame_t xy, th;
    rfs_can_pack_pose_xy(&p, 1, &xy);
    rfs_can_pack_pose_th(&p, 2, &th);

    rfs_can_err_t e_alone = rfs_can_rx_frame(&rx, &th, 1000, &m);
    (void)rfs_can_rx_frame(&rx, &xy, 1000, &m);
    rfs_can_pack_pose_th(&p, 3, &th);
    rfs_can_err_t e_mismatch = rfs_can_rx_frame(&rx, &th, 1000, &m);

    assert_int_equal(e_alone, RFS_CAN_E_PAIR);
    assert_int_equal(e_mismatch, RFS_CAN_E_PAIR);
    assert_int_equal(m.kind, RFS_CAN_MSG_NONE);
    assert_int_equal(rx.dropped[RFS_CAN_E_PAIR], 2);
}

static void rx_drops_stale_future_and_out_of_order_times(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_msg_t m;
    rfs_can_frame_t f;
    const int64_t now = 10000000;
    rfs_can_rssi_t r = {0, -60, 0, rfs_can_wrap_time(now - 500000)};
    rfs_can_pack_rssi(&r, 0, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, now - 500000);

    r.t_us32 = rfs_can_wrap_time(now - 600000); /* older than the newest of source 0 */
    rfs_can_pack_rssi(&r, 1, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_ORDER);
    r.t_us32 = rfs_can_wrap_time(now - 1000001); /* beyond max_age */
    rfs_can_pack_rssi(&r, 2, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_STALE);
    r.t_us32 = rfs_can_wrap_time(now + 100001); /* beyond max_future */
    rfs_can_pack_rssi(&r, 3, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_FUTURE);
    /* Another source has its own order. */
    r.src = 1;
    r.t_us32 = rfs_can_wrap_time(now - 600000);
    rfs_can_pack_rssi(&r, 4, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_src, 1);
    /* The window's edges are inside it: only older than max_age, later than max_future drop. */
    r.src = 2;
    r.t_us32 = rfs_can_wrap_time(now - 1000000);
    rfs_can_pack_rssi(&r, 5, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    r.src = 3;
    r.t_us32 = rfs_can_wrap_time(now + 100000);
    rfs_can_pack_rssi(&r, 6, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, now + 100000);
    assert_int_equal(rx.dropped[RFS_CAN_E_ORDER], 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_STALE], 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_FUTURE], 1);
}

static void rx_counts_unknown_ids_short_frames_and_seq_gaps(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_msg_t m;
    const uint8_t d[8] = {0};
    rfs_can_frame_t unknown = frame_of(0x7FF, d, 8);
    rfs_can_frame_t ext = frame_of(0x12345678u, d, 8);
    rfs_can_frame_t shortf = frame_of(RFS_CAN_ID_RSSI, d, 3);

    assert_int_equal(rfs_can_rx_frame(&rx, &unknown, 0, &m), RFS_CAN_E_ID);
    assert_int_equal(rfs_can_rx_frame(&rx, &ext, 0, &m), RFS_CAN_E_ID);
    assert_int_equal(rfs_can_rx_frame(&rx, &shortf, 0, &m), RFS_CAN_E_DLC);

    rfs_can_rssi_t r = {3, -50, 250, 0};
    rfs_can_frame_t f;
    rfs_can_pack_rssi(&r, 0, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, 0, &m), RFS_CAN_OK);
    r.seq = 4; /* 251..255, 0..3 missing: 9 packets, across the 8-bit wrap */
    rfs_can_pack_rssi(&r, 1, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, 0, &m), RFS_CAN_OK);
    assert_int_equal(rx.rssi_seq_gaps, 9);
    assert_int_equal(rx.dropped[RFS_CAN_E_ID], 2);
    assert_int_equal(rx.dropped[RFS_CAN_E_DLC], 1);
    assert_string_equal(rfs_can_err_str(RFS_CAN_E_CHECKSUM), "checksum");
}

static void random_frames_are_all_accounted_for(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 4);
    const uint32_t ids[] = {0x100, 0x110, 0x111, 0x120, 0x180, 0x7FF, 0x12345678u};
    uint32_t ok = 0, none = 0, errs[RFS_CAN_NERR] = {0};
    const uint32_t n = 200000;
    for (uint32_t i = 0; i < n; i++) {
        rfs_can_frame_t f;
        f.id = ids[rfs_rng_below(&rng, 7)];
        f.dlc = (uint8_t)rfs_rng_below(&rng, 10); /* 9 is an invalid DLC */
        for (int b = 0; b < 8; b++) {
            f.data[b] = (uint8_t)rfs_rng_u32(&rng);
        }
        /* Half the frames get a valid checksum so the later checks run too. */
        if (f.dlc >= 1 && f.dlc <= 8 && (i & 1)) {
            f.data[f.dlc - 1] = rfs_can_checksum(f.id, f.dlc, f.data);
        }
        rfs_can_msg_t m;
        int64_t now = (int64_t)rfs_rng_u32(&rng) * 1000;

        rfs_can_err_t e = rfs_can_rx_frame(&rx, &f, now, &m);

        if (e == RFS_CAN_OK) {
            ok++;
            none += m.kind == RFS_CAN_MSG_NONE;
        } else {
            errs[e]++;
            assert_int_equal(m.kind, RFS_CAN_MSG_NONE);
        }
    }
    uint32_t accepted = 0;
    for (unsigned i = 0; i < RFS_CAN_NMSG; i++) {
        accepted += rx.msg[i].accepted;
    }
    /* Every frame is either accepted (counted per id) or dropped (counted per reason).
     * An XY half replaced by the next before its TH half is one more PAIR count on a
     * frame that was itself accepted. */
    assert_int_equal(accepted, ok);
    for (unsigned e = 1; e < RFS_CAN_NERR; e++) {
        if (e == RFS_CAN_E_PAIR) {
            assert_true(rx.dropped[e] >= errs[e]);
        } else {
            assert_int_equal(rx.dropped[e], errs[e]);
        }
    }
    assert_int_equal(errs[RFS_CAN_OK], 0);
    assert_true(ok > 100);
    assert_true(errs[RFS_CAN_E_CHECKSUM] > 1000 && errs[RFS_CAN_E_DLC] > 1000 && errs[RFS_CAN_E_ID] > 1000);
    assert_true(none > 0);
}

static void rx_init_validates_config(void **state)
{
    (void)state;
    rfs_can_rx_t rx;
    rfs_can_rx_cfg_t cfg = rfs_can_rx_cfg_default();
    assert_int_equal(cfg.max_age_us, 1000000);
    assert_int_equal(cfg.max_future_us, 100000);
    cfg.max_age_us = 0;
    assert_int_equal(rfs_can_rx_init(&rx, &cfg), -1);
    cfg = rfs_can_rx_cfg_default();
    cfg.max_future_us = -1;
    assert_int_equal(rfs_can_rx_init(&rx, &cfg), -1);
    cfg.max_future_us = 3600000001LL;
    assert_int_equal(rfs_can_rx_init(&rx, &cfg), -1);
}

static void seek_output_maps_to_status_and_wheels(void **state)
{
    (void)state;
    rfs_seek_out_t out;
    memset(&out, 0, sizeof out);
    out.left_mm_s = -300;
    out.right_mm_s = 450;
    out.state = RFS_SEEK_DRIVING;
    out.faults = RFS_SEEK_FAULT_NO_GOAL;
    out.decision.iteration = 42;
    out.decision.kind = RFS_SEEK_EPSILON;
    out.decision.prev = RFS_DRIVE_BLOCKED;
    out.decision.relearned = true;
    rfs_can_status_t s;
    rfs_can_wheel_t w;
    memset(&s, 0x5A, sizeof s); /* every field must be written (UBSan: bools read unset) */
    memset(&w, 0x5A, sizeof w);

    rfs_can_from_seek_out(&out, &s, &w);

    assert_int_equal(s.state, 3);
    assert_int_equal(s.kind, 3);
    assert_int_equal(s.prev, 4);
    assert_true(s.relearned);
    assert_false(s.line_search);
    assert_int_equal(s.faults, 4);
    assert_int_equal(s.iteration, 42);
    assert_false(s.configured);
    assert_int_equal(w.left_mm_s, -300);
    assert_int_equal(w.right_mm_s, 450);
    assert_int_equal(w.flags, 0);
    out.state = RFS_SEEK_STALE;
    rfs_can_from_seek_out(&out, &s, &w);
    assert_int_equal(w.flags, RFS_CAN_WHEEL_STOP);
    /* The baselines' kinds in the 2-bit field (docs/CAN.md, "0x180 STATUS"): probe 4 and
     * tumble 7 explore (3, epsilon), gradient 5 and run 6 are directed (2, greedy). */
    const struct { rfs_seek_kind_t k; uint8_t want; } map[] = {
        {RFS_SEEK_NONE, 0}, {RFS_SEEK_INITIAL, 1}, {RFS_SEEK_GREEDY, 2}, {RFS_SEEK_EPSILON, 3},
        {RFS_SEEK_PROBE, 3}, {RFS_SEEK_GRADIENT, 2}, {RFS_SEEK_RUN, 2}, {RFS_SEEK_TUMBLE, 3},
    };
    s.configured = false; /* the application's, not the output's */
    for (unsigned i = 0; i < sizeof map / sizeof map[0]; i++) {
        out.decision.kind = map[i].k;
        rfs_can_from_seek_out(&out, &s, &w);
        assert_int_equal(s.kind, map[i].want);
        rfs_can_frame_t f;
        rfs_can_pack_status(&s, 0, &f);
        assert_int_equal(f.data[1] & 0x3u, map[i].want);
    }
}

/* RX_STATUS (0x121, docs/CAN.md): bytes from the Python reference (struct '<BI' + CRC-8 over
 * 21 01 and the payload), every time value round trips, a wrong DLC, any flipped bit and
 * the reserved nibble are rejected. */
static void receiver_frame_bytes_round_trip_and_rejects(void **state)
{
    (void)state;
    const uint8_t want[] = {0x03, 0x00, 0xFF, 0xFF, 0xFF, 0x4B};
    const uint8_t want2[] = {0x0A, 0x15, 0xCD, 0x5B, 0x07, 0x8D};
    rfs_can_receiver_t r = {0xFFFFFF00u}, out = {0};
    rfs_can_frame_t f, g;
    uint8_t c = 99;

    rfs_can_pack_receiver(&r, 3, &f);
    r.t_us32 = 123456789u;
    rfs_can_pack_receiver(&r, 0x1A, &g); /* only the counter's low 4 bits are used */

    assert_int_equal(f.id, 0x121);
    assert_int_equal(f.dlc, 6);
    assert_memory_equal(f.data, want, 6);
    assert_int_equal(f.data[6], 0);
    assert_int_equal(f.data[7], 0);
    assert_memory_equal(g.data, want2, 6);
    assert_int_equal(rfs_can_unpack_receiver(&f, &out, &c), RFS_CAN_OK);
    assert_int_equal(out.t_us32, 0xFFFFFF00u);
    assert_int_equal(c, 3);
    const uint32_t ts[] = {0u, 1u, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu};
    for (unsigned i = 0; i < 5u; i++) {
        rfs_can_receiver_t a = {ts[i]}, b = {0};
        rfs_can_pack_receiver(&a, (uint8_t)i, &g);
        assert_int_equal(rfs_can_unpack_receiver(&g, &b, &c), RFS_CAN_OK);
        assert_int_equal(b.t_us32, ts[i]);
        assert_int_equal(c, i);
    }
    for (uint8_t dlc = 0; dlc <= 8; dlc++) {
        g = f;
        g.dlc = dlc;
        out.t_us32 = 0;
        assert_int_equal(rfs_can_unpack_receiver(&g, &out, &c),
                         dlc == 6 ? RFS_CAN_OK : RFS_CAN_E_DLC);
        assert_int_equal(out.t_us32, dlc == 6 ? 0xFFFFFF00u : 0u);
    }
    for (unsigned bit = 0; bit < 48u; bit++) {
        g = f;
        g.data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_equal(rfs_can_unpack_receiver(&g, &out, &c), RFS_CAN_E_CHECKSUM);
    }
    g = f;
    g.id = RFS_CAN_ID_RSSI; /* a copy under another id fails its checksum there */
    assert_int_equal(rfs_can_unpack_receiver(&g, &out, &c), RFS_CAN_E_ID);
    g.dlc = 8;
    assert_int_equal(rfs_can_unpack_rssi(&g, &(rfs_can_rssi_t){0}, &c), RFS_CAN_E_CHECKSUM);
    g = f;
    g.data[0] |= 0x10u; /* reserved nibble set: re-seal so only the range check fails */
    g.data[5] = rfs_can_checksum(g.id, g.dlc, g.data);
    assert_int_equal(rfs_can_unpack_receiver(&g, &out, &c), RFS_CAN_E_RANGE);
}

/* CONFIG FitEarly (bits 6..7 of data[0], docs/CAN.md): bytes worked out by hand from the
 * layout (counter | target << 4 | fit_early << 6) with the CRC-8 from the Python reference
 * (poly 0x1D over 30 01 and the payload); 0 is the frame without the field; every value
 * round trips; 3 is refused and counted by the receiver. */
static void config_fit_early_bits(void **state)
{
    (void)state;
    /* meta-path, pathloss, -40 dBm, seed 0x123456, counter 5, on: 0x05 | 2 << 6 = 0x85. */
    const uint8_t on[] = {0x85, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12, 0xD8};
    /* bridge, meta, ridge, no floor, seed 0xFFFFFF, counter 15, off: 0x1F | 1 << 6 = 0x5F. */
    const uint8_t off[] = {0x5F, 0x00, 0x00, 0x80, 0xFF, 0xFF, 0xFF, 0x84};
    /* on's frame with FitEarly 3 (0xC5), sealed. */
    const uint8_t reserved[] = {0xC5, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12, 0x06};
    rfs_can_config_t a = {.target = 0, .strategy = 5, .model = RFS_CAN_MODEL_PATHLOSS, .p0_min = -5120,
                          .seed = 0x123456u, .fit_early = RFS_CAN_FIT_EARLY_ON};
    rfs_can_config_t b = {.target = 1, .strategy = 0, .model = RFS_CAN_MODEL_RIDGE,
                          .p0_min = RFS_CAN_P0_NONE, .seed = 0xFFFFFFu, .fit_early = RFS_CAN_FIT_EARLY_OFF};
    rfs_can_config_t out;
    rfs_can_frame_t f, g;
    uint8_t c = 99;

    rfs_can_pack_config(&a, 5, &f);
    rfs_can_pack_config(&b, 15, &g);

    assert_memory_equal(f.data, on, 8);
    assert_memory_equal(g.data, off, 8);
    assert_int_equal(rfs_can_unpack_config(&f, &out, &c), RFS_CAN_OK);
    assert_int_equal(out.fit_early, RFS_CAN_FIT_EARLY_ON);
    assert_int_equal(out.target, 0);
    assert_int_equal(out.strategy, 5);
    assert_int_equal(c, 5);
    assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_OK);
    assert_int_equal(out.fit_early, RFS_CAN_FIT_EARLY_OFF);
    assert_int_equal(out.target, 1);
    assert_int_equal(out.seed, 0xFFFFFFu);
    /* Round trip of every value with every target. */
    for (uint8_t fe = 0; fe <= (uint8_t)RFS_CAN_FIT_EARLY_ON; fe++) {
        for (uint8_t t = 0; t <= 1u; t++) {
            rfs_can_config_t x = {.target = t, .strategy = 5, .model = RFS_CAN_MODEL_KNN, .p0_min = 0,
                                  .seed = 42u, .fit_early = fe};
            rfs_can_pack_config(&x, fe, &g);
            memset(&out, 0xA5, sizeof out);
            assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_OK);
            assert_int_equal(out.fit_early, fe);
            assert_int_equal(out.target, t);
            assert_int_equal(out.model, RFS_CAN_MODEL_KNN);
        }
    }
    /* The reserved value: refused, outputs untouched; the receiver drops and counts it. */
    memcpy(g.data, reserved, 8);
    assert_int_equal(g.data[7], rfs_can_checksum(g.id, g.dlc, g.data));
    memset(&out, 0, sizeof out);
    c = 99;
    assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_E_RANGE);
    assert_int_equal(c, 99);
    assert_int_equal(out.fit_early, 0);
    rfs_can_rx_t rx;
    const rfs_can_rx_cfg_t rc = rfs_can_rx_cfg_default();
    assert_int_equal(rfs_can_rx_init(&rx, &rc), 0);
    rfs_can_msg_t m;
    assert_int_equal(rfs_can_rx_frame(&rx, &g, 0, &m), RFS_CAN_E_RANGE);
    assert_int_equal(m.kind, RFS_CAN_MSG_NONE);
    assert_int_equal(rx.dropped[RFS_CAN_E_RANGE], 1u);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, 0, &m), RFS_CAN_OK);
    assert_int_equal(m.kind, RFS_CAN_MSG_CONFIG);
    assert_int_equal(m.config.fit_early, RFS_CAN_FIT_EARLY_ON);
}

/* CONFIG (0x130, docs/CAN.md): bytes from the Python reference (bit fields, struct '<h' for
 * P0Min, the seed's three low bytes, CRC-8 over 30 01 and the payload); every field's
 * limits; values outside them, reserved bits, a wrong DLC and flipped bits rejected; the
 * receiver takes it with a counter check and no time window. */
static void config_frame_bytes_ranges_and_receiver(void **state)
{
    (void)state;
    /* meta-path (5), pathloss (4), -40 dBm (-5120), seed 0x123456, counter 5. */
    const uint8_t want[] = {0x05, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12, 0x79};
    /* bridge, meta, ridge, no floor, seed 0xFFFFFF (0x1FFFFFF masked), counter 15. */
    const uint8_t want2[] = {0x1F, 0x00, 0x00, 0x80, 0xFF, 0xFF, 0xFF, 0x5A};
    rfs_can_config_t a = {.target = 0, .strategy = 5, .model = RFS_CAN_MODEL_PATHLOSS, .p0_min = -5120,
                          .seed = 0x123456u};
    rfs_can_config_t b = {.target = 1, .strategy = 0, .model = RFS_CAN_MODEL_RIDGE,
                          .p0_min = RFS_CAN_P0_NONE, .seed = 0x1FFFFFFu};
    rfs_can_config_t out;
    rfs_can_frame_t f, g;
    uint8_t c = 99;

    rfs_can_pack_config(&a, 5, &f);
    rfs_can_pack_config(&b, 0x1F, &g);

    assert_int_equal(f.id, 0x130);
    assert_int_equal(f.dlc, 8);
    assert_memory_equal(f.data, want, 8);
    assert_memory_equal(g.data, want2, 8);
    assert_int_equal(rfs_can_unpack_config(&f, &out, &c), RFS_CAN_OK);
    assert_int_equal(c, 5);
    assert_int_equal(out.strategy, 5);
    assert_int_equal(out.model, RFS_CAN_MODEL_PATHLOSS);
    assert_int_equal(out.p0_min, -5120);
    assert_int_equal(out.seed, 0x123456u);
    assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_OK);
    assert_int_equal(out.target, 1);
    assert_int_equal(out.p0_min, RFS_CAN_P0_NONE);
    assert_int_equal(out.seed, 0xFFFFFFu);
    /* -40 dBm in Q16.16 is -40 * 65536; no floor is INT32_MIN; the limits -200, 100 dBm. */
    assert_int_equal(rfs_can_p0_to_q16(-5120), -40 * 65536);
    assert_int_equal(rfs_can_p0_to_q16(RFS_CAN_P0_NONE), INT32_MIN);
    assert_int_equal(rfs_can_p0_to_q16(RFS_CAN_P0_MIN), -200 * 65536);
    assert_int_equal(rfs_can_p0_to_q16(RFS_CAN_P0_MAX), 100 * 65536);
    /* Each field at and past its limit (re-sealed: only the range check may fail). */
    const struct {
        uint8_t target, strategy, model;
        int16_t p0;
        rfs_can_err_t want;
    } cases[] = {
        {1, 0, 0, 0, RFS_CAN_OK},           {2, 0, 0, 0, RFS_CAN_E_RANGE},
        {0, 5, 0, 0, RFS_CAN_OK},           {0, 6, 0, 0, RFS_CAN_E_RANGE},
        {0, 15, 0, 0, RFS_CAN_E_RANGE},     {0, 0, 4, 0, RFS_CAN_OK},
        {0, 0, 5, 0, RFS_CAN_E_RANGE},      {0, 0, 0, -25600, RFS_CAN_OK},
        {0, 0, 0, -25601, RFS_CAN_E_RANGE}, {0, 0, 0, 12800, RFS_CAN_OK},
        {0, 0, 0, 12801, RFS_CAN_E_RANGE},  {0, 0, 0, -32767, RFS_CAN_E_RANGE},
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        rfs_can_config_t x = {cases[i].target, cases[i].strategy, cases[i].model, cases[i].p0, 7u,
                              RFS_CAN_FIT_EARLY_KEEP};
        rfs_can_pack_config(&x, 1, &g);
        assert_int_equal(rfs_can_unpack_config(&g, &out, &c), cases[i].want);
    }
    g = f;
    g.data[0] |= 0xC0u; /* FitEarly 3, reserved */
    g.data[7] = rfs_can_checksum(g.id, g.dlc, g.data);
    assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_E_RANGE);
    g = f;
    g.dlc = 7;
    assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_E_DLC);
    for (unsigned bit = 0; bit < 64u; bit++) {
        g = f;
        g.data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_equal(rfs_can_unpack_config(&g, &out, &c), RFS_CAN_E_CHECKSUM);
    }
    /* The receiver: accepted whatever the time, a repeated counter is a duplicate. */
    rfs_can_rx_t rx;
    const rfs_can_rx_cfg_t rc = rfs_can_rx_cfg_default();
    assert_int_equal(rfs_can_rx_init(&rx, &rc), 0);
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_can_msg_t m;
    rfs_can_tx_config(&tx, &a, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, (int64_t)1 << 40, &m), RFS_CAN_OK);
    assert_int_equal(m.kind, RFS_CAN_MSG_CONFIG);
    assert_int_equal(m.config.seed, 0x123456u);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, 0, &m), RFS_CAN_E_REPEAT);
    assert_int_equal(m.kind, RFS_CAN_MSG_NONE);
    assert_int_equal(rx.msg[RFS_CAN_IDX_CONFIG].accepted, 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_REPEAT], 1);
    /* The model codes name the registry's models (rfs_models.h). */
    assert_string_equal(rfs_can_model_name(RFS_CAN_MODEL_RIDGE), "ridge");
    assert_string_equal(rfs_can_model_name(RFS_CAN_MODEL_PATHLOSS), "pathloss");
    assert_null(rfs_can_model_name(RFS_CAN_NMODELS));
}

static void rx_receiver_unwraps_and_applies_the_packet_time_window(void **state)
{
    (void)state;
    rfs_can_rx_t rx = rx_fixture();
    rfs_can_msg_t m;
    rfs_can_frame_t f;
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    /* now is just past a 2^32 us wrap of the low 32 bits. */
    const int64_t now = ((int64_t)1 << 32) + 1000;
    rfs_can_receiver_t r = {0xFFFFFFF0u}; /* 1,016 us before now, across the wrap */
    rfs_can_tx_receiver(&tx, &r, &f);

    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    assert_int_equal(m.kind, RFS_CAN_MSG_RECEIVER);
    assert_true(m.receiver_t_us == ((int64_t)1 << 32) - 16);

    r.t_us32 = rfs_can_wrap_time(now - 2000); /* older than the newest heartbeat */
    rfs_can_tx_receiver(&tx, &r, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_ORDER);
    assert_int_equal(m.kind, RFS_CAN_MSG_NONE);
    r.t_us32 = rfs_can_wrap_time(now - 1000001);
    rfs_can_tx_receiver(&tx, &r, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_STALE);
    r.t_us32 = rfs_can_wrap_time(now + 100001);
    rfs_can_tx_receiver(&tx, &r, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_E_FUTURE);
    /* A packet stamped later does not order the heartbeat stream (its own stream). */
    rfs_can_rssi_t p = {0, -60, 0, rfs_can_wrap_time(now + 50000)};
    rfs_can_tx_rssi(&tx, &p, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    r.t_us32 = rfs_can_wrap_time(now);
    rfs_can_tx_receiver(&tx, &r, &f);
    assert_int_equal(rfs_can_rx_frame(&rx, &f, now, &m), RFS_CAN_OK);
    assert_true(m.receiver_t_us == now);
    rfs_can_frame_t dup = f; /* the same counter again: a duplicate */
    assert_int_equal(rfs_can_rx_frame(&rx, &dup, now, &m), RFS_CAN_E_REPEAT);
    assert_int_equal(rx.msg[RFS_CAN_IDX_RX_STATUS].accepted, 2);
    assert_int_equal(rx.msg[RFS_CAN_IDX_RX_STATUS].lost, 3); /* counters 1..3 were dropped */
    assert_int_equal(rx.dropped[RFS_CAN_E_ORDER], 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_STALE], 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_FUTURE], 1);
    assert_int_equal(rx.dropped[RFS_CAN_E_REPEAT], 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(crc8_matches_catalogue_check_value),
        cmocka_unit_test(table_and_bitwise_checksums_agree),
        cmocka_unit_test(wheel_bytes_match_python_reference),
        cmocka_unit_test(pose_bytes_match_python_reference),
        cmocka_unit_test(rssi_and_status_bytes_match_python_reference),
        cmocka_unit_test(wheel_every_speed_round_trips),
        cmocka_unit_test(pose_extremes_round_trip_and_saturate),
        cmocka_unit_test(rssi_and_status_every_field_value_round_trips),
        cmocka_unit_test(bad_dlc_is_rejected),
        cmocka_unit_test(every_single_bit_error_is_rejected),
        cmocka_unit_test(reserved_bits_and_enum_ranges_are_rejected),
        cmocka_unit_test(unwrap_time_handles_the_32_bit_wrap),
        cmocka_unit_test(unit_conversions_match_double_reference),
        cmocka_unit_test(rx_counts_jumps_and_rejects_repeats),
        cmocka_unit_test(rx_pairs_pose_halves_into_core_units),
        cmocka_unit_test(rx_rejects_unpaired_pose_halves),
        cmocka_unit_test(rx_drops_stale_future_and_out_of_order_times),
        cmocka_unit_test(rx_counts_unknown_ids_short_frames_and_seq_gaps),
        cmocka_unit_test(random_frames_are_all_accounted_for),
        cmocka_unit_test(rx_init_validates_config),
        cmocka_unit_test(seek_output_maps_to_status_and_wheels),
        cmocka_unit_test(receiver_frame_bytes_round_trip_and_rejects),
        cmocka_unit_test(rx_receiver_unwraps_and_applies_the_packet_time_window),
        cmocka_unit_test(config_frame_bytes_ranges_and_receiver),
        cmocka_unit_test(config_fit_early_bits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
