/*
 * util/rng.h — deterministic random numbers and stratified samples.
 *
 * rayes draws no number from a stream whose state depends on the order of
 * work: every sample is a pure function of a 64-bit key that names where it
 * is used (pixel, pixel sample, bounce, dimension; or cache key, vertex,
 * dimension; DESIGN.md "Determinism"). Keys are built with hash_combine.
 *
 * Stratified sets use Kensler's correlated multi-jittered sampling (Pixar
 * technical memo 13-01): any count n, stratified in 2D and in each 1D
 * projection, with a pattern chosen by a 32-bit seed.
 */
#ifndef RAYES_UTIL_RNG_H
#define RAYES_UTIL_RNG_H

#include <stdint.h>

/* The splitmix64 finaliser: a bijective 64-bit mix. */
static inline uint64_t hash_u64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* A key for b used under key a. Order matters: (a, b) != (b, a). */
static inline uint64_t hash_combine(uint64_t a, uint64_t b)
{
    return hash_u64(a ^ (hash_u64(b) + 0x632be59bd9b4e019ull + (a << 6) + (a >> 2)));
}

/* A float in [0, 1) from a key. */
static inline float rng_float(uint64_t key)
{
    return (float)(hash_u64(key) >> 40) * (1.0f / 16777216.0f);
}

/* The s-th of n correlated multi-jittered points in [0,1)^2 for pattern
 * seed p (0 <= s < n). */
void cmj_sample_2d(uint32_t s, uint32_t n, uint32_t p, float *x, float *y);

/* The m columns and k rows of strata of n points: n = m k where n has a
 * divisor m near sqrt(n) (at least half of floor(sqrt(n))), else m =
 * floor(sqrt(n)), k = ceil(n / m) and each pattern leaves its own m k - n
 * strata empty (uniform on average). */
void cmj_strata(uint32_t n, uint32_t *m, uint32_t *k);

/* The s-th of n stratified samples in [0, 1) for pattern seed p: stratum
 * permute(s) of n, jittered (the strata shuffled against cmj_sample_2d's,
 * so a pixel's time and lens samples are stratified with its positions but
 * not correlated with them). */
float stratified_1d(uint32_t s, uint32_t n, uint32_t p);

/* The s-th point of the first two dimensions of Sobol's sequence, a
 * (0, 2)-sequence in base 2, Owen-scrambled with seed p (Burley 2020's
 * hashed nested uniform scramble): every prefix of 2^k points is
 * stratified in every 2^k elementary interval of [0,1)^2 (n-rooks and
 * jittered at once), so a pixel taking samples a block at a time stays
 * stratified over all it took (adaptive sampling), where separate CMJ
 * patterns per block are stratified within each block only. */
void sobol_owen_2d(uint32_t s, uint32_t p, float *x, float *y);

/* A pattern whose samples are drawn many times over (a light's n shadow
 * rays at a point): the column and row shuffles tabled once, so each
 * sample costs one permutation instead of three. Its samples are
 * cmj_sample_2d's, bit for bit. */
#define CMJ_TABLE 128
typedef struct CmjPattern {
    uint32_t n, m, k, p;
    int tabled; /* m and k fit the tables (n up to about 16,000) */
    uint8_t sx[CMJ_TABLE], sy[CMJ_TABLE];
} CmjPattern;

void cmj_pattern_init(CmjPattern *c, uint32_t n, uint32_t p);
void cmj_pattern_sample(const CmjPattern *c, uint32_t s, float *x, float *y);

/* Samples first .. first + count - 1 of the pattern into x[] and y[]
 * (caller-sized), the same as cmj_pattern_sample's, bit for bit, at a
 * fraction of the cost each: a loop drawing a pattern's samples one at a
 * time between rays waits on each sample's hash in turn. CMJ_BATCH is
 * the batch a caller's stack arrays are sized for. */
#define CMJ_BATCH 32
void cmj_pattern_samples(const CmjPattern *c, uint32_t first, uint32_t count, float *x, float *y);

/* Sample dimensions: the second argument of hash_combine when a key names
 * what a sample is for. */
enum {
    DIM_PIXEL = 1,      /* pixel sample positions */
    DIM_LIGHT = 2,      /* shadow-ray positions on lights */
    DIM_DIFFUSE = 3,    /* diffuse-ray directions */
    DIM_SPECULAR = 4,   /* specular rays */
    DIM_PATH = 5,       /* child path keys */
    DIM_REFRACTION = 6, /* refracted rays */
    DIM_SHADER = 7,     /* the random service: shaders' own choices */
    DIM_OCCLUSION = 8,  /* ambient occlusion rays */
    DIM_SUBSURFACE = 9, /* subsurface rays from a probe point (memo 6.2) */
    DIM_TIME = 10,      /* camera rays' times in the shutter */
    DIM_LENS = 11,      /* camera rays' positions on the lens */
    DIM_FRAME = 12,     /* adaptive sampling's estimate of the frame's mean */
    DIM_MEDIUM = 13     /* a medium's scattered rays (multiple scattering) */
};

#endif /* RAYES_UTIL_RNG_H */
