/*
 * render/integrator.c — distribution ray tracing: a camera or specular hit
 * runs the shader's lighting() at the hit; a diffuse hit reads the
 * radiosity cache (radiosity.c), or with the cache off (the memo's "without
 * caching" baseline) runs diffuselighting() at that one point (one shading
 * point, counted at its diffuse depth). Area lights (quads, disks,
 * spheres) and environment lights are seen by camera and specular rays;
 * diffuse rays see them as black because direct lighting already integrates
 * them (no double counting). Shaders run with the worker's services table
 * (services.c), whose rays come back here.
 *
 * Every random number is a function of a key: the camera path's key, then
 * hash_combine(key, ray index) for each child ray, so images do not depend
 * on threads or order.
 */
#include "render/integrator.h"

#include "render/hider.h"
#include "render/radiosity.h"
#include "render/volume.h"

#include <math.h>
#include <string.h>

#include "util/check.h"
#include "util/rng.h"

/* The shading inputs of one hit: a 1-point context. */
typedef struct HitPoint {
    float P[3], N[3], Ng[3], dPdu[3], dPdv[3], I[3], Cs[3], Os[3];
    float u, v, du, dv;
    float s, t, ds, dt, dst[4]; /* texture coordinates, filter widths, derivatives */
    uint64_t key;
    RayDiff diff;
    float curvature, offset;
} HitPoint;

/* Interpolates the grid at a hit (the shading normal, texture coordinates,
 * colour and opacity among the rest; Cs and Os from obj without primitive
 * variables);
 * N and Ng face the incoming ray. Returns 1 if the front side (dPdu x dPdv)
 * was hit. */
static int hit_point(const Worker *w, const Ray *ray, const Hit *hit, const RenderObject *obj,
                     HitPoint *hp)
{
    const GridSet *gs = w->rs->gs;
    const Grid *g = &gs->grids[hit->grid];
    Vec3 N = v3(0, 0, 0), du = N, dv = N, Cs = N, Os = N, dflt = v3_load(obj->Cs);
    Vec3 Os_obj = v3_load(obj->Os);
    float u = 0.0f, v = 0.0f, st[2] = {0, 0}, dst[4] = {0, 0, 0, 0}, f;
    int seg = geom_motion_segment(gs, ray->time, &f); /* a moving grid: where it is then */
    for (int k = 0; k < hit->n_vertex; k++) {
        uint32_t i = hit->vertex[k];
        float wk = hit->weight[k], sti[2], dsti[4];
        GeomVertex gv = geom_vertex_at(gs, g, i, seg, f);
        N = v3_madd(N, (g->primvars & GEOM_PV_N) ? gs->Ns[i] : gv.N, wk);
        du = v3_madd(du, gv.dPdu, wk);
        dv = v3_madd(dv, gv.dPdv, wk);
        u += gs->uv[i][0] * wk;
        v += gs->uv[i][1] * wk;
        Cs = v3_madd(Cs, geom_vertex_color(gs, g, i, dflt), wk);
        Os = v3_madd(Os, geom_vertex_opacity(gs, g, i, Os_obj), wk);
        geom_vertex_st(gs, g, i, sti, dsti);
        for (int c = 0; c < 4; c++)
            dst[c] += dsti[c] * wk;
        st[0] += sti[0] * wk, st[1] += sti[1] * wk;
    }
    v3_store(hp->Cs, Cs);
    v3_store(hp->Os, Os);
    hp->s = st[0], hp->t = st[1];
    memcpy(hp->dst, dst, sizeof dst);
    GeomInstance moved; /* a moving instance where it is at the ray's time */
    const GeomInstance *gi =
        geom_instance_at(w->rs->gs, render_instance(w->rs, hit->instance), ray->time, &moved);
    if (gi) { /* a master's grid: its vectors to world space (hit->Ng is already) */
        N = mat4_vector(&gi->normal_to_world, N);
        du = mat4_vector(&gi->world_from_master, du);
        dv = mat4_vector(&gi->world_from_master, dv);
    }
    N = v3_normalize(N);
    Vec3 Ng = v3_length(hit->Ng) > 0.0f ? hit->Ng : N;
    int front = v3_dot(Ng, ray->d) < 0.0f;
    if (!front) {
        N = v3_neg(N);
        Ng = v3_neg(Ng);
    }
    if (v3_dot(N, Ng) < 0.0f || hit->shape == GEOM_SHAPE_ROUND_CURVE ||
        hit->shape == GEOM_SHAPE_SPHERE) /* across a silhouette; round shapes' own normal */
        N = Ng;
    else if (render_faces_ray(hit->shape))
        N = render_facing(ray->d, du, hit->shape, Ng);
    v3_store(hp->P, v3_madd(ray->o, ray->d, hit->t));
    v3_store(hp->N, N);
    v3_store(hp->Ng, Ng);
    v3_store(hp->dPdu, du);
    v3_store(hp->dPdv, dv);
    v3_store(hp->I, ray->d);
    hp->u = u;
    hp->v = v;
    hp->du = hp->dv = 0.0f;
    hp->curvature = g->curvature / (gi ? gi->scale : 1.0f);
    hp->offset = path_ray_offset_in(w, g, hit->instance);
    return front;
}

