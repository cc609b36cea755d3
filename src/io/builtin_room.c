/*
 * io/builtin_room.c — the built-in scene "production-room" (builtin.h):
 * a furnished interior in the spirit of the memo's Figures 1 and 7, for
 * the production benchmark (bench/production, issue 21).
 *
 * Metres, right-handed, y up. The room spans x -3..3, y 0..2.8, z -4..3;
 * the camera stands near the front wall looking at the brick back wall,
 * a window in the left wall lets in the sky (an environment light) and
 * the sun (a distant light). Furniture is Catmull-Clark subdivision
 * surfaces (boxes with creased, rounded edges) and bicubic patches
 * (surfaces of revolution: a vase, a bowl, lamp shades); walls and floor
 * are displaced (brickwall's mortar, fractal noise on the floor and
 * plaster). Shaders: wood (the floor's planks, the table, shelves, frames),
 * brickwall, paintedplastic with texture maps (wallpaper, plaster, a
 * painting), coateddiffuse with a pattern-bound reflectance (the chairs'
 * layered coat), diffuse with pattern-bound reflectance (the rug and the
 * sofa's fabric), plastic (books, a vase), shinymetal (a chrome ball, the
 * lamp). 20 lights: an environment light, a distant light, six quad area
 * lights (ceiling panels, diffusers, the window's portal), seven spot lights with soft edges
 * and five point lights.
 *
 * The texture maps are made here, deterministically, into
 * $TMPDIR/rayes-production-room-1 (/tmp without TMPDIR), each written to
 * a temporary name and renamed (so concurrent builds never see half a
 * file) unless it is already there; the scene's texture search path
 * points at that directory, so `rayes convert` writes it into the RIB.
 */
#define _POSIX_C_SOURCE 200809L /* mkdir, getpid */
#include "io/builtin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/image.h"
#include "rayes/shader.h"

#define TEXTURE_VERSION "1"

typedef struct Room {
    const IoSink *s;
    RayesError e; /* the first error; later calls do nothing */
} Room;

