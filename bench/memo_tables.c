/*
 * bench/memo_tables.c — the memo's Table 1 and Table 4 on cornell-teapots,
 * measured in one run so that ratios are taken on one machine state.
 *
 *   memo_tables table1 [--size N] [--spp N] [--bounces-max B] [--accuracy-spp N]
 *                      [--accuracy-size N] [--out DIR] [--data DIR] [--threads N]
 *                      [--cache-k K] [--gridsize N] [--dice-raster 0|1]
 *                      [--scene cornell-teapots|cornell-teapots-displaced]
 *   memo_tables table4 [...same...] [--budgets MB,MB,...]
 *   memo_tables table2 [...same...] [--uncached-max B]
 *   memo_tables figure5 [--size N] [--spp N] [--out DIR] [--data DIR] [--scene S]
 *
 * table1: preview quality, bounces 1..B (default 3), caching off and on:
 * shading points, rays, time, speed-up and hit rates per resolution.
 * table4: one bounce at cache budgets 0 (off), 1, 4, 16, 64, 256 MB.
 * table2: final quality (the grid hider with irradiance interpolation),
 * bounces 1..B, caching on, and off up to --uncached-max bounces (default
 * 1: an uncached row costs 64 times the one before). No accuracy pass:
 * bench/figure5 measures final against a reference.
 * figure5: reference (4096 diffuse rays, nothing cached), preview and final
 * images at one bounce, the relative RMSE and mean relative error of preview
 * and final against the reference, 20x difference images, and times.
 * Both then measure bias: the same rows at --accuracy-spp pixel samples
 * (default 64) and --accuracy-size pixels (default: --size, the table's own), the
 * relative difference of the cached and uncached image means and the
 * largest relative difference of their 32 x 32 tile means. Images (PNG) and
 * a JSON record of every row go to --out (default bench-out/).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "image/image.h"
#include "rayes/rayes.h"

typedef struct Args {
    const char *mode, *data, *out, *scene;
    int size, spp, bounces_max, accuracy_spp, accuracy_size, threads;
    int uncached_max;             /* table2: uncached rows up to this many bounces */
    int quality;                  /* RayesQuality of the rows */
    double cache_k;
    int grid_size;                /* micropolygons per grid, at most (0: the default) */
    int dice_raster;              /* 1: rayes's default raster-oriented dicing; 0: isotropic */
    double budgets[16];
    int n_budgets;
} Args;

typedef struct Row {
    int bounces, cache;
    double budget_mb;
    double time_s;                /* wall clock */
    double cpu_s;                 /* process CPU time (user + system), less sensitive to
                                     other tenants of a shared machine */
    unsigned long long shading_points, rays, shadow, diffuse, records;
    unsigned long long grids, grid_vertices, grid_size;
    double hit[3];
    float *rgba;
    int w, h;
} Row;

static void die(const char *msg)
{
    fprintf(stderr, "memo_tables: %s\n", msg);
    exit(1);
}

static const RayesStat *find(const RayesStats *s, const char *name)
{
    return rayes_stats_find(s, name);
}

static double cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * ru.ru_stime.tv_usec;
}

