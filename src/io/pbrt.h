/*
 * io/pbrt.h — the pbrt-v4 scene file (.pbrt; PLY meshes through io/ply.h) reader. It drives an IoSink (io/sink.h) and fills
 * the IoSettings the file gives. Bad input: one line
 * "file:line:col: what was expected" in err and a nonzero return.
 */
#ifndef RAYES_IO_PBRT_H
#define RAYES_IO_PBRT_H

#include <stddef.h>

#include "io/sink.h"

/* Reads the file at path into sink. */
RayesError io_pbrt_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size);

/* The same from a buffer (tests, fuzzing); name is used in messages and
 * relative paths (includes, archives, textures) are resolved against its
 * directory. */
RayesError io_pbrt_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size);

#endif
