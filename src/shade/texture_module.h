/*
 * shade/texture_module.h — what the texture shim (texture.c) and the
 * OpenImageIO module (oiio/texture.cpp, built as librayes_oiio.so) share.
 *
 * OpenImageIO as Debian builds it pulls in OpenCV, GDAL, FFmpeg, OpenVDB
 * and more, whose loading alone makes a process 130 MB resident (measured:
 * an empty program linked with -lOpenImageIO). So rayes links none of it:
 * texture.c loads the module with dlopen on the first texture lookup or
 * environment map, and a scene without textures never pays for it
 * (DESIGN.md "Textures").
 *
 * The module exports one symbol, TEXTURE_MODULE_ENTRY, returning this
 * table; everything else in it is hidden.
 */
#ifndef RAYES_SHADE_TEXTURE_MODULE_H
#define RAYES_SHADE_TEXTURE_MODULE_H

#include "shade/texture.h"

#define TEXTURE_MODULE_VERSION 3
#define TEXTURE_MODULE_ENTRY "rayes_texture_module"
#define TEXTURE_MODULE_FILE "librayes_oiio.so"

typedef struct TextureModule {
    uint32_t version;     /* TEXTURE_MODULE_VERSION */
    /* Where the module's warnings go (the host's log). */
    void (*set_warning)(void (*warn)(const char *message));
    /* texture.h's functions, on the module's own systems. */
    void *(*system_new)(const char *search_path, uint64_t budget_bytes, float width);
    void (*system_free)(void *ts);
    int (*lookup)(void *ts, const char *name, const char *encoding, TextureWrap wrap, size_t n,
                  const float *s, const float *t, const float *ds, const float *dt, float (*rgb)[3],
                  float *alpha);
    void (*get_stats)(void *ts, TextureStats *stats);
    int (*channels)(void *ts, const char *name, const char *encoding);
    int (*read_image)(const char *path, int *w, int *h, float **rgba, char *err,
                      size_t err_size);
} TextureModule;

typedef const TextureModule *(*TextureModuleEntry)(void);

#endif /* RAYES_SHADE_TEXTURE_MODULE_H */
