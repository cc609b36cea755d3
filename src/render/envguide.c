/*
 * render/envguide.c — an environment light's guide per grid (envguide.h,
 * DESIGN.md "Lights").
 */
#include "render/envguide.h"

#include <math.h>

#include "render/integrator.h"
#include "render/radiosity.h"
#include "util/half.h"

/* Shadow rays per bin at a guide's fill: the bin's 2 x 2 strata, drawn by
 * the map within the bin, each from another of the patch's coarse points
 * (a quad grid's four: what the patch sees, not what one point of it
 * sees). 128 bins, about half above a surface's horizon:
 * some 256 rays a grid, once, where a camera hit's light takes 4 to 64 per
 * pixel sample. */
#define GUIDE_RAYS 4
/* Every bin keeps at least this share of the largest bin's weight: a
 * point away from the guide's points may see a bin they do not (a
 * window's edge), and the floor bounds how much rarer its samples get
 * there (1 / GUIDE_FLOOR times at most). */
#define GUIDE_FLOOR (1.0f / 64.0f)
/* A bin's weight is at least this share of its neighbours' (fill_guide). */
#define GUIDE_SPREAD 0.5f
/* A guide pays where the light's samples on its patch outnumber its rays
 * this many times: a patch covering p pixels takes p x spp x n samples at
 * n shadow rays a point (the grid hider, which shades vertices: its
 * vertices x n), and a smaller one draws by the light alone. */
#define GUIDE_PAYS 4.0f
/* A guide's values in the cache: its bins, three to a value. */
#define GUIDE_VALUES ((LIGHT_GUIDE_BINS + 2) / 3)

typedef struct GuideJob {
    Worker *w;
    const Light *l;
} GuideJob;

/* CacheFillFn: the bins' weights seen from the patch's points, each the
 * mean over its rays of the cosine to the surface's normal times the
 * transmittance, scaled so that the largest is 1, floored by GUIDE_FLOOR;
 * all 1 where no ray gets out (nothing to guide by). */
static void fill_guide(void *user, const CacheKey *key, size_t n, float (*out)[3])
{
    const GuideJob *job = user;
    Worker *w = job->w;
    const Light *l = job->l;
    const Camera *cam = &w->rs->camera;
    float outer_time = w->time;
    const RenderObject *outer_shading = w->shading;
    const GridSet *gs = w->rs->gs;
    uint32_t grid =
        key->patch >= gs->n_grids ? gs->clusters[key->patch - gs->n_grids].rep : key->patch;
    /* whichever ray asked: the shutter's middle, and the patch's own
     * object (its thin shadow is its own, RAYES_SHADER_THIN_SHADOW) */
    w->time = 0.5f * (cam->shutter[0] + cam->shutter[1]);
    w->shading = render_object(w->rs, grid, key->instance);
    Vec3 P[4], N[4], o[4];
    float offset;
    int np = radiosity_patch_points(w, key->patch, key->instance, key->side, P, N, &offset);
    for (int i = 0; i < np; i++)
        o[i] = v3_madd(P[i], N[i], offset);
    float wt[LIGHT_GUIDE_BINS], top = 0.0f;
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++) {
        wt[b] = 0.0f;
        if (!(light_guide_mass(l, b) > 0.0f))
            continue;
        float sum = 0.0f;
        for (int s = 0; s < GUIDE_RAYS; s++) {
            LightSample ls;
            float a = ((float)(s & 1) + 0.5f) * 0.5f, c = ((float)(s >> 1) + 0.5f) * 0.5f;
            if (!light_guide_bin_sample(l, b, a, c, &ls))
                continue;
            int k = s % np; /* each ray from another of the patch's points */
            float cos_n = v3_dot(N[k], ls.wi);
            if (!(cos_n > 0.0f))
                continue;
            Ray shadow = {o[k], ls.wi, path_ray_epsilon(w), INFINITY, RAYES_RAY_SHADOW, w->time};
            /* a bin is about a fifth of a radian wide */
            Vec3 T = integrator_transmission(w, &shadow, (RayDiff){0.0f, 0.2f, 0.0f, 0.0f});
            sum += cos_n * (T.x + T.y + T.z) / 3.0f;
        }
        wt[b] = sum / GUIDE_RAYS;
        top = fmaxf(top, wt[b]);
    }
    w->time = outer_time;
    w->shading = outer_shading;
    /* Each bin takes half its brightest neighbour's weight: the light
     * seen through an opening moves across bins from point to point of
     * the patch (parallax), and a bin next to a seen one is likely seen
     * from somewhere. */
    float grown[LIGHT_GUIDE_BINS];
    for (int j = 0; j < LIGHT_GUIDE_V; j++)
        for (int i = 0; i < LIGHT_GUIDE_U; i++) {
            float m = wt[j * LIGHT_GUIDE_U + i];
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++) {
                    int jj = j + dj, ii = (i + di + LIGHT_GUIDE_U) % LIGHT_GUIDE_U;
                    if (jj >= 0 && jj < LIGHT_GUIDE_V)
                        m = fmaxf(m, GUIDE_SPREAD * wt[jj * LIGHT_GUIDE_U + ii]);
                }
            grown[j * LIGHT_GUIDE_U + i] =
                light_guide_mass(l, j * LIGHT_GUIDE_U + i) > 0.0f ? m : 0.0f;
        }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            size_t b = 3 * i + (size_t)c;
            out[i][c] = b >= LIGHT_GUIDE_BINS ? 0.0f
                        : top > 0.0f ? (grown[b] / top + GUIDE_FLOOR) / (1.0f + GUIDE_FLOOR)
                                     : 1.0f;
        }
}

