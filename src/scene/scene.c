/*
 * scene/scene.c — rayes.h's scene calls. Each validates its arguments
 * (finite numbers, sane counts and indices) before changing anything, so a
 * failed call leaves the scene as it was, and records the first error.
 */
#include "scene/scene.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/subdiv.h"
#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "shade/builtin.h"
#include "shade/registry.h"
#include "util/check.h"
#include "util/grow.h"
#include "util/log.h"

/* The camera of rayes_scene_set_camera: an orthonormal frame looking from
 * eye at target, the fov spanning the image height. */
static void look_at(SceneCamera *c, const float eye[3], const float target[3], const float up[3],
                    float fov)
{
    c->eye = v3_load(eye);
    c->z = v3_normalize(v3_sub(v3_load(target), c->eye));
    c->x = v3_normalize(v3_cross(c->z, v3_load(up)));
    c->y = v3_cross(c->x, c->z);
    c->tan_half_fov = tanf(0.5f * fov * (float)(M_PI / 180.0));
    c->fov_vertical = 1;
    c->has_screen = 0;
}

RayesScene *rayes_scene_new(void)
{
    RayesScene *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    atomic_init(&s->refs, 1);
    static const float eye[3] = {0, 0, -5}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    look_at(&s->camera, eye, target, up, 40.0f);
    s->world_from_object = mat4_identity();
    s->shading_rate = 1.0f;
    s->current_object = -1;
    s->last_geometry_object = -1;
    s->current_visibility =
        RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR | RAYES_RAY_SHADOW;
    s->current_opacity_cache = 1;
    s->open_master = -1;
    s->open_solid = -1;
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
    for (size_t i = 0; i < s->n_displacements; i++)
        shade_instance_fini(&s->displacements[i]);
    free(s->displacements);
    for (size_t i = 0; i < s->n_links; i++)
        free(s->links[i].lights);
    free(s->links);
    free(s->objects);
    free(s->solids);
    free(s->prims);
    for (size_t i = 0; i < s->cap_bigs; i++)
        free(s->bigs[i]);
    free(s->bigs);
    free(s->motions);
    free(s->motion_prims);
    for (size_t i = 0; i < s->n_subdivs; i++)
        geom_subdiv_free(s->subdivs[i]);
    free(s->subdivs);
    free(s->pv);
    for (size_t i = 0; i < s->n_lights; i++)
        light_fini(&s->lights[i]);
    free(s->lights);
    free(s->volumes);
    for (int k = 0; k < SCENE_SEARCH_PATH_COUNT; k++)
        free(s->search_paths[k]);
    scene_patterns_free(s);
    for (size_t i = 0; i < s->n_masters; i++)
        free(s->masters[i].name);
    free(s->masters);
    free(s->instances);
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
    if (!scene_finite(eye, 3) || !scene_finite(target, 3) || !scene_finite(up, 3) ||
        !(fov > 0.0f) || !(fov < 180.0f))
        return scene_fail(
            s, RAYES_ERROR_INVALID_ARGUMENT,
            "camera: expected finite vectors and a field of view in (0, 180) degrees");
    Vec3 f = v3_sub(v3_load(target), v3_load(eye));
    if (v3_length(f) <= 0.0f || v3_length(v3_cross(f, v3_load(up))) <= 0.0f)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "camera: the eye equals the target, or up is parallel to the view");
    look_at(&s->camera, eye, target, up, fov);
    s->camera.n_motion = 0; /* a still camera now: set_camera_motion comes after */
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

RayesError rayes_scene_set_camera_matrix(RayesScene *s, const float m[16], RayesProjection proj,
                                         float fov, const float screen[4])
{
    if (!s || !m)
        return RAYES_ERROR_INVALID_ARGUMENT;
    Mat4 world_from_camera;
    if (!scene_finite(m, 16) || !mat4_invert(mat4_from_array(m), &world_from_camera))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "camera: expected a finite, invertible camera_from_world matrix");
    if (proj != RAYES_PROJECTION_PERSPECTIVE && proj != RAYES_PROJECTION_ORTHOGRAPHIC)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "camera: expected a perspective or orthographic projection");
    if (proj == RAYES_PROJECTION_PERSPECTIVE && !(fov > 0.0f && fov < 180.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "camera: expected a field of view in (0, 180) degrees");
    if (screen &&
        (!scene_finite(screen, 4) || !(screen[1] != screen[0]) || !(screen[3] != screen[2])))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "camera: expected a screen window of nonzero width and height");
    SceneCamera *c = &s->camera;
    c->eye = mat4_point(&world_from_camera, v3(0, 0, 0));
    c->x = mat4_vector(&world_from_camera, v3(1, 0, 0));
    c->y = mat4_vector(&world_from_camera, v3(0, 1, 0));
    c->z = mat4_vector(&world_from_camera, v3(0, 0, 1));
    c->tan_half_fov = proj == RAYES_PROJECTION_PERSPECTIVE
                          ? tanf(0.5f * fov * (float)(M_PI / 180.0))
                          : 0.0f;
    c->fov_vertical = 0;
    c->n_motion = 0; /* a still camera now: set_camera_motion comes after */
    c->has_screen = screen != NULL;
    if (screen)
        memcpy(c->screen, screen, sizeof c->screen);
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

void scene_camera_screen(const SceneCamera *c, int width, int height, float screen[4])
{
    if (c->has_screen) {
        memcpy(screen, c->screen, 4 * sizeof *screen);
        return;
    }
    float a = (float)width / (float)height;
    if (a >= 1.0f || c->fov_vertical) {
        screen[0] = -a, screen[1] = a, screen[2] = -1.0f, screen[3] = 1.0f;
    } else {
        screen[0] = -1.0f, screen[1] = 1.0f, screen[2] = -1.0f / a, screen[3] = 1.0f / a;
    }
}

RayesError rayes_scene_set_transform(RayesScene *s, const float m[16])
{
    if (!s || !m)
        return RAYES_ERROR_INVALID_ARGUMENT;
    Mat4 inv;
    if (!scene_finite(m, 16) || !mat4_invert(mat4_from_array(m), &inv))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "transform: expected a finite, invertible matrix");
    if (!scene_affine(m))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, AFFINE_EXPECTED, "transform");
    s->world_from_object = scene_unit_w(m);
    s->current_motion = 0;
    return RAYES_OK;
}

RayesError rayes_scene_set_visibility(RayesScene *s, uint32_t ray_types)
{
    const uint32_t known = RAYES_RAY_CAMERA | RAYES_RAY_SHADOW | RAYES_RAY_DIFFUSE |
                           RAYES_RAY_SPECULAR | RAYES_RAY_TRANSMISSION;
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (ray_types & ~known)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "visibility: expected camera, shadow, diffuse, specular and transmission "
                          "ray bits only");
    /* Shadow and transmission rays are one kind to the tracer. */
    if (ray_types & RAYES_RAY_TRANSMISSION)
        ray_types = (ray_types & ~(uint32_t)RAYES_RAY_TRANSMISSION) | RAYES_RAY_SHADOW;
    s->current_visibility = ray_types;
    return RAYES_OK;
}

RayesError rayes_scene_set_opacity_mode(RayesScene *s, RayesTransmissionHitMode mode, int cache)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (mode != RAYES_TRANSMISSION_SHADER && mode != RAYES_TRANSMISSION_PRIMITIVE)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "opacity mode: expected RAYES_TRANSMISSION_SHADER or _PRIMITIVE");
    s->current_hitmode = (uint8_t)mode;
    s->current_opacity_cache = cache != 0;
    return RAYES_OK;
}

RayesError rayes_scene_set_shading_rate(RayesScene *s, float rate)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(rate > 0.0f) || !isfinite(rate))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "shading rate: expected a positive number");
    s->shading_rate = rate;
    return RAYES_OK;
}

/* Makes an object; the surface colour and opacity are taken from the
 * reserved parameters "Cs" and "Os" (RenderMan's Color and Opacity). */
static RayesError find_shader(RayesScene *s, const char *name, const RayesShaderClass **cls,
                              int record);

#define MIX_MAX_DEPTH 8 /* mixes of mixes, at most */

/* An instance of cls with params (their patterns bound). A class with
 * children (mix) takes its own parameters here, and makes its two
 * materials of the classes its "a" and "b" name, each with the parameters
 * "a:NAME" (or "b:NAME") as NAME, mixes among them down to MIX_MAX_DEPTH.
 * On failure nothing is left made. */
static RayesError make_instance(RayesScene *s, const RayesShaderClass *cls,
                                const RayesParam *params, size_t n, ShaderInstance *inst, int depth)
{
    int mix = (shade_class_flags(cls) & SHADE_CLASS_CHILDREN) != 0;
    RayesParam *own = malloc((n ? n : 1) * sizeof *own);
    if (!own)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    size_t n_own = 0;
    for (size_t i = 0; i < n; i++)
        if (!mix || !(params[i].name[0] && params[i].name[1] == ':'))
            own[n_own++] = params[i];
    char err[256];
    if (shade_instance_init(inst, cls, own, n_own, err, sizeof err) != 0) {
        free(own);
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "%s", err);
    }
    RayesError e = scene_bind_patterns(s, inst, own, n_own);
    ShaderInstance *ch = mix && e == RAYES_OK ? calloc(2, sizeof *ch) : NULL;
    if (mix && e == RAYES_OK && !ch)
        e = scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    if (mix && e == RAYES_OK && depth >= MIX_MAX_DEPTH)
        e = scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "mix: nested more than %d deep",
                       MIX_MAX_DEPTH);
    int made = 0;
    for (int k = 0; k < 2 && ch && e == RAYES_OK; k++) {
        const char key[2] = {(char)('a' + k), '\0'};
        const char *cname = NULL;
        n_own = 0;
        for (size_t i = 0; i < n; i++) {
            const char *nm = params[i].name;
            if (strcmp(nm, key) == 0 && params[i].type == RAYES_PARAM_STRING)
                cname = params[i].string;
            else if (nm[0] == key[0] && nm[1] == ':') {
                own[n_own] = params[i];
                own[n_own++].name = nm + 2;
            }
        }
        const RayesShaderClass *ccls = NULL;
        if (!cname || !cname[0])
            e = scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                           "mix: expected \"string %s\" naming the class of its material %s", key,
                           key);
        else
            e = find_shader(s, cname, &ccls, 1);
        if (e == RAYES_OK)
            e = make_instance(s, ccls, own, n_own, &ch[k], depth + 1);
        made += e == RAYES_OK;
    }
    free(own);
    if (e != RAYES_OK) {
        for (int k = 0; k < made; k++)
            shade_instance_fini(&ch[k]);
        free(ch);
        shade_instance_fini(inst);
        return e;
    }
    if (ch)
        shade_instance_adopt(inst, ch, 2);
    return RAYES_OK;
}

static RayesError add_object(RayesScene *s, const RayesShaderClass *cls, const RayesParam *params,
                             size_t n_params, int light)
{
    if (util_grow((void **)&s->objects, &s->cap_objects, s->n_objects, sizeof *s->objects) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    SceneObject *o = &s->objects[s->n_objects];
    memset(o, 0, sizeof *o);
    o->light = light;
    o->links = s->current_links;
    o->ray_mask = s->current_visibility & ~(light >= 0 ? (uint32_t)RAYES_RAY_SHADOW : 0u);
    o->transmission_hitmode = s->current_hitmode;
    o->opacity_cache = s->current_opacity_cache;
    for (int c = 0; c < 3; c++)
        o->Cs[c] = o->Os[c] = 1.0f;
    RayesParam *rest = n_params ? malloc(n_params * sizeof *rest) : NULL;
    size_t n_rest = 0;
    if (n_params && !rest)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < n_params; i++) {
        if (strcmp(params[i].name, "Os") == 0 && params[i].type == RAYES_PARAM_PATTERN) {
            o->Os_pattern = scene_find_pattern(s, params[i].string);
            if (!o->Os_pattern) {
                free(rest);
                return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                  "Os: names no pattern (\"%.64s\")",
                                  params[i].string ? params[i].string : "");
            }
            continue;
        }
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
    RayesError made = cls ? make_instance(s, cls, rest, n_rest, &o->shader, 0) : RAYES_OK;
    free(rest);
    if (made != RAYES_OK)
        return made;
    s->current_object = light >= 0 ? s->current_object : (int64_t)s->n_objects;
    s->n_objects++;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

/* Checks a shader call's parameters: named and finite. */
static RayesError check_params(RayesScene *s, const char *what, const char *name,
                               const RayesParam *params, size_t n_params)
{
    for (size_t i = 0; i < n_params; i++) {
        if (!params[i].name)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s \"%s\": a parameter has no name",
                              what, name);
        if (params[i].type != RAYES_PARAM_STRING && params[i].type != RAYES_PARAM_PATTERN &&
            !scene_finite(params[i].value, 3))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s \"%s\": parameter \"%s\" is not finite", what, name,
                              params[i].name);
    }
    return RAYES_OK;
}

/* Sets *cls to a built-in class, else a plugin from the scene's shader
 * search path and then $RAYES_SHADER_PATH. Returns RAYES_OK, or an error
 * recorded in the scene when record is set. */
static RayesError find_shader(RayesScene *s, const char *name, const RayesShaderClass **cls,
                              int record)
{
    *cls = shade_find_class(name);
    if (*cls)
        return RAYES_OK;
    const char *mine = scene_search_path(s, SCENE_SEARCH_PATH_SHADER);
    const char *env = getenv("RAYES_SHADER_PATH");
    size_t len = strlen(mine) + (env ? strlen(env) : 0) + 2;
    char *path = malloc(len), err[512];
    if (!path)
        return record ? scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory")
                      : RAYES_ERROR_OUT_OF_MEMORY;
    snprintf(path, len, "%s:%s", mine, env ? env : "");
    *cls = shade_find_class_on_path(name, path, err, sizeof err);
    free(path);
    if (*cls)
        return RAYES_OK;
    return record ? scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s", err)
                  : RAYES_ERROR_INVALID_ARGUMENT;
}

int rayes_scene_has_shader(RayesScene *s, const char *name)
{
    const RayesShaderClass *cls;
    return s && name && name[0] && find_shader(s, name, &cls, 0) == RAYES_OK;
}

