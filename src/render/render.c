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

#include "render/envguide.h"
#include "render/hider.h"
#include "render/integrator.h"
#include "render/optable.h"
#include "render/services.h"
#include "util/check.h"
#include "util/rng.h"
#include "util/sampling.h"
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
    int adaptive;             /* adaptive sampling (RenderSettings.max_spp) */
    double frame_mean;        /* adaptive sampling: the frame's mean luminance (estimated) */
    int margin;               /* pixels of neighbours whose samples reach a tile */
    int aov_channels;         /* rayes_aov_channels(set->aovs) */
    float **aov_acc;          /* per worker, its tile's AOV sums (AOV_ACC floats a pixel), or
                                 NULL: no AOVs */
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
    case RAYES_FILTER_CATMULL_ROM: /* RenderMan's: the cubic in pixels, windowed by the width
                                      (not stretched to it: a width of 1 keeps its middle) */
        return mitchell(x, 0.0f, 0.5f);
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

/* The camera's eye and axes at time t: blended linearly between its
 * motion samples (clamped), or the still camera. */
static void camera_at(const Camera *c, float t, Vec3 *eye, Vec3 *x, Vec3 *y, Vec3 *z)
{
    *eye = c->eye, *x = c->x, *y = c->y, *z = c->z;
    if (c->n_motion < 2)
        return;
    int k = 0;
    while (k + 2 < c->n_motion && t >= c->motion_time[k + 1])
        k++;
    float f = (t - c->motion_time[k]) / (c->motion_time[k + 1] - c->motion_time[k]);
    f = f < 0.0f ? 0.0f : f > 1.0f ? 1.0f : f;
    *eye = v3_lerp(c->motion_eye[k], c->motion_eye[k + 1], f);
    *x = v3_lerp(c->motion_x[k], c->motion_x[k + 1], f);
    *y = v3_lerp(c->motion_y[k], c->motion_y[k + 1], f);
    *z = v3_lerp(c->motion_z[k], c->motion_z[k + 1], f);
}

Ray render_camera_ray_at(const RenderScene *rs, int width, int height, float px, float py,
                         float time, float lu, float lv, float *lens, float *focus)
{
    const Camera *c = &rs->camera;
    Vec3 eye, x, y, z;
    camera_at(c, time, &eye, &x, &y, &z);
    Vec3 forward = v3_normalize(z);
    float sx = c->screen[0] + (c->screen[1] - c->screen[0]) * px / (float)width;
    float sy = c->screen[3] - (c->screen[3] - c->screen[2]) * py / (float)height;
    Vec3 across = v3_add(v3_scale(x, sx), v3_scale(y, sy));
    Ray ray = c->tan_half_fov > 0.0f
                  ? (Ray){eye, v3_normalize(v3_add(z, v3_scale(across, c->tan_half_fov))), 0.0f,
                          INFINITY, RAYES_RAY_CAMERA, time}
                  : (Ray){v3_add(eye, across), forward, 0.0f, INFINITY, RAYES_RAY_CAMERA, time};
    *lens = *focus = 0.0f;
    if (!(c->lens_radius > 0.0f))
        return ray;
    /* A thin lens: every ray through the pixel position meets the pinhole
     * ray on the plane of focus, focal_distance along the view; the lens
     * is the disk of lens_radius about the pinhole across the view. */
    float along = c->focal_distance / v3_dot(ray.d, forward);
    Vec3 F = v3_madd(ray.o, ray.d, along);
    float dx, dy;
    sample_concentric_disk(lu, lv, &dx, &dy);
    Vec3 o = v3_add(ray.o, v3_add(v3_scale(v3_normalize(x), c->lens_radius * dx),
                                  v3_scale(v3_normalize(y), c->lens_radius * dy)));
    Vec3 d = v3_sub(F, o);
    ray.o = o;
    *focus = v3_length(d);
    ray.d = v3_scale(d, 1.0f / *focus);
    *lens = 2.0f * c->lens_radius;
    return ray;
}

