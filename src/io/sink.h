/*
 * io/sink.h — where scene readers send what they read.
 *
 * Readers (RIB, pbrt, OBJ, the patch file, the built-in scenes) never call
 * rayes.h's scene functions directly: they call the methods of an IoSink,
 * which mirror those functions one for one (same arguments, the scene
 * replaced by the sink's target; the patch and mesh methods are the _pv
 * calls, with primitive variables). Three sinks exist:
 *   - io_sink_scene (sink.c): forwards to rayes.h, building a RayesScene;
 *   - the RIB writer (rib_write.c): writes each call as ASCII RIB, so every
 *     reader doubles as a converter (`rayes convert`);
 *   - a recording stub in the tests, which checks what a reader said.
 * Render settings a file gives (image size, samples, filter, outputs) go
 * into an IoSettings, which the caller merges with the command line (the
 * command line wins).
 *
 * Errors: a method returns RayesError; a reader that gets an error stops
 * and reports it, naming its file and line. Messages of the scene sink come
 * from rayes_scene_get_error.
 */
#ifndef RAYES_IO_SINK_H
#define RAYES_IO_SINK_H

#include <stddef.h>
#include <stdint.h>

#include "rayes/rayes.h"

typedef struct IoSink {
    void *target; /* the first argument of every method */
    RayesError (*set_camera)(void *target, const float eye[3], const float look_at[3],
                             const float up[3], float fov_y_degrees);
    RayesError (*set_camera_matrix)(void *target, const float camera_from_world[16],
                                    RayesProjection projection, float fov_degrees,
                                    const float screen_window[4]);
    RayesError (*set_transform)(void *target, const float world_from_object[16]);
    RayesError (*set_shader)(void *target, const char *name, const RayesParam *params,
                             size_t n_params);
    RayesError (*set_displacement)(void *target, const char *name, const RayesParam *params,
                                   size_t n_params);
    RayesError (*set_displacement_bound)(void *target, float bound);
    RayesError (*set_search_path)(void *target, const char *kind, const char *path);
    RayesError (*set_shading_rate)(void *target, float shading_rate);
    RayesError (*bilinear_patch)(void *target, const float P[4][3], const RayesPrimvar *pv,
                                 size_t n_pv);
    RayesError (*bicubic_patch)(void *target, const float P[16][3], const RayesPrimvar *pv,
                                size_t n_pv);
    RayesError (*polygon_mesh)(void *target, size_t n_faces, const int *n_verts,
                               const int *indices, size_t n_points, const float *P,
                               const RayesPrimvar *pv, size_t n_pv);
    RayesError (*sphere)(void *target, float radius);
    RayesError (*quadric)(void *target, RayesQuadric type, const float *params, size_t n_params,
                          unsigned flags);
    RayesError (*area_light)(void *target, const float P[4][3], const float L[3]);
    RayesError (*light)(void *target, const char *type, const RayesParam *params,
                        size_t n_params);
    RayesError (*set_light_links)(void *target, RayesLightLinks mode, const size_t *lights,
                                  size_t n_lights);
    /* rayes_scene_light_count: the index the next light will get. */
    size_t (*light_count)(void *target);
    /* The last error message of the target, for reports; "" if none. */
    const char *(*get_error)(void *target);
    /* Nonzero if set_shader and set_displacement know the shader name (a
     * plugin, say), for readers that fall back to a built-in one. May be
     * NULL: only the built-in names are known. */
    int (*has_shader)(void *target, const char *name);
    /* rayes_scene_subdivision_mesh (last, so positional initialisers of
     * older sinks leave it NULL: readers then refuse subdivision meshes
     * with an error). */
    RayesError (*subdivision_mesh)(void *target, RayesSubdivScheme scheme, size_t n_faces,
                                   const int *n_verts, const int *indices, size_t n_points,
                                   const float *P, const RayesSubdivTags *tags,
                                   const RayesPrimvar *pv, size_t n_pv);
    /* rayes_scene_curves and rayes_scene_points (after it for the same
     * reason: readers refuse curves and points a sink lacks). */
    RayesError (*curves)(void *target, const RayesCurves *curves, const RayesPrimvar *pv,
                         size_t n_pv);
    RayesError (*points)(void *target, RayesPointShape shape, size_t n_points, const float *P,
                         const RayesPrimvar *pv, size_t n_pv);
    /* rayes_scene_pattern, in the space of the last set_transform (after
     * subdivision_mesh, so older sinks leave it NULL: readers then use
     * constants where textures would vary, with one warning). */
    RayesError (*pattern)(void *target, const char *name, const char *type,
                          const RayesParam *params, size_t n_params);
    /* rayes_scene_volume (NULL in sinks without it: readers skip volumes
     * with one warning). */
    RayesError (*volume)(void *target, const float bound[6]);
    /* rayes_scene_set_visibility and rayes_scene_set_opacity_mode (last,
     * so older sinks leave them NULL: readers then make every object
     * visible, with the shader's opacity, cached). */
    RayesError (*set_visibility)(void *target, uint32_t ray_types);
    RayesError (*set_opacity_mode)(void *target, RayesTransmissionHitMode mode, int cache);
    /* rayes_scene_object_begin, _end and _instance (last, so older sinks
     * leave them NULL: readers then record object definitions and replay
     * them per instance, as copies). Names are the reader's: RIB passes
     * its handle key (#1 or "name", quotes included), pbrt the name. */
    RayesError (*object_begin)(void *target, const char *name);
    RayesError (*object_end)(void *target);
    RayesError (*object_instance)(void *target, const char *name);
    /* Time (rayes.h's motion blur and depth of field calls; last, so older
     * sinks leave them NULL: readers then use the first motion sample and
     * a pinhole, with one warning). */
    RayesError (*set_shutter)(void *target, float open, float close);
    RayesError (*set_transform_motion)(void *target, size_t n_times, const float *times,
                                       const float (*world_from_object)[16]);
    RayesError (*motion_begin)(void *target, size_t n_times, const float *times);
    RayesError (*motion_end)(void *target);
    RayesError (*set_camera_motion)(void *target, size_t n_times, const float *times,
                                    const float (*camera_from_world)[16]);
    RayesError (*set_depth_of_field)(void *target, float lens_radius, float focal_distance);
    RayesError (*set_dice_blur)(void *target, float motionfactor, float focusfactor);
    /* rayes_scene_blobby (last, so older sinks leave it NULL: readers then
     * skip blobbies with one warning). */
    RayesError (*blobby)(void *target, const RayesBlobby *blobby, const RayesPrimvar *pv,
                         size_t n_pv);
    /* rayes_scene_solid_begin and _end (last: readers draw solids as the
     * union of their primitives, with one warning, for sinks without). */
    RayesError (*solid_begin)(void *target, RayesSolidOp op);
    RayesError (*solid_end)(void *target);
    /* rayes_scene_area_light_mesh (last: readers make quad lights of an
     * emitter's quads alone, with one warning, for sinks without). */
    RayesError (*area_light_mesh)(void *target, size_t n_faces, const int *n_verts,
                                  const int *indices, size_t n_points, const float *P,
                                  const float L[3], int two_sided);
    /* rayes_scene_area_light_quadric (last: readers draw emitting
     * quadrics as ordinary surfaces, with one warning, for sinks without). */
    RayesError (*area_light_quadric)(void *target, RayesQuadric type, const float *params,
                                     size_t n_params, unsigned flags, const float L[3],
                                     int two_sided);
    /* rayes_scene_volume_inside (last; NULL: readers make the box volume,
     * as before). */
    RayesError (*volume_inside)(void *target, const float bound[6]);
    /* rayes_scene_atmosphere (last; NULL: readers drop the atmosphere with
     * one warning). */
    RayesError (*atmosphere)(void *target);
    /* rayes_scene_area_light_mesh_textured (last; NULL: readers make the
     * emitter of radiance L alone, with one warning). */
    RayesError (*area_light_mesh_textured)(void *target, size_t n_faces, const int *n_verts,
                                           const int *indices, size_t n_points, const float *P,
                                           const float *st, const float L[3], int two_sided,
                                           const char *texture);
} IoSink;

