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
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "hs_ctrl.h"
#include "hs_poses.h"
#include "lx_err.h"
#include "lx_feed.h"
#include "lx_lcm.h"
#include "lx_pcap.h"
#include "lx_radiotap.h"
#include "hs_scenario.h"
#include "hs_sim.h"
#include "hs_survey.h"
#include "rfs_models.h"
#include "rfs_pdr.h"

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
    "  --help         this text\n"
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

/* "<sec>.<9 digits>\t<mac>\t<dbm>\n" into out; returns its length. Hand-formatted: this
 * is the inner loop of the bench (millions of lines). */
static size_t format_line(char *out, uint64_t sec, uint32_t frac, const uint8_t mac[6], int dbm)
{
    static const char hex[] = "0123456789abcdef";
    char tmp[24];
    size_t n = 0;
    int k = 0;
    do { tmp[k++] = (char)('0' + sec % 10u); sec /= 10u; } while (sec != 0u);
    while (k > 0) { out[n++] = tmp[--k]; }
    out[n++] = '.';
    for (int i = 8; i >= 0; i--) { out[n + (size_t)i] = (char)('0' + frac % 10u); frac /= 10u; }
    n += 9;
    out[n++] = '\t';
    for (int i = 0; i < 6; i++) {
        out[n++] = hex[mac[i] >> 4];
        out[n++] = hex[mac[i] & 15u];
        out[n++] = i < 5 ? ':' : '\t';
    }
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

/* A live run ends at SIGINT or SIGTERM like a capture file at its end: nothing removed. */
static void live_stop_on_signal(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_live_stop;
    sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
}

/* A live capture's clock: the kernel stamps packets with CLOCK_REALTIME. */
static int64_t realtime_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* The next record whose radiotap header parsed (with bad_rt, or was unusable but located
 * the 802.11 frame: counted in st->rt_kept) and an 802.11 header followed, in *pkt and *f;
 * alive (when not NULL) is called for every record read and, live, after every wait
 * without one (at the clock's time), and why a record gives nothing is counted in st. 1,
 * 0 at the end (live: SIGINT or SIGTERM), -1 after a read error (message on stderr) or
 * when alive failed. */
static int next_frame(lx_pcap_reader_t *r, feed_stats_t *st, lx_pcap_pkt_t *pkt, lx_rt_frame_t *f,
                      bool bad_rt, alive_fn alive, void *alive_ctx)
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
        const int prc = lx_rt_frame_parse(pkt->data, pkt->caplen, f);
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
        const int got = next_frame(r, st, &pkt, &f, false, alive, alive_ctx);
        if (got <= 0) { return got < 0 ? 1 : 0; }
        if (!f.wlan.has_sa) { st->no_sa++; continue; }
        int m = 0;
        while (m < n_macs && memcmp(macs[m], f.wlan.sa, 6) != 0) { m++; }
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
        const int got = rc == 0 ? next_frame(r, st, &pkt, &f, true, NULL, NULL) : 0;
        if (got <= 0) {
            rc = got < 0 ? 1 : rc;
            break;
        }
        if (!f.wlan.has_ta) { st->no_ta++; continue; }
        int m = 0;
        while (m < n_macs && memcmp(macs[m], f.wlan.ta, 6) != 0) { m++; }
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
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
}

typedef struct tsv_ctx {
    FILE *out;
    bool live; /* flush each line: a live reader wants it at once */
} tsv_ctx_t;

static int tsv_line(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f)
{
    tsv_ctx_t *c = ctx;
    (void)m;
    char line[64];
    const size_t len = format_line(line, pkt->ts_sec, pkt->ts_nsec, f->wlan.sa, f->rt.dbm_signal);
    fwrite(line, 1, len, c->out);
    /* Live, a lost line ends the reading (a batch's table is checked at the end). */
    return c->live && fflush(c->out) != 0 ? 1 : 0;
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
    tsv_ctx_t c = {out, live};
    int rc = list ? scan_list(r, macs, n_macs, st, out) : scan_capture(r, macs, n_macs, st, tsv_line, &c, NULL, NULL);
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

/* --- replay mode (--pose) ------------------------------------------------------------ */

typedef struct rp_pkt {
    int64_t t_us; /* capture clock, microseconds since the epoch */
    uint8_t src;  /* source index (scenario order) */
    int8_t dbm;   /* first (combined) dBm antenna signal */
    uint16_t seq_ctrl; /* 802.11 Sequence Control: number << 4 | fragment */
} rp_pkt_t;

typedef struct rp_vec {
    rp_pkt_t *v;
    size_t n, cap;
} rp_vec_t;

static int rp_collect(void *ctx, int m, const lx_pcap_pkt_t *pkt, const lx_rt_frame_t *f)
{
    rp_vec_t *vec = ctx;
    if (vec->n == vec->cap) {
        const size_t cap = vec->cap ? vec->cap * 2 : 1024;
        rp_pkt_t *nv = realloc(vec->v, cap * sizeof(*nv));
        if (nv == NULL) { fprintf(stderr, "rfseek-feed: out of memory\n"); return 1; }
        vec->v = nv;
        vec->cap = cap;
    }
    vec->v[vec->n++] = (rp_pkt_t){pkt->t_us, (uint8_t)m, f->rt.dbm_signal,
                                  (uint16_t)(f->wlan.seq << 4 | f->wlan.frag)};
    return 0;
}

/* Receiver heartbeat times (docs/FAULTS.md, "The receiver heartbeat"): every record the
 * capture loop reads proves it alive at that record's time, whoever sent it; heartbeats
 * spaced as the live feed spaces them (lx_feed_hb_due). */
typedef struct rp_times {
    int64_t *v;
    size_t n, cap;
    lx_feed_hb_t rule;
} rp_times_t;

static int rp_alive(void *ctx, int64_t t_us)
{
    rp_times_t *hb = ctx;
    if (!lx_feed_hb_due(&hb->rule, t_us)) {
        return 0;
    }
    if (hb->n == hb->cap) {
        const size_t cap = hb->cap ? hb->cap * 2 : 1024;
        int64_t *nv = realloc(hb->v, cap * sizeof(*nv));
        if (nv == NULL) { fprintf(stderr, "rfseek-feed: out of memory\n"); return 1; }
        hb->v = nv;
        hb->cap = cap;
    }
    hb->v[hb->n++] = t_us;
    return 0;
}

static rfs_q16_t rp_q16(double v) { return (rfs_q16_t)llround(v * 65536.0); }

static double rp_d(rfs_q16_t v) { return (double)v / 65536.0; }

/* Same names as the simulator's log. */
static const char *rp_kind(rfs_seek_kind_t k)
{
    switch (k) {
    case RFS_SEEK_INITIAL: return "initial";
    case RFS_SEEK_GREEDY: return "greedy";
    case RFS_SEEK_EPSILON: return "epsilon";
    default: return "none";
    }
}

static const char *rp_prev(rfs_drive_status_t s)
{
    switch (s) {
    case RFS_DRIVE_REACHED: return "reached";
    case RFS_DRIVE_TIMEOUT: return "timeout";
    case RFS_DRIVE_BLOCKED: return "blocked";
    case RFS_DRIVE_RUNNING: return "running";
    default: return "start";
    }
}

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

typedef struct rp_opts {
    const char *capture, *poses, *scenario, *out;
    const char *model, *target; /* overrides of the scenario's, or NULL */
    bool has_seed;
    uint64_t seed;
} rp_opts_t;

/* One replay: the scenario, the recorded inputs, the controller and the outputs. */
typedef struct replay {
    const rp_opts_t *o;
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
    bool seen[FEED_MAX_MACS];
    uint16_t last_seq[FEED_MAX_MACS];
    uint64_t lost;
    /* Target "pdr": one delivery window (1 s) per source, fed from Sequence Control. */
    rfs_pdr_t pdr[FEED_MAX_MACS];
} replay_t;

/* The robot at an event: its recorded pose interpolated, and the distance travelled. */
typedef struct rp_at {
    int64_t te;            /* microseconds from the first pose */
    double ex, ey, eth;    /* metres, radians */
    double etr;            /* metres */
} rp_at_t;

/* The scenario with the options' overrides, and the MACs of its sources (unless given):
 * 0, or the exit status after a message. */
static int rp_scenario(replay_t *rp, uint8_t (*macs)[6], int n_macs)
{
    const rp_opts_t *o = rp->o;
    hs_scenario_t *sc = &rp->sc;
    char err[1200];
    if (hs_scenario_load(o->scenario, sc, err, sizeof(err)) != 0) {
        fprintf(stderr, "rfseek-feed: %s\n", err);
        return 1;
    }
    if (o->model != NULL) { snprintf(sc->model, sizeof(sc->model), "%s", o->model); }
    if (o->target != NULL) {
        if (sc->nsources != 1) {
            fprintf(stderr, "rfseek-feed: --target: %s needs exactly 1 source, scenario %s has %u\n",
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
        fprintf(stderr, "rfseek-feed: --mac: %d addresses given, scenario %s has %u sources\n", n_macs,
                o->scenario, sc->nsources);
        return 2;
    }
    rp->n_macs = n_macs;
    return 0;
}

/* The poses, the capture's frames and heartbeats, the environment and the controller:
 * 0, or 1 after a message. */
static int rp_open_inputs(replay_t *rp, lx_pcap_reader_t *r, uint8_t (*macs)[6], feed_stats_t *st)
{
    const rp_opts_t *o = rp->o;
    char err[1200];
    if (hs_poses_load(o->poses, &rp->poses, &rp->n_poses, err, sizeof(err)) != 0) {
        fprintf(stderr, "rfseek-feed: %s\n", err);
        return 1;
    }
    if (scan_capture(r, (const uint8_t(*)[6])macs, rp->n_macs, st, rp_collect, &rp->pk,
                     rp->sc.rx_heartbeat ? rp_alive : NULL, &rp->hb) != 0) {
        return 1;
    }
    if (hs_sim_env_open(&rp->env, &rp->sc, err, sizeof(err)) != 0) {
        fprintf(stderr, "rfseek-feed: %s\n", err);
        return 1;
    }
    rp->env_open = true;
    hs_ctrl_inproc_cfg_t cc = hs_ctrl_inproc_cfg_default();
    cc.model = rp->sc.model;
    cc.target = rp->sc.target;
    cc.seed = o->has_seed ? o->seed : rp->sc.seed;
    char cerr[256];
    if (hs_ctrl_inproc_open(&rp->ctrl, &cc, &rp->env.core.map, cerr, sizeof(cerr)) != 0) {
        fprintf(stderr, "rfseek-feed: %s: %s\n", o->scenario, cerr);
        return 1;
    }
    rp->ctrl_open = true;
    memset(&rp->res, 0, sizeof(rp->res));
    rp->res.seed = cc.seed;
    return 0;
}

/* The output directory (a temporary one) and its three logs: 0, or 1 after a message. */
static int rp_open_outputs(replay_t *rp)
{
    snprintf(rp->tmp, sizeof(rp->tmp), "%s.tmp-%ld", rp->o->out, (long)getpid());
    cleanup_on_signal(rp->tmp, k_rp_files, (int)(sizeof(k_rp_files) / sizeof(k_rp_files[0])));
    if (mkdir(rp->tmp, 0777) != 0) {
        fprintf(stderr, "rfseek-feed: %s: cannot create: %s\n", rp->tmp, strerror(errno));
        return 1;
    }
    rp->flog = rp_open(rp->tmp, "log.tsv");
    rp->fsam = rp_open(rp->tmp, "samples.tsv");
    rp->ftrk = rp_open(rp->tmp, "track.tsv");
    if (rp->flog == NULL || rp->fsam == NULL || rp->ftrk == NULL) {
        fprintf(stderr, "rfseek-feed: %s: cannot create the logs: %s\n", rp->tmp, strerror(errno));
        return 1;
    }
    return 0;
}

/* A matching frame: counted (sequence gaps), and fed to the controller (as its PDR with
 * target pdr) and to samples.tsv. */
static void rp_packet(replay_t *rp, const rp_pkt_t *p, const rp_at_t *at)
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
static void rp_pose(replay_t *rp, const hs_pose_rec_t *q, int64_t te)
{
    rfs_pose_t pose = {te, rp_q16(q->x), rp_q16(q->y), rp_q16(hs_poses_wrap(q->theta))};
    rp->ctrl.on_pose(rp->ctrl.self, &pose);
    fprintf(rp->ftrk, "%.3f\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%.4f\t0\n", te * 1e-6, q->x, q->y,
            hs_poses_wrap(q->theta), q->x, q->y, hs_poses_wrap(q->theta));
}

/* A control period: the controller's step, its decision counted and logged (the wheel
 * commands go nowhere). */
static void rp_step(replay_t *rp, const rp_at_t *at)
{
    hs_ctrl_out_t out;
    memset(&out, 0, sizeof(out));
    rp->ctrl.step(rp->ctrl.self, at->te, &out);
    if (!out.decided) {
        return;
    }
    const rfs_seek_decision_t *d = &out.decision;
    hs_sim_result_t *res = &rp->res;
    res->iterations++;
    res->model_updates += d->relearned ? 1u : 0u;
    res->greedy += d->kind == RFS_SEEK_GREEDY ? 1u : 0u;
    res->epsilon += d->kind == RFS_SEEK_EPSILON ? 1u : 0u;
    char reason[96];
    snprintf(reason, sizeof(reason), "prev=%s%s%s%s%s", rp_prev(d->prev),
             d->line_search ? ",line_search" : "", d->sampled ? ",sampled" : "",
             d->model_valid ? "" : ",no_model",
             d->mean_valid ? "" : ",no_mean");
    fprintf(rp->flog,
            "%u\t%.3f\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\t%s\t%s\t%d\t%.3f\t%.3f\t"
            "%.4f\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%u\t%.3f",
            d->iteration, at->te * 1e-6, at->ex, at->ey, at->eth, rp_d(d->x), rp_d(d->y), rp_kind(d->kind),
            reason, d->relearned ? 1 : 0, d->model_valid ? rp_d(d->prediction) : NAN,
            d->mean_valid ? rp_d(d->mean) : NAN, rp_d(d->epsilon), rp_d(d->goal_x),
            rp_d(d->goal_y), rp_d(d->max_x), rp_d(d->max_y), rp_d(d->path_len), d->samples,
            at->etr);
    hs_sim_log_estimate(rp->flog, &rp->ctrl); /* the path-loss estimate, or nan */
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
static void rp_run(replay_t *rp)
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
static int rp_close(const replay_t *rp, FILE *f, const char *name, int rc)
{
    errno = 0;
    const bool bad = ferror(f) != 0;
    if ((fclose(f) != 0 || bad) && rc == 0) {
        fprintf(stderr, "rfseek-feed: %s/%s: write error: %s\n", rp->tmp, name,
                errno != 0 ? strerror(errno) : "write failed");
        rc = 1;
    }
    return rc;
}

/* summary.json, the logs closed, the directory renamed into place (removed on failure),
 * and everything freed: the exit status (rc: so far). */
static int rp_finish(replay_t *rp, feed_stats_t *st, int rc, bool ran)
{
    if (ran) {
        FILE *fsum = rp_open(rp->tmp, "summary.json");
        if (fsum == NULL) {
            fprintf(stderr, "rfseek-feed: %s/summary.json: %s\n", rp->tmp, strerror(errno));
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
            fprintf(stderr, "rfseek-feed: %s: cannot rename to %s: %s\n", rp->tmp, rp->o->out, strerror(errno));
            rc = 1;
        }
        if (rc != 0) { rp_rmdir(rp->tmp); }
        if (rc == 0 && st != NULL) {
            st->replay_before = rp->before;
            st->replay_after = rp->after;
        }
    }
    if (rp->ctrl_open) { hs_ctrl_close(&rp->ctrl); }
    if (rp->env_open) { hs_sim_env_close(&rp->env); }
    free(rp->poses);
    free(rp->pk.v);
    free(rp->hb.v);
    return rc;
}

/* Replay the capture and the poses through the controller into o->out (rp_run). */
static int run_replay(const rp_opts_t *o, lx_pcap_reader_t *r, uint8_t (*macs)[6], int n_macs,
                      feed_stats_t *st)
{
    static replay_t rp;
    memset(&rp, 0, sizeof(rp));
    rp.o = o;
    int rc = rp_scenario(&rp, macs, n_macs);
    if (rc != 0) {
        return rc;
    }
    if (rp_open_inputs(&rp, r, macs, st) != 0) {
        return rp_finish(&rp, st, 1, false);
    }
    rc = rp_open_outputs(&rp);
    if (rc == 0) {
        rp_run(&rp);
    }
    return rp_finish(&rp, st, rc, rc == 0);
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
    rp_opts_t ro;                    /* the capture, and the replay's options */
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
    rp_opts_t *ro = &fo->ro;
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
    const rp_opts_t *ro = &fo->ro;
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