/* The parameter footprint of a hit (the context's du, dv). The ray's
 * footprint of width w lands on the surface as an ellipse, w across the
 * incoming direction and w / cos(theta) along it (cos clamped at 1/64, so
 * grazing hits stay finite); du and dv are its extents along dPdu and dPdv,
 * divided by their lengths: the parameter ranges the point stands for. */
static void hit_footprint(HitPoint *hp)
{
    Vec3 Ng = v3(hp->Ng[0], hp->Ng[1], hp->Ng[2]), I = v3(hp->I[0], hp->I[1], hp->I[2]);
    float w = hp->diff.width, cos_i = v3_dot(Ng, I);
    float stretch = 1.0f / fmaxf(fabsf(cos_i) / fmaxf(v3_length(I), 1e-30f), 1.0f / 64.0f);
    Vec3 t1, t2; /* along I's direction in the plane (stretched), and across it */
    v3_basis_toward(Ng, I, &t1, &t2);
    const float *d[2] = {hp->dPdu, hp->dPdv};
    float *out[2] = {&hp->du, &hp->dv};
    for (int k = 0; k < 2; k++) {
        Vec3 e = v3(d[k][0], d[k][1], d[k][2]);
        float len = v3_length(e);
        if (!(len > 0.0f) || !(w > 0.0f)) {
            *out[k] = 0.0f;
            continue;
        }
        float a = w * stretch * v3_dot(t1, e) / len, b = w * v3_dot(t2, e) / len;
        *out[k] = sqrtf(a * a + b * b) / len;
    }
}

/* Turns a hit's point to face the side the ray leaves through (a
 * subsurface ray's hit from inside: the object's outside, memo 6.2). */
static void face_outside(HitPoint *hp, int *backfacing)
{
    for (int c = 0; c < 3; c++)
        hp->N[c] = -hp->N[c], hp->Ng[c] = -hp->Ng[c];
    *backfacing = !*backfacing;
}

/* A hit's shading context and what it points at (set up by shade_site;
 * it must not move afterwards). */
typedef struct ShadeSite {
    HitPoint hp;
    PathState ps;
    int backfacing;
    RayesShadeCtx ctx;
} ShadeSite;

/* The context of one point: the hit as a ray of type kind sees it (with
 * RAYES_RAY_SUBSURFACE, on the side the ray leaves through). */
