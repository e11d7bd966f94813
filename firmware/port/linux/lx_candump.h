/* lx_candump.h - CAN logs in the can-utils text format (`candump -L`), written and read.
 *
 * One frame per line, as candump -L writes it and canplayer, log2asc and asc2log read it:
 *
 *   (0000000012.345678) can0 120#0BC203D0C2B40100
 *
 * the time in seconds and exactly 6 digits of microseconds since the Unix epoch (candump
 * pads the seconds to 10 digits), the interface, then the frame: the identifier in 3 hex
 * digits (11-bit) or 8 (29-bit), '#', the data bytes as hex pairs (0 to 8). A remote frame
 * is `ID#R` with an optional length digit; an error frame is an 8-digit id with bit 29
 * (0x20000000) set. CAN FD (`ID##...`) is not read: the protocol is classic CAN
 * (docs/CAN.md). The writer produces exactly candump's form (upper-case hex, no
 * separators), so its lines equal candump's for the same frames (tests/vm/).
 *
 * A clock that starts at 0 (a simulated one) is written shifted by one wrap of the
 * frames' 32-bit Time fields, 2^32 us (4294.967296 s): the Time fields still name the
 * log's clock (modulo 2^32, as on the bus), and log2asc, which takes a first time of
 * second 0 for "no start yet", gets a real one.
 */
#ifndef LX_CANDUMP_H
#define LX_CANDUMP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rfs_can.h"

/// Longest interface name, characters (Linux IFNAMSIZ - 1).
#define LX_CANDUMP_IFNAME_MAX 15u
/// Interface named in logs when the program has none of its own (docs/CAN.md).
#define LX_CANDUMP_DEFAULT_IF "can0"
/// Longest line read, characters without the line break.
#define LX_CANDUMP_LINE_MAX 200u
/// Room for one line written: timestamp, name, frame, newline, NUL.
#define LX_CANDUMP_FMT_MAX 80u
/// Shift of a log whose first frame comes before it: one wrap of a 32-bit microsecond
/// Time field, microseconds.
#define LX_CANDUMP_SHIFT_US 4294967296LL

/// What a line holds.
typedef enum lx_candump_kind {
    LX_CANDUMP_DATA = 0, ///< a data frame
    LX_CANDUMP_REMOTE,   ///< a remote (RTR) frame: dlc only, no data
    LX_CANDUMP_ERROR,    ///< an error frame (8-digit id with bit 29): id holds the error class
} lx_candump_kind_t;

/// One parsed line.
typedef struct lx_candump_rec {
    int64_t t_us;          ///< time, microseconds since the epoch
    char ifname[LX_CANDUMP_IFNAME_MAX + 1u]; ///< interface, NUL-terminated
    lx_candump_kind_t kind; ///< data, remote or error frame
    bool ext;              ///< 29-bit identifier (8 hex digits)
    uint32_t id;           ///< identifier (0..0x7FF, or 0..0x1FFFFFFF when ext), no flag bits
    uint8_t dlc;           ///< data length, 0..8
    uint8_t data[8];       ///< data bytes; zero past dlc
} lx_candump_rec_t;

/// True when `name` can name an interface in a log: 1 to LX_CANDUMP_IFNAME_MAX printable
/// characters, none of them a space, '(' or '#'.
bool lx_candump_ifname_ok(const char *name);

/// Format one classic frame as a log line with its newline into buf (cap bytes, at least
/// LX_CANDUMP_FMT_MAX is always enough). Returns the line's length, 0 when t_us < 0 (no
/// time before the epoch in the format), f->id > 0x7FF, f->dlc > 8 or the line does not
/// fit.
size_t lx_candump_format(char *buf, size_t cap, int64_t t_us, const char *ifname, const rfs_can_frame_t *f);

/// Parse one line (len characters, no line break; a trailing '\r' is allowed). Returns 0
/// and fills *rec, or -1 with *why set to a static reason ("identifier: 3 or 8 hex digits
/// expected", ...). A candump -x direction suffix (" R" or " T") is accepted and ignored.
/// Never reads past line[len - 1].
int lx_candump_parse(const char *line, size_t len, lx_candump_rec_t *rec, const char **why);

/// A log being written: the lines go to PATH.tmp.PID, renamed to PATH by a successful
/// lx_candump_close, so no reader sees a half-written log.
typedef struct lx_candump lx_candump_t;

/// Create the log at `path` with interface name `ifname` on every line (checked with
/// lx_candump_ifname_ok). NULL and one line in `err` ("PATH: reason") on failure.
lx_candump_t *lx_candump_open(const char *path, const char *ifname, char *err, size_t errlen);

/// Append one frame sent or received at t_us (microseconds). When the log's first frame
/// comes before LX_CANDUMP_SHIFT_US, every time of the log is written that much later. A
/// failed or refused write (see lx_candump_format) is remembered and reported by
/// lx_candump_close.
void lx_candump_write(lx_candump_t *w, int64_t t_us, const rfs_can_frame_t *f);

/// Frames written so far.
uint64_t lx_candump_count(const lx_candump_t *w);

/// Finish: with keep, flush and rename into place (0), or -1 and `err` when a write
/// failed; without keep (the run failed), remove the temporary file and return 0. Frees w
/// (NULL is fine).
int lx_candump_close(lx_candump_t *w, bool keep, char *err, size_t errlen);

#endif /* LX_CANDUMP_H */
