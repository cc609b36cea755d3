/*
 * shade/hair.c — pbrt-v4's hair BSDF (shade/hair.h): the model of Chiang
 * et al. 2016 as pbrt-v4 writes it (Physically Based Rendering, 4th
 * edition, 9.9), in RGB.
 */
#include "shade/hair.h"

#include <math.h>

#include "shade/bsdf.h"

#define PI_F 3.14159265358979f

static float sqr(float x)
{
    return x * x;
}

static float safe_sqrt(float x)
{
    return sqrtf(fmaxf(x, 0.0f));
}

static float safe_asin(float x)
{
    return asinf(fminf(fmaxf(x, -1.0f), 1.0f));
}

/* The modified Bessel function of the first kind I0, by its series, and
 * its logarithm (asymptotic beyond 12). */
static float bessel_i0(float x)
{
    float val = 0.0f, x2i = 1.0f, i4 = 1.0f, ifact = 1.0f;
    for (int i = 0; i < 10; i++) {
        if (i > 1)
            ifact *= (float)i;
        val += x2i / (i4 * ifact * ifact);
        x2i *= x * x;
        i4 *= 4.0f;
    }
    return val;
}

static float log_i0(float x)
{
    if (x > 12.0f)
        return x + 0.5f * (-logf(2.0f * PI_F) + logf(1.0f / x) + 1.0f / (8.0f * x));
    return logf(bessel_i0(x));
}

/* d'Eon's longitudinal scattering of variance v; for narrow lobes through
 * logarithms, which keep it finite. */
static float lobe_m(float cos_i, float cos_o, float sin_i, float sin_o, float v)
{
    float a = cos_i * cos_o / v, b = sin_i * sin_o / v;
    if (v <= 0.1f)
        return expf(log_i0(a) - b - 1.0f / v + 0.6931f + logf(1.0f / (2.0f * v)));
    return expf(-b) * bessel_i0(a) / (sinhf(1.0f / v) * 2.0f * v);
}

/* The attenuation of each lobe for the view's cos theta_o and the
 * transmittance T of one crossing; ap[HAIR_LOBES] sums the rest. */
static void lobe_a(float cos_o, float eta, float h, Vec3 T, Vec3 ap[HAIR_LOBES + 1])
{
    float f = fresnel_dielectric(cos_o * safe_sqrt(1.0f - h * h), eta);
    ap[0] = v3(f, f, f);
    ap[1] = v3_scale(T, sqr(1.0f - f));
    for (int p = 2; p < HAIR_LOBES; p++)
        ap[p] = v3_scale(v3_mul(ap[p - 1], T), f);
    Vec3 tf = v3_scale(T, f), rest = v3_mul(v3_scale(ap[HAIR_LOBES - 1], f), T);
    ap[HAIR_LOBES] = v3(rest.x / (1.0f - tf.x), rest.y / (1.0f - tf.y), rest.z / (1.0f - tf.z));
}

/* The azimuth a path of lobe p turns through. */
static float lobe_phi(int p, float gamma_o, float gamma_t)
{
    return 2.0f * (float)p * gamma_t - 2.0f * gamma_o + (float)p * PI_F;
}

static float logistic(float x, float s)
{
    x = fabsf(x);
    float e = expf(-x / s);
    return e / (s * sqr(1.0f + e));
}

static float logistic_cdf(float x, float s)
{
    return 1.0f / (1.0f + expf(-x / s));
}

/* The logistic trimmed to [-pi, pi], normalised there. */
static float trimmed_logistic(float x, float s)
{
    return logistic(x, s) / (logistic_cdf(PI_F, s) - logistic_cdf(-PI_F, s));
}

static float sample_trimmed_logistic(float u, float s)
{
    float lo = logistic_cdf(-PI_F, s), k = logistic_cdf(PI_F, s) - lo;
    float x = -s * logf(1.0f / (u * k + lo) - 1.0f);
    return fminf(fmaxf(x, -PI_F), PI_F);
}

/* An angle taken into [-pi, pi]. */
static float wrap_pi(float a)
{
    if (!isfinite(a))
        return 0.0f;
    a = fmodf(a + PI_F, 2.0f * PI_F);
    return a < 0.0f ? a + PI_F : a - PI_F;
}

