/*
 * tests/io/test_pbrt.c — the pbrt-v4 reader of io/pbrt.h against a
 * recording IoSink: transforms and the camera matrix, the mapping of
 * materials and lights (measured: matte with a warning), quadrics,
 * instancing, plymesh, Include and Import through files written to
 * RAYES_TEST_TMP, filters and film types with their warnings, the Bitterli Cornell box from the
 * shared data (walls on the right sides as its camera sees them, the
 * ceiling light), and bad input with "file:line:col" errors.
 */
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "io/pbrt.h"
#include "rayes/rayes.h"

#include "test.h"
#include "test_stderr.h"

static const double PI_D = 3.14159265358979323846;

#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

/* ------------------------------------------------------------- the stub */

#define MAX_REC 64

typedef struct Shader {
    char name[32];
    int n;
    RayesParam p[24];
    char str[24][256];
    char names[24][32];
} Shader;

typedef struct Rec {
    float camera[16];
    int projection, n_camera;
    float fov;
    int have_screen;
    float screen[4];
    float xform[16];
    Shader shader;
    /* geometry, with the transform and shader current then */
    int n_meshes, n_quadrics, n_patches, n_area, n_lights, n_curves, n_mesh_lights;
    int n_quadric_lights;
    struct {
        RayesQuadric type;
        unsigned flags;
        int two_sided;
    } quadric_light[MAX_REC];
    struct {
        size_t n_faces, n_points;
        int two_sided, first[3]; /* the first face's indices */
        float L[3];
    } mesh_light[MAX_REC];
    struct {
        size_t n_faces, n_points;
        float centre[3]; /* mean of the points, object space */
        float xform[16];
        Shader shader;
        int first[4];    /* the first face's indices */
    } mesh[MAX_REC];
    struct {
        RayesQuadric type;
        float p[8];
        size_t n;
        unsigned flags;
        float xform[16];
    } quadric[MAX_REC];
    struct {
        float P[4][3], L[3], xform[16];
    } area[MAX_REC];
    struct {
        char type[32];
        Shader params; /* name unused */
        float xform[16];
    } light[MAX_REC];
    struct {
        char name[64], type[32];
        Shader params; /* name unused */
        float xform[16];
    } pattern[MAX_REC];
    int n_patterns;
    Shader displacement; /* the last set_displacement ("" name: none) */
    int primvars;        /* 1: an N was given, 2: an st */
    int bad_primvars;    /* primitive variables not per point */
    float N0[3], st0[2]; /* the last N and st call's first value */
} Rec;

static void copy_params(Shader *s, const char *name, const RayesParam *p, size_t n)
{
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name ? name : "");
    for (size_t i = 0; i < n && i < 24; i++) {
        s->p[i] = p[i];
        snprintf(s->names[i], sizeof s->names[i], "%s", p[i].name);
        s->p[i].name = s->names[i]; /* the caller's strings are borrowed */
        if (p[i].type == RAYES_PARAM_STRING || p[i].type == RAYES_PARAM_PATTERN) {
            snprintf(s->str[i], sizeof s->str[i], "%s", p[i].string);
            s->p[i].string = s->str[i];
        }
        s->n++;
    }
}

/* A parameter of a recorded shader (its pointers re-aimed at its own
 * copies, since the Shader may have been copied as a struct). */
static const RayesParam *param(const Shader *cs, const char *name)
{
    Shader *s = (Shader *)cs;
    for (int i = 0; i < s->n; i++) {
        s->p[i].name = s->names[i];
        if (s->p[i].type == RAYES_PARAM_STRING || s->p[i].type == RAYES_PARAM_PATTERN)
            s->p[i].string = s->str[i];
    }
    for (int i = 0; i < s->n; i++)
        if (strcmp(s->p[i].name, name) == 0)
            return &s->p[i];
    return NULL;
}

static RayesError r_camera(void *t, const float e[3], const float a[3], const float u[3], float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    return RAYES_ERROR_INVALID_OPERATION; /* the pbrt reader gives matrices */
}

static RayesError r_camera_matrix(void *t, const float m[16], RayesProjection proj, float fov,
                                  const float sw[4])
{
    Rec *r = t;
    memcpy(r->camera, m, sizeof r->camera);
    r->projection = proj;
    r->fov = fov;
    r->have_screen = sw != NULL;
    if (sw)
        memcpy(r->screen, sw, sizeof r->screen);
    r->n_camera++;
    return RAYES_OK;
}

static RayesError r_transform(void *t, const float m[16])
{
    memcpy(((Rec *)t)->xform, m, 16 * sizeof(float));
    return RAYES_OK;
}

static RayesError r_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    copy_params(&((Rec *)t)->shader, name, p, n);
    return RAYES_OK;
}

static RayesError r_displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    copy_params(&((Rec *)t)->displacement, name, p, n);
    return RAYES_OK;
}

static RayesError r_bound(void *t, float b)
{
    (void)t, (void)b;
    return RAYES_OK;
}

static RayesError r_search(void *t, const char *k, const char *p)
{
    (void)t, (void)k, (void)p;
    return RAYES_OK;
}

static RayesError r_rate(void *t, float r)
{
    (void)t, (void)r;
    return RAYES_OK;
}

/* Keeps the first value of N and st, and checks their counts (n). */
static void r_primvars(Rec *r, const RayesPrimvar *pv, size_t n_pv, size_t n)
{
    for (size_t i = 0; i < n_pv; i++) {
        int st = strcmp(pv[i].name, "st") == 0;
        if (pv[i].cls != RAYES_PRIMVAR_VERTEX || pv[i].count != n)
            r->bad_primvars++;
        memcpy(st ? r->st0 : r->N0, pv[i].data, (st ? 2 : 3) * sizeof(float));
        r->primvars |= st ? 2 : 1;
    }
}

static RayesError r_bilinear(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)P;
    ((Rec *)t)->n_patches++;
    r_primvars(t, pv, n_pv, 4);
    return RAYES_OK;
}

static RayesError r_bicubic(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)t, (void)P, (void)pv, (void)n_pv;
    return RAYES_OK;
}

static RayesError r_mesh(void *t, size_t n_faces, const int *nv, const int *idx, size_t n_points,
                         const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    Rec *r = t;
    r_primvars(r, pv, n_pv, n_points);
    size_t n_idx = 0;
    for (size_t f = 0; f < n_faces; f++) {
        if (nv[f] != 3 && nv[f] != 4)
            return RAYES_ERROR_INVALID_ARGUMENT;
        n_idx += (size_t)nv[f];
    }
    for (size_t i = 0; i < n_idx; i++)
        if (idx[i] < 0 || (size_t)idx[i] >= n_points)
            return RAYES_ERROR_INVALID_ARGUMENT;
    if (r->n_meshes < MAX_REC) {
        int k = r->n_meshes;
        r->mesh[k].n_faces = n_faces;
        r->mesh[k].n_points = n_points;
        for (int c = 0; c < 3; c++) {
            double s = 0;
            for (size_t i = 0; i < n_points; i++)
                s += P[3 * i + c];
            r->mesh[k].centre[c] = (float)(s / (double)n_points);
        }
        memcpy(r->mesh[k].xform, r->xform, sizeof r->xform);
        r->mesh[k].shader = r->shader;
        for (int i = 0; i < 4; i++)
            r->mesh[k].first[i] = i < nv[0] ? idx[i] : -1;
    }
    r->n_meshes++;
    return RAYES_OK;
}

static RayesError r_sphere(void *t, float radius)
{
    (void)t, (void)radius;
    return RAYES_OK;
}

static RayesError r_quadric(void *t, RayesQuadric type, const float *p, size_t n, unsigned flags)
{
    Rec *r = t;
    if (r->n_quadrics < MAX_REC && n <= 8) {
        int k = r->n_quadrics;
        r->quadric[k].type = type;
        memcpy(r->quadric[k].p, p, n * sizeof *p);
        r->quadric[k].n = n;
        r->quadric[k].flags = flags;
        memcpy(r->quadric[k].xform, r->xform, sizeof r->xform);
    }
    r->n_quadrics++;
    return RAYES_OK;
}

static RayesError r_area(void *t, const float P[4][3], const float L[3])
{
    Rec *r = t;
    if (r->n_area < MAX_REC) {
        memcpy(r->area[r->n_area].P, P, sizeof r->area[0].P);
        memcpy(r->area[r->n_area].L, L, sizeof r->area[0].L);
        memcpy(r->area[r->n_area].xform, r->xform, sizeof r->xform);
    }
    r->n_area++;
    return RAYES_OK;
}

static RayesError r_area_mesh(void *t, size_t n_faces, const int *nv, const int *idx,
                              size_t n_points, const float *P, const float L[3], int two_sided)
{
    Rec *r = t;
    (void)nv, (void)P;
    if (r->n_mesh_lights < MAX_REC) {
        r->mesh_light[r->n_mesh_lights].n_faces = n_faces;
        r->mesh_light[r->n_mesh_lights].n_points = n_points;
        r->mesh_light[r->n_mesh_lights].two_sided = two_sided;
        memcpy(r->mesh_light[r->n_mesh_lights].first, idx, sizeof(int[3]));
        memcpy(r->mesh_light[r->n_mesh_lights].L, L, sizeof(float[3]));
    }
    r->n_mesh_lights++;
    return RAYES_OK;
}

static RayesError r_area_quadric(void *t, RayesQuadric type, const float *p, size_t n,
                                 unsigned flags, const float L[3], int two_sided)
{
    Rec *r = t;
    (void)p, (void)n, (void)L;
    if (r->n_quadric_lights < MAX_REC) {
        r->quadric_light[r->n_quadric_lights].type = type;
        r->quadric_light[r->n_quadric_lights].flags = flags;
        r->quadric_light[r->n_quadric_lights].two_sided = two_sided;
    }
    r->n_quadric_lights++;
    return RAYES_OK;
}

static RayesError r_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    Rec *r = t;
    if (r->n_lights < MAX_REC) {
        snprintf(r->light[r->n_lights].type, sizeof r->light[0].type, "%s", type);
        copy_params(&r->light[r->n_lights].params, type, p, n);
        memcpy(r->light[r->n_lights].xform, r->xform, sizeof r->xform);
    }
    r->n_lights++;
    return RAYES_OK;
}

static RayesError r_pattern(void *t, const char *name, const char *type, const RayesParam *p,
                            size_t n)
{
    Rec *r = t;
    if (r->n_patterns < MAX_REC) {
        snprintf(r->pattern[r->n_patterns].name, sizeof r->pattern[0].name, "%s", name);
        snprintf(r->pattern[r->n_patterns].type, sizeof r->pattern[0].type, "%s", type);
        copy_params(&r->pattern[r->n_patterns].params, type, p, n);
        memcpy(r->pattern[r->n_patterns].xform, r->xform, sizeof r->xform);
    }
    r->n_patterns++;
    return RAYES_OK;
}

/* The recorded pattern of that name, or NULL. */
static int pattern_index(const Rec *r, const char *name)
{
    for (int i = 0; i < r->n_patterns && i < MAX_REC; i++)
        if (strcmp(r->pattern[i].name, name) == 0)
            return i;
    return -1;
}

static const char *r_error(void *t)
{
    (void)t;
    return "stub error";
}

static RayesError r_curves(void *t, const RayesCurves *c, const RayesPrimvar *pv, size_t n_pv)
{
    (void)c, (void)pv, (void)n_pv;
    ((Rec *)t)->n_curves++;
    return RAYES_OK;
}

static IoSink stub(Rec *r)
{
    memset(r, 0, sizeof *r);
    return (IoSink){.target = r,
                    .set_camera = r_camera,
                    .set_camera_matrix = r_camera_matrix,
                    .set_transform = r_transform,
                    .set_shader = r_shader,
                    .set_displacement = r_displacement,
                    .set_displacement_bound = r_bound,
                    .set_search_path = r_search,
                    .set_shading_rate = r_rate,
                    .bilinear_patch = r_bilinear,
                    .bicubic_patch = r_bicubic,
                    .polygon_mesh = r_mesh,
                    .sphere = r_sphere,
                    .quadric = r_quadric,
                    .area_light = r_area,
                    .area_light_mesh = r_area_mesh,
                    .area_light_quadric = r_area_quadric,
                    .light = r_light,
                    .get_error = r_error,
                    .pattern = r_pattern,
                    .curves = r_curves};
}

/* Parses text from an exact-size heap copy; err gets the message. */
static RayesError parse_with(const char *name, const char *text, const IoReadOptions *opt, Rec *r,
                             IoSettings *s, char *err, size_t n)
{
    size_t size = strlen(text);
    unsigned char *copy = malloc(size ? size : 1);
    memcpy(copy, text, size);
    IoSink sink = stub(r);
    io_settings_init(s);
    RayesError e = io_pbrt_parse(name, copy, size, &sink, opt, s, err, n);
    free(copy);
    if (e != RAYES_OK)
        fprintf(stderr, "  (parse: %s)\n", err);
    return e;
}

