/*
 * render/radiosity.c — the multiresolution radiosity cache at diffuse-ray
 * hits (memo sections 3.2 and 4.3).
 *
 * The same fills serve the irradiance cache of subsurface rays (memo 6.2,
 * subsurface.c): entries of data type irradiance at depth 0 for the side
 * the ray leaves through, filled by diffuselighting's Irradiance output.
 *
 * At a diffuse hit the resolution is chosen from the ray's footprint (the
 * coarsest level whose micropolygon edge is at most k times the footprint,
 * DESIGN.md, and bends through at most RADIOSITY_MAX_BEND), the entry for (patch, diffuse depth,
 * side, RADIOSITY, level) is looked up, and on a miss filled by running prelighting and
 * diffuselighting on every vertex of the grid at that level; the hit's value
 * is interpolated: bilinear in the quad cell, barycentric in the triangle.
 * Coarser still, for radiosity and irradiance on an opaque object: the
 * clusters of tiny grids (geom/cluster.c), one value each, keyed by patch
 * n_grids + the cluster's index (volume.c's bricks use the same range for
 * opacity, a type clusters never have).
 *
 * Level layouts, per grid:
 *   quad FINE    all nu x nv vertices, in vertex order;
 *   quad MEDIUM  knots 0, 4, 8, ... and the last, in u and in v (memo Fig. 2);
 *   quad COARSE  the 4 corners;
 *   tri  FINE    all vertices of the n-subdivision lattice;
 *   tri  MEDIUM  the lattice of m = ceil(n / 4) subdivisions, its points
 *                interpolated on the fine grid (exact vertices when 4 | n);
 *   tri  COARSE  the 3 corners.
 * A MEDIUM layout with the same points as FINE or COARSE is aliased to that
 * level (no duplicate entries).
 *
 * A fill's random numbers depend only on the key and the render seed, so an
 * evicted entry refills to the same bytes and images do not depend on the
 * cache size or on threads.
 */
#include "render/radiosity.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/optable.h"
#include "util/check.h"
#include "util/half.h"
#include "util/rng.h"

/* Knots of the medium level along a side of n fine vertices. */
static int medium_knots(int n)
{
    return (n - 1 + 3) / 4 + 1; /* 0, 4, ..., and n - 1 */
}

static int medium_knot(int k, int n) /* fine index of knot k */
{
    return RY_MIN(4 * k, n - 1);
}

static int tri_medium_m(int n)
{
    return (n + 3) / 4;
}

/* Points per side of a quad level along a side of n fine vertices, and the
 * fine index of its k-th point. */
static int quad_level_points(int level, int n)
{
    return level == CACHE_FINE ? n : level == CACHE_MEDIUM ? medium_knots(n) : 2;
}

static int quad_level_index(int level, int k, int n)
{
    return level == CACHE_FINE ? k : medium_knot(k, n);
}

/* The coarse level's points are the middles of the grid's corner cells
 * after one midpoint split: a quad grid's quadrants, at a quarter and
 * three quarters of each side, a triangular grid's corner triangles, at
 * barycentric 2/3, 1/6, 1/6. The memo shades the patch's corners; but a
 * mesh's corners lie where its surface meets another (a wall's at the
 * floor, at a window's frame), and four values from those rims stood for
 * the whole patch: on the benchmark's box the worst 32 x 32 tile at 3
 * bounces was 2.66% from the uncached image, 1.28% with these points, and
 * on a classroom lit through windows the coarse level was 1.9% bright, 0.8%
 * with them (DESIGN.md "The radiosity cache"). Between the points values
 * are bilinear (barycentric); toward the rim they are held, never
 * extrapolated. */
#define COARSE_INSET 0.25f
#define COARSE_SPAN (1.0f - 2.0f * COARSE_INSET) /* the points' span, of the grid's */

/* Subdivisions of a triangular level of a grid of n subdivisions; 0: one
 * value, at the centroid. A grid of one micropolygon (a dense mesh's
 * face, its own grid) has its corners as its fine level, and as its
 * coarse level its centroid, read as a constant: its corners would fill
 * three shading points where the hit alone needs one, and such grids are
 * seldom hit twice (a mesh of 2 million triangles: the coarse level's
 * hit rate 9%, 2.8 times the uncached render's shading points at depth
 * 1, and slower than no cache). The coarse level is chosen only when the
 * ray's footprint covers the micropolygon (radiosity_choose_level). */
static int tri_level_m(int level, int n)
{
    return level == CACHE_FINE ? n : level == CACHE_MEDIUM ? tri_medium_m(n) : n == 1 ? 0 : 1;
}

/* The level actually stored for a requested one (aliasing MEDIUM). */
static int effective_level(const Grid *g, int level)
{
    if (level != CACHE_MEDIUM)
        return level;
    if (g->triangular) {
        int m = tri_medium_m(g->nu);
        return m == g->nu ? CACHE_FINE : m == 1 ? CACHE_COARSE : CACHE_MEDIUM;
    }
    int mu = medium_knots(g->nu), mv = medium_knots(g->nv);
    if (mu == g->nu && mv == g->nv)
        return CACHE_FINE;
    if (mu == 2 && mv == 2)
        return CACHE_COARSE;
    return CACHE_MEDIUM;
}

