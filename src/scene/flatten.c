/*
 * scene/flatten.c — object instances at prepare time (DESIGN.md
 * "Instances"): the bounds of masters and of the instances that place
 * them, and the flattening of nested instances into GeomInstances, one
 * per placement of a master with primitives, each with its world
 * transform and the object its inheriting geometry takes.
 *
 * A block can only instance masters whose blocks have ended, so a master's
 * nested instances place masters of lower index, and the instances, in
 * the order made, list every nested one before the instance of its
 * parent: one pass in that order finds every master's bounds.
 * Flattening recurses at most SCENE_MAX_NESTING levels (checked when
 * instances are made). Memory: gs->instances, owned by the GridSet.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/subdiv.h"
#include "scene/scene.h"

Bounds3 scene_prim_bounds(const Prim *p)
{
    Bounds3 b = bounds_empty();
    if (p->type == PRIM_SPHERE) {
        Vec3 c = mat4_point(&p->big->sphere.world_from_object, v3(0, 0, 0));
        float r = p->big->sphere.radius;
        for (int k = 0; k < 3; k++) {
            Vec3 axis = mat4_vector(&p->big->sphere.world_from_object,
                                    v3(k == 0 ? r : 0, k == 1 ? r : 0, k == 2 ? r : 0));
            float l = v3_length(axis);
            b = bounds_add(b, v3_add(c, v3(l, l, l)));
            b = bounds_add(b, v3_sub(c, v3(l, l, l)));
        }
        return b;
    }
    if (p->type == PRIM_SUBDIV) { /* the control points hold the limit surface */
        float lo[3], hi[3];
        geom_subdiv_patch_bounds(p->subdiv.mesh, p->subdiv.patch, lo, hi);
        return bounds_add(bounds_add(b, v3(lo[0], lo[1], lo[2])), v3(hi[0], hi[1], hi[2]));
    }
    if (p->type == PRIM_QUADRIC) { /* a lattice of surface points, widened */
        Bounds3 q = bounds_empty();
        for (int j = 0; j <= 16; j++)
            for (int i = 0; i <= 16; i++) {
                Vec3 P, du, dv;
                geom_prim_eval(p, (float)i / 16.0f, (float)j / 16.0f, &P, &du, &dv);
                q = bounds_add(q, P);
            }
        Vec3 pad = v3_scale(v3_sub(q.hi, q.lo), 0.05f);
        return bounds_add(bounds_add(b, v3_sub(q.lo, pad)), v3_add(q.hi, pad));
    }
    if (p->type == PRIM_CURVE || p->type == PRIM_POINT) { /* control points, widened */
        int n = p->type == PRIM_CURVE ? 3 * p->curve.n_seg + 1 : 1;
        const Vec3 *c = p->type == PRIM_CURVE ? p->big->curve.cp : &p->point.centre;
        float r = p->point.radius;
        for (int k = 0; p->type == PRIM_CURVE && k <= p->curve.n_seg; k++)
            r = k ? fmaxf(r, 0.5f * p->big->curve.width[k]) : 0.5f * p->big->curve.width[0];
        for (int k = 0; k < n; k++)
            b = bounds_add(bounds_add(b, v3_sub(c[k], v3(r, r, r))), v3_add(c[k], v3(r, r, r)));
        return b;
    }
    int n = p->type == PRIM_BICUBIC ? 16 : p->type == PRIM_TRIANGLE ? 3 : 4;
    for (int k = 0; k < n; k++)
        b = bounds_add(b, geom_prim_cp(p)[k]);
    return b;
}

/* The box b (empty stays empty) under m: the bounds of its 8 corners. */
static Bounds3 bounds_transform(const Mat4 *m, Bounds3 b)
{
    Bounds3 r = bounds_empty();
    if (!(b.lo.x <= b.hi.x))
        return r;
    for (int k = 0; k < 8; k++)
        r = bounds_add(r, mat4_point(m, v3(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y,
                                           k & 4 ? b.hi.z : b.lo.z)));
    return r;
}