RayesError rayes_scene_set_shader(RayesScene *s, const char *name, const RayesParam *params,
                                  size_t n_params)
{
    if (!s || !name || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    const RayesShaderClass *cls;
    RayesError e = find_shader(s, name, &cls, 1);
    if (e != RAYES_OK)
        return e;
    e = check_params(s, "shader", name, params, n_params);
    if (e != RAYES_OK)
        return e;
    return add_object(s, cls, params, n_params, -1);
}

RayesError rayes_scene_set_displacement(RayesScene *s, const char *name, const RayesParam *params,
                                        size_t n_params)
{
    if (!s || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!name || !name[0]) {
        s->current_displacement = 0;
        return RAYES_OK;
    }
    const RayesShaderClass *cls;
    RayesError e = find_shader(s, name, &cls, 1);
    if (e != RAYES_OK)
        return e;
    if (!cls->displacement)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "shader \"%s\" has no displacement method", name);
    /* "__bump" 1: the displaced surface's normal bends the shading normal,
     * and the surface stays where it is (a bump map) */
    int bump = 0;
    RayesParam own[64];
    size_t n_own = 0;
    for (size_t i = 0; i < n_params; i++) {
        if (params[i].name && strcmp(params[i].name, "__bump") == 0 &&
            params[i].type == RAYES_PARAM_FLOAT)
            bump = params[i].value[0] != 0.0f;
        else if (n_own < sizeof own / sizeof own[0])
            own[n_own++] = params[i];
        else
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "displacement shader \"%s\": more than 64 parameters", name);
    }
    params = own, n_params = n_own;
    e = check_params(s, "displacement shader", name, params, n_params);
    if (e != RAYES_OK)
        return e;
    if (util_grow((void **)&s->displacements, &s->cap_displacements, s->n_displacements,
                  sizeof *s->displacements) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    char err[256];
    ShaderInstance *inst = &s->displacements[s->n_displacements];
    if (shade_instance_init(inst, cls, params, n_params, err, sizeof err) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "%s", err);
    e = scene_bind_patterns(s, inst, params, n_params);
    if (e != RAYES_OK) {
        shade_instance_fini(inst);
        return e;
    }
    inst->bump = bump;
    s->current_displacement = (uint32_t)++s->n_displacements;
    return RAYES_OK;
}

RayesError rayes_scene_set_displacement_bound(RayesScene *s, float bound)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(bound >= 0.0f) || !isfinite(bound))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "displacement bound: expected a finite number >= 0");
    s->displacement_bound = bound;
    return RAYES_OK;
}

RayesError rayes_scene_solid_begin(RayesScene *s, RayesSolidOp op)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if ((unsigned)op > RAYES_SOLID_DIFFERENCE)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "solid: unknown operation %d", (int)op);
    if (s->open_solid >= 0 && s->solids[s->open_solid].op == GEOM_SOLID_PRIMITIVE)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "solid: a solid inside a primitive solid (only primitives may be)");
    if (s->n_solids >= UINT32_MAX - 1)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "solid: too many solids");
    if (util_grow((void **)&s->solids, &s->cap_solids, s->n_solids, sizeof *s->solids) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->solids[s->n_solids] = (GeomSolid){(uint32_t)op, (uint32_t)(s->open_solid + 1), 0};
    s->open_solid = (int64_t)s->n_solids++;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

RayesError rayes_scene_solid_end(RayesScene *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->open_solid < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "solid: an end without a begin");
    GeomSolid *g = &s->solids[s->open_solid];
    g->end = (uint32_t)s->n_solids;
    s->open_solid = (int64_t)g->parent - 1;
    return RAYES_OK;
}

#define SCENE_BIG_BLOCK 1024

/* Copies what p->big points to into the scene's arena (blocks never move,
 * so copies of the Prim share it) and points p there. */
static RayesError intern_big(RayesScene *s, Prim *p)
{
    if (!p->big)
        return RAYES_OK;
    size_t block = s->n_bigs / SCENE_BIG_BLOCK;
    if (block == s->cap_bigs) {
        PrimBig **bigs = realloc(s->bigs, (block + 1) * sizeof *bigs);
        if (!bigs)
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
        s->bigs = bigs;
        if (!(bigs[block] = malloc(SCENE_BIG_BLOCK * sizeof *bigs[block])))
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
        s->cap_bigs++;
    }
    PrimBig *to = &s->bigs[block][s->n_bigs++ % SCENE_BIG_BLOCK];
    *to = *p->big;
    p->big = to;
    return RAYES_OK;
}

static RayesError add_prim(RayesScene *s, Prim *p)
{
    /* a subdivision patch's points were checked with its mesh's */
    if (p->type != PRIM_SUBDIV && !scene_within(scene_prim_bounds(p)))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, WITHIN_EXPECTED, "primitive");
    if (s->current_object == -1) {
        RayesError e = rayes_scene_set_shader(s, "matte", NULL, 0);
        if (e != RAYES_OK)
            return e;
    }
    if (util_grow((void **)&s->prims, &s->cap_prims, s->n_prims, sizeof *s->prims) != 0 ||
        intern_big(s, p) != RAYES_OK)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    p->object = s->current_object == SCENE_OBJECT_INHERIT ? GEOM_OBJECT_INHERIT
                                                          : (uint32_t)s->current_object;
    s->last_geometry_object = s->current_object == SCENE_OBJECT_INHERIT ? -1 : s->current_object;
    p->master = s->open_master >= 0 ? (uint32_t)s->open_master + 1 : 0;
    p->solid = 0;
    if (s->open_solid >= 0 && p->master == 0) {
        if (s->solids[s->open_solid].op == GEOM_SOLID_PRIMITIVE)
            p->solid = (uint32_t)s->open_solid + 1;
        else
            log_warning_once("solid loose", "a primitive in a boolean solid but in no primitive "
                                            "solid is drawn as it is (not part of the solid)");
    } else if (s->open_solid >= 0) {
        log_warning_once("solid master", "solids inside object definitions are drawn as their "
                                         "primitives (not combined)");
    }
    if ((p->pv & GEOM_PV_OS) && s->pv_Os_below_1) {
        if (p->object != GEOM_OBJECT_INHERIT)
            s->objects[p->object].Os_primvar_below_1 = 1;
        else if (p->master) /* the objects of its block's instances (object_instance) */
            s->masters[p->master - 1].inherit_Os_below_1 = 1;
    }
    p->shading_rate = s->shading_rate;
    p->motion = s->current_motion;
    p->motionfactor = s->motionfactor;
    p->focusfactor = s->focusfactor;
    p->displacement = s->current_displacement;
    p->displacement_bound = s->displacement_bound;
    s->prims[s->n_prims++] = *p;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

void scene_note_Os(RayesScene *s, const float *Os, size_t n)
{
    s->pv_Os_below_1 = 0;
    for (size_t i = 0; Os && i < 3 * n; i++)
        if (Os[i] < 1.0f)
            s->pv_Os_below_1 = 1;
}

/* Room for n more floats in the primitive variable pool. */
static RayesError reserve_pv(RayesScene *s, size_t n)
{
    if (s->n_pv + n <= s->cap_pv)
        return RAYES_OK;
    size_t cap = s->cap_pv ? s->cap_pv : 1024;
    while (cap < s->n_pv + n)
        cap *= 2;
    float *pv = realloc(s->pv, cap * sizeof *pv);
    if (!pv)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->pv = pv;
    s->cap_pv = cap;
    return RAYES_OK;
}

RayesError scene_add_prim(RayesScene *s, Prim *p)
{
    return add_prim(s, p);
}

RayesError scene_push_values(RayesScene *s, Prim *p, unsigned mask, const float *values,
                             size_t n)
{
    p->pv = (uint8_t)mask;
    p->pv_cubic = 0;
    p->pv_first = s->n_pv;
    if (reserve_pv(s, n) != RAYES_OK)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(s->pv + s->n_pv, values, n * sizeof *values);
    s->n_pv += n;
    return RAYES_OK;
}

/* The bounds of the n points at xyz (three floats each). */
static Bounds3 bounds_of(const float *xyz, size_t n)
{
    Bounds3 b = bounds_empty();
    for (size_t i = 0; i < n; i++)
        b = bounds_add(b, v3_load(xyz + 3 * i));
    return b;
}

static void transform_points(const RayesScene *s, const float (*P)[3], size_t n, Vec3 *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = mat4_point(&s->world_from_object, v3_load(P[i]));
}

/* ------------------------------------------------- primitive variables */

/* The variables rayes.h's RayesPrimvar names, in GEOM_PV_* bit order. */
static const struct {
    const char *name;
    unsigned bit;
    int size; /* floats per value */
} primvar_names[GEOM_N_PV] = {
    {"N", GEOM_PV_N, 3}, {"st", GEOM_PV_ST, 2}, {"Cs", GEOM_PV_CS, 3}, {"Os", GEOM_PV_OS, 3}};

static const char *const primvar_class_names[5] = {"constant", "uniform", "varying", "vertex",
                                                   "facevarying"};

/* A call's primitive variables, checked: by[b] is the one named
 * primvar_names[b].name, or NULL. */
typedef struct PrimvarSet {
    const RayesPrimvar *by[GEOM_N_PV];
    unsigned mask;            /* GEOM_PV_* bits given */
    Mat4 normal_from_object;  /* for N: the inverse transpose of world_from_object */
} PrimvarSet;

/* Checks pv against the counts each class needs (expect[cls]) and fills
 * set. what names the call in messages. */
static RayesError check_primvars(RayesScene *s, const char *what, const RayesPrimvar *pv,
                                 size_t n_pv, const size_t expect[5], PrimvarSet *set)
{
    memset(set, 0, sizeof *set);
    if (n_pv && !pv)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: primitive variables are NULL",
                          what);
    for (size_t i = 0; i < n_pv; i++) {
        int b = 0;
        while (b < GEOM_N_PV && !(pv[i].name && strcmp(pv[i].name, primvar_names[b].name) == 0))
            b++;
        if (b == GEOM_N_PV)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: unknown primitive variable \"%.64s\"; expected N, st, Cs or Os",
                              what, pv[i].name ? pv[i].name : "(null)");
        if (set->by[b])
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s given twice", what, pv[i].name);
        if ((unsigned)pv[i].cls > RAYES_PRIMVAR_FACEVARYING)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s has class %d", what, pv[i].name,
                              (int)pv[i].cls);
        size_t want = expect[pv[i].cls];
        if (pv[i].count != want)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: %s %s has %zu values; expected %zu", what,
                              primvar_class_names[pv[i].cls], pv[i].name, pv[i].count, want);
        if (want && !pv[i].data)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s has no data", what, pv[i].name);
        if (!scene_finite(pv[i].data, want * (size_t)primvar_names[b].size))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s has a non-finite value", what, pv[i].name);
        set->by[b] = &pv[i];
        set->mask |= primvar_names[b].bit;
    }
    const RayesPrimvar *Os = set->by[GEOM_N_PV - 1];
    scene_note_Os(s, Os ? Os->data : NULL, Os ? Os->count : 0);
    Mat4 inv;
    mat4_invert(s->world_from_object, &inv);
    set->normal_from_object = mat4_transpose(inv);
    return RAYES_OK;
}

/* Where one control value of a primitive comes from: its face, its corner
 * among all face corners, its point. */
typedef struct PrimvarSource {
    size_t face, corner, point;
} PrimvarSource;

static size_t primvar_index(RayesPrimvarClass cls, PrimvarSource src)
{
    switch (cls) {
    case RAYES_PRIMVAR_CONSTANT: return 0;
    case RAYES_PRIMVAR_UNIFORM: return src.face;
    case RAYES_PRIMVAR_FACEVARYING: return src.corner;
    default: return src.point; /* varying, vertex */
    }
}

/* Appends prim p's values to the pool: per variable of set (bit order),
 * n values, the k-th taken from src[k] (or, when the variable is in cubic,
 * its 16 values in order). Sets p's pv fields. */
static RayesError push_primvars(RayesScene *s, Prim *p, const PrimvarSet *set,
                                const PrimvarSource *src, int n, unsigned cubic)
{
    p->pv = (uint8_t)set->mask;
    p->pv_cubic = (uint8_t)(set->mask & cubic);
    p->pv_first = s->n_pv;
    if (!set->mask)
        return RAYES_OK;
    size_t need = 0;
    for (int b = 0; b < GEOM_N_PV; b++)
        if (set->by[b])
            need += (size_t)((cubic & primvar_names[b].bit) ? 16 : n) * (size_t)primvar_names[b].size;
    if (reserve_pv(s, need) != RAYES_OK)
        return RAYES_ERROR_OUT_OF_MEMORY;
    for (int b = 0; b < GEOM_N_PV; b++) {
        const RayesPrimvar *v = set->by[b];
        if (!v)
            continue;
        int size = primvar_names[b].size, per_control = (cubic & primvar_names[b].bit) != 0;
        for (int k = 0; k < (per_control ? 16 : n); k++) {
            size_t at = per_control ? (size_t)k : primvar_index(v->cls, src[k]);
            const float *x = v->data + at * (size_t)size;
            float *out = s->pv + s->n_pv;
            if (primvar_names[b].bit == GEOM_PV_N) {
                Vec3 N = v3_normalize(mat4_vector(&set->normal_from_object, v3_load(x)));
                out[0] = N.x, out[1] = N.y, out[2] = N.z;
            } else
                memcpy(out, x, (size_t)size * sizeof *out);
            s->n_pv += (size_t)size;
        }
    }
    return RAYES_OK;
}

RayesError rayes_scene_bilinear_patch(RayesScene *s, const float P[4][3])
{
    return rayes_scene_bilinear_patch_pv(s, P, NULL, 0);
}

RayesError rayes_scene_bilinear_patch_pv(RayesScene *s, const float P[4][3],
                                         const RayesPrimvar *pv, size_t n_pv)
{
    if (!s || !P)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(&P[0][0], 12))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "bilinear patch: non-finite point");
    static const size_t expect[5] = {1, 1, 4, 4, 4};
    PrimvarSet set;
    RayesError e = check_primvars(s, "bilinear patch", pv, n_pv, expect, &set);
    if (e != RAYES_OK)
        return e;
    Prim p = {.type = PRIM_BILINEAR};
    transform_points(s, P, 4, p.cp);
    const PrimvarSource src[4] = {{0, 0, 0}, {0, 1, 1}, {0, 2, 2}, {0, 3, 3}};
    if ((e = push_primvars(s, &p, &set, src, 4, 0)) != RAYES_OK)
        return e;
    return add_prim(s, &p);
}

RayesError rayes_scene_bicubic_patch(RayesScene *s, const float P[16][3])
{
    return rayes_scene_bicubic_patch_pv(s, P, NULL, 0);
}

