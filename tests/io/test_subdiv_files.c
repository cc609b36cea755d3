/*
 * Subdivision meshes in scene files: RIB's SubdivisionMesh and
 * HierarchicalSubdivisionMesh (schemes, every tag, primitive variables in
 * every class, RenderMan's orientation, errors naming the line), pbrt's
 * loopsubdiv, and the RIB writer's SubdivisionMesh read back to the same
 * call.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt.h"
#include "io/rib.h"
#include "io/rib_write.h"
#include "record_sink.h"
#include "test.h"

static Record rec;
static char err[1024];

static RayesError rib(const char *text)
{
    return record_rib(&rec, text, NULL, err, sizeof err);
}

#define CUBE_FACES "[4 4 4 4 4 4] [0 1 3 2 2 3 5 4 4 5 7 6 6 7 1 0 1 7 5 3 6 0 2 4]"
#define CUBE_P                                                                                   \
    "\"P\" [-1 -1 1 1 -1 1 -1 1 1 1 1 1 -1 1 -1 1 1 -1 -1 -1 -1 1 -1 -1]"

static void test_rib_tags(void)
{
    CHECK(rib("Surface \"matte\"\nWorldBegin\nSubdivisionMesh \"catmull-clark\" " CUBE_FACES "\n"
              "[\"interpolateboundary\" \"crease\" \"corner\" \"hole\" "
              "\"facevaryinginterpolateboundary\" \"vertexedit\"]\n"
              "[1 0  3 2  2 1  1 0  1 0  0 0] [2  0 1 3  4 6  5  3] [1.5 4.5  10]\n" CUBE_P
              "\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec_param(&rec.shader[0], "Kd") == NULL);
    RecMesh *m = &rec.mesh[0];
    CHECK(m->subdiv && m->scheme == RAYES_SUBDIV_CATMULL_CLARK && m->has_tags);
    CHECK(m->n_faces == 6 && m->n_points == 8);
    CHECK(m->tags.interpolate_boundary == 2 && m->tags.facevarying_boundary == 3);
    /* The chain 0 1 3 is two edges, with a sharpness each. */
    CHECK(m->tags.n_creases == 2);
    CHECK(m->tags.crease_edges[0] == 0 && m->tags.crease_edges[1] == 1);
    CHECK(m->tags.crease_edges[2] == 1 && m->tags.crease_edges[3] == 3);
    CHECK(m->tags.crease_sharpness[0] == 1.5f && m->tags.crease_sharpness[1] == 4.5f);
    /* Two corners, one sharpness for both; one hole. */
    CHECK(m->tags.n_corners == 2 && m->tags.corner_points[1] == 6);
    CHECK(m->tags.corner_sharpness[0] == 10.0f && m->tags.corner_sharpness[1] == 10.0f);
    CHECK(m->tags.n_holes == 1 && m->tags.hole_faces[0] == 5);
    record_free(&rec);
    /* No interpolateboundary tag: RenderMan's default leaves the boundary
     * out. */
    CHECK(rib("WorldBegin\nSubdivisionMesh \"loop\" [3] [0 1 2] [] [] [] []\n"
              "\"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].scheme == RAYES_SUBDIV_LOOP);
    CHECK(rec.mesh[0].tags.interpolate_boundary == 0 && rec.mesh[0].tags.facevarying_boundary == 1);
    record_free(&rec);
    /* The tag arrays left out altogether (Aqsis's motion blur example);
     * a bare tag name still reads as a one-tag array. */
    CHECK(rib("WorldBegin\nSubdivisionMesh \"catmull-clark\" [3 3 3 3] [0 1 3 1 2 3 2 0 3 2 1 0]\n"
              "\"P\" [1 0 0 -0.5 1 0 -0.5 -1 0 0 0 1]\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].n_faces == 4 && rec.mesh[0].n_points == 4);
    CHECK(rec.mesh[0].tags.interpolate_boundary == 0);
    record_free(&rec);
    CHECK(rib("WorldBegin\nSubdivisionMesh \"catmull-clark\" [3] [0 1 2] \"interpolateboundary\" "
              "[0 0] "
              "[] []\n\"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].tags.interpolate_boundary == 1);
    record_free(&rec);
    /* HierarchicalSubdivisionMesh: three counts per tag and string
     * arguments. */
    CHECK(rib("WorldBegin\nHierarchicalSubdivisionMesh \"bilinear\" [4] [0 1 2 3]\n"
              "[\"interpolateboundary\"] [1 0 0] [1] [] []\n"
              "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nWorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].scheme == RAYES_SUBDIV_BILINEAR);
    CHECK(rec.mesh[0].tags.interpolate_boundary == 1);
    record_free(&rec);
}

/* Primitive variables keep their classes (varying stays varying); a
 * left-handed orientation reverses each face after its first corner, and
 * facevarying values follow their corners. */
static void test_rib_primvars_and_orientation(void)
{
    CHECK(rib("WorldBegin\nOrientation \"rh\"\n"
              "SubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"interpolateboundary\"] [0 0] [] []\n"
              "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"varying color Cs\" [1 0 0 0 1 0 0 0 1 1 1 1]\n"
              "\"facevarying float[2] st\" [0 0 1 0 1 1 0 1] \"uniform normal N\" [0 0 1]\n"
              "WorldEnd\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    RecMesh *m = &rec.mesh[0];
    int flipped = m->idx[1] == 3;
    CHECK(m->idx[0] == 0 && (flipped ? m->idx[3] == 1 : m->idx[1] == 1));
    const RayesPrimvar *cs = NULL, *st = NULL, *N = NULL;
    for (size_t i = 0; i < m->pv.n; i++) {
        const char *name = m->pv.name[i];
        if (strcmp(name, "Cs") == 0)
            cs = &m->pv.pv[i];
        else if (strcmp(name, "st") == 0)
            st = &m->pv.pv[i];
        else if (strcmp(name, "N") == 0)
            N = &m->pv.pv[i];
    }
    CHECK(cs && cs->cls == RAYES_PRIMVAR_VARYING && cs->count == 4);
    CHECK(N && N->cls == RAYES_PRIMVAR_UNIFORM && N->count == 1);
    CHECK(st && st->cls == RAYES_PRIMVAR_FACEVARYING && st->count == 4);
    /* Corner k of the wound face is point idx[k], whose st is that point's. */
    for (int k = 0; st && k < 4; k++) {
        static const float want[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        CHECK(st->data[2 * k] == want[m->idx[k]][0] && st->data[2 * k + 1] == want[m->idx[k]][1]);
    }
    record_free(&rec);
}

static void test_rib_errors(void)
{
    CHECK(rib("WorldBegin\nSubdivisionMesh \"doo-sabin\" [4] [0 1 2 3] [] [] [] []\n"
              "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nWorldEnd\n") != RAYES_OK);
    CHECK(strstr(err, "t.rib:2:") && strstr(err, "unknown scheme \"doo-sabin\""));
    record_free(&rec);
    CHECK(rib("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\"] [2 1]"
              " [0 1] []\n\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nWorldEnd\n") != RAYES_OK);
    CHECK(strstr(err, "asks for more arguments"));
    record_free(&rec);
    CHECK(rib("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"corner\"] [1 2]"
              " [0] [1 2]\n\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nWorldEnd\n") != RAYES_OK);
    CHECK(strstr(err, "tag \"corner\": 1 points and 2 sharpnesses"));
    record_free(&rec);
    CHECK(rib("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [] [] [] []\n"
              "\"P\" [0 0 0 1 0 0 1 1 0]\nWorldEnd\n") != RAYES_OK);
    CHECK(strstr(err, "past the 3 points"));
    record_free(&rec);
}

/* The writer's SubdivisionMesh reads back to the call it was given. */
static void test_writer_round_trip(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink ws = io_rib_writer_sink(w);
    const float P[8][3] = {{-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1},
                           {-1, 1, -1}, {1, 1, -1}, {-1, -1, -1}, {1, -1, -1}};
    const int nv[6] = {4, 4, 4, 4, 4, 4};
    const int idx[24] = {0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4};
    const int edges[4] = {0, 1, 1, 3}, corners[1] = {6}, holes[1] = {2};
    const float sharp[2] = {2, 10}, csharp[1] = {3};
    RayesSubdivTags t = {2, 0, 2, edges, sharp, 1, corners, csharp, 1, holes};
    const float Cs[6][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
    RayesPrimvar pv = {"Cs", RAYES_PRIMVAR_UNIFORM, &Cs[0][0], 6};
    CHECK(ws.set_shader(ws.target, "matte", NULL, 0) == RAYES_OK);
    CHECK(ws.subdivision_mesh(ws.target, RAYES_SUBDIV_CATMULL_CLARK, 6, nv, idx, 8, &P[0][0], &t,
                              &pv, 1) == RAYES_OK);
    IoSettings settings;
    io_settings_init(&settings);
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    CHECK(io_rib_writer_finish(w, &settings, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    io_rib_writer_free(w);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    RecMesh *m = &rec.mesh[0];
    CHECK(m->subdiv && m->n_faces == 6 && memcmp(m->idx, idx, sizeof idx) == 0);
    CHECK(memcmp(m->P, P, sizeof P) == 0);
    CHECK(m->tags.interpolate_boundary == 2 && m->tags.facevarying_boundary == 0);
    CHECK(m->tags.n_creases == 2 && m->tags.crease_edges[3] == 3 && m->tags.crease_sharpness[1] == 10);
    CHECK(m->tags.n_corners == 1 && m->tags.corner_points[0] == 6 && m->tags.corner_sharpness[0] == 3);
    CHECK(m->tags.n_holes == 1 && m->tags.hole_faces[0] == 2);
    CHECK(m->pv.n == 1 && m->pv.pv[0].cls == RAYES_PRIMVAR_UNIFORM && m->pv.pv[0].data[4] == 1.0f);
    record_free(&rec);
    free(text);
}

static void test_pbrt_loopsubdiv(void)
{
    const char *text =
        "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 3 \"integer indices\" [0 1 2 0 2 3]"
        " \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n"
        "Shape \"loopsubdiv\" \"integer indices\" [0 1 5] \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    IoSink s = record_sink(&rec);
    IoSettings settings;
    io_settings_init(&settings);
    size_t n = strlen(text);
    unsigned char *copy = malloc(n);
    memcpy(copy, text, n);
    RayesError e = io_pbrt_parse("t.pbrt", copy, n, &s, NULL, &settings, err, sizeof err);
    free(copy);
    CHECK(e != RAYES_OK && strstr(err, "t.pbrt:3:") && strstr(err, "index 2 is 5"));
    CHECK(rec.n_mesh == 1);
    RecMesh *m = &rec.mesh[0];
    CHECK(m->subdiv && m->scheme == RAYES_SUBDIV_LOOP && m->n_faces == 2 && m->n_points == 4);
    CHECK(m->has_tags && m->tags.interpolate_boundary == 1);
    CHECK(m->pv.n == 1 && strcmp(m->pv.name[0], "st") == 0);
    CHECK(m->pv.pv[0].data[5] == 0.0f); /* t = 1 - v */
    record_free(&rec);
}

TEST_MAIN(TEST(test_rib_tags), TEST(test_rib_primvars_and_orientation), TEST(test_rib_errors),
          TEST(test_writer_round_trip), TEST(test_pbrt_loopsubdiv))
