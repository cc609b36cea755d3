/*
 * The radiosity cache in the renderer (render/): interpolation reproduces a
 * linear function exactly at every resolution, for quad grids of every size
 * and triangular grids of every subdivision up to the default gridsize
 * (the coarse level between its inset points and held beyond them; a
 * triangle of one micropolygon's coarse level: its centroid), and
 * of the largest sizes a larger gridsize allows; levels alias as documented;
 * images do not depend on the cache budget (evicted entries refill to the
 * same bytes) nor on threads.
 */
#include <math.h>
#include <string.h>

#include "cache_stats.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "render/radiosity.h"
#include "test.h"
#include "util/half.h"

static float linear(float gu, float gv)
{
    return 2.0f + 3.0f * gu - 1.5f * gv;
}

static int knots(int n)
{
    return (n - 1 + 3) / 4 + 1;
}

static int knot(int k, int n)
{
    return 4 * k < n - 1 ? 4 * k : n - 1;
}

/* The documented layouts (radiosity.c): values of the linear function. */
static size_t quad_values(const Grid *g, int level, uint16_t *v)
{
    int mu = level == CACHE_FINE ? g->nu : level == CACHE_MEDIUM ? knots(g->nu) : 2;
    int mv = level == CACHE_FINE ? g->nv : level == CACHE_MEDIUM ? knots(g->nv) : 2;
    size_t n = 0;
    for (int j = 0; j < mv; j++)
        for (int i = 0; i < mu; i++) {
            int fi = level == CACHE_FINE ? i : knot(i, g->nu);
            int fj = level == CACHE_FINE ? j : knot(j, g->nv);
            float f = linear((float)fi / (g->nu - 1), (float)fj / (g->nv - 1));
            if (level == CACHE_COARSE) /* the quadrants' middles */
                f = linear(i ? 0.75f : 0.25f, j ? 0.75f : 0.25f);
            for (int c = 0; c < 3; c++)
                v[3 * n + c] = half_from_float(f);
            n++;
        }
    return n;
}

static size_t tri_values(const Grid *g, int level, uint16_t *v)
{
    int m = level == CACHE_FINE ? g->nu : level == CACHE_MEDIUM ? (g->nu + 3) / 4 : 1;
    size_t n = 0;
    if (level == CACHE_COARSE && g->nu == 1) { /* one micropolygon: its centroid */
        for (int c = 0; c < 3; c++)
            v[c] = half_from_float(linear(1.0f / 3.0f, 1.0f / 3.0f));
        return 1;
    }
    for (int j = 0; j <= m; j++)
        for (int i = 0; i + j <= m; i++) {
            float f = linear((float)i / m, (float)j / m);
            if (level == CACHE_COARSE) /* the corner triangles' middles */
                f = linear(i ? 2.0f / 3.0f : 1.0f / 6.0f, j ? 2.0f / 3.0f : 1.0f / 6.0f);
            for (int c = 0; c < 3; c++)
                v[3 * n + c] = half_from_float(f);
            n++;
        }
    return n;
}

/* Sides (vertices of a quad grid, subdivisions of a triangular one) up to
 * GEOM_MAX_GRID: every one to 17, then some of gridsize 4096's. */
static int next_side(int n)
{
    return n < 17 ? n + 1 : n < 33 ? 33 : n < 64 ? 64 : n + 1;
}

/* What the coarse level reads at (a, b): the linear function there between
 * its points, and beyond them at the nearest point of their square
 * (triangle: clamped barycentric coordinates). */
static float coarse_want(int tri, float a, float b)
{
    if (!tri)
        return linear(fminf(fmaxf(a, 0.25f), 0.75f), fminf(fmaxf(b, 0.25f), 0.75f));
    float w[3] = {0, fmaxf(2.0f * a - 1.0f / 3.0f, 0.0f), fmaxf(2.0f * b - 1.0f / 3.0f, 0.0f)};
    w[0] = fmaxf(1.0f - (2.0f * a - 1.0f / 3.0f) - (2.0f * b - 1.0f / 3.0f), 0.0f);
    float sum = w[0] + w[1] + w[2];
    return linear((w[0] / 6 + w[1] * 2 / 3 + w[2] / 6) / sum,
                  (w[0] / 6 + w[1] / 6 + w[2] * 2 / 3) / sum);
}

