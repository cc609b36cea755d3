/*
 * app/main.c — the rayes command line. Only this folder exits.
 *
 * Exit status: 0 success; 1 bad input or a failed render or write (one line
 * on stderr naming the file and what is wrong); 2 a usage error; 130
 * interrupted (SIGINT), with no output written.
 */
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/builtin.h"
#include "image/image.h"
#include "io/stats_json.h"
#include "rayes/rayes.h"
#include "util/log.h"

#define MAX_OUTPUTS 8

typedef struct Args {
    const char *scene;
    const char *outputs[MAX_OUTPUTS];
    int n_outputs;
    const char *stats_path;
    const char *data_dir;
    const char *shader_path;    /* --shader-path: put before the scene's own shader path */
    int quiet;
    RayesRenderOptions opt;
} Args;

typedef struct Progress {
    double start;
    int tty, last_percent, quiet;
} Progress;

static volatile sig_atomic_t interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    interrupted = 1;
}

static void usage(FILE *f)
{
    fputs("usage: rayes render [SCENE] [options]\n"
          "       rayes --help | --version\n"
          "\n"
          "SCENE is a built-in scene: cornell (default), cornell-teapots,\n"
          "cornell-teapots-displaced, cornell-spheres, cornell-brick (needs the plugin\n"
          "brick.so: --shader-path build/examples/shaders).\n"
          "\n"
          "options:\n"
          "  -o FILE                 output image, .exr or .png (repeatable; default SCENE.exr)\n"
          "  --res W[xH]             resolution in pixels (default 512x512)\n"
          "  --spp N                 pixel samples (default 4)\n"
          "  --threads N             worker threads (default: all cores)\n"
          "  --bounces N             maximum diffuse depth (default 1)\n"
          "  --quality Q             preview (4 shadow, 4 diffuse rays), final (64; 1024 at\n"
          "                          depth 0, 64 deeper), reference (64 and 4096 at depth 0,\n"
          "                          1 and 1 deeper); later options override it\n"
          "  --shadow-rays N         shadow rays per shading point and light\n"
          "  --diffuse-rays N        diffuse rays per shading point (all depths)\n"
          "  --diffuse-rays-deep N   diffuse rays per shading point below depth 0\n"
          "  --specular-depth N      maximum specular depth (default 4)\n"
          "  --filter box|gaussian   pixel filter (default box)\n"
          "  --filter-width W        filter width in pixels (default 1 box, 2 gaussian)\n"
          "  --seed N                changes every random number (default 0)\n"
          "  --cache on|off          the radiosity cache at diffuse hits (default on; off for\n"
          "                          --quality reference)\n"
          "  --cache-mb MB           cache budget in megabytes (default 100)\n"
          "  --cache-split C,M,F     budget shares of coarse, medium, fine (default .25,.25,.5)\n"
          "  --cache-resolution R    auto (by ray differentials), coarse, medium or fine\n"
          "  --cache-k K             use the coarsest resolution whose micropolygons are at\n"
          "                          most K times the ray footprint (default 1)\n"
          "  --hider raytrace|grid   shade every camera hit (default), or once per vertex of\n"
          "                          each visible grid and interpolate (PRMan's REYES mode;\n"
          "                          default for --quality final)\n"
          "  --irradiance on|off     irradiance interpolation with gradients at depth 0 (grid\n"
          "                          hider; on for --quality final)\n"
          "  --texture-mb MB         texture cache budget in megabytes (default 64)\n"
          "  --data DIR              data directory (teapot.bpt); default $RAYES_DATA\n"
          "  --shader-path DIRS      directories of shader plugins NAME.so, ':'-separated;\n"
          "                          searched before $RAYES_SHADER_PATH\n"
          "  --stats FILE.json       write statistics as JSON\n"
          "  --quiet                 no progress bar and no summary\n",
          f);
}

static void die_usage(const char *fmt, ...) __attribute__((noreturn, format(printf, 1, 2)));
static void die_usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("rayes: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputs(" (rayes --help shows the usage)\n", stderr);
    va_end(ap);
    exit(2);
}

static long parse_long(const char *opt, const char *s, long lo, long hi)
{
    char *end;
    errno = 0;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || *s == '\0' || *end != '\0' || errno != 0 || v < lo || v > hi)
        die_usage("%s: expected an integer from %ld to %ld, got \"%s\"", opt, lo, hi,
                  s ? s : "nothing");
    return v;
}

static float parse_float(const char *opt, const char *s, float lo, float hi)
{
    char *end;
    errno = 0;
    float v = s ? strtof(s, &end) : 0.0f;
    if (!s || *s == '\0' || *end != '\0' || errno != 0 || !(v >= lo && v <= hi))
        die_usage("%s: expected a number from %g to %g, got \"%s\"", opt, lo, hi,
                  s ? s : "nothing");
    return v;
}

