/*
 * session/session.c — one render: prepare (dice, build the ray tracing
 * structure), the frame, and statistics; plus the small public calls
 * (options, errors, versions, images).
 *
 * Memory: everything a render allocates is freed before rayes_render
 * returns, except the image and statistics handed to the caller.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "cache/cache.h"
#include "geom/geom.h"
#include "rayes/rayes.h"
#include "render/pbgi.h"
#include "render/render.h"
#include "render/services.h"
#include "render/volume.h"
#include "scene/scene.h"
#include "session/replay.h"
#include "session/session.h"
#include "session/stats.h"
#include "util/check.h"
#include "util/log.h"
#include "util/thread.h"

/* RayesRenderOptions.replay_rays keeps at most this much of rays. */
#define REPLAY_MAX_BYTES ((size_t)2000 * 1000 * 1000)

const char *rayes_error_string(RayesError e)
{
    switch (e) {
    case RAYES_OK: return "no error";
    case RAYES_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RAYES_ERROR_INVALID_OPERATION: return "invalid operation";
    case RAYES_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RAYES_ERROR_IO: return "input/output error";
    case RAYES_ERROR_PARSE: return "parse error";
    case RAYES_ERROR_CANCELLED: return "cancelled";
    }
    return "unknown error";
}

const char *rayes_version_string(void)
{
    return RAYES_VERSION_STRING;
}

void rayes_render_options_init(RayesRenderOptions *o, RayesQuality quality)
{
    memset(o, 0, sizeof *o);
    o->struct_size = sizeof *o;
    o->width = o->height = 512;
    o->spp = 4;
    o->threads = 0;
    o->bounces = 1;
    o->specular_depth = 4;
    o->filter = RAYES_FILTER_BOX;
    o->filter_width = 1.0f;
    o->tile_size = 32;
    o->cache = quality != RAYES_QUALITY_REFERENCE; /* the reference caches nothing */
    o->cache_mb = 100.0;
    o->cache_split[0] = 0.25f;
    o->cache_split[1] = 0.25f;
    o->cache_split[2] = 0.5f;
    o->cache_resolution = -1;
    o->cache_k = 1.0f;
    o->cache_fine_depth = 1;
    o->grid_size = GEOM_GRID_SIZE;
    o->branch_depth = 1;
    o->dice_offscreen = 4.0f;
    o->vertex_budget = 2e7;
    o->texture_mb = 64.0;
    o->texture_width = 1.0f;
    o->crop[1] = o->crop[3] = 1.0f;
    o->opacity_cache = quality != RAYES_QUALITY_REFERENCE;
    o->opacity_cache_mb = 20.0;
    o->volume_step = 1.0f;
    o->adaptive_error = 0.02f;
    o->irradiance_cache = quality != RAYES_QUALITY_REFERENCE;
    o->irradiance_cache_mb = 20.0;
    o->env_guide = quality != RAYES_QUALITY_REFERENCE;
    o->subsurface_rays = quality == RAYES_QUALITY_PREVIEW ? 4 : 64;
    o->pbgi_max_solid_angle = 0.05f;
    o->pbgi_raster = 8;
    switch (quality) {
    case RAYES_QUALITY_PREVIEW:
        o->shadow_rays = o->shadow_rays_deep = 4;
        o->diffuse_rays = o->diffuse_rays_deep = 4;
        break;
    case RAYES_QUALITY_FINAL:
        o->shadow_rays = o->shadow_rays_deep = 64;
        o->diffuse_rays = 1024;
        o->diffuse_rays_deep = 64;
        o->hider = RAYES_HIDER_GRID; /* the memo's REYES-style grid shading */
        o->irradiance = 1;
        break;
    case RAYES_QUALITY_REFERENCE:
        /* Converged in pixels as well as in light: at least 64 pixel
         * samples, each with 256 diffuse and 16 shadow rays (16,384 diffuse
         * paths a pixel, as the memo's 4096 rays at 4 samples gave), and up
         * to 1024 where the adaptive test finds a pixel short of 2% (edges,
         * reflections, the light's outline: docs/performance.md). */
        o->spp = 64;
        o->max_spp = 1024;
        o->shadow_rays = 16;
        o->shadow_rays_deep = 1;
        o->diffuse_rays = 256;
        o->diffuse_rays_deep = 1;
        break;
    }
}

void rayes_image_free(RayesImage *image)
{
    if (!image)
        return;
    free(image->rgba);
    free(image->aov);
    free(image);
}

