/*
 * render/services.c — the services table shaders call (rayes/shader.h):
 * direct lighting (light sampling and BSDF sampling with multiple
 * importance), ambient light, indirect diffuse (diffuse rays, read through
 * the radiosity cache at their hits by integrator.c, or interpolated
 * irradiance over a grid, irrgrid.c), indirect specular and refraction,
 * transmission, textures, noise, attributes and options. Each renderer's
 * worker holds a pointer to it (Worker.services), set by render.c, so the
 * files that run shaders (integrator.c, radiosity.c, hider.c) do not call
 * this file, which calls them.
 *
 * Every random number is a function of the point's key (PathState.keys)
 * and the ray's index, so images do not depend on threads or order.
 */
#include "render/services.h"

#include <math.h>
#include <string.h>

#include "render/envguide.h"
#include "render/integrator.h"
#include "render/irrgrid.h"
#include "render/pbgi.h"
#include "render/subsurface.h"
#include "shade/bsdf.h"
#include "shade/builtin.h"
#include "shade/diffusion.h"
#include "shade/hair.h"
#include "shade/noise.h"
#include "shade/pattern.h"
#include "util/check.h"
#include "util/rng.h"
#include "util/sampling.h"

/* The renderer's index of the context's point i. */
static size_t point(const RayesShadeCtx *ctx, size_t i)
{
    return ctx->first_point + i;
}

/* The reflection lobe of direct lighting's specular output and of the
 * glossy services (shader.h), with its frame: the normalised Blinn-Phong
 * f = (e + 8) / (8 pi) (N.H)^e (alpha 0), or GGX, Trowbridge-Reitz of
 * width alpha with the height-correlated Smith G, f = D G / (4 N.V N.L) (the
 * microfacet service; shade/bsdf.h evaluates it in the frame). Both are
 * sampled by their half vector about N. */
typedef struct Lobe {
    Vec3 N, t, b; /* the frame about N */
    Vec3 V;       /* toward the viewer */
    Vec3 Vl;      /* GGX's: V in the frame, kept just above the surface */
    float e;      /* Blinn-Phong's exponent */
    float alpha;  /* GGX's width; 0: Blinn-Phong */
    int classic;  /* Blinn-Phong as RenderMan's specular(): (N.H)^e / (pi N.L) */
} Lobe;

/* The lobes point_lobe makes. */

enum { LOBE_BLINN, LOBE_GGX, LOBE_CLASSIC };

/* GGX's narrowest lobe: a smaller width is taken as this one (a mirror is
 * indirect_specular's). */
#define LOBE_MIN_ALPHA 1e-3f

static Lobe lobe_blinn(Vec3 N, Vec3 V, float e)
{
    Lobe l = {N, N, N, V, V, e, 0.0f, 0};
    v3_basis(N, &l.t, &l.b);
    return l;
}

/* A direction in the lobe's frame. */
static Vec3 lobe_local(const Lobe *l, Vec3 d)
{
    return v3(v3_dot(d, l->t), v3_dot(d, l->b), v3_dot(d, l->N));
}

/* The view is kept just above the surface: an interpolated normal may
 * turn a little away from it, where Smith's G would otherwise black the
 * lobe out. */
static Lobe lobe_ggx(Vec3 N, Vec3 V, float alpha)
{
    Lobe l = lobe_blinn(N, V, 0.0f);
    l.alpha = fmaxf(alpha, LOBE_MIN_ALPHA);
    l.Vl = lobe_local(&l, V);
    l.Vl.z = fmaxf(l.Vl.z, 1e-4f);
    return l;
}

/* The lobe's value f toward wi (no cosine). */
static float lobe_f(const Lobe *l, Vec3 wi)
{
    if (l->alpha > 0.0f) {
        Vec3 i = lobe_local(l, wi);
        return i.z > 0.0f ? bsdf_ggx_eval(l->Vl, i, l->alpha) / i.z : 0.0f;
    }
    Vec3 H = v3_normalize(v3_add(wi, l->V));
    float nh = fmaxf(v3_dot(l->N, H), 0.0f);
    if (l->classic) { /* f cos = (N.H)^e / pi: no cosine, as RSL sums Cl (N.H)^e */
        float cos_i = v3_dot(l->N, wi);
        return cos_i > 0.0f ? powf(nh, l->e) / ((float)M_PI * cos_i) : 0.0f;
    }
    return (l->e + 8.0f) / (8.0f * (float)M_PI) * powf(nh, l->e);
}

/* The solid-angle pdf of drawing wi by lobe_sample: the half vector's
 * density divided by 4 V.H, the reflection's Jacobian (Blinn-Phong's
 * half vector has (e + 1) / (2 pi) (N.H)^e, GGX's D(H) N.H). */
static float lobe_pdf(const Lobe *l, Vec3 wi)
{
    if (l->alpha > 0.0f)
        return bsdf_ggx_pdf(l->Vl, lobe_local(l, wi), l->alpha);
    Vec3 H = v3_normalize(v3_add(wi, l->V));
    float nh = v3_dot(l->N, H), vh = v3_dot(l->V, H);
    if (nh <= 0.0f || vh <= 0.0f)
        return 0.0f;
    return (l->e + 1.0f) / (2.0f * (float)M_PI) * powf(nh, l->e) / (4.0f * vh);
}

/* A direction drawn from the lobe with (u1, u2): its half vector about N,
 * the view reflected about it. Returns 0 when the half vector faces away
 * from the view (no direction). */
static int lobe_sample(const Lobe *l, float u1, float u2, Vec3 *wi)
{
    float cos_h;
    if (l->alpha > 0.0f) /* tan^2 = alpha^2 u1 / (1 - u1) (shade/bsdf.c) */
        cos_h = 1.0f / sqrtf(1.0f + l->alpha * l->alpha * u1 / fmaxf(1.0f - u1, 1e-7f));
    else
        cos_h = powf(u1, 1.0f / (l->e + 1.0f));
    float sin_h = sqrtf(fmaxf(0.0f, 1.0f - cos_h * cos_h)), phi = 2.0f * (float)M_PI * u2;
    Vec3 H = v3_add(v3_add(v3_scale(l->t, sin_h * cosf(phi)), v3_scale(l->b, sin_h * sinf(phi))),
                    v3_scale(l->N, cos_h));
    float vh = v3_dot(l->V, H);
    if (vh <= 0.0f)
        return 0;
    *wi = v3_normalize(v3_sub(v3_scale(H, 2.0f * vh), l->V));
    return 1;
}

