/*
 * util/sampling.h — warping [0,1)^2 samples to directions and points.
 * Pure inline functions.
 */
#ifndef RAYES_UTIL_SAMPLING_H
#define RAYES_UTIL_SAMPLING_H

#include <math.h>

#include "util/vec.h"

/* Cosine-weighted direction about unit n (pdf cos(theta)/pi), by Malley's
 * method on a concentric disk map (keeps stratification), in the frame
 * (t, bt, n) of v3_basis(n): a loop over one point's samples makes the
 * frame once. */
static inline Vec3 sample_cosine_frame(Vec3 t, Vec3 bt, Vec3 n, float u1, float u2)
{
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f, r, phi;
    if (a == 0.0f && b == 0.0f) {
        r = 0.0f;
        phi = 0.0f;
    } else if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = (float)(M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (float)(M_PI / 2.0) - (float)(M_PI / 4.0) * (a / b);
    }
    float x = r * cosf(phi), y = r * sinf(phi);
    float z2 = 1.0f - x * x - y * y; /* fmaxf(0, z2), without libm's call */
    float z = sqrtf(z2 > 0.0f ? z2 : 0.0f);
    return v3_add(v3_add(v3_scale(t, x), v3_scale(bt, y)), v3_scale(n, z));
}

/* The same about unit n, its frame made here. */
static inline Vec3 sample_cosine_hemisphere(Vec3 n, float u1, float u2)
{
    Vec3 t, bt;
    v3_basis(n, &t, &bt);
    return sample_cosine_frame(t, bt, n, u1, u2);
}

/* A point of the unit disk from [0,1)^2, by Shirley's concentric map
 * (keeps stratification). */
static inline void sample_concentric_disk(float u1, float u2, float *x, float *y)
{
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f, r, phi;
    if (a == 0.0f && b == 0.0f) {
        *x = *y = 0.0f;
        return;
    }
    if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = (float)(M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (float)(M_PI / 2.0) - (float)(M_PI / 4.0) * (a / b);
    }
    *x = r * cosf(phi);
    *y = r * sinf(phi);
}

#endif /* RAYES_UTIL_SAMPLING_H */
