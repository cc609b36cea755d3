/*
 * Depth of field (a thin lens, DESIGN.md "Motion blur and depth of field"):
 * the edge of a plane at the focal distance stays sharp; the edge of one
 * far behind is blurred by the analytic circle of confusion (a uniform
 * disk); defocused camera rays have wider footprints, so their diffuse
 * hits read coarser cache resolutions, without visible bias against the
 * uncached render; the lens samples are deterministic across threads.
 */
#include <math.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#define W 128
#define FOV 40.0f
#define FOCUS 10.0f
#define LENS 0.5f

/* A constant-shaded half plane x < 0 at depth z, seen by a camera at the
 * origin looking along +z through a lens focused at FOCUS. */
static RayesImage *half_plane_ff(float z, int threads, float focusfactor, uint64_t *verts)
{
    RayesScene *s = rayes_scene_new();
    const float cam[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_camera_matrix(s, cam, RAYES_PROJECTION_PERSPECTIVE, FOV, NULL) ==
          RAYES_OK);
    CHECK(rayes_scene_set_depth_of_field(s, LENS, FOCUS) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "constant", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_dice_blur(s, 0, focusfactor) == RAYES_OK);
    float big = z; /* beyond the 40 degree view */
    float P[4][3] = {{-big, -big, z}, {0, -big, z}, {-big, big, z}, {0, big, z}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = W, o.spp = 64, o.threads = threads, o.bounces = 0;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *v = rayes_stats_find(st, "grid_vertices");
    if (verts)
        *verts = v ? v->count : 0;
    rayes_stats_free(st);
    rayes_scene_release(s);
    return img;
}

static RayesImage *half_plane(float z, int threads)
{
    return half_plane_ff(z, threads, 0, NULL);
}

/* Mean alpha of column x over all rows. */
static double column(const RayesImage *img, int x)
{
    double sum = 0;
    for (int y = 0; y < W; y++)
        sum += img->rgba[4 * ((size_t)y * W + x) + 3];
    return sum / W;
}

/* The share of a disk of radius r centred at x (pixels from the edge, the
 * covered side negative) on the covered side. */
static double disk_cover(double x, double r)
{
    if (r <= 0)
        return x < 0 ? 1 : 0;
    if (x <= -r)
        return 1;
    if (x >= r)
        return 0;
    return (r * r * acos(x / r) - x * sqrt(r * r - x * x)) / (M_PI * r * r);
}

/* The worst difference between the rendered edge profile and a disk of
 * diameter coc pixels (box-filtered over each pixel); the 10-90% width. */
static double edge_error(const RayesImage *img, double coc, double *width)
{
    double worst = 0, lo = -1, hi = -1;
    for (int x = 0; x < W; x++) {
        double want = 0;
        for (int k = 0; k < 16; k++)
            want += disk_cover(x + (k + 0.5) / 16 - W / 2.0, coc / 2) / 16;
        double got = column(img, x);
        worst = fmax(worst, fabs(got - want));
        if (got < 0.9 && lo < 0)
            lo = x;
        if (got < 0.1 && hi < 0)
            hi = x;
    }
    *width = hi - lo;
    return worst;
}

static void test_focus_and_circle_of_confusion(void)
{
    double pixel = FOCUS * tan(FOV / 2 * M_PI / 180) * 2 / W; /* on the focal plane */
    RayesImage *sharp = half_plane(FOCUS, 2), *far = half_plane(3 * FOCUS, 2);
    double z = 3 * FOCUS, coc = 2 * LENS * (z - FOCUS) / z / pixel, w_sharp, w_far;
    double e_sharp = edge_error(sharp, 0, &w_sharp), e_far = edge_error(far, coc, &w_far);
    CHECK(e_sharp < 0.02);
    CHECK(w_sharp <= 1);
    CHECK(e_far < 0.02);
    /* a disk's 10-90% width is 0.6 of its diameter */
    CHECK(w_far > 0.5 * coc && w_far < 0.8 * coc);
    printf("  in focus: edge within %.3f of a step, 10-90%% width %.0f px; behind: circle of "
           "confusion %.1f px, profile within %.3f, width %.0f px\n",
           e_sharp, w_sharp, coc, e_far, w_far);
    RayesImage *again = half_plane(3 * FOCUS, 1);
    CHECK(again && far && memcmp(again->rgba, far->rgba, 4 * W * W * sizeof(float)) == 0);
    rayes_image_free(sharp);
    rayes_image_free(far);
    rayes_image_free(again);
}

/* The Cornell box focused 300 mm in front of the eye (everything in the
 * box far out of focus) or through a pinhole. */
static RayesImage *box(float lens, int cache, RayesStats **stats)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_set_depth_of_field(s, lens, 300.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 128, o.spp = 16, o.threads = 2, o.bounces = 1, o.diffuse_rays = 16;
    o.cache = cache;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static double share_coarse(const RayesStats *st)
{
    const RayesStat *c = rayes_stats_find(st, "cache/coarse/lookups");
    const RayesStat *m = rayes_stats_find(st, "cache/medium/lookups");
    const RayesStat *f = rayes_stats_find(st, "cache/fine/lookups");
    CHECK(c && m && f);
    double n = c && m && f ? (double)(c->count + m->count + f->count) : 0;
    return n > 0 ? (double)c->count / n : 0;
}

static double tile_mean(const RayesImage *img, int x0, int y0, int size)
{
    double sum = 0.0;
    for (int y = y0; y < y0 + size; y++)
        for (int x = x0; x < x0 + size; x++)
            for (int c = 0; c < 3; c++)
                sum += img->rgba[4 * ((size_t)y * img->width + x) + c];
    return sum / (3.0 * size * size);
}

static void test_defocus_reads_coarser(void)
{
    RayesStats *sp = NULL, *sd = NULL;
    RayesImage *pin = box(0.0f, 1, &sp), *dof = box(8.0f, 1, &sd), *ref = box(8.0f, 0, NULL);
    double cp = share_coarse(sp), cd = share_coarse(sd);
    CHECK(cd > 1.15 * cp); /* 8.5% -> 10.9% at 16 spp */
    printf("  coarse share of cache lookups: pinhole %.1f%%, defocused %.1f%%\n", 100 * cp,
           100 * cd);
    if (getenv("RAYES_TEST_VERBOSE")) {
        RayesImage *pref = box(0.0f, 0, NULL);
        for (int y = 0; y < 128; y += 32)
            for (int x = 0; x < 128; x += 32) {
                double ta = tile_mean(pin, x, y, 32), tb = tile_mean(pref, x, y, 32);
                printf("  pinhole tile %d %d: %.4f %.4f %+.2f%%\n", x, y, ta, tb,
                       100 * (ta - tb) / tb);
            }
        rayes_image_free(pref);
    }
    if (dof && ref) {
        double ma = tile_mean(dof, 0, 0, 128), mb = tile_mean(ref, 0, 0, 128), worst = 0;
        for (int y = 0; y < 128; y += 32)
            for (int x = 0; x < 128; x += 32) {
                double ta = tile_mean(dof, x, y, 32), tb = tile_mean(ref, x, y, 32);
                if (tb > 0.05 * mb)
                    worst = fmax(worst, fabs(ta - tb) / tb);
                if (getenv("RAYES_TEST_VERBOSE"))
                    printf("  tile %d %d: %.4f %.4f %+.2f%%\n", x, y, ta, tb, 100 * (ta - tb) / tb);
            }
        CHECK(fabs(ma - mb) < 0.01 * mb);
        CHECK(worst < 0.03);
        printf("  defocused, cached vs uncached: means %.5f %.5f, worst tile %.2f%%\n", ma, mb,
               100 * worst);
    }
    rayes_stats_free(sp);
    rayes_stats_free(sd);
    rayes_image_free(pin);
    rayes_image_free(dof);
    rayes_image_free(ref);
}

/* Attribute "dice" "focusfactor": the plane behind, blurred over 11.7
 * pixels, is diced with edges 1 + 2 x 10.5 / 16 = 2.3 times longer (10.5
 * pixels: the blur at the plane's centre, further from the eye), and its
 * edge profile still follows the circle of confusion. (With a factor of
 * 1, edges 1.65 times longer, binary dicing's powers of two save only 3%
 * here.) */
static void test_focusfactor(void)
{
    double pixel = FOCUS * tan(FOV / 2 * M_PI / 180) * 2 / W, z = 3 * FOCUS;
    double coc = 2 * LENS * (z - FOCUS) / z / pixel, w;
    uint64_t v0, v1;
    RayesImage *a = half_plane_ff(3 * FOCUS, 2, 0, &v0), *b = half_plane_ff(3 * FOCUS, 2, 2, &v1);
    CHECK(v1 * 2 < v0);
    CHECK(edge_error(b, coc, &w) < 0.02);
    printf("  focusfactor 2: %llu grid vertices instead of %llu\n", (unsigned long long)v1,
           (unsigned long long)v0);
    rayes_image_free(a);
    rayes_image_free(b);
}

TEST_MAIN(TEST_THREADS(test_focus_and_circle_of_confusion), TEST(test_focusfactor),
          TEST(test_defocus_reads_coarser))
