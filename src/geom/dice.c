/*
 * geom/dice.c — splitting primitives into patches and dicing patches into
 * grids (DESIGN.md "Geometry: patches and grids").
 *
 * A patch domain is a rectangle [u0,u1] x [v0,v1] of the primitive's
 * parameters, or for triangles a sub-triangle given by three barycentric
 * corners. Its size is estimated on a 5 x 5 lattice of surface points. As
 * in RenderMan, a quad domain whose grid at the camera's rate would hold
 * more than gridsize micropolygons (256 by default, or more than
 * GEOM_MAX_GRID - 1 along a side) is split in two across its longer
 * direction; a triangle needing more than sqrt(gridsize) subdivisions per
 * edge (so more than gridsize micro-triangles) is bisected across its long
 * edge while it is thin, then made three quads. Each part is estimated
 * again, nearer parts getting
 * finer rates. The area rule gives grids of 128 to 256 micropolygons where
 * a per-side rule of 16 gave 64 to 256: on the benchmark box at 1024 x 1024,
 * 17,158 grids of 3.61 M vertices, against the memo's "approximately 18,000
 * micropolygon grids with a total of 3.9 million grid vertices" (the
 * per-side rule made 24,144). Splitting is depth-first in a fixed order,
 * so patch ids are deterministic.
 */
#include "geom/geom.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/check.h"
#include "util/grow.h"

#define LATTICE 5           /* estimation lattice, per side */
#define MAX_SPLIT_DEPTH 48  /* a bound on recursion for degenerate input */
#define SLIVER_MIN_RATE 4   /* a sliver diced finer than this along its length: sliver_shape */

typedef struct Domain {
    float c[3][2]; /* quad: c[0] = (u0, v0), c[1] = (u1, v1); triangle: three corners */
    int triangular;
    /* A quad over part of a triangle (sub_quad): c[0], c[1] bound a
     * rectangle of the quad's own (s, t), and q holds the quad's corners
     * (s, t) = (0,0), (1,0), (0,1), (1,1) as the triangle's barycentric
     * (u, v), interpolated bilinearly. */
    int sub_quad;
    float q[4][2];
    float tri[3][2]; /* sub_quad: the triangle's corners, and the one q[0] is */
    int corner;
} Domain;

typedef struct Estimate {
    int n_u, n_v;  /* micropolygons needed along u and v (triangle: n_u per edge) */
    int thin_edge; /* triangle: its longest edge when thin (tri_shape) in the lattice's
                      space, to bisect when it must split, or -1 */
    int needle;    /* triangle: a needle's apex + 1 (sliver_shape), or 0 */
    int cap;       /* triangle: a thin one's long edge + 1 when it is less than a
                      micropolygon high (sliver_shape), or 0 */
    double foot;   /* a cap's split: its apex's foot on that edge, as a dyadic fraction */
} Estimate;

void geom_gridset_init(GridSet *gs)
{
    memset(gs, 0, sizeof *gs);
}

void geom_gridset_fini(GridSet *gs)
{
    free(gs->grids);
    free(gs->subs);
    free(gs->grid_cluster);
    free(gs->clusters);
    free(gs->P);
    free(gs->N);
    free(gs->dPdu);
    free(gs->dPdv);
    free(gs->uv);
    free(gs->Ns);
    free(gs->st);
    free(gs->dst);
    free(gs->Cs);
    free(gs->Os);
    free(gs->instances);
    free(gs->instance_motion);
    free(gs->solids);
    for (int k = 0; k < GEOM_MAX_TIMES - 1; k++) {
        free(gs->Pt[k]);
        free(gs->Nt[k]);
        free(gs->dPdut[k]);
        free(gs->dPdvt[k]);
    }
    memset(gs, 0, sizeof *gs);
}

int geom_instance_set(GeomInstance *gi, Mat4 world_from_master)
{
    gi->world_from_master = world_from_master;
    if (!mat4_invert(world_from_master, &gi->master_from_world))
        return -1;
    const float(*a)[4] = world_from_master.m;
    float det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    gi->normal_to_world = mat4_transpose(gi->master_from_world);
    if (det < 0.0f) /* mirrored: keep N on the side of dPdu x dPdv */
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                gi->normal_to_world.m[r][c] = -gi->normal_to_world.m[r][c];
    gi->scale = cbrtf(fabsf(det));
    return 0;
}

const GeomInstance *geom_instance_at(const GridSet *gs, const GeomInstance *gi, float t,
                                     GeomInstance *tmp)
{
    if (!gi || !gi->motion || gs->n_times < 2)
        return gi;
    float f;
    int seg = geom_motion_segment(gs, t, &f);
    const Mat4 *M = &gs->instance_motion[(size_t)(gi->motion - 1) * (size_t)gs->n_times];
    Mat4 m;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            m.m[i][j] = M[seg].m[i][j] + (M[seg + 1].m[i][j] - M[seg].m[i][j]) * f;
    *tmp = *gi;
    if (geom_instance_set(tmp, m) != 0)
        return gi; /* a blend that is singular (a flip through zero): the first sample */
    return tmp;
}

/* The primitive's (u, v) at lattice position (a, b) in [0,1]^2 of a domain
 * (for triangles a + b <= 1 addresses the sub-triangle barycentrically). */
