/*
 * cache/cache.c — the multiresolution cache (memo section 3.1 and 3.2): per
 * data type (memo section 6) three resolutions, each in CACHE_SHARDS shards; a shard is a mutex, a
 * chained hash table, an LRU list of unpinned entries and a byte budget.
 *
 * Entry layout: a CacheEntry header followed by 3 * n_values half floats.
 * An entry is
 *   - resident: in its shard's hash table (counted in the shard's bytes), or
 *     private: filled for one lookup when it could not fit, never shared;
 *   - pinned while refs > 0 (held by CacheLocal slots or a thread waiting for
 *     it), else on the shard's LRU list (least recently used at lru.next);
 *   - ready once its values are written; lookups of an entry that is not
 *     ready wait on the shard's condition variable.
 * A resident entry found stale (older timestamp) is unlinked from the table;
 * if nobody holds it, it is freed at once, otherwise by its last release.
 * Its bytes stay counted until it is freed, so the budget is never exceeded.
 *
 * Lending: a shard's budget is its share of its level's (the split) of its
 * partition's (the type's), and every byte a shard counts is also taken
 * from the cache's atomic count, which never exceeds the sum of the
 * partitions' budgets (the pool). A shard at its share may go on past it
 * with bytes the pool leaves unused: other levels' and other types' (not
 * its own level's in its own partition: those are its sibling shards');
 * a shard within its share that finds the pool full takes its bytes back
 * from shards past theirs (reclaim, its own partition's first, their least
 * recently used entries first). So a level or a type that thrashes
 * borrows what the others do not use, and gives it back as they need it;
 * a type within its budget is never evicted by another.
 *
 * Locks: one shard lock at a time; the fill function runs with no lock held
 * (it may look up other keys: a fill at diffuse depth d only looks up depth
 * d + 1, so waits cannot form a cycle). CacheLocal slots are touched only by
 * their thread.
 */
#include "cache/cache.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "util/check.h"
#include "util/half.h"
#include "util/log.h"
#include "util/rng.h"

#define CACHE_SHARDS 8

struct CacheEntry {
    CacheKey key;
    uint64_t timestamp;           /* cache timestamp when filled */
    uint64_t hash;                /* of key */
    CacheEntry *hnext;            /* hash chain */
    CacheEntry *prev, *next;      /* LRU links, while unpinned and resident */
    uint32_t refs;                /* holders; under the shard lock (private: always 1) */
    uint32_t n_values;
    uint8_t ready;                /* values written */
    uint8_t resident;             /* in the hash table */
    uint8_t private_entry;        /* never in a table; freed by its only release */
    /* followed by the values: RGB halves, 3 * n_values (entry_values); not a
     * flexible array member, so that a Shard can embed its LRU sentinel */
};

static inline uint16_t *entry_values(CacheEntry *e)
{
    return (uint16_t *)(e + 1);
}

/* The bytes every partition counts against the sum of their budgets. */
typedef struct Pool {
    uint64_t budget;
    atomic_uint_fast64_t used, peak;
} Pool;

/* A partition's budget (its share of the pool) and what its shards count. */
typedef struct Part {
    Pool *pool;
    uint64_t budget;
    atomic_uint_fast64_t used, peak;
    atomic_uint_fast64_t level_used[CACHE_N_LEVELS];
    uint64_t level_budget[CACHE_N_LEVELS];
} Part;

typedef struct Shard {
    Part *part;
    int level;
    pthread_mutex_t lock;
    pthread_cond_t filled;        /* an entry became ready */
    CacheEntry **table;           /* n_slots chains, NULL if the budget allows none */
    size_t n_slots;               /* a power of two */
    CacheEntry lru;               /* sentinel: lru.next is least recently used */
    uint64_t budget, bytes, peak; /* bytes: table + resident and dropped-but-held entries */
    uint64_t lru_bytes;           /* bytes of the entries on the LRU list (evictable) */
    uint64_t entries;             /* resident */
    uint64_t evictions[CACHE_N_TYPES];
} Shard;

