/*
 * geom/cluster.c — clusters of tiny grids, the radiosity cache's levels
 * coarser than one grid (DESIGN.md "The radiosity cache").
 *
 * A dense mesh's faces are grids of one micropolygon or a few, and a
 * grid's coarsest cache entry can cover no more than the grid: a diffuse
 * ray whose footprint spans a hundred faces still fills one entry for the
 * face it hit, and neighbouring rays fill their own, so entries are
 * seldom reused and each fill's rays branch into more fills at the next
 * depth (a room of 480,000 triangles at 3 bounces: 3.3 million fills for
 * 5.7 million lookups, eleven times the uncached render's time). Clusters
 * group such grids as the dicer groups a large patch's micropolygons: up
 * to CLUSTER_FANOUT neighbouring grids of one object, then clusters of
 * clusters, up to CLUSTER_LEVELS levels; a ray whose footprint covers a
 * whole cluster reads one value for it, shaded at the member nearest its
 * middle (render/radiosity.c).
 *
 * Neighbours: the grids of each (master, object) in Morton order of their
 * middles, cut into runs. A run takes the next grid (or cluster) while it
 * has fewer than CLUSTER_FANOUT, the newcomer's normals lie within
 * CLUSTER_CONE of the run's first (so the run's normals span at most twice
 * that, the cache's bend limit, and all face one side), and the run's box
 * stays within CLUSTER_COMPACT times the square root of its area (a jump of
 * the Morton curve does not join two distant pieces) and its middles
 * within CLUSTER_THICK times that along its normal (layers of one object
 * facing one way, a board on a board, do not join). A cluster with one
 * child is its child and is not kept.
 *
 * Memory: 4 bytes a grid and 12 a cluster, kept; 104 bytes a tiny grid and
 * 80 a run while building. Deterministic: the order is total (ties by
 * grid index).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/geom.h"
#include "util/check.h"
#include "util/rng.h"

#define CLUSTER_FANOUT 16
/* Two levels: a cluster holds at most 256 grids, the default gridsize, as
 * a grid holds at most that many micropolygons. A third and fourth level
 * (4,096 and 65,536 faces) halved the shading points again, but one value
 * shaded for a quarter of a wall is as noisy as one path, and is shared
 * by every ray that lands there: a closed room of 480,000 triangles at 3
 * bounces came out 1.7% dark over four seeds (two levels: 0.1%). */
#define CLUSTER_LEVELS 2
#define CLUSTER_CONE 0.25f    /* radians: half the cache's bend limit */
#define CLUSTER_COMPACT 3.0f  /* box diagonal over the square root of the area */
#define CLUSTER_THICK                                                                              \
    0.25f /* spread along the normal over the square root of the area:                             \
             stacked layers (foliage, boards) stay apart */

/* A grid small enough to cluster: a surface of at most 2 x 2
 * micropolygons, still (a moving grid's entries are per motion segment)
 * and outside solids (their hits depend on the tree). */
int geom_grid_tiny(const Grid *g)
{
    if (g->shape != GEOM_SHAPE_SURFACE || g->moving || g->solid)
        return 0;
    return g->triangular ? g->nu <= 2 : g->nu <= 3 && g->nv <= 3;
}

/* A grid's corner vertices (GridSet indices); returns how many. */
static int grid_corners(const Grid *g, size_t c[4])
{
    size_t f = g->first_vertex;
    if (g->triangular) {
        uint32_t n = g->nu;
        c[0] = f + geom_tri_vertex(n, 0, 0);
        c[1] = f + geom_tri_vertex(n, n, 0);
        c[2] = f + geom_tri_vertex(n, 0, n);
        return 3;
    }
    size_t nu = g->nu, nv = g->nv;
    c[0] = f, c[1] = f + nu - 1, c[2] = f + (nv - 1) * nu, c[3] = f + nv * nu - 1;
    return 4;
}

typedef struct Shape {
    Vec3 middle, normal; /* the corners' mean; the corners' normals' mean, unit */
    float area;
    Bounds3 box;
} Shape;

