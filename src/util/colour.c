/*
 * util/colour.c — colours of light sources (colour.h).
 */
#include "util/colour.h"

void colour_blackbody(double T, float out[3])
{
    if (T < 1667)
        T = 1667;
    if (T > 25000)
        T = 25000;
    double t = 1e3 / T, t2 = t * t, t3 = t2 * t, x, y;
    x = T <= 4000 ? -0.2661239 * t3 - 0.2343589 * t2 + 0.8776956 * t + 0.179910
                  : -3.0258469 * t3 + 2.1070379 * t2 + 0.2226347 * t + 0.240390;
    double x2 = x * x, x3 = x2 * x;
    if (T <= 2222)
        y = -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683;
    else if (T <= 4000)
        y = -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867;
    else
        y = 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
    double X = x / y, Y = 1.0, Z = (1 - x - y) / y;
    double rgb[3] = {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z,
                     -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
                     0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
    double m = 0;
    for (int c = 0; c < 3; c++) {
        rgb[c] = rgb[c] > 0 ? rgb[c] : 0;
        m = rgb[c] > m ? rgb[c] : m;
    }
    for (int c = 0; c < 3; c++)
        out[c] = (float)(m > 0 ? rgb[c] / m : 1.0);
}

void colour_temperature(double T, float out[3])
{
    float c[3], w[3];
    colour_blackbody(T, c);
    colour_blackbody(6500.0, w);
    for (int k = 0; k < 3; k++)
        c[k] /= w[k];
    float Y = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
    for (int k = 0; k < 3; k++)
        out[k] = Y > 0.0f ? c[k] / Y : 1.0f;
}