static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static RayesParam fp(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static RayesParam cp(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

static RayesParam sp(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

static RayesParam pat(const char *name, const char *pattern)
{
    return (RayesParam){name, RAYES_PARAM_PATTERN, {0, 0, 0}, pattern};
}

static void shader(Room *r, const char *name, const RayesParam *p, size_t n)
{
    if (r->e == RAYES_OK)
        r->e = r->s->set_shader(r->s->target, name, p, n);
}

static void transform(Room *r, const float m[16])
{
    if (r->e == RAYES_OK)
        r->e = r->s->set_transform(r->s->target, m);
}

static void displacement(Room *r, const char *name, const RayesParam *p, size_t n, float bound)
{
    if (r->e == RAYES_OK)
        r->e = r->s->set_displacement(r->s->target, name, p, n);
    if (r->e == RAYES_OK)
        r->e = r->s->set_displacement_bound(r->s->target, bound);
}

static void pattern(Room *r, const char *name, const char *type, const RayesParam *p, size_t n)
{
    if (r->e == RAYES_OK && !r->s->pattern)
        r->e = RAYES_ERROR_INVALID_ARGUMENT;
    if (r->e == RAYES_OK)
        r->e = r->s->pattern(r->s->target, name, type, p, n);
}

static void light(Room *r, const char *type, const RayesParam *p, size_t n)
{
    if (r->e == RAYES_OK)
        r->e = r->s->light(r->s->target, type, p, n);
}

/* A rectangle from corner o along edges a and b (normal a x b), split into
 * nu x nv bilinear patches; st runs 0..su along a and 0..sv along b (so
 * a periodic texture repeats su x sv times). */
static void rect(Room *r, const float o[3], const float a[3], const float b[3], int nu, int nv,
                 float su, float sv)
{
    for (int j = 0; j < nv && r->e == RAYES_OK; j++)
        for (int i = 0; i < nu && r->e == RAYES_OK; i++) {
            float P[4][3], st[8];
            const float uu[4] = {(float)i / nu, (float)(i + 1) / nu, (float)i / nu,
                                 (float)(i + 1) / nu};
            const float vv[4] = {(float)j / nv, (float)j / nv, (float)(j + 1) / nv,
                                 (float)(j + 1) / nv};
            for (int k = 0; k < 4; k++) {
                for (int c = 0; c < 3; c++)
                    P[k][c] = o[c] + uu[k] * a[c] + vv[k] * b[c];
                st[2 * k] = uu[k] * su;
                st[2 * k + 1] = vv[k] * sv;
            }
            RayesPrimvar pv = {"st", RAYES_PRIMVAR_VARYING, st, 4};
            r->e = r->s->bilinear_patch(r->s->target, (const float(*)[3])P, &pv, 1);
        }
}

/* A box x0..x1, y0..y1, z0..z1 as a Catmull-Clark cube whose twelve
 * edges are creased with sharpness crease (about 3: nearly sharp, with
 * a small rounding; 0: a soft cushion). */
static void box(Room *r, float x0, float x1, float y0, float y1, float z0, float z1, float crease)
{
    static const int nv[6] = {4, 4, 4, 4, 4, 4};
    static const int idx[24] = {0, 4, 6, 2, 5, 1, 3, 7, 0, 1, 5, 4,
                                3, 2, 6, 7, 1, 0, 2, 3, 4, 5, 7, 6};
    static const int edges[24] = {0, 1, 2, 3, 4, 5, 6, 7, 0, 2, 1, 3,
                                  4, 6, 5, 7, 0, 4, 1, 5, 2, 6, 3, 7};
    float P[8][3], sharp[12];
    for (int k = 0; k < 8; k++) {
        P[k][0] = k & 1 ? x1 : x0;
        P[k][1] = k & 2 ? y1 : y0;
        P[k][2] = k & 4 ? z1 : z0;
    }
    for (int k = 0; k < 12; k++)
        sharp[k] = crease;
    RayesSubdivTags tags = {.interpolate_boundary = 1,
                            .n_creases = crease > 0.0f ? 12 : 0,
                            .crease_edges = edges,
                            .crease_sharpness = sharp};
    if (r->e == RAYES_OK && !r->s->subdivision_mesh)
        r->e = RAYES_ERROR_INVALID_ARGUMENT;
    if (r->e == RAYES_OK)
        r->e = r->s->subdivision_mesh(r->s->target, RAYES_SUBDIV_CATMULL_CLARK, 6, nv, idx, 8,
                                      &P[0][0], &tags, NULL, 0);
}

/* A surface of revolution about the y axis through (cx, cy, cz): the
 * profile, a cubic Bezier of points (radius, height), swept in four
 * quarter turns of bicubic patches (the usual 0.5523 circle
 * approximation). */
static void revolve(Room *r, float cx, float cy, float cz, const float prof[4][2])
{
    static const float ring[13][2] = {
        {1, 0},  {1, 0.5522847f},   {0.5522847f, 1},   {0, 1},  {-0.5522847f, 1}, {-1, 0.5522847f},
        {-1, 0}, {-1, -0.5522847f}, {-0.5522847f, -1}, {0, -1}, {0.5522847f, -1}, {1, -0.5522847f},
        {1, 0}};
    for (int q = 0; q < 4 && r->e == RAYES_OK; q++) {
        float P[16][3];
        for (int j = 0; j < 4; j++)       /* along the profile */
            for (int i = 0; i < 4; i++) { /* around */
                const float *c = ring[3 * q + i];
                P[4 * j + i][0] = cx + prof[j][0] * c[0];
                P[4 * j + i][1] = cy + prof[j][1];
                P[4 * j + i][2] = cz - prof[j][0] * c[1];
            }
        r->e = r->s->bicubic_patch(r->s->target, (const float(*)[3])P, NULL, 0);
    }
}

/* A sphere of radius rad about the current origin: RenderMan's quadric,
 * which is what the RIB writer turns a sphere into (the API's sphere is
 * parametrised otherwise, so a converted file would differ in the last
 * bits). */
static void sphere_quadric(Room *r, float rad)
{
    const float p[4] = {rad, -rad, rad, 360.0f};
    if (r->e == RAYES_OK)
        r->e = r->s->quadric(r->s->target, RAYES_QUADRIC_SPHERE, p, 4, 0);
}

/* ---- texture maps, made at build time */

static float hash01(int x, int y, int seed)
{
    uint32_t h = (uint32_t)x * 374761393u + (uint32_t)y * 668265263u + (uint32_t)seed * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return (float)((h ^ (h >> 16)) & 0xffffff) / 16777216.0f;
}

/* Value noise, periodic with period per (in cells), at (x, y) in cells. */
static float vnoise(float x, float y, int per, int seed)
{
    int xi = (int)floorf(x), yi = (int)floorf(y);
    float fx = x - (float)xi, fy = y - (float)yi;
    fx = fx * fx * (3 - 2 * fx);
    fy = fy * fy * (3 - 2 * fy);
    int x0 = ((xi % per) + per) % per, y0 = ((yi % per) + per) % per;
    int x1 = (x0 + 1) % per, y1 = (y0 + 1) % per;
    float a = hash01(x0, y0, seed), b = hash01(x1, y0, seed);
    float c = hash01(x0, y1, seed), d = hash01(x1, y1, seed);
    return (a + (b - a) * fx) + ((c + (d - c) * fx) - (a + (b - a) * fx)) * fy;
}

static float vfbm(float x, float y, int per, int seed)
{
    float s = 0.0f, amp = 0.5f;
    for (int o = 0; o < 5; o++, x *= 2, y *= 2, per *= 2, amp *= 0.5f)
        s += amp * vnoise(x, y, per, seed + o);
    return s;
}

typedef void (*TexelFn)(int x, int y, int w, int h, float rgb[3]);

/* Wallpaper: a damask-like motif of diamonds on two-tone stripes. */
static void wallpaper_texel(int x, int y, int w, int h, float rgb[3])
{
    float u = (float)x / w, v = (float)y / h;
    float stripe = fmodf(u * 4.0f, 1.0f) < 0.5f ? 1.0f : 0.0f;
    float cu = fmodf(u * 4.0f, 1.0f) - 0.5f, cv = fmodf(v * 3.0f, 1.0f) - 0.5f;
    float diamond = fabsf(cu) * 1.6f + fabsf(cv) < 0.28f && fabsf(cu) * 1.6f + fabsf(cv) > 0.2f;
    float n = vfbm(u * 16, v * 16, 16, 3);
    static const float a[3] = {0.62f, 0.55f, 0.38f}, b[3] = {0.55f, 0.48f, 0.32f},
                       d[3] = {0.32f, 0.36f, 0.22f};
    for (int c = 0; c < 3; c++) {
        float base = stripe ? a[c] : b[c];
        rgb[c] = (diamond ? d[c] : base) * (0.9f + 0.2f * n);
    }
}

/* Plaster: warm white with soft blotches. */
static void plaster_texel(int x, int y, int w, int h, float rgb[3])
{
    float n = vfbm((float)x / w * 8, (float)y / h * 8, 8, 11);
    static const float base[3] = {0.78f, 0.74f, 0.66f};
    for (int c = 0; c < 3; c++)
        rgb[c] = base[c] * (0.85f + 0.25f * n);
}

/* A painting: a sunset over hills and a lake. */
static void painting_texel(int x, int y, int w, int h, float rgb[3])
{
    float u = (float)x / w, v = (float)y / h; /* v down */
    float hill = 0.55f + 0.08f * sinf(u * 7.0f) + 0.05f * sinf(u * 17.0f + 1.0f) +
                 0.06f * (vfbm(u * 6, 0.5f, 6, 5) - 0.5f);
    float n = vfbm(u * 32, v * 32, 32, 7);
    if (v < hill) {
        float t = v / hill;
        float sx = u - 0.68f, sy = v - 0.42f;
        float sun = expf(-(sx * sx + sy * sy) * 400.0f);
        rgb[0] = 0.25f + 0.7f * t + 0.6f * sun;
        rgb[1] = 0.25f + 0.35f * t + 0.5f * sun;
        rgb[2] = 0.55f - 0.35f * t + 0.2f * sun;
    } else if (v < 0.78f) {
        float t = (v - hill) / (0.78f - hill);
        rgb[0] = 0.12f + 0.1f * t;
        rgb[1] = 0.22f + 0.08f * t;
        rgb[2] = 0.1f;
    } else {
        float t = (v - 0.78f) / 0.22f;
        rgb[0] = 0.3f - 0.15f * t;
        rgb[1] = 0.32f - 0.12f * t;
        rgb[2] = 0.5f - 0.2f * t;
    }
    for (int c = 0; c < 3; c++)
        rgb[c] = fminf(1.0f, rgb[c] * (0.85f + 0.3f * n)); /* brush strokes */
}

/* The sky, latitude-longitude (+y up, the top row the zenith): a blue
 * zenith, a bright hazy horizon, clouds, green-brown ground below. */
static void sky_texel(int x, int y, int w, int h, float rgb[3])
{
    float elev = 0.5f - ((float)y + 0.5f) / h; /* +0.5 zenith, -0.5 nadir */
    if (elev < 0.0f) {
        float n = vfbm((float)x / w * 32, (float)y / h * 16, 32, 9);
        rgb[0] = 0.22f * (0.8f + 0.4f * n);
        rgb[1] = 0.25f * (0.8f + 0.4f * n);
        rgb[2] = 0.12f;
        return;
    }
    float t = powf(elev * 2.0f, 0.5f);
    float cl = vfbm((float)x / w * 16, (float)y / h * 8, 16, 13);
    float cloud = elev > 0.02f ? fmaxf(0.0f, (cl - 0.55f) * 3.0f) : 0.0f;
    static const float hz[3] = {0.95f, 0.92f, 0.85f}, zn[3] = {0.28f, 0.48f, 0.9f};
    for (int c = 0; c < 3; c++) {
        float s = hz[c] + (zn[c] - hz[c]) * t;
        rgb[c] = s + (0.97f - s) * fminf(cloud, 1.0f);
    }
}

/* Writes dir/name (w x h, from fn) unless it exists. */
static RayesError make_texture(const char *dir, const char *name, int w, int h, TexelFn fn,
                               char *err, size_t err_size)
{
    char path[1100], tmp[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    struct stat st;
    if (stat(path, &st) == 0)
        return RAYES_OK;
    float *rgba = malloc((size_t)w * h * 4 * sizeof *rgba);
    if (!rgba) {
        snprintf(err, err_size, "production-room: out of memory for its textures");
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = &rgba[4 * ((size_t)y * w + x)];
            fn(x, y, w, h, p);
            p[3] = 1.0f;
        }
    snprintf(tmp, sizeof tmp, "%s.%ld.tmp.png", path, (long)getpid());
    RayesError e = image_write_png(tmp, w, h, rgba, err, err_size);
    free(rgba);
    if (e == RAYES_OK && rename(tmp, path) != 0) {
        snprintf(err, err_size, "%s: cannot rename the texture into place", path);
        remove(tmp);
        e = RAYES_ERROR_IO;
    }
    return e;
}

static RayesError make_textures(char *dir, size_t dir_size, char *err, size_t err_size)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, dir_size, "%s/rayes-production-room-" TEXTURE_VERSION,
             tmp && tmp[0] ? tmp : "/tmp");
    if (mkdir(dir, 0777) != 0) {
        struct stat st;
        if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
            snprintf(err, err_size, "%s: cannot make the directory for production-room's textures",
                     dir);
            return RAYES_ERROR_IO;
        }
    }
    RayesError e = make_texture(dir, "wallpaper.png", 256, 256, wallpaper_texel, err, err_size);
    if (e == RAYES_OK)
        e = make_texture(dir, "plaster.png", 256, 256, plaster_texel, err, err_size);
    if (e == RAYES_OK)
        e = make_texture(dir, "painting.png", 512, 384, painting_texel, err, err_size);
    if (e == RAYES_OK)
        e = make_texture(dir, "sky.png", 512, 256, sky_texel, err, err_size);
    return e;
}

/* ---- the shell: walls, floor, ceiling, the window */

static void walls(Room *r)
{
    /* floor: oak planks along x, displaced a little */
    const RayesParam floorwood[] = {fp("plankwidth", 0.16f),
                                    fp("planklength", 1.9f),
                                    fp("axis", 0),
                                    fp("Ks", 0.25f),
                                    fp("roughness", 0.04f),
                                    cp("Clight", 0.78f, 0.55f, 0.32f),
                                    cp("Cdark", 0.5f, 0.3f, 0.14f),
                                    fp("ringscale", 25),
                                    fp("grainamp", 0.7f),
                                    fp("gapwidth", 0.006f)};
    shader(r, "wood", floorwood, 10);
    const RayesParam fl[] = {fp("amplitude", 0.0015f), fp("frequency", 6), fp("octaves", 4)};
    displacement(r, "fractal", fl, 3, 0.003f);
    rect(r, (float[3]){-3, 0, 3}, (float[3]){6, 0, 0}, (float[3]){0, 0, -7}, 6, 7, 1, 1);
    /* back wall: bricks, their mortar recessed by the same class */
    const RayesParam brick[] = {cp("Cbrick", 0.5f, 0.19f, 0.11f), fp("variation", 0.2f)};
    displacement(r, "brickwall", brick, 2, 0.01f);
    shader(r, "brickwall", brick, 2);
    rect(r, (float[3]){-3, 0, -4}, (float[3]){6, 0, 0}, (float[3]){0, 2.8f, 0}, 6, 3, 1, 1);
    /* plaster walls and ceiling: a texture map and fractal bumps */
    const RayesParam pl[] = {sp("texturename", "plaster.png"), fp("Kd", 0.9f), fp("Ks", 0.05f),
                             fp("roughness", 0.2f)};
    const RayesParam bump[] = {fp("amplitude", 0.002f), fp("frequency", 3), fp("octaves", 5)};
    displacement(r, "fractal", bump, 3, 0.004f);
    shader(r, "paintedplastic", pl, 4);
    /* left wall, x = -3, facing +x, with a window z -2.7..-0.7, y 0.9..2.3 */
    rect(r, (float[3]){-3, 0, -4}, (float[3]){0, 0, 7}, (float[3]){0, 0.9f, 0}, 7, 1, 7, 1);
    rect(r, (float[3]){-3, 2.3f, -4}, (float[3]){0, 0, 7}, (float[3]){0, 0.5f, 0}, 7, 1, 7, 1);
    rect(r, (float[3]){-3, 0.9f, -4}, (float[3]){0, 0, 1.3f}, (float[3]){0, 1.4f, 0}, 1, 1, 1, 1);
    rect(r, (float[3]){-3, 0.9f, -0.7f}, (float[3]){0, 0, 3.7f}, (float[3]){0, 1.4f, 0}, 4, 1, 4,
         1);
    /* front wall, z = 3, facing -z (behind the camera) */
    rect(r, (float[3]){-3, 0, 3}, (float[3]){0, 2.8f, 0}, (float[3]){6, 0, 0}, 2, 2, 2, 4);
    /* ceiling, facing down */
    rect(r, (float[3]){-3, 2.8f, -4}, (float[3]){0, 0, 7}, (float[3]){6, 0, 0}, 4, 4, 4, 4);
    /* right wall, x = 3, facing -x: wallpaper, 0.5 m a repeat */
    displacement(r, NULL, NULL, 0, 0.0f);
    const RayesParam wp[] = {sp("texturename", "wallpaper.png"), fp("Kd", 0.9f), fp("Ks", 0.1f),
                             fp("roughness", 0.15f)};
    shader(r, "paintedplastic", wp, 4);
    rect(r, (float[3]){3, 0, 3}, (float[3]){0, 0, -7}, (float[3]){0, 2.8f, 0}, 7, 3, 14, 5.6f);
    /* skirting boards */
    const RayesParam paint[] = {cp("Cs", 0.85f, 0.84f, 0.8f), fp("Ks", 0.3f),
                                fp("roughness", 0.05f)};
    shader(r, "plastic", paint, 3);
    box(r, -3, 3, 0, 0.12f, -4, -3.98f, 3);
    box(r, 2.98f, 3, 0, 0.12f, -4, 3, 3);
    box(r, -3, -2.98f, 0, 0.12f, -4, 3, 3);
}

/* The window's frame and cross bars, in wood painted white. */
static void window(Room *r)
{
    const RayesParam paint[] = {cp("Cs", 0.9f, 0.9f, 0.88f), fp("Ks", 0.4f),
                                fp("roughness", 0.04f)};
    shader(r, "plastic", paint, 3);
    const float x0 = -3.08f, x1 = -2.92f;
    box(r, x0, x1, 0.84f, 0.9f, -2.76f, -0.64f, 3); /* sill */
    box(r, x0, x1, 2.3f, 2.36f, -2.76f, -0.64f, 3); /* head */
    box(r, x0, x1, 0.9f, 2.3f, -2.76f, -2.7f, 3);   /* jambs */
    box(r, x0, x1, 0.9f, 2.3f, -0.7f, -0.64f, 3);
    box(r, -3.04f, -2.96f, 0.9f, 2.3f, -1.72f, -1.68f, 3); /* mullion */
    box(r, -3.04f, -2.96f, 1.58f, 1.62f, -2.7f, -0.7f, 3); /* transom */
    box(r, -2.98f, -2.8f, 0.86f, 0.9f, -2.8f, -0.6f, 3);   /* the inner sill */
}

/* ---- furniture */

static void table_and_chairs(Room *r)
{
    const RayesParam walnut[] = {fp("axis", 0),
                                 cp("Clight", 0.45f, 0.28f, 0.15f),
                                 cp("Cdark", 0.24f, 0.13f, 0.06f),
                                 fp("Ks", 0.5f),
                                 fp("roughness", 0.03f),
                                 fp("ringscale", 60)};
    shader(r, "wood", walnut, 6);
    const float tx = -0.7f, tz = -1.7f;
    box(r, tx - 0.85f, tx + 0.85f, 0.72f, 0.77f, tz - 0.48f, tz + 0.48f, 2.5f);
    for (int k = 0; k < 4; k++) {
        float x = tx + (k & 1 ? 0.72f : -0.72f), z = tz + (k & 2 ? 0.36f : -0.36f);
        box(r, x - 0.035f, x + 0.035f, 0, 0.72f, z - 0.035f, z + 0.035f, 3);
    }
    /* chairs: a layered coat (a clear coat over painted wood whose colour
     * varies by a marble pattern) */
    static const RayesParam chairpat[] = {
        {"octaves", RAYES_PARAM_FLOAT, {6, 0, 0}, NULL},
        {"scale", RAYES_PARAM_FLOAT, {6, 0, 0}, NULL},
        {"variation", RAYES_PARAM_FLOAT, {0.15f, 0, 0}, NULL},
    };
    transform(r, identity);
    pattern(r, "chairgrain", "marble", chairpat, 3);
    const RayesParam tint[] = {cp("tex", 0.18f, 0.32f, 0.3f), pat("scale", "chairgrain")};
    pattern(r, "chaircolour", "scale", tint, 2);
    const RayesParam coat[] = {pat("reflectance", "chaircolour"), fp("roughness", 0.0f)};
    shader(r, "coateddiffuse", coat, 2);
    const float cx[3] = {tx - 0.35f, tx + 0.4f, tx + 1.1f}, cz[3] = {tz + 0.75f, tz + 0.8f, tz};
    for (int c = 0; c < 3; c++) {
        float x = cx[c], z = cz[c];
        int side = c == 2; /* the third stands at the table's end, its back to the right */
        box(r, x - 0.23f, x + 0.23f, 0.44f, 0.48f, z - 0.23f, z + 0.23f, 2.5f);
        for (int k = 0; k < 4; k++) {
            float lx = x + (k & 1 ? 0.19f : -0.19f), lz = z + (k & 2 ? 0.19f : -0.19f);
            box(r, lx - 0.02f, lx + 0.02f, 0, 0.44f, lz - 0.02f, lz + 0.02f, 3);
        }
        if (side)
            box(r, x + 0.19f, x + 0.23f, 0.48f, 0.98f, z - 0.23f, z + 0.23f, 2.5f);
        else
            box(r, x - 0.23f, x + 0.23f, 0.48f, 0.98f, z + 0.19f, z + 0.23f, 2.5f);
    }
}

static void sofa(Room *r)
{
    /* fabric: a woven pattern (wrinkled noise) scaling a teal */
    static const RayesParam weave[] = {{"octaves", RAYES_PARAM_FLOAT, {6, 0, 0}, NULL},
                                       {"roughness", RAYES_PARAM_FLOAT, {0.6f, 0, 0}, NULL}};
    const float s = 18.0f;
    const float m[16] = {s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1};
    transform(r, m);
    pattern(r, "weave", "wrinkled", weave, 2);
    transform(r, identity);
    const RayesParam mixp[] = {cp("tex1", 0.1f, 0.3f, 0.33f), cp("tex2", 0.05f, 0.16f, 0.2f),
                               pat("amount", "weave")};
    pattern(r, "fabric", "mix", mixp, 3);
    const RayesParam fabric[] = {pat("reflectance", "fabric")};
    shader(r, "diffuse", fabric, 1);
    const float x0 = 0.6f, x1 = 2.7f, z0 = -3.85f, z1 = -2.95f;
    box(r, x0 + 0.2f, x1 - 0.2f, 0.12f, 0.4f, z0, z1, 1.5f);         /* base */
    box(r, x0 + 0.2f, x1 - 0.2f, 0.4f, 0.95f, z0, z0 + 0.25f, 1.0f); /* back */
    box(r, x0, x0 + 0.22f, 0.12f, 0.68f, z0, z1, 1.5f);              /* arms */
    box(r, x1 - 0.22f, x1, 0.12f, 0.68f, z0, z1, 1.5f);
    for (int k = 0; k < 3; k++) { /* seat cushions, soft */
        float a = x0 + 0.22f + (x1 - x0 - 0.44f) * k / 3.0f, b = a + (x1 - x0 - 0.44f) / 3.0f;
        box(r, a + 0.01f, b - 0.01f, 0.4f, 0.55f, z0 + 0.25f, z1 + 0.02f, 0.6f);
    }
    box(r, x0 + 0.35f, x0 + 0.8f, 0.5f, 0.92f, z0 + 0.22f, z0 + 0.42f, 0.3f); /* a pillow */
    /* feet */
    const RayesParam dark[] = {cp("Cs", 0.08f, 0.06f, 0.05f), fp("Ks", 0.3f)};
    shader(r, "plastic", dark, 2);
    for (int k = 0; k < 4; k++) {
        float x = k & 1 ? x1 - 0.1f : x0 + 0.1f, z = k & 2 ? z1 - 0.1f : z0 + 0.1f;
        box(r, x - 0.03f, x + 0.03f, 0, 0.12f, z - 0.03f, z + 0.03f, 3);
    }
}

/* A bookcase against the right wall with books and a chrome ball. */
static void shelves(Room *r)
{
    const RayesParam oak[] = {fp("axis", 2), cp("Clight", 0.6f, 0.42f, 0.25f),
                              cp("Cdark", 0.4f, 0.25f, 0.12f), fp("Ks", 0.3f),
                              fp("roughness", 0.05f)};
    shader(r, "wood", oak, 5);
    const float x0 = 2.6f, x1 = 2.97f, z0 = -1.6f, z1 = 0.2f, top = 2.0f;
    box(r, x0, x1, 0, top, z0, z0 + 0.03f, 3);
    box(r, x0, x1, 0, top, z1 - 0.03f, z1, 3);
    box(r, x1 - 0.02f, x1, 0, top, z0, z1, 3);
    const float boards[5] = {0.05f, 0.5f, 0.95f, 1.4f, 1.97f};
    for (int b = 0; b < 5; b++)
        box(r, x0, x1 - 0.02f, boards[b], boards[b] + 0.03f, z0 + 0.03f, z1 - 0.03f, 3);
    /* books: plastic covers, colours and sizes from a hash */
    static const float covers[6][3] = {{0.5f, 0.08f, 0.06f},  {0.1f, 0.2f, 0.45f},
                                       {0.12f, 0.35f, 0.15f}, {0.7f, 0.6f, 0.35f},
                                       {0.3f, 0.12f, 0.3f},   {0.15f, 0.15f, 0.15f}};
    for (int b = 0; b < 3 && r->e == RAYES_OK; b++) {
        float z = z0 + 0.05f + (b == 1 ? 0.6f : 0.0f);
        float end = b == 1 ? z1 - 0.05f : z1 - (b == 2 ? 0.55f : 0.05f);
        for (int k = 0; z < end && r->e == RAYES_OK; k++) {
            float w = 0.025f + 0.03f * hash01(k, b, 1), h = 0.28f + 0.12f * hash01(k, b, 2);
            float d = 0.18f + 0.08f * hash01(k, b, 3);
            const float *c = covers[(int)(hash01(k, b, 4) * 6) % 6];
            const RayesParam cov[] = {cp("Cs", c[0], c[1], c[2]), fp("Ks", 0.25f),
                                      fp("roughness", 0.08f)};
            shader(r, "plastic", cov, 3);
            float y0 = boards[b + 1] + 0.03f;
            box(r, x1 - 0.03f - d, x1 - 0.03f, y0, y0 + h, z, z + w, 2.5f);
            z += w + 0.002f;
        }
    }
    const RayesParam chrome[] = {cp("Cs", 0.85f, 0.85f, 0.88f), fp("roughness", 0.02f)};
    shader(r, "shinymetal", chrome, 2);
    const float ball[16] = {1, 0, 0, 2.78f, 0, 1, 0, boards[3] + 0.03f + 0.12f,
                            0, 0, 1, -0.3f, 0, 0, 0, 1};
    transform(r, ball);
    sphere_quadric(r, 0.12f);
    transform(r, identity);
    /* a vase on the top shelf */
    const RayesParam glaze[] = {cp("Cs", 0.6f, 0.25f, 0.08f), fp("Ks", 0.6f),
                                fp("roughness", 0.03f)};
    shader(r, "plastic", glaze, 3);
    const float vase[4][2] = {{0.06f, 0}, {0.16f, 0.1f}, {0.02f, 0.25f}, {0.07f, 0.34f}};
    revolve(r, 2.78f, boards[4] + 0.03f, -0.5f, vase);
}

/* On the table: a bowl of fruit-like balls, a ceramic vase; a painting
 * on the back wall; a rug. */
static void objects(Room *r)
{
    const RayesParam ceramic[] = {cp("Cs", 0.85f, 0.82f, 0.75f), fp("Ks", 0.5f),
                                  fp("roughness", 0.04f)};
    shader(r, "plastic", ceramic, 3);
    const float bowl[4][2] = {{0.001f, 0}, {0.18f, 0.0f}, {0.2f, 0.06f}, {0.2f, 0.11f}};
    revolve(r, -0.95f, 0.77f, -1.75f, bowl);
    const float inner[4][2] = {{0.19f, 0.11f}, {0.19f, 0.06f}, {0.17f, 0.01f}, {0.001f, 0.01f}};
    revolve(r, -0.95f, 0.77f, -1.75f, inner);
    static const float fruit[5][4] = {{-1.0f, 0.84f, -1.75f, 0.06f},
                                      {-0.88f, 0.84f, -1.72f, 0.055f},
                                      {-0.95f, 0.84f, -1.84f, 0.06f},
                                      {-0.93f, 0.92f, -1.76f, 0.05f},
                                      {-1.04f, 0.83f, -1.85f, 0.05f}};
    static const float fc[5][3] = {{0.7f, 0.1f, 0.05f},
                                   {0.8f, 0.55f, 0.05f},
                                   {0.25f, 0.5f, 0.1f},
                                   {0.75f, 0.2f, 0.05f},
                                   {0.8f, 0.6f, 0.1f}};
    for (int k = 0; k < 5 && r->e == RAYES_OK; k++) {
        const RayesParam skin[] = {cp("Cs", fc[k][0], fc[k][1], fc[k][2]), fp("Ks", 0.4f),
                                   fp("roughness", 0.06f)};
        shader(r, "plastic", skin, 3);
        const float m[16] = {1, 0, 0, fruit[k][0], 0, 1, 0, fruit[k][1],
                             0, 0, 1, fruit[k][2], 0, 0, 0, 1};
        transform(r, m);
        if (r->e == RAYES_OK)
            sphere_quadric(r, fruit[k][3]);
    }
    transform(r, identity);
    const RayesParam blue[] = {cp("Cs", 0.12f, 0.22f, 0.5f), fp("Ks", 0.7f),
                               fp("roughness", 0.02f)};
    shader(r, "plastic", blue, 3);
    const float vase[4][2] = {{0.05f, 0}, {0.14f, 0.12f}, {0.03f, 0.26f}, {0.06f, 0.4f}};
    revolve(r, -0.25f, 0.77f, -1.6f, vase);
    /* the painting: a wooden frame and a canvas with a texture map */
    const RayesParam frame[] = {fp("axis", 0), cp("Clight", 0.5f, 0.35f, 0.12f),
                                cp("Cdark", 0.3f, 0.18f, 0.05f), fp("Ks", 0.6f)};
    shader(r, "wood", frame, 4);
    const float px0 = -1.4f, px1 = 0.0f, py0 = 1.2f, py1 = 2.25f, z = -3.99f;
    box(r, px0 - 0.06f, px1 + 0.06f, py0 - 0.06f, py0, z, z + 0.04f, 3);
    box(r, px0 - 0.06f, px1 + 0.06f, py1, py1 + 0.06f, z, z + 0.04f, 3);
    box(r, px0 - 0.06f, px0, py0, py1, z, z + 0.04f, 3);
    box(r, px1, px1 + 0.06f, py0, py1, z, z + 0.04f, 3);
    const RayesParam canvas[] = {sp("texturename", "painting.png"), fp("Kd", 0.9f),
                                 fp("Ks", 0.05f)};
    shader(r, "paintedplastic", canvas, 3);
    /* (s, t) = (0, 0) at the top left */
    rect(r, (float[3]){px0, py1, z + 0.02f}, (float[3]){px1 - px0, 0, 0},
         (float[3]){0, py0 - py1, 0}, 2, 1, 1, 1);
    /* the rug: a checkerboard worn by fbm */
    static const RayesParam check[] = {{"tex1", RAYES_PARAM_COLOR, {0.45f, 0.08f, 0.06f}, NULL},
                                       {"tex2", RAYES_PARAM_COLOR, {0.7f, 0.6f, 0.4f}, NULL},
                                       {"uscale", RAYES_PARAM_FLOAT, {10, 0, 0}, NULL},
                                       {"vscale", RAYES_PARAM_FLOAT, {7, 0, 0}, NULL}};
    pattern(r, "rugcheck", "checkerboard", check, 4);
    static const RayesParam wear[] = {{"octaves", RAYES_PARAM_FLOAT, {5, 0, 0}, NULL}};
    const float ws = 8.0f;
    const float wm[16] = {ws, 0, 0, 0, 0, ws, 0, 0, 0, 0, ws, 0, 0, 0, 0, 1};
    transform(r, wm);
    pattern(r, "rugwear", "fbm", wear, 1);
    transform(r, identity);
    const RayesParam rugmix[] = {pat("tex1", "rugcheck"), cp("tex2", 0.3f, 0.22f, 0.15f),
                                 pat("amount", "rugwear")};
    pattern(r, "rug", "mix", rugmix, 3);
    const RayesParam rugp[] = {pat("reflectance", "rug")};
    shader(r, "diffuse", rugp, 1);
    rect(r, (float[3]){-2.0f, 0.008f, 0.2f}, (float[3]){2.6f, 0, 0}, (float[3]){0, 0, -1.8f}, 2, 2,
         1, 1);
}

/* A floor lamp by the sofa and a pendant over the table: shades of
 * revolution, a chrome pole. */
static void lamps(Room *r)
{
    const RayesParam chrome[] = {cp("Cs", 0.8f, 0.8f, 0.8f), fp("roughness", 0.05f)};
    shader(r, "shinymetal", chrome, 2);
    const float pole[16] = {1, 0, 0, 0.3f, 0, 0, 1, 0, 0, -1, 0, -3.5f, 0, 0, 0, 1};
    transform(r, pole); /* a cylinder along object z, turned to stand along +y */
    const float cyl[4] = {0.015f, 0.0f, 1.55f, 360.0f};
    if (r->e == RAYES_OK)
        r->e = r->s->quadric(r->s->target, RAYES_QUADRIC_CYLINDER, cyl, 4, 0);
    const float disk[3] = {0.0f, 0.16f, 360.0f};
    if (r->e == RAYES_OK)
        r->e = r->s->quadric(r->s->target, RAYES_QUADRIC_DISK, disk, 3, 0);
    transform(r, identity);
    const RayesParam linen[] = {cp("Cs", 0.9f, 0.82f, 0.65f), fp("Kd", 0.8f), fp("Ks", 0.0f)};
    shader(r, "plastic", linen, 3);
    const float shade[4][2] = {{0.22f, 0}, {0.2f, 0.1f}, {0.17f, 0.2f}, {0.14f, 0.28f}};
    revolve(r, 0.3f, 1.45f, -3.5f, shade);
    const float pendant[4][2] = {{0.3f, 0}, {0.22f, 0.12f}, {0.1f, 0.22f}, {0.03f, 0.25f}};
    const RayesParam brass[] = {cp("Cs", 0.75f, 0.55f, 0.25f), fp("roughness", 0.1f)};
    shader(r, "shinymetal", brass, 2);
    revolve(r, -0.7f, 1.85f, -1.7f, pendant);
}

/* A light frame: origin o, +z toward dir (the emitting side), x along a
 * vector not parallel to it. */
static void frame_toward(float m[16], const float o[3], const float dir[3])
{
    float z[3] = {dir[0], dir[1], dir[2]}, n = sqrtf(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
    for (int c = 0; c < 3; c++)
        z[c] /= n;
    float up[3] = {0, 1, 0};
    if (fabsf(z[1]) > 0.9f)
        up[0] = 1, up[1] = 0;
    float x[3] = {up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2],
                  up[0] * z[1] - up[1] * z[0]};
    n = sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int c = 0; c < 3; c++)
        x[c] /= n;
    float y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    const float f[16] = {x[0], y[0], z[0], o[0], x[1], y[1], z[1], o[1],
                         x[2], y[2], z[2], o[2], 0,    0,    0,    1};
    memcpy(m, f, sizeof f);
}

