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
    PbgiDisk *d = calloc(n, sizeof *d);
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
    PbgiDisk *d = calloc((size_t)6 * m * m, sizeof *d), *k = d;
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
        PbgiDisk *copy = calloc((size_t)6 * m * m, sizeof *copy);
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
    PbgiDisk *far = calloc(1, sizeof *far);
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
        PbgiDisk *two = calloc(2, sizeof *two);
        put_disk(&two[order], 2.0f, 2.0f, 1.0f);
        put_disk(&two[1 - order], 1.0f, 1.5f, 0.0f); /* nearer, black, wider cone */
        c = pbgi_cloud_new(two, 2, 0.05f, 8);
        CHECK(pbgi_raster_init(&r, c) == 0);
        float hidden = pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x;
        CHECK(hidden < 0.05f * alone);
        pbgi_raster_fini(&r);
        pbgi_cloud_free(c);
    }
    PbgiDisk *aside = calloc(2, sizeof *aside);
    put_disk(&aside[0], 2.0f, 2.0f, 1.0f);
    put_disk(&aside[1], 1.0f, 0.3f, 0.0f);
    v3_store(aside[1].P, v3(-3.0f, 0.0f, 1.0f)); /* black, off to the side */
    c = pbgi_cloud_new(aside, 2, 0.05f, 8);
    CHECK(pbgi_raster_init(&r, c) == 0);
    CHECK_NEAR(pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x, alone, 1e-6);
    pbgi_raster_fini(&r);
    pbgi_cloud_free(c);
}

/* A wall of m x m disks facing -x at x = 1 over y in [-0.5, 1.5], z in
 * [0, 1.5], radiosity 1 (a red and a green half), and a black one nearer,
 * at x = 0.6, over y in [-1, -0.2], z in [0, 0.6], facing +x: a cloud
 * whose irradiance at points of the plane z = 0 varies in x and y. */
static PbgiCloud *wall_cloud(int m, int raster)
{
    PbgiDisk *d = calloc((size_t)2 * m * m, sizeof *d), *k = d;
    for (int w = 0; w < 2; w++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++, k++) {
                float u = ((float)i + 0.5f) / (float)m, v = ((float)j + 0.5f) / (float)m;
                float y0 = w ? -1.0f : -0.5f, dy = w ? 0.8f : 2.0f, dz = w ? 0.6f : 1.5f;
                v3_store(k->P, v3(w ? 0.6f : 1.0f, y0 + dy * u, dz * v));
                v3_store(k->N, v3(w ? 1.0f : -1.0f, 0, 0));
                k->area = dy * dz / (float)(m * m);
                v3_store(k->L, w ? v3(0, 0, 0) : u < 0.5f ? v3(1, 0.2f, 0.1f) : v3(0.1f, 1, 0.2f));
            }
    return pbgi_cloud_new(d, (size_t)2 * m * m, 0.01f, raster);
}

/* The record's gradients against central differences of the gather (the
 * point moved 0.04 along x and y, the normal turned 0.04 rad about them),
 * at three points, red and green, on the default 8 x 8 raster. The
 * differences are themselves uneven (the raster's pixels and the
 * clusters change as the point moves: they vary by up to a third between
 * steps of 0.01 and 0.04), so the check is of the sum of the errors over
 * the 12 derivatives against the sum of their sizes: measured 15.8%
 * translational, 5.3% rotational (a gradient missing, of the wrong sign or
 * scale would be 100% or more), and of each one's sign where it is large. */
