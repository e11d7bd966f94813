/* rfseek-feed - RSSI of chosen transmitters from an 802.11 radiotap capture (docs/FEEDER.md).
 *
 * Prints one line per frame whose source address (Wireshark's wlan.sa) is one of the
 * --mac addresses and whose radiotap header carries a dBm antenna signal:
 *   epoch_seconds<TAB>source_mac<TAB>dbm
 * with the epoch printed as tshark prints frame.time_epoch (9 decimals), so the output
 * equals `tshark -r CAPTURE -Y 'wlan.sa == MAC' -T fields -e frame.time_epoch -e wlan.sa
 * -e radiotap.dbm_antsignal -E occurrence=f` for the frames that have a signal.
 *
 * With --list it surveys the capture instead: one TSV row per transmitter (hs_survey.h).
 *
 * A --mac from which no frame came is a warning line and exit status 3 (the output is
 * complete): a typing error should not pass for an empty capture.
 *
 * With --live IFACE --lcm URL it feeds the controller instead (docs/FEEDER.md, "Live to
 * the controller"): every matching frame as an RFS_RSSI message (source = the --mac's
 * position), and receiver heartbeats (RFS_RSSI_STATUS) while the capture loop runs, heard
 * or not (lx_feed.h), until SIGINT or SIGTERM.
 *
 * With --pose it replays a real experiment offline instead: the matching frames and the
 * recorded poses go, in time order, through the same in-process controller over the core
 * (rfs_seek) as the simulator uses, and the simulator's log.tsv, samples.tsv, track.tsv
 * and summary.json are written (docs/FEEDER.md).
 */
#include <errno.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "hs_replay.h"
#include "lx_err.h"
#include "lx_feed.h"
#include "lx_lcm.h"
#include "lx_pcap.h"
#include "lx_radiotap.h"
#include "hs_survey.h"
#include "rfs_models.h"

#define FEED_MAX_MACS 8

static const char k_usage[] =
    "usage: rfseek-feed CAPTURE --mac MAC [--mac MAC2 ...] [--format tsv] [--stats]\n"
    "                   [--output FILE] [--live]\n"
    "       rfseek-feed IFACE --live --lcm URL --mac MAC [--mac MAC2 ...] [--stats]\n"
    "       rfseek-feed CAPTURE --list [--mac MAC ...] [--stats] [--output FILE]\n"
    "       rfseek-feed CAPTURE --pose POSES.csv --scenario SCENARIO.yaml --out DIR\n"
    "                   [--mac MAC ...] [--seed N] [--model NAME] [--target rssi|pdr] [--stats]\n"
    "Print epoch_seconds<TAB>source_mac<TAB>dbm for every 802.11 frame in CAPTURE (a .pcap\n"
    "or .pcapng with radiotap headers, link type 127) whose source address (as tshark's\n"
    "wlan.sa) is one of the MACs and that carries a dBm antenna signal (the combined value\n"
    "when per-chain values follow). epoch_seconds has 9 decimals, exactly as tshark prints\n"
    "frame.time_epoch (a microsecond capture ends in 000).\n"
    "  --mac MAC      aa:bb:cc:dd:ee:ff; repeat for up to 8 transmitters\n"
    "  --format tsv   output format (tsv is the only one)\n"
    "  --stats        print packet counts (parsed, skipped and why) to stderr\n"
    "  --output FILE  write to FILE (via FILE.tmp, renamed only on success)\n"
    "  --live         CAPTURE is a monitor-mode interface; read until SIGINT or SIGTERM\n"
    "  --lcm URL      with --live: publish to the controller over LCM (e.g. udpm://...)\n"
    "                 instead of printing: RFS_RSSI per line (source = the --mac's position,\n"
    "                 0 first), RFS_RSSI_STATUS heartbeats every 50-75 ms while reading\n"
    "  --list         survey: one row per transmitter (802.11 addr2, tshark's wlan.ta; only\n"
    "                 the --mac ones when given), most frames first: mac, frames, frames\n"
    "                 with a dBm signal, their mean/min/max dBm, first and last time (as\n"
    "                 frame.time_epoch), the SSID of its beacons or probe responses\n"
    "  --pose POSES   replay: CSV with the header t_us,x_m,y_m,theta_rad (capture clock,\n"
    "                 microseconds since the epoch; map frame, metres, radians), increasing\n"
    "                 times; packets and poses go through the seeker (rfs_seek) offline\n"
    "  --scenario F   replay: the simulator scenario giving the map, model, target, goal and\n"
    "                 the sources (their MACs, in order, unless --mac names them)\n"
    "  --out DIR      replay: write log.tsv, samples.tsv, track.tsv, summary.json (as\n"
    "                 rfseek-sim) into DIR (via DIR.tmp-PID, renamed when complete)\n"
    "  --seed N       replay: seed of the controller's randomness (default: the scenario's)\n"
    "  --model NAME   replay: internal model, overriding the scenario's: ridge, mlp, knn,\n"
    "                 radius, pathloss (docs/MODELS.md)\n"
    "  --target T     replay: what the seeker maximises, overriding the scenario's: rssi, or\n"
    "                 pdr (the packet delivery ratio over 1 s from the 802.11 sequence numbers\n"
    "                 of the matching frames; samples.tsv then holds the percentages fed)\n"
    "  -h, --help     this text\n"
    "Exit 0 on success, 1 on a bad capture or I/O error, 2 on bad options, 3 when a --mac\n"
    "sent no frame (a warning line; the output is complete).\n";

