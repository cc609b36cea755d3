/*
 * accel/accel.c — the Embree 3 implementation of accel.h.
 *
 * Layout, per level (the world, then each master's own Embree scene,
 * which instance geometries in the world's place): per object with quad
 * grids, one RTC_GEOMETRY_TYPE_GRID whose grid buffer lists its grids
 * (startVertexID = the grid's first vertex in the shared vertex array,
 * stride = nu); per object with triangular grids,
 * one RTC_GEOMETRY_TYPE_TRIANGLE whose index buffer lists every
 * micropolygon; per object with curves, one ROUND_ or FLAT_LINEAR_CURVE
 * through the centre lines of their grids; per object with points, one
 * SPHERE_ or DISC_POINT, a point per grid. Geom records map (geomID,
 * primID) back to grids. An object whose mask holds ACCEL_MASK_OWN_SCENE
 * has its world geometries attached to a scene of its own too, under the
 * same geomIDs (Embree lets a geometry belong to several scenes):
 * subsurface rays test only their object's micropolygons (memo 6.2).
 *
 * Motion blur: the quad and triangle geometries of an object with a moving
 * grid have the GridSet's n_times time steps over Embree's time range
 * [0, 1], each a vertex buffer of their own (Geom.steps: the grids'
 * vertices one grid after another, still grids copied); a ray's time maps
 * onto the range (clamped). Other geometries share GridSet.P. Curves and
 * points stay still. A moving instance (GeomInstance.motion) has as many
 * time steps, each its world_from_master at that sample; Embree blends the
 * matrices linearly (no quaternion form), and make_hit maps a hit's
 * points with the same blend (geom_instance_at).
 *
 * Embree with TBB builds on its own threads; commit happens once, before
 * any query, and queries are concurrent (Embree's contract).
 */
#include "accel/accel.h"
#include "accel/record.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/check.h"
#include "util/rng.h"

typedef struct MicroTri {
    uint32_t grid;     /* patch id */
    uint8_t i, j;      /* lattice position of the cell */
    uint8_t upper;     /* 0: (i,j),(i+1,j),(i,j+1); 1: (i+1,j),(i+1,j+1),(i,j+1) */
} MicroTri;

typedef struct CurveSeg {
    uint32_t grid;     /* patch id */
    uint32_t i;        /* the segment from centre-line vertex i to i + 1 */
} CurveSeg;

typedef enum GeomKind {
    KIND_QUADS,
    KIND_TRIS,
    KIND_PLANAR_TRIS, /* a planar triangular grid as one triangle (build_planar) */
    KIND_CURVES,
    KIND_POINTS,
    KIND_INSTANCE
} GeomKind;

typedef struct Geom {
    GeomKind kind;
    uint8_t shape;     /* GeomShape of its grids */
    uint32_t instance; /* KIND_INSTANCE: the GridSet's instance index */
    uint32_t *grids;   /* quads, points: primID -> grid index */
    MicroTri *tris;    /* triangles: primID -> micropolygon */
    CurveSeg *segs;    /* curves: primID -> segment */
    Vec3 *steps;       /* a moving geometry's vertices, owned: per time sample, its grids'
                          vertices one grid after another (set_vertices) */
} Geom;

/* One Embree scene: the world's (level 0: world geometry, then one
 * instance geometry per GeomInstance), or master m's (level m + 1, in
 * master space, traced only through instances). */
typedef struct Level {
    RTCScene scene;    /* NULL: a master no instance places */
    RTCScene also[3];  /* while building: an object's own scene, a primitive solid's and all
                          solids' that take the geometries too (level 0 only), or NULL */
    int only_also;     /* while building: the level's scene does not take them (solids) */
    Geom *geoms;       /* indexed by geomID */
    size_t n_geoms;
} Level;

struct Accel {
    RTCDevice device;
    const GridSet *gs;
    Level *levels;     /* 1 + gs->n_masters */
    size_t n_levels;
    RTCScene *object_scene; /* per object: its own scene (ACCEL_MASK_OWN_SCENE), or NULL */
    size_t n_objects;
    uint32_t *object_mask;  /* per object: its ray mask (solids' geometries have
                               ACCEL_MASK_SOLID instead; queries check this) */
    RTCScene *solid_scene;  /* per node of the solids' tree: a primitive solid's surfaces
                               alone, or NULL */
    Bounds3 *solid_bound;   /* per node: a primitive solid's bound (its grids' vertices) */
    RTCScene solids;        /* every primitive solid's surfaces (not in the world's scene:
                               intersect_solids finds them), or NULL */
    atomic_llong bytes; /* Embree's allocations, from the memory monitor */
    AccelRecord *record; /* NULL, or where queries are kept (record.h) */
    const volatile int *stop; /* nonzero: builds are cancelled (accel_new's) */
    char error[256];   /* the first Embree error */
};

static void on_error(void *user, enum RTCError code, const char *str)
{
    Accel *a = user;
    if (a->error[0] == '\0')
        snprintf(a->error, sizeof a->error, "Embree error %d: %s", (int)code, str ? str : "");
}

static bool on_memory(void *user, ssize_t bytes, bool post)
{
    Accel *a = user;
    (void)post;
    atomic_fetch_add(&a->bytes, (long long)bytes);
    return true;
}

/* Embree's build progress: false cancels the build once a stop is asked
 * (called from Embree's build threads). */
static bool on_progress(void *user, double done)
{
    const Accel *a = user;
    (void)done;
    return !__atomic_load_n(a->stop, __ATOMIC_RELAXED);
}

static int add_geom(Level *lv, Geom g)
{
    Geom *geoms = realloc(lv->geoms, (lv->n_geoms + 1) * sizeof *geoms);
    if (!geoms)
        return -1;
    lv->geoms = geoms;
    lv->geoms[lv->n_geoms++] = g;
    return 0;
}

static void transmission_filter(const struct RTCFilterFunctionNArguments *args);
static void keep_filter(const struct RTCFilterFunctionNArguments *args);

/* Commits geom with its ray mask into the level's scene as the next
 * geometry, whose primitives map back to grids through g. */
static int attach(Level *lv, RTCGeometry geom, uint32_t mask, Geom g)
{
    if (mask & ACCEL_MASK_TRANSPARENT) {
        rtcSetGeometryOccludedFilterFunction(geom, transmission_filter);
        rtcSetGeometryIntersectFilterFunction(geom, keep_filter);
    }
    uint32_t seen = mask & ~(ACCEL_MASK_TRANSPARENT | ACCEL_MASK_OWN_SCENE);
    /* An object no ray type sees but with a scene of its own (a hidden
     * volume bound) keeps a bit that only its scene's queries carry. */
    rtcSetGeometryMask(geom, seen || !(mask & ACCEL_MASK_OWN_SCENE) ? seen : ACCEL_MASK_OWN_SCENE);
    rtcCommitGeometry(geom);
    unsigned id = (unsigned)lv->n_geoms;
    if (!lv->only_also)
        id = rtcAttachGeometry(lv->scene, geom);
    for (int k = 0; k < 3; k++)
        if (lv->also[k])
            rtcAttachGeometryByID(lv->also[k], geom, id);
    rtcReleaseGeometry(geom);
    RY_CHECK(id == lv->n_geoms);
    return add_geom(lv, g);
}

/* The vertex buffers of geom, whose grids are idx[0 .. n - 1]: the
 * GridSet's P, shared, with base[k] = grid k's first vertex; or, if any of
 * them moves, a buffer per time sample of their vertices one grid after
 * another (returned, for the Geom to own; base[k] then counts in it).
 * *failed is set when out of memory. */
static Vec3 *set_vertices(const GridSet *gs, RTCGeometry geom, const uint32_t *idx, size_t n,
                          uint32_t *base, int *failed)
{
    int moving = 0;
    size_t total = 0;
    for (size_t k = 0; k < n; k++) {
        const Grid *g = &gs->grids[idx[k]];
        moving |= gs->n_times > 1 && g->moving;
        base[k] = (uint32_t)total;
        total += geom_grid_n_vertices(g);
    }
    *failed = 0;
    if (!moving) {
        for (size_t k = 0; k < n; k++)
            base[k] = gs->grids[idx[k]].first_vertex;
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, gs->P, 0,
                                   sizeof(Vec3), gs->n_vertices);
        return NULL;
    }
    int steps = gs->n_times;
    Vec3 *buf = malloc(((size_t)steps * total + 1) * sizeof *buf); /* + 1: Embree reads 16 B */
    if (!buf) {
        *failed = 1;
        return NULL;
    }
    rtcSetGeometryTimeStepCount(geom, (unsigned)steps);
    for (int t = 0; t < steps; t++) {
        Vec3 *out = buf + (size_t)t * total;
        for (size_t k = 0; k < n; k++) {
            const Grid *g = &gs->grids[idx[k]];
            for (size_t i = 0; i < geom_grid_n_vertices(g); i++)
                out[base[k] + i] = geom_vertex_P_at_sample(gs, g, g->first_vertex + i, t);
        }
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, (unsigned)t, RTC_FORMAT_FLOAT3,
                                   out, 0, sizeof(Vec3), total);
    }
    return buf;
}

