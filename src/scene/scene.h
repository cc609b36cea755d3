/*
 * scene/scene.h — the state machine behind rayes.h's scene calls, and
 * prepare: a committed scene diced into a GridSet for rendering.
 *
 * Every set_shader call makes a new object (a shader instance, colour,
 * opacity, ray visibility); geometry added afterwards belongs to it. Area
 * lights make their own objects. Primitives are stored in world space.
 *
 * Thread-safety: one editing thread at a time (rayes.h); prepare reads a
 * committed scene and may run concurrently with other prepares.
 */
#ifndef RAYES_SCENE_SCENE_H
#define RAYES_SCENE_SCENE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "geom/geom.h"
#include "shade/light.h"
#include "shade/shade.h"
#include "util/vec.h"

/* The kinds of rayes_scene_set_search_path, indexing RayesScene.search_path. */
typedef enum ScenePathKind {
    SCENE_PATH_TEXTURE = 0,
    SCENE_N_PATH_KINDS
} ScenePathKind;

/* The kind's name in the API ("texture"). */
const char *scene_path_kind_name(ScenePathKind kind);

typedef struct SceneObject {
    ShaderInstance shader;    /* owned; cls NULL for lights */
    float Cs[3], Os[3];       /* surface colour and opacity */
    int light;                /* light index, or -1 */
    uint32_t ray_mask;        /* RayesRayType bits of the rays that see it */
} SceneObject;

struct RayesScene {
    atomic_int refs;
    char error[512];          /* the first error since the last clear */
    Vec3 eye, target, up;     /* camera */
    float fov_y;              /* degrees */
    Mat4 world_from_object;   /* the current transform */
    float shading_rate;       /* the current shading rate */
    int64_t current_object;   /* object of geometry added next; -1: make a default matte */
    Prim *prims;
    size_t n_prims, cap_prims;
    SceneObject *objects;
    size_t n_objects, cap_objects;
    Light *lights;
    size_t n_lights, cap_lights;
    uint64_t timestamp;       /* commits so far */
    int dirty;                /* edited since the last commit */
    char *search_path[SCENE_N_PATH_KINDS]; /* colon-separated directories, owned, or NULL */
};

/* Dices every primitive of a committed scene for a camera that sees
 * `height` pixels over its vertical field of view. Returns 0, or -1 when
 * out of memory. */
int scene_prepare(const RayesScene *scene, int height, GridSet *gs);

/* The bounds of all primitives' control points (lights included). */
Bounds3 scene_bounds(const RayesScene *scene);

#endif /* RAYES_SCENE_SCENE_H */
