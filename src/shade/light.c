/*
 * shade/light.c — sampling, intersecting and looking up lights (light.h).
 */
#include "shade/light.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shade/noise.h"
#include "shade/texture.h"
#include "util/sky.h"

static const float PI = 3.14159265358979f;

int light_category_match(const Light *l, const char *category)
{
    if (!category || !category[0])
        return 1;
    int negate = category[0] == '-';
    const char *name = category + negate;
    size_t n = strlen(name);
    int found = 0;
    for (const char *c = l->category; *c;) {
        while (*c == ',' || *c == ' ')
            c++;
        const char *end = c;
        while (*end && *end != ',')
            end++;
        const char *last = end;
        while (last > c && last[-1] == ' ')
            last--;
        if ((size_t)(last - c) == n && n > 0 && strncmp(c, name, n) == 0)
            found = 1;
        c = end;
    }
    return negate ? !found : found;
}

/* ------------------------------------------------------------ quads */

/* (a, b) of the quad point nearest y, by Gauss-Newton (exact in one step
 * for a parallelogram). */
static void quad_invert(const Light *l, Vec3 y, float *a, float *b)
{
    float u = 0.5f, v = 0.5f;
    for (int it = 0; it < 8; it++) {
        Vec3 e0 = v3_lerp(l->P[0], l->P[1], u), e1 = v3_lerp(l->P[2], l->P[3], u);
        Vec3 p = v3_lerp(e0, e1, v);
        Vec3 du = v3_lerp(v3_sub(l->P[1], l->P[0]), v3_sub(l->P[3], l->P[2]), v);
        Vec3 dv = v3_sub(e1, e0);
        Vec3 r = v3_sub(y, p);
        float a11 = v3_dot(du, du), a12 = v3_dot(du, dv), a22 = v3_dot(dv, dv);
        float b1 = v3_dot(du, r), b2 = v3_dot(dv, r);
        float det = a11 * a22 - a12 * a12;
        if (!(fabsf(det) > 0.0f))
            break;
        float su = (a22 * b1 - a12 * b2) / det, sv = (a11 * b2 - a12 * b1) / det;
        u += su;
        v += sv;
        if (fabsf(su) + fabsf(sv) < 1e-6f)
            break;
    }
    *a = u;
    *b = v;
}

static int ray_triangle(Vec3 o, Vec3 d, Vec3 p0, Vec3 p1, Vec3 p2, float *t)
{
    Vec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0), pv = v3_cross(d, e2);
    float det = v3_dot(e1, pv);
    if (fabsf(det) < 1e-20f)
        return 0;
    float inv = 1.0f / det;
    Vec3 tv = v3_sub(o, p0);
    float u = v3_dot(tv, pv) * inv;
    if (u < 0.0f || u > 1.0f)
        return 0;
    Vec3 qv = v3_cross(tv, e1);
    float v = v3_dot(d, qv) * inv;
    if (v < 0.0f || u + v > 1.0f)
        return 0;
    *t = v3_dot(e2, qv) * inv;
    return *t > 0.0f;
}

/* Solid-angle pdf and radiance of the quad point y (normal ny, |ny| the
 * Jacobian) seen along wi at distance d. */
/* What a quad or disk light's cone lets out at cos_y, the cosine off its
 * normal: 1 inside cone_start, 0 beyond cone, smoothstep between (in the
 * angle, as USD's shaping:cone:softness). */
static float cone_factor(const Light *l, float cos_y)
{
    if (!(l->cone > 0.0f))
        return 1.0f;
    float t = acosf(fminf(fmaxf(cos_y, -1.0f), 1.0f));
    if (t >= l->cone)
        return 0.0f;
    if (t <= l->cone_start)
        return 1.0f;
    float x = (t - l->cone_start) / (l->cone - l->cone_start);
    return 1.0f - x * x * (3.0f - 2.0f * x);
}

float light_cone_factor(const Light *l, float cos_y)
{
    return cone_factor(l, cos_y);
}

static int area_finish(const Light *l, Vec3 wi, float d, Vec3 ny, LightSample *s)
{
    float jac = v3_length(ny);
    float cos_y = -v3_dot(ny, wi) / (jac > 0.0f ? jac : 1.0f);
    if (!(cos_y > 0.0f) || !(jac > 0.0f) || !(d > 0.0f))
        return 0;
    float k = cone_factor(l, cos_y);
    if (!(k > 0.0f))
        return 0;
    s->wi = wi;
    s->dist = d;
    s->Li = k < 1.0f ? v3_scale(l->L, k) : l->L;
    s->pdf = d * d / (cos_y * jac);
    return 1;
}

/* ------------------------------------------------- spherical rectangles
 *
 * A rectangular quad light is sampled uniformly in the solid angle it
 * subtends (Urena, Fajardo and King 2013, "An area-preserving
 * parametrization for spherical rectangles"), not by area: by area, a
 * point near a large light (a wall beside a window-sized one) draws most
 * samples where the light is seen at a grazing angle, and their 1 / d^2
 * weights made its direct light speckle (Bitterli's kitchen at 64 shadow
 * rays a pixel; a point 0.05 below a 2 x 2 light, 16 samples: 8% off by
 * area, 1.6% by solid angle). Quads that are not rectangles, and
 * rectangles under SPHRECT_MIN steradians (about as far as they are wide,
 * where both weigh their samples alike and area sampling is cheaper: at
 * every solid angle the set-up and the trigonometry cost the memo's box
 * about 10% of its render), keep area sampling; sampling and
 * light_intersect's pdf use the same rule. */

#define SPHRECT_MIN 0.25f

typedef struct SphRect {
    Vec3 o, x, y, z;
    float x0, x1, y0, y1, z0, b0, b1, k, S;
} SphRect;

static int sphrect_setup(const Light *l, Vec3 o, SphRect *r);

/* Nonzero, and r set up, if l is a rectangle of solid angle at least
 * SPHRECT_MIN whose emitting side o is on. A shading point draws all its
 * samples of a light in a row: the thread's last answer is kept (keyed by
 * the light's corners, since a moving light is a copy made per time). */
static int sphrect_init(const Light *l, Vec3 o, SphRect *r)
{
    static _Thread_local struct {
        Vec3 P[4], o;
        SphRect r;
        int ok, valid;
    } last;
    if (last.valid && memcmp(last.P, l->P, sizeof last.P) == 0 && last.o.x == o.x &&
        last.o.y == o.y && last.o.z == o.z) {
        *r = last.r;
        return last.ok;
    }
    last.ok = sphrect_setup(l, o, &last.r);
    memcpy(last.P, l->P, sizeof last.P);
    last.o = o;
    last.valid = 1;
    *r = last.r;
    return last.ok;
}

static int sphrect_setup(const Light *l, Vec3 o, SphRect *r)
{
    Vec3 e1 = v3_sub(l->P[1], l->P[0]), e2 = v3_sub(l->P[2], l->P[0]);
    float l1 = v3_length(e1), l2 = v3_length(e2);
    Vec3 off = v3_sub(l->P[3], v3_add(l->P[1], e2));
    if (!(l1 > 0.0f && l2 > 0.0f) || fabsf(v3_dot(e1, e2)) > 1e-4f * l1 * l2 ||
        v3_length(off) > 1e-4f * (l1 + l2))
        return 0;
    Vec3 n = v3_cross(e1, e2), d = v3_sub(l->P[0], o);
    if (!(v3_dot(d, n) < 0.0f)) /* behind the emitting side: nothing, as by area */
        return 0;
    r->o = o;
    r->x = v3_scale(e1, 1.0f / l1);
    r->y = v3_scale(e2, 1.0f / l2);
    r->z = v3_cross(r->x, r->y);
    r->x0 = v3_dot(d, r->x), r->y0 = v3_dot(d, r->y), r->z0 = v3_dot(d, r->z);
    if (r->z0 > 0.0f)
        r->z0 = -r->z0, r->z = v3_neg(r->z);
    r->x1 = r->x0 + l1, r->y1 = r->y0 + l2;
    Vec3 v00 = v3(r->x0, r->y0, r->z0), v01 = v3(r->x0, r->y1, r->z0);
    Vec3 v10 = v3(r->x1, r->y0, r->z0), v11 = v3(r->x1, r->y1, r->z0);
    Vec3 n0 = v3_normalize(v3_cross(v00, v10)), n1 = v3_normalize(v3_cross(v10, v11));
    Vec3 n2 = v3_normalize(v3_cross(v11, v01)), n3 = v3_normalize(v3_cross(v01, v00));
    float g0 = acosf(fminf(fmaxf(-v3_dot(n0, n1), -1.0f), 1.0f));
    float g1 = acosf(fminf(fmaxf(-v3_dot(n1, n2), -1.0f), 1.0f));
    float g2 = acosf(fminf(fmaxf(-v3_dot(n2, n3), -1.0f), 1.0f));
    float g3 = acosf(fminf(fmaxf(-v3_dot(n3, n0), -1.0f), 1.0f));
    r->b0 = n0.z, r->b1 = n2.z;
    r->k = 2.0f * PI - g2 - g3;
    r->S = g0 + g1 - r->k;
    return isfinite(r->S) && r->S >= SPHRECT_MIN;
}

