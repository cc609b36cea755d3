/*
 * bench/figure9.c — the memo's Figure 9 (section 6.1): illumination and
 * shadows in an inhomogeneous volume whose extinction is a turbulence
 * function of five octaves of noise, rendered with opacity caching off
 * and on in one run (memo: 49 M transmission rays, 20 min without caching
 * and 4.7 min with, 4.3x).
 *
 * The scene: the built-in `turbulence` medium in a box over a floor, lit
 * by a spot light from above and to the side, so the cloud is lit on one
 * side, shadows itself and casts a shadow on the floor. Camera rays march
 * the cloud (single scattering: shadow rays at every step, through the
 * medium), the floor's shadow rays march it too.
 *
 *   figure9 [--size 128] [--spp 4] [--shadow-rays 4] [--threads 2] [--opacity-mb 20]
 *           [--out DIR]
 *
 * Prints rays, extinction shader evaluations, times off/on and the
 * speed-up, cache hit rates, the difference of the image means and the
 * worst 32 x 32 tile, whether the cached image is the same with 1 thread
 * and with a tiny opacity budget; writes DIR/figure9-{cached,uncached,
 * diff20}.png.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "image/image.h"
#include "rayes/rayes.h"

typedef struct Args {
    int size, spp, shadow_rays, threads;
    double opacity_mb;
    const char *out;
} Args;

static void die(const char *msg)
{
    fprintf(stderr, "figure9: %s\n", msg);
    exit(2);
}

static int parse_int(const char *s, int lo, int hi)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (*end || v < lo || v > hi)
        die("expected an integer in range");
    return (int)v;
}

static Args parse(int argc, char **argv)
{
    Args a = {128, 4, 4, 2, 20.0, "out/figure9"};
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            die("an option lacks its value");
        if (!strcmp(o, "--size"))
            a.size = parse_int(v, 16, 4096);
        else if (!strcmp(o, "--spp"))
            a.spp = parse_int(v, 1, 1 << 16);
        else if (!strcmp(o, "--shadow-rays"))
            a.shadow_rays = parse_int(v, 1, 1 << 12);
        else if (!strcmp(o, "--threads"))
            a.threads = parse_int(v, 0, 1024);
        else if (!strcmp(o, "--opacity-mb"))
            a.opacity_mb = parse_int(v, 0, 100000);
        else if (!strcmp(o, "--out"))
            a.out = v;
        else
            die("usage: figure9 [--size N] [--spp N] [--shadow-rays N] [--threads N] "
                "[--opacity-mb MB] [--out DIR]");
        i++;
    }
    return a;
}

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static RayesParam pc(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

static RayesScene *scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1.6f, 6.5f}, at[3] = {0, 1.1f, 0}, up[3] = {0, 1, 0};
    if (rayes_scene_set_camera(s, eye, at, up, 38.0f) != RAYES_OK)
        die(rayes_scene_get_error(s));
    RayesParam m[1] = {pf("Ka", 0.0f)};
    rayes_scene_set_shader(s, "matte", m, 1);
    const float P[4][3] = {{-6, 0, -6}, {6, 0, -6}, {-6, 0, 6}, {6, 0, 6}};
    rayes_scene_bilinear_patch(s, P);
    RayesParam lp[5] = {pc("from", 3, 6, 2), pc("to", 0, 1, 0), pf("intensity", 60.0f),
                        pf("coneangle", 35.0f), pf("conedeltaangle", 10.0f)};
    rayes_scene_light(s, "spotlight", lp, 5);
    RayesParam fill[2] = {pc("from", -3, 4, 5), pf("intensity", 6.0f)};
    rayes_scene_light(s, "pointlight", fill, 2);
    RayesParam v[4] = {pf("density", 6.0f), pf("frequency", 1.4f), pc("albedo", 0.9f, 0.9f, 0.9f),
                       pf("g", 0.3f)};
    rayes_scene_set_shader(s, "turbulence", v, 4);
    const float box[6] = {-1.4f, 1.4f, 0.3f, 2.5f, -1.2f, 1.2f};
    if (rayes_scene_volume(s, box) != RAYES_OK || rayes_scene_commit(s) != RAYES_OK)
        die(rayes_scene_get_error(s));
    return s;
}

typedef struct Run {
    RayesImage *img;
    RayesStats *st;
    double seconds, cpu; /* wall time of the render, and the process's CPU time over the call
                            (which other jobs on a shared machine disturb less) */
} Run;

static double cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * ru.ru_stime.tv_usec;
}

static uint64_t stat_count(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return s ? s->count : 0;
}

static double stat_real(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return s ? s->real : 0.0;
}

static Run run(RayesScene *s, const Args *a, int cached, int threads, double budget_mb)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = a->size;
    o.spp = a->spp;
    o.threads = threads;
    o.bounces = 0;
    o.shadow_rays = o.shadow_rays_deep = a->shadow_rays;
    o.opacity_cache = cached;
    o.opacity_cache_mb = budget_mb;
    o.cache_mb = o.irradiance_cache_mb = 0.0; /* budget_mb bounds the cache */
    o.env_guide = 0;                          /* (no environment light) */
    Run r = {0};
    double cpu0 = cpu_seconds();
    if (rayes_render(s, &o, &r.img, &r.st) != RAYES_OK)
        die(rayes_scene_get_error(s));
    r.cpu = cpu_seconds() - cpu0;
    r.seconds = stat_real(r.st, "time/render_s");
    return r;
}

