/*
 * shade/pattern.h — patterns: pbrt-v4's textures (constant, scale, mix,
 * directionmix, checkerboard in 2-D and 3-D, imagemap, bilerp, dots, fbm,
 * wrinkled, windy, marble) as small graphs that shaders evaluate at their
 * shading points through the `pattern` service (DESIGN.md "Patterns"),
 * and voxel grids of density (densitygrid, pbrt-v4's uniform grid, and
 * nanovdb, a float grid of a NanoVDB file; grid.h) for volumes.
 *
 * A pattern is made once from a class name and RayesParams whose inputs are
 * constants or earlier patterns (found through a PatternFind), so graphs
 * have no cycles; it is immutable afterwards and may be evaluated by any
 * number of threads. Its inputs are borrowed: whoever owns the patterns
 * (the scene) frees them all together. Evaluation is a pure function of
 * the points and of the image files, so renders stay deterministic.
 */
#ifndef RAYES_SHADE_PATTERN_H
#define RAYES_SHADE_PATTERN_H

#include <stddef.h>

#include "rayes/shader.h"
#include "shade/texture.h"

typedef struct RayesPattern Pattern;

/* Patterns nest at most this deep (evaluation keeps a chunk per level on
 * the stack). */
#define PATTERN_MAX_DEPTH 16

/* The pattern a name stands for, or NULL (data is the finder's). */
typedef const Pattern *(*PatternFind)(void *data, const char *name);

/* A new pattern of class type (rayes.h's rayes_scene_pattern lists them)
 * with texture space given by world_from_texture (row-major 4 x 4; its
 * inverse is taken here). Returns NULL with err filled for an unknown
 * class, parameter, pattern name, wrong type, too deep a graph, a
 * singular transform, a grid that cannot be made or read (nanovdb's
 * "filename" is opened as given: the scene resolves it first) or no
 * memory. The caller owns the result. */
Pattern *pattern_new(const char *type, const RayesParam *params, size_t n_params,
                     const float world_from_texture[16], PatternFind find, void *find_data,
                     char *err, size_t err_size);
void pattern_free(Pattern *p);

/* The pattern at ctx's points into out (linear RGB; float patterns grey):
 * 2-D classes read ctx->s and ctx->t and filter over ds x dt (NULL:
 * ctx->du, ctx->dv), 3-D classes ctx->P with the footprint ctx->dPdu du,
 * ctx->dPdv dv. Images come from ts (NULL: they read as 0). Returns 0, or
 * -1 when an image could not be read. */
int pattern_eval(const Pattern *p, TextureSystem *ts, const RayesShadeCtx *ctx, const float *ds,
                 const float *dt, float (*out)[3]);

#endif /* RAYES_SHADE_PATTERN_H */
