/*
 * bench/figure10.c — the memo's Figure 10 (section 6.2): a translucent
 * object lit from one side, single-pass subsurface scattering with the
 * irradiance cache off and on, in preview quality (4 shadow and 4
 * subsurface rays per shading point) and final quality (64 and 64), in one
 * run (memo: preview 64 s without caching and 19 s with, 3.4x; final 54
 * min and 3.2 min, 17x).
 *
 * The scene: the Utah teapot in marble (Jensen 2001's measured medium,
 * the dipole), 77 units across at 2 units per mm (a 38 mm figurine), on a
 * grey floor, lit from behind, a little to the left and above, by a
 * spherical area light (so the thin parts, spout, handle and lid knob,
 * glow; the shadow rays per shading point sample it) and weakly from the
 * front right by a larger one. No diffuse bounces: what is measured is
 * the subsurface integral.
 *
 *   figure10 [--size 256] [--final-size 192] [--spp 16] [--threads 2] [--mb 20]
 *            [--coat 1] [--floor 1] [--data DIR] [--out DIR] [--only preview|final]
 *            [--medium marble] [--profile dipole] [--images-only 0] [--alone 1]
 *
 * --coat 0 takes the specular coat off (Ks 0), --floor 0 the floor: what
 * caching cannot speed up shrinks to the camera rays and the subsurface
 * rays themselves. Unless --alone 0 (or the floor and coat are already
 * off), the run ends with that second row: both qualities again on the
 * teapot alone, images DIR/figure10-QUALITY-alone-*.png. --medium (a
 * preset: skin1, ketchup, ...) and --profile (burley) change the material;
 * --images-only 1 renders the cached images alone (no timing).
 *
 * Prints, per quality: subsurface rays, shadow rays, irradiance shading
 * points, render times off and on (wall, and the process's CPU time) and
 * the speed-ups, the irradiance cache's
 * hit rates, the image means and the worst 32 x 32 tile, whether the
 * cached image is the same with 1 thread and with a 0.1 MB irradiance budget
 * (evicting); the peak resident memory; writes DIR/figure10-QUALITY-{cached,
 * uncached,diff20}.png. Exits 1 if an image depends on threads or budget.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "image/image.h"
#include "io/bpt.h"
#include "io/sink.h"
#include "rayes/rayes.h"

typedef struct Args {
    int size, final_size, spp, threads, coat, images_only, floor, resolution, irr_rays, alone;
    double mb;
    const char *data, *out, *only, *medium, *profile;
} Args;

static void die(const char *msg)
{
    fprintf(stderr, "figure10: %s\n", msg);
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
    Args a = {256,  192,      16,      2, 1, 0, 1, -1, 0, 1, 20.0, NULL, "out/figure10",
              NULL, "marble", "dipole"};
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            die("an option lacks its value");
        if (!strcmp(o, "--size"))
            a.size = parse_int(v, 16, 4096);
        else if (!strcmp(o, "--final-size"))
            a.final_size = parse_int(v, 16, 4096);
        else if (!strcmp(o, "--spp"))
            a.spp = parse_int(v, 1, 1 << 16);
        else if (!strcmp(o, "--threads"))
            a.threads = parse_int(v, 0, 1024);
        else if (!strcmp(o, "--floor"))
            a.floor = parse_int(v, 0, 1);
        else if (!strcmp(o, "--resolution"))
            a.resolution = parse_int(v, -1, 2);
        else if (!strcmp(o, "--irradiance-shadow-rays"))
            a.irr_rays = parse_int(v, 0, 1 << 20);
        else if (!strcmp(o, "--coat"))
            a.coat = parse_int(v, 0, 1);
        else if (!strcmp(o, "--mb"))
            a.mb = parse_int(v, 1, 100000);
        else if (!strcmp(o, "--data"))
            a.data = v;
        else if (!strcmp(o, "--out"))
            a.out = v;
        else if (!strcmp(o, "--only"))
            a.only = v;
        else if (!strcmp(o, "--medium"))
            a.medium = v;
        else if (!strcmp(o, "--profile"))
            a.profile = v;
        else if (!strcmp(o, "--alone"))
            a.alone = parse_int(v, 0, 1);
        else if (!strcmp(o, "--images-only"))
            a.images_only = parse_int(v, 0, 1);
        else
            die("usage: figure10 [--size N] [--final-size N] [--spp N] [--threads N] [--mb MB] "
                "[--coat 0|1] [--floor 0|1] [--data DIR] [--out DIR] [--only preview|final] [--medium NAME] "
                "[--profile dipole|burley] [--images-only 1] [--alone 0|1]");
        i++;
    }
    if (!a.data)
        a.data = getenv("RAYES_DATA");
    if (!a.data)
        a.data = "../shared/data";
    return a;
}

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static void check(RayesScene *s, RayesError e)
{
    if (e != RAYES_OK)
        die(rayes_scene_get_error(s));
}

/* The teapot's data is z up, 6.4 units across: world = S(12) * (x, z, -y),
 * turned 30 degrees about y so the spout comes toward the camera. */
