/*
 * rayes.h — the public C API of rayes.
 *
 * rayes renders with distribution ray tracing and the multiresolution
 * radiosity cache of Pixar's technical memo 12-06. A program builds a scene
 * through this header (readers for scene files do the same), commits it, and
 * renders it with a set of options.
 *
 * Conventions (see docs/api.md and STYLE.md):
 *  - Objects are opaque handles with _new, _retain and _release.
 *  - A scene is edited, then committed. Every commit bumps the scene's
 *    timestamp, which radiosity cache entries are checked against.
 *  - Fallible calls return RayesError; the scene keeps the first error
 *    message until rayes_scene_clear_error().
 *  - A scene may be edited by one thread at a time. Rendering a committed
 *    scene may run while nobody edits it.
 *  - Lengths are in the scene's units (the benchmark scenes use millimetres),
 *    colours are linear RGB, angles are in degrees, matrices are row-major
 *    4 x 4 and map column vectors: p' = M p.
 *
 * This header compiles as C11 and as C++ (tests/api proves it).
 */
#ifndef RAYES_RAYES_H
#define RAYES_RAYES_H

#include <stddef.h>
#include <stdint.h>

#include "rayes/version.h"

#if defined(__GNUC__)
#define RAYES_API __attribute__((visibility("default")))
#else
#define RAYES_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Error codes. RAYES_OK is zero; everything else is a failure. */
typedef enum RayesError {
    RAYES_OK = 0,
    RAYES_ERROR_INVALID_ARGUMENT = 1, /* a parameter is out of range or NULL */
    RAYES_ERROR_INVALID_OPERATION = 2, /* the call is not allowed in this state */
    RAYES_ERROR_OUT_OF_MEMORY = 3,
    RAYES_ERROR_IO = 4,                /* a file could not be read or written */
    RAYES_ERROR_PARSE = 5,             /* a file's contents are malformed */
    RAYES_ERROR_CANCELLED = 6          /* the progress callback asked to stop */
} RayesError;

/* A short English name of an error code; never NULL, static storage. */
RAYES_API const char *rayes_error_string(RayesError error);

/* The version string, e.g. "0.1.0"; static storage. */
RAYES_API const char *rayes_version_string(void);

/* ---------------------------------------------------------------- scene */

typedef struct RayesScene RayesScene;

/* Creates an empty scene with a reference count of one, a default camera
 * and the default shader "matte". Returns NULL when out of memory. */
RAYES_API RayesScene *rayes_scene_new(void);
RAYES_API void rayes_scene_retain(RayesScene *scene);
/* Drops a reference; the last one frees the scene. NULL is ignored. */
RAYES_API void rayes_scene_release(RayesScene *scene);

/* The first error message recorded since the last clear, or "" if none.
 * Borrowed: valid until the next call on the scene. */
RAYES_API const char *rayes_scene_get_error(const RayesScene *scene);
RAYES_API void rayes_scene_clear_error(RayesScene *scene);

/* A pinhole camera at eye looking at target, with the given up vector and
 * vertical field of view in degrees (0 < fov < 180). */
RAYES_API RayesError rayes_scene_set_camera(RayesScene *scene, const float eye[3],
                                            const float target[3], const float up[3],
                                            float fov_y_degrees);

/* Projections of rayes_scene_set_camera_matrix. */
typedef enum RayesProjection {
    RAYES_PROJECTION_PERSPECTIVE = 0,
    RAYES_PROJECTION_ORTHOGRAPHIC = 1
} RayesProjection;

/* A camera given as RenderMan gives it: camera_from_world (row-major, a
 * rigid motion possibly with a uniform scale or a mirror), in whose camera
 * space the eye is at the origin looking down +z with +y up and +x to the
 * right of the image (left-handed, RenderMan's and pbrt's convention; a
 * mirror in the matrix mirrors the image). A point (x, y, z) of camera
 * space lands at screen position (x / z, y / z) / tan(fov / 2) in
 * perspective, (x, y) in orthographic projection (fov is then ignored).
 * screen_window is {left, right, bottom, top} of the screen rectangle the
 * image shows (RenderMan's ScreenWindow), or NULL for the default, which
 * depends on the image's aspect ratio a = width / height: {-a, a, -1, 1}
 * when a >= 1, else {-1, 1, -1/a, 1/a}, so the field of view spans the
 * shorter side of the image. Replaces any earlier camera. */
RAYES_API RayesError rayes_scene_set_camera_matrix(RayesScene *scene,
                                                   const float camera_from_world[16],
                                                   RayesProjection projection, float fov_degrees,
                                                   const float screen_window[4]);

/* The transform applied to geometry added from now on: world_from_object,
 * row-major. The identity at first. */
RAYES_API RayesError rayes_scene_set_transform(RayesScene *scene,
                                               const float world_from_object[16]);

/* ------------------------------------------------------------- time
 * Motion blur and depth of field (docs/scenes.md "Time"). Times are in
 * the scene's own units; the shutter says which of them the frame sees.
 * At most RAYES_MAX_TIMES samples per motion. */
#define RAYES_MAX_TIMES 16

/* The shutter interval: camera rays take times in [open, close] (RenderMan's
 * Shutter; default 0 0, no blur). open <= close. */
RAYES_API RayesError rayes_scene_set_shutter(RayesScene *scene, float open, float close);

/* A moving transform for geometry added from now on: world_from_object
 * (row-major) at n_times increasing times (2 to RAYES_MAX_TIMES); the
 * geometry moves linearly between samples (RenderMan's MotionBegin around
 * transforms). Lights made under it move with it within the frame, and
 * so do object instances placed under it. set_transform ends it. */
RAYES_API RayesError rayes_scene_set_transform_motion(RayesScene *scene, size_t n_times,
                                                      const float *times,
                                                      const float (*world_from_object)[16]);

/* Deformation blur: the next n_times primitive calls (until motion_end)
 * give one primitive at each of the increasing times, with the same
 * topology (the same call with the same counts, only positions differing);
 * their primitive variables and attributes are the first call's, but for
 * the widths and normals that place curves and points, each sample's. */
RAYES_API RayesError rayes_scene_motion_begin(RayesScene *scene, size_t n_times,
                                              const float *times);
RAYES_API RayesError rayes_scene_motion_end(RayesScene *scene);

/* A moving camera: camera_from_world at n_times increasing times (2 to
 * RAYES_MAX_TIMES), the projection of the last set_camera_matrix; the
 * first sample also becomes the still camera (dicing uses it). */
RAYES_API RayesError rayes_scene_set_camera_motion(RayesScene *scene, size_t n_times,
                                                   const float *times,
                                                   const float (*camera_from_world)[16]);

/* Depth of field: a thin lens of radius lens_radius (world units; 0: a
 * pinhole, the default) focused on the plane focal_distance along the
 * view (RenderMan's DepthOfField gives lens_radius = focallength / (2
 * fstop); pbrt's lensradius and focaldistance are these). */
RAYES_API RayesError rayes_scene_set_depth_of_field(RayesScene *scene, float lens_radius,
                                                    float focal_distance);

/* Coarser dicing of blurred geometry added from now on (RenderMan's
 * Attribute "dice" "motionfactor" and "focusfactor"; 0, the default, for
 * none): micropolygon edges longer by 1 + factor * blur / 16, blur in
 * pixels (the motion over the shutter, or the circle of confusion). */
RAYES_API RayesError rayes_scene_set_dice_blur(RayesScene *scene, float motionfactor,
                                               float focusfactor);

/* Shader parameters, given by name; the shader's class table says which
 * names and types it understands. Unknown names get one warning. */
typedef enum RayesParamType {
    RAYES_PARAM_NONE = 0,
    RAYES_PARAM_FLOAT = 1,   /* value[0] */
    RAYES_PARAM_COLOR = 2,   /* value[0..2], linear RGB */
    RAYES_PARAM_STRING = 3,  /* string */
    RAYES_PARAM_PATTERN = 4, /* string: the name of a pattern (rayes_scene_pattern); given for
                                a shader's FLOAT or COLOR parameter, the value varies over
                                the surface as the pattern does */
    RAYES_PARAM_FLOATS = 5   /* floats[0 .. n_floats - 1]: an array, for patterns' data
                                (densitygrid's "density") */
} RayesParamType;

typedef struct RayesParam {
    const char *name;    /* e.g. "Kd" */
    RayesParamType type;
    float value[3];      /* FLOAT and COLOR values */
    const char *string;  /* STRING value, copied by the callee */
    const float *floats; /* FLOATS values, copied by the callee */
    size_t n_floats;
} RayesParam;