static void parse_res(const char *s, RayesRenderOptions *o)
{
    char w[32];
    const char *x = s ? strchr(s, 'x') : NULL;
    if (s && x && (size_t)(x - s) < sizeof w) {
        snprintf(w, sizeof w, "%.*s", (int)(x - s), s);
        o->width = (int)parse_long("--res", w, 1, 65536);
        o->height = (int)parse_long("--res", x + 1, 1, 65536);
    } else {
        o->width = o->height = (int)parse_long("--res", s, 1, 65536);
    }
}

static void parse_split(const char *s, float split[3])
{
    char buf[128], *save = NULL;
    snprintf(buf, sizeof buf, "%s", s);
    float sum = 0.0f;
    for (int i = 0; i < 3; i++) {
        char *tok = strtok_r(i == 0 ? buf : NULL, ",", &save);
        split[i] = parse_float("--cache-split", tok, 0.0f, 1.0f);
        sum += split[i];
    }
    if (strtok_r(NULL, ",", &save) || sum > 1.0001f)
        die_usage("--cache-split: expected three shares C,M,F summing to at most 1, got \"%s\"",
                  s);
}

static int parse_resolution(const char *s)
{
    static const char *const names[] = {"coarse", "medium", "fine"};
    if (strcmp(s, "auto") == 0)
        return -1;
    for (int i = 0; i < 3; i++)
        if (strcmp(s, names[i]) == 0)
            return i;
    die_usage("--cache-resolution: expected auto, coarse, medium or fine, got \"%s\"", s);
}

static RayesQuality parse_quality(const char *s)
{
    if (s && strcmp(s, "preview") == 0)
        return RAYES_QUALITY_PREVIEW;
    if (s && strcmp(s, "final") == 0)
        return RAYES_QUALITY_FINAL;
    if (s && strcmp(s, "reference") == 0)
        return RAYES_QUALITY_REFERENCE;
    die_usage("--quality: expected preview, final or reference, got \"%s\"", s ? s : "nothing");
}

/* The preset first (it sets ray counts), then every other option in order. */
static void parse_args(int argc, char **argv, Args *a)
{
    RayesQuality q = RAYES_QUALITY_PREVIEW;
    for (int i = 2; i < argc; i++)
        if (strcmp(argv[i], "--quality") == 0)
            q = parse_quality(i + 1 < argc ? argv[i + 1] : NULL);
    rayes_render_options_init(&a->opt, q);
    int filter_width_set = 0;
    for (int i = 2; i < argc; i++) {
        const char *o = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        RayesRenderOptions *opt = &a->opt;
        if (o[0] != '-') {
            if (a->scene)
                die_usage("only one scene may be given (\"%s\" and \"%s\")", a->scene, o);
            a->scene = o;
            continue;
        }
        if (strcmp(o, "--quiet") == 0) {
            a->quiet = 1;
            continue;
        }
        if (!v)
            die_usage("%s: expected a value", o);
        i++;
        if (strcmp(o, "-o") == 0) {
            if (a->n_outputs == MAX_OUTPUTS)
                die_usage("-o: at most %d outputs", MAX_OUTPUTS);
            if (image_format_from_path(v) == IMAGE_FORMAT_UNKNOWN)
                die_usage("-o %s: expected a file name ending in .exr or .png", v);
            a->outputs[a->n_outputs++] = v;
        } else if (strcmp(o, "--res") == 0)
            parse_res(v, opt);
        else if (strcmp(o, "--spp") == 0)
            opt->spp = (int)parse_long(o, v, 1, 1 << 20);
        else if (strcmp(o, "--threads") == 0)
            opt->threads = (int)parse_long(o, v, 0, 1024);
        else if (strcmp(o, "--bounces") == 0)
            opt->bounces = (int)parse_long(o, v, 0, 64);
        else if (strcmp(o, "--quality") == 0)
            continue;
        else if (strcmp(o, "--shadow-rays") == 0)
            opt->shadow_rays = opt->shadow_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays") == 0)
            opt->diffuse_rays = opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays-deep") == 0)
            opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--specular-depth") == 0)
            opt->specular_depth = (int)parse_long(o, v, 0, 64);
        else if (strcmp(o, "--filter") == 0) {
            if (strcmp(v, "box") == 0)
                opt->filter = RAYES_FILTER_BOX;
            else if (strcmp(v, "gaussian") == 0)
                opt->filter = RAYES_FILTER_GAUSSIAN;
            else
                die_usage("--filter: expected box or gaussian, got \"%s\"", v);
        } else if (strcmp(o, "--filter-width") == 0) {
            opt->filter_width = parse_float(o, v, 0.01f, 16.0f);
            filter_width_set = 1;
        } else if (strcmp(o, "--seed") == 0)
            opt->seed = (uint64_t)parse_long(o, v, 0, LONG_MAX);
        else if (strcmp(o, "--cache") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--cache: expected on or off, got \"%s\"", v);
            opt->cache = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--cache-mb") == 0)
            opt->cache_mb = parse_float(o, v, 0.0f, 1e7f);
        else if (strcmp(o, "--cache-split") == 0)
            parse_split(v, opt->cache_split);
        else if (strcmp(o, "--cache-resolution") == 0)
            opt->cache_resolution = parse_resolution(v);
        else if (strcmp(o, "--cache-k") == 0)
            opt->cache_k = parse_float(o, v, 1e-3f, 1e3f);
        else if (strcmp(o, "--hider") == 0) {
            if (strcmp(v, "raytrace") != 0 && strcmp(v, "grid") != 0)
                die_usage("--hider: expected raytrace or grid, got \"%s\"", v);
            opt->hider = strcmp(v, "grid") == 0 ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
        } else if (strcmp(o, "--irradiance") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--irradiance: expected on or off, got \"%s\"", v);
            opt->irradiance = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--texture-mb") == 0)
            opt->texture_mb = parse_float(o, v, 0.0f, 1e7f);
        else if (strcmp(o, "--data") == 0)
            a->data_dir = v;
        else if (strcmp(o, "--stats") == 0)
            a->stats_path = v;
        else if (strcmp(o, "--shader-path") == 0)
            a->shader_path = v;
        else
            die_usage("unknown option \"%s\"", o);
    }
    if (!filter_width_set && a->opt.filter == RAYES_FILTER_GAUSSIAN)
        a->opt.filter_width = 2.0f;
    if (!a->scene)
        a->scene = "cornell";
    if (!a->data_dir)
        a->data_dir = getenv("RAYES_DATA");
}

