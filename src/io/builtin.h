/*
 * io/builtin.h — the built-in scenes, built through rayes.h like any scene
 * file: "cornell" (the classic Cornell box with its two blocks; the
 * default), "cornell-teapots" (the memo's benchmark box, with the Utah
 * teapot read from data_dir/teapot.bpt), "cornell-teapots-displaced" (the
 * same with the memo's fractal displacement on the matte teapot), specified
 * in ../shared/data, and "cornell-brick" (the classic box with a back wall
 * shaded by the example plugin brick, found on the scene's shader search
 * path).
 */
#ifndef RAYES_IO_BUILTIN_H
#define RAYES_IO_BUILTIN_H

#include <stddef.h>

#include "rayes/rayes.h"

/* Adds the named scene to an empty scene and commits it. data_dir may be
 * NULL if the scene needs no data. Errors fill err (one line) and return
 * nonzero: an unknown name is RAYES_ERROR_INVALID_ARGUMENT, missing data
 * (teapot.bpt, or a plugin not on the shader search path) RAYES_ERROR_IO. */
RayesError io_builtin_scene(const char *name, const char *data_dir, RayesScene *scene, char *err,
                            size_t err_size);

/* The names, NULL-terminated. */
extern const char *const io_builtin_scene_names[];

#endif /* RAYES_IO_BUILTIN_H */
