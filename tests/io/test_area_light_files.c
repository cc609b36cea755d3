/*
 * tests/io/test_area_light_files.c — RIB area lights of any polygons: up
 * to four quads stay quad lights, more faces (triangles, polygons, holes)
 * make one mesh light, "twosided" is read, and the writer's RIB reads back
 * into the same light, corner for corner.
 */
#include <math.h>
#include <string.h>

#include "image/image.h"
#include "io/rib_round_trip.h"
#include "scene/scene.h"
#include "shade/light.h"
#include "test.h"

#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

#define WORLD(body) "WorldBegin\n" body "\nWorldEnd\n"

static size_t count_type(const RayesScene *s, LightType type)
{
    size_t n = 0;
    for (size_t k = 0; k < s->n_lights; k++)
        n += s->lights[k].type == type;
    return n;
}

/* Four quads: quad lights; five, or any other polygon: one mesh light.
 * An arealight's intensity is BMRT's, a point light's spread over the
 * shapes it is given to (a radiance of pi I / area); a lightcolor alone
 * is the radiance (rayes' own). */
static void test_polygons_under_area_lights(void)
{
    char err[256];
    RayesError e;
    RayesScene *s = rib_read_scene(
        WORLD("AttributeBegin\nAreaLightSource \"arealight\" 1 \"intensity\" 2\n"
              "PointsPolygons [4 4 4 4] [0 1 2 3 0 1 2 3 0 1 2 3 0 1 2 3] "
              "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nAttributeEnd"),
        &e, err, sizeof err);
    CHECK(e == RAYES_OK && s->n_lights == 4 && count_type(s, LIGHT_QUAD) == 4);
    CHECK(s->n_lights == 4 && fabsf(s->lights[0].L.x - (float)M_PI * 2 / 4) < 1e-5f);
    Vec3 quad_front = v3(0, 0, 0), c;
    if (s->n_lights == 4)
        light_quad_eval(&s->lights[0], 0.5f, 0.5f, &c, &quad_front);
    rayes_scene_release(s);
    s = rib_read_scene(
        WORLD("AttributeBegin\nAreaLightSource \"arealight\" 1 \"intensity\" 2\n"
              "PointsPolygons [4 4 4 4 4] [0 1 2 3 0 1 2 3 0 1 2 3 0 1 2 3 0 1 2 3] "
              "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nAttributeEnd\n"
              "AttributeBegin\nAreaLightSource \"arealight\" 2 \"float twosided\" [1]\n"
              "GeneralPolygon [4 3] \"P\" [0 0 0 4 0 0 4 4 0 0 4 0  1 1 0 2 1 0 1 2 0]\n"
              "AttributeEnd\nPolygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0 0.5 2 0]"),
        &e, err, sizeof err);
    CHECK(e == RAYES_OK && s->n_lights == 2 && count_type(s, LIGHT_MESH) == 2);
    if (s->n_lights == 2) {
        const Light *a = &s->lights[0], *b = &s->lights[1];
        CHECK(a->mesh->n == 10 && !a->two_sided);
        CHECK_NEAR(a->L.x, M_PI * 2.0 / 5.0, 1e-5); /* five unit squares */
        CHECK_NEAR(a->mesh->area, 5.0, 1e-5);
        CHECK(b->two_sided && b->L.x == 1.0f);
        CHECK_NEAR(b->mesh->area, 16.0 - 0.5, 1e-5); /* the square less its hole */
        /* facing as the same polygon's quad light */
        Vec3 n = v3_cross(v3_sub(a->mesh->v[1], a->mesh->v[0]),
                          v3_sub(a->mesh->v[2], a->mesh->v[0]));
        CHECK(v3_dot(n, quad_front) > 0);
    }
    CHECK(s->n_objects >= 3); /* two emitters, and the plain polygon's object */
    rayes_scene_release(s);
}

/* Written and read back: the same triangles bit for bit, the same sides. */
static void test_round_trip(void)
{
    static const char text[] =
        WORLD("Translate 0 0 5\nAttributeBegin\n"
              "AreaLightSource \"arealight\" 1 \"color lightcolor\" [0.1 0.2 0.3] "
              "\"float twosided\" [1]\n"
              "PointsPolygons [3 5] [0 1 2 0 2 3 4 5] \"P\" [0 0 0 1 0 0 1 1 0.1 0.5 1.7 0 "
              "-0.3 0.9 0 0 0.5 0]\nAttributeEnd");
    char err[256];
    RayesError e;
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written && strstr(written, "\"float twosided\" [1]") != NULL);
    RayesScene *a = rib_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK);
    RayesScene *b = written ? rib_read_scene(written, &e, err, sizeof err) : NULL;
    CHECK(b && e == RAYES_OK);
    if (b && a->n_lights == 1 && b->n_lights == 1) {
        const LightMesh *m = a->lights[0].mesh, *n = b->lights[0].mesh;
        CHECK(m && n && m->n == 4 && n->n == 4);
        CHECK(m && n && memcmp(m->v, n->v, 3 * m->n * sizeof *m->v) == 0);
        CHECK(b->lights[0].two_sided && b->lights[0].L.z == 0.3f);
    } else {
        CHECK(!"one light each");
    }
    rayes_scene_release(a);
    if (b)
        rayes_scene_release(b);
    free(written);
}

