/* Vectors, matrices, hashing and sampling (util/). */
#include "test.h"
#include "util/rng.h"
#include "util/sampling.h"
#include "util/vec.h"

static void test_matrix_inverse(void)
{
    Mat4 m = mat4_mul(mat4_translate(3, -2, 7),
                      mat4_mul(mat4_rotate(35.0f, v3(0, 1, 0)), mat4_scale(45, 45, 45)));
    Mat4 inv;
    CHECK(mat4_invert(m, &inv));
    Mat4 id = mat4_mul(m, inv);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            CHECK_NEAR(id.m[i][j], i == j ? 1.0 : 0.0, 1e-5);
    Mat4 singular = mat4_scale(1, 0, 1);
    CHECK(!mat4_invert(singular, &inv));
}

static void test_rotation_is_right_handed(void)
{
    /* 90 degrees about +y takes +z to +x (x' = x cos + z sin). */
    Mat4 r = mat4_rotate(90.0f, v3(0, 1, 0));
    Vec3 p = mat4_vector(&r, v3(0, 0, 1));
    CHECK_NEAR(p.x, 1.0, 1e-6);
    CHECK_NEAR(p.z, 0.0, 1e-6);
}

static void test_basis_is_orthonormal(void)
{
    const Vec3 ns[] = {v3(0, 0, 1), v3(0, 0, -1), v3(1, 0, 0), v3_normalize(v3(1, 2, -3))};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        Vec3 t, b;
        v3_basis(ns[i], &t, &b);
        CHECK_NEAR(v3_dot(t, ns[i]), 0.0, 1e-6);
        CHECK_NEAR(v3_dot(b, ns[i]), 0.0, 1e-6);
        CHECK_NEAR(v3_dot(t, b), 0.0, 1e-6);
        CHECK_NEAR(v3_length(t), 1.0, 1e-6);
        CHECK_NEAR(v3_dot(v3_cross(t, b), ns[i]), 1.0, 1e-6); /* right-handed */
    }
}

/* v3_basis_toward's t is d's direction in the plane; for d along n, or
 * off it by rounding alone, still a frame of the plane (it once lay along
 * n, and a hit's texture footprint came out zero). */
static void test_basis_toward(void)
{
    Vec3 n = v3_normalize(v3(1e-8f, -1.0f, 3e-8f)), t, b;
    const Vec3 ds[] = {v3(0, 1, 0), v3(0, -2, 0), v3(1e-7f, 1, 0), v3(0, 0.99999994f, 1e-9f),
                       v3(1, 1, 0)};
    for (size_t i = 0; i < sizeof ds / sizeof ds[0]; i++) {
        v3_basis_toward(n, ds[i], &t, &b);
        CHECK_NEAR(v3_dot(t, n), 0.0, 1e-5);
        CHECK_NEAR(v3_dot(b, n), 0.0, 1e-5);
        CHECK_NEAR(v3_dot(t, b), 0.0, 1e-5);
        CHECK_NEAR(v3_length(t), 1.0, 1e-5);
        CHECK_NEAR(v3_length(b), 1.0, 1e-5);
    }
    /* along a normal of float length not exactly 1: the old projection
     * normalised came out along n (t.n = 0.99 for (1, 2, 3)) */
    const Vec3 ns[] = {v3_normalize(v3(1, 2, 3)), v3_normalize(v3(-2, 1, 0.5f)),
                       v3_normalize(v3(0.3f, -0.7f, 0.2f))};
    const float cs[] = {1.0f, -3.7f, 0.25f};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++)
        for (size_t k = 0; k < sizeof cs / sizeof cs[0]; k++) {
            v3_basis_toward(ns[i], v3_scale(ns[i], cs[k]), &t, &b);
            CHECK_NEAR(v3_dot(t, ns[i]), 0.0, 1e-5);
            CHECK_NEAR(v3_dot(b, ns[i]), 0.0, 1e-5);
            CHECK_NEAR(v3_length(t), 1.0, 1e-5);
            CHECK_NEAR(v3_length(b), 1.0, 1e-5);
        }
    v3_basis_toward(v3(0, 0, 1), v3(3, 0, -5), &t, &b);
    CHECK_NEAR(t.x, 1.0, 1e-6);
    CHECK_NEAR(b.y, 1.0, 1e-6);
}

/* Every count n puts at most one sample in each of its m x k strata (one
 * in each when n = m k), and n = m k whenever n has a divisor between
 * half of floor(sqrt(n)) and sqrt(n). */
static void test_cmj_stratified(void)
{
    for (uint32_t n = 1; n <= 70; n++) {
        uint32_t m, k, r = 1, exact = 0;
        cmj_strata(n, &m, &k);
        while ((r + 1) * (r + 1) <= n)
            r++;
        for (uint32_t d = r; 2 * d >= r; d--)
            exact |= n % d == 0;
        CHECK(m * k >= n && m <= r && (m * k == n) == (exact != 0));
        int cells[80][80] = {{0}};
        for (uint32_t s = 0; s < n; s++) {
            float x, y;
            cmj_sample_2d(s, n, 1234u + n, &x, &y);
            CHECK(x >= 0.0f && x < 1.0f && y >= 0.0f && y < 1.0f);
            cells[(int)(x * m)][(int)(y * k)]++;
        }
        int worst = 0;
        for (uint32_t i = 0; i < m; i++)
            for (uint32_t j = 0; j < k; j++)
                worst = cells[i][j] > worst ? cells[i][j] : worst;
        CHECK(worst <= 1);
    }
}

