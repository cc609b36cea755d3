/*
 * io/rib_write.c — the RIB writer of rib_write.h. Three memory streams
 * (open_memstream) hold what comes before WorldBegin (options: search
 * paths), the camera (replaced by each camera call) and the world; finish
 * puts them in order after the settings.
 */
#include "io/rib_write.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_internal.h"
#include "rayes/shader.h"

/* A growing text in memory. */
typedef struct Stream {
    char *buf;
    size_t size;
    FILE *f;
} Stream;

struct RibWriter {
    Stream options;          /* before the camera: Option "searchpath" */
    Stream camera;           /* Projection, ScreenWindow, Transform */
    Stream world;            /* between WorldBegin and WorldEnd */
    float fov_y;             /* set_camera's vertical fov (-1: a camera matrix, or none) */
    int in_transform;        /* a TransformBegin is open */
    int bezier_basis;        /* Basis "bezier" was written */
    int opacity_set;         /* the last Opacity was not 1 1 1 */
    int next_light;          /* the next light handle (a light's index + 1) */
    int links_mode;          /* RayesLightLinks in force */
    size_t *links, n_links;  /* their lights; owned */
    unsigned char off[4097]; /* by handle: turned off by an Illuminate written */
    unsigned char area[4097]; /* by handle: an area light (not linkable in RIB) */
    uint32_t visibility;      /* the RayesRayType bits written last (default: all) */
    int hitmode, opacity_cache; /* the opacity mode written last (default: shader, 1) */
    int in_object;           /* inside ObjectBegin ... ObjectEnd */
    struct {                 /* what ObjectBegin saved (ObjectEnd restores attributes) */
        int in_transform, opacity_set, hitmode, opacity_cache;
        uint32_t visibility;
    } outer;
    float shutter[2];        /* Shutter (written when open < close) */
    float lens[2];           /* lens radius (0: none) and focal distance: DepthOfField */
    float motionfactor, focusfactor; /* Attribute "dice" written last */
    Stream motion;           /* a deformation block's samples, until motion_end */
    FILE *world_f;           /* the world stream's FILE while motion holds the output */
    size_t motion_n;         /* the block's time samples (0: none open) */
    float motion_time[RAYES_MAX_TIMES];
    char *shader;            /* the last shader's name and parameters as written (for
                                Atmosphere), owned, or NULL */
    char *atmosphere;        /* the Atmosphere line, written first in the world (it is
                                an attribute of the primitives after it), owned, or NULL */
    char error[256];         /* the last error, "" if none */
};

static void stream_close(Stream *s)
{
    if (s->f)
        fclose(s->f);
    s->f = NULL;
    free(s->buf);
    s->buf = NULL;
    s->size = 0;
}

/* Opens s empty (closing what it held). */
static int stream_open(Stream *s)
{
    stream_close(s);
    s->f = open_memstream(&s->buf, &s->size);
    return s->f ? 0 : -1;
}

RibWriter *io_rib_writer_new(void)
{
    RibWriter *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->next_light = 1;
    w->visibility = RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR | RAYES_RAY_SHADOW;
    w->opacity_cache = 1;
    w->fov_y = -1.0f;
    if (stream_open(&w->options) != 0 || stream_open(&w->camera) != 0 ||
        stream_open(&w->world) != 0) {
        io_rib_writer_free(w);
        return NULL;
    }
    return w;
}

void io_rib_writer_free(RibWriter *w)
{
    if (!w)
        return;
    stream_close(&w->options);
    stream_close(&w->camera);
    stream_close(&w->world);
    stream_close(&w->motion);
    free(w->links);
    free(w->shader);
    free(w->atmosphere);
    free(w);
}

static RayesError fail(RibWriter *w, RayesError e, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static RayesError fail(RibWriter *w, RayesError e, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->error, sizeof w->error, fmt, ap);
    va_end(ap);
    return e;
}

static int finite_all(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* "[a b c ...]" with %.9g: every float reads back exactly. */
static void floats(FILE *f, const float *v, size_t n)
{
    fputc('[', f);
    for (size_t i = 0; i < n; i++)
        fprintf(f, i ? " %.9g" : "%.9g", v[i] == 0.0f ? 0.0 : (double)v[i]); /* no "-0" */
    fputc(']', f);
}

/* A RIB string: quotes and backslashes escaped, control characters as
 * octal escapes. */
static void string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20 || c == 0x7f)
            fprintf(f, "\\%03o", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* The 4 x 4 matrix m (column vectors) as RIB's 16 numbers (row vectors):
 * m transposed. */
static void matrix(FILE *f, const float m[16])
{
    float t[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            t[4 * i + j] = m[4 * j + i];
    floats(f, t, 16);
}

/* Typed inline parameters; points names "from" and "to" of lights. */
static RayesError params(RibWriter *w, FILE *f, const RayesParam *p, size_t n, int light)
{
    for (size_t i = 0; i < n; i++) {
        if (!p[i].name || !p[i].name[0] || strpbrk(p[i].name, " \"\\"))
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "a parameter without a valid name");
        int is_point = light && (!strcmp(p[i].name, "from") || !strcmp(p[i].name, "to"));
        switch (p[i].type) {
        case RAYES_PARAM_FLOAT:
        case RAYES_PARAM_COLOR: {
            size_t k = p[i].type == RAYES_PARAM_FLOAT ? 1 : 3;
            if (!finite_all(p[i].value, k))
                return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "parameter \"%s\": not finite",
                            p[i].name);
            fprintf(f, " \"%s %s\" ", k == 1 ? "float" : is_point ? "point" : "color",
                    p[i].name);
            floats(f, p[i].value, k);
            break;
        }
        case RAYES_PARAM_FLOATS:
            if (!p[i].floats || !finite_all(p[i].floats, p[i].n_floats))
                return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "parameter \"%s\": not finite",
                            p[i].name);
            fprintf(f, " \"float %s\" ", p[i].name);
            floats(f, p[i].floats, p[i].n_floats);
            break;
        case RAYES_PARAM_STRING:
        case RAYES_PARAM_PATTERN: /* rayes' RIB: "reference pattern NAME" [pattern] */
            fprintf(f,
                    p[i].type == RAYES_PARAM_STRING ? " \"string %s\" ["
                                                    : " \"reference pattern %s\" [",
                    p[i].name);
            string(f, p[i].string ? p[i].string : "");
            fputc(']', f);
            break;
        default:
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "parameter \"%s\": unknown type",
                        p[i].name);
        }
    }
    return RAYES_OK;
}

/* The typed inline parameters as text (params), into a new *text (free()
 * it; NULL when there are none). */
static RayesError params_text(RibWriter *w, const RayesParam *p, size_t n, int light, char **text)
{
    size_t size = 0;
    *text = NULL;
    FILE *m = open_memstream(text, &size);
    if (!m)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    RayesError e = params(w, m, p, n, light);
    fclose(m);
    return e;
}

/* ------------------------------------------------------------ camera */

static RayesError w_set_camera(void *t, const float eye[3], const float at[3], const float up[3],
                               float fov)
{
    RibWriter *w = t;
    double fw[3], u[3], r[3], l = 0.0;
    for (int k = 0; k < 3; k++)
        fw[k] = (double)at[k] - eye[k];
    for (int k = 0; k < 3; k++)
        l += fw[k] * fw[k];
    if (!finite_all(eye, 3) || !finite_all(at, 3) || !finite_all(up, 3) || !(l > 0.0) ||
        !(fov > 0.0f && fov < 180.0f))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "camera: degenerate or out of range");
    for (int k = 0; k < 3; k++)
        fw[k] /= sqrt(l);
    /* right = forward x up, up' = right x forward: a right-handed world
     * seen in RenderMan's left-handed camera space (a mirror). */
    r[0] = fw[1] * up[2] - fw[2] * up[1];
    r[1] = fw[2] * up[0] - fw[0] * up[2];
    r[2] = fw[0] * up[1] - fw[1] * up[0];
    l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(l > 0.0))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "camera: up is along the view direction");
    for (int k = 0; k < 3; k++)
        r[k] /= l;
    u[0] = r[1] * fw[2] - r[2] * fw[1];
    u[1] = r[2] * fw[0] - r[0] * fw[2];
    u[2] = r[0] * fw[1] - r[1] * fw[0];
    const double *rows[3] = {r, u, fw};
    float m[16] = {0};
    for (int i = 0; i < 3; i++) {
        double d = 0.0;
        for (int k = 0; k < 3; k++) {
            m[4 * i + k] = (float)rows[i][k];
            d += rows[i][k] * eye[k];
        }
        m[4 * i + 3] = (float)-d;
    }
    m[15] = 1.0f;
    if (stream_open(&w->camera) != 0)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    w->fov_y = fov;
    fprintf(w->camera.f, "Transform ");
    matrix(w->camera.f, m);
    fputc('\n', w->camera.f);
    return RAYES_OK;
}