static double mean(const RayesImage *img)
{
    double m = 0.0;
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        m += (img->rgba[4 * i] + img->rgba[4 * i + 1] + img->rgba[4 * i + 2]) / 3.0;
    return m / (double)n;
}

/* The largest relative difference of 32 x 32 tiles' means. */
static double worst_tile(const RayesImage *a, const RayesImage *b)
{
    double worst = 0.0;
    for (int ty = 0; ty + 32 <= a->height; ty += 32)
        for (int tx = 0; tx + 32 <= a->width; tx += 32) {
            double ma = 0.0, mb = 0.0;
            for (int y = ty; y < ty + 32; y++)
                for (int x = tx; x < tx + 32; x++)
                    for (int c = 0; c < 3; c++) {
                        size_t i = 4 * ((size_t)y * a->width + x) + c;
                        ma += a->rgba[i];
                        mb += b->rgba[i];
                    }
            if (mb > 1e-3 * 32 * 32 * 3)
                worst = fmax(worst, fabs(ma - mb) / mb);
        }
    return worst;
}

static void write(const char *dir, const char *name, int w, int h, const float *rgba)
{
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/figure9-%s.png", dir, name);
    if (image_write(path, w, h, rgba, err, sizeof err) != RAYES_OK)
        die(err);
}

int main(int argc, char **argv)
{
    Args a = parse(argc, argv);
    RayesScene *s = scene();
    Run off = run(s, &a, 0, a.threads, a.opacity_mb), on = run(s, &a, 1, a.threads, a.opacity_mb);
    Run one = run(s, &a, 1, 1, a.opacity_mb), tiny = run(s, &a, 1, a.threads, 5.0);
    size_t n = (size_t)a.size * a.size, bytes = n * 4 * sizeof(float);
    int same_threads = memcmp(on.img->rgba, one.img->rgba, bytes) == 0;
    int same_budget = memcmp(on.img->rgba, tiny.img->rgba, bytes) == 0;
    printf("memo Figure 9: a turbulence volume (5 octaves), %d x %d, %d spp, %d shadow rays, "
           "%d threads, opacity budget %g MB\n",
           a.size, a.size, a.spp, a.shadow_rays, a.threads, a.opacity_mb);
    printf("%-10s %14s %14s %14s %10s %10s\n", "opacity", "transmission", "shadow rays",
           "shader evals", "render s", "cpu s");
    const Run *rows[2] = {&off, &on};
    for (int k = 0; k < 2; k++)
        printf("%-10s %14llu %14llu %14llu %10.2f %10.2f\n", k ? "cached" : "uncached",
               (unsigned long long)stat_count(rows[k]->st, "rays/transmission"),
               (unsigned long long)stat_count(rows[k]->st, "rays/shadow"),
               (unsigned long long)stat_count(rows[k]->st, "opacity/shading_points"),
               rows[k]->seconds, rows[k]->cpu);
    static const char *const levels[3] = {"coarse", "medium", "fine"};
    for (int l = 0; l < 3; l++) {
        char name[64];
        snprintf(name, sizeof name, "cache/opacity/%s/lookups", levels[l]);
        uint64_t lookups = stat_count(on.st, name);
        snprintf(name, sizeof name, "cache/opacity/%s/hit_rate", levels[l]);
        printf("  opacity cache %-6s %12llu lookups, hit rate %.4f\n", levels[l],
               (unsigned long long)lookups, stat_real(on.st, name));
    }
    double ma = mean(on.img), mb = mean(off.img);
    printf("speed-up %.2f (cpu %.2f; memo 4.3); means %.5f cached, %.5f uncached (%.2f%%); worst 32x32 "
           "tile %.2f%%\n",
           off.seconds / on.seconds, off.cpu / on.cpu, ma, mb, 100.0 * (ma - mb) / mb,
           100.0 * worst_tile(on.img, off.img));
    unsigned long long evicted = 0;
    for (int l = 0; l < 3; l++) {
        char name[64];
        snprintf(name, sizeof name, "cache/opacity/%s/evictions", levels[l]);
        evicted += stat_count(tiny.st, name);
    }
    printf("cached image with 1 thread: %s; with a 5 MB opacity budget (%llu entries evicted): "
           "%s\n",
           same_threads ? "identical" : "DIFFERENT", evicted,
           same_budget ? "identical" : "DIFFERENT");
    mkdir(a.out, 0777);
    float *diff = malloc(bytes);
    if (!diff)
        die("out of memory");
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            diff[4 * i + c] = 20.0f * fabsf(on.img->rgba[4 * i + c] - off.img->rgba[4 * i + c]);
        diff[4 * i + 3] = 1.0f;
    }
    write(a.out, "cached", a.size, a.size, on.img->rgba);
    write(a.out, "uncached", a.size, a.size, off.img->rgba);
    write(a.out, "diff20", a.size, a.size, diff);
    printf("images in %s\n", a.out);
    free(diff);
    Run *all[4] = {&off, &on, &one, &tiny};
    for (int k = 0; k < 4; k++) {
        rayes_image_free(all[k]->img);
        rayes_stats_free(all[k]->st);
    }
    rayes_scene_release(s);
    return same_threads && same_budget ? 0 : 1;
}
