/*
 * util/rng.c — correlated multi-jittered sampling (Kensler, "Correlated
 * Multi-Jittered Sampling", Pixar technical memo 13-01, 2013), written from
 * the memo's description: a hashed permutation of any length, and a hashed
 * jitter, so that the s-th sample is computed on its own, in O(1). Pure
 * functions; thread-safe.
 */
#include "util/rng.h"

#include <math.h>

/* One round of the permutation's hash over [0, w], w + 1 a power of two. */
static inline uint32_t permute_round(uint32_t i, uint32_t w, uint32_t p)
{
    i ^= p;
    i *= 0xe170893du;
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i *= 0x0929eb3fu;
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | p >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
    return i;
}

/* A permutation of [0, l) chosen by p, evaluated at i, by cycle-walking a
 * hash over the next power of two. */
static uint32_t permute(uint32_t i, uint32_t l, uint32_t p)
{
    uint32_t w = l - 1;
    if (l <= 1)
        return 0;
    if ((l & w) == 0)
        return (permute_round(i, w, p) + p) & w; /* one round; % l is & w */
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    do {
        i = permute_round(i, w, p);
    } while (i >= l);
    return (i + p) % l;
}

static float randfloat(uint32_t i, uint32_t p)
{
    i ^= p;
    i ^= i >> 17;
    i ^= i >> 10;
    i *= 0xb36534e5u;
    i ^= i >> 12;
    i ^= i >> 21;
    i *= 0x93fc4795u;
    i ^= 0xdf6e307fu;
    i ^= i >> 17;
    i *= 1u | p >> 18;
    return (float)(i >> 8) * (1.0f / 16777216.0f);
}

void cmj_sample_2d(uint32_t s, uint32_t n, uint32_t p, float *x, float *y)
{
    uint32_t m = (uint32_t)sqrtf((float)n);
    if (m * m > n)
        m--;
    while ((m + 1) * (m + 1) <= n)
        m++;
    if (m == 0)
        m = 1;
    uint32_t k = (n + m - 1) / m; /* m columns, k rows: m * k >= n strata */
    s = permute(s, n, p * 0x51633e2du);
    uint32_t col, row; /* s % m and s / m: a mask and a shift when m is a power of two */
    if ((m & (m - 1)) == 0) {
        col = s & (m - 1);
        row = s >> __builtin_ctz(m);
    } else {
        col = s % m;
        row = s / m;
    }
    uint32_t sx = permute(col, m, p * 0x68bc21ebu);
    uint32_t sy = permute(row, k, p * 0x02e5be93u);
    float jx = randfloat(s, p * 0x967a889bu);
    float jy = randfloat(s, p * 0x368cc8b7u);
    float fx = ((float)col + ((float)sy + jx) / (float)k) / (float)m;
    float fy = ((float)row + ((float)sx + jy) / (float)m) / (float)k;
    *x = fminf(fx, 0x1.fffffep-1f);
    *y = fminf(fy, 0x1.fffffep-1f);
}

float stratified_1d(uint32_t s, uint32_t n, uint32_t p)
{
    uint32_t stratum = permute(s % n, n, p * 0x9e3779b9u);
    float x = ((float)stratum + randfloat(s, p * 0x85ebca6bu)) / (float)n;
    return x < 1.0f ? x : 0x1.fffffep-1f;
}
