/*
 * io/rib_reader.h — the RIB reader's state and the helpers its files
 * share. The reader (rib.h) is one file per concern:
 *
 *   rib.c         reading and dispatch: files and archives, a file's
 *                 requests and their arguments, dispatch to the request
 *                 tables, the two passes, entry points
 *   rib_params.c  messages, and the arguments of requests: numbers,
 *                 strings, handles, parameter lists, Declare and inline
 *                 declarations, value counts
 *   rib_state.c   graphics state, options and attributes: transforms,
 *                 blocks, coordinate systems, camera and image options,
 *                 Attribute and Option, Basis
 *   rib_shade.c   shaders and lights, and bringing the sink up to date
 *                 (transform, shader, light links) before a primitive
 *   rib_prim.c    geometric primitives: polygons, patches, quadrics,
 *                 Geometry, and their primitive variables
 *   rib_nurbs.c   NuPatch and TrimCurve
 *   rib_ris.c     RenderMan 19 and later: Bxdf, Light, Integrator, the
 *                 geometric area lights of RenderMan 19 and 20
 *   rib_frame.c   the block structure: frames, worlds, object definitions
 *
 * with rib_lex.c (tokens), rib_geom.c (tessellation, bases, matrices) and
 * rib_record.c (object definitions) beside them (rib_internal.h). A new
 * request goes into its concern's file, with a line in that file's table
 * of requests (RibRequest), which rib.c's dispatch reads. The files call
 * one way only (tools/check_deps): rib.c calls them all, rib_frame.c
 * rib_state.c and rib_shade.c, rib_nurbs.c rib_prim.c, rib_prim.c
 * rib_ris.c and rib_shade.c, rib_ris.c rib_shade.c, and every file
 * rib_params.c, which calls none.
 *
 * State: the attribute state (transform, colour, shaders, orientation,
 * basis) is a value copied onto a stack by AttributeBegin/TransformBegin.
 * Shaders are immutable records (ShaderRec) owned by the reader, so the
 * copies share them. What was last sent to each sink (transform, shader,
 * ...) is remembered in a SinkState, and resent only when it changes.
 * Every handler returns 0, or -1 with the message in Rib.err.
 */
#ifndef RAYES_IO_RIB_READER_H
#define RAYES_IO_RIB_READER_H

#include <stddef.h>
#include <stdint.h>

#include "io/rib_internal.h"
#include "io/rib_lex.h"
#include "io/sink.h"
#include "rayes/shader.h"

#define RIB_MAX_ARCHIVE_DEPTH 32
#define RIB_MAX_STACK 1024
#define RIB_MAX_ARGS 1000000
#define RIB_MAX_FILE_BYTES ((size_t)1 << 30)
#define RIB_MAX_WARNED 512
#define RIB_MAX_LIGHTS 4096
#define RIB_MAX_TIMES 16   /* motion samples (rayes.h's RAYES_MAX_TIMES) */
#define RIB_MAX_HANDLE 256 /* a handle's key: "#N" for a number, "\"name\"" for a string */

/* ----------------------------------------------------------- arguments */

typedef enum ArgKind { ARG_NUM, ARG_STR, ARG_NUMS, ARG_STRS } ArgKind;

typedef struct Arg {
    ArgKind kind;
    double *d;   /* NUM, NUMS */
    char **s;    /* STR, STRS */
    size_t n;    /* values */
    long line, col;
} Arg;

typedef struct Args {
    Arg *v;
    size_t n, cap;
} Args;

/* ------------------------------------------------------- declarations */

typedef enum Cls { CLS_CONSTANT, CLS_UNIFORM, CLS_VARYING, CLS_VERTEX, CLS_FACEVARYING } Cls;
typedef enum Ty { TY_FLOAT, TY_INT, TY_STRING, TY_COLOR, TY_POINT, TY_HPOINT, TY_MATRIX } Ty;

