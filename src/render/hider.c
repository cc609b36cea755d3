/*
 * render/hider.c — the grid hider (hider.h).
 *
 * Each vertex is shaded on the side that faces the eye, with I from the eye
 * to the vertex, the ray differential of a camera ray reaching it (width =
 * pixel angle times distance), and the grid's parameter spacing as du, dv.
 * Grids are shaded at most once: a pointer per grid, published with
 * release semantics after its values are written; a striped lock makes the
 * threads that want the same grid wait for the one shading it. A master's
 * grid is shaded once per instance that a camera ray hits (in world space,
 * with the instance's object and random numbers): each instance has a
 * table of its master's grids, made when the instance is first hit.
 *
 * Motion (DESIGN.md "Motion blur and depth of field"): a moving grid is
 * shaded once per motion segment, where it is at the segment's middle
 * time (its rays leave then), as the radiosity cache fills it; a hit
 * interpolates the shading of its ray's segment, as REYES interpolates a
 * grid shaded once over its blurred micropolygons. A still grid is shaded
 * at the shutter's middle. A grid lit by a light that moves within the
 * frame is shaded per hit (at the ray's time), so that the light's
 * shadows blur, and so is a moving grid of a master.
 */
#include "render/hider.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "render/irrgrid.h"
#include "util/check.h"
#include "util/rng.h"

enum { STRIPES = 256 };

typedef float Rgb[3];

typedef _Atomic(Rgb *) GridSlot; /* a grid's vertices' radiance (then, for a transparent
                                     object, their opacity), NULL until shaded */

struct GridShading {
    const RenderScene *rs;
    float contrast;              /* the limit of hider_camera_hit (HIDER_CONTRAST, scaled) */
    GridSlot *ci;                /* per grid (world grids; unused for masters') */
    _Atomic(GridSlot *) *inst;   /* per instance: a slot per grid of its master (from the
                                    master's first grid), NULL until the instance is hit */
    uint32_t *master_first;      /* per master: its first grid (a master's are contiguous) */
    uint32_t *master_count;      /* and how many */
    uint32_t *moving;            /* per grid: a moving world grid's index among them, else
                                    UINT32_MAX; NULL: nothing moves */
    GridSlot *seg_ci;            /* per moving world grid, per motion segment */
    int n_seg;                   /* motion segments (GridSet.n_times - 1) */
    int moving_lights;           /* 1: some light moves within the frame */
    pthread_mutex_t locks[STRIPES];
};

GridShading *hider_new(const RenderScene *rs, const RenderSettings *set)
{
    GridShading *gsh = calloc(1, sizeof *gsh);
    if (!gsh)
        return NULL;
    gsh->rs = rs;
    int n = set->shadow_rays < set->diffuse_rays ? set->shadow_rays : set->diffuse_rays;
    gsh->contrast = HIDER_CONTRAST * sqrtf(fmaxf(1.0f, 64.0f / (float)(n > 1 ? n : 1)));
    const GridSet *gs = rs->gs;
    gsh->ci = calloc(gs->n_grids ? gs->n_grids : 1, sizeof *gsh->ci);
    gsh->inst = calloc(gs->n_instances + 1, sizeof *gsh->inst);
    gsh->master_first = calloc(gs->n_masters + 1, sizeof *gsh->master_first);
    gsh->master_count = calloc(gs->n_masters + 1, sizeof *gsh->master_count);
    if (!gsh->ci || !gsh->inst || !gsh->master_first || !gsh->master_count) {
        free(gsh->ci);
        free(gsh->inst);
        free(gsh->master_first);
        free(gsh->master_count);
        free(gsh);
        return NULL;
    }
    for (size_t i = 0; i < gs->n_grids; i++) {
        atomic_init(&gsh->ci[i], NULL);
        uint32_t m = gs->grids[i].master;
        if (m && gsh->master_count[m - 1]++ == 0)
            gsh->master_first[m - 1] = (uint32_t)i;
    }
    for (size_t i = 0; i < gs->n_instances; i++)
        atomic_init(&gsh->inst[i], NULL);
    for (size_t k = 0; k < rs->n_lights; k++)
        gsh->moving_lights |= rs->lights[k].n_times > 1;
    size_t n_moving = 0;
    for (size_t i = 0; i < gs->n_grids; i++)
        n_moving += gs->grids[i].moving && !gs->grids[i].master;
    if (n_moving && gs->n_times > 1) {
        gsh->n_seg = gs->n_times - 1;
        gsh->moving = malloc(gs->n_grids * sizeof *gsh->moving);
        gsh->seg_ci = malloc(n_moving * (size_t)gsh->n_seg * sizeof *gsh->seg_ci);
        RY_CHECK(gsh->moving && gsh->seg_ci);
        for (size_t i = 0, m = 0; i < gs->n_grids; i++)
            gsh->moving[i] = gs->grids[i].moving && !gs->grids[i].master ? (uint32_t)m++
                                                                          : UINT32_MAX;
        for (size_t k = 0; k < n_moving * (size_t)gsh->n_seg; k++)
            atomic_init(&gsh->seg_ci[k], NULL);
    }
    for (int i = 0; i < STRIPES; i++)
        pthread_mutex_init(&gsh->locks[i], NULL);
    return gsh;
}

