/*
 * scene/valid.c — what every file of the scene API uses to refuse bad
 * input: the first error of a scene, and the finiteness of arrays. A
 * leaf of the folder (it calls nothing in it), so that scene.c, curves.c,
 * motion.c and instances.c share it without calling each other in a
 * circle.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "scene/scene.h"

RayesError scene_fail(RayesScene *s, RayesError e, const char *fmt, ...)
{
    if (s->error[0] == '\0') {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(s->error, sizeof s->error, fmt, ap);
        va_end(ap);
    }
    return e;
}

int scene_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

int scene_within(Bounds3 b)
{
    const float m = SCENE_MAX_COORD;
    return b.lo.x >= -m && b.lo.y >= -m && b.lo.z >= -m && b.hi.x <= m && b.hi.y <= m &&
           b.hi.z <= m;
}

int scene_affine(const float m[16])
{
    float w = fabsf(m[15]);
    return w > 0.0f && fabsf(m[12]) + fabsf(m[13]) + fabsf(m[14]) <= SCENE_AFFINE_EPS * w;
}

Mat4 scene_unit_w(const float m[16])
{
    Mat4 r = mat4_from_array(m);
    r.m[3][0] = r.m[3][1] = r.m[3][2] = 0.0f; /* within SCENE_AFFINE_EPS: an exporter's noise */
    for (int i = 0; m[15] != 1.0f && i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] /= m[15];
    return r;
}
