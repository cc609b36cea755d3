/*
 * render/pbgi.c — point-based global illumination (pbgi.h; memo 5.3,
 * Christensen 2008, "Point-Based Approximate Color Bleeding").
 *
 * The octree: nodes split their disks' bounding box at its centre into
 * eight octants, leaves hold at most LEAF_DISKS disks (or the disks of a box
 * too small to split). Children of a node are contiguous. Each node holds
 * order-2 spherical harmonics of its disks' power toward a direction w
 * (sum L A max(0, N.w)) and of their projected area facing w (sum A
 * max(0, N.w)), each disk's zonal lobe projected exactly (coefficients
 * A_l Y_lm(N), A_l = pi, 2pi/3, pi/4 for the clamped cosine). A cluster
 * covers the larger of its areas facing P and facing away, with radiance
 * power / that area: a uniform cluster's radiance is exact.
 *
 * A gather at P, N: a cube raster in the frame of N (faces raster^2
 * pixels; those below the horizon weigh nothing but keep the shares of
 * fragments across it). The octree is traversed front to back (children
 * by distance from P, leaf disks likewise); a node whose bounding sphere
 * subtends less than max_solid_angle is splatted as one cluster (its power
 * and projected area toward P from the harmonics, splat_cluster), a
 * leaf's disks one by one (a disk's solid angle is that of a disk of its
 * area seen face on, times |cos| of its tilt: right near P too). Splats
 * are anti-aliased (splat): a fragment smaller than a pixel shares its
 * coverage bilinearly between four pixels (across a face's edge too), a
 * larger one covers the pixels inside its outline with a ramp at the
 * edge. Coverage adds up to 1 and no further: nearer fragments,
 * rasterised first, hide farther ones. The result is the sum over pixels
 * of radiance times cos d(omega), over pi; uncovered pixels are black, as
 * the sky is to diffuse rays.
 *
 * A record (pbgi_record, for irradiance interpolation) is the same gather
 * with each pixel's coverage-weighted fragment distance kept: its
 * gradients are sums over the pixels and over the walls between them.
 *
 * The passes shade whole grids through radiosity_shade_grid (the cache's
 * fill, FINE level, both sides; a master's grids once per instance), on
 * threads, each grid into its own slots: disks do not depend on threads,
 * and the octree is built on one thread.
 */
#include "render/pbgi.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/radiosity.h"
#include "util/check.h"
#include "util/thread.h"
#include "util/log.h"

#define LEAF_DISKS 8
#define MAX_TREE_DEPTH 32

/* ------------------------------------------------------------ harmonics */

/* The 9 real spherical harmonics at unit w. */
static void sh_eval(Vec3 w, float y[PBGI_SH])
{
    y[0] = 0.282095f;
    y[1] = 0.488603f * w.y;
    y[2] = 0.488603f * w.z;
    y[3] = 0.488603f * w.x;
    y[4] = 1.092548f * w.x * w.y;
    y[5] = 1.092548f * w.y * w.z;
    y[6] = 0.315392f * (3.0f * w.z * w.z - 1.0f);
    y[7] = 1.092548f * w.x * w.z;
    y[8] = 0.546274f * (w.x * w.x - w.y * w.y);
}

static int sh_band(int k)
{
    return k == 0 ? 0 : k < 4 ? 1 : 2;
}

/* A disk's power toward w is A (L max(0, N.w) + Lb max(0, -N.w)): the
 * back side is a disk facing -N, whose harmonics are the front's with band
 * 1 negated. The area stays the front's (splat_cluster takes the larger of
 * it at w and -w). */
static void node_add_disk(PbgiCluster *n, const PbgiDisk *d)
{
    static const float clamped[3] = {(float)M_PI, 2.0f * (float)M_PI / 3.0f, (float)M_PI / 4.0f};
    float y[PBGI_SH];
    sh_eval(v3_load(d->N), y);
    for (int k = 0; k < PBGI_SH; k++) {
        float p = d->area * clamped[sh_band(k)] * y[k], pb = sh_band(k) == 1 ? -p : p;
        for (int c = 0; c < 3; c++)
            n->power[k][c] += p * d->L[c] + pb * d->Lb[c];
        n->area[k] += d->area * clamped[sh_band(k)] * y[k];
    }
}

static void cluster_add(PbgiCluster *into, const PbgiCluster *ch)
{
    for (int q = 0; q < PBGI_SH; q++) {
        for (int col = 0; col < 3; col++)
            into->power[q][col] += ch->power[q][col];
        into->area[q] += ch->area[q];
    }
}

/* --------------------------------------------------------------- octree */

typedef struct Build {
    PbgiCloud *cloud;
    size_t cap_nodes;
    PbgiDisk *tmp;
    uint32_t *tmp_perm;
    int failed;
} Build;

static int octant(Vec3 p, Vec3 mid)
{
    return (p.x > mid.x) | (p.y > mid.y) << 1 | (p.z > mid.z) << 2;
}

static size_t new_nodes(Build *b, size_t n)
{
    PbgiCloud *c = b->cloud;
    if (c->n_nodes + n > b->cap_nodes) {
        size_t cap = RY_MAX(2 * b->cap_nodes, c->n_nodes + n);
        PbgiNode *nodes = realloc(c->nodes, cap * sizeof *nodes);
        if (nodes)
            c->nodes = nodes;
        PbgiCluster *cl = nodes ? realloc(c->clusters, cap * sizeof *cl) : NULL;
        if (!cl) {
            b->failed = 1;
            return (size_t)-1;
        }
        c->clusters = cl;
        b->cap_nodes = cap;
    }
    size_t first = c->n_nodes;
    memset(&c->nodes[first], 0, n * sizeof *c->nodes);
    memset(&c->clusters[first], 0, n * sizeof *c->clusters);
    c->n_nodes += n;
    return first;
}

/* Node `at` over disks [lo, hi): its box, its children (recursively), its
 * harmonics and bounding sphere. */
