/* io/obj.c — placeholder until the OBJ reader lands (see io/obj.h). */
#include "io/obj.h"

#include <stdio.h>

RayesError io_obj_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size)
{
    (void)data, (void)size, (void)sink, (void)options, (void)settings;
    snprintf(err, err_size, "%s: the OBJ reader is not built yet", name);
    return RAYES_ERROR_PARSE;
}

RayesError io_obj_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size)
{
    return io_obj_parse(path, NULL, 0, sink, options, settings, err, err_size);
}