typedef struct Decl {
    char name[64];
    Cls cls;
    Ty ty;
    int array; /* elements per value, >= 1 */
    int reference; /* "reference TYPE name": the value names a pattern (a string) */
} Decl;

typedef struct Param {
    Decl d;
    int declared; /* 0: unknown name, type guessed from the values */
    const Arg *v;
} Param;

/* ------------------------------------------------------------- state */

typedef struct ShaderRec {
    char name[64];
    char pattern[160];  /* a Pattern's name once the sink has it, else "" */
    int channels;       /* a PxrTexture's imagemap: its outputs resultR ... resultA are
                           its channels (rib_pattern_ref) */
    const struct ShaderRec *of; /* a channel's pattern: the image's record */
    int bump;           /* a displacement made from a Bxdf's PxrBump (shading normal only) */
    RayesParam *params; /* names and strings owned */
    size_t n;
    struct ShaderRec *next;
} ShaderRec;

enum { ORIENT_OUTSIDE, ORIENT_INSIDE, ORIENT_LH, ORIENT_RH };

typedef struct Attr {
    float M[16];               /* camera_from_object before WorldBegin, world_from_object after */
    int orient;
    float Cs[3], Os[3];
    double texcoords[8];       /* TextureCoordinates: st at a patch's four corners */
    int have_texcoords;        /* 1 when they are not RenderMan's default (0 0 1 0 0 1 1 1) */
    long color_gen;            /* changes with Cs/Os */
    long cs_gen, os_gen;       /* change with Cs, with Os (an object block's own) */
    const ShaderRec *surface;  /* NULL: matte */
    const ShaderRec *atmosphere; /* Atmosphere in force (rayes' volume shader), or NULL */
    const ShaderRec *displacement;
    float shading_rate;
    float bound;
    int light_filter; /* a LightFilter in force (RIS): its gain multiplies the
                         lights declared after it in the block */
    float light_filter_gain[3];
    int area;                  /* AreaLightSource in force */
    int area_twosided;         /* its "twosided" (rayes's own parameter; default 0) */
    unsigned char on[RIB_MAX_LIGHTS / 8]; /* bit k: Rib.lights[k] is on */
    float area_L[3];
    char area_map[256]; /* its environment map (RenderMan 19-20's envsphere), or "" */
    char area_texture[256];     /* rayes' arealight's "texturename": its emission texture, or "" */
    const struct TrimSet *trim; /* TrimCurve in force (rib_nurbs.c), or NULL */
    int area_normalize;         /* its areaNormalize (RenderMan 19-20's geometry lights) */
    int area_point_units;       /* BMRT's and Pixie's arealight: area_L is a point light's
                                   intensity spread over each shape (rib_prim.c) */
    int area_unseen;            /* its rman__LightPrimaryVisibility 0: the camera sees none */
    int trim_outside;           /* Attribute "trimcurve" "sense" "outside": the loops'
                                   outsides are cut away, not their insides */
    float ubasis[16], vbasis[16];
    int ustep, vstep;
    int lod_coarse; /* DetailRange ends before infinity: a coarser representation,
                       whose primitives are skipped */
    int roundcurve; /* Attribute "dice" "roundcurve": curves without N are tubes */
    uint32_t visibility; /* Attribute "visibility": RayesRayType bits of the rays that see it */
    int shadows; /* Attribute "light" "shadows" (BMRT's): "on" 1, the lights that follow cast
                    ray-traced shadows; "off" -1, none; 0 unsaid (each shader's own way) */
    int camera_said;     /* Attribute "visibility" "camera" 1 is in force (RenderMan 21's
                            lights are seen by the camera only then) */
    int hitmode;         /* Attribute "shade" "transmissionhitmode": RayesTransmissionHitMode */
    int opacity_cache;   /* Attribute "shade" "opacitycache": 0, its opacity is never cached */
    float motionfactor, focusfactor; /* Attribute "dice" "motionfactor", "focusfactor" */
    int n_motion;        /* M moves: n_motion samples (MotionBegin around transforms), else 0 */
    float motion_time[RIB_MAX_TIMES];
    float motion_M[RIB_MAX_TIMES][16]; /* M at each time; M is motion_M[0] */
} Attr;

