/*
 * shade/noise.h — procedural patterns: Perlin's improved gradient noise
 * (2002), fractal Brownian motion and turbulence, as the memo's procedural
 * displacement uses them (technical digest, section 5: octaves at a
 * frequency ratio of 1.99, so lattices of successive octaves do not line up).
 *
 * Pure functions of their arguments: the same point gives the same value on
 * every thread and machine (no tables built at run time).
 */
#ifndef RAYES_SHADE_NOISE_H
#define RAYES_SHADE_NOISE_H

/* The digest's octave frequency ratio. */
#define NOISE_LACUNARITY 1.99f

/* Gradient noise in [-1, 1], zero on integer lattice points, C2-smooth. */
float noise3(float x, float y, float z);

/* sum over octaves k of gain^k * noise3(p * lacunarity^k). */
float noise_fbm(const float p[3], int octaves, float lacunarity, float gain);

/* sum over octaves k of gain^k * |noise3(p * lacunarity^k)|. */
float noise_turbulence(const float p[3], int octaves, float lacunarity, float gain);

/* A checkerboard of unit squares, 1 where floor(s) + floor(t) is even and 0
 * elsewhere, box-filtered over ds x dt (0: point sampled). Exact: the
 * box filter of the separable square waves is a difference of triangle
 * waves. */
float pattern_checker(float s, float t, float ds, float dt);

#endif /* RAYES_SHADE_NOISE_H */
