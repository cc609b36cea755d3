/*
 * scene/scene.h — the state machine behind rayes.h's scene calls, and
 * prepare: a committed scene diced into a GridSet for rendering.
 *
 * Every set_shader call makes a new object (a shader instance, colour,
 * opacity, ray visibility); geometry added afterwards belongs to it. Area
 * lights make their own objects. Primitives are stored in world space.
 *
 * Thread-safety: one editing thread at a time (rayes.h); prepare reads a
 * committed scene and may run concurrently with other prepares.
 */
#ifndef RAYES_SCENE_SCENE_H
#define RAYES_SCENE_SCENE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "geom/geom.h"
#include "shade/light.h"
#include "shade/shade.h"
#include "shade/texture.h"
#include "util/vec.h"

typedef struct SceneObject {
    ShaderInstance shader; /* owned; cls NULL for lights */
    float Cs[3], Os[3];    /* surface colour and opacity */
    int light;             /* light index, or -1 */
    uint32_t ray_mask;     /* RayesRayType bits of the rays that see it */
    uint32_t links;        /* its light links: RayesScene.links index + 1, or 0: all lights */
    const struct RayesPattern *Os_pattern; /* Os's pattern (the scene's; an "Os" parameter
                                                naming one), multiplying Os, or NULL */
    uint8_t transmission_hitmode;          /* RayesTransmissionHitMode */
    uint8_t opacity_cache;                 /* 1: its opacity may be cached */
    uint8_t Os_primvar_below_1;            /* 1: an Os primitive variable of one of its
                                              primitives is below 1 somewhere */
} SceneObject;

/* A volume (rayes_scene_volume): a box of object space under a transform,
 * filled by its object's shader. */
typedef struct SceneVolume {
    uint32_t object;
    int64_t inside; /* -1, or the object whose surfaces bound it */
    Mat4 world_from_object;
    float bound[6];           /* xmin, xmax, ymin, ymax, zmin, zmax */
    float shading_rate;
    int atmosphere; /* 1: rayes_scene_atmosphere's (bound unused: the scene's, at render) */
} SceneVolume;

/* A named pattern (rayes_scene_pattern, patterns.c). */
typedef struct ScenePattern {
    char *name;                   /* owned */
    struct RayesPattern *pattern; /* owned; lives as long as the scene */
} ScenePattern;

/* A set of light links (rayes_scene_set_light_links). */
typedef struct SceneLinks {
    int mode;                 /* RayesLightLinks: ONLY or EXCEPT */
    size_t *lights;           /* light indices, sorted, unique; owned */
    size_t n;
} SceneLinks;

/* A master (rayes_scene_object_begin ... _end): the primitives
 * [first_prim, end_prim), in master space, and the instances made inside
 * its block (SceneInstance.parent). */
typedef struct SceneMaster {
    char *name;               /* owned */
    size_t first_prim, end_prim;
    uint64_t leaves;          /* placements of masters with primitives one instance of it
                                 makes when flattened (itself if it has primitives, plus its
                                 nested instances'); caps the flattened count */
    int depth;                /* 1 + the deepest nesting of its instances' masters */
    uint8_t inherit_Os_below_1; /* 1: geometry of it (or of a master it places) that takes
                                   each instance's object carries an Os primitive variable
                                   below 1, so that object must be drawn transparent */
} SceneMaster;

/* One rayes_scene_object_instance. */
typedef struct SceneInstance {
    Mat4 parent_from_master;  /* the current transform when it was made */
    uint32_t master;          /* the master placed */
    uint32_t parent;          /* 0: the world; else the master index + 1 whose block holds it */
    uint32_t object;          /* the object its master's inheriting geometry takes, or
                                 GEOM_OBJECT_INHERIT (inside a block before any shader: the
                                 enclosing instance's) */
    uint32_t motion;          /* 0: still; else the motions index + 1 of its moving transform
                                 (parent_from_master at time k: delta[k] parent_from_master) */
} SceneInstance;

