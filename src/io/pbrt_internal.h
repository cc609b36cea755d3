/*
 * io/pbrt_internal.h — pieces of the pbrt-v4 reader shared by its files
 * (the opening comment of pbrt.c describes the reader as a whole): the
 * reader's state and types, and what one file gives the others.
 *
 *   pbrt.c           the graphics-state directives (transforms,
 *                    Attribute/Transform/Object blocks, Include), the
 *                    directive table, entry points;
 *   pbrt_lex.c       messages, tokens, matrices, paths, named coordinate
 *                    systems: what every file uses;
 *   pbrt_params.c    parameter lists, colours and spectra;
 *   pbrt_emit.c      geometry and lights to the sink, or recorded for
 *                    ObjectInstance;
 *   pbrt_options.c   Camera, Film, Sampler, Integrator, PixelFilter,
 *                    ColorSpace, WorldBegin/End;
 *   pbrt_material.c  Material, MakeNamedMaterial, NamedMaterial, Texture;
 *   pbrt_shape.c     Shape;
 *   pbrt_light.c     LightSource, AreaLightSource;
 *   pbrt_medium.c    MakeNamedMedium, MediumInterface, and the volume
 *                    a shape with an inside medium bounds.
 *
 * A new directive's handler goes in the file of its concern and gets a
 * line in pbrt.c's table. The files call one way (tools/check_deps):
 * pbrt.c calls the others, pbrt_lex.c none, and no file calls pbrt.c. Functions taking the Parser return 0, or -1 with
 * the message written into P->err (pbrt_fail_at). Matrices are row-major
 * 4 x 4 doubles mapping column vectors (world_from_object), as in rayes.h.
 * One Parser per read; nothing here is shared between threads.
 */
#ifndef RAYES_IO_PBRT_INTERNAL_H
#define RAYES_IO_PBRT_INTERNAL_H

#include <stddef.h>

#include "io/sink.h"

#define PBRT_PATH 1024
#define PBRT_MAX_WARNED 512 /* kinds of warning said per read */
#define MAT_MAX_PARAMS 24   /* a mix: two materials' (10 each, say) and its amount */
/* The shader name of pbrt's "interface" material: shapes with it are not
 * emitted (they only bound media). */
#define PBRT_INVISIBLE "(interface)"

static const double PI = 3.14159265358979323846;

/* ---------------------------------------------------------------- types */

/* Tokens and the parameter list of the directive being read; the graphics
 * state, with its material and area light; what the file defined by name
 * (coordinate systems, materials, textures, objects); the Parser holding
 * them all for one read. */

typedef enum TokKind { TOK_END, TOK_WORD, TOK_STRING, TOK_LBRACKET, TOK_RBRACKET } TokKind;

typedef struct Token {
    TokKind kind;
    const char *s; /* the word, or the inside of the quotes (escapes not yet resolved) */
    size_t n;
    long line, col;
} Token;

typedef struct Lexer {
    const char *name; /* for messages */
    const char *p, *end;
    long line;
    const char *line_start;
    char dir[PBRT_PATH]; /* relative paths resolve here ("" = the working directory) */
    struct Lexer *parent; /* an included file's: the file that included it, whose tokens
                             follow its own (pbrt-v4 reads one stream of tokens), or NULL */
    char *text;           /* an included file's text, owned (freed with the parser) */
    struct Lexer *next;   /* the parser's list of included files' lexers */
} Lexer;

typedef enum ParamType {
    PT_INTEGER, PT_FLOAT, PT_POINT2, PT_VECTOR2, PT_POINT3, PT_VECTOR3, PT_NORMAL, PT_RGB,
    PT_SPECTRUM, PT_BLACKBODY, PT_BOOL, PT_STRING, PT_TEXTURE
} ParamType;

typedef struct Param {
    ParamType type;
    char type_name[32];
    char name[96];
    double *num;  /* numeric values (bools as 0/1) */
    size_t n_num;
    char **str;   /* string values */
    size_t n_str;
    long line, col;
    int used;
} Param;

typedef struct ParamList {
    Param *p;
    size_t n, cap;
} ParamList;

/* A shader call: the built-in class and its parameters, and the
 * displacement that goes with it. Zeroed before it is filled, so two
 * materials compare with memcmp. */
