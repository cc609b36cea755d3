/* Half floats (util/half.h) against GCC's _Float16 over every float bit
 * pattern in a large stride, and at the digest's listed values. */
#include <stdint.h>
#include <string.h>

#include "test.h"
#include "util/half.h"

/* GCC has _Float16 on x86-64; clang 14 does not: then only the known values
 * and the half -> float -> half round trip are checked. */
#if defined(__FLT16_MAX__)
#define HAVE_FLOAT16 1
static uint16_t ref_half(float f)
{
    _Float16 h = (_Float16)f;
    uint16_t u;
    memcpy(&u, &h, sizeof u);
    return u;
}

#endif

static void test_known_values(void)
{
    CHECK(half_from_float(65504.0f) == 0x7bff);
    CHECK(half_from_float(65520.0f) == 0x7c00);
    CHECK(half_from_float(1e5f) == 0x7c00);
    CHECK(half_from_float(6.1035e-5f) == 0x0400);
    CHECK(half_from_float(5.96e-8f) == 0x0001);
    CHECK(half_from_float(2.9e-8f) == 0x0000);
    CHECK(half_from_float(3.0e-8f) == 0x0001);
    CHECK(half_from_float(0.1f) == 0x2e66);
    CHECK(half_from_float_clamped(1e9f) == 0x7bff);
    CHECK(half_from_float_clamped(-1e9f) == 0xfbff);
    CHECK(half_from_float_clamped(0.0f / 0.0f) == 0x0000);
    CHECK(half_to_float(0x3c00) == 1.0f);
    CHECK(half_to_float(0x0001) == 0x1p-24f);
}

static void test_matches_float16_everywhere(void)
{
#ifdef HAVE_FLOAT16
    int mismatches = 0;
    for (uint64_t bits = 0; bits <= 0xffffffffull; bits += 997) {
        uint32_t b = (uint32_t)bits;
        float f;
        memcpy(&f, &b, sizeof f);
        uint16_t mine = half_from_float(f), ref = ref_half(f);
        if (f != f) /* NaN: any quiet NaN will do */
            mismatches += (mine & 0x7c00) != 0x7c00 || (mine & 0x3ff) == 0;
        else
            mismatches += mine != ref;
    }
    CHECK(mismatches == 0);
#endif
}

static void test_round_trip_all_halves(void)
{
    int bad = 0;
    for (uint32_t h = 0; h < 0x10000; h++) {
        if ((h & 0x7c00) == 0x7c00 && (h & 0x3ff))
            continue; /* NaN payloads */
        bad += half_from_float(half_to_float((uint16_t)h)) != h;
#ifdef HAVE_FLOAT16
        _Float16 r;
        uint16_t u = (uint16_t)h;
        memcpy(&r, &u, sizeof r);
        bad += half_to_float((uint16_t)h) != (float)r;
#endif
    }
    CHECK(bad == 0);
}

/* The branch-free decoding agrees bit for bit on every finite half. */
static void test_finite_decoding(void)
{
    int bad = 0;
    for (uint32_t h = 0; h < 0x10000; h++) {
        if ((h & 0x7c00) == 0x7c00)
            continue; /* infinities and NaNs */
        float a = half_to_float((uint16_t)h), b = half_to_float_finite((uint16_t)h);
        bad += memcmp(&a, &b, sizeof a) != 0;
    }
    CHECK(bad == 0);
}

/* Six at a time (SSE2 where there is SSE2) agrees with one at a time, at
 * every position of the six. */
static void test_finite_decoding_x6(void)
{
    int bad = 0;
    for (uint32_t h = 0; h < 0x10000; h++) {
        if ((h & 0x7c00) == 0x7c00)
            continue;
        uint16_t in[6];
        for (int k = 0; k < 6; k++)
            in[k] = (uint16_t)((h + 0x1111u * (uint32_t)k) & 0xffffu);
        float out[6];
        half_to_float_finite_x6(in, out);
        for (int k = 0; k < 6; k++) {
            if ((in[k] & 0x7c00) == 0x7c00)
                continue;
            float a = half_to_float_finite(in[k]);
            bad += memcmp(&a, &out[k], sizeof a) != 0;
        }
    }
    CHECK(bad == 0);
}

TEST_MAIN(TEST(test_known_values), TEST(test_matches_float16_everywhere),
          TEST(test_round_trip_all_halves), TEST(test_finite_decoding),
          TEST(test_finite_decoding_x6))
