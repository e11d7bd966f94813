/* rfs_fix.c - fixed-point arithmetic, wide integers and the PRNG (see rfs_fix.h). */
#include "rfs_fix.h"

#include "rfs_assert.h"

/* floor((hi * 2^32 + lo) / v) for 0 < v and hi < v (so the quotient fits 32 bits):
 * Knuth's algorithm D on 16-bit digits (Hacker's Delight, 2nd ed.,
 * section 9-4, divlu). Two 32-bit hardware divisions, each quotient digit corrected at
 * most twice.
 * Scaling and overflow: v is shifted left until its top bit is set and the dividend with
 * it (hi < v keeps it in 64 bits); digit products q * vn0 are taken only for q < 2^16, so
 * they fit 32 bits; the partial remainder un21 is below v, so its wrapping 32-bit
 * arithmetic is exact. */
static uint32_t div64_32(uint32_t hi, uint32_t lo, uint32_t v)
{
    const uint32_t b = 65536u;
    int s = __builtin_clz(v);
    v <<= s;
    uint32_t vn1 = v >> 16, vn0 = v & 0xFFFFu;
    uint32_t un32 = s == 0 ? hi : (hi << s) | (lo >> (32 - s));
    uint32_t un10 = lo << s;
    uint32_t un1 = un10 >> 16, un0 = un10 & 0xFFFFu;
    uint32_t q1 = un32 / vn1;
    uint32_t rhat = un32 - q1 * vn1;
    while (q1 >= b || q1 * vn0 > b * rhat + un1) {
        q1--;
        rhat += vn1;
        if (rhat >= b) {
            break;
        }
    }
    uint32_t un21 = un32 * b + un1 - q1 * v;
    uint32_t q0 = un21 / vn1;
    rhat = un21 - q0 * vn1;
    while (q0 >= b || q0 * vn0 > b * rhat + un0) {
        q0--;
        rhat += vn1;
        if (rhat >= b) {
            break;
        }
    }
    return q1 * b + q0;
}

uint64_t rfs_udiv64(uint64_t n, uint64_t d)
{
    if (d == 0u) {
        return UINT64_MAX;
    }
    if (n < d) {
        return 0u;
    }
    if (d <= UINT32_MAX) {
        /* A 32-bit divisor: 32-bit hardware divisions (the Cortex-M4's UDIV), high word
         * first, then the 64 / 32 step with the quotient known to fit 32 bits. */
        uint32_t v = (uint32_t)d, hi = (uint32_t)(n >> 32);
        if (hi == 0u) {
            return (uint32_t)n / v;
        }
        uint32_t qh = hi / v;
        uint32_t ql = div64_32(hi - qh * v, (uint32_t)n, v);
        return ((uint64_t)qh << 32) | ql;
    }
    /* Align the divisor's top bit with the dividend's, then shift-subtract: as many
     * rounds as the bit-length difference (at most 32 here), never a libgcc call. */
    int shift = __builtin_clzll(d) - __builtin_clzll(n);
    uint64_t q = 0u;
    d <<= shift;
    for (; shift >= 0; --shift) {
        q <<= 1;
        if (n >= d) {
            n -= d;
            q |= 1u;
        }
        d >>= 1;
    }
    return q;
}

int64_t rfs_sdiv64_round(int64_t n, int64_t d)
{
    if (d == 0) {
        return n > 0 ? INT64_MAX : (n < 0 ? INT64_MIN : 0);
    }
    bool neg = (n < 0) != (d < 0);
    uint64_t un = n < 0 ? (uint64_t)0 - (uint64_t)n : (uint64_t)n;
    uint64_t ud = d < 0 ? (uint64_t)0 - (uint64_t)d : (uint64_t)d;
    uint64_t q = rfs_udiv64(un, ud);
    uint64_t r = un - q * ud;
    if (r >= ud - r) { /* r >= d/2 without overflow: round half away from zero */
        q += 1u;
    }
    if (neg) {
        return q > (uint64_t)INT64_MAX ? INT64_MIN : -(int64_t)q;
    }
    return q > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)q;
}