/* Counts reported by --stats. */
typedef struct feed_stats {
    uint64_t packets;                 /* records read */
    uint64_t rt_bad[LX_RT_N_STATUS]; /* per radiotap status */
    uint64_t no_wlan;                 /* nothing after the radiotap header */
    uint64_t no_sa;                   /* 802.11 header without a source address */
    uint64_t sa_match;                /* SA is one of the MACs */
    uint64_t no_signal;               /* ... but no dBm antenna signal */
    uint64_t lines;                   /* lines printed */
    uint64_t caplen_short;            /* records captured shorter than on the air */
    uint64_t replay_before;           /* replay: matching frames before the first pose */
    uint64_t replay_after;            /* replay: ... after the last pose or the stop */
    uint64_t no_ta;                   /* --list: 802.11 header without a transmitter address */
    uint64_t rt_kept;                 /* --list: unusable radiotap header, its 802.11 frame counted */
    uint64_t mac_frames[FEED_MAX_MACS]; /* frames from each --mac (SA; --list: TA) */
    uint64_t heartbeats;              /* --lcm: receiver heartbeats published */
    uint64_t refused;                 /* --lcm: messages LCM refused */
    bool count_all;                   /* --stats: parse every record to count why it gave
                                         nothing (else one from another source is skipped
                                         unparsed, docs/FEEDER.md) */
    lx_rt_layout_t layout;            /* the last radiotap layout read (a capture's records
                                         mostly share one: lx_radiotap_parse_memo) */
} feed_stats_t;

static int parse_mac(const char *s, uint8_t mac[6])
{
    unsigned v[6];
    char sep[5];
    char tail;
    // NOLINTNEXTLINE(cert-err34-c): the digits and separators are checked below, %2x cannot overflow
    const int n = sscanf(s, "%2x%c%2x%c%2x%c%2x%c%2x%c%2x%c", &v[0], &sep[0], &v[1], &sep[1], &v[2],
                         &sep[2], &v[3], &sep[3], &v[4], &sep[4], &v[5], &tail);
    if (n != 11 || strlen(s) != 17) { return -1; }
    for (int i = 0; i < 5; i++) {
        if (sep[i] != ':' && sep[i] != '-') { return -1; }
    }
    for (int i = 0; i < 6; i++) {
        const char *h = s + 3 * i;
        for (int k = 0; k < 2; k++) {
            const char c = h[k];
            if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'))) { return -1; }
        }
        mac[i] = (uint8_t)v[i];
    }
    return 0;
}

/* "00" .. "99": two digits a division. */
static const char k_d2[] = "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
                           "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
                           "8081828384858687888990919293949596979899";

/* The decimal digits of sec into out (at least 20 bytes); returns their number. */
static size_t format_sec(char *out, uint64_t sec)
{
    char tmp[20];
    size_t k = sizeof(tmp);
    while (sec >= 100u) { k -= 2; memcpy(tmp + k, k_d2 + 2u * (sec % 100u), 2); sec /= 100u; }
    if (sec >= 10u) { k -= 2; memcpy(tmp + k, k_d2 + 2u * sec, 2); } else { tmp[--k] = (char)('0' + sec); }
    memcpy(out, tmp + k, sizeof(tmp) - k);
    return sizeof(tmp) - k;
}

/* "aa:bb:cc:dd:ee:ff\t" (18 bytes, no NUL) into out. */
static void format_mac(char *out, const uint8_t mac[6])
{
    static const char hex[] = "0123456789abcdef";
    for (int i = 0; i < 6; i++) {
        out[3 * i] = hex[mac[i] >> 4];
        out[3 * i + 1] = hex[mac[i] & 15u];
        out[3 * i + 2] = i < 5 ? ':' : '\t';
    }
}

/* ".<9 digits>\t<mac>\t<dbm>\n" into out (after the seconds), with mac_tab the 18 bytes
 * of format_mac; returns its length. Hand-formatted: this is the inner loop of the bench
 * (millions of lines). */