static void domain_uv(const Domain *d, float a, float b, float *u, float *v)
{
    if (!d->triangular) {
        *u = d->c[0][0] + (d->c[1][0] - d->c[0][0]) * a;
        *v = d->c[0][1] + (d->c[1][1] - d->c[0][1]) * b;
        if (d->sub_quad) {
            float s = *u, t = *v, w[4] = {(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t};
            *u = *v = 0.0f;
            for (int k = 0; k < 4; k++)
                *u += w[k] * d->q[k][0], *v += w[k] * d->q[k][1];
        }
    } else {
        float w = 1.0f - a - b;
        *u = w * d->c[0][0] + a * d->c[1][0] + b * d->c[2][0];
        *v = w * d->c[0][1] + a * d->c[1][1] + b * d->c[2][1];
    }
}

static Vec3 domain_point(const Prim *prim, const Domain *d, float a, float b)
{
    Vec3 P, du, dv;
    float u, v;
    domain_uv(d, a, b, &u, &v);
    geom_prim_eval(prim, u, v, &P, &du, &dv);
    return P;
}

/* Where a domain's lattice lies, for choosing how it is measured. */
typedef enum ViewPlace {
    VIEW_NONE,     /* no view: by distance */
    VIEW_ON,       /* may be on screen, in front of the eye: by raster size */
    VIEW_CROSSING, /* crosses the eye plane: by distance, no off-screen factor */
    VIEW_OFF       /* off screen: by distance, with the off-screen factor */
} ViewPlace;

/* Classifies the n lattice points p against the view; writes their screen
 * positions (VIEW_ON) into s, and how far outside the frustum the lattice
 * is (VIEW_OFF), as a fraction of the ramp over which the off-screen
 * factor grows (half the frame), into outside.
 *
 * A lattice is off screen when all its points lie beyond one side plane
 * of the frustum (the test is conservative: a lattice beside a corner may
 * count as on screen). Perspective side planes pass through the eye, so
 * points behind the eye are classified too, and how far beyond a plane a
 * point lies is an angle (its sine: the distance to the plane over the
 * distance from the eye); orthographic planes are parallel, and the
 * distance is in screen units. Points behind the eye plane (orthographic)
 * are off screen however far to the side. */
static ViewPlace view_place(const DiceCamera *cam, const Vec3 *p, int n, float (*s)[2],
                            float *outside)
{
    if (!cam->has_view)
        return VIEW_NONE;
    const float t = cam->tan_half_fov;
    float lo[2] = {fminf(cam->screen[0], cam->screen[1]), fminf(cam->screen[2], cam->screen[3])};
    float hi[2] = {fmaxf(cam->screen[0], cam->screen[1]), fmaxf(cam->screen[2], cam->screen[3])};
    float half = 0.5f * (hi[1] - lo[1]); /* the ramp, in screen units */
    /* beyond[side]: the smallest excess over the points, sides left,
     * right, bottom, top. */
    float beyond[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    int near = 0, behind = 0;
    for (int k = 0; k < n; k++) {
        Vec3 c = mat4_point(&cam->camera_from_world, p[k]);
        float xy[2] = {c.x, c.y};
        for (int axis = 0; axis < 2; axis++) {
            float below, above;
            if (t > 0.0f) {
                /* Signed distances to the planes x = lo t z and x = hi t z
                 * (outward positive), over the distance from the eye. */
                float r = fmaxf(v3_length(c), 1e-30f);
                below = (lo[axis] * t * c.z - xy[axis]) /
                        (r * sqrtf(1.0f + lo[axis] * lo[axis] * t * t));
                above = (xy[axis] - hi[axis] * t * c.z) /
                        (r * sqrtf(1.0f + hi[axis] * hi[axis] * t * t));
            } else {
                below = lo[axis] - xy[axis];
                above = xy[axis] - hi[axis];
            }
            beyond[2 * axis] = fminf(beyond[2 * axis], below);
            beyond[2 * axis + 1] = fminf(beyond[2 * axis + 1], above);
        }
        near += t > 0.0f && c.z <= cam->min_distance;
        behind += c.z < 0.0f;
        if (c.z > cam->min_distance || t == 0.0f) {
            float d = t > 0.0f ? c.z * t : 1.0f;
            s[k][0] = c.x / d, s[k][1] = c.y / d;
        }
    }
    float out = fmaxf(fmaxf(beyond[0], beyond[1]), fmaxf(beyond[2], beyond[3]));
    if (t > 0.0f) /* the sine of the angle of half the frame's height */
        half = half * t / sqrtf(1.0f + half * half * t * t);
    if (t == 0.0f && behind == n)
        out = INFINITY;
    if (out > 0.0f) {
        *outside = out / half;
        return VIEW_OFF;
    }
    return near ? VIEW_CROSSING : VIEW_ON;
}

/* Lengths of the lattice lines along u (rows) and v (columns), and for
 * triangles along the third edge, c1 -> c2 (the diagonals): the longest
 * line of each direction. */
static void lattice_lengths(const Vec3 (*p)[LATTICE], int triangular, float len[3])
{
    const int last = LATTICE - 1;
    len[0] = len[1] = len[2] = 0.0f;
    for (int j = 0; j < LATTICE; j++) {
        float lu = 0.0f, lv = 0.0f;
        int end = triangular ? last - j : last; /* last i (or j) of the line */
        for (int i = 0; i < end; i++) {
            lu += v3_length(v3_sub(p[j][i + 1], p[j][i]));
            lv += v3_length(v3_sub(p[i + 1][j], p[i][j]));
        }
        len[0] = fmaxf(len[0], lu);
        len[1] = fmaxf(len[1], lv);
    }
    if (triangular)
        for (int j = 0; j < last; j++)
            len[2] += v3_length(v3_sub(p[j + 1][last - 1 - j], p[j][last - j]));
}

/* A triangle's shape from its corners: edge k's length (corner k to
 * k + 1), its shortest and longest edges (the first of equals), twice its
 * area, and whether it is thin: its longest edge more than three times
 * its height above it. A triangle that must split and is thin in the
 * lattice's space is bisected across that edge (Estimate.thin_edge; else
 * split_quads): split in four, a thin triangle kept its shape and its
 * grids of slivers grew with the square of its length; bisected across
 * its long edge it grows fatter. */
typedef struct TriShape {
    float l[3], area2;
    int lo, hi, thin;
} TriShape;

static TriShape tri_shape(const Vec3 *c)
{
    TriShape t = {.lo = 0, .hi = 0};
    for (int k = 0; k < 3; k++) {
        t.l[k] = v3_length(v3_sub(c[(k + 1) % 3], c[k]));
        t.lo = t.l[k] < t.l[t.lo] ? k : t.lo;
        t.hi = t.l[k] > t.l[t.hi] ? k : t.hi;
    }
    t.area2 = v3_length(v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0])));
    t.thin = t.l[t.hi] > 0.0f && t.l[t.hi] * t.l[t.hi] > 3.0f * t.area2;
    return t;
}

