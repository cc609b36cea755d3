/*
 * scene/motion.c — time in the scene: the shutter, moving transforms,
 * deformation blur, camera motion, depth of field and the dicing of
 * blurred geometry (DESIGN.md "Motion blur and depth of field").
 *
 * A moving primitive is diced once, at its first time sample (the scene
 * stores primitives in world space at that time); scene_motion_prepare
 * then gives every vertex its position, normal and derivatives at each of
 * the GridSet's time samples. Those are uniformly spaced (Embree's
 * linear motion needs it) from the earliest to the latest time of any
 * motion, as many as the finest motion's spacing needs (at most
 * GEOM_MAX_TIMES); a motion whose own samples fall between them is
 * resampled linearly.
 *  - Transform blur: the vertex moves by delta(t) = world_from_object(t)
 *    object_from_world(t0), blended linearly between the motion's samples
 *    (for points the same as blending the moved points); normals by its
 *    inverse transpose.
 *  - Deformation blur: the vertex moves by the difference of the
 *    primitive's surface at (u, v) between time t and t0, so the diced,
 *    displaced and stitched vertex keeps its offset from the surface.
 *    Curves and points deform the same way, their samples evaluated facing
 *    the eye the grid was diced for (a point's square keeps its first
 *    orientation, as a transform would carry it: it faces the eye moved
 *    with the centre), so a tube's centre line and width, and a point's
 *    centre and radius, are the sample's own at every time.
 * Only the grids of moving primitives have later samples (GridSet.Pt and
 * the rest, compact: Grid.motion_vertex).
 *
 * Threading: the API calls edit one scene (one thread); prepare reads it.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "util/grow.h"

/* 1 if times[0 .. n - 1] are finite and strictly increasing. */
static int increasing(const float *times, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(times[i]) || (i > 0 && !(times[i] > times[i - 1])))
            return 0;
    return 1;
}

static RayesError check_times(RayesScene *s, const char *what, size_t n, const float *times)
{
    if (!times || n < 2 || n > RAYES_MAX_TIMES)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "%s: expected 2 to %d time samples, got %zu", what, RAYES_MAX_TIMES, n);
    if (!increasing(times, n))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: expected finite, increasing times",
                          what);
    return RAYES_OK;
}

RayesError rayes_scene_set_shutter(RayesScene *s, float open, float close)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!isfinite(open) || !isfinite(close) || close < open)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "shutter: expected finite open <= close, got %g %g", open, close);
    s->shutter[0] = open, s->shutter[1] = close;
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

static SceneMotion *new_motion(RayesScene *s)
{
    if (s->n_motions == s->cap_motions) {
        size_t cap = s->cap_motions ? 2 * s->cap_motions : 8;
        SceneMotion *m = realloc(s->motions, cap * sizeof *m);
        if (!m)
            return NULL;
        s->motions = m;
        s->cap_motions = cap;
    }
    SceneMotion *m = &s->motions[s->n_motions++];
    memset(m, 0, sizeof *m);
    return m;
}

RayesError rayes_scene_set_transform_motion(RayesScene *s, size_t n, const float *times,
                                            const float (*M)[16])
{
    if (!s || !M)
        return RAYES_ERROR_INVALID_ARGUMENT;
    RayesError e = check_times(s, "transform motion", n, times);
    if (e != RAYES_OK)
        return e;
    Mat4 W[GEOM_MAX_TIMES], inv0;
    for (size_t k = 0; k < n; k++) {
        Mat4 inv;
        if (!scene_finite(M[k], 16) || !mat4_invert(mat4_from_array(M[k]), &inv))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "transform motion: expected finite, invertible matrices");
        if (!scene_affine(M[k]))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, AFFINE_EXPECTED, "transform motion");
        W[k] = scene_unit_w(M[k]);
        mat4_invert(W[k], &inv);
        if (k == 0)
            inv0 = inv;
    }
    SceneMotion *m = new_motion(s);
    if (!m)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    m->n_times = (int)n;
    for (size_t k = 0; k < n; k++) {
        m->time[k] = times[k];
        m->delta[k] = mat4_mul(W[k], inv0);
    }
    s->world_from_object = W[0];
    s->current_motion = (uint32_t)s->n_motions;
    return RAYES_OK;
}