/* The surface shader of geometry added from now on: a built-in class name
 * ("matte", "plastic", "mirror", "constant", "metal", "shinymetal", "glass",
 * "diffuse", "conductor", "dielectric", "coateddiffuse"), else a plugin
 * NAME.so found on the scene's "shader" search path, then on
 * $RAYES_SHADER_PATH (docs/shaders.md), with parameters. The parameters are
 * copied. An unknown class, or a plugin that fails to load or its checks,
 * is RAYES_ERROR_INVALID_ARGUMENT; the message names the file and the
 * problem, or the directories searched. */
RAYES_API RayesError rayes_scene_set_shader(RayesScene *scene, const char *name,
                                            const RayesParam *params, size_t n_params);

/* Nonzero if rayes_scene_set_shader would find a class of that name now (a
 * built-in, or a plugin that loads from the search paths; loading it is
 * kept). For readers of scene files that fall back to a built-in shader. No
 * error is recorded in the scene. */
RAYES_API int rayes_scene_has_shader(RayesScene *scene, const char *name);

/* The displacement shader of geometry added from now on: a class with a
 * displacement method (the built-ins "bumpy" and "fractal", or a plugin's),
 * run on every vertex of the fine grids when the scene is prepared, before
 * ray tracing structures are built; normals are then those of the
 * displaced surface. NULL or "" removes it (the default: none). Parameters
 * as for rayes_scene_set_shader. A class without a displacement method is
 * RAYES_ERROR_INVALID_ARGUMENT. */
RAYES_API RayesError rayes_scene_set_displacement(RayesScene *scene, const char *name,
                                                  const RayesParam *params, size_t n_params);

/* The displacement bound of geometry added from now on (RenderMan's
 * Attribute "displacementbound" "sphere"), in world units: the promise that
 * no point moves farther. Displacements are clamped to it, with one
 * warning per shader. 0 (the default) means unbounded. */
RAYES_API RayesError rayes_scene_set_displacement_bound(RayesScene *scene, float bound);

/* Defines the pattern `name`: one of pbrt-v4's texture classes, which
 * shader parameters may then take (a RAYES_PARAM_PATTERN parameter of
 * set_shader, set_displacement or edit_shader naming it). An input
 * ("tex1", "amount", ...) is a FLOAT or COLOR constant or another pattern
 * (RAYES_PARAM_PATTERN); the 3-D classes work in the space of the current
 * transform (texture space = object space of the call).
 *   "constant"      value
 *   "scale"         tex * scale
 *   "mix"           (1 - amount) tex1 + amount tex2
 *   "directionmix"  tex1 weighted by |N . dir| (dir a COLOR, a direction in
 *                   texture space), tex2 by the rest
 *   "checkerboard"  tex1 on squares where floor(u) + floor(v) is even, tex2
 *                   on the others, box-filtered; "dimension" 3: on cubes of
 *                   texture space, unfiltered
 *   "imagemap"      "filename" (STRING, on the texture search path) times
 *                   "scale", "invert" (1: 1 - value), "encoding" (STRING:
 *                   "sRGB", "linear" or "gamma G", for integer files; default
 *                   the file's), "channel" (-1: RGB, 0 to 3 that channel grey,
 *                   -2 the matte: alpha if the file has it, else channel 0;
 *                   a bump slot's file, a normal map told from a height map
 *                   by its average texel: -3 the height, channel 0 times
 *                   scale, 0 for a normal map; -4 the normal, the texels
 *                   with x and y about 0.5 times scale, (0.5, 0.5, 1) for a
 *                   height map)
 *   "bilerp"        v00 v01 v10 v11 (constants) over (u, v)
 *   "dots"          inside, outside: polka dots on the (u, v) cells
 *   "fbm", "wrinkled", "windy", "marble"  pbrt's noise patterns (octaves,
 *                   roughness; marble: scale, variation)
 *   "densitygrid"   pbrt-v4's uniform grid: "nx", "ny", "nz" (FLOAT counts),
 *                   "density" (FLOATS, nx ny nz values, x fastest) over the
 *                   box "p0" to "p1" (COLORs, default 0 0 0 and 1 1 1);
 *                   trilinear between voxel centres, 0 outside the box
 *   "nanovdb"       a float grid of a NanoVDB file: "filename" (STRING, on
 *                   the texture search path), "grid" (STRING, default
 *                   "density"); the file's world space is texture space;
 *                   read at once (a missing, damaged or compressed file, or
 *                   no float grid of that name, is an error naming the
 *                   file); trilinear, 0 (the background) outside the tree
 * The 2-D classes take pbrt's (u, v) = (s, 1 - t) and "uscale", "vscale",
 * "udelta", "vdelta". A later definition of a name replaces it for later
 * references. An unknown class, parameter or pattern name, a wrong type, or
 * patterns nested deeper than 16 are RAYES_ERROR_INVALID_ARGUMENT. */
RAYES_API RayesError rayes_scene_pattern(RayesScene *scene, const char *name, const char *type,
                                         const RayesParam *params, size_t n_params);
/* Sets the scene's search path of a kind ("shader" or "texture"):
 * directories separated by ':', searched in order by later calls
 * (set_shader) or, for textures, by the renders of the scene (a texture
 * name is tried as given, then in each directory, then in those of
 * $RAYES_TEXTURE_PATH). An entry "&" or "@" stands for the previous value
 * (as in RenderMan), so "mine:&" prepends. Empty entries are ignored. */
RAYES_API RayesError rayes_scene_set_search_path(RayesScene *scene, const char *kind,
                                                 const char *path);

/* The shading rate of geometry added from now on: the area of a
 * micropolygon in pixels (RenderMan's ShadingRate). Default 1. */
/* Visibility of the objects made from now on: the RayesRayType bits
 * (rayes/shader.h) of the rays that see them, RenderMan's Attribute
 * "visibility" (camera, diffuse, specular, and transmission, which is
 * RAYES_RAY_SHADOW or RAYES_RAY_TRANSMISSION: shadow and transmission rays
 * alike). Default: all. An object invisible to shadow rays casts no
 * shadow. */
RAYES_API RayesError rayes_scene_set_visibility(RayesScene *scene, uint32_t ray_types);

/* How shadow and transmission rays find the opacity of the objects made
 * from now on (RenderMan's Attribute "shade" "transmissionhitmode"). */
typedef enum RayesTransmissionHitMode {
    RAYES_TRANSMISSION_SHADER = 0,   /* the shader's opacity method, or Os without one
                                        (default) */
    RAYES_TRANSMISSION_PRIMITIVE = 1 /* Os alone (the Opacity colour, or its primitive
                                        variable); the shader never runs */
} RayesTransmissionHitMode;

/* The transmission hit mode of the objects made from now on, and whether
 * their opacity may be cached (memo 6.1: cache 1, the default, assumes one
 * opacity per point whatever the side seen and the ray depth; 0 for
 * shaders that break that assumption: they run at every hit). */
RAYES_API RayesError rayes_scene_set_opacity_mode(RayesScene *scene, RayesTransmissionHitMode mode,
                                                  int cache);

RAYES_API RayesError rayes_scene_set_shading_rate(RayesScene *scene, float shading_rate);

/* A bilinear patch with corners P[0] = (u0,v0), P[1] = (u1,v0),
 * P[2] = (u0,v1), P[3] = (u1,v1), as RenderMan's Patch "bilinear". */
RAYES_API RayesError rayes_scene_bilinear_patch(RayesScene *scene, const float P[4][3]);

/* A bicubic Bezier patch of 16 control points, row-major with u varying
 * fastest (P[4*j + i] is the i-th point of row j). */
RAYES_API RayesError rayes_scene_bicubic_patch(RayesScene *scene, const float P[16][3]);

/* A polygon mesh: n_faces faces, face f having n_verts[f] vertices (3 or 4,
 * convex, counter-clockwise seen from the front), indices into P (n_points
 * points, three floats each). Quads become bilinear patches, triangles
 * triangular patches. */
RAYES_API RayesError rayes_scene_polygon_mesh(RayesScene *scene, size_t n_faces,
                                              const int *n_verts, const int *indices,
                                              size_t n_points, const float *P);