static void build_node(Build *b, size_t at, size_t lo, size_t hi, int depth)
{
    PbgiCloud *c = b->cloud;
    Bounds3 box = bounds_empty();
    for (size_t i = lo; i < hi; i++)
        box = bounds_add(box, v3_load(c->disks[i].P));
    Vec3 mid = v3_scale(v3_add(box.lo, box.hi), 0.5f);
    float extent = v3_max_component(v3_sub(box.hi, box.lo));
    PbgiNode *n = &c->nodes[at];
    v3_store(n->c, mid);
    if (hi - lo <= LEAF_DISKS || depth >= MAX_TREE_DEPTH || !(extent > 0.0f)) {
        n->leaf = 1;
        n->first = (uint32_t)lo;
        n->count = (uint16_t)RY_MIN(hi - lo, 65535);
        float r = 0.0f;
        for (size_t i = lo; i < lo + n->count; i++) {
            const PbgiDisk *d = &c->disks[i];
            node_add_disk(&c->clusters[at], d);
            r = fmaxf(r, v3_length(v3_sub(v3_load(d->P), mid)) + sqrtf(d->area / (float)M_PI));
        }
        n->r = r;
        return;
    }
    size_t count[8] = {0}, start[8];
    for (size_t i = lo; i < hi; i++)
        count[octant(v3_load(c->disks[i].P), mid)]++;
    int children = 0;
    for (int o = 0, s = (int)0; o < 8; o++) {
        start[o] = lo + (size_t)s;
        s += (int)count[o];
        children += count[o] > 0;
    }
    size_t fill[8];
    memcpy(fill, start, sizeof fill);
    for (size_t i = lo; i < hi; i++) {
        size_t k = fill[octant(v3_load(c->disks[i].P), mid)]++;
        b->tmp[k] = c->disks[i];
        b->tmp_perm[k] = c->perm[i];
    }
    memcpy(&c->disks[lo], &b->tmp[lo], (hi - lo) * sizeof *c->disks);
    memcpy(&c->perm[lo], &b->tmp_perm[lo], (hi - lo) * sizeof *c->perm);
    size_t first = new_nodes(b, (size_t)children);
    if (b->failed)
        return;
    n = &c->nodes[at]; /* new_nodes may have moved it */
    n->first = (uint32_t)first;
    n->count = (uint16_t)children;
    size_t k = first;
    for (int o = 0; o < 8; o++)
        if (count[o] > 0) {
            build_node(b, k++, start[o], start[o] + count[o], depth + 1);
            if (b->failed)
                return;
        }
    n = &c->nodes[at];
    float r = 0.0f;
    for (size_t j = first; j < first + (size_t)children; j++) {
        cluster_add(&c->clusters[at], &c->clusters[j]);
        r = fmaxf(r, v3_length(v3_sub(v3_load(c->nodes[j].c), mid)) + c->nodes[j].r);
    }
    n->r = r;
}

/* The harmonics of node `at` and below from its disks' radiosities. */
static void relight_node(PbgiCloud *c, size_t at)
{
    const PbgiNode *n = &c->nodes[at];
    memset(&c->clusters[at], 0, sizeof c->clusters[at]);
    if (n->leaf) {
        for (size_t i = n->first; i < n->first + n->count; i++)
            node_add_disk(&c->clusters[at], &c->disks[i]);
        return;
    }
    for (size_t j = n->first; j < n->first + n->count; j++) {
        relight_node(c, j);
        cluster_add(&c->clusters[at], &c->clusters[j]);
    }
}

void pbgi_cloud_relight(PbgiCloud *cloud, const float (*L)[3], const float (*Lb)[3])
{
    for (size_t k = 0; k < cloud->n_disks; k++) {
        memcpy(cloud->disks[k].L, L[cloud->perm[k]], sizeof cloud->disks[k].L);
        memcpy(cloud->disks[k].Lb, Lb[cloud->perm[k]], sizeof cloud->disks[k].Lb);
    }
    if (cloud->n_nodes)
        relight_node(cloud, 0);
}

/* --------------------------------------------------------------- raster */

/* Face f's axes: the major axis a, and u, v. */
static void face_axes(int f, int *a, int *u, int *v)
{
    *a = f / 2;
    *u = *a == 0 ? 1 : 0;
    *v = *a == 2 ? 1 : 2;
}

static int raster_tables(PbgiCloud *c)
{
    int R = c->raster, n = 6 * R * R;
    c->pix_of = malloc((size_t)n * sizeof *c->pix_of);
    c->pix_dir = malloc((size_t)n * sizeof *c->pix_dir);
    c->pix_weight = malloc((size_t)n * sizeof *c->pix_weight);
    c->pix_omega = malloc((size_t)n * sizeof *c->pix_omega);
    if (!c->pix_of || !c->pix_dir || !c->pix_weight || !c->pix_omega)
        return -1;
    double sum = 0.0;
    int m = 0;
    for (int upper = 1; upper >= 0; upper--) /* the upper pixels first */
        for (int f = 0; f < 6; f++) {
            int a, u, v;
            face_axes(f, &a, &u, &v);
            for (int j = 0; j < R; j++)
                for (int i = 0; i < R; i++) {
                    float x = -1.0f + (2.0f * (float)i + 1.0f) / (float)R;
                    float y = -1.0f + (2.0f * (float)j + 1.0f) / (float)R;
                    float d[3];
                    d[a] = f % 2 ? -1.0f : 1.0f;
                    d[u] = x;
                    d[v] = y;
                    Vec3 dir = v3_normalize(v3_load(d));
                    if ((dir.z > 0.0f) != upper)
                        continue;
                    float r2 = 1.0f + x * x + y * y;
                    c->pix_of[(f * R + j) * R + i] = m;
                    v3_store(c->pix_dir[m], dir);
                    c->pix_omega[m] = 4.0f / (float)(R * R) / (r2 * sqrtf(r2));
                    c->pix_weight[m] = upper ? dir.z * c->pix_omega[m] : 0.0f;
                    sum += c->pix_weight[m];
                    if (upper)
                        c->n_upper = m + 1;
                    m++;
                }
        }
    for (int k = 0; k < m; k++)
        c->pix_weight[k] = (float)(c->pix_weight[k] * M_PI / sum);
    c->n_pix = m;
    return 0;
}

