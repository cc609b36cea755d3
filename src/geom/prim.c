/*
 * geom/prim.c — evaluation of primitives: position and first derivatives at
 * (u, v), and normals robust to degenerate points (the teapot's lid and
 * bottom patches collapse a whole row to a point; spheres have poles).
 * Pure functions; thread-safe.
 */
#include "geom/geom.h"

#include <math.h>
#include <string.h>

#include "geom/subdiv.h"

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
    float r = prim->big->sphere.radius;
    float phi = 2.0f * (float)M_PI * u, theta = (float)M_PI * v;
    float sp = sinf(phi), cp = cosf(phi), st = sinf(theta), ct = cosf(theta);
    Vec3 p = v3(r * st * cp, r * st * sp, -r * ct);
    Vec3 du = v3(-2.0f * (float)M_PI * r * st * sp, 2.0f * (float)M_PI * r * st * cp, 0.0f);
    Vec3 dv = v3((float)M_PI * r * ct * cp, (float)M_PI * r * ct * sp, (float)M_PI * r * st);
    const Mat4 *m = &prim->big->sphere.world_from_object;
    *P = mat4_point(m, p);
    *dPdu = mat4_vector(m, du);
    *dPdv = mat4_vector(m, dv);
}

/* Quadric kinds: RayesQuadric's values (geom does not include rayes.h). */
enum { Q_SPHERE, Q_CYLINDER, Q_CONE, Q_DISK, Q_PARABOLOID, Q_HYPERBOLOID, Q_TORUS };

void geom_quadric_eval(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    const float *q = prim->big->quadric.p;
    if (prim->big->quadric.reverse)
        u = 1.0f - u;
    /* Surfaces of revolution: (rho cos theta, rho sin theta, z), rho and z
     * functions of v; the hyperboloid sweeps a line (qx, qy, qz) instead. */
    double rho = 0, drho = 0, z = 0, dz = 0, T;
    switch (prim->big->quadric.kind) {
    case Q_SPHERE: { /* radius, phimin, phimax (latitudes from zmin, zmax), thetamax */
        /* within the poles: -pi/2 as a float lies just beyond -pi/2, where
         * rho = r cos(phi) < 0 turned the pole's normal inward (and the
         * normals interpolated around it sideways: a mirror ball seen along
         * its axis reflected the wrong way at its centre) */
        double phi = fmax(-M_PI / 2, fmin(M_PI / 2, q[1] + v * (q[2] - q[1]))), d = q[2] - q[1];
        rho = q[0] * cos(phi), z = q[0] * sin(phi);
        drho = -q[0] * sin(phi) * d, dz = q[0] * cos(phi) * d;
        T = q[3];
        break;
    }
    case Q_CYLINDER: /* radius zmin zmax thetamax */
        rho = q[0], z = q[1] + v * (q[2] - q[1]), dz = q[2] - q[1];
        T = q[3];
        break;
    case Q_CONE: /* height radius thetamax */
        rho = q[1] * (1.0 - v), drho = -q[1], z = v * q[0], dz = q[0];
        T = q[2];
        break;
    case Q_DISK: /* height radius thetamax */
        rho = q[1] * (1.0 - v), drho = -q[1], z = q[0];
        T = q[2];
        break;
    case Q_PARABOLOID: { /* rmax zmin zmax thetamax */
        z = q[1] + v * (q[2] - q[1]), dz = q[2] - q[1];
        double zz = fmax(z, 1e-9 * q[2]);
        rho = q[0] * sqrt(zz / q[2]), drho = q[0] * dz / (2.0 * sqrt(zz * q[2]));
        T = q[3];
        break;
    }
    case Q_TORUS: { /* rmajor rminor phimin phimax thetamax */
        double phi = q[2] + v * (q[3] - q[2]), d = q[3] - q[2];
        rho = q[0] + q[1] * cos(phi), z = q[1] * sin(phi);
        drho = -q[1] * sin(phi) * d, dz = q[1] * cos(phi) * d;
        T = q[4];
        break;
    }
    default: { /* Q_HYPERBOLOID: x1 y1 z1 x2 y2 z2 thetamax */
        T = q[6];
        double th = u * T, c = cos(th), sn = sin(th);
        double dx = q[3] - q[0], dy = q[4] - q[1];
        double x = q[0] + v * dx, y = q[1] + v * dy;
        Vec3 p = v3((float)(x * c - y * sn), (float)(x * sn + y * c), (float)(q[2] + v * (q[5] - q[2])));
        Vec3 du = v3((float)(T * (-x * sn - y * c)), (float)(T * (x * c - y * sn)), 0.0f);
        Vec3 dv = v3((float)(dx * c - dy * sn), (float)(dx * sn + dy * c), q[5] - q[2]);
        *P = p, *dPdu = prim->big->quadric.reverse ? v3_neg(du) : du, *dPdv = dv;
        return;
    }
    }
    double th = u * T, c = cos(th), sn = sin(th);
    *P = v3((float)(rho * c), (float)(rho * sn), (float)z);
    Vec3 du = v3((float)(-rho * T * sn), (float)(rho * T * c), 0.0f);
    *dPdu = prim->big->quadric.reverse ? v3_neg(du) : du;
    *dPdv = v3((float)(drho * c), (float)(drho * sn), (float)dz);
}

