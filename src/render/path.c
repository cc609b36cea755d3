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
    /* Never more than a micropolygon edge, whatever the curvature estimate. */
    return path_ray_epsilon(w) + fminf(0.5f * g->edge * g->edge * g->curvature, g->edge);
}
