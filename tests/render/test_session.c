/*
 * The progressive session (rayes.h): passes accumulate to the image of a
 * one-shot render; edits followed by an update give, bit for bit, the image
 * of a fresh render of the edited scene (so radiosity cached before a light
 * or shader edit is never used after it: memo 3.2's timestamps); a camera
 * move keeps the cached radiosity; cancellation discards the accumulation
 * and leaves the session usable.
 */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#define W 48
#define H 40

static RayesScene *scene(const char *name)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    RayesError e = io_builtin_scene(name, RAYES_TEST_DATA, &sink, err, sizeof err);
    if (e == RAYES_OK)
        e = rayes_scene_commit(s);
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    CHECK(e == RAYES_OK);
    return s;
}

static RayesRenderOptions options(int spp, int threads, RayesFilter filter)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = W;
    o.height = H;
    o.spp = spp;
    o.threads = threads;
    o.tile_size = 16;
    o.filter = filter;
    o.filter_width = filter == RAYES_FILTER_GAUSSIAN ? 2.0f : 1.0f;
    o.bounces = 2;
    return o;
}

static RayesImage *render(RayesScene *s, const RayesRenderOptions *o)
{
    RayesImage *img = NULL;
    CHECK(rayes_render(s, o, &img, NULL) == RAYES_OK);
    return img;
}

static RayesImage *passes(RayesSession *ss, int n)
{
    for (int i = 0; i < n; i++)
        CHECK(rayes_session_render_pass(ss) == RAYES_OK);
    RayesImage *img = NULL;
    CHECK(rayes_session_image(ss, &img) == RAYES_OK);
    return img;
}

static int same(const RayesImage *a, const RayesImage *b)
{
    return a && b && a->width == b->width && a->height == b->height &&
           memcmp(a->rgba, b->rgba, sizeof(float) * 4 * (size_t)a->width * a->height) == 0;
}

static double max_diff(const RayesImage *a, const RayesImage *b)
{
    double m = 0.0;
    for (size_t i = 0; a && b && i < 4 * (size_t)a->width * a->height; i++) {
        double d = a->rgba[i] - b->rgba[i];
        m = d > m ? d : -d > m ? -d : m;
    }
    return m;
}

static double stat(const RayesSession *ss, const char *name)
{
    RayesStats *st = NULL;
    CHECK(rayes_session_stats(ss, &st) == RAYES_OK);
    const RayesStat *x = rayes_stats_find(st, name);
    double v = !x ? -1.0 : x->kind == RAYES_STAT_REAL ? x->real : (double)x->count;
    rayes_stats_free(st);
    return v;
}

/* N passes of one sample are the render of N samples, bit for bit (box
 * filter), whatever the thread counts; with a Gaussian filter, the same
 * sums in another order. */
static void test_passes_equal_render(void)
{
    RayesScene *s = scene("cornell-teapots");
    RayesRenderOptions o = options(4, 2, RAYES_FILTER_BOX), one = options(4, 1, RAYES_FILTER_BOX);
    RayesSession *ss = NULL;
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    RayesImage *a = passes(ss, 4), *b = render(s, &one);
    CHECK(rayes_session_samples(ss) == 4);
    CHECK(same(a, b));
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_session_free(ss);

    o = options(3, 2, RAYES_FILTER_GAUSSIAN);
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    a = passes(ss, 3);
    b = render(s, &o);
    CHECK(max_diff(a, b) < 1e-4);
    rayes_image_free(a);
    /* Passes beyond the pattern keep adding samples (further patterns). */
    RayesImage *c = passes(ss, 2);
    CHECK(rayes_session_samples(ss) == 5);
    CHECK(c && max_diff(c, b) > 0.0);
    rayes_image_free(b);
    rayes_image_free(c);
    rayes_session_free(ss);
    rayes_scene_release(s);
}

typedef void (*EditFn)(RayesScene *s, size_t object);

static void edit_light(RayesScene *s, size_t object)
{
    (void)object;
    RayesParam p[2] = {{"intensity", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL},
                       {"lightcolor", RAYES_PARAM_COLOR, {1.0f, 0.6f, 0.3f}, NULL}};
    CHECK(rayes_scene_edit_light(s, 0, p, 2) == RAYES_OK);
}

