/*
 * util/media.h — measured scattering media: Jensen, Marschner, Levoy and
 * Hanrahan 2001's Figure 5 (reduced scattering and absorption coefficients
 * per mm, RGB, measured at eta 1.3), which the subsurface shader's presets
 * (shade/diffusion.h) and pbrt-v4's named media (io/pbrt_material.c) both
 * name. Constant data; thread-safe.
 */
#ifndef RAYES_UTIL_MEDIA_H
#define RAYES_UTIL_MEDIA_H

typedef struct MeasuredMedium {
    const char *name; /* lower case: "skin1", "marble", "wholemilk", ... */
    float sigma_s[3]; /* reduced scattering coefficient sigma_s', per mm */
    float sigma_a[3]; /* absorption coefficient, per mm */
} MeasuredMedium;

/* The medium of that name (case-insensitive), or NULL. */
const MeasuredMedium *media_find(const char *name);

/* Every medium, NULL-name terminated. */
extern const MeasuredMedium media_measured[];

#endif /* RAYES_UTIL_MEDIA_H */
