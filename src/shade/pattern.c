/*
 * shade/pattern.c — pattern graphs (pattern.h): pbrt-v4's textures made
 * from a class table, and their evaluation PATTERN_CHUNK points at a time.
 *
 * Each node evaluates its inputs (constants, or the nodes they name) into
 * arrays on the stack, one set per level of the graph (PATTERN_MAX_DEPTH
 * levels at most), then combines them. The formulas are pbrt-v4's
 * (textures.h, noise.cpp), with rayes' own gradient noise (noise.h) in
 * place of pbrt's and checkerboards box-filtered exactly (noise.h's
 * pattern_checker, as the checker service). pbrt's (u, v) is rayes' (s,
 * 1 - t): the pbrt reader turned v into t = 1 - v, and pbrt flips v again
 * before an image lookup, so an image lands as pbrt shows it. The grid
 * classes (densitygrid, nanovdb) own a VoxelGrid (grid.h), made here from
 * their parameters and sampled in texture space.
 */
#include "shade/pattern.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shade/grid.h"
#include "shade/noise.h"
#include "shade/shade.h"
#include "util/vec.h"

#define PATTERN_CHUNK 64
#define MAX_INPUTS 4
#define MAX_SLOTS 6

typedef float Rgb[3];

typedef enum PatternKind {
    PK_CONSTANT,
    PK_SCALE,
    PK_MIX,
    PK_DIRECTIONMIX,
    PK_CHECKERBOARD,
    PK_IMAGEMAP,
    PK_BILERP,
    PK_DOTS,
    PK_FBM,
    PK_WRINKLED,
    PK_WINDY,
    PK_MARBLE,
    PK_CLOUD,
    PK_DENSITYGRID,
    PK_NANOVDB
} PatternKind;

/* One input: another pattern, or a constant when node is NULL. */
typedef struct Input {
    const Pattern *node;
    float value[3];
} Input;

struct RayesPattern {
    PatternKind kind;
    int depth;                    /* 1 + the deepest input's depth */
    Input in[MAX_INPUTS];         /* the class's inputs, in its slot order */
    float num[4];                 /* the class's numbers (ClassDesc's 'n' slots) */
    float vec[3];                 /* directionmix's dir, world space, unit */
    float uv[4];                  /* uscale, vscale, udelta, vdelta */
    int mapping;                  /* MAP_UV ... MAP_PLANAR: pbrt-v4's (u, v) of a point */
    float v1[3], v2[3];           /* planar: the texture-space axes of u and v */
    float texture_from_world[16]; /* row-major; the 3-D classes' space */
    char filename[1024];          /* imagemap */
    char encoding[32];            /* imagemap: "" (the file's), "sRGB", "linear", "gamma G" */
    char wrap[16];                /* imagemap: "" or "repeat", "black", "clamp" */
    VoxelGrid *grid;              /* densitygrid, nanovdb: owned */
    _Atomic int probed;           /* what the file's texels told, once read (0: not yet; a
                                     file does not change, renders share it): channel -2,
                                     the matte's channel + 1; -3 and -4, BUMP_HEIGHT or
                                     BUMP_NORMAL */
};

/* A parameter of a class: an input ('i'), a number ('n'), a string ('s')
 * or a direction ('v'), stored at index of its kind. */
typedef struct Slot {
    const char *name;
    char what;
    int index;
    float def[3];
} Slot;

typedef struct ClassDesc {
    const char *name;
    PatternKind kind;
    int uv; /* takes uscale, vscale, udelta, vdelta */
    Slot slots[MAX_SLOTS];
} ClassDesc;

/* pbrt-v4's parameters and defaults. */
static const ClassDesc classes[] = {
    {"constant", PK_CONSTANT, 0, {{"value", 'i', 0, {1, 1, 1}}}},
    {"scale", PK_SCALE, 0, {{"tex", 'i', 0, {1, 1, 1}}, {"scale", 'i', 1, {1, 1, 1}}}},
    {"mix",
     PK_MIX,
     0,
     {{"tex1", 'i', 0, {0, 0, 0}},
      {"tex2", 'i', 1, {1, 1, 1}},
      {"amount", 'i', 2, {.5f, .5f, .5f}}}},
    {"directionmix",
     PK_DIRECTIONMIX,
     0,
     {{"tex1", 'i', 0, {0, 0, 0}}, {"tex2", 'i', 1, {1, 1, 1}}, {"dir", 'v', 0, {0, 1, 0}}}},
    {"checkerboard",
     PK_CHECKERBOARD,
     1,
     {{"tex1", 'i', 0, {1, 1, 1}}, {"tex2", 'i', 1, {0, 0, 0}}, {"dimension", 'n', 0, {2}}}},
    {"imagemap",
     PK_IMAGEMAP,
     1,
     {{"filename", 's', 0, {0}},
      {"encoding", 's', 1, {0}},
      {"wrap", 's', 2, {0}},
      {"scale", 'n', 0, {1}},
      {"invert", 'n', 1, {0}},
      {"channel", 'n', 2, {-1}}}},
    {"bilerp",
     PK_BILERP,
     1,
     {{"v00", 'i', 0, {0, 0, 0}},
      {"v01", 'i', 1, {1, 1, 1}},
      {"v10", 'i', 2, {0, 0, 0}},
      {"v11", 'i', 3, {1, 1, 1}}}},
    {"dots", PK_DOTS, 1, {{"inside", 'i', 0, {1, 1, 1}}, {"outside", 'i', 1, {0, 0, 0}}}},
    {"fbm", PK_FBM, 0, {{"octaves", 'n', 0, {8}}, {"roughness", 'n', 1, {.5f}}}},
    {"wrinkled", PK_WRINKLED, 0, {{"octaves", 'n', 0, {8}}, {"roughness", 'n', 1, {.5f}}}},
    {"windy", PK_WINDY, 0, {{NULL, 0, 0, {0}}}},
    {"marble",
     PK_MARBLE,
     0,
     {{"octaves", 'n', 0, {8}},
      {"roughness", 'n', 1, {.5f}},
      {"scale", 'n', 2, {1}},
      {"variation", 'n', 3, {.2f}}}},
    {"cloud",
     PK_CLOUD,
     0,
     {{"density", 'n', 0, {1}}, {"wispiness", 'n', 1, {1}}, {"frequency", 'n', 2, {5}}}},
    /* their parameters are read by make_grid */
    {"densitygrid", PK_DENSITYGRID, 0, {{NULL, 0, 0, {0}}}},
    {"nanovdb", PK_NANOVDB, 0, {{NULL, 0, 0, {0}}}},
};