static RayesError parse(const char *name, const char *text, Rec *r, IoSettings *s, char *err,
                        size_t n)
{
    return parse_with(name, text, NULL, r, s, err, n);
}

/* m p for a point p (row-major m). */
static void xform_point(const float m[16], const float p[3], float out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
}

/* ------------------------------------------------------------- tests */

static void test_cornell_box(void)
{
    Rec *r = malloc(sizeof *r);
    IoSink sink = stub(r);
    IoSettings s;
    io_settings_init(&s);
    char err[512] = "";
    RayesError e = io_pbrt_read(RAYES_TEST_DATA "/scenes/pbrt-bitterli/cornell-box/scene-v4.pbrt",
                                &sink, NULL, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    if (e != RAYES_OK) {
        fprintf(stderr, "%s\n", err);
        free(r);
        return;
    }
    CHECK(s.width == 512 && s.height == 512 && s.spp == 1);
    CHECK(s.bounces == 8 && s.specular_depth == 64); /* maxdepth 65: diffuse capped */
    CHECK(s.n_displays == 1 && strcmp(s.displays[0].name, "cornell-box.exr") == 0);
    CHECK(r->n_camera == 1 && r->projection == RAYES_PROJECTION_PERSPECTIVE);
    CHECK_NEAR(r->fov, 19.5, 1e-6);
    CHECK(!r->have_screen);
    /* camera_from_world: the file's Transform, given column by column */
    static const float want[16] = {1, 0, 0, 0, 0, 1, 0, -1, 0, 0, -1, 6.8f, 0, 0, 0, 1};
    for (int i = 0; i < 16; i++)
        CHECK_NEAR(r->camera[i], want[i], 1e-6);
    CHECK(r->n_meshes == 7); /* floor, ceiling, back, right, left, two boxes */
    int red = 0, green = 0, white = 0;
    for (int k = 0; k < r->n_meshes && k < MAX_REC; k++) {
        const RayesParam *refl = param(&r->mesh[k].shader, "reflectance");
        CHECK(strcmp(r->mesh[k].shader.name, "diffuse") == 0 && refl);
        if (!refl)
            continue;
        float world[3], cam[3];
        xform_point(r->mesh[k].xform, r->mesh[k].centre, world);
        xform_point(r->camera, world, cam);
        float x_screen = cam[0] / cam[2]; /* + is the right of the image */
        if (fabs(refl->value[0] - 0.63) < 1e-6) {
            red++;
            CHECK_NEAR(refl->value[1], 0.065, 1e-6);
            CHECK_NEAR(refl->value[2], 0.05, 1e-6);
            CHECK(x_screen < -0.1); /* the red wall is on the left */
        } else if (fabs(refl->value[0] - 0.14) < 1e-6) {
            green++;
            CHECK_NEAR(refl->value[1], 0.45, 1e-6);
            CHECK_NEAR(refl->value[2], 0.091, 1e-6);
            CHECK(x_screen > 0.1); /* the green wall on the right */
        } else {
            white++;
            CHECK_NEAR(refl->value[0], 0.725, 1e-6);
            CHECK_NEAR(refl->value[1], 0.71, 1e-6);
            CHECK_NEAR(refl->value[2], 0.68, 1e-6);
        }
    }
    CHECK(red == 1 && green == 1 && white == 5);
    /* the light: one quad from the two triangles, in the ceiling, emitting down */
    CHECK(r->n_area == 1);
    if (r->n_area == 1) {
        CHECK_NEAR(r->area[0].L[0], 17, 0);
        CHECK_NEAR(r->area[0].L[1], 12, 0);
        CHECK_NEAR(r->area[0].L[2], 4, 0);
        float(*P)[3] = r->area[0].P;
        for (int k = 0; k < 4; k++)
            CHECK_NEAR(P[k][1], 1.98, 1e-6);
        float a[3], b[3];
        for (int c = 0; c < 3; c++)
            a[c] = P[1][c] - P[0][c], b[c] = P[2][c] - P[0][c];
        CHECK(a[2] * b[0] - a[0] * b[2] < 0); /* (P1 - P0) x (P2 - P0) points down (-y) */
    }
    free(r);
}

static void test_transforms(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *text =
        "LookAt 0 0 -5  0 0 0  0 1 0\n"
        "Camera \"perspective\" \"float fov\" 45 \"float screenwindow\" [-1 1 -0.5 0.5]\n"
        "Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" [32]\n"
        "WorldBegin\n"
        "AttributeBegin\n"
        "  Translate 1 2 3\n"
        "  Scale 2 2 2\n"
        "  Shape \"sphere\" \"float radius\" 0.5\n"
        "AttributeEnd\n"
        "AttributeBegin\n"
        "  Rotate 90 0 0 1\n"
        "  ReverseOrientation\n"
        "  Shape \"disk\" \"float height\" 0.25 \"float radius\" 2 \"float phimax\" 180\n"
        "AttributeEnd\n"
        "Transform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\n"
        "Shape \"cylinder\"\n"
        "CoordSysTransform \"camera\"\n"
        "Shape \"sphere\"\n";
    RayesError e = parse("t.pbrt", text, r, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(s.width == 64 && s.height == 32);
    CHECK_NEAR(r->fov, 45, 1e-6);
    CHECK(r->have_screen && r->screen[2] == -0.5f && r->screen[3] == 0.5f);
    /* LookAt from -z toward the origin: camera z is world z, x is world -x... pbrt's
     * left-handed convention: right = up x dir = (0,1,0) x (0,0,1) = (1,0,0) */
    static const float cam[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 5, 0, 0, 0, 1};
    for (int i = 0; i < 16; i++)
        CHECK_NEAR(r->camera[i], cam[i], 1e-6);
    CHECK(r->n_quadrics == 4);
    if (r->n_quadrics == 4) {
        CHECK(r->quadric[0].type == RAYES_QUADRIC_SPHERE && r->quadric[0].n == 4);
        CHECK_NEAR(r->quadric[0].p[0], 0.5, 0);
        CHECK_NEAR(r->quadric[0].p[1], -0.5, 0);
        CHECK_NEAR(r->quadric[0].p[3], 360, 0);
        CHECK(r->quadric[0].flags == 0);
        CHECK_NEAR(r->quadric[0].xform[0], 2, 1e-6);
        CHECK_NEAR(r->quadric[0].xform[3], 1, 1e-6);
        CHECK_NEAR(r->quadric[0].xform[7], 2, 1e-6);
        CHECK_NEAR(r->quadric[0].xform[11], 3, 1e-6);
        CHECK(r->quadric[1].type == RAYES_QUADRIC_DISK && r->quadric[1].n == 3);
        CHECK_NEAR(r->quadric[1].p[0], 0.25, 0);
        CHECK_NEAR(r->quadric[1].p[1], 2, 0);
        CHECK_NEAR(r->quadric[1].p[2], 180, 0);
        CHECK(r->quadric[1].flags == RAYES_QUADRIC_REVERSE);
        CHECK_NEAR(r->quadric[1].xform[1], -1, 1e-6); /* Rotate 90 about z: x' = -y */
        CHECK_NEAR(r->quadric[1].xform[4], 1, 1e-6);
        CHECK(r->quadric[2].type == RAYES_QUADRIC_CYLINDER);
        CHECK_NEAR(r->quadric[2].xform[3], 5, 1e-6); /* Transform: column-major */
        CHECK_NEAR(r->quadric[2].xform[7], 6, 1e-6);
        CHECK_NEAR(r->quadric[2].xform[11], 7, 1e-6);
        /* the camera's coordinate system: world_from_camera puts the origin at the eye */
        CHECK_NEAR(r->quadric[3].xform[11], -5, 1e-6);
    }
    /* Scale -1 1 1 before LookAt mirrors: camera x is world -x then */
    e = parse("t.pbrt", "Scale -1 1 1\nLookAt 0 0 -5 0 0 0 0 1 0\nCamera \"perspective\"\n"
                        "WorldBegin\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK_NEAR(r->camera[0], -1, 1e-6);
    CHECK_NEAR(r->fov, 90, 1e-6);
    CHECK(s.width == 1280 && s.height == 720); /* pbrt's default film */
    free(r);
}

static void test_materials(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *text =
        "Sampler \"halton\" \"integer pixelsamples\" 8\n"
        "Integrator \"volpath\" \"integer maxdepth\" 1\n"
        "PixelFilter \"gaussian\" \"float xradius\" 1\n"
        "WorldBegin\n"
        "Texture \"grid\" \"spectrum\" \"imagemap\" \"string filename\" \"tex/grid.png\"\n"
        "  \"string wrap\" \"clamp\"\n"
        "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.2 0.4 0.6]\n"
        "MakeNamedMaterial \"b\" \"string type\" \"diffuse\" \"float reflectance\" 1\n"
        "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"\n"
        "  \"float uroughness\" 0.1 \"float vroughness\" 0.3\n"
        "Shape \"sphere\"\n"
        "Material \"dielectric\" \"float eta\" 1.33\n"
        "Shape \"sphere\"\n"
        "Material \"coateddiffuse\" \"rgb reflectance\" [0.1 0.2 0.3] \"float roughness\" 0.05\n"
        "Shape \"sphere\"\n"
        "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0.25\n"
        "Shape \"sphere\"\n"
        "Material \"hair\" \"float eumelanin\" 1.3\n"
        "Shape \"sphere\"\n"
        "Material \"diffuse\" \"texture reflectance\" \"grid\" \"float nonsense\" 3\n"
        "Shape \"sphere\"\n"
        "Material \"conductor\" \"rgb reflectance\" [0.9 0.8 0.7]\n"
        "Shape \"sphere\"\n"
        "Material \"diffuse\" \"blackbody reflectance\" 6500\n"
        "Shape \"sphere\"\n"
        "Material \"conductor\" \"float roughness\" 0.1 \"bool remaproughness\" false\n"
        "Shape \"sphere\"\n"
        "Material \"interface\"\n" /* a medium's boundary: not a surface, left out */
        "Shape \"sphere\"\n";
    /* a small mesh after each Material (the stub records shaders with meshes) */
    char full[8192] = "";
    const char *tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    for (const char *p = text; *p;) {
        const char *q = strstr(p, "Shape \"sphere\"\n");
        if (!q) {
            strncat(full, p, sizeof full - strlen(full) - 1);
            break;
        }
        strncat(full, p, (size_t)(q - p));
        strncat(full, tri, sizeof full - strlen(full) - 1);
        p = q + strlen("Shape \"sphere\"\n");
    }
    RayesError e = parse("dir/t.pbrt", full, r, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(s.spp == 8 && s.bounces == 0 && s.specular_depth == 1);
    CHECK(s.filter == RAYES_FILTER_GAUSSIAN && s.filter_width == 2.0f);
    CHECK(r->n_meshes == 9);
    if (r->n_meshes != 9) {
        free(r);
        return;
    }
    const Shader *sh = &r->mesh[0].shader;
    CHECK(strcmp(sh->name, "conductor") == 0);
    CHECK(param(sh, "eta") && fabs(param(sh, "eta")->value[2] - 1.442) < 1e-3);
    CHECK(param(sh, "k") && fabs(param(sh, "k")->value[0] - 3.983) < 1e-3);
    /* anisotropic: the alphas' geometric mean, sqrt(0.1) sqrt(0.3), squared */
    CHECK(param(sh, "roughness") && fabs(param(sh, "roughness")->value[0] - sqrt(0.03)) < 1e-6);
    sh = &r->mesh[1].shader;
    CHECK(strcmp(sh->name, "dielectric") == 0 && param(sh, "eta") &&
          fabs(param(sh, "eta")->value[0] - 1.33) < 1e-6);
    sh = &r->mesh[2].shader;
    CHECK(strcmp(sh->name, "coateddiffuse") == 0 && param(sh, "reflectance") &&
          fabs(param(sh, "reflectance")->value[2] - 0.3) < 1e-6);
    sh = &r->mesh[3].shader; /* mix of two diffuse: blended, 0.75 a + 0.25 b */
    CHECK(strcmp(sh->name, "diffuse") == 0 && param(sh, "reflectance") &&
          fabs(param(sh, "reflectance")->value[0] - (0.75 * 0.2 + 0.25)) < 1e-6);
    /* hair: pbrt's BSDF, coloured by its melanin (sigma_a and reflectance
     * unset, so the shader takes the concentrations) */
    CHECK(strcmp(r->mesh[4].shader.name, "physicalhair") == 0);
    const RayesParam *hs = param(&r->mesh[4].shader, "sigma_a");
    const RayesParam *hb = param(&r->mesh[4].shader, "beta_m");
    CHECK(hs && hs->value[0] < 0.0f && param(&r->mesh[4].shader, "eumelanin") &&
          fabsf(param(&r->mesh[4].shader, "eumelanin")->value[0] - 1.3f) < 1e-6f);
    CHECK(hb && fabsf(hb->value[0] - 0.3f) < 1e-6f);
    sh = &r->mesh[5].shader; /* an image texture: a pattern on the reflectance */
    CHECK(strcmp(sh->name, "diffuse") == 0 && param(sh, "reflectance") &&
          param(sh, "reflectance")->type == RAYES_PARAM_PATTERN &&
          strcmp(param(sh, "reflectance")->string, "0:grid") == 0);
    int g = pattern_index(r, "0:grid");
    CHECK(g >= 0 && strcmp(r->pattern[g].type, "imagemap") == 0 &&
          param(&r->pattern[g].params, "filename") &&
          strcmp(param(&r->pattern[g].params, "filename")->string, "dir/tex/grid.png") == 0);
    CHECK(g >= 0 && param(&r->pattern[g].params, "wrap") &&
          strcmp(param(&r->pattern[g].params, "wrap")->string, "clamp") == 0);
    sh = &r->mesh[6].shader;
    CHECK(strcmp(sh->name, "conductor") == 0 && param(sh, "reflectance") && !param(sh, "eta"));
    sh = &r->mesh[7].shader; /* 6500 K: nearly white, normalised to a maximum of 1 */
    CHECK(param(sh, "reflectance") && fabs(param(sh, "reflectance")->value[0] - 1) < 0.05 &&
          fabs(param(sh, "reflectance")->value[2] - 1) < 0.1);
    /* remaproughness false: 0.1 is alpha itself, rayes' roughness alpha^2 */
    sh = &r->mesh[8].shader;
    CHECK(param(sh, "roughness") && fabs(param(sh, "roughness")->value[0] - 0.01) < 1e-7);
    free(r);
}

static void test_lights(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *text =
        "WorldBegin\n"
        "LightSource \"point\" \"rgb I\" [1 2 3] \"float scale\" 4 \"point3 from\" [0 5 0]\n"
        "LightSource \"spot\" \"point3 from\" [0 0 0] \"point3 to\" [0 -1 0] \"float coneangle\" "
        "20\n"
        "LightSource \"distant\" \"point3 from\" [0 1 0] \"point3 to\" [0 0 0] \"blackbody L\" "
        "3000\n"
        "LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3] \"string filename\" \"sky.exr\"\n"
        "LightSource \"goniometric\" \"string filename\" \"x.exr\"\n"
        "AttributeBegin\n"
        "  AreaLightSource \"diffuse\" \"rgb L\" [2 2 2] \"float scale\" 3\n"
        "  Translate 0 1 0\n"
        "  Shape \"sphere\" \"float radius\" 0.25\n"
        "  Shape \"disk\" \"float radius\" 0.5\n"
        "  Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"
        "  Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n"
        "  Shape \"cylinder\" \"float radius\" 0.1\n"
        "  Shape \"sphere\" \"float zmin\" 0\n"
        "  ReverseOrientation\n"
        "  Shape \"sphere\"\n"
        "AttributeEnd\n"
        "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n";
    RayesError e = parse("t.pbrt", text, r, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(r->n_lights == 7);
    if (r->n_lights == 7) {
        CHECK(strcmp(r->light[0].type, "pointlight") == 0);
        const Shader *p = &r->light[0].params;
        CHECK(param(p, "intensity") && param(p, "intensity")->value[0] == 4);
        CHECK(param(p, "lightcolor") && param(p, "lightcolor")->value[2] == 3);
        CHECK(param(p, "from") && param(p, "from")->value[1] == 5);
        p = &r->light[1].params;
        CHECK(strcmp(r->light[1].type, "spotlight") == 0 && param(p, "coneangle") &&
              param(p, "coneangle")->value[0] == 20 && param(p, "beamdistribution") &&
              param(p, "beamdistribution")->value[0] == 0);
        p = &r->light[2].params;
        CHECK(strcmp(r->light[2].type, "distantlight") == 0 && param(p, "lightcolor") &&
              param(p, "lightcolor")->value[0] > 1 && param(p, "lightcolor")->value[2] < 0.5);
        if (param(p, "lightcolor")) { /* a blackbody light: luminance 1, as pbrt-v4's */
            const float *c = param(p, "lightcolor")->value;
            CHECK_NEAR(0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2], 1.0, 1e-5);
        }
        CHECK(strcmp(r->light[3].type, "environmentlight") == 0);
        p = &r->light[3].params;
        CHECK(param(p, "mapping") && strcmp(param(p, "mapping")->string, "octahedral") == 0);
        CHECK(param(p, "mapname") && strstr(param(p, "mapname")->string, "sky.exr") != NULL);
        CHECK(strcmp(r->light[4].type, "pointlight") == 0); /* goniometric: a map */
        p = &r->light[4].params;
        CHECK(param(p, "mapping") && strcmp(param(p, "mapping")->string, "octahedral") == 0);
        CHECK(param(p, "mapname") && strstr(param(p, "mapname")->string, "x.exr") != NULL);
        CHECK(strcmp(r->light[5].type, "arealight") == 0); /* the sphere */
        p = &r->light[5].params;
        CHECK(param(p, "shape") && strcmp(param(p, "shape")->string, "sphere") == 0);
        CHECK(param(p, "radius") && param(p, "radius")->value[0] == 0.25f);
        CHECK(param(p, "lightcolor") && param(p, "lightcolor")->value[0] == 6);
        CHECK_NEAR(r->light[5].xform[7], 1, 0);
        CHECK(strcmp(r->light[6].type, "arealight") == 0 && param(&r->light[6].params, "shape") &&
              strcmp(param(&r->light[6].params, "shape")->string, "disk") == 0);
    }
    CHECK(r->n_area == 1 && r->n_patches == 1); /* the emitting patch, then a plain one */
    CHECK(r->n_curves == 1);                     /* a curve under an area light does not emit */
    /* a cylinder, a half sphere and an inward sphere: quadric lights */
    CHECK(r->n_quadric_lights == 3);
    if (r->n_quadric_lights == 3) {
        CHECK(r->quadric_light[0].type == RAYES_QUADRIC_CYLINDER && !r->quadric_light[0].flags);
        CHECK(r->quadric_light[1].type == RAYES_QUADRIC_SPHERE);
        CHECK(r->quadric_light[2].flags == RAYES_QUADRIC_REVERSE);
    }
    if (r->n_area == 1) {
        CHECK_NEAR(r->area[0].L[1], 6, 0);
        float(*P)[3] = r->area[0].P; /* around the patch: p00 p10 p11 p01, normal +z */
        CHECK(P[2][0] == 1 && P[2][1] == 1 && P[3][0] == 0 && P[3][1] == 1);
    }
    free(r);
}

static void test_instances_include_ply(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "", path[512], text[2048];
    snprintf(path, sizeof path, "%s/test_pbrt_quad.ply", RAYES_TEST_TMP);
    test_write_text(path, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                          "property float y\nproperty float z\nelement face 1\n"
                          "property list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    snprintf(path, sizeof path, "%s/test_pbrt_inc.pbrt", RAYES_TEST_TMP);
    test_write_text(path,
                    "# included\nShape \"plymesh\" \"string filename\" \"test_pbrt_quad.ply\"\n");
    snprintf(text, sizeof text,
             "WorldBegin\n"
             "ObjectBegin \"thing\"\n"
             "  Translate 0 0 1\n"
             "  Shape \"sphere\"\n"
             "  Include \"test_pbrt_inc.pbrt\"\n"
             "ObjectEnd\n"
             "Translate 10 0 0\n"
             "ObjectInstance \"thing\"\n"
             "Translate 10 0 0\n"
             "ObjectInstance \"thing\"\n"
             "AttributeBegin\n"
             "  Scale -1 1 1\n"
             "  Include \"test_pbrt_inc.pbrt\"\n"
             "AttributeEnd\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    RayesError e = parse(path, text, r, &s, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(r->n_quadrics == 2 && r->n_meshes == 3);
    if (r->n_quadrics == 2 && r->n_meshes == 3) {
        CHECK_NEAR(r->quadric[0].xform[3], 10, 0);
        CHECK_NEAR(r->quadric[0].xform[11], 1, 0);
        CHECK_NEAR(r->quadric[1].xform[3], 20, 0);
        CHECK_NEAR(r->mesh[1].xform[3], 20, 0);
        CHECK(r->mesh[0].n_faces == 1 && r->mesh[0].n_points == 4);
        CHECK(r->mesh[0].first[1] == 1); /* counter-clockwise as given */
        CHECK(r->mesh[2].first[1] == 3); /* mirrored: the winding flips, as pbrt's normal does */
    }
    /* an emitting plymesh quad becomes an area light */
    snprintf(text, sizeof text,
             "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" true\n"
             "Include \"test_pbrt_inc.pbrt\"\n");
    e = parse(path, text, r, &s, err, sizeof err);
    CHECK(e == RAYES_OK && r->n_area == 2 && r->n_meshes == 0);
    /* an error inside an included file names that file */
    snprintf(path, sizeof path, "%s/test_pbrt_bad.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "\n  Shape \"sphere\" \"float radius\" [ \"x\" ]\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_bad.pbrt\"\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE && strstr(err, "test_pbrt_bad.pbrt:2:35: expected a float "
                                                "value for \"radius\"") != NULL);
    /* pbrt-v4 reads one stream of tokens: a directive that ends an
     * included file takes the parameters that follow the Include, and an
     * error after it names the including file again */
    snprintf(path, sizeof path, "%s/test_pbrt_tail.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "Shape \"sphere\"");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_tail.pbrt\"\n  \"float radius\" 3\n"
                    "Shape \"sphere\"\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_OK && r->n_quadrics == 2);
    if (e == RAYES_OK && r->n_quadrics == 2) {
        CHECK_NEAR(r->quadric[0].p[0], 3, 0);
        CHECK_NEAR(r->quadric[1].p[0], 1, 0);
    }
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_tail.pbrt\"\n  \"float radius\" [ \"x\" ]\n",
              r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE && strstr(err, "test_pbrt_main.pbrt:3:") != NULL);
    /* gzip-compressed files read as plain ones (pbrt-v4-scenes' hair.pbrt.gz) */
    snprintf(path, sizeof path, "%s/test_pbrt_gz.pbrt.gz", RAYES_TEST_TMP);
    gzFile gz = gzopen(path, "wb");
    CHECK(gz != NULL);
    if (gz) {
        gzputs(gz, "Shape \"sphere\" \"float radius\" 2\n");
        gzclose(gz);
    }
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_gz.pbrt.gz\"\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_OK && r->n_quadrics == 1);
    if (e == RAYES_OK && r->n_quadrics == 1)
        CHECK_NEAR(r->quadric[0].p[0], 2, 0);
    /* relative paths, inside included files too, are relative to the
     * directory of the file given (pbrt-v4's search directory), not to the
     * including file's */
    char sub[512];
    snprintf(sub, sizeof sub, "%s/test_pbrt_sub", RAYES_TEST_TMP);
    mkdir(sub, 0777);
    snprintf(path, sizeof path, "%s/test_pbrt_sub/a.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "Include \"test_pbrt_sub/b.pbrt\"\n"
                          "Shape \"plymesh\" \"string filename\" \"test_pbrt_quad.ply\"\n");
    snprintf(path, sizeof path, "%s/test_pbrt_sub/b.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "Shape \"plymesh\" \"string filename\" \"test_pbrt_quad.ply\"\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_sub/a.pbrt\"\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_OK && r->n_meshes == 2);
    /* a file including itself stops at the depth limit */
    snprintf(path, sizeof path, "%s/test_pbrt_self.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "Include \"test_pbrt_self.pbrt\"\nInclude \"test_pbrt_self.pbrt\"\n");
    e = parse(path, "WorldBegin\nInclude \"test_pbrt_self.pbrt\"\n", r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE && strstr(err, "nested Include") != NULL);
    free(r);
}

static void expect_error(const char *text, const char *want)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    RayesError e = parse("t.pbrt", text, r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE);
    CHECK(strstr(err, want) != NULL && !strchr(err, '\n'));
    if (!strstr(err, want))
        fprintf(stderr, "  got \"%s\", wanted \"%s\"\n", err, want);
    free(r);
}

static void test_errors(void)
{
    expect_error("", "t.pbrt: expected WorldBegin");
    expect_error("WorldBegin\n  Bogus 1\n", "t.pbrt:2:3: expected a directive");
    expect_error("Translate 1 2\nWorldBegin\n", "t.pbrt:2:1: expected a number (Translate x y z)");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius [1]\n",
                 "t.pbrt:2:16: expected a closing quote");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius\" [1\n",
                 "t.pbrt:3:1: expected a value or \"]\"");
    expect_error("WorldBegin\nShape \"sphere\" \"real radius\" 1\n",
                 "t.pbrt:2:16: expected a parameter type");
    expect_error("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                 "  \"integer indices\" [0 1 3]\n",
                 "t.pbrt:3:3: trianglemesh: index 2 is 3 but P has 3 points");
    expect_error("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0]\n",
                 "t.pbrt:2:22: expected a multiple of 3 values");
    /* a NamedMaterial is looked up at its shapes, at the file's end */
    expect_error("WorldBegin\nNamedMaterial \"nope\"\nShape \"sphere\"\n",
                 "t.pbrt:2:15: NamedMaterial: expected a material defined");
    expect_error("WorldBegin\nNamedMaterial \"n\"\nObjectBegin \"o\"\nShape \"sphere\"\n",
                 "t.pbrt:2:15: NamedMaterial: expected a material defined with MakeNamedMaterial "
                 "before an ObjectBegin's shapes");
    expect_error("WorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"diffuse\" \"texture "
                 "reflectance\" \"t\"\nNamedMaterial \"m\"\n",
                 "t.pbrt:2:47: expected the name of a texture defined before, found \"t\"");
    expect_error("WorldBegin\nAttributeEnd\n", "t.pbrt:2:1: AttributeEnd without a matching");
    expect_error("WorldBegin\nCamera \"perspective\"\n", "t.pbrt:2:1: expected this directive before "
                 "WorldBegin");
    expect_error("Shape \"sphere\"\n", "t.pbrt:1:1: expected WorldBegin before this directive");
    expect_error("WorldBegin\nObjectBegin \"a\"\n", "ObjectBegin \"a\" has no ObjectEnd");
    expect_error("WorldBegin\nObjectInstance \"b\"\n", "t.pbrt:2:16: ObjectInstance: expected an "
                 "object");
    expect_error("WorldBegin\nShape \"plymesh\" \"string filename\" \"/nonexistent.ply\"\n",
                 "t.pbrt:2:1: plymesh: /nonexistent.ply: cannot open");
    expect_error("WorldBegin\nShape \"sphere\" \"integer radius\" 1.5\n",
                 "t.pbrt:2:33: expected an integer");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius\" 1e999\n",
                 "t.pbrt:2:31: expected a value for \"float radius\", found \"1e999\"");
    /* an escaped newline in a name stays out of the one-line message (fuzz finding) */
    expect_error("WorldBegin\nNamedMaterial \"a\\nb\"\nShape \"sphere\"\n", "found \"a?b\"");
    expect_error("WorldBegin\nRotate 90 0 0 0\n", "t.pbrt:2:1: Rotate: expected a nonzero axis");
    expect_error("WorldBegin\nTexture \"a\" \"colour\" \"constant\"\n",
                 "t.pbrt:2:1: Texture \"a\": expected the type \"spectrum\" or \"float\"");
    expect_error(
        "WorldBegin\nTexture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"x.png\"\n"
        "  \"string encoding\" \"gamma\"\n",
        "t.pbrt:3:3: imagemap: expected encoding \"sRGB\", \"linear\" or \"gamma G\"");
    expect_error("WorldBegin\nTexture \"a\" \"spectrum\" \"scale\" \"texture tex\" \"b\"\n",
                 "t.pbrt:2:32: expected the name of a texture defined before");
    expect_error("WorldBegin\nTexture \"a\" \"float\" \"checkerboard\" \"integer dimension\" 4\n",
                 "checkerboard: expected dimension 2 or 3, found 4");
}

/* Every texture class and every textured material parameter: patterns
 * of the right class and parameters, parameters bound to them, with no
 * warning but the one for two different anisotropic roughness textures. */
static const char *const texture_text =
    "WorldBegin\n"
    "Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 4\n"
    "  \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1]\n"
    "Translate 1 2 3\n"
    "Texture \"cubes\" \"float\" \"checkerboard\" \"integer dimension\" 3\n"
    "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"grid.png\"\n"
    "  \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.5 \"float vdelta\" 0.25\n"
    "  \"bool invert\" true \"string encoding\" \"gamma 2.2\" \"float scale\" 0.5\n"
    "  \"string filter\" \"ewa\"\n"
    "Texture \"bump\" \"float\" \"imagemap\" \"string filename\" \"h.exr\"\n"
    "Texture \"sc\" \"spectrum\" \"scale\" \"texture tex\" \"img\" \"float scale\" 2\n"
    "Texture \"mx\" \"spectrum\" \"mix\" \"texture tex1\" \"checks\" \"texture tex2\" \"sc\"\n"
    "  \"texture amount\" \"cubes\"\n"
    "Texture \"dm\" \"spectrum\" \"directionmix\" \"texture tex1\" \"mx\" \"vector3 dir\" [0 0 1]\n"
    "Texture \"bl\" \"spectrum\" \"bilerp\" \"rgb v00\" [1 0 0] \"rgb v11\" [0 1 0]\n"
    "Texture \"dt\" \"spectrum\" \"dots\" \"rgb inside\" [1 1 0]\n"
    "Texture \"fb\" \"float\" \"fbm\" \"integer octaves\" 4 \"float roughness\" 0.6\n"
    "Texture \"wr\" \"float\" \"wrinkled\"\n"
    "Texture \"wi\" \"float\" \"windy\"\n"
    "Texture \"ma\" \"spectrum\" \"marble\" \"float variation\" 0.3\n"
    "Texture \"k\" \"float\" \"constant\" \"float value\" 0.25\n"
    "Material \"conductor\" \"texture eta\" \"dm\" \"texture k\" \"bl\" \"texture roughness\" "
    "\"cubes\"\n"
    "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
    "Material \"conductor\" \"texture reflectance\" \"dt\" \"texture roughness\" \"fb\"\n"
    "  \"bool remaproughness\" false\n"
    "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
    "Material \"coateddiffuse\" \"texture reflectance\" \"ma\" \"texture roughness\" \"wr\"\n"
    "  \"texture thickness\" \"wi\" \"texture displacement\" \"bump\"\n"
    "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
    "Material \"dielectric\" \"texture uroughness\" \"fb\" \"texture vroughness\" \"wr\"\n"
    "  \"texture displacement\" \"k\"\n"
    "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";

typedef struct TextureRun {
    Rec *r;
    RayesError e;
} TextureRun;

static void run_textures(void *arg)
{
    TextureRun *tr = arg;
    IoSettings s;
    char err[512] = "";
    tr->e = parse("dir/t.pbrt", texture_text, tr->r, &s, err, sizeof err);
}

/* The pattern a recorded parameter names, or -1. */
static int bound_pattern(const Rec *r, const Shader *sh, const char *name)
{
    const RayesParam *p = param(sh, name);
    return p && p->type == RAYES_PARAM_PATTERN ? pattern_index(r, p->string) : -1;
}

static void test_textures(void)
{
    Rec *r = malloc(sizeof *r);
    TextureRun tr = {r, RAYES_OK};
    const char *said = test_stderr_of(run_textures, &tr);
    CHECK(tr.e == RAYES_OK);
    /* the one expected warning, and none of the old ones */
    CHECK(strstr(said, "textured uroughness and vroughness become one") != NULL);
    CHECK(strstr(said, "not supported") == NULL && strstr(said, "average") == NULL);
    if (strstr(said, "not supported"))
        fprintf(stderr, "%s", said);
    CHECK(r->n_patterns == 15); /* 13 textures (not the constant), a squared and a mean roughness */
    CHECK(r->n_meshes == 4);
    if (tr.e != RAYES_OK || r->n_meshes != 4) {
        free(r);
        return;
    }
    int c = pattern_index(r, "0:checks");
    CHECK(c >= 0 && strcmp(r->pattern[c].type, "checkerboard") == 0 &&
          param(&r->pattern[c].params, "uscale")->value[0] == 8 &&
          param(&r->pattern[c].params, "tex2")->value[2] == 1);
    int cu = pattern_index(r, "1:cubes"); /* 3-D: in the space of its transform */
    CHECK(cu >= 0 && param(&r->pattern[cu].params, "dimension")->value[0] == 3 &&
          r->pattern[cu].xform[3] == 1 && r->pattern[cu].xform[7] == 2);
    int im = pattern_index(r, "2:img");
    CHECK(im >= 0 &&
          strcmp(param(&r->pattern[im].params, "filename")->string, "dir/grid.png") == 0);
    CHECK(im >= 0 && param(&r->pattern[im].params, "invert")->value[0] == 1 &&
          strcmp(param(&r->pattern[im].params, "encoding")->string, "gamma 2.2") == 0 &&
          param(&r->pattern[im].params, "vdelta")->value[0] == 0.25f &&
          !param(&r->pattern[im].params, "channel"));
    int b = pattern_index(r, "3:bump"); /* a float image: its first channel */
    CHECK(b >= 0 && param(&r->pattern[b].params, "channel") &&
          param(&r->pattern[b].params, "channel")->value[0] == 0);
    int mx = pattern_index(r, "5:mx");
    CHECK(mx >= 0 && param(&r->pattern[mx].params, "amount")->type == RAYES_PARAM_PATTERN &&
          strcmp(param(&r->pattern[mx].params, "tex2")->string, "4:sc") == 0);
    int dm = pattern_index(r, "6:dm");
    CHECK(dm >= 0 && param(&r->pattern[dm].params, "dir") &&
          param(&r->pattern[dm].params, "dir")->value[2] == 1);
    /* conductor: eta, k and roughness bound */
    const Shader *sh = &r->mesh[0].shader;
    CHECK(strcmp(sh->name, "conductor") == 0 && bound_pattern(r, sh, "eta") >= 0 &&
          strcmp(r->pattern[bound_pattern(r, sh, "k")].type, "bilerp") == 0 &&
          bound_pattern(r, sh, "roughness") == cu);
    /* alpha given (remaproughness false): rayes' roughness is its square */
    sh = &r->mesh[1].shader;
    int sq = bound_pattern(r, sh, "roughness");
    CHECK(strcmp(param(sh, "reflectance")->string, "8:dt") == 0 && sq >= 0 &&
          strcmp(r->pattern[sq].type, "scale") == 0 &&
          strcmp(param(&r->pattern[sq].params, "tex")->string, "9:fb") == 0 &&
          strcmp(param(&r->pattern[sq].params, "scale")->string, "9:fb") == 0);
    sh = &r->mesh[2].shader;
    CHECK(strcmp(sh->name, "coateddiffuse") == 0 && bound_pattern(r, sh, "reflectance") >= 0 &&
          bound_pattern(r, sh, "roughness") >= 0 && bound_pattern(r, sh, "thickness") >= 0);
    sh = &r->mesh[3].shader; /* two roughness textures: their mean */
    int mean = bound_pattern(r, sh, "roughness");
    CHECK(mean >= 0 && strcmp(r->pattern[mean].type, "mix") == 0);
    /* the last displacement: a constant texture is a constant amount */
    CHECK(strcmp(r->displacement.name, "displace") == 0 &&
          param(&r->displacement, "amount")->type == RAYES_PARAM_FLOAT &&
          param(&r->displacement, "amount")->value[0] == 0.25f);
    /* pbrt-v4's material displacement is a bump map */
    CHECK(param(&r->displacement, "__bump") && param(&r->displacement, "__bump")->value[0] == 1);
    free(r);
}

/* coatedconductor: its conductor's parameters, textures included, make the
 * conductor it maps to, under its coat. */
static void test_coated_conductor_textures(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *text =
        "WorldBegin\n"
        "Texture \"c\" \"float\" \"checkerboard\" \"float tex1\" 0.01 \"float tex2\" 0.3\n"
        "Material \"coatedconductor\" \"texture conductor.roughness\" \"c\"\n"
        "  \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_meshes == 1);
    const Shader *sh = &r->mesh[0].shader;
    CHECK(strcmp(sh->name, "conductor") == 0 && param(sh, "roughness") &&
          param(sh, "roughness")->type == RAYES_PARAM_PATTERN &&
          strcmp(param(sh, "roughness")->string, "0:c") == 0);
    CHECK(param(sh, "eta") && fabs(param(sh, "eta")->value[2] - 1.442) < 1e-3);
    /* the coat: pbrt's interface roughness (0 by default) and eta (1.5) */
    CHECK(param(sh, "coat") && param(sh, "coat")->value[0] == 1.0f);
    CHECK(param(sh, "coat_roughness") && param(sh, "coat_roughness")->value[0] == 0.0f);
    CHECK(param(sh, "coat_eta") && param(sh, "coat_eta")->value[0] == 1.5f);
    text = "WorldBegin\nMaterial \"coatedconductor\" \"float interface.roughness\" 0.1 "
           "\"float interface.eta\" 1.6\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK && r->n_meshes == 1);
    sh = &r->mesh[0].shader;
    CHECK(param(sh, "coat_roughness") && fabsf(param(sh, "coat_roughness")->value[0] - 0.1f) < 1e-6f);
    CHECK(param(sh, "coat_eta") && fabsf(param(sh, "coat_eta")->value[0] - 1.6f) < 1e-6f);
    free(r);
}

/* trianglemesh, bilinearmesh and plymesh pass N and uv per point, as
 * vertex-class N and st with t = 1 - v; instanced meshes keep them. */
static void test_normals_and_uv(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "", path[512];
    CHECK(parse("t.pbrt", "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] "
                          "\"integer indices\" [0 1 2] \"normal N\" [0 0.6 0.8 0 0 1 0 0 1] "
                          "\"point2 uv\" [0.25 0.125 1 0 0 1]\n", r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->primvars == 3 && r->bad_primvars == 0);
    CHECK_NEAR(r->N0[1], 0.6, 1e-6);
    CHECK_NEAR(r->st0[0], 0.25, 0);
    CHECK_NEAR(r->st0[1], 0.875, 0);
    CHECK(parse("t.pbrt", "WorldBegin\nObjectBegin \"o\"\nShape \"bilinearmesh\" \"point3 P\" "
                          "[0 0 0 1 0 0 0 1 0 1 1 0] \"point2 uv\" [0.5 0 1 0 0 1 1 1]\n"
                          "ObjectEnd\nObjectInstance \"o\"\n", r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_patches == 1 && r->primvars == 2 && r->bad_primvars == 0);
    CHECK_NEAR(r->st0[0], 0.5, 0);
    CHECK_NEAR(r->st0[1], 1, 0);
    snprintf(path, sizeof path, "%s/test_pbrt_nuv.ply", RAYES_TEST_TMP);
    test_write_text(path,
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                    "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
                    "property float nz\nproperty float u\nproperty float v\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n"
                    "0 0 0 0 0 1 0.5 0.25\n1 0 0 0 0 1 1 0\n0 1 0 0 0 1 0 1\n3 0 1 2\n");
    char text[1024];
    snprintf(text, sizeof text, "WorldBegin\nShape \"plymesh\" \"string filename\" \"%s\"\n",
             path);
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->primvars == 3 && r->bad_primvars == 0);
    CHECK_NEAR(r->N0[2], 1, 0);
    CHECK_NEAR(r->st0[1], 0.75, 0);
    free(r);
}

/* Filters: each of pbrt's, with its radius or pbrt's default radius
 * (rayes' width is the diameter). */
static void test_filters(void)
{
    static const struct {
        const char *text;
        int filter;
        float width;
    } cases[] = {
        {"PixelFilter \"box\"\n", RAYES_FILTER_BOX, 1.0f},
        {"PixelFilter \"gaussian\"\n", RAYES_FILTER_GAUSSIAN, 3.0f},
        {"PixelFilter \"triangle\" \"float xradius\" 1\n", RAYES_FILTER_TRIANGLE, 2.0f},
        {"PixelFilter \"triangle\"\n", RAYES_FILTER_TRIANGLE, 4.0f},
        {"PixelFilter \"mitchell\" \"float B\" 0.3 \"float C\" 0.3\n", RAYES_FILTER_MITCHELL, 4.0f},
        {"PixelFilter \"sinc\" \"float tau\" 3\n", RAYES_FILTER_LANCZOS, 8.0f},
        {"PixelFilter \"lanczos\"\n", RAYES_FILTER_LANCZOS, 8.0f},
        {"PixelFilter \"lanczos\" \"float xradius\" 2 \"float yradius\" 2\n", RAYES_FILTER_LANCZOS,
         4.0f},
        {"PixelFilter \"gaussian\" \"float sigma\" 0.5 \"float xradius\" 1\n",
         RAYES_FILTER_GAUSSIAN, 2.0f},
        {"PixelFilter \"mitchell\"\n", RAYES_FILTER_MITCHELL, 4.0f},
    };
    Rec *r = malloc(sizeof *r);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[256], err[512] = "";
        snprintf(text, sizeof text, "%sWorldBegin\n", cases[k].text);
        IoSettings s;
        CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
        CHECK(s.filter == cases[k].filter);
        CHECK_NEAR(s.filter_width, cases[k].width, 1e-6);
    }
    free(r);
}

/* A parse with standard error captured (stderr_of's argument). */
typedef struct ParseRun {
    const char *name, *text;
    const IoReadOptions *opt; /* NULL: none */
    Rec *r;
    IoSettings s;
    RayesError e;
    char err[512];
} ParseRun;

static void run_parse(void *arg)
{
    ParseRun *pr = arg;
    pr->err[0] = '\0';
    pr->e = parse_with(pr->name, pr->text, pr->opt, pr->r, &pr->s, pr->err, sizeof pr->err);
}

/* Import reads a file as Include does (pbrt-v4 allows it only for shapes
 * and named things, which rayes does not enforce), relative to the
 * directory of the file given, and its errors name the imported file. */
static void test_import(void)
{
    Rec *r = malloc(sizeof *r);
    char path[512];
    snprintf(path, sizeof path, "%s/test_pbrt_import.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "# imported\nShape \"sphere\" \"float radius\" 2\n"
                          "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n");
    snprintf(path, sizeof path, "%s/test_pbrt_import_bad.pbrt", RAYES_TEST_TMP);
    test_write_text(path, "\nShape \"sphere\" \"float radius\" [ \"x\" ]\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    ParseRun pr = {.name = path,
                   .r = r,
                   .text = "WorldBegin\nTranslate 0 0 5\nImport \"test_pbrt_import.pbrt\"\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_quadrics == 1 && r->n_meshes == 1);
    CHECK(strstr(said, "warning") == NULL);
    if (r->n_quadrics == 1) {
        CHECK_NEAR(r->quadric[0].p[0], 2, 0);
        CHECK_NEAR(r->quadric[0].xform[11], 5, 0); /* the importing file's transform applies */
    }
    pr.text = "WorldBegin\nImport \"test_pbrt_import_bad.pbrt\"\n";
    test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_ERROR_PARSE &&
          strstr(pr.err, "test_pbrt_import_bad.pbrt:2:33: expected a float value") != NULL);
    pr.text = "WorldBegin\nImport \"test_pbrt_none.pbrt\"\n";
    test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_ERROR_PARSE && strstr(pr.err, "Import: ") != NULL &&
          strstr(pr.err, "test_pbrt_none.pbrt") != NULL);
    free(r);
}

