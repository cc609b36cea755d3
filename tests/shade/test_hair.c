/*
 * The hair BSDF (shade/hair.h, pbrt-v4's model of Chiang et al. 2016)
 * against what must hold of it, as pbrt-v4's own tests check: a fibre
 * that absorbs nothing scatters all the light it receives (a white
 * furnace, by uniform directions over the sphere, for every roughness and
 * offset); its density integrates to 1; drawing from it with no absorption
 * gives weights f / pdf of exactly 1; drawing from it and drawing
 * uniformly estimate the same integrals for an absorbing fibre; it is
 * reciprocal in the sense that swapping the directions leaves the
 * absorption-free sum unchanged for a fibre without tilt; and the colour
 * conversions round-trip.
 */
#include <math.h>
#include <stdint.h>

#include "shade/hair.h"
#include "test.h"

/* A small deterministic generator (xorshift64*), uniform in [0, 1). */
static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static float uniform(void)
{
    rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
    return (float)((rng_state * 2685821657736338717ull) >> 40) / 16777216.0f;
}

static Vec3 uniform_sphere(float a, float b)
{
    float z = 1.0f - 2.0f * a, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 6.2831853f * b;
    return v3(r * cosf(phi), r * sinf(phi), z);
}

static void test_white_furnace(void)
{
    const float betas[] = {0.1f, 0.3f, 0.6f, 1.0f};
    for (int m = 0; m < 4; m++)
        for (int n = 0; n < 4; n++) {
            double sum = 0.0;
            const int count = 200000;
            for (int k = 0; k < count; k++) {
                HairBsdf b;
                hair_bsdf_init(&b, -1.0f + 2.0f * uniform(), 1.55f, v3(0, 0, 0), betas[m], betas[n],
                               2.0f);
                Vec3 wo = uniform_sphere(uniform(), uniform());
                Vec3 wi = uniform_sphere(uniform(), uniform());
                sum += hair_bsdf_f(&b, wo, wi).y * (4.0 * M_PI);
            }
            /* narrow lobes make the uniform estimate noisy: pbrt allows 5% */
            CHECK_NEAR(sum / count, 1.0, betas[m] < 0.2f ? 0.08 : 0.03);
        }
}

static void test_pdf_integrates_to_one(void)
{
    const float betas[] = {0.2f, 0.5f, 0.9f};
    for (int m = 0; m < 3; m++) {
        HairBsdf b;
        hair_bsdf_init(&b, 0.3f, 1.55f, v3(0.5f, 1.0f, 2.0f), betas[m], betas[m], 2.0f);
        Vec3 wo = v3_normalize(v3(0.3f, 0.5f, 0.8f));
        double sum = 0.0;
        const int count = 400000;
        for (int k = 0; k < count; k++)
            sum += hair_bsdf_pdf(&b, wo, uniform_sphere(uniform(), uniform())) * 4.0 * M_PI;
        CHECK_NEAR(sum / count, 1.0, 0.03);
    }
}

static void test_sampling_weights_without_absorption(void)
{
    int bad = 0, drawn = 0;
    for (int k = 0; k < 100000; k++) {
        HairBsdf b;
        hair_bsdf_init(&b, -1.0f + 2.0f * uniform(), 1.55f, v3(0, 0, 0), 0.05f + uniform(),
                       0.05f + uniform(), 2.0f);
        Vec3 wo = uniform_sphere(uniform(), uniform()), wi;
        float pdf;
        if (!hair_bsdf_sample(&b, wo, uniform(), uniform(), uniform(), &wi, &pdf))
            continue;
        drawn++;
        float w = hair_bsdf_f(&b, wo, wi).x / pdf;
        bad += !(fabsf(w - 1.0f) < 1e-3f) || !(fabsf(v3_length(wi) - 1.0f) < 1e-4f);
    }
    CHECK(drawn > 99000);
    CHECK(bad == 0);
}