static const char *const uv_names[4] = {"uscale", "vscale", "udelta", "vdelta"};

/* pbrt-v4's texture mappings (textures.h), in the pattern's space: the
 * surface's (u, v); the sphere's (theta / pi, phi / 2 pi) about the
 * origin; the cylinder's ((pi + atan2(y, x)) / 2 pi, z) about z; the
 * plane's (P.v1 + udelta, P.v2 + vdelta). */
enum { MAP_UV, MAP_SPHERICAL, MAP_CYLINDRICAL, MAP_PLANAR };
static const char *const mapping_names[4] = {"uv", "spherical", "cylindrical", "planar"};

/* ------------------------------------------------------------ making */

static const ClassDesc *find_class(const char *type)
{
    for (size_t i = 0; i < sizeof classes / sizeof classes[0]; i++)
        if (strcmp(classes[i].name, type) == 0)
            return &classes[i];
    return NULL;
}

static const Slot *find_slot(const ClassDesc *c, const char *name)
{
    for (int k = 0; k < MAX_SLOTS && c->slots[k].name; k++)
        if (strcmp(c->slots[k].name, name) == 0)
            return &c->slots[k];
    return NULL;
}

/* The values of one parameter into p; -1 with err filled if it does not
 * fit its slot. */
static int set_slot(Pattern *p, const ClassDesc *c, const RayesParam *q, PatternFind find,
                    void *data, char *err, size_t err_size)
{
    for (int k = 0; k < 4; k++)
        if (c->uv && strcmp(q->name, uv_names[k]) == 0 && q->type == RAYES_PARAM_FLOAT) {
            p->uv[k] = q->value[0];
            return 0;
        }
    if (c->uv && strcmp(q->name, "mapping") == 0 && q->type == RAYES_PARAM_STRING) {
        for (int k = 0; k < 4; k++)
            if (q->string && strcmp(q->string, mapping_names[k]) == 0) {
                p->mapping = k;
                return 0;
            }
        snprintf(err, err_size,
                 "pattern \"%s\": mapping \"%.40s\" is not uv, spherical, cylindrical or planar",
                 c->name, q->string ? q->string : "");
        return -1;
    }
    if (c->uv && (strcmp(q->name, "v1") == 0 || strcmp(q->name, "v2") == 0) &&
        q->type == RAYES_PARAM_COLOR) {
        memcpy(q->name[1] == '1' ? p->v1 : p->v2, q->value, sizeof p->v1);
        return 0;
    }
    const Slot *s = find_slot(c, q->name);
    int ok = s && ((s->what == 'i' && q->type != RAYES_PARAM_STRING) ||
                   (s->what == 'n' && q->type == RAYES_PARAM_FLOAT) ||
                   (s->what == 'v' && q->type == RAYES_PARAM_COLOR) ||
                   (s->what == 's' && q->type == RAYES_PARAM_STRING));
    if (!ok) {
        snprintf(err, err_size,
                 s ? "pattern \"%s\": parameter \"%s\" has the wrong type"
                   : "pattern \"%s\" has no parameter \"%s\"",
                 c->name, q->name);
        return -1;
    }
    if (s->what == 'n') {
        p->num[s->index] = q->value[0];
    } else if (s->what == 'v') {
        memcpy(p->vec, q->value, sizeof p->vec);
    } else if (s->what == 's') {
        const char *v = q->string ? q->string : "";
        char *dst = s->index == 0 ? p->filename : s->index == 1 ? p->encoding : p->wrap;
        size_t size = s->index == 0   ? sizeof p->filename
                      : s->index == 1 ? sizeof p->encoding
                                      : sizeof p->wrap;
        if (strlen(v) >= size) {
            snprintf(err, err_size, "pattern \"%s\": \"%s\" is too long", c->name, q->name);
            return -1;
        }
        memcpy(dst, v, strlen(v) + 1);
    } else if (q->type == RAYES_PARAM_PATTERN) {
        const Pattern *n = q->string && find ? find(data, q->string) : NULL;
        if (!n) {
            snprintf(err, err_size, "pattern \"%s\": \"%s\" names no pattern (\"%.64s\")", c->name,
                     q->name, q->string ? q->string : "");
            return -1;
        }
        p->in[s->index].node = n;
    } else {
        Input *in = &p->in[s->index];
        in->node = NULL;
        for (int k = 0; k < 3; k++)
            in->value[k] = q->type == RAYES_PARAM_FLOAT ? q->value[0] : q->value[k];
    }
    return 0;
}