static void test_gradients(void)
{
    PbgiCloud *c = wall_cloud(32, 8);
    PbgiRaster r;
    CHECK(c && pbgi_raster_init(&r, c) == 0);
    if (!c)
        return;
    const Vec3 P[3] = {v3(0, 0, 0), v3(0.2f, 0.5f, 0), v3(-0.3f, -0.3f, 0)}, N = v3(0, 0, 1);
    const float h = 0.04f;
    double err_t = 0.0, sum_t = 0.0, err_r = 0.0, sum_r = 0.0;
    for (int k = 0; k < 3; k++) {
        IrrRecord rec;
        pbgi_record(c, &r, P[k], N, &rec);
        Vec3 E0 = v3_scale(pbgi_gather(c, &r, P[k], N), (float)PI);
        CHECK_NEAR(rec.E.x, E0.x, 1e-4);
        CHECK_NEAR(rec.E.y, E0.y, 1e-4);
        CHECK(rec.R > 0.3f && rec.R < 1.5f); /* the black wall's and the wall's distances */
        for (int axis = 0; axis < 2; axis++) {
            Vec3 e = axis ? v3(0, 1, 0) : v3(1, 0, 0), t = v3_cross(e, N);
            Vec3 up = pbgi_gather(c, &r, v3_madd(P[k], e, h), N);
            Vec3 dn = pbgi_gather(c, &r, v3_madd(P[k], e, -h), N);
            Vec3 ru = pbgi_gather(c, &r, P[k], v3_normalize(v3_madd(N, t, h))); /* turned about e */
            Vec3 rd = pbgi_gather(c, &r, P[k], v3_normalize(v3_madd(N, t, -h)));
            for (int ch = 0; ch < 2; ch++) {
                double fd = PI * (ch ? up.y - dn.y : up.x - dn.x) / (2 * h);
                double fr = PI * (ch ? ru.y - rd.y : ru.x - rd.x) / (2 * h);
                double gt = v3_dot(rec.grad_t[ch], e), gr = v3_dot(rec.grad_r[ch], e);
                double E = ch ? E0.y : E0.x;
                err_t += fabs(gt - fd), sum_t += fabs(fd);
                err_r += fabs(gr - fr), sum_r += fabs(fr);
                CHECK(fabs(fd) < 0.2 * E || gt * fd > 0.0);
                CHECK(fabs(fr) < 0.2 * E || gr * fr > 0.0);
            }
        }
    }
    CHECK(err_t < 0.3 * sum_t);
    CHECK(err_r < 0.1 * sum_r);
    printf("gradients against differences: translational %.1f%%, rotational %.1f%%\n",
           100 * err_t / sum_t, 100 * err_r / sum_r);
    pbgi_raster_fini(&r);
    pbgi_cloud_free(c);
}

