/*
 * Lights (shade/light.c, the direct-lighting and ambient services of
 * render/integrator.c, rayes_scene_light): analytic irradiance of point,
 * spot, distant, ambient, disk and sphere lights; multiple importance
 * sampling against brute-force estimates of a glossy lobe under small and
 * large quads, and under mesh lights of many faces; a closed mesh light
 * against a sphere's closed form; a constant-environment white furnace; an importance-sampled
 * latitude-longitude map against a uniform-sphere estimate, its sampling
 * against a binary search and pixel_pdf (chi-square); categories;
 * emitters seen by the camera; determinism with every light type; errors.
 *
 * The services are called directly on one shading point, on a scene
 * prepared the way a render prepares it.
 */
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "image/image.h"
#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "render/services.h"
#include "scene/scene.h"
#include "shade/light.h"
#include "test.h"
#include "util/rng.h"

static const double PI = 3.14159265358979;

/* ------------------------------------------------------------ fixture */

typedef struct Fx {
    RayesScene *s;
    GridSet gs;
    Accel *accel;
    uint32_t *masks;
    RenderObject *objs;
    RenderScene rs;
    RenderSettings set;
    Worker w;
} Fx;

static void fx_init(Fx *f, RayesScene *s)
{
    memset(f, 0, sizeof *f);
    f->s = s;
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    geom_gridset_init(&f->gs);
    CHECK(scene_prepare(s, 64, 64, NULL, NULL, &f->gs, NULL, NULL, 0) == 0);
    f->masks = calloc(s->n_objects + 1, sizeof *f->masks);
    f->objs = calloc(s->n_objects + 1, sizeof *f->objs);
    for (size_t i = 0; i < s->n_objects; i++) {
        f->masks[i] = s->objects[i].ray_mask;
        if (s->objects[i].light >= 0 && s->lights[s->objects[i].light].type == LIGHT_MESH)
            f->masks[i] |= ACCEL_MASK_OWN_SCENE; /* as the session makes them */
        f->objs[i].light = s->objects[i].light;
        f->objs[i].shader = s->objects[i].shader.cls ? &s->objects[i].shader : NULL;
        memcpy(f->objs[i].Cs, s->objects[i].Cs, sizeof f->objs[i].Cs);
        memcpy(f->objs[i].Os, s->objects[i].Os, sizeof f->objs[i].Os);
    }
    char err[300];
    f->accel = accel_new(&f->gs, f->masks, s->n_objects, NULL, err, sizeof err);
    CHECK(f->accel != NULL);
    f->rs = (RenderScene){.gs = &f->gs, .accel = f->accel, .objects = f->objs,
                          .n_objects = s->n_objects, .lights = s->lights,
                          .n_lights = s->n_lights, .scene_radius = 10.0f};
    f->set = (RenderSettings){.width = 64, .height = 64, .spp = 1, .threads = 1,
                              .tile_size = 16, .shadow_rays = 16, .shadow_rays_deep = 16};
    f->w = (Worker){.rs = &f->rs, .set = &f->set, .services = &render_services, .split = 1.0f};
}

static void fx_fini(Fx *f)
{
    accel_free(f->accel);
    geom_gridset_fini(&f->gs);
    free(f->masks);
    free(f->objs);
    rayes_scene_release(f->s);
}

/* The direct-lighting service at P with normal N (viewed along I if not
 * NULL), n samples, averaged over `keys` sample keys. */
static void fx_direct(Fx *f, Vec3 P, Vec3 N, const Vec3 *I, int n, const char *category,
                      float roughness, int keys, double d[3], double s[3])
{
    float Pa[1][3] = {{P.x, P.y, P.z}}, Na[1][3] = {{N.x, N.y, N.z}};
    float Ia[1][3] = {{I ? I->x : 0, I ? I->y : 0, I ? I->z : 0}};
    RayDiff diff[1] = {{0.0f, 0.0f}};
    float curv[1] = {0.0f}, off[1] = {0.0f}; /* rays leave from P itself */
    for (int c = 0; c < 3; c++)
        d[c] = s[c] = 0.0;
    for (int k = 0; k < keys; k++) {
        uint64_t key[1] = {hash_combine(1234, (uint64_t)k)};
        PathState ps = {&f->w, key, diff, curv, off};
        RayesShadeCtx ctx = {.n_points = 1, .ray_type = RAYES_RAY_CAMERA,
                             .P = (const float(*)[3])Pa, .N = (const float(*)[3])Na,
                             .Ng = (const float(*)[3])Na,
                             .I = I ? (const float(*)[3])Ia : NULL, .renderer = &ps};
        float dd[1][3], ss[1][3];
        render_services.direct_lighting(&render_services, &ctx, n, category, &roughness, dd, ss);
        for (int c = 0; c < 3; c++) {
            d[c] += dd[0][c] / keys;
            s[c] += ss[0][c] / keys;
        }
    }
}

/* Irradiance: pi times the diffuse output. */
static double fx_irradiance(Fx *f, Vec3 P, Vec3 N, int n, const char *category)
{
    double d[3], s[3];
    fx_direct(f, P, N, NULL, n, category, 0.1f, 1, d, s);
    return PI * d[0];
}

/* Irradiance averaged over `keys` sample keys (mesh lights draw a cluster
 * before a point: one key's 64 samples stratify less than a quad's). */
static double fx_irradiance_mean(Fx *f, Vec3 P, Vec3 N, int n, int keys)
{
    double d[3], s[3];
    fx_direct(f, P, N, NULL, n, NULL, 0.1f, keys, d, s);
    return PI * d[0];
}

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}
static RayesParam pv(const char *name, float x, float y, float z)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {x, y, z}, NULL};
}
static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

/* ------------------------------------------------------- delta lights */

static void test_point_light_inverse_square(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam p[3] = {pv("from", 0, 0, 2), pf("intensity", 4), pv("lightcolor", 1, 0.5f, 0.25f)};
    CHECK(rayes_scene_light(s, "pointlight", p, 3) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    double d[3], sp[3];
    fx_direct(&f, v3(0, 0, 0), v3(0, 0, 1), NULL, 4, NULL, 0.1f, 1, d, sp);
    CHECK_NEAR(PI * d[0], 1.0, 1e-5); /* 4 / 2^2 */
    CHECK_NEAR(PI * d[1], 0.5, 1e-5);
    CHECK_NEAR(PI * d[2], 0.25, 1e-5);
    /* 60 degrees off the normal: E = I cos / d^2. */
    CHECK_NEAR(fx_irradiance(&f, v3(0, 0, 0), v3((float)sin(PI / 3), 0, (float)cos(PI / 3)), 4,
                             NULL),
               0.5, 1e-5);
    /* From behind: nothing. */
    CHECK_NEAR(fx_irradiance(&f, v3(0, 0, 0), v3(0, 0, -1), 4, NULL), 0.0, 0.0);
    fx_fini(&f);
}

static void test_spot_light_cone(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam p[6] = {pv("from", 0, 0, 2),      pv("to", 0, 0, 0),
                       pf("intensity", 4),       pf("coneangle", 30),
                       pf("conedeltaangle", 10), pf("beamdistribution", 2)};
    CHECK(rayes_scene_light(s, "spotlight", p, 6) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    const double cos30 = cos(30 * PI / 180), cos20 = cos(20 * PI / 180);
    const double angles[3] = {10, 25, 35}; /* inside, in the falloff band, outside */
    for (int k = 0; k < 3; k++) {
        double a = angles[k] * PI / 180, x = 2 * tan(a), d2 = 4 + x * x, c = cos(a);
        double t = (c - cos30) / (cos20 - cos30);
        double smooth = c <= cos30 ? 0 : c >= cos20 ? 1 : t * t * (3 - 2 * t);
        double expected = 4 / d2 * c /* surface cosine */ * smooth * c * c;
        double got = fx_irradiance(&f, v3((float)x, 0, 0), v3(0, 0, 1), 4, NULL);
        CHECK_NEAR(got, expected, 1e-5 + 1e-4 * expected);
        if (k == 1)
            CHECK(got > 0.05 && smooth < 0.9); /* really in the band */
        if (k == 2)
            CHECK(got == 0.0);
    }
    fx_fini(&f);
}

static void test_distant_light(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam p[3] = {pv("from", 0, 0, 1), pv("to", 0, 0, 0), pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "distantlight", p, 3) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    CHECK_NEAR(fx_irradiance(&f, v3(5, 7, -3), v3((float)sin(PI / 3), 0, (float)cos(PI / 3)), 4,
                             NULL),
               1.0, 1e-5); /* no 1/d^2 */
    fx_fini(&f);
}

static void test_ambient_light(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam a[2] = {pf("intensity", 0.5f), pv("lightcolor", 1, 0.5f, 0.25f)};
    RayesParam b[1] = {pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "ambientlight", a, 2) == RAYES_OK);
    CHECK(rayes_scene_light(s, "ambientlight", b, 1) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    float P[1][3] = {{0, 0, 0}}, N[1][3] = {{0, 0, 1}}, out[1][3];
    PathState st = {&f.w, (uint64_t[]){1}, (RayDiff[]){{0, 0}}, (float[]){0}, (float[]){1e-4f}};
    RayesShadeCtx ctx = {.n_points = 1, .P = (const float(*)[3])P, .N = (const float(*)[3])N,
                         .Ng = (const float(*)[3])N, .renderer = &st};
    render_services.ambient(&render_services, &ctx, out);
    CHECK_NEAR(out[0][0], 1.5, 1e-6);
    CHECK_NEAR(out[0][1], 1.25, 1e-6);
    CHECK_NEAR(out[0][2], 1.125, 1e-6);
    CHECK(f.w.stats.ambient_lookups == 1);
    /* Ambient lights are not direct light. */
    CHECK(fx_irradiance(&f, v3(0, 0, 0), v3(0, 0, 1), 4, NULL) == 0.0);
    fx_fini(&f);
}

/* --------------------------------------------------------- area lights */

static void test_disk_light_irradiance(void)
{
    RayesScene *s = rayes_scene_new();
    /* The disk's +z turned to -z, 2 above the origin. */
    const float flip[16] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 2, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, flip) == RAYES_OK);
    RayesParam p[3] = {ps("shape", "disk"), pf("radius", 1), pf("intensity", 3)};
    CHECK(rayes_scene_light(s, "arealight", p, 3) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    /* A disk of radius R at height h on the axis: E = L pi R^2 / (h^2 + R^2). */
    double E = fx_irradiance(&f, v3(0, 0, 0), v3(0, 0, 1), 64, NULL);
    CHECK_NEAR(E / (3 * PI / 5), 1.0, 0.01);
    /* Far below (h = 12 >= 5 R): the light's samples alone, no cosine
     * strategy; the same closed form. */
    E = fx_irradiance(&f, v3(0, 0, -10), v3(0, 0, 1), 64, NULL);
    CHECK_NEAR(E / (3 * PI / 145), 1.0, 0.01);
    /* Above the disk: its back, which does not emit. */
    CHECK(fx_irradiance(&f, v3(0, 0, 4), v3(0, 0, -1), 64, NULL) == 0.0);
    fx_fini(&f);
}

/* The ball around a light (LightBound) never rejects a direction that
 * light_intersect takes, from points near and far, including directions
 * aimed exactly at a quad's corners and edges; and it rejects most
 * directions from far points (else it would save nothing). */
static void test_light_bound_keeps_every_hit(void)
{
    Light q = {.type = LIGHT_QUAD, .L = {1, 1, 1}};
    q.P[0] = v3(-0.75f, -4.5f, 5.5f), q.P[1] = v3(0.8f, -4.6f, 5.4f);
    q.P[2] = v3(-0.7f, -3.9f, 4.9f), q.P[3] = v3(0.75f, -4.0f, 4.95f); /* not a parallelogram */
    Light d = {.type = LIGHT_DISK, .L = {1, 1, 1}, .from = {0, 0, 3}, .ex = {1.5f, 0, 0},
               .ey = {0, 0.4f, 0.3f}};
    d.normal = v3_normalize(v3_neg(v3_cross(d.ex, d.ey)));
    d.area = (float)PI * v3_length(v3_cross(d.ex, d.ey));
    Light sp = {.type = LIGHT_SPHERE, .L = {1, 1, 1}, .from = {1, 2, 3}, .radius = 0.5f};
    const Light *lights[3] = {&q, &d, &sp};
    long hits = 0, rejected = 0, far = 0;
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 200; i++) {
            float scale = i < 100 ? 2.0f : 40.0f; /* near, then far */
            Vec3 o = v3(scale * (rng_float(hash_combine(i, 1)) - 0.5f),
                        scale * (rng_float(hash_combine(i, 2)) - 0.5f),
                        scale * (rng_float(hash_combine(i, 3)) - 0.5f));
            LightBound b;
            light_bound_init(lights[k], o, &b);
            for (int j = 0; j < 2000; j++) {
                Vec3 wi;
                if (k == 0 && j < 8) { /* a corner, or an edge's midpoint */
                    Vec3 y = j < 4 ? q.P[j] : v3_scale(v3_add(q.P[j - 4], q.P[(j - 3) % 4]), 0.5f);
                    wi = v3_normalize(v3_sub(y, o));
                } else {
                    float z = 1.0f - 2.0f * rng_float(hash_combine(hash_combine(i, j), 4));
                    float phi = 2.0f * (float)PI * rng_float(hash_combine(hash_combine(i, j), 5));
                    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
                    wi = v3(r * cosf(phi), r * sinf(phi), z);
                }
                LightSample ls;
                int hit = light_intersect(lights[k], o, wi, &ls);
                int may = light_bound_may_hit(&b, wi);
                hits += hit;
                if (hit && !may) {
                    CHECK(!"the bound rejected a hit");
                    return;
                }
                if (i >= 100) {
                    far++;
                    rejected += !may;
                }
            }
        }
    CHECK(hits > 1000);
    CHECK(rejected > far * 9 / 10);
}