typedef struct SinkState {
    float M[16];
    int have_M;
    const ShaderRec *surface;
    long color_gen;
    int have_shader;
    const ShaderRec *displacement;
    int have_displacement;
    float rate, bound;
    int have_rate, have_bound;
    uint32_t visibility;
    int hitmode, opacity_cache;
    int have_visibility, have_opacity_mode;
    int n_motion;                      /* the motion last sent with M (0: none) */
    float motion_M[RIB_MAX_TIMES][16];
    float motionfactor, focusfactor;   /* the dice blur last sent */
    int have_blur;
} SinkState;

#define RIB_LIGHT_PARAMS 40

typedef struct Light {
    char handle[RIB_MAX_HANDLE]; /* "" once a later light took the handle */
    char type[32];
    RayesParam params[RIB_LIGHT_PARAMS];
    char names[RIB_LIGHT_PARAMS][64];
    char category[128];
    char mapname[1024]; /* an environment light's map, as given */
    char mapping[32];   /* and its layout ("latlong", "octahedral") */
    char shape[16];     /* an arealight's ("quad", "disk", "sphere") */
    char lighttype[16]; /* an uberlight's ("spot", "omni") */
    float blocker[16];  /* an uberlight's blockermatrix (world_from_blocker) */
    size_t n;
    float M[16];   /* world_from_light (camera_from_light before WorldBegin) */
    int n_motion;  /* a light moving within the frame (MotionBegin around its transform,
                      in the world): n_motion samples, else 0 */
    float motion_time[RIB_MAX_TIMES];
    float motion_M[RIB_MAX_TIMES][16];
    int pre_world;
    int own_visibility; /* a light with geometry of its own seen by the rays of visibility
                           (RenderMan 21's), else the geometry's visibility as it is */
    uint32_t visibility;
    long index;    /* the sink's index of the light once sent, else -1 */
} Light;

typedef struct Object {
    char key[RIB_MAX_HANDLE];
    RibRecording *rec;
} Object;

typedef struct Frame {
    long number;
    int renders; /* a world block whose display is not a shadow map */
} Frame;

typedef struct StackEntry {
    Attr a;
    int attribute; /* 1: AttributeBegin, 0: TransformBegin, 2: SolidBegin */
    int solid_op;  /* SolidBegin: its RayesSolidOp */
    int solid_sent; /* SolidBegin: the sink was told (solid_begin) */
} StackEntry;

/* A texture the file makes from an image (MakeTexture "in.tif"
 * "out.tex"): rayes reads the image itself wherever the made name is used. */
typedef struct RibTextureAlias {
    char made[256], from[256];
} RibTextureAlias;

