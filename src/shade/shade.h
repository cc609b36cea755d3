/*
 * shade/shade.h — shader classes, shader instances and the helpers built-in
 * shaders share (DESIGN.md "The shading system").
 *
 * A ShaderInstance is a class plus a parameter block filled from the
 * class's parameter table (defaults, then the parameters a scene gave by
 * name). Instances are immutable once made and shared by all threads.
 */
#ifndef RAYES_SHADE_SHADE_H
#define RAYES_SHADE_SHADE_H

#include <stddef.h>
#include <stdint.h>

#include "rayes/shader.h"

/* Whether the renderer's services table holds service m: within the size
 * it was built with, and set (supports() alone trusts the renderer's
 * word). Built-in shaders ask it before using a service appended later. */
#define SHADE_HAS_SERVICE(sv, m)                                                                   \
    ((sv)->struct_size >= offsetof(RayesShaderServices, m) + sizeof((sv)->m) && (sv)->m != NULL)

typedef struct ShaderInstance {
    const RayesShaderClass *cls;
    void *params;               /* the parameter block, cls->params_size bytes, owned */
    RayesPatternBinding *patterns; /* parameters bound to patterns (owned array; the
                                      patterns are the scene's), what methods see in
                                      ctx->patterns */
    size_t n_patterns;
    int bump; /* a displacement that bends the shading normal alone (its
                 "__bump" 1, pbrt's material displacement): P stays */
    struct ShaderInstance *children; /* a class of SHADE_CLASS_CHILDREN's: the instances
                                        it shades with (owned array), else NULL */
    size_t n_children;
} ShaderInstance;

/* rayes' own flag (no plugin sets it): the class shades with other
 * instances, its children (mix.c), which shade_instance_adopt gives it; its
 * parameter block begins with a `const ShaderInstance *` to them. */
#define SHADE_CLASS_CHILDREN (1u << 31)

/* Makes an instance: defaults, then params by name. Unknown names and type
 * mismatches get a warning naming the shader and the parameter (once per
 * class and name). Returns 0, or -1 (out of memory, err filled). */
int shade_instance_init(ShaderInstance *inst, const RayesShaderClass *cls,
                        const RayesParam *params, size_t n_params, char *err, size_t err_size);
/* Sets params by name on an instance, over the values it has. Unknown names
 * and wrong types get one warning each and are skipped, or, when strict,
 * make it return -1 with err filled (nothing after the bad one is set). */
int shade_instance_apply(ShaderInstance *inst, const RayesParam *params, size_t n_params,
                         int strict, char *err, size_t err_size);
void shade_instance_fini(ShaderInstance *inst);

/* Gives a SHADE_CLASS_CHILDREN instance its n children (a malloc'd array of
 * initialised instances, owned from now on: shade_instance_fini ends
 * them). */
void shade_instance_adopt(ShaderInstance *inst, ShaderInstance *children, size_t n);

/* Binds the FLOAT or COLOR parameter `name` of the instance to pattern (a
 * later binding of the same name replaces it). Returns 0, or -1 with err
 * filled (no such parameter, another type, out of memory). */
int shade_instance_bind(ShaderInstance *inst, const char *name, const RayesPattern *pattern,
                        char *err, size_t err_size);

/* The values at ctx's points of a FLOAT or COLOR parameter whose constant
 * is value: the pattern ctx->patterns binds to name if there is one and
 * the renderer has the pattern service, else the constant (a float reads
 * a pattern's first channel). For shaders written against shader.h, the
 * built-ins as plugins. */
void shade_param_color(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                       const float value[3], float (*out)[3]);
void shade_param_float(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                       float value, float *out);
/* Nonzero if ctx->patterns binds name. */
int shade_param_bound(const RayesShadeCtx *ctx, const char *name);

/* The shading normals at ctx's points (SHADE_CHUNK at most) of the normal
 * map bound to "normalmap" (pbrt-v4's: texel n = 2 rgb - 1 in the frame of
 * x = dP/ds, z = N, y = z cross x), into out; ctx->N where the mapped
 * normal turns away from the geometric one. */
void shade_normal_map(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3]);

/* Runs diffuselighting, or the fallback for classes without it: lighting
 * with I absent, whose services then return only view-independent (diffuse)
 * lobes; warns once per class. */
void shade_run_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const ShaderInstance *inst, RayesShadeOutputs *out);

/* Runs prelighting (if any) and lighting, then postlighting (if any).
 * Both run functions give the methods scratch (the class's scratch_size
 * bytes per point, zeroed) when the class asks for some and ctx->scratch
 * is NULL. */
void shade_run_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const ShaderInstance *inst, RayesShadeOutputs *out);

/* Runs the opacity method into out->Oi (only Oi is written), or copies
 * ctx->Os (1 without it) for classes without one. Cache fills give no I
 * (one opacity per point whatever the side seen, memo 6.1); uncached
 * transmission hits do. */
void shade_run_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const ShaderInstance *inst, RayesShadeOutputs *out);

/* The class's RayesShaderFlags (0 for a class built before the field). */
static inline uint32_t shade_class_flags(const RayesShaderClass *cls)
{
    return cls && cls->struct_size >= offsetof(RayesShaderClass, flags) + sizeof cls->flags
               ? cls->flags
               : 0u;
}

/* The bytes of a STRING parameter of cls. */
static inline size_t shade_string_bytes(const RayesShaderClass *cls)
{
    return shade_class_flags(cls) & RAYES_SHADER_PATH_STRINGS ? RAYES_SHADER_PATH_BYTES : 64;
}

/* The flags an object shaded by inst needs: its class's, and its
 * children's (a mix of a subsurface material needs the object's own
 * scene), without SHADE_CLASS_CHILDREN. */
uint32_t shade_instance_flags(const ShaderInstance *inst);

/* Nonzero if inst computes opacity: its class has an opacity method, or
 * for a class with children, one of them does. */
int shade_instance_has_opacity(const ShaderInstance *inst);

/* Points per chunk when a shader needs scratch arrays on the stack. */
#define SHADE_CHUNK 64

/* The sub-context of points [start, start + count) of ctx. Its scratch is
 * ctx's (a slice does not know the class's scratch_size): offset it by
 * start * scratch_size where the sub-context's methods read it. */
void shade_ctx_slice(const RayesShadeCtx *ctx, size_t start, size_t count, RayesShadeCtx *sub);

/* Runs fn on ctx's points SHADE_CHUNK at a time, each slice with its part
 * of out (Ci, Oi, Irradiance). */
typedef void (*ShadeChunkFn)(const RayesShaderServices *sv, const RayesShadeCtx *sub,
                             const void *params, RayesShadeOutputs *out);
void shade_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                  RayesShadeOutputs *out, ShadeChunkFn fn);

/* shade_chunks, then Oi = Os (1 without it) and Ci premultiplied by it. */
void shade_chunks_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out, ShadeChunkFn fn);

/* The other side of ctx's points (at most SHADE_CHUNK): *back is ctx with
 * N and Ng (N without it) turned over, held in N and Ng, so that services
 * called on it light that side and send its rays from there. */
void shade_ctx_turned(const RayesShadeCtx *ctx, float (*N)[3], float (*Ng)[3], RayesShadeCtx *back);

#endif /* RAYES_SHADE_SHADE_H */
