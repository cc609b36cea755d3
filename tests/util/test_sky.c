/* The daylight model (util/sky.h) against its paper's numbers, the sun's
 * place against the sky's geometry, and light colours (util/colour.h). */
#include <math.h>

#include "test.h"
#include "util/colour.h"
#include "util/sky.h"

static double luminance(const float c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

static void test_sky(void)
{
    /* the sun 30 degrees from the zenith, turbidity 2: Preetham et al.'s
     * zenith luminance, (4.0453 T - 4.9710) tan chi - 0.2155 T + 2.4192
     * kcd/m^2 with chi = (4/9 - T/120)(pi - 2 theta_s): 5.878 */
    float sun[3] = {sinf(M_PI / 6), cosf(M_PI / 6), 0}, up[3] = {0, 1, 0}, c[3];
    Sky sky;
    sky_init(&sky, sun, 2.0f);
    sky_radiance(&sky, up, c);
    printf("  zenith: %.1f cd/m^2 (%.4f %.4f %.4f)\n", luminance(c), c[0], c[1], c[2]);
    CHECK_NEAR(luminance(c), 5878.0, 25.0);
    CHECK(c[2] > c[0]); /* blue */
    /* brighter near the sun than across the sky from it, at the same height;
     * nothing below the horizon */
    float near[3] = {sinf(1.2f), cosf(1.2f), 0}, far[3] = {-sinf(1.2f), cosf(1.2f), 0}, a[3], b[3];
    sky_radiance(&sky, near, a);
    sky_radiance(&sky, far, b);
    CHECK(luminance(a) > 1.5 * luminance(b));
    float down[3] = {0, -1, 0};
    sky_radiance(&sky, down, a);
    CHECK(a[0] == 0 && a[1] == 0 && a[2] == 0);
    /* the sun: about 1.2e9 cd/m^2 overhead on a clear day, redder and
     * dimmer low, none once set; haze dims it */
    float s[3], low[3], hazy[3];
    sky_init(&sky, up, 2.0f);
    sky_sun_radiance(&sky, s);
    CHECK(luminance(s) > 0.9e9 && luminance(s) < 1.6e9);
    float l[3] = {cosf(0.1f), sinf(0.1f), 0};
    sky_init(&sky, l, 2.0f);
    sky_sun_radiance(&sky, low);
    CHECK(luminance(low) < 0.3 * luminance(s) && low[0] > 2 * low[2]);
    sky_init(&sky, up, 8.0f);
    sky_sun_radiance(&sky, hazy);
    CHECK(luminance(hazy) < 0.5 * luminance(s));
    float set[3] = {1, -0.2f, 0};
    sky_init(&sky, set, 2.0f);
    sky_sun_radiance(&sky, s);
    CHECK(s[0] == 0 && s[1] == 0 && s[2] == 0);
}

static void test_sun_direction(void)
{
    /* at an equinox's noon on its time zone's meridian, latitude 40 north:
     * 50 degrees up, due south (-z); 6 in the morning: east (+x); the June
     * solstice's noon 73.4 degrees up, December's 26.6 */
    float d[3];
    sky_sun_direction(3, 21, 12.0f, 0, 40, 0, d);
    printf("  equinox noon: %.3f %.3f %.3f (elevation %.1f)\n", d[0], d[1], d[2],
           asin(d[1]) * 180 / M_PI);
    CHECK_NEAR(asin(d[1]) * 180 / M_PI, 50, 2.0);
    CHECK(d[2] < 0 && fabsf(d[0]) < 0.1f);
    sky_sun_direction(3, 21, 8.0f, 0, 40, 0, d);
    CHECK(d[0] > 0.5f && d[1] > 0);
    sky_sun_direction(6, 21, 12.0f, 0, 40, 0, d);
    CHECK_NEAR(asin(d[1]) * 180 / M_PI, 73.4, 2.0);
    sky_sun_direction(12, 21, 12.0f, 0, 40, 0, d);
    CHECK_NEAR(asin(d[1]) * 180 / M_PI, 26.6, 2.0);
    /* 15 degrees east of the zone's meridian: an hour ahead of it */
    float e[3];
    sky_sun_direction(3, 21, 11.0f, 0, 40, 15, e);
    sky_sun_direction(3, 21, 12.0f, 0, 40, 0, d);
    CHECK(fabsf(e[0] - d[0]) < 1e-3f && fabsf(e[1] - d[1]) < 1e-3f);
}

static void test_temperature(void)
{
    float w[3], c[3];
    colour_temperature(6500, w);
    CHECK_NEAR(w[0], 1, 1e-5);
    CHECK_NEAR(w[1], 1, 1e-5);
    CHECK_NEAR(w[2], 1, 1e-5);
    colour_temperature(3000, c);
    CHECK(c[0] > c[1] && c[1] > c[2]);
    CHECK_NEAR(luminance(c), 1, 1e-5);
    colour_temperature(10000, c);
    CHECK(c[2] > c[0]);
}

TEST_MAIN(TEST(test_sky), TEST(test_sun_direction), TEST(test_temperature))