/* Where direction l (local, l.z > 0) falls: its face and continuous
 * pixel coordinates (pixel centres at integers). */
static int face_coords(const PbgiCloud *c, Vec3 l, float *x, float *y)
{
    float al[3] = {fabsf(l.x), fabsf(l.y), fabsf(l.z)}, lv[3] = {l.x, l.y, l.z};
    int a = al[0] >= al[1] && al[0] >= al[2] ? 0 : al[1] >= al[2] ? 1 : 2;
    int f = 2 * a + (lv[a] < 0.0f), u, v;
    face_axes(f, &a, &u, &v);
    *x = (lv[u] / al[a] + 1.0f) * 0.5f * (float)c->raster - 0.5f;
    *y = (lv[v] / al[a] + 1.0f) * 0.5f * (float)c->raster - 0.5f;
    return f;
}

/* Pixel (i, j) of face f, indices clamped into the face. */
static int face_pixel(const PbgiCloud *c, int f, int i, int j)
{
    int R = c->raster;
    i = RY_MIN(RY_MAX(i, 0), R - 1);
    j = RY_MIN(RY_MAX(j, 0), R - 1);
    return c->pix_of[(f * R + j) * R + i];
}

/* The pixel of a bilinear tap (i, j) of face f: itself inside the face;
 * beyond an edge, the pixel of the adjacent face that the tap's centre,
 * on the face's plane extended, falls in (clamping into the face would
 * pile a fragment near an edge onto one face's edge pixel and starve the
 * other face's). */
static int tap_pixel(const PbgiCloud *c, int f, int i, int j)
{
    int R = c->raster;
    if (i >= 0 && i < R && j >= 0 && j < R)
        return c->pix_of[(f * R + j) * R + i];
    int a, u, v;
    face_axes(f, &a, &u, &v);
    float d[3], x, y;
    d[a] = f % 2 ? -1.0f : 1.0f;
    d[u] = -1.0f + (2.0f * (float)i + 1.0f) / (float)R;
    d[v] = -1.0f + (2.0f * (float)j + 1.0f) / (float)R;
    int g = face_coords(c, v3_load(d), &x, &y);
    return face_pixel(c, g, (int)floorf(x + 0.5f), (int)floorf(y + 0.5f));
}

/* The walls between adjacent upper pixels, across the faces' edges too,
 * for the translational gradient (pbgi_record). A wall is an arc of a
 * great circle (a cube edge's or a pixel edge's image on the sphere): its
 * normal on the sphere is constant along it, the normal of the circle's
 * plane, and the integral of the unit direction along an arc from w0 to
 * w1 is (w0 + w1) tan(gamma / 2), gamma the arc's angle. */
static int wall_tables(PbgiCloud *c)
{
    int R = c->raster;
    c->wall_pix = malloc((size_t)12 * R * R * sizeof *c->wall_pix);
    c->wall_vec = malloc((size_t)12 * R * R * sizeof *c->wall_vec);
    if (!c->wall_pix || !c->wall_vec)
        return -1;
    c->n_walls = 0;
    for (int f = 0; f < 6; f++) {
        int a, u, v;
        face_axes(f, &a, &u, &v);
        for (int j = 0; j < R; j++)
            for (int i = 0; i < R; i++)
                for (int e = 0; e < 4; e++) { /* the pixel's left, right, lower, upper edge */
                    int di = e == 0 ? -1 : e == 1 ? 1 : 0, dj = e == 2 ? -1 : e == 3 ? 1 : 0;
                    int p = c->pix_of[(f * R + j) * R + i], q = tap_pixel(c, f, i + di, j + dj);
                    if (q <= p || q >= c->n_upper) /* once a wall, upper pixels only */
                        continue;
                    float w[2][3];
                    for (int k = 0; k < 2; k++) { /* the edge's ends on the face */
                        int ci = di ? i + (di > 0) : i + k, cj = dj ? j + (dj > 0) : j + k;
                        w[k][a] = f % 2 ? -1.0f : 1.0f;
                        w[k][u] = -1.0f + 2.0f * (float)ci / (float)R;
                        w[k][v] = -1.0f + 2.0f * (float)cj / (float)R;
                    }
                    Vec3 w0 = v3_normalize(v3_load(w[0])), w1 = v3_normalize(v3_load(w[1]));
                    Vec3 m = v3_normalize(v3_cross(w0, w1));
                    if (v3_dot(m, v3_load(c->pix_dir[q])) < 0.0f)
                        m = v3_neg(m);
                    float along = v3_length(v3_cross(w0, w1)) / (1.0f + v3_dot(w0, w1));
                    float cos_len = (w0.z + w1.z) * along; /* the integral of cos(theta) */
                    if (!(cos_len > 0.0f))
                        continue; /* on the horizon */
                    c->wall_pix[c->n_walls][0] = p;
                    c->wall_pix[c->n_walls][1] = q;
                    v3_store(c->wall_vec[c->n_walls++], v3_scale(m, cos_len));
                }
    }
    return 0;
}

int pbgi_raster_init(PbgiRaster *r, const PbgiCloud *cloud)
{
    r->cov = malloc((size_t)cloud->n_pix * sizeof *r->cov);
    r->col = malloc((size_t)cloud->n_pix * sizeof *r->col);
    r->tmp = malloc((size_t)cloud->n_pix * sizeof *r->tmp);
    r->dist = malloc((size_t)cloud->n_pix * sizeof *r->dist);
    if (!r->cov || !r->col || !r->tmp || !r->dist) {
        pbgi_raster_fini(r);
        return -1;
    }
    return 0;
}

void pbgi_raster_fini(PbgiRaster *r)
{
    free(r->cov);
    free(r->col);
    free(r->tmp);
    free(r->dist);
    r->cov = NULL;
    r->col = NULL;
    r->tmp = NULL;
    r->dist = NULL;
}