static void shade_site(Worker *w, const Ray *ray, const Hit *hit, const RenderObject *obj,
                       uint32_t kind, int diffuse_depth, int specular_depth, uint64_t key,
                       RayDiff diff, ShadeSite *s)
{
    HitPoint *hp = &s->hp;
    s->backfacing = !hit_point(w, ray, hit, obj, hp);
    if (kind == RAYES_RAY_SUBSURFACE)
        face_outside(hp, &s->backfacing);
    hp->key = key;
    hp->diff = (RayDiff){path_footprint(diff, hit->t), diff.spread};
    hit_footprint(hp);
    path_st_footprint(hp->dst, hp->du, hp->dv, &hp->ds, &hp->dt);
    int own_st = (w->rs->gs->grids[hit->grid].primvars & GEOM_PV_ST) != 0;
    s->ps = (PathState){w,
                        &hp->key,
                        &hp->diff,
                        &hp->curvature,
                        &hp->offset,
                        NULL,
                        hit->grid,
                        own_st ? &hp->ds : NULL,
                        own_st ? &hp->dt : NULL,
                        1,
                        NULL,
                        hit->instance};
    s->ctx = (RayesShadeCtx){
        .n_points = 1,
        .ray_type = kind & ~PATH_RAY_GLOSSY,
        .diffuse_depth = diffuse_depth,
        .specular_depth = specular_depth,
        .P = (const float(*)[3])hp->P,
        .N = (const float(*)[3])hp->N,
        .Ng = (const float(*)[3])hp->Ng,
        .dPdu = (const float(*)[3])hp->dPdu,
        .dPdv = (const float(*)[3])hp->dPdv,
        .u = &hp->u,
        .v = &hp->v,
        .s = &hp->s,
        .t = &hp->t,
        .du = &hp->du,
        .dv = &hp->dv,
        .I = (const float(*)[3])hp->I,
        .Cs = (const float(*)[3])hp->Cs,
        .Os = (const float(*)[3])hp->Os,
        .renderer = &s->ps,
        .backfacing = &s->backfacing,
        .dst = own_st ? (const float(*)[4]) & hp->dst : NULL,
    };
    path_apply_Os_pattern(w, obj, &s->ctx, &hp->Os);
}

/* Shades the hit as a ray of type kind sees it (lighting, diffuselighting,
 * or with kind RAYES_RAY_TRANSMISSION the opacity method; with
 * RAYES_RAY_SUBSURFACE diffuselighting on the side the ray leaves through,
 * whose Irradiance output is returned); *Oi receives the shader's
 * opacity. */
static Vec3 shade_hit(Worker *w, const Ray *ray, const Hit *hit, const RenderObject *obj,
                      uint32_t kind, int diffuse_depth, int specular_depth, uint64_t key,
                      RayDiff diff, Vec3 *Oi_out)
{
    ShadeSite site;
    shade_site(w, ray, hit, obj, kind, diffuse_depth, specular_depth, key, diff, &site);
    /* A hole in a cut-out: Os 0 here (a pattern's, a primitive
     * variable's), and no opacity method that could say otherwise. Its
     * lighting would be multiplied by 0 (Ci is premultiplied; the built-in
     * shaders multiply by Os) after casting its shadow and diffuse rays:
     * the ray goes on behind it unshaded, as a path tracer's alpha test
     * lets it. */
    if (obj->transparent && !obj->opacity_shader &&
        (kind & (RAYES_RAY_CAMERA | RAYES_RAY_SPECULAR | RAYES_RAY_DIFFUSE)) &&
        path_clear(site.hp.Os)) { /* NaN: shaded */
        w->stats.holes++;
        *Oi_out = v3(0, 0, 0);
        return v3(0, 0, 0);
    }
    float Ci[1][3] = {{0, 0, 0}}, Oi[1][3] = {{1, 1, 1}}, E[1][3] = {{0, 0, 0}};
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    /* Whatever the kind, the hit is shaded as its own object: a glass's
     * thin shadow is opaque to its own light samples alone, not to those
     * of what its refraction rays reach (RAYES_SHADER_THIN_SHADOW). */
    const RenderObject *outer = w->shading;
    int outer_depth = w->depth;
    w->shading = obj;
    w->depth = diffuse_depth;
    if (kind == RAYES_RAY_SUBSURFACE) {
        w->stats.irradiance_points++;
        out.Irradiance = site.ps.irradiance = E;
        shade_run_diffuselighting(w->services, &site.ctx, obj->shader, &out);
        Oi[0][0] = Oi[0][1] = Oi[0][2] = 1.0f;
        Ci[0][0] = E[0][0], Ci[0][1] = E[0][1], Ci[0][2] = E[0][2];
    } else if (kind == RAYES_RAY_TRANSMISSION) {
        w->stats.opacity_points++;
        shade_run_opacity(w->services, &site.ctx, obj->shader, &out);
    } else if (kind == RAYES_RAY_DIFFUSE) {
        w->stats.shading_points[RY_MIN(diffuse_depth, RENDER_MAX_DEPTH)]++;
        shade_run_diffuselighting(w->services, &site.ctx, obj->shader, &out);
    } else {
        w->stats.shading_points[RY_MIN(diffuse_depth, RENDER_MAX_DEPTH)]++;
        shade_run_lighting(w->services, &site.ctx, obj->shader, &out);
    }
    w->shading = outer;
    w->depth = outer_depth;
    *Oi_out = v3(Oi[0][0], Oi[0][1], Oi[0][2]);
    return v3(Ci[0][0], Ci[0][1], Ci[0][2]);
}

