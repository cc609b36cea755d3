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

#include "render/integrator.h"


/* For a frame of rs; NULL when out of memory. */
GridShading *hider_new(const RenderScene *rs);
void hider_free(GridShading *gsh);

/* The radiance toward the camera at a camera ray's hit on a surface (not an
 * emitter): the hit grid's shaded vertices, interpolated with the hit's
 * weights. Shades the grid first if nobody has. */
Vec3 hider_camera_hit(Worker *w, const Ray *ray, const Hit *hit);

#endif /* RAYES_RENDER_HIDER_H */
