/* rfs_fix.h - fixed-point types, saturating arithmetic, wide integers and the PRNG.
 *
 * This header owns every Q format used in the core:
 *   rfs_q16_t  signed Q16.16 in int32_t: range [-32768, 32768), step 1/65536 (1.5e-5).
 *              Used for metres, dB, radians, seconds and unitless ratios.
 *   rfs_i128_t signed 128-bit integer, for exact intermediate products in the
 *              ridge solve (the core may not use __int128: not on Cortex-M or -m32).
 * Integers that are not Q16 say their unit in their name (_mm, _cm, _us, _q6, ...).
 *
 * Nothing here calls libgcc helpers: 64-bit division is done by rfs_udiv64() (32-bit
 * hardware divisions for a 32-bit divisor, else shift-subtract), so the library needs no
 * external symbol but memcpy/memset/memmove.
 */
#ifndef RFS_FIX_H
#define RFS_FIX_H

#include <stdbool.h>
#include <stdint.h>

/// Signed Q16.16 fixed point.
typedef int32_t rfs_q16_t;

#define RFS_Q16_ONE ((rfs_q16_t)65536)          ///< 1.0 in Q16.16
#define RFS_Q16_HALF ((rfs_q16_t)32768)         ///< 0.5 in Q16.16
#define RFS_Q16_MAX ((rfs_q16_t)INT32_MAX)      ///< largest Q16.16 (32767.99998)
#define RFS_Q16_MIN ((rfs_q16_t)INT32_MIN)      ///< smallest Q16.16 (-32768)

/// Q16.16 from an integer constant, for compile-time use (no saturation).
#define RFS_Q16_INT(n) ((rfs_q16_t)((n) * 65536))
/// Q16.16 from a constant ratio num/den (rounded toward zero), for compile-time use.
#define RFS_Q16_FRAC(num, den) ((rfs_q16_t)(((int64_t)(num) * 65536) / (den)))

/// Saturate a 64-bit value into int32_t.
static inline int32_t rfs_sat32(int64_t v)
{
    return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (int32_t)v);
}

/// Saturate a 64-bit value into int16_t.
static inline int16_t rfs_sat16(int64_t v)
{
    return v > INT16_MAX ? INT16_MAX : (v < INT16_MIN ? INT16_MIN : (int16_t)v);
}

/// Saturating Q16.16 addition. Scaling and overflow: exact in int64, saturated to Q16.16.
static inline rfs_q16_t rfs_q16_add(rfs_q16_t a, rfs_q16_t b)
{
    return rfs_sat32((int64_t)a + b);
}

/// Saturating Q16.16 subtraction. Scaling and overflow: exact in int64, saturated to Q16.16.
static inline rfs_q16_t rfs_q16_sub(rfs_q16_t a, rfs_q16_t b)
{
    return rfs_sat32((int64_t)a - b);
}

/// Saturating Q16.16 multiplication, rounded to nearest (ties up).
/// Scaling and overflow: Q16.16 x Q16.16 = Q32.32 in int64 (cannot overflow), +2^15,
/// shifted right 16, saturated to Q16.16. Error <= 0.5 LSB unless saturated.
static inline rfs_q16_t rfs_q16_mul(rfs_q16_t a, rfs_q16_t b)
{
    return rfs_sat32(((int64_t)a * b + 32768) >> 16);
}

/// Absolute value, saturating (|INT32_MIN| gives INT32_MAX).
static inline rfs_q16_t rfs_q16_abs(rfs_q16_t a)
{
    return a < 0 ? (a == INT32_MIN ? INT32_MAX : -a) : a;
}

/// Unsigned 64-bit division, floor: long division on 32-bit hardware divisions when d
/// fits 32 bits, else shift-subtract. d == 0 gives UINT64_MAX.
uint64_t rfs_udiv64(uint64_t n, uint64_t d);

/// Signed 64-bit division rounded to nearest (ties away from zero). d == 0 saturates
/// to INT64_MAX/INT64_MIN by the sign of n (0 for n == 0).
int64_t rfs_sdiv64_round(int64_t n, int64_t d);

/// Saturating Q16.16 division a / b, rounded to nearest.
/// Scaling and overflow: a << 16 (Q32.32 in int64, exact) / b (Q16.16) = Q16.16,
/// saturated. b == 0 saturates by the sign of a (0 / 0 = 0).
rfs_q16_t rfs_q16_div(rfs_q16_t a, rfs_q16_t b);

/// floor(sqrt(v)) for a 32-bit unsigned integer; exact.
uint32_t rfs_isqrt32(uint32_t v);

/// floor(sqrt(v)) for a 64-bit unsigned integer; exact.
uint32_t rfs_isqrt64(uint64_t v);

/// Square root of a Q16.16 value, floor of the exact result (error < 1 LSB).
/// Scaling and overflow: x (Q16.16) << 16 = Q32.32 in uint64; its integer square
/// root is Q16.16. Negative input is a programmer error (asserts), 0 gives 0.
rfs_q16_t rfs_q16_sqrt(rfs_q16_t x);