/* The AOVs' channels, in the order of their bits (RayesAov). */
static const struct {
    unsigned aov;
    const char *names[3];
} aov_table[] = {{RAYES_AOV_Z, {"Z"}},
                 {RAYES_AOV_N, {"N.X", "N.Y", "N.Z"}},
                 {RAYES_AOV_P, {"P.X", "P.Y", "P.Z"}},
                 {RAYES_AOV_ID, {"id"}},
                 {RAYES_AOV_PATCH, {"patch"}},
                 {RAYES_AOV_CACHE, {"cache"}},
                 {RAYES_AOV_ALBEDO, {"albedo.R", "albedo.G", "albedo.B"}}};

int rayes_aov_channels(unsigned aovs)
{
    int n = 0;
    for (size_t k = 0; k < sizeof aov_table / sizeof aov_table[0]; k++)
        for (int c = 0; c < 3 && (aovs & aov_table[k].aov) && aov_table[k].names[c]; c++)
            n++;
    return n;
}

const char *rayes_aov_channel_name(unsigned aovs, int channel)
{
    for (size_t k = 0; k < sizeof aov_table / sizeof aov_table[0]; k++)
        for (int c = 0; c < 3 && (aovs & aov_table[k].aov) && aov_table[k].names[c]; c++)
            if (channel-- == 0)
                return aov_table[k].names[c];
    return NULL;
}

RayesError session_check_options(RayesScene *scene, const RayesRenderOptions *o)
{
    const char *what = NULL;
    if (o->struct_size != sizeof *o)
        what = "options: struct_size mismatch (call rayes_render_options_init)";
    else if (o->width < 1 || o->height < 1 || o->width > 65536 || o->height > 65536)
        what = "options: resolution must be 1 to 65536 pixels per side";
    else if (o->spp < 1 || o->spp > 1 << 20)
        what = "options: pixel samples must be 1 to 1048576";
    else if (o->max_spp < 0 || o->max_spp > 1 << 20 ||
             (o->max_spp > o->spp && !(o->adaptive_error > 0.0f && o->adaptive_error < 1e6f)))
        what = "options: max_spp must be 0 to 1048576 and adaptive_error positive";
    else if (!(o->sample_clamp >= 0.0f) || isinf(o->sample_clamp))
        what = "options: sample_clamp must be 0 (off) or positive";
    else if (o->bounces < 0 || o->bounces > 64 || o->specular_depth < 0 || o->specular_depth > 64)
        what = "options: depths must be 0 to 64";
    else if (o->shadow_rays < 0 || o->shadow_rays_deep < 0 || o->diffuse_rays < 0 ||
             o->diffuse_rays_deep < 0 || o->shadow_rays > 1 << 20 || o->diffuse_rays > 1 << 20 ||
             o->subsurface_rays < 0 || o->subsurface_rays > 1 << 20 ||
             o->irradiance_shadow_rays < 0 || o->irradiance_shadow_rays > 1 << 20)
        what = "options: ray counts must be 0 to 1048576";
    else if (!(o->filter_width > 0.0f) || o->filter_width > 16.0f ||
             (int)o->filter < RAYES_FILTER_BOX || o->filter > RAYES_FILTER_LANCZOS)
        what = "options: filter width must be in (0, 16]";
    else if ((o->gi != RAYES_GI_RAYTRACE && o->gi != RAYES_GI_POINTBASED) ||
             !(o->pbgi_max_solid_angle > 0.0f) || o->pbgi_max_solid_angle > 12.57f ||
             o->pbgi_raster < 2 || o->pbgi_raster > 64 || o->pbgi_raster % 2)
        what = "options: gi must be RAYES_GI_RAYTRACE or RAYES_GI_POINTBASED, the point-based "
               "solid angle in (0, 12.57] and its raster even, 2 to 64";
    else if (o->hider != RAYES_HIDER_RAYTRACE && o->hider != RAYES_HIDER_GRID)
        what = "options: hider must be RAYES_HIDER_RAYTRACE or RAYES_HIDER_GRID";
    else if (o->aovs & ~(unsigned)RAYES_AOV_ALL)
        what = "options: aovs must be RayesAov bits";
    else if (o->tile_size < 1 || o->threads < 0 || o->threads > 1024)
        what = "options: tile size must be positive and threads 0 to 1024";
    else if (!(o->cache_mb >= 0.0) || o->cache_mb > 1e7 || !(o->cache_k > 0.0f) ||
             !(o->opacity_cache_mb >= 0.0) || o->opacity_cache_mb > 1e7 ||
             !(o->irradiance_cache_mb >= 0.0) || o->irradiance_cache_mb > 1e7 ||
             o->cache_resolution < -1 || o->cache_resolution > 2 || o->cache_fine_depth < 0 ||
             o->cache_fine_depth > 128 || o->cache_split[0] < 0.0f || o->cache_split[1] < 0.0f ||
             o->cache_split[2] < 0.0f ||
             !(o->cache_split[0] + o->cache_split[1] + o->cache_split[2] <= 1.0001f))
        what = "options: cache budget 0 to 1e7 MB, split shares >= 0 summing to at most 1, "
               "k > 0, resolution -1 to 2, fine depth 0 to 128";
    else if (!(o->volume_step >= 0.01f) || !(o->volume_step <= 1000.0f))
        what = "options: volume step must be 0.01 to 1000 voxels";
    else if (o->grid_size < 1 || o->grid_size > GEOM_MAX_GRID_SIZE)
        what = "options: grid size must be 1 to 4096 micropolygons";
    else if (!(o->dice_offscreen >= 1.0f) || o->dice_offscreen > 1000.0f ||
             !(o->vertex_budget >= 0.0) || o->vertex_budget > 1e12)
        what =
            "options: off-screen dicing factor must be 1 to 1000 and the vertex budget 0 to 1e12";
    else if (!(o->crop[0] >= 0.0f && o->crop[0] < o->crop[1] && o->crop[1] <= 1.0f &&
               o->crop[2] >= 0.0f && o->crop[2] < o->crop[3] && o->crop[3] <= 1.0f))
        what = "options: the crop window must be xmin < xmax and ymin < ymax within [0, 1]";
    else if (!session_crop_pixels(o, NULL))
        what = "options: the crop window holds no pixel";
    else if (o->branch_depth < 1 || o->branch_depth > 129)
        what = "options: branch depth must be 1 to 129";
    else if (!(o->texture_mb >= 0.0) || o->texture_mb > 1e7 || !(o->texture_width >= 0.0f) ||
             o->texture_width > 1e3f)
        what = "options: texture cache budget must be 0 to 1e7 MB and texture width 0 to 1000";
    if (!what)
        return RAYES_OK;
    if (scene->error[0] == '\0')
        snprintf(scene->error, sizeof scene->error, "%s", what);
    return RAYES_ERROR_INVALID_ARGUMENT;
}

