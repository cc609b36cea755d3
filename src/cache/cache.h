/*
 * cache/cache.h — the multiresolution cache of memo section 3 (radiosity,
 * and later opacity and irradiance), knowing nothing of shading: a miss
 * calls the fill function it is given.
 *
 * Structure (memo 3.1, DESIGN.md "The multiresolution cache"):
 *  - per data type (radiosity, opacity, irradiance: memo 6, one cache whose
 *    keys carry the type; and rayes's environment guides) a budget of its
 *    own (a type past it borrows what the others leave unused, until they
 *    need it back), and within it
 *  - three resolutions (COARSE, MEDIUM, FINE), each with its own share of the
 *    byte budget (default 25% / 25% / 50% of 100 MB; a resolution past its
 *    share borrows what the others leave unused, until they need it back)
 *    and least-recently-used replacement;
 *  - each resolution is split into shards (a lock, a hash table, an LRU list
 *    and an equal part of the resolution's budget); LRU is exact within a
 *    shard;
 *  - entries hold RGB half floats per vertex and are reference-counted; an
 *    entry held by anyone is pinned (off its LRU list, never evicted);
 *  - each thread has a CacheLocal: a small direct-mapped table of entries it
 *    holds references to, so repeated coherent lookups take no lock;
 *  - an entry being filled by one thread is waited for by others (never
 *    returned half-written);
 *  - every entry records the timestamp it was filled at; an entry older than
 *    the cache's current timestamp is a miss and is dropped (memo 3.2).
 *
 * Budget: header, payload and hash-slot bytes of every resident entry are
 * counted; the budget is never exceeded. When an entry cannot fit (a budget
 * smaller than one entry, or everything pinned), the lookup fills a private
 * entry that is not inserted and is freed when released: rendering stays
 * correct, just slower.
 *
 * Thread-safety: cache_* functions are thread-safe; a CacheLocal belongs to
 * one thread.
 */
#ifndef RAYES_CACHE_CACHE_H
#define RAYES_CACHE_CACHE_H

#include <stddef.h>
#include <stdint.h>

typedef enum CacheLevel {
    CACHE_COARSE = 0,
    CACHE_MEDIUM = 1,
    CACHE_FINE = 2,
    CACHE_N_LEVELS = 3
} CacheLevel;

typedef enum CacheType {
    CACHE_RADIOSITY = 0,
    CACHE_OPACITY = 1,
    CACHE_IRRADIANCE = 2,
    CACHE_GUIDE = 3, /* an environment light's weights per grid (render/envguide.c) */
    CACHE_N_TYPES = 4
} CacheType;

/* What an entry is for. Two keys are equal iff all fields are. */
typedef struct CacheKey {
    uint32_t patch;    /* patch id (a master's, for instances: see instance); past the
                          grids, a cluster of tiny grids (radiosity, irradiance) or a
                          volume's brick (opacity) */
    uint16_t depth;    /* diffuse depth */
    uint8_t segment;   /* motion segment */
    uint8_t side;      /* 0: front (dPdu x dPdv), 1: back */
    uint8_t type;      /* CacheType */
    uint8_t level;     /* CacheLevel */
    uint32_t instance; /* 0: geometry placed once; else the object instance + 1 whose
                          master grid `patch` is (memo 3.1: each instance has its own
                          entries, its illumination and attributes differ) */
} CacheKey;

/* Fills n_values RGB values for key (float, any finite or infinite value;
 * the cache clamps to the largest finite half). Must depend only on key and
 * user so that a refill gives the same bytes. Called without locks held. */
typedef void (*CacheFillFn)(void *user, const CacheKey *key, size_t n_values, float (*out)[3]);

typedef struct Cache Cache;
typedef struct CacheEntry CacheEntry;

/* Per level and data type counters. */
typedef struct CacheCounters {
    uint64_t lookups, hits, misses, fills, evictions;
    uint64_t waits;     /* lookups that found their entry being filled by another
                           thread and waited for it */
    uint64_t wait_ns;   /* the time they waited, nanoseconds */
    uint64_t contended; /* lookups that found their shard's lock taken */
} CacheCounters;

