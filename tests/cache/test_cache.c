/*
 * The multiresolution cache (src/cache/cache.c, memo 3.1 and 3.2) against its
 * contract in cache.h, with a stub fill function (no shading, no renderer):
 * hits and misses and their counters, half-float storage, keys, LRU order
 * within a shard, budget accounting, timestamps, waiting for another
 * thread's fill, recursive fills and determinism. Single-threaded except the
 * waiting tests; tests/cache/test_cache_stress.c is the contention test.
 *
 * The cache hides how keys map to shards, so tests that need two keys in one
 * shard learn it through behaviour: in a cache holding one entry per shard,
 * b evicts a exactly when they share a shard. Entries held in a CacheLocal
 * slot are pinned, so a test that wants an entry evictable looks it up
 * through a fresh CacheLocal (lookup_once) or finis its local first.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#include "cache/cache.h"
#include "test.h"
#include "util/half.h"
#include "util/rng.h"

static const float split_default[CACHE_N_LEVELS] = {0.25f, 0.25f, 0.5f};
static const float split_coarse[CACHE_N_LEVELS] = {1.0f, 0.0f, 0.0f};

/* A stub fill: values are a pure function of the key and a scene version. */
typedef struct Filler {
    int fills;        /* calls so far */
    size_t last_n;    /* n_values of the last call */
    uint32_t version; /* changed together with a timestamp bump */
} Filler;

static uint64_t key_bits(const CacheKey *k)
{
    uint64_t a = (uint64_t)k->patch | (uint64_t)k->depth << 32 | (uint64_t)k->segment << 48 |
                 (uint64_t)k->side << 56;
    return hash_combine(a, (uint64_t)k->type | (uint64_t)k->level << 8 |
                               (uint64_t)k->instance << 16);
}

static int key_same(const CacheKey *a, const CacheKey *b)
{
    return a->patch == b->patch && a->depth == b->depth && a->segment == b->segment &&
           a->side == b->side && a->type == b->type && a->level == b->level &&
           a->instance == b->instance;
}

static float key_value(const CacheKey *k, uint32_t version, size_t i, int c)
{
    uint64_t h = hash_combine(hash_combine(key_bits(k), version), 3 * i + (size_t)c);
    return 1000.0f * rng_float(h); /* fractional: exercises rounding to half */
}

static void stub_fill(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    Filler *f = user;
    f->fills++;
    f->last_n = n;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = key_value(key, f->version, i, c);
}

/* 1 if vals are exactly the halves stub_fill stores for key at version. */
static int values_ok(const uint16_t *vals, const CacheKey *key, uint32_t version, size_t n)
{
    if (!vals)
        return 0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            if (vals[3 * i + c] != half_from_float_clamped(key_value(key, version, i, c)))
                return 0;
    return 1;
}

static CacheKey key_at(uint32_t patch, CacheLevel level)
{
    return (CacheKey){.patch = patch, .level = (uint8_t)level};
}

/* One lookup through a fresh CacheLocal, so the entry is unpinned after.
 * Checks the values; returns 1 if the fill ran. Copies values if out. */
static int lookup_once(Cache *c, Filler *f, const CacheKey *key, size_t n, uint16_t *out)
{
    CacheLocal local;
    cache_local_init(&local, c);
    int before = f->fills;
    const uint16_t *v = cache_lookup(&local, key, n, stub_fill, f);
    CHECK(values_ok(v, key, f->version, n));
    if (out)
        memcpy(out, v, 3 * n * sizeof *out);
    cache_local_fini(&local);
    return f->fills != before;
}

static CacheStats stats_of(const Cache *c)
{
    CacheStats s;
    cache_get_stats(c, &s);
    return s;
}

/* Every counter set adds up: lookups = hits + misses, one fill per miss. */
static void check_counters_add_up(const CacheStats *s)
{
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++) {
            const CacheCounters *k = &s->counters[l][t];
            CHECK(k->lookups == k->hits + k->misses);
            CHECK(k->fills == k->misses);
        }
}

/* The budget holds, now and at the peak (a level may borrow past its
 * share what the others leave unused). */
static int budget_holds(const CacheStats *s)
{
    uint64_t bytes = 0, peak = 0;
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        bytes += s->bytes[l];
    for (int t = 0; t < CACHE_N_TYPES; t++)
        peak = s->type_peak_bytes[t] > peak ? s->type_peak_bytes[t] : peak;
    return bytes <= s->budget_bytes && s->peak_total_bytes <= s->budget_bytes &&
           peak <= s->peak_total_bytes;
}