struct Cache {
    /* Partitions of the budget: a type's entries live in partition
     * part_of[type] (all in 0 for cache_new, each its own for
     * cache_new_typed), whose budget they share. */
    Shard shards[CACHE_N_TYPES][CACHE_N_LEVELS][CACHE_SHARDS];
    Part parts[CACHE_N_TYPES];
    uint8_t part_of[CACHE_N_TYPES];
    Pool pool; /* all partitions */
    atomic_uint_fast64_t timestamp;
    pthread_mutex_t counters_lock;
    CacheCounters counters[CACHE_N_LEVELS][CACHE_N_TYPES];
};

const int cache_local_slots[CACHE_N_LEVELS] = {4096, 512, 1024}; /* powers of two */

/* Nominal values per entry, for sizing hash tables (memo Figure 2 sizes). */
static const size_t nominal_values[CACHE_N_LEVELS] = {4, 25, 289};

size_t cache_entry_bytes(size_t n_values)
{
    return sizeof(CacheEntry) + 3 * sizeof(uint16_t) * n_values;
}

static uint64_t key_hash(const CacheKey *k)
{
    uint64_t a = (uint64_t)k->patch | (uint64_t)k->depth << 32 | (uint64_t)k->segment << 48 |
                 (uint64_t)k->side << 56;
    uint64_t b = (uint64_t)k->type | (uint64_t)k->level << 8 | (uint64_t)k->instance << 16;
    return hash_combine(hash_u64(a), b);
}

static int key_equal(const CacheKey *a, const CacheKey *b)
{
    return a->patch == b->patch && a->depth == b->depth && a->segment == b->segment &&
           a->side == b->side && a->type == b->type && a->level == b->level &&
           a->instance == b->instance;
}

/* Counts n more bytes of s against its partition and the pool; with take,
 * only if they fit the pool's budget (returns 0 if not). Caller holds s's
 * lock. */
static int part_add(Shard *s, uint64_t n, int take)
{
    Part *p = s->part;
    uint_fast64_t u = atomic_load(&p->pool->used);
    do {
        if (take && u + n > p->pool->budget)
            return 0;
    } while (!atomic_compare_exchange_weak(&p->pool->used, &u, u + n));
    uint_fast64_t peak = atomic_load(&p->pool->peak);
    while (u + n > peak && !atomic_compare_exchange_weak(&p->pool->peak, &peak, u + n))
        ;
    uint_fast64_t now = atomic_fetch_add(&p->used, n) + n;
    peak = atomic_load(&p->peak);
    while (now > peak && !atomic_compare_exchange_weak(&p->peak, &peak, now))
        ;
    atomic_fetch_add(&p->level_used[s->level], n);
    return 1;
}

/* The pool's count last, as part_add's first: the partitions' counts
 * never sum past the pool's, nor their peaks past its budget. */
static void part_sub(Shard *s, uint64_t n)
{
    atomic_fetch_sub(&s->part->level_used[s->level], n);
    atomic_fetch_sub(&s->part->used, n);
    atomic_fetch_sub(&s->part->pool->used, n);
}

/* Returns 0, or -1 when out of memory. */
static int shard_init(Shard *s, Part *part, int level, uint64_t budget, size_t nominal)
{
    s->part = part;
    s->level = level;
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->filled, NULL);
    s->lru.prev = s->lru.next = &s->lru;
    s->budget = budget;
    /* The largest power of two of slots that, with nominal entries, fits. */
    size_t per = sizeof(CacheEntry *) + cache_entry_bytes(nominal);
    size_t n = 1;
    while ((n * 2) * per <= budget && n < ((size_t)1 << 24))
        n *= 2;
    if (n * sizeof(CacheEntry *) > budget)
        return 0; /* not even one slot: every lookup fills privately */
    s->table = calloc(n, sizeof *s->table);
    if (!s->table)
        return -1;
    s->n_slots = n;
    s->bytes = s->peak = n * sizeof(CacheEntry *);
    part_add(s, s->bytes, 0); /* within the share, which is within the budget */
    return 0;
}

static Cache *cache_new_parts(const uint64_t budget_bytes[CACHE_N_TYPES],
                              const float split[CACHE_N_LEVELS], int shared);

Cache *cache_new(uint64_t budget_bytes, const float split[CACHE_N_LEVELS])
{
    uint64_t budgets[CACHE_N_TYPES] = {budget_bytes};
    return cache_new_parts(budgets, split, 1);
}

Cache *cache_new_typed(const uint64_t budget_bytes[CACHE_N_TYPES],
                       const float split[CACHE_N_LEVELS])
{
    return cache_new_parts(budget_bytes, split, 0);
}