static int build_quads(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask)
{
    const GridSet *gs = a->gs;
    RTCGeometry geom = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_GRID);
    uint32_t *base = malloc((n + 1) * sizeof *base);
    int failed = !base;
    Vec3 *steps = base ? set_vertices(gs, geom, idx, n, base, &failed) : NULL;
    struct RTCGrid *grids = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_GRID, 0, RTC_FORMAT_GRID,
                                             sizeof(struct RTCGrid), n);
    Geom g = {.kind = KIND_QUADS, .grids = malloc(n * sizeof(uint32_t)), .steps = steps};
    if (!grids || !g.grids || failed) {
        free(g.grids);
        free(steps);
        free(base);
        rtcReleaseGeometry(geom);
        return -1;
    }
    for (size_t k = 0; k < n; k++) {
        const Grid *src = &gs->grids[idx[k]];
        grids[k] = (struct RTCGrid){base[k], src->nu, src->nu, src->nv};
        g.grids[k] = idx[k];
    }
    free(base);
    return attach(lv, geom, mask, g);
}

static size_t count_tris(const GridSet *gs, const uint32_t *idx, size_t n)
{
    size_t t = 0;
    for (size_t k = 0; k < n; k++) {
        size_t s = gs->grids[idx[k]].nu;
        t += s * s;
    }
    return t;
}

static void tri_vertices(const Grid *g, const MicroTri *m, uint32_t v[3])
{
    uint32_t n = g->nu, i = m->i, j = m->j, b = g->first_vertex;
    if (!m->upper) {
        v[0] = b + geom_tri_vertex(n, i, j);
        v[1] = b + geom_tri_vertex(n, i + 1, j);
        v[2] = b + geom_tri_vertex(n, i, j + 1);
    } else {
        v[0] = b + geom_tri_vertex(n, i + 1, j);
        v[1] = b + geom_tri_vertex(n, i + 1, j + 1);
        v[2] = b + geom_tri_vertex(n, i, j + 1);
    }
}

/* Planar grids (grid_planar, tri_grid_planar) as one Embree primitive
 * each between their corners: a quad grid as a 2 x 2 grid cell, whose
 * (u, v) over the grid is the same affine coordinate as over the fine
 * cells (so hits map back as build_quads's do); a triangular grid of n
 * subdivisions as the triangle (0, 0), (n, 0), (0, n), whose barycentrics
 * are the patch's (gu, gv), from which planar_tri_hit finds the
 * micro-triangle. A fraction of the primitives for the same surface. */
static int build_planar(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask,
                        int tris)
{
    const GridSet *gs = a->gs;
    size_t per = tris ? 3 : 4;
    RTCGeometry geom =
        rtcNewGeometry(a->device, tris ? RTC_GEOMETRY_TYPE_TRIANGLE : RTC_GEOMETRY_TYPE_GRID);
    Vec3 *corners = malloc((per * n + 1) * sizeof *corners); /* + 1: Embree reads 16 B */
    void *prims = tris ? rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                 3 * sizeof(uint32_t), n)
                       : rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_GRID, 0, RTC_FORMAT_GRID,
                                                 sizeof(struct RTCGrid), n);
    Geom g = {.kind = tris ? KIND_PLANAR_TRIS : KIND_QUADS,
              .grids = malloc(n * sizeof(uint32_t)),
              .steps = corners};
    if (!prims || !g.grids || !corners) {
        free(g.grids);
        free(corners);
        rtcReleaseGeometry(geom);
        return -1;
    }
    for (size_t k = 0; k < n; k++) {
        const Grid *src = &gs->grids[idx[k]];
        const Vec3 *P = gs->P + src->first_vertex;
        Vec3 *c = corners + per * k;
        uint32_t first = (uint32_t)(per * k);
        if (tris) {
            uint32_t sub = src->nu;
            c[0] = P[0];
            c[1] = P[geom_tri_vertex(sub, sub, 0)];
            c[2] = P[geom_tri_vertex(sub, 0, sub)];
            uint32_t *t = (uint32_t *)prims + 3 * k;
            t[0] = first, t[1] = first + 1, t[2] = first + 2;
        } else {
            size_t w = src->nu, h = src->nv;
            c[0] = P[0];
            c[1] = P[w - 1];
            c[2] = P[(h - 1) * w];
            c[3] = P[h * w - 1];
            ((struct RTCGrid *)prims)[k] = (struct RTCGrid){first, 2, 2, 2};
        }
        g.grids[k] = idx[k];
    }
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, corners, 0,
                               sizeof(Vec3), per * n);
    return attach(lv, geom, mask, g);
}

static int build_tris(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask)
{
    const GridSet *gs = a->gs;
    size_t n_tris = count_tris(gs, idx, n);
    RTCGeometry geom = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    uint32_t *base = malloc((n + 1) * sizeof *base);
    int failed = !base;
    Vec3 *steps = base ? set_vertices(gs, geom, idx, n, base, &failed) : NULL;
    uint32_t(*tri)[3] = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                3 * sizeof(uint32_t), n_tris);
    Geom g = {.kind = KIND_TRIS, .tris = malloc(n_tris * sizeof(MicroTri)), .steps = steps};
    if (!tri || !g.tris || failed) {
        free(g.tris);
        free(steps);
        free(base);
        rtcReleaseGeometry(geom);
        return -1;
    }
    size_t t = 0;
    for (size_t k = 0; k < n; k++) {
        const Grid *src = &gs->grids[idx[k]];
        uint32_t s = src->nu;
        for (uint32_t j = 0; j < s; j++)
            for (uint32_t i = 0; i + j < s; i++)
                for (uint8_t up = 0; up < 2; up++) {
                    if (up && i + j + 1 >= s)
                        continue;
                    g.tris[t] = (MicroTri){idx[k], (uint8_t)i, (uint8_t)j, up};
                    tri_vertices(src, &g.tris[t], tri[t]);
                    for (int c = 0; c < 3; c++) /* into the buffer's numbering */
                        tri[t][c] = tri[t][c] - src->first_vertex + base[k];
                    t++;
                }
    }
    RY_CHECK(t == n_tris);
    free(base);
    return attach(lv, geom, mask, g);
}

/* Time samples a run of grids needs: the grid set's when any moves,
 * else 1. */
static int run_steps(const GridSet *gs, const uint32_t *idx, size_t n)
{
    for (size_t k = 0; gs->n_times > 1 && k < n; k++)
        if (gs->grids[idx[k]].moving)
            return gs->n_times;
    return 1;
}

/* A curve grid's centre line at time sample t: vertex i of its 2 rows,
 * midway, and half the distance between them (the radius). */
static void centre_vertex(const GridSet *gs, const Grid *g, uint32_t i, int t, float out[4])
{
    Vec3 a = geom_vertex_P_at_sample(gs, g, g->first_vertex + i, t);
    Vec3 b = geom_vertex_P_at_sample(gs, g, g->first_vertex + g->nu + i, t);
    Vec3 c = v3_scale(v3_add(a, b), 0.5f);
    out[0] = c.x, out[1] = c.y, out[2] = c.z;
    out[3] = 0.5f * v3_length(v3_sub(b, a));
}

/* Curve grids (2 rows: the ribbon diced facing the eye) as Embree linear
 * curves through their centre lines, round (tubes) or flat (ribbons that
 * face each ray); Embree joins the segments of one grid, and ends each
 * grid's run with a sphere (round), which fills the joint to the next. */
static int build_curves(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask,
                        int shape)
{
    const GridSet *gs = a->gs;
    size_t n_vtx = 0, n_seg = 0;
    for (size_t k = 0; k < n; k++) {
        n_vtx += gs->grids[idx[k]].nu;
        n_seg += gs->grids[idx[k]].nu - 1u;
    }
    RTCGeometry geom = rtcNewGeometry(a->device, shape == GEOM_SHAPE_ROUND_CURVE
                                                     ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE
                                                     : RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE);
    int steps = run_steps(gs, idx, n);
    rtcSetGeometryTimeStepCount(geom, (unsigned)steps);
    float(*vtx)[4] = NULL;
    for (int t = 0; t < steps; t++) { /* Embree copies nothing: a buffer per sample */
        float(*b)[4] = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, (unsigned)t,
                                               RTC_FORMAT_FLOAT4, 4 * sizeof(float), n_vtx);
        if (!b) {
            rtcReleaseGeometry(geom);
            return -1;
        }
        for (size_t k = 0, v = 0; k < n; v += gs->grids[idx[k]].nu, k++)
            for (uint32_t i = 0; i < gs->grids[idx[k]].nu; i++)
                centre_vertex(gs, &gs->grids[idx[k]], i, t, b[v + i]);
        if (t == 0)
            vtx = b;
    }
    uint32_t *index = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                              sizeof(uint32_t), n_seg);
    Geom g = {.kind = KIND_CURVES, .shape = (uint8_t)shape, .segs = malloc(n_seg * sizeof(CurveSeg))};
    if (!vtx || !index || !g.segs) {
        free(g.segs);
        rtcReleaseGeometry(geom);
        return -1;
    }
    size_t v = 0, t = 0;
    for (size_t k = 0; k < n; k++) {
        const Grid *src = &gs->grids[idx[k]];
        for (uint32_t i = 0; i < src->nu; i++) {
            if (i + 1 < src->nu) {
                index[t] = (uint32_t)(v + i);
                g.segs[t++] = (CurveSeg){idx[k], i};
            }
        }
        v += src->nu;
    }
    return attach(lv, geom, mask, g);
}

