/* rfseek-feed - RSSI of chosen transmitters from an 802.11 radiotap capture (issue 5).
 *
 * Prints one line per frame whose source address (Wireshark's wlan.sa) is one of the
 * --mac addresses and whose radiotap header carries a dBm antenna signal:
 *   epoch_seconds<TAB>source_mac<TAB>dbm
 * with the epoch printed as tshark prints frame.time_epoch (9 decimals), so the output
 * equals `tshark -r CAPTURE -Y 'wlan.sa == MAC' -T fields -e frame.time_epoch -e wlan.sa
 * -e radiotap.dbm_antsignal -E occurrence=f` for the frames that have a signal.
 *
 * With --pose it replays a real experiment offline instead: the matching frames and the
 * recorded poses go, in time order, through the same in-process controller over the core
 * (rfs_seek) as the simulator uses, and the simulator's log.tsv, samples.tsv, track.tsv
 * and summary.json are written (docs/FEEDER.md).
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hs_ctrl.h"
#include "hs_pcap.h"
#include "hs_radiotap.h"
#include "hs_scenario.h"
#include "hs_sim.h"

#define FEED_MAX_MACS 8

static const char k_usage[] =
    "usage: rfseek-feed CAPTURE --mac MAC [--mac MAC2 ...] [--format tsv] [--stats]\n"
    "                   [--output FILE] [--live]\n"
    "       rfseek-feed CAPTURE --pose POSES.csv --scenario SCENARIO.yaml --out DIR\n"
    "                   [--mac MAC ...] [--seed N] [--stats]\n"
    "Print epoch_seconds<TAB>source_mac<TAB>dbm for every 802.11 frame in CAPTURE (a .pcap\n"
    "or .pcapng with radiotap headers, link type 127) whose source address (as tshark's\n"
    "wlan.sa) is one of the MACs and that carries a dBm antenna signal (the combined value\n"
    "when per-chain values follow).\n"
    "  --mac MAC      aa:bb:cc:dd:ee:ff; repeat for up to 8 transmitters\n"
    "  --format tsv   output format (tsv is the only one)\n"
    "  --stats        print packet counts (parsed, skipped and why) to stderr\n"
    "  --output FILE  write to FILE (via FILE.tmp, renamed only on success)\n"
    "  --live         CAPTURE is a monitor-mode interface; read until interrupted\n"
    "  --pose POSES   replay: CSV with the header t_us,x_m,y_m,theta_rad (capture clock,\n"
    "                 microseconds since the epoch; map frame, metres, radians), increasing\n"
    "                 times; packets and poses go through the seeker (rfs_seek) offline\n"
    "  --scenario F   replay: the simulator scenario giving the map, model, target, goal and\n"
    "                 the sources (their MACs, in order, unless --mac names them)\n"
    "  --out DIR      replay: write log.tsv, samples.tsv, track.tsv, summary.json (as\n"
    "                 rfseek-sim) into DIR (via DIR.tmp-PID, renamed when complete)\n"
    "  --seed N       replay: seed of the controller's randomness (default: the scenario's)\n"
    "  --help         this text\n"
    "Exit 0 on success, 1 on a bad capture or I/O error, 2 on bad options.\n";

/* Counts reported by --stats. */
typedef struct feed_stats {
    uint64_t packets;                 /* records read */
    uint64_t rt_bad[HS_RT_N_STATUS]; /* per radiotap status */
    uint64_t no_wlan;                 /* nothing after the radiotap header */
    uint64_t no_sa;                   /* 802.11 header without a source address */
    uint64_t sa_match;                /* SA is one of the MACs */
    uint64_t no_signal;               /* ... but no dBm antenna signal */
    uint64_t lines;                   /* lines printed */
    uint64_t caplen_short;            /* records captured shorter than on the air */
} feed_stats_t;