PbgiCloud *pbgi_cloud_new(PbgiDisk *disks, size_t n, float max_solid_angle, int raster)
{
    PbgiCloud *c = calloc(1, sizeof *c);
    if (!c) {
        free(disks);
        return NULL;
    }
    c->disks = disks;
    c->n_disks = n;
    c->max_solid_angle = max_solid_angle;
    c->raster = raster;
    c->perm = malloc(RY_MAX(n, 1) * sizeof *c->perm);
    Build b = {.cloud = c};
    b.tmp = malloc(RY_MAX(n, 1) * sizeof *b.tmp);
    b.tmp_perm = malloc(RY_MAX(n, 1) * sizeof *b.tmp_perm);
    int ok = c->perm && b.tmp && b.tmp_perm && raster_tables(c) == 0 && wall_tables(c) == 0;
    if (ok) {
        for (size_t i = 0; i < n; i++)
            c->perm[i] = (uint32_t)i;
        if (n > 0 && new_nodes(&b, 1) == 0)
            build_node(&b, 0, 0, n, 0);
        ok = !b.failed;
    }
    free(b.tmp);
    free(b.tmp_perm);
    if (!ok) {
        pbgi_cloud_free(c);
        return NULL;
    }
    return c;
}

void pbgi_cloud_free(PbgiCloud *c)
{
    if (!c)
        return;
    free(c->disks);
    free(c->perm);
    free(c->nodes);
    free(c->clusters);
    free(c->pix_of);
    free(c->pix_dir);
    free(c->pix_weight);
    free(c->pix_omega);
    free(c->wall_pix);
    free(c->wall_vec);
    free(c);
}

/* --------------------------------------------------------------- gather */

typedef struct Gather {
    const PbgiCloud *c;
    PbgiRaster *r;
    Vec3 P, N, T, B;
    int full;                  /* pixels fully covered */
} Gather;

static void cover(Gather *g, int p, float cov, Vec3 L, float dist)
{
    float have = g->r->cov[p];
    if (have >= 1.0f)
        return;
    float a = fminf(cov, 1.0f - have);
    g->r->cov[p] = have + a;
    g->r->col[p][0] += a * L.x;
    g->r->col[p][1] += a * L.y;
    g->r->col[p][2] += a * L.z;
    g->r->dist[p] += a * dist;
    if (have + a >= 1.0f - 1e-6f) {
        g->r->cov[p] = 1.0f;
        g->full += p < g->c->n_upper;
    }
}

/* A fragment of solid angle omega and radiance L in unit world direction
 * d at distance dist, anti-aliased: one smaller than a pixel shares its coverage between
 * the four pixels about it (bilinear), a larger one covers the pixels
 * within its outline with a ramp a pixel wide at the edge, scaled so that
 * its coverages times the pixels' solid angles add up to omega. The
 * outline is an ellipse whose minor axis, along the unit world vector
 * `minor` (across d), is `squash` (in (0, 1]) times its major axis: a
 * tilted disk's. Then fragments that tile a surface cover the raster
 * evenly, without the gaps and overlaps of whole pixels or of circles
 * (with those, a furnace lost 10-20%, and 3-7% near its wall). */
static void splat(Gather *g, Vec3 d, float dist, float omega, Vec3 L, Vec3 minor, float squash)
{
    const PbgiCloud *c = g->c;
    Vec3 l = v3(v3_dot(d, g->T), v3_dot(d, g->B), v3_dot(d, g->N));
    if (l.z < -0.5f || !(omega > 0.0f))
        return; /* nothing of it above the horizon (cones wider than 30 degrees aside) */
    float x, y;
    int f = face_coords(c, l, &x, &y);
    int i = (int)floorf(x), j = (int)floorf(y);
    float fx = x - (float)i, fy = y - (float)j;
    int centre = face_pixel(c, f, (int)floorf(x + 0.5f), (int)floorf(y + 0.5f));
    if (omega <= c->pix_omega[centre]) {
        if (l.z < -3.0f / (float)c->raster)
            return; /* its pixels are all below the horizon */
        const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
        for (int k = 0; k < 4; k++) {
            int p = tap_pixel(c, f, i + (k & 1), j + (k >> 1));
            if (w[k] > 0.0f)
                cover(g, p, w[k] * omega / c->pix_omega[p], L, dist);
        }
        return;
    }
    squash = fminf(fmaxf(squash, 1e-3f), 1.0f);
    float face_on = fminf(omega / squash, 2.0f * (float)M_PI);
    float major = acosf(1.0f - face_on / (2.0f * (float)M_PI)), minor_r = major * squash;
    Vec3 m = v3(v3_dot(minor, g->T), v3_dot(minor, g->B), v3_dot(minor, g->N));
    float ramp = 2.0f / (float)c->raster; /* about a pixel's angular width near the axis */
    float cos_out = cosf(fminf(major + 0.5f * ramp, (float)M_PI));
    float *t = g->r->tmp, sum = 0.0f;
    for (int q = 0; q < c->n_pix; q++) {
        Vec3 p = v3_load(c->pix_dir[q]);
        float dq = v3_dot(p, l);
        t[q] = 0.0f;
        if (dq < cos_out)
            continue;
        float ang = acosf(fminf(dq, 1.0f));
        Vec3 across = v3_sub(p, v3_scale(l, dq)); /* |across| = sin(ang) */
        float s = v3_length(across);
        float a = s > 1e-12f ? v3_dot(across, m) / s * ang : 0.0f; /* along the minor axis */
        float b2 = fmaxf(ang * ang - a * a, 0.0f);
        float e = sqrtf(a * a / (minor_r * minor_r) + b2 / (major * major));
        /* the distance to the outline along this direction: ang (1 / e - 1) */
        t[q] = e <= 0.0f ? 1.0f : fminf(fmaxf(ang * (1.0f / e - 1.0f) / ramp + 0.5f, 0.0f), 1.0f);
        sum += t[q] * c->pix_omega[q];
    }
    if (!(sum > 0.0f))
        return; /* all below the horizon */
    float scale = fminf(omega, 2.0f * (float)M_PI) / sum;
    for (int q = 0; q < c->n_pix; q++)
        if (t[q] > 0.0f)
            cover(g, q, t[q] * scale, L, dist);
}

