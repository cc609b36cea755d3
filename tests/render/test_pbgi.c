/*
 * Point-based global illumination (render/pbgi.c): the gather against
 * analytic answers on clouds made here (a furnace: inside a uniformly
 * bright sphere of disks every point gathers its radiosity; a nearer disk
 * hides a farther one), the point cloud of a lit plane (its total power,
 * read back from the PLY the renderer writes), and whole renders that do
 * not depend on the number of threads.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "render/pbgi.h"
#include "test.h"

static const double PI = 3.14159265358979323846;

/* n disks tiling the sphere of radius R about the origin (a Fibonacci
 * lattice), facing inward, each of radiosity L. */
static PbgiDisk *sphere_disks(size_t n, float R, Vec3 L)
{
    PbgiDisk *d = malloc(n * sizeof *d);
    double golden = PI * (3.0 - sqrt(5.0));
    for (size_t i = 0; i < n; i++) {
        double z = 1.0 - (2.0 * (double)i + 1.0) / (double)n, r = sqrt(1.0 - z * z);
        double phi = golden * (double)i;
        Vec3 u = v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
        v3_store(d[i].P, v3_scale(u, R));
        v3_store(d[i].N, v3_neg(u));
        d[i].area = (float)(4.0 * PI * R * R / (double)n);
        v3_store(d[i].L, L);
    }
    return d;
}

/* Inside a closed sphere of radiosity L every point, whatever its normal,
 * gathers L: the clusters far away and the disks near the wall alike.
 * Light is lost where the raster's coverage has gaps: measured at most
 * 0.9% at the first two points, 2-5.2% at the last two, near the wall (at
 * 0.1 of the radius, looking along it), where clusters are seen edge-on
 * and the horizon cuts fragments. */
static void test_furnace(void)
{
    Vec3 L = v3(0.5f, 1.0f, 2.0f);
    const float angles[2] = {0.01f, 0.05f};
    for (int a = 0; a < 2; a++) {
        PbgiCloud *c = pbgi_cloud_new(sphere_disks(20000, 1.0f, L), 20000, angles[a], 8);
        CHECK(c != NULL);
        if (!c)
            return;
        PbgiRaster r;
        CHECK(pbgi_raster_init(&r, c) == 0);
        const Vec3 P[4] = {v3(0, 0, 0), v3(0.3f, -0.2f, 0.1f), v3(0, 0, -0.9f),
                           v3(0.5f, 0.5f, 0.5f)};
        const Vec3 N[4] = {v3(0, 0, 1), v3(0.6f, 0, 0.8f), v3(0, 0, 1), v3(-0.48f, 0.6f, -0.64f)};
        for (int k = 0; k < 4; k++) {
            Vec3 E = pbgi_gather(c, &r, P[k], N[k]);
            double tol = k < 2 ? 0.015 : 0.06;
            CHECK_NEAR(E.x / L.x, 1.0, tol);
            CHECK_NEAR(E.y / L.y, 1.0, tol);
            CHECK_NEAR(E.z / L.z, 1.0, tol);
        }
        pbgi_raster_fini(&r);
        pbgi_cloud_free(c);
    }
}

/* The same furnace in a closed cube [-1, 1]^3 of 6 x 40 x 40 disks facing
 * in (flat walls, as the box's): at its centre (a normal along an axis,
 * the raster's cube then aligned with the walls) and at points with tilted
 * normals, near a wall and a corner too. Measured: 96.4-99.2% gathered. */
static void test_furnace_cube(void)
{
    const int m = 40;
    PbgiDisk *d = malloc((size_t)6 * m * m * sizeof *d), *k = d;
    for (int f = 0; f < 6; f++) {
        int a = f / 2, u = (a + 1) % 3, v = (a + 2) % 3;
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++, k++) {
                float p[3], n[3] = {0, 0, 0};
                p[a] = f % 2 ? -1.0f : 1.0f;
                p[u] = -1.0f + 2.0f * ((float)i + 0.5f) / (float)m;
                p[v] = -1.0f + 2.0f * ((float)j + 0.5f) / (float)m;
                n[a] = -p[a];
                memcpy(k->P, p, sizeof p);
                memcpy(k->N, n, sizeof n);
                k->area = 4.0f / (float)(m * m);
                v3_store(k->L, v3(1, 1, 1));
            }
    }
    for (int s = 0; s < 2; s++) {
        PbgiDisk *copy = malloc((size_t)6 * m * m * sizeof *copy);
        memcpy(copy, d, (size_t)6 * m * m * sizeof *copy);
        PbgiCloud *c = pbgi_cloud_new(copy, (size_t)6 * m * m, s ? 0.05f : 0.01f, 8);
        PbgiRaster r;
        CHECK(c && pbgi_raster_init(&r, c) == 0);
        if (!c)
            break;
        const Vec3 P[5] = {v3(0, 0, 0), v3(0, 0, 0), v3(0.5f, 0.3f, -0.2f), v3(0, 0, -0.99f),
                           v3(0.9f, 0.9f, -0.99f)};
        const Vec3 N[5] = {v3(0, 0, 1), v3_normalize(v3(0.13f, 0.21f, 1)), v3(0.6f, 0, 0.8f),
                           v3_normalize(v3(0.1f, -0.17f, 1)), v3_normalize(v3(-0.2f, 0.1f, 1))};
        for (int q = 0; q < 5; q++)
            CHECK_NEAR(pbgi_gather(c, &r, P[q], N[q]).x, 1.0, 0.045);
        pbgi_raster_fini(&r);
        pbgi_cloud_free(c);
    }
    free(d);
}