static void test_sampling_agrees_with_uniform(void)
{
    HairBsdf b;
    hair_bsdf_init(&b, 0.4f, 1.55f, v3(0.2f, 0.6f, 1.5f), 0.3f, 0.3f, 2.0f);
    Vec3 wo = v3_normalize(v3(-0.2f, 0.9f, 0.4f));
    /* a smooth weight over directions, so the two estimates meet */
    double by_bsdf[3] = {0, 0, 0}, by_sphere[3] = {0, 0, 0};
    const int count = 400000;
    for (int k = 0; k < count; k++) {
        Vec3 wi;
        float pdf;
        if (hair_bsdf_sample(&b, wo, uniform(), uniform(), uniform(), &wi, &pdf)) {
            Vec3 f = hair_bsdf_f(&b, wo, wi);
            double g = 1.0 + wi.x * wi.z;
            by_bsdf[0] += f.x * g / pdf, by_bsdf[1] += f.y * g / pdf, by_bsdf[2] += f.z * g / pdf;
        }
        wi = uniform_sphere(uniform(), uniform());
        Vec3 f = hair_bsdf_f(&b, wo, wi);
        double g = 4.0 * M_PI * (1.0 + wi.x * wi.z);
        by_sphere[0] += f.x * g, by_sphere[1] += f.y * g, by_sphere[2] += f.z * g;
    }
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(by_bsdf[c] / count, by_sphere[c] / count, 0.02 * by_bsdf[c] / count + 1e-4);
    /* absorption: red (least absorbed) ahead of blue, all below 1 */
    CHECK(by_bsdf[0] > by_bsdf[1] && by_bsdf[1] > by_bsdf[2] && by_bsdf[0] / count < 1.0);
}

static void test_colour_conversions(void)
{
    Vec3 c = v3(0.8f, 0.5f, 0.2f);
    for (float bn = 0.1f; bn < 1.0f; bn += 0.2f) {
        Vec3 back = hair_reflectance_from_sigma_a(hair_sigma_a_from_reflectance(c, bn), bn);
        CHECK_NEAR(back.x, c.x, 1e-4);
        CHECK_NEAR(back.y, c.y, 1e-4);
        CHECK_NEAR(back.z, c.z, 1e-4);
    }
    /* pbrt's default, 1.3 of eumelanin: brown, red the brightest */
    Vec3 s = hair_sigma_a_from_melanin(1.3f, 0.0f);
    CHECK_NEAR(s.x, 1.3 * 0.419, 1e-5);
    CHECK_NEAR(s.z, 1.3 * 1.37, 1e-5);
}

/* The mean albedo's quadrature against a brute-force average: 1 without
 * absorption, and for an absorbing fibre the same as uniform views,
 * offsets and directions give. */
static void test_mean_albedo(void)
{
    Vec3 one = hair_bsdf_mean_albedo(1.55f, v3(0, 0, 0), 0.3f, 0.3f, 2.0f);
    CHECK_NEAR(one.x, 1.0, 1e-3);
    CHECK_NEAR(one.z, 1.0, 1e-3);
    Vec3 sigma = v3(0.13f, 0.21f, 0.41f);
    Vec3 q = hair_bsdf_mean_albedo(1.55f, sigma, 0.3f, 0.3f, 2.0f);
    double sum[3] = {0, 0, 0};
    const int count = 400000;
    for (int k = 0; k < count; k++) {
        HairBsdf b;
        hair_bsdf_init(&b, -1.0f + 2.0f * uniform(), 1.55f, sigma, 0.3f, 0.3f, 2.0f);
        Vec3 wo = uniform_sphere(uniform(), uniform()), wi;
        float pdf;
        if (hair_bsdf_sample(&b, wo, uniform(), uniform(), uniform(), &wi, &pdf)) {
            Vec3 f = hair_bsdf_f(&b, wo, wi);
            sum[0] += f.x / pdf, sum[1] += f.y / pdf, sum[2] += f.z / pdf;
        }
    }
    CHECK_NEAR(q.x, sum[0] / count, 0.01 * q.x);
    CHECK_NEAR(q.y, sum[1] / count, 0.01 * q.y);
    CHECK_NEAR(q.z, sum[2] / count, 0.015 * q.z);
    CHECK(q.x > q.y && q.y > q.z && q.x < 1.0f);
}

TEST_MAIN(TEST(test_mean_albedo), TEST(test_white_furnace), TEST(test_pdf_integrates_to_one),
          TEST(test_sampling_weights_without_absorption), TEST(test_sampling_agrees_with_uniform),
          TEST(test_colour_conversions))
