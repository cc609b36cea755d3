/*
 * io/builtin.h — the built-in scenes, built through rayes.h like any scene
 * file: "cornell" (the classic Cornell box with its two blocks; the
 * default) and "cornell-teapots" (the memo's benchmark box, with the Utah
 * teapot read from data_dir/teapot.bpt), and "cornell-spheres" (the box
 * with a sphere per built-in shader). Specified in ../shared/data.
 */
#ifndef RAYES_IO_BUILTIN_H
#define RAYES_IO_BUILTIN_H

#include <stddef.h>

#include "rayes/rayes.h"

/* Adds the named scene to an empty scene and commits it. data_dir may be
 * NULL if the scene needs no data. Errors fill err (one line) and return
 * nonzero: an unknown name is RAYES_ERROR_INVALID_ARGUMENT, missing data
 * RAYES_ERROR_IO. */
RayesError io_builtin_scene(const char *name, const char *data_dir, RayesScene *scene, char *err,
                            size_t err_size);

/* The names, NULL-terminated. */
extern const char *const io_builtin_scene_names[];

#endif /* RAYES_IO_BUILTIN_H */