RayesError rayes_scene_motion_begin(RayesScene *s, size_t n, const float *times)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (s->deforming)
        return scene_fail(s, RAYES_ERROR_INVALID_OPERATION,
                          "motion begin: already in a motion block");
    RayesError e = check_times(s, "motion begin", n, times);
    if (e != RAYES_OK)
        return e;
    s->deforming = (int)n;
    s->deform_first = s->n_prims;
    memcpy(s->deform_time, times, n * sizeof *times);
    return RAYES_OK;
}

static int push_motion_prim(RayesScene *s, const Prim *p)
{
    if (util_grow((void **)&s->motion_prims, &s->cap_motion_prims, s->n_motion_prims,
                  sizeof *s->motion_prims) != 0)
        return -1;
    s->motion_prims[s->n_motion_prims++] = *p;
    return 0;
}

/* 1 if a and b are samples of one primitive: of a type, and curves of as
 * many segments and a shape, points of a shape. */
static int same_topology(const Prim *a, const Prim *b)
{
    if (a->type != b->type)
        return 0;
    if (a->type == PRIM_CURVE)
        return a->curve.n_seg == b->curve.n_seg && a->curve.shape == b->curve.shape;
    if (a->type == PRIM_POINT)
        return a->point.shape == b->point.shape;
    return 1;
}

RayesError rayes_scene_motion_end(RayesScene *s)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!s->deforming)
        return scene_fail(s, RAYES_ERROR_INVALID_OPERATION, "motion end: no motion block");
    size_t n_times = (size_t)s->deforming, total = s->n_prims - s->deform_first;
    s->deforming = 0;
    size_t per = total / n_times;
    int same = total > 0 && total % n_times == 0;
    for (size_t k = 1; same && k < n_times; k++)
        for (size_t j = 0; j < per; j++)
            if (!same_topology(&s->prims[s->deform_first + k * per + j],
                               &s->prims[s->deform_first + j]))
                same = 0;
    if (!same) {
        s->n_prims = s->deform_first;
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "motion end: expected %zu primitives of the same topology, one per time "
                          "sample",
                          n_times);
    }
    SceneMotion *m = new_motion(s);
    if (!m)
        return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    m->n_times = (int)n_times;
    memcpy(m->time, s->deform_time, n_times * sizeof *m->time);
    m->deform = 1;
    m->first_prim = s->deform_first;
    m->n_prims = per;
    m->first = s->n_motion_prims;
    for (size_t j = per; j < total; j++)
        if (push_motion_prim(s, &s->prims[s->deform_first + j]) != 0)
            return scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "out of memory");
    s->n_prims = s->deform_first + per;
    for (size_t j = 0; j < per; j++)
        s->prims[s->deform_first + j].motion = (uint32_t)s->n_motions;
    scene_mark(s, SCENE_CHANGE_GEOMETRY);
    return RAYES_OK;
}

RayesError rayes_scene_set_camera_motion(RayesScene *s, size_t n, const float *times,
                                         const float (*M)[16])
{
    if (!s || !M)
        return RAYES_ERROR_INVALID_ARGUMENT;
    RayesError e = check_times(s, "camera motion", n, times);
    if (e != RAYES_OK)
        return e;
    SceneCamera *c = &s->camera;
    for (size_t k = 0; k < n; k++) {
        Mat4 wc;
        if (!scene_finite(M[k], 16) || !mat4_invert(mat4_from_array(M[k]), &wc))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "camera motion: expected finite, invertible matrices");
        c->motion_time[k] = times[k];
        c->motion_eye[k] = mat4_point(&wc, v3(0, 0, 0));
        c->motion_x[k] = mat4_vector(&wc, v3(1, 0, 0));
        c->motion_y[k] = mat4_vector(&wc, v3(0, 1, 0));
        c->motion_z[k] = mat4_vector(&wc, v3(0, 0, 1));
    }
    c->n_motion = (int)n;
    c->eye = c->motion_eye[0];
    c->x = c->motion_x[0], c->y = c->motion_y[0], c->z = c->motion_z[0];
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

