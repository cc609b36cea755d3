/*
 * io/ply.h — our own reader of PLY polygon files (Greg Turk's format), as
 * pbrt-v4's "plymesh" uses them: ascii, binary_little_endian and
 * binary_big_endian; element "vertex" with x y z, optional nx ny nz and
 * optional u v (or s t, texture_u texture_v); element "face" with a list
 * property vertex_indices (or vertex_index) of any integer types. Other
 * elements and properties are read and skipped. Faces of three vertices
 * stay triangles; a quad stays a quad when it is planar and convex, else it
 * is split along its 0-2 diagonal; larger polygons are split into a fan.
 *
 * Bad input: one line "file:line:col: what was expected" (header and ascii
 * body) or "file: element index: what was wrong" (binary body) in err and
 * a nonzero return; indices are checked against the vertex count, counts
 * against the bytes the file holds. Reentrant; the mesh is owned by the
 * caller (io_ply_mesh_fini).
 */
#ifndef RAYES_IO_PLY_H
#define RAYES_IO_PLY_H

#include <stddef.h>

#include "rayes/rayes.h"

typedef struct PlyMesh {
    size_t n_vertices;
    float *P;          /* 3 per vertex, object space */
    float *N;          /* 3 per vertex, or NULL when the file has no normals */
    float *uv;         /* 2 per vertex, or NULL when the file has no texture coordinates */
    size_t n_faces;
    int *n_verts;      /* per face: 3 or 4 */
    int *indices;      /* n_verts[f] per face, concatenated, in [0, n_vertices) */
    size_t n_indices;  /* the sum of n_verts */
    size_t n_split;    /* faces of the file that were split (non-planar quads, n-gons) */
    size_t n_skipped;  /* faces of the file with fewer than 3 vertices, left out */
    size_t n_bad_normals; /* vertex normals NaN, infinite or zero: their faces' instead */
} PlyMesh;

/* Parses data[0..size) (not NUL-terminated) into mesh, which is zeroed
 * first and holds nothing on failure. name is used in messages. */
RayesError io_ply_parse(const char *name, const unsigned char *data, size_t size, PlyMesh *mesh,
                        char *err, size_t err_size);

/* Reads the file at path (RAYES_ERROR_IO when it cannot be read). */
RayesError io_ply_read(const char *path, PlyMesh *mesh, char *err, size_t err_size);

/* Frees what mesh holds and zeroes it. */
void io_ply_mesh_fini(PlyMesh *mesh);

#endif /* RAYES_IO_PLY_H */
