/*
 * examples/shaders/chunk.h — running a shader method CHUNK points at a
 * time, so per-point arrays for the services' results can live on the
 * stack. Uses rayes/shader.h only, like the plugins that include it.
 *
 * A chunk's context is the points [start, start + count) of the whole:
 * every input array advanced by start, first_point too (the renderer
 * finds its own per-point state through it), and scratch advanced by
 * start * scratch_size (point i's scratch is at scratch + i * scratch_size).
 */
#ifndef RAYES_EXAMPLES_CHUNK_H
#define RAYES_EXAMPLES_CHUNK_H

#include <stddef.h>

#include "rayes/shader.h"

#define CHUNK 64

static inline void chunk_ctx(const RayesShadeCtx *ctx, size_t scratch_size, size_t start,
                             size_t count, RayesShadeCtx *sub)
{
    *sub = *ctx;
    sub->n_points = count;
    sub->first_point = ctx->first_point + start;
#define CHUNK_SLICE(f) sub->f = ctx->f ? ctx->f + start : NULL;
    CHUNK_SLICE(P) CHUNK_SLICE(N) CHUNK_SLICE(Ng) CHUNK_SLICE(dPdu) CHUNK_SLICE(dPdv)
    CHUNK_SLICE(u) CHUNK_SLICE(v) CHUNK_SLICE(s) CHUNK_SLICE(t) CHUNK_SLICE(du) CHUNK_SLICE(dv)
    CHUNK_SLICE(I) CHUNK_SLICE(Cs) CHUNK_SLICE(Os)
#undef CHUNK_SLICE
    sub->scratch = ctx->scratch ? (char *)ctx->scratch + start * scratch_size : NULL;
}

/* The outputs of the chunk starting at point start. */
static inline RayesShadeOutputs chunk_out(const RayesShadeOutputs *out, size_t start)
{
    RayesShadeOutputs o = {
        out->Ci ? out->Ci + start : NULL,
        out->Oi ? out->Oi + start : NULL,
        out->Irradiance ? out->Irradiance + start : NULL,
        out->P ? out->P + start : NULL,
    };
    return o;
}

/* Points in the chunk starting at start. */
static inline size_t chunk_size(const RayesShadeCtx *ctx, size_t start)
{
    return ctx->n_points - start < CHUNK ? ctx->n_points - start : CHUNK;
}

#endif /* RAYES_EXAMPLES_CHUNK_H */
