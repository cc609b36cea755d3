/*
 * util/sky.h — a clear sky and its sun, as RenderMan's PxrEnvDayLight
 * models them: the sky of Preetham, Shirley and Smits, "A Practical
 * Analytic Model for Daylight" (SIGGRAPH 1999), and the sun's disk dimmed
 * by Hottel's clear-day transmittance (1976). Directions are in the sky's
 * frame: +y the zenith, the horizon the xz plane. Radiances are linear
 * sRGB in cd/m^2 (luminance) units, as the model gives them: a caller
 * scales them (RenderMan by 1e-5).
 */
#ifndef RAYES_UTIL_SKY_H
#define RAYES_UTIL_SKY_H

typedef struct Sky {
    float sun[3];     /* unit, toward the sun's centre */
    float turbidity;  /* 1.7 (very clear) to 10 (hazy); RenderMan's haziness */
    /* set by sky_init: Perez coefficients (Y, x, y) and the zenith's Yxy */
    float perez[3][5];
    float zenith[3];
    float theta_s;    /* the sun's zenith angle */
} Sky;

/* Sets up sky from its sun direction (any length; at most 90 degrees from
 * the zenith is used, a sun below the horizon set on it) and turbidity
 * (clamped to [1.7, 10]). */
void sky_init(Sky *sky, const float sun[3], float turbidity);

/* The sky's radiance toward direction d (unit), the sun's disk left out;
 * black below the horizon. */
void sky_radiance(const Sky *sky, const float d[3], float rgb[3]);

/* The radiance of the sun's disk at the ground (linear sRGB, cd/m^2):
 * about 1.6e9 at the zenith on a clear day, dimmer and redder toward the
 * horizon; 0 when it has set. */
void sky_sun_radiance(const Sky *sky, float rgb[3]);

/* The direction toward the sun (+y the zenith, +z north, +x east) at
 * hour (local standard time, 0-24) of day (1-31) of month (1-12), at
 * latitude and longitude (degrees, north and east positive) in time zone
 * (hours from Greenwich, east positive), by Preetham et al.'s appendix. */
void sky_sun_direction(int month, int day, float hour, float zone, float latitude,
                       float longitude, float out[3]);

#endif /* RAYES_UTIL_SKY_H */
