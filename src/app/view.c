/*
 * app/view.c — `rayes view`: progressive interactive preview (docs/view.md).
 *
 * Two threads. The driver thread owns the scene and the progressive
 * session: it applies edits, commits, updates the session and renders
 * passes, one pixel sample each. The window thread (main) owns SDL: it turns
 * input into edit commands, queues them and cancels the running pass, and
 * shows the film as tiles finish. Edits are text commands, the same
 * language the --script file speaks, so the interactive path and the
 * scripted one (tested headless in CI) are one path.
 *
 * Script lines: "PASS COMMAND ...": the command runs once PASS passes have
 * been rendered since the start (lines in file order within a pass).
 * Commands:
 *   light I intensity X | light I color R G B | light I translate X Y Z
 *   light I scale F       (intensity times F)
 *   light I tint R G B    (lightcolor R G B times the largest component of
 *                          the light's colour now: a hue at the same power)
 *   light I nudge DX DY   (moves it by DX camera-rights and DY world-ups, in
 *                          fractions of the distance from the eye to the pivot)
 *   shader OBJ NAME V...  (OBJ an object index, "@X,Y" the object seen at
 *                          pixel X,Y, or "selected"; one number: a float,
 *                          three: a colour, else a string)
 *   select @X,Y           (the object later "selected" commands edit)
 *   camera orbit YAW PITCH | camera pan DX DY | camera dolly F
 *                         (degrees about the pivot, the point first seen at
 *                          the image centre; pan in fractions of the
 *                          distance to it; dolly moves that fraction of it
 *                          closer)
 *   exposure E | gamma G  (display and written images)
 *   write FILE            (.png or .exr: the image so far)
 *   quit
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef RAYES_HAVE_SDL
#include <SDL.h>
#endif

#include "app/cli.h"
#include "app/view.h"
#include "image/image.h"
#include "util/colour.h"
#include "util/log.h"
#include "util/vec.h"

#define MAX_QUEUE 256
#define LINE_MAX_LEN 512

typedef struct ScriptLine {
    int pass;
    int line;                   /* in the script file */
    char text[LINE_MAX_LEN];
} ScriptLine;

typedef struct View {
    Args *args;
    RayesScene *scene;
    RayesSession *session;
    int width, height;
    const char *script_name;
    ScriptLine *script;
    size_t n_script, next_script;
    /* Camera pivot and the world's up (the first camera's y). */
    Vec3 pivot, up;
    int64_t selected;           /* object "selected" names, or -1 */
    /* Shared between the threads, under lock. */
    pthread_mutex_t lock;
    pthread_cond_t wake;
    char queue[MAX_QUEUE][LINE_MAX_LEN];
    int n_queue;
    int quit;                   /* the driver stops */
    int finished;               /* the driver reached --passes */
    int failed;                 /* exit status 1: a script command failed */
    float *display;             /* the film as tiles finish, width * height * 4 */
    int display_dirty;
    float exposure, gamma;
    int passes;                 /* rendered since the start */
    int samples;
    double pass_s, hit[3], points_per_s;
} View;

/* ------------------------------------------------------------ commands */

static int parse_floats(const char *s, float *out, int max)
{
    int n = 0;
    while (n < max) {
        char *end;
        errno = 0;
        float f = strtof(s, &end);
        if (end == s || errno || !isfinite(f))
            break;
        out[n++] = f;
        s = end;
    }
    while (isspace((unsigned char)*s))
        s++;
    return *s ? -1 : n;
}

static RayesError image_of(View *v, RayesImage **img)
{
    RayesError e = rayes_session_image(v->session, img);
    if (e != RAYES_OK)
        return e;
    pthread_mutex_lock(&v->lock); /* the window thread sets them */
    float gain = exp2f(v->exposure), g = v->gamma;
    pthread_mutex_unlock(&v->lock);
    size_t n = (size_t)(*img)->width * (size_t)(*img)->height;
    if (gain != 1.0f || g != 1.0f)
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                float x = fmaxf((*img)->rgba[4 * i + c] * gain, 0.0f);
                (*img)->rgba[4 * i + c] = g != 1.0f ? powf(x, 1.0f / g) : x;
            }
    return RAYES_OK;
}

static void camera_axes(View *v, Vec3 *eye, Vec3 *x, Vec3 *y, Vec3 *z)
{
    float e[3], a[3], b[3], c[3];
    rayes_scene_get_camera(v->scene, e, a, b, c);
    *eye = v3_load(e);
    *x = v3_normalize(v3_load(a));
    *y = v3_normalize(v3_load(b));
    *z = v3_normalize(v3_load(c));
}