/* Primitive variables: values given with a patch or mesh and interpolated
 * over its surface, as RenderMan's. Each name has a fixed size:
 *   "N"   3 floats: the shading normal (object space, transformed like a
 *         normal; interpolated, then normalised). The geometric normal of
 *         the surface still decides its front, ray offsets and shadows; a
 *         supplied normal pointing to the back is turned to the front
 *         side. A displacement shader replaces it with the displaced
 *         surface's normal.
 *   "st"  2 floats: the texture coordinates shaders get as s and t (and
 *         texture filter widths derived from them). Default: (u, v).
 *   "Cs"  3 floats: the surface colour, replacing the shader's Cs.
 *   "Os"  3 floats: the surface opacity, replacing the shader's Os (an
 *         "Os" pattern still multiplies it); an object with a value below
 *         1 anywhere is partly transparent to every ray.
 * A class says how many values there are (count) and how they are
 * interpolated:
 *   CONSTANT     1 for the whole call
 *   UNIFORM      1 per face (patch)
 *   VARYING      polygon mesh: 1 per point (as VERTEX); patches: 1 per
 *                corner, in the corner order of P, interpolated bilinearly
 *                (a bicubic patch too, as RenderMan does)
 *   VERTEX       polygon mesh: 1 per point; bilinear patch: 1 per corner;
 *                bicubic patch: 1 per control point (16, in P's order),
 *                interpolated with the Bezier basis as P is
 *   FACEVARYING  1 per face corner (polygon mesh: in the order of indices;
 *                a patch: its 4 corners)
 * Mesh faces interpolate point and corner values bilinearly on quads and
 * barycentrically on triangles. The data are copied. A name not listed,
 * a class out of range, a count that does not match, a name given twice
 * or a non-finite value is RAYES_ERROR_INVALID_ARGUMENT. */
typedef enum RayesPrimvarClass {
    RAYES_PRIMVAR_CONSTANT = 0,
    RAYES_PRIMVAR_UNIFORM = 1,
    RAYES_PRIMVAR_VARYING = 2,
    RAYES_PRIMVAR_VERTEX = 3,
    RAYES_PRIMVAR_FACEVARYING = 4
} RayesPrimvarClass;

typedef struct RayesPrimvar {
    const char *name;        /* "N", "st", "Cs" or "Os" */
    RayesPrimvarClass cls;   /* how many values and how they are interpolated */
    const float *data;       /* count values of the name's size, back to back */
    size_t count;            /* values (not floats) */
} RayesPrimvar;

/* The patch and mesh calls above with primitive variables (pv may be NULL
 * when n_pv is 0; the calls above are these with none). */
RAYES_API RayesError rayes_scene_bilinear_patch_pv(RayesScene *scene, const float P[4][3],
                                                   const RayesPrimvar *pv, size_t n_pv);
RAYES_API RayesError rayes_scene_bicubic_patch_pv(RayesScene *scene, const float P[16][3],
                                                  const RayesPrimvar *pv, size_t n_pv);
RAYES_API RayesError rayes_scene_polygon_mesh_pv(RayesScene *scene, size_t n_faces,
                                                 const int *n_verts, const int *indices,
                                                 size_t n_points, const float *P,
                                                 const RayesPrimvar *pv, size_t n_pv);

/* Subdivision surfaces: the exact limit surface of a control mesh
 * (RenderMan's SubdivisionMesh), evaluated with OpenSubdiv. Faces are as
 * in rayes_scene_polygon_mesh but of any size of at least 3 (Loop: 3
 * only). Primitive variables follow the polygon mesh's counts; vertex ones
 * are interpolated as P is (on the limit surface), varying ones linearly
 * over each face, facevarying ones on OpenSubdiv's face-varying surface
 * (smooth across faces where the corners agree, as tags say at
 * boundaries). */
typedef enum RayesSubdivScheme {
    RAYES_SUBDIV_CATMULL_CLARK = 0,
    RAYES_SUBDIV_LOOP = 1,
    RAYES_SUBDIV_BILINEAR = 2
} RayesSubdivScheme;

/* Sharpness of an infinitely sharp crease or corner (OpenSubdiv's; any
 * value at least this is infinite). */
#define RAYES_SUBDIV_INFINITELY_SHARP 10.0f

/* RenderMan's tags. interpolate_boundary: 0 leaves boundary faces out
 * (they have no limit surface), 1 interpolates boundary edges and
 * corners (the default of rayes_scene_subdivision_mesh with NULL tags),
 * 2 edges only. facevarying_boundary: RenderMan's
 * "facevaryinginterpolateboundary" 0 (smooth) to 3 (default 1). Creases
 * are edges (pairs of point indices) with a sharpness each; corners
 * points with a sharpness each; holes faces that are left out. */
typedef struct RayesSubdivTags {
    int interpolate_boundary;
    int facevarying_boundary;
    size_t n_creases;
    const int *crease_edges;       /* 2 * n_creases point indices */
    const float *crease_sharpness; /* n_creases, >= 0 */
    size_t n_corners;
    const int *corner_points;      /* n_corners point indices */
    const float *corner_sharpness; /* n_corners, >= 0 */
    size_t n_holes;
    const int *hole_faces; /* n_holes face indices */
} RayesSubdivTags;

RAYES_API RayesError rayes_scene_subdivision_mesh(RayesScene *scene, RayesSubdivScheme scheme,
                                                  size_t n_faces, const int *n_verts,
                                                  const int *indices, size_t n_points,
                                                  const float *P, const RayesSubdivTags *tags,
                                                  const RayesPrimvar *pv, size_t n_pv);

/* Curves (RenderMan's Curves, pbrt-v4's curve): n_curves curves of
 * n_verts[c] control points each, P all their points back to back.
 * degree 1 is linear; degree 3 is cubic in RenderMan's basis matrix
 * (RiBasis's: a segment is [t^3 t^2 t 1] basis G, G its 4 control points,
 * the next segment step points on; Bezier has step 3, B-spline and
 * Catmull-Rom 1). A non-periodic cubic curve has (n - 4) / step + 1
 * segments (n - 4 a multiple of step), a periodic one n / step (n a
 * multiple of step) and wraps; a linear one n - 1, or n when periodic.
 *
 * Primitive variables: "width" (1 float, object units, the diameter;
 * default 1), "N" (3 floats: the curves become ribbons facing N, which
 * should be across the curve), "Cs", "Os", "st". Classes: constant, uniform
 * (one per curve), varying (one per segment end: segments + 1 per
 * non-periodic curve, segments per periodic one; facevarying reads as
 * varying), vertex (one per control point, evaluated with the basis at
 * the segment ends). Between ends every value is linear.
 * Without N, shape says how they are traced: RAYES_CURVE_ROUND tubes or
 * RAYES_CURVE_FLAT ribbons that face each ray. They are diced into grids
 * one micropolygon wide (cached like any surface) facing the camera. */
typedef enum RayesCurveShape { RAYES_CURVE_ROUND = 0, RAYES_CURVE_FLAT = 1 } RayesCurveShape;

typedef struct RayesCurves {
    int degree;              /* 1 or 3 */
    float basis[16];         /* degree 3: row-major basis matrix (RiBezierBasis, ...) */
    int step;                /* degree 3: 1 to 4 */
    int periodic;            /* 1: every curve wraps */
    RayesCurveShape shape;   /* without N */
    size_t n_curves;
    const int *n_verts;      /* control points per curve */
    const float *P;          /* 3 floats per control point */
} RayesCurves;

/* RenderMan's cubic bases, row-major, for RayesCurves.basis. */
RAYES_API extern const float rayes_basis_bezier[16];
RAYES_API extern const float rayes_basis_bspline[16];
RAYES_API extern const float rayes_basis_catmull_rom[16];

RAYES_API RayesError rayes_scene_curves(RayesScene *scene, const RayesCurves *curves,
                                        const RayesPrimvar *pv, size_t n_pv);

/* The counts primitive variables of curves must have: control points
 * (vertex) and segment ends (varying). Returns 0; -1 - k when curve k's
 * count makes no whole segments; or LONG_MIN for a bad degree or step, or
 * missing arrays. */
RAYES_API long rayes_curves_counts(const RayesCurves *curves, size_t *n_points, size_t *n_varying);

/* Points (RenderMan's Points): n_points spheres or disks facing each ray
 * (shape), or with "N" disks facing N, centred at P. Primitive
 * variables: "width" (the diameter, object units; constant, or varying or
 * vertex: one per point; default 1), "N", "Cs", "Os", "st" (constant, uniform:
 * 1, varying or vertex: one per point). Each point is one grid. */
