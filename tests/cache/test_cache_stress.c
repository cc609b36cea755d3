/*
 * The multiresolution cache (src/cache/cache.c, memo 3.1 and 3.2) under
 * contention: 8 threads with overlapping keys on a tiny budget (constant
 * eviction and private fills) and on a medium one (mostly hits), fills that
 * sometimes sleep or yield so they overlap, recursive fills (a fill at
 * diffuse depth d looks up depth d + 1 keys through the same CacheLocal, as
 * the renderer does), and timestamp bumps from one more thread throughout.
 *
 * Every value read is checked: vertex 0 carries the timestamp the fill saw,
 * which must lie between the timestamps read just before and just after the
 * lookup (an entry filled before a bump is never returned after it); every
 * other value is derived from the key alone (never half-written). A watchdog
 * reports a stall (a waiter never woken) instead of hanging. Fewer lookups
 * when built with a sanitizer.
 */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#include "cache/cache.h"
#include "test.h"
#include "util/half.h"
#include "util/rng.h"

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
#define STRESS_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer) || __has_feature(address_sanitizer)
#define STRESS_SANITIZED 1
#endif
#endif
#ifdef STRESS_SANITIZED
#define STRESS_DEFAULT_LOOKUPS 2000
static const double stall_seconds = 20.0;
#else
#define STRESS_DEFAULT_LOOKUPS 10000
static const double stall_seconds = 5.0;
#endif
#ifndef STRESS_LOOKUPS /* -DSTRESS_LOOKUPS=n for a longer soak */
#define STRESS_LOOKUPS STRESS_DEFAULT_LOOKUPS
#endif
enum { LOOKUPS_PER_THREAD = STRESS_LOOKUPS };

enum { N_THREADS = 8, N_PATCHES = 24, MAX_DEPTH = 2, N_CHILDREN = 3 };

static const float split_default[CACHE_N_LEVELS] = {0.25f, 0.25f, 0.5f};
static const size_t level_n[CACHE_N_LEVELS] = {4, 9, 25};

typedef struct Shared {
    Cache *cache;
    long bump_period_us;          /* 0: no bumps */
    atomic_int stop;              /* workers done: the bumper stops */
    atomic_int finished;          /* workers done */
    atomic_uint_fast64_t progress; /* checked lookups, all threads */
    uint64_t kick_lookups;        /* made by the watchdog after a stall */
} Shared;

typedef struct Worker {
    Shared *sh;
    CacheLocal local;
    uint64_t rng;
    uint64_t lookups; /* made by this thread (top level and in fills) */
    uint64_t bad;     /* values not as derived from the key */
    uint64_t stale;   /* fill timestamps outside the lookup's window */
} Worker;

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

static uint64_t key_bits(const CacheKey *k)
{
    uint64_t a = (uint64_t)k->patch | (uint64_t)k->depth << 32 | (uint64_t)k->segment << 48 |
                 (uint64_t)k->side << 56;
    return hash_combine(a, (uint64_t)k->type | (uint64_t)k->level << 8);
}

/* The half stored for value (i, c) of key; (0, 0) and (0, 1) hold the
 * fill's timestamp instead. */
static uint16_t key_half(const CacheKey *k, size_t i, int c)
{
    uint64_t h = hash_combine(key_bits(k), 3 * i + (size_t)c);
    return half_from_float_clamped(100.0f * rng_float(h));
}

static void checked_lookup(Worker *w, const CacheKey *key);

static void stress_fill(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    Worker *w = user;
    uint64_t seen = cache_timestamp(w->sh->cache);
    w->rng = hash_u64(w->rng);
    if (w->rng % 16 == 0)
        sleep_us(20 + (long)(w->rng >> 60));
    else if (w->rng % 16 < 4)
        sched_yield();
    if (key->depth < MAX_DEPTH && key->patch % 3 != 0)
        for (int j = 0; j < N_CHILDREN; j++) {
            CacheKey child = *key;
            child.patch = (key->patch * 7 + (uint32_t)j) % N_PATCHES;
            child.depth = (uint16_t)(key->depth + 1);
            child.level = (uint8_t)((key->level + (unsigned)j) % CACHE_N_LEVELS);
            checked_lookup(w, &child);
        }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = half_to_float(key_half(key, i, c));
    out[0][0] = (float)(seen & 1023); /* exact in a half */
    out[0][1] = (float)((seen >> 10) & 1023);
}

