/*
 * accel/accel.h — ray tracing against diced grids. The only module that
 * sees Embree (DESIGN.md).
 *
 * Quad grids become Embree GRID geometry and triangular grids TRIANGLE
 * geometry, one Embree geometry of each kind per object, all sharing the
 * GridSet's vertex array (no copy). Curve grids (2 rows) become Embree's
 * linear curves through their centre lines, with the rows' half distance
 * as radius (round tubes, or flat ribbons facing each ray), and point
 * grids spheres or ray-facing disks inscribed in their squares: the grid
 * stays what is shaded and cached, Embree's shape what is hit. A hit leads back to its patch (the grid
 * index, which is the patch id), its micropolygon's vertices and the
 * interpolation weights inside it, and its position in the whole grid (the
 * coordinates the radiosity cache interpolates with).
 *
 * Each object has a ray mask: a ray hits an object only if their masks
 * share a bit (RayesRayType bits). An object whose mask also holds
 * ACCEL_MASK_TRANSPARENT may be partly transparent: accel_transmission
 * asks for the opacity of each of its hits (an Embree occlusion filter)
 * and goes on through it; other objects stop shadow rays.
 *
 * Object instances (GridSet.instances): each master's grids are one Embree
 * scene of their own, in master space, and each instance one Embree
 * instance geometry of it in the world's scene (one instance level, as
 * Debian's Embree is built; nested instances are flattened before). An
 * instance's mask is GeomInstance.ray_mask (its object's, and its
 * enclosing instances'); a master's grids that inherit the instance's
 * object see every ray type.
 *
 * Memory: the Accel borrows the GridSet, which must outlive it.
 * Thread-safety: queries are thread-safe after accel_new returns; threads
 * that trace must have FTZ/DAZ set (util/thread does).
 */
#ifndef RAYES_ACCEL_ACCEL_H
#define RAYES_ACCEL_ACCEL_H

#include <stddef.h>
#include <stdint.h>

#include "geom/geom.h"
#include "util/vec.h"

typedef struct Accel Accel;

typedef struct Ray {
    Vec3 o, d;           /* origin and direction (need not be unit length) */
    float tnear, tfar;   /* the segment searched, in units of |d| */
    uint32_t mask;       /* RayesRayType bits */
    float time;          /* in the shutter interval, scene time (moving geometry is where it
                            is then; GridSet.time) */
} Ray;

typedef struct Hit {
    float t;             /* distance along d, in units of |d| */
    uint32_t grid;       /* the patch id (index of its grid) */
    uint32_t instance;   /* 0; or through an object instance, its GridSet index + 1: grid is
                            its master's, vertex[] in master space (GeomInstance maps them) */
    Vec3 Ng;             /* unit geometric normal (world), on the side of dPdu x dPdv; zero if
                            the micropolygon is degenerate */
    float gu, gv;        /* position in the grid: quad: [0,1]^2 over the whole grid;
                            triangle: barycentrics (b1, b2) in the patch */
    uint32_t vertex[4];  /* vertices (GridSet indices) of the micropolygon hit */
    float weight[4];     /* their interpolation weights (bilinear or barycentric) */
    int n_vertex;        /* 4 (quad cell) or 3 (triangle) */
    int shape;           /* the grid's GeomShape: for round ones (tubes, spheres) Ng is the
                            true surface normal at the hit, not the grid's */
} Hit;

/* In an object's mask: shadow rays may pass through it (not a ray type). */
#define ACCEL_MASK_TRANSPARENT (1u << 31)
/* In an object's mask: it has an Embree scene of its own as well, for rays
 * that may hit only it (subsurface rays, memo 6.2: accel_intersect_object).
 * Not a ray type. */
#define ACCEL_MASK_OWN_SCENE (1u << 30)
/* The mask of the surfaces of primitive solids (GridSet.solids): ordinary
 * queries miss them; accel_intersect, accel_occluded and
 * accel_transmission find them one by one and keep a hit only where it
 * lies on its tree's solid (RenderMan's CSG; DESIGN.md "Solids"). Set by
 * accel_new itself. */