static size_t level_values(const Grid *g, int level)
{
    if (g->triangular) {
        size_t n = (size_t)tri_level_m(level, g->nu);
        return (n + 1) * (n + 2) / 2;
    }
    return (size_t)quad_level_points(level, g->nu) * (size_t)quad_level_points(level, g->nv);
}

/* Micropolygon edge of a level: the grid's mean edge times the longer
 * side of the level's cell in fine edges. (The longer side, not the mean
 * of the two: grids of RenderMan's gridsize are often 2:1, and a 10 x 20
 * grid's coarse cell spans 20 edges. Bilinear interpolation of a peaked
 * radiosity, like the floor under the light, undershoots by about h^2/8
 * of its curvature over a cell of side h; measured on the box at 3
 * bounces, the worst 32 x 32 tile against the uncached image went from
 * 2.86% with the mean to 2.23% with the longer side.) */
static float level_edge(const Grid *g, int level)
{
    if (level == CACHE_FINE)
        return g->edge;
    if (g->triangular) {
        float n = g->nu;
        return g->edge * (level == CACHE_MEDIUM ? n / (float)tri_medium_m(g->nu) : n);
    }
    float su = g->nu - 1, sv = g->nv - 1;
    if (level == CACHE_COARSE)
        return g->edge * fmaxf(su, sv);
    return g->edge *
           fmaxf(su / (float)(medium_knots(g->nu) - 1), sv / (float)(medium_knots(g->nv) - 1));
}

/* The largest angle (radians) a level's micropolygon may bend through,
 * edge x the grid's curvature. Radiosity on a curved surface follows the
 * cosine of its normal to the light, which bilinear interpolation across a
 * strongly bent cell undershoots: on the benchmark's matte teapot the coarse
 * level alone darkened the ceiling above it by 3% (measured, 64 spp). 0.5
 * brings that under 1% for 0.5% more shading points. */
#define RADIOSITY_MAX_BEND 0.5f

int radiosity_choose_level(const Grid *g, float footprint, float k, int forced)
{
    if (forced >= 0)
        return effective_level(g, forced);
    for (int level = CACHE_COARSE; level < CACHE_FINE; level++) {
        float edge = level_edge(g, level);
        if (edge <= k * footprint && edge * g->curvature <= RADIOSITY_MAX_BEND)
            return effective_level(g, level);
    }
    return CACHE_FINE;
}

uint32_t radiosity_choose_cluster(const GridSet *gs, uint32_t grid, float footprint, float k)
{
    uint32_t best = 0;
    if (!gs->grid_cluster)
        return 0;
    for (uint32_t c = gs->grid_cluster[grid]; c; c = gs->clusters[c - 1].parent) {
        if (gs->clusters[c - 1].edge > k * footprint)
            break;
        best = c;
    }
    return best;
}

/* --------------------------------------------------------------- fills */

typedef struct FillJob {
    Worker *w;
    uint32_t grid;
} FillJob;

/* Barycentric sample of a triangular fine grid at lattice coordinates
 * (x, y), 0 <= x, y, x + y <= n: its three vertices and weights. */
