/* io/rib.c — placeholder until the RIB reader lands (see io/rib.h). */
#include "io/rib.h"

#include <stdio.h>

RayesError io_rib_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size)
{
    (void)data, (void)size, (void)sink, (void)options, (void)settings;
    snprintf(err, err_size, "%s: the RIB reader is not built yet", name);
    return RAYES_ERROR_PARSE;
}

RayesError io_rib_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size)
{
    return io_rib_parse(path, NULL, 0, sink, options, settings, err, err_size);
}