static void move_light(RayesScene *s, size_t object)
{
    (void)object;
    RayesParam p = {"translate", RAYES_PARAM_COLOR, {60.0f, 0.0f, -40.0f}, NULL};
    CHECK(rayes_scene_edit_light(s, 0, &p, 1) == RAYES_OK);
}

static void edit_shader(RayesScene *s, size_t object)
{
    RayesParam p[2] = {{"Cs", RAYES_PARAM_COLOR, {0.2f, 0.3f, 0.9f}, NULL},
                       {"Kd", RAYES_PARAM_FLOAT, {0.9f, 0, 0}, NULL}};
    CHECK(rayes_scene_edit_shader(s, object, p, 2) == RAYES_OK);
}

/* A session that rendered the scene before the edit, then the edit, gives
 * the image of a fresh render of the edited scene. */
static void check_edit(EditFn edit, float pick_x, float pick_y)
{
    RayesScene *s = scene("cornell-teapots");
    RayesRenderOptions o = options(4, 2, RAYES_FILTER_BOX);
    RayesSession *ss = NULL;
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    int64_t object = -1;
    float at[3] = {0, 0, 0};
    CHECK(rayes_session_pick(ss, pick_x, pick_y, &object, at) == RAYES_OK);
    CHECK(at[2] > 0.0f && at[2] < 560.0f); /* inside the box */
    CHECK(object >= 0 && rayes_scene_object_shader(s, (size_t)object)[0] != '\0');
    RayesImage *before = passes(ss, 3);
    edit(s, (size_t)object);
    CHECK(rayes_session_render_pass(ss) == RAYES_ERROR_INVALID_OPERATION); /* not committed */
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    CHECK(rayes_session_update(ss) == RAYES_OK);
    CHECK(rayes_session_samples(ss) == 0);
    RayesImage *after = passes(ss, 4);

    RayesScene *fresh = scene("cornell-teapots");
    edit(fresh, (size_t)object);
    CHECK(rayes_scene_commit(fresh) == RAYES_OK);
    RayesImage *want = render(fresh, &o);
    CHECK(same(after, want));
    CHECK(max_diff(before, after) > 0.01);
    rayes_image_free(before);
    rayes_image_free(after);
    rayes_image_free(want);
    rayes_session_free(ss);
    rayes_scene_release(s);
    rayes_scene_release(fresh);
}

static void test_light_edit_equals_fresh_render(void)
{
    check_edit(edit_light, W * 0.5f, H * 0.9f);
}

static void test_shader_edit_equals_fresh_render(void)
{
    check_edit(edit_shader, W * 0.62f, H * 0.72f);
}

static void test_light_move_equals_fresh_render(void)
{
    check_edit(move_light, W * 0.5f, H * 0.9f);
}

/* After a camera move the cached radiosity is still valid: the first pass
 * fills far fewer entries than the first pass after a light edit. */