Ray render_camera_ray(const RenderScene *rs, int width, int height, float x, float y)
{
    float lens, focus;
    return render_camera_ray_at(rs, width, height, x, y, rs->camera.shutter[0], 0.5f, 0.5f, &lens,
                                &focus);
}

/* Adaptive pixel sampling (RenderSettings.max_spp): whether a pixel's
 * samples so far, n of luminance sum y and sum of squares y2, estimate
 * its mean within the standard error asked: adaptive_error times the
 * pixel's mean, or times the frame's mean if that is less (a pixel
 * brighter than the frame's mean is held to the frame's absolute error:
 * a light's edge or a highlight, noisy by a few percent of its own value,
 * dominated the image's error and stopped it near 2.4% on
 * cornell-teapots). The variance is at least floor times the mean
 * squared: the largest relative variance of the first blocks of the
 * pixel and its 3 x 3 neighbours (render_adaptive), so that a pixel whose
 * first samples all missed a rare bright path its neighbours found (a
 * small highlight, a light's thin edge) keeps sampling rather than
 * stopping with no variance seen. All of it depends on samples of fixed
 * pixels, whichever tile (or margin) computes them, and on the frame's
 * mean, estimated once from the whole frame whatever the crop: the image
 * stays deterministic. */
static int pixel_converged(const Frame *f, int n, double y, double y2, double floor)
{
    double mean = y / n, var = (y2 - y * mean) / (n > 1 ? n - 1 : 1);
    if (!(mean > 0.0))
        return 1; /* black (or negative-lobed) so far: nothing to refine */
    var = fmax(var, floor * mean * mean);
    double scale = f->frame_mean > 0.0 ? fmin(mean, f->frame_mean) : mean;
    return sqrt(fmax(var, 0.0) / n) <= (double)f->set->adaptive_error * scale;
}

/* The relative variance (variance over mean squared) of n samples of
 * luminance sum y and sum of squares y2; 0 for a black pixel. */
static double relative_variance(int n, double y, double y2)
{
    double mean = y / n, var = (y2 - y * mean) / (n > 1 ? n - 1 : 1);
    return mean > 0.0 ? fmax(var, 0.0) / (mean * mean) : 0.0;
}

/* A tile pixel's AOV sums: the nearest sample's z, id and patch (among
 * those the filter weighs positively; the first of equals), the cache
 * levels and look-ups of those samples, then w N, w P and w albedo summed
 * as colours are. */
enum {
    AOV_Z,
    AOV_ID,
    AOV_PATCH,
    AOV_LEVELS,
    AOV_LOOKUPS,
    AOV_N,
    AOV_P = AOV_N + 3,
    AOV_ALBEDO = AOV_P + 3,
    AOV_ACC = AOV_ALBEDO + 3
};

static void aov_splat(float *a, const AovSample *s, float wgt)
{
    if (!s->set)
        return;
    if (wgt > 0.0f && s->z < a[AOV_Z]) {
        a[AOV_Z] = s->z;
        a[AOV_ID] = (float)s->id;
        a[AOV_PATCH] = (float)s->patch;
    }
    if (wgt > 0.0f) {
        a[AOV_LEVELS] += s->levels;
        a[AOV_LOOKUPS] += (float)s->lookups;
    }
    const float v[9] = {s->N.x, s->N.y,      s->N.z,      s->P.x,     s->P.y,
                        s->P.z, s->albedo.x, s->albedo.y, s->albedo.z};
    for (int c = 0; c < 9; c++)
        a[AOV_N + c] += wgt * v[c];
}

/* The tile's AOVs into the frame's (RenderSettings.aov), channels in the
 * order of the bits (rayes_aov_channel_name). */