/* The power heuristic for one sample from each of two strategies. */
static float power_heuristic(float pa, float pb)
{
    float a = pa * pa, b = pb * pb;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

/* The transmittance from o to the point dist along unit wi (INFINITY: the
 * ray escapes): 1 if nothing stands between, 0 behind an opaque surface,
 * the product of (1 - opacity) through transparent ones (memo 6.1); diff
 * is the shadow ray's differential. Counts the shadow ray. */
static Vec3 transmittance(Worker *w, Vec3 o, Vec3 wi, float dist, RayDiff diff)
{
    Ray shadow;
    if (isinf(dist)) {
        shadow = (Ray){o, wi, path_ray_epsilon(w), INFINITY, RAYES_RAY_SHADOW, w->time};
    } else {
        /* tnear skips surfaces through the origin itself: a grid vertex on a
         * corner line (a floor vertex against a wall) lies in the other
         * surface's plane, and would shadow itself. */
        shadow = (Ray){o, v3_scale(wi, dist), path_ray_epsilon(w) / dist, 1.0f - 1e-4f,
                       RAYES_RAY_SHADOW, w->time};
        diff.spread *= dist; /* per unit of the ray's parameter, which spans dist */
    }
    return integrator_transmission(w, &shadow, diff);
}

/* light_intersect, and for a mesh light (seen as v says) its emitter's
 * own Embree scene: the nearest face along wi, whatever else lies between
 * (transmittance asks that). */
static int light_hit(Worker *w, const Light *l, const LightMeshView *v, Vec3 o, Vec3 wi,
                     LightSample *s)
{
    if (l->type != LIGHT_MESH)
        return light_intersect(l, o, wi, s);
    Ray ray = {o, wi, 0.0f, INFINITY, RAYES_RAY_SHADOW, w->time};
    Hit hit;
    if (!accel_intersect_object(w->rs->accel, (uint32_t)l->emitter, &ray, &hit))
        return 0;
    uint32_t tri = w->rs->gs->grids[hit.grid].prim - l->mesh->first_prim;
    return light_mesh_finish(l, v, tri, o, wi, hit.t, hit.Ng, s);
}

/* A light's sample from o, for a mesh light seen as v says. */
static int light_draw(const Light *l, const LightMeshView *v, Vec3 o, float a, float b,
                      LightSample *s)
{
    return l->type == LIGHT_MESH ? light_mesh_sample(l, v, o, a, b, s)
                                 : light_sample(l, o, a, b, s);
}

/* split_rays: n rays at a path's own hit (ps->path) reached through a
 * split of the path into w->split rays (a glossy lobe's several rays at a
 * camera hit) are n / split, at least 1: together the lobe's rays trace n,
 * as the camera hit itself does. Distribution ray tracing branches where
 * the memo does, at depth 0; a glossy lobe of the final preset's 1024
 * rays, each hit tracing 1024 diffuse and 64 shadow rays per light, made a
 * million rays a camera sample (Bitterli's classroom did not finish 48 x
 * 27 pixels in 15 minutes). A mirror's or a refraction's one ray does not
 * split: a wall seen in a mirror keeps the camera's counts. */
static int split_rays(const Worker *w, const PathState *ps, int n)
{
    if (!ps || !ps->path || w->split <= 1.0f || n <= 1)
        return n;
    float m = (float)n / w->split;
    return m < 1.0f ? 1 : (int)(m + 0.5f);
}

/* Traces a lobe's n rays under a split n times the path's (split_rays). */
#define SPLIT_BEGIN(w, n)                                                                          \
    float outer_split_ = (w)->split;                                                               \
    (w)->split *= (float)((n) > 1 ? (n) : 1)
#define SPLIT_END(w) (w)->split = outer_split_

/* The shadow rays a service asked for n_shadow_rays traces per light and
 * point: that many, or with 0 the renderer's setting for the depth (over
 * the path's split, split_rays). */
static int shadow_ray_count(const Worker *w, const RayesShadeCtx *ctx, int n_shadow_rays)
{
    const PathState *ps = ctx->renderer;
    if (n_shadow_rays > 0)
        return n_shadow_rays;
    if (ps && ps->shadow_rays > 0) /* an irradiance fill's own count */
        return ps->shadow_rays;
    return split_rays(w, ps,
                      ctx->diffuse_depth == 0 ? w->set->shadow_rays : w->set->shadow_rays_deep);
}

/* The differential of a shadow ray from point j of ps, one of n: the
 * point's footprint, spreading as a diffuse ray's of n (each stands for
 * 1/n of the light's solid angle). A delta light's one ray spreads not at
 * all (delta_diff). */
static RayDiff shadow_diff(const PathState *ps, size_t j, int n)
{
    float lobe = n > 1 ? 1.0f / sqrtf((float)n) : 0.0f;
    return (RayDiff){ps->diff[j].width, fmaxf(ps->diff[j].spread, lobe)};
}

/* What direct lighting needs of one shading point. */
typedef struct DirectPoint {
    Vec3 o, N, Ng, V;
    Lobe lobe;      /* the specular output's */
    int diff;       /* the diffuse output is wanted */
    int spec;       /* the specular output is wanted */
    RayDiff shadow; /* its shadow rays' differential, for rays drawn from a lobe */
    float spread;   /* the point's own ray spread */
    const LightGuide *guide; /* the environment light's guide here, or NULL (envguide.h) */
} DirectPoint;

/* The differential of the one shadow ray from point j of ps toward a
 * delta light or a given point: its footprint carried there unspread
 * (a distant light's rays from neighbouring points run parallel, a point
 * light's converge), so a cut-out's shadow is as sharp as the cut-out. */
static RayDiff delta_diff(const PathState *ps, size_t j)
{
    return (RayDiff){ps->diff[j].width, 0.0f};
}

/* The transmittance toward light l (transmittance's), 1 for a light
 * nothing shadows. */
static Vec3 light_transmittance(Worker *w, const Light *l, Vec3 o, Vec3 wi, float dist,
                                RayDiff diff)
{
    return l->shadowless ? v3(1, 1, 1) : transmittance(w, o, wi, dist, diff);
}

/* A direction wi that a lobe drew from o toward light l: 1 with the
 * light's sample there (its pdf) and *Li its radiance times the
 * transmittance from o_shadow (o, or a fibre's side), 0 when it adds
 * nothing. An environment is hit by every
 * direction, and its map's look-up is a cache miss where the shadow ray
 * often ends on a wall (an interior lit through its windows): it traces
 * the ray first and looks the map up only for a direction it sees (the
 * same sums: an occluded direction adds 0 either way). */
static int lobe_light(Worker *w, const Light *l, const LightMeshView *v, Vec3 o, Vec3 o_shadow,
                      Vec3 wi, RayDiff diff, LightSample *ls, Vec3 *Li)
{
    if (l->type == LIGHT_ENVIRONMENT) {
        if (!light_env_may_emit(l, wi))
            return 0;
        Vec3 T = light_transmittance(w, l, o_shadow, wi, INFINITY, diff);
        if (!(v3_max_component(T) > 0.0f) || !light_hit(w, l, v, o, wi, ls) ||
            !(v3_max_component(ls->Li) > 0.0f))
            return 0;
        *Li = v3_mul(ls->Li, T);
        return 1;
    }
    if (!light_hit(w, l, v, o, wi, ls) || !(v3_max_component(ls->Li) > 0.0f))
        return 0;
    *Li = v3_mul(ls->Li, light_transmittance(w, l, o_shadow, wi, ls->dist, diff));
    return 1;
}

/* A delta light's one direction from o (point, spot, distant, uber):
 * 0 when it sends nothing there. The shadow ray is u->sw, u->sdist. */
static int delta_sample(const Light *l, Vec3 o, LightUberSample *u)
{
    if (l->type == LIGHT_UBER)
        return light_uber_sample(l, o, u);
    if (!light_sample(l, o, 0.5f, 0.5f, &u->s))
        return 0;
    u->sw = u->s.wi;
    u->sdist = u->s.dist;
    return 1;
}

/* What arrives at o of delta_sample's u: Li times the transmittance of its
 * shadow ray; an uberlight's shadowed share gets its shadowcolor, and its
 * blocker counts as a shadow (Barzel's: Ls + (Li - Ls) unoccluded). */
static Vec3 delta_arriving(Worker *w, const Light *l, Vec3 o, const LightUberSample *u,
                           RayDiff diff)
{
    Vec3 T = light_transmittance(w, l, o, u->sw, u->sdist, diff);
    if (l->type != LIGHT_UBER)
        return v3_mul(u->s.Li, T);
    Vec3 v = v3_scale(T, u->unblocked);
    return v3_add(u->Ls, v3_mul(v3_sub(u->s.Li, u->Ls), v));
}

/* A delta light (point, spot, distant, uber): one shadow ray. */
static void light_delta(Worker *w, const DirectPoint *p, const Light *l, Vec3 *diffuse,
                        Vec3 *spec)
{
    LightUberSample u;
    if (!delta_sample(l, p->o, &u))
        return;
    Vec3 wi = u.s.wi;
    float cos_x = v3_dot(p->N, wi);
    if (cos_x <= 0.0f || v3_dot(p->Ng, wi) <= 0.0f)
        return;
    /* one ray, not a share of a solid angle: the point's footprint carried
     * to the light unspread (a distant light's rays from neighbouring points
     * run parallel, a point light's converge), so a cut-out's shadow is as
     * sharp as the cut-out */
    RayDiff one = {p->shadow.width, 0.0f};
    Vec3 Li = delta_arriving(w, l, p->o, &u, one);
    if (p->diff)
        *diffuse = v3_madd(*diffuse, Li, cos_x / (float)M_PI);
    if (p->spec)
        *spec = v3_madd(*spec, Li, cos_x * lobe_f(&p->lobe, wi));
}

/* Nonzero if the diffuse lobe's strategy is worth its samples for a light
 * in the ball of bound b: not where the light is far for its size, d >= 5 r
 * (d the distance to the ball's centre, r its radius). There the light
 * strategy's solid-angle pdf, d'^2 / (A cos) on a flat light of area A
 * (below pi r^2) at distance d' (above d - r = 4 r), is at least 16 / pi
 * (a sphere's cone: more), 16 times the lobe's largest, 1 / pi: the power
 * heuristic gives the lobe's samples weights below 1/257, and they hit the
 * light rarely (the light's solid angle, below pi / 16, times the lobe's
 * pdf). The light's samples alone, weight 1, are as good an estimate with
 * half the samples; unbiased either way (DESIGN.md "Lights"). */
static int lobe_strategy_useful(const LightBound *b)
{
    return b->all || b->d2 < 25.0f * b->r2;
}

/* An area or environment light, n samples with multiple importance
 * sampling (power heuristic): each light sample is paired with a
 * cosine-distributed direction for the diffuse output and, when the
 * specular output is wanted, a Blinn-Phong direction, which count when
 * they reach the light's emitting side unoccluded; the cosine directions
 * only where the light is near for its size (lobe_strategy_useful: far
 * off, the light's samples alone). The samples are drawn
 * CMJ_BATCH at a time (cmj_pattern_samples) and the lobes' directions
 * first tested against a ball around the light (LightBound); the sums are
 * the same, in the same order, as drawing each sample on its own. */
static void light_area(Worker *w, const DirectPoint *p, const Light *l, uint64_t key, int n,
                       Vec3 *diffuse, Vec3 *spec)
{
    /* wholly below the point's horizon: every strategy's sample has a
     * cosine <= 0 and adds nothing (the same sums, without drawing them) */
    if (light_below_plane(l, p->o, p->N))
        return;
    LightMeshView view; /* a mesh light's clusters as the point sees them */
    if (l->type == LIGHT_MESH) {
        light_mesh_view(l, p->o, p->N, &view);
        if (!(view.cdf[view.n] > 0.0f))
            return; /* every cluster faces away or lies below the horizon */
    }
    Vec3 sum_d = v3(0, 0, 0), sum_s = v3(0, 0, 0);
    LightBound bound;
    light_bound_init(l, p->o, &bound);
    int cosine = p->diff && lobe_strategy_useful(&bound); /* the cosine strategy */
    CmjPattern pattern, pat_cos, pat_bp; /* the light's, the cosine's and the lobe's */
    cmj_pattern_init(&pattern, (uint32_t)n, (uint32_t)key);
    if (cosine)
        cmj_pattern_init(&pat_cos, (uint32_t)n, (uint32_t)hash_combine(key, 1));
    if (p->spec)
        cmj_pattern_init(&pat_bp, (uint32_t)n, (uint32_t)hash_combine(key, 2));
    float la[CMJ_BATCH], lb[CMJ_BATCH], ca[CMJ_BATCH], cb[CMJ_BATCH], ba[CMJ_BATCH], bb[CMJ_BATCH];
    for (int s0 = 0; s0 < n; s0 += CMJ_BATCH) {
        int nb = n - s0 < CMJ_BATCH ? n - s0 : CMJ_BATCH;
        cmj_pattern_samples(&pattern, (uint32_t)s0, (uint32_t)nb, la, lb);
        if (cosine)
            cmj_pattern_samples(&pat_cos, (uint32_t)s0, (uint32_t)nb, ca, cb);
        if (p->spec)
            cmj_pattern_samples(&pat_bp, (uint32_t)s0, (uint32_t)nb, ba, bb);
        /* The light's samples of the batch first, independent of each
         * other (their square roots and divisions overlap), then the rays. */
        LightSample lsb[CMJ_BATCH];
        unsigned char got[CMJ_BATCH];
        for (int j = 0; j < nb; j++)
            got[j] = (p->guide ? light_guide_sample(l, p->guide, la[j], lb[j], &lsb[j])
                               : light_draw(l, &view, p->o, la[j], lb[j], &lsb[j])) &&
                     lsb[j].pdf > 0.0f;
        for (int j = 0; j < nb; j++) {
            LightSample ls = lsb[j];
            /* The light's strategy. */
            if (got[j]) {
                float cos_x = v3_dot(p->N, ls.wi);
                if (cos_x > 0.0f && v3_dot(p->Ng, ls.wi) > 0.0f &&
                    v3_max_component(ls.Li) > 0.0f) {
                    /* each of the n samples stands for 1 / (n pdf) of solid angle */
                    float spread = sqrtf(1.0f / (n * ls.pdf));
                    spread = p->shadow.spread < spread ? p->shadow.spread : spread;
                    RayDiff sd = {p->shadow.width, p->spread > spread ? p->spread : spread};
                    Vec3 Li = v3_mul(ls.Li, light_transmittance(w, l, p->o, ls.wi, ls.dist, sd));
                    /* weighed against the cosine strategy only where it is drawn */
                    float wd = cosine ? power_heuristic(ls.pdf, cos_x / (float)M_PI) : 1.0f;
                    if (p->diff)
                        sum_d = v3_madd(sum_d, Li, wd * cos_x / ((float)M_PI * ls.pdf));
                    if (p->spec) {
                        float ws = power_heuristic(ls.pdf, lobe_pdf(&p->lobe, ls.wi));
                        float f = lobe_f(&p->lobe, ls.wi);
                        sum_s = v3_madd(sum_s, Li, ws * f * cos_x / ls.pdf);
                    }
                }
            }
            /* The diffuse lobe's strategy: weight (cos / pi) / pdf = 1. */
            Vec3 wi;
            float cos_x;
            if (cosine) {
                wi = sample_cosine_frame(p->lobe.t, p->lobe.b, p->N, ca[j], cb[j]);
                cos_x = v3_dot(p->N, wi);
                Vec3 Li;
                if (cos_x > 0.0f && v3_dot(p->Ng, wi) > 0.0f && light_bound_may_hit(&bound, wi) &&
                    lobe_light(w, l, &view, p->o, p->o, wi, p->shadow, &ls, &Li)) {
                    if (p->guide)
                        ls.pdf *= light_guide_factor(l, p->guide, wi);
                    sum_d = v3_madd(sum_d, Li, power_heuristic(cos_x / (float)M_PI, ls.pdf));
                }
            }
            if (!p->spec)
                continue;
            /* The specular lobe's strategy: the half vector about N. */
            if (!lobe_sample(&p->lobe, ba[j], bb[j], &wi))
                continue;
            cos_x = v3_dot(p->N, wi);
            if (cos_x <= 0.0f || v3_dot(p->Ng, wi) <= 0.0f || !light_bound_may_hit(&bound, wi))
                continue;
            float pdf = lobe_pdf(&p->lobe, wi);
            Vec3 Li;
            if (!(pdf > 0.0f) || !lobe_light(w, l, &view, p->o, p->o, wi, p->shadow, &ls, &Li))
                continue;
            if (p->guide)
                ls.pdf *= light_guide_factor(l, p->guide, wi);
            float f = lobe_f(&p->lobe, wi);
            sum_s = v3_madd(sum_s, Li, power_heuristic(pdf, ls.pdf) * f * cos_x / pdf);
        }
    }
    *diffuse = v3_add(*diffuse, v3_scale(sum_d, 1.0f / n));
    if (p->spec)
        *spec = v3_add(*spec, v3_scale(sum_s, 1.0f / n));
}

/* The object whose light links apply to the points of ps: its grid's
 * (every caller, camera hit, grid hider, radiosity fill, irradiance,
 * knows the grid); a test calling services on no grid gets an object lit
 * by every light. */
static const RenderObject *lit_object(const PathState *ps)
{
    static const RenderObject every = {.light = -1};
    const RenderScene *rs = ps->w->rs;
    return ps->grid < rs->gs->n_grids ? render_object(rs, ps->grid, ps->instance) : &every;
}

/* The specular lobe of point i, of kind LOBE_*: GGX of width[i], else
 * Blinn-Phong of exponent 1 / width[i], a roughness (NULL or not above 0:
 * 0.1), normalised or RenderMan's. */
static Lobe point_lobe(Vec3 N, Vec3 V, const float *width, size_t i, int kind)
{
    if (kind == LOBE_GGX)
        return lobe_ggx(N, V, width ? width[i] : 0.0f);
    Lobe l = lobe_blinn(N, V, 1.0f / (width && width[i] > 0.0f ? width[i] : 0.1f));
    l.classic = kind == LOBE_CLASSIC;
    return l;
}

/* 1 if point i is a hole of a cut-out (PathState.holes): no rays of its
 * own, its lighting 0. */
static int hole(const RayesShadeCtx *ctx, size_t i)
{
    const PathState *ps = ctx->renderer;
    return ps->holes && !ps->irradiance && ctx->Os && path_clear(ctx->Os[i]);
}

/* direct_lighting with the lobe of point_lobe of that kind. */
static void direct_lighting(const RayesShadeCtx *ctx, int n_shadow_rays, const char *category,
                            const float *width, int kind, float (*diffuse)[3], float (*specular)[3])
{
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int n = shadow_ray_count(w, ctx, n_shadow_rays);
    int want_spec = specular && ctx->I;
    const RenderObject *obj = lit_object(ps);
    /* camera hits only: not an irradiance fill's points (depth 0 too, with
     * a shadow-ray count of their own), whose guides would depend on
     * which lookup came first */
    int guided = ctx->diffuse_depth == 0 && w->set->env_guide && ps->shadow_rays == 0;
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 d = v3(0, 0, 0), s = v3(0, 0, 0);
        if (hole(ctx, i)) {
            if (diffuse)
                v3_store(diffuse[i], d);
            if (specular)
                v3_store(specular[i], s);
            continue;
        }
        DirectPoint p;
        p.N = v3_load(ctx->N[i]);
        p.Ng = v3_load(ctx->Ng[i]);
        p.o = v3_madd(v3_load(ctx->P[i]), p.Ng, ps->offset[point(ctx, i)]);
        p.V = ctx->I ? v3_neg(v3_load(ctx->I[i])) : v3(0, 0, 0);
        p.lobe = point_lobe(p.N, p.V, width, i, kind);
        p.spec = want_spec;
        p.diff = diffuse != NULL;
        p.shadow = shadow_diff(ps, point(ctx, i), n);
        p.spread = ps->diff[point(ctx, i)].spread;
        int env_slot = 0; /* environment lights so far: each its guide's slot */
        for (size_t k = 0; k < w->rs->n_lights && n > 0; k++) {
            Light moved; /* a light moving within the frame: where it is at w->time */
            const Light *l = light_at_time(&w->rs->lights[k], w->time, &moved);
            int slot = l->type == LIGHT_ENVIRONMENT ? env_slot++ : -1;
            if (l->type == LIGHT_AMBIENT || !render_lit_by(obj, k) ||
                !light_category_match(l, category))
                continue;
            /* camera hits draw an environment by their grid's guide (a
             * moving one, whose bins move, by itself alone) */
            p.guide = slot >= 0 && guided && l == &w->rs->lights[k]
                          ? envguide_get(w, l, slot, ps->grid, ps->instance,
                                         ctx->backfacing ? ctx->backfacing[i] != 0 : 0, n)
                          : NULL;
            const DirectPoint *use = &p;
            DirectPoint q; /* a light for one lobe: the outputs it adds to */
            if (l->nondiffuse || l->nonspecular) {
                q = p;
                q.diff = p.diff && !l->nondiffuse;
                q.spec = p.spec && !l->nonspecular;
                if (!q.diff && !q.spec)
                    continue;
                use = &q;
            }
            if (light_is_area(l))
                light_area(w, use, l,
                           hash_combine(hash_combine(ps->keys[point(ctx, i)], DIM_LIGHT), k), n, &d,
                           &s);
            else
                light_delta(w, use, l, &d, &s);
        }
        if (diffuse)
            v3_store(diffuse[i], d);
        if (specular)
            v3_store(specular[i], s);
        if (ps->irradiance && diffuse) /* memo 6.2: irradiance as a side effect */
            v3_store(ps->irradiance[point(ctx, i)], v3_scale(d, (float)M_PI));
    }
}

