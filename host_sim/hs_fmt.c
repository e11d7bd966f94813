/* hs_fmt.c - printf("%.*f") text of doubles, fast (see hs_fmt.h). */
#include "hs_fmt.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

static const double k_pow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6};

size_t hs_fmt_fixed(char *buf, double v, int prec)
{
    double a = fabs(v);
    if (prec < 0 || prec > 6 || !(a < 1e9)) { /* NaN fails the comparison */
        return (size_t)snprintf(buf, HS_FMT_MAX, "%.*f", prec, v);
    }
    /* s is a 10^prec (exact) rounded once: within s 2^-53 of the true product, so the
     * true value rounds the same way unless its fraction is that close to a half (then
     * printf's exact conversion decides, ties to even included). */
    double s = a * k_pow10[prec];
    double n = floor(s);
    double frac = s - n; /* exact below 2^52 */
    if (fabs(frac - 0.5) <= s * 0x1p-50 + 0x1p-40) {
        return (size_t)snprintf(buf, HS_FMT_MAX, "%.*f", prec, v);
    }
    uint64_t u = (uint64_t)n + (frac > 0.5 ? 1u : 0u);
    char dig[24];
    int k = 0;
    do {
        dig[k++] = (char)('0' + (int)(u % 10u));
        u /= 10u;
    } while (u != 0u || k <= prec);
    char *p = buf;
    if (signbit(v)) { /* printf keeps the sign of a negative value rounded to zero */
        *p++ = '-';
    }
    for (int i = k - 1; i >= prec; --i) {
        *p++ = dig[i];
    }
    if (prec > 0) {
        *p++ = '.';
        for (int i = prec - 1; i >= 0; --i) {
            *p++ = dig[i];
        }
    }
    *p = '\0';
    return (size_t)(p - buf);
}