typedef enum RayesPointShape { RAYES_POINT_SPHERE = 0, RAYES_POINT_DISK = 1 } RayesPointShape;

RAYES_API RayesError rayes_scene_points(RayesScene *scene, RayesPointShape shape,
                                        size_t n_points, const float *P, const RayesPrimvar *pv,
                                        size_t n_pv);

/* Blobby implicit surfaces (RenderMan's RiBlobby): primitive fields
 * combined by a small program; the surface is where the field reaches
 * 0.421875 (a lone blob's surface at half its unit sphere), made polygons
 * with normals from the field (docs/scenes.md "Blobby"). code, floats and
 * strings are RiBlobby's arrays: opcodes 1000 constant (1 float), 1001
 * ellipsoid (16 floats: the matrix from its unit sphere to object space,
 * row vectors as RIB writes it; its field (1 - r^2)^3), 1002 segment (two
 * ends, a radius and such a matrix: 23 floats; the ellipsoid's field
 * convolved along it, so that segments end to end make one tube), 1003
 * repelling plane, 1004 field plugin and 9000 (AIR's plugin blob: a
 * count, then operands) (read, and taken as 0); 0 add, 1 multiply, 2 maximum, 3 minimum (a count, then
 * that many operands), 4 subtract, 5 divide (two operands: first minus, or
 * over, second), 6 negate, 7 identity (one); an operand is the index of an
 * earlier instruction, and the last instruction is the field. n_leaf
 * counts the primitive fields (opcodes 1000 and more) as RiBlobby's nleaf.
 * Primitive variables "Cs", "Os" and "st": constant or uniform (1 value),
 * or varying or vertex (n_leaf values, one per primitive field in code
 * order), blended at each point by the fields' values there. A bad program
 * is RAYES_ERROR_INVALID_ARGUMENT naming the instruction. */
typedef struct RayesBlobby {
    size_t n_leaf;   /* primitive fields, for vertex values */
    const int *code; /* n_code opcodes and operands */
    size_t n_code;
    const float *floats; /* n_floats values the operands index */
    size_t n_floats;
    const char *const *strings; /* n_strings names the operands may index (depth maps
                                   and plugins; unused in rendering, kept by the RIB
                                   writer) */
    size_t n_strings;
} RayesBlobby;

RAYES_API RayesError rayes_scene_blobby(RayesScene *scene, const RayesBlobby *blobby,
                                        const RayesPrimvar *pv, size_t n_pv);

/* Constructive solid geometry (RenderMan's SolidBegin/SolidEnd): blocks
 * nest into a tree of solids. The primitives given inside a primitive
 * solid's block are its closed surface, its inside behind their fronts
 * (counter-clockwise seen from outside; quadrics unless reversed); union,
 * intersection and difference (the first child less the others) combine
 * the solids given in their blocks. A ray sees a surface of a solid where
 * it bounds its tree's result: a difference's holes are open, their walls
 * the subtracted solids' surfaces. Geometry in a boolean block but no
 * primitive one, and solids in object definitions, are drawn as they are
 * (one warning). A primitive solid inside a primitive solid, or an end
 * without a begin, is RAYES_ERROR_INVALID_ARGUMENT; blocks left open end
 * with the scene. */
typedef enum RayesSolidOp {
    RAYES_SOLID_PRIMITIVE = 0,
    RAYES_SOLID_UNION = 1,
    RAYES_SOLID_INTERSECTION = 2,
    RAYES_SOLID_DIFFERENCE = 3
} RayesSolidOp;

RAYES_API RayesError rayes_scene_solid_begin(RayesScene *scene, RayesSolidOp op);
RAYES_API RayesError rayes_scene_solid_end(RayesScene *scene);

/* A sphere of the given radius centred at the object-space origin. */
RAYES_API RayesError rayes_scene_sphere(RayesScene *scene, float radius);

/* RenderMan's quadrics, in object space (the current transform places
 * them), swept about the z axis through thetamax degrees (0 < |thetamax|
 * <= 360); parameters in RenderMan's order:
 *   SPHERE       radius zmin zmax thetamax
 *   CYLINDER     radius zmin zmax thetamax
 *   CONE         height radius thetamax           (apex at z = height)
 *   DISK         height radius thetamax           (in the plane z = height)
 *   PARABOLOID   rmax zmin zmax thetamax          (r = rmax sqrt(z / zmax))
 *   HYPERBOLOID  x1 y1 z1 x2 y2 z2 thetamax       (the line p1 p2 swept)
 *   TORUS        rmajor rminor phimin phimax thetamax
 * Normals point away from the z axis (up for the disk), or the other way
 * when flags has RAYES_QUADRIC_REVERSE (RenderMan's ReverseOrientation,
 * or a left-handed current transform). A wrong count or a degenerate
 * shape is RAYES_ERROR_INVALID_ARGUMENT. */
typedef enum RayesQuadric {
    RAYES_QUADRIC_SPHERE = 0,
    RAYES_QUADRIC_CYLINDER = 1,
    RAYES_QUADRIC_CONE = 2,
    RAYES_QUADRIC_DISK = 3,
    RAYES_QUADRIC_PARABOLOID = 4,
    RAYES_QUADRIC_HYPERBOLOID = 5,
    RAYES_QUADRIC_TORUS = 6
} RayesQuadric;

#define RAYES_QUADRIC_REVERSE 1u

RAYES_API RayesError rayes_scene_quadric(RayesScene *scene, RayesQuadric type,
                                         const float *params, size_t n_params, unsigned flags);

/* An emitting quadric (an area light): the quadric as rayes_scene_quadric
 * makes it, emitting radiance L from its front (the side its normal
 * points to, as above) or from both sides if two_sided. It is made a mesh
 * light (rayes_scene_area_light_mesh) of its surface cut in steps of
 * about 5.6 degrees around z and along curved profiles, which camera rays
 * see. */
RAYES_API RayesError rayes_scene_area_light_quadric(RayesScene *scene, RayesQuadric type,
                                                    const float *params, size_t n_params,
                                                    unsigned flags, const float L[3],
                                                    int two_sided);

/* A volume (memo 6.1): the box bound = xmin, xmax, ymin, ymax, zmin, zmax
 * of object space (RenderMan's Volume "box"), filled by a medium that the
 * current shader describes: its opacity method returns the extinction
 * coefficient per unit length (RGB; the memo's convention) and its
 * lighting method the light the medium scatters and emits toward I per
 * unit length (the built-in volume shaders: docs/shaders.md). With no
 * shader set, "homogeneous". Volumes are ray marched (RayesRenderOptions'
 * volume_step); camera and specular rays see their single scattering,
 * shadow rays their extinction. */
RAYES_API RayesError rayes_scene_volume(RayesScene *scene, const float bound[6]);

/* The same medium, only inside the closed surface of the geometry added
 * last (its object): a ray's segment counts only where the ray leaves
 * that surface through its back, as after entering it (glass holding a
 * coloured liquid); shadow rays cross it only where the surface lets them
 * through (a glass's thin shadow, tinted by the liquid). Geometry seen by
 * no ray (rayes_scene_set_visibility(scene, 0): how the pbrt reader sends
 * the shapes a MediumInterface names a medium on, docs/pbrt.md) only
 * bounds the medium: every ray, shadow rays too, is in it between its
 * crossings of that surface, entering it against the surface's normals.
 * The box still bounds the march.
 * INVALID_ARGUMENT without geometry before it. */
RAYES_API RayesError rayes_scene_volume_inside(RayesScene *scene, const float bound[6]);

/* An atmosphere (RenderMan's Atmosphere): a volume of the current shader,
 * as rayes_scene_volume's, filling the space between the eye and the
 * surfaces camera rays meet. Camera rays see it in front of what they hit,
 * and not at all where they meet nothing (the background stays as it is);
 * shadow, diffuse and specular rays cross it untouched (RenderMan applies
 * an atmosphere to the light reaching the eye alone). Its box is the
 * scene's bounds and the eye, found when the scene is rendered. A scene
 * has at most one: a second replaces the first. */
RAYES_API RayesError rayes_scene_atmosphere(RayesScene *scene);

/* A one-sided emitting quad (an area light) with vertices P[0..3] in order
 * around the quad; it emits radiance L from the side toward which
 * (P1 - P0) x (P2 - P0) points, and is seen by the camera. */
