/*
 * app/main.c — the rayes command line. Only this folder exits.
 *
 * Exit status: 0 success; 1 bad input or a failed render or write (one line
 * on stderr naming the file and what is wrong); 2 a usage error; 130
 * interrupted (SIGINT), with no output written.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/rib_write.h"
#include "io/scene_file.h"
#include "io/stats_json.h"
#include "rayes/rayes.h"
#include "util/log.h"

#include "app/app.h"

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
          "       rayes convert SCENE OUT.rib [--data DIR] [--frame N] [--quiet]\n"
          "       rayes --help | --version\n"
          "\n"
          "SCENE is a scene file (.rib, .rib.gz, .pbrt, .obj) or a built-in scene:\n"
          "cornell (default), cornell-teapots, cornell-teapots-displaced, cornell-spheres,\n"
          "cornell-brick (needs the plugin brick.so: --shader-path build/examples/shaders).\n"
          "A scene file's image size, samples, filter, depths and displays are used unless\n"
          "the command line gives them. convert writes SCENE as ASCII RIB.\n"
          "\n"
          "options:\n"
          "  -o FILE                 output image, .exr or .png (repeatable; default: the\n"
          "                          scene file's displays, else SCENE.exr)\n"
          "  --frame N               the frame of a RIB file to read (default: the last)\n"
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
          "  --gridsize N            micropolygons per grid, at most (default 256, or the\n"
          "                          scene file's; 1 to 4096): the size of a cache entry\n"
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

void die_usage(const char *fmt, ...)
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
void parse_args(int argc, char **argv, Args *a)
{
    RayesQuality q = RAYES_QUALITY_PREVIEW;
    for (int i = 2; i < argc; i++)
        if (strcmp(argv[i], "--quality") == 0)
            q = parse_quality(i + 1 < argc ? argv[i + 1] : NULL);
    rayes_render_options_init(&a->opt, q);
    a->frame = -1;
    a->gamma = 1.0f;
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
        if (strcmp(o, "--headless") == 0 && a->view) {
            a->headless = 1;
            continue;
        }
        if (!v)
            die_usage("%s: expected a value", o);
        i++;
        if (strcmp(o, "-o") == 0) {
            if (a->n_outputs == MAX_OUTPUTS)
                die_usage("-o: at most %d outputs", MAX_OUTPUTS);
            Output *out = &a->outputs[a->n_outputs++];
            out->format = image_format_from_path(v);
            if (out->format == IMAGE_FORMAT_UNKNOWN)
                die_usage("-o %s: expected a file name ending in .exr or .png", v);
            if (strlen(v) >= sizeof out->path)
                die_usage("-o: the file name is too long");
            snprintf(out->path, sizeof out->path, "%s", v);
        } else if (strcmp(o, "--res") == 0) {
            parse_res(v, opt);
            a->set |= SET_RES;
        } else if (strcmp(o, "--spp") == 0) {
            opt->spp = (int)parse_long(o, v, 1, 1 << 20);
            a->set |= SET_SPP;
        } else if (strcmp(o, "--frame") == 0)
            a->frame = (int)parse_long(o, v, 0, INT_MAX);
        else if (strcmp(o, "--threads") == 0)
            opt->threads = (int)parse_long(o, v, 0, 1024);
        else if (strcmp(o, "--bounces") == 0) {
            opt->bounces = (int)parse_long(o, v, 0, 64);
            a->set |= SET_BOUNCES;
        }
        else if (strcmp(o, "--quality") == 0)
            continue;
        else if (strcmp(o, "--shadow-rays") == 0)
            opt->shadow_rays = opt->shadow_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays") == 0)
            opt->diffuse_rays = opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays-deep") == 0)
            opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--specular-depth") == 0) {
            opt->specular_depth = (int)parse_long(o, v, 0, 64);
            a->set |= SET_SPECULAR_DEPTH;
        } else if (strcmp(o, "--filter") == 0) {
            a->set |= SET_FILTER;
            if (strcmp(v, "box") == 0)
                opt->filter = RAYES_FILTER_BOX;
            else if (strcmp(v, "gaussian") == 0)
                opt->filter = RAYES_FILTER_GAUSSIAN;
            else
                die_usage("--filter: expected box or gaussian, got \"%s\"", v);
        } else if (strcmp(o, "--filter-width") == 0) {
            opt->filter_width = parse_float(o, v, 0.01f, 16.0f);
            a->set |= SET_FILTER_WIDTH;
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
        else if (strcmp(o, "--gridsize") == 0) {
            opt->grid_size = (int)parse_long(o, v, 1, 4096);
            a->set |= SET_GRID_SIZE;
        } else if (strcmp(o, "--hider") == 0) {
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
        else if (a->view && strcmp(o, "--script") == 0)
            a->script = v;
        else if (a->view && strcmp(o, "--passes") == 0)
            a->passes = (int)parse_long(o, v, 0, 1 << 20);
        else if (a->view && strcmp(o, "--screenshot") == 0)
            a->screenshot = v;
        else if (a->view && strcmp(o, "--exposure") == 0)
            a->exposure = parse_float(o, v, -30.0f, 30.0f);
        else if (a->view && strcmp(o, "--gamma") == 0)
            a->gamma = parse_float(o, v, 0.05f, 20.0f);
        else
            die_usage("unknown option \"%s\"", o);
    }
    if (!(a->set & SET_FILTER_WIDTH) && a->opt.filter == RAYES_FILTER_GAUSSIAN)
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

/* Builds the scene `scene` names (a scene file, else a built-in scene)
 * into sink; settings receive what a file gives. */