static void test_sphere_light_irradiance(void)
{
    RayesScene *s = rayes_scene_new();
    const float move[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, move) == RAYES_OK);
    RayesParam p[3] = {ps("shape", "sphere"), pf("radius", 1), pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "arealight", p, 3) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    /* A sphere wholly above the horizon: E = L pi (R / D)^2. */
    double E = fx_irradiance(&f, v3(0, 0, 0), v3(0, 0, 1), 64, NULL);
    CHECK_NEAR(E / (2 * PI / 9), 1.0, 0.01);
    /* Tilted 45 degrees the sphere (half angle 19.5) still stands above the
     * horizon: E scales with the cosine. */
    E = fx_irradiance(&f, v3(0, 0, 0), v3((float)sqrt(0.5), 0, (float)sqrt(0.5)), 64, NULL);
    CHECK_NEAR(E / (2 * PI / 9 * sqrt(0.5)), 1.0, 0.01);
    fx_fini(&f);
}

/* Irradiance from a polygon of constant radiance 1 (Lambert's formula). */
static double polygon_irradiance(Vec3 o, Vec3 N, const Vec3 *v, int n)
{
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        Vec3 a = v3_normalize(v3_sub(v[i], o)), b = v3_normalize(v3_sub(v[(i + 1) % n], o));
        double angle = acos(fmax(-1.0, fmin(1.0, v3_dot(a, b))));
        sum += angle * v3_dot(N, v3_normalize(v3_cross(a, b)));
    }
    return 0.5 * fabs(sum);
}

/* Brute force: the specular output's integral by sampling the half vector
 * about N (no MIS), against the light's quad intersected here. */
static double brute_glossy(Vec3 N, Vec3 V, float e, Vec3 c, float half, int m)
{
    double sum = 0.0;
    Vec3 t, b;
    v3_basis(N, &t, &b);
    for (int k = 0; k < m; k++) {
        float a1, a2;
        cmj_sample_2d((uint32_t)k, (uint32_t)m, 77u, &a1, &a2);
        float ch = powf(a1, 1.0f / (e + 1.0f)), sh = sqrtf(fmaxf(0.0f, 1 - ch * ch));
        float phi = 2.0f * (float)PI * a2;
        Vec3 H = v3_add(v3_add(v3_scale(t, sh * cosf(phi)), v3_scale(b, sh * sinf(phi))),
                        v3_scale(N, ch));
        float vh = v3_dot(V, H);
        if (vh <= 0)
            continue;
        Vec3 wi = v3_sub(v3_scale(H, 2 * vh), V);
        if (v3_dot(N, wi) <= 0 || wi.z <= 0)
            continue;
        float tt = c.z / wi.z; /* the light lies in z = c.z, facing down */
        float x = wi.x * tt - c.x, y = wi.y * tt - c.y;
        if (fabsf(x) > half || fabsf(y) > half)
            continue;
        double pdf = (e + 1) / (2 * PI) * pow(ch, e) / (4 * vh);
        double f = (e + 8) / (8 * PI) * pow(ch, e);
        sum += f * v3_dot(N, wi) / pdf;
    }
    return sum / m;
}

static void mesh_light_square(RayesScene *s, Vec3 c, float half, int n, float L, int two_sided);

/* RenderMan's specular() (the classic_lighting service) at the origin,
 * normal +z, viewed from V: keys sample keys of n samples. */
static double fx_classic_specular(Fx *f, Vec3 V, float roughness, int n, int keys)
{
    float Pa[1][3] = {{0, 0, 0}}, Na[1][3] = {{0, 0, 1}}, Ia[1][3] = {{-V.x, -V.y, -V.z}};
    RayDiff diff[1] = {{0.0f, 0.0f}};
    float curv[1] = {0.0f}, off[1] = {0.0f};
    double sum = 0.0;
    for (int k = 0; k < keys; k++) {
        uint64_t key[1] = {hash_combine(99, (uint64_t)k)};
        PathState ps = {&f->w, key, diff, curv, off};
        RayesShadeCtx ctx = {.n_points = 1,
                             .ray_type = RAYES_RAY_CAMERA,
                             .P = (const float(*)[3])Pa,
                             .N = (const float(*)[3])Na,
                             .Ng = (const float(*)[3])Na,
                             .I = (const float(*)[3])Ia,
                             .renderer = &ps};
        float dd[1][3], ss[1][3];
        render_services.classic_lighting(&render_services, &ctx, n, NULL, &roughness, dd, ss);
        sum += ss[0][0] / keys;
    }
    return sum;
}

/* The classic shaders' highlight is the RenderMan specification's
 * specular(): the sum over lights of Cl (N.H)^(1 / roughness), no cosine,
 * not normalised (a RIB point light of intensity I is pi I here, so its Cl
 * is the irradiance over pi); an area light's is (1/pi) times the integral
 * of L (N.H)^e over its solid angle, checked against a brute-force sum over
 * the light's area. The reference pictures of classic RIB files (a
 * plastic teapot, gears) match it within 1.2% in the mean; the normalised
 * lobe made their highlights 2.25 times as bright and far wider. */