/* What rayes_scene_object_begin saves and rayes_scene_object_end restores. */
typedef struct SceneSaved {
    Mat4 world_from_object;
    int64_t current_object;
    float shading_rate, displacement_bound;
    uint32_t displacement, links, visibility;
    uint8_t hitmode, opacity_cache;
    uint32_t motion; /* current_motion (a block starts still, in master space) */
} SceneSaved;

/* Flattened instances are at most this many (nested blocks multiply), and
 * blocks nest at most SCENE_MAX_NESTING deep. */
#define SCENE_MAX_INSTANCES (1u << 24)
#define SCENE_MAX_NESTING 32

/* The kinds of rayes_scene_set_search_path, indexing RayesScene.search_paths
 * (names in scene.c's search_path_kinds). */
typedef enum SceneSearchPath {
    SCENE_SEARCH_PATH_SHADER = 0,
    SCENE_SEARCH_PATH_TEXTURE = 1,
    SCENE_SEARCH_PATH_COUNT
} SceneSearchPath;

/* The camera as set through rayes.h: camera space's origin and axes in
 * world space (x right, y up, z the view direction; of the length of a
 * camera-space unit, so a uniform scale or a mirror in camera_from_world
 * carries through). The screen window is resolved per image size. */
typedef struct SceneCamera {
    Vec3 eye;                 /* camera-space origin, world */
    Vec3 x, y, z;             /* camera-space axes, world */
    float tan_half_fov;       /* perspective: tan(fov / 2); orthographic: 0 */
    int fov_vertical;         /* rayes_scene_set_camera: the fov spans the image height */
    int has_screen;           /* screen[] given; else the default of the aspect ratio */
    float screen[4];          /* left, right, bottom, top */
    float lens_radius;        /* depth of field: the thin lens's radius, world units; 0: pinhole */
    float focal_distance;     /* the plane in focus, world units along z from the eye */
    int n_motion;             /* camera motion: time samples (0 or 1: still) */
    float motion_time[GEOM_MAX_TIMES];   /* increasing, scene time */
    Vec3 motion_eye[GEOM_MAX_TIMES];     /* eye and axes at each time */
    Vec3 motion_x[GEOM_MAX_TIMES], motion_y[GEOM_MAX_TIMES], motion_z[GEOM_MAX_TIMES];
} SceneCamera;

/* A primitive's motion (motion.c): its time samples and, for a moving
 * transform, the motion of world space from the first sample to each; for
 * deformation, its shapes at the later samples (RayesScene.motion_prims). */
typedef struct SceneMotion {
    int n_times;
    float time[GEOM_MAX_TIMES];  /* increasing, scene time */
    int deform;                  /* 1: deformation blur; 0: transform blur */
    Mat4 delta[GEOM_MAX_TIMES];  /* transform blur: world_from_object(time k) times
                                    object_from_world(time 0) */
    size_t first_prim;           /* deformation: the scene's prim of time 0 first */
    size_t n_prims;              /* deformation: prims per time sample */
    size_t first;                /* deformation: motion_prims index of time 1's first prim;
                                    time k's prim j is first + (k - 1) n_prims + j */
} SceneMotion;

/* The screen window of the camera for an image of width x height pixels. */
void scene_camera_screen(const SceneCamera *camera, int width, int height, float screen[4]);

/* What an edit changed, so that a progressive session (session/progressive.c)
 * keeps what is still valid: the camera alone keeps the diced grids and the
 * cached radiosity (view-independent); shading parameters keep the grids
 * but not the radiosity; anything else is prepared again. */
typedef enum SceneChange {
    SCENE_CHANGE_CAMERA = 1,
    SCENE_CHANGE_SHADING = 2,
    SCENE_CHANGE_GEOMETRY = 4
} SceneChange;

