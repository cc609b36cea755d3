/*
 * render/envguide.h — guided sampling of environment lights at camera hits
 * (not the memo's; DESIGN.md "Lights"): from the coarse points of each
 * grid (or the middle of the cluster a tiny grid is in) a fill traces a
 * few shadow rays into
 * every bin of the light's map (LightGuide) and keeps how much of each
 * bin that surface sees, cosine-weighted, in the cache (data type guide:
 * bounded memory, the same values whoever fills it). A point's light
 * samples are then drawn by the map's brightness times those weights,
 * with a floor under every bin, so an interior lit through a window draws
 * most of its samples through the window; the estimate stays unbiased.
 *
 * Thread-safety: as the cache; a worker's slots are its own.
 */
#ifndef RAYES_RENDER_ENVGUIDE_H
#define RAYES_RENDER_ENVGUIDE_H

#include "render/path.h"

/* The guide of environment light l (the scene's light, not a moved copy;
 * its slot: the first ENVGUIDE_LIGHTS environment lights have one) for
 * points of grid `grid` through instance (0: none) on side side (0 front,
 * 1 back), whose points take n shadow rays each, or NULL: draw by the
 * light alone (no guide, or too few samples on the grid to pay for one). */
const LightGuide *envguide_get(Worker *w, const Light *l, int slot, uint32_t grid,
                               uint32_t instance, int side, int n);

/* The patch a grid's guide is kept for: a tiny grid's largest cluster
 * (one guide for up to 256 of them; GridSet's grids, then its clusters),
 * else the grid. Worker.guide_pixels counts pixels by it (render.c). */
uint32_t envguide_patch(const GridSet *gs, uint32_t grid);

#endif /* RAYES_RENDER_ENVGUIDE_H */