static float lobe_n(float phi, int p, float s, float gamma_o, float gamma_t)
{
    return trimmed_logistic(wrap_pi(phi - lobe_phi(p, gamma_o, gamma_t)), s);
}

void hair_bsdf_init(HairBsdf *b, float h, float eta, Vec3 sigma_a, float beta_m, float beta_n,
                    float alpha)
{
    b->h = fminf(fmaxf(h, -1.0f), 1.0f);
    b->gamma_o = safe_asin(b->h);
    b->eta = eta > 1.0f ? eta : 1.55f;
    b->sigma_a = v3(fmaxf(sigma_a.x, 0.0f), fmaxf(sigma_a.y, 0.0f), fmaxf(sigma_a.z, 0.0f));
    beta_m = fminf(fmaxf(beta_m, 1e-3f), 1.0f);
    beta_n = fminf(fmaxf(beta_n, 1e-3f), 1.0f);
    b->v[0] = sqr(0.726f * beta_m + 0.812f * sqr(beta_m) + 3.7f * powf(beta_m, 20.0f));
    b->v[1] = 0.25f * b->v[0];
    b->v[2] = 4.0f * b->v[0];
    for (int p = 3; p <= HAIR_LOBES; p++)
        b->v[p] = b->v[2];
    b->s = 0.626657069f * (0.265f * beta_n + 1.194f * sqr(beta_n) + 5.372f * powf(beta_n, 22.0f));
    b->sin2k[0] = sinf(alpha * PI_F / 180.0f);
    b->cos2k[0] = safe_sqrt(1.0f - sqr(b->sin2k[0]));
    for (int i = 1; i < 3; i++) {
        b->sin2k[i] = 2.0f * b->cos2k[i - 1] * b->sin2k[i - 1];
        b->cos2k[i] = sqr(b->cos2k[i - 1]) - sqr(b->sin2k[i - 1]);
    }
}

/* The view's angles and the crossing's transmittance and gamma_t. */
typedef struct HairView {
    float sin_o, cos_o, phi_o, gamma_t;
    Vec3 T;
} HairView;

static HairView hair_view(const HairBsdf *b, Vec3 wo)
{
    HairView v;
    v.sin_o = fminf(fmaxf(wo.x, -1.0f), 1.0f);
    v.cos_o = safe_sqrt(1.0f - sqr(v.sin_o));
    v.phi_o = atan2f(wo.z, wo.y);
    float sin_t = v.sin_o / b->eta, cos_t = safe_sqrt(1.0f - sqr(sin_t));
    float etap = safe_sqrt(sqr(b->eta) - sqr(v.sin_o)) / fmaxf(v.cos_o, 1e-7f);
    float sin_gt = b->h / etap, cos_gt = safe_sqrt(1.0f - sqr(sin_gt));
    v.gamma_t = safe_asin(sin_gt);
    float len = 2.0f * cos_gt / fmaxf(cos_t, 1e-7f);
    v.T = v3(expf(-b->sigma_a.x * len), expf(-b->sigma_a.y * len), expf(-b->sigma_a.z * len));
    return v;
}

/* theta_o tilted by the scales for lobe p (R toward the root by 2 alpha,
 * TT away by alpha, TRT away by 4 alpha). */
static void tilt(const HairBsdf *b, int p, float sin_o, float cos_o, float *sp, float *cp)
{
    if (p == 0) {
        *sp = sin_o * b->cos2k[1] - cos_o * b->sin2k[1];
        *cp = cos_o * b->cos2k[1] + sin_o * b->sin2k[1];
    } else if (p == 1) {
        *sp = sin_o * b->cos2k[0] + cos_o * b->sin2k[0];
        *cp = cos_o * b->cos2k[0] - sin_o * b->sin2k[0];
    } else {
        *sp = sin_o * b->cos2k[2] + cos_o * b->sin2k[2];
        *cp = cos_o * b->cos2k[2] - sin_o * b->sin2k[2];
    }
    *cp = fabsf(*cp);
}