RayesError load_scene(const char *scene, const char *data_dir, int frame,
                             const IoSink *sink, IoSettings *settings, char *err, size_t err_size)
{
    io_settings_init(settings);
    if (io_is_scene_file(scene)) {
        IoReadOptions ro = {.data_dir = data_dir, .frame = frame};
        return io_read_scene_file(scene, sink, &ro, settings, err, err_size);
    }
    return io_builtin_scene(scene, data_dir, sink, err, err_size);
}

/* The exit status of a failed load: an unknown built-in name is a usage
 * error, everything else bad input. */
int load_status(const char *scene, RayesError e)
{
    return !io_is_scene_file(scene) && e == RAYES_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

/* The file's settings where the command line gave none. */
void merge_settings(Args *a, const IoSettings *s)
{
    RayesRenderOptions *o = &a->opt;
    if (!(a->set & SET_RES) && s->width > 0 && s->height > 0) {
        o->width = s->width;
        o->height = s->height;
    }
    if (!(a->set & SET_SPP) && s->spp > 0)
        o->spp = s->spp;
    if (!(a->set & SET_FILTER) && (s->filter == RAYES_FILTER_BOX || s->filter == RAYES_FILTER_GAUSSIAN)) {
        o->filter = (RayesFilter)s->filter;
        if (!(a->set & SET_FILTER_WIDTH))
            o->filter_width = o->filter == RAYES_FILTER_GAUSSIAN ? 2.0f : 1.0f;
    }
    if (!(a->set & SET_FILTER_WIDTH) && s->filter_width > 0.0f)
        o->filter_width = s->filter_width;
    if (!(a->set & SET_BOUNCES) && s->bounces >= 0)
        o->bounces = s->bounces < 64 ? s->bounces : 64;
    if (!(a->set & SET_SPECULAR_DEPTH) && s->specular_depth >= 0)
        o->specular_depth = s->specular_depth < 64 ? s->specular_depth : 64;
    if (!(a->set & SET_GRID_SIZE) && s->grid_size > 0)
        o->grid_size = s->grid_size;
    if (s->crop[0] != 0.0f || s->crop[1] != 1.0f || s->crop[2] != 0.0f || s->crop[3] != 1.0f)
        fprintf(stderr, "rayes: warning: %s: CropWindow is not supported; the whole image is "
                        "rendered\n", a->scene);
}

/* The scene's name without its directory and extensions, for default
 * output names. */
static void scene_stem(const char *scene, char *out, size_t size)
{
    const char *slash = strrchr(scene, '/');
    snprintf(out, size, "%s", slash ? slash + 1 : scene);
    if (!io_is_scene_file(scene))
        return;
    char *dot = strchr(out[0] == '.' ? out + 1 : out, '.');
    if (dot)
        *dot = '\0';
}

static void add_output(Args *a, const char *path, ImageFormat format)
{
    if (a->n_outputs == MAX_OUTPUTS)
        return;
    snprintf(a->outputs[a->n_outputs].path, sizeof a->outputs[0].path, "%s", path);
    a->outputs[a->n_outputs++].format = format;
}

/* The images a file's displays ask for: exr/openexr and png by type,
 * file and tiff by the name's extension, else OpenEXR (with a note);
 * framebuffer windows write nothing; displays of other modes than rgb and
 * rgba (AOVs) are skipped with a warning each. */
static void outputs_from_displays(Args *a, const IoSettings *s)
{
    for (int i = 0; i < s->n_displays && i < IO_MAX_DISPLAYS; i++) {
        const IoDisplay *d = &s->displays[i];
        const char *type = d->type[0] ? d->type : "file";
        if (d->mode[0] && strcasecmp(d->mode, "rgb") != 0 && strcasecmp(d->mode, "rgba") != 0) {
            fprintf(stderr, "rayes: warning: display \"%s\": mode \"%s\" is not rendered (only "
                            "rgb and rgba); skipped\n", d->name, d->mode);
            continue;
        }
        if (strcasecmp(type, "framebuffer") == 0)
            continue;
        if (strcasecmp(type, "exr") == 0 || strcasecmp(type, "openexr") == 0) {
            add_output(a, d->name, IMAGE_FORMAT_EXR);
        } else if (strcasecmp(type, "png") == 0) {
            add_output(a, d->name, IMAGE_FORMAT_PNG);
        } else if (strcasecmp(type, "file") == 0 || strcasecmp(type, "tiff") == 0) {
            ImageFormat f = image_format_from_path(d->name);
            if (f != IMAGE_FORMAT_UNKNOWN) {
                add_output(a, d->name, f);
                continue;
            }
            char path[600];
            const char *slash = strrchr(d->name, '/'), *dot = strrchr(d->name, '.');
            int stem = dot && (!slash || dot > slash) ? (int)(dot - d->name) : (int)strlen(d->name);
            snprintf(path, sizeof path, "%.*s.exr", stem, d->name);
            fprintf(stderr, "rayes: note: display \"%s\" (%s): written as OpenEXR to %s\n",
                    d->name, type, path);
            add_output(a, path, IMAGE_FORMAT_EXR);
        } else {
            fprintf(stderr, "rayes: warning: display \"%s\": type \"%s\" is not supported; "
                            "skipped\n", d->name, type);
        }
    }
}

/* RenderMan's Exposure: colour = (gain colour)^(1 / gamma); alpha kept. */
static void apply_exposure(RayesImage *img, float gain, float gamma)
{
    if (gain == 1.0f && gamma == 1.0f)
        return;
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float v = fmaxf(img->rgba[4 * i + c] * gain, 0.0f);
            img->rgba[4 * i + c] = gamma > 0.0f && gamma != 1.0f ? powf(v, 1.0f / gamma) : v;
        }
}