/* shared: every type in partition 0 (budget_bytes[0]); else type t in
 * partition t. */
static Cache *cache_new_parts(const uint64_t budget_bytes[CACHE_N_TYPES],
                              const float split[CACHE_N_LEVELS], int shared)
{
    Cache *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    for (int t = 0; t < CACHE_N_TYPES; t++)
        c->part_of[t] = shared ? 0 : (uint8_t)t;
    int failed = 0;
    atomic_init(&c->timestamp, 1);
    pthread_mutex_init(&c->counters_lock, NULL);
    atomic_init(&c->pool.used, 0);
    atomic_init(&c->pool.peak, 0);
    for (int t = 0; t < CACHE_N_TYPES; t++)
        c->pool.budget += budget_bytes[t];
    for (int t = 0; t < CACHE_N_TYPES; t++) {
        Part *p = &c->parts[t];
        p->pool = &c->pool;
        p->budget = budget_bytes[t];
        atomic_init(&p->used, 0);
        atomic_init(&p->peak, 0);
        for (int l = 0; l < CACHE_N_LEVELS; l++) {
            float f = split[l] < 0.0f ? 0.0f : split[l];
            p->level_budget[l] = (uint64_t)((double)budget_bytes[t] * f);
            atomic_init(&p->level_used[l], 0);
            for (int s = 0; s < CACHE_SHARDS; s++)
                if (shard_init(&c->shards[t][l][s], p, l, p->level_budget[l] / CACHE_SHARDS,
                               nominal_values[l]) != 0)
                    failed = 1;
        }
    }
    if (failed) {
        cache_free(c);
        return NULL;
    }
    return c;
}

void cache_free(Cache *c)
{
    if (!c)
        return;
    for (int t = 0; t < CACHE_N_TYPES; t++)
        for (int l = 0; l < CACHE_N_LEVELS; l++)
            for (int s = 0; s < CACHE_SHARDS; s++) {
                Shard *sh = &c->shards[t][l][s];
                for (size_t i = 0; i < sh->n_slots; i++)
                    for (CacheEntry *e = sh->table[i], *next; e; e = next) {
                        next = e->hnext;
                        RY_CHECK(e->refs == 0); /* nobody may hold an entry now */
                        free(e);
                    }
                free(sh->table);
                pthread_mutex_destroy(&sh->lock);
                pthread_cond_destroy(&sh->filled);
            }
    pthread_mutex_destroy(&c->counters_lock);
    free(c);
}

uint64_t cache_timestamp(const Cache *c)
{
    return atomic_load(&((Cache *)c)->timestamp);
}

uint64_t cache_bump_timestamp(Cache *c)
{
    return atomic_fetch_add(&c->timestamp, 1) + 1;
}

static Shard *shard_of(Cache *c, const CacheKey *k, uint64_t hash)
{
    return &c->shards[c->part_of[k->type]][k->level][(hash >> 40) % CACHE_SHARDS];
}

static void lru_unlink(Shard *s, CacheEntry *e)
{
    s->lru_bytes -= cache_entry_bytes(e->n_values);
    e->prev->next = e->next;
    e->next->prev = e->prev;
    e->prev = e->next = NULL;
}

static void lru_append(Shard *s, CacheEntry *e) /* as most recently used */
{
    s->lru_bytes += cache_entry_bytes(e->n_values);
    e->prev = s->lru.prev;
    e->next = &s->lru;
    s->lru.prev->next = e;
    s->lru.prev = e;
}

/* Removes e from its hash chain. Caller holds the shard lock. */
static void table_unlink(Shard *s, CacheEntry *e)
{
    CacheEntry **p = &s->table[e->hash & (s->n_slots - 1)];
    while (*p != e)
        p = &(*p)->hnext;
    *p = e->hnext;
    e->resident = 0;
    s->entries--;
}

static void entry_free(Shard *s, CacheEntry *e)
{
    uint64_t n = cache_entry_bytes(e->n_values);
    s->bytes -= n;
    part_sub(s, n);
    free(e);
}

static void evict_lru(Shard *s)
{
    CacheEntry *victim = s->lru.next;
    lru_unlink(s, victim);
    table_unlink(s, victim);
    s->evictions[victim->key.type]++;
    entry_free(s, victim);
}