static void tri_cell(int n, float x, float y, int vi[3][2], float wt[3])
{
    int i = RY_MIN((int)floorf(x), n - 1), j = RY_MIN((int)floorf(y), n - 1);
    i = RY_MAX(i, 0);
    j = RY_MAX(j, 0);
    if (i + j > n - 1) { /* on the last diagonal: step back into a cell */
        if (i > 0)
            i = n - 1 - j;
        else
            j = n - 1 - i;
    }
    float fx = x - (float)i, fy = y - (float)j;
    if (fx + fy <= 1.0f || i + j + 1 > n - 1) {
        int v[3][2] = {{i, j}, {i + 1, j}, {i, j + 1}};
        float w[3] = {1.0f - fx - fy, fx, fy};
        memcpy(vi, v, sizeof v);
        memcpy(wt, w, sizeof w);
    } else {
        int v[3][2] = {{i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
        float w[3] = {1.0f - fy, fx + fy - 1.0f, 1.0f - fx};
        memcpy(vi, v, sizeof v);
        memcpy(wt, w, sizeof w);
    }
}

typedef struct FillPoints {
    float (*P)[3], (*N)[3], (*Ng)[3], (*dPdu)[3], (*dPdv)[3], (*Cs)[3], (*Os)[3], (*Ci)[3];
    float (*Oi)[3];
    float *u, *v, *s, *t, (*dst)[4], *du, *dv, *ds, *dt, *curv, *offset;
    uint64_t *keys;
    RayDiff *diff;
} FillPoints;

/* Point p of the fill takes fine vertices vtx[0..n) with weights wt; its
 * colour and opacity are the object's unless the grid has its own. */
static void put_point(const GridSet *gs, const Grid *g, FillPoints *fp, size_t p,
                      const uint32_t *vtx, const float *wt, int nv, int side,
                      const RenderObject *obj, const GeomInstance *gi, int segment)
{
    Vec3 P = v3(0, 0, 0), N = P, Ng = P, du = P, dv = P, Cs = P, Os = P;
    Vec3 Cs_obj = v3_load(obj->Cs), Os_obj = v3_load(obj->Os);
    float u = 0.0f, v = 0.0f, st[2] = {0, 0}, dst[4] = {0, 0, 0, 0};
    for (int k = 0; k < nv; k++) {
        uint32_t i = g->first_vertex + vtx[k];
        float sti[2], dsti[4];
        GeomVertex gv = geom_vertex_at(gs, g, i, segment, 0.5f); /* the segment's middle */
        P = v3_madd(P, gv.P, wt[k]);
        N = v3_madd(N, (g->primvars & GEOM_PV_N) ? gs->Ns[i] : gv.N, wt[k]);
        Ng = v3_madd(Ng, gv.N, wt[k]);
        du = v3_madd(du, gv.dPdu, wt[k]);
        dv = v3_madd(dv, gv.dPdv, wt[k]);
        u += gs->uv[i][0] * wt[k];
        v += gs->uv[i][1] * wt[k];
        Cs = v3_madd(Cs, geom_vertex_color(gs, g, i, Cs_obj), wt[k]);
        Os = v3_madd(Os, geom_vertex_opacity(gs, g, i, Os_obj), wt[k]);
        geom_vertex_st(gs, g, i, sti, dsti);
        st[0] += sti[0] * wt[k], st[1] += sti[1] * wt[k];
        for (int c = 0; c < 4; c++)
            dst[c] += dsti[c] * wt[k];
    }
    if (gi) { /* a master's grid through an instance: to world space */
        P = mat4_point(&gi->world_from_master, P);
        N = mat4_vector(&gi->normal_to_world, N);
        Ng = mat4_vector(&gi->normal_to_world, Ng);
        du = mat4_vector(&gi->world_from_master, du);
        dv = mat4_vector(&gi->world_from_master, dv);
    }
    N = v3_normalize(N);
    Ng = v3_normalize(Ng);
    if (side)
        N = v3_neg(N), Ng = v3_neg(Ng);
    memcpy(fp->P[p], &P, sizeof fp->P[p]);
    memcpy(fp->N[p], &N, sizeof fp->N[p]);
    memcpy(fp->Ng[p], &Ng, sizeof fp->Ng[p]);
    memcpy(fp->Cs[p], &Cs, sizeof fp->Cs[p]);
    memcpy(fp->Os[p], &Os, sizeof fp->Os[p]);
    fp->s[p] = st[0], fp->t[p] = st[1];
    memcpy(fp->dst[p], dst, sizeof dst);
    memcpy(fp->dPdu[p], &du, sizeof fp->dPdu[p]);
    memcpy(fp->dPdv[p], &dv, sizeof fp->dPdv[p]);
    fp->u[p] = u;
    fp->v[p] = v;
}

/* A ray-facing shape's fill points through an instance: their normals
 * face the eye from this instance (the master's, diced for another
 * instance's view, need not), turned for side 1 as put_point turns them. */
static void face_instance_eye(const Camera *cam, int shape, int side, size_t n, FillPoints *fp)
{
    for (size_t p = 0; p < n; p++) {
        Vec3 P = v3_load(fp->P[p]), Ng = v3_load(fp->Ng[p]);
        Vec3 N = render_facing(render_view_toward(cam, P), v3_load(fp->dPdu[p]), shape,
                               side ? v3_neg(Ng) : Ng);
        if (side)
            N = v3_neg(N);
        v3_store(fp->N[p], N);
        v3_store(fp->Ng[p], N);
    }
}

/* Positions of the level's points on the fine grid. */
static void layout_points(const GridSet *gs, const Grid *g, int level, int side,
                          const RenderObject *obj, const GeomInstance *gi, int segment,
                          FillPoints *fp)
{
    size_t p = 0;
    if (!g->triangular) {
        int nu = g->nu, nv = g->nv;
        int mu = quad_level_points(level, nu), mv = quad_level_points(level, nv);
        for (int j = 0; j < mv; j++)
            for (int i = 0; i < mu; i++) {
                if (level == CACHE_COARSE) { /* bilinear between fine vertices */
                    float x = (i ? 1.0f - COARSE_INSET : COARSE_INSET) * (float)(nu - 1);
                    float y = (j ? 1.0f - COARSE_INSET : COARSE_INSET) * (float)(nv - 1);
                    int i0 = RY_MAX(RY_MIN((int)x, nu - 2), 0),
                        j0 = RY_MAX(RY_MIN((int)y, nv - 2), 0);
                    int i1 = RY_MIN(i0 + 1, nu - 1), j1 = RY_MIN(j0 + 1, nv - 1);
                    float fx = x - (float)i0, fy = y - (float)j0;
                    uint32_t vtx[4] = {(uint32_t)(j0 * nu + i0), (uint32_t)(j0 * nu + i1),
                                       (uint32_t)(j1 * nu + i0), (uint32_t)(j1 * nu + i1)};
                    float wt[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
                    put_point(gs, g, fp, p++, vtx, wt, 4, side, obj, gi, segment);
                    continue;
                }
                int fi = quad_level_index(level, i, nu), fj = quad_level_index(level, j, nv);
                uint32_t vtx = (uint32_t)(fj * nu + fi);
                float one = 1.0f;
                put_point(gs, g, fp, p++, &vtx, &one, 1, side, obj, gi, segment);
            }
        return;
    }
    int n = g->nu;
    int m = tri_level_m(level, n);
    if (m == 0) { /* the centroid */
        const uint32_t corners[3] = {geom_tri_vertex(1, 0, 0), geom_tri_vertex(1, 1, 0),
                                     geom_tri_vertex(1, 0, 1)};
        const float third[3] = {1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f};
        put_point(gs, g, fp, 0, corners, third, 3, side, obj, gi, segment);
        return;
    }
    for (int j = 0; j <= m; j++)
        for (int i = 0; i + j <= m; i++) {
            int vi[3][2];
            float wt[3], x = (float)i * n / m, y = (float)j * n / m, c = (float)n / 3.0f;
            if (level == CACHE_COARSE) /* halfway from the centroid to the corner */
                x = c + (x - c) * COARSE_SPAN, y = c + (y - c) * COARSE_SPAN;
            tri_cell(n, x, y, vi, wt);
            uint32_t vtx[3];
            for (int k = 0; k < 3; k++)
                vtx[k] = geom_tri_vertex((uint32_t)n, (uint32_t)vi[k][0], (uint32_t)vi[k][1]);
            put_point(gs, g, fp, p++, vtx, wt, 3, side, obj, gi, segment);
        }
}

/* A tiny grid's middle, the one point of its cluster's fill: the centroid
 * of a triangular grid, the middle of a quad grid's vertices (bilinear
 * between the nearest). */
static void middle_point(const GridSet *gs, const Grid *g, int side, const RenderObject *obj,
                         const GeomInstance *gi, int segment, FillPoints *fp)
{
    uint32_t vtx[4];
    float wt[4];
    int nv;
    if (g->triangular) {
        int vi[3][2];
        float n = (float)g->nu;
        tri_cell(g->nu, n / 3.0f, n / 3.0f, vi, wt);
        for (int k = 0; k < 3; k++)
            vtx[k] = geom_tri_vertex(g->nu, (uint32_t)vi[k][0], (uint32_t)vi[k][1]);
        nv = 3;
    } else {
        int i0 = (g->nu - 1) / 2, j0 = (g->nv - 1) / 2, i1 = g->nu / 2, j1 = g->nv / 2;
        uint32_t nu = g->nu;
        vtx[0] = (uint32_t)(j0 * nu + i0), vtx[1] = (uint32_t)(j0 * nu + i1);
        vtx[2] = (uint32_t)(j1 * nu + i0), vtx[3] = (uint32_t)(j1 * nu + i1);
        wt[0] = wt[1] = wt[2] = wt[3] = 0.25f;
        nv = 4;
    }
    put_point(gs, g, fp, 0, vtx, wt, nv, side, obj, gi, segment);
}

/* Moves each point toward the middle of its level's points, along its
 * surface, by twice its ray offset. A vertex on a grid's rim may lie in
 * another surface's plane (a floor's edge against a wall): its rays toward
 * that surface would start on it and, found at t = 0 or not at all, leave
 * the room through it; moved off the line, they meet the wall as a point
 * beside the edge does. Every bounce of a closed room lost light at its
 * corners that way (4 bounces in a white box: 15% dark, DESIGN.md). */
static void nudge_inward(FillPoints *fp, size_t n)
{
    if (n < 2)
        return;
    Vec3 c = v3(0, 0, 0);
    for (size_t i = 0; i < n; i++)
        c = v3_add(c, v3_load(fp->P[i]));
    c = v3_scale(c, 1.0f / (float)n);
    for (size_t i = 0; i < n; i++) {
        Vec3 P = v3_load(fp->P[i]), Ng = v3_load(fp->Ng[i]), d = v3_sub(c, P);
        d = v3_sub(d, v3_scale(Ng, v3_dot(d, Ng))); /* along the surface */
        float len = v3_length(d), step = fminf(2.0f * fp->offset[i], 0.5f * len);
        if (len > 0.0f && step > 0.0f) {
            P = v3_madd(P, d, step / len);
            memcpy(fp->P[i], &P, sizeof fp->P[i]);
        }
    }
}

/* The parameter footprint of a level's points: its mean knot spacing in the
 * primitive's (u, v) (triangles: the widest extent of the patch's corners
 * in u and in v over the level's subdivisions). */
static void level_footprint(const Grid *g, int level, float *du, float *dv)
{
    if (!g->triangular) {
        int mu = quad_level_points(level, g->nu), mv = quad_level_points(level, g->nv);
        *du = fabsf(g->uv[1][0] - g->uv[0][0]) / (float)RY_MAX(mu - 1, 1);
        *dv = fabsf(g->uv[1][1] - g->uv[0][1]) / (float)RY_MAX(mv - 1, 1);
        return;
    }
    float m = (float)RY_MAX(tri_level_m(level, g->nu), 1), ext[2] = {0.0f, 0.0f};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 2; c++)
            ext[c] = fmaxf(ext[c], fabsf(g->uv[a][c] - g->uv[(a + 1) % 3][c]));
    *du = ext[0] / m;
    *dv = ext[1] / m;
}

/* Runs the shader's method for the fill's data type on ctx's points into
 * out: diffuselighting's Ci (radiosity), the opacity method's Oi
 * (opacity), or diffuselighting's Irradiance (irradiance: subsurface rays
 * at depth 0, memo 6.2; 0 where the shader leaves it). */
static void fill_run(Worker *w, int type, const RayesShadeCtx *ctx, const RenderObject *obj,
                     FillPoints *fp, float (*E)[3], float (*out)[3])
{
    size_t n = ctx->n_points;
    RayesShadeOutputs o = {fp->Ci, fp->Oi, NULL, NULL};
    if (type == CACHE_OPACITY) {
        w->stats.opacity_points += n;
        shade_run_opacity(w->services, ctx, obj->shader, &o);
        memcpy(out, fp->Oi, n * sizeof *out);
    } else if (type == CACHE_IRRADIANCE) {
        w->stats.irradiance_points += n;
        memset(E, 0, n * sizeof *E);
        o.Irradiance = E;
        ((PathState *)ctx->renderer)->irradiance = E;
        shade_run_diffuselighting(w->services, ctx, obj->shader, &o);
        memcpy(out, E, n * sizeof *out);
    } else {
        w->stats.shading_points[RY_MIN(ctx->diffuse_depth, RENDER_MAX_DEPTH)] += n;
        shade_run_diffuselighting(w->services, ctx, obj->shader, &o);
        memcpy(out, fp->Ci, n * sizeof *out);
    }
}

/* The ray type a fill's shader sees. */
static uint32_t fill_ray_type(int type)
{
    return type == CACHE_OPACITY      ? RAYES_RAY_TRANSMISSION
           : type == CACHE_IRRADIANCE ? RAYES_RAY_SUBSURFACE
                                      : RAYES_RAY_DIFFUSE;
}

/* CacheFillFn: shade every point of the level with diffuselighting
 * (radiosity: Ci; irradiance: Irradiance) or the opacity method (opacity:
 * Oi, transmission rays at depth 0, the front side). */
static void fill_radiosity(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    FillJob *job = user;
    Worker *w = job->w;
    const GridSet *gs = w->rs->gs;
    /* A cluster's one value is shaded at the middle of its member nearest
     * its own (keys past the grids name clusters: cached_at_hit). */
    const GeomCluster *cl =
        key->patch >= gs->n_grids ? &gs->clusters[key->patch - gs->n_grids] : NULL;
    RY_DCHECK(!cl || (key->type != CACHE_OPACITY && key->patch - gs->n_grids < gs->n_clusters));
    uint32_t grid = cl ? cl->rep : key->patch;
    const Grid *g = &gs->grids[grid];
    const RenderObject *obj = render_object(w->rs, grid, key->instance);
    const GeomInstance *gi = render_instance(w->rs, key->instance);
    /* A grid seen through a moving instance moves too: filled per segment,
     * at the segment's middle, the instance where it is then. */
    int moves = g->moving || (gi && gi->motion && gs->n_times > 1);
    GeomInstance moved;
    if (gi && gi->motion)
        gi = geom_instance_at(gs, gi, geom_segment_mid_time(gs, key->segment), &moved);
    float scale = gi ? gi->scale : 1.0f; /* world units per grid unit */
    FillPoints fp;
    float(*f3)[3] = malloc(n * 10 * sizeof *f3);
    float *f1 = malloc(n * 14 * sizeof *f1);
    fp.keys = malloc(n * sizeof *fp.keys);
    fp.diff = malloc(n * sizeof *fp.diff);
    int *backfacing = malloc(n * sizeof *backfacing);
    RY_CHECK(f3 && f1 && fp.keys && fp.diff && backfacing);
    fp.P = f3, fp.N = f3 + n, fp.dPdu = f3 + 2 * n, fp.dPdv = f3 + 3 * n;
    fp.Cs = f3 + 4 * n, fp.Os = f3 + 5 * n, fp.Ci = f3 + 6 * n, fp.Oi = f3 + 7 * n;
    fp.Ng = f3 + 8 * n;
    fp.u = f1, fp.v = f1 + n, fp.du = f1 + 2 * n, fp.dv = f1 + 3 * n, fp.curv = f1 + 4 * n;
    fp.offset = f1 + 5 * n, fp.s = f1 + 6 * n, fp.t = f1 + 7 * n, fp.ds = f1 + 8 * n;
    fp.dt = f1 + 9 * n, fp.dst = (float(*)[4])(f1 + 10 * n);
    if (cl)
        middle_point(gs, g, key->side, obj, gi, key->segment, &fp);
    else
        layout_points(gs, g, key->level, key->side, obj, gi, key->segment, &fp);
    if (gi && render_faces_ray(g->shape))
        face_instance_eye(&w->rs->camera, g->shape, key->side, n, &fp);
    uint64_t fill_key = hash_combine(hash_combine(w->set->seed, 0x7261646f73ull /* "rados" */),
                                     ((uint64_t)key->patch << 32) | ((uint64_t)key->depth << 16) |
                                         ((uint64_t)key->side << 8) | key->level);
    if (key->type == CACHE_IRRADIANCE) /* apart from the radiosity fill of the same grid */
        fill_key = hash_combine(fill_key, 0x69727261ull /* "irra" */);
    if (key->instance) /* each instance its own numbers; uninstanced keys as before */
        fill_key = hash_combine(fill_key, key->instance);
    if (key->segment)
        fill_key = hash_combine(fill_key, key->segment);
    /* A moving grid is shaded at its segment's middle, a still one at the
     * shutter's: its rays leave then, whichever ray's lookup filled it
     * (DESIGN.md "Motion blur"). */
    float outer_time = w->time, outer_split = w->split;
    const RenderObject *outer_shading = w->shading;
    int outer_depth = w->depth;
    const Camera *cam = &w->rs->camera;
    w->split = 1.0f; /* a fill is the same whichever path asked */
    /* and as the grid's own object, whoever asked: a fill asked for by a
     * glass's refraction ray found that glass opaque to its shadow rays (a
     * floor seen through a pane was black, and the cache kept it) */
    w->shading = obj;
    w->depth = key->depth;
    w->time = moves ? geom_segment_mid_time(gs, key->segment)
                    : 0.5f * (cam->shutter[0] + cam->shutter[1]);
    float width = level_edge(g, key->level) * scale, du, dv;
    level_footprint(g, key->level, &du, &dv);
    if (cl) { /* the member's footprint, grown to the cluster's */
        float grow = cl->edge / fmaxf(level_edge(g, CACHE_COARSE), 1e-30f);
        width = cl->edge * scale;
        du *= fmaxf(grow, 1.0f), dv *= fmaxf(grow, 1.0f);
    }
    for (size_t i = 0; i < n; i++) {
        fp.du[i] = du;
        fp.dv[i] = dv;
        path_st_footprint(fp.dst[i], du, dv, &fp.ds[i], &fp.dt[i]);
        fp.curv[i] = g->curvature / scale;
        fp.offset[i] = path_ray_offset_in(w, g, key->instance);
        fp.keys[i] = hash_combine(fill_key, i);
        fp.diff[i] = (RayDiff){width, 0.0f};
        backfacing[i] = key->side != 0; /* side 1: against dPdu x dPdv */
    }
    /* Not irradiance: its fills' light comes by shadow rays, not diffuse
     * rays into a neighbouring wall, and moved points misplaced it along a
     * subsurface object's terminator (bench/figure10, the teapot alone:
     * worst tile 5.25% moved, 2.28% not; DESIGN.md) */
    if (key->type != CACHE_IRRADIANCE)
        nudge_inward(&fp, n);
    int own_st = (g->primvars & GEOM_PV_ST) != 0;
    PathState ps = {w, fp.keys, fp.diff, fp.curv, fp.offset, NULL, grid, own_st ? fp.ds : NULL,
                    own_st ? fp.dt : NULL, 0, NULL, key->instance,
                    /* irradiance is shared by every subsurface ray near it: more
                     * light samples than a camera hit's (DESIGN.md) */
                    key->type == CACHE_IRRADIANCE ? w->set->irradiance_shadow_rays : 0};
    RayesShadeCtx ctx = {
        .n_points = n,
        .ray_type = fill_ray_type(key->type),
        .diffuse_depth = key->depth,
        .specular_depth = 0,
        .P = (const float(*)[3])fp.P,
        .N = (const float(*)[3])fp.N,
        .Ng = (const float(*)[3])fp.Ng,
        .dPdu = (const float(*)[3])fp.dPdu,
        .dPdv = (const float(*)[3])fp.dPdv,
        .u = fp.u,
        .v = fp.v,
        .s = fp.s,
        .t = fp.t,
        .du = fp.du,
        .dv = fp.dv,
        .I = NULL,
        .Cs = (const float(*)[3])fp.Cs,
        .Os = (const float(*)[3])fp.Os,
        .renderer = &ps,
        .backfacing = backfacing,
        .dst = own_st ? (const float(*)[4])fp.dst : NULL,
    };
    path_apply_Os_pattern(w, obj, &ctx, fp.Os);
    if (key->type == CACHE_RADIOSITY) {
        size_t holes = path_count_holes(obj, n, (const float(*)[3])fp.Os);
        ps.holes = holes > 0;
        w->stats.hole_points += holes;
    }
    w->stats.instance_fills += key->instance != 0 && key->type == CACHE_RADIOSITY;
    if (moves && key->type == CACHE_RADIOSITY)
        w->stats.segment_fills[key->segment]++;
    fill_run(w, key->type, &ctx, obj, &fp, f3 + 9 * n, out);
    w->time = outer_time;
    w->split = outer_split;
    w->shading = outer_shading;
    w->depth = outer_depth;
    free(f3);
    free(f1);
    free(fp.keys);
    free(fp.diff);
    free(backfacing);
}

void radiosity_shade_grid(Worker *w, uint32_t grid, uint32_t instance, int depth, int side,
                          float (*out)[3])
{
    const Grid *g = &w->rs->gs->grids[grid];
    CacheKey key = {.patch = grid, .instance = instance, .depth = (uint16_t)depth,
                    .side = (uint8_t)side, .type = CACHE_RADIOSITY, .level = CACHE_FINE};
    FillJob job = {w, grid};
    fill_radiosity(&job, &key, level_values(g, CACHE_FINE), out);
}

int radiosity_patch_points(Worker *w, uint32_t patch, uint32_t instance, int side, Vec3 P[4],
                           Vec3 N[4], float *offset)
{
    const GridSet *gs = w->rs->gs;
    int cluster = patch >= gs->n_grids;
    uint32_t grid = cluster ? gs->clusters[patch - gs->n_grids].rep : patch;
    const Grid *g = &gs->grids[grid];
    size_t n = cluster ? 1 : level_values(g, CACHE_COARSE); /* 4, 3 or 1 */
    RY_CHECK(n >= 1 && n <= 4);
    float f3[9][4][3], f1[10][4], dst[4][4];
    uint64_t keys[4];
    RayDiff diff[4];
    FillPoints fp = {.P = f3[0],
                     .N = f3[1],
                     .Ng = f3[2],
                     .dPdu = f3[3],
                     .dPdv = f3[4],
                     .Cs = f3[5],
                     .Os = f3[6],
                     .Ci = f3[7],
                     .Oi = f3[8],
                     .u = f1[0],
                     .v = f1[1],
                     .s = f1[2],
                     .t = f1[3],
                     .dst = dst,
                     .du = f1[4],
                     .dv = f1[5],
                     .ds = f1[6],
                     .dt = f1[7],
                     .curv = f1[8],
                     .offset = f1[9],
                     .keys = keys,
                     .diff = diff};
    const RenderObject *obj = render_object(w->rs, grid, instance);
    const GeomInstance *gi = render_instance(w->rs, instance);
    if (cluster)
        middle_point(gs, g, side, obj, gi, 0, &fp);
    else
        layout_points(gs, g, CACHE_COARSE, side, obj, gi, 0, &fp);
    for (size_t i = 0; i < n; i++) {
        P[i] = v3_load(fp.P[i]);
        N[i] = v3_load(fp.Ng[i]);
    }
    *offset = path_ray_offset_in(w, g, instance);
    return (int)n;
}

/* -------------------------------------------------------- interpolation */

static Vec3 value(const uint16_t *vals, size_t i)
{
    /* the cache stores finite halves only (it clamps, and NaN is 0) */
    return v3(half_to_float_finite(vals[3 * i]), half_to_float_finite(vals[3 * i + 1]),
              half_to_float_finite(vals[3 * i + 2]));
}

/* Bilinear at (x, y) in knot-grid coordinates of an mu x mv lattice. */
static Vec3 bilinear(const uint16_t *vals, int mu, int mv, float x, float y)
{
    int i = RY_MAX(RY_MIN((int)x, mu - 2), 0), j = RY_MAX(RY_MIN((int)y, mv - 2), 0);
    float fx = fminf(fmaxf(x - i, 0.0f), 1.0f), fy = fminf(fmaxf(y - j, 0.0f), 1.0f);
    float lo[6], hi[6]; /* knots i and i + 1 of rows j and j + 1: adjacent values */
    half_to_float_finite_x6(vals + 3 * ((size_t)j * mu + i), lo);
    half_to_float_finite_x6(vals + 3 * ((size_t)(j + 1) * mu + i), hi);
    Vec3 a = v3_lerp(v3(lo[0], lo[1], lo[2]), v3(lo[3], lo[4], lo[5]), fx);
    Vec3 b = v3_lerp(v3(hi[0], hi[1], hi[2]), v3(hi[3], hi[4], hi[5]), fx);
    return v3_lerp(a, b, fy);
}

/* Knot-grid coordinate of fine index position x along n vertices. */
static float medium_coord(float x, int n)
{
    int m = medium_knots(n);
    int k = RY_MIN((int)(x / 4.0f), m - 2);
    int a = medium_knot(k, n), b = medium_knot(k + 1, n);
    return (float)k + (x - (float)a) / (float)(b - a);
}

Vec3 radiosity_interpolate(const Grid *g, const Hit *hit, int level, const uint16_t *vals)
{
    if (!g->triangular) {
        float x = hit->gu * (g->nu - 1), y = hit->gv * (g->nv - 1);
        if (level == CACHE_FINE)
            return bilinear(vals, g->nu, g->nv, x, y);
        if (level == CACHE_COARSE) /* bilinear clamps beyond the points */
            return bilinear(vals, 2, 2, (hit->gu - COARSE_INSET) / COARSE_SPAN,
                            (hit->gv - COARSE_INSET) / COARSE_SPAN);
        return bilinear(vals, medium_knots(g->nu), medium_knots(g->nv),
                        medium_coord(x, g->nu), medium_coord(y, g->nv));
    }
    int n = g->nu;
    int m = tri_level_m(level, n);
    if (m == 0)
        return value(vals, 0);
    int vi[3][2];
    float wt[3];
    if (level == CACHE_COARSE) { /* barycentric in the points' triangle, clamped */
        const float third = 1.0f / 3.0f;
        float b[3] = {0, third + (hit->gu - third) / COARSE_SPAN,
                      third + (hit->gv - third) / COARSE_SPAN};
        b[0] = 1.0f - b[1] - b[2];
        float sum = 0.0f;
        for (int k = 0; k < 3; k++)
            sum += b[k] = fmaxf(b[k], 0.0f);
        return v3_scale(
            v3_add(v3_add(v3_scale(value(vals, 0), b[0]), v3_scale(value(vals, 1), b[1])),
                   v3_scale(value(vals, 2), b[2])),
            1.0f / sum);
    }
    tri_cell(m, hit->gu * m, hit->gv * m, vi, wt);
    Vec3 r = v3(0, 0, 0);
    for (int k = 0; k < 3; k++)
        r = v3_madd(r, value(vals, geom_tri_vertex((uint32_t)m, (uint32_t)vi[k][0],
                                                   (uint32_t)vi[k][1])),
                    wt[k]);
    return r;
}

/* The cached value of a type at a hit. */
static Vec3 cached_at_hit(Worker *w, const Hit *hit, int type, int depth, int side, RayDiff diff,
                          float time)
{
    const GridSet *gs = w->rs->gs;
    const Grid *g = &gs->grids[hit->grid];
    const GeomInstance *gi = render_instance(w->rs, hit->instance);
    float f;
    int moves = g->moving || (gi && gi->motion && gs->n_times > 1); /* memo 3.2 */
    int segment = moves ? geom_motion_segment(gs, time, &f) : 0;
    /* the footprint in the grid's units (a master's, through an instance) */
    float footprint = path_footprint(diff, hit->t) / (gi ? gi->scale : 1.0f);
    FillJob job = {w, hit->grid};
    CacheKey key = {.patch = hit->grid,
                    .depth = (uint16_t)depth,
                    .segment = (uint8_t)segment,
                    .side = (uint8_t)side,
                    .type = (uint8_t)type,
                    .level = CACHE_COARSE,
                    .instance = hit->instance};
    /* Clusters (no bend limit of their own: their normals span at most
     * the bend limit) for radiosity and irradiance, not opacity, and not
     * on a transparent object, whose Ci is premultiplied by its own
     * opacity (a cut-out's holes would take a member's light). */
    uint32_t cluster = 0;
    if (type != CACHE_OPACITY && w->set->cache_resolution < 0 &&
        !render_object(w->rs, hit->grid, hit->instance)->transparent)
        cluster = radiosity_choose_cluster(gs, hit->grid, footprint, w->set->cache_k);
    AovSample *aov = type == CACHE_RADIOSITY && depth == 1 ? w->aov : NULL;
    if (aov) /* a camera sample's own diffuse ray at its first hit (RAYES_AOV_CACHE) */
        aov->lookups++;
    if (cluster) {
        key.patch = (uint32_t)gs->n_grids + cluster - 1;
        w->stats.cluster_lookups++;
        return value(cache_lookup(&w->cache, &key, 1, fill_radiosity, &job), 0);
    }
    int level = radiosity_choose_level(g, footprint, w->set->cache_k, w->set->cache_resolution);
    /* Past the fine depth, medium at finest: the rays of a fill near a
     * contact are short and ask for the fine level of the surface across
     * it, whose fill's rays ask again; on a classroom each bounce's fine
     * fills outgrew the last (DESIGN.md "The radiosity cache"). */
    if (type == CACHE_RADIOSITY && depth > w->set->cache_fine_depth && level == CACHE_FINE &&
        w->set->cache_resolution < 0)
        level = effective_level(g, CACHE_MEDIUM);
    key.level = (uint8_t)level;
    if (aov)
        aov->levels += (float)level;
    size_t n = level_values(g, level);
    if (type == CACHE_OPACITY && !moves) {
        uint16_t scratch[3 * OPTABLE_VALUES];
        int filled;
        const uint16_t *vals =
            optable_values(w->opacity_table, &key, n, fill_radiosity, &job, scratch, &filled);
        if (vals) {
            w->stats.table_lookups++;
            w->stats.table_fills += (uint64_t)filled;
            return radiosity_interpolate(g, hit, level, vals);
        }
    }
    return radiosity_interpolate(g, hit, level,
                                 cache_lookup(&w->cache, &key, n, fill_radiosity, &job));
}

Vec3 radiosity_at_hit(Worker *w, const Ray *ray, const Hit *hit, int diffuse_depth, RayDiff diff)
{
    int side = v3_dot(hit->Ng, ray->d) < 0.0f ? 0 : 1;
    return cached_at_hit(w, hit, CACHE_RADIOSITY, diffuse_depth, side, diff, ray->time);
}

Vec3 radiosity_irradiance_at_hit(Worker *w, const Ray *ray, const Hit *hit, float footprint)
{
    /* The outside: the side the ray leaves the object through. */
    int side = v3_dot(hit->Ng, ray->d) < 0.0f ? 1 : 0;
    return cached_at_hit(w, hit, CACHE_IRRADIANCE, 0, side, (RayDiff){footprint, 0.0f},
                         ray->time);
}

int radiosity_opacity_too_fine(const Worker *w, const Hit *hit, RayDiff diff)
{
    if (w->set->cache_resolution >= 0)
        return 0;
    const GeomInstance *gi = render_instance(w->rs, hit->instance);
    float footprint = path_footprint(diff, hit->t) / (gi ? gi->scale : 1.0f);
    return w->rs->gs->grids[hit->grid].edge >
           RADIOSITY_OPACITY_DETAIL * w->set->cache_k * footprint;
}

Vec3 radiosity_opacity_at_hit(Worker *w, const Hit *hit, RayDiff diff)
{
    /* The memo's assumption: one opacity per point, whatever the side and
     * the depth. */
    return cached_at_hit(w, hit, CACHE_OPACITY, 0, 0, diff, w->time);
}
