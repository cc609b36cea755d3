/*
 * tests/io/test_obj.c — the OBJ/MTL reader of io/obj.h, through a recording
 * IoSink (io/record_sink.h): face syntaxes and relative indices, n-gon and
 * concave triangulation (the triangles cover the polygon, all facing its
 * way), materials from an MTL beside the file, emissive quads as area
 * lights, the default camera and light, and bad input, whose one-line
 * errors name "file:line:col" and leave the sink untouched. Buffers are
 * heap copies of exactly their size, so AddressSanitizer catches reads past
 * the end.
 */
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "io/obj.h"
#include "io/record_sink.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#ifndef RAYES_TEST_TMP
#error "RAYES_TEST_TMP must name a scratch directory"
#endif

#define DIR RAYES_TEST_TMP "/io_obj"

static Record rec;
static char err[512];

static IoReadOptions read_options = {NULL, -1};

static RayesError parse(const char *name, const char *text)
{
    size_t n = strlen(text);
    char *copy = malloc(n ? n : 1);
    memcpy(copy, text, n);
    IoSink sink = record_sink(&rec);
    IoSettings st;
    IoReadOptions ro = read_options;
    io_settings_init(&st);
    RayesError e = io_obj_parse(name, (const unsigned char *)copy, n, &sink, &ro, &st, err,
                                sizeof err);
    free(copy);
    CHECK(st.width == 0 && st.n_displays == 0); /* OBJ gives no settings */
    return e;
}

/* The point of corner c of face f of mesh m. */
static const float *corner(const RecMesh *m, size_t f, int c)
{
    size_t k = 0;
    for (size_t i = 0; i < f; i++)
        k += (size_t)m->nv[i];
    return &m->P[3 * (size_t)m->idx[k + (size_t)c]];
}

/* The z component of the total signed area of mesh m's faces (twice). */
static double area_z(const RecMesh *m)
{
    double a = 0.0;
    for (size_t f = 0; f < m->n_faces; f++)
        for (int c = 0; c < m->nv[f]; c++) {
            const float *p = corner(m, f, c), *q = corner(m, f, (c + 1) % m->nv[f]);
            a += (double)p[0] * q[1] - (double)q[0] * p[1];
        }
    return a * 0.5;
}

/* -------------------------------------------------------------- tests */

/* The normal of corner c of face f of m, and whether it is n. */
static int corner_normal_is(const RecMesh *m, size_t f, int c, float x, float y, float z)
{
    const RayesPrimvar *N = rec_primvar(&m->pv, "N");
    if (!N || N->cls != RAYES_PRIMVAR_FACEVARYING)
        return 0;
    const float *v = &N->data[3 * (3 * f + (size_t)c)];
    return fabsf(v[0] - x) < 1e-6f && fabsf(v[1] - y) < 1e-6f && fabsf(v[2] - z) < 1e-6f;
}

static void test_face_syntax(void)
{
    static const char text[] = "# a square four ways\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                               "g one two\ns 1\no obj\n"
                               "f 1 2 3\n"
                               "f 1/1 3/3 4/3\n"
                               "f -4//1 -3//-1 -2//1\n"
                               "f -4/-3/-1 -2/-1/1 -1/2/1\r\n"
                               "f 1 2 \\\n 3 4"; /* continued, no final newline */
    CHECK(parse("sq.obj", text) == RAYES_OK);
    CHECK(err[0] == '\0');
    /* the faces with texture coordinates, then those without */
    CHECK(rec.n_mesh == 2 && rec.n_shader == 1);
    if (rec.n_mesh == 2) {
        const RecMesh *m = &rec.mesh[0], *w = &rec.mesh[1];
        CHECK(m->n_faces == 2 && m->n_points == 3 && w->n_faces == 3 && w->n_points == 4);
        CHECK(w->nv[0] == 3 && w->nv[2] == 4);
        CHECK(rec_primvar(&m->pv, "st") != NULL && rec_primvar(&w->pv, "st") == NULL);
        /* -4/-3/-1 -2/-1/1 -1/2/1 = vertices 1 3 4 */
        CHECK(corner(m, 1, 0)[0] == 0 && corner(m, 1, 0)[1] == 0);
        CHECK(corner(m, 1, 1)[0] == 1 && corner(m, 1, 1)[1] == 1);
        CHECK(corner(m, 1, 2)[0] == 0 && corner(m, 1, 2)[1] == 1);
        CHECK_NEAR(area_z(m) + area_z(w), 0.5 * 4 + 1, 1e-6);
    }
    CHECK(strcmp(rec.shader[0].name, "matte") == 0);
    record_free(&rec);
}