/* The rectangle's point of solid-angle parameters (a, b) in [0, 1)^2. */
static Vec3 sphrect_point(const SphRect *r, float a, float b)
{
    float au = a * r->S + r->k, sa = sinf(au);
    float fu = (cosf(au) * r->b0 - r->b1) / (sa != 0.0f ? sa : 1e-30f);
    float cu = copysignf(1.0f, fu) / sqrtf(fu * fu + r->b0 * r->b0);
    cu = fminf(fmaxf(cu, -1.0f), 1.0f);
    float xu = -(cu * r->z0) / fmaxf(sqrtf(1.0f - cu * cu), 1e-30f);
    xu = fminf(fmaxf(xu, r->x0), r->x1);
    float dd = sqrtf(xu * xu + r->z0 * r->z0);
    float h0 = r->y0 / sqrtf(dd * dd + r->y0 * r->y0), h1 = r->y1 / sqrtf(dd * dd + r->y1 * r->y1);
    float hv = h0 + b * (h1 - h0), hv2 = hv * hv;
    float yv = hv2 < 1.0f - 1e-6f ? hv * dd / sqrtf(1.0f - hv2) : r->y1;
    yv = fminf(fmaxf(yv, r->y0), r->y1);
    return v3_add(r->o,
                  v3_add(v3_add(v3_scale(r->x, xu), v3_scale(r->y, yv)), v3_scale(r->z, r->z0)));
}

/* ------------------------------------------------------------ disks */

static void concentric_disk(float a, float b, float *x, float *y)
{
    float sa = 2.0f * a - 1.0f, sb = 2.0f * b - 1.0f, r, phi;
    if (sa == 0.0f && sb == 0.0f) {
        *x = *y = 0.0f;
        return;
    }
    if (fabsf(sa) > fabsf(sb)) {
        r = sa;
        phi = (PI / 4.0f) * (sb / sa);
    } else {
        r = sb;
        phi = PI / 2.0f - (PI / 4.0f) * (sa / sb);
    }
    *x = r * cosf(phi);
    *y = r * sinf(phi);
}

/* ------------------------------------------------------ environments */

static void env_dir_to_uv(const Light *l, Vec3 d, float *u, float *v)
{
    Vec3 ld = v3_normalize(mat4_vector(&l->light_from_world, d));
    float phi = atan2f(-ld.x, ld.z); /* 0 at +z, growing toward -x */
    *u = 0.5f + phi / (2.0f * PI);
    *v = acosf(fminf(fmaxf(ld.y, -1.0f), 1.0f)) / PI;
}

static Vec3 env_uv_to_dir(const Light *l, float u, float v, float *sin_theta)
{
    float phi = (u - 0.5f) * 2.0f * PI, theta = v * PI;
    float st = sinf(theta);
    *sin_theta = st;
    Vec3 ld = v3(-st * sinf(phi), cosf(theta), st * cosf(phi));
    return v3_normalize(mat4_vector(&l->world_from_light, ld));
}

static int env_pixel(const LightEnvMap *m, float u, float v, int *x, int *y)
{
    *x = (int)floorf(u * (float)m->width);
    *y = (int)floorf(v * (float)m->height);
    *x = *x < 0 ? 0 : *x >= m->width ? m->width - 1 : *x;
    *y = *y < 0 ? 0 : *y >= m->height ? m->height - 1 : *y;
    return *y * m->width + *x;
}

static Vec3 env_texel(const Light *l, float u, float v)
{
    int x, y;
    const float *c = &l->env->rgb[3 * (size_t)env_pixel(l->env, u, v, &x, &y)];
    return v3_mul(l->L, v3(c[0], c[1], c[2]));
}

/* The pdf (solid angle) of drawing the direction at (u, v) of the map. */
static float env_pdf_uv(const Light *l, float u, float v)
{
    int x, y;
    float p = l->env->pixel_pdf[env_pixel(l->env, u, v, &x, &y)];
    float st = sinf(v * PI);
    if (!(st > 0.0f))
        return 0.0f;
    return p * (float)l->env->width * (float)l->env->height / (2.0f * PI * PI * st);
}

Vec3 light_env_radiance(const Light *l, Vec3 d)
{
    if (!l->env)
        return l->L;
    float u, v;
    env_dir_to_uv(l, d, &u, &v);
    return env_texel(l, u, v);
}

/* A point or spot light's intensity toward world direction d (unit, from
 * the light) by its map: the latitude-longitude map's texel, or through a
 * projection along the light's +z of tan(fov / 2) = map_tan on the
 * shorter side of the image (its first row at light-space +y's end), black
 * outside it and behind. */
static Vec3 point_map(const Light *l, Vec3 d)
{
    if (!l->map_projection)
        return light_env_radiance(l, d);
    const LightEnvMap *m = l->env;
    Vec3 ld = mat4_vector(&l->light_from_world, d);
    if (!(ld.z > 1e-3f * v3_length(ld)))
        return v3(0, 0, 0);
    float x = ld.x / (ld.z * l->map_tan), y = ld.y / (ld.z * l->map_tan);
    float aspect = (float)m->width / (float)m->height;
    float xr = aspect > 1.0f ? aspect : 1.0f, yr = aspect > 1.0f ? 1.0f : 1.0f / aspect;
    float u = 0.5f * (x / xr + 1.0f), v = 0.5f * (1.0f - y / yr);
    if (!(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f))
        return v3(0, 0, 0);
    int px, py;
    const float *c = &m->rgb[3 * (size_t)env_pixel(m, u, v, &px, &py)];
    return v3_mul(l->L, v3(c[0], c[1], c[2]));
}

/* Index i with cdf[i] <= x < cdf[i + 1] among n intervals, skipping empty
 * ones: the largest i < n with cdf[i] <= x, the binary search's answer
 * exactly, found from the guide table's start for x (guide: n entries). */
static int cdf_find(const float *cdf, const int *guide, int n, float x)
{
    int k = (int)(x * (float)n);
    int lo = guide[k < 0 ? 0 : k >= n ? n - 1 : k];
    while (lo > 0 && cdf[lo] > x) /* x * n rounded up into the next bucket */
        lo--;
    while (lo < n - 1 && cdf[lo + 1] <= x)
        lo++;
    while (lo < n - 1 && cdf[lo + 1] <= cdf[lo])
        lo++;
    return lo;
}

/* guide[k] for k < n: the largest i < n with cdf[i] <= k / n. */
static void cdf_guide(const float *cdf, int n, int *guide)
{
    int i = 0;
    for (int k = 0; k < n; k++) {
        float x = (float)k / (float)n;
        while (i < n - 1 && cdf[i + 1] <= x)
            i++;
        guide[k] = i;
    }
}

/* The sample at fraction (fx, fy) of map pixel (x, y): its direction,
 * radiance and the light's own pdf; 0 where the pixel sends nothing. */
static int env_pixel_sample(const Light *l, int x, int y, float fx, float fy, LightSample *s)
{
    const LightEnvMap *m = l->env;
    float st, u = ((float)x + fminf(fmaxf(fx, 0.0f), 0.9999f)) / (float)m->width;
    float v = ((float)y + fminf(fmaxf(fy, 0.0f), 0.9999f)) / (float)m->height;
    s->wi = env_uv_to_dir(l, u, v, &st);
    float p = m->pixel_pdf[(size_t)y * m->width + x];
    if (!(st > 0.0f) || !(p > 0.0f))
        return 0;
    const float *c = &m->rgb[3 * ((size_t)y * m->width + x)];
    s->Li = v3_mul(l->L, v3(c[0], c[1], c[2]));
    s->pdf = p * (float)m->width * (float)m->height / (2.0f * PI * PI * st);
    s->dist = INFINITY;
    return 1;
}

static int env_sample(const Light *l, float a, float b, LightSample *s)
{
    const LightEnvMap *m = l->env;
    if (!m) {
        float z = 1.0f - 2.0f * a, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * PI * b;
        s->wi = v3(r * cosf(phi), r * sinf(phi), z);
        s->Li = l->L;
        s->pdf = 1.0f / (4.0f * PI);
        s->dist = INFINITY;
        return 1;
    }
    if (!(m->row_cdf[m->height] > 0.0f))
        return 0;
    int y = cdf_find(m->row_cdf, m->row_guide, m->height, a);
    float dr = m->row_cdf[y + 1] - m->row_cdf[y];
    float fy = dr > 0.0f ? (a - m->row_cdf[y]) / dr : 0.5f;
    const float *cc = &m->col_cdf[(size_t)y * (m->width + 1)];
    int x = cdf_find(cc, &m->col_guide[(size_t)y * m->width], m->width, b);
    float dc = cc[x + 1] - cc[x];
    float fx = dc > 0.0f ? (b - cc[x]) / dc : 0.5f;
    return env_pixel_sample(l, x, y, fx, fy, s);
}

/* ------------------------------------------- guided environment */

/* The map's guide bins (LightEnvMap.bin_x0 ...). 0, or -1 out of memory. */
static int env_bins(LightEnvMap *m)
{
    int w = m->width, h = m->height;
    for (int i = 0; i <= LIGHT_GUIDE_U; i++) /* the first x with x * U / w >= i */
        m->bin_x0[i] = (int)(((int64_t)i * w + LIGHT_GUIDE_U - 1) / LIGHT_GUIDE_U);
    for (int j = 0; j <= LIGHT_GUIDE_V; j++)
        m->bin_y0[j] = (int)(((int64_t)j * h + LIGHT_GUIDE_V - 1) / LIGHT_GUIDE_V);
    m->band_cdf = malloc((size_t)LIGHT_GUIDE_U * ((size_t)h + 1) * sizeof *m->band_cdf);
    if (!m->band_cdf)
        return -1;
    for (int i = 0; i < LIGHT_GUIDE_U; i++) {
        double *band = &m->band_cdf[(size_t)i * (h + 1)];
        double acc = 0.0, bin = 0.0;
        band[0] = 0.0;
        for (int y = 0; y < h; y++) {
            double r = 0.0;
            for (int x = m->bin_x0[i]; x < m->bin_x0[i + 1]; x++)
                r += m->pixel_pdf[(size_t)y * w + x];
            acc += r;
            bin += r;
            band[y + 1] = acc;
            int j = (int)((int64_t)y * LIGHT_GUIDE_V / h);
            if (y + 1 == m->bin_y0[j + 1]) { /* the bin's last row */
                m->bin_mass[j * LIGHT_GUIDE_U + i] = (float)bin;
                bin = 0.0;
            }
        }
    }
    return 0;
}