/* A quad area light a x b centred on o, emitting toward dir, of radiance
 * intensity times colour (a quad, as RIB's AreaLightSource writes and
 * reads them). */
static void area(Room *r, const float o[3], const float dir[3], float a, float b, float intensity,
                 const float colour[3])
{
    float m[16], P[4][3];
    frame_toward(m, o, dir);
    static const float su[4] = {-0.5f, 0.5f, 0.5f, -0.5f}, sv[4] = {-0.5f, -0.5f, 0.5f, 0.5f};
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++)
            P[k][c] = o[c] + su[k] * a * m[4 * c] + sv[k] * b * m[4 * c + 1];
    const float L[3] = {intensity * colour[0], intensity * colour[1], intensity * colour[2]};
    if (r->e == RAYES_OK)
        r->e = r->s->area_light(r->s->target, (const float(*)[3])P, L);
}

static void spot(Room *r, const float from[3], const float to[3], float cone, float delta,
                 float intensity, const float colour[3])
{
    const RayesParam p[] = {cp("from", from[0], from[1], from[2]),
                            cp("to", to[0], to[1], to[2]),
                            fp("coneangle", cone),
                            fp("conedeltaangle", delta),
                            fp("intensity", intensity),
                            cp("lightcolor", colour[0], colour[1], colour[2])};
    light(r, "spotlight", p, 6);
}