/* A sliver of a triangle: w holds its corners in space, r its shape in
 * the lattice's (raster or space), unit the micropolygon's edge there. A
 * needle in space (its shortest edge at most a quarter of its longest)
 * whose short edge is at most four micropolygons long gets *needle = the
 * corner across that edge + 1 (dice_fan); another thin triangle
 * less than a micropolygon high gets *cap = its long edge + 1 and *foot
 * the point of that edge to split it at (into two needles). A triangular grid has one
 * rate for its three edges and gave a sliver its long edge's rate across
 * its width too: on Bitterli's staircase, slivers 13 pixels long and 0.3
 * wide took 153 vertices each where a strip of 16 quads along them takes
 * 34. The shape is the one in space: a wall seen edge on is a sliver on
 * the screen only, and its grid serves the rays that meet it face on
 * (radiosity, shadows) too. */
static void sliver_shape(const Vec3 *w, const TriShape *r, float unit, int *needle, int *cap,
                         double *foot)
{
    TriShape t = tri_shape(w);
    *needle = *cap = 0;
    if (!t.thin)
        return;
    /* in the lattice's space: the short edge, and the height over the long one */
    float r_lo = r->l[t.lo], r_hi = r->l[t.hi];
    if (4.0f * t.l[t.lo] <= t.l[t.hi]) {
        if (r_lo <= 4.0f * unit)
            *needle = (t.lo + 2) % 3 + 1; /* edge lo runs from corner lo to lo + 1 */
    } else if (r->area2 <= unit * r_hi) {
        /* Split at the apex's foot, rounded to a multiple of 2^-k whose
         * step along the edge is two to four micropolygons (k at least 1,
         * at most 12: the domain's corners stay exact), so the split
         * point is a vertex of whatever shares the edge: a neighbour
         * diced finer than that step has vertices at the multiples of its
         * power-of-two step, one diced coarser is coarser than both parts
         * (at most 1.42 micropolygons a step) all along, and stitching
         * puts every vertex on its polyline (geom/stitch.c). Both parts
         * are then needles (the foot at most two micropolygons off); at
         * the midpoint the part that held the foot was a cap again,
         * halved again and again. */
        int hi = t.hi;
        Vec3 e = v3_sub(w[(hi + 1) % 3], w[hi]);
        double f = v3_dot(v3_sub(w[(hi + 2) % 3], w[hi]), e) / ((double)t.l[hi] * t.l[hi]);
        int k = 1;
        while (k < 12 && ldexp(2.0 * unit, k + 1) <= r_hi)
            k++;
        double steps = ldexp(1.0, k), at = round(f * steps);
        *cap = hi + 1;
        *foot = fmin(fmax(at, 1.0), steps - 1.0) / steps;
    }
}

/* How a primitive's grids are traced (GeomShape). */
static int prim_shape(const Prim *prim)
{
    return prim->type == PRIM_CURVE ? prim->curve.shape
           : prim->type == PRIM_POINT ? prim->point.shape
                                      : GEOM_SHAPE_SURFACE;
}

/* The largest power of two not above n (n >= 1). */
static int power_of_two_below(int n)
{
    int p = 1;
    while (p <= n / 2)
        p *= 2;
    return p;
}

/* The power of two nearest n (in ratio: up from 1.42 p). Patches of
 * surfaces dice at such rates (triangles one for all three edges) over
 * domains halved when split, so that along any line two grids share, the
 * coarser grid's vertices are vertices of the finer one too, which
 * stitching (geom/stitch.c) needs. */
static int nearest_power_of_two(int n)
{
    int p = power_of_two_below(n);
    return (int64_t)n * n > 2 * (int64_t)p * p ? 2 * p : p;
}

/* Whether a domain of a flat triangle needs one micropolygon, found from
 * its three corners alone (a dense mesh's faces: the lattice costs 15
 * evaluations and projections). Every lattice line lies inside the
 * triangle, in raster space too (a projection in front of the eye maps it
 * to a triangle), so none is longer than its longest edge; the corners
 * place it against the view as the lattice does (side planes and the eye
 * plane bound convex half-spaces), and the off-screen factor, left out,
 * only lengthens the unit. (Far from the origin the lattice's sums of
 * roundings could say two where this says one: DESIGN.md.) rate: the
 * target edge in pixels. */