static RayesError write_output(const Output *o, const RayesImage *img, char *err, size_t n)
{
    if (o->format == IMAGE_FORMAT_PNG)
        return image_write_png(o->path, img->width, img->height, img->rgba, err, n);
    return image_write_exr(o->path, img->width, img->height, img->rgba, err, n);
}

static int cmd_render(int argc, char **argv)
{
    Args a = {0};
    parse_args(argc, argv, &a);
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
    IoSettings settings;
    IoSink sink = io_sink_scene(scene);
    RayesError e = load_scene(a.scene, a.data_dir, a.frame, &sink, &settings, err, sizeof err);
    if (e == RAYES_OK && rayes_scene_commit(scene) != RAYES_OK) {
        e = RAYES_ERROR_PARSE;
        snprintf(err, sizeof err, "%s: %s", a.scene, rayes_scene_get_error(scene));
    }
    if (e != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        rayes_scene_release(scene);
        return load_status(a.scene, e);
    }
    merge_settings(&a, &settings);
    if (a.n_outputs == 0) {
        outputs_from_displays(&a, &settings);
        if (a.n_outputs == 0) {
            char stem[512], path[600];
            scene_stem(a.scene, stem, sizeof stem);
            snprintf(path, sizeof path, "%s.exr", stem);
            if (settings.n_displays > 0)
                fprintf(stderr, "rayes: note: %s: no display writes a file; writing %s\n",
                        a.scene, path);
            add_output(&a, path, IMAGE_FORMAT_EXR);
        }
    }
    int status = 0;
    for (int i = 0; i < a.n_outputs && status == 0; i++)
        status = check_output_dir(a.outputs[i].path) != 0;
    if (status == 0 && a.stats_path && check_output_dir(a.stats_path) != 0)
        status = 1;
    if (status != 0) {
        rayes_scene_release(scene);
        return 1;
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
    apply_exposure(img, settings.exposure_gain, settings.exposure_gamma);
    int written = 0; /* outputs written whole */
    while (written < a.n_outputs && status == 0) {
        if (write_output(&a.outputs[written], img, err, sizeof err) == RAYES_OK) {
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
        unlink(a.outputs[i].path);
    if (status == 0 && !a.quiet) {
        summary(&a, stats);
        for (int i = 0; i < a.n_outputs; i++)
            printf("  wrote         %s\n", a.outputs[i].path);
    }
    rayes_stats_free(stats);
    rayes_image_free(img);
    rayes_scene_release(scene);
    return status;
}

/* Writes the RIB through a temporary file in out's directory, renamed into
 * place once whole: an error leaves nothing behind. */
static int write_rib(RibWriter *w, const IoSettings *settings, const char *out)
{
    char tmp[4200], err[512];
    snprintf(tmp, sizeof tmp, "%s.tmp.XXXXXX", out);
    int fd = mkstemp(tmp);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        fprintf(stderr, "rayes: %s: cannot write: %s\n", out, strerror(errno));
        if (fd >= 0) {
            close(fd);
            unlink(tmp);
        }
        return 1;
    }
    RayesError e = io_rib_writer_finish(w, settings, f, err, sizeof err);
    int bad = fclose(f) != 0;
    if (e == RAYES_OK && !bad && rename(tmp, out) == 0)
        return 0;
    fprintf(stderr, "rayes: %s: cannot write: %s\n", out, e != RAYES_OK ? err : strerror(errno));
    unlink(tmp);
    return 1;
}

/* rayes convert IN OUT.rib [--data DIR] [--frame N] [--quiet] */
static int cmd_convert(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *data_dir = getenv("RAYES_DATA");
    int frame = -1, quiet = 0;
    for (int i = 2; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (o[0] != '-') {
            if (out)
                die_usage("convert: expected one scene and one output (got \"%s\" too)", o);
            *(in ? &out : &in) = o;
        } else if (strcmp(o, "--quiet") == 0) {
            quiet = 1;
        } else if (strcmp(o, "--data") == 0) {
            if (!v)
                die_usage("--data: expected a value");
            data_dir = v;
            i++;
        } else if (strcmp(o, "--frame") == 0) {
            frame = (int)parse_long(o, v, 0, INT_MAX);
            i++;
        } else {
            die_usage("convert: unknown option \"%s\"", o);
        }
    }
    size_t n = out ? strlen(out) : 0;
    if (!in || !out)
        die_usage("convert: expected a scene and an output file OUT.rib");
    if (n < 4 || strcasecmp(out + n - 4, ".rib") != 0)
        die_usage("convert %s: expected an output file name ending in .rib", out);
    if (check_output_dir(out) != 0)
        return 1;
    RibWriter *w = io_rib_writer_new();
    if (!w) {
        fprintf(stderr, "rayes: out of memory\n");
        return 1;
    }
    IoSettings settings;
    IoSink sink = io_rib_writer_sink(w);
    char err[1024];
    RayesError e = load_scene(in, data_dir, frame, &sink, &settings, err, sizeof err);
    int status = e == RAYES_OK ? write_rib(w, &settings, out) : load_status(in, e);
    if (e != RAYES_OK)
        fprintf(stderr, "rayes: %s\n", err);
    io_rib_writer_free(w);
    if (status == 0 && !quiet)
        printf("wrote %s\n", out);
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
    if (strcmp(argv[1], "convert") == 0)
        return cmd_convert(argc, argv);
    if (strcmp(argv[1], "view") == 0)
        return cmd_view(argc, argv);
    die_usage("unknown command \"%s\"", argv[1]);
}
