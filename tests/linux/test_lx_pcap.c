/* test_lx_pcap.c - lx_pcap_writer: what it writes, as tshark reads it back.
 *
 * The reference reader is tshark (an independent 802.11/radiotap dissector): every value
 * passed to lx_pcap_writer_frame() must come back in its fields.
 */
#include "rfs_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lx_pcap.h"

typedef struct wr_case {
    int64_t t_us;
    uint8_t src[6];
    uint16_t seq;
    int8_t dbm;
    uint16_t freq;
} wr_case_t;

static const uint8_t k_bssid[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0xaa};

static const wr_case_t k_cases[] = {
    {1700000000000001, {0x02, 0x52, 0x46, 0x53, 0x00, 0x01}, 0, -20, 2412},
    {1700000000999999, {0x02, 0x52, 0x46, 0x53, 0x00, 0x02}, 4095, -95, 5180},
    {1700000001000000, {0xb8, 0x27, 0xeb, 0x12, 0x34, 0x56}, 1234, -128, 2484},
    {1700000123456789, {0x02, 0x52, 0x46, 0x53, 0x00, 0x01}, 1, 0, 5825},
    {0, {0xff, 0xff, 0xff, 0xff, 0xff, 0xfe}, 77, 127, 2437},
};
#define N_CASES (sizeof(k_cases) / sizeof(k_cases[0]))

typedef struct fixture {
    char dir[64];
    char path[128];
    char tmp[136];
} fixture_t;

static int setup(void **state)
{
    fixture_t *fx = calloc(1, sizeof(*fx));
    if (fx == NULL) { return -1; }
    snprintf(fx->dir, sizeof(fx->dir), "/tmp/rfs_pcapw_XXXXXX");
    if (mkdtemp(fx->dir) == NULL) { free(fx); return -1; }
    snprintf(fx->path, sizeof(fx->path), "%s/out.pcap", fx->dir);
    snprintf(fx->tmp, sizeof(fx->tmp), "%s.tmp", fx->path);
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture_t *fx = *state;
    (void)remove(fx->path);
    (void)remove(fx->tmp);
    (void)rmdir(fx->dir);
    free(fx);
    return 0;
}

static void test_tshark_reads_back_every_value(void **state)
{
    fixture_t *fx = *state;
    char err[256] = "";
    lx_pcap_writer_t *w = lx_pcap_writer_open(fx->path, err, sizeof(err));
    assert_non_null(w);
    for (size_t i = 0; i < N_CASES; i++) {
        const wr_case_t *c = &k_cases[i];
        assert_int_equal(lx_pcap_writer_frame(w, c->t_us, c->src, k_bssid, c->seq, c->dbm, c->freq), 0);
    }
    assert_int_equal(access(fx->path, F_OK), -1); /* only the temporary exists so far */
    assert_int_equal(access(fx->tmp, F_OK), 0);
    assert_true(lx_pcap_writer_count(w) == N_CASES);

    assert_int_equal(lx_pcap_writer_close(w), 0);

    assert_int_equal(access(fx->path, F_OK), 0);
    assert_int_equal(access(fx->tmp, F_OK), -1);
    char cmd[512];
    snprintf(cmd, sizeof(cmd),
             "tshark -r %s -T fields -E separator=/t -e frame.time_epoch -e radiotap.mactime "
             "-e radiotap.flags.fcs -e radiotap.channel.freq -e radiotap.dbm_antsignal -e wlan.fc.type_subtype "
             "-e wlan.fc.ds -e wlan.sa -e wlan.ta -e wlan.bssid -e wlan.seq -e wlan.frag -e llc.type "
             "2>/dev/null",
             fx->path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    char line[512];
    size_t n = 0;
    while (fgets(line, sizeof(line), p) != NULL) {
        assert_true(n < N_CASES);
        const wr_case_t *c = &k_cases[n];
        char want[512];
        char mac[18];
        snprintf(mac, sizeof(mac), "%02x:%02x:%02x:%02x:%02x:%02x", c->src[0], c->src[1], c->src[2],
                 c->src[3], c->src[4], c->src[5]);
        snprintf(want, sizeof(want), "%lld.%06lld000\t%lld\t0\t%u\t%d\t0x0020\t0x01\t%s\t%s\t02:00:00:00:00:aa\t%u\t0\t0x88b5\n",
                 (long long)(c->t_us / 1000000), (long long)(c->t_us % 1000000), (long long)c->t_us,
                 (unsigned)c->freq, (int)c->dbm, mac, mac, (unsigned)c->seq);
        assert_string_equal(line, want);
        n++;
    }
    assert_int_equal(pclose(p), 0);
    assert_int_equal(n, N_CASES);
}

static void test_open_in_missing_directory_fails_with_message(void **state)
{
    fixture_t *fx = *state;
    char path[200];
    snprintf(path, sizeof(path), "%s/no/such/dir/out.pcap", fx->dir);
    char err[256] = "";

    lx_pcap_writer_t *w = lx_pcap_writer_open(path, err, sizeof(err));

    assert_null(w);
    assert_non_null(strstr(err, "no/such/dir/out.pcap.tmp: cannot create"));
}

static void test_negative_time_discards_file(void **state)
{
    fixture_t *fx = *state;
    char err[256] = "";
    lx_pcap_writer_t *w = lx_pcap_writer_open(fx->path, err, sizeof(err));
    assert_non_null(w);
    const wr_case_t *c = &k_cases[0];

    assert_int_equal(lx_pcap_writer_frame(w, c->t_us, c->src, k_bssid, c->seq, c->dbm, c->freq), 0);
    assert_int_equal(lx_pcap_writer_frame(w, -1, c->src, k_bssid, c->seq, c->dbm, c->freq), -1);
    assert_int_equal(lx_pcap_writer_close(w), -1);

    assert_int_equal(access(fx->path, F_OK), -1);
    assert_int_equal(access(fx->tmp, F_OK), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_tshark_reads_back_every_value, setup, teardown),
        cmocka_unit_test_setup_teardown(test_open_in_missing_directory_fails_with_message, setup, teardown),
        cmocka_unit_test_setup_teardown(test_negative_time_discards_file, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
