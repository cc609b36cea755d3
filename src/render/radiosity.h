/*
 * render/radiosity.h — private to render/: the radiosity cache at diffuse
 * hits, and the opacity cache at transmission hits (radiosity.c).
 */
#ifndef RAYES_RENDER_RADIOSITY_H
#define RAYES_RENDER_RADIOSITY_H

#include "render/path.h"

/* The cache level for a hit on grid g with the given ray footprint: the
 * coarsest whose micropolygon edge is at most k * footprint and whose
 * micropolygons bend through at most 0.5 radians (edge x curvature), or `forced`
 * (>= 0), after aliasing a MEDIUM level that equals FINE or COARSE. */
int radiosity_choose_level(const Grid *g, float footprint, float k, int forced);

/* The coarsest cluster (geom/cluster.c) that grid `grid` is in whose size is
 * at most k * footprint: its index + 1, or 0 if none (the grid's own
 * levels serve). Radiosity and irradiance only: the memo's opacity stays
 * per grid (a cut-out's holes are its own). */
uint32_t radiosity_choose_cluster(const GridSet *gs, uint32_t grid, float footprint, float k);

/* The cached radiosity leaving the hit toward the ray (filling the entry on
 * a miss). */
Vec3 radiosity_at_hit(Worker *w, const Ray *ray, const Hit *hit, int diffuse_depth, RayDiff diff);

/* How many of a ray's footprints the finest opacity level's points may
 * lie apart before the ray asks the shader at its hit instead. */
#define RADIOSITY_OPACITY_DETAIL 2.0f

/* 1 if the ray's footprint at the hit is finer than the opacity cache can
 * show: the grid's micropolygons (its finest level's spacing) are more than
 * RADIOSITY_OPACITY_DETAIL footprints long. A cut-out's detail lives in
 * its pattern, not its dicing: a leaf off screen is diced coarsely, and
 * the shadow it casts on what the camera sees would be as coarse (a sharp
 * sun's rays keep the receiving point's footprint). With the resolution
 * forced (`--cache-resolution`), 0. */
int radiosity_opacity_too_fine(const Worker *w, const Hit *hit, RayDiff diff);

/* The cached opacity at a hit (memo 6.1): entries of data type opacity, of
 * the front side and depth 0 whatever the ray, filled by the shader's
 * opacity method over the level's points. */
Vec3 radiosity_opacity_at_hit(Worker *w, const Hit *hit, RayDiff diff);

/* The cached irradiance at a subsurface ray's hit from inside an object
 * (memo 6.2): entries of data type irradiance, depth 0, of the side the ray
 * leaves through (the object's outside), at the level the footprint
 * (scene units) chooses, filled by diffuselighting's Irradiance output. */
Vec3 radiosity_irradiance_at_hit(Worker *w, const Ray *ray, const Hit *hit, float footprint);

/* Shades every vertex of grid `grid` (world geometry, or a master's grid
 * seen through object instance `instance` - 1; its side `side`, 0 front, 1
 * back, as a cache entry's; the FINE level) with diffuselighting at
 * diffuse depth `depth`, as a cache fill would, into out (the fill's order: vertex order; triangles row by row):
 * point-based GI's passes (pbgi.c). */
void radiosity_shade_grid(Worker *w, uint32_t grid, uint32_t instance, int depth, int side,
                          float (*out)[3]);

/* A patch's points as its coarse fill shades them (a quad grid's four,
 * a triangular grid's three or its centroid; past the grids, a cluster:
 * its representative's middle), on side side, through instance (0:
 * none), at the shutter's segment 0: their world positions, unit
 * geometric normals (facing the side) and the offset their rays start at.
 * Returns how many (1 to 4). */
int radiosity_patch_points(Worker *w, uint32_t patch, uint32_t instance, int side, Vec3 P[4],
                           Vec3 N[4], float *offset);

/* Interpolates a level's values at a hit. */
Vec3 radiosity_interpolate(const Grid *g, const Hit *hit, int level, const uint16_t *values);

#endif /* RAYES_RENDER_RADIOSITY_H */