/* Quadrics under an area light emit (mesh lights of their surfaces) and
 * are written back as the quadric; a deforming emitter keeps its first
 * sample, where the motion block was an error for the scene. */
static void test_quadrics_and_motion(void)
{
    static const char text[] =
        WORLD("AttributeBegin\nAreaLightSource \"arealight\" 1 \"intensity\" 3\n"
              "Cylinder 0.1 0 1 360\nAttributeEnd\n"
              "AttributeBegin\nAreaLightSource \"arealight\" 2\nMotionBegin [0 1]\n"
              "Polygon \"P\" [0 0 0 1 0 0 1 1 0 0.5 1.5 0 0 1 0]\n"
              "Polygon \"P\" [0 0 1 1 0 1 1 1 1 0.5 1.5 1 0 1 1]\nMotionEnd\nAttributeEnd");
    char err[256];
    RayesError e;
    RayesScene *a = rib_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK && a->n_lights == 2 && count_type(a, LIGHT_MESH) == 2);
    if (a->n_lights == 2) {
        /* BMRT's units: pi 3 over the tube's 2 pi 0.1 */
        CHECK_NEAR(a->lights[0].L.x, 15.0, 15.0 * 1e-4);
        CHECK(a->lights[0].mesh->n >= 64);
        CHECK(a->lights[1].mesh->lo.z == 0.0f && a->lights[1].mesh->hi.z == 0.0f);
    }
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written && strstr(written, "\nCylinder 0.100000001 0 1 360\nAttributeEnd") != NULL);
    RayesScene *b = written ? rib_read_scene(written, &e, err, sizeof err) : NULL;
    CHECK(b && e == RAYES_OK && b->n_lights == 2);
    if (b && a->n_lights == 2 && b->n_lights == 2) {
        const LightMesh *m = a->lights[0].mesh, *n = b->lights[0].mesh;
        CHECK(m->n == n->n && memcmp(m->v, n->v, 3 * m->n * sizeof *m->v) == 0);
        CHECK(a->lights[0].L.x == b->lights[0].L.x); /* written as the radiance */
    }
    rayes_scene_release(a);
    if (b)
        rayes_scene_release(b);
    free(written);
}

/* BMRT's arealight lights as a point light of its intensity spread over
 * the shape: a small square, disk or bilinear patch of intensity 4, two
 * units from a white matte floor, gives it 4 / 2^2 = 1 below (RSL's
 * diffuse() has no 1 / pi), a small sphere a quarter of that (the mean of
 * its samples' cosines toward the floor, as BMRT averages them). */
static void test_bmrt_units(void)
{
    static const struct {
        const char *shape;
        double expect;
    } cases[] = {
        {"Polygon \"P\" [-0.05 -0.05 4  0.05 -0.05 4  0.05 0.05 4  -0.05 0.05 4]", 1.0},
        {"Translate 0 0 4\nDisk 0 0.05 360", 1.0},
        {"Patch \"bilinear\" \"P\" [-0.05 -0.05 4  0.05 -0.05 4  -0.05 0.05 4  0.05 0.05 4]", 1.0},
        {"Translate 0 0 4\nSphere 0.05 -0.05 0.05 360", 0.25},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "Format 8 8 1\nProjection \"perspective\" \"fov\" [4]\nWorldBegin\n"
                 "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"
                 "AreaLightSource \"arealight\" 1 \"intensity\" [4] \"float twosided\" [%d]\n"
                 "%s\nAttributeEnd\nSurface \"matte\"\n"
                 "Polygon \"P\" [-9 -9 6  9 -9 6  9 9 6  -9 9 6]\nWorldEnd\n",
                 k < 3, cases[k].shape);
        RayesImage *img = rib_render_text(text, 8, 64);
        CHECK(img != NULL);
        if (img) {
            double m = 0; /* the four middle pixels */
            for (int y = 3; y < 5; y++)
                for (int x = 3; x < 5; x++)
                    m += img->rgba[4 * (8 * y + x)] / 4.0;
            CHECK_NEAR(m, cases[k].expect, 0.02 * cases[k].expect);
            if (fabs(m - cases[k].expect) > 0.02 * cases[k].expect)
                fprintf(stderr, "  %s: %g\n", cases[k].shape, m);
        }
        rayes_image_free(img);
    }
}