static void aov_write(const Frame *f, const float *acc5, const float *a, float *out)
{
    unsigned aovs = f->set->aovs;
    float inv = acc5[4] > 0.0f ? 1.0f / acc5[4] : 0.0f;
    int c = 0;
    if (aovs & RAYES_AOV_Z)
        out[c++] = a[AOV_Z];
    for (int k = 0; k < 3 && (aovs & RAYES_AOV_N); k++)
        out[c++] = a[AOV_N + k] * inv;
    for (int k = 0; k < 3 && (aovs & RAYES_AOV_P); k++)
        out[c++] = a[AOV_P + k] * inv;
    if (aovs & RAYES_AOV_ID)
        out[c++] = a[AOV_ID];
    if (aovs & RAYES_AOV_PATCH)
        out[c++] = a[AOV_PATCH];
    if (aovs & RAYES_AOV_CACHE)
        out[c++] = a[AOV_LOOKUPS] > 0.0f ? a[AOV_LEVELS] / a[AOV_LOOKUPS] : -1.0f;
    for (int k = 0; k < 3 && (aovs & RAYES_AOV_ALBEDO); k++)
        out[c++] = a[AOV_ALBEDO + k] * inv;
}

/* Samples k0 to k1 - 1 of pixel (px, py), splatted into the tile's
 * accumulators when splat is set (with adaptive sampling, the first block
 * of a pixel just outside the filter's reach is taken for its variance
 * only), their luminance added to *lum and *lum2. Sample s of a pixel is
 * in block s / spp, each block its own CMJ pattern (as a progressive
 * session's passes); with adaptive sampling its position is the s-th of
 * the pixel's one Sobol sequence instead (its time and lens position
 * keep the block's patterns). */
static void render_samples(Frame *f, Worker *w, int px, int py, int x0, int y0, int tw, int th,
                           float (*acc)[5], int k0, int k1, int splat, double *lum, double *lum2)
{
    const RenderSettings *set = f->set;
    uint64_t pixel_key = hash_combine(hash_combine(set->seed, (uint64_t)py), (uint64_t)px);
    uint32_t pattern = (uint32_t)hash_combine(pixel_key, DIM_PIXEL);
    const Camera *cam = &f->rs->camera;
    uint32_t n = (uint32_t)(set->pattern_spp > 0 ? set->pattern_spp : set->spp);
    /* the block's patterns, their shuffles tabled once for its samples */
    CmjPattern pixel_pat, lens_pat;
    uint32_t pat_block = UINT32_MAX;
    for (int k = k0; k < k1; k++) {
        uint32_t s = (uint32_t)(set->first_sample + k), block = s / n;
        uint32_t p = block ? (uint32_t)hash_combine(pattern, block) : pattern;
        float jx, jy, lu = 0.5f, lv = 0.5f, time = cam->shutter[0];
        if (block != pat_block) {
            if (!f->adaptive)
                cmj_pattern_init(&pixel_pat, n, p);
            if (cam->lens_radius > 0.0f)
                cmj_pattern_init(&lens_pat, n, (uint32_t)hash_combine(p, DIM_LENS));
            pat_block = block;
        }
        if (f->adaptive) /* stratified over all the blocks a pixel takes */
            sobol_owen_2d(s, pattern, &jx, &jy);
        else
            cmj_pattern_sample(&pixel_pat, s % n, &jx, &jy);
        /* Time and lens position: stratified over the same n samples, with
         * patterns of their own (DESIGN.md "Sampling and determinism"). */
        if (cam->shutter[1] > cam->shutter[0])
            time += (cam->shutter[1] - cam->shutter[0]) *
                    stratified_1d(s % n, n, (uint32_t)hash_combine(p, DIM_TIME));
        if (cam->lens_radius > 0.0f)
            cmj_pattern_sample(&lens_pat, s % n, &lu, &lv);
        float x = (float)px + jx, y = (float)py + jy;
        RayDiff diff = {cam->pixel_width, cam->pixel_spread, 0.0f, 0.0f};
        Ray ray = render_camera_ray_at(f->rs, set->width, set->height, x, y, time, lu, lv,
                                       &diff.lens, &diff.focus);
        /* The pixel's estimate averages n rays over the lens: each ray stands
         * for 1/sqrt(n) of the defocus beam's width (as pbrt scales camera
         * differentials by 1/sqrt(spp)); the whole beam let corners read
         * the coarse resolution and biased dark tiles by 8% (test_dof.c). */
        diff.lens /= sqrtf((float)n);
        float alpha;
        w->stats.rays_camera++;
        AovSample aov = {0};
        float *aov_acc = f->aov_acc ? f->aov_acc[w - f->workers] : NULL;
        w->aov = aov_acc ? &aov : NULL;
        Vec3 L = integrator_trace(w, &ray, RAYES_RAY_CAMERA, 0, 0,
                                  hash_combine(pixel_key, (uint64_t)s + 1), diff, &alpha);
        w->aov = NULL;
        float top = fmaxf(L.x, fmaxf(L.y, L.z));
        if (set->sample_clamp > 0.0f && top > set->sample_clamp) /* as pbrt-v4's film does */
            L = v3_scale(L, set->sample_clamp / top);
        double yl = 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
        *lum += yl;
        *lum2 += yl * yl;
        if (!splat)
            continue;
        for (int qy = RY_MAX(py - f->margin, y0); qy <= RY_MIN(py + f->margin, y0 + th - 1); qy++)
            for (int qx = RY_MAX(px - f->margin, x0); qx <= RY_MIN(px + f->margin, x0 + tw - 1);
                 qx++) {
                float wgt = filter_weight(f, x - ((float)qx + 0.5f), y - ((float)qy + 0.5f));
                if (wgt == 0.0f)
                    continue; /* negative lobes count */
                float *a = acc[(qy - y0) * tw + (qx - x0)];
                if (aov_acc)
                    aov_splat(&aov_acc[AOV_ACC * (size_t)((qy - y0) * tw + (qx - x0))], &aov, wgt);
                a[0] += wgt * L.x;
                a[1] += wgt * L.y;
                a[2] += wgt * L.z;
                a[3] += wgt * alpha;
                a[4] += wgt;
            }
    }
}

