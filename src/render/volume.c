/*
 * render/volume.c — volumes by ray marching, their extinction cached in
 * bricks (volume.h).
 *
 * A ray's segment inside a box is cut into n equal steps of about one fine
 * voxel (times the volume step option), each sampled once at a jittered
 * position (one jitter per ray, from a hash of the ray: deterministic).
 * Extinction at the samples comes from the opacity cache (a brick entry
 * at the resolution the ray's footprint chooses, trilinear) or, uncached,
 * from one call of the shader's opacity method on all of a ray's samples.
 */
#include "render/volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "shade/builtin.h"
#include "util/check.h"
#include "util/half.h"
#include "util/rng.h"

/* Steps of one ray through one volume, at most. */
#define VOLUME_MAX_STEPS 4096

/* Points of a camera or specular ray's segment through a volume where the
 * medium's lighting (its shadow rays) is computed, at most: production
 * renderers light volumes more coarsely than they sample extinction. */
#define VOLUME_LIGHT_SAMPLES 16

/* The same for a diffuse ray's segment (a radiosity fill's, a medium's
 * scattered ray): many of them stand for one surface point's or one
 * medium point's light, so each is lit at one point, and a medium's
 * scattered light follows one path through the bounces (its lighting
 * point's own scattered ray) instead of branching at each. */
#define VOLUME_DIFFUSE_LIGHT_SAMPLES 1

/* A march ends where the optical depth on every channel passes this:
 * the transmittance is below 1e-4 there (exp(-9.21)), and what lies
 * behind adds at most that much of itself (RenderMan's opacity
 * threshold, at 0.9999). */
#define VOLUME_TAU_CUTOFF 9.21f

static int opaque_enough(Vec3 tau)
{
    return tau.x > VOLUME_TAU_CUTOFF && tau.y > VOLUME_TAU_CUTOFF && tau.z > VOLUME_TAU_CUTOFF;
}

uint32_t volume_init(RenderVolume *v, uint32_t object, const Mat4 *world_from_object, Vec3 lo,
                     Vec3 hi, float voxel, uint32_t key_base)
{
    memset(v, 0, sizeof *v);
    v->object = object;
    v->world_from_object = *world_from_object;
    if (!mat4_invert(*world_from_object, &v->object_from_world))
        return 0;
    v->lo = v3(fminf(lo.x, hi.x), fminf(lo.y, hi.y), fminf(lo.z, hi.z));
    v->hi = v3(fmaxf(lo.x, hi.x), fmaxf(lo.y, hi.y), fmaxf(lo.z, hi.z));
    Vec3 ext = v3_sub(v->hi, v->lo);
    if (!(ext.x > 0.0f && ext.y > 0.0f && ext.z > 0.0f) || !(voxel > 0.0f))
        return 0;
    /* world length of a unit of object space along each axis */
    float scale[3] = {v3_length(mat4_vector(world_from_object, v3(1, 0, 0))),
                      v3_length(mat4_vector(world_from_object, v3(0, 1, 0))),
                      v3_length(mat4_vector(world_from_object, v3(0, 0, 1)))};
    float e[3] = {ext.x, ext.y, ext.z}, cell[3];
    float longest = fmaxf(e[0] * scale[0], fmaxf(e[1] * scale[1], e[2] * scale[2]));
    voxel = fmaxf(voxel, longest / VOLUME_MAX_VOXELS);
    uint32_t bricks = 1;
    for (int a = 0; a < 3; a++) {
        v->n_vox[a] = (int)fminf(fmaxf(ceilf(e[a] * scale[a] / voxel), 1.0f), VOLUME_MAX_VOXELS);
        cell[a] = e[a] / (float)v->n_vox[a];
        v->n_brick[a] = (v->n_vox[a] + VOLUME_BRICK - 1) / VOLUME_BRICK;
        bricks *= (uint32_t)v->n_brick[a];
    }
    v->cell = v3(cell[0], cell[1], cell[2]);
    v->voxel = voxel;
    v->key_base = key_base;
    return bricks;
}

/* The ray's parameter range [*t0, *t1] inside the box, within [tnear,
 * tmax]; 0 if it misses. */
