/*
 * io/rib_geom.c — matrices, polygon tessellation and basis changes of the
 * RIB reader (rib_internal.h).
 *
 * Tessellation: holes are bridged to the outline (each hole's vertex of
 * largest u joined to the nearest outline vertex the joining segment can
 * see), then the simple polygon is ear-clipped in 2D. Ear clipping is
 * O(n^2) per polygon (O(n^3) at worst); polygons of more than RIB_MAX_EARCLIP vertices are
 * fanned instead so a hostile file cannot make it quadratic-cubed.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_internal.h"

#define RIB_MAX_EARCLIP 512

/* ------------------------------------------------------------ matrices */

void rib_mat_identity(float m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1;
}

void rib_mat_mul(const float a[16], const float b[16], float out[16])
{
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += (double)a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = (float)s;
        }
    memcpy(out, r, sizeof r);
}

int rib_mat_inverse(const float m[16], float out[16])
{
    double a[4][8];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 8; j++)
            a[i][j] = j < 4 ? m[4 * i + j] : (j - 4 == i);
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (!(fabs(a[piv][c]) > 1e-30))
            return -1;
        if (piv != c)
            for (int j = 0; j < 8; j++) {
                double t = a[c][j];
                a[c][j] = a[piv][j];
                a[piv][j] = t;
            }
        double inv = 1.0 / a[c][c];
        for (int j = 0; j < 8; j++)
            a[c][j] *= inv;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int j = 0; j < 8; j++)
                    a[r][j] -= f * a[c][j];
            }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            out[4 * i + j] = (float)a[i][j + 4];
    return 0;
}

double rib_mat_det3(const float m[16])
{
    return (double)m[0] * ((double)m[5] * m[10] - (double)m[6] * m[9]) -
           (double)m[1] * ((double)m[4] * m[10] - (double)m[6] * m[8]) +
           (double)m[2] * ((double)m[4] * m[9] - (double)m[5] * m[8]);
}

double rib_polygon_area(const float M[16], const float *P, const int *idx, int n)
{
    double w[3][3], area = 0.0; /* the fan's apex and the last two points, placed */
    for (int k = 0; k < n; k++) {
        const float *p = &P[3 * idx[k]];
        double *q = w[k < 2 ? k : 2];
        for (int i = 0; i < 3; i++)
            q[i] =
                (double)M[4 * i] * p[0] + (double)M[4 * i + 1] * p[1] + (double)M[4 * i + 2] * p[2];
        if (k >= 2) {
            double a[3], b[3];
            for (int i = 0; i < 3; i++)
                a[i] = w[1][i] - w[0][i], b[i] = w[2][i] - w[0][i];
            double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2],
                   cz = a[0] * b[1] - a[1] * b[0];
            area += 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
            memcpy(w[1], w[2], sizeof w[1]);
        }
    }
    return area;
}

/* The point (r, z) a fraction t along quadric type's profile (RenderMan's
 * parameters v), which it sweeps about z. */
static void quadric_profile(int type, const float *v, double t, double *r, double *z)
{
    switch (type) {
    case RAYES_QUADRIC_SPHERE: { /* radius zmin zmax */
        double R = fabs(v[0]), lo = asin(fmax(-1.0, fmin(1.0, v[1] / fmax(R, 1e-30)))),
               hi = asin(fmax(-1.0, fmin(1.0, v[2] / fmax(R, 1e-30))));
        double phi = lo + t * (hi - lo);
        *r = R * cos(phi), *z = R * sin(phi);
        break;
    }
    case RAYES_QUADRIC_CYLINDER: /* radius zmin zmax */
        *r = fabs(v[0]), *z = v[1] + t * (v[2] - v[1]);
        break;
    case RAYES_QUADRIC_CONE: /* height radius */
        *r = fabs(v[1]) * (1.0 - t), *z = t * v[0];
        break;
    case RAYES_QUADRIC_DISK: /* height radius */
        *r = fabs(v[1]) * t, *z = v[0];
        break;
    case RAYES_QUADRIC_PARABOLOID: /* rmax zmin zmax */
        *z = v[1] + t * (v[2] - v[1]);
        *r = v[2] != 0.0f ? fabs(v[0]) * sqrt(fmax(0.0, *z / v[2])) : 0.0;
        break;
    case RAYES_QUADRIC_HYPERBOLOID: { /* point1 point2: the line swept */
        double x = v[0] + t * (v[3] - v[0]), y = v[1] + t * (v[4] - v[1]);
        *r = sqrt(x * x + y * y), *z = v[2] + t * (v[5] - v[2]);
        break;
    }
    default: { /* torus: major minor phimin phimax */
        double phi = (v[2] + t * (v[3] - v[2])) * M_PI / 180.0;
        *r = v[0] + v[1] * cos(phi), *z = v[1] * sin(phi);
        break;
    }
    }
}

