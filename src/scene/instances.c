/*
 * scene/instances.c — rayes_scene_object_begin, _end and _instance
 * (rayes.h): masters and the instances that place them (scene.h
 * SceneMaster, SceneInstance; DESIGN.md "Instances").
 *
 * A block's geometry is added as any other, with Prim.master set (add_prim
 * in scene.c reads open_master), so that its points stay in master space;
 * until a shader is set inside the block, current_object is
 * SCENE_OBJECT_INHERIT and its primitives take each instance's object.
 * object_end restores what object_begin saved (SceneSaved), so attributes
 * set inside a block do not leak out. Each instance records the current
 * transform (moving: its motion, SceneInstance.motion) and object;
 * nesting and the flattened count are bounded here (SCENE_MAX_NESTING,
 * SCENE_MAX_INSTANCES), so prepare cannot explode.
 */
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "util/grow.h"

/* The latest master of that name, or -1. */
static int64_t find_master(const RayesScene *s, const char *name)
{
    for (size_t m = s->n_masters; m-- > 0;)
        if (strcmp(s->masters[m].name, name) == 0)
            return (int64_t)m;
    return -1;
}

RayesError rayes_scene_object_begin(RayesScene *s, const char *name)
{
    if (!s || !name)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->open_master >= 0)
        return scene_fail(s, RAYES_ERROR_INVALID_OPERATION,
                          "object begin \"%.64s\": inside the block of \"%.64s\" (blocks do "
                          "not nest; instance an ended one instead)",
                          name, s->masters[s->open_master].name);
    if (s->n_masters >= UINT32_MAX - 1)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "object begin: too many masters");
    if (util_grow((void **)&s->masters, &s->cap_masters, s->n_masters, sizeof *s->masters) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    SceneMaster *m = &s->masters[s->n_masters];
    memset(m, 0, sizeof *m);
    m->name = strdup(name);
    if (!m->name)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    m->first_prim = m->end_prim = s->n_prims;
    m->depth = 1;
    s->saved = (SceneSaved){
        s->world_from_object,     s->current_object, s->shading_rate,       s->displacement_bound,
        s->current_displacement,  s->current_links,  s->current_visibility, s->current_hitmode,
        s->current_opacity_cache, s->current_motion};
    s->open_master = (int64_t)s->n_masters++;
    s->current_object = SCENE_OBJECT_INHERIT;
    s->world_from_object = mat4_identity();
    s->current_motion = 0;
    return RAYES_OK;
}

RayesError rayes_scene_object_end(RayesScene *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->open_master < 0)
        return scene_fail(s, RAYES_ERROR_INVALID_OPERATION,
                          "object end: no object block is open (rayes_scene_object_begin)");
    SceneMaster *m = &s->masters[s->open_master];
    m->end_prim = s->n_prims;
    m->leaves += m->end_prim > m->first_prim;
    const SceneSaved *v = &s->saved;
    s->world_from_object = v->world_from_object;
    s->current_object = v->current_object;
    s->shading_rate = v->shading_rate;
    s->displacement_bound = v->displacement_bound;
    s->current_displacement = v->displacement;
    s->current_links = v->links;
    s->current_visibility = v->visibility;
    s->current_hitmode = v->hitmode;
    s->current_opacity_cache = v->opacity_cache;
    s->current_motion = v->motion;
    s->open_master = -1;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

RayesError rayes_scene_object_instance(RayesScene *s, const char *name)
{
    if (!s || !name)
        return RAYES_ERROR_INVALID_ARGUMENT;
    int64_t m = find_master(s, name);
    if (m < 0 || m == s->open_master)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          m < 0 ? "object instance: no object block is named \"%.64s\""
                                : "object instance: \"%.64s\" is the block being defined",
                          name);
    SceneMaster *mm = &s->masters[m];
    uint64_t leaves = mm->leaves;
    SceneMaster *parent = s->open_master >= 0 ? &s->masters[s->open_master] : NULL;
    uint64_t total = (parent ? parent->leaves : s->leaves) + leaves;
    if (total > SCENE_MAX_INSTANCES || (parent && mm->depth + 1 > SCENE_MAX_NESTING))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "object instance \"%.64s\": more than %u instances, or blocks "
                          "nested more than %d deep",
                          name, SCENE_MAX_INSTANCES, SCENE_MAX_NESTING);
    if (s->current_object == -1) { /* the default matte, as geometry gets */
        RayesError e = rayes_scene_set_shader(s, "matte", NULL, 0);
        if (e != RAYES_OK)
            return e;
    }
    if (util_grow((void **)&s->instances, &s->cap_instances, s->n_instances,
                  sizeof *s->instances) != 0)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->instances[s->n_instances++] = (SceneInstance){
        .parent_from_master = s->world_from_object,
        .master = (uint32_t)m,
        .motion = s->current_motion,
        .parent = parent ? (uint32_t)s->open_master + 1 : 0,
        .object = s->current_object == SCENE_OBJECT_INHERIT ? GEOM_OBJECT_INHERIT
                                                            : (uint32_t)s->current_object,
    };
    if (mm->inherit_Os_below_1) { /* its see-through geometry takes this object */
        if (s->current_object != SCENE_OBJECT_INHERIT)
            s->objects[s->current_object].Os_primvar_below_1 = 1;
        else if (parent)
            parent->inherit_Os_below_1 = 1;
    }
    if (parent) {
        parent->leaves = total;
        parent->depth = mm->depth + 1 > parent->depth ? mm->depth + 1 : parent->depth;
    } else {
        s->leaves = total;
    }
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

size_t rayes_scene_instance_count(const RayesScene *s)
{
    return s ? s->n_instances : 0;
}
