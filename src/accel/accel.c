/*
 * accel/accel.c — the Embree 3 implementation of accel.h.
 *
 * Layout: per object with quad grids, one RTC_GEOMETRY_TYPE_GRID whose
 * grid buffer lists its grids (startVertexID = the grid's first vertex in
 * the shared vertex array, stride = nu); per object with triangular grids,
 * one RTC_GEOMETRY_TYPE_TRIANGLE whose index buffer lists every
 * micropolygon; per object with curves, one ROUND_ or FLAT_LINEAR_CURVE
 * through the centre lines of their grids; per object with points, one
 * SPHERE_ or DISC_POINT, a point per grid. Geom records map (geomID,
 * primID) back to grids.
 *
 * Motion blur: the quad and triangle geometries of an object with a moving
 * grid have the GridSet's n_times time steps over Embree's time range
 * [0, 1], each a vertex buffer of their own (Geom.steps: the grids'
 * vertices one grid after another, still grids copied); a ray's time maps
 * onto the range (clamped). Other geometries share GridSet.P. Curves and
 * points stay still.
 *
 * Embree with TBB builds on its own threads; commit happens once, before
 * any query, and queries are concurrent (Embree's contract).
 */
#include "accel/accel.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/check.h"

typedef struct MicroTri {
    uint32_t grid;     /* patch id */
    uint8_t i, j;      /* lattice position of the cell */
    uint8_t upper;     /* 0: (i,j),(i+1,j),(i,j+1); 1: (i+1,j),(i+1,j+1),(i,j+1) */
} MicroTri;

typedef struct CurveSeg {
    uint32_t grid;     /* patch id */
    uint32_t i;        /* the segment from centre-line vertex i to i + 1 */
} CurveSeg;

typedef enum GeomKind { KIND_QUADS, KIND_TRIS, KIND_CURVES, KIND_POINTS } GeomKind;

typedef struct Geom {
    GeomKind kind;
    uint8_t shape;     /* GeomShape of its grids */
    uint32_t *grids;   /* quads, points: primID -> grid index */
    MicroTri *tris;    /* triangles: primID -> micropolygon */
    CurveSeg *segs;    /* curves: primID -> segment */
    Vec3 *steps;       /* a moving geometry's vertices, owned: per time sample, its grids'
                          vertices one grid after another (set_vertices) */
} Geom;

struct Accel {
    RTCDevice device;
    RTCScene scene;
    const GridSet *gs;
    Geom *geoms;       /* indexed by geomID */
    size_t n_geoms;
    atomic_llong bytes; /* Embree's allocations, from the memory monitor */
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

static int add_geom(Accel *a, Geom g)
{
    Geom *geoms = realloc(a->geoms, (a->n_geoms + 1) * sizeof *geoms);
    if (!geoms)
        return -1;
    a->geoms = geoms;
    a->geoms[a->n_geoms++] = g;
    return 0;
}

static void transmission_filter(const struct RTCFilterFunctionNArguments *args);

/* Commits geom with its ray mask into the scene as the next geometry,
 * whose primitives map back to grids through g. */
static int attach(Accel *a, RTCGeometry geom, uint32_t mask, Geom g)
{
    if (mask & ACCEL_MASK_TRANSPARENT)
        rtcSetGeometryOccludedFilterFunction(geom, transmission_filter);
    rtcSetGeometryMask(geom, mask & ~ACCEL_MASK_TRANSPARENT);
    rtcCommitGeometry(geom);
    unsigned id = rtcAttachGeometry(a->scene, geom);
    rtcReleaseGeometry(geom);
    RY_CHECK(id == a->n_geoms);
    return add_geom(a, g);
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

static int build_quads(Accel *a, const uint32_t *idx, size_t n, uint32_t mask)
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
    return attach(a, geom, mask, g);
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

static int build_tris(Accel *a, const uint32_t *idx, size_t n, uint32_t mask)
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
    return attach(a, geom, mask, g);
}

/* A curve grid's centre line: vertex i of its 2 rows, midway, and half
 * the distance between them (the radius). */
static void centre_vertex(const GridSet *gs, const Grid *g, uint32_t i, float out[4])
{
    Vec3 a = gs->P[g->first_vertex + i], b = gs->P[g->first_vertex + g->nu + i];
    Vec3 c = v3_scale(v3_add(a, b), 0.5f);
    out[0] = c.x, out[1] = c.y, out[2] = c.z;
    out[3] = 0.5f * v3_length(v3_sub(b, a));
}

/* Curve grids (2 rows: the ribbon diced facing the eye) as Embree linear
 * curves through their centre lines, round (tubes) or flat (ribbons that
 * face each ray); Embree joins the segments of one grid, and ends each
 * grid's run with a sphere (round), which fills the joint to the next. */
static int build_curves(Accel *a, const uint32_t *idx, size_t n, uint32_t mask, int shape)
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
    float(*vtx)[4] = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                             4 * sizeof(float), n_vtx);
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
            centre_vertex(gs, src, i, vtx[v + i]);
            if (i + 1 < src->nu) {
                index[t] = (uint32_t)(v + i);
                g.segs[t++] = (CurveSeg){idx[k], i};
            }
        }
        v += src->nu;
    }
    return attach(a, geom, mask, g);
}