struct RayesScene {
    atomic_int refs;
    char error[512];          /* the first error since the last clear */
    SceneCamera camera;
    Mat4 world_from_object;   /* the current transform */
    float shading_rate;       /* the current shading rate */
    int64_t current_object;   /* object of geometry added next; -1: make a default matte */
    int64_t last_geometry_object; /* the object of the last primitive added, or -1 */
    Prim *prims;
    size_t n_prims, cap_prims;
    PrimBig **bigs;              /* blocks of SCENE_BIG_BLOCK: what prims point to (Prim.big) */
    size_t n_bigs, cap_bigs;     /* PrimBigs used, block pointers allocated */
    struct SubdivMesh **subdivs; /* subdivision meshes, owned; their patches are prims */
    size_t n_subdivs, cap_subdivs;
    float *pv;                /* primitive variable values of every prim (Prim.pv_first) */
    size_t n_pv, cap_pv;      /* floats */
    SceneObject *objects;
    size_t n_objects, cap_objects;
    Light *lights;
    size_t n_lights, cap_lights;
    SceneVolume *volumes;
    size_t n_volumes, cap_volumes;
    ShaderInstance *displacements; /* displacement shader instances, owned */
    size_t n_displacements, cap_displacements;
    uint32_t current_displacement; /* of geometry added next: index + 1, or 0 */
    float displacement_bound;      /* of geometry added next; 0: unbounded */
    SceneLinks *links;        /* light link sets, each made by a set_light_links call */
    size_t n_links, cap_links;
    uint32_t current_links;        /* of objects made next: links index + 1, or 0: all lights */
    uint32_t current_visibility;   /* of objects made next: RayesRayType bits that see them */
    uint8_t current_hitmode;       /* of objects made next: RayesTransmissionHitMode */
    uint8_t current_opacity_cache; /* of objects made next: 1, their opacity may be cached */
    uint8_t pv_Os_below_1;         /* the primitive variables being added have an Os below 1
                                      (scene_note_Os), for the object add_prim puts them in */
    uint64_t timestamp;            /* commits so far */
    int dirty;                     /* edited since the last commit */
    unsigned changes;              /* SceneChange bits since the last commit */
    uint64_t stamp_camera;         /* the last commit that changed the camera, */
    uint64_t stamp_shading;        /* lights' or shaders' parameters (not the geometry), */
    uint64_t stamp_geometry;       /* anything else (primitives, objects, lights added) */
    char *search_paths[SCENE_SEARCH_PATH_COUNT]; /* colon-separated, "&" expanded; owned; NULL:
                                                    empty */
    ScenePattern *patterns; /* in the order made; a name's latest is the one found */
    size_t n_patterns, cap_patterns;
    SceneMaster *masters;   /* in the order their blocks began; a name's latest is found */
    size_t n_masters, cap_masters;
    SceneInstance *instances; /* in the order made */
    size_t n_instances, cap_instances;
    int64_t open_master;    /* the master whose block is open, or -1 */
    GeomSolid *solids;      /* the solids' tree (rayes_scene_solid_begin), in block order */
    size_t n_solids, cap_solids;
    int64_t open_solid;     /* the innermost solid whose block is open, or -1 */
    SceneSaved saved;       /* the state before that block */
    uint64_t leaves;        /* flattened instances the world's instances make */
    /* Time (motion.c): the shutter, motions and blur attributes. */
    float shutter[2];              /* open and close, scene time (default 0 0: no blur) */
    SceneMotion *motions;
    size_t n_motions, cap_motions;
    Prim *motion_prims;            /* deformation blur: primitives of later time samples */
    size_t n_motion_prims, cap_motion_prims;
    uint32_t current_motion;       /* transform motion of geometry added next: motions index
                                      + 1, or 0 */
    int deforming;                 /* inside motion_begin: n_times of the block, else 0 */
    size_t deform_first;           /* the prim the block's first call added first */
    float deform_time[GEOM_MAX_TIMES];
    float motionfactor, focusfactor; /* dicing of blurred geometry added next (RenderMan's
                                        "dice" attributes; 0: none) */
};

/* current_object inside a block before any shader: geometry inherits. */
#define SCENE_OBJECT_INHERIT (-2)

/* Flattens the scene's instances (nested ones into their innermost
 * masters with primitives) into gs->instances, and sets gs->n_masters
 * (instances.c). Returns 0, or -1 when out of memory. */
int scene_flatten_instances(const RayesScene *scene, GridSet *gs);

/* The world bounds of every instance placed in the world (flatten.c). */
Bounds3 scene_instances_bounds(const RayesScene *scene);
/* Every master's bounds in master space (its primitives and nested
 * instances), n_masters of them (malloc'd: the caller frees), or NULL
 * when out of memory. */