static Shape grid_shape(const GridSet *gs, const Grid *g)
{
    size_t c[4];
    int n = grid_corners(g, c);
    Shape s = {v3(0, 0, 0), v3(0, 0, 0), 0.0f, {gs->P[c[0]], gs->P[c[0]]}};
    for (int k = 0; k < n; k++) {
        Vec3 p = gs->P[c[k]];
        s.middle = v3_add(s.middle, p);
        s.normal = v3_add(s.normal, gs->N[c[k]]);
        /* the box by comparisons (fminf and fmaxf are calls here) */
        s.box.lo = v3(p.x < s.box.lo.x ? p.x : s.box.lo.x, p.y < s.box.lo.y ? p.y : s.box.lo.y,
                      p.z < s.box.lo.z ? p.z : s.box.lo.z);
        s.box.hi = v3(p.x > s.box.hi.x ? p.x : s.box.hi.x, p.y > s.box.hi.y ? p.y : s.box.hi.y,
                      p.z > s.box.hi.z ? p.z : s.box.hi.z);
    }
    s.middle = v3_scale(s.middle, 1.0f / (float)n);
    s.normal = v3_normalize(s.normal);
    Vec3 twice = n == 3 ? v3_cross(v3_sub(gs->P[c[1]], gs->P[c[0]]), v3_sub(gs->P[c[2]], gs->P[c[0]]))
                        : v3_cross(v3_sub(gs->P[c[3]], gs->P[c[0]]), v3_sub(gs->P[c[2]], gs->P[c[1]]));
    s.area = 0.5f * v3_length(twice);
    return s;
}

/* Whether grid g is clustered: tiny, of some area and a normal; its shape. */
static int clusterable(const GridSet *gs, const Grid *g, Shape *s)
{
    if (!geom_grid_tiny(g))
        return 0;
    *s = grid_shape(gs, g);
    return s->area > 0.0f && v3_dot(s->normal, s->normal) > 0.5f;
}

/* A tiny grid (in grid order; Sorted gives the order they are cut in). */
typedef struct Rec {
    uint64_t group; /* master << 32 | object */
    Shape shape;
    uint32_t grid;
    uint32_t parent; /* its first-level run's index + 1 */
} Rec;

typedef struct Sorted {
    uint64_t key; /* the rank of the record's group, then the Morton code of its middle */
    uint32_t rec;
} Sorted;

/* Sorts by key, ties in the order given (LSD radix sort by bytes, passing
 * over the bytes every key shares); tmp holds n. 0, or -1 when out of
 * memory. */
static int sort_keys(Sorted *a, Sorted *tmp, size_t n)
{
    enum { bytes = 8 };
    size_t (*count)[256] = calloc(bytes, sizeof *count);
    if (!count)
        return -1;
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < bytes; d++)
            count[d][(a[i].key >> (8 * d)) & 255]++;
    for (int d = 0; d < bytes; d++) {
        size_t at = 0, shared = 0;
        for (int v = 0; v < 256; v++)
            shared |= count[d][v] == n;
        if (shared)
            continue;
        for (int v = 0; v < 256; v++) {
            size_t c = count[d][v];
            count[d][v] = at;
            at += c;
        }
        for (size_t i = 0; i < n; i++)
            tmp[count[d][(a[i].key >> (8 * d)) & 255]++] = a[i];
        memcpy(a, tmp, n * sizeof *a);
    }
    free(count);
    return 0;
}

static uint64_t spread_bits(uint64_t x) /* 16 bits to every third of 48 */
{
    x &= 0xffff;
    x = (x | x << 16) & 0x0000ff0000ffull;
    x = (x | x << 8) & 0x00f00f00f00full;
    x = (x | x << 4) & 0x0c30c30c30c3ull;
    x = (x | x << 2) & 0x249249249249ull;
    return x;
}

/* The Morton code of p in box b, 16 bits an axis (cells of 1/65536 of the
 * box order neighbours well enough: runs check their shapes). */
static uint64_t morton(Vec3 p, Bounds3 b)
{
    uint64_t m = 0;
    for (int a = 0; a < 3; a++) {
        float lo = v3_index(b.lo, a), ext = v3_index(b.hi, a) - lo;
        float x = ext > 0.0f ? (v3_index(p, a) - lo) / ext : 0.0f;
        x = x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x;
        m |= spread_bits((uint64_t)(x * 65535.0f)) << a;
    }
    return m;
}