/* A unit vector across t (any, when t is zero). */
static Vec3 any_perpendicular(Vec3 t)
{
    Vec3 a, b;
    float l = v3_length(t);
    v3_basis(l > 0.0f ? v3_scale(t, 1.0f / l) : v3(0, 0, 1), &a, &b);
    return a;
}

int geom_curve_segment(const Prim *prim, float u, float *t)
{
    int n = prim->curve.n_seg > 0 ? prim->curve.n_seg : 1;
    float x = fminf(fmaxf(u, 0.0f), 1.0f) * (float)n;
    int k = (int)x < n ? (int)x : n - 1;
    *t = x - (float)k;
    return k;
}

void geom_curve_frame(const Prim *prim, float u, Vec3 *C, Vec3 *T, float *w, float *dw, Vec3 *B)
{
    float b[4], db[4], t;
    int k = geom_curve_segment(prim, u, &t), n = prim->curve.n_seg > 0 ? prim->curve.n_seg : 1;
    const Vec3 *cp = prim->big->curve.cp + 3 * k;
    geom_bezier_basis(t, b, db);
    Vec3 c = v3(0, 0, 0), d = c;
    for (int j = 0; j < 4; j++) {
        c = v3_madd(c, cp[j], b[j]);
        d = v3_madd(d, cp[j], db[j] * (float)n);
    }
    Vec3 toward = prim->curve.shape == GEOM_SHAPE_SURFACE
                      ? v3_lerp(prim->big->curve.n[0], prim->big->curve.n[1], t)
                      : v3_sub(prim->curve.facing, c);
    Vec3 across = v3_cross(toward, d);
    float l = v3_length(across);
    *B = l > 1e-12f * v3_length(d) * v3_length(toward) && l > 0.0f ? v3_scale(across, 1.0f / l)
                                                                   : any_perpendicular(d);
    *C = c;
    *T = d;
    float w0 = prim->big->curve.width[k], w1 = prim->big->curve.width[k + 1];
    *w = w0 + (w1 - w0) * t;
    *dw = (w1 - w0) * (float)n;
}

/* A point's square: u along X, v along Y, X x Y its normal. */
static void eval_point(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    Vec3 Z = prim->point.shape == GEOM_SHAPE_ORIENTED_DISK ? prim->point.n
                                                     : v3_sub(prim->point.facing, prim->point.centre);
    float l = v3_length(Z);
    Z = l > 0.0f ? v3_scale(Z, 1.0f / l) : v3(0, 0, 1);
    Vec3 X = any_perpendicular(Z), Y = v3_cross(Z, X);
    float r = prim->point.radius;
    *P = v3_add(prim->point.centre,
                v3_add(v3_scale(X, r * (2.0f * u - 1.0f)), v3_scale(Y, r * (2.0f * v - 1.0f))));
    *dPdu = v3_scale(X, 2.0f * r);
    *dPdv = v3_scale(Y, 2.0f * r);
}

