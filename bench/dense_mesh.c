/*
 * bench/dense_mesh.c — a scanned-looking mesh far denser than the pixels:
 * a bumpy sphere of 2 n^2 triangles (one polygon mesh, as a PLY or an OBJ
 * file gives it) under a distant light, each triangle well below a
 * micropolygon, so every face is one grid of three vertices. Prints the
 * preparation time (dicing, stitching, Embree), the grids and vertices,
 * the vertex budget's coarsening, the render time and the peak resident
 * memory (docs/performance.md "Dense meshes").
 *
 *   dense_mesh [--millions 2] [--res 256] [--spp 4] [--threads 2]
 *              [--budget 20] [--out FILE.png]
 *
 * --millions gives the triangles, in millions (0.01 to 64); --budget the
 * vertex budget in millions (--vertex-budget). Exits 1 when the render
 * fails (a scene too big for the memory left is refused, not killed).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "rayes/rayes.h"

typedef struct Args {
    double millions, budget;
    int res, spp, threads;
    const char *out;
} Args;

static void die(const char *msg)
{
    fprintf(stderr, "dense_mesh: %s\n", msg);
    exit(2);
}

static Args parse(int argc, char **argv)
{
    Args a = {2.0, 20.0, 256, 4, 2, NULL};
    for (int i = 1; i < argc; i += 2) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            die("an option lacks its value");
        if (!strcmp(o, "--millions"))
            a.millions = atof(v);
        else if (!strcmp(o, "--budget"))
            a.budget = atof(v);
        else if (!strcmp(o, "--res"))
            a.res = atoi(v);
        else if (!strcmp(o, "--spp"))
            a.spp = atoi(v);
        else if (!strcmp(o, "--threads"))
            a.threads = atoi(v);
        else if (!strcmp(o, "--out"))
            a.out = v;
        else
            die("usage: dense_mesh [--millions M] [--res N] [--spp N] [--threads N] "
                "[--budget M] [--out FILE.png]");
    }
    if (!(a.millions >= 0.01 && a.millions <= 64) || !(a.budget >= 0) || a.res < 8 ||
        a.res > 8192 || a.spp < 1 || a.threads < 0)
        die("an option is out of range");
    return a;
}

static void check(RayesScene *s, RayesError e)
{
    if (e != RAYES_OK) {
        fprintf(stderr, "dense_mesh: %s\n", rayes_scene_get_error(s));
        exit(1);
    }
}

/* The sphere's (n + 1)^2 points, radius 1 with bumps of 5%, and its 2 n^2
 * triangles (the poles' rows degenerate, as a scan's seldom are). */
static void add_mesh(RayesScene *s, int n)
{
    size_t m = (size_t)n + 1, faces = 2 * (size_t)n * n;
    float *P = malloc(3 * m * m * sizeof *P);
    int *nv = malloc(faces * sizeof *nv), *idx = malloc(3 * faces * sizeof *idx);
    if (!P || !nv || !idx)
        die("out of memory");
    for (size_t j = 0; j < m; j++)
        for (size_t i = 0; i < m; i++) {
            double th = 2.0 * M_PI * (double)i / n, ph = M_PI * (double)j / n;
            double r = 1.0 + 0.05 * sin(40.0 * th) * sin(30.0 * ph);
            float *p = &P[3 * (j * m + i)];
            p[0] = (float)(r * sin(ph) * cos(th));
            p[1] = (float)(r * cos(ph));
            p[2] = (float)(r * sin(ph) * sin(th));
        }
    size_t f = 0;
    for (size_t j = 0; j < (size_t)n; j++)
        for (size_t i = 0; i < (size_t)n; i++, f += 2) {
            int a = (int)(j * m + i), b = a + 1, c = a + (int)m + 1, d = a + (int)m;
            const int tri[6] = {a, c, b, a, d, c};
            memcpy(&idx[3 * f], tri, sizeof tri);
            nv[f] = nv[f + 1] = 3;
        }
    check(s, rayes_scene_polygon_mesh(s, faces, nv, idx, m * m, P));
    free(P), free(nv), free(idx);
}

static double stat(const RayesStats *st, const char *name)
{
    const RayesStat *x = rayes_stats_find(st, name);
    return !x ? 0.0 : x->kind == RAYES_STAT_REAL ? x->real : (double)x->count;
}

int main(int argc, char **argv)
{
    Args a = parse(argc, argv);
    int n = (int)ceil(sqrt(a.millions * 1e6 / 2.0));
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1.0f, -3.2f}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    check(s, rayes_scene_set_camera(s, eye, at, up, 40.0f));
    RayesParam dl[2] = {{"intensity", RAYES_PARAM_FLOAT, {3.0f, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {-0.3f, -1.0f, 0.6f}, NULL}};
    check(s, rayes_scene_light(s, "distantlight", dl, 2));
    RayesParam grey = {"Cs", RAYES_PARAM_COLOR, {0.6f, 0.6f, 0.6f}, NULL};
    check(s, rayes_scene_set_shader(s, "matte", &grey, 1));
    add_mesh(s, n);
    check(s, rayes_scene_commit(s));
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = a.res;
    o.spp = a.spp;
    o.threads = a.threads;
    o.vertex_budget = a.budget * 1e6;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    printf("dense mesh: %zu triangles, %d x %d, %d spp, %d threads, vertex budget %.0f M\n",
           2 * (size_t)n * n, a.res, a.res, a.spp, a.threads, a.budget);
    check(s, rayes_render(s, &o, &img, &st));
    printf("  prepare %.2f s, render %.2f s\n", stat(st, "time/prepare_s"),
           stat(st, "time/render_s"));
    printf("  grids %.0f, grid vertices %.0f, coarsened x%.2f\n", stat(st, "grids"),
           stat(st, "grid_vertices"), stat(st, "dicing/coarsened"));
    printf("  grid bytes %.1f MB, Embree %.1f MB, peak resident %.1f MB\n",
           stat(st, "memory/grid_bytes") / 1e6, stat(st, "memory/accel_bytes") / 1e6,
           stat(st, "memory/peak_rss_bytes") / 1e6);
    char err[300];
    if (a.out && image_write(a.out, img->width, img->height, img->rgba, err, sizeof err) != 0)
        fprintf(stderr, "dense_mesh: %s\n", err);
    rayes_image_free(img);
    rayes_stats_free(st);
    rayes_scene_release(s);
    return 0;
}
