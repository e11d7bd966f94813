/* test_lx_radiotap.c - the radiotap and 802.11 header parser.
 *
 * Expected values come from the bytes each test lays down by hand (offsets worked out
 * from the radiotap alignment rules in the comments) and, for the two real captures,
 * from tshark 4.0.17 (`-T fields -e radiotap.length -e radiotap.dbm_antsignal ...`).
 */
#include "rfs_test.h"

#include <stdio.h>
#include <string.h>

#include "lx_radiotap.h"

/* Little-endian writers for building headers. */
static void put16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static void put32(uint8_t *p, uint32_t v) { put16(p, (uint16_t)v); put16(p + 2, (uint16_t)(v >> 16)); }
static void put64(uint8_t *p, uint64_t v) { put32(p, (uint32_t)v); put32(p + 4, (uint32_t)(v >> 32)); }

static const uint8_t k_a[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0x0a};
static const uint8_t k_b[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0x0b};
static const uint8_t k_c[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0x0c};
static const uint8_t k_d[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0x0d};

static void test_minimal_header_has_no_fields(void **state)
{
    (void)state;
    uint8_t b[8] = {0, 0, 8, 0, 0, 0, 0, 0};
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);

    assert_int_equal(rt.status, LX_RT_OK);
    assert_int_equal(rt.it_len, 8);
    assert_int_equal(rt.n_present, 1);
    assert_false(rt.has_tsft);
    assert_false(rt.has_dbm_signal);
}

/* Two present words (default namespace continues, nothing set in the second), so the
 * fields start at 12: TSFT aligns to 16, flags 24, rate 25, channel aligns to 26,
 * signal 30, noise 31, antenna 32, MCS 33..35. it_len 36. */
static size_t build_aligned(uint8_t *b)
{
    memset(b, 0xee, 64);
    b[0] = 0;
    b[1] = 0;
    put16(b + 2, 36);
    put32(b + 4, (1u << 31) | (1u << 0) | (1u << 1) | (1u << 2) | (1u << 3) | (1u << 5) | (1u << 6) |
                     (1u << 11) | (1u << 19));
    put32(b + 8, 0);
    put64(b + 16, 0x0123456789abcdefull);
    b[24] = LX_RT_FLAG_FCS;
    b[25] = 108;
    put16(b + 26, 5180);
    put16(b + 28, 0x0140);
    b[30] = (uint8_t)-57;
    b[31] = (uint8_t)-92;
    b[32] = 2;
    b[33] = 0x07;
    b[34] = 0x01;
    b[35] = 7;
    return 36;
}

static void test_fields_aligned_to_header_start(void **state)
{
    (void)state;
    uint8_t b[64];
    const size_t n = build_aligned(b);
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, n, &rt), 0);

    assert_int_equal(rt.status, LX_RT_OK);
    assert_int_equal(rt.n_present, 2);
    assert_true(rt.has_tsft);
    assert_true(rt.tsft_us == 0x0123456789abcdefull);
    assert_int_equal(rt.flags, LX_RT_FLAG_FCS);
    assert_int_equal(rt.rate_500k, 108);
    assert_int_equal(rt.freq_mhz, 5180);
    assert_int_equal(rt.chan_flags, 0x0140);
    assert_int_equal(rt.dbm_signal, -57);
    assert_int_equal(rt.n_dbm_signal, 1);
    assert_int_equal(rt.dbm_noise, -92);
    assert_int_equal(rt.antenna, 2);
    assert_true(rt.has_mcs);
    assert_int_equal(rt.mcs_known, 0x07);
    assert_int_equal(rt.mcs_flags, 0x01);
    assert_int_equal(rt.mcs_index, 7);
}

/* Alignment is relative to the header, not to memory: the same header one byte into a
 * buffer reads the same values. */
static void test_alignment_independent_of_buffer_address(void **state)
{
    (void)state;
    uint8_t tmp[64];
    uint8_t b[80];
    const size_t n = build_aligned(tmp);
    memcpy(b + 1, tmp, n);
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b + 1, n, &rt), 0);

    assert_true(rt.tsft_us == 0x0123456789abcdefull);
    assert_int_equal(rt.freq_mhz, 5180);
    assert_int_equal(rt.dbm_signal, -57);
}

/* mac80211 per-chain layout: word 0 flags + signal + restart, word 1 signal + antenna +
 * restart, word 2 signal + antenna. Fields at 16: flags 16, signal 17 (combined), then
 * chain 0: signal 18, antenna 19; chain 1: signal 20, antenna 21. */
