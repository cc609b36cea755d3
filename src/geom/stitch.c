/*
 * geom/stitch.c — closing the cracks between grids diced at different
 * rates (DESIGN.md "Stitching").
 *
 * Two grids that share a line of the surface (a split inside one
 * primitive, or an edge between primitives: subdivision faces, polygon
 * mesh quads, bicubic patches of one mesh) are diced at their own rates,
 * so their vertices along it differ and rays pass between them. Quad
 * patches of surfaces dice at powers of two over domains halved when
 * split (dice.c), so along a shared line the vertices of the coarser grid
 * are vertices of the finer one. After dicing and displacement, every
 * vertex on a grid's side is moved onto the polyline of the coarsest grid
 * there: a vertex of that polyline takes one position for all grids (the
 * least, compared x, y, z, of their copies, which neighbouring primitives
 * evaluate a rounding apart), and a vertex between two of them is put on
 * the segment by its parameter. Both sides of a line then have the same
 * polyline, and grids stay regular (Embree grids, cache entries); only
 * positions move, by at most the sagitta of the coarser side.
 *
 * A line is a curve with a key and a parameter t: a line u = c or v = c
 * inside one primitive (t = the other parameter), or a side of the
 * primitive's domain, keyed by what its neighbour shares: a subdivision
 * mesh's edge (geom_subdiv_patch_side), the bit patterns of a bilinear
 * patch's or a triangle's corners or a bicubic patch's four edge control
 * points, in a canonical order. Triangular grids (one power of two on
 * all three edges) are stitched along their edges, and the quads a large
 * triangle dices into along halves of its edges and the spokes between
 * them (sub_quad_side). Lines a vertex lies on more than one of (grid
 * corners) are settled by repeating the pass until nothing moves.
 *
 * Memory: one record per grid side and one position per side vertex,
 * freed on return. Thread-safety: writes only gs->P.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/geom.h"
#include "geom/subdiv.h"
#include "util/rng.h"

#define STITCH_PASSES 6 /* corners settle in two or three; a bound for odd input */

/* One grid side on a curve: its n + 1 vertices at t = lo + i (hi - lo) / n
 * are P[side_vertex(side, i)]: P[first + i * stride] on a quad grid. */
typedef struct Side {
    uint64_t key[2];  /* the curve (hashed) */
    double lo, hi;    /* its range of the curve's parameter, lo < hi */
    size_t first;     /* the vertex at lo; a triangular grid's edge: the grid's first */
    ptrdiff_t stride; /* to the next vertex toward hi (quad grids) */
    uint32_t n;       /* segments */
    uint8_t tri_edge; /* a triangular grid's edge k, from corner k to k + 1: 1 + k; else 0 */
    uint8_t reversed; /* that edge runs from hi to lo */
    uint8_t apex_back; /* a needle fan's side s = 1: its apex end is the apex row's
                          first vertex, this many before the row's last (the fan's
                          two sides meet in one vertex, as a grid's sides do) */
} Side;

/* The index in the GridSet of vertex i (from lo) of a side. */
static size_t side_vertex(const Side *sd, uint32_t i)
{
    if (!sd->tri_edge) {
        size_t v = (size_t)((ptrdiff_t)sd->first + sd->stride * (ptrdiff_t)i);
        return sd->apex_back && i == (sd->reversed ? 0 : sd->n) ? v - sd->apex_back : v;
    }
    /* Edge 0 is row j = 0, edge 1 the diagonal i + j = n, edge 2 column i = 0. */
    uint32_t n = sd->n, k = sd->reversed ? n - i : i;
    uint32_t a = sd->tri_edge == 1 ? k : sd->tri_edge == 2 ? n - k : 0;
    uint32_t b = sd->tri_edge == 1 ? 0 : sd->tri_edge == 2 ? k : n - k;
    return sd->first + geom_tri_vertex(n, a, b);
}