static void splat_disk(Gather *g, const PbgiDisk *k)
{
    Vec3 v = v3_sub(v3_load(k->P), g->P);
    float dist2 = v3_dot(v, v);
    if (!(dist2 > 0.0f) || k->area <= 0.0f)
        return;
    float dist = sqrtf(dist2);
    Vec3 d = v3_scale(v, 1.0f / dist), n = v3_load(k->N);
    float cosk = v3_dot(n, d); /* < 0: the disk faces P */
    float r2 = k->area / (float)M_PI;
    float omega = 2.0f * (float)M_PI * (1.0f - dist / sqrtf(dist2 + r2)) * fabsf(cosk);
    Vec3 L = v3_load(cosk < 0.0f ? k->L : k->Lb); /* seen from behind: the back side's */
    Vec3 across = v3_sub(n, v3_scale(d, cosk)); /* the normal across d: the outline's minor axis */
    float s = v3_length(across);
    Vec3 minor = s > 1e-6f ? v3_scale(across, 1.0f / s) : g->T;
    splat(g, d, dist, omega, L, minor, fabsf(cosk));
}

/* A node as one cluster, seen from P along -d. */
static void splat_cluster(Gather *g, const PbgiCluster *n, Vec3 d, float dist)
{
    float y[PBGI_SH];
    sh_eval(v3_neg(d), y); /* toward P */
    float front = 0.0f, back = 0.0f, pw[3] = {0, 0, 0};
    for (int k = 0; k < PBGI_SH; k++) {
        front += n->area[k] * y[k];
        back += sh_band(k) == 1 ? -n->area[k] * y[k] : n->area[k] * y[k]; /* at -w */
        for (int c = 0; c < 3; c++)
            pw[c] += n->power[k][c] * y[k];
    }
    /* What covers the raster: the disks facing P, or those facing away
     * where more of them do (a closed object shows P as much of either:
     * its silhouette). The same harmonics for power and area make a
     * uniform cluster's radiance exact. */
    float area = fmaxf(front, back);
    if (!(area > 0.0f))
        return;
    Vec3 L = v3(fmaxf(pw[0], 0.0f) / area, fmaxf(pw[1], 0.0f) / area, fmaxf(pw[2], 0.0f) / area);
    splat(g, d, dist, area / (dist * dist), L, g->T, 1.0f);
}

/* Squared distance from P: the order of the walk. */
static float node_distance2(const Gather *g, const PbgiNode *n)
{
    Vec3 v = v3_sub(v3_load(n->c), g->P);
    return v3_dot(v, v);
}

static void traverse(Gather *g, const PbgiNode *n)
{
    const PbgiCloud *c = g->c;
    if (g->full >= c->n_upper)
        return;
    Vec3 v = v3_sub(v3_load(n->c), g->P);
    float dist = v3_length(v);
    if (v3_dot(v, g->N) < -n->r)
        return; /* below the horizon */
    if (dist > n->r && (float)M_PI * n->r * n->r < c->max_solid_angle * dist * dist) {
        splat_cluster(g, &c->clusters[n - c->nodes], v3_scale(v, 1.0f / dist), dist);
        return;
    }
    if (n->leaf) {
        uint32_t order[LEAF_DISKS];
        float key[LEAF_DISKS];
        int m = RY_MIN((int)n->count, LEAF_DISKS);
        if (n->count > LEAF_DISKS) { /* a box too small to split: any order */
            for (uint32_t i = n->first; i < n->first + n->count; i++)
                splat_disk(g, &c->disks[i]);
            return;
        }
        for (int i = 0; i < m; i++) { /* insertion sort, nearest first */
            Vec3 v = v3_sub(v3_load(c->disks[n->first + i].P), g->P);
            float k = v3_dot(v, v);
            int j = i;
            for (; j > 0 && key[j - 1] > k; j--) {
                key[j] = key[j - 1];
                order[j] = order[j - 1];
            }
            key[j] = k;
            order[j] = n->first + (uint32_t)i;
        }
        for (int i = 0; i < m; i++)
            splat_disk(g, &c->disks[order[i]]);
        return;
    }
    uint32_t order[8];
    float key[8];
    int m = n->count;
    for (int i = 0; i < m; i++) {
        float k = node_distance2(g, &c->nodes[n->first + i]);
        int j = i;
        for (; j > 0 && key[j - 1] > k; j--) {
            key[j] = key[j - 1];
            order[j] = order[j - 1];
        }
        key[j] = k;
        order[j] = n->first + (uint32_t)i;
    }
    for (int i = 0; i < m; i++)
        traverse(g, &c->nodes[order[i]]);
}

/* Rasterises the cloud as seen from P, N into r; g is the gather's frame. */
static void rasterise(const PbgiCloud *c, PbgiRaster *r, Vec3 P, Vec3 N, Gather *g)
{
    *g = (Gather){.c = c, .r = r, .P = P, .N = N};
    v3_basis(N, &g->T, &g->B);
    memset(r->cov, 0, (size_t)c->n_pix * sizeof *r->cov);
    memset(r->col, 0, (size_t)c->n_pix * sizeof *r->col);
    memset(r->dist, 0, (size_t)c->n_pix * sizeof *r->dist);
    if (c->n_nodes)
        traverse(g, &c->nodes[0]);
}

Vec3 pbgi_gather(const PbgiCloud *c, PbgiRaster *r, Vec3 P, Vec3 N)
{
    Gather g;
    rasterise(c, r, P, N, &g);
    double s[3] = {0, 0, 0};
    for (int p = 0; p < c->n_upper; p++)
        for (int k = 0; k < 3; k++)
            s[k] += (double)c->pix_weight[p] * r->col[p][k];
    return v3((float)(s[0] / M_PI), (float)(s[1] / M_PI), (float)(s[2] / M_PI));
}