/* The parameter of that name and type among params, or NULL. */
static const RayesParam *grid_param(const RayesParam *params, size_t n, const char *name,
                                    RayesParamType type)
{
    for (size_t i = 0; i < n; i++)
        if (params[i].name && strcmp(params[i].name, name) == 0 && params[i].type == type)
            return &params[i];
    return NULL;
}

/* densitygrid's grid from nx ny nz, density, p0 and p1 (checked for
 * type by make_grid); -1 with err filled. */
static int dense_grid(Pattern *p, const RayesParam *params, size_t n, char *err, size_t err_size)
{
    static const char *const counts[3] = {"nx", "ny", "nz"};
    size_t res[3] = {1, 1, 1};
    float p0[3] = {0, 0, 0}, p1[3] = {1, 1, 1};
    for (int k = 0; k < 3; k++) {
        const RayesParam *q = grid_param(params, n, counts[k], RAYES_PARAM_FLOAT);
        if (q && !(q->value[0] >= 1.0f && q->value[0] <= 1048576.0f &&
                   q->value[0] == floorf(q->value[0]))) {
            snprintf(err, err_size, "%s must be a count", counts[k]);
            return -1;
        }
        res[k] = q ? (size_t)q->value[0] : 1;
    }
    const RayesParam *d = grid_param(params, n, "density", RAYES_PARAM_FLOATS);
    const RayesParam *one = grid_param(params, n, "density", RAYES_PARAM_FLOAT);
    const RayesParam *lo = grid_param(params, n, "p0", RAYES_PARAM_COLOR);
    const RayesParam *hi = grid_param(params, n, "p1", RAYES_PARAM_COLOR);
    if (lo)
        memcpy(p0, lo->value, sizeof p0);
    if (hi)
        memcpy(p1, hi->value, sizeof p1);
    const float *values = d ? d->floats : one ? one->value : NULL;
    size_t n_values = d ? d->n_floats : one ? 1 : 0;
    p->grid = grid_new_dense(res, values, n_values, p0, p1, err, err_size);
    return p->grid ? 0 : -1;
}

/* The grid classes' parameters: densitygrid's nx ny nz, density, p0, p1
 * (pbrt-v4's uniformgrid medium), nanovdb's filename, grid and optional
 * (nonzero: a file without that grid reads 0 everywhere). Unknown or
 * mistyped parameters are refused like set_slot's. */
static int make_grid(Pattern *p, const ClassDesc *c, const RayesParam *params, size_t n, char *err,
                     size_t err_size)
{
    static const char *const dense_names[] = {"nx", "ny", "nz", "density", "p0", "p1", NULL};
    static const RayesParamType dense_types[] = {RAYES_PARAM_FLOAT, RAYES_PARAM_FLOAT,
                                                 RAYES_PARAM_FLOAT, RAYES_PARAM_FLOATS,
                                                 RAYES_PARAM_COLOR, RAYES_PARAM_COLOR};
    static const char *const vdb_names[] = {"filename", "grid", "optional", NULL};
    static const RayesParamType vdb_types[] = {RAYES_PARAM_STRING, RAYES_PARAM_STRING,
                                               RAYES_PARAM_FLOAT};
    int dense = p->kind == PK_DENSITYGRID;
    const char *const *names = dense ? dense_names : vdb_names;
    const RayesParamType *types = dense ? dense_types : vdb_types;
    for (size_t i = 0; i < n; i++) {
        int k = 0;
        while (names[k] && strcmp(names[k], params[i].name) != 0)
            k++;
        /* one density value may come as a FLOAT */
        int single = dense && k == 3 && params[i].type == RAYES_PARAM_FLOAT;
        if (!names[k] || (params[i].type != types[k] && !single)) {
            snprintf(err, err_size,
                     names[k] ? "pattern \"%s\": parameter \"%s\" has the wrong type"
                              : "pattern \"%s\" has no parameter \"%s\"",
                     c->name, params[i].name);
            return -1;
        }
    }
    char grid_err[1200];
    if (dense) {
        if (dense_grid(p, params, n, grid_err, sizeof grid_err) != 0) {
            snprintf(err, err_size, "pattern \"densitygrid\": %s", grid_err);
            return -1;
        }
    } else {
        const RayesParam *file = grid_param(params, n, "filename", RAYES_PARAM_STRING);
        const RayesParam *name = grid_param(params, n, "grid", RAYES_PARAM_STRING);
        if (!file || !file->string || !file->string[0]) {
            snprintf(err, err_size, "pattern \"nanovdb\": no filename");
            return -1;
        }
        const RayesParam *optional = grid_param(params, n, "optional", RAYES_PARAM_FLOAT);
        p->grid = grid_read_nanovdb(file->string, name && name->string ? name->string : "density",
                                    grid_err, sizeof grid_err);
        if (!p->grid && optional && optional->value[0] != 0.0f && grid_error_missing(grid_err)) {
            /* an optional grid the file lacks (pbrt's temperature): 0 everywhere */
            static const size_t one[3] = {1, 1, 1};
            static const float zero = 0.0f, p0[3] = {0, 0, 0}, p1[3] = {1, 1, 1};
            p->grid = grid_new_dense(one, &zero, 1, p0, p1, grid_err, sizeof grid_err);
        }
    }
    if (!p->grid) {
        snprintf(err, err_size, "pattern \"%s\": %s", c->name, grid_err);
        return -1;
    }
    return 0;
}