int geom_prim_stitched(const Prim *prim)
{
    switch (prim->type) {
    case PRIM_BILINEAR:
    case PRIM_BICUBIC:
    case PRIM_SPHERE:
    case PRIM_QUADRIC:
    case PRIM_TRIANGLE:
    case PRIM_SUBDIV: return 1;
    default: return 0;
    }
}

static uint64_t hash_bits(uint64_t h, const Vec3 *p, int n)
{
    for (int k = 0; k < n; k++) {
        uint32_t b[3];
        memcpy(b, &p[k], sizeof b);
        for (int c = 0; c < 3; c++)
            h = hash_combine(h, b[c]);
    }
    return h;
}

static uint64_t hash_floats(uint64_t h, const float *f, int n)
{
    for (int k = 0; k < n; k++) {
        uint32_t b;
        memcpy(&b, &f[k], sizeof b);
        h = hash_combine(h, b);
    }
    return h;
}

/* -1, 0, 1 as the bit patterns of n points of a compare to those of b. */
static int cmp_points(const Vec3 *a, const Vec3 *b, int n)
{
    for (int k = 0; k < n; k++)
        for (int c = 0; c < 3; c++) {
            uint32_t x, y;
            memcpy(&x, (const float *)&a[k] + c, sizeof x);
            memcpy(&y, (const float *)&b[k] + c, sizeof y);
            if (x != y)
                return x < y ? -1 : 1;
        }
    return 0;
}

/* A patch side given by its n control points (2 for a bilinear patch's
 * straight edge, 4 for a Bezier curve), from s = 0 to 1: keyed in the
 * order whose bits are less, t running that way. */
static void points_side(const Vec3 *cp, int n, uint64_t key[2], float t[2])
{
    Vec3 rev[4];
    for (int k = 0; k < n; k++)
        rev[k] = cp[n - 1 - k];
    int forward = cmp_points(cp, rev, n) <= 0;
    const Vec3 *p = forward ? cp : rev;
    key[0] = hash_bits(0x5354495443480001ull + (uint64_t)n, p, n);
    key[1] = hash_bits(0x5354495443480002ull + (uint64_t)n, p, n);
    t[0] = forward ? 0.0f : 1.0f;
    t[1] = 1.0f - t[0];
}

/* The curve of side `side` of prim's domain (0: v = 0, 1: u = 1, 2: v = 1,
 * 3: u = 0; a triangle's: from corner side to side + 1), shared with
 * whatever neighbour shares it, and its parameter at s = 0 and 1 along
 * the side (s: u or v, or from the triangle's corner). 0 if it has none. */
static int prim_side(const Prim *prim, int side, uint64_t key[2], float t[2])
{
    static const int bilinear[4][2] = {{0, 1}, {1, 3}, {2, 3}, {0, 2}};
    static const int bicubic[4][4] = {{0, 1, 2, 3}, {3, 7, 11, 15}, {12, 13, 14, 15},
                                      {0, 4, 8, 12}};
    Vec3 p[4];
    switch (prim->type) {
    case PRIM_BILINEAR:
        p[0] = prim->cp[bilinear[side][0]], p[1] = prim->cp[bilinear[side][1]];
        points_side(p, 2, key, t);
        return 1;
    case PRIM_BICUBIC:
        for (int k = 0; k < 4; k++)
            p[k] = prim->big->cp[bicubic[side][k]];
        points_side(p, 4, key, t);
        return 1;
    case PRIM_TRIANGLE: /* a polygon mesh's edge: keyed as a bilinear patch's */
        if (side > 2)
            return 0;
        p[0] = prim->cp[side], p[1] = prim->cp[(side + 1) % 3];
        points_side(p, 2, key, t);
        return 1;
    case PRIM_SUBDIV: {
        uint64_t k[2];
        if (!geom_subdiv_patch_side(prim->subdiv.mesh, prim->subdiv.patch, side, k, t))
            return 0;
        uint64_t mesh = (uint64_t)(uintptr_t)prim->subdiv.mesh;
        key[0] = hash_combine(hash_combine(mesh, k[0]), k[1]);
        key[1] = hash_combine(hash_combine(k[1], mesh), k[0] + 0x9e3779b97f4a7c15ull);
        return 1;
    }
    default: return 0;
    }
}

