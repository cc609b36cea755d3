/*
 * Diffusion profiles (shade/diffusion.h, memo 6.2) against analytic
 * answers: the dipole's integral over the plane is Jensen 2001's closed
 * form of the total diffuse reflectance (computed here on its own) for
 * every measured medium; Burley's profile is the paper's closed form for
 * the diffuse mean free path and integrates to the same Rd; the
 * conversions from RenderMan's albedo and diffuse mean free path and from
 * pbrt's reflectance and mean free path give back what they were given;
 * the 4 pi / N area estimate of rays cast from points inside a sphere sums
 * to the sphere's area; presets resolve by name, unknown names fail.
 */
#include <math.h>

#include "shade/diffusion.h"
#include "test.h"
#include "util/media.h"

/* Jensen 2001 eq. 8, written from the paper, not from diffusion.c. */
static double closed_form(double alpha, double eta)
{
    double fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    double A = (1.0 + fdr) / (1.0 - fdr), q = sqrt(3.0 * (1.0 - alpha));
    return alpha / 2.0 * (1.0 + exp(-4.0 / 3.0 * A * q)) * exp(-q);
}

/* The integral of 2 pi r R(r) dr over [0, far], midpoint rule on a
 * logarithmic grid (the profiles are peaked at 0 and long-tailed). */
static double plane_integral(const DiffusionChannel *ch, double far)
{
    double sum = 0.0, r0 = 0.0;
    const int n = 200000;
    for (int k = 1; k <= n; k++) {
        double r1 = far * (exp(12.0 * k / n) - 1.0) / (exp(12.0) - 1.0), r = 0.5 * (r0 + r1);
        sum += 2.0 * M_PI * r * diffusion_profile(ch, (float)r) * (r1 - r0);
        r0 = r1;
    }
    return sum;
}

static void test_dipole_integrates_to_closed_form_rd(void)
{
    for (int i = 0; media_measured[i].name; i++) {
        RayesSubsurfaceParams p = {.eta = 1.3f, .scale = 1.0f, .profile = RAYES_SUBSURFACE_DIPOLE};
        CHECK(diffusion_preset(media_measured[i].name, p.sigma_s, p.sigma_a) == 0);
        for (int c = 0; c < 3; c++) {
            if (p.sigma_a[c] <= 0.0f)
                continue; /* spectralon: no absorption, no finite reach */
            DiffusionChannel ch;
            diffusion_channel(&p, c, &ch);
            double alpha = p.sigma_s[c] / (double)(p.sigma_s[c] + p.sigma_a[c]);
            double want = closed_form(alpha, 1.3);
            CHECK_NEAR(ch.Rd, want, 1e-4);
            CHECK_NEAR(plane_integral(&ch, 60.0 / ch.sigma_tr), want, 0.005 * want);
        }
    }
}

static void test_burley_integrates_to_the_same_rd(void)
{
    static const char *const media[3] = {"marble", "skin1", "ketchup"};
    for (int i = 0; i < 3; i++) {
        RayesSubsurfaceParams p = {.eta = 1.3f, .scale = 1.0f, .profile = RAYES_SUBSURFACE_BURLEY};
        CHECK(diffusion_preset(media[i], p.sigma_s, p.sigma_a) == 0);
        for (int c = 0; c < 3; c++) {
            DiffusionChannel ch;
            diffusion_channel(&p, c, &ch);
            CHECK_NEAR(plane_integral(&ch, 200.0 * ch.d), ch.Rd, 0.005 * ch.Rd);
        }
    }
}

/* Burley's profile is the paper's closed form, written here from
 * Christensen and Burley 2015 (eq. 2 with their fit of s for the diffuse
 * mean free path, section 5), with A the dipole's Rd and l = 1 / sigma_tr:
 * R(r) = A s (e^{-s r / l} + e^{-s r / 3l}) / (8 pi l r), s = 3.5 + 100
 * (A - 0.33)^4. */