static Vec3 unit_or_zero(Vec3 n);

/* The corners of a point grid's square: (0,0), (1,0), (0,1). */
static void point_square(const GridSet *gs, const Grid *g, Vec3 *o, Vec3 *x, Vec3 *y)
{
    uint32_t b = g->first_vertex;
    *o = gs->P[b];
    *x = v3_sub(gs->P[b + g->nu - 1u], *o);
    *y = v3_sub(gs->P[b + (uint32_t)(g->nv - 1) * g->nu], *o);
}

/* Point grids as Embree spheres or ray-facing disks inscribed in their
 * squares. */
static int build_points(Accel *a, const uint32_t *idx, size_t n, uint32_t mask, int shape)
{
    const GridSet *gs = a->gs;
    RTCGeometry geom = rtcNewGeometry(a->device, shape == GEOM_SHAPE_SPHERE
                                                     ? RTC_GEOMETRY_TYPE_SPHERE_POINT
                                                 : shape == GEOM_SHAPE_DISK
                                                     ? RTC_GEOMETRY_TYPE_DISC_POINT
                                                     : RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    float(*vtx)[4] = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                             4 * sizeof(float), n);
    float(*nrm)[3] = shape == GEOM_SHAPE_ORIENTED_DISK
                         ? rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0,
                                                   RTC_FORMAT_FLOAT3, 3 * sizeof(float), n)
                         : NULL;
    Geom g = {.kind = KIND_POINTS, .shape = (uint8_t)shape, .grids = malloc(n * sizeof(uint32_t))};
    if (!vtx || !g.grids || (shape == GEOM_SHAPE_ORIENTED_DISK && !nrm)) {
        free(g.grids);
        rtcReleaseGeometry(geom);
        return -1;
    }
    for (size_t k = 0; k < n; k++) {
        Vec3 o, x, y;
        point_square(gs, &gs->grids[idx[k]], &o, &x, &y);
        Vec3 c = v3_add(o, v3_scale(v3_add(x, y), 0.5f));
        vtx[k][0] = c.x, vtx[k][1] = c.y, vtx[k][2] = c.z;
        vtx[k][3] = 0.5f * v3_length(x);
        if (nrm) {
            Vec3 N = unit_or_zero(v3_cross(x, y));
            nrm[k][0] = N.x, nrm[k][1] = N.y, nrm[k][2] = N.z;
        }
        g.grids[k] = idx[k];
    }
    return attach(a, geom, mask, g);
}

/* The kinds of grids an object may have, each one Embree geometry. */
enum {
    GROUP_QUADS,
    GROUP_TRIS,
    GROUP_ROUND,
    GROUP_FLAT,
    GROUP_SPHERES,
    GROUP_DISKS,
    GROUP_ORIENTED,
    N_GROUPS
};