double rib_quadric_area(const float M[16], int type, const float *v)
{
    static const int theta_at[7] = {3, 3, 2, 2, 3, 6, 4}; /* thetamax's index */
    if (type < 0 || type > 6)
        return 0.0;
    double theta = fmin(fabs((double)v[theta_at[type]]), 360.0) * M_PI / 180.0, sum = 0.0, r0, z0;
    quadric_profile(type, v, 0.0, &r0, &z0);
    for (int k = 1; k <= 256; k++) {
        double r1, z1;
        quadric_profile(type, v, k / 256.0, &r1, &z1);
        sum += 0.5 * (fabs(r0) + fabs(r1)) * hypot(r1 - r0, z1 - z0);
        r0 = r1, z0 = z1;
    }
    return theta * sum * pow(fabs(rib_mat_det3(M)), 2.0 / 3.0);
}

void rib_mat_rotate(float deg, const float axis[3], float m[16])
{
    double len =
        sqrt((double)axis[0] * axis[0] + (double)axis[1] * axis[1] + (double)axis[2] * axis[2]);
    double x = axis[0] / len, y = axis[1] / len, z = axis[2] / len;
    double th = deg * M_PI / 180, c = cos(th), s = sin(th), t = 1 - c;
    rib_mat_identity(m);
    m[0] = (float)(t * x * x + c), m[1] = (float)(t * x * y - s * z);
    m[2] = (float)(t * x * z + s * y), m[4] = (float)(t * x * y + s * z);
    m[5] = (float)(t * y * y + c), m[6] = (float)(t * y * z - s * x);
    m[8] = (float)(t * x * z - s * y), m[9] = (float)(t * y * z + s * x);
    m[10] = (float)(t * z * z + c);
}

/* The polar decomposition of m's 3 x 3 part, A = Q S (Q a rotation, S
 * symmetric; a mirror's -1 goes into S), by Higham's iteration Q <- (Q +
 * Q^-T) / 2. Returns 0, or -1 when A is singular. */
static int polar(const float m[16], double Q[3][3], double S[3][3])
{
    double A[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            A[r][c] = m[4 * r + c];
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                 A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(fabs(det) > 1e-30) || !isfinite(det))
        return -1;
    double sign = det < 0 ? -1 : 1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            Q[r][c] = sign * A[r][c];
    for (int it = 0; it < 40; it++) {
        double d = Q[0][0] * (Q[1][1] * Q[2][2] - Q[1][2] * Q[2][1]) -
                   Q[0][1] * (Q[1][0] * Q[2][2] - Q[1][2] * Q[2][0]) +
                   Q[0][2] * (Q[1][0] * Q[2][1] - Q[1][1] * Q[2][0]);
        double C[3][3]; /* the cofactors: Q^-T = C / det */
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
                C[r][c] = Q[r1][c1] * Q[r2][c2] - Q[r1][c2] * Q[r2][c1];
            }
        double change = 0;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double q = 0.5 * (Q[r][c] + C[r][c] / d);
                change = fmax(change, fabs(q - Q[r][c]));
                Q[r][c] = q;
            }
        if (change < 1e-12)
            break;
    }
    for (int r = 0; r < 3; r++) /* S = Q^T A */
        for (int c = 0; c < 3; c++)
            S[r][c] = Q[0][r] * A[0][c] + Q[1][r] * A[1][c] + Q[2][r] * A[2][c];
    return 0;
}