/// Distance between (x0, y0) and (x1, y1), Q16.16 (metres), floor of the exact value.
/// Scaling and overflow: differences of Q16 values fit in 33 bits; each is clamped to 2^31
/// (the result saturates near 46 km) so the Q32 squares sum in uint64; the integer square
/// root of a Q32 value is Q16.
rfs_q16_t rfs_q16_dist(rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1);

/// e^(-x) for x >= 0 in Q16.16, result in [0, 1] Q16.16; negative x is clamped to 0
/// (result 1.0). Error <= 0.55 LSB (8.4e-6) over the whole input range (tested
/// exhaustively on [0, 13); above 13 the result is 0, off by < 0.15 LSB).
/// Scaling and overflow: integer part from a Q30 table of e^-n (n <= 12, above that
/// the result rounds to 0), the top 4 fraction bits from a Q30 table of e^-(k/16),
/// the last 12 bits by a cubic Taylor term in Q30; products Q60 in int64 >> 30.
rfs_q16_t rfs_q16_exp_neg(rfs_q16_t x);

/// log2(x) for x > 0 in Q16.16, rounded to nearest: error <= 0.51 LSB (tested over the
/// whole range); x <= 0 is a programmer error.
/// Scaling and overflow: the integer part from the bit length; 20 fraction bits by
/// squaring a Q31 mantissa in [1, 2) (squares < 2^64 in uint64), rounded to 16.
rfs_q16_t rfs_q16_log2(rfs_q16_t x);

/// 10*log10(x) for x > 0 in Q16.16 (decibels of a power ratio), error <= 0.75 LSB
/// (tested); x <= 0 is a programmer error.
/// Scaling and overflow: log2 in Q20 (< 2^25) times 10*log10(2) in Q28 = Q48 in int64.
rfs_q16_t rfs_q16_db10(rfs_q16_t x);

/// pi in Q16.16 radians (3.14159 rounded: 205887 / 65536).
#define RFS_Q16_PI ((rfs_q16_t)205887)

/// atan2(y, x) in Q16.16 radians, (-pi, pi]; 0 for (0, 0). Error <= 2^-13 rad (tested
/// against double precision).
/// Scaling and overflow: inputs within +-2^62 are shifted so the larger magnitude lies
/// in [2^27, 2^28) (only the ratio matters); 24 CORDIC vectoring iterations in Q28 with
/// the gain 1.65 keep |x|, |y| below 2^29 in int32.
rfs_q16_t rfs_q16_atan2(int64_t y, int64_t x);

/// cos and sin of an angle (Q16.16 radians, any value within +-2^15 rad) in Q16.16,
/// error <= 2^-14 (tested against double precision).
/// Scaling and overflow: the angle is reduced to [-pi/2, pi/2] (a half-turn flips both
/// signs); CORDIC rotation in Q28 (|x|, |y| <= 2^28 with the gain compensated at the
/// start), 24 iterations, rounded to Q16.
void rfs_q16_sincos(rfs_q16_t a, rfs_q16_t *c, rfs_q16_t *s);

/// Signed 128-bit integer as two 64-bit halves (two's complement).
typedef struct rfs_i128 {
    uint64_t lo; ///< low 64 bits
    int64_t hi;  ///< high 64 bits, carries the sign
} rfs_i128_t;

/// Exact 64 x 64 -> 128-bit signed product.
rfs_i128_t rfs_i128_mul(int64_t a, int64_t b);

/// 128-bit a - b (wraps on overflow, which cannot happen for products of int64).
rfs_i128_t rfs_i128_sub(rfs_i128_t a, rfs_i128_t b);

/// 128-bit a + b.
rfs_i128_t rfs_i128_add(rfs_i128_t a, rfs_i128_t b);

/// true when a < 0.
static inline bool rfs_i128_neg(rfs_i128_t a) { return a.hi < 0; }

/// Round-to-nearest quotient (n * 2^shift) / d, saturated to int64.
/// d == 0 saturates by the sign of n. shift is 0..62. Exact otherwise.
int64_t rfs_i128_div_shift(rfs_i128_t n, rfs_i128_t d, unsigned shift);

/// Deterministic PRNG (xoshiro128++), state owned by the caller.
typedef struct rfs_rng {
    uint32_t s[4]; ///< generator state, never all zero
} rfs_rng_t;

/// Seed the generator from a 64-bit seed (splitmix64 expansion). Any seed is valid.
void rfs_rng_seed(rfs_rng_t *rng, uint64_t seed);

/// Next 32 uniformly distributed bits.
uint32_t rfs_rng_u32(rfs_rng_t *rng);

/// Uniform integer in [0, n) without modulo bias (Lemire's method); n == 0 gives 0.
uint32_t rfs_rng_below(rfs_rng_t *rng, uint32_t n);

/// Uniform Q16.16 in [0, 1).
static inline rfs_q16_t rfs_rng_q16(rfs_rng_t *rng)
{
    return (rfs_q16_t)(rfs_rng_u32(rng) >> 16);
}

#endif /* RFS_FIX_H */