static int grid_group(const Grid *g)
{
    switch (g->shape) {
    case GEOM_SHAPE_ROUND_CURVE: return GROUP_ROUND;
    case GEOM_SHAPE_FLAT_CURVE: return GROUP_FLAT;
    case GEOM_SHAPE_SPHERE: return GROUP_SPHERES;
    case GEOM_SHAPE_DISK: return GROUP_DISKS;
    case GEOM_SHAPE_ORIENTED_DISK: return GROUP_ORIENTED;
    default: return g->triangular ? GROUP_TRIS : GROUP_QUADS;
    }
}

/* Adds the geometries of one object: its quad grids, its triangular, then
 * its curves and points. */
static int build_object(Accel *a, uint32_t object, uint32_t mask, uint32_t *scratch)
{
    const GridSet *gs = a->gs;
    for (int group = 0; group < N_GROUPS; group++) {
        size_t n = 0;
        for (size_t k = 0; k < gs->n_grids; k++)
            if (gs->grids[k].object == object && grid_group(&gs->grids[k]) == group)
                scratch[n++] = (uint32_t)k;
        if (n == 0)
            continue;
        int rc;
        switch (group) {
        case GROUP_QUADS: rc = build_quads(a, scratch, n, mask); break;
        case GROUP_TRIS: rc = build_tris(a, scratch, n, mask); break;
        case GROUP_ROUND: rc = build_curves(a, scratch, n, mask, GEOM_SHAPE_ROUND_CURVE); break;
        case GROUP_FLAT: rc = build_curves(a, scratch, n, mask, GEOM_SHAPE_FLAT_CURVE); break;
        case GROUP_SPHERES: rc = build_points(a, scratch, n, mask, GEOM_SHAPE_SPHERE); break;
        case GROUP_DISKS: rc = build_points(a, scratch, n, mask, GEOM_SHAPE_DISK); break;
        default: rc = build_points(a, scratch, n, mask, GEOM_SHAPE_ORIENTED_DISK); break;
        }
        if (rc != 0)
            return -1;
    }
    return 0;
}

Accel *accel_new(const GridSet *gs, const uint32_t *object_mask, size_t n_objects, char *err,
                 size_t err_size)
{
    Accel *a = calloc(1, sizeof *a);
    uint32_t *scratch = malloc((gs->n_grids + 1) * sizeof *scratch);
    if (!a || !scratch) {
        free(a);
        free(scratch);
        snprintf(err, err_size, "out of memory building the ray tracing structure");
        return NULL;
    }
    a->gs = gs;
    atomic_init(&a->bytes, 0);
    a->device = rtcNewDevice("verbose=0");
    if (!a->device) {
        snprintf(err, err_size, "cannot create an Embree device (error %d)",
                 (int)rtcGetDeviceError(NULL));
        free(a);
        free(scratch);
        return NULL;
    }
    rtcSetDeviceErrorFunction(a->device, on_error, a);
    rtcSetDeviceMemoryMonitorFunction(a->device, on_memory, a);
    a->scene = rtcNewScene(a->device);
    /* Watertight intersection: without it Embree's fast path lets rays
     * slip between micropolygons that share an edge, inside a grid and
     * between stitched grids (tests/render/test_watertight.c). */
    rtcSetSceneFlags(a->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(a->scene, RTC_BUILD_QUALITY_MEDIUM);
    int rc = 0;
    for (size_t o = 0; o < n_objects && rc == 0; o++)
        rc = build_object(a, (uint32_t)o, object_mask[o], scratch);
    free(scratch);
    if (rc == 0)
        rtcCommitScene(a->scene);
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
    for (size_t k = 0; k < a->n_geoms; k++) {
        free(a->geoms[k].grids);
        free(a->geoms[k].tris);
        free(a->geoms[k].segs);
        free(a->geoms[k].steps);
    }
    free(a->geoms);
    if (a->scene)
        rtcReleaseScene(a->scene);
    if (a->device)
        rtcReleaseDevice(a->device);
    free(a);
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
    const GridSet *gs = a->gs;
    float span = gs->time[1] - gs->time[0];
    float t = gs->n_times > 1 && span > 0.0f ? (ray->time - gs->time[0]) / span : 0.0f;
    r->time = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    r->mask = ray->mask;
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

static void quad_hit(const Accel *a, const Geom *g, unsigned prim, float u, float v, float rt,
                     Hit *hit)
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
    Vec3 P[4];
    for (int k = 0; k < 4; k++)
        P[k] = vertex_at(gs, grid, hit->vertex[k], rt);
    /* The cell normal from its diagonals: 2 dPdu x dPdv for a parallelogram. */
    hit->Ng = unit_or_zero(v3_cross(v3_sub(P[3], P[0]), v3_sub(P[2], P[1])));
}

static void tri_hit(const Accel *a, const Geom *g, unsigned prim, float u, float v, float rt,
                    Hit *hit)
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
    Vec3 P[3];
    for (int k = 0; k < 3; k++)
        P[k] = vertex_at(gs, grid, vtx[k], rt);
    hit->Ng = unit_or_zero(v3_cross(v3_sub(P[1], P[0]), v3_sub(P[2], P[0])));
}