/* Fills *out for a side of n segments whose vertices run from first by
 * stride (a quad grid's), or along edge tri_edge - 1 of a triangular grid,
 * on curve key from parameter a to b, of a grid of master `master` (its
 * space: a master's grids meet only each other). Returns 0 for an empty
 * range. */
static int put_side(Side *out, const uint64_t key[2], uint32_t master, double a, double b,
                    size_t first, ptrdiff_t stride, uint32_t n, int tri_edge)
{
    out->key[0] = key[0], out->key[1] = key[1];
    if (master) /* world grids keep their keys */
        out->key[0] = hash_combine(key[0], 0x4d4153544552ull + master);
    out->n = n;
    out->tri_edge = (uint8_t)tri_edge;
    out->apex_back = 0;
    out->reversed = a > b;
    if (a > b && !tri_edge) {
        first += (size_t)(stride * (ptrdiff_t)n);
        stride = -stride;
    }
    out->lo = fmin(a, b), out->hi = fmax(a, b);
    out->first = first, out->stride = stride;
    return out->hi > out->lo;
}

/* The curve of a segment from a to b, corners of a triangle of a
 * triangular primitive's domain (barycentric (u, v)), and its parameter
 * at a and b: the primitive's edge when both lie on it (a neighbour's),
 * else a line inside it keyed by the segment's ends (split triangles
 * that share the whole segment). 0 if none. */
static int tri_segment(const Prim *prim, uint32_t prim_index, const float *a, const float *b,
                       uint64_t key[2], double t[2])
{
    for (int k = 0; k < 3; k++) {
        /* Edge k from corner k; domain corners are dyadic, so these are exact. */
        int on = k == 0   ? a[1] == 0.0f && b[1] == 0.0f
                 : k == 1 ? a[0] + a[1] == 1.0f && b[0] + b[1] == 1.0f
                          : a[0] == 0.0f && b[0] == 0.0f;
        if (!on)
            continue;
        double pa = k == 0 ? a[0] : k == 1 ? a[1] : 1.0 - a[1];
        double pb = k == 0 ? b[0] : k == 1 ? b[1] : 1.0 - b[1];
        float e[2];
        if (!prim_side(prim, k, key, e))
            return 0;
        t[0] = e[0] + ((double)e[1] - e[0]) * pa;
        t[1] = e[0] + ((double)e[1] - e[0]) * pb;
        return 1;
    }
    /* A line inside: keyed by the line, not the segment, since a split
     * triangle's halves may be split again along the segment their
     * neighbour shares whole. Its direction scaled by a power of two to
     * [1, 2) and pointing to +u (or +v), the parameter the projection on
     * it: exact in doubles for a domain's dyadic corners, so the halves of
     * a segment find its key and its parameters. */
    double du = (double)b[0] - a[0], dv = (double)b[1] - a[1];
    int ex;
    if (du == 0.0 && dv == 0.0)
        return 0;
    frexp(fmax(fabs(du), fabs(dv)), &ex);
    du = ldexp(du, 1 - ex), dv = ldexp(dv, 1 - ex);
    if (du < 0.0 || (du == 0.0 && dv < 0.0))
        du = -du, dv = -dv;
    /* + 0.0: a zero of either sign keys alike */
    double line[3] = {du + 0.0, dv + 0.0, (double)a[0] * dv - (double)a[1] * du + 0.0};
    key[0] = hash_combine(0x5452494c494e45ull, prim_index);
    for (int k = 0; k < 3; k++) {
        uint64_t bits;
        memcpy(&bits, &line[k], sizeof bits);
        key[0] = hash_combine(key[0], bits);
    }
    key[1] = hash_combine(key[0], 0x9e3779b97f4a7c15ull);
    t[0] = (double)a[0] * du + (double)a[1] * dv;
    t[1] = (double)b[0] * du + (double)b[1] * dv;
    return 1;
}