/* What a shard past its share may borrow: bytes of the pool that neither
 * are used nor belong to its own level's unused share in its partition. */
static int may_borrow(const Shard *s, uint64_t need)
{
    Part *p = s->part;
    uint64_t used = atomic_load(&p->pool->used), level = atomic_load(&p->level_used[s->level]);
    uint64_t own_unused = level < p->level_budget[s->level] ? p->level_budget[s->level] - level : 0;
    return used + need + own_unused <= p->pool->budget;
}

/* Counts need more bytes in s: within its share, or borrowed, or in place
 * of its own least recently used entries, as few as make room. Returns 0
 * if they do not fit, evicting nothing when even every unpinned entry of
 * its own would not make room; then *reclaim = 1 if the shard is within
 * its share and others hold the partition's bytes. Caller holds the lock. */
static int take_room(Shard *s, uint64_t need, int *reclaim)
{
    *reclaim = 0;
    for (;;) {
        int within = s->bytes + need <= s->budget;
        if ((within || may_borrow(s, need)) && part_add(s, need, 1))
            return 1;
        if (within) {
            *reclaim = 1;
            return 0;
        }
        if (s->lru.next == &s->lru || s->bytes - s->lru_bytes + need > s->budget)
            return 0;
        evict_lru(s);
    }
}

/* Evicts least recently used entries of shards past their share, partition
 * p's first, then the other partitions' in order, until need bytes are
 * freed or none is past. Holds no lock but one shard's at a time. */
static void reclaim(Cache *c, const Part *p, uint64_t need)
{
    uint64_t freed = 0;
    int own = (int)(p - c->parts);
    for (int k = 0; k < CACHE_N_TYPES && freed < need; k++) {
        Shard(*part)[CACHE_SHARDS] = c->shards[(own + k) % CACHE_N_TYPES]; /* partition t */
        for (int l = 0; l < CACHE_N_LEVELS && freed < need; l++)
            for (int i = 0; i < CACHE_SHARDS && freed < need; i++) {
                Shard *s = &part[l][i];
                pthread_mutex_lock(&s->lock);
                while (s->bytes > s->budget && s->lru.next != &s->lru && freed < need) {
                    freed += cache_entry_bytes(s->lru.next->n_values);
                    evict_lru(s);
                }
                pthread_mutex_unlock(&s->lock);
            }
    }
}

/* Drops a reference. Caller does not hold the shard lock. */
static void release(Cache *c, CacheEntry *e)
{
    if (e->private_entry) {
        free(e);
        return;
    }
    Shard *s = shard_of(c, &e->key, e->hash);
    pthread_mutex_lock(&s->lock);
    RY_DCHECK(e->refs > 0);
    if (--e->refs == 0) {
        if (e->resident && e->timestamp < cache_timestamp(c)) {
            table_unlink(s, e); /* stale: let it go now rather than age out */
            entry_free(s, e);
        } else if (e->resident)
            lru_append(s, e);
        else
            entry_free(s, e); /* dropped as stale while held */
    }
    pthread_mutex_unlock(&s->lock);
}

void cache_local_init(CacheLocal *local, Cache *cache)
{
    memset(local, 0, sizeof *local);
    local->cache = cache;
    for (int l = 0; l < CACHE_N_LEVELS; l++) {
        uint64_t level_budget = 0;
        for (int t = 0; t < CACHE_N_TYPES; t++)
            level_budget += cache->parts[t].level_budget[l];
        uint64_t capacity = level_budget / cache_entry_bytes(nominal_values[l]);
        uint32_t n = (uint32_t)cache_local_slots[l];
        while (n > 4 && (uint64_t)n * 32 > capacity)
            n /= 2;
        local->n_slots[l] = n;
    }
}

void cache_local_fini(CacheLocal *local)
{
    Cache *c = local->cache;
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (uint32_t i = 0; i < local->n_slots[l]; i++)
            if (local->slots[l][i]) {
                release(c, local->slots[l][i]);
                local->slots[l][i] = NULL;
            }
    pthread_mutex_lock(&c->counters_lock);
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++) {
            CacheCounters *to = &c->counters[l][t];
            const CacheCounters *from = &local->counters[l][t];
            to->lookups += from->lookups;
            to->hits += from->hits;
            to->misses += from->misses;
            to->fills += from->fills;
            to->waits += from->waits;
            to->wait_ns += from->wait_ns;
            to->contended += from->contended;
        }
    pthread_mutex_unlock(&c->counters_lock);
    memset(local->counters, 0, sizeof local->counters);
}