static void sleep_us(long us)
{
    struct timespec ts = {us / 1000000, (us % 1000000) * 1000};
    nanosleep(&ts, NULL);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- hits, misses and counters ---- */

static void test_hit_miss_counters(void)
{
    Cache *c = cache_new(1000000, split_default);
    CHECK(c != NULL);
    CacheStats s0 = stats_of(c);
    CHECK(s0.budget_bytes == 1000000);
    CHECK(s0.level_budget_bytes[CACHE_COARSE] == 250000);
    CHECK(s0.level_budget_bytes[CACHE_FINE] == 500000);
    Filler f = {0};
    CacheLocal a, b;
    cache_local_init(&a, c);
    cache_local_init(&b, c);
    CacheKey k1 = key_at(7, CACHE_COARSE);
    CacheKey k2 = {.patch = 7, .type = CACHE_OPACITY, .level = CACHE_FINE};
    const uint16_t *v1 = cache_lookup(&a, &k1, 4, stub_fill, &f);
    CHECK(f.fills == 1 && values_ok(v1, &k1, 0, 4));
    CHECK(cache_lookup(&a, &k1, 4, stub_fill, &f) == v1); /* the local slot, no refill */
    CHECK(f.fills == 1);
    const uint16_t *v2 = cache_lookup(&a, &k2, 9, stub_fill, &f);
    CHECK(f.fills == 2 && values_ok(v2, &k2, 0, 9));
    CHECK(cache_lookup(&a, &k2, 9, stub_fill, &f) == v2);
    CHECK(cache_lookup(&a, &k1, 4, stub_fill, &f) == v1); /* other level: still held */
    CHECK(values_ok(cache_lookup(&b, &k1, 4, stub_fill, &f), &k1, 0, 4)); /* shared hit */
    CHECK(f.fills == 2);
    CacheStats mid = stats_of(c); /* counters of unfinished locals are not in yet */
    CHECK(mid.counters[CACHE_COARSE][CACHE_RADIOSITY].lookups == 0);
    CHECK(mid.entries[CACHE_COARSE] == 1 && mid.entries[CACHE_FINE] == 1);
    cache_local_fini(&a);
    cache_local_fini(&b);
    CacheStats s = stats_of(c);
    const CacheCounters *cr = &s.counters[CACHE_COARSE][CACHE_RADIOSITY];
    const CacheCounters *fo = &s.counters[CACHE_FINE][CACHE_OPACITY];
    CHECK(cr->lookups == 4 && cr->hits == 3 && cr->misses == 1 && cr->fills == 1);
    CHECK(fo->lookups == 2 && fo->hits == 1 && fo->misses == 1 && fo->fills == 1);
    uint64_t total = 0;
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++)
            total += s.counters[l][t].lookups + s.counters[l][t].evictions;
    CHECK(total == 6); /* nothing else counted anywhere */
    check_counters_add_up(&s);
    CHECK(s.entries[CACHE_MEDIUM] == 0);
    CHECK(s.bytes[CACHE_COARSE] == s0.bytes[CACHE_COARSE] + cache_entry_bytes(4));
    CHECK(s.bytes[CACHE_FINE] == s0.bytes[CACHE_FINE] + cache_entry_bytes(9));
    CHECK(budget_holds(&s));
    cache_free(c);
}

/* A local can be used again after fini; its counters start from zero. */
static void test_local_reuse(void)
{
    Cache *c = cache_new(1000000, split_default);
    Filler f = {0};
    CacheLocal a;
    cache_local_init(&a, c);
    CacheKey k = key_at(1, CACHE_MEDIUM);
    cache_lookup(&a, &k, 25, stub_fill, &f);
    cache_local_fini(&a);
    CHECK(values_ok(cache_lookup(&a, &k, 25, stub_fill, &f), &k, 0, 25));
    cache_local_fini(&a);
    CacheStats s = stats_of(c);
    const CacheCounters *m = &s.counters[CACHE_MEDIUM][CACHE_RADIOSITY];
    CHECK(m->lookups == 2 && m->hits == 1 && m->fills == 1 && f.fills == 1);
    cache_free(c);
}

/* ---- half-float storage ---- */

typedef struct Fixed {
    const float *v; /* 3 * n floats */
    size_t n;
} Fixed;

static void fixed_fill(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    const Fixed *x = user;
    (void)key;
    CHECK(n == x->n);
    memcpy(out, x->v, n * sizeof *out);
}

static void test_half_storage(void)
{
    static const float v[] = {
        0.0f,    1.0f,     0.1f,   -2.5f,   1000.3f, 3.14159265f, 6e-5f,    1e-7f,     1e-9f,
        0.5f,    2047.0f,  4097.0f, -0.001f, 65504.0f, 65519.0f, 65520.0f, 70000.0f, 1e30f,
        INFINITY, -INFINITY, -1e9f, -65504.0f, 12345.678f, 33000.5f};
    Fixed x = {v, sizeof v / sizeof v[0] / 3};
    Cache *c = cache_new(1000000, split_default);
    CacheLocal l;
    cache_local_init(&l, c);
    CacheKey k = key_at(3, CACHE_MEDIUM);
    const uint16_t *h = cache_lookup(&l, &k, x.n, fixed_fill, &x);
    for (size_t i = 0; i < 3 * x.n; i++) {
        if (v[i] > 65504.0f)
            CHECK(h[i] == 0x7bff); /* clamped, not infinity */
        else if (v[i] < -65504.0f)
            CHECK(h[i] == 0xfbff);
        else /* round to nearest: half a unit in the last place, or of the subnormal step */
            CHECK_NEAR(half_to_float(h[i]), v[i], fabsf(v[i]) * 0x1p-11f + 0x1p-25f);
    }
    CHECK(h[14] == 0x7bff && h[15] == 0x7bff); /* 65519, 65520 */
    CHECK(h[18] == 0x7bff && h[19] == 0xfbff); /* +inf, -inf */
    cache_local_fini(&l);
    cache_free(c);
}

/* The fill gets exactly the n_values of the lookup, and all of them are kept. */
static void test_n_values_honoured(void)
{
    static const size_t ns[] = {1, 7, 300, 0, 2, 1000};
    for (int budget = 0; budget < 2; budget++) { /* private and resident entries */
        Cache *c = cache_new(budget ? 4000000 : 0, split_default);
        Filler f = {0};
        CacheLocal l;
        cache_local_init(&l, c);
        for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
            CacheKey k = key_at((uint32_t)i, (CacheLevel)(i % CACHE_N_LEVELS));
            const uint16_t *v = cache_lookup(&l, &k, ns[i], stub_fill, &f);
            CHECK(f.last_n == ns[i]);
            CHECK(v != NULL && values_ok(v, &k, 0, ns[i]));
        }
        CHECK(f.fills == (int)(sizeof ns / sizeof ns[0]));
        cache_local_fini(&l);
        CacheStats s = stats_of(c);
        CHECK(budget_holds(&s));
        CHECK(s.entries[0] + s.entries[1] + s.entries[2] == (budget ? 6u : 0u));
        cache_free(c);
    }
}

/* ---- keys ---- */