/* Checks what set_slot cannot: values that only make sense together. */
static int check_pattern(Pattern *p, const ClassDesc *c, char *err, size_t err_size)
{
    if (p->kind == PK_CHECKERBOARD && p->num[0] != 2.0f && p->num[0] != 3.0f) {
        snprintf(err, err_size, "pattern \"checkerboard\": dimension must be 2 or 3");
        return -1;
    }
    if (p->kind == PK_IMAGEMAP) {
        float g;
        char tail;
        if (!p->filename[0]) {
            snprintf(err, err_size, "pattern \"imagemap\": no filename");
            return -1;
        }
        if (p->wrap[0] && strcmp(p->wrap, "repeat") != 0 && strcmp(p->wrap, "black") != 0 &&
            strcmp(p->wrap, "clamp") != 0) {
            snprintf(err, err_size,
                     "pattern \"imagemap\": wrap \"%s\" is not \"repeat\", \"black\" or \"clamp\"",
                     p->wrap);
            return -1;
        }
        if (p->encoding[0] && strcmp(p->encoding, "sRGB") != 0 &&
            strcmp(p->encoding, "linear") != 0 &&
            !(sscanf(p->encoding, "gamma %f%c", &g, &tail) == 1 && g > 0.0f && g < 100.0f)) {
            snprintf(err, err_size,
                     "pattern \"imagemap\": encoding \"%s\" is not \"sRGB\", \"linear\" or "
                     "\"gamma G\"",
                     p->encoding);
            return -1;
        }
        if (!(p->num[2] >= -4.0f && p->num[2] <= 3.0f)) {
            snprintf(err, err_size, "pattern \"imagemap\": channel must be -4 to 3");
            return -1;
        }
    }
    if ((p->kind == PK_FBM || p->kind == PK_WRINKLED || p->kind == PK_MARBLE) &&
        !(p->num[0] >= 0.0f && p->num[0] <= 32.0f)) {
        snprintf(err, err_size, "pattern \"%s\": octaves must be 0 to 32", c->name);
        return -1;
    }
    for (int k = 0; k < MAX_INPUTS; k++)
        if (p->in[k].node && p->in[k].node->depth + 1 > p->depth)
            p->depth = p->in[k].node->depth + 1;
    if (p->depth > PATTERN_MAX_DEPTH) {
        snprintf(err, err_size, "pattern \"%s\": patterns nest deeper than %d", c->name,
                 PATTERN_MAX_DEPTH);
        return -1;
    }
    return 0;
}

Pattern *pattern_new(const char *type, const RayesParam *params, size_t n_params,
                     const float world_from_texture[16], PatternFind find, void *find_data,
                     char *err, size_t err_size)
{
    const ClassDesc *c = type ? find_class(type) : NULL;
    if (!c) {
        snprintf(err, err_size, "unknown pattern class \"%.64s\"", type ? type : "");
        return NULL;
    }
    Pattern *p = calloc(1, sizeof *p);
    if (!p) {
        snprintf(err, err_size, "out of memory");
        return NULL;
    }
    p->kind = c->kind;
    p->depth = 1;
    p->uv[0] = p->uv[1] = 1.0f;
    p->v1[0] = p->v2[1] = 1.0f; /* pbrt's planar defaults: x and y */
    for (int k = 0; k < MAX_SLOTS && c->slots[k].name; k++) {
        const Slot *s = &c->slots[k];
        if (s->what == 'i')
            memcpy(p->in[s->index].value, s->def, sizeof s->def);
        else if (s->what == 'n')
            p->num[s->index] = s->def[0];
        else if (s->what == 'v')
            memcpy(p->vec, s->def, sizeof s->def);
    }
    int grid = c->kind == PK_DENSITYGRID || c->kind == PK_NANOVDB;
    for (size_t i = 0; i < n_params; i++)
        if (!params[i].name ||
            (!grid && set_slot(p, c, &params[i], find, find_data, err, err_size) != 0)) {
            if (!params[i].name)
                snprintf(err, err_size, "pattern \"%s\": a parameter has no name", c->name);
            free(p);
            return NULL;
        }
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const float *m = world_from_texture ? world_from_texture : identity;
    /* dir is a direction in texture space; shading normals are world */
    float d[3], len = 0.0f;
    for (int r = 0; r < 3; r++) {
        d[r] = m[4 * r] * p->vec[0] + m[4 * r + 1] * p->vec[1] + m[4 * r + 2] * p->vec[2];
        len += d[r] * d[r];
    }
    len = sqrtf(len);
    for (int r = 0; r < 3; r++)
        p->vec[r] = len > 0.0f ? d[r] / len : 0.0f;
    Mat4 inv;
    if (!mat4_invert(mat4_from_array(m), &inv)) {
        snprintf(err, err_size, "pattern \"%s\": the transform is singular", c->name);
        free(p);
        return NULL;
    }
    memcpy(p->texture_from_world, inv.m, sizeof p->texture_from_world);
    if ((grid && make_grid(p, c, params, n_params, err, err_size) != 0) ||
        check_pattern(p, c, err, err_size) != 0) {
        pattern_free(p);
        return NULL;
    }
    return p;
}

void pattern_free(Pattern *p)
{
    if (p)
        grid_free(p->grid);
    free(p);
}

/* ------------------------------------------------------------ evaluating */