static int one_micropolygon(const Prim *prim, const Domain *d, const DiceCamera *cam, float rate)
{
    if (prim->type != PRIM_TRIANGLE)
        return 0;
    Vec3 c[3] = {domain_point(prim, d, 0.0f, 0.0f), domain_point(prim, d, 1.0f, 0.0f),
                 domain_point(prim, d, 0.0f, 1.0f)};
    float s[3][2], outside = 0.0f, longest = 0.0f, unit;
    ViewPlace place = view_place(cam, c, 3, s, &outside);
    if (place == VIEW_ON && !cam->isotropic) {
        for (int k = 0; k < 3; k++)
            longest =
                fmaxf(longest, hypotf(s[(k + 1) % 3][0] - s[k][0], s[(k + 1) % 3][1] - s[k][1]) /
                                   cam->pixel);
        unit = rate;
    } else {
        Bounds3 box = bounds_empty();
        for (int k = 0; k < 3; k++) {
            box = bounds_add(box, c[k]);
            longest = fmaxf(longest, v3_length(v3_sub(c[(k + 1) % 3], c[k])));
        }
        float dist = fmaxf(bounds_distance(box, cam->eye), cam->min_distance);
        unit = rate * (cam->pixel_width + cam->pixel_angle * dist);
    }
    return longest * 1.001f <= 0.999f * unit; /* margins for the lattice's roundings */
}

static Estimate estimate(const Prim *prim, const Domain *d, const DiceCamera *cam)
{
    float scale = cam->rate_scale > 1.0f ? cam->rate_scale : 1.0f;
    float rate = sqrtf(fmaxf(prim->shading_rate, 1e-6f)) * scale; /* edge, in pixels */
    if (d->triangular && one_micropolygon(prim, d, cam, rate))
        return (Estimate){1, 1, -1, 0, 0, 0.5};
    Vec3 p[LATTICE][LATTICE];
    float s[LATTICE * LATTICE][2];
    Vec3 pts[LATTICE * LATTICE];
    int n = 0;
    Bounds3 box = bounds_empty();
    const float step = 1.0f / (LATTICE - 1);
    for (int j = 0; j < LATTICE; j++)
        for (int i = 0; i < LATTICE; i++) {
            p[j][i] = v3(0, 0, 0);
            if (d->triangular && i + j > LATTICE - 1)
                continue;
            p[j][i] = domain_point(prim, d, (float)i * step, (float)j * step);
            box = bounds_add(box, p[j][i]);
            pts[n++] = p[j][i];
        }
    float outside = 0.0f;
    ViewPlace place = view_place(cam, pts, n, s, &outside);
    float len[3], unit;
    const Vec3 world[3] = {p[0][0], p[0][LATTICE - 1], p[LATTICE - 1][0]}; /* a triangle's */
    if (place == VIEW_ON && !cam->isotropic) {
        /* Raster positions in the lattice's own layout, then measured as
         * points in the plane. */
        int k = 0;
        for (int j = 0; j < LATTICE; j++)
            for (int i = 0; i < LATTICE; i++)
                if (!(d->triangular && i + j > LATTICE - 1)) {
                    p[j][i] = v3(s[k][0] / cam->pixel, s[k][1] / cam->pixel, 0.0f);
                    k++;
                }
        unit = rate;
    } else {
        float dist = fmaxf(bounds_distance(box, cam->eye), cam->min_distance);
        unit = rate * (cam->pixel_width + cam->pixel_angle * dist);
        if (place == VIEW_OFF && cam->offscreen > 1.0f)
            unit *= 1.0f + (cam->offscreen - 1.0f) * fminf(outside, 1.0f);
    }
    lattice_lengths((const Vec3(*)[LATTICE])p, d->triangular, len);
    Estimate e = {.thin_edge = -1, .foot = 0.5};
    if (d->triangular) {
        float l = fmaxf(len[0], fmaxf(len[1], len[2]));
        e.n_u = e.n_v = (int)fminf(ceilf(l / unit), 1e6f);
        const Vec3 r[3] = {p[0][0], p[0][LATTICE - 1], p[LATTICE - 1][0]};
        TriShape rs = tri_shape(r);
        e.thin_edge = rs.thin ? rs.hi : -1;
        sliver_shape(world, &rs, unit, &e.needle, &e.cap, &e.foot);
    } else {
        e.n_u = (int)fminf(ceilf(len[0] / unit), 1e6f);
        e.n_v = (int)fminf(ceilf(len[1] / unit), 1e6f);
    }
    e.n_u = RY_MAX(e.n_u, 1);
    e.n_v = RY_MAX(e.n_v, 1);
    if (cam->binary && geom_prim_stitched(prim)) {
        e.n_u = nearest_power_of_two(e.n_u);
        e.n_v = nearest_power_of_two(e.n_v);
    }
    if (prim_shape(prim) == GEOM_SHAPE_ROUND_CURVE || prim_shape(prim) == GEOM_SHAPE_FLAT_CURVE)
        e.n_v = 1; /* one micropolygon across: the tube or ribbon about the centre line */
    return e;
}

static int reserve_primvars(GridSet *gs, size_t cap, unsigned want);

int geom_gridset_want_primvars(GridSet *gs, unsigned want)
{
    return (want & ~gs->pv_arrays) ? reserve_primvars(gs, gs->cap_vertices, want) : 0;
}

/* Grows (or first allocates, when a GEOM_PV_* bit of want is new) the
 * primitive variable arrays to cap vertices. */