/* Adaptive sampling of the pixels [ex0, ex1) x [ey0, ey1) whose samples
 * reach the tile (x0, y0, tw, th): the first block (spp samples) of each
 * and of a ring of one pixel more, whose relative variances give each
 * pixel its floor (the largest of its 3 x 3 neighbourhood's, inside the
 * image); then further blocks of the pixel until pixel_converged or
 * max_spp. The ring's first blocks are recomputed by each tile beside it,
 * as margins are: a pixel's decision never depends on its tile. */
static void render_adaptive(Frame *f, Worker *w, int ex0, int ey0, int ex1, int ey1, int x0,
                            int y0, int tw, int th, float (*acc)[5])
{
    const RenderSettings *set = f->set;
    int rx0 = RY_MAX(ex0 - 1, 0), ry0 = RY_MAX(ey0 - 1, 0);
    int rx1 = RY_MIN(ex1 + 1, set->width), ry1 = RY_MIN(ey1 + 1, set->height);
    int rw = rx1 - rx0, rh = ry1 - ry0;
    double *sums = malloc(sizeof *sums * 3 * (size_t)rw * rh); /* lum, lum2, relative variance */
    RY_CHECK(sums != NULL);
    for (int py = ry0; py < ry1; py++)
        for (int px = rx0; px < rx1; px++) {
            double *s = &sums[3 * ((size_t)(py - ry0) * rw + (px - rx0))];
            int reach = px >= ex0 && px < ex1 && py >= ey0 && py < ey1;
            s[0] = s[1] = 0.0;
            render_samples(f, w, px, py, x0, y0, tw, th, acc, 0, set->spp, reach, &s[0], &s[1]);
            s[2] = relative_variance(set->spp, s[0], s[1]);
        }
    for (int py = ey0; py < ey1; py++)
        for (int px = ex0; px < ex1; px++) {
            double floor = 0.0;
            for (int qy = RY_MAX(py - 1, ry0); qy <= RY_MIN(py + 1, ry1 - 1); qy++)
                for (int qx = RY_MAX(px - 1, rx0); qx <= RY_MIN(px + 1, rx1 - 1); qx++)
                    floor = fmax(floor, sums[3 * ((size_t)(qy - ry0) * rw + (qx - rx0)) + 2]);
            double *s = &sums[3 * ((size_t)(py - ry0) * rw + (px - rx0))];
            int k = set->spp;
            while (k < set->max_spp && !pixel_converged(f, k, s[0], s[1], floor)) {
                int next = RY_MIN(k + set->spp, set->max_spp);
                render_samples(f, w, px, py, x0, y0, tw, th, acc, k, next, 1, &s[0], &s[1]);
                k = next;
            }
            if (k == set->max_spp && px >= x0 && px < x0 + tw && py >= y0 && py < y0 + th)
                w->stats.adaptive_pixels_max++; /* counted by the pixel's own tile */
        }
    free(sums);
}

