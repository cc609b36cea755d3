/*
 * render/subsurface.c — single-pass subsurface scattering with cached
 * irradiance (memo section 6.2): the subsurface service of shader.h.
 *
 * At a shading point P with normal N (facing out): a probe ray along -N
 * finds the distance to the back side of the object; the probe point lies
 * one mean free path in, or half that distance if shorter. From it, n
 * subsurface rays uniform over the sphere (stratified, cmj) hit only the
 * object's own surfaces (accel_intersect_object: the object's own Embree
 * scene, so a surface inside the object, a bone under skin, stops them).
 * At each hit x the irradiance on the object's outside comes from the
 * irradiance cache (radiosity.c: entries of data type irradiance, level by
 * the ray's footprint t sqrt(4 pi / n)) or, uncached, from the shader's
 * diffuselighting at x alone (integrator.c); the hit stands for the area
 * 4 pi t^2 / (n cos), cos between the ray and the surface (clamped at
 * SUBSURFACE_MIN_COS). The sum of R(|x - P|) E A over the hits, over pi,
 * is the radiance the diffusion brings out at P (shade/diffusion.h).
 *
 * Every random number is a function of the point's key, so images do not
 * depend on threads; cached irradiance depends only on its key, so images
 * do not depend on the cache's budget either. Statistics: rays/subsurface
 * (probe rays and rays from probes), subsurface/points, and the cache's
 * cache/irradiance/... counters.
 */
#include "render/subsurface.h"

#include <math.h>
#include <string.h>

#include "render/integrator.h"
#include "render/radiosity.h"
#include "shade/diffusion.h"
#include "util/rng.h"

#define SUBSURFACE_PI 3.14159265358979f

typedef SubsurfaceMedium Medium;

/* The medium of a call's parameters: the worker's last one when they are
 * the same (a shader's calls, chunk after chunk), else set up again. */
static const Medium *medium_of(Worker *w, const RayesSubsurfaceParams *p)
{
    Medium *m = &w->medium;
    if (w->has_medium && memcmp(&m->params, p, sizeof *p) == 0)
        return m;
    m->params = *p;
    m->scale = p->scale > 0.0f ? p->scale : 1.0f;
    float mfp = 0.0f;
    for (int c = 0; c < 3; c++) {
        diffusion_channel(p, c, &m->ch[c]);
        mfp += m->ch[c].zr / 3.0f;
    }
    m->mfp = mfp * m->scale;
    w->has_medium = 1;
    return m;
}

/* A unit direction uniform over the sphere, from a point of [0,1)^2. */
static Vec3 sphere_direction(float a, float b)
{
    float z = 1.0f - 2.0f * a, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * SUBSURFACE_PI * b;
    return v3(r * cosf(phi), r * sinf(phi), z);
}

/* One shading point of a call. */
typedef struct SubsurfacePoint {
    Vec3 P, N, Ng;   /* N and Ng face out of the object */
    float offset;    /* how far rays start inside the surface, scene units */
    uint32_t object; /* the object it belongs to */
    uint64_t key;    /* its subsurface rays' random numbers */
} SubsurfacePoint;

/* The probe point: one mean free path in along -N, or half the distance
 * to the back side if shorter. */
static Vec3 probe_point(Worker *w, const Medium *m, const SubsurfacePoint *sp)
{
    Vec3 in = v3_neg(sp->N), o = v3_madd(sp->P, sp->Ng, -sp->offset);
    /* A back side beyond 2 mfp leaves the probe at 1 mfp: the ray need not
     * look further (a short ray is cheaper to trace; the same point). */
    Ray ray = {o, in, 0.0f, 2.0f * m->mfp, RAYES_RAY_SUBSURFACE, w->time};
    Hit hit;
    w->stats.rays_subsurface++;
    float back = accel_intersect_object(w->rs->accel, sp->object, &ray, &hit) ? hit.t : INFINITY;
    return v3_madd(o, in, fminf(m->mfp, 0.5f * back));
}

