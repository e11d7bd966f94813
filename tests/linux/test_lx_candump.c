/* test_lx_candump.c - candump -L lines: ours as can-utils reads them, can-utils' as we do.
 *
 * The reference reader is can-utils' log2long (its parse_canframe): every frame written by
 * lx_candump_format must come back with its time, interface, id, length and bytes. The
 * lines we parse follow candump.c's format string, "(%010ld.%06ld) %*s " + ID#HEX.
 */
#include "rfs_test.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "lx_candump.h"

typedef struct wr_case {
    int64_t t_us;
    const char *ifname;
    rfs_can_frame_t f;
} wr_case_t;

static const wr_case_t k_frames[] = {
    {0, "can0", {0x000, 0, {0}}},
    {4294967296LL, "can0", {0x100, 6, {0x10, 0x00, 0x00, 0x00, 0x00, 0xA2}}},
    {1700000000123456LL, "vcan0", {0x7FF, 8, {0xDE, 0xAD, 0xBE, 0xEF, 0x00, 0x01, 0x80, 0xFF}}},
    {999999, "can-robot_1", {0x121, 1, {0x5A}}},
    {123456789012345678LL, "x", {0x0AB, 3, {1, 2, 3}}},
};
#define N_FRAMES (sizeof(k_frames) / sizeof(k_frames[0]))

/* log2long prints "(S.U)  IFACE  ID   [N]  B0 B1 ...  'ASCII'". */
static void test_format_read_by_log2long(void **state)
{
    (void)state;
    char path[] = "/tmp/rfs_candump_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    for (size_t i = 0; i < N_FRAMES; i++) {
        char line[LX_CANDUMP_FMT_MAX];
        const size_t n = lx_candump_format(line, sizeof line, k_frames[i].t_us, k_frames[i].ifname, &k_frames[i].f);
        assert_true(n > 0 && line[n - 1] == '\n' && strlen(line) == n);
        fputs(line, f);
    }
    fclose(f);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "log2long < %s", path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    char got[256];
    size_t i = 0;
    for (; fgets(got, sizeof got, p) != NULL; i++) {
        assert_true(i < N_FRAMES);
        unsigned long long sec = 0, usec = 0;
        char ifname[32];
        unsigned id = 0, len = 0;
        int used = 0;
        assert_int_equal(sscanf(got, " (%llu.%llu) %31s %x [%u]%n", &sec, &usec, ifname, &id, &len, &used), 5);
        const wr_case_t *c = &k_frames[i];
        assert_int_equal((long long)(sec * 1000000ull + usec), c->t_us);
        assert_string_equal(ifname, c->ifname);
        assert_int_equal(id, c->f.id);
        assert_int_equal(len, c->f.dlc);
        const char *at = got + used;
        for (unsigned b = 0; b < c->f.dlc; b++) {
            unsigned v = 0;
            int k = 0;
            assert_int_equal(sscanf(at, " %2x%n", &v, &k), 1);
            assert_int_equal(v, c->f.data[b]);
            at += k;
        }
    }
    assert_int_equal(pclose(p), 0);
    assert_int_equal(i, N_FRAMES);
    remove(path);
}

static void test_format_refuses(void **state)
{
    (void)state;
    char line[LX_CANDUMP_FMT_MAX];
    rfs_can_frame_t f = {0x800, 0, {0}};
    assert_int_equal(lx_candump_format(line, sizeof line, 0, "can0", &f), 0);   /* 12-bit id */
    f.id = 0x100;
    f.dlc = 9;
    assert_int_equal(lx_candump_format(line, sizeof line, 0, "can0", &f), 0);   /* dlc */
    f.dlc = 8;
    assert_int_equal(lx_candump_format(line, sizeof line, -1, "can0", &f), 0);  /* before the epoch */
    assert_int_equal(lx_candump_format(line, 46, 0, "can0", &f), 0);           /* no room for the NUL */
    assert_int_equal(lx_candump_format(line, 47, 0, "can0", &f), 46);          /* just room */
    assert_string_equal(line, "(0000000000.000000) can0 100#0000000000000000\n");
}

/* Lines as candump.c, candump -x and asc2log write them. */
static void test_parse_candump_lines(void **state)
{
    (void)state;
    lx_candump_rec_t r;
    const char *why = NULL;
    const char *l1 = "(1345212884.318850) can0 123#DEADBEEF";
    assert_int_equal(lx_candump_parse(l1, strlen(l1), &r, &why), 0);
    assert_int_equal(r.t_us, 1345212884318850LL);
    assert_string_equal(r.ifname, "can0");
    assert_int_equal(r.kind, LX_CANDUMP_DATA);
    assert_false(r.ext);
    assert_int_equal(r.id, 0x123);
    assert_int_equal(r.dlc, 4);
    assert_int_equal(r.data[0], 0xDE);
    assert_int_equal(r.data[3], 0xEF);
    assert_int_equal(r.data[4], 0);
    const char *l2 = "(0000000001.000000)   can0 1FFFFFFF#0011 T\r";
    assert_int_equal(lx_candump_parse(l2, strlen(l2), &r, &why), 0);
    assert_true(r.ext);
    assert_int_equal(r.id, 0x1FFFFFFF);
    assert_int_equal(r.dlc, 2);
    const char *l3 = "(5.000001) vcan10 20000080#0000000000000000";
    assert_int_equal(lx_candump_parse(l3, strlen(l3), &r, &why), 0);
    assert_int_equal(r.kind, LX_CANDUMP_ERROR);
    assert_int_equal(r.id, 0x80);
    assert_int_equal(r.t_us, 5000001);
    const char *l4 = "(5.000001) can0 7FF#R3";
    assert_int_equal(lx_candump_parse(l4, strlen(l4), &r, &why), 0);
    assert_int_equal(r.kind, LX_CANDUMP_REMOTE);
    assert_int_equal(r.dlc, 3);
    const char *l5 = "(5.000001) can0 100#11.22.33";
    assert_int_equal(lx_candump_parse(l5, strlen(l5), &r, &why), 0);
    assert_int_equal(r.dlc, 3);
    assert_int_equal(r.data[2], 0x33);
    /* The parser reads len bytes only: the rest of the buffer is not part of the line. */
    assert_int_equal(lx_candump_parse(l1, strlen(l1) - 2, &r, &why), 0);
    assert_int_equal(r.dlc, 3);
}