rfs_q16_t rfs_q16_div(rfs_q16_t a, rfs_q16_t b)
{
    if (b == 0) {
        return a > 0 ? RFS_Q16_MAX : (a < 0 ? RFS_Q16_MIN : 0);
    }
    /* |a| << 16 < 2^47 and |b| >= 1: the quotient fits int64 and rounds exactly. */
    return rfs_sat32(rfs_sdiv64_round((int64_t)a * 65536, b));
}

uint32_t rfs_isqrt32(uint32_t v)
{
    return rfs_isqrt64(v);
}

uint32_t rfs_isqrt64(uint64_t v)
{
    /* Digit-by-digit (base 4) square root: 32 rounds, exact floor. */
    uint64_t rem = v;
    uint64_t root = 0u;
    uint64_t bit = (uint64_t)1 << 62;
    while (bit > rem) {
        bit >>= 2;
    }
    while (bit != 0u) {
        if (rem >= root + bit) {
            rem -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    return (uint32_t)root;
}

rfs_q16_t rfs_q16_sqrt(rfs_q16_t x)
{
    RFS_ASSERT(x >= 0);
    return (rfs_q16_t)rfs_isqrt64((uint64_t)(uint32_t)x << 16);
}

rfs_q16_t rfs_q16_dist(rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1)
{
    int64_t dx = (int64_t)x1 - x0;
    int64_t dy = (int64_t)y1 - y0;
    uint64_t ax = (uint64_t)(dx < 0 ? -dx : dx);
    uint64_t ay = (uint64_t)(dy < 0 ? -dy : dy);
    ax = ax > 0x80000000u ? 0x80000000u : ax;
    ay = ay > 0x80000000u ? 0x80000000u : ay;
    uint32_t d = rfs_isqrt64(ax * ax + ay * ay);
    return d > (uint32_t)INT32_MAX ? INT32_MAX : (rfs_q16_t)d;
}

/* e^-n in Q30 for n = 0..12 (round(exp(-n) * 2^30)). */
static const int32_t k_exp_int_q30[13] = {
    1073741824, 395007542, 145315154, 53458458, 19666268, 7234816, 2661540,
    979126,     360200,    132510,    48748,    17933,    6597,
};

/* e^-(k/16) in Q30 for k = 0..15. */
static const int32_t k_exp_frac_q30[16] = {
    1073741824, 1008687096, 947573834, 890163238, 836230973, 785566300,
    737971244,  693259826,  651257337, 611799650, 574732583, 539911296,
    507199724,  476470046,  447602185, 420483340,
};

rfs_q16_t rfs_q16_exp_neg(rfs_q16_t x)
{
    if (x <= 0) {
        return RFS_Q16_ONE;
    }
    int32_t n = x >> 16;
    if (n > 12) {
        return 0; /* e^-13 * 2^16 = 0.15 LSB */
    }
    uint32_t k = ((uint32_t)x >> 12) & 15u;
    /* r in [0, 1/16) as Q30: the low 12 bits of Q16 shifted up by 14. */
    int64_t r = (int64_t)((uint32_t)x & 0xFFFu) << 14;
    int64_t r2 = (r * r) >> 30;
    int64_t r3 = (r2 * r) >> 30;
    /* 1 - r + r^2/2 - r^3/6 in Q30; truncation error < (1/16)^4/24 = 6e-7. */
    int64_t poly = ((int64_t)1 << 30) - r + (r2 >> 1) - ((r3 * 178956971) >> 30); /* 1/6 in Q30 */
    int64_t v = ((int64_t)k_exp_int_q30[n] * k_exp_frac_q30[k]) >> 30;
    v = (v * poly) >> 30;
    return (rfs_q16_t)((v + (1 << 13)) >> 14);
}

/* log2(x) for x > 0 (x Q16.16) in Q43.20: the integer part from the bit length, 20
 * fraction bits by repeated squaring of a Q31 mantissa in [1, 2) (squares < 2^64 in
 * uint64, truncated). Error below 2^-19 (measured over the whole range by test_fix). */
static int64_t log2_q20(rfs_q16_t x)
{
    int bitlen = 32 - __builtin_clz((uint32_t)x);
    int64_t e = bitlen - 17;
    /* Mantissa in Q31: the top bit of x lands at bit 31. */
    uint64_t m = (uint64_t)(uint32_t)x << (32 - bitlen);
    int64_t frac = 0;
    for (int i = 0; i < 20; ++i) {
        m = (m * m) >> 31; /* m < 2^32, m^2 < 2^64; result in [1, 4) Q31 */
        const uint64_t top = m >> 32; /* m >= 2: the next bit is 1 (branch-free: it is */
        frac = (frac << 1) | (int64_t)top; /* a coin toss, mispredicted half the time) */
        m >>= top;
    }
    return e * ((int64_t)1 << 20) + frac;
}

rfs_q16_t rfs_q16_log2(rfs_q16_t x)
{
    RFS_ASSERT(x > 0);
    /* Q20 to Q16, rounded to nearest (ties up). */
    return (rfs_q16_t)((log2_q20(x) + 8) >> 4);
}

rfs_q16_t rfs_q16_db10(rfs_q16_t x)
{
    RFS_ASSERT(x > 0);
    /* 10*log10(x) = log2(x) * 10*log10(2). 10*log10(2) = 3.01029996 = 808071242 in Q28
     * (rounded). Scaling and overflow: |log2| < 17 in Q20 (< 2^25) x Q28 (< 2^30) =
     * Q48 < 2^55 in int64; + 2^31, >> 32 rounds to Q16. */
    return (rfs_q16_t)((log2_q20(x) * 808071242 + ((int64_t)1 << 31)) >> 32);
}

static rfs_i128_t u128_mul(uint64_t a, uint64_t b)
{
    uint64_t a0 = (uint32_t)a, a1 = a >> 32;
    uint64_t b0 = (uint32_t)b, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (uint32_t)p01 + (uint32_t)p10;
    rfs_i128_t r;
    r.lo = (mid << 32) | (uint32_t)p00;
    r.hi = (int64_t)(p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32));
    return r;
}

static rfs_i128_t i128_negate(rfs_i128_t a)
{
    rfs_i128_t r;
    r.lo = ~a.lo + 1u;
    r.hi = (int64_t)(~(uint64_t)a.hi + (r.lo == 0u ? 1u : 0u));
    return r;
}

rfs_i128_t rfs_i128_mul(int64_t a, int64_t b)
{
    bool neg = (a < 0) != (b < 0);
    uint64_t ua = a < 0 ? (uint64_t)0 - (uint64_t)a : (uint64_t)a;
    uint64_t ub = b < 0 ? (uint64_t)0 - (uint64_t)b : (uint64_t)b;
    rfs_i128_t r = u128_mul(ua, ub);
    return neg ? i128_negate(r) : r;
}

rfs_i128_t rfs_i128_add(rfs_i128_t a, rfs_i128_t b)
{
    rfs_i128_t r;
    r.lo = a.lo + b.lo;
    r.hi = (int64_t)((uint64_t)a.hi + (uint64_t)b.hi + (r.lo < a.lo ? 1u : 0u));
    return r;
}

rfs_i128_t rfs_i128_sub(rfs_i128_t a, rfs_i128_t b)
{
    return rfs_i128_add(a, i128_negate(b));
}

/* Unsigned 128-bit helpers on (hi, lo) pairs, hi kept as uint64. */
static int u128_cmp(uint64_t ah, uint64_t al, uint64_t bh, uint64_t bl)
{
    if (ah != bh) {
        return ah < bh ? -1 : 1;
    }
    return al < bl ? -1 : (al > bl ? 1 : 0);
}

/* (w2, w1, w0) >> sh for 0 <= sh < 192, when the result fits 128 bits (hi, lo). */
static void shr192(uint64_t w2, uint64_t w1, uint64_t w0, int sh, uint64_t *hi, uint64_t *lo)
{
    if (sh >= 128) {
        *hi = 0u;
        *lo = w2 >> (sh - 128);
    } else if (sh >= 64) {
        const int t = sh - 64;
        *hi = w2 >> t;
        *lo = t ? (w1 >> t) | (w2 << (64 - t)) : w1;
    } else {
        *hi = sh ? (w1 >> sh) | (w2 << (64 - sh)) : w1;
        *lo = sh ? (w0 >> sh) | (w1 << (64 - sh)) : w0;
    }
}

/* rfs_i128_div_shift() for a quotient below 2^30: numerator N = (w2, w1, w0) of nb bits,
 * divisor D = (dh, dl) of db bits, db <= 125, nb - db <= 29. The quotient is estimated
 * from D's top 31 bits with one 64 / 32 division (never above the true one, at most two
 * below), then corrected and rounded on the remainder: the long division's result bit for
 * bit, in a few dozen instructions instead of one 128-bit round per quotient bit.
 * Scaling and overflow: N >> s (s = db - 31) has <= nb - db + 31 <= 60 bits; with the
 * estimate q <= N / D, N - q D < 3 D < 2^127, so the remainder is exact from N's and
 * q D's low 128 bits (q D taken modulo 2^128). Not inlined: one copy beside the long
 * division keeps the Cortex-M4 image small. */
__attribute__((noinline)) static int64_t div_small(uint64_t w2, uint64_t w1, uint64_t w0,
                                                   uint64_t dh, uint64_t dl, int db, bool neg)
{
    uint64_t nt = w0, dt = dl; /* db <= 31: D and N fit one word each, exact */
    if (db > 31) {
        const int s = db - 31;
        uint64_t nh;
        shr192(w2, w1, w0, s, &nh, &nt);
        dt = (s >= 64 ? dh >> (s - 64) : (dl >> s) | (dh << (64 - s))) + 1u;
    }
    uint64_t q = rfs_udiv64(nt, dt);
    rfs_i128_t qd = u128_mul(q, dl);
    uint64_t ph = (uint64_t)qd.hi + q * dh;
    uint64_t rl = w0 - qd.lo;
    uint64_t rh = w1 - ph - (w0 < qd.lo ? 1u : 0u);
    while (u128_cmp(rh, rl, dh, dl) >= 0) {
        rh = rh - dh - (rl < dl ? 1u : 0u);
        rl -= dl;
        q++;
    }
    /* Round to nearest: remainder * 2 >= d (the remainder is below 2^125). */
    if (u128_cmp((rh << 1) | (rl >> 63), rl << 1, dh, dl) >= 0) {
        q++;
    }
    return neg ? -(int64_t)q : (int64_t)q;
}

int64_t rfs_i128_div_shift(rfs_i128_t n, rfs_i128_t d, unsigned shift)
{
    RFS_ASSERT(shift <= 62u);
    bool nneg = rfs_i128_neg(n), dneg = rfs_i128_neg(d);
    if (nneg) {
        n = i128_negate(n);
    }
    if (dneg) {
        d = i128_negate(d);
    }
    uint64_t nh = (uint64_t)n.hi, nl = n.lo, dh = (uint64_t)d.hi, dl = d.lo;
    if (dh == 0u && dl == 0u) {
        if (nh == 0u && nl == 0u) {
            return 0;
        }
        return nneg ? INT64_MIN : INT64_MAX;
    }
    /* Numerator times 2^shift needs up to 190 bits: keep it as three words. */
    uint64_t w2 = shift ? nh >> (64u - shift) : 0u;
    uint64_t w1 = shift ? (nh << shift) | (nl >> (64u - shift)) : nh;
    uint64_t w0 = nl << shift;
    /* Long division, one bit per round over 192 bits; remainder stays < 2 * d. The
     * numerator's top bits shorter than d (db bits) only shift into the remainder with
     * quotient bits 0: they are taken at once, and the rounds start below them. */
    uint64_t rh = 0u, rl = 0u, qh = 0u, ql = 0u;
    bool overflow = false;
    int top_bit = w2 ? 191 - __builtin_clzll(w2) : w1 ? 127 - __builtin_clzll(w1)
                : w0 ? 63 - __builtin_clzll(w0) : -1;
    const int db = dh ? 128 - __builtin_clzll(dh) : 64 - __builtin_clzll(dl);
    if (db <= 125 && top_bit + 1 - db <= 29) {
        return div_small(w2, w1, w0, dh, dl, db, nneg != dneg);
    }
    const int skip = top_bit + 1 < db - 1 ? top_bit + 1 : db - 1; /* bits taken at once */
    if (skip > 0) {
        shr192(w2, w1, w0, top_bit + 1 - skip, &rh, &rl);
        top_bit -= skip;
    }
    for (int i = top_bit; i >= 0; --i) {
        uint64_t bit = i >= 128 ? (w2 >> ((unsigned)(i - 128) & 63u)) & 1u
                     : i >= 64  ? (w1 >> ((unsigned)(i - 64) & 63u)) & 1u
                                : (w0 >> ((unsigned)i & 63u)) & 1u;
        uint64_t top = rh >> 63;
        rh = (rh << 1) | (rl >> 63);
        rl = (rl << 1) | bit;
        if (qh >> 63) {
            overflow = true;
        }
        qh = (qh << 1) | (ql >> 63);
        ql <<= 1;
        if (top || u128_cmp(rh, rl, dh, dl) >= 0) {
            uint64_t borrow = rl < dl ? 1u : 0u;
            rl -= dl;
            rh = rh - dh - borrow;
            ql |= 1u;
        }
    }
    /* Round to nearest: remainder * 2 >= d. */
    uint64_t r2h = (rh << 1) | (rl >> 63), r2l = rl << 1;
    if ((rh >> 63) || u128_cmp(r2h, r2l, dh, dl) >= 0) {
        ql += 1u;
        if (ql == 0u) {
            qh += 1u;
        }
    }
    if (overflow || qh != 0u || ql > (uint64_t)INT64_MAX) {
        return (nneg != dneg) ? INT64_MIN : INT64_MAX;
    }
    return (nneg != dneg) ? -(int64_t)ql : (int64_t)ql;
}

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void rfs_rng_seed(rfs_rng_t *rng, uint64_t seed)
{
    RFS_ASSERT(rng != 0);
    uint64_t x = seed;
    uint64_t a = splitmix64(&x), b = splitmix64(&x);
    rng->s[0] = (uint32_t)a;
    rng->s[1] = (uint32_t)(a >> 32);
    rng->s[2] = (uint32_t)b;
    rng->s[3] = (uint32_t)(b >> 32);
    if ((rng->s[0] | rng->s[1] | rng->s[2] | rng->s[3]) == 0u) {
        rng->s[0] = 1u;
    }
}

static uint32_t rotl32(uint32_t x, int k)
{
    return (x << k) | (x >> (32 - k));
}

uint32_t rfs_rng_u32(rfs_rng_t *rng)
{
    uint32_t *s = rng->s;
    uint32_t result = rotl32(s[0] + s[3], 7) + s[0];
    uint32_t t = s[1] << 9;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl32(s[3], 11);
    return result;
}

uint32_t rfs_rng_below(rfs_rng_t *rng, uint32_t n)
{
    if (n == 0u) {
        return 0u;
    }
    uint64_t m = (uint64_t)rfs_rng_u32(rng) * n;
    uint32_t low = (uint32_t)m;
    if (low < n) {
        uint32_t threshold = (0u - n) % n;
        while (low < threshold) {
            m = (uint64_t)rfs_rng_u32(rng) * n;
            low = (uint32_t)m;
        }
    }
    return (uint32_t)(m >> 32);
}

/* atan(2^-i) for i = 0..23 in Q28 radians (round(atan(2^-i) * 2^28)). */
static const int32_t ATAN_Q28[24] = {
    210828714, 124459457, 65760959, 33381290, 16755422, 8385879, 4193963, 2097109,
    1048571,   524287,    262144,   131072,   65536,    32768,   16384,   8192,
    4096,      2048,      1024,     512,      256,      128,     64,      32};

rfs_q16_t rfs_q16_atan2(int64_t y, int64_t x)
{
    if (x == 0 && y == 0) {
        return 0;
    }
    int64_t ax = x < 0 ? -x : x;
    int64_t ay = y < 0 ? -y : y;
    int64_t mx = ax > ay ? ax : ay;
    while (mx >= ((int64_t)1 << 28)) {
        x /= 2;
        y /= 2;
        mx >>= 1;
    }
    while (mx < ((int64_t)1 << 27)) {
        x *= 2;
        y *= 2;
        mx <<= 1;
    }
    int32_t xi = (int32_t)x;
    int32_t yi = (int32_t)y;
    int64_t base = 0; /* Q28 */
    if (xi < 0) {
        base = yi >= 0 ? (int64_t)843314857 : -(int64_t)843314857; /* pi in Q28 */
        xi = -xi;
        yi = -yi;
    }
    int32_t z = 0; /* Q28 */
    for (int i = 0; i < 24; i++) {
        int32_t xs = xi >> i;
        int32_t ys = yi >> i;
        if (yi > 0) {
            xi += ys;
            yi -= xs;
            z += ATAN_Q28[i];
        } else {
            xi -= ys;
            yi += xs;
            z -= ATAN_Q28[i];
        }
    }
    int64_t a = (base + z + 2048) >> 12; /* Q16, rounded */
    if (a > RFS_Q16_PI) {
        a -= 2 * (int64_t)RFS_Q16_PI;
    } else if (a <= -RFS_Q16_PI) {
        a += 2 * (int64_t)RFS_Q16_PI;
    }
    return (rfs_q16_t)a;
}

void rfs_q16_sincos(rfs_q16_t a, rfs_q16_t *c, rfs_q16_t *s)
{
    const int64_t pi28 = 843314857;   /* pi in Q28 */
    const int64_t two_pi28 = 1686629713;
    int64_t z = (int64_t)a * 4096;    /* Q28, |z| < 2^43 */
    /* Reduce to (-pi, pi]: one division, not a loop, whatever the angle. */
    z -= rfs_sdiv64_round(z, two_pi28) * two_pi28;
    if (z <= -pi28) {
        z += two_pi28;
    } else if (z > pi28) {
        z -= two_pi28;
    }
    int32_t sign = 1;
    if (z > pi28 / 2) {
        z -= pi28;
        sign = -1;
    } else if (z < -pi28 / 2) {
        z += pi28;
        sign = -1;
    }
    int32_t x = 163008219; /* 1 / CORDIC gain (0.607253) in Q28 */
    int32_t y = 0;
    int32_t zz = (int32_t)z;
    for (int i = 0; i < 24; i++) {
        int32_t xs = x >> i;
        int32_t ys = y >> i;
        if (zz >= 0) {
            x -= ys;
            y += xs;
            zz -= ATAN_Q28[i];
        } else {
            x += ys;
            y -= xs;
            zz += ATAN_Q28[i];
        }
    }
    *c = (rfs_q16_t)(sign * ((x + 2048) >> 12));
    *s = (rfs_q16_t)(sign * ((y + 2048) >> 12));
}