RayesError rayes_scene_bicubic_patch_pv(RayesScene *s, const float P[16][3],
                                        const RayesPrimvar *pv, size_t n_pv)
{
    if (!s || !P)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(&P[0][0], 48))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "bicubic patch: non-finite point");
    static const size_t expect[5] = {1, 1, 4, 16, 4};
    PrimvarSet set;
    RayesError e = check_primvars(s, "bicubic patch", pv, n_pv, expect, &set);
    if (e != RAYES_OK)
        return e;
    unsigned cubic = 0;
    for (int b = 0; b < GEOM_N_PV; b++)
        if (set.by[b] && set.by[b]->cls == RAYES_PRIMVAR_VERTEX)
            cubic |= primvar_names[b].bit;
    PrimBig big;
    Prim p = {.type = PRIM_BICUBIC, .big = &big};
    transform_points(s, P, 16, big.cp);
    const PrimvarSource src[4] = {{0, 0, 0}, {0, 1, 1}, {0, 2, 2}, {0, 3, 3}};
    if ((e = push_primvars(s, &p, &set, src, 4, cubic)) != RAYES_OK)
        return e;
    return add_prim(s, &p);
}

RayesError rayes_scene_polygon_mesh(RayesScene *s, size_t n_faces, const int *n_verts,
                                    const int *indices, size_t n_points, const float *P)
{
    return rayes_scene_polygon_mesh_pv(s, n_faces, n_verts, indices, n_points, P, NULL, 0);
}

/* Checks a mesh's faces: sizes from lo to hi vertices (hint names the rule
 * in messages) and every index a point. Writes the corners' count. */
static RayesError check_faces(RayesScene *s, const char *what, size_t n_faces, const int *n_verts,
                              const int *indices, size_t n_points, int lo, int hi, const char *hint,
                              size_t *n_corners)
{
    size_t k = 0;
    for (size_t f = 0; f < n_faces; f++) {
        if (n_verts[f] < lo || n_verts[f] > hi)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: face %zu has %d vertices; expected %s", what, f, n_verts[f],
                              hint);
        for (int v = 0; v < n_verts[f]; v++)
            if (indices[k + (size_t)v] < 0 || (size_t)indices[k + (size_t)v] >= n_points)
                return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                  "%s: face %zu uses vertex %d; expected 0 to %zu", what, f,
                                  indices[k + (size_t)v], n_points ? n_points - 1 : 0);
        k += (size_t)n_verts[f];
    }
    *n_corners = k;
    return RAYES_OK;
}

RayesError rayes_scene_polygon_mesh_pv(RayesScene *s, size_t n_faces, const int *n_verts,
                                       const int *indices, size_t n_points, const float *P,
                                       const RayesPrimvar *pv, size_t n_pv)
{
    if (!s || (n_faces && (!n_verts || !indices || !P)))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(P, 3 * n_points))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "polygon mesh: non-finite point");
    size_t k = 0;
    RayesError e =
        check_faces(s, "polygon mesh", n_faces, n_verts, indices, n_points, 3, 4, "3 or 4", &k);
    if (e != RAYES_OK)
        return e;
    const size_t expect[5] = {1, n_faces, n_points, n_points, k};
    PrimvarSet set;
    e = check_primvars(s, "polygon mesh", pv, n_pv, expect, &set);
    if (e != RAYES_OK)
        return e;
    k = 0;
    for (size_t f = 0; f < n_faces; f++) {
        const float(*pts)[3] = (const float(*)[3])P;
        const int *ix = indices + k;
        Prim p = {.type = n_verts[f] == 3 ? PRIM_TRIANGLE : PRIM_BILINEAR};
        /* Polygon order v0 v1 v2 v3 -> bilinear P00 = v0, P10 = v1, P01 = v3, P11 = v2. */
        static const int tri[3] = {0, 1, 2}, quad[4] = {0, 1, 3, 2};
        const int *order = n_verts[f] == 3 ? tri : quad;
        PrimvarSource src[4];
        for (int v = 0; v < n_verts[f]; v++) {
            transform_points(s, &pts[ix[order[v]]], 1, &p.cp[v]);
            src[v] = (PrimvarSource){f, k + (size_t)order[v], (size_t)ix[order[v]]};
        }
        if ((e = push_primvars(s, &p, &set, src, n_verts[f], 0)) != RAYES_OK)
            return e;
        if ((e = add_prim(s, &p)) != RAYES_OK)
            return e;
        k += (size_t)n_verts[f];
    }
    return RAYES_OK;
}

/* Checks the faces and tags of a subdivision mesh. */
static RayesError check_subdiv(RayesScene *s, RayesSubdivScheme scheme, size_t n_faces,
                               const int *n_verts, const int *indices, size_t n_points,
                               const RayesSubdivTags *t, size_t *n_corners)
{
    const char *what = "subdivision mesh";
    if ((unsigned)scheme > RAYES_SUBDIV_BILINEAR)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: unknown scheme %d", what,
                          (int)scheme);
    if (n_faces > INT32_MAX || n_points > INT32_MAX)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: too many faces or points", what);
    int loop = scheme == RAYES_SUBDIV_LOOP;
    RayesError e = check_faces(s, what, n_faces, n_verts, indices, n_points, 3, loop ? 3 : 64,
                               loop ? "3 (Loop takes triangles)" : "3 to 64", n_corners);
    if (e != RAYES_OK || !t)
        return e;
    if (t->interpolate_boundary < 0 || t->interpolate_boundary > 2 || t->facevarying_boundary < 0 ||
        t->facevarying_boundary > 3)
        return scene_fail(
            s, RAYES_ERROR_INVALID_ARGUMENT,
            "%s: interpolateboundary must be 0 to 2 and facevaryinginterpolateboundary 0 "
            "to 3",
            what);
    if ((t->n_creases && (!t->crease_edges || !t->crease_sharpness)) ||
        (t->n_corners && (!t->corner_points || !t->corner_sharpness)) ||
        (t->n_holes && !t->hole_faces))
        return RAYES_ERROR_INVALID_ARGUMENT;
    for (size_t i = 0; i < 2 * t->n_creases; i++)
        if (t->crease_edges[i] < 0 || (size_t)t->crease_edges[i] >= n_points)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: crease point %d; expected 0 to %zu", what, t->crease_edges[i],
                              n_points ? n_points - 1 : 0);
    for (size_t i = 0; i < t->n_corners; i++)
        if (t->corner_points[i] < 0 || (size_t)t->corner_points[i] >= n_points)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: corner point %d; expected 0 to %zu", what, t->corner_points[i],
                              n_points ? n_points - 1 : 0);
    for (size_t i = 0; i < t->n_holes; i++)
        if (t->hole_faces[i] < 0 || (size_t)t->hole_faces[i] >= n_faces)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: hole face %d; expected 0 to %zu", what, t->hole_faces[i],
                              n_faces ? n_faces - 1 : 0);
    if (!scene_finite(t->crease_sharpness, t->n_creases) ||
        !scene_finite(t->corner_sharpness, t->n_corners))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: a sharpness is not finite", what);
    for (size_t i = 0; i < t->n_creases; i++)
        if (t->crease_sharpness[i] < 0.0f)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: a crease sharpness is negative",
                              what);
    for (size_t i = 0; i < t->n_corners; i++)
        if (t->corner_sharpness[i] < 0.0f)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: a corner sharpness is negative",
                              what);
    return RAYES_OK;
}

RayesError rayes_scene_subdivision_mesh(RayesScene *s, RayesSubdivScheme scheme, size_t n_faces,
                                        const int *n_verts, const int *indices, size_t n_points,
                                        const float *P, const RayesSubdivTags *tags,
                                        const RayesPrimvar *pv, size_t n_pv)
{
    if (!s || (n_faces && (!n_verts || !indices || !P)))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(P, 3 * n_points))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "subdivision mesh: non-finite point");
    size_t n_corners = 0;
    RayesError e = check_subdiv(s, scheme, n_faces, n_verts, indices, n_points, tags, &n_corners);
    if (e != RAYES_OK)
        return e;
    const size_t expect[5] = {1, n_faces, n_points, n_points, n_corners};
    PrimvarSet set;
    if ((e = check_primvars(s, "subdivision mesh", pv, n_pv, expect, &set)) != RAYES_OK)
        return e;
    if (n_faces == 0)
        return RAYES_OK;
    /* World space: points, and normals (the only variable that moves). */
    size_t n_n = set.by[0] ? set.by[0]->count : 0;
    float *world = malloc((3 * n_points + 3 * n_n + 1) * sizeof *world);
    if (!world)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    transform_points(s, (const float(*)[3])P, n_points, (Vec3 *)world);
    if (!scene_within(bounds_of(world, n_points))) {
        free(world);
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, WITHIN_EXPECTED, "subdivision mesh");
    }
    float *N = world + 3 * n_points;
    for (size_t i = 0; i < n_n; i++) {
        Vec3 n = mat4_vector(&set.normal_from_object, v3_load(set.by[0]->data + 3 * i));
        N[3 * i] = n.x, N[3 * i + 1] = n.y, N[3 * i + 2] = n.z;
    }
    SubdivDesc d = {.scheme = (int)scheme,
                    .n_faces = n_faces,
                    .n_verts = n_verts,
                    .indices = indices,
                    .n_points = n_points,
                    .P = world,
                    .interpolate_boundary = tags ? tags->interpolate_boundary : 1,
                    .facevarying_boundary = tags ? tags->facevarying_boundary : 1};
    if (tags) {
        d.n_creases = tags->n_creases, d.crease_edges = tags->crease_edges;
        d.crease_sharpness = tags->crease_sharpness;
        d.n_corners = tags->n_corners, d.corner_points = tags->corner_points;
        d.corner_sharpness = tags->corner_sharpness;
        d.n_holes = tags->n_holes, d.hole_faces = tags->hole_faces;
    }
    for (int b = 0; b < GEOM_N_PV; b++)
        if (set.by[b])
            d.pv[d.n_pv++] = (SubdivPrimvar){primvar_names[b].bit, (int)set.by[b]->cls,
                                             primvar_names[b].size, b == 0 ? N : set.by[b]->data};
    char err[256] = "";
    SubdivMesh *mesh = geom_subdiv_new(&d, err, sizeof err);
    free(world);
    if (!mesh)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "subdivision mesh: %s", err);
    if (util_grow((void **)&s->subdivs, &s->cap_subdivs, s->n_subdivs, sizeof *s->subdivs) != 0) {
        geom_subdiv_free(mesh);
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    s->subdivs[s->n_subdivs++] = mesh;
    for (size_t k = 0; k < geom_subdiv_n_patches(mesh); k++) {
        Prim p = {.type = PRIM_SUBDIV, .pv = (uint8_t)set.mask};
        p.subdiv.mesh = mesh;
        p.subdiv.patch = (uint32_t)k;
        p.subdiv.triangular = geom_subdiv_patch_triangular(mesh, k);
        if ((e = add_prim(s, &p)) != RAYES_OK)
            return e;
    }
    return RAYES_OK;
}

RayesError rayes_scene_sphere(RayesScene *s, float radius)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(radius > 0.0f) || !isfinite(radius))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "sphere: expected a positive radius");
    PrimBig big;
    Prim p = {.type = PRIM_SPHERE, .big = &big};
    Mat4 inv;
    mat4_invert(s->world_from_object, &inv);
    p.big->sphere.world_from_object = s->world_from_object;
    p.big->sphere.normal_from_object = mat4_transpose(inv);
    p.big->sphere.radius = radius;
    return add_prim(s, &p);
}

static RayesError add_volume(RayesScene *s, const float bound[6], int64_t inside, int atmosphere)
{
    if (!s || !bound)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(bound, 6) || !(bound[0] < bound[1]) || !(bound[2] < bound[3]) ||
        !(bound[4] < bound[5]))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "volume: expected a finite box xmin < xmax, ymin < ymax, zmin < zmax");
    if (s->open_master >= 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "volume: not allowed in an object block");
    if (s->current_object < 0) {
        RayesError e = rayes_scene_set_shader(s, "homogeneous", NULL, 0);
        if (e != RAYES_OK)
            return e;
    }
    SceneVolume *v = NULL;
    for (size_t i = 0; atmosphere && i < s->n_volumes && !v; i++)
        if (s->volumes[i].atmosphere)
            v = &s->volumes[i]; /* the one atmosphere, replaced */
    if (!v) {
        if (util_grow((void **)&s->volumes, &s->cap_volumes, s->n_volumes, sizeof *s->volumes) != 0)
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
        v = &s->volumes[s->n_volumes++];
    }
    v->object = (uint32_t)s->current_object;
    v->inside = inside;
    v->atmosphere = atmosphere;
    v->world_from_object = s->world_from_object;
    memcpy(v->bound, bound, sizeof v->bound);
    v->shading_rate = s->shading_rate;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

RayesError rayes_scene_volume(RayesScene *s, const float bound[6])
{
    return add_volume(s, bound, -1, 0);
}

RayesError rayes_scene_atmosphere(RayesScene *s)
{
    static const float unit[6] = {0, 1, 0, 1, 0, 1}; /* unused: the scene's bounds */
    return add_volume(s, unit, -1, 1);
}

RayesError rayes_scene_volume_inside(RayesScene *s, const float bound[6])
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->last_geometry_object < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "volume inside: no geometry before it (a closed shape bounds it)");
    return add_volume(s, bound, s->last_geometry_object, 0);
}

static void light_motion(const RayesScene *s, Light *l);
static RayesError push_light(RayesScene *s, const Light *l, const Prim *prims, size_t n_prims);