/* Film "gbuffer" and "spectral" are written as rgb films: resolution,
 * file name and crop window kept, one warning at the directive. */
static void test_film_types(void)
{
    static const char *const types[] = {"gbuffer", "spectral"};
    Rec *r = malloc(sizeof *r);
    for (size_t k = 0; k < 2; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "Sampler \"halton\"\nFilm \"%s\" \"integer xresolution\" 64 "
                 "\"integer yresolution\" 32 \"string filename\" \"out.exr\"\n"
                 "  \"float cropwindow\" [0 0.5 0 1]\nWorldBegin\n",
                 types[k]);
        ParseRun pr = {.name = "t.pbrt", .text = text, .r = r};
        const char *said = test_stderr_of(run_parse, &pr);
        CHECK(pr.e == RAYES_OK);
        CHECK(pr.s.width == 64 && pr.s.height == 32);
        CHECK(pr.s.n_displays == 1 && strcmp(pr.s.displays[0].name, "out.exr") == 0 &&
              strcmp(pr.s.displays[0].type, "openexr") == 0);
        CHECK_NEAR(pr.s.crop[1], 0.5, 0);
        char want[128];
        snprintf(want, sizeof want,
                 k == 0 ? "t.pbrt:2:1: Film \"%s\": N and P are written in world space"
                        : "t.pbrt:2:1: Film \"%s\": written as an rgb film",
                 types[k]);
        /* gbuffer's channels are rayes's AOVs */
        CHECK(strcmp(pr.s.displays[0].mode, k == 0 ? "rgba,albedo,z,N,P" : "rgba") == 0);
        CHECK(strstr(said, want) != NULL);
        if (!strstr(said, want))
            fprintf(stderr, "  got \"%s\"\n", said);
    }
    free(r);
}