static void svc_direct_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                int n_shadow_rays, const char *category, const float *roughness,
                                float (*diffuse)[3], float (*specular)[3])
{
    (void)sv;
    direct_lighting(ctx, n_shadow_rays, category, roughness, LOBE_BLINN, diffuse, specular);
}

static void svc_classic_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 int n_shadow_rays, const char *category, const float *roughness,
                                 float (*diffuse)[3], float (*specular)[3])
{
    (void)sv;
    direct_lighting(ctx, n_shadow_rays, category, roughness, LOBE_CLASSIC, diffuse, specular);
}

/* Kajiya-Kay's terms for tangent T, toward the light wi and the viewer V
 * (zero: no highlight). */
static void fiber_terms(Vec3 T, Vec3 V, Vec3 wi, float e, float *diff, float *spec)
{
    float t = v3_dot(T, wi), sin_t = sqrtf(fmaxf(0.0f, 1.0f - t * t));
    *diff = sin_t / (float)M_PI;
    *spec = 0.0f;
    if (v3_length(V) > 0.0f) {
        float v = v3_dot(T, V), c = sin_t * sqrtf(fmaxf(0.0f, 1.0f - v * v)) - t * v;
        *spec = c > 0.0f ? (e + 2.0f) / (2.0f * (float)M_PI) * powf(c, e) : 0.0f;
    }
}

/* Sampling the fibre highlight: theta (from T) drawn about the mirror
 * cone's pi - theta_v from a Gaussian of width 1 / sqrt(e) (cos^e of the
 * offset is about exp(-e offset^2 / 2)), phi about T uniform. The density
 * of a direction, in solid angle, and a draw from (a, b, c). */
static float fiber_lobe_pdf(Vec3 T, Vec3 V, Vec3 wi, float e)
{
    float tv = fminf(fmaxf(v3_dot(T, V), -1.0f), 1.0f);
    float ti = fminf(fmaxf(v3_dot(T, wi), -1.0f), 1.0f), sin_t = sqrtf(1.0f - ti * ti);
    if (sin_t < 1e-4f)
        return 0.0f;
    float sigma = 1.0f / sqrtf(e), x = (acosf(ti) - ((float)M_PI - acosf(tv))) / sigma;
    return expf(-0.5f * x * x) / (sigma * sqrtf(2.0f * (float)M_PI)) /
           (2.0f * (float)M_PI * sin_t);
}

static int fiber_lobe_sample(Vec3 T, Vec3 V, float e, float a, float b, float c, Vec3 *wi)
{
    float tv = fminf(fmaxf(v3_dot(T, V), -1.0f), 1.0f);
    float gauss = sqrtf(-2.0f * logf(fmaxf(a, 1e-12f))) * cosf(2.0f * (float)M_PI * b);
    float theta = (float)M_PI - acosf(tv) + gauss / sqrtf(e);
    if (!(theta > 0.0f && theta < (float)M_PI))
        return 0;
    Vec3 X, Y;
    v3_basis(T, &X, &Y);
    float phi = 2.0f * (float)M_PI * c, st = sinf(theta);
    *wi = v3_add(v3_scale(T, cosf(theta)),
                 v3_add(v3_scale(X, st * cosf(phi)), v3_scale(Y, st * sinf(phi))));
    return 1;
}

/* What fibre lighting needs of one point. */
typedef struct FiberPoint {
    Vec3 P, Ng, T, V; /* V zero: no highlight */
    float e, offset;
    uint64_t key;   /* the light's sample key */
    RayDiff shadow; /* its shadow rays' differential */
} FiberPoint;