typedef struct Material {
    char shader[24];
    int n;
    struct {
        char name[24];
        RayesParamType type; /* FLOAT, COLOR, PATTERN, or STRING (a mix's classes) */
        float v[3];
        size_t tex; /* PATTERN: the index of its Texture in Parser.textures */
        char s[24]; /* STRING */
    } p[MAT_MAX_PARAMS];
    int displaced; /* pbrt's "displacement": 1 a constant (displacement_v), 2 a
                      texture (displacement_tex), both bump maps; a plymesh's, which
                      moves the surface: 3 a texture, 4 a constant */
    float displacement_v;
    size_t displacement_tex;
} Material;

typedef struct AreaLight {
    int on;
    float L[3];      /* radiance, scale included: the current shape's (pbrt_area_power) */
    float L_base[3]; /* L and scale as given */
    double power;    /* "power" (watts per pbrt shape), or 0 */
    int twosided;
    char filename[PBRT_PATH]; /* "filename": its image (resolved), or "" */
} AreaLight;

typedef struct GState {
    double ctm[16]; /* world_from_object, row-major, at the start time */
    double ctm_end[16]; /* and at the end time (ActiveTransform EndTime's) */
    int reverse;    /* ReverseOrientation */
    int active;     /* ActiveTransform: bits 1 StartTime (ctm), 2 EndTime (ctm_end); All 3 */
    Material material;
    AreaLight area;
    char inside[128], outside[128]; /* MediumInterface: media names, "" for none */
    int kind; /* on the stack: 'A' AttributeBegin, 'T' TransformBegin, 'O' ObjectBegin */
    /* A NamedMaterial of a name no MakeNamedMaterial has defined yet (pbrt
     * looks it up at its shapes, after the whole file), "" for none; where
     * it was, for the message if it never is (pbrt_defer.c) */
    char pending[128];
    const char *pending_file;
    long pending_line, pending_col;
} GState;

typedef struct Named {
    char name[128];
    double m[16];
} Named;

typedef struct NamedMaterial {
    char name[128];
    Material m;
} NamedMaterial;

/* A named texture: a pattern sent to the sink (pattern), or a constant.
 * Textures the reader makes itself (a squared roughness, say) have a name
 * that starts with a space, which no file's name is looked up as. */
typedef struct Texture {
    char name[128];
    char pattern[160]; /* the sink's name of its pattern; "": a constant (rgb) */
    float rgb[3];      /* the constant, or the pattern's stand-in colour for
                          what cannot vary (its mean where pbrt's class has one) */
    int is_float;      /* a "float" texture (else "spectrum") */
} Texture;

typedef enum OpKind { OP_MESH, OP_QUADRIC, OP_PATCH, OP_CURVES } OpKind;

typedef struct Op {
    OpKind kind;
    double m[16];
    Material *mat;        /* owned */
    size_t n_faces, n_points;
    int *n_verts, *idx;   /* owned */
    float *pts;           /* owned */
    float *N, *uv;        /* per point, owned; NULL when not given */
    RayesQuadric q;
    float qp[8];
    size_t n_qp;
    unsigned flags;
    float patch[4][3];
    int patch_pv;         /* GEOM-like bits: 1 patch_N, 2 patch_uv given */
    float patch_N[4][3], patch_uv[4][2];
    int subdiv; /* OP_MESH: a Loop subdivision surface (loopsubdiv) */
    /* OP_CURVES: the curves (n_verts and pts, owned, are its arrays) and
     * their primitive variables (width, N), whose data are owned */
    RayesCurves curves;
    RayesPrimvar curve_pv[2];
    size_t n_curve_pv;
} Op;

/* A directive read again later (pbrt_defer.c): its lexer as it was after
 * the directive's name, that name's token, the graphics state then, and
 * for a MakeNamedMaterial its material's name. */
typedef struct Deferred {
    Lexer lx;
    Token t;
    GState gs;
    char name[128];
    int done; /* read again already */
} Deferred;

typedef struct DeferList {
    Deferred *d;
    size_t n, cap;
} DeferList;

typedef struct Object {
    char name[128];
    int sent;                 /* sent to a sink with instances as a master (object_begin) */
    Op *ops;
    size_t n_ops, cap_ops;
} Object;

/* A named medium (MakeNamedMedium): the homogeneous shader's parameters
 * and, for grids, the density pattern; and the shapes that bound it
 * (MediumInterface), recorded to be sent at the end of the file as one
 * hidden object, the medium's volume inside it (pbrt_media_send). */