RayesError rayes_scene_area_light(RayesScene *s, const float P[4][3], const float L[3])
{
    if (!s || !P || !L)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(&P[0][0], 12) || !scene_finite(L, 3) || L[0] < 0 || L[1] < 0 || L[2] < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light: expected finite points and a non-negative radiance");
    if (s->open_master >= 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light: not allowed in an object block");
    if (util_grow((void **)&s->lights, &s->cap_lights, s->n_lights, sizeof *s->lights) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    Light *l = &s->lights[s->n_lights];
    memset(l, 0, sizeof *l);
    l->type = LIGHT_QUAD;
    Vec3 v[4];
    transform_points(s, P, 4, v);
    if (!scene_within(bounds_of(&v[0].x, 4)))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, WITHIN_EXPECTED, "area light");
    l->P[0] = v[0];
    l->P[1] = v[1];
    l->P[2] = v[3];
    l->P[3] = v[2];
    l->L = l->color = v3_load(L);
    l->intensity = 1.0f;
    Vec3 n;
    Vec3 c;
    light_quad_eval(l, 0.5f, 0.5f, &c, &n);
    if (!(v3_length(n) > 0.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "area light: the quad has no area");
    light_motion(s, l);
    int64_t keep = s->current_object;
    RayesError e = add_object(s, NULL, NULL, 0, (int)s->n_lights);
    if (e != RAYES_OK)
        return e;
    s->n_lights++;
    Prim p = {.type = PRIM_BILINEAR, .object = (uint32_t)(s->n_objects - 1),
              .shading_rate = s->shading_rate, .motion = s->current_motion};
    memcpy(p.cp, l->P, sizeof l->P);
    if (util_grow((void **)&s->prims, &s->cap_prims, s->n_prims, sizeof *s->prims) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->prims[s->n_prims++] = p;
    s->current_object = keep;
    return RAYES_OK;
}

/* The emitter's geometry is the light's triangles; a moving transform is
 * taken at its first time (mesh lights are still: light.h). */
/* rayes_scene_area_light_mesh, with an emission texture when st and
 * texture are given (rayes_scene_area_light_mesh_textured). */
static RayesError area_light_mesh(RayesScene *s, size_t n_faces, const int *n_verts,
                                  const int *indices, size_t n_points, const float *P,
                                  const float *st, const char *texture, const float L[3],
                                  int two_sided)
{
    if (!s || !L || !n_faces || !n_verts || !indices || !P)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(P, 3 * n_points) || !scene_finite(L, 3) || L[0] < 0 || L[1] < 0 || L[2] < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light mesh: expected finite points and a non-negative radiance");
    if (st && !scene_finite(st, 2 * n_points))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light mesh: expected finite texture coordinates");
    if (s->open_master >= 0 || s->deforming)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light mesh: not allowed in an object block or a deformation "
                          "(emitters do not deform)");
    size_t n_corners = 0;
    RayesError e = check_faces(s, "area light mesh", n_faces, n_verts, indices, n_points, 3,
                               INT32_MAX, "3 or more", &n_corners);
    if (e != RAYES_OK)
        return e;
    size_t n_tris = n_corners - 2 * n_faces; /* each face a fan */
    Vec3 *v = malloc(3 * n_tris * sizeof *v);
    Prim *prims = malloc(n_tris * sizeof *prims);
    float *tri_st = st ? malloc(6 * n_tris * sizeof *tri_st) : NULL;
    if (!v || !prims || (st && !tri_st)) {
        free(v);
        free(prims);
        free(tri_st);
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    const float(*pts)[3] = (const float(*)[3])P;
    size_t t = 0, k = 0;
    for (size_t f = 0; f < n_faces; k += (size_t)n_verts[f], f++)
        for (int c = 1; c + 1 < n_verts[f]; c++, t++) {
            const int corner[3] = {indices[k], indices[k + (size_t)c], indices[k + (size_t)c + 1]};
            prims[t] = (Prim){.type = PRIM_TRIANGLE};
            for (int j = 0; j < 3; j++) {
                transform_points(s, &pts[corner[j]], 1, &v[3 * t + (size_t)j]);
                prims[t].cp[j] = v[3 * t + (size_t)j];
                if (tri_st)
                    memcpy(&tri_st[6 * t + 2 * (size_t)j], &st[2 * (size_t)corner[j]],
                           2 * sizeof *st);
            }
        }
    if (!scene_within(bounds_of(&v[0].x, 3 * n_tris))) {
        free(v);
        free(prims);
        free(tri_st);
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, WITHIN_EXPECTED, "area light mesh");
    }
    Light l;
    memset(&l, 0, sizeof l);
    l.L = l.color = v3_load(L);
    l.intensity = 1.0f;
    if (light_mesh_init(&l, v, n_tris, two_sided) != 0) {
        free(v);
        free(prims);
        free(tri_st);
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "area light mesh: no face has area (or out of memory)");
    }
    if (tri_st) {
        char path[1024], err[800];
        int bad = 1;
        if (scene_find_texture(s, texture, path, sizeof path) != 0)
            snprintf(err, sizeof err, "area light mesh: texture name too long");
        else
            bad = light_mesh_texture(&l, tri_st, path, err, sizeof err) != 0;
        free(tri_st);
        if (bad) { /* as a surface's texture that cannot be read: said, and left out */
            char key[128];
            snprintf(key, sizeof key, "emission texture %.100s", texture);
            log_warning_once(key, "%s; the light emits its radiance alone", err);
        }
    }
    l.emitter = (int)s->n_objects;
    l.mesh->first_prim = (uint32_t)s->n_prims; /* push_light appends the triangles */
    uint32_t motion = s->current_motion;
    if (motion)
        log_warning_once("mesh light motion", "a mesh area light under a moving transform is "
                                              "still, where the shutter opens");
    s->current_motion = 0;
    e = push_light(s, &l, prims, n_tris);
    s->current_motion = motion;
    if (e == RAYES_OK) /* it shadows: its near faces hide its far ones, as other lights */
        s->objects[s->n_objects - 1].ray_mask |= s->current_visibility & RAYES_RAY_SHADOW;
    free(v);
    free(prims);
    if (e != RAYES_OK)
        light_fini(&l);
    return e;
}

RayesError rayes_scene_area_light_mesh(RayesScene *s, size_t n_faces, const int *n_verts,
                                       const int *indices, size_t n_points, const float *P,
                                       const float L[3], int two_sided)
{
    return area_light_mesh(s, n_faces, n_verts, indices, n_points, P, NULL, NULL, L, two_sided);
}

RayesError rayes_scene_area_light_mesh_textured(RayesScene *s, size_t n_faces, const int *n_verts,
                                                const int *indices, size_t n_points, const float *P,
                                                const float *st, const float L[3], int two_sided,
                                                const char *texture)
{
    if (!st || !texture || !texture[0])
        return s ? scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "area light mesh: expected texture coordinates and a texture")
                 : RAYES_ERROR_INVALID_ARGUMENT;
    return area_light_mesh(s, n_faces, n_verts, indices, n_points, P, st, texture, L, two_sided);
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return x < y ? -1 : x > y;
}

RayesError rayes_scene_set_light_links(RayesScene *s, RayesLightLinks mode, const size_t *lights,
                                       size_t n_lights)
{
    if (!s || (n_lights && !lights))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (mode != RAYES_LIGHT_LINKS_ALL && mode != RAYES_LIGHT_LINKS_ONLY &&
        mode != RAYES_LIGHT_LINKS_EXCEPT)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "light links: unknown mode %d",
                          (int)mode);
    if (mode == RAYES_LIGHT_LINKS_ALL) {
        s->current_links = 0;
        return RAYES_OK;
    }
    if (s->n_links >= UINT32_MAX - 1 ||
        util_grow((void **)&s->links, &s->cap_links, s->n_links, sizeof *s->links) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    size_t *copy = malloc((n_lights ? n_lights : 1) * sizeof *copy);
    if (!copy)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    if (n_lights)
        memcpy(copy, lights, n_lights * sizeof *copy);
    qsort(copy, n_lights, sizeof *copy, cmp_size);
    size_t n = 0;
    for (size_t i = 0; i < n_lights; i++)
        if (n == 0 || copy[n - 1] != copy[i])
            copy[n++] = copy[i];
    s->links[s->n_links++] = (SceneLinks){(int)mode, copy, n};
    s->current_links = (uint32_t)s->n_links;
    return RAYES_OK;
}

int scene_object_lit_by(const RayesScene *s, size_t object, size_t light)
{
    uint32_t k = s->objects[object].links;
    if (k == 0)
        return 1;
    const SceneLinks *l = &s->links[k - 1];
    int listed = bsearch(&light, l->lights, l->n, sizeof *l->lights, cmp_size) != NULL;
    return l->mode == RAYES_LIGHT_LINKS_ONLY ? listed : !listed;
}

/* Light links name lights that may be made after them: every light an
 * object's links name must exist by the commit. */
static RayesError check_links(RayesScene *s)
{
    for (size_t i = 0; i < s->n_objects; i++) {
        uint32_t k = s->objects[i].links;
        if (k == 0 || s->links[k - 1].n == 0)
            continue;
        size_t last = s->links[k - 1].lights[s->links[k - 1].n - 1];
        if (last >= s->n_lights)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "light links of object %zu: no light %zu (the scene has %zu)", i,
                              last, s->n_lights);
    }
    return RAYES_OK;
}

RayesError rayes_scene_commit(RayesScene *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->open_master >= 0)
        return scene_fail(s, RAYES_ERROR_INVALID_OPERATION,
                          "commit: the object block \"%.64s\" has no end (rayes_scene_object_end)",
                          s->masters[s->open_master].name);
    RayesError e = check_links(s);
    if (e != RAYES_OK)
        return e;
    s->timestamp++;
    s->dirty = 0;
    if (s->changes & SCENE_CHANGE_CAMERA)
        s->stamp_camera = s->timestamp;
    if (s->changes & SCENE_CHANGE_SHADING)
        s->stamp_shading = s->timestamp;
    if (s->changes & SCENE_CHANGE_GEOMETRY)
        s->stamp_geometry = s->timestamp;
    s->changes = 0;
    return RAYES_OK;
}

uint64_t rayes_scene_get_timestamp(const RayesScene *s)
{
    return s ? s->timestamp : 0;
}

Bounds3 scene_bounds(const RayesScene *s)
{
    Bounds3 b = bounds_empty();
    for (size_t i = 0; i < s->n_volumes; i++) {
        const SceneVolume *v = &s->volumes[i];
        if (v->atmosphere)
            continue; /* it has the others' bounds */
        for (int k = 0; k < 8; k++)
            b = bounds_add(b, mat4_point(&v->world_from_object,
                                         v3(v->bound[k & 1], v->bound[2 + (k >> 1 & 1)],
                                            v->bound[4 + (k >> 2)])));
    }
    for (size_t i = 0; i < s->n_prims; i++)
        if (!s->prims[i].master) /* masters' are in master space: their instances' below */
            b = bounds_union(b, scene_prim_bounds(&s->prims[i]));
    return bounds_union(b, scene_instances_bounds(s));
}

/* The dicing camera of the scene's camera for an image of width x height. */
static DiceCamera dice_camera(const RayesScene *s, int width, int height, const DiceOptions *dice,
                              float radius)
{
    DiceCamera cam = {0};
    const SceneCamera *c = &s->camera;
    scene_camera_screen(c, width, height, cam.screen);
    float pixel = fabsf(cam.screen[3] - cam.screen[2]) / (float)height; /* screen units */
    cam.eye = c->eye;
    cam.pixel_angle = c->tan_half_fov * pixel;
    cam.pixel_width = c->tan_half_fov > 0.0f ? 0.0f : pixel * v3_length(c->y);
    cam.min_distance = 1e-3f * fmaxf(radius, 1e-6f);
    cam.grid_size = dice ? dice->grid_size : 0;
    cam.offscreen = dice && dice->offscreen > 1.0f ? dice->offscreen : 1.0f;
    cam.isotropic = dice ? dice->isotropic : 0;
    cam.rate_scale = 1.0f;
    cam.binary = 1; /* for geom_stitch */
    Mat4 world_from_camera = {{{c->x.x, c->y.x, c->z.x, c->eye.x},
                               {c->x.y, c->y.y, c->z.y, c->eye.y},
                               {c->x.z, c->y.z, c->z.z, c->eye.z},
                               {0, 0, 0, 1}}};
    cam.has_view = mat4_invert(world_from_camera, &cam.camera_from_world);
    cam.tan_half_fov = c->tan_half_fov;
    cam.pixel = pixel;
    return cam;
}

/* The dicing cameras of the masters: master m's (cams[m + 1]) measures
 * by distance from the eye of its nearest instance, in master space
 * (DESIGN.md "Instances": one tessellation serves every instance, so it
 * is as fine as the nearest needs); cams[m + 1].grid_size is -1 for a
 * master no instance places (not diced). Returns 0, or -1 when out of
 * memory. */
static int master_cameras(const RayesScene *s, const GridSet *gs, DiceCamera *cams)
{
    Bounds3 *mb = scene_masters_bounds(s);
    float *best = malloc((s->n_masters + 1) * sizeof *best);
    if (!mb || !best) {
        free(mb);
        free(best);
        return -1;
    }
    for (size_t m = 0; m < s->n_masters; m++) {
        best[m] = INFINITY;
        cams[m + 1] = cams[0];
        cams[m + 1].grid_size = -1;
    }
    for (size_t i = 0; i < gs->n_instances; i++) {
        const GeomInstance *gi = &gs->instances[i];
        Vec3 e = mat4_point(&gi->master_from_world, cams[0].eye);
        Bounds3 b = mb[gi->master];
        Vec3 near = v3(fminf(fmaxf(e.x, b.lo.x), b.hi.x), fminf(fmaxf(e.y, b.lo.y), b.hi.y),
                       fminf(fmaxf(e.z, b.lo.z), b.hi.z));
        float d = v3_length(v3_sub(near, e)); /* master units: world distance / scale */
        if (!(d < best[gi->master]))
            continue;
        best[gi->master] = d;
        DiceCamera *c = &cams[gi->master + 1];
        *c = cams[0];
        c->eye = e;
        c->has_view = 0; /* by distance: the frustum is the world's, not the master's */
        c->pixel_width = cams[0].pixel_width / gi->scale;
        c->min_distance = cams[0].min_distance / gi->scale;
    }
    free(mb);
    free(best);
    return 0;
}

/* Primitive i as cam dices it: its shading rate coarser when it is
 * blurred (scene_blur_dice_factor). */
static Prim as_diced(const RayesScene *s, size_t i, const DiceCamera *cam)
{
    Prim p = s->prims[i];
    float c = scene_blur_dice_factor(s, i, cam);
    p.shading_rate *= c * c; /* a rate is an area */
    return p;
}

/* The grid vertices primitives first.. of s need at cams' rates (blurred
 * ones coarser), counted without dicing (the same walk as dicing); the
 * grids are added to *grids when that is not NULL. */
static size_t count_from(const RayesScene *s, const DiceCamera *cams, size_t first, size_t *grids)
{
    size_t total = 0;
    for (size_t k = first; k < s->n_prims; k++) {
        const DiceCamera *ck = &cams[s->prims[k].master];
        if (ck->grid_size < 0)
            continue;
        Prim p = as_diced(s, k, ck);
        total += geom_count_prim(&p, ck, grids);
    }
    return total;
}

/* Dices (and displaces) every primitive into gs, world geometry with
 * cams[0] and master m's with cams[m + 1] (skipping masters no instance
 * places), or stops as soon as gs holds more than budget vertices (0: no
 * budget) and returns the vertices all primitives would need, counted;
 * else returns 0. -1 (as size_t) when out of memory. */
/* What dice_all returns when *stop became nonzero. */
#define DICE_STOPPED ((size_t)-2)