/* Looks key up through w's local and checks what comes back at once (the
 * values stay valid only until the next lookup of the level). */
static void checked_lookup(Worker *w, const CacheKey *key)
{
    Cache *c = w->sh->cache;
    size_t n = level_n[key->level];
    uint64_t before = cache_timestamp(c);
    const uint16_t *v = cache_lookup(&w->local, key, n, stress_fill, w);
    uint64_t after = cache_timestamp(c);
    float lo = half_to_float(v[0]), hi = half_to_float(v[1]);
    if (lo >= 0.0f && lo < 1024.0f && hi >= 0.0f && hi < 1024.0f) {
        uint64_t seen = (uint64_t)lo | (uint64_t)hi << 10;
        w->stale += seen < (before & 0xfffff) || seen > (after & 0xfffff);
    } else {
        w->bad++;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = i == 0 ? 2 : 0; k < 3; k++)
            w->bad += v[3 * i + (size_t)k] != key_half(key, i, k);
    w->lookups++;
    atomic_fetch_add_explicit(&w->sh->progress, 1, memory_order_relaxed);
}

static void *worker_main(void *arg)
{
    Worker *w = arg;
    cache_local_init(&w->local, w->sh->cache);
    for (int it = 0; it < LOOKUPS_PER_THREAD; it++) {
        w->rng = hash_u64(w->rng);
        uint64_t r = w->rng;
        CacheKey k = {.patch = (uint32_t)(r % N_PATCHES), .side = (uint8_t)((r >> 8) & 1),
                      .type = (uint8_t)((r >> 16) % 2),
                      .level = (uint8_t)((r >> 24) % CACHE_N_LEVELS)};
        checked_lookup(w, &k);
        if ((r >> 40) % 512 == 0) { /* finis and starts over: releases under contention */
            cache_local_fini(&w->local);
            cache_local_init(&w->local, w->sh->cache);
        }
    }
    cache_local_fini(&w->local);
    atomic_fetch_add(&w->sh->finished, 1);
    return NULL;
}

static void *bumper_main(void *arg)
{
    Shared *sh = arg;
    while (!atomic_load(&sh->stop)) {
        sleep_us(sh->bump_period_us);
        cache_bump_timestamp(sh->cache);
    }
    return NULL;
}

/* Fills in every shard of every level so that a waiter never woken by its
 * filler is woken by another broadcast; only used after a stall. Returns
 * the lookups made. */
static uint64_t kick_all_shards(Cache *c)
{
    Worker w = {.rng = 1};
    Shared sh = {.cache = c};
    w.sh = &sh;
    cache_local_init(&w.local, c);
    cache_bump_timestamp(c);
    for (uint32_t p = 0; p < 256; p++)
        for (int l = 0; l < CACHE_N_LEVELS; l++) {
            CacheKey k = {.patch = 1000000 + p, .depth = MAX_DEPTH, .level = (uint8_t)l};
            checked_lookup(&w, &k);
        }
    cache_local_fini(&w.local);
    return w.lookups;
}

/* Waits for the workers; returns 0 (after un-sticking them) if they made no
 * progress for stall_seconds. */
static int wait_for_workers(Shared *sh)
{
    uint64_t last = 0;
    double since = now_s();
    int stalled = 0;
    while (atomic_load(&sh->finished) < N_THREADS) {
        sleep_us(5000);
        uint64_t p = atomic_load(&sh->progress);
        if (p != last) {
            last = p;
            since = now_s();
        } else if (now_s() - since > stall_seconds) {
            stalled = 1;
            sh->kick_lookups += kick_all_shards(sh->cache);
            since = now_s();
        }
    }
    return !stalled;
}