static Vec3 unit_or_zero(Vec3 n);

/* The corners of a point grid's square at time sample t: (0,0), (1,0),
 * (0,1). */
static void point_square(const GridSet *gs, const Grid *g, int t, Vec3 *o, Vec3 *x, Vec3 *y)
{
    uint32_t b = g->first_vertex;
    *o = geom_vertex_P_at_sample(gs, g, b, t);
    *x = v3_sub(geom_vertex_P_at_sample(gs, g, b + g->nu - 1u, t), *o);
    *y = v3_sub(geom_vertex_P_at_sample(gs, g, b + (uint32_t)(g->nv - 1) * g->nu, t), *o);
}

/* Point grids as Embree spheres or ray-facing disks inscribed in their
 * squares. */
static int build_points(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask,
                        int shape)
{
    const GridSet *gs = a->gs;
    RTCGeometry geom = rtcNewGeometry(a->device, shape == GEOM_SHAPE_SPHERE
                                                     ? RTC_GEOMETRY_TYPE_SPHERE_POINT
                                                 : shape == GEOM_SHAPE_DISK
                                                     ? RTC_GEOMETRY_TYPE_DISC_POINT
                                                     : RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    int steps = run_steps(gs, idx, n);
    rtcSetGeometryTimeStepCount(geom, (unsigned)steps);
    Geom g = {.kind = KIND_POINTS, .shape = (uint8_t)shape, .grids = malloc(n * sizeof(uint32_t))};
    for (int t = 0; g.grids && t < steps; t++) {
        float(*vtx)[4] = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, (unsigned)t,
                                                 RTC_FORMAT_FLOAT4, 4 * sizeof(float), n);
        float(*nrm)[3] = shape == GEOM_SHAPE_ORIENTED_DISK
                             ? rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, (unsigned)t,
                                                       RTC_FORMAT_FLOAT3, 3 * sizeof(float), n)
                             : NULL;
        if (!vtx || (shape == GEOM_SHAPE_ORIENTED_DISK && !nrm)) {
            free(g.grids);
            rtcReleaseGeometry(geom);
            return -1;
        }
        for (size_t k = 0; k < n; k++) {
            Vec3 o, x, y;
            point_square(gs, &gs->grids[idx[k]], t, &o, &x, &y);
            Vec3 c = v3_add(o, v3_scale(v3_add(x, y), 0.5f));
            vtx[k][0] = c.x, vtx[k][1] = c.y, vtx[k][2] = c.z;
            vtx[k][3] = 0.5f * v3_length(x);
            if (nrm) {
                Vec3 N = unit_or_zero(v3_cross(x, y));
                nrm[k][0] = N.x, nrm[k][1] = N.y, nrm[k][2] = N.z;
            }
            g.grids[k] = idx[k];
        }
    }
    if (!g.grids) {
        rtcReleaseGeometry(geom);
        return -1;
    }
    return attach(lv, geom, mask, g);
}

/* The kinds of grids an object may have, each one Embree geometry. */
enum {
    GROUP_QUADS,
    GROUP_PLANAR_QUADS,
    GROUP_TRIS,
    GROUP_PLANAR_TRIS,
    GROUP_ROUND,
    GROUP_FLAT,
    GROUP_SPHERES,
    GROUP_DISKS,
    GROUP_ORIENTED,
    N_GROUPS
};

static float max_abs(Vec3 v)
{
    return fmaxf(fabsf(v.x), fmaxf(fabsf(v.y), fabsf(v.z)));
}

/* Whether a still quad grid is a parallelogram diced evenly: every vertex
 * where the corners' affine map puts it (within float rounding of the
 * coordinates' size, far below a ray's offset from its surface). A flat
 * floor or wall, undisplaced. */
static int grid_planar(const GridSet *gs, const Grid *g)
{
    if (g->triangular || (g->moving && gs->n_times > 1) || g->nu < 2 || g->nv < 2)
        return 0;
    const Vec3 *P = gs->P + g->first_vertex;
    int w = g->nu, h = g->nv;
    Vec3 o = P[0], du = v3_scale(v3_sub(P[w - 1], o), 1.0f / (float)(w - 1)),
         dv = v3_scale(v3_sub(P[(size_t)(h - 1) * w], o), 1.0f / (float)(h - 1));
    float size = fmaxf(max_abs(o), v3_length(v3_sub(P[(size_t)h * w - 1], o)));
    float tol = 4e-6f * size;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            Vec3 d = v3_sub(P[(size_t)j * w + i], v3_madd(v3_madd(o, du, (float)i), dv, (float)j));
            if (max_abs(d) > tol)
                return 0;
        }
    return 1;
}

/* grid_planar for a triangular grid of n subdivisions: every vertex (i, j)
 * where the corners' affine map puts it. */
static int tri_grid_planar(const GridSet *gs, const Grid *g)
{
    if (!g->triangular || (g->moving && gs->n_times > 1) || g->nu < 1)
        return 0;
    const Vec3 *P = gs->P + g->first_vertex;
    uint32_t n = g->nu;
    Vec3 o = P[0], du = v3_scale(v3_sub(P[geom_tri_vertex(n, n, 0)], o), 1.0f / (float)n),
         dv = v3_scale(v3_sub(P[geom_tri_vertex(n, 0, n)], o), 1.0f / (float)n);
    float size = fmaxf(max_abs(o), fmaxf(v3_length(v3_scale(du, (float)n)),
                                         v3_length(v3_scale(dv, (float)n))));
    float tol = 4e-6f * size;
    for (uint32_t j = 0; j <= n; j++)
        for (uint32_t i = 0; i + j <= n; i++) {
            Vec3 d = v3_sub(P[geom_tri_vertex(n, i, j)],
                            v3_madd(v3_madd(o, du, (float)i), dv, (float)j));
            if (max_abs(d) > tol)
                return 0;
        }
    return 1;
}

static int grid_group(const GridSet *gs, const Grid *g)
{
    switch (g->shape) {
    case GEOM_SHAPE_ROUND_CURVE: return GROUP_ROUND;
    case GEOM_SHAPE_FLAT_CURVE: return GROUP_FLAT;
    case GEOM_SHAPE_SPHERE: return GROUP_SPHERES;
    case GEOM_SHAPE_DISK: return GROUP_DISKS;
    case GEOM_SHAPE_ORIENTED_DISK: return GROUP_ORIENTED;
    default:
        if (g->triangular)
            return tri_grid_planar(gs, g) ? GROUP_PLANAR_TRIS : GROUP_TRIS;
        return grid_planar(gs, g) ? GROUP_PLANAR_QUADS : GROUP_QUADS;
    }
}

/* A grid's place in the build order: by level, object, kind of geometry,
 * then index (runs of equal level, object and kind are one geometry). */
typedef struct GridKey {
    uint32_t master, object, solid, group, grid;
} GridKey;

static int cmp_keys(const void *pa, const void *pb)
{
    const GridKey *a = pa, *b = pb;
    if (a->master != b->master)
        return a->master < b->master ? -1 : 1;
    if (a->object != b->object)
        return a->object < b->object ? -1 : 1;
    if (a->solid != b->solid)
        return a->solid < b->solid ? -1 : 1;
    if (a->group != b->group)
        return a->group < b->group ? -1 : 1;
    return a->grid < b->grid ? -1 : a->grid > b->grid;
}

/* Adds one Embree geometry for the n grids idx (one level, object and
 * group), in grid order. */