/* An infinite light's "portal" (pbrt-v4 samples the window only) is not
 * dropped silently: one warning at the directive, the light still made. */
static void test_portal_warns(void)
{
    Rec *r = malloc(sizeof *r);
    ParseRun pr = {.name = "t.pbrt",
                   .r = r,
                   .text =
                       "WorldBegin\n"
                       "LightSource \"infinite\" \"point3 portal\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_lights == 1);
    CHECK(strstr(said, "t.pbrt:2:1: LightSource \"infinite\": \"portal\" is not used") != NULL);
    free(r);
}

/* measured (a tabulated BSDF file rayes does not read) becomes matte with
 * one warning naming the type at the directive; the shape under it keeps
 * its geometry. */
static void test_measured_material(void)
{
    Rec *r = malloc(sizeof *r);
    ParseRun pr = {
        .name = "t.pbrt",
        .r = r,
        .text = "WorldBegin\n"
                "Material \"measured\" \"string filename\" \"bsdfs/ilm_l3_37_metallic.bsdf\"\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_meshes == 2);
    if (r->n_meshes == 2)
        CHECK(strcmp(r->mesh[0].shader.name, "matte") == 0 &&
              strcmp(r->mesh[1].shader.name, "matte") == 0);
    const char *w = strstr(said, "t.pbrt:2:1: material \"measured\" is not supported; using matte");
    CHECK(w != NULL);
    CHECK(w == NULL ||
          strstr(strchr(w, '\n') ? strchr(w, '\n') : w, "measured") == NULL); /* once */
    if (!w)
        fprintf(stderr, "  got \"%s\"\n", said);
    free(r);
}

/* "normalmap": a linear imagemap pattern bound to the shader's
 * "normalmap"; a material drawn by a shader without one warns. */
static void test_normal_map(void)
{
    Rec *r = malloc(sizeof *r);
    ParseRun pr = {.name = "t.pbrt",
                   .r = r,
                   .text = "WorldBegin\n"
                           "Material \"coateddiffuse\" \"string normalmap\" \"nm.png\"\n"
                           "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                           "Material \"hair\" \"string normalmap\" \"nm.png\"\n"
                           "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_meshes == 2);
    if (r->n_meshes == 2) {
        const RayesParam *nm = param(&r->mesh[0].shader, "normalmap");
        CHECK(nm && nm->type == RAYES_PARAM_PATTERN);
        CHECK(param(&r->mesh[1].shader, "normalmap") == NULL);
    }
    CHECK(strstr(said, "t.pbrt:4:1: \"normalmap\" on a material rayes draws as \"physicalhair\"") !=
          NULL);
    free(r);
}

/* Emitters: a square of two triangles is one quad light; a lone
 * triangle, and a mesh of more than four quads, one mesh light each, wound
 * to face as pbrt's normals (here ReverseOrientation turns the second). */
static void test_triangle_light(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[256];
    char text[2048];
    int n = snprintf(text, sizeof text,
                     "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\n"
                     "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                     "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] "
                     "\"integer indices\" [0 1 2 0 2 3]\n"
                     "AreaLightSource \"diffuse\" \"rgb L\" [3 3 3] \"bool twosided\" true\n"
                     "ReverseOrientation\nShape \"bilinearmesh\" \"point3 P\" [");
    for (int k = 0; k < 12; k++) /* a strip of 5 quads */
        n += snprintf(text + n, sizeof text - (size_t)n, "%d %d 0 ", k / 2, k % 2);
    n += snprintf(text + n, sizeof text - (size_t)n, "] \"integer indices\" [");
    for (int k = 0; k < 5; k++)
        n += snprintf(text + n, sizeof text - (size_t)n, "%d %d %d %d ", 2 * k, 2 * k + 2,
                      2 * k + 1, 2 * k + 3);
    snprintf(text + n, sizeof text - (size_t)n,
             "]\n"
             "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0 2 0 0 2 1 0] "
             "\"integer indices\" [0 1 2  1 3 2  1 4 3  4 5 3  0 2 3  0 4 5]\n");
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_area == 1 && r->n_mesh_lights == 3);
    if (r->n_area == 1 && r->n_mesh_lights == 3) {
        CHECK(r->area[0].L[0] == 2.0f);
        CHECK(r->mesh_light[0].n_faces == 1 && r->mesh_light[0].L[0] == 2.0f);
        const int want[3] = {0, 1, 2};
        CHECK(memcmp(r->mesh_light[0].first, want, sizeof want) == 0 &&
              !r->mesh_light[0].two_sided);
        CHECK(r->mesh_light[1].n_faces == 5 && r->mesh_light[1].two_sided &&
              r->mesh_light[1].L[0] == 3.0f);
        const int strip[3] = {0, 1, 3}; /* ReverseOrientation: 0 2 3 1 turned */
        CHECK(memcmp(r->mesh_light[1].first, strip, sizeof strip) == 0);
        CHECK(r->mesh_light[2].n_faces == 6 && r->mesh_light[2].two_sided);
        const int turned[3] = {0, 2, 1};
        CHECK(memcmp(r->mesh_light[2].first, turned, sizeof turned) == 0);
    }
    free(r);
}

/* "power" on area lights (pbrt-v4: each triangle, patch or quadric emits
 * it): a square of two triangles, a lone triangle, a two-sided one, a
 * sphere scaled twice; on point lights 4 pi watts of an rgb colour keep
 * the colour's own luminance, as pbrt's do. */
static void test_light_power(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[256];
    CHECK(parse("t.pbrt",
                "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 1] \"float power\" 100\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 2 0 0 2 2 0 0 2 0] "
                "\"integer indices\" [0 1 2 0 2 3]\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 2 0 0 0 2 0]\n"
                "AreaLightSource \"diffuse\" \"float power\" 100 \"bool twosided\" true\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 2 0 0 0 2 0]\n"
                "AreaLightSource \"diffuse\" \"float power\" 100\n"
                "Scale 2 2 2\nShape \"sphere\"\n"
                "LightSource \"point\" \"rgb I\" [2 2 2] \"float power\" 12.566371\n",
                r, &s, err, sizeof err) == RAYES_OK);
    const double tri = 100 / (PI_D * 2); /* each triangle of area 2 emits 100 */
    CHECK(r->n_area == 1 && r->n_mesh_lights == 2 && r->n_lights == 2);
    if (r->n_area == 1 && r->n_mesh_lights == 2 && r->n_lights == 2) {
        CHECK_NEAR(r->area[0].L[0], tri, 1e-4);
        CHECK_NEAR(r->area[0].L[1], 2 * tri, 1e-4);
        CHECK_NEAR(r->mesh_light[0].L[0], tri, 1e-4);
        CHECK_NEAR(r->mesh_light[1].L[0], tri / 2, 1e-4); /* two-sided: half each side */
        const RayesParam *c = param(&r->light[0].params, "lightcolor");
        CHECK(c && fabs(c->value[0] - 100 / (PI_D * 16 * PI_D)) < 1e-4); /* area 16 pi */
        const RayesParam *in = param(&r->light[1].params, "intensity");
        CHECK(in && fabs(in->value[0] - 1) < 1e-5);
    }
    free(r);
}

/* A disk with an inner radius: an annulus, RenderMan's hyperboloid of the
 * line from the rim in (facing as the disk); without, a disk. */
static void test_annulus(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[256];
    CHECK(parse("t.pbrt",
                "WorldBegin\nShape \"disk\" \"float radius\" 2 \"float innerradius\" 0.5 "
                "\"float height\" 0.25\nShape \"disk\" \"float radius\" 2\n",
                r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_quadrics == 2);
    if (r->n_quadrics == 2) {
        CHECK(r->quadric[0].type == RAYES_QUADRIC_HYPERBOLOID && r->quadric[0].n == 7);
        const float want[7] = {2, 0, 0.25f, 0.5f, 0, 0.25f, 360};
        for (int k = 0; k < 7; k++)
            CHECK(r->quadric[0].p[k] == want[k]);
        CHECK(r->quadric[1].type == RAYES_QUADRIC_DISK);
    }
    free(r);
}

/* thindielectric: rayes's thin glass sheet, its eta, and no warning. */
static void test_thin_dielectric(void)
{
    Rec *r = malloc(sizeof *r);
    ParseRun pr = {.name = "t.pbrt",
                   .r = r,
                   .text = "WorldBegin\n"
                           "Material \"thindielectric\" \"float eta\" 1.4\n"
                           "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_meshes == 1);
    if (r->n_meshes == 1) {
        const Shader *sh = &r->mesh[0].shader;
        CHECK(strcmp(sh->name, "thindielectric") == 0 && param(sh, "eta") &&
              fabs(param(sh, "eta")->value[0] - 1.4) < 1e-6);
    }
    CHECK(strstr(said, "thindielectric") == NULL);
    free(r);
}

/* Filter parameters rayes does not use are said once, at the directive;
 * an unknown filter keeps the default with a warning. */
static void test_filter_warnings(void)
{
    static const struct {
        const char *text, *want;
    } cases[] = {
        {"PixelFilter \"lanczos\" \"float tau\" 2\nWorldBegin\n",
         "t.pbrt:1:1: PixelFilter \"lanczos\": rayes' Mitchell has B = C = 1/3 and its sinc tau = "
         "3"},
        {"PixelFilter \"mitchell\" \"float B\" 0\nWorldBegin\n",
         "t.pbrt:1:1: PixelFilter \"mitchell\": rayes' Mitchell has B = C = 1/3"},
        {"PixelFilter \"blackman\"\nWorldBegin\n",
         "t.pbrt:1:1: PixelFilter \"blackman\" is not supported; using the renderer's default"},
        {"PixelFilter \"triangle\" \"float xradius\" 1.5\nWorldBegin\n", NULL},
    };
    Rec *r = malloc(sizeof *r);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ParseRun pr = {.name = "t.pbrt", .text = cases[k].text, .r = r};
        const char *said = test_stderr_of(run_parse, &pr);
        CHECK(pr.e == RAYES_OK);
        CHECK(cases[k].want ? strstr(said, cases[k].want) != NULL
                            : strstr(said, "warning") == NULL);
        if (cases[k].want && !strstr(said, cases[k].want))
            fprintf(stderr, "  got \"%s\"\n", said);
    }
    free(r);
}

/* uroughness and vroughness become one isotropic lobe, the geometric
 * mean of their alphas; when they differ the reader says so once, at the
 * first material's directive, naming the file and line. */
static void test_anisotropic_roughness(void)
{
    Rec *r = malloc(sizeof *r);
    ParseRun pr = {
        .name = "t.pbrt",
        .r = r,
        .text = "WorldBegin\n"
                "Material \"conductor\" \"float uroughness\" 0.01 \"float vroughness\" 0.04\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                "Material \"conductor\" \"float uroughness\" 0.1 \"float vroughness\" 0.4\n"
                "  \"bool remaproughness\" false\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                "Material \"conductor\" \"float uroughness\" 0.2 \"float vroughness\" 0.2\n"
                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"};
    const char *said = test_stderr_of(run_parse, &pr);
    CHECK(pr.e == RAYES_OK && r->n_meshes == 3);
    const char *w = strstr(said, "t.pbrt:2:1: uroughness 0.01 and vroughness 0.04 differ");
    CHECK(w != NULL);
    CHECK(w == NULL || strstr(strchr(w, '\n') ? strchr(w, '\n') : w, "differ") == NULL); /* once */
    if (!w)
        fprintf(stderr, "  got \"%s\"\n", said);
    if (r->n_meshes == 3) {
        const RayesParam *a = param(&r->mesh[0].shader, "roughness");
        const RayesParam *b = param(&r->mesh[1].shader, "roughness");
        const RayesParam *c = param(&r->mesh[2].shader, "roughness");
        CHECK(a && b && c);
        if (a && b && c) {
            CHECK_NEAR(a->value[0], 0.02, 1e-6);      /* alphas 0.1, 0.2: mean sqrt(0.02) */
            CHECK_NEAR(b->value[0], 0.1 * 0.4, 1e-6); /* alphas given: their product */
            CHECK_NEAR(c->value[0], 0.2, 1e-6);
        }
    }
    free(r);
}

/* Camera "realistic": a thin lens of its lens file's focal length (the
 * 22 mm wide-angle lens of pbrt-v4-scenes, paraxially 22.02 mm), its field
 * of view over the film's shorter side (pbrt's 35 mm diagonal); a missing
 * lens file is an error naming it. */
static void test_realistic_camera(void)
{
    test_write_text(
        "test_pbrt_lens.dat",
        "# radius sep n aperture\n35.98738 1.21638 1.54 23.716\n11.69718 9.9957 1 17.996\n"
        "13.08714 5.12622 1.772 12.364\n-22.63294 1.76924 1.617 9.812\n"
        "71.05802 0.8184 1 9.152\n0 2.27766 0 8.756\n-9.58584 2.43254 1.617 8.184\n"
        "-11.28864 0.11506 1 9.152\n-166.7765 3.09606 1.713 10.648\n"
        "-7.5911 1.32682 1.805 11.44\n-16.7662 3.98068 1 12.276\n"
        "-7.70286 1.21638 1.617 13.42\n-11.97328 0 1 17.996\n");
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    CHECK(
        parse("t.pbrt",
              "Camera \"realistic\" \"string lensfile\" \"test_pbrt_lens.dat\" \"float "
              "focusdistance\" 1e6 \"float aperturediameter\" 0\n"
              "Film \"rgb\" \"integer xresolution\" 160 \"integer yresolution\" 120\nWorldBegin\n",
              r, &s, err, sizeof err) == RAYES_OK);
    /* 2 atan(35 * 120 / 200 / 2 / 22.0235) */
    CHECK_NEAR(r->fov, 2 * atan(21.0 / 2 / 22.0235) * 180 / M_PI, 0.02);
    ParseRun pr = {.name = "t.pbrt",
                   .text = "Camera \"realistic\" \"string lensfile\" \"no-such-lens.dat\"\n",
                   .r = r};
    test_stderr_of(run_parse, &pr);
    CHECK(pr.e != RAYES_OK && strstr(pr.err, "no-such-lens.dat") != NULL);
    remove("test_pbrt_lens.dat");
    free(r);
}

/* Forward references, as pbrt-v4 allows them (it makes named materials
 * and textures after reading the file): a NamedMaterial before its
 * MakeNamedMaterial (its shapes wait for the file's end, in their own
 * transform and area light), a MakeNamedMaterial before its texture (read
 * again when first used), a mix before its materials; a NamedMaterial that
 * no shape follows is no error. */
static void test_forward_references(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *text =
        "WorldBegin\n"
        "AttributeBegin\n"
        "  NamedMaterial \"later\"\n"
        "  AreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\n"
        "  Translate 0 5 0\n"
        "  Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 0 1] \"integer indices\" [0 1 2]\n"
        "AttributeEnd\n"
        "NamedMaterial \"never\"\n"
        "Material \"diffuse\"\n"
        "Shape \"sphere\"\n"
        "MakeNamedMaterial \"tex\" \"string type\" \"diffuse\" \"texture reflectance\" \"c\"\n"
        "MakeNamedMaterial \"mixed\" \"string type\" \"mix\" \"string materials\" [\"tex\" "
        "\"later\"]\n"
        "Texture \"c\" \"spectrum\" \"checkerboard\"\n"
        "MakeNamedMaterial \"later\" \"string type\" \"conductor\"\n"
        "NamedMaterial \"tex\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n"
        "NamedMaterial \"mixed\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n";
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_quadrics == 1 && r->n_meshes == 2 && r->n_mesh_lights == 1);
    if (r->n_meshes == 2) {
        const RayesParam *refl = param(&r->mesh[0].shader, "reflectance");
        CHECK(strcmp(r->mesh[0].shader.name, "diffuse") == 0 && refl &&
              refl->type == RAYES_PARAM_PATTERN);
        CHECK(strcmp(r->mesh[1].shader.name, "mix") == 0);
    }
    if (r->n_mesh_lights == 1) /* the emitter, read at the end under its own state */
        CHECK(r->mesh_light[0].L[0] == 2);
    /* a chain of mixes each defined before its part: read again nested, up to
     * a depth (64, PBRT_MAX_REREAD: each level is a parse on the stack), then
     * an error */
    for (int depth = 10; depth <= 100; depth += 90) {
        size_t cap = 200 * (size_t)depth + 256, len = 0;
        char *chain = malloc(cap);
        len +=
            (size_t)snprintf(chain + len, cap - len,
                             "WorldBegin\nMakeNamedMaterial \"d\" \"string type\" \"diffuse\"\n");
        for (int k = 0; k < depth; k++)
            len += (size_t)snprintf(chain + len, cap - len,
                                    "MakeNamedMaterial \"m%d\" \"string type\" \"mix\" \"string "
                                    "materials\" [\"m%d\" \"d\"]\n",
                                    k, k + 1);
        snprintf(chain + len, cap - len,
                 "MakeNamedMaterial \"m%d\" \"string type\" \"diffuse\"\nNamedMaterial \"m0\"\n"
                 "Shape \"sphere\"\n",
                 depth);
        ParseRun pr = {.name = "t.pbrt", .text = chain, .r = r};
        test_stderr_of(run_parse, &pr);
        CHECK(depth < 64 ? pr.e == RAYES_OK : pr.e != RAYES_OK && strstr(pr.err, "nest more than"));
        free(chain);
    }
    free(r);
}

/* A perspective row in the transform: dropped for a light that only
 * turns directions (pbrt-v4-scenes' sssdragon sky), kept for a shape
 * (which the scene refuses: it sends geometry through infinity). */
static void test_projective_transform(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
#define PROJECTIVE "ConcatTransform [-0.22 0 -0.97 0 -0.97 0 0.22 0 0 1 0 8.87 0 0 0 1]\n"
    CHECK(parse("t.pbrt",
                "WorldBegin\n" PROJECTIVE "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                "LightSource \"distant\"\n",
                r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_lights == 2);
    if (r->n_lights == 2)
        CHECK(r->light[0].xform[14] == 0 && r->light[0].xform[15] == 1 &&
              r->light[0].xform[6] == 1 && r->light[1].xform[14] == 0);
    /* a shape keeps it (the scene refuses it: tests/scene) */
    CHECK(parse("t.pbrt", "WorldBegin\n" PROJECTIVE "Shape \"sphere\"\n", r, &s, err, sizeof err) ==
          RAYES_OK);
    CHECK(r->quadric[0].xform[14] > 8.8f);
#undef PROJECTIVE
    free(r);
}

/* maxdepth: maxdepth - 1 diffuse bounces up to 8 and maxdepth as the
 * specular depth up to 64; past the cap one warning at the directive,
 * unless the caller sets the bounces itself (rayes --bounces). */
static void test_maxdepth(void)
{
    static const struct {
        int depth, bounces, specular, warns;
    } cases[] = {{0, 0, 0, 0},   {1, 0, 1, 0},   {5, 4, 5, 0},    {9, 8, 9, 0},
                 {10, 8, 10, 1}, {65, 8, 64, 1}, {1000, 8, 64, 1}};
    Rec *r = malloc(sizeof *r);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[128];
        snprintf(text, sizeof text, "Integrator \"path\" \"integer maxdepth\" %d\nWorldBegin\n",
                 cases[k].depth);
        ParseRun pr = {.name = "t.pbrt", .text = text, .r = r};
        const char *said = test_stderr_of(run_parse, &pr);
        CHECK(pr.e == RAYES_OK);
        CHECK(pr.s.bounces == cases[k].bounces && pr.s.specular_depth == cases[k].specular);
        CHECK((strstr(said, "t.pbrt:1:1: Integrator \"maxdepth\"") != NULL) == cases[k].warns);
        if (cases[k].warns) {
            char not [64];
            snprintf(not, sizeof not, ": 8 diffuse bounces, not %d ", cases[k].depth - 1);
            CHECK(strstr(said, not ) != NULL);
        }
        IoReadOptions given = {.frame = -1, .bounces_given = 1};
        pr.opt = &given;
        said = test_stderr_of(run_parse, &pr);
        CHECK(pr.e == RAYES_OK && pr.s.specular_depth == cases[k].specular);
        CHECK(strstr(said, "maxdepth") == NULL);
    }
    /* no Integrator: pbrt-v4's volpath with maxdepth 5 */
    ParseRun none = {.name = "t.pbrt", .text = "WorldBegin\n", .r = r};
    run_parse(&none);
    CHECK(none.e == RAYES_OK && none.s.bounces == 4 && none.s.specular_depth == 5);
    free(r);
}

/* Spectrum files (.spd), relative to the scene's directory: RGB at 650,
 * 550, 450 nm of the piecewise linear spectrum; a malformed one is an
 * error naming the file. */
static void test_spectrum_files(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "", path[512];
    snprintf(path, sizeof path, "%s/test_pbrt_refl.spd", RAYES_TEST_TMP);
    test_write_text(path, "# reflectance\n400 0.1\n500 0.3\n600 0.5\n700 0.9 # red end\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    RayesError e = parse(path,
                         "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" "
                         "\"test_pbrt_refl.spd\"\nShape \"trianglemesh\" \"point3 P\" "
                         "[0 0 0 1 0 0 0 1 0]\n",
                         r, &s, err, sizeof err);
    CHECK(e == RAYES_OK && r->n_meshes == 1);
    const Shader *sh = r->n_meshes == 1 ? &r->mesh[0].shader : NULL;
    const RayesParam *refl = sh ? param(sh, "reflectance") : NULL;
    CHECK(refl != NULL);
    if (refl) {
        CHECK_NEAR(refl->value[0], 0.7, 1e-6); /* 650 nm */
        CHECK_NEAR(refl->value[1], 0.4, 1e-6); /* 550 nm */
        CHECK_NEAR(refl->value[2], 0.2, 1e-6); /* 450 nm */
    }
    snprintf(path, sizeof path, "%s/test_pbrt_bad.spd", RAYES_TEST_TMP);
    test_write_text(path, "400 0.1\n500\n");
    snprintf(path, sizeof path, "%s/test_pbrt_main.pbrt", RAYES_TEST_TMP);
    e = parse(path,
              "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"test_pbrt_bad.spd\"\n",
              r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE && strstr(err, "test_pbrt_bad.spd: expected") != NULL);
    e = parse(path, "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"none.spd\"\n",
              r, &s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE && strstr(err, "none.spd") != NULL);
    free(r);
}

/* pbrt-v4's subsurface (memo 6.2): a named medium (Jensen's, by name in
 * any case), reflectance and mfp, sigma_a and sigma_s reduced by g; scale
 * becomes unitlength 1 / scale; an unknown medium is an error at its
 * line. */
static void test_subsurface_material(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    const char *tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    char text[2048];
    snprintf(text, sizeof text,
             "WorldBegin\n"
             "Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 4\n%s"
             "Material \"subsurface\" \"rgb reflectance\" [0.8 0.5 0.3] \"rgb mfp\" [2 1 0.5]\n%s"
             "Material \"subsurface\" \"rgb sigma_a\" [0.1 0.2 0.3] \"rgb sigma_s\" [2 2 2] "
             "\"float g\" 0.5 \"float eta\" 1.5\n%s",
             tri, tri, tri);
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_meshes == 3);
    if (r->n_meshes == 3) {
        const Shader *sh = &r->mesh[0].shader;
        CHECK(strcmp(sh->name, "subsurface") == 0);
        CHECK(param(sh, "sigma_s") && fabsf(param(sh, "sigma_s")->value[0] - 0.74f) < 1e-6f);
        CHECK(param(sh, "sigma_a") && fabsf(param(sh, "sigma_a")->value[2] - 0.48f) < 1e-6f);
        CHECK(param(sh, "unitlength") && fabsf(param(sh, "unitlength")->value[0] - 0.25f) < 1e-6f);
        CHECK(param(sh, "eta") && fabsf(param(sh, "eta")->value[0] - 1.33f) < 1e-6f);
        sh = &r->mesh[1].shader;
        CHECK(param(sh, "reflectance") && fabsf(param(sh, "reflectance")->value[1] - 0.5f) < 1e-6f);
        CHECK(param(sh, "mfp") && fabsf(param(sh, "mfp")->value[2] - 0.5f) < 1e-6f);
        CHECK(!param(sh, "sigma_s"));
        sh = &r->mesh[2].shader;
        CHECK(param(sh, "sigma_s") && fabsf(param(sh, "sigma_s")->value[0] - 1.0f) < 1e-6f);
        CHECK(param(sh, "eta") && fabsf(param(sh, "eta")->value[0] - 1.5f) < 1e-6f);
    }
    const char *bad = "WorldBegin\n"
                      "Material \"subsurface\" \"string name\" \"Granite\"\n";
    CHECK(parse("bad.pbrt", bad, r, &s, err, sizeof err) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "bad.pbrt:2:") != NULL && strstr(err, "Granite") != NULL &&
          !strchr(err, '\n'));
    free(r);
}

