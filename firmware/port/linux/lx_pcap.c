/* lx_pcap.c - the one libpcap adapter: capture reader (offline/live) and writer. */
#include "lx_pcap.h"

#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>

#include <pcap/pcap.h>

struct lx_pcap_reader {
    pcap_t *p;        /* libpcap handle */
    bool live;        /* a live interface (timeouts are not the end) */
    bool classic;     /* a classic pcap file: its seconds are unsigned 32-bit */
    char name[256];   /* file or interface, for messages */
};

struct lx_pcap_writer {
    pcap_t *dead;       /* libpcap handle that only describes the format */
    pcap_dumper_t *d;   /* the open temporary file */
    char *path;         /* final name */
    char *tmp;          /* path + ".tmp" */
    bool failed;        /* a write or an argument failed: discard at close */
    uint64_t count;     /* frames written */
};

/* Fail unless the handle delivers radiotap; names the link type it has instead. */
static int check_linktype(pcap_t *p, const char *name, char *err, size_t errlen)
{
    const int lt = pcap_datalink(p);
    if (lt == DLT_IEEE802_11_RADIO) { return 0; }
    const char *lname = pcap_datalink_val_to_name(lt);
    snprintf(err, errlen, "%s: link type %d (%s) is not 127 (IEEE802_11_RADIO, radiotap)", name, lt,
             lname != NULL ? lname : "unknown");
    return -1;
}

static void copy_name(char *dst, size_t n, const char *src)
{
    snprintf(dst, n, "%s", src);
}

lx_pcap_reader_t *lx_pcap_open_offline(const char *path, char *err, size_t errlen)
{
    char ebuf[PCAP_ERRBUF_SIZE] = "";
    /* Nanosecond precision keeps a pcapng/ns file's full timestamp; a microsecond file
     * is scaled by 1000 exactly. */
    pcap_t *p = pcap_open_offline_with_tstamp_precision(path, PCAP_TSTAMP_PRECISION_NANO, ebuf);
    if (p == NULL) {
        snprintf(err, errlen, "%s: cannot read capture: %s", path, ebuf);
        return NULL;
    }
    if (check_linktype(p, path, err, errlen) != 0) {
        pcap_close(p);
        return NULL;
    }
    lx_pcap_reader_t *r = calloc(1, sizeof(*r));
    if (r == NULL) {
        pcap_close(p);
        snprintf(err, errlen, "%s: out of memory", path);
        return NULL;
    }
    r->p = p;
    r->classic = pcap_major_version(p) == 2; /* a pcapng section is version 1 */
    copy_name(r->name, sizeof(r->name), path);
    return r;
}

lx_pcap_reader_t *lx_pcap_open_live(const char *ifname, char *err, size_t errlen)
{
    char ebuf[PCAP_ERRBUF_SIZE] = "";
    pcap_t *p = pcap_create(ifname, ebuf);
    if (p == NULL) {
        snprintf(err, errlen, "%s: cannot open interface: %s", ifname, ebuf);
        return NULL;
    }
    (void)pcap_set_snaplen(p, 65535);
    (void)pcap_set_promisc(p, 1);
    /* Immediate mode: each frame as it arrives. Buffered (TPACKET_V3) the kernel hands out
     * a block only once it holds a packet, so a silent channel would never time out and
     * the reader could not say it is alive (docs/FAULTS.md, "The receiver heartbeat"). */
    (void)pcap_set_immediate_mode(p, 1);
    (void)pcap_set_tstamp_precision(p, PCAP_TSTAMP_PRECISION_NANO); /* falls back to µs */
    const int rc = pcap_activate(p);
    if (rc < 0) {
        snprintf(err, errlen, "%s: cannot activate interface: %s", ifname, pcap_geterr(p));
        pcap_close(p);
        return NULL;
    }
    /* A monitor-mode adapter may offer several link types; ask for radiotap. */
    if (pcap_datalink(p) != DLT_IEEE802_11_RADIO) { (void)pcap_set_datalink(p, DLT_IEEE802_11_RADIO); }
    if (check_linktype(p, ifname, err, errlen) != 0) {
        const size_t n = strlen(err);
        snprintf(err + n, errlen > n ? errlen - n : 0, ": not a monitor-mode interface (iw dev %s set type monitor)",
                 ifname);
        pcap_close(p);
        return NULL;
    }
    /* Non-blocking, waited on with poll() in lx_pcap_next: a bounded wait whatever
     * libpcap's own timeout does. */
    if (pcap_setnonblock(p, 1, ebuf) != 0 || pcap_get_selectable_fd(p) < 0) {
        snprintf(err, errlen, "%s: cannot poll the interface: %s", ifname, ebuf[0] != '\0' ? ebuf : "no descriptor");
        pcap_close(p);
        return NULL;
    }
    lx_pcap_reader_t *r = calloc(1, sizeof(*r));
    if (r == NULL) {
        pcap_close(p);
        snprintf(err, errlen, "%s: out of memory", ifname);
        return NULL;
    }
    r->p = p;
    r->live = true;
    copy_name(r->name, sizeof(r->name), ifname);
    return r;
}