static RayesError move_camera(View *v, Mat4 m)
{
    float a[16];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            a[4 * r + c] = m.m[r][c];
    return rayes_scene_move_camera(v->scene, a);
}

static int pick(View *v, const char *at, int64_t *object, char *err, size_t n)
{
    float x, y;
    if (sscanf(at, "@%f,%f", &x, &y) != 2 || x < 0 || y < 0 || x >= (float)v->width ||
        y >= (float)v->height) {
        snprintf(err, n, "expected @X,Y inside the %dx%d image, got \"%s\"", v->width,
                 v->height, at);
        return -1;
    }
    rayes_session_pick(v->session, x, y, object, NULL);
    if (*object < 0) {
        snprintf(err, n, "nothing is seen at %s", at);
        return -1;
    }
    return 0;
}

/* The scene's error as the command's (cleared for the next edit): -1. */
static int scene_failed(View *v, char *err, size_t n)
{
    snprintf(err, n, "%s", rayes_scene_get_error(v->scene));
    rayes_scene_clear_error(v->scene);
    return -1;
}

/* Runs one command; *edited is set when the scene changed (commit and
 * update follow). Returns 0, 1 for quit, or -1 with err filled. */
static int run_command(View *v, const char *cmd, int *edited, char *err, size_t n)
{
    char word[64] = "", arg[64] = "", name[64] = "";
    int used = 0;
    sscanf(cmd, " %63s %n", word, &used);
    const char *rest = cmd + used;
    if (!word[0] || word[0] == '#')
        return 0;
    if (strcmp(word, "quit") == 0)
        return 1;
    if (strcmp(word, "exposure") == 0 || strcmp(word, "gamma") == 0) {
        float f;
        if (parse_floats(rest, &f, 1) != 1 || (word[0] == 'g' && !(f > 0.0f))) {
            snprintf(err, n, "%s: expected a number%s", word, word[0] == 'g' ? " > 0" : "");
            return -1;
        }
        pthread_mutex_lock(&v->lock);
        *(word[0] == 'e' ? &v->exposure : &v->gamma) = f;
        v->display_dirty = 1;
        pthread_mutex_unlock(&v->lock);
        return 0;
    }
    if (strcmp(word, "write") == 0) {
        char path[LINE_MAX_LEN];
        if (sscanf(rest, "%511s", path) != 1 || image_format_from_path(path) == IMAGE_FORMAT_UNKNOWN) {
            snprintf(err, n, "write: expected a file name ending in .png or .exr");
            return -1;
        }
        RayesImage *img = NULL;
        RayesError e = image_of(v, &img);
        if (e == RAYES_OK)
            e = image_write(path, img->width, img->height, img->rgba, err, n);
        else
            snprintf(err, n, "write: out of memory");
        rayes_image_free(img);
        return e == RAYES_OK ? 0 : -1;
    }
    if (strcmp(word, "select") == 0) {
        int64_t object;
        if (pick(v, rest, &object, err, n) != 0)
            return -1;
        v->selected = object;
        printf("selected object %lld (%s)\n", (long long)object,
               rayes_scene_object_shader(v->scene, (size_t)object));
        return 0;
    }
    if (strcmp(word, "light") == 0) {
        long index;
        int k = 0;
        if (sscanf(rest, "%ld %63s %n", &index, name, &k) < 2 || index < 0) {
            snprintf(err, n, "light: expected an index and intensity, color, translate or scale");
            return -1;
        }
        float f[3], now = 0.0f, c[3] = {0, 0, 0};
        int count = parse_floats(rest + k, f, 3);
        int relative = strcmp(name, "scale") == 0 || strcmp(name, "tint") == 0;
        if (relative && rayes_scene_get_light(v->scene, (size_t)index, &now, c, NULL) != RAYES_OK) {
            snprintf(err, n, "light: no light %ld", index);
            return -1;
        }
        RayesParam p = {0};
        if (strcmp(name, "intensity") == 0 && count == 1)
            p = (RayesParam){"intensity", RAYES_PARAM_FLOAT, {f[0], 0, 0}, NULL};
        else if (strcmp(name, "nudge") == 0 && count == 2) {
            Vec3 eye, x, y, z;
            camera_axes(v, &eye, &x, &y, &z);
            float d = v3_length(v3_sub(v->pivot, eye));
            Vec3 t = v3_scale(v3_add(v3_scale(x, f[0]), v3_scale(v->up, f[1])), d);
            p = (RayesParam){"translate", RAYES_PARAM_COLOR, {t.x, t.y, t.z}, NULL};
        } else if (strcmp(name, "scale") == 0 && count == 1) {
            p = (RayesParam){"intensity", RAYES_PARAM_FLOAT, {now * f[0], 0, 0}, NULL};
        } else if (strcmp(name, "tint") == 0 && count == 3) {
            float m = fmaxf(c[0], fmaxf(c[1], c[2]));
            p = (RayesParam){"lightcolor", RAYES_PARAM_COLOR, {f[0] * m, f[1] * m, f[2] * m}, NULL};
        } else if ((strcmp(name, "color") == 0 || strcmp(name, "translate") == 0) && count == 3)
            p = (RayesParam){name[0] == 'c' ? "lightcolor" : "translate", RAYES_PARAM_COLOR,
                             {f[0], f[1], f[2]}, NULL};
        else {
            snprintf(err, n, "light: expected intensity X, scale F, color R G B, tint R G B, "
                             "translate X Y Z or nudge DX DY");
            return -1;
        }
        if (rayes_scene_edit_light(v->scene, (size_t)index, &p, 1) != RAYES_OK) {
            return scene_failed(v, err, n);
        }
        *edited = 1;
        return 0;
    }
    if (strcmp(word, "shader") == 0) {
        int k = 0;
        if (sscanf(rest, "%63s %63s %n", arg, name, &k) < 2) {
            snprintf(err, n, "shader: expected an object, a parameter name and values");
            return -1;
        }
        int64_t object = -1;
        if (arg[0] == '@') {
            if (pick(v, arg, &object, err, n) != 0)
                return -1;
        } else if (strcmp(arg, "selected") == 0) {
            object = v->selected;
            if (object < 0) {
                snprintf(err, n, "shader: no object is selected (click one, or select @X,Y)");
                return -1;
            }
        } else {
            char *end;
            object = strtol(arg, &end, 10);
            if (*end || object < 0) {
                snprintf(err, n, "shader: expected an object index, @X,Y or selected, got \"%s\"",
                         arg);
                return -1;
            }
        }
        float f[3];
        int count = parse_floats(rest + k, f, 3);
        char value[LINE_MAX_LEN];
        RayesParam p = {name, RAYES_PARAM_FLOAT, {0, 0, 0}, NULL};
        if (count == 1 || count == 3) {
            p.type = count == 1 ? RAYES_PARAM_FLOAT : RAYES_PARAM_COLOR;
            memcpy(p.value, f, sizeof(float) * (size_t)count);
        } else if (sscanf(rest + k, "%511s", value) == 1) {
            p.type = RAYES_PARAM_STRING;
            p.string = value;
        } else {
            snprintf(err, n, "shader: expected one number, three, or a string after \"%s\"", name);
            return -1;
        }
        if (rayes_scene_edit_shader(v->scene, (size_t)object, &p, 1) != RAYES_OK) {
            return scene_failed(v, err, n);
        }
        *edited = 1;
        return 0;
    }
    if (strcmp(word, "camera") == 0) {
        int k = 0;
        float f[2];
        sscanf(rest, "%63s %n", name, &k);
        int count = parse_floats(rest + k, f, 2);
        Vec3 eye, x, y, z;
        camera_axes(v, &eye, &x, &y, &z);
        float dist = fmaxf(v3_length(v3_sub(v->pivot, eye)), 1e-6f);
        Mat4 m;
        if (strcmp(name, "orbit") == 0 && count == 2) {
            Mat4 to = mat4_translate(-v->pivot.x, -v->pivot.y, -v->pivot.z);
            Mat4 back = mat4_translate(v->pivot.x, v->pivot.y, v->pivot.z);
            m = mat4_mul(back, mat4_mul(mat4_rotate(f[0], v->up),
                                        mat4_mul(mat4_rotate(f[1], x), to)));
        } else if (strcmp(name, "pan") == 0 && count == 2) {
            Vec3 t = v3_scale(v3_add(v3_scale(x, -f[0]), v3_scale(y, f[1])), dist);
            m = mat4_translate(t.x, t.y, t.z);
            v->pivot = v3_add(v->pivot, t);
        } else if (strcmp(name, "dolly") == 0 && count == 1 && f[0] < 1.0f) {
            Vec3 t = v3_scale(z, f[0] * dist);
            m = mat4_translate(t.x, t.y, t.z);
        } else {
            snprintf(err, n, "camera: expected orbit YAW PITCH, pan DX DY or dolly F (F < 1)");
            return -1;
        }
        if (move_camera(v, m) != RAYES_OK) {
            return scene_failed(v, err, n);
        }
        *edited = 1;
        return 0;
    }
    snprintf(err, n, "unknown command \"%s\" (expected light, shader, select, camera, exposure, "
                     "gamma, write or quit)",
             word);
    return -1;
}