static void test_ngons(void)
{
    /* a convex pentagon, an L-shaped hexagon (concave), a dart (concave
     * quad) and a convex quad */
    static const char text[] = "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\n"
                               "f 1 2 3 4 5\n"
                               "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\n"
                               "f -6 -5 -4 -3 -2 -1\n"
                               "v 0 0 2\nv 2 1 2\nv 0 2 2\nv 0.5 1 2\n"
                               "f -4 -3 -2 -1\n"
                               "v 0 0 3\nv 1 0 3\nv 1 1 3\nv 0 1 3\n"
                               "f -4 -3 -2 -1\n";
    CHECK(parse("ngon.obj", text) == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    if (rec.n_mesh != 1)
        return;
    const RecMesh *m = &rec.mesh[0];
    CHECK(m->n_faces == 3 + 4 + 2 + 1);
    /* every triangle faces +z (CCW), and each polygon's area is covered */
    double by_z[4] = {0};
    int all_ccw = 1;
    for (size_t f = 0; f < m->n_faces; f++) {
        const float *a = corner(m, f, 0), *b = corner(m, f, 1), *c = corner(m, f, 2);
        double cz = ((double)b[0] - a[0]) * ((double)c[1] - a[1]) -
                    ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
        all_ccw &= cz > 0.0;
        if (!(cz > 0.0))
            fprintf(stderr, "  face %zu: (%g %g) (%g %g) (%g %g) z %g\n", f, a[0], a[1], b[0], b[1],
                    c[0], c[1], a[2]);
        RecMesh one = *m;
        one.n_faces = 1;
        size_t k = 0;
        for (size_t i = 0; i < f; i++)
            k += (size_t)m->nv[i];
        one.nv = &m->nv[f];
        one.idx = &m->idx[k];
        by_z[(int)a[2]] += area_z(&one);
    }
    CHECK(all_ccw);
    CHECK_NEAR(by_z[0], 5.0, 1e-5);  /* pentagon: shoelace */
    CHECK_NEAR(by_z[1], 3.0, 1e-5);  /* L: 2 x 2 minus 1 x 1 */
    CHECK_NEAR(by_z[2], 1.5, 1e-5);  /* dart */
    CHECK_NEAR(by_z[3], 1.0, 1e-5);
    CHECK(m->nv[m->n_faces - 1] == 4); /* the convex quad stays a quad */
    record_free(&rec);
}

static void test_materials(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    test_write_text(DIR "/m.mtl", "# materials\n"
                                  "newmtl red\nKd 0.6 0.1 0.05\nd 1\nillum 1\n"
                                  "newmtl shiny\nKd 0.2 0.3 0.4\nKs 0.5 0.5 0.5\nNs 40\nillum 2\n"
                                  "newmtl wood\nKd 0.47 0.47 0.47\nmap_Kd -s 2 2 1 wood.png\n"
                                  "newmtl lamp\nKd 0 0 0\nKe 5 4 3\n"
                                  "newmtl panel\nKe 1 2 3\n");
    static const char text[] = "mtllib m.mtl\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "usemtl red\nf 1 2 3\n"
                               "usemtl shiny\nf 1 3 4\n"
                               "usemtl wood\nf 1 2 3 4\n"
                               "usemtl lamp\nf 4 3 2 1\nf 1 2 3\n"
                               "usemtl missing\nf 2 3 4\n"
                               "usemtl panel\nf 4 3 2 1\n";
    CHECK(parse(DIR "/scene.obj", text) == RAYES_OK);
    if (err[0])
        fprintf(stderr, "  %s\n", err);
    /* default (the undefined material), red, shiny, wood */
    CHECK(rec.n_shader == 4 && rec.n_mesh == 4);
    if (rec.n_shader != 4)
        return;
    const RayesParam *p;
    CHECK(strcmp(rec.shader[0].name, "matte") == 0);
    CHECK(strcmp(rec.shader[1].name, "matte") == 0);
    CHECK((p = rec_param(&rec.shader[1], "Cs")) && p->value[0] == 0.6f && p->value[2] == 0.05f);
    CHECK(strcmp(rec.shader[2].name, "plastic") == 0);
    CHECK((p = rec_param(&rec.shader[2], "Cs")) && p->value[1] == 0.3f);
    CHECK((p = rec_param(&rec.shader[2], "specularcolor")) && p->value[0] == 0.5f);
    CHECK((p = rec_param(&rec.shader[2], "roughness")) && fabsf(p->value[0] - 1.0f / 40) < 1e-7f);
    CHECK(strcmp(rec.shader[3].name, "paintedplastic") == 0);
    CHECK((p = rec_param(&rec.shader[3], "texturename")) &&
          strcmp(p->string, DIR "/wood.png") == 0);
    /* the map replaces Kd (3ds Max's default 0.47 beside it) */
    CHECK((p = rec_param(&rec.shader[3], "Cs")) && p->value[0] == 1.0f && p->value[2] == 1.0f);
    /* the lamp's quad and triangle are one mesh light with L = Ke; the
     * panel's one quad a quad light, in order */
    CHECK(rec.n_area == 1 && rec.n_mesh_light == 1);
    CHECK(rec.area_P[0][0][0] == 0 && rec.area_P[0][0][1] == 1 && rec.area_L[0][1] == 2.0f);
    CHECK(rec.mesh_light_faces[0] == 2 && rec.mesh_light_L[0][1] == 4.0f &&
          !rec.mesh_light_two_sided[0]);
    CHECK(rec.n_light == 0); /* something emits: no default light */
    CHECK(rec.n_camera == 1);
    record_free(&rec);

    /* a missing MTL is a warning, not an error */
    CHECK(parse(DIR "/x.obj", "mtllib nosuch.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") ==
          RAYES_OK);
    CHECK(rec.n_mesh == 1);
    record_free(&rec);
}

/* d and Tr: d wins when both are given ("d 1 Tr 1", MeshLab's Tr as d's
 * synonym), Tr alone is 1 - d, and an opacity of 0 ("d 0", which many
 * exporters write for opaque) is opaque, not an invisible material. */
static void test_opacity_words(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    test_write_text(DIR "/o.mtl", "newmtl zero\nKd 0.5 0.5 0.5\nd 0.000000\nillum 2\n"
                                  "newmtl both\nd 1\nTr 1\n"
                                  "newmtl tr\nTr 0.25\n"
                                  "newmtl trone\nTr 1\n"
                                  "newmtl half\nd 0.5\n"
                                  "newmtl win\nKd 0 0 0\nd 0\nTf 0.5 0.5 0.5\nillum 6\n"
                                  "newmtl green\nd 0\nTf 0.25 0.75 0.125\nillum 4\n"
                                  "newmtl yellow\nd 1\nTf 1 0.875 0\nillum 4\n"
                                  "newmtl clear\nd 0\nillum 9\n"
                                  "newmtl glass\nKd 0 0 0\nNi 1.5\nillum 7\n"
                                  "newmtl redglaze\nKd 0.8 0 0\nNi 1.45\nd 0.9\nillum 6\n");
    static const char text[] = "mtllib o.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                               "usemtl zero\nf 1 2 3\nusemtl both\nf 1 2 3\n"
                               "usemtl tr\nf 1 2 3\nusemtl trone\nf 1 2 3\n"
                               "usemtl half\nf 1 2 3\nusemtl win\nf 1 2 3\n"
                               "usemtl green\nf 1 2 3\nusemtl yellow\nf 1 2 3\n"
                               "usemtl clear\nf 1 2 3\nusemtl glass\nf 1 2 3\n"
                               "usemtl redglaze\nf 1 2 3\n";
    CHECK(parse(DIR "/o.obj", text) == RAYES_OK);
    CHECK(rec.n_shader == 11);
    if (rec.n_shader == 11) {
        const RayesParam *p;
        CHECK(rec_param(&rec.shader[0], "Os") == NULL); /* d 0: opaque */
        CHECK(rec_param(&rec.shader[1], "Os") == NULL); /* d 1 wins over Tr 1 */
        CHECK((p = rec_param(&rec.shader[2], "Os")) && p->value[0] == 0.75f);
        CHECK(rec_param(&rec.shader[3], "Os") == NULL); /* Tr 1 alone: 0, opaque */
        CHECK((p = rec_param(&rec.shader[4], "Os")) && p->value[1] == 0.5f);
        /* the transparent models (illum 4, 6, 7, 9) pass Tf, else 1 - d */
        CHECK((p = rec_param(&rec.shader[5], "Os")) && p->value[0] == 0.5f);
        CHECK((p = rec_param(&rec.shader[6], "Os")) && p->value[0] == 0.75f &&
              p->value[1] == 0.25f && p->value[2] == 0.875f);
        CHECK((p = rec_param(&rec.shader[7], "Os")) && p->value[0] == 0.0f &&
              p->value[1] == 0.125f && p->value[2] == 1.0f);
        CHECK((p = rec_param(&rec.shader[8], "Os")) && p->value[0] == 0.0f);
        /* refraction with an index: a thin sheet of glass */
        CHECK(strcmp(rec.shader[9].name, "thindielectric") == 0 &&
              (p = rec_param(&rec.shader[9], "eta")) && p->value[0] == 1.5f);
        /* an opaque colour an exporter marked illum 6 stays that colour */
        CHECK(strcmp(rec.shader[10].name, "thindielectric") != 0 &&
              (p = rec_param(&rec.shader[10], "Cs")) && p->value[0] == 0.8f &&
              (p = rec_param(&rec.shader[10], "Os")) && fabsf(p->value[0] - 0.9f) < 1e-6f);
    }
    record_free(&rec);
}

/* A map's file as a Windows-authored MTL names it: backslashes, other
 * capitals than the disk's, or an absolute path of the machine that wrote
 * it whose file lies beside the MTL. */
static void test_map_paths(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    mkdir(DIR "/tex", 0777);
    test_write_text(DIR "/tex/wood.png", "not read by the parser");
    test_write_text(DIR "/stone.png", "not read by the parser");
    test_write_text(DIR "/my wood.png", "not read by the parser");
    test_write_text(DIR "/p.mtl", "newmtl a\nmap_Kd tex\\wood.png\n"
                                  "newmtl b\nmap_Kd TEX/Wood.PNG\n"
                                  "newmtl c\nmap_Kd C:\\Users\\me\\Stone.png\n"
                                  "newmtl d\nmap_Kd tex/gone.png\n"
                                  "newmtl f\nmap_Kd D:\\work\\proj\\TEX\\wood.png\n");
    test_write_text(DIR "/my lib.mtl", "newmtl e\nmap_Kd -s 1 1 1 my wood.png\n");
    CHECK(parse(DIR "/p.obj",
                "mtllib p.mtl\nmtllib my lib.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\n"
                "f 1 2 3\nusemtl b\nf 1 2 3\nusemtl c\nf 1 2 3\nusemtl d\nf 1 2 3\n"
                "usemtl e\nf 1 2 3\nusemtl f\nf 1 2 3\n") == RAYES_OK);
    /* names with spaces, as Blender writes them: the library and the map
     * (materials in the order their libraries define them: f before e);
     * another machine's absolute path found by its tail */
    CHECK(rec.n_shader == 6);
    if (rec.n_shader == 6) {
        const char *want[6] = {DIR "/tex/wood.png", DIR "/tex/wood.png", DIR "/stone.png",
                               DIR "/tex/gone.png", DIR "/tex/wood.png", DIR "/my wood.png"};
        for (int k = 0; k < 6; k++) {
            const RayesParam *p = rec_param(&rec.shader[k], "texturename");
            CHECK(p && strcmp(p->string, want[k]) == 0);
            if (p && strcmp(p->string, want[k]) != 0)
                printf("  material %d: %s, expected %s\n", k, p->string, want[k]);
        }
    }
    record_free(&rec);
}

/* The PBR extension (Pr, Pm): a dielectric lobe under a glossy coat, a
 * metal of the base colour, or their mix by the metallic; rayes' roughness
 * is alpha squared, Pr^4. */
static void test_pbr_extension(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    test_write_text(DIR "/b.mtl", "newmtl gold\nKd 0.9 0.6 0.2\nPr 0.5\nPm 1\n"
                                  "NEWMTL paint\nkd 0.2 0.3 0.8\npr 0.25\nKS 0.5 0.5 0.5\n"
                                  "newmtl half\nPm 0.5\nd 0.5\n");
    CHECK(parse(DIR "/b.obj", "mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl gold\nf 1 2 3\n"
                              "usemtl paint\nf 1 2 3\nusemtl half\nf 1 2 3\n") == RAYES_OK);
    CHECK(rec.n_shader == 3);
    if (rec.n_shader == 3) {
        const RayesParam *p;
        CHECK(strcmp(rec.shader[0].name, "conductor") == 0);
        CHECK((p = rec_param(&rec.shader[0], "reflectance")) && p->value[1] == 0.6f);
        CHECK((p = rec_param(&rec.shader[0], "roughness")) && p->value[0] == 0.0625f);
        CHECK(strcmp(rec.shader[1].name, "coateddiffuse") == 0);
        CHECK((p = rec_param(&rec.shader[1], "reflectance")) && p->value[2] == 0.8f);
        CHECK((p = rec_param(&rec.shader[1], "roughness")) &&
              fabsf(p->value[0] - 0.25f * 0.25f * 0.25f * 0.25f) < 1e-9f);
        CHECK(strcmp(rec.shader[2].name, "mix") == 0);
        CHECK((p = rec_param(&rec.shader[2], "a")) && strcmp(p->string, "coateddiffuse") == 0);
        CHECK((p = rec_param(&rec.shader[2], "b")) && strcmp(p->string, "conductor") == 0);
        CHECK((p = rec_param(&rec.shader[2], "amount")) && p->value[0] == 0.5f);
        CHECK((p = rec_param(&rec.shader[2], "b:roughness")) && p->value[0] == 0.0625f);
        CHECK((p = rec_param(&rec.shader[2], "Os")) && p->value[0] == 0.5f);
    }
    record_free(&rec);
}

static void test_default_camera_and_light(void)
{
    CHECK(parse("c.obj", "v -1 -2 -3\nv 3 -2 -3\nv 3 4 5\nf 1 2 3\n") == RAYES_OK);
    CHECK(rec.n_camera == 1);
    CHECK(rec.at[0] == 1 && rec.at[1] == 1 && rec.at[2] == 1); /* the bounds' centre */
    CHECK(rec.eye[0] == rec.at[0] && rec.eye[1] == rec.at[1] && rec.eye[2] > rec.at[2] + 5);
    CHECK(rec.up[1] == 1 && rec.fov == 40.0f);
    /* the bounding sphere (radius sqrt(4 + 9 + 16)) fits the field of view */
    double d = rec.eye[2] - rec.at[2];
    CHECK(asin(sqrt(29.0) / d) <= 20.0 * M_PI / 180.0 + 1e-6);
    CHECK(rec.n_light == 1 && strcmp(rec.light[0].name, "distantlight") == 0);
    const RayesParam *from = rec_param(&rec.light[0], "from");
    CHECK(from && from->value[0] < rec.at[0] && from->value[1] > rec.at[1] &&
          from->value[2] > rec.at[2]); /* upper left, in front */
    record_free(&rec);
    CHECK(!rec_param(&rec.light[0], "shadows")); /* it casts them */
    record_free(&rec);
    /* an empty file: a camera at the origin's front and a light, no geometry */
    CHECK(parse("e.obj", "") == RAYES_OK);
    CHECK(rec.n_camera == 1 && rec.n_mesh == 0 && rec.n_light == 1);
    record_free(&rec);
}

/* map_Ke: an emitter textured over its faces' vt (a sign, a screen), one
 * mesh light however few quads, t = 1 - v, the map alone when Ke is 0 or
 * missing; faces without vt emit Ke alone, with a warning. */
static void test_emission_map(void)
{
    test_write_text(DIR "/sign.mtl", "newmtl sign\nKe 0 0 0\nmap_Ke sign.png\n"
                                     "newmtl tinted\nKe 2 1 1\nmap_Ke sign.png\n");
    test_write_text(DIR "/sign.png", "not read by the parser");
    CHECK(parse(DIR "/sign.obj", "mtllib sign.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                 "vt 0.25 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                 "usemtl sign\nf 1/1 2/2 3/3 4/4\n"
                                 "usemtl tinted\nf 1/1 2/2 3/3\n") == RAYES_OK);
    CHECK(rec.n_area == 0 && rec.n_mesh_light == 2 && rec.n_light == 0);
    CHECK(strcmp(rec.mesh_light_texture[0], DIR "/sign.png") == 0);
    CHECK(rec.mesh_light_L[0][0] == 1.0f && rec.mesh_light_L[0][2] == 1.0f); /* the map alone */
    CHECK(rec.mesh_light_st0[0][0] == 0.25f && rec.mesh_light_st0[0][1] == 1.0f);
    CHECK(rec.mesh_light_L[1][0] == 2.0f && rec.mesh_light_texture[1][0] != '\0');
    record_free(&rec);
    /* without vt: Ke alone (here the map's white), untextured */
    CHECK(parse(DIR "/sign2.obj", "mtllib sign.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                  "usemtl sign\nf 1 2 3\n") == RAYES_OK);
    CHECK(rec.n_mesh_light == 1);
    CHECK(rec.mesh_light_texture[0][0] == '\0');
    CHECK(rec.mesh_light_L[0][1] == 1.0f);
    record_free(&rec);
}

/* The default light follows the view the caller will set: from behind
 * the geometry (looking down +z) it comes from that view's upper left;
 * from inside the bounds (a room) it is a headlight along the view that
 * casts no shadows, since the walls would shadow any other. */
static void test_default_light_follows_the_view(void)
{
    static const char *box = "v -2 -1 -2\nv 2 -1 -2\nv 2 1 2\nf 1 2 3\n";
    read_options.view = IO_VIEW_FROM | IO_VIEW_AT;
    memcpy(read_options.view_from, (float[3]){0, 0, -20}, sizeof read_options.view_from);
    memcpy(read_options.view_at, (float[3]){0, 0, 0}, sizeof read_options.view_at);
    CHECK(parse("behind.obj", box) == RAYES_OK && rec.n_light == 1);
    const RayesParam *from = rec_param(&rec.light[0], "from"), *to = rec_param(&rec.light[0], "to");
    CHECK(from && to);
    if (from && to) {
        float dir[3];
        for (int k = 0; k < 3; k++)
            dir[k] = from->value[k] - to->value[k];
        /* the view's right is -x, its up +y, behind it -z */
        CHECK(dir[0] > 0.5f * fabsf(dir[1]) && dir[1] > 0.0f && dir[2] < -0.5f * dir[1]);
        CHECK(!rec_param(&rec.light[0], "shadows"));
    }
    record_free(&rec);
    memcpy(read_options.view_from, (float[3]){0.5f, 0, 0}, sizeof read_options.view_from);
    memcpy(read_options.view_at, (float[3]){0.5f, 0, 1}, sizeof read_options.view_at);
    CHECK(parse("inside.obj", box) == RAYES_OK && rec.n_light == 1);
    const RayesParam *shadows = rec_param(&rec.light[0], "shadows");
    from = rec_param(&rec.light[0], "from"), to = rec_param(&rec.light[0], "to");
    CHECK(shadows && shadows->value[0] == 0.0f && from && to);
    if (from && to)
        CHECK(to->value[2] - from->value[2] > 0.99f &&
              fabsf(to->value[0] - from->value[0]) < 1e-6f);
    record_free(&rec);
    read_options.view = 0;
}

/* Bad input: the message, and nothing sent to the sink. */
static void expect_error(const char *text, const char *where)
{
    RayesError e = parse("bad.obj", text);
    CHECK(e == RAYES_ERROR_PARSE);
    CHECK(strncmp(err, where, strlen(where)) == 0 && strchr(err, '\n') == NULL);
    CHECK(rec.calls == 0);
    if (e != RAYES_ERROR_PARSE || strncmp(err, where, strlen(where)) != 0)
        fprintf(stderr, "  expected %s..., got: %s\n", where, err);
    record_free(&rec);
}

/* vn and vt reach the sink as facevarying N and st (t = 1 - v), one per
 * corner of the faces sent, also through ear clipping; a material whose
 * faces only partly have them gets none. */
static void test_normals_and_texture_coordinates(void)
{
    CHECK(parse("n.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nvn 0 1 1\n"
                         "f 1/1/1 2/2/1 3/3/2 4/4/2\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    const RecMesh *m = &rec.mesh[0];
    const RayesPrimvar *N = rec_primvar(&m->pv, "N"), *st = rec_primvar(&m->pv, "st");
    CHECK(N && N->cls == RAYES_PRIMVAR_FACEVARYING && N->count == 4);
    CHECK(st && st->cls == RAYES_PRIMVAR_FACEVARYING && st->count == 4);
    for (int c = 0; N && st && c < 4; c++) {
        const float *p = corner(m, 0, c); /* vt = the point's (x, y); vn 2 on y = 1 */
        CHECK_NEAR(st->data[2 * c], p[0], 0);
        CHECK_NEAR(st->data[2 * c + 1], 1 - p[1], 0);
        CHECK_NEAR(N->data[3 * c + 1], p[1], 0);
    }
    record_free(&rec);
    /* an L-shaped hexagon, ear clipped: every corner keeps its own vt */
    CHECK(parse("l.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                         "vt 0 0\nvt 2 0\nvt 2 1\nvt 1 1\nvt 1 2\nvt 0 2\n"
                         "f 1/1 2/2 3/3 4/4 5/5 6/6\n") == RAYES_OK);
    m = &rec.mesh[0];
    st = rec_primvar(&m->pv, "st");
    CHECK(st && st->count == 3 * m->n_faces && !rec_primvar(&m->pv, "N"));
    for (size_t f = 0; st && f < m->n_faces; f++)
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(st->data[2 * (3 * f + (size_t)c)], corner(m, f, c)[0], 0);
            CHECK_NEAR(st->data[2 * (3 * f + (size_t)c) + 1], 1 - corner(m, f, c)[1], 0);
        }
    record_free(&rec);
    /* a face without vn beside one with: its corners take its own normal */
    CHECK(parse("p.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nvn 0 1 0\nf 1//1 2//1 3//1\n"
                         "f 1 3 4\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].pv.n == 1);
    if (rec.n_mesh == 1) {
        const float r = 1.0f / sqrtf(3.0f); /* (1,1,0) x (0,1,1) normalised */
        CHECK(corner_normal_is(&rec.mesh[0], 0, 0, 0, 1, 0));
        CHECK(corner_normal_is(&rec.mesh[0], 1, 2, r, -r, r));
    }
    record_free(&rec);
}

/* Smoothing groups: faces of one group share their vertices' normals (the
 * sum of their area-weighted normals), so a fold between two faces of
 * group 1 is smooth; faces in different groups, or in none, stay flat;
 * a file without s statements sends no normals. "s on" (exporters') is
 * group 1; numbers of any size read. */
static void test_smoothing_groups(void)
{
    static const char fold[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    char text[256];
    const float h = (float)(1.0 / sqrt(2.0));
    for (int mode = 0; mode < 3; mode++) {
        /* the face in z = 0 faces +z, the one in y = 0 faces +y; they
         * share the edge from vertex 1 to 2 */
        static const char *const s[3][2] = {
            {"s 1", "s on"}, {"s 1", "s 4294967298"}, {"s off", "s 0"}};
        snprintf(text, sizeof text, "%s%s\nf 1 2 3\n%s\nf 2 1 4\n", fold, s[mode][0], s[mode][1]);
        CHECK(parse("s.obj", text) == RAYES_OK);
        CHECK(rec.n_mesh == 1 && rec.mesh[0].n_faces == 2);
        const RecMesh *m = &rec.mesh[0];
        if (mode == 2) {
            CHECK(rec_primvar(&m->pv, "N") == NULL); /* flat, as without s */
            record_free(&rec);
            continue;
        }
        for (size_t f = 0; f < 2; f++)
            for (int c = 0; c < 3; c++) {
                const float *p = corner(m, f, c);
                int shared = p[1] == 0 && p[2] == 0; /* on the fold's edge */
                if (mode == 0 && shared)
                    CHECK(corner_normal_is(m, f, c, 0, h, h));
                else if (f == 0)
                    CHECK(corner_normal_is(m, f, c, 0, 0, 1));
                else
                    CHECK(corner_normal_is(m, f, c, 0, 1, 0));
            }
        record_free(&rec);
    }
}

/* Vertex colours (v x y z r g b, an extension scanners and MeshLab
 * write): a vertex-class Cs of the mesh's points, sRGB-encoded values made
 * linear, 0-255 values when some exceeds 1; none when a vertex has none. */
static void test_vertex_colours(void)
{
    CHECK(parse("c.obj", "v 0 0 0 0.5 0.5 0.5\nv 1 0 0 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n") ==
          RAYES_OK);
    CHECK(rec.n_mesh == 1);
    const RecMesh *m = &rec.mesh[0];
    const RayesPrimvar *Cs = rec_primvar(&m->pv, "Cs");
    CHECK(Cs && Cs->cls == RAYES_PRIMVAR_VERTEX && Cs->count == 3);
    for (int c = 0; Cs && c < 3; c++) {
        const float *p = corner(m, 0, c), *k = &Cs->data[3 * (size_t)m->idx[c]];
        if (p[0] == 0 && p[1] == 0)
            CHECK_NEAR(k[1], 0.2140, 1e-4); /* sRGB 0.5 */
        else if (p[0] == 1)
            CHECK(k[0] == 1.0f && k[1] == 0.0f);
        else
            CHECK(k[2] == 1.0f && k[0] == 0.0f);
    }
    record_free(&rec);
    CHECK(parse("c.obj", "v 0 0 0 255 128 0\nv 1 0 0 0 0 0\nv 0 1 0 0 0 0\nf 1 2 3\n") == RAYES_OK);
    Cs = rec_primvar(&rec.mesh[0].pv, "Cs");
    CHECK(Cs != NULL);
    for (int c = 0; Cs && c < 3; c++)
        if (corner(&rec.mesh[0], 0, c)[0] == 0 && corner(&rec.mesh[0], 0, c)[1] == 0)
            CHECK(Cs->data[3 * (size_t)rec.mesh[0].idx[c]] == 1.0f &&
                  fabsf(Cs->data[3 * (size_t)rec.mesh[0].idx[c] + 1] - 0.2159f) < 1e-3f);
    record_free(&rec);
    CHECK(parse("c.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n") == RAYES_OK);
    CHECK(rec_primvar(&rec.mesh[0].pv, "Cs") == NULL);
    record_free(&rec);
}

static void test_errors(void)
{
    expect_error("v 1 2\n", "bad.obj:1:6: expected a vertex coordinate, found the end");
    expect_error("v 1 2 x\n", "bad.obj:1:7: expected a vertex coordinate, found \"x\"");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\n\nf 1 2 9\n", "bad.obj:5:7: expected a vertex index from 1 to 3");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\nf 1 0 2\n", "bad.obj:4:5: expected a vertex index");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\nf -4 1 2\n", "bad.obj:4:3: expected a vertex index");
    expect_error("v 1 2 3\nv 1 2 3\nf 1 2\n", "bad.obj:3:6: expected at least 3 vertices");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\nf 1/1 2/1 3/1\n",
                 "bad.obj:4:5: expected a texture coordinate index, found 1 with none");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\nvn 0 0 1\nf 1//1 2//2 3//1\n",
                 "bad.obj:5:11: expected a normal index from 1 to 1");
    expect_error("v 1 2 3\nv 1 2 3\nv 1 2 3\nf 1 2 3x\n", "bad.obj:4:7: expected a vertex index");
    expect_error("usemtl\n", "bad.obj:1:7: expected a material name");
    expect_error("vn 1 2\n", "bad.obj:1:7: expected a number");
    expect_error("v 1 2 3 1e99\n", "bad.obj:1:9: expected a number");
    /* an MTL error names the MTL file */
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    test_write_text(DIR "/bad.mtl", "newmtl a\nKd 1 0.5\n");
    CHECK(parse(DIR "/b.obj", "mtllib bad.mtl\n") == RAYES_ERROR_PARSE);
    CHECK(strstr(err, DIR "/bad.mtl:2:9: expected the third colour component") == err);
    CHECK(rec.calls == 0);
    test_write_text(DIR "/bad.mtl", "Kd 1 0.5 1\n");
    CHECK(parse(DIR "/b.obj", "mtllib bad.mtl\n") == RAYES_ERROR_PARSE);
    CHECK(strstr(err, DIR "/bad.mtl:1:1: expected newmtl") == err);
    /* a negative emission would be a negative area light (fuzz) */
    test_write_text(DIR "/bad.mtl", "newmtl a\nKe 1 -1 1\n");
    CHECK(parse(DIR "/b.obj", "mtllib bad.mtl\n") == RAYES_ERROR_PARSE);
    CHECK(strstr(err, DIR "/bad.mtl:2:1: Ke: an emission must not be negative") == err);
}

/* Unknown statements are skipped (with one warning each), comments and
 * blank lines ignored. */
static void test_unknown_statements(void)
{
    CHECK(parse("u.obj", "\n\n# c\ncstype bezier\ndeg 3\nv 0 0 0 # x\nv 1 0 0\nv 0 1 0\n"
                         "l 1 2\np 1\ncstype rat\nf 1 2 3\n") == RAYES_OK);
    CHECK(rec.n_mesh == 1 && rec.mesh[0].n_faces == 1);
    record_free(&rec);
}

static void test_read_file(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    test_write_text(DIR "/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    IoSink sink = record_sink(&rec);
    IoSettings st;
    io_settings_init(&st);
    CHECK(io_obj_read(DIR "/t.obj", &sink, NULL, &st, err, sizeof err) == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    record_free(&rec);
    CHECK(io_obj_read(DIR "/none.obj", &sink, NULL, &st, err, sizeof err) == RAYES_ERROR_IO);
    CHECK(strstr(err, DIR "/none.obj") != NULL);
}

/* The red and green means over columns [x0, x1) and rows [y0, y1). */
static void means(const RayesImage *img, int x0, int x1, int y0, int y1, double *r, double *g)
{
    double sr = 0.0, sg = 0.0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const float *px = img->rgba + 4 * ((size_t)y * (size_t)img->width + (size_t)x);
            sr += px[0], sg += px[1];
        }
    *r = sr / ((x1 - x0) * (y1 - y0)), *g = sg / ((x1 - x0) * (y1 - y0));
}

/* A green quad with the material `cut` before a red wall, rendered at 64
 * x 64 (the quad covers the middle half of the view). */
static RayesImage *render_cut(const char *cut)
{
    char mtl[512];
    snprintf(mtl, sizeof mtl, "newmtl back\nKd 0.8 0.05 0.05\nnewmtl cut\nKd 0.05 0.8 0.05\n%s\n",
             cut);
    test_write_text(DIR "/cut.mtl", mtl);
    test_write_text(DIR "/cut.obj", "mtllib cut.mtl\n"
                                    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                    "v -9 -9 -1\nv 9 -9 -1\nv 9 9 -1\nv -9 9 -1\n"
                                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                    "usemtl back\nf 5 6 7 8\nusemtl cut\nf 1/1 2/2 3/3 4/4\n");
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings st;
    io_settings_init(&st);
    RayesImage *img = NULL;
    CHECK(io_obj_read(DIR "/cut.obj", &sink, NULL, &st, err, sizeof err) == RAYES_OK);
    const float eye[3] = {0, 0, 5.4f}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 43.6f) ==
          RAYES_OK); /* the quad: the middle half */
    if (rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = 64;
        o.spp = 4;
        o.bounces = 0;
        o.threads = 2;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

/* Writes a w x h binary PPM of one colour per column (rgb of column x). */
static void write_columns(const char *path, int w, int h,
                          void (*rgb)(int x, int w, unsigned char c[3]))
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "P6 %d %d 255\n", w, h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            unsigned char c[3];
            rgb(x, w, c);
            fwrite(c, 1, 3, f);
        }
    fclose(f);
}

/* Writes a w x h binary PPM of one colour. */
static void write_solid(const char *path, int w, int h, int r, int g, int b)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "P6 %d %d 255\n", w, h);
    for (int i = 0; i < w * h; i++) {
        const unsigned char c[3] = {(unsigned char)r, (unsigned char)g, (unsigned char)b};
        fwrite(c, 1, 3, f);
    }
    fclose(f);
}

static void ramp_texel(int x, int w, unsigned char c[3]) /* grey, rising along u */
{
    c[0] = c[1] = c[2] = (unsigned char)(255 * x / (w - 1));
}

/* bump, map_Bump and norm: a normal map's texels tilt the shading normal
 * (toward the light from the upper left: brighter), a flat one changes
 * nothing, and a grey height map is a bump of height times -bm object
 * units (a ramp rising 1 unit over the 2-unit quad: a normal tilted 27
 * degrees toward the light, or away with -bm -1). The same keyword reads
 * either kind; the file's texels tell them apart. */
static void test_bump_maps(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    write_solid(DIR "/tilt.ppm", 8, 8, 89, 128, 249); /* n = (-0.3, 0, 0.954) */
    write_solid(DIR "/flatn.ppm", 8, 8, 128, 128, 255);
    write_columns(DIR "/ramp.ppm", 64, 4, ramp_texel);
    RayesImage *plain = render_cut("");
    RayesImage *tilt = render_cut("map_Bump -bm 1.0 tilt.ppm");
    RayesImage *flat = render_cut("norm flatn.ppm");
    RayesImage *up = render_cut("bump ramp.ppm");
    RayesImage *down = render_cut("map_bump -bm -1 ramp.ppm");
    /* the first of several bump statements wins, each with its own -bm;
     * bumped glass (which takes no normal map) still loads */
    RayesImage *first = render_cut("bump ramp.ppm\nmap_Bump -bm -1 tilt.ppm\ndisp flatn.ppm");
    RayesImage *glass = render_cut("Kd 0 0 0\nNi 1.5\nillum 7\nbump tilt.ppm");
    CHECK(first && glass);
    if (first && plain) {
        double r, g0, g5;
        means(plain, 24, 40, 24, 40, &r, &g0);
        means(first, 24, 40, 24, 40, &r, &g5);
        CHECK(fabs(g5 / g0 - 1.34) < 0.05);
    }
    rayes_image_free(first);
    rayes_image_free(glass);
    CHECK(plain && tilt && flat && up && down);
    if (plain && tilt && flat && up && down) {
        double r, g0, g1, g2, g3, g4;
        means(plain, 24, 40, 24, 40, &r, &g0);
        means(tilt, 24, 40, 24, 40, &r, &g1);
        means(flat, 24, 40, 24, 40, &r, &g2);
        means(up, 24, 40, 24, 40, &r, &g3);
        means(down, 24, 40, 24, 40, &r, &g4);
        printf("  green: plain %.4f, normal map %.4f (x %.3f, expected 1.25), flat map %.4f, "
               "ramp %.4f (x %.3f, expected 1.34), ramp -bm -1 %.4f (x %.3f, expected 0.45)\n",
               g0, g1, g1 / g0, g2, g3, g3 / g0, g4, g4 / g0);
        CHECK(fabs(g1 / g0 - 1.25) < 0.04);
        CHECK(fabs(g2 / g0 - 1.0) < 0.01);
        CHECK(fabs(g3 / g0 - 1.34) < 0.05);
        CHECK(fabs(g4 / g0 - 0.45) < 0.05);
    }
    rayes_image_free(plain);
    rayes_image_free(tilt);
    rayes_image_free(flat);
    rayes_image_free(up);
    rayes_image_free(down);
}

/* map_Ks: the highlight's colour by a texture (times Ks): a white map is
 * the highlight of Ks alone, a black one none. */
static void test_specular_map(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    write_solid(DIR "/white.ppm", 4, 4, 255, 255, 255);
    write_solid(DIR "/black.ppm", 4, 4, 0, 0, 0);
    RayesImage *shiny = render_cut("Ks 1 1 1\nNs 4");
    RayesImage *white = render_cut("Ks 1 1 1\nNs 4\nmap_Ks white.ppm");
    RayesImage *black = render_cut("Ks 1 1 1\nNs 4\nmap_Ks black.ppm");
    RayesImage *dull = render_cut("Ks 0 0 0\nNs 4");
    CHECK(shiny && white && black && dull);
    if (shiny && white && black && dull) {
        double r[4], g[4];
        RayesImage *im[4] = {shiny, white, black, dull};
        for (int k = 0; k < 4; k++)
            means(im[k], 24, 40, 24, 40, &r[k], &g[k]);
        printf("  red (the highlight): Ks %.4f, white map %.4f, black map %.4f, Ks 0 %.4f\n", r[0],
               r[1], r[2], r[3]);
        CHECK(r[0] > r[3] + 0.01 && fabs(r[1] - r[0]) < 1e-3 && fabs(r[2] - r[3]) < 1e-3);
    }
    rayes_image_free(shiny);
    rayes_image_free(white);
    rayes_image_free(black);
    rayes_image_free(dull);
}

/* MTL transparency: d (and Tr) is the opacity, map_d a cut-out by its
 * texture's matte (a grey mask's value, an RGBA image's alpha) or the
 * channel -imfchan names; where it is 0 the wall behind shows. */
static void test_transparency(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(DIR, 0777);
    /* a grey mask: its left half opaque; an RGBA TGA: its top half */
    FILE *f = fopen(DIR "/mask.ppm", "wb");
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "P6 8 1 255\n");
        for (int k = 0; k < 24; k++)
            fputc(k < 12 ? 255 : 0, f);
        fclose(f);
    }
    f = fopen(DIR "/leaf.tga", "wb");
    CHECK(f != NULL);
    if (f) {
        const unsigned char hdr[18] = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 8, 0, 32, 0x28};
        fwrite(hdr, 1, sizeof hdr, f);
        for (int y = 0; y < 8; y++) { /* top-left origin: rows top down, BGRA */
            const unsigned char px[4] = {40, 200, 40, (unsigned char)(y < 4 ? 255 : 0)};
            fwrite(px, 1, sizeof px, f);
        }
        fclose(f);
    }
    RayesImage *solid = render_cut("");
    RayesImage *half = render_cut("d 0.5");
    RayesImage *tr = render_cut("Tr 0.5");
    RayesImage *mask = render_cut("map_d mask.ppm");
    RayesImage *leaf = render_cut("map_d leaf.tga");
    RayesImage *red = render_cut("map_d -imfchan r leaf.tga"); /* its red: 40 / 255, nearly clear */
    RayesImage *gone = render_cut("map_d missing.png"); /* unreadable: opaque, as without it */
    CHECK(solid && half && tr && mask && leaf && red && gone);
    if (solid && gone) {
        double r0, g0, r1, g1;
        means(solid, 24, 40, 24, 40, &r0, &g0);
        means(gone, 24, 40, 24, 40, &r1, &g1);
        CHECK(fabs(g1 - g0) < 0.01 * g0 && fabs(r1 - r0) < 0.01 + 0.01 * r0);
    }
    rayes_image_free(gone);
    if (solid && half && tr && mask && leaf && red) {
        double r0, g0, r1, g1, r2, g2, r3, g3;
        means(solid, 24, 40, 24, 40, &r0, &g0);
        CHECK(g0 > 4 * r0); /* green */
        means(half, 24, 40, 24, 40, &r1, &g1);
        means(tr, 24, 40, 24, 40, &r2, &g2);
        printf("  opaque quad r %.3f g %.3f; d 0.5: r %.3f g %.3f\n", r0, g0, r1, g1);
        CHECK(r1 > 2 * r0 && g1 < 0.8 * g0 && fabs(r1 - r2) < 1e-6 && fabs(g1 - g2) < 1e-6);
        /* the mask: the quad's left quarter green, its right quarter the wall */
        means(mask, 18, 22, 24, 40, &r1, &g1);
        means(mask, 42, 46, 24, 40, &r2, &g2);
        printf("  mask: left r %.3f g %.3f, right r %.3f g %.3f\n", r1, g1, r2, g2);
        CHECK(g1 > 4 * r1 && r2 > 4 * g2);
        /* the TGA's alpha: its top quarter green, its bottom quarter the wall */
        means(leaf, 24, 40, 18, 22, &r1, &g1);
        means(leaf, 24, 40, 42, 46, &r2, &g2);
        means(red, 24, 40, 18, 22, &r3, &g3);
        printf("  alpha: top r %.3f g %.3f, bottom r %.3f g %.3f; red channel: r %.3f g %.3f\n", r1,
               g1, r2, g2, r3, g3);
        CHECK(g1 > 4 * r1 && r2 > 4 * g2 && r3 > 2 * g3);
    }
    rayes_image_free(solid);
    rayes_image_free(half);
    rayes_image_free(tr);
    rayes_image_free(mask);
    rayes_image_free(leaf);
    rayes_image_free(red);
}

TEST_MAIN(TEST(test_face_syntax), TEST(test_ngons), TEST(test_materials), TEST(test_opacity_words),
          TEST(test_map_paths), TEST(test_bump_maps), TEST(test_pbr_extension),
          TEST(test_specular_map), TEST(test_default_camera_and_light),
          TEST(test_default_light_follows_the_view), TEST(test_emission_map), TEST(test_errors),
          TEST(test_unknown_statements), TEST(test_read_file),
          TEST(test_normals_and_texture_coordinates), TEST(test_transparency),
          TEST(test_smoothing_groups), TEST(test_vertex_colours))
