/* lx_radiotap.c - radiotap and 802.11 header parsing (see lx_radiotap.h). */
#include "lx_radiotap.h"

#include <stddef.h>
#include <string.h>

/* Default-namespace field bits with their alignment and size in bytes
 * (https://www.radiotap.org/fields/defined). Alignment 0 = not a field we may skip:
 * bit 18 (XChannel) is only "suggested" upstream, bit 28 (TLVs) has no fixed size. The
 * same table as the Linux/Wireshark iterator for bits 0..22, so parsing stops where
 * theirs does; 23..27 as radiotap.org defines them. */
typedef struct rt_field {
    uint8_t align; /* bytes, a power of two; 0 = unknown */
    uint8_t size;  /* bytes */
} rt_field_t;

enum {
    RT_TSFT = 0,
    RT_FLAGS = 1,
    RT_RATE = 2,
    RT_CHANNEL = 3,
    RT_DBM_ANTSIGNAL = 5,
    RT_DBM_ANTNOISE = 6,
    RT_ANTENNA = 11,
    RT_MCS = 19,
    RT_NS_RADIOTAP = 29,
    RT_NS_VENDOR = 30,
    RT_EXT = 31,
    RT_HDR = 8, /* version, pad, it_len (LE16), it_present (LE32) */
};

static const rt_field_t k_fields[] = {
    {8, 8},  /* 0 TSFT: u64 */
    {1, 1},  /* 1 flags */
    {1, 1},  /* 2 rate */
    {2, 4},  /* 3 channel: u16 freq, u16 flags */
    {2, 2},  /* 4 FHSS: u8 hop set, u8 pattern */
    {1, 1},  /* 5 dBm antenna signal */
    {1, 1},  /* 6 dBm antenna noise */
    {2, 2},  /* 7 lock quality */
    {2, 2},  /* 8 TX attenuation */
    {2, 2},  /* 9 dB TX attenuation */
    {1, 1},  /* 10 dBm TX power */
    {1, 1},  /* 11 antenna */
    {1, 1},  /* 12 dB antenna signal */
    {1, 1},  /* 13 dB antenna noise */
    {2, 2},  /* 14 RX flags */
    {2, 2},  /* 15 TX flags */
    {1, 1},  /* 16 RTS retries */
    {1, 1},  /* 17 data retries */
    {0, 0},  /* 18 XChannel: not a defined field */
    {1, 3},  /* 19 MCS: known, flags, index */
    {4, 8},  /* 20 A-MPDU status */
    {2, 12}, /* 21 VHT */
    {8, 12}, /* 22 timestamp: u64, u16, u8, u8 */
    {2, 12}, /* 23 HE: six u16 */
    {2, 12}, /* 24 HE-MU: u16 flags1, u16 flags2, u8 RU_channel1[4], u8 RU_channel2[4] */
    {2, 6},  /* 25 HE-MU-other-user: u16, u16, u8, u8 */
    {1, 1},  /* 26 0-length PSDU */
    {2, 4},  /* 27 L-SIG: u16 data1, u16 data2 */
};

static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static uint64_t rd64(const uint8_t *p) { return (uint64_t)rd32(p) | ((uint64_t)rd32(p + 4) << 32); }

const char *lx_radiotap_status_str(lx_rt_status_t st)
{
    switch (st) {
    case LX_RT_OK: return "ok";
    case LX_RT_STOP_UNKNOWN: return "stopped at an unknown field";
    case LX_RT_FIELD_OVERRUN: return "a field runs past it_len";
    case LX_RT_ERR_SHORT: return "fewer than 8 bytes for the radiotap header";
    case LX_RT_ERR_VERSION: return "radiotap version byte is not 0";
    case LX_RT_ERR_LEN: return "radiotap it_len is below 8 or beyond the captured bytes";
    case LX_RT_ERR_BITMAP: return "radiotap present bitmaps run past it_len";
    case LX_RT_ERR_NS_BOTH: return "radiotap present word selects both namespaces (bits 29 and 30)";
    }
    return "unknown status";
}

/* Store a default-namespace field we use; `p` points at its `size` bytes. Repeated
 * fields (per-chain signal, noise, antenna) keep the first value: the combined one. */
