/*
 * shade/hair.h — scattering by a dielectric fibre (hair, fur): pbrt-v4's
 * hair BSDF, Chiang, Bitterli, Tappan and Burley 2016 after d'Eon et al.
 * 2011 and Marschner et al. 2003. Light reflects off the cuticle (R),
 * crosses the fibre (TT) or reflects once inside it (TRT), and the rest
 * (TRTT and beyond) is summed into one lobe spread over every azimuth.
 * Each lobe is a longitudinal term M_p (d'Eon's, of variance v_p from the
 * roughness beta_m, tilted by the cuticle's scales alpha) times an
 * attenuation A_p (Fresnel and the absorption sigma_a along the path
 * inside) times an azimuthal term N_p (a trimmed logistic of width s from
 * beta_n about the path's exit azimuth).
 *
 * Directions are in the fibre's frame: x along the fibre, y and z any
 * two unit vectors completing it (only the azimuth difference counts).
 * h in [-1, 1] is where the ray met the fibre's width (0: its axis).
 * Pure functions; thread-safe.
 */
#ifndef RAYES_SHADE_HAIR_H
#define RAYES_SHADE_HAIR_H

#include "util/vec.h"

#define HAIR_LOBES 3 /* R, TT, TRT; the rest is lobe HAIR_LOBES */

/* One point's fibre as seen from one viewing direction. */
typedef struct HairBsdf {
    float h, gamma_o, eta, s; /* offset, its angle, index, azimuthal width */
    float v[HAIR_LOBES + 1];  /* longitudinal variances */
    float sin2k[3], cos2k[3]; /* sin and cos of 2^k alpha, the scales' tilt */
    Vec3 sigma_a;             /* absorption per unit of the fibre's radius */
} HairBsdf;

/* beta_m, beta_n in [0, 1] (longitudinal and azimuthal roughness), alpha
 * the scales' angle in degrees, eta the fibre's index (pbrt's defaults:
 * 0.3, 0.3, 2, 1.55). */
void hair_bsdf_init(HairBsdf *b, float h, float eta, Vec3 sigma_a, float beta_m, float beta_n,
                    float alpha);

/* f(wo, wi) |cos| as pbrt-v4's integrator weighs it: the sum over lobes
 * of M_p A_p N_p (pbrt's f divided by |cos theta_i| about the normal,
 * times it again), so that light L arriving from wi leaves toward wo as
 * L times this per unit solid angle. wo and wi unit, in the fibre's
 * frame. */
Vec3 hair_bsdf_f(const HairBsdf *b, Vec3 wo, Vec3 wi);

/* The solid-angle density of hair_bsdf_sample drawing wi. */
float hair_bsdf_pdf(const HairBsdf *b, Vec3 wo, Vec3 wi);

/* A direction drawn from the lobes (chosen by their attenuation's share,
 * uc, then reused), M_p (u0, u1) and N_p (uc): wi and its density.
 * Returns 0 when none was drawn. */
int hair_bsdf_sample(const HairBsdf *b, Vec3 wo, float uc, float u0, float u1, Vec3 *wi,
                     float *pdf);

/* The fibre's albedo (the BSDF's integral over the sphere) averaged over
 * views (uniform in sin theta_o) and offsets h, by a fixed stratified
 * quadrature of HAIR_ALBEDO_VIEWS x HAIR_ALBEDO_VIEWS (view, offset)
 * pairs with HAIR_ALBEDO_DRAWS draws each: deterministic, within about
 * 1% (1 where sigma_a is 0): what a Lambertian stand-in for the fibre
 * reflects (the light diffuse rays read off hair). */
#define HAIR_ALBEDO_VIEWS 8
#define HAIR_ALBEDO_DRAWS 32
Vec3 hair_bsdf_mean_albedo(float eta, Vec3 sigma_a, float beta_m, float beta_n, float alpha);

/* sigma_a from melanin concentrations (eumelanin, pheomelanin: pbrt's
 * RGB coefficients), from the colour c the fibre shows after multiple
 * scattering in a mass of hair (Chiang et al.'s fit for beta_n), and back. */
Vec3 hair_sigma_a_from_melanin(float eumelanin, float pheomelanin);
Vec3 hair_sigma_a_from_reflectance(Vec3 c, float beta_n);
Vec3 hair_reflectance_from_sigma_a(Vec3 sigma_a, float beta_n);

#endif /* RAYES_SHADE_HAIR_H */