RAYES_API RayesError rayes_scene_area_light(RayesScene *scene, const float P[4][3],
                                            const float L[3]);

/* An emitting polygon mesh (an area light of any shape): n_faces faces,
 * face f of n_verts[f] >= 3 vertices (convex, counter-clockwise seen from
 * the front; fanned into triangles), indices into P (n_points points),
 * radiance L from each face's front, or from both sides if two_sided. One
 * light however many faces: its shadow rays draw points over the whole
 * mesh (by area within clusters of faces, each weighed from the lit
 * point). Seen by camera and specular rays; it does not move within
 * the frame (under a moving transform it stays where the shutter opens,
 * with one warning). */
RAYES_API RayesError rayes_scene_area_light_mesh(RayesScene *scene, size_t n_faces,
                                                 const int *n_verts, const int *indices,
                                                 size_t n_points, const float *P, const float L[3],
                                                 int two_sided);

/* rayes_scene_area_light_mesh with an emission texture (a sign, a screen, a
 * stained window): the radiance at a point is L times the image's colour at
 * its (s, t), interpolated over each face from st (2 floats a point; (0, 0)
 * is the image's top left, clamped at its edges as pbrt-v4 reads it),
 * bilinear on the image's full resolution. Seen so by camera and specular
 * rays and by the shadow rays that reach it; shadow rays draw its points by
 * area, not by the image's brightness. texture names an image any format
 * OpenImageIO reads (integer files are sRGB and come back linear), found as
 * shaders' textures are (as given, then on the texture search path) and
 * read whole when the light is made (halved until at most 2048 texels a
 * side); one that cannot be read is said once (a warning) and the light
 * emits L alone, as a surface's missing texture is left out. */
RAYES_API RayesError rayes_scene_area_light_mesh_textured(RayesScene *scene, size_t n_faces,
                                                          const int *n_verts, const int *indices,
                                                          size_t n_points, const float *P,
                                                          const float *st, const float L[3],
                                                          int two_sided, const char *texture);

/* A light source of the given type, with parameters (unknown names get
 * one warning; a wrong type is RAYES_ERROR_INVALID_ARGUMENT). Points and
 * directions are 3-vectors given as RAYES_PARAM_COLOR and transform by the
 * current transform. Every light takes "intensity" (FLOAT, default 1),
 * "lightcolor" (COLOR, default 1 1 1) and "__category" (STRING, a
 * comma-separated list the direct-lighting service's category argument
 * selects on). Types, RenderMan's semantics (angles in degrees):
 *   "pointlight"       "from" (default 0 0 0): irradiance intensity / d^2
 *                      at normal incidence, times the map "mapname" (if
 *                      given) in the direction from the light, in the
 *                      current rotation: "mapping" "latlong",
 *                      "latlong-zup" or "octahedral" as an environment's,
 *                      or "projection"
 *                      (the image projected along +z over "fov", 90,
 *                      degrees on its shorter side; black elsewhere);
 *                      spotlights take a map too
 *   "spotlight"        "from" (0 0 0), "to" (0 0 1), "coneangle" (30),
 *                      "conedeltaangle" (5), "beamdistribution" (2): a
 *                      point light times smoothstep(cos(cone), cos(cone -
 *                      delta), cos a) * cos(a)^beamdistribution, a the angle
 *                      from the axis
 *   "distantlight"     "from" (0 0 0), "to" (0 0 1): irradiance intensity
 *                      along to - from
 *   "ambientlight"     adds intensity * lightcolor to the ambient service
 *   "environmentlight" radiance intensity * lightcolor, times the
 *                      latitude-longitude map "mapname" (any format
 *                      OpenImageIO reads; as given, else on the texture
 *                      search path) if given, seen by camera and specular rays that miss
 *                      everything (docs/DESIGN.md: orientation); "mapping"
 *                      "latlong" (+y up), "latlong-zup" (pbrt-v3's, +z up)
 *                      or "octahedral" (pbrt-v4's), resampled when loaded
 *   "arealight"        radiance intensity * lightcolor from a "shape"
 *                      (default "quad"): "quad" the square of side
 *                      "width" x "height" (1 x 1) about the object-space
 *                      origin in z = 0, "disk" of "radius" (1) at the
 *                      origin in z = 0, both emitting toward +z, or
 *                      "sphere" of "radius" (1) emitting outward; seen by
 *                      camera and specular rays
 *   "uberlight"        Barzel's light (RenderMan's uberlight) at the origin
 *                      of the current transform, aiming along +z: its
 *                      intensity is shaped, not physical (no distance
 *                      falloff by default): "lighttype" "spot" (default)
 *                      or "omni", "cuton" (0.01), "cutoff" (1e6),
 *                      "nearedge", "faredge" (0), "falloff" (0),
 *                      "falloffdist" (1), "maxintensity" (1),
 *                      "parallelrays" (0), "shearx", "sheary" (0), "width",
 *                      "height" (1), "wedge", "hedge" (0.1), "roundness"
 *                      (1), "beamdistribution" (0), "slidename" (an image),
 *                      "noiseamp" (0), "noisefreq" (4), "noiseoffset",
 *                      "shadowcolor" (0 0 0), "shadowcheat" (a light-space
 *                      vector), "blockermatrix" (FLOATS, 16: the blocker's
 *                      space to world, as rayes_scene_set_transform's) with
 *                      "blockerwidth", "blockerheight" (1), "blockerwedge",
 *                      "blockerhedge" (0.1), "blockerround" (1)
 *                      (docs/DESIGN.md "Lights")
 * Every light but ambient and environment lights also takes "shadows"
 * (FLOAT, default 1; 0: nothing shadows it), "__nondiffuse" and
 * "__nonspecular" (FLOAT, default 0; 1: it adds nothing to direct
 * lighting's diffuse, or specular, output).
 * An unknown type is RAYES_ERROR_INVALID_ARGUMENT; an unreadable map or
 * slide is RAYES_ERROR_IO. */
RAYES_API RayesError rayes_scene_light(RayesScene *scene, const char *type,
                                       const RayesParam *params, size_t n_params);

/* Light linking: which lights illuminate the objects made from now on
 * (by rayes_scene_set_shader, or the default matte of geometry added
 * before any shader), as RenderMan's Illuminate does for the geometry
 * that follows it. lights are light indices as rayes_scene_light_count
 * numbers them (from 0, in creation order, rayes_scene_light and
 * rayes_scene_area_light alike), and may name lights made later, so a
 * reader can link geometry to lights it sends afterwards; an index the
 * scene has no light for at rayes_scene_commit is then
 * RAYES_ERROR_INVALID_ARGUMENT. Direct lighting and the ambient service
 * skip, for each shaded object, the lights not linked to it. Objects keep
 * the links in force when they were made; an emitter's links do not
 * matter (emitters are not shaded). The list is copied; lights may be
 * NULL when n_lights is 0. */
typedef enum RayesLightLinks {
    RAYES_LIGHT_LINKS_ALL = 0,    /* every light (the default); the list is ignored */
    RAYES_LIGHT_LINKS_ONLY = 1,   /* only the listed lights */
    RAYES_LIGHT_LINKS_EXCEPT = 2  /* every light but the listed ones */
} RayesLightLinks;

RAYES_API RayesError rayes_scene_set_light_links(RayesScene *scene, RayesLightLinks mode,
                                                 const size_t *lights, size_t n_lights);

/* Object instancing (RenderMan's ObjectBegin, ObjectEnd, ObjectInstance;
 * pbrt-v4's ObjectBegin, ObjectEnd, ObjectInstance; memo 3.1). Between
 * rayes_scene_object_begin and rayes_scene_object_end, geometry goes into
 * a master named name instead of the world, in the master's own space
 * (the current transform inside the block is master_from_object, still
 * until a motion inside; the one before the block, moving or not, is
 * restored by object_end, as are the shader, the
 * displacement, the shading rate, the visibility and the light links).
 * Geometry of the block made before any rayes_scene_set_shader inside it
 * takes, per instance, the object (shader, colour, opacity, visibility,
 * light links) current at rayes_scene_object_instance; geometry after a
 * set_shader inside the block keeps that shader in every instance.
 * rayes_scene_object_instance places the master defined last under that
 * name with the current transform (world_from_master; a moving one,
 * rayes_scene_set_transform_motion, moves the instance): one diced master
 * is shared by all its instances (Embree instances; its grids are counted
 * once), each instance has its own radiosity and opacity cache entries.
 * Inside a block it nests the named master in the one being defined
 * (flattened at render time into instances of the inner master). Lights
 * and volumes inside a block are RAYES_ERROR_INVALID_ARGUMENT, as are
 * a begin inside a block, an end without a begin, and an unknown name. A
 * name defined again replaces the master for instances made afterwards. */