/* Os of the grid's primitive variable at a hit (by the hit's weights). */
static Vec3 hit_Os(const GridSet *gs, const Hit *hit, const RenderObject *obj)
{
    const Grid *g = &gs->grids[hit->grid];
    Vec3 Os = v3(0, 0, 0), Os_obj = v3_load(obj->Os);
    for (int k = 0; k < hit->n_vertex; k++)
        Os = v3_madd(Os, geom_vertex_opacity(gs, g, hit->vertex[k], Os_obj), hit->weight[k]);
    return Os;
}

Vec3 integrator_irradiance(Worker *w, const Ray *ray, const Hit *hit, uint64_t key,
                           RayDiff diff)
{
    const RenderObject *obj = &w->rs->objects[w->rs->gs->grids[hit->grid].object];
    if (!obj->shader)
        return v3(0, 0, 0);
    Vec3 Oi;
    return shade_hit(w, ray, hit, obj, RAYES_RAY_SUBSURFACE, 0, 0, key, diff, &Oi);
}

Vec3 integrator_opacity(Worker *w, const Ray *ray, Hit *hit, const AccelCrossing *crossing,
                        RayDiff diff)
{
    const GridSet *gs = w->rs->gs;
    const RenderObject *obj = render_object(w->rs, hit->grid, hit->instance);
    if (!obj->transparent || (obj->thin_shadow && obj == w->shading))
        return v3(1, 1, 1);
    if (!obj->opacity_shader && !obj->Os_pattern) /* Os alone: no shader runs */
        return (gs->grids[hit->grid].primvars & GEOM_PV_OS) ? hit_Os(gs, hit, obj)
                                                            : v3_load(obj->Os);
    /* A shadow ray (a crossing) too fine for the cache asks the shader; a
     * diffuse ray's hit (no crossing) keeps the cache's, as its Ci is the
     * radiosity cache's, premultiplied by the same cached opacity. */
    if (w->set->opacity_cache && obj->opacity_cached &&
        !(crossing && radiosity_opacity_too_fine(w, hit, diff)))
        return radiosity_opacity_at_hit(w, hit, diff);
    Vec3 Oi;
    accel_crossing_normal(crossing, hit);
    shade_hit(w, ray, hit, obj, RAYES_RAY_TRANSMISSION, 0, 0, 0, diff, &Oi);
    return Oi;
}

/* AccelOpacityFn of shadow rays: the opacity at a transparent hit. */
typedef struct ShadowRay {
    Worker *w;
    RayDiff diff;
} ShadowRay;

static Vec3 shadow_opacity(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    ShadowRay *sr = user;
    sr->w->stats.transparent_hits++;
    return integrator_opacity(sr->w, ray, hit, crossing, sr->diff);
}

Vec3 integrator_transmission(Worker *w, const Ray *ray, RayDiff diff)
{
    w->stats.rays_shadow++;
    Vec3 T;
    if (!w->rs->any_transparent) {
        T = accel_occluded(w->rs->accel, ray) ? v3(0, 0, 0) : v3(1, 1, 1);
    } else {
        ShadowRay sr = {w, diff};
        T = accel_transmission(w->rs->accel, ray, shadow_opacity, &sr,
                               w->depth > 0 ? INTEGRATOR_SHADOW_ROULETTE : 0.0f);
    }
    if (w->rs->n_volumes && v3_max_component(T) > 0.0f)
        T = v3_mul(T, volume_transmittance(w, ray, diff));
    return T;
}

