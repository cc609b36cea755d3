/* io/scene_file.c — see scene_file.h. */
#include "io/scene_file.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "io/obj.h"
#include "io/pbrt.h"
#include "io/rib.h"

typedef RayesError (*ReadFn)(const char *, const IoSink *, const IoReadOptions *, IoSettings *,
                             char *, size_t);

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcasecmp(s + n - k, suffix) == 0;
}

static ReadFn reader_of(const char *path)
{
    if (ends_with(path, ".rib") || ends_with(path, ".rib.gz"))
        return io_rib_read;
    if (ends_with(path, ".pbrt"))
        return io_pbrt_read;
    if (ends_with(path, ".obj"))
        return io_obj_read;
    return NULL;
}

int io_is_scene_file(const char *path)
{
    return reader_of(path) != NULL;
}

RayesError io_read_scene_file(const char *path, const IoSink *sink, const IoReadOptions *options,
                              IoSettings *settings, char *err, size_t err_size)
{
    ReadFn read = reader_of(path);
    if (!read) {
        snprintf(err, err_size, "%s: unknown scene file type (expected .rib, .rib.gz, .pbrt, .obj)",
                 path);
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    return read(path, sink, options, settings, err, err_size);
}