/* The gather's record. Rotational gradient: turning the normal by a small
 * rotation vector alpha changes each direction's cosine by alpha . (N x
 * w), so grad_r = sum over upper pixels of L_p omega_p (N x w_p) (the
 * tan(theta) v_k sum of Ward and Heckbert on their strata). Translational
 * gradient: moving P by dx moves the outline of the nearer surface at a
 * wall between pixels p and q by -dx across w over its distance, trading
 * solid angle between them: grad_t = sum over walls of (L_q - L_p) m
 * (integral of cos(theta) along it) / min(r_p, r_q), m its normal into q,
 * Ward and Heckbert's formula with the raster's walls for their strata's
 * (DESIGN.md, "Point-based global illumination"); in the tangent plane, as
 * theirs. Pixel depths are their fragments' coverage-weighted distances. */
void pbgi_record(const PbgiCloud *c, PbgiRaster *r, Vec3 P, Vec3 N, IrrRecord *rec)
{
    Gather g;
    rasterise(c, r, P, N, &g);
    double E[3] = {0, 0, 0}, rot[3][2] = {{0, 0}, {0, 0}, {0, 0}};
    double tr[3][2] = {{0, 0}, {0, 0}, {0, 0}};
    IrrRadius radius = IRR_RADIUS_INIT;
    for (int p = 0; p < c->n_upper; p++) {
        const float *w = c->pix_dir[p], *L = r->col[p];
        float omega = c->pix_weight[p] / w[2]; /* the solid angle, normalised as the weights */
        for (int k = 0; k < 3; k++) {
            E[k] += (double)c->pix_weight[p] * L[k];
            rot[k][0] -= (double)(omega * w[1] * L[k]); /* N x w = (-w.y, w.x, 0) */
            rot[k][1] += (double)(omega * w[0] * L[k]);
        }
        r->dist[p] = r->cov[p] > 0.0f ? r->dist[p] / r->cov[p] : INFINITY;
        irr_radius_add(&radius, r->dist[p], w[2]);
    }
    for (int k = 0; k < c->n_walls; k++) {
        int p = c->wall_pix[k][0], q = c->wall_pix[k][1];
        float rr = fminf(r->dist[p], r->dist[q]);
        if (!isfinite(rr) || !(rr > 0.0f))
            continue;
        for (int ch = 0; ch < 3; ch++) {
            double d = (double)(r->col[q][ch] - r->col[p][ch]) / rr;
            tr[ch][0] += d * c->wall_vec[k][0];
            tr[ch][1] += d * c->wall_vec[k][1];
        }
    }
    rec->p = P;
    rec->n = N;
    rec->E = v3((float)E[0], (float)E[1], (float)E[2]);
    for (int k = 0; k < 3; k++) {
        rec->grad_r[k] = v3_add(v3_scale(g.T, (float)rot[k][0]), v3_scale(g.B, (float)rot[k][1]));
        rec->grad_t[k] = v3_add(v3_scale(g.T, (float)tr[k][0]), v3_scale(g.B, (float)tr[k][1]));
    }
    rec->R = irr_radius(&radius);
}

/* --------------------------------------------------------------- passes */

/* A grid of the cloud: grid `grid` seen through `instance` (0: world
 * geometry; else an object instance + 1 of the grid's master). */
typedef struct CloudGrid {
    uint32_t grid, instance;
} CloudGrid;

/* Whether grid g seen through instance goes into the cloud: a surface,
 * curve or point grid (world geometry, or a master's grid through an
 * instance of it; curves and points as diced, facing the eye: a ribbon's
 * quads, a point's square) whose object has a shader (lights do not: diffuse rays see them black, direct
 * lighting counts them). */
static int cloud_grid(const RenderScene *rs, uint32_t g, uint32_t instance)
{
    const Grid *grid = &rs->gs->grids[g];
    if ((grid->master != 0) != (instance != 0) ||
        (!instance && grid->object == GEOM_OBJECT_INHERIT))
        return 0;
    return render_object(rs, g, instance)->shader != NULL;
}

/* The cloud's grids: world geometry's in grid order, then each instance's
 * master grids, instances in order. *n gets their count; NULL when out of
 * memory. */
static CloudGrid *cloud_grids(const RenderScene *rs, size_t *n)
{
    const GridSet *gs = rs->gs;
    uint32_t *mfirst = calloc(gs->n_masters + 1, sizeof *mfirst);
    uint32_t *mcount = calloc(gs->n_masters + 1, sizeof *mcount);
    size_t cap = gs->n_grids;
    for (uint32_t g = 0; mfirst && mcount && g < gs->n_grids; g++) {
        uint32_t m = gs->grids[g].master; /* a master's grids are contiguous */
        if (m && mcount[m - 1]++ == 0)
            mfirst[m - 1] = g;
    }
    for (size_t i = 0; mcount && i < gs->n_instances; i++)
        cap += mcount[gs->instances[i].master];
    CloudGrid *out = mfirst && mcount ? malloc(RY_MAX(cap, 1) * sizeof *out) : NULL;
    *n = 0;
    if (out) {
        for (uint32_t g = 0; g < gs->n_grids; g++)
            if (cloud_grid(rs, g, 0))
                out[(*n)++] = (CloudGrid){g, 0};
        for (size_t i = 0; i < gs->n_instances; i++) {
            uint32_t m = gs->instances[i].master;
            for (uint32_t g = mfirst[m]; g < mfirst[m] + mcount[m]; g++)
                if (cloud_grid(rs, g, (uint32_t)i + 1))
                    out[(*n)++] = (CloudGrid){g, (uint32_t)i + 1};
        }
    }
    free(mfirst);
    free(mcount);
    return out;
}

/* Disks of grid g: its micropolygons (quads; a triangular grid's lattice
 * triangles). */
static size_t grid_disk_count(const Grid *g)
{
    return g->triangular ? (size_t)g->nu * g->nu : (size_t)(g->nu - 1) * (g->nv - 1);
}

