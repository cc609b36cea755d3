/*
 * render/integrator.h — private to render/: tracing radiance along rays
 * (integrator.c). The per-worker and path state are in path.h, the
 * services table shaders call in services.h.
 */
#ifndef RAYES_RENDER_INTEGRATOR_H
#define RAYES_RENDER_INTEGRATOR_H

#include "render/path.h"

/* Radiance arriving at ray->o from direction ray->d (unit length), for a ray
 * of type kind (RAYES_RAY_CAMERA, _DIFFUSE or _SPECULAR) at the given
 * depths, its random numbers named by key. *alpha (if not NULL) is set to 1
 * if something was hit. */
Vec3 integrator_trace(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                      int specular_depth, uint64_t key, RayDiff diff, float *alpha);

/* As integrator_trace, with the distance to the hit in *t (INFINITY for a
 * miss) instead of alpha. */
Vec3 integrator_trace_hit(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                          int specular_depth, uint64_t key, RayDiff diff, float *t);

/* The opacity (RGB) of the surface at a hit, as shadow and transmission
 * rays see it: 1 for opaque objects, Os where the transmission hit mode is
 * "primitive" or the shader has no opacity method, else the opacity cache
 * (memo 6.1) or, uncached, the shader's opacity method at the hit. diff is
 * the ray's differential (its footprint chooses the cache resolution).
 * crossing: a transmission query's (whose hit may lack Ng until a shader
 * runs; a footprint too fine for the cache asks the shader,
 * radiosity_opacity_too_fine), or NULL for a diffuse ray's hit with Ng
 * (always the cache's, matching its cached radiosity). */
Vec3 integrator_opacity(Worker *w, const Ray *ray, Hit *hit, const AccelCrossing *crossing,
                        RayDiff diff);

/* The irradiance on the outside of the surface at a subsurface ray's hit
 * from inside its object, uncached (memo 6.2's "without caching"): the
 * object's diffuselighting run at the hit alone, its Irradiance output
 * (the direct_lighting service fills it), random numbers named by key.
 * Counts an irradiance point. */
Vec3 integrator_irradiance(Worker *w, const Ray *ray, const Hit *hit, uint64_t key,
                           RayDiff diff);

/* The transmittance along a shadow ray below which its further crossings
 * of transparent surfaces play Russian roulette (accel_transmission), for
 * points deeper than the camera's hits (cache fills: their noise is
 * averaged by the diffuse rays that read them; a shadow the camera sees
 * stays smooth). On 20,000 cut-out leaves, where a shadow ray crossed a
 * dozen, it halved the crossings. DESIGN.md "Opacity". */
#define INTEGRATOR_SHADOW_ROULETTE 0.25f

/* The transmittance along a shadow or transmission ray: 1 where nothing is
 * in the way, the product of (1 - opacity) through transparent surfaces
 * (Russian roulette past INTEGRATOR_SHADOW_ROULETTE below diffuse depth
 * 0, w->depth), 0 at an opaque one.
 * Counts the ray. */
Vec3 integrator_transmission(Worker *w, const Ray *ray, RayDiff diff);

#endif /* RAYES_RENDER_INTEGRATOR_H */