static size_t format_line(char *out, uint32_t frac, const char *mac_tab, int dbm)
{
    size_t n = 0;
    out[n++] = '.';
    for (int i = 7; i >= 1; i -= 2) { memcpy(out + n + (size_t)i, k_d2 + 2u * (frac % 100u), 2); frac /= 100u; }
    out[n] = (char)('0' + frac);
    n += 9;
    out[n++] = '\t';
    memcpy(out + n, mac_tab, 18);
    n += 18;
    if (dbm < 0) { out[n++] = '-'; dbm = -dbm; }
    if (dbm >= 100) { out[n++] = (char)('0' + dbm / 100); }
    if (dbm >= 10) { out[n++] = (char)('0' + dbm / 10 % 10); }
    out[n++] = (char)('0' + dbm % 10);
    out[n++] = '\n';
    return n;
}

/* One line: totals, then every non-zero reason a packet gave no line. */
static void print_stats(const char *name, const feed_stats_t *st)
{
    fprintf(stderr, "%s: %llu packets, %llu lines", name, (unsigned long long)st->packets,
            (unsigned long long)st->lines);
    for (int s = LX_RT_STOP_UNKNOWN; s < LX_RT_N_STATUS; s++) {
        if (st->rt_bad[s] != 0) {
            fprintf(stderr, "; %llu %s %s", (unsigned long long)st->rt_bad[s],
                    s >= LX_RT_ERR_SHORT ? "skipped:" : "note:", lx_radiotap_status_str((lx_rt_status_t)s));
        }
    }
    const struct { uint64_t n; const char *what; } rest[] = {
        {st->no_wlan, "skipped: no 802.11 header"},
        {st->no_sa, "skipped: no source address"},
        {st->no_ta, "skipped: no transmitter address"},
        {st->rt_kept, "note: unusable radiotap header, the 802.11 frame after it counted without signal"},
        {st->no_signal, "skipped: matching source without dBm signal"},
        {st->caplen_short, "note: cut by the snap length"},
        {st->replay_before, "replay: not fed, before the first pose"},
        {st->replay_after, "replay: not fed, after the last pose or the stop"},
        {st->heartbeats, "receiver heartbeats published"},
        {st->refused, "LCM messages refused (not sent)"},
    };
    for (size_t i = 0; i < sizeof(rest) / sizeof(rest[0]); i++) {
        if (rest[i].n != 0) { fprintf(stderr, "; %llu %s", (unsigned long long)rest[i].n, rest[i].what); }
    }
    fputc('\n', stderr);
}

/* Called for each frame from one of the MACs (index m) that carries a signal. */
typedef int (*feed_fn)(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f);

/* Called for every record read, from any transmitter, parsable or not: the capture loop
 * was alive at its time (the receiver heartbeat). */
typedef int (*alive_fn)(void *ctx, int64_t t_us);

/* Set by SIGINT or SIGTERM in a live run (live_stop_on_signal): the normal end. */
static volatile sig_atomic_t g_live_stop;

static void on_live_stop(int sig)
{
    (void)sig;
    g_live_stop = 1;
}

/* handler for SIGINT and SIGTERM. */
static void on_int_term(void (*handler)(int))
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
}

/* A live run ends at SIGINT or SIGTERM like a capture file at its end: nothing removed. */
static void live_stop_on_signal(void)
{
    on_int_term(on_live_stop);
}

/* A live capture's clock: the kernel stamps packets with CLOCK_REALTIME. */
static int64_t realtime_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* Whether two MAC addresses are equal: two loads each, no call (once a record). */
static inline bool mac_eq(const uint8_t *a, const uint8_t *b)
{
    uint32_t a4, b4;
    uint16_t a2, b2;
    memcpy(&a4, a, 4);
    memcpy(&b4, b, 4);
    memcpy(&a2, a + 4, 2);
    memcpy(&b2, b + 4, 2);
    return a4 == b4 && a2 == b2;
}

/* The index of sa among the n MACs, or n. */
static inline int mac_index(const uint8_t (*macs)[6], int n, const uint8_t *sa)
{
    int m = 0;
    while (m < n && !mac_eq(macs[m], sa)) { m++; }
    return m;
}

/* Whether the record's source address is one of the n MACs (lx_rt_frame_sa). */
static bool sa_wanted(const lx_pcap_pkt_t *pkt, const uint8_t (*macs)[6], int n)
{
    const uint8_t *sa = lx_rt_frame_sa(pkt->data, pkt->caplen);
    return sa != NULL && mac_index(macs, n, sa) < n;
}

/* The next record whose radiotap header parsed (with bad_rt, or was unusable but located
 * the 802.11 frame: counted in st->rt_kept) and an 802.11 header followed, in *pkt and *f;
 * alive (when not NULL) is called for every record read and, live, after every wait
 * without one (at the clock's time), and why a record gives nothing is counted in st. With
 * `want` (and not st->count_all) a record whose source address is not one of its n_want
 * MACs is skipped before its radiotap header is parsed, uncounted. 1, 0 at the end (live:
 * SIGINT or SIGTERM), -1 after a read error (message on stderr) or when alive failed. */