static void teapot(RayesScene *s, const Args *a)
{
    double th = 30.0 * M_PI / 180.0;
    float c = (float)cos(th), sn = (float)sin(th), k = 12.0f;
    const float m[16] = {k * c, -k * sn, 0, 0, 0, 0, k, 0, -k * sn, -k * c, 0, 0, 0, 0, 0, 1};
    RayesParam p[5] = {(RayesParam){"preset", RAYES_PARAM_STRING, {0, 0, 0}, a->medium},
                       (RayesParam){"profile", RAYES_PARAM_STRING, {0, 0, 0}, a->profile},
                       pf("roughness", 0.08f), pf("unitlength", 2.0f),
                       pf("Ks", a->coat ? 1.0f : 0.0f)};
    check(s, rayes_scene_set_shader(s, "subsurface", p, 5));
    check(s, rayes_scene_set_transform(s, m));
    char path[4096], err[1024];
    snprintf(path, sizeof path, "%s/teapot.bpt", a->data);
    IoSink sink = io_sink_scene(s);
    if (io_read_bpt(path, &sink, err, sizeof err) != RAYES_OK)
        die(err);
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    check(s, rayes_scene_set_transform(s, identity));
}

static RayesScene *scene(const Args *a)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 55, 130}, at[3] = {0, 17, 0}, up[3] = {0, 1, 0};
    check(s, rayes_scene_set_camera(s, eye, at, up, 30.0f));
    RayesParam m[2] = {pf("Ka", 0.0f), pf("Kd", 0.6f)};
    check(s, rayes_scene_set_shader(s, "matte", m, 2));
    const float P[4][3] = {{-300, 0, -300}, {300, 0, -300}, {-300, 0, 300}, {300, 0, 300}};
    if (a->floor)
        check(s, rayes_scene_bilinear_patch(s, P));
    teapot(s, a);
    const float at_back[16] = {1, 0, 0, -30, 0, 1, 0, 60, 0, 0, 1, -110, 0, 0, 0, 1};
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    RayesParam back[3] = {(RayesParam){"shape", RAYES_PARAM_STRING, {0, 0, 0}, "sphere"},
                          pf("radius", 12.0f), pf("intensity", 150.0f)};
    check(s, rayes_scene_set_transform(s, at_back));
    check(s, rayes_scene_light(s, "arealight", back, 3));
    check(s, rayes_scene_set_transform(s, identity));
    const float at_fill[16] = {1, 0, 0, 150, 0, 1, 0, 80, 0, 0, 1, 120, 0, 0, 0, 1};
    RayesParam fill[3] = {(RayesParam){"shape", RAYES_PARAM_STRING, {0, 0, 0}, "sphere"},
                          pf("radius", 20.0f), pf("intensity", 8.0f)};
    check(s, rayes_scene_set_transform(s, at_fill));
    check(s, rayes_scene_light(s, "arealight", fill, 3));
    check(s, rayes_scene_set_transform(s, identity));
    check(s, rayes_scene_commit(s));
    return s;
}