void hider_free(GridShading *gsh)
{
    if (!gsh)
        return;
    const GridSet *gs = gsh->rs->gs;
    for (size_t i = 0; i < gs->n_grids; i++)
        free(atomic_load_explicit(&gsh->ci[i], memory_order_relaxed));
    for (size_t i = 0; i < gs->n_instances; i++) {
        GridSlot *slots = atomic_load_explicit(&gsh->inst[i], memory_order_relaxed);
        for (uint32_t k = 0; slots && k < gsh->master_count[gs->instances[i].master]; k++)
            free(atomic_load_explicit(&slots[k], memory_order_relaxed));
        free(slots);
    }
    for (size_t i = 0; gsh->moving && i < gs->n_grids; i++)
        for (int k = 0; gsh->moving[i] != UINT32_MAX && k < gsh->n_seg; k++)
            free(atomic_load_explicit(&gsh->seg_ci[(size_t)gsh->moving[i] * gsh->n_seg + k],
                                      memory_order_relaxed));
    free(gsh->moving);
    free(gsh->seg_ci);
    free(gsh->inst);
    free(gsh->master_first);
    free(gsh->master_count);
    for (int i = 0; i < STRIPES; i++)
        pthread_mutex_destroy(&gsh->locks[i]);
    free(gsh->ci);
    free(gsh);
}

static void put3(float out[3], Vec3 v)
{
    out[0] = v.x, out[1] = v.y, out[2] = v.z;
}

/* Half the parameter spacing of g's vertices in u and v. */
static void grid_spacing(const Grid *g, float *du, float *dv)
{
    if (g->triangular) {
        *du = *dv = 1.0f / (float)g->nu;
        return;
    }
    *du = (g->uv[1][0] - g->uv[0][0]) / (float)(g->nu - 1);
    *dv = (g->uv[1][1] - g->uv[0][1]) / (float)(g->nv - 1);
}

/* A master's vertex i through instance gi (NULL: as it is): world P, the
 * normals and the derivatives. */
static void vertex_to_world(const GeomInstance *gi, Vec3 *P, Vec3 *Ng, Vec3 *N, Vec3 *du,
                            Vec3 *dv)
{
    if (!gi)
        return;
    *P = mat4_point(&gi->world_from_master, *P);
    *Ng = v3_normalize(mat4_vector(&gi->normal_to_world, *Ng));
    *N = v3_normalize(mat4_vector(&gi->normal_to_world, *N));
    *du = mat4_vector(&gi->world_from_master, *du);
    *dv = mat4_vector(&gi->world_from_master, *dv);
}

/* How many RGB values a shaded grid holds before its trailer: Ci of each
 * vertex, then Oi of each for a transparent object. */
static size_t grid_values(const Grid *g, int transparent)
{
    return geom_grid_n_vertices(g) * (transparent ? 2 : 1);
}

/* Shades every vertex of grid gi, seen through instance (0: none), with
 * lighting() into a new array: Ci of each vertex, followed by Oi of each if
 * the object is transparent; a moving grid where it is in the middle of
 * motion segment seg (a still one: seg -1). */