static size_t dice_all(const RayesScene *s, const DiceCamera *cams, size_t budget,
                       DicingServices *sv, float step, const volatile int *stop, GridSet *gs)
{
    for (size_t i = 0; i < s->n_prims; i++) {
        size_t first = gs->n_grids;
        if (stop && __atomic_load_n(stop, __ATOMIC_RELAXED))
            return DICE_STOPPED;
        const DiceCamera *cam = &cams[s->prims[i].master];
        if (cam->grid_size < 0)
            continue;
        Prim blurred = as_diced(s, i, cam);
        if (geom_dice_prim(gs, &blurred, (uint32_t)i, s->pv, cam) != 0)
            return (size_t)-1;
        if (budget && gs->n_vertices > budget)
            return gs->n_vertices + count_from(s, cams, i + 1, NULL);
        /* Normals of displaced surfaces: differences over 1e-3 of the scene radius.
         * Curves and points are not displaced (as in RenderMan). */
        const Prim *p = &s->prims[i];
        if (p->displacement && p->type != PRIM_CURVE && p->type != PRIM_POINT) {
            if (scene_displace(s, gs, first, step, &sv->sv) != 0)
                return (size_t)-1;
            geom_bound_sagitta(gs, first);
        }
    }
    return 0;
}

/* Whether the primitives' smallest grids (three vertices or four each)
 * already exceed the budget: then the first dicing, which would stop at
 * the budget, is left out for counting (a mesh of 8 million triangles:
 * 2 GB of grids diced and dropped, 8 of its 25 s). */
static int over_budget(const RayesScene *s, const DiceCamera *cams, size_t budget)
{
    size_t least = 0;
    for (size_t i = 0; i < s->n_prims && budget; i++)
        if (cams[s->prims[i].master].grid_size >= 0)
            least += geom_prim_triangular(&s->prims[i]) ? 3 : 4;
    return budget && least > budget;
}

/* About the bytes grids take with their ray tracing data: per vertex its
 * position, normal, derivatives, (u, v) and the primitive variables the
 * scene carries, and Embree's share; per grid its record and Embree's
 * (measured on a mesh of 8 million triangles diced whole: 362 bytes a
 * grid of three vertices, 78 of them Embree's; this says 420). */
static double grid_bytes(const RayesScene *s, size_t vertices, size_t grids)
{
    unsigned pv = 0;
    for (size_t i = 0; i < s->n_prims; i++)
        pv |= s->prims[i].pv;
    double per_vertex = 4 * sizeof(Vec3) + 2 * sizeof(float) + 24.0;
    per_vertex += (pv & GEOM_PV_N ? sizeof(Vec3) : 0) + (pv & GEOM_PV_ST ? 6 * sizeof(float) : 0) +
                  (pv & GEOM_PV_CS ? sizeof(Vec3) : 0) + (pv & GEOM_PV_OS ? sizeof(Vec3) : 0);
    return (double)vertices * per_vertex + (double)grids * (sizeof(Grid) + 64.0);
}

/* scene_prepare's return when dice_all returned r (failed or stopped). */
static int prepare_stopped(size_t r, char *err, size_t err_size)
{
    if (r != DICE_STOPPED)
        return -1;
    if (err && err_size)
        snprintf(err, err_size, "render: cancelled");
    return -2;
}

int scene_prepare(const RayesScene *s, int width, int height, const DiceOptions *dice,
                  TextureSystem *textures, GridSet *gs, float *coarsened, char *err,
                  size_t err_size)
{
    DicingServices sv;
    shade_dicing_services_init(&sv, textures);
    Bounds3 b = scene_bounds(s);
    float radius = s->n_prims ? 0.5f * v3_length(v3_sub(b.hi, b.lo)) : 1.0f;
    DiceCamera *cams = malloc((s->n_masters + 1) * sizeof *cams);
    if (!cams || scene_flatten_instances(s, gs) != 0) {
        free(cams);
        return -1;
    }
    cams[0] = dice_camera(s, width, height, dice, radius);
    if (master_cameras(s, gs, cams) != 0) {
        free(cams);
        return -1;
    }
    size_t budget = dice ? dice->vertex_budget : 0;
    /* Over the budget: vertices go as the inverse square of the edge, so
     * edges longer by the square root of the excess (and 5%) fit, but
     * for the grids' minimum sizes. The first dicing stops at the
     * budget; the rates are then found by counting alone (at most eight
     * rounds) and the scene diced once more. A round that saved under 1%
     * is followed by one with edges sqrt(2) times as long, since grid
     * sizes come in steps (a sphere at 64 x 48 stayed at 1156 vertices of
     * a 1000 budget), and a third such round in a row ends it: primitives
     * at their minimum sizes, a dense mesh's, cannot shrink. */
    const volatile int *stop = dice ? dice->stop : NULL;
    size_t first_need = over_budget(s, cams, budget)
                            ? count_from(s, cams, 0, NULL)
                            : dice_all(s, cams, budget, &sv, 1e-3f * radius, stop, gs);
    if (first_need == (size_t)-1 || first_need == DICE_STOPPED) {
        free(cams);
        return prepare_stopped(first_need, err, err_size);
    }
    if (first_need) {
        size_t need = first_need, grids = 0;
        int stalled = 0;
        for (int round = 0; round < 8 && need > budget; round++) {
            float step = stalled ? 1.41421356f : 1.05f * sqrtf((float)need / (float)budget);
            for (size_t m = 0; m <= s->n_masters; m++)
                cams[m].rate_scale *= step;
            size_t before = need;
            grids = 0;
            need = count_from(s, cams, 0, &grids);
            if ((double)need > 0.99 * (double)before) {
                if (++stalled == 3)
                    break;
            } else {
                stalled = 0;
            }
        }
        GeomInstance *keep = gs->instances; /* the instances stay; the grids go */
        size_t n_keep = gs->n_instances, n_moving = gs->n_moving_instances;
        Mat4 *keep_motion = gs->instance_motion;
        gs->instances = NULL;
        gs->instance_motion = NULL;
        geom_gridset_fini(gs);
        geom_gridset_init(gs);
        gs->instances = keep;
        gs->n_instances = n_keep;
        gs->instance_motion = keep_motion;
        gs->n_moving_instances = n_moving;
        gs->n_masters = s->n_masters;
        /* Too big for the memory left (measured with the first dicing
         * dropped): a clear error, not the kernel's out-of-memory killer
         * half way through. */
        double bytes = grid_bytes(s, need, grids), room = dice ? dice->memory_limit : 0.0;
        if (room <= 0.0) {
            uint64_t phys = mem_physical_bytes(), rss = mem_rss_bytes();
            room = phys > rss ? 0.9 * (double)(phys - rss) : 0.0;
        }
        if (bytes > room) {
            if (err && err_size)
                snprintf(err, err_size,
                         "render: the scene needs %zu grid vertices in %zu grids, about %.1f GB, "
                         "more than the %.1f GB of memory left; raise the shading rate or "
                         "simplify the geometry",
                         need, grids, bytes / 1e9, room / 1e9);
            free(cams);
            return -1;
        }
        size_t again = dice_all(s, cams, 0, &sv, 1e-3f * radius, stop, gs);
        if (again == (size_t)-1 || again == DICE_STOPPED) {
            free(cams);
            return prepare_stopped(again, err, err_size);
        }
    }
    float rate_scale = cams[0].rate_scale;
    int stitched = geom_stitch(gs, s->prims, stop);
    int failed = stitched != 0 || scene_motion_prepare(s, cams, gs) != 0;
    free(cams);
    if (stitched == -2)
        return prepare_stopped(DICE_STOPPED, err, err_size);
    if (failed)
        return -1;
    if (first_need) /* over the budget still: primitives diced finer than it allows
                       (a dense mesh's faces take 3 or 4 vertices however far they are) */
        log_warning("dicing: the scene needs %zu grid vertices, more than the budget of %zu "
                    "(--vertex-budget); micropolygons made %.2f times longer (%zu vertices%s)",
                    first_need, budget, rate_scale, gs->n_vertices,
                    gs->n_vertices > budget
                        ? "; still over it: its primitives dice no coarser, a mesh's faces "
                          "keeping 3 or 4 vertices however small"
                        : "");
    if (s->n_solids) { /* the solids' tree, blocks still open closed at the end */
        if (!(gs->solids = malloc(s->n_solids * sizeof *gs->solids)))
            return -1;
        memcpy(gs->solids, s->solids, s->n_solids * sizeof *gs->solids);
        gs->n_solids = s->n_solids;
        for (size_t k = 0; k < s->n_solids; k++)
            if (gs->solids[k].end <= k)
                gs->solids[k].end = (uint32_t)s->n_solids;
    }
    if (dice && dice->clusters && geom_cluster_grids(gs) != 0)
        return -1;
    if (coarsened)
        *coarsened = rate_scale;
    return 0;
}

/* ------------------------------------------------------------ lights */

/* The parameters of rayes_scene_light, checked and with defaults. */
typedef struct LightParams {
    float intensity, color[3], from[3], to[3];
    float coneangle, conedeltaangle, beamdistribution; /* beamdistribution NAN: not given */
    float radius, width, height, fov;
    float cone, conesoftness; /* arealight quad and disk: the emission's cone, degrees */
    const char *mapname, *mapping, *shape, *category;
    float shadows, nondiffuse, nonspecular;
    float sundirection[3], haziness, groundcolor[3]; /* an environment's "sky" */
    /* uberlight's */
    const char *lighttype, *slidename;
    float cuton, cutoff, nearedge, faredge, falloff, falloffdist, maxintensity, parallelrays;
    float shearx, sheary, wedge, hedge, roundness, noiseamp, noisefreq, noiseoffset[3];
    float shadowcolor[3], shadowcheat[3];
    const float *blockermatrix; /* 16 floats, or NULL: no blocker */
    float blockerwidth, blockerheight, blockerwedge, blockerhedge, blockerround;
} LightParams;

typedef struct LightParamDesc {
    const char *name;
    RayesParamType type;
    size_t offset;
    int uber; /* 1: an uberlight's alone (others warn and ignore it) */
} LightParamDesc;

static const LightParamDesc light_param_descs[] = {
    {"intensity", RAYES_PARAM_FLOAT, offsetof(LightParams, intensity)},
    {"lightcolor", RAYES_PARAM_COLOR, offsetof(LightParams, color)},
    {"from", RAYES_PARAM_COLOR, offsetof(LightParams, from)},
    {"to", RAYES_PARAM_COLOR, offsetof(LightParams, to)},
    {"coneangle", RAYES_PARAM_FLOAT, offsetof(LightParams, coneangle)},
    {"conedeltaangle", RAYES_PARAM_FLOAT, offsetof(LightParams, conedeltaangle)},
    {"beamdistribution", RAYES_PARAM_FLOAT, offsetof(LightParams, beamdistribution)},
    {"radius", RAYES_PARAM_FLOAT, offsetof(LightParams, radius)},
    {"width", RAYES_PARAM_FLOAT, offsetof(LightParams, width)},
    {"height", RAYES_PARAM_FLOAT, offsetof(LightParams, height)},
    {"mapname", RAYES_PARAM_STRING, offsetof(LightParams, mapname)},
    {"mapping", RAYES_PARAM_STRING, offsetof(LightParams, mapping)},
    {"sundirection", RAYES_PARAM_COLOR, offsetof(LightParams, sundirection)},
    {"haziness", RAYES_PARAM_FLOAT, offsetof(LightParams, haziness)},
    {"groundcolor", RAYES_PARAM_COLOR, offsetof(LightParams, groundcolor)},
    {"fov", RAYES_PARAM_FLOAT, offsetof(LightParams, fov)},
    {"cone", RAYES_PARAM_FLOAT, offsetof(LightParams, cone)},
    {"conesoftness", RAYES_PARAM_FLOAT, offsetof(LightParams, conesoftness)},
    {"shape", RAYES_PARAM_STRING, offsetof(LightParams, shape)},
    {"__category", RAYES_PARAM_STRING, offsetof(LightParams, category)},
    {"shadows", RAYES_PARAM_FLOAT, offsetof(LightParams, shadows)},
    {"__nondiffuse", RAYES_PARAM_FLOAT, offsetof(LightParams, nondiffuse)},
    {"__nonspecular", RAYES_PARAM_FLOAT, offsetof(LightParams, nonspecular)},
    {"lighttype", RAYES_PARAM_STRING, offsetof(LightParams, lighttype), 1},
    {"slidename", RAYES_PARAM_STRING, offsetof(LightParams, slidename), 1},
    {"cuton", RAYES_PARAM_FLOAT, offsetof(LightParams, cuton), 1},
    {"cutoff", RAYES_PARAM_FLOAT, offsetof(LightParams, cutoff), 1},
    {"nearedge", RAYES_PARAM_FLOAT, offsetof(LightParams, nearedge), 1},
    {"faredge", RAYES_PARAM_FLOAT, offsetof(LightParams, faredge), 1},
    {"falloff", RAYES_PARAM_FLOAT, offsetof(LightParams, falloff), 1},
    {"falloffdist", RAYES_PARAM_FLOAT, offsetof(LightParams, falloffdist), 1},
    {"maxintensity", RAYES_PARAM_FLOAT, offsetof(LightParams, maxintensity), 1},
    {"parallelrays", RAYES_PARAM_FLOAT, offsetof(LightParams, parallelrays), 1},
    {"shearx", RAYES_PARAM_FLOAT, offsetof(LightParams, shearx), 1},
    {"sheary", RAYES_PARAM_FLOAT, offsetof(LightParams, sheary), 1},
    {"wedge", RAYES_PARAM_FLOAT, offsetof(LightParams, wedge), 1},
    {"hedge", RAYES_PARAM_FLOAT, offsetof(LightParams, hedge), 1},
    {"roundness", RAYES_PARAM_FLOAT, offsetof(LightParams, roundness), 1},
    {"noiseamp", RAYES_PARAM_FLOAT, offsetof(LightParams, noiseamp), 1},
    {"noisefreq", RAYES_PARAM_FLOAT, offsetof(LightParams, noisefreq), 1},
    {"noiseoffset", RAYES_PARAM_COLOR, offsetof(LightParams, noiseoffset), 1},
    {"shadowcolor", RAYES_PARAM_COLOR, offsetof(LightParams, shadowcolor), 1},
    {"shadowcheat", RAYES_PARAM_COLOR, offsetof(LightParams, shadowcheat), 1},
    {"blockermatrix", RAYES_PARAM_FLOATS, offsetof(LightParams, blockermatrix), 1},
    {"blockerwidth", RAYES_PARAM_FLOAT, offsetof(LightParams, blockerwidth), 1},
    {"blockerheight", RAYES_PARAM_FLOAT, offsetof(LightParams, blockerheight), 1},
    {"blockerwedge", RAYES_PARAM_FLOAT, offsetof(LightParams, blockerwedge), 1},
    {"blockerhedge", RAYES_PARAM_FLOAT, offsetof(LightParams, blockerhedge), 1},
    {"blockerround", RAYES_PARAM_FLOAT, offsetof(LightParams, blockerround), 1},
};