static void test_interpolation_is_exact_for_linear_functions(void)
{
    static uint16_t vals[3 * GEOM_MAX_GRID * GEOM_MAX_GRID];
    int worst_level_checks = 0;
    for (int tri = 0; tri < 2; tri++)
        for (int nu = tri ? 1 : 2; nu <= GEOM_MAX_GRID - tri; nu = next_side(nu))
            for (int nv = tri ? 0 : 2; nv <= (tri ? 0 : GEOM_MAX_GRID); nv = tri ? 1 : next_side(nv)) {
                Grid g = {.nu = (uint16_t)nu, .nv = (uint16_t)nv, .triangular = (uint8_t)tri,
                          .edge = 1.0f};
                for (int requested = 0; requested < 3; requested++) {
                    int level = radiosity_choose_level(&g, 0.0f, 1.0f, requested);
                    if (tri)
                        tri_values(&g, level, vals);
                    else
                        quad_values(&g, level, vals);
                    for (int s = 0; s < 25; s++) {
                        float a = (float)(s % 5) / 4.0f * 0.999f, b = (float)(s / 5) / 4.0f * 0.999f;
                        if (tri && a + b > 1.0f) {
                            a = 1.0f - a;
                            b = 1.0f - b;
                        }
                        Hit h = {.gu = a, .gv = b};
                        Vec3 r = radiosity_interpolate(&g, &h, level, vals);
                        /* Half precision at values around 2..5: 2^-9 relative;
                         * a triangle of one micropolygon's coarse level is
                         * its centroid's value, everywhere. */
                        int centroid = tri && nu == 1 && level == CACHE_COARSE;
                        float want = centroid                ? linear(1.0f / 3.0f, 1.0f / 3.0f)
                                     : level == CACHE_COARSE ? coarse_want(tri, a, b)
                                                             : linear(a, b);
                        CHECK_NEAR(r.x, want, 5e-3);
                        worst_level_checks++;
                    }
                }
            }
    CHECK(worst_level_checks > 1000);
}

static void test_medium_aliasing(void)
{
    Grid small = {.nu = 5, .nv = 5, .edge = 1.0f};  /* knots 0, 4: the corners */
    Grid two = {.nu = 2, .nv = 2, .edge = 1.0f};    /* knots are every vertex */
    Grid big = {.nu = 17, .nv = 12, .edge = 1.0f};
    CHECK(radiosity_choose_level(&small, 0.0f, 1.0f, CACHE_MEDIUM) == CACHE_COARSE);
    CHECK(radiosity_choose_level(&two, 0.0f, 1.0f, CACHE_MEDIUM) == CACHE_FINE);
    CHECK(radiosity_choose_level(&big, 0.0f, 1.0f, CACHE_MEDIUM) == CACHE_MEDIUM);
}

/* The coarsest level whose micropolygon edge is at most k x footprint. */
static void test_level_choice(void)
{
    Grid g = {.nu = 17, .nv = 17, .edge = 1.0f}; /* edges: fine 1, medium 4, coarse 16 */
    CHECK(radiosity_choose_level(&g, 0.5f, 1.0f, -1) == CACHE_FINE);
    CHECK(radiosity_choose_level(&g, 1.0f, 1.0f, -1) == CACHE_FINE);
    CHECK(radiosity_choose_level(&g, 4.0f, 1.0f, -1) == CACHE_MEDIUM);
    CHECK(radiosity_choose_level(&g, 15.9f, 1.0f, -1) == CACHE_MEDIUM);
    CHECK(radiosity_choose_level(&g, 16.0f, 1.0f, -1) == CACHE_COARSE);
    CHECK(radiosity_choose_level(&g, 8.0f, 2.0f, -1) == CACHE_COARSE); /* k scales the rule */
}

/* The benchmark scene, committed. */
static RayesScene *teapots(void)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell-teapots", RAYES_TEST_DATA, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

/* The benchmark box at size x size, one sample, reading the fine level to
 * diffuse depth fine_depth at most; its statistics in *st if st. */
