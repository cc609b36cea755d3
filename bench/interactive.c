/*
 * bench/interactive.c — interactive preview figures (README "Performance"):
 * a progressive session on cornell-teapots, preview quality, 1 bounce,
 * timed pass by pass to 16 samples per pixel after the start, after a
 * camera move (radiosity cache kept) and after a light edit (cache
 * invalidated by its timestamp), with hit rates; then the edited session
 * refined to 64 samples and compared with a fresh render of the edited
 * scene.
 *
 *   interactive [--size N] [--passes N] [--final-spp N] [--bounces N] [--threads N]
 *               [--data DIR] [--out DIR]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "util/log.h"

typedef struct Phase {
    const char *name;
    double update_s;              /* rayes_session_update (or new) */
    double pass_s[1024];
    double hit[3];                /* first pass */
    double fills;                 /* first pass, all resolutions */
    double shading_points;        /* first pass */
    int n;
} Phase;

static double stat_of(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return !s ? 0.0 : s->kind == RAYES_STAT_REAL ? s->real : (double)s->count;
}

static void run_passes(RayesSession *ss, Phase *p, int passes)
{
    for (int i = 0; i < passes; i++) {
        double t0 = time_now();
        if (rayes_session_render_pass(ss) != RAYES_OK) {
            fprintf(stderr, "interactive: a pass failed\n");
            exit(1);
        }
        p->pass_s[p->n++] = time_now() - t0;
        if (i == 0) {
            RayesStats *st = NULL;
            rayes_session_stats(ss, &st);
            p->hit[0] = stat_of(st, "cache/coarse/hit_rate");
            p->hit[1] = stat_of(st, "cache/medium/hit_rate");
            p->hit[2] = stat_of(st, "cache/fine/hit_rate");
            p->fills = stat_of(st, "cache/coarse/fills") + stat_of(st, "cache/medium/fills") +
                       stat_of(st, "cache/fine/fills");
            p->shading_points = stat_of(st, "shading_points/total");
            rayes_stats_free(st);
        }
    }
}

static RayesScene *load(const char *data)
{
    RayesScene *s = rayes_scene_new();
    char err[600];
    IoSink sink = io_sink_scene(s);
    if (io_builtin_scene("cornell-teapots", data, &sink, err, sizeof err) != RAYES_OK ||
        rayes_scene_commit(s) != RAYES_OK) {
        fprintf(stderr, "interactive: %s\n", err);
        exit(1);
    }
    return s;
}

/* The edits of the bench, the same on the session's scene and the fresh one. */
static void orbit(RayesScene *s, const float pivot[3])
{
    float eye[3], x[3], y[3], z[3];
    rayes_scene_get_camera(s, eye, x, y, z);
    float a = 10.0f * (float)M_PI / 180.0f, c = cosf(a), sn = sinf(a);
    /* 10 degrees about the vertical axis through the pivot. */
    float m[16] = {c, 0, sn, pivot[0] - c * pivot[0] - sn * pivot[2],
                   0, 1, 0,  0,
                   -sn, 0, c, pivot[2] + sn * pivot[0] - c * pivot[2],
                   0, 0, 0, 1};
    rayes_scene_move_camera(s, m);
}

static void edit_light(RayesScene *s)
{
    RayesParam p = {"intensity", RAYES_PARAM_FLOAT, {0.6f, 0, 0}, NULL};
    rayes_scene_edit_light(s, 0, &p, 1);
}

static void compare(const char *what, const RayesImage *a, const RayesImage *b)
{
    double ma = 0, mb = 0, maxd = 0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            ma += a->rgba[4 * i + c];
            mb += b->rgba[4 * i + c];
            maxd = fmax(maxd, fabs((double)a->rgba[4 * i + c] - b->rgba[4 * i + c]));
        }
    printf("%-44s mean relative difference %.4f%%, largest pixel difference %.3g\n", what,
           100.0 * fabs(ma - mb) / fmax(mb, 1e-30), maxd);
}

