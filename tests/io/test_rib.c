/*
 * tests/io/test_rib.c — the RIB reader of io/rib.h against a recording
 * IoSink stub: transforms and the camera matrix, parameter classes and
 * value counts, the basis change of PatchMesh, binary RIB (encoded by hand
 * here, with encoded requests and strings), gzip, frames, objects, errors
 * naming file:line:col, and the Aqsis files of ../shared/data/scenes.
 * Buffers are parsed from heap copies of exactly their size so
 * AddressSanitizer sees any read past the end.
 */
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#include "io/builtin.h"
#include "io/rib.h"
#include "io/rib_write.h"
#include "rayes/rayes.h"
#include "test.h"
#include "test_stderr.h"

#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

/* ------------------------------------------------------ recording stub */

#define MAX_SHADERS 64

typedef struct Rec {
    int cameras;
    float camera[16];
    int projection;
    float fov;
    int have_screen;
    float screen[4];
    float M[16];           /* the last transform */
    char shader[64];       /* the last shader */
    float Cs[3];
    int n_shader_calls;
    int bilinear, bicubic, meshes, faces, tris, quads, quadrics, area_lights, lights;
    int subdivs;           /* subdivision meshes */
    int link_calls, links_mode;  /* set_light_links calls, the last one's mode */
    size_t links[8], n_links;    /* and its lights */
    float first_bicubic[16][3];
    float last_bilinear[4][3];
    float last_mesh_P0[3];
    float area_P[4][3];
    unsigned quadric_flags;
    int quadric_type;
    char light_types[16][32];
    float light_params[16][3]; /* first param value of each light */
    char search[256];
    /* per mesh: its colour and the x of its first point in world space */
    float mesh_Cs[64][3];
    float mesh_x[64];
    int n_mesh_rec;
    /* the primitive variables of the last patch or mesh (values: the first 64) */
    RayesPrimvar pv[3];
    float pv_data[3][64 * 3];
    int n_pv;
    int mesh_idx[64];      /* the last mesh's first indices */
    char light_map[16][64];  /* each light's mapname, "" if none */
    char shader_pattern[64]; /* the last shader's first pattern parameter: "param=pattern" */
    char pattern[64];        /* the last pattern: "type name" */
    char pattern_log[1024];  /* every pattern since cleared: "type name(param=value,...);" */
    float pattern_M[16];     /* the transform current then */
} Rec;

static Rec rec;

static RayesError s_camera(void *t, const float *e, const float *a, const float *u, float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    return RAYES_OK;
}
static RayesError s_camera_matrix(void *t, const float m[16], RayesProjection p, float fov,
                                  const float s[4])
{
    (void)t;
    rec.cameras++;
    memcpy(rec.camera, m, sizeof rec.camera);
    rec.projection = (int)p;
    rec.fov = fov;
    rec.have_screen = s != NULL;
    if (s)
        memcpy(rec.screen, s, sizeof rec.screen);
    return RAYES_OK;
}
static RayesError s_transform(void *t, const float m[16])
{
    (void)t;
    memcpy(rec.M, m, sizeof rec.M);
    return RAYES_OK;
}
static RayesError s_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    (void)t;
    snprintf(rec.shader, sizeof rec.shader, "%s", name);
    rec.n_shader_calls++;
    rec.shader_pattern[0] = '\0';
    for (size_t i = 0; i < n; i++) {
        if (strcmp(p[i].name, "Cs") == 0)
            memcpy(rec.Cs, p[i].value, sizeof rec.Cs);
        if (p[i].type == RAYES_PARAM_PATTERN && !rec.shader_pattern[0])
            snprintf(rec.shader_pattern, sizeof rec.shader_pattern, "%s=%s", p[i].name,
                     p[i].string);
    }
    return RAYES_OK;
}
static RayesError s_pattern(void *t, const char *name, const char *type, const RayesParam *p,
                            size_t n)
{
    (void)t;
    snprintf(rec.pattern, sizeof rec.pattern, "%s %s", type, name);
    char *log = rec.pattern_log + strlen(rec.pattern_log);
    size_t room = sizeof rec.pattern_log - (size_t)(log - rec.pattern_log);
    int w = snprintf(log, room, "%s %s(", type, name);
    for (size_t i = 0; i < n && w > 0 && (size_t)w < room; i++) {
        if (p[i].type == RAYES_PARAM_STRING || p[i].type == RAYES_PARAM_PATTERN)
            w += snprintf(log + w, room - (size_t)w, "%s=%s,", p[i].name, p[i].string);
        else
            w += snprintf(log + w, room - (size_t)w, "%s=%g,", p[i].name, p[i].value[0]);
    }
    if (w > 0 && (size_t)w < room)
        snprintf(log + w, room - (size_t)w, ");");
    memcpy(rec.pattern_M, rec.M, sizeof rec.M);
    return RAYES_OK;
}
static RayesError s_displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    (void)t, (void)name, (void)p, (void)n;
    return RAYES_OK;
}
static RayesError s_float(void *t, float f)
{
    (void)t, (void)f;
    return RAYES_OK;
}
static RayesError s_search(void *t, const char *kind, const char *path)
{
    (void)t;
    snprintf(rec.search, sizeof rec.search, "%s=%s", kind, path);
    return RAYES_OK;
}
static void s_primvars(const RayesPrimvar *pv, size_t n)
{
    rec.n_pv = (int)(n < 3 ? n : 3);
    for (int i = 0; i < rec.n_pv; i++) {
        size_t floats = pv[i].count * (strcmp(pv[i].name, "st") == 0 ? 2u : 3u);
        rec.pv[i] = pv[i];
        memcpy(rec.pv_data[i], pv[i].data, (floats < 192 ? floats : 192) * sizeof(float));
        rec.pv[i].data = rec.pv_data[i];
    }
}
/* The last call's primitive variable of that name, or NULL. */
static const RayesPrimvar *last_pv(const char *name)
{
    for (int i = 0; i < rec.n_pv; i++)
        if (strcmp(rec.pv[i].name, name) == 0)
            return &rec.pv[i];
    return NULL;
}
static RayesError s_bilinear(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)t;
    rec.bilinear++;
    memcpy(rec.last_bilinear, P, sizeof rec.last_bilinear);
    s_primvars(pv, n_pv);
    return RAYES_OK;
}
static RayesError s_bicubic(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)t;
    if (rec.bicubic++ == 0)
        memcpy(rec.first_bicubic, P, sizeof rec.first_bicubic);
    s_primvars(pv, n_pv);
    return RAYES_OK;
}
static RayesError s_mesh(void *t, size_t nf, const int *nv, const int *idx, size_t np,
                         const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    (void)t;
    s_primvars(pv, n_pv);
    size_t n_idx = 0;
    for (size_t f = 0; f < nf; f++)
        n_idx += (size_t)nv[f];
    for (size_t i = 0; i < 64; i++)
        rec.mesh_idx[i] = i < n_idx ? idx[i] : -1;
    rec.meshes++;
    rec.faces += (int)nf;
    for (size_t f = 0; f < nf; f++) {
        rec.tris += nv[f] == 3;
        rec.quads += nv[f] == 4;
    }
    if (np)
        memcpy(rec.last_mesh_P0, P, sizeof rec.last_mesh_P0);
    if (rec.n_mesh_rec < 64 && np) {
        memcpy(rec.mesh_Cs[rec.n_mesh_rec], rec.Cs, sizeof rec.Cs);
        const float *m = rec.M, *p = &P[3 * idx[0]];
        rec.mesh_x[rec.n_mesh_rec++] = m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3];
    }
    return RAYES_OK;
}
static RayesError s_quadric(void *t, RayesQuadric q, const float *p, size_t n, unsigned flags)
{
    (void)t, (void)p, (void)n;
    rec.quadrics++;
    rec.quadric_type = (int)q;
    rec.quadric_flags = flags;
    return RAYES_OK;
}
static RayesError s_sphere(void *t, float r)
{
    (void)t, (void)r;
    rec.quadrics++;
    return RAYES_OK;
}
static RayesError s_area(void *t, const float P[4][3], const float L[3])
{
    (void)t, (void)L;
    rec.area_lights++;
    memcpy(rec.area_P, P, sizeof rec.area_P);
    return RAYES_OK;
}
static RayesError s_subdiv(void *t, RayesSubdivScheme scheme, size_t n_faces, const int *n_verts,
                           const int *indices, size_t n_points, const float *P,
                           const RayesSubdivTags *tags, const RayesPrimvar *pv, size_t n_pv)
{
    (void)t, (void)scheme, (void)n_faces, (void)n_verts, (void)indices, (void)n_points, (void)P;
    (void)tags, (void)pv, (void)n_pv;
    rec.subdivs++;
    return RAYES_OK;
}
static RayesError s_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    (void)t;
    if (rec.lights < 16) {
        snprintf(rec.light_types[rec.lights], 32, "%s", type);
        if (n)
            memcpy(rec.light_params[rec.lights], p[0].value, sizeof rec.light_params[0]);
        rec.light_map[rec.lights][0] = '\0';
        for (size_t i = 0; i < n; i++)
            if (strcmp(p[i].name, "mapname") == 0)
                snprintf(rec.light_map[rec.lights], 64, "%s", p[i].string);
    }
    rec.lights++;
    return RAYES_OK;
}
static RayesError s_links(void *t, RayesLightLinks mode, const size_t *l, size_t n)
{
    (void)t;
    rec.link_calls++;
    rec.links_mode = (int)mode;
    rec.n_links = n;
    for (size_t i = 0; i < n && i < 8; i++)
        rec.links[i] = l[i];
    return RAYES_OK;
}
static size_t s_count(void *t)
{
    (void)t;
    return (size_t)(rec.lights + rec.area_lights);
}
static const char *s_error(void *t)
{
    (void)t;
    return "";
}

static const IoSink stub = {
    NULL,    s_camera,   s_camera_matrix, s_transform, s_shader, s_displacement, s_float, s_search,
    s_float, s_bilinear, s_bicubic,       s_mesh,      s_sphere, s_quadric,      s_area,  s_light,
    s_links, s_count,    s_error,         NULL,        s_subdiv, NULL, NULL, s_pattern};

static IoSettings settings;
static char err[1024];

static RayesError parse_n(const char *name, const void *data, size_t size, int frame)
{
    memset(&rec, 0, sizeof rec);
    io_settings_init(&settings);
    unsigned char *copy = malloc(size ? size : 1);
    memcpy(copy, data, size);
    IoReadOptions opt = {RAYES_TEST_DATA, frame};
    err[0] = '\0';
    RayesError e = io_rib_parse(name, copy, size, &stub, &opt, &settings, err, sizeof err);
    free(copy);
    return e;
}

static RayesError parse(const char *text)
{
    return parse_n("t.rib", text, strlen(text), -1);
}