static void test_classic_specular(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam p[2] = {pv("from", 0, 0, 2), pf("intensity", 4)};
    CHECK(rayes_scene_light(s, "pointlight", p, 2) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    const float rough[3] = {0.1f, 0.05f, 0.5f};
    for (int k = 0; k < 3; k++) {
        Vec3 V = v3_normalize(v3(0.4f, 0.1f, 1.0f)), L = v3(0, 0, 1);
        Vec3 H = v3_normalize(v3_add(V, L));
        double want = 4.0 / 4.0 / PI * pow(H.z, 1.0 / rough[k]);
        CHECK_NEAR(fx_classic_specular(&f, V, rough[k], 4, 1), want, 1e-5 * want + 1e-9);
    }
    /* the diffuse output is direct_lighting's */
    double d[3], sp[3];
    fx_direct(&f, v3(0, 0, 0), v3(0, 0, 1), NULL, 4, NULL, 0.1f, 1, d, sp);
    CHECK_NEAR(PI * d[0], 1.0, 1e-5);
    fx_fini(&f);

    s = rayes_scene_new();
    Vec3 c = v3(0.6f, 0.1f, 1.5f);
    const float half = 0.4f, m[16] = {1, 0, 0, c.x, 0, -1, 0, c.y, 0, 0, -1, c.z, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    RayesParam q[4] = {ps("shape", "quad"), pf("width", 2 * half), pf("height", 2 * half),
                       pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "arealight", q, 4) == RAYES_OK);
    fx_init(&f, s);
    Vec3 V = v3_normalize(v3(-0.5f, -0.1f, 1.0f));
    for (int k = 0; k < 2; k++) {
        float r = k ? 0.02f : 0.2f;
        double ref = 0.0; /* (1/pi) sum of (N.H)^e cos_light / d^2 dA over a 1024^2 lattice */
        const int g = 1024;
        for (int j = 0; j < g; j++)
            for (int i = 0; i < g; i++) {
                Vec3 x = v3(c.x - half + 2 * half * (i + 0.5f) / g,
                            c.y - half + 2 * half * (j + 0.5f) / g, c.z);
                double d2 = v3_dot(x, x);
                Vec3 wi = v3_scale(x, 1.0f / (float)sqrt(d2));
                Vec3 H = v3_normalize(v3_add(wi, V));
                ref += pow(fmax(H.z, 0.0), 1.0 / r) * wi.z / d2;
            }
        ref *= (2.0 * half / g) * (2.0 * half / g) / PI;
        double got = fx_classic_specular(&f, V, r, 64, 16);
        CHECK(ref > 0.0);
        CHECK_NEAR(got / ref, 1.0, 0.02);
    }
    fx_fini(&f);
}

/* A square light of side 2 half facing down at c, a quad light or (mesh)
 * a mesh light of many faces tiling it (its lobe's directions found in the
 * emitter's own scene). */
static void check_glossy_light(float half, float roughness, int mesh)
{
    RayesScene *s = rayes_scene_new();
    Vec3 c = v3(0.6f, 0.1f, 1.5f);
    if (mesh) {
        mesh_light_square(s, c, half, 6, 1.0f, 0);
    } else { /* turn +z to -z, centre at c */
        const float m[16] = {1, 0, 0, c.x, 0, -1, 0, c.y, 0, 0, -1, c.z, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
        RayesParam p[4] = {ps("shape", "quad"), pf("width", 2 * half), pf("height", 2 * half),
                           pf("intensity", 1)};
        CHECK(rayes_scene_light(s, "arealight", p, 4) == RAYES_OK);
    }
    Fx f;
    fx_init(&f, s);
    Vec3 N = v3(0, 0, 1), V = v3_normalize(v3(-0.5f, -0.1f, 1.0f)), I = v3_neg(V);
    double d[3], sp[3];
    fx_direct(&f, v3(0, 0, 0), N, &I, 64, NULL, roughness, 16, d, sp);
    double ref_s = brute_glossy(N, V, 1.0f / roughness, c, half, 1 << 21);
    Vec3 quad[4] = {v3(c.x - half, c.y - half, c.z), v3(c.x + half, c.y - half, c.z),
                    v3(c.x + half, c.y + half, c.z), v3(c.x - half, c.y + half, c.z)};
    double ref_d = polygon_irradiance(v3(0, 0, 0), N, quad, 4) / PI;
    CHECK(ref_s > 0.0);
    CHECK_NEAR(d[0] / ref_d, 1.0, 0.01);
    CHECK_NEAR(sp[0] / ref_s, 1.0, 0.02);
    fx_fini(&f);
}

/* A point close below a large rectangular light, near its edge (a wall
 * beside a window-sized light): the light is sampled by solid angle
 * (light.c sphrect_point), so 16 samples find its irradiance within 3%
 * at each of 8 points along the edge (measured 1.6%; by area, samples
 * land where the light is seen at a grazing angle, weighted by 1 / d^2:
 * 8.1%). */
static void test_quad_light_close(void)
{
    RayesScene *s = rayes_scene_new();
    const float m[16] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 0.05f, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    RayesParam p[4] = {ps("shape", "quad"), pf("width", 2), pf("height", 2), pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "arealight", p, 4) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    Vec3 quad[4] = {v3(-1, -1, 0.05f), v3(1, -1, 0.05f), v3(1, 1, 0.05f), v3(-1, 1, 0.05f)};
    Vec3 N = v3(0, 0, 1);
    double worst = 0.0, least = 1e30;
    for (int k = 0; k < 8; k++) { /* points along the edge */
        Vec3 P = v3(0.97f, -0.7f + 0.2f * (float)k, 0);
        double d[3], sp[3], ref = polygon_irradiance(P, N, quad, 4);
        fx_direct(&f, P, N, NULL, 16, NULL, 0.1f, 1, d, sp);
        worst = fmax(worst, fabs(PI * d[0] / ref - 1.0));
        least = fmin(least, ref);
    }
    CHECK(least > 1.0 && worst < 0.03);
    fx_fini(&f);
}

static void test_mis_glossy_small_quad(void)
{
    check_glossy_light(0.1f, 0.1f, 0);
    check_glossy_light(0.1f, 0.02f, 0);
}

static void test_mis_glossy_large_quad(void)
{
    check_glossy_light(2.0f, 0.1f, 0);
    check_glossy_light(2.0f, 0.02f, 0);
}

/* ---------------------------------------------------------- mesh lights */

/* The square of side 2 half about c in z = c.z as an n x n mesh light of
 * quads and triangles in turn (counter-clockwise seen from -z: facing
 * down), radiance L, one- or two-sided. */
static void mesh_light_square(RayesScene *s, Vec3 c, float half, int n, float L, int two_sided)
{
    float *P = malloc(sizeof(float) * 3 * (size_t)((n + 1) * (n + 1)));
    int *nv = malloc(sizeof(int) * (size_t)(2 * n * n)),
        *idx = malloc(sizeof(int) * 6 * (size_t)(n * n));
    size_t n_faces = 0, k = 0;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            float *p = &P[3 * (j * (n + 1) + i)];
            p[0] = c.x - half + 2 * half * (float)i / (float)n;
            p[1] = c.y - half + 2 * half * (float)j / (float)n;
            p[2] = c.z;
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i, b = a + 1, d = a + n + 1, e = d + 1;
            if ((i + j) % 2) { /* a quad */
                nv[n_faces++] = 4;
                idx[k++] = a, idx[k++] = d, idx[k++] = e, idx[k++] = b;
            } else { /* two triangles */
                nv[n_faces++] = 3, nv[n_faces++] = 3;
                idx[k++] = a, idx[k++] = d, idx[k++] = e;
                idx[k++] = a, idx[k++] = e, idx[k++] = b;
            }
        }
    const float Lc[3] = {L, L, L};
    CHECK(rayes_scene_area_light_mesh(s, n_faces, nv, idx, (size_t)((n + 1) * (n + 1)), P, Lc,
                                      two_sided) == RAYES_OK);
    free(P);
    free(nv);
    free(idx);
}

/* The clusters' bounds never cull a face that could light a point: for
 * triangles about a sphere, most facing out, and points about it, a
 * triangle with a corner or its centre in front of it and above the
 * point's horizon has a cluster of positive weight; and the bounds do cull
 * (else they would save nothing). */
static void test_mesh_light_clusters_keep_every_face(void)
{
    enum { N_TRI = 600 };
    Vec3 *v = malloc(sizeof *v * 3 * N_TRI);
    for (int k = 0; k < N_TRI; k++) { /* on a sphere of radius 2, facing out, some turned */
        float z = 2 * rng_float(hash_combine(k, 1)) - 1,
              ph = 6.2831853f * rng_float(hash_combine(k, 2));
        float r = sqrtf(fmaxf(0.0f, 1 - z * z));
        Vec3 n = v3(r * cosf(ph), r * sinf(ph), z), t, b;
        if (rng_float(hash_combine(k, 3)) < 0.1f)
            n = v3_normalize(v3_add(n, v3(0.9f, -0.5f, 0.3f)));
        v3_basis(n, &t, &b);
        Vec3 c = v3_scale(n, 2.0f);
        float e = 0.05f + 0.2f * rng_float(hash_combine(k, 4));
        v[3 * k] = v3_add(c, v3_scale(t, e));
        v[3 * k + 1] = v3_add(c, v3_add(v3_scale(t, -0.5f * e), v3_scale(b, 0.9f * e)));
        v[3 * k + 2] = v3_add(c, v3_add(v3_scale(t, -0.5f * e), v3_scale(b, -0.9f * e)));
    }
    Light l = {.L = {1, 1, 1}};
    CHECK(light_mesh_init(&l, v, N_TRI, 0) == 0);
    const LightMesh *m = l.mesh;
    CHECK(m->n_clusters == LIGHT_MESH_CLUSTERS);
    long culled = 0, facing = 0;
    for (int i = 0; i < 300; i++) {
        float sc = i < 150 ? 3.0f : 12.0f;
        Vec3 o = v3(sc * (rng_float(hash_combine(i, 11)) - 0.5f),
                    sc * (rng_float(hash_combine(i, 12)) - 0.5f),
                    sc * (rng_float(hash_combine(i, 13)) - 0.5f));
        Vec3 N = v3_normalize(v3(rng_float(hash_combine(i, 14)) - 0.5f,
                                 rng_float(hash_combine(i, 15)) - 0.5f,
                                 rng_float(hash_combine(i, 16)) - 0.5f));
        LightMeshView view;
        light_mesh_view(&l, o, N, &view);
        for (int c = 0; c < m->n_clusters; c++) {
            int weightless = !(view.cdf[c + 1] > view.cdf[c]);
            culled += weightless;
            for (uint32_t k = m->cluster[c].start; k < m->cluster[c].end; k++) {
                const Vec3 *p = &m->v[3 * (size_t)k];
                Vec3 n = v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
                Vec3 y[4] = {p[0], p[1], p[2],
                             v3_scale(v3_add(v3_add(p[0], p[1]), p[2]), 1 / 3.0f)};
                for (int j = 0; j < 4; j++) {
                    Vec3 d = v3_sub(y[j], o);
                    if (v3_dot(n, d) < 0 && v3_dot(N, d) > 0) {
                        facing++;
                        if (weightless) {
                            CHECK(!"a cluster that could light the point was culled");
                            light_fini(&l);
                            free(v);
                            return;
                        }
                    }
                }
            }
        }
    }
    CHECK(facing > 10000);
    CHECK(culled > 300L * m->n_clusters / 4);
    light_fini(&l);
    free(v);
}

/* A mesh light of many faces lights as the one quad it tiles: diffuse
 * irradiance against Lambert's closed form, the glossy highlight against
 * the brute-force lobe estimate; from above, one-sided, nothing; two-sided,
 * as from below. */
static void test_mesh_light_irradiance(void)
{
    check_glossy_light(0.1f, 0.1f, 1);
    check_glossy_light(2.0f, 0.02f, 1);
    for (int two = 0; two < 2; two++) {
        RayesScene *s = rayes_scene_new();
        mesh_light_square(s, v3(0, 0, 1.5f), 1.0f, 5, 2.0f, two);
        Fx f;
        fx_init(&f, s);
        double below = fx_irradiance_mean(&f, v3(0, 0, 0), v3(0, 0, 1), 64, 16);
        double above = fx_irradiance_mean(&f, v3(0, 0, 3), v3(0, 0, -1), 64, 16);
        Vec3 sq[4] = {v3(-1, -1, 1.5f), v3(1, -1, 1.5f), v3(1, 1, 1.5f), v3(-1, 1, 1.5f)};
        double want = 2.0 * polygon_irradiance(v3(0, 0, 0), v3(0, 0, 1), sq, 4);
        CHECK_NEAR(below / want, 1.0, 0.01);
        if (two)
            CHECK_NEAR(above / want, 1.0, 0.01);
        else
            CHECK(above == 0.0);
        fx_fini(&f);
    }
}

/* A closed mesh: a UV sphere of radius 1 (outward faces) at distance 3
 * gives a sphere light's irradiance, L pi (R / D)^2, within its facets'
 * loss of area; a mesh without area is refused. */
static void test_mesh_light_sphere(void)
{
    enum { NU = 64, NV = 32 };
    float *P = malloc(sizeof(float) * 3 * NU * (NV + 1));
    int nv[NU * NV], idx[4 * NU * NV];
    for (int j = 0; j <= NV; j++)
        for (int i = 0; i < NU; i++) {
            double th = PI * j / NV, ph = 2 * PI * i / NU;
            float *p = &P[3 * (j * NU + i)];
            p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)(sin(th) * sin(ph));
            p[2] = (float)(3 + cos(th));
        }
    size_t n_faces = 0, k = 0;
    for (int j = 0; j < NV; j++)
        for (int i = 0; i < NU; i++) {
            int a = j * NU + i, b = j * NU + (i + 1) % NU;
            nv[n_faces++] = 4; /* degenerate at the poles: triangles of no area in the fan */
            idx[k++] = a, idx[k++] = a + NU, idx[k++] = b + NU, idx[k++] = b;
        }
    RayesScene *s = rayes_scene_new();
    const float L[3] = {2, 2, 2};
    CHECK(rayes_scene_area_light_mesh(s, n_faces, nv, idx, NU * (NV + 1), P, L, 0) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    double E = fx_irradiance_mean(&f, v3(0, 0, 0), v3(0, 0, 1), 64, 64);
    CHECK_NEAR(E / (2 * PI / 9), 0.995, 0.01);
    /* inside the sphere: its faces face away, no light */
    CHECK(fx_irradiance(&f, v3(0, 0, 3), v3(0, 0, 1), 16, NULL) == 0.0);
    fx_fini(&f);
    s = rayes_scene_new();
    const float flat[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    const int tri[3] = {0, 1, 2}, three = 3, two = 2;
    CHECK(rayes_scene_area_light_mesh(s, 1, &three, tri, 3, flat, L, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no face has area") != NULL);
    CHECK(rayes_scene_area_light_mesh(s, 1, &two, tri, 3, P, L, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(s->n_lights == 0 && s->n_objects == 0 && s->n_prims == 0);
    rayes_scene_release(s);
    free(P);
}

/* Emitting quadrics (rayes_scene_area_light_quadric, made mesh lights): a
 * disk at z = 1.5 facing up, against the disk's closed form 1.5 above it
 * (its 64-gon has 0.16% less area), dark from its back, lit from both
 * sides when two-sided, only from below when reversed; a two-sided closed sphere lights
 * a point outside as a one-sided one does (its near faces hide its far
 * faces' inner sides: mesh lights shadow). */
static void test_quadric_lights(void)
{
    const float L[3] = {2, 2, 2}, disk[3] = {1.5f, 1.0f, 360.0f};
    double want = 2.0 * PI * 1.0 / (1.5 * 1.5 + 1.0) * 0.9984;
    for (int k = 0; k < 3; k++) { /* plain, two-sided, reversed */
        RayesScene *s = rayes_scene_new();
        CHECK(rayes_scene_area_light_quadric(s, RAYES_QUADRIC_DISK, disk, 3,
                                             k == 2 ? RAYES_QUADRIC_REVERSE : 0, L,
                                             k == 1) == RAYES_OK);
        CHECK(s->n_lights == 1 && s->lights[0].type == LIGHT_MESH);
        Fx f;
        fx_init(&f, s);
        double above = fx_irradiance_mean(&f, v3(0, 0, 3), v3(0, 0, -1), 64, 4);
        double below = fx_irradiance_mean(&f, v3(0, 0, 0), v3(0, 0, 1), 64, 4);
        if (k == 2) { /* facing down */
            CHECK(above == 0.0);
            CHECK_NEAR(below / want, 1.0, 0.01);
        } else { /* facing up (+z), or both */
            CHECK(k == 1 || below == 0.0);
            CHECK_NEAR(above / want, 1.0, 0.01);
            if (k == 1)
                CHECK_NEAR(below / want, 1.0, 0.01);
        }
        fx_fini(&f);
    }
    const float ball[4] = {1, -1, 1, 360};
    double E[2];
    for (int two = 0; two < 2; two++) {
        RayesScene *s = rayes_scene_new();
        const float up[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, up) == RAYES_OK);
        CHECK(rayes_scene_area_light_quadric(s, RAYES_QUADRIC_SPHERE, ball, 4, 0, L, two) ==
              RAYES_OK);
        Fx f;
        fx_init(&f, s);
        E[two] = fx_irradiance_mean(&f, v3(0, 0, 0), v3(0, 0, 1), 64, 16);
        fx_fini(&f);
    }
    CHECK_NEAR(E[0] / (2 * PI / 9), 1.0, 0.015);
    CHECK_NEAR(E[1] / E[0], 1.0, 0.02);
    RayesScene *s = rayes_scene_new();
    const float bad[4] = {-1, 0, 1, 360};
    CHECK(rayes_scene_area_light_quadric(s, RAYES_QUADRIC_CYLINDER, bad, 4, 0, L, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(s->n_lights == 0);
    rayes_scene_release(s);
}

/* ------------------------------------------------------- environments */

/* The preview preset at size x size pixels, spp samples, on threads. */
static RayesRenderOptions preview_options(int size, int spp, int threads)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = size;
    o.spp = spp;
    o.threads = threads;
    return o;
}

static RayesImage *render_scene(RayesScene *s, int threads, int size)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview_options(size, 1, threads);
    o.shadow_rays = o.shadow_rays_deep = 16;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

static void test_constant_environment_white_furnace(void)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -3}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 45.0f) == RAYES_OK);
    RayesParam kd = pf("Kd", 1);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesParam e[1] = {pf("intensity", 0.5f)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 1) == RAYES_OK);
    RayesImage *img = render_scene(s, 2, 32);
    double sum = 0.0;
    int hits = 0, background_ok = 1;
    for (int i = 0; img && i < img->width * img->height; i++) {
        if (img->rgba[4 * i + 3] == 1.0f) {
            sum += img->rgba[4 * i];
            hits++;
        } else if (img->rgba[4 * i] != 0.5f) {
            background_ok = 0; /* the camera sees the environment */
        }
    }
    CHECK(hits > 100);
    CHECK(background_ok);
    /* Every point of a Lambertian of albedo 1 under L reflects L (diffuse
     * rays that escape are black: the light is counted once). */
    CHECK_NEAR(sum / hits / 0.5, 1.0, 0.01);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A chrome ball in a constant environment reflects it everywhere: a
 * grazing reflection that the smooth normal sends out but the coarse
 * micropolygon's plane would turn back into the ball is bent out above that
 * plane (services.c, above_facet), not lost inside the ball (before: 0.47
 * instead of 0.5 on some pixels, 1 sample in 16 black). */
static void chrome_ball_white_furnace(int quadric)
{
    RayesScene *s = rayes_scene_new();
    /* the sphere from its side; RenderMan's and pbrt's along its axis */
    float eye[3] = {quadric == 1 ? 0.0f : -6.0f, 0, quadric == 1 ? -6.0f : 0.0f},
          target[3] = {0, 0, 0}, up[3] = {0, quadric == 1 ? 1.0f : 0.0f, quadric == 1 ? 0.0f : 1.0f};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 30.0f) == RAYES_OK);
    RayesParam chrome[2] = {pf("Kr", 1), {"specularcolor", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}};
    /* mode 2: a white conductor under a clear coat (pbrt's coatedconductor):
     * the coat's Fresnel and what crosses it add up to all the light */
    RayesParam coated[3] = {{"reflectance", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}, pf("coat", 1),
                            pf("coat_eta", 1.5f)};
    CHECK((quadric == 2 ? rayes_scene_set_shader(s, "conductor", coated, 3)
                        : rayes_scene_set_shader(s, "mirror", chrome, 2)) == RAYES_OK);
    const float q[4] = {1, -1, 1, 360};
    CHECK((quadric == 1 ? rayes_scene_quadric(s, RAYES_QUADRIC_SPHERE, q, 4, 0)
                        : rayes_scene_sphere(s, 1.0f)) == RAYES_OK);
    RayesParam e[1] = {pf("intensity", 0.5f)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview_options(32, 16, 2);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    int hits = 0, dark = 0;
    for (int i = 0; img && i < img->width * img->height; i++)
        if (img->rgba[4 * i + 3] == 1.0f) {
            hits++;
            dark += img->rgba[4 * i] < 0.4995f || img->rgba[4 * i] > 0.5005f;
        }
    CHECK(hits > 100);
    CHECK(dark == 0);
    if (dark)
        fprintf(stderr, "  %d of %d pixels of the ball lost or made light (mode %d)\n", dark, hits,
                quadric);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* ... and a quadric sphere seen along its axis: its pole faces the camera,
 * where a latitude of -pi/2 rounded to a float once turned the normal
 * inward and its neighbours' sideways (geom/prim.c): the middle of the
 * ball reflected the wrong way (and a small light behind the camera was
 * never seen in it). */
static void test_chrome_ball_white_furnace(void)
{
    chrome_ball_white_furnace(0);
    chrome_ball_white_furnace(1);
    chrome_ball_white_furnace(2);
}

/* Glass balls in a constant environment, smooth and rough (pbrt's
 * dielectric, roughness 0.02 and 0.1: GGX of alpha 0.14 and 0.32, rough
 * refraction as well as reflection; builtin_bsdf.c rough_refraction). A
 * smooth ball keeps the environment's radiance; a rough one loses what a
 * single-scattering microfacet model loses (Smith's G; refractions
 * through steep microfacets that point back inside), most where light
 * leaves the glass, but never makes light. Index-matched (eta 1.0001),
 * where nothing reflects or bends, a rough ball all but vanishes: its
 * refraction's weights are right. */
static double glass_ball_mean(float eta, float roughness)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -6}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 30.0f) == RAYES_OK);
    RayesParam g[2] = {pf("eta", eta), pf("roughness", roughness)};
    CHECK(rayes_scene_set_shader(s, "dielectric", g, 2) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesParam e[1] = {pf("intensity", 0.5f)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview_options(32, 16, 2);
    o.specular_depth = 16;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double sum = 0.0;
    int hits = 0;
    for (int i = 0; img && i < img->width * img->height; i++)
        if (img->rgba[4 * i + 3] == 1.0f)
            hits++, sum += img->rgba[4 * i];
    CHECK(hits > 100);
    rayes_image_free(img);
    rayes_scene_release(s);
    return hits ? sum / hits : 0.0;
}

static void test_glass_ball_white_furnace(void)
{
    double smooth = glass_ball_mean(1.5f, 0.0f);
    CHECK(smooth > 0.49 && smooth <= 0.5);
    CHECK_NEAR(glass_ball_mean(1.0001f, 0.02f), 0.5, 0.02);
    CHECK_NEAR(glass_ball_mean(1.0001f, 0.1f), 0.5, 0.05);
    for (int k = 0; k < 2; k++) {
        double rough = glass_ball_mean(1.5f, k ? 0.1f : 0.02f);
        CHECK(rough > 0.3 && rough < 0.5);
    }
}

/* A floor's light in and out of the shadow of a sphere of the given
 * shader (eta 1.5, transmitcolor tint) lit by a distant light at 45
 * degrees, seen orthographically: the shadow's mean over the lit floor's,
 * per channel (direct light only). */
static Vec3 shadow_ratio(const char *shader, const float tint[3], int cache)
{
    RayesScene *s = rayes_scene_new();
    const float cam[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const float screen[4] = {-4, 4, -4, 4};
    CHECK(rayes_scene_set_camera_matrix(s, cam, RAYES_PROJECTION_ORTHOGRAPHIC, 40, screen) ==
          RAYES_OK);
    RayesParam l[3] = {pv("from", 1, 0, -1), pv("to", 0, 0, 0), pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "distantlight", l, 3) == RAYES_OK);
    RayesParam kd[1] = {pf("Kd", 1)};
    CHECK(rayes_scene_set_shader(s, "matte", kd, 1) == RAYES_OK);
    const float P[12] = {-5, -5, 10, 5, -5, 10, 5, 5, 10, -5, 5, 10};
    const int nv[1] = {4}, idx[4] = {0, 1, 2, 3};
    CHECK(rayes_scene_polygon_mesh(s, 1, nv, idx, 4, P) == RAYES_OK);
    RayesParam g[2] = {pf("eta", 1.5f), pv("transmitcolor", tint[0], tint[1], tint[2])};
    CHECK(rayes_scene_set_shader(s, shader, g, strcmp(shader, "matte") ? 2 : 0) == RAYES_OK);
    const float at[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 8, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, at) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview_options(64, 4, 2);
    o.bounces = 0;
    o.cache = cache;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    /* x = -2 and +2 on the floor (the shadow falls 2 to one side of the
     * sphere's middle, whichever way the image runs), y near 0 */
    Vec3 side[2] = {v3(0, 0, 0), v3(0, 0, 0)};
    for (int y = 29; img && y < 35; y++)
        for (int k = 0; k < 2; k++)
            for (int x = (k ? 45 : 13); x < (k ? 51 : 19); x++) {
                const float *px = &img->rgba[4 * (y * 64 + x)];
                side[k] = v3_add(side[k], v3(px[0], px[1], px[2]));
            }
    rayes_image_free(img);
    rayes_scene_release(s);
    Vec3 lo = side[0].x < side[1].x ? side[0] : side[1],
         hi = side[0].x < side[1].x ? side[1] : side[0];
    CHECK(hi.x > 0.0f && hi.y > 0.0f && hi.z > 0.0f);
    return v3(lo.x / hi.x, lo.y / hi.y, lo.z / hi.z);
}

/* Thin shadows of glass (builtin_bsdf.c thin_shadow): a dielectric sphere
 * passes (1 - R0)^2 of the light to the floor behind it, tinted by its
 * transmitcolor twice (once a crossing), where an opaque one passes none;
 * cached and uncached alike. (That its own rough lobes do not see the
 * light through its body is the glass furnace's test above: they came
 * out at 0.77 and 0.64, making light.) */
static void test_glass_thin_shadow(void)
{
    const float white[3] = {1, 1, 1}, red[3] = {1, 0.5f, 0.5f};
    double T = pow(1.0 - 0.04, 2.0); /* R0 at eta 1.5 */
    Vec3 opaque = shadow_ratio("matte", white, 1);
    CHECK(opaque.x < 0.01);
    for (int cache = 0; cache < 2; cache++) {
        Vec3 glass = shadow_ratio("dielectric", white, cache);
        CHECK_NEAR(glass.x, T, 0.02);
        CHECK_NEAR(glass.z, T, 0.02);
        Vec3 tinted = shadow_ratio("dielectric", red, cache);
        CHECK_NEAR(tinted.x, T, 0.02);
        CHECK_NEAR(tinted.y, T * 0.25, 0.02);
    }
    Vec3 classic = shadow_ratio("glass", white, 1);
    CHECK_NEAR(classic.x, T, 0.02);
}

/* The sample clamp (pbrt's Film "maxcomponentvalue"): each camera
 * sample's largest component is at most the clamp, its colour's ratios
 * kept; 0 is off; a negative clamp is refused. */
static void test_sample_clamp(void)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -3}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 45.0f) == RAYES_OK);
    RayesParam e[2] = {pf("intensity", 4.0f), {"lightcolor", RAYES_PARAM_COLOR, {1, 0.5f, 0.25f}, NULL}};
    CHECK(rayes_scene_light(s, "environmentlight", e, 2) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview_options(8, 4, 1);
    for (int k = 0; k < 3; k++) {
        o.sample_clamp = k == 0 ? 0.0f : k == 1 ? 2.0f : -1.0f;
        RayesImage *img = NULL;
        RayesError err = rayes_render(s, &o, &img, NULL);
        CHECK((err == RAYES_OK) == (k < 2));
        if (img) { /* the environment everywhere: (4, 2, 1), or (2, 1, 0.5) clamped */
            CHECK_NEAR(img->rgba[0], k ? 2.0 : 4.0, 1e-5);
            CHECK_NEAR(img->rgba[1], k ? 1.0 : 2.0, 1e-5);
            CHECK_NEAR(img->rgba[2], k ? 0.5 : 1.0, 1e-5);
        }
        rayes_image_free(img);
    }
    rayes_scene_release(s);
}

