/*
 * shade/builtin_volume.c — built-in volume shaders (memo 6.1: "the
 * opacity returned by a shader is interpreted as the volume extinction
 * coefficients"): homogeneous, and turbulence, the memo's Figure 9 medium
 * whose extinction is a turbulence function of five octaves of noise.
 *
 * Both: opacity() = sigma_t = density * extinction (RGB, per unit
 * length), times turbulence's pattern; density may be bound to a pattern
 * (a densitygrid or nanovdb grid, shade_param_float), negative values
 * read as 0; lighting() = sigma_s * (the direct
 * light the phase function scatters toward the viewer, the direct_volume
 * service) + density * emission + sigma_a * blackbodyscale * B(T), sigma_s
 * = albedo * sigma_t, sigma_a = sigma_t - sigma_s, B(T) the blackbody of
 * temperature T = (temperature - temperatureoffset) * temperaturescale
 * (temperature may be bound to a pattern: pbrt-v4's nanovdb temperature
 * grid) as pbrt-v4 emits it: Planck's spectrum divided by its peak, in
 * linear sRGB, 0 at or below 100 K. Volume points carry their position
 * in the box in u, v and s (0 to 1).
 */
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/shade.h"

typedef float Rgb[3];

typedef struct VolumeParams {
    float density;
    float extinction[3]; /* sigma_t per unit density (pbrt's sigma_a + sigma_s) */
    float albedo[3];     /* sigma_s / sigma_t */
    float g;             /* Henyey-Greenstein asymmetry */
    float emission[3];   /* emitted radiance per unit length and density */
    float frequency;     /* turbulence only: the noise's frequency in world units */
    float octaves;
    float falloff;       /* turbulence only: 1 fades the density to 0 at the box's inscribed
                            sphere (a puff), 0 fills the box */
    float temperature;   /* kelvin, or a pattern's (blackbody emission) */
    float temperatureoffset, temperaturescale;
    float blackbodyscale; /* blackbody radiance per unit absorption; 0: none */
} VolumeParams;

/* ---- blackbody emission
 *
 * B(T) tabled over log T from 100 K to 100,000 K (hotter reads the last):
 * Planck's law over 360-830 nm in 1 nm steps divided by its value at
 * Wien's peak (pbrt-v4's BlackbodySpectrum), to CIE XYZ through the
 * colour matching functions' multi-lobe fit of Wyman, Sloan and Shirley
 * (2013) normalised so that a spectrum of 1 has Y = 1 (pbrt's film), then
 * to linear sRGB. */

enum { BB_N = 512 };
static const double bb_lo = 100.0, bb_hi = 100000.0;
static float bb_table[BB_N][3];
static pthread_once_t bb_once = PTHREAD_ONCE_INIT;

static double lobe(double l, double mu, double s1, double s2)
{
    double t = (l - mu) / (l < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

static double planck(double l_nm, double T)
{
    double l = l_nm * 1e-9, c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
    return 2.0 * h * c * c / (pow(l, 5) * (exp(h * c / (l * kb * T)) - 1.0));
}

static void bb_init(void)
{
    double ybar_sum = 0.0;
    for (int l = 360; l <= 830; l++)
        ybar_sum += 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    for (int k = 0; k < BB_N; k++) {
        double T = bb_lo * pow(bb_hi / bb_lo, k / (double)(BB_N - 1));
        double peak = planck(2.8977721e-3 / T * 1e9, T), X = 0, Y = 0, Z = 0;
        for (int l = 360; l <= 830; l++) {
            double b = planck(l, T) / peak;
            X += b * (1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
                      0.065 * lobe(l, 501.1, 20.4, 26.2));
            Y += b * (0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1));
            Z += b * (1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8));
        }
        X /= ybar_sum, Y /= ybar_sum, Z /= ybar_sum;
        double rgb[3] = {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z,
                         -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
                         0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
        for (int c = 0; c < 3; c++)
            bb_table[k][c] = (float)fmax(rgb[c], 0.0);
    }
}

/* B(T) into out (0 at or below 100 K). */
static void blackbody(float T, float out[3])
{
    if (!(T > (float)bb_lo)) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    pthread_once(&bb_once, bb_init);
    double x = log(fmin((double)T, bb_hi) / bb_lo) / log(bb_hi / bb_lo) * (BB_N - 1);
    int k = (int)x;
    k = k > BB_N - 2 ? BB_N - 2 : k;
    float f = (float)(x - k);
    for (int c = 0; c < 3; c++)
        out[c] = (1.0f - f) * bb_table[k][c] + f * bb_table[k + 1][c];
}

/* The density pattern at point i: 1 for homogeneous media. */
typedef float (*DensityFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                           const VolumeParams *p);

static float uniform_density(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                             const VolumeParams *p)
{
    (void)sv, (void)ctx, (void)i, (void)p;
    return 1.0f;
}

/* The memo's medium: turbulence (|noise| summed over octaves) at the
 * point's world position, optionally faded toward the box's edges. */
static float turbulence_density(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                                const VolumeParams *p)
{
    float q[3] = {ctx->P[i][0] * p->frequency, ctx->P[i][1] * p->frequency,
                  ctx->P[i][2] * p->frequency};
    float turb = sv->turbulence ? sv->turbulence(sv, q, (int)p->octaves, 2.0f, 0.5f) : 0.5f;
    float fade = 1.0f;
    if (p->falloff > 0.0f && ctx->u && ctx->v && ctx->s) {
        float dx = ctx->u[i] - 0.5f, dy = ctx->v[i] - 0.5f, dz = ctx->s[i] - 0.5f;
        float r = 2.0f * sqrtf(dx * dx + dy * dy + dz * dz); /* 1 at the inscribed sphere */
        float edge = fminf(fmaxf((1.0f - r) / 0.5f, 0.0f), 1.0f);
        fade = 1.0f - p->falloff + p->falloff * edge * edge * (3.0f - 2.0f * edge);
    }
    return fmaxf(0.0f, 2.0f * turb - 0.3f) * fade;
}

/* sigma_t at ctx's points into out: density (a constant, or the pattern
 * bound to "density") times fn's pattern times extinction. */
static void extinction(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const VolumeParams *p, DensityFn fn, Rgb *out)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        float density[SHADE_CHUNK];
        shade_ctx_slice(ctx, start, n, &sub);
        shade_param_float(sv, &sub, "density", p->density, density);
        for (size_t i = 0; i < n; i++) {
            float d = fmaxf(density[i], 0.0f) * fn(sv, &sub, i, p);
            for (int c = 0; c < 3; c++)
                out[start + i][c] = d * p->extinction[c];
        }
    }
}

