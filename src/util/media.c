/*
 * util/media.c — Jensen et al. 2001's measured media (media.h).
 */
#include "util/media.h"

#include <ctype.h>
#include <stddef.h>
#include <strings.h>

const MeasuredMedium media_measured[] = {
    {"apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"spectralon", {11.6f, 20.4f, 14.9f}, {0.0f, 0.0f, 0.0f}},
    {"wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {NULL, {0, 0, 0}, {0, 0, 0}},
};

/* Shaders look their preset up at every call: the names are lower case,
 * so a first letter that differs skips the comparison. */
const MeasuredMedium *media_find(const char *name)
{
    if (!name)
        return NULL;
    int first = tolower((unsigned char)name[0]);
    for (const MeasuredMedium *m = media_measured; m->name; m++)
        if (first == m->name[0] && strcasecmp(name, m->name) == 0)
            return m;
    return NULL;
}
