/*
 * render/services.h — private to render/: the services table shaders call
 * (services.c), which render.c gives each worker (Worker.services).
 */
#ifndef RAYES_RENDER_SERVICES_H
#define RAYES_RENDER_SERVICES_H

#include "render/path.h"

extern const RayesShaderServices render_services;

/* The albedo AOV's services (RAYES_AOV_ALBEDO): render_services's, but the
 * light is a white furnace, radiance 1 from every direction, and nothing
 * is traced. A shader's lighting method then gives its surface's albedo,
 * the colour its lobes reflect, without the shader's cooperation: direct
 * lighting's diffuse and specular are 1 (they stand for all the light, so
 * indirect diffuse and glossy lobes' indirect specular are 0), mirrors,
 * refraction, glossy and microfacet lobes 1, the classic specular its
 * lobe's integral 8 / (e + 8), subsurface diffusion its medium's total
 * diffuse reflectance Rd, ambient lights and occlusion 0. */
extern const RayesShaderServices albedo_services;

#endif /* RAYES_RENDER_SERVICES_H */