/* A disk seen from behind is black but still hides what is beyond. */
static void test_back_faces_occlude(void)
{
    PbgiDisk *two = calloc(2, sizeof *two);
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

/* A disk's back side (Lb, against its normal) is what a point behind it
 * gathers: a disk and a far cluster of 32 x 32 disks facing away from the
 * point, back radiosity 3, gather what they gather facing it with front
 * radiosity 3 (within 1%); with back radiosity 0 (a one-sided disk) they
 * are black from behind. */
static void test_back_sides(void)
{
    const int m = 32;
    for (int cluster = 0; cluster < 2; cluster++) {
        float got[3];
        for (int v = 0; v < 3; v++) { /* facing, its back lit, its back black */
            size_t n = cluster ? (size_t)m * m : 1;
            PbgiDisk *d = calloc(n, sizeof *d);
            for (size_t k = 0; k < n; k++) {
                float x = cluster ? -0.5f + ((float)(k % m) + 0.5f) / (float)m : 0.0f;
                float y = cluster ? -0.5f + ((float)(k / m) + 0.5f) / (float)m : 0.0f;
                put_disk(&d[k], cluster ? 6.0f : 1.0f, 1.0f, 3.0f);
                v3_store(d[k].P, v3(x, y, d[k].P[2]));
                if (cluster)
                    d[k].area = 1.0f / (float)(m * m);
                if (v > 0) {
                    v3_store(d[k].N, v3(0, 0, 1));
                    v3_store(d[k].Lb, v3(v == 1 ? 3.0f : 0.0f, 0, 0));
                    v3_store(d[k].L, v3(0, 0, 0));
                }
            }
            PbgiCloud *c = pbgi_cloud_new(d, n, 0.05f, 8);
            PbgiRaster r;
            CHECK(c && pbgi_raster_init(&r, c) == 0);
            if (!c)
                return;
            got[v] = pbgi_gather(c, &r, v3(0, 0, 0), v3(0, 0, 1)).x;
            pbgi_raster_fini(&r);
            pbgi_cloud_free(c);
        }
        CHECK(got[0] > 0.0f);
        CHECK_NEAR(got[1] / got[0], 1.0, 0.01);
        CHECK(got[2] == 0.0f);
    }
}

/* The disks of a PLY the renderer wrote: count and sum of L A per channel
 * (0 on a malformed file). */
static size_t read_ply_x(const char *path, double power[3], double *x_max, double back[3]);

static size_t read_ply(const char *path, double power[3])
{
    double x, back[3];
    return read_ply_x(path, power, &x, back);
}

/* The same, the largest x of a disk's centre in *x_max and the sum of
 * back_L A per channel in back. */
static size_t read_ply_x(const char *path, double power[3], double *x_max, double back[3])
{
    FILE *f = fopen(path, "rb");
    char line[256];
    size_t n = 0;
    power[0] = power[1] = power[2] = 0.0;
    back[0] = back[1] = back[2] = 0.0;
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n") != 0)
        sscanf(line, "element vertex %zu", &n);
    for (size_t i = 0; i < n; i++) {
        unsigned char b[52];
        float rec[13];
        if (fread(b, 1, sizeof b, f) != sizeof b) {
            n = 0;
            break;
        }
        for (int k = 0; k < 13; k++) {
            uint32_t u = (uint32_t)b[4 * k] | (uint32_t)b[4 * k + 1] << 8 |
                         (uint32_t)b[4 * k + 2] << 16 | (uint32_t)b[4 * k + 3] << 24;
            memcpy(&rec[k], &u, 4);
        }
        for (int c = 0; c < 3; c++) {
            power[c] += (double)rec[6] * rec[7 + c];
            back[c] += (double)rec[6] * rec[10 + c];
        }
        *x_max = i == 0 ? rec[0] : fmax(*x_max, rec[0]);
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

/* Commits and renders s (16 x 16, preview, point-based GI) to write its
 * cloud to ply, its statistics into *st (st may be NULL); releases s. */
static void write_cloud(RayesScene *s, const char *ply, RayesStats **st)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 1;
    o.threads = 2;
    o.gi = RAYES_GI_POINTBASED;
    o.pointcloud_out = ply;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A 4 x 3 matte plane (Kd 0.6, Cs 1 0.5 0.25) under a distant light of
 * irradiance 2 at 60 degrees, off camera; instanced: an object instanced
 * twice, the second moved 10 along x and stretched 2 times along it.
 * Rendered with point-based GI, its cloud written to ply; its statistics
 * into *st. */
static void render_lit_plane(int instanced, const char *ply, RayesStats **st)
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
    if (instanced) {
        const float moved[16] = {2, 0, 0, 10, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        CHECK(rayes_scene_object_begin(s, "plane") == RAYES_OK);
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
        CHECK(rayes_scene_object_instance(s, "plane") == RAYES_OK);
        CHECK(rayes_scene_set_transform(s, moved) == RAYES_OK);
        CHECK(rayes_scene_object_instance(s, "plane") == RAYES_OK);
    } else {
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    }
    write_cloud(s, ply, st);
}

/* The lit plane's point cloud: its power, sum pi L A, is Kd Cs E A with E
 * = 2 cos 60 = 1 (the plane is off camera: the cloud has it all the
 * same). */
static void test_lit_plane_power(void)
{
    const char *ply = RAYES_TEST_TMP "/test_pbgi_plane.ply";
    RayesStats *st = NULL;
    render_lit_plane(0, ply, &st);
    double power[3];
    size_t n = read_ply(ply, power);
    const RayesStat *pts = st ? rayes_stats_find(st, "pbgi/points") : NULL;
    CHECK(n >= 16 && pts && pts->count == n);
    const double cs[3] = {1.0, 0.5, 0.25};
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(PI * power[c] / (0.6 * cs[c] * 1.0 * 12.0), 1.0, 1e-3);
    rayes_stats_free(st);
}

/* The plane instanced twice: the cloud has both instances' disks, in
 * world space, carrying Kd Cs E times 12 + 24. */
static void test_instances_in_cloud(void)
{
    const char *ply = RAYES_TEST_TMP "/test_pbgi_instances.ply";
    render_lit_plane(1, ply, NULL);
    double power[3], x_max = 0.0, back[3];
    size_t n = read_ply_x(ply, power, &x_max, back);
    CHECK(n >= 32 && n % 2 == 0);
    CHECK(x_max > 13.0 && x_max < 14.0); /* the second instance spans x in [6, 14] */
    const double cs[3] = {1.0, 0.5, 0.25};
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(PI * power[c] / (0.6 * cs[c] * 1.0 * 36.0), 1.0, 1e-3);
}

/* Hair and particles in the cloud: a sphere point of width 0.5 at the
 * origin and a linear round curve of width 0.1 from (-1, 0.3, 0) to (1,
 * 0.3, 0), off camera (the eye at z = 10 looks away), both facing the eye
 * as diced and lit head-on by a distant light of irradiance 2: their disks
 * cover the point's square and the ribbon, 0.25 + 0.2 (to 0.1%), and carry
 * pi L A = Kd E A (Kd 0.6; within 2%) on their front side, none on their
 * back. */
static void test_curves_points(void)
{
    const char *ply = RAYES_TEST_TMP "/test_pbgi_hair.ply";
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, 10}, target[3] = {0, 0, 11}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 40.0f);
    RayesParam light[3] = {pf("intensity", 2.0f), pc("from", 0, 0, 1), pc("to", 0, 0, 0)};
    CHECK(rayes_scene_light(s, "distantlight", light, 3) == RAYES_OK);
    RayesParam m[2] = {pf("Kd", 0.6f), pc("Cs", 1.0f, 1.0f, 1.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 2) == RAYES_OK);
    const float pw = 0.5f, cw = 0.1f, pp[3] = {0, 0, 0}, cp[6] = {-1, 0.3f, 0, 1, 0.3f, 0};
    RayesPrimvar pwv = {"width", RAYES_PRIMVAR_CONSTANT, &pw, 1};
    RayesPrimvar cwv = {"width", RAYES_PRIMVAR_CONSTANT, &cw, 1};
    CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 1, pp, &pwv, 1) == RAYES_OK);
    const int nv = 2;
    RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1, .n_verts = &nv,
                     .P = cp};
    CHECK(rayes_scene_curves(s, &c, &cwv, 1) == RAYES_OK);
    write_cloud(s, ply, NULL);
    double power[3], x_max = 0.0, back[3], area = 0.0;
    size_t n = read_ply_x(ply, power, &x_max, back);
    FILE *f = fopen(ply, "rb");
    char line[256];
    while (f && fgets(line, sizeof line, f) && strcmp(line, "end_header\n") != 0)
        ;
    for (size_t i = 0; f && i < n; i++) {
        float rec[13];
        if (fread(rec, sizeof rec, 1, f) == 1) /* little-endian, like the test machines */
            area += rec[6];
    }
    if (f)
        fclose(f);
    printf("curves and points: %zu disks, area %.5f, pi L A %.4f, back %.4f\n", n, area,
           PI * power[0], PI * back[0]);
    CHECK(n >= 2);
    CHECK_NEAR(area / 0.45, 1.0, 1e-3);
    CHECK_NEAR(PI * power[0] / (0.6 * 2.0 * 0.45), 1.0, 0.02);
    CHECK(back[0] < 1e-3 * power[0]);
}

