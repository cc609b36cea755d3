/*
 * render/path.c — where rays leaving a point start, and cut-out opacity
 * patterns (path.h).
 */
#include "render/path.h"

#include <math.h>

#include "shade/pattern.h"
#include "util/check.h"

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

float path_ray_offset_in(const Worker *w, const Grid *g, uint32_t instance)
{
    const GeomInstance *gi = render_instance(w->rs, instance);
    return path_ray_epsilon(w) + g->sagitta * (gi ? gi->scale : 1.0f);
}

void path_apply_Os_pattern(const Worker *w, const RenderObject *obj, const RayesShadeCtx *ctx,
                           float (*Os)[3])
{
    if (!obj->Os_pattern)
        return;
    const PathState *ps = ctx->renderer;
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = RY_MIN(ctx->n_points - start, (size_t)SHADE_CHUNK);
        RayesShadeCtx sub;
        float m[SHADE_CHUNK][3];
        shade_ctx_slice(ctx, start, n, &sub);
        pattern_eval(obj->Os_pattern, w->set->textures, &sub,
                     ps->ds ? ps->ds + sub.first_point : NULL,
                     ps->dt ? ps->dt + sub.first_point : NULL, m);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                Os[start + i][c] *= fminf(fmaxf(m[i][c], 0.0f), 1.0f);
    }
}

size_t path_count_holes(const RenderObject *obj, size_t n, const float (*Os)[3])
{
    size_t holes = 0;
    for (size_t i = 0; obj->transparent && !obj->opacity_shader && i < n; i++)
        holes += path_clear(Os[i]);
    return holes;
}
