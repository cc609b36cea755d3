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
 * clamped: grazing hits stand for vast areas whose estimate is all
 * variance (DESIGN.md, subsurface scattering). */
#define SUBSURFACE_MIN_COS 0.1f

#endif /* RAYES_RENDER_SUBSURFACE_H */