/* A ray's origin off a fibre: on the side of Ng that wi leaves by. */
static Vec3 fiber_origin(const FiberPoint *p, Vec3 wi)
{
    return v3_madd(p->P, p->Ng, v3_dot(wi, p->Ng) >= 0.0f ? p->offset : -p->offset);
}

/* One light's m samples (1 for delta lights), adding to diffuse d and
 * highlight s; an area light's highlight is weighed against the lobe's
 * own samples (power heuristic). Delta lights' Li is what a Lambertian
 * cosine term scales (direct_lighting's (1/pi) Li cos); fibres take Li
 * the same. */
static void fiber_light_samples(Worker *w, const FiberPoint *p, const Light *l,
                                const LightMeshView *view, int m, uint32_t pattern, Vec3 *d,
                                Vec3 *s)
{
    int area = light_is_area(l), spec = v3_length(p->V) > 0.0f;
    CmjPattern pat;
    if (area)
        cmj_pattern_init(&pat, (uint32_t)m, pattern);
    for (int j = 0; j < m; j++) {
        float a = 0.5f, b = 0.5f, fd, fs;
        if (area)
            cmj_pattern_sample(&pat, (uint32_t)j, &a, &b);
        LightSample ls;
        if (!area) { /* a delta light: its shadow ray may aim elsewhere (uberlight) */
            LightUberSample u;
            if (!delta_sample(l, p->P, &u))
                continue;
            ls = u.s;
            ls.Li =
                delta_arriving(w, l, fiber_origin(p, ls.wi), &u, (RayDiff){p->shadow.width, 0.0f});
        } else {
            if (!light_draw(l, view, p->P, a, b, &ls) || !(v3_max_component(ls.Li) > 0.0f) ||
                !(ls.pdf > 0.0f))
                continue;
            ls.Li = v3_mul(ls.Li, light_transmittance(w, l, fiber_origin(p, ls.wi), ls.wi, ls.dist,
                                                      p->shadow));
        }
        float weight = area ? 1.0f / (ls.pdf * (float)m) : 1.0f;
        float ws = area && spec ? power_heuristic(ls.pdf, fiber_lobe_pdf(p->T, p->V, ls.wi, p->e))
                                : 1.0f;
        fiber_terms(p->T, p->V, ls.wi, p->e, &fd, &fs);
        if (!l->nondiffuse)
            *d = v3_madd(*d, ls.Li, fd * weight);
        if (!l->nonspecular)
            *s = v3_madd(*s, ls.Li, fs * weight * ws);
    }
}

/* The highlight's own strategy for an area light: m directions from the
 * lobe that reach the light. */
static void fiber_lobe_samples(Worker *w, const FiberPoint *p, const Light *l,
                               const LightMeshView *view, int m, uint64_t key, Vec3 *s)
{
    CmjPattern pat_ab, pat_c;
    cmj_pattern_init(&pat_ab, (uint32_t)m, (uint32_t)hash_combine(key, 1));
    cmj_pattern_init(&pat_c, (uint32_t)m, (uint32_t)hash_combine(key, 2));
    for (int j = 0; j < m; j++) {
        float a, b, c, c2, fd, fs;
        cmj_pattern_sample(&pat_ab, (uint32_t)j, &a, &b);
        cmj_pattern_sample(&pat_c, (uint32_t)j, &c, &c2);
        Vec3 wi;
        LightSample ls;
        if (!fiber_lobe_sample(p->T, p->V, p->e, a, b, c, &wi))
            continue;
        float pdf = fiber_lobe_pdf(p->T, p->V, wi, p->e);
        if (!(pdf > 0.0f) ||
            !lobe_light(w, l, view, p->P, fiber_origin(p, wi), wi, p->shadow, &ls, &ls.Li))
            continue;
        fiber_terms(p->T, p->V, wi, p->e, &fd, &fs);
        *s = v3_madd(*s, ls.Li, fs * power_heuristic(pdf, ls.pdf) / (pdf * (float)m));
    }
}

static void svc_direct_fiber(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             int n_shadow_rays, const char *category, const float (*T)[3],
                             const float *roughness, float (*diffuse)[3], float (*specular)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int n = shadow_ray_count(w, ctx, n_shadow_rays);
    const RenderObject *obj = lit_object(ps);
    for (size_t i = 0; i < ctx->n_points; i++) {
        FiberPoint p;
        p.P = v3_load(ctx->P[i]);
        p.Ng = v3_load(ctx->Ng[i]);
        p.T = v3_normalize(v3_load(T[i]));
        p.V = specular && ctx->I ? v3_normalize(v3_neg(v3_load(ctx->I[i]))) : v3(0, 0, 0);
        p.e = 1.0f / (roughness && roughness[i] > 0.0f ? roughness[i] : 0.1f);
        p.offset = ps->offset[point(ctx, i)];
        p.shadow = shadow_diff(ps, point(ctx, i), n);
        uint64_t key = hash_combine(ps->keys[point(ctx, i)], DIM_LIGHT);
        Vec3 d = v3(0, 0, 0), s = d;
        for (size_t k = 0; k < w->rs->n_lights && n > 0; k++) {
            Light moved; /* a light moving within the frame: where it is at w->time */
            const Light *l = light_at_time(&w->rs->lights[k], w->time, &moved);
            if (l->type == LIGHT_AMBIENT || !render_lit_by(obj, k) ||
                !light_category_match(l, category) || (l->nondiffuse && l->nonspecular))
                continue;
            int m = light_is_area(l) ? n : 1;
            LightMeshView view; /* fibres light from every side: no horizon */
            if (l->type == LIGHT_MESH)
                light_mesh_view(l, p.P, v3(0, 0, 0), &view);
            fiber_light_samples(w, &p, l, &view, m, (uint32_t)hash_combine(key, k), &d, &s);
            if (light_is_area(l) && v3_length(p.V) > 0.0f && !l->nonspecular)
                fiber_lobe_samples(w, &p, l, &view, m, hash_combine(hash_combine(key, k), 1), &s);
        }
        if (diffuse)
            v3_store(diffuse[i], d);
        if (specular)
            v3_store(specular[i], s);
    }
}

/* ------------------------------------------------------------ hair */

/* What the hair service needs of one point: the fibre's point (its
 * origin, offset and shadow rays' differential), its frame (x along the
 * fibre), the view in it and the BSDF for the view, at the point's offset
 * h or, with across set, at an offset of its own for each sample (the
 * fibre integrated over its width: hair_offset). */
typedef struct HairPoint {
    FiberPoint f;
    Vec3 y, z;
    Vec3 wo; /* toward the viewer, in the frame */
    HairBsdf bsdf;
    const RayesHairParams *params;
    Vec3 sigma_a;
    int across;    /* no offset given: each sample draws its own */
    float h_shift; /* the samples' offsets' shift, from the point's key */
} HairPoint;

/* Offsets a delta light's one ray averages over, with across set. */
#define HAIR_DELTA_OFFSETS 8

static Vec3 hair_local(const HairPoint *p, Vec3 d)
{
    return v3(v3_dot(d, p->f.T), v3_dot(d, p->y), v3_dot(d, p->z));
}

static Vec3 hair_world(const HairPoint *p, Vec3 l)
{
    return v3_add(v3_scale(p->f.T, l.x), v3_add(v3_scale(p->y, l.y), v3_scale(p->z, l.z)));
}

/* The BSDF of a fibre of sigma_a at offset h, the parameters' zeros
 * taken as their defaults (shader.h). */
static void hair_params_bsdf(const RayesHairParams *hp, Vec3 sigma_a, float h, HairBsdf *b)
{
    hair_bsdf_init(b, h, hp->eta > 0.0f ? hp->eta : 1.55f, sigma_a,
                   hp->beta_m > 0.0f ? hp->beta_m : 0.3f, hp->beta_n > 0.0f ? hp->beta_n : 0.3f,
                   hp->alpha);
}

static void hair_bsdf_at(const HairPoint *p, float h, HairBsdf *b)
{
    hair_params_bsdf(p->params, p->sigma_a, h, b);
}

/* The BSDF for sample j of m: the point's own, or with across set the
 * BSDF at the j-th of m stratified offsets over the width (shifted per
 * point), so the m samples together integrate over it. */
static const HairBsdf *hair_offset(const HairPoint *p, int j, int m, HairBsdf *b)
{
    if (!p->across)
        return &p->bsdf;
    hair_bsdf_at(p, -1.0f + 2.0f * fmodf(((float)j + p->h_shift) / (float)m, 1.0f), b);
    return b;
}

/* The BSDF's draws of one strategy: a pattern of pairs for M_p and one
 * more for the lobe and N_p, keyed apart. */
typedef struct HairDraws {
    CmjPattern ab, c;
} HairDraws;

static void hair_draws_init(HairDraws *d, int n, uint64_t key_ab, uint64_t key_c)
{
    cmj_pattern_init(&d->ab, (uint32_t)n, (uint32_t)key_ab);
    cmj_pattern_init(&d->c, (uint32_t)n, (uint32_t)key_c);
}

/* Draw j from BSDF bsdf: world wi and its density. Returns 0 when none. */
static int hair_draw(const HairPoint *p, const HairBsdf *bsdf, const HairDraws *d, int j, Vec3 *wi,
                     float *pdf)
{
    float a, b, c, unused;
    cmj_pattern_sample(&d->ab, (uint32_t)j, &a, &b);
    cmj_pattern_sample(&d->c, (uint32_t)j, &c, &unused);
    Vec3 l;
    if (!hair_bsdf_sample(bsdf, p->wo, c, a, b, &l, pdf))
        return 0;
    *wi = hair_world(p, l);
    return 1;
}

/* A delta light's light toward the viewer: its one ray, through the BSDF
 * at the point's offset or averaged over HAIR_DELTA_OFFSETS of them. */
static Vec3 hair_delta(Worker *w, const HairPoint *p, const Light *l)
{
    LightUberSample u;
    if (!delta_sample(l, p->f.P, &u))
        return v3(0, 0, 0);
    Vec3 wl = hair_local(p, u.s.wi), f = v3(0, 0, 0);
    int k = p->across ? HAIR_DELTA_OFFSETS : 1;
    for (int j = 0; j < k; j++) {
        HairBsdf b;
        f = v3_add(f, hair_bsdf_f(hair_offset(p, j, k, &b), p->wo, wl));
    }
    f = v3_scale(f, 1.0f / (float)k);
    if (!(v3_max_component(f) > 0.0f))
        return v3(0, 0, 0);
    RayDiff one = {p->f.shadow.width, 0.0f};
    return v3_mul(f, delta_arriving(w, l, fiber_origin(&p->f, u.s.wi), &u, one));
}

/* One light's light toward the viewer: a delta light's one ray, or m
 * light samples and m BSDF samples weighed by the power heuristic. */
