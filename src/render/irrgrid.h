/*
 * render/irrgrid.h — irradiance interpolation with gradients over a shaded
 * grid at diffuse depth 0 (the memo's section 5.2; issue 5), the per-grid
 * scheme the technical digest recommends (section 3.5, option 4).
 *
 * When the grid hider shades a grid with interpolation on, the first call
 * of the indirect-diffuse service on that grid's points computes the
 * indirect diffuse of every vertex at once: irradiance records (with
 * rotational and translational gradients, irradiance.h) at the vertices of
 * the medium lattice (every 4th vertex, last row and column kept), then, in
 * vertex order, each other vertex either interpolates the records that
 * cover it or, where none covers it or the covering records disagree, gets
 * a record of its own. Records never leave their grid, so light cannot
 * leak across patch boundaries, and one thread does a grid in a fixed
 * order, so images do not depend on threads. With point-based GI the
 * records are gathers from the point cloud (pbgi.h), not rays.
 */
#ifndef RAYES_RENDER_IRRGRID_H
#define RAYES_RENDER_IRRGRID_H

#include "render/path.h"

typedef struct IrrGrid {
    const Grid *grid;
    const float (*P)[3];     /* the grid context's positions and normals, vertex order */
    const float (*N)[3];
    int done;                /* E holds the results */
    int n_rays;              /* the ray count they were computed with */
    float (*E)[3];           /* per vertex: indirect diffuse as the service defines it */
} IrrGrid;

/* Computes irr->E for every vertex with n_rays rays per record, from the
 * path state of the grid context (keys, differentials, offsets per vertex). */
void irrgrid_compute(const PathState *ps, IrrGrid *irr, int n_rays);

#endif /* RAYES_RENDER_IRRGRID_H */
