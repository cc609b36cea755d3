/*
 * scene/displace.c — running displacement shaders on freshly diced grids
 * (DESIGN.md "Geometry"; decisions in docs/DESIGN.md "Displacement").
 *
 * The shader runs on every grid vertex and on four neighbours of each, a
 * small fixed world-space step away in u and in v on the undisplaced
 * surface (the step in parameter space is step / |dPdu|, at most half a
 * grid step). The displaced vertex is the vertex's result; its derivatives
 * are the central differences of the neighbours' results, and its normal
 * their cross product. So the normal is that of the displaced surface at
 * the vertex, computed the same way whichever grid the vertex belongs to
 * and whatever its dicing rate: neighbouring grids agree along their
 * shared edges (no shading seams), and a grid's boundary vertices need no
 * vertices of the grid next door.
 *
 * Each displacement is clamped to the primitive's displacement bound (if
 * any), with one warning per shader.
 */
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shade/builtin.h"
#include "util/log.h"

enum { SAMPLES = 5 }; /* the vertex, then u - h, u + h, v - h, v + h */

typedef struct Scratch {
    size_t cap;          /* points */
    float (*P)[3], (*N)[3], (*dPdu)[3], (*dPdv)[3], (*Cs)[3], (*Os)[3], (*out)[3];
    float *u, *v, *s, *t, *du, *dv;
    float *hu, *hv;      /* per vertex: the parameter steps of the differences */
    void *shader_scratch;
    size_t shader_scratch_size;
} Scratch;

static void scratch_free(Scratch *s)
{
    free(s->P), free(s->N), free(s->dPdu), free(s->dPdv), free(s->Cs), free(s->Os), free(s->out);
    free(s->u), free(s->v), free(s->s), free(s->t), free(s->du), free(s->dv);
    free(s->hu), free(s->hv);
    free(s->shader_scratch);
    memset(s, 0, sizeof *s);
}

static int scratch_reserve(Scratch *s, size_t n, size_t shader_bytes)
{
    if (n > s->cap) {
        scratch_free(s);
        s->P = malloc(n * sizeof *s->P), s->N = malloc(n * sizeof *s->N);
        s->dPdu = malloc(n * sizeof *s->dPdu), s->dPdv = malloc(n * sizeof *s->dPdv);
        s->Cs = malloc(n * sizeof *s->Cs), s->Os = malloc(n * sizeof *s->Os);
        s->out = malloc(n * sizeof *s->out);
        s->u = malloc(n * sizeof *s->u), s->v = malloc(n * sizeof *s->v);
        s->s = malloc(n * sizeof *s->s), s->t = malloc(n * sizeof *s->t);
        s->du = malloc(n * sizeof *s->du), s->dv = malloc(n * sizeof *s->dv);
        s->hu = malloc(n * sizeof *s->hu), s->hv = malloc(n * sizeof *s->hv);
        if (!s->P || !s->N || !s->dPdu || !s->dPdv || !s->Cs || !s->Os || !s->out || !s->u ||
            !s->v || !s->s || !s->t || !s->du || !s->dv || !s->hu || !s->hv)
            return -1;
        s->cap = n;
    }
    if (shader_bytes > s->shader_scratch_size) {
        free(s->shader_scratch);
        s->shader_scratch = malloc(shader_bytes);
        if (!s->shader_scratch)
            return -1;
        s->shader_scratch_size = shader_bytes;
    }
    return 0;
}

static void put3(float out[3], Vec3 v)
{
    out[0] = v.x, out[1] = v.y, out[2] = v.z;
}

static Vec3 get3(const float p[3])
{
    return v3(p[0], p[1], p[2]);
}

/* Half the parameter step between neighbouring vertices of g, in u and v. */
static void half_steps(const Grid *g, float *hu, float *hv)
{
    if (g->triangular) {
        float su = 0.0f, sv = 0.0f;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                su = fmaxf(su, fabsf(g->uv[a][0] - g->uv[b][0]));
                sv = fmaxf(sv, fabsf(g->uv[a][1] - g->uv[b][1]));
            }
        *hu = 0.5f * su / (float)g->nu;
        *hv = 0.5f * sv / (float)g->nu;
    } else {
        *hu = 0.5f * fabsf(g->uv[1][0] - g->uv[0][0]) / (float)(g->nu - 1);
        *hv = 0.5f * fabsf(g->uv[1][1] - g->uv[0][1]) / (float)(g->nv - 1);
    }
}