static int clip(const RenderVolume *v, const Ray *ray, float tmax, float *t0, float *t1)
{
    Vec3 o = mat4_point(&v->object_from_world, ray->o);
    Vec3 d = mat4_vector(&v->object_from_world, ray->d);
    float lo[3] = {v->lo.x, v->lo.y, v->lo.z}, hi[3] = {v->hi.x, v->hi.y, v->hi.z};
    float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    float a = ray->tnear, b = tmax;
    for (int k = 0; k < 3; k++) {
        if (dd[k] == 0.0f) {
            if (oo[k] < lo[k] || oo[k] > hi[k])
                return 0;
            continue;
        }
        float inv = 1.0f / dd[k], ta = (lo[k] - oo[k]) * inv, tb = (hi[k] - oo[k]) * inv;
        if (ta > tb) {
            float s = ta;
            ta = tb;
            tb = s;
        }
        a = fmaxf(a, ta);
        b = fminf(b, tb);
    }
    *t0 = a;
    *t1 = b;
    return b > a;
}

/* A deterministic number in [0, 1) for a ray (its origin and direction). */
static float ray_jitter(const Ray *ray)
{
    uint32_t bits[6];
    memcpy(bits, &ray->o, sizeof(float) * 3);
    memcpy(bits + 3, &ray->d, sizeof(float) * 3);
    uint64_t h = 0x766f6cull;
    for (int k = 0; k < 6; k++)
        h = hash_combine(h, bits[k]);
    return rng_float(h);
}

/* Crossings of a hidden bounding surface a ray follows, at most: past
 * them the ray stays as the last one left it. A closed surface makes a
 * segment of every two; one whose normals disagree may make one of each. */
#define VOLUME_MAX_CROSSINGS 64
#define VOLUME_MAX_SEGMENTS (VOLUME_MAX_CROSSINGS + 1)

/* The parts of [t0, t1] along the ray inside a volume's hidden bounding
 * object (v->hidden_bound), at most VOLUME_MAX_SEGMENTS of them, into seg;
 * returns their count. Its surfaces are met one after another
 * in its own scene: a crossing against the normal enters it, one along
 * the normal leaves it (its inside is behind its normals, as for
 * rayes_scene_volume_inside), and the first crossing says whether the
 * ray started inside. */
static int inside_segments(const Worker *w, const RenderVolume *v, const Ray *ray, float t0,
                           float t1, float (*seg)[2])
{
    Ray r = *ray;
    r.tnear = 0.0f;
    r.tfar = INFINITY;
    int n = 0, inside = -1; /* -1: not known yet */
    float from = t0;
    for (int k = 0; k < VOLUME_MAX_CROSSINGS; k++) {
        Hit h;
        if (!accel_intersect_object(w->rs->accel, (uint32_t)v->inside, &r, &h))
            break;
        int entering = v3_dot(h.Ng, ray->d) < 0.0f;
        if (inside < 0)
            inside = !entering;
        if (inside && h.t > from && from < t1)
            seg[n][0] = from, seg[n][1] = fminf(h.t, t1), n++;
        inside = entering;
        from = fmaxf(h.t, t0);
        if (h.t >= t1)
            return n;
        r.tnear = nextafterf(h.t, INFINITY) + 1e-6f * h.t;
    }
    if (inside > 0 && from < t1) /* left inside (an open surface, or too many crossings) */
        seg[n][0] = from, seg[n][1] = t1, n++;
    return n;
}

/* Steps through [t0, t1]: n of them, dt apart (ray parameter), the first
 * sample at t0 + jitter dt. */
typedef struct March {
    int n;
    float t0, dt, jitter, dl; /* dl: a step's world length */
} March;

int volume_uniform(const RenderObject *obj)
{
    return obj->shader && obj->shader->cls == &shade_class_homogeneous &&
           obj->shader->n_patterns == 0;
}

/* A march of at most max_steps (a uniform volume's: its extinction needs
 * no more). */
static March march(const Worker *w, const RenderVolume *v, const Ray *ray, float t0, float t1,
                   float jitter, int max_steps)
{
    float len = v3_length(ray->d), world = (t1 - t0) * len;
    float h = v->voxel * w->set->volume_step;
    int n = (int)fminf(fmaxf(ceilf(world / h), 1.0f), (float)max_steps);
    March m = {n, t0, (t1 - t0) / (float)n, jitter, world / (float)n};
    return m;
}

/* ----------------------------------------------------------- the points */

