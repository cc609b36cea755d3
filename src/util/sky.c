/*
 * util/sky.c — Preetham et al.'s clear sky and Hottel's sun (sky.h).
 */
#include "util/sky.h"

#include <math.h>

#define SKY_PI 3.14159265358979323846

/* Perez et al.'s luminance distribution, of the view's zenith angle theta
 * (its cosine) and its angle gamma to the sun. */
static double perez(const float c[5], double cos_theta, double gamma)
{
    double cg = cos(gamma);
    return (1.0 + c[0] * exp(c[1] / fmax(cos_theta, 0.01))) *
           (1.0 + c[2] * exp(c[3] * gamma) + c[4] * cg * cg);
}

void sky_init(Sky *sky, const float sun[3], float turbidity)
{
    double len = sqrt((double)sun[0] * sun[0] + (double)sun[1] * sun[1] + (double)sun[2] * sun[2]);
    double s[3] = {0, 1, 0};
    if (len > 0)
        for (int k = 0; k < 3; k++)
            s[k] = sun[k] / len;
    if (s[1] < 0) { /* set: on the horizon, the sky of dusk */
        double h = sqrt(s[0] * s[0] + s[2] * s[2]);
        s[0] = h > 0 ? s[0] / h : 1, s[1] = 0, s[2] = h > 0 ? s[2] / h : 0;
    }
    for (int k = 0; k < 3; k++)
        sky->sun[k] = (float)s[k];
    double T = fmin(fmax(turbidity, 1.7), 10.0);
    sky->turbidity = (float)T;
    double ts = acos(fmin(fmax(s[1], -1.0), 1.0));
    sky->theta_s = (float)ts;
    /* the paper's appendix: coefficients linear in T */
    static const double dist[3][5][2] = {
        {{0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}},
        {{-0.0193, -0.2592}, {-0.0665, 0.0008}, {-0.0004, 0.2125}, {-0.0641, -0.8989}, {-0.0033, 0.0452}},
        {{-0.0167, -0.2608}, {-0.0950, 0.0092}, {-0.0079, 0.2102}, {-0.0441, -1.6537}, {-0.0109, 0.0529}}};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 5; k++)
            sky->perez[i][k] = (float)(dist[i][k][0] * T + dist[i][k][1]);
    double chi = (4.0 / 9.0 - T / 120.0) * (SKY_PI - 2.0 * ts);
    double Yz = ((4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192) * 1000.0; /* cd/m^2 */
    static const double cx[3][4] = {{0.00166, -0.00375, 0.00209, 0},
                                    {-0.02903, 0.06377, -0.03202, 0.00394},
                                    {0.11693, -0.21196, 0.06052, 0.25886}};
    static const double cy[3][4] = {{0.00275, -0.00610, 0.00317, 0},
                                    {-0.04214, 0.08970, -0.04153, 0.00516},
                                    {0.15346, -0.26756, 0.06670, 0.26688}};
    double th[4] = {ts * ts * ts, ts * ts, ts, 1}, tt[3] = {T * T, T, 1}, xz = 0, yz = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            xz += tt[i] * cx[i][j] * th[j], yz += tt[i] * cy[i][j] * th[j];
    sky->zenith[0] = (float)fmax(Yz, 0.0);
    sky->zenith[1] = (float)xz;
    sky->zenith[2] = (float)yz;
}

/* CIE xyY to linear sRGB. */
static void xyY_to_rgb(double x, double y, double Y, float rgb[3])
{
    double X = y > 1e-6 ? x * Y / y : 0, Z = y > 1e-6 ? (1 - x - y) * Y / y : 0;
    rgb[0] = (float)fmax(3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, 0.0);
    rgb[1] = (float)fmax(-0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z, 0.0);
    rgb[2] = (float)fmax(0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z, 0.0);
}

void sky_radiance(const Sky *sky, const float d[3], float rgb[3])
{
    if (d[1] <= 0.0f) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    double cg = (double)d[0] * sky->sun[0] + (double)d[1] * sky->sun[1] + (double)d[2] * sky->sun[2];
    double gamma = acos(fmin(fmax(cg, -1.0), 1.0)), v[3];
    for (int i = 0; i < 3; i++)
        v[i] = sky->zenith[i] * perez(sky->perez[i], d[1], gamma) /
               perez(sky->perez[i], 1.0, sky->theta_s);
    xyY_to_rgb(v[1], v[2], v[0], rgb);
}

void sky_sun_radiance(const Sky *sky, float rgb[3])
{
    double c = cos(sky->theta_s);
    if (c <= 0.0) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    /* Hottel's beam transmittance for a 23 km visibility at sea level
     * (mid-latitude summer), its optical depth scaled with turbidity
     * (2 the clear day), and redder toward the horizon: per channel
     * tau^((550 / lambda)^2) at 612, 549 and 464 nm */
    double tau = 0.1243 + 0.7493 * exp(-0.3949 / fmax(c, 0.01));
    tau = pow(tau, sky->turbidity / 2.0);
    static const double w[3] = {0.8076, 1.0036, 1.4049};
    for (int k = 0; k < 3; k++)
        rgb[k] = (float)(1.96e9 * pow(tau, w[k])); /* the disk outside the atmosphere */
}

void sky_sun_direction(int month, int day, float hour, float zone, float latitude,
                       float longitude, float out[3])
{
    static const int before[12] = {0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334};
    int m = month < 1 ? 1 : month > 12 ? 12 : month;
    double J = before[m - 1] + (day < 1 ? 1 : day > 31 ? 31 : day);
    double ts = hour + 0.170 * sin(4 * SKY_PI * (J - 80) / 373) -
                0.129 * sin(2 * SKY_PI * (J - 8) / 355) + (longitude - 15.0 * zone) / 15.0;
    double dec = 0.4093 * sin(2 * SKY_PI * (J - 81) / 368), l = latitude * SKY_PI / 180.0;
    double h = SKY_PI * ts / 12.0;
    double elev = asin(sin(l) * sin(dec) - cos(l) * cos(dec) * cos(h));
    /* azimuth from the south, positive toward the west */
    double phi = atan2(-cos(dec) * sin(h), cos(l) * sin(dec) - sin(l) * cos(dec) * cos(h));
    double st = cos(elev);
    out[0] = (float)(-st * sin(phi));
    out[1] = (float)sin(elev);
    out[2] = (float)(-st * cos(phi));
}
