/*
 * io/builtin.c — the built-in scenes of builtin.h, with the numbers of
 * ../shared/data/cornell-box.md and cornell-teapots.md (millimetres,
 * right-handed, y up; quads listed in order around, front side
 * counter-clockwise).
 */
#include "io/builtin.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/bpt.h"
#include "io/sink.h"

const char *const io_builtin_scene_names[] = {"cornell", "cornell-teapots",
                                              "cornell-teapots-displaced", "cornell-spheres",
                                              "cornell-brick", "cornell-teapots-motion",
                                              "production-room", NULL};

typedef struct Quad {
    float P[4][3];
} Quad;

static const float white[3] = {0.725f, 0.71f, 0.68f};
static const float red[3] = {0.63f, 0.065f, 0.05f};
static const float green[3] = {0.14f, 0.45f, 0.091f};

static RayesError matte(const IoSink *s, const float Cs[3])
{
    RayesParam p = {"Cs", RAYES_PARAM_COLOR, {Cs[0], Cs[1], Cs[2]}, NULL};
    return s->set_shader(s->target, "matte", &p, 1);
}

static RayesError quads(const IoSink *s, const Quad *q, size_t n)
{
    int nv[8], idx[32];
    RayesError e = RAYES_OK;
    for (size_t i = 0; i < n && e == RAYES_OK; i++) {
        nv[0] = 4;
        for (int k = 0; k < 4; k++)
            idx[k] = k;
        e = s->polygon_mesh(s->target, 1, nv, idx, 4, &q[i].P[0][0], NULL, 0);
    }
    return e;
}

/* The box, the light and the camera, shared by both Cornell scenes. */
static RayesError cornell_shell(const IoSink *s)
{
    static const Quad white_quads[] = {
        {{{552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f}}},               /* floor */
        {{{556, 548.8f, 0}, {556, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0}}}, /* ceiling */
        {{{549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f}}}, /* back */
    };
    static const Quad green_wall = {{{0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f}}};
    static const Quad red_wall = {
        {{552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0}}};
    static const float light[4][3] = {
        {343, 548.7f, 227}, {343, 548.7f, 332}, {213, 548.7f, 332}, {213, 548.7f, 227}};
    static const float L[3] = {17, 12, 4};
    static const float eye[3] = {278, 273, -800}, target[3] = {278, 273, 0}, up[3] = {0, 1, 0};
    RayesError e = s->set_camera(s->target, eye, target, up, 39.3077f);
    if (e == RAYES_OK)
        e = matte(s, white);
    if (e == RAYES_OK)
        e = quads(s, white_quads, 3);
    if (e == RAYES_OK)
        e = matte(s, green);
    if (e == RAYES_OK)
        e = quads(s, &green_wall, 1);
    if (e == RAYES_OK)
        e = matte(s, red);
    if (e == RAYES_OK)
        e = quads(s, &red_wall, 1);
    if (e == RAYES_OK)
        e = s->area_light(s->target, light, L);
    return e;
}

