/*
 * shade/registry.c — finding a shader class by name (registry.h): the
 * built-in classes are a constant table, then plugins on a search path
 * (plugin.c). Thread-safe.
 */
#include "shade/registry.h"

#include <string.h>

#include "shade/builtin.h"
#include "shade/plugin.h"

static const RayesShaderClass *const builtin_classes[] = {
    &shade_class_matte,       &shade_class_plastic,        &shade_class_mirror,
    &shade_class_constant,    &shade_class_bumpy,          &shade_class_fractal,
    &shade_class_displace,    &shade_class_metal,          &shade_class_shinymetal,
    &shade_class_glass,       &shade_class_diffuse,        &shade_class_conductor,
    &shade_class_dielectric,  &shade_class_coateddiffuse,  &shade_class_paintedplastic,
    &shade_class_hair,        &shade_class_stainedglass,   &shade_class_occlusion,
    &shade_class_glow,        &shade_class_thindielectric, &shade_class_diffusetransmission,
    &shade_class_homogeneous, &shade_class_turbulence,     &shade_class_subsurface,
    &shade_class_wood,        &shade_class_brickwall,      &shade_class_defaultsurface,
    &shade_class_mix,         &shade_class_physicalhair,
};

const RayesShaderClass *shade_find_class(const char *name)
{
    for (size_t i = 0; i < sizeof builtin_classes / sizeof builtin_classes[0]; i++)
        if (strcmp(builtin_classes[i]->name, name) == 0)
            return builtin_classes[i];
    return NULL;
}

const RayesShaderClass *shade_find_class_on_path(const char *name, const char *search_path,
                                                 char *err, size_t err_size)
{
    const RayesShaderClass *cls = name ? shade_find_class(name) : NULL;
    return cls ? cls : shade_plugin_find(name, search_path, err, err_size);
}
