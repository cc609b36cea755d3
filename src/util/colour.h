/*
 * util/colour.h — colours of light sources: a blackbody's, and a colour
 * temperature as lighting tools give one.
 */
#ifndef RAYES_UTIL_COLOUR_H
#define RAYES_UTIL_COLOUR_H

/* The colour of a blackbody at T kelvin (clamped to 1667 - 25000) in
 * linear sRGB, its largest component 1, through the Planckian locus
 * approximation of Kim et al. (2002): pbrt-v4's "blackbody" colours. */
void colour_blackbody(double T, float out[3]);

/* A light's tint for a colour temperature of T kelvin, as RenderMan's
 * lights take "temperature": the blackbody's colour over 6500 K's (so
 * 6500 K is white), scaled to a luminance of 1 (the light's brightness
 * stays its intensity's). */
void colour_temperature(double T, float out[3]);

#endif /* RAYES_UTIL_COLOUR_H */