/* --------------------------------------------------------------- script */

static int load_script(View *v, const char *path)
{
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "r");
    v->script_name = strcmp(path, "-") == 0 ? "<stdin>" : path;
    if (!f) {
        fprintf(stderr, "rayes: %s: cannot open: %s\n", path, strerror(errno));
        return -1;
    }
    char buf[LINE_MAX_LEN + 2];
    int lineno = 0, status = 0;
    size_t cap = 0;
    while (status == 0 && fgets(buf, sizeof buf, f)) {
        lineno++;
        size_t len = strlen(buf);
        if (len == sizeof buf - 1 && buf[len - 1] != '\n') {
            fprintf(stderr, "rayes: %s:%d: line longer than %d characters\n", v->script_name,
                    lineno, LINE_MAX_LEN);
            status = -1;
            break;
        }
        buf[strcspn(buf, "\r\n")] = '\0';
        const char *s = buf;
        while (isspace((unsigned char)*s))
            s++;
        if (!*s || *s == '#')
            continue;
        char *end;
        errno = 0;
        long pass = strtol(s, &end, 10);
        if (end == s || errno || pass < 0 || pass > 1 << 20 || !isspace((unsigned char)*end)) {
            fprintf(stderr, "rayes: %s:%d:1: expected a pass number, then a command\n",
                    v->script_name, lineno);
            status = -1;
            break;
        }
        if (v->n_script && pass < v->script[v->n_script - 1].pass) {
            fprintf(stderr, "rayes: %s:%d:1: passes must not decrease (%ld after %d)\n",
                    v->script_name, lineno, pass, v->script[v->n_script - 1].pass);
            status = -1;
            break;
        }
        if (v->n_script == cap) {
            cap = cap ? 2 * cap : 16;
            ScriptLine *grown = realloc(v->script, cap * sizeof *grown);
            if (!grown) {
                status = -1;
                break;
            }
            v->script = grown;
        }
        ScriptLine *l = &v->script[v->n_script++];
        l->pass = (int)pass;
        l->line = lineno;
        while (isspace((unsigned char)*end))
            end++;
        snprintf(l->text, sizeof l->text, "%s", end);
    }
    if (f != stdin)
        fclose(f);
    return status;
}

