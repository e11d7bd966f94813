/* lx_radiotap.h - radiotap and 802.11 MAC header parsing over a byte buffer.
 *
 * Pure C, no libpcap, every read bounds-checked against the captured length, so it can
 * run on anything a capture or the air hands us (the fuzz target drives it directly).
 *
 * Radiotap (https://www.radiotap.org): version byte 0, it_len within the capture, the
 * chain of it_present words (bit 31 = another word follows), each field aligned to its
 * natural size relative to the START of the radiotap header, radiotap-namespace restarts
 * (bit 29: the next word starts again at bit 0 of the default namespace), vendor
 * namespaces (bit 30: OUI, sub-namespace, skip_length; their data is skipped by length
 * because we know none of them). A field we do not know ends the parse: its size and
 * alignment are unknown, so nothing after it can be located; the fields already read are
 * kept. This is the rule of the Linux/Wireshark radiotap iterator, so what we report
 * equals tshark's radiotap.* fields.
 *
 * The RSSI the seeker uses (paper section 5.1) is the dBm antenna signal; with per-chain
 * values (Linux mac80211 layout: a namespace restart per chain) the first value is the
 * combined one and is the one reported.
 */
#ifndef LX_RADIOTAP_H
#define LX_RADIOTAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/// Number of lx_rt_status_t values.
#define LX_RT_N_STATUS 8

/// Radiotap flags field bits used here.
#define LX_RT_FLAG_FCS 0x10u     ///< frame includes the 4-byte FCS at its end
#define LX_RT_FLAG_BADFCS 0x40u  ///< frame failed the FCS check

/// Why a radiotap header was rejected or stopped early (lx_radiotap_t.status).
typedef enum lx_rt_status {
    LX_RT_OK = 0,          ///< every present field parsed
    LX_RT_STOP_UNKNOWN,    ///< stopped at a field we do not know; fields before it kept
    LX_RT_FIELD_OVERRUN,   ///< a field ran past it_len; fields before it kept
    LX_RT_ERR_SHORT,       ///< fewer than 8 bytes captured
    LX_RT_ERR_VERSION,     ///< version byte is not 0
    LX_RT_ERR_LEN,         ///< it_len < 8 or larger than the captured bytes
    LX_RT_ERR_BITMAP,      ///< present words run past it_len (bit 31 chain never ends)
    LX_RT_ERR_NS_BOTH,     ///< a present word sets both namespace bits 29 and 30
} lx_rt_status_t;

/// What a radiotap header says; `has_*` tells which fields were present and read.
typedef struct lx_radiotap {
    lx_rt_status_t status;   ///< see lx_rt_status_t; >= LX_RT_ERR_SHORT means unusable
    uint16_t it_len;         ///< radiotap header length, bytes (the 802.11 frame follows)
    uint8_t n_present;       ///< number of it_present words
    bool has_tsft;           ///< TSFT present
    uint64_t tsft_us;        ///< MAC timer at the first bit of the MPDU, microseconds
    bool has_flags;          ///< flags present
    uint8_t flags;           ///< LX_RT_FLAG_* bits
    bool has_rate;           ///< legacy rate present
    uint8_t rate_500k;       ///< TX/RX rate, units of 500 kbit/s
    bool has_channel;        ///< channel present
    uint16_t freq_mhz;       ///< channel centre frequency, MHz
    uint16_t chan_flags;     ///< channel flags bitmap
    bool has_dbm_signal;     ///< dBm antenna signal present
    int8_t dbm_signal;       ///< first (combined) dBm antenna signal, dBm
    uint8_t n_dbm_signal;    ///< dBm antenna signal values seen (combined + per chain)
    bool has_dbm_noise;      ///< dBm antenna noise present
    int8_t dbm_noise;        ///< first dBm antenna noise, dBm
    bool has_antenna;        ///< antenna index present
    uint8_t antenna;         ///< first antenna index
    bool has_mcs;            ///< MCS present
    uint8_t mcs_known;       ///< MCS known bits
    uint8_t mcs_flags;       ///< MCS flags (bandwidth, GI, format, FEC, STBC)
    uint8_t mcs_index;       ///< MCS rate index
    uint8_t n_vendor;        ///< vendor namespaces skipped
} lx_radiotap_t;

