/*
 * Cameras (rayes_scene_set_camera_matrix): a camera_from_world matrix
 * equal to a look-at camera renders the look-at image; a mirror in the
 * matrix mirrors the image; orthographic projection shows a sphere at its
 * true size whatever its distance; the screen window crops and shifts; the
 * default window spans the shorter side; bad matrices are refused.
 */
#include <math.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

/* A matte sphere of radius 1 at (0, 0, z), a distant light along +z. */
static RayesScene *sphere_scene(float z)
{
    RayesScene *s = rayes_scene_new();
    const float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, z, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesParam lp[2] = {{"from", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0, 0, 1}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", lp, 2) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, int w, int h, int spp)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = w, o.height = h, o.spp = spp, o.bounces = 0, o.threads = 2;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

/* Pixels the sphere covers (alpha over a half), and their mean x. */
static int coverage(const RayesImage *img, double *mean_x)
{
    int n = 0;
    double sx = 0;
    for (int y = 0; img && y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            if (img->rgba[4 * (y * img->width + x) + 3] > 0.5f)
                n++, sx += x + 0.5;
    *mean_x = n ? sx / n : 0;
    return n;
}

/* camera_from_world of the look-at camera: rows are the camera axes. */
static void look_at_matrix(const float eye[3], const float at[3], const float up[3], float m[16])
{
    float z[3], x[3], y[3];
    float l = 0;
    for (int k = 0; k < 3; k++)
        z[k] = at[k] - eye[k], l += z[k] * z[k];
    for (int k = 0; k < 3; k++)
        z[k] /= sqrtf(l);
    x[0] = z[1] * up[2] - z[2] * up[1], x[1] = z[2] * up[0] - z[0] * up[2],
    x[2] = z[0] * up[1] - z[1] * up[0];
    l = sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int k = 0; k < 3; k++)
        x[k] /= l;
    y[0] = x[1] * z[2] - x[2] * z[1], y[1] = x[2] * z[0] - x[0] * z[2],
    y[2] = x[0] * z[1] - x[1] * z[0];
    const float *axes[3] = {x, y, z};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[4 * r + c] = axes[r][c];
        m[4 * r + 3] = -(axes[r][0] * eye[0] + axes[r][1] * eye[1] + axes[r][2] * eye[2]);
    }
    m[12] = m[13] = m[14] = 0, m[15] = 1;
}

static void test_matrix_equals_look_at(void)
{
    const float eye[3] = {0.5f, 0.3f, -4}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    RayesScene *a = sphere_scene(0), *b = sphere_scene(0);
    CHECK(rayes_scene_set_camera(a, eye, at, up, 35.0f) == RAYES_OK);
    float m[16];
    look_at_matrix(eye, at, up, m);
    CHECK(rayes_scene_set_camera_matrix(b, m, RAYES_PROJECTION_PERSPECTIVE, 35.0f, NULL) ==
          RAYES_OK);
    RayesImage *ia = render(a, 48, 32, 2), *ib = render(b, 48, 32, 2);
    double worst = 0;
    for (int i = 0; ia && ib && i < 48 * 32 * 4; i++)
        worst = fmax(worst, fabs(ia->rgba[i] - ib->rgba[i]));
    CHECK(worst < 1e-3);
    double xa, xb;
    CHECK(coverage(ia, &xa) > 50);
    CHECK(coverage(ia, &xa) == coverage(ib, &xb));
    rayes_image_free(ia), rayes_image_free(ib);
    rayes_scene_release(a), rayes_scene_release(b);
}

static void test_mirror_mirrors(void)
{
    /* The eye at the origin looking down +z; the sphere off to +x in the
     * world, which is the image's left for a right-handed world; a matrix
     * mirrored in x puts it on the right. */
    const float eye[3] = {0, 0, 0}, at[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    float m[16];
    RayesImage *ia = NULL, *ib = NULL;
    RayesScene *a = rayes_scene_new(), *b = rayes_scene_new();
    const float at6[16] = {1, 0, 0, 1.5f, 0, 1, 0, 0, 0, 0, 1, 6, 0, 0, 0, 1};
    RayesScene *both[2] = {a, b};
    for (int k = 0; k < 2; k++) {
        CHECK(rayes_scene_set_transform(both[k], at6) == RAYES_OK);
        CHECK(rayes_scene_sphere(both[k], 1.0f) == RAYES_OK);
    }
    look_at_matrix(eye, at, up, m);
    CHECK(rayes_scene_set_camera_matrix(a, m, RAYES_PROJECTION_PERSPECTIVE, 40.0f, NULL) == 0);
    for (int c = 0; c < 4; c++)
        m[c] = -m[c];
    CHECK(rayes_scene_set_camera_matrix(b, m, RAYES_PROJECTION_PERSPECTIVE, 40.0f, NULL) == 0);
    ia = render(a, 40, 40, 1), ib = render(b, 40, 40, 1);
    double xa, xb;
    int na = coverage(ia, &xa), nb = coverage(ib, &xb);
    CHECK(na > 20 && abs(na - nb) <= na / 10);
    CHECK(xa < 20 && xb > 20);
    CHECK(fabs((40 - xa) - xb) < 1.0);
    rayes_image_free(ia), rayes_image_free(ib);
    rayes_scene_release(a), rayes_scene_release(b);
}

static void test_orthographic_true_size(void)
{
    /* Screen window 4 x 4 units on 64 x 64 pixels: a unit sphere covers a
     * disk of 16 pixels' radius at any distance. */
    const float window[4] = {-2, 2, -2, 2};
    const float eye[3] = {0, 0, 0}, at[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    float m[16];
    look_at_matrix(eye, at, up, m);
    for (int k = 0; k < 2; k++) {
        RayesScene *s = sphere_scene(k ? 50.0f : 5.0f);
        CHECK(rayes_scene_set_camera_matrix(s, m, RAYES_PROJECTION_ORTHOGRAPHIC, 0, window) == 0);
        RayesImage *img = render(s, 64, 64, 4);
        double x;
        int n = coverage(img, &x);
        CHECK(fabs(n - M_PI * 16 * 16) < 0.03 * M_PI * 16 * 16);
        CHECK_NEAR(x, 32.0, 0.5);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
    /* A window from 0 to 4 in x shows the sphere's right half at the left edge. */
    const float shifted[4] = {0, 4, -2, 2};
    RayesScene *s = sphere_scene(5.0f);
    CHECK(rayes_scene_set_camera_matrix(s, m, RAYES_PROJECTION_ORTHOGRAPHIC, 0, shifted) == 0);
    RayesImage *img = render(s, 64, 64, 4);
    double x;
    int n = coverage(img, &x);
    CHECK(fabs(n - 0.5 * M_PI * 16 * 16) < 0.04 * M_PI * 16 * 16);
    CHECK(x < 10);
    rayes_image_free(img);
    rayes_scene_release(s);
}

static void test_default_window_spans_shorter_side(void)
{
    /* A portrait image: the fov spans the width. The sphere at distance d
     * with fov 90 shows a disk of tan(asin(1 / d)) screen units' radius,
     * the screen's width being 2 units. */
    const float eye[3] = {0, 0, 0}, at[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    float m[16];
    look_at_matrix(eye, at, up, m);
    RayesScene *s = sphere_scene(3.0f);
    CHECK(rayes_scene_set_camera_matrix(s, m, RAYES_PROJECTION_PERSPECTIVE, 90.0f, NULL) == 0);
    RayesImage *img = render(s, 60, 120, 4);
    double x;
    int n = coverage(img, &x);
    /* radius in pixels: width / 2 * tan(asin(1/3)) / tan(45) = 30 * 0.354 */
    double r = 30.0 * tan(asin(1.0 / 3.0));
    CHECK(fabs(n - M_PI * r * r) < 0.1 * M_PI * r * r);
    rayes_image_free(img);
    rayes_scene_release(s);
}

static void test_bad_cameras(void)
{
    RayesScene *s = rayes_scene_new();
    const float singular[16] = {0};
    const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const float empty[4] = {1, 1, -1, 1};
    CHECK(rayes_scene_set_camera_matrix(s, singular, RAYES_PROJECTION_PERSPECTIVE, 40, NULL) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "invertible") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_set_camera_matrix(s, id, RAYES_PROJECTION_PERSPECTIVE, 180, NULL) != 0);
    CHECK(rayes_scene_set_camera_matrix(s, id, RAYES_PROJECTION_ORTHOGRAPHIC, 0, empty) != 0);
    CHECK(rayes_scene_set_camera_matrix(s, id, (RayesProjection)7, 40, NULL) != 0);
    CHECK(rayes_scene_set_camera_matrix(s, id, RAYES_PROJECTION_ORTHOGRAPHIC, 0, NULL) == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_matrix_equals_look_at), TEST(test_mirror_mirrors),
          TEST(test_orthographic_true_size), TEST(test_default_window_spans_shorter_side),
          TEST(test_bad_cameras))