Vec3 hair_bsdf_f(const HairBsdf *b, Vec3 wo, Vec3 wi)
{
    HairView v = hair_view(b, wo);
    float sin_i = fminf(fmaxf(wi.x, -1.0f), 1.0f), cos_i = safe_sqrt(1.0f - sqr(sin_i));
    float phi = atan2f(wi.z, wi.y) - v.phi_o;
    Vec3 ap[HAIR_LOBES + 1], sum = v3(0, 0, 0);
    lobe_a(v.cos_o, b->eta, b->h, v.T, ap);
    for (int p = 0; p < HAIR_LOBES; p++) {
        float sp, cp;
        tilt(b, p, v.sin_o, v.cos_o, &sp, &cp);
        float w =
            lobe_m(cos_i, cp, sin_i, sp, b->v[p]) * lobe_n(phi, p, b->s, b->gamma_o, v.gamma_t);
        sum = v3_madd(sum, ap[p], w);
    }
    float m = lobe_m(cos_i, v.cos_o, sin_i, v.sin_o, b->v[HAIR_LOBES]);
    sum = v3_madd(sum, ap[HAIR_LOBES], m / (2.0f * PI_F));
    return isfinite(sum.x + sum.y + sum.z) ? sum : v3(0, 0, 0);
}

/* The lobes' shares of the attenuation, the sampling's choice. */
static void lobe_pdf(const HairBsdf *b, const HairView *v, float share[HAIR_LOBES + 1])
{
    Vec3 ap[HAIR_LOBES + 1];
    lobe_a(v->cos_o, b->eta, b->h, v->T, ap);
    float sum = 0.0f;
    for (int p = 0; p <= HAIR_LOBES; p++) {
        share[p] = (ap[p].x + ap[p].y + ap[p].z) / 3.0f;
        sum += share[p];
    }
    for (int p = 0; p <= HAIR_LOBES; p++)
        share[p] = sum > 0.0f ? share[p] / sum : (p == 0 ? 1.0f : 0.0f);
}

static float pdf_at(const HairBsdf *b, const HairView *v, Vec3 wi)
{
    float share[HAIR_LOBES + 1];
    lobe_pdf(b, v, share);
    float sin_i = fminf(fmaxf(wi.x, -1.0f), 1.0f), cos_i = safe_sqrt(1.0f - sqr(sin_i));
    float phi = atan2f(wi.z, wi.y) - v->phi_o, pdf = 0.0f;
    for (int p = 0; p < HAIR_LOBES; p++) {
        float sp, cp;
        tilt(b, p, v->sin_o, v->cos_o, &sp, &cp);
        pdf += lobe_m(cos_i, cp, sin_i, sp, b->v[p]) * share[p] *
               lobe_n(phi, p, b->s, b->gamma_o, v->gamma_t);
    }
    pdf += lobe_m(cos_i, v->cos_o, sin_i, v->sin_o, b->v[HAIR_LOBES]) * share[HAIR_LOBES] /
           (2.0f * PI_F);
    return isfinite(pdf) ? pdf : 0.0f;
}

float hair_bsdf_pdf(const HairBsdf *b, Vec3 wo, Vec3 wi)
{
    HairView v = hair_view(b, wo);
    return pdf_at(b, &v, wi);
}

int hair_bsdf_sample(const HairBsdf *b, Vec3 wo, float uc, float u0, float u1, Vec3 *wi, float *pdf)
{
    HairView v = hair_view(b, wo);
    float share[HAIR_LOBES + 1];
    lobe_pdf(b, &v, share);
    int p = 0;
    while (p < HAIR_LOBES && uc >= share[p]) {
        uc -= share[p];
        p++;
    }
    uc = share[p] > 0.0f ? fminf(uc / share[p], 0.99999994f) : 0.5f;
    float sp = v.sin_o, cp = v.cos_o;
    if (p < HAIR_LOBES)
        tilt(b, p, v.sin_o, v.cos_o, &sp, &cp);
    /* M_p: theta_i about the (tilted) mirror of theta_o */
    u0 = fmaxf(u0, 1e-5f);
    float cos_t = 1.0f + b->v[p] * logf(u0 + (1.0f - u0) * expf(-2.0f / b->v[p]));
    float sin_t = safe_sqrt(1.0f - sqr(cos_t)), cos_phi = cosf(2.0f * PI_F * u1);
    float sin_i = -cos_t * sp + sin_t * cos_phi * cp, cos_i = safe_sqrt(1.0f - sqr(sin_i));
    /* N_p: the azimuth about the lobe's exit */
    float dphi = p < HAIR_LOBES
                     ? lobe_phi(p, b->gamma_o, v.gamma_t) + sample_trimmed_logistic(uc, b->s)
                     : 2.0f * PI_F * uc;
    float phi_i = v.phi_o + dphi;
    *wi = v3(sin_i, cos_i * cosf(phi_i), cos_i * sinf(phi_i));
    *pdf = pdf_at(b, &v, *wi);
    return *pdf > 0.0f && isfinite(sin_i);
}