/* A scene of one environment light of the map at path, intensity 1, set
 * up in f. */
static RayesScene *env_fixture(Fx *f, const char *path)
{
    RayesScene *s = rayes_scene_new();
    RayesParam e[2] = {ps("mapname", path), pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 2) == RAYES_OK);
    fx_init(f, s);
    return s;
}

/* A 64 x 32 map, dim everywhere but a small bright patch. */
static void write_test_map(const char *path)
{
    int w = 64, h = 32;
    float *p = malloc(sizeof(float) * 4 * w * h);
    for (int i = 0; i < w * h; i++) {
        int x = i % w, y = i / w;
        int bright = x >= 40 && x < 43 && y >= 9 && y < 12;
        p[4 * i + 0] = bright ? 200.0f : 0.02f;
        p[4 * i + 1] = bright ? 150.0f : 0.03f;
        p[4 * i + 2] = bright ? 100.0f : 0.05f;
        p[4 * i + 3] = 1.0f;
        if (x == 32 && y == 16) /* the map's centre: +z */
            p[4 * i + 0] = 7.0f;
        if (y == 0)
            p[4 * i + 1] = 5.0f; /* the top row: +y */
    }
    CHECK(image_write_exr(path, w, h, p, NULL, 0) == RAYES_OK);
    free(p);
}

/* Point lights with maps: an image projected along +z (fov 90, its first
 * row at +y, black outside and behind), and a latitude-longitude map of
 * intensity by direction (the test map: 7 red at +z, its top row green). */
static void test_point_light_maps(void)
{
    const char *path = RAYES_TEST_TMP "/test_lights_slide.exr";
    float px[2 * 2 * 4] = {1, 0, 0, 1, 0, 1, 0, 1,  /* top: red, green */
                           0, 0, 1, 1, 1, 1, 1, 1}; /* bottom: blue, white */
    CHECK(image_write_exr(path, 2, 2, px, NULL, 0) == RAYES_OK);
    RayesScene *s = rayes_scene_new();
    RayesParam p[4] = {ps("mapname", path), ps("mapping", "projection"), pf("fov", 90),
                       pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "pointlight", p, 4) == RAYES_OK);
    const float at[4][3] = {{-0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}, {-0.5f, -0.5f, 1}, {0.5f, -0.5f, 1}};
    for (int k = 0; k < 4 && s->n_lights == 1; k++) {
        LightSample ls;
        Vec3 o = v3_load(at[k]);
        CHECK(light_sample(&s->lights[0], o, 0.5f, 0.5f, &ls));
        float d2 = v3_dot(o, o);
        CHECK_NEAR(ls.Li.x * d2, 2 * px[4 * k], 1e-5);
        CHECK_NEAR(ls.Li.y * d2, 2 * px[4 * k + 1], 1e-5);
        CHECK_NEAR(ls.Li.z * d2, 2 * px[4 * k + 2], 1e-5);
    }
    LightSample ls;
    CHECK(s->n_lights == 1 && !light_sample(&s->lights[0], v3(2, 0, 1), 0.5f, 0.5f, &ls));
    CHECK(s->n_lights == 1 && !light_sample(&s->lights[0], v3(0, 0, -1), 0.5f, 0.5f, &ls));
    RayesParam bad[3] = {ps("mapname", path), ps("mapping", "projection"), pf("fov", 180)};
    CHECK(rayes_scene_light(s, "spotlight", bad, 3) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
    write_test_map(RAYES_TEST_TMP "/test_lights_map.exr");
    s = rayes_scene_new();
    RayesParam g[1] = {ps("mapname", RAYES_TEST_TMP "/test_lights_map.exr")};
    CHECK(rayes_scene_light(s, "pointlight", g, 1) == RAYES_OK);
    if (s->n_lights == 1) {
        CHECK(light_sample(&s->lights[0], v3(0, 0, 3), 0.5f, 0.5f, &ls));
        CHECK_NEAR(ls.Li.x * 9, 7, 1e-4); /* toward +z */
        CHECK(light_sample(&s->lights[0], v3(0, 3, 0), 0.5f, 0.5f, &ls));
        CHECK_NEAR(ls.Li.y * 9, 5, 1e-4); /* straight up: the top row */
    }
    rayes_scene_release(s);
}