Bounds3 *scene_masters_bounds(const RayesScene *scene);

/* The bounds of one primitive's control points (scene.c). */
Bounds3 scene_prim_bounds(const Prim *p);

/* Records an edit: the scene is uncommitted, and the change is stamped
 * with the next commit. */
static inline void scene_mark(RayesScene *scene, SceneChange change)
{
    scene->dirty = 1;
    scene->changes |= (unsigned)change;
}

/* How scene_prepare dices: gridsize, the off-screen factor and the vertex
 * budget (DESIGN.md "Splitting and dicing"). */
typedef struct DiceOptions {
    int grid_size;        /* micropolygons per grid, at most; 0: GEOM_GRID_SIZE */
    float offscreen;      /* >= 1: edge factor far off screen (DiceCamera.offscreen); 0: 1 */
    size_t vertex_budget; /* grid vertices, at most; 0: no budget */
    int isotropic;        /* 1: on screen by distance too (DiceCamera.isotropic) */
    double memory_limit;  /* bytes the grids of a scene over the budget may take; 0: 90% of
                             the memory the machine has beyond the process's */
    int clusters;         /* 1: tiny grids are clustered for the radiosity and irradiance
                             caches (geom_cluster_grids) */
    const volatile int *stop; /* NULL, or dicing stops between primitives once *stop is
                                 nonzero (RayesRenderOptions.stop) */
} DiceOptions;

/* Dices every primitive of a committed scene for its camera making an
 * image of width x height pixels (dice may be NULL: gridsize 256, no
 * off-screen factor, no budget), and runs displacement shaders (whose
 * texture lookups read from textures, which may be NULL). A scene that
 * would exceed the vertex budget is diced again with every micropolygon
 * edge longer by one factor, found by counting, with one warning; the
 * factor is written to *coarsened when that is not NULL (1: none). One
 * whose grids would still take more than dice->memory_limit is refused,
 * with a message in err (err_size bytes; err may be NULL). Tiny grids are
 * then clustered where dice->clusters says so.
 * Returns 0, -1 when out of memory or refused, or -2 when dice->stop
 * stopped it ("render: cancelled" in err). */
int scene_prepare(const RayesScene *scene, int width, int height, const DiceOptions *dice,
                  TextureSystem *textures, GridSet *gs, float *coarsened, char *err,
                  size_t err_size);

/* Runs the displacement shaders of the primitives of grids [first_grid,
 * n_grids) of gs (displace.c); normals come from differences over step
 * (world units). Returns 0, or -1 when out of memory. */
int scene_displace(const RayesScene *scene, GridSet *gs, size_t first_grid, float step,
                   const RayesShaderServices *sv);
/* The scene's search path of that kind: colon-separated directories, ""
 * if never set. Borrowed: valid until the next set_search_path. */
const char *scene_search_path(const RayesScene *scene, SceneSearchPath kind);

/* The latest pattern of that name, or NULL (patterns.c). */
const struct RayesPattern *scene_find_pattern(const RayesScene *scene, const char *name);

/* Binds the instance's parameters that params gives as RAYES_PARAM_PATTERN
 * to the scene's patterns of those names (patterns.c). Returns RAYES_OK, or
 * an error recorded in the scene (no such pattern or parameter). */
RayesError scene_bind_patterns(RayesScene *scene, ShaderInstance *inst, const RayesParam *params,
                               size_t n_params);
/* The file a texture name given to the scene stands for (an environment
 * map's): as given if readable or absolute, else the first readable one in
 * the scene's texture search path, then $RAYES_TEXTURE_PATH, else as given
 * (whose reading then fails with its name). Returns 0, or -1 if too long. */
int scene_find_texture(const RayesScene *scene, const char *name, char *out, size_t size);
/* Frees the scene's patterns (when the scene is freed). */
void scene_patterns_free(RayesScene *scene);

/* Whether light `light` illuminates object `object` (its light links);
 * 1 or 0. */
int scene_object_lit_by(const RayesScene *scene, size_t object, size_t light);