static RayesImage *teapots_render(int size, int bounces, int fine_depth, double cache_mb,
                                  int threads, int cache, RayesStats **st)
{
    RayesScene *s = teapots();
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = size;
    o.spp = 1;
    o.bounces = bounces;
    o.threads = threads;
    o.cache = cache;
    o.cache_mb = cache_mb;
    o.opacity_cache_mb = o.irradiance_cache_mb = 0.0; /* no budget to lend: cache_mb bounds */
    o.env_guide = 0;                                  /* the cache (no environment light) */
    o.cache_fine_depth = fine_depth;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static RayesImage *render(double cache_mb, int threads, int cache)
{
    return teapots_render(40, 2, 1, cache_mb, threads, cache, NULL);
}

static int same(const RayesImage *a, const RayesImage *b)
{
    return a && b && memcmp(a->rgba, b->rgba, sizeof(float) * 4 * (size_t)a->width * a->height) == 0;
}

/* 100 MB holds everything; 0.05 MB evicts constantly; 0 fills privately. */
static void test_same_bytes_for_any_budget_and_threads(void)
{
    RayesImage *ref = render(100, 1, 1);
    const double budgets[] = {0.05, 1e-6, 100}; /* 1 byte: every lookup fills privately */
    const int threads[] = {2, 3, 4};
    for (int i = 0; i < 3; i++) {
        RayesStats *st = NULL;
        RayesImage *img = teapots_render(40, 2, 1, budgets[i], threads[i], 1, &st);
        CHECK(same(ref, img));
        CHECK((test_cache_evictions(st, "radiosity") > 0) == (budgets[i] == 0.05));
        rayes_image_free(img);
        rayes_stats_free(st);
    }
    RayesImage *off = render(100, 2, 0);
    CHECK(!same(ref, off)); /* caching changes the estimate (it is biased) */
    RayesImage *zero = render(0.0, 2, 1); /* a budget of 0 is the cache off */
    CHECK(same(off, zero));
    rayes_image_free(zero);
    rayes_image_free(off);
    rayes_image_free(ref);
}

/* The gridsize option: smaller grids are more grids, every size renders
 * the same picture within the cache's bias, and sizes out of range are
 * refused with a message. */
static void test_grid_size(void)
{
    RayesScene *s = teapots();
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    CHECK(o.grid_size == 256);
    o.width = o.height = 48;
    o.spp = 4;
    o.threads = 2;
    static const int sizes[] = {16, 256, 4096};
    double grids[3] = {0}, mean[3] = {0};
    for (int i = 0; i < 3; i++) {
        o.grid_size = sizes[i];
        RayesImage *img = NULL;
        RayesStats *st = NULL;
        CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
        const RayesStat *g = st ? rayes_stats_find(st, "grids") : NULL;
        const RayesStat *gsz = st ? rayes_stats_find(st, "grid_size") : NULL;
        CHECK(g && gsz && gsz->count == (uint64_t)sizes[i]);
        grids[i] = g ? (double)g->count : 0.0;
        for (size_t k = 0; img && k < (size_t)img->width * img->height; k++)
            mean[i] += img->rgba[4 * k] + img->rgba[4 * k + 1] + img->rgba[4 * k + 2];
        rayes_stats_free(st);
        rayes_image_free(img);
    }
    /* 305, 85, 70 (binary dicing rounds rates to powers of two, so a
     * gridsize of 16 fills its grids more than 256 does: 340 before). */
    CHECK(grids[0] >= 3.5 * grids[1] && grids[1] > grids[2]);
    CHECK(mean[0] > 0.0 && fabs(mean[0] / mean[1] - 1.0) < 0.03);
    CHECK(fabs(mean[2] / mean[1] - 1.0) < 0.03);
    o.grid_size = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT && !img);
    CHECK(strstr(rayes_scene_get_error(s), "grid size must be 1 to 4096") != NULL);
    o.grid_size = 4097;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT && !img);
    rayes_scene_release(s);
}

/* A floor of 80,000 triangles, each below a micropolygon, before a wall
 * the camera sees: the wall's diffuse rays look up the floor's grids of
 * one triangle at the coarse level, their centroids (radiosity.c
 * tri_level_m). Returns the image mean; *depth1 the shading points at
 * diffuse depth 1. */
