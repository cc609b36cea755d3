/*
 * bench/instances.c — issue 18's instancing target: 10,000 instances of
 * an object of about 100,000 micropolygons prepare in under 1 GB and
 * render at 512 x 512 (memo 3.1: the instances share the master's
 * tessellation, each has its own radiosity cache entries).
 *
 * The scene: a floor lit by a distant light and a 100 x 100 field of
 * balls (a sphere whose dicing the shading rate sets: 1, the default,
 * makes about 110,000 micropolygons at 512 x 512), every instance with a colour of its own
 * (a shader made before it), the nearest close to the camera so that the
 * master is diced for it. With --flatten the same balls are placed as
 * copies (rayes_scene_sphere under each transform), for comparison at
 * small counts.
 *
 *   instances [--count 10000] [--size 512] [--spp 4] [--threads 2]
 *             [--rate 1] [--flatten] [--out FILE.png]
 *
 * Prints the instances, the master's grids, micropolygons and vertices,
 * the vertices flattened copies would need, the radiosity fills per
 * instance, the prepare and render times and the peak resident memory,
 * from the render's statistics.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "rayes/rayes.h"

typedef struct Args {
    int count, size, spp, threads, flatten;
    float rate;
    const char *out;
} Args;

static void die(const char *msg)
{
    fprintf(stderr, "instances: %s\n", msg);
    exit(2);
}

static Args parse(int argc, char **argv)
{
    Args a = {10000, 512, 4, 2, 0, 1.0f, NULL};
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(o, "--flatten")) {
            a.flatten = 1;
            continue;
        }
        if (!v)
            die("an option lacks its value");
        if (!strcmp(o, "--count"))
            a.count = atoi(v);
        else if (!strcmp(o, "--size"))
            a.size = atoi(v);
        else if (!strcmp(o, "--spp"))
            a.spp = atoi(v);
        else if (!strcmp(o, "--threads"))
            a.threads = atoi(v);
        else if (!strcmp(o, "--rate"))
            a.rate = (float)atof(v);
        else if (!strcmp(o, "--out"))
            a.out = v;
        else
            die("unknown option");
        i++;
    }
    if (a.count < 1 || a.count > 1000000 || a.size < 8 || a.spp < 1 || a.threads < 0 ||
        !(a.rate > 0))
        die("an option is out of range");
    return a;
}

static void check(RayesScene *s, RayesError e)
{
    if (e != RAYES_OK) {
        fprintf(stderr, "instances: %s\n", rayes_scene_get_error(s));
        exit(1);
    }
}

/* A colour per instance from its index (deterministic). */
static void colour(int i, float c[3])
{
    unsigned h = (unsigned)i * 2654435761u;
    for (int k = 0; k < 3; k++, h = h * 1103515245u + 12345u)
        c[k] = 0.25f + 0.7f * (float)((h >> 16) & 255) / 255.0f;
}

static RayesScene *build(const Args *a)
{
    RayesScene *s = rayes_scene_new();
    int side = (int)ceil(sqrt((double)a->count));
    float extent = 2.0f * (float)side;
    const float eye[3] = {0, 2.0f, -3.0f}, at[3] = {0, 0.6f, 4.0f}, up[3] = {0, 1, 0};
    check(s, rayes_scene_set_camera(s, eye, at, up, 50.0f));
    RayesParam dl[2] = {{"intensity", RAYES_PARAM_FLOAT, {2.5f, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0.3f, -1.0f, 0.5f}, NULL}};
    check(s, rayes_scene_light(s, "distantlight", dl, 2));
    RayesParam white = {"Cs", RAYES_PARAM_COLOR, {0.8f, 0.8f, 0.8f}, NULL};
    check(s, rayes_scene_set_shader(s, "matte", &white, 1));
    const float floor[4][3] = {
        {-extent, 0, -4}, {extent, 0, -4}, {-extent, 0, extent}, {extent, 0, extent}};
    check(s, rayes_scene_bilinear_patch(s, floor));
    check(s, rayes_scene_set_shading_rate(s, a->rate));
    if (!a->flatten) {
        check(s, rayes_scene_object_begin(s, "ball"));
        check(s, rayes_scene_sphere(s, 0.6f));
        check(s, rayes_scene_object_end(s));
    }
    for (int i = 0; i < a->count; i++) {
        float x = 2.0f * (float)(i % side) - (float)side + 1.0f, z = 2.0f * (float)(i / side);
        const float m[16] = {1, 0, 0, x, 0, 1, 0, 0.6f, 0, 0, 1, z, 0, 0, 0, 1};
        RayesParam c = {"Cs", RAYES_PARAM_COLOR, {0, 0, 0}, NULL};
        colour(i, c.value);
        check(s, rayes_scene_set_shader(s, "matte", &c, 1));
        check(s, rayes_scene_set_transform(s, m));
        check(s, a->flatten ? rayes_scene_sphere(s, 0.6f) : rayes_scene_object_instance(s, "ball"));
    }
    const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    check(s, rayes_scene_set_transform(s, id));
    check(s, rayes_scene_commit(s));
    return s;
}

static double real_stat(const RayesStats *st, const char *name)
{
    const RayesStat *x = rayes_stats_find(st, name);
    return !x ? 0.0 : x->kind == RAYES_STAT_REAL ? x->real : (double)x->count;
}

int main(int argc, char **argv)
{
    Args a = parse(argc, argv);
    RayesScene *s = build(&a);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = a.size;
    o.spp = a.spp;
    o.threads = a.threads;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    if (rayes_render(s, &o, &img, &st) != RAYES_OK)
        die(rayes_scene_get_error(s));
    printf("%s: %d balls at %d x %d, %d spp, %d threads, shading rate %g\n",
           a.flatten ? "flattened copies" : "instances", a.count, a.size, a.size, a.spp, a.threads,
           (double)a.rate);
    static const char *const names[] = {"instances/count",
                                        "instances/master_grids",
                                        "instances/master_micropolygons",
                                        "instances/master_vertices",
                                        "instances/flattened_vertices",
                                        "grids",
                                        "grid_vertices",
                                        "instances/radiosity_fills",
                                        "instances/radiosity_entries_per_instance",
                                        "memory/grid_bytes",
                                        "memory/accel_bytes",
                                        "time/prepare_s",
                                        "time/render_s",
                                        "memory/peak_rss_bytes"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++)
        printf("  %-42s %.6g\n", names[k], real_stat(st, names[k]));
    printf("  peak resident: %.1f MB\n", real_stat(st, "memory/peak_rss_bytes") / 1e6);
    char err[256];
    if (a.out &&
        image_write(a.out, img->width, img->height, img->rgba, err, sizeof err) != RAYES_OK)
        die(err);
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
    return 0;
}