static Row run(const Args *a, int size, int spp, int bounces, int cache, double budget_mb)
{
    RayesScene *scene = rayes_scene_new();
    char err[1024];
    if (!scene)
        die("out of memory");
    IoSink sink = io_sink_scene(scene);
    if (io_builtin_scene(a->scene, a->data, &sink, err, sizeof err) != RAYES_OK)
        die(err);
    if (rayes_scene_commit(scene) != RAYES_OK)
        die(rayes_scene_get_error(scene));
    RayesRenderOptions o;
    rayes_render_options_init(&o, (RayesQuality)a->quality);
    o.width = o.height = size;
    o.spp = spp;
    o.bounces = bounces;
    o.threads = a->threads;
    o.cache = cache;
    o.cache_mb = budget_mb;
    o.cache_k = (float)a->cache_k;
    /* The memo's trees: every uncached diffuse hit branches into the
     * preset's deeper rays, as its tables count them. */
    o.branch_depth = bounces + 1;
    if (a->grid_size > 0)
        o.grid_size = a->grid_size;
    /* The memo's tessellation of the box, "approximately 18,000 micropolygon
     * grids with a total of 3.9 million grid vertices" at 1024, is what
     * isotropic dicing makes (17,158 and 3.61 M); rayes's raster-oriented
     * default makes 8,113 and 1.71 M (--dice-raster). */
    o.dice_isotropic = !a->dice_raster;
    RayesImage *img;
    RayesStats *st;
    double cpu0 = cpu_seconds();
    if (rayes_render(scene, &o, &img, &st) != RAYES_OK)
        die(rayes_scene_get_error(scene));
    Row r = {.bounces = bounces, .cache = cache, .budget_mb = budget_mb};
    r.cpu_s = cpu_seconds() - cpu0;
    r.time_s = find(st, "time/total_s")->real;
    r.shading_points = find(st, "shading_points/total")->count;
    r.grids = find(st, "grids")->count;
    r.grid_vertices = find(st, "grid_vertices")->count;
    r.grid_size = find(st, "grid_size")->count;
    r.rays = find(st, "rays/total")->count;
    r.shadow = find(st, "rays/shadow")->count;
    r.diffuse = find(st, "rays/diffuse")->count;
    static const char *const hr[3] = {"cache/coarse/hit_rate", "cache/medium/hit_rate",
                                      "cache/fine/hit_rate"};
    for (int l = 0; l < 3; l++)
        r.hit[l] = cache ? find(st, hr[l])->real : 0.0;
    const RayesStat *rec = rayes_stats_find(st, "irradiance/records");
    r.records = rec ? rec->count : 0;
    r.rgba = img->rgba;
    r.w = img->width;
    r.h = img->height;
    img->rgba = NULL;
    rayes_image_free(img);
    rayes_stats_free(st);
    rayes_scene_release(scene);
    return r;
}

static void save(const Args *a, const Row *r, const char *tag)
{
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/%s-b%d-%s.png", a->out, tag, r->bounces,
             r->cache ? "cached" : "uncached");
    if (image_write(path, r->w, r->h, r->rgba, err, sizeof err) != RAYES_OK)
        die(err);
}

static void human(char *buf, size_t n, double v)
{
    if (v >= 1e9)
        snprintf(buf, n, "%.2fB", v / 1e9);
    else if (v >= 1e6)
        snprintf(buf, n, "%.2fM", v / 1e6);
    else if (v >= 1e3)
        snprintf(buf, n, "%.1fk", v / 1e3);
    else
        snprintf(buf, n, "%.0f", v);
}

/* Mean of the RGB average over a region. */
static double region_mean(const Row *r, int x0, int y0, int w, int h)
{
    double s = 0.0;
    for (int y = y0; y < y0 + h; y++)
        for (int x = x0; x < x0 + w; x++) {
            const float *p = &r->rgba[4 * ((size_t)y * r->w + x)];
            s += (p[0] + p[1] + p[2]) / 3.0;
        }
    return s / ((double)w * h);
}

/* Relative difference of the means, and the largest over 32 x 32 tiles
 * (whose position and means go to *where). */
static void accuracy(const Row *on, const Row *off, double *mean_rel, double *tile_rel,
                     char *where, size_t where_size)
{
    double m_on = region_mean(on, 0, 0, on->w, on->h), m_off = region_mean(off, 0, 0, off->w, off->h);
    *mean_rel = fabs(m_on - m_off) / m_off;
    *tile_rel = 0.0;
    for (int ty = 0; ty + 32 <= on->h; ty += 32)
        for (int tx = 0; tx + 32 <= on->w; tx += 32) {
            double a = region_mean(on, tx, ty, 32, 32), b = region_mean(off, tx, ty, 32, 32);
            if (b > 1e-4 && fabs(a - b) / b > *tile_rel) { /* black tiles have no relative error */
                *tile_rel = fabs(a - b) / b;
                snprintf(where, where_size, "tile at (%d, %d): cached %.4f, uncached %.4f", tx, ty,
                         a, b);
            }
        }
}