/* A run while building: records [first, end) and how many units of the
 * level below it took. */
typedef struct Build {
    uint32_t first, end, children;
    uint32_t parent; /* the run above: its index in Runs + 1; 0: none */
    Vec3 normal;     /* its first child's */
    float cone;      /* the angle its normals span about normal */
    float area;
    Vec3 weighted;   /* sum of area x middle */
    Bounds3 box;
    float depth[2]; /* the range of its middles (and its children's thickness) along normal */
    uint64_t group;
} Build;

/* Child c's range along r's normal: its middle, give or take half its
 * own thickness. */
static void depth_along(const Build *r, const Build *c, float *lo, float *hi)
{
    float mid = v3_dot(v3_scale(c->weighted, 1.0f / c->area), r->normal);
    float half = 0.5f * (c->depth[1] - c->depth[0]);
    *lo = fminf(r->depth[0], mid - half);
    *hi = fmaxf(r->depth[1], mid + half);
}

/* Whether run r may take child c (a grid's shape as a cluster of one). */
static int may_join(const Build *r, const Build *c)
{
    if (r->group != c->group || r->children >= CLUSTER_FANOUT)
        return 0;
    float cosine = fminf(fmaxf(v3_dot(r->normal, c->normal), -1.0f), 1.0f);
    if (acosf(cosine) + c->cone > CLUSTER_CONE)
        return 0;
    Bounds3 b = bounds_union(r->box, c->box);
    float diag = v3_length(v3_sub(b.hi, b.lo)), area = r->area + c->area, lo, hi;
    depth_along(r, c, &lo, &hi);
    return diag * diag <= CLUSTER_COMPACT * CLUSTER_COMPACT * area &&
           (hi - lo) * (hi - lo) <= CLUSTER_THICK * CLUSTER_THICK * area;
}

static void join(Build *r, const Build *c)
{
    float cosine = fminf(fmaxf(v3_dot(r->normal, c->normal), -1.0f), 1.0f);
    r->cone = fmaxf(r->cone, acosf(cosine) + c->cone);
    depth_along(r, c, &r->depth[0], &r->depth[1]);
    r->end = c->end;
    r->children++;
    r->area += c->area;
    r->weighted = v3_add(r->weighted, c->weighted);
    r->box = bounds_union(r->box, c->box);
}

typedef struct Runs {
    Build *b;
    size_t n, cap;
} Runs;

/* Unit u (a grid, or a cluster of the level below) joins the last run, or
 * starts one when it may not or when first says so. Returns the run's
 * index + 1, or 0 when out of memory. */
static uint32_t add_unit(Runs *rs, const Build *u, int first)
{
    if (!first && may_join(&rs->b[rs->n - 1], u)) {
        join(&rs->b[rs->n - 1], u);
        return (uint32_t)rs->n;
    }
    if (rs->n == rs->cap) {
        size_t cap = rs->cap ? 2 * rs->cap : 1024;
        Build *grown = realloc(rs->b, cap * sizeof *grown);
        if (!grown)
            return 0;
        rs->b = grown, rs->cap = cap;
    }
    Build run = *u;
    run.children = 1;
    run.parent = 0;
    rs->b[rs->n++] = run;
    return (uint32_t)rs->n;
}

/* The member of the cut order's records [first, end) whose middle is
 * nearest p. */
static uint32_t nearest_member(const Rec *recs, const Sorted *order, uint32_t first,
                               uint32_t end, Vec3 p)
{
    uint32_t best = recs[order[first].rec].grid;
    float best_d = INFINITY;
    for (uint32_t i = first; i < end; i++) {
        const Rec *r = &recs[order[i].rec];
        Vec3 d = v3_sub(r->shape.middle, p);
        float dd = v3_dot(d, d);
        if (dd < best_d)
            best_d = dd, best = r->grid;
    }
    return best;
}