static void format_time(char *buf, size_t n, double s)
{
    long t = (long)(s + 0.5);
    snprintf(buf, n, "%02ld:%02ld", t / 60, t % 60);
}

static int on_progress(void *user, double fraction)
{
    Progress *p = user;
    if (!p->quiet) {
        int percent = (int)(fraction * 100.0);
        if (p->tty || percent / 25 != p->last_percent / 25 || fraction >= 1.0) {
            double elapsed = time_now() - p->start;
            double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
            char bar[41], e1[48], e2[48];
            int filled = (int)(fraction * 40.0);
            for (int i = 0; i < 40; i++)
                bar[i] = i < filled ? '#' : '.';
            bar[40] = '\0';
            format_time(e1, sizeof e1, elapsed);
            format_time(e2, sizeof e2, eta);
            if (p->tty || percent != p->last_percent)
                fprintf(stderr, "%s[%s] %3d%%  %s elapsed  ETA %s%s", p->tty ? "\r" : "", bar,
                        percent, e1, e2, p->tty && fraction < 1.0 ? "" : "\n");
            p->last_percent = percent;
        }
    }
    return interrupted;
}

static uint64_t stat_count(const RayesStats *s, const char *name)
{
    const RayesStat *st = rayes_stats_find(s, name);
    return st ? st->count : 0;
}

static double stat_real(const RayesStats *s, const char *name)
{
    const RayesStat *st = rayes_stats_find(s, name);
    return st ? st->real : 0.0;
}