static int reserve_primvars(GridSet *gs, size_t cap, unsigned want)
{
    unsigned have = gs->pv_arrays | want;
    if (have & GEOM_PV_N) {
        Vec3 *Ns = realloc(gs->Ns, cap * sizeof *Ns);
        if (!Ns)
            return -1;
        gs->Ns = Ns;
    }
    if (have & GEOM_PV_ST) {
        float(*st)[2] = realloc(gs->st, cap * sizeof *st);
        if (st)
            gs->st = st;
        float(*dst)[4] = realloc(gs->dst, cap * sizeof *dst);
        if (dst)
            gs->dst = dst;
        if (!st || !dst)
            return -1;
    }
    if (have & GEOM_PV_CS) {
        Vec3 *Cs = realloc(gs->Cs, cap * sizeof *Cs);
        if (!Cs)
            return -1;
        gs->Cs = Cs;
    }
    if (have & GEOM_PV_OS) {
        Vec3 *Os = realloc(gs->Os, cap * sizeof *Os);
        if (!Os)
            return -1;
        gs->Os = Os;
    }
    gs->pv_arrays = have;
    return 0;
}

static int reserve(GridSet *gs, size_t n_vertices, unsigned primvars)
{
    if (util_grow((void **)&gs->grids, &gs->cap_grids, gs->n_grids, sizeof *gs->grids) != 0)
        return -1;
    if (gs->n_vertices + n_vertices > gs->cap_vertices) {
        size_t cap = gs->cap_vertices ? 2 * gs->cap_vertices : 4096;
        while (cap < gs->n_vertices + n_vertices)
            cap *= 2;
        /* One spare vertex: Embree reads 16 bytes for the last float3. */
        Vec3 *P = realloc(gs->P, (cap + 1) * sizeof *P);
        if (P)
            gs->P = P;
        Vec3 *N = realloc(gs->N, cap * sizeof *N);
        if (N)
            gs->N = N;
        Vec3 *du = realloc(gs->dPdu, cap * sizeof *du);
        if (du)
            gs->dPdu = du;
        Vec3 *dv = realloc(gs->dPdv, cap * sizeof *dv);
        if (dv)
            gs->dPdv = dv;
        float(*uv)[2] = realloc(gs->uv, cap * sizeof *uv);
        if (uv)
            gs->uv = uv;
        if (!P || !N || !du || !dv || !uv || reserve_primvars(gs, cap, gs->pv_arrays) != 0)
            return -1;
        gs->cap_vertices = cap;
    }
    if ((primvars & ~gs->pv_arrays) && reserve_primvars(gs, gs->cap_vertices, primvars) != 0)
        return -1;
    return 0;
}

static void put_vertex(GridSet *gs, size_t k, const Prim *prim, const float *pool, float u,
                       float v)
{
    geom_prim_eval(prim, u, v, &gs->P[k], &gs->dPdu[k], &gs->dPdv[k]);
    gs->N[k] = geom_prim_normal(prim, u, v);
    gs->uv[k][0] = u;
    gs->uv[k][1] = v;
    if (!prim->pv)
        return;
    PrimvarSample s;
    geom_prim_primvars(prim, pool, u, v, &s);
    if (prim->pv & GEOM_PV_N) {
        /* The front is the geometric one: a supplied normal on the back
         * (the other winding convention, a mirror) is turned round, and
         * one that interpolates to nothing is the geometric normal. */
        float c = v3_dot(s.N, gs->N[k]);
        gs->Ns[k] = v3_length(s.N) > 0.0f ? (c < 0.0f ? v3_neg(s.N) : s.N) : gs->N[k];
    }
    if (prim->pv & GEOM_PV_ST) {
        memcpy(gs->st[k], s.st, sizeof gs->st[k]);
        memcpy(gs->dst[k], s.dst, sizeof gs->dst[k]);
    }
    if (prim->pv & GEOM_PV_CS)
        gs->Cs[k] = s.Cs;
    if (prim->pv & GEOM_PV_OS)
        gs->Os[k] = s.Os;
}

/* One neighbour pair, in one of two passes: the first sums edge lengths;
 * the second takes the largest normal change per length, over pairs no
 * shorter than a tenth of the mean edge (a collapsed row, the teapot lid's
 * apex, has pairs of length ~0 whose ratio means nothing). */
static void measure(const GridSet *gs, size_t a, size_t b, double *sum, size_t *n, float *curv)
{
    float len = v3_length(v3_sub(gs->P[a], gs->P[b]));
    if (!curv) {
        *sum += len;
        (*n)++;
    } else if (len > 0.1f * (float)(*sum / (double)(*n ? *n : 1)))
        *curv = fmaxf(*curv, v3_length(v3_sub(gs->N[a], gs->N[b])) / len);
}

void geom_grid_measure(GridSet *gs, Grid *g)
{
    size_t base = g->first_vertex;
    double sum = 0.0;
    size_t m = 0;
    float curv = 0.0f;
    for (int pass = 0; pass < 2; pass++) {
        float *c = pass ? &curv : NULL;
        if (g->triangular) {
            uint32_t n = g->nu;
            for (uint32_t j = 0; j <= n; j++)
                for (uint32_t i = 0; i + j < n; i++) {
                    size_t k = base + geom_tri_vertex(n, i, j);
                    measure(gs, k, base + geom_tri_vertex(n, i + 1, j), &sum, &m, c);
                    measure(gs, k, base + geom_tri_vertex(n, i, j + 1), &sum, &m, c);
                }
        } else {
            int nu = g->nu, nv = g->nv;
            for (int j = 0; j < nv; j++)
                for (int i = 0; i < nu; i++) {
                    size_t k = base + (size_t)j * nu + i;
                    if (i + 1 < nu)
                        measure(gs, k, k + 1, &sum, &m, c);
                    if (j + 1 < nv)
                        measure(gs, k, k + nu, &sum, &m, c);
                }
        }
    }
    g->edge = m ? (float)(sum / (double)m) : 0.0f;
    g->curvature = curv;
}