typedef struct Medium {
    char name[128];
    char type[16];       /* "homogeneous", "uniformgrid", "cloud" or "nanovdb" */
    double m[16];        /* world_from_medium: the transform at MakeNamedMedium */
    float extinction[3]; /* (sigma_a + sigma_s) scale */
    float albedo[3];     /* sigma_s / (sigma_a + sigma_s) */
    float emission[3];   /* sigma_a scale Le Lescale */
    float g;
    size_t res[3];            /* uniformgrid: nx ny nz */
    float *density;           /* uniformgrid: nx ny nz values, owned */
    float p0[3], p1[3];       /* uniformgrid, cloud: the box, medium space */
    float cloud[3];           /* cloud: density, wispiness, frequency */
    char filename[PBRT_PATH]; /* nanovdb: resolved */
    char grids[2][64];        /* nanovdb: its density and temperature grids' names */
    float Lescale;            /* nanovdb: the temperature grid's blackbody emission scale */
    float temp_offset, temp_scale; /* nanovdb: temperaturecutoff, temperaturescale */
    char pattern[160];        /* the sink's pattern of the density once sent, else "" */
    char temperature[176];    /* nanovdb: the sink's pattern of its optional temperature grid */
    int sent;                 /* the pattern was sent */
    Object bound;             /* the shapes with the medium on a side, hidden, each turned so
                                 that the medium lies behind its normals */
    float box[6];             /* their bounds, world space (xmin, xmax, ymin, ...) */
    int have_box;             /* box holds a point */
    const char *file;         /* where the first of them was read (a lexer's name: the parser's */
    int line, col;            /* until it is freed) */
} Medium;

typedef struct Parser {
    const IoSink *sink;
    const IoReadOptions *options;
    IoSettings *settings;
    char *err;
    size_t err_size;
    Lexer *lx;
    Lexer *included; /* every included file's lexer and text, kept to the parse's end */
    Token peeked;
    int has_peek;
    int depth, n_files;
    GState gs;
    GState *stack;
    size_t n_stack, cap_stack;
    Named *coordsys;
    size_t n_coordsys;
    NamedMaterial *materials;
    size_t n_materials;
    Texture *textures;
    size_t n_textures;
    Object *objects;
    size_t n_objects;
    Medium *media;
    size_t n_media;
    float shape_bound[6]; /* object-space bounds of the Shape being read (x0 x1 y0 y1 z0 z1) */
    int have_shape_bound;
    int shape_bounds;     /* the Shape being read is recorded into a medium's bound (an
                             "interface" one too: pbrt_medium_bounded) */
    int shape_hidden;     /* a bound's shapes are being sent, seen by no ray */
    float world_bound[6]; /* world-space bounds of every Shape outside ObjectBegin so far */
    int have_world_bound;
    char camera_medium[128]; /* the outside medium current at Camera, "" for none */
    long camera_line, camera_col; /* where Camera was (the camera medium's messages) */
    Object *recording; /* between ObjectBegin and ObjectEnd */
    long replayed;
    /* camera and options */
    int world; /* after WorldBegin */
    double camera_from_world[16];
    double camera_from_world_end[16]; /* at the end time: the camera moves if it differs */
    double transform_times[2];        /* TransformTimes (default 0 1) */
    float shutter[2];                 /* the camera's shutteropen, shutterclose */
    float iso;                        /* the film's iso (100: pbrt's default) */
    float lens_radius, focal_distance; /* the camera's lensradius, focaldistance */
    double lens_image;    /* a realistic camera: its lens system's image distance, mm (0: none) */
    double film_diagonal; /* the film's diagonal, mm (pbrt's 35) */
    RayesProjection projection;
    float fov;
    float screen[4];
    int have_screen;
    /* what the sink was last told */
    Material sent;
    int have_sent;
    char (*warned)[96];
    size_t n_warned;
    /* forward references (pbrt_defer.c) */
    DeferList shapes;    /* shapes whose NamedMaterial was not defined yet */
    DeferList defs;      /* MakeNamedMaterial whose textures were not defined yet */
    int missing_texture; /* a texture name was looked up and not found */
    int rereading;       /* deferred directives being read again, nested (they are not
                            deferred twice) */
} Parser;

/* ------------------------------------------------ messages (pbrt_lex.c) */