static void test_per_chain_reports_combined_signal(void **state)
{
    (void)state;
    uint8_t b[22] = {0};
    put16(b + 2, 22);
    put32(b + 4, (1u << 31) | (1u << 29) | (1u << 1) | (1u << 5));
    put32(b + 8, (1u << 31) | (1u << 29) | (1u << 5) | (1u << 11));
    put32(b + 12, (1u << 5) | (1u << 11));
    b[16] = 0;
    b[17] = (uint8_t)-40;
    b[18] = (uint8_t)-45;
    b[19] = 0;
    b[20] = (uint8_t)-38;
    b[21] = 1;
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);

    assert_int_equal(rt.status, LX_RT_OK);
    assert_int_equal(rt.dbm_signal, -40);
    assert_int_equal(rt.n_dbm_signal, 3);
    assert_int_equal(rt.antenna, 0);
}

/* Word 0: TSFT + vendor namespace; word 1 (vendor, its bits are inside the skipped data)
 * + restart; word 2: signal + channel. Fields at 16: TSFT 16..23, vendor header aligned
 * at 24: OUI 00:13:74, sub 0, skip_length 5, data 30..34; channel aligns 35 -> 36,
 * signal 40 (channel is bit 3, signal bit 5). it_len 41. */
static void test_vendor_namespace_skipped_by_length(void **state)
{
    (void)state;
    uint8_t b[41];
    memset(b, 0xcc, sizeof(b));
    b[0] = 0;
    b[1] = 0;
    put16(b + 2, 41);
    put32(b + 4, (1u << 31) | (1u << 30) | (1u << 0));
    put32(b + 8, (1u << 31) | (1u << 29) | 0x0000ffffu);
    put32(b + 12, (1u << 3) | (1u << 5));
    put64(b + 16, 1000);
    b[24] = 0x00;
    b[25] = 0x13;
    b[26] = 0x74;
    b[27] = 0;
    put16(b + 28, 5);
    put16(b + 36, 2462);
    put16(b + 38, 0x00c0);
    b[40] = (uint8_t)-61;
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);

    assert_int_equal(rt.status, LX_RT_OK);
    assert_int_equal(rt.n_vendor, 1);
    assert_true(rt.tsft_us == 1000);
    assert_int_equal(rt.freq_mhz, 2462);
    assert_int_equal(rt.dbm_signal, -61);
}

/* Bit 32 of the default namespace (second word without a restart) is unknown: parsing
 * stops there, the first word's fields stay. */
static void test_unknown_ext_bit_keeps_earlier_fields(void **state)
{
    (void)state;
    uint8_t b[16] = {0};
    put16(b + 2, 16);
    put32(b + 4, (1u << 31) | (1u << 1) | (1u << 5));
    put32(b + 8, 1u);
    b[12] = 0x10;
    b[13] = (uint8_t)-70;
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);

    assert_int_equal(rt.status, LX_RT_STOP_UNKNOWN);
    assert_int_equal(rt.flags, 0x10);
    assert_int_equal(rt.dbm_signal, -70);
}

/* XChannel (bit 18) has no defined size: the MCS after it is not read. */
static void test_unknown_field_stops_before_later_fields(void **state)
{
    (void)state;
    uint8_t b[24] = {0};
    put16(b + 2, 24);
    put32(b + 4, (1u << 5) | (1u << 18) | (1u << 19));
    b[8] = (uint8_t)-33;
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);

    assert_int_equal(rt.status, LX_RT_STOP_UNKNOWN);
    assert_int_equal(rt.dbm_signal, -33);
    assert_false(rt.has_mcs);
}