/* The GridSet's time samples (motion.c): uniformly spaced from the
 * earliest to the latest time of any primitive's or instance's motion, as
 * many as the finest spacing asks (at most GEOM_MAX_TIMES); the count (1:
 * nothing moves) and, in span, the first and last. */
int scene_time_samples(const RayesScene *s, float span[2]);

/* Instance si's parent_from_master at time t: its motion's delta, blended
 * linearly between the motion's samples, times its transform (motion.c). */
Mat4 scene_instance_at(const RayesScene *s, const SceneInstance *si, float t);

/* Motion blur at prepare (motion.c): fills gs's time samples (GridSet.Pt
 * and the rest) for the scene's moving primitives, after dicing,
 * displacement and stitching; cams[m] is master m's dicing camera (0: the
 * world's), whose eye deforming curves and points face. Returns 0, or -1
 * when out of memory. */
int scene_motion_prepare(const RayesScene *scene, const DiceCamera *cams, GridSet *gs);

/* The factor (>= 1) by which blur lengthens the micropolygon edges of the
 * scene's primitive `index` (motionfactor and focusfactor, motion.c); cam
 * is the dicing camera. */
float scene_blur_dice_factor(const RayesScene *scene, size_t index, const DiceCamera *cam);

/* For the scene's other files (curves.c): adds a primitive to the current
 * object; records the first error (printf-style) and returns e; appends n
 * primitive variable floats (per GEOM_PV_* bit of mask, per corner, its
 * floats) as p's values. */
RayesError scene_add_prim(RayesScene *scene, Prim *p);
RayesError scene_fail(RayesScene *scene, RayesError e, const char *fmt, ...)
    __attribute__((format(printf, 3, 4))); /* valid.c */
/* 1 if the n floats at v are all finite (valid.c). */
int scene_finite(const float *v, size_t n);
/* 1 if the box b lies within SCENE_MAX_COORD of the origin on every axis
 * (valid.c; an empty box does). Farther, squared distances overflow a
 * float: a ray from such a point is not valid to Embree (a quad 1e20 wide
 * failed its assertion) and dicing what spans it does not end (1e24: out
 * of memory). */
#define SCENE_MAX_COORD 1e18f
int scene_within(Bounds3 b);
#define WITHIN_EXPECTED                                                                            \
    "%s: geometry reaches beyond 1e18 from the origin in world space (float arithmetic on rays "   \
    "and dicing fails there); expected coordinates within 1e18"
/* 1 if the row-major matrix m is affine up to a homogeneous scale: its
 * last row 0 0 0 w, w != 0 (valid.c; scene_unit_w divides w out), the
 * zeros within SCENE_AFFINE_EPS of w together: exporters write noise there
 * (Maya's MTOR, a camera's perspective row -4.8e-9 -6.8e-18 -5.0e-9 1, in
 * the RenderMan repository), which scene_unit_w drops. Geometry is transformed point by
 * point, so a projective row sends the points where it gives w = 0 through
 * infinity: rays from near them are not valid, and dicing what spans them
 * does not end. AFFINE_EXPECTED is the message, its %s the call. */
#define SCENE_AFFINE_EPS 1e-6f
int scene_affine(const float m[16]);
/* An affine m with its homogeneous scale divided out (last row 0 0 0 1),
 * as the scene keeps it: instances hand Embree its 3 x 4 part. */
Mat4 scene_unit_w(const float m[16]);
#define AFFINE_EXPECTED                                                                            \
    "%s: expected an affine matrix, not a projective one (a perspective row other than 0 0 0 "     \
    "w sends geometry through infinity; is a translation in the wrong row or column?)"
RayesError scene_push_values(RayesScene *scene, Prim *p, unsigned mask, const float *values,
                             size_t n);
/* Notes whether an Os primitive variable of n values (or none: NULL) has
 * a component below 1, so that the object of the primitives added next
 * is transparent. */
void scene_note_Os(RayesScene *scene, const float *Os, size_t n);

/* The bounds of all primitives' control points (lights included). */
Bounds3 scene_bounds(const RayesScene *scene);

#endif /* RAYES_SCENE_SCENE_H */
