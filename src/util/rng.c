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

/* permute(., l, p) set up once for many indices: the mask, and the final
 * (i + p) % l done without a division (i < l, so only p mod l and whether
 * i + p wraps past 2^32 matter). */
typedef struct Permutation {
    uint32_t l, w, p;
    uint32_t p_mod;     /* p % l */
    uint32_t wrap;      /* l - 2^32 % l: what a wrapped sum i + p gains mod l */
} Permutation;

static void permutation_init(Permutation *pm, uint32_t l, uint32_t p)
{
    uint32_t w = l > 0 ? l - 1 : 0;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    pm->l = l;
    pm->w = w;
    pm->p = p;
    int general = l > 1 && (l & (l - 1)) != 0; /* not a power of two: the cycle walk */
    pm->p_mod = general ? p % l : 0;
    pm->wrap = general ? l - (uint32_t)((1ull << 32) % l) : 0;
}

/* permute(i, l, p), bit for bit. */
static inline uint32_t permutation_at(const Permutation *pm, uint32_t i)
{
    uint32_t l = pm->l;
    if (l <= 1)
        return 0;
    if ((l & (l - 1)) == 0)
        return (permute_round(i, pm->w, pm->p) + pm->p) & pm->w;
    do {
        i = permute_round(i, pm->w, pm->p);
    } while (i >= l);
    uint32_t r = i + pm->p_mod; /* (i + p) mod l, from below 3 l */
    if (i + pm->p < i)
        r += pm->wrap;
    r = r >= l ? r - l : r;
    return r >= l ? r - l : r;
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

/* m columns and k rows of strata for n samples. Where n has a divisor m
 * <= sqrt(n) of at least half floor(sqrt(n)) (the strata no more than
 * about 4 times taller than wide), n = m k and every stratum holds a
 * sample. Otherwise (a prime n, say) m = floor(sqrt(n)), k = ceil(n / m),
 * and the n samples take n of the m k strata, the ones the pattern's
 * permutation of all m k picks: which strata stay empty changes from
 * pattern to pattern, so the points are uniform on average. (Taking the
 * first n strata, as Kensler's arbitrary-n variant does, always left the
 * top row's end empty: an estimate with n = 32 came out 0.7% dark.) */
void cmj_strata(uint32_t n, uint32_t *m_out, uint32_t *k_out)
{
    uint32_t m = (uint32_t)sqrtf((float)n);
    if (m * m > n)
        m--;
    while ((m + 1) * (m + 1) <= n)
        m++;
    if (m == 0)
        m = 1;
    for (uint32_t d = m; 2 * d >= m; d--)
        if (n % d == 0) {
            *m_out = d;
            *k_out = n / d;
            return;
        }
    *m_out = m;
    *k_out = (n + m - 1) / m;
}

/* The point of stratum s (already permuted) given its column's and row's
 * shuffled sub-strata sx and sy. */
static inline void cmj_point(uint32_t s, uint32_t col, uint32_t row, uint32_t sx, uint32_t sy,
                             uint32_t m, uint32_t k, uint32_t p, float *x, float *y)
{
    float jx = randfloat(s, p * 0x967a889bu);
    float jy = randfloat(s, p * 0x368cc8b7u);
    float fx = ((float)col + ((float)sy + jx) / (float)k) / (float)m;
    float fy = ((float)row + ((float)sx + jy) / (float)m) / (float)k;
    *x = fx < 0x1.fffffep-1f ? fx : 0x1.fffffep-1f;
    *y = fy < 0x1.fffffep-1f ? fy : 0x1.fffffep-1f;
}

/* s % m and s / m: a mask and a shift when m is a power of two. */
static inline void cmj_cell(uint32_t s, uint32_t m, uint32_t *col, uint32_t *row)
{
    if ((m & (m - 1)) == 0) {
        *col = s & (m - 1);
        *row = s >> __builtin_ctz(m);
    } else {
        *col = s % m;
        *row = s / m;
    }
}

void cmj_sample_2d(uint32_t s, uint32_t n, uint32_t p, float *x, float *y)
{
    uint32_t m, k, col, row;
    cmj_strata(n, &m, &k);
    s = permute(s, m * k, p * 0x51633e2du); /* m k = n, or n of the strata */
    cmj_cell(s, m, &col, &row);
    cmj_point(s, col, row, permute(col, m, p * 0x68bc21ebu), permute(row, k, p * 0x02e5be93u), m, k,
              p, x, y);
}

void cmj_pattern_init(CmjPattern *c, uint32_t n, uint32_t p)
{
    c->n = n;
    c->p = p;
    cmj_strata(n, &c->m, &c->k);
    c->tabled = c->m <= CMJ_TABLE && c->k <= CMJ_TABLE;
    if (!c->tabled)
        return;
    Permutation px, py;
    permutation_init(&px, c->m, p * 0x68bc21ebu);
    permutation_init(&py, c->k, p * 0x02e5be93u);
    for (uint32_t i = 0; i < c->m; i++)
        c->sx[i] = (uint8_t)permutation_at(&px, i);
    for (uint32_t i = 0; i < c->k; i++)
        c->sy[i] = (uint8_t)permutation_at(&py, i);
}

void cmj_pattern_sample(const CmjPattern *c, uint32_t s, float *x, float *y)
{
    if (!c->tabled) {
        cmj_sample_2d(s, c->n, c->p, x, y);
        return;
    }
    uint32_t col, row;
    s = permute(s, c->m * c->k, c->p * 0x51633e2du);
    cmj_cell(s, c->m, &col, &row);
    cmj_point(s, col, row, c->sx[col], c->sy[row], c->m, c->k, c->p, x, y);
}

void cmj_pattern_samples(const CmjPattern *c, uint32_t first, uint32_t count, float *x, float *y)
{
    if (!c->tabled) {
        for (uint32_t i = 0; i < count; i++)
            cmj_sample_2d(first + i, c->n, c->p, &x[i], &y[i]);
        return;
    }
    /* Two passes: the permutations first, each independent of the others,
     * so that their hash chains overlap in the processor instead of
     * waiting, one at a time, behind the caller's work between samples. */
    uint32_t idx[CMJ_BATCH];
    Permutation ps;
    permutation_init(&ps, c->m * c->k, c->p * 0x51633e2du);
    for (uint32_t done = 0; done < count; done += CMJ_BATCH) {
        uint32_t nb = count - done < CMJ_BATCH ? count - done : CMJ_BATCH;
        for (uint32_t i = 0; i < nb; i++)
            idx[i] = permutation_at(&ps, first + done + i);
        for (uint32_t i = 0; i < nb; i++) {
            uint32_t col, row, s = idx[i];
            cmj_cell(s, c->m, &col, &row);
            cmj_point(s, col, row, c->sx[col], c->sy[row], c->m, c->k, c->p, &x[done + i],
                      &y[done + i]);
        }
    }
}

static uint32_t reverse_bits(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Burley's nested uniform scramble of x's bits (Laine and Karras's hash
 * on the reversed bits: each bit flipped by a hash of the bits above it). */
static uint32_t owen_scramble(uint32_t x, uint32_t seed)
{
    x = reverse_bits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits(x);
}

void sobol_owen_2d(uint32_t s, uint32_t p, float *x, float *y)
{
    /* dimension 0: the van der Corput sequence; dimension 1: direction
     * numbers of the polynomial x + 1, v_i = v_{i-1} ^ (v_{i-1} >> 1) */
    uint32_t a = reverse_bits(s), b = 0, v = 0x80000000u;
    for (uint32_t i = s; i; i >>= 1, v ^= v >> 1)
        if (i & 1)
            b ^= v;
    a = owen_scramble(a, (uint32_t)hash_combine(p, 1));
    b = owen_scramble(b, (uint32_t)hash_combine(p, 2));
    *x = (float)(a >> 8) * (1.0f / 16777216.0f);
    *y = (float)(b >> 8) * (1.0f / 16777216.0f);
}

float stratified_1d(uint32_t s, uint32_t n, uint32_t p)
{
    uint32_t stratum = permute(s % n, n, p * 0x9e3779b9u);
    float x = ((float)stratum + randfloat(s, p * 0x85ebca6bu)) / (float)n;
    return x < 1.0f ? x : 0x1.fffffep-1f;
}
