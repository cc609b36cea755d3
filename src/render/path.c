/*
 * render/path.c — where rays leaving a point start (path.h).
 */
#include "render/path.h"

#include <math.h>

float path_ray_epsilon(const Worker *w)
{
    return 1e-5f * w->rs->scene_radius;
}

float path_ray_offset(const Worker *w, const Grid *g)
{
    /* The sagitta bound of the primitive's grids (never more than an edge,
     * whatever the curvature estimate): neighbouring grids diced at
     * another rate share no vertices, and a coarser one runs further
     * inside. */
    return path_ray_epsilon(w) + g->sagitta;
}