static Vec3 hair_light(Worker *w, const HairPoint *p, const Light *l, int m, uint64_t key)
{
    Vec3 sum = v3(0, 0, 0);
    if (!light_is_area(l))
        return hair_delta(w, p, l);
    LightMeshView view; /* fibres light from every side: no horizon */
    if (l->type == LIGHT_MESH)
        light_mesh_view(l, p->f.P, v3(0, 0, 0), &view);
    LightBound bound;
    light_bound_init(l, p->f.P, &bound);
    CmjPattern pat;
    HairDraws draws;
    cmj_pattern_init(&pat, (uint32_t)m, (uint32_t)key);
    hair_draws_init(&draws, m, hash_combine(key, 1), hash_combine(key, 2));
    for (int j = 0; j < m; j++) {
        float a, b, pdf;
        LightSample ls;
        HairBsdf own;
        const HairBsdf *bsdf = hair_offset(p, j, m, &own);
        cmj_pattern_sample(&pat, (uint32_t)j, &a, &b);
        if (light_draw(l, &view, p->f.P, a, b, &ls) && ls.pdf > 0.0f &&
            v3_max_component(ls.Li) > 0.0f) {
            Vec3 wl = hair_local(p, ls.wi);
            Vec3 f = hair_bsdf_f(bsdf, p->wo, wl);
            if (v3_max_component(f) > 0.0f) {
                /* each of the m samples stands for 1 / (m pdf) of solid angle */
                float spread = fminf(p->f.shadow.spread, sqrtf(1.0f / ((float)m * ls.pdf)));
                RayDiff sd = {p->f.shadow.width, spread};
                Vec3 Li = v3_mul(ls.Li, light_transmittance(w, l, fiber_origin(&p->f, ls.wi), ls.wi,
                                                            ls.dist, sd));
                float wt = power_heuristic(ls.pdf, hair_bsdf_pdf(bsdf, p->wo, wl));
                sum = v3_add(sum, v3_scale(v3_mul(Li, f), wt / ls.pdf));
            }
        }
        Vec3 wi;
        Vec3 Li;
        if (!hair_draw(p, bsdf, &draws, j, &wi, &pdf) || !light_bound_may_hit(&bound, wi) ||
            !lobe_light(w, l, &view, p->f.P, fiber_origin(&p->f, wi), wi, p->f.shadow, &ls, &Li))
            continue;
        Vec3 f = hair_bsdf_f(bsdf, p->wo, hair_local(p, wi));
        sum = v3_add(sum, v3_scale(v3_mul(Li, f), power_heuristic(pdf, ls.pdf) / pdf));
    }
    return v3_scale(sum, 1.0f / (float)m);
}

/* Everything but the lights: n rays drawn from the BSDF, read as diffuse
 * rays (svc_indirect_diffuse's), to which emitters look black. */
static Vec3 hair_indirect(Worker *w, const RayesShadeCtx *ctx, const HairPoint *p, int n,
                          uint64_t key, RayDiff diff)
{
    Vec3 sum = v3(0, 0, 0);
    HairDraws draws;
    hair_draws_init(&draws, n, key, hash_combine(key, 1));
    for (int s = 0; s < n; s++) {
        float pdf;
        Vec3 wi;
        HairBsdf own;
        const HairBsdf *bsdf = hair_offset(p, s, n, &own);
        if (!hair_draw(p, bsdf, &draws, s, &wi, &pdf))
            continue;
        Ray ray = {fiber_origin(&p->f, wi), wi, 0.0f, INFINITY, RAYES_RAY_DIFFUSE, w->time};
        w->stats.rays_diffuse++;
        Vec3 L =
            integrator_trace(w, &ray, RAYES_RAY_DIFFUSE, ctx->diffuse_depth + 1,
                             ctx->specular_depth, hash_combine(key, (uint64_t)s + 2), diff, NULL);
        Vec3 f = hair_bsdf_f(bsdf, p->wo, hair_local(p, wi));
        sum = v3_add(sum, v3_scale(v3_mul(L, f), 1.0f / pdf));
    }
    return n > 0 ? v3_scale(sum, 1.0f / (float)n) : sum;
}

/* The rays a service reading its hits as diffuse rays traces at a point
 * (n_rays: a shader's own count; 0: the renderer's for the depth, over
 * the path's split); none at the last bounce, one past the branch depth. */
static int diffuse_ray_count(const Worker *w, const RayesShadeCtx *ctx, int n_rays)
{
    const PathState *ps = ctx->renderer;
    int depth = ctx->diffuse_depth;
    int n = n_rays > 0 ? n_rays : depth == 0 ? w->set->diffuse_rays : w->set->diffuse_rays_deep;
    if (n_rays <= 0)
        n = split_rays(w, ps, n);
    if (depth >= w->set->bounces)
        n = 0;
    if (ps->path && n > 1 && depth >= w->set->branch_depth)
        n = 1; /* an uncached hit past the branch depth: one ray follows the path */
    return n;
}

static void svc_hair(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                     const RayesHairParams *hp, int n_shadow_rays, int n_rays, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    memset(out, 0, ctx->n_points * sizeof *out);
    if (!ctx->I || !hp || !hp->T || !hp->sigma_a)
        return;
    int n = shadow_ray_count(w, ctx, n_shadow_rays), n_ind = diffuse_ray_count(w, ctx, n_rays);
    const RenderObject *obj = lit_object(ps);
    float lobe_spread = n_ind > 0 ? 1.0f / sqrtf((float)n_ind) : 0.0f;
    for (size_t i = 0; i < ctx->n_points; i++) {
        HairPoint p;
        Vec3 T = v3_load(hp->T[i]);
        if (hole(ctx, i) || !(v3_length(T) > 0.0f))
            continue;
        size_t j = point(ctx, i);
        p.f.P = v3_load(ctx->P[i]);
        p.f.Ng = v3_load(ctx->Ng[i]);
        p.f.T = v3_normalize(T);
        p.f.V = v3_normalize(v3_neg(v3_load(ctx->I[i])));
        p.f.offset = ps->offset[j];
        p.f.shadow = shadow_diff(ps, j, n);
        v3_basis(p.f.T, &p.y, &p.z);
        p.wo = hair_local(&p, p.f.V);
        p.params = hp;
        p.sigma_a = v3_load(hp->sigma_a[i]);
        float h = hp->h ? hp->h[i] : 2.0f;
        p.across = !(h >= -1.0f && h <= 1.0f);
        p.h_shift = rng_float(hash_combine(hash_combine(ps->keys[j], DIM_SHADER), 0x6861u));
        hair_bsdf_at(&p, p.across ? 0.0f : h, &p.bsdf);
        uint64_t key = hash_combine(ps->keys[j], DIM_LIGHT);
        Vec3 sum = v3(0, 0, 0);
        for (size_t k = 0; k < w->rs->n_lights && n > 0; k++) {
            Light moved; /* a light moving within the frame: where it is at w->time */
            const Light *l = light_at_time(&w->rs->lights[k], w->time, &moved);
            if (l->type == LIGHT_AMBIENT || !render_lit_by(obj, k) ||
                (l->nondiffuse && l->nonspecular))
                continue;
            sum = v3_add(sum, hair_light(w, &p, l, light_is_area(l) ? n : 1, hash_combine(key, k)));
        }
        if (n_ind > 0) {
            RayDiff diff = {ps->diff[j].width, fmaxf(ps->diff[j].spread, lobe_spread)};
            sum = v3_add(sum, hair_indirect(w, ctx, &p, n_ind,
                                            hash_combine(ps->keys[j], DIM_DIFFUSE), diff));
        }
        v3_store(out[i], sum);
    }
}

static void svc_indirect_diffuse(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 int n_rays, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int depth = ctx->diffuse_depth;
    int n = diffuse_ray_count(w, ctx, n_rays);
    IrrGrid *irr = ps->irr;
    if (irr && n > 0 && ctx->N == irr->N + ctx->first_point) {
        /* A grid's own points with its own normals: interpolate (irrgrid.h),
         * records from rays or, with point-based GI, from gathers. */
        if (!irr->done || irr->n_rays != n)
            irrgrid_compute(ps, irr, n);
        memcpy(out, irr->E + ctx->first_point, ctx->n_points * sizeof *out);
        return;
    }
    if (w->set->pbgi && n > 0) { /* point-based GI: gather from the cloud (pbgi.h) */
        PbgiRaster r;
        RY_CHECK(pbgi_raster_init(&r, w->set->pbgi) == 0);
        for (size_t i = 0; i < ctx->n_points; i++)
            v3_store(out[i], pbgi_gather(w->set->pbgi, &r, v3_load(ctx->P[i]), v3_load(ctx->N[i])));
        w->stats.pbgi_gathers += ctx->n_points;
        pbgi_raster_fini(&r);
        return;
    }
    /* Each ray stands for 1/n of the hemisphere: its spread never shrinks. */
    float lobe_spread = n > 0 ? 1.0f / sqrtf((float)n) : 0.0f;
    for (size_t i = 0; i < ctx->n_points; i++) {
        if (hole(ctx, i)) {
            v3_store(out[i], v3(0, 0, 0));
            continue;
        }
        size_t j = point(ctx, i);
        Vec3 P = v3_load(ctx->P[i]), N = v3_load(ctx->N[i]), Ng = v3_load(ctx->Ng[i]);
        Vec3 o = v3_madd(P, Ng, ps->offset[j]), sum = v3(0, 0, 0);
        uint64_t key = hash_combine(ps->keys[j], DIM_DIFFUSE);
        RayDiff diff = {ps->diff[j].width, fmaxf(ps->diff[j].spread, lobe_spread)};
        CmjPattern pat;
        cmj_pattern_init(&pat, (uint32_t)n, (uint32_t)key);
        Vec3 t, bt; /* the point's frame, made once for its rays */
        v3_basis(N, &t, &bt);
        float ua[CMJ_BATCH], ub[CMJ_BATCH];
        for (int s0 = 0; s0 < n; s0 += CMJ_BATCH) {
            int nb = n - s0 < CMJ_BATCH ? n - s0 : CMJ_BATCH;
            cmj_pattern_samples(&pat, (uint32_t)s0, (uint32_t)nb, ua, ub);
            for (int s = s0; s < s0 + nb; s++) {
                Vec3 d = sample_cosine_frame(t, bt, N, ua[s - s0], ub[s - s0]);
                if (v3_dot(d, Ng) <= 0.0f)
                    continue; /* below the geometric surface: no light from there */
                Ray ray = {o, d, 0.0f, INFINITY, RAYES_RAY_DIFFUSE, w->time};
                w->stats.rays_diffuse++;
                Vec3 L = integrator_trace(w, &ray, RAYES_RAY_DIFFUSE, depth + 1,
                                          ctx->specular_depth, hash_combine(key, (uint64_t)s + 1),
                                          diff, NULL);
                sum = v3_add(sum, L);
            }
        }
        v3_store(out[i], n > 0 ? v3_scale(sum, 1.0f / n) : v3(0, 0, 0));
    }
}

