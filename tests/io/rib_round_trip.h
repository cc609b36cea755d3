/*
 * tests/io/rib_round_trip.h — RIB texts for the tests that read a
 * writer's RIB back (curves, blobbies, solids, area lights): the writer's
 * text for a RIB text, a RIB or pbrt-v4 text read into a new scene, and
 * a RIB text rendered. Header-only.
 */
#ifndef RAYES_TESTS_IO_RIB_ROUND_TRIP_H
#define RAYES_TESTS_IO_RIB_ROUND_TRIP_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt.h"
#include "io/rib.h"
#include "io/rib_write.h"
#include "io/sink.h"
#include "rayes/rayes.h"

typedef RayesError (*SceneParse)(const char *name, const unsigned char *data, size_t size,
                                 const IoSink *sink, const IoReadOptions *options,
                                 IoSettings *settings, char *err, size_t err_size);

/* A new scene (release it) of a text read by parse as file `name`; *e
 * the reader's result, err its message. */
static inline RayesScene *read_scene_text(SceneParse parse, const char *name, const char *text,
                                          RayesError *e, char *err, size_t n)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    err[0] = '\0';
    *e = parse(name, (const unsigned char *)text, strlen(text), &sink, &opt, &settings, err, n);
    return s;
}

/* A RIB text named t.rib, and a pbrt-v4 text named t.pbrt. */
static RayesScene *rib_read_scene(const char *text, RayesError *e, char *err, size_t n)
{
    return read_scene_text(io_rib_parse, "t.rib", text, e, err, n);
}

static inline RayesScene *pbrt_read_scene(const char *text, RayesError *e, char *err, size_t n)
{
    return read_scene_text(io_pbrt_parse, "t.pbrt", text, e, err, n);
}

/* The written RIB (malloc'd; free it), or NULL if reading or writing
 * failed (err says why). */
static char *rib_round_trip(const char *text, char *err, size_t n)
{
    RibWriter *w = io_rib_writer_new();
    if (!w)
        return NULL;
    IoSink sink = io_rib_writer_sink(w);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    char *buf = NULL;
    size_t len = 0;
    FILE *f = NULL;
    if (io_rib_parse("t.rib", (const unsigned char *)text, strlen(text), &sink, &opt, &settings,
                     err, n) == RAYES_OK &&
        (f = open_memstream(&buf, &len)) != NULL &&
        io_rib_writer_finish(w, &settings, f, err, n) != RAYES_OK) {
        fclose(f);
        f = NULL;
        free(buf);
        buf = NULL;
    }
    if (f)
        fclose(f);
    io_rib_writer_free(w);
    return buf;
}

/* A RIB text rendered at size x size with spp pixel samples (preview, no
 * bounces, 2 threads): the image (free it), or NULL, the reader's or the
 * renderer's message on stderr. */
static inline RayesImage *rib_render_text(const char *text, int size, int spp)
{
    RayesError e;
    char err[512];
    RayesScene *s = rib_read_scene(text, &e, err, sizeof err);
    RayesImage *img = NULL;
    if (e != RAYES_OK) {
        fprintf(stderr, "  %s\n", err);
    } else if (rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = size;
        o.spp = spp;
        o.threads = 2;
        o.bounces = 0;
        if (rayes_render(s, &o, &img, NULL) != RAYES_OK)
            fprintf(stderr, "  render: %s\n", rayes_scene_get_error(s));
    }
    rayes_scene_release(s);
    return img;
}

/* The mean of channel c over the middle 2 half x 2 half pixels of a size
 * x size image. */
static inline double rib_image_middle(const RayesImage *img, int size, int half, int c)
{
    double t = 0;
    for (int y = size / 2 - half; y < size / 2 + half; y++)
        for (int x = size / 2 - half; x < size / 2 + half; x++)
            t += img->rgba[4 * (y * size + x) + c];
    return t / (4.0 * half * half);
}

#endif /* RAYES_TESTS_IO_RIB_ROUND_TRIP_H */