RayesError rayes_scene_set_depth_of_field(RayesScene *s, float lens_radius, float focal_distance)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(lens_radius >= 0.0f) || !isfinite(lens_radius) ||
        (lens_radius > 0.0f && !(focal_distance > 0.0f && isfinite(focal_distance))))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "depth of field: expected a lens radius >= 0 and a focal distance > 0, "
                          "got %g %g",
                          lens_radius, focal_distance);
    s->camera.lens_radius = lens_radius;
    s->camera.focal_distance = lens_radius > 0.0f ? focal_distance : 0.0f;
    scene_mark(s, SCENE_CHANGE_CAMERA);
    return RAYES_OK;
}

RayesError rayes_scene_set_dice_blur(RayesScene *s, float motionfactor, float focusfactor)
{
    if (!s)
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!(motionfactor >= 0.0f) || !(focusfactor >= 0.0f) || !isfinite(motionfactor) ||
        !isfinite(focusfactor))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "dice blur: expected motionfactor and focusfactor >= 0");
    s->motionfactor = motionfactor;
    s->focusfactor = focusfactor;
    return RAYES_OK;
}

/* ------------------------------------------------------------ prepare */

/* The motion's sample pair around time t and the fraction between. */
static void motion_pair(const SceneMotion *m, float t, int *a, int *b, float *f)
{
    *a = 0, *b = 0, *f = 0.0f;
    if (t <= m->time[0])
        return;
    if (t >= m->time[m->n_times - 1]) {
        *a = *b = m->n_times - 1;
        return;
    }
    int k = 0;
    while (k + 2 < m->n_times && t >= m->time[k + 1])
        k++;
    *a = k, *b = k + 1;
    *f = (t - m->time[k]) / (m->time[k + 1] - m->time[k]);
}

static Mat4 mat4_lerp(const Mat4 *a, const Mat4 *b, float f)
{
    Mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a->m[i][j] + (b->m[i][j] - a->m[i][j]) * f;
    return r;
}

/* The primitive of deformation m at its sample k (0: the scene's). */
static const Prim *deform_prim(const RayesScene *s, const SceneMotion *m, size_t j, int k)
{
    return k == 0 ? &s->prims[m->first_prim + j]
                  : &s->motion_prims[m->first + (size_t)(k - 1) * m->n_prims + j];
}

/* 1 if grid g has later time samples: a grid of a moving primitive. */
static int grid_moves(const RayesScene *s, const Grid *g)
{
    return s->prims[g->prim].motion != 0;
}

/* A curve or point sample p as diced (geom_dice_prim): facing eye (for
 * points, moved by the centre's offset from the first sample's, first)
 * unless it is a ribbon or an oriented disk, whose normals place it. */
static Prim facing(const Prim *p, const Prim *first, Vec3 eye)
{
    Prim c = *p;
    if (p->type == PRIM_CURVE && p->curve.shape != GEOM_SHAPE_SURFACE)
        c.curve.facing = eye;
    else if (p->type == PRIM_POINT && p->point.shape != GEOM_SHAPE_ORIENTED_DISK)
        c.point.facing = v3_add(eye, v3_sub(p->point.centre, first->point.centre));
    return c;
}

/* Widens lo, hi, step by motion m's times. */
static void add_times(const SceneMotion *m, float *lo, float *hi, float *step)
{
    *lo = fminf(*lo, m->time[0]);
    *hi = fmaxf(*hi, m->time[m->n_times - 1]);
    for (int k = 1; k < m->n_times; k++)
        *step = fminf(*step, m->time[k] - m->time[k - 1]);
}

int scene_time_samples(const RayesScene *s, float span[2])
{
    int any = 0;
    float lo = INFINITY, hi = -INFINITY, step = INFINITY;
    span[0] = span[1] = 0.0f;
    for (size_t i = 0; i < s->n_prims; i++) {
        if (!s->prims[i].motion)
            continue;
        any = 1;
        add_times(&s->motions[s->prims[i].motion - 1], &lo, &hi, &step);
    }
    for (size_t i = 0; i < s->n_instances; i++) {
        if (!s->instances[i].motion)
            continue;
        any = 1;
        add_times(&s->motions[s->instances[i].motion - 1], &lo, &hi, &step);
    }
    if (!any)
        return 1;
    span[0] = lo, span[1] = hi;
    double n = ceil((double)(hi - lo) / (double)step - 1e-3) + 1.0;
    return n > GEOM_MAX_TIMES ? GEOM_MAX_TIMES : n < 2 ? 2 : (int)n;
}

