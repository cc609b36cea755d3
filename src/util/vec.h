/*
 * util/vec.h — 3-vectors, 4 x 4 matrices and bounds, all inline.
 *
 * Vec3 is three floats; Mat4 is row-major and maps column vectors
 * (p' = M p), the convention of rayes.h. Transforms are named by their
 * spaces (world_from_object), as pbrt does.
 */
#ifndef RAYES_UTIL_VEC_H
#define RAYES_UTIL_VEC_H

#include <math.h>

typedef struct Vec3 {
    float x, y, z;
} Vec3;

typedef struct Mat4 {
    float m[4][4]; /* m[row][column] */
} Mat4;

typedef struct Bounds3 {
    Vec3 lo, hi;
} Bounds3;

static inline Vec3 v3(float x, float y, float z) { return (Vec3){x, y, z}; }
static inline Vec3 v3_load(const float p[3]) { return (Vec3){p[0], p[1], p[2]}; }
static inline void v3_store(float out[3], Vec3 v) { out[0] = v.x, out[1] = v.y, out[2] = v.z; }
static inline Vec3 v3_add(Vec3 a, Vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline Vec3 v3_sub(Vec3 a, Vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline Vec3 v3_mul(Vec3 a, Vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline Vec3 v3_scale(Vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline Vec3 v3_madd(Vec3 a, Vec3 b, float s) /* a + b s */
{
    return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline Vec3 v3_neg(Vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline float v3_dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline Vec3 v3_cross(Vec3 a, Vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_length(Vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline Vec3 v3_normalize(Vec3 a)
{
    float l = v3_length(a);
    return l > 0.0f ? v3_scale(a, 1.0f / l) : a;
}
static inline Vec3 v3_lerp(Vec3 a, Vec3 b, float t) { return v3_madd(v3_scale(a, 1.0f - t), b, t); }
static inline Vec3 v3_min(Vec3 a, Vec3 b)
{
    return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z));
}
static inline Vec3 v3_max(Vec3 a, Vec3 b)
{
    return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z));
}
static inline float v3_max_component(Vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
static inline float v3_average(Vec3 a) { return (a.x + a.y + a.z) * (1.0f / 3.0f); }
static inline float v3_index(Vec3 a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }
static inline Vec3 v3_faceforward(Vec3 n, Vec3 d) /* n turned to face against d */
{
    return v3_dot(n, d) > 0.0f ? v3_neg(n) : n;
}

/* An orthonormal basis (t, b) around unit n (Duff et al. 2017). */
static inline void v3_basis(Vec3 n, Vec3 *t, Vec3 *b)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float c = n.x * n.y * a;
    *t = v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = v3(c, sign + n.y * n.y * a, -n.y);
}

/* An orthonormal frame (t, b) of the plane normal to unit n whose t is
 * d's direction in that plane (d need not be unit). Near d = +-n that
 * direction is rounding error, which normalised would lie along n: there
 * v3_basis's frame serves. */
static inline void v3_basis_toward(Vec3 n, Vec3 d, Vec3 *t, Vec3 *b)
{
    Vec3 p = v3_sub(d, v3_scale(n, v3_dot(n, d)));
    float l = v3_length(p);
    if (!(l > 1e-4f * v3_length(d))) {
        v3_basis(n, t, b);
        return;
    }
    *t = v3_scale(p, 1.0f / l);
    *b = v3_cross(n, *t);
}

static inline Bounds3 bounds_empty(void)
{
    return (Bounds3){v3(INFINITY, INFINITY, INFINITY), v3(-INFINITY, -INFINITY, -INFINITY)};
}
static inline Bounds3 bounds_add(Bounds3 b, Vec3 p)
{
    return (Bounds3){v3_min(b.lo, p), v3_max(b.hi, p)};
}
static inline Bounds3 bounds_union(Bounds3 a, Bounds3 b)
{
    return (Bounds3){v3_min(a.lo, b.lo), v3_max(a.hi, b.hi)};
}
/* Distance from p to the box (0 inside). */
static inline float bounds_distance(Bounds3 b, Vec3 p)
{
    Vec3 d = v3_max(v3_max(v3_sub(b.lo, p), v3_sub(p, b.hi)), v3(0, 0, 0));
    return v3_length(d);
}

Mat4 mat4_identity(void);
Mat4 mat4_mul(Mat4 a, Mat4 b);
Mat4 mat4_translate(float x, float y, float z);
Mat4 mat4_scale(float x, float y, float z);
/* Rotation by angle_degrees about a unit-length axis (right-handed). */
Mat4 mat4_rotate(float angle_degrees, Vec3 axis);
/* The inverse; returns 0 (and leaves *inv the identity) if singular. */
int mat4_invert(Mat4 m, Mat4 *inv);
Mat4 mat4_transpose(Mat4 m);
Mat4 mat4_from_array(const float a[16]);

static inline Vec3 mat4_point(const Mat4 *m, Vec3 p)
{
    const float(*a)[4] = m->m;
    float x = a[0][0] * p.x + a[0][1] * p.y + a[0][2] * p.z + a[0][3];
    float y = a[1][0] * p.x + a[1][1] * p.y + a[1][2] * p.z + a[1][3];
    float z = a[2][0] * p.x + a[2][1] * p.y + a[2][2] * p.z + a[2][3];
    float w = a[3][0] * p.x + a[3][1] * p.y + a[3][2] * p.z + a[3][3];
    return w == 1.0f ? v3(x, y, z) : v3(x / w, y / w, z / w);
}
static inline Vec3 mat4_vector(const Mat4 *m, Vec3 v)
{
    const float(*a)[4] = m->m;
    return v3(a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z,
              a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
              a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z);
}

#endif /* RAYES_UTIL_VEC_H */