void geom_prim_eval(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv)
{
    const Vec3 *c = prim->type <= PRIM_TRIANGLE ? geom_prim_cp(prim) : NULL;
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
    case PRIM_TRIANGLE: /* weights, not differences: the corners are exact, bit for bit */
        *P = v3_add(v3_scale(c[0], 1.0f - u - v), v3_add(v3_scale(c[1], u), v3_scale(c[2], v)));
        *dPdu = v3_sub(c[1], c[0]);
        *dPdv = v3_sub(c[2], c[0]);
        break;
    case PRIM_SPHERE:
        eval_sphere(prim, u, v, P, dPdu, dPdv);
        break;
    case PRIM_SUBDIV: {
        float p[3], du[3], dv[3];
        geom_subdiv_eval(prim->subdiv.mesh, prim->subdiv.patch, u, v, p, du, dv);
        *P = v3(p[0], p[1], p[2]), *dPdu = v3(du[0], du[1], du[2]), *dPdv = v3(dv[0], dv[1], dv[2]);
        break;
    }
    case PRIM_QUADRIC: {
        Vec3 p, du, dv;
        const Mat4 *m = &prim->big->quadric.world_from_object;
        geom_quadric_eval(prim, u, v, &p, &du, &dv);
        *P = mat4_point(m, p);
        *dPdu = mat4_vector(m, du);
        *dPdv = mat4_vector(m, dv);
        break;
    }
    case PRIM_CURVE: {
        Vec3 C, T, B;
        float w, dw;
        geom_curve_frame(prim, u, &C, &T, &w, &dw, &B);
        *P = v3_madd(C, B, (v - 0.5f) * w);
        *dPdu = v3_madd(T, B, (v - 0.5f) * dw);
        *dPdv = v3_scale(B, w);
        break;
    }
    case PRIM_POINT:
        eval_point(prim, u, v, P, dPdu, dPdv);
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
        return v3_normalize(mat4_vector(&prim->big->sphere.normal_from_object, n));
    }
    geom_prim_eval(prim, u, v, &P, &du, &dv);
    Vec3 n = v3_cross(du, dv);
    float scale = v3_length(du) * v3_length(dv);
    if (v3_length(n) > 1e-6f * scale && scale > 0.0f)
        return v3_normalize(n);
    /* Degenerate: step toward the middle of the parameter domain until the
     * tangent plane is defined. The first step is tiny so that the normal
     * stays the limit of the neighbouring normals. */
    float cu = geom_prim_triangular(prim) ? 1.0f / 3.0f : 0.5f;
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

int geom_prim_corners(const Prim *prim)
{
    return geom_prim_triangular(prim) ? 3 : 4;
}

/* Interpolation weights of the control values and their u and v
 * derivatives: Bezier products (16), bilinear corners P00 P10 P01 P11 (4),
 * or barycentric corners (3). Returns the count. */
static int primvar_weights(const Prim *prim, int cubic, float u, float v, float w[16],
                           float wu[16], float wv[16])
{
    if (cubic) {
        float bu[4], dbu[4], bv[4], dbv[4];
        geom_bezier_basis(u, bu, dbu);
        geom_bezier_basis(v, bv, dbv);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                w[4 * j + i] = bu[i] * bv[j];
                wu[4 * j + i] = dbu[i] * bv[j];
                wv[4 * j + i] = bu[i] * dbv[j];
            }
        return 16;
    }
    if (prim->type == PRIM_TRIANGLE) {
        const float t[3] = {1.0f - u - v, u, v}, tu[3] = {-1, 1, 0}, tv[3] = {-1, 0, 1};
        memcpy(w, t, sizeof t), memcpy(wu, tu, sizeof tu), memcpy(wv, tv, sizeof tv);
        return 3;
    }
    const float b[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
    const float bu[4] = {-(1 - v), 1 - v, -v, v}, bv[4] = {-(1 - u), -u, 1 - u, u};
    memcpy(w, b, sizeof b), memcpy(wu, bu, sizeof bu), memcpy(wv, bv, sizeof bv);
    return 4;
}

