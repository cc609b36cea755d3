/*
 * render/render.c — the frame: camera, tiles on the thread pool, pixel
 * samples and the film filter.
 *
 * Film and determinism: a tile owns its pixels and computes every sample
 * that reaches them through the filter, including the samples of a margin
 * of neighbouring pixels (recomputed, not shared: a sample is a pure
 * function of its pixel, index and seed). So a pixel's value never depends
 * on which thread rendered which tile, nor on the order tiles finish.
 * A box filter of width 1 has no margin.
 */
#include "render/render.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "render/hider.h"
#include "render/integrator.h"
#include "render/services.h"
#include "util/check.h"
#include "util/rng.h"
#include "util/thread.h"

Camera render_camera(Vec3 eye, Vec3 x, Vec3 y, Vec3 z, float tan_half_fov, const float screen[4],
                     int height)
{
    Camera c = {.eye = eye, .forward = v3_normalize(z), .x = x, .y = y, .z = z,
                .tan_half_fov = tan_half_fov};
    memcpy(c.screen, screen, sizeof c.screen);
    float pixel = fabsf(screen[3] - screen[2]) / (float)height; /* screen units */
    if (tan_half_fov > 0.0f)
        c.pixel_spread = pixel * tan_half_fov * v3_length(y) / v3_length(z);
    else
        c.pixel_width = pixel * v3_length(y);
    return c;
}

typedef struct Frame {
    const RenderScene *rs;
    const RenderSettings *set;
    float *rgba;
    Worker *workers;
    int tiles_x, tiles_y;     /* over crop */
    int crop[4];              /* the pixels rendered: x0, y0, x1, y1 */
    float radius;             /* filter radius, pixels */
    int margin;               /* pixels of neighbours whose samples reach a tile */
    atomic_int cancelled;
    atomic_size_t tiles_done;
    pthread_mutex_t progress_lock;
} Frame;

/* The Mitchell-Netravali cubic of parameters B and C at |x| in [0, 2]. */
static float mitchell(float x, float B, float C)
{
    x = fabsf(x);
    if (x < 1.0f)
        return ((12 - 9 * B - 6 * C) * x * x * x + (-18 + 12 * B + 6 * C) * x * x + (6 - 2 * B)) /
               6;
    if (x < 2.0f)
        return ((-B - 6 * C) * x * x * x + (6 * B + 30 * C) * x * x + (-12 * B - 48 * C) * x +
                (8 * B + 24 * C)) /
               6;
    return 0.0f;
}

static float sinc(float x)
{
    x *= (float)M_PI;
    return fabsf(x) < 1e-5f ? 1.0f : sinf(x) / x;
}

/* The filter in one dimension at offset x, |x| at most r. */
static float filter_1d(int filter, float x, float r)
{
    switch (filter) {
    case RAYES_FILTER_GAUSSIAN: {
        const float alpha = 2.0f;
        return fmaxf(0.0f, expf(-alpha * x * x) - expf(-alpha * r * r));
    }
    case RAYES_FILTER_TRIANGLE: return fmaxf(0.0f, 1.0f - fabsf(x) / r);
    case RAYES_FILTER_CATMULL_ROM: return mitchell(2.0f * x / r, 0.0f, 0.5f);
    case RAYES_FILTER_MITCHELL: return mitchell(2.0f * x / r, 1.0f / 3.0f, 1.0f / 3.0f);
    case RAYES_FILTER_LANCZOS: return sinc(x) * sinc(x / 3.0f); /* x in pixels, as pbrt's */
    default: return 1.0f;
    }
}

static float filter_weight(const Frame *f, float dx, float dy)
{
    float r = f->radius;
    if (fabsf(dx) > r || fabsf(dy) > r)
        return 0.0f;
    if (f->set->filter == RAYES_FILTER_BOX)
        return 1.0f;
    return filter_1d(f->set->filter, dx, r) * filter_1d(f->set->filter, dy, r);
}

Ray render_camera_ray(const RenderScene *rs, int width, int height, float x, float y)
{
    const Camera *c = &rs->camera;
    float sx = c->screen[0] + (c->screen[1] - c->screen[0]) * x / (float)width;
    float sy = c->screen[3] - (c->screen[3] - c->screen[2]) * y / (float)height;
    Vec3 across = v3_add(v3_scale(c->x, sx), v3_scale(c->y, sy));
    if (c->tan_half_fov > 0.0f) {
        Vec3 d = v3_normalize(v3_add(c->z, v3_scale(across, c->tan_half_fov)));
        return (Ray){c->eye, d, 0.0f, INFINITY, RAYES_RAY_CAMERA};
    }
    return (Ray){v3_add(c->eye, across), c->forward, 0.0f, INFINITY, RAYES_RAY_CAMERA};
}