/* Doubles s's hash table when it holds more entries than slots, so chains
 * stay about one entry long: a table sized for a level's nominal entries
 * (memo Figure 2's) held 8 a chain where a level borrowed the others'
 * bytes for small entries (coarse fills of a dense mesh at 8 bounces:
 * walking them was a fifth of the render). The new slots' bytes are
 * counted like an entry's, and the table stays as it is when they do not
 * fit the cache's budget (the pool). Caller holds s's lock. */
static void table_grow(Shard *s)
{
    size_t n = s->n_slots, grown = 2 * n;
    if (s->entries <= n || grown > ((size_t)1 << 24))
        return;
    uint64_t extra = (grown - n) * sizeof(CacheEntry *);
    if (!part_add(s, extra, 1))
        return;
    CacheEntry **table = calloc(grown, sizeof *table);
    if (!table) {
        part_sub(s, extra);
        return;
    }
    for (size_t i = 0; i < n; i++)
        for (CacheEntry *e = s->table[i], *next; e; e = next) {
            next = e->hnext;
            CacheEntry **chain = &table[e->hash & (grown - 1)];
            e->hnext = *chain;
            *chain = e;
        }
    free(s->table);
    s->table = table;
    s->n_slots = grown;
    s->bytes += extra;
    s->peak = s->bytes > s->peak ? s->bytes : s->peak;
}

/* Finds a current entry and takes a reference (waiting until it is ready),
 * or inserts a new pinned, unready entry for the caller to fill (*inserted =
 * 1), or returns NULL if none fits. Drops a stale entry it meets. */
static CacheEntry *find_or_insert(Cache *c, const CacheKey *key, uint64_t hash, size_t n_values,
                                  int *inserted, CacheCounters *ctr)
{
    Shard *s = shard_of(c, key, hash);
    uint64_t now = cache_timestamp(c);
    int reclaimed = 0;
    *inserted = 0;
again:
    if (pthread_mutex_trylock(&s->lock) != 0) {
        ctr->contended++;
        pthread_mutex_lock(&s->lock);
    }
    CacheEntry *e = NULL;
    if (s->table) {
        for (e = s->table[hash & (s->n_slots - 1)]; e; e = e->hnext)
            if (e->hash == hash && key_equal(&e->key, key))
                break;
        if (e && e->timestamp < now) { /* stale: a miss; drop it */
            table_unlink(s, e);
            if (e->refs == 0) {
                lru_unlink(s, e);
                entry_free(s, e);
            }
            e = NULL;
        }
    }
    if (e) {
        if (e->refs++ == 0)
            lru_unlink(s, e);
        if (!e->ready) { /* another thread fills it: wait (what threads cost each other) */
            double t0 = time_now();
            while (!e->ready)
                pthread_cond_wait(&s->filled, &s->lock);
            ctr->waits++;
            ctr->wait_ns += (uint64_t)(1e9 * (time_now() - t0));
        }
        pthread_mutex_unlock(&s->lock);
        return e;
    }
    uint64_t need = cache_entry_bytes(n_values);
    int reclaim_others = 0, counted = s->table && take_room(s, need, &reclaim_others);
    if (!counted && reclaim_others && !reclaimed) {
        pthread_mutex_unlock(&s->lock); /* one lock at a time */
        reclaim(c, s->part, need);
        reclaimed = 1;
        goto again; /* another thread may have inserted the key meanwhile */
    }
    if (counted && (e = malloc(need)) == NULL)
        part_sub(s, need);
    if (counted && e) {
        memset(e, 0, sizeof *e);
        e->key = *key;
        e->hash = hash;
        e->timestamp = now;
        e->n_values = (uint32_t)n_values;
        e->refs = 1;
        e->resident = 1;
        CacheEntry **chain = &s->table[hash & (s->n_slots - 1)];
        e->hnext = *chain;
        *chain = e;
        s->entries++;
        s->bytes += need;
        s->peak = s->bytes > s->peak ? s->bytes : s->peak;
        *inserted = 1;
        table_grow(s);
    }
    pthread_mutex_unlock(&s->lock);
    return e;
}