static void drop(GridSet *gs)
{
    free(gs->grid_cluster);
    free(gs->clusters);
    gs->grid_cluster = NULL, gs->clusters = NULL, gs->n_clusters = 0;
}

static Build grid_unit(const Rec *r, uint32_t k)
{
    const Shape *s = &r->shape;
    float d = v3_dot(s->middle, s->normal);
    return (Build){k,         k + 1,  1,       0,
                   s->normal, 0.0f,   s->area, v3_scale(s->middle, s->area),
                   s->box,    {d, d}, r->group};
}

/* Runs of the records in order (the first level), then runs of the runs
 * of the level below, all in rs; each record's parent is its first-level
 * run's index + 1. */
static int cut_levels(Rec *recs, const Sorted *order, size_t n, Runs *rs)
{
    for (size_t k = 0; k < n; k++) {
        Rec *r = &recs[order[k].rec];
        Build u = grid_unit(r, (uint32_t)k);
        if (!(r->parent = add_unit(rs, &u, k == 0)))
            return -1;
    }
    if (rs->n == n) { /* nothing joined */
        rs->n = 0;
        return 0;
    }
    size_t first = 0, count = rs->n;
    for (int level = 1; level < CLUSTER_LEVELS && count > 1; level++) {
        size_t before = rs->n;
        for (size_t k = 0; k < count; k++) {
            Build u = rs->b[first + k]; /* a copy: the array may move */
            uint32_t up = add_unit(rs, &u, k == 0);
            if (!up)
                return -1;
            rs->b[first + k].parent = up;
        }
        if (rs->n - before == count) { /* nothing joined: drop the level */
            for (size_t k = 0; k < count; k++)
                rs->b[first + k].parent = 0;
            rs->n = before;
            break;
        }
        first = before, count = rs->n - before;
    }
    return 0;
}

/* The rank of each record's group in order of first appearance, into
 * ranks[i]; returns the number of groups, or 0 when out of memory. */
static size_t group_ranks(const Rec *recs, size_t n, uint32_t *ranks)
{
    size_t cap = 64, used = 0;
    uint64_t *keys = malloc(cap * sizeof *keys);
    uint32_t *vals = malloc(cap * sizeof *vals);
    if (!keys || !vals)
        goto fail;
    memset(vals, 0xff, cap * sizeof *vals);
    for (size_t i = 0; i < n; i++) {
        if (i && recs[i].group == recs[i - 1].group) {
            ranks[i] = ranks[i - 1];
            continue;
        }
        if (2 * (used + 1) > cap) { /* grow and rehash */
            size_t ncap = 2 * cap;
            uint64_t *nk = malloc(ncap * sizeof *nk);
            uint32_t *nv = malloc(ncap * sizeof *nv);
            if (!nk || !nv) {
                free(nk), free(nv);
                goto fail;
            }
            memset(nv, 0xff, ncap * sizeof *nv);
            for (size_t k = 0; k < cap; k++)
                if (vals[k] != UINT32_MAX) {
                    size_t h = (size_t)(hash_u64(keys[k]) & (ncap - 1));
                    while (nv[h] != UINT32_MAX)
                        h = (h + 1) & (ncap - 1);
                    nk[h] = keys[k], nv[h] = vals[k];
                }
            free(keys), free(vals);
            keys = nk, vals = nv, cap = ncap;
        }
        size_t h = (size_t)(hash_u64(recs[i].group) & (cap - 1));
        while (vals[h] != UINT32_MAX && keys[h] != recs[i].group)
            h = (h + 1) & (cap - 1);
        if (vals[h] == UINT32_MAX)
            keys[h] = recs[i].group, vals[h] = (uint32_t)used++;
        ranks[i] = vals[h];
    }
    free(keys), free(vals);
    return used;
fail:
    free(keys), free(vals);
    return 0;
}

