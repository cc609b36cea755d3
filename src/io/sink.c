/*
 * io/sink.c — the sink that builds a RayesScene through rayes.h, and the
 * defaults of IoSettings.
 */
#include "io/sink.h"

#include <string.h>

static RayesError scene_set_camera(void *t, const float eye[3], const float at[3],
                                   const float up[3], float fov)
{
    return rayes_scene_set_camera(t, eye, at, up, fov);
}

static RayesError scene_set_camera_matrix(void *t, const float m[16], RayesProjection proj,
                                          float fov, const float screen[4])
{
    return rayes_scene_set_camera_matrix(t, m, proj, fov, screen);
}

static RayesError scene_set_transform(void *t, const float m[16])
{
    return rayes_scene_set_transform(t, m);
}

static RayesError scene_set_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    return rayes_scene_set_shader(t, name, p, n);
}

static RayesError scene_set_displacement(void *t, const char *name, const RayesParam *p,
                                         size_t n)
{
    return rayes_scene_set_displacement(t, name, p, n);
}

static RayesError scene_set_displacement_bound(void *t, float bound)
{
    return rayes_scene_set_displacement_bound(t, bound);
}

static RayesError scene_set_search_path(void *t, const char *kind, const char *path)
{
    return rayes_scene_set_search_path(t, kind, path);
}

static RayesError scene_set_shading_rate(void *t, float rate)
{
    return rayes_scene_set_shading_rate(t, rate);
}

static RayesError scene_set_visibility(void *t, uint32_t ray_types)
{
    return rayes_scene_set_visibility(t, ray_types);
}

static RayesError scene_set_opacity_mode(void *t, RayesTransmissionHitMode mode, int cache)
{
    return rayes_scene_set_opacity_mode(t, mode, cache);
}

static RayesError scene_bilinear_patch(void *t, const float P[4][3], const RayesPrimvar *pv,
                                       size_t n_pv)
{
    return rayes_scene_bilinear_patch_pv(t, P, pv, n_pv);
}

static RayesError scene_bicubic_patch(void *t, const float P[16][3], const RayesPrimvar *pv,
                                      size_t n_pv)
{
    return rayes_scene_bicubic_patch_pv(t, P, pv, n_pv);
}

static RayesError scene_subdivision_mesh(void *t, RayesSubdivScheme scheme, size_t n_faces,
                                         const int *n_verts, const int *indices, size_t n_points,
                                         const float *P, const RayesSubdivTags *tags,
                                         const RayesPrimvar *pv, size_t n_pv)
{
    return rayes_scene_subdivision_mesh(t, scheme, n_faces, n_verts, indices, n_points, P, tags, pv,
                                        n_pv);
}

static RayesError scene_curves(void *t, const RayesCurves *curves, const RayesPrimvar *pv,
                               size_t n_pv)
{
    return rayes_scene_curves(t, curves, pv, n_pv);
}

static RayesError scene_points(void *t, RayesPointShape shape, size_t n_points, const float *P,
                               const RayesPrimvar *pv, size_t n_pv)
{
    return rayes_scene_points(t, shape, n_points, P, pv, n_pv);
}

static RayesError scene_solid_begin(void *t, RayesSolidOp op)
{
    return rayes_scene_solid_begin(t, op);
}

static RayesError scene_solid_end(void *t) { return rayes_scene_solid_end(t); }

static RayesError scene_blobby(void *t, const RayesBlobby *b, const RayesPrimvar *pv, size_t n_pv)
{
    return rayes_scene_blobby(t, b, pv, n_pv);
}

static RayesError scene_polygon_mesh(void *t, size_t n_faces, const int *n_verts,
                                     const int *indices, size_t n_points, const float *P,
                                     const RayesPrimvar *pv, size_t n_pv)
{
    return rayes_scene_polygon_mesh_pv(t, n_faces, n_verts, indices, n_points, P, pv, n_pv);
}

static RayesError scene_sphere(void *t, float radius)
{
    return rayes_scene_sphere(t, radius);
}

static RayesError scene_volume_inside(void *t, const float bound[6])
{
    return rayes_scene_volume_inside(t, bound);
}

static RayesError scene_volume(void *t, const float bound[6])
{
    return rayes_scene_volume(t, bound);
}

static RayesError scene_atmosphere(void *t)
{
    return rayes_scene_atmosphere(t);
}

static RayesError scene_quadric(void *t, RayesQuadric type, const float *params, size_t n,
                                unsigned flags)
{
    return rayes_scene_quadric(t, type, params, n, flags);
}

static RayesError scene_area_light(void *t, const float P[4][3], const float L[3])
{
    return rayes_scene_area_light(t, P, L);
}

static RayesError scene_area_light_mesh(void *t, size_t n_faces, const int *n_verts,
                                        const int *indices, size_t n_points, const float *P,
                                        const float L[3], int two_sided)
{
    return rayes_scene_area_light_mesh(t, n_faces, n_verts, indices, n_points, P, L, two_sided);
}

static RayesError scene_area_light_mesh_textured(void *t, size_t n_faces, const int *n_verts,
                                                 const int *indices, size_t n_points,
                                                 const float *P, const float *st, const float L[3],
                                                 int two_sided, const char *texture)
{
    return rayes_scene_area_light_mesh_textured(t, n_faces, n_verts, indices, n_points, P, st, L,
                                                two_sided, texture);
}

static RayesError scene_area_light_quadric(void *t, RayesQuadric type, const float *params,
                                           size_t n, unsigned flags, const float L[3],
                                           int two_sided)
{
    return rayes_scene_area_light_quadric(t, type, params, n, flags, L, two_sided);
}