static RayesImage *render_box_irr(int threads, int bounces, const char *ply, int irradiance,
                                  int scale, uint64_t *gathers)
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
    o.width = 40 * scale;
    o.height = 32 * scale;
    o.spp = 1;
    o.threads = threads;
    o.bounces = bounces;
    o.hider = RAYES_HIDER_GRID;
    o.gi = RAYES_GI_POINTBASED;
    o.pointcloud_out = ply;
    o.irradiance = irradiance;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *g = st ? rayes_stats_find(st, "pbgi/gathers") : NULL;
    if (gathers)
        *gathers = g ? g->count : 0;
    rayes_stats_free(st);
    rayes_scene_release(s);
    return img;
}

static RayesImage *render_box(int threads, int bounces, const char *ply)
{
    return render_box_irr(threads, bounces, ply, 0, 1, NULL);
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

/* A floor whose normals face down (y = 0, x and z in [-2, 2]), lit from
 * above on its back side, and a wall at z = 2 facing the camera, which
 * the light grazes: the wall's light is the floor's bounce. The camera
 * sees the wall alone. Point-based GI's image mean within 8% of the
 * ray-traced one's (256 diffuse rays; measured 3.9% below;
 * before disks had back sides: 0, the floor black in the cloud); the floor
 * carries its light on its back side in the cloud, and the cloud and image
 * are the same bytes on one and two threads. */
static double flipped_floor(int gi, int threads, const char *ply)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 1, -1}, target[3] = {0, 1, 2}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 40.0f);
    RayesParam light[3] = {pf("intensity", 2.0f), pc("from", 0, 10, 0), pc("to", 0, 0, 0)};
    CHECK(rayes_scene_light(s, "distantlight", light, 3) == RAYES_OK);
    RayesParam m[2] = {pf("Kd", 0.8f), pc("Cs", 1.0f, 1.0f, 1.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 2) == RAYES_OK);
    const float floor[4][3] = {{-2, 0, -2}, {2, 0, -2}, {-2, 0, 2}, {2, 0, 2}};
    const float wall[4][3] = {{-2, 0, 2}, {2, 0, 2}, {-2, 2, 2}, {2, 2, 2}};
    CHECK(rayes_scene_bilinear_patch(s, floor) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 1;
    o.threads = threads;
    o.diffuse_rays = 256;
    o.gi = gi ? RAYES_GI_POINTBASED : o.gi;
    o.pointcloud_out = ply;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double mean = image_mean(img);
    rayes_image_free(img);
    rayes_scene_release(s);
    return mean;
}

