/*
 * render/hider.h — the grid hider (PRMan's REYES mode; issue 5): at diffuse
 * depth 0, camera-visible patches are shaded once per fine-grid vertex with
 * the full lighting(), and camera ray hits interpolate the shaded grid, so
 * the cost of depth 0 follows visible grid vertices, not pixel samples.
 *
 * A grid is shaded the first time a camera ray hits it, by whichever thread
 * gets there first; others wait for it. Its random numbers derive from the
 * grid and vertex only, so the result does not depend on the thread or the
 * pixel that asked. Shaded grids live for one frame.
 *
 * Thread-safety: hider_camera_hit may be called from all workers at once.
 */
#ifndef RAYES_RENDER_HIDER_H
#define RAYES_RENDER_HIDER_H

#include "render/path.h"


/* For a frame of rs; NULL when out of memory. */
GridShading *hider_new(const RenderScene *rs, const RenderSettings *set);
void hider_free(GridShading *gsh);

/* Relative spread of a micropolygon's shaded corners above which the grid
 * hider does not interpolate them (see hider_camera_hit), at 64 or more
 * shadow and diffuse rays per point; with n < 64 it grows as sqrt(64 / n),
 * so that the noise of few rays is interpolated, not mistaken for a
 * highlight (at 1 ray it is 4: never, for four corners). */
#define HIDER_CONTRAST 0.5f

/* Relative spread of a micropolygon's corner opacities (summed RGB) above
 * which a transparent object's hit is shaded where the ray hits rather
 * than interpolated: opacity carries no noise to smooth, and a cut-out's
 * edge drawn from the grid's corners would be as coarse as the grid. */
#define HIDER_OPACITY_STEP 0.05f

/* The radiance toward the camera at a camera ray's hit on a surface (not an
 * emitter): the hit grid's shaded vertices, interpolated with the hit's
 * weights, into *L, and its opacity into *Oi (1 for an opaque object; a
 * transparent object's Ci is premultiplied, as the shader gave it, and the
 * caller composites what lies behind). Shades the grid first if nobody
 * has. Returns 0 instead when the hit micropolygon's corners disagree too
 * much to be interpolated (max - min of their summed RGB above the
 * contrast limit times their mean: a highlight or a sharp reflection
 * smaller than a micropolygon; or their opacities by more than
 * HIDER_OPACITY_STEP of their mean); the caller then shades the sample
 * itself, as the ray-tracing hider does. */
int hider_camera_hit(Worker *w, const Ray *ray, const Hit *hit, Vec3 *L, Vec3 *Oi);

#endif /* RAYES_RENDER_HIDER_H */
