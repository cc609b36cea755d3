/*
 * shade/builtin.h — the built-in shader classes. They are written against
 * rayes/shader.h only, exactly as a plugin would be.
 */
#ifndef RAYES_SHADE_BUILTIN_H
#define RAYES_SHADE_BUILTIN_H

#include "rayes/shader.h"

extern const RayesShaderClass shade_class_matte;    /* Lambertian: Ka, Kd, Ke */
extern const RayesShaderClass shade_class_plastic;  /* Ka, Kd, Ks, roughness, specularcolor */
extern const RayesShaderClass shade_class_mirror;   /* perfect specular: Kr, specularcolor */
extern const RayesShaderClass shade_class_constant; /* Ci = Cs */
extern const RayesShaderClass shade_class_defaultsurface; /* Cs (Ka + Kd (I.N)^2): no lights */
extern const RayesShaderClass shade_class_hair; /* fibres: Ka, Kd, Ks, roughness, specularcolor */
extern const RayesShaderClass shade_class_physicalhair; /* pbrt-v4's hair: sigma_a, reflectance,
                                                           eumelanin, pheomelanin, eta, beta_m,
                                                           beta_n, alpha */
extern const RayesShaderClass shade_class_stainedglass; /* coloured opacity: Kd, frequency,
                                                           leadwidth, clarity */
extern const RayesShaderClass shade_class_occlusion;    /* ambient occlusion: samples, maxdist */
extern const RayesShaderClass shade_class_glow; /* the RenderMan Companion's halo: attenuation */
extern const RayesShaderClass shade_class_diffusetransmission; /* Lambertian reflection and
                                                                  transmission: reflectance,
                                                                  transmittance, scale */
extern const RayesShaderClass shade_class_thindielectric; /* a glass sheet, light through it
                                                             unbent: eta */
extern const RayesShaderClass shade_class_homogeneous; /* volume: density, extinction, albedo,
                                                          g, emission */
extern const RayesShaderClass shade_class_turbulence; /* volume: the same, frequency, octaves,
                                                         falloff (memo Figure 9) */
extern const RayesShaderClass shade_class_subsurface; /* memo 6.2: preset, sigma_s, sigma_a,
                                                         albedo, diffusemeanfreepath, eta,
                                                         unitlength, profile, Kd, Ks, ... */
extern const RayesShaderClass shade_class_mix;        /* two materials blended by amount (mix.c) */
extern const RayesShaderClass shade_class_bumpy;    /* displacement: Km, frequency, texturename */
extern const RayesShaderClass shade_class_fractal;  /* displacement: the memo's fractal noise */
extern const RayesShaderClass shade_class_displace; /* displacement: P + amount N (a pattern) */

/* The services displacement runs with at dicing time: patterns only (the
 * lighting services are NULL; supports() says so). */
extern const RayesShaderServices shade_dicing_services;

/* The same with the texture service reading from a texture system. */
typedef struct TextureSystem TextureSystem;
typedef struct DicingServices {
    RayesShaderServices sv;   /* first, so a services pointer is a DicingServices pointer */
    TextureSystem *textures;  /* may be NULL: the texture service then fails */
} DicingServices;

void shade_dicing_services_init(DicingServices *ds, TextureSystem *textures);

/* Service functions that both the renderer's table and the dicing table
 * use: patterns (noise.h), and the texture service over a texture system
 * (NULL: -1, black, alpha 1); ds and dt NULL mean ctx->du and ctx->dv. */
float shade_service_noise(const RayesShaderServices *sv, const float p[3]);
float shade_service_fbm(const RayesShaderServices *sv, const float p[3], int octaves,
                        float lacunarity, float gain);
float shade_service_turbulence(const RayesShaderServices *sv, const float p[3], int octaves,
                               float lacunarity, float gain);
float shade_service_checker(const RayesShaderServices *sv, float s, float t, float ds, float dt);
int shade_texture_service(TextureSystem *ts, const RayesShadeCtx *ctx, const char *name,
                          const float *s, const float *t, const float *ds, const float *dt,
                          float (*rgb)[3], float *alpha);
/* RenderMan's diffuse() and specular(Nf, V, roughness) at the points, with
 * one set of shadow rays (either output may be NULL): the classic_lighting
 * service, or from a renderer without it direct_lighting, whose highlight
 * is its own normalised lobe. The classic shaders' lighting (builtin.c). */
void shade_classic_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const float *roughness, float (*diffuse)[3], float (*specular)[3]);

/* plastic with a texture: Ka, Kd, Ks, roughness, specularcolor, texturename */
extern const RayesShaderClass shade_class_paintedplastic;

/* builtin_procedural.c: wood grain under a varnish (planks optional) and a
 * brick wall whose displacement recesses its mortar (docs/shaders.md). */
extern const RayesShaderClass shade_class_wood;
extern const RayesShaderClass shade_class_brickwall;

/* builtin_bsdf.c: the rest of RenderMan's classics and the physically based
 * family the pbrt reader maps to (README.md lists their parameters). */
extern const RayesShaderClass shade_class_metal;         /* Ka, Ks, roughness */
extern const RayesShaderClass shade_class_shinymetal;    /* Ka, Ks, Kr, roughness, texturename */
extern const RayesShaderClass shade_class_glass;         /* Kr, Kt, eta, roughness, ... */
extern const RayesShaderClass shade_class_diffuse;       /* reflectance */
extern const RayesShaderClass shade_class_conductor;     /* eta, k, reflectance, roughness, preset */
extern const RayesShaderClass shade_class_dielectric;    /* eta, roughness */
extern const RayesShaderClass shade_class_coateddiffuse; /* reflectance, roughness, eta, thickness */

/* Whether the context's points branch (reflection and refraction both,
 * a mix's two materials both) or follow one lobe: below the renderer's
 * "branchdepth" they branch, and always when the renderer has no random
 * service to choose with (builtin_bsdf.c). */
int shade_branches(const RayesShaderServices *sv, const RayesShadeCtx *ctx);

#endif /* RAYES_SHADE_BUILTIN_H */
