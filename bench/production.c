/*
 * bench/production.c — the memo's production claim (section 5.4, Tables 3
 * and 4) on the built-in scene production-room: a furnished interior with
 * 20 lights, textures, procedural wood and brick, displaced walls and
 * floor (io/builtin_room.c). Caching off and on at 0 (direct), 1 and 2
 * bounces, measured in one run so that ratios are taken on one machine
 * state.
 *
 *   production [--size WxH] [--spp N] [--shadow-rays N] [--diffuse-rays N]
 *              [--diffuse-rays-deep N] [--bounces-max B] [--uncached 0|1]
 *              [--tiles K | --uncached-sample F] [--threads N] [--cache-mb MB]
 *              [--out DIR]
 *
 * Defaults: 1280 x 720, 1 pixel sample, 8 shadow rays per area light and
 * point (delta lights take one; the environment light counts as an area
 * light), 256 diffuse rays per camera hit (the memo's production scenes
 * use 256-1024) and 16 deeper (what a cache fill traces), branch depth 1
 * (rayes's default: an uncached diffuse hit below depth 1 traces one
 * diffuse ray, so the uncached two-bounce render costs a path tracer's
 * continuation, not a tree), a 100 MB cache.
 *
 * Rows: direct illumination (0 bounces), then 1..B bounces with caching
 * off and on, each a whole frame of --size. An uncached frame at these
 * settings costs about 8 ms of CPU per pixel on this machine (hours at
 * 1280 x 720), so docs/performance.md measures the pairs at a reduced
 * --size and the cached rows alone (--uncached 0) at 1280 x 720.
 * --tiles K renders one 32 x 32 tile in K, spread over the frame by a
 * stratified pattern (rayes's tile_source; each pixel bit for bit what
 * the whole frame has there), for quick looks: the cache then fills the
 * grids those tiles' rays reach for fewer pixels, so a subset's speed-up
 * understates the whole frame's. Pictures go to DIR/production-bB-*.png.
 *
 * --uncached-sample F (0 < F < 1) renders the cached rows whole and the
 * uncached ones on a stratified random sample of about F of the 32 x 32
 * tiles (one drawn in each of as many blocks of the frame), timing each
 * tile by its thread's CPU clock; an uncached pixel does not depend on
 * any other (there is no cache), so the whole frame's CPU time is
 * estimated as the render's CPU outside the tiles (scene, dicing) plus
 * the tiles' CPU per pixel times the frame's pixels, with the standard
 * error of that estimate (docs/performance.md, "Production scene").
 *
 * Bias: the cached and uncached frames (or subsets) compared as the other benches
 * compare whole images: the relative difference of their means, and the
 * largest relative difference of the means of one 32 x 32 tile.
 * A JSON record of every row goes to DIR/production.json (DIR: --out,
 * default bench-out).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <time.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"

#define TILE 32

typedef struct Args {
    int width, height, spp, shadow_rays, diffuse_rays, diffuse_rays_deep, tiles, bounces_max;
    int uncached, threads;
    double cache_mb, uncached_sample;
    const char *out;
} Args;

typedef struct Row {
    int bounces, cache, subset;
    double time_s, cpu_s, peak_mb, grid_mb, accel_mb;
    unsigned long long shading_points, rays, shadow, diffuse, specular, grids, vertices;
    double hit[3];
    float *rgba;
    int w, h;
    double fixed_cpu_s, est_cpu_s, est_se_s; /* --uncached-sample: outside the tiles, frame */
} Row;

static void die(const char *msg)
{
    fprintf(stderr, "production: %s\n", msg);
    exit(1);
}

/* The stratified subset of --tiles K: tile (x, y) when (x + 5 y) mod K
 * is 0, for K > 1: one tile in K of every row, shifted from row to row. */
static int subset_tile(int tx, int ty, int k)
{
    return k <= 1 || (tx + 5 * ty) % k == 0;
}

/* The tiles a render takes, in order, and (--uncached-sample) the CPU
 * time of each: the source callback runs on the worker thread that will
 * render the tile it returns (render.c), and tile_done on the same
 * thread as that tile ends, so the thread's CPU clock between the two is
 * the tile's. */
