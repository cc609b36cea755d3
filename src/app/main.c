/*
 * app/main.c — the rayes command line. Only this folder exits.
 *
 * Exit status: 0 success; 1 bad input or a failed render or write (one line
 * on stderr naming the file and what is wrong); 2 a usage error; 130
 * interrupted by SIGINT, 143 by SIGTERM (a farm's pre-emption), with no
 * output written (with --checkpoint, the finished tiles saved for
 * --resume). docs/cli.md lists them for farm managers.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
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

#include "app/assemble.h"
#include "app/checkpoint.h"
#include "app/cli.h"
#include "app/distribute.h"
#include "app/view.h"

typedef struct Progress {
    double start;
    int tty, last_percent, quiet;
    int json;       /* --progress json */
    int frame;      /* the frame's number, or -1 */
} Progress;

static volatile sig_atomic_t interrupted; /* the signal that interrupted, or 0 */
static volatile int stop;                 /* 1 once interrupted: the workers read it
                                             (RayesRenderOptions.stop), atomically */

static void on_signal(int sig)
{
    interrupted = sig;
    __atomic_store_n(&stop, 1, __ATOMIC_RELAXED); /* lock-free: safe in a handler */
}

static void format_time(char *buf, size_t n, double s)
{
    long t = (long)(s + 0.5);
    snprintf(buf, n, "%02ld:%02ld", t / 60, t % 60);
}

/* s as a JSON string on standard output (control characters as '?'). */
static void print_json_string(const char *s)
{
    putchar('"');
    for (const char *c = s; *c; c++) {
        if (*c == '"' || *c == '\\')
            putchar('\\');
        putchar((unsigned char)*c < 0x20 ? '?' : *c);
    }
    putchar('"');
}

