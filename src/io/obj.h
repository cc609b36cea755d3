/*
 * io/obj.h — the Wavefront OBJ with its MTL material libraries (.obj) reader. It drives an IoSink (io/sink.h) and fills
 * the IoSettings the file gives. Bad input: one line
 * "file:line:col: what was expected" in err and a nonzero return.
 */
#ifndef RAYES_IO_OBJ_H
#define RAYES_IO_OBJ_H

#include <stddef.h>

#include "io/sink.h"

/* Reads the file at path into sink. */
RayesError io_obj_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size);

/* The same from a buffer (tests, fuzzing); name is used in messages and
 * relative paths (includes, archives, textures) are resolved against its
 * directory. */
RayesError io_obj_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size);

#endif