/* All samples of pixel (px, py), splatted into the tile's accumulators. */
static void render_pixel(Frame *f, Worker *w, int px, int py, int x0, int y0, int tw, int th,
                         float (*acc)[5])
{
    const RenderSettings *set = f->set;
    uint64_t pixel_key = hash_combine(hash_combine(set->seed, (uint64_t)py), (uint64_t)px);
    uint32_t pattern = (uint32_t)hash_combine(pixel_key, DIM_PIXEL);
    RayDiff diff = {f->rs->camera.pixel_width, f->rs->camera.pixel_spread};
    uint32_t n = (uint32_t)(set->pattern_spp > 0 ? set->pattern_spp : set->spp);
    for (int k = 0; k < set->spp; k++) {
        uint32_t s = (uint32_t)(set->first_sample + k), block = s / n;
        float jx, jy;
        cmj_sample_2d(s % n, n, block ? (uint32_t)hash_combine(pattern, block) : pattern, &jx, &jy);
        float x = (float)px + jx, y = (float)py + jy;
        Ray ray = render_camera_ray(f->rs, set->width, set->height, x, y);
        float alpha;
        w->stats.rays_camera++;
        Vec3 L = integrator_trace(w, &ray, RAYES_RAY_CAMERA, 0, 0,
                                  hash_combine(pixel_key, (uint64_t)s + 1), diff, &alpha);
        for (int qy = RY_MAX(py - f->margin, y0); qy <= RY_MIN(py + f->margin, y0 + th - 1); qy++)
            for (int qx = RY_MAX(px - f->margin, x0); qx <= RY_MIN(px + f->margin, x0 + tw - 1);
                 qx++) {
                float wgt = filter_weight(f, x - ((float)qx + 0.5f), y - ((float)qy + 0.5f));
                if (wgt == 0.0f)
                    continue; /* negative lobes count */
                float *a = acc[(qy - y0) * tw + (qx - x0)];
                a[0] += wgt * L.x;
                a[1] += wgt * L.y;
                a[2] += wgt * L.z;
                a[3] += wgt * alpha;
                a[4] += wgt;
            }
    }
}

static void report_progress(Frame *f)
{
    size_t done = atomic_fetch_add(&f->tiles_done, 1) + 1;
    if (!f->set->progress)
        return;
    pthread_mutex_lock(&f->progress_lock);
    double fraction = (double)done / (double)((size_t)f->tiles_x * f->tiles_y);
    if (f->set->progress(f->set->progress_user, fraction))
        atomic_store(&f->cancelled, 1);
    pthread_mutex_unlock(&f->progress_lock);
}

static void render_tile(void *ctx, size_t task, int worker)
{
    Frame *f = ctx;
    const RenderSettings *set = f->set;
    if (set->cancel && atomic_load(set->cancel))
        atomic_store(&f->cancelled, 1);
    if (atomic_load(&f->cancelled))
        return;
    if (set->tile_source) { /* the caller's choice of tile, in place of task */
        pthread_mutex_lock(&f->progress_lock);
        int t = set->tile_source(set->tile_source_user, f->tiles_x, f->tiles_y);
        pthread_mutex_unlock(&f->progress_lock);
        if (t < 0 || (size_t)t >= (size_t)f->tiles_x * f->tiles_y)
            return;
        task = (size_t)t;
    }
    int ts = set->tile_size;
    int x0 = f->crop[0] + (int)(task % (size_t)f->tiles_x) * ts;
    int y0 = f->crop[1] + (int)(task / (size_t)f->tiles_x) * ts;
    int tw = RY_MIN(ts, f->crop[2] - x0), th = RY_MIN(ts, f->crop[3] - y0);
    float(*acc)[5] = calloc((size_t)tw * th, sizeof *acc);
    RY_CHECK(acc != NULL);
    if (set->accum)
        for (int y = 0; y < th; y++)
            memcpy(acc[y * tw], set->accum[(size_t)(y0 + y) * set->width + x0], sizeof *acc * tw);
    Worker *w = &f->workers[worker];
    for (int py = RY_MAX(y0 - f->margin, 0); py < RY_MIN(y0 + th + f->margin, set->height); py++)
        for (int px = RY_MAX(x0 - f->margin, 0); px < RY_MIN(x0 + tw + f->margin, set->width); px++)
            render_pixel(f, w, px, py, x0, y0, tw, th, acc);
    for (int y = 0; y < th; y++)
        for (int x = 0; x < tw; x++) {
            const float *a = acc[y * tw + x];
            float *out = &f->rgba[4 * ((size_t)(y0 + y) * set->width + (x0 + x))];
            float inv = a[4] > 0.0f ? 1.0f / a[4] : 0.0f;
            for (int c = 0; c < 4; c++)
                out[c] = a[c] * inv;
            out[3] = fminf(fmaxf(out[3], 0.0f), 1.0f); /* coverage, rung by negative lobes */
        }
    if (set->accum)
        for (int y = 0; y < th; y++)
            memcpy(set->accum[(size_t)(y0 + y) * set->width + x0], acc[y * tw], sizeof *acc * tw);
    free(acc);
    if (set->tile_done)
        set->tile_done(set->tile_user, x0, y0, tw, th, f->rgba, set->width);
    report_progress(f);
}

