/*
 * shade/registry.h — shader classes by name: the built-in ones
 * (builtin.h), then plugins (plugin.h). registry.c.
 */
#ifndef RAYES_SHADE_REGISTRY_H
#define RAYES_SHADE_REGISTRY_H

#include <stddef.h>

#include "rayes/shader.h"

/* The built-in class of that name, or NULL. */
const RayesShaderClass *shade_find_class(const char *name);

/* The built-in class of that name, else the plugin name.so from the
 * colon-separated directories of search_path (plugin.h). Returns the class,
 * or NULL with err filled (one line: the plugin's load error, or the
 * unknown name and the directories searched). */
const RayesShaderClass *shade_find_class_on_path(const char *name, const char *search_path,
                                                 char *err, size_t err_size);

#endif /* RAYES_SHADE_REGISTRY_H */