/* Values (vertices) of a grid's FINE level, in the fill's order. */
static size_t grid_values(const Grid *g)
{
    size_t n = g->nu;
    return g->triangular ? (n + 1) * (n + 2) / 2 : n * g->nv;
}

/* The fill's index of triangular lattice point (i, j), i + j <= n: rows
 * j = 0..n of n + 1 - j points. */
static size_t tri_value(int n, int i, int j)
{
    return (size_t)j * (size_t)(n + 1) - (size_t)j * (size_t)(j - 1) / 2 + (size_t)i;
}

/* One disk over the polygon of k vertices (grid vertex vi[], fill value
 * ki[]), facing the vertices' normals; in world space through inst (or
 * NULL). */
static void polygon_disk(const GridSet *gs, const Grid *g, const GeomInstance *inst,
                         const uint32_t *vi, const size_t *ki, int k, const float (*val)[3],
                         const float (*valb)[3], PbgiDisk *out)
{
    Vec3 P = v3(0, 0, 0), N = P, L = P, Lb = P, p[4];
    for (int a = 0; a < k; a++) {
        uint32_t v = g->first_vertex + vi[a];
        p[a] = inst ? mat4_point(&inst->world_from_master, gs->P[v]) : gs->P[v];
        P = v3_add(P, p[a]);
        N = v3_add(N, inst ? mat4_vector(&inst->normal_to_world, gs->N[v]) : gs->N[v]);
        L = v3_add(L, v3_load(val[ki[a]]));
        Lb = v3_add(Lb, v3_load(valb[ki[a]]));
    }
    Vec3 x = k == 4 ? v3_cross(v3_sub(p[2], p[0]), v3_sub(p[3], p[1]))
                    : v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
    float len = v3_length(x);
    Vec3 n = len > 0.0f ? v3_scale(x, 1.0f / len) : v3_normalize(N);
    if (v3_dot(n, N) < 0.0f)
        n = v3_neg(n);
    v3_store(out->P, v3_scale(P, 1.0f / (float)k));
    v3_store(out->N, n);
    out->area = 0.5f * len;
    v3_store(out->L, v3_scale(L, 1.0f / (float)k));
    v3_store(out->Lb, v3_scale(Lb, 1.0f / (float)k));
}

/* The disks of grid g from its vertices' values, front (val) and back
 * (valb). */
static void grid_disks(const GridSet *gs, const Grid *g, const GeomInstance *inst,
                       const float (*val)[3], const float (*valb)[3], PbgiDisk *out)
{
    if (!g->triangular) {
        int nu = g->nu;
        for (int j = 0; j + 1 < g->nv; j++)
            for (int i = 0; i + 1 < nu; i++) {
                /* counter-clockwise: (i, j), (i+1, j), (i+1, j+1), (i, j+1) */
                uint32_t vi[4] = {(uint32_t)(j * nu + i), (uint32_t)(j * nu + i + 1),
                                  (uint32_t)((j + 1) * nu + i + 1), (uint32_t)((j + 1) * nu + i)};
                size_t ki[4] = {vi[0], vi[1], vi[2], vi[3]};
                polygon_disk(gs, g, inst, vi, ki, 4, val, valb, out++);
            }
        return;
    }
    int n = g->nu;
    for (int j = 0; j < n; j++)
        for (int i = 0; i + j < n; i++) {
            int tri[2][3][2] = {{{i, j}, {i + 1, j}, {i, j + 1}},
                                {{i + 1, j}, {i + 1, j + 1}, {i, j + 1}}};
            for (int t = 0; t < 2; t++) {
                if (t == 1 && i + j + 2 > n)
                    continue;
                uint32_t vi[3];
                size_t ki[3];
                for (int a = 0; a < 3; a++) {
                    vi[a] = geom_tri_vertex((uint32_t)n, (uint32_t)tri[t][a][0],
                                            (uint32_t)tri[t][a][1]);
                    ki[a] = tri_value(n, tri[t][a][0], tri[t][a][1]);
                }
                polygon_disk(gs, g, inst, vi, ki, 3, val, valb, out++);
            }
        }
}

typedef struct Pass {
    const RenderScene *rs;
    const RenderSettings *set;
    Worker *workers;
    const CloudGrid *grids;    /* the cloud's grids */
    size_t n_grids;
    const size_t *first;       /* per cloud grid: its first disk; first[n_grids]: all */
    PbgiDisk *disks;           /* pass 1: geometry and radiosity */
    float (*L)[3], (*Lb)[3];   /* pass 2: radiosity alone, per disk in grid order */
    int depth;                 /* the diffuse depth the grids are shaded at */
} Pass;

static void pass_grid(void *ctx, size_t task, int worker)
{
    Pass *p = ctx;
    const GridSet *gs = p->rs->gs;
    const CloudGrid *cg = &p->grids[task];
    const Grid *g = &gs->grids[cg->grid];
    const GeomInstance *inst = render_instance(p->rs, cg->instance);
    size_t nd = grid_disk_count(g);
    size_t nv = grid_values(g);
    float(*val)[3] = malloc(2 * nv * sizeof *val), (*valb)[3] = val + nv;
    PbgiDisk *tmp = p->disks ? NULL : malloc(nd * sizeof *tmp);
    RY_CHECK(val && (p->disks || tmp));
    /* both sides, as the ray-traced cache keeps an entry for each */
    radiosity_shade_grid(&p->workers[worker], cg->grid, cg->instance, p->depth, 0, val);
    radiosity_shade_grid(&p->workers[worker], cg->grid, cg->instance, p->depth, 1, valb);
    const float(*cv)[3] = (const float(*)[3])val, (*cvb)[3] = (const float(*)[3])valb;
    if (p->disks) {
        grid_disks(gs, g, inst, cv, cvb, &p->disks[p->first[task]]);
    } else {
        grid_disks(gs, g, inst, cv, cvb, tmp);
        for (size_t k = 0; k < nd; k++) {
            memcpy(p->L[p->first[task] + k], tmp[k].L, sizeof *p->L);
            memcpy(p->Lb[p->first[task] + k], tmp[k].Lb, sizeof *p->Lb);
        }
        free(tmp);
    }
    free(val);
}