/* A sink that builds scene through rayes.h (borrowed, not retained). */
IoSink io_sink_scene(RayesScene *scene);

#define IO_MAX_DISPLAYS 8

/* One output image a file asks for (RIB's Display, pbrt's Film filename). */
typedef struct IoDisplay {
    char name[512];  /* file name as given ("+" of an extra RIB display removed) */
    char type[32];   /* "file", "exr", "openexr", "png", "tiff", "framebuffer", ... */
    char mode[256];  /* "rgb", "rgba", "z", "Ci,a,...", ... ("rgba" when the file says
                        nothing) */
} IoDisplay;

/* Render settings a scene file gives; a field the file does not set keeps
 * the value io_settings_init gave it (0 or -1: "not given"). */
typedef struct IoSettings {
    int width, height;        /* pixels; 0: not given */
    int spp;                  /* pixel samples; 0: not given */
    int max_spp;              /* adaptive sampling's most pixel samples (RIB Hider
                                 "maxsamples"); 0: not given */
    float adaptive_error;     /* its relative standard error (RIB PixelVariance); 0: not
                                 given */
    float sample_clamp;       /* a camera sample's largest component (pbrt's Film
                                 "maxcomponentvalue"); 0: not given */
    int filter;               /* RayesFilter, or -1: not given */
    float filter_width;       /* pixels; 0: not given */
    int bounces;              /* maximum diffuse depth; -1: not given */
    int specular_depth;       /* maximum specular depth; -1: not given */
    int grid_size;            /* micropolygons per grid, at most (RIB Option "limits"
                                 "gridsize"); 0: not given */
    double texture_mb;        /* texture cache budget in 10^6 bytes (RIB Option "limits"
                                 "texturememory", in KB); 0: not given */
    double opacity_cache_mb;  /* opacity cache budget in 10^6 bytes (RIB Option "limits"
                                 "opacitycachememory", in KB); 0: not given */
    float crop[4];            /* xmin xmax ymin ymax in [0, 1] (RIB CropWindow); default 0 1 0 1 */
    float exposure_gain;      /* RIB Exposure; 1 when not given */
    float exposure_gamma;     /* RIB Exposure; 1 when not given */
    float background[4];      /* RIB Imager "background": the colour the image is
                                 composited over, before exposure; [3] 1 when given */
    int headlight;            /* 1: a scene without lights is lit by a light at the camera
                                 (RIB RenderMan 19+ without an Integrator: PxrDefault's) */
    int opaque;               /* 1: the format's films have no alpha (pbrt): images are
                                 written with alpha 1, the environment seen as pbrt shows it */
    int png_curve;            /* 8-bit files: IO_CURVE_SRGB (also 0, unsaid) or
                                 IO_CURVE_LINEAR (RenderMan's: values quantized as they are,
                                 after its Exposure) */
    IoDisplay displays[IO_MAX_DISPLAYS];
    int n_displays;
} IoSettings;