static int build_run(Accel *a, Level *lv, const uint32_t *idx, size_t n, uint32_t mask,
                     int group)
{
    switch (group) {
    case GROUP_QUADS: return build_quads(a, lv, idx, n, mask);
    case GROUP_PLANAR_QUADS: return build_planar(a, lv, idx, n, mask, 0);
    case GROUP_TRIS: return build_tris(a, lv, idx, n, mask);
    case GROUP_PLANAR_TRIS: return build_planar(a, lv, idx, n, mask, 1);
    case GROUP_ROUND: return build_curves(a, lv, idx, n, mask, GEOM_SHAPE_ROUND_CURVE);
    case GROUP_FLAT: return build_curves(a, lv, idx, n, mask, GEOM_SHAPE_FLAT_CURVE);
    case GROUP_SPHERES: return build_points(a, lv, idx, n, mask, GEOM_SHAPE_SPHERE);
    case GROUP_DISKS: return build_points(a, lv, idx, n, mask, GEOM_SHAPE_DISK);
    default: return build_points(a, lv, idx, n, mask, GEOM_SHAPE_ORIENTED_DISK);
    }
}

static RTCScene new_scene(Accel *a, int robust)
{
    RTCScene scene = rtcNewScene(a->device);
    /* Watertight intersection: without it Embree's fast path lets rays
     * slip between micropolygons that share an edge, inside a grid and
     * between stitched grids (tests/render/test_watertight.c). An
     * object's own scene does without (a subsurface ray that slips is one
     * sample lost; DESIGN.md). */
    rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
    if (a->stop)
        rtcSetSceneProgressMonitorFunction(scene, on_progress, a);
    return scene;
}

/* The mask of grids of object o in a master: the object's own, or for
 * inheriting grids every ray type (the instance's mask decides), with
 * ACCEL_MASK_TRANSPARENT when any instance's object is transparent. */
static uint32_t grid_mask(const Grid *g, const uint32_t *object_mask,
                          const uint8_t *inherit_transparent)
{
    if (g->object != GEOM_OBJECT_INHERIT)
        return object_mask[g->object];
    return ~ACCEL_MASK_TRANSPARENT |
           (inherit_transparent[g->master - 1] ? ACCEL_MASK_TRANSPARENT : 0u);
}

/* The world's and the masters' geometries: every run of grids of one
 * level, object and kind becomes one Embree geometry. */
static int build_levels(Accel *a, const uint32_t *object_mask, const uint8_t *inherit_transparent,
                        uint32_t *order)
{
    const GridSet *gs = a->gs;
    GridKey *keys = malloc((gs->n_grids + 1) * sizeof *keys);
    if (!keys)
        return -1;
    for (size_t k = 0; k < gs->n_grids; k++) {
        const Grid *g = &gs->grids[k];
        uint32_t solid = g->master == 0 && g->solid <= gs->n_solids ? g->solid : 0;
        keys[k] = (GridKey){g->master, g->object, solid, (uint32_t)grid_group(gs, g), (uint32_t)k};
    }
    qsort(keys, gs->n_grids, sizeof *keys, cmp_keys);
    for (size_t k = 0; k < gs->n_grids; k++)
        order[k] = keys[k].grid;
    for (size_t k = 0; k < gs->n_grids;) {
        const Grid *g = &gs->grids[order[k]];
        size_t n = 1;
        while (k + n < gs->n_grids && keys[k + n].master == keys[k].master &&
               keys[k + n].object == keys[k].object && keys[k + n].solid == keys[k].solid &&
               keys[k + n].group == keys[k].group)
            n++;
        Level *lv = &a->levels[g->master];
        if (!lv->scene)
            lv->scene = new_scene(a, 1);
        uint32_t mask = grid_mask(g, object_mask, inherit_transparent);
        lv->also[0] = lv->also[1] = lv->also[2] = NULL;
        lv->only_also = 0;
        if (g->master == 0 && (mask & ACCEL_MASK_OWN_SCENE) && g->object < a->n_objects) {
            if (!a->object_scene[g->object])
                a->object_scene[g->object] = new_scene(a, 0);
            lv->also[0] = a->object_scene[g->object];
        }
        uint32_t solid = keys[k].solid;
        if (solid) { /* a primitive solid's surface: found by solid queries alone, opaque */
            if (!a->solid_scene[solid - 1])
                a->solid_scene[solid - 1] = new_scene(a, 1);
            lv->also[1] = a->solid_scene[solid - 1];
            if (!a->solids)
                a->solids = new_scene(a, 1);
            lv->also[2] = a->solids;
            lv->only_also = 1;
            mask = ACCEL_MASK_SOLID | (mask & ACCEL_MASK_OWN_SCENE);
        }
        int rc = build_run(a, lv, order + k, n, mask, (int)keys[k].group);
        lv->also[0] = lv->also[1] = lv->also[2] = NULL;
        lv->only_also = 0;
        if (rc != 0) {
            free(keys);
            return -1;
        }
        k += n;
    }
    free(keys);
    return 0;
}

/* One Embree instance per GeomInstance, in the world's scene, after its
 * own geometry; the masters' scenes are committed first. */
static int build_instances(Accel *a)
{
    const GridSet *gs = a->gs;
    for (size_t m = 1; m < a->n_levels; m++)
        if (a->levels[m].scene)
            rtcCommitScene(a->levels[m].scene);
    for (size_t i = 0; i < gs->n_instances; i++) {
        const GeomInstance *gi = &gs->instances[i];
        RTCScene master = a->levels[gi->master + 1].scene;
        if (!master)
            continue; /* a master whose grids all fell away */
        RTCGeometry geom = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(geom, master);
        if (gi->motion && gs->n_times > 1) { /* instance motion: a transform per time step */
            const Mat4 *W = &gs->instance_motion[(size_t)(gi->motion - 1) * (size_t)gs->n_times];
            rtcSetGeometryTimeStepCount(geom, (unsigned)gs->n_times);
            for (int k = 0; k < gs->n_times; k++)
                rtcSetGeometryTransform(geom, (unsigned)k, RTC_FORMAT_FLOAT3X4_ROW_MAJOR,
                                        &W[k].m[0][0]);
        } else {
            rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR,
                                    &gi->world_from_master.m[0][0]);
        }
        Geom g = {.kind = KIND_INSTANCE, .instance = (uint32_t)i};
        if (attach(&a->levels[0], geom, gi->ray_mask & ~ACCEL_MASK_TRANSPARENT, g) != 0)
            return -1;
    }
    return 0;
}

/* Which masters' inheriting grids may be transparent: those placed by an
 * instance whose object is. NULL when out of memory. */
static uint8_t *inherit_transparency(const GridSet *gs, const uint32_t *object_mask)
{
    uint8_t *t = calloc(gs->n_masters + 1, 1);
    for (size_t i = 0; t && i < gs->n_instances; i++)
        if (object_mask[gs->instances[i].object] & ACCEL_MASK_TRANSPARENT)
            t[gs->instances[i].master] = 1;
    return t;
}

Accel *accel_new(const GridSet *gs, const uint32_t *object_mask, size_t n_objects,
                 const volatile int *stop, char *err, size_t err_size)
{
    Accel *a = calloc(1, sizeof *a);
    uint32_t *order = malloc((gs->n_grids + 1) * sizeof *order);
    uint8_t *inherit_transparent = inherit_transparency(gs, object_mask);
    if (a) {
        a->levels = calloc(gs->n_masters + 1, sizeof *a->levels);
        a->object_scene = calloc(n_objects + 1, sizeof *a->object_scene);
        a->n_objects = n_objects;
        a->object_mask = malloc((n_objects + 1) * sizeof *a->object_mask);
        a->solid_scene = calloc(gs->n_solids + 1, sizeof *a->solid_scene);
        a->solid_bound = malloc((gs->n_solids + 1) * sizeof *a->solid_bound);
    }
    if (!a || !a->levels || !a->object_scene || !a->object_mask || !a->solid_scene ||
        !a->solid_bound || !order || !inherit_transparent) {
        if (a)
            free(a->levels), free(a->object_scene), free(a->object_mask), free(a->solid_scene),
                free(a->solid_bound);
        free(a);
        free(order);
        free(inherit_transparent);
        snprintf(err, err_size, "out of memory building the ray tracing structure");
        return NULL;
    }
    a->n_levels = gs->n_masters + 1;
    a->gs = gs;
    a->stop = stop;
    if (n_objects)
        memcpy(a->object_mask, object_mask, n_objects * sizeof *object_mask);
    for (size_t k = 0; k < gs->n_solids; k++)
        a->solid_bound[k] = bounds_empty();
    for (size_t k = 0; k < gs->n_grids; k++) { /* primitive solids' bounds, a little wider */
        const Grid *g = &gs->grids[k];
        if (g->master || !g->solid || g->solid > gs->n_solids)
            continue;
        Bounds3 *b = &a->solid_bound[g->solid - 1];
        for (size_t i = 0; i < geom_grid_n_vertices(g); i++)
            for (int t = 0; t < (g->moving ? gs->n_times : 1); t++)
                *b = bounds_add(*b, geom_vertex_P_at_sample(gs, g, g->first_vertex + i, t));
    }
    for (size_t k = 0; k < gs->n_solids; k++) {
        Bounds3 *b = &a->solid_bound[k];
        Vec3 m = v3_scale(v3_sub(b->hi, b->lo), 1e-3f);
        b->lo = v3_sub(b->lo, m), b->hi = v3_add(b->hi, m);
    }
    atomic_init(&a->bytes, 0);
    a->device = rtcNewDevice("verbose=0");
    if (!a->device) {
        snprintf(err, err_size, "cannot create an Embree device (error %d)",
                 (int)rtcGetDeviceError(NULL));
        free(a->levels);
        free(a->object_scene);
        free(a->object_mask);
        free(a->solid_scene);
        free(a->solid_bound);
        free(a);
        free(order);
        free(inherit_transparent);
        return NULL;
    }
    rtcSetDeviceErrorFunction(a->device, on_error, a);
    rtcSetDeviceMemoryMonitorFunction(a->device, on_memory, a);
    a->levels[0].scene = new_scene(a, 1);
    int rc = build_levels(a, object_mask, inherit_transparent, order);
    if (rc == 0)
        rc = build_instances(a);
    free(order);
    free(inherit_transparent);
    if (rc == 0)
        rtcCommitScene(a->levels[0].scene);
    for (size_t o = 0; o < n_objects && rc == 0; o++)
        if (a->object_scene[o])
            rtcCommitScene(a->object_scene[o]);
    for (size_t k = 0; k < gs->n_solids && rc == 0; k++)
        if (a->solid_scene[k])
            rtcCommitScene(a->solid_scene[k]);
    if (a->solids && rc == 0)
        rtcCommitScene(a->solids);
    if (stop && __atomic_load_n(stop, __ATOMIC_RELAXED)) {
        snprintf(err, err_size, "render: cancelled");
        accel_free(a);
        return NULL;
    }
    if (rc != 0 || a->error[0]) {
        snprintf(err, err_size, "%s", a->error[0] ? a->error : "out of memory in Embree");
        accel_free(a);
        return NULL;
    }
    return a;
}