static void test_parse_rejects(void **state)
{
    (void)state;
    static const struct {
        const char *line, *why;
    } k_bad[] = {
        {"", "no '(' opening the timestamp"},
        {"(.000000) can0 100#", "timestamp: seconds expected after '('"},
        {"(1234567890123.000000) can0 100#", "timestamp: more than 12 digits of seconds"},
        {"(1.00000) can0 100#", "timestamp: '.', 6 digits of microseconds and ')' expected"},
        {"(1.0000000) can0 100#", "timestamp: '.', 6 digits of microseconds and ')' expected"},
        {"(1.000000)can0 100#", "a space and the interface expected after the timestamp"},
        {"(1.000000) can0", "interface name and frame expected after the timestamp"},
        {"(1.000000) abcdefghijklmnop 100#", "interface name longer than 15 characters"},
        {"(1.000000) can0 10#", "identifier: 3 hex digits (11-bit) or 8 (29-bit) expected"},
        {"(1.000000) can0 123456789#", "identifier: 3 hex digits (11-bit) or 8 (29-bit) expected"},
        {"(1.000000) can0 800#", "identifier: an 11-bit one is at most 7FF"},
        {"(1.000000) can0 40000000#", "identifier: a 29-bit one is at most 1FFFFFFF (20000000 marks an error frame)"},
        {"(1.000000) can0 100", "'#' expected after the identifier"},
        {"(1.000000) can0 100##0", "CAN FD frame ('##'): only classic CAN is read"},
        {"(1.000000) can0 100#0", "data: hex digits in pairs expected"},
        {"(1.000000) can0 100#0G", "data: hex digits in pairs expected"},
        {"(1.000000) can0 100#001122334455667788", "data: more than 8 bytes"},
        {"(1.000000) can0 100#0011223344556677_9", "a raw DLC over 8 ('_' suffix) is not read"},
        {"(1.000000) can0 100#00 X", "unexpected text after the frame"},
        {"(1.000000) can0 100#00 TT", "unexpected text after the frame"},
    };
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; i++) {
        lx_candump_rec_t r;
        const char *why = NULL;
        assert_int_equal(lx_candump_parse(k_bad[i].line, strlen(k_bad[i].line), &r, &why), -1);
        assert_string_equal(why, k_bad[i].why);
    }
}

/* A log whose clock starts at 0 is shifted by 2^32 us; a real clock is not; a log not kept
 * leaves nothing; a bad interface name is refused. */
static void test_writer(void **state)
{
    (void)state;
    char dir[] = "/tmp/rfs_candumpw_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64], err[256], text[256];
    snprintf(path, sizeof path, "%s/a.log", dir);
    const rfs_can_frame_t f = {0x180, 2, {0xAB, 0x01}};
    for (int real = 0; real < 2; real++) {
        lx_candump_t *w = lx_candump_open(path, "can0", err, sizeof err);
        assert_non_null(w);
        const int64_t t0 = real ? 1700000000000000LL : 0;
        lx_candump_write(w, t0, &f);
        lx_candump_write(w, t0 + 50000, &f);
        assert_int_equal(lx_candump_count(w), 2);
        assert_int_equal(access(path, F_OK), -1); /* not there before the close */
        assert_int_equal(lx_candump_close(w, true, err, sizeof err), 0);
        FILE *in = fopen(path, "r");
        assert_non_null(in);
        const size_t n = fread(text, 1, sizeof text - 1, in);
        text[n] = '\0';
        fclose(in);
        assert_string_equal(text, real ? "(1700000000.000000) can0 180#AB01\n(1700000000.050000) can0 180#AB01\n"
                                        : "(0000004294.967296) can0 180#AB01\n(0000004295.017296) can0 180#AB01\n");
        remove(path);
    }
    lx_candump_t *w = lx_candump_open(path, "can0", err, sizeof err);
    lx_candump_write(w, 1, &f);
    assert_int_equal(lx_candump_close(w, false, err, sizeof err), 0);
    assert_null(lx_candump_open(path, "can 0", err, sizeof err));
    assert_non_null(strstr(err, "interface name 'can 0'"));
    w = lx_candump_open(path, "can0", err, sizeof err);
    lx_candump_write(w, -5, &f);
    assert_int_equal(lx_candump_close(w, true, err, sizeof err), -1);
    assert_non_null(strstr(err, "a.log: write failed: a frame has a time before the epoch"));
    assert_int_equal(rmdir(dir), 0); /* nothing was left in it */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_format_read_by_log2long),
        cmocka_unit_test(test_format_refuses),
        cmocka_unit_test(test_parse_candump_lines),
        cmocka_unit_test(test_parse_rejects),
        cmocka_unit_test(test_writer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