/* The points of one chunk and what evaluation needs of them. */
typedef struct Eval {
    const RayesShadeCtx *ctx; /* at most PATTERN_CHUNK points */
    const float *ds, *dt;     /* st footprint, or NULL */
    TextureSystem *ts;
    int failed; /* an image could not be read */
} Eval;

static void eval_node(const Pattern *p, Eval *e, Rgb *out);

static void eval_input(const Input *in, Eval *e, Rgb *out)
{
    if (in->node) {
        eval_node(in->node, e, out);
        return;
    }
    for (size_t i = 0; i < e->ctx->n_points; i++)
        memcpy(out[i], in->value, sizeof out[i]);
}

static void point_at(const Pattern *p, const Eval *e, size_t i, float q[3], float dx[3],
                     float dy[3]);

/* The (s, t) of a texture-space point q by mapping m (not MAP_UV). */
static void map_point(const Pattern *p, const float q[3], float st[2])
{
    if (p->mapping == MAP_SPHERICAL) {
        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        float z = len > 0.0f ? fminf(fmaxf(q[2] / len, -1.0f), 1.0f) : 1.0f;
        float phi = atan2f(q[1], q[0]);
        st[0] = acosf(z) / (float)M_PI;
        st[1] = (phi < 0.0f ? phi + 2.0f * (float)M_PI : phi) / (2.0f * (float)M_PI);
    } else if (p->mapping == MAP_CYLINDRICAL) {
        st[0] = ((float)M_PI + atan2f(q[1], q[0])) / (2.0f * (float)M_PI);
        st[1] = q[2];
    } else {
        st[0] = q[0] * p->v1[0] + q[1] * p->v1[1] + q[2] * p->v1[2] + p->uv[2];
        st[1] = q[0] * p->v2[0] + q[1] * p->v2[1] + q[2] * p->v2[2] + p->uv[3];
    }
}

/* The change of a mapped coordinate, across the seam of an angle taken
 * the short way round. */
static float map_delta(const Pattern *p, int k, float d)
{
    int angle =
        (p->mapping == MAP_SPHERICAL && k == 1) || (p->mapping == MAP_CYLINDRICAL && k == 0);
    if (angle && fabsf(d) > 0.5f)
        d -= copysignf(1.0f, d);
    return fabsf(d);
}

/* pbrt's (u, v) and its footprint at point i: the surface's after
 * uscale ... vdelta, or the mapping's of the point (its footprint the
 * mapped change across the point's dPdu du and dPdv dv). */
static void uv_at(const Pattern *p, const Eval *e, size_t i, float *u, float *v, float *du,
                  float *dv)
{
    const RayesShadeCtx *c = e->ctx;
    if (p->mapping != MAP_UV) {
        float q[3], dx[3], dy[3], qx[3], qy[3], st[2], sx[2], sy[2];
        point_at(p, e, i, q, dx, dy);
        for (int k = 0; k < 3; k++)
            qx[k] = q[k] + dx[k], qy[k] = q[k] + dy[k];
        map_point(p, q, st);
        map_point(p, qx, sx);
        map_point(p, qy, sy);
        *u = st[0];
        *v = st[1];
        *du = fmaxf(map_delta(p, 0, sx[0] - st[0]), map_delta(p, 0, sy[0] - st[0]));
        *dv = fmaxf(map_delta(p, 1, sx[1] - st[1]), map_delta(p, 1, sy[1] - st[1]));
        return;
    }
    float s = c->s ? c->s[i] : c->u ? c->u[i] : 0.0f;
    float t = c->t ? c->t[i] : c->v ? c->v[i] : 0.0f;
    float ws = e->ds ? e->ds[i] : c->du ? c->du[i] : 0.0f;
    float wt = e->dt ? e->dt[i] : c->dv ? c->dv[i] : 0.0f;
    *u = p->uv[0] * s + p->uv[2];
    *v = p->uv[1] * (1.0f - t) + p->uv[3];
    *du = fabsf(p->uv[0] * ws);
    *dv = fabsf(p->uv[1] * wt);
}

static void xform_point(const float m[16], const float a[3], float o[3])
{
    for (int r = 0; r < 3; r++)
        o[r] = m[4 * r] * a[0] + m[4 * r + 1] * a[1] + m[4 * r + 2] * a[2] + m[4 * r + 3];
}

static void xform_vector(const float m[16], const float a[3], float s, float o[3])
{
    for (int r = 0; r < 3; r++)
        o[r] = s * (m[4 * r] * a[0] + m[4 * r + 1] * a[1] + m[4 * r + 2] * a[2]);
}

/* The texture-space point of point i and its footprint vectors (pbrt's
 * dpdx, dpdy): dPdu du and dPdv dv. */
static void point_at(const Pattern *p, const Eval *e, size_t i, float q[3], float dx[3],
                     float dy[3])
{
    const RayesShadeCtx *c = e->ctx;
    static const float zero[3] = {0, 0, 0};
    xform_point(p->texture_from_world, c->P ? c->P[i] : zero, q);
    xform_vector(p->texture_from_world, c->dPdu ? c->dPdu[i] : zero, c->du ? c->du[i] : 0.0f, dx);
    xform_vector(p->texture_from_world, c->dPdv ? c->dPdv[i] : zero, c->dv ? c->dv[i] : 0.0f, dy);
}