/* What a shader call on n volume points needs. */
typedef struct VolumePoints {
    size_t n;
    float (*P)[3], (*N)[3], (*I)[3], (*zero3)[3], (*Cs)[3], (*Os)[3], (*Ci)[3], (*Oi)[3];
    float *u, *v, *s, *zero1;
    uint64_t *keys;
    RayDiff *diff;
    int *back;
} VolumePoints;

static void points_alloc(VolumePoints *p, size_t n)
{
    memset(p, 0, sizeof *p);
    p->n = n;
    float(*f3)[3] = calloc(n * 8, sizeof *f3);
    float *f1 = calloc(n * 4, sizeof *f1);
    p->keys = calloc(n, sizeof *p->keys);
    p->diff = calloc(n, sizeof *p->diff);
    p->back = calloc(n, sizeof *p->back);
    RY_CHECK(f3 && f1 && p->keys && p->diff && p->back);
    p->P = f3, p->N = f3 + n, p->I = f3 + 2 * n, p->zero3 = f3 + 3 * n, p->Cs = f3 + 4 * n;
    p->Os = f3 + 5 * n, p->Ci = f3 + 6 * n, p->Oi = f3 + 7 * n;
    p->u = f1, p->v = f1 + n, p->s = f1 + 2 * n, p->zero1 = f1 + 3 * n;
}

static void points_free(VolumePoints *p)
{
    free(p->P);
    free(p->u);
    free(p->keys);
    free(p->diff);
    free(p->back);
}

/* Point i at object-space q (world P), seen along unit I (zero: none). */
static void point_put(VolumePoints *p, size_t i, const RenderVolume *v, const RenderObject *obj,
                      Vec3 q, Vec3 I)
{
    Vec3 P = mat4_point(&v->world_from_object, q), ext = v3_sub(v->hi, v->lo);
    v3_store(p->P[i], P);
    v3_store(p->I[i], I);
    v3_store(p->N[i], v3_length(I) > 0.0f ? v3_neg(I) : v3(0, 0, 1));
    memcpy(p->Cs[i], obj->Cs, sizeof p->Cs[i]);
    memcpy(p->Os[i], obj->Os, sizeof p->Os[i]);
    p->u[i] = (q.x - v->lo.x) / ext.x;
    p->v[i] = (q.y - v->lo.y) / ext.y;
    p->s[i] = (q.z - v->lo.z) / ext.z;
}

/* The context of p's n points (ray_type, I or not). */
static RayesShadeCtx points_ctx(const VolumePoints *p, size_t n, uint32_t ray_type, int with_I,
                                int diffuse_depth, int specular_depth, PathState *ps)
{
    RayesShadeCtx c = {
        .n_points = n, .ray_type = ray_type, .diffuse_depth = diffuse_depth,
        .specular_depth = specular_depth, .P = (const float(*)[3])p->P,
        .N = (const float(*)[3])p->N, .Ng = (const float(*)[3])p->N,
        .dPdu = (const float(*)[3])p->zero3, .dPdv = (const float(*)[3])p->zero3, .u = p->u,
        .v = p->v, .s = p->s, .t = p->zero1, .du = p->zero1, .dv = p->zero1,
        .I = with_I ? (const float(*)[3])p->I : NULL, .Cs = (const float(*)[3])p->Cs,
        .Os = (const float(*)[3])p->Os, .renderer = ps, .backfacing = p->back,
    };
    return c;
}

/* Runs the opacity method on p's n points: sigma_t into p->Oi. */
static void run_extinction(Worker *w, const RenderObject *obj, VolumePoints *p, size_t n)
{
    PathState ps = {w, p->keys, p->diff, p->zero1, p->zero1, NULL, UINT32_MAX, NULL, NULL, 1};
    RayesShadeCtx ctx = points_ctx(p, n, RAYES_RAY_TRANSMISSION, 0, 0, 0, &ps);
    RayesShadeOutputs o = {p->Ci, p->Oi, NULL, NULL};
    w->stats.opacity_points += n;
    shade_run_opacity(w->services, &ctx, obj->shader, &o);
}

/* ---------------------------------------------------------- the bricks */

/* Points per side of a brick's level, and the fine voxels between them. */
static int level_points(int level)
{
    return level == CACHE_FINE ? VOLUME_BRICK + 1 : level == CACHE_MEDIUM ? 3 : 2;
}