/// Parse the radiotap header at the start of `buf` (`len` captured bytes). Fills *rt
/// and returns 0 when the header is usable (status LX_RT_OK, LX_RT_STOP_UNKNOWN or
/// LX_RT_FIELD_OVERRUN; the 802.11 frame starts at it_len), -1 otherwise (status says
/// why). Never reads outside buf[0, len).
int lx_radiotap_parse(const uint8_t *buf, size_t len, lx_radiotap_t *rt);

/// The layout of one kind of radiotap header, kept by a caller that parses many records
/// of one capture (lx_radiotap_parse_memo): a header with a single present word (no
/// namespace or extension bit) and a given it_len always puts the same fields at the same
/// offsets and gets the same status. Zero-initialise it; it holds no pointer into a record.
typedef struct lx_rt_layout {
    uint32_t present;  ///< the present word it describes
    uint16_t it_len;   ///< and the header length; 0: empty
    uint8_t status;    ///< the status such a header gets (an lx_rt_status_t)
    uint16_t off[20];  ///< byte offset of each field bit 0..19 lx_radiotap_t holds; 0: absent
} lx_rt_layout_t;

/// lx_radiotap_parse(), with `memo` (or NULL) remembering the last single-word layout:
/// a header of that layout is read from its offsets without walking the present word
/// again. The result is the same as lx_radiotap_parse()'s for every input.
int lx_radiotap_parse_memo(const uint8_t *buf, size_t len, lx_radiotap_t *rt, lx_rt_layout_t *memo);

/// One line describing a status ("version byte is not 0", ...).
const char *lx_radiotap_status_str(lx_rt_status_t st);

/// 802.11 frame types (frame control bits 2-3).
enum {
    LX_WLAN_MGMT = 0, ///< management
    LX_WLAN_CTRL = 1, ///< control
    LX_WLAN_DATA = 2, ///< data
    LX_WLAN_EXT = 3,  ///< extension
};

/// What the 802.11 MAC header says. Addresses follow IEEE 802.11-2020 Table 9-30 and
/// Wireshark's wlan.ta / wlan.sa fields.
typedef struct lx_wlan {
    uint16_t fc;          ///< frame control, host order
    uint8_t type;         ///< LX_WLAN_*
    uint8_t subtype;      ///< subtype, 0..15
    uint8_t ds;           ///< ToDS | FromDS << 1 (0..3)
    bool has_ta;          ///< a transmitter address is in the frame
    uint8_t ta[6];        ///< transmitter address (addr2)
    bool has_sa;          ///< a source address is in the frame (wlan.sa)
    uint8_t sa[6];        ///< source address
    bool has_seq;         ///< a sequence control field is in the frame
    uint16_t seq;         ///< sequence number, 0..4095 (for the packet delivery ratio)
    uint8_t frag;         ///< fragment number, 0..15
    uint16_t hdr_len;     ///< MAC header length incl. +HTC, bytes (2 when incomplete)
} lx_wlan_t;

/// Parse the 802.11 MAC header of `frame` (`len` bytes, FCS already removed). Returns 0
/// when at least the frame control was readable, -1 when len < 2. Addresses and the
/// sequence number count only when the whole MAC header is there (as Wireshark adds
/// wlan.sa): an ACK, a CTS or a frame cut inside its header has no SA; nor has a frame of
/// protocol version 1 (S1G, another layout) or a reserved one.
int lx_wlan_parse(const uint8_t *frame, size_t len, lx_wlan_t *w);

/// Longest SSID element kept, bytes: its one-byte length's limit. IEEE 802.11-2020 9.4.2.2
/// allows 32; tshark shows longer ones whole, and so do we.
#define LX_WLAN_SSID_MAX 255u