static int next_frame(lx_pcap_reader_t *r, feed_stats_t *st, lx_pcap_pkt_t *pkt, lx_rt_frame_t *f,
                      bool bad_rt, const uint8_t (*want)[6], int n_want, alive_fn alive, void *alive_ctx)
{
    char err[512];
    for (;;) {
        if (g_live_stop) { return 0; }
        const int got = lx_pcap_next(r, pkt, err, sizeof(err));
        if (got == 2) {
            if (alive != NULL && alive(alive_ctx, realtime_us()) != 0) { return -1; }
            continue;
        }
        if (got == 0) { return 0; }
        if (got < 0) {
            lx_err_one_line(err);
            fprintf(stderr, "rfseek-feed: %s (after %llu packets)\n", err, (unsigned long long)st->packets);
            return -1;
        }
        st->packets++;
        if (alive != NULL && alive(alive_ctx, pkt->t_us) != 0) { return -1; }
        if (pkt->caplen < pkt->origlen) { st->caplen_short++; }
        if (want != NULL && !st->count_all && !sa_wanted(pkt, want, n_want)) { continue; }
        const int prc = lx_rt_frame_parse_memo(pkt->data, pkt->caplen, f, &st->layout);
        if (prc != 0 && bad_rt && f->wlan_ok) {
            st->rt_kept++;
            return 1;
        }
        st->rt_bad[f->rt.status]++;
        if (prc != 0) { continue; }
        if (!f->wlan_ok) { st->no_wlan++; continue; }
        return 1;
    }
}

/* Read every packet, count why packets give nothing, call fn for the matching ones and
 * alive (when not NULL) for every one. Returns 0, or 1 after a read error (message on
 * stderr) or when fn or alive failed. */
static int scan_capture(lx_pcap_reader_t *r, const uint8_t (*macs)[6], int n_macs, feed_stats_t *st,
                        feed_fn fn, void *ctx, alive_fn alive, void *alive_ctx)
{
    for (;;) {
        lx_pcap_pkt_t pkt;
        lx_rt_frame_t f;
        const int got = next_frame(r, st, &pkt, &f, false, macs, n_macs, alive, alive_ctx);
        if (got <= 0) { return got < 0 ? 1 : 0; }
        if (!f.wlan.has_sa) { st->no_sa++; continue; }
        const int m = mac_index(macs, n_macs, f.wlan.sa);
        if (m == n_macs) { continue; }
        st->sa_match++;
        st->mac_frames[m]++;
        if (!f.rt.has_dbm_signal) { st->no_signal++; continue; }
        if (fn(ctx, m, &pkt, &f) != 0) { return 1; }
        st->lines++;
    }
}

/* --list: every frame with a transmitter address (from the --mac ones only, when given)
 * into a survey, then its table into out (hs_survey_write). 0, or 1 after a message. */
static int scan_list(lx_pcap_reader_t *r, const uint8_t (*macs)[6], int n_macs, feed_stats_t *st, FILE *out)
{
    hs_survey_t *sv = hs_survey_new();
    int rc = sv == NULL ? -1 : 0;
    for (;;) {
        lx_pcap_pkt_t pkt;
        lx_rt_frame_t f;
        const int got = rc == 0 ? next_frame(r, st, &pkt, &f, true, NULL, 0, NULL, NULL) : 0;
        if (got <= 0) {
            rc = got < 0 ? 1 : rc;
            break;
        }
        if (!f.wlan.has_ta) { st->no_ta++; continue; }
        const int m = mac_index(macs, n_macs, f.wlan.ta);
        if (n_macs > 0 && m == n_macs) { continue; }
        if (n_macs > 0) { st->mac_frames[m]++; }
        const bool usable = f.rt.status < LX_RT_ERR_SHORT; /* else no radiotap field counts */
        const hs_survey_frame_t sf = {f.wlan.ta, pkt.ts_sec, pkt.ts_nsec, usable && f.rt.has_dbm_signal,
                                      f.rt.dbm_signal, f.has_ssid ? f.ssid : NULL, f.ssid_len};
        rc = hs_survey_add(sv, &sf);
    }
    const long rows = rc == 0 ? hs_survey_write(sv, out) : -1;
    if (rows < 0 && rc <= 0) { fprintf(stderr, "rfseek-feed: out of memory\n"); }
    st->lines = rows > 0 ? (uint64_t)rows : 0u;
    hs_survey_free(sv);
    return rows < 0 ? 1 : 0;
}

/* --- TSV mode ----------------------------------------------------------------------- */

/* The temporary outputs of this run (FILE.tmp, or DIR.tmp-PID and its files), removed when
 * SIGINT or SIGTERM ends it: the paths are written before the handler is installed, and
 * the handler only unlinks them (async-signal-safe) and dies of the same signal. */