static void test_camera_move_keeps_cache(void)
{
    RayesScene *s = scene("cornell-teapots");
    RayesRenderOptions o = options(4, 2, RAYES_FILTER_BOX);
    RayesSession *ss = NULL;
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    RayesImage *start = passes(ss, 2);
    double first_fills = stat(ss, "cache/coarse/fills") + stat(ss, "cache/medium/fills") +
                         stat(ss, "cache/fine/fills");
    float eye[3], x[3], y[3], z[3];
    CHECK(rayes_scene_get_camera(s, eye, x, y, z) == RAYES_OK);
    const float shift[16] = {1, 0, 0, 25, 0, 1, 0, 10, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_move_camera(s, shift) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    CHECK(rayes_session_update(ss) == RAYES_OK);
    float eye2[3];
    CHECK(rayes_scene_get_camera(s, eye2, x, y, z) == RAYES_OK);
    CHECK_NEAR(eye2[0], eye[0] + 25.0f, 1e-3);
    RayesImage *moved = passes(ss, 1);
    CHECK(max_diff(start, moved) > 0.01);
    double camera_fills = stat(ss, "cache/coarse/fills") + stat(ss, "cache/medium/fills") +
                          stat(ss, "cache/fine/fills");
    double camera_hits = stat(ss, "cache/coarse/hit_rate");
    edit_light(s, 0);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    CHECK(rayes_session_update(ss) == RAYES_OK);
    RayesImage *lit = passes(ss, 1);
    double light_fills = stat(ss, "cache/coarse/fills") + stat(ss, "cache/medium/fills") +
                         stat(ss, "cache/fine/fills");
    CHECK(first_fills > 0 && light_fills > 0);
    CHECK(camera_fills * 4 < light_fills);
    CHECK(camera_hits > stat(ss, "cache/coarse/hit_rate"));
    rayes_image_free(start);
    rayes_image_free(moved);
    rayes_image_free(lit);
    rayes_session_free(ss);
    rayes_scene_release(s);
}

typedef struct TileCount {
    pthread_mutex_t lock;
    int *hits; /* per pixel */
    int calls;
    RayesSession *cancel; /* cancel on the first tile, if set */
} TileCount;

static void count_tile(void *user, int x, int y, int w, int h, const float *rgba, int stride)
{
    TileCount *t = user;
    (void)rgba;
    pthread_mutex_lock(&t->lock);
    t->calls++;
    for (int j = y; j < y + h; j++)
        for (int i = x; i < x + w; i++)
            t->hits[j * stride + i]++;
    pthread_mutex_unlock(&t->lock);
    if (t->cancel)
        rayes_session_cancel(t->cancel);
}

/* Every pixel is reported once a pass; a cancelled pass returns
 * RAYES_ERROR_CANCELLED, discards the accumulation, and the session goes
 * on to the image of an uncancelled one. */
static void test_tiles_and_cancel(void)
{
    RayesScene *s = scene("cornell");
    TileCount t = {.hits = calloc(W * H, sizeof(int))};
    pthread_mutex_init(&t.lock, NULL);
    RayesRenderOptions o = options(2, 2, RAYES_FILTER_BOX);
    o.tile_done = count_tile;
    o.tile_user = &t;
    o.tile_size = 8;
    RayesSession *ss = NULL;
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    CHECK(rayes_session_render_pass(ss) == RAYES_OK);
    int once = 1;
    for (int i = 0; i < W * H; i++)
        once &= t.hits[i] == 1;
    CHECK(once);
    CHECK(t.calls == ((W + 7) / 8) * ((H + 7) / 8));
    t.cancel = ss;
    CHECK(rayes_session_render_pass(ss) == RAYES_ERROR_CANCELLED);
    CHECK(rayes_session_samples(ss) == 0);
    t.cancel = NULL;
    rayes_session_cancel(ss); /* before a pass: that pass is cancelled */
    CHECK(rayes_session_render_pass(ss) == RAYES_ERROR_CANCELLED);
    RayesImage *a = passes(ss, 2);
    o.tile_done = NULL;
    RayesImage *b = render(s, &o);
    CHECK(same(a, b));
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_session_free(ss);
    pthread_mutex_destroy(&t.lock);
    free(t.hits);
    rayes_scene_release(s);
}

typedef struct Canceller {
    RayesSession *ss;
    int n;
} Canceller;

static void *cancel_often(void *arg)
{
    Canceller *c = arg;
    for (int i = 0; i < c->n; i++) {
        rayes_session_cancel(c->ss);
        struct timespec ts = {0, 2000000};
        nanosleep(&ts, NULL);
    }
    return NULL;
}

/* Another thread cancels while passes run: every pass ends, cancelled or
 * not, and nothing leaks (AddressSanitizer, ThreadSanitizer). */
static void test_cancel_from_another_thread(void)
{
    RayesScene *s = scene("cornell-teapots");
    RayesRenderOptions o = options(4, 2, RAYES_FILTER_BOX);
    RayesSession *ss = NULL;
    CHECK(rayes_session_new(s, &o, &ss) == RAYES_OK);
    Canceller c = {ss, 20};
    pthread_t th;
    pthread_create(&th, NULL, cancel_often, &c);
    int cancelled = 0;
    for (int i = 0; i < 20; i++) {
        RayesError e = rayes_session_render_pass(ss);
        CHECK(e == RAYES_OK || e == RAYES_ERROR_CANCELLED);
        cancelled += e == RAYES_ERROR_CANCELLED;
    }
    pthread_join(th, NULL);
    CHECK(cancelled > 0);
    rayes_session_free(ss);
    rayes_scene_release(s);
}

typedef struct Stopper {
    volatile int flag;
    int after_ms;
} Stopper;

static void *stop_later(void *arg)
{
    Stopper *st = arg;
    struct timespec ts = {st->after_ms / 1000, (long)(st->after_ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
    __atomic_store_n(&st->flag, 1, __ATOMIC_RELAXED);
    return NULL;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* RayesRenderOptions.stop ends a one-shot render within a ray, even in
 * the middle of its only tile (a farm's SIGTERM used to wait for the
 * tile: minutes in a deep interior): RAYES_ERROR_CANCELLED, no tile
 * reported. Set before the render, nothing is traced at all. */
static void test_stop_inside_a_tile(void)
{
    RayesScene *s = scene("cornell-teapots");
    RayesRenderOptions o = options(256, 2, RAYES_FILTER_BOX);
    o.width = o.height = 128;
    o.tile_size = 128; /* one tile, one thread's: about 35 s in a Release build */
    o.bounces = 8;
    o.diffuse_rays = o.diffuse_rays_deep = 16;
    TileCount t = {.hits = calloc(128 * 128, sizeof(int))};
    pthread_mutex_init(&t.lock, NULL);
    o.tile_done = count_tile;
    o.tile_user = &t;
    Stopper st = {0, 300};
    o.stop = &st.flag;
    pthread_t th;
    pthread_create(&th, NULL, stop_later, &st);
    double t0 = now_s();
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_CANCELLED);
    double took = now_s() - t0;
    pthread_join(th, NULL);
    printf("  stopped 0.3 s into a one-tile render: returned after %.2f s\n", took);
    CHECK(took < 10.0); /* the tile alone takes far longer, even on one fast core */
    CHECK(t.calls == 0 && img == NULL);
    rayes_image_free(img);
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_CANCELLED); /* stopped already */
    CHECK(t.calls == 0);
    pthread_mutex_destroy(&t.lock);
    free(t.hits);
    rayes_scene_release(s);
}

static void test_edit_errors(void)
{
    RayesScene *s = scene("cornell-teapots");
    RayesParam bad = {"wattage", RAYES_PARAM_FLOAT, {2, 0, 0}, NULL};
    RayesParam neg = {"intensity", RAYES_PARAM_FLOAT, {-1, 0, 0}, NULL};
    CHECK(rayes_scene_light_count(s) == 1);
    CHECK(rayes_scene_edit_light(s, 1, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no light 1") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_edit_light(s, 0, &bad, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_edit_light(s, 0, &neg, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    size_t n = rayes_scene_object_count(s), light_object = n;
    for (size_t i = 0; i < n; i++)
        if (rayes_scene_object_light(s, i) == 0)
            light_object = i;
    CHECK(light_object < n);
    CHECK(rayes_scene_object_shader(s, light_object)[0] == '\0');
    CHECK(rayes_scene_edit_shader(s, light_object, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_edit_shader(s, n, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_edit_shader(s, 0, &bad, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "wattage") != NULL);
    /* Nothing changed: the scene still renders as committed. */
    RayesRenderOptions o = options(1, 2, RAYES_FILTER_BOX);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_image_free(img);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_passes_equal_render), TEST(test_light_edit_equals_fresh_render),
          TEST(test_shader_edit_equals_fresh_render), TEST(test_light_move_equals_fresh_render),
          TEST(test_camera_move_keeps_cache), TEST(test_tiles_and_cancel),
          TEST(test_cancel_from_another_thread), TEST(test_stop_inside_a_tile),
          TEST(test_edit_errors))
