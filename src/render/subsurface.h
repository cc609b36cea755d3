/*
 * render/subsurface.h — private to render/: the subsurface service of
 * shader.h (memo section 6.2), subsurface.c.
 */
#ifndef RAYES_RENDER_SUBSURFACE_H
#define RAYES_RENDER_SUBSURFACE_H

#include "render/path.h"

/* RayesShaderServices.subsurface: ctx->renderer is a PathState. */
void subsurface_service(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const RayesSubsurfaceParams *p, int n_rays, float (*out)[3]);

/* The cosine below which a subsurface hit's area 4 pi t^2 / (N cos) is
 * clamped: a ray grazing a surface stands for an area without bound. On a
 * plane, hits at cos c lie 1/c probe depths away, where the profile has
 * decayed (R A stays bounded), so the clamp must be small: at 0.1 a
 * marble slab lost 8% of its red (DESIGN.md, subsurface scattering). */
#define SUBSURFACE_MIN_COS 0.001f
/* Cached irradiance is looked up at the resolution of a subsurface ray's
 * footprint t sqrt(4 pi / n), n at least this many (final quality's): with
 * fewer rays the footprint would choose coarse levels whose interpolant is
 * biased (DESIGN.md). */
#define SUBSURFACE_LOOKUP_RAYS 64

#endif /* RAYES_RENDER_SUBSURFACE_H */
