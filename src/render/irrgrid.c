/*
 * render/irrgrid.c — irradiance interpolation over a grid (irrgrid.h).
 *
 * Records: M x N strata with M = round(sqrt(n / pi)), N = n / M (so N is
 * about pi M and cells are square-ish), one jittered ray each. Radius
 * clamps (digest 3.2): at most E / |grad_t E| per channel, then within 3 and
 * 20 times the pixel footprint at the vertex.
 *
 * Quad grids: records at the lattice knots (every 4th vertex, the last row
 * and column). A lattice cell interpolates its four corner records at its
 * other vertices (bilinear weights times irr_weight with kappa 0.5, values
 * extrapolated with both gradients), unless the corners' predictions for
 * the cell's centre vertex disagree by more than max(DISAGREE, 3 /
 * sqrt(rays)) of their mean (a shadow edge, an occluder between records),
 * or a corner's radius is smaller than the cell: then every vertex of the
 * cell gets its own record, the refinement where neighbours disagree.
 *
 * Triangular grids: in vertex order, a vertex whose earlier records' weights
 * (kappa 1) sum to MIN_WEIGHT or more interpolates them; otherwise it gets
 * a record.
 *
 * With point-based GI (set->pbgi) a record is a gather from the cloud
 * instead of rays (pbgi_record: its gradients come from the cube raster),
 * with the same lattice, clamps and criteria; a gather has no noise, so
 * the disagreement tolerance is DISAGREE.
 */
#include "render/irrgrid.h"

#include <math.h>
#include <stdlib.h>

#include "render/integrator.h"
#include "render/irradiance.h"
#include "render/pbgi.h"
#include "util/check.h"
#include "util/rng.h"

#define MIN_WEIGHT 0.1f
#define DISAGREE 0.1f

static float comp(Vec3 v, int c)
{
    return c == 0 ? v.x : c == 1 ? v.y : v.z;
}

/* How records are made: M x N rays into L and r, or, with point-based
 * GI, gathers from cloud into raster. */
typedef struct Sampler {
    int M, N;
    Vec3 *L;
    float *r;
    const PbgiCloud *cloud;
    PbgiRaster raster;
} Sampler;

/* The record of vertex k from the sampler's rays. */
static void trace_record(const PathState *ps, size_t k, Vec3 P, Vec3 n, Sampler *s,
                         IrrRecord *rec)
{
    Worker *w = ps->w;
    int M = s->M, N = s->N;
    Vec3 o = v3_madd(P, n, ps->offset[k]);
    uint64_t key = hash_combine(ps->keys[k], DIM_DIFFUSE);
    RayDiff diff = {ps->diff[k].width, fmaxf(ps->diff[k].spread, 1.0f / sqrtf((float)(M * N)))};
    for (int j = 0; j < M; j++)
        for (int q = 0; q < N; q++) {
            int c = j * N + q;
            float xi1 = rng_float(hash_combine(key, 2 * (uint64_t)c));
            float xi2 = rng_float(hash_combine(key, 2 * (uint64_t)c + 1));
            Ray ray = {o, irr_direction(M, N, j, q, xi1, xi2, n), 0.0f, INFINITY,
                       RAYES_RAY_DIFFUSE, w->time};
            w->stats.rays_diffuse++;
            s->L[c] = integrator_trace_hit(w, &ray, RAYES_RAY_DIFFUSE, 1, 0,
                                           hash_combine(key, (uint64_t)c + 1), diff, &s->r[c]);
        }
    irr_record(M, N, s->L, s->r, P, n, rec);
}

static void make_record(const PathState *ps, const IrrGrid *irr, size_t k, Sampler *s,
                        IrrRecord *rec)
{
    Worker *w = ps->w;
    Vec3 P = v3_load(irr->P[k]), n = v3_load(irr->N[k]);
    if (s->cloud) {
        pbgi_record(s->cloud, &s->raster, P, n, rec);
        w->stats.pbgi_gathers++;
    } else {
        trace_record(ps, k, P, n, s, rec);
    }
    float R = rec->R;
    for (int c = 0; c < 3; c++) {
        float g = v3_length(rec->grad_t[c]);
        if (g > 0.0f)
            R = fminf(R, comp(rec->E, c) / g);
    }
    float f = ps->diff[k].width;
    rec->R = fminf(fmaxf(R, 3.0f * f), 20.0f * f);
    w->stats.irradiance_records++;
}

/* Lattice knots along n vertices: every 4th, and the last. */
static int knots(int n, int *at)
{
    int m = 0;
    for (int i = 0; i < n - 1; i += 4)
        at[m++] = i;
    at[m++] = n - 1;
    return m;
}

/* Indirect diffuse of the vertices of a quad grid: records at the lattice
 * knots; each lattice cell either interpolates its four corner records or,
 * where they disagree or see geometry closer than the cell is wide, gets a
 * record at every vertex. */