int session_crop_pixels(const RayesRenderOptions *o, int rect[4])
{
    /* RenderMan's rule: pixels ceil(res min) to ceil(res max) - 1, less a
     * hundredth of a pixel so that a float's rounding (0.3f is a little
     * over 0.3) does not take a pixel away. */
    int x0 = (int)ceil((double)o->width * o->crop[0] - 0.01);
    int x1 = (int)ceil((double)o->width * o->crop[1] - 0.01);
    int y0 = (int)ceil((double)o->height * o->crop[2] - 0.01);
    int y1 = (int)ceil((double)o->height * o->crop[3] - 0.01);
    if (rect)
        rect[0] = x0, rect[1] = y0, rect[2] = x1, rect[3] = y1;
    return x1 > x0 && y1 > y0;
}

RenderSettings session_settings(const RayesRenderOptions *o)
{
    RenderSettings s = {
        .width = o->width,
        .height = o->height,
        .spp = o->spp,
        .threads = o->threads,
        .tile_size = o->tile_size,
        .bounces = o->bounces,
        .specular_depth = o->specular_depth,
        .shadow_rays = o->shadow_rays,
        .shadow_rays_deep = o->shadow_rays_deep,
        .diffuse_rays = o->diffuse_rays,
        .diffuse_rays_deep = o->diffuse_rays_deep,
        .filter = (int)o->filter,
        .filter_width = o->filter_width,
        .seed = o->seed,
        .progress = o->progress,
        .progress_user = o->progress_user,
        .stop = o->stop,
        .cache_resolution = o->cache_resolution,
        .cache_k = o->cache_k,
        .cache_fine_depth = o->cache_fine_depth,
        .grid_size = o->grid_size,
        .dice_offscreen = o->dice_offscreen,
        .vertex_budget = (size_t)o->vertex_budget,
        .dice_isotropic = o->dice_isotropic != 0,
        .branch_depth = o->branch_depth,
        .hider = o->hider == RAYES_HIDER_GRID,
        .irradiance = o->irradiance != 0,
        .radiosity_cache = session_caches(o, CACHE_RADIOSITY),
        .opacity_cache = session_caches(o, CACHE_OPACITY),
        .irradiance_cache = session_caches(o, CACHE_IRRADIANCE),
        .env_guide = o->env_guide != 0,
        .subsurface_rays = o->subsurface_rays,
        /* the camera's count, at most RENDER_IRRADIANCE_SHADOW_RAYS (DESIGN.md) */
        .irradiance_shadow_rays = o->irradiance_shadow_rays > 0 ? o->irradiance_shadow_rays
                                  : o->shadow_rays < RENDER_IRRADIANCE_SHADOW_RAYS
                                      ? o->shadow_rays
                                      : RENDER_IRRADIANCE_SHADOW_RAYS,
        .volume_step = o->volume_step,
        .max_spp = o->max_spp,
        .adaptive_error = o->adaptive_error,
        .sample_clamp = o->sample_clamp,
        .pbgi_max_solid_angle = o->pbgi_max_solid_angle,
        .pbgi_raster = o->pbgi_raster,
        .tile_done = o->tile_done,
        .tile_user = o->tile_user,
        .tile_aov_done = o->tile_aov_done,
        .tile_source = o->tile_source,
        .tile_source_user = o->tile_source_user,
    };
    if (s.threads == 0)
        s.threads = thread_count_cores();
    session_crop_pixels(o, s.crop);
    return s;
}

