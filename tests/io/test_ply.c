/*
 * tests/io/test_ply.c — the PLY reader of io/ply.h: ascii and binary (both
 * byte orders) files written here, plain and gzip-compressed, the split of quads and n-gons, and bad
 * input whose one-line errors name the place. Buffers are exact-size heap
 * copies so AddressSanitizer catches any read past the end.
 */
#include <stdint.h>
#include <string.h>
#include <zlib.h>

#include "io/ply.h"
#include "test.h"

static RayesError parse_exact(const char *text, size_t size, PlyMesh *m, char *err, size_t n)
{
    unsigned char *copy = malloc(size ? size : 1);
    memcpy(copy, text, size);
    err[0] = '\0';
    RayesError e = io_ply_parse("t.ply", copy, size, m, err, n);
    free(copy);
    return e;
}

static const char ascii_ply[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment a unit square (quad), a triangle and a pentagon\n"
    "element vertex 8\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n"
    "property float u\nproperty float v\n"
    "element face 3\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n"
    "2 0 0 0 0 1 0 0\n3 0 0 0 0 1 0 0\n2 1 0 0 0 1 0 0\n4 1 0 0 0 1 0 0\n"
    "4 0 1 2 3\n3 4 5 6\n5 0 1 4 5 7\n";

static void test_ascii(void)
{
    PlyMesh m;
    char err[256];
    RayesError e = parse_exact(ascii_ply, strlen(ascii_ply), &m, err, sizeof err);
    CHECK(e == RAYES_OK);
    if (e != RAYES_OK) {
        fprintf(stderr, "%s\n", err);
        return;
    }
    CHECK(m.n_vertices == 8);
    CHECK(m.N != NULL && m.uv != NULL);
    CHECK(m.n_faces == 1 + 1 + 3); /* the quad kept, the triangle, the pentagon as a fan of 3 */
    CHECK(m.n_verts[0] == 4 && m.n_verts[1] == 3);
    CHECK(m.n_indices == 4 + 3 + 9);
    CHECK(m.n_split == 1);
    CHECK(m.indices[4] == 4 && m.indices[5] == 5 && m.indices[6] == 6);
    CHECK_NEAR(m.P[3 * 2 + 1], 1.0, 0);
    CHECK_NEAR(m.uv[2 * 2 + 1], 1.0, 0);
    io_ply_mesh_fini(&m);
}

static void put(unsigned char **p, const void *v, size_t n, int big)
{
    for (size_t i = 0; i < n; i++)
        (*p)[i] = ((const unsigned char *)v)[big ? n - 1 - i : i];
    *p += n;
}

/* A binary file: 4 vertices (x y z float, an extra double), a non-planar
 * quad given as uint8 count and uint32 indices, then an ignored element. */
static size_t binary_ply(unsigned char *buf, int big)
{
    const char *hdr = big ? "ply\nformat binary_big_endian 1.0\n"
                          : "ply\r\nformat binary_little_endian 1.0\r\n";
    size_t n = (size_t)sprintf((char *)buf,
                               "%selement vertex 4\nproperty float x\nproperty float y\n"
                               "property float z\nproperty double quality\n"
                               "element face 1\nproperty list uint8 uint32 vertex_indices\n"
                               "element edge 1\nproperty int a\nend_header\n",
                               hdr);
    unsigned char *p = buf + n;
    float pts[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, 0}};
    for (int i = 0; i < 4; i++) {
        for (int c = 0; c < 3; c++)
            put(&p, &pts[i][c], 4, big);
        double q = i;
        put(&p, &q, 8, big);
    }
    uint8_t count = 4;
    put(&p, &count, 1, big);
    for (uint32_t i = 0; i < 4; i++)
        put(&p, &i, 4, big);
    int32_t a = 7;
    put(&p, &a, 4, big);
    return (size_t)(p - buf);
}