/* An area light made as geometry (a quad, a tube) takes the controls its
 * parameters gave l: category, intensity and colour kept apart, shadows,
 * diffuse and specular switches, the cone. */
static void take_controls(Light *made, const Light *l)
{
    memcpy(made->category, l->category, sizeof l->category);
    made->intensity = l->intensity;
    made->color = l->color;
    made->shadowless = l->shadowless;
    made->nondiffuse = l->nondiffuse;
    made->nonspecular = l->nonspecular;
    made->cone = l->cone, made->cone_start = l->cone_start;
}

static RayesError light_params(RayesScene *s, const char *type, const RayesParam *params,
                               size_t n_params, LightParams *lp)
{
    *lp = (LightParams){.intensity = 1,
                        .color = {1, 1, 1},
                        .to = {0, 0, 1},
                        .coneangle = 30,
                        .conedeltaangle = 5,
                        .beamdistribution = NAN,
                        .radius = 1,
                        .width = 1,
                        .height = 1,
                        .fov = 90,
                        .cone = 90,
                        .mapname = "",
                        .mapping = "latlong",
                        .sundirection = {0, 1, 0},
                        .haziness = 2,
                        .groundcolor = {0.18f, 0.18f, 0.18f},
                        .shape = "quad",
                        .category = "",
                        .shadows = 1,
                        .lighttype = "spot",
                        .slidename = "",
                        .cuton = 0.01f,
                        .cutoff = 1e6f,
                        .falloffdist = 1,
                        .maxintensity = 1,
                        .wedge = 0.1f,
                        .hedge = 0.1f,
                        .roundness = 1,
                        .noisefreq = 4,
                        .blockerwidth = 1,
                        .blockerheight = 1,
                        .blockerwedge = 0.1f,
                        .blockerhedge = 0.1f,
                        .blockerround = 1};
    for (size_t i = 0; i < n_params; i++) {
        const RayesParam *p = &params[i];
        if (!p->name)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: a parameter has no name", type);
        const LightParamDesc *d = NULL;
        for (size_t k = 0; k < sizeof light_param_descs / sizeof *light_param_descs; k++)
            if (strcmp(light_param_descs[k].name, p->name) == 0)
                d = &light_param_descs[k];
        if (!d) {
            char key[128];
            snprintf(key, sizeof key, "light:%s:%s", type, p->name);
            log_warning_once(key, "%s has no parameter \"%s\"; ignored", type, p->name);
            continue;
        }
        int ok = p->type == d->type || (d->type == RAYES_PARAM_COLOR && p->type == RAYES_PARAM_FLOAT &&
                                        strcmp(d->name, "lightcolor") == 0);
        if (!ok)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: parameter \"%s\" expects a %s",
                              type, p->name,
                              d->type == RAYES_PARAM_FLOAT    ? "float"
                              : d->type == RAYES_PARAM_COLOR  ? "3-vector (RAYES_PARAM_COLOR)"
                              : d->type == RAYES_PARAM_FLOATS ? "16-float matrix"
                                                              : "string");
        char *dst = (char *)lp + d->offset;
        if (d->type == RAYES_PARAM_FLOATS) { /* a matrix */
            if (!p->floats || p->n_floats != 16 || !scene_finite(p->floats, 16))
                return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                  "%s: parameter \"%s\" expects 16 finite floats", type, p->name);
            *(const float **)dst = p->floats;
            continue;
        }
        if (d->type == RAYES_PARAM_STRING) {
            if (!p->string)
                return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                  "%s: parameter \"%s\" has no string", type, p->name);
            *(const char **)dst = p->string;
            continue;
        }
        if (!scene_finite(p->value, d->type == RAYES_PARAM_FLOAT ? 1 : 3))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: parameter \"%s\" is not finite",
                              type, p->name);
        float *f = (float *)(void *)dst;
        if (d->type == RAYES_PARAM_FLOAT)
            f[0] = p->value[0];
        else
            for (int c = 0; c < 3; c++)
                f[c] = p->value[p->type == RAYES_PARAM_FLOAT ? 0 : c];
    }
    if (lp->intensity < 0 || lp->color[0] < 0 || lp->color[1] < 0 || lp->color[2] < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "%s: expected a non-negative intensity and lightcolor", type);
    if (strlen(lp->category) >= LIGHT_CATEGORY_MAX)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "%s: __category longer than %d characters", type, LIGHT_CATEGORY_MAX - 1);
    return RAYES_OK;
}

/* A light made under a moving transform moves with it (Light.time). */
static void light_motion(const RayesScene *s, Light *l)
{
    l->n_times = 0;
    if (!s->current_motion)
        return;
    const SceneMotion *m = &s->motions[s->current_motion - 1];
    l->n_times = m->n_times;
    memcpy(l->time, m->time, (size_t)m->n_times * sizeof *l->time);
    memcpy(l->delta, m->delta, (size_t)m->n_times * sizeof *l->delta);
}

/* Adds light l and, for emitters, its object and the primitives camera and
 * specular rays see (n_prims of them). */
static RayesError push_light(RayesScene *s, const Light *l, const Prim *prims, size_t n_prims)
{
    if (util_grow((void **)&s->lights, &s->cap_lights, s->n_lights, sizeof *s->lights) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < n_prims; i++)
        if (util_grow((void **)&s->prims, &s->cap_prims, s->n_prims + i, sizeof *s->prims) != 0)
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    if (n_prims) {
        int64_t keep = s->current_object;
        RayesError e = add_object(s, NULL, NULL, 0, (int)s->n_lights);
        s->current_object = keep;
        if (e != RAYES_OK)
            return e;
        for (size_t i = 0; i < n_prims; i++) {
            Prim p = prims[i];
            if (intern_big(s, &p) != RAYES_OK)
                return RAYES_ERROR_OUT_OF_MEMORY;
            p.object = (uint32_t)(s->n_objects - 1);
            p.shading_rate = s->shading_rate;
            p.motion = s->current_motion; /* the emitter moves with the light */
            s->prims[s->n_prims++] = p;
        }
    }
    s->lights[s->n_lights] = *l;
    light_motion(s, &s->lights[s->n_lights++]);
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

#define DISK_FAN 64 /* triangles of the polygon a disk light shows the camera */

/* A light's map (an environment's radiance, or a point or spot light's
 * intensity by direction) in the rotation of m: lp's mapname read with its
 * mapping; a projection's field of view. */
static RayesError light_map(RayesScene *s, const char *type, const LightParams *lp, const Mat4 *m,
                            Light *l)
{
    Mat4 rot = *m;
    rot.m[0][3] = rot.m[1][3] = rot.m[2][3] = 0.0f;
    l->world_from_light = rot;
    mat4_invert(rot, &l->light_from_world);
    int octahedral = strcmp(lp->mapping, "octahedral") == 0;
    int zup = strcmp(lp->mapping, "latlong-zup") == 0;
    int projection = strcmp(lp->mapping, "projection") == 0 && l->type != LIGHT_ENVIRONMENT;
    int sky = strcmp(lp->mapping, "sky") == 0 && l->type == LIGHT_ENVIRONMENT;
    if (!octahedral && !zup && !projection && !sky && strcmp(lp->mapping, "latlong") != 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "%s: unknown mapping \"%s\"; expected latlong, latlong-zup, "
                          "octahedral%s",
                          type, lp->mapping,
                          l->type != LIGHT_ENVIRONMENT ? " or projection" : " or sky");
    if (sky) { /* a clear sky of its sun, no map */
        char err[400];
        if (!(lp->haziness > 0.0f && lp->haziness < 100.0f))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: expected a sky's haziness in (0, 100)", type);
        if (light_env_sky(l, lp->sundirection, lp->haziness, lp->groundcolor, err, sizeof err) != 0)
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "%s", err);
        return RAYES_OK;
    }
    if (projection && !(lp->fov > 0.0f && lp->fov < 180.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "%s: expected a projection's fov in (0, 180) degrees", type);
    l->map_projection = projection;
    l->map_tan = projection ? tanf(lp->fov * (float)(M_PI / 360.0)) : 0.0f;
    if (!lp->mapname[0])
        return RAYES_OK;
    char err[400], path[1024];
    if (scene_find_texture(s, lp->mapname, path, sizeof path) != 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: map name too long", type);
    int layout = octahedral ? LIGHT_MAP_OCTAHEDRAL
                 : zup      ? LIGHT_MAP_LATLONG_ZUP
                            : LIGHT_MAP_LATLONG;
    if (light_env_load(l, path, layout, err, sizeof err) != 0)
        return scene_fail(s, RAYES_ERROR_IO, "%s", err);
    return RAYES_OK;
}

/* Whether a light parameter is an uberlight's alone. */
static int uber_only(const char *name)
{
    for (size_t k = 0; k < sizeof light_param_descs / sizeof *light_param_descs; k++)
        if (strcmp(light_param_descs[k].name, name) == 0)
            return light_param_descs[k].uber;
    return 0;
}

/* Barzel's light (uberlight): its space is the current transform; lp's
 * shaping checked and kept in l->uber (DESIGN.md "Lights"). */
static RayesError uber_light(RayesScene *s, const LightParams *lp, Light *l)
{
    LightUber *u = &l->uber;
    const char *lt = lp->lighttype;
    if (strcmp(lt, "spot") != 0 && strcmp(lt, "omni") != 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "uberlight: unknown lighttype \"%.40s\"; expected spot or omni", lt);
    if (!(lp->width > 0.0f) || !(lp->height > 0.0f) || lp->wedge < 0.0f || lp->hedge < 0.0f ||
        lp->roundness < 0.0f || lp->roundness > 1.0f || lp->beamdistribution < 0.0f)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "uberlight: expected a positive width and height, wedge, hedge and "
                          "beamdistribution >= 0 and roundness in [0, 1]");
    if (lp->nearedge < 0.0f || lp->faredge < 0.0f || lp->cutoff < lp->cuton ||
        !(lp->falloffdist > 0.0f) || !(lp->maxintensity > 0.0f) || lp->falloff < 0.0f ||
        lp->noiseamp < 0.0f)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "uberlight: expected nearedge, faredge, falloff and noiseamp >= 0, "
                          "cutoff >= cuton and a positive falloffdist and maxintensity");
    if (lp->blockermatrix &&
        (!(lp->blockerwidth > 0.0f) || !(lp->blockerheight > 0.0f) || lp->blockerwedge < 0.0f ||
         lp->blockerhedge < 0.0f || lp->blockerround < 0.0f || lp->blockerround > 1.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "uberlight: expected a positive blockerwidth and blockerheight, "
                          "blockerwedge and blockerhedge >= 0 and blockerround in [0, 1]");
    l->type = LIGHT_UBER;
    l->world_from_light = s->world_from_object;
    if (!mat4_invert(l->world_from_light, &l->light_from_world))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "uberlight: a singular transform");
    l->from = mat4_point(&l->world_from_light, v3(0, 0, 0));
    l->dir = v3_normalize(mat4_vector(&l->world_from_light, v3(0, 0, 1)));
    u->omni = strcmp(lt, "omni") == 0;
    u->parallel = lp->parallelrays != 0.0f;
    u->cuton = lp->cuton;
    u->cutoff = lp->cutoff;
    u->nearedge = lp->nearedge;
    u->faredge = lp->faredge;
    u->falloff = lp->falloff;
    u->falloffdist = lp->falloffdist;
    u->maxintensity = lp->maxintensity;
    u->maxratio = lp->intensity > 0.0f ? lp->maxintensity / lp->intensity : 1.0f;
    u->shearx = lp->shearx;
    u->sheary = lp->sheary;
    u->width = lp->width;
    u->height = lp->height;
    u->wedge = lp->wedge;
    u->hedge = lp->hedge;
    u->roundness = lp->roundness;
    u->beam = lp->beamdistribution;
    /* the cone RenderMan's illuminate() lets light through: the
     * cross-section's farthest corner, sheared, with room to spare */
    float r = 1.4142136f * fmaxf(lp->height + lp->hedge + fabsf(lp->sheary),
                                 lp->width + lp->wedge + fabsf(lp->shearx));
    u->cos_cone = 1.0f / sqrtf(1.0f + r * r);
    u->noiseamp = lp->noiseamp;
    u->noisefreq = lp->noisefreq;
    u->noiseoffset = v3_load(lp->noiseoffset);
    u->shadowcolor = v3_load(lp->shadowcolor);
    u->cheat = v3_load(lp->shadowcheat);
    if (lp->blockermatrix) {
        if (!mat4_invert(mat4_from_array(lp->blockermatrix), &u->blocker_from_world))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "uberlight: a singular blockermatrix");
        u->blocker = 1;
        u->bwidth = lp->blockerwidth;
        u->bheight = lp->blockerheight;
        u->bwedge = lp->blockerwedge;
        u->bhedge = lp->blockerhedge;
        u->bround = lp->blockerround;
    }
    if (lp->slidename[0]) {
        char err[400], path[1024];
        if (scene_find_texture(s, lp->slidename, path, sizeof path) != 0)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "uberlight: slide name too long");
        if (light_env_load(l, path, LIGHT_MAP_LATLONG, err, sizeof err) != 0)
            return scene_fail(s, RAYES_ERROR_IO, "uberlight slide: %s", err);
        u->slide = 1;
    }
    RayesError e = push_light(s, l, NULL, 0);
    if (e != RAYES_OK)
        light_fini(l);
    return e;
}