/* --------------------------------------------------------------- driver */

static void on_tile(void *user, int x, int y, int w, int h, const float *rgba, int stride)
{
    View *v = user;
    pthread_mutex_lock(&v->lock);
    for (int j = y; j < y + h; j++)
        memcpy(&v->display[4 * ((size_t)j * v->width + x)], &rgba[4 * ((size_t)j * stride + x)],
               sizeof(float) * 4 * (size_t)w);
    v->display_dirty = 1;
    pthread_mutex_unlock(&v->lock);
}

static double stat_of(const RayesStats *st, const char *name)
{
    const RayesStat *s = rayes_stats_find(st, name);
    return !s ? 0.0 : s->kind == RAYES_STAT_REAL ? s->real : (double)s->count;
}

static void pass_done(View *v)
{
    RayesStats *st = NULL;
    if (rayes_session_stats(v->session, &st) != RAYES_OK)
        return;
    pthread_mutex_lock(&v->lock);
    v->passes++;
    v->samples = rayes_session_samples(v->session);
    v->pass_s = stat_of(st, "time/render_s");
    v->hit[0] = stat_of(st, "cache/coarse/hit_rate");
    v->hit[1] = stat_of(st, "cache/medium/hit_rate");
    v->hit[2] = stat_of(st, "cache/fine/hit_rate");
    v->points_per_s = v->pass_s > 0 ? stat_of(st, "shading_points/total") / v->pass_s : 0;
    pthread_mutex_unlock(&v->lock);
    rayes_stats_free(st);
}

static void status_line(View *v, char *buf, size_t n)
{
    pthread_mutex_lock(&v->lock);
    snprintf(buf, n,
             "pass %d, %d spp, %.3f s/pass, cache hits %.1f%% %.1f%% %.1f%% (coarse medium "
             "fine), %.2f M shading points/s, exposure %+.1f, gamma %.2f",
             v->passes, v->samples, v->pass_s, 100 * v->hit[0], 100 * v->hit[1], 100 * v->hit[2],
             v->points_per_s * 1e-6, v->exposure, v->gamma);
    pthread_mutex_unlock(&v->lock);
}

/* Runs a list of commands; commits and updates the session if any edited.
 * Script errors name the script's line and stop the view. */
