/*
 * shade/diffusion.c — diffusion profiles of subsurface scattering
 * (diffusion.h; memo section 6.2).
 */
#include "shade/diffusion.h"

#include <math.h>

#include "util/media.h"

#define DIFFUSION_PI 3.14159265358979f

float diffusion_fdr(float eta)
{
    return -1.440f / (eta * eta) + 0.710f / eta + 0.668f + 0.0636f * eta;
}

float diffusion_A(float eta)
{
    float fdr = diffusion_fdr(eta);
    return (1.0f + fdr) / (1.0f - fdr);
}

float diffusion_total_reflectance(float alpha, float eta)
{
    float s = sqrtf(3.0f * fmaxf(1.0f - alpha, 0.0f));
    return 0.5f * alpha * (1.0f + expf(-4.0f / 3.0f * diffusion_A(eta) * s)) * expf(-s);
}

/* Newton's method kept inside a bracket that every step narrows (a step
 * that leaves it bisects instead): Rd rises with alpha, steeply near 1.
 * Shaders convert their parameters at every call (RenderMan's albedo and
 * diffuse mean free path, pbrt's reflectance and mfp), so this is on the
 * shading path: 4 to 8 steps of two exponentials against 40 bisections. */
float diffusion_albedo_from_reflectance(float Rd, float eta)
{
    float A = diffusion_A(eta), lo = 0.0f, hi = 1.0f, a = 0.5f;
    for (int k = 0; k < 60; k++) {
        float s = sqrtf(3.0f * (1.0f - a)), e1 = expf(-4.0f / 3.0f * A * s), e2 = expf(-s);
        float f = 0.5f * a * (1.0f + e1) * e2 - Rd;
        if (f < 0.0f)
            lo = a;
        else
            hi = a;
        /* dRd/dalpha = dRd/dalpha at fixed s + dRd/ds ds/dalpha, ds/dalpha = -3 / (2 s) */
        float dfds = -0.5f * a * e2 * (4.0f / 3.0f * A * e1 + 1.0f + e1);
        float df = 0.5f * (1.0f + e1) * e2 + (s > 0.0f ? dfds * -1.5f / s : 0.0f);
        float next = df > 0.0f ? a - f / df : 0.5f * (lo + hi);
        if (!(next > lo && next < hi))
            next = 0.5f * (lo + hi);
        if (fabsf(next - a) <= 1e-7f || hi - lo <= 1e-7f)
            return next;
        a = next;
    }
    return a;
}

/* Reduced albedos this close to 1 give sigma_tr = 0: no absorption, light
 * diffuses without end; keep a trace of it so the profile stays finite. */
#define DIFFUSION_MAX_ALBEDO 0.99999f

void diffusion_channel(const RayesSubsurfaceParams *p, int c, DiffusionChannel *ch)
{
    float ss = fmaxf(p->sigma_s[c], 0.0f), sa = fmaxf(p->sigma_a[c], 0.0f);
    float st = fmaxf(ss + sa, 1e-6f);
    float eta = p->eta > 0.0f ? p->eta : 1.3f;
    ch->profile = p->profile;
    ch->alpha = fminf(ss / st, DIFFUSION_MAX_ALBEDO);
    sa = fmaxf(sa, st * (1.0f - DIFFUSION_MAX_ALBEDO));
    ch->sigma_tr = sqrtf(3.0f * sa * st);
    ch->zr = 1.0f / st;
    ch->zv = ch->zr * (1.0f + 4.0f / 3.0f * diffusion_A(eta));
    ch->Rd = diffusion_total_reflectance(ch->alpha, eta);
    /* Burley's d = l / s for the diffuse mean free path l = 1 / sigma_tr,
     * with the paper's fit of s for that length, s = 3.5 + 100 (A - 0.33)^4
     * (Christensen and Burley 2015, section 5; the searchlight fit
     * 1.85 - A + 7 |A - 0.8|^3 is for the mean free path 1 / sigma_t), and
     * A the dipole's total reflectance: the same total as the dipole. */
    float a = ch->Rd - 0.33f;
    ch->d = 1.0f / (ch->sigma_tr * (3.5f + 100.0f * a * a * a * a));
}

/* Jensen 2001, eq. 4: the real source at depth zr and the virtual one at
 * -zv seen from distance r along the surface. */
static float dipole(const DiffusionChannel *ch, float r)
{
    float dr = sqrtf(r * r + ch->zr * ch->zr), dv = sqrtf(r * r + ch->zv * ch->zv);
    float s = ch->sigma_tr;
    float real = ch->zr * (s * dr + 1.0f) * expf(-s * dr) / (dr * dr * dr);
    float virt = ch->zv * (s * dv + 1.0f) * expf(-s * dv) / (dv * dv * dv);
    return ch->alpha / (4.0f * DIFFUSION_PI) * (real + virt);
}

/* Christensen and Burley 2015, eq. 2: A s (e^{-s r / l} + e^{-s r / 3l}) /
 * (8 pi l r), with d = l / s; r is kept off 0 (the profile's 1/r is
 * integrable, a sample exactly at 0 is not). */
static float burley(const DiffusionChannel *ch, float r)
{
    float d = ch->d;
    r = fmaxf(r, 1e-3f * d);
    return ch->Rd * (expf(-r / d) + expf(-r / (3.0f * d))) / (8.0f * DIFFUSION_PI * d * r);
}

float diffusion_profile(const DiffusionChannel *ch, float r)
{
    return ch->profile == RAYES_SUBSURFACE_BURLEY ? burley(ch, r) : dipole(ch, r);
}

void diffusion_from_dmfp(float Rd, float dmfp, float eta, float *sigma_s, float *sigma_a)
{
    float alpha = fminf(diffusion_albedo_from_reflectance(Rd, eta), DIFFUSION_MAX_ALBEDO);
    float st = 1.0f / (fmaxf(dmfp, 1e-6f) * sqrtf(3.0f * (1.0f - alpha)));
    *sigma_s = alpha * st;
    *sigma_a = st - *sigma_s;
}

void diffusion_from_mfp(float Rd, float mfp, float eta, float *sigma_s, float *sigma_a)
{
    float alpha = fminf(diffusion_albedo_from_reflectance(Rd, eta), DIFFUSION_MAX_ALBEDO);
    float st = 1.0f / fmaxf(mfp, 1e-6f);
    *sigma_s = alpha * st;
    *sigma_a = st - *sigma_s;
}

int diffusion_preset(const char *name, float sigma_s[3], float sigma_a[3])
{
    const MeasuredMedium *m = media_find(name);
    if (!m)
        return -1;
    for (int c = 0; c < 3; c++) {
        sigma_s[c] = m->sigma_s[c];
        sigma_a[c] = m->sigma_a[c];
    }
    return 0;
}