static void parse(int argc, char **argv, Args *a)
{
    a->mode = argc > 1 ? argv[1] : "";
    a->out = "bench-out";
    a->scene = "cornell-teapots";
    a->size = 512;
    a->spp = 4;
    a->bounces_max = 3;
    a->accuracy_spp = 64;
    a->threads = 0;
    a->uncached_max = 1;
    a->quality = RAYES_QUALITY_PREVIEW;
    a->cache_k = 1.0;
    const double budgets[] = {0, 1, 4, 16, 64, 256};
    a->n_budgets = 6;
    memcpy(a->budgets, budgets, sizeof budgets);
    for (int i = 2; i + 1 < argc; i += 2) {
        const char *o = argv[i], *v = argv[i + 1];
        if (strcmp(o, "--size") == 0)
            a->size = atoi(v);
        else if (strcmp(o, "--spp") == 0)
            a->spp = atoi(v);
        else if (strcmp(o, "--bounces-max") == 0)
            a->bounces_max = atoi(v);
        else if (strcmp(o, "--accuracy-spp") == 0)
            a->accuracy_spp = atoi(v);
        else if (strcmp(o, "--accuracy-size") == 0)
            a->accuracy_size = atoi(v);
        else if (strcmp(o, "--cache-k") == 0)
            a->cache_k = atof(v);
        else if (strcmp(o, "--gridsize") == 0)
            a->grid_size = atoi(v);
        else if (strcmp(o, "--dice-raster") == 0)
            a->dice_raster = atoi(v);
        else if (strcmp(o, "--threads") == 0)
            a->threads = atoi(v);
        else if (strcmp(o, "--data") == 0)
            a->data = v;
        else if (strcmp(o, "--out") == 0)
            a->out = v;
        else if (strcmp(o, "--scene") == 0)
            a->scene = v;
        else if (strcmp(o, "--uncached-max") == 0)
            a->uncached_max = atoi(v);
        else if (strcmp(o, "--budgets") == 0) {
            a->n_budgets = 0;
            for (char *s = (char *)v; *s && a->n_budgets < 16; s += strcspn(s, ",") + (s[strcspn(s, ",")] != 0))
                a->budgets[a->n_budgets++] = atof(s);
        } else
            die("unknown option (see the comment at the top of bench/memo_tables.c)");
    }
    if (a->accuracy_size == 0)
        a->accuracy_size = a->size;
    if (strcmp(a->mode, "table2") == 0)
        a->quality = RAYES_QUALITY_FINAL;
    if ((strcmp(a->mode, "table1") && strcmp(a->mode, "table2") && strcmp(a->mode, "table4") &&
         strcmp(a->mode, "figure5")) ||
        a->size < 32 || a->spp < 1)
        die("usage: memo_tables table1|table2|table4|figure5 [--size N] [--spp N] ...");
    if (mkdir(a->out, 0777) != 0 && errno != EEXIST)
        die("cannot create the output directory");
}

static void json_row(FILE *j, const Row *r, int first)
{
    fprintf(j,
            "%s\n    {\"bounces\": %d, \"cache\": %d, \"budget_mb\": %g, \"time_s\": %.3f, \"cpu_s\": %.3f, "
            "\"shading_points\": %llu, \"rays\": %llu, \"shadow_rays\": %llu, "
            "\"diffuse_rays\": %llu, \"hit_rate\": {\"coarse\": %.5f, \"medium\": %.5f, "
            "\"fine\": %.5f}, \"grids\": %llu, \"grid_vertices\": %llu, \"grid_size\": %llu}",
            first ? "" : ",", r->bounces, r->cache, r->budget_mb, r->time_s, r->cpu_s,
            r->shading_points, r->rays, r->shadow, r->diffuse, r->hit[0], r->hit[1], r->hit[2],
            r->grids, r->grid_vertices, r->grid_size);
}

static void table1(const Args *a, FILE *j)
{
    printf("Table 1 (%s, preview: 4 shadow + 4 diffuse rays, %dx%d, %d spp)\n", a->scene,
           a->size, a->size, a->spp);
    printf("%-3s | %9s %9s %8s %8s | %9s %9s %8s %8s | %8s %8s | %s\n", "b", "sh.pts", "rays",
           "time", "cpu", "sh.pts", "rays", "time", "cpu", "speed-up", "(cpu)",
           "hit % coarse/medium/fine");
    fprintf(j, "{\"table\": 1, \"size\": %d, \"spp\": %d, \"rows\": [", a->size, a->spp);
    double t1_on = 0.0, c1_on = 0.0;
    for (int b = 1; b <= a->bounces_max; b++) {
        Row off = run(a, a->size, a->spp, b, 0, 100), on = run(a, a->size, a->spp, b, 1, 100);
        char s1[32], s2[32], s3[32], s4[32];
        human(s1, sizeof s1, off.shading_points);
        human(s2, sizeof s2, off.rays);
        human(s3, sizeof s3, on.shading_points);
        human(s4, sizeof s4, on.rays);
        printf("%-3d | %9s %9s %7.2fs %7.2fs | %9s %9s %7.2fs %7.2fs | %8.2f %8.2f | %.2f / %.2f / "
               "%.2f\n",
               b, s1, s2, off.time_s, off.cpu_s, s3, s4, on.time_s, on.cpu_s,
               off.time_s / on.time_s, off.cpu_s / on.cpu_s, 100 * on.hit[0], 100 * on.hit[1],
               100 * on.hit[2]);
        fflush(stdout);
        if (b == 1) {
            t1_on = on.time_s;
            c1_on = on.cpu_s;
            printf("    %llu grids, %llu vertices (gridsize %llu)\n", on.grids, on.grid_vertices,
                   on.grid_size);
        } else {
            printf("    cached time %d bounces / 1 bounce: %.2f (cpu %.2f)\n", b, on.time_s / t1_on,
                   on.cpu_s / c1_on);
        }
        json_row(j, &off, b == 1);
        json_row(j, &on, 0);
        save(a, &off, "table1");
        save(a, &on, "table1");
        free(off.rgba);
        free(on.rgba);
    }
    fprintf(j, "\n  ]");
}

