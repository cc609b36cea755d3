/*
 * shade/noise.c — improved Perlin noise: quintic fade, gradients chosen by
 * hashing the lattice point among the 12 cube-edge directions (Perlin
 * 2002). Lattice coordinates are hashed instead of looked up in a 256-entry
 * permutation, so the noise does not repeat every 256 units.
 */
#include "shade/noise.h"

#include <math.h>
#include <stdint.h>

static uint32_t lattice_hash(int32_t x, int32_t y, int32_t z)
{
    uint32_t h = (uint32_t)x * 0x8da6b343u ^ (uint32_t)y * 0xd8163841u ^ (uint32_t)z * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

/* Dot product of the lattice point's gradient with (x, y, z). */
static float grad(uint32_t h, float x, float y, float z)
{
    switch (h % 12u) {
    case 0: return x + y;
    case 1: return -x + y;
    case 2: return x - y;
    case 3: return -x - y;
    case 4: return x + z;
    case 5: return -x + z;
    case 6: return x - z;
    case 7: return -x - z;
    case 8: return y + z;
    case 9: return -y + z;
    case 10: return y - z;
    default: return -y - z;
    }
}

static float fade(float t)
{
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

static float lerp(float t, float a, float b)
{
    return a + t * (b - a);
}

float noise3(float x, float y, float z)
{
    float fx = floorf(x), fy = floorf(y), fz = floorf(z);
    int32_t X = (int32_t)fx, Y = (int32_t)fy, Z = (int32_t)fz;
    x -= fx;
    y -= fy;
    z -= fz;
    float u = fade(x), v = fade(y), w = fade(z);
    float c[2][2][2];
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++)
                c[k][j][i] = grad(lattice_hash(X + i, Y + j, Z + k), x - (float)i, y - (float)j,
                                  z - (float)k);
    float y0 = lerp(v, lerp(u, c[0][0][0], c[0][0][1]), lerp(u, c[0][1][0], c[0][1][1]));
    float y1 = lerp(v, lerp(u, c[1][0][0], c[1][0][1]), lerp(u, c[1][1][0], c[1][1][1]));
    float n = lerp(w, y0, y1);
    /* The 12-gradient noise reaches about +-1.04 at most: clamp to [-1, 1]. */
    return fminf(fmaxf(n, -1.0f), 1.0f);
}

static float octaves_sum(const float p[3], int octaves, float lacunarity, float gain, int absolute)
{
    float sum = 0.0f, amp = 1.0f, f = 1.0f;
    for (int k = 0; k < octaves; k++) {
        float n = noise3(p[0] * f, p[1] * f, p[2] * f);
        sum += amp * (absolute ? fabsf(n) : n);
        amp *= gain;
        f *= lacunarity;
    }
    return sum;
}

float noise_fbm(const float p[3], int octaves, float lacunarity, float gain)
{
    return octaves_sum(p, octaves, lacunarity, gain, 0);
}

/* The integral from 0 to x of the square wave that is +1 on [0,1) and -1
 * on [1,2), period 2: a triangle wave. */
static float tri(float x)
{
    float f = x - 2.0f * floorf(0.5f * x);
    return f < 1.0f ? f : 2.0f - f;
}

/* The square wave, box-filtered over width w around x. */
static float square_filtered(float x, float w)
{
    if (w <= 1e-6f)
        return x - 2.0f * floorf(0.5f * x) < 1.0f ? 1.0f : -1.0f;
    return (tri(x + 0.5f * w) - tri(x - 0.5f * w)) / w;
}

float pattern_checker(float s, float t, float ds, float dt)
{
    return 0.5f + 0.5f * square_filtered(s, fabsf(ds)) * square_filtered(t, fabsf(dt));
}

float noise_turbulence(const float p[3], int octaves, float lacunarity, float gain)
{
    return octaves_sum(p, octaves, lacunarity, gain, 1);
}