typedef struct Rib {
    int pass;                  /* 1: check and list frames, 2: read into the sink */
    const IoSink *sink;
    const IoReadOptions *opt;
    IoSettings *settings;
    char *err;
    size_t err_size;
    RibLexer *lx;              /* the file being read (NULL after the top file ends) */
    const char *top_name;      /* the top file, for messages after it ends */
    const char *file;          /* its path */
    char req[64];              /* the current request */
    long req_line, req_col;
    int archive_depth;

    Attr a;
    StackEntry *stack;
    size_t depth;
    long next_gen;
    ShaderRec *shaders;
    struct TrimSet *trims; /* every TrimCurve read (rib_nurbs.c) */
    size_t world_depth;    /* the attribute stack's depth at WorldBegin */
    double nurbs_work;     /* the NuPatch and trim work of the pass (rib_nurbs.c) */
    int lit;               /* a light was made (pass 1: anywhere in the file) */
    int ris;               /* a RenderMan 19+ request was read (Bxdf, Light, Integrator) */
    int integrator;        /* an Integrator request was read */
    int unlit_file;        /* pass 2: the file makes no light, so geometry without a
                              Surface is drawn with RenderMan's defaultsurface */

    int in_world;
    int worlds;
    float camera_from_world[16];
    /* named cameras (Camera "name": RenderMan 22's layout declares the
     * camera in a TransformBegin block; Display's "string camera" picks) */
    struct NamedCamera {
        char name[64];
        float M[16]; /* camera_from_world at its Camera */
    } cameras[8];
    int n_cameras;
    char display_camera[64];   /* the main Display's "camera", "" for none */
    int camera_motion;         /* camera_from_world moves: samples in camera_motion_M */
    float camera_motion_time[RIB_MAX_TIMES], camera_motion_M[RIB_MAX_TIMES][16];
    float shutter[2], shutter_offset; /* Shutter, Option "shutter" "offset" */
    float dof[3];              /* DepthOfField fstop focallength focaldistance; fstop 0: none */
    /* A MotionBegin block: its times, the request count so far, what it
     * holds (1: transforms, 2: primitives, 0: nothing yet), and for
     * transforms M before it (with its own motion, from an earlier block)
     * and after each sample. */
    int motion_kind;
    size_t motion_n;
    float motion_time[RIB_MAX_TIMES];
    float motion_pre[16];
    int motion_pre_n; /* M before the block moved: its samples */
    float motion_pre_time[RIB_MAX_TIMES];
    float motion_pre_M[RIB_MAX_TIMES][16];
    char motion_req[RIB_MAX_TIMES][20];    /* each sample's request (a transform block) */
    float motion_rotate[RIB_MAX_TIMES][4]; /* a Rotate sample's angle and axis */
    float motion_M[RIB_MAX_TIMES][16];
    int projection;            /* RayesProjection */
    float fov;
    float screen[4];
    int have_screen;
    float frame_aspect;
    int width, height;

    Decl *decls;
    size_t n_decls;
    Light *lights;
    size_t n_lights;
    char (*area_handles)[RIB_MAX_HANDLE]; /* AreaLightSource handles, for Illuminate */
    size_t n_area_handles;
    size_t *links;             /* the light links last sent (EXCEPT these; none: ALL) */
    size_t n_links;
    Object *objects;
    size_t n_objects;
    RibRecording *rec;         /* the object being defined, when the sink has no instances */
    int in_object;             /* 1: inside ObjectBegin, sent to a sink with instances
                                  (object_begin); the block's state is `recorded` */
    const ShaderRec *world_atmosphere; /* the world's atmosphere: that of its first primitive
                                          under one, sent at WorldEnd */
    const void *object_surface; /* the surface and colour generation at that ObjectBegin: */
    long object_color_gen;     /* geometry under them inherits each instance's shader */
    long object_cs_gen, object_os_gen; /* Cs's and Os's generations there */
    int pv_block_color;                /* the request's primitive carries the block's Color or
                                          Opacity as a constant Cs or Os (rib_block_color_only), so
                                          it still inherits */
    double block_Cs[3], block_Os[3];
    IoSink rec_sink;
    char rec_key[RIB_MAX_HANDLE];
    float rec_saved_M[16];
    SinkState real, recorded;

    char archive_path[4096];
    char texture_path[4096];   /* the texture search path as the sink has it ("&" expanded) */
    RibTextureAlias *made;     /* MakeTexture, MakeLatLongEnvironment: made name -> image */
    size_t n_made;
    char *coordsys_names;      /* CoordinateSystem: n x 64 names */
    float *coordsys_M;
    int *coordsys_world;
    size_t n_coordsys;

    Frame *frames;
    size_t n_frames;
    long frame_ordinal;
    long selected;             /* ordinal of the frame to read, -1: no frames */
    int in_frame, skipping, done;
    int shadow_display;
    IoSettings frame_saved;
    int frame_saved_shadow;
    int motion, motion_seen;
    int archive_block;
    /* conditional blocks (IfBegin ... IfEnd), innermost last: 0 the branch
     * being read, 1 skipped with none taken yet, 2 skipped after one was
     * taken, 3 skipped inside a skipped branch */
    unsigned char cond[64];
    int n_cond;
    /* Pattern classes rayes has not (RenderMan's Pxr networks): the colour
     * each passes on, its input's (PxrExposure's inputRGB, ...), for the
     * parameters that reference it */
    struct PatternStandIn {
        char name[128];
        float rgb[3];
        char alias[160]; /* its input is this pattern (sent), passed on; else "" */
    } * stand_ins;
    size_t n_stand_ins, cap_stand_ins;
    /* texture names found beside the scene's file rather than where PRMan
     * looks (rib_texture_source), kept for the parameters that use them */
    char **found;
    size_t n_found, cap_found;
    /* PxrManifold2D's placements of s and t, by name, for the textures and
     * checkers that reference them */
    struct RisManifold {
        char name[128];
        float scale[2], offset[2];
        int invert_t; /* -1: not given */
    } * manifolds;
    size_t n_manifolds, cap_manifolds;
    /* PxrBump patterns, by name: the pattern of their height (sent) and
     * their scale, for the Bxdfs whose bumpNormal references them */
    struct RisBump {
        char name[128];
        char height[160];
        float scale;
    } * bumps;
    size_t n_bumps, cap_bumps;
    unsigned n_internal; /* patterns the RIS translation made itself (their names) */
    /* inline archives (ArchiveBegin "name" ... ArchiveEnd): their text, read
     * by a ReadArchive of their name before any file */
    struct InlineArchive {
        char *name, *file, *text; /* owned */
        size_t size;
        long line; /* of the text's first request in file */
    } * inline_archives;
    size_t n_inline, cap_inline;
    char *archive_name;                /* the block being skipped: its name, owned */
    int archive_nest;                  /* ArchiveBegin ... ArchiveEnd inside it */
    size_t inline_read;                /* bytes of inline archives read, in all */
    const unsigned char *archive_body; /* and its first request, NULL until read */
    long archive_line;
    const unsigned char *req_at; /* the current request's first byte in its text, or NULL */
    long first_line;             /* the line run() starts its text at (1) */

    char *warned[RIB_MAX_WARNED];
    size_t n_warned;
} Rib;

