/* Clusters of tiny grids (geom/cluster.c): neighbours of one object and
 * one facing, at most 16 grids and then 16 clusters, kept only when they
 * join two or more. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/geom.h"
#include "test.h"

enum { N = 48 }; /* lattice cells along a side */

/* A GridSet of 2 N^2 triangular grids of one micropolygon over the lattice
 * cells of [0, 1]^2 in the plane z = 0 (or, where fold says, its right half
 * turned up into the plane x = 0.5); object(i, j) per cell, and every
 * other triangle wound backwards where flip says. */
static void lattice_layers(GridSet *gs, int fold, int (*object)(int, int), int flip, int layers)
{
    geom_gridset_init(gs);
    size_t n = 2 * N * N * (size_t)layers + (layers > 1);
    gs->grids = calloc(n, sizeof *gs->grids);
    gs->P = calloc(3 * n, sizeof *gs->P);
    gs->N = calloc(3 * n, sizeof *gs->N);
    CHECK(gs->grids && gs->P && gs->N);
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int t = 0; t < 2 * layers; t++) {
                size_t g = gs->n_grids++;
                float x0 = (float)i / N, y0 = (float)j / N, h = 1.0f / N, z = 0.05f * (t / 2);
                Vec3 c[3] = {v3(x0, y0, z), v3(x0 + h, y0 + h, z), v3(x0 + h, y0, z)};
                if (t % 2)
                    c[1] = v3(x0, y0 + h, z), c[2] = v3(x0 + h, y0 + h, z);
                int backwards = flip && (i + j + t) % 2;
                Vec3 normal = v3(0, 0, backwards ? 1.0f : -1.0f);
                if (backwards) {
                    Vec3 tmp = c[1];
                    c[1] = c[2], c[2] = tmp;
                }
                for (int k = 0; k < 3; k++) {
                    Vec3 p = c[k], nk = normal;
                    if (fold && i >= N / 2) /* x beyond 0.5 turned up to z */
                        p = v3(0.5f, p.y, p.x - 0.5f), nk = v3(-normal.z, 0, 0);
                    gs->P[3 * g + k] = p;
                    gs->N[3 * g + k] = nk;
                }
                gs->grids[g] = (Grid){.first_vertex = (uint32_t)(3 * g), .nu = 1, .triangular = 1,
                                      .edge = h, .object = object ? (uint32_t)object(i, j) : 0};
            }
    if (layers > 1) { /* one face far above, of another object: the layers' middles then
                         interleave in Morton order (they would sort one after the other) */
        size_t g = gs->n_grids++;
        for (int k = 0; k < 3; k++)
            gs->P[3 * g + k] = v3(k == 1 ? 0.01f : 0.0f, k == 2 ? 0.01f : 0.0f, 10.0f),
                          gs->N[3 * g + k] = v3(0, 0, -1);
        gs->grids[g] = (Grid){.first_vertex = (uint32_t)(3 * g),
                              .nu = 1,
                              .triangular = 1,
                              .edge = 0.01f,
                              .object = 1};
    }
    gs->n_vertices = 3 * n;
}

static void lattice(GridSet *gs, int fold, int (*object)(int, int), int flip)
{
    lattice_layers(gs, fold, object, flip, 1);
}

/* The members of cluster c (index + 1): grids whose chain reaches it. */
static size_t members(const GridSet *gs, uint32_t c, uint32_t *out)
{
    size_t m = 0;
    for (size_t g = 0; g < gs->n_grids; g++)
        for (uint32_t k = gs->grid_cluster[g]; k; k = gs->clusters[k - 1].parent)
            if (k == c) {
                out[m++] = (uint32_t)g;
                break;
            }
    return m;
}

static Vec3 grid_normal(const GridSet *gs, uint32_t g)
{
    return gs->N[gs->grids[g].first_vertex];
}

/* Every cluster: two grids or more, of one object and one facing, its
 * representative among them, no larger than its parent, compact. */
static void check_clusters(const GridSet *gs)
{
    uint32_t *m = malloc(gs->n_grids * sizeof *m);
    CHECK(m != NULL);
    for (size_t c = 0; m && c < gs->n_clusters; c++) {
        const GeomCluster *cl = &gs->clusters[c];
        size_t n = members(gs, (uint32_t)c + 1, m);
        CHECK(n >= 2 && n <= 256);
        int has_rep = 0, depth = 0;
        Bounds3 box = bounds_empty();
        for (size_t k = 0; k < n; k++) {
            has_rep |= m[k] == cl->rep;
            CHECK(gs->grids[m[k]].object == gs->grids[m[0]].object);
            CHECK(v3_dot(grid_normal(gs, m[k]), grid_normal(gs, m[0])) > 0.8f);
            for (int v = 0; v < 3; v++)
                box = bounds_add(box, gs->P[gs->grids[m[k]].first_vertex + v]);
        }
        CHECK(has_rep);
        float area = 0.5f * (float)n / (N * N), diag = v3_length(v3_sub(box.hi, box.lo));
        CHECK(diag <= 3.0f * sqrtf(area) * 1.0001f);
        CHECK(cl->edge >= 0.999f * sqrtf(area)); /* its own, or a child's if larger */
        for (uint32_t p = cl->parent; p; p = gs->clusters[p - 1].parent, depth++)
            CHECK(gs->clusters[p - 1].edge >= cl->edge);
        CHECK(depth <= 1);
    }
    free(m);
}