static RayesError w_set_camera_matrix(void *t, const float m[16], RayesProjection proj, float fov,
                                      const float screen[4])
{
    RibWriter *w = t;
    if (!finite_all(m, 16) || (screen && !finite_all(screen, 4)) ||
        (proj == RAYES_PROJECTION_PERSPECTIVE && !(fov > 0.0f && fov < 180.0f)) ||
        (proj != RAYES_PROJECTION_PERSPECTIVE && proj != RAYES_PROJECTION_ORTHOGRAPHIC))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "camera: out of range");
    if (stream_open(&w->camera) != 0)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    FILE *f = w->camera.f;
    w->fov_y = -1.0f;
    if (proj == RAYES_PROJECTION_PERSPECTIVE)
        fprintf(f, "Projection \"perspective\" \"fov\" [%.9g]\n", (double)fov);
    else
        fprintf(f, "Projection \"orthographic\"\n");
    if (screen)
        fprintf(f, "ScreenWindow %.9g %.9g %.9g %.9g\n", (double)screen[0], (double)screen[1],
                (double)screen[2], (double)screen[3]);
    fprintf(f, "Transform ");
    matrix(f, m);
    fputc('\n', f);
    return RAYES_OK;
}

/* ------------------------------------------------------- attributes */

static int is_identity(const float m[16])
{
    for (int i = 0; i < 16; i++)
        if (m[i] != (i % 5 == 0 ? 1.0f : 0.0f))
            return 0;
    return 1;
}

static RayesError w_set_transform(void *t, const float m[16])
{
    RibWriter *w = t;
    if (!finite_all(m, 16))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "transform: not finite");
    FILE *f = w->world.f;
    if (w->in_transform)
        fprintf(f, "TransformEnd\n");
    w->in_transform = !is_identity(m);
    if (w->in_transform) {
        fprintf(f, "TransformBegin\nConcatTransform ");
        matrix(f, m);
        fputc('\n', f);
    }
    return RAYES_OK;
}

/* ------------------------------------------------------------- time */

static void motion_times(FILE *f, size_t n, const float *times)
{
    fprintf(f, "MotionBegin [");
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%s%.9g", k ? " " : "", (double)times[k]);
    fprintf(f, "]\n");
}

static RayesError w_set_shutter(void *t, float open, float close)
{
    RibWriter *w = t;
    w->shutter[0] = open, w->shutter[1] = close;
    return RAYES_OK;
}

static RayesError w_set_depth_of_field(void *t, float lens_radius, float focal_distance)
{
    RibWriter *w = t;
    w->lens[0] = lens_radius, w->lens[1] = focal_distance;
    return RAYES_OK;
}

/* Camera motion: after the camera's Transform, a motion block of
 * Transforms (each replaces it, RIB's sample semantics). */
static RayesError w_set_camera_motion(void *t, size_t n, const float *times,
                                      const float (*m)[16])
{
    RibWriter *w = t;
    if (n < 2 || n > RAYES_MAX_TIMES || !finite_all(times, n) || !finite_all(m[0], 16 * n))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "camera motion: out of range");
    motion_times(w->camera.f, n, times);
    for (size_t k = 0; k < n; k++) {
        fprintf(w->camera.f, "Transform ");
        matrix(w->camera.f, m[k]);
        fputc('\n', w->camera.f);
    }
    fprintf(w->camera.f, "MotionEnd\n");
    return RAYES_OK;
}

static RayesError w_set_transform_motion(void *t, size_t n, const float *times,
                                         const float (*m)[16])
{
    RibWriter *w = t;
    if (n < 2 || n > RAYES_MAX_TIMES || !finite_all(times, n) || !finite_all(m[0], 16 * n))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "transform motion: out of range");
    FILE *f = w->world.f;
    if (w->in_transform)
        fprintf(f, "TransformEnd\n");
    w->in_transform = 1;
    fprintf(f, "TransformBegin\n");
    motion_times(f, n, times);
    for (size_t k = 0; k < n; k++) {
        fprintf(f, "ConcatTransform ");
        matrix(f, m[k]);
        fputc('\n', f);
    }
    fprintf(f, "MotionEnd\n");
    return RAYES_OK;
}

static RayesError w_set_dice_blur(void *t, float motionfactor, float focusfactor)
{
    RibWriter *w = t;
    if (motionfactor != w->motionfactor || focusfactor != w->focusfactor)
        fprintf(w->world.f, "Attribute \"dice\" \"float motionfactor\" [%.9g] "
                            "\"float focusfactor\" [%.9g]\n",
                (double)motionfactor, (double)focusfactor);
    w->motionfactor = motionfactor, w->focusfactor = focusfactor;
    return RAYES_OK;
}

/* Deformation: the samples' requests go to a stream of their own; at the
 * end, primitive request j of every sample (the same topology writes the
 * same primitives) makes motion block j, written where the first sample
 * wrote its primitive j, among the first sample's other requests (the
 * state around its primitives: a Basis, an AttributeBegin block). The
 * later samples' state is the first's, and is dropped: a sample ends
 * after its last primitive once its AttributeBegin and TransformBegin
 * blocks are closed, so a sample may write state the others do not (a
 * Basis the first one set). */
static RayesError w_motion_begin(void *t, size_t n, const float *times)
{
    RibWriter *w = t;
    if (w->motion_n || n < 2 || n > RAYES_MAX_TIMES || !finite_all(times, n))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "motion begin: out of range or nested");
    if (stream_open(&w->motion) != 0)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    w->motion_n = n;
    memcpy(w->motion_time, times, n * sizeof *times);
    w->world_f = w->world.f;
    w->world.f = w->motion.f;
    return RAYES_OK;
}

/* The starts of the requests in text (a request begins a line with a
 * capital letter); returns their count, at most max. */
static size_t request_starts(const char *text, size_t size, const char **starts, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < size; i++)
        if ((i == 0 || text[i - 1] == '\n') && text[i] >= 'A' && text[i] <= 'Z' && n < max)
            starts[n++] = text + i;
    return n;
}

/* 1 if the request at r (up to end) is named name. */
static int request_is(const char *r, const char *end, const char *name)
{
    size_t n = strlen(name);
    return (size_t)(end - r) > n && strncmp(r, name, n) == 0 &&
           (r[n] == ' ' || r[n] == '\n');
}

/* The request at r: 1 a primitive the writer writes, else 0; *depth moves
 * with the blocks it opens and closes. */
static int request_kind(const char *r, const char *end, int *depth)
{
    static const char *const prims[] = {"Patch",    "PointsPolygons", "SubdivisionMesh", "Curves",
                                        "Points",   "Sphere",         "Cylinder",        "Cone",
                                        "Disk",     "Paraboloid",     "Hyperboloid",     "Torus",
                                        "Volume",   NULL};
    for (int k = 0; prims[k]; k++)
        if (request_is(r, end, prims[k]))
            return 1;
    if (request_is(r, end, "AttributeBegin") || request_is(r, end, "TransformBegin"))
        (*depth)++;
    else if (request_is(r, end, "AttributeEnd") || request_is(r, end, "TransformEnd"))
        (*depth)--;
    return 0;
}

