/*
 * Blobby implicit surfaces made polygons (geom/blobby.h): a lone blob is a
 * sphere of half its unit radius, closed and wound outward, with the
 * enclosed volume; ellipsoids keep their shapes; a segment is a tube,
 * and two end to end the same tube (a convolution); adding
 * blends two blobs into one piece where the maximum keeps them apart;
 * subtraction dents; the gradient is the field's; bad programs are
 * refused with the instruction named; a mesh over budget is refused.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/blobby.h"
#include "test.h"

static char msg[256];

/* RiBlobby's matrix (row vectors): scale s then translate t. */
static void blob(float *f, float sx, float sy, float sz, float tx, float ty, float tz)
{
    memset(f, 0, 16 * sizeof *f);
    f[0] = sx, f[5] = sy, f[10] = sz;
    f[12] = tx, f[13] = ty, f[14] = tz, f[15] = 1.0f;
}

static BlobbyMesh mesh_of(const int *code, size_t n_code, const float *floats, size_t n_floats)
{
    BlobbyMesh m = {0};
    Blobby *b = blobby_compile(code, n_code, floats, n_floats, 0, msg, sizeof msg);
    CHECK(b != NULL);
    if (!b)
        return m;
    CHECK(blobby_polygonize(b, 0.0f, 1u << 22, &m, msg, sizeof msg) == 0);
    blobby_free(b);
    return m;
}

static Vec3 point(const BlobbyMesh *m, int i)
{
    return v3_load(m->P + 3 * (size_t)i);
}

/* Volume by the divergence theorem (each quad as two triangles). */
static double volume(const BlobbyMesh *m)
{
    double v = 0.0;
    for (size_t q = 0; q < m->n_quads; q++) {
        const int *k = m->quads + 4 * q;
        for (int t = 0; t < 2; t++) {
            Vec3 a = point(m, k[0]), b = point(m, k[1 + t]), c = point(m, k[2 + t]);
            v += v3_dot(a, v3_cross(b, c)) / 6.0;
        }
    }
    return v;
}

/* Every directed edge used as often as its reverse: closed, wound one
 * way; manifold: once each. */
static int closed_mesh(const BlobbyMesh *m, int manifold)
{
    size_t n = 4 * m->n_quads;
    long long *e = malloc((n + 1) * sizeof *e);
    for (size_t q = 0; q < m->n_quads; q++)
        for (int k = 0; k < 4; k++)
            e[4 * q + (size_t)k] =
                (long long)m->quads[4 * q + (size_t)k] * (1 << 24) + m->quads[4 * q + (k + 1) % 4];
    int ok = 1;
    for (size_t i = 0; i < n && ok; i++) {
        long long a = e[i] / (1 << 24), b = e[i] % (1 << 24), rev = b * (1 << 24) + a;
        int same = 0, back = 0;
        for (size_t j = 0; j < n; j++)
            same += e[j] == e[i], back += e[j] == rev;
        ok = same == back && (!manifold || same == 1);
        if (!ok)
            fprintf(stderr, "  edge %lld-%lld: %d times, reversed %d\n", a, b, same, back);
    }
    free(e);
    return ok;
}

static int closed(const BlobbyMesh *m)
{
    return closed_mesh(m, 1);
}

