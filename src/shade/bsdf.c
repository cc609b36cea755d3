/*
 * shade/bsdf.c — the lobes and Fresnel terms of bsdf.h (formulas:
 * Walter et al. 2007 for GGX and Smith G; pbrt-v3 8.2 for the exact
 * dielectric and conductor Fresnel equations).
 */
#include "shade/bsdf.h"

#include <math.h>
#include <string.h>

#define PI_F 3.14159265358979f

static Vec3 local_dir(float cos_t, float phi)
{
    float sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t));
    return v3(sin_t * cosf(phi), sin_t * sinf(phi), cos_t);
}

/* ------------------------------------------------------------ Fresnel */

float fresnel_dielectric(float cos_i, float eta)
{
    if (cos_i < 0.0f) {
        cos_i = -cos_i;
        eta = 1.0f / eta;
    }
    cos_i = fminf(cos_i, 1.0f);
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f)
        return 1.0f; /* total internal reflection */
    float cos_t = sqrtf(1.0f - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_par * r_par + r_perp * r_perp);
}

float fresnel_conductor(float cos_i, float eta, float k)
{
    cos_i = fminf(fmaxf(cos_i, 0.0f), 1.0f);
    float cos2 = cos_i * cos_i, sin2 = 1.0f - cos2;
    float eta2 = eta * eta, k2 = k * k;
    float t0 = eta2 - k2 - sin2;
    float a2b2 = sqrtf(t0 * t0 + 4.0f * eta2 * k2);
    float t1 = a2b2 + cos2;
    float a = sqrtf(fmaxf(0.0f, 0.5f * (a2b2 + t0)));
    float t2 = 2.0f * cos_i * a;
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = cos2 * a2b2 + sin2 * sin2;
    float t4 = t2 * sin2;
    float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (rp + rs);
}

Vec3 fresnel_conductor_rgb(float cos_i, Vec3 eta, Vec3 k)
{
    return v3(fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
              fresnel_conductor(cos_i, eta.z, k.z));
}

float fresnel_dielectric_average(float eta)
{
    /* 2 * integral_0^1 F(mu) mu dmu, midpoint rule: from outside there is
     * no critical angle and 64 steps are within 2e-5 (eta 1.1 to 2.4). */
    enum { STEPS = 64 };
    double sum = 0.0;
    for (int i = 0; i < STEPS; i++) {
        float mu = ((float)i + 0.5f) / STEPS;
        sum += fresnel_dielectric(mu, eta) * mu;
    }
    return (float)(2.0 * sum / STEPS);
}

typedef struct Preset {
    const char *name;
    float eta[3], k[3];
} Preset;

/* RGB fits of measured spectra (the values Mitsuba and pbrt's RGB modes
 * use at roughly 650, 550 and 450 nm). */
static const Preset presets[] = {
    {"gold", {0.143f, 0.374f, 1.442f}, {3.983f, 2.385f, 1.603f}},
    {"copper", {0.200f, 0.924f, 1.102f}, {3.912f, 2.452f, 2.142f}},
    {"aluminium", {1.657f, 0.880f, 0.521f}, {9.224f, 6.270f, 4.837f}},
    {"aluminum", {1.657f, 0.880f, 0.521f}, {9.224f, 6.270f, 4.837f}},
    {"silver", {0.155f, 0.117f, 0.138f}, {4.828f, 3.122f, 2.147f}},
};

int conductor_preset(const char *name, Vec3 *eta, Vec3 *k)
{
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; i++)
        if (strcmp(presets[i].name, name) == 0) {
            *eta = v3_load(presets[i].eta);
            *k = v3_load(presets[i].k);
            return 0;
        }
    return -1;
}

float conductor_k_from_reflectance(float r)
{
    r = fminf(fmaxf(r, 0.0f), 0.9999f);
    return 2.0f * sqrtf(r) / sqrtf(1.0f - r);
}

/* ------------------------------------------------------------ directions */

Vec3 bsdf_reflect(Vec3 wo, Vec3 n)
{
    return v3_sub(v3_scale(n, 2.0f * v3_dot(wo, n)), wo);
}

int bsdf_refract(Vec3 wo, Vec3 n, float eta, Vec3 *wt)
{
    float cos_i = v3_dot(wo, n);
    float sin2_t = fmaxf(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f)
        return 0;
    float cos_t = sqrtf(1.0f - sin2_t);
    *wt = v3_add(v3_scale(wo, -1.0f / eta), v3_scale(n, cos_i / eta - cos_t));
    return 1;
}

