/*
 * shader.h — the shader ABI of rayes: shader classes, shading contexts and
 * the renderer's services (memo section 4).
 *
 * A shader class is a versioned table of methods. The renderer calls each
 * method on a shading context of n_points shading points at once (a whole
 * grid, or a batch of ray hits): inputs are structure-of-arrays, owned by
 * the renderer and valid for the call only; outputs are separate arrays.
 *
 *   displacement     at dicing, on every fine-grid vertex: writes out->P (the
 *                    renderer recomputes N from the displaced grid)
 *   opacity          shadow and transmission rays: writes Oi
 *   prelighting      before lighting or diffuselighting: illumination-independent
 *                    work (texture lookups), kept in ctx->scratch for the
 *                    methods that follow on the same points
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
 * contexts; a shader must not keep mutable state outside its outputs and
 * its scratch.
 *
 * Plugins: a shared object NAME.so on the shader search path that exports
 * RAYES_SHADER_ENTRY_NAME, a RayesShaderEntry returning its class (whose
 * name is NAME). The renderer refuses a class whose abi_version differs
 * from its own.
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
#define RAYES_SHADER_ABI_VERSION 2u

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

/* A pattern: a small graph of textures made by rayes_scene_pattern (pbrt-v4's
 * texture classes), opaque to shaders, evaluated by the pattern service. */
typedef struct RayesPattern RayesPattern;

/* A FLOAT or COLOR parameter of the instance being shaded that the scene
 * bound to a pattern (a RAYES_PARAM_PATTERN value): its value varies over
 * the surface and is the pattern service's result at each point. */
typedef struct RayesPatternBinding {
    const char *param;           /* the parameter's name, as in the class's table */
    const RayesPattern *pattern; /* what it is bound to; valid during the call */
} RayesPatternBinding;

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
    void *scratch;              /* the class's scratch_size bytes per point, shared by the
                                   methods run on these points (prelighting writes it,
                                   lighting reads it); point i at scratch + i * scratch_size;
                                   NULL when scratch_size is 0 */
    const int *backfacing;      /* appended in ABI 2: 1 where the ray hit the back side of
                                   the surface (against dPdu x dPdv, so N and Ng were turned
                                   to face it; a cache fill for that side), else 0; NULL:
                                   every point is on the front (displacement) */
    const RayesPatternBinding *patterns; /* appended in ABI 2: the instance's parameters
                                   bound to patterns, n_patterns of them (NULL, 0: none); a
                                   parameter not listed has its value in params */
    size_t n_patterns;
    const float (*dst)[4]; /* appended after ABI 2 (a renderer that predates it leaves
                              it NULL): per point ds/du, ds/dv, dt/du, dt/dv, the texture
                              coordinates' derivatives (NULL: s and t are u and v) */
} RayesShadeCtx;

/* The outputs of a method call, n_points each. Irradiance may be NULL. */
typedef struct RayesShadeOutputs {
    float (*Ci)[3];         /* outgoing radiance toward the viewer (or radiosity) */
    float (*Oi)[3];         /* opacity */
    float (*Irradiance)[3]; /* diffuselighting's optional irradiance (memo 6.2): the
                               integral of incident radiance times cos over the
                               hemisphere of N; when the renderer asks for it (subsurface
                               rays), it holds pi times the diffuse result of the last
                               direct_lighting call on the points (0 before any), which
                               the shader may overwrite */
    float (*P)[3];          /* displacement: the displaced positions (input P copied in) */
} RayesShadeOutputs;

typedef struct RayesShaderServices RayesShaderServices;

/* A shader method. params points at the instance's parameter block (laid out
 * as the class's parameter table says). */
typedef void (*RayesShaderMethod)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out);

/* One entry of a class's parameter table. */
typedef struct RayesShaderParamDesc {
    const char *name;        /* e.g. "Kd" */
    RayesParamType type;     /* FLOAT: one float; COLOR: three floats; STRING: char[64]
                                (char[RAYES_SHADER_PATH_BYTES] with RAYES_SHADER_PATH_STRINGS) */
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
    size_t scratch_size;               /* bytes of scratch per point (ctx->scratch) */
    uint32_t flags;                    /* appended in ABI 2: RayesShaderFlags (a class built
                                          before it has struct_size short of it: none) */
} RayesShaderClass;