static int apply(View *v, char (*cmds)[LINE_MAX_LEN], const int *lines, int n)
{
    int edited = 0, status = 0;
    for (int i = 0; i < n && status == 0; i++) {
        char err[600] = "";
        int r = run_command(v, cmds[i], &edited, err, sizeof err);
        if (r < 0 && lines) {
            fprintf(stderr, "rayes: %s:%d: %s\n", v->script_name, lines[i], err);
            status = -1;
        } else if (r < 0) {
            fprintf(stderr, "rayes: view: %s\n", err);
        } else if (r > 0) {
            status = 1;
        }
    }
    if (edited) {
        RayesError e = rayes_scene_commit(v->scene);
        if (e == RAYES_OK)
            e = rayes_session_update(v->session);
        if (e != RAYES_OK) {
            fprintf(stderr, "rayes: view: %s\n", rayes_scene_get_error(v->scene));
            status = -1;
        }
    }
    return status;
}

/* The driver: script lines due at this pass, queued commands, a pass. */
static void *drive(void *arg)
{
    View *v = arg;
    static char cmds[MAX_QUEUE][LINE_MAX_LEN];
    int lines[MAX_QUEUE];
    int limit = v->args->passes;          /* headless: passes in all */
    int target = limit > 0 ? limit : 256; /* window: samples to refine to after an edit */
    int rendered = 0;
    for (;;) {
        int n = 0;
        while (v->next_script < v->n_script && v->script[v->next_script].pass <= rendered &&
               n < MAX_QUEUE) {
            memcpy(cmds[n], v->script[v->next_script].text, LINE_MAX_LEN);
            lines[n++] = v->script[v->next_script++].line;
        }
        int status = n ? apply(v, cmds, lines, n) : 0;
        pthread_mutex_lock(&v->lock);
        int q = v->n_queue;
        memcpy(cmds, v->queue, sizeof cmds[0] * (size_t)q);
        v->n_queue = 0;
        pthread_mutex_unlock(&v->lock);
        if (status == 0 && q)
            status = apply(v, cmds, NULL, q);
        pthread_mutex_lock(&v->lock);
        if (status < 0 && !v->failed)
            v->failed = 1;
        int script_left = v->next_script < v->n_script;
        int headless_done = v->args->headless && !script_left && rendered >= limit;
        if (status != 0 || v->quit || headless_done) {
            v->quit = 1;
            v->finished = 1;
            pthread_mutex_unlock(&v->lock);
            break;
        }
        if (!v->args->headless && !script_left &&
            rayes_session_samples(v->session) >= target) {
            v->finished = 1; /* idle until an edit or quit */
            while (!v->quit && v->n_queue == 0)
                pthread_cond_wait(&v->wake, &v->lock);
            pthread_mutex_unlock(&v->lock);
            continue;
        }
        pthread_mutex_unlock(&v->lock);
        RayesError e = rayes_session_render_pass(v->session);
        if (e == RAYES_OK) {
            rendered++;
            pass_done(v);
            if (v->args->headless && !v->args->quiet) {
                char buf[300];
                status_line(v, buf, sizeof buf);
                printf("%s\n", buf);
            }
        } else if (e != RAYES_ERROR_CANCELLED) {
            fprintf(stderr, "rayes: view: %s\n", rayes_scene_get_error(v->scene));
            pthread_mutex_lock(&v->lock);
            v->failed = v->quit = v->finished = 1;
            pthread_mutex_unlock(&v->lock);
            break;
        }
    }
    return NULL;
}

/* Queues a command for the driver; an edit (cancel) also cancels the
 * running pass, others wait for it to end. */