void accel_free(Accel *a)
{
    if (!a)
        return;
    for (size_t l = 0; a->levels && l < a->n_levels; l++) {
        Level *lv = &a->levels[l];
        for (size_t k = 0; k < lv->n_geoms; k++) {
            free(lv->geoms[k].grids);
            free(lv->geoms[k].tris);
            free(lv->geoms[k].segs);
            free(lv->geoms[k].steps);
        }
        free(lv->geoms);
        if (lv->scene)
            rtcReleaseScene(lv->scene);
    }
    free(a->levels);
    for (size_t o = 0; a->object_scene && o < a->n_objects; o++)
        if (a->object_scene[o])
            rtcReleaseScene(a->object_scene[o]);
    free(a->object_scene);
    for (size_t k = 0; a->solid_scene && k < a->gs->n_solids; k++)
        if (a->solid_scene[k])
            rtcReleaseScene(a->solid_scene[k]);
    free(a->solid_scene);
    free(a->solid_bound);
    free(a->object_mask);
    if (a->solids)
        rtcReleaseScene(a->solids);
    if (a->device)
        rtcReleaseDevice(a->device);
    free(a);
}

/* The ray's time as Embree takes it: [0, 1] over the grid set's time
 * samples (0 when nothing moves). */
static float embree_time(const Accel *a, const Ray *ray)
{
    const GridSet *gs = a->gs;
    float span = gs->time[1] - gs->time[0];
    float t = gs->n_times > 1 && span > 0.0f ? (ray->time - gs->time[0]) / span : 0.0f;
    return t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
}

static void set_ray(const Accel *a, struct RTCRay *r, const Ray *ray)
{
    r->org_x = ray->o.x;
    r->org_y = ray->o.y;
    r->org_z = ray->o.z;
    r->dir_x = ray->d.x;
    r->dir_y = ray->d.y;
    r->dir_z = ray->d.z;
    r->tnear = ray->tnear;
    r->tfar = ray->tfar;
    r->time = embree_time(a, ray);
    r->mask = ray->mask & ~ACCEL_MASK_SOLID; /* solids' surfaces: intersect_solids */
    r->id = 0;
    r->flags = 0;
}

static Vec3 unit_or_zero(Vec3 n)
{
    float l = v3_length(n);
    return l > 0.0f && isfinite(l) ? v3_scale(n, 1.0f / l) : v3(0, 0, 0);
}

/* Vertex i of grid g where it is at Embree's ray time rt in [0, 1] (a
 * still grid: sample 0). */
static Vec3 vertex_at(const GridSet *gs, const Grid *g, uint32_t i, float rt)
{
    if (!g->moving || gs->n_times < 2)
        return gs->P[i];
    float x = rt * (float)(gs->n_times - 1);
    int seg = (int)x;
    seg = seg > gs->n_times - 2 ? gs->n_times - 2 : seg < 0 ? 0 : seg;
    return geom_vertex_at(gs, g, i, seg, x - (float)seg).P;
}

/* The unit normal of the micropolygon a quad or triangle hit names, at
 * Embree's ray time rt (object space): a cell's from its diagonals (2 dPdu
 * x dPdv for a parallelogram), a triangle's from its edges. */
static Vec3 mesh_normal(const GridSet *gs, const Hit *hit, float rt)
{
    const Grid *grid = &gs->grids[hit->grid];
    Vec3 P[4];
    for (int k = 0; k < hit->n_vertex; k++)
        P[k] = vertex_at(gs, grid, hit->vertex[k], rt);
    if (hit->n_vertex == 4)
        return unit_or_zero(v3_cross(v3_sub(P[3], P[0]), v3_sub(P[2], P[1])));
    return unit_or_zero(v3_cross(v3_sub(P[1], P[0]), v3_sub(P[2], P[0])));
}

/* A quad cell's hit; its Ng only when normal is set (zero otherwise). */
static void quad_hit(const Accel *a, const Geom *g, unsigned prim, float u, float v, float rt,
                     int normal, Hit *hit)
{
    const GridSet *gs = a->gs;
    const Grid *grid = &gs->grids[g->grids[prim]];
    int w = grid->nu, h = grid->nv;
    float fu = u * (float)(w - 1), fv = v * (float)(h - 1);
    int x = RY_MIN((int)fu, w - 2), y = RY_MIN((int)fv, h - 2);
    x = RY_MAX(x, 0);
    y = RY_MAX(y, 0);
    fu = fminf(fmaxf(fu - (float)x, 0.0f), 1.0f);
    fv = fminf(fmaxf(fv - (float)y, 0.0f), 1.0f);
    uint32_t b = grid->first_vertex + (uint32_t)(y * w + x);
    hit->grid = g->grids[prim];
    hit->gu = u;
    hit->gv = v;
    hit->n_vertex = 4;
    hit->vertex[0] = b;
    hit->vertex[1] = b + 1;
    hit->vertex[2] = b + (uint32_t)w;
    hit->vertex[3] = b + (uint32_t)w + 1;
    hit->weight[0] = (1.0f - fu) * (1.0f - fv);
    hit->weight[1] = fu * (1.0f - fv);
    hit->weight[2] = (1.0f - fu) * fv;
    hit->weight[3] = fu * fv;
    hit->Ng = normal ? mesh_normal(gs, hit, rt) : v3(0, 0, 0);
}

static void tri_hit(const Accel *a, const Geom *g, unsigned prim, float u, float v, float rt,
                    int normal, Hit *hit)
{
    const GridSet *gs = a->gs;
    const MicroTri *m = &g->tris[prim];
    const Grid *grid = &gs->grids[m->grid];
    uint32_t vtx[3];
    tri_vertices(grid, m, vtx);
    float w[3] = {1.0f - u - v, u, v};
    /* Lattice coordinates of the three vertices, for the patch barycentrics. */
    float li[3], lj[3];
    if (!m->upper) {
        li[0] = m->i, lj[0] = m->j, li[1] = m->i + 1, lj[1] = m->j, li[2] = m->i, lj[2] = m->j + 1;
    } else {
        li[0] = m->i + 1, lj[0] = m->j, li[1] = m->i + 1, lj[1] = m->j + 1;
        li[2] = m->i, lj[2] = m->j + 1;
    }
    float n = grid->nu;
    hit->grid = m->grid;
    hit->gu = (w[0] * li[0] + w[1] * li[1] + w[2] * li[2]) / n;
    hit->gv = (w[0] * lj[0] + w[1] * lj[1] + w[2] * lj[2]) / n;
    hit->n_vertex = 3;
    for (int k = 0; k < 3; k++) {
        hit->vertex[k] = vtx[k];
        hit->weight[k] = w[k];
    }
    hit->vertex[3] = vtx[0];
    hit->weight[3] = 0.0f;
    hit->Ng = normal ? mesh_normal(gs, hit, rt) : v3(0, 0, 0);
}

