/*
 * scene/scene.c — rayes.h's scene calls. Each validates its arguments
 * (finite numbers, sane counts and indices) before changing anything, so a
 * failed call leaves the scene as it was, and records the first error.
 */
#include "scene/scene.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "util/check.h"

static RayesError fail(RayesScene *s, RayesError e, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static RayesError fail(RayesScene *s, RayesError e, const char *fmt, ...)
{
    if (s->error[0] == '\0') {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(s->error, sizeof s->error, fmt, ap);
        va_end(ap);
    }
    return e;
}

static int finite_n(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Grows *array (of *cap elements of size elem) to hold n + 1. */
static int grow(void **array, size_t *cap, size_t n, size_t elem)
{
    if (n < *cap)
        return 0;
    size_t c = *cap ? 2 * *cap : 16;
    void *p = realloc(*array, c * elem);
    if (!p)
        return -1;
    *array = p;
    *cap = c;
    return 0;
}

RayesScene *rayes_scene_new(void)
{
    RayesScene *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    atomic_init(&s->refs, 1);
    s->eye = v3(0, 0, -5);
    s->target = v3(0, 0, 0);
    s->up = v3(0, 1, 0);
    s->fov_y = 40.0f;
    s->world_from_object = mat4_identity();
    s->shading_rate = 1.0f;
    s->current_object = -1;
    return s;
}

void rayes_scene_retain(RayesScene *s)
{
    if (s)
        atomic_fetch_add(&s->refs, 1);
}

void rayes_scene_release(RayesScene *s)
{
    if (!s || atomic_fetch_sub(&s->refs, 1) != 1)
        return;
    for (size_t i = 0; i < s->n_objects; i++)
        if (s->objects[i].shader.cls)
            shade_instance_fini(&s->objects[i].shader);
    for (int k = 0; k < SCENE_N_PATH_KINDS; k++)
        free(s->search_path[k]);
    free(s->objects);
    free(s->prims);
    free(s->lights);
    free(s);
}

const char *rayes_scene_get_error(const RayesScene *s)
{
    return s ? s->error : "no scene";
}

void rayes_scene_clear_error(RayesScene *s)
{
    if (s)
        s->error[0] = '\0';
}

RayesError rayes_scene_set_camera(RayesScene *s, const float eye[3], const float target[3],
                                  const float up[3], float fov)
{
    if (!s || !eye || !target || !up)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!finite_n(eye, 3) || !finite_n(target, 3) || !finite_n(up, 3) || !(fov > 0.0f) ||
        !(fov < 180.0f))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                    "camera: expected finite vectors and a field of view in (0, 180) degrees");
    Vec3 f = v3_sub(v3_load(target), v3_load(eye));
    if (v3_length(f) <= 0.0f || v3_length(v3_cross(f, v3_load(up))) <= 0.0f)
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                    "camera: the eye equals the target, or up is parallel to the view");
    s->eye = v3_load(eye);
    s->target = v3_load(target);
    s->up = v3_load(up);
    s->fov_y = fov;
    s->dirty = 1;
    return RAYES_OK;
}

RayesError rayes_scene_set_transform(RayesScene *s, const float m[16])
{
    if (!s || !m)
        return RAYES_ERROR_INVALID_ARGUMENT;
    Mat4 inv;
    if (!finite_n(m, 16) || !mat4_invert(mat4_from_array(m), &inv))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                    "transform: expected a finite, invertible matrix");
    s->world_from_object = mat4_from_array(m);
    return RAYES_OK;
}

RayesError rayes_scene_set_shading_rate(RayesScene *s, float rate)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(rate > 0.0f) || !isfinite(rate))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "shading rate: expected a positive number");
    s->shading_rate = rate;
    return RAYES_OK;
}

/* Makes an object; the surface colour and opacity are taken from the
 * reserved parameters "Cs" and "Os" (RenderMan's Color and Opacity). */
static RayesError add_object(RayesScene *s, const RayesShaderClass *cls, const RayesParam *params,
                             size_t n_params, int light)
{
    if (grow((void **)&s->objects, &s->cap_objects, s->n_objects, sizeof *s->objects) != 0)
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    SceneObject *o = &s->objects[s->n_objects];
    memset(o, 0, sizeof *o);
    o->light = light;
    o->ray_mask = RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR |
                  (light >= 0 ? 0u : (uint32_t)RAYES_RAY_SHADOW);
    for (int c = 0; c < 3; c++)
        o->Cs[c] = o->Os[c] = 1.0f;
    RayesParam *rest = n_params ? malloc(n_params * sizeof *rest) : NULL;
    size_t n_rest = 0;
    if (n_params && !rest)
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < n_params; i++) {
        float *dst = strcmp(params[i].name, "Cs") == 0   ? o->Cs
                     : strcmp(params[i].name, "Os") == 0 ? o->Os
                                                         : NULL;
        if (!dst) {
            rest[n_rest++] = params[i];
            continue;
        }
        int single = params[i].type == RAYES_PARAM_FLOAT;
        for (int c = 0; c < 3; c++)
            dst[c] = params[i].value[single ? 0 : c];
    }
    char err[256];
    if (cls && shade_instance_init(&o->shader, cls, rest, n_rest, err, sizeof err) != 0) {
        free(rest);
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "%s", err);
    }
    free(rest);
    s->current_object = light >= 0 ? s->current_object : (int64_t)s->n_objects;
    s->n_objects++;
    s->dirty = 1;
    return RAYES_OK;
}