/* The guide bin of world direction d. */
static int env_bin(const Light *l, Vec3 d)
{
    const LightEnvMap *m = l->env;
    float u, v;
    if (m) {
        env_dir_to_uv(l, d, &u, &v);
    } else { /* a constant environment's bins: world space, as it is drawn */
        u = 0.5f + atan2f(-d.x, d.z) / (2.0f * PI);
        v = acosf(fminf(fmaxf(d.y, -1.0f), 1.0f)) / PI;
    }
    int i, j;
    if (m) {
        int x, y;
        env_pixel(m, u, v, &x, &y);
        i = (int)((int64_t)x * LIGHT_GUIDE_U / m->width);
        j = (int)((int64_t)y * LIGHT_GUIDE_V / m->height);
    } else {
        i = (int)(u * LIGHT_GUIDE_U), j = (int)(v * LIGHT_GUIDE_V);
        i = i < 0 ? 0 : i >= LIGHT_GUIDE_U ? LIGHT_GUIDE_U - 1 : i;
        j = j < 0 ? 0 : j >= LIGHT_GUIDE_V ? LIGHT_GUIDE_V - 1 : j;
    }
    return j * LIGHT_GUIDE_U + i;
}

int light_env_may_emit(const Light *l, Vec3 d)
{
    if (!l->env)
        return v3_max_component(l->L) > 0.0f;
    return l->env->bin_mass[env_bin(l, d)] > 0.0f;
}

float light_guide_mass(const Light *l, int b)
{
    if (l->env)
        return l->env->bin_mass[b];
    /* a constant environment: the band's share of the sphere */
    float v0 = (float)(b / LIGHT_GUIDE_U) / LIGHT_GUIDE_V, v1 = v0 + 1.0f / LIGHT_GUIDE_V;
    return 0.5f * (cosf(PI * v0) - cosf(PI * v1)) / LIGHT_GUIDE_U;
}

/* The interval i of cdf[lo .. hi] (hi - lo intervals) with cdf[i] <= x <
 * cdf[i + 1], skipping empty ones. */
static int range_find(const float *cdf, int lo, int hi, float x)
{
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* range_find over a cdf of doubles. */
static int range_find_d(const double *cdf, int lo, int hi, double x)
{
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

int light_guide_bin_sample(const Light *l, int b, float a, float c, LightSample *s)
{
    const LightEnvMap *m = l->env;
    int bi = b % LIGHT_GUIDE_U, bj = b / LIGHT_GUIDE_U;
    if (!m) {
        float z0 = cosf(PI * (float)bj / LIGHT_GUIDE_V),
              z1 = cosf(PI * (float)(bj + 1) / LIGHT_GUIDE_V);
        float z = z0 + c * (z1 - z0);
        float phi = (((float)bi + a) / LIGHT_GUIDE_U - 0.5f) * 2.0f * PI;
        float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        s->wi = v3(-r * sinf(phi), z, r * cosf(phi)); /* env_bin's inverse */
        s->Li = l->L;
        s->pdf = 1.0f / (4.0f * PI);
        s->dist = INFINITY;
        return 1;
    }
    int w = m->width, h = m->height;
    int x0 = m->bin_x0[bi], x1 = m->bin_x0[bi + 1], y0 = m->bin_y0[bj], y1 = m->bin_y0[bj + 1];
    if (x1 <= x0 || y1 <= y0)
        return 0;
    const double *band = &m->band_cdf[(size_t)bi * (h + 1)];
    double mass = band[y1] - band[y0];
    if (!(mass > 0.0))
        return 0;
    double t = band[y0] + a * mass;
    int y = range_find_d(band, y0, y1, t);
    double dr = band[y + 1] - band[y];
    float fy = dr > 0.0 ? (float)((t - band[y]) / dr) : 0.5f;
    const float *cc = &m->col_cdf[(size_t)y * (w + 1)];
    float lo = cc[x0], span = cc[x1] - lo;
    if (!(span > 0.0f))
        return 0;
    float tx = lo + c * span;
    int x = range_find(cc, x0, x1, tx);
    float dc = cc[x + 1] - cc[x];
    float fx = dc > 0.0f ? (tx - cc[x]) / dc : 0.5f;
    return env_pixel_sample(l, x, y, fx, fy, s);
}

int light_guide_init(const Light *l, const float *w, LightGuide *g)
{
    double acc = 0.0, sum[LIGHT_GUIDE_BINS + 1];
    sum[0] = 0.0;
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++) {
        acc += (double)light_guide_mass(l, b) * (double)fmaxf(w[b], 0.0f);
        sum[b + 1] = acc;
    }
    if (!(acc > 0.0))
        return 0;
    for (int b = 0; b <= LIGHT_GUIDE_BINS; b++)
        g->cdf[b] = (float)(sum[b] / acc);
    g->cdf[LIGHT_GUIDE_BINS] = 1.0f;
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++)
        g->scale[b] = (float)((double)fmaxf(w[b], 0.0f) / acc);
    return 1;
}

int light_guide_sample(const Light *l, const LightGuide *g, float a, float b, LightSample *s)
{
    int k = range_find(g->cdf, 0, LIGHT_GUIDE_BINS, a);
    while (k < LIGHT_GUIDE_BINS - 1 && !(g->cdf[k + 1] > g->cdf[k]))
        k++; /* a at an empty bin's edge */
    float d = g->cdf[k + 1] - g->cdf[k];
    if (!(d > 0.0f))
        return 0;
    float a2 = fminf(fmaxf((a - g->cdf[k]) / d, 0.0f), 0.99999994f);
    if (!light_guide_bin_sample(l, k, a2, b, s))
        return 0;
    s->pdf *= g->scale[k];
    return s->pdf > 0.0f;
}

float light_guide_factor(const Light *l, const LightGuide *g, Vec3 wi)
{
    return g->scale[env_bin(l, wi)];
}

/* ------------------------------------------------------------ meshes */

/* A triangle's unnormalised normal (twice its area). */
static Vec3 tri_normal(const Vec3 *p)
{
    return v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
}

/* A triangle's area (0 when not finite). */
static float tri_area(const Vec3 *p)
{
    float a = 0.5f * v3_length(tri_normal(p));
    return isfinite(a) ? a : 0.0f;
}

/* Places the k-th smallest of t[lo, hi) (by centroid coordinate key) at k,
 * smaller ones before it (Hoare's selection). */
