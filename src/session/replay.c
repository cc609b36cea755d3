/*
 * session/replay.c — a render's recorded rays traced again with no shading
 * (RayesRenderOptions.replay_rays): what ray casting alone costs.
 *
 * The runs of rays (accel/record.h) go to the threads in the order they
 * were recorded, each making the query it was: intersections find and
 * describe their hit (the accel's make_hit) as the render's did; a
 * transmission ray passes through every transparent surface (no opacity,
 * a shader's or the cache's, is asked).
 */
#include "session/replay.h"

#include "util/log.h"
#include "util/thread.h"

/* Transparent surfaces let a replayed transmission ray through. */
static Vec3 clear(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    (void)user, (void)ray, (void)hit, (void)crossing;
    return v3(0, 0, 0);
}

typedef struct Replay {
    const Accel *accel;
    const AccelRecord *record;
} Replay;

static void replay_run(void *ctx, size_t task, int worker)
{
    (void)worker;
    const Replay *rp = ctx;
    size_t n;
    const RecordedRay *rays = accel_record_run(rp->record, task, &n);
    for (size_t i = 0; i < n; i++) {
        const RecordedRay *r = &rays[i];
        Hit hit;
        switch ((AccelQuery)r->query) {
        case ACCEL_QUERY_INTERSECT:
            accel_intersect(rp->accel, &r->ray, &hit);
            break;
        case ACCEL_QUERY_INTERSECT_OBJECT:
            accel_intersect_object(rp->accel, r->object, &r->ray, &hit);
            break;
        case ACCEL_QUERY_OCCLUDED:
            accel_occluded(rp->accel, &r->ray);
            break;
        case ACCEL_QUERY_TRANSMISSION:
            accel_transmission(rp->accel, &r->ray, clear, NULL, 0.0f);
            break;
        }
    }
}

int session_replay(const Accel *accel, const AccelRecord *record, int threads, double *wall_s,
                   double *cpu_s)
{
    Replay rp = {accel, record};
    double w0 = time_now(), c0 = time_cpu();
    int e = thread_parallel_for(threads, accel_record_runs(record), replay_run, &rp);
    *wall_s = time_now() - w0;
    *cpu_s = time_cpu() - c0;
    return e ? -1 : 0;
}