RAYES_API RayesError rayes_scene_object_begin(RayesScene *scene, const char *name);
RAYES_API RayesError rayes_scene_object_end(RayesScene *scene);
RAYES_API RayesError rayes_scene_object_instance(RayesScene *scene, const char *name);
/* The rayes_scene_object_instance calls made so far (one nested in a
 * block counts once, however often the block is placed). */
RAYES_API size_t rayes_scene_instance_count(const RayesScene *scene);

/* ---------------------------------------------------------------- edits
 *
 * Changes to a scene that has been rendered, for interactive preview (a
 * progressive session, below, keeps what an edit leaves valid). Lights are
 * numbered from 0 in the order they were made (rayes_scene_light and
 * rayes_scene_area_light); objects likewise: every rayes_scene_set_shader
 * makes one, and so does every light with a shape (its emitter). Edit only
 * while no render or pass of the scene runs, then commit. */

RAYES_API size_t rayes_scene_light_count(const RayesScene *scene);
RAYES_API size_t rayes_scene_object_count(const RayesScene *scene);
/* The surface shader class of an object ("" for a light's emitter or an
 * index out of range); static or scene storage. */
RAYES_API const char *rayes_scene_object_shader(const RayesScene *scene, size_t object);
/* The light an object emits as, or -1. */
RAYES_API int64_t rayes_scene_object_light(const RayesScene *scene, size_t object);

/* Changes a light: "intensity" (FLOAT >= 0) and "lightcolor" (COLOR, or a
 * FLOAT grey, >= 0) replace the values it was made with (a light made by
 * rayes_scene_area_light has intensity 1 and lightcolor L); "translate"
 * (COLOR, a world-space vector) moves it and its shape (not distant,
 * ambient or environment lights, for which it does nothing). Any other
 * parameter is RAYES_ERROR_INVALID_ARGUMENT, and nothing changes. */
RAYES_API RayesError rayes_scene_edit_light(RayesScene *scene, size_t light,
                                            const RayesParam *params, size_t n_params);

/* A light's intensity and lightcolor (as rayes_scene_edit_light sets them)
 * and its position (point, spot; the centre of an area light's shape;
 * zero for the others); any output may be NULL. */
RAYES_API RayesError rayes_scene_get_light(const RayesScene *scene, size_t light,
                                           float *intensity, float color[3], float position[3]);

/* Changes parameters of an object's surface shader (and its "Cs" and
 * "Os"), as rayes_scene_set_shader takes them; the others keep their
 * values. A name the shader lacks, or a wrong type, is
 * RAYES_ERROR_INVALID_ARGUMENT, and nothing changes. */
RAYES_API RayesError rayes_scene_edit_shader(RayesScene *scene, size_t object,
                                             const RayesParam *params, size_t n_params);

/* Where the camera is: the eye and camera space's axes x (right), y (up)
 * and z (the view direction), in world space, each of the length of a unit
 * of camera space. */
RAYES_API RayesError rayes_scene_get_camera(const RayesScene *scene, float eye[3], float x[3],
                                            float y[3], float z[3]);

/* Moves the camera by a world-space motion m (row-major; rigid, possibly
 * with a uniform scale): eye' = m eye, axes' = m axes. The projection, the
 * field of view and the screen window stay. */
RAYES_API RayesError rayes_scene_move_camera(RayesScene *scene, const float m[16]);

/* Ends an edit: checks the scene and bumps its timestamp. Rendering an
 * uncommitted scene is RAYES_ERROR_INVALID_OPERATION. */
RAYES_API RayesError rayes_scene_commit(RayesScene *scene);

/* The number of commits so far (the scene timestamp of memo section 3.2). */
RAYES_API uint64_t rayes_scene_get_timestamp(const RayesScene *scene);

/* -------------------------------------------------------------- options */

typedef enum RayesQuality {
    RAYES_QUALITY_PREVIEW = 0,   /* 4 shadow rays, 4 diffuse rays */
    RAYES_QUALITY_FINAL = 1,     /* 64 shadow; 1024 diffuse at depth 0, 64 deeper */
    RAYES_QUALITY_REFERENCE = 2  /* uncached; 64-1024 adaptive pixel samples, each 16 shadow
                                    and 256 diffuse at depth 0, 1 and 1 deeper */
} RayesQuality;

/* Pixel filters, all separable (the product of one in x and one in y) and
 * zero beyond half the width. Mitchell-Netravali, Catmull-Rom and Lanczos
 * have negative lobes: EXR pixels may ring below zero at sharp edges. */
typedef enum RayesFilter {
    RAYES_FILTER_BOX = 0,         /* width 1 pixel by default */
    RAYES_FILTER_GAUSSIAN = 1,    /* width 2 pixels by default, alpha 2 */
    RAYES_FILTER_TRIANGLE = 2,    /* a tent, 1 - |x| / r */
    RAYES_FILTER_CATMULL_ROM = 3, /* the cubic B = 0, C = 1/2 over the width */
    RAYES_FILTER_MITCHELL = 4,    /* Mitchell-Netravali, B = C = 1/3 */
    RAYES_FILTER_LANCZOS = 5      /* sinc(x) sinc(x / 3), x in pixels (pbrt's sinc) */
} RayesFilter;

/* How camera rays are shaded at diffuse depth 0. */
typedef enum RayesHider {
    RAYES_HIDER_RAYTRACE = 0, /* lighting() at every camera ray hit */
    RAYES_HIDER_GRID = 1      /* lighting() once per vertex of every visible grid; camera
                                 hits interpolate the shaded grid (PRMan's REYES mode) */
} RayesHider;

/* How indirect diffuse light is computed (DESIGN.md "Point-based global
 * illumination"). */
typedef enum RayesGi {
    RAYES_GI_RAYTRACE = 0,   /* diffuse rays, their hits read the radiosity cache (default) */
    RAYES_GI_POINTBASED = 1  /* point-based GI (Christensen 2008): a point cloud of every
                                grid's direct radiosity, bounces on it, and gathers from an
                                octree of its disks at shading points */
} RayesGi;

/* A finished tile: the pixels [x, x + w) x [y, y + h) of rgba, whose rows
 * are stride pixels apart (4 floats a pixel, linear, top row first). Called
 * from worker threads, for different tiles at once; valid during the call. */
typedef void (*RayesTileFn)(void *user, int x, int y, int w, int h, const float *rgba,
                            int stride);

/* A finished tile's AOVs (RayesRenderOptions.aovs): the pixels [x, x + w)
 * x [y, y + h) of aov, channels floats a pixel (rayes_aov_channels, in
 * rayes_aov_channel_name's order), rows stride pixels apart. Called just
 * before the tile's RayesTileFn, on the same thread; valid during the
 * call. */
typedef void (*RayesTileAovFn)(void *user, int x, int y, int w, int h, const float *aov,
                               int channels, int stride);

/* Which tile a render thread takes next: an index into the frame's tiles
 * (tiles_x * tiles_y of tile_size pixels over the crop window, row by
 * row), or -1 when no tile is left for this render. Called from worker
 * threads, one call at a time. A pixel is the same whichever tiles are
 * rendered and in what order, so a render of some tiles (a resumed
 * checkpoint, one machine's share of a frame) gives them the bytes of the
 * whole render. */
typedef int (*RayesTileSourceFn)(void *user, int tiles_x, int tiles_y);

/* Progress: fraction done in [0, 1]. Return nonzero to cancel the render.
 * Called from worker threads, one call at a time. */
typedef int (*RayesProgressFn)(void *user, double fraction);