int session_caches(const RayesRenderOptions *o, int t)
{
    switch (t) {
    case CACHE_RADIOSITY:
        return o->cache && o->cache_mb > 0.0;
    case CACHE_OPACITY:
        return o->opacity_cache && o->opacity_cache_mb > 0.0;
    case CACHE_IRRADIANCE:
        return o->irradiance_cache && o->irradiance_cache_mb > 0.0;
    }
    return 0;
}

Cache *session_cache(const RayesRenderOptions *o)
{
    uint64_t budgets[CACHE_N_TYPES] = {0};
    if (session_caches(o, CACHE_RADIOSITY))
        budgets[CACHE_RADIOSITY] = (uint64_t)(o->cache_mb * 1e6);
    if (session_caches(o, CACHE_OPACITY))
        budgets[CACHE_OPACITY] = (uint64_t)(o->opacity_cache_mb * 1e6);
    if (session_caches(o, CACHE_IRRADIANCE))
        budgets[CACHE_IRRADIANCE] = (uint64_t)(o->irradiance_cache_mb * 1e6);
    if (o->env_guide)
        budgets[CACHE_GUIDE] = RENDER_GUIDE_CACHE_BYTES;
    return cache_new_typed(budgets, o->cache_split);
}

/* The texture system of a render: the scene's texture path, then
 * RAYES_TEXTURE_PATH's directories. NULL when out of memory. */
TextureSystem *session_textures(const RayesScene *scene, double mb, float width)
{
    const char *a = scene_search_path(scene, SCENE_SEARCH_PATH_TEXTURE);
    const char *b = getenv("RAYES_TEXTURE_PATH");
    b = b ? b : "";
    size_t len = strlen(a) + strlen(b) + 2;
    char *path = malloc(len);
    if (!path)
        return NULL;
    snprintf(path, len, "%s:%s", a, b);
    TextureSystem *ts = texture_system_new(path, (uint64_t)(mb * 1e6), width);
    free(path);
    return ts;
}

/* The render-side view of the scene's objects, one block: the objects,
 * then for each light link set its n_lights flags, shared by the objects
 * made under it. */