#define FEED_TMP_FILES 5
static char g_tmp_file[FEED_TMP_FILES][4200];
static char g_tmp_dir[4096];

static void on_stop_signal(int sig)
{
    for (int i = 0; i < FEED_TMP_FILES; i++) {
        if (g_tmp_file[i][0] != '\0') { (void)unlink(g_tmp_file[i]); }
    }
    if (g_tmp_dir[0] != '\0') { (void)rmdir(g_tmp_dir); }
    (void)signal(sig, SIG_DFL);
    (void)raise(sig);
}

/* Remove `dir` (or NULL) and its `n` files `names` (or, with dir NULL, the paths
 * `names` themselves) on SIGINT and SIGTERM. */
static void cleanup_on_signal(const char *dir, const char *const *names, int n)
{
    for (int i = 0; i < n && i < FEED_TMP_FILES; i++) {
        if (dir != NULL) {
            snprintf(g_tmp_file[i], sizeof(g_tmp_file[i]), "%s/%s", dir, names[i]);
        } else {
            snprintf(g_tmp_file[i], sizeof(g_tmp_file[i]), "%s", names[i]);
        }
    }
    snprintf(g_tmp_dir, sizeof(g_tmp_dir), "%s", dir != NULL ? dir : "");
    on_int_term(on_stop_signal);
}

typedef struct tsv_ctx {
    FILE *out;
    bool live;      /* flush each line: a live reader wants it at once */
    char sec_txt[20]; /* the digits of `sec` */
    size_t sec_len; /* their number, 0 before the first line */
    uint64_t sec;
    char mac_tab[FEED_MAX_MACS][18]; /* each --mac as format_mac writes it */
    size_t n;       /* bytes of lines in buf, not yet handed to out */
    char buf[1 << 16];
} tsv_ctx_t;

/* Hand the buffered lines to c->out (and, live, flush it): 0, or 1 when that failed. */
static int tsv_flush(tsv_ctx_t *c)
{
    const size_t n = c->n;
    c->n = 0;
    if (fwrite_unlocked(c->buf, 1, n, c->out) != n) { return 1; } /* one thread: no locks */
    return c->live && fflush(c->out) != 0 ? 1 : 0;
}

static int tsv_line(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f)
{
    tsv_ctx_t *c = ctx;
    if (c->sec_len == 0u || c->sec != pkt->ts_sec) { /* about once a second of capture */
        c->sec = pkt->ts_sec;
        c->sec_len = format_sec(c->sec_txt, pkt->ts_sec);
    }
    char *o = c->buf + c->n; /* room for a line: flushed below 128 bytes from the end */
    memcpy(o, c->sec_txt, sizeof(c->sec_txt));
    c->n += c->sec_len + format_line(o + c->sec_len, pkt->ts_nsec, c->mac_tab[m], f->rt.dbm_signal);
    /* Live, a lost line ends the reading (a batch's table is checked at the end). */
    return c->live || c->n > sizeof(c->buf) - 128u ? tsv_flush(c) : 0;
}

/* The TSV lines (or with list the survey, scan_list) into stdout or output. */
static int run_tsv(lx_pcap_reader_t *r, const char *output, bool live, bool list, const uint8_t (*macs)[6],
                   int n_macs, feed_stats_t *st)
{
    char *tmp = NULL;
    FILE *out = stdout;
    if (output != NULL) {
        const size_t n = strlen(output);
        tmp = malloc(n + 5);
        if (tmp == NULL) { fprintf(stderr, "rfseek-feed: out of memory\n"); return 1; }
        memcpy(tmp, output, n);
        memcpy(tmp + n, ".tmp", 5);
        const char *names[1] = {tmp};
        if (!live) { /* live, a signal is the end: the file is renamed into place */
            cleanup_on_signal(NULL, names, 1);
        }
        out = fopen(tmp, "w");
        if (out == NULL) {
            fprintf(stderr, "rfseek-feed: %s: cannot create: %s\n", tmp, strerror(errno));
            free(tmp);
            return 1;
        }
    }
    static char obuf[1 << 16];
    setvbuf(out, obuf, _IOFBF, sizeof(obuf));
    static tsv_ctx_t c;
    c.out = out;
    c.live = live;
    c.sec_len = 0u;
    c.n = 0u;
    for (int m = 0; m < n_macs; m++) { format_mac(c.mac_tab[m], macs[m]); } /* = the SA of its lines */
    int rc = list ? scan_list(r, macs, n_macs, st, out) : scan_capture(r, macs, n_macs, st, tsv_line, &c, NULL, NULL);
    if (tsv_flush(&c) != 0) {
        rc = 1; /* the stream's error is reported below */
    }
    if (output != NULL && (fflush(out) != 0 || ferror(out))) {
        fprintf(stderr, "rfseek-feed: %s: write error: %s\n", tmp, strerror(errno));
        rc = 1;
    }
    if (output == NULL && ferror(out)) {
        rc = 1; /* reported once, by lx_err_close_stdout */
    }
    if (output != NULL) {
        if (fclose(out) != 0) { rc = 1; }
        if (rc == 0 && rename(tmp, output) != 0) {
            fprintf(stderr, "rfseek-feed: %s: cannot rename to %s: %s\n", tmp, output, strerror(errno));
            rc = 1;
        }
        if (rc != 0) { (void)remove(tmp); }
        free(tmp);
    }
    return rc;
}