/* pbrt-v4's imaging ratio: the exposure time times iso / 100 scales the
 * image (1 by default); a shutter that never opens is an error, as in
 * pbrt-v4. */
static void test_exposure(void)
{
    Rec *r = malloc(sizeof *r);
    IoSettings s;
    char err[512] = "";
    CHECK(parse("t.pbrt", "Camera \"perspective\"\nWorldBegin\n", r, &s, err, sizeof err) ==
          RAYES_OK);
    CHECK_NEAR(s.exposure_gain, 1, 0);
    CHECK(parse("t.pbrt",
                "Film \"rgb\" \"float iso\" 400\nCamera \"perspective\" \"float shutteropen\" 0.25 "
                "\"float shutterclose\" 0.75\nWorldBegin\n",
                r, &s, err, sizeof err) == RAYES_OK);
    CHECK_NEAR(s.exposure_gain, 2, 1e-6);
    free(r);
    expect_error("Camera \"perspective\" \"float shutteropen\" 0.5 \"float shutterclose\" 0.5\n"
                 "WorldBegin\n",
                 "t.pbrt:1:1: Camera: expected shutteropen < shutterclose");
    expect_error("Film \"rgb\" \"float iso\" 0\nWorldBegin\n", "t.pbrt:1:1: Film: expected iso > 0");
    /* pbrt's maxcomponentvalue is the sample clamp (infinite: none) */
    r = malloc(sizeof *r);
    CHECK(parse("t.pbrt", "Film \"rgb\" \"float maxcomponentvalue\" 10\nWorldBegin\n", r, &s, err,
                sizeof err) == RAYES_OK);
    CHECK_NEAR(s.sample_clamp, 10, 0);
    CHECK(parse("t.pbrt", "WorldBegin\n", r, &s, err, sizeof err) == RAYES_OK && s.sample_clamp == 0);
    free(r);
    expect_error("Film \"rgb\" \"float maxcomponentvalue\" 0\nWorldBegin\n",
                 "t.pbrt:1:1: Film: expected maxcomponentvalue > 0");
}