RenderObject *session_render_objects(const RayesScene *scene)
{
    size_t n_ro = scene->n_objects + 1, n_lit = scene->n_links * scene->n_lights;
    RenderObject *ro = calloc(1, n_ro * sizeof *ro + n_lit);
    if (!ro)
        return NULL;
    unsigned char *lit = (unsigned char *)(ro + n_ro);
    for (size_t i = 0; i < scene->n_objects; i++) {
        const SceneObject *so = &scene->objects[i];
        ro[i].shader = so->shader.cls ? &so->shader : NULL;
        memcpy(ro[i].Cs, so->Cs, sizeof ro[i].Cs);
        memcpy(ro[i].Os, so->Os, sizeof ro[i].Os);
        ro[i].light = so->light;
        ro[i].opacity_shader = shade_instance_has_opacity(&so->shader) &&
                               so->transmission_hitmode == RAYES_TRANSMISSION_SHADER;
        ro[i].Os_pattern = so->Os_pattern;
        ro[i].transparent =
            so->light < 0 && (ro[i].opacity_shader || so->Os_pattern || so->Os[0] < 1.0f ||
                              so->Os[1] < 1.0f || so->Os[2] < 1.0f || so->Os_primvar_below_1);
        ro[i].opacity_cached = so->opacity_cache != 0;
        ro[i].thin_shadow =
            ro[i].opacity_shader && shade_instance_flags(&so->shader) & RAYES_SHADER_THIN_SHADOW;
        if (so->links == 0)
            continue;
        unsigned char *mine = lit + (size_t)(so->links - 1) * scene->n_lights;
        ro[i].lit = mine;
        for (size_t k = 0; k < scene->n_lights; k++)
            mine[k] = (unsigned char)scene_object_lit_by(scene, i, k);
    }
    return ro;
}

/* Whether object o, which bounds a volume, is seen by no ray: a pbrt
 * "interface" shape, which only says where its medium is. */
static int session_hidden_bound(const RayesScene *scene, int64_t o)
{
    return (scene->objects[o].ray_mask & (RAYES_RAY_CAMERA | RAYES_RAY_SHADOW | RAYES_RAY_DIFFUSE |
                                          RAYES_RAY_SPECULAR | RAYES_RAY_TRANSMISSION)) == 0;
}

/* Whether shadow rays cross object o, which bounds a volume (hidden, or
 * letting them through): the volume's segments inside it are then found
 * from its crossings, in a scene of its own (volume.c). */
static int session_crossed_bound(const RayesScene *scene, const RenderObject *ro, int64_t o)
{
    return session_hidden_bound(scene, o) || ro[o].transparent;
}

/* Ray masks; shadow rays pass through transparent objects (accel.h); subsurface
 * objects and mesh lights' emitters have scenes of their own. */
static uint32_t *object_masks(const RayesScene *scene, const RenderObject *ro)
{
    uint32_t *m = calloc(scene->n_objects + 1, sizeof *m);
    if (!m)
        return NULL;
    for (size_t i = 0; i < scene->n_objects; i++)
        m[i] = scene->objects[i].ray_mask | (ro[i].transparent ? ACCEL_MASK_TRANSPARENT : 0u) |
               ((ro[i].shader && (shade_instance_flags(ro[i].shader) & RAYES_SHADER_SUBSURFACE)) ||
                        (ro[i].light >= 0 && scene->lights[ro[i].light].type == LIGHT_MESH)
                    ? ACCEL_MASK_OWN_SCENE
                    : 0u);
    for (size_t i = 0; i < scene->n_volumes; i++) {
        int64_t o = scene->volumes[i].inside;
        if (o >= 0 && (size_t)o < scene->n_objects && session_crossed_bound(scene, ro, o))
            m[o] |= ACCEL_MASK_OWN_SCENE;
    }
    return m;
}

RayesError session_fail(RayesScene *scene, RayesError e, const char *msg)
{
    if (scene->error[0] == '\0')
        snprintf(scene->error, sizeof scene->error, "%s", msg);
    return e;
}

/* The render form of the scene's volumes: fine voxels about a pixel wide at
 * the box's nearest point to the eye (times the square root of its
 * shading rate, as grids are diced), their bricks' cache keys after the
 * grids'; an atmosphere's box is bounds (the scene's) and the eye. Returns 0,
 * or -1 when out of memory. */
