/*
 * session/session.h — what rayes_render (session.c) and the progressive
 * session (progressive.c) share: checking options, preparing a committed
 * scene (diced grids, ray tracing structure, the render-side objects) and
 * the RenderScene of a prepared scene.
 */
#ifndef RAYES_SESSION_SESSION_H
#define RAYES_SESSION_SESSION_H

#include "accel/accel.h"
#include "geom/geom.h"
#include "rayes/rayes.h"
#include "render/render.h"
#include "scene/scene.h"
#include "shade/texture.h"

/* A scene prepared for rendering. Borrows the scene (objects' shaders,
 * lights), which must not change while it is used. */
typedef struct Prepared {
    GridSet gs;
    RenderObject *objects;    /* n_objects + 1 */
    uint32_t *masks;          /* object ray masks */
    Accel *accel;
    float scene_radius;  /* for ray offsets */
    int any_transparent; /* some object may be partly transparent */
    struct RenderVolume *volumes; /* n_volumes (render/volume.h) */
    size_t n_volumes;
    float coarsened;     /* >= 1: how much longer the vertex budget made micropolygons */
} Prepared;

/* Records msg as the scene's error (if it has none) and returns e. */
RayesError session_fail(RayesScene *scene, RayesError e, const char *msg);

/* RAYES_OK, or RAYES_ERROR_INVALID_ARGUMENT with the scene's error set. */
RayesError session_check_options(RayesScene *scene, const RayesRenderOptions *options);

/* The render settings of checked options (threads resolved; no cache or
 * textures yet). */
RenderSettings session_settings(const RayesRenderOptions *options);

/* The crop window's pixels, x0 y0 x1 y1 (exclusive ends), into rect (may
 * be NULL); 1 if it holds any. */
int session_crop_pixels(const RayesRenderOptions *options, int rect[4]);

/* 1 if data type t (CACHE_RADIOSITY, _OPACITY, _IRRADIANCE) is cached:
 * its switch is on and its budget above 0 (a budget of 0 turns it off, as
 * RenderMan's cache memory limits do). */
int session_caches(const RayesRenderOptions *o, int t);

/* The cache of a render: a budget per data type session_caches keeps
 * (cache_mb, opacity_cache_mb, irradiance_cache_mb; one Cache). NULL when
 * out of memory. */
Cache *session_cache(const RayesRenderOptions *o);

/* The texture system of a render: the scene's texture path, then
 * $RAYES_TEXTURE_PATH's. NULL when out of memory. */
TextureSystem *session_textures(const RayesScene *scene, double mb, float width);

/* The render-side view of the scene's objects (shader, Cs, Os, light), or
 * NULL when out of memory. */
RenderObject *session_render_objects(const RayesScene *scene);

/* Dices the scene for its camera at set's width x height and grid size
 * and builds the ray tracing structure. On failure *p is empty and the
 * scene's error set. */
RayesError session_prepare(RayesScene *scene, const RenderSettings *set, TextureSystem *textures,
                           Prepared *p);
void session_prepared_fini(Prepared *p);

/* The RenderScene of a prepared scene, with the scene's current camera. */
RenderScene session_render_scene(const RayesScene *scene, const Prepared *p, int width,
                                 int height);

#endif /* RAYES_SESSION_SESSION_H */
