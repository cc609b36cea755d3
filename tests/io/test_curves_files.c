/*
 * Curves and points in scene files: RIB's Curves (the current v basis,
 * varying widths, Attribute "dice" "roundcurve", N for ribbons) and
 * Points ("type" "disk", constantwidth), errors naming the line, pbrt's
 * curve shape (cylinder, bspline of degree 2 raised to cubic Bezier,
 * width0 to width1), and the RIB writer's Curves and Points read back to
 * the same primitives.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt.h"
#include "io/rib.h"
#include "io/rib_round_trip.h"
#include "io/sink.h"
#include "scene/scene.h"
#include "test.h"

static char err[1024];

static RayesScene *read(const char *text, int pbrt, RayesError *e)
{
    return pbrt ? pbrt_read_scene(text, e, err, sizeof err)
                : rib_read_scene(text, e, err, sizeof err);
}

static const char *const rib_text =
    "WorldBegin\n"
    "Basis \"b-spline\" 1 \"b-spline\" 1\n"
    "Curves \"cubic\" [5] \"nonperiodic\" \"P\" [0 0 0 1 0 0 2 1 0 3 1 0 4 0 0]\n"
    "  \"width\" [0.1 0.2 0.3]\n"
    "AttributeBegin\n"
    "Attribute \"dice\" \"int roundcurve\" [1]\n"
    "Curves \"linear\" [3] \"periodic\" \"P\" [0 0 0 1 0 0 0 1 0] \"constantwidth\" [0.05]\n"
    "  \"Cs\" [1 0 0 0 1 0 0 0 1]\n"
    "Curves \"linear\" [2] \"nonperiodic\" \"P\" [0 0 0 0 1 0] \"N\" [0 0 1 0 0 1]\n"
    "AttributeEnd\n"
    "Points \"P\" [0 0 0 1 1 1] \"constantwidth\" [0.5] \"uniform string type\" \"disk\"\n"
    "WorldEnd\n";

static void test_rib(void)
{
    RayesError e;
    RayesScene *s = read(rib_text, 0, &e);
    CHECK(e == RAYES_OK);
    /* Runs: 2 B-spline segments, 3 periodic linear ones; 1 ribbon; 2 points. */
    CHECK(s->n_prims == 5);
    if (s->n_prims == 5) {
        const Prim *p = s->prims;
        CHECK(p[0].type == PRIM_CURVE && p[0].curve.shape == GEOM_SHAPE_FLAT_CURVE);
        CHECK(p[0].curve.n_seg == 2);
        CHECK_NEAR(p[0].big->curve.width[0], 0.1, 1e-6);
        CHECK_NEAR(p[0].big->curve.width[1], 0.2, 1e-6);
        CHECK_NEAR(p[0].big->curve.width[2], 0.3, 1e-6);
        /* The B-spline's first point: (P0 + 4 P1 + P2) / 6. */
        CHECK_NEAR(p[0].big->curve.cp[0].x, 1.0, 1e-6);
        CHECK_NEAR(p[0].big->curve.cp[0].y, 1.0 / 6.0, 1e-6);
        CHECK(p[1].curve.shape == GEOM_SHAPE_ROUND_CURVE && p[1].curve.n_seg == 3);
        CHECK_NEAR(p[1].big->curve.width[3], 0.05, 1e-6);
        CHECK(p[1].pv == GEOM_PV_CS);
        /* The periodic curve's last segment ends where it began. */
        CHECK(v3_length(v3_sub(p[1].big->curve.cp[9], p[1].big->curve.cp[0])) < 1e-6f);
        CHECK(p[2].curve.shape == GEOM_SHAPE_SURFACE && p[2].big->curve.n[0].z > 0.99f);
        CHECK(p[3].type == PRIM_POINT && p[3].point.shape == GEOM_SHAPE_DISK);
        CHECK_NEAR(p[4].point.radius, 0.25, 1e-6);
    }
    rayes_scene_release(s);
}