/* Adaptive sampling's frame mean: the mean luminance of FRAME_SAMPLES^2
 * camera samples stratified over the whole frame (not the crop window),
 * each its own key: one number, the same whatever the threads, tiles or
 * crop. A few thousand samples: noisy by a few percent where a small
 * bright light is seen, which only moves the threshold of the brightest
 * pixels by as much. */
#define FRAME_SAMPLES 64
static double frame_mean(Frame *f, Worker *w)
{
    const RenderSettings *set = f->set;
    const Camera *cam = &f->rs->camera;
    uint64_t key = hash_combine(set->seed, DIM_FRAME);
    double sum = 0.0;
    for (int j = 0; j < FRAME_SAMPLES; j++)
        for (int i = 0; i < FRAME_SAMPLES; i++) {
            uint64_t k = hash_combine(key, (uint64_t)(j * FRAME_SAMPLES + i));
            float x = ((float)i + rng_float(hash_combine(k, 0))) * (float)set->width;
            float y = ((float)j + rng_float(hash_combine(k, 1))) * (float)set->height;
            x /= FRAME_SAMPLES, y /= FRAME_SAMPLES;
            float lens, focus, alpha;
            RayDiff diff = {cam->pixel_width, cam->pixel_spread, 0.0f, 0.0f};
            Ray ray = render_camera_ray_at(f->rs, set->width, set->height, x, y,
                                           cam->shutter[0], 0.5f, 0.5f, &lens, &focus);
            w->stats.rays_camera++;
            Vec3 L = integrator_trace(w, &ray, RAYES_RAY_CAMERA, 0, 0, hash_combine(k, 2), diff,
                                      &alpha);
            sum += 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
        }
    return sum / (FRAME_SAMPLES * FRAME_SAMPLES);
}

/* The environment guides' pixel counts (Worker.guide_pixels): the pixels
 * of the whole frame (not the crop window: the same guides for every crop
 * and machine) whose centre's camera ray first meets each guide patch,
 * counted by atomic adds (the same sums in any order). */
typedef struct CountJob {
    const RenderScene *rs;
    const RenderSettings *set;
    uint32_t *count;
} CountJob;

static void count_row(void *ctx, size_t row, int worker)
{
    (void)worker;
    const CountJob *job = ctx;
    const RenderScene *rs = job->rs;
    const Camera *cam = &rs->camera;
    float time = 0.5f * (cam->shutter[0] + cam->shutter[1]);
    for (int x = 0; x < job->set->width; x++) {
        float lens, focus;
        Ray ray = render_camera_ray_at(rs, job->set->width, job->set->height, (float)x + 0.5f,
                                       (float)row + 0.5f, time, 0.5f, 0.5f, &lens, &focus);
        Hit hit;
        if (accel_intersect(rs->accel, &ray, &hit) && hit.grid < rs->gs->n_grids)
            __atomic_fetch_add(&job->count[envguide_patch(rs->gs, hit.grid)], 1u, __ATOMIC_RELAXED);
    }
}