static int level_spacing(int level)
{
    return VOLUME_BRICK / (level_points(level) - 1);
}

/* The coarsest level whose spacing is at most k times the footprint. */
static int choose_level(const Worker *w, const RenderVolume *v, float footprint)
{
    if (w->set->cache_resolution >= 0)
        return w->set->cache_resolution;
    for (int level = CACHE_COARSE; level < CACHE_FINE; level++)
        if (v->voxel * (float)level_spacing(level) <= w->set->cache_k * footprint)
            return level;
    return CACHE_FINE;
}

typedef struct BrickJob {
    Worker *w;
    const RenderVolume *v;
    int b[3]; /* the brick */
} BrickJob;

/* CacheFillFn: sigma_t at the brick level's lattice points. */
static void fill_brick(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    BrickJob *job = user;
    const RenderVolume *v = job->v;
    const RenderObject *obj = &job->w->rs->objects[v->object];
    int m = level_points(key->level), sp = level_spacing(key->level);
    VolumePoints p;
    points_alloc(&p, n);
    size_t i = 0;
    for (int z = 0; z < m; z++)
        for (int y = 0; y < m; y++)
            for (int x = 0; x < m; x++, i++) {
                Vec3 q = v3(v->lo.x + v->cell.x * (float)(job->b[0] * VOLUME_BRICK + x * sp),
                            v->lo.y + v->cell.y * (float)(job->b[1] * VOLUME_BRICK + y * sp),
                            v->lo.z + v->cell.z * (float)(job->b[2] * VOLUME_BRICK + z * sp));
                point_put(&p, i, v, obj, q, v3(0, 0, 0));
                p.keys[i] = hash_combine(key->patch, i);
                p.diff[i] = (RayDiff){v->voxel * (float)sp, 0.0f};
            }
    run_extinction(job->w, obj, &p, n);
    memcpy(out, p.Oi, n * sizeof *out);
    points_free(&p);
}

/* x clamped to [lo, hi], NaN to lo (no libm call: fminf and fmaxf are
 * calls without -ffinite-math-only, and this runs at every step). */
static inline float clamp_step(float x, float lo, float hi)
{
    return x > lo ? (x < hi ? x : hi) : lo;
}

/* The entry a march looked up last, and the cell of it that it decoded
 * last: consecutive steps mostly stay in one brick at one level (coarse
 * and medium steps in one cell too), and nothing else looks up an entry
 * between them, so its values stay valid (cache.h) and the lookup, or the
 * decoding, is skipped. */
typedef struct LastBrick {
    uint32_t patch;
    int level;
    const uint16_t *vals;
    int cell;         /* the decoded cell's index in the entry, -1 none */
    float c[4][6];    /* its corners: rows (y, z) = 00, 10, 01, 11; x, x + 1; rgb */
} LastBrick;

#define LAST_BRICK_NONE {0, -1, NULL, -1, {{0}}}

/* The corners of the cell at lattice point (x, y, z) of an entry with m
 * points a side, into last (each row's two corners lie side by side). */
static void decode_cell(LastBrick *last, int m, int x, int y, int z)
{
    for (int r = 0; r < 4; r++) {
        size_t i = 3 * ((size_t)((z + (r >> 1)) * m + y + (r & 1)) * m + x);
        half_to_float_finite_x6(last->vals + i, last->c[r]);
    }
}