static void quad_grid(const PathState *ps, IrrGrid *irr, Sampler *s,
                      IrrRecord *recs, float tol)
{
    const Grid *g = irr->grid;
    int nu = g->nu, nv = g->nv, ku[GEOM_MAX_GRID], kv[GEOM_MAX_GRID];
    int mu = knots(nu, ku), mv = knots(nv, kv);
    char *done = calloc((size_t)nu * nv, 1);
    RY_CHECK(done != NULL);
    /* records[k] is valid where done[k] == 1 */
    for (int b = 0; b < mv; b++)
        for (int a = 0; a < mu; a++) {
            size_t k = (size_t)kv[b] * nu + ku[a];
            make_record(ps, irr, k, s, &recs[k]);
            done[k] = 1;
        }
    for (int b = 0; b + 1 < mv; b++)
        for (int a = 0; a + 1 < mu; a++) {
            int i0 = ku[a], i1 = ku[a + 1], j0 = kv[b], j1 = kv[b + 1];
            const IrrRecord *c[4] = {&recs[(size_t)j0 * nu + i0], &recs[(size_t)j0 * nu + i1],
                                     &recs[(size_t)j1 * nu + i0], &recs[(size_t)j1 * nu + i1]};
            /* The corners' predictions for the cell's centre vertex. */
            size_t mid = (size_t)((j0 + j1) / 2) * nu + (i0 + i1) / 2;
            Vec3 pm = v3_load(irr->P[mid]), nm = v3_load(irr->N[mid]);
            float lo = INFINITY, hi = 0.0f, sum = 0.0f, span = 0.0f;
            for (int q = 0; q < 4; q++) {
                Vec3 e = irr_extrapolate(c[q], pm, nm);
                float y = e.x + e.y + e.z;
                lo = fminf(lo, y), hi = fmaxf(hi, y), sum += y;
                span = fmaxf(span, v3_length(v3_sub(c[q]->p, pm)));
            }
            int refine = hi - lo > tol * 0.25f * sum + 1e-6f;
            for (int q = 0; q < 4; q++)
                refine |= c[q]->R < span;
            for (int j = j0; j <= j1; j++)
                for (int i = i0; i <= i1; i++) {
                    size_t k = (size_t)j * nu + i;
                    if (done[k])
                        continue;
                    if (refine) {
                        make_record(ps, irr, k, s, &recs[k]);
                        done[k] = 1;
                        continue;
                    }
                    /* Bilinear weights in the cell, times the corners' validity. */
                    float fx = (float)(i - i0) / (float)(i1 - i0), fy = (float)(j - j0) / (float)(j1 - j0);
                    float bw[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
                    Vec3 p = v3_load(irr->P[k]), n = v3_load(irr->N[k]), e = v3(0, 0, 0);
                    float wsum = 0.0f;
                    for (int q = 0; q < 4; q++) {
                        float wq = bw[q] * irr_weight(c[q], p, n, 0.5f);
                        e = v3_madd(e, irr_extrapolate(c[q], p, n), wq);
                        wsum += wq;
                    }
                    if (wsum < 1e-3f) {
                        make_record(ps, irr, k, s, &recs[k]);
                        done[k] = 1;
                        continue;
                    }
                    e = v3_scale(e, 1.0f / wsum);
                    recs[k].E = e; /* not a record: only E is used below */
                    done[k] = 2;
                    ps->w->stats.irradiance_interpolated++;
                }
        }
    for (size_t k = 0; k < (size_t)nu * nv; k++) {
        Vec3 E = recs[k].E;
        irr->E[k][0] = E.x, irr->E[k][1] = E.y, irr->E[k][2] = E.z;
    }
    free(done);
}

/* Triangular grids: records where no earlier record covers a vertex. */
static void tri_grid(const PathState *ps, IrrGrid *irr, Sampler *s,
                     IrrRecord *recs)
{
    size_t n = geom_grid_n_vertices(irr->grid), n_recs = 0;
    for (size_t k = 0; k < n; k++) {
        Vec3 p = v3_load(irr->P[k]), nk = v3_load(irr->N[k]), sum = v3(0, 0, 0);
        float wsum = 0.0f;
        for (size_t i = 0; i < n_recs; i++) {
            float wi = irr_weight(&recs[i], p, nk, 1.0f);
            if (wi > 0.0f) {
                sum = v3_madd(sum, irr_extrapolate(&recs[i], p, nk), wi);
                wsum += wi;
            }
        }
        Vec3 E;
        if (wsum < MIN_WEIGHT) {
            make_record(ps, irr, k, s, &recs[n_recs]);
            E = recs[n_recs++].E;
        } else {
            E = v3_scale(sum, 1.0f / wsum);
            ps->w->stats.irradiance_interpolated++;
        }
        irr->E[k][0] = E.x, irr->E[k][1] = E.y, irr->E[k][2] = E.z;
    }
}

void irrgrid_compute(const PathState *ps, IrrGrid *irr, int n_rays)
{
    const Grid *g = irr->grid;
    size_t n = geom_grid_n_vertices(g);
    Sampler s = {.cloud = ps->w->set->pbgi};
    IrrRecord *recs = malloc(n * sizeof *recs);
    RY_CHECK(recs != NULL);
    /* Noise of a record's E is about 1/sqrt(rays): disagreement must exceed
     * it. A gather has no noise. */
    float tol = DISAGREE;
    if (s.cloud) {
        RY_CHECK(pbgi_raster_init(&s.raster, s.cloud) == 0);
    } else {
        s.M = (int)lroundf(sqrtf((float)n_rays / (float)M_PI));
        s.M = s.M < 1 ? 1 : s.M;
        s.N = n_rays / s.M < 3 ? 3 : n_rays / s.M;
        s.L = malloc((size_t)(s.M * s.N) * sizeof *s.L);
        s.r = malloc((size_t)(s.M * s.N) * sizeof *s.r);
        RY_CHECK(s.L && s.r);
        tol = fmaxf(DISAGREE, 3.0f / sqrtf((float)(s.M * s.N)));
    }
    if (g->triangular)
        tri_grid(ps, irr, &s, recs);
    else
        quad_grid(ps, irr, &s, recs, tol);
    /* The service's indirect diffuse is irradiance / pi. */
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            irr->E[k][c] *= (float)(1.0 / M_PI);
    irr->done = 1;
    irr->n_rays = n_rays;
    free(recs);
    free(s.L);
    free(s.r);
    if (s.cloud)
        pbgi_raster_fini(&s.raster);
}