static void test_environment_map_importance_sampling(void)
{
    const char *path = RAYES_TEST_TMP "/test_lights_map.exr";
    write_test_map(path);
    Fx f;
    RayesScene *s = env_fixture(&f, path);
    const Light *l = &s->lights[0];
    /* Orientation: the centre pixel is +z, the top row +y. */
    CHECK(light_env_radiance(l, v3_normalize(v3(-0.03f, -0.05f, 1.0f))).x == 7.0f);
    CHECK(light_env_radiance(l, v3(0.0f, 1.0f, 0.0f)).y == 5.0f);
    /* The bright patch is around u = 0.66 (toward -x), v = 0.33 (above the
     * horizon); aim a normal near it and one away from it. */
    Vec3 normals[2] = {v3_normalize(v3(-1.0f, 0.6f, -0.4f)), v3_normalize(v3(0.3f, -0.2f, 1.0f))};
    for (int k = 0; k < 2; k++) {
        Vec3 N = normals[k];
        double d[3], sp[3];
        fx_direct(&f, v3(0, 0, 0), N, NULL, 64, NULL, 0.1f, 4, d, sp);
        /* Brute force: stratified uniform directions over the sphere. */
        const int m = 1500;
        double ref = 0.0;
        for (int i = 0; i < m; i++)
            for (int j = 0; j < m; j++) {
                uint64_t key = hash_combine((uint64_t)i, (uint64_t)j);
                float z = 1.0f - 2.0f * ((float)i + rng_float(key)) / m;
                float phi = 2.0f * (float)PI * ((float)j + rng_float(key + 1)) / m;
                float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
                Vec3 wi = v3(r * cosf(phi), r * sinf(phi), z);
                float c = v3_dot(N, wi);
                if (c > 0.0f)
                    ref += light_env_radiance(l, wi).x * c;
            }
        ref *= 4.0 * PI / ((double)m * m);
        CHECK_NEAR(PI * d[0] / ref, 1.0, 0.02);
    }
    fx_fini(&f);
}

/* The binary search the guide tables replaced: the largest i < n with
 * cdf[i] <= x, then past empty intervals. */
static int reference_find(const float *cdf, int n, float x)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (cdf[mid] <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    while (lo < n - 1 && cdf[lo + 1] <= cdf[lo])
        lo++;
    return lo;
}

/* A 64 x 32 map with empty intervals in both cdfs: the bottom rows and a
 * band of columns black, a bright patch, a gradient elsewhere. */
static void write_holed_map(const char *path)
{
    int w = 64, h = 32;
    float *p = malloc(sizeof(float) * 4 * w * h);
    for (int i = 0; i < w * h; i++) {
        int x = i % w, y = i / w;
        float v = y >= 24 || (x >= 10 && x < 20) ? 0.0f
                  : x >= 40 && x < 43 && y >= 9 && y < 12 ? 300.0f
                                                           : 0.05f + 0.01f * (float)(x + y);
        p[4 * i + 0] = p[4 * i + 1] = p[4 * i + 2] = v;
        p[4 * i + 3] = 1.0f;
    }
    CHECK(image_write_exr(path, w, h, p, NULL, 0) == RAYES_OK);
    free(p);
}

/* The map's sampling (shade/light.c's guide tables): each (a, b) draws the
 * pixel the binary search draws, with the same pdf bit for bit, at random
 * numbers and at every bucket's edge and its neighbours; black pixels are
 * never drawn; the drawn pixels follow pixel_pdf (chi-square); and the pdf
 * of a drawn direction, looked up again (light_intersect, what multiple
 * importance sampling uses), is the sample's. */
static void test_environment_map_sampling_consistency(void)
{
    const char *path = RAYES_TEST_TMP "/test_lights_holed.exr";
    write_holed_map(path);
    Fx f;
    RayesScene *s = env_fixture(&f, path);
    const Light *l = &s->lights[0];
    const LightEnvMap *m = l->env;
    CHECK(m != NULL);
    int w = m->width, h = m->height, n = 400000, edges = 0;
    int *count = calloc((size_t)w * h, sizeof *count);
    int wrong = 0, black = 0, pdf_far = 0, failed = 0;
    for (int i = 0; i < n + 4 * (w + h); i++) {
        float a = rng_float(hash_combine(11, (uint64_t)i));
        float b = rng_float(hash_combine(12, (uint64_t)i));
        if (i >= n) { /* bucket edges k / n and the floats beside them */
            int j = (i - n) / 4, side = (i - n) % 4;
            float ea = (float)(j % h) / (float)h, eb = (float)(j % w) / (float)w;
            a = side == 1 ? nextafterf(ea, 0.0f) : side == 2 ? nextafterf(ea, 1.0f) : ea;
            b = side == 3 ? nextafterf(eb, 0.0f) : side == 2 ? nextafterf(eb, 1.0f) : eb;
            a = fminf(fmaxf(a, 0.0f), nextafterf(1.0f, 0.0f));
            b = fminf(fmaxf(b, 0.0f), nextafterf(1.0f, 0.0f));
            edges++;
        }
        int y = reference_find(m->row_cdf, h, a);
        const float *cc = &m->col_cdf[(size_t)y * (w + 1)];
        int x = reference_find(cc, w, b);
        float dr = m->row_cdf[y + 1] - m->row_cdf[y];
        float fy = dr > 0.0f ? (a - m->row_cdf[y]) / dr : 0.5f;
        float v = ((float)y + fminf(fmaxf(fy, 0.0f), 0.9999f)) / (float)h;
        float pdf = m->pixel_pdf[(size_t)y * w + x] * (float)w * (float)h /
                    (2.0f * (float)PI * (float)PI * sinf(v * (float)PI));
        LightSample ls;
        if (!light_sample(l, v3(0, 0, 0), a, b, &ls)) {
            failed += sinf(v * (float)PI) > 0.0f; /* only at the pole, a = 0 */
            continue;
        }
        wrong += ls.pdf != pdf;
        black += !(m->pixel_pdf[(size_t)y * w + x] > 0.0f);
        if (i < n)
            count[y * w + x]++;
        LightSample back;
        CHECK(light_intersect(l, v3(0, 0, 0), ls.wi, &back));
        pdf_far += fabsf(back.pdf - ls.pdf) > 1e-3f * ls.pdf;
    }
    CHECK(edges == 4 * (w + h));
    CHECK(failed == 0);
    CHECK(wrong == 0);
    CHECK(black == 0);
    /* a direction on a pixel's edge may look up its neighbour */
    CHECK(pdf_far < n / 100);
    double chi2 = 0.0;
    int dof = -1;
    for (int i = 0; i < w * h; i++) {
        double expect = (double)m->pixel_pdf[i] * n;
        if (expect >= 5.0) {
            chi2 += (count[i] - expect) * (count[i] - expect) / expect;
            dof++;
        } else
            CHECK(m->pixel_pdf[i] > 0.0f || count[i] == 0);
    }
    /* chi-square of dof degrees: mean dof, deviation sqrt(2 dof); 5 of them */
    CHECK(dof > 500);
    CHECK(chi2 < dof + 5.0 * sqrt(2.0 * dof));
    free(count);
    fx_fini(&f);
}

/* pbrt-v4's equal-area octahedral maps: the square's centre is light-space
 * +z, its corners -z, the middle of its right edge +x and of its top row
 * -y (pbrt's EqualAreaSphereToSquare, (0, 0) the top left). Red marks the
 * centre, green the top rows; a map that is not square is an error. */
static void test_octahedral_environment_map(void)
{
    enum { N = 32 };
    const char *path = RAYES_TEST_TMP "/test_lights_octahedral.exr";
    float *p = calloc((size_t)N * N * 4, sizeof *p);
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            float *q = &p[4 * (y * N + x)];
            q[0] = abs(2 * x + 1 - N) < 8 && abs(2 * y + 1 - N) < 8 ? 1.0f : 0.0f;
            q[1] = y < N / 8 && abs(2 * x + 1 - N) < 8 ? 1.0f : 0.0f;
            q[2] = 0.25f;
            q[3] = 1.0f;
        }
    CHECK(image_write_exr(path, N, N, p, NULL, 0) == RAYES_OK);
    free(p);
    RayesScene *s = rayes_scene_new();
    RayesParam e[2] = {ps("mapname", path), ps("mapping", "octahedral")};
    CHECK(rayes_scene_light(s, "environmentlight", e, 2) == RAYES_OK);
    const Light *l = &s->lights[0];
    CHECK(light_env_radiance(l, v3(0, 0, 1)).x == 1.0f);
    CHECK(light_env_radiance(l, v3(0, 0, -1)).x == 0.0f);
    CHECK(light_env_radiance(l, v3(1, 0, 0)).x == 0.0f);
    CHECK(light_env_radiance(l, v3(0, -1, 0)).y > 0.9f);
    CHECK(light_env_radiance(l, v3(0, 1, 0)).y == 0.0f);
    CHECK_NEAR(light_env_radiance(l, v3_normalize(v3(1, 1, 1))).z, 0.25, 1e-6);
    RayesParam bad[2] = {ps("mapname", RAYES_TEST_TMP "/test_lights_map.exr"),
                         ps("mapping", "octahedral")};
    CHECK(rayes_scene_light(s, "environmentlight", bad, 2) == RAYES_ERROR_IO);
    CHECK(strstr(rayes_scene_get_error(s), "must be square") != NULL);
    RayesParam odd[1] = {ps("mapping", "cube")};
    CHECK(rayes_scene_light(s, "environmentlight", odd, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
}

/* ----------------------------------------------------------- categories */

static void test_categories(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam a[3] = {pv("from", 0, 0, 1), pf("intensity", 1), ps("__category", "key, fill")};
    RayesParam b[3] = {pv("from", 0, 0, 1), pf("intensity", 10), ps("__category", "rim")};
    RayesParam c[2] = {pv("from", 0, 0, 1), pf("intensity", 100)};
    CHECK(rayes_scene_light(s, "pointlight", a, 3) == RAYES_OK);
    CHECK(rayes_scene_light(s, "pointlight", b, 3) == RAYES_OK);
    CHECK(rayes_scene_light(s, "pointlight", c, 2) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    Vec3 o = v3(0, 0, 0), N = v3(0, 0, 1);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, NULL), 111.0, 1e-3);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, ""), 111.0, 1e-3);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "key"), 1.0, 1e-5);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "fill"), 1.0, 1e-5);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "rim"), 10.0, 1e-4);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "-key"), 110.0, 1e-3);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "ke"), 0.0, 0.0);
    CHECK_NEAR(fx_irradiance(&f, o, N, 1, "none"), 0.0, 0.0);
    fx_fini(&f);
}

/* ------------------------------------------------------ glossy service */

/* The glossy service (microfacet: the microfacet service, width the GGX
 * alpha; else width the roughness) at P (normal N, viewed along I)
 * averaged over keys. */
static void fx_lobe(Fx *f, int microfacet, Vec3 P, Vec3 N, Vec3 I, float width, int keys,
                    double out[3])
{
    float Pa[1][3] = {{P.x, P.y, P.z}}, Na[1][3] = {{N.x, N.y, N.z}}, Ia[1][3] = {{I.x, I.y, I.z}};
    RayDiff diff[1] = {{0.0f, 0.0f}};
    float curv[1] = {0.0f}, off[1] = {0.0f};
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 0; k < keys; k++) {
        uint64_t key[1] = {hash_combine(4321, (uint64_t)k)};
        PathState ps = {&f->w, key, diff, curv, off};
        RayesShadeCtx ctx = {.n_points = 1, .ray_type = RAYES_RAY_CAMERA,
                             .P = (const float(*)[3])Pa, .N = (const float(*)[3])Na,
                             .Ng = (const float(*)[3])Na, .I = (const float(*)[3])Ia,
                             .renderer = &ps};
        float o[1][3];
        (microfacet ? render_services.microfacet : render_services.glossy)(&render_services, &ctx,
                                                                           &width, 0, o);
        for (int c = 0; c < 3; c++)
            out[c] += o[0][c] / keys;
    }
}

/* The normalised Blinn-Phong lobe times the cosine, as shader.h defines it. */
static double lobe_cos(Vec3 N, Vec3 V, Vec3 wi, double e)
{
    Vec3 H = v3_normalize(v3_add(wi, V));
    double nh = fmax(v3_dot(N, H), 0.0), cos_x = v3_dot(N, wi);
    return cos_x > 0.0 ? (e + 8) / (8 * PI) * pow(nh, e) * cos_x : 0.0;
}

/* GGX times the cosine, as shader.h's microfacet service defines it:
 * D / (1 + Lambda(V) + Lambda(L)) / (4 N.V N.L) N.L, in double. */
static double ggx_cos(Vec3 N, Vec3 V, Vec3 wi, double alpha)
{
    double no = v3_dot(N, V), ni = v3_dot(N, wi), a2 = alpha * alpha;
    if (no <= 0.0 || ni <= 0.0)
        return 0.0;
    Vec3 H = v3_normalize(v3_add(wi, V));
    double nh = v3_dot(N, H), d = nh * nh * (a2 - 1) + 1;
    double D = a2 / (PI * d * d);
    double Lo = (sqrt(1 + a2 * (1 - no * no) / (no * no)) - 1) / 2;
    double Li = (sqrt(1 + a2 * (1 - ni * ni) / (ni * ni)) - 1) / 2;
    return D / (1 + Lo + Li) / (4 * no);
}

typedef double (*LobeCos)(Vec3 N, Vec3 V, Vec3 wi, double width);

