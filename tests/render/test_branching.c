/*
 * Ray trees past the branch depth (RayesRenderOptions.branch_depth): glass
 * nested in glass inside a white furnace (a closed sphere emitting
 * radiance 1, no bounces), so every path that leaves the glass sees
 * exactly 1. Past the branch depth a glass hit follows one of reflection
 * and refraction (shade/builtin_bsdf.c), so at specular depth 64 the rays
 * per camera ray stay bounded where branching at every hit would double
 * them per bounce; the image keeps its expectation (1 for clear glass,
 * and the fully branched image's for tinted glass, whose paths end by
 * Russian roulette); a glossy lobe traces one ray past the branch
 * depth; and so does an uncached diffuse hit (a white furnace); a path
 * split into a glossy lobe's rays traces its share of diffuse rays; a
 * lobe takes its share of the hemisphere's rays; a mix of two materials
 * follows one of them.
 */
#include <stdio.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

typedef struct Result {
    double mean;          /* red channel over the image */
    uint64_t camera, specular, diffuse;
} Result;

/* Commits and renders s with o on 2 threads, and releases it. */
static Result run(RayesScene *s, RayesRenderOptions *o)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    o->threads = 2;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, o, &img, &st) == RAYES_OK);
    Result r = {0, 0, 0, 0};
    for (int i = 0; img && i < img->width * img->height; i++)
        r.mean += img->rgba[4 * i];
    r.mean /= img ? img->width * img->height : 1;
    const RayesStat *cam = rayes_stats_find(st, "rays/camera");
    const RayesStat *spec = rayes_stats_find(st, "rays/specular");
    const RayesStat *dif = rayes_stats_find(st, "rays/diffuse");
    CHECK(cam && spec && dif);
    r.camera = cam ? cam->count : 0;
    r.specular = spec ? spec->count : 0;
    r.diffuse = dif ? dif->count : 0;
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
    return r;
}

/* A scene seen from (0, 0, -4) over fov degrees, inside a furnace: a
 * sphere of radius 20 emitting 1, of albedo kd. */
static RayesScene *furnace(float kd, float fov)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, fov);
    RayesParam wall[3] = {
        {"Kd", RAYES_PARAM_FLOAT, {kd, 0, 0}, NULL},
        {"Ke", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
        {"Cs", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "matte", wall, 3) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 20.0f) == RAYES_OK);
    return s;
}