/* Cached sigma_t at object-space q for a ray of that footprint. */
static Vec3 extinction_cached(Worker *w, const RenderVolume *v, Vec3 q, float footprint,
                              LastBrick *last)
{
    float f[3] = {(q.x - v->lo.x) / v->cell.x, (q.y - v->lo.y) / v->cell.y,
                  (q.z - v->lo.z) / v->cell.z};
    int b[3];
    float r[3]; /* position in the brick, fine voxels */
    uint32_t brick = 0;
    for (int a = 2; a >= 0; a--) {
        float c = clamp_step(f[a], 0.0f, (float)v->n_vox[a]);
        b[a] = RY_MIN((int)(c / VOLUME_BRICK), v->n_brick[a] - 1);
        r[a] = c - (float)(b[a] * VOLUME_BRICK);
        brick = brick * (uint32_t)v->n_brick[a] + (uint32_t)b[a];
    }
    int level = choose_level(w, v, footprint), m = level_points(level);
    float sp = (float)level_spacing(level);
    if (!last->vals || last->patch != v->key_base + brick || last->level != level) {
        CacheKey key = {.patch = v->key_base + brick, .type = CACHE_OPACITY,
                        .level = (uint8_t)level};
        BrickJob job = {w, v, {b[0], b[1], b[2]}};
        last->vals = cache_lookup(&w->cache, &key, (size_t)m * m * m, fill_brick, &job);
        last->patch = key.patch;
        last->level = level;
        last->cell = -1;
    }
    int i[3];
    float t[3];
    for (int a = 0; a < 3; a++) {
        float x = r[a] / sp;
        i[a] = RY_MIN((int)x, m - 2);
        t[a] = clamp_step(x - (float)i[a], 0.0f, 1.0f);
    }
    int cell = (i[2] * m + i[1]) * m + i[0];
    if (cell != last->cell) {
        decode_cell(last, m, i[0], i[1], i[2]);
        last->cell = cell;
    }
    float out[3];
    for (int k = 0; k < 3; k++) {
        const float(*c)[6] = last->c;
        float c00 = c[0][k] + (c[0][k + 3] - c[0][k]) * t[0];
        float c10 = c[1][k] + (c[1][k + 3] - c[1][k]) * t[0];
        float c01 = c[2][k] + (c[2][k + 3] - c[2][k]) * t[0];
        float c11 = c[3][k] + (c[3][k + 3] - c[3][k]) * t[0];
        float c0 = c00 + (c10 - c00) * t[1], c1 = c01 + (c11 - c01) * t[1];
        out[k] = c0 + (c1 - c0) * t[2];
    }
    return v3(out[0], out[1], out[2]);
}

/* sigma_t at the march's samples into p->Oi (p holds the samples' points),
 * up to the step where the march is opaque enough (VOLUME_TAU_CUTOFF):
 * returns the count of steps before it and that one. Uncached, the
 * shader runs on chunks of steps in turn. */
static int extinction_at(Worker *w, const RenderVolume *v, const Ray *ray, RayDiff diff,
                         const March *m, VolumePoints *p)
{
    const RenderObject *obj = &w->rs->objects[v->object];
    Vec3 tau = v3(0, 0, 0);
    if (!(w->set->opacity_cache && obj->opacity_cached)) {
        enum { CHUNK = 64 };
        for (int i0 = 0; i0 < m->n; i0 += CHUNK) {
            int n = RY_MIN(CHUNK, m->n - i0);
            VolumePoints part = *p; /* the chunk's points: p's arrays from i0 */
            part.P += i0, part.N += i0, part.I += i0, part.Cs += i0, part.Os += i0;
            part.Ci += i0, part.Oi += i0, part.u += i0, part.v += i0, part.s += i0;
            part.keys += i0, part.diff += i0, part.back += i0;
            run_extinction(w, obj, &part, (size_t)n);
            for (int i = i0; i < i0 + n; i++) {
                tau = v3_madd(tau, v3_load(p->Oi[i]), m->dl);
                if (opaque_enough(tau))
                    return i + 1;
            }
        }
        return m->n;
    }
    float len = v3_length(ray->d);
    LastBrick last = LAST_BRICK_NONE;
    /* object space is an affine image of world space: step along it */
    Vec3 q0 = mat4_point(&v->object_from_world, ray->o);
    Vec3 dq = mat4_vector(&v->object_from_world, ray->d);
    if (v->uniform && m->n > 0) { /* one extinction everywhere: one lookup */
        float t = m->t0 + m->jitter * m->dt;
        Vec3 s = extinction_cached(w, v, v3_madd(q0, dq, t), diff.width + diff.spread * t * len,
                                   &last);
        for (int i = 0; i < m->n; i++)
            v3_store(p->Oi[i], s);
        return m->n;
    }
    for (int i = 0; i < m->n; i++) {
        float t = m->t0 + ((float)i + m->jitter) * m->dt;
        Vec3 s =
            extinction_cached(w, v, v3_madd(q0, dq, t), diff.width + diff.spread * t * len, &last);
        v3_store(p->Oi[i], s);
        tau = v3_madd(tau, s, m->dl);
        if (opaque_enough(tau))
            return i + 1;
    }
    return m->n;
}

/* The step of lighting point j of n_light on a march of n steps: the
 * middle of its stratum. */
static int light_step(int j, int n, int n_light)
{
    return (int)(((float)j + 0.5f) * (float)n / (float)n_light);
}

