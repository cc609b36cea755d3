/*
 * geom/subdiv.h — subdivision surfaces: the exact limit surface of a
 * Catmull-Clark, Loop or bilinear mesh with RenderMan's tags, evaluated by
 * OpenSubdiv's Bfr (geom/subdiv.cpp, the one C++ file of rayes, behind
 * this C interface). DESIGN.md "Subdivision surfaces".
 *
 * A mesh is cut into patches as OpenSubdiv's ptex faces are: a face of the
 * scheme's regular size (4 for Catmull-Clark and bilinear, 3 for Loop) is
 * one patch, a Catmull-Clark face of n != 4 sides is n quad patches, one
 * per corner (the corner at (0, 0), the edge midpoints at (1, 0) and
 * (0, 1), the face's centre at (1, 1)). Quad patches take (u, v) in
 * [0, 1]^2, Loop triangles barycentric (u, v) of their second and third
 * corners, as PRIM_TRIANGLE. Holes and faces with no limit surface (the
 * boundary faces of a mesh whose boundary is not interpolated) make no
 * patch.
 *
 * Primitive variables (N, st, Cs, Os, the bits of GEOM_PV_*) are evaluated
 * with the surface: vertex ones on the limit surface, varying ones
 * linearly over the face, facevarying ones on OpenSubdiv's face-varying
 * surface (values equal at a point are shared, so they are smooth across
 * faces where they agree), uniform and constant ones held per face.
 *
 * Memory: a mesh holds, per face, OpenSubdiv's Surface and its patch
 * points (3 floats plus the vertex primitive variables per point).
 * Thread-safety: evaluation of a finished mesh is thread-safe.
 */
#ifndef RAYES_GEOM_SUBDIV_H
#define RAYES_GEOM_SUBDIV_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct SubdivMesh SubdivMesh;

enum { SUBDIV_CATMULL_CLARK = 0, SUBDIV_LOOP = 1, SUBDIV_BILINEAR = 2 };

/* One primitive variable, already in world space (a normal transformed). */
typedef struct SubdivPrimvar {
    unsigned bit;          /* GEOM_PV_N, GEOM_PV_ST, GEOM_PV_CS or GEOM_PV_OS */
    int cls;               /* RayesPrimvarClass */
    int size;              /* floats per value: 3, 2, 3, 3 */
    const float *data;     /* values in the class's count */
} SubdivPrimvar;

typedef struct SubdivDesc {
    int scheme;                     /* SUBDIV_* */
    size_t n_faces;
    const int *n_verts;             /* per face */
    const int *indices;             /* the faces' points, face after face */
    size_t n_points;
    const float *P;                 /* 3 floats per point, world space */
    int interpolate_boundary;       /* RenderMan's: 0 none, 1 edges and corners, 2 edges */
    int facevarying_boundary;       /* RenderMan's facevaryinginterpolateboundary, 0 to 3 */
    size_t n_creases;               /* crease edges */
    const int *crease_edges;        /* 2 points per edge */
    const float *crease_sharpness;  /* per edge; 10 or more: infinitely sharp */
    size_t n_corners;
    const int *corner_points;
    const float *corner_sharpness;
    size_t n_holes;
    const int *hole_faces;
    SubdivPrimvar pv[4];
    int n_pv;
} SubdivDesc;

/* A new mesh (free with geom_subdiv_free), or NULL with a message in err
 * (a topology OpenSubdiv refuses, a Loop face that is not a triangle, out
 * of memory). The description's arrays are copied as needed. */
SubdivMesh *geom_subdiv_new(const SubdivDesc *desc, char *err, size_t err_size);
void geom_subdiv_free(SubdivMesh *mesh);

/* Patches of the mesh, numbered face by face (sub-faces in corner order). */
size_t geom_subdiv_n_patches(const SubdivMesh *mesh);

/* The face a patch belongs to, and 1 if the patch is a triangle (Loop). */
size_t geom_subdiv_patch_face(const SubdivMesh *mesh, size_t patch);
int geom_subdiv_patch_triangular(const SubdivMesh *mesh, size_t patch);

/* Which curve side `side` of a patch lies on (quads 0: v = 0, 1: u = 1,
 * 2: v = 1, 3: u = 0; triangles: side k from corner k to corner k + 1,
 * the corners at (0, 0), (1, 0), (0, 1)), for stitching neighbours
 * (geom/stitch.c): key names it within the mesh (a mesh edge, or a line
 * inside a face split into sub-faces), and the curve's parameter is
 * t[0] + (t[1] - t[0]) s at the patch's parameter s along the side (for
 * triangles, s from corner k). Patches on either side of a curve agree on
 * its key and parameter. Returns 1, or 0 for a triangle's side 3. */
int geom_subdiv_patch_side(const SubdivMesh *mesh, size_t patch, int side, uint64_t key[2],
                           float t[2]);

/* OpenSubdiv's own uniform refinement of a mesh to `level`
 * (Far::TopologyRefiner::RefineUniform, Far::PrimvarRefiner), for
 * checking the limit surface against (tests/scene/test_subdiv.c): the
 * positions of the vertices of the last level, or with limit their
 * limit positions (PrimvarRefiner::Limit), 3 floats each, in a new array
 * the caller frees (free()), *n of them. NULL when the topology is
 * refused or out of memory. */
float *geom_subdiv_refine_uniform(const SubdivDesc *desc, int level, int limit, size_t *n);

/* Bounds of a patch's control points, which hold its limit surface. */
void geom_subdiv_patch_bounds(const SubdivMesh *mesh, size_t patch, float lo[3], float hi[3]);

/* The limit surface of a patch at (u, v): position and derivatives with
 * respect to the patch's u and v, world space. */
void geom_subdiv_eval(const SubdivMesh *mesh, size_t patch, float u, float v, float P[3],
                      float dPdu[3], float dPdv[3]);

/* The primitive variables of a patch at (u, v): those of the returned
 * GEOM_PV_* bits are written (N not normalised; dst = ds/du, ds/dv,
 * dt/du, dt/dv). */
unsigned geom_subdiv_primvars(const SubdivMesh *mesh, size_t patch, float u, float v, float N[3],
                              float st[2], float dst[4], float Cs[3], float Os[3]);

#ifdef __cplusplus
}
#endif

#endif /* RAYES_GEOM_SUBDIV_H */