static void point(Room *r, const float from[3], float intensity, const float colour[3])
{
    const RayesParam p[] = {cp("from", from[0], from[1], from[2]), fp("intensity", intensity),
                            cp("lightcolor", colour[0], colour[1], colour[2])};
    light(r, "pointlight", p, 3);
}

/* The 20 lights. */
static void lights(Room *r)
{
    static const float warm[3] = {1.0f, 0.85f, 0.65f}, white[3] = {1.0f, 0.96f, 0.9f},
                       cool[3] = {0.8f, 0.88f, 1.0f}, candle[3] = {1.0f, 0.7f, 0.4f};
    transform(r, identity);
    /* the back of an area light quad is a surface like any other: a dark
     * housing (which the pendant's brass shade reflects) */
    const RayesParam housing[] = {cp("Cs", 0.05f, 0.05f, 0.05f)};
    shader(r, "matte", housing, 1);
    /* 1: the sky, seen through the window */
    const RayesParam sky[] = {sp("mapname", "sky.png"), fp("intensity", 0.35f)};
    light(r, "environmentlight", sky, 2);
    /* 2: the sun through the window, onto the floor */
    const RayesParam sun[] = {cp("from", 0, 0, 0), cp("to", 1.0f, -0.75f, 0.25f),
                              fp("intensity", 8.0f), cp("lightcolor", 1.0f, 0.92f, 0.8f)};
    light(r, "distantlight", sun, 4);
    /* 3-5: ceiling panels facing down */
    area(r, (float[3]){-0.7f, 2.78f, -1.7f}, (float[3]){0, -1, 0}, 1.0f, 0.5f, 7.0f, white);
    area(r, (float[3]){1.5f, 2.78f, -2.8f}, (float[3]){0, -1, 0}, 1.0f, 0.5f, 6.0f, white);
    /* the window's portal: the sky's light through the opening, which the
     * environment light alone gives only as the speckle of its few samples
     * that pass the window; unseen by camera rays, which see the sky */
    if (r->e == RAYES_OK && r->s->set_visibility)
        r->e = r->s->set_visibility(r->s->target, RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR);
    area(r, (float[3]){-3.09f, 1.6f, -1.7f}, (float[3]){1, 0, 0}, 2.0f, 1.4f, 0.9f, cool);
    if (r->e == RAYES_OK && r->s->set_visibility)
        r->e = r->s->set_visibility(r->s->target, RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE |
                                                      RAYES_RAY_SPECULAR | RAYES_RAY_SHADOW);
    /* 6: the pendant's diffuser, 7: a wall washer by the shelves, 8: the
     * floor lamp's diffuser */
    area(r, (float[3]){-0.7f, 1.86f, -1.7f}, (float[3]){0, -1, 0}, 0.35f, 0.35f, 12.0f, warm);
    area(r, (float[3]){2.5f, 2.6f, 1.0f}, (float[3]){0.3f, -1, 0}, 0.2f, 0.2f, 10.0f, white);
    area(r, (float[3]){0.3f, 1.55f, -3.5f}, (float[3]){0, -1, 0}, 0.18f, 0.18f, 15.0f, warm);
    /* 9-15: spot lights with soft edges */
    spot(r, (float[3]){-0.7f, 2.75f, -2.2f}, (float[3]){-0.7f, 1.7f, -4.0f}, 30, 10, 3.5f, warm);
    spot(r, (float[3]){-0.2f, 2.75f, -2.4f}, (float[3]){-0.8f, 1.6f, -4.0f}, 25, 10, 2.0f, white);
    spot(r, (float[3]){2.0f, 2.75f, -0.7f}, (float[3]){2.9f, 1.2f, -0.7f}, 35, 12, 3.0f, white);
    spot(r, (float[3]){2.0f, 2.75f, 0.5f}, (float[3]){2.9f, 0.8f, -1.0f}, 30, 12, 2.0f, warm);
    spot(r, (float[3]){0.3f, 2.75f, -0.8f}, (float[3]){-0.7f, 0.77f, -1.7f}, 28, 8, 4.0f, warm);
    spot(r, (float[3]){1.6f, 2.75f, -2.0f}, (float[3]){1.6f, 0.4f, -3.4f}, 35, 15, 2.5f, warm);
    spot(r, (float[3]){-2.5f, 2.75f, 1.5f}, (float[3]){-1.5f, 0.0f, -0.5f}, 40, 15, 2.0f, cool);
    /* 16-20: point lights: fills and a candle on the table */
    point(r, (float[3]){-0.45f, 0.95f, -1.45f}, 0.08f, candle);
    point(r, (float[3]){0.0f, 2.3f, 1.5f}, 0.8f, white);
    point(r, (float[3]){-2.3f, 2.2f, -3.3f}, 0.5f, warm);
    point(r, (float[3]){2.3f, 1.2f, 2.2f}, 0.4f, cool);
    point(r, (float[3]){1.6f, 1.5f, -2.4f}, 0.3f, warm);
}