/* Shades every cloud grid at p->depth on the thread pool. */
static void run_pass(Pass *p, const RayesShaderServices *services, RenderStats *stats)
{
    int threads = p->set->threads > 0 ? p->set->threads : thread_count_cores();
    p->workers = aligned_alloc(WORKER_ALIGN, (size_t)threads * sizeof *p->workers);
    RY_CHECK(p->workers != NULL);
    memset(p->workers, 0, (size_t)threads * sizeof *p->workers);
    for (int i = 0; i < threads; i++) {
        p->workers[i] = (Worker){.rs = p->rs, .set = p->set, .services = services, .split = 1.0f};
        if (p->set->cache)
            cache_local_init(&p->workers[i].cache, p->set->cache);
    }
    thread_parallel_for(threads, p->n_grids, pass_grid, p);
    for (int i = 0; i < threads; i++) {
        const RenderStats *s = &p->workers[i].stats;
        stats->rays_shadow += s->rays_shadow;
        stats->rays_diffuse += s->rays_diffuse;
        stats->rays_specular += s->rays_specular;
        stats->opacity_points += s->opacity_points;
        stats->transparent_hits += s->transparent_hits;
        stats->holes += s->holes;
        stats->hole_points += s->hole_points;
        stats->table_lookups += s->table_lookups;
        stats->table_fills += s->table_fills;
        for (int d = 0; d <= RENDER_MAX_DEPTH; d++)
            stats->shading_points[d] += s->shading_points[d];
        if (p->set->cache)
            cache_local_fini(&p->workers[i].cache);
    }
    free(p->workers);
    p->workers = NULL;
}

PbgiCloud *pbgi_build(const RenderScene *rs, const RenderSettings *set,
                      const RayesShaderServices *services, RenderStats *stats, PbgiTimes *times)
{
    const GridSet *gs = rs->gs;
    size_t n_grids;
    CloudGrid *grids = cloud_grids(rs, &n_grids);
    size_t *first = grids ? malloc((n_grids + 1) * sizeof *first) : NULL;
    if (!first) {
        free(grids);
        return NULL;
    }
    first[0] = 0;
    for (size_t k = 0; k < n_grids; k++)
        first[k + 1] = first[k] + grid_disk_count(&gs->grids[grids[k].grid]);
    size_t n = first[n_grids];
    PbgiDisk *disks = malloc(RY_MAX(n, 1) * sizeof *disks);
    if (!disks) {
        free(first);
        free(grids);
        return NULL;
    }
    /* Pass 1: direct lighting only (shaded at the last depth, where the
     * indirect-diffuse service traces nothing). */
    RenderSettings direct = *set;
    direct.pbgi = NULL;
    double t0 = time_now();
    Pass p = {.rs = rs, .set = &direct, .grids = grids, .n_grids = n_grids, .first = first,
              .disks = disks, .depth = set->bounces};
    run_pass(&p, services, stats);
    double t1 = time_now();
    PbgiCloud *cloud = pbgi_cloud_new(disks, n, set->pbgi_max_solid_angle, set->pbgi_raster);
    double t2 = time_now();
    times->cloud_s += t1 - t0;
    times->octree_s += t2 - t1;
    if (!cloud || set->bounces < 2) {
        free(first);
        free(grids);
        return cloud;
    }
    /* Pass 2: bounce k reshades the grids at depth bounces - k, their
     * indirect diffuse gathered from the cloud of k - 1 bounces. */
    float(*L)[3] = malloc(2 * RY_MAX(n, 1) * sizeof *L), (*Lb)[3] = L + RY_MAX(n, 1);
    if (!L) {
        free(first);
        free(grids);
        pbgi_cloud_free(cloud);
        return NULL;
    }
    for (int k = 1; k < set->bounces; k++) {
        RenderSettings bounce = *set;
        bounce.pbgi = cloud;
        double t3 = time_now();
        Pass q = {.rs = rs, .set = &bounce, .grids = grids, .n_grids = n_grids, .first = first,
                  .L = L, .Lb = Lb, .depth = set->bounces - k};
        run_pass(&q, services, stats);
        double t4 = time_now();
        pbgi_cloud_relight(cloud, (const float(*)[3])L, (const float(*)[3])Lb);
        times->bounces_s += t4 - t3;
        times->octree_s += time_now() - t4;
    }
    free(L);
    free(first);
    free(grids);
    return cloud;
}

/* ------------------------------------------------------------------ PLY */

int pbgi_write_ply(const PbgiCloud *c, const char *path, char *err, size_t err_size)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        snprintf(err, err_size, "point cloud: cannot write %s: %s", path, strerror(errno));
        return -1;
    }
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\ncomment rayes point cloud (docs/cli.md): "
            "disks, radiosity r g b as outgoing radiance toward n, back_r back_g back_b "
            "against it\nelement vertex %zu\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "property float area\nproperty float r\nproperty float g\nproperty float b\n"
            "property float back_r\nproperty float back_g\nproperty float back_b\n"
            "end_header\n",
            c->n_disks);
    int ok = 1;
    for (size_t i = 0; i < c->n_disks && ok; i++) {
        const PbgiDisk *d = &c->disks[i];
        float rec[13] = {d->P[0], d->P[1], d->P[2], d->N[0],  d->N[1],  d->N[2], d->area,
                         d->L[0], d->L[1], d->L[2], d->Lb[0], d->Lb[1], d->Lb[2]};
        unsigned char b[52];
        for (int k = 0; k < 13; k++) { /* little-endian whatever the host */
            uint32_t u;
            memcpy(&u, &rec[k], 4);
            for (int q = 0; q < 4; q++)
                b[4 * k + q] = (unsigned char)(u >> (8 * q));
        }
        ok = fwrite(b, 1, sizeof b, f) == sizeof b;
    }
    if (fclose(f) != 0 || !ok) {
        snprintf(err, err_size, "point cloud: cannot write %s: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}