/* Disks of radius rad at height h above the origin, facing down, of
 * radiosity L, as a cloud of one or two. */
static void put_disk(PbgiDisk *d, float h, float rad, float L)
{
    v3_store(d->P, v3(0, 0, h));
    v3_store(d->N, v3(0, 0, -1));
    d->area = (float)(PI * rad * rad);
    v3_store(d->L, v3(L, L, L));
}

/* A bright disk above the point gives its form factor; a black disk
 * nearer, covering it, hides it (in either order in the cloud), and one
 * beside it does not. */
static void test_occlusion(void)
{
    PbgiRaster r;
    PbgiDisk *far = malloc(sizeof *far);
    put_disk(far, 2.0f, 2.0f, 1.0f);
    PbgiCloud *c = pbgi_cloud_new(far, 1, 0.05f, 8);
    CHECK(pbgi_raster_init(&r, c) == 0);
    /* The form factor of a coaxial disk of radius a at height h: a^2 /
     * (a^2 + h^2) = 0.5. */
    float alone = pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x;
    CHECK_NEAR(alone, 0.5, 0.08);
    pbgi_raster_fini(&r);
    pbgi_cloud_free(c);
    for (int order = 0; order < 2; order++) {
        PbgiDisk *two = malloc(2 * sizeof *two);
        put_disk(&two[order], 2.0f, 2.0f, 1.0f);
        put_disk(&two[1 - order], 1.0f, 1.5f, 0.0f); /* nearer, black, wider cone */
        c = pbgi_cloud_new(two, 2, 0.05f, 8);
        CHECK(pbgi_raster_init(&r, c) == 0);
        float hidden = pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x;
        CHECK(hidden < 0.05f * alone);
        pbgi_raster_fini(&r);
        pbgi_cloud_free(c);
    }
    PbgiDisk *aside = malloc(2 * sizeof *aside);
    put_disk(&aside[0], 2.0f, 2.0f, 1.0f);
    put_disk(&aside[1], 1.0f, 0.3f, 0.0f);
    v3_store(aside[1].P, v3(-3.0f, 0.0f, 1.0f)); /* black, off to the side */
    c = pbgi_cloud_new(aside, 2, 0.05f, 8);
    CHECK(pbgi_raster_init(&r, c) == 0);
    CHECK_NEAR(pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x, alone, 1e-6);
    pbgi_raster_fini(&r);
    pbgi_cloud_free(c);
}

/* A disk seen from behind is black but still hides what is beyond. */
static void test_back_faces_occlude(void)
{
    PbgiDisk *two = malloc(2 * sizeof *two);
    put_disk(&two[0], 2.0f, 2.0f, 1.0f);
    put_disk(&two[1], 1.0f, 1.5f, 5.0f);
    v3_store(two[1].N, v3(0, 0, 1)); /* bright on its far side only */
    PbgiCloud *c = pbgi_cloud_new(two, 2, 0.05f, 8);
    PbgiRaster r;
    CHECK(pbgi_raster_init(&r, c) == 0);
    CHECK(pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x < 0.03f);
    pbgi_raster_fini(&r);
    pbgi_cloud_free(c);
}

/* The disks of a PLY the renderer wrote: count and sum of L A per channel
 * (0 on a malformed file). */
static size_t read_ply(const char *path, double power[3])
{
    FILE *f = fopen(path, "rb");
    char line[256];
    size_t n = 0;
    power[0] = power[1] = power[2] = 0.0;
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n") != 0)
        sscanf(line, "element vertex %zu", &n);
    for (size_t i = 0; i < n; i++) {
        unsigned char b[40];
        float rec[10];
        if (fread(b, 1, sizeof b, f) != sizeof b) {
            n = 0;
            break;
        }
        for (int k = 0; k < 10; k++) {
            uint32_t u = (uint32_t)b[4 * k] | (uint32_t)b[4 * k + 1] << 8 |
                         (uint32_t)b[4 * k + 2] << 16 | (uint32_t)b[4 * k + 3] << 24;
            memcpy(&rec[k], &u, 4);
        }
        for (int c = 0; c < 3; c++)
            power[c] += (double)rec[6] * rec[7 + c];
    }
    fclose(f);
    return n;
}

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static RayesParam pc(const char *name, float a, float b, float c)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {a, b, c}, NULL};
}