static int prepare_volumes(const RayesScene *scene, const RenderSettings *set, Bounds3 bounds,
                           Prepared *p)
{
    if (!scene->n_volumes)
        return 0;
    p->volumes = calloc(scene->n_volumes, sizeof *p->volumes);
    if (!p->volumes)
        return -1;
    float screen[4];
    scene_camera_screen(&scene->camera, set->width, set->height, screen);
    const SceneCamera *c = &scene->camera;
    Camera cam = render_camera(c->eye, c->x, c->y, c->z, c->tan_half_fov, screen, set->height);
    uint32_t base = (uint32_t)p->gs.n_grids;
    for (size_t i = 0; i < scene->n_volumes; i++) {
        const SceneVolume *sv = &scene->volumes[i];
        Mat4 world_from_object = sv->world_from_object;
        Vec3 lo = v3(sv->bound[0], sv->bound[2], sv->bound[4]);
        Vec3 hi = v3(sv->bound[1], sv->bound[3], sv->bound[5]);
        Bounds3 wb = bounds_empty();
        if (sv->atmosphere) { /* the scene's bounds and the eye, a thousandth wider */
            wb = bounds_add(bounds, cam.eye);
            Vec3 pad = v3_scale(v3(1, 1, 1), fmaxf(1e-3f * v3_length(v3_sub(wb.hi, wb.lo)), 1e-3f));
            wb.lo = v3_sub(wb.lo, pad), wb.hi = v3_add(wb.hi, pad);
            world_from_object = mat4_identity();
            lo = wb.lo, hi = wb.hi;
        } else {
            for (int k = 0; k < 8; k++)
                wb = bounds_add(wb, mat4_point(&sv->world_from_object,
                                               v3(sv->bound[k & 1], sv->bound[2 + (k >> 1 & 1)],
                                                  sv->bound[4 + (k >> 2)])));
        }
        /* voxels a pixel wide where the box is nearest the eye (an
         * atmosphere, around the eye: at the scene's middle) */
        Vec3 near = sv->atmosphere ? v3_scale(v3_add(wb.lo, wb.hi), 0.5f)
                                   : v3(fminf(fmaxf(cam.eye.x, wb.lo.x), wb.hi.x),
                                        fminf(fmaxf(cam.eye.y, wb.lo.y), wb.hi.y),
                                        fminf(fmaxf(cam.eye.z, wb.lo.z), wb.hi.z));
        float dist =
            fmaxf(v3_length(v3_sub(near, cam.eye)), 1e-3f * v3_length(v3_sub(wb.hi, wb.lo)));
        float voxel = (cam.pixel_width + cam.pixel_spread * dist) * sqrtf(sv->shading_rate);
        RenderVolume *v = &p->volumes[p->n_volumes];
        uint32_t bricks = volume_init(v, sv->object, &world_from_object, lo, hi, voxel, base);
        if (bricks == 0)
            continue; /* a singular transform: nothing to march */
        v->atmosphere = sv->atmosphere;
        v->uniform = volume_uniform(&p->objects[sv->object]);
        v->inside = sv->inside;
        v->hidden_bound = sv->inside >= 0 && session_hidden_bound(scene, sv->inside);
        v->shadow_crosses = sv->inside >= 0 && session_crossed_bound(scene, p->objects, sv->inside);
        base += bricks;
        p->n_volumes++;
    }
    return 0;
}

RayesError session_prepare(RayesScene *scene, const RenderSettings *set, TextureSystem *textures,
                           Prepared *p)
{
    memset(p, 0, sizeof *p);
    geom_gridset_init(&p->gs);
    p->objects = session_render_objects(scene);
    p->masks = p->objects ? object_masks(scene, p->objects) : NULL;
    char err[300] = "";
    DiceOptions dice = {set->grid_size,
                        set->dice_offscreen,
                        set->vertex_budget,
                        set->dice_isotropic,
                        0.0,
                        set->radiosity_cache || set->irradiance_cache,
                        set->stop};
    int rc = !p->objects || !p->masks
                 ? -1
                 : scene_prepare(scene, set->width, set->height, &dice, textures, &p->gs,
                                 &p->coarsened, err, sizeof err);
    if (rc != 0) {
        session_prepared_fini(p);
        return session_fail(scene, rc == -2 ? RAYES_ERROR_CANCELLED : RAYES_ERROR_OUT_OF_MEMORY,
                            err[0] ? err : "render: out of memory preparing the scene");
    }
    p->accel = accel_new(&p->gs, p->masks, scene->n_objects, set->stop, err, sizeof err);
    if (!p->accel) {
        session_prepared_fini(p);
        return session_fail(
            scene, render_stop_requested(set) ? RAYES_ERROR_CANCELLED : RAYES_ERROR_OUT_OF_MEMORY,
            err);
    }
    for (size_t i = 0; i < scene->n_objects; i++)
        p->any_transparent |= p->objects[i].transparent;
    Bounds3 b = scene_bounds(scene);
    p->scene_radius = scene->n_prims || scene->n_volumes
                          ? fmaxf(0.5f * v3_length(v3_sub(b.hi, b.lo)), 1e-6f)
                          : 1.0f;
    if (prepare_volumes(scene, set, b, p) != 0) {
        session_prepared_fini(p);
        return session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY,
                            "render: out of memory preparing the volumes");
    }
    return RAYES_OK;
}