static void select_kth(uint32_t *t, const float *key, size_t lo, size_t hi, size_t k)
{
    while (hi - lo > 1) {
        float pivot = key[t[lo + (hi - lo) / 2]];
        size_t i = lo, j = hi - 1;
        while (i <= j) {
            while (key[t[i]] < pivot)
                i++;
            while (key[t[j]] > pivot)
                j--;
            if (i <= j) {
                uint32_t tmp = t[i];
                t[i] = t[j];
                t[j] = tmp;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j + 1;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

/* Splits t[lo, hi) at the median of its centroids' widest axis until a
 * part holds at most `leaf` triangles or `depth` halvings are done; the
 * parts become clusters in order. */
static void cluster_split(LightMesh *m, const Vec3 *v, uint32_t *t, float *key, size_t lo,
                          size_t hi, size_t leaf, int depth)
{
    if (hi - lo <= leaf || depth == 0) {
        LightCluster *c = &m->cluster[m->n_clusters++];
        c->start = (uint32_t)lo, c->end = (uint32_t)hi;
        return;
    }
    Vec3 clo = v3(INFINITY, INFINITY, INFINITY), chi = v3_neg(clo);
    for (size_t i = lo; i < hi; i++) {
        const Vec3 *p = &v[3 * (size_t)t[i]];
        Vec3 c = v3_scale(v3_add(v3_add(p[0], p[1]), p[2]), 1.0f / 3.0f);
        clo = v3_min(clo, c), chi = v3_max(chi, c);
    }
    Vec3 e = v3_sub(chi, clo);
    int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    for (size_t i = lo; i < hi; i++) {
        const Vec3 *p = &v[3 * (size_t)t[i]];
        key[t[i]] = axis == 0   ? p[0].x + p[1].x + p[2].x
                    : axis == 1 ? p[0].y + p[1].y + p[2].y
                                : p[0].z + p[1].z + p[2].z;
    }
    size_t mid = lo + (hi - lo) / 2;
    select_kth(t, key, lo, hi, mid);
    cluster_split(m, v, t, key, lo, mid, leaf, depth - 1);
    cluster_split(m, v, t, key, mid, hi, leaf, depth - 1);
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* A cluster's bounds, area, and cone of front directions. */
static void cluster_bound(LightMesh *m, LightCluster *c)
{
    Vec3 sum = v3(0, 0, 0);
    c->lo = v3(INFINITY, INFINITY, INFINITY), c->hi = v3_neg(c->lo);
    for (uint32_t k = c->start; k < c->end; k++) {
        const Vec3 *p = &m->v[3 * (size_t)k];
        sum = v3_add(sum, tri_normal(p));
        for (int j = 0; j < 3; j++)
            c->lo = v3_min(c->lo, p[j]), c->hi = v3_max(c->hi, p[j]);
    }
    c->centre = v3_scale(v3_add(c->lo, c->hi), 0.5f);
    Vec3 h = v3_sub(c->hi, c->centre);
    c->radius2 = v3_dot(h, h);
    c->sin_cone = 0.0f;
    float len = v3_length(sum);
    c->cos_cone = -1.0f;
    c->axis = v3(0, 0, 1);
    if (!(len > 0.0f))
        return;
    c->axis = v3_scale(sum, 1.0f / len);
    float cos_min = 1.0f;
    for (uint32_t k = c->start; k < c->end; k++) {
        Vec3 n = tri_normal(&m->v[3 * (size_t)k]);
        float l = v3_length(n);
        if (l > 0.0f)
            cos_min = fminf(cos_min, v3_dot(n, c->axis) / l);
    }
    c->cos_cone = fmaxf(-1.0f, cos_min - 1e-4f); /* a margin for rounding */
    c->sin_cone = sqrtf(fmaxf(0.0f, 1.0f - c->cos_cone * c->cos_cone));
}

static void mesh_free(LightMesh *m);

int light_mesh_init(Light *l, const Vec3 *v, size_t n, int two_sided)
{
    if (n == 0 || n > (size_t)INT32_MAX)
        return -1;
    LightMesh *m = calloc(1, sizeof *m);
    uint32_t *t = malloc(n * sizeof *t);
    float *key = malloc(n * sizeof *key);
    if (m) {
        m->v = malloc(3 * n * sizeof *m->v);
        m->cdf = malloc((n + 1) * sizeof *m->cdf);
        m->cluster_of = malloc(n);
    }
    if (!m || !t || !key || !m->v || !m->cdf || !m->cluster_of) {
        free(t);
        free(key);
        mesh_free(m);
        return -1;
    }
    m->n = n;
    for (size_t k = 0; k < n; k++)
        t[k] = (uint32_t)k;
    size_t leaf = (n + LIGHT_MESH_CLUSTERS - 1) / LIGHT_MESH_CLUSTERS;
    cluster_split(m, v, t, key, 0, n, leaf, 4); /* 2^4 = LIGHT_MESH_CLUSTERS parts at most */
    /* Within a cluster the mesh's own order, whose neighbours are mostly
     * neighbours in space: the stratified numbers that pick triangles then
     * spread over the surface (the selection's order scatters them). */
    for (int c = 0; c < m->n_clusters; c++)
        qsort(t + m->cluster[c].start, m->cluster[c].end - m->cluster[c].start, sizeof *t, cmp_u32);
    double sum = 0.0;              /* the whole mesh's area */
    for (size_t k = 0; k < n; k++) /* the clusters' order */
        memcpy(&m->v[3 * k], &v[3 * (size_t)t[k]], 3 * sizeof *v);
    m->lo = v3(INFINITY, INFINITY, INFINITY);
    m->hi = v3_neg(m->lo);
    for (int c = 0; c < m->n_clusters; c++) {
        /* each cluster's cdf from 0 to 1, summed in double from its start
         * (a running sum over a large mesh loses small faces) */
        LightCluster *cl = &m->cluster[c];
        double area = 0.0;
        for (uint32_t k = cl->start; k < cl->end; k++)
            area += tri_area(&m->v[3 * (size_t)k]);
        double run = 0.0;
        for (uint32_t k = cl->start; k < cl->end; k++) {
            m->cdf[k] = area > 0.0 ? (float)(run / area) : 0.0f;
            run += tri_area(&m->v[3 * (size_t)k]);
        }
        cluster_bound(m, cl);
        cl->area = (float)area;
        sum += area;
        for (uint32_t k = cl->start; k < cl->end; k++)
            m->cluster_of[t[k]] = (uint8_t)c;
        m->lo = v3_min(m->lo, cl->lo), m->hi = v3_max(m->hi, cl->hi);
    }
    m->cdf[n] = 1.0f;
    m->area = (float)sum;
    /* t: place -> scene triangle; kept inverted for light_mesh_texture
     * (the same n words, reused) */
    m->place = t;
    for (size_t k = 0; k < n; k++)
        ((uint32_t *)key)[t[k]] = (uint32_t)k;
    memcpy(t, key, n * sizeof *t);
    free(key);
    if (!(sum > 0.0)) {
        mesh_free(m);
        return -1;
    }
    l->type = LIGHT_MESH;
    l->mesh = m;
    l->two_sided = two_sided != 0;
    return 0;
}

int light_mesh_texture(Light *l, const float *st, const char *path, char *err, size_t err_size)
{
    LightMesh *m = l->mesh;
    int w = 0, h = 0;
    float *rgba = NULL;
    char ierr[600];
    if (texture_read_image(path, &w, &h, &rgba, ierr, sizeof ierr) != 0) {
        snprintf(err, err_size, "area light texture: %s", ierr);
        return -1;
    }
    /* kept whole in memory, at most LIGHT_TEXTURE_MAX texels a side: a
     * larger image is halved (2 x 2 means) until it fits (a 4096-square
     * emission image would hold 200 MB) */
    while (w > LIGHT_TEXTURE_MAX || h > LIGHT_TEXTURE_MAX) {
        int w2 = (w + 1) / 2, h2 = (h + 1) / 2;
        for (int y = 0; y < h2; y++)
            for (int x = 0; x < w2; x++) {
                float sum[4] = {0, 0, 0, 0};
                int n = 0;
                for (int j = 2 * y; j < 2 * y + 2 && j < h; j++)
                    for (int i = 2 * x; i < 2 * x + 2 && i < w; i++, n++)
                        for (int c = 0; c < 4; c++) {
                            float v = rgba[4 * ((size_t)j * (size_t)w + (size_t)i) + (size_t)c];
                            sum[c] += isfinite(v) && v > 0.0f ? v : 0.0f;
                        }
                for (int c = 0; c < 4; c++) /* in place: (x, y) is read before written */
                    rgba[4 * ((size_t)y * (size_t)w2 + (size_t)x) + (size_t)c] = sum[c] / (float)n;
            }
        w = w2, h = h2;
    }
    size_t n_px = (size_t)w * (size_t)h;
    m->st = malloc(6 * m->n * sizeof *m->st);
    m->tex = malloc(3 * n_px * sizeof *m->tex);
    if (!m->st || !m->tex) {
        free(rgba);
        free(m->st), free(m->tex);
        m->st = m->tex = NULL;
        snprintf(err, err_size, "area light texture %s: out of memory", path);
        return -1;
    }
    for (size_t i = 0; i < n_px; i++)
        for (int c = 0; c < 3; c++) {
            float x = rgba[4 * i + (size_t)c];
            m->tex[3 * i + (size_t)c] = isfinite(x) && x > 0.0f ? x : 0.0f;
        }
    free(rgba);
    for (size_t k = 0; k < m->n; k++)
        memcpy(&m->st[6 * (size_t)m->place[k]], &st[6 * k], 6 * sizeof *st);
    m->tex_w = w, m->tex_h = h;
    return 0;
}

/* cos(max(0, a - b)) and sin(max(0, a - b)) from the sines and cosines of
 * angles a, b in [0, pi]. */
static inline float cos_sub_clamped(float sa, float ca, float sb, float cb)
{
    return ca > cb ? 1.0f : ca * cb + sa * sb;
}

static inline float sin_sub_clamped(float sa, float ca, float sb, float cb)
{
    return ca > cb ? 0.0f : sa * cb - ca * sb;
}

/* sqrt(1 - c^2) for a cosine c that may round past 1 (no libm calls: this
 * runs for every cluster at every lit point) */
static inline float sin_of(float c)
{
    float s2 = 1.0f - c * c;
    return s2 > 0.0f ? sqrtf(s2) : 0.0f;
}

/* The importance of cluster c from o (normal N, or zero), as
 * light_mesh_view says: the cosines bounded by the cone and by the ball
 * around the cluster's bounds. */
static float cluster_importance(const LightCluster *c, int two_sided, Vec3 o, Vec3 N)
{
    if (!(c->area > 0.0f))
        return 0.0f;
    Vec3 w = v3_sub(o, c->centre);
    float r2 = c->radius2, d2 = v3_dot(w, w);
    if (!(d2 > r2 * 1.0001f)) /* o within the ball: no bound on the angles */
        return c->area / (r2 > 1e-30f ? r2 : 1e-30f);
    float inv_d = 1.0f / sqrtf(d2), sin_b = sqrtf(r2) * inv_d, cos_b = sin_of(sin_b);
    Vec3 wn = v3_scale(w, inv_d);
    float cos_e = 1.0f;
    if (!two_sided && c->cos_cone > -1.0f) { /* the faces' fronts toward o */
        float cw = v3_dot(c->axis, wn), sw = sin_of(cw);
        float c1 = cos_sub_clamped(sw, cw, c->sin_cone, c->cos_cone);
        float s1 = sin_sub_clamped(sw, cw, c->sin_cone, c->cos_cone);
        cos_e = cos_sub_clamped(s1, c1, sin_b, cos_b);
        if (!(cos_e > 0.0f))
            return 0.0f;
    }
    float cos_i = 1.0f;
    if (N.x != 0.0f || N.y != 0.0f || N.z != 0.0f) { /* above o's horizon */
        float ci = -v3_dot(N, wn);
        cos_i = cos_sub_clamped(sin_of(ci), ci, sin_b, cos_b);
        if (!(cos_i > 0.0f))
            return 0.0f;
    }
    return c->area * cos_e * cos_i / d2;
}

void light_mesh_view(const Light *l, Vec3 o, Vec3 N, LightMeshView *v)
{
    const LightMesh *m = l->mesh;
    v->n = m->n_clusters;
    float sum = 0.0f;
    for (int c = 0; c < m->n_clusters; c++) {
        v->cdf[c] = sum;
        float imp = cluster_importance(&m->cluster[c], l->two_sided, o, N);
        sum += isfinite(imp) ? imp : 0.0f;
    }
    v->cdf[m->n_clusters] = sum;
}

/* The probability of cluster c in v. */
static float view_pmf(const LightMeshView *v, int c)
{
    return v->cdf[v->n] > 0.0f ? (v->cdf[c + 1] - v->cdf[c]) / v->cdf[v->n] : 0.0f;
}

/* Cluster c's point at distance t along wi (unit) with unit normal Ng:
 * its radiance and pdf in *s if its emitting side faces the ray's origin. */
static int mesh_finish(const Light *l, const LightMeshView *v, int c, Vec3 wi, float t, Vec3 Ng,
                       LightSample *s)
{
    float cos_y = -v3_dot(Ng, wi);
    if (l->two_sided)
        cos_y = fabsf(cos_y);
    float p = view_pmf(v, c) / l->mesh->cluster[c].area; /* per unit area */
    if (!(cos_y > 0.0f) || !(t > 0.0f) || !(p > 0.0f))
        return 0;
    s->wi = wi;
    s->dist = t;
    s->Li = l->L;
    s->pdf = t * t / cos_y * p;
    return 1;
}

/* An rgb image (w x h, top row first) at (s, t) in [0, 1]^2: bilinear
 * between its texels' centres, its edge texels beyond them. */
static Vec3 rgb_bilinear(const float *rgb, int w, int h, float s, float t)
{
    float x = s * (float)w - 0.5f, y = t * (float)h - 0.5f;
    float fx = floorf(x), fy = floorf(y), ax = x - fx, ay = y - fy;
    Vec3 c = v3(0, 0, 0);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int px = (int)fx + i, py = (int)fy + j;
            px = px < 0 ? 0 : px >= w ? w - 1 : px;
            py = py < 0 ? 0 : py >= h ? h - 1 : py;
            const float *q = &rgb[3 * ((size_t)py * (size_t)w + (size_t)px)];
            float wgt = (i ? ax : 1.0f - ax) * (j ? ay : 1.0f - ay);
            c = v3_madd(c, v3(q[0], q[1], q[2]), wgt);
        }
    return c;
}

/* The emission texture at (s, t), clamped at the image's edges (pbrt-v4's
 * lookup: a sign's border does not take the opposite one's). */
static Vec3 mesh_texel(const LightMesh *m, float s, float t)
{
    return rgb_bilinear(m->tex, m->tex_w, m->tex_h, fminf(fmaxf(s, 0.0f), 1.0f),
                        fminf(fmaxf(t, 0.0f), 1.0f));
}

/* The radiance at barycentrics (b1, b2) of the triangle at place k. */
static Vec3 mesh_radiance_at(const Light *l, size_t k, float b1, float b2)
{
    const LightMesh *m = l->mesh;
    if (!m->tex)
        return l->L;
    const float *st = &m->st[6 * k];
    float b0 = 1.0f - b1 - b2;
    return v3_mul(l->L, mesh_texel(m, b0 * st[0] + b1 * st[2] + b2 * st[4],
                                   b0 * st[1] + b1 * st[3] + b2 * st[5]));
}

Vec3 light_mesh_radiance(const Light *l, uint32_t tri, Vec3 P)
{
    const LightMesh *m = l->mesh;
    if (!m->tex || tri >= m->n)
        return l->L;
    size_t k = m->place[tri];
    const Vec3 *p = &m->v[3 * k];
    /* P's barycentrics in the triangle's plane */
    Vec3 e1 = v3_sub(p[1], p[0]), e2 = v3_sub(p[2], p[0]), d = v3_sub(P, p[0]);
    float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
    float d1 = v3_dot(d, e1), d2 = v3_dot(d, e2), den = d11 * d22 - d12 * d12;
    if (!(fabsf(den) > 0.0f))
        return mesh_radiance_at(l, k, 1.0f / 3.0f, 1.0f / 3.0f);
    float b1 = (d22 * d1 - d12 * d2) / den, b2 = (d11 * d2 - d12 * d1) / den;
    return mesh_radiance_at(l, k, fminf(fmaxf(b1, 0.0f), 1.0f), fminf(fmaxf(b2, 0.0f), 1.0f));
}

int light_mesh_finish(const Light *l, const LightMeshView *v, uint32_t tri, Vec3 o, Vec3 wi,
                      float t, Vec3 Ng, LightSample *s)
{
    if (!(tri < l->mesh->n) || !mesh_finish(l, v, l->mesh->cluster_of[tri], wi, t, Ng, s))
        return 0;
    if (l->mesh->tex)
        s->Li = light_mesh_radiance(l, tri, v3_madd(o, wi, t));
    return 1;
}

/* The largest k in [lo, hi) with cdf[k] <= x. */
static uint32_t cdf_search(const float *cdf, uint32_t lo, uint32_t hi, float x)
{
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (cdf[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

int light_mesh_sample(const Light *l, const LightMeshView *v, Vec3 o, float a, float b,
                      LightSample *s)
{
    const LightMesh *m = l->mesh;
    float total = v->cdf[v->n];
    if (!(total > 0.0f))
        return 0;
    /* the cluster, then what is left of a: the triangle, then what is
     * left: the point with b */
    float x = a * total;
    int c = 0;
    while (c + 1 < v->n && v->cdf[c + 1] <= x)
        c++;
    while (c + 1 < v->n && !(v->cdf[c + 1] > v->cdf[c])) /* skip weightless ones */
        c++;
    float wc = v->cdf[c + 1] - v->cdf[c];
    float r = wc > 0.0f ? fminf(fmaxf((x - v->cdf[c]) / wc, 0.0f), 0.99999994f) : 0.5f;
    const LightCluster *cl = &m->cluster[c];
    uint32_t k = cdf_search(m->cdf, cl->start, cl->end, r);
    while (k + 1 < cl->end && !(m->cdf[k + 1] > m->cdf[k]))
        k++;
    float w = (k + 1 < cl->end ? m->cdf[k + 1] : 1.0f) - m->cdf[k];
    float u = w > 0.0f ? fminf(fmaxf((r - m->cdf[k]) / w, 0.0f), 1.0f) : 0.5f;
    const Vec3 *p = &m->v[3 * (size_t)k];
    float su = sqrtf(u); /* uniform over the triangle */
    Vec3 y = v3_add(v3_scale(p[0], 1.0f - su),
                    v3_add(v3_scale(p[1], su * (1.0f - b)), v3_scale(p[2], su * b)));
    Vec3 n = tri_normal(p);
    float len = v3_length(n);
    Vec3 d = v3_sub(y, o);
    float dist = v3_length(d);
    if (!(dist > 0.0f) || !(len > 0.0f))
        return 0;
    if (!mesh_finish(l, v, c, v3_scale(d, 1.0f / dist), dist, v3_scale(n, 1.0f / len), s))
        return 0;
    if (m->tex)
        s->Li = mesh_radiance_at(l, k, su * (1.0f - b), su * b);
    return 1;
}

/* A mesh light's sample without a view made for the point: one made here,
 * without a horizon. */
static int mesh_sample(const Light *l, Vec3 o, float a, float b, LightSample *s)
{
    LightMeshView v;
    light_mesh_view(l, o, v3(0, 0, 0), &v);
    return light_mesh_sample(l, &v, o, a, b, s);
}

/* ------------------------------------------------------------ motion */

const Light *light_at_time(const Light *l, float t, Light *tmp)
{
    if (l->n_times < 2 || t <= l->time[0])
        return l;
    int k = 0;
    float f = 1.0f;
    while (k + 2 < l->n_times && t >= l->time[k + 1])
        k++;
    if (t < l->time[k + 1])
        f = (t - l->time[k]) / (l->time[k + 1] - l->time[k]);
    Mat4 D;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            D.m[i][j] = l->delta[k].m[i][j] + (l->delta[k + 1].m[i][j] - l->delta[k].m[i][j]) * f;
    *tmp = *l;
    tmp->n_times = 0;
    for (int i = 0; i < 4; i++)
        tmp->P[i] = mat4_point(&D, l->P[i]);
    tmp->from = mat4_point(&D, l->from);
    Vec3 dir = mat4_vector(&D, l->dir);
    tmp->dir = v3_length(dir) > 0.0f ? v3_normalize(dir) : l->dir;
    tmp->ex = mat4_vector(&D, l->ex);
    tmp->ey = mat4_vector(&D, l->ey);
    if (l->type == LIGHT_DISK) {
        Vec3 n = v3_cross(tmp->ex, tmp->ey);
        tmp->area = (float)M_PI * v3_length(n);
        tmp->normal = tmp->area > 0.0f ? v3_normalize(n) : l->normal;
    }
    if (l->type == LIGHT_SPHERE) { /* scaled as the object's x axis */
        Vec3 x = mat4_vector(&D, v3(1, 0, 0));
        tmp->radius = l->radius * v3_length(x);
    }
    if (l->type == LIGHT_UBER) { /* its whole space moves */
        tmp->world_from_light = mat4_mul(D, l->world_from_light);
        if (!mat4_invert(tmp->world_from_light, &tmp->light_from_world))
            return l;
    }
    if (l->type == LIGHT_ENVIRONMENT) { /* the rotation alone */
        Mat4 R = D;
        R.m[0][3] = R.m[1][3] = R.m[2][3] = 0.0f;
        tmp->world_from_light = mat4_mul(R, l->world_from_light);
        if (!mat4_invert(tmp->world_from_light, &tmp->light_from_world))
            return l;
    }
    return tmp;
}

/* ---------------------------------------------------------- sampling */

int light_below_plane(const Light *l, Vec3 o, Vec3 n)
{
    float top, size; /* the light's highest point over the plane, and its scale */
    switch (l->type) {
    case LIGHT_SPHERE: {
        Vec3 dc = v3_sub(l->from, o);
        top = v3_dot(dc, n) + l->radius;
        size = v3_length(dc) + l->radius;
        break;
    }
    case LIGHT_DISK: {
        Vec3 dc = v3_sub(l->from, o);
        float r = fabsf(v3_dot(l->ex, n)) + fabsf(v3_dot(l->ey, n));
        top = v3_dot(dc, n) + r;
        size = v3_length(dc) + v3_length(l->ex) + v3_length(l->ey);
        break;
    }
    case LIGHT_QUAD:
        top = -INFINITY, size = 0.0f;
        for (int k = 0; k < 4; k++) { /* a bilinear patch lies in its corners' hull */
            Vec3 d = v3_sub(l->P[k], o);
            top = fmaxf(top, v3_dot(d, n));
            size = fmaxf(size, v3_length(d));
        }
        break;
    case LIGHT_MESH:
        top = -INFINITY, size = 0.0f;
        for (int k = 0; k < 8; k++) { /* the bounding box's corners */
            Vec3 c =
                v3(k & 1 ? l->mesh->hi.x : l->mesh->lo.x, k & 2 ? l->mesh->hi.y : l->mesh->lo.y,
                   k & 4 ? l->mesh->hi.z : l->mesh->lo.z);
            Vec3 d = v3_sub(c, o);
            top = fmaxf(top, v3_dot(d, n));
            size = fmaxf(size, v3_length(d));
        }
        break;
    default:
        return 0;
    }
    return top < -1e-3f * size; /* the margin: sampled directions are rounded */
}

void light_bound_init(const Light *l, Vec3 o, LightBound *b)
{
    Vec3 c;
    float r2;
    switch (l->type) {
    case LIGHT_QUAD: /* a bilinear patch lies in its corners' hull */
        c = v3_scale(v3_add(v3_add(l->P[0], l->P[1]), v3_add(l->P[2], l->P[3])), 0.25f);
        r2 = 0.0f;
        for (int k = 0; k < 4; k++) {
            Vec3 d = v3_sub(l->P[k], c);
            float d2 = v3_dot(d, d);
            r2 = d2 > r2 ? d2 : r2;
        }
        break;
    case LIGHT_DISK: /* |x ex + y ey| <= sqrt(|ex|^2 + |ey|^2) for x^2 + y^2 <= 1 */
        c = l->from;
        r2 = v3_dot(l->ex, l->ex) + v3_dot(l->ey, l->ey);
        break;
    case LIGHT_SPHERE:
        c = l->from;
        r2 = l->radius * l->radius;
        break;
    case LIGHT_MESH: {
        c = v3_scale(v3_add(l->mesh->lo, l->mesh->hi), 0.5f);
        Vec3 h = v3_sub(l->mesh->hi, c);
        r2 = v3_dot(h, h);
        break;
    }
    default:
        *b = (LightBound){.all = 1};
        return;
    }
    b->dc = v3_sub(c, o);
    b->d2 = v3_dot(b->dc, b->dc);
    /* 2% on the radius, and 1e-4 of the distance squared for the
     * cancellation in d2 - proj^2 and a direction's rounded length */
    b->r2 = r2 * 1.0404f + 1e-4f * b->d2;
    b->all = !(b->d2 > b->r2) || !(b->r2 < INFINITY);
}

/* ---------------------------------------------------------- uberlight */

/* RenderMan's smoothstep, exactly: 0 below lo, 1 from hi on (a step at
 * lo == hi), Hermite between. */
static float rsl_smoothstep(float lo, float hi, float x)
{
    if (x < lo)
        return 0.0f;
    if (x >= hi)
        return 1.0f;
    float t = (x - lo) / (hi - lo);
    return t * t * (3.0f - 2.0f * t);
}

/* a b / ((b x)^e + (a y)^e)^(1/e): 1 on the superellipse of half-axes
 * (a, b), above 1 inside it; scaled by the larger term, so that no power
 * overflows at large exponents (roundness near 0). */
static float superellipse_level(float x, float y, float a, float b, float e)
{
    float u = b * x, v = a * y, m = fmaxf(u, v);
    if (!(m > 0.0f))
        return INFINITY; /* the centre */
    return a * b / (m * powf(powf(u / m, e) + powf(v / m, e), 1.0f / e));
}

float light_superellipse(float x, float y, float a, float b, float A, float B, float roundness)
{
    x = fabsf(x);
    y = fabsf(y);
    if (roundness < 1e-6f)
        return 1.0f - (1.0f - rsl_smoothstep(a, A, x)) * (1.0f - rsl_smoothstep(b, B, y));
    float e = 2.0f / roundness;
    return rsl_smoothstep(superellipse_level(x, y, a, b, e), superellipse_level(x, y, A, B, e),
                          1.0f);
}

/* The slide's colour at light-space point p: the image stretched over the
 * cross-section (width + wedge by height + hedge at z = 1), its first row
 * at +y, bilinear, black outside it and behind the light. */
static Vec3 uber_slide(const Light *l, Vec3 p)
{
    const LightUber *u = &l->uber;
    const LightEnvMap *m = l->env;
    if (!(p.z > 0.0f))
        return v3(0, 0, 0);
    float s = 0.5f + 0.5f * p.x / (p.z * (u->width + u->wedge));
    float t = 0.5f - 0.5f * p.y / (p.z * (u->height + u->hedge));
    if (!(s >= 0.0f && s <= 1.0f && t >= 0.0f && t <= 1.0f))
        return v3(0, 0, 0);
    return rgb_bilinear(m->rgb, m->width, m->height, s, t);
}

/* The shaping of the light's intensity at light-space point p (Barzel's
 * section 4): depth cut on and off, distance falloff, beam falloff, the
 * superellipse cross-section and projected noise. */
static float uber_shape(const LightUber *u, Vec3 p)
{
    float len = v3_length(p);
    float z = u->omni ? len : p.z;
    if (!u->omni && !(z >= u->cos_cone * len && z > 0.0f))
        return 0.0f; /* outside the cone the cross-section fits in, or behind */
    float k = rsl_smoothstep(u->cuton - u->nearedge, u->cuton, z) *
              (1.0f - rsl_smoothstep(u->cutoff, u->cutoff + u->faredge, z));
    if (!(k > 0.0f))
        return 0.0f;
    if (u->falloff != 0.0f) {
        if (len > u->falloffdist) {
            k *= powf(u->falloffdist / len, u->falloff);
        } else if (u->maxratio > 1.0f) {
            /* within falloffdist the intensity rises smoothly to maxratio
             * at the light instead of without bound (1 at falloffdist);
             * with maxintensity at or below intensity it stays at 1 there
             * (Gritz's formula would grow without bound) */
            float s = logf(1.0f / u->maxratio), beta = -u->falloff / s;
            k *= u->maxratio * expf(s * powf(len / u->falloffdist, beta));
        }
    }
    if (!u->omni && u->beam > 0.0f)
        k *= powf(fmaxf(p.z / len, 0.0f), u->beam);
    if (!u->omni)
        k *=
            1.0f - light_superellipse(p.x / z - u->shearx, p.y / z - u->sheary, u->width, u->height,
                                      u->width + u->wedge, u->height + u->hedge, u->roundness);
    if (u->noiseamp > 0.0f && k > 0.0f) {
        float f = u->noisefreq;
        float n = 0.5f + 0.5f * noise3(f * (p.x + u->noiseoffset.x), f * (p.y + u->noiseoffset.y),
                                       0.0f); /* RenderMan's noise, in [0, 1] */
        k *= rsl_smoothstep(0.0f, 1.0f, 0.5f + u->noiseamp * (n - 0.5f));
    }
    return k;
}

int light_uber_sample(const Light *l, Vec3 o, LightUberSample *us)
{
    const LightUber *u = &l->uber;
    Vec3 p = mat4_point(&l->light_from_world, o);
    float k = uber_shape(u, p);
    if (!(k > 0.0f))
        return 0;
    /* the origin of its shadows: the light, or for parallel rays the
     * point's foot on the plane z = cuton; moved by the cheat */
    Vec3 origin = u->parallel ? mat4_point(&l->world_from_light, v3(p.x, p.y, u->cuton)) : l->from;
    origin = v3_add(origin, mat4_vector(&l->world_from_light, u->cheat));
    LightSample *s = &us->s;
    if (u->parallel) {
        s->wi = v3_neg(l->dir);
        s->dist = INFINITY;
    } else {
        Vec3 d = v3_sub(l->from, o);
        s->dist = v3_length(d);
        if (!(s->dist > 0.0f))
            return 0;
        s->wi = v3_scale(d, 1.0f / s->dist);
    }
    s->pdf = 0.0f;
    Vec3 lc = l->L;
    if (u->slide && l->env)
        lc = v3_mul(lc, uber_slide(l, p));
    s->Li = v3_scale(lc, k);
    us->Ls = v3_scale(u->shadowcolor, l->intensity * k);
    Vec3 sd = v3_sub(origin, o);
    us->sdist = v3_length(sd);
    us->sw = us->sdist > 0.0f ? v3_scale(sd, 1.0f / us->sdist) : s->wi;
    us->unblocked = 1.0f;
    if (u->blocker) { /* the segment from the point to the shadows' origin */
        Vec3 b1 = mat4_point(&u->blocker_from_world, o);
        Vec3 b2 = mat4_point(&u->blocker_from_world, origin);
        if (b1.z * b2.z < 0.0f) {
            Vec3 v = v3_sub(b1, b2), q = v3_sub(b1, v3_scale(v, b1.z / v.z));
            us->unblocked =
                light_superellipse(q.x, q.y, u->bwidth, u->bheight, u->bwidth + u->bwedge,
                                   u->bheight + u->bhedge, u->bround);
        }
    }
    return v3_max_component(s->Li) > 0.0f || v3_max_component(us->Ls) > 0.0f;
}

int light_sample(const Light *l, Vec3 o, float a, float b, LightSample *s)
{
    switch (l->type) {
    case LIGHT_QUAD: {
        Vec3 y, ny;
        SphRect r;
        int by_angle = sphrect_init(l, o, &r);
        if (by_angle)
            y = sphrect_point(&r, a, b);
        else
            light_quad_eval(l, a, b, &y, &ny);
        Vec3 d = v3_sub(y, o);
        float dist = v3_length(d);
        if (!by_angle)
            return dist > 0.0f && area_finish(l, v3_scale(d, 1.0f / dist), dist, ny, s);
        if (!(dist > 0.0f))
            return 0;
        s->wi = v3_scale(d, 1.0f / dist);
        s->dist = dist;
        s->Li = l->L;
        s->pdf = 1.0f / r.S;
        if (l->cone > 0.0f) { /* a rectangle: one normal */
            Vec3 p, n;
            light_quad_eval(l, 0.5f, 0.5f, &p, &n);
            float k = cone_factor(l, -v3_dot(v3_normalize(n), s->wi));
            s->Li = v3_scale(l->L, k);
            return k > 0.0f;
        }
        return 1;
    }
    case LIGHT_DISK: {
        float x, z;
        concentric_disk(a, b, &x, &z);
        Vec3 y = v3_add(l->from, v3_add(v3_scale(l->ex, x), v3_scale(l->ey, z)));
        Vec3 d = v3_sub(y, o);
        float dist = v3_length(d);
        return dist > 0.0f &&
               area_finish(l, v3_scale(d, 1.0f / dist), dist, v3_scale(l->normal, l->area), s);
    }
    case LIGHT_SPHERE: {
        Vec3 dc = v3_sub(l->from, o);
        float d2 = v3_dot(dc, dc), r2 = l->radius * l->radius;
        if (d2 <= r2 * 1.00001f)
            return 0; /* inside: the sphere emits outward only */
        float dlen = sqrtf(d2), sin2 = r2 / d2;
        float cos_max = sqrtf(fmaxf(0.0f, 1.0f - sin2));
        float one_minus = sin2 / (1.0f + cos_max); /* 1 - cos_max without cancellation */
        float cos_t = 1.0f - a * one_minus;
        float sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t)), phi = 2.0f * PI * b;
        Vec3 w = v3_scale(dc, 1.0f / dlen), t, bt;
        v3_basis(w, &t, &bt);
        Vec3 wi = v3_normalize(v3_add(v3_add(v3_scale(t, sin_t * cosf(phi)),
                                             v3_scale(bt, sin_t * sinf(phi))),
                                      v3_scale(w, cos_t)));
        /* The near intersection; a grazing direction touches the sphere. */
        float proj = v3_dot(dc, wi), h2 = d2 - proj * proj;
        float dist = proj - sqrtf(fmaxf(0.0f, r2 - h2));
        s->wi = wi;
        s->dist = fmaxf(dist, 0.0f);
        s->Li = l->L;
        s->pdf = 1.0f / (2.0f * PI * one_minus);
        return one_minus > 0.0f;
    }
    case LIGHT_POINT:
    case LIGHT_SPOT: {
        Vec3 d = v3_sub(l->from, o);
        float d2 = v3_dot(d, d);
        if (!(d2 > 0.0f))
            return 0;
        float dist = sqrtf(d2);
        s->wi = v3_scale(d, 1.0f / dist);
        s->dist = dist;
        s->pdf = 0.0f;
        float k = 1.0f / d2;
        if (l->type == LIGHT_SPOT) {
            float c = -v3_dot(s->wi, l->dir);
            k *= light_smoothstep(l->cos_outer, l->cos_inner, c) * powf(fmaxf(c, 0.0f), l->beam);
        }
        Vec3 I = l->env ? point_map(l, v3_neg(s->wi)) : l->L;
        s->Li = v3_scale(I, k);
        return k > 0.0f && v3_max_component(s->Li) > 0.0f;
    }
    case LIGHT_DISTANT:
        s->wi = v3_neg(l->dir);
        s->dist = INFINITY;
        s->pdf = 0.0f;
        s->Li = l->L;
        return 1;
    case LIGHT_ENVIRONMENT:
        return env_sample(l, a, b, s);
    case LIGHT_MESH:
        return mesh_sample(l, o, a, b, s);
    case LIGHT_UBER: {
        LightUberSample us;
        if (!light_uber_sample(l, o, &us))
            return 0;
        *s = us.s; /* unshadowed, behind the blocker as it lets through */
        s->Li = v3_add(us.Ls, v3_scale(v3_sub(us.s.Li, us.Ls), us.unblocked));
        return v3_max_component(s->Li) > 0.0f;
    }
    case LIGHT_AMBIENT:
        return 0;
    }
    return 0;
}

int light_intersect(const Light *l, Vec3 o, Vec3 wi, LightSample *s)
{
    switch (l->type) {
    case LIGHT_QUAD: {
        float t;
        if (!ray_triangle(o, wi, l->P[0], l->P[1], l->P[3], &t) &&
            !ray_triangle(o, wi, l->P[0], l->P[3], l->P[2], &t))
            return 0;
        float a, b;
        Vec3 y = v3_madd(o, wi, t), p, ny;
        quad_invert(l, y, &a, &b);
        light_quad_eval(l, a, b, &p, &ny);
        if (!area_finish(l, wi, t, ny, s))
            return 0;
        SphRect r; /* the pdf of the sampling light_sample does */
        if (sphrect_init(l, o, &r))
            s->pdf = 1.0f / r.S;
        return 1;
    }
    case LIGHT_DISK: {
        float den = v3_dot(wi, l->normal);
        if (!(den < 0.0f))
            return 0;
        float t = v3_dot(v3_sub(l->from, o), l->normal) / den;
        if (!(t > 0.0f))
            return 0;
        Vec3 r = v3_sub(v3_madd(o, wi, t), l->from);
        /* Coordinates in the (ex, ey) frame: the 2 x 2 Gram system. */
        float a11 = v3_dot(l->ex, l->ex), a12 = v3_dot(l->ex, l->ey), a22 = v3_dot(l->ey, l->ey);
        float b1 = v3_dot(l->ex, r), b2 = v3_dot(l->ey, r), det = a11 * a22 - a12 * a12;
        float x = (a22 * b1 - a12 * b2) / det, y = (a11 * b2 - a12 * b1) / det;
        if (x * x + y * y > 1.0f)
            return 0;
        return area_finish(l, wi, t, v3_scale(l->normal, l->area), s);
    }
    case LIGHT_SPHERE: {
        Vec3 dc = v3_sub(l->from, o);
        float d2 = v3_dot(dc, dc), r2 = l->radius * l->radius;
        if (d2 <= r2 * 1.00001f)
            return 0;
        float proj = v3_dot(dc, wi), h2 = d2 - proj * proj;
        if (proj <= 0.0f || h2 > r2)
            return 0;
        float sin2 = r2 / d2, cos_max = sqrtf(fmaxf(0.0f, 1.0f - sin2));
        float one_minus = sin2 / (1.0f + cos_max);
        if (!(one_minus > 0.0f))
            return 0; /* too small to be sampled: too small to hit */
        s->wi = wi;
        s->dist = proj - sqrtf(fmaxf(0.0f, r2 - h2));
        s->Li = l->L;
        s->pdf = 1.0f / (2.0f * PI * one_minus);
        return 1;
    }
    case LIGHT_ENVIRONMENT:
        s->wi = wi;
        s->dist = INFINITY;
        if (!l->env) {
            s->Li = l->L;
            s->pdf = 1.0f / (4.0f * PI);
            return 1;
        }
        float u, v; /* one look-up of the map for its radiance and pdf */
        env_dir_to_uv(l, wi, &u, &v);
        s->Li = env_texel(l, u, v);
        s->pdf = env_pdf_uv(l, u, v);
        return 1;
    default:
        return 0;
    }
}

/* ------------------------------------------------------- map loading */

/* Clarberg's equal-area map of the unit sphere onto the square [0, 1]^2
 * (pbrt-v4's EqualAreaSphereToSquare), with the exact arctangent. */
static void equal_area_sphere_to_square(Vec3 d, float *u, float *v)
{
    float x = fabsf(d.x), y = fabsf(d.y), z = fabsf(d.z);
    float r = sqrtf(fmaxf(0.0f, 1.0f - z));
    float a = fmaxf(x, y), b = fminf(x, y);
    b = a == 0.0f ? 0.0f : b / a;
    float phi = atanf(b) * 2.0f / PI;
    if (x < y)
        phi = 1.0f - phi;
    float vv = phi * r, uu = r - vv;
    if (d.z < 0.0f) {
        float t = uu;
        uu = 1.0f - vv, vv = 1.0f - t;
    }
    uu = copysignf(uu, d.x), vv = copysignf(vv, d.y);
    *u = 0.5f * (uu + 1.0f), *v = 0.5f * (vv + 1.0f);
}

/* The light-space direction at the centre of texel (x, y) of rayes'
 * latitude-longitude map of w x h (as env_uv_to_dir). */
static Vec3 latlong_texel_dir(int x, int y, int w, int h)
{
    float phi = (((float)x + 0.5f) / (float)w - 0.5f) * 2.0f * PI;
    float theta = ((float)y + 0.5f) / (float)h * PI, st = sinf(theta);
    return v3(-st * sinf(phi), cosf(theta), st * cosf(phi));
}

/* The bilinear RGBA of src (w x h) at texel coordinates (fx, fy) (texel
 * centres at + 0.5), rows clamped, columns clamped or (wrap) around. */
static void bilinear_rgba(const float *src, int w, int h, float fx, float fy, int wrap,
                          float out[4])
{
    int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
    float tx = fx - (float)x0, ty = fy - (float)y0;
    memset(out, 0, 4 * sizeof *out);
    for (int k = 0; k < 4; k++) {
        int sx = x0 + (k & 1), sy = y0 + (k >> 1);
        sx = wrap ? (sx % w + w) % w : sx < 0 ? 0 : sx >= w ? w - 1 : sx;
        sy = sy < 0 ? 0 : sy >= h ? h - 1 : sy;
        float wgt = ((k & 1) ? tx : 1.0f - tx) * ((k >> 1) ? ty : 1.0f - ty);
        for (int c = 0; c < 4; c++)
            out[c] += wgt * src[4 * ((size_t)sy * w + sx) + (size_t)c];
    }
}

/* The octahedral map src (n x n RGBA) resampled into a latitude-longitude
 * map of 2n x n: new array, or NULL. */
static float *octahedral_to_latlong(const float *src, int n)
{
    int w = 2 * n, h = n;
    float *out = malloc((size_t)w * h * 4 * sizeof *out);
    if (!out)
        return NULL;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float u, v;
            equal_area_sphere_to_square(latlong_texel_dir(x, y, w, h), &u, &v);
            bilinear_rgba(src, n, n, u * (float)n - 0.5f, v * (float)n - 0.5f, 0,
                          &out[4 * ((size_t)y * w + x)]);
        }
    return out;
}

/* A latitude-longitude map src (w x h RGBA) whose poles are its space's
 * +z and -z and whose longitude runs from +x toward +y (pbrt-v3's, the
 * direction (sin theta cos phi, sin theta sin phi, cos theta) at (phi / 2
 * pi, theta / pi)) resampled into rayes' (y up, env_uv_to_dir) of the same
 * size, bilinearly, around in longitude: new array, or NULL. */
static float *zup_to_latlong(const float *src, int w, int h)
{
    float *out = malloc((size_t)w * h * 4 * sizeof *out);
    if (!out)
        return NULL;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            Vec3 ld = latlong_texel_dir(x, y, w, h);
            float phi = atan2f(ld.y, ld.x), theta = acosf(fminf(fmaxf(ld.z, -1.0f), 1.0f));
            if (phi < 0.0f)
                phi += 2.0f * PI;
            bilinear_rgba(src, w, h, phi / (2.0f * PI) * (float)w - 0.5f,
                          theta / PI * (float)h - 0.5f, 1, &out[4 * ((size_t)y * w + x)]);
        }
    return out;
}

static int env_from_rgba(Light *l, float *rgba, int w, int h, const char *path, char *err,
                         size_t err_size);

int light_env_load(Light *l, const char *path, int layout, char *err, size_t err_size)
{
    int w = 0, h = 0;
    float *rgba = NULL;
    char ierr[300] = "";
    if (texture_read_image(path, &w, &h, &rgba, ierr, sizeof ierr) != 0) {
        snprintf(err, err_size, "environment light: %s",
                 ierr[0] ? ierr : "expected a latitude-longitude map");
        free(rgba);
        return -1;
    }
    if (layout == LIGHT_MAP_LATLONG_ZUP) {
        float *ll = zup_to_latlong(rgba, w, h);
        free(rgba);
        if (!ll) {
            snprintf(err, err_size, "environment light: out of memory for %s", path);
            return -1;
        }
        rgba = ll;
    }
    if (layout == LIGHT_MAP_OCTAHEDRAL) {
        if (w != h) {
            snprintf(err, err_size,
                     "environment light: %s: an octahedral map must be square, "
                     "not %d x %d",
                     path, w, h);
            free(rgba);
            return -1;
        }
        float *ll = octahedral_to_latlong(rgba, w);
        free(rgba);
        if (!ll) {
            snprintf(err, err_size, "environment light: out of memory for %s", path);
            return -1;
        }
        rgba = ll;
        w = 2 * h;
    }
    return env_from_rgba(l, rgba, w, h, path, err, err_size);
}

/* Makes l's map (its pixels and their sampling tables) of rgba (w x h,
 * latitude-longitude; freed here); path names it in errors. */
static int env_from_rgba(Light *l, float *rgba, int w, int h, const char *path, char *err,
                         size_t err_size)
{
    LightEnvMap *m = calloc(1, sizeof *m);
    size_t n = (size_t)w * h;
    if (m) {
        m->width = w;
        m->height = h;
        m->rgb = malloc(3 * n * sizeof *m->rgb);
        m->row_cdf = malloc(((size_t)h + 1) * sizeof *m->row_cdf);
        m->col_cdf = malloc((size_t)h * ((size_t)w + 1) * sizeof *m->col_cdf);
        m->pixel_pdf = malloc(n * sizeof *m->pixel_pdf);
        m->row_guide = malloc((size_t)h * sizeof *m->row_guide);
        m->col_guide = malloc(n * sizeof *m->col_guide);
    }
    if (!m || !m->rgb || !m->row_cdf || !m->col_cdf || !m->pixel_pdf || !m->row_guide ||
        !m->col_guide) {
        free(rgba);
        l->env = m;
        light_fini(l);
        snprintf(err, err_size, "environment light: out of memory for %s", path);
        return -1;
    }
    /* Weights in double: a large map sums many small numbers. */
    double total = 0.0;
    double *row = calloc((size_t)h, sizeof *row);
    if (!row) {
        free(rgba);
        l->env = m;
        light_fini(l);
        snprintf(err, err_size, "environment light: out of memory for %s", path);
        return -1;
    }
    for (int y = 0; y < h; y++) {
        double st = sin(PI * (y + 0.5) / h), acc = 0.0;
        float *cc = &m->col_cdf[(size_t)y * (w + 1)];
        cc[0] = 0.0f;
        for (int x = 0; x < w; x++) {
            const float *p = &rgba[4 * ((size_t)y * w + x)];
            float *c = &m->rgb[3 * ((size_t)y * w + x)];
            for (int k = 0; k < 3; k++)
                c[k] = isfinite(p[k]) && p[k] > 0.0f ? p[k] : 0.0f;
            double lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            double wgt = lum * st;
            m->pixel_pdf[(size_t)y * w + x] = (float)wgt;
            acc += wgt;
            cc[x + 1] = (float)acc;
        }
        for (int x = 0; x <= w; x++)
            cc[x] = acc > 0.0 ? (float)(cc[x] / acc) : (float)x / (float)w;
        cc[w] = 1.0f;
        row[y] = acc;
        total += acc;
    }
    double acc = 0.0;
    m->row_cdf[0] = 0.0f;
    for (int y = 0; y < h; y++) {
        acc += row[y];
        m->row_cdf[y + 1] = total > 0.0 ? (float)(acc / total) : 0.0f;
    }
    if (total > 0.0)
        m->row_cdf[h] = 1.0f;
    for (size_t i = 0; i < n; i++)
        m->pixel_pdf[i] = total > 0.0 ? (float)(m->pixel_pdf[i] / total) : 0.0f;
    cdf_guide(m->row_cdf, h, m->row_guide);
    for (int y = 0; y < h; y++)
        cdf_guide(&m->col_cdf[(size_t)y * (w + 1)], w, &m->col_guide[(size_t)y * w]);
    free(row);
    free(rgba);
    if (env_bins(m) != 0) {
        l->env = m;
        light_fini(l);
        snprintf(err, err_size, "environment light: out of memory for %s", path);
        return -1;
    }
    light_fini(l);
    l->env = m;
    return 0;
}

int light_env_sky(Light *l, const float sun[3], float turbidity, const float ground[3], char *err,
                  size_t err_size)
{
    enum { W = 512, H = 256 };
    float *rgba = malloc((size_t)4 * W * H * sizeof *rgba);
    if (!rgba) {
        snprintf(err, err_size, "environment light: out of memory for its sky");
        return -1;
    }
    Sky sky;
    sky_init(&sky, sun, turbidity);
    /* the sky's irradiance on the ground, and the sun's: what a Lambertian
     * ground of the given albedo returns below the horizon */
    double E[3] = {0, 0, 0};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float phi = (((float)x + 0.5f) / (float)W - 0.5f) * 2.0f * PI;
            float theta = ((float)y + 0.5f) / (float)H * PI, st = sinf(theta);
            float d[3] = {-st * sinf(phi), cosf(theta), st * cosf(phi)}; /* as env_uv_to_dir */
            float *o = &rgba[4 * ((size_t)y * W + x)];
            sky_radiance(&sky, d, o);
            o[3] = 1.0f;
            double dw = (2.0 * PI / W) * (PI / H) * st; /* the pixel's solid angle */
            for (int k = 0; k < 3; k++)
                E[k] += o[k] * fmax(d[1], 0.0f) * dw;
        }
    float sun_rgb[3];
    sky_sun_radiance(&sky, sun_rgb);
    double sun_sr = 2.0 * PI * (1.0 - cos(0.265 * PI / 180.0)); /* a 0.53-degree disk */
    for (int k = 0; k < 3; k++)
        E[k] += sun_rgb[k] * sun_sr * sky.sun[1];
    for (int y = H / 2; y < H; y++) /* the rows below the horizon */
        for (int x = 0; x < W; x++) {
            float *o = &rgba[4 * ((size_t)y * W + x)];
            for (int k = 0; k < 3; k++)
                o[k] = (float)(ground[k] * E[k] / PI);
        }
    return env_from_rgba(l, rgba, W, H, "its sky", err, err_size);
}

static void mesh_free(LightMesh *m)
{
    if (!m)
        return;
    free(m->st);
    free(m->place);
    free(m->tex);
    free(m->v);
    free(m->cdf);
    free(m->cluster_of);
    free(m);
}

void light_fini(Light *l)
{
    mesh_free(l->mesh);
    l->mesh = NULL;
    if (!l->env)
        return;
    free(l->env->rgb);
    free(l->env->row_cdf);
    free(l->env->col_cdf);
    free(l->env->pixel_pdf);
    free(l->env->row_guide);
    free(l->env->col_guide);
    free(l->env->band_cdf);
    free(l->env);
    l->env = NULL;
}