/* AccelKeepFn of cached diffuse rays: a transparent hit of grey opacity a
 * is kept with probability a (a coloured one always: trace_layers
 * composites it), its opacity read as trace_layers reads it. */
static float diffuse_keep(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    ShadowRay *sr = user;
    Worker *w = sr->w;
    const RenderObject *obj = render_object(w->rs, hit->grid, hit->instance);
    if (!obj->transparent)
        return 1.0f;
    if (!(w->set->opacity_cache && obj->opacity_cached)) /* a shader may run at the hit */
        accel_crossing_normal(crossing, hit);
    Vec3 Oi = integrator_opacity(w, ray, hit, NULL, sr->diff);
    if (Oi.x != Oi.y || Oi.y != Oi.z)
        return 1.0f;
    return fminf(fmaxf(Oi.x, 0.0f), 1.0f);
}

/* Surfaces a ray sees through before the next is taken as opaque. */
#define INTEGRATOR_MAX_LAYERS 64

/* integrator_trace_hit, with alpha (the coverage along the ray: 1 - the
 * mean of the transmittance through what it hit) and the layer count of
 * partly transparent surfaces already crossed. A transparent surface's
 * premultiplied Ci is composited over what lies behind it, front to back:
 * Ci + (1 - Oi) L_behind, Oi the shader's (camera, specular and uncached
 * diffuse hits) or the opacity cache's (cached diffuse hits). */
static Vec3 trace_volumes(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                          int specular_depth, uint64_t key, RayDiff diff, float *t, float *alpha,
                          int layer);

/* A camera sample's AOVs from the surface it sees first (RayesAov): the
 * first it meets that is not a hole (a cut-out's Os 0 is passed). */
static void aov_capture(Worker *w, const Ray *ray, const Hit *hit, const RenderObject *obj,
                        uint64_t key, RayDiff diff)
{
    /* The albedo: the shader's lighting in a white furnace (nothing
     * traced, nothing counted, no random number of the colour's drawn),
     * on the hit's context, whose point the other AOVs read too. */
    int albedo =
        (w->set->aovs & RAYES_AOV_ALBEDO) && obj->light < 0 && obj->shader && w->albedo_services;
    ShadeSite site;
    if (albedo)
        shade_site(w, ray, hit, obj, RAYES_RAY_CAMERA, 0, 0, key, diff, &site);
    else
        hit_point(w, ray, hit, obj, &site.hp);
    const HitPoint *hp = &site.hp;
    AovSample *a = w->aov;
    a->set = 1;
    a->P = v3_load(hp->P);
    a->N = v3_load(hp->N);
    a->z = v3_dot(v3_sub(a->P, ray->o), w->rs->camera.forward);
    a->id = (uint32_t)(obj - w->rs->objects) + 1;
    a->patch = hit->grid + 1;
    if (albedo) {
        float Ci[1][3] = {{0, 0, 0}}, Oi[1][3] = {{1, 1, 1}};
        RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
        const RenderObject *outer = w->shading;
        w->shading = obj;
        shade_run_lighting(w->albedo_services, &site.ctx, obj->shader, &out);
        w->shading = outer;
        a->albedo = v3(Ci[0][0], Ci[0][1], Ci[0][2]);
    } else if ((w->set->aovs & RAYES_AOV_ALBEDO) && obj->light >= 0) { /* its hue */
        Vec3 L = w->rs->lights[obj->light].L;
        float m = v3_max_component(L);
        a->albedo = m > 0.0f ? v3_scale(L, 1.0f / m) : v3(0, 0, 0);
    }
}

