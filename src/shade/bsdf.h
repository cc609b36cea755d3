/*
 * shade/bsdf.h — the scattering functions of the built-in shaders, in a
 * local shading frame (z is the normal, wo and wi unit, both pointing away
 * from the surface), and Fresnel.
 *
 * Each non-delta lobe has eval (f * |cos wi|), sample and pdf (solid angle
 * measure). Lobes are scalar shapes of unit albedo scale: shaders multiply
 * colours and Fresnel in. A sample's weight is eval / pdf (0 when the
 * sample is below the surface and so is wasted).
 *
 *   Lambertian         f = 1/pi, cosine sampled
 *   Blinn-Phong        f = (e + 8) / (8 pi) (N.H)^e, the lobe of the
 *                      renderer's direct_lighting service; sampled by the
 *                      half vector, pdf_h = (e + 1) / (2 pi) (N.H)^e
 *   GGX                Trowbridge-Reitz D with Smith's height-correlated
 *                      G = 1 / (1 + Lambda(wo) + Lambda(wi)) (pbrt-v4's),
 *                      f = D G / (4 cos_o cos_i); sampled by D(h) cos(h)
 *   smooth dielectric  delta reflection and refraction, chosen by Fresnel
 *
 * Pure functions: thread-safe.
 */
#ifndef RAYES_SHADE_BSDF_H
#define RAYES_SHADE_BSDF_H

#include "util/vec.h"

typedef struct BsdfSample {
    Vec3 wi;      /* the sampled direction */
    float weight; /* eval / pdf; for delta lobes the throughput */
    float pdf;    /* solid-angle density; 0 for delta lobes */
    int delta;    /* 1: a delta lobe (eval and pdf are 0 everywhere) */
} BsdfSample;

/* ---- Fresnel */

/* Exact unpolarised reflectance of a smooth dielectric boundary for light
 * arriving at cos_i (> 0 on the outside, the side of the normal) and
 * eta = n_inside / n_outside. cos_i < 0 means from the inside (eta is then
 * inverted). 1 under total internal reflection. */
float fresnel_dielectric(float cos_i, float eta);

/* Exact unpolarised reflectance of a conductor of complex index
 * eta + i k (relative to the outside medium) at cos_i in [0, 1]. */
float fresnel_conductor(float cos_i, float eta, float k);

/* fresnel_conductor per RGB channel. */
Vec3 fresnel_conductor_rgb(float cos_i, Vec3 eta, Vec3 k);

/* The hemispherical average 2 * integral of F(mu) mu dmu of
 * fresnel_dielectric from outside: the share of diffuse light a coat
 * reflects. */
float fresnel_dielectric_average(float eta);

/* The complex index (RGB) of a named metal: "gold", "copper",
 * "aluminium" (or "aluminum"), "silver". Returns 0, or -1 for other names. */
int conductor_preset(const char *name, Vec3 *eta, Vec3 *k);

/* eta = 1, k such that the normal-incidence reflectance is r (pbrt-v4's
 * "reflectance" conductors): k = 2 sqrt(r) / sqrt(1 - r). */
float conductor_k_from_reflectance(float r);

/* ---- directions */

/* Mirror of wo about the normal n (both pointing away). */
Vec3 bsdf_reflect(Vec3 wo, Vec3 n);

/* Refraction of wo (pointing away, on the side of n) through a boundary
 * of relative index eta = n_transmitted / n_incident: writes the
 * transmitted direction (pointing away, on the other side) and returns 1,
 * or returns 0 under total internal reflection. */
int bsdf_refract(Vec3 wo, Vec3 n, float eta, Vec3 *wt);

/* ---- Lambertian */
float bsdf_lambert_eval(Vec3 wo, Vec3 wi);
float bsdf_lambert_pdf(Vec3 wo, Vec3 wi);
BsdfSample bsdf_lambert_sample(Vec3 wo, float u1, float u2);

/* ---- normalised Blinn-Phong, exponent e > 0 */
float bsdf_blinn_eval(Vec3 wo, Vec3 wi, float e);
float bsdf_blinn_pdf(Vec3 wo, Vec3 wi, float e);
BsdfSample bsdf_blinn_sample(Vec3 wo, float u1, float u2, float e);

/* Blinn-Phong exponent of a GGX lobe of width alpha (Walter et al.'s
 * mapping e = 2 / alpha^2 - 2, at least 1), and alpha from the roughness
 * of pbrt-v4 materials (remaproughness: alpha = sqrt(roughness)). */
float bsdf_blinn_exponent_from_alpha(float alpha);
float bsdf_alpha_from_roughness(float roughness);

/* ---- GGX microfacet reflection, width alpha > 0 (no Fresnel: F = 1) */
float bsdf_ggx_D(Vec3 h, float alpha);
float bsdf_ggx_G1(Vec3 w, float alpha);
float bsdf_ggx_eval(Vec3 wo, Vec3 wi, float alpha);
float bsdf_ggx_pdf(Vec3 wo, Vec3 wi, float alpha);
BsdfSample bsdf_ggx_sample(Vec3 wo, float u1, float u2, float alpha);

/* Rough refraction through a GGX surface of width alpha and relative
 * index eta (the far side's over wo's; wo.z > 0): a microfacet normal h
 * drawn as bsdf_ggx_sample draws it, wo refracted through it into *wt
 * (wt.z < 0), or where h reflects totally, wo reflected about it (wt.z >
 * 0: light leaving glass at a steep microfacet stays inside). Returns the
 * sample's weight without Fresnel, |wo.h| G / (wo.z h.z) (Walter et al.
 * 2007), whose mean is the share of light the lobe passes on (below 1 by
 * what Smith's G loses), or 0 when h gives nothing (a refraction back to
 * wo's side). */
float bsdf_ggx_refract_sample(Vec3 wo, float u1, float u2, float alpha, float eta, Vec3 *wt);

/* ---- smooth dielectric, eta = n_inside / n_outside; wo on either side
 * (wo.z < 0: from the inside). u1 picks reflection with probability F;
 * weight is 1 (radiance is not scaled by eta^2: closed objects). */
BsdfSample bsdf_dielectric_sample(Vec3 wo, float u1, float eta);

#endif /* RAYES_SHADE_BSDF_H */
