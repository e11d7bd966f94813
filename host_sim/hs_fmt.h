/* hs_fmt.h - fixed-point decimal text of doubles, as printf("%.*f") writes it, without
 * printf's cost: the run logs (track.tsv, samples.tsv) write tens of thousands of
 * numbers a run, and printf's exact conversion was a tenth of a run's time
 * (docs/PERFORMANCE.md, "Seek benchmark"). The text is printf's byte for byte: a value
 * whose rounding is in doubt (within a few ulps of a half), out of range or not finite
 * goes to snprintf. */
#ifndef HS_FMT_H
#define HS_FMT_H

#include <stddef.h>

/// Room hs_fmt_fixed() may use, bytes, with the terminating NUL.
#define HS_FMT_MAX 40

/// Write v as printf("%.*f", prec, v) would into buf (HS_FMT_MAX bytes), NUL-terminated;
/// returns the characters written. prec 0..6 take the fast path.
size_t hs_fmt_fixed(char *buf, double v, int prec);

#endif /* HS_FMT_H */
