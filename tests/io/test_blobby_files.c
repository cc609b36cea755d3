/*
 * Blobby in RIB files: RenderMan's blobby (Aqsis's blend example, the
 * blended and the unblended cluster) becomes closed quad meshes on the
 * surface with normals and blended vertex colours, under the current
 * transform; bad programs and counts are errors naming the file and line; the RIB
 * writer writes Blobby back, and reading that gives the same quads.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "io/rib_round_trip.h"
#include "io/sink.h"
#include "scene/scene.h"
#include "test.h"

static char err[1024];

static RayesScene *read(const char *text, RayesError *e)
{
    return rib_read_scene(text, e, err, sizeof err);
}

#define SIX_BLOBS                                                                                  \
    "  [1 0 0 0 0 1 0 0 0 0 1 0 0.6 0 0 1  1 0 0 0 0 1 0 0 0 0 1 0 0 0.6 0 1\n"                    \
    "   1 0 0 0 0 1 0 0 0 0 1 0 0 0 0.6 1  1 0 0 0 0 1 0 0 0 0 1 0 -0.6 0 0 1\n"                   \
    "   1 0 0 0 0 1 0 0 0 0 1 0 0 -0.6 0 1  1 0 0 0 0 1 0 0 0 0 1 0 0 0 -0.6 1] [\"\"]\n"

static const char *const rib_text =
    "WorldBegin\n"
    "Translate 10 0 0\n"
    "Blobby 6 [1001 0 1001 16 1001 32 1001 48 1001 64 1001 80 0 6 0 1 2 3 4 5]\n" SIX_BLOBS
    "  \"vertex color Cs\" [1 0 0 1 0 0 1 0 0 0 0 1 0 0 1 0 0 1]\n"
    "Blobby 6 [1001 0 1001 16 1001 32 1001 48 1001 64 1001 80 2 6 0 1 2 3 4 5]\n" SIX_BLOBS
    "WorldEnd\n";

/* The prims' corner points, their distance to the nearest blob centre at
 * most, and the mean colour on either side of x = 10. */
static void survey(const RayesScene *s, size_t from, size_t to, float *far_most, float *near_most,
                   float red_pos[3], float red_neg[3])
{
    static const float c[6][3] = {{0.6f, 0, 0},  {0, 0.6f, 0},  {0, 0, 0.6f},
                                  {-0.6f, 0, 0}, {0, -0.6f, 0}, {0, 0, -0.6f}};
    *far_most = 0.0f, *near_most = 1e30f;
    double sum[2][3] = {{0}}, n[2] = {0};
    for (size_t k = from; k < to; k++) {
        const Prim *p = &s->prims[k];
        for (int v = 0; v < 4; v++) {
            Vec3 q = v3_sub(p->cp[v], v3(10, 0, 0));
            float d = 1e30f;
            for (int b = 0; b < 6; b++)
                d = fminf(d, v3_length(v3_sub(q, v3_load(c[b]))));
            *far_most = fmaxf(*far_most, d);
            *near_most = fminf(*near_most, d);
        }
        if (red_pos && (p->pv & GEOM_PV_CS)) {
            /* N (12 floats) first, then Cs (one per corner). */
            const float *cs = s->pv + p->pv_first + 12;
            int side = p->cp[0].x > 10.0f;
            for (int ch = 0; ch < 3; ch++)
                sum[side][ch] += cs[ch];
            n[side]++;
        }
    }
    if (red_pos)
        for (int ch = 0; ch < 3; ch++) {
            red_pos[ch] = n[1] ? (float)(sum[1][ch] / n[1]) : 0.0f;
            red_neg[ch] = n[0] ? (float)(sum[0][ch] / n[0]) : 0.0f;
        }
}

static void test_rib(void)
{
    RayesError e;
    RayesScene *s = read(rib_text, &e);
    CHECK(e == RAYES_OK);
    size_t first = 0, n = s->n_prims;
    while (first < n && s->prims[first].object == s->prims[0].object &&
           (s->prims[first].pv & GEOM_PV_CS))
        first++;
    CHECK(first > 1000 && n > first + 1000);
    for (size_t k = 0; k < n; k++)
        CHECK(s->prims[k].type == PRIM_BILINEAR && (s->prims[k].pv & GEOM_PV_N));
    float far_most, near_most, pos[3], neg[3];
    /* Blended: nothing inside a lone blob's sphere (radius 0.5), and the
     * surface swells beyond it between the blobs. */
    survey(s, 0, first, &far_most, &near_most, pos, neg);
    CHECK(near_most > 0.5f - 1e-3f && far_most > 0.6f && far_most < 1.0f);
    /* Red blobs at +x, +y, +z, blue ones opposite: red where x > 0. */
    CHECK(pos[0] > 0.6f && pos[2] < 0.4f && neg[2] > pos[2]);
    /* The maximum: every point on some blob's sphere of radius 0.5. */
    survey(s, first, n, &far_most, &near_most, NULL, NULL);
    CHECK(far_most < 0.5f + 1e-3f && near_most > 0.5f - 1e-3f);
    rayes_scene_release(s);
}

static void test_rib_errors(void)
{
    static const struct {
        const char *text, *says;
    } bad[] = {
        {"WorldBegin\nBlobby 1 [1001 0 0 2 0 1] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1] [\"\"]\n",
         "operand 1 is not an earlier"},
        {"WorldBegin\nBlobby 1 [1001 3] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1] [\"\"]\n",
         "needs floats 3 to 18"},
        {"WorldBegin\nBlobby 1 [1001 0]\n", "float array"},
        {"WorldBegin\nBlobby 1 [1001 0] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\n", "string array"},
        {"WorldBegin\nBlobby 2 [1001 0] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1] [\"\"]\n"
         "  \"vertex color Cs\" [1 0 0]\n",
         "Cs"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        RayesError e;
        RayesScene *s = read(bad[i].text, &e);
        CHECK(e != RAYES_OK && strstr(err, "t.rib:") && strstr(err, bad[i].says));
        if (!strstr(err, bad[i].says) || !strstr(err, "t.rib:"))
            fprintf(stderr, "  got \"%s\"\n", err);
        rayes_scene_release(s);
    }
}

/* The writer's Blobby read again gives the same quads. */
static void test_write_back(void)
{
    char *buf = rib_round_trip(rib_text, err, sizeof err);
    CHECK(buf && strstr(buf, "Blobby 6 [1001 0 1001 16"));
    RayesError e1, e2;
    RayesScene *a = read(rib_text, &e1), *b = read(buf ? buf : "", &e2);
    CHECK(e1 == RAYES_OK && e2 == RAYES_OK);
    CHECK(a->n_prims == b->n_prims && a->n_pv == b->n_pv);
    int same = a->n_prims == b->n_prims;
    for (size_t k = 0; same && k < a->n_prims; k++)
        for (int v = 0; v < 4; v++)
            same &= v3_length(v3_sub(a->prims[k].cp[v], b->prims[k].cp[v])) < 1e-5f;
    CHECK(same);
    rayes_scene_release(a);
    rayes_scene_release(b);
    free(buf);
}

TEST_MAIN(TEST(test_rib), TEST(test_rib_errors), TEST(test_write_back))