/* The key of a line inside a quad over part of a triangle (split_quads):
 * a line s or t = c of quad k (axis 0: t = c, 1: s = c), or (axis 2) the
 * spoke k from the midpoint of edge k to the centroid; k GEOM_FAN + apex
 * for a fan's. */
static void sub_quad_line(const Grid *g, const GridSub *sub, int axis, float c, int k,
                          uint64_t key[2])
{
    uint32_t bits;
    memcpy(&bits, &c, sizeof bits);
    key[0] = hash_floats(hash_combine(0x5355425155414455ull, g->prim), &sub->tri[0][0], 6);
    if (k >= GEOM_FAN) /* apart from split_quads' (whose keys stay as they were) */
        key[0] = hash_combine(key[0], 0x46414eull /* "FAN" */);
    key[0] = hash_combine(hash_combine(key[0], (uint64_t)axis * 4 + (uint64_t)k), bits);
    key[1] = hash_combine(key[0], 0x9e3779b97f4a7c15ull);
}

/* A side over fractions p0 to p1 of the segment from `from` to `to` (a
 * triangle's corners, barycentric): its curve and its range of the
 * curve's parameter (tri_segment). */
static int on_segment(const Grid *g, const Prim *prim, const float *from, const float *to,
                      double p0, double p1, uint64_t key[2], double *a, double *b)
{
    double t[2];
    if (!tri_segment(prim, g->prim, from, to, key, t))
        return 0;
    *a = t[0] + (t[1] - t[0]) * p0, *b = t[0] + (t[1] - t[0]) * p1;
    return 1;
}

/* Side `side` of a quad over part of a triangle: its outer sides (s or
 * t = 0) lie on half of the triangle's edges (corner k to k + 1 at
 * s / 2, corner k - 1 to k at 1 - t / 2), its sides s or t = 1 on the
 * spokes k and k - 1 it shares with the next and previous quads. */
static int sub_quad_side(const Grid *g, const GridSub *sub, const Prim *prim, int side, double s0,
                         double s1, double c, uint64_t key[2], double *a, double *b)
{
    int k = sub->corner, prev = (k + 2) % 3;
    if (c == 0.0 && (side == 0 || side == 3)) {
        int e = side == 0 ? k : prev;
        double p0 = side == 0 ? 0.5 * s0 : 1.0 - 0.5 * s0, p1 = side == 0 ? 0.5 * s1 : 1.0 - 0.5 * s1;
        return on_segment(g, prim, sub->tri[e], sub->tri[(e + 1) % 3], p0, p1, key, a, b);
    }
    if (c == 1.0 && (side == 1 || side == 2))
        sub_quad_line(g, sub, 2, 0.0f, side == 1 ? k : prev, key);
    else
        sub_quad_line(g, sub, side == 0 || side == 2 ? 0 : 1, (float)c, k, key);
    *a = s0, *b = s1;
    return 1;
}

/* Side `side` of a needle's fan (dice_fan; apex k, base from k + 1 to
 * k + 2): its side t = 0 on the base, s = 0 and 1 on the edges from the
 * base's ends to the apex (the quad's map is linear along each), t = 1
 * the apex itself (no line); lines inside it keyed as a sub-quad's. */
static int fan_side(const Grid *g, const GridSub *sub, const Prim *prim, int side, double s0,
                    double s1, double c, uint64_t key[2], double *a, double *b)
{
    int apex = sub->corner - GEOM_FAN, b0 = (apex + 1) % 3, b1 = (apex + 2) % 3;
    const float *from = NULL, *to = NULL;
    if (c == 0.0 && side == 0)
        from = sub->tri[b0], to = sub->tri[b1];
    else if (c == 0.0 && side == 3)
        from = sub->tri[b0], to = sub->tri[apex];
    else if (c == 1.0 && side == 1)
        from = sub->tri[b1], to = sub->tri[apex];
    else if (c == 1.0 && side == 2)
        return 0;
    if (from)
        return on_segment(g, prim, from, to, s0, s1, key, a, b);
    sub_quad_line(g, sub, side == 0 || side == 2 ? 0 : 1, (float)c, sub->corner, key);
    *a = s0, *b = s1;
    return 1;
}

