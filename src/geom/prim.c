/*
 * geom/prim.c — evaluation of primitives: position and first derivatives at
 * (u, v), and normals robust to degenerate points (the teapot's lid and
 * bottom patches collapse a whole row to a point; spheres have poles).
 * Pure functions; thread-safe.
 */
#include "geom/geom.h"

#include <math.h>

void geom_bezier_basis(float t, float b[4], float db[4])
{
    float s = 1.0f - t;
    b[0] = s * s * s;
    b[1] = 3.0f * t * s * s;
    b[2] = 3.0f * t * t * s;
    b[3] = t * t * t;
    db[0] = -3.0f * s * s;
    db[1] = 3.0f * s * s - 6.0f * t * s;
    db[2] = 6.0f * t * s - 3.0f * t * t;
    db[3] = 3.0f * t * t;
}

static void eval_bicubic(const Vec3 *cp, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    float bu[4], dbu[4], bv[4], dbv[4];
    geom_bezier_basis(u, bu, dbu);
    geom_bezier_basis(v, bv, dbv);
    Vec3 p = v3(0, 0, 0), du = p, dv = p;
    for (int j = 0; j < 4; j++) {
        Vec3 row = v3(0, 0, 0), drow = row;
        for (int i = 0; i < 4; i++) {
            row = v3_madd(row, cp[4 * j + i], bu[i]);
            drow = v3_madd(drow, cp[4 * j + i], dbu[i]);
        }
        p = v3_madd(p, row, bv[j]);
        du = v3_madd(du, drow, bv[j]);
        dv = v3_madd(dv, row, dbv[j]);
    }
    *P = p;
    *dPdu = du;
    *dPdv = dv;
}

static void eval_sphere(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    float r = prim->sphere.radius;
    float phi = 2.0f * (float)M_PI * u, theta = (float)M_PI * v;
    float sp = sinf(phi), cp = cosf(phi), st = sinf(theta), ct = cosf(theta);
    Vec3 p = v3(r * st * cp, r * st * sp, -r * ct);
    Vec3 du = v3(-2.0f * (float)M_PI * r * st * sp, 2.0f * (float)M_PI * r * st * cp, 0.0f);
    Vec3 dv = v3((float)M_PI * r * ct * cp, (float)M_PI * r * ct * sp, (float)M_PI * r * st);
    const Mat4 *m = &prim->sphere.world_from_object;
    *P = mat4_point(m, p);
    *dPdu = mat4_vector(m, du);
    *dPdv = mat4_vector(m, dv);
}

void geom_prim_eval(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    const Vec3 *c = prim->cp;
    switch (prim->type) {
    case PRIM_BILINEAR: {
        Vec3 a = v3_lerp(c[0], c[1], u), b = v3_lerp(c[2], c[3], u);
        *P = v3_lerp(a, b, v);
        *dPdu = v3_lerp(v3_sub(c[1], c[0]), v3_sub(c[3], c[2]), v);
        *dPdv = v3_sub(b, a);
        break;
    }
    case PRIM_BICUBIC:
        eval_bicubic(c, u, v, P, dPdu, dPdv);
        break;
    case PRIM_TRIANGLE:
        *P = v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), u), v3_scale(v3_sub(c[2], c[0]), v)));
        *dPdu = v3_sub(c[1], c[0]);
        *dPdv = v3_sub(c[2], c[0]);
        break;
    case PRIM_SPHERE:
        eval_sphere(prim, u, v, P, dPdu, dPdv);
        break;
    }
}

Vec3 geom_prim_normal(const Prim *prim, float u, float v)
{
    Vec3 P, du, dv;
    if (prim->type == PRIM_SPHERE) {
        /* Exact at the poles too: the normal is the object-space position. */
        float phi = 2.0f * (float)M_PI * u, theta = (float)M_PI * v;
        Vec3 n = v3(sinf(theta) * cosf(phi), sinf(theta) * sinf(phi), -cosf(theta));
        return v3_normalize(mat4_vector(&prim->sphere.normal_from_object, n));
    }
    geom_prim_eval(prim, u, v, &P, &du, &dv);
    Vec3 n = v3_cross(du, dv);
    float scale = v3_length(du) * v3_length(dv);
    if (v3_length(n) > 1e-6f * scale && scale > 0.0f)
        return v3_normalize(n);
    /* Degenerate: step toward the middle of the parameter domain until the
     * tangent plane is defined. The first step is tiny so that the normal
     * stays the limit of the neighbouring normals. */
    float cu = prim->type == PRIM_TRIANGLE ? 1.0f / 3.0f : 0.5f;
    float cv = cu;
    for (float e = 1e-4f; e < 0.6f; e *= 4.0f) {
        float uu = u + (cu - u) * e, vv = v + (cv - v) * e;
        geom_prim_eval(prim, uu, vv, &P, &du, &dv);
        n = v3_cross(du, dv);
        scale = v3_length(du) * v3_length(dv);
        if (scale > 0.0f && v3_length(n) > 1e-6f * scale)
            return v3_normalize(n);
    }
    return v3(0.0f, 0.0f, 1.0f);
}