typedef struct Sample {
    int k;             /* --tiles K; 0 with a list */
    int *tiles, count; /* --uncached-sample: tile indices, ascending */
    int next;          /* the next tile of the list or the frame */
    int generation;    /* this render's, to reset the threads' clocks */
    double *cpu_s;     /* per tile of the list: thread CPU seconds */
} Sample;

static _Thread_local int clock_generation = -1, clock_tile = -1;
static _Thread_local double clock_start;

static double thread_cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int sample_source(void *user, int tiles_x, int tiles_y)
{
    Sample *s = user;
    clock_generation = s->generation;
    clock_tile = -1;
    clock_start = thread_cpu_seconds();
    if (s->tiles) {
        if (s->next >= s->count)
            return -1;
        clock_tile = s->next++;
        return s->tiles[clock_tile];
    }
    while (s->next < tiles_x * tiles_y) {
        int i = s->next++;
        if (subset_tile(i % tiles_x, i / tiles_x, s->k))
            return i;
    }
    return -1;
}

/* Called by the render as each tile ends, on its thread (several tiles
 * at once, each thread writing its own tile's entry). */
static void sample_tile_done(void *user, int x, int y, int w, int h, const float *rgba, int stride)
{
    (void)x, (void)y, (void)w, (void)h, (void)rgba, (void)stride;
    Sample *s = user;
    if (clock_generation == s->generation && clock_tile >= 0 && s->cpu_s)
        s->cpu_s[clock_tile] += thread_cpu_seconds() - clock_start;
    clock_tile = -1;
}

/* --uncached-sample F: a stratified random sample of the frame's
 * TILE x TILE tiles, about F of them: the tile grid cut into as many
 * nearly square blocks (strata), one tile drawn in each by a fixed
 * seed. Returns the count; *tiles (ascending) is the caller's. */
static int sample_tiles(int tiles_x, int tiles_y, double fraction, int **tiles)
{
    int n = (int)lround(fraction * tiles_x * tiles_y);
    n = n < 2 ? 2 : n > tiles_x * tiles_y ? tiles_x * tiles_y : n;
    int sy = (int)lround(sqrt((double)n * tiles_y / tiles_x));
    sy = sy < 1 ? 1 : sy > tiles_y ? tiles_y : sy;
    int sx = (n + sy - 1) / sy;
    sx = sx > tiles_x ? tiles_x : sx;
    *tiles = malloc(sizeof **tiles * (size_t)sx * sy);
    if (!*tiles)
        die("out of memory");
    unsigned long long seed = 0x9e3779b97f4a7c15ull;
    int count = 0;
    for (int by = 0; by < sy; by++)
        for (int bx = 0; bx < sx; bx++) {
            int x0 = bx * tiles_x / sx, x1 = (bx + 1) * tiles_x / sx;
            int y0 = by * tiles_y / sy, y1 = (by + 1) * tiles_y / sy;
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            int x = x0 + (int)((seed >> 33) % (unsigned long long)(x1 - x0));
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            int y = y0 + (int)((seed >> 33) % (unsigned long long)(y1 - y0));
            (*tiles)[count++] = y * tiles_x + x;
        }
    for (int i = 1; i < count; i++) /* insertion sort: the frame's order */
        for (int j = i; j > 0 && (*tiles)[j - 1] > (*tiles)[j]; j--) {
            int t = (*tiles)[j];
            (*tiles)[j] = (*tiles)[j - 1];
            (*tiles)[j - 1] = t;
        }
    return count;
}

static double cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * ru.ru_stime.tv_usec;
}

static unsigned long long count(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return s ? s->count : 0;
}

static double real(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return s ? s->real : 0.0;
}

/* The whole frame's CPU time from the sample's (a ratio estimator): the
 * render's CPU outside the tiles (scene, dicing, threads) is paid once,
 * a tile's in proportion to its pixels. The standard error is simple
 * random sampling's, without replacement; one tile drawn per stratum
 * has at most that variance when neighbouring tiles cost alike. */