void session_prepared_fini(Prepared *p)
{
    accel_free(p->accel);
    geom_gridset_fini(&p->gs);
    free(p->objects);
    free(p->masks);
    free(p->volumes);
    memset(p, 0, sizeof *p);
}

/* The frame's camera: the still one, with the shutter, the lens and the
 * camera's motion. */
static Camera frame_camera(const RayesScene *scene, int width, int height)
{
    float screen[4];
    const SceneCamera *c = &scene->camera;
    scene_camera_screen(c, width, height, screen);
    Camera cam = render_camera(c->eye, c->x, c->y, c->z, c->tan_half_fov, screen, height);
    cam.shutter[0] = scene->shutter[0], cam.shutter[1] = scene->shutter[1];
    cam.lens_radius = c->lens_radius;
    cam.focal_distance = c->focal_distance;
    cam.n_motion = c->n_motion;
    for (int k = 0; k < c->n_motion; k++) {
        cam.motion_time[k] = c->motion_time[k];
        cam.motion_eye[k] = c->motion_eye[k];
        cam.motion_x[k] = c->motion_x[k], cam.motion_y[k] = c->motion_y[k];
        cam.motion_z[k] = c->motion_z[k];
    }
    return cam;
}

RenderScene session_render_scene(const RayesScene *scene, const Prepared *p, int width,
                                 int height)
{
    return (RenderScene){
        .gs = &p->gs, .accel = p->accel, .objects = p->objects, .n_objects = scene->n_objects,
        .lights = scene->lights, .n_lights = scene->n_lights,
        .camera = frame_camera(scene, width, height),
        .scene_radius = p->scene_radius,
        .any_transparent = p->any_transparent,
        .volumes = p->volumes,
        .n_volumes = p->n_volumes,
    };
}

/* Point-based GI's passes 1 and 2 (render/pbgi.h): the cloud into *cloud
 * (owned by the caller) and set->pbgi, written to opt->pointcloud_out if
 * given. */
static RayesError session_point_cloud(RayesScene *scene, const RayesRenderOptions *opt,
                                      const RenderScene *rs, RenderSettings *set,
                                      RenderStats *stats, PbgiCloud **cloud, PbgiTimes *times)
{
    *cloud = pbgi_build(rs, set, &render_services, stats, times);
    if (!*cloud)
        return session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY,
                            "render: out of memory for the point cloud");
    set->pbgi = *cloud;
    char err[400];
    if (opt->pointcloud_out && pbgi_write_ply(*cloud, opt->pointcloud_out, err, sizeof err) != 0)
        return session_fail(scene, RAYES_ERROR_IO, err);
    return RAYES_OK;
}

