/*
 * shade/diffusion.h — diffusion profiles of multiple subsurface scattering
 * (memo section 6.2): Jensen et al. 2001's dipole and Christensen and
 * Burley 2015's normalized diffusion, their total diffuse reflectance, the
 * conversions between the ways materials give a medium (coefficients,
 * albedo and mean free path, RenderMan's diffuse mean free path), and
 * Jensen 2001's measured media.
 *
 * Units: lengths in mm, coefficients per mm, profiles per mm^2. One colour
 * channel at a time. Pure functions; thread-safe.
 */
#ifndef RAYES_SHADE_DIFFUSION_H
#define RAYES_SHADE_DIFFUSION_H

#include "rayes/shader.h"

/* One channel of a medium, ready for the profile. */
typedef struct DiffusionChannel {
    int profile;    /* RayesSubsurfaceProfile */
    float alpha;    /* reduced albedo alpha' = sigma_s' / sigma_t' */
    float sigma_tr; /* effective transport coefficient sqrt(3 sigma_a sigma_t'), per mm */
    float zr, zv;   /* dipole: depths of the real and virtual sources, mm */
    float Rd;       /* total diffuse reflectance (the profile's integral over the plane) */
    float d;        /* Burley: the shape parameter dmfp / s, mm (dmfp = 1 / sigma_tr) */
} DiffusionChannel;

/* Donner and Jensen's fit of the diffuse Fresnel reflectance for relative
 * index eta, and Jensen's A = (1 + Fdr) / (1 - Fdr). */
float diffusion_fdr(float eta);
float diffusion_A(float eta);

/* The dipole's total diffuse reflectance of a semi-infinite medium of reduced
 * albedo alpha (Jensen 2001, eq. 8): (alpha / 2)(1 + exp(-4/3 A sqrt(3(1 -
 * alpha)))) exp(-sqrt(3(1 - alpha))). Increasing in alpha. */
float diffusion_total_reflectance(float alpha, float eta);

/* The reduced albedo whose total diffuse reflectance is Rd (bisection on
 * diffusion_total_reflectance; Rd clamped to what alpha in [0, 1] gives). */
float diffusion_albedo_from_reflectance(float Rd, float eta);

/* Channel c of the medium p (its sigma_s' and sigma_a), for p->profile. */
void diffusion_channel(const RayesSubsurfaceParams *p, int c, DiffusionChannel *ch);

/* The profile R(r) per mm^2 at distance r mm: its integral over the plane,
 * 2 pi r R(r) dr, is ch->Rd. */
float diffusion_profile(const DiffusionChannel *ch, float r);

/* The surface area (t's units squared) one of n rays cast uniformly over
 * the sphere stands for where it hits a surface at distance t and cosine
 * cos_x between the ray and the surface's normal (memo 6.2): 4 pi / n t^2 /
 * cos_x, cos_x clamped below at min_cos. */
static inline float diffusion_sample_area(int n, float t, float cos_x, float min_cos)
{
    return 4.0f * 3.14159265358979f / (float)n * t * t / (cos_x > min_cos ? cos_x : min_cos);
}

/* The medium of total diffuse reflectance Rd and diffuse mean free path
 * dmfp (mm, 1 / sigma_tr; RenderMan's classic "albedo" and
 * "diffusemeanfreepath"), or of reflectance Rd and volume mean free path
 * mfp (mm, 1 / sigma_t'; pbrt-v4's "reflectance" and "mfp"): writes
 * sigma_s' and sigma_a of channel c. */
void diffusion_from_dmfp(float Rd, float dmfp, float eta, float *sigma_s, float *sigma_a);
void diffusion_from_mfp(float Rd, float mfp, float eta, float *sigma_s, float *sigma_a);

/* Jensen 2001's measured media (Figure 5, per mm, eta 1.3; util/media.h),
 * by name (case-insensitive; "skin1", "marble", "wholemilk", ...). Returns
 * 0 and fills sigma_s' and sigma_a, or -1 for an unknown name. */
int diffusion_preset(const char *name, float sigma_s[3], float sigma_a[3]);

#endif /* RAYES_SHADE_DIFFUSION_H */