static RayesError w_motion_end(void *t)
{
    RibWriter *w = t;
    if (!w->motion_n)
        return fail(w, RAYES_ERROR_INVALID_OPERATION, "motion end: no motion block");
    size_t n = w->motion_n;
    w->motion_n = 0;
    w->world.f = w->world_f;
    if (fflush(w->motion.f) != 0)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    const char *text = w->motion.buf, *end = text + w->motion.size;
    size_t cap = w->motion.size / 2 + 2;
    const char **starts = malloc((cap + 1) * sizeof *starts);
    uint8_t *prim = malloc(cap + 1);
    if (!starts || !prim) {
        free(starts), free(prim);
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    size_t total = request_starts(text, w->motion.size, starts, cap), n_prims = 0;
    starts[total] = end;
    int depth = 0;
    for (size_t i = 0; i < total; i++)
        n_prims += prim[i] = (uint8_t)request_kind(starts[i], starts[i + 1], &depth);
    size_t per = n_prims / n;
    /* sample k: requests first[k] .. first[k + 1] - 1; its primitives */
    size_t first[RAYES_MAX_TIMES + 1], i = 0;
    depth = 0;
    for (size_t k = 0; per && n_prims % n == 0 && k < n; k++) {
        first[k] = i;
        for (size_t seen = 0; i < total;) {
            seen += prim[i];
            request_kind(starts[i], starts[i + 1], &depth);
            i++;
            if (seen == per && depth == 0)
                break;
        }
    }
    first[n] = total;
    if (per == 0 || n_prims % n != 0) {
        free(starts), free(prim);
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                    "motion end: the samples wrote %zu primitives, not a multiple of %zu",
                    n_prims, n);
    }
    size_t j = 0;
    for (size_t r = first[0]; r < first[1]; r++) {
        if (!prim[r]) {
            fwrite(starts[r], 1, (size_t)(starts[r + 1] - starts[r]), w->world.f);
            continue;
        }
        motion_times(w->world.f, n, w->motion_time);
        for (size_t k = 0; k < n; k++) { /* sample k's primitive j */
            size_t q = first[k], seen = 0;
            while (q < first[k + 1] && !(prim[q] && seen++ == j))
                q++;
            fwrite(starts[q], 1, (size_t)(starts[q + 1] - starts[q]), w->world.f);
        }
        fprintf(w->world.f, "MotionEnd\n");
        j++;
    }
    free(starts), free(prim);
    return RAYES_OK;
}

/* Cs and Os from a shader's parameters when they are constants (Color
 * and Opacity in RIB); bound to a pattern they stay shader parameters. */
static int constant_color(const RayesParam *p)
{
    return p->name && (!strcmp(p->name, "Cs") || !strcmp(p->name, "Os")) &&
           p->type != RAYES_PARAM_STRING && p->type != RAYES_PARAM_PATTERN;
}

static const RayesParam *find_param(const RayesParam *p, size_t n, const char *name)
{
    for (size_t i = 0; i < n; i++)
        if (constant_color(&p[i]) && strcmp(p[i].name, name) == 0)
            return &p[i];
    return NULL;
}

static void color_of(const RayesParam *p, float c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = p ? p->value[p->type == RAYES_PARAM_FLOAT ? 0 : k] : 1.0f;
}

static RayesError w_set_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    RibWriter *w = t;
    if (!name || !name[0])
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "set_shader: no name");
    FILE *f = w->world.f;
    float cs[3], os[3];
    color_of(find_param(p, n, "Cs"), cs);
    color_of(find_param(p, n, "Os"), os);
    if (!finite_all(cs, 3) || !finite_all(os, 3))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "Cs or Os: not finite");
    int opaque = os[0] == 1.0f && os[1] == 1.0f && os[2] == 1.0f;
    /* everything but Cs and Os, checked before anything is written */
    RayesParam rest[64];
    size_t n_rest = 0;
    for (size_t i = 0; i < n; i++) {
        if (constant_color(&p[i]))
            continue;
        if (n_rest == 64)
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "set_shader: too many parameters");
        rest[n_rest++] = p[i];
    }
    char *text = NULL;
    RayesError e = params_text(w, rest, n_rest, 0, &text);
    if (e == RAYES_OK) {
        fprintf(f, "Color ");
        floats(f, cs, 3);
        fputc('\n', f);
        if (!opaque || w->opacity_set) {
            fprintf(f, "Opacity ");
            floats(f, os, 3);
            fputc('\n', f);
        }
        w->opacity_set = !opaque;
        fprintf(f, "Surface ");
        string(f, name);
        fprintf(f, "%s\n", text ? text : "");
        size_t len = strlen(name) + (text ? strlen(text) : 0) + 4;
        free(w->shader);
        w->shader = malloc(len);
        if (!w->shader)
            e = fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
        else
            snprintf(w->shader, len, "%s%c%s", name, 0, text ? text : "");
    }
    free(text);
    return e;
}

/* Atmosphere of the shader set last (rayes' volume shader and its
 * parameters, which the reader takes as they are), kept for the world's
 * start, where it applies to every primitive. */
static RayesError w_atmosphere(void *t)
{
    RibWriter *w = t;
    if (!w->shader)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "atmosphere: no shader");
    char *line = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&line, &size);
    if (!f)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    fprintf(f, "Atmosphere ");
    string(f, w->shader);
    fprintf(f, "%s\n", w->shader + strlen(w->shader) + 1);
    if (fclose(f) != 0 || !line) {
        free(line);
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    free(w->atmosphere);
    w->atmosphere = line;
    return RAYES_OK;
}

static RayesError w_set_displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    RibWriter *w = t;
    FILE *f = w->world.f;
    if (!name || !name[0]) {
        fprintf(f, "Displacement \"null\"\n");
        return RAYES_OK;
    }
    char *text = NULL;
    RayesError e = params_text(w, p, n, 0, &text);
    if (e == RAYES_OK) {
        fprintf(f, "Displacement ");
        string(f, name);
        fprintf(f, "%s\n", text ? text : "");
    }
    free(text);
    return e;
}

/* Pattern "type" "name" params (RenderMan's Pattern request, rayes'
 * classes), in the current transform. */
static RayesError w_pattern(void *t, const char *name, const char *type, const RayesParam *p,
                            size_t n)
{
    RibWriter *w = t;
    if (!name || !name[0] || !type || !type[0])
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "pattern: no name or type");
    char *text = NULL;
    RayesError e = params_text(w, p, n, 0, &text);
    if (e == RAYES_OK) {
        fprintf(w->world.f, "Pattern ");
        string(w->world.f, type);
        fputc(' ', w->world.f);
        string(w->world.f, name);
        fprintf(w->world.f, "%s\n", text ? text : "");
    }
    free(text);
    return e;
}

static RayesError w_set_displacement_bound(void *t, float bound)
{
    RibWriter *w = t;
    if (!(bound >= 0.0f) || !isfinite(bound))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "displacement bound: out of range");
    fprintf(w->world.f,
            "Attribute \"displacementbound\" \"float sphere\" [%.9g] "
            "\"string coordinatesystem\" [\"world\"]\n",
            (double)bound);
    return RAYES_OK;
}

static RayesError w_set_search_path(void *t, const char *kind, const char *path)
{
    RibWriter *w = t;
    if (!kind || !kind[0] || !path || strpbrk(kind, " \"\\"))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "search path: bad kind or path");
    fprintf(w->options.f, "Option \"searchpath\" \"string %s\" [", kind);
    string(w->options.f, path);
    fprintf(w->options.f, "]\n");
    return RAYES_OK;
}

static RayesError w_set_shading_rate(void *t, float rate)
{
    RibWriter *w = t;
    if (!(rate > 0.0f) || !isfinite(rate))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "shading rate: out of range");
    fprintf(w->world.f, "ShadingRate %.9g\n", (double)rate);
    return RAYES_OK;
}

/* Attribute "visibility" when the bits change (transmission is shadow). */
static RayesError w_set_visibility(void *t, uint32_t ray_types)
{
    RibWriter *w = t;
    if (ray_types & RAYES_RAY_TRANSMISSION)
        ray_types = (ray_types & ~(uint32_t)RAYES_RAY_TRANSMISSION) | RAYES_RAY_SHADOW;
    if (ray_types == w->visibility)
        return RAYES_OK;
    w->visibility = ray_types;
    fprintf(w->world.f,
            "Attribute \"visibility\" \"int camera\" [%d] \"int diffuse\" [%d] "
            "\"int specular\" [%d] \"int transmission\" [%d]\n",
            !!(ray_types & RAYES_RAY_CAMERA), !!(ray_types & RAYES_RAY_DIFFUSE),
            !!(ray_types & RAYES_RAY_SPECULAR), !!(ray_types & RAYES_RAY_SHADOW));
    return RAYES_OK;
}

/* Attribute "shade" (transmissionhitmode, rayes' opacitycache) on change. */
static RayesError w_set_opacity_mode(void *t, RayesTransmissionHitMode mode, int cache)
{
    RibWriter *w = t;
    if (mode != RAYES_TRANSMISSION_SHADER && mode != RAYES_TRANSMISSION_PRIMITIVE)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "opacity mode: out of range");
    if ((int)mode == w->hitmode && (cache != 0) == w->opacity_cache)
        return RAYES_OK;
    w->hitmode = (int)mode;
    w->opacity_cache = cache != 0;
    fprintf(w->world.f,
            "Attribute \"shade\" \"string transmissionhitmode\" [\"%s\"] "
            "\"int opacitycache\" [%d]\n",
            mode == RAYES_TRANSMISSION_PRIMITIVE ? "primitive" : "shader", w->opacity_cache);
    return RAYES_OK;
}

/* --------------------------------------------------------- geometry */