static void test_binary(void)
{
    for (int big = 0; big < 2; big++) {
        unsigned char buf[1024];
        size_t n = binary_ply(buf, big);
        PlyMesh m;
        char err[256];
        RayesError e = parse_exact((const char *)buf, n, &m, err, sizeof err);
        CHECK(e == RAYES_OK);
        if (e != RAYES_OK) {
            fprintf(stderr, "%s\n", err);
            continue;
        }
        CHECK(m.n_vertices == 4 && m.N == NULL && m.uv == NULL);
        CHECK(m.n_faces == 2 && m.n_split == 1); /* non-planar: split */
        CHECK_NEAR(m.P[3 * 2 + 2], 0.5, 0);
        CHECK_NEAR(m.P[3 * 1 + 0], 1.0, 0);
        io_ply_mesh_fini(&m);
        /* every truncation fails cleanly, naming the element */
        for (size_t cut = 0; cut < n; cut++) {
            e = parse_exact((const char *)buf, cut, &m, err, sizeof err);
            CHECK(e != RAYES_OK && strncmp(err, "t.ply:", 6) == 0 && !strchr(err, '\n'));
        }
    }
    /* written to a file and read back */
    char path[512];
    snprintf(path, sizeof path, "%s/test_ply_le.ply", RAYES_TEST_TMP);
    unsigned char buf[1024];
    size_t n = binary_ply(buf, 0);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        fwrite(buf, 1, n, f);
        fclose(f);
        PlyMesh m;
        char err[256];
        CHECK(io_ply_read(path, &m, err, sizeof err) == RAYES_OK);
        CHECK(m.n_vertices == 4);
        io_ply_mesh_fini(&m);
    }
    /* gzip-compressed (pbrt-v4's .ply.gz), and a compressed stream cut
     * short: an error naming the file, not a crash */
    char gz_path[512];
    snprintf(gz_path, sizeof gz_path, "%s/test_ply_le.ply.gz", RAYES_TEST_TMP);
    gzFile g = gzopen(gz_path, "wb");
    CHECK(g != NULL);
    if (g) {
        CHECK(gzwrite(g, buf, (unsigned)n) == (int)n);
        gzclose(g);
        PlyMesh m;
        char err[256];
        CHECK(io_ply_read(gz_path, &m, err, sizeof err) == RAYES_OK);
        CHECK(m.n_vertices == 4 && m.n_faces == 2);
        CHECK_NEAR(m.P[3 * 2 + 2], 0.5, 0);
        io_ply_mesh_fini(&m);
        FILE *in = fopen(gz_path, "rb");
        unsigned char z[2048];
        size_t zn = in ? fread(z, 1, sizeof z, in) : 0;
        if (in)
            fclose(in);
        f = fopen(gz_path, "wb");
        if (f) {
            fwrite(z, 1, zn / 2, f);
            fclose(f);
        }
        CHECK(io_ply_read(gz_path, &m, err, sizeof err) != RAYES_OK);
        CHECK(strstr(err, "test_ply_le.ply.gz") != NULL && !strchr(err, '\n'));
    }
    PlyMesh m;
    char err[256];
    CHECK(io_ply_read("/nonexistent/x.ply", &m, err, sizeof err) == RAYES_ERROR_IO);
}

static void expect_error(const char *text, const char *want)
{
    PlyMesh m;
    char err[256];
    RayesError e = parse_exact(text, strlen(text), &m, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE);
    CHECK(strstr(err, want) != NULL);
    if (!strstr(err, want))
        fprintf(stderr, "  got \"%s\", wanted \"%s\"\n", err, want);
    CHECK(m.P == NULL && m.indices == NULL);
}

#define HDR "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n" \
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"

static void test_errors(void)
{
    expect_error("", "t.ply:1:1: expected \"ply\"");
    expect_error("ply\nformat ascii 2.0\n", "t.ply:2:1: expected \"format");
    expect_error("ply\nformat ascii 1.0\nelement vertex -3\n", "t.ply:3:1: expected \"element NAME COUNT\"");
    expect_error("ply\nformat ascii 1.0\nproperty float x\n", "t.ply:3:1: expected an element");
    expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n",
                 "t.ply:4:1: expected a property type");
    expect_error("ply\nformat ascii 1.0\nelement vertex 1\n", "expected \"end_header\"");
    expect_error(HDR "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "t.ply: face 0 uses vertex 3 but the file has 3 vertices");
    expect_error(HDR "0 0 0\n1 0 x\n", "t.ply:11:5: expected a number in vertex 1, found \"x\"");
    expect_error(HDR "0 0 0\n1 nan 0\n", "vertex 1: a coordinate is not a finite float");
    expect_error(HDR "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "expected a value of face 0, found the end");
    expect_error("ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\n"
                 "property float y\nproperty float z\nelement face 0\n"
                 "property list uchar int vertex_indices\nend_header\n",
                 "t.ply: element \"vertex\": 1000000 of them cannot fit");
    expect_error("ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
                 "end_header\n", "no element \"vertex\"");
#define IHDR(type) "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n" \
                   "property float y\nproperty float z\nelement face 1\n" \
                   "property list uchar " type " vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
    expect_error(IHDR("float") "3 0 1 2\n", "t.ply:8:1: expected integer vertex indices");
    expect_error(IHDR("uint") "3 0 1 3000000000\n",
                 "face 0: vertex index 3e+09 is not an integer from 0 to 2147483647");
    expect_error(IHDR("int") "3 0 1 -1\n", "face 0: vertex index -1 is not an integer");
}

/* Vertex normals NaN, infinite or zero become their faces' normals, turned
 * toward the faces' good vertex normals (pbrt-v4 shades such faces with
 * their geometric normal); the others stay as given. */
static void test_bad_normals(void)
{
    static const char text[] =
        "ply\nformat ascii 1.0\nelement vertex 6\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0 nan nan nan\n1 0 0 0 0.6 0.8\n1 1 0 0 0 1\n0 1 0 0 0 1\n"
        "5 0 0 0 0 0\n5 1 0 inf 0 0\n"
        "4 0 1 2 3\n3 4 1 5\n"; /* the square +z; the triangle wound -z */
    PlyMesh m;
    char err[256];
    CHECK(parse_exact(text, strlen(text), &m, err, sizeof err) == RAYES_OK);
    CHECK(m.n_bad_normals == 3);
    if (m.N && m.n_vertices == 6) {
        for (int v = 0; v < 6; v++) /* all +z but vertex 1's, as given */
            if (v != 1)
                CHECK(m.N[3 * v] == 0.0f && m.N[3 * v + 1] == 0.0f && m.N[3 * v + 2] == 1.0f);
        CHECK(m.N[4] == 0.6f && m.N[5] == 0.8f);
    }
    io_ply_mesh_fini(&m);
}

TEST_MAIN(TEST(test_ascii), TEST(test_binary), TEST(test_errors), TEST(test_bad_normals))