/* A 4 x 3 matte plane (Kd 0.6, Cs 1 0.5 0.25) under a distant light of
 * irradiance 2 at 60 degrees: its point cloud's power, sum pi L A, is Kd
 * Cs E A with E = 2 cos 60 = 1 (the plane is off camera: the cloud has it
 * all the same). */
static void test_lit_plane_power(void)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, 10}, target[3] = {0, 0, 11}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 40.0f); /* looking away */
    RayesParam light[3] = {pf("intensity", 2.0f), pc("from", 0, 0, 0),
                           pc("to", 0, -(float)sin(PI / 3), -0.5f)};
    CHECK(rayes_scene_light(s, "distantlight", light, 3) == RAYES_OK);
    RayesParam m[2] = {pf("Kd", 0.6f), pc("Cs", 1.0f, 0.5f, 0.25f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 2) == RAYES_OK);
    const float P[4][3] = {{-2, -1.5f, 0}, {2, -1.5f, 0}, {-2, 1.5f, 0}, {2, 1.5f, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 1;
    o.threads = 2;
    o.gi = RAYES_GI_POINTBASED;
    o.pointcloud_out = RAYES_TEST_TMP "/test_pbgi_plane.ply";
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    double power[3];
    size_t n = read_ply(o.pointcloud_out, power);
    const RayesStat *pts = st ? rayes_stats_find(st, "pbgi/points") : NULL;
    CHECK(n >= 16 && pts && pts->count == n);
    const double cs[3] = {1.0, 0.5, 0.25};
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(PI * power[c] / (0.6 * cs[c] * 1.0 * 12.0), 1.0, 1e-3);
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
}

static RayesImage *render_box(int threads, int bounces, const char *ply)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    RayesError e = io_builtin_scene("cornell-teapots", RAYES_TEST_DATA, &sink, err, sizeof err);
    if (e == RAYES_OK)
        e = rayes_scene_commit(s);
    CHECK(e == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = 40;
    o.height = 32;
    o.spp = 1;
    o.threads = threads;
    o.bounces = bounces;
    o.hider = RAYES_HIDER_GRID;
    o.gi = RAYES_GI_POINTBASED;
    o.pointcloud_out = ply;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static int same_image(const RayesImage *a, const RayesImage *b)
{
    return a && b && a->width == b->width && a->height == b->height &&
           memcmp(a->rgba, b->rgba, sizeof(float) * 4 * (size_t)a->width * a->height) == 0;
}

static int same_file(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb, ca, cb;
    while (same && (ca = fgetc(fa)) != EOF) {
        cb = fgetc(fb);
        same = ca == cb;
    }
    if (same)
        same = fgetc(fb) == EOF;
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

static double image_mean(const RayesImage *img)
{
    double s = 0.0;
    for (int i = 0; img && i < img->width * img->height; i++)
        s += img->rgba[4 * i] + img->rgba[4 * i + 1] + img->rgba[4 * i + 2];
    return img ? s / (3.0 * img->width * img->height) : 0.0;
}

/* The same cloud and image bytes on one and two threads, with a bounce on
 * the cloud (pass 2); each bounce adds light. */
static void test_threads_and_bounces(void)
{
    const char *p1 = RAYES_TEST_TMP "/test_pbgi_t1.ply", *p2 = RAYES_TEST_TMP "/test_pbgi_t2.ply";
    RayesImage *one = render_box(1, 2, p1), *two = render_box(2, 2, p2);
    CHECK(same_image(one, two));
    CHECK(same_file(p1, p2));
    RayesImage *b0 = render_box(2, 0, NULL), *b1 = render_box(2, 1, NULL);
    double m0 = image_mean(b0), m1 = image_mean(b1), m2 = image_mean(two);
    CHECK(m0 > 0.0 && m1 > 1.05 * m0 && m2 > 1.01 * m1);
    rayes_image_free(one);
    rayes_image_free(two);
    rayes_image_free(b0);
    rayes_image_free(b1);
}

/* Bad options are refused with a message. */
static void test_bad_options(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 8;
    o.gi = RAYES_GI_POINTBASED;
    o.pbgi_raster = 7;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT);
    o.pbgi_raster = 8;
    o.pbgi_max_solid_angle = 0.0f;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT);
    o.pbgi_max_solid_angle = 0.05f;
    rayes_scene_release(s); /* a scene keeps its first message: a new one */
    s = rayes_scene_new();
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    o.pointcloud_out = RAYES_TEST_TMP "/no/such/dir/cloud.ply";
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_IO);
    CHECK(strstr(rayes_scene_get_error(s), "cloud.ply") != NULL);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_furnace), TEST(test_furnace_cube), TEST(test_occlusion), TEST(test_back_faces_occlude),
          TEST(test_lit_plane_power), TEST(test_threads_and_bounces), TEST(test_bad_options))