#define ACCEL_MASK_SOLID (1u << 29)

/* A transparent surface a transmission query crosses. */
typedef struct AccelCrossing AccelCrossing;

/* The opacity (RGB, each in [0, 1]) of a transparent object's hit, asked by
 * accel_transmission. hit is filled as accel_intersect fills it, but a
 * micropolygon's Ng may be left zero (its vertices unread: an opacity
 * cache lookup needs grid, gu, gv, t and instance alone);
 * accel_crossing_normal adds it, for a shader that runs. */
typedef Vec3 (*AccelOpacityFn)(void *user, const Ray *ray, Hit *hit,
                               const AccelCrossing *crossing);

/* Fills in the Ng of the crossing's hit if it was left out; a NULL crossing
 * (a hit from accel_intersect) is left as it is. */
void accel_crossing_normal(const AccelCrossing *crossing, Hit *hit);

/* Builds the acceleration structure. object_mask[o] is object o's ray
 * mask. Returns NULL and fills err on failure, and once *stop (if given)
 * is nonzero: Embree's builds read it as they go. */
Accel *accel_new(const GridSet *gs, const uint32_t *object_mask, size_t n_objects,
                 const volatile int *stop, char *err, size_t err_size);
void accel_free(Accel *accel);

/* The nearest hit in [tnear, tfar]; returns 1 and fills hit, or 0. */
int accel_intersect(const Accel *accel, const Ray *ray, Hit *hit);

/* The nearest hit on object `object` alone, whatever the ray's mask (the
 * object's own scene: its mask had ACCEL_MASK_OWN_SCENE; any other object
 * is never hit and returns 0). A micropolygon's Ng is Embree's, of the
 * triangle hit (facing as accel_intersect's: the same for a flat cell). */
int accel_intersect_object(const Accel *accel, uint32_t object, const Ray *ray, Hit *hit);

/* The probability in [0, 1] that a transparent object's hit is kept by
 * accel_intersect_stochastic (asked as AccelOpacityFn is, with the same
 * hit; it must not trace rays). */
typedef float (*AccelKeepFn)(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing);

/* accel_intersect, where each hit on a transparent object is kept with the
 * probability keep gives it, by a number in [0, 1) drawn from key and the
 * hit (its primitive and its place on it: the same hit, reported twice,
 * gets the same draw), and passed otherwise: the nearest kept hit. Kept
 * with probability a, a cut-out of opacity a is what a path tracer's
 * stochastic alpha makes it: the ray stops at layer k with the probability
 * that compositing the layers would weight it by, in one traversal. */
int accel_intersect_stochastic(const Accel *accel, const Ray *ray, AccelKeepFn keep, void *user,
                               uint64_t key, Hit *hit);

/* Returns 1 if anything lies in [tnear, tfar]. */
int accel_occluded(const Accel *accel, const Ray *ray);

/* The transmittance along the ray: the product over every surface in
 * [tnear, tfar] of (1 - its opacity), in any order, each surface crossing
 * counted once (Embree may report a hit twice); an opaque object's hit, or
 * a product reaching 0, ends the query at 0. opacity is called from inside
 * Embree's traversal, on the calling thread, for transparent objects only;
 * it must not trace rays.
 *
 * Once the product's largest component has fallen below roulette, each
 * further crossing of transmittance t (RGB) ends the query at 0 with
 * probability 1 - max(t), and is otherwise counted as t / max(t): Russian
 * roulette, the same in expectation, by a number drawn from the ray (its
 * origin and direction) and the hit, so the same ray gives the same
 * answer. A ray through foliage stops after a few leaves past the
 * threshold instead of crossing them all. 0: every crossing multiplies. */
Vec3 accel_transmission(const Accel *accel, const Ray *ray, AccelOpacityFn opacity, void *user,
                        float roulette);

/* Bytes Embree reported allocating for the structure. */
size_t accel_memory_bytes(const Accel *accel);

#endif /* RAYES_ACCEL_ACCEL_H */