/* Runs the fill and stores halves; publishes a resident entry. */
static void fill_entry(Cache *c, CacheEntry *e, CacheFillFn fill, void *user)
{
    size_t n = e->n_values;
    float(*tmp)[3] = malloc((n ? n : 1) * sizeof *tmp);
    RY_CHECK(tmp != NULL);
    fill(user, &e->key, n, tmp);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            entry_values(e)[3 * i + k] = half_from_float_clamped(tmp[i][k]);
    free(tmp);
    if (e->private_entry) { /* never shared: nobody can be waiting */
        e->ready = 1;
        return;
    }
    /* A shared entry, even one dropped as stale during the fill (resident is
     * then 0, written under the lock), may have waiters: publish under the
     * lock and wake them. */
    Shard *s = shard_of(c, &e->key, e->hash);
    pthread_mutex_lock(&s->lock);
    e->ready = 1;
    pthread_cond_broadcast(&s->filled);
    pthread_mutex_unlock(&s->lock);
}

const uint16_t *cache_lookup(CacheLocal *local, const CacheKey *key, size_t n_values,
                             CacheFillFn fill, void *user)
{
    Cache *c = local->cache;
    RY_CHECK(key->level < CACHE_N_LEVELS && key->type < CACHE_N_TYPES);
    uint64_t hash = key_hash(key);
    CacheCounters *ctr = &local->counters[key->level][key->type];
    CacheEntry **slot = &local->slots[key->level][hash & (uint64_t)(local->n_slots[key->level] - 1)];
    ctr->lookups++;
    CacheEntry *held = *slot;
    if (held && held->hash == hash && key_equal(&held->key, key) &&
        held->timestamp == cache_timestamp(c) && held->ready) {
        ctr->hits++; /* the lock-free path of coherent lookups */
        return entry_values(held);
    }
    if (held) {
        *slot = NULL;
        release(c, held);
    }
    int inserted;
    CacheEntry *e = find_or_insert(c, key, hash, n_values, &inserted, ctr);
    if (e && !inserted) {
        ctr->hits++;
    } else {
        ctr->misses++;
        ctr->fills++;
        if (!e) { /* cannot fit: a private entry, correct but not shared */
            e = calloc(1, cache_entry_bytes(n_values));
            RY_CHECK(e != NULL);
            e->key = *key;
            e->hash = hash;
            e->timestamp = cache_timestamp(c);
            e->n_values = (uint32_t)n_values;
            e->refs = 1;
            e->private_entry = 1;
        }
        fill_entry(c, e, fill, user);
    }
    RY_CHECK(e->n_values == n_values);
    /* The fill may have looked up other keys through this local part and
     * parked one in our slot: release it before taking the slot. */
    if (*slot)
        release(c, *slot);
    *slot = e;
    return entry_values(e);
}

void cache_get_stats(const Cache *cc, CacheStats *st)
{
    Cache *c = (Cache *)cc;
    memset(st, 0, sizeof *st);
    st->budget_bytes = c->pool.budget;
    st->peak_total_bytes = atomic_load(&c->pool.peak);
    pthread_mutex_lock(&c->counters_lock);
    memcpy(st->counters, c->counters, sizeof st->counters);
    pthread_mutex_unlock(&c->counters_lock);
    for (int t = 0; t < CACHE_N_TYPES; t++)
        st->type_peak_bytes[t] = atomic_load(&c->parts[t].peak);
    for (int t = 0; t < CACHE_N_TYPES; t++)
        for (int l = 0; l < CACHE_N_LEVELS; l++) {
            st->type_budget_bytes[t] = c->parts[c->part_of[t]].budget;
            st->level_budget_bytes[l] += c->parts[t].level_budget[l];
            for (int s = 0; s < CACHE_SHARDS; s++) {
                Shard *sh = &c->shards[t][l][s];
                pthread_mutex_lock(&sh->lock);
                st->entries[l] += sh->entries;
                st->type_entries[t][l] += sh->entries; /* partition t's */
                st->bytes[l] += sh->bytes;
                st->slots[l] += sh->n_slots;
                st->peak_bytes[l] += sh->peak;
                for (int t = 0; t < CACHE_N_TYPES; t++)
                    st->counters[l][t].evictions += sh->evictions[t];
                pthread_mutex_unlock(&sh->lock);
            }
        }
}