/* Floats per value of a primitive variable rayes.h knows ("width" is
 * curves' and points'), or 0. */
static int primvar_size(const char *name)
{
    static const char *const three[] = {"N", "Cs", "Os"};
    if (!name)
        return 0;
    for (size_t k = 0; k < sizeof three / sizeof three[0]; k++)
        if (strcmp(name, three[k]) == 0)
            return 3;
    return strcmp(name, "st") == 0 ? 2 : strcmp(name, "width") == 0 ? 1 : 0;
}

/* Checks primitive variables as rayes.h does (expect[cls]: the counts of
 * each class for the primitive); returns 0 or fails. */
static RayesError check_primvars(RibWriter *w, const char *what, const RayesPrimvar *pv,
                                 size_t n_pv, const size_t expect[5])
{
    if (n_pv && !pv)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "%s: primitive variables are NULL", what);
    for (size_t i = 0; i < n_pv; i++) {
        int size = primvar_size(pv[i].name);
        if (!size || (unsigned)pv[i].cls > RAYES_PRIMVAR_FACEVARYING ||
            pv[i].count != expect[pv[i].cls] || (pv[i].count && !pv[i].data) ||
            !finite_all(pv[i].data, pv[i].count * (size_t)size))
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "%s: bad primitive variable %s", what,
                        pv[i].name && size ? pv[i].name : "(unknown)");
    }
    return RAYES_OK;
}

/* Starts a primitive variable's RIB parameter on a line of its own: its
 * inline declaration. Returns its floats per value. */
static size_t primvar_decl(FILE *f, const RayesPrimvar *p)
{
    static const char *const cls[5] = {"constant", "uniform", "varying", "vertex", "facevarying"};
    int size = primvar_size(p->name);
    const char *type = size == 2 ? "float[2]" : size == 1 ? "float"
                     : strcmp(p->name, "N") == 0 ? "normal" : "color";
    fprintf(f, "\n  \"%s %s %s\" ", cls[p->cls], type, p->name);
    return (size_t)size;
}

/* Writes primitive variables as RIB parameters, each on a line of its own. */
static void primvars(FILE *f, const RayesPrimvar *pv, size_t n_pv)
{
    for (size_t i = 0; i < n_pv; i++)
        floats(f, pv[i].data, pv[i].count * primvar_decl(f, &pv[i]));
}

static RayesError w_bilinear_patch(void *t, const float P[4][3], const RayesPrimvar *pv,
                                   size_t n_pv)
{
    RibWriter *w = t;
    static const size_t expect[5] = {1, 1, 4, 4, 4};
    if (!finite_all(&P[0][0], 12))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "bilinear patch: non-finite point");
    if (check_primvars(w, "bilinear patch", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    fprintf(w->world.f, "Patch \"bilinear\" \"P\" ");
    floats(w->world.f, &P[0][0], 12);
    primvars(w->world.f, pv, n_pv);
    fputc('\n', w->world.f);
    return RAYES_OK;
}

static RayesError w_bicubic_patch(void *t, const float P[16][3], const RayesPrimvar *pv,
                                  size_t n_pv)
{
    RibWriter *w = t;
    static const size_t expect[5] = {1, 1, 4, 16, 4};
    if (!finite_all(&P[0][0], 48))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "bicubic patch: non-finite point");
    if (check_primvars(w, "bicubic patch", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!w->bezier_basis)
        fprintf(w->world.f, "Basis \"bezier\" 3 \"bezier\" 3\n");
    w->bezier_basis = 1;
    fprintf(w->world.f, "Patch \"bicubic\" \"P\" ");
    floats(w->world.f, &P[0][0], 48);
    primvars(w->world.f, pv, n_pv);
    fputc('\n', w->world.f);
    return RAYES_OK;
}

/* A polygon mesh being written. */
typedef struct Mesh {
    const int *nv, *idx;
    size_t n_faces, n_points;
    const float *P;
    const RayesPrimvar *pv;
    size_t n_pv;
    size_t *map;  /* point -> index in the run being written, else SIZE_MAX; owned */
    size_t *used; /* the points of that run, ascending; owned */
} Mesh;

static int ascending(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* Nonzero if face f (its corners from k on) is a quad the reader would split. */
static int split_quad(const Mesh *m, size_t f, size_t k)
{
    return m->nv[f] == 4 && !rib_quad_kept(m->P, m->idx + k);
}

/* "[...]" of the elements which[0..n) (or first.. first + n when which is
 * NULL) of values of size floats each. */
static void elements(FILE *f, const float *values, size_t size, const size_t *which, size_t first,
                     size_t n)
{
    fputc('[', f);
    for (size_t i = 0; i < n; i++)
        for (size_t c = 0; c < size; c++) {
            float v = values[size * (which ? which[i] : first + i) + c];
            fprintf(f, "%s%.9g",
                    i + c == 0                ? ""
                    : (size * i + c) % 9 == 0 ? "\n   "
                                              : " ",
                    v == 0.0f ? 0.0 : (double)v);
        }
    fputc(']', f);
}

/* The primitive variables of one primitive written from the mesh: face f,
 * the points points[0..n_points) and the corners corners[0..n_corners) (or
 * first_corner on when corners is NULL). */
static void mesh_primvars(FILE *f, const Mesh *m, size_t face, size_t n_faces, const size_t *points,
                          size_t n_points, const size_t *corners, size_t first_corner,
                          size_t n_corners)
{
    for (size_t i = 0; i < m->n_pv; i++) {
        const RayesPrimvar *p = &m->pv[i];
        size_t size = primvar_decl(f, p);
        switch (p->cls) {
        case RAYES_PRIMVAR_CONSTANT:
            elements(f, p->data, size, NULL, 0, 1);
            break;
        case RAYES_PRIMVAR_UNIFORM:
            elements(f, p->data, size, NULL, face, n_faces);
            break;
        case RAYES_PRIMVAR_VARYING:
        case RAYES_PRIMVAR_VERTEX:
            elements(f, p->data, size, points, 0, n_points);
            break;
        default:
            elements(f, p->data, size, corners, first_corner, n_corners);
            break;
        }
    }
}

/* Face f, a quad with corners from k on, as RIB's bilinear patch: P00 = v0,
 * P10 = v1, P01 = v3, P11 = v2, as rayes_scene_polygon_mesh makes it. */
static void quad_patch(FILE *f, const Mesh *m, size_t face, size_t k)
{
    static const int order[4] = {0, 1, 3, 2};
    size_t points[4], corners[4];
    for (int c = 0; c < 4; c++) {
        points[c] = (size_t)m->idx[k + (size_t)order[c]];
        corners[c] = k + (size_t)order[c];
    }
    fprintf(f, "Patch \"bilinear\" \"P\" ");
    elements(f, m->P, 3, points, 0, 4);
    mesh_primvars(f, m, face, 1, points, 4, corners, 0, 4);
    fputc('\n', f);
}

/* Faces [a, b) (corners [k, kb)) as PointsPolygons with the points they
 * use, in the mesh's order (all of them, as given, for a whole mesh). The
 * work is in the run's corners, not the mesh's points, so a mesh of many
 * short runs stays linear. Returns 0, or -1 when out of memory. */
static int polygons(FILE *f, Mesh *m, size_t a, size_t b, size_t k, size_t kb)
{
    size_t cap = m->n_points ? m->n_points : 1, n_used = 0;
    if (!m->map) {
        m->map = malloc(cap * sizeof *m->map);
        m->used = malloc(cap * sizeof *m->used);
        if (!m->map || !m->used)
            return -1;
        for (size_t i = 0; i < m->n_points; i++)
            m->map[i] = SIZE_MAX;
    }
    size_t *used = m->used;
    if (a == 0 && b == m->n_faces) {
        for (size_t i = 0; i < m->n_points; i++)
            used[n_used++] = i;
    } else {
        for (size_t i = k; i < kb; i++)
            if (m->map[m->idx[i]] == SIZE_MAX) {
                m->map[m->idx[i]] = 0;
                used[n_used++] = (size_t)m->idx[i];
            }
        qsort(used, n_used, sizeof *used, ascending);
    }
    for (size_t i = 0; i < n_used; i++)
        m->map[used[i]] = i;
    fprintf(f, "PointsPolygons [");
    for (size_t i = a; i < b; i++)
        fprintf(f, i > a ? " %d" : "%d", m->nv[i]);
    fprintf(f, "]\n  [");
    for (size_t i = k; i < kb; i++)
        fprintf(f, "%s%zu", i == k ? "" : (i - k) % 24 == 0 ? "\n   " : " ", m->map[m->idx[i]]);
    fprintf(f, "]\n  \"P\" ");
    elements(f, m->P, 3, used, 0, n_used);
    mesh_primvars(f, m, a, b - a, used, n_used, NULL, k, kb - k);
    fprintf(f, "\n");
    for (size_t i = 0; i < n_used; i++)
        m->map[used[i]] = SIZE_MAX;
    return 0;
}

static RayesError w_polygon_mesh(void *t, size_t n_faces, const int *nv, const int *idx,
                                 size_t n_points, const float *P, const RayesPrimvar *pv,
                                 size_t n_pv)
{
    RibWriter *w = t;
    size_t k = 0;
    if (n_faces == 0)
        return RAYES_OK;
    if (!nv || !idx || !P || !finite_all(P, 3 * n_points))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "polygon mesh: missing or non-finite data");
    for (size_t i = 0; i < n_faces; k += (size_t)nv[i], i++) {
        if (nv[i] != 3 && nv[i] != 4)
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                        "polygon mesh: face %zu has %d vertices; expected 3 or 4", i, nv[i]);
        for (int v = 0; v < nv[i]; v++)
            if (idx[k + (size_t)v] < 0 || (size_t)idx[k + (size_t)v] >= n_points)
                return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "polygon mesh: index out of range");
    }
    const size_t expect[5] = {1, n_faces, n_points, n_points, k};
    if (check_primvars(w, "polygon mesh", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    /* Runs of faces the reader keeps as they are, in order, between the
     * quads it would split (not planar, or not convex): those are written
     * as the bilinear patches they are here, so that a converted scene has
     * the same primitives in the same order. */
    Mesh m = {nv, idx, n_faces, n_points, P, pv, n_pv, NULL, NULL};
    k = 0;
    for (size_t a = 0; a < n_faces;) {
        if (split_quad(&m, a, k)) {
            quad_patch(w->world.f, &m, a, k);
            k += 4;
            a++;
            continue;
        }
        size_t b = a, kb = k;
        while (b < n_faces && !split_quad(&m, b, kb))
            kb += (size_t)nv[b++];
        if (polygons(w->world.f, &m, a, b, k, kb) != 0) {
            free(m.map);
            free(m.used);
            return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "polygon mesh: out of memory");
        }
        a = b;
        k = kb;
    }
    free(m.map);
    free(m.used);
    return RAYES_OK;
}