/* --- live to the controller (--live --lcm) ------------------------------------------- */

/* The feed, and whether a refusal was reported (once: the counts say how many). */
typedef struct lcm_ctx {
    lx_feed_t feed;
    bool told;
} lcm_ctx_t;

static void lcm_refused(lcm_ctx_t *c, const char *what)
{
    if (!c->told) {
        fprintf(stderr, "rfseek-feed: LCM refused %s (counted; the feed goes on)\n", what);
        c->told = true;
    }
}

static int lcm_frame(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f)
{
    lcm_ctx_t *c = ctx;
    if (lx_feed_frame(&c->feed, (uint8_t)m, pkt->t_us, f->rt.dbm_signal, f->wlan.seq) != 0) {
        lcm_refused(c, "an RFS_RSSI message");
    }
    return 0;
}

static int lcm_alive(void *ctx, int64_t t_us)
{
    lcm_ctx_t *c = ctx;
    if (lx_feed_alive(&c->feed, t_us) < 0) {
        lcm_refused(c, "a heartbeat");
    }
    return 0;
}

/* The LCM connection for --lcm: NULL after a message. */
static lx_lcm_t *open_lcm(const char *url)
{
    char err[1024];
    lx_lcm_t *l = lx_lcm_open(url, NULL, err, sizeof(err));
    if (err[0] != '\0') { /* the reason, or liblcm's warning: one line (lx_lcm.h) */
        fprintf(stderr, "rfseek-feed: %s\n", err);
    }
    return l;
}

/* Publish the live interface's matching frames and heartbeats on l until SIGINT or
 * SIGTERM (or a read error): 0, or 1 after a message. */
static int run_lcm(lx_pcap_reader_t *r, lx_lcm_t *l, const uint8_t (*macs)[6], int n_macs, feed_stats_t *st)
{
    static lcm_ctx_t c;
    memset(&c, 0, sizeof(c));
    lx_feed_init(&c.feed, l);
    const int rc = scan_capture(r, macs, n_macs, st, lcm_frame, &c, lcm_alive, &c);
    st->heartbeats = c.feed.st.heartbeats;
    st->refused = c.feed.st.refused;
    return rc;
}

/* --- replay mode (--pose, hs_replay.h) ----------------------------------------------- */

static int rp_collect(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f)
{
    const hs_replay_frame_t fr = {pkt->t_us, (uint8_t)m, f->rt.dbm_signal,
                                  (uint16_t)(f->wlan.seq << 4 | f->wlan.frag)};
    return hs_replay_frame(ctx, &fr);
}

static int rp_alive(void *ctx, int64_t t_us)
{
    return hs_replay_alive(ctx, t_us);
}

/* Replay the capture and the poses through the controller into o->out. */
static int run_replay(const hs_replay_opts_t *o, lx_pcap_reader_t *r, uint8_t (*macs)[6], int n_macs,
                      feed_stats_t *st)
{
    hs_replay_t *rp = NULL;
    int rc = hs_replay_open(o, macs, n_macs, &rp);
    if (rc != 0) {
        return rc;
    }
    if (scan_capture(r, (const uint8_t(*)[6])macs, hs_replay_sources(rp), st, rp_collect, rp,
                     hs_replay_heartbeats(rp) ? rp_alive : NULL, rp) != 0) {
        hs_replay_free(rp);
        return 1;
    }
    return hs_replay_run(rp, cleanup_on_signal, &st->replay_before, &st->replay_after);
}

/* An option error with the offending value: one line on stderr even when the value holds
 * a line break (shown as '?'). fmt has one %s. */
static void opt_err(const char *fmt, const char *v)
{
    char msg[512];
    snprintf(msg, sizeof msg, fmt, v);
    lx_err_one_line(msg);
    fprintf(stderr, "rfseek-feed: %s\n", msg);
}

/* The command line. */
typedef struct feed_opts {
    hs_replay_opts_t ro;                    /* the capture, and the replay's options */
    const char *output;              /* --output, or NULL: stdout */
    const char *lcm;                 /* --lcm URL (with --live), or NULL */
    uint8_t macs[FEED_MAX_MACS][6];
    int n_macs;
    bool stats;
    bool live;
    bool list;                       /* --list: the survey */
} feed_opts_t;