static float smoothstep(float x, float a, float b)
{
    float t = fminf(fmaxf((x - a) / (b - a), 0.0f), 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

/* pbrt's FBm and Turbulence: octaves beyond the footprint's Nyquist limit
 * are left out, the last one faded in. */
static float fractal(const float q[3], const float dx[3], const float dy[3], float omega,
                     int octaves, int turbulent)
{
    float l2 = fmaxf(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2],
                     dy[0] * dy[0] + dy[1] * dy[1] + dy[2] * dy[2]);
    float n = fminf(fmaxf(-1.0f - 0.5f * log2f(fmaxf(l2, 1e-30f)), 0.0f), (float)octaves);
    int whole = (int)floorf(n);
    float sum = 0.0f, lambda = 1.0f, o = 1.0f;
    for (int k = 0; k < whole; k++) {
        float v = noise3(lambda * q[0], lambda * q[1], lambda * q[2]);
        sum += o * (turbulent ? fabsf(v) : v);
        lambda *= NOISE_LACUNARITY;
        o *= omega;
    }
    float v = noise3(lambda * q[0], lambda * q[1], lambda * q[2]);
    float fade = smoothstep(n - (float)whole, 0.3f, 0.7f);
    if (!turbulent)
        return sum + o * fade * v;
    sum += o * (0.2f + fade * (fabsf(v) - 0.2f));
    for (int k = whole + 1; k < octaves; k++) { /* the octaves left out, at their mean */
        o *= omega;
        sum += o * 0.2f;
    }
    return sum;
}

static void grey(Rgb out, float v)
{
    out[0] = out[1] = out[2] = v;
}

/* pbrt's marble: a sine of height perturbed by fBm, through a spline. */
static void marble(const Pattern *p, const float q[3], const float dx[3], const float dy[3],
                   Rgb out)
{
    static const float colors[9][3] = {{.58f, .58f, .6f}, {.58f, .58f, .6f}, {.58f, .58f, .6f},
                                       {.5f, .5f, .5f},   {.6f, .59f, .58f}, {.58f, .58f, .6f},
                                       {.58f, .58f, .6f}, {.2f, .2f, .33f},  {.58f, .58f, .6f}};
    float sc = p->num[2], ps[3], sx[3], sy[3];
    for (int k = 0; k < 3; k++)
        ps[k] = q[k] * sc, sx[k] = dx[k] * sc, sy[k] = dy[k] * sc;
    float m = ps[1] + p->num[3] * fractal(ps, sx, sy, p->num[1], (int)p->num[0], 0);
    float t = 0.5f + 0.5f * sinf(m);
    int segments = 6, first = (int)floorf(t * (float)segments);
    first = first < 0 ? 0 : first > segments - 1 ? segments - 1 : first;
    t = t * (float)segments - (float)first;
    for (int c = 0; c < 3; c++) { /* de Casteljau on four control points */
        float b[4];
        for (int k = 0; k < 4; k++)
            b[k] = colors[first + k][c];
        for (int r = 3; r > 0; r--)
            for (int k = 0; k < r; k++)
                b[k] += t * (b[k + 1] - b[k]);
        out[c] = fminf(fmaxf(1.5f * b[0], 0.0f), 1.0f);
    }
}

/* pbrt's polka dots: a dot of radius 0.35 in half the cells of (u, v),
 * jittered within its cell; 1 inside, 0 outside. */
static float dot_at(float u, float v)
{
    float sc = floorf(u + 0.5f), tc = floorf(v + 0.5f);
    if (noise3(sc + 0.5f, tc + 0.5f, 0.5f) <= 0.0f)
        return 0.0f;
    const float radius = 0.35f, shift = 0.5f - radius;
    float cs = sc + shift * noise3(sc + 1.5f, tc + 2.8f, 0.5f);
    float ct = tc + shift * noise3(sc + 4.5f, tc + 9.8f, 0.5f);
    float a = u - cs, b = v - ct;
    return a * a + b * b < radius * radius ? 1.0f : 0.0f;
}

/* The weight of tex1 (0 to 1) at point i of the selecting classes. */
static float weight_at(const Pattern *p, const Eval *e, const Rgb *amount, size_t i)
{
    float u, v, du, dv, q[3], dx[3], dy[3];
    switch (p->kind) {
    case PK_MIX:
        return 1.0f - amount[i][0];
    case PK_DIRECTIONMIX: {
        const float *N = e->ctx->N ? e->ctx->N[i] : p->vec;
        return fabsf(N[0] * p->vec[0] + N[1] * p->vec[1] + N[2] * p->vec[2]);
    }
    case PK_CHECKERBOARD:
        if (p->num[0] == 3.0f) {
            point_at(p, e, i, q, dx, dy);
            float f = floorf(q[0]) + floorf(q[1]) + floorf(q[2]);
            return fmodf(fabsf(f), 2.0f) == 0.0f ? 1.0f : 0.0f;
        }
        uv_at(p, e, i, &u, &v, &du, &dv);
        return pattern_checker(u, v, du, dv);
    default: /* PK_DOTS */
        uv_at(p, e, i, &u, &v, &du, &dv);
        return dot_at(u, v);
    }
}

enum { BUMP_HEIGHT = 1, BUMP_NORMAL = 2 };

/* Whether the file of a bump slot (an OBJ's bump, map_Bump, norm) is a
 * normal map or a height map, from its average texel (the lookup's widest
 * footprint, the MIP pyramid's last level): a tangent-space normal map
 * averages about (0.5, 0.5, 1) — blue well above red and green, both near
 * a half — where a height map is grey. Kept once the file was read. */
static int bump_kind(const Pattern *p, Eval *e)
{
    Pattern *mp = (Pattern *)p;
    int known = atomic_load_explicit(&mp->probed, memory_order_relaxed);
    if (known || !e->ts)
        return known ? known : BUMP_HEIGHT;
    float s = 0.5f, t = 0.5f, w = 1.0f, avg[1][3], alpha;
    if (texture_lookup_encoded(e->ts, p->filename, p->encoding, TEXTURE_WRAP_REPEAT, 1, &s, &t, &w,
                               &w, avg, &alpha) != 0)
        return BUMP_HEIGHT; /* unreadable: the caller's texels are 0, flat either way */
    const float r = avg[0][0], g = avg[0][1], b = avg[0][2];
    int kind = texture_channels(e->ts, p->filename, p->encoding) >= 3 && b > 0.6f &&
                       fabsf(r - 0.5f) < 0.2f && fabsf(g - 0.5f) < 0.2f && b - fmaxf(r, g) > 0.15f
                   ? BUMP_NORMAL
                   : BUMP_HEIGHT;
    atomic_store_explicit(&mp->probed, kind, memory_order_relaxed);
    return kind;
}

/* imagemap channel -3 and -4, a bump slot's file read either way: -3 its
 * height (the first channel times scale; 0 for a normal map), -4 its
 * normal (the texels, their x and y about 0.5 times scale, the strength;
 * the flat (0.5, 0.5, 1) for a height map). out holds the texels. */
static void bump_texels(const Pattern *p, Eval *e, int ch, Rgb *out)
{
    int normal = bump_kind(p, e) == BUMP_NORMAL;
    for (size_t i = 0; i < e->ctx->n_points; i++) {
        if (ch == -3) {
            grey(out[i], normal ? 0.0f : p->num[0] * out[i][0]);
        } else if (!normal) {
            out[i][0] = out[i][1] = 0.5f, out[i][2] = 1.0f;
        } else {
            out[i][0] = 0.5f + p->num[0] * (out[i][0] - 0.5f);
            out[i][1] = 0.5f + p->num[0] * (out[i][1] - 0.5f);
        }
    }
}

static void eval_image(const Pattern *p, Eval *e, Rgb *out)
{
    size_t n = e->ctx->n_points;
    float s[PATTERN_CHUNK] = {0}, t[PATTERN_CHUNK] = {0}, ds[PATTERN_CHUNK] = {0},
          dt[PATTERN_CHUNK] = {0}, alpha[PATTERN_CHUNK];
    for (size_t i = 0; i < n; i++) {
        float u, v;
        uv_at(p, e, i, &u, &v, &ds[i], &dt[i]);
        s[i] = u, t[i] = 1.0f - v; /* images have (0, 0) at the top left */
    }
    if (!e->ts || texture_lookup_encoded(e->ts, p->filename, p->encoding,
                                         strcmp(p->wrap, "black") == 0   ? TEXTURE_WRAP_BLACK
                                         : strcmp(p->wrap, "clamp") == 0 ? TEXTURE_WRAP_CLAMP
                                                                         : TEXTURE_WRAP_REPEAT,
                                         n, s, t, ds, dt, out, alpha) != 0) {
        e->failed = 1;
        memset(out, 0, n * sizeof *out);
        for (size_t i = 0; i < n; i++)
            alpha[i] = 1.0f;
    }
    int ch = (int)p->num[2];
    if (ch == -3 || ch == -4) {
        bump_texels(p, e, ch, out);
        return;
    }
    if (ch == -2) { /* the matte: the alpha channel if the file has one, else the first;
                       a file that cannot be read, its alpha (1: opaque) */
        Pattern *mp = (Pattern *)p; /* the answer, kept once the file was read */
        int known = atomic_load_explicit(&mp->probed, memory_order_relaxed);
        int nc = known ? 0 : e->ts ? texture_channels(e->ts, p->filename, p->encoding) : 0;
        ch = known ? known - 1 : nc == 2 || nc >= 4 || nc == 0 ? 3 : 0;
        if (!known && nc > 0)
            atomic_store_explicit(&mp->probed, ch + 1, memory_order_relaxed);
    }
    for (size_t i = 0; i < n; i++) {
        if (ch >= 0)
            grey(out[i], ch == 3 ? alpha[i] : out[i][ch]);
        for (int c = 0; c < 3; c++) {
            float v = p->num[0] * out[i][c];
            out[i][c] = fmaxf(p->num[1] != 0.0f ? 1.0f - v : v, 0.0f);
        }
    }
}

/* The gradient of noise3 at q by forward differences (pbrt's DNoise). */
static void noise_gradient(const float q[3], float g[3])
{
    const float h = 0.01f;
    float n0 = noise3(q[0], q[1], q[2]);
    g[0] = (noise3(q[0] + h, q[1], q[2]) - n0) / h;
    g[1] = (noise3(q[0], q[1] + h, q[2]) - n0) / h;
    g[2] = (noise3(q[0], q[1], q[2] + h) - n0) / h;
}

/* pbrt-v4's cloud medium's density at medium-space point q, in [0, 1]:
 * five octaves of noise at the frequency, their lookup point stirred by
 * two octaves of the noise's gradient (wispiness), thinning with height
 * (y) and solid below y = 0.5 - 1/2 of the bottom. Every octave is
 * evaluated: a density is sampled at points, its footprint the march's. */
static float cloud_density(const Pattern *p, const float q[3])
{
    float density = p->num[0], wisp = p->num[1], freq = p->num[2];
    float pp[3] = {freq * q[0], freq * q[1], freq * q[2]};
    if (wisp > 0.0f) {
        float omega = 0.05f * wisp, lambda = 10.0f;
        for (int k = 0; k < 2; k++) {
            float at[3] = {lambda * pp[0], lambda * pp[1], lambda * pp[2]}, g[3];
            noise_gradient(at, g);
            for (int c = 0; c < 3; c++)
                pp[c] += omega * g[c];
            omega *= 0.5f;
            lambda *= NOISE_LACUNARITY;
        }
    }
    float d = 0.0f, omega = 0.5f, lambda = 1.0f;
    for (int k = 0; k < 5; k++) {
        d += omega * noise3(lambda * pp[0], lambda * pp[1], lambda * pp[2]);
        omega *= 0.5f;
        lambda *= NOISE_LACUNARITY;
    }
    d = fminf(fmaxf((1.0f - q[1]) * 4.5f * density * d, 0.0f), 1.0f);
    d += 2.0f * fmaxf(0.0f, 0.5f - q[1]);
    return fminf(fmaxf(d, 0.0f), 1.0f);
}

static void eval_noise(const Pattern *p, const Eval *e, Rgb *out)
{
    for (size_t i = 0; i < e->ctx->n_points; i++) {
        float q[3], dx[3], dy[3];
        point_at(p, e, i, q, dx, dy);
        if (p->kind == PK_FBM || p->kind == PK_WRINKLED) {
            grey(out[i], fractal(q, dx, dy, p->num[1], (int)p->num[0], p->kind == PK_WRINKLED));
        } else if (p->kind == PK_CLOUD) {
            grey(out[i], cloud_density(p, q));
        } else if (p->kind == PK_WINDY) {
            float q1[3], dx1[3], dy1[3];
            for (int k = 0; k < 3; k++)
                q1[k] = 0.1f * q[k], dx1[k] = 0.1f * dx[k], dy1[k] = 0.1f * dy[k];
            float strength = fractal(q1, dx1, dy1, 0.5f, 3, 0);
            grey(out[i], fabsf(strength) * fractal(q, dx, dy, 0.5f, 6, 0));
        } else {
            marble(p, q, dx, dy, out[i]);
        }
    }
}

/* A grid in texture space, grey. */
static void eval_grid(const Pattern *p, const Eval *e, Rgb *out)
{
    float q[PATTERN_CHUNK][3], v[PATTERN_CHUNK];
    for (size_t i = 0; i < e->ctx->n_points; i++) {
        float dx[3], dy[3];
        point_at(p, e, i, q[i], dx, dy);
    }
    grid_sample(p->grid, e->ctx->n_points, (const float(*)[3])q, v);
    for (size_t i = 0; i < e->ctx->n_points; i++)
        grey(out[i], v[i]);
}

static void eval_node(const Pattern *p, Eval *e, Rgb *out)
{
    size_t n = e->ctx->n_points;
    Rgb in[MAX_INPUTS][PATTERN_CHUNK];
    switch (p->kind) {
    case PK_CONSTANT:
        eval_input(&p->in[0], e, out);
        return;
    case PK_SCALE:
        eval_input(&p->in[0], e, out);
        eval_input(&p->in[1], e, in[1]);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                out[i][c] *= in[1][i][c];
        return;
    case PK_IMAGEMAP:
        eval_image(p, e, out);
        return;
    case PK_BILERP:
        for (int k = 0; k < 4; k++)
            eval_input(&p->in[k], e, in[k]);
        for (size_t i = 0; i < n; i++) {
            float u, v, du, dv;
            uv_at(p, e, i, &u, &v, &du, &dv);
            for (int c = 0; c < 3; c++) /* pbrt: v00 (0,0), v10 (1,0), v01 (0,1), v11 (1,1) */
                out[i][c] = (1 - u) * (1 - v) * in[0][i][c] + u * (1 - v) * in[2][i][c] +
                            (1 - u) * v * in[1][i][c] + u * v * in[3][i][c];
        }
        return;
    case PK_FBM:
    case PK_WRINKLED:
    case PK_WINDY:
    case PK_MARBLE:
    case PK_CLOUD:
        eval_noise(p, e, out);
        return;
    case PK_DENSITYGRID:
    case PK_NANOVDB:
        eval_grid(p, e, out);
        return;
    default: /* a weighted choice of tex1 and tex2 */
        eval_input(&p->in[0], e, in[0]);
        eval_input(&p->in[1], e, in[1]);
        if (p->kind == PK_MIX)
            eval_input(&p->in[2], e, in[2]);
        for (size_t i = 0; i < n; i++) {
            float w = weight_at(p, e, (const Rgb *)in[2], i);
            for (int c = 0; c < 3; c++)
                out[i][c] = w * in[0][i][c] + (1.0f - w) * in[1][i][c];
        }
        return;
    }
}

int pattern_eval(const Pattern *p, TextureSystem *ts, const RayesShadeCtx *ctx, const float *ds,
                 const float *dt, float (*out)[3])
{
    int failed = 0;
    for (size_t start = 0; start < ctx->n_points; start += PATTERN_CHUNK) {
        size_t n = ctx->n_points - start < PATTERN_CHUNK ? ctx->n_points - start : PATTERN_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        Eval e = {&sub, ds ? ds + start : NULL, dt ? dt + start : NULL, ts, 0};
        eval_node(p, &e, out + start);
        failed |= e.failed;
    }
    return failed ? -1 : 0;
}