static Rgb *shade_grid(Worker *w, uint32_t gi, uint32_t instance, int seg)
{
    const RenderScene *rs = w->rs;
    const GridSet *gs = rs->gs;
    const Grid *g = &gs->grids[gi];
    const RenderObject *obj = render_object(rs, gi, instance);
    const GeomInstance *inst = render_instance(rs, instance);
    size_t n = geom_grid_n_vertices(g);
    float(*f3)[3] = malloc(n * 10 * sizeof *f3);
    float *f1 = malloc(n * 10 * sizeof *f1);
    float(*dsts)[4] = malloc(n * sizeof *dsts);
    uint64_t *keys = malloc(n * sizeof *keys);
    RayDiff *diff = malloc(n * sizeof *diff);
    size_t n_ci = grid_values(g, obj->transparent);
    Rgb *ci = malloc((n_ci + 1) * sizeof *ci);
    int *back = malloc(n * sizeof *back);
    RY_CHECK(f3 && f1 && dsts && keys && diff && ci && back);
    float(*P)[3] = f3, (*N)[3] = f3 + n, (*dPdu)[3] = f3 + 2 * n, (*dPdv)[3] = f3 + 3 * n;
    float(*I)[3] = f3 + 4 * n, (*Cs)[3] = f3 + 5 * n, (*Os)[3] = f3 + 6 * n;
    float(*Ci)[3] = f3 + 7 * n, (*Oi)[3] = f3 + 8 * n, (*Ng)[3] = f3 + 9 * n;
    float *u = f1, *v = f1 + n, *du = f1 + 2 * n, *dv = f1 + 3 * n, *curv = f1 + 4 * n;
    float *offset = f1 + 5 * n, *s = f1 + 6 * n, *t = f1 + 7 * n, *ds = f1 + 8 * n;
    float *dt = f1 + 9 * n;
    float su, sv;
    grid_spacing(g, &su, &sv);
    const Camera *cam = &rs->camera;
    uint64_t grid_key = hash_combine(hash_combine(w->set->seed, 0x6772696468ull /* "gridh" */), gi);
    if (instance) /* each instance its own numbers; world grids as before */
        grid_key = hash_combine(grid_key, instance);
    if (seg >= 0) /* each segment its own */
        grid_key = hash_combine(grid_key, 0x736567ull + (uint64_t)seg /* "seg" */);
    for (size_t k = 0; k < n; k++) {
        size_t i = g->first_vertex + k;
        Vec3 Pk = gs->P[i], Ngk = gs->N[i], Nk = geom_vertex_normal(gs, g, i);
        Vec3 duk = gs->dPdu[i], dvk = gs->dPdv[i];
        if (seg >= 0) { /* the segment's middle */
            GeomVertex gv = geom_vertex_at(gs, g, i, seg, 0.5f);
            Pk = gv.P, duk = gv.dPdu, dvk = gv.dPdv;
            Ngk = v3_length(gv.N) > 0.0f ? v3_normalize(gv.N) : gs->N[i];
            if (!(g->primvars & GEOM_PV_N))
                Nk = Ngk;
        }
        vertex_to_world(inst, &Pk, &Ngk, &Nk, &duk, &dvk);
        /* The camera ray toward the vertex: from the eye in perspective,
         * along the view in orthographic projection. */
        Vec3 to = v3_sub(Pk, cam->eye);
        float dist = cam->tan_half_fov > 0.0f ? v3_length(to) : v3_dot(to, cam->forward);
        Vec3 d = render_view_toward(cam, Pk);
        if (inst && render_faces_ray(g->shape)) /* faces this instance's eye */
            Nk = Ngk = render_facing(d, duk, g->shape, Ngk);
        back[k] = v3_dot(Ngk, d) > 0.0f; /* the eye sees the back: shade that side */
        if (back[k])
            Nk = v3_neg(Nk), Ngk = v3_neg(Ngk);
        put3(P[k], Pk);
        put3(N[k], Nk);
        put3(Ng[k], Ngk);
        put3(dPdu[k], duk);
        put3(dPdv[k], dvk);
        put3(I[k], d);
        put3(Cs[k], geom_vertex_color(gs, g, i, v3_load(obj->Cs)));
        put3(Os[k], geom_vertex_opacity(gs, g, i, v3_load(obj->Os)));
        u[k] = gs->uv[i][0];
        v[k] = gs->uv[i][1];
        du[k] = su;
        dv[k] = sv;
        float st[2], *dst = dsts[k];
        geom_vertex_st(gs, g, i, st, dst);
        s[k] = st[0], t[k] = st[1];
        path_st_footprint(dst, su, sv, &ds[k], &dt[k]);
        curv[k] = g->curvature / (inst ? inst->scale : 1.0f);
        offset[k] = path_ray_offset_in(w, g, instance);
        keys[k] = hash_combine(grid_key, k);
        diff[k] = (RayDiff){cam->pixel_width + cam->pixel_spread * fmaxf(dist, 0.0f), cam->pixel_spread};
    }
    IrrGrid irr = {.grid = g, .P = (const float(*)[3])P, .N = (const float(*)[3])N};
    float(*irr_E)[3] = NULL;
    if (w->set->irradiance) {
        irr_E = malloc(n * sizeof *irr_E);
        RY_CHECK(irr_E != NULL);
        irr.E = irr_E;
    }
    int own_st = (g->primvars & GEOM_PV_ST) != 0;
    PathState ps = {w, keys, diff, curv, offset, w->set->irradiance ? &irr : NULL, gi,
                    own_st ? ds : NULL, own_st ? dt : NULL, 0, NULL, instance};
    RayesShadeCtx ctx = {
        .n_points = n,
        .ray_type = RAYES_RAY_CAMERA,
        .diffuse_depth = 0,
        .specular_depth = 0,
        .P = (const float(*)[3])P,
        .N = (const float(*)[3])N,
        .Ng = (const float(*)[3])Ng,
        .dPdu = (const float(*)[3])dPdu,
        .dPdv = (const float(*)[3])dPdv,
        .u = u,
        .v = v,
        .s = s,
        .t = t,
        .du = du,
        .dv = dv,
        .I = (const float(*)[3])I,
        .Cs = (const float(*)[3])Cs,
        .Os = (const float(*)[3])Os,
        .renderer = &ps,
        .backfacing = back,
        .dst = own_st ? (const float(*)[4])dsts : NULL,
    };
    path_apply_Os_pattern(w, obj, &ctx, Os);
    size_t holes = path_count_holes(obj, n, (const float(*)[3])Os);
    ps.holes = holes > 0;
    w->stats.hole_points += holes;
    RayesShadeOutputs out = {.Ci = Ci, .Oi = Oi};
    w->stats.shading_points[0] += n;
    uint64_t sharp = w->sharp_rays;
    const RenderObject *outer = w->shading;
    w->shading = obj;
    /* the cache AOV's count of the grid's own diffuse rays (RAYES_AOV_CACHE) */
    AovSample grid_aov = {0}, *outer_aov = w->aov;
    w->aov = w->set->aovs & RAYES_AOV_CACHE ? &grid_aov : NULL;
    shade_run_lighting(w->services, &ctx, obj->shader, &out);
    w->aov = outer_aov;
    w->shading = outer;
    memcpy(ci, Ci, n * sizeof *ci);
    if (obj->transparent)
        memcpy(ci + n, Oi, n * sizeof *ci);
    /* the trailer: 1 if the grid reflects or refracts sharply (hider_camera_hit),
     * then the cache levels its diffuse rays read and their number */
    ci[n_ci][0] = w->sharp_rays != sharp ? 1.0f : 0.0f;
    ci[n_ci][1] = grid_aov.levels;
    ci[n_ci][2] = (float)grid_aov.lookups;
    free(irr_E);
    free(back);
    free(f3);
    free(f1);
    free(dsts);
    free(keys);
    free(diff);
    return ci;
}