static double dense_floor(int cache, uint64_t *depth1)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1, -3}, at[3] = {0, 1, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    RayesParam dl[2] = {{"intensity", RAYES_PARAM_FLOAT, {3.0f, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0.2f, -1.0f, 0.4f}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", dl, 2) == RAYES_OK);
    const float wall[4][3] = {{-3, 0, 1}, {3, 0, 1}, {-3, 3, 1}, {3, 3, 1}};
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    enum { N = 200, M = N + 1 };
    static float P[3 * M * M];
    static int nv[2 * N * N], idx[6 * N * N];
    for (int j = 0; j < M; j++)
        for (int i = 0; i < M; i++) {
            float *p = &P[3 * (j * M + i)];
            p[0] = -3.0f + 6.0f * i / N, p[1] = 0.0f, p[2] = -3.0f + 4.0f * j / N;
        }
    test_lattice_triangles(N, nv, idx);
    const float red[3] = {0.9f, 0.2f, 0.1f};
    RayesParam cs = {"Cs", RAYES_PARAM_COLOR, {red[0], red[1], red[2]}, NULL};
    CHECK(rayes_scene_set_shader(s, "matte", &cs, 1) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, 2 * N * N, nv, idx, M * M, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 48;
    o.spp = 4;
    o.threads = 2;
    o.cache = cache;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *d = st ? rayes_stats_find(st, "shading_points/by_depth") : NULL;
    *depth1 = d && d->n_counts > 1 ? d->counts[1] : 0;
    double mean = 0.0;
    for (int i = 0; img && i < img->width * img->height; i++)
        mean += img->rgba[4 * i] / (double)(img->width * img->height);
    rayes_image_free(img);
    rayes_stats_free(st);
    rayes_scene_release(s);
    return mean;
}

/* Cached, the floor's coarse lookups shade one point per miss, as many as
 * the uncached render (its corners made three times as many), and the
 * red bounced onto the wall is the same within noise. */
static void test_dense_mesh_coarse_level(void)
{
    uint64_t on, off;
    double mean_on = dense_floor(1, &on), mean_off = dense_floor(0, &off);
    CHECK(off > 1000);
    CHECK(on <= off + off / 10);
    CHECK(fabs(mean_on - mean_off) < 0.02 * mean_off);
}

/* The room's camera inside it, a point light near its centre and matte
 * walls of opacity os; geometry to be added. */
static RayesScene *room_begin(float os)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0.8f, 0.3f, -0.9f}, at[3] = {-1, -0.2f, 1}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 70.0f) == RAYES_OK);
    RayesParam light[2] = {{"intensity", RAYES_PARAM_FLOAT, {1.0f, 0, 0}, NULL},
                           {"from", RAYES_PARAM_COLOR, {0.3f, 0.5f, 0.2f}, NULL}};
    CHECK(rayes_scene_light(s, "pointlight", light, 2) == RAYES_OK);
    RayesParam kd[2] = {{"Kd", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL},
                        {"Os", RAYES_PARAM_COLOR, {os, os, os}, NULL}};
    CHECK(rayes_scene_set_shader(s, "matte", kd, 2) == RAYES_OK);
    return s;
}