/* A brute-force estimate with no light sampling: directions uniform in the
 * cone a sphere of radius R at C subtends from the origin, L inside, of
 * lobe (width w). */
static double brute_sphere(Vec3 C, double R, double L, Vec3 N, Vec3 V, double w, LobeCos lobe)
{
    double D = v3_length(C), cos_max = sqrt(1 - R * R / (D * D)), sum = 0.0;
    Vec3 z = v3_scale(C, (float)(1 / D)), t, b;
    v3_basis(z, &t, &b);
    const int n = 1 << 20;
    for (int k = 0; k < n; k++) {
        double u1 = rng_float(hash_combine(77, 2 * (uint64_t)k));
        double u2 = rng_float(hash_combine(77, 2 * (uint64_t)k + 1));
        double ct = 1 - u1 * (1 - cos_max), st = sqrt(fmax(0, 1 - ct * ct)), ph = 2 * PI * u2;
        Vec3 wi = v3_add(v3_add(v3_scale(t, (float)(st * cos(ph))), v3_scale(b, (float)(st * sin(ph)))),
                         v3_scale(z, (float)ct));
        sum += L * lobe(N, V, wi, w);
    }
    return sum / n * 2 * PI * (1 - cos_max);
}

/* One light through a lobe (microfacet: GGX of width w, else the glossy
 * service's roughness 1 / w) against lobe's brute-force integral over the
 * light's cone: a sphere of the radius at (x, 0, 3), viewed so that the
 * mirror direction points at x = 1. */
static void check_sphere_light(int microfacet, float radius, float x, float w, LobeCos lobe)
{
    RayesScene *s = rayes_scene_new();
    Vec3 C = v3(x, 0, 3);
    const float move[16] = {1, 0, 0, C.x, 0, 1, 0, C.y, 0, 0, 1, C.z, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, move) == RAYES_OK);
    RayesParam p[3] = {ps("shape", "sphere"), pf("radius", radius),
                       pf("intensity", 1.0f / (radius * radius))};
    CHECK(rayes_scene_light(s, "arealight", p, 3) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    f.set.specular_depth = 4;
    f.set.branch_depth = 1;
    f.set.diffuse_rays = 4;
    Vec3 N = v3(0, 0, 1), R = v3_normalize(v3(1, 0, 3)), I = v3(R.x, 0, -R.z);
    double got[3];
    fx_lobe(&f, microfacet, v3(0, 0, 0), N, I, microfacet ? w : 1.0f / w, 256, got);
    double want = brute_sphere(C, radius, 1.0 / (radius * radius), N, v3_neg(I), w, lobe);
    CHECK(want > 0.0);
    CHECK_NEAR(got[0] / want, 1.0, 0.03);
    fx_fini(&f);
}

/* Inside an incandescent sphere (matte, Kd 0, Ke 1: radiance 1, not a
 * light) a lobe (as check_sphere_light's) viewed at theta degrees off
 * the normal gives its directional albedo, estimated here by brute force
 * with uniform directions over the hemisphere; returns it. */
static double check_surroundings(int microfacet, float theta, float w, LobeCos lobe)
{
    RayesScene *s = rayes_scene_new();
    RayesParam m[2] = {pf("Kd", 0.0f), pv("Ke", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 2) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 5.0f) == RAYES_OK);
    Fx f;
    fx_init(&f, s);
    f.set.specular_depth = 4;
    f.set.branch_depth = 1;
    f.set.diffuse_rays = 16;
    float th = theta * (float)PI / 180.0f;
    Vec3 N = v3(0, 0, 1), I = v3(sinf(th), 0, -cosf(th));
    double got[3], sum = 0.0;
    fx_lobe(&f, microfacet, v3(0, 0, 0), N, I, microfacet ? w : 1.0f / w, 256, got);
    const int n = 1 << 21;
    for (int j = 0; j < n; j++) {
        double u1 = rng_float(hash_combine(99, 2 * (uint64_t)j));
        double u2 = rng_float(hash_combine(99, 2 * (uint64_t)j + 1));
        double ct = u1, st = sqrt(fmax(0, 1 - ct * ct)), ph = 2 * PI * u2;
        Vec3 wi = v3((float)(st * cos(ph)), (float)(st * sin(ph)), (float)ct);
        sum += lobe(N, v3_neg(I), wi, w);
    }
    double want = sum / n * 2 * PI;
    CHECK_NEAR(got[0] / want, 1.0, 0.02);
    fx_fini(&f);
    return want;
}

/* Lights through a glossy lobe (multiple importance sampling) against the
 * brute-force integral over the light's cone: small and large spheres,
 * sharp and broad lobes, the light at and off the mirror direction. The
 * defect this guards: a glossy surface that saw lights only through its
 * lobe's rays speckled all over under a small bright light. */
static void test_glossy_lights_against_brute_force(void)
{
    static const struct {
        float radius, x, e;
    } cases[] = {{0.05f, 1.0f, 200}, {0.05f, 1.0f, 20}, {1.0f, 1.0f, 200},
                 {1.0f, 1.0f, 20},   {0.3f, 2.5f, 50},  {0.05f, 1.0f, 2000}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        check_sphere_light(0, cases[k].radius, cases[k].x, cases[k].e, lobe_cos);
}

/* What is not a light comes through the lobe's rays: the glossy service's
 * directional albedo, 37 degrees off the normal. */
static void test_glossy_surroundings_against_brute_force(void)
{
    static const float es[] = {20, 100};
    for (int k = 0; k < 2; k++) {
        double want = check_surroundings(0, 36.87f, es[k], lobe_cos);
        CHECK(want > 0.5 && want < 1.1);
    }
}

/* The microfacet service (GGX) against brute force, as the glossy
 * service's tests: lights, and the lobe's directional albedo at the
 * normal, 60 and 80 degrees off it. Unlike Blinn-Phong's, the albedo
 * changes little off the normal (the reason the physically based shaders
 * use it: pbrt's rough metals were dark toward their rims). */
static void test_microfacet_against_brute_force(void)
{
    static const struct {
        float radius, x, alpha;
    } cases[] = {{0.05f, 1.0f, 0.05f}, {0.05f, 1.0f, 0.3f}, {1.0f, 1.0f, 0.05f},
                 {1.0f, 1.0f, 0.3f},   {0.3f, 2.5f, 0.15f}, {0.3f, 1.0f, 0.6f}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        check_sphere_light(1, cases[k].radius, cases[k].x, cases[k].alpha, ggx_cos);
    static const float alphas[] = {0.2f, 0.5f}, views[] = {0.0f, 60.0f, 80.0f};
    for (int k = 0; k < 2; k++) {
        double w0 = 1.0; /* along the normal */
        for (int v = 0; v < 3; v++) {
            double want = check_surroundings(1, views[v], alphas[k], ggx_cos);
            if (v == 0)
                w0 = want;
            CHECK(want > 0.6 && want < 1.0);
            CHECK(want > 0.85 * w0); /* Blinn-Phong's: (N.V)^2, 0.25 and 0.03 */
        }
    }
}

/* ------------------------------------------- emitters seen by the camera */

static void test_emitters_seen_by_camera(void)
{
    for (int shape = 0; shape < 2; shape++) {
        RayesScene *s = rayes_scene_new();
        float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
        CHECK(rayes_scene_set_camera(s, eye, target, up, 30.0f) == RAYES_OK);
        /* The disk faces the camera (-z) */
        const float flip[16] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
        if (shape == 0)
            CHECK(rayes_scene_set_transform(s, flip) == RAYES_OK);
        RayesParam p[3] = {ps("shape", shape ? "sphere" : "disk"), pf("radius", 0.5f),
                           pv("lightcolor", 3, 2, 1)};
        CHECK(rayes_scene_light(s, "arealight", p, 3) == RAYES_OK);
        RayesImage *img = render_scene(s, 1, 16);
        const float *c = img ? &img->rgba[4 * (8 * 16 + 8)] : NULL;
        CHECK(c && c[0] == 3.0f && c[1] == 2.0f && c[2] == 1.0f && c[3] == 1.0f);
        CHECK(img && img->rgba[3] == 0.0f); /* the corner misses */
        rayes_image_free(img);
        rayes_scene_release(s);
    }
    /* A mesh light facing the camera, and one facing away: black unless
     * two-sided. */
    for (int k = 0; k < 3; k++) {
        RayesScene *m = rayes_scene_new();
        float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
        CHECK(rayes_scene_set_camera(m, eye, target, up, 30.0f) == RAYES_OK);
        const float P[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
        const int toward[6] = {0, 2, 1, 0, 3, 2}, away[6] = {0, 1, 2, 0, 2, 3}, nv[2] = {3, 3};
        const float L[3] = {3, 2, 1};
        CHECK(rayes_scene_area_light_mesh(m, 2, nv, k == 0 ? toward : away, 4, P, L, k == 2) ==
              RAYES_OK);
        RayesImage *img = render_scene(m, 1, 16);
        const float *c = img ? &img->rgba[4 * (8 * 16 + 8)] : NULL;
        CHECK(c && c[0] == (k == 1 ? 0.0f : 3.0f) && c[2] == (k == 1 ? 0.0f : 1.0f));
        rayes_image_free(img);
        rayes_scene_release(m);
    }
    /* A quad with an emission cone of 25 degrees, seen head-on: its
     * radiance; turned 60 degrees away: dark, as it lights nothing there */
    for (int turned = 0; turned < 2; turned++) {
        RayesScene *q = rayes_scene_new();
        float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
        CHECK(rayes_scene_set_camera(q, eye, target, up, 30.0f) == RAYES_OK);
        float c = cosf(turned ? 60.0f * (float)M_PI / 180.0f : 0.0f);
        float sn = sqrtf(1.0f - c * c);
        /* y flipped and z turned toward the camera (-z), then about y */
        const float m[16] = {c, 0, -sn, 0, 0, -1, 0, 0, -sn, 0, -c, 0, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(q, m) == RAYES_OK);
        RayesParam p[4] = {ps("shape", "quad"), pf("width", 1.5f), pf("cone", 25.0f),
                           pv("lightcolor", 3, 2, 1)};
        CHECK(rayes_scene_light(q, "arealight", p, 4) == RAYES_OK);
        RayesImage *img = render_scene(q, 1, 16);
        const float *px = img ? &img->rgba[4 * (8 * 16 + 8)] : NULL;
        CHECK(px && px[3] == 1.0f && px[0] == (turned ? 0.0f : 3.0f));
        rayes_image_free(img);
        rayes_scene_release(q);
    }
    /* A disk seen from behind is black. */
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 30.0f) == RAYES_OK);
    RayesParam p[2] = {ps("shape", "disk"), pf("radius", 0.5f)};
    CHECK(rayes_scene_light(s, "arealight", p, 2) == RAYES_OK);
    RayesImage *img = render_scene(s, 1, 16);
    const float *c = img ? &img->rgba[4 * (8 * 16 + 8)] : NULL;
    CHECK(c && c[0] == 0.0f && c[3] == 1.0f);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A textured mesh light (rayes_scene_area_light_mesh_textured): the
 * camera sees L times the image at the hit's (s, t); a uniform image of
 * 0.5 lights the floor as a light of L 0.5 does; an image red on one side
 * and green on the other lights the floor under each side in its colour;
 * a texture that cannot be read is left out, no st refused. */
static void test_textured_mesh_light(void)
{
    const char *two = RAYES_TEST_TMP "/test_lights_emit_two.exr";
    const char *grey = RAYES_TEST_TMP "/test_lights_emit_grey.exr";
    float px[4 * 4] = {1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1}; /* red red green green */
    CHECK(image_write_exr(two, 4, 1, px, NULL, 0) == RAYES_OK);
    for (int i = 0; i < 4; i++)
        px[4 * i] = px[4 * i + 1] = px[4 * i + 2] = 0.5f;
    CHECK(image_write_exr(grey, 4, 1, px, NULL, 0) == RAYES_OK);
    const float P[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const float st[8] = {0, 1, 1, 1, 1, 0, 0, 0}; /* s along x, (0, 0) at the top left */
    const int toward[6] = {0, 2, 1, 0, 3, 2}, nv[2] = {3, 3};
    const float L2[3] = {2, 2, 2};
    /* seen: each side's texel times L, exactly */
    RayesScene *m = rayes_scene_new();
    float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(m, eye, target, up, 30.0f) == RAYES_OK);
    CHECK(rayes_scene_area_light_mesh_textured(m, 2, nv, toward, 4, P, st, L2, 0, two) == RAYES_OK);
    RayesImage *img = render_scene(m, 1, 16);
    const float *a = img ? &img->rgba[4 * (8 * 16 + 2)] : NULL;
    const float *b = img ? &img->rgba[4 * (8 * 16 + 13)] : NULL;
    CHECK(a && b && a[0] + a[1] == 2.0f && b[0] + b[1] == 2.0f && a[2] == 0.0f);
    CHECK(a && b && a[0] != b[0]); /* one side red, the other green */
    rayes_image_free(img);
    rayes_scene_release(m);
    /* lighting a floor from above: the grey image against L 0.5, and the
     * two colours under each side */
    float floor_mean[3][2][3]; /* scene, half of the image (left, right), rgb */
    for (int k = 0; k < 3; k++) {
        RayesScene *s = rayes_scene_new();
        float e2[3] = {0, 3, -3}, t2[3] = {0, 0, 0};
        CHECK(rayes_scene_set_camera(s, e2, t2, up, 50.0f) == RAYES_OK);
        RayesParam kd = pf("Kd", 1);
        CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
        float fl[4][3] = {{-3, 0, -3}, {3, 0, -3}, {-3, 0, 3}, {3, 0, 3}};
        CHECK(rayes_scene_bilinear_patch(s, fl) == RAYES_OK);
        /* the light 1 unit up, facing down, s along x */
        const float Q[12] = {-1, 1, -1, 1, 1, -1, 1, 1, 1, -1, 1, 1};
        const int down[6] = {0, 1, 2, 0, 2, 3};
        const float half[3] = {0.5f, 0.5f, 0.5f}, one[3] = {1, 1, 1};
        RayesError e = k == 0 ? rayes_scene_area_light_mesh(s, 2, nv, down, 4, Q, half, 0)
                              : rayes_scene_area_light_mesh_textured(s, 2, nv, down, 4, Q, st, one,
                                                                     0, k == 1 ? grey : two);
        CHECK(e == RAYES_OK);
        img = render_scene(s, 2, 32);
        for (int h = 0; h < 2; h++)
            for (int c = 0; c < 3; c++) {
                double sum = 0.0;
                for (int y = 12; img && y < 32; y++)
                    for (int x = h * 16; x < h * 16 + 16; x++)
                        sum += img->rgba[4 * (y * 32 + x) + c];
                floor_mean[k][h][c] = (float)(sum / (20 * 16));
            }
        rayes_image_free(img);
        rayes_scene_release(s);
    }
    printf("  floor, left / right half (r g b): L 0.5 %.4f %.4f / %.4f %.4f, grey image %.4f "
           "%.4f / %.4f %.4f, red and green %.4f %.4f / %.4f %.4f\n",
           floor_mean[0][0][0], floor_mean[0][0][1], floor_mean[0][1][0], floor_mean[0][1][1],
           floor_mean[1][0][0], floor_mean[1][0][1], floor_mean[1][1][0], floor_mean[1][1][1],
           floor_mean[2][0][0], floor_mean[2][0][1], floor_mean[2][1][0], floor_mean[2][1][1]);
    for (int h = 0; h < 2; h++)
        for (int c = 0; c < 3; c++)
            CHECK(floor_mean[0][h][c] > 0.05f &&
                  fabsf(floor_mean[1][h][c] - floor_mean[0][h][c]) < 1e-4f * floor_mean[0][h][c]);
    /* each half of the floor takes the colour of the light above it */
    float r_l = floor_mean[2][0][0], g_l = floor_mean[2][0][1];
    float r_r = floor_mean[2][1][0], g_r = floor_mean[2][1][1];
    CHECK((r_l > 1.5f * g_l && g_r > 1.5f * r_r) || (g_l > 1.5f * r_l && r_r > 1.5f * g_r));
    CHECK(floor_mean[2][0][2] < 1e-6f && floor_mean[2][1][2] < 1e-6f);
    /* an image that cannot be read is left out (a warning): the light
     * emits L; no st is refused */
    RayesScene *bad = rayes_scene_new();
    CHECK(rayes_scene_area_light_mesh_textured(bad, 2, nv, toward, 4, P, st, L2, 0,
                                               RAYES_TEST_TMP "/no_such_emission.exr") == RAYES_OK);
    CHECK(bad->n_lights == 1 && bad->lights[0].type == LIGHT_MESH && !bad->lights[0].mesh->tex &&
          bad->lights[0].L.x == 2.0f);
    CHECK(rayes_scene_area_light_mesh_textured(bad, 2, nv, toward, 4, P, NULL, L2, 0, two) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_light_count(bad) == 1);
    rayes_scene_release(bad);
}

/* ---------------------------------------------------------- determinism */

static RayesScene *every_light_scene(void)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 1, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 50.0f);
    RayesParam pl[2] = {pf("Kd", 0.6f), pf("roughness", 0.05f)};
    rayes_scene_set_shader(s, "plastic", pl, 2);
    rayes_scene_sphere(s, 0.8f);
    float floor[4][3] = {{-3, -0.8f, -3}, {3, -0.8f, -3}, {-3, -0.8f, 3}, {3, -0.8f, 3}};
    rayes_scene_bilinear_patch(s, floor);
    RayesParam sp[3] = {pv("from", 1, 3, -1), pv("to", 0, 0, 0), pf("intensity", 5)};
    rayes_scene_light(s, "spotlight", sp, 3);
    RayesParam pt[2] = {pv("from", -2, 2, -1), pf("intensity", 2)};
    rayes_scene_light(s, "pointlight", pt, 2);
    RayesParam di[2] = {pv("to", 0.3f, -1, 0.2f), pf("intensity", 0.3f)};
    rayes_scene_light(s, "distantlight", di, 2);
    const float m[16] = {1, 0, 0, 1.5f, 0, 1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1};
    rayes_scene_set_transform(s, m);
    RayesParam sph[3] = {ps("shape", "sphere"), pf("radius", 0.2f), pf("intensity", 5)};
    rayes_scene_light(s, "arealight", sph, 3);
    RayesParam dk[3] = {ps("shape", "disk"), pf("radius", 0.3f), pf("intensity", 5)};
    rayes_scene_light(s, "arealight", dk, 3);
    const float tri[9] = {-0.3f, 2, 0.5f, 0.3f, 2, 0.5f, 0, 2, 0.9f}, L[3] = {4, 4, 4};
    const int three[1] = {3}, corners[3] = {0, 2, 1};
    rayes_scene_area_light_mesh(s, 1, three, corners, 3, tri, L, 1);
    RayesParam env[2] = {ps("mapname", RAYES_TEST_TMP "/test_lights_map.exr"),
                         pf("intensity", 0.2f)};
    rayes_scene_light(s, "environmentlight", env, 2);
    CHECK(rayes_scene_get_error(s)[0] == '\0');
    return s;
}