static void test_keys_separate_every_field(void)
{
    const CacheKey base = {.patch = 10, .depth = 1, .segment = 2, .side = 0,
                           .type = CACHE_RADIOSITY, .level = CACHE_MEDIUM};
    CacheKey keys[20];
    int n = 0;
    keys[n++] = base;
    keys[n] = base, keys[n++].patch = 11;
    keys[n] = base, keys[n++].patch = 10 | 0x80000000u;
    keys[n] = base, keys[n++].patch = 10 | 0x10000u;
    keys[n] = base, keys[n++].depth = 2;
    keys[n] = base, keys[n++].depth = 1 | 0x100; /* the high byte of depth */
    keys[n] = base, keys[n++].segment = 3;
    keys[n] = base, keys[n++].segment = 255;
    keys[n] = base, keys[n++].side = 1;
    keys[n] = base, keys[n++].type = CACHE_OPACITY;
    keys[n] = base, keys[n++].type = CACHE_IRRADIANCE;
    keys[n] = base, keys[n++].level = CACHE_COARSE;
    keys[n] = base, keys[n++].level = CACHE_FINE;
    keys[n] = base, keys[n].depth = 2, keys[n++].segment = 1; /* fields trading places */
    keys[n] = base, keys[n++].instance = 1; /* an object instance's own entries (memo 3.1) */
    keys[n] = base, keys[n++].instance = 2;
    keys[n] = base, keys[n++].instance = 0x10000u;
    Cache *c = cache_new(4000000, split_default);
    Filler f = {0};
    for (int i = 0; i < n; i++)
        CHECK(lookup_once(c, &f, &keys[i], 5, NULL));
    CHECK(f.fills == n);
    for (int i = 0; i < n; i++) /* each key finds its own entry (values checked) */
        CHECK(!lookup_once(c, &f, &keys[i], 5, NULL));
    CHECK(f.fills == n);
    CacheStats s = stats_of(c);
    CHECK(s.entries[0] + s.entries[1] + s.entries[2] == (uint64_t)n);
    cache_free(c);
}

/* Many random keys: each distinct key fills once, then only hits. */
static void test_random_keys_distinct(void)
{
    enum { N = 300 };
    static CacheKey keys[N];
    uint64_t r = 12345;
    int n = 0;
    while (n < N) {
        r = hash_u64(r);
        CacheKey k = {.patch = (uint32_t)(r & 15) | (uint32_t)(r >> 60) << 28,
                      .depth = (uint16_t)((r >> 8) & 3), .segment = (uint8_t)((r >> 12) & 1),
                      .side = (uint8_t)((r >> 16) & 1), .type = (uint8_t)((r >> 20) % 3),
                      .level = (uint8_t)((r >> 24) % 3)};
        int dup = 0;
        for (int i = 0; i < n; i++)
            dup |= key_same(&keys[i], &k);
        if (!dup)
            keys[n++] = k;
    }
    Cache *c = cache_new(16000000, split_default);
    Filler f = {0};
    CacheLocal l; /* one local: slots collide and get replaced */
    cache_local_init(&l, c);
    for (int pass = 0; pass < 3; pass++)
        for (int i = 0; i < N; i++)
            CHECK(values_ok(cache_lookup(&l, &keys[i], 3, stub_fill, &f), &keys[i], 0, 3));
    CHECK(f.fills == N);
    cache_local_fini(&l);
    CacheStats s = stats_of(c);
    CHECK(s.entries[0] + s.entries[1] + s.entries[2] == N);
    check_counters_add_up(&s);
    cache_free(c);
}

/* ---- LRU within a shard ---- */

enum { LRU_KEYS = 128 };

static CacheKey lru_key(int i)
{
    return key_at(5000 + (uint32_t)i, CACHE_COARSE);
}

/* A COARSE-only cache whose shards hold cap entries of 4 values each (the
 * hash table sized for cap too); returns the capacity the stats show. */
static Cache *cache_with_capacity(uint64_t cap, uint64_t *actual_cap)
{
    uint64_t e = cache_entry_bytes(4), shard = cap * (e + sizeof(void *));
    Cache *c = cache_new(8 * shard, split_coarse);
    CacheStats s = stats_of(c);
    uint64_t table = s.bytes[CACHE_COARSE] / 8;
    *actual_cap = table <= shard ? (shard - table) / e : 0;
    return c;
}

/* Groups the LRU keys by shard, learnt through behaviour; returns the
 * number of groups (0 if the cache does not allow learning it). */
static int group_by_shard(int group_of[LRU_KEYS])
{
    uint64_t cap;
    Cache *c = cache_with_capacity(1, &cap);
    CHECK(cap == 1);
    if (cap != 1) {
        cache_free(c);
        return 0;
    }
    Filler f = {0};
    int reps[LRU_KEYS], n_groups = 0;
    for (int i = 0; i < LRU_KEYS; i++) {
        group_of[i] = -1;
        for (int g = 0; g < n_groups && group_of[i] < 0; g++) {
            CacheKey a = lru_key(reps[g]), b = lru_key(i);
            lookup_once(c, &f, &a, 4, NULL);
            lookup_once(c, &f, &b, 4, NULL);
            if (lookup_once(c, &f, &a, 4, NULL)) /* b evicted a */
                group_of[i] = g;
        }
        if (group_of[i] < 0) {
            reps[n_groups] = i;
            group_of[i] = n_groups++;
        }
    }
    cache_free(c);
    return n_groups;
}

/* An exact model of per-shard LRU replacement: a random workload of
 * lookups, each released at once, hits exactly when the model says. */
static void test_lru_matches_model(void)
{
    int group_of[LRU_KEYS];
    int n_groups = group_by_shard(group_of);
    CHECK(n_groups >= 2 && n_groups <= LRU_KEYS / 4);
    if (n_groups < 2)
        return;
    uint64_t cap;
    Cache *c = cache_with_capacity(4, &cap);
    CHECK(cap >= 2 && cap <= 16);
    int lru[LRU_KEYS][16], len[LRU_KEYS] = {0}; /* per group, least recent first */
    Filler f = {0};
    int mismatches = 0;
    uint64_t r = 99;
    for (int step = 0; step < 4000 && cap >= 2 && cap <= 16; step++) {
        r = hash_u64(r);
        int i = (int)((r % LRU_KEYS) * ((r >> 32) % LRU_KEYS) / LRU_KEYS); /* skewed */
        int g = group_of[i], at = -1;
        for (int j = 0; j < len[g]; j++)
            if (lru[g][j] == i)
                at = j;
        CacheKey k = lru_key(i);
        mismatches += lookup_once(c, &f, &k, 4, NULL) != (at < 0);
        if (at < 0 && len[g] == (int)cap)
            at = 0; /* evict the least recent */
        else if (at < 0)
            at = len[g]++;
        memmove(&lru[g][at], &lru[g][at + 1], (size_t)(len[g] - 1 - at) * sizeof(int));
        lru[g][len[g] - 1] = i;
    }
    CHECK(mismatches == 0);
    CacheStats s = stats_of(c);
    CHECK(budget_holds(&s));
    CHECK(s.counters[CACHE_COARSE][CACHE_RADIOSITY].evictions > 0);
    cache_free(c);
}