static RayesError scene_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    return rayes_scene_light(t, type, p, n);
}

static RayesError scene_set_light_links(void *t, RayesLightLinks mode, const size_t *lights,
                                        size_t n)
{
    return rayes_scene_set_light_links(t, mode, lights, n);
}

static size_t scene_light_count(void *t)
{
    return rayes_scene_light_count(t);
}

static const char *scene_get_error(void *t)
{
    return rayes_scene_get_error(t);
}

static RayesError scene_pattern(void *t, const char *name, const char *type,
                                const RayesParam *params, size_t n_params)
{
    return rayes_scene_pattern(t, name, type, params, n_params);
}

static int scene_has_shader(void *t, const char *name)
{
    return rayes_scene_has_shader(t, name);
}

static RayesError scene_object_begin(void *t, const char *name)
{
    return rayes_scene_object_begin(t, name);
}

static RayesError scene_object_end(void *t)
{
    return rayes_scene_object_end(t);
}

static RayesError scene_object_instance(void *t, const char *name)
{
    return rayes_scene_object_instance(t, name);
}

static RayesError scene_set_shutter(void *t, float open, float close)
{
    return rayes_scene_set_shutter(t, open, close);
}

static RayesError scene_set_transform_motion(void *t, size_t n, const float *times,
                                             const float (*m)[16])
{
    return rayes_scene_set_transform_motion(t, n, times, m);
}

static RayesError scene_motion_begin(void *t, size_t n, const float *times)
{
    return rayes_scene_motion_begin(t, n, times);
}

static RayesError scene_motion_end(void *t)
{
    return rayes_scene_motion_end(t);
}

static RayesError scene_set_camera_motion(void *t, size_t n, const float *times,
                                          const float (*m)[16])
{
    return rayes_scene_set_camera_motion(t, n, times, m);
}

static RayesError scene_set_depth_of_field(void *t, float lens_radius, float focal_distance)
{
    return rayes_scene_set_depth_of_field(t, lens_radius, focal_distance);
}

static RayesError scene_set_dice_blur(void *t, float motionfactor, float focusfactor)
{
    return rayes_scene_set_dice_blur(t, motionfactor, focusfactor);
}

IoSink io_sink_scene(RayesScene *scene)
{
    return (IoSink){
        .target = scene,
        .set_camera = scene_set_camera,
        .set_camera_matrix = scene_set_camera_matrix,
        .set_transform = scene_set_transform,
        .set_shader = scene_set_shader,
        .set_displacement = scene_set_displacement,
        .set_displacement_bound = scene_set_displacement_bound,
        .set_search_path = scene_set_search_path,
        .set_shading_rate = scene_set_shading_rate,
        .bilinear_patch = scene_bilinear_patch,
        .bicubic_patch = scene_bicubic_patch,
        .polygon_mesh = scene_polygon_mesh,
        .sphere = scene_sphere,
        .quadric = scene_quadric,
        .area_light = scene_area_light,
        .light = scene_light,
        .set_light_links = scene_set_light_links,
        .light_count = scene_light_count,
        .get_error = scene_get_error,
        .has_shader = scene_has_shader,
        .subdivision_mesh = scene_subdivision_mesh,
        .curves = scene_curves,
        .points = scene_points,
        .pattern = scene_pattern,
        .volume = scene_volume,
        .volume_inside = scene_volume_inside,
        .atmosphere = scene_atmosphere,
        .area_light_mesh_textured = scene_area_light_mesh_textured,
        .set_visibility = scene_set_visibility,
        .set_opacity_mode = scene_set_opacity_mode,
        .object_begin = scene_object_begin,
        .object_end = scene_object_end,
        .object_instance = scene_object_instance,
        .set_shutter = scene_set_shutter,
        .set_transform_motion = scene_set_transform_motion,
        .motion_begin = scene_motion_begin,
        .motion_end = scene_motion_end,
        .set_camera_motion = scene_set_camera_motion,
        .set_depth_of_field = scene_set_depth_of_field,
        .set_dice_blur = scene_set_dice_blur,
        .blobby = scene_blobby,
        .solid_begin = scene_solid_begin,
        .solid_end = scene_solid_end,
        .area_light_mesh = scene_area_light_mesh,
        .area_light_quadric = scene_area_light_quadric,
    };
}

void io_settings_init(IoSettings *s)
{
    memset(s, 0, sizeof *s);
    s->filter = -1;
    s->bounces = -1;
    s->specular_depth = -1;
    s->crop[1] = s->crop[3] = 1.0f;
    s->exposure_gain = s->exposure_gamma = 1.0f;
}

static const struct {
    const char *name;
    int filter;
    float width;
} filters[] = {
    {"box", RAYES_FILTER_BOX, 1},           {"gaussian", RAYES_FILTER_GAUSSIAN, 2},
    {"triangle", RAYES_FILTER_TRIANGLE, 2}, {"catmull-rom", RAYES_FILTER_CATMULL_ROM, 4},
    {"mitchell", RAYES_FILTER_MITCHELL, 4}, {"lanczos", RAYES_FILTER_LANCZOS, 6},
    {"sinc", RAYES_FILTER_LANCZOS, 6},
};

int io_filter_named(const char *name, float *width)
{
    for (size_t i = 0; i < sizeof filters / sizeof filters[0]; i++)
        if (strcmp(filters[i].name, name) == 0) {
            if (width)
                *width = filters[i].width;
            return filters[i].filter;
        }
    return -1;
}

const char *io_filter_name(int filter)
{
    for (size_t i = 0; i < sizeof filters / sizeof filters[0]; i++)
        if (filters[i].filter == filter)
            return filters[i].name;
    return "box";
}