/* A subdivision mesh as RenderMan's SubdivisionMesh, every tag written
 * (interpolateboundary too: RenderMan's default, 0, is not rayes.h's):
 * a "crease" tag per edge, one "corner" and one "hole" tag. */
static RayesError w_subdivision_mesh(void *t, RayesSubdivScheme scheme, size_t n_faces,
                                     const int *nv, const int *idx, size_t n_points, const float *P,
                                     const RayesSubdivTags *tags, const RayesPrimvar *pv,
                                     size_t n_pv)
{
    static const char *const schemes[3] = {"catmull-clark", "loop", "bilinear"};
    RibWriter *w = t;
    FILE *f = w->world.f;
    size_t k = 0;
    if ((unsigned)scheme > RAYES_SUBDIV_BILINEAR || (n_faces && (!nv || !idx || !P)) ||
        !finite_all(P, 3 * n_points))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "subdivision mesh: bad scheme or data");
    for (size_t i = 0; i < n_faces; k += (size_t)nv[i], i++) {
        if (nv[i] < 3)
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "subdivision mesh: a face of %d", nv[i]);
        for (int v = 0; v < nv[i]; v++)
            if (idx[k + (size_t)v] < 0 || (size_t)idx[k + (size_t)v] >= n_points)
                return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                            "subdivision mesh: index out of range");
    }
    const size_t expect[5] = {1, n_faces, n_points, n_points, k};
    if (check_primvars(w, "subdivision mesh", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    RayesSubdivTags none = {.interpolate_boundary = 1, .facevarying_boundary = 1};
    const RayesSubdivTags *g = tags ? tags : &none;
    if (n_faces == 0)
        return RAYES_OK;
    fprintf(f, "SubdivisionMesh \"%s\" [", schemes[scheme]);
    for (size_t i = 0; i < n_faces; i++)
        fprintf(f, i ? " %d" : "%d", nv[i]);
    fprintf(f, "]\n  [");
    for (size_t i = 0; i < k; i++)
        fprintf(f, "%s%d", i == 0 ? "" : i % 24 == 0 ? "\n   " : " ", idx[i]);
    fprintf(f, "]\n  [\"interpolateboundary\" \"facevaryinginterpolateboundary\"");
    for (size_t i = 0; i < g->n_creases; i++)
        fprintf(f, " \"crease\"");
    fprintf(f, "%s%s]\n  [1 0 1 0", g->n_corners ? " \"corner\"" : "",
            g->n_holes ? " \"hole\"" : "");
    for (size_t i = 0; i < g->n_creases; i++)
        fprintf(f, " 2 1");
    if (g->n_corners)
        fprintf(f, " %zu %zu", g->n_corners, g->n_corners);
    if (g->n_holes)
        fprintf(f, " %zu 0", g->n_holes);
    fprintf(f, "]\n  [%d %d", g->interpolate_boundary, g->facevarying_boundary);
    for (size_t i = 0; i < 2 * g->n_creases; i++)
        fprintf(f, " %d", g->crease_edges[i]);
    for (size_t i = 0; i < g->n_corners; i++)
        fprintf(f, " %d", g->corner_points[i]);
    for (size_t i = 0; i < g->n_holes; i++)
        fprintf(f, " %d", g->hole_faces[i]);
    fprintf(f, "]\n  ");
    float *sharp = malloc((g->n_creases + g->n_corners + 1) * sizeof *sharp);
    if (!sharp)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "subdivision mesh: out of memory");
    if (g->n_creases)
        memcpy(sharp, g->crease_sharpness, g->n_creases * sizeof *sharp);
    if (g->n_corners)
        memcpy(sharp + g->n_creases, g->corner_sharpness, g->n_corners * sizeof *sharp);
    floats(f, sharp, g->n_creases + g->n_corners);
    free(sharp);
    fprintf(f, "\n  \"P\" ");
    floats(f, P, 3 * n_points);
    primvars(f, pv, n_pv);
    fputc('\n', f);
    return RAYES_OK;
}

/* Curves as RenderMan's Curves, in an attribute block of their own (the
 * basis is graphics state, and round tubes are Attribute "dice"
 * "roundcurve" 1, rib.md). */
