/*
 * io/builtin.h — the built-in scenes, sent to an IoSink (io/sink.h) like any
 * scene file, so they can be rendered (io_sink_scene) or written as RIB
 * (`rayes convert`): "cornell" (the classic Cornell box with its two blocks; the
 * default), "cornell-teapots" (the memo's benchmark box, with the Utah
 * teapot read from data_dir/teapot.bpt), "cornell-teapots-displaced" (the
 * same with the memo's fractal displacement on the matte teapot), specified
 * in ../shared/data, "cornell-spheres" (the box with a sphere per built-in
 * shader) and "cornell-brick" (the classic box with a back wall shaded by
 * the example plugin brick, found on the scene's shader search path).
 */
#ifndef RAYES_IO_BUILTIN_H
#define RAYES_IO_BUILTIN_H

#include <stddef.h>

#include "io/sink.h"

/* Sends the named scene to sink (for a RayesScene: an empty one; the caller
 * commits it). data_dir may be
 * NULL if the scene needs no data. Errors fill err (one line) and return
 * nonzero: an unknown name is RAYES_ERROR_INVALID_ARGUMENT, missing data
 * (teapot.bpt, or a plugin not on the shader search path) RAYES_ERROR_IO. */
RayesError io_builtin_scene(const char *name, const char *data_dir, const IoSink *sink, char *err,
                            size_t err_size);

/* "production-room" (builtin_room.c): the furnished interior of the
 * production benchmark (bench/production), 20 lights, textures made at
 * build time into $TMPDIR/rayes-production-room-N. */
RayesError io_builtin_production_room(const IoSink *sink, char *err, size_t err_size);

/* The names, NULL-terminated. */
extern const char *const io_builtin_scene_names[];

#endif /* RAYES_IO_BUILTIN_H */