int main(int argc, char **argv)
{
    int size = 512, passes = 16, final_spp = 64, threads = 0, bounces = 1;
    const char *data = "../shared/data", *out = "bench-out";
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--size") == 0)
            size = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--passes") == 0)
            passes = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--final-spp") == 0)
            final_spp = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--bounces") == 0)
            bounces = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--threads") == 0)
            threads = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--data") == 0)
            data = argv[i + 1];
        else if (strcmp(argv[i], "--out") == 0)
            out = argv[i + 1];
        else {
            fprintf(stderr, "interactive: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (size < 8 || bounces < 0 || bounces > 16 || passes < 1 || passes > 1024 || final_spp < passes) {
        fprintf(stderr, "interactive: expected --size >= 8, 1 <= --passes <= 1024 <= ... and "
                        "--final-spp >= --passes\n");
        return 2;
    }
    mkdir(out, 0755);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = size;
    o.spp = final_spp; /* the pattern the passes draw from */
    o.bounces = bounces;
    o.threads = threads;
    o.dice_isotropic = 1; /* the memo's tessellation, as bench/memo_tables */

    RayesScene *s = load(data);
    Phase ph[3] = {{.name = "start"}, {.name = "camera move (orbit 10 deg)"},
                   {.name = "light edit (intensity 0.6)"}};
    double t0 = time_now();
    RayesSession *ss = NULL;
    if (rayes_session_new(s, &o, &ss) != RAYES_OK) {
        fprintf(stderr, "interactive: %s\n", rayes_scene_get_error(s));
        return 1;
    }
    ph[0].update_s = time_now() - t0;
    float pivot[3];
    int64_t object;
    rayes_session_pick(ss, 0.5f * size, 0.5f * size, &object, pivot);
    run_passes(ss, &ph[0], passes);

    orbit(s, pivot);
    rayes_scene_commit(s);
    t0 = time_now();
    rayes_session_update(ss);
    ph[1].update_s = time_now() - t0;
    run_passes(ss, &ph[1], passes);
    RayesImage *moved = NULL;
    rayes_session_image(ss, &moved);

    edit_light(s);
    rayes_scene_commit(s);
    t0 = time_now();
    rayes_session_update(ss);
    ph[2].update_s = time_now() - t0;
    run_passes(ss, &ph[2], passes);

    printf("cornell-teapots %dx%d, preview, %d bounce%s, %d passes of 1 sample\n\n", size, size,
           bounces, bounces == 1 ? "" : "s", passes);
    printf("| after | update | first pass | mean of passes 2-%d | to %d spp | first pass hit rate "
           "c / m / f | first pass fills | first pass shading points |\n",
           passes, passes);
    printf("|---|---|---|---|---|---|---|---|\n");
    for (int k = 0; k < 3; k++) {
        double rest = 0, total = ph[k].update_s;
        for (int i = 0; i < ph[k].n; i++) {
            total += ph[k].pass_s[i];
            if (i)
                rest += ph[k].pass_s[i];
        }
        printf("| %s | %.3f s | %.3f s | %.3f s | %.2f s | %.2f%% / %.2f%% / %.2f%% | %.0f | "
               "%.0f |\n",
               ph[k].name, ph[k].update_s, ph[k].pass_s[0],
               ph[k].n > 1 ? rest / (ph[k].n - 1) : 0.0, total, 100 * ph[k].hit[0],
               100 * ph[k].hit[1], 100 * ph[k].hit[2], ph[k].fills, ph[k].shading_points);
    }
    printf("\npass times (s):\n");
    for (int k = 0; k < 3; k++) {
        printf("  %-28s", ph[k].name);
        for (int i = 0; i < ph[k].n; i++)
            printf(" %.3f", ph[k].pass_s[i]);
        printf("\n");
    }
    printf("\nfirst pass after a light edit / after a camera move: %.2f\n\n",
           ph[2].pass_s[0] / ph[1].pass_s[0]);

    /* Convergence: the edited session to final_spp against fresh renders. */
    run_passes(ss, &ph[2], final_spp - passes);
    RayesImage *edited = NULL;
    rayes_session_image(ss, &edited);
    RayesScene *fresh = load(data);
    orbit(fresh, pivot);
    edit_light(fresh);
    rayes_scene_commit(fresh);
    RayesImage *want = NULL;
    if (rayes_render(fresh, &o, &want, NULL) != RAYES_OK) {
        fprintf(stderr, "interactive: %s\n", rayes_scene_get_error(fresh));
        return 1;
    }
    char label[100];
    snprintf(label, sizeof label, "light edit, %d spp, vs a fresh render:", final_spp);
    compare(label, edited, want);
    /* The camera-moved session kept the grids diced for the first camera;
     * a fresh render dices for the moved one. */
    RayesRenderOptions o16 = o;
    o16.spp = passes;
    RayesScene *moved_fresh = load(data);
    orbit(moved_fresh, pivot);
    rayes_scene_commit(moved_fresh);
    RayesImage *moved_want = NULL;
    rayes_render(moved_fresh, &o16, &moved_want, NULL);
    snprintf(label, sizeof label, "camera move, %d spp, vs a fresh render:", passes);
    compare(label, moved, moved_want);
    char path[600], err[600];
    snprintf(path, sizeof path, "%s/interactive-edited.png", out);
    image_write_png(path, edited->width, edited->height, edited->rgba, err, sizeof err);
    snprintf(path, sizeof path, "%s/interactive-fresh.png", out);
    image_write_png(path, want->width, want->height, want->rgba, err, sizeof err);
    printf("images: %s/interactive-edited.png, %s/interactive-fresh.png\n", out, out);
    rayes_image_free(moved);
    rayes_image_free(moved_want);
    rayes_image_free(edited);
    rayes_image_free(want);
    rayes_session_free(ss);
    rayes_scene_release(s);
    rayes_scene_release(fresh);
    rayes_scene_release(moved_fresh);
    return 0;
}