/* Master bounds b placed by instance si: under each of its motion's
 * samples (the blend between two samples of an affine map keeps a box's
 * corners within the samples' boxes' hull only approximately; Embree
 * bounds the motion itself, this is for the scene's extent). */
static Bounds3 instance_bounds(const RayesScene *s, const SceneInstance *si, Bounds3 b)
{
    Bounds3 r = bounds_transform(&si->parent_from_master, b);
    const SceneMotion *m = si->motion ? &s->motions[si->motion - 1] : NULL;
    for (int k = 1; m && k < m->n_times; k++) {
        Mat4 M = scene_instance_at(s, si, m->time[k]);
        r = bounds_union(r, bounds_transform(&M, b));
    }
    return r;
}

Bounds3 *scene_masters_bounds(const RayesScene *s)
{
    Bounds3 *mb = malloc((s->n_masters ? s->n_masters : 1) * sizeof *mb);
    if (!mb)
        return NULL;
    for (size_t m = 0; m < s->n_masters; m++) {
        mb[m] = bounds_empty();
        for (size_t i = s->masters[m].first_prim; i < s->masters[m].end_prim; i++)
            mb[m] = bounds_union(mb[m], scene_prim_bounds(&s->prims[i]));
    }
    for (size_t i = 0; i < s->n_instances; i++) {
        const SceneInstance *si = &s->instances[i];
        if (si->parent)
            mb[si->parent - 1] =
                bounds_union(mb[si->parent - 1], instance_bounds(s, si, mb[si->master]));
    }
    return mb;
}

Bounds3 scene_instances_bounds(const RayesScene *s)
{
    Bounds3 b = bounds_empty();
    if (!s->n_instances)
        return b;
    Bounds3 *mb = scene_masters_bounds(s);
    if (!mb)
        return b; /* out of memory: prepare fails on its own allocations */
    for (size_t i = 0; i < s->n_instances; i++) {
        const SceneInstance *si = &s->instances[i];
        if (!si->parent)
            b = bounds_union(b, instance_bounds(s, si, mb[si->master]));
    }
    free(mb);
    return b;
}

/* The GeomInstance of master m under world_from_master; 0, or -1 if the
 * transform is singular. */
static int make_instance(Mat4 world_from_master, uint32_t m, uint32_t object, uint32_t mask,
                         GeomInstance *gi)
{
    gi->master = m;
    gi->object = object;
    gi->ray_mask = mask;
    gi->motion = 0;
    return geom_instance_set(gi, world_from_master);
}

/* The instances made inside each master's block: children[first[m] ..
 * first[m + 1]) are indices into the scene's instances, in order made. */
typedef struct Children {
    size_t *first; /* n_masters + 1 */
    uint32_t *of;  /* n_instances */
} Children;

static int children_init(const RayesScene *s, Children *c)
{
    c->first = calloc(s->n_masters + 1, sizeof *c->first);
    c->of = malloc((s->n_instances ? s->n_instances : 1) * sizeof *c->of);
    if (!c->first || !c->of)
        return -1;
    for (size_t i = 0; i < s->n_instances; i++)
        if (s->instances[i].parent)
            c->first[s->instances[i].parent]++; /* counts, shifted by one */
    for (size_t m = 0; m < s->n_masters; m++)
        c->first[m + 1] += c->first[m];
    size_t *next = calloc(s->n_masters + 1, sizeof *next);
    if (!next)
        return -1;
    memcpy(next, c->first, (s->n_masters + 1) * sizeof *next);
    for (size_t i = 0; i < s->n_instances; i++)
        if (s->instances[i].parent)
            c->of[next[s->instances[i].parent - 1]++] = (uint32_t)i;
    free(next);
    return 0;
}

/* What flattening carries down: the GridSet's time samples and where the
 * moving instances' matrices go. */
