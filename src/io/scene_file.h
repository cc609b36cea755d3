/*
 * io/scene_file.h — reading a scene file by its name: .rib and .rib.gz
 * (io/rib.h), .pbrt (io/pbrt.h), .obj (io/obj.h).
 */
#ifndef RAYES_IO_SCENE_FILE_H
#define RAYES_IO_SCENE_FILE_H

#include <stddef.h>

#include "io/sink.h"

/* Nonzero if path names a scene file of a format rayes reads (by its
 * extension, case-insensitive). */
int io_is_scene_file(const char *path);

/* Reads path with the reader its extension names. Errors as the readers'. */
RayesError io_read_scene_file(const char *path, const IoSink *sink, const IoReadOptions *options,
                              IoSettings *settings, char *err, size_t err_size);

#endif