static void estimate(const Args *a, const Sample *s, int tiles_x, Row *r)
{
    double t = 0.0, p = 0.0;
    for (int i = 0; i < s->count; i++) {
        int x0 = s->tiles[i] % tiles_x * TILE, y0 = s->tiles[i] / tiles_x * TILE;
        t += s->cpu_s[i];
        p += (double)(fmin(x0 + TILE, a->width) - x0) * (fmin(y0 + TILE, a->height) - y0);
    }
    double rate = t / p, ss = 0.0, pixels = (double)a->width * a->height;
    for (int i = 0; i < s->count; i++) {
        int x0 = s->tiles[i] % tiles_x * TILE, y0 = s->tiles[i] / tiles_x * TILE;
        double pi = (fmin(x0 + TILE, a->width) - x0) * (fmin(y0 + TILE, a->height) - y0);
        ss += (s->cpu_s[i] - rate * pi) * (s->cpu_s[i] - rate * pi);
    }
    int n = s->count;
    double tiles = (double)tiles_x * ((a->height + TILE - 1) / TILE), mean_p = p / n;
    double var = n > 1 ? (1.0 - n / tiles) * ss / (n - 1) / n / (mean_p * mean_p) : 0.0;
    for (int i = 0; i < s->count; i++)
        if (!(s->cpu_s[i] > 0.0))
            die("a sampled tile was not timed");
    r->fixed_cpu_s = r->cpu_s - t;
    r->est_cpu_s = r->fixed_cpu_s + rate * pixels;
    r->est_se_s = sqrt(var) * pixels;
}

/* subset: 0 the whole frame, 1 --tiles K's tiles, 2 --uncached-sample's
 * (the frame's CPU time then estimated from theirs: fixed_cpu_s, est_*). */
static Row run(const Args *a, int bounces, int cache, int subset)
{
    static int generation;
    RayesScene *scene = rayes_scene_new();
    char err[1024];
    if (!scene)
        die("out of memory");
    IoSink sink = io_sink_scene(scene);
    if (io_builtin_scene("production-room", NULL, &sink, err, sizeof err) != RAYES_OK)
        die(err);
    if (rayes_scene_commit(scene) != RAYES_OK)
        die(rayes_scene_get_error(scene));
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = a->width;
    o.height = a->height;
    o.spp = a->spp;
    o.threads = a->threads;
    o.bounces = bounces;
    o.shadow_rays = o.shadow_rays_deep = a->shadow_rays;
    o.diffuse_rays = a->diffuse_rays;
    o.diffuse_rays_deep = a->diffuse_rays_deep;
    o.cache = cache;
    o.cache_mb = a->cache_mb;
    o.tile_size = TILE;
    int tiles_x = (a->width + TILE - 1) / TILE, tiles_y = (a->height + TILE - 1) / TILE;
    Sample sample = {.k = a->tiles, .generation = ++generation};
    if (subset == 2) {
        sample.count = sample_tiles(tiles_x, tiles_y, a->uncached_sample, &sample.tiles);
        sample.cpu_s = calloc((size_t)sample.count, sizeof *sample.cpu_s);
        if (!sample.cpu_s)
            die("out of memory");
    }
    if (subset == 2 || (subset && a->tiles > 1)) {
        o.tile_source = sample_source;
        o.tile_source_user = &sample;
        o.tile_done = sample_tile_done;
        o.tile_user = &sample;
    }
    RayesImage *img;
    RayesStats *st;
    double cpu0 = cpu_seconds();
    if (rayes_render(scene, &o, &img, &st) != RAYES_OK)
        die(rayes_scene_get_error(scene));
    Row r = {.bounces = bounces, .cache = cache, .subset = subset == 2 ? 2 : subset && a->tiles > 1};
    r.cpu_s = cpu_seconds() - cpu0;
    if (subset == 2)
        estimate(a, &sample, tiles_x, &r);
    free(sample.tiles);
    free(sample.cpu_s);
    r.time_s = real(st, "time/total_s");
    r.peak_mb = 1e-6 * (double)count(st, "memory/peak_rss_bytes");
    r.grid_mb = 1e-6 * (double)count(st, "memory/grid_bytes");
    r.accel_mb = 1e-6 * (double)count(st, "memory/accel_bytes");
    r.shading_points = count(st, "shading_points/total");
    r.rays = count(st, "rays/total");
    r.shadow = count(st, "rays/shadow");
    r.diffuse = count(st, "rays/diffuse");
    r.specular = count(st, "rays/specular");
    r.grids = count(st, "grids");
    r.vertices = count(st, "grid_vertices");
    static const char *const hr[3] = {"cache/coarse/hit_rate", "cache/medium/hit_rate",
                                      "cache/fine/hit_rate"};
    for (int l = 0; l < 3; l++)
        r.hit[l] = cache ? real(st, hr[l]) : 0.0;
    r.rgba = img->rgba;
    r.w = img->width;
    r.h = img->height;
    img->rgba = NULL;
    rayes_image_free(img);
    rayes_stats_free(st);
    rayes_scene_release(scene);
    return r;
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

/* Bias of on against off over the tiles both rendered (whole 32 x 32
 * tiles only): the relative difference of the means, and the largest of
 * one tile's (black tiles have no relative error). */
static void bias(const Args *a, const Row *on, const Row *off, double *mean_rel, double *tile_rel,
                 char *where, size_t where_size)
{
    int tiles_x = (a->width + TILE - 1) / TILE, tiles_y = (a->height + TILE - 1) / TILE;
    int *list = NULL, count = 0;
    if (off->subset == 2)
        count = sample_tiles(tiles_x, tiles_y, a->uncached_sample, &list);
    double s_on = 0.0, s_off = 0.0;
    *tile_rel = 0.0;
    int n = 0;
    for (int ty = 0; (ty + 1) * TILE <= on->h; ty++)
        for (int tx = 0; (tx + 1) * TILE <= on->w; tx++) {
            int in = !list && subset_tile(tx, ty, a->tiles);
            for (int i = 0; i < count; i++)
                in |= list[i] == ty * tiles_x + tx;
            if (!in)
                continue;
            double x = region_mean(on, tx * TILE, ty * TILE, TILE, TILE);
            double y = region_mean(off, tx * TILE, ty * TILE, TILE, TILE);
            s_on += x;
            s_off += y;
            n++;
            if (y > 1e-4 && fabs(x - y) / y > *tile_rel) {
                *tile_rel = fabs(x - y) / y;
                snprintf(where, where_size, "tile at (%d, %d): cached %.4f, uncached %.4f",
                         tx * TILE, ty * TILE, x, y);
            }
        }
    free(list);
    *mean_rel = n && s_off > 0.0 ? fabs(s_on - s_off) / s_off : 0.0;
}

static void save(const Args *a, const Row *r)
{
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/production-b%d%s-%s.png", a->out, r->bounces,
             r->subset == 2 ? "-sample" : r->subset ? "-tiles" : "", r->cache ? "cached" : "uncached");
    if (image_write(path, r->w, r->h, r->rgba, err, sizeof err) != RAYES_OK)
        die(err);
}