typedef struct CacheStats {
    uint64_t budget_bytes;                                /* whole budget, all types */
    uint64_t peak_total_bytes;                            /* all types', at its peak */
    uint64_t level_budget_bytes[CACHE_N_LEVELS];          /* these four: all types summed */
    uint64_t entries[CACHE_N_LEVELS];                     /* resident now */
    uint64_t bytes[CACHE_N_LEVELS];                       /* counted now */
    uint64_t slots[CACHE_N_LEVELS]; /* hash slots now (8 bytes each, in bytes): a shard's table
                                       doubles when its entries outnumber its slots */
    uint64_t peak_bytes[CACHE_N_LEVELS];                  /* sum of the shards' peaks (a
                                                       level may borrow past its share) */
    uint64_t type_budget_bytes[CACHE_N_TYPES];            /* the budget of the type's partition; */
    uint64_t type_entries[CACHE_N_TYPES][CACHE_N_LEVELS]; /* these two: partition t's (the
                                                       type's in a cache_new_typed cache) */
    uint64_t type_peak_bytes[CACHE_N_TYPES]; /* the partition's peak (past its budget when it
                                                borrowed the others') */
    CacheCounters counters[CACHE_N_LEVELS][CACHE_N_TYPES];
} CacheStats;

/* A new cache whose data type t has budget_bytes[t], split among the
 * resolutions by fractions split[level] (summing to at most 1; a level
 * whose share is full borrows what the others leave unused, and gives it
 * back as they need it). Types lend the same way: a type past its budget
 * borrows what the other types leave unused, and gives it back as they
 * need it, so the cache holds at most the budgets' sum and entries of a
 * type within its budget are never evicted by another's (the radiosity
 * budget is the user's "cache size", the opacity budget RenderMan's
 * "opacitycachememory"). A type of budget 0 borrows nothing: it fills a
 * private entry at every lookup. Returns NULL when out of memory. */
Cache *cache_new_typed(const uint64_t budget_bytes[CACHE_N_TYPES],
                       const float split[CACHE_N_LEVELS]);
/* A cache whose types all share one budget (entries of any type may evict
 * any other's). */
Cache *cache_new(uint64_t budget_bytes, const float split[CACHE_N_LEVELS]);
/* Frees the cache; no entry may be held. */
void cache_free(Cache *cache);

/* The current timestamp, and a new one (returns it). Entries filled before
 * the bump are never returned after it. */
uint64_t cache_timestamp(const Cache *cache);
uint64_t cache_bump_timestamp(Cache *cache);

/* A thread's local part: a direct-mapped table of held entries per level,
 * largest for COARSE, whose lookups are the least coherent and whose entries
 * are the smallest, and large for FINE, whose entries a volume's march
 * walks through by the hundred (at most cache_local_slots[level] slots, at most
 * CACHE_LOCAL_SLOTS; fewer when the level's budget is small, so that one
 * thread never pins more than 1/32 of the entries a level can hold). A
 * lookup found here takes no lock; the tables are large because diffuse
 * rays hit patches all over the scene: on cornell-teapots at 512 x 512,
 * going from 256 to 4096 coarse slots took a fifth off the cached render. */
#define CACHE_LOCAL_SLOTS 4096
extern const int cache_local_slots[CACHE_N_LEVELS];

typedef struct CacheLocal {
    Cache *cache;
    CacheEntry *slots[CACHE_N_LEVELS][CACHE_LOCAL_SLOTS]; /* held references */
    uint32_t n_slots[CACHE_N_LEVELS];                      /* slots in use, a power of two */
    CacheCounters counters[CACHE_N_LEVELS][CACHE_N_TYPES]; /* merged on fini */
} CacheLocal;

void cache_local_init(CacheLocal *local, Cache *cache);
/* Releases every held entry and adds the counters to the cache's. */
void cache_local_fini(CacheLocal *local);

/* The values (n_values RGB half floats, 3 * n_values uint16_t) of the entry
 * for key, filling it with fill(user, key, ...) on a miss. The entry stays
 * valid until the next lookup of the same level through this CacheLocal, or
 * cache_local_fini. n_values must be the same for every lookup of a key. */
const uint16_t *cache_lookup(CacheLocal *local, const CacheKey *key, size_t n_values,
                             CacheFillFn fill, void *user);

/* The statistics so far (counters of finished CacheLocals only). */
void cache_get_stats(const Cache *cache, CacheStats *stats);

/* Bytes an entry of n_values values is charged (header + payload + slot). */
size_t cache_entry_bytes(size_t n_values);

#endif /* RAYES_CACHE_CACHE_H */