RayesError rayes_scene_set_shader(RayesScene *s, const char *name, const RayesParam *params,
                                  size_t n_params)
{
    if (!s || !name || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    const RayesShaderClass *cls = shade_find_class(name);
    if (!cls)
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "unknown shader \"%s\"", name);
    for (size_t i = 0; i < n_params; i++) {
        if (!params[i].name)
            return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "shader \"%s\": a parameter has no name",
                        name);
        if (params[i].type != RAYES_PARAM_STRING && !finite_n(params[i].value, 3))
            return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                        "shader \"%s\": parameter \"%s\" is not finite", name, params[i].name);
    }
    return add_object(s, cls, params, n_params, -1);
}

static RayesError add_prim(RayesScene *s, Prim *p)
{
    if (s->current_object < 0) {
        RayesError e = rayes_scene_set_shader(s, "matte", NULL, 0);
        if (e != RAYES_OK)
            return e;
    }
    if (grow((void **)&s->prims, &s->cap_prims, s->n_prims, sizeof *s->prims) != 0)
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    p->object = (uint32_t)s->current_object;
    p->shading_rate = s->shading_rate;
    s->prims[s->n_prims++] = *p;
    s->dirty = 1;
    return RAYES_OK;
}

static void transform_points(const RayesScene *s, const float (*P)[3], size_t n, Vec3 *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = mat4_point(&s->world_from_object, v3_load(P[i]));
}

RayesError rayes_scene_bilinear_patch(RayesScene *s, const float P[4][3])
{
    if (!s || !P)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!finite_n(&P[0][0], 12))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "bilinear patch: non-finite point");
    Prim p = {.type = PRIM_BILINEAR};
    transform_points(s, P, 4, p.cp);
    return add_prim(s, &p);
}

RayesError rayes_scene_bicubic_patch(RayesScene *s, const float P[16][3])
{
    if (!s || !P)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!finite_n(&P[0][0], 48))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "bicubic patch: non-finite point");
    Prim p = {.type = PRIM_BICUBIC};
    transform_points(s, P, 16, p.cp);
    return add_prim(s, &p);
}

RayesError rayes_scene_polygon_mesh(RayesScene *s, size_t n_faces, const int *n_verts,
                                    const int *indices, size_t n_points, const float *P)
{
    if (!s || (n_faces && (!n_verts || !indices || !P)))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!finite_n(P, 3 * n_points))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "polygon mesh: non-finite point");
    size_t k = 0;
    for (size_t f = 0; f < n_faces; f++) {
        if (n_verts[f] != 3 && n_verts[f] != 4)
            return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                        "polygon mesh: face %zu has %d vertices; expected 3 or 4", f, n_verts[f]);
        for (int v = 0; v < n_verts[f]; v++)
            if (indices[k + (size_t)v] < 0 || (size_t)indices[k + (size_t)v] >= n_points)
                return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                            "polygon mesh: face %zu uses vertex %d; expected 0 to %zu", f,
                            indices[k + (size_t)v], n_points ? n_points - 1 : 0);
        k += (size_t)n_verts[f];
    }
    k = 0;
    for (size_t f = 0; f < n_faces; f++) {
        const float(*pts)[3] = (const float(*)[3])P;
        const int *ix = indices + k;
        Prim p = {.type = n_verts[f] == 3 ? PRIM_TRIANGLE : PRIM_BILINEAR};
        if (n_verts[f] == 3) {
            for (int v = 0; v < 3; v++)
                transform_points(s, &pts[ix[v]], 1, &p.cp[v]);
        } else {
            /* Polygon order v0 v1 v2 v3 -> bilinear P00 = v0, P10 = v1, P01 = v3, P11 = v2. */
            static const int order[4] = {0, 1, 3, 2};
            for (int v = 0; v < 4; v++)
                transform_points(s, &pts[ix[order[v]]], 1, &p.cp[v]);
        }
        RayesError e = add_prim(s, &p);
        if (e != RAYES_OK)
            return e;
        k += (size_t)n_verts[f];
    }
    return RAYES_OK;
}

RayesError rayes_scene_sphere(RayesScene *s, float radius)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(radius > 0.0f) || !isfinite(radius))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "sphere: expected a positive radius");
    Prim p = {.type = PRIM_SPHERE};
    Mat4 inv;
    mat4_invert(s->world_from_object, &inv);
    p.sphere.world_from_object = s->world_from_object;
    p.sphere.normal_from_object = mat4_transpose(inv);
    p.sphere.radius = radius;
    return add_prim(s, &p);
}