/* A live interface still there and up: 0, or -1 with `err`. libpcap reads on through an
 * interface taken down (it may come back), but a reader that hears nothing must not go on
 * saying it listens. */
static int live_up(const lx_pcap_reader_t *r, char *err, size_t errlen)
{
    struct ifreq ifr;
    memset(&ifr, 0, sizeof(ifr));
    const size_t n = strnlen(r->name, sizeof(ifr.ifr_name) - 1); /* libpcap took the name: it fits */
    memcpy(ifr.ifr_name, r->name, n);
    if (ioctl(pcap_get_selectable_fd(r->p), SIOCGIFFLAGS, &ifr) != 0) {
        snprintf(err, errlen, "%s: the interface is gone: %s", r->name, strerror(errno));
        return -1;
    }
    if ((ifr.ifr_flags & IFF_UP) == 0) {
        snprintf(err, errlen, "%s: the interface went down", r->name);
        return -1;
    }
    return 0;
}

int lx_pcap_next(lx_pcap_reader_t *r, lx_pcap_pkt_t *pkt, char *err, size_t errlen)
{
    struct pcap_pkthdr *h = NULL;
    const u_char *data = NULL;
    int rc = pcap_next_ex(r->p, &h, &data);
    if (rc == 0 && r->live) {
        /* Nothing buffered: wait for the socket. A timeout or a signal is a timeout; an
         * error or a hang-up (the interface went away) is read by pcap_next_ex. */
        struct pollfd pfd = {pcap_get_selectable_fd(r->p), POLLIN, 0};
        if (poll(&pfd, 1, LX_PCAP_LIVE_TIMEOUT_MS) <= 0) { return live_up(r, err, errlen) != 0 ? -1 : 2; }
        rc = pcap_next_ex(r->p, &h, &data);
    }
    if (rc == 1) {
        /* libpcap sign-extends a classic record's 32-bit seconds into time_t and gives a
         * pcapng's 64-bit unsigned seconds (its timestamp divided by if_tsresol, decimal or
         * binary) as time_t too: both are unsigned on the wire, as tshark reads them. */
        const uint64_t sec = r->classic ? (uint64_t)(uint32_t)h->ts.tv_sec : (uint64_t)h->ts.tv_sec;
        const int64_t scale = pcap_get_tstamp_precision(r->p) == PCAP_TSTAMP_PRECISION_NANO ? 1 : 1000;
        /* A classic record's fraction field beyond 1 s (2^31 and up reads negative) is damage. */
        if (h->ts.tv_usec < 0 || (int64_t)h->ts.tv_usec >= 1000000000 / scale) {
            snprintf(err, errlen, "%s: damaged record: timestamp fraction not below one second", r->name);
            return -1;
        }
        pkt->ts_sec = sec;
        pkt->ts_nsec = (uint32_t)((int64_t)h->ts.tv_usec * scale);
        pkt->t_ns = pkt->ts_sec < (uint64_t)INT64_MAX / 1000000000u
                        ? (int64_t)(pkt->ts_sec * 1000000000u + pkt->ts_nsec) : INT64_MAX;
        pkt->t_us = pkt->ts_sec < (uint64_t)INT64_MAX / 1000000u
                        ? (int64_t)(pkt->ts_sec * 1000000u + pkt->ts_nsec / 1000u) : INT64_MAX;
        pkt->caplen = h->caplen;
        pkt->origlen = h->len;
        pkt->data = data;
        return 1;
    }
    if (rc == 0) { return 2; }
    if (rc == PCAP_ERROR_BREAK) { return 0; }
    snprintf(err, errlen, "%s: %s", r->name, pcap_geterr(r->p));
    return -1;
}

void lx_pcap_close(lx_pcap_reader_t *r)
{
    if (r == NULL) { return; }
    pcap_close(r->p);
    free(r);
}

static void writer_free(lx_pcap_writer_t *w)
{
    if (w->d != NULL) { pcap_dump_close(w->d); }
    if (w->dead != NULL) { pcap_close(w->dead); }
    free(w->path);
    free(w->tmp);
    free(w);
}