/* The slot of grid gi as seen through instance (0: a world grid's own);
 * an instance's table is made when first asked for (under a lock). */
static GridSlot *grid_slot(GridShading *gsh, uint32_t gi, uint32_t instance)
{
    if (!instance)
        return &gsh->ci[gi];
    _Atomic(GridSlot *) *table = &gsh->inst[instance - 1];
    uint32_t m = gsh->rs->gs->instances[instance - 1].master;
    GridSlot *slots = atomic_load_explicit(table, memory_order_acquire);
    if (!slots) {
        pthread_mutex_t *lock = &gsh->locks[(instance * 2654435761u) % STRIPES];
        pthread_mutex_lock(lock);
        slots = atomic_load_explicit(table, memory_order_acquire);
        if (!slots) {
            slots = malloc((gsh->master_count[m] ? gsh->master_count[m] : 1) * sizeof *slots);
            RY_CHECK(slots != NULL);
            for (uint32_t k = 0; k < gsh->master_count[m]; k++)
                atomic_init(&slots[k], NULL);
            atomic_store_explicit(table, slots, memory_order_release);
        }
        pthread_mutex_unlock(lock);
    }
    return &slots[gi - gsh->master_first[m]];
}

/* The hit's corners of c (one RGB per grid vertex) interpolated into *out;
 * returns whether their summed RGB spreads by at most limit times its mean. */