static void test_flipped_floor(void)
{
    const char *p1 = RAYES_TEST_TMP "/test_pbgi_flip1.ply";
    const char *p2 = RAYES_TEST_TMP "/test_pbgi_flip2.ply";
    double traced = flipped_floor(0, 2, NULL), pb = flipped_floor(1, 1, p1);
    double pb2 = flipped_floor(1, 2, p2);
    CHECK(traced > 0.01);
    CHECK_NEAR(pb / traced, 1.0, 0.08);
    CHECK(pb == pb2 && same_file(p1, p2));
    double power[3], x_max, back[3];
    CHECK(read_ply_x(p1, power, &x_max, back) > 0);
    printf("flipped floor: point-based %.4f, ray-traced %.4f; cloud front %.3f back %.3f\n", pb,
           traced, power[0], back[0]);
    CHECK(back[0] > 10.0 * power[0]); /* the floor's light is behind it */
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

/* Irradiance interpolation over grids with records from gathers (the
 * final preset's) at 80 x 64: fewer gathers (measured 4,814 against 7,037:
 * the grids of so small an image are small, their lattice knots many;
 * 31% at 128 x 128 in bench/figure5), the image within 0.5% (relative
 * RMSE; measured 0.17%) of a gather at every vertex, its mean within
 * 0.3%; the same bytes on one and two threads (at 40 x 32). */
static void test_interpolation(void)
{
    uint64_t g_off = 0, g_on = 0, g_one = 0, g_two = 0;
    RayesImage *off = render_box_irr(2, 1, NULL, 0, 2, &g_off);
    RayesImage *on = render_box_irr(2, 1, NULL, 1, 2, &g_on);
    CHECK(g_on > 0 && g_on < g_off * 4 / 5);
    double se = 0.0, mean = image_mean(off);
    for (int i = 0; off && on && i < off->width * off->height; i++)
        for (int c = 0; c < 3; c++) {
            double d = on->rgba[4 * i + c] - off->rgba[4 * i + c];
            se += d * d;
        }
    double rmse = off && on ? sqrt(se / (3.0 * off->width * off->height)) / mean : 1.0;
    printf("interpolation: %llu gathers (off: %llu), relative RMSE %.3f%%, means %.4f %.4f\n",
           (unsigned long long)g_on, (unsigned long long)g_off, 100 * rmse, image_mean(on), mean);
    CHECK(rmse < 0.005);
    CHECK_NEAR(image_mean(on) / mean, 1.0, 0.003);
    RayesImage *one = render_box_irr(1, 1, NULL, 1, 1, &g_one);
    RayesImage *two = render_box_irr(2, 1, NULL, 1, 1, &g_two);
    CHECK(same_image(one, two));
    CHECK(g_one == g_two);
    rayes_image_free(off);
    rayes_image_free(on);
    rayes_image_free(one);
    rayes_image_free(two);
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

TEST_MAIN(TEST(test_gradients), TEST(test_furnace), TEST(test_furnace_cube), TEST(test_occlusion),
          TEST(test_back_faces_occlude), TEST(test_back_sides), TEST(test_lit_plane_power),
          TEST(test_flipped_floor), TEST(test_curves_points), TEST(test_instances_in_cloud), TEST(test_threads_and_bounces),
          TEST(test_interpolation), TEST(test_bad_options))
