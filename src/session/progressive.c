/*
 * session/progressive.c — the progressive session of rayes.h: a prepared
 * scene, a radiosity cache, a texture system and the film's running sums
 * kept from pass to pass, for interactive preview (memo section 3.2:
 * "interactive re-rendering ... timestamps").
 *
 * What an update keeps follows the scene's change stamps (scene.h
 * SceneChange): a camera-only change keeps the grids, diced for the camera
 * the scene was last prepared with, and the cache, whose radiosity does not
 * depend on the view; a shading change (light or shader parameters)
 * refreshes the render-side objects and bumps the cache's timestamp; any
 * other change prepares the scene again (and bumps the timestamp: the
 * grids' patch ids may now name other patches).
 *
 * Memory: the film is width * height * 9 floats (running sums and the
 * image). Thread-safety: one driving thread; cancel is an atomic flag.
 */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "cache/cache.h"
#include "rayes/rayes.h"
#include "render/render.h"
#include "scene/scene.h"
#include "session/session.h"
#include "session/stats.h"
#include "util/log.h"
#include "util/thread.h"

struct RayesSession {
    RayesScene *scene;          /* a reference */
    RayesRenderOptions options;
    RenderSettings set;         /* of options; cache, textures and film filled in */
    Prepared *prep;             /* on the heap: the Accel points into its GridSet */
    Cache *cache;               /* NULL with options.cache off */
    TextureSystem *textures;
    float (*accum)[5];          /* running sums, width * height */
    float *rgba;                /* the image, width * height * 4 */
    int samples;                /* accumulated since the last restart */
    uint64_t seen_camera, seen_shading, seen_geometry; /* scene stamps taken */
    atomic_int cancel;
    /* The last finished pass. */
    RenderStats pass_stats;
    CacheStats pass_cache;      /* counters of that pass alone */
    double pass_s, prepare_s;
};

static void restart(RayesSession *s)
{
    size_t n = (size_t)s->set.width * s->set.height;
    memset(s->accum, 0, n * sizeof *s->accum);
    memset(s->rgba, 0, n * 4 * sizeof *s->rgba);
    s->samples = 0;
}

static void take_stamps(RayesSession *s)
{
    s->seen_camera = s->scene->stamp_camera;
    s->seen_shading = s->scene->stamp_shading;
    s->seen_geometry = s->scene->stamp_geometry;
}

RayesError rayes_session_new(RayesScene *scene, const RayesRenderOptions *options,
                             RayesSession **out)
{
    if (!scene || !options || !out)
        return RAYES_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (scene->timestamp == 0 || scene->dirty)
        return session_fail(scene, RAYES_ERROR_INVALID_OPERATION,
                            "session: the scene is not committed");
    RayesError e = session_check_options(scene, options);
    if (e != RAYES_OK)
        return e;
    if (options->aovs) /* its passes accumulate colour alone */
        return session_fail(scene, RAYES_ERROR_INVALID_ARGUMENT,
                            "session: AOVs are rendered by rayes_render alone");
    RayesSession *s = calloc(1, sizeof *s);
    if (!s)
        return RAYES_ERROR_OUT_OF_MEMORY;
    double t0 = time_now();
    s->options = *options;
    s->set = session_settings(options);
    s->set.stop = NULL; /* its cache outlives a pass: fills must finish (rayes.h) */
    atomic_init(&s->cancel, 0);
    size_t n = (size_t)s->set.width * s->set.height;
    s->accum = malloc(n * sizeof *s->accum);
    s->rgba = calloc(n * 4, sizeof *s->rgba); /* 0 outside a crop window */
    s->textures = session_textures(scene, options->texture_mb, options->texture_width);
    int cached = session_caches(options, CACHE_RADIOSITY) ||
                 session_caches(options, CACHE_OPACITY) ||
                 session_caches(options, CACHE_IRRADIANCE) || options->env_guide;
    if (cached)
        s->cache = session_cache(options);
    if (!s->accum || !s->rgba || !s->textures || (cached && !s->cache)) {
        e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "session: out of memory");
        goto fail;
    }
    s->prep = malloc(sizeof *s->prep);
    if (!s->prep) {
        e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "session: out of memory");
        goto fail;
    }
    e = session_prepare(scene, &s->set, s->textures, s->prep);
    if (e != RAYES_OK)
        goto fail;
    rayes_scene_retain(scene);
    s->scene = scene;
    take_stamps(s);
    s->set.cache = s->cache;
    s->set.textures = s->textures;
    s->set.accum = s->accum;
    s->set.pattern_spp = s->set.spp;
    s->set.spp = 1;
    s->set.cancel = &s->cancel;
    s->prepare_s = time_now() - t0;
    restart(s);
    *out = s;
    return RAYES_OK;
fail:
    rayes_session_free(s);
    return e;
}

/* Also frees a session that rayes_session_new gave up on part way (no
 * scene reference yet, prep NULL or emptied by a failed prepare). */
void rayes_session_free(RayesSession *s)
{
    if (!s)
        return;
    if (s->prep)
        session_prepared_fini(s->prep);
    free(s->prep);
    cache_free(s->cache);
    texture_system_free(s->textures);
    free(s->accum);
    free(s->rgba);
    rayes_scene_release(s->scene);
    free(s);
}