static RayesError cornell_blocks(const IoSink *s)
{
    static const Quad blocks[] = {
        /* short block */
        {{{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}}},
        {{{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}}},
        {{{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}}},
        {{{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}}},
        {{{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}},
        /* tall block */
        {{{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}}},
        {{{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}}},
        {{{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}}},
        {{{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}}},
        {{{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}},
    };
    RayesError e = matte(s, white);
    return e == RAYES_OK ? quads(s, blocks, sizeof blocks / sizeof blocks[0]) : e;
}

/* world = T(tx, 0, tz) * Ry(theta) * S(45) * (x, z, -y): the teapot data is z up. */
static void teapot_transform(float theta_degrees, float tx, float tz, float m[16])
{
    double th = theta_degrees * M_PI / 180.0;
    float c = (float)cos(th), s = (float)sin(th), k = 45.0f;
    /* Ry(theta) * (x, z, -y): x' = c x - s y, y' = z, z' = -s x - c y. */
    const float r[16] = {
        k * c,  -k * s, 0, tx,
        0,      0,      k, 0,
        -k * s, -k * c, 0, tz,
        0,      0,      0, 1,
    };
    memcpy(m, r, sizeof r);
}

/* The memo's procedural displacement of the matte teapot (the
 * cornell-teapots-displaced variant of ../shared/data/cornell-teapots.md):
 * along the normal, 3 mm times fractal noise of 4 octaves at a base
 * frequency of 0.04 per mm. The fractal sum stays within 1.875 times the
 * amplitude, so the bound is 6 mm. */
static RayesError teapot_displacement(const IoSink *s)
{
    const RayesParam p[] = {
        {"amplitude", RAYES_PARAM_FLOAT, {3.0f, 0, 0}, NULL},
        {"frequency", RAYES_PARAM_FLOAT, {0.04f, 0, 0}, NULL},
        {"octaves", RAYES_PARAM_FLOAT, {4.0f, 0, 0}, NULL},
    };
    RayesError e = s->set_displacement(s->target, "fractal", p, sizeof p / sizeof p[0]);
    return e == RAYES_OK ? s->set_displacement_bound(s->target, 6.0f) : e;
}

/* The cornell-teapots-motion variant: the matte teapot spins 40 degrees
 * about its axis over the shutter [0, 1] (5 samples, 10 degrees apart),
 * and a thin lens of radius 20 mm focuses on the chrome teapot, 1170 mm
 * along the view. */
#define MOTION_SAMPLES 5

static RayesError teapot_spin(const IoSink *s)
{
    float times[MOTION_SAMPLES], m[MOTION_SAMPLES][16];
    for (int k = 0; k < MOTION_SAMPLES; k++) {
        times[k] = (float)k / (MOTION_SAMPLES - 1);
        teapot_transform(150.0f + 40.0f * times[k], 160.0f, 195.0f, m[k]);
    }
    if (!s->set_transform_motion || !s->set_shutter || !s->set_depth_of_field)
        return s->set_transform(s->target, m[0]); /* a sink without time: the still frame */
    RayesError e = s->set_shutter(s->target, 0.0f, 1.0f);
    if (e == RAYES_OK)
        e = s->set_depth_of_field(s->target, 20.0f, 1170.0f);
    return e == RAYES_OK
               ? s->set_transform_motion(s->target, MOTION_SAMPLES, times, (const float(*)[16])m)
               : e;
}

static RayesError cornell_teapots(const IoSink *s, const char *data_dir, int displaced,
                                  int motion, char *err, size_t err_size)
{
    char path[4096];
    if (!data_dir) {
        snprintf(err, err_size,
                 "cornell-teapots needs teapot.bpt: give the data directory with --data DIR "
                 "or RAYES_DATA");
        return RAYES_ERROR_IO;
    }
    snprintf(path, sizeof path, "%s/teapot.bpt", data_dir);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_size,
                 "%s: cannot open the teapot patches; point --data (or RAYES_DATA) at the "
                 "directory holding teapot.bpt",
                 path);
        return RAYES_ERROR_IO;
    }
    fclose(f);
    static const float chrome[3] = {0.9f, 0.9f, 0.9f}, grey[3] = {0.7f, 0.7f, 0.7f};
    float m[16];
    RayesParam mirror = {"specularcolor", RAYES_PARAM_COLOR, {chrome[0], chrome[1], chrome[2]},
                         NULL};
    RayesError e = s->set_shader(s->target, "mirror", &mirror, 1);
    teapot_transform(35.0f, 395.0f, 370.0f, m);
    if (e == RAYES_OK)
        e = s->set_transform(s->target, m);
    if (e == RAYES_OK && (e = io_read_bpt(path, s, err, err_size)) != RAYES_OK)
        return e;
    if (e == RAYES_OK)
        e = matte(s, grey);
    if (e == RAYES_OK && displaced)
        e = teapot_displacement(s);
    teapot_transform(150.0f, 160.0f, 195.0f, m);
    if (e == RAYES_OK)
        e = motion ? teapot_spin(s) : s->set_transform(s->target, m);
    if (e == RAYES_OK && (e = io_read_bpt(path, s, err, err_size)) != RAYES_OK)
        return e;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    if (e == RAYES_OK)
        e = s->set_transform(s->target, identity);
    if (e == RAYES_OK)
        e = s->set_displacement(s->target, NULL, NULL, 0);
    return e;
}

/* A wall 1.2 mm in front of the back wall, shaded by the example plugin
 * brick (examples/shaders): bricks about 55 x 25 mm. */
static RayesError cornell_brick(const IoSink *s, char *err, size_t err_size)
{
    static const Quad wall = {{{549.6f, 0, 558}, {0, 0, 558}, {0, 548.8f, 558}, {556, 548.8f, 558}}};
    static const RayesParam p[] = {
        {"brickwidth", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL},
        {"brickheight", RAYES_PARAM_FLOAT, {0.045f, 0, 0}, NULL},
        {"mortarthickness", RAYES_PARAM_FLOAT, {0.008f, 0, 0}, NULL},
        {"Cbrick", RAYES_PARAM_COLOR, {0.6f, 0.16f, 0.1f}, NULL},
        {"Cmortar", RAYES_PARAM_COLOR, {0.7f, 0.7f, 0.65f}, NULL},
    };
    RayesError e = s->set_shader(s->target, "brick", p, sizeof p / sizeof p[0]);
    if (e != RAYES_OK) {
        const char *why = (s->get_error ? s->get_error(s->target) : "");
        int missing = strncmp(why, "unknown shader", 14) == 0;
        snprintf(err, err_size, "scene cornell-brick: %s%s", why,
                 missing ? " (give the directory of brick.so with --shader-path DIRS or "
                           "RAYES_SHADER_PATH)"
                         : "");
        return e == RAYES_ERROR_INVALID_ARGUMENT ? RAYES_ERROR_IO : e; /* missing data */
    }
    return quads(s, &wall, 1);
}