uint32_t envguide_patch(const GridSet *gs, uint32_t grid)
{
    if (!gs->grid_cluster || !gs->grid_cluster[grid])
        return grid;
    uint32_t c = gs->grid_cluster[grid];
    while (gs->clusters[c - 1].parent)
        c = gs->clusters[c - 1].parent;
    return (uint32_t)gs->n_grids + c - 1;
}

/* The samples of a light the points of a patch take at n shadow rays
 * each: the grid hider shades each vertex once; the ray-traced hider each
 * pixel sample's hit (the pixels the patch covers, by the frame's count). */
static float patch_samples(const Worker *w, uint32_t patch, int n)
{
    const RenderSettings *set = w->set;
    const GridSet *gs = w->rs->gs;
    if (set->hider == 1) {
        const Grid *g =
            &gs->grids[patch >= gs->n_grids ? gs->clusters[patch - gs->n_grids].rep : patch];
        return (float)geom_grid_n_vertices(g) * (float)n;
    }
    /* a progressive pass: its pattern's samples, which the guide serves all of */
    float spp = (float)(set->pattern_spp ? set->pattern_spp : set->spp);
    return (float)w->guide_pixels[patch] * spp * (float)n;
}

const LightGuide *envguide_get(Worker *w, const Light *l, int slot, uint32_t grid,
                               uint32_t instance, int side, int n)
{
    const GridSet *gs = w->rs->gs;
    if (!w->set->env_guide || !w->set->cache || slot >= ENVGUIDE_LIGHTS || l->shadowless ||
        grid >= gs->n_grids || (!w->guide_pixels && w->set->hider != 1))
        return NULL;
    uint32_t patch = envguide_patch(gs, grid);
    GuideSlot *g = &w->guides[slot];
    if (g->state && g->patch == patch && g->instance == instance && g->side == side && g->n == n)
        return g->state == 1 ? &g->g : NULL;
    g->patch = patch, g->instance = instance, g->side = side, g->n = n;
    /* about half the bins lie above a surface's horizon */
    if (patch_samples(w, patch, n) < GUIDE_PAYS * GUIDE_RAYS * LIGHT_GUIDE_BINS / 2) {
        g->state = 2;
        return NULL;
    }
    CacheKey key = {.patch = patch,
                    .depth = (uint16_t)slot,
                    .side = (uint8_t)side,
                    .type = CACHE_GUIDE,
                    .level = CACHE_COARSE,
                    .instance = instance};
    GuideJob job = {w, l};
    const uint16_t *v = cache_lookup(&w->cache, &key, GUIDE_VALUES, fill_guide, &job);
    float wt[LIGHT_GUIDE_BINS];
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++)
        wt[b] = half_to_float_finite(v[b]);
    g->state = light_guide_init(l, wt, &g->g) ? 1 : 2;
    return g->state == 1 ? &g->g : NULL;
}