RayesError rayes_scene_light(RayesScene *s, const char *type, const RayesParam *params,
                             size_t n_params)
{
    if (!s || !type || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->open_master >= 0)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "light: not allowed in an object block");
    static const char *const types[] = {"pointlight",   "spotlight",        "distantlight",
                                        "ambientlight", "environmentlight", "arealight",
                                        "uberlight"};
    int t = -1;
    for (int k = 0; k < 7; k++)
        if (strcmp(type, types[k]) == 0)
            t = k;
    if (t < 0)
        return scene_fail(
            s, RAYES_ERROR_INVALID_ARGUMENT,
            "unknown light type \"%s\"; expected pointlight, spotlight, distantlight, "
            "ambientlight, environmentlight, arealight or uberlight",
            type);
    LightParams lp;
    RayesError e = light_params(s, type, params, n_params, &lp);
    if (e != RAYES_OK)
        return e;
    if (isnan(lp.beamdistribution)) /* RenderMan's defaults */
        lp.beamdistribution = t == 6 ? 0.0f : 2.0f;
    for (size_t i = 0; t != 6 && i < n_params; i++) /* the shaping is uberlight's alone */
        if (uber_only(params[i].name)) {
            char key[128];
            snprintf(key, sizeof key, "light:%s:%s", type, params[i].name);
            log_warning_once(key, "%s has no parameter \"%s\" (an uberlight's); ignored", type,
                             params[i].name);
        }
    Light l;
    memset(&l, 0, sizeof l);
    snprintf(l.category, sizeof l.category, "%s", lp.category);
    l.shadowless = lp.shadows == 0.0f;
    l.nondiffuse = lp.nondiffuse != 0.0f;
    l.nonspecular = lp.nonspecular != 0.0f;
    l.L = v3_scale(v3_load(lp.color), lp.intensity);
    l.intensity = lp.intensity;
    l.color = v3_load(lp.color);
    if (t == 6)
        return uber_light(s, &lp, &l);
    const Mat4 *m = &s->world_from_object;
    l.from = mat4_point(m, v3_load(lp.from));
    Vec3 to = mat4_point(m, v3_load(lp.to));
    if (t < 2 && lp.mapname[0]) { /* a point or spot light's intensity by direction */
        e = light_map(s, type, &lp, m, &l);
        if (e != RAYES_OK)
            return e;
    }
    switch (t) {
    case 0:
        l.type = LIGHT_POINT;
        e = push_light(s, &l, NULL, 0);
        if (e != RAYES_OK)
            light_fini(&l);
        return e;
    case 1:
    case 2:
        l.type = t == 1 ? LIGHT_SPOT : LIGHT_DISTANT;
        l.dir = v3_normalize(v3_sub(to, l.from));
        if (!(v3_length(v3_sub(to, l.from)) > 0.0f))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: \"from\" and \"to\" coincide",
                              type);
        if (t == 1) {
            if (!(lp.coneangle > 0.0f && lp.coneangle <= 180.0f) || lp.conedeltaangle < 0.0f ||
                lp.beamdistribution < 0.0f)
                return scene_fail(
                    s, RAYES_ERROR_INVALID_ARGUMENT,
                    "spotlight: expected coneangle in (0, 180], conedeltaangle >= 0 and "
                    "beamdistribution >= 0 (degrees)");
            float rad = (float)(M_PI / 180.0);
            l.cos_outer = cosf(lp.coneangle * rad);
            l.cos_inner = cosf(fmaxf(lp.coneangle - lp.conedeltaangle, 0.0f) * rad);
            l.beam = lp.beamdistribution;
        }
        e = push_light(s, &l, NULL, 0);
        if (e != RAYES_OK)
            light_fini(&l);
        return e;
    case 3:
        l.type = LIGHT_AMBIENT;
        return push_light(s, &l, NULL, 0);
    case 4: {
        l.type = LIGHT_ENVIRONMENT;
        l.seen_by = s->current_visibility;
        e = light_map(s, type, &lp, m, &l);
        if (e == RAYES_OK)
            e = push_light(s, &l, NULL, 0);
        if (e != RAYES_OK)
            light_fini(&l);
        return e;
    }
    default:
        break;
    }
    /* arealight */
    if (!(lp.cone > 0.0f && lp.cone <= 180.0f) ||
        !(lp.conesoftness >= 0.0f && lp.conesoftness <= 1.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "arealight: expected a cone in (0, 180] degrees and a conesoftness in "
                          "[0, 1]");
    float cone = lp.cone < 90.0f ? lp.cone * (float)(M_PI / 180.0) : 0.0f; /* 90: none */
    l.cone = cone, l.cone_start = cone * (1.0f - lp.conesoftness);
    if (strcmp(lp.shape, "quad") == 0) {
        if (!(lp.width > 0.0f) || !(lp.height > 0.0f))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "arealight: expected a positive width and height");
        float w = 0.5f * lp.width, h = 0.5f * lp.height;
        const float P[4][3] = {{-w, -h, 0}, {w, -h, 0}, {w, h, 0}, {-w, h, 0}};
        float L[3] = {l.L.x, l.L.y, l.L.z};
        if (lp.mapname[0]) { /* an image over it (PxrRectLight's lightColorMap): upright seen
                                from the side it lights, its top at +y */
            static const float st[8] = {0, 1, 1, 1, 1, 0, 0, 0};
            static const int nv[1] = {4}, idx[4] = {0, 1, 2, 3};
            if (cone > 0.0f)
                log_warning_once("textured quad cone", "arealight: a quad with a map lights "
                                                       "without its cone");
            e = rayes_scene_area_light_mesh_textured(s, 1, nv, idx, 4, &P[0][0], st, L, 0,
                                                     lp.mapname);
            if (e == RAYES_OK) {
                Light *made = &s->lights[s->n_lights - 1];
                take_controls(made, &l);
                made->cone = made->cone_start = 0.0f;
            }
            return e;
        }
        e = rayes_scene_area_light(s, P, L);
        if (e == RAYES_OK)
            take_controls(&s->lights[s->n_lights - 1], &l);
        return e;
    }
    if (!(lp.radius > 0.0f))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "arealight: expected a positive radius");
    if (strcmp(lp.shape, "cylinder") == 0) { /* RenderMan's tube: along object x, width long */
        if (!(lp.width > 0.0f))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "arealight: expected a cylinder of positive width (its length)");
        enum { SIDES = 32 };
        float P[2 * SIDES][3], w = 0.5f * lp.width, L[3] = {l.L.x, l.L.y, l.L.z};
        int nv[SIDES], idx[4 * SIDES];
        for (int k = 0; k < SIDES; k++) {
            float a = 2.0f * (float)M_PI * (float)k / SIDES;
            float y = lp.radius * cosf(a), z = lp.radius * sinf(a);
            P[2 * k][0] = -w, P[2 * k][1] = y, P[2 * k][2] = z;
            P[2 * k + 1][0] = w, P[2 * k + 1][1] = y, P[2 * k + 1][2] = z;
            int n = (k + 1) % SIDES; /* counter-clockwise seen from outside */
            nv[k] = 4;
            idx[4 * k] = 2 * k, idx[4 * k + 1] = 2 * n, idx[4 * k + 2] = 2 * n + 1;
            idx[4 * k + 3] = 2 * k + 1;
        }
        e = rayes_scene_area_light_mesh(s, SIDES, nv, idx, 2 * SIDES, &P[0][0], L, 0);
        if (e == RAYES_OK)
            take_controls(&s->lights[s->n_lights - 1], &l);
        return e;
    }
    if (strcmp(lp.shape, "sphere") == 0) {
        l.type = LIGHT_SPHERE;
        l.from = mat4_point(m, v3(0, 0, 0));
        l.radius = lp.radius * v3_length(mat4_vector(m, v3(1, 0, 0)));
        PrimBig big;
        Prim p = {.type = PRIM_SPHERE, .big = &big};
        Mat4 inv;
        mat4_invert(*m, &inv);
        p.big->sphere.world_from_object = *m;
        p.big->sphere.normal_from_object = mat4_transpose(inv);
        p.big->sphere.radius = lp.radius;
        return push_light(s, &l, &p, 1);
    }
    if (strcmp(lp.shape, "disk") == 0) {
        l.type = LIGHT_DISK;
        l.from = mat4_point(m, v3(0, 0, 0));
        l.ex = mat4_vector(m, v3(lp.radius, 0, 0));
        l.ey = mat4_vector(m, v3(0, lp.radius, 0));
        Vec3 n = v3_cross(l.ex, l.ey);
        l.area = (float)M_PI * v3_length(n);
        l.normal = v3_normalize(n);
        if (!(l.area > 0.0f))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "arealight: the disk has no area");
        Prim fan[DISK_FAN];
        for (int k = 0; k < DISK_FAN; k++) {
            float a0 = 2.0f * (float)M_PI * (float)k / DISK_FAN;
            float a1 = 2.0f * (float)M_PI * (float)(k + 1) / DISK_FAN;
            fan[k] = (Prim){.type = PRIM_TRIANGLE};
            fan[k].cp[0] = l.from;
            fan[k].cp[1] = v3_add(l.from, v3_add(v3_scale(l.ex, cosf(a0)), v3_scale(l.ey, sinf(a0))));
            fan[k].cp[2] = v3_add(l.from, v3_add(v3_scale(l.ex, cosf(a1)), v3_scale(l.ey, sinf(a1))));
        }
        return push_light(s, &l, fan, DISK_FAN);
    }
    return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                      "arealight: unknown shape \"%s\"; expected quad, disk, sphere or cylinder",
                      lp.shape);
}

/* ------------------------------------------------------------ edits */

size_t rayes_scene_light_count(const RayesScene *s)
{
    return s ? s->n_lights : 0;
}

size_t rayes_scene_object_count(const RayesScene *s)
{
    return s ? s->n_objects : 0;
}

const char *rayes_scene_object_shader(const RayesScene *s, size_t object)
{
    if (!s || object >= s->n_objects || !s->objects[object].shader.cls)
        return "";
    return s->objects[object].shader.cls->name;
}

int64_t rayes_scene_object_light(const RayesScene *s, size_t object)
{
    if (!s || object >= s->n_objects)
        return -1;
    return s->objects[object].light;
}

/* Moves a primitive by d (world space). */
static void translate_prim(Prim *p, Vec3 d)
{
    if (p->type == PRIM_SPHERE) {
        for (int k = 0; k < 3; k++)
            p->big->sphere.world_from_object.m[k][3] += k == 0 ? d.x : k == 1 ? d.y : d.z;
        return;
    }
    int n = p->type == PRIM_BICUBIC ? 16 : p->type == PRIM_TRIANGLE ? 3 : 4;
    Vec3 *cp = p->type == PRIM_BICUBIC ? p->big->cp : p->cp;
    for (int k = 0; k < n; k++)
        cp[k] = v3_add(cp[k], d);
}

RayesError rayes_scene_edit_light(RayesScene *s, size_t index, const RayesParam *params,
                                  size_t n_params)
{
    if (!s || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (index >= s->n_lights)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "edit light: no light %zu (the scene has %zu)", index, s->n_lights);
    Light *l = &s->lights[index];
    float intensity = l->intensity;
    Vec3 color = l->color, d = v3(0, 0, 0);
    for (size_t i = 0; i < n_params; i++) {
        const RayesParam *p = &params[i];
        const char *name = p->name ? p->name : "";
        int is_float = p->type == RAYES_PARAM_FLOAT, is_color = p->type == RAYES_PARAM_COLOR;
        if (!scene_finite(p->value, is_color ? 3 : 1) && (is_float || is_color))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "edit light: \"%s\" is not finite",
                              name);
        if (strcmp(name, "intensity") == 0 && is_float && p->value[0] >= 0.0f)
            intensity = p->value[0];
        else if (strcmp(name, "lightcolor") == 0 && (is_float || is_color) && p->value[0] >= 0.0f &&
                 (is_float || (p->value[1] >= 0.0f && p->value[2] >= 0.0f)))
            color = is_float ? v3(p->value[0], p->value[0], p->value[0]) : v3_load(p->value);
        else if (strcmp(name, "translate") == 0 && is_color)
            d = v3_add(d, v3_load(p->value));
        else
            return scene_fail(
                s, RAYES_ERROR_INVALID_ARGUMENT,
                "edit light: expected \"intensity\" (a float >= 0), \"lightcolor\" (a "
                "colour >= 0) or \"translate\" (a vector), not \"%s\"",
                name);
    }
    l->intensity = intensity;
    l->color = color;
    l->L = v3_scale(color, intensity);
    if (l->type == LIGHT_UBER) { /* maxintensity stays what it was */
        l->uber.maxratio = intensity > 0.0f ? l->uber.maxintensity / intensity : 1.0f;
        l->world_from_light.m[0][3] += d.x; /* moved with "translate" */
        l->world_from_light.m[1][3] += d.y;
        l->world_from_light.m[2][3] += d.z;
        mat4_invert(l->world_from_light, &l->light_from_world);
    }
    scene_mark(s, SCENE_CHANGE_SHADING);
    if (v3_length(d) == 0.0f || l->type == LIGHT_DISTANT || l->type == LIGHT_AMBIENT ||
        l->type == LIGHT_ENVIRONMENT)
        return RAYES_OK;
    for (int k = 0; k < 4; k++)
        l->P[k] = v3_add(l->P[k], d);
    l->from = v3_add(l->from, d);
    if (l->mesh) {
        for (size_t k = 0; k < 3 * l->mesh->n; k++)
            l->mesh->v[k] = v3_add(l->mesh->v[k], d);
        l->mesh->lo = v3_add(l->mesh->lo, d);
        l->mesh->hi = v3_add(l->mesh->hi, d);
        for (int c = 0; c < l->mesh->n_clusters; c++) {
            l->mesh->cluster[c].lo = v3_add(l->mesh->cluster[c].lo, d);
            l->mesh->cluster[c].hi = v3_add(l->mesh->cluster[c].hi, d);
            l->mesh->cluster[c].centre = v3_add(l->mesh->cluster[c].centre, d);
        }
    }
    for (size_t i = 0; i < s->n_prims; i++)
        if (s->objects[s->prims[i].object].light == (int)index) {
            translate_prim(&s->prims[i], d);
            scene_mark(s, SCENE_CHANGE_GEOMETRY);
        }
    return RAYES_OK;
}

RayesError rayes_scene_get_light(const RayesScene *s, size_t index, float *intensity,
                                 float color[3], float position[3])
{
    if (!s || index >= s->n_lights)
        return RAYES_ERROR_INVALID_ARGUMENT;
    const Light *l = &s->lights[index];
    Vec3 at = l->from;
    if (l->type == LIGHT_QUAD)
        at = v3_scale(v3_add(v3_add(l->P[0], l->P[1]), v3_add(l->P[2], l->P[3])), 0.25f);
    else if (l->type == LIGHT_MESH) /* its bounding box's centre */
        at = v3_scale(v3_add(l->mesh->lo, l->mesh->hi), 0.5f);
    else if (l->type != LIGHT_POINT && l->type != LIGHT_SPOT && l->type != LIGHT_DISK &&
             l->type != LIGHT_SPHERE && l->type != LIGHT_UBER)
        at = v3(0, 0, 0);
    if (intensity)
        *intensity = l->intensity;
    if (color) {
        color[0] = l->color.x;
        color[1] = l->color.y;
        color[2] = l->color.z;
    }
    if (position) {
        position[0] = at.x;
        position[1] = at.y;
        position[2] = at.z;
    }
    return RAYES_OK;
}