/* A candle on the table (for the point light above it). */
static void candle(Room *r)
{
    const RayesParam wax[] = {cp("Cs", 0.95f, 0.92f, 0.85f), fp("Ks", 0.2f)};
    shader(r, "plastic", wax, 2);
    box(r, -0.48f, -0.42f, 0.77f, 0.92f, -1.48f, -1.42f, 1.0f);
}

/* The camera, looking from near the front wall at the back wall, as a
 * matrix (RenderMan's camera space: +z ahead, +y up, +x right, so the
 * right-handed world is seen through a mirror), rounded to floats once:
 * the RIB writer writes these floats exactly, so a converted file renders
 * the same bytes (a look-at camera would be rounded again on the way). */
static void camera_matrix(float m[16])
{
    const double eye[3] = {1.0, 1.5, 2.5}, at[3] = {-0.35, 0.95, -2.6}, up[3] = {0, 1, 0};
    double f[3], r[3], u[3];
    for (int k = 0; k < 3; k++)
        f[k] = at[k] - eye[k];
    double l = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= l;
    r[0] = f[1] * up[2] - f[2] * up[1];
    r[1] = f[2] * up[0] - f[0] * up[2];
    r[2] = f[0] * up[1] - f[1] * up[0];
    l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        r[k] /= l;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    const double *rows[3] = {r, u, f};
    memset(m, 0, 16 * sizeof *m);
    for (int i = 0; i < 3; i++) {
        double d = 0.0;
        for (int k = 0; k < 3; k++) {
            m[4 * i + k] = (float)rows[i][k];
            d += rows[i][k] * eye[k];
        }
        m[4 * i + 3] = (float)-d;
    }
    m[15] = 1.0f;
}

RayesError io_builtin_production_room(const IoSink *s, char *err, size_t err_size)
{
    char dir[1024];
    RayesError e = make_textures(dir, sizeof dir, err, err_size);
    if (e != RAYES_OK)
        return e;
    Room r = {s, RAYES_OK};
    if (s->set_search_path)
        r.e = s->set_search_path(s->target, "texture", dir);
    float camera_from_world[16];
    camera_matrix(camera_from_world);
    if (r.e == RAYES_OK)
        r.e = s->set_camera_matrix(s->target, camera_from_world, RAYES_PROJECTION_PERSPECTIVE,
                                   52.0f, NULL);
    walls(&r);
    displacement(&r, NULL, NULL, 0, 0.0f);
    window(&r);
    table_and_chairs(&r);
    sofa(&r);
    shelves(&r);
    objects(&r);
    lamps(&r);
    candle(&r);
    lights(&r);
    return r.e;
}
