/*
 * geom/blobby.h — RenderMan's blobby implicit surfaces (RiBlobby), made
 * polygons (DESIGN.md "Blobby implicit surfaces").
 *
 * A blobby is a program: primitive fields (the leaves: opcode 1000 a
 * constant, 1001 an ellipsoid, 1002 a segment, 1003 a repelling plane,
 * 1004 a field plugin and AIR's 9000 plugin blob (a count, then its
 * operands), the last three read and taken as 0) combined by
 * operators (0 add, 1 multiply, 2 maximum, 3 minimum, 4 subtract, 5
 * divide, 6 negate, 7 identity) whose operands are earlier instructions;
 * the last instruction is the field. An ellipsoid's field is
 * (1 - r^2)^3 for r < 1, r the distance from its centre in the unit
 * sphere its matrix maps to object space; a segment's is that bump
 * convolved along the segment (distances over its radius), scaled to 1 on
 * a long segment's axis, so that segments end to end make one smooth tube
 * (of radius 0.4675 times theirs). The surface is the field's level set at
 * BLOBBY_THRESHOLD, inside where the field is larger.
 *
 * blobby_polygonize finds the surface on a lattice of cubes (dual
 * contouring's surface nets): only cubes an interval bound of the field
 * cannot rule out are visited, an octree descent that skips empty space;
 * each cube the surface crosses gets one vertex, moved onto the surface by
 * Newton steps along the gradient (from the point nearest the crossings'
 * tangent planes, which keeps creases sharp), and each lattice edge the
 * surface crosses one quad joining the vertices of its four cubes. The lattice's
 * cube is a sixth of the smallest leaf's radius.
 *
 * Matrices are given as RiBlobby gives them: 16 floats mapping row vectors
 * (p' = p M), the translation in floats 12 to 14.
 *
 * Memory: a Blobby and a BlobbyMesh own their arrays. Thread-safety: a
 * compiled Blobby is read-only; the functions may run on several threads.
 */
#ifndef RAYES_GEOM_BLOBBY_H
#define RAYES_GEOM_BLOBBY_H

#include <stddef.h>

#include "util/vec.h"

/* The field value of the surface: a lone ellipsoid's surface lies at half
 * its unit sphere's radius ((1 - 1/4)^3), as Aqsis and K-3D draw it. */
#define BLOBBY_THRESHOLD 0.421875f

typedef struct Blobby Blobby;

/* Checks and compiles a program: n_code ints of code, the floats and the
 * number of strings its operands index. NULL with msg set on bad input
 * ("instruction 3: operand 5 is not an earlier instruction") or when out
 * of memory. */
Blobby *blobby_compile(const int *code, size_t n_code, const float *floats, size_t n_floats,
                       size_t n_strings, char *msg, size_t n_msg);
void blobby_free(Blobby *b);

/* The primitive fields (opcodes of 1000 and more) in code order, and how
 * many of them are repelling planes or plugins (taken as 0). */
size_t blobby_leaf_count(const Blobby *b);
size_t blobby_unsupported_count(const Blobby *b);

/* The field at object-space point p, and its gradient when grad is not
 * NULL. */
float blobby_field(const Blobby *b, Vec3 p, Vec3 *grad);

/* Each leaf's own field at p (blobby_leaf_count values, 0 for constants,
 * planes and plugins): the weights vertex values are blended with. */
void blobby_leaf_fields(const Blobby *b, Vec3 p, float *out);

typedef struct BlobbyMesh {
    size_t n_points, n_quads;
    float *P, *N;    /* 3 floats per point: on the surface; the unit outward normal */
    int *quads;      /* 4 points per quad, counter-clockwise seen from outside */
    float *corner_N; /* 12 floats per quad: its corners' normals (a point's, but where
                        a crease runs, the normal of the quad's side of it) */
    float cell;      /* the lattice's cube side */
} BlobbyMesh;

/* Polygonizes with cubes of side cell (0: the default, a sixth of the
 * smallest leaf's radius). Returns 0; 1 if the mesh would have more than
 * max_points points (nothing made); -1 out of memory (msg set). */
int blobby_polygonize(const Blobby *b, float cell, size_t max_points, BlobbyMesh *out, char *msg,
                      size_t n_msg);
/* The default cube side (0 when no leaf has a bounded field). */
float blobby_default_cell(const Blobby *b);
/* About how many points cubes of side cell make, at most (the leaves'
 * lone surfaces' areas over the cube's face). */
double blobby_estimate_points(const Blobby *b, float cell);
void blobby_mesh_free(BlobbyMesh *m);

#endif /* RAYES_GEOM_BLOBBY_H */
