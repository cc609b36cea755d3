/*
 * shader.h — the shader ABI of rayes: shader classes, shading contexts and
 * the renderer's services (memo section 4).
 *
 * A shader class is a versioned table of methods. The renderer calls each
 * method on a shading context of n_points shading points at once (a whole
 * grid, or a batch of ray hits): inputs are structure-of-arrays, owned by
 * the renderer and valid for the call only; outputs are separate arrays.
 *
 *   displacement     at dicing             writes P, N            (later)
 *   opacity          shadow rays           writes Oi              (later)
 *   prelighting      before lighting       illumination-independent work
 *   lighting         camera and specular hits: Ci, Oi, complete and view-dependent
 *   diffuselighting  diffuse hits and radiosity cache fills: Ci, Oi, optional
 *                    Irradiance; view-independent: ctx->I is NULL here
 *   postlighting     after lighting
 *
 * Shaders reach the renderer only through RayesShaderServices, built-in
 * shaders included. Services count the rays they trace; a service's ray
 * count argument of 0 means "the renderer's setting for this depth", which
 * is how quality presets reach shaders.
 *
 * Conventions: colours are linear RGB float[3]; N and Ng are unit length
 * and face the side being shaded (toward the incoming ray, or toward the
 * side a cache entry is filled for), so shaders need no faceforward.
 * Radiance-like service results are in the scene's radiance units.
 *
 * Thread-safety: methods run concurrently on many threads with distinct
 * contexts; a shader must not keep mutable state outside its outputs.
 */
#ifndef RAYES_SHADER_H
#define RAYES_SHADER_H

#include <stddef.h>
#include <stdint.h>

#include "rayes/rayes.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped whenever a struct below changes incompatibly. */
#define RAYES_SHADER_ABI_VERSION 1u

/* Ray types: one flag set. */
typedef enum RayesRayType {
    RAYES_RAY_NONE = 0,
    RAYES_RAY_CAMERA = 1u << 0,
    RAYES_RAY_SHADOW = 1u << 1,
    RAYES_RAY_DIFFUSE = 1u << 2,
    RAYES_RAY_SPECULAR = 1u << 3,
    RAYES_RAY_TRANSMISSION = 1u << 4,
    RAYES_RAY_SUBSURFACE = 1u << 5
} RayesRayType;

/* The inputs of one method call on n_points shading points. Arrays that a
 * method may not read are NULL (I in diffuselighting). */
typedef struct RayesShadeCtx {
    size_t n_points;
    uint32_t ray_type;          /* RayesRayType of the rays that led here */
    int diffuse_depth;          /* diffuse bounces before these points */
    int specular_depth;         /* specular bounces before these points */
    const float (*P)[3];        /* positions, world space */
    const float (*N)[3];        /* shading normals, unit, facing the shaded side */
    const float (*Ng)[3];       /* geometric normals, unit, facing the shaded side */
    const float (*dPdu)[3];     /* surface derivatives */
    const float (*dPdv)[3];
    const float *u, *v;         /* surface parameters of the primitive, [0,1] */
    const float *s, *t;         /* texture coordinates (default: u and v) */
    const float *du, *dv;       /* parameter footprint of the point (filter widths) */
    const float (*I)[3];        /* unit incident directions, toward the points; NULL in
                                   diffuselighting */
    const float (*Cs)[3];       /* surface colour (default 1) */
    const float (*Os)[3];       /* surface opacity (default 1) */
    void *renderer;             /* the renderer's private state; pass it back untouched */
    size_t first_point;         /* index of point 0 in the renderer's own per-point state;
                                   a context made of points [a, b) of another adds a */
} RayesShadeCtx;

/* The outputs of a method call, n_points each. Irradiance may be NULL. */
typedef struct RayesShadeOutputs {
    float (*Ci)[3];         /* outgoing radiance toward the viewer (or radiosity) */
    float (*Oi)[3];         /* opacity */
    float (*Irradiance)[3]; /* diffuselighting's optional irradiance (memo 6.2) */
} RayesShadeOutputs;

typedef struct RayesShaderServices RayesShaderServices;

/* A shader method. params points at the instance's parameter block (laid out
 * as the class's parameter table says). */
typedef void (*RayesShaderMethod)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out);

/* One entry of a class's parameter table. */
typedef struct RayesShaderParamDesc {
    const char *name;        /* e.g. "Kd" */
    RayesParamType type;     /* FLOAT: one float; COLOR: three floats; STRING: char[64] */
    size_t offset;           /* byte offset in the parameter block */
    float default_value[3];  /* FLOAT and COLOR defaults */
} RayesShaderParamDesc;

typedef struct RayesShaderClass {
    uint32_t abi_version;    /* RAYES_SHADER_ABI_VERSION the class was built against */
    uint32_t struct_size;    /* sizeof(RayesShaderClass) when built */
    const char *name;        /* the name scenes use, e.g. "matte" */
    size_t params_size;      /* bytes of the parameter block */
    const RayesShaderParamDesc *params;
    size_t n_params;
    RayesShaderMethod displacement;    /* may be NULL */
    RayesShaderMethod opacity;         /* may be NULL: opaque */
    RayesShaderMethod prelighting;     /* may be NULL */
    RayesShaderMethod lighting;        /* required */
    RayesShaderMethod diffuselighting; /* may be NULL: the diffuse lobes of lighting */
    RayesShaderMethod postlighting;    /* may be NULL */
} RayesShaderClass;

/* Everything a shader may ask of the renderer. Each function takes the
 * services table and the context it was given. */
struct RayesShaderServices {
    uint32_t abi_version;
    uint32_t struct_size;

    /* Direct lighting from the scene's lights with n_shadow_rays shadow rays
     * per light and point (0: the renderer's setting). Per point:
     *   diffuse[i]  = (1/pi) * integral of L_light cos(theta) dw (so a Lambertian
     *                 surface of albedo a reflects a * diffuse[i]);
     *   specular[i] = integral of L_light f(w) cos(theta) dw with the normalised
     *                 Blinn-Phong lobe f = (e + 8) / (8 pi) (N.H)^e, e = 1 / roughness[i].
     * Either output may be NULL. specular needs I: in diffuselighting it is
     * set to zero. */
    void (*direct_lighting)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            int n_shadow_rays, const float *roughness, float (*diffuse)[3],
                            float (*specular)[3]);

    /* Indirect diffuse: (1/pi) * integral of incident indirect radiance
     * cos(theta) dw over the hemisphere of N, with n_rays cosine-distributed
     * diffuse rays per point (0: the renderer's setting for this depth). Zero
     * beyond the maximum diffuse depth. */
    void (*indirect_diffuse)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             int n_rays, float (*out)[3]);

    /* Indirect specular: the radiance arriving along the unit directions
     * dir[i] (a perfect specular lobe), one specular ray per point. Zero
     * beyond the maximum specular depth. */
    void (*indirect_specular)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const float (*dir)[3], float (*out)[3]);

    /* Nonzero if the renderer offers the named service ("direct_lighting",
     * "indirect_diffuse", "indirect_specular", ...), so the table can grow. */
    int (*supports)(const RayesShaderServices *sv, const char *service);
};

#ifdef __cplusplus
}
#endif

#endif /* RAYES_SHADER_H */
