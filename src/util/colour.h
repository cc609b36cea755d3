/*
 * util/colour.h — colours of light sources: a blackbody's, and a colour
 * temperature as lighting tools give one; sRGB's transfer function.
 */
#ifndef RAYES_UTIL_COLOUR_H
#define RAYES_UTIL_COLOUR_H

#include <math.h>

/* The colour of a blackbody at T kelvin (clamped to 1667 - 25000) in
 * linear sRGB, its largest component 1, through the Planckian locus
 * approximation of Kim et al. (2002): pbrt-v4's "blackbody" colours. */
void colour_blackbody(double T, float out[3]);

/* A light's tint for a colour temperature of T kelvin, as RenderMan's
 * lights take "temperature": the blackbody's colour over 6500 K's (so
 * 6500 K is white), scaled to a luminance of 1 (the light's brightness
 * stays its intensity's). */
void colour_temperature(double T, float out[3]);

/* sRGB's encoding undone: the linear value of an sRGB-encoded v in [0, 1]. */
static inline float colour_srgb_to_linear(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* sRGB's encoding of a linear value in [0, 1]. */
static inline float colour_linear_to_srgb(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

#endif /* RAYES_UTIL_COLOUR_H */
