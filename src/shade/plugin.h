/*
 * shade/plugin.h — shader classes loaded from shared objects (shader.h,
 * "Plugins"; docs/shaders.md).
 *
 * A plugin NAME is the file NAME.so in one of the directories of a search
 * path (colon-separated, searched in order, empty entries skipped). It is
 * opened with dlopen(RTLD_NOW | RTLD_LOCAL), its RAYES_SHADER_ENTRY_NAME
 * function returns the class, and the class is checked (ABI version,
 * struct size, name, methods, parameter table) before anyone uses it.
 *
 * Loaded classes stay loaded for the life of the process in a registry
 * keyed by the file's real path, so a class pointer never dangles and a
 * file is opened once however many scenes use it. Thread-safe: one mutex
 * guards the registry and every load. A file that fails its checks is
 * closed again and not remembered (a later call reports it again).
 */
#ifndef RAYES_SHADE_PLUGIN_H
#define RAYES_SHADE_PLUGIN_H

#include <stddef.h>

#include "rayes/shader.h"

/* Largest plausible sizes in a class table, against garbage. */
#define PLUGIN_MAX_STRUCT_SIZE 65536u
#define PLUGIN_MAX_PARAMS_SIZE (1u << 20)
#define PLUGIN_MAX_SCRATCH_SIZE 65536u

/* Loads the class `name` from the shared object at `path`. Returns the
 * class (owned by the registry, valid for the process's life), or NULL
 * with err filled with one line "PATH: what is wrong". */
const RayesShaderClass *shade_plugin_load(const char *path, const char *name, char *err,
                                          size_t err_size);

/* Looks for name.so in the directories of search_path (may be NULL or
 * "") and loads the first one found. Returns the class, or NULL with err
 * filled: a load error of the file found, or, when no directory holds
 * name.so, `unknown shader "NAME": ...` listing the directories searched. */
const RayesShaderClass *shade_plugin_find(const char *name, const char *search_path, char *err,
                                          size_t err_size);

/* The checks shade_plugin_load makes on a class table, for a class
 * expected to be called `name`. Returns 0, or -1 with err filled (what is
 * wrong, without a file name). */
int shade_plugin_check_class(const RayesShaderClass *cls, const char *name, char *err,
                             size_t err_size);

#endif /* RAYES_SHADE_PLUGIN_H */