/* The counts, or NULL where no guide is drawn by them (off, uncached, the
 * grid hider's vertices count instead, or no environment light that casts
 * shadows). */
static uint32_t *guide_pixels(const RenderScene *rs, const RenderSettings *set, int threads)
{
    if (!set->env_guide || !set->cache || set->hider == 1)
        return NULL;
    int any = 0;
    for (size_t k = 0; k < rs->n_lights; k++)
        any |= rs->lights[k].type == LIGHT_ENVIRONMENT && !rs->lights[k].shadowless;
    if (!any)
        return NULL;
    uint32_t *count = calloc(rs->gs->n_grids + rs->gs->n_clusters, sizeof *count);
    RY_CHECK(count != NULL);
    CountJob job = {rs, set, count};
    thread_parallel_for(threads, (size_t)set->height, count_row, &job);
    return count;
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

/* Whether the frame was stopped (RenderSettings.stop): then cancelled. */
static int stopped(Frame *f)
{
    if (!render_stop_requested(f->set))
        return 0;
    atomic_store(&f->cancelled, 1);
    return 1;
}

static void render_tile(void *ctx, size_t task, int worker)
{
    Frame *f = ctx;
    const RenderSettings *set = f->set;
    stopped(f);
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
    float *aov_acc = NULL;
    if (f->aov_acc) {
        aov_acc = malloc(sizeof *aov_acc * AOV_ACC * (size_t)tw * th);
        RY_CHECK(aov_acc != NULL);
        for (size_t i = 0; i < (size_t)tw * th; i++) {
            memset(&aov_acc[AOV_ACC * i], 0, sizeof *aov_acc * AOV_ACC);
            aov_acc[AOV_ACC * i + AOV_Z] = INFINITY;
        }
        f->aov_acc[worker] = aov_acc;
    }
    int ex0 = RY_MAX(x0 - f->margin, 0), ex1 = RY_MIN(x0 + tw + f->margin, set->width);
    int ey0 = RY_MAX(y0 - f->margin, 0), ey1 = RY_MIN(y0 + th + f->margin, set->height);
    if (f->adaptive)
        render_adaptive(f, w, ex0, ey0, ex1, ey1, x0, y0, tw, th, acc);
    else
        for (int py = ey0; py < ey1; py++)
            for (int px = ex0; px < ex1; px++) {
                double lum = 0.0, lum2 = 0.0;
                render_samples(f, w, px, py, x0, y0, tw, th, acc, 0, set->spp, 1, &lum, &lum2);
            }
    if (stopped(f)) { /* its rays came back black somewhere: abandoned */
        free(acc);
        free(aov_acc);
        return;
    }
    for (int y = 0; y < th; y++)
        for (int x = 0; x < tw; x++) {
            const float *a = acc[y * tw + x];
            float *out = &f->rgba[4 * ((size_t)(y0 + y) * set->width + (x0 + x))];
            float inv = a[4] > 0.0f ? 1.0f / a[4] : 0.0f;
            for (int c = 0; c < 4; c++)
                out[c] = a[c] * inv;
            out[3] = fminf(fmaxf(out[3], 0.0f), 1.0f); /* coverage, rung by negative lobes */
            if (aov_acc)
                aov_write(f, a, &aov_acc[AOV_ACC * (size_t)(y * tw + x)],
                          &set->aov[(size_t)f->aov_channels *
                                    ((size_t)(y0 + y) * set->width + (x0 + x))]);
        }
    free(aov_acc);
    if (set->accum)
        for (int y = 0; y < th; y++)
            memcpy(set->accum[(size_t)(y0 + y) * set->width + x0], acc[y * tw], sizeof *acc * tw);
    free(acc);
    if (set->tile_aov_done && set->aov)
        set->tile_aov_done(set->tile_user, x0, y0, tw, th, set->aov, f->aov_channels, set->width);
    if (set->tile_done)
        set->tile_done(set->tile_user, x0, y0, tw, th, f->rgba, set->width);
    report_progress(f);
}

static void merge_stats(RenderStats *into, const RenderStats *s)
{
    into->rays_camera += s->rays_camera;
    into->adaptive_pixels_max += s->adaptive_pixels_max;
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
    into->holes += s->holes;
    into->hole_points += s->hole_points;
    into->table_lookups += s->table_lookups;
    into->table_fills += s->table_fills;
    into->rays_transmission += s->rays_transmission;
    into->volume_steps += s->volume_steps;
    into->rays_subsurface += s->rays_subsurface;
    into->subsurface_points += s->subsurface_points;
    into->irradiance_points += s->irradiance_points;
    into->instance_fills += s->instance_fills;
    into->cluster_lookups += s->cluster_lookups;
    into->pbgi_gathers += s->pbgi_gathers;
    for (int k = 0; k < GEOM_MAX_TIMES - 1; k++)
        into->segment_fills[k] += s->segment_fills[k];
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
    f.workers = aligned_alloc(WORKER_ALIGN, (size_t)threads * sizeof *f.workers);
    RY_CHECK(f.workers != NULL);
    memset(f.workers, 0, (size_t)threads * sizeof *f.workers);
    GridShading *gsh = NULL;
    if (set->hider == 1) {
        gsh = hider_new(rs, set);
        RY_CHECK(gsh != NULL);
    }
    OpacityTable *optable = NULL;
    if (set->cache && set->opacity_cache) {
        CacheStats cst;
        cache_get_stats(set->cache, &cst);
        optable = optable_new(rs, cst.type_budget_bytes[CACHE_OPACITY]);
    }
    uint32_t *pixels = guide_pixels(rs, set, threads);
    for (int i = 0; i < threads; i++) {
        f.workers[i] = (Worker){.split = 1.0f,
                                .rs = rs,
                                .set = set,
                                .grid_shading = gsh,
                                .opacity_table = optable,
                                .services = &render_services,
                                .albedo_services = &albedo_services,
                                .guide_pixels = pixels};
        if (set->cache)
            cache_local_init(&f.workers[i].cache, set->cache);
    }
    if (!set->accum)
        memset(rgba, 0, sizeof(float) * 4 * (size_t)set->width * set->height);
    if (set->aovs && set->aov && !set->accum) {
        f.aov_channels = rayes_aov_channels(set->aovs);
        memset(set->aov, 0, sizeof(float) * (size_t)f.aov_channels * set->width * set->height);
        f.aov_acc = calloc((size_t)threads, sizeof *f.aov_acc);
        RY_CHECK(f.aov_acc != NULL);
    }
    f.adaptive = set->max_spp > set->spp && !set->accum;
    if (f.adaptive)
        f.frame_mean = frame_mean(&f, &f.workers[0]);
    thread_parallel_for(threads, (size_t)f.tiles_x * f.tiles_y, render_tile, &f);
    for (int i = 0; i < threads; i++) {
        merge_stats(stats, &f.workers[i].stats);
        if (set->cache)
            cache_local_fini(&f.workers[i].cache);
    }
    stats->table_bytes = RY_MAX(stats->table_bytes, optable_bytes(optable));
    free(f.workers);
    free(f.aov_acc);
    free(pixels);
    hider_free(gsh);
    optable_free(optable);
    pthread_mutex_destroy(&f.progress_lock);
    return atomic_load(&f.cancelled) ? 1 : 0;
}