Mat4 scene_instance_at(const RayesScene *s, const SceneInstance *si, float t)
{
    if (!si->motion)
        return si->parent_from_master;
    const SceneMotion *m = &s->motions[si->motion - 1];
    int a, b;
    float f;
    motion_pair(m, t, &a, &b, &f);
    Mat4 D = mat4_lerp(&m->delta[a], &m->delta[b], f);
    return mat4_mul(D, si->parent_from_master);
}

/* Moves grid g's vertices to time t (into sample k's arrays). */
static void move_grid(const RayesScene *s, GridSet *gs, Grid *g, int k, float t, Vec3 eye)
{
    const Prim *p = &s->prims[g->prim];
    const SceneMotion *m = &s->motions[p->motion - 1];
    int a, b;
    float f;
    motion_pair(m, t, &a, &b, &f);
    size_t first = g->first_vertex, n = geom_grid_n_vertices(g);
    /* The grid's slots in the later samples' arrays, indexed like gs->P. */
    size_t off = g->motion_vertex - first;
    Vec3 *P = gs->Pt[k - 1] + off, *N = gs->Nt[k - 1] + off, *U = gs->dPdut[k - 1] + off,
         *V = gs->dPdvt[k - 1] + off;
    if (!m->deform) {
        Mat4 D = mat4_lerp(&m->delta[a], &m->delta[b], f), inv, nrm;
        nrm = mat4_invert(D, &inv) ? mat4_transpose(inv) : D;
        for (size_t i = first; i < first + n; i++) {
            P[i] = mat4_point(&D, gs->P[i]);
            U[i] = mat4_vector(&D, gs->dPdu[i]);
            V[i] = mat4_vector(&D, gs->dPdv[i]);
            Vec3 ni = mat4_vector(&nrm, gs->N[i]);
            N[i] = v3_length(ni) > 0.0f ? v3_normalize(ni) : gs->N[i];
        }
        return;
    }
    size_t j = g->prim - m->first_prim;
    const Prim *pa = deform_prim(s, m, j, a), *pb = deform_prim(s, m, j, b);
    Prim fp = facing(p, p, eye), fa = facing(pa, p, eye), fb = facing(pb, p, eye);
    p = &fp, pa = &fa, pb = &fb;
    for (size_t i = first; i < first + n; i++) {
        float u = gs->uv[i][0], v = gs->uv[i][1];
        Vec3 P0, U0, V0, Pa, Ua, Va, Pb, Ub, Vb;
        geom_prim_eval(p, u, v, &P0, &U0, &V0);
        geom_prim_eval(pa, u, v, &Pa, &Ua, &Va);
        geom_prim_eval(pb, u, v, &Pb, &Ub, &Vb);
        Vec3 Pt = v3_lerp(Pa, Pb, f), Ut = v3_lerp(Ua, Ub, f), Vt = v3_lerp(Va, Vb, f);
        P[i] = v3_add(gs->P[i], v3_sub(Pt, P0));
        U[i] = v3_add(gs->dPdu[i], v3_sub(Ut, U0));
        V[i] = v3_add(gs->dPdv[i], v3_sub(Vt, V0));
        Vec3 n0 = v3_cross(U0, V0), nt = v3_cross(Ut, Vt);
        if (v3_length(n0) > 0.0f && v3_length(nt) > 0.0f) {
            Vec3 ni = v3_add(gs->N[i], v3_sub(v3_normalize(nt), v3_normalize(n0)));
            N[i] = v3_length(ni) > 0.0f ? v3_normalize(ni) : gs->N[i];
        } else
            N[i] = gs->N[i];
    }
}

