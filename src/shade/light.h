/*
 * shade/light.h — light sources. For now the emissive quad area light of
 * the Cornell box: one-sided, constant radiance, sampled by the renderer's
 * direct-lighting service over its bilinear parameterisation.
 */
#ifndef RAYES_SHADE_LIGHT_H
#define RAYES_SHADE_LIGHT_H

#include "util/vec.h"

typedef struct Light {
    Vec3 P[4];   /* corners as a bilinear patch: P00, P10, P01, P11 (world) */
    Vec3 L;      /* emitted radiance, front side only */
} Light;

/* Point and unnormalised normal (dPda x dPdb, the emitting side; its length
 * is the area Jacobian) of the light at (a, b) in [0,1]^2. */
static inline void light_quad_eval(const Light *l, float a, float b, Vec3 *P, Vec3 *n)
{
    Vec3 e0 = v3_lerp(l->P[0], l->P[1], a), e1 = v3_lerp(l->P[2], l->P[3], a);
    *P = v3_lerp(e0, e1, b);
    Vec3 da = v3_lerp(v3_sub(l->P[1], l->P[0]), v3_sub(l->P[3], l->P[2]), b);
    *n = v3_cross(da, v3_sub(e1, e0));
}

#endif /* RAYES_SHADE_LIGHT_H */