static void rt_store(lx_radiotap_t *rt, unsigned bit, const uint8_t *p)
{
    switch (bit) {
    case RT_TSFT:
        if (!rt->has_tsft) { rt->has_tsft = true; rt->tsft_us = rd64(p); }
        break;
    case RT_FLAGS:
        if (!rt->has_flags) { rt->has_flags = true; rt->flags = p[0]; }
        break;
    case RT_RATE:
        if (!rt->has_rate) { rt->has_rate = true; rt->rate_500k = p[0]; }
        break;
    case RT_CHANNEL:
        if (!rt->has_channel) { rt->has_channel = true; rt->freq_mhz = rd16(p); rt->chan_flags = rd16(p + 2); }
        break;
    case RT_DBM_ANTSIGNAL:
        if (!rt->has_dbm_signal) { rt->has_dbm_signal = true; rt->dbm_signal = (int8_t)p[0]; }
        if (rt->n_dbm_signal < UINT8_MAX) { rt->n_dbm_signal++; }
        break;
    case RT_DBM_ANTNOISE:
        if (!rt->has_dbm_noise) { rt->has_dbm_noise = true; rt->dbm_noise = (int8_t)p[0]; }
        break;
    case RT_ANTENNA:
        if (!rt->has_antenna) { rt->has_antenna = true; rt->antenna = p[0]; }
        break;
    case RT_MCS:
        if (!rt->has_mcs) { rt->has_mcs = true; rt->mcs_known = p[0]; rt->mcs_flags = p[1]; rt->mcs_index = p[2]; }
        break;
    default:
        break;
    }
}

/* The fields rt_store keeps. */
#define RT_KEPT ((1u << RT_TSFT) | (1u << RT_FLAGS) | (1u << RT_RATE) | (1u << RT_CHANNEL) | \
                 (1u << RT_DBM_ANTSIGNAL) | (1u << RT_DBM_ANTNOISE) | (1u << RT_ANTENNA) | (1u << RT_MCS))

/* A present word whose layout a memo may hold: no namespace switch, no further word. */
#define RT_SINGLE(w) (((w) & ((1u << RT_NS_RADIOTAP) | (1u << RT_NS_VENDOR) | (1u << RT_EXT))) == 0u)

/* The walk's end with status st: remembered in memo (when not NULL) for a single word. */
static int rt_done(lx_radiotap_t *rt, lx_rt_status_t st, lx_rt_layout_t *memo)
{
    rt->status = st;
    if (memo != NULL) {
        memo->status = (uint8_t)st;
    }
    return 0;
}

/* The kept fields of a header of layout m: what rt_store reads, each field once. */
static void rt_from_layout(lx_radiotap_t *rt, const lx_rt_layout_t *m, const uint8_t *buf)
{
    _Static_assert(sizeof(m->off) / sizeof(m->off[0]) > RT_MCS, "an offset for every kept bit");
    if (m->off[RT_TSFT] != 0u) { rt->has_tsft = true; rt->tsft_us = rd64(buf + m->off[RT_TSFT]); }
    if (m->off[RT_FLAGS] != 0u) { rt->has_flags = true; rt->flags = buf[m->off[RT_FLAGS]]; }
    if (m->off[RT_RATE] != 0u) { rt->has_rate = true; rt->rate_500k = buf[m->off[RT_RATE]]; }
    if (m->off[RT_CHANNEL] != 0u) {
        rt->has_channel = true;
        rt->freq_mhz = rd16(buf + m->off[RT_CHANNEL]);
        rt->chan_flags = rd16(buf + m->off[RT_CHANNEL] + 2);
    }
    if (m->off[RT_DBM_ANTSIGNAL] != 0u) {
        rt->has_dbm_signal = true;
        rt->dbm_signal = (int8_t)buf[m->off[RT_DBM_ANTSIGNAL]];
        rt->n_dbm_signal = 1u;
    }
    if (m->off[RT_DBM_ANTNOISE] != 0u) { rt->has_dbm_noise = true; rt->dbm_noise = (int8_t)buf[m->off[RT_DBM_ANTNOISE]]; }
    if (m->off[RT_ANTENNA] != 0u) { rt->has_antenna = true; rt->antenna = buf[m->off[RT_ANTENNA]]; }
    if (m->off[RT_MCS] != 0u) {
        const uint8_t *p = buf + m->off[RT_MCS];
        rt->has_mcs = true;
        rt->mcs_known = p[0];
        rt->mcs_flags = p[1];
        rt->mcs_index = p[2];
    }
}

int lx_radiotap_parse(const uint8_t *buf, size_t len, lx_radiotap_t *rt)
{
    return lx_radiotap_parse_memo(buf, len, rt, NULL);
}