RayesError rayes_render(RayesScene *scene, const RayesRenderOptions *opt, RayesImage **image,
                        RayesStats **stats_out)
{
    if (!scene || !opt || !image)
        return RAYES_ERROR_INVALID_ARGUMENT;
    *image = NULL;
    if (stats_out)
        *stats_out = NULL;
    if (scene->timestamp == 0 || scene->dirty)
        return session_fail(scene, RAYES_ERROR_INVALID_OPERATION,
                            "render: the scene is not committed");
    RayesError e = session_check_options(scene, opt);
    if (e != RAYES_OK)
        return e;
    double t0 = time_now();
    RenderSettings set = session_settings(opt);
    Prepared prep;
    memset(&prep, 0, sizeof prep);
    RayesImage *img = calloc(1, sizeof *img);
    float *rgba = malloc(sizeof(float) * 4 * (size_t)set.width * set.height);
    size_t aov_floats = (size_t)rayes_aov_channels(opt->aovs) * set.width * set.height;
    float *aov = aov_floats ? malloc(sizeof(float) * aov_floats) : NULL;
    set.aovs = aov ? opt->aovs : 0;
    set.aov = aov;
    Cache *cache = NULL;
    AccelRecord *record = NULL;
    TextureSystem *textures = session_textures(scene, opt->texture_mb, opt->texture_width);
    RenderStats rstats = {0};
    PbgiCloud *cloud = NULL;
    PbgiTimes pbgi_times = {0};
    set.textures = textures;
    if (!img || !rgba || !textures || (aov_floats && !aov)) {
        e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "render: out of memory");
        goto done;
    }
    e = session_prepare(scene, &set, textures, &prep);
    if (e != RAYES_OK)
        goto done;
    if (session_caches(opt, CACHE_RADIOSITY) || session_caches(opt, CACHE_OPACITY) ||
        session_caches(opt, CACHE_IRRADIANCE) || opt->env_guide) {
        cache = session_cache(opt);
        if (!cache) {
            e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY,
                             "render: out of memory for the cache");
            goto done;
        }
        set.cache = cache;
    }
    double t1 = time_now();
    RenderScene rs = session_render_scene(scene, &prep, set.width, set.height);
    if (opt->gi == RAYES_GI_POINTBASED) {
        e = session_point_cloud(scene, opt, &rs, &set, &rstats, &cloud, &pbgi_times);
        if (e != RAYES_OK)
            goto done;
    }
    if (opt->replay_rays) { /* the frame's rays, not the point cloud's */
        record = accel_record_new(REPLAY_MAX_BYTES);
        if (!record) {
            e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "render: out of memory");
            goto done;
        }
        accel_attach_record(prep.accel, record);
    }
    double t1b = time_now(), cpu1 = time_cpu();
    if (render_frame(&rs, &set, rgba, &rstats) != 0) {
        e = session_fail(scene, RAYES_ERROR_CANCELLED, "render: cancelled");
        goto done;
    }
    double t2 = time_now(), cpu2 = time_cpu(), replay_wall = 0.0, replay_cpu = 0.0;
    if (record) {
        accel_attach_record(prep.accel, NULL);
        if (session_replay(prep.accel, record, set.threads, &replay_wall, &replay_cpu) != 0) {
            e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY, "render: cannot replay the rays");
            goto done;
        }
    }
    if (stats_out) {
        SessionTimes times = {t2 - t0, t1 - t0, t2 - t1b, cpu2 - cpu1, cloud != NULL,
                              pbgi_times.cloud_s, pbgi_times.bounces_s, pbgi_times.octree_s};
        *stats_out = session_stats_new(&set, &rstats, &prep.gs, &times,
                                       accel_memory_bytes(prep.accel));
        if (*stats_out && cache) {
            CacheStats cs;
            cache_get_stats(cache, &cs);
            session_stats_add_cache(*stats_out, &cs);
        }
        if (*stats_out) {
            TextureStats ts;
            texture_get_stats(textures, &ts);
            session_stats_add_textures(*stats_out, &ts);
            session_stats_add_real(*stats_out, "dicing/coarsened", prep.coarsened);
            if (record) {
                session_stats_add_count(*stats_out, "replay/rays", accel_record_rays(record));
                session_stats_add_count(*stats_out, "replay/dropped", accel_record_dropped(record));
                session_stats_add_real(*stats_out, "replay/wall_s", replay_wall);
                session_stats_add_real(*stats_out, "replay/cpu_s", replay_cpu);
            }
        }
        if (*stats_out && cloud) {
            session_stats_add_count(*stats_out, "pbgi/points", cloud->n_disks);
            session_stats_add_count(*stats_out, "pbgi/nodes", cloud->n_nodes);
            session_stats_add_count(*stats_out, "pbgi/gathers", rstats.pbgi_gathers);
        }
        if (!*stats_out) {
            e = session_fail(scene, RAYES_ERROR_OUT_OF_MEMORY,
                             "render: out of memory for statistics");
            goto done;
        }
    }
    img->width = set.width;
    img->height = set.height;
    img->rgba = rgba;
    img->aovs = set.aovs;
    img->aov_channels = rayes_aov_channels(set.aovs);
    img->aov = aov;
    aov = NULL;
    if (set.crop[0] > 0 || set.crop[1] > 0 || set.crop[2] < set.width || set.crop[3] < set.height) {
        img->crop[0] = set.crop[0], img->crop[1] = set.crop[1];
        img->crop[2] = set.crop[2] - set.crop[0], img->crop[3] = set.crop[3] - set.crop[1];
    }
    *image = img;
    img = NULL;
    rgba = NULL;
done:
    accel_record_free(record);
    pbgi_cloud_free(cloud);
    cache_free(cache);
    session_prepared_fini(&prep);
    texture_system_free(textures);
    free(rgba);
    free(aov);
    free(img);
    return e;
}
