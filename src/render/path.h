/*
 * render/path.h — private to render/: what a path carries and what every
 * file of render/ that shades points needs: the ray differential, the
 * per-worker state (with the services table its shaders call), the path
 * state a shading context points to, and where rays leaving a point start.
 * It calls nothing of render/, so the files that trace (integrator.c), fill
 * (radiosity.c, irrgrid.c), shade grids (hider.c) and serve shaders
 * (services.c) depend on it and not on each other's circles.
 */
#ifndef RAYES_RENDER_PATH_H
#define RAYES_RENDER_PATH_H

#include "render/render.h"
#include "shade/diffusion.h"

/* The simplified ray differential of DESIGN.md: the footprint at distance t
 * is width + t * spread. */
typedef struct RayDiff {
    float width;   /* at the origin, scene units */
    float spread;  /* radians */
    float lens;    /* a camera ray through a thin lens: the lens's diameter (0: none); the
                      beam of the pixel's rays through the whole lens is lens * |t - focus|
                      / focus wide at t, added to the footprint (render_camera_ray_at) */
    float focus;   /* where that beam converges, in units of the ray's |d| */
} RayDiff;

/* The footprint of a ray at distance t (units of |d|): its width plus t
 * times its spread, plus a thin lens's defocus. */
static inline float path_footprint(RayDiff d, float t)
{
    float f = d.width + d.spread * t;
    if (d.lens > 0.0f && d.focus > 0.0f)
        f += d.lens * fabsf(t - d.focus) / d.focus;
    return f;
}

typedef struct GridShading GridShading;
typedef struct OpacityTable OpacityTable;

/* A medium under a surface as the subsurface service uses it
 * (subsurface.c): its three channels' profile constants and its lengths
 * in scene units, and the parameters they came from. */
typedef struct SubsurfaceMedium {
    RayesSubsurfaceParams params;
    DiffusionChannel ch[3];
    float scale; /* scene units per mm */
    float mfp;   /* the mean over channels of 1 / sigma_t', scene units */
} SubsurfaceMedium;

/* Workers sit side by side in one array, each written all the time by its
 * own thread (statistics, cache counters, the ray's time): aligned to a
 * cache line, so that no two share one. */
#define WORKER_ALIGN 64

/* The guide a worker built last for one environment light (envguide.c):
 * points of one grid come one after another, so it is looked up once. */
#define ENVGUIDE_LIGHTS 2
typedef struct GuideSlot {
    uint32_t patch, instance;
    int side, n; /* n: the shadow rays its decision was made for */
    int state;   /* 0: empty; 1: g usable; 2: no guide for that key */
    LightGuide g;
} GuideSlot;

typedef struct Worker {
    _Alignas(WORKER_ALIGN) const RenderScene *rs;
    const RenderSettings *set;
    RenderStats stats;
    CacheLocal cache;             /* this thread's part of the radiosity cache */
    GridShading *grid_shading; /* the grid hider's shaded grids, or NULL (hider.h) */
    OpacityTable *opacity_table; /* coarse opacity of transparent grids, or NULL (optable.h) */
    const RayesShaderServices *services; /* what shaders run here call (services.h) */
    const RayesShaderServices *albedo_services; /* the albedo AOV's furnace (services.h) */
    uint64_t sharp_rays;          /* perfect mirror and refraction rays traced from points at
                                     depth 0 (the grid hider asks whether a grid's shading
                                     traced any: hider.c) */
    float time;                   /* the time of the ray being shaded (scene time): rays the
                                     shading traces take it (integrator_trace sets and restores
                                     it; a cache fill sets its segment's middle) */
    SubsurfaceMedium medium;      /* the subsurface service's last medium: a shader passes
                                     the same one call after call, and setting one up is
                                     three profiles' constants (subsurface.c) */
    int has_medium;
    const struct RenderObject *shading; /* the object whose shader runs (its thin shadow is
                                           opaque to it: RAYES_SHADER_THIN_SHADOW) */
    int depth;                          /* the diffuse depth of the point being shaded (0 at a
                                           camera ray's hit; a fill's key's): its shadow rays
                                           play Russian roulette deeper (integrator.h) */
    float split;                        /* the rays the path being traced has split into so far (a
                                           glossy lobe's n at a camera hit: n), 1 at a camera ray
                                           and in cache fills: a path's own hit under a split of m
                                           traces n / m of its n diffuse and shadow rays (at least
                                           1), so a lobe of 1024 rays does not trace 1024 x 1024
                                           (services.c "split_rays") */
    GuideSlot guides[ENVGUIDE_LIGHTS];  /* environment lights' last guides (envguide.h) */
    const uint32_t *guide_pixels;       /* envguide_pixels's counts, or NULL: no guides (but
                                           the grid hider's) */
    AovSample *aov;                     /* the camera sample being traced's AOVs, or NULL */
} Worker;

