/* lx_pcap.h - 802.11 radiotap captures in and out, behind our own types.
 *
 * The only header in front of libpcap: lx_pcap.c is the one file that includes pcap.h.
 * The reader hands out raw captured packets (radiotap header + 802.11 frame) with their
 * timestamps; parsing them is lx_radiotap's job. The writer produces a classic
 * little-endian pcap, link type 127 (LINKTYPE_IEEE802_11_RADIOTAP), microsecond
 * timestamps, that Wireshark and tshark open: what the simulator writes for every packet
 * it simulates (paper section 5.1: RSSI read from a monitor-mode adapter through libpcap).
 */
#ifndef LX_PCAP_H
#define LX_PCAP_H

#include <stddef.h>
#include <stdint.h>

/// Link type every reader requires: LINKTYPE_IEEE802_11_RADIOTAP.
#define LX_PCAP_LINKTYPE_RADIOTAP 127

/// An open capture (offline file or live interface).
typedef struct lx_pcap_reader lx_pcap_reader_t;

/// One captured packet; `data` stays valid until the next lx_pcap_next() or close.
typedef struct lx_pcap_pkt {
    uint64_t ts_sec;      ///< capture time as the file states it: seconds since the Unix epoch
                          ///< (a classic pcap's are unsigned 32-bit, a pcapng's unsigned 64-bit)
    uint32_t ts_nsec;     ///< ... and nanoseconds (0..999999999), as tshark's frame.time_epoch
    int64_t t_us;         ///< the same in microseconds, saturated at INT64_MAX (year 294247)
    int64_t t_ns;         ///< the same in nanoseconds, saturated at INT64_MAX (year 2262)
    uint32_t caplen;      ///< bytes captured (length of `data`)
    uint32_t origlen;     ///< bytes on the air as the capture header states them
    const uint8_t *data;  ///< captured bytes: radiotap header then the 802.11 frame
} lx_pcap_pkt_t;

/// Open a .pcap or .pcapng file. Requires link type 127; any other link type, an empty or
/// damaged file gets NULL and one line in `err` naming the file and the reason.
lx_pcap_reader_t *lx_pcap_open_offline(const char *path, char *err, size_t errlen);

/// How long lx_pcap_next() waits on a live interface before it returns 2, milliseconds.
#define LX_PCAP_LIVE_TIMEOUT_MS 25

/// Open a monitor-mode interface live (promiscuous, snaplen 65535, immediate mode: each
/// frame as it arrives). Same link-type rule as the offline reader (the message then
/// says it is not a monitor-mode interface). NULL and `err` on failure.
lx_pcap_reader_t *lx_pcap_open_live(const char *ifname, char *err, size_t errlen);

/// Read the next packet: 1 = a packet in *pkt, 0 = end of file, 2 = live: no packet
/// within LX_PCAP_LIVE_TIMEOUT_MS or a signal came (the interface is still up), -1 = read
/// error (a truncated record, a timestamp fraction of a second or more, a live interface
/// down or removed; message in `err`).
int lx_pcap_next(lx_pcap_reader_t *r, lx_pcap_pkt_t *pkt, char *err, size_t errlen);

/// Close the reader (NULL is fine).
void lx_pcap_close(lx_pcap_reader_t *r);

/// A radiotap pcap being written.
typedef struct lx_pcap_writer lx_pcap_writer_t;

/// Create `path`: the packets go to `path`.tmp, which lx_pcap_writer_close() renames to
/// `path`, so a reader never sees a half-written file. NULL and `err` on failure.
lx_pcap_writer_t *lx_pcap_writer_open(const char *path, char *err, size_t errlen);

/// Append one received 802.11 data frame: radiotap with TSFT (= t_us), flags (no FCS),
/// channel (freq_mhz, 2.4 or 5 GHz OFDM) and dBm antenna signal; then a data frame with
/// ToDS set (addr1 = bssid, addr2 = src_mac = wlan.sa, addr3 = bssid), sequence number
/// `seq` (low 12 bits), fragment 0, and an 8-byte LLC/SNAP header (ethertype 0x88B5,
/// local experimental) with 4 bytes of payload. Timestamp: t_us (must be >= 0).
/// Returns 0, or -1 on a write error or a negative t_us (the file is then discarded at
/// close).
int lx_pcap_writer_frame(lx_pcap_writer_t *w, int64_t t_us, const uint8_t src_mac[6],
                         const uint8_t bssid[6], uint16_t seq, int8_t dbm, uint16_t freq_mhz);

/// Flush, close and rename `path`.tmp to `path`. Returns 0; -1 when any write failed (the
/// temporary file is removed and `path` is left untouched). Frees `w` either way.
int lx_pcap_writer_close(lx_pcap_writer_t *w);

/// Frames written so far.
uint64_t lx_pcap_writer_count(const lx_pcap_writer_t *w);

#endif /* LX_PCAP_H */