/* ------------------------------------------------------------ Lambertian */

float bsdf_lambert_eval(Vec3 wo, Vec3 wi)
{
    return wo.z > 0.0f && wi.z > 0.0f ? wi.z / PI_F : 0.0f;
}

float bsdf_lambert_pdf(Vec3 wo, Vec3 wi)
{
    return wo.z > 0.0f && wi.z > 0.0f ? wi.z / PI_F : 0.0f;
}

BsdfSample bsdf_lambert_sample(Vec3 wo, float u1, float u2)
{
    BsdfSample s = {local_dir(sqrtf(1.0f - u1), 2.0f * PI_F * u2), 0.0f, 0.0f, 0};
    if (wo.z <= 0.0f || s.wi.z <= 0.0f)
        return s;
    s.pdf = s.wi.z / PI_F;
    s.weight = 1.0f;
    return s;
}

/* ------------------------------------------------------------ Blinn-Phong */

/* The half vector of a reflection pair, or 0 if it is not a valid one
 * (below the surface or facing away from wo). */
static int half_vector(Vec3 wo, Vec3 wi, Vec3 *h)
{
    Vec3 s = v3_add(wo, wi);
    float len = v3_length(s);
    if (len <= 1e-7f)
        return 0;
    *h = v3_scale(s, 1.0f / len);
    return h->z > 0.0f && v3_dot(wo, *h) > 0.0f;
}

float bsdf_blinn_eval(Vec3 wo, Vec3 wi, float e)
{
    Vec3 h;
    if (wo.z <= 0.0f || wi.z <= 0.0f || !half_vector(wo, wi, &h))
        return 0.0f;
    return (e + 8.0f) / (8.0f * PI_F) * powf(h.z, e) * wi.z;
}

float bsdf_blinn_pdf(Vec3 wo, Vec3 wi, float e)
{
    Vec3 h;
    if (wo.z <= 0.0f || !half_vector(wo, wi, &h))
        return 0.0f;
    return (e + 1.0f) / (2.0f * PI_F) * powf(h.z, e) / (4.0f * v3_dot(wo, h));
}

static BsdfSample from_half(Vec3 wo, Vec3 h, float pdf_h)
{
    BsdfSample s = {v3(0, 0, 1), 0.0f, 0.0f, 0};
    float oh = v3_dot(wo, h);
    if (wo.z <= 0.0f || oh <= 0.0f)
        return s; /* no valid reflection: pdf 0 marks the sample wasted */
    s.wi = bsdf_reflect(wo, h);
    s.pdf = pdf_h / (4.0f * oh);
    return s;
}

BsdfSample bsdf_blinn_sample(Vec3 wo, float u1, float u2, float e)
{
    float cos_h = powf(u1, 1.0f / (e + 1.0f));
    Vec3 h = local_dir(cos_h, 2.0f * PI_F * u2);
    BsdfSample s = from_half(wo, h, (e + 1.0f) / (2.0f * PI_F) * powf(cos_h, e));
    if (s.pdf > 0.0f)
        s.pdf = bsdf_blinn_pdf(wo, s.wi, e); /* the same float as pdf() gives */
    if (s.pdf > 0.0f && s.wi.z > 0.0f)
        s.weight = bsdf_blinn_eval(wo, s.wi, e) / s.pdf;
    return s;
}

float bsdf_blinn_exponent_from_alpha(float alpha)
{
    return fmaxf(2.0f / fmaxf(alpha * alpha, 1e-8f) - 2.0f, 1.0f);
}

float bsdf_alpha_from_roughness(float roughness)
{
    return sqrtf(fmaxf(roughness, 0.0f));
}

/* ------------------------------------------------------------ GGX */

float bsdf_ggx_D(Vec3 h, float alpha)
{
    if (h.z <= 0.0f)
        return 0.0f;
    float a2 = alpha * alpha, c2 = h.z * h.z;
    float d = c2 * (a2 - 1.0f) + 1.0f;
    return a2 / (PI_F * d * d);
}