static const char *label(const Row *r)
{
    static char buf[32];
    snprintf(buf, sizeof buf, "%s %s",
             r->bounces == 0   ? "direct"
             : r->bounces == 1 ? "1 bounce"
                               : "2 bounces",
             r->bounces == 0 ? ""
             : r->cache      ? "on"
                             : "off");
    return buf;
}

/* One line of the memo's Table 3 (rays by type, memory, time) with Table
 * 4's shading points and hit rates. */
static void print_row(const Row *r)
{
    char sh[32], df[32], sp[32], pts[32];
    human(sh, sizeof sh, (double)r->shadow);
    human(df, sizeof df, (double)r->diffuse);
    human(sp, sizeof sp, (double)r->specular);
    human(pts, sizeof pts, (double)r->shading_points);
    printf("%-14s | %8s %8s %7s | %8s | %7.0f MB | %8.1fs %8.1fs |", label(r), sh, df, sp, pts,
           r->peak_mb, r->time_s, r->cpu_s);
    if (r->cache && r->bounces > 0)
        printf(" %5.2f / %5.2f / %5.2f\n", 100 * r->hit[0], 100 * r->hit[1], 100 * r->hit[2]);
    else
        printf(" -\n");
    fflush(stdout);
}

static void json_row(FILE *j, const Row *r, int first)
{
    fprintf(j,
            "%s\n    {\"bounces\": %d, \"cache\": %d, \"subset\": %d, \"time_s\": %.3f, "
            "\"cpu_s\": %.3f, \"peak_rss_mb\": %.1f, \"grid_mb\": %.1f, \"accel_mb\": %.1f, "
            "\"shading_points\": %llu, \"rays\": %llu, \"shadow_rays\": %llu, "
            "\"diffuse_rays\": %llu, \"specular_rays\": %llu, \"grids\": %llu, "
            "\"grid_vertices\": %llu, \"hit_rate\": {\"coarse\": %.5f, \"medium\": %.5f, "
            "\"fine\": %.5f}, \"frame_cpu_estimate_s\": %.3f, \"frame_cpu_se_s\": %.3f, "
            "\"outside_tiles_cpu_s\": %.3f}",
            first ? "" : ",", r->bounces, r->cache, r->subset, r->time_s, r->cpu_s, r->peak_mb,
            r->grid_mb, r->accel_mb, r->shading_points, r->rays, r->shadow, r->diffuse, r->specular,
            r->grids, r->vertices, r->hit[0], r->hit[1], r->hit[2],
            r->subset == 2 ? r->est_cpu_s : r->cpu_s, r->est_se_s, r->fixed_cpu_s);
}