enum { IO_CURVE_UNSAID, IO_CURVE_SRGB, IO_CURVE_LINEAR };

void io_settings_init(IoSettings *settings);

/* Pixel filters by RenderMan's and pbrt's names: "box", "gaussian",
 * "triangle", "catmull-rom", "mitchell", "sinc" and "lanczos" (both the
 * Lanczos windowed sinc). Returns the RayesFilter, its default width in
 * pixels in *width (if not NULL), or -1 for another name. */
int io_filter_named(const char *name, float *width);
/* The RenderMan name of a RayesFilter ("box" for an unknown one). */
const char *io_filter_name(int filter);

/* What the caller tells a reader. */
typedef struct IoReadOptions {
    const char *data_dir;     /* where teapot.bpt lives (RIB's Geometry "teapot"); may be NULL */
    int frame;                /* RIB: the frame to read (FrameBegin n); -1: the last frame */
    int bounces_given;        /* the caller sets the diffuse bounces: a file's depth past
                                 the readers' cap is not worth a warning */
    unsigned view;            /* IO_VIEW_*: what of the view the caller sets after reading
                                 (the command line's camera; OBJ places its light for it) */
    float view_from[3], view_at[3], view_up[3];
} IoReadOptions;

enum { IO_VIEW_FROM = 1, IO_VIEW_AT = 2, IO_VIEW_UP = 4 };

#endif /* RAYES_IO_SINK_H */