Vec3 hair_bsdf_mean_albedo(float eta, Vec3 sigma_a, float beta_m, float beta_n, float alpha)
{
    const int nv = HAIR_ALBEDO_VIEWS, nd = HAIR_ALBEDO_DRAWS;
    Vec3 sum = v3(0, 0, 0);
    float total = 0.0f;
    for (int a = 0; a < nv; a++) {
        float sin_o = -1.0f + 2.0f * ((float)a + 0.5f) / (float)nv;
        Vec3 wo = v3(sin_o, safe_sqrt(1.0f - sin_o * sin_o), 0.0f);
        for (int k = 0; k < nv; k++) {
            /* offsets h = sin(gamma), gamma evenly spaced: the Fresnel term
             * turns steeply near the edges, where the nodes crowd */
            float gamma = PI_F * (((float)k + 0.5f) / (float)nv - 0.5f), weight = cosf(gamma);
            HairBsdf b;
            hair_bsdf_init(&b, sinf(gamma), eta, sigma_a, beta_m, beta_n, alpha);
            Vec3 part = v3(0, 0, 0);
            for (int d = 0; d < nd; d++) {
                /* an 8 x 4 lattice for M_p, shuffled for the lobe and N_p */
                float u0 = ((float)(d % 8) + 0.5f) / 8.0f, u1 = ((float)(d / 8) + 0.5f) / 4.0f;
                float uc = ((float)((d * 13 + a + 3 * k) % nd) + 0.5f) / (float)nd, pdf;
                Vec3 wi;
                if (hair_bsdf_sample(&b, wo, uc, u0, u1, &wi, &pdf))
                    part = v3_madd(part, hair_bsdf_f(&b, wo, wi), 1.0f / pdf);
            }
            sum = v3_madd(sum, part, weight);
            total += weight * (float)nd;
        }
    }
    return v3_scale(sum, 1.0f / total);
}

Vec3 hair_sigma_a_from_melanin(float eumelanin, float pheomelanin)
{
    return v3(eumelanin * 0.419f + pheomelanin * 0.187f, eumelanin * 0.697f + pheomelanin * 0.4f,
              eumelanin * 1.37f + pheomelanin * 1.05f);
}

/* Chiang et al.'s fit: sqrt(sigma_a) = -ln(c) / d(beta_n). */
static float reflectance_fit(float bn)
{
    return 5.969f - 0.215f * bn + 2.532f * sqr(bn) - 10.73f * bn * sqr(bn) + 5.574f * sqr(sqr(bn)) +
           0.245f * bn * sqr(sqr(bn));
}

Vec3 hair_sigma_a_from_reflectance(Vec3 c, float beta_n)
{
    float d = reflectance_fit(beta_n), in[3] = {c.x, c.y, c.z}, out[3];
    for (int k = 0; k < 3; k++)
        out[k] = sqr(logf(fminf(fmaxf(in[k], 1e-4f), 1.0f)) / d);
    return v3(out[0], out[1], out[2]);
}

Vec3 hair_reflectance_from_sigma_a(Vec3 sigma_a, float beta_n)
{
    float d = reflectance_fit(beta_n);
    return v3(expf(-safe_sqrt(sigma_a.x) * d), expf(-safe_sqrt(sigma_a.y) * d),
              expf(-safe_sqrt(sigma_a.z) * d));
}