static int parse_size(const char *v, int *w, int *h)
{
    return sscanf(v, "%dx%d", w, h) == 2 && *w >= TILE && *h >= TILE;
}

static void parse(int argc, char **argv, Args *a)
{
    *a = (Args){1280, 720, 1, 8, 256, 16, 1, 2, 1, 0, 100.0, 0.0, "bench-out"};
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *o = argv[i], *v = argv[i + 1];
        if (strcmp(o, "--size") == 0) {
            if (!parse_size(v, &a->width, &a->height))
                die("--size WxH, each at least 32");
        } else if (strcmp(o, "--spp") == 0)
            a->spp = atoi(v);
        else if (strcmp(o, "--shadow-rays") == 0)
            a->shadow_rays = atoi(v);
        else if (strcmp(o, "--diffuse-rays") == 0)
            a->diffuse_rays = atoi(v);
        else if (strcmp(o, "--diffuse-rays-deep") == 0)
            a->diffuse_rays_deep = atoi(v);
        else if (strcmp(o, "--tiles") == 0)
            a->tiles = atoi(v);
        else if (strcmp(o, "--bounces-max") == 0)
            a->bounces_max = atoi(v);
        else if (strcmp(o, "--uncached") == 0)
            a->uncached = atoi(v);
        else if (strcmp(o, "--threads") == 0)
            a->threads = atoi(v);
        else if (strcmp(o, "--uncached-sample") == 0)
            a->uncached_sample = atof(v);
        else if (strcmp(o, "--cache-mb") == 0)
            a->cache_mb = atof(v);
        else if (strcmp(o, "--out") == 0)
            a->out = v;
        else
            die("unknown option (see the comment at the top of bench/production.c)");
    }
    if (argc % 2 == 0 || a->spp < 1 || a->shadow_rays < 1 || a->diffuse_rays < 1 ||
        a->diffuse_rays_deep < 1 || a->tiles < 1 || a->bounces_max < 1 || a->bounces_max > 4 ||
        a->cache_mb <= 0.0 || !(a->uncached_sample >= 0.0 && a->uncached_sample < 1.0) ||
        (a->uncached_sample > 0.0 && a->tiles > 1))
        die("usage: production [--size WxH] [--spp N] [--tiles K] ... (see bench/production.c)");
    if (mkdir(a->out, 0777) != 0 && errno != EEXIST)
        die("cannot create the output directory");
}