/* Writes "file:line:col: message" into P->err; returns -1. */
int pbrt_fail_at(Parser *P, long line, long col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#define FAIL_TOK(P, t, ...) pbrt_fail_at((P), (t)->line, (t)->col, __VA_ARGS__)

/* One warning per key and read. */
void pbrt_warn_at(Parser *P, long line, long col, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* A printable copy of a token for messages (at most 40 characters). */
const char *pbrt_shown(const Token *t, char buf[48]);

/* --------------------------------------------------- lexer (pbrt_lex.c) */

/* The next token: consumed (pbrt_next) or kept for the next read (pbrt_peek). */
int pbrt_next(Parser *P, Token *t);
int pbrt_peek(Parser *P, Token *t);
/* Nonzero if t is the bare word w. */
int pbrt_word_is(const Token *t, const char *w);
/* The string's contents with escapes resolved, into buf (error if long). */
int pbrt_string_value(Parser *P, const Token *t, char *buf, size_t size);
/* A finite number of at most 1e30 in magnitude; -1 (no message) if not. */
int pbrt_parse_number(const Token *t, double *out);
/* A quoted string (what names it in the message), its token in *where
 * when where is not NULL. */
int pbrt_expect_string(Parser *P, char *buf, size_t size, const char *what, Token *where);
/* A number, or n numbers (bare or in one bracket); what names them in the
 * message. */
int pbrt_expect_number(Parser *P, double *out, const char *what);
int pbrt_expect_numbers(Parser *P, double *out, int n, const char *what);

/* ------------------------------------------------ matrices (pbrt_lex.c) */

void pbrt_mat_identity(double m[16]);
void pbrt_mat_mul(const double a[16], const double b[16], double out[16]); /* out = a b */
/* The determinant of the upper-left 3 x 3 (negative: a mirror). */
double pbrt_mat_det3(const double m[16]);
/* Gauss-Jordan with partial pivoting; -1 if singular. */
int pbrt_mat_inverse(const double m[16], double out[16]);
/* Nonzero when every element is finite and at most 1e30 in magnitude. */
int pbrt_mat_finite(const double m[16]);
void pbrt_mat_to_float(const double m[16], float out[16]);
void pbrt_cross3d(const double a[3], const double b[3], double o[3]);
double pbrt_dot3d(const double a[3], const double b[3]);

/* ------------------------------------------- paths, state (pbrt_lex.c) */

/* Fails unless the world has begun (inside 1) or not yet (inside 0). */
int pbrt_need_world(Parser *P, const Token *t, int inside);
/* file relative to the directory of the file being read (error if long). */
int pbrt_resolve(Parser *P, const Token *t, const char *file, char *out, size_t size);
/* Defines or redefines the named coordinate system as m. */
int pbrt_set_coordsys(Parser *P, const Token *t, const char *name, const double m[16]);

/* ------------------------------------------- parameters (pbrt_params.c) */

void pbrt_params_free(ParamList *pl);
/* Reads the "name" argument and the parameter list of a directive. */
int pbrt_name_and_params(Parser *P, char *name, size_t size, const char *what, ParamList *pl,
                         Token *where);
/* Reads `"type name" value|[values]` pairs up to the first token that is
 * not a quoted string. */
int pbrt_parse_params(Parser *P, ParamList *pl);
/* The last parameter of that name, marked used, or NULL. */
Param *pbrt_find(ParamList *pl, const char *name);
double pbrt_get_float(ParamList *pl, const char *name, double def);
const char *pbrt_get_string(ParamList *pl, const char *name, const char *def);
/* The first three numbers of a point parameter, or NULL (borrowed). */
const double *pbrt_get_point(ParamList *pl, const char *name);
/* One warning per parameter nobody asked for. */
void pbrt_warn_unused(Parser *P, ParamList *pl, const char *directive, const char *kind);
/* A colour parameter: rgb, spectrum (named, sampled or constant), blackbody,
 * float (grey) or texture. Returns 0 (not given: out = def), 1 (a colour
 * in out; a constant texture's, or any texture's stand-in when tex is
 * NULL), 2 (a pattern texture in *tex, out = its stand-in) or -1 (error). */
int pbrt_get_color(Parser *P, ParamList *pl, const char *name, const float def[3], float out[3],
                   const Texture **tex);
/* A light's radiance or intensity parameter (L, I): as pbrt_get_color
 * (default white, no textures), a spectrum or blackbody normalised to
 * luminance 1 as pbrt-v4 normalises a light's spectrum. */
int pbrt_get_emission(Parser *P, ParamList *pl, const char *name, float out[3]);
/* A float parameter that may be a texture (its stand-in's mean grey then). */
int pbrt_get_float_tex(Parser *P, ParamList *pl, const char *name, double def, double *out);
/* The texture defined with that name latest, or NULL. */
const Texture *pbrt_find_texture(const Parser *P, const char *name);

/* ----------------------------------------------- emitting (pbrt_emit.c) */

/* Reports the sink's error e at t; returns -1. */
int pbrt_sink_failed(Parser *P, const Token *t, RayesError e);
/* Geometry under the current transform and material, sent or recorded;
 * arrays are borrowed (copied when recorded). N and uv per point or NULL. */
int pbrt_emit_mesh(Parser *P, const Token *t, size_t n_faces, const int *n_verts,
                   const int *idx, size_t n_points, const float *pts, const float *N,
                   const float *uv);
/* A Loop subdivision surface of triangles (loopsubdiv), sent or recorded
 * like a mesh. */
int pbrt_emit_subdiv(Parser *P, const Token *t, size_t n_faces, const int *n_verts, const int *idx,
                     size_t n_points, const float *pts, const float *uv);
/* Curves (the curve shape) under the current transform and material;
 * inside ObjectBegin skipped with one warning. */
int pbrt_emit_curves(Parser *P, const Token *t, const RayesCurves *c, const RayesPrimvar *pv,
                     size_t n_pv);
/* Grow the current Shape's bounds (object space; the world bound that a
 * camera's medium fills, pbrt_medium.c): by n points, by a quadric. */
void pbrt_grow_bound(Parser *P, const float *pts, size_t n);
void pbrt_grow_quadric(Parser *P, RayesQuadric q, const float *qp);
int pbrt_emit_quadric(Parser *P, const Token *t, RayesQuadric q, const float *qp, size_t n,
                      unsigned flags);
/* The bilinear patch of patch (its patch, patch_pv, patch_N, patch_uv). */
int pbrt_emit_patch(Parser *P, const Token *t, const Op *patch);
/* A light under m, sent at once (never recorded). */
int pbrt_emit_light(Parser *P, const Token *t, const double m[16], const char *type,
                    const RayesParam *params, size_t n);
/* A pattern (rayes_scene_pattern) in the space of the current transform;
 * the sink must have the pattern method. */
int pbrt_emit_pattern(Parser *P, const Token *t, const char *name, const char *type,
                      const RayesParam *params, size_t n);
/* A pattern (as pbrt_emit_pattern) in the space of m. */
int pbrt_emit_pattern_in(Parser *P, const Token *t, const double m[16], const char *name,
                         const char *type, const RayesParam *params, size_t n);
/* A volume (rayes_scene_volume) of the box bound in the space of m, with
 * the built-in "homogeneous" shader of these parameters; inside 1: only
 * inside the shape just sent (rayes_scene_volume_inside, when the sink
 * has it). The next shape sends its material again. The sink must have
 * the volume method. */
int pbrt_emit_volume(Parser *P, const Token *t, const double m[16], const RayesParam *params,
                     size_t n, const float bound[6], int inside);
/* Frees o's Ops. */
void pbrt_object_free(Object *o);
/* Sends the recorded object o under the current transform. */
int pbrt_replay(Parser *P, const Token *t, Object *o);

/* ------------------------------------------ materials (pbrt_material.c) */

/* A zeroed material of that shader, and a colour parameter added to it. */
void pbrt_mat_init(Material *m, const char *shader);
void pbrt_mat_color(Material *m, const char *name, const float c[3]);
/* The material named name, defined by a deferred MakeNamedMaterial read
 * again now if it must be (pbrt_defer.c); NULL if none is (no error), or
 * on error (then *r is -1). Valid until the next material is defined. */
const Material *pbrt_named_material(Parser *P, const char *name, int *r);

/* ----------------------------------------------------------- directives */

/* The handlers of pbrt.c's table that live in the other files: each reads
 * its directive's arguments after the directive's token t. */
int pbrt_d_colorspace(Parser *P, const Token *t); /* pbrt_options.c */
int pbrt_d_camera(Parser *P, const Token *t);
int pbrt_d_film(Parser *P, const Token *t);
int pbrt_d_sampler(Parser *P, const Token *t);
int pbrt_d_integrator(Parser *P, const Token *t);
int pbrt_d_filter(Parser *P, const Token *t);
int pbrt_d_worldbegin(Parser *P, const Token *t);
int pbrt_d_worldend(Parser *P, const Token *t);
int pbrt_d_material(Parser *P, const Token *t); /* pbrt_material.c */
int pbrt_d_makenamedmaterial(Parser *P, const Token *t);
int pbrt_d_namedmaterial(Parser *P, const Token *t);
int pbrt_d_texture(Parser *P, const Token *t);
/* A plymesh's "texture displacement" (pbrt-v4's: each vertex moved along
 * its normal by the float texture, in object space) into m, for that shape
 * alone: m->displaced 3 (4 for a texture that is a constant), scaled by the
 * current transform's uniform scale (world units). Returns 0 (nothing
 * given: m unchanged), or -1 (an error in P). */
int pbrt_shape_displacement(Parser *P, const Token *t, ParamList *pl, Material *m);
int pbrt_d_shape(Parser *P, const Token *t); /* pbrt_shape.c */
/* Forward references. pbrt-v4 makes its named materials and textures
 * after reading the whole file, so a file may name them before it defines
 * them. A Shape whose NamedMaterial is not defined yet is deferred (read
 * again at the file's end: pbrt_deferred_shapes), a MakeNamedMaterial
 * whose textures are not defined yet likewise (read again when a
 * NamedMaterial or a deferred shape first asks for it:
 * pbrt_named_material, pbrt_material.c). */
int pbrt_deferred_shapes(Parser *P);
/* How deep deferred materials (mixes of mixes) are read again inside one
 * another, at most: each level is a parse on the stack. */
#define PBRT_MAX_REREAD 64
/* pbrt_defer.c: appends the directive whose name t was read (at: its
 * lexer just after t; the graphics state as it is now), or NULL (an error
 * in P). */
Deferred *pbrt_defer(Parser *P, DeferList *list, const Lexer *at, const Token *t);
/* Reads directive d again with its handler fn, under the graphics state
 * gs; the parser's lexer and state are restored after. */
int pbrt_reread(Parser *P, const Deferred *d, const GState *gs,
                int (*fn)(Parser *P, const Token *t));
/* The error of gs's pending NamedMaterial, at it, in its file; -1. */
int pbrt_undefined_material(Parser *P, const GState *gs, const char *what);
void pbrt_defer_free(Parser *P);
int pbrt_d_arealight(Parser *P, const Token *t); /* pbrt_light.c */
/* An area light's radiance for the next shape, of n_prims pbrt shapes
 * (triangles, bilinear patches, one quadric) over `area` square units of
 * the world: with "power", each pbrt shape emits that power, as pbrt-v4
 * makes a light of each (L_base power n_prims / (pi area sides)); else
 * L_base. Sets P->gs.area.L. */
void pbrt_area_power(Parser *P, size_t n_prims, double area);
int pbrt_d_light(Parser *P, const Token *t);
int pbrt_d_makenamedmedium(Parser *P, const Token *t); /* pbrt_medium.c */
int pbrt_d_mediuminterface(Parser *P, const Token *t);
/* After a Shape: checks its MediumInterface's media (defined, and
 * renderable here, else a warning) and grows the camera medium's bounds. */
int pbrt_medium_shape(Parser *P, const Token *t);
/* The medium on one side of the Shape being read (side 0 its inside,
 * behind its normals; 1 its outside) that the shape bounds, or NULL: none,
 * the same on both sides, the camera's, or not renderable here. */
Medium *pbrt_medium_bounded(Parser *P, int side);
/* Grows md's box by the Shape just recorded into its bound. */
void pbrt_medium_grow(Parser *P, Medium *md, const Token *t);
/* At the end of the file: each medium's bound, seen by no ray, and its
 * volume inside it (rayes_scene_volume_inside). */
int pbrt_media_send(Parser *P);
/* Sends a medium's bound: its shapes as one object seen by no ray
 * (pbrt_emit.c). */
int pbrt_emit_bound(Parser *P, const Token *t, const Object *o);
/* After a medium's bound (sent hidden) and its volume: what follows is seen again
 * (pbrt_emit.c). */
int pbrt_shown_again(Parser *P, const Token *t);
/* At the end of the file: the camera's medium, if any, as a volume over
 * the scene's bounds and the camera. */
int pbrt_medium_camera(Parser *P);
/* Frees the media's arrays. */
void pbrt_media_free(Parser *P);

#endif /* RAYES_IO_PBRT_INTERNAL_H */