float bsdf_ggx_G1(Vec3 w, float alpha)
{
    if (w.z <= 0.0f)
        return 0.0f;
    float c2 = w.z * w.z, tan2 = (1.0f - c2) / c2;
    return 2.0f / (1.0f + sqrtf(1.0f + alpha * alpha * tan2));
}

/* Smith's Lambda for GGX (G1 = 1 / (1 + Lambda)); w above the surface. */
static float ggx_lambda(Vec3 w, float alpha)
{
    float c2 = w.z * w.z, tan2 = (1.0f - c2) / c2;
    return 0.5f * (sqrtf(1.0f + alpha * alpha * tan2) - 1.0f);
}

float bsdf_ggx_eval(Vec3 wo, Vec3 wi, float alpha)
{
    Vec3 h;
    if (wo.z <= 0.0f || wi.z <= 0.0f || !half_vector(wo, wi, &h))
        return 0.0f;
    /* the height-correlated G = 1 / (1 + Lambda(wo) + Lambda(wi)), pbrt-v4's */
    return bsdf_ggx_D(h, alpha) /
           ((1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha)) * (4.0f * wo.z));
}

float bsdf_ggx_pdf(Vec3 wo, Vec3 wi, float alpha)
{
    Vec3 h;
    if (wo.z <= 0.0f || !half_vector(wo, wi, &h))
        return 0.0f;
    return bsdf_ggx_D(h, alpha) * h.z / (4.0f * v3_dot(wo, h));
}

BsdfSample bsdf_ggx_sample(Vec3 wo, float u1, float u2, float alpha)
{
    /* D(h) cos(h) sampling: tan^2(theta_h) = alpha^2 u1 / (1 - u1). */
    float tan2 = alpha * alpha * u1 / fmaxf(1.0f - u1, 1e-7f);
    float cos_h = 1.0f / sqrtf(1.0f + tan2);
    Vec3 h = local_dir(cos_h, 2.0f * PI_F * u2);
    BsdfSample s = from_half(wo, h, bsdf_ggx_D(h, alpha) * cos_h);
    if (s.pdf > 0.0f)
        s.pdf = bsdf_ggx_pdf(wo, s.wi, alpha); /* the same float as pdf() gives */
    if (s.pdf > 0.0f && s.wi.z > 0.0f)
        s.weight = bsdf_ggx_eval(wo, s.wi, alpha) / s.pdf;
    return s;
}

float bsdf_ggx_refract_sample(Vec3 wo, float u1, float u2, float alpha, float eta, Vec3 *wt)
{
    float tan2 = alpha * alpha * u1 / fmaxf(1.0f - u1, 1e-7f);
    float cos_h = 1.0f / sqrtf(1.0f + tan2);
    Vec3 h = local_dir(cos_h, 2.0f * PI_F * u2);
    float oh = v3_dot(wo, h);
    if (wo.z <= 0.0f || oh <= 0.0f)
        return 0.0f;
    if (bsdf_refract(wo, h, eta, wt)) {
        if (wt->z >= 0.0f)
            return 0.0f; /* refracted back to wo's side */
    } else {
        *wt = bsdf_reflect(wo, h); /* total internal reflection at h */
        if (wt->z <= 0.0f)
            return 0.0f; /* reflected into the surface */
    }
    /* D(h) cos_h sampling: f |cos| / pdf, Fresnel left out, is
     * |wo.h| G / (wo.z h.z) either way (Walter et al. 2007, eq. 41) */
    Vec3 away = v3(wt->x, wt->y, fabsf(wt->z));
    return oh / ((1.0f + ggx_lambda(wo, alpha) + ggx_lambda(away, alpha)) * wo.z * cos_h);
}

/* ------------------------------------------------------------ smooth dielectric */

BsdfSample bsdf_dielectric_sample(Vec3 wo, float u1, float eta)
{
    BsdfSample s = {v3(-wo.x, -wo.y, wo.z), 1.0f, 0.0f, 1};
    float F = fresnel_dielectric(wo.z, eta);
    if (u1 < F)
        return s;
    Vec3 n = wo.z >= 0.0f ? v3(0, 0, 1) : v3(0, 0, -1);
    float rel = wo.z >= 0.0f ? eta : 1.0f / eta;
    if (!bsdf_refract(wo, n, rel, &s.wi))
        s.wi = v3(-wo.x, -wo.y, wo.z); /* not reached: F is 1 under TIR */
    return s;
}