static void svc_ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    const RenderScene *rs = ps->w->rs;
    const RenderObject *obj = lit_object(ps);
    Vec3 sum = v3(0, 0, 0);
    for (size_t k = 0; k < rs->n_lights; k++)
        if (rs->lights[k].type == LIGHT_AMBIENT && render_lit_by(obj, k))
            sum = v3_add(sum, rs->lights[k].L);
    for (size_t i = 0; i < ctx->n_points; i++)
        v3_store(out[i], sum);
    ps->w->stats.ambient_lookups += ctx->n_points;
}

/* A reflected direction d that leaves above the smooth surface (N) but
 * below the micropolygon's own plane (Ng), as grazing reflections off a
 * coarsely diced curve do, bent to leave just above that plane: traced as
 * it is, it would start inside the object and bounce about in it until
 * the specular depth ran out, black (a chrome ball in a white furnace lost
 * 6% at normal view, more at its rim). Directions below N are the lobe's
 * own horizon and stay as they are. */
#define SPECULAR_ABOVE 1e-3f
static Vec3 above_facet(Vec3 d, Vec3 N, Vec3 Ng)
{
    float dn = v3_dot(d, Ng);
    if (dn >= SPECULAR_ABOVE || v3_dot(d, N) <= 0.0f)
        return d;
    return v3_normalize(v3_madd(d, Ng, SPECULAR_ABOVE - dn));
}

/* Radiance along d from point i of ctx, a specular or refracted ray. */
static Vec3 trace_specular(const RayesShadeCtx *ctx, size_t i, Vec3 d, uint64_t key,
                           uint32_t kind)
{
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    size_t j = point(ctx, i);
    Vec3 Ng = v3_load(ctx->Ng[i]);
    float off = ps->offset[j];
    Vec3 o = v3_madd(v3_load(ctx->P[i]), Ng, v3_dot(d, Ng) >= 0.0f ? off : -off);
    /* A mirror keeps the spread and adds the curvature's share. */
    float width = ps->diff[j].width;
    RayDiff diff = {width, ps->diff[j].spread + 2.0f * ps->curvature[j] * width};
    Ray ray = {o, d, path_ray_epsilon(w), INFINITY, RAYES_RAY_SPECULAR, w->time};
    w->stats.rays_specular++;
    return integrator_trace(w, &ray, kind, ctx->diffuse_depth, ctx->specular_depth + 1, key, diff,
                            NULL);
}

/* A glossy lobe's rays when n were asked for a whole hemisphere (the
 * depth-0 diffuse count): in proportion to the lobe's solid angle, about
 * 4 pi alpha^2 about the mirror direction (GGX's width alpha; Blinn-Phong's
 * exponent e as alpha^2 = 2 / (e + 2)), against the cosine-weighted
 * hemisphere's pi, so that its rays lie as close together as n diffuse
 * rays' and a bright patch in the lobe is met as often: n 4 alpha^2,
 * at least GLOSSY_MIN_RAYS and at most n. The final preset's 1024 rays a
 * lobe were 1024 for a near mirror too (Bitterli's veach-mis at 128 pixels,
 * final: 27 s, 8.6 s now; docs/performance.md). */
#define GLOSSY_MIN_RAYS 16

/* n times the lobe's share of the hemisphere, share, within the bounds. */
static int glossy_share(int n, float share)
{
    if (n <= GLOSSY_MIN_RAYS)
        return n;
    float m = ceilf((float)n * fminf(share, 1.0f));
    return m < GLOSSY_MIN_RAYS ? GLOSSY_MIN_RAYS : m > (float)n ? n : (int)m;
}

static int glossy_ray_count(const Lobe *l, int n)
{
    float a2 = l->alpha > 0.0f ? l->alpha * l->alpha : 2.0f / (l->e + 2.0f);
    return glossy_share(n, 4.0f * a2);
}

/* The rays a glossy lobe is asked for: a shader's own n_rays, else the
 * renderer's diffuse count for the depth (glossy_share's n), one past the
 * branch depth. */
static int lobe_rays(const Worker *w, const RayesShadeCtx *ctx, int n_rays)
{
    int n = n_rays > 0                ? n_rays
            : ctx->diffuse_depth == 0 ? w->set->diffuse_rays
                                      : w->set->diffuse_rays_deep;
    if (n > 1 && ctx->diffuse_depth + ctx->specular_depth >= w->set->branch_depth)
        n = 1; /* past the branch depth: one ray follows the lobe */
    return n;
}

static void svc_indirect_specular(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const float (*dir)[3], const float *roughness, int n_rays,
                                  float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    for (size_t i = 0; i < ctx->n_points; i++) {
        if (ctx->specular_depth >= w->set->specular_depth) {
            v3_store(out[i], v3(0, 0, 0));
            continue;
        }
        uint64_t key = hash_combine(ps->keys[point(ctx, i)], DIM_SPECULAR);
        Vec3 d = v3_normalize(v3_load(dir[i]));
        Vec3 N = v3_load(ctx->N[i]);
        float r = roughness ? roughness[i] : 0.0f;
        if (r <= 0.0f) {
            w->sharp_rays += ctx->diffuse_depth == 0 && ctx->specular_depth == 0;
            d = above_facet(d, N, v3_load(ctx->Ng[i]));
            v3_store(out[i], trace_specular(ctx, i, d, key, RAYES_RAY_SPECULAR));
            continue;
        }
        /* A glossy lobe: directions with density proportional to cos^e of
         * their angle to d; those below the surface bring nothing. */
        int n = lobe_rays(w, ctx, n_rays);
        float e = 1.0f / r;
        if (n_rays <= 0) /* cos^e about d covers 2 pi / (e + 1) of the sphere */
            n = glossy_share(n, 2.0f / (e + 1.0f));
        Vec3 Ng = v3_load(ctx->Ng[i]), sum = v3(0, 0, 0), t, b;
        v3_basis(d, &t, &b);
        CmjPattern pat;
        cmj_pattern_init(&pat, (uint32_t)n, (uint32_t)key);
        SPLIT_BEGIN(w, n);
        for (int s = 0; s < n; s++) {
            float a1, a2;
            cmj_pattern_sample(&pat, (uint32_t)s, &a1, &a2);
            float cos_t = powf(a1, 1.0f / (e + 1.0f)), sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t));
            float phi = 2.0f * (float)M_PI * a2;
            Vec3 wi = v3_add(v3_add(v3_scale(t, sin_t * cosf(phi)), v3_scale(b, sin_t * sinf(phi))),
                             v3_scale(d, cos_t));
            wi = above_facet(wi, N, Ng);
            if (v3_dot(wi, Ng) <= 0.0f)
                continue;
            sum = v3_add(sum, trace_specular(ctx, i, wi, hash_combine(key, (uint64_t)s + 1),
                                             RAYES_RAY_SPECULAR));
        }
        SPLIT_END(w);
        v3_store(out[i], n > 0 ? v3_scale(sum, 1.0f / n) : v3(0, 0, 0));
    }
}

/* Glossy reflection toward -I with a lobe of point_lobe's (Blinn-Phong,
 * direct lighting's, or GGX): the lights through direct lighting's
 * specular part (multiple importance sampling against the lobe for area
 * and environment lights), everything else through rays drawn from the
 * lobe (half vectors about N), to which emitters look black, each
 * weighted by f cos / pdf. One lobe for lights and for the rest: the sum
 * is the lobe's integral of all incident light. */
static void glossy(const RayesShadeCtx *ctx, const float *width, int kind, int n_rays,
                   float (*out)[3])
{
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    if (!ctx->I) {
        memset(out, 0, ctx->n_points * sizeof *out);
        return;
    }
    direct_lighting(ctx, 0, NULL, width, kind, NULL, out);
    if (ctx->specular_depth >= w->set->specular_depth)
        return;
    int n_all = lobe_rays(w, ctx, n_rays);
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 N = v3_load(ctx->N[i]), Ng = v3_load(ctx->Ng[i]), sum = v3(0, 0, 0);
        Lobe lobe = point_lobe(N, v3_neg(v3_load(ctx->I[i])), width, i, kind);
        uint64_t key = hash_combine(ps->keys[point(ctx, i)], DIM_SPECULAR);
        /* a shader's own count is kept; the renderer's is the lobe's share */
        int n = n_rays > 0 ? n_all : glossy_ray_count(&lobe, n_all);
        CmjPattern pat;
        cmj_pattern_init(&pat, (uint32_t)n, (uint32_t)key);
        SPLIT_BEGIN(w, n);
        for (int s = 0; s < n; s++) {
            float a1, a2;
            Vec3 wi;
            cmj_pattern_sample(&pat, (uint32_t)s, &a1, &a2);
            if (!lobe_sample(&lobe, a1, a2, &wi))
                continue;
            float cos_x = v3_dot(N, wi), pdf = lobe_pdf(&lobe, wi);
            if (cos_x <= 0.0f || v3_dot(Ng, wi) <= 0.0f || !(pdf > 0.0f))
                continue;
            Vec3 L = trace_specular(ctx, i, wi, hash_combine(key, (uint64_t)s + 1),
                                    RAYES_RAY_SPECULAR | PATH_RAY_GLOSSY);
            sum = v3_madd(sum, L, lobe_f(&lobe, wi) * cos_x / pdf);
        }
        SPLIT_END(w);
        v3_store(out[i], v3_add(v3_load(out[i]), v3_scale(sum, 1.0f / (float)n)));
    }
}

static void svc_glossy(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const float *roughness, int n_rays, float (*out)[3])
{
    (void)sv;
    glossy(ctx, roughness, LOBE_BLINN, n_rays, out);
}

static void svc_microfacet(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const float *alpha, int n_rays, float (*out)[3])
{
    (void)sv;
    glossy(ctx, alpha, LOBE_GGX, n_rays, out);
}

static void svc_indirect_refraction(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                    const float (*dir)[3], float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    for (size_t i = 0; i < ctx->n_points; i++) {
        if (ctx->specular_depth >= ps->w->set->specular_depth) {
            v3_store(out[i], v3(0, 0, 0));
            continue;
        }
        uint64_t key = hash_combine(ps->keys[point(ctx, i)], DIM_REFRACTION);
        ps->w->sharp_rays += ctx->diffuse_depth == 0 && ctx->specular_depth == 0;
        v3_store(out[i],
                 trace_specular(ctx, i, v3_normalize(v3_load(dir[i])), key, RAYES_RAY_SPECULAR));
    }
}