/* The edges of a triangular grid: edge k from its corner k to k + 1. */
static int tri_grid_side(const Grid *g, const Prim *prim, int side, Side *out)
{
    uint64_t key[2];
    double t[2];
    if (side > 2 || !tri_segment(prim, g->prim, g->uv[side], g->uv[(side + 1) % 3], key, t))
        return 0;
    return put_side(out, key, g->master, t[0], t[1], g->first_vertex, 0, g->nu, 1 + side);
}

/* The record of side `side` of grid g (of prim; sub: its GridSub or NULL),
 * or 0 when the side is on no curve a neighbour can share. */
static int grid_side(const Grid *g, const GridSub *sub, const Prim *prim, int side, Side *out)
{
    static const int on_v[4] = {1, 0, 1, 0}; /* the side is a line of constant v */
    if (g->triangular)
        return tri_grid_side(g, prim, side, out);
    int nu = g->nu, nv = g->nv;
    const float(*r)[2] = sub ? sub->sub : g->uv; /* the domain's rectangle */
    float c = side == 0 ? r[0][1] : side == 1 ? r[1][0] : side == 2 ? r[1][1] : r[0][0];
    int axis = on_v[side] ? 0 : 1; /* s runs along u or v */
    float s0 = r[0][axis], s1 = r[1][axis];
    float border = side == 0 || side == 3 ? 0.0f : 1.0f;
    float t[2] = {0.0f, 1.0f};
    uint64_t key[2];
    double a, b;
    if (sub) {
        if (!(sub->corner >= GEOM_FAN ? fan_side : sub_quad_side)(g, sub, prim, side, s0, s1, c,
                                                                  key, &a, &b))
            return 0;
    } else {
        if (c == border) {
            if (!prim_side(prim, side, key, t))
                return 0;
        } else {
            uint32_t bits;
            memcpy(&bits, &c, sizeof bits);
            key[0] = hash_combine(hash_combine(0x494e4e4552ull, g->prim), (uint64_t)axis);
            key[1] = hash_combine(key[0], bits);
        }
        a = (double)t[0] + ((double)t[1] - t[0]) * s0;
        b = (double)t[0] + ((double)t[1] - t[0]) * s1;
    }
    size_t base = g->first_vertex;
    size_t start = side == 0 || side == 3 ? base
                   : side == 1            ? base + (size_t)nu - 1
                                          : base + (size_t)(nv - 1) * (size_t)nu;
    ptrdiff_t stride = on_v[side] ? 1 : nu;
    uint32_t n = (uint32_t)(on_v[side] ? nu - 1 : nv - 1);
    if (!put_side(out, key, g->master, a, b, start, stride, n, 0))
        return 0;
    if (sub && sub->corner >= GEOM_FAN && side == 1 && r[1][1] == 1.0f)
        out->apex_back = (uint8_t)(nu - 1);
    return 1;
}

static int cmp_side(const void *pa, const void *pb)
{
    const Side *a = pa, *b = pb;
    for (int k = 0; k < 2; k++)
        if (a->key[k] != b->key[k])
            return a->key[k] < b->key[k] ? -1 : 1;
    return a->lo < b->lo ? -1 : a->lo > b->lo;
}

static int vec_less(Vec3 a, Vec3 b)
{
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
}

/* The sides of a curve are s[0..n), sorted by lo; the longest is len. */
typedef struct Curve {
    const Side *s;
    size_t n;
    double len;
} Curve;

/* The largest spacing among the sides covering t, and the canonical
 * position at t (the least copy, over the sides with a vertex there) in
 * *at when some side has one; returns that spacing. */