static void post(View *v, int cancel, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void post(View *v, int cancel, const char *fmt, ...)
{
    va_list ap;
    pthread_mutex_lock(&v->lock);
    if (v->n_queue < MAX_QUEUE) {
        va_start(ap, fmt);
        vsnprintf(v->queue[v->n_queue++], LINE_MAX_LEN, fmt, ap);
        va_end(ap);
    }
    pthread_cond_signal(&v->wake);
    pthread_mutex_unlock(&v->lock);
    if (cancel)
        rayes_session_cancel(v->session);
}

/* Display settings change at once, without a pass. */
static void adjust(View *v, float exposure_step, float gamma_step)
{
    pthread_mutex_lock(&v->lock);
    v->exposure += exposure_step;
    v->gamma = fmaxf(v->gamma + gamma_step, 0.1f);
    v->display_dirty = 1;
    pthread_mutex_unlock(&v->lock);
}

/* --------------------------------------------------------------- window */

#ifdef RAYES_HAVE_SDL
static uint8_t to_display(float x, float gain, float inv_gamma)
{
    x = fmaxf(x * gain, 0.0f);
    if (inv_gamma != 1.0f)
        x = powf(x, inv_gamma);
    x = colour_linear_to_srgb(x);
    return (uint8_t)lrintf(fminf(fmaxf(x, 0.0f), 1.0f) * 255.0f);
}

/* Converts the film for the window, if it changed. */
static int refresh(View *v, uint32_t *pixels)
{
    pthread_mutex_lock(&v->lock);
    int dirty = v->display_dirty;
    v->display_dirty = 0;
    float gain = exp2f(v->exposure), ig = 1.0f / v->gamma;
    if (dirty)
        for (size_t i = 0; i < (size_t)v->width * v->height; i++) {
            const float *p = &v->display[4 * i];
            pixels[i] = 0xff000000u | (uint32_t)to_display(p[0], gain, ig) << 16 |
                        (uint32_t)to_display(p[1], gain, ig) << 8 | to_display(p[2], gain, ig);
        }
    pthread_mutex_unlock(&v->lock);
    return dirty;
}

/* Writes what the window shows (its renderer's pixels) as a PNG. */
static int screenshot(SDL_Renderer *r, View *v, const char *path)
{
    int w = v->width, h = v->height;
    uint8_t *px = malloc((size_t)w * h * 4);
    float *rgba = malloc(sizeof(float) * 4 * (size_t)w * h);
    char err[600];
    int status = -1;
    if (px && rgba && SDL_RenderReadPixels(r, NULL, SDL_PIXELFORMAT_ABGR8888, px, w * 4) == 0) {
        for (size_t i = 0; i < (size_t)w * h; i++)
            for (int c = 0; c < 4; c++) {
                float x = px[4 * i + c] / 255.0f; /* back to linear, so the file holds it */
                rgba[4 * i + c] = c == 3 ? 1.0f : colour_srgb_to_linear(x);
            }
        status = image_write_png(path, w, h, rgba, err, sizeof err) == RAYES_OK ? 0 : -1;
        if (status)
            fprintf(stderr, "rayes: %s\n", err);
    } else {
        fprintf(stderr, "rayes: --screenshot: %s\n", SDL_GetError());
    }
    free(px);
    free(rgba);
    return status;
}

static int window_loop(View *v)
{
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "rayes: view: no display (%s); use --headless\n", SDL_GetError());
        return -1;
    }
    SDL_Window *win = SDL_CreateWindow("rayes view", SDL_WINDOWPOS_UNDEFINED,
                                       SDL_WINDOWPOS_UNDEFINED, v->width, v->height,
                                       SDL_WINDOW_RESIZABLE);
    SDL_Renderer *r = win ? SDL_CreateRenderer(win, -1, 0) : NULL;
    SDL_Texture *tex = r ? SDL_CreateTexture(r, SDL_PIXELFORMAT_ARGB8888,
                                             SDL_TEXTUREACCESS_STREAMING, v->width, v->height)
                         : NULL;
    uint32_t *pixels = calloc((size_t)v->width * v->height, sizeof *pixels);
    if (!win || !r || !tex || !pixels) {
        fprintf(stderr, "rayes: view: cannot open a window (%s); use --headless\n",
                SDL_GetError());
        free(pixels);
        if (r)
            SDL_DestroyRenderer(r);
        if (win)
            SDL_DestroyWindow(win);
        SDL_Quit();
        return -1;
    }
    SDL_RenderSetLogicalSize(r, v->width, v->height);
    int status = 0, light = 0, n_lights = (int)rayes_scene_light_count(v->scene);
    int down_x = 0, down_y = 0, last_x = 0, last_y = 0, dragged = 0;
    Uint32 buttons = 0;
    static const float colors[4][3] = {{1, 1, 1}, {1, 0.75f, 0.5f}, {0.6f, 0.75f, 1}, {1, 0.4f, 0.4f}};
    static const float tints[5][3] = {{0.8f, 0.15f, 0.1f}, {0.15f, 0.6f, 0.2f},
                                      {0.15f, 0.25f, 0.8f}, {0.9f, 0.9f, 0.9f}, {0.9f, 0.6f, 0.1f}};
    int color = 0, tint = 0, shots = 0;
    double last_title = 0.0;
    for (int running = 1; running;) {
        SDL_Event ev;
        while (SDL_PollEvent(&ev)) {
            if (ev.type == SDL_QUIT) {
                running = 0;
            } else if (ev.type == SDL_MOUSEBUTTONDOWN) {
                down_x = last_x = ev.button.x;
                down_y = last_y = ev.button.y;
                dragged = 0;
                buttons = SDL_GetMouseState(NULL, NULL);
            } else if (ev.type == SDL_MOUSEMOTION && ev.motion.state) {
                int dx = ev.motion.x - last_x, dy = ev.motion.y - last_y;
                last_x = ev.motion.x;
                last_y = ev.motion.y;
                if (abs(last_x - down_x) + abs(last_y - down_y) > 3)
                    dragged = 1;
                if (!dragged || (!dx && !dy))
                    continue;
                int shift = (SDL_GetModState() & KMOD_SHIFT) != 0;
                if ((ev.motion.state & SDL_BUTTON_MMASK) ||
                    ((ev.motion.state & SDL_BUTTON_LMASK) && shift))
                    post(v, 1, "camera pan %g %g", (double)dx / v->height, (double)dy / v->height);
                else if (ev.motion.state & SDL_BUTTON_RMASK)
                    post(v, 1, "camera dolly %g", fmax(-2.0, -2.0 * dy / v->height));
                else if (ev.motion.state & SDL_BUTTON_LMASK)
                    post(v, 1, "camera orbit %g %g", -0.3 * dx, -0.3 * dy);
            } else if (ev.type == SDL_MOUSEBUTTONUP) {
                if (!dragged && ev.button.button == SDL_BUTTON_LEFT && (buttons & SDL_BUTTON_LMASK))
                    post(v, 0, "select @%d,%d", ev.button.x, ev.button.y);
            } else if (ev.type == SDL_MOUSEWHEEL) {
                post(v, 1, "camera dolly %g", 0.1 * ev.wheel.y);
            } else if (ev.type == SDL_KEYDOWN) {
                SDL_Keycode k = ev.key.keysym.sym;
                float step = 0.05f;
                if (k == SDLK_ESCAPE || k == SDLK_q)
                    running = 0;
                else if (k == SDLK_EQUALS || k == SDLK_PLUS || k == SDLK_KP_PLUS)
                    adjust(v, 0.5f, 0.0f);
                else if (k == SDLK_MINUS || k == SDLK_KP_MINUS)
                    adjust(v, -0.5f, 0.0f);
                else if (k == SDLK_RIGHTBRACKET)
                    adjust(v, 0.0f, 0.1f);
                else if (k == SDLK_LEFTBRACKET)
                    adjust(v, 0.0f, -0.1f);
                else if (k == SDLK_l && n_lights)
                    printf("light %d selected\n", light = (light + 1) % n_lights);
                else if (k == SDLK_UP && n_lights)
                    post(v, 1, "light %d scale 1.25", light);
                else if (k == SDLK_DOWN && n_lights)
                    post(v, 1, "light %d scale 0.8", light);
                else if (k == SDLK_c && n_lights) {
                    color = (color + 1) % 4;
                    post(v, 1, "light %d tint %g %g %g", light, colors[color][0], colors[color][1],
                         colors[color][2]);
                } else if ((k == SDLK_LEFT || k == SDLK_RIGHT || k == SDLK_PAGEUP ||
                            k == SDLK_PAGEDOWN) && n_lights) {
                    float dx = k == SDLK_LEFT ? -step : k == SDLK_RIGHT ? step : 0.0f;
                    float dy = k == SDLK_PAGEUP ? step : k == SDLK_PAGEDOWN ? -step : 0.0f;
                    post(v, 1, "light %d nudge %g %g", light, (double)dx, (double)dy);
                } else if (k == SDLK_m) {
                    tint = (tint + 1) % 5;
                    post(v, 1, "shader selected Cs %g %g %g", tints[tint][0], tints[tint][1],
                         tints[tint][2]);
                } else if (k == SDLK_s) {
                    post(v, 0, "write rayes-view-%d.png", ++shots);
                }
            }
        }
        if (refresh(v, pixels)) {
            SDL_UpdateTexture(tex, NULL, pixels, v->width * (int)sizeof *pixels);
            SDL_RenderClear(r);
            SDL_RenderCopy(r, tex, NULL, NULL);
            SDL_RenderPresent(r);
        }
        double now = time_now();
        if (now - last_title > 0.25) {
            char buf[300];
            status_line(v, buf, sizeof buf);
            SDL_SetWindowTitle(win, buf);
            last_title = now;
        }
        pthread_mutex_lock(&v->lock);
        int finished = v->finished, quit = v->quit;
        pthread_mutex_unlock(&v->lock);
        if (quit)
            running = 0;
        if (finished && v->args->screenshot) {
            refresh(v, pixels);
            SDL_UpdateTexture(tex, NULL, pixels, v->width * (int)sizeof *pixels);
            SDL_RenderClear(r);
            SDL_RenderCopy(r, tex, NULL, NULL);
            status = screenshot(r, v, v->args->screenshot);
            SDL_RenderPresent(r);
            running = 0;
        }
        SDL_Delay(15);
    }
    free(pixels);
    SDL_DestroyTexture(tex);
    SDL_DestroyRenderer(r);
    SDL_DestroyWindow(win);
    SDL_Quit();
    return status;
}
#endif