int lx_radiotap_parse_memo(const uint8_t *buf, size_t len, lx_radiotap_t *rt, lx_rt_layout_t *keep)
{
    memset(rt, 0, sizeof(*rt));
    if (len < RT_HDR) { rt->status = LX_RT_ERR_SHORT; return -1; }
    if (buf[0] != 0) { rt->status = LX_RT_ERR_VERSION; return -1; }
    const size_t it_len = rd16(buf + 2);
    rt->it_len = (uint16_t)it_len;
    if (it_len < RT_HDR || it_len > len) { rt->status = LX_RT_ERR_LEN; return -1; }
    lx_rt_layout_t *memo = NULL; /* filled by this walk */
    if (keep != NULL && it_len >= RT_HDR && RT_SINGLE(rd32(buf + 4))) {
        const uint32_t w = rd32(buf + 4);
        if (keep->it_len == it_len && keep->present == w) {
            rt->n_present = 1u;
            rt->status = (lx_rt_status_t)keep->status;
            rt_from_layout(rt, keep, buf);
            return 0;
        }
        memo = keep;
        memset(memo, 0, sizeof(*memo));
        memo->present = w;
        memo->it_len = (uint16_t)it_len;
    }

    /* The present words: all inside it_len, the last one without bit 31. */
    size_t words_end = 4;
    for (;;) {
        if (words_end + 4 > it_len) { rt->status = LX_RT_ERR_BITMAP; return -1; }
        const uint32_t w = rd32(buf + words_end);
        words_end += 4;
        /* Which namespace the next word is in would be ambiguous: the header is invalid
         * (radiotap.org, "Extended presence masks"; Wireshark rejects it too). */
        if ((w & (3u << RT_NS_RADIOTAP)) == (3u << RT_NS_RADIOTAP)) { rt->status = LX_RT_ERR_NS_BOTH; return -1; }
        if (rt->n_present < UINT8_MAX) { rt->n_present++; }
        if (!(w & (1u << RT_EXT))) { break; }
    }

    /* Walk the words. In a vendor namespace every field lies inside the data that was
     * skipped by its skip_length, so only bits 29..31 matter there. */
    size_t off = words_end;   /* next field, bytes from the start of the header */
    bool vendor = false;      /* inside a vendor namespace */
    unsigned base = 0;        /* namespace bit index of bit 0 of this word */
    bool reset_on_ext = false;
    for (size_t wo = 4; wo < words_end; wo += 4) {
        const uint32_t w = rd32(buf + wo);
        /* The set bits below bit 31, lowest first. */
        for (uint32_t bits = w & ~(1u << RT_EXT); bits != 0u; bits &= bits - 1u) {
            const unsigned b = (unsigned)__builtin_ctz(bits);
            if (b == RT_NS_RADIOTAP) {
                /* The next word restarts at bit 0 of the default namespace. */
                vendor = false;
                reset_on_ext = true;
                continue;
            }
            if (b == RT_NS_VENDOR) {
                /* OUI (3), sub-namespace (1), skip_length (LE16), aligned to 2; we know
                 * no vendor namespace, so its data is skipped whole. */
                off = (off + 1u) & ~(size_t)1u;
                if (off + 6 > it_len) { return rt_done(rt, LX_RT_FIELD_OVERRUN, memo); }
                off += 6u + rd16(buf + off + 4);
                if (off > it_len) { return rt_done(rt, LX_RT_FIELD_OVERRUN, memo); }
                vendor = true;
                reset_on_ext = true;
                if (rt->n_vendor < UINT8_MAX) { rt->n_vendor++; }
                continue;
            }
            if (vendor) { continue; }
            const unsigned idx = base + b;
            if (idx >= sizeof(k_fields) / sizeof(k_fields[0]) || k_fields[idx].align == 0) {
                /* Size and alignment unknown: nothing after it can be located. */
                return rt_done(rt, LX_RT_STOP_UNKNOWN, memo);
            }
            const size_t a = k_fields[idx].align;
            off = (off + a - 1u) & ~(a - 1u);
            if (off + k_fields[idx].size > it_len) { return rt_done(rt, LX_RT_FIELD_OVERRUN, memo); }
            rt_store(rt, idx, buf + off);
            if (memo != NULL && (RT_KEPT & (1u << idx)) != 0u) { /* idx <= RT_MCS: one word */
                memo->off[idx] = (uint16_t)off; /* >= 8: after the present word */
            }
            off += k_fields[idx].size;
        }
        /* Bit 31 moves to the next word: bit 32 of the same namespace, or bit 0 after a
         * namespace switch in this word. */
        base = reset_on_ext ? 0u : base + 32u;
        reset_on_ext = false;
    }
    return rt_done(rt, LX_RT_OK, memo);
}