void geom_bound_sagitta(GridSet *gs, size_t first)
{
    float bound = 0.0f;
    for (size_t k = first; k < gs->n_grids; k++) {
        const Grid *g = &gs->grids[k];
        bound = fmaxf(bound, fminf(0.5f * g->edge * g->edge * g->curvature, g->edge));
        if (g->shape == GEOM_SHAPE_SURFACE || g->shape == GEOM_SHAPE_ORIENTED_DISK)
            continue; /* flat */
        /* Tubes, spheres and ray-facing disks are shaded on the ribbon or
         * square that faces the eye, through their middle, or at hits on
         * their surface: rays leave from a little more than a diameter
         * (|dPdv|) off either side, so that none starts inside the shape
         * or crosses it (fibres are lit from both sides). */
        size_t n = geom_grid_n_vertices(g);
        for (size_t i = 0; i < n; i++)
            bound = fmaxf(bound, 1.1f * v3_length(gs->dPdv[g->first_vertex + i]));
    }
    for (size_t k = first; k < gs->n_grids; k++)
        gs->grids[k].sagitta = bound;
}

/* The limits of one grid: micropolygons, and the side of a square of
 * that many (a triangle's subdivisions per edge). */
typedef struct Limits {
    int size, side;
    int tri; /* subdivisions per edge of a triangular grid, at most: side, or with binary
                dicing the power of two below it */
} Limits;

static Limits limits_of(const DiceCamera *cam)
{
    Limits l = {cam->grid_size > 0 ? RY_MIN(cam->grid_size, GEOM_MAX_GRID_SIZE) : GEOM_GRID_SIZE,
                1, 1};
    while ((l.side + 1) * (l.side + 1) <= l.size)
        l.side++;
    l.tri = cam->binary ? power_of_two_below(l.side) : l.side;
    return l;
}

static int dice_quad(GridSet *gs, const Prim *prim, uint32_t prim_index, const float *pool,
                     const Domain *d, Estimate e, Limits lim)
{
    /* Clamped to a square of lim.size only when splitting gave up
     * (degenerate input). */
    if ((int64_t)e.n_u * e.n_v > lim.size) {
        e.n_u = RY_MIN(e.n_u, lim.side);
        e.n_v = RY_MIN(e.n_v, lim.side);
    }
    int nu = RY_MIN(e.n_u, GEOM_MAX_GRID - 1) + 1, nv = RY_MIN(e.n_v, GEOM_MAX_GRID - 1) + 1;
    if (reserve(gs, (size_t)nu * nv, prim->pv) != 0)
        return -1;
    Grid *g = &gs->grids[gs->n_grids];
    *g = (Grid){.prim = prim_index, .object = prim->object, .master = prim->master,
                .solid = prim->solid,
                .first_vertex = (uint32_t)gs->n_vertices,
                .nu = (uint16_t)nu, .nv = (uint16_t)nv, .primvars = prim->pv,
                .shape = (uint8_t)prim_shape(prim)};
    memcpy(g->uv, d->c, sizeof g->uv);
    if (d->sub_quad) {
        /* Its rows and columns run askew in the triangle's (u, v): uv holds
         * a box whose spacing, (uv[1] - uv[0]) / (n - 1), is the largest
         * step in u and in v between neighbouring vertices along either
         * direction (its edges bound them: the map is bilinear). */
        float c[4][2], step[2] = {0, 0};
        for (int k = 0; k < 4; k++)
            domain_uv(d, (float)(k & 1), (float)(k >> 1), &c[k][0], &c[k][1]);
        for (int a = 0; a < 2; a++) {
            float du = fmaxf(fabsf(c[1][a] - c[0][a]), fabsf(c[3][a] - c[2][a])) / (float)(nu - 1);
            float dv = fmaxf(fabsf(c[2][a] - c[0][a]), fabsf(c[3][a] - c[1][a])) / (float)(nv - 1);
            step[a] = fmaxf(du, dv);
        }
        g->uv[0][0] = c[0][0], g->uv[0][1] = c[0][1];
        g->uv[1][0] = c[0][0] + step[0] * (float)(nu - 1);
        g->uv[1][1] = c[0][1] + step[1] * (float)(nv - 1);
        if (util_grow((void **)&gs->subs, &gs->cap_subs, gs->n_subs, sizeof *gs->subs) != 0)
            return -1;
        GridSub *sub = &gs->subs[gs->n_subs++];
        sub->corner = (uint8_t)d->corner;
        memcpy(sub->sub, d->c, sizeof sub->sub);
        memcpy(sub->tri, d->tri, sizeof sub->tri);
        g->sub = (uint32_t)gs->n_subs;
    }
    size_t base = gs->n_vertices;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            float u, v;
            domain_uv(d, (float)i / (nu - 1), (float)j / (nv - 1), &u, &v);
            put_vertex(gs, base + (size_t)j * nu + i, prim, pool, u, v);
        }
    gs->n_vertices += (size_t)nu * nv;
    geom_grid_measure(gs, g);
    gs->n_grids++;
    return 0;
}