enum { RUN = -1 }; /* parse_options: go on (else the exit status) */

/* One option a that takes a value v: RUN, or the exit status after a message. */
static int parse_value(feed_opts_t *fo, const char *a, const char *v)
{
    hs_replay_opts_t *ro = &fo->ro;
    if (strcmp(a, "--mac") == 0) {
        if (fo->n_macs == FEED_MAX_MACS) {
            fprintf(stderr, "rfseek-feed: --mac: at most %d addresses\n", FEED_MAX_MACS);
            return 2;
        }
        if (parse_mac(v, fo->macs[fo->n_macs]) != 0) {
            opt_err("--mac: '%s' is not a MAC address (aa:bb:cc:dd:ee:ff)", v);
            return 2;
        }
        fo->n_macs++;
    } else if (strcmp(a, "--format") == 0) {
        if (strcmp(v, "tsv") != 0) {
            opt_err("--format: '%s' is not supported (tsv)", v);
            return 2;
        }
    } else if (*v == '\0' && strcmp(a, "--seed") != 0) { /* "" --lcm: liblcm's default */
        opt_err("%s: empty value (see --help)", a);
        return 2;
    } else if ((strcmp(a, "--output") == 0 || strcmp(a, "--pose") == 0 || strcmp(a, "--scenario") == 0 ||
                strcmp(a, "--out") == 0) &&
               lx_err_path_opt("rfseek-feed", a, v) != 0) {
        return 2;
    } else if (strcmp(a, "--output") == 0) {
        fo->output = v;
    } else if (strcmp(a, "--lcm") == 0) {
        fo->lcm = v;
    } else if (strcmp(a, "--pose") == 0) {
        ro->poses = v;
    } else if (strcmp(a, "--scenario") == 0) {
        ro->scenario = v;
    } else if (strcmp(a, "--out") == 0) {
        ro->out = v;
    } else if (strcmp(a, "--model") == 0) {
        if (rfs_models_lookup(v) == NULL) {
            opt_err("--model: unknown '%s' (ridge, mlp, knn, radius, pathloss)", v);
            return 2;
        }
        ro->model = v;
    } else if (strcmp(a, "--target") == 0) {
        if (strcmp(v, "rssi") != 0 && strcmp(v, "pdr") != 0) {
            opt_err("--target: unknown '%s' (rssi, pdr)", v);
            return 2;
        }
        ro->target = v;
    } else {
        char *e = NULL;
        errno = 0;
        ro->seed = strtoull(v, &e, 10);
        if (e == v || *e != '\0' || errno != 0 || v[0] == '-') {
            opt_err("--seed: '%s' is not a non-negative integer", v);
            return 2;
        }
        ro->has_seed = true;
    }
    return RUN;
}

/* The options that go together, checked: RUN, or the exit status after a message. */
static int check_options(const feed_opts_t *fo)
{
    const hs_replay_opts_t *ro = &fo->ro;
    const bool replay = ro->poses != NULL;
    if (ro->capture == NULL) {
        fprintf(stderr, "rfseek-feed: no CAPTURE given (see --help)\n");
        return 2;
    }
    if (replay && (ro->scenario == NULL || ro->out == NULL)) {
        fprintf(stderr, "rfseek-feed: --pose needs --scenario and --out (see --help)\n");
        return 2;
    }
    if (!replay && (ro->scenario != NULL || ro->out != NULL || ro->has_seed || ro->model != NULL ||
                    ro->target != NULL)) {
        fprintf(stderr, "rfseek-feed: --scenario, --out, --seed, --model and --target only go with --pose "
                        "(see --help)\n");
        return 2;
    }
    if (replay && (fo->output != NULL || fo->live)) {
        fprintf(stderr, "rfseek-feed: --output and --live do not go with --pose (see --help)\n");
        return 2;
    }
    if (fo->lcm != NULL && (!fo->live || fo->output != NULL)) {
        fprintf(stderr, "rfseek-feed: --lcm publishes a live interface: needs --live, not with --output "
                        "(see --help)\n");
        return 2;
    }
    if (fo->list && (replay || fo->live)) {
        fprintf(stderr, "rfseek-feed: --list reads a capture file: not with --pose or --live (see --help)\n");
        return 2;
    }
    if (!replay && !fo->list && fo->n_macs == 0) {
        fprintf(stderr, "rfseek-feed: no --mac given (see --help)\n");
        return 2;
    }
    return RUN;
}