int geom_cluster_grids(GridSet *gs)
{
    drop(gs);
    if (gs->n_grids > UINT32_MAX / 2) /* cache keys name clusters past the grids */
        return 0;
    size_t n = 0;
    for (size_t i = 0; i < gs->n_grids; i++)
        n += geom_grid_tiny(&gs->grids[i]);
    if (n < 2)
        return 0;
    Rec *recs = malloc(n * sizeof *recs);
    Sorted *order = malloc(n * sizeof *order), *tmp = malloc(n * sizeof *tmp);
    Runs rs = {NULL, 0, 0};
    uint32_t *kept = NULL;
    int failed = !recs || !order || !tmp;
    Bounds3 all = bounds_empty();
    n = 0;
    for (size_t i = 0; !failed && i < gs->n_grids; i++) {
        const Grid *g = &gs->grids[i];
        Shape s;
        if (!clusterable(gs, g, &s))
            continue;
        recs[n++] = (Rec){(uint64_t)g->master << 32 | g->object, s, (uint32_t)i, 0};
        all = bounds_add(all, s.middle);
    }
    /* The cut order: by group, then along the Morton curve (group ranks in
     * the top bits, as few as they need). */
    uint32_t *ranks = (uint32_t *)tmp; /* tmp is free until the sort */
    size_t groups = failed || n < 2 ? 0 : group_ranks(recs, n, ranks);
    failed |= n >= 2 && groups == 0;
    int rank_bits = 0;
    while (((size_t)1 << rank_bits) < groups)
        rank_bits++;
    for (size_t k = 0; !failed && k < n; k++) {
        uint64_t m = morton(recs[k].shape.middle, all);
        order[k].key = rank_bits ? (uint64_t)ranks[k] << (64 - rank_bits) | m >> RY_MAX(rank_bits - 16, 0) : m;
        order[k].rec = (uint32_t)k;
    }
    if (!failed && n >= 2) {
        failed = sort_keys(order, tmp, n) != 0 || cut_levels(recs, order, n, &rs) != 0;
    }
    free(tmp);
    if (!failed && rs.n) {
        kept = malloc(rs.n * sizeof *kept);
        gs->clusters = malloc(rs.n * sizeof *gs->clusters);
        gs->grid_cluster = calloc(gs->n_grids, sizeof *gs->grid_cluster);
        failed = !kept || !gs->clusters || !gs->grid_cluster;
    }
    /* Keep the runs of two children or more; each grid and kept cluster
     * points to its nearest kept ancestor. */
    for (size_t r = 0; !failed && r < rs.n; r++) {
        const Build *b = &rs.b[r];
        kept[r] = 0;
        if (b->children < 2)
            continue;
        GeomCluster *c = &gs->clusters[gs->n_clusters];
        c->rep = nearest_member(recs, order, b->first, b->end,
                                v3_scale(b->weighted, 1.0f / b->area));
        c->edge = sqrtf(b->area);
        c->parent = 0;
        kept[r] = (uint32_t)++gs->n_clusters;
    }
    if (!failed && gs->n_clusters && gs->n_clusters < rs.n) { /* only the kept */
        GeomCluster *fit = realloc(gs->clusters, gs->n_clusters * sizeof *fit);
        gs->clusters = fit ? fit : gs->clusters;
    }
    for (size_t r = 0; !failed && r < rs.n; r++) {
        uint32_t up = rs.b[r].parent;
        while (up && !kept[up - 1])
            up = rs.b[up - 1].parent;
        if (kept[r])
            gs->clusters[kept[r] - 1].parent = up ? kept[up - 1] : 0;
    }
    for (size_t k = 0; !failed && rs.n && k < n; k++) {
        uint32_t up = recs[k].parent;
        while (up && !kept[up - 1])
            up = rs.b[up - 1].parent;
        gs->grid_cluster[recs[k].grid] = up ? kept[up - 1] : 0;
    }
    /* A parent is at least as large as its child. */
    for (size_t c = 0; !failed && c < gs->n_clusters; c++)
        for (uint32_t p = gs->clusters[c].parent; p; p = gs->clusters[p - 1].parent)
            gs->clusters[p - 1].edge = fmaxf(gs->clusters[p - 1].edge, gs->clusters[c].edge);
    free(kept);
    free(rs.b);
    free(order);
    free(recs);
    if (failed) {
        drop(gs);
        return -1;
    }
    if (!gs->n_clusters) /* every run a single grid */
        drop(gs);
    return 0;
}
