/*
 * io/rib_internal.h — pieces of the RIB reader shared by its files:
 * polygon tessellation and basis changes (rib_geom.c), and the recording
 * sink of object definitions (rib_record.c). Matrices are row-major 4 x 4
 * mapping column vectors, as in rayes.h.
 */
#ifndef RAYES_IO_RIB_INTERNAL_H
#define RAYES_IO_RIB_INTERNAL_H

#include <stddef.h>

#include "io/sink.h"

/* ------------------------------------------------------------ matrices */

void rib_mat_identity(float m[16]);
void rib_mat_mul(const float a[16], const float b[16], float out[16]); /* out = a b */
/* out = m^-1; returns -1 (out untouched) when m is singular. */
int rib_mat_inverse(const float m[16], float out[16]);
/* The rotation of deg degrees about axis (not zero: the caller checks),
 * right-handed, as RIB's Rotate makes it. */
void rib_mat_rotate(float deg, const float axis[3], float m[16]);
/* The determinant of the upper-left 3 x 3 (negative: a mirror). */
double rib_mat_det3(const float m[16]);
/* The area, once M places it, of the polygon of n >= 3 points P[3 idx[k]]
 * (a fan from its first: exact for convex and planar ones). */
double rib_polygon_area(const float M[16], const float *P, const int *idx, int n);
/* The area, once M places it, of quadric type (RayesQuadric) of
 * RenderMan's parameters v (a surface of revolution summed over 256 steps
 * of its profile; a transform that is not a uniform scale is taken as the
 * uniform scale of the same volume). */
double rib_quadric_area(const float M[16], int type, const float *v);
/* The angle (radians) between the rotations of two transforms (their
 * polar decompositions'); 0 if either is singular. */
float rib_mat_turn(const float a[16], const float b[16]);
/* The transform a fraction f from a to b as a motion goes: translation
 * and stretch linearly, rotation along the shorter arc about the
 * transforms' own origin; linear when either is singular or only one
 * mirrors. */
void rib_mat_blend(const float a[16], const float b[16], float f, float out[16]);

/* --------------------------------------------------------- tessellation */

/* Faces for polygon_mesh: n_verts[f] (3 or 4) and indices. Owned arrays. */
typedef struct RibFaces {
    int *n_verts;
    int *idx;
    size_t n_faces, n_idx;
    size_t cap_faces, cap_idx;
} RibFaces;

void rib_faces_fini(RibFaces *f);

/* Nonzero when the quad v[0..3] of P is planar (within 1e-4 of its size)
 * and strictly convex: rib_tessellate passes it whole, where other quads
 * are split in two triangles. The RIB writer writes the others as bilinear
 * patches, which is what a quad of rayes_scene_polygon_mesh is. */
int rib_quad_kept(const float *P, const int *v);

/* Appends the faces of one polygon given as n_loops loops (the first the
 * outline, the others holes) of loop_n[k] indices each into P: triangles
 * and quads (a quad only when it is convex and planar, without holes),
 * wound as the outline is, reversed when flip. Holes are bridged to the
 * outline, and the result ear-clipped in the plane of the outline's
 * Newell normal; degenerate input gives some triangles, never a hang.
 * Returns 0, or -1 when out of memory. */
int rib_tessellate(const float *P, const int *loop_n, size_t n_loops, const int *idx, int flip,
                   RibFaces *out);

/* --------------------------------------------------------------- bases */

/* The named basis ("bezier", "b-spline", "catmull-rom", "hermite",
 * "power") as RenderMan gives it (P(u) = [u^3 u^2 u 1] B G) and its
 * default step; -1 for an unknown name. */
int rib_basis_named(const char *name, float basis[16], int *step);

/* The Bezier control points of the bicubic patch whose 4 x 4 control
 * points G (row-major, u fastest) are in bases bu (along u) and bv. */
void rib_basis_to_bezier(const float bu[16], const float bv[16], const float G[16][3],
                         float out[16][3]);

/* ------------------------------------------------------------ recording */

typedef struct RibRecording RibRecording;

RibRecording *rib_recording_new(void);
void rib_recording_free(RibRecording *rec);
/* A sink appending every call to rec (lights are not recorded). */
IoSink rib_recording_sink(RibRecording *rec);
/* Sends the recorded calls to out, every transform premultiplied by
 * world_from_instance. Returns the first error of out. */
RayesError rib_recording_replay(const RibRecording *rec, const IoSink *out,
                                const float world_from_instance[16]);

#endif /* RAYES_IO_RIB_INTERNAL_H */