int lx_wlan_parse(const uint8_t *frame, size_t len, lx_wlan_t *w)
{
    memset(w, 0, sizeof(*w));
    if (len < 2) { return -1; }
    w->fc = rd16(frame);
    w->type = (uint8_t)((w->fc >> 2) & 3u);
    w->subtype = (uint8_t)((w->fc >> 4) & 15u);
    w->ds = (uint8_t)((w->fc >> 8) & 3u);
    const bool order = (w->fc & 0x8000u) != 0;
    w->hdr_len = 2;
    /* Address offsets: addr1 4, addr2 10, addr3 16, seq 22, addr4 24. */
    if ((w->fc & 3u) == 0u && w->type == LX_WLAN_CTRL) {
        /* RTS, PS-Poll, CF-End+CF-Ack, BlockAckReq, BlockAck carry RA then TA; ACK and CTS
         * carry only RA; CF-End carries RA then the BSSID (tshark 4.0: wlan.bssid, no wlan.ta).
         * None of them has a source address (Wireshark: no wlan.sa). */
        const uint16_t with_ta = (1u << 8) | (1u << 9) | (1u << 10) | (1u << 11) | (1u << 15);
        if ((with_ta & (1u << w->subtype)) && len >= 16) {
            memcpy(w->ta, frame + 10, 6);
            w->has_ta = true;
            w->hdr_len = 16;
        }
        return 0;
    }
    size_t need = lx_wlan_addr_len(w->fc);
    if (need == 0 || len < need) { return 0; }
    const bool qos = w->type == LX_WLAN_DATA && (w->subtype & 8u) != 0;
    if (order && (w->type == LX_WLAN_MGMT || qos)) { need += 4; }
    w->hdr_len = (uint16_t)need;
    memcpy(w->ta, frame + 10, 6);
    w->has_ta = true;
    memcpy(w->sa, frame + lx_wlan_sa_offset(w->fc), 6);
    w->has_sa = true;
    const uint16_t sc = rd16(frame + 22);
    w->has_seq = true;
    w->seq = (uint16_t)(sc >> 4);
    w->frag = (uint8_t)(sc & 15u);
    return 0;
}

/* The SSID element of a beacon or probe response: body[0..n) are the bytes after the MAC
 * header, FCS excluded; elements follow the 12 bytes of timestamp, interval, capability. */
static void frame_ssid(const uint8_t *body, size_t n, lx_rt_frame_t *f)
{
    for (size_t at = 12; at + 2u <= n;) {
        const size_t elen = body[at + 1u];
        if (at + 2u + elen > n) {
            return;
        }
        if (body[at] == 0u) {
            memcpy(f->ssid, body + at + 2u, elen);
            f->ssid_len = (uint8_t)elen; /* a one-byte length: <= LX_WLAN_SSID_MAX */
            f->has_ssid = true;
            return;
        }
        at += 2u + elen;
    }
}

int lx_rt_frame_parse(const uint8_t *buf, size_t len, lx_rt_frame_t *f)
{
    return lx_rt_frame_parse_memo(buf, len, f, NULL);
}

int lx_rt_frame_parse_memo(const uint8_t *buf, size_t len, lx_rt_frame_t *f, lx_rt_layout_t *memo)
{
    /* Every field but the SSID bytes, which count only up to ssid_len when has_ssid. */
    memset(f, 0, offsetof(lx_rt_frame_t, ssid));
    const int rc = lx_radiotap_parse_memo(buf, len, &f->rt, memo);
    /* An unusable header whose length field still lies in [8, len]: the 802.11 frame is
     * there, as Wireshark reads it; its fields (and so the FCS flag) are not. */
    const size_t it_len = rc == 0 ? f->rt.it_len : (len >= RT_HDR ? rd16(buf + 2) : 0u);
    if (it_len < RT_HDR || it_len > len) { return -1; }
    const size_t n = len - it_len;
    /* The FCS is the last 4 bytes of the frame. Like Wireshark we still read the MAC
     * header from every captured byte: a frame shorter than header + FCS is damaged
     * either way, and this keeps our SA equal to tshark's wlan.sa. */
    const bool fcs = rc == 0 && f->rt.has_flags && (f->rt.flags & LX_RT_FLAG_FCS) != 0;
    f->frame_len = (uint32_t)(fcs ? (n >= 4 ? n - 4 : 0) : n);
    f->wlan_ok = lx_wlan_parse(buf + it_len, n, &f->wlan) == 0;
    const bool beacon = f->wlan.subtype == 8u || f->wlan.subtype == 5u; /* or probe response */
    if (f->wlan_ok && f->wlan.has_sa && f->wlan.type == LX_WLAN_MGMT && beacon && f->wlan.hdr_len <= f->frame_len) {
        frame_ssid(buf + it_len + f->wlan.hdr_len, f->frame_len - f->wlan.hdr_len, f);
    }
    return rc;
}