static RayesError w_curves(void *t, const RayesCurves *c, const RayesPrimvar *pv, size_t n_pv)
{
    RibWriter *w = t;
    size_t n_points, n_varying;
    if (rayes_curves_counts(c, &n_points, &n_varying) != 0 || !finite_all(c->P, 3 * n_points) ||
        (c->degree == 3 && !finite_all(c->basis, 16)))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "curves: bad degree, step or counts");
    const size_t expect[5] = {1, c->n_curves, n_varying, n_points, n_varying};
    if (check_primvars(w, "curves", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (c->n_curves == 0)
        return RAYES_OK;
    FILE *f = w->world.f;
    fprintf(f, "AttributeBegin\nAttribute \"dice\" \"int roundcurve\" [%d]\n",
            c->shape == RAYES_CURVE_ROUND);
    if (c->degree == 3) {
        for (int k = 0; k < 2; k++) {
            fprintf(f, k ? " " : "Basis ");
            floats(f, c->basis, 16);
            fprintf(f, " %d", c->step);
        }
        fputc('\n', f);
    }
    fprintf(f, "Curves \"%s\" [", c->degree == 3 ? "cubic" : "linear");
    for (size_t i = 0; i < c->n_curves; i++)
        fprintf(f, i ? " %d" : "%d", c->n_verts[i]);
    fprintf(f, "] \"%s\"\n  \"P\" ", c->periodic ? "periodic" : "nonperiodic");
    floats(f, c->P, 3 * n_points);
    primvars(f, pv, n_pv);
    fprintf(f, "\nAttributeEnd\n");
    return RAYES_OK;
}

/* Points as RenderMan's Points, their shape as 3Delight's "uniform string
 * type". */
static RayesError w_points(void *t, RayesPointShape shape, size_t n, const float *P,
                           const RayesPrimvar *pv, size_t n_pv)
{
    RibWriter *w = t;
    const size_t expect[5] = {1, 1, n, n, n};
    if ((n && !P) || !finite_all(P, 3 * n) ||
        (shape != RAYES_POINT_SPHERE && shape != RAYES_POINT_DISK))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "points: bad shape or points");
    if (check_primvars(w, "points", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (n == 0)
        return RAYES_OK;
    FILE *f = w->world.f;
    fprintf(f, "Points \"uniform string type\" \"%s\"\n  \"P\" ",
            shape == RAYES_POINT_DISK ? "disk" : "sphere");
    floats(f, P, 3 * n);
    primvars(f, pv, n_pv);
    fputc('\n', f);
    return RAYES_OK;
}

static RayesError w_solid_begin(void *t, RayesSolidOp op)
{
    static const char *const names[] = {"primitive", "union", "intersection", "difference"};
    RibWriter *w = t;
    if ((unsigned)op > RAYES_SOLID_DIFFERENCE)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "solid: unknown operation");
    /* The block saves attributes and transform: no TransformBegin of the
     * writer's may straddle it. */
    if (w->in_transform)
        fprintf(w->world.f, "TransformEnd\n");
    w->in_transform = 0;
    fprintf(w->world.f, "SolidBegin \"%s\"\n", names[op]);
    return RAYES_OK;
}

static RayesError w_solid_end(void *t)
{
    RibWriter *w = t;
    if (w->in_transform)
        fprintf(w->world.f, "TransformEnd\n");
    w->in_transform = 0;
    fprintf(w->world.f, "SolidEnd\n");
    return RAYES_OK;
}

static RayesError w_blobby(void *t, const RayesBlobby *b, const RayesPrimvar *pv, size_t n_pv)
{
    RibWriter *w = t;
    const size_t expect[5] = {1, 1, b ? b->n_leaf : 0, b ? b->n_leaf : 0, (size_t)-1};
    if (!b || (b->n_code && !b->code) || (b->n_floats && !b->floats) ||
        (b->n_strings && !b->strings) || !finite_all(b->floats, b->n_floats))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "blobby: missing or non-finite arrays");
    if (check_primvars(w, "blobby", pv, n_pv, expect) != RAYES_OK)
        return RAYES_ERROR_INVALID_ARGUMENT;
    FILE *f = w->world.f;
    fprintf(f, "Blobby %zu [", b->n_leaf);
    for (size_t i = 0; i < b->n_code; i++)
        fprintf(f, i ? " %d" : "%d", b->code[i]);
    fputs("]\n  ", f);
    floats(f, b->floats, b->n_floats);
    fputs("\n  [", f);
    for (size_t i = 0; i < b->n_strings; i++) {
        if (i)
            fputc(' ', f);
        string(f, b->strings[i]);
    }
    fputc(']', f);
    primvars(f, pv, n_pv);
    fputc('\n', f);
    return RAYES_OK;
}

static RayesError w_quadric(void *t, RayesQuadric type, const float *p, size_t n, unsigned flags)
{
    static const char *const names[] = {"Sphere",     "Cylinder",    "Cone", "Disk",
                                        "Paraboloid", "Hyperboloid", "Torus"};
    static const size_t counts[] = {4, 4, 3, 3, 4, 7, 5};
    RibWriter *w = t;
    if ((unsigned)type > RAYES_QUADRIC_TORUS || n != counts[type] || !p || !finite_all(p, n))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "quadric: wrong type or parameters");
    FILE *f = w->world.f;
    int reverse = (flags & RAYES_QUADRIC_REVERSE) != 0;
    if (reverse)
        fprintf(f, "AttributeBegin\nReverseOrientation\n");
    fprintf(f, "%s", names[type]);
    for (size_t i = 0; i < n; i++)
        fprintf(f, " %.9g", p[i] == 0.0f ? 0.0 : (double)p[i]);
    fprintf(f, "\n%s", reverse ? "AttributeEnd\n" : "");
    return RAYES_OK;
}

static RayesError volume(RibWriter *w, const float b[6], int inside)
{
    if (!b || !finite_all(b, 6))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "volume: bound not finite");
    fprintf(w->world.f, "Volume \"box\" [%.9g %.9g %.9g %.9g %.9g %.9g] [1 1 1]%s\n", (double)b[0],
            (double)b[1], (double)b[2], (double)b[3], (double)b[4], (double)b[5],
            inside ? " \"constant int inside\" [1]" : "");
    return RAYES_OK;
}

static RayesError w_volume(void *t, const float b[6])
{
    return volume(t, b, 0);
}

/* Inside the geometry written just before (rayes' own parameter). */
static RayesError w_volume_inside(void *t, const float b[6])
{
    return volume(t, b, 1);
}

static RayesError w_sphere(void *t, float r)
{
    const float p[4] = {r, -r, r, 360.0f};
    if (!(r > 0.0f))
        return fail(t, RAYES_ERROR_INVALID_ARGUMENT, "sphere: radius not positive");
    return w_quadric(t, RAYES_QUADRIC_SPHERE, p, 4, 0);
}

/* --------------------------------------------------------------- lights */

static int w_linked(const RibWriter *w, size_t light);

/* An area light's block opened, its shader's lightcolor written (the line
 * goes on); returns the world's file. */
static FILE *area_light_begin(RibWriter *w, const float L[3])
{
    FILE *f = w->world.f;
    if (w->next_light < 4097)
        w->area[w->next_light] = 1;
    fprintf(f, "AttributeBegin\nAreaLightSource \"arealight\" %d \"color lightcolor\" ",
            w->next_light++);
    floats(f, L, 3);
    return f;
}

static RayesError w_area_light(void *t, const float P[4][3], const float L[3])
{
    RibWriter *w = t;
    if (!finite_all(&P[0][0], 12) || !finite_all(L, 3) || L[0] < 0 || L[1] < 0 || L[2] < 0)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light: expected finite points and a non-negative radiance");
    FILE *f = area_light_begin(w, L);
    fprintf(f, "\nPolygon \"P\" ");
    floats(f, &P[0][0], 12);
    fprintf(f, "\nAttributeEnd\n");
    return RAYES_OK;
}

static RayesError area_light_mesh(RibWriter *w, size_t n_faces, const int *nv, const int *idx,
                                  size_t n_points, const float *P, const float *st,
                                  const float L[3], int two_sided, const char *texture)
{
    if (!n_faces || !nv || !idx || !P || !finite_all(P, 3 * n_points) || !finite_all(L, 3) ||
        L[0] < 0 || L[1] < 0 || L[2] < 0)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light mesh: expected faces, finite points and a non-negative radiance");
    size_t k = 0;
    for (size_t i = 0; i < n_faces; k += (size_t)nv[i], i++) {
        if (nv[i] < 3)
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                        "area light mesh: face %zu has %d vertices; expected 3 or more", i, nv[i]);
        for (int v = 0; v < nv[i]; v++)
            if (idx[k + (size_t)v] < 0 || (size_t)idx[k + (size_t)v] >= n_points)
                return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "area light mesh: index out of range");
    }
    if (st && !finite_all(st, 2 * n_points))
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light mesh: expected finite texture coordinates");
    FILE *f = area_light_begin(w, L);
    if (two_sided)
        fprintf(f, " \"float twosided\" [1]");
    if (texture) {
        fprintf(f, " \"string texturename\" ");
        string(f, texture);
    }
    /* Written as the triangles the scene keeps, so that a mesh of a few
     * quads reads back as the same one light, not as quad lights. */
    size_t n_tris = k - 2 * n_faces;
    fprintf(f, "\nPointsPolygons [");
    for (size_t i = 0; i < n_tris; i++)
        fprintf(f, i ? (i % 40 == 0 ? "\n   3" : " 3") : "3");
    fprintf(f, "]\n  [");
    k = 0;
    size_t out = 0;
    for (size_t i = 0; i < n_faces; k += (size_t)nv[i], i++)
        for (int c = 1; c + 1 < nv[i]; c++, out++)
            fprintf(f, "%s%d %d %d",
                    out == 0       ? ""
                    : out % 8 == 0 ? "\n   "
                                   : " ",
                    idx[k], idx[k + (size_t)c], idx[k + (size_t)c + 1]);
    fprintf(f, "]\n  \"P\" ");
    floats(f, P, 3 * n_points);
    if (st) {
        fprintf(f, "\n  \"st\" ");
        floats(f, st, 2 * n_points);
    }
    fprintf(f, "\nAttributeEnd\n");
    return RAYES_OK;
}

static RayesError w_area_light_mesh(void *t, size_t n_faces, const int *nv, const int *idx,
                                    size_t n_points, const float *P, const float L[3],
                                    int two_sided)
{
    return area_light_mesh(t, n_faces, nv, idx, n_points, P, NULL, L, two_sided, NULL);
}