/* The keys of the largest group (at least want of them), or 0. */
static int largest_group(const int group_of[LRU_KEYS], int n_groups, int *keys, int want)
{
    int best = -1, best_n = 0;
    for (int g = 0; g < n_groups; g++) {
        int m = 0;
        for (int i = 0; i < LRU_KEYS; i++)
            m += group_of[i] == g;
        if (m > best_n)
            best = g, best_n = m;
    }
    if (best_n < want)
        return 0;
    int m = 0;
    for (int i = 0; i < LRU_KEYS && m < want; i++)
        if (group_of[i] == best)
            keys[m++] = i;
    return m;
}

/* Fill cap keys of one shard, touch the first, add one more: the second
 * (least recently used) is evicted, the touched one stays. An entry held
 * in a slot is pinned and survives any number of insertions. */
static void test_lru_touch_and_pin(void)
{
    int group_of[LRU_KEYS], keys[12];
    int n_groups = group_by_shard(group_of);
    uint64_t cap;
    Cache *c = cache_with_capacity(4, &cap);
    if (cap != 4 || !largest_group(group_of, n_groups, keys, 12)) {
        CHECK(!"no shard with enough keys");
        cache_free(c);
        return;
    }
    Filler f = {0};
    CacheKey k[12];
    for (int i = 0; i < 12; i++)
        k[i] = lru_key(keys[i]);
    for (int i = 0; i < 4; i++)
        CHECK(lookup_once(c, &f, &k[i], 4, NULL));
    CHECK(!lookup_once(c, &f, &k[0], 4, NULL)); /* touch: now most recent */
    CHECK(lookup_once(c, &f, &k[4], 4, NULL));  /* evicts k[1] */
    CHECK(!lookup_once(c, &f, &k[0], 4, NULL));
    CHECK(!lookup_once(c, &f, &k[2], 4, NULL));
    CHECK(!lookup_once(c, &f, &k[3], 4, NULL));
    CHECK(!lookup_once(c, &f, &k[4], 4, NULL));
    CHECK(lookup_once(c, &f, &k[1], 4, NULL)); /* the one evicted */
    CacheLocal pin;
    cache_local_init(&pin, c);
    Filler pf = {0};
    cache_lookup(&pin, &k[2], 4, stub_fill, &pf); /* k[2] is pinned from here */
    for (int i = 5; i < 12; i++)
        CHECK(lookup_once(c, &f, &k[i], 4, NULL));
    CHECK(!lookup_once(c, &f, &k[2], 4, NULL));
    cache_local_fini(&pin);
    CHECK(pf.fills == 0);
    CacheStats s = stats_of(c);
    CHECK(s.entries[CACHE_COARSE] >= 4 && budget_holds(&s));
    cache_free(c);
}

/* An entry that cannot fit even after every unpinned entry of its shard is
 * evicted gets a private fill; evicting those entries first would only
 * throw away good entries for nothing. */
static void test_unfittable_entry_evicts_nothing(void)
{
    int group_of[LRU_KEYS], keys[12];
    int n_groups = group_by_shard(group_of);
    uint64_t cap;
    Cache *c = cache_with_capacity(4, &cap);
    if (cap != 4 || !largest_group(group_of, n_groups, keys, 6)) {
        CHECK(!"no shard with enough keys");
        cache_free(c);
        return;
    }
    Filler f = {0};
    CacheKey k[6];
    for (int i = 0; i < 6; i++)
        k[i] = lru_key(keys[i]);
    for (int i = 0; i < 4; i++)
        lookup_once(c, &f, &k[i], 4, NULL);
    CHECK(lookup_once(c, &f, &k[4], 400, NULL)); /* larger than the whole shard */
    for (int i = 0; i < 4; i++)
        CHECK(!lookup_once(c, &f, &k[i], 4, NULL));
    CacheLocal pin[3]; /* three of four pinned: the fourth's room is too small */
    for (int i = 0; i < 3; i++) {
        cache_local_init(&pin[i], c);
        cache_lookup(&pin[i], &k[i], 4, stub_fill, &f);
    }
    CHECK(cache_entry_bytes(8) > cache_entry_bytes(4));
    CHECK(lookup_once(c, &f, &k[5], 8, NULL));
    CHECK(!lookup_once(c, &f, &k[3], 4, NULL)); /* still resident */
    for (int i = 0; i < 3; i++)
        cache_local_fini(&pin[i]);
    CacheStats s = stats_of(c);
    CHECK(s.counters[CACHE_COARSE][CACHE_RADIOSITY].evictions == 0);
    CHECK(budget_holds(&s));
    cache_free(c);
}

/* ---- budget accounting ---- */

static const size_t level_n[CACHE_N_LEVELS] = {4, 25, 100};

typedef struct Workload {
    uint64_t budget;
    float split[CACHE_N_LEVELS];
    int n_keys;
    int mixed_sizes; /* n_values per key instead of per level */
} Workload;

static Workload random_workload(uint64_t *r, int trial)
{
    static const uint64_t small[] = {0, 1, 63, 64, 200, 1000, 3000};
    Workload w = {0};
    *r = hash_u64(*r);
    w.budget = trial < 7 ? small[trial] : *r % 400000;
    float a = rng_float(*r + 1), b = rng_float(*r + 2), d = rng_float(*r + 3), sum = a + b + d;
    w.split[0] = 0.999f * a / sum;
    w.split[1] = 0.999f * b / sum;
    w.split[2] = 0.999f * d / sum;
    w.n_keys = 8 + (int)(*r >> 40) % 400;
    w.mixed_sizes = trial % 3 == 2;
    return w;
}

static size_t workload_n(const Workload *w, const CacheKey *k)
{
    return w->mixed_sizes ? 1 + hash_u64(k->patch * 3u + k->level) % 200 : level_n[k->level];
}