/* pbrt's mix of two materials of other classes: the "mix" shader, its
 * materials' classes in "a" and "b", their parameters as "a:NAME" and
 * "b:NAME", the amount a pattern; a mix within a mix nests. */
static void test_mix_classes(void)
{
    Rec *r = calloc(1, sizeof *r);
    IoSettings s;
    char err[512];
    const char *text =
        "Camera \"perspective\"\nWorldBegin\n"
        "Texture \"checks\" \"float\" \"checkerboard\" \"float uscale\" 4\n"
        "MakeNamedMaterial \"red\" \"string type\" \"coateddiffuse\" \"rgb reflectance\" [0.8 "
        "0.1 0.1]\n"
        "MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"float roughness\" 0.2\n"
        "MakeNamedMaterial \"both\" \"string type\" \"mix\" \"string materials\" [\"red\" "
        "\"gold\"] \"texture amount\" \"checks\"\n"
        "MakeNamedMaterial \"deeper\" \"string type\" \"mix\" \"string materials\" [\"both\" "
        "\"red\"] \"float amount\" 0.75\n"
        "MakeNamedMaterial \"none\" \"string type\" \"interface\"\n"
        "MakeNamedMaterial \"cut\" \"string type\" \"mix\" \"string materials\" [\"none\" "
        "\"red\"] \"float amount\" 0.75\n"
        "NamedMaterial \"both\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
        "NamedMaterial \"deeper\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
        "NamedMaterial \"cut\"\n"
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    CHECK(parse("t.pbrt", text, r, &s, err, sizeof err) == RAYES_OK);
    CHECK(r->n_meshes == 3);
    if (r->n_meshes == 3) {
        const Shader *sh = &r->mesh[0].shader;
        CHECK(strcmp(sh->name, "mix") == 0);
        CHECK(param(sh, "a") && strcmp(param(sh, "a")->string, "coateddiffuse") == 0);
        CHECK(param(sh, "b") && strcmp(param(sh, "b")->string, "conductor") == 0);
        CHECK(param(sh, "a:reflectance") &&
              fabsf(param(sh, "a:reflectance")->value[0] - 0.8f) < 1e-6f);
        CHECK(param(sh, "b:roughness") && param(sh, "b:roughness")->value[0] > 0.0f);
        CHECK(param(sh, "amount") && param(sh, "amount")->type == RAYES_PARAM_PATTERN);
        CHECK(bound_pattern(r, sh, "amount") >= 0);
        /* a mix of a mix and another: nested, the inner one's parameters
         * "a:"-prefixed once more */
        sh = &r->mesh[1].shader;
        CHECK(strcmp(sh->name, "mix") == 0);
        CHECK(param(sh, "a") && strcmp(param(sh, "a")->string, "mix") == 0);
        CHECK(param(sh, "a:b") && strcmp(param(sh, "a:b")->string, "conductor") == 0);
        CHECK(param(sh, "a:a:reflectance") && param(sh, "b:reflectance"));
        CHECK(bound_pattern(r, sh, "a:amount") >= 0);
        CHECK(param(sh, "amount") && fabsf(param(sh, "amount")->value[0] - 0.75f) < 1e-6f);
        /* with an interface (no surface): the heavier, as before */
        CHECK(strcmp(r->mesh[2].shader.name, "coateddiffuse") == 0);
    }
    free(r);
}

