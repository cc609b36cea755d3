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