/* A hit (u, v) on a planar triangular grid's one triangle: the patch's
 * barycentrics, and the micro-triangle of the lattice that holds them,
 * with its vertices and weights as tri_hit gives them. */
static void planar_tri_hit(const Accel *a, const Geom *g, unsigned prim, float u, float v,
                           float rt, int normal, Hit *hit)
{
    const GridSet *gs = a->gs;
    uint32_t gi = g->grids[prim];
    const Grid *grid = &gs->grids[gi];
    int n = grid->nu;
    float x = fmaxf(u, 0.0f) * (float)n, y = fmaxf(v, 0.0f) * (float)n;
    int i = RY_MAX(RY_MIN((int)x, n - 1), 0);
    int j = RY_MAX(RY_MIN((int)y, n - 1 - i), 0);
    float fx = fminf(fmaxf(x - (float)i, 0.0f), 1.0f), fy = fminf(fmaxf(y - (float)j, 0.0f), 1.0f);
    uint32_t b = grid->first_vertex, un = (uint32_t)n, ui = (uint32_t)i, uj = (uint32_t)j;
    hit->grid = gi;
    hit->gu = u;
    hit->gv = v;
    hit->n_vertex = 3;
    if (fx + fy <= 1.0f || i + j + 1 >= n) { /* the lower triangle (the only one at the edge) */
        float s = fx + fy > 1.0f ? fx + fy : 1.0f;
        fx /= s, fy /= s;
        hit->vertex[0] = b + geom_tri_vertex(un, ui, uj);
        hit->vertex[1] = b + geom_tri_vertex(un, ui + 1, uj);
        hit->vertex[2] = b + geom_tri_vertex(un, ui, uj + 1);
        hit->weight[0] = 1.0f - fx - fy;
        hit->weight[1] = fx;
        hit->weight[2] = fy;
    } else {
        hit->vertex[0] = b + geom_tri_vertex(un, ui + 1, uj);
        hit->vertex[1] = b + geom_tri_vertex(un, ui + 1, uj + 1);
        hit->vertex[2] = b + geom_tri_vertex(un, ui, uj + 1);
        hit->weight[0] = 1.0f - fy;
        hit->weight[1] = fx + fy - 1.0f;
        hit->weight[2] = 1.0f - fx;
    }
    hit->vertex[3] = hit->vertex[0];
    hit->weight[3] = 0.0f;
    hit->Ng = normal ? mesh_normal(gs, hit, rt) : v3(0, 0, 0);
}

/* Embree's geometric normal of a round shape's hit (in the space of its
 * level); a flat one faces the ray (world). */
static Vec3 shape_normal(const struct RTCHit *h, const Ray *ray, int shape)
{
    if (shape == GEOM_SHAPE_ROUND_CURVE || shape == GEOM_SHAPE_SPHERE ||
        shape == GEOM_SHAPE_ORIENTED_DISK)
        return unit_or_zero(v3(h->Ng_x, h->Ng_y, h->Ng_z));
    return unit_or_zero(v3_neg(ray->d));
}

static int shape_flat(int shape)
{
    return shape == GEOM_SHAPE_FLAT_CURVE || shape == GEOM_SHAPE_DISK;
}

/* A curve segment's hit: u along it, half way across the grid's 2 rows. */
/* Where a ray met a curve's width, 0 to 1 across the ribbon diced facing
 * the eye (its rows v = 0 and 1): (h + 1) / 2, h the signed distance of the
 * hit from the centre line across the ray, over the radius (a tube's sine
 * of the angle between its normal and the view about the axis, a
 * ribbon's offset; the hair BSDF's h). The centre and radius are the
 * segment's at u, the rows' midpoints and half their distance; an
 * instance's curve (gi not NULL) is met in its master's space. */
static float curve_across(const Accel *a, const Grid *grid, uint32_t b, float u, const Ray *ray,
                          float t, const GeomInstance *gi)
{
    Ray local = *ray;
    if (gi) {
        local.o = mat4_point(&gi->master_from_world, ray->o);
        local.d = mat4_vector(&gi->master_from_world, ray->d);
        ray = &local; /* the same t: the map is affine */
    }
    const GridSet *gs = a->gs;
    float rt = embree_time(a, ray);
    uint32_t w = grid->nu;
    Vec3 p0 = vertex_at(gs, grid, b, rt), p1 = vertex_at(gs, grid, b + 1, rt);
    Vec3 q0 = vertex_at(gs, grid, b + w, rt), q1 = vertex_at(gs, grid, b + w + 1, rt);
    Vec3 c0 = v3_scale(v3_add(p0, q0), 0.5f), c1 = v3_scale(v3_add(p1, q1), 0.5f);
    float r = 0.5f * ((1.0f - u) * v3_length(v3_sub(q0, p0)) + u * v3_length(v3_sub(q1, p1)));
    Vec3 T = v3_sub(c1, c0), wo = v3_neg(ray->d);
    float lt = v3_length(T), lo = v3_length(wo);
    if (!(lt > 0.0f) || !(lo > 0.0f) || !(r > 0.0f))
        return 0.5f;
    T = v3_scale(T, 1.0f / lt), wo = v3_scale(wo, 1.0f / lo);
    float perp = sqrtf(fmaxf(0.0f, 1.0f - v3_dot(wo, T) * v3_dot(wo, T)));
    if (!(perp > 1e-6f))
        return 0.5f;
    Vec3 P = v3_madd(ray->o, ray->d, t), C = v3_lerp(c0, c1, u);
    float h = v3_dot(v3_cross(v3_sub(P, C), wo), T) / (r * perp);
    return isfinite(h) ? 0.5f * (fminf(fmaxf(h, -1.0f), 1.0f) + 1.0f) : 0.5f;
}

static void curve_hit(const Accel *a, const Geom *g, const struct RTCHit *h, const Ray *ray,
                      const GeomInstance *gi, Hit *hit)
{
    const CurveSeg *seg = &g->segs[h->primID];
    const Grid *grid = &a->gs->grids[seg->grid];
    float u = fminf(fmaxf(h->u, 0.0f), 1.0f);
    uint32_t b = grid->first_vertex + seg->i, w = grid->nu;
    float v = curve_across(a, grid, b, u, ray, hit->t, gi);
    hit->grid = seg->grid;
    hit->gu = ((float)seg->i + u) / (float)(w - 1u);
    hit->gv = v;
    hit->n_vertex = 4;
    const uint32_t vtx[4] = {b, b + 1, b + w, b + w + 1};
    const float wt[4] = {(1.0f - v) * (1.0f - u), (1.0f - v) * u, v * (1.0f - u), v * u};
    memcpy(hit->vertex, vtx, sizeof vtx);
    memcpy(hit->weight, wt, sizeof wt);
    hit->Ng = shape_normal(h, ray, g->shape);
}

/* A point's hit: where the hit (at tfar on the world ray; in master space
 * through instance gi, when not NULL) projects on its square. */
static void point_hit(const Accel *a, const Geom *g, const struct RTCHit *h, const Ray *ray,
                      float tfar, const GeomInstance *gi, Hit *hit)
{
    const GridSet *gs = a->gs;
    const Grid *grid = &gs->grids[g->grids[h->primID]];
    float rt = embree_time(a, ray); /* the square where the ray met it */
    uint32_t b = grid->first_vertex;
    Vec3 o = vertex_at(gs, grid, b, rt);
    Vec3 x = v3_sub(vertex_at(gs, grid, b + grid->nu - 1u, rt), o);
    Vec3 y = v3_sub(vertex_at(gs, grid, b + (uint32_t)(grid->nv - 1) * grid->nu, rt), o);
    Vec3 p = v3_madd(ray->o, ray->d, tfar);
    if (gi)
        p = mat4_point(&gi->master_from_world, p);
    Vec3 d = v3_sub(p, o);
    float xx = v3_dot(x, x), yy = v3_dot(y, y);
    float u = xx > 0.0f ? fminf(fmaxf(v3_dot(d, x) / xx, 0.0f), 1.0f) : 0.5f;
    float v = yy > 0.0f ? fminf(fmaxf(v3_dot(d, y) / yy, 0.0f), 1.0f) : 0.5f;
    quad_hit(a, g, h->primID, u, v, rt, 0, hit);
    hit->Ng = shape_normal(h, ray, g->shape);
}

/* The Hit of Embree's hit h at distance tfar along the world ray. A hit
 * through an instance is found in its master's level; Ng is turned to
 * world space. Without normal, a quad's or triangle's Ng is left zero (its
 * vertices' positions are not read; returns 1): hit_normal adds it. */