/* What a shading context's `renderer` points to: per point (indexed from
 * ctx->first_point), the sample key its random numbers derive from, the ray
 * differential that arrived (width = footprint at the point), the grid's
 * curvature, and how far rays leaving the point start from it. */
typedef struct PathState {
    Worker *w;
    const uint64_t *keys;
    const RayDiff *diff;
    const float *curvature;
    const float *offset;
    struct IrrGrid *irr;          /* irradiance interpolation over this grid, or NULL
                                     (irrgrid.h) */
    uint32_t grid;                /* the grid (patch) all the points lie on */
    const float *ds, *dt;         /* texture filter widths in (s, t) where the points have
                                     texture coordinates of their own (primitive variable st),
                                     or NULL: the texture service then takes ctx->du, dv */
    int path;                     /* 1: a path's own hit (integrator.c), not a grid (a cache
                                     fill, the grid hider): past the branch depth its diffuse
                                     rays are one */
    float (*irradiance)[3];       /* per point, where direct lighting leaves pi times its
                                     diffuse result (the shader's Irradiance output, memo
                                     6.2), or NULL: not asked for */
    uint32_t instance;            /* the object instance grid is seen through: 0, or its
                                     GridSet index + 1 (its object's light links apply) */
    int shadow_rays;              /* shadow rays per light where the shader asks for the
                                     default, or 0: the renderer's setting for the depth
                                     (an irradiance cache fill sets its own) */
    int holes;                    /* 1: the points are a cut-out's (transparent, no opacity
                                     method), and one whose Os is 0 is a hole: its
                                     premultiplied Ci is 0 whatever its light, so the
                                     lighting services cast none of its rays (a fill's or
                                     the grid hider's points; a path's own hole is never
                                     shaded) */
} PathState;

/* The texture-space footprint of a point whose parameter footprint is
 * (du, dv), given dst = ds/du, ds/dv, dt/du, dt/dv. */
static inline void path_st_footprint(const float dst[4], float du, float dv, float *ds,
                                     float *dt)
{
    *ds = fabsf(dst[0]) * du + fabsf(dst[1]) * dv;
    *dt = fabsf(dst[2]) * du + fabsf(dst[3]) * dv;
}

/* A renderer's own bit on a specular ray's kind: a ray drawn from a glossy
 * lobe whose lights direct lighting integrates (services.c, glossy), so
 * emitters and environment lights look black to it, as to diffuse rays.
 * Never reaches a shader's ctx->ray_type. */
#define PATH_RAY_GLOSSY (1u << 16)

/* How far rays leaving a point of grid g start from it, along its normal:
 * the ray epsilon plus a bound on the sagitta of neighbouring grids' chords.
 * Adjacent patches diced at different rates do not share boundary vertices,
 * and on a curved surface a neighbour's micropolygons run inside a vertex
 * on the true surface by up to edge^2 * curvature / 8; rays from a grid's
 * boundary vertex (every cache fill has them) would otherwise hit the
 * neighbour from behind. The bound allows neighbours twice as coarse. */
float path_ray_offset(const Worker *w, const Grid *g);
/* The same for a master's grid seen through an instance (0: none): its
 * sagitta in world units. */
float path_ray_offset_in(const Worker *w, const Grid *g, uint32_t instance);

/* The distance rays start from a point off a grid (a light, an eye) and
 * stop short of a light: a millionth of the scene's radius times ten. */
float path_ray_epsilon(const Worker *w);

/* Multiplies the Os of ctx's points (Os, the array ctx->Os points to) by
 * obj's Os pattern, if it has one (a cut-out: pbrt's alpha texture),
 * filtered over the points' footprints; ctx->renderer is a PathState. */
void path_apply_Os_pattern(const Worker *w, const RenderObject *obj, const RayesShadeCtx *ctx,
                           float (*Os)[3]);

/* 1 if opacity Os is 0 in every channel: where a cut-out has a hole (NaN
 * is not). */
static inline int path_clear(const float Os[3])
{
    return Os[0] <= 0.0f && Os[1] <= 0.0f && Os[2] <= 0.0f;
}

/* The holes among n points of obj (path_clear) when obj is a cut-out
 * without an opacity method (PathState.holes), else 0. */
size_t path_count_holes(const RenderObject *obj, size_t n, const float (*Os)[3]);

#endif /* RAYES_RENDER_PATH_H */
