/*
 * render/render.h — the integrator and the frame loop (DESIGN.md "The
 * frame, end to end"): camera rays with differentials over tiles on a
 * thread pool; lighting() at camera and specular hits; at diffuse hits the
 * radiosity cache, or with it off diffuselighting() at the hit (the memo's
 * "without caching" baseline);
 * services for shaders; film with separable pixel filters.
 *
 * Inputs are immutable during a frame and shared by all workers; each
 * worker has its own statistics, merged at the end in worker order (sums of
 * integers, so the merge order does not matter).
 */
#ifndef RAYES_RENDER_RENDER_H
#define RAYES_RENDER_RENDER_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "cache/cache.h"
#include "geom/geom.h"
#include "shade/light.h"
#include "shade/shade.h"
#include "shade/texture.h"
#include "util/vec.h"

#define RENDER_MAX_DEPTH 16 /* diffuse depths counted separately in statistics */
/* The most shadow rays per light irradiance cache fills take by default:
 * they take the camera hits' count up to this (memo 6.2; DESIGN.md,
 * subsurface scattering). */
#define RENDER_IRRADIANCE_SHADOW_RAYS 16
/* The environment guides' cache budget (envguide.h): some 270 bytes a
 * grid's guide, so 16 MB hold about 60,000 grids' at once. */
#define RENDER_GUIDE_CACHE_BYTES 16000000

typedef struct RenderObject {
    const ShaderInstance *shader;          /* surface shader (NULL for lights) */
    float Cs[3], Os[3];                    /* surface colour and opacity */
    int light;                             /* index of the light it emits as, or -1 */
    const struct RayesPattern *Os_pattern; /* multiplies Os where not NULL (a cut-out) */
    uint8_t transparent;                   /* 1: may be partly transparent (Os or its primitive
                                              variable below 1, or a shader with an opacity
                                              method): shadow rays ask its opacity and
                                              other rays composite what lies behind it */
    uint8_t opacity_shader;                /* 1: its opacity is its shader's opacity method's
                                              (transmissionhitmode "shader"); 0: Os alone */
    uint8_t opacity_cached;                /* 1: its opacity may come from the cache (memo 6.1) */
    uint8_t thin_shadow;                   /* 1: opaque to the shadow rays its own shader casts
                                              (RAYES_SHADER_THIN_SHADOW) */
    const unsigned char *lit; /* n_lights flags, nonzero: that light illuminates it (its
                                 light links); NULL: every light does */
} RenderObject;

/* Whether light k illuminates obj (direct lighting, ambient). */
static inline int render_lit_by(const RenderObject *obj, size_t k)
{
    return !obj->lit || obj->lit[k];
}

/* The camera of a frame (rayes.h's rayes_scene_set_camera_matrix): a
 * screen position (sx, sy) in the screen window looks along
 * z + tan_half_fov (sx x + sy y) from eye in perspective, along z from
 * eye + sx x + sy y in orthographic projection. */
typedef struct Camera {
    Vec3 eye;                     /* world */
    Vec3 forward;                 /* unit view direction */
    Vec3 x, y, z;                 /* camera space's axes in world space (z = the view) */
    float tan_half_fov;           /* perspective: tan(fov / 2); orthographic: 0 */
    float screen[4];              /* left, right, bottom, top of the image on the screen */
    float pixel_spread;           /* radians between neighbouring camera rays (perspective) */
    float pixel_width;            /* world units between neighbouring rays (orthographic) */
    float shutter[2];             /* open, close: camera rays' times (scene time) */
    float lens_radius;            /* thin lens, world units; 0: a pinhole */
    float focal_distance;         /* along z from the eye (world units: z is unit length in
                                     focal_distance's measure, see render_camera_ray) */
    int n_motion;                 /* camera motion: time samples (0 or 1: still) */
    float motion_time[GEOM_MAX_TIMES];
    Vec3 motion_eye[GEOM_MAX_TIMES], motion_x[GEOM_MAX_TIMES], motion_y[GEOM_MAX_TIMES];
    Vec3 motion_z[GEOM_MAX_TIMES];
} Camera;