static double curve_at(const Curve *c, const Vec3 *P, double t, Vec3 *at, int *found,
                       double *origin)
{
    double H = 0.0;
    *found = 0;
    *origin = 0.0;
    /* Sides are sorted by lo, none longer than len: those covering t
     * start in [t - len, t]. */
    size_t lo = 0, hi = c->n; /* the first side starting past t (a binary search: a
                                 mesh's straight rows make curves of thousands of sides) */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->s[mid].lo > t)
            hi = mid;
        else
            lo = mid + 1;
    }
    for (size_t k = hi; k-- > 0 && c->s[k].lo >= t - c->len;) {
        const Side *sd = &c->s[k];
        if (t > sd->hi)
            continue;
        double h = (sd->hi - sd->lo) / sd->n, i = (t - sd->lo) / h;
        if (h > H)
            H = h, *origin = sd->lo;
        if (i == floor(i)) {
            Vec3 p = P[side_vertex(sd, (uint32_t)i)];
            if (!*found || vec_less(p, *at))
                *at = p;
            *found = 1;
        }
    }
    return H;
}

/* Where vertex i of side sd belongs: on the coarsest polyline at its t.
 * Returns 0 when that polyline has no vertex to place it by (dicing
 * rates that are not powers of two: left alone). */
static int settle(const Curve *c, const Vec3 *P, const Side *sd, uint32_t i, Vec3 *out)
{
    double t = sd->lo + (sd->hi - sd->lo) * i / sd->n, origin, unused;
    int found;
    double H = curve_at(c, P, t, out, &found, &origin);
    /* the coarsest side's vertex at or before t (its vertices lie at its
     * lo plus multiples of H: a line inside a triangle starts anywhere) */
    double t0 = origin + floor((t - origin) / H) * H;
    if (t0 == t)
        return found;
    Vec3 a, b;
    int fa, fb;
    curve_at(c, P, t0, &a, &fa, &unused);
    curve_at(c, P, t0 + H, &b, &fb, &unused);
    if (!fa || !fb)
        return 0;
    *out = v3_add(a, v3_scale(v3_sub(b, a), (float)((t - t0) / H)));
    return 1;
}

/* Bits per vertex: set for those moved (Moved.now) in this pass and
 * (Moved.before) in the one before. */
typedef struct Moved {
    uint64_t *now, *before;
} Moved;

static int bit_get(const uint64_t *bits, size_t i)
{
    return (int)(bits[i / 64] >> (i % 64)) & 1;
}

/* Whether a vertex of a curve moved since the curve was settled in the
 * pass before: if not, settling it again moves nothing. */
static int curve_touched(const Curve *c, const Moved *mv)
{
    for (size_t k = 0; k < c->n; k++)
        for (uint32_t i = 0; i <= c->s[k].n; i++) {
            size_t v = side_vertex(&c->s[k], i);
            if (bit_get(mv->now, v) || bit_get(mv->before, v))
                return 1;
        }
    return 0;
}

/* Settles the vertices of one curve's sides, marking those that move in
 * mv->now; returns how many moved, or -1 when out of memory. */
static long stitch_curve(const Curve *c, Vec3 *P, Moved *mv)
{
    size_t count = 0;
    for (size_t k = 0; k < c->n; k++)
        count += c->s[k].n + 1;
    Vec3 *to = malloc(count * sizeof *to);
    if (!to)
        return -1;
    size_t m = 0;
    for (size_t k = 0; k < c->n; k++)
        for (uint32_t i = 0; i <= c->s[k].n; i++, m++)
            if (!settle(c, P, &c->s[k], i, &to[m]))
                to[m] = P[side_vertex(&c->s[k], i)];
    long moved = 0;
    m = 0;
    for (size_t k = 0; k < c->n; k++)
        for (uint32_t i = 0; i <= c->s[k].n; i++, m++) {
            size_t v = side_vertex(&c->s[k], i);
            if (memcmp(&P[v], &to[m], sizeof *P) != 0) {
                moved++;
                mv->now[v / 64] |= (uint64_t)1 << (v % 64);
            }
            P[v] = to[m];
        }
    free(to);
    return moved;
}