/* pbrt-v3's materials (Bitterli's and pbrt-v3-scenes' files): matte,
 * plastic, uber and substrate (a Lambertian base plus a coat's lobe
 * scaled by Ks), metal, mirror, glass (index), translucent, disney,
 * kdsubsurface, v3's mix names and bumpmap; v3's roughness remapping
 * (RoughnessToAlpha, not v4's square root); the infinite light's mapname
 * (a z-up latitude-longitude map) and the image film, without warnings. */
static void test_pbrt_v3(void)
{
    Rec *r = malloc(sizeof *r);
    static const char *const mats[] = {
        "Texture \"im\" \"color\" \"imagemap\" \"string filename\" \"a.png\" \"bool gamma\" "
        "\"false\" "
        "\"bool trilinear\" \"true\"\nMaterial \"matte\" \"texture Kd\" \"im\"",
        "Material \"matte\" \"rgb Kd\" [0.2 0.4 0.6]",
        "Material \"plastic\" \"rgb Kd\" [0.5 0.1 0.1] \"rgb Ks\" [0.3 0.3 0.3] \"float "
        "roughness\" 0.1",
        "Material \"uber\" \"rgb Kd\" [0.1 0.2 0.3] \"float index\" 1.4 \"rgb opacity\" [0.5 0.5 "
        "0.5]",
        "Material \"metal\" \"rgb eta\" [0.2 0.9 1.1] \"rgb k\" [3.9 2.4 2.1]",
        "Material \"mirror\"",
        "Material \"glass\" \"float index\" 1.33 \"rgb Kt\" [0.9 1 0.9]",
        "Material \"substrate\" \"rgb Kd\" [0.6 0.6 0.6] \"rgb Ks\" [0.2 0.2 0.2] "
        "\"float uroughness\" 0.01 \"float vroughness\" 0.01 \"bool remaproughness\" \"false\"",
        "Material \"translucent\" \"rgb Kd\" [0.5 0.5 0.5] \"rgb reflect\" [0.4 0.4 0.4]",
        "Material \"disney\" \"rgb color\" [0.7 0.5 0.3] \"float metallic\" 1 \"float roughness\" "
        "0.5",
        "Material \"kdsubsurface\" \"rgb Kd\" [0.8 0.7 0.6] \"float mfp\" 2 \"float scale\" 4",
        "Material \"hair\" \"rgb color\" [0.3 0.2 0.1]",
        "MakeNamedMaterial \"a\" \"string type\" \"matte\" \"rgb Kd\" [0.2 0.2 0.2]\n"
        "MakeNamedMaterial \"b\" \"string type\" \"plastic\"\n"
        "Texture \"bumps\" \"float\" \"scale\" \"float tex1\" 0.5 \"float tex2\" 0.1\n"
        "Material \"mix\" \"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"b\" "
        "\"float amount\" 0.5 \"texture bumpmap\" \"bumps\"",
    };
    enum { N = sizeof mats / sizeof mats[0] };
    char text[8192] = "Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 "
                      "\"float scale\" 2 \"float maxsampleluminance\" 10\n"
                      "Integrator \"directlighting\" \"integer maxdepth\" 7\n"
                      "Accelerator \"kdtree\" \"integer maxprims\" 1\n"
                      "PixelFilter \"triangle\" \"float xwidth\" 1 \"float ywidth\" 1\n"
                      "WorldBegin\nLightSource \"infinite\" \"string mapname\" \"sky.exr\"\n"
                      "LightSource \"goniometric\" \"string mapname\" \"g.exr\"\n"
                      "LightSource \"projection\" \"string mapname\" \"p.exr\"\n";
    for (int k = 0; k < N; k++) {
        strncat(text, mats[k], sizeof text - strlen(text) - 1);
        strncat(text,
                "\nShape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0] "
                "\"integer indices\" [0 1 2]\n",
                sizeof text - strlen(text) - 1);
    }
    strncat(text,
            "Shape \"cone\" \"float height\" 2 \"float radius\" 0.5\nShape \"paraboloid\"\n"
            "Shape \"hyperboloid\" \"point p1\" [1 0 0] \"point p2\" [0 1 1] \"float phimax\" 180\n"
            "Shape \"heightfield\" \"integer nu\" 3 \"integer nv\" 2 \"float Pz\" [0 1 0 0 1 0]\n",
            sizeof text - strlen(text) - 1);
    ParseRun pr = {.name = "v3/t.pbrt", .text = text, .r = r};
    const char *said = test_stderr_of(run_parse, &pr);
    RayesError e = pr.e;
    if (strstr(said, "warning"))
        fprintf(stderr, "  %s", said);
    CHECK(e == RAYES_OK && strstr(said, "warning") == NULL);
    CHECK(pr.s.bounces == 0 && pr.s.specular_depth == 7); /* directlighting: direct light */
    CHECK(pr.s.exposure_gain == 2.0f && pr.s.sample_clamp == 10.0f); /* the image film's */
    CHECK(pr.s.filter_width == 2.0f);                                /* v3's xwidth is the radius */
    CHECK(r->n_meshes == N + 1); /* and the heightfield: 3 x 2 heights, 4 triangles */
    CHECK(r->mesh[N].n_faces == 4 && r->mesh[N].n_points == 6);
    if (e != RAYES_OK || r->n_meshes != N + 1) {
        free(r);
        return;
    }
    const Shader *sh = &r->mesh[0].shader; /* v3's gamma false: a linear image */
    const RayesParam *kd = param(sh, "reflectance");
    int g = kd && kd->type == RAYES_PARAM_PATTERN ? pattern_index(r, kd->string) : -1;
    CHECK(strcmp(sh->name, "diffuse") == 0 && g >= 0 && param(&r->pattern[g].params, "encoding") &&
          strcmp(param(&r->pattern[g].params, "encoding")->string, "linear") == 0);
    sh = &r->mesh[1].shader;
    CHECK(strcmp(sh->name, "diffuse") == 0 &&
          fabsf(param(sh, "reflectance")->value[1] - 0.4f) < 1e-6f);
    sh = &r->mesh[2].shader; /* v3's alpha of roughness 0.1, 0.4618, squared */
    CHECK(strcmp(sh->name, "coateddiffuse") == 0 && param(sh, "specular") &&
          fabsf(param(sh, "specular")->value[0] - 0.3f) < 1e-6f &&
          fabsf(param(sh, "roughness")->value[0] - 0.21322f) < 1e-4f);
    sh = &r->mesh[3].shader;
    CHECK(strcmp(sh->name, "coateddiffuse") == 0 &&
          fabsf(param(sh, "eta")->value[0] - 1.4f) < 1e-6f && param(sh, "Os") &&
          fabsf(param(sh, "Os")->value[0] - 0.5f) < 1e-6f);
    sh = &r->mesh[4].shader; /* metal's default roughness 0.01: alpha 0.1389 */
    CHECK(strcmp(sh->name, "conductor") == 0 && fabsf(param(sh, "k")->value[0] - 3.9f) < 1e-6f &&
          fabsf(param(sh, "roughness")->value[0] - 0.0193f) < 1e-5f);
    sh = &r->mesh[5].shader;
    CHECK(strcmp(sh->name, "conductor") == 0 &&
          fabsf(param(sh, "reflectance")->value[0] - 0.9f) < 1e-6f &&
          param(sh, "roughness")->value[0] == 0.0f);
    sh = &r->mesh[6].shader;
    CHECK(strcmp(sh->name, "dielectric") == 0 &&
          fabsf(param(sh, "eta")->value[0] - 1.33f) < 1e-6f && param(sh, "transmitcolor") &&
          fabsf(param(sh, "transmitcolor")->value[0] - 0.9f) < 1e-6f);
    CHECK(param(sh, "roughness") && param(sh, "roughness")->value[0] == 0.0f); /* v3: specular */
    sh = &r->mesh[7].shader; /* alpha 0.01 given: roughness 1e-4 */
    CHECK(strcmp(sh->name, "coateddiffuse") == 0 &&
          fabsf(param(sh, "roughness")->value[0] - 1e-4f) < 1e-7f);
    sh = &r->mesh[8].shader;
    CHECK(strcmp(sh->name, "diffusetransmission") == 0 &&
          fabsf(param(sh, "reflectance")->value[0] - 0.2f) < 1e-6f &&
          fabsf(param(sh, "transmittance")->value[0] - 0.25f) < 1e-6f);
    sh = &r->mesh[9].shader; /* Disney's alpha r^2: rayes' roughness r^4 */
    CHECK(strcmp(sh->name, "conductor") == 0 &&
          fabsf(param(sh, "roughness")->value[0] - 0.0625f) < 1e-6f);
    sh = &r->mesh[10].shader;
    CHECK(strcmp(sh->name, "subsurface") == 0 &&
          fabsf(param(sh, "unitlength")->value[0] - 4.0f) <
              1e-6f && /* scale mfp: unitlength scale */
          fabsf(param(sh, "mfp")->value[0] - 2.0f) < 1e-6f);
    sh = &r->mesh[11].shader; /* v3 hair's color is v4's reflectance */
    CHECK(strcmp(sh->name, "physicalhair") == 0 && param(sh, "reflectance") &&
          fabsf(param(sh, "reflectance")->value[0] - 0.3f) < 1e-6f);
    sh = &r->mesh[12].shader; /* a matte and a plastic: a mix shader */
    CHECK(strcmp(sh->name, "mix") == 0 && param(sh, "a") &&
          strcmp(param(sh, "a")->string, "diffuse") == 0);
    /* v3's quadrics, as RenderMan's */
    CHECK(r->n_quadrics == 3);
    if (r->n_quadrics == 3) {
        CHECK(r->quadric[0].type == RAYES_QUADRIC_CONE && r->quadric[0].n == 3 &&
              r->quadric[0].p[0] == 2.0f && r->quadric[0].p[1] == 0.5f &&
              r->quadric[0].p[2] == 360.0f);
        CHECK(r->quadric[1].type == RAYES_QUADRIC_PARABOLOID && r->quadric[1].n == 4 &&
              r->quadric[1].p[0] == 1.0f && r->quadric[1].p[2] == 1.0f);
        CHECK(r->quadric[2].type == RAYES_QUADRIC_HYPERBOLOID && r->quadric[2].n == 7 &&
              r->quadric[2].p[0] == 1.0f && r->quadric[2].p[4] == 1.0f &&
              r->quadric[2].p[6] == 180.0f);
    }
    CHECK(r->n_lights == 3 && strcmp(r->light[0].type, "environmentlight") == 0);
    const Shader *lp = &r->light[0].params;
    CHECK(param(lp, "mapping") && strcmp(param(lp, "mapping")->string, "latlong-zup") == 0);
    CHECK(param(lp, "mapname") && strstr(param(lp, "mapname")->string, "sky.exr") != NULL);
    if (r->n_lights == 3) { /* v3's goniometric map: z-up latitude-longitude too */
        lp = &r->light[1].params;
        CHECK(param(lp, "mapping") && strcmp(param(lp, "mapping")->string, "latlong-zup") == 0);
        lp = &r->light[2].params;
        CHECK(param(lp, "mapping") && strcmp(param(lp, "mapping")->string, "projection") == 0 &&
              strstr(param(lp, "mapname")->string, "p.exr") != NULL);
    }
    free(r);
}

TEST_MAIN(TEST(test_filters), TEST(test_pbrt_v3), TEST(test_mix_classes), TEST(test_exposure),
          TEST(test_subsurface_material), TEST(test_filter_warnings), TEST(test_import),
          TEST(test_film_types), TEST(test_measured_material), TEST(test_portal_warns),
          TEST(test_thin_dielectric), TEST(test_annulus), TEST(test_triangle_light),
          TEST(test_light_power), TEST(test_normal_map), TEST(test_anisotropic_roughness),
          TEST(test_maxdepth), TEST(test_projective_transform), TEST(test_forward_references),
          TEST(test_realistic_camera), TEST(test_spectrum_files), TEST(test_cornell_box),
          TEST(test_transforms), TEST(test_materials), TEST(test_lights),
          TEST(test_instances_include_ply), TEST(test_errors), TEST(test_normals_and_uv),
          TEST(test_textures), TEST(test_coated_conductor_textures))