typedef struct Flatten {
    int n_times;
    float time[GEOM_MAX_TIMES]; /* the GridSet's samples, scene time */
    size_t cap_motion;          /* matrices room in gs->instance_motion */
    int failed;                 /* out of memory */
} Flatten;

/* Appends the placements of master m under W (world_from_master at each of
 * fl's time samples: W[0] only, if moving is 0), its own if it has
 * primitives, then its nested instances', seen by the rays of mask (the
 * enclosing instances' objects' visibility, ANDed). Motion at any level
 * composes sample by sample (DESIGN.md "Instances": instance motion). */
static void place(const RayesScene *s, const Children *c, Flatten *fl, uint32_t m, const Mat4 *W,
                  int moving, uint32_t object, uint32_t mask, GridSet *gs)
{
    const SceneMaster *ms = &s->masters[m];
    GeomInstance *gi = &gs->instances[gs->n_instances];
    if (ms->end_prim > ms->first_prim && make_instance(W[0], m, object, mask, gi) == 0) {
        gs->n_instances++;
        if (moving) {
            size_t n = (size_t)fl->n_times, need = (gs->n_moving_instances + 1) * n;
            if (need > fl->cap_motion) {
                size_t cap = fl->cap_motion ? 2 * fl->cap_motion : 16 * n;
                Mat4 *a = realloc(gs->instance_motion, (cap > need ? cap : need) * sizeof *a);
                if (!a) {
                    fl->failed = 1;
                    return;
                }
                gs->instance_motion = a;
                fl->cap_motion = cap > need ? cap : need;
            }
            memcpy(&gs->instance_motion[gs->n_moving_instances * n], W, n * sizeof *W);
            gi->motion = (uint32_t)++gs->n_moving_instances;
        }
    }
    Mat4 Wc[GEOM_MAX_TIMES];
    for (size_t k = c->first[m]; k < c->first[m + 1]; k++) {
        const SceneInstance *si = &s->instances[c->of[k]];
        uint32_t o = si->object == GEOM_OBJECT_INHERIT ? object : si->object;
        int mv = moving || si->motion;
        for (int j = 0; j < (mv ? fl->n_times : 1); j++)
            Wc[j] = mat4_mul(W[moving ? j : 0], scene_instance_at(s, si, fl->time[j]));
        place(s, c, fl, si->master, Wc, mv, o, mask & s->objects[o].ray_mask, gs);
    }
}

int scene_flatten_instances(const RayesScene *s, GridSet *gs)
{
    free(gs->instances);
    free(gs->instance_motion);
    gs->instances = NULL;
    gs->instance_motion = NULL;
    gs->n_instances = 0;
    gs->n_moving_instances = 0;
    gs->n_masters = s->n_masters;
    if (!s->leaves)
        return 0;
    Children c = {0};
    gs->instances = malloc(s->leaves * sizeof *gs->instances);
    if (!gs->instances || children_init(s, &c) != 0) {
        free(c.first);
        free(c.of);
        return -1;
    }
    Flatten fl = {0};
    float span[2];
    fl.n_times = scene_time_samples(s, span);
    for (int j = 0; j < fl.n_times; j++)
        fl.time[j] = fl.n_times > 1
                         ? span[0] + (span[1] - span[0]) * (float)j / (float)(fl.n_times - 1)
                         : span[0];
    Mat4 W[GEOM_MAX_TIMES];
    for (size_t i = 0; i < s->n_instances && !fl.failed; i++) {
        const SceneInstance *si = &s->instances[i];
        if (si->parent)
            continue;
        int mv = si->motion != 0 && fl.n_times > 1;
        for (int j = 0; j < (mv ? fl.n_times : 1); j++)
            W[j] = scene_instance_at(s, si, fl.time[j]);
        place(s, &c, &fl, si->master, W, mv, si->object, s->objects[si->object].ray_mask, gs);
    }
    free(c.first);
    free(c.of);
    return fl.failed ? -1 : 0;
}