/* Runs w through three interleaved locals; returns lookups made. Checks
 * every value and the budget after every fini. */
static uint64_t run_workload(Cache *c, const Workload *w, uint64_t *r)
{
    Filler f = {0};
    CacheLocal locals[3];
    for (int i = 0; i < 3; i++)
        cache_local_init(&locals[i], c);
    uint64_t lookups = 0;
    int bad = 0, over = 0;
    for (int step = 0; step < 1500; step++, lookups++) {
        *r = hash_u64(*r);
        CacheLocal *l = &locals[*r % 3];
        uint32_t patch = (uint32_t)((*r >> 8) % (uint64_t)w->n_keys);
        CacheKey k = key_at(patch, (CacheLevel)((*r >> 20) % 3));
        k.type = (uint8_t)((*r >> 24) % 3);
        size_t n = workload_n(w, &k);
        bad += !values_ok(cache_lookup(l, &k, n, stub_fill, &f), &k, 0, n);
        if ((*r >> 32) % 64 == 0) {
            cache_local_fini(l);
            CacheStats s = stats_of(c);
            over += !budget_holds(&s);
        }
    }
    for (int i = 0; i < 3; i++)
        cache_local_fini(&locals[i]);
    CHECK(bad == 0);
    CHECK(over == 0);
    return lookups;
}

static void test_budget_random(void)
{
    uint64_t r = 2024;
    for (int trial = 0; trial < 60; trial++) {
        Workload w = random_workload(&r, trial);
        Cache *c = cache_new(w.budget, w.split);
        CHECK(c != NULL);
        CacheStats s0 = stats_of(c);
        uint64_t lookups = run_workload(c, &w, &r);
        CacheStats s = stats_of(c);
        CHECK(budget_holds(&s));
        check_counters_add_up(&s);
        uint64_t counted = 0;
        for (int l = 0; l < CACHE_N_LEVELS; l++) {
            CHECK(s.level_budget_bytes[l] <= w.budget);
            for (int t = 0; t < CACHE_N_TYPES; t++)
                counted += s.counters[l][t].lookups;
            /* nothing held, no bumps: exactly table + resident entries */
            if (!w.mixed_sizes)
                CHECK(s.bytes[l] == s.slots[l] * sizeof(void *) +
                                        s.entries[l] * cache_entry_bytes(level_n[l]));
            CHECK(s.slots[l] >= s0.slots[l]);
        }
        CHECK(counted == lookups);
        cache_free(c);
    }
}

/* A budget smaller than one entry (or, all of it coarse, a shard's share
 * smaller than one entry: a shard never borrows its own level's unused
 * share): correct values from private fills, a fill every time, nothing
 * resident, the budget kept. */
static void test_budget_too_small(void)
{
    uint64_t e = cache_entry_bytes(4);
    const uint64_t budgets[] = {0, 1, 63, 8 * (e - 1), 8 * (e + sizeof(void *)) - 8};
    for (size_t b = 0; b < sizeof budgets / sizeof budgets[0]; b++)
        for (int sp = 0; sp < 2; sp++) {
            if (!sp && budgets[b] >= e) /* the coarse share may borrow the others' */
                continue;
            Cache *c = cache_new(budgets[b], sp ? split_coarse : split_default);
            Filler f = {0};
            int fills = 0;
            for (int i = 0; i < 40; i++) {
                CacheKey k = key_at((uint32_t)(i % 5), CACHE_COARSE);
                fills += lookup_once(c, &f, &k, 4, NULL);
            }
            CHECK(fills == 40);
            CacheLocal l; /* the same key again through one local: still right */
            cache_local_init(&l, c);
            CacheKey k = key_at(1, CACHE_COARSE);
            for (int i = 0; i < 3; i++)
                CHECK(values_ok(cache_lookup(&l, &k, 4, stub_fill, &f), &k, 0, 4));
            cache_local_fini(&l);
            CacheStats s = stats_of(c);
            CHECK(s.entries[CACHE_COARSE] == 0);
            CHECK(budget_holds(&s));
            check_counters_add_up(&s);
            cache_free(c);
        }
}

/* A level whose share is full borrows what the others leave unused:
 * coarse entries alone fill most of the budget; fine entries then take
 * back what their share needs (coarse ones evicted) and stay, and the
 * budget holds all along. */
static void test_levels_lend(void)
{
    const uint64_t budget = 400000;
    Cache *c = cache_new(budget, split_default);
    Filler f = {0};
    uint64_t coarse_e = cache_entry_bytes(4), fine_e = cache_entry_bytes(289);
    uint32_t n_coarse = (uint32_t)(budget / coarse_e);
    for (uint32_t i = 0; i < n_coarse; i++) {
        CacheKey k = key_at(i, CACHE_COARSE);
        lookup_once(c, &f, &k, 4, NULL);
    }
    CacheStats s = stats_of(c);
    CHECK(budget_holds(&s));
    /* past its share (25%) by what medium and fine leave */
    CHECK(s.bytes[CACHE_COARSE] > s.level_budget_bytes[CACHE_COARSE] * 3);
    uint64_t coarse_before = s.entries[CACHE_COARSE];
    uint32_t n_fine = (uint32_t)(s.level_budget_bytes[CACHE_FINE] / fine_e / 2);
    int fine_fills = 0;
    for (uint32_t i = 0; i < n_fine; i++) {
        CacheKey k = key_at(i, CACHE_FINE);
        fine_fills += lookup_once(c, &f, &k, 289, NULL);
    }
    s = stats_of(c);
    CHECK(budget_holds(&s));
    CHECK(fine_fills == (int)n_fine && n_fine >= 40);
    CHECK(s.entries[CACHE_FINE] == n_fine); /* each shard's keys within its share */
    CHECK(s.entries[CACHE_COARSE] < coarse_before);
    CHECK(s.bytes[CACHE_COARSE] + 8 * coarse_e >= s.level_budget_bytes[CACHE_COARSE]);
    int refills = 0; /* the fine entries stayed */
    for (uint32_t i = 0; i < n_fine; i++) {
        CacheKey k = key_at(i, CACHE_FINE);
        refills += lookup_once(c, &f, &k, 289, NULL);
    }
    CHECK(refills == 0);
    check_counters_add_up(&s);
    cache_free(c);
}