static RayesError w_area_light_mesh_textured(void *t, size_t n_faces, const int *nv, const int *idx,
                                             size_t n_points, const float *P, const float *st,
                                             const float L[3], int two_sided, const char *texture)
{
    if (!st || !texture || !texture[0])
        return fail(t, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light mesh: expected texture coordinates and a texture");
    return area_light_mesh(t, n_faces, nv, idx, n_points, P, st, L, two_sided, texture);
}

static RayesError w_area_light_quadric(void *t, RayesQuadric type, const float *p, size_t n,
                                       unsigned flags, const float L[3], int two_sided)
{
    RibWriter *w = t;
    if (!finite_all(L, 3) || L[0] < 0 || L[1] < 0 || L[2] < 0)
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light quadric: expected a non-negative radiance");
    FILE *f = area_light_begin(w, L);
    fprintf(f, "%s\n", two_sided ? " \"float twosided\" [1]" : "");
    RayesError e = w_quadric(w, type, p, n, flags);
    fprintf(f, "AttributeEnd\n");
    return e;
}

static RayesError w_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    RibWriter *w = t;
    if (!type || !type[0])
        return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "light: no type");
    /* RenderMan's spotlight takes its angles in radians, rayes's in
     * degrees: they are written apart, in radians to 17 digits, so the
     * reader's conversion back gives the same float. */
    int spot = strcmp(type, "spotlight") == 0;
    /* RenderMan's point, spot and distant lights are pi times as intense
     * as rayes' (the reader's conversion): written apart, to 17 digits,
     * always (the default 1 too) */
    int uber = strcmp(type, "uberlight") == 0;
    int unit = spot || uber || strcmp(type, "pointlight") == 0 || strcmp(type, "distantlight") == 0;
    int shadows_given = 0;
    double maxintensity = -1.0;
    double I[3] = {1.0, 1.0, 1.0};
    int I_color = 0;
    RayesParam rest[64];
    double angle[2] = {-1.0, -1.0};
    size_t n_rest = 0;
    for (size_t i = 0; i < n; i++) {
        int k = !spot || p[i].type != RAYES_PARAM_FLOAT || !p[i].name ? -1
                : strcmp(p[i].name, "coneangle") == 0                 ? 0
                : strcmp(p[i].name, "conedeltaangle") == 0            ? 1
                                                                      : -1;
        if (unit && p[i].name && strcmp(p[i].name, "intensity") == 0 &&
            (p[i].type == RAYES_PARAM_FLOAT || p[i].type == RAYES_PARAM_COLOR)) {
            I_color = p[i].type == RAYES_PARAM_COLOR;
            for (int c = 0; c < 3; c++)
                I[c] = p[i].value[I_color ? c : 0];
        } else if (k >= 0) {
            angle[k] = (double)p[i].value[0] * M_PI / 180.0;
        } else if (uber && p[i].name && strcmp(p[i].name, "maxintensity") == 0 &&
                   p[i].type == RAYES_PARAM_FLOAT) {
            maxintensity = (double)p[i].value[0]; /* an intensity: pi times in RenderMan */
        } else if (uber && p[i].type == RAYES_PARAM_FLOATS) {
            continue; /* the blocker's matrix, written apart as an array */
        } else if (n_rest < sizeof rest / sizeof rest[0]) {
            shadows_given |= p[i].name && strcmp(p[i].name, "shadows") == 0;
            rest[n_rest++] = p[i];
        } else
            return fail(w, RAYES_ERROR_INVALID_ARGUMENT, "light: too many parameters");
    }
    char *text = NULL;
    RayesError e = params_text(w, rest, n_rest, 1, &text);
    if (e == RAYES_OK) {
        fprintf(w->world.f, "LightSource ");
        string(w->world.f, type);
        int h = w->next_light++;
        fprintf(w->world.f, " %d%s", h, text ? text : "");
        static const char *const angle_names[2] = {"coneangle", "conedeltaangle"};
        for (int k = 0; k < 2; k++)
            if (angle[k] >= 0.0)
                fprintf(w->world.f, " \"float %s\" [%.17g]", angle_names[k], angle[k]);
        if (unit && I_color)
            fprintf(w->world.f, " \"color intensity\" [%.17g %.17g %.17g]", I[0] / M_PI,
                    I[1] / M_PI, I[2] / M_PI);
        else if (unit)
            fprintf(w->world.f, " \"float intensity\" [%.17g]", I[0] / M_PI);
        if (maxintensity >= 0.0)
            fprintf(w->world.f, " \"float maxintensity\" [%.17g]", maxintensity / M_PI);
        if (unit && !shadows_given) /* rayes' default; RenderMan's lights cast none */
            fprintf(w->world.f, " \"float shadows\" [1]");
        for (size_t i = 0; uber && i < n; i++)
            if (p[i].type == RAYES_PARAM_FLOATS && p[i].name && p[i].floats &&
                finite_all(p[i].floats, p[i].n_floats)) {
                fprintf(w->world.f, " \"float[%zu] %s\" ", p[i].n_floats, p[i].name);
                floats(w->world.f, p[i].floats, p[i].n_floats);
            }
        fprintf(w->world.f, "\n");
        if (h < 4097 && !w_linked(w, (size_t)h - 1)) {
            fprintf(w->world.f, "Illuminate %d 0\n", h);
            w->off[h] = 1;
        }
    }
    free(text);
    return e;
}

/* Illuminate: the lights written so far are turned on or off to match the
 * links; a light written later is turned off after its LightSource if the
 * links in force exclude it. Links to lights not yet written, and area
 * lights, cannot be expressed (docs/convert.md). */
static int w_linked(const RibWriter *w, size_t light)
{
    int listed = 0;
    for (size_t i = 0; i < w->n_links; i++)
        listed |= w->links[i] == light;
    return w->links_mode == RAYES_LIGHT_LINKS_ALL    ? 1
           : w->links_mode == RAYES_LIGHT_LINKS_ONLY ? listed
                                                     : !listed;
}

