/*
 * The built-in scene production-room (io/builtin_room.c; issue 21's
 * production benchmark): it builds with its 20 lights and its texture
 * maps; a small render is deterministic (1 and 2 threads, a cache budget
 * far too small for it: the same bytes) and uses every kind of ray; and
 * the scene written as RIB (the RIB writer sink, what `rayes convert`
 * does) and read back renders the same bytes.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io/builtin.h"
#include "io/rib_write.h"
#include "io/scene_file.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#ifndef RAYES_TEST_TMP
#error "RAYES_TEST_TMP must name a scratch directory"
#endif

enum { W = 64, H = 36 };

static RayesScene *built(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(s != NULL);
    IoSink sink = io_sink_scene(s);
    char err[1024];
    RayesError e = io_builtin_scene("production-room", NULL, &sink, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    CHECK(e == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

/* A small render: its pixels (free them), and the stats' counts wanted
 * (rays by type, grids, radiosity evictions). The other data types get no
 * budget, so that cache_mb bounds the cache (types lend theirs). */
static float *render(RayesScene *s, int threads, double cache_mb, unsigned long long counts[5])
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = W;
    o.height = H;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 1;
    o.cache_mb = cache_mb;
    o.opacity_cache_mb = o.irradiance_cache_mb = 0.0;
    o.env_guide = 0;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    if (!img || !st)
        return NULL;
    static const char *const names[5] = {"rays/shadow", "rays/diffuse", "rays/specular", "grids",
                                         "cache/radiosity/fine/evictions"};
    for (int k = 0; counts && k < 5; k++) {
        const RayesStat *x = rayes_stats_find(st, names[k]);
        counts[k] = x ? x->count : 0;
    }
    float *px = img->rgba;
    img->rgba = NULL;
    rayes_image_free(img);
    rayes_stats_free(st);
    return px;
}

static int same(const float *a, const float *b)
{
    return a && b && memcmp(a, b, sizeof(float) * 4 * W * H) == 0;
}

static void test_builds_with_twenty_lights(void)
{
    RayesScene *s = built();
    CHECK(rayes_scene_light_count(s) == 20);
    CHECK(rayes_scene_object_count(s) >= 100); /* one per shader set: books, furniture... */
    /* the texture maps it made */
    const char *tmp = getenv("TMPDIR");
    static const char *const maps[4] = {"wallpaper.png", "plaster.png", "painting.png", "sky.png"};
    for (int k = 0; k < 4; k++) {
        char path[1100];
        struct stat st;
        snprintf(path, sizeof path, "%s/rayes-production-room-1/%s", tmp && tmp[0] ? tmp : "/tmp",
                 maps[k]);
        CHECK(stat(path, &st) == 0 && st.st_size > 1000);
    }
    rayes_scene_release(s);
}

static void test_render_is_deterministic(void)
{
    RayesScene *s = built();
    unsigned long long c[5] = {0}, t[5] = {0};
    float *two = render(s, 2, 100.0, c);
    float *one = render(s, 1, 100.0, NULL);
    float *tiny = render(s, 2, 0.02, t); /* 20 kB: entries evicted and filled again */
    CHECK(same(two, one));
    CHECK(same(two, tiny));
    CHECK(c[0] > 0 && c[1] > 0 && c[2] > 0 && c[3] > 500);
    CHECK(c[4] == 0 && t[4] > 0);
    /* not black: the room is lit */
    double sum = 0.0;
    for (int i = 0; two && i < W * H; i++)
        sum += two[4 * i] + two[4 * i + 1] + two[4 * i + 2];
    CHECK(sum / (3.0 * W * H) > 0.05);
    free(two);
    free(one);
    free(tiny);
    rayes_scene_release(s);
}

static void test_rib_renders_the_same(void)
{
    const char *path = RAYES_TEST_TMP "/production-room.rib";
    RibWriter *w = io_rib_writer_new();
    CHECK(w != NULL);
    IoSink k = io_rib_writer_sink(w);
    char err[1024];
    CHECK(io_builtin_scene("production-room", NULL, &k, err, sizeof err) == RAYES_OK);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    CHECK(io_rib_writer_finish(w, NULL, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    io_rib_writer_free(w);

    RayesScene *from_rib = rayes_scene_new();
    IoSink sink = io_sink_scene(from_rib);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions ro = {.data_dir = NULL, .frame = -1};
    RayesError e = io_read_scene_file(path, &sink, &ro, &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    CHECK(e == RAYES_OK);
    CHECK(rayes_scene_commit(from_rib) == RAYES_OK);
    CHECK(rayes_scene_light_count(from_rib) == 20);
    RayesScene *s = built();
    float *a = render(s, 2, 100.0, NULL), *b = render(from_rib, 2, 100.0, NULL);
    CHECK(same(a, b));
    free(a);
    free(b);
    rayes_scene_release(s);
    rayes_scene_release(from_rib);
    remove(path);
}

TEST_MAIN(TEST(test_builds_with_twenty_lights), TEST(test_render_is_deterministic),
          TEST(test_rib_renders_the_same))