/* ----------------------------------------------------------------- main */

int cmd_view(int argc, char **argv)
{
    Args a = {.view = 1};
    parse_args(argc, argv, &a);
    if (a.opt.aovs)
        die_usage("--aov: rayes view shows colour alone; use rayes render");
#ifndef RAYES_HAVE_SDL
    if (!a.headless) {
        fprintf(stderr, "rayes: view: built without SDL2 (libsdl2-dev); use --headless\n");
        return 1;
    }
#endif
    if (a.screenshot && (a.headless || a.passes <= 0))
        die_usage("--screenshot: needs a window and --passes N");
    View v = {.args = &a, .selected = -1, .exposure = a.exposure, .gamma = a.gamma};
    if (a.script && load_script(&v, a.script) != 0) {
        free(v.script);
        return 1;
    }
    v.scene = rayes_scene_new();
    char err[1024];
    IoSettings settings;
    IoSink sink = io_sink_scene(v.scene);
    IoReadOptions ro = read_options(&a, a.frame);
    RayesError e = load_scene(a.scene, &ro, &sink, &settings, err, sizeof err);
    if (e == RAYES_OK && (e = command_line_camera(&a, v.scene)) != RAYES_OK)
        snprintf(err, sizeof err, "%s: the command line's camera: %s", a.scene,
                 rayes_scene_get_error(v.scene));
    else if (e == RAYES_OK && (e = default_light(&a, &settings, v.scene)) != RAYES_OK)
        snprintf(err, sizeof err, "%s: %s", a.scene, rayes_scene_get_error(v.scene));
    if (e == RAYES_OK && rayes_scene_commit(v.scene) != RAYES_OK) {
        e = RAYES_ERROR_PARSE;
        snprintf(err, sizeof err, "%s: %s", a.scene, rayes_scene_get_error(v.scene));
    }
    if (e != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        rayes_scene_release(v.scene);
        free(v.script);
        return load_status(a.scene, e);
    }
    merge_settings(&a, &settings);
    /* the scene's own exposure (RIB Exposure, pbrt's iso and shutter), as
     * rayes render applies it, under the viewer's */
    if (settings.exposure_gain > 0.0f && settings.exposure_gain != 1.0f)
        v.exposure += log2f(settings.exposure_gain);
    if (settings.exposure_gamma > 0.0f)
        v.gamma *= settings.exposure_gamma;
    v.width = a.opt.width;
    v.height = a.opt.height;
    a.opt.tile_done = on_tile;
    a.opt.tile_user = &v;
    v.display = calloc((size_t)v.width * v.height * 4, sizeof(float));
    pthread_mutex_init(&v.lock, NULL);
    pthread_cond_init(&v.wake, NULL);
    int status = 0;
    if (!v.display || rayes_session_new(v.scene, &a.opt, &v.session) != RAYES_OK) {
        fprintf(stderr, "rayes: view: %s\n", v.display ? rayes_scene_get_error(v.scene)
                                                       : "out of memory");
        status = 1;
    }
    if (status == 0) {
        Vec3 eye, x, y, z;
        camera_axes(&v, &eye, &x, &y, &z);
        v.up = y;
        float at[3];
        int64_t object;
        rayes_session_pick(v.session, 0.5f * v.width, 0.5f * v.height, &object, at);
        v.pivot = object >= 0 ? v3_load(at) : v3_add(eye, z);
        pthread_t driver;
        pthread_create(&driver, NULL, drive, &v);
#ifdef RAYES_HAVE_SDL
        if (!a.headless) {
            if (window_loop(&v) != 0)
                status = 1;
            pthread_mutex_lock(&v.lock);
            v.quit = 1;
            pthread_cond_signal(&v.wake);
            pthread_mutex_unlock(&v.lock);
            rayes_session_cancel(v.session);
        }
#endif
        pthread_join(driver, NULL);
        if (v.failed)
            status = 1;
    }
    rayes_session_free(v.session);
    rayes_scene_release(v.scene);
    pthread_mutex_destroy(&v.lock);
    pthread_cond_destroy(&v.wake);
    free(v.display);
    free(v.script);
    return status;
}