typedef struct RayesRenderOptions {
    size_t struct_size;        /* sizeof(RayesRenderOptions), set by _init */
    int width, height;         /* pixels */
    int spp;                   /* pixel samples */
    int threads;               /* 0: one per core */
    int bounces;               /* maximum diffuse depth */
    int shadow_rays;           /* shadow rays per shading point at depth 0 */
    int shadow_rays_deep;      /* shadow rays per shading point deeper */
    int diffuse_rays;          /* diffuse rays per shading point at depth 0 */
    int diffuse_rays_deep;     /* diffuse rays per shading point deeper */
    int specular_depth;        /* maximum specular depth */
    RayesFilter filter;
    float filter_width;        /* pixels */
    uint64_t seed;             /* changes every random number */
    int tile_size;             /* pixels */
    int cache;                 /* 1: the radiosity cache at diffuse hits (default); 0: off */
    double cache_mb;           /* cache budget in megabytes (10^6 bytes), default 100; 0 turns
                                  the radiosity cache off (as cache 0) */
    float cache_split[3];      /* budget shares of coarse, medium, fine (default .25 .25 .5) */
    int cache_resolution;      /* -1: chosen by ray differentials (default); 0, 1, 2: always
                                  coarse, medium, fine */
    float cache_k;             /* the coarsest resolution whose micropolygon edge is below
                                  cache_k times the ray footprint is used (default 1) */
    RayesProgressFn progress;  /* may be NULL */
    void *progress_user;
    RayesHider hider;          /* how camera rays are shaded (default RAYES_HIDER_RAYTRACE;
                                  RAYES_HIDER_GRID for the final preset) */
    int irradiance;            /* 1: irradiance interpolation with gradients at depth 0 over
                                  each shaded grid (grid hider only; on for the final preset) */
    double texture_mb;         /* texture cache budget in megabytes (10^6 bytes), default 64 */
    float texture_width;       /* multiplies every texture filter width (RenderMan's "width"):
                                  default 1; 0 point-samples the finest MIP level */
    RayesTileFn tile_done;     /* may be NULL: called as each tile of a render or pass ends */
    void *tile_user;
    int grid_size;           /* micropolygons per grid, at most (RenderMan's "gridsize"):
                                1 to 4096, default 256; smaller grids mean more, smaller
                                radiosity cache entries */
    int branch_depth;        /* shading points whose diffuse plus specular depth is below
                                this branch: several glossy rays, reflection and refraction
                                both; deeper ones follow one lobe, chosen at random, and end
                                by Russian roulette; an uncached diffuse hit at a diffuse
                                depth of at least this traces one diffuse ray (cache fills
                                keep diffuse_rays_deep). Default 1: camera hits only; 1 to
                                129 */
    float dice_offscreen;    /* micropolygons of patches off screen are this much longer
                                (from 1 at the frame's edge to this half a frame beyond it;
                                Cycles' "offscreen dicing scale"): 1 to 1000, default 4 */
    int dice_isotropic;      /* 1: patches on screen are diced by their distance from the eye
                                like those off screen, the same along the view as across it
                                (RenderMan's "rasterorient" 0); 0 (default): by their
                                projected size, coarser along the view where foreshortened */
    double vertex_budget;    /* grid vertices of the whole scene, at most: a scene needing
                                more is diced coarser, with one warning. Default 2e7 (about
                                1.2 to 4.4 GB of grids and ray tracing data); 0: none */
    float crop[4];           /* the crop window (RenderMan's CropWindow): xmin, xmax, ymin,
                                ymax in [0, 1] of the image, y down; pixels from ceil(W xmin)
                                to ceil(W xmax) - 1 (and alike in y) are rendered, each the
                                same bit for bit as in the whole frame, the rest are 0.
                                Default 0 1 0 1 */
    int opacity_cache;       /* 1 (default): opacity() results are cached per grid at the
                                three resolutions, data type opacity (memo 6.1); 0: shadow
                                and transmission rays run the shader at every hit */
    double opacity_cache_mb; /* the opacity entries' budget in megabytes (10^6 bytes;
                                RenderMan's "opacitycachememory"), default 20, apart from
                                cache_mb; 0 turns the opacity cache off */
    float volume_step;         /* volumes are ray marched in steps of this many fine voxels
                                  (a voxel projects to about a pixel at the volume's nearest
                                  point, times the square root of its shading rate): default
                                  1; larger is faster and coarser */
    RayesTileSourceFn tile_source; /* may be NULL (every tile, in order): the tiles to render;
                                      the others stay 0 in the image */
    void *tile_source_user;
    int subsurface_rays;       /* subsurface rays per shading point of a subsurface material
                                  (memo 6.2): 4 in the preview preset, 64 in final and
                                  reference */
    int irradiance_cache;      /* 1 (default): the irradiance subsurface rays find is cached
                                  per grid at the three resolutions, data type irradiance
                                  (memo 6.2); 0: the shader runs at every subsurface hit */
    double irradiance_cache_mb; /* the irradiance entries' budget in megabytes (10^6 bytes),
                                  default 20, apart from cache_mb; 0 turns it off */
    int irradiance_shadow_rays; /* shadow rays per light at each point of an irradiance
                                   cache fill, where the shader asks for the default: a
                                   cached value is shared by every subsurface ray near it,
                                   which average it, so it needs no more than a camera hit's
                                   shadow_rays, nor 64 in final (measured: 16 is as close).
                                   0 (default): shadow_rays, at most 16 (4 in preview) */
    int max_spp;                /* adaptive pixel sampling: with max_spp > spp a pixel takes
                                   further blocks of spp samples while the standard error of
                                   its mean luminance exceeds adaptive_error times the lesser
                                   of its mean and the frame's, its variance taken at least
                                   its 3 x 3 neighbourhood's first blocks' (relative), up to
                                   max_spp samples; its positions are one stratified (0, 2)
                                   sequence over all its blocks. Its count depends on fixed
                                   pixels' samples only, so images stay deterministic.
                                   0 (default): spp everywhere */
    float adaptive_error;       /* the relative standard error at which a pixel stops
                                   (default 0.02) */
    float sample_clamp;         /* each camera sample's radiance scaled down so that no
                                   component exceeds it (pbrt-v4's Film "maxcomponentvalue",
                                   Cycles' clamp): fewer fireflies, for a biased, darker
                                   image. 0 (default): off */
    int replay_rays;            /* 1: keep every ray the render traces (48 bytes each, at most
                                   2 GB; more are dropped and counted) and, once the image is
                                   made, trace them again with no shading on as many threads:
                                   what ray casting alone costs of the render (the statistics'
                                   "replay" block). The image is the same. Default 0 */
    RayesGi gi;                /* RAYES_GI_RAYTRACE (default) or RAYES_GI_POINTBASED; the
                                  progressive session renders the latter as the former */
    float pbgi_max_solid_angle; /* point-based GI: octree nodes subtending less than this
                                   (steradians) are gathered as one cluster: default 0.05,
                                   (0, 12.57] */
    int pbgi_raster;           /* point-based GI: the gather's cube raster, pixels a face
                                  side: default 8, even, 2 to 64 */
    const char *pointcloud_out; /* point-based GI: NULL, or a file the point cloud is written
                                   to (binary PLY: x y z nx ny nz area r g b, docs/cli.md) */
    const volatile int *stop;   /* may be NULL: when *stop becomes nonzero (another thread
                                   or a signal handler sets it, with an atomic store such as
                                   __atomic_store_n) rayes_render stops within a ray, even
                                   inside a tile: the tiles under way are abandoned and
                                   RAYES_ERROR_CANCELLED returned (tiles done before were
                                   passed to tile_done). Sessions ignore it: an abandoned
                                   fill would leave its cache entry wrong */
    int cache_fine_depth;       /* the deepest diffuse depth whose hits may read the fine
                                   radiosity level: deeper hits read medium at finest, the
                                   wider differentials of rays after several bounces (memo
                                   5.1). Default 1; 0 to 128 (128: the rule alone) */
    int env_guide;              /* 1 (default but in the reference preset): an environment
                                   light's samples at camera hits are drawn where the hit's
                                   grid sees the environment (a window's sky), by weights
                                   its fill traces once per grid and keeps in the cache
                                   (data type guide, 16 MB); unbiased either way, 0 draws
                                   by the map's brightness alone (DESIGN.md "Lights") */
    unsigned aovs;              /* RayesAov bits: the arbitrary output variables the image
                                   carries beside its colour (RayesImage.aov). Default 0 */
    RayesTileAovFn tile_aov_done; /* may be NULL: called with each tile's AOVs (when aovs
                                     is not 0) just before tile_done, with tile_user */
} RayesRenderOptions;

/* Fills options with the defaults of a quality preset: 512 x 512, 4 pixel
 * samples, all cores, 1 bounce, box filter, seed 0, the radiosity cache on
 * with 100 MB, a texture cache of 64 MB. The reference preset caches
 * nothing (radiosity, opacity and irradiance caches off) and takes 64
 * pixel samples of 16 shadow and 256 diffuse rays, converged in pixels as
 * well as in light. */