/* pbrt-v4's goniometric light: its equal-area square's centre is the
 * light space's +y (pbrt swaps y and z), times I and scale; projection
 * lights take their fov. */
static void test_pbrt_goniometric(void)
{
    const char *path = RAYES_TEST_TMP "/test_gonio.exr";
    float px[8 * 8 * 4];
    for (int i = 0; i < 64; i++) {
        int x = i % 8, y = i / 8, centre = (x == 3 || x == 4) && (y == 3 || y == 4);
        for (int c = 0; c < 3; c++)
            px[4 * i + c] = centre ? 10.0f : 0.5f;
        px[4 * i + 3] = 1;
    }
    CHECK(image_write_exr(path, 8, 8, px, NULL, 0) == RAYES_OK);
    char text[512];
    snprintf(text, sizeof text,
             "WorldBegin\nLightSource \"goniometric\" \"string filename\" \"%s\" "
             "\"rgb I\" [1 2 1] \"float scale\" 3\n"
             "LightSource \"projection\" \"string filename\" \"%s\" \"float fov\" 30\n",
             path, path);
    char err[256];
    RayesError e;
    RayesScene *s = pbrt_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(s->n_lights == 2);
    if (s->n_lights == 2) {
        LightSample up, side;
        CHECK(light_sample(&s->lights[0], v3(0, 1, 0), 0.5f, 0.5f, &up)); /* above the light */
        CHECK(light_sample(&s->lights[0], v3(1, 0, 0), 0.5f, 0.5f, &side));
        CHECK_NEAR(up.Li.y, 3 * 2 * 10, 0.1 * 60); /* toward +y: the centre */
        CHECK_NEAR(side.Li.y, 3 * 2 * 0.5, 0.1 * 3);
        CHECK(s->lights[1].map_projection &&
              fabsf(s->lights[1].map_tan - tanf(0.2617994f)) < 1e-5f);
    }
    rayes_scene_release(s);
}

/* Textured emitters: RIB's arealight "texturename" over the shape's st,
 * written back and read again (the same texture coordinates, corner for
 * corner); pbrt-v4's "filename" over a bilinear patch (its default uv,
 * looked up at (u, 1 - v)) and over a triangle mesh's uv. */