/* The memo's Table 2: final quality (64 shadow rays, 1024 diffuse rays at
 * depth 0 and 64 deeper, the grid hider with irradiance interpolation),
 * bounces 1..B, caching off (up to --uncached-max bounces: the uncached
 * rows grow as 64^b) and on. */
static void table2(const Args *a, FILE *j)
{
    printf("Table 2 (%s, final: 64 shadow, 1024/64 diffuse rays, grid hider + irradiance "
           "interpolation, %dx%d, %d spp)\n",
           a->scene, a->size, a->size, a->spp);
    printf("%-3s | %9s %9s %8s %8s | %9s %9s %8s %8s %8s | %8s %8s | %s\n", "b", "sh.pts", "rays",
           "time", "cpu", "sh.pts", "rays", "records", "time", "cpu", "speed-up", "(cpu)",
           "hit % coarse/medium/fine");
    fprintf(j, "{\"table\": 2, \"size\": %d, \"spp\": %d, \"rows\": [", a->size, a->spp);
    double t1_on = 0.0, c1_on = 0.0;
    for (int b = 1; b <= a->bounces_max; b++) {
        Row off = {0};
        int have_off = b <= a->uncached_max;
        if (have_off)
            off = run(a, a->size, a->spp, b, 0, 100);
        Row on = run(a, a->size, a->spp, b, 1, 100);
        char s1[32] = "-", s2[32] = "-", s3[32], s4[32], s5[32];
        if (have_off) {
            human(s1, sizeof s1, off.shading_points);
            human(s2, sizeof s2, off.rays);
        }
        human(s3, sizeof s3, on.shading_points);
        human(s4, sizeof s4, on.rays);
        human(s5, sizeof s5, on.records);
        if (have_off)
            printf("%-3d | %9s %9s %7.1fs %7.1fs |", b, s1, s2, off.time_s, off.cpu_s);
        else
            printf("%-3d | %9s %9s %8s %8s |", b, s1, s2, "-", "-");
        printf(" %9s %9s %8s %7.1fs %7.1fs |", s3, s4, s5, on.time_s, on.cpu_s);
        if (have_off)
            printf(" %8.1f %8.1f |", off.time_s / on.time_s, off.cpu_s / on.cpu_s);
        else
            printf(" %8s %8s |", "-", "-");
        printf(" %.2f / %.2f / %.2f\n", 100 * on.hit[0], 100 * on.hit[1], 100 * on.hit[2]);
        if (b == 1) {
            t1_on = on.time_s;
            c1_on = on.cpu_s;
        } else {
            printf("    cached time %d bounces / 1 bounce: %.2f (cpu %.2f)\n", b, on.time_s / t1_on,
                   on.cpu_s / c1_on);
        }
        fflush(stdout);
        if (have_off) {
            json_row(j, &off, b == 1);
            save(a, &off, "table2");
            free(off.rgba);
        }
        json_row(j, &on, b == 1 && !have_off);
        save(a, &on, "table2");
        free(on.rgba);
    }
    fprintf(j, "\n  ]");
}

/* Error of image r against the reference: RMSE over pixels and channels
 * divided by the reference's mean, and the mean relative error
 * sum |r - ref| / sum ref, on linear values (clamp 0) or on values clamped
 * to the displayable [0, 1] (clamp 1: a light seen directly or in a mirror
 * is worth 1, not 17); with write, 20 x |r - ref| (linear) goes to
 * DIR/figure5-TAG-diff.png. */