/* Nonzero for a grid of one micropolygon over a whole undisplaced
 * triangle (a dense mesh's faces, nearly all of its grids): its vertices
 * are the triangle's corners, bit for bit (geom_prim_eval weighs them),
 * as are its neighbours' copies of them, and a finer undisplaced
 * neighbour's vertices along its straight edges lie on them to a
 * rounding. Nothing to stitch, in a scene where nothing stitched is
 * displaced (a displaced neighbour, of another mesh sharing the corners'
 * bits, must be moved onto its edge): its sides are not collected (for a
 * mesh of 8 million triangles, 2.7 GB of sides and a fifth of the
 * preparation). */
static int whole_flat_triangle(const Grid *g, const Prim *prim)
{
    static const float whole[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    return prim->type == PRIM_TRIANGLE && !prim->displacement && g->triangular && g->nu == 1 &&
           !memcmp(g->uv, whole, sizeof whole);
}

/* sides[0..n) ordered by cmp_side, in a new array (sides freed): a
 * stable radix sort of the first key (four passes of 16 bits) over (key,
 * index) pairs, the sides gathered in that order, and runs of one first
 * key (one curve's sides, with rare collisions) sorted by cmp_side. A
 * dense mesh's millions of sides sort in a tenth of qsort's time.
 * Returns NULL when out of memory (sides freed too). */
static Side *sort_sides(Side *sides, size_t n)
{
    if (n > UINT32_MAX) { /* indices are 32 bits */
        qsort(sides, n, sizeof *sides, cmp_side);
        return sides;
    }
    uint64_t *key = malloc(2 * n * sizeof *key + 1);
    uint32_t *idx = malloc(2 * n * sizeof *idx + 1);
    size_t *count = malloc(65536 * sizeof *count);
    if (!key || !idx || !count) {
        free(key), free(idx), free(count), free(sides);
        return NULL;
    }
    uint64_t *k0 = key, *k1 = key + n;
    uint32_t *i0 = idx, *i1 = idx + n;
    for (size_t j = 0; j < n; j++)
        k0[j] = sides[j].key[0], i0[j] = (uint32_t)j;
    for (int shift = 0; shift < 64; shift += 16) {
        memset(count, 0, 65536 * sizeof *count);
        for (size_t j = 0; j < n; j++)
            count[(k0[j] >> shift) & 0xffff]++;
        for (size_t d = 0, sum = 0; d < 65536; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t j = 0; j < n; j++) {
            size_t to = count[(k0[j] >> shift) & 0xffff]++;
            k1[to] = k0[j], i1[to] = i0[j];
        }
        uint64_t *kt = k0;
        uint32_t *it = i0;
        k0 = k1, i0 = i1, k1 = kt, i1 = it;
    }
    free(key), free(count);
    /* A gather, not a permutation in place: its loads do not wait on each
     * other (a cycle's do, one cache miss after another). */
    Side *sorted = malloc((n + 1) * sizeof *sorted);
    if (sorted)
        for (size_t j = 0; j < n; j++)
            sorted[j] = sides[i0[j]];
    free(idx), free(sides);
    if (!sorted)
        return NULL;
    for (size_t a = 0, b; a < n; a = b) {
        for (b = a + 1; b < n && sorted[b].key[0] == sorted[a].key[0]; b++)
            ;
        if (b - a > 1)
            qsort(sorted + a, b - a, sizeof *sorted, cmp_side);
    }
    return sorted;
}

/* The sides of every stitched grid of gs, sorted by curve; NULL when out
 * of memory (*n = 0 with none). */
static Side *collect_sides(const GridSet *gs, const Prim *prims, size_t *n)
{
    Side *sides = malloc((4 * gs->n_grids + 1) * sizeof *sides);
    *n = 0;
    if (!sides)
        return NULL;
    int displaced = 0;
    for (size_t g = 0; g < gs->n_grids && !displaced; g++)
        displaced =
            geom_prim_stitched(&prims[gs->grids[g].prim]) && prims[gs->grids[g].prim].displacement;
    for (size_t g = 0; g < gs->n_grids; g++) {
        const Grid *grid = &gs->grids[g];
        const Prim *prim = &prims[grid->prim];
        if (grid->shape != GEOM_SHAPE_SURFACE || !geom_prim_stitched(prim) ||
            (!displaced && whole_flat_triangle(grid, prim)))
            continue;
        for (int side = 0; side < 4; side++)
            *n += (size_t)grid_side(grid, grid->sub ? &gs->subs[grid->sub - 1] : NULL, prim, side,
                                    &sides[*n]);
    }
    return sort_sides(sides, *n);
}

/* Nonzero when a curve's sides are single segments over the same range
 * whose ends are the same bits on every side: nothing to move (a dense
 * mesh's edges between faces diced whole, nearly all of its curves). */
static int settled(const Curve *c, const Vec3 *P)
{
    const Side *s0 = &c->s[0];
    for (size_t k = 0; k < c->n; k++) {
        const Side *sd = &c->s[k];
        if (sd->n != 1 || sd->lo != s0->lo || sd->hi != s0->hi ||
            memcmp(&P[side_vertex(sd, 0)], &P[side_vertex(s0, 0)], sizeof *P) != 0 ||
            memcmp(&P[side_vertex(sd, 1)], &P[side_vertex(s0, 1)], sizeof *P) != 0)
            return 0;
    }
    return 1;
}

/* A fan's apex row: every vertex where its first one was settled (that
 * one stands for the apex on both of the fan's sides, Side.apex_back;
 * the others lie on no side and would keep their own copy of it). */
static void close_fans(GridSet *gs)
{
    for (size_t k = 0; k < gs->n_grids; k++) {
        const Grid *g = &gs->grids[k];
        const GridSub *sub = g->sub ? &gs->subs[g->sub - 1] : NULL;
        if (!sub || sub->corner < GEOM_FAN || sub->sub[1][1] != 1.0f)
            continue;
        size_t row = g->first_vertex + (size_t)(g->nv - 1) * g->nu;
        for (size_t i = 1; i < g->nu; i++)
            gs->P[row + i] = gs->P[row];
    }
}

/* How many grid sides geom_stitch meets between two reads of its stop flag. */
#define STITCH_STOP_EVERY 4096

int geom_stitch(GridSet *gs, const Prim *prims, const volatile int *stop)
{
    size_t n, words = gs->n_vertices / 64 + 1;
    Side *sides = collect_sides(gs, prims, &n);
    Moved mv = {calloc(words, sizeof *mv.now), calloc(words, sizeof *mv.before)};
    if (!sides || !mv.now || !mv.before) {
        free(sides), free(mv.now), free(mv.before);
        return -1;
    }
    /* Corners lie on two curves: passes repeat while anything moves, each
     * after the first settling only the curves a move touched (the same
     * positions: settling a curve whose vertices stayed moves nothing). */
    long moved = 1;
    size_t seen = 0; /* sides met, for the stop flag's reads */
    for (int pass = 0; pass < STITCH_PASSES && moved > 0; pass++) {
        moved = 0;
        for (size_t a = 0, b; a < n; a = b) {
            if (stop && seen >= STITCH_STOP_EVERY) {
                seen = 0;
                if (__atomic_load_n(stop, __ATOMIC_RELAXED)) {
                    free(sides), free(mv.now), free(mv.before);
                    return -2;
                }
            }
            Curve c = {&sides[a], 0, 0.0};
            for (b = a; b < n && !memcmp(sides[b].key, sides[a].key, sizeof sides[a].key); b++)
                c.len = fmax(c.len, sides[b].hi - sides[b].lo);
            c.n = b - a;
            seen += c.n;
            if (c.n < 2 || (pass > 0 && !curve_touched(&c, &mv)) || settled(&c, gs->P))
                continue;
            long m = stitch_curve(&c, gs->P, &mv);
            if (m < 0) {
                free(sides), free(mv.now), free(mv.before);
                return -1;
            }
            moved += m;
        }
        uint64_t *t = mv.before; /* this pass's moves become the pass before's */
        mv.before = mv.now;
        mv.now = t;
        memset(mv.now, 0, words * sizeof *mv.now);
    }
    free(sides), free(mv.now), free(mv.before);
    close_fans(gs);
    return 0;
}