/* What a class tells the renderer before rendering. */
typedef enum RayesShaderFlags {
    RAYES_SHADER_SUBSURFACE = 1u << 0,  /* its methods call the subsurface service: objects
                                           shaded by it get an acceleration structure of
                                           their own for subsurface rays (memo 6.2) */
    RAYES_SHADER_THIN_SHADOW = 1u << 1, /* its opacity method is a refracting surface's thin
                                           shadow (glass): other objects' shadow and diffuse
                                           rays see through it, but the shadow rays its own
                                           methods cast find it opaque, since its lobes
                                           trace the light that crosses it */
    RAYES_SHADER_PATH_STRINGS = 1u << 2 /* its STRING parameters are
                                           char[RAYES_SHADER_PATH_BYTES], room for a file's
                                           path (a texture's); without it char[64] */
} RayesShaderFlags;

/* The bytes of a STRING parameter of a class with RAYES_SHADER_PATH_STRINGS
 * (a longer value is cut, with a warning). */
#define RAYES_SHADER_PATH_BYTES 1024

/* Diffusion profiles of the subsurface service. */
typedef enum RayesSubsurfaceProfile {
    RAYES_SUBSURFACE_DIPOLE = 0, /* Jensen et al. 2001, the memo's */
    RAYES_SUBSURFACE_BURLEY = 1  /* Christensen and Burley 2015's normalized diffusion,
                                    of the dipole's total diffuse reflectance and diffuse
                                    mean free path 1 / sigma_tr */
} RayesSubsurfaceProfile;

/* A homogeneous scattering medium under the surface, per RGB channel. */
typedef struct RayesSubsurfaceParams {
    float sigma_s[3]; /* reduced scattering coefficient sigma_s', per mm */
    float sigma_a[3]; /* absorption coefficient, per mm */
    float eta;        /* index of refraction of the medium over the outside's */
    float scale;      /* scene units per mm */
    int profile;      /* RayesSubsurfaceProfile */
} RayesSubsurfaceParams;

/* A fibre (hair, fur) for the hair service: pbrt-v4's hair BSDF. */
typedef struct RayesHairParams {
    const float (*T)[3];       /* per point, the fibre's direction (a curve's dPdu) */
    const float *h;            /* per point, where the ray met the fibre's width, -1 to 1
                                  (a curve's 2 v - 1); outside [-1, 1], or h NULL: the
                                  fibre integrated over its width (each sample an offset
                                  of its own), what a pixel sees of a fibre thinner than
                                  itself and a grid's vertex stands for */
    const float (*sigma_a)[3]; /* per point, absorption per unit of the fibre's radius */
    float eta;                 /* the fibre's index (0: 1.55) */
    float beta_m, beta_n;      /* longitudinal and azimuthal roughness, 0 to 1 (0: 0.3) */
    float alpha;               /* the cuticle scales' tilt, degrees (pbrt's 2) */
} RayesHairParams;

/* What a plugin exports under RAYES_SHADER_ENTRY_NAME. */
typedef const RayesShaderClass *(*RayesShaderEntry)(void);
#define RAYES_SHADER_ENTRY_NAME "rayes_shader_entry"


/* Everything a shader may ask of the renderer. Each function takes the
 * services table and the context it was given. A function the renderer
 * lacks is NULL; supports() names the ones present, so the table can grow
 * (new members are appended; struct_size says how many there are). */
struct RayesShaderServices {
    uint32_t abi_version;
    uint32_t struct_size;