static int make_hit(const Accel *a, const Ray *ray, const struct RTCHit *h, float tfar,
                    int normal, Hit *hit)
{
    const GeomInstance *gi = NULL;
    GeomInstance moved;
    const Geom *g;
    hit->instance = 0;
    if (h->instID[0] != RTC_INVALID_GEOMETRY_ID) {
        uint32_t i = a->levels[0].geoms[h->instID[0]].instance;
        /* a moving instance at the ray's time, blended as Embree blends it */
        gi = geom_instance_at(a->gs, &a->gs->instances[i], ray->time, &moved);
        g = &a->levels[gi->master + 1].geoms[h->geomID];
        hit->instance = i + 1;
    } else {
        g = &a->levels[0].geoms[h->geomID];
    }
    hit->t = tfar;
    hit->shape = g->shape;
    switch (g->kind) {
    case KIND_TRIS:
        tri_hit(a, g, h->primID, h->u, h->v, embree_time(a, ray), normal, hit);
        break;
    case KIND_QUADS:
        quad_hit(a, g, h->primID, h->u, h->v, embree_time(a, ray), normal, hit);
        break;
    case KIND_PLANAR_TRIS:
        planar_tri_hit(a, g, h->primID, h->u, h->v, embree_time(a, ray), normal, hit);
        break;
    case KIND_CURVES:
        curve_hit(a, g, h, ray, gi, hit);
        break;
    case KIND_POINTS:
        point_hit(a, g, h, ray, tfar, gi, hit);
        break;
    case KIND_INSTANCE:
        RY_CHECK(!"an instance geometry hit as a primitive");
        break;
    }
    if (gi && !shape_flat(g->shape))
        hit->Ng = unit_or_zero(mat4_vector(&gi->normal_to_world, hit->Ng));
    return !normal &&
           (g->kind == KIND_TRIS || g->kind == KIND_QUADS || g->kind == KIND_PLANAR_TRIS);
}

/* The Ng make_hit left out of a quad's or triangle's hit. */
static void hit_normal(const Accel *a, const Ray *ray, Hit *hit)
{
    hit->Ng = mesh_normal(a->gs, hit, embree_time(a, ray));
    if (hit->instance) {
        GeomInstance moved;
        const GeomInstance *gi =
            geom_instance_at(a->gs, &a->gs->instances[hit->instance - 1], ray->time, &moved);
        hit->Ng = unit_or_zero(mat4_vector(&gi->normal_to_world, hit->Ng));
    }
}

/* What an intersection query carries: Embree hands the context to the
 * filter of transparent objects, which keeps every hit unless keep is set
 * (accel_intersect_stochastic). */
typedef struct IntersectCtx {
    struct RTCIntersectContext rtc; /* first: the filter casts back */
    const Accel *accel;
    const Ray *ray;
    AccelKeepFn keep;
    void *user;
    uint64_t key;
} IntersectCtx;

/* The nearest hit in scene (the world's or an object's own), under mask,
 * transparent objects' hits kept as ctx says (its ray and accel set here).
 * With embree_ng, a quad's or triangle's Ng is the one Embree found (of
 * the triangle of the cell it hit: the cell's own for a flat one, facing
 * the same way), and the micropolygon's vertices are not read. */
