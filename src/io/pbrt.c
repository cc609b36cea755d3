/* io/pbrt.c — placeholder until the pbrt reader lands (see io/pbrt.h). */
#include "io/pbrt.h"

#include <stdio.h>

RayesError io_pbrt_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size)
{
    (void)data, (void)size, (void)sink, (void)options, (void)settings;
    snprintf(err, err_size, "%s: the pbrt reader is not built yet", name);
    return RAYES_ERROR_PARSE;
}

RayesError io_pbrt_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size)
{
    return io_pbrt_parse(path, NULL, 0, sink, options, settings, err, err_size);
}