/* The steps of a march's lighting points, increasing, into at[]; returns
 * their count, at most n_light. With as many steps as points, every step.
 * Else the middles of n_light strata of equal weight, a step's weight what
 * it adds to the ray, T (1 - exp(-sigma_t dl)) (the mean over channels),
 * a step holding several middles taken once: the points gather where the
 * ray sees the medium, not in empty space or behind its opaque front
 * (steps of equal count put most of them where they added nothing to a
 * dense cloud, which came out 9% dark beside 512 points, 7.5% with its
 * march cut at VOLUME_TAU_CUTOFF; now within noise). Where no step adds
 * anything, strata of equal step counts (light_step). u places the
 * points in their strata: 0.5 their middles; a diffuse ray's one point is
 * drawn in proportion to the weight (u random), so its source, taken as
 * the whole segment's, is right on average. */
static int light_steps(const VolumePoints *p, const March *m, int n_light, float u, int *at)
{
    if (n_light >= m->n) {
        for (int i = 0; i < m->n; i++)
            at[i] = i;
        return m->n;
    }
    double total = 0.0, tau = 0.0;
    for (int i = 0; i < m->n; i++) {
        double s = (double)(p->Oi[i][0] + p->Oi[i][1] + p->Oi[i][2]) / 3.0 * m->dl;
        total += exp(-tau) * -expm1(-s);
        tau += s;
    }
    if (!(total > 1e-12) || !isfinite(total)) {
        for (int j = 0; j < n_light; j++)
            at[j] = light_step(j, m->n, n_light);
        return n_light;
    }
    int n = 0, j = 0;
    double sum = 0.0;
    tau = 0.0;
    for (int i = 0; i < m->n && j < n_light; i++) {
        double s = (double)(p->Oi[i][0] + p->Oi[i][1] + p->Oi[i][2]) / 3.0 * m->dl;
        sum += exp(-tau) * -expm1(-s);
        tau += s;
        int taken = 0;
        while (j < n_light && ((double)j + u) / n_light * total <= sum) {
            if (!taken++)
                at[n++] = i;
            j++;
        }
    }
    if (n == 0) /* roundings left every middle past the last step */
        at[n++] = m->n - 1;
    return n;
}

/* Fills p with the march's sample points. */
static void march_points(const RenderVolume *v, const RenderObject *obj, const Ray *ray,
                         const March *m, uint64_t key, RayDiff diff, VolumePoints *p)
{
    Vec3 I = v3_normalize(ray->d);
    float len = v3_length(ray->d);
    for (int i = 0; i < m->n; i++) {
        float t = m->t0 + ((float)i + m->jitter) * m->dt;
        Vec3 q = mat4_point(&v->object_from_world, v3_madd(ray->o, ray->d, t));
        point_put(p, (size_t)i, v, obj, q, I);
        p->keys[i] = hash_combine(key, (uint64_t)i);
        p->diff[i] = (RayDiff){diff.width + diff.spread * t * len, diff.spread};
    }
}

static Vec3 v3_exp_neg(Vec3 a)
{
    return v3(expf(-a.x), expf(-a.y), expf(-a.z));
}

/* The optical depth of the march from cached extinction (no points to
 * shade: the shadow ray's own steps, nothing allocated). */
static Vec3 optical_depth_cached(Worker *w, const RenderVolume *v, const Ray *ray, RayDiff diff,
                                 const March *m)
{
    float len = v3_length(ray->d);
    LastBrick last = LAST_BRICK_NONE;
    Vec3 q0 = mat4_point(&v->object_from_world, ray->o);
    Vec3 dq = mat4_vector(&v->object_from_world, ray->d), tau = v3(0, 0, 0);
    for (int i = 0; i < m->n; i++) {
        float t = m->t0 + ((float)i + m->jitter) * m->dt;
        tau = v3_add(tau, v3_scale(extinction_cached(w, v, v3_madd(q0, dq, t),
                                                     diff.width + diff.spread * t * len, &last),
                                   m->dl));
        if (opaque_enough(tau))
            break; /* the steps beyond could only darken it further */
    }
    return tau;
}

/* ----------------------------------------------------------- the rays */