static int parse_mac(const char *s, uint8_t mac[6])
{
    unsigned v[6];
    char sep[5];
    char tail;
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
static size_t format_line(char *out, int64_t t_ns, const uint8_t mac[6], int dbm)
{
    static const char hex[] = "0123456789abcdef";
    char tmp[24];
    size_t n = 0;
    uint64_t sec = (uint64_t)(t_ns / 1000000000);
    uint64_t frac = (uint64_t)(t_ns % 1000000000);
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
    for (int s = HS_RT_STOP_UNKNOWN; s < HS_RT_N_STATUS; s++) {
        if (st->rt_bad[s] != 0) {
            fprintf(stderr, "; %llu %s %s", (unsigned long long)st->rt_bad[s],
                    s >= HS_RT_ERR_SHORT ? "skipped:" : "note:", hs_radiotap_status_str((hs_rt_status_t)s));
        }
    }
    const struct { uint64_t n; const char *what; } rest[] = {
        {st->no_wlan, "skipped: no 802.11 header"},
        {st->no_sa, "skipped: no source address"},
        {st->no_signal, "skipped: matching source without dBm signal"},
        {st->caplen_short, "note: cut by the snap length"},
    };
    for (size_t i = 0; i < sizeof(rest) / sizeof(rest[0]); i++) {
        if (rest[i].n != 0) { fprintf(stderr, "; %llu %s", (unsigned long long)rest[i].n, rest[i].what); }
    }
    fputc('\n', stderr);
}

int main(int argc, char **argv)
{
    const char *capture = NULL;
    const char *output = NULL;
    uint8_t macs[FEED_MAX_MACS][6];
    int n_macs = 0;
    bool stats = false;
    bool live = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(k_usage, stdout);
            return 0;
        } else if (strcmp(a, "--mac") == 0 || strcmp(a, "--format") == 0 || strcmp(a, "--output") == 0) {
            if (i + 1 >= argc) {
                fprintf(stderr, "rfseek-feed: %s needs a value (see --help)\n", a);
                return 2;
            }
            const char *v = argv[++i];
            if (strcmp(a, "--mac") == 0) {
                if (n_macs == FEED_MAX_MACS) {
                    fprintf(stderr, "rfseek-feed: --mac: at most %d addresses\n", FEED_MAX_MACS);
                    return 2;
                }
                if (parse_mac(v, macs[n_macs]) != 0) {
                    fprintf(stderr, "rfseek-feed: --mac: '%s' is not a MAC address (aa:bb:cc:dd:ee:ff)\n", v);
                    return 2;
                }
                n_macs++;
            } else if (strcmp(a, "--format") == 0) {
                if (strcmp(v, "tsv") != 0) {
                    fprintf(stderr, "rfseek-feed: --format: '%s' is not supported (tsv)\n", v);
                    return 2;
                }
            } else {
                output = v;
            }
        } else if (strcmp(a, "--stats") == 0) {
            stats = true;
        } else if (strcmp(a, "--live") == 0) {
            live = true;
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "rfseek-feed: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (capture == NULL) {
            capture = a;
        } else {
            fprintf(stderr, "rfseek-feed: more than one capture given ('%s' and '%s')\n", capture, a);
            return 2;
        }
    }
    if (capture == NULL || n_macs == 0) {
        fprintf(stderr, "rfseek-feed: %s (see --help)\n", capture == NULL ? "no CAPTURE given" : "no --mac given");
        return 2;
    }

    char err[512];
    hs_pcap_reader_t *r = live ? hs_pcap_open_live(capture, err, sizeof(err))
                               : hs_pcap_open_offline(capture, err, sizeof(err));
    if (r == NULL) {
        fprintf(stderr, "rfseek-feed: %s\n", err);
        return 1;
    }
    char *tmp = NULL;
    FILE *out = stdout;
    if (output != NULL) {
        const size_t n = strlen(output);
        tmp = malloc(n + 5);
        if (tmp == NULL) { hs_pcap_close(r); fprintf(stderr, "rfseek-feed: out of memory\n"); return 1; }
        memcpy(tmp, output, n);
        memcpy(tmp + n, ".tmp", 5);
        out = fopen(tmp, "w");
        if (out == NULL) {
            fprintf(stderr, "rfseek-feed: %s: cannot create: %s\n", tmp, strerror(errno));
            hs_pcap_close(r);
            free(tmp);
            return 1;
        }
    }
    static char obuf[1 << 16];
    setvbuf(out, obuf, _IOFBF, sizeof(obuf));

    feed_stats_t st;
    memset(&st, 0, sizeof(st));
    int rc = 0;
    for (;;) {
        hs_pcap_pkt_t pkt;
        const int got = hs_pcap_next(r, &pkt, err, sizeof(err));
        if (got == 2) { fflush(out); continue; }
        if (got == 0) { break; }
        if (got < 0) {
            fprintf(stderr, "rfseek-feed: %s (after %llu packets)\n", err, (unsigned long long)st.packets);
            rc = 1;
            break;
        }
        st.packets++;
        if (pkt.caplen < pkt.origlen) { st.caplen_short++; }
        hs_rt_frame_t f;
        if (hs_rt_frame_parse(pkt.data, pkt.caplen, &f) != 0) {
            st.rt_bad[f.rt.status]++;
            continue;
        }
        st.rt_bad[f.rt.status]++;
        if (!f.wlan_ok) { st.no_wlan++; continue; }
        if (!f.wlan.has_sa) { st.no_sa++; continue; }
        int m = 0;
        while (m < n_macs && memcmp(macs[m], f.wlan.sa, 6) != 0) { m++; }
        if (m == n_macs) { continue; }
        st.sa_match++;
        if (!f.rt.has_dbm_signal) { st.no_signal++; continue; }
        char line[64];
        const size_t len = format_line(line, pkt.t_ns, f.wlan.sa, f.rt.dbm_signal);
        fwrite(line, 1, len, out);
        st.lines++;
    }
    hs_pcap_close(r);
    if (fflush(out) != 0 || ferror(out)) {
        fprintf(stderr, "rfseek-feed: %s: write error: %s\n", output != NULL ? tmp : "stdout", strerror(errno));
        rc = 1;
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
    if (stats) { print_stats(capture, &st); }
    return rc;
}