/* Embree's geometric normal of a round shape's hit; a flat one faces the
 * ray. */
static Vec3 shape_normal(const struct RTCRayHit *rh, int shape)
{
    if (shape == GEOM_SHAPE_ROUND_CURVE || shape == GEOM_SHAPE_SPHERE ||
        shape == GEOM_SHAPE_ORIENTED_DISK)
        return unit_or_zero(v3(rh->hit.Ng_x, rh->hit.Ng_y, rh->hit.Ng_z));
    return unit_or_zero(v3(-rh->ray.dir_x, -rh->ray.dir_y, -rh->ray.dir_z));
}

/* A curve segment's hit: u along it, half way across the grid's 2 rows. */
static void curve_hit(const Accel *a, const Geom *g, const struct RTCRayHit *rh, Hit *hit)
{
    const CurveSeg *seg = &g->segs[rh->hit.primID];
    const Grid *grid = &a->gs->grids[seg->grid];
    float u = fminf(fmaxf(rh->hit.u, 0.0f), 1.0f);
    uint32_t b = grid->first_vertex + seg->i, w = grid->nu;
    hit->grid = seg->grid;
    hit->gu = ((float)seg->i + u) / (float)(w - 1u);
    hit->gv = 0.5f;
    hit->n_vertex = 4;
    const uint32_t vtx[4] = {b, b + 1, b + w, b + w + 1};
    const float wt[4] = {0.5f * (1.0f - u), 0.5f * u, 0.5f * (1.0f - u), 0.5f * u};
    memcpy(hit->vertex, vtx, sizeof vtx);
    memcpy(hit->weight, wt, sizeof wt);
    hit->Ng = shape_normal(rh, g->shape);
}

/* A point's hit: where the hit projects on its square. */
static void point_hit(const Accel *a, const Geom *g, const struct RTCRayHit *rh, Hit *hit)
{
    const GridSet *gs = a->gs;
    const Grid *grid = &gs->grids[g->grids[rh->hit.primID]];
    Vec3 o, x, y;
    point_square(gs, grid, &o, &x, &y);
    Vec3 p = v3(rh->ray.org_x + rh->ray.tfar * rh->ray.dir_x,
                rh->ray.org_y + rh->ray.tfar * rh->ray.dir_y,
                rh->ray.org_z + rh->ray.tfar * rh->ray.dir_z);
    Vec3 d = v3_sub(p, o);
    float xx = v3_dot(x, x), yy = v3_dot(y, y);
    float u = xx > 0.0f ? fminf(fmaxf(v3_dot(d, x) / xx, 0.0f), 1.0f) : 0.5f;
    float v = yy > 0.0f ? fminf(fmaxf(v3_dot(d, y) / yy, 0.0f), 1.0f) : 0.5f;
    quad_hit(a, g, rh->hit.primID, u, v, 0.0f, hit);
    hit->Ng = shape_normal(rh, g->shape);
}