static void test_every_light_any_thread_count(void)
{
    write_test_map(RAYES_TEST_TMP "/test_lights_map.exr");
    RayesScene *a = every_light_scene(), *b = every_light_scene();
    RayesImage *one = render_scene(a, 1, 24), *three = render_scene(b, 3, 24);
    CHECK(one && three &&
          memcmp(one->rgba, three->rgba, sizeof(float) * 4 * 24 * 24) == 0);
    rayes_image_free(one);
    rayes_image_free(three);
    rayes_scene_release(a);
    rayes_scene_release(b);
}

/* --------------------------------------------------------------- errors */

/* ---------------------------------------------------------- uberlight */

/* Irradiance from an uberlight at the origin aiming +z (the identity
 * transform), at P facing it: light_sample's Li times the cosine. */
static double uber_at(const Light *l, Vec3 P, Vec3 N)
{
    LightSample ls;
    if (!light_sample(l, P, 0.5f, 0.5f, &ls))
        return 0.0;
    return ls.Li.x * fmax(0.0, v3_dot(N, ls.wi));
}

/* Barzel's shaping, each control alone: depth cut on and off with their
 * smooth edges, the cross-section (a sharp rectangle, an ellipse, sheared),
 * the beam falloff, the distance falloff with its smooth clamp, omni and
 * parallel rays; and the superellipse's own values. */
static void test_uber_light_shaping(void)
{
    CHECK(light_superellipse(0, 0, 1, 1, 2, 2, 1) == 0.0f);
    CHECK(light_superellipse(3, 0, 1, 1, 2, 2, 1) == 1.0f);
    CHECK_NEAR(light_superellipse(1.5f, 0, 1, 1, 2, 2, 1), 0.5, 1e-6); /* halfway, smoothstep */
    CHECK(light_superellipse(0.9f, 0.9f, 1, 1, 1, 1, 0) == 0.0f);      /* a square's corner */
    CHECK(light_superellipse(0.9f, 0.9f, 1, 1, 1, 1, 1) == 1.0f);      /* outside the circle */
    CHECK(light_superellipse(0.6f, 0.6f, 1, 1, 1.0001f, 1.0001f, 1) == 0.0f);
    CHECK(light_superellipse(0.5f, 0.5f, 1, 1, 1, 1, 0.01f) == 0.0f); /* no overflow */
    struct {
        RayesParam p[6];
        int n;
        Vec3 P;
        double expected;
    } c[] = {
        /* a sharp 1 x 0.5 rectangle (wedge, hedge 0, roundness 0) */
        {{pf("wedge", 0), pf("hedge", 0), pf("roundness", 0), pf("height", 0.5f)},
         4,
         v3(4.9f, 0, 5),
         1},
        {{pf("wedge", 0), pf("hedge", 0), pf("roundness", 0), pf("height", 0.5f)},
         4,
         v3(5.1f, 0, 5),
         0},
        {{pf("wedge", 0), pf("hedge", 0), pf("roundness", 0), pf("height", 0.5f)},
         4,
         v3(0, 2.6f, 5),
         0},
        {{pf("wedge", 0), pf("hedge", 0), pf("roundness", 0), pf("height", 0.5f)},
         4,
         v3(4, 2, 5),
         1}, /* the corner is lit */
        {{pf("wedge", 0), pf("hedge", 0), pf("roundness", 1), pf("height", 0.5f)},
         4,
         v3(4, 2, 5),
         0}, /* not in the ellipse */
        {{pf("wedge", 0), pf("hedge", 0), pf("shearx", 1)},
         3,
         v3(9.9f, 0, 5),
         1}, /* sheared: the centre at x / z = 1 */
        {{pf("wedge", 0), pf("hedge", 0), pf("shearx", 1)}, 3, v3(-0.1f, 0, 5), 0},
        /* depth: cuton 2 with a near edge of 1; cutoff 10 and far edge 2 */
        {{pf("cuton", 2), pf("nearedge", 1)}, 2, v3(0, 0, 1.5f), 0.5},
        {{pf("cuton", 2), pf("nearedge", 1)}, 2, v3(0, 0, 0.9f), 0},
        {{pf("cutoff", 10), pf("faredge", 2)}, 2, v3(0, 0, 11), 0.5},
        {{pf("cutoff", 10), pf("faredge", 2)}, 2, v3(0, 0, 12.5f), 0},
        /* the beam: cos^2 */
        {{pf("beamdistribution", 2)}, 1, v3(3, 0, 4), 0.8 * 0.8},
        /* falloff 2 beyond falloffdist 4: (4 / d)^2; 1 at falloffdist */
        {{pf("falloff", 2), pf("falloffdist", 4), pf("maxintensity", 3)}, 3, v3(0, 0, 8), 0.25},
        {{pf("falloff", 2), pf("falloffdist", 4), pf("maxintensity", 3)}, 3, v3(0, 0, 4), 1},
        /* omni: behind the light, depth by distance */
        {{ps("lighttype", "omni"), pf("cuton", 2)}, 2, v3(0, 0, -3), 1},
        {{ps("lighttype", "omni"), pf("cuton", 2)}, 2, v3(0, 0, -1), 0},
    };
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        RayesScene *s = rayes_scene_new();
        CHECK(rayes_scene_light(s, "uberlight", c[k].p, (size_t)c[k].n) == RAYES_OK);
        if (s->n_lights == 1) {
            /* facing the light: its shaping alone */
            double got = uber_at(&s->lights[0], c[k].P, v3_normalize(v3_neg(c[k].P)));
            if (fabs(got - c[k].expected) > 1e-5)
                fprintf(stderr, "  case %zu: %.6f, expected %.6f\n", k, got, c[k].expected);
            CHECK_NEAR(got, c[k].expected, 1e-5);
        }
        rayes_scene_release(s);
    }
    /* omni lights every side at depth above cuton; the distance falloff
     * rises smoothly to maxintensity toward the light, never above */
    RayesScene *s = rayes_scene_new();
    RayesParam omni[1] = {ps("lighttype", "omni")};
    CHECK(rayes_scene_light(s, "uberlight", omni, 1) == RAYES_OK);
    CHECK_NEAR(uber_at(&s->lights[0], v3(0, -3, 0), v3(0, 1, 0)), 1.0, 1e-6);
    rayes_scene_release(s);
    s = rayes_scene_new();
    RayesParam fall[4] = {ps("lighttype", "omni"), pf("falloff", 2), pf("falloffdist", 4),
                          pf("maxintensity", 3)};
    CHECK(rayes_scene_light(s, "uberlight", fall, 4) == RAYES_OK);
    double last = 0.0;
    for (float d = 3.9f; d > 0.05f; d -= 0.25f) {
        double k = uber_at(&s->lights[0], v3(0, 0, d), v3(0, 0, -1));
        CHECK(k > last && k <= 3.0 && k < 4.0 * 4.0 / (d * d));
        last = k;
    }
    CHECK(last > 2.9); /* near the light: maxintensity */
    rayes_scene_release(s);
    /* maxintensity at or below intensity: 1 within falloffdist, bounded */
    s = rayes_scene_new();
    RayesParam low[5] = {ps("lighttype", "omni"), pf("falloff", 2), pf("falloffdist", 4),
                         pf("maxintensity", 0.5f), pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "uberlight", low, 5) == RAYES_OK);
    CHECK_NEAR(uber_at(&s->lights[0], v3(0, 0, 0.5f), v3(0, 0, -1)), 1.0, 1e-6);
    CHECK_NEAR(uber_at(&s->lights[0], v3(0, 0, 8), v3(0, 0, -1)), 0.25, 1e-6);
    rayes_scene_release(s);
    /* parallel rays: along -z from anywhere in the cone, so a floor facing
     * the light gets its full intensity off the axis too */
    s = rayes_scene_new();
    RayesParam par[2] = {pf("parallelrays", 1), pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "uberlight", par, 2) == RAYES_OK);
    LightSample ls;
    CHECK(light_sample(&s->lights[0], v3(3, 1, 5), 0.5f, 0.5f, &ls));
    CHECK_NEAR(ls.wi.z, -1.0, 1e-6);
    CHECK_NEAR(ls.Li.x, 2.0, 1e-6);
    rayes_scene_release(s);
    /* the viewer's edits: moved, the shaping moves along; a new intensity
     * keeps maxintensity where it was */
    s = rayes_scene_new();
    RayesParam lit[5] = {pf("wedge", 0), pf("hedge", 0), pf("falloff", 2), pf("falloffdist", 4),
                         pf("maxintensity", 3)};
    CHECK(rayes_scene_light(s, "uberlight", lit, 5) == RAYES_OK);
    RayesParam move[2] = {pv("translate", 10, 0, 0), pf("intensity", 1.5f)};
    CHECK(rayes_scene_edit_light(s, 0, move, 2) == RAYES_OK);
    float at[3];
    CHECK(rayes_scene_get_light(s, 0, NULL, NULL, at) == RAYES_OK && at[0] == 10.0f);
    CHECK_NEAR(uber_at(&s->lights[0], v3(10, 0, 8), v3(0, 0, -1)), 1.5 * 0.25, 1e-6);
    CHECK(uber_at(&s->lights[0], v3(0, 0, 8), v3(0, 0, -1)) == 0.0); /* outside, now */
    CHECK_NEAR(s->lights[0].uber.maxratio, 2.0, 1e-6);
    rayes_scene_release(s);
}