/* A rotation matrix's unit quaternion (w, x, y, z). */
static void quaternion(double R[3][3], double q[4])
{
    double t = R[0][0] + R[1][1] + R[2][2];
    if (t > 0) {
        double s = 2 * sqrt(t + 1);
        q[0] = s / 4, q[1] = (R[2][1] - R[1][2]) / s, q[2] = (R[0][2] - R[2][0]) / s,
        q[3] = (R[1][0] - R[0][1]) / s;
    } else if (R[0][0] > R[1][1] && R[0][0] > R[2][2]) {
        double s = 2 * sqrt(1 + R[0][0] - R[1][1] - R[2][2]);
        q[0] = (R[2][1] - R[1][2]) / s, q[1] = s / 4, q[2] = (R[0][1] + R[1][0]) / s,
        q[3] = (R[0][2] + R[2][0]) / s;
    } else if (R[1][1] > R[2][2]) {
        double s = 2 * sqrt(1 + R[1][1] - R[0][0] - R[2][2]);
        q[0] = (R[0][2] - R[2][0]) / s, q[1] = (R[0][1] + R[1][0]) / s, q[2] = s / 4,
        q[3] = (R[1][2] + R[2][1]) / s;
    } else {
        double s = 2 * sqrt(1 + R[2][2] - R[0][0] - R[1][1]);
        q[0] = (R[1][0] - R[0][1]) / s, q[1] = (R[0][2] + R[2][0]) / s,
        q[2] = (R[1][2] + R[2][1]) / s, q[3] = s / 4;
    }
}

float rib_mat_turn(const float a[16], const float b[16])
{
    double Qa[3][3], Qb[3][3], S[3][3], qa[4], qb[4];
    if (polar(a, Qa, S) != 0 || polar(b, Qb, S) != 0)
        return 0;
    quaternion(Qa, qa);
    quaternion(Qb, qb);
    double d = fabs(qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3]);
    return (float)(2 * acos(fmin(d, 1.0)));
}