lx_pcap_writer_t *lx_pcap_writer_open(const char *path, char *err, size_t errlen)
{
    lx_pcap_writer_t *w = calloc(1, sizeof(*w));
    const size_t n = strlen(path);
    if (w == NULL || (w->path = malloc(n + 1)) == NULL || (w->tmp = malloc(n + 5)) == NULL) {
        snprintf(err, errlen, "%s: out of memory", path);
        if (w != NULL) { writer_free(w); }
        return NULL;
    }
    memcpy(w->path, path, n + 1);
    memcpy(w->tmp, path, n); // NOLINT(bugprone-not-null-terminated-result): ".tmp" and its NUL follow
    memcpy(w->tmp + n, ".tmp", 5);
    w->dead = pcap_open_dead_with_tstamp_precision(DLT_IEEE802_11_RADIO, 65535, PCAP_TSTAMP_PRECISION_MICRO);
    if (w->dead == NULL) {
        snprintf(err, errlen, "%s: cannot set up the pcap writer", path);
        writer_free(w);
        return NULL;
    }
    w->d = pcap_dump_open(w->dead, w->tmp);
    if (w->d == NULL) {
        snprintf(err, errlen, "%s: cannot create: %s", w->tmp, pcap_geterr(w->dead));
        writer_free(w);
        return NULL;
    }
    return w;
}

/* Bytes of one written record: radiotap 23, 802.11 data header 24, LLC/SNAP 8, payload 4. */
enum { WR_RT_LEN = 23, WR_LEN = WR_RT_LEN + 24 + 8 + 4 };

int lx_pcap_writer_frame(lx_pcap_writer_t *w, int64_t t_us, const uint8_t src_mac[6],
                         const uint8_t bssid[6], uint16_t seq, int8_t dbm, uint16_t freq_mhz)
{
    if (w->failed) { return -1; }
    if (t_us < 0) { w->failed = true; return -1; }
    uint8_t b[WR_LEN];
    memset(b, 0, sizeof(b));
    /* Radiotap: version 0, pad, it_len, present = TSFT | flags | channel | dBm signal. */
    b[2] = WR_RT_LEN;
    b[4] = 0x2b;
    for (int i = 0; i < 8; i++) { b[8 + i] = (uint8_t)((uint64_t)t_us >> (8 * i)); } /* TSFT, offset 8 */
    b[16] = 0x00;                                                                  /* flags: no FCS */
    /* channel at 18 (2-aligned): frequency, then flags OFDM + 2 GHz (0x00c0) or 5 GHz (0x0140). */
    const uint16_t cflags = freq_mhz >= 4000 ? 0x0140 : 0x00c0;
    b[18] = (uint8_t)freq_mhz;
    b[19] = (uint8_t)(freq_mhz >> 8);
    b[20] = (uint8_t)cflags;
    b[21] = (uint8_t)(cflags >> 8);
    b[22] = (uint8_t)dbm;
    /* 802.11 data frame, ToDS: addr1 = BSSID, addr2 = SA = TA, addr3 = DA (the BSSID). */
    uint8_t *f = b + WR_RT_LEN;
    f[0] = 0x08;
    f[1] = 0x01;
    memcpy(f + 4, bssid, 6);
    memcpy(f + 10, src_mac, 6);
    memcpy(f + 16, bssid, 6);
    const uint16_t sc = (uint16_t)((seq & 0x0fffu) << 4);
    f[22] = (uint8_t)sc;
    f[23] = (uint8_t)(sc >> 8);
    static const uint8_t llc[8] = {0xaa, 0xaa, 0x03, 0x00, 0x00, 0x00, 0x88, 0xb5};
    memcpy(f + 24, llc, sizeof(llc));
    f[32] = 'r';
    f[33] = 'f';
    f[34] = (uint8_t)(seq >> 8);
    f[35] = (uint8_t)seq;

    struct pcap_pkthdr h;
    memset(&h, 0, sizeof(h));
    h.ts.tv_sec = (time_t)(t_us / 1000000);
    h.ts.tv_usec = (suseconds_t)(t_us % 1000000);
    h.caplen = WR_LEN;
    h.len = WR_LEN;
    pcap_dump((u_char *)w->d, &h, b);
    w->count++;
    return 0;
}

int lx_pcap_writer_close(lx_pcap_writer_t *w)
{
    if (w == NULL) { return -1; }
    int rc = w->failed ? -1 : 0;
    if (pcap_dump_flush(w->d) != 0 || ferror(pcap_dump_file(w->d))) { rc = -1; }
    pcap_dump_close(w->d);
    w->d = NULL;
    if (rc == 0 && rename(w->tmp, w->path) != 0) { rc = -1; }
    if (rc != 0) { (void)remove(w->tmp); }
    writer_free(w);
    return rc;
}

uint64_t lx_pcap_writer_count(const lx_pcap_writer_t *w)
{
    return w->count;
}