void geom_prim_primvars(const Prim *prim, const float *pool, float u, float v,
                        PrimvarSample *out)
{
    static const unsigned bits[GEOM_N_PV] = {GEOM_PV_N, GEOM_PV_ST, GEOM_PV_CS, GEOM_PV_OS};
    static const int sizes[GEOM_N_PV] = {3, 2, 3, 3};
    if (!prim->pv)
        return;
    if (prim->type == PRIM_SUBDIV) { /* evaluated with the surface */
        float N[3], st[2], dst[4], Cs[3], Os[3];
        unsigned got =
            geom_subdiv_primvars(prim->subdiv.mesh, prim->subdiv.patch, u, v, N, st, dst, Cs, Os);
        if (got & GEOM_PV_N)
            out->N = v3_normalize(v3(N[0], N[1], N[2]));
        if (got & GEOM_PV_ST)
            memcpy(out->st, st, sizeof out->st), memcpy(out->dst, dst, sizeof out->dst);
        if (got & GEOM_PV_CS)
            out->Cs = v3(Cs[0], Cs[1], Cs[2]);
        if (got & GEOM_PV_OS)
            out->Os = v3(Os[0], Os[1], Os[2]);
        return;
    }
    const float *p = pool + prim->pv_first;
    if (prim->type == PRIM_CURVE) { /* per segment end, linear between, alike across */
        float t;
        int k = geom_curve_segment(prim, u, &t), n = prim->curve.n_seg > 0 ? prim->curve.n_seg : 1;
        for (int b = 0; b < GEOM_N_PV; b++) {
            if (!(prim->pv & bits[b]))
                continue;
            const float *x0 = p + (size_t)k * (size_t)sizes[b], *x1 = x0 + sizes[b];
            float val[3], du[3];
            for (int c = 0; c < sizes[b]; c++)
                val[c] = x0[c] + (x1[c] - x0[c]) * t, du[c] = (x1[c] - x0[c]) * (float)n;
            if (bits[b] == GEOM_PV_ST) {
                out->st[0] = val[0], out->st[1] = val[1];
                out->dst[0] = du[0], out->dst[1] = 0.0f, out->dst[2] = du[1], out->dst[3] = 0.0f;
            } else if (bits[b] == GEOM_PV_CS)
                out->Cs = v3(val[0], val[1], val[2]);
            else if (bits[b] == GEOM_PV_OS)
                out->Os = v3(val[0], val[1], val[2]);
            else
                out->N = v3_normalize(v3(val[0], val[1], val[2]));
            p += (size_t)(n + 1) * (size_t)sizes[b];
        }
        return;
    }
    for (int b = 0; b < GEOM_N_PV; b++) {
        if (!(prim->pv & bits[b]))
            continue;
        float w[16], wu[16], wv[16], val[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
        int n = primvar_weights(prim, (prim->pv_cubic & bits[b]) != 0, u, v, w, wu, wv);
        for (int k = 0; k < n; k++, p += sizes[b])
            for (int c = 0; c < sizes[b]; c++) {
                val[c] += w[k] * p[c];
                du[c] += wu[k] * p[c];
                dv[c] += wv[k] * p[c];
            }
        if (bits[b] == GEOM_PV_N)
            out->N = v3_normalize(v3(val[0], val[1], val[2]));
        else if (bits[b] == GEOM_PV_ST) {
            out->st[0] = val[0], out->st[1] = val[1];
            out->dst[0] = du[0], out->dst[1] = dv[0], out->dst[2] = du[1], out->dst[3] = dv[1];
        } else if (bits[b] == GEOM_PV_CS)
            out->Cs = v3(val[0], val[1], val[2]);
        else
            out->Os = v3(val[0], val[1], val[2]);
    }
}