void rib_mat_blend(const float a[16], const float b[16], float f, float out[16])
{
    double Qa[3][3], Qb[3][3], Sa[3][3], Sb[3][3], qa[4], qb[4], q[4];
    if (polar(a, Qa, Sa) != 0 || polar(b, Qb, Sb) != 0 ||
        (rib_mat_det3(a) < 0) != (rib_mat_det3(b) < 0)) {
        for (int k = 0; k < 16; k++) /* singular, or a mirror at one end only */
            out[k] = a[k] + (b[k] - a[k]) * f;
        return;
    }
    quaternion(Qa, qa);
    quaternion(Qb, qb);
    double d = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
    if (d < 0) /* the shorter arc */
        for (int k = 0; k < 4; k++)
            qb[k] = -qb[k];
    d = fabs(d);
    double wa = 1 - f, wb = f;
    if (d < 0.9999999) {
        double th = acos(d), s = sin(th);
        wa = sin((1 - f) * th) / s, wb = sin(f * th) / s;
    }
    double n = 0;
    for (int k = 0; k < 4; k++)
        q[k] = wa * qa[k] + wb * qb[k], n += q[k] * q[k];
    n = sqrt(n);
    for (int k = 0; k < 4; k++)
        q[k] /= n;
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                      {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                      {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double v = 0;
            for (int k = 0; k < 3; k++)
                v += R[r][k] * (Sa[k][c] + (Sb[k][c] - Sa[k][c]) * f);
            out[4 * r + c] = (float)v;
        }
    for (int r = 0; r < 4; r++) /* translation and the projective row: linear */
        out[4 * r + 3] = a[4 * r + 3] + (b[4 * r + 3] - a[4 * r + 3]) * f;
    for (int c = 0; c < 3; c++)
        out[12 + c] = a[12 + c] + (b[12 + c] - a[12 + c]) * f;
}

/* --------------------------------------------------------- tessellation */

void rib_faces_fini(RibFaces *f)
{
    free(f->n_verts);
    free(f->idx);
    memset(f, 0, sizeof *f);
}

static int faces_add(RibFaces *f, const int *v, int n, int flip)
{
    if (f->n_faces + 1 > f->cap_faces) {
        size_t cap = f->cap_faces ? 2 * f->cap_faces : 16;
        int *nv = realloc(f->n_verts, cap * sizeof *nv);
        if (!nv)
            return -1;
        f->n_verts = nv;
        f->cap_faces = cap;
    }
    if (f->n_idx + (size_t)n > f->cap_idx) {
        size_t cap = f->cap_idx ? 2 * f->cap_idx : 64;
        while (cap < f->n_idx + (size_t)n)
            cap *= 2;
        int *ix = realloc(f->idx, cap * sizeof *ix);
        if (!ix)
            return -1;
        f->idx = ix;
        f->cap_idx = cap;
    }
    f->n_verts[f->n_faces++] = n;
    for (int k = 0; k < n; k++)
        f->idx[f->n_idx++] = flip ? v[n - 1 - k] : v[k];
    return 0;
}

static void newell(const float *P, const int *v, size_t n, double nrm[3])
{
    nrm[0] = nrm[1] = nrm[2] = 0;
    for (size_t i = 0; i < n; i++) {
        const float *a = &P[3 * v[i]], *b = &P[3 * v[(i + 1) % n]];
        nrm[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        nrm[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        nrm[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
}

/* A quad is kept when it is planar (within 1e-4 of its size) and convex. */
int rib_quad_kept(const float *P, const int *v)
{
    double n[3];
    newell(P, v, 4, n);
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0))
        return 0;
    for (int i = 0; i < 4; i++) {
        const float *a = &P[3 * v[i]], *b = &P[3 * v[(i + 1) % 4]], *c = &P[3 * v[(i + 2) % 4]];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
        double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
        if (cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2] <= 0)
            return 0;
    }
    const float *p0 = &P[3 * v[0]];
    double size = 0;
    for (int i = 1; i < 4; i++) {
        const float *p = &P[3 * v[i]];
        double d = (n[0] * (p[0] - p0[0]) + n[1] * (p[1] - p0[1]) + n[2] * (p[2] - p0[2])) / len;
        double e = fabs(p[0] - p0[0]) + fabs(p[1] - p0[1]) + fabs(p[2] - p0[2]);
        size = e > size ? e : size;
        if (fabs(d) > 1e-4 * size + 1e-30 && fabs(d) > 1e-4 * e)
            return 0;
    }
    return 1;
}

typedef struct V2 {
    double u, v;
    int id; /* index into P */
} V2;

static double cross2(V2 a, V2 b, V2 c)
{
    return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

static int fan(const int *v, size_t n, int flip, RibFaces *out)
{
    for (size_t i = 1; i + 1 < n; i++) {
        int t[3] = {v[0], v[i], v[i + 1]};
        if (faces_add(out, t, 3, flip) != 0)
            return -1;
    }
    return 0;
}

static int point_in_tri(V2 p, V2 a, V2 b, V2 c)
{
    return cross2(a, b, p) > 0 && cross2(b, c, p) > 0 && cross2(c, a, p) > 0;
}

static int earclip(V2 *poly, size_t n, int flip, RibFaces *out)
{
    size_t guard = 0;
    size_t i = 0;
    while (n > 3) {
        size_t ip = (i + n - 1) % n, in = (i + 1) % n;
        int ear = cross2(poly[ip], poly[i], poly[in]) > 0;
        for (size_t k = 0; ear && k < n; k++) {
            if (k == ip || k == i || k == in)
                continue;
            V2 q = poly[k];
            if ((q.u == poly[ip].u && q.v == poly[ip].v) || (q.u == poly[i].u && q.v == poly[i].v) ||
                (q.u == poly[in].u && q.v == poly[in].v))
                continue;
            if (point_in_tri(q, poly[ip], poly[i], poly[in]))
                ear = 0;
        }
        if (ear || guard >= n) {
            int t[3] = {poly[ip].id, poly[i].id, poly[in].id};
            if (faces_add(out, t, 3, flip) != 0)
                return -1;
            memmove(&poly[i], &poly[i + 1], (n - i - 1) * sizeof *poly);
            n--;
            if (i >= n)
                i = 0;
            guard = 0;
        } else {
            i = (i + 1) % n;
            guard++;
        }
    }
    int t[3] = {poly[0].id, poly[1].id, poly[2].id};
    return faces_add(out, t, 3, flip);
}

static int segs_cross(V2 a, V2 b, V2 c, V2 d)
{
    double d1 = cross2(a, b, c), d2 = cross2(a, b, d), d3 = cross2(c, d, a), d4 = cross2(c, d, b);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Splices hole h (nh points, clockwise) into poly (n points); poly has room. */
static size_t bridge(V2 *poly, size_t n, const V2 *h, size_t nh)
{
    size_t hk = 0;
    for (size_t k = 1; k < nh; k++)
        if (h[k].u > h[hk].u)
            hk = k;
    size_t best = 0;
    double best_d = INFINITY;
    for (size_t i = 0; i < n; i++) {
        double du = poly[i].u - h[hk].u, dv = poly[i].v - h[hk].v, d = du * du + dv * dv;
        if (d >= best_d)
            continue;
        int blocked = 0;
        for (size_t e = 0; !blocked && e < n; e++)
            blocked = segs_cross(h[hk], poly[i], poly[e], poly[(e + 1) % n]);
        for (size_t e = 0; !blocked && e < nh; e++)
            blocked = segs_cross(h[hk], poly[i], h[e], h[(e + 1) % nh]);
        if (!blocked) {
            best = i;
            best_d = d;
        }
    }
    /* poly[0..best], h[hk..], h[..hk], h[hk], poly[best..n) */
    size_t tail = n - best;
    memmove(&poly[best + nh + 2], &poly[best], tail * sizeof *poly);
    for (size_t k = 0; k <= nh; k++)
        poly[best + 1 + k] = h[(hk + k) % nh];
    return n + nh + 2;
}

static double signed_area(const V2 *p, size_t n)
{
    double a = 0;
    for (size_t i = 0; i < n; i++)
        a += p[i].u * p[(i + 1) % n].v - p[(i + 1) % n].u * p[i].v;
    return a / 2;
}

int rib_tessellate(const float *P, const int *loop_n, size_t n_loops, const int *idx, int flip,
                   RibFaces *out)
{
    size_t n0 = (size_t)loop_n[0], total = 0;
    for (size_t k = 0; k < n_loops; k++)
        total += (size_t)loop_n[k];
    if (n0 < 3)
        return 0;
    if (n_loops == 1 && n0 == 3)
        return faces_add(out, idx, 3, flip);
    if (n_loops == 1 && n0 == 4 && rib_quad_kept(P, idx))
        return faces_add(out, idx, 4, flip);
    double nrm[3];
    newell(P, idx, n0, nrm);
    int ax = fabs(nrm[0]) > fabs(nrm[1]) ? (fabs(nrm[0]) > fabs(nrm[2]) ? 0 : 2)
                                         : (fabs(nrm[1]) > fabs(nrm[2]) ? 1 : 2);
    if (!(fabs(nrm[ax]) > 0) || total + 2 * n_loops > RIB_MAX_EARCLIP)
        return fan(idx, n0, flip, out);
    int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
    if (nrm[ax] < 0) {
        int t = a1;
        a1 = a2;
        a2 = t;
    }
    V2 *all = malloc((total + 1) * sizeof *all);
    V2 *poly = malloc((total + 2 * n_loops + 1) * sizeof *poly);
    if (!all || !poly) {
        free(all);
        free(poly);
        return -1;
    }
    for (size_t k = 0; k < total; k++)
        all[k] = (V2){P[3 * idx[k] + a1], P[3 * idx[k] + a2], idx[k]};
    memcpy(poly, all, n0 * sizeof *poly);
    size_t n = n0, start = n0;
    for (size_t h = 1; h < n_loops; h++) {
        size_t nh = (size_t)loop_n[h];
        V2 *hole = &all[start];
        start += nh;
        if (nh < 3)
            continue;
        if (signed_area(hole, nh) > 0) /* holes go clockwise */
            for (size_t k = 0; k < nh / 2; k++) {
                V2 t = hole[k];
                hole[k] = hole[nh - 1 - k];
                hole[nh - 1 - k] = t;
            }
        n = bridge(poly, n, hole, nh);
    }
    int e = earclip(poly, n, flip, out);
    free(all);
    free(poly);
    return e;
}

/* --------------------------------------------------------------- bases */

int rib_basis_named(const char *name, float b[16], int *step)
{
    static const float bezier[16] = {-1, 3, -3, 1, 3, -6, 3, 0, -3, 3, 0, 0, 1, 0, 0, 0};
    static const float bspline[16] = {-1 / 6.f, 3 / 6.f, -3 / 6.f, 1 / 6.f, 3 / 6.f, -6 / 6.f,
                                      3 / 6.f,  0,       -3 / 6.f, 0,       3 / 6.f, 0,
                                      1 / 6.f,  4 / 6.f, 1 / 6.f,  0};
    static const float catmull[16] = {-0.5f, 1.5f, -1.5f, 0.5f, 1, -2.5f, 2, -0.5f,
                                      -0.5f, 0,    0.5f,  0,    0, 1,     0, 0};
    static const float hermite[16] = {2, 1, -2, 1, -3, -2, 3, -1, 0, 1, 0, 0, 1, 0, 0, 0};
    static const float power[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    static const struct {
        const char *name;
        const float *m;
        int step;
    } table[] = {{"bezier", bezier, 3},     {"b-spline", bspline, 1}, {"bspline", bspline, 1},
                 {"catmull-rom", catmull, 1}, {"catmullrom", catmull, 1}, {"hermite", hermite, 2},
                 {"power", power, 4}};
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strcmp(name, table[i].name) == 0) {
            memcpy(b, table[i].m, 16 * sizeof *b);
            *step = table[i].step;
            return 0;
        }
    return -1;
}

/* C = Mbezier^-1 B: the matrix taking control points in basis B to Bezier
 * control points of the same curve. */
static void to_bezier_matrix(const float B[16], double C[16])
{
    static const double bezier_inv[16] = {0, 0, 0, 1, 0, 0, 1 / 3.0, 1, 0, 1 / 3.0, 2 / 3.0, 1,
                                          1, 1, 1,    1};
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += bezier_inv[4 * i + k] * B[4 * k + j];
            C[4 * i + j] = s;
        }
}

void rib_basis_to_bezier(const float bu[16], const float bv[16], const float G[16][3],
                         float out[16][3])
{
    double cu[16], cv[16];
    to_bezier_matrix(bu, cu);
    to_bezier_matrix(bv, cv);
    for (int c = 0; c < 3; c++) {
        double t[4][4]; /* t[j][i] = sum_k cu[i][k] G[j][k] (along u) */
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                double s = 0;
                for (int k = 0; k < 4; k++)
                    s += cu[4 * i + k] * G[4 * j + k][c];
                t[j][i] = s;
            }
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                double s = 0;
                for (int l = 0; l < 4; l++)
                    s += cv[4 * j + l] * t[l][i];
                out[4 * j + i][c] = (float)s;
            }
    }
}