static void volume_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const VolumeParams *p, DensityFn fn, RayesShadeOutputs *out)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        Rgb sigma[SHADE_CHUNK], light[SHADE_CHUNK], hot[SHADE_CHUNK];
        extinction(sv, &sub, p, fn, sigma);
        if (p->blackbodyscale > 0.0f) { /* sigma_a B(T) */
            float T[SHADE_CHUNK];
            shade_param_float(sv, &sub, "temperature", p->temperature, T);
            for (size_t i = 0; i < n; i++) {
                blackbody((T[i] - p->temperatureoffset) * p->temperaturescale, hot[i]);
                for (int c = 0; c < 3; c++)
                    hot[i][c] *= p->blackbodyscale * sigma[i][c] * (1.0f - p->albedo[c]);
            }
        } else {
            memset(hot, 0, n * sizeof *hot);
        }
        int lit = sv->direct_volume && (p->albedo[0] > 0 || p->albedo[1] > 0 || p->albedo[2] > 0);
        if (lit)
            sv->direct_volume(sv, &sub, 0, NULL, p->g, light);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                float d = p->extinction[c] > 0.0f ? sigma[i][c] / p->extinction[c] : 0.0f;
                out->Ci[start + i][c] = (lit ? p->albedo[c] * sigma[i][c] * light[i][c] : 0.0f) +
                                        d * p->emission[c] + hot[i][c];
                out->Oi[start + i][c] = sigma[i][c];
                if (out->Irradiance)
                    out->Irradiance[start + i][c] = 0.0f;
            }
    }
}

static void homogeneous_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    extinction(sv, ctx, params, uniform_density, out->Oi);
}

static void homogeneous_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    volume_lighting(sv, ctx, params, uniform_density, out);
}

static void turbulence_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    extinction(sv, ctx, params, turbulence_density, out->Oi);
}

static void turbulence_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    volume_lighting(sv, ctx, params, turbulence_density, out);
}

#define VOLUME_COMMON_PARAMS                                                                       \
    {"density", RAYES_PARAM_FLOAT, offsetof(VolumeParams, density), {1, 0, 0}},                    \
        {"extinction", RAYES_PARAM_COLOR, offsetof(VolumeParams, extinction), {1, 1, 1}},          \
        {"albedo", RAYES_PARAM_COLOR, offsetof(VolumeParams, albedo), {0.8f, 0.8f, 0.8f}},         \
        {"g", RAYES_PARAM_FLOAT, offsetof(VolumeParams, g), {0, 0, 0}},                            \
        {"emission", RAYES_PARAM_COLOR, offsetof(VolumeParams, emission), {0, 0, 0}},              \
        {"temperature", RAYES_PARAM_FLOAT, offsetof(VolumeParams, temperature), {0, 0, 0}},        \
        {"temperatureoffset",                                                                      \
         RAYES_PARAM_FLOAT,                                                                        \
         offsetof(VolumeParams, temperatureoffset),                                                \
         {0, 0, 0}},                                                                               \
        {"temperaturescale",                                                                       \
         RAYES_PARAM_FLOAT,                                                                        \
         offsetof(VolumeParams, temperaturescale),                                                 \
         {1, 0, 0}},                                                                               \
    {                                                                                              \
        "blackbodyscale", RAYES_PARAM_FLOAT, offsetof(VolumeParams, blackbodyscale),               \
        {                                                                                          \
            0, 0, 0                                                                                \
        }                                                                                          \
    }

static const RayesShaderParamDesc homogeneous_params[] = {VOLUME_COMMON_PARAMS};

const RayesShaderClass shade_class_homogeneous = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "homogeneous",
    .params_size = sizeof(VolumeParams),
    .params = homogeneous_params,
    .n_params = sizeof homogeneous_params / sizeof homogeneous_params[0],
    .opacity = homogeneous_opacity,
    .lighting = homogeneous_lighting,
    .diffuselighting = homogeneous_lighting,
};

static const RayesShaderParamDesc turbulence_params[] = {
    VOLUME_COMMON_PARAMS,
    {"frequency", RAYES_PARAM_FLOAT, offsetof(VolumeParams, frequency), {1, 0, 0}},
    {"octaves", RAYES_PARAM_FLOAT, offsetof(VolumeParams, octaves), {5, 0, 0}},
    {"falloff", RAYES_PARAM_FLOAT, offsetof(VolumeParams, falloff), {1, 0, 0}},
};

const RayesShaderClass shade_class_turbulence = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "turbulence",
    .params_size = sizeof(VolumeParams),
    .params = turbulence_params,
    .n_params = sizeof turbulence_params / sizeof turbulence_params[0],
    .opacity = turbulence_opacity,
    .lighting = turbulence_lighting,
    .diffuselighting = turbulence_lighting,
};