static void test_textured_emitters(void)
{
    const char *path = RAYES_TEST_TMP "/test_emit_tex.exr";
    float px[4 * 2 * 4];
    for (int i = 0; i < 8; i++)
        for (int c = 0; c < 4; c++)
            px[4 * i + c] = c == 3 ? 1.0f : (float)(i + c) / 8.0f;
    CHECK(image_write_exr(path, 4, 2, px, NULL, 0) == RAYES_OK);
    char text[1024];
    snprintf(text, sizeof text,
             WORLD("Translate 0 0 5\nAttributeBegin\n"
                   "AreaLightSource \"arealight\" 1 \"color lightcolor\" [2 2 2] "
                   "\"string texturename\" \"%s\"\n"
                   "PointsPolygons [4] [0 1 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0] "
                   "\"st\" [0 1 1 1 1 0 0 0]\nAttributeEnd"),
             path);
    char err[256];
    RayesError e;
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written && strstr(written, "texturename") && strstr(written, "\"st\""));
    RayesScene *a = rib_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK);
    RayesScene *b = written ? rib_read_scene(written, &e, err, sizeof err) : NULL;
    CHECK(b && e == RAYES_OK);
    if (b && a->n_lights == 1 && b->n_lights == 1 && a->lights[0].type == LIGHT_MESH &&
        b->lights[0].type == LIGHT_MESH) {
        const LightMesh *m = a->lights[0].mesh, *n = b->lights[0].mesh;
        CHECK(m->tex && n->tex && m->tex_w == 4 && m->tex_h == 2 && n->n == m->n);
        CHECK(m->st && n->st && memcmp(m->st, n->st, 6 * m->n * sizeof *m->st) == 0);
        /* the corner at (0, 0, 0) of the file is st (0, 1): the image's
         * bottom left; the light's radiance there is L times that texel */
        Vec3 at = v3(0.001f, 0.001f, 5.0f), want = v3(2 * 4 / 8.0f, 2 * 5 / 8.0f, 2 * 6 / 8.0f);
        uint32_t tri = 0;
        for (uint32_t k = 0; k < m->n; k++) /* the triangle holding that corner */
            for (int c = 0; c < 3; c++)
                tri = m->v[3 * m->place[k] + (size_t)c].x == 0.0f &&
                              m->v[3 * m->place[k] + (size_t)c].y == 0.0f
                          ? k
                          : tri;
        Vec3 got = light_mesh_radiance(&a->lights[0], tri, at);
        CHECK_NEAR(got.x, want.x, 0.02);
        CHECK_NEAR(got.z, want.z, 0.02);
    } else {
        CHECK(!"one mesh light each");
    }
    rayes_scene_release(a);
    if (b)
        rayes_scene_release(b);
    free(written);
    /* pbrt-v4: a bilinear patch (default uv) and a triangle mesh's uv */
    snprintf(text, sizeof text,
             "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" "
             "\"%s\" \"float scale\" 3\n"
             "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\nAttributeEnd\n"
             "AttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" \"%s\"\n"
             "Shape \"trianglemesh\" \"point3 P\" [0 0 1 1 0 1 1 1 1] \"integer indices\" "
             "[0 1 2] \"point2 uv\" [0 0 1 0 0.25 0.75]\nAttributeEnd\n",
             path, path);
    RayesScene *s = pbrt_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK && s->n_lights == 2);
    if (e == RAYES_OK && s->n_lights == 2 && s->lights[0].type == LIGHT_MESH &&
        s->lights[1].type == LIGHT_MESH) {
        const LightMesh *m = s->lights[0].mesh, *n = s->lights[1].mesh;
        CHECK(m->tex && n->tex && s->lights[0].L.x == 3.0f && s->lights[1].L.x == 1.0f);
        /* the triangle's third corner: uv (0.25, 0.75), st (0.25, 0.25) */
        CHECK(n->n == 1 && n->st[4] == 0.25f && n->st[5] == 0.25f);
        float lo = 1, hi = 0; /* the patch's t spans 0 to 1 */
        for (size_t k = 0; k < 6 * m->n; k += 2)
            lo = fminf(lo, m->st[k + 1]), hi = fmaxf(hi, m->st[k + 1]);
        CHECK(lo == 0.0f && hi == 1.0f);
    } else {
        CHECK(!"two mesh lights");
    }
    rayes_scene_release(s);
    /* an image wider than LIGHT_TEXTURE_MAX is halved until it fits, its
     * halves keeping their colours */
    const char *wide = RAYES_TEST_TMP "/test_emit_wide.exr";
    enum { WIDE = 2 * LIGHT_TEXTURE_MAX + 4 };
    float *row = calloc(4 * WIDE * 3, sizeof *row);
    for (int i = 0; row && i < WIDE * 3; i++) {
        row[4 * i + ((i % WIDE) < WIDE / 2 ? 0 : 1)] = 1.0f; /* red, then green */
        row[4 * i + 3] = 1.0f;
    }
    CHECK(row && image_write_exr(wide, WIDE, 3, row, NULL, 0) == RAYES_OK);
    free(row);
    snprintf(text, sizeof text,
             "WorldBegin\nAreaLightSource \"diffuse\" \"string filename\" \"%s\"\n"
             "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n",
             wide);
    s = pbrt_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK && s->n_lights == 1);
    if (e == RAYES_OK && s->n_lights == 1 && s->lights[0].type == LIGHT_MESH) {
        const LightMesh *m = s->lights[0].mesh;
        CHECK(m->tex_w == WIDE / 4 && m->tex_h == 1);
        CHECK(m->tex && m->tex[0] == 1.0f && m->tex[1] == 0.0f); /* the left: red */
        CHECK(m->tex && m->tex[3 * (m->tex_w - 1) + 1] == 1.0f); /* the right: green */
    }
    rayes_scene_release(s);
    /* RenderMan's PxrRectLight with a lightColorMap: a quad of the image,
     * written back as rayes' arealight with its mapname, read again */
    snprintf(text, sizeof text,
             WORLD("Light \"PxrRectLight\" \"r\" \"float intensity\" [2] "
                   "\"string lightColorMap\" \"%s\"\nBxdf \"PxrDiffuse\" \"d\"\n"
                   "Polygon \"P\" [-3 -1 -3 3 -1 -3 3 -1 3 -3 -1 3]"),
             path);
    written = rib_round_trip(text, err, sizeof err);
    CHECK(written && strstr(written, "\"string mapname\"") != NULL);
    for (int pass = 0; pass < 2; pass++) {
        RayesScene *q = rib_read_scene(pass ? (written ? written : "") : text, &e, err, sizeof err);
        CHECK(e == RAYES_OK && q->n_lights == 1);
        if (e == RAYES_OK && q->n_lights == 1) {
            const Light *l = &q->lights[0];
            CHECK(l->type == LIGHT_MESH && l->mesh->tex && l->mesh->n == 2 && l->L.x == 2.0f);
        }
        rayes_scene_release(q);
    }
    free(written);
}

TEST_MAIN(TEST(test_polygons_under_area_lights), TEST(test_round_trip),
          TEST(test_quadrics_and_motion), TEST(test_bmrt_units), TEST(test_pbrt_goniometric),
          TEST(test_textured_emitters))
