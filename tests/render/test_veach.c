/*
 * Veach's multiple-importance-sampling scene, rendered (issue 15, item 1):
 * two copper conductor plates side by side, one nearly smooth and one
 * rough, each reflecting a small bright and a large dim spherical area
 * light of equal power. The whole image is plate; each plate's image
 * half (less the columns beside the seam) is compared with a brute-force
 * estimate made here, by many samples of the conductor's lobe (the
 * microfacet service's GGX, shade/bsdf.h) traced against the
 * spheres analytically, with no light sampling at all.
 *
 * The defect this would have caught: plates glowing copper all over
 * under the small light instead of carrying its blurred reflection.
 */
#include <math.h>
#include <string.h>

#include "rayes/rayes.h"
#include "shade/bsdf.h"
#include "test.h"
#include "util/rng.h"

enum { RES = 48, SEAM = 2 };

static const float ROUGHNESS[2] = {0.005f, 0.1f}; /* pbrt-v4 roughness, x < 0 and x > 0 */
static const float EYE[3] = {0, -3, 3}, TARGET[3] = {0, 0, 0}, UP[3] = {0, 0, 1};
static const float FOV = 40.0f; /* degrees */

typedef struct Sphere {
    Vec3 C;
    float r, L; /* radius, radiance */
} Sphere;

/* Each light's reflection falls at x = C.x / 2 on the plate: two on each. */
static const Sphere LIGHTS[4] = {{{-2.4f, 3, 3}, 0.5f, 1.0f},
                                 {{-0.8f, 3, 3}, 0.05f, 100.0f},
                                 {{0.8f, 3, 3}, 0.5f, 1.0f},
                                 {{2.4f, 3, 3}, 0.05f, 100.0f}};

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}
static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

static RayesScene *veach_scene(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_camera(s, EYE, TARGET, UP, FOV) == RAYES_OK);
    for (int k = 0; k < 2; k++) {
        float x0 = k ? 0.0f : -10.0f, x1 = k ? 10.0f : 0.0f;
        const float P[4][3] = {{x0, -10, 0}, {x1, -10, 0}, {x0, 10, 0}, {x1, 10, 0}};
        RayesParam p[1] = {pf("roughness", ROUGHNESS[k])};
        CHECK(rayes_scene_set_shader(s, "conductor", p, 1) == RAYES_OK);
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    }
    for (int k = 0; k < 4; k++) {
        const Sphere *l = &LIGHTS[k];
        const float move[16] = {1, 0, 0, l->C.x, 0, 1, 0, l->C.y, 0, 0, 1, l->C.z, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, move) == RAYES_OK);
        RayesParam p[3] = {ps("shape", "sphere"), pf("radius", l->r), pf("intensity", l->L)};
        CHECK(rayes_scene_light(s, "arealight", p, 3) == RAYES_OK);
    }
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

/* Radiance along the ray o + t d (d unit) from the nearest sphere hit, or 0. */
static double sphere_radiance(Vec3 o, Vec3 d)
{
    double best = INFINITY, L = 0.0;
    for (int k = 0; k < 4; k++) {
        Vec3 oc = v3_sub(o, LIGHTS[k].C);
        double b = v3_dot(oc, d), c = v3_dot(oc, oc) - (double)LIGHTS[k].r * LIGHTS[k].r;
        double disc = b * b - c;
        if (disc < 0.0)
            continue;
        double t = -b - sqrt(disc);
        if (t > 0.0 && t < best)
            best = t, L = LIGHTS[k].L;
    }
    return L;
}

/* The camera ray through screen position (sx, sy) in [-1, 1]^2, +x right,
 * +y up (rayes_scene_set_camera: fov spans the square image). */
static Vec3 camera_dir(float sx, float sy)
{
    Vec3 f = v3_normalize(v3_sub(v3(TARGET[0], TARGET[1], TARGET[2]), v3(EYE[0], EYE[1], EYE[2])));
    Vec3 r = v3_normalize(v3_cross(f, v3(UP[0], UP[1], UP[2]))), u = v3_cross(r, f);
    float t = tanf(FOV * 0.5f * (float)M_PI / 180.0f);
    return v3_normalize(v3_add(f, v3_add(v3_scale(r, sx * t), v3_scale(u, sy * t))));
}

/* The brute-force mean of the red channel over pixel columns [x0, x1) of
 * the whole image height: image positions uniform over those pixels, each
 * with n_lobe directions from the conductor's lobe. */
static double brute_force_mean(int x0, int x1, int n_pos, int n_lobe)
{
    Vec3 eye = v3(EYE[0], EYE[1], EYE[2]), eta = v3(0.200f, 0.924f, 1.102f),
         k = v3(3.912f, 2.452f, 2.142f);
    double sum = 0.0;
    for (int i = 0; i < n_pos; i++) {
        uint64_t key = hash_combine(99, (uint64_t)i);
        float px = x0 + (x1 - x0) * rng_float(hash_combine(key, 1));
        float py = RES * rng_float(hash_combine(key, 2));
        Vec3 d = camera_dir(2.0f * px / RES - 1.0f, 1.0f - 2.0f * py / RES);
        if (!(d.z < 0.0f))
            continue;
        Vec3 P = v3_madd(eye, d, -eye.z / d.z), V = v3_neg(d); /* plate z = 0, N = +z */
        float alpha = bsdf_alpha_from_roughness(ROUGHNESS[P.x > 0]);
        double F = v3_index(fresnel_conductor_rgb(V.z, eta, k), 0), Li = 0.0;
        for (int j = 0; j < n_lobe; j++) {
            BsdfSample b =
                bsdf_ggx_sample(V, rng_float(hash_combine(key, 3 + 2 * (uint64_t)j)),
                                rng_float(hash_combine(key, 4 + 2 * (uint64_t)j)), alpha);
            if (b.weight > 0.0f && b.wi.z > 0.0f)
                Li += b.weight * sphere_radiance(P, b.wi);
        }
        sum += F * Li / n_lobe;
    }
    return sum / n_pos;
}

static void test_veach_plates_against_brute_force(void)
{
    RayesScene *s = veach_scene();
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 16;
    o.filter = RAYES_FILTER_BOX;
    o.filter_width = 1.0f;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    for (int half = 0; img && half < 2; half++) {
        int x0 = half ? RES / 2 + SEAM : 0, x1 = half ? RES : RES / 2 - SEAM;
        double sum = 0.0;
        for (int y = 0; y < RES; y++)
            for (int x = x0; x < x1; x++)
                sum += img->rgba[4 * (y * RES + x)];
        double got = sum / ((double)(x1 - x0) * RES), want = brute_force_mean(x0, x1, 1 << 14, 256);
        printf("plate roughness %g: rendered %.5f, brute force %.5f\n", ROUGHNESS[half], got, want);
        CHECK(want > 0.0);
        CHECK_NEAR(got / want, 1.0, 0.05); /* the two estimates' noise, about 1% each */
    }
    rayes_image_free(img);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_veach_plates_against_brute_force))