int scene_motion_prepare(const RayesScene *s, const DiceCamera *cams, GridSet *gs)
{
    float span[2] = {0.0f, 0.0f};
    int n = scene_time_samples(s, span);
    gs->n_times = n;
    gs->time[0] = span[0], gs->time[1] = span[1];
    if (n < 2)
        return 0;
    /* Slots in the later samples for the grids that may move (those of
     * moving primitives). */
    size_t slots = 0;
    for (size_t gi = 0; gi < gs->n_grids; gi++) {
        Grid *g = &gs->grids[gi];
        if (grid_moves(s, g)) {
            g->motion_vertex = (uint32_t)slots;
            slots += geom_grid_n_vertices(g);
        }
    }
    gs->n_motion_vertices = slots;
    size_t bytes = (slots + 1) * sizeof(Vec3);
    for (int k = 0; k + 1 < n; k++) {
        gs->Pt[k] = malloc(bytes);
        gs->Nt[k] = malloc(bytes);
        gs->dPdut[k] = malloc(bytes);
        gs->dPdvt[k] = malloc(bytes);
        if (!gs->Pt[k] || !gs->Nt[k] || !gs->dPdut[k] || !gs->dPdvt[k])
            return -1;
    }
    for (size_t gi = 0; gi < gs->n_grids; gi++) {
        Grid *g = &gs->grids[gi];
        if (!grid_moves(s, g))
            continue;
        for (int k = 1; k < n; k++)
            move_grid(s, gs, g, k, span[0] + (span[1] - span[0]) * (float)k / (float)(n - 1),
                      cams[g->master].eye);
        size_t first = g->first_vertex, nv = geom_grid_n_vertices(g);
        for (int k = 1; k < n && !g->moving; k++)
            for (size_t i = 0; i < nv && !g->moving; i++)
                if (memcmp(&gs->Pt[k - 1][g->motion_vertex + i], &gs->P[first + i], sizeof(Vec3)) !=
                    0)
                    g->moving = 1;
    }
    return 0;
}

/* The primitive's centre at time t (its (1/2, 1/2), or a triangle's
 * centroid). */
static Vec3 prim_centre(const RayesScene *s, size_t index, float t)
{
    const Prim *p = &s->prims[index];
    float u = geom_prim_triangular(p) ? 1.0f / 3.0f : 0.5f, v = u;
    Vec3 P, dU, dV;
    geom_prim_eval(p, u, v, &P, &dU, &dV);
    if (!p->motion)
        return P;
    const SceneMotion *m = &s->motions[p->motion - 1];
    int a, b;
    float f;
    motion_pair(m, t, &a, &b, &f);
    if (!m->deform) {
        Mat4 D = mat4_lerp(&m->delta[a], &m->delta[b], f);
        return mat4_point(&D, P);
    }
    size_t j = index - m->first_prim;
    Vec3 Pa, Pb;
    geom_prim_eval(deform_prim(s, m, j, a), u, v, &Pa, &dU, &dV);
    geom_prim_eval(deform_prim(s, m, j, b), u, v, &Pb, &dU, &dV);
    return v3_lerp(Pa, Pb, f);
}

float scene_blur_dice_factor(const RayesScene *s, size_t index, const DiceCamera *cam)
{
    const Prim *p = &s->prims[index];
    if (!(p->motionfactor > 0.0f) && !(p->focusfactor > 0.0f))
        return 1.0f;
    Vec3 c0 = prim_centre(s, index, s->shutter[0]);
    float dist = fmaxf(v3_length(v3_sub(c0, cam->eye)), cam->min_distance);
    float pixel = cam->pixel_angle > 0.0f ? dist * cam->pixel_angle : cam->pixel_width;
    if (!(pixel > 0.0f))
        return 1.0f;
    float blur = 0.0f;
    if (p->motionfactor > 0.0f && p->motion && s->shutter[1] > s->shutter[0]) {
        Vec3 c1 = prim_centre(s, index, s->shutter[1]);
        blur = fmaxf(blur, p->motionfactor * v3_length(v3_sub(c1, c0)) / pixel);
    }
    const SceneCamera *c = &s->camera;
    if (p->focusfactor > 0.0f && c->lens_radius > 0.0f) {
        float z = v3_dot(v3_sub(c0, c->eye), v3_normalize(c->z));
        if (z > 0.0f) {
            /* the circle of confusion's diameter at the point, world units */
            float coc = 2.0f * c->lens_radius * fabsf(z - c->focal_distance) / c->focal_distance;
            blur = fmaxf(blur, p->focusfactor * coc / pixel);
        }
    }
    return 1.0f + blur / 16.0f;
}