/* A data type whose budget is full borrows what the other types leave
 * unused: opacity entries alone go far past opacity's budget; radiosity
 * entries then take back what their budget needs (opacity ones evicted)
 * and stay; a type of budget 0 borrows nothing (its lookups fill
 * privately); the pool holds all along. */
static void test_types_lend(void)
{
    uint64_t budgets[CACHE_N_TYPES] = {0};
    budgets[CACHE_RADIOSITY] = 400000;
    budgets[CACHE_OPACITY] = 100000;
    Cache *c = cache_new_typed(budgets, split_default);
    Filler f = {0};
    uint64_t fine_e = cache_entry_bytes(289);
    uint32_t n_opacity = (uint32_t)(500000 / fine_e);
    for (uint32_t i = 0; i < n_opacity; i++) {
        CacheKey k = key_at(i, CACHE_FINE);
        k.type = CACHE_OPACITY;
        lookup_once(c, &f, &k, 289, NULL);
    }
    CacheStats s = stats_of(c);
    CHECK(budget_holds(&s) && s.budget_bytes == 500000);
    uint64_t opacity_before = s.type_entries[CACHE_OPACITY][CACHE_FINE];
    CHECK(opacity_before * fine_e > 3 * budgets[CACHE_OPACITY]); /* radiosity's, lent */
    CHECK(s.type_peak_bytes[CACHE_OPACITY] > budgets[CACHE_OPACITY]);
    /* radiosity within its fine share takes it back */
    uint32_t n_fine = (uint32_t)(s.level_budget_bytes[CACHE_FINE] / fine_e / 4);
    int fills = 0;
    for (uint32_t i = 0; i < n_fine; i++) {
        CacheKey k = key_at(i, CACHE_FINE);
        fills += lookup_once(c, &f, &k, 289, NULL);
    }
    s = stats_of(c);
    CHECK(budget_holds(&s));
    CHECK(fills == (int)n_fine && n_fine >= 20);
    CHECK(s.type_entries[CACHE_RADIOSITY][CACHE_FINE] == n_fine);
    CHECK(s.type_entries[CACHE_OPACITY][CACHE_FINE] < opacity_before);
    CHECK(s.counters[CACHE_FINE][CACHE_OPACITY].evictions > 0);
    CHECK(s.counters[CACHE_FINE][CACHE_RADIOSITY].evictions == 0);
    int refills = 0; /* the radiosity entries stayed */
    for (uint32_t i = 0; i < n_fine; i++) {
        CacheKey k = key_at(i, CACHE_FINE);
        refills += lookup_once(c, &f, &k, 289, NULL);
    }
    CHECK(refills == 0);
    /* irradiance has no budget: nothing lent, nothing kept */
    CacheKey k = key_at(1, CACHE_FINE);
    k.type = CACHE_IRRADIANCE;
    CHECK(lookup_once(c, &f, &k, 289, NULL) == 1 && lookup_once(c, &f, &k, 289, NULL) == 1);
    CHECK(stats_of(c).type_entries[CACHE_IRRADIANCE][CACHE_FINE] == 0);
    check_counters_add_up(&s);
    cache_free(c);
}

/* A level that borrows holds far more entries than its table was sized
 * for: each shard's table doubles as its entries outnumber its slots, so a
 * lookup walks chains of about one entry, and the slots' bytes are counted
 * within the budget. */
static void test_tables_grow(void)
{
    const uint64_t budget = 10000000;
    Cache *c = cache_new(budget, split_default);
    Filler f = {0};
    CacheStats s0 = stats_of(c);
    const uint32_t n = 60000; /* 6.2 MB of coarse entries: 2.5 times the share */
    for (uint32_t i = 0; i < n; i++) {
        CacheKey k = key_at(i, CACHE_COARSE);
        lookup_once(c, &f, &k, 4, NULL);
    }
    CacheStats s = stats_of(c);
    CHECK(s.entries[CACHE_COARSE] == n);
    CHECK(s0.slots[CACHE_COARSE] < n / 2);
    CHECK(s.slots[CACHE_COARSE] >= n && s.slots[CACHE_COARSE] <= 4 * n);
    CHECK(s.bytes[CACHE_COARSE] == s.slots[CACHE_COARSE] * sizeof(void *) + n * cache_entry_bytes(4));
    CHECK(budget_holds(&s));
    int refills = 0; /* every entry is still found */
    for (uint32_t i = 0; i < n; i++) {
        CacheKey k = key_at(i, CACHE_COARSE);
        refills += lookup_once(c, &f, &k, 4, NULL);
    }
    CHECK(refills == 0);
    cache_free(c);
}

/* ---- timestamps ---- */

static void test_bump_invalidates(void)
{
    Cache *c = cache_new(1000000, split_default);
    CacheStats s0 = stats_of(c);
    Filler f = {0};
    CacheLocal a, b, d;
    cache_local_init(&a, c);
    cache_local_init(&b, c);
    cache_local_init(&d, c);
    CacheKey k = key_at(42, CACHE_FINE);
    CHECK(values_ok(cache_lookup(&a, &k, 16, stub_fill, &f), &k, 0, 16));
    CHECK(values_ok(cache_lookup(&b, &k, 16, stub_fill, &f), &k, 0, 16)); /* b holds it too */
    CHECK(f.fills == 1);
    uint64_t t0 = cache_timestamp(c);
    CHECK(cache_bump_timestamp(c) == t0 + 1 && cache_timestamp(c) == t0 + 1);
    f.version = 1;
    CHECK(values_ok(cache_lookup(&a, &k, 16, stub_fill, &f), &k, 1, 16)); /* held by a itself */
    CHECK(f.fills == 2);
    CHECK(values_ok(cache_lookup(&b, &k, 16, stub_fill, &f), &k, 1, 16)); /* b held the old */
    CHECK(values_ok(cache_lookup(&d, &k, 16, stub_fill, &f), &k, 1, 16));
    CHECK(f.fills == 2);
    cache_local_fini(&a);
    cache_local_fini(&b);
    cache_local_fini(&d);
    CacheStats s = stats_of(c);
    CHECK(s.entries[CACHE_FINE] == 1); /* the old entry is gone, bytes with it */
    CHECK(s.bytes[CACHE_FINE] == s0.bytes[CACHE_FINE] + cache_entry_bytes(16));
    cache_bump_timestamp(c); /* nobody holds it now */
    f.version = 2;
    CHECK(lookup_once(c, &f, &k, 16, NULL));
    cache_free(c);
}