static void translate(RayesScene *s, float x, float y, float z)
{
    float m[16] = {1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
}

/* tint: the glass's transmitcolor; roughness 0: smooth. */
static Result render(int specular_depth, int branch_depth, float tint, float roughness, int spp)
{
    RayesScene *s = furnace(0.0f, 30.0f);
    RayesParam glass[3] = {
        {"eta", RAYES_PARAM_FLOAT, {1.5f, 0, 0}, NULL},
        {"transmitcolor", RAYES_PARAM_COLOR, {tint, tint, tint}, NULL},
        {"roughness", RAYES_PARAM_FLOAT, {roughness, 0, 0}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "glass", glass, 3) == RAYES_OK);
    for (int k = 0; k < 3; k++) { /* three spheres, each inside the last */
        translate(s, 0.05f * (float)k, 0.0f, 0.0f);
        CHECK(rayes_scene_sphere(s, 1.0f - 0.3f * (float)k) == RAYES_OK);
    }
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = spp;
    o.bounces = 0;
    o.specular_depth = specular_depth;
    o.branch_depth = branch_depth;
    return run(s, &o);
}

static void test_deep_glass_stays_a_path(void)
{
    Result r = render(64, 1, 1.0f, 0.0f, 16);
    /* depth 0 traces reflection and refraction, each a path of at most 64 */
    CHECK(r.specular <= r.camera * (2 + 2 * 64));
    CHECK(r.specular < r.camera * 16); /* most paths leave after a few bounces */
    CHECK_NEAR(r.mean, 1.0, 0.01);     /* clear glass loses nothing */
}

/* A mix of two glasses follows one of them past the branch depth (each
 * following its own lobe doubled the paths at every bounce: 2^depth), and
 * keeps clear glass's expectation. */
static void test_mix_stays_a_path(void)
{
    RayesScene *s = furnace(0.0f, 30.0f);
    RayesParam mix[5] = {
        {"a", RAYES_PARAM_STRING, {0, 0, 0}, "glass"},
        {"b", RAYES_PARAM_STRING, {0, 0, 0}, "glass"},
        {"a:eta", RAYES_PARAM_FLOAT, {1.5f, 0, 0}, NULL},
        {"b:eta", RAYES_PARAM_FLOAT, {1.4f, 0, 0}, NULL},
        {"amount", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "mix", mix, 5) == RAYES_OK);
    for (int k = 0; k < 3; k++) {
        translate(s, 0.05f * (float)k, 0.0f, 0.0f);
        CHECK(rayes_scene_sphere(s, 1.0f - 0.3f * (float)k) == RAYES_OK);
    }
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 16;
    o.bounces = 0;
    o.specular_depth = 20;
    o.branch_depth = 1;
    Result r = run(s, &o);
    /* depth 0 branches (both glasses, reflection and refraction), then
     * paths of at most 20 */
    CHECK(r.specular <= r.camera * 4 * (1 + 20));
    CHECK_NEAR(r.mean, 1.0, 0.02);
}

static void test_same_expectation_as_branching(void)
{
    /* At specular depth 6 full branching is affordable (2^6 rays a path):
     * the one-lobe image must agree with it, for clear glass and for
     * tinted glass whose paths end by roulette. */
    Result tree = render(6, 129, 1.0f, 0.0f, 4);
    Result path = render(6, 1, 1.0f, 0.0f, 64);
    /* the tree is several times bigger per camera ray */
    CHECK(tree.specular * path.camera > 4 * path.specular * tree.camera);
    CHECK_NEAR(path.mean / tree.mean, 1.0, 0.01);
    Result ttree = render(6, 129, 0.6f, 0.0f, 4);
    Result tpath = render(6, 1, 0.6f, 0.0f, 64);
    CHECK(ttree.mean < 0.9 && ttree.mean > 0.2);
    CHECK_NEAR(tpath.mean / ttree.mean, 1.0, 0.03);
    /* A branch depth beyond the specular depth is the old full tree */
    Result same = render(6, 7, 0.6f, 0.0f, 4);
    CHECK(same.specular == ttree.specular && same.mean == ttree.mean);
}

static void test_glossy_lobe_one_ray_deep(void)
{
    /* A rough glass: at depth 0 the lobe takes the preset's 4 rays, deeper
     * one; branching everywhere multiplies them per bounce. Same
     * expectation; and deep enough, little is lost (the lobe's directions
     * below the surface bring nothing: 3% here, total internal reflection
     * at grazing angles). */
    Result path = render(4, 1, 1.0f, 0.05f, 16);
    Result tree = render(4, 129, 1.0f, 0.05f, 4);
    CHECK(path.specular * 4 < tree.specular); /* for 4 times the samples */
    CHECK_NEAR(path.mean / tree.mean, 1.0, 0.02);
    double deep = render(32, 1, 1.0f, 0.05f, 16).mean;
    CHECK(deep > 0.95 && deep < 1.01);
}

/* Uncached diffuse paths: a furnace of albedo a emitting 1, the cache off,
 * 8 bounces with 4 diffuse rays a point. Past the branch depth each hit
 * traces one ray: a path, not 4^8 rays, with the same expectation, the
 * sum of a^k for k = 0..8. */
static void test_uncached_diffuse_path(void)
{
    const float a = 0.5f;
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, 0}, target[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 90.0f);
    RayesParam p[3] = {
        {"Kd", RAYES_PARAM_FLOAT, {a, 0, 0}, NULL},
        {"Ke", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
        {"Cs", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "matte", p, 3) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 10.0f) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 4;
    o.bounces = 8;
    o.cache = 0;
    Result r = run(s, &o);
    double expected = 0.0, ak = 1.0;
    for (int k = 0; k <= 8; k++, ak *= a)
        expected += ak;
    CHECK_NEAR(r.mean / expected, 1.0, 0.01);
    CHECK(r.diffuse <= r.camera * (4 + 4 * 7));
}

/* A rough glass ball filling the frame in a furnace whose wall (albedo
 * 0.5, emitting 1) bounces light once, 64 diffuse rays a camera hit. The
 * ball's reflection and refraction lobes take 64 rays each at the camera
 * hit; each wall hit they reach is a path split 64 ways, so it traces
 * 64 / 64 = 1 diffuse ray (and one shadow ray, were there lights), not
 * 64: some 128 a camera ray rather than 8192. The image keeps the
 * expectation of one ray a lobe and a hit. */
static Result render_split(int diffuse_rays, int spp)
{
    RayesScene *s = furnace(0.5f, 20.0f);
    RayesParam glass[2] = {
        {"eta", RAYES_PARAM_FLOAT, {1.5f, 0, 0}, NULL},
        {"roughness", RAYES_PARAM_FLOAT, {0.05f, 0, 0}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "glass", glass, 2) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 8;
    o.spp = spp;
    o.bounces = 1;
    o.diffuse_rays = diffuse_rays;
    return run(s, &o);
}

/* A rough copper ball filling the frame in a white furnace, 1024 diffuse
 * rays a camera hit (final's), no bounces: its GGX lobe of width alpha
 * takes 1024 times 4 alpha^2 rays (its share of the hemisphere), at least
 * 16 and at most 1024: alpha 0.05 takes 16, 0.25 takes 256, 0.6 all 1024
 * (a lobe's ray may leave below the surface: not traced); preview's 4 stay
 * 4. The image is the same furnace within noise at every count. */
static Result render_copper(float alpha, int diffuse_rays)
{
    RayesScene *s = furnace(0.0f, 10.0f);
    RayesParam copper[1] = {{"roughness", RAYES_PARAM_FLOAT, {alpha * alpha, 0, 0}, NULL}};
    CHECK(rayes_scene_set_shader(s, "conductor", copper, 1) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 8;
    o.spp = 4;
    o.bounces = 0;
    o.diffuse_rays = diffuse_rays;
    return run(s, &o);
}

static void test_glossy_rays_by_width(void)
{
    const float alpha[3] = {0.05f, 0.25f, 0.6f};
    const int want[3] = {16, 256, 1024};
    for (int k = 0; k < 3; k++) {
        Result r = render_copper(alpha[k], 1024), p = render_copper(alpha[k], 4);
        double per = (double)r.specular / (double)r.camera;
        fprintf(stderr, "alpha %g: %g lobe rays a camera ray (%d asked), mean %g; preview %g\n",
                (double)alpha[k], per, want[k], r.mean, (double)p.specular / (double)p.camera);
        CHECK(per <= want[k] && per > (k < 2 ? 0.9 : 0.6) * want[k]); /* wide: more below */
        CHECK((double)p.specular / (double)p.camera <= 4.0);
        CHECK(r.mean > 0.5 && r.mean < 1.0);
        CHECK_NEAR(p.mean / r.mean, 1.0, 0.03);
    }
}

static void test_split_lobe_keeps_counts(void)
{
    Result split = render_split(64, 16), one = render_split(1, 1024);
    /* and the cache fills' 4 a point */
    CHECK(split.diffuse <= split.camera * 3 * 64);
    CHECK(split.diffuse >= split.camera * 64);
    CHECK(split.mean > 1.2 && split.mean < 1.6);
    CHECK_NEAR(split.mean / one.mean, 1.0, 0.02);
}

TEST_MAIN(TEST(test_glossy_rays_by_width), TEST(test_split_lobe_keeps_counts),
          TEST(test_uncached_diffuse_path), TEST(test_deep_glass_stays_a_path),
          TEST(test_same_expectation_as_branching), TEST(test_glossy_lobe_one_ray_deep),
          TEST(test_mix_stays_a_path))