static void against(const Args *a, const Row *r, const Row *ref, const char *tag, int clamp,
                    int write, double *rel_rmse, double *mean_rel)
{
    size_t n = (size_t)r->w * r->h;
    double se = 0.0, ae = 0.0, sum = 0.0;
    float *diff = malloc(n * 4 * sizeof *diff);
    if (!diff)
        die("out of memory");
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            double x = r->rgba[4 * i + c], y = ref->rgba[4 * i + c];
            diff[4 * i + c] = (float)(20.0 * fabs(x - y));
            if (clamp) {
                x = fmin(fmax(x, 0.0), 1.0);
                y = fmin(fmax(y, 0.0), 1.0);
            }
            se += (x - y) * (x - y);
            ae += fabs(x - y);
            sum += y;
        }
        diff[4 * i + 3] = 1.0f;
    }
    double mean = sum / (3.0 * (double)n);
    *rel_rmse = sqrt(se / (3.0 * (double)n)) / mean;
    *mean_rel = ae / sum;
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/figure5-%s-diff.png", a->out, tag);
    if (write && image_write(path, r->w, r->h, diff, err, sizeof err) != RAYES_OK)
        die(err);
    free(diff);
}

/* The memo's Figure 5 (bottom row): preview and final images against a
 * reference of 4096 diffuse rays per shading point and no caching of any
 * kind, one bounce, with 20x difference images. */
static void figure5(Args *a, FILE *j)
{
    static const struct {
        const char *tag;
        int quality;
    } rows[3] = {{"reference", RAYES_QUALITY_REFERENCE},
                 {"preview", RAYES_QUALITY_PREVIEW},
                 {"final", RAYES_QUALITY_FINAL}};
    printf("Figure 5 (%s, 1 bounce, %dx%d, %d spp): against the reference\n", a->scene, a->size,
           a->size, a->spp);
    printf("%-9s | %9s %9s %8s %8s | %10s %10s | %10s %10s | %s\n", "image", "sh.pts", "rays",
           "time", "cpu", "rel. RMSE", "mean rel.", "(display)", "(display)", "time / reference");
    fprintf(j, "{\"figure\": 5, \"size\": %d, \"spp\": %d, \"rows\": [", a->size, a->spp);
    Row ref = {0};
    for (int i = 0; i < 3; i++) {
        a->quality = rows[i].quality;
        Row r = run(a, a->size, a->spp, 1, rows[i].quality != RAYES_QUALITY_REFERENCE, 100);
        char path[1024], err[1024], s1[32], s2[32];
        snprintf(path, sizeof path, "%s/figure5-%s.png", a->out, rows[i].tag);
        if (image_write(path, r.w, r.h, r.rgba, err, sizeof err) != RAYES_OK)
            die(err);
        human(s1, sizeof s1, r.shading_points);
        human(s2, sizeof s2, r.rays);
        double rmse = 0.0, mrel = 0.0, drmse = 0.0, dmrel = 0.0;
        if (i > 0) {
            against(a, &r, &ref, rows[i].tag, 0, 1, &rmse, &mrel);
            against(a, &r, &ref, rows[i].tag, 1, 0, &drmse, &dmrel);
        }
        printf("%-9s | %9s %9s %7.1fs %7.1fs |", rows[i].tag, s1, s2, r.time_s, r.cpu_s);
        if (i > 0)
            printf(" %9.2f%% %9.2f%% | %9.2f%% %9.2f%% | %.3f (cpu %.3f)\n", 100 * rmse,
                   100 * mrel, 100 * drmse, 100 * dmrel, r.time_s / ref.time_s,
                   r.cpu_s / ref.cpu_s);
        else
            printf(" %10s %10s | %10s %10s |\n", "-", "-", "-", "-");
        fflush(stdout);
        fprintf(j,
                "%s\n    {\"image\": \"%s\", \"time_s\": %.3f, \"cpu_s\": %.3f, "
                "\"shading_points\": %llu, \"rays\": %llu, \"rel_rmse\": %.6f, "
                "\"mean_rel\": %.6f, \"display_rel_rmse\": %.6f, \"display_mean_rel\": %.6f}",
                i ? "," : "", rows[i].tag, r.time_s, r.cpu_s, r.shading_points, r.rays, rmse, mrel,
                drmse, dmrel);
        if (i == 0)
            ref = r;
        else
            free(r.rgba);
    }
    free(ref.rgba);
    fprintf(j, "\n  ]\n}\n");
}