static Vec3 trace_layers(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                         int specular_depth, uint64_t key, RayDiff diff, float *t, float *alpha,
                         int layer, int64_t *leaving)
{
    Hit hit;
    *t = INFINITY;
    *alpha = 0.0f;
    *leaving = -1;
    /* A cached diffuse ray meets cut-outs stochastically: one traversal
     * to the layer it stops at, instead of one per layer in front of it,
     * each looked up in the radiosity cache (foliage: a dozen; DESIGN.md
     * "Opacity"). */
    int stochastic = kind == RAYES_RAY_DIFFUSE && w->set->radiosity_cache && w->rs->any_transparent;
    ShadowRay sr = {w, diff};
    if (!(stochastic ? accel_intersect_stochastic(w->rs->accel, ray, diffuse_keep, &sr, key, &hit)
                     : accel_intersect(w->rs->accel, ray, &hit))) {
        /* Environment lights: seen by camera and specular rays; black to
         * diffuse rays, as direct lighting integrates them. */
        Vec3 L = v3(0, 0, 0);
        int sees_lights = !(kind & (RAYES_RAY_DIFFUSE | PATH_RAY_GLOSSY));
        for (size_t k = 0; sees_lights && k < w->rs->n_lights; k++)
            if (w->rs->lights[k].type == LIGHT_ENVIRONMENT &&
                (w->rs->lights[k].seen_by &
                 (kind & RAYES_RAY_CAMERA ? RAYES_RAY_CAMERA : RAYES_RAY_SPECULAR))) {
                Light moved; /* a turning map: its rotation at the ray's time */
                L = v3_add(L, light_env_radiance(light_at_time(&w->rs->lights[k], ray->time,
                                                               &moved),
                                                 ray->d));
            }
        return L;
    }
    *t = hit.t;
    *alpha = 1.0f;
    const RenderObject *obj = render_object(w->rs, hit.grid, hit.instance);
    if (v3_dot(hit.Ng, ray->d) > 0.0f) /* out through its back: the ray was inside it */
        *leaving = obj - w->rs->objects;
    int aov = w->aov && !w->aov->set && kind == RAYES_RAY_CAMERA;
    if (obj->light >= 0) {
        if (aov)
            aov_capture(w, ray, &hit, obj, key, diff);
        /* Emitters: seen by camera and specular rays, on their front side
         * or both (not by glossy-lobe rays: direct lighting has them). */
        const Light *l = &w->rs->lights[obj->light];
        if ((kind & (RAYES_RAY_DIFFUSE | PATH_RAY_GLOSSY)) ||
            (!l->two_sided && v3_dot(hit.Ng, ray->d) >= 0.0f))
            return v3(0, 0, 0);
        if (l->type == LIGHT_MESH && l->mesh->tex) /* its texture at the hit */
            return light_mesh_radiance(l, w->rs->gs->grids[hit.grid].prim - l->mesh->first_prim,
                                       v3_madd(ray->o, ray->d, hit.t));
        if (l->cone > 0.0f) /* seen from outside its cone, dark, as it lights */
            return v3_scale(l->L, light_cone_factor(l, -v3_dot(hit.Ng, v3_normalize(ray->d))));
        return l->L;
    }
    int see_through = obj->transparent && layer < INTEGRATOR_MAX_LAYERS;
    Vec3 Ci = v3(0, 0, 0), Oi = v3(1, 1, 1);
    if (kind == RAYES_RAY_DIFFUSE && w->set->radiosity_cache) {
        if (obj->transparent) /* the opacity diffuse_keep kept it by */
            Oi = integrator_opacity(w, ray, &hit, NULL, diff);
        if (obj->transparent && Oi.x == Oi.y && Oi.y == Oi.z) {
            /* kept with probability Oi: the premultiplied radiosity over
             * it, and nothing behind (what lay in front was passed) */
            float a = fminf(fmaxf(Oi.x, 0.0f), 1.0f);
            return a > 0.0f
                       ? v3_scale(radiosity_at_hit(w, ray, &hit, diffuse_depth, diff), 1.0f / a)
                       : v3(0, 0, 0);
        }
        if (see_through && !obj->opacity_shader && Oi.x <= 0.0f && Oi.y <= 0.0f && Oi.z <= 0.0f)
            w->stats.holes++; /* a cut-out's hole (shade_hit's) */
        else
            Ci = radiosity_at_hit(w, ray, &hit, diffuse_depth, diff);
    } else if (kind == RAYES_RAY_CAMERA && w->grid_shading &&
               hider_camera_hit(w, ray, &hit, &Ci, &Oi)) {
        /* the grid hider's shaded grid (a master's grid per instance; Ci
         * and Oi of a transparent one) */
    } else {
        Ci = shade_hit(w, ray, &hit, obj, kind, diffuse_depth, specular_depth, key, diff, &Oi);
    }
    if (aov && !(obj->transparent && !(v3_max_component(Oi) > 0.0f))) /* not a hole */
        aov_capture(w, ray, &hit, obj, key, diff);
    if (!see_through)
        return Ci;
    Vec3 T = v3(1.0f - fminf(fmaxf(Oi.x, 0.0f), 1.0f), 1.0f - fminf(fmaxf(Oi.y, 0.0f), 1.0f),
                1.0f - fminf(fmaxf(Oi.z, 0.0f), 1.0f));
    if (!(v3_max_component(T) > 0.0f))
        return Ci;
    /* What lies behind, from just past the hit (never the same surface). */
    Ray next = *ray;
    next.tnear = hit.t + path_ray_epsilon(w) / fmaxf(v3_length(ray->d), 1e-30f);
    float t_behind, a_behind; /* the volumes between it and the next surface too */
    Vec3 L = trace_volumes(w, &next, kind, diffuse_depth, specular_depth,
                           hash_combine(key, 0x6c61796572ull /* "layer" */), diff, &t_behind,
                           &a_behind, layer + 1);
    float cover = 1.0f - (T.x + T.y + T.z) / 3.0f;
    *alpha = cover + (1.0f - cover) * a_behind;
    return v3_add(Ci, v3_mul(T, L));
}