static int dice_triangle(GridSet *gs, const Prim *prim, uint32_t prim_index, const float *pool,
                         const Domain *d, Estimate e, Limits lim)
{
    uint32_t n = (uint32_t)RY_MIN(e.n_u, lim.tri);
    size_t count = (size_t)(n + 1) * (n + 2) / 2;
    if (reserve(gs, count, prim->pv) != 0)
        return -1;
    Grid *g = &gs->grids[gs->n_grids];
    *g = (Grid){.prim = prim_index, .object = prim->object, .master = prim->master,
                .solid = prim->solid,
                .first_vertex = (uint32_t)gs->n_vertices,
                .nu = (uint16_t)n, .nv = 0, .triangular = 1, .primvars = prim->pv};
    memcpy(g->uv, d->c, sizeof g->uv);
    size_t base = gs->n_vertices;
    for (uint32_t j = 0; j <= n; j++)
        for (uint32_t i = 0; i + j <= n; i++) {
            float u, v;
            domain_uv(d, (float)i / n, (float)j / n, &u, &v);
            put_vertex(gs, base + geom_tri_vertex(n, i, j), prim, pool, u, v);
        }
    gs->n_vertices += count;
    geom_grid_measure(gs, g);
    gs->n_grids++;
    return 0;
}

/* What a split-and-dice walk writes to: grids appended to gs, or (gs
 * NULL) only the vertices they would hold, counted. */
typedef struct Walk {
    GridSet *gs;
    const Prim *prim;
    uint32_t prim_index;
    const float *pool;
    const DiceCamera *cam;
    Limits lim;
    size_t vertices; /* counted, when gs is NULL */
    size_t grids;    /* counted, when gs is NULL */
} Walk;

static int leaf(Walk *w, const Domain *d, Estimate e)
{
    if (w->gs)
        return d->triangular ? dice_triangle(w->gs, w->prim, w->prim_index, w->pool, d, e, w->lim)
                             : dice_quad(w->gs, w->prim, w->prim_index, w->pool, d, e, w->lim);
    w->grids++;
    if (d->triangular) {
        size_t n = (size_t)RY_MIN(e.n_u, w->lim.tri);
        w->vertices += (n + 1) * (n + 2) / 2;
    } else {
        if ((int64_t)e.n_u * e.n_v > w->lim.size) {
            e.n_u = RY_MIN(e.n_u, w->lim.side);
            e.n_v = RY_MIN(e.n_v, w->lim.side);
        }
        w->vertices += (size_t)(RY_MIN(e.n_u, GEOM_MAX_GRID - 1) + 1) *
                       (size_t)(RY_MIN(e.n_v, GEOM_MAX_GRID - 1) + 1);
    }
    return 0;
}

static int split_dice(Walk *w, const Domain *d, int depth);

static int split_sub_triangle(Walk *w, const float *a, const float *b, const float *c, int depth)
{
    Domain sub = {.triangular = 1};
    memcpy(sub.c[0], a, sizeof sub.c[0]);
    memcpy(sub.c[1], b, sizeof sub.c[1]);
    memcpy(sub.c[2], c, sizeof sub.c[2]);
    return split_dice(w, &sub, depth + 1);
}

/* A thin triangle: two parts at a point of its long edge (thin: that
 * edge's first corner, k, to k + 1), corners kept in order: at the edge's
 * fraction `at` (a dyadic fraction: sliver_shape), or at its midpoint
 * (rounded) when that point is not exact in the domain's floats. */
static int split_triangle(Walk *w, const Domain *d, int thin, double at, int depth)
{
    int a = thin, b = (thin + 1) % 3;
    float m[2];
    int exact = 1;
    for (int c = 0; c < 2; c++) {
        double x = d->c[a][c] + at * ((double)d->c[b][c] - d->c[a][c]);
        m[c] = (float)x;
        exact &= (double)m[c] == x;
    }
    if (!exact || at == 0.5) /* the midpoint, as floats give it */
        for (int c = 0; c < 2; c++)
            m[c] = 0.5f * (d->c[a][c] + d->c[b][c]);
    float half[2][3][2];
    for (int h = 0; h < 2; h++)
        memcpy(half[h], d->c, sizeof half[h]);
    memcpy(half[0][b], m, sizeof m);
    memcpy(half[1][a], m, sizeof m);
    for (int h = 0; h < 2; h++)
        if (split_sub_triangle(w, half[h][0], half[h][1], half[h][2], depth) != 0)
            return -1;
    return 0;
}

/* A triangle too large for one grid (and not thin: thin ones are bisected
 * first), as three quads meeting at its centroid (each from a corner
 * through its edges' midpoints), which dice as quads do: into grids finer
 * along one side than the other where the view foreshortens them (a
 * triangular grid has one rate for all its edges), traced as Embree's
 * grids (a sixth of its triangles' bytes). */
static int split_quads(Walk *w, const Domain *d, int depth)
{
    const float third = 1.0f / 3.0f;
    float mid[3][2], centre[2] = {0, 0};
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 2; c++) {
            mid[k][c] = 0.5f * (d->c[k][c] + d->c[(k + 1) % 3][c]); /* edge k, k + 1 */
            centre[c] += third * d->c[k][c];
        }
    for (int k = 0; k < 3; k++) {
        Domain sub = {.c = {{0, 0}, {1, 1}, {0, 0}}, .sub_quad = 1, .corner = k};
        memcpy(sub.tri, d->c, sizeof sub.tri);
        /* Corner k, the midpoint toward k + 1, the one toward k - 1, the
         * centroid: (s, t) = (0,0), (1,0), (0,1), (1,1). */
        memcpy(sub.q[0], d->c[k], sizeof sub.q[0]);
        memcpy(sub.q[1], mid[k], sizeof sub.q[1]);
        memcpy(sub.q[2], mid[(k + 2) % 3], sizeof sub.q[2]);
        memcpy(sub.q[3], centre, sizeof sub.q[3]);
        if (split_dice(w, &sub, depth + 1) != 0)
            return -1;
    }
    return 0;
}