static void svc_transmission(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const float (*to)[3], float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 P = v3_load(ctx->P[i]), d = v3_sub(v3_load(to[i]), P);
        float len = v3_length(d);
        Vec3 vis = v3(1, 1, 1);
        if (len > 0.0f) {
            Vec3 Ng = v3_load(ctx->Ng[i]);
            float off = ps->offset[point(ctx, i)];
            Vec3 o = v3_madd(P, Ng, v3_dot(d, Ng) >= 0.0f ? off : -off);
            Vec3 wi = v3_sub(v3_load(to[i]), o);
            float dist = v3_length(wi);
            Ray shadow = {o, wi, path_ray_epsilon(w) / dist, 1.0f - 1e-4f, RAYES_RAY_SHADOW,
                          w->time};
            vis = integrator_transmission(w, &shadow, delta_diff(ps, point(ctx, i)));
        }
        v3_store(out[i], vis);
    }
}

static void svc_occlusion(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n_rays,
                          float maxdist, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int n = n_rays > 0                ? n_rays
            : ctx->diffuse_depth == 0 ? w->set->diffuse_rays
                                      : w->set->diffuse_rays_deep;
    float far = maxdist > 0.0f ? maxdist : INFINITY;
    for (size_t i = 0; i < ctx->n_points; i++) {
        size_t j = point(ctx, i);
        Vec3 N = v3_load(ctx->N[i]), Ng = v3_load(ctx->Ng[i]);
        Vec3 o = v3_madd(v3_load(ctx->P[i]), Ng, ps->offset[j]), open = v3(0, 0, 0);
        uint64_t key = hash_combine(ps->keys[j], DIM_OCCLUSION);
        RayDiff diff = shadow_diff(ps, j, n);
        int counted = 0;
        CmjPattern pat;
        cmj_pattern_init(&pat, (uint32_t)n, (uint32_t)key);
        for (int s = 0; s < n; s++) {
            float a, b;
            cmj_pattern_sample(&pat, (uint32_t)s, &a, &b);
            Vec3 d = sample_cosine_hemisphere(N, a, b);
            counted++;
            if (v3_dot(d, Ng) <= 0.0f)
                continue; /* below the geometric surface: blocked */
            Ray ray = {o, d, 0.0f, far, RAYES_RAY_SHADOW, w->time};
            open = v3_add(open, integrator_transmission(w, &ray, diff));
        }
        Vec3 occ = counted ? v3_sub(v3(1, 1, 1), v3_scale(open, 1.0f / counted)) : v3(0, 0, 0);
        v3_store(out[i], occ);
    }
}

/* The Henyey-Greenstein phase function of the angle whose cosine is c
 * (between the light's direction and the view). */
static float phase_hg(float g, float c)
{
    float d = 1.0f + g * g - 2.0f * g * c;
    return (1.0f - g * g) / (4.0f * (float)M_PI * d * sqrtf(fmaxf(d, 1e-12f)));
}

/* A direction of Henyey-Greenstein's lobe of asymmetry g about the unit
 * axis (its density phase_hg(g, d . axis)), from u1, u2 in [0, 1). */
static Vec3 sample_hg(float g, Vec3 axis, float u1, float u2)
{
    float c;
    if (fabsf(g) < 1e-3f) {
        c = 1.0f - 2.0f * u1;
    } else {
        float q = (1.0f - g * g) / (1.0f - g + 2.0f * g * u1);
        c = (1.0f + g * g - q * q) / (2.0f * g);
    }
    c = fminf(fmaxf(c, -1.0f), 1.0f);
    float s = sqrtf(fmaxf(0.0f, 1.0f - c * c)), phi = 2.0f * (float)M_PI * u2;
    Vec3 t, b;
    v3_basis(axis, &t, &b);
    return v3_add(v3_add(v3_scale(t, s * cosf(phi)), v3_scale(b, s * sinf(phi))),
                  v3_scale(axis, c));
}

/* Rays of multiple scattering a medium's lighting call traces, at most. */
#define MEDIUM_RAYS 4

/* Multiple scattering at a medium's point j: one ray drawn from the phase
 * function (so its weight, phase over density, is 1) and traced as a
 * diffuse ray one depth deeper; the surfaces it meets give their
 * radiosity (the cache's, or their shading), the media it crosses their
 * own scattered light. Lights are direct_volume's: a ray that meets one,
 * or the environment, brings nothing. */
static Vec3 medium_indirect(Worker *w, const RayesShadeCtx *ctx, const PathState *ps, size_t j,
                            Vec3 P, Vec3 I, float g)
{
    uint64_t key = hash_combine(ps->keys[j], DIM_MEDIUM);
    Vec3 axis = v3_length(I) > 0.0f ? v3_normalize(I) : v3(0, 0, 1);
    Vec3 d = sample_hg(v3_length(I) > 0.0f ? g : 0.0f, axis, rng_float(key),
                       rng_float(hash_combine(key, 1)));
    Ray ray = {P, d, 0.0f, INFINITY, RAYES_RAY_DIFFUSE, w->time};
    w->stats.rays_diffuse++;
    RayDiff diff = {ps->diff[j].width, fmaxf(ps->diff[j].spread, 1.0f)};
    return integrator_trace(w, &ray, RAYES_RAY_DIFFUSE, ctx->diffuse_depth + 1, ctx->specular_depth,
                            hash_combine(key, 2), diff, NULL);
}

static void svc_direct_volume(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              int n_shadow_rays, const char *category, float g, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    Worker *w = ps->w;
    int n = shadow_ray_count(w, ctx, n_shadow_rays);
    g = fminf(fmaxf(g, -0.99f), 0.99f);
    /* Multiple scattering from one point in stride (a camera segment's 16
     * lighting points: 4 rays, each standing for its neighbours), the
     * first at random: the light a medium scatters again varies slowly
     * along a ray, its direct light does not */
    int indirect = ctx->diffuse_depth < w->set->bounces && !w->set->pbgi && ctx->n_points > 0 &&
                   (!category || !category[0]); /* once: with every light, not a category */
    size_t stride = (ctx->n_points + MEDIUM_RAYS - 1) / MEDIUM_RAYS, first = 0;
    if (indirect && stride > 1)
        first = (size_t)(rng_float(hash_combine(ps->keys[point(ctx, 0)], DIM_MEDIUM + 100)) *
                         (float)stride) %
                stride;
    for (size_t i = 0; i < ctx->n_points; i++) {
        size_t j = point(ctx, i);
        Vec3 P = v3_load(ctx->P[i]), I = ctx->I ? v3_load(ctx->I[i]) : v3(0, 0, 0);
        uint64_t key = hash_combine(ps->keys[j], DIM_LIGHT);
        Vec3 sum = v3(0, 0, 0);
        for (size_t k = 0; k < w->rs->n_lights && n > 0; k++) {
            Light moved; /* a light moving within the frame: where it is at w->time */
            const Light *l = light_at_time(&w->rs->lights[k], w->time, &moved);
            if (l->type == LIGHT_AMBIENT || !light_category_match(l, category))
                continue;
            int m = light_is_area(l) ? n : 1;
            CmjPattern pattern;
            if (m > 1)
                cmj_pattern_init(&pattern, (uint32_t)m, (uint32_t)hash_combine(key, k));
            for (int s = 0; s < m; s++) {
                float a = 0.5f, b = 0.5f;
                if (m > 1)
                    cmj_pattern_sample(&pattern, (uint32_t)s, &a, &b);
                LightSample ls;
                RayDiff sd = {ps->diff[j].width, ps->diff[j].spread};
                Vec3 T = v3(1, 1, 1);
                if (!light_is_area(l)) { /* its shadow ray may aim elsewhere (uberlight) */
                    LightUberSample u;
                    if (!delta_sample(l, P, &u))
                        continue;
                    ls = u.s;
                    /* the camera's spread kept: a volume's extinction is
                     * smooth, and wider footprints read coarser bricks far
                     * along (Figure 9's cached render: 10% less CPU than
                     * with delta_diff) */
                    ls.Li = delta_arriving(w, l, P, &u, sd);
                } else {
                    if (!light_sample(l, P, a, b, &ls) || !(v3_max_component(ls.Li) > 0.0f) ||
                        !(ls.pdf > 0.0f))
                        continue;
                    sd.spread = fmaxf(sd.spread, sqrtf(1.0f / ((float)m * ls.pdf)));
                    T = light_transmittance(w, l, P, ls.wi, ls.dist, sd);
                }
                float weight = light_is_area(l) ? 1.0f / (ls.pdf * (float)m) : 1.0f;
                float p = v3_length(I) > 0.0f ? phase_hg(g, v3_dot(ls.wi, I))
                                              : 1.0f / (4.0f * (float)M_PI);
                /* delta lights' Li is irradiance-like (direct_lighting's Li cos / pi for a
                 * Lambertian): the medium takes Li p */
                sum = v3_add(sum, v3_scale(v3_mul(ls.Li, T), p * weight));
            }
        }
        if (indirect && i % stride == first)
            sum = v3_add(sum, v3_scale(medium_indirect(w, ctx, ps, j, P, I, g), (float)stride));
        v3_store(out[i], sum);
    }
}

static int svc_texture(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                       const float *s, const float *t, const float *ds, const float *dt,
                       float (*rgb)[3], float *alpha)
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    if (!ds && ps->ds)
        ds = ps->ds + ctx->first_point;
    if (!dt && ps->dt)
        dt = ps->dt + ctx->first_point;
    return shade_texture_service(ps->w->set->textures, ctx, name, s, t, ds, dt, rgb, alpha);
}

static int svc_pattern(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const RayesPattern *pattern, float (*out)[3])
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    return pattern_eval(pattern, ps->w->set->textures, ctx,
                        ps->ds ? ps->ds + ctx->first_point : NULL,
                        ps->dt ? ps->dt + ctx->first_point : NULL, out);
}

static int put_floats(float *value, int n, const float *have, int n_have)
{
    for (int k = 0; k < n && k < n_have; k++)
        value[k] = have[k];
    return n_have;
}

static int svc_attribute(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const char *name, float *value, int n)
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    const Grid *g = &ps->w->rs->gs->grids[ps->grid];
    const RenderScene *rs = ps->w->rs;
    if (strcmp(name, "object:id") == 0)
        return put_floats(value, n,
                          (float[]){(float)(render_object(rs, ps->grid, ps->instance) -
                                            rs->objects)},
                          1);
    if (strcmp(name, "patch:id") == 0)
        return put_floats(value, n, (float[]){(float)ps->grid}, 1);
    if (strcmp(name, "instance:id") == 0) /* 0: not instanced; else the instance + 1 */
        return put_floats(value, n, (float[]){(float)ps->instance}, 1);
    if (strcmp(name, "grid:size") == 0)
        return put_floats(value, n, (float[]){(float)g->nu, (float)g->nv}, 2);
    if (strcmp(name, "grid:edge") == 0)
        return put_floats(value, n, (float[]){g->edge}, 1);
    if (strcmp(name, "grid:curvature") == 0)
        return put_floats(value, n, (float[]){g->curvature}, 1);
    return 0;
}