/* A flat lattice: every grid is in a cluster, 16 grids at most at the
 * first level and 256 at the second, about N^2 / 128 of those. */
static void test_flat_lattice(void)
{
    GridSet gs;
    lattice(&gs, 0, NULL, 0);
    CHECK(geom_cluster_grids(&gs) == 0);
    CHECK(gs.grid_cluster && gs.n_clusters > 0);
    size_t in = 0, top = 0;
    for (size_t g = 0; g < gs.n_grids; g++)
        in += gs.grid_cluster[g] != 0;
    for (size_t c = 0; c < gs.n_clusters; c++)
        top += gs.clusters[c].parent == 0;
    CHECK(in >= gs.n_grids * 99 / 100);
    CHECK(top >= gs.n_grids / 256 && top <= gs.n_grids / 64);
    check_clusters(&gs);
    /* a first-level cluster of 16 half cells: about sqrt(8) cells across */
    uint32_t c = gs.grid_cluster[gs.n_grids / 2];
    CHECK(c && gs.clusters[c - 1].edge <= 3.0f / N && gs.clusters[c - 1].edge >= 1.0f / N);
    geom_gridset_fini(&gs);
}

/* Folded through 90 degrees, two objects in a checkerboard of 4 x 4
 * cells, every other triangle wound backwards: no cluster mixes them. */
static int checker(int i, int j)
{
    return (i / 4 + j / 4) % 2;
}

static void test_clusters_keep_apart(void)
{
    GridSet gs;
    lattice(&gs, 1, NULL, 0);
    CHECK(geom_cluster_grids(&gs) == 0 && gs.n_clusters > 0);
    check_clusters(&gs);
    geom_gridset_fini(&gs);
    lattice(&gs, 0, checker, 0);
    CHECK(geom_cluster_grids(&gs) == 0 && gs.n_clusters > 0);
    check_clusters(&gs);
    geom_gridset_fini(&gs);
    lattice(&gs, 0, NULL, 1);
    CHECK(geom_cluster_grids(&gs) == 0 && gs.n_clusters > 0);
    check_clusters(&gs);
    geom_gridset_fini(&gs);
}

/* Grids larger than 2 x 2 micropolygons, moving ones, and curves are
 * never clustered; made again, the clusters are the same. */
static void test_only_tiny_grids(void)
{
    Grid g = {.nu = 3, .nv = 3};
    CHECK(geom_grid_tiny(&g));
    g.nu = 4;
    CHECK(!geom_grid_tiny(&g));
    Grid t = {.nu = 2, .triangular = 1};
    CHECK(geom_grid_tiny(&t));
    t.nu = 3;
    CHECK(!geom_grid_tiny(&t));
    t.nu = 1, t.moving = 1;
    CHECK(!geom_grid_tiny(&t));
    t.moving = 0, t.shape = GEOM_SHAPE_FLAT_CURVE;
    CHECK(!geom_grid_tiny(&t));
    GridSet gs;
    lattice(&gs, 0, NULL, 0);
    for (size_t k = 0; k < gs.n_grids; k += 2)
        gs.grids[k].moving = 1;
    CHECK(geom_cluster_grids(&gs) == 0);
    size_t n = gs.n_clusters;
    uint32_t *first = malloc(gs.n_grids * sizeof *first);
    CHECK(first != NULL && n > 0);
    for (size_t k = 0; first && k < gs.n_grids; k++) {
        CHECK(k % 2 == 1 || gs.grid_cluster[k] == 0);
        first[k] = gs.grid_cluster[k];
    }
    CHECK(geom_cluster_grids(&gs) == 0 && gs.n_clusters == n);
    CHECK(first && memcmp(first, gs.grid_cluster, gs.n_grids * sizeof *first) == 0);
    free(first);
    geom_gridset_fini(&gs);
}

/* Two layers of one object facing one way, 0.05 apart (a board on a
 * board, leaves over leaves): no cluster joins them, though their boxes
 * are compact. */
static void test_layers_stay_apart(void)
{
    GridSet gs;
    lattice_layers(&gs, 0, NULL, 0, 2);
    CHECK(geom_cluster_grids(&gs) == 0 && gs.n_clusters > 0);
    uint32_t *m = malloc(gs.n_grids * sizeof *m);
    CHECK(m != NULL);
    for (size_t c = 0; m && c < gs.n_clusters; c++) {
        size_t n = members(&gs, (uint32_t)c + 1, m);
        for (size_t k = 1; k < n; k++)
            CHECK(gs.P[gs.grids[m[k]].first_vertex].z == gs.P[gs.grids[m[0]].first_vertex].z);
    }
    free(m);
    check_clusters(&gs);
    geom_gridset_fini(&gs);
}

TEST_MAIN(TEST(test_flat_lattice), TEST(test_clusters_keep_apart), TEST(test_only_tiny_grids),
          TEST(test_layers_stay_apart))