/// One parsed capture record: radiotap + 802.11, as the feeder needs it.
typedef struct lx_rt_frame {
    lx_radiotap_t rt;     ///< the radiotap header
    lx_wlan_t wlan;       ///< the 802.11 header (valid when wlan_ok)
    bool wlan_ok;         ///< an 802.11 header followed the radiotap header
    uint32_t frame_len;   ///< 802.11 bytes after radiotap, FCS removed when flagged
                          ///< (the MAC header is parsed from all captured bytes)
    bool has_ssid;        ///< a beacon or probe response whose SSID element was read
    uint8_t ssid_len;     ///< its length, 0..LX_WLAN_SSID_MAX (0: a hidden network)
    uint8_t ssid[LX_WLAN_SSID_MAX]; ///< its first ssid_len bytes (not a C string; the
                                    ///< rest left as they were: the field comes last)
} lx_rt_frame_t;

/// Parse a whole captured record. Returns 0 when the radiotap header was usable (the
/// 802.11 part may still be absent: see wlan_ok), -1 otherwise; then rt.status says why,
/// and when the header's length field still lies within the record the 802.11 frame
/// after it is parsed all the same (wlan_ok; no FCS known), as Wireshark does. The SSID is the first
/// SSID element (id 0) among the elements after a beacon's or probe
/// response's 12 bytes of fixed fields, within the captured frame without its FCS.
int lx_rt_frame_parse(const uint8_t *buf, size_t len, lx_rt_frame_t *f);

/// lx_rt_frame_parse() with a layout memo for the radiotap header (lx_radiotap_parse_memo).
int lx_rt_frame_parse_memo(const uint8_t *buf, size_t len, lx_rt_frame_t *f, lx_rt_layout_t *memo);

/// The MAC header bytes that must be captured before a management or data frame's
/// addresses count (Wireshark adds wlan.sa only then): 24, + 6 for addr4 (data, ToDS and
/// FromDS), + 2 QoS control (QoS data subtypes); 0 for any other frame: control,
/// extension, protocol version 1 (S1G, another layout) or reserved. A +HTC field is not
/// required: Wireshark reports the addresses of a frame cut inside it.
static inline size_t lx_wlan_addr_len(uint16_t fc)
{
    const unsigned type = (fc >> 2) & 3u;
    if ((fc & 3u) != 0u || (type != LX_WLAN_MGMT && type != LX_WLAN_DATA)) { return 0; }
    size_t need = 24;
    if (type == LX_WLAN_DATA && ((fc >> 8) & 3u) == 3u) { need += 6; }
    if (type == LX_WLAN_DATA && (fc & 0x80u) != 0u) { need += 2; }
    return need;
}

/// Offset of the source address in a management or data frame. IEEE 802.11-2020 Table
/// 9-30: addr2 with FromDS 0, addr3 with FromDS 1 and ToDS 0, addr4 with both; a
/// management frame's SA is addr2 whatever the DS bits.
static inline size_t lx_wlan_sa_offset(uint16_t fc)
{
    static const uint8_t sa_at[4] = {10, 10, 16, 24};
    return ((fc >> 2) & 3u) == LX_WLAN_MGMT ? 10u : sa_at[(fc >> 8) & 3u];
}

/// The source address (wlan.sa) of a captured record, found from the radiotap length
/// field (bytes 2-3) and the 802.11 header alone, no radiotap field parsed: a filter ahead
/// of lx_rt_frame_parse(). Its 6 bytes inside buf, or NULL when there is none. For a
/// record lx_rt_frame_parse() accepts (returns 0) the answer agrees with its wlan.has_sa
/// and wlan.sa; a record it rejects may still have one here. Never reads outside buf[0, len).
static inline const uint8_t *lx_rt_frame_sa(const uint8_t *buf, size_t len)
{
    /* The same location as lx_rt_frame_parse (a header it accepts has it_len in [8, len])
     * and lx_wlan_parse's rule for when the SA counts. Inline: it runs on every record. */
    const size_t it_len = len >= 8u ? (size_t)(buf[2] | (buf[3] << 8)) : 0u;
    if (it_len < 8u || it_len + 2u > len) { return NULL; }
    const uint8_t *frame = buf + it_len;
    const uint16_t fc = (uint16_t)(frame[0] | (frame[1] << 8));
    const size_t need = lx_wlan_addr_len(fc);
    return need == 0 || len - it_len < need ? NULL : frame + lx_wlan_sa_offset(fc);
}

#endif /* LX_RADIOTAP_H */
