/*
 * render/irradiance.h — irradiance records with gradients (Ward 1988; Ward
 * and Heckbert 1992), for irradiance interpolation at diffuse depth 0 (the
 * memo's section 5.2; technical digest section 3).
 *
 * A record is computed from M x N stratified cosine-weighted samples of
 * the hemisphere of n: cell (j, k) spans sin^2(theta) in [j/M, (j+1)/M) and
 * phi in [2 pi k/N, 2 pi (k+1)/N), every cell the same projected solid
 * angle pi/(MN). The caller traces one ray per cell (direction from
 * irr_direction) and hands back the radiance and hit distance of each;
 * irr_record turns them into the irradiance, its rotational and
 * translational gradients and a validity radius. Gradients are per colour
 * channel: grad_r[c] and grad_t[c] are the gradient vectors (world space) of
 * channel c.
 *
 * Conventions: E is irradiance (W/m^2-like: pi times the mean radiance for
 * a uniform sky); the extrapolated value of a record at (p, n) is
 *   E + (n_i x n) . grad_r + (p - p_i) . grad_t, each channel clamped >= 0.
 * Pure functions; thread-safe.
 */
#ifndef RAYES_RENDER_IRRADIANCE_H
#define RAYES_RENDER_IRRADIANCE_H

#include <math.h>

#include "util/vec.h"

typedef struct IrrRecord {
    Vec3 p, n;          /* position and unit normal */
    Vec3 E;             /* irradiance, RGB */
    Vec3 grad_r[3];     /* rotational gradient of each channel */
    Vec3 grad_t[3];     /* translational gradient of each channel */
    float R;            /* validity radius: the smallest hit distance of rays more than
                           ~10 degrees above the tangent plane (harmonic mean if none) */
} IrrRecord;

/* The tangent frame (t, b, n) records use: right-handed, t x b = n. */
void irr_frame(Vec3 n, Vec3 *t, Vec3 *b);

/* The direction of cell (j, k) at jitter (xi1, xi2) in [0,1)^2, world space. */
Vec3 irr_direction(int M, int N, int j, int k, float xi1, float xi2, Vec3 n);

/* Fills rec (E, gradients, R) from the radiance L[j * N + k] and hit
 * distance r[j * N + k] (INFINITY for a miss) of each cell, at p with
 * normal n. M >= 1, N >= 3. */
void irr_record(int M, int N, const Vec3 *L, const float *r, Vec3 p, Vec3 n, IrrRecord *rec);

/* A record's validity radius from the hit distances of its samples: the
 * smallest distance of those more than ~10 degrees above the tangent plane
 * (cos theta > 0.173), else the harmonic mean of all (a miss, r INFINITY,
 * counts as infinitely far), else INFINITY. Start from IRR_RADIUS_INIT,
 * irr_radius_add each sample. */
typedef struct IrrRadius {
    double inv_r;
    int n;
    float r_min;
} IrrRadius;
#define IRR_RADIUS_INIT ((IrrRadius){0.0, 0, INFINITY})
void irr_radius_add(IrrRadius *acc, float r, float cos_theta);
float irr_radius(const IrrRadius *acc);

/* The record's value extrapolated to (p, n) with its gradients. */
Vec3 irr_extrapolate(const IrrRecord *rec, Vec3 p, Vec3 n);

/* The smooth weight of Tabellion and Lamorlette (2004) of a record at
 * (p, n): 1 - kappa * max(|p - p_i| / R_i, sqrt(1 - n.n_i) / sqrt(1 - cos 10deg)),
 * 0 when negative or when the record lies in front of p. */
float irr_weight(const IrrRecord *rec, Vec3 p, Vec3 n, float kappa);

#endif /* RAYES_RENDER_IRRADIANCE_H */