RayesError rayes_scene_edit_shader(RayesScene *s, size_t object, const RayesParam *params,
                                   size_t n_params)
{
    if (!s || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (object >= s->n_objects)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "edit shader: no object %zu (the scene has %zu)", object, s->n_objects);
    SceneObject *o = &s->objects[object];
    if (!o->shader.cls)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "edit shader: object %zu is light %d's emitter; edit the light", object,
                          o->light);
    const RayesShaderClass *cls = o->shader.cls;
    ShaderInstance trial = {cls, malloc(cls->params_size ? cls->params_size : 1)};
    RayesParam *rest = malloc((n_params ? n_params : 1) * sizeof *rest);
    if (!trial.params || !rest) {
        free(trial.params);
        free(rest);
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    memcpy(trial.params, o->shader.params, cls->params_size);
    float Cs[3], Os[3];
    memcpy(Cs, o->Cs, sizeof Cs);
    memcpy(Os, o->Os, sizeof Os);
    size_t n_rest = 0;
    for (size_t i = 0; i < n_params; i++) {
        const RayesParam *p = &params[i];
        int n = p->type == RAYES_PARAM_COLOR ? 3 : 1;
        if (!p->name || ((p->type == RAYES_PARAM_FLOAT || p->type == RAYES_PARAM_COLOR) &&
                         !scene_finite(p->value, (size_t)n))) {
            free(trial.params);
            free(rest);
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "edit shader: a parameter has no name or is not finite");
        }
        if (o->shader.n_children && (strcmp(p->name, "a") == 0 || strcmp(p->name, "b") == 0)) {
            free(trial.params);
            free(rest);
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "edit shader: a mix's materials (\"%s\") cannot be edited; its "
                              "\"amount\" can",
                              p->name);
        }
        float *dst = strcmp(p->name, "Cs") == 0 ? Cs : strcmp(p->name, "Os") == 0 ? Os : NULL;
        if (dst && (p->type == RAYES_PARAM_FLOAT || p->type == RAYES_PARAM_COLOR)) {
            for (int c = 0; c < 3; c++)
                dst[c] = p->value[n == 1 ? 0 : c];
            continue;
        }
        rest[n_rest++] = *p;
    }
    char err[256];
    if (shade_instance_apply(&trial, rest, n_rest, 1, err, sizeof err) != 0) {
        free(trial.params);
        free(rest);
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "edit shader: %s", err);
    }
    /* the bindings too are edited on a copy, kept only if all succeed */
    for (size_t i = 0; i < o->shader.n_patterns; i++)
        if (shade_instance_bind(&trial, o->shader.patterns[i].param, o->shader.patterns[i].pattern,
                                err, sizeof err) != 0)
            break;
    RayesError e = trial.n_patterns == o->shader.n_patterns
                       ? scene_bind_patterns(s, &trial, rest, n_rest)
                       : scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    free(rest);
    if (e != RAYES_OK) {
        shade_instance_fini(&trial);
        return e;
    }
    trial.children = o->shader.children; /* a mix keeps its materials (and the
                                            pointer its block holds to them) */
    trial.n_children = o->shader.n_children;
    o->shader.children = NULL;
    o->shader.n_children = 0;
    shade_instance_fini(&o->shader);
    o->shader = trial;
    memcpy(o->Cs, Cs, sizeof Cs);
    memcpy(o->Os, Os, sizeof Os);
    scene_mark(s, SCENE_CHANGE_SHADING);
    return RAYES_OK;
}

RayesError rayes_scene_get_camera(const RayesScene *s, float eye[3], float x[3], float y[3],
                                  float z[3])
{
    if (!s || !eye || !x || !y || !z)
        return RAYES_ERROR_INVALID_ARGUMENT;
    const SceneCamera *c = &s->camera;
    const Vec3 *from[4] = {&c->eye, &c->x, &c->y, &c->z};
    float *to[4] = {eye, x, y, z};
    for (int k = 0; k < 4; k++) {
        to[k][0] = from[k]->x;
        to[k][1] = from[k]->y;
        to[k][2] = from[k]->z;
    }
    return RAYES_OK;
}

RayesError rayes_scene_move_camera(RayesScene *s, const float m[16])
{
    if (!s || !m)
        return RAYES_ERROR_INVALID_ARGUMENT;
    Mat4 inv, M = mat4_from_array(m);
    if (!scene_finite(m, 16) || !mat4_invert(M, &inv))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "move camera: expected a finite, invertible matrix");
    SceneCamera *c = &s->camera;
    c->eye = mat4_point(&M, c->eye);
    c->x = mat4_vector(&M, c->x);
    c->y = mat4_vector(&M, c->y);
    c->z = mat4_vector(&M, c->z);
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

/* ------------------------------------------------------- search paths */

/* Kind names of rayes_scene_set_search_path, by SceneSearchPath. */
static const char *const search_path_kinds[SCENE_SEARCH_PATH_COUNT] = {
    [SCENE_SEARCH_PATH_SHADER] = "shader",
    [SCENE_SEARCH_PATH_TEXTURE] = "texture",
};

#define SEARCH_PATH_MAX 65536 /* characters, after expanding "&" */

const char *scene_search_path(const RayesScene *s, SceneSearchPath kind)
{
    return s->search_paths[kind] ? s->search_paths[kind] : "";
}

/* path with each entry "&" or "@" replaced by prev, empty entries dropped;
 * NULL when too long or out of memory (*too_long says which). */
static char *expand_search_path(const char *path, const char *prev, int *too_long)
{
    size_t len = 0, cap = strlen(path) + 1;
    for (const char *p = path; *p; p++)
        cap += (*p == '&' || *p == '@') ? strlen(prev) : 0;
    *too_long = cap > SEARCH_PATH_MAX;
    char *out = *too_long ? NULL : malloc(cap);
    if (!out)
        return NULL;
    out[0] = '\0';
    for (const char *d = path; *d;) {
        size_t n = strcspn(d, ":");
        const char *text = d;
        size_t tn = n;
        if (n == 1 && (d[0] == '&' || d[0] == '@')) {
            text = prev;
            tn = strlen(prev);
        }
        if (tn > 0) {
            if (len > 0)
                out[len++] = ':';
            memcpy(out + len, text, tn);
            len += tn;
            out[len] = '\0';
        }
        d += n + (d[n] == ':');
    }
    return out;
}

RayesError rayes_scene_set_search_path(RayesScene *s, const char *kind, const char *path)
{
    if (!s || !kind || !path)
        return RAYES_ERROR_INVALID_ARGUMENT;
    int k = 0;
    while (k < SCENE_SEARCH_PATH_COUNT && strcmp(search_path_kinds[k], kind) != 0)
        k++;
    if (k == SCENE_SEARCH_PATH_COUNT)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "search path: unknown kind \"%.64s\"; expected \"shader\" or \"texture\"",
                          kind);
    int too_long;
    char *expanded = expand_search_path(path, scene_search_path(s, (SceneSearchPath)k), &too_long);
    if (!expanded)
        return too_long ? scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                     "search path \"%s\": longer than %d characters", kind,
                                     SEARCH_PATH_MAX)
                        : scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    free(s->search_paths[k]);
    s->search_paths[k] = expanded;
    return RAYES_OK;
}



/* RenderMan's quadrics: checks the parameters and stores them with angles
 * in radians (the sphere's zmin, zmax as latitudes). */
/* The primitive of a quadric (rayes.h's parameters, checked), its
 * transform and parameters in *big (out->big points there). */
static RayesError quadric_prim(RayesScene *s, RayesQuadric type, const float *params, size_t n,
                               unsigned flags, Prim *out, PrimBig *big)
{
    static const struct {
        const char *name, *params;
        size_t n;
    } kinds[] = {
        {"sphere", "radius zmin zmax thetamax", 4},   {"cylinder", "radius zmin zmax thetamax", 4},
        {"cone", "height radius thetamax", 3},         {"disk", "height radius thetamax", 3},
        {"paraboloid", "rmax zmin zmax thetamax", 4},  {"hyperboloid", "x1 y1 z1 x2 y2 z2 thetamax", 7},
        {"torus", "rmajor rminor phimin phimax thetamax", 5},
    };
    if (!s || (n && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if ((unsigned)type > RAYES_QUADRIC_TORUS)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "quadric: unknown type %d", (int)type);
    const char *name = kinds[type].name;
    if (n != kinds[type].n || !scene_finite(params, n))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: expected %zu finite numbers (%s)",
                          name, kinds[type].n, kinds[type].params);
    const float deg = (float)(M_PI / 180.0);
    float thetamax = params[n - 1];
    if (!(thetamax != 0.0f) || fabsf(thetamax) > 360.0f)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: expected 0 < |thetamax| <= 360",
                          name);
    *big = (PrimBig){0};
    Prim p = {.type = PRIM_QUADRIC, .big = big};
    p.big->quadric.world_from_object = s->world_from_object;
    p.big->quadric.kind = (int)type;
    p.big->quadric.reverse = (flags & RAYES_QUADRIC_REVERSE) != 0;
    memcpy(p.big->quadric.p, params, n * sizeof *params);
    p.big->quadric.p[n - 1] = thetamax * deg;
    const float *q = params;
    const char *bad = NULL;
    switch (type) {
    case RAYES_QUADRIC_SPHERE: {
        float r = q[0], lo = fmaxf(fminf(q[1], q[2]), -r), hi = fminf(fmaxf(q[1], q[2]), r);
        if (!(r > 0.0f) || !(lo < hi))
            bad = "a positive radius and zmin != zmax overlapping [-radius, radius]";
        else {
            p.big->quadric.p[1] = asinf(lo / r);
            p.big->quadric.p[2] = asinf(hi / r);
        }
        break;
    }
    case RAYES_QUADRIC_CYLINDER:
        if (!(q[0] > 0.0f) || !(q[1] != q[2]))
            bad = "a positive radius and zmin != zmax";
        break;
    case RAYES_QUADRIC_CONE:
    case RAYES_QUADRIC_DISK:
        if (!(q[1] > 0.0f) || (type == RAYES_QUADRIC_CONE && !(q[0] != 0.0f)))
            bad = "a positive radius (and a cone's nonzero height)";
        break;
    case RAYES_QUADRIC_PARABOLOID:
        if (!(q[0] > 0.0f) || !(q[2] > 0.0f) || !(q[1] >= 0.0f) || !(q[1] != q[2]))
            bad = "rmax > 0, zmax > 0 and 0 <= zmin != zmax";
        break;
    case RAYES_QUADRIC_HYPERBOLOID:
        if (!(q[0] != q[3] || q[1] != q[4] || q[2] != q[5]) ||
            (q[0] == 0 && q[1] == 0 && q[3] == 0 && q[4] == 0))
            bad = "two different points, not both on the z axis";
        break;
    case RAYES_QUADRIC_TORUS:
        if (!(q[1] > 0.0f) || !(q[2] != q[3]))
            bad = "rminor > 0 and phimin != phimax";
        else {
            p.big->quadric.p[2] = q[2] * deg;
            p.big->quadric.p[3] = q[3] * deg;
        }
        break;
    }
    if (bad)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: expected %s", name, bad);
    *out = p;
    return RAYES_OK;
}

RayesError rayes_scene_quadric(RayesScene *s, RayesQuadric type, const float *params, size_t n,
                               unsigned flags)
{
    Prim p;
    PrimBig big;
    RayesError e = quadric_prim(s, type, params, n, flags, &p, &big);
    if (e != RAYES_OK)
        return e;
    return add_prim(s, &p);
}

/* A quadric's steps around z (u) and along its profile (v) for a mesh
 * light: about 64 for a full turn, 32 over a half circle of profile, one
 * for straight profiles. */
static void quadric_steps(const Prim *p, int *nu, int *nv)
{
    const float *q = p->big->quadric.p;
    static const int theta_at[7] = {3, 3, 2, 2, 3, 6, 4}; /* thetamax's index by kind */
    float turns = fabsf(q[theta_at[p->big->quadric.kind]]) / (2.0f * (float)M_PI);
    *nu = (int)ceilf(64.0f * turns);
    *nu = *nu < 8 ? 8 : *nu;
    *nv = 1;
    if (p->big->quadric.kind == RAYES_QUADRIC_SPHERE)
        *nv = (int)ceilf(32.0f * fabsf(q[2] - q[1]) / (float)M_PI);
    else if (p->big->quadric.kind == RAYES_QUADRIC_TORUS)
        *nv = (int)ceilf(32.0f * fabsf(q[3] - q[2]) / (float)M_PI);
    else if (p->big->quadric.kind == RAYES_QUADRIC_PARABOLOID)
        *nv = 16;
    *nv = *nv < 1 ? 1 : *nv;
}

/* The quadric tessellated (quads of (u, v) steps, wound as dPdu x dPdv
 * faces: its front) and made a mesh light. */
RayesError rayes_scene_area_light_quadric(RayesScene *s, RayesQuadric type, const float *params,
                                          size_t n, unsigned flags, const float L[3], int two_sided)
{
    if (!s || !L)
        return RAYES_ERROR_INVALID_ARGUMENT;
    Prim p;
    PrimBig big;
    RayesError e = quadric_prim(s, type, params, n, flags, &p, &big);
    if (e != RAYES_OK)
        return e;
    int nu, nv;
    quadric_steps(&p, &nu, &nv);
    size_t n_points = (size_t)(nu + 1) * (size_t)(nv + 1), n_faces = (size_t)nu * (size_t)nv;
    float *P = malloc(3 * n_points * sizeof *P);
    int *nverts = malloc(n_faces * sizeof *nverts), *idx = malloc(4 * n_faces * sizeof *idx);
    if (!P || !nverts || !idx) {
        free(P);
        free(nverts);
        free(idx);
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++) {
            Vec3 x, du, dv;
            geom_quadric_eval(&p, (float)i / (float)nu, (float)j / (float)nv, &x, &du, &dv);
            v3_store(&P[3 * ((size_t)j * (size_t)(nu + 1) + (size_t)i)], x);
        }
    size_t k = 0;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            int a = j * (nu + 1) + i;
            nverts[k / 4] = 4;
            idx[k++] = a, idx[k++] = a + 1, idx[k++] = a + nu + 2, idx[k++] = a + nu + 1;
        }
    e = rayes_scene_area_light_mesh(s, n_faces, nverts, idx, n_points, P, L, two_sided);
    free(P);
    free(nverts);
    free(idx);
    return e;
}