Vec3 volume_transmittance(Worker *w, const Ray *ray, RayDiff diff)
{
    Vec3 T = v3(1, 1, 1);
    int counted = 0;
    for (size_t k = 0; k < w->rs->n_volumes; k++) {
        const RenderVolume *v = &w->rs->volumes[k];
        float t0, t1, seg[VOLUME_MAX_SEGMENTS][2];
        /* inside an opaque object: no shadow ray from outside reaches it;
         * an atmosphere stands between surfaces and the eye alone */
        if (v->atmosphere || (v->inside >= 0 && !v->shadow_crosses) ||
            !clip(v, ray, ray->tfar, &t0, &t1))
            continue;
        int n_seg = 1;
        if (v->shadow_crosses)
            n_seg = inside_segments(w, v, ray, t0, t1, seg);
        else
            seg[0][0] = t0, seg[0][1] = t1;
        if (n_seg && !counted++)
            w->stats.rays_transmission++;
        const RenderObject *obj = &w->rs->objects[v->object];
        Vec3 tau = v3(0, 0, 0);
        float jitter = ray_jitter(ray);
        for (int s = 0; s < n_seg; s++) {
            March m =
                march(w, v, ray, seg[s][0], seg[s][1], jitter, v->uniform ? 1 : VOLUME_MAX_STEPS);
            if (w->set->opacity_cache && obj->opacity_cached) {
                tau = v3_add(tau, optical_depth_cached(w, v, ray, diff, &m));
            } else {
                VolumePoints p;
                points_alloc(&p, (size_t)m.n);
                march_points(v, obj, ray, &m, 0, diff, &p);
                int n = extinction_at(w, v, ray, diff, &m, &p);
                for (int i = 0; i < n; i++)
                    tau = v3_madd(tau, v3_load(p.Oi[i]), m.dl);
                points_free(&p);
            }
            w->stats.volume_steps += (uint64_t)m.n;
            if (opaque_enough(tau))
                break;
        }
        T = v3_mul(T, v3_exp_neg(tau));
    }
    return T;
}

/* The light one segment [t0, t1] of the ray through volume v adds, into
 * *Lv, and its transmittance, into *Tv. */