static void table4(const Args *a, FILE *j)
{
    printf("Table 4 (%s, 1 bounce, preview, %dx%d, %d spp)\n", a->scene, a->size, a->size,
           a->spp);
    printf("%-9s | %6s %6s %6s | %9s %9s %8s %8s\n", "cache", "coarse", "medium", "fine",
           "sh.pts", "rays", "time", "cpu");
    fprintf(j, "{\"table\": 4, \"size\": %d, \"spp\": %d, \"rows\": [", a->size, a->spp);
    for (int i = 0; i < a->n_budgets; i++) {
        double mb = a->budgets[i];
        Row r = run(a, a->size, a->spp, 1, mb > 0.0, mb);
        char s1[32], s2[32];
        human(s1, sizeof s1, r.shading_points);
        human(s2, sizeof s2, r.rays);
        printf("%6g MB | %6.2f %6.2f %6.2f | %9s %9s %7.2fs %7.2fs\n", mb, 100 * r.hit[0],
               100 * r.hit[1], 100 * r.hit[2], s1, s2, r.time_s, r.cpu_s);
        fflush(stdout);
        json_row(j, &r, i == 0);
        free(r.rgba);
    }
    fprintf(j, "\n  ]");
}

/* Bias of caching at each bounce count (table1) or budget (table4). */
static void bias(const Args *a, FILE *j)
{
    printf("Accuracy (%dx%d, %d spp): cached vs uncached image\n", a->accuracy_size,
           a->accuracy_size, a->accuracy_spp);
    printf("%-12s | %16s | %22s\n", "row", "mean rel. diff", "max 32x32 tile rel. diff");
    fprintf(j, ",\n  \"accuracy\": {\"size\": %d, \"spp\": %d, \"rows\": [", a->accuracy_size,
            a->accuracy_spp);
    int rows = strcmp(a->mode, "table1") == 0 ? a->bounces_max : a->n_budgets;
    int first = 1;
    Row off = {0};
    for (int i = 0; i < rows; i++) {
        int b = strcmp(a->mode, "table1") == 0 ? i + 1 : 1;
        double mb = strcmp(a->mode, "table1") == 0 ? 100.0 : a->budgets[i];
        if (mb <= 0.0)
            continue;
        if (!off.rgba || off.bounces != b) {
            free(off.rgba);
            off = run(a, a->accuracy_size, a->accuracy_spp, b, 0, 100);
            save(a, &off, "accuracy");
        }
        Row on = run(a, a->accuracy_size, a->accuracy_spp, b, 1, mb);
        save(a, &on, "accuracy");
        double mrel, trel;
        char where[128] = "";
        accuracy(&on, &off, &mrel, &trel, where, sizeof where);
        char label[32];
        snprintf(label, sizeof label, "b=%d %gMB", b, mb);
        printf("%-12s | %15.3f%% | %21.3f%%  %s\n", label, 100 * mrel, 100 * trel, where);
        fflush(stdout);
        fprintf(j, "%s\n    {\"bounces\": %d, \"budget_mb\": %g, \"mean_rel\": %.6f, "
                   "\"max_tile_rel\": %.6f}",
                first ? "" : ",", b, mb, mrel, trel);
        first = 0;
        free(on.rgba);
    }
    free(off.rgba);
    fprintf(j, "\n  ]}\n}\n");
}

int main(int argc, char **argv)
{
    Args a = {0};
    parse(argc, argv, &a);
    if (!a.data)
        a.data = getenv("RAYES_DATA");
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", a.out, a.mode);
    FILE *j = fopen(path, "w");
    if (!j)
        die("cannot write the JSON record");
    if (strcmp(a.mode, "table1") == 0)
        table1(&a, j);
    else if (strcmp(a.mode, "table2") == 0)
        table2(&a, j);
    else if (strcmp(a.mode, "figure5") == 0) {
        figure5(&a, j);
        a.accuracy_spp = -1; /* its JSON is closed */
    }
    else
        table4(&a, j);
    if (a.accuracy_spp > 0 && strcmp(a.mode, "table2") != 0)
        bias(&a, j);
    else if (a.accuracy_spp == 0 || strcmp(a.mode, "table2") == 0)
        fprintf(j, "\n}\n");
    fclose(j);
    printf("wrote %s and the images beside it\n", path);
    return 0;
}