/* Whether shape faces each ray (flat curves without N, disks of points):
 * its grids' normals face the eye it was diced for, which for an
 * instance's master is the eye seen from another instance. */
static inline int render_faces_ray(int shape)
{
    return shape == GEOM_SHAPE_FLAT_CURVE || shape == GEOM_SHAPE_DISK;
}

/* The normal of a ray-facing shape seen along d, as pbrt's flat curves
 * face the ray: -d made perpendicular to the curve's tangent du (a disk:
 * -d itself), unit; fallback when d lies along du. */
static inline Vec3 render_facing(Vec3 d, Vec3 du, int shape, Vec3 fallback)
{
    Vec3 n = v3_neg(d);
    float tt = v3_dot(du, du);
    if (shape == GEOM_SHAPE_FLAT_CURVE && tt > 0.0f)
        n = v3_madd(n, du, -v3_dot(n, du) / tt);
    float len = v3_length(n);
    return len > 1e-6f * v3_length(d) ? v3_scale(n, 1.0f / len) : fallback;
}

/* The direction of the camera ray toward P: from the eye in perspective,
 * along the view in orthographic projection. */
static inline Vec3 render_view_toward(const Camera *cam, Vec3 P)
{
    Vec3 to = v3_sub(P, cam->eye);
    float dist = cam->tan_half_fov > 0.0f ? v3_length(to) : 0.0f;
    return dist > 0.0f ? v3_scale(to, 1.0f / dist) : cam->forward;
}

typedef struct RenderScene {
    const GridSet *gs;
    const Accel *accel;
    const RenderObject *objects;
    size_t n_objects;
    const Light *lights;
    size_t n_lights;
    Camera camera;
    float scene_radius;  /* for ray offsets */
    int any_transparent; /* 1: some object is transparent (shadow rays filter) */
    const struct RenderVolume *volumes; /* volume.h; not in the accel */
    size_t n_volumes;
} RenderScene;

/* The object a grid is shaded with when seen through instance (Hit.instance:
 * 0, or a GridSet instance index + 1): its own, or for a master's inheriting
 * grid the instance's (DESIGN.md "Instances"). */
static inline const RenderObject *render_object(const RenderScene *rs, uint32_t grid,
                                                uint32_t instance)
{
    uint32_t o = rs->gs->grids[grid].object;
    if (o == GEOM_OBJECT_INHERIT) /* never seen but through an instance; else the spare */
        o = instance ? rs->gs->instances[instance - 1].object : (uint32_t)rs->n_objects;
    return &rs->objects[o];
}

/* The instance of a hit or a cache key (0: none), or NULL. */
static inline const GeomInstance *render_instance(const RenderScene *rs, uint32_t instance)
{
    return instance ? &rs->gs->instances[instance - 1] : (const GeomInstance *)0;
}

/* What a camera sample's first visible surface says (RayesAov), filled by
 * the integrator (integrator.c) where Worker.aov points. */
typedef struct AovSample {
    int set;        /* 0: no surface (yet) */
    float z;        /* along the camera's view axis from the ray's origin */
    Vec3 N, P;      /* world: the shading normal facing the ray, the point */
    uint32_t id;    /* 1 + the render object */
    uint32_t patch; /* 1 + the grid */
    uint32_t lookups; /* radiosity look-ups of the sample's own diffuse rays' first hits */
    float levels;     /* and the sum of their resolutions (0 coarse, 1 medium, 2 fine) */
    Vec3 albedo;      /* the shader's lighting in a white furnace (albedo_services) */
} AovSample;