RayesError rayes_session_update(RayesSession *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    RayesScene *scene = s->scene;
    if (scene->dirty)
        return session_fail(scene, RAYES_ERROR_INVALID_OPERATION,
                            "session: the scene is not committed");
    double t0 = time_now();
    if (scene->stamp_geometry != s->seen_geometry) {
        Prepared *fresh = malloc(sizeof *fresh);
        if (!fresh)
            return session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "session: out of memory");
        RayesError e = session_prepare(scene, &s->set, s->textures, fresh);
        if (e != RAYES_OK) {
            free(fresh);
            return e;
        }
        session_prepared_fini(s->prep);
        free(s->prep);
        s->prep = fresh;
        if (s->cache)
            cache_bump_timestamp(s->cache);
    } else if (scene->stamp_shading != s->seen_shading) {
        RenderObject *objects = session_render_objects(scene);
        if (!objects)
            return session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "session: out of memory");
        free(s->prep->objects);
        s->prep->objects = objects;
        if (s->cache)
            cache_bump_timestamp(s->cache);
    }
    s->prepare_s = time_now() - t0;
    take_stamps(s);
    restart(s);
    return RAYES_OK;
}

static void cache_delta(const CacheStats *before, CacheStats *after)
{
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++) {
            CacheCounters *a = &after->counters[l][t];
            const CacheCounters *b = &before->counters[l][t];
            a->lookups -= b->lookups;
            a->hits -= b->hits;
            a->misses -= b->misses;
            a->fills -= b->fills;
            a->evictions -= b->evictions;
        }
}

RayesError rayes_session_render_pass(RayesSession *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    RayesScene *scene = s->scene;
    if (scene->dirty || scene->stamp_camera != s->seen_camera ||
        scene->stamp_shading != s->seen_shading || scene->stamp_geometry != s->seen_geometry)
        return session_fail(scene, RAYES_ERROR_INVALID_OPERATION,
                            "session: the scene changed; commit and call rayes_session_update");
    double t0 = time_now();
    CacheStats before;
    if (s->cache)
        cache_get_stats(s->cache, &before);
    RenderScene rs = session_render_scene(scene, s->prep, s->set.width, s->set.height);
    RenderStats stats = {0};
    s->set.first_sample = s->samples;
    if (render_frame(&rs, &s->set, s->rgba, &stats) != 0) {
        atomic_store(&s->cancel, 0);
        restart(s);
        return RAYES_ERROR_CANCELLED;
    }
    s->samples++;
    s->pass_stats = stats;
    if (s->cache) {
        cache_get_stats(s->cache, &s->pass_cache);
        cache_delta(&before, &s->pass_cache);
    }
    s->pass_s = time_now() - t0;
    return RAYES_OK;
}

void rayes_session_cancel(RayesSession *s)
{
    if (s)
        atomic_store(&s->cancel, 1);
}

int rayes_session_samples(const RayesSession *s)
{
    return s ? s->samples : 0;
}

RayesError rayes_session_image(const RayesSession *s, RayesImage **image)
{
    if (!s || !image)
        return RAYES_ERROR_INVALID_ARGUMENT;
    size_t bytes = (size_t)s->set.width * s->set.height * 4 * sizeof(float);
    RayesImage *img = malloc(sizeof *img);
    float *rgba = malloc(bytes);
    if (!img || !rgba) {
        free(img);
        free(rgba);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    memcpy(rgba, s->rgba, bytes);
    *img = (RayesImage){s->set.width, s->set.height, rgba};
    *image = img;
    return RAYES_OK;
}

RayesError rayes_session_stats(const RayesSession *s, RayesStats **out)
{
    if (!s || !out)
        return RAYES_ERROR_INVALID_ARGUMENT;
    SessionTimes times = {s->pass_s, 0.0, s->pass_s};
    RayesStats *st = session_stats_new(&s->set, &s->pass_stats, &s->prep->gs, &times,
                                       accel_memory_bytes(s->prep->accel));
    if (!st)
        return RAYES_ERROR_OUT_OF_MEMORY;
    if (s->cache)
        session_stats_add_cache(st, &s->pass_cache);
    session_stats_add_count(st, "session/samples", (uint64_t)s->samples);
    session_stats_add_real(st, "session/prepare_s", s->prepare_s);
    *out = st;
    return RAYES_OK;
}

RayesError rayes_session_pick(const RayesSession *s, float x, float y, int64_t *object,
                              float position[3])
{
    if (!s || !object)
        return RAYES_ERROR_INVALID_ARGUMENT;
    *object = -1;
    thread_set_ftz_daz(); /* as in the workers, so a pick sees what a pass sees */
    RenderScene rs = session_render_scene(s->scene, s->prep, s->set.width, s->set.height);
    Ray ray = render_camera_ray(&rs, s->set.width, s->set.height, x, y);
    Hit hit;
    if (!accel_intersect(s->prep->accel, &ray, &hit))
        return RAYES_OK;
    *object = render_object(&rs, hit.grid, hit.instance) - rs.objects;
    if (position) {
        Vec3 P = v3_madd(ray.o, ray.d, hit.t);
        position[0] = P.x;
        position[1] = P.y;
        position[2] = P.z;
    }
    return RAYES_OK;
}