static void segment_radiance(Worker *w, const RenderVolume *v, const Ray *ray, float t0, float t1,
                             uint32_t kind, int diffuse_depth, int specular_depth, uint64_t vkey,
                             RayDiff diff, Vec3 *Lv_out, Vec3 *Tv_out)
{
    const RenderObject *obj = &w->rs->objects[v->object];
    /* Every ray that carries light sees the medium's: camera and specular
     * rays, and diffuse rays (multiple scattering: the light a medium
     * scatters reaches surfaces and other parts of it) */
    int scatter = (kind & (RAYES_RAY_CAMERA | RAYES_RAY_SPECULAR | RAYES_RAY_DIFFUSE)) != 0;
    int max_light = kind & RAYES_RAY_DIFFUSE ? VOLUME_DIFFUSE_LIGHT_SAMPLES : VOLUME_LIGHT_SAMPLES;
    March m = march(w, v, ray, t0, t1, rng_float(vkey),
                    v->uniform ? VOLUME_LIGHT_SAMPLES : VOLUME_MAX_STEPS);
    VolumePoints p;
    points_alloc(&p, (size_t)m.n);
    march_points(v, obj, ray, &m, vkey, diff, &p);
    m.n = extinction_at(w, v, ray, diff, &m, &p); /* the steps before it is opaque enough */
    w->stats.volume_steps += (uint64_t)m.n;
    VolumePoints lp;
    if (scatter) {
        /* The source at n_light of the steps (light_steps), interpolated
         * between them. */
        int at[VOLUME_LIGHT_SAMPLES];
        float u = max_light == 1 ? rng_float(hash_combine(vkey, 0x6c6974ull)) : 0.5f;
        int n_light = light_steps(&p, &m, RY_MIN(m.n, max_light), u, at);
        points_alloc(&lp, (size_t)n_light);
        for (int j = 0; j < n_light; j++) {
            int i = at[j];
            memcpy(lp.P[j], p.P[i], sizeof lp.P[j]);
            memcpy(lp.N[j], p.N[i], sizeof lp.N[j]);
            memcpy(lp.I[j], p.I[i], sizeof lp.I[j]);
            memcpy(lp.Cs[j], p.Cs[i], sizeof lp.Cs[j]);
            memcpy(lp.Os[j], p.Os[i], sizeof lp.Os[j]);
            lp.u[j] = p.u[i], lp.v[j] = p.v[i], lp.s[j] = p.s[i];
            lp.keys[j] = p.keys[i];
            lp.diff[j] = p.diff[i];
        }
        PathState ps = {w, lp.keys, lp.diff, lp.zero1, lp.zero1, NULL, UINT32_MAX, NULL, NULL, 1};
        RayesShadeCtx ctx = points_ctx(&lp, (size_t)n_light, kind & ~PATH_RAY_GLOSSY, 1,
                                       diffuse_depth, specular_depth, &ps);
        RayesShadeOutputs o = {lp.Ci, lp.Oi, NULL, NULL};
        w->stats.shading_points[RY_MIN(diffuse_depth, RENDER_MAX_DEPTH)] += (uint64_t)n_light;
        shade_run_lighting(w->services, &ctx, obj->shader, &o);
        /* the source per unit extinction, interpolated between the
         * lighting points (linearly: its error is second order) and
         * times each step's own extinction */
        for (int i = 0, j = 0; i < m.n; i++) {
            while (j + 1 < n_light && at[j + 1] <= i)
                j++;
            int a = at[j], b = j + 1 < n_light ? j + 1 : j;
            int ib = at[b];
            float f = ib > a ? fminf(fmaxf((float)(i - a) / (float)(ib - a), 0.0f), 1.0f) : 0.0f;
            for (int c = 0; c < 3; c++) {
                float ra = lp.Oi[j][c] > 0.0f ? lp.Ci[j][c] / lp.Oi[j][c] : 0.0f;
                float rb = lp.Oi[b][c] > 0.0f ? lp.Ci[b][c] / lp.Oi[b][c] : 0.0f;
                p.Ci[i][c] = (ra + (rb - ra) * f) * p.Oi[i][c];
            }
        }
        points_free(&lp);
    }
    /* Front to back: each step adds its source times the transmittance
     * to its middle, then attenuates what lies behind it. */
    Vec3 Tv = v3(1, 1, 1), Lv = v3(0, 0, 0);
    for (int i = 0; i < m.n; i++) {
        Vec3 step = v3_exp_neg(v3_scale(v3_load(p.Oi[i]), m.dl));
        if (scatter) {
            Vec3 half = v3_exp_neg(v3_scale(v3_load(p.Oi[i]), 0.5f * m.dl));
            Lv = v3_add(Lv, v3_scale(v3_mul(v3_mul(Tv, half), v3_load(p.Ci[i])), m.dl));
        }
        Tv = v3_mul(Tv, step);
    }
    points_free(&p);
    *Lv_out = Lv;
    *Tv_out = Tv;
}

Vec3 volume_radiance(Worker *w, const Ray *ray, float tmax, int64_t leaving, int hit, uint32_t kind,
                     int diffuse_depth, int specular_depth, uint64_t key, RayDiff diff, Vec3 *T)
{
    Vec3 L = v3(0, 0, 0);
    *T = v3(1, 1, 1);
    for (size_t k = 0; k < w->rs->n_volumes; k++) {
        const RenderVolume *v = &w->rs->volumes[k];
        float t0, t1, seg[VOLUME_MAX_SEGMENTS][2];
        if (v->atmosphere && (kind != RAYES_RAY_CAMERA || !hit))
            continue; /* RenderMan's atmosphere: the light reaching the eye from a surface */
        if ((v->inside >= 0 && !v->hidden_bound && v->inside != leaving) ||
            !clip(v, ray, tmax, &t0, &t1))
            continue; /* bounded by an object the ray is not inside */
        int n_seg = 1;
        if (v->hidden_bound)
            n_seg = inside_segments(w, v, ray, t0, t1, seg);
        else
            seg[0][0] = t0, seg[0][1] = t1;
        uint64_t vkey = hash_combine(key, 0x766f6c0000ull + k);
        for (int s = 0; s < n_seg; s++) {
            Vec3 Lv, Tv;
            segment_radiance(w, v, ray, seg[s][0], seg[s][1], kind, diffuse_depth, specular_depth,
                             s ? hash_combine(vkey, (uint64_t)s) : vkey, diff, &Lv, &Tv);
            L = v3_add(L, v3_mul(*T, Lv));
            *T = v3_mul(*T, Tv);
        }
    }
    return L;
}