/* One sphere per built-in shader, two rows of four: the back row floats
 * (RenderMan's classics), the front row stands on the floor (the
 * physically based family, and glass). */
static RayesError cornell_spheres(const IoSink *s)
{
    typedef struct Ball {
        const char *shader;
        RayesParam p[3];
        size_t n;
    } Ball;
    const Ball balls[8] = {
        {"matte", {{"Cs", RAYES_PARAM_COLOR, {0.2f, 0.7f, 0.8f}, NULL}}, 1},
        {"plastic", {{"Cs", RAYES_PARAM_COLOR, {0.8f, 0.1f, 0.1f}, NULL}}, 1},
        {"metal",
         {{"Cs", RAYES_PARAM_COLOR, {0.9f, 0.7f, 0.3f}, NULL},
          {"roughness", RAYES_PARAM_FLOAT, {0.15f, 0, 0}, NULL}},
         2},
        {"shinymetal",
         {{"Cs", RAYES_PARAM_COLOR, {0.8f, 0.8f, 0.85f}, NULL},
          {"roughness", RAYES_PARAM_FLOAT, {0.05f, 0, 0}, NULL}},
         2},
        {"glass", {{"eta", RAYES_PARAM_FLOAT, {1.5f, 0, 0}, NULL}}, 1},
        {"conductor",
         {{"preset", RAYES_PARAM_STRING, {0, 0, 0}, "gold"},
          {"roughness", RAYES_PARAM_FLOAT, {0.01f, 0, 0}, NULL}},
         2},
        {"dielectric", {{"eta", RAYES_PARAM_FLOAT, {1.33f, 0, 0}, NULL}}, 1},
        {"coateddiffuse",
         {{"reflectance", RAYES_PARAM_COLOR, {0.1f, 0.5f, 0.2f}, NULL}}, 1},
    };
    const float r = 55.0f, x[4] = {464, 340, 216, 92}; /* left to right as seen */
    RayesError e = RAYES_OK;
    for (int i = 0; i < 8 && e == RAYES_OK; i++) {
        int back = i < 4;
        const float m[16] = {1, 0, 0, x[i % 4], 0, 1, 0, back ? 260.0f : r,
                             0, 0, 1, back ? 400.0f : 170.0f, 0, 0, 0, 1};
        e = s->set_shader(s->target, balls[i].shader, balls[i].p, balls[i].n);
        if (e == RAYES_OK)
            e = s->set_transform(s->target, m);
        if (e == RAYES_OK)
            e = s->sphere(s->target, r);
    }
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    if (e == RAYES_OK)
        e = s->set_transform(s->target, identity);
    return e;
}

RayesError io_builtin_scene(const char *name, const char *data_dir, const IoSink *s, char *err,
                            size_t err_size)
{
    RayesError e;
    err[0] = '\0';
    if (strcmp(name, "cornell") == 0) {
        e = cornell_shell(s);
        if (e == RAYES_OK)
            e = cornell_blocks(s);
    } else if (strcmp(name, "cornell-teapots") == 0 ||
               strcmp(name, "cornell-teapots-displaced") == 0 ||
               strcmp(name, "cornell-teapots-motion") == 0) {
        e = cornell_shell(s);
        if (e == RAYES_OK)
            e = cornell_teapots(s, data_dir, strcmp(name, "cornell-teapots-displaced") == 0,
                                strcmp(name, "cornell-teapots-motion") == 0, err, err_size);
    } else if (strcmp(name, "cornell-spheres") == 0) {
        e = cornell_shell(s);
        if (e == RAYES_OK)
            e = cornell_spheres(s);
    } else if (strcmp(name, "cornell-brick") == 0) {
        e = cornell_shell(s);
        if (e == RAYES_OK)
            e = cornell_blocks(s);
        if (e == RAYES_OK)
            e = cornell_brick(s, err, err_size);
    } else if (strcmp(name, "production-room") == 0) {
        e = io_builtin_production_room(s, err, err_size);
    } else {
        snprintf(err, err_size,
                 "unknown scene \"%s\" (built-in scenes: cornell, cornell-teapots, "
                 "cornell-teapots-displaced, cornell-spheres, cornell-brick, "
                 "cornell-teapots-motion, production-room)",
                 name);
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    if (e != RAYES_OK && err[0] == '\0')
        snprintf(err, err_size, "scene %s: %s", name, (s->get_error ? s->get_error(s->target) : ""));
    return e;
}
