/*
 * render/integrator.h — private to render/: tracing radiance along rays,
 * the per-worker state, and the services table shaders call.
 */
#ifndef RAYES_RENDER_INTEGRATOR_H
#define RAYES_RENDER_INTEGRATOR_H

#include "render/render.h"

/* The simplified ray differential of DESIGN.md: the footprint at distance t
 * is width + t * spread. */
typedef struct RayDiff {
    float width;   /* at the origin, scene units */
    float spread;  /* radians */
} RayDiff;

typedef struct Worker {
    const RenderScene *rs;
    const RenderSettings *set;
    RenderStats stats;
    CacheLocal cache;             /* this thread's part of the radiosity cache */
} Worker;

/* What a shading context's `renderer` points to: per point, the sample key
 * its random numbers derive from, the ray differential that arrived (width
 * = footprint at the point) and the grid's curvature. */
typedef struct PathState {
    Worker *w;
    const uint64_t *keys;
    const RayDiff *diff;
    const float *curvature;
} PathState;

extern const RayesShaderServices render_services;

/* Radiance arriving at ray->o from direction ray->d (unit length), for a ray
 * of type kind (RAYES_RAY_CAMERA, _DIFFUSE or _SPECULAR) at the given
 * depths, its random numbers named by key. *alpha (if not NULL) is set to 1
 * if something was hit. */
Vec3 integrator_trace(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                      int specular_depth, uint64_t key, RayDiff diff, float *alpha);

#endif /* RAYES_RENDER_INTEGRATOR_H */