RAYES_API void rayes_render_options_init(RayesRenderOptions *options, RayesQuality quality);

/* ---------------------------------------------------------------- stats */

typedef struct RayesStats RayesStats;

typedef enum RayesStatKind {
    RAYES_STAT_COUNT = 0,   /* an integer count */
    RAYES_STAT_REAL = 1,    /* a real value (seconds, a ratio) */
    RAYES_STAT_STRING = 2,  /* text */
    RAYES_STAT_COUNTS = 3   /* an array of counts */
} RayesStatKind;

/* One statistic. Names are paths such as "rays/shadow" or "time/total_s";
 * the JSON statistics nest on the slashes. */
typedef struct RayesStat {
    const char *name;
    RayesStatKind kind;
    uint64_t count;          /* COUNT */
    double real;             /* REAL */
    const char *string;      /* STRING */
    const uint64_t *counts;  /* COUNTS */
    size_t n_counts;
} RayesStat;

RAYES_API size_t rayes_stats_size(const RayesStats *stats);
/* The i-th statistic, in a stable order; borrowed, valid while stats lives. */
RAYES_API const RayesStat *rayes_stats_get(const RayesStats *stats, size_t i);
/* The statistic of that name, or NULL. */
RAYES_API const RayesStat *rayes_stats_find(const RayesStats *stats, const char *name);
RAYES_API void rayes_stats_free(RayesStats *stats);

/* --------------------------------------------------------------- render */

/* Arbitrary output variables (AOVs): what the first surface each camera
 * sample meets says about itself, for compositing and for inspecting a
 * scene. Deterministic as the colour is. Samples the filter weighs
 * positively decide the "nearest" ones (and feed "cache"); N and P are
 * filtered as colour is (a pixel on an edge blends toward 0). Ids are
 * floats, exact to 2^24; outside a crop window every channel is 0.
 * rayes_render alone renders them (a session refuses them). Surfaces behind a transparent one
 * do not count; lights seen directly do (their own object). */
typedef enum RayesAov {
    RAYES_AOV_Z = 1u << 0,      /* "Z": camera-space depth of the pixel's nearest sample
                                   (distance along the view axis; orthographic too); +inf
                                   where no sample meets a surface */
    RAYES_AOV_N = 1u << 1,      /* "N.X" "N.Y" "N.Z": world-space shading normal, facing the
                                   camera */
    RAYES_AOV_P = 1u << 2,      /* "P.X" "P.Y" "P.Z": world-space position */
    RAYES_AOV_ID = 1u << 3,     /* "id": 1 + the object (shader binding) of the nearest
                                   sample, in the order the scene made them; 0: none */
    RAYES_AOV_PATCH = 1u << 4,  /* "patch": 1 + the grid (diced patch, the radiosity cache's
                                   entry; an instance's: its master's grid) of the nearest
                                   sample; 0: none */
    RAYES_AOV_CACHE = 1u << 5,  /* "cache": the radiosity cache's resolution the pixel's
                                   diffuse rays read at their first hits, by ray differentials
                                   (memo 3.2), averaged over the pixel's look-ups: 0 coarse
                                   (or a cluster of grids), 1 medium, 2 fine; -1 where no
                                   sample traced any (lights, the background, --cache off).
                                   With the grid hider, a grid's mean over the rays of its
                                   shading counts as one look-up of each sample on it */
    RAYES_AOV_ALBEDO = 1u << 6, /* "albedo.R" "albedo.G" "albedo.B": the colour the surface
                                  reflects (a denoiser's albedo feature): its shader's
                                  lighting method run again in a white furnace (radiance 1
                                  from everywhere, nothing traced), filtered as colour is; a
                                  light seen directly gives its hue (its colour over its
                                  largest component) */
    RAYES_AOV_ALL = 0x7f
} RayesAov;

#define RAYES_AOV_CHANNELS_MAX 13 /* rayes_aov_channels(RAYES_AOV_ALL) */

/* The float channels of aovs (RayesAov bits), and the name of channel c
 * ("Z", "N.X", ...; NULL when c is out of range): channels come in the
 * order of the bits. */
RAYES_API int rayes_aov_channels(unsigned aovs);
RAYES_API const char *rayes_aov_channel_name(unsigned aovs, int channel);

typedef struct RayesImage {
    int width, height;  /* pixels */
    float *rgba;        /* width * height * 4 floats, linear RGB and alpha, top row first */
    int crop[4];        /* the pixels rendered: x, y, width, height (a crop window; outside
                           it rgba is 0); width 0: all of them */
    unsigned aovs;      /* the RayesAov bits rendered (RayesRenderOptions.aovs) */
    int aov_channels;   /* rayes_aov_channels(aovs) */
    float *aov;         /* width * height * aov_channels floats, or NULL: channel c of a
                           pixel is rayes_aov_channel_name(aovs, c) */
} RayesImage;

/* Renders a committed scene. On success *image (free with
 * rayes_image_free) and, if stats is not NULL, *stats (free with
 * rayes_stats_free) are new. Thread-safe against other renders of the same
 * committed scene. */
RAYES_API RayesError rayes_render(RayesScene *scene, const RayesRenderOptions *options,
                                  RayesImage **image, RayesStats **stats);

RAYES_API void rayes_image_free(RayesImage *image);

/* -------------------------------------------------- progressive session
 *
 * A session renders a committed scene in passes of one pixel sample each,
 * accumulating, for interactive preview (rayes view). It keeps between
 * passes what rayes_render rebuilds every time: the diced grids and the
 * ray tracing structure, the radiosity cache, the texture cache and the
 * film. Pass k takes pixel sample k of patterns of options->spp samples
 * (then of further patterns), so with the box filter of width 1 the image
 * after options->spp passes equals rayes_render's with options->spp
 * samples, bit for bit.
 *
 * Edits: change the scene (edits above, or any other call) while no pass
 * runs, commit, then rayes_session_update. A camera-only edit keeps the
 * grids (diced for the camera the session was prepared with) and every
 * cached radiosity entry, which does not depend on the view; light and
 * shader edits keep the grids but bump the cache's timestamp, so entries
 * filled before are never used again (they age out by LRU); anything else
 * prepares the scene again, for its current camera. Either way the
 * accumulation restarts.
 *
 * Threads: one thread drives a session; rayes_session_cancel may be called
 * from any thread. The session holds a reference to its scene. */

typedef struct RayesSession RayesSession;

/* A session on a committed scene, prepared at once. options is copied
 * (progress, if set, reports each pass's fraction). */
RAYES_API RayesError rayes_session_new(RayesScene *scene, const RayesRenderOptions *options,
                                       RayesSession **session);
/* Frees a session; no pass may be running. NULL is ignored. */
RAYES_API void rayes_session_free(RayesSession *session);

/* Takes the scene's committed edits (see above) and restarts the
 * accumulation. RAYES_ERROR_INVALID_OPERATION if the scene is uncommitted. */
RAYES_API RayesError rayes_session_update(RayesSession *session);

/* Renders one pass (one more sample in every pixel), calling
 * options->tile_done as tiles finish. RAYES_ERROR_CANCELLED if cancelled:
 * the accumulation is then discarded, and the next pass starts over. */
RAYES_API RayesError rayes_session_render_pass(RayesSession *session);

/* Makes the running pass, or the next one if none runs, stop as soon as
 * its running tiles finish and return RAYES_ERROR_CANCELLED. Thread-safe. */
RAYES_API void rayes_session_cancel(RayesSession *session);

/* Pixel samples accumulated since the last restart. */
RAYES_API int rayes_session_samples(const RayesSession *session);

/* A copy of the accumulated image (free with rayes_image_free). Between
 * passes only. */
RAYES_API RayesError rayes_session_image(const RayesSession *session, RayesImage **image);

/* The statistics of the last finished pass (rays, shading points, times,
 * the cache's lookups and hit rates in that pass) plus "session/samples"
 * and "session/prepare_s" (the last update's preparation time). */
RAYES_API RayesError rayes_session_stats(const RayesSession *session, RayesStats **stats);

/* The object seen through image position (x, y) (pixels, top left origin),
 * or -1 for none, in *object; and, if position is not NULL and something
 * is seen, the world-space point seen. */
RAYES_API RayesError rayes_session_pick(const RayesSession *session, float x, float y,
                                        int64_t *object, float position[3]);

#ifdef __cplusplus
}
#endif

#endif /* RAYES_RAYES_H */
