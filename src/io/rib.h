/*
 * io/rib.h — the RIB (ASCII or binary, plain or gzip-compressed; .rib, .rib.gz) reader. It drives an IoSink (io/sink.h) and fills
 * the IoSettings the file gives. Bad input: one line
 * "file:line:col: what was expected" in err and a nonzero return.
 */
#ifndef RAYES_IO_RIB_H
#define RAYES_IO_RIB_H

#include <stddef.h>

#include "io/sink.h"

/* Reads the file at path into sink. */
RayesError io_rib_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size);

/* The same from a buffer (tests, fuzzing); name is used in messages and
 * relative paths (includes, archives, textures) are resolved against its
 * directory. */
RayesError io_rib_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size);

#endif