RayesError rayes_scene_area_light(RayesScene *s, const float P[4][3], const float L[3])
{
    if (!s || !P || !L)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!finite_n(&P[0][0], 12) || !finite_n(L, 3) || L[0] < 0 || L[1] < 0 || L[2] < 0)
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                    "area light: expected finite points and a non-negative radiance");
    if (grow((void **)&s->lights, &s->cap_lights, s->n_lights, sizeof *s->lights) != 0)
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    Light *l = &s->lights[s->n_lights];
    Vec3 v[4];
    transform_points(s, P, 4, v);
    l->P[0] = v[0];
    l->P[1] = v[1];
    l->P[2] = v[3];
    l->P[3] = v[2];
    l->L = v3_load(L);
    Vec3 n;
    Vec3 c;
    light_quad_eval(l, 0.5f, 0.5f, &c, &n);
    if (!(v3_length(n) > 0.0f))
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT, "area light: the quad has no area");
    int64_t keep = s->current_object;
    RayesError e = add_object(s, NULL, NULL, 0, (int)s->n_lights);
    if (e != RAYES_OK)
        return e;
    s->n_lights++;
    Prim p = {.type = PRIM_BILINEAR, .object = (uint32_t)(s->n_objects - 1),
              .shading_rate = s->shading_rate};
    memcpy(p.cp, l->P, sizeof l->P);
    if (grow((void **)&s->prims, &s->cap_prims, s->n_prims, sizeof *s->prims) != 0)
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->prims[s->n_prims++] = p;
    s->current_object = keep;
    return RAYES_OK;
}

static const char *const path_kinds[SCENE_N_PATH_KINDS] = {
    [SCENE_PATH_TEXTURE] = "texture",
};

const char *scene_path_kind_name(ScenePathKind kind)
{
    return kind < SCENE_N_PATH_KINDS ? path_kinds[kind] : "";
}

RayesError rayes_scene_set_search_path(RayesScene *s, const char *kind, const char *path)
{
    if (!s || !kind)
        return RAYES_ERROR_INVALID_ARGUMENT;
    int k = 0;
    while (k < SCENE_N_PATH_KINDS && strcmp(kind, path_kinds[k]) != 0)
        k++;
    if (k == SCENE_N_PATH_KINDS)
        return fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                    "search path: unknown kind \"%s\" (expected \"texture\")", kind);
    char *copy = NULL;
    if (path && path[0] && !(copy = strdup(path)))
        return fail(s, RAYES_ERROR_OUT_OF_MEMORY, "search path: out of memory");
    free(s->search_path[k]);
    s->search_path[k] = copy;
    s->dirty = 1;
    return RAYES_OK;
}

RayesError rayes_scene_commit(RayesScene *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    s->timestamp++;
    s->dirty = 0;
    return RAYES_OK;
}

uint64_t rayes_scene_get_timestamp(const RayesScene *s)
{
    return s ? s->timestamp : 0;
}

Bounds3 scene_bounds(const RayesScene *s)
{
    Bounds3 b = bounds_empty();
    for (size_t i = 0; i < s->n_prims; i++) {
        const Prim *p = &s->prims[i];
        if (p->type == PRIM_SPHERE) {
            Vec3 c = mat4_point(&p->sphere.world_from_object, v3(0, 0, 0));
            float r = p->sphere.radius;
            for (int k = 0; k < 3; k++) {
                Vec3 axis = mat4_vector(&p->sphere.world_from_object,
                                        v3(k == 0 ? r : 0, k == 1 ? r : 0, k == 2 ? r : 0));
                float l = v3_length(axis);
                b = bounds_add(b, v3_add(c, v3(l, l, l)));
                b = bounds_add(b, v3_sub(c, v3(l, l, l)));
            }
            continue;
        }
        int n = p->type == PRIM_BICUBIC ? 16 : p->type == PRIM_TRIANGLE ? 3 : 4;
        for (int k = 0; k < n; k++)
            b = bounds_add(b, p->cp[k]);
    }
    return b;
}

int scene_prepare(const RayesScene *s, int height, GridSet *gs)
{
    DiceCamera cam;
    Bounds3 b = scene_bounds(s);
    float radius = s->n_prims ? 0.5f * v3_length(v3_sub(b.hi, b.lo)) : 1.0f;
    cam.eye = s->eye;
    cam.pixel_angle = 2.0f * tanf(0.5f * s->fov_y * (float)(M_PI / 180.0)) / (float)height;
    cam.min_distance = 1e-3f * fmaxf(radius, 1e-6f);
    for (size_t i = 0; i < s->n_prims; i++)
        if (geom_dice_prim(gs, &s->prims[i], (uint32_t)i, &cam) != 0)
            return -1;
    return 0;
}