static void test_rib_errors(void)
{
    RayesError e;
    RayesScene *s = read("WorldBegin\nCurves \"cubic\" [5] \"nonperiodic\"\n"
                         "  \"P\" [0 0 0 1 0 0 2 1 0 3 1 0 4 0 0]\nWorldEnd\n",
                         0, &e);
    CHECK(e != RAYES_OK && strstr(err, "t.rib:2") && strstr(err, "no whole"));
    rayes_scene_release(s);
    s = read("WorldBegin\nCurves \"linear\" [2] \"nonperiodic\" \"P\" [0 0 0 1 0 0]\n"
             "  \"width\" [1 2 3]\nWorldEnd\n",
             0, &e);
    CHECK(e != RAYES_OK && strstr(err, "t.rib:3") && strstr(err, "width"));
    rayes_scene_release(s);
    s = read("WorldBegin\nCurves \"quadratic\" [2] \"nonperiodic\" \"P\" [0 0 0 1 0 0]\nWorldEnd\n",
             0, &e);
    CHECK(e != RAYES_OK && strstr(err, "linear"));
    rayes_scene_release(s);
}

static void test_pbrt(void)
{
    RayesError e;
    RayesScene *s = read("WorldBegin\n"
                         "Shape \"curve\" \"point3 P\" [0 0 0 1 1 0 2 0 0 3 1 0]\n"
                         "  \"string type\" \"cylinder\" \"string basis\" \"bspline\"\n"
                         "  \"integer degree\" 2 \"float width0\" 0.2 \"float width1\" 0.1\n"
                         "Shape \"curve\" \"point3 P\" [0 0 0 1 1 0 2 0 0 3 1 0]\n"
                         "  \"string type\" \"ribbon\" \"normal N\" [0 0 1 0 0 1]\n",
                         1, &e);
    CHECK(e == RAYES_OK);
    CHECK(s->n_prims == 2);
    if (s->n_prims == 2) {
        const Prim *p = s->prims;
        CHECK(p[0].curve.shape == GEOM_SHAPE_ROUND_CURVE && p[1].curve.shape == GEOM_SHAPE_SURFACE);
        CHECK(p[0].curve.n_seg == 2);
        /* Quadratic B-spline (0 0 0, 1 1 0, 2 0 0): from (0.5, 0.5) to (1.5, 0.5). */
        CHECK_NEAR(p[0].big->curve.cp[0].x, 0.5, 1e-6);
        CHECK_NEAR(p[0].big->curve.cp[3].x, 1.5, 1e-6);
        CHECK_NEAR(p[0].big->curve.cp[3].y, 0.5, 1e-6);
        CHECK_NEAR(p[0].big->curve.width[0], 0.2, 1e-6);
        CHECK_NEAR(p[0].big->curve.width[2], 0.1, 1e-6);
    }
    rayes_scene_release(s);
    s = read("WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 1 0 2 0 0]\n", 1, &e);
    CHECK(e != RAYES_OK && strstr(err, "t.pbrt:2") && strstr(err, "whole"));
    rayes_scene_release(s);
}

/* The writer's RIB read again gives the same primitives. */
static void test_write_back(void)
{
    char *buf = rib_round_trip(rib_text, err, sizeof err);
    CHECK(buf != NULL);
    RayesError e1, e2;
    RayesScene *a = read(rib_text, 0, &e1), *b = read(buf ? buf : "", 0, &e2);
    CHECK(e1 == RAYES_OK && e2 == RAYES_OK);
    CHECK(a->n_prims == b->n_prims);
    for (size_t k = 0; k < a->n_prims && k < b->n_prims; k++) {
        CHECK(a->prims[k].type == b->prims[k].type);
        if (a->prims[k].type == PRIM_CURVE) {
            CHECK(a->prims[k].curve.shape == b->prims[k].curve.shape);
            for (int j = 0; j < 4; j++)
                CHECK(v3_length(v3_sub(a->prims[k].big->curve.cp[j],
                                       b->prims[k].big->curve.cp[j])) < 1e-5f);
            CHECK(a->prims[k].curve.n_seg == b->prims[k].curve.n_seg);
            CHECK_NEAR(a->prims[k].big->curve.width[1], b->prims[k].big->curve.width[1], 1e-6);
        } else {
            CHECK(a->prims[k].point.shape == b->prims[k].point.shape);
            CHECK_NEAR(a->prims[k].point.radius, b->prims[k].point.radius, 1e-6);
        }
    }
    rayes_scene_release(a);
    rayes_scene_release(b);
    free(buf);
}

TEST_MAIN(TEST(test_rib), TEST(test_rib_errors), TEST(test_pbrt), TEST(test_write_back))