static int corners(const Hit *hit, uint32_t first, const Rgb *c, float limit, Vec3 *out)
{
    Vec3 sum = v3(0, 0, 0);
    float lo = INFINITY, hi = 0.0f, mean = 0.0f;
    for (int k = 0; k < hit->n_vertex; k++) {
        const float *ck = c[hit->vertex[k] - first];
        float y = ck[0] + ck[1] + ck[2];
        lo = fminf(lo, y), hi = fmaxf(hi, y), mean += y / (float)hit->n_vertex;
        sum = v3_madd(sum, v3(ck[0], ck[1], ck[2]), hit->weight[k]);
    }
    *out = sum;
    return hi - lo <= limit * mean;
}

/* 1 if grid gi seen through instance is lit by a light that moves. */
static int lit_by_moving_light(const RenderScene *rs, uint32_t gi, uint32_t instance)
{
    const RenderObject *obj = render_object(rs, gi, instance);
    for (size_t k = 0; k < rs->n_lights; k++)
        if (rs->lights[k].n_times > 1 && rs->lights[k].type != LIGHT_AMBIENT &&
            render_lit_by(obj, k))
            return 1;
    return 0;
}

int hider_camera_hit(Worker *w, const Ray *ray, const Hit *hit, Vec3 *L, Vec3 *Oi)
{
    GridShading *gsh = w->grid_shading;
    uint32_t gi = hit->grid;
    const GridSet *gs = w->rs->gs;
    int moving = gs->grids[gi].moving;
    if ((moving && (hit->instance || !gsh->moving)) ||
        (hit->instance && gs->instances[hit->instance - 1].motion) || /* instance motion */
        (gsh->moving_lights && lit_by_moving_light(w->rs, gi, hit->instance)))
        return 0; /* shaded where the ray finds it, at its time */
    float f;
    int seg = moving ? geom_motion_segment(gs, ray->time, &f) : -1;
    GridSlot *slot = moving ? &gsh->seg_ci[(size_t)gsh->moving[gi] * gsh->n_seg + seg]
                            : grid_slot(gsh, gi, hit->instance);
    Rgb *ci = atomic_load_explicit(slot, memory_order_acquire);
    if (!ci) {
        pthread_mutex_t *lock =
            &gsh->locks[(gi + hit->instance * 2654435761u + (uint32_t)(seg + 1) * 40503u) %
                        STRIPES];
        pthread_mutex_lock(lock);
        ci = atomic_load_explicit(slot, memory_order_acquire);
        if (!ci) {
            /* a still grid's shading is shared by every time: its rays leave
             * at the shutter's middle, whichever ray came first; a moving
             * grid's by every time of its segment, whose middle it takes */
            float outer = w->time, outer_split = w->split;
            AovSample *outer_aov = w->aov; /* shared by every sample: none's own */
            w->aov = NULL;                 /* (shade_grid counts the grid's apart) */
            w->time = moving ? geom_segment_mid_time(gs, seg)
                             : 0.5f * (w->rs->camera.shutter[0] + w->rs->camera.shutter[1]);
            w->split = 1.0f;
            ci = shade_grid(w, gi, hit->instance, seg);
            w->time = outer;
            w->split = outer_split;
            w->aov = outer_aov;
            atomic_store_explicit(slot, ci, memory_order_release);
        }
        pthread_mutex_unlock(lock);
    }
    const Grid *g = &w->rs->gs->grids[gi];
    int transparent = render_object(w->rs, gi, hit->instance)->transparent;
    if (ci[grid_values(g, transparent)][0] != 0.0f)
        return 0; /* a sharp reflection or refraction: shaded where the ray hits */
    if (!corners(hit, g->first_vertex, ci, gsh->contrast, L))
        return 0;
    *Oi = v3(1, 1, 1);
    /* Opacity is no noisy estimate: a cut-out's edge (corners of 0 and 1)
     * or any step beyond HIDER_OPACITY_STEP is shaded where the ray hits. */
    if (transparent &&
        !corners(hit, g->first_vertex, ci + geom_grid_n_vertices(g), HIDER_OPACITY_STEP, Oi))
        return 0;
    const float *trailer = ci[grid_values(g, transparent)];
    if (w->aov && trailer[2] > 0.0f) { /* the grid's mean level, as one look-up */
        w->aov->levels += trailer[1] / trailer[2];
        w->aov->lookups++;
    }
    return 1;
}