/* trace_layers from layer on, seen through the volumes in front of what
 * the ray hits: their light added, what lies behind attenuated
 * (volume.h). A transparent surface's layer behind it comes here again, so
 * the volumes behind it count too. */
static Vec3 trace_volumes(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                          int specular_depth, uint64_t key, RayDiff diff, float *t, float *alpha,
                          int layer)
{
    int64_t leaving;
    Vec3 L = trace_layers(w, ray, kind, diffuse_depth, specular_depth, key, diff, t, alpha, layer,
                          &leaving);
    if (!w->rs->n_volumes)
        return L;
    Vec3 T;
    float tmax = isfinite(*t) ? *t : ray->tfar;
    Vec3 Lv =
        volume_radiance(w, ray, tmax, leaving, isfinite(*t), kind, diffuse_depth, specular_depth,
                        hash_combine(key, 0x766f6c756d65ull /* "volume" */), diff, &T);
    *alpha = 1.0f - (1.0f - *alpha) * (T.x + T.y + T.z) / 3.0f;
    return v3_add(Lv, v3_mul(T, L));
}

Vec3 integrator_trace(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                      int specular_depth, uint64_t key, RayDiff diff, float *alpha)
{
    if (render_stop_requested(w->set)) { /* abandoned: nothing of this frame is kept */
        if (alpha)
            *alpha = 0.0f;
        return v3(0, 0, 0);
    }
    float t, a, outer = w->time;
    w->time = ray->time; /* what the hit's shading traces inherits */
    Vec3 L = trace_volumes(w, ray, kind, diffuse_depth, specular_depth, key, diff, &t, &a, 0);
    w->time = outer;
    if (alpha)
        *alpha = a;
    return L;
}

Vec3 integrator_trace_hit(Worker *w, const Ray *ray, uint32_t kind, int diffuse_depth,
                          int specular_depth, uint64_t key, RayDiff diff, float *t)
{
    float a, outer = w->time;
    w->time = ray->time;
    Vec3 L = trace_volumes(w, ray, kind, diffuse_depth, specular_depth, key, diff, t, &a, 0);
    w->time = outer;
    return L;
}