static void test_bad_headers_rejected(void **state)
{
    (void)state;
    lx_radiotap_t rt;
    uint8_t b[16] = {0};
    put16(b + 2, 8);

    assert_int_equal(lx_radiotap_parse(b, 7, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_SHORT);

    b[0] = 1;
    assert_int_equal(lx_radiotap_parse(b, 16, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_VERSION);
    b[0] = 0;

    put16(b + 2, 17);
    assert_int_equal(lx_radiotap_parse(b, 16, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_LEN);
    put16(b + 2, 7);
    assert_int_equal(lx_radiotap_parse(b, 16, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_LEN);

    /* every word says another follows: runs into it_len */
    put16(b + 2, 16);
    put32(b + 4, 1u << 31);
    put32(b + 8, 1u << 31);
    put32(b + 12, 1u << 31);
    assert_int_equal(lx_radiotap_parse(b, 16, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_BITMAP);

    put32(b + 4, (1u << 29) | (1u << 30));
    assert_int_equal(lx_radiotap_parse(b, 16, &rt), -1);
    assert_int_equal(rt.status, LX_RT_ERR_NS_BOTH);
}

/* A field that runs past it_len ends the parse; the fields before it stay. */
static void test_field_overrun_keeps_earlier_fields(void **state)
{
    (void)state;
    uint8_t b[20] = {0};
    put16(b + 2, 12);
    put32(b + 4, (1u << 5) | (1u << 22)); /* signal at 8, timestamp would need 16..27 */
    b[8] = (uint8_t)-50;
    lx_radiotap_t rt;

    assert_int_equal(lx_radiotap_parse(b, sizeof(b), &rt), 0);
    assert_int_equal(rt.status, LX_RT_FIELD_OVERRUN);
    assert_int_equal(rt.dbm_signal, -50);

    /* vendor skip_length beyond it_len */
    uint8_t v[16] = {0};
    put16(v + 2, 16);
    put32(v + 4, 1u << 30);
    put16(v + 12, 200);
    assert_int_equal(lx_radiotap_parse(v, sizeof(v), &rt), 0);
    assert_int_equal(rt.status, LX_RT_FIELD_OVERRUN);
}

/* A data frame header: fc, duration, addr1..3, seq ctl, [addr4], [QoS]. */
static size_t build_data(uint8_t *f, int ds, bool qos, const uint8_t *a1, const uint8_t *a2,
                         const uint8_t *a3, const uint8_t *a4)
{
    memset(f, 0, 40);
    f[0] = qos ? 0x88 : 0x08;
    f[1] = (uint8_t)ds;
    memcpy(f + 4, a1, 6);
    memcpy(f + 10, a2, 6);
    memcpy(f + 16, a3, 6);
    put16(f + 22, 0x1234); /* seq 0x123, fragment 4 */
    size_t n = 24;
    if (ds == 3) { memcpy(f + 24, a4, 6); n = 30; }
    if (qos) { n += 2; }
    return n;
}

/* IEEE 802.11 Table 9-30: SA is addr2 (ds 0, ToDS), addr3 (FromDS), addr4 (both). */
static void test_source_address_by_ds_bits(void **state)
{
    (void)state;
    const uint8_t *want_sa[4] = {k_b, k_b, k_c, k_d};
    for (int ds = 0; ds < 4; ds++) {
        uint8_t f[40];
        const size_t n = build_data(f, ds, ds == 2, k_a, k_b, k_c, k_d);
        lx_wlan_t w;

        assert_int_equal(lx_wlan_parse(f, n, &w), 0);

        assert_int_equal(w.type, LX_WLAN_DATA);
        assert_int_equal(w.ds, ds);
        assert_true(w.has_sa);
        assert_memory_equal(w.sa, want_sa[ds], 6);
        assert_true(w.has_ta);
        assert_memory_equal(w.ta, k_b, 6);
        assert_int_equal(w.seq, 0x123);
        assert_int_equal(w.frag, 4);
    }
}

static void test_short_frames_have_no_source(void **state)
{
    (void)state;
    uint8_t f[40];
    lx_wlan_t w;
    size_t n = build_data(f, 3, true, k_a, k_b, k_c, k_d); /* 32 bytes needed */

    assert_int_equal(lx_wlan_parse(f, n - 1, &w), 0);
    assert_false(w.has_sa);
    assert_int_equal(lx_wlan_parse(f, n, &w), 0);
    assert_true(w.has_sa);

    n = build_data(f, 0, false, k_a, k_b, k_c, k_d);
    assert_int_equal(lx_wlan_parse(f, 23, &w), 0);
    assert_false(w.has_sa);
    assert_false(w.has_seq);
    assert_int_equal(lx_wlan_parse(f, 1, &w), -1);

    /* ACK: fc d4 00, duration, RA only */
    const uint8_t ack[10] = {0xd4, 0, 0, 0, 2, 0, 0, 0, 0, 0x0a};
    assert_int_equal(lx_wlan_parse(ack, sizeof(ack), &w), 0);
    assert_int_equal(w.type, LX_WLAN_CTRL);
    assert_false(w.has_sa);
    assert_false(w.has_ta);

    /* RTS: RA + TA, but no SA */
    uint8_t rts[16] = {0xb4, 0};
    memcpy(rts + 4, k_a, 6);
    memcpy(rts + 10, k_b, 6);
    assert_int_equal(lx_wlan_parse(rts, sizeof(rts), &w), 0);
    assert_true(w.has_ta);
    assert_memory_equal(w.ta, k_b, 6);
    assert_false(w.has_sa);
}

static void test_management_source_is_addr2(void **state)
{
    (void)state;
    uint8_t f[24] = {0x80, 0x02}; /* beacon, FromDS bit set: still addr2 */
    memcpy(f + 4, k_a, 6);
    memcpy(f + 10, k_b, 6);
    memcpy(f + 16, k_c, 6);
    lx_wlan_t w;

    assert_int_equal(lx_wlan_parse(f, sizeof(f), &w), 0);

    assert_int_equal(w.type, LX_WLAN_MGMT);
    assert_int_equal(w.subtype, 8);
    assert_true(w.has_sa);
    assert_memory_equal(w.sa, k_b, 6);
}

/* With the FCS flag the frame length excludes the last 4 bytes. */
static void test_fcs_flag_strips_four_bytes(void **state)
{
    (void)state;
    uint8_t b[9 + 40] = {0}; /* 9 radiotap + 32 frame + 4 FCS used */
    const size_t n = 9 + 32 + 4;
    put16(b + 2, 9);
    put32(b + 4, 1u << 1);
    b[8] = LX_RT_FLAG_FCS;
    build_data(b + 9, 1, false, k_a, k_b, k_c, k_d);
    lx_rt_frame_t f;

    assert_int_equal(lx_rt_frame_parse(b, n, &f), 0);

    assert_int_equal(f.frame_len, 32);
    assert_true(f.wlan_ok);
    assert_memory_equal(f.wlan.sa, k_b, 6);

    b[8] = 0;
    assert_int_equal(lx_rt_frame_parse(b, n, &f), 0);
    assert_int_equal(f.frame_len, 36);
}

/* First record of a capture file (classic pcap: 24-byte file header, 16-byte record
 * header). */
static size_t first_record(const char *path, uint8_t *buf, size_t cap)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    uint8_t h[40];
    assert_int_equal(fread(h, 1, sizeof(h), fp), sizeof(h));
    const size_t incl = (size_t)h[32] | ((size_t)h[33] << 8) | ((size_t)h[34] << 16) | ((size_t)h[35] << 24);
    assert_true(incl <= cap);
    assert_int_equal(fread(buf, 1, incl, fp), incl);
    fclose(fp);
    return incl;
}

/* Bytes of the radiotap struct both parses wrote (memset first: padding compares). */
static void assert_same_parse(const uint8_t *b, size_t n, lx_rt_layout_t *memo)
{
    lx_radiotap_t walk, kept;
    const int rc = lx_radiotap_parse(b, n, &walk);
    assert_int_equal(lx_radiotap_parse_memo(b, n, &kept, memo), rc);
    assert_memory_equal(&kept, &walk, sizeof(walk));
}

/* A layout memo: TSFT, flags, rate, channel, dBm signal at 8, 16, 17, 18 (channel aligned
 * to 2), 22; it_len 23. A second header of the same layout is read from the memo with its
 * own values; the same word with it_len 22 (the signal overruns), an unknown bit 18 and a
 * two-word header are not taken for it, and each gives what the walk gives. */
static void test_layout_memo_reads_each_header(void **state)
{
    (void)state;
    lx_rt_layout_t memo;
    memset(&memo, 0, sizeof(memo));
    uint8_t a[32] = {0};
    put16(a + 2, 23);
    put32(a + 4, (1u << 0) | (1u << 1) | (1u << 2) | (1u << 3) | (1u << 5));
    put64(a + 8, 123456789ull);
    a[16] = LX_RT_FLAG_FCS;
    a[17] = 12;
    put16(a + 18, 2437);
    put16(a + 20, 0x00a0);
    a[22] = (uint8_t)-47;
    lx_radiotap_t rt;
    assert_int_equal(lx_radiotap_parse_memo(a, 23, &rt, &memo), 0);
    assert_int_equal(memo.it_len, 23);
    assert_int_equal(memo.off[5], 22);
    assert_int_equal(memo.off[3], 18);

    uint8_t a2[32];
    memcpy(a2, a, sizeof(a2));
    put64(a2 + 8, 987654321ull);
    a2[16] = 0;
    a2[17] = 108;
    put16(a2 + 18, 5180);
    a2[22] = (uint8_t)-71;
    assert_int_equal(lx_radiotap_parse_memo(a2, 23, &rt, &memo), 0);
    assert_int_equal(rt.status, LX_RT_OK);
    assert_true(rt.tsft_us == 987654321ull);
    assert_int_equal(rt.flags, 0);
    assert_int_equal(rt.rate_500k, 108);
    assert_int_equal(rt.freq_mhz, 5180);
    assert_int_equal(rt.chan_flags, 0x00a0);
    assert_int_equal(rt.dbm_signal, -71);
    assert_int_equal(rt.n_dbm_signal, 1);
    assert_int_equal(rt.n_present, 1);
    assert_false(rt.has_dbm_noise);
    assert_same_parse(a2, 23, &memo);

    put16(a2 + 2, 22); /* the signal byte lies outside it_len now */
    assert_int_equal(lx_radiotap_parse_memo(a2, 23, &rt, &memo), 0);
    assert_int_equal(rt.status, LX_RT_FIELD_OVERRUN);
    assert_false(rt.has_dbm_signal);
    assert_true(rt.has_channel);
    assert_same_parse(a2, 23, &memo); /* now from the memo of it_len 22 */

    uint8_t u[16] = {0};
    put16(u + 2, 12);
    put32(u + 4, (1u << 1) | (1u << 5) | (1u << 18));
    u[8] = 0x02;
    u[9] = (uint8_t)-60;
    for (int i = 0; i < 2; i++) { /* walked, then from the memo */
        assert_int_equal(lx_radiotap_parse_memo(u, 12, &rt, &memo), 0);
        assert_int_equal(rt.status, LX_RT_STOP_UNKNOWN);
        assert_int_equal(rt.dbm_signal, -60);
        assert_same_parse(u, 12, &memo);
    }

    uint8_t e[32] = {0}; /* two present words: walked, the memo kept as it was */
    put16(e + 2, 13);
    put32(e + 4, (1u << 5) | (1u << 31));
    put32(e + 8, 0);
    e[12] = (uint8_t)-33;
    const lx_rt_layout_t before = memo;
    assert_same_parse(e, 13, &memo);
    assert_memory_equal(&memo, &before, sizeof(memo));
    assert_same_parse(a, 23, &memo);
    assert_same_parse(u, 12, &memo);
}

/* tshark: radiotap.length 56, dbm_antsignal -34,-39,-34, channel.freq 5745, flags.fcs 1,
 * antenna 0,1, datarate 6, mactime 9526800862, wlan.sa 18:31:bf:57:da:1c, wlan.seq 268,
 * type_subtype 0x0008, frame.cap_len 239. */
static void test_real_meshid_capture(void **state)
{
    (void)state;
    uint8_t buf[2048];
    const size_t n = first_record("tests/data/captures/ieee802.11_meshid.pcap", buf, sizeof(buf));
    const uint8_t sa[6] = {0x18, 0x31, 0xbf, 0x57, 0xda, 0x1c};
    lx_rt_frame_t f;

    assert_int_equal(lx_rt_frame_parse(buf, n, &f), 0);

    assert_int_equal(n, 239);
    assert_int_equal(f.rt.it_len, 56);
    assert_int_equal(f.rt.dbm_signal, -34);
    assert_int_equal(f.rt.n_dbm_signal, 3);
    assert_int_equal(f.rt.freq_mhz, 5745);
    assert_true(f.rt.flags & LX_RT_FLAG_FCS);
    assert_int_equal(f.rt.antenna, 0);
    assert_int_equal(f.rt.rate_500k, 12);
    assert_true(f.rt.tsft_us == 9526800862ull);
    assert_int_equal(f.frame_len, 239 - 56 - 4);
    assert_int_equal(f.wlan.type, LX_WLAN_MGMT);
    assert_int_equal(f.wlan.subtype, 8);
    assert_memory_equal(f.wlan.sa, sa, 6);
    assert_int_equal(f.wlan.seq, 268);
    const uint8_t *peek = lx_rt_frame_sa(buf, n);
    assert_non_null(peek);
    assert_memory_equal(peek, sa, 6);
}

/* tshark: radiotap.length 89, dbm_antsignal -22, freq 2412, fcs 1, dbm_antnoise -86,
 * antenna 1, datarate 1, mactime 10016360, wlan.sa 90:a4:de:c0:46:11, seq 1. The second
 * present word continues the default namespace with bits tshark does not know. */
static void test_real_exthdr_capture(void **state)
{
    (void)state;
    uint8_t buf[2048];
    const size_t n = first_record("tests/data/captures/ieee802.11_exthdr.pcap", buf, sizeof(buf));
    const uint8_t sa[6] = {0x90, 0xa4, 0xde, 0xc0, 0x46, 0x11};
    lx_rt_frame_t f;

    assert_int_equal(lx_rt_frame_parse(buf, n, &f), 0);

    assert_int_equal(f.rt.status, LX_RT_STOP_UNKNOWN);
    assert_int_equal(f.rt.it_len, 89);
    assert_int_equal(f.rt.n_present, 2);
    assert_int_equal(f.rt.dbm_signal, -22);
    assert_int_equal(f.rt.dbm_noise, -86);
    assert_int_equal(f.rt.freq_mhz, 2412);
    assert_int_equal(f.rt.antenna, 1);
    assert_int_equal(f.rt.rate_500k, 2);
    assert_true(f.rt.tsft_us == 10016360ull);
    assert_memory_equal(f.wlan.sa, sa, 6);
    assert_int_equal(f.wlan.seq, 1);
    const uint8_t *peek = lx_rt_frame_sa(buf, n);
    assert_non_null(peek);
    assert_memory_equal(peek, sa, 6);
}

/* The source address from the radiotap length alone: the header's fields are not read
 * (a bad version still locates the frame), its length must lie within the record, and
 * the 802.11 rules are lx_wlan_parse's (a data frame with FromDS: addr3; one byte short
 * of its header, an ACK: none). */
static void test_source_address_before_radiotap(void **state)
{
    (void)state;
    uint8_t b[64] = {0};
    put16(b + 2, 12);
    put32(b + 4, 1u << 5);
    b[8] = (uint8_t)-40;
    const size_t n = 12 + build_data(b + 12, 2, false, k_a, k_b, k_c, k_d);

    assert_ptr_equal(lx_rt_frame_sa(b, n), b + 12 + 16);
    assert_memory_equal(lx_rt_frame_sa(b, n), k_c, 6);

    b[0] = 1; /* version: lx_rt_frame_parse rejects the record, the address is still there */
    lx_rt_frame_t f;
    assert_int_equal(lx_rt_frame_parse(b, n, &f), -1);
    assert_ptr_equal(lx_rt_frame_sa(b, n), b + 12 + 16);
    b[0] = 0;
    assert_null(lx_rt_frame_sa(b, n - 1));
    put16(b + 2, (uint16_t)(n + 1));
    assert_null(lx_rt_frame_sa(b, n));
    put16(b + 2, 7);
    assert_null(lx_rt_frame_sa(b, n));
    assert_null(lx_rt_frame_sa(b, 7));
    const uint8_t ack[18] = {0, 0, 8, 0, 0, 0, 0, 0, 0xd4, 0, 0, 0, 2, 0, 0, 0, 0, 0x0a};
    assert_null(lx_rt_frame_sa(ack, sizeof(ack)));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_minimal_header_has_no_fields),
        cmocka_unit_test(test_fields_aligned_to_header_start),
        cmocka_unit_test(test_alignment_independent_of_buffer_address),
        cmocka_unit_test(test_per_chain_reports_combined_signal),
        cmocka_unit_test(test_vendor_namespace_skipped_by_length),
        cmocka_unit_test(test_unknown_ext_bit_keeps_earlier_fields),
        cmocka_unit_test(test_unknown_field_stops_before_later_fields),
        cmocka_unit_test(test_bad_headers_rejected),
        cmocka_unit_test(test_field_overrun_keeps_earlier_fields),
        cmocka_unit_test(test_source_address_by_ds_bits),
        cmocka_unit_test(test_short_frames_have_no_source),
        cmocka_unit_test(test_management_source_is_addr2),
        cmocka_unit_test(test_fcs_flag_strips_four_bytes),
        cmocka_unit_test(test_real_meshid_capture),
        cmocka_unit_test(test_real_exthdr_capture),
        cmocka_unit_test(test_source_address_before_radiotap),
        cmocka_unit_test(test_layout_memo_reads_each_header),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