static int on_progress(void *user, double fraction)
{
    Progress *p = user;
    if (p->json) {
        int percent = (int)(fraction * 100.0);
        if (percent != p->last_percent) {
            printf("{\"event\": \"progress\", \"frame\": %d, \"fraction\": %.4f, "
                   "\"elapsed\": %.3f}\n",
                   p->frame, fraction, time_now() - p->start);
            fflush(stdout);
            p->last_percent = percent;
        }
    } else if (!p->quiet) {
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
    return interrupted != 0;
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
    if (rayes_stats_find(s, "instances/count"))
        printf("  instances     %llu, of %llu master(s): %llu grids, %llu micropolygons held "
               "once; %.1f radiosity fills each\n",
               (unsigned long long)stat_count(s, "instances/count"),
               (unsigned long long)stat_count(s, "instances/masters"),
               (unsigned long long)stat_count(s, "instances/master_grids"),
               (unsigned long long)stat_count(s, "instances/master_micropolygons"),
               stat_real(s, "instances/radiosity_entries_per_instance"));
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
    if (rayes_stats_find(s, "replay/rays"))
        printf("  replay        %llu rays (%llu dropped) traced again unshaded: %.2f s (cpu %.2f "
               "s), the render %.2f s (cpu %.2f s), %.2fx ray casting alone\n",
               (unsigned long long)stat_count(s, "replay/rays"),
               (unsigned long long)stat_count(s, "replay/dropped"), stat_real(s, "replay/wall_s"),
               stat_real(s, "replay/cpu_s"), stat_real(s, "time/render_s"),
               stat_real(s, "time/render_cpu_s"),
               stat_real(s, "time/render_cpu_s") / fmax(stat_real(s, "replay/cpu_s"), 1e-9));
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
    if (stat_count(s, "motion/time_samples") > 1) {
        printf("  motion        %llu time samples, %llu moving grids, radiosity fills by segment",
               (unsigned long long)stat_count(s, "motion/time_samples"),
               (unsigned long long)stat_count(s, "motion/moving_grids"));
        const RayesStat *f = rayes_stats_find(s, "motion/fills_by_segment");
        for (size_t i = 0; f && i < f->n_counts; i++)
            printf("%s%llu", i ? " " : ": ", (unsigned long long)f->counts[i]);
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

static Output *add_output(Args *a, const char *path, ImageFormat format, int no_alpha)
{
    if (a->n_outputs == MAX_OUTPUTS)
        return NULL;
    Output *o = &a->outputs[a->n_outputs++];
    memset(o, 0, sizeof *o);
    snprintf(o->path, sizeof o->path, "%s", path);
    o->format = format;
    o->no_alpha = no_alpha;
    return o;
}

/* A display's mode: colour ("rgb", "rgba", RenderMan RIS's "Ci" and
 * "Ci,a") and AOVs ("z", "N", "P", "id", "patch", "cache", with or
 * without a type: "normal N"; RenderMan's denoiser channels "zfiltered"
 * and "normal" are z and N), comma-separated, or RenderMan's "rgbz" and
 * "rgbaz". 0 when nothing in it is rendered; what is not is warned of in
 * one line; *colour 1 rgb, 2 rgba, 0 none. */
static int display_mode(const IoDisplay *d, int aovs_ok, int *colour, unsigned *aovs)
{
    *colour = 0, *aovs = 0;
    char mode[sizeof d->mode], skipped[2 * sizeof d->mode] = "", unwritten[2 * sizeof d->mode] = "";
    snprintf(mode, sizeof mode, "%s", d->mode[0] ? d->mode : "rgba");
    for (char *save = NULL, *tok = strtok_r(mode, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        while (*tok == ' ')
            tok++;
        const char *space = strrchr(tok, ' '), *name = space ? space + 1 : tok;
        int z = strcmp(name, "rgbz") == 0 || strcmp(name, "rgbaz") == 0; /* colour and Z */
        unsigned aov =
            strcmp(name, "all") == 0 ? 0 : aov_named(name, strlen(name)) | (z ? RAYES_AOV_Z : 0);
        /* RenderMan RIS's beauty is "Ci,a" (RenderMan for Blender's, Maya's) */
        int rgb = strcasecmp(name, "rgb") == 0 || strcmp(name, "rgbz") == 0 ||
                  strcmp(name, "Ci") == 0,
            rgba = strcasecmp(name, "rgba") == 0 || strcmp(name, "rgbaz") == 0 ||
                   (strcmp(name, "a") == 0 && *colour);
        if (rgb || rgba)
            *colour = *colour == 2 || rgba ? 2 : 1;
        char *list = !aov && !(rgb || rgba) ? skipped : aov && !aovs_ok ? unwritten : NULL;
        if (aov && aovs_ok)
            *aovs |= aov;
        else if (list) /* "a", "b", ... */
            snprintf(list + strlen(list), sizeof skipped - strlen(list), "%s\"%s\"",
                     list[0] ? ", " : "", tok);
    }
    if (unwritten[0])
        fprintf(stderr,
                "rayes: warning: display \"%s\": AOVs %s are not written (AOVs are for one "
                "process without --checkpoint or --resume)\n",
                d->name, unwritten);
    if (skipped[0])
        fprintf(stderr,
                "rayes: warning: display \"%s\": %s not rendered (only rgb, rgba, z, N, P, id, "
                "patch and cache); left out\n",
                d->name, skipped);
    return *colour || *aovs;
}

/* The images a file's displays ask for: exr/openexr and png by type,
 * file and tiff by the name's extension, else OpenEXR (with a note);
 * framebuffer windows write nothing. A display's mode may name AOVs
 * (display_mode): an EXR of them beside the colour, or alone; a PNG holds
 * colour alone. --aov's AOVs go beside the colour of every EXR display. Mode rgb writes no alpha,
 * as RenderMan's displays do: a black background. The AOVs asked for are added to a->opt.aovs. */
static void outputs_from_displays(Args *a, const IoSettings *s, int aovs_ok)
{
    unsigned cli = a->opt.aovs; /* --aov's: beside the colour of every EXR display */
    for (int i = 0; i < s->n_displays && i < IO_MAX_DISPLAYS; i++) {
        const IoDisplay *d = &s->displays[i];
        const char *type = d->type[0] ? d->type : "file";
        if (strcasecmp(type, "framebuffer") == 0)
            continue;
        int colour;
        unsigned aovs;
        if (!display_mode(d, aovs_ok, &colour, &aovs))
            continue;
        int rgb = colour == 1;
        ImageFormat f = IMAGE_FORMAT_UNKNOWN;
        char path[600];
        snprintf(path, sizeof path, "%s", d->name);
        if (strcasecmp(type, "exr") == 0 || strcasecmp(type, "openexr") == 0) {
            f = IMAGE_FORMAT_EXR;
        } else if (strcasecmp(type, "png") == 0) {
            f = IMAGE_FORMAT_PNG;
        } else if (strcasecmp(type, "file") == 0 || strcasecmp(type, "tiff") == 0) {
            f = image_format_from_path(d->name);
        } else {
            fprintf(stderr,
                    "rayes: warning: display \"%s\": type \"%s\" is not supported; "
                    "skipped\n",
                    d->name, type);
            continue;
        }
        if (f == IMAGE_FORMAT_UNKNOWN) {
            const char *slash = strrchr(d->name, '/'), *dot = strrchr(d->name, '.');
            int stem = dot && (!slash || dot > slash) ? (int)(dot - d->name) : (int)strlen(d->name);
            snprintf(path, sizeof path, "%.*s.exr", stem, d->name);
            fprintf(stderr, "rayes: note: display \"%s\" (%s): written as OpenEXR to %s\n",
                    d->name, type, path);
            f = IMAGE_FORMAT_EXR;
        }
        if (f == IMAGE_FORMAT_PNG && aovs) {
            fprintf(stderr,
                    "rayes: warning: display \"%s\": AOVs are written to EXR files "
                    "only; %s\n",
                    d->name, colour ? "its colour alone is written" : "skipped");
            aovs = 0;
            if (!colour)
                continue;
        }
        Output *o = add_output(a, path, f, rgb);
        if (o) {
            o->display = 1;
            o->aovs = aovs | (colour && f == IMAGE_FORMAT_EXR ? cli : 0);
            o->no_colour = !colour;
            a->opt.aovs |= aovs;
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

/* An image's pixels as written: a crop window's alone in a PNG; in an
 * EXR the crop is the data window of the whole display window. */
static RayesError write_output(const Output *o, const RayesImage *img, int linear, char *err,
                               size_t n)
{
    int flags = (linear ? IMAGE_LINEAR : 0) | (o->no_alpha ? IMAGE_NO_ALPHA : 0);
    int win[4] = {0, 0, img->width, img->height};
    if (img->crop[2] > 0)
        memcpy(win, img->crop, sizeof win);
    if (o->format != IMAGE_FORMAT_PNG) {
        /* the AOVs it writes: a display's own (a subset of the image's), or all */
        unsigned want = img->aov ? (o->display ? o->aovs & img->aovs : img->aovs) : 0;
        int k = rayes_aov_channels(want);
        const char *names[RAYES_AOV_CHANNELS_MAX];
        float *aov = want == img->aovs ? img->aov : NULL;
        size_t npix = (size_t)img->width * (size_t)img->height;
        if (k && !aov && !(aov = malloc(sizeof(float) * (size_t)k * npix))) {
            snprintf(err, n, "%s: out of memory", o->path);
            return RAYES_ERROR_OUT_OF_MEMORY;
        }
        for (int c = 0, from = 0; c < k; c++) {
            names[c] = rayes_aov_channel_name(want, c);
            while (strcmp(rayes_aov_channel_name(img->aovs, from), names[c]) != 0)
                from++;
            for (size_t i = 0; aov != img->aov && i < npix; i++)
                aov[(size_t)k * i + (size_t)c] =
                    img->aov[(size_t)img->aov_channels * i + (size_t)from];
        }
        if (o->no_colour && k)
            flags |= IMAGE_NO_COLOUR;
        RayesError e = image_write_exr_aov(o->path, img->width, img->height, img->rgba, win, flags,
                                           aov, k, names, err, n);
        if (aov != img->aov)
            free(aov);
        return e;
    }
    if (win[2] == img->width && win[3] == img->height)
        return image_write_png_curve(o->path, img->width, img->height, img->rgba, flags, err, n);
    float *crop = malloc(sizeof(float) * 4 * (size_t)win[2] * (size_t)win[3]);
    if (!crop) {
        snprintf(err, n, "%s: out of memory", o->path);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    for (int y = 0; y < win[3]; y++)
        memcpy(crop + 4 * (size_t)y * (size_t)win[2],
               img->rgba + 4 * ((size_t)(win[1] + y) * (size_t)img->width + (size_t)win[0]),
               sizeof(float) * 4 * (size_t)win[2]);
    RayesError e = image_write_png_curve(o->path, win[2], win[3], crop, flags, err, n);
    free(crop);
    return e;
}

/* Renders frame `frame` of a's scene (-1: as --frame says) to its outputs,
 * whose '#' runs become the frame number `number` (zero-padded to the
 * run's length; -1: none), as one rank of d (NULL: one process). Returns
 * the exit status. */
static int render_job(Args a, int frame, int number, Distributed *d);

/* --frames LIST: comma-separated N, N-M or N-MxS (a step), into a new
 * array of *n frame numbers; dies with a usage error on anything else. */
static int *parse_frames(const char *list, size_t *n)
{
    size_t cap = 16;
    int *out = malloc(cap * sizeof *out);
    char buf[4096], *save = NULL;
    if (!out || strlen(list) >= sizeof buf)
        die_usage("--frames: out of memory or the list is too long");
    snprintf(buf, sizeof buf, "%s", list);
    *n = 0;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *end;
        long a = strtol(tok, &end, 10), b = a, step = 1;
        if (end != tok && *end == '-')
            b = strtol(end + 1, &end, 10);
        if (end != tok && *end == 'x')
            step = strtol(end + 1, &end, 10);
        if (end == tok || *end || a < 0 || b < a || b > INT_MAX || step < 1 || step > INT_MAX)
            die_usage("--frames: expected frames like 1-100x2 or 1,5,9-12, got \"%s\"", tok);
        for (long f = a; f <= b; f += step) {
            if (*n == 1000000)
                die_usage("--frames: more than 1000000 frames");
            if (*n == cap) {
                int *more = realloc(out, 2 * cap * sizeof *out);
                if (!more)
                    die_usage("--frames: out of memory");
                out = more, cap *= 2;
            }
            out[(*n)++] = (int)f;
        }
    }
    if (*n == 0)
        die_usage("--frames: no frame in \"%s\"", list);
    return out;
}

/* path with its '#' runs replaced by number, zero-padded to each run's
 * length; 0 if it has no '#'. */
static int frame_path(const char *path, int number, char *out, size_t size)
{
    size_t k = 0;
    int any = 0;
    for (const char *c = path; *c && k + 1 < size;) {
        if (*c != '#') {
            out[k++] = *c++;
            continue;
        }
        int width = 0;
        while (c[width] == '#')
            width++;
        int w = snprintf(out + k, size - k, "%0*d", width, number);
        k += w > 0 ? (size_t)w : 0;
        c += width;
        any = 1;
    }
    out[k < size ? k : size - 1] = '\0';
    return any;
}

static int cmd_render(int argc, char **argv)
{
    Args a = {0};
    Distributed *d = distribute_begin(&argc, &argv);
    parse_args(argc, argv, &a);
    if (d && (a.checkpoint_s >= 0.0 || a.resume))
        die_usage("--checkpoint and --resume are for one process, not an MPI job");

    if (distribute_rank(d) != 0) /* rank 0 speaks for the job */
        a.quiet = 1, a.progress_json = 0, a.stats_path = NULL;
    if (!a.frames) {
        int status = render_job(a, a.frame, -1, d);
        distribute_end(d);
        return status;
    }
    size_t n;
    int *frames = parse_frames(a.frames, &n);
    for (int i = 0; i < a.n_outputs && n > 1; i++)
        if (!strchr(a.outputs[i].path, '#'))
            die_usage("--frames: -o %s needs '#'s for the frame number, or every frame would "
                      "write it",
                      a.outputs[i].path);
    int status = 0;
    for (size_t i = 0; i < n && status == 0; i++)
        status = render_job(a, frames[i], frames[i], d);
    free(frames);
    distribute_end(d);
    return status;
}

/* The checkpoint of a's render of frame, beside its first output, taken
 * as done with --resume; NULL after printing why not. */
static Checkpoint *open_checkpoint(Args *a, int frame)
{
    char path[4200], err[1024];
    snprintf(path, sizeof path, "%s.checkpoint", a->outputs[0].path);
    double every = a->checkpoint_s >= 0.0 ? a->checkpoint_s : INFINITY;
    float camera[11] = {(float)a->camera, a->fov}; /* the command line's view */
    memcpy(camera + 2, a->look_from, sizeof a->look_from);
    memcpy(camera + 5, a->look_at, sizeof a->look_at);
    memcpy(camera + 8, a->up, sizeof a->up);
    Checkpoint *ck = checkpoint_new(
        path, checkpoint_digest(a->scene, frame, &a->opt, camera, a->camera ? sizeof camera : 0),
        &a->opt, every, a->resume, err, sizeof err);
    if (!ck) {
        fprintf(stderr, "rayes: %s\n", err);
        return NULL;
    }
    checkpoint_attach(ck, &a->opt);
    if (checkpoint_resumed_tiles(ck) && !a->quiet && !a->progress_json)
        printf("  resumed       %d tiles from %s\n", checkpoint_resumed_tiles(ck), path);
    return ck;
}

static int render_job(Args a, int frame, int number, Distributed *d)
{
    for (int i = 0; i < a.n_outputs && number >= 0; i++) {
        char path[sizeof a.outputs[i].path];
        frame_path(a.outputs[i].path, number, path, sizeof path);
        memcpy(a.outputs[i].path, path, sizeof path);
    }
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
    IoReadOptions ro = read_options(&a, frame);
    RayesError e = load_scene(a.scene, &ro, &sink, &settings, err, sizeof err);
    if (e == RAYES_OK && (e = command_line_camera(&a, scene)) != RAYES_OK)
        snprintf(err, sizeof err, "%s: the command line's camera: %s", a.scene,
                 rayes_scene_get_error(scene));
    else if (e == RAYES_OK && (e = default_light(&a, &settings, scene)) != RAYES_OK)
        snprintf(err, sizeof err, "%s: %s", a.scene, rayes_scene_get_error(scene));
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
        outputs_from_displays(&a, &settings, !d && a.checkpoint_s < 0.0 && !a.resume);
        if (a.n_outputs == 0) {
            char stem[512], path[600];
            scene_stem(a.scene, stem, sizeof stem);
            snprintf(path, sizeof path, "%s.exr", stem);
            if (settings.n_displays > 0)
                fprintf(stderr, "rayes: note: %s: no display writes a file; writing %s\n",
                        a.scene, path);
            add_output(&a, path, IMAGE_FORMAT_EXR, 0);
        }
    }
    unsigned aovs_written = 0; /* the AOVs some output holds */
    for (int k = 0; k < a.n_outputs; k++)
        if (a.outputs[k].format == IMAGE_FORMAT_EXR)
            aovs_written |= a.outputs[k].display ? a.outputs[k].aovs : a.opt.aovs;
    if (a.opt.aovs & ~aovs_written)
        fprintf(stderr, "rayes: warning: --aov: no EXR output holds %s; they are not written\n",
                aovs_written ? "some of the AOVs" : "the AOVs");
    if (a.skip_existing) { /* a farm's retry: the frame is done when all its outputs are */
        int all = 1;
        for (int i = 0; i < a.n_outputs; i++)
            all &= access(a.outputs[i].path, F_OK) == 0;
        if (all) {
            if (!a.quiet)
                printf("  skipped       %s (exists)\n", a.outputs[0].path);
            rayes_scene_release(scene);
            return 0;
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
    Checkpoint *ck = NULL;
    if ((a.checkpoint_s >= 0.0 || a.resume) && (ck = open_checkpoint(&a, frame)) == NULL) {
        rayes_scene_release(scene);
        return 1;
    }
    Progress prog = {.start = time_now(), .tty = isatty(2), .last_percent = -1, .quiet = a.quiet,
                     .json = a.progress_json, .frame = number};
    a.opt.stop = &stop; /* within a ray of the signal, even inside a tile */
    a.opt.progress = on_progress;
    a.opt.progress_user = &prog;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    RayesImage *img = NULL;
    RayesStats *stats = NULL;
    if (d && distribute_frame_begin(d, &a.opt, err, sizeof err) != 0) {
        fprintf(stderr, "rayes: %s\n", err);
        rayes_scene_release(scene);
        return 1;
    }
    e = rayes_render(scene, &a.opt, &img, &stats);
    if (d && distribute_frame_end(d, e == RAYES_OK ? img : NULL, stats, err, sizeof err) != 0 &&
        e == RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        e = RAYES_ERROR_CANCELLED;
    }
    if (e == RAYES_OK && distribute_rank(d) != 0) { /* rank 0 writes the frame */
        rayes_stats_free(stats);
        rayes_image_free(img);
        rayes_scene_release(scene);
        return 0;
    }
    if (e != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", rayes_scene_get_error(scene));
        if (ck && a.checkpoint_s >= 0.0 && e == RAYES_ERROR_CANCELLED &&
            checkpoint_save(ck, err, sizeof err) != 0)
            fprintf(stderr, "rayes: %s\n", err);
        checkpoint_free(ck);
        rayes_scene_release(scene);
        return e != RAYES_ERROR_CANCELLED ? 1 : interrupted == SIGTERM ? 143 : 130;
    }
    if (ck) {
        if (checkpoint_error(ck))
            fprintf(stderr, "rayes: warning: %s\n", checkpoint_error(ck));
        checkpoint_fill(ck, img);
    }
    if (settings.background[3] > 0.0f) /* over the background imager's colour */
        for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++) {
            float *px = img->rgba + 4 * i;
            for (int c = 0; c < 3; c++)
                px[c] += (1.0f - px[3]) * settings.background[c];
            px[3] = 1.0f;
        }
    apply_exposure(img, settings.exposure_gain, settings.exposure_gamma);
    for (size_t i = 0; settings.opaque && i < (size_t)img->width * (size_t)img->height; i++)
        img->rgba[4 * i + 3] = 1.0f; /* a pbrt film: no alpha, the environment opaque */
    int written = 0; /* outputs written whole */
    while (written < a.n_outputs && status == 0) {
        int curve = a.png_curve != IO_CURVE_UNSAID ? a.png_curve : settings.png_curve;
        if (write_output(&a.outputs[written], img, curve == IO_CURVE_LINEAR, err, sizeof err) ==
            RAYES_OK) {
            written++;
        } else {
            fprintf(stderr, "rayes: %s\n", err);
            status = 1;
        }
    }
    if (status == 0 && a.stats_path &&
        distribute_save_stats(d, a.stats_path, stats, a.scene, err, sizeof err) != 0) {
        fprintf(stderr, "rayes: %s\n", err);
        status = 1;
    }
    /* A failed run leaves none of its outputs behind; a finished one no
     * checkpoint. */
    for (int i = 0; status != 0 && i < written; i++)
        unlink(a.outputs[i].path);
    if (ck && status == 0)
        checkpoint_remove(ck);
    checkpoint_free(ck);
    if (a.progress_json) { /* the frame's end, for farm managers */
        printf("{\"event\": \"frame\", \"frame\": %d, \"status\": %d, \"seconds\": %.3f, "
               "\"outputs\": [",
               number, status, time_now() - prog.start);
        for (int i = 0; i < a.n_outputs && status == 0; i++) {
            printf("%s", i ? ", " : "");
            print_json_string(a.outputs[i].path);
        }
        printf("]}\n");
        fflush(stdout);
    } else if (status == 0 && !a.quiet) {
        summary(&a, stats);
        distribute_print_summary(d, stdout);
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
    const char *in = NULL, *out = NULL, *data_dir = default_data_dir();
    int frame = -1, quiet = 0;
    for (int i = 2; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (o[0] != '-') {
            if (out)
                die_usage("convert: expected one scene and one output (got \"%s\" too)", o);
            *(in ? &out : &in) = o;
        } else if (strcmp(o, "--quiet") == 0) {
            quiet = 1;
        } else if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0) {
            print_command_usage("convert", stdout);
            return 0;
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
    IoReadOptions ro = {.data_dir = data_dir, .frame = frame};
    RayesError e = load_scene(in, &ro, &sink, &settings, err, sizeof err);
    if (e == RAYES_OK && !(settings.width > 0 && settings.height > 0)) {
        /* a built-in scene: the size it renders at, so the RIB file (whose
         * Format would otherwise be RenderMan's 640 x 480) frames it alike */
        RayesRenderOptions d;
        rayes_render_options_init(&d, RAYES_QUALITY_PREVIEW);
        settings.width = d.width;
        settings.height = d.height;
    }
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
        print_usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_usage(stdout);
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
    if (strcmp(argv[1], "assemble") == 0)
        return cmd_assemble(argc, argv);
    die_usage("unknown command \"%s\"", argv[1]);
}