/* A unit square at depth z centred at (x, 0), facing -z (a bilinear patch). */
static void square_at(RayesScene *s, float x, float z, float half)
{
    const float P[4][3] = {
        {x - half, -half, z}, {x + half, -half, z}, {x - half, half, z}, {x + half, half, z}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
}

/* Shadows of an uberlight at the origin aiming +z on a point at (0, 0, 6)
 * facing it, a square between: ray traced (the default), off, coloured,
 * cast toward a cheated origin, and a blocker's (no geometry). */
static void test_uber_light_shadows(void)
{
    struct {
        RayesParam p[4];
        int n;
        float sq_x; /* the square's centre, z = 3 (NAN: none) */
        double r, g;
    } c[] = {
        {{pf("intensity", 1)}, 1, NAN, 1, 1},
        {{pf("intensity", 1)}, 1, 0, 0, 0},
        {{pf("shadows", 0)}, 1, 0, 1, 1},
        {{pv("shadowcolor", 0.25f, 0.5f, 1)}, 1, 0, 0.25, 0.5},
        /* the cheat moves the shadows' origin 4 along +x: a square off
         * the light's path but on the cheated one shadows, the one on the
         * light's path does not */
        {{pv("shadowcheat", 4, 0, 0)}, 1, 2, 0, 0},
        {{pv("shadowcheat", 4, 0, 0)}, 1, 0, 1, 1},
    };
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        RayesScene *s = rayes_scene_new();
        CHECK(rayes_scene_light(s, "uberlight", c[k].p, (size_t)c[k].n) == RAYES_OK);
        if (!isnan(c[k].sq_x))
            square_at(s, c[k].sq_x, 3, 0.5f);
        Fx f;
        fx_init(&f, s);
        double d[3], sp[3];
        fx_direct(&f, v3(0, 0, 6), v3(0, 0, -1), NULL, 1, NULL, 0.1f, 1, d, sp);
        if (fabs(PI * d[0] - c[k].r) > 1e-4)
            fprintf(stderr, "  case %zu: %.6f, expected %.6f\n", k, PI * d[0], c[k].r);
        CHECK_NEAR(PI * d[0], c[k].r, 1e-4);
        CHECK_NEAR(PI * d[1], c[k].g, 1e-4);
        fx_fini(&f);
    }
    /* A blocker: a sharp 0.5 x 0.5 square in the plane z = 3 of its own
     * space (translated 0.2 along y), no geometry: (0, 0, 6) lies behind it,
     * (3, 0, 6) beside (the segment crosses z = 3 at x = 1.5). */
    const float M[16] = {1, 0, 0, 0, 0, 1, 0, 0.2f, 0, 0, 1, 3, 0, 0, 0, 1};
    RayesParam b[6] = {{"blockermatrix", RAYES_PARAM_FLOATS, {0, 0, 0}, NULL, M, 16},
                       pf("blockerwidth", 0.5f),
                       pf("blockerheight", 0.5f),
                       pf("blockerwedge", 0),
                       pf("blockerhedge", 0),
                       pf("blockerround", 0)};
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_light(s, "uberlight", b, 6) == RAYES_OK);
    CHECK(s->n_lights == 1 && s->lights[0].uber.blocker);
    CHECK_NEAR(uber_at(&s->lights[0], v3(0, 0, 6), v3(0, 0, -1)), 0.0, 0.0);
    CHECK_NEAR(uber_at(&s->lights[0], v3(0, 1.6f, 6), v3(0, 0, -1)), 6 / sqrt(36 + 2.56), 1e-5);
    CHECK(uber_at(&s->lights[0], v3(3, 0, 6), v3(0, 0, -1)) > 0.8);
    rayes_scene_release(s);
}

/* A slide over the cross-section: each quarter of a 2 x 2 image on its
 * quarter of the beam (the first row at +y); black outside. */
static void test_uber_light_slide(void)
{
    const char *path = RAYES_TEST_TMP "/test_lights_uberslide.exr";
    float px[2 * 2 * 4] = {1, 0, 0, 1, 0, 1, 0, 1,  /* top: red, green */
                           0, 0, 1, 1, 1, 1, 1, 1}; /* bottom: blue, white */
    CHECK(image_write_exr(path, 2, 2, px, NULL, 0) == RAYES_OK);
    RayesScene *s = rayes_scene_new();
    RayesParam p[3] = {ps("slidename", path), pf("wedge", 0), pf("hedge", 0)};
    CHECK(rayes_scene_light(s, "uberlight", p, 3) == RAYES_OK);
    const float at[4][3] = {{-0.7f, 0.7f, 1}, {0.7f, 0.7f, 1}, {-0.7f, -0.7f, 1}, {0.7f, -0.7f, 1}};
    for (int k = 0; k < 4 && s->n_lights == 1; k++) {
        LightSample ls;
        CHECK(light_sample(&s->lights[0], v3_load(at[k]), 0.5f, 0.5f, &ls));
        /* bilinear between texel centres at s = 1/4, 3/4: 0.85 is past them */
        CHECK_NEAR(ls.Li.x, px[4 * k], 1e-5);
        CHECK_NEAR(ls.Li.y, px[4 * k + 1], 1e-5);
        CHECK_NEAR(ls.Li.z, px[4 * k + 2], 1e-5);
    }
    rayes_scene_release(s);
}

/* Any light may cast no shadows, or light only the diffuse or only the
 * specular output (RenderMan's __nondiffuse, __nonspecular). */
static void test_light_output_flags(void)
{
    for (int k = 0; k < 4; k++) {
        RayesScene *s = rayes_scene_new();
        RayesParam p[3] = {pv("from", 0, 0, 0), pf("intensity", 36),
                           k == 0   ? pf("shadows", 0)
                           : k == 1 ? pf("__nondiffuse", 1)
                           : k == 2 ? pf("__nonspecular", 1)
                                    : pf("shadows", 1)};
        CHECK(rayes_scene_light(s, "pointlight", p, 3) == RAYES_OK);
        square_at(s, 0, 3, 0.5f);
        Fx f;
        fx_init(&f, s);
        double d[3], sp[3];
        Vec3 I = v3(0, 0, 1);
        fx_direct(&f, v3(0, 0, 6), v3(0, 0, -1), &I, 1, NULL, 0.1f, 1, d, sp);
        /* unshadowed: 36 / 36 = 1 (times the cosine 1) */
        CHECK_NEAR(PI * d[0], k == 0 ? 1.0 : 0.0, 1e-5);
        CHECK(k == 0 ? sp[0] > 0.0 : sp[0] == 0.0);
        fx_fini(&f);
        s = rayes_scene_new();
        CHECK(rayes_scene_light(s, "pointlight", p, 3) == RAYES_OK);
        fx_init(&f, s); /* no square */
        fx_direct(&f, v3(0, 0, 6), v3(0, 0, -1), &I, 1, NULL, 0.1f, 1, d, sp);
        CHECK_NEAR(PI * d[0], k == 1 ? 0.0 : 1.0, 1e-5);
        CHECK(k == 2 ? sp[0] == 0.0 : sp[0] > 0.0);
        fx_fini(&f);
    }
}

static void test_bad_lights(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_light(s, "moonlight", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "moonlight") != NULL);
    rayes_scene_clear_error(s);
    RayesParam bad_type = pv("intensity", 1, 2, 3);
    CHECK(rayes_scene_light(s, "pointlight", &bad_type, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "intensity") != NULL);
    rayes_scene_clear_error(s);
    RayesParam map = ps("mapname", "/nonexistent/sky.exr");
    CHECK(rayes_scene_light(s, "environmentlight", &map, 1) == RAYES_ERROR_IO);
    CHECK(strstr(rayes_scene_get_error(s), "sky.exr") != NULL);
    rayes_scene_clear_error(s);
    RayesParam shape = ps("shape", "torus");
    CHECK(rayes_scene_light(s, "arealight", &shape, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    RayesParam same[2] = {pv("from", 1, 1, 1), pv("to", 1, 1, 1)};
    CHECK(rayes_scene_light(s, "distantlight", same, 2) == RAYES_ERROR_INVALID_ARGUMENT);
    RayesParam neg = pf("intensity", -1);
    CHECK(rayes_scene_light(s, "ambientlight", &neg, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    RayesParam nan = pf("radius", NAN);
    CHECK(rayes_scene_light(s, "arealight", &nan, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_light(s, NULL, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_clear_error(s);
    RayesParam area = ps("lighttype", "arealight");
    CHECK(rayes_scene_light(s, "uberlight", &area, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "lighttype \"arealight\"") != NULL);
    RayesParam round = pf("roundness", 2), width = pf("width", 0), fd = pf("falloffdist", 0);
    CHECK(rayes_scene_light(s, "uberlight", &round, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_light(s, "uberlight", &width, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_light(s, "uberlight", &fd, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    const float zero[16] = {0}, nine[9] = {0};
    RayesParam sing = {"blockermatrix", RAYES_PARAM_FLOATS, {0, 0, 0}, NULL, zero, 16};
    RayesParam short9 = {"blockermatrix", RAYES_PARAM_FLOATS, {0, 0, 0}, NULL, nine, 9};
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_light(s, "uberlight", &sing, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "singular") != NULL);
    CHECK(rayes_scene_light(s, "uberlight", &short9, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    RayesParam noslide = ps("slidename", "/nonexistent/slide.tx");
    CHECK(rayes_scene_light(s, "uberlight", &noslide, 1) == RAYES_ERROR_IO);
    CHECK(s->n_lights == 0); /* failed calls change nothing */
    CHECK(s->n_objects == 0 && s->n_prims == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_point_light_inverse_square), TEST(test_spot_light_cone),
          TEST(test_distant_light), TEST(test_ambient_light), TEST(test_disk_light_irradiance),
          TEST(test_sphere_light_irradiance), TEST(test_light_bound_keeps_every_hit),
          TEST(test_mis_glossy_small_quad), TEST(test_mis_glossy_large_quad),
          TEST(test_mesh_light_clusters_keep_every_face), TEST(test_mesh_light_irradiance),
          TEST(test_mesh_light_sphere), TEST(test_quadric_lights),
          TEST(test_glossy_lights_against_brute_force), TEST(test_classic_specular),
          TEST(test_glossy_surroundings_against_brute_force),
          TEST(test_microfacet_against_brute_force), TEST(test_constant_environment_white_furnace),
          TEST(test_sample_clamp), TEST(test_chrome_ball_white_furnace),
          TEST(test_glass_ball_white_furnace), TEST(test_glass_thin_shadow),
          TEST(test_quad_light_close), TEST(test_environment_map_importance_sampling),
          TEST(test_environment_map_sampling_consistency), TEST(test_octahedral_environment_map),
          TEST(test_point_light_maps), TEST(test_categories), TEST(test_emitters_seen_by_camera),
          TEST(test_textured_mesh_light), TEST(test_every_light_any_thread_count),
          TEST(test_uber_light_shaping), TEST(test_uber_light_shadows), TEST(test_uber_light_slide),
          TEST(test_light_output_flags), TEST(test_bad_lights))