static RayesError read_file(const char *rel, int frame)
{
    memset(&rec, 0, sizeof rec);
    io_settings_init(&settings);
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/rib-aqsis/%s", RAYES_TEST_DATA, rel);
    IoReadOptions opt = {RAYES_TEST_DATA, frame};
    err[0] = '\0';
    RayesError e = io_rib_read(path, &stub, &opt, &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "%s: %s\n", rel, err);
    return e;
}

/* --------------------------------------------------------------- tests */

#define WORLD(body) "Projection \"perspective\" \"fov\" 40\nWorldBegin\n" body "\nWorldEnd\n"

static void test_camera_and_transforms(void)
{
    CHECK(parse("Format 320 240 1\nProjection \"perspective\" \"fov\" [30]\n"
                "Translate 0 0 5\nRotate 90 0 1 0\n"
                "WorldBegin\nTranslate 1 2 3\nScale 2 2 2\n"
                "Polygon \"P\" [0 0 0 1 0 0 1 1 0]\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.cameras == 1);
    CHECK(rec.projection == RAYES_PROJECTION_PERSPECTIVE);
    CHECK_NEAR(rec.fov, 30, 1e-6);
    CHECK(!rec.have_screen);
    /* camera_from_world = T(0,0,5) R_y(90): world x goes to camera -z */
    CHECK_NEAR(rec.camera[3], 0, 1e-6);
    CHECK_NEAR(rec.camera[11], 5, 1e-6);
    CHECK_NEAR(rec.camera[8], -1, 1e-6); /* row z, column x */
    CHECK_NEAR(rec.camera[2], 1, 1e-6);
    /* world_from_object = T(1,2,3) S(2) */
    CHECK_NEAR(rec.M[0], 2, 1e-6);
    CHECK_NEAR(rec.M[3], 1, 1e-6);
    CHECK_NEAR(rec.M[7], 2, 1e-6);
    CHECK_NEAR(rec.M[11], 3, 1e-6);
    CHECK(rec.tris == 1);
    CHECK(settings.width == 320 && settings.height == 240);

    /* ConcatTransform takes RIB's row-vector matrices (translation last) */
    CHECK(parse(WORLD("ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 4 5 6 1]\n"
                      "TransformBegin\nTranslate 1 0 0\nTransformEnd\n"
                      "Sphere 1 -1 1 360")) == RAYES_OK);
    CHECK_NEAR(rec.M[3], 4, 1e-6);
    CHECK_NEAR(rec.M[7], 5, 1e-6);
    CHECK_NEAR(rec.M[11], 6, 1e-6);
    CHECK(rec.quadrics == 1 && rec.quadric_type == RAYES_QUADRIC_SPHERE);
    CHECK(rec.quadric_flags == 0);
    CHECK(parse(WORLD("ReverseOrientation\nDisk 0 1 360")) == RAYES_OK);
    CHECK(rec.quadric_flags == RAYES_QUADRIC_REVERSE);
    CHECK(parse(WORLD("Scale -1 1 1\nCylinder 1 0 1 360")) == RAYES_OK);
    CHECK(rec.quadric_flags == RAYES_QUADRIC_REVERSE);

    /* Skew: points slide along the second vector; the first turns by the
     * angle toward it. 45 degrees of y toward x: x' = x + y. */
    CHECK(parse(WORLD("Skew 45 0 1 0 1 0 0\nSphere 1 -1 1 360")) == RAYES_OK);
    CHECK_NEAR(rec.M[0], 1, 1e-6);
    CHECK_NEAR(rec.M[1], 1, 1e-6);
    CHECK_NEAR(rec.M[4], 0, 1e-6);
    CHECK_NEAR(rec.M[5], 1, 1e-6);
    /* 30 degrees of y toward (1 1 0), 45 degrees from it: y turns by 30
     * degrees in the xy plane, (1 1 0) stays */
    CHECK(parse(WORLD("Skew 30 0 1 0 1 1 0\nSphere 1 -1 1 360")) == RAYES_OK);
    double yx = rec.M[1], yy = rec.M[5], yz = rec.M[9];
    CHECK_NEAR(atan2(yx, yy) * 180 / M_PI, 30, 1e-4);
    CHECK_NEAR(yz, 0, 1e-6);
    CHECK_NEAR(rec.M[0] + rec.M[1], 1, 1e-5);
    CHECK_NEAR(rec.M[4] + rec.M[5], 1, 1e-5);
    /* an angle past the vectors' own is an error at its line */
    CHECK(parse(WORLD("Skew 90 0 1 0 1 0 0\nSphere 1 -1 1 360")) == RAYES_ERROR_PARSE);
    CHECK(parse(WORLD("Skew 10 0 1 0 0 2 0\nSphere 1 -1 1 360")) == RAYES_ERROR_PARSE);
    /* "Pz", a height field: x and y are the mesh's surface parameters at
     * each point (over nu and nv where it wraps); elsewhere it is an error */
    CHECK(parse(WORLD("PatchMesh \"bilinear\" 3 \"nonperiodic\" 2 \"nonperiodic\" "
                      "\"Pz\" [0 1 2 3 4 5]")) == RAYES_OK);
    CHECK(rec.bilinear == 2);
    CHECK_NEAR(rec.last_bilinear[0][0], 0.5, 1e-6); /* the second patch: (0.5, 0, 1) */
    CHECK_NEAR(rec.last_bilinear[0][1], 0.0, 1e-6);
    CHECK_NEAR(rec.last_bilinear[0][2], 1.0, 1e-6);
    CHECK_NEAR(rec.last_bilinear[3][0], 1.0, 1e-6); /* ... to (1, 1, 5) */
    CHECK_NEAR(rec.last_bilinear[3][1], 1.0, 1e-6);
    CHECK_NEAR(rec.last_bilinear[3][2], 5.0, 1e-6);
    CHECK(parse(WORLD("PatchMesh \"bilinear\" 2 \"periodic\" 2 \"nonperiodic\" "
                      "\"Pz\" [0 1 2 3]")) == RAYES_OK);
    CHECK(rec.bilinear == 2);
    CHECK_NEAR(rec.last_bilinear[0][0], 0.5, 1e-6); /* u wraps: x = i / 2 */
    CHECK(parse(WORLD("Patch \"bilinear\" \"Pz\" [0 0 0 2]")) == RAYES_OK);
    CHECK(rec.bilinear == 1);
    CHECK_NEAR(rec.last_bilinear[3][0], 1.0, 1e-6);
    CHECK_NEAR(rec.last_bilinear[3][2], 2.0, 1e-6);
    CHECK(parse(WORLD("PatchMesh \"bilinear\" 3 \"nonperiodic\" 2 \"nonperiodic\" "
                      "\"Pz\" [0 1 2 3 4]")) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "\"Pz\" needs 3 x 2 = 6 heights, found 5") != NULL);
    CHECK(parse(WORLD("Polygon \"Pz\" [0 1 2]")) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "for Patch and PatchMesh") != NULL);
    /* A Scale of 0 collapses what follows to nothing: RenderMan draws
     * nothing (a particle system's dead embers), rayes skips it (the
     * scene's transforms must be invertible); the rest is drawn */
    CHECK(parse(WORLD("AttributeBegin\nScale 0 0 0\nSphere 1 -1 1 360\nPolygon \"P\" [0 0 0 1 0 0 "
                      "1 1 0]\nAttributeEnd\nSphere 1 -1 1 360")) == RAYES_OK);
    CHECK(rec.quadrics == 1 && rec.meshes == 0);
    CHECK(parse(WORLD("Scale 1 0 1\nObjectBegin \"o\"\nSphere 1 -1 1 360\nObjectEnd\n"
                      "ObjectInstance \"o\"")) == RAYES_OK);
    CHECK(rec.quadrics == 0);

    CHECK(parse("ScreenWindow -1 1 -0.5 0.5\nProjection \"orthographic\"\n"
                "WorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.projection == RAYES_PROJECTION_ORTHOGRAPHIC && rec.have_screen);
    CHECK_NEAR(rec.screen[2], -0.5, 1e-6);
}

static void test_settings(void)
{
    CHECK(parse("PixelSamples 2 3\nPixelFilter \"gaussian\" 2 2\nExposure 1.5 2.2\n"
                "CropWindow 0 0.5 0.25 1\nDisplay \"a.exr\" \"openexr\" \"rgba\"\n"
                "Display \"+b.png\" \"png\" \"rgb\"\nClipping 0.1 100\nQuantize \"rgba\" 255 0 255 0.5\n"
                "PixelVariance 0.01\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.spp == 6);
    CHECK_NEAR(settings.adaptive_error, 0.01, 1e-7);
    CHECK(settings.max_spp == 0);
    CHECK(settings.filter == RAYES_FILTER_GAUSSIAN);
    CHECK_NEAR(settings.filter_width, 2, 0);
    CHECK_NEAR(settings.exposure_gamma, 2.2, 1e-6);
    CHECK(settings.background[3] == 0.0f); /* no Imager */
    CHECK_NEAR(settings.crop[1], 0.5, 0);
    CHECK(settings.n_displays == 2);
    CHECK(strcmp(settings.displays[1].name, "b.png") == 0);
    CHECK(strcmp(settings.displays[0].type, "openexr") == 0);
    /* Option "trace" "maxdepth": the specular depth. */
    CHECK(parse("Option \"trace\" \"int maxdepth\" [4]\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.specular_depth == 4 && settings.bounces == -1);
    /* Imager "background": its colour (bgcolor, or Aqsis files' "color"),
     * white by default; other imagers are ignored. */
    CHECK(parse("Imager \"background\" \"color bgcolor\" [0.5 0.25 0]\nWorldBegin\nWorldEnd\n") ==
          RAYES_OK);
    CHECK(settings.background[3] == 1.0f && settings.background[0] == 0.5f &&
          settings.background[1] == 0.25f && settings.background[2] == 0.0f);
    CHECK(parse("WorldBegin\nImager \"background\" \"color\" [0 1 0]\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.background[1] == 1.0f && settings.background[0] == 0.0f);
    CHECK(parse("Imager \"background\"\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.background[3] == 1.0f && settings.background[2] == 1.0f);
    CHECK(parse("Imager \"sepia\"\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.background[3] == 0.0f);
    CHECK(parse("Imager \"background\" \"color bgcolor\" [1 2]\nWorldBegin\nWorldEnd\n") !=
          RAYES_OK);
    /* RenderMan RIS's adaptive sampling: minsamples everywhere, up to
     * maxsamples where noisy */
    CHECK(parse("Hider \"raytrace\" \"int minsamples\" [8] \"int maxsamples\" [256]\n"
                "WorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.spp == 8 && settings.max_spp == 256);
    CHECK(parse("Hider \"raytrace\" \"int maxsamples\" [-2]\nWorldBegin\nWorldEnd\n") ==
          RAYES_ERROR_PARSE);
    CHECK(parse("PixelVariance -1\nWorldBegin\nWorldEnd\n") == RAYES_ERROR_PARSE);
    CHECK(parse("PixelFilter \"sinc\" 3 3\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.filter == RAYES_FILTER_LANCZOS);
    CHECK(parse("PixelFilter \"catmull-rom\" 4 4\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.filter == RAYES_FILTER_CATMULL_ROM && settings.filter_width == 4.0f);
    CHECK(parse("PixelFilter \"blackman-harris\" 3 3\nWorldBegin\nWorldEnd\n") == RAYES_OK);
    CHECK(settings.filter == RAYES_FILTER_GAUSSIAN); /* unknown: the nearest smooth filter */
    CHECK(settings.grid_size == 0);
    CHECK(parse("Option \"limits\" \"gridsize\" [64] \"bucketsize\" [16 16]\nWorldBegin\n"
                "WorldEnd\n") == RAYES_OK);
    CHECK(settings.grid_size == 64);
    CHECK(parse("Option \"limits\" \"integer gridsize\" 100000\nWorldBegin\nWorldEnd\n") ==
          RAYES_OK);
    CHECK(settings.grid_size == 4096);
}

static void test_shaders_and_lights(void)
{
    CHECK(parse(WORLD("LightSource \"spotlight\" 1 \"coneangle\" 0.5 \"intensity\" 3\n"
                      "LightSource \"ambientlight\" \"amb\" \"intensity\" 0.1\n"
                      "LightSource \"weird\" 3\n"
                      "Color [1 0 0]\nSurface \"plastic\" \"Ks\" 0.3\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
                      "Surface \"indirect\" \"Kd\" 0.8\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) ==
          RAYES_OK);
    CHECK(rec.lights == 2);
    CHECK(strcmp(rec.light_types[0], "spotlight") == 0);
    CHECK_NEAR(rec.light_params[0][0], 0.5 * 180 / M_PI, 1e-3); /* radians to degrees */
    CHECK(strcmp(rec.light_types[1], "ambientlight") == 0);
    CHECK(strcmp(rec.shader, "matte") == 0); /* the unknown shader falls back */
    CHECK_NEAR(rec.Cs[0], 1, 0);
    CHECK_NEAR(rec.Cs[1], 0, 0);
    CHECK(rec.quads == 1 && rec.tris == 1);
    /* the RenderMan Companion's names for the classics */
    CHECK(parse(WORLD("Surface \"RCPlastic\" \"Ks\" 0.3\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) ==
          RAYES_OK);
    CHECK(strcmp(rec.shader, "plastic") == 0);
    CHECK(parse(WORLD("Surface \"RCMatte\" \"Kd\" 0.7\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) ==
          RAYES_OK);
    CHECK(strcmp(rec.shader, "matte") == 0);
    CHECK(parse(WORLD("Surface \"RCGlow\"\nSphere 1 -1 1 360")) == RAYES_OK);
    CHECK(strcmp(rec.shader, "glow") == 0);
    /* Illuminate off before any geometry: the light is sent, and the
     * geometry is linked to every light except it */
    CHECK(parse(WORLD("LightSource \"pointlight\" 1\nIlluminate 1 0\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 1 && rec.links_mode == RAYES_LIGHT_LINKS_EXCEPT && rec.n_links == 1);
    /* ... but not if no geometry follows and it is off at the end */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1 0]\nLightSource \"pointlight\" 1\n"
                      "Illuminate 1 0")) == RAYES_OK);
    CHECK(rec.lights == 0);
    /* Illuminate off in an attribute scope: the objects in it are linked
     * EXCEPT the light; AttributeEnd turns it back on (links ALL) */
    CHECK(parse(WORLD("LightSource \"pointlight\" 1\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "AttributeBegin\nIlluminate 1 0\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "AttributeEnd\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 1 && rec.link_calls == 2 && rec.links_mode == RAYES_LIGHT_LINKS_ALL);
    CHECK(parse(WORLD("LightSource \"pointlight\" 1\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "AttributeBegin\nIlluminate 1 0\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "AttributeEnd")) == RAYES_OK);
    CHECK(rec.link_calls == 1 && rec.links_mode == RAYES_LIGHT_LINKS_EXCEPT && rec.n_links == 1 &&
          rec.links[0] == 0);
    CHECK(parse(WORLD("AttributeBegin\nAreaLightSource \"arealight\" 1 \"intensity\" 2\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nAttributeEnd\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]")) == RAYES_OK);
    CHECK(rec.area_lights == 1 && rec.quads == 1);
    /* Production environment and occlusion lights: an environmentlight of
     * their intensity (position, samples and maps dropped); indirectlight:
     * skipped, rayes' own global illumination stands in */
    CHECK(parse(WORLD("LightSource \"envlight\" 2 \"float intensity\" 0.8 \"from\" [0 1 0]\n"
                      "LightSource \"indirectlight\" 3\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) ==
          RAYES_OK);
    CHECK(rec.lights == 1 && strcmp(rec.light_types[0], "environmentlight") == 0);
    CHECK_NEAR(rec.light_params[0][0], 0.8, 1e-6);
    CHECK(rec.light_map[0][0] == '\0');
    /* their map, by any of its usual names, is the environment's mapname
     * when it is found (here on the texture search path), else dropped
     * with a warning; rayes' own environmentlight keeps its mapname */
    FILE *sky = fopen(RAYES_TEST_TMP "/test_rib_sky.exr", "w");
    CHECK(sky != NULL);
    if (sky)
        fclose(sky);
    CHECK(parse("Option \"searchpath\" \"texture\" [\"/nonexistent:" RAYES_TEST_TMP "\"]\n" WORLD(
              "LightSource \"envlight\" 2 \"string envname\" \"test_rib_sky.exr\"\n"
              "LightSource \"PxrDomeLight\" 3 \"string lightColorMap\" \"dome.tx\"\n"
              "LightSource \"environmentlight\" 4 \"string mapname\" \"m.exr\"\n"
              "  \"string mapping\" \"octahedral\"\n"
              "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 3 && strcmp(rec.light_map[0], "test_rib_sky.exr") == 0 &&
          rec.light_map[1][0] == '\0' && strcmp(rec.light_map[2], "m.exr") == 0);
    /* RenderMan's classic subsurface parameters: the built-in subsurface */
    CHECK(parse(WORLD("Surface \"subsurface\" \"color albedo\" [0.8 0.6 0.5]\n"
                      "  \"color diffusemeanfreepath\" [8 4 2] \"float ior\" 1.4\n"
                      "  \"float unitlength\" 0.1\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.shader, "subsurface") == 0);
    CHECK(parse("Option \"searchpath\" \"shader\" [\"mine:&\"]\nWorldBegin\nWorldEnd\n") ==
          RAYES_OK);
    CHECK(strcmp(rec.search, "shader=mine:&") == 0);
}

/* Pattern requests reach the sink at once, in the current transform, and
 * a shader's "reference pattern NAME" parameter names one. */
/* A project's file rendered from elsewhere: a relative texture name that
 * is not in the working directory (where PRMan looks) is found beside the
 * file or above it, and an archive named from the project's directory is
 * found above the including file's. */
static void test_project_relative(void)
{
    mkdir(RAYES_TEST_TMP "/proj", 0755);
    mkdir(RAYES_TEST_TMP "/proj/textures", 0755);
    mkdir(RAYES_TEST_TMP "/proj/rib", 0755);
    test_write_text(RAYES_TEST_TMP "/proj/textures/wood.ppm", "P3 1 1 255 200 100 50\n");
    test_write_text(RAYES_TEST_TMP "/proj/rib/geo.rib", "Polygon \"P\" [0 0 0 1 0 0 1 1 0]\n");
    test_write_text(RAYES_TEST_TMP "/proj/rib/scene.rib",
                    "WorldBegin\nPattern \"PxrTexture\" \"w\" \"string filename\" "
                    "[\"textures/wood.ppm\"]\nPattern \"PxrTexture\" \"m\" \"string filename\" "
                    "[\"textures/missing.ppm\"]\nReadArchive \"rib/geo.rib\"\nWorldEnd\n");
    memset(&rec, 0, sizeof rec);
    io_settings_init(&settings);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    RayesError e =
        io_rib_read(RAYES_TEST_TMP "/proj/rib/scene.rib", &stub, &opt, &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    CHECK(e == RAYES_OK && rec.meshes == 1);
    CHECK(strstr(rec.pattern_log,
                 "imagemap w(filename=" RAYES_TEST_TMP "/proj/rib/../textures/wood.ppm,") != NULL);
    /* a name found nowhere is kept as it is (the texture system warns) */
    CHECK(strstr(rec.pattern_log, "imagemap m(filename=textures/missing.ppm,") != NULL);
}

static void test_patterns(void)
{
    CHECK(parse(WORLD("Translate 1 2 3\n"
                      "Pattern \"checkerboard\" \"0:checks\" \"float uscale\" [8]\n"
                      "Surface \"diffuse\" \"reference pattern reflectance\" [\"0:checks\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.pattern, "checkerboard 0:checks") == 0);
    CHECK(rec.pattern_M[3] == 1 && rec.pattern_M[7] == 2 && rec.pattern_M[11] == 3);
    CHECK(strcmp(rec.shader, "diffuse") == 0 &&
          strcmp(rec.shader_pattern, "reflectance=0:checks") == 0);
    /* RenderMan's own pattern classes are not built (but PxrTexture, an
     * imagemap): skipped with a warning, and what references them keeps
     * its default; a reference's ":output" is RenderMan's */
    rec.pattern[0] = '\0';
    CHECK(parse(WORLD("Pattern \"PxrWorley\" \"f\" \"float frequency\" [4]\n"
                      "Surface \"diffuse\" \"reference color reflectance\" [\"f:resultRGB\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.pattern[0] == '\0' && strcmp(rec.shader, "diffuse") == 0 &&
          rec.shader_pattern[0] == '\0');
    CHECK(parse(WORLD("Pattern \"PxrTexture\" \"tex\" \"string filename\" [\"a.tex\"]\n"
                      "Surface \"diffuse\" \"reference color reflectance\" [\"tex:resultRGB\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.pattern, "imagemap tex") == 0 &&
          strcmp(rec.shader_pattern, "reflectance=tex") == 0);
    /* RenderMan's placement: a PxrManifold2D's scale and offset, t
     * inverted by default (invertT), texels as they are unless linearize;
     * PxrChecker and PxrMix; a texture's alpha output is its own pattern */
    rec.pattern_log[0] = '\0';
    CHECK(parse(WORLD("Pattern \"PxrManifold2D\" \"m\" \"float scaleS\" [4] \"float scaleT\" "
                      "[2] \"float offsetT\" [0.5]\n"
                      "Pattern \"PxrTexture\" \"logo\" \"string filename\" [\"a.tex\"] "
                      "\"reference struct manifold\" [\"m:result\"]\n"
                      "Pattern \"PxrTexture\" \"up\" \"string filename\" [\"b.tex\"] "
                      "\"int invertT\" [0] \"int linearize\" [1]\n"
                      "Pattern \"PxrChecker\" \"c\" \"color colorA\" [1 0 0] "
                      "\"reference struct manifold\" [\"m:result\"]\n"
                      "Pattern \"PxrMix\" \"mx\" \"reference color color1\" [\"c:resultRGB\"] "
                      "\"reference color color2\" [\"logo:resultRGB\"] \"reference float mix\" "
                      "[\"logo:resultA\"]\n"
                      "Surface \"diffuse\" \"reference color reflectance\" [\"mx:resultRGB\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.pattern_log,
                 "imagemap logo(filename=a.tex,encoding=linear,uscale=4,udelta=0,vscale=-2,"
                 "vdelta=2.5,);"
                 "imagemap up(filename=b.tex,encoding=sRGB,uscale=1,udelta=0,vscale=1,vdelta=0,);"
                 "checkerboard c(tex1=1,tex2=0,uscale=4,udelta=0,vscale=-2,vdelta=2.5,);"
                 "imagemap logo:resultA(filename=a.tex,encoding=linear,uscale=4,udelta=0,"
                 "vscale=-2,vdelta=2.5,channel=3,);"
                 "mix mx(tex1=c,tex2=logo,amount=logo:resultA,);") == 0);
    CHECK(strcmp(rec.shader_pattern, "reflectance=mx") == 0);
    /* a Bxdf's bumpNormal from a PxrNormalMap: rayes' normalmap, a linear
     * image */
    rec.pattern_log[0] = '\0';
    CHECK(parse(WORLD("Pattern \"PxrNormalMap\" \"nm\" \"string filename\" [\"n.tx\"]\n"
                      "Bxdf \"PxrSurface\" \"d\" \"reference normal bumpNormal\" [\"nm:resultN\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.pattern_log, "imagemap nm(filename=n.tx,encoding=linear,uscale=1,udelta=0,"
                                  "vscale=-1,vdelta=1,);") == 0);
    CHECK(strcmp(rec.shader_pattern, "normalmap=nm") == 0);
    /* a texture's name used again: its alpha is the new texture's */
    rec.pattern_log[0] = '\0';
    CHECK(parse(WORLD("Pattern \"PxrTexture\" \"tex\" \"string filename\" [\"a.tex\"]\n"
                      "Pattern \"PxrMix\" \"m1\" \"reference float mix\" [\"tex:resultA\"]\n"
                      "Pattern \"PxrTexture\" \"tex\" \"string filename\" [\"b.tex\"]\n"
                      "Pattern \"PxrMix\" \"m2\" \"reference float mix\" [\"tex:resultA\"]\n"
                      "Pattern \"PxrMix\" \"m3\" \"reference float mix\" [\"tex:resultA\"]\n")) ==
          RAYES_OK);
    const char *second = strstr(rec.pattern_log, "imagemap tex:resultA(filename=b.tex");
    CHECK(strstr(rec.pattern_log, "imagemap tex:resultA(filename=a.tex") != NULL && second);
    CHECK(second && strstr(second + 1, "imagemap tex:resultA") == NULL); /* m3 reuses it */
    /* a stand-in passing a pattern on, referenced by its bare name */
    CHECK(parse(WORLD("Pattern \"checkerboard\" \"img\"\n"
                      "Pattern \"foo\" \"f\" \"reference pattern inputRGB\" [\"img\"]\n"
                      "Surface \"diffuse\" \"reference pattern reflectance\" [\"f\"]\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.shader_pattern, "reflectance=img") == 0);
    /* PxrExposure: its input times 2^stops; an unbuilt class after it
     * (PxrColorCorrect) passes the pattern of its input on */
    rec.pattern_log[0] = '\0';
    CHECK(
        parse(WORLD("Pattern \"PxrExposure\" \"e\" \"color inputRGB\" [0.25 0.5 0.1] "
                    "\"float stops\" [1]\n"
                    "Pattern \"PxrColorCorrect\" \"c\" \"reference color inputRGB\" "
                    "[\"e:resultRGB\"]\n"
                    "Bxdf \"PxrDiffuse\" \"d\" \"reference color diffuseColor\" [\"c:resultRGB\"]\n"
                    "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(strcmp(rec.pattern_log, "scale e(tex=0.25,scale=2,);") == 0);
    CHECK(strcmp(rec.shader_pattern, "reflectance=e") == 0);
    /* the grid classes, a float array among their parameters */
    CHECK(parse(WORLD("Pattern \"densitygrid\" \"g\" \"float nx\" 2 \"float density\" [0.5 1.5]\n"
                      "Pattern \"nanovdb\" \"c\" \"string filename\" \"cloud.nvdb\"\n")) ==
          RAYES_OK);
    CHECK(strcmp(rec.pattern, "nanovdb c") == 0);
}

static void test_parameter_classes(void)
{
    /* uniform Cs: one colour per face, a uniform primitive variable */
    CHECK(parse(WORLD("PointsPolygons [3 3] [0 1 2 0 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
                      "\"uniform color Cs\" [1 0 0 0 1 0]")) == RAYES_OK);
    CHECK(rec.meshes == 1);
    const RayesPrimvar *v = last_pv("Cs");
    CHECK(v && v->cls == RAYES_PRIMVAR_UNIFORM && v->count == 2);
    CHECK(v && v->data[0] == 1 && v->data[4] == 1);
    /* vertex Cs: per point */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1 0] \"vertex color Cs\" [1 0 0 0 1 0 0 0 1]")) ==
          RAYES_OK);
    v = last_pv("Cs");
    CHECK(v && v->cls == RAYES_PRIMVAR_VERTEX && v->count == 3 && v->data[8] == 1);
    /* facevarying float[2] st: 2 values per face corner; a user variable is ignored */
    CHECK(parse(WORLD("Declare \"foo\" \"facevarying float[2]\"\n"
                      "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 1 1 0] \"foo\" [0 0 1 0 1 1]"
                      " \"facevarying float[2] st\" [0 0 1 0 1 1]")) == RAYES_OK);
    v = last_pv("st");
    CHECK(v && v->cls == RAYES_PRIMVAR_FACEVARYING && v->count == 3 && v->data[2] == 1);
    CHECK(rec.n_pv == 1);
    /* N and separate s, t (varying); Np as a uniform N */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1 0] \"N\" [0 0 1 0 0 1 0 1 1] "
                      "\"s\" [0 1 1] \"t\" [0 0 1]")) == RAYES_OK);
    v = last_pv("N");
    CHECK(v && v->cls == RAYES_PRIMVAR_VERTEX && v->count == 3 && v->data[7] == 1);
    v = last_pv("st");
    CHECK(v && v->count == 3 && v->data[2] == 1 && v->data[3] == 0 && v->data[5] == 1);
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1 0] \"Np\" [0 0 1]")) == RAYES_OK);
    v = last_pv("N");
    CHECK(v && v->cls == RAYES_PRIMVAR_UNIFORM && v->count == 1);
    /* facevarying on an ear-clipped polygon: each corner keeps its value */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 4 0 0 4 4 0 2 1 0 0 4 0 0 2 0] "
                      "\"facevarying float[2] st\" [0 0 1 0 2 0 3 0 4 0 5 0]")) == RAYES_OK);
    v = last_pv("st");
    CHECK(v && v->count == 12);
    int corners_ok = v != NULL;
    for (size_t k = 0; v && k < 12; k++)
        corners_ok &= v->data[2 * k] == (float)rec.mesh_idx[k]; /* s = the point's index */
    CHECK(corners_ok);
    /* patches: varying st at the corners, reversed along u when the front flips */
    CHECK(parse(WORLD("Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0] "
                      "\"st\" [0 0 1 0 0 1 1 1]")) == RAYES_OK);
    v = last_pv("st");
    CHECK(v && v->cls == RAYES_PRIMVAR_VARYING && v->count == 4 && v->data[2] == 1);
    CHECK(parse(WORLD("ReverseOrientation\nPatch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0] "
                      "\"st\" [0 0 1 0 0 1 1 1]")) == RAYES_OK);
    v = last_pv("st");
    CHECK(v && v->data[0] == 1 && v->data[2] == 0);
    /* bicubic vertex Cs: 16 values in the current basis, made Bezier as P is */
    CHECK(parse(WORLD("Basis \"b-spline\" 1 \"b-spline\" 1\n"
                      "Patch \"bicubic\" \"P\" [0 0 0 1 0 0 2 0 0 3 0 0  0 1 0 1 1 0 2 1 0 3 1 0 "
                      "0 2 0 1 2 0 2 2 0 3 2 0  0 3 0 1 3 0 2 3 0 3 3 0] \"vertex color Cs\" ["
                      "0 0 0 1 0 0 2 0 0 3 0 0  0 0 0 1 0 0 2 0 0 3 0 0 "
                      "0 0 0 1 0 0 2 0 0 3 0 0  0 0 0 1 0 0 2 0 0 3 0 0]")) == RAYES_OK);
    v = last_pv("Cs");
    CHECK(v && v->cls == RAYES_PRIMVAR_VERTEX && v->count == 16);
    for (int k = 0; v && k < 4; k++) /* Cs red = P x, whose Bezier points are 1, 4/3, 5/3, 2 */
        CHECK_NEAR(v->data[3 * k], rec.first_bicubic[k][0], 1e-5);
    /* PatchMesh: varying values at each sub-patch's corners, uniform per patch */
    CHECK(parse(WORLD("PatchMesh \"bilinear\" 3 \"nonperiodic\" 2 \"nonperiodic\" \"P\" ["
                      "0 0 0 1 0 0 2 0 0 0 1 0 1 1 0 2 1 0] \"varying float s\" [0 1 2 3 4 5] "
                      "\"varying float t\" [0 0 0 1 1 1] \"uniform normal N\" [0 0 1 0 0 1]")) ==
          RAYES_OK);
    v = last_pv("st"); /* the second patch: points 1 2 4 5 */
    CHECK(v && v->data[0] == 1 && v->data[2] == 2 && v->data[4] == 4 && v->data[6] == 5);
    CHECK(last_pv("N") && last_pv("N")->cls == RAYES_PRIMVAR_UNIFORM);
    /* wrong counts are errors naming file:line:col */
    CHECK(parse("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n  \"varying float s\" [0 1]\n"
                "WorldEnd\n") == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "t.rib:3:21:") != NULL);
    CHECK(strstr(err, "needs 3 values") != NULL);
    CHECK(parse("WorldBegin\nPointsPolygons [3 3] [0 1 2 0 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0] "
                "\"uniform color Cs\" [1 0 0]\nWorldEnd\n") == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "t.rib:2:") != NULL);
    CHECK(parse("WorldBegin\nPatch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n") ==
          RAYES_ERROR_PARSE);
    CHECK(strstr(err, "needs 4 points") != NULL);
}

static void test_polygons(void)
{
    /* a concave hexagon: ear clipped into 4 triangles; a square with a hole */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 4 0 0 4 4 0 2 1 0 0 4 0 0 2 0]")) == RAYES_OK);
    CHECK(rec.tris == 4 && rec.quads == 0);
    CHECK(parse(WORLD("GeneralPolygon [4 4] \"P\" [0 0 0 4 0 0 4 4 0 0 4 0 "
                      "1 1 0 3 1 0 3 3 0 1 3 0]")) == RAYES_OK);
    CHECK(rec.tris == 8);
    /* a non-planar quad is split */
    CHECK(parse(WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1 1 0 1 0]")) == RAYES_OK);
    CHECK(rec.tris == 2);
    CHECK(parse(WORLD("PointsGeneralPolygons [1 2] [3 4 3] [0 1 2 3 4 5 6 7 8 9] "
                      "\"P\" [0 0 0 1 0 0 1 1 0 0 0 1 4 0 1 4 4 1 0 4 1 1 1 1 3 1 1 2 3 1]")) ==
          RAYES_OK);
    CHECK(rec.tris == 1 + 7);
}

static void test_patch_mesh_bases(void)
{
    /* A uniform b-spline over collinear, evenly spaced points is the same
     * line: its Bezier points are evenly spaced over the middle third. */
    const char *bspline =
        WORLD("Basis \"b-spline\" 1 \"b-spline\" 1\n"
              "PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" ["
              "0 0 0 3 0 0 6 0 0 9 0 0  0 3 0 3 3 0 6 3 0 9 3 0 "
              "0 6 0 3 6 0 6 6 0 9 6 0  0 9 0 3 9 0 6 9 0 9 9 0]");
    CHECK(parse(bspline) == RAYES_OK);
    CHECK(rec.bicubic == 1);
    for (int i = 0; i < 4; i++) {
        CHECK_NEAR(rec.first_bicubic[i][0], 3 + i, 1e-5);
        CHECK_NEAR(rec.first_bicubic[4 * i][1], 3 + i, 1e-5);
    }
    /* b-spline with a known non-linear window: P = 0 6 0 0 gives Bezier
     * points (0+24+0)/6=4, (4*6+2*0)/6=4, (2*6+4*0)/6=2, (6+0+0)/6... */
    CHECK(parse(WORLD("Basis \"b-spline\" 1 \"bezier\" 3\n"
                      "PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" ["
                      "0 0 0 1 6 0 2 0 0 3 0 0  0 0 1 1 6 1 2 0 1 3 0 1 "
                      "0 0 2 1 6 2 2 0 2 3 0 2  0 0 3 1 6 3 2 0 3 3 0 3]")) == RAYES_OK);
    /* B-spline points y = 0 6 0 0: b0 = (0 + 24 + 0)/6 = 4, b1 = (4*6 + 2*0)/6 = 4,
     * b2 = (2*6 + 4*0)/6 = 2, b3 = (6 + 0 + 0)/6 = 1 */
    CHECK_NEAR(rec.first_bicubic[0][1], 4, 1e-5);
    CHECK_NEAR(rec.first_bicubic[1][1], 4, 1e-5);
    CHECK_NEAR(rec.first_bicubic[2][1], 2, 1e-5);
    CHECK_NEAR(rec.first_bicubic[3][1], 1, 1e-5);
    /* periodic catmull-rom 4 x 4, step 1: 4 x 4 patches; bezier 7 x 4: 2 x 1 */
    CHECK(parse(WORLD("Basis \"catmull-rom\" 1 \"catmull-rom\" 1\n"
                      "PatchMesh \"bicubic\" 4 \"periodic\" 4 \"periodic\" \"P\" ["
                      "0 0 0 1 0 0 1 1 0 0 1 0  0 0 1 1 0 1 1 1 1 0 1 1 "
                      "0 0 2 1 0 2 1 1 2 0 1 2  0 0 3 1 0 3 1 1 3 0 1 3]")) == RAYES_OK);
    CHECK(rec.bicubic == 16);
    CHECK(parse(WORLD("PatchMesh \"bilinear\" 3 \"nonperiodic\" 2 \"nonperiodic\" \"P\" ["
                      "0 0 0 1 0 0 2 0 0 0 1 0 1 1 0 2 1 0] \"varying color Cs\" [1 0 0 1 0 0 "
                      "1 0 0 1 0 0 1 0 0 1 0 0]")) == RAYES_OK);
    CHECK(rec.bilinear == 2);
    /* an explicit matrix equal to the Bezier basis, step 3 */
    CHECK(parse(WORLD("Basis [-1 3 -3 1 3 -6 3 0 -3 3 0 0 1 0 0 0] 3 \"bezier\" 3\n"
                      "Patch \"bicubic\" \"P\" [0 0 0 1 0 0 2 0 0 3 0 0  0 1 0 1 1 0 2 1 0 3 1 0 "
                      "0 2 0 1 2 0 2 2 0 3 2 0  0 3 0 1 3 0 2 3 0 3 3 0]")) == RAYES_OK);
    CHECK_NEAR(rec.first_bicubic[5][0], 1, 1e-5);
    CHECK_NEAR(rec.first_bicubic[5][1], 1, 1e-5);
}

/* Name-keyed tables: a handle, object, coordinate system or declaration
 * used again names the latest, and nothing earlier vanishes. */
static void test_handles(void)
{
    /* Two lights with one handle: two lights, both on; Illuminate turns
     * off only the latest (the links exclude light 1, not light 0). */
    CHECK(parse(WORLD("LightSource \"pointlight\" 1 \"intensity\" 2\n"
                      "LightSource \"pointlight\" 1 \"intensity\" 3\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]\nIlluminate 1 0\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 2);
    CHECK_NEAR(rec.light_params[0][0], (float)(2 * M_PI), 0); /* RenderMan's units: pi */
    CHECK_NEAR(rec.light_params[1][0], (float)(3 * M_PI), 0);
    CHECK(rec.links_mode == RAYES_LIGHT_LINKS_EXCEPT && rec.n_links == 1 && rec.links[0] == 1);
    /* The same after geometry saw the first, and for string handles */
    CHECK(parse(WORLD("LightSource \"pointlight\" \"key\"\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "LightSource \"pointlight\" \"key\"\nIlluminate \"key\" 0\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 2 && rec.n_links == 1 && rec.links[0] == 1);
    /* The number 1 and the string "1" are different handles */
    CHECK(parse(WORLD("LightSource \"pointlight\" 1\nLightSource \"pointlight\" \"1\"\n"
                      "Illuminate \"1\" 0\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 2 && rec.n_links == 1 && rec.links[0] == 1);
    /* a handle no light has (a light skipped): ignored, as RenderMan goes on */
    CHECK(parse(WORLD("LightSource \"pointlight\" 1\nIlluminate \"#1\" 0\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK(rec.lights == 1 && rec.n_links == 0);
    CHECK(parse(WORLD("Illuminate 7 1")) == RAYES_OK);
    /* An area light's handle: Illuminate warns (area lights light
     * everything) instead of failing */
    CHECK(parse(WORLD("AttributeBegin\nAreaLightSource \"arealight\" 4\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nAttributeEnd\nIlluminate 4 0")) ==
          RAYES_OK);
    CHECK(rec.area_lights == 1);
    /* A handle too long for a key is an error, not a truncated key that
     * could meet another */
    char text[1024];
    snprintf(text, sizeof text, WORLD("LightSource \"pointlight\" \"%0300d\""), 0);
    CHECK(parse(text) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "a handle longer than") != NULL);
    /* An object defined again: later instances get the new definition,
     * earlier ones keep the old */
    CHECK(parse(WORLD("ObjectBegin \"o\"\nPolygon \"P\" [1 0 0 2 0 0 2 1 0]\nObjectEnd\n"
                      "ObjectInstance \"o\"\n"
                      "ObjectBegin \"o\"\nPolygon \"P\" [5 0 0 6 0 0 6 1 0]\nObjectEnd\n"
                      "ObjectInstance \"o\"")) == RAYES_OK);
    CHECK(rec.meshes == 2);
    CHECK_NEAR(rec.mesh_x[0], 1, 1e-6);
    CHECK_NEAR(rec.mesh_x[1], 5, 1e-6);
    /* A coordinate system marked again: the latest */
    CHECK(parse(WORLD("Translate 1 0 0\nCoordinateSystem \"c\"\nTranslate 2 0 0\n"
                      "CoordinateSystem \"c\"\nIdentity\nCoordSysTransform \"c\"\n"
                      "Polygon \"P\" [0 0 0 1 0 0 1 1 0]")) == RAYES_OK);
    CHECK_NEAR(rec.mesh_x[0], 3, 1e-6);
    /* A name declared again: the latest declaration types it */
    CHECK(parse(WORLD("Declare \"k\" \"uniform float\"\nDeclare \"k\" \"uniform color\"\n"
                      "Surface \"plastic\" \"k\" [1 2 3]")) == RAYES_OK);
    CHECK(parse(WORLD("Declare \"k\" \"uniform color\"\nDeclare \"k\" \"uniform float\"\n"
                      "Surface \"plastic\" \"k\" [1 2 3]")) == RAYES_ERROR_PARSE);
}

static void test_objects_and_frames(void)
{
    CHECK(parse(WORLD("ObjectBegin \"box\"\nTranslate 1 0 0\nPolygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                      "ObjectEnd\nTranslate 10 0 0\nObjectInstance \"box\"\n"
                      "Translate 10 0 0\nObjectInstance \"box\"")) == RAYES_OK);
    CHECK(rec.meshes == 2);
    CHECK_NEAR(rec.mesh_x[0], 11, 1e-5);
    CHECK_NEAR(rec.mesh_x[1], 21, 1e-5);
    const char *frames = "FrameBegin 1\nDisplay \"a.shad\" \"zfile\" \"z\"\nWorldBegin\n"
                         "Sphere 1 -1 1 360\nWorldEnd\nFrameEnd\n"
                         "FrameBegin 2\nDisplay \"b.tif\" \"file\" \"rgb\"\nWorldBegin\n"
                         "Polygon \"P\" [0 0 0 1 0 0 1 1 0]\nWorldEnd\nFrameEnd\n"
                         "FrameBegin 3\nDisplay \"c.shad\" \"shadow\" \"z\"\nWorldBegin\n"
                         "Disk 0 1 360\nWorldEnd\nFrameEnd\n";
    CHECK(parse_n("f.rib", frames, strlen(frames), -1) == RAYES_OK);
    CHECK(rec.meshes == 1 && rec.quadrics == 0 && rec.cameras == 1);
    CHECK(settings.n_displays == 1 && strcmp(settings.displays[0].name, "b.tif") == 0);
    CHECK(parse_n("f.rib", frames, strlen(frames), 3) == RAYES_OK);
    CHECK(rec.meshes == 0 && rec.quadrics == 1);
    CHECK(parse_n("f.rib", frames, strlen(frames), 7) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "no frame 7") != NULL);
}

/* A small binary stream, encoded by hand (RISpec Appendix C.2). */
static void test_binary(void)
{
    static const unsigned char bin[] = {
        0314, 1, 0232, 'W', 'o', 'r', 'l', 'd', 'B', 'e', 'g', 'i', 'n', /* request 1 */
        0314, 2, 0227, 'P', 'o', 'l', 'y', 'g', 'o', 'n',                /* request 2 */
        0315, 7, 0221, 'P',                                               /* string 7 = "P" */
        'F', 'o', 'r', 'm', 'a', 't', ' ', 0200, 64, 0201, 0, 48, 0204, 1, '\n', /* 64 48 1/256 */
        0246, 1, '\n',
        'T', 'r', 'a', 'n', 's', 'l', 'a', 't', 'e', ' ', 0244, 0x3f, 0x80, 0, 0, /* 1.0f */
        0245, 0x40, 0, 0, 0, 0, 0, 0, 0,                                  /* 2.0 */
        0205, 0x01, 0x80,                                                 /* 1.5 */
        '\n', 0246, 2, 0317, 7, 0310, 9,                                  /* Polygon "P" [9 floats] */
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
        0x3f, 0x80, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
        0x3f, 0x80, 0, 0, 0x3f, 0x80, 0, 0, 0, 0, 0, 0,
        'W', 'o', 'r', 'l', 'd', 'E', 'n', 'd', '\n'};
    CHECK(parse_n("b.rib", bin, sizeof bin, -1) == RAYES_OK);
    if (err[0])
        fprintf(stderr, "%s\n", err);
    CHECK(settings.width == 64 && settings.height == 48);
    CHECK(rec.tris == 1);
    CHECK_NEAR(rec.M[3], 1, 0);
    CHECK_NEAR(rec.M[7], 2, 0);
    CHECK_NEAR(rec.M[11], 1.5, 0);
    CHECK_NEAR(rec.last_mesh_P0[0], 0, 0);
    /* binary floats that are not finite, alone or in an array, are refused
     * where they stand (requests then only see finite numbers) */
    static const char nan_one[] = "Attribute \"trace\" \"int maxdiffusedepth\" \244\177\300\0\0\n";
    CHECK(parse_n("b.rib", nan_one, sizeof nan_one - 1, -1) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "b.rib:1:41: a number out of range") != NULL);
    static const char inf_array[] = "FrameBegin \310\1\177\200\0\0\nFrameEnd\n";
    CHECK(parse_n("b.rib", inf_array, sizeof inf_array - 1, -1) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "b.rib:1:12: a number out of range") != NULL);
    /* reserved codes, undefined requests and truncation are errors */
    static const unsigned char reserved[] = {'W', 'o', 'r', 'l', 'd', 'B', 'e', 'g', 'i', 'n', ' ', 0250};
    CHECK(parse_n("b.rib", reserved, sizeof reserved, -1) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "b.rib:1:12: reserved") != NULL);
    static const unsigned char undefined[] = {0246, 9};
    CHECK(parse_n("b.rib", undefined, sizeof undefined, -1) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "not defined") != NULL);
    static const unsigned char truncated[] = {'S', 'i', 'd', 'e', 's', ' ', 0310, 9, 0, 0};
    CHECK(parse_n("b.rib", truncated, sizeof truncated, -1) == RAYES_ERROR_PARSE);
    static const unsigned char nested[] = {0314, 1, 0314, 2, 0220};
    CHECK(parse_n("b.rib", nested, sizeof nested, -1) == RAYES_ERROR_PARSE);
}

static void test_gzip(void)
{
    const char *text = WORLD("Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]");
    char path[1024];
    snprintf(path, sizeof path, "%s/test_rib.rib.gz", RAYES_TEST_TMP);
    gzFile f = gzopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    gzwrite(f, text, (unsigned)strlen(text));
    gzclose(f);
    memset(&rec, 0, sizeof rec);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    io_settings_init(&settings);
    CHECK(io_rib_read(path, &stub, &opt, &settings, err, sizeof err) == RAYES_OK);
    CHECK(rec.bilinear == 1);
    /* the same bytes from a buffer */
    FILE *g = fopen(path, "rb");
    unsigned char buf[4096];
    size_t n = g ? fread(buf, 1, sizeof buf, g) : 0;
    if (g)
        fclose(g);
    CHECK(parse_n("x.rib.gz", buf, n, -1) == RAYES_OK && rec.bilinear == 1);
    CHECK(parse_n("x.rib.gz", buf, n / 2, -1) == RAYES_ERROR_PARSE);
}

static void test_errors(void)
{
    static const struct {
        const char *text, *want;
    } cases[] = {
        {"WorldBegin\nFooBar 1 2\n", "t.rib:2:1: FooBar: unknown request"},
        {"Translate 1 2\n", "t.rib:1:1: Translate: expected dx dy dz"},
        {"Display \"x\" \"file\" \"rgb\n", "t.rib:1:20: the string has no closing"},
        {"Color [1 0 \"a\"]\n", "t.rib:1:12: an array mixes"},
        {"Format [1 2 3\n", "no closing ']'"},
        {"Sides ]", "t.rib:1:7: ']' without '['"},
        {"1 2 3", "t.rib:1:1: expected a request name"},
        {"WorldBegin\nPolygon \"P\" [0 0 0 1 0 0]\n", "at least 3 points"},
        {"WorldBegin\nPointsPolygons [3] [0 1 5] \"P\" [0 0 0 1 0 0 1 1 0]\n", "vertex index 5"},
        {"ReadArchive \"no-such-file.rib\"\n", "t.rib:1:1: ReadArchive: archive"},
        {"ObjectInstance 4\n", "no object has the handle 4"},
        {"Surface \"matte\" \"uniform color Kd\" [1 1]\n", "needs 3 values"},
        {"Surface \"matte\" \"Kd\"\n", "has no value"},
        {"Format 1e999 1\n", "t.rib:1:8: expected a number"},
        {"Basis \"nurbs\" 1 \"bezier\" 3\n", "unknown basis"},
        {"PatchMesh \"bicubic\" 5 \"nonperiodic\" 4 \"nonperiodic\" \"P\" [0 0 0]\n",
         "do not make whole patches"},
        {"Attribute \"x\" \"float[0] y\" 1\n", "inline declaration"},
        {"ObjectBegin 1\nSphere 1 -1 1 360\n", "inside an object definition"},
        {"Polygon \x01", "unexpected character 0x01"},
        {"FrameBegin -2.35e38\n", "t.rib:1:1: FrameBegin: the frame number must be an integer"},
        {"FrameBegin 1.5\n", "must be an integer, found 1.5"},
        {"Option \"limits\" \"gridsize\" 0\n",
         "t.rib:1:1: Option: Option \"limits\" \"gridsize\": expected a positive integer, found 0"},
        {"Option \"limits\" \"gridsize\" [16.5]\n", "found 16.5"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        RayesError e = parse(cases[i].text);
        CHECK(e != RAYES_OK);
        if (!strstr(err, cases[i].want)) {
            fprintf(stderr, "case %zu: got \"%s\", expected \"%s\"\n", i, err, cases[i].want);
            CHECK(0);
        }
        CHECK(strchr(err, '\n') == NULL);
    }
    /* archive recursion is bounded */
    char path[1024];
    snprintf(path, sizeof path, "%s/test_rib_loop.rib", RAYES_TEST_TMP);
    FILE *f = fopen(path, "w");
    if (f) {
        fputs("ReadArchive \"test_rib_loop.rib\"\n", f);
        fclose(f);
    }
    IoReadOptions opt = {NULL, -1};
    CHECK(io_rib_read(path, &stub, &opt, &settings, err, sizeof err) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "nested more than") != NULL);
}

static void test_aqsis_files(void)
{
    static const char *const files[] = {
        "cornellbox/all_passes.rib", "cornellbox/beauty_pass.rib", "cornellbox/bake_pass.rib",
        "cornellbox/shadow_pass.rib", "cornellbox/geometry.rib", "cornellbox/lights.rib",
        "vase/vase.rib", "archives/bike.rib", "xpm/teapotgeom.rib",
        "objectinstance/singlepolygon.rib"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        CHECK(read_file(files[i], -1) == RAYES_OK);

    CHECK(read_file("archives/bike.rib", -1) == RAYES_OK);
    CHECK(rec.bicubic == 5216);
    CHECK(rec.lights == 4);
    CHECK_NEAR(settings.exposure_gamma, 2.2, 1e-6);

    CHECK(read_file("xpm/teapotgeom.rib", -1) == RAYES_OK);
    CHECK(rec.bicubic == 32);
    CHECK(rec.lights == 3);

    /* the vase: its beauty frame (3) with 126 patches and the PatchMesh body */
    CHECK(read_file("vase/vase.rib", -1) == RAYES_OK);
    CHECK(settings.width == 480 && settings.height == 360);
    CHECK(strcmp(settings.displays[0].name, "vase.tif") == 0);
    CHECK(rec.lights == 5);
    CHECK(rec.cameras == 1);
    CHECK(rec.bicubic == 42 + 12 + 8 + 4 * 2); /* Patch, then PatchMesh 13x10, 13x7, 4 x (4x7) */

    CHECK(read_file("objectinstance/singlepolygon.rib", -1) == RAYES_OK);
    CHECK(rec.meshes >= 10);
    CHECK(rec.have_screen);

    /* The Cornell box seen from its camera: green on the left, red on the
     * right. Camera x of each wall's first point tells the side. */
    CHECK(read_file("cornellbox/all_passes.rib", -1) == RAYES_OK);
    CHECK(rec.cameras == 1);
    int red = 0, green = 0;
    for (int i = 0; i < rec.n_mesh_rec; i++) {
        const float *c = rec.mesh_Cs[i];
        float x = rec.camera[0] * rec.mesh_x[i]; /* approximate: the camera has no rotation */
        if (c[0] == 1 && c[1] == 0 && c[2] == 0)
            red += x > 0 ? 1 : -100;
        if (c[0] == 0 && c[1] == 1 && c[2] == 0)
            green += x < 0 ? 1 : -100;
    }
    CHECK(red == 1 && green == 1);
    CHECK(strcmp(settings.displays[0].name, "cornellbox.tif") == 0);
}

/* Through the real scene sink: the files build scenes the API accepts. */
static void test_scene_sink(void)
{
    static const char *const files[] = {"xpm/teapotgeom.rib", "cornellbox/all_passes.rib",
                                        "objectinstance/singlepolygon.rib"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        RayesScene *scene = rayes_scene_new();
        IoSink sink = io_sink_scene(scene);
        char path[1024];
        snprintf(path, sizeof path, "%s/scenes/rib-aqsis/%s", RAYES_TEST_DATA, files[i]);
        IoReadOptions opt = {RAYES_TEST_DATA, -1};
        io_settings_init(&settings);
        RayesError e = io_rib_read(path, &sink, &opt, &settings, err, sizeof err);
        if (e != RAYES_OK)
            fprintf(stderr, "%s: %s\n", files[i], err);
        CHECK(e == RAYES_OK);
        CHECK(rayes_scene_commit(scene) == RAYES_OK);
        rayes_scene_release(scene);
    }
}

/* Round trip: each built-in scene, written as RIB by io/rib_write.h, reads
 * back into the same patches, faces, quadrics and lights: a mesh's quad
 * that is not planar (the Cornell box's side walls and blocks) is a
 * bilinear patch in rayes, and comes back as one, not as two triangles. */
static void test_writer_round_trip(void)
{
    for (int i = 0; io_builtin_scene_names[i]; i++) {
        const char *name = io_builtin_scene_names[i];
        memset(&rec, 0, sizeof rec);
        if (io_builtin_scene(name, RAYES_TEST_DATA, &stub, err, sizeof err) != RAYES_OK) {
            fprintf(stderr, "%s: %s\n", name, err);
            CHECK(0);
            continue;
        }
        Rec direct = rec;
        RibWriter *w = io_rib_writer_new();
        IoSink ws = io_rib_writer_sink(w);
        char path[1024];
        snprintf(path, sizeof path, "%s/test_rib_%s.rib", RAYES_TEST_TMP, name);
        FILE *f = fopen(path, "w");
        CHECK(f != NULL);
        if (!f) {
            io_rib_writer_free(w);
            continue;
        }
        CHECK(io_builtin_scene(name, RAYES_TEST_DATA, &ws, err, sizeof err) == RAYES_OK);
        CHECK(io_rib_writer_finish(w, NULL, f, err, sizeof err) == RAYES_OK);
        fclose(f);
        io_rib_writer_free(w);
        memset(&rec, 0, sizeof rec);
        IoReadOptions opt = {RAYES_TEST_DATA, -1};
        io_settings_init(&settings);
        RayesError e = io_rib_read(path, &stub, &opt, &settings, err, sizeof err);
        if (e != RAYES_OK)
            fprintf(stderr, "%s: %s\n", name, err);
        CHECK(e == RAYES_OK);
        CHECK(rec.bicubic == direct.bicubic);
        CHECK(rec.tris == direct.tris);
        CHECK(rec.quads + rec.bilinear == direct.quads + direct.bilinear);
        CHECK(strcmp(name, "cornell") != 0 || rec.bilinear > 0);
        CHECK(rec.quadrics == direct.quadrics);
        CHECK(rec.subdivs == direct.subdivs);
        CHECK(rec.area_lights == direct.area_lights);
        CHECK(rec.lights == direct.lights);
        CHECK(rec.cameras == 1);
    }
}

/* Finishes w into RAYES_TEST_TMP/name (path gets the full name), frees
 * it, and reads the file back into rec. Returns -1 if the file could not
 * be written. */
static int write_and_read(RibWriter *w, const char *name, char *path, size_t size)
{
    snprintf(path, size, "%s/%s", RAYES_TEST_TMP, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        CHECK(io_rib_writer_finish(w, NULL, f, err, sizeof err) == RAYES_OK);
        fclose(f);
    }
    io_rib_writer_free(w);
    if (!f)
        return -1;
    memset(&rec, 0, sizeof rec);
    IoReadOptions opt = {NULL, -1};
    io_settings_init(&settings);
    CHECK(io_rib_read(path, &stub, &opt, &settings, err, sizeof err) == RAYES_OK);
    return 0;
}

/* Primitive variables written by the RIB writer read back as they were
 * sent: a mesh's vertex N, facevarying st and uniform Cs, a bilinear
 * patch's varying st, a bicubic patch's vertex Cs (16 Bezier values). */
static void test_writer_primvars(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink ws = io_rib_writer_sink(w);
    const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const int nv[2] = {3, 3}, idx[6] = {0, 1, 2, 0, 2, 3};
    const float N[4][3] = {{0, 0, 1}, {0, 0.6f, 0.8f}, {0, 0, 1}, {0.6f, 0, 0.8f}};
    const float st[6][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 0.125f}, {1, 1}, {0, 1}};
    const float Cs[2][3] = {{1, 0, 0}, {0, 0.5f, 1}};
    const RayesPrimvar mesh_pv[3] = {{"N", RAYES_PRIMVAR_VERTEX, &N[0][0], 4},
                                     {"st", RAYES_PRIMVAR_FACEVARYING, &st[0][0], 6},
                                     {"Cs", RAYES_PRIMVAR_UNIFORM, &Cs[0][0], 2}};
    CHECK(ws.polygon_mesh(ws.target, 2, nv, idx, 4, &P[0][0], mesh_pv, 3) == RAYES_OK);
    const float Q[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    const RayesPrimvar patch_pv = {"st", RAYES_PRIMVAR_VARYING, &st[0][0], 4};
    CHECK(ws.bilinear_patch(ws.target, Q, &patch_pv, 1) == RAYES_OK);
    float B[16][3], C[16][3];
    for (int k = 0; k < 16; k++)
        for (int c = 0; c < 3; c++)
            B[k][c] = (float)(k % 4) + (c == 1 ? (float)(k / 4) : 0.0f), C[k][c] = 0.0625f * (float)k;
    const RayesPrimvar cubic_pv = {"Cs", RAYES_PRIMVAR_VERTEX, &C[0][0], 16};
    CHECK(ws.bicubic_patch(ws.target, (const float(*)[3])B, &cubic_pv, 1) == RAYES_OK);
    const RayesPrimvar bad = {"st", RAYES_PRIMVAR_VERTEX, &st[0][0], 3};
    CHECK(ws.polygon_mesh(ws.target, 2, nv, idx, 4, &P[0][0], &bad, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    char path[1024];
    /* Read it back, checking the mesh (the first geometry) on the way. */
    if (write_and_read(w, "test_rib_primvars.rib", path, sizeof path) != 0)
        return;
    CHECK(rec.meshes == 1 && rec.bilinear == 1 && rec.bicubic == 1);
    const RayesPrimvar *v = last_pv("Cs"); /* the last call: the bicubic patch */
    CHECK(v && v->cls == RAYES_PRIMVAR_VERTEX && v->count == 16);
    CHECK(v && memcmp(v->data, C, sizeof C) == 0);
    /* the mesh and the patch, each read alone */
    FILE *f = fopen(path, "r");
    char line[8192], mesh_rib[8192] = "WorldBegin\n", patch_rib[8192] = "WorldBegin\n";
    int in_mesh = 0;
    while (f && fgets(line, sizeof line, f)) {
        if (strncmp(line, "PointsPolygons", 14) == 0)
            in_mesh = 1;
        else if (strncmp(line, "Patch \"bilinear\"", 16) == 0)
            in_mesh = 2;
        else if (line[0] != ' ')
            in_mesh = 0;
        char *to = in_mesh == 1 ? mesh_rib : patch_rib;
        size_t have = strlen(to), add = strlen(line);
        if (in_mesh && have + add + 16 < sizeof mesh_rib)
            memcpy(to + have, line, add + 1);
    }
    if (f)
        fclose(f);
    strcat(mesh_rib, "WorldEnd\n");
    strcat(patch_rib, "WorldEnd\n");
    CHECK(parse(mesh_rib) == RAYES_OK);
    CHECK(rec.n_pv == 3);
    for (int i = 0; i < 3; i++) {
        v = last_pv(mesh_pv[i].name);
        CHECK(v && v->cls == mesh_pv[i].cls && v->count == mesh_pv[i].count);
        CHECK(v && memcmp(v->data, mesh_pv[i].data,
                          v->count * (i == 1 ? 2 : 3) * sizeof(float)) == 0);
    }
    CHECK(parse(patch_rib) == RAYES_OK);
    v = last_pv("st");
    CHECK(v && v->cls == RAYES_PRIMVAR_VARYING && memcmp(v->data, st, 8 * sizeof(float)) == 0);
}

/* A mesh whose last face is a quad the reader would split (not planar) is
 * written as a mesh of the faces before it, with only the points they use,
 * and a bilinear patch carrying the quad's own primitive variables: vertex N
 * and facevarying st at its corners in patch order (v0 v1 v3 v2), its
 * uniform Cs. */
static void test_writer_split_quad(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink ws = io_rib_writer_sink(w);
    const float P[6][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.5f}, {2, 1, 0}};
    const int nv[3] = {3, 3, 4}, idx[10] = {0, 1, 2, 0, 2, 3, 1, 4, 5, 2};
    float N[6][3], st[10][2], Cs[3][3];
    for (int i = 0; i < 6; i++)
        N[i][0] = 0.1f * (float)i, N[i][1] = 0, N[i][2] = 1;
    for (int i = 0; i < 10; i++)
        st[i][0] = 0.1f * (float)i, st[i][1] = 1.0f - 0.1f * (float)i;
    for (int i = 0; i < 3; i++)
        Cs[i][0] = Cs[i][1] = Cs[i][2] = 0.25f * (float)(i + 1);
    const RayesPrimvar pv[3] = {{"N", RAYES_PRIMVAR_VERTEX, &N[0][0], 6},
                                {"st", RAYES_PRIMVAR_FACEVARYING, &st[0][0], 10},
                                {"Cs", RAYES_PRIMVAR_UNIFORM, &Cs[0][0], 3}};
    CHECK(ws.polygon_mesh(ws.target, 3, nv, idx, 6, &P[0][0], pv, 3) == RAYES_OK);
    char path[1024];
    if (write_and_read(w, "test_rib_split_quad.rib", path, sizeof path) != 0)
        return;
    CHECK(rec.meshes == 1 && rec.tris == 2 && rec.quads == 0 && rec.bilinear == 1);
    static const int corner[4] = {6, 7, 9, 8}; /* v0 v1 v3 v2 of the quad */
    const RayesPrimvar *n = last_pv("N"), *t = last_pv("st"), *c = last_pv("Cs");
    CHECK(n && n->cls == RAYES_PRIMVAR_VERTEX && n->count == 4);
    CHECK(t && t->cls == RAYES_PRIMVAR_FACEVARYING && t->count == 4);
    CHECK(c && c->cls == RAYES_PRIMVAR_UNIFORM && c->count == 1 && c->data[0] == Cs[2][0]);
    for (int k = 0; n && t && k < 4; k++) {
        CHECK(memcmp(&n->data[3 * k], N[idx[corner[k]]], sizeof N[0]) == 0);
        CHECK(memcmp(&t->data[2 * k], st[corner[k]], sizeof st[0]) == 0);
    }
    /* the quad between two triangles: two meshes, the second renumbered to
     * the points it uses (3, 2, 0 -> 2, 1, 0) */
    w = io_rib_writer_new();
    ws = io_rib_writer_sink(w);
    const int nv2[3] = {3, 4, 3}, idx2[10] = {0, 1, 2, 1, 4, 5, 2, 3, 2, 0};
    CHECK(ws.polygon_mesh(ws.target, 3, nv2, idx2, 6, &P[0][0], NULL, 0) == RAYES_OK);
    if (write_and_read(w, "test_rib_split_quad2.rib", path, sizeof path) != 0)
        return;
    CHECK(rec.meshes == 2 && rec.tris == 2 && rec.bilinear == 1);
    CHECK(rec.mesh_idx[0] == 2 && rec.mesh_idx[1] == 1 && rec.mesh_idx[2] == 0);
    CHECK(memcmp(rec.last_mesh_P0, P[0], sizeof P[0]) == 0);
}

/* Level of detail: of the representations DetailRange selects, the most
 * detailed (open to infinity) is drawn, the others skipped, within their
 * attribute blocks only; bad ranges are errors. */
static void test_detail_range(void)
{
    CHECK(parse("WorldBegin\nAttributeBegin\nDetail [-1 1 -1 1 -1 1]\n"
                "AttributeBegin\nDetailRange [0 0 10 20]\nSphere 1 -1 1 360\n"
                "Polygon \"P\" [0 0 0 1 0 0 1 1 0]\nAttributeEnd\n"
                "AttributeBegin\nDetailRange [10 20 1e38 1e38]\nCylinder 1 0 1 360\n"
                "AttributeEnd\nAttributeEnd\nDisk 0 1 360\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.quadrics == 2 && rec.meshes == 0);
    CHECK(parse("WorldBegin\nDetailRange [0 10 5 20]\nWorldEnd\n") != RAYES_OK);
    CHECK(strstr(err, "in order"));
}

typedef struct TextRun {
    const char *text;
    RayesError e;
} TextRun;

static void run_text(void *arg)
{
    TextRun *t = arg;
    t->e = parse(t->text);
}

/* Attributes that ask for what rayes always does (true displacement, rays
 * that see it, power-of-two dicing) are taken without a word; another
 * value is said once, naming what rayes does instead. */
static void test_attributes_rayes_always_does(void)
{
    TextRun yes = {WORLD("Attribute \"render\" \"truedisplacement\" [1]\n"
                         "Attribute \"trace\" \"displacements\" [1]\n"
                         "Attribute \"dice\" \"binary\" [1]\n"
                         "Attribute \"user\" \"string look\" [\"wet\"] \"float id\" [3]\n"
                         "Sphere 1 -1 1 360")};
    const char *said = test_stderr_of(run_text, &yes);
    CHECK(yes.e == RAYES_OK && strstr(said, "warning") == NULL);
    TextRun no = {WORLD("Attribute \"render\" \"truedisplacement\" [0]\nSphere 1 -1 1 360")};
    said = test_stderr_of(run_text, &no);
    CHECK(no.e == RAYES_OK);
    CHECK(strstr(said, "t.rib:3: Attribute \"render\" \"truedisplacement\" 0: rayes always "
                       "displaces the surface itself; ignored") != NULL);
    CHECK(rec.quadrics == 1);
}

/* What PRMan reads and renders that a strict reading refused (students'
 * and exporters' files): single-quoted strings, a spotlight's coneangle
 * outside (0, pi] taken through its cosine as RenderMan's spotlight takes
 * it, a light whose from and to coincide skipped, a disk of negative
 * radius (turned over), RenderMan 21's Displace (a PxrDisplace of nothing), an
 * archive found in the working directory, shaders named by a path, a light
 * shader with a position alone as a point light, inline archives
 * (ArchiveBegin ... ArchiveEnd), RenderMan 22's "Ri" options and
 * attributes, conditional blocks (IfBegin ... IfEnd: one branch). */
static void test_prman_leniency(void)
{
    CHECK(parse(WORLD(
              "Surface 'plastic' 'Ks' 0.3\nLightSource 'spotlight' 1 'coneangle' 20 'intensity' 3\n"
              "LightSource \"distantlight\" 2 \"to\" [0 0 0]\n"
              "Displace \"PxrDisplace\" \"d\" \"float dispAmount\" [0.1]\n"
              "Disk 1.2 -0.05 360\n")) == RAYES_OK);
    CHECK(rec.lights == 1);
    CHECK_NEAR(rec.light_params[0][0], acos(cos(20.0)) * 180 / M_PI, 1e-2);
    CHECK(rec.quadrics == 1 && (rec.quadric_flags & RAYES_QUADRIC_REVERSE));
    /* an unknown shader keeps Ka and Kd only: its other values are not checked */
    CHECK(parse(WORLD("Surface \"difSpec\" \"color myOpacity\" .9 \"Kd\" 0.5\n")) == RAYES_OK);
    CHECK(parse(WORLD("Surface \"difSpec\" \"color Kd\" .9\n")) != RAYES_OK);
    /* shaders named by a path: their last component */
    CHECK(parse(WORLD("LightSource \"shaders/shadowlight\" 1 \"from\" [0 3 2]\n"
                      "Surface \"shaders/plastic\" \"Ks\" 1\nSphere 1 -1 1 360\n")) == RAYES_OK);
    CHECK(strcmp(rec.shader, "plastic") == 0);
    CHECK(rec.lights == 1 && strcmp(rec.light_types[0], "pointlight") == 0);
    /* RenderMan 22's named camera, declared in a block, picked by Display */
    CHECK(parse("TransformBegin\nProjection \"PxrCamera\" \"float fov\" [30]\nTranslate 0 0 10\n"
                "Camera \"main\"\nTransformEnd\nDisplay \"x.exr\" \"openexr\" \"rgba\" \"string "
                "camera\" [\"main\"]\nWorldBegin\nSphere 1 -1 1 360\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.fov == 30.0f && rec.camera[11] == 10.0f);
    /* a classic file's Camera names a coordinate frame; its transform stays */
    CHECK(parse("Translate 0 0 5\nCamera \"shadowcam\"\nTranslate 0 0 2\nWorldBegin\nWorldEnd\n") ==
          RAYES_OK);
    CHECK(rec.camera[11] == 7.0f);
    /* RenderMan 22's Option and Attribute "Ri" (capital R) */
    CHECK(parse("Option \"Ri\" \"int[2] FormatResolution\" [320 180]\n" WORLD(
              "Attribute \"Ri\" \"string Orientation\" [\"inside\"] \"int Sides\" [1]\n"
              "Disk 1.2 0.05 360\n")) == RAYES_OK);
    CHECK(settings.width == 320 && settings.height == 180);
    unsigned inside = rec.quadric_flags & RAYES_QUADRIC_REVERSE;
    CHECK(parse(WORLD("Disk 1.2 0.05 360\n")) == RAYES_OK);
    CHECK(inside != (rec.quadric_flags & RAYES_QUADRIC_REVERSE));
    CHECK(rec.quadrics == 1 && !(rec.quadric_flags & RAYES_QUADRIC_REVERSE));
    /* an inline archive, read where its name is asked for (twice here);
     * its errors name their line in the file */
    CHECK(parse("ArchiveBegin \"ball\"\nSphere 1 -1 1 360\nArchiveEnd\n" WORLD(
              "ReadArchive \"ball\"\nTranslate 0 0 3\nReadArchive \"ball\"\n")) == RAYES_OK);
    CHECK(rec.quadrics == 2);
    CHECK(parse("ArchiveBegin \"a\"\n\n  Sphere 1\nArchiveEnd\nWorldBegin\nReadArchive \"a\"\n") !=
          RAYES_OK);
    CHECK(strstr(err, "t.rib:3:3: Sphere: expected") != NULL);
    /* conditional blocks: one branch is read; nothing is defined */
    CHECK(parse(WORLD("IfBegin \"0\"\nLightSource \"pointlight\" 1\n"
                      "ElseIf \"!defined(RMSTREE) && 'a' == \\\"a\\\"\"\n"
                      "  IfBegin \"$user:pass == 'shadow' || (2 > 3)\"\n"
                      "    LightSource \"pointlight\" 2\n"
                      "  Else\n    LightSource \"distantlight\" 3\n  IfEnd\n"
                      "Else\nLightSource \"spotlight\" 4\nIfEnd\nSphere 1 -1 1 360\n")) ==
          RAYES_OK);
    CHECK(rec.lights == 1 && strcmp(rec.light_types[0], "distantlight") == 0);
    CHECK(parse(WORLD("IfBegin \"1\"\nIfBegin \"0\"\nElse\nSphere 1 -1 1 360\nIfEnd\nElse\n"
                      "Sphere 1 -1 1 360\nIfEnd\n")) == RAYES_OK);
    CHECK(rec.quadrics == 1);
    CHECK(parse(WORLD("Else\n")) != RAYES_OK && strstr(err, "Else without IfBegin"));
    /* an archive's text that ends inside ArchiveBegin is an error; nested
     * blocks are kept in the outer one's text; a light's from given as
     * strings is not read as a position */
    CHECK(parse("ArchiveBegin \"x\"\nSphere 1 -1 1 360\n") != RAYES_OK &&
          strstr(err, "before its ArchiveEnd") != NULL);
    CHECK(parse("ArchiveBegin \"x\"\nArchiveBegin \"y\"\nSphere 1 -1 1 360\nArchiveEnd\n"
                "ArchiveEnd\n" WORLD("ReadArchive \"x\"\nReadArchive \"y\"\n")) == RAYES_OK);
    CHECK(rec.quadrics == 1);
    CHECK(parse("ArchiveBegin \"x\"\nArchiveBegin \"y\"\nSphere 1 -1 1 360\nArchiveEnd\n"
                "ReadArchive \"x\"\nArchiveEnd\n" WORLD("ReadArchive \"x\"\n")) != RAYES_OK);
    CHECK(parse(WORLD("LightSource \"spotlight\" 1 \"string[3] from\" [\"a\" \"b\" \"c\"]\n")) ==
              RAYES_OK ||
          err[0]);
    FILE *f = fopen("test_rib_cwd_archive.rib", "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("Sphere 1 -1 1 360\n", f);
    fclose(f);
    const char *text = WORLD("ReadArchive \"test_rib_cwd_archive.rib\"\n");
    CHECK(parse_n("no_such_dir/scene.rib", text, strlen(text), -1) == RAYES_OK);
    CHECK(rec.quadrics == 1);
    remove("test_rib_cwd_archive.rib");
}

TEST_MAIN(TEST(test_camera_and_transforms), TEST(test_attributes_rayes_always_does),
          TEST(test_settings), TEST(test_shaders_and_lights), TEST(test_parameter_classes),
          TEST(test_patterns), TEST(test_project_relative), TEST(test_polygons),
          TEST(test_patch_mesh_bases), TEST(test_handles), TEST(test_objects_and_frames),
          TEST(test_binary), TEST(test_gzip), TEST(test_errors), TEST(test_aqsis_files),
          TEST(test_scene_sink), TEST(test_writer_round_trip), TEST(test_writer_primvars),
          TEST(test_writer_split_quad), TEST(test_detail_range), TEST(test_prman_leniency))