static void summary(const Args *a, const RayesStats *s)
{
    printf("rayes %s: %s, %dx%d, %d spp, %d bounce%s, %llu threads\n", rayes_version_string(),
           a->scene, a->opt.width, a->opt.height, a->opt.spp, a->opt.bounces,
           a->opt.bounces == 1 ? "" : "s", (unsigned long long)stat_count(s, "threads"));
    printf("  time          %.2f s total (%.2f prepare, %.2f render)\n",
           stat_real(s, "time/total_s"), stat_real(s, "time/prepare_s"),
           stat_real(s, "time/render_s"));
    printf("  geometry      %llu grids, %llu grid vertices\n",
           (unsigned long long)stat_count(s, "grids"),
           (unsigned long long)stat_count(s, "grid_vertices"));
    printf("  shading pts   %llu", (unsigned long long)stat_count(s, "shading_points/total"));
    const RayesStat *d = rayes_stats_find(s, "shading_points/by_depth");
    for (size_t i = 0; d && i < d->n_counts; i++)
        printf("%s depth %zu: %llu", i ? "," : " (", i, (unsigned long long)d->counts[i]);
    printf("%s\n", d && d->n_counts ? ")" : "");
    printf("  rays          %llu (camera %llu, shadow %llu, diffuse %llu, specular %llu)\n",
           (unsigned long long)stat_count(s, "rays/total"),
           (unsigned long long)stat_count(s, "rays/camera"),
           (unsigned long long)stat_count(s, "rays/shadow"),
           (unsigned long long)stat_count(s, "rays/diffuse"),
           (unsigned long long)stat_count(s, "rays/specular"));
    if (rayes_stats_find(s, "cache/budget_bytes")) {
        static const char *const lv[3] = {"coarse", "medium", "fine"};
        printf("  cache         %.0f MB:", (double)stat_count(s, "cache/budget_bytes") / 1e6);
        for (int l = 0; l < 3; l++) {
            char k1[64], k2[64], k3[64];
            snprintf(k1, sizeof k1, "cache/%s/hit_rate", lv[l]);
            snprintf(k2, sizeof k2, "cache/%s/lookups", lv[l]);
            snprintf(k3, sizeof k3, "cache/%s/entries", lv[l]);
            printf("%s %s %.2f%% of %llu (%llu entries)", l ? "," : "", lv[l],
                   100.0 * stat_real(s, k1), (unsigned long long)stat_count(s, k2),
                   (unsigned long long)stat_count(s, k3));
        }
        printf("\n");
    }
    printf("  memory        %.1f MB peak resident\n",
           (double)stat_count(s, "memory/peak_rss_bytes") / 1e6);
}

/* Fails early, before a long render, when an output's directory cannot be
 * written. */
static int check_output_dir(const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    if (access(dir, W_OK) == 0)
        return 0;
    fprintf(stderr, "rayes: %s: cannot write: directory %s %s\n", path, dir,
            errno == ENOENT ? "does not exist" : "is not writable");
    return -1;
}

static int cmd_render(int argc, char **argv)
{
    Args a = {0};
    parse_args(argc, argv, &a);
    char default_out[512];
    if (a.n_outputs == 0) {
        snprintf(default_out, sizeof default_out, "%s.exr", a.scene);
        a.outputs[a.n_outputs++] = default_out;
    }
    for (int i = 0; i < a.n_outputs; i++)
        if (check_output_dir(a.outputs[i]) != 0)
            return 1;
    if (a.stats_path && check_output_dir(a.stats_path) != 0)
        return 1;
    RayesScene *scene = rayes_scene_new();
    char err[1024];
    if (!scene) {
        fprintf(stderr, "rayes: out of memory\n");
        return 1;
    }
    /* Before the scene, so a scene file's own path can keep it with "&". */
    if (a.shader_path && rayes_scene_set_search_path(scene, "shader", a.shader_path) != RAYES_OK) {
        fprintf(stderr, "rayes: --shader-path: %s\n", rayes_scene_get_error(scene));
        rayes_scene_release(scene);
        return 2;
    }
    RayesError e = io_builtin_scene(a.scene, a.data_dir, scene, err, sizeof err);
    if (e != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        rayes_scene_release(scene);
        return e == RAYES_ERROR_INVALID_ARGUMENT ? 2 : 1;
    }
    Progress prog = {.start = time_now(), .tty = isatty(2), .last_percent = -1, .quiet = a.quiet};
    a.opt.progress = on_progress;
    a.opt.progress_user = &prog;
    signal(SIGINT, on_sigint);
    RayesImage *img = NULL;
    RayesStats *stats = NULL;
    e = rayes_render(scene, &a.opt, &img, &stats);
    if (e != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", rayes_scene_get_error(scene));
        rayes_scene_release(scene);
        return e == RAYES_ERROR_CANCELLED ? 130 : 1;
    }
    int status = 0, written = 0; /* outputs written whole */
    while (written < a.n_outputs && status == 0) {
        if (image_write(a.outputs[written], img->width, img->height, img->rgba, err,
                           sizeof err) == RAYES_OK) {
            written++;
        } else {
            fprintf(stderr, "rayes: %s\n", err);
            status = 1;
        }
    }
    if (status == 0 && a.stats_path &&
        io_stats_json_save(a.stats_path, stats, a.scene, err, sizeof err) != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        status = 1;
    }
    /* A failed run leaves none of its outputs behind. */
    for (int i = 0; status != 0 && i < written; i++)
        unlink(a.outputs[i]);
    if (status == 0 && !a.quiet) {
        summary(&a, stats);
        for (int i = 0; i < a.n_outputs; i++)
            printf("  wrote         %s\n", a.outputs[i]);
    }
    rayes_stats_free(stats);
    rayes_image_free(img);
    rayes_scene_release(scene);
    return status;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("rayes %s\n", rayes_version_string());
        return 0;
    }
    if (strcmp(argv[1], "render") == 0)
        return cmd_render(argc, argv);
    die_usage("unknown command \"%s\"", argv[1]);
}
