/*
 * render/services.h — private to render/: the services table shaders call
 * (services.c), which render.c gives each worker (Worker.services).
 */
#ifndef RAYES_RENDER_SERVICES_H
#define RAYES_RENDER_SERVICES_H

#include "render/path.h"

extern const RayesShaderServices render_services;

#endif /* RAYES_RENDER_SERVICES_H */