static void merge_stats(RenderStats *into, const RenderStats *s)
{
    into->rays_camera += s->rays_camera;
    into->rays_shadow += s->rays_shadow;
    into->rays_diffuse += s->rays_diffuse;
    into->rays_specular += s->rays_specular;
    into->irradiance_records += s->irradiance_records;
    into->irradiance_interpolated += s->irradiance_interpolated;
    for (int d = 0; d <= RENDER_MAX_DEPTH; d++)
        into->shading_points[d] += s->shading_points[d];
    into->ambient_lookups += s->ambient_lookups;
    into->opacity_points += s->opacity_points;
    into->transparent_hits += s->transparent_hits;
    into->rays_transmission += s->rays_transmission;
    into->volume_steps += s->volume_steps;
    into->rays_subsurface += s->rays_subsurface;
    into->subsurface_points += s->subsurface_points;
    into->irradiance_points += s->irradiance_points;
    into->instance_fills += s->instance_fills;
}

int render_frame(const RenderScene *rs, const RenderSettings *set, float *rgba, RenderStats *stats)
{
    int threads = set->threads > 0 ? set->threads : thread_count_cores();
    Frame f = {.rs = rs, .set = set, .rgba = rgba};
    /* Tiles over the crop window (the whole frame without one): a pixel's
     * samples and its filter's neighbours do not depend on its tile. */
    int whole[4] = {0, 0, set->width, set->height};
    const int *c = set->crop[2] > set->crop[0] && set->crop[3] > set->crop[1] ? set->crop : whole;
    memcpy(f.crop, c, sizeof f.crop);
    f.tiles_x = (f.crop[2] - f.crop[0] + set->tile_size - 1) / set->tile_size;
    f.tiles_y = (f.crop[3] - f.crop[1] + set->tile_size - 1) / set->tile_size;
    f.radius = 0.5f * set->filter_width;
    f.margin = RY_MAX((int)ceilf(f.radius + 0.5f) - 1, 0);
    atomic_init(&f.cancelled, 0);
    atomic_init(&f.tiles_done, 0);
    pthread_mutex_init(&f.progress_lock, NULL);
    f.workers = calloc((size_t)threads, sizeof *f.workers);
    RY_CHECK(f.workers != NULL);
    GridShading *gsh = NULL;
    if (set->hider == 1) {
        gsh = hider_new(rs, set);
        RY_CHECK(gsh != NULL);
    }
    for (int i = 0; i < threads; i++) {
        f.workers[i] = (Worker){.rs = rs, .set = set, .grid_shading = gsh,
                                .services = &render_services};
        if (set->cache)
            cache_local_init(&f.workers[i].cache, set->cache);
    }
    if (!set->accum)
        memset(rgba, 0, sizeof(float) * 4 * (size_t)set->width * set->height);
    thread_parallel_for(threads, (size_t)f.tiles_x * f.tiles_y, render_tile, &f);
    for (int i = 0; i < threads; i++) {
        merge_stats(stats, &f.workers[i].stats);
        if (set->cache)
            cache_local_fini(&f.workers[i].cache);
    }
    free(f.workers);
    hider_free(gsh);
    pthread_mutex_destroy(&f.progress_lock);
    return atomic_load(&f.cancelled) ? 1 : 0;
}