/* The irradiance on the outside at a subsurface hit: cached, or the
 * shader's at the hit alone; spread is the ray's share of the sphere
 * (radians), lookup the spread that chooses the cache's resolution. */
static Vec3 irradiance_at(Worker *w, const Ray *ray, const Hit *hit, float spread, float lookup,
                          uint64_t key)
{
    if (w->set->irradiance_cache && w->set->cache)
        return radiosity_irradiance_at_hit(w, ray, hit, lookup * hit->t);
    return integrator_irradiance(w, ray, hit, key, (RayDiff){0.0f, spread});
}

/* The diffusion's radiance at one point with n rays (memo 6.2). */
static Vec3 integrate_point(Worker *w, const Medium *m, const SubsurfacePoint *sp, int n)
{
    Vec3 c = probe_point(w, m, sp), sum = v3(0, 0, 0);
    float spread = sqrtf(4.0f * SUBSURFACE_PI / (float)n), mm2 = 1.0f / (m->scale * m->scale);
    /* the cache's resolution: no coarser than SUBSURFACE_LOOKUP_RAYS rays'
     * footprint (DESIGN.md: a coarse level's interpolant is biased) */
    int nl = n > SUBSURFACE_LOOKUP_RAYS ? n : SUBSURFACE_LOOKUP_RAYS;
    float lookup = sqrtf(4.0f * SUBSURFACE_PI / (float)nl);
    CmjPattern pattern; /* cmj_sample_2d's points, its shuffles tabled once */
    cmj_pattern_init(&pattern, (uint32_t)n, (uint32_t)sp->key);
    for (int s = 0; s < n; s++) {
        float a, b;
        cmj_pattern_sample(&pattern, (uint32_t)s, &a, &b);
        Ray ray = {c, sphere_direction(a, b), 0.0f, INFINITY, RAYES_RAY_SUBSURFACE, w->time};
        Hit hit;
        w->stats.rays_subsurface++;
        if (!accel_intersect_object(w->rs->accel, sp->object, &ray, &hit))
            continue; /* an open object: the ray left it */
        float cos_x = fabsf(v3_dot(hit.Ng, ray.d));
        float area = diffusion_sample_area(n, hit.t, cos_x, SUBSURFACE_MIN_COS) * mm2; /* mm^2 */
        Vec3 E =
            irradiance_at(w, &ray, &hit, spread, lookup, hash_combine(sp->key, (uint64_t)s + 1));
        float r = v3_length(v3_sub(v3_madd(c, ray.d, hit.t), sp->P)) / m->scale; /* mm */
        sum.x += diffusion_profile(&m->ch[0], r) * E.x * area;
        sum.y += diffusion_profile(&m->ch[1], r) * E.y * area;
        sum.z += diffusion_profile(&m->ch[2], r) * E.z * area;
    }
    return v3_scale(sum, 1.0f / SUBSURFACE_PI);
}

void subsurface_service(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const RayesSubsurfaceParams *p, int n_rays, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int n = n_rays > 0 ? n_rays : w->set->subsurface_rays;
    const GridSet *gs = w->rs->gs;
    const Medium *m = medium_of(w, p);
    for (size_t i = 0; i < ctx->n_points; i++) {
        size_t j = ctx->first_point + i;
        if (n <= 0 || ps->grid >= gs->n_grids) {
            v3_store(out[i], v3(0, 0, 0));
            continue;
        }
        SubsurfacePoint sp = {.P = v3_load(ctx->P[i]),
                              .N = v3_load(ctx->N[i]),
                              .Ng = v3_load(ctx->Ng[i]),
                              .offset = ps->offset[j],
                              .object = gs->grids[ps->grid].object,
                              .key = hash_combine(ps->keys[j], DIM_SUBSURFACE)};
        w->stats.subsurface_points++;
        v3_store(out[i], integrate_point(w, m, &sp, n));
    }
}