/* Commits s and renders it at 40 x 40, 4 samples, 3 bounces; releases s. */
static RayesImage *room_render(RayesScene *s, int cache, int threads, double mb, RayesStats **st)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 40;
    o.spp = 4;
    o.threads = threads;
    o.bounces = 3;
    o.cache = cache;
    o.cache_mb = mb;
    if (mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.opacity_cache_mb = o.irradiance_cache_mb = 0.0, o.env_guide = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

/* A wall of 2 x 40 x 40 triangles: the plane x_a = side over [-1, 1] in
 * the other two axes (b = a + 1 along the lattice's rows, c = a + 2). */
enum { ROOM_N = 40, ROOM_M = ROOM_N + 1, ROOM_F = 2 * ROOM_N * ROOM_N };

static void room_wall(RayesScene *s, int a, float side)
{
    static float P[3 * ROOM_M * ROOM_M];
    static int nv[ROOM_F], idx[3 * ROOM_F];
    int b = (a + 1) % 3, c = (a + 2) % 3;
    test_lattice_triangles(ROOM_N, nv, idx);
    for (int j = 0; j < ROOM_M; j++)
        for (int i = 0; i < ROOM_M; i++) {
            float *p = &P[3 * (j * ROOM_M + i)];
            p[a] = side;
            p[b] = -1.0f + 2.0f * i / ROOM_N;
            p[c] = -1.0f + 2.0f * j / ROOM_N;
        }
    CHECK(rayes_scene_polygon_mesh(s, ROOM_F, nv, idx, ROOM_M * ROOM_M, P) == RAYES_OK);
}

/* A closed box [-1, 1]^3 of six walls of 2 x 40 x 40 triangles each, below
 * a micropolygon, lit by a point light near its centre, seen from inside;
 * 3 bounces. Its statistics in *st. */
static RayesImage *dense_room_os(int cache, int threads, double mb, float os, RayesStats **st)
{
    RayesScene *s = room_begin(os);
    for (int w = 0; w < 6; w++) /* wall at x_a = +-1 */
        room_wall(s, w / 2, w % 2 ? 1.0f : -1.0f);
    return room_render(s, cache, threads, mb, st);
}

static RayesImage *dense_room(int cache, int threads, double mb, RayesStats **st)
{
    return dense_room_os(cache, threads, mb, 1.0f, st);
}

/* The same room with its six walls instances of one master wall (each
 * instance its own cache entries, memo 3.1). */
static RayesImage *dense_room_instanced(int threads, double mb, RayesStats **st)
{
    RayesScene *s = room_begin(1.0f);
    CHECK(rayes_scene_object_begin(s, "wall") == RAYES_OK);
    room_wall(s, 2, 0.0f);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
    for (int w = 0; w < 6; w++) { /* the master's x, y, z to world axes b, c, a; at x_a = +-1 */
        int a = w / 2, b = (a + 1) % 3, c = (a + 2) % 3;
        float m[16] = {0};
        for (int r = 0; r < 3; r++)
            m[4 * r] = r == b, m[4 * r + 1] = r == c, m[4 * r + 2] = r == a,
                  m[4 * r + 3] = r == a ? (w % 2 ? 1.0f : -1.0f) : 0.0f;
        m[15] = 1.0f;
        CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
        CHECK(rayes_scene_object_instance(s, "wall") == RAYES_OK);
    }
    return room_render(s, 1, threads, mb, st);
}

static double image_mean(const RayesImage *img)
{
    double sum = 0.0;
    for (size_t k = 0; img && k < (size_t)img->width * img->height; k++)
        sum += img->rgba[4 * k] + img->rgba[4 * k + 1] + img->rgba[4 * k + 2];
    return img ? sum / (3.0 * img->width * img->height) : 0.0;
}

static uint64_t count(const RayesStats *st, const char *name, int i)
{
    const RayesStat *x = st ? rayes_stats_find(st, name) : NULL;
    if (!x)
        return 0;
    return x->kind == RAYES_STAT_COUNTS ? (i < (int)x->n_counts ? x->counts[i] : 0) : x->count;
}

/* Diffuse rays wider than a face read one value for a cluster of faces
 * (geom/cluster.c): the shading points at depths 2 and 3 drop far below
 * the uncached render's (they grew past them, about 4 a lookup, with one
 * entry per face), the mean stays within noise, and the bytes do not
 * depend on threads or on a budget that evicts. */
static void test_dense_room_clusters(void)
{
    RayesStats *on = NULL, *off = NULL;
    RayesImage *a = dense_room(1, 2, 100, &on), *b = dense_room(0, 2, 100, &off);
    CHECK(count(on, "clusters/count", 0) > 6 * 2 * 40 * 40 / 256);
    CHECK(count(on, "clusters/lookups", 0) > 1000);
    uint64_t deep_on =
        count(on, "shading_points/by_depth", 2) + count(on, "shading_points/by_depth", 3);
    uint64_t deep_off =
        count(off, "shading_points/by_depth", 2) + count(off, "shading_points/by_depth", 3);
    CHECK(deep_off > 1000 && deep_on < deep_off / 3);
    double m_on = image_mean(a), m_off = image_mean(b);
    CHECK(m_off > 0.0 && fabs(m_on / m_off - 1.0) < 0.03);
    RayesStats *tiny = NULL;
    RayesImage *c = dense_room(1, 1, 0.05, &tiny);
    CHECK(same(a, c));
    CHECK(test_cache_evictions(on, "radiosity") == 0 &&
          test_cache_evictions(tiny, "radiosity") > 0);
    rayes_stats_free(tiny);
    /* Partly transparent walls keep their own levels: a cluster's one
     * value, premultiplied by one member's opacity, would not do for a
     * cut-out's holes. */
    RayesStats *see = NULL;
    rayes_image_free(dense_room_os(1, 2, 100, 0.99f, &see));
    CHECK(count(see, "clusters/count", 0) > 0 && count(see, "clusters/lookups", 0) == 0);
    rayes_stats_free(see);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
    rayes_stats_free(on);
    rayes_stats_free(off);
}

/* Clusters of a master's grids serve each instance apart: the instanced
 * room reads clusters, keeps the plain room's mean within noise, and its
 * bytes do not depend on threads or on a budget that evicts. */
static void test_clusters_through_instances(void)
{
    RayesStats *st = NULL;
    RayesImage *a = dense_room_instanced(2, 100, &st), *plain = dense_room(0, 2, 100, NULL);
    CHECK(count(st, "clusters/count", 0) > 2 * 40 * 40 / 256);
    CHECK(count(st, "clusters/lookups", 0) > 1000);
    CHECK(count(st, "instances/count", 0) == 6);
    double m = image_mean(a), m_plain = image_mean(plain);
    CHECK(m_plain > 0.0 && fabs(m / m_plain - 1.0) < 0.03);
    RayesStats *tiny = NULL;
    RayesImage *b = dense_room_instanced(1, 0.05, &tiny);
    CHECK(same(a, b));
    CHECK(test_cache_evictions(tiny, "radiosity") > 0);
    rayes_stats_free(tiny);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(plain);
    rayes_stats_free(st);
}

/* The benchmark box at 3 bounces, 32 x 32. */
static RayesImage *teapots_deep(int fine_depth, int threads, RayesStats **st)
{
    return teapots_render(32, 3, fine_depth, 100, threads, 1, st);
}

/* Past the first bounce no hit reads the fine level (radiosity.c): the
 * fills of the second and third bounces shade fewer points than with the
 * fine level to any depth (near the teapots' contacts with the floor, short
 * rays ask for it), the image mean stays within the cache's bias, and the
 * bytes do not depend on threads; out of range is refused. */
static void test_fine_depth(void)
{
    RayesStats *lim = NULL, *all = NULL;
    RayesImage *a = teapots_deep(1, 2, &lim), *b = teapots_deep(128, 2, &all);
    uint64_t deep_lim =
        count(lim, "shading_points/by_depth", 2) + count(lim, "shading_points/by_depth", 3);
    uint64_t deep_all =
        count(all, "shading_points/by_depth", 2) + count(all, "shading_points/by_depth", 3);
    CHECK(count(lim, "shading_points/by_depth", 1) == count(all, "shading_points/by_depth", 1));
    CHECK(deep_all > 1000 && deep_lim < deep_all * 3 / 4);
    double m = image_mean(a), m_all = image_mean(b);
    CHECK(m_all > 0.0 && fabs(m / m_all - 1.0) < 0.02);
    RayesImage *c = teapots_deep(1, 1, NULL);
    CHECK(same(a, c));
    RayesScene *s = teapots();
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.cache_fine_depth = 129;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT && !img);
    CHECK(strstr(rayes_scene_get_error(s), "fine depth 0 to 128") != NULL);
    rayes_scene_release(s);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
    rayes_stats_free(lim);
    rayes_stats_free(all);
}

TEST_MAIN(TEST(test_interpolation_is_exact_for_linear_functions), TEST(test_medium_aliasing),
          TEST(test_level_choice), TEST(test_same_bytes_for_any_budget_and_threads),
          TEST(test_grid_size), TEST(test_dense_mesh_coarse_level), TEST(test_dense_room_clusters),
          TEST(test_clusters_through_instances), TEST(test_fine_depth))
