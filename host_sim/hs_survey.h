/* hs_survey.h - the transmitters of an 802.11 capture, as airodump-ng or Kismet list them
 * (rfseek-feed --list; docs/FEEDER.md, "Survey").
 *
 * One row per transmitter address (802.11 addr2, Wireshark's wlan.ta): frames, frames
 * with a dBm antenna signal, mean/min/max of those signals, the earliest and latest
 * capture times, and the SSID its beacons or probe responses name.
 */
#ifndef HS_SURVEY_H
#define HS_SURVEY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/// The transmitters seen so far (heap; hs_survey_free).
typedef struct hs_survey hs_survey_t;

/// One frame, as hs_survey_add counts it.
typedef struct hs_survey_frame {
    const uint8_t *ta;      ///< transmitter address, 6 bytes
    uint64_t sec;           ///< capture time: seconds since the epoch
    uint32_t nsec;          ///< ... and nanoseconds (0..999999999)
    bool has_dbm;           ///< a dBm antenna signal was captured
    int dbm;                ///< that signal, dBm (the first, combined, value)
    const uint8_t *ssid;    ///< SSID of a beacon or probe response, or NULL
    size_t ssid_len;        ///< its length, bytes (0..255; 0: a hidden network)
} hs_survey_frame_t;

/// A new, empty survey; NULL when out of memory.
hs_survey_t *hs_survey_new(void);

/// Release it (NULL is fine).
void hs_survey_free(hs_survey_t *s);

/// Count one frame. The SSID kept is the first non-hidden one (neither empty nor all
/// zero bytes). Returns 0, or -1 when out of memory.
int hs_survey_add(hs_survey_t *s, const hs_survey_frame_t *f);

/// Frames counted from mac (6 bytes); 0 when none.
uint64_t hs_survey_frames(const hs_survey_t *s, const uint8_t *mac);

/// Write the table: the header line, then one TSV row per transmitter, most frames first
/// (ties by address):
///   mac frames dbm_frames mean_dbm min_dbm max_dbm first_epoch last_epoch ssid
/// mean with 2 decimals; the dBm fields empty without a signal; times with 9 decimals as
/// tshark's frame.time_epoch; the SSID's bytes as text, each byte outside printable ASCII
/// (0x20..0x7E) and each backslash as \xNN (lower-case hex), so a row stays one TSV line.
/// Returns the rows written, or -1 when out of memory.
long hs_survey_write(const hs_survey_t *s, FILE *out);

#endif /* HS_SURVEY_H */
