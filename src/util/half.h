/*
 * util/half.h — IEEE 754 binary16 ("half") conversion, by bit manipulation
 * (no _Float16 or F16C needed): round to nearest even, subnormals kept,
 * NaN kept quiet. half_from_float_clamped clamps to the largest finite half
 * (65504) first, as the radiosity cache stores values (memo 3.1; digest 7).
 * Pure functions; thread-safe.
 */
#ifndef RAYES_UTIL_HALF_H
#define RAYES_UTIL_HALF_H

#include <stdint.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define HALF_MAX 65504.0f

static inline uint16_t half_from_float(float f)
{
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u;
    uint32_t abs = x & 0x7fffffffu;
    if (abs >= 0x7f800000u) /* inf or NaN */
        return (uint16_t)(sign | 0x7c00u | (abs > 0x7f800000u ? 0x200u | (abs >> 13) : 0u));
    if (abs >= 0x477ff000u) /* rounds to >= 65520: infinity */
        return (uint16_t)(sign | 0x7c00u);
    if (abs < 0x38800000u) { /* below the smallest normal half: subnormal or zero */
        if (abs < 0x33000000u) /* below half the smallest subnormal (2^-25): zero */
            return (uint16_t)sign;
        uint32_t e = abs >> 23, m = (abs & 0x7fffffu) | 0x800000u;
        uint32_t shift = 126u - e; /* 14..24 bits out */
        uint32_t r = m >> shift, rest = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
        if (rest > halfway || (rest == halfway && (r & 1u)))
            r++;
        return (uint16_t)(sign | r);
    }
    uint32_t r = (abs - 0x38000000u) >> 13; /* rebias 127 -> 15 */
    uint32_t rest = abs & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (r & 1u)))
        r++; /* may carry into the exponent, which is right */
    return (uint16_t)(sign | r);
}

/* half_to_float for finite halves (what the cache stores: it clamps),
 * branch-free: the half's bits moved into a float's place and rescaled by
 * 2^112, exact for normal and subnormal halves alike. */
static inline float half_to_float_finite(uint16_t h)
{
    uint32_t x = ((uint32_t)(h & 0x8000u) << 16) | ((uint32_t)(h & 0x7fffu) << 13);
    float f;
    memcpy(&f, &x, sizeof f);
    return f * 0x1p112f;
}

/* Six finite halves (two corners of a brick's cell, three channels each)
 * to floats, as half_to_float_finite does one: the same bits, four and
 * two at a time where SSE2 is there (every x86-64). */
static inline void half_to_float_finite_x6(const uint16_t *h, float *out)
{
#if defined(__SSE2__)
    uint64_t lo4;
    uint32_t hi2;
    memcpy(&lo4, h, sizeof lo4);
    memcpy(&hi2, h + 4, sizeof hi2);
    __m128i zero = _mm_setzero_si128();
    __m128i a = _mm_unpacklo_epi16(_mm_cvtsi64_si128((long long)lo4), zero);
    __m128i b = _mm_unpacklo_epi16(_mm_cvtsi32_si128((int)hi2), zero);
    __m128i sign = _mm_set1_epi32(0x8000), mag = _mm_set1_epi32(0x7fff);
    __m128 scale = _mm_set1_ps(0x1p112f);
    __m128i xa = _mm_or_si128(_mm_slli_epi32(_mm_and_si128(a, sign), 16),
                              _mm_slli_epi32(_mm_and_si128(a, mag), 13));
    __m128i xb = _mm_or_si128(_mm_slli_epi32(_mm_and_si128(b, sign), 16),
                              _mm_slli_epi32(_mm_and_si128(b, mag), 13));
    _mm_storeu_ps(out, _mm_mul_ps(_mm_castsi128_ps(xa), scale));
    __m128 fb = _mm_mul_ps(_mm_castsi128_ps(xb), scale);
    _mm_storel_pi((__m64 *)(out + 4), fb);
#else
    for (int k = 0; k < 6; k++)
        out[k] = half_to_float_finite(h[k]);
#endif
}

static inline float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu, x;
    if (e == 0x1fu)
        x = sign | 0x7f800000u | (m << 13);
    else if (e != 0)
        x = sign | ((e + 112u) << 23) | (m << 13);
    else if (m == 0)
        x = sign;
    else { /* subnormal: normalise */
        e = 113u;
        while (!(m & 0x400u)) {
            m <<= 1;
            e--;
        }
        x = sign | (e << 23) | ((m & 0x3ffu) << 13);
    }
    float f;
    memcpy(&f, &x, sizeof f);
    return f;
}

/* Clamped to [-65504, 65504] before conversion; NaN becomes 0. */
static inline uint16_t half_from_float_clamped(float f)
{
    if (!(f == f))
        f = 0.0f;
    f = f > HALF_MAX ? HALF_MAX : f < -HALF_MAX ? -HALF_MAX : f;
    return half_from_float(f);
}

#endif /* RAYES_UTIL_HALF_H */