/* The Hit of Embree's hit rh (tfar its distance). */
static void make_hit(const Accel *a, const struct RTCRayHit *rh, Hit *hit)
{
    const Geom *g = &a->geoms[rh->hit.geomID];
    hit->t = rh->ray.tfar;
    hit->shape = g->shape;
    switch (g->kind) {
    case KIND_TRIS:
        tri_hit(a, g, rh->hit.primID, rh->hit.u, rh->hit.v, rh->ray.time, hit);
        break;
    case KIND_QUADS:
        quad_hit(a, g, rh->hit.primID, rh->hit.u, rh->hit.v, rh->ray.time, hit);
        break;
    case KIND_CURVES:
        curve_hit(a, g, rh, hit);
        break;
    case KIND_POINTS:
        point_hit(a, g, rh, hit);
        break;
    }
}

int accel_intersect(const Accel *a, const Ray *ray, Hit *hit)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    set_ray(a, &rh.ray, ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(a->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    make_hit(a, &rh, hit);
    return 1;
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
    int n_seen;
    struct {
        unsigned geom, prim;
        float t;
    } seen[TRANSMISSION_SEEN];
} TransmissionCtx;

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
    struct RTCRayHit rh;
    rh.ray = *(const struct RTCRay *)args->ray;
    rh.hit = *(const struct RTCHit *)args->hit;
    for (int k = 0; k < tc->n_seen; k++)
        if (tc->seen[k].geom == rh.hit.geomID && tc->seen[k].prim == rh.hit.primID &&
            fabsf(tc->seen[k].t - rh.ray.tfar) <= 1e-6f * fmaxf(1.0f, rh.ray.tfar)) {
            args->valid[0] = 0;
            return;
        }
    if (tc->n_seen < TRANSMISSION_SEEN) {
        tc->seen[tc->n_seen].geom = rh.hit.geomID;
        tc->seen[tc->n_seen].prim = rh.hit.primID;
        tc->seen[tc->n_seen].t = rh.ray.tfar;
        tc->n_seen++;
    }
    Hit hit;
    make_hit(tc->accel, &rh, &hit);
    Vec3 op = tc->opacity(tc->user, tc->ray, &hit);
    tc->T = v3(tc->T.x * (1.0f - fminf(fmaxf(op.x, 0.0f), 1.0f)),
               tc->T.y * (1.0f - fminf(fmaxf(op.y, 0.0f), 1.0f)),
               tc->T.z * (1.0f - fminf(fmaxf(op.z, 0.0f), 1.0f)));
    if (v3_max_component(tc->T) > 0.0f)
        args->valid[0] = 0; /* seen through: look further */
}

Vec3 accel_transmission(const Accel *a, const Ray *ray, AccelOpacityFn opacity, void *user)
{
    TransmissionCtx tc;
    rtcInitIntersectContext(&tc.rtc);
    tc.accel = a;
    tc.ray = ray;
    tc.opacity = opacity;
    tc.user = user;
    tc.T = v3(1, 1, 1);
    tc.n_seen = 0;
    struct RTCRay r;
    set_ray(a, &r, ray);
    rtcOccluded1(a->scene, &tc.rtc, &r);
    return r.tfar < 0.0f ? v3(0, 0, 0) : tc.T;
}

int accel_occluded(const Accel *a, const Ray *ray)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    set_ray(a, &r, ray);
    rtcOccluded1(a->scene, &ctx, &r);
    return r.tfar < 0.0f;
}

size_t accel_memory_bytes(const Accel *a)
{
    long long b = atomic_load(&a->bytes);
    return b > 0 ? (size_t)b : 0;
}
