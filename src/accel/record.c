/*
 * accel/record.c — a render's rays kept and traced again (record.h).
 */
#include "accel/record.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

/* One thread's rays, in the order it traced them. */
#define CHUNK_RAYS 4096
typedef struct RecordChunk {
    size_t n;
    RecordedRay rays[CHUNK_RAYS];
} RecordChunk;

struct AccelRecord {
    pthread_mutex_t lock; /* guards chunks, n_chunks and cap */
    RecordChunk **chunks; /* oldest first */
    size_t n_chunks, cap, max_chunks;
    uint64_t id; /* tells a thread's chunk of this record from one of a freed record */
    atomic_ullong dropped;
    atomic_int full; /* max_chunks reached: rays are dropped without the lock */
};

/* The chunk this thread fills, and the record it belongs to. */
static _Thread_local RecordChunk *tl_chunk;
static _Thread_local uint64_t tl_id;
static atomic_ullong next_id = 1;

AccelRecord *accel_record_new(size_t max_bytes)
{
    AccelRecord *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    if (pthread_mutex_init(&r->lock, NULL) != 0) {
        free(r);
        return NULL;
    }
    r->max_chunks = max_bytes / sizeof(RecordChunk);
    r->id = atomic_fetch_add(&next_id, 1);
    return r;
}

void accel_record_free(AccelRecord *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->n_chunks; i++)
        free(r->chunks[i]);
    free(r->chunks);
    pthread_mutex_destroy(&r->lock);
    free(r);
}

/* A new chunk for this thread, linked into the record (NULL: no room). */
static RecordChunk *record_chunk(AccelRecord *r)
{
    RecordChunk *c = NULL;
    pthread_mutex_lock(&r->lock);
    if (r->n_chunks == r->cap && r->cap < r->max_chunks) {
        size_t cap = r->cap ? 2 * r->cap : 64;
        RecordChunk **chunks = realloc(r->chunks, cap * sizeof *chunks);
        if (chunks) {
            r->chunks = chunks;
            r->cap = cap;
        }
    }
    if (r->n_chunks < r->cap && r->n_chunks < r->max_chunks && (c = malloc(sizeof *c)) != NULL) {
        c->n = 0;
        r->chunks[r->n_chunks++] = c;
    }
    pthread_mutex_unlock(&r->lock);
    return c;
}

void accel_record_ray(AccelRecord *r, AccelQuery query, uint32_t object, const Ray *ray)
{
    RecordChunk *c = tl_id == r->id ? tl_chunk : NULL;
    if (!c || c->n == CHUNK_RAYS) {
        c = atomic_load_explicit(&r->full, memory_order_relaxed) ? NULL : record_chunk(r);
        tl_chunk = c;
        tl_id = r->id;
        if (!c) {
            tl_id = 0;
            atomic_store_explicit(&r->full, 1, memory_order_relaxed);
            atomic_fetch_add(&r->dropped, 1);
            return;
        }
    }
    c->rays[c->n++] = (RecordedRay){*ray, (uint32_t)query, object};
}

uint64_t accel_record_rays(const AccelRecord *r)
{
    uint64_t n = 0;
    for (size_t i = 0; i < r->n_chunks; i++)
        n += r->chunks[i]->n;
    return n;
}

uint64_t accel_record_dropped(const AccelRecord *r)
{
    return atomic_load(&((AccelRecord *)r)->dropped);
}

size_t accel_record_runs(const AccelRecord *r)
{
    return r->n_chunks;
}

const RecordedRay *accel_record_run(const AccelRecord *r, size_t i, size_t *n)
{
    *n = r->chunks[i]->n;
    return r->chunks[i]->rays;
}