static int displace_grid(const RayesScene *s, GridSet *gs, Grid *g, float step,
                         const RayesShaderServices *sv, Scratch *sc)
{
    const Prim *prim = &s->prims[g->prim];
    const ShaderInstance *inst = &s->displacements[prim->displacement - 1];
    /* A master's inheriting geometry is displaced once for every instance:
     * it sees white Cs and Os (its instances' colours are not known here). */
    static const SceneObject white = {.Cs = {1, 1, 1}, .Os = {1, 1, 1}};
    const SceneObject *obj =
        prim->object == GEOM_OBJECT_INHERIT ? &white : &s->objects[prim->object];
    size_t n = geom_grid_n_vertices(g), m = SAMPLES * n;
    if (scratch_reserve(sc, m, m * inst->cls->scratch_size) != 0)
        return -1;
    float grid_hu, grid_hv;
    half_steps(g, &grid_hu, &grid_hv);
    static const float off[SAMPLES][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    float *hu = sc->hu, *hv = sc->hv;
    for (size_t k = 0; k < n; k++) {
        size_t vtx = g->first_vertex + k;
        float lu = v3_length(gs->dPdu[vtx]), lv = v3_length(gs->dPdv[vtx]);
        hu[k] = lu * grid_hu > step ? step / lu : grid_hu;
        hv[k] = lv * grid_hv > step ? step / lv : grid_hv;
    }
    for (size_t k = 0; k < n; k++) {
        size_t vtx = g->first_vertex + k;
        float hku = hu[k], hkv = hv[k];
        for (int q = 0; q < SAMPLES; q++) {
            size_t i = (size_t)q * n + k;
            float u = gs->uv[vtx][0] + off[q][0] * hku, v = gs->uv[vtx][1] + off[q][1] * hkv;
            Vec3 P, du, dv;
            geom_prim_eval(prim, u, v, &P, &du, &dv);
            put3(sc->P[i], q == 0 ? gs->P[vtx] : P);
            Vec3 N = q == 0 ? gs->N[vtx] : geom_prim_normal(prim, u, v);
            /* Primitive variables as the surface shader would see them:
             * displacing along a supplied normal keeps a smooth mesh
             * closed along its shared edges (as RenderMan's N). */
            PrimvarSample pv = {.N = N, .st = {u, v}, .Cs = get3(obj->Cs)};
            geom_prim_primvars(prim, s->pv, u, v, &pv);
            if (v3_length(pv.N) > 0.0f)
                N = v3_dot(pv.N, N) < 0.0f ? v3_neg(pv.N) : pv.N;
            put3(sc->N[i], N);
            put3(sc->dPdu[i], du);
            put3(sc->dPdv[i], dv);
            sc->u[i] = u, sc->v[i] = v;
            sc->s[i] = pv.st[0], sc->t[i] = pv.st[1];
            sc->du[i] = 2.0f * grid_hu, sc->dv[i] = 2.0f * grid_hv; /* the grid's spacing */
            put3(sc->Cs[i], pv.Cs);
            memcpy(sc->Os[i], obj->Os, sizeof obj->Os);
            memcpy(sc->out[i], sc->P[i], sizeof sc->out[i]);
        }
    }
    RayesShadeCtx ctx = {
        .n_points = m,
        .ray_type = RAYES_RAY_NONE,
        .P = (const float(*)[3])sc->P,
        .N = (const float(*)[3])sc->N,
        .Ng = (const float(*)[3])sc->N,
        .dPdu = (const float(*)[3])sc->dPdu,
        .dPdv = (const float(*)[3])sc->dPdv,
        .u = sc->u,
        .v = sc->v,
        .s = sc->s,
        .t = sc->t,
        .du = sc->du,
        .dv = sc->dv,
        .Cs = (const float(*)[3])sc->Cs,
        .Os = (const float(*)[3])sc->Os,
        .scratch = inst->cls->scratch_size ? sc->shader_scratch : NULL,
        .patterns = inst->patterns,
        .n_patterns = inst->n_patterns,
    };
    RayesShadeOutputs out = {.P = sc->out};
    inst->cls->displacement(sv, &ctx, inst->params, &out);
    float bound = prim->displacement_bound;
    for (size_t i = 0; i < m; i++) {
        Vec3 d = v3_sub(get3(sc->out[i]), get3(sc->P[i]));
        float len = v3_length(d);
        if (!isfinite(len)) {
            memcpy(sc->out[i], sc->P[i], sizeof sc->out[i]); /* a NaN stays where it was */
            continue;
        }
        if (bound > 0.0f && len > bound) {
            char key[96];
            snprintf(key, sizeof key, "displacementbound:%s", inst->cls->name);
            log_warning_once(key,
                             "displacement shader \"%s\" moves points %g units, beyond the "
                             "displacement bound %g; clamped",
                             inst->cls->name, (double)len, (double)bound);
            put3(sc->out[i], v3_madd(get3(sc->P[i]), d, bound / len));
        }
    }
    if (inst->bump && geom_gridset_want_primvars(gs, GEOM_PV_N) != 0)
        return -1;
    for (size_t k = 0; k < n; k++) {
        size_t vtx = g->first_vertex + k;
        Vec3 du = v3_scale(v3_sub(get3(sc->out[2 * n + k]), get3(sc->out[n + k])), 0.5f / hu[k]);
        Vec3 dv = v3_scale(v3_sub(get3(sc->out[4 * n + k]), get3(sc->out[3 * n + k])), 0.5f / hv[k]);
        Vec3 N = v3_cross(du, dv);
        float scale = v3_length(du) * v3_length(dv);
        if (inst->bump) { /* the normal bends, the surface stays (a bump map) */
            Vec3 Ns = scale > 0.0f && v3_length(N) > 1e-6f * scale ? v3_normalize(N) : gs->N[vtx];
            gs->Ns[vtx] = v3_dot(Ns, gs->N[vtx]) < 0.0f ? v3_neg(Ns) : Ns;
            continue;
        }
        gs->P[vtx] = get3(sc->out[k]);
        if (scale > 0.0f && v3_length(N) > 1e-6f * scale) {
            gs->N[vtx] = v3_normalize(N);
            gs->dPdu[vtx] = du;
            gs->dPdv[vtx] = dv;
        } /* else a degenerate point (a pole): keep the undisplaced frame */
    }
    if (inst->bump) { /* the bent normals are the grid's shading normals */
        g->primvars |= GEOM_PV_N;
        return 0;
    }
    g->primvars &= (uint8_t)~GEOM_PV_N; /* the displaced surface's normals replace N */
    geom_grid_measure(gs, g);
    return 0;
}

int scene_displace(const RayesScene *s, GridSet *gs, size_t first_grid, float step,
                   const RayesShaderServices *sv)
{
    Scratch sc = {0};
    int status = 0;
    for (size_t i = first_grid; i < gs->n_grids && status == 0; i++)
        if (s->prims[gs->grids[i].prim].displacement)
            status = displace_grid(s, gs, &gs->grids[i], step, sv, &sc);
    scratch_free(&sc);
    return status;
}