/* Points are uniform on average over patterns, whatever n: the means of
 * x and y are 1/2 and the top eighth holds an eighth of them. (Filling
 * the first n of m k strata, the top row's end stays empty: n = 32 had a
 * mean y of 0.46 and diffuse estimates 0.7% dark.) */
static void test_cmj_uniform_on_average(void)
{
    const uint32_t counts[] = {5, 7, 28, 31, 32, 33, 40, 127};
    for (size_t c = 0; c < sizeof counts / sizeof *counts; c++) {
        uint32_t n = counts[c];
        double mx = 0.0, my = 0.0, top = 0.0, total = 0.0;
        for (uint32_t p = 1; p <= 4000; p++)
            for (uint32_t s = 0; s < n; s++) {
                float x, y;
                cmj_sample_2d(s, n, p * 0x2545f491u, &x, &y);
                mx += x, my += y, top += y >= 0.875f, total++;
            }
        CHECK_NEAR(mx / total, 0.5, 0.004);
        CHECK_NEAR(my / total, 0.5, 0.004);
        CHECK_NEAR(top / total, 0.125, 0.004);
    }
}

static void test_cmj_deterministic_and_pattern_dependent(void)
{
    float x1, y1, x2, y2, x3, y3;
    cmj_sample_2d(3, 16, 42, &x1, &y1);
    cmj_sample_2d(3, 16, 42, &x2, &y2);
    cmj_sample_2d(3, 16, 43, &x3, &y3);
    CHECK(x1 == x2 && y1 == y2);
    CHECK(x1 != x3 || y1 != y3);
}

/* A tabled pattern draws cmj_sample_2d's samples bit for bit, one at a
 * time and in batches (from an odd start, past CMJ_BATCH), for counts
 * whose shape fits the tables and for those past them (17,000 samples:
 * 130 columns). */
static void test_cmj_pattern_equals_samples(void)
{
    const uint32_t counts[] = {1, 2, 3, 4, 5, 16, 24, 63, 64, 100, 1000, 4096, 17000};
    for (size_t c = 0; c < sizeof counts / sizeof *counts; c++) {
        uint32_t n = counts[c], p = 0x9e3779b9u * (uint32_t)(c + 1);
        CmjPattern pat;
        cmj_pattern_init(&pat, n, p);
        CHECK(pat.tabled == (n < 17000));
        for (uint32_t s = 0; s < n; s++) {
            float x1, y1, x2, y2;
            cmj_sample_2d(s, n, p, &x1, &y1);
            cmj_pattern_sample(&pat, s, &x2, &y2);
            if (x1 != x2 || y1 != y2) {
                CHECK(x1 == x2 && y1 == y2);
                break;
            }
        }
        static float xs[17000], ys[17000];
        uint32_t first = n > 3 ? 3 : 0;
        cmj_pattern_samples(&pat, first, n - first, xs, ys);
        for (uint32_t s = first; s < n; s++) {
            float x1, y1;
            cmj_sample_2d(s, n, p, &x1, &y1);
            if (x1 != xs[s - first] || y1 != ys[s - first]) {
                CHECK(x1 == xs[s - first] && y1 == ys[s - first]);
                break;
            }
        }
    }
}

static void test_hash_combine_is_ordered(void)
{
    CHECK(hash_combine(1, 2) != hash_combine(2, 1));
    CHECK(hash_combine(7, 9) == hash_combine(7, 9));
    CHECK(rng_float(5) >= 0.0f && rng_float(5) < 1.0f);
}

/* Cosine-weighted directions: E[cos] = 2/3, E[cos^2] = 1/2, all above. */
static void test_cosine_hemisphere_moments(void)
{
    Vec3 n = v3_normalize(v3(0.3f, -0.5f, 0.8f));
    const uint32_t N = 4096;
    double m1 = 0.0, m2 = 0.0;
    for (uint32_t s = 0; s < N; s++) {
        float a, b;
        cmj_sample_2d(s, N, 99, &a, &b);
        Vec3 d = sample_cosine_hemisphere(n, a, b);
        CHECK_NEAR(v3_length(d), 1.0, 1e-5);
        float c = v3_dot(d, n);
        CHECK(c >= -1e-6f);
        m1 += c;
        m2 += c * c;
    }
    CHECK_NEAR(m1 / N, 2.0 / 3.0, 2e-3);
    CHECK_NEAR(m2 / N, 0.5, 2e-3);
}

static void test_bounds_distance(void)
{
    Bounds3 b = {v3(0, 0, 0), v3(1, 1, 1)};
    CHECK_NEAR(bounds_distance(b, v3(0.5f, 0.5f, 0.5f)), 0.0, 0.0);
    CHECK_NEAR(bounds_distance(b, v3(4, 1, 1)), 3.0, 1e-6);
    CHECK_NEAR(bounds_distance(b, v3(-3, -4, 0.5f)), 5.0, 1e-6);
}

TEST_MAIN(TEST(test_matrix_inverse), TEST(test_rotation_is_right_handed),
          TEST(test_basis_is_orthonormal), TEST(test_basis_toward), TEST(test_cmj_stratified),
          TEST(test_cmj_uniform_on_average), TEST(test_cmj_deterministic_and_pattern_dependent),
          TEST(test_cmj_pattern_equals_samples), TEST(test_hash_combine_is_ordered),
          TEST(test_cosine_hemisphere_moments), TEST(test_bounds_distance))