/* The command line into *fo: RUN, or the exit status (--help, a bad option). */
static int parse_options(int argc, char **argv, feed_opts_t *fo)
{
    static const char *const k_valued[] = {"--mac",  "--format", "--output", "--pose",  "--scenario",
                                           "--out",  "--seed",   "--model",  "--target", "--lcm"};
    memset(fo, 0, sizeof(*fo));
    fo->ro.prog = "rfseek-feed";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool valued = false;
        for (size_t k = 0; k < sizeof(k_valued) / sizeof(k_valued[0]); k++) {
            valued = valued || strcmp(a, k_valued[k]) == 0;
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(k_usage, stdout);
            return 0;
        } else if (valued) {
            if (i + 1 >= argc) {
                fprintf(stderr, "rfseek-feed: %s needs a value (see --help)\n", a);
                return 2;
            }
            const int rc = parse_value(fo, a, argv[++i]);
            if (rc != RUN) {
                return rc;
            }
        } else if (strcmp(a, "--stats") == 0) {
            fo->stats = true;
        } else if (strcmp(a, "--live") == 0) {
            fo->live = true;
        } else if (strcmp(a, "--list") == 0) {
            fo->list = true;
        } else if (a[0] == '-' && a[1] != '\0') {
            opt_err("unknown option '%s' (see --help)", a);
            return 2;
        } else if (fo->ro.capture == NULL) {
            fo->ro.capture = a;
        } else {
            fprintf(stderr, "rfseek-feed: more than one capture given ('%s' and '%s')\n", fo->ro.capture, a);
            return 2;
        }
    }
    return check_options(fo);
}

/* After a complete TSV or --list run: a warning line for each --mac no frame came from
 * (by source address; --list: transmitter address) and exit status 3, else 0. */
static int warn_unheard(const feed_opts_t *fo, const feed_stats_t *st)
{
    int rc = 0;
    for (int m = 0; m < fo->n_macs; m++) {
        if (st->mac_frames[m] == 0u) {
            const uint8_t *a = fo->macs[m];
            char msg[600];
            snprintf(msg, sizeof msg, "rfseek-feed: warning: %s: no frame from %02x:%02x:%02x:%02x:%02x:%02x",
                     fo->ro.capture, a[0], a[1], a[2], a[3], a[4], a[5]);
            lx_err_one_line(msg);
            fprintf(stderr, "%s\n", msg);
            rc = 3;
        }
    }
    return rc;
}

static int feed_main(int argc, char **argv)
{
    static feed_opts_t fo;
    int rc = parse_options(argc, argv, &fo);
    if (rc != RUN) {
        return rc;
    }
    // Outputs checked before the capture is read: not an input, their directory there,
    // no directory at --out (rfseek-sim's rule: the run's files never mix with others).
    const char *ins[3] = {fo.ro.capture, fo.ro.poses, fo.ro.scenario};
    const char *outs[2] = {fo.output, fo.ro.out};
    struct stat st_out;
    if (fo.ro.out != NULL && lstat(fo.ro.out, &st_out) == 0) {
        opt_err("%s: already exists (choose a new --out directory)", fo.ro.out);
        return 1;
    }
    for (int i = 0; i < 2; i++) {
        for (int k = 0; outs[i] != NULL && k < 3; k++) {
            if (lx_err_same_file("rfseek-feed", ins[k], outs[i]) != 0) {
                return 1;
            }
        }
        if (outs[i] != NULL && lx_err_check_dest("rfseek-feed", outs[i]) != 0) {
            return 1;
        }
    }
    /* LCM before the interface: a bad URL is an option's error, whatever the interface. */
    lx_lcm_t *lcm = fo.lcm != NULL ? open_lcm(fo.lcm) : NULL;
    if (fo.lcm != NULL && lcm == NULL) {
        return 1;
    }
    char err[512];
    lx_pcap_reader_t *r = fo.live ? lx_pcap_open_live(fo.ro.capture, err, sizeof(err))
                                  : lx_pcap_open_offline(fo.ro.capture, err, sizeof(err));
    if (r == NULL) {
        lx_err_one_line(err);
        fprintf(stderr, "rfseek-feed: %s\n", err);
        lx_lcm_close(lcm);
        return 1;
    }
    if (fo.live) {
        live_stop_on_signal();
    }
    feed_stats_t st;
    memset(&st, 0, sizeof(st));
    st.count_all = fo.stats;
    const uint8_t(*macs)[6] = (const uint8_t(*)[6])fo.macs;
    if (fo.ro.poses != NULL) {
        rc = run_replay(&fo.ro, r, fo.macs, fo.n_macs, &st);
    } else if (fo.lcm != NULL) {
        rc = run_lcm(r, lcm, macs, fo.n_macs, &st);
    } else {
        rc = run_tsv(r, fo.output, fo.live, fo.list, macs, fo.n_macs, &st);
    }
    lx_pcap_close(r);
    lx_lcm_close(lcm);
    if (fo.stats) { print_stats(fo.ro.capture, &st); }
    return rc == 0 && fo.ro.poses == NULL ? warn_unheard(&fo, &st) : rc;
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout("rfseek-feed", feed_main(argc, argv));
}