typedef struct RenderSettings {
    int width, height, spp, threads, tile_size;
    int crop[4];                  /* the pixels rendered: x0, y0, x1, y1 (exclusive ends);
                                     all zero: the whole frame */
    int bounces;                  /* maximum diffuse depth */
    int specular_depth;           /* maximum specular depth */
    int branch_depth;             /* points below this diffuse + specular depth branch
                                     (RayesRenderOptions.branch_depth) */
    int shadow_rays, shadow_rays_deep;
    int diffuse_rays, diffuse_rays_deep;
    int filter;                   /* RayesFilter */
    float filter_width;           /* pixels */
    uint64_t seed;
    int (*progress)(void *user, double fraction); /* nonzero: cancel */
    const volatile int *stop; /* nonzero: stop now, abandoning tiles under way (rays come back
                                 black; the frame is cancelled): one-shot renders only */
    void *progress_user;
    Cache *cache;            /* the cache (every data type), or NULL: uncached */
    int radiosity_cache;     /* 1: diffuse hits read radiosity from cache */
    int opacity_cache;       /* 1: shadow and diffuse rays read opacity from cache */
    int irradiance_cache;    /* 1: subsurface rays read irradiance from cache (memo 6.2) */
    int env_guide;           /* 1: environment lights drawn by per-grid guides (envguide.h) */
    int subsurface_rays;     /* subsurface rays per shading point (the service's 0) */
    int irradiance_shadow_rays; /* shadow rays per light at irradiance cache fills' points
                                   (the shader's 0): the option, or
                                   min(shadow_rays, RENDER_IRRADIANCE_SHADOW_RAYS) */
    float volume_step;       /* ray marching steps, in fine voxels of each volume */
    int cache_resolution;    /* -1: by differentials; else a forced CacheLevel */
    float cache_k;           /* resolution rule constant (DESIGN.md) */
    int cache_fine_depth;    /* deeper radiosity lookups read medium at finest */
    int grid_size;           /* micropolygons per grid, at most (dicing; geom.h) */
    float dice_offscreen;    /* off-screen dicing factor (DiceOptions) */
    size_t vertex_budget;    /* grid vertices, at most; 0: none (DiceOptions) */
    int dice_isotropic;      /* on screen by distance too (DiceOptions) */
    int hider;               /* 0: shade at every camera hit; 1: the grid hider (hider.h) */
    int irradiance;          /* 1: irradiance interpolation at depth 0 (irrgrid.h; grid
                                hider only) */
    const struct PbgiCloud *pbgi; /* point-based GI: the indirect-diffuse service gathers
                                     from this cloud (pbgi.h), or NULL: diffuse rays */
    float pbgi_max_solid_angle;   /* its clusters' largest solid angle, steradians */
    int pbgi_raster;              /* its gathers' cube raster, pixels a face side */
    TextureSystem *textures; /* image textures for the texture service, or NULL */
    int max_spp;             /* adaptive pixel sampling: above spp, a pixel takes further
                                blocks of spp samples while its error exceeds
                                adaptive_error, up to this many (0: off; one-shot frames;
                                render.c's pixel_converged) */
    float adaptive_error;    /* the relative standard error of a pixel's mean luminance
                                at which it stops */
    float sample_clamp;      /* a camera sample's largest component, or 0: no clamp */
    /* Progressive rendering (session/progressive.c); all zero for a one-shot frame. */
    int first_sample;             /* the frame takes pixel samples first_sample .. + spp - 1 */
    int pattern_spp;              /* of patterns of this many samples (0: spp); sample g is
                                     g % pattern_spp of block g / pattern_spp's pattern */
    float (*accum)[5];            /* width * height running sums (w r, w g, w b, w a, w) the
                                     frame adds to, or NULL: the frame's samples alone */
    unsigned aovs;                /* RayesAov bits (not with accum) */
    float *aov;                   /* width * height * rayes_aov_channels(aovs) floats the
                                     frame writes, or NULL */
    atomic_int *cancel;           /* nonzero: stop (tiles not yet started are skipped) */
    void (*tile_done)(void *user, int x, int y, int w, int h, const float *rgba, int stride);
    void *tile_user;              /* tile_done gets the frame's rgba and its row stride */
    void (*tile_aov_done)(void *user, int x, int y, int w, int h, const float *aov, int channels,
                          int stride); /* before tile_done: the frame's aov */
    int (*tile_source)(void *user, int tiles_x, int tiles_y); /* NULL: every tile */
    void *tile_source_user;
} RenderSettings;