/* A needle (sliver_shape) as a quad whose side t = 0 is its short edge
 * and whose side t = 1 is its apex (GridSub.corner GEOM_FAN + apex): its
 * rows cross it, so it dices finely along and once or twice across; the
 * quad's rows and columns are the triangle's lines, its winding the
 * triangle's. */
static int dice_fan(Walk *w, const Domain *d, int apex, int depth)
{
    int b0 = (apex + 1) % 3, b1 = (apex + 2) % 3;
    Domain fan = {.c = {{0, 0}, {1, 1}, {0, 0}}, .sub_quad = 1, .corner = GEOM_FAN + apex};
    memcpy(fan.tri, d->c, sizeof fan.tri);
    memcpy(fan.q[0], d->c[b0], sizeof fan.q[0]);
    memcpy(fan.q[1], d->c[b1], sizeof fan.q[1]);
    memcpy(fan.q[2], d->c[apex], sizeof fan.q[2]);
    memcpy(fan.q[3], d->c[apex], sizeof fan.q[3]);
    return split_dice(w, &fan, depth + 1);
}

static int split_dice(Walk *w, const Domain *d, int depth)
{
    Estimate e = estimate(w->prim, d, w->cam);
    /* Slivers a triangular grid would dice at their long edge's rate all
     * over (below a few micropolygons it costs no more than a strip). */
    if (d->triangular && e.n_u >= SLIVER_MIN_RATE && depth < MAX_SPLIT_DEPTH) {
        if (e.needle)
            return dice_fan(w, d, e.needle - 1, depth);
        if (e.cap)
            return split_triangle(w, d, e.cap - 1, e.foot, depth);
    }
    if (w->prim->type == PRIM_POINT) {
        /* One grid per point (accel.h traces it whole), square. */
        e.n_u = e.n_v = RY_MIN(RY_MAX(e.n_u, e.n_v), w->lim.side);
        return leaf(w, d, e);
    }
    int split = d->triangular ? e.n_u > w->lim.tri
                              : (int64_t)e.n_u * e.n_v > w->lim.size || e.n_u > GEOM_MAX_GRID - 1 ||
                                    e.n_v > GEOM_MAX_GRID - 1;
    if (!split || depth >= MAX_SPLIT_DEPTH)
        return leaf(w, d, e);
    if (d->triangular && e.thin_edge < 0)
        return split_quads(w, d, depth);
    if (d->triangular)
        return split_triangle(w, d, e.thin_edge, 0.5, depth);
    /* Across the longer direction (u on a tie). */
    int su = e.n_u >= e.n_v ? 2 : 1, sv = 3 - su;
    for (int j = 0; j < sv; j++)
        for (int i = 0; i < su; i++) {
            Domain sub = *d;
            float du = (d->c[1][0] - d->c[0][0]) / su, dv = (d->c[1][1] - d->c[0][1]) / sv;
            sub.c[0][0] = d->c[0][0] + du * i;
            sub.c[1][0] = i + 1 == su ? d->c[1][0] : d->c[0][0] + du * (i + 1);
            sub.c[0][1] = d->c[0][1] + dv * j;
            sub.c[1][1] = j + 1 == sv ? d->c[1][1] : d->c[0][1] + dv * (j + 1);
            if (split_dice(w, &sub, depth + 1) != 0)
                return -1;
        }
    return 0;
}

static Domain whole_domain(const Prim *prim)
{
    Domain d = {.triangular = geom_prim_triangular(prim)};
    if (d.triangular) {
        const float c[3][2] = {{0, 0}, {1, 0}, {0, 1}};
        memcpy(d.c, c, sizeof c);
    } else {
        const float c[3][2] = {{0, 0}, {1, 1}, {0, 0}};
        memcpy(d.c, c, sizeof c);
    }
    return d;
}

/* prim, or (curves and points that face the eye) a copy of it in *copy
 * facing the camera. */
static const Prim *facing_eye(const Prim *prim, const DiceCamera *cam, Prim *copy)
{
    if (prim_shape(prim) == GEOM_SHAPE_SURFACE || prim_shape(prim) == GEOM_SHAPE_ORIENTED_DISK)
        return prim;
    *copy = *prim;
    if (prim->type == PRIM_CURVE)
        copy->curve.facing = cam->eye;
    else
        copy->point.facing = cam->eye;
    return copy;
}

int geom_dice_prim(GridSet *gs, const Prim *prim, uint32_t prim_index, const float *pv_pool,
                   const DiceCamera *cam)
{
    Prim copy;
    prim = facing_eye(prim, cam, &copy);
    Walk w = {gs, prim, prim_index, pv_pool, cam, limits_of(cam), 0, 0};
    Domain d = whole_domain(prim);
    size_t first = gs->n_grids;
    if (split_dice(&w, &d, 0) != 0)
        return -1;
    geom_bound_sagitta(gs, first);
    return 0;
}

size_t geom_count_prim(const Prim *prim, const DiceCamera *cam, size_t *grids)
{
    Prim copy;
    prim = facing_eye(prim, cam, &copy);
    Walk w = {NULL, prim, 0, NULL, cam, limits_of(cam), 0, 0};
    Domain d = whole_domain(prim);
    split_dice(&w, &d, 0);
    if (grids)
        *grids += w.grids;
    return w.vertices;
}