static int find(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

static int components(const BlobbyMesh *m)
{
    int *parent = malloc((m->n_points + 1) * sizeof *parent);
    for (size_t i = 0; i < m->n_points; i++)
        parent[i] = (int)i;
    for (size_t q = 0; q < m->n_quads; q++)
        for (int k = 1; k < 4; k++)
            parent[find(parent, m->quads[4 * q])] = find(parent, m->quads[4 * q + (size_t)k]);
    int n = 0;
    for (size_t i = 0; i < m->n_points; i++)
        n += find(parent, (int)i) == (int)i;
    free(parent);
    return n;
}

static void test_sphere(void)
{
    float f[16];
    blob(f, 1, 1, 1, 0, 0, 0);
    const int code[] = {1001, 0};
    BlobbyMesh m = mesh_of(code, 2, f, 16);
    CHECK(m.n_points > 500 && m.n_quads > 500);
    double worst = 0.0, worst_n = 1.0;
    for (size_t i = 0; i < m.n_points; i++) {
        Vec3 p = point(&m, (int)i), n = v3_load(m.N + 3 * i);
        worst = fmax(worst, fabs(v3_length(p) - 0.5));
        worst_n = fmin(worst_n, v3_dot(n, v3_normalize(p)));
    }
    CHECK(worst < 1e-4);     /* on the surface: a lone blob at half its radius */
    CHECK(worst_n > 0.9999); /* normals outward, radial */
    CHECK(closed(&m));
    CHECK(components(&m) == 1);
    /* Outward winding encloses a positive volume, within 2% of the ball's
     * (the mesh is inscribed). */
    double v = volume(&m), ball = 4.0 / 3.0 * M_PI * 0.125;
    CHECK(v > 0.98 * ball && v < ball);
    blobby_mesh_free(&m);
}

static void test_ellipsoid(void)
{
    float f[16];
    blob(f, 2, 1, 0.5f, 1, 2, 3);
    const int code[] = {1001, 0};
    BlobbyMesh m = mesh_of(code, 2, f, 16);
    double worst = 0.0;
    for (size_t i = 0; i < m.n_points; i++) {
        Vec3 p = v3_sub(point(&m, (int)i), v3(1, 2, 3));
        worst = fmax(worst, fabs(sqrt(p.x * p.x + 4 * p.y * p.y + 16 * p.z * p.z) - 1.0));
    }
    CHECK(m.n_points > 500 && worst < 1e-3);
    CHECK(closed(&m));
    double v = volume(&m), ell = 4.0 / 3.0 * M_PI * 1.0 * 0.5 * 0.25;
    CHECK(v > 0.97 * ell && v < 1.001 * ell);
    blobby_mesh_free(&m);
}

static void test_blend_and_maximum(void)
{
    float f[32];
    blob(f, 1, 1, 1, -0.6f, 0, 0);
    blob(f + 16, 1, 1, 1, 0.6f, 0, 0);
    /* Added, the blobs' fields at the midpoint (0.262 each) pass the threshold. */
    const int add[] = {1001, 0, 1001, 16, 0, 2, 0, 1};
    BlobbyMesh m = mesh_of(add, 8, f, 32);
    CHECK(components(&m) == 1 && closed(&m));
    blobby_mesh_free(&m);
    const int max[] = {1001, 0, 1001, 16, 2, 2, 0, 1};
    m = mesh_of(max, 8, f, 32);
    CHECK(components(&m) == 2 && closed(&m));
    blobby_mesh_free(&m);
}

static void test_subtract(void)
{
    float f[32];
    blob(f, 2, 2, 2, 0, 0, 0); /* surface at radius 1 */
    blob(f + 16, 1, 1, 1, 1, 0, 0);
    const int code[] = {1001, 0, 1001, 16, 4, 0, 1};
    BlobbyMesh m = mesh_of(code, 7, f, 32);
    int dent = 0, far_side = 0;
    for (size_t i = 0; i < m.n_points; i++) {
        Vec3 p = point(&m, (int)i);
        dent += p.x > 0.75f && fabsf(p.y) < 0.1f && fabsf(p.z) < 0.1f;
        far_side += p.x < -0.95f;
    }
    CHECK(dent == 0 && far_side > 0);
    /* Closed, though where the dent's rim is sharp a cube may hold two
     * sheets, whose quads then share an edge (four at it). */
    CHECK(closed_mesh(&m, 0));
    blobby_mesh_free(&m);
}

/* A segment's tube: (1 - d^2)^(7/2) = T, d in radii. */
static double tube_radius(double radius)
{
    return radius * sqrt(1.0 - pow(BLOBBY_THRESHOLD, 2.0 / 7.0));
}

static void test_segment(void)
{
    float f[23] = {-1, 0, 0, 1, 0, 0, 0.5f};
    blob(f + 7, 1, 1, 1, 0, 0, 0);
    const int code[] = {1002, 0};
    BlobbyMesh m = mesh_of(code, 2, f, 23);
    double worst = 0.0;
    int middle = 0;
    for (size_t i = 0; i < m.n_points; i++) {
        Vec3 p = point(&m, (int)i);
        if (fabsf(p.x) < 0.5f) {
            middle++;
            worst = fmax(worst, fabs(hypot(p.y, p.z) - tube_radius(0.5)));
        }
        CHECK(fabsf(p.x) < 1.26f);
    }
    CHECK(middle > 100 && worst < 1e-4);
    CHECK(closed(&m));
    blobby_mesh_free(&m);
    /* Two segments end to end convolve to the one they make: the same
     * field everywhere, so no bead at the joint. */
    float g[46] = {-1, 0, 0, 0, 0, 0, 0.5f};
    blob(g + 7, 1, 1, 1, 0, 0, 0);
    const float second[7] = {0, 0, 0, 1, 0, 0, 0.5f};
    memcpy(g + 23, second, sizeof second);
    blob(g + 30, 1, 1, 1, 0, 0, 0);
    const int chain[] = {1002, 0, 1002, 23, 0, 2, 0, 1};
    Blobby *one = blobby_compile(code, 2, f, 23, 0, msg, sizeof msg);
    Blobby *two = blobby_compile(chain, 8, g, 46, 0, msg, sizeof msg);
    CHECK(one && two);
    const Vec3 at[4] = {{0, 0.2f, 0}, {0.05f, 0.1f, 0.15f}, {-0.7f, 0, 0.3f}, {1.1f, 0.1f, 0}};
    for (int i = 0; one && two && i < 4; i++) {
        Vec3 ga, gb;
        CHECK_NEAR(blobby_field(one, at[i], &ga), blobby_field(two, at[i], &gb), 1e-5);
        CHECK(v3_length(v3_sub(ga, gb)) < 1e-4f);
        /* and the gradient is the field's */
        const float e = 1e-3f;
        for (int a = 0; a < 3; a++) {
            Vec3 d = v3(a == 0 ? e : 0, a == 1 ? e : 0, a == 2 ? e : 0);
            float fd = (blobby_field(one, v3_add(at[i], d), NULL) -
                        blobby_field(one, v3_sub(at[i], d), NULL)) /
                       (2 * e);
            CHECK_NEAR(v3_index(ga, a), fd, 2e-3 * (1 + fabs(fd)));
        }
    }
    blobby_free(one);
    blobby_free(two);
}

static void test_gradient(void)
{
    float f[49];
    blob(f, 1, 1.5f, 1, -0.3f, 0, 0);
    blob(f + 16, 1, 1, 1, 0.4f, 0.1f, 0);
    f[32] = 0.3f; /* a constant */
    blob(f + 33, 0.8f, 0.8f, 0.8f, 0, 0.2f, 0.1f);
    /* ((e0 + e1) * e3 - c) / (e1 + c) and the maximum with e0 */
    const int code[] = {1001, 0, 1001, 16, 1000, 32, 1001, 33, 0, 2, 0, 1, 1, 2, 4,
                        3,    4, 5,    2,  0,    2,  1,    2,  5, 6, 7, 2, 2, 8, 0};
    Blobby *b = blobby_compile(code, sizeof code / sizeof *code, f, 49, 0, msg, sizeof msg);
    CHECK(b != NULL);
    if (!b)
        return;
    CHECK(blobby_leaf_count(b) == 4);
    const Vec3 ps[3] = {{0.05f, 0.1f, 0.02f}, {-0.2f, 0.15f, 0.1f}, {0.3f, -0.1f, 0.05f}};
    for (int i = 0; i < 3; i++) {
        Vec3 g;
        float v = blobby_field(b, ps[i], &g);
        CHECK(isfinite(v));
        const float e = 1e-3f;
        float dx = (blobby_field(b, v3_add(ps[i], v3(e, 0, 0)), NULL) -
                    blobby_field(b, v3_sub(ps[i], v3(e, 0, 0)), NULL)) /
                   (2 * e);
        float dy = (blobby_field(b, v3_add(ps[i], v3(0, e, 0)), NULL) -
                    blobby_field(b, v3_sub(ps[i], v3(0, e, 0)), NULL)) /
                   (2 * e);
        float dz = (blobby_field(b, v3_add(ps[i], v3(0, 0, e)), NULL) -
                    blobby_field(b, v3_sub(ps[i], v3(0, 0, e)), NULL)) /
                   (2 * e);
        CHECK_NEAR(g.x, dx, 2e-3 * (1 + fabs(dx)));
        CHECK_NEAR(g.y, dy, 2e-3 * (1 + fabs(dy)));
        CHECK_NEAR(g.z, dz, 2e-3 * (1 + fabs(dz)));
    }
    /* The mesh of that program lies on its level set. */
    BlobbyMesh m;
    CHECK(blobby_polygonize(b, 0.0f, 1u << 22, &m, msg, sizeof msg) == 0);
    CHECK(m.n_points > 100);
    double worst = 0.0;
    for (size_t i = 0; i < m.n_points; i++)
        worst = fmax(worst, fabs(blobby_field(b, point(&m, (int)i), NULL) - BLOBBY_THRESHOLD));
    CHECK(worst < 1e-3);
    blobby_mesh_free(&m);
    blobby_free(b);
}

static void test_errors(void)
{
    float f[16];
    blob(f, 1, 1, 1, 0, 0, 0);
    const struct {
        int code[8];
        size_t n;
        const char *says;
    } bad[] = {
        {{1001, 0, 99}, 3, "unknown opcode 99"},
        {{1001, 0, 0, 2, 0, 1}, 6, "operand 1 is not an earlier"},
        {{1001, 4}, 2, "needs floats 4 to 19"},
        {{1001, 0, 4, 0}, 4, "expected its operands"},
        {{1003, 0, 0}, 3, "string index"},
        {{0, 0}, 2, "count of at least 1"},
        {{0}, 0, "no instructions"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        msg[0] = '\0';
        Blobby *b = blobby_compile(bad[i].code, bad[i].n, f, 16, 0, msg, sizeof msg);
        CHECK(b == NULL);
        CHECK(strstr(msg, bad[i].says) != NULL);
        if (!strstr(msg, bad[i].says))
            fprintf(stderr, "  got \"%s\"\n", msg);
        blobby_free(b);
    }
    float singular[16] = {0};
    singular[15] = 1.0f;
    const int code[] = {1001, 0};
    CHECK(blobby_compile(code, 2, singular, 16, 0, msg, sizeof msg) == NULL);
    CHECK(strstr(msg, "not an invertible affine") != NULL);
    /* A repelling plane is read and counted as unsupported (its field 0). */
    const int plane[] = {1001, 0, 1003, 0, 0, 0, 2, 0, 1};
    Blobby *b = blobby_compile(plane, 9, f, 16, 1, msg, sizeof msg);
    CHECK(b && blobby_unsupported_count(b) == 1 && blobby_leaf_count(b) == 2);
    blobby_free(b);
}

static void test_budget(void)
{
    float f[16];
    blob(f, 1, 1, 1, 0, 0, 0);
    const int code[] = {1001, 0};
    Blobby *b = blobby_compile(code, 2, f, 16, 0, msg, sizeof msg);
    BlobbyMesh m;
    CHECK(blobby_polygonize(b, 0.0f, 100, &m, msg, sizeof msg) == 1);
    CHECK(m.n_points == 0 && m.P == NULL);
    /* A coarser lattice fits. */
    CHECK(blobby_polygonize(b, 0.1f, 1000, &m, msg, sizeof msg) == 0);
    CHECK(m.n_points > 0 && m.n_points <= 1000 && m.cell == 0.1f);
    blobby_mesh_free(&m);
    blobby_free(b);
}

TEST_MAIN(TEST(test_sphere), TEST(test_ellipsoid), TEST(test_blend_and_maximum),
          TEST(test_subtract), TEST(test_segment), TEST(test_gradient), TEST(test_errors),
          TEST(test_budget))