    /* Direct lighting from the scene's lights with n_shadow_rays shadow
     * rays per light and point (0: the renderer's setting). category
     * selects lights as RenderMan's illuminance does: NULL or "" all
     * lights, "name" those whose category list holds name, "-name" those
     * whose list does not. Ambient lights are excluded (see ambient). Per
     * point:
     *   diffuse[i]  = (1/pi) * integral of L_light cos(theta) dw (so a Lambertian
     *                 surface of albedo a reflects a * diffuse[i]);
     *   specular[i] = integral of L_light f(w) cos(theta) dw with the normalised
     *                 Blinn-Phong lobe f = (e + 8) / (8 pi) (N.H)^e, e = 1 / roughness[i]
     *                 (roughness NULL: 0.1).
     * Area and environment lights are sampled with multiple importance
     * sampling against each lobe. Either output may be NULL. specular
     * needs I: in diffuselighting it is set to zero. */
    void (*direct_lighting)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            int n_shadow_rays, const char *category, const float *roughness,
                            float (*diffuse)[3], float (*specular)[3]);

    /* The light of ambient lights (RenderMan's ambient()): a Lambertian
     * surface of albedo a reflects a * out[i]. Counted apart from global
     * illumination. */
    void (*ambient)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3]);

    /* Indirect diffuse: (1/pi) * integral of incident indirect radiance
     * cos(theta) dw over the hemisphere of N, with n_rays cosine-distributed
     * diffuse rays per point (0: the renderer's setting for this depth). Zero
     * beyond the maximum diffuse depth. */
    void (*indirect_diffuse)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             int n_rays, float (*out)[3]);

    /* Indirect specular: radiance arriving around the unit directions
     * dir[i]. roughness NULL (or roughness[i] 0): a perfect mirror, one ray;
     * otherwise the mean over n_rays directions drawn from the normalised
     * Blinn-Phong lobe of exponent 1 / roughness[i] about dir[i] (0 rays:
     * the renderer's setting), which is the lobe's integral divided by its
     * albedo. Zero beyond the maximum specular depth. */
    void (*indirect_specular)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const float (*dir)[3], const float *roughness, int n_rays,
                              float (*out)[3]);

    /* Refraction: the radiance arriving along dir[i], a direction that
     * crosses the surface (into or out of it); one ray, counted as a
     * specular bounce. */
    void (*indirect_refraction)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const float (*dir)[3], float (*out)[3]);

    /* Transmission (RenderMan's transmission()): the fraction of light that
     * passes from each point to the world-space point to[i], through the
     * opacity of what lies between (1: nothing in the way). */
    void (*transmission)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const float (*to)[3], float (*out)[3]);

    /* A texture lookup: the image file name (found on the texture search
     * path; EXR or PNG) at (s[i], t[i]), (0,0) the top-left corner, filtered
     * over ds[i] x dt[i] in texture space (NULL: ctx->du and ctx->dv, right
     * when s and t are u and v), wrapping periodically. rgb receives linear
     * colour; alpha (may be NULL) the alpha channel, 1 if absent. Returns 0,
     * or -1 when the texture cannot be read (one warning; rgb is then 0 and
     * alpha 1). */
    int (*texture)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                   const float *s, const float *t, const float *ds, const float *dt,
                   float (*rgb)[3], float *alpha);

    /* Gradient (Perlin) noise in [-1, 1], zero on integer lattice points. */
    float (*noise)(const RayesShaderServices *sv, const float p[3]);
    /* Fractal sums of noise over octaves, frequency multiplied by
     * lacunarity and amplitude by gain per octave: fbm sums noise,
     * turbulence sums its absolute value. */
    float (*fbm)(const RayesShaderServices *sv, const float p[3], int octaves, float lacunarity,
                 float gain);
    float (*turbulence)(const RayesShaderServices *sv, const float p[3], int octaves,
                        float lacunarity, float gain);

    /* Attribute of what is being shaded ("object:id"; "patch:id";
     * "grid:size", the grid's vertices in u and v (triangles: subdivisions
     * and 0); "grid:edge", its mean micropolygon edge; "grid:curvature")
     * and option of the render ("resolution", "bounces", "samples",
     * "shadowrays", "diffuserays", "branchdepth"): writes up to n floats to value and
     * returns how many the attribute has, or 0 if unknown (always 0 at
     * dicing time). */
    int (*attribute)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                     float *value, int n);
    int (*option)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                  float *value, int n);

    /* Nonzero if the renderer offers the named service ("direct_lighting",
     * "ambient", "texture", ...), so the table can grow. */
    int (*supports)(const RayesShaderServices *sv, const char *service);

    /* A checkerboard of unit squares in (s, t): 1 where floor(s) + floor(t)
     * is even, else 0, box-filtered over ds x dt (0: point sampled). */
    float (*checker)(const RayesShaderServices *sv, float s, float t, float ds, float dt);

    /* A random number in [0, 1) for point i and a dimension of the
     * shader's choosing: a function of the point's path, so the same
     * render gives the same numbers whatever the threads. For choosing
     * among lobes: a point whose diffuse plus specular depth is at least
     * the option "branchdepth" should follow one lobe (chosen with
     * probability p, its result divided by p) rather than call
     * indirect_specular and indirect_refraction both, and may end by
     * Russian roulette on the lobe's weight; the renderer then traces one
     * ray per glossy lobe too. Older renderers lack it (supports()). */
    float (*random)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                    uint32_t dimension);

    /* Glossy reflection toward the viewer (-I) with direct_lighting's
     * normalised Blinn-Phong lobe, e = 1 / roughness[i] (NULL: 0.1):
     * out[i] = integral of L f(w) cos(theta) dw over all incident light,
     * the scene's lights by multiple importance sampling against the lobe
     * (as direct_lighting's specular) and everything else by n_rays rays
     * drawn from the lobe (0: the renderer's setting; one past the branch
     * depth). Unlike indirect_specular's lobe it is not divided by the
     * lobe's albedo, and small bright lights do not make it speckle. Zero
     * without I. Older renderers lack it (supports()). */
    void (*glossy)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                   const float *roughness, int n_rays, float (*out)[3]);

    /* Direct lighting of fibres (hair, fur, grass), whose shading depends
     * on the unit tangent T[i] (the fibre's direction, e.g. dPdu), not on
     * a normal: light from every direction counts (a fibre has no back),
     * with direct_lighting's shadow rays and light selection. Per point,
     * with t = T.w and (specular, needs I) v = T.V:
     *   diffuse[i]  = (1/pi) integral of L sqrt(1 - t^2) dw (Kajiya-Kay's
     *                 diffuse: a fibre of albedo a reflects a * diffuse[i]);
     *   specular[i] = integral of L (e + 2) / (2 pi) max(0, sqrt(1 - t^2)
     *                 sqrt(1 - v^2) - t v)^e dw, e = 1 / roughness[i] (NULL:
     *                 0.1): Kajiya-Kay's highlight on the cone of mirror
     *                 directions about the fibre.
     * Area and environment lights: the diffuse part by light samples, the
     * highlight by light samples and samples of its lobe, weighed by
     * multiple importance. Either output may be NULL. Older renderers
     * lack it (supports()). */
    void (*direct_fiber)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         int n_shadow_rays, const char *category, const float (*T)[3],
                         const float *roughness, float (*diffuse)[3], float (*specular)[3]);

    /* A pattern (one of ctx->patterns' pattern) at the points: linear RGB,
     * a float pattern grey in all three. Image lookups are filtered over
     * the points' texture footprint, as the texture service's with ds and
     * dt NULL; checkerboards are box-filtered like checker. Deterministic.
     * Returns 0, or -1 when an image cannot be read (one warning; its
     * lookups are then 0). Older renderers lack it (supports()). */
    int (*pattern)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                   const RayesPattern *pattern, float (*out)[3]);

    /* Ambient occlusion (RenderMan's occlusion()): the cosine-weighted
     * fraction of the hemisphere about N from which light is blocked
     * within maxdist (0: any distance), estimated with n_rays transmission
     * rays (0: the renderer's diffuse ray count for this depth). Partly
     * transparent surfaces block by their opacity (memo 6.1: read from the
     * opacity cache), so a cut-out occludes only where it is opaque; per
     * channel, in [0, 1]. Older renderers lack it (supports()). */
    void (*occlusion)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n_rays,
                      float maxdist, float (*out)[3]);

    /* Direct lighting of a medium (volume shaders' lighting method): per
     * point, the integral of L_light(w) p(w) dw over the scene's lights,
     * p the Henyey-Greenstein phase function of asymmetry g (0:
     * isotropic, 1 / (4 pi)) between the light's direction and the view
     * (ctx->I; g > 0 scatters forward, toward a viewer looking at the
     * light). Shadow rays as direct_lighting's (n_shadow_rays, category),
     * attenuated by surfaces' opacity and volumes' extinction. A medium of
     * scattering coefficient sigma_s scatters sigma_s * out[i] toward the
     * viewer per unit length. Below the render's maximum diffuse depth, a
     * call for all lights (category NULL or "") also adds to out[i] the
     * light arriving from everything else (surfaces, the medium itself:
     * multiple scattering), by rays drawn from the phase function; a call
     * for a category adds none, so a shader summing categories counts it
     * once if one of its calls is for all lights, else not at all. Older
     * renderers lack it (supports()). */
    void (*direct_volume)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          int n_shadow_rays, const char *category, float g, float (*out)[3]);

    /* Multiple subsurface scattering by diffusion (memo 6.2): per point,
     * out[i] = (1/pi) integral of R(|x - P[i]|) E(x) dA(x) over the surface
     * of the object being shaded, R the medium's diffusion profile in 1/mm^2
     * (p->profile), E the irradiance on the object's outside, which the
     * renderer gets from the object's shader's diffuselighting (its
     * Irradiance output; the direct_lighting service fills it) and keeps
     * in the multiresolution cache as data type irradiance. The integral
     * is estimated with n_rays subsurface rays (0: the renderer's setting)
     * cast uniformly over the sphere from a probe point inside the object,
     * which only hit its own surfaces (so surfaces inside it block). out is
     * radiance leaving through the surface before the exit Fresnel factor,
     * which the shader applies (it sees I). The class must have the flag
     * RAYES_SHADER_SUBSURFACE. Older renderers lack it (supports()). */
    void (*subsurface)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const RayesSubsurfaceParams *p, int n_rays, float (*out)[3]);

    /* Microfacet reflection toward the viewer (-I): glossy's integral with
     * the GGX (Trowbridge-Reitz) lobe of width alpha[i] and Smith's
     * height-correlated shadowing, f = D(H) G / (4 N.V N.L), D = alpha^2 /
     * (pi ((N.H)^2 (alpha^2 - 1) + 1)^2), G = 1 / (1 + Lambda(V) +
     * Lambda(L)), Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta_w) - 1) / 2
     * (no Fresnel: the shader multiplies it in), pbrt-v4's model. Unlike
     * the Blinn-Phong lobe, whose albedo falls toward (N.V)^2 off the
     * normal, its albedo changes little with the view (light that would
     * scatter between microfacets is lost, as in pbrt: about 5% at alpha
     * 0.2 and 30% at alpha 0.5, seen along the normal). alpha below
     * 0.001 is taken as 0.001 (a mirror is indirect_specular's). Lights
     * by multiple importance sampling against the lobe, the rest by
     * n_rays rays drawn from D(H) N.H (0: the renderer's setting; one past
     * the branch depth). Zero without I. Older renderers lack it
     * (supports()). */
    void (*microfacet)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const float *alpha,
                       int n_rays, float (*out)[3]);

    /* RenderMan's diffuse() and specular(), with the shadow rays of one
     * direct_lighting call (the same arguments): diffuse[i] as
     * direct_lighting's; specular[i] = (1/pi) * integral of L_light
     * (N.H)^(1 / roughness[i]) dw, with no cosine and no normalisation
     * (roughness NULL: 0.1). Under RenderMan's point, spot and distant
     * lights, whose intensity the RIB reader multiplies by pi, that is the
     * RenderMan specification's sum of Cl (N.H)^(1 / roughness): the
     * classic shaders' highlight, dimmer than direct_lighting's normalised
     * lobe by about 8 / (e + 8) and brighter toward grazing light. (PRMan
     * and Aqsis raise N.H to 8 / roughness instead; the reference pictures
     * of classic RIB files measured match the specification.) Area and
     * environment lights are sampled with multiple importance sampling
     * against the Blinn-Phong lobe of that exponent. Older renderers lack
     * it (supports()). */
    void (*classic_lighting)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             int n_shadow_rays, const char *category, const float *roughness,
                             float (*diffuse)[3], float (*specular)[3]);

    /* Light scattered by fibres toward the viewer (-I) with pbrt-v4's hair
     * BSDF (Chiang et al. 2016: reflection off the cuticle, transmission
     * through the fibre, one internal reflection, and the rest, each with
     * its longitudinal and azimuthal spread, tinted by sigma_a along its
     * path inside): out[i] = integral over the whole sphere of L(w) f(-I,
     * w) |cos| dw. The scene's lights by multiple importance sampling of
     * n_shadow_rays light samples against as many drawn from the BSDF (0:
     * the renderer's setting); everything else by n_rays rays drawn from
     * the BSDF (0: the renderer's diffuse count for the depth; one past the
     * branch depth), read as diffuse rays (their hits' view-independent
     * light, through the radiosity cache). Zero without I. Older renderers
     * lack it (supports()). */
    void (*hair)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const RayesHairParams *p,
                 int n_shadow_rays, int n_rays, float (*out)[3]);
};

#ifdef __cplusplus
}
#endif

#endif /* RAYES_SHADER_H */