static int svc_option(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                      float *value, int n)
{
    (void)sv;
    const RenderSettings *set = ((const PathState *)ctx->renderer)->w->set;
    if (strcmp(name, "resolution") == 0)
        return put_floats(value, n, (float[]){(float)set->width, (float)set->height}, 2);
    if (strcmp(name, "bounces") == 0)
        return put_floats(value, n, (float[]){(float)set->bounces}, 1);
    if (strcmp(name, "samples") == 0)
        return put_floats(value, n, (float[]){(float)set->spp}, 1);
    if (strcmp(name, "shadowrays") == 0)
        return put_floats(value, n, (float[]){(float)set->shadow_rays, (float)set->shadow_rays_deep}, 2);
    if (strcmp(name, "diffuserays") == 0)
        return put_floats(value, n,
                          (float[]){(float)set->diffuse_rays, (float)set->diffuse_rays_deep}, 2);
    if (strcmp(name, "branchdepth") == 0)
        return put_floats(value, n, (float[]){(float)set->branch_depth}, 1);
    if (strcmp(name, "subsurfacerays") == 0)
        return put_floats(value, n, (float[]){(float)set->subsurface_rays}, 1);
    return 0;
}

static float svc_random(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                        uint32_t dimension)
{
    (void)sv;
    const PathState *ps = ctx->renderer;
    uint64_t key = hash_combine(ps->keys[point(ctx, i)], DIM_SHADER);
    return rng_float(hash_combine(key, dimension));
}

static const char *const service_names[] = {
    "direct_lighting",
    "ambient",
    "indirect_diffuse",
    "indirect_specular",
    "indirect_refraction",
    "transmission",
    "noise",
    "fbm",
    "turbulence",
    "attribute",
    "option",
    "texture",
    "checker",
    "random",
    "glossy",
    "pattern",
    "direct_fiber",
    "occlusion",
    "direct_volume",
    "subsurface",
    "microfacet",
    "classic_lighting",
    "hair",
};

static int svc_supports(const RayesShaderServices *sv, const char *service)
{
    (void)sv;
    for (size_t i = 0; i < sizeof service_names / sizeof service_names[0]; i++)
        if (strcmp(service, service_names[i]) == 0)
            return 1;
    return 0;
}

const RayesShaderServices render_services = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .direct_lighting = svc_direct_lighting,
    .ambient = svc_ambient,
    .indirect_diffuse = svc_indirect_diffuse,
    .indirect_specular = svc_indirect_specular,
    .indirect_refraction = svc_indirect_refraction,
    .transmission = svc_transmission,
    .occlusion = svc_occlusion,
    .direct_volume = svc_direct_volume,
    .texture = svc_texture,
    .noise = shade_service_noise,
    .fbm = shade_service_fbm,
    .turbulence = shade_service_turbulence,
    .attribute = svc_attribute,
    .option = svc_option,
    .checker = shade_service_checker,
    .supports = svc_supports,
    .random = svc_random,
    .glossy = svc_glossy,
    .direct_fiber = svc_direct_fiber,
    .pattern = svc_pattern,
    .subsurface = subsurface_service,
    .microfacet = svc_microfacet,
    .classic_lighting = svc_classic_lighting,
    .hair = svc_hair,
};

/* ------------------------------------------------ the albedo's furnace */

static void fill(const RayesShadeCtx *ctx, float (*out)[3], float v)
{
    for (size_t i = 0; out && i < ctx->n_points; i++)
        out[i][0] = out[i][1] = out[i][2] = v;
}

static void alb_direct_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                int n_shadow_rays, const char *category, const float *roughness,
                                float (*diffuse)[3], float (*specular)[3])
{
    (void)sv, (void)n_shadow_rays, (void)category, (void)roughness;
    fill(ctx, diffuse, 1.0f);
    fill(ctx, specular, ctx->I ? 1.0f : 0.0f);
}

static void alb_classic_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 int n_shadow_rays, const char *category, const float *roughness,
                                 float (*diffuse)[3], float (*specular)[3])
{
    (void)sv, (void)n_shadow_rays, (void)category;
    fill(ctx, diffuse, 1.0f);
    for (size_t i = 0; specular && i < ctx->n_points; i++) {
        float r = roughness ? roughness[i] : 0.1f, e = r > 0.0f ? 1.0f / r : 1e6f;
        specular[i][0] = specular[i][1] = specular[i][2] = 8.0f / (e + 8.0f);
    }
}

static void alb_direct_fiber(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             int n_shadow_rays, const char *category, const float (*T)[3],
                             const float *roughness, float (*diffuse)[3], float (*specular)[3])
{
    (void)sv, (void)n_shadow_rays, (void)category, (void)T, (void)roughness;
    fill(ctx, diffuse, 1.0f);
    fill(ctx, specular, ctx->I ? 1.0f : 0.0f);
}

static void alb_ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3])
{
    (void)sv;
    fill(ctx, out, 0.0f);
}

static void alb_indirect_diffuse(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 int n_rays, float (*out)[3])
{
    (void)sv, (void)n_rays;
    fill(ctx, out, 0.0f);
}

static void alb_indirect_specular(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const float (*dir)[3], const float *roughness, int n_rays,
                                  float (*out)[3])
{
    (void)sv, (void)dir, (void)n_rays;
    for (size_t i = 0; i < ctx->n_points; i++) /* a mirror: 1; a lobe: direct lighting's */
        out[i][0] = out[i][1] = out[i][2] = !roughness || !(roughness[i] > 0.0f) ? 1.0f : 0.0f;
}

static void alb_lobe(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                     const float *roughness, int n_rays, float (*out)[3])
{
    (void)sv, (void)roughness, (void)n_rays;
    fill(ctx, out, ctx->I ? 1.0f : 0.0f);
}

static void alb_indirect_refraction(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                    const float (*dir)[3], float (*out)[3])
{
    (void)sv, (void)dir;
    fill(ctx, out, 1.0f);
}

static void alb_transmission(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const float (*to)[3], float (*out)[3])
{
    (void)sv, (void)to;
    fill(ctx, out, 1.0f);
}

static void alb_occlusion(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n_rays,
                          float maxdist, float (*out)[3])
{
    (void)sv, (void)n_rays, (void)maxdist;
    fill(ctx, out, 0.0f);
}

static void alb_direct_volume(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              int n_shadow_rays, const char *category, float g, float (*out)[3])
{
    (void)sv, (void)n_shadow_rays, (void)category, (void)g;
    fill(ctx, out, 0.0f);
}

/* Under irradiance pi everywhere the diffusion integral is Rd. */
static void alb_subsurface(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const RayesSubsurfaceParams *p, int n_rays, float (*out)[3])
{
    (void)sv, (void)n_rays;
    float Rd[3];
    for (int c = 0; c < 3; c++) {
        DiffusionChannel ch;
        diffusion_channel(p, c, &ch);
        Rd[c] = ch.Rd;
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        out[i][0] = Rd[0], out[i][1] = Rd[1], out[i][2] = Rd[2];
}

/* The fibre's directional albedo toward -I: its BSDF's integral over the
 * sphere, by HAIR_ALBEDO_SAMPLES stratified draws from it. */
#define HAIR_ALBEDO_SAMPLES 64
static void alb_hair(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                     const RayesHairParams *hp, int n_shadow_rays, int n_rays, float (*out)[3])
{
    (void)sv, (void)n_shadow_rays, (void)n_rays;
    memset(out, 0, ctx->n_points * sizeof *out);
    for (size_t i = 0; ctx->I && hp && hp->T && hp->sigma_a && i < ctx->n_points; i++) {
        Vec3 T = v3_load(hp->T[i]), y, z, sum = v3(0, 0, 0);
        if (!(v3_length(T) > 0.0f))
            continue;
        T = v3_normalize(T);
        v3_basis(T, &y, &z);
        Vec3 V = v3_neg(v3_load(ctx->I[i])), wo = v3(v3_dot(V, T), v3_dot(V, y), v3_dot(V, z));
        HairBsdf b;
        float h = hp->h ? hp->h[i] : 2.0f;
        int across = !(h >= -1.0f && h <= 1.0f); /* the width's mean: an offset a draw */
        Vec3 sigma = v3_load(hp->sigma_a[i]);
        hair_params_bsdf(hp, sigma, across ? 0.0f : h, &b);
        for (int k = 0; k < HAIR_ALBEDO_SAMPLES; k++) {
            if (across)
                hair_params_bsdf(hp, sigma, -1.0f + 2.0f * ((float)k + 0.5f) / HAIR_ALBEDO_SAMPLES,
                                 &b);
            float a = ((float)(k % 8) + 0.5f) / 8.0f, c = ((float)(k / 8) + 0.5f) / 8.0f, pdf;
            float u = ((float)((k * 29) % HAIR_ALBEDO_SAMPLES) + 0.5f) / HAIR_ALBEDO_SAMPLES;
            Vec3 wi;
            if (hair_bsdf_sample(&b, wo, u, a, c, &wi, &pdf))
                sum = v3_madd(sum, hair_bsdf_f(&b, wo, wi), 1.0f / pdf);
        }
        v3_store(out[i], v3_scale(sum, 1.0f / HAIR_ALBEDO_SAMPLES));
    }
}

const RayesShaderServices albedo_services = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .direct_lighting = alb_direct_lighting,
    .ambient = alb_ambient,
    .indirect_diffuse = alb_indirect_diffuse,
    .indirect_specular = alb_indirect_specular,
    .indirect_refraction = alb_indirect_refraction,
    .transmission = alb_transmission,
    .occlusion = alb_occlusion,
    .direct_volume = alb_direct_volume,
    .texture = svc_texture,
    .noise = shade_service_noise,
    .fbm = shade_service_fbm,
    .turbulence = shade_service_turbulence,
    .attribute = svc_attribute,
    .option = svc_option,
    .checker = shade_service_checker,
    .supports = svc_supports,
    .random = svc_random,
    .glossy = alb_lobe,
    .direct_fiber = alb_direct_fiber,
    .pattern = svc_pattern,
    .subsurface = alb_subsurface,
    .microfacet = alb_lobe,
    .classic_lighting = alb_classic_lighting,
    .hair = alb_hair,
};