static void test_burley_is_the_papers_dmfp_fit(void)
{
    static const char *const media[4] = {"marble", "skin1", "ketchup", "cream"};
    for (int i = 0; i < 4; i++) {
        RayesSubsurfaceParams p = {.eta = 1.3f, .scale = 1.0f, .profile = RAYES_SUBSURFACE_BURLEY};
        CHECK(diffusion_preset(media[i], p.sigma_s, p.sigma_a) == 0);
        for (int c = 0; c < 3; c++) {
            DiffusionChannel ch;
            diffusion_channel(&p, c, &ch);
            double st = (double)p.sigma_s[c] + p.sigma_a[c];
            double A = closed_form(p.sigma_s[c] / st, 1.3), l = 1.0 / sqrt(3.0 * p.sigma_a[c] * st);
            double sc = 3.5 + 100.0 * pow(A - 0.33, 4.0);
            for (int k = 0; k < 5; k++) {
                double r = l * (0.05 + 0.6 * k);
                double want = A * sc * (exp(-sc * r / l) + exp(-sc * r / (3.0 * l))) /
                              (8.0 * M_PI * l * r);
                /* float against double: A (1e-4) enters s, amplified by s r / l */
                CHECK_NEAR(diffusion_profile(&ch, (float)r), want, 5e-3 * want);
            }
        }
    }
}

static void test_conversions_round_trip(void)
{
    const float Rd[3] = {0.1f, 0.5f, 0.85f}, len[3] = {0.2f, 1.0f, 7.0f};
    for (int k = 0; k < 3; k++) {
        float ss, sa;
        diffusion_from_dmfp(Rd[k], len[k], 1.4f, &ss, &sa);
        RayesSubsurfaceParams p = {{ss, ss, ss}, {sa, sa, sa}, 1.4f, 1.0f, 0};
        DiffusionChannel ch;
        diffusion_channel(&p, 0, &ch);
        CHECK_NEAR(ch.Rd, Rd[k], 1e-4);
        CHECK_NEAR(1.0 / ch.sigma_tr, len[k], 1e-3 * len[k]);
        diffusion_from_mfp(Rd[k], len[k], 1.4f, &ss, &sa);
        p = (RayesSubsurfaceParams){{ss, ss, ss}, {sa, sa, sa}, 1.4f, 1.0f, 0};
        diffusion_channel(&p, 0, &ch);
        CHECK_NEAR(ch.Rd, Rd[k], 1e-4);
        CHECK_NEAR(1.0 / (ss + sa), len[k], 1e-4 * len[k]);
        CHECK_NEAR(
            diffusion_total_reflectance(diffusion_albedo_from_reflectance(Rd[k], 1.4f), 1.4f),
            Rd[k], 1e-5);
    }
}

/* Rays from points inside a sphere of radius R (centre 0): the areas of
 * their hits add up to 4 pi R^2, whatever the point (stratified
 * directions, as the renderer casts them). */
static void test_area_estimate_integrates_a_sphere(void)
{
    const double R = 2.0, offsets[3] = {0.0, 0.7, 1.5};
    const int n = 64 * 64;
    for (int k = 0; k < 3; k++) {
        double o[3] = {offsets[k], 0.0, 0.0}, sum = 0.0;
        for (int i = 0; i < 64; i++)
            for (int j = 0; j < 64; j++) {
                double a = (i + 0.5) / 64.0, b = (j + 0.5) / 64.0;
                double z = 1.0 - 2.0 * a, s = sqrt(1.0 - z * z), phi = 2.0 * M_PI * b;
                double d[3] = {s * cos(phi), s * sin(phi), z};
                double od = o[0] * d[0], oo = o[0] * o[0];
                double t = -od + sqrt(od * od - (oo - R * R));
                double x[3] = {o[0] + t * d[0], t * d[1], t * d[2]};
                double cos_x = (x[0] * d[0] + x[1] * d[1] + x[2] * d[2]) / R;
                sum += diffusion_sample_area(n, (float)t, (float)cos_x, 0.001f);
            }
        CHECK_NEAR(sum, 4.0 * M_PI * R * R, 0.002 * 4.0 * M_PI * R * R);
    }
}

static void test_presets_by_name(void)
{
    float s[3], a[3];
    static const char *const jensen[9] = {"skin1", "Skin2",     "marble",   "ketchup", "apple",
                                          "cream", "wholemilk", "skimmilk", "potato"};
    for (int i = 0; i < 9; i++)
        CHECK(diffusion_preset(jensen[i], s, a) == 0);
    CHECK(diffusion_preset("marble", s, a) == 0 && fabsf(s[0] - 2.19f) < 1e-6f &&
          fabsf(a[2] - 0.0071f) < 1e-7f);
    CHECK(diffusion_preset("granite", s, a) != 0);
}

TEST_MAIN(TEST(test_dipole_integrates_to_closed_form_rd),
          TEST(test_burley_integrates_to_the_same_rd), TEST(test_burley_is_the_papers_dmfp_fit),
          TEST(test_conversions_round_trip),
          TEST(test_area_estimate_integrates_a_sphere), TEST(test_presets_by_name))