typedef struct RenderStats {
    uint64_t rays_camera, rays_shadow, rays_diffuse, rays_specular;
    uint64_t adaptive_pixels_max; /* pixels that took max_spp samples (adaptive sampling) */
    uint64_t shading_points[RENDER_MAX_DEPTH + 1]; /* by diffuse depth */
    uint64_t irradiance_records;                   /* irradiance interpolation: records computed */
    uint64_t irradiance_interpolated;              /* and points interpolated */
    uint64_t ambient_lookups;                      /* points the ambient service was asked for */
    uint64_t opacity_points;   /* points whose opacity a shader computed (cache fills and
                                  uncached transmission hits) */
    uint64_t transparent_hits; /* surfaces shadow rays passed through (or stopped at) that
                                  were partly transparent */
    uint64_t holes;            /* camera, specular and diffuse hits on a cut-out's hole (Os
                                  0, no opacity method), passed unshaded */
    uint64_t hole_points;      /* points of fills and the grid hider's grids in such holes,
                                  their lighting's rays not cast (PathState.holes) */
    uint64_t table_lookups;    /* coarse opacity read from the opacity table (optable.h; not
                                  in the cache's counters) */
    uint64_t table_fills;      /* and the slots filled */
    uint64_t table_bytes;      /* the table's bytes at the frame's end */
    uint64_t rays_transmission; /* shadow and transmission rays that marched a volume (also
                                   counted in rays_shadow) */
    uint64_t volume_steps;      /* ray marching steps through volumes */
    uint64_t rays_subsurface;   /* subsurface rays: probes along -N and rays from probes */
    uint64_t subsurface_points; /* points the subsurface service integrated at */
    uint64_t irradiance_points; /* points whose irradiance a shader computed (cache fills
                                   and uncached subsurface hits) */
    uint64_t instance_fills;    /* radiosity cache fills of grids seen through object instances
                                   (each instance fills its own entries) */
    uint64_t pbgi_gathers;      /* point-based GI: points gathered from the cloud */
    uint64_t cluster_lookups;   /* radiosity and irradiance lookups a cluster of tiny grids
                                   answered (geom/cluster.c; counted in the coarse level's) */
    uint64_t segment_fills[GEOM_MAX_TIMES - 1]; /* radiosity cache fills of moving grids, by
                                                   motion segment (the entries each made) */
} RenderStats;

/* The camera of an image of `height` pixels: eye, axes and tan(fov / 2)
 * (0: orthographic) as camera_matrix gives them, and the screen window. */
Camera render_camera(Vec3 eye, Vec3 x, Vec3 y, Vec3 z, float tan_half_fov, const float screen[4],
                     int height);

/* The camera ray through image position (x, y) of a width x height image
 * (pixels, from the top left corner). */
Ray render_camera_ray(const RenderScene *rs, int width, int height, float x, float y);

/* The camera ray through (x, y) at a time (the camera where it is then)
 * and lens position (lu, lv) in [0, 1)^2 (with a thin lens). *lens and
 * *focus receive the lens's diameter and the distance along the unit ray
 * to the plane of focus (0 for a pinhole), for RayDiff's defocus term;
 * render_camera_ray is the ray at the shutter's opening through the lens's
 * centre. */
Ray render_camera_ray_at(const RenderScene *rs, int width, int height, float x, float y,
                         float time, float lu, float lv, float *lens, float *focus);

/* Whether set->stop asks the frame to stop (read atomically: another
 * thread or a signal handler writes it). */
static inline int render_stop_requested(const RenderSettings *set)
{
    return set->stop && __atomic_load_n(set->stop, __ATOMIC_RELAXED) != 0;
}

/* Renders a frame into rgba (width * height * 4 floats, top row first) and
 * adds to stats. Returns 0, or 1 if the progress callback or set->cancel
 * cancelled it (some tiles were then skipped; with accum, those finished
 * have added their samples). A box filter of width 1 (no margin) adds each
 * pixel's samples in sample order whatever the split into frames, so N
 * frames of one sample equal one frame of N samples, bit for bit. */
int render_frame(const RenderScene *rs, const RenderSettings *set, float *rgba, RenderStats *stats);

#endif /* RAYES_RENDER_RENDER_H */