static RayesError w_set_light_links(void *t, RayesLightLinks mode, const size_t *l, size_t n)
{
    RibWriter *w = t;
    size_t *copy = n ? malloc(n * sizeof *copy) : NULL;
    if (n && !copy)
        return fail(w, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    if (n)
        memcpy(copy, l, n * sizeof *copy);
    free(w->links);
    w->links = copy;
    w->n_links = n;
    w->links_mode = (int)mode;
    for (int h = 1; h < w->next_light && h < 4097; h++) {
        if (w->area[h])
            continue;
        int on = w_linked(w, (size_t)h - 1);
        if (on != !w->off[h]) {
            fprintf(w->world.f, "Illuminate %d %d\n", h, on);
            w->off[h] = (unsigned char)!on;
        }
    }
    return RAYES_OK;
}

static size_t w_light_count(void *t)
{
    return (size_t)((RibWriter *)t)->next_light - 1;
}

/* RIB names any shader: a converted file keeps the names it was given,
 * for the renderer that reads it to find (or fall back from). */
static int w_has_shader(void *t, const char *name)
{
    (void)t;
    return name && name[0];
}

static const char *w_get_error(void *t)
{
    return ((RibWriter *)t)->error;
}

/* An object handle as the RIB reader gave it (#1 or "name", quoted), or
 * another reader's name, written as a string. */
static void handle(FILE *f, const char *name)
{
    size_t n = strlen(name);
    if (name[0] == '#' && n > 1 && strspn(name + 1, "0123456789.-+eE") == n - 1) {
        fprintf(f, "%s", name + 1);
    } else if (n >= 2 && name[0] == '"' && name[n - 1] == '"') {
        char inner[256];
        snprintf(inner, sizeof inner, "%.*s", (int)(n - 2), name + 1);
        string(f, inner);
    } else {
        string(f, name);
    }
}

/* ObjectBegin: the block starts at the identity transform (the reader
 * resets it) and its attributes are restored at ObjectEnd, so the
 * writer's own record of them is saved. */
static RayesError w_object_begin(void *t, const char *name)
{
    RibWriter *w = t;
    if (w->in_object)
        return fail(w, RAYES_ERROR_INVALID_OPERATION, "object begin: inside an object block");
    w->outer.in_transform = w->in_transform;
    w->outer.opacity_set = w->opacity_set;
    w->outer.hitmode = w->hitmode;
    w->outer.opacity_cache = w->opacity_cache;
    w->outer.visibility = w->visibility;
    w->in_transform = 0;
    w->in_object = 1;
    fprintf(w->world.f, "ObjectBegin ");
    handle(w->world.f, name);
    fputc('\n', w->world.f);
    return RAYES_OK;
}

static RayesError w_object_end(void *t)
{
    RibWriter *w = t;
    if (!w->in_object)
        return fail(w, RAYES_ERROR_INVALID_OPERATION, "object end: no object block");
    if (w->in_transform)
        fprintf(w->world.f, "TransformEnd\n");
    fprintf(w->world.f, "ObjectEnd\n");
    w->in_object = 0;
    w->in_transform = w->outer.in_transform;
    w->opacity_set = w->outer.opacity_set;
    w->hitmode = w->outer.hitmode;
    w->opacity_cache = w->outer.opacity_cache;
    w->visibility = w->outer.visibility;
    return RAYES_OK;
}

static RayesError w_object_instance(void *t, const char *name)
{
    RibWriter *w = t;
    fprintf(w->world.f, "ObjectInstance ");
    handle(w->world.f, name);
    fputc('\n', w->world.f);
    return RAYES_OK;
}

IoSink io_rib_writer_sink(RibWriter *w)
{
    return (IoSink){
        .target = w,
        .set_camera = w_set_camera,
        .set_camera_matrix = w_set_camera_matrix,
        .set_transform = w_set_transform,
        .set_shader = w_set_shader,
        .set_displacement = w_set_displacement,
        .set_displacement_bound = w_set_displacement_bound,
        .set_search_path = w_set_search_path,
        .set_shading_rate = w_set_shading_rate,
        .bilinear_patch = w_bilinear_patch,
        .bicubic_patch = w_bicubic_patch,
        .polygon_mesh = w_polygon_mesh,
        .sphere = w_sphere,
        .quadric = w_quadric,
        .volume = w_volume,
        .volume_inside = w_volume_inside,
        .atmosphere = w_atmosphere,
        .area_light = w_area_light,
        .light = w_light,
        .set_light_links = w_set_light_links,
        .light_count = w_light_count,
        .get_error = w_get_error,
        .has_shader = w_has_shader,
        .subdivision_mesh = w_subdivision_mesh,
        .curves = w_curves,
        .points = w_points,
        .pattern = w_pattern,
        .set_visibility = w_set_visibility,
        .set_opacity_mode = w_set_opacity_mode,
        .object_begin = w_object_begin,
        .object_end = w_object_end,
        .object_instance = w_object_instance,
        .set_shutter = w_set_shutter,
        .set_transform_motion = w_set_transform_motion,
        .motion_begin = w_motion_begin,
        .motion_end = w_motion_end,
        .set_camera_motion = w_set_camera_motion,
        .set_depth_of_field = w_set_depth_of_field,
        .set_dice_blur = w_set_dice_blur,
        .blobby = w_blobby,
        .solid_begin = w_solid_begin,
        .solid_end = w_solid_end,
        .area_light_mesh = w_area_light_mesh,
        .area_light_mesh_textured = w_area_light_mesh_textured,
        .area_light_quadric = w_area_light_quadric,
    };
}

/* ------------------------------------------------------------- finish */

static void settings_rib(FILE *f, const IoSettings *s)
{
    if (s->width > 0 && s->height > 0)
        fprintf(f, "Format %d %d 1\n", s->width, s->height);
    if (s->spp > 0) {
        int r = (int)lround(sqrt((double)s->spp));
        if (r * r == s->spp)
            fprintf(f, "PixelSamples %d %d\n", r, r);
        else
            fprintf(f, "PixelSamples %d 1\n", s->spp);
    }
    if (s->max_spp > 0)
        fprintf(f, "Hider \"raytrace\" \"int maxsamples\" [%d]\n", s->max_spp);
    if (s->adaptive_error > 0.0f)
        fprintf(f, "PixelVariance %.9g\n", (double)s->adaptive_error);
    if (s->filter >= RAYES_FILTER_BOX && s->filter <= RAYES_FILTER_LANCZOS) {
        float def = 1.0f;
        io_filter_named(io_filter_name(s->filter), &def);
        double fw = s->filter_width > 0.0f ? s->filter_width : def;
        fprintf(f, "PixelFilter \"%s\" %.9g %.9g\n", io_filter_name(s->filter), fw, fw);
    }
    if (s->grid_size > 0)
        fprintf(f, "Option \"limits\" \"int gridsize\" [%d]\n", s->grid_size);
    if (s->texture_mb > 0.0)
        fprintf(f, "Option \"limits\" \"int texturememory\" [%.0f]\n",
                s->texture_mb * 1e6 / 1024.0);
    if (s->opacity_cache_mb > 0.0)
        fprintf(f, "Option \"limits\" \"int opacitycachememory\" [%.0f]\n",
                s->opacity_cache_mb * 1e6 / 1024.0);
    if (s->background[3] > 0.0f)
        fprintf(f, "Imager \"background\" \"color bgcolor\" [%.9g %.9g %.9g]\n",
                (double)s->background[0], (double)s->background[1], (double)s->background[2]);
    if (s->exposure_gain != 1.0f || s->exposure_gamma != 1.0f)
        fprintf(f, "Exposure %.9g %.9g\n", (double)s->exposure_gain, (double)s->exposure_gamma);
    /* the curve always: a RIB file without it is read as RenderMan's */
    fprintf(f, "Option \"rayes\" \"string pngcurve\" [\"%s\"]\n",
            s->png_curve == IO_CURVE_LINEAR ? "linear" : "srgb");
    if (s->crop[0] != 0.0f || s->crop[1] != 1.0f || s->crop[2] != 0.0f || s->crop[3] != 1.0f)
        fprintf(f, "CropWindow %.9g %.9g %.9g %.9g\n", (double)s->crop[0], (double)s->crop[1],
                (double)s->crop[2], (double)s->crop[3]);
    for (int i = 0; i < s->n_displays && i < IO_MAX_DISPLAYS; i++) {
        char name[520];
        snprintf(name, sizeof name, "%s%s", i ? "+" : "", s->displays[i].name);
        fprintf(f, "Display ");
        string(f, name);
        fputc(' ', f);
        string(f, s->displays[i].type[0] ? s->displays[i].type : "file");
        fputc(' ', f);
        string(f, s->displays[i].mode[0] ? s->displays[i].mode : "rgba");
        fputc('\n', f);
    }
}

/* RenderMan's fov spans the shorter side of the image; set_camera's is
 * vertical, so a portrait image needs the horizontal angle. */
static double rib_fov(const RibWriter *w, const IoSettings *s)
{
    double fov = w->fov_y;
    if (s && s->width > 0 && s->height > s->width) {
        double t = tan(fov * M_PI / 360.0) * s->width / s->height;
        fov = atan(t) * 360.0 / M_PI;
    }
    return fov;
}

RayesError io_rib_writer_finish(RibWriter *w, const IoSettings *s, FILE *out, char *err,
                                size_t err_size)
{
    if (fflush(w->options.f) != 0 || fflush(w->camera.f) != 0 || fflush(w->world.f) != 0) {
        snprintf(err, err_size, "out of memory");
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    fprintf(out, "##RenderMan RIB\n# written by rayes %s\nversion 3.04\n",
            rayes_version_string());
    if (s) {
        settings_rib(out, s);
        if (s->bounces >= 0 || s->specular_depth >= 0) {
            fprintf(out, "Attribute \"trace\"");
            if (s->bounces >= 0)
                fprintf(out, " \"int maxdiffusedepth\" [%d]", s->bounces);
            if (s->specular_depth >= 0)
                fprintf(out, " \"int maxspeculardepth\" [%d]", s->specular_depth);
            fputc('\n', out);
        }
    }
    fwrite(w->options.buf, 1, w->options.size, out);
    if (w->shutter[1] > w->shutter[0])
        fprintf(out, "Shutter %.9g %.9g\n", (double)w->shutter[0], (double)w->shutter[1]);
    if (w->lens[0] > 0.0f) /* fstop 1: a focal length of the lens's diameter */
        fprintf(out, "DepthOfField 1 %.9g %.9g\n", 2.0 * w->lens[0], (double)w->lens[1]);
    if (w->fov_y > 0.0f)
        fprintf(out, "Projection \"perspective\" \"fov\" [%.9g]\n", rib_fov(w, s));
    fwrite(w->camera.buf, 1, w->camera.size, out);
    fprintf(out, "WorldBegin\n%s", w->atmosphere ? w->atmosphere : "");
    fwrite(w->world.buf, 1, w->world.size, out);
    fprintf(out, "%sWorldEnd\n", w->in_transform ? "TransformEnd\n" : "");
    if (fflush(out) != 0 || ferror(out)) {
        snprintf(err, err_size, "write error");
        return RAYES_ERROR_IO;
    }
    return RAYES_OK;
}