int main(int argc, char **argv)
{
    Args a;
    parse(argc, argv, &a);
    char path[1024];
    snprintf(path, sizeof path, "%s/production.json", a.out);
    FILE *j = fopen(path, "w");
    if (!j)
        die("cannot write the JSON record");
    printf("production-room, %dx%d, %d spp, %d shadow rays per area light, %d diffuse rays (%d "
           "deeper), %d threads\n",
           a.width, a.height, a.spp, a.shadow_rays, a.diffuse_rays, a.diffuse_rays_deep, a.threads);
    printf("%s%s\n\n", a.tiles > 1 ? "one 32x32 tile in --tiles of the frame" : "the whole frame",
           a.uncached ? "" : ", cached rows only");
    printf("%-14s | %8s %8s %7s | %8s | %10s | %9s %9s | %s\n", "illumination", "shadow", "diffuse",
           "spec", "sh.pts", "peak mem", "time", "cpu", "hit % coarse/medium/fine");
    fprintf(j,
            "{\"scene\": \"production-room\", \"width\": %d, \"height\": %d, \"spp\": %d, "
            "\"shadow_rays\": %d, \"diffuse_rays\": %d, \"diffuse_rays_deep\": %d, \"tiles\": %d, "
            "\"rows\": [",
            a.width, a.height, a.spp, a.shadow_rays, a.diffuse_rays, a.diffuse_rays_deep, a.tiles);
    Row direct = run(&a, 0, 1, 1);
    print_row(&direct);
    printf("    %llu grids, %llu grid vertices (grids %.0f MB, ray tracing %.0f MB)\n",
           direct.grids, direct.vertices, direct.grid_mb, direct.accel_mb);
    json_row(j, &direct, 1);
    save(&a, &direct);
    free(direct.rgba);
    Row off[5] = {{0}}, on[5] = {{0}};
    for (int b = 1; b <= a.bounces_max; b++) {
        if (a.uncached) {
            off[b] = run(&a, b, 0, a.uncached_sample > 0.0 ? 2 : 1);
            print_row(&off[b]);
            if (off[b].subset == 2)
                printf("%-14s   whole frame estimated from the sample: %.1fs cpu +- %.1fs (one "
                       "standard error; %.1fs outside the tiles)\n",
                       "", off[b].est_cpu_s, off[b].est_se_s, off[b].fixed_cpu_s);
            save(&a, &off[b]);
            json_row(j, &off[b], 0);
        }
        on[b] = run(&a, b, 1, 1);
        print_row(&on[b]);
        save(&a, &on[b]);
        json_row(j, &on[b], 0);
    }
    printf("\n");
    for (int b = 1; b <= a.bounces_max; b++) {
        if (a.uncached) {
            double mrel, trel;
            char where[160] = "";
            bias(&a, &on[b], &off[b], &mrel, &trel, where, sizeof where);
            if (off[b].subset == 2) {
                double x = off[b].est_cpu_s / on[b].cpu_s, e = off[b].est_se_s / on[b].cpu_s;
                printf("%d bounce%s: speed-up (cpu, uncached frame estimated) %.1f +- %.1f; "
                       "cached vs uncached on the sample's tiles: mean %.3f%%, worst 32x32 tile "
                       "%.3f%% (%s)\n",
                       b, b > 1 ? "s" : "", x, e, 100 * mrel, 100 * trel, where);
            } else
                printf("%d bounce%s: speed-up %.1f (cpu %.1f); cached vs uncached: mean %.3f%%, "
                       "worst 32x32 tile %.3f%% (%s)\n",
                       b, b > 1 ? "s" : "", off[b].time_s / on[b].time_s,
                       off[b].cpu_s / on[b].cpu_s, 100 * mrel, 100 * trel, where);
            double off_cpu = off[b].subset == 2 ? off[b].est_cpu_s : off[b].cpu_s;
            fprintf(j,
                    ",\n    {\"bias_bounces\": %d, \"mean_rel\": %.6f, \"max_tile_rel\": %.6f, "
                    "\"speedup\": %.3f, \"speedup_cpu\": %.3f, \"speedup_cpu_se\": %.3f}",
                    b, mrel, trel, off[b].time_s / on[b].time_s, off_cpu / on[b].cpu_s,
                    off[b].est_se_s / on[b].cpu_s);
        }
        if (b > 1) {
            printf("    cached %d bounces / 1 bounce: %.2f (cpu %.2f)", b,
                   on[b].time_s / on[1].time_s, on[b].cpu_s / on[1].cpu_s);
            if (a.uncached && off[b].subset == 2)
                printf("; uncached (cpu, frames estimated) %.2f",
                       off[b].est_cpu_s / off[1].est_cpu_s);
            else if (a.uncached)
                printf("; uncached %.2f (cpu %.2f)", off[b].time_s / off[1].time_s,
                       off[b].cpu_s / off[1].cpu_s);
            printf("\n");
        }
        free(off[b].rgba);
        free(on[b].rgba);
    }
    fflush(stdout);
    fprintf(j, "\n  ]\n}\n");
    fclose(j);
    printf("wrote %s and the images beside it\n", path);
    return 0;
}