/* Counts of a primitive's classes, for value-count checks. */
typedef struct Counts {
    size_t uniform, varying, vertex, facevarying;
} Counts;

/* ------------------------------------------------------------ requests */

typedef int (*Handler)(Rib *r, const Args *a);

/* A request a file handles; each file's table ends with {NULL, NULL}. */
typedef struct RibRequest {
    const char *name;
    Handler fn;
} RibRequest;

extern const RibRequest rib_params_requests[]; /* rib_params.c */
extern const RibRequest rib_state_requests[];  /* rib_state.c */
extern const RibRequest rib_shade_requests[];  /* rib_shade.c */
extern const RibRequest rib_prim_requests[];   /* rib_prim.c */
extern const RibRequest rib_curves_requests[]; /* rib_curves.c */
extern const RibRequest rib_frame_requests[];  /* rib_frame.c */

/* ------------------------------------- rib_params.c: messages, arguments */

/* Sets r->err to "file:line:col: Request: message" at the current
 * request (rib_arg_error: at argument a) and returns -1. */
int rib_error(Rib *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int rib_arg_error(Rib *r, const Arg *a, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* One warning per key and read (the second pass only, so each is said once). */
void rib_warn_once(Rib *r, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* The sink's own message as the request's error; returns -1. */
int rib_sink_failed(Rib *r, const IoSink *s);
/* Keeps an area light's handle (AreaLightSource, PxrMeshLight) for
 * Illuminate; 0, or -1 with the error set. */
int rib_add_area_handle(Rib *r, const char *handle);
/* A copy of s (malloc), or NULL. */
char *rib_strdup(const char *s);

int rib_is_num(const Arg *g);
/* n numbers from args *i on (scalars or arrays, an array taken whole). */
int rib_get_floats(Rib *r, const Args *a, size_t *i, float *out, size_t n, const char *what);
/* The string at *i (owned by a), or NULL with the error set. */
const char *rib_get_string(Rib *r, const Args *a, size_t *i, const char *what);
/* A handle: an integer or a string, as a key ("#N" or "\"name\"": the
 * two never meet); a string too long for a key is an error. */
int rib_get_handle(Rib *r, const Args *a, size_t *i, char key[RIB_MAX_HANDLE]);
/* The handle of key as the file wrote it, for messages. */
const char *rib_handle_name(const char *key);
/* An integer array (or one integer) with every value in [lo, hi]; *out
 * is a new array of *n values. */
int rib_get_ints(Rib *r, const Args *a, size_t *i, int **out, size_t *n, long lo, long hi,
                 const char *what);
/* Numbers per value of a type: 1, 3, 4 or 16. */
int rib_type_size(Ty t);
/* The parameter list of args[start..]: pairs of a name and values, as a
 * new array of *n_out parameters (pointing into a). */
int rib_get_params(Rib *r, const Args *a, size_t start, Param **out, size_t *n_out);
/* The last parameter called name, or NULL. */
const Param *rib_find_param(const Param *p, size_t n, const char *name);
/* Checks the number of values of each declared parameter against the
 * primitive's counts c (warning about undeclared ones). */
int rib_check_counts(Rib *r, const Param *p, size_t n, const Counts *c);
/* Warns once per parameter name a primitive does not use. */
void rib_warn_unused(Rib *r, const Param *p, size_t n);
/* The primitive's "Cs" when it is one colour per value; NULL otherwise. */
const Param *rib_color_param(Rib *r, const Param *p, size_t n);

/* ------------------------------------------ rib_prim.c: primitives' data */

/* Primitive variables for one sink call (N, st, Cs, Os; curves and
 * points add width); the data are owned. */
typedef struct PvOut {
    RayesPrimvar pv[5];
    float *data[5];
    size_t n;
} PvOut;

/* 1 inside an ObjectBegin block (of a sink with instances) that set Color
 * but no Surface, before any shader was sent in it: its geometry keeps
 * each instance's shader, with the block's colour as a constant Cs. */
int rib_block_color_only(const Rib *r);

/* Frees o's data; o is then empty. */
void rib_pv_out_free(PvOut *o);

/* A parameter that is a numeric declared value of size floats, or NULL
 * (with one warning when it has the name but another type). */
const Param *rib_var_param(Rib *r, const Param *p, size_t n, const char *name, int size);
/* The points of a primitive from "P" or "Pw" (divided by w); a new array
 * of *n_points points, or NULL with the error set. */
float *rib_get_points(Rib *r, const Param *p, size_t n_par, size_t *n_points);

/* --------------------------------------------------- rib_state.c: state */

/* AttributeBegin (attribute 1) or TransformBegin (0), and their ends. */
int rib_push(Rib *r, int attribute);
int rib_pop(Rib *r, int attribute);
/* world_from_camera, or the identity (with a warning) when singular. */
void rib_world_from_camera(Rib *r, float m[16]);
/* The matrix of the coordinate system named (CoordinateSystem), as the
 * current transform would be after CoordSysTransform: 0, or -1 if no such
 * system was made. */
int rib_coordsys(Rib *r, const char *name, float M[16]);
/* The sink geometry goes to (the recording inside ObjectBegin) and what
 * it was last sent. */
const IoSink *rib_out_sink(Rib *r, SinkState **st);

/* -------------------------------------------- rib_shade.c: the sink's state */

/* Brings the sink up to date before a primitive; Cs overrides the
 * colour (a per-face colour) when not NULL. 1: skip (outside the world). */
int rib_emit_begin(Rib *r, const float *Cs);
/* 1, with one warning, when the current transform (at any motion sample)
 * is finite but singular (a Scale 0 0 0): what follows collapses to
 * nothing, and RenderMan draws nothing of it; 0 otherwise (a transform
 * that is not finite is left to the sink's error). */
int rib_collapsed(Rib *r);
/* Sends the lights never sent and the light links, if they changed. */
int rib_send_lights(Rib *r);
/* The name of the Pattern that reached the sink a reference names: ref
 * itself, or RenderMan's "pattern:output" without its output (in buf), or
 * the pattern an unbuilt pattern of that name passes on (its input's);
 * NULL if none did. */
const char *rib_pattern_name(const Rib *r, const char *ref, char *buf, size_t size);
/* rib_pattern_name for a parameter's reference: a PxrTexture's resultR,
 * resultG, resultB or resultA (resultF: its red) is that channel of its
 * image, sent under the reference's whole name the first time it is named
 * (an imagemap with "channel"); other outputs are the pattern itself. */
const char *rib_pattern_ref(Rib *r, const char *ref, char *buf, size_t size);
/* Pattern "type" "name" p: sends the pattern sh (RenderMan's class
 * translated by rib_ris.c, p unused) or rayes' class type of p, in the
 * current transform; a class rayes has not is a stand-in (its input's
 * colour, for the parameters that reference it) with one warning. Frees
 * p. */
int rib_pattern_define(Rib *r, const char *type, const char *name, Param *p, size_t n,
                       ShaderRec *sh);
/* The colour an unbuilt pattern referenced as ref ("name:output") passes on
 * (h_pattern's stand-in) into rgb; 0 if there is none. */
int rib_pattern_stand_in(const Rib *r, const char *ref, float rgb[3]);
/* Whether a texture name is a readable file as given or on the texture
 * search path. */
int rib_texture_found(const Rib *r, const char *name);
/* The image a texture name stands for: the source image of the file's
 * MakeTexture or MakeLatLongEnvironment that made it; a relative name
 * found neither as given (the working directory, where PRMan looks) nor
 * on the texture search path but beside the file being read or in a
 * directory up to 4 above it (the scene rendered from elsewhere): that
 * path; else name. */
const char *rib_texture_source(Rib *r, const char *name);
/* The path of a readable file name relative to the directory of file or
 * one of the levels directories above it (the nearest), in out: 0, or -1
 * if none holds it. */
int rib_find_above(const char *file, const char *name, int levels, char *out, size_t size);
/* A shader record of name with copies of the parameters p (floats arrays
 * are not taken), the attributes' to point to; NULL with the error set. */
ShaderRec *rib_shader_rec(Rib *r, const char *name, const RayesParam *p, size_t n);
/* A new light record of type under handle, in the current transform and
 * on; NULL with the error set. */
Light *rib_new_light(Rib *r, const char *handle, const char *type);
/* Appends a parameter to a light record (a string one must be named
 * mapname, mapping, shape or __category). */
void rib_light_param(Light *L, const char *name, RayesParamType type, const float v[3],
                     const char *string);

/* Whether the current orientation flips a patch (its u reverses). */
int rib_flip(Rib *r);
/* Sends a bicubic Bezier patch (u fastest; flipped as rib_flip says). */
int rib_emit_bicubic(Rib *r, float B[16][3], const PvOut *pv);

/* ------------------------------------------- rib_nurbs.c: NuPatch */

extern const RibRequest rib_nurbs_requests[];
void rib_trims_free(Rib *r);

/* ------------------------------ rib_ris.c: RenderMan 19 and later (RIS) */

extern const RibRequest rib_ris_requests[];
/* Geometry "rectlight", "disklight", "spherelight", "distantlight" or
 * "envsphere" under AreaLightSource (RenderMan 19 and 20): the light of
 * that shape; 1 if name is one of them, 0 if not, -1 on error. */
int rib_ris_geometry_light(Rib *r, const char *name);

/* At WorldEnd: sends the lights on then that were never sent, and ends
 * the world's lights. */
int rib_flush_lights(Rib *r);

#endif /* RAYES_IO_RIB_READER_H */
