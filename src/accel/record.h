/*
 * accel/record.h — a render's rays, recorded as the accel sees them and
 * traced again without shading: what ray casting alone costs of a render
 * (RayesRenderOptions.replay_rays, bench/table1 --replay 1; the replay is
 * session/replay.c).
 *
 * Every query (accel_intersect, accel_intersect_object, accel_occluded,
 * accel_transmission) made while a record is attached to the Accel is
 * kept, in the order each thread made them, in runs of one thread's rays
 * (4096 at most).
 *
 * Thread-safety: any number of threads may record into one record; read
 * the runs once the recording threads have joined.
 */
#ifndef RAYES_ACCEL_RECORD_H
#define RAYES_ACCEL_RECORD_H

#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"

typedef struct AccelRecord AccelRecord;

typedef enum AccelQuery {
    ACCEL_QUERY_INTERSECT = 0,
    ACCEL_QUERY_INTERSECT_OBJECT = 1,
    ACCEL_QUERY_OCCLUDED = 2,
    ACCEL_QUERY_TRANSMISSION = 3
} AccelQuery;

typedef struct RecordedRay {
    Ray ray;
    uint32_t query;  /* AccelQuery */
    uint32_t object; /* ACCEL_QUERY_INTERSECT_OBJECT's object */
} RecordedRay;

/* A record of at most max_bytes of rays (48 bytes each); rays beyond are
 * counted as dropped. NULL when out of memory. */
AccelRecord *accel_record_new(size_t max_bytes);
void accel_record_free(AccelRecord *record);

/* Keeps one query (called by the accel's queries while attached). */
void accel_record_ray(AccelRecord *record, AccelQuery query, uint32_t object, const Ray *ray);

/* Attaches record to accel (NULL detaches); queries record while attached. */
void accel_attach_record(Accel *accel, AccelRecord *record);

/* Rays kept, and rays dropped for want of room. */
uint64_t accel_record_rays(const AccelRecord *record);
uint64_t accel_record_dropped(const AccelRecord *record);

/* The record's runs of rays, oldest first: run i holds *n rays. */
size_t accel_record_runs(const AccelRecord *record);
const RecordedRay *accel_record_run(const AccelRecord *record, size_t i, size_t *n);

#endif /* RAYES_ACCEL_RECORD_H */