static void run(uint64_t budget, long bump_period_us, int expect_hits)
{
    Shared sh = {.cache = cache_new(budget, split_default), .bump_period_us = bump_period_us};
    CHECK(sh.cache != NULL);
    static Worker workers[N_THREADS];
    pthread_t threads[N_THREADS], bumper;
    for (int i = 0; i < N_THREADS; i++) {
        workers[i] = (Worker){.sh = &sh, .rng = hash_u64(budget * 31 + (uint64_t)i)};
        pthread_create(&threads[i], NULL, worker_main, &workers[i]);
    }
    if (bump_period_us)
        pthread_create(&bumper, NULL, bumper_main, &sh);
    CHECK(wait_for_workers(&sh)); /* else: a lookup waited for a fill forever */
    for (int i = 0; i < N_THREADS; i++)
        pthread_join(threads[i], NULL);
    atomic_store(&sh.stop, 1);
    if (bump_period_us)
        pthread_join(bumper, NULL);
    uint64_t lookups = sh.kick_lookups, bad = 0, stale = 0;
    for (int i = 0; i < N_THREADS; i++) {
        lookups += workers[i].lookups;
        bad += workers[i].bad;
        stale += workers[i].stale;
    }
    CHECK(bad == 0);
    CHECK(stale == 0);
    CacheStats s;
    cache_get_stats(sh.cache, &s);
    uint64_t counted = 0, hits = 0, waits = 0, contended = 0;
    uint64_t total = 0, peak = 0;
    for (int t = 0; t < CACHE_N_TYPES; t++)
        peak += s.type_peak_bytes[t];
    for (int l = 0; l < CACHE_N_LEVELS; l++) {
        total += s.bytes[l]; /* a level may borrow past its share */
        for (int t = 0; t < CACHE_N_TYPES; t++) {
            const CacheCounters *k = &s.counters[l][t];
            CHECK(k->lookups == k->hits + k->misses && k->fills == k->misses);
            /* a wait is a hit on an entry another thread was filling */
            CHECK(k->waits <= k->hits && (k->waits == 0) == (k->wait_ns == 0));
            CHECK(k->contended <= k->lookups);
            counted += k->lookups;
            hits += k->hits;
            waits += k->waits;
            contended += k->contended;
        }
    }
    CHECK(counted == lookups);
    CHECK(total <= s.budget_bytes && peak <= s.budget_bytes &&
          s.peak_total_bytes <= s.budget_bytes);
    uint64_t fills = counted - hits, evictions = 0;
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++)
            evictions += s.counters[l][t].evictions;
    printf("  budget %llu: %llu lookups, %llu hits, %llu fills, %llu evictions, timestamp %llu, "
           "%llu waits for another's fill, %llu contended locks\n",
           (unsigned long long)budget, (unsigned long long)lookups, (unsigned long long)hits,
           (unsigned long long)fills, (unsigned long long)evictions,
           (unsigned long long)cache_timestamp(sh.cache), (unsigned long long)waits,
           (unsigned long long)contended);
    if (expect_hits)
        CHECK(hits > lookups / 2);
    cache_free(sh.cache); /* aborts if any entry is still held */
}

/* Tiny: a few entries per shard, most lookups evict or fill privately. */
static void test_tiny_budget_with_bumps(void)
{
    run(24000, 1000, 0);
}

/* Small: evictions of resident entries dominate. */
static void test_small_budget_with_bumps(void)
{
    run(60000, 2000, 0);
}

static void test_medium_budget_with_bumps(void)
{
    run(150000, 3000, 0);
}

static void test_medium_budget_no_bumps(void)
{
    run(150000, 0, 1);
}

TEST_MAIN(TEST(test_tiny_budget_with_bumps), TEST(test_small_budget_with_bumps),
          TEST(test_medium_budget_with_bumps),
          TEST(test_medium_budget_no_bumps))