typedef struct Run {
    RayesImage *img;
    RayesStats *st;
    double seconds, cpu; /* wall time of the render, and the process's CPU time over the call
                            (less sensitive to other jobs on a shared machine) */
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

static Run run(RayesScene *s, const Args *a, int final, int cached, int threads, double mb)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, final ? RAYES_QUALITY_FINAL : RAYES_QUALITY_PREVIEW);
    o.width = o.height = final ? a->final_size : a->size;
    o.spp = a->spp;
    o.threads = threads;
    o.bounces = 0;
    o.irradiance_cache = cached;
    o.irradiance_cache_mb = mb;
    o.cache_mb = o.opacity_cache_mb = 0.0; /* mb bounds the cache (no bounces, no */
    o.env_guide = 0;                       /* transparency, no environment light) */
    o.cache_resolution = a->resolution;
    o.irradiance_shadow_rays = a->irr_rays;
    Run r = {0};
    double cpu0 = cpu_seconds();
    check(s, rayes_render(s, &o, &r.img, &r.st));
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

/* The largest relative difference of 32 x 32 tiles' means (tiles darker
 * than 1/100 of the image's mean are skipped: relative noise there). */
static double worst_tile(const RayesImage *a, const RayesImage *b, int *wx, int *wy, double *wa,
                         double *wb)
{
    double worst = 0.0, floor = 0.01 * mean(b) * 32 * 32 * 3;
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
            if (mb > floor && fabs(ma - mb) / mb > worst) {
                worst = fabs(ma - mb) / mb;
                *wx = tx, *wy = ty, *wa = ma / (32 * 32 * 3), *wb = mb / (32 * 32 * 3);
            }
        }
    return worst;
}

static void write(const Args *a, const char *quality, const char *name, const RayesImage *img,
                  const float *rgba)
{
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/figure10-%s-%s.png", a->out, quality, name);
    if (image_write(path, img->width, img->height, rgba, err, sizeof err) != RAYES_OK)
        die(err);
}

static void print_cache(const RayesStats *st)
{
    static const char *const levels[3] = {"coarse", "medium", "fine"};
    for (int l = 0; l < 3; l++) {
        char name[64];
        snprintf(name, sizeof name, "cache/irradiance/%s/lookups", levels[l]);
        uint64_t lookups = stat_count(st, name);
        snprintf(name, sizeof name, "cache/irradiance/%s/hit_rate", levels[l]);
        double rate = stat_real(st, name);
        snprintf(name, sizeof name, "cache/irradiance/%s/entries", levels[l]);
        printf("  irradiance cache %-6s %12llu lookups, hit rate %.4f, %llu entries\n", levels[l],
               (unsigned long long)lookups, rate, (unsigned long long)stat_count(st, name));
    }
}

/* One quality: off and on, then the determinism renders. Returns 1 if
 * the cached image is the same with 1 thread and a 0.1 MB budget. */