/* A private entry parked in a slot is not returned after a bump either. */
static void test_bump_invalidates_private(void)
{
    Cache *c = cache_new(0, split_default);
    Filler f = {0};
    CacheLocal l;
    cache_local_init(&l, c);
    CacheKey k = key_at(9, CACHE_MEDIUM);
    CHECK(values_ok(cache_lookup(&l, &k, 25, stub_fill, &f), &k, 0, 25));
    cache_bump_timestamp(c);
    f.version = 1;
    CHECK(values_ok(cache_lookup(&l, &k, 25, stub_fill, &f), &k, 1, 25));
    CHECK(f.fills == 2);
    cache_local_fini(&l);
    cache_free(c);
}

/* Over many bumps with a small budget old entries age out: an old key
 * always refills, and the bytes stay within the budget and account
 * exactly for what is resident. */
static void test_old_entries_age_out(void)
{
    uint64_t cap;
    Cache *c = cache_with_capacity(4, &cap);
    CacheStats s0 = stats_of(c);
    Filler f = {0};
    int stale_hits = 0, over = 0;
    for (int round = 0; round < 300; round++) {
        cache_bump_timestamp(c);
        f.version = (uint32_t)round + 1;
        CacheLocal l;
        cache_local_init(&l, c);
        for (int i = 0; i < 12; i++) { /* some keys every round, some new */
            uint32_t patch = i < 6 ? (uint32_t)i : (uint32_t)(100 + round * 6 + i);
            CacheKey k = key_at(patch, CACHE_COARSE);
            int before = f.fills;
            CHECK(values_ok(cache_lookup(&l, &k, 4, stub_fill, &f), &k, f.version, 4));
            stale_hits += f.fills == before; /* the first lookup in a round must fill */
        }
        cache_local_fini(&l);
        CacheStats s = stats_of(c);
        uint64_t resident = s.entries[CACHE_COARSE] * cache_entry_bytes(4);
        over += !budget_holds(&s) || s.bytes[CACHE_COARSE] != s0.bytes[CACHE_COARSE] + resident;
    }
    CHECK(stale_hits == 0);
    CHECK(over == 0);
    CacheStats s = stats_of(c);
    CHECK(s.entries[CACHE_COARSE] <= 8 * cap);
    cache_free(c);
}

/* Same keys every round with room for all: the stale entry is replaced, not
 * added to, so entries and bytes stay constant across bumps. */
static void test_bump_replaces_in_place(void)
{
    Cache *c = cache_new(4000000, split_default);
    Filler f = {0};
    CacheStats first = {0};
    for (int round = 0; round < 50; round++) {
        f.version = (uint32_t)round;
        for (int i = 0; i < 20; i++) {
            CacheKey k = key_at((uint32_t)i, (CacheLevel)(i % 3));
            CHECK(lookup_once(c, &f, &k, level_n[k.level], NULL));
        }
        CacheStats s = stats_of(c);
        if (round == 0)
            first = s;
        for (int l = 0; l < CACHE_N_LEVELS; l++)
            CHECK(s.entries[l] == first.entries[l] && s.bytes[l] == first.bytes[l]);
        cache_bump_timestamp(c);
    }
    cache_free(c);
}

/* A timestamp bump while a fill is running, with a second thread waiting for
 * that fill: the entry is dropped as stale under the filler's feet, yet the
 * waiter must still be woken when the fill ends. */
typedef struct Gate {
    Cache *cache;
    CacheKey key;
    atomic_int in_fill, go, waiter_done;
    int filler_ok, waiter_ok;
} Gate;

static void gated_fill(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    Gate *g = user;
    atomic_store(&g->in_fill, 1);
    while (!atomic_load(&g->go))
        sleep_us(200);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = key_value(key, 0, i, c);
}

static void *gate_filler(void *arg)
{
    Gate *g = arg;
    CacheLocal l;
    cache_local_init(&l, g->cache);
    g->filler_ok = values_ok(cache_lookup(&l, &g->key, 8, gated_fill, g), &g->key, 0, 8);
    cache_local_fini(&l);
    return NULL;
}

static void *gate_waiter(void *arg)
{
    Gate *g = arg;
    Filler f = {.version = 1}; /* runs only if it came after the bump */
    CacheLocal l;
    cache_local_init(&l, g->cache);
    const uint16_t *v = cache_lookup(&l, &g->key, 8, stub_fill, &f);
    g->waiter_ok = values_ok(v, &g->key, 0, 8) || values_ok(v, &g->key, 1, 8);
    cache_local_fini(&l);
    atomic_store(&g->waiter_done, 1);
    return NULL;
}

static void test_bump_during_fill_wakes_waiters(void)
{
    Gate g = {.cache = cache_new(1000000, split_default), .key = key_at(77, CACHE_MEDIUM)};
    pthread_t filler, waiter;
    pthread_create(&filler, NULL, gate_filler, &g);
    while (!atomic_load(&g.in_fill))
        sleep_us(100);
    pthread_create(&waiter, NULL, gate_waiter, &g);
    sleep_us(100000); /* the waiter now waits for the filler's entry */
    cache_bump_timestamp(g.cache);
    Filler f = {.version = 1};
    CHECK(lookup_once(g.cache, &f, &g.key, 8, NULL)); /* drops the entry being filled */
    atomic_store(&g.go, 1);
    pthread_join(filler, NULL);
    double t = now_s();
    while (!atomic_load(&g.waiter_done) && now_s() - t < 3.0)
        sleep_us(1000);
    CHECK(atomic_load(&g.waiter_done)); /* else: never woken */
    for (int kick = 0; !atomic_load(&g.waiter_done); kick++) {
        cache_bump_timestamp(g.cache); /* a fill in the shard broadcasts */
        f.version = 2 + (uint32_t)kick;
        lookup_once(g.cache, &f, &g.key, 8, NULL);
        sleep_us(10000);
    }
    pthread_join(waiter, NULL);
    CHECK(g.filler_ok && g.waiter_ok);
    CacheStats s = stats_of(g.cache);
    CHECK(s.entries[CACHE_MEDIUM] == 1);
    CHECK(budget_holds(&s));
    cache_free(g.cache);
}