static int intersect_in(const Accel *a, RTCScene scene, const Ray *ray, uint32_t mask,
                        int embree_ng, IntersectCtx *ctx, Hit *hit)
{
    rtcInitIntersectContext(&ctx->rtc);
    ctx->accel = a;
    ctx->ray = ray;
    struct RTCRayHit rh;
    set_ray(a, &rh.ray, ray);
    rh.ray.mask = mask;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx->rtc, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    if (!embree_ng)
        make_hit(a, ray, &rh.hit, rh.ray.tfar, 1, hit);
    else if (make_hit(a, ray, &rh.hit, rh.ray.tfar, 0, hit))
        hit->Ng = unit_or_zero(v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    return 1;
}

static int intersect_scene(const Accel *a, RTCScene scene, const Ray *ray, uint32_t mask,
                           int embree_ng, Hit *hit)
{
    IntersectCtx ctx = {.keep = NULL};
    return intersect_in(a, scene, ray, mask, embree_ng, &ctx, hit);
}

void accel_attach_record(Accel *a, AccelRecord *record)
{
    a->record = record;
}

/* ------------------------------------------------------------ solids */

/* Whether point x is inside primitive solid k: within its bound, and the
 * nearest of its surfaces along d from x is met from behind (the solid's
 * inside lies behind its surfaces' fronts). */
static int inside_solid(const Accel *a, size_t k, Vec3 x, Vec3 d, float time)
{
    const Bounds3 *b = &a->solid_bound[k];
    if (!a->solid_scene[k] || x.x < b->lo.x || x.y < b->lo.y || x.z < b->lo.z ||
        x.x > b->hi.x || x.y > b->hi.y || x.z > b->hi.z)
        return 0;
    Ray r = {x, d, 0.0f, INFINITY, ~0u, time};
    Hit h;
    return intersect_scene(a, a->solid_scene[k], &r, ~0u, 1, &h) && v3_dot(h.Ng, d) > 0.0f;
}

/* Whether node k of a tree (indices from its root, 0) holds a point, the
 * primitive solids' states given (in[], per node). */
static int solid_holds(const GeomSolid *s, size_t k, size_t root, const uint8_t *in)
{
    if (s[k].op == GEOM_SOLID_PRIMITIVE)
        return in[k - root];
    int any = 0, all = 1, first = -1, rest = 0;
    for (size_t c = k + 1; c < s[k].end; c = s[c].end) {
        int h = solid_holds(s, c, root, in);
        any |= h, all &= h;
        if (first < 0)
            first = h;
        else
            rest |= h;
    }
    switch (s[k].op) {
    case GEOM_SOLID_UNION: return any;
    case GEOM_SOLID_INTERSECTION: return first >= 0 && all;
    default: return first > 0 && !rest; /* difference */
    }
}

#define SOLID_MAX_NODES 256 /* nodes of one tree a query classifies, at most */
#define SOLID_TREES 4       /* trees a query follows along the ray, at most */

/* Along one ray, a tree's primitive solids' states: found at the first
 * hit on the tree (a query per primitive solid), then changed at each of
 * its surfaces the ray crosses. */
typedef struct SolidWalk {
    size_t root, n;
    uint8_t in[SOLID_MAX_NODES];
} SolidWalk;

/* The nearest hit on the surface of a solid in [tnear, tfar]: the
 * solids' surfaces are found one after another (queries with
 * ACCEL_MASK_SOLID) until one lies on its tree's surface (the tree holds
 * the points just before and just after it differently) and is seen by
 * the ray's type. */
static int intersect_solids(const Accel *a, const Ray *ray, Hit *hit)
{
    const GeomSolid *s = a->gs->solids;
    SolidWalk walk[SOLID_TREES], spare;
    int n_walk = 0;
    Vec3 d = v3_normalize(ray->d);
    Ray r = *ray;
    for (int step = 0; step < 1024 && r.tnear <= r.tfar; step++) {
        if (!a->solids || !intersect_scene(a, a->solids, &r, ~0u, 0, hit))
            return 0;
        const Grid *g = &a->gs->grids[hit->grid];
        uint32_t mask = g->object < a->n_objects ? a->object_mask[g->object] : ~0u;
        size_t leaf = g->solid ? g->solid - 1 : 0, root = leaf;
        while (g->solid && s[root].parent)
            root = s[root].parent - 1;
        size_t n = s[root].end - root;
        if (!g->solid || n > SOLID_MAX_NODES) { /* too large to classify: drawn whole */
            if (mask & ray->mask)
                return 1;
        } else {
            SolidWalk *w = NULL;
            for (int k = 0; k < n_walk && !w; k++)
                if (walk[k].root == root)
                    w = &walk[k];
            if (!w) { /* the first hit on this tree: classify at the hit */
                w = n_walk < SOLID_TREES ? &walk[n_walk++] : &spare;
                w->root = root, w->n = n;
                Vec3 x = v3_madd(ray->o, ray->d, hit->t);
                for (size_t k = root; k < root + n; k++)
                    w->in[k - root] = s[k].op == GEOM_SOLID_PRIMITIVE && k != leaf &&
                                      inside_solid(a, k, x, d, ray->time);
            }
            int entering = v3_dot(hit->Ng, d) < 0.0f;
            w->in[leaf - root] = (uint8_t)!entering;
            int before = solid_holds(s, root, root, w->in);
            w->in[leaf - root] = (uint8_t)entering;
            if (solid_holds(s, root, root, w->in) != before && (mask & ray->mask))
                return 1;
        }
        r.tnear = nextafterf(hit->t, INFINITY) + 1e-6f * hit->t;
    }
    return 0;
}

/* The nearest hit in the world, transparent objects' hits kept as ctx
 * says, and on the solids. */
static int intersect_world(const Accel *a, const Ray *ray, IntersectCtx *ctx, Hit *hit)
{
    if (a->record)
        accel_record_ray(a->record, ACCEL_QUERY_INTERSECT, 0, ray);
    int found =
        intersect_in(a, a->levels[0].scene, ray, ray->mask & ~ACCEL_MASK_SOLID, 0, ctx, hit);
    if (!a->gs->n_solids)
        return found;
    Ray r = *ray;
    if (found)
        r.tfar = hit->t;
    Hit h;
    if (intersect_solids(a, &r, &h)) {
        *hit = h;
        return 1;
    }
    return found;
}

int accel_intersect(const Accel *a, const Ray *ray, Hit *hit)
{
    IntersectCtx ctx = {.keep = NULL};
    return intersect_world(a, ray, &ctx, hit);
}

int accel_intersect_object(const Accel *a, uint32_t object, const Ray *ray, Hit *hit)
{
    if (a->record)
        accel_record_ray(a->record, ACCEL_QUERY_INTERSECT_OBJECT, object, ray);
    if (object >= a->n_objects || !a->object_scene[object])
        return 0;
    return intersect_scene(a, a->object_scene[object], ray, ~0u, 1, hit);
}

struct AccelCrossing {
    const Accel *accel;
    const Ray *ray;
    int no_normal; /* make_hit left the hit's Ng out */
};

void accel_crossing_normal(const AccelCrossing *c, Hit *hit)
{
    if (c && c->no_normal)
        hit_normal(c->accel, c->ray, hit);
}

/* Crossings a transmission query remembers, to count each once. */
#define TRANSMISSION_SEEN 64

/* What an occlusion query through transparent objects carries: Embree
 * hands the context to the filter, which finds the rest behind it. */
typedef struct TransmissionCtx {
    struct RTCIntersectContext rtc; /* first: the filter casts back */
    const Accel *accel;
    const Ray *ray;
    AccelOpacityFn opacity;
    void *user;
    Vec3 T; /* the product so far */
    float roulette;   /* below it, crossings play Russian roulette */
    uint64_t ray_key; /* the ray's draws derive from it */
    int n_seen;
    struct {
        unsigned inst, geom, prim;
        float t;
    } seen[TRANSMISSION_SEEN];
} TransmissionCtx;

/* A number in [0, 1) for a hit of a query whose draws derive from key:
 * from the primitive and the place on it, so a hit Embree reports twice
 * draws the same. */
static float hit_draw(uint64_t key, const struct RTCHit *h)
{
    uint32_t u, v;
    memcpy(&u, &h->u, sizeof u);
    memcpy(&v, &h->v, sizeof v);
    uint64_t prim = hash_combine(((uint64_t)h->instID[0] << 32) ^ h->geomID, h->primID);
    return rng_float(hash_combine(hash_combine(key, prim), ((uint64_t)u << 32) | v));
}

/* A key from a ray's origin and direction (pbrt-v4 draws its stochastic
 * alpha from the same): shadow rays carry no sample key. */
static uint64_t ray_key(const Ray *ray)
{
    uint32_t b[6];
    memcpy(&b[0], &ray->o.x, sizeof b[0]);
    memcpy(&b[1], &ray->o.y, sizeof b[1]);
    memcpy(&b[2], &ray->o.z, sizeof b[2]);
    memcpy(&b[3], &ray->d.x, sizeof b[3]);
    memcpy(&b[4], &ray->d.y, sizeof b[4]);
    memcpy(&b[5], &ray->d.z, sizeof b[5]);
    return hash_combine(hash_combine(((uint64_t)b[0] << 32) | b[1], ((uint64_t)b[2] << 32) | b[3]),
                        ((uint64_t)b[4] << 32) | b[5]);
}

/* Embree's occlusion filter on transparent objects: multiplies the
 * query's transmittance by 1 - opacity and rejects the hit (traversal goes
 * on), unless the product has reached 0 (the hit stands: occluded). A hit
 * already seen (same primitive, same distance: a primitive referenced from
 * two BVH leaves) is rejected without counting. */
static void transmission_filter(const struct RTCFilterFunctionNArguments *args)
{
    RY_CHECK(args->N == 1);
    if (args->valid[0] != -1)
        return;
    TransmissionCtx *tc = (TransmissionCtx *)args->context;
    const struct RTCHit *h = (const struct RTCHit *)args->hit;
    /* Inside an instance, args->ray is in master space: its tfar is the
     * same parameter along the world ray, which make_hit uses. */
    float tfar = ((const struct RTCRay *)args->ray)->tfar;
    for (int k = 0; k < tc->n_seen; k++)
        if (tc->seen[k].inst == h->instID[0] && tc->seen[k].geom == h->geomID &&
            tc->seen[k].prim == h->primID &&
            fabsf(tc->seen[k].t - tfar) <= 1e-6f * fmaxf(1.0f, tfar)) {
            args->valid[0] = 0;
            return;
        }
    if (tc->n_seen < TRANSMISSION_SEEN) {
        tc->seen[tc->n_seen].inst = h->instID[0];
        tc->seen[tc->n_seen].geom = h->geomID;
        tc->seen[tc->n_seen].prim = h->primID;
        tc->seen[tc->n_seen].t = tfar;
        tc->n_seen++;
    }
    Hit hit;
    AccelCrossing crossing = {tc->accel, tc->ray, 0};
    crossing.no_normal = make_hit(tc->accel, tc->ray, h, tfar, 0, &hit);
    Vec3 op = tc->opacity(tc->user, tc->ray, &hit, &crossing);
    Vec3 t = v3(1.0f - fminf(fmaxf(op.x, 0.0f), 1.0f), 1.0f - fminf(fmaxf(op.y, 0.0f), 1.0f),
                1.0f - fminf(fmaxf(op.z, 0.0f), 1.0f));
    if (v3_max_component(tc->T) < tc->roulette) {
        float q = v3_max_component(t);
        t = hit_draw(tc->ray_key, h) < q ? v3_scale(t, 1.0f / q) : v3(0, 0, 0);
    }
    tc->T = v3_mul(tc->T, t);
    if (v3_max_component(tc->T) > 0.0f)
        args->valid[0] = 0; /* seen through: look further */
}

Vec3 accel_transmission(const Accel *a, const Ray *ray, AccelOpacityFn opacity, void *user,
                        float roulette)
{
    if (a->record)
        accel_record_ray(a->record, ACCEL_QUERY_TRANSMISSION, 0, ray);
    TransmissionCtx tc;
    rtcInitIntersectContext(&tc.rtc);
    tc.accel = a;
    tc.ray = ray;
    tc.opacity = opacity;
    tc.user = user;
    tc.T = v3(1, 1, 1);
    tc.roulette = roulette;
    tc.ray_key = roulette > 0.0f ? ray_key(ray) : 0;
    tc.n_seen = 0;
    Hit h;
    if (a->gs->n_solids && intersect_solids(a, ray, &h))
        return v3(0, 0, 0);
    struct RTCRay r;
    set_ray(a, &r, ray);
    rtcOccluded1(a->levels[0].scene, &tc.rtc, &r);
    return r.tfar < 0.0f ? v3(0, 0, 0) : tc.T;
}

/* Embree's intersection filter on transparent objects: with a keep
 * function, passes the hit unless a number drawn from the query's key and
 * the hit falls below the probability of keeping it. */
static void keep_filter(const struct RTCFilterFunctionNArguments *args)
{
    RY_CHECK(args->N == 1);
    const IntersectCtx *ic = (const IntersectCtx *)args->context;
    if (args->valid[0] != -1 || !ic->keep)
        return;
    const struct RTCHit *h = (const struct RTCHit *)args->hit;
    float tfar = ((const struct RTCRay *)args->ray)->tfar; /* as in transmission_filter */
    Hit hit;
    AccelCrossing crossing = {ic->accel, ic->ray, 0};
    crossing.no_normal = make_hit(ic->accel, ic->ray, h, tfar, 0, &hit);
    if (!(hit_draw(ic->key, h) < ic->keep(ic->user, ic->ray, &hit, &crossing)))
        args->valid[0] = 0;
}

int accel_intersect_stochastic(const Accel *a, const Ray *ray, AccelKeepFn keep, void *user,
                               uint64_t key, Hit *hit)
{
    IntersectCtx ctx = {.keep = keep, .user = user, .key = key};
    return intersect_world(a, ray, &ctx, hit);
}

int accel_occluded(const Accel *a, const Ray *ray)
{
    if (a->record)
        accel_record_ray(a->record, ACCEL_QUERY_OCCLUDED, 0, ray);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    set_ray(a, &r, ray);
    rtcOccluded1(a->levels[0].scene, &ctx, &r);
    if (r.tfar < 0.0f)
        return 1;
    Hit h;
    return a->gs->n_solids && intersect_solids(a, ray, &h);
}

size_t accel_memory_bytes(const Accel *a)
{
    long long b = atomic_load(&a->bytes);
    return b > 0 ? (size_t)b : 0;
}