static int quality(RayesScene *s, const Args *a, int final, const char *q)
{
    Run off = run(s, a, final, 0, a->threads, a->mb), on = run(s, a, final, 1, a->threads, a->mb);
    Run one = run(s, a, final, 1, 1, a->mb), tiny = run(s, a, final, 1, a->threads, 0.1);
    size_t n = (size_t)on.img->width * on.img->height, bytes = n * 4 * sizeof(float);
    int same_threads = memcmp(on.img->rgba, one.img->rgba, bytes) == 0;
    int same_budget = memcmp(on.img->rgba, tiny.img->rgba, bytes) == 0;
    printf("\n%s: %d x %d, %d spp, %d shadow and %d subsurface rays, %d threads, irradiance "
           "budget %g MB, floor %s, coat %s\n",
           q, on.img->width, on.img->height, a->spp, final ? 64 : 4, final ? 64 : 4, a->threads,
           a->mb, a->floor ? "on" : "off", a->coat ? "on" : "off");
    printf("%-10s %14s %14s %14s %10s %10s\n", "irradiance", "subsurface", "shadow rays",
           "irr. points", "render s", "cpu s");
    const Run *rows[2] = {&off, &on};
    for (int k = 0; k < 2; k++)
        printf("%-10s %14llu %14llu %14llu %10.2f %10.2f\n", k ? "cached" : "uncached",
               (unsigned long long)stat_count(rows[k]->st, "rays/subsurface"),
               (unsigned long long)stat_count(rows[k]->st, "rays/shadow"),
               (unsigned long long)stat_count(rows[k]->st, "subsurface/irradiance_points"),
               rows[k]->seconds, rows[k]->cpu);
    print_cache(on.st);
    double ma = mean(on.img), mb = mean(off.img), ta = 0.0, tb = 0.0;
    int tx = 0, ty = 0;
    double worst = worst_tile(on.img, off.img, &tx, &ty, &ta, &tb);
    printf("speed-up %.2f (cpu %.2f; memo %s); means %.5f cached, %.5f uncached (%+.2f%%); worst 32x32 "
           "tile %.2f%% (at %d,%d: %.5f cached, %.5f uncached)\n",
           off.seconds / on.seconds, off.cpu / on.cpu, final ? "17" : "3.4", ma, mb, 100.0 * (ma - mb) / mb,
           100.0 * worst, tx, ty, ta, tb);
    printf("of which preparing the scene (wall): %.2f s uncached, %.2f s cached\n",
           stat_real(off.st, "time/prepare_s"), stat_real(on.st, "time/prepare_s"));
    unsigned long long evicted = stat_count(tiny.st, "cache/irradiance/coarse/evictions") +
                                 stat_count(tiny.st, "cache/irradiance/medium/evictions") +
                                 stat_count(tiny.st, "cache/irradiance/fine/evictions");
    printf("cached image with 1 thread: %s; with a 0.1 MB irradiance budget (%llu entries "
           "evicted): %s\n",
           same_threads ? "identical" : "DIFFERENT", evicted,
           same_budget ? "identical" : "DIFFERENT");
    float *diff = malloc(bytes);
    if (!diff)
        die("out of memory");
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            diff[4 * i + c] = 20.0f * fabsf(on.img->rgba[4 * i + c] - off.img->rgba[4 * i + c]);
        diff[4 * i + 3] = 1.0f;
    }
    write(a, q, "cached", on.img, on.img->rgba);
    write(a, q, "uncached", off.img, off.img->rgba);
    write(a, q, "diff20", on.img, diff);
    free(diff);
    Run *all[4] = {&off, &on, &one, &tiny};
    for (int k = 0; k < 4; k++) {
        if (k == 3)
            printf("peak resident memory so far %.1f MB\n",
                   stat_count(all[k]->st, "memory/peak_rss_bytes") / 1e6);
        rayes_image_free(all[k]->img);
        rayes_stats_free(all[k]->st);
    }
    return same_threads && same_budget;
}

/* --images-only: the cached render of each quality asked for, to
 * DIR/figure10-MEDIUM-PROFILE-QUALITY.png. */
static void images(RayesScene *s, const Args *a)
{
    for (int final = 0; final < 2; final++) {
        const char *q = final ? "final" : "preview";
        if (a->only && strcmp(a->only, q))
            continue;
        Run r = run(s, a, final, 1, a->threads, a->mb);
        char name[256];
        snprintf(name, sizeof name, "%s-%s", a->medium, a->profile);
        write(a, q, name, r.img, r.img->rgba);
        printf("%s %s: %.2f s\n", name, q, r.seconds);
        rayes_image_free(r.img);
        rayes_stats_free(r.st);
    }
}

int main(int argc, char **argv)
{
    Args a = parse(argc, argv);
    RayesScene *s = scene(&a);
    mkdir(a.out, 0777);
    printf("memo Figure 10: a %s teapot lit from behind (subsurface scattering, %s), coat %s\n",
           a.medium, a.profile, a.coat ? "on" : "off");
    int ok = 1;
    if (a.images_only) {
        images(s, &a);
        rayes_scene_release(s);
        return 0;
    }
    if (!a.only || !strcmp(a.only, "preview"))
        ok &= quality(s, &a, 0, "preview");
    if (!a.only || !strcmp(a.only, "final"))
        ok &= quality(s, &a, 1, "final");
    rayes_scene_release(s);
    if (a.alone && (a.floor || a.coat)) {
        /* The second row: the translucent object alone (the memo's Figure
         * 10 is a candle face), without what caching cannot touch, the
         * floor's direct lighting and the coat's highlights. */
        Args b = a;
        b.floor = b.coat = 0;
        s = scene(&b);
        printf("\nthe teapot alone (no floor, no coat):\n");
        if (!a.only || !strcmp(a.only, "preview"))
            ok &= quality(s, &b, 0, "preview-alone");
        if (!a.only || !strcmp(a.only, "final"))
            ok &= quality(s, &b, 1, "final-alone");
        rayes_scene_release(s);
    }
    printf("images in %s\n", a.out);
    return ok ? 0 : 1;
}