/* Threads that look up a key while it is being filled wait for that fill:
 * one fill in all, and every thread sees the complete values. */
typedef struct Crowd {
    Gate *gate;
    Filler f; /* must never run */
    int ok;
} Crowd;

static void *crowd_main(void *arg)
{
    Crowd *cr = arg;
    CacheLocal l;
    cache_local_init(&l, cr->gate->cache);
    const uint16_t *v = cache_lookup(&l, &cr->gate->key, 8, stub_fill, &cr->f);
    cr->ok = values_ok(v, &cr->gate->key, 0, 8);
    cache_local_fini(&l);
    return NULL;
}

static void test_waiters_share_one_fill(void)
{
    Gate g = {.cache = cache_new(1000000, split_default), .key = key_at(78, CACHE_FINE)};
    pthread_t filler, crowd[4];
    Crowd cr[4] = {{0}};
    pthread_create(&filler, NULL, gate_filler, &g);
    while (!atomic_load(&g.in_fill))
        sleep_us(100);
    for (int i = 0; i < 4; i++) {
        cr[i].gate = &g;
        pthread_create(&crowd[i], NULL, crowd_main, &cr[i]);
    }
    sleep_us(50000);
    atomic_store(&g.go, 1);
    pthread_join(filler, NULL);
    for (int i = 0; i < 4; i++) {
        pthread_join(crowd[i], NULL);
        CHECK(cr[i].ok && cr[i].f.fills == 0);
    }
    CHECK(g.filler_ok);
    CacheStats s = stats_of(g.cache);
    const CacheCounters *k = &s.counters[CACHE_FINE][CACHE_RADIOSITY];
    CHECK(k->lookups == 5 && k->fills == 1 && k->hits == 4);
    cache_free(g.cache);
}

/* ---- recursion and determinism ---- */

typedef struct Recursive {
    CacheLocal *local;
    Filler leaf;
    int bad; /* wrong child values seen inside fills */
} Recursive;

/* A fill at depth d looks up three depth d + 1 keys through the same local
 * (one per level, like the renderer's diffuse bounces), then writes the
 * stub values. */
static void recursive_fill(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    Recursive *rc = user;
    if (key->depth < 3)
        for (int j = 0; j < 6; j++) {
            CacheKey child = key_at(key->patch * 7 + (uint32_t)j, (CacheLevel)(j % 3));
            child.depth = (uint16_t)(key->depth + 1);
            size_t cn = level_n[child.level];
            const uint16_t *v = cache_lookup(rc->local, &child, cn, recursive_fill, rc);
            rc->bad += !values_ok(v, &child, 0, cn);
        }
    stub_fill(&rc->leaf, key, n, out);
}

static void test_recursive_fill(void)
{
    const uint64_t budgets[] = {0, 3000, 20000, 4000000};
    for (size_t b = 0; b < sizeof budgets / sizeof budgets[0]; b++) {
        Cache *c = cache_new(budgets[b], split_default);
        CacheLocal l;
        cache_local_init(&l, c);
        Recursive rc = {.local = &l};
        for (int pass = 0; pass < 2; pass++)
            for (uint32_t p = 0; p < 40; p++) {
                CacheKey k = key_at(p, (CacheLevel)(p % 3));
                const uint16_t *v = cache_lookup(&l, &k, level_n[k.level], recursive_fill, &rc);
                CHECK(values_ok(v, &k, 0, level_n[k.level]));
            }
        CHECK(rc.bad == 0);
        cache_local_fini(&l);
        CacheStats s = stats_of(c);
        CHECK(budget_holds(&s));
        check_counters_add_up(&s);
        cache_free(c); /* aborts if a reference leaked */
    }
}

/* The same key refilled after eviction, or privately, gives the same bytes. */
static void test_refill_deterministic(void)
{
    uint64_t cap;
    Cache *c = cache_with_capacity(2, &cap);
    Cache *none = cache_new(0, split_default);
    Filler f = {0};
    CacheKey k = key_at(123456, CACHE_COARSE);
    uint16_t first[12], again[12], priv[12];
    CHECK(lookup_once(c, &f, &k, 4, first));
    int refilled = 0;
    for (uint32_t i = 0; i < 1000 && !refilled; i++) {
        CacheKey o = key_at(i, CACHE_COARSE);
        lookup_once(c, &f, &o, 4, NULL);
        if (i % 16 == 15)
            refilled = lookup_once(c, &f, &k, 4, again);
    }
    CHECK(refilled);
    CHECK(memcmp(first, again, sizeof first) == 0);
    CHECK(lookup_once(none, &f, &k, 4, priv));
    CHECK(memcmp(first, priv, sizeof first) == 0);
    cache_free(c);
    cache_free(none);
}

TEST_MAIN(TEST(test_hit_miss_counters), TEST(test_local_reuse), TEST(test_half_storage),
          TEST(test_n_values_honoured), TEST(test_keys_separate_every_field),
          TEST(test_random_keys_distinct), TEST(test_lru_matches_model),
          TEST(test_lru_touch_and_pin), TEST(test_unfittable_entry_evicts_nothing),
          TEST(test_budget_random), TEST(test_budget_too_small), TEST(test_levels_lend),
          TEST(test_types_lend), TEST(test_tables_grow), TEST(test_bump_invalidates),
          TEST(test_bump_invalidates_private), TEST(test_old_entries_age_out),
          TEST(test_bump_replaces_in_place), TEST(test_waiters_share_one_fill),
          TEST(test_bump_during_fill_wakes_waiters), TEST(test_recursive_fill),
          TEST(test_refill_deterministic))
