/*
 * geom/geom.h — primitives, patches and grids (DESIGN.md "Geometry").
 *
 * A primitive (bilinear patch, bicubic Bezier patch, triangle, sphere) is
 * split into patches small enough to dice into one grid of at most
 * "gridsize" micropolygons (RenderMan's limit, GEOM_GRID_SIZE unless the
 * options say otherwise), no side longer than GEOM_MAX_GRID vertices;
 * triangles into triangular grids of at most sqrt(gridsize) subdivisions
 * per edge (GEOM_MAX_TRI by default). The dicing rate comes from
 * the camera: a micropolygon edge of about sqrt(shading rate) pixels at the
 * patch's distance from the eye, whether or not the patch is in view (the
 * "spherical projection" of RenderMan), at least one micropolygon per side.
 *
 * A patch's global id is its index in the GridSet, which holds one grid per
 * patch: patches and grids are numbered alike, in primitive order, so ids
 * do not depend on threads. Grid vertices are structure-of-arrays in the
 * GridSet; quad grids are row-major (u fastest), triangular grids are rows
 * j = 0..n of n - j + 1 vertices (barycentric b1 = i/n, b2 = j/n).
 *
 * Memory: a GridSet owns its arrays (geom_gridset_fini frees them).
 * Thread-safety: dicing writes only into its own GridSet; reading a
 * finished GridSet is thread-safe.
 */
#ifndef RAYES_GEOM_GEOM_H
#define RAYES_GEOM_GEOM_H

#include <stddef.h>
#include <stdint.h>

#include "util/vec.h"

#define GEOM_GRID_SIZE 256 /* micropolygons per grid, at most, by default (RenderMan's) */
#define GEOM_MAX_GRID 65   /* vertices per side of a quad grid, at most */
#define GEOM_MAX_TRI 16    /* subdivisions per edge of a triangular grid, by default
                              (sqrt(GEOM_GRID_SIZE)); GEOM_MAX_GRID - 1 at most */
#define GEOM_MAX_GRID_SIZE ((GEOM_MAX_GRID - 1) * (GEOM_MAX_GRID - 1)) /* largest gridsize */
#define GEOM_MAX_TIMES 16  /* time samples of moving geometry, at most (motion blur) */
#define GEOM_CURVE_RUN                                                                             \
    3 /* segments of a curve one primitive holds, at most (what fits in                            \
         a bicubic patch's control points) */

typedef enum PrimType {
    PRIM_BILINEAR = 1, /* cp[0..3] = P00, P10, P01, P11 */
    PRIM_BICUBIC = 2,  /* big->cp[0..15] Bezier, row-major, u fastest */
    PRIM_TRIANGLE = 3, /* cp[0..2]; (u, v) are barycentrics of cp[1], cp[2] */
    PRIM_SPHERE = 4,   /* big->sphere.radius at the origin of its world_from_object */
    PRIM_QUADRIC = 5,  /* one of RenderMan's quadrics (big->quadric.kind: RayesQuadric's values),
                          swept about object-space z; see geom_quadric_eval */
    PRIM_SUBDIV = 6,   /* one patch of a subdivision mesh's limit surface (subdiv.h): a quad,
                          or a triangle (subdiv.triangular) with PRIM_TRIANGLE's (u, v) */
    PRIM_CURVE = 7,    /* a run of up to GEOM_CURVE_RUN cubic Bezier segments of a curve
                          with a width: u along the run, v across, the centre line at
                          v = 1/2 (geom_curve_frame) */
    PRIM_POINT = 8     /* a sphere or disk: the square of its diameter facing the camera (or
                          its normal), u and v across */
} PrimType;

/* How curves and points are traced (Grid.shape): surfaces are grids
 * (ribbons with normals too); the others are Embree's curve and point
 * primitives built from the grid's vertices (accel.h). */
typedef enum GeomShape {
    GEOM_SHAPE_SURFACE = 0,
    GEOM_SHAPE_ROUND_CURVE = 1, /* a tube about the centre line of a 2-row grid */
    GEOM_SHAPE_FLAT_CURVE = 2,  /* a ribbon that faces each ray */
    GEOM_SHAPE_SPHERE = 3,      /* a sphere in a 2 x 2 grid's square */
    GEOM_SHAPE_DISK = 4,        /* a disk in the square, facing each ray */
    GEOM_SHAPE_ORIENTED_DISK = 5 /* a disk in the square, in its plane */
} GeomShape;

struct SubdivMesh;

/* Primitive variables a primitive may carry (rayes.h's RayesPrimvar), as
 * bits of Prim.pv and Grid.primvars. */
enum {
    GEOM_PV_N = 1u << 0,  /* shading normal, 3 floats */
    GEOM_PV_ST = 1u << 1, /* texture coordinates, 2 floats */
    GEOM_PV_CS = 1u << 2, /* surface colour, 3 floats */
    GEOM_PV_OS = 1u << 3  /* surface opacity, 3 floats */
};
#define GEOM_N_PV 4 /* the GEOM_PV_* bits */

/* Prim.object and Grid.object of a master's geometry made before any
 * shader inside its block: each instance's own object applies. */
#define GEOM_OBJECT_INHERIT UINT32_MAX

/* Constructive solid geometry (RenderMan's SolidBegin, DESIGN.md
 * "Solids"): a tree of solids, nodes in the order their blocks open, a
 * node's subtree the nodes [its index, end). A primitive solid is a leaf:
 * the closed surface of its primitives, inside behind their fronts. */
typedef enum GeomSolidOp {
    GEOM_SOLID_PRIMITIVE = 0,
    GEOM_SOLID_UNION = 1,
    GEOM_SOLID_INTERSECTION = 2,
    GEOM_SOLID_DIFFERENCE = 3 /* the first child less the others */
} GeomSolidOp;

typedef struct GeomSolid {
    uint32_t op;     /* GeomSolidOp */
    uint32_t parent; /* the enclosing solid's index + 1; 0: a root */
    uint32_t end;    /* one past the last node of its subtree */
} GeomSolid;

/* What does not fit in a Prim: a bicubic patch's control points, a
 * sphere's or a quadric's transforms, a curve run's centre line. A Prim
 * is kept small because a dense mesh has one per face (DESIGN.md
 * "Primitives"); the scene keeps these in an arena of its own
 * (scene_add_prim copies the one a primitive points to). */
typedef struct PrimBig {
    union {
        Vec3 cp[16]; /* bicubic: world-space Bezier control points */
        struct {
            Mat4 world_from_object;
            Mat4 normal_from_object; /* inverse transpose, for normals */
            float radius;
        } sphere;
        struct {
            Mat4 world_from_object;
            int kind;    /* RayesQuadric's value */
            int reverse; /* 1: u runs backwards, so the normal turns inward */
            float p[7];  /* RenderMan's parameters, thetamax (and phi) in radians */
        } quadric;
        struct {
            Vec3 cp[3 * GEOM_CURVE_RUN + 1]; /* the centre line's Bezier control points,
                                world: segment k's are cp[3k .. 3k + 3] */
            float width[GEOM_CURVE_RUN + 1]; /* world units, at the segments' ends (linear
                                between) */
            Vec3 n[2]; /* ribbons (one segment each): the normals at its ends, world */
        } curve;
    };
} PrimBig;

typedef struct Prim {
    PrimType type;
    uint32_t object;       /* the object (shader, attributes) it belongs to, or
                              GEOM_OBJECT_INHERIT (a master's: its instance's) */
    uint32_t master;       /* 0: world geometry; else its master's index + 1: its points are
                              in master space, and it is seen only through instances */
    uint32_t motion;       /* its motion (the scene's SceneMotion index + 1), or 0: still */
    uint32_t solid;        /* its primitive solid (GeomSolid index + 1), or 0: none */
    uint8_t pv;            /* GEOM_PV_* bits: the primitive variables it carries */
    uint8_t pv_cubic;      /* of those, the ones with 16 Bezier control values (a bicubic
                              patch's vertex class); the others have one per corner */
    size_t pv_first;       /* index of its first value in the scene's primvar pool: per
                              variable in bit order, per control value, its floats */
    float shading_rate;    /* micropolygon area in pixels */
    float motionfactor;    /* coarser dicing when motion blurred (RenderMan's "dice"
                              "motionfactor"; motion.c), 0: none */
    float focusfactor;     /* coarser dicing when out of focus ("focusfactor"), 0: none */
    uint32_t displacement; /* the scene's displacement shader + 1, or 0: none */
    float displacement_bound; /* world units; 0: unbounded */
    PrimBig *big;             /* bicubic, sphere, quadric and curve: the rest of it; else NULL */
    union {
        Vec3 cp[4]; /* bilinear and triangle: world-space control points (bicubic:
                       big->cp; geom_prim_cp) */
        struct {
            const struct SubdivMesh *mesh; /* owned by the scene */
            uint32_t patch;                /* its patch number in the mesh */
            int triangular;                /* a Loop triangle */
        } subdiv;
        struct {
            Vec3 facing;     /* round and flat: the ribbon diced faces this point (the eye:
                                geom_dice_prim sets it) */
            uint8_t shape;   /* GEOM_SHAPE_ROUND_CURVE, _FLAT_CURVE, or _SURFACE: a ribbon
                                oriented by big->curve.n */
            uint8_t n_seg;   /* segments in the run, 1 to GEOM_CURVE_RUN (1 for ribbons) */
        } curve;
        struct {
            Vec3 centre;
            float radius;
            Vec3 n;          /* an oriented disk's normal, world */
            Vec3 facing;     /* spheres and disks: the square faces this point (the eye) */
            uint8_t shape;   /* GEOM_SHAPE_SPHERE, _DISK or _ORIENTED_DISK */
        } point;
    };
} Prim;

/* The control points of a bilinear, bicubic or triangular primitive. */
static inline const Vec3 *geom_prim_cp(const Prim *prim)
{
    return prim->type == PRIM_BICUBIC ? prim->big->cp : prim->cp;
}

/* A curve run's frame at u: the centre line C, its derivative T (with
 * respect to u), the width w and its derivative dw, and the unit
 * direction B across the ribbon (from v = 0 to 1: n x T for ribbons,
 * facing x T otherwise, so that dPdu x dPdv turns to n or to the facing
 * point). Segment k of n_seg covers u in [k / n_seg, (k + 1) / n_seg]. */
void geom_curve_frame(const Prim *prim, float u, Vec3 *C, Vec3 *T, float *w, float *dw, Vec3 *B);

/* The segment of a curve run at u and the parameter t in it. */
int geom_curve_segment(const Prim *prim, float u, float *t);

/* A quadric's object-space position and derivatives at (u, v) in [0, 1]^2:
 * u sweeps theta from 0 to thetamax, v runs along the profile (RenderMan's
 * parameterisation). */
void geom_quadric_eval(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv);

/* Evaluates a primitive at parameters (u, v): position and derivatives, in
 * world space. */
void geom_prim_eval(const Prim *prim, float u, float v, Vec3 *P, Vec3 *dPdu, Vec3 *dPdv);

/* Primitive variables at one point. */
typedef struct PrimvarSample {
    Vec3 N;                /* unit shading normal, world (GEOM_PV_N) */
    float st[2];           /* texture coordinates (GEOM_PV_ST) */
    float dst[4];          /* ds/du, ds/dv, dt/du, dt/dv (GEOM_PV_ST) */
    Vec3 Cs;               /* surface colour (GEOM_PV_CS) */
    Vec3 Os;               /* surface opacity (GEOM_PV_OS) */
} PrimvarSample;

/* 1 if prim's (u, v) domain is a triangle (barycentric u, v). */
static inline int geom_prim_triangular(const Prim *prim)
{
    return prim->type == PRIM_TRIANGLE || (prim->type == PRIM_SUBDIV && prim->subdiv.triangular);
}

/* The number of control values per variable of a primitive without
 * pv_cubic: its corners (4 for patches, 3 for triangles). */
int geom_prim_corners(const Prim *prim);

/* Interpolates prim's primitive variables (those of prim->pv; the other
 * fields of out are left alone) at (u, v) from its values in pool:
 * bilinear over the corners of patches (bicubic ones too), barycentric on
 * triangles, with the Bezier basis for pv_cubic values. The normal is not
 * yet turned toward dPdu x dPdv (see geom_dice_prim). */
void geom_prim_primvars(const Prim *prim, const float *pool, float u, float v,
                        PrimvarSample *out);

/* The unit normal at (u, v): dPdu x dPdv, or at a degenerate point (a pole,
 * a collapsed patch row) the normal a little way inside the patch. */
Vec3 geom_prim_normal(const Prim *prim, float u, float v);

typedef struct Grid {
    uint32_t prim;         /* the primitive it was diced from */
    uint32_t object;       /* the primitive's object, or GEOM_OBJECT_INHERIT */
    uint32_t master;       /* the primitive's master (Prim.master): 0, world geometry */
    uint32_t solid;        /* the primitive's solid (Prim.solid): 0, none */
    uint32_t first_vertex; /* index of its first vertex in the GridSet */
    uint16_t nu, nv;       /* quad: vertices in u and v; triangle: nu = n subdivisions, nv = 0 */
    uint8_t triangular;    /* 1 for a triangular grid */
    uint8_t shape;         /* GeomShape: how it is traced (curves and points: 2 rows, or 2 x 2) */
    float edge;            /* mean micropolygon edge length, scene units */
    float curvature;       /* largest |dN| / |dP| between neighbouring vertices, 1/units */
    float sagitta;         /* how far a neighbouring grid's micropolygons may run inside
                              this grid's vertices, units: the largest min(edge^2 curvature
                              / 2, edge) over its primitive's grids (geom_bound_sagitta),
                              since neighbours may be diced at other rates */
    float uv[3][2];        /* corners in the primitive's (u, v): quad (u0,v0), (u1,v1);
                              triangle: the three corners; a quad over part of a triangle
                              (dice.c's split_quads): a box whose spacing is its vertices'
                              largest step in u and in v */
    uint8_t primvars;      /* GEOM_PV_* bits: the GridSet's Ns, st, Cs, Os hold its vertices'
                              values (else: N, uv, the object's colour and opacity) */
    uint8_t moving;        /* 1: its vertices differ between time samples (GridSet.Pt); its
                              radiosity is cached per motion segment */
    uint32_t sub;          /* a quad over part of a triangle (dice.c's split_quads): its
                              GridSet.subs index + 1, for stitching; else 0 */
    uint32_t motion_vertex; /* a moving grid: its first vertex in GridSet.Pt and the rest */
} Grid;

/* Where a quad over part of a triangle lies in it (Grid.sub): one of the
 * three quads a large triangle dices into (split_quads), from its corner
 * `corner`; or a needle's fan (dice_fan, corner GEOM_FAN + the apex),
 * whose side t = 0 is the edge across from the apex, from corner apex + 1
 * (s = 0) to apex + 2, and side t = 1 the apex. */
#define GEOM_FAN 3
typedef struct GridSub {
    uint8_t corner;  /* the triangle's corner it starts at, or GEOM_FAN + a fan's apex */
    float sub[2][2]; /* its rectangle of the quad's own (s, t), (s0, t0) and (s1, t1),
                        in [0, 1] */
    float tri[3][2]; /* the triangle's corners, the primitive's (u, v) */
} GridSub;

/* One placement of a master (an object instance, nested ones flattened):
 * the master's grids, diced once in master space, are traced through an
 * Embree instance and shaded through these transforms (DESIGN.md
 * "Instances"). */
typedef struct GeomInstance {
    Mat4 world_from_master;
    Mat4 master_from_world;
    Mat4 normal_to_world;  /* the inverse transpose, negated when the transform mirrors, so
                              that N stays on the side of dPdu x dPdv mapped to world */
    float scale;           /* world units per master unit: the cube root of |det| (edges,
                              offsets and curvatures of master grids scale by it) */
    uint32_t master;       /* the master's index (its grids have Grid.master = master + 1) */
    uint32_t object;       /* the object its master's GEOM_OBJECT_INHERIT grids take */
    uint32_t ray_mask;     /* RayesRayType bits that see it: those of every instance's object
                              along its nesting (an enclosing instance's visibility holds) */
    uint32_t motion;       /* 0: still; else 1 + the index in GridSet.instance_motion of its
                              world_from_master at each of the GridSet's n_times samples (the
                              fields above are sample 0's); geom_instance_at blends them */
} GeomInstance;

/* A cluster of tiny neighbouring grids of one object (geom/cluster.c): the
 * radiosity cache's levels coarser than one grid. */
typedef struct GeomCluster {
    uint32_t rep;    /* the member grid nearest its middle, whose middle it is shaded at */
    uint32_t parent; /* the cluster of clusters it is in, index + 1; 0: none */
    float edge;      /* its size, the square root of its area (its grids' units) */
} GeomCluster;

typedef struct GridSet {
    Grid *grids;           /* one per patch; the index is the patch id */
    size_t n_grids;
    GridSub *subs; /* Grid.sub's records */
    size_t n_subs, cap_subs;
    uint32_t *grid_cluster; /* per grid, the smallest cluster it is in, index + 1; 0: none.
                              NULL: no clusters (geom_cluster_grids) */
    GeomCluster *clusters;  /* owned */
    size_t n_clusters;
    Vec3 *P;               /* vertex positions, world */
    Vec3 *N;               /* unit normals, world (front = dPdu x dPdv) */
    Vec3 *dPdu, *dPdv;     /* derivatives with respect to the primitive's u, v */
    float (*uv)[2];        /* the primitive's (u, v) at the vertex */
    /* Primitive variables, allocated (for every vertex) once any grid has
     * them, valid at the vertices of grids whose primvars bit says so. */
    Vec3 *Ns;              /* unit shading normals, on N's side (GEOM_PV_N) */
    float (*st)[2];        /* texture coordinates (GEOM_PV_ST) */
    float (*dst)[4];       /* their derivatives ds/du, ds/dv, dt/du, dt/dv (GEOM_PV_ST) */
    Vec3 *Cs;              /* surface colours (GEOM_PV_CS) */
    Vec3 *Os;              /* surface opacities (GEOM_PV_OS) */
    unsigned pv_arrays;    /* GEOM_PV_* bits of the arrays allocated */
    size_t n_vertices;
    size_t cap_grids, cap_vertices;
    GeomInstance *instances; /* the flattened object instances; a hit's instance is an index
                              here + 1 (Hit.instance, CacheKey.instance); owned */
    size_t n_instances;
    size_t n_masters;      /* masters (grids may have master 1 .. n_masters) */
    Mat4 *instance_motion; /* moving instances' world_from_master, n_times per instance
                              (GeomInstance.motion); owned, NULL if none moves */
    size_t n_moving_instances;
    GeomSolid *solids;     /* the solids' tree (Grid.solid indexes it, + 1); owned */
    size_t n_solids;
    /* Motion blur (DESIGN.md "Motion blur and depth of field"): n_times
     * uniformly spaced time samples from time[0] to time[1]. Sample 0 is P,
     * N, dPdu, dPdv above; sample k >= 1 of a vertex of a moving grid g
     * (Grid.moving) is Pt[k - 1][g->motion_vertex + (i - g->first_vertex)]
     * and so on: only moving grids' vertices have later samples.
     * n_times 1: nothing moves, the arrays are NULL. */
    int n_times;
    float time[2];         /* the first and last time sample, scene (shutter) time */
    size_t n_motion_vertices; /* vertices of each later sample's arrays */
    Vec3 *Pt[GEOM_MAX_TIMES - 1], *Nt[GEOM_MAX_TIMES - 1];
    Vec3 *dPdut[GEOM_MAX_TIMES - 1], *dPdvt[GEOM_MAX_TIMES - 1];
} GridSet;

/* Where time t falls among gs's time samples: the motion segment (0 to
 * n_times - 2; 0 without motion) and the fraction f in [0, 1] across it
 * (times outside the samples clamp to the first or last). */
static inline int geom_motion_segment(const GridSet *gs, float t, float *f)
{
    *f = 0.0f;
    if (gs->n_times < 2)
        return 0;
    float span = gs->time[1] - gs->time[0];
    float x = span > 0.0f ? (t - gs->time[0]) / span * (float)(gs->n_times - 1) : 0.0f;
    x = x < 0.0f ? 0.0f : x > (float)(gs->n_times - 1) ? (float)(gs->n_times - 1) : x;
    int seg = (int)x;
    seg = seg > gs->n_times - 2 ? gs->n_times - 2 : seg;
    *f = x - (float)seg;
    return seg;
}

/* The time in the middle of motion segment seg (where a cache fill shades). */
static inline float geom_segment_mid_time(const GridSet *gs, int seg)
{
    if (gs->n_times < 2)
        return gs->time[0];
    return gs->time[0] + (gs->time[1] - gs->time[0]) * ((float)seg + 0.5f) / (float)(gs->n_times - 1);
}

/* Sets gi's world_from_master, its inverse, normal_to_world and scale
 * (the other fields are left alone). 0, or -1 if m is singular. */
int geom_instance_set(GeomInstance *gi, Mat4 world_from_master);

/* Instance gi at time t: gi itself if it is still, else *tmp, a copy whose
 * transforms are the linear blend of its world_from_master at the two
 * GridSet time samples about t (the matrices blended entry by entry, as
 * Embree blends an instance's FLOAT3X4 transforms; clamped outside). */
const GeomInstance *geom_instance_at(const GridSet *gs, const GeomInstance *gi, float t,
                                     GeomInstance *tmp);

/* Where vertex i of moving grid g is in the later samples' arrays. */
static inline size_t geom_motion_index(const Grid *g, size_t i)
{
    return g->motion_vertex + (i - g->first_vertex);
}

/* Vertex i's position at time sample k (sample 0 for a still grid). */
static inline Vec3 geom_vertex_P_at_sample(const GridSet *gs, const Grid *g, size_t i, int k)
{
    return k == 0 || !g->moving ? gs->P[i] : gs->Pt[k - 1][geom_motion_index(g, i)];
}

/* What a vertex of grid g is at segment seg, fraction f: the linear blend
 * of the two time samples (Embree's linear motion). A still grid's is
 * sample 0. */
typedef struct GeomVertex {
    Vec3 P, N, dPdu, dPdv; /* N not renormalised */
} GeomVertex;

static inline GeomVertex geom_vertex_at(const GridSet *gs, const Grid *g, size_t i, int seg, float f)
{
    if (!g->moving || gs->n_times < 2)
        return (GeomVertex){gs->P[i], gs->N[i], gs->dPdu[i], gs->dPdv[i]};
    size_t j = geom_motion_index(g, i);
    GeomVertex a = seg == 0 ? (GeomVertex){gs->P[i], gs->N[i], gs->dPdu[i], gs->dPdv[i]}
                            : (GeomVertex){gs->Pt[seg - 1][j], gs->Nt[seg - 1][j],
                                           gs->dPdut[seg - 1][j], gs->dPdvt[seg - 1][j]};
    GeomVertex b = {gs->Pt[seg][j], gs->Nt[seg][j], gs->dPdut[seg][j], gs->dPdvt[seg][j]};
    return (GeomVertex){v3_lerp(a.P, b.P, f), v3_lerp(a.N, b.N, f), v3_lerp(a.dPdu, b.dPdu, f),
                        v3_lerp(a.dPdv, b.dPdv, f)};
}

/* How the camera sets dicing rates, and how large a grid may be.
 *
 * With a view (has_view), a patch that may be on screen (its lattice is
 * not wholly outside one side of the viewing frustum) and lies in front
 * of the eye is diced by its projected (raster) size, as RenderMan does:
 * micropolygon edges of sqrt(shading rate) pixels on the image, so a
 * floor seen at a grazing angle is diced as coarsely along the view as
 * its pixels are. Everything else (off screen, behind the eye, or
 * crossing the eye plane, where a projection explodes) is diced by its
 * distance from the eye ("spherical projection"), its edges longer by a
 * factor that grows from 1 at the frustum's side to offscreen half a
 * screen beyond it. Without a view every patch is diced by distance. */
typedef struct DiceCamera {
    Vec3 eye;              /* camera position, world */
    float pixel_angle;     /* radians subtended by one pixel (0 in orthographic projection) */
    float pixel_width;     /* world units of one pixel at any distance (orthographic; else 0) */
    float min_distance;    /* distances are clamped to this (the eye inside a patch) */
    int grid_size;         /* micropolygons per grid, at most (RenderMan's "gridsize"), 1 to
                              GEOM_MAX_GRID_SIZE; 0: GEOM_GRID_SIZE */
    int has_view;          /* 1: the fields below describe the view */
    Mat4 camera_from_world; /* camera space: x right, y up, z the view direction */
    float tan_half_fov; /* perspective: tan(fov / 2), screen = (x, y) / (z tan); 0: orthographic,
                           screen = (x, y) */
    float screen[4];    /* screen window: left, right, bottom, top (screen units) */
    float pixel;        /* screen units per pixel */
    float offscreen;    /* >= 1: the edge factor of patches far off screen (1: none) */
    int isotropic;      /* 1: on-screen patches by distance too (RenderMan's rasterorient 0) */
    float rate_scale;   /* >= 1 (0 reads as 1): every edge this much longer (the vertex
                           budget, scene_prepare) */
    int binary;         /* 1: grids of stitched primitives (geom_prim_stitched) take the
                           power of two nearest their rate along each side (RenderMan's
                           binary dicing; triangular grids one for all three), as
                           geom_stitch needs; scene_prepare sets it */
} DiceCamera;

void geom_gridset_init(GridSet *gs);
void geom_gridset_fini(GridSet *gs);

/* Splits prim into patches and dices each into a grid appended to gs; its
 * primitive variables (if any) come from pv_pool and are interpolated at
 * every vertex, the shading normal turned to the side of N. Returns 0, or
 * -1 when out of memory (gs keeps what was added). */
int geom_dice_prim(GridSet *gs, const Prim *prim, uint32_t prim_index, const float *pv_pool,
                   const DiceCamera *cam);

/* The grid vertices geom_dice_prim would add for prim, without dicing;
 * adds the grids to *grids when that is not NULL. */
size_t geom_count_prim(const Prim *prim, const DiceCamera *cam, size_t *grids);

/* Recomputes a grid's mean edge and curvature from its vertices (after
 * displacement has moved them). */
void geom_grid_measure(GridSet *gs, Grid *g);

/* Allocates the primitive variable arrays of the GEOM_PV_* bits of want
 * that gs has not yet, for every vertex it can hold; 0, or -1 when out of
 * memory. */
int geom_gridset_want_primvars(GridSet *gs, unsigned want);

/* Sets the sagitta of grids [first, n_grids) of gs, all of one primitive
 * and measured, to the largest bound among them. */
void geom_bound_sagitta(GridSet *gs, size_t first);

/* 1 if prim's grids are stitched to their neighbours (geom_stitch):
 * bilinear and bicubic patches, quadrics, triangles, subdivision patches
 * (with DiceCamera.binary, they dice at powers of two). */
int geom_prim_stitched(const Prim *prim);

/* Moves the vertices on the sides of gs's stitched grids (prims: the
 * primitives they were diced from, by Grid.prim) onto the polyline of the
 * coarsest grid along each shared line, so that neighbours diced at
 * different rates leave no crack (geom/stitch.c). Run after dicing and
 * displacement, before the ray tracing structure is built. Returns 0,
 * -1 when out of memory or -2 once *stop (if given) is nonzero, read
 * between lines (gs is then partly stitched). */
int geom_stitch(GridSet *gs, const Prim *prims, const volatile int *stop);

/* 1 if g is small enough to be clustered: a still surface grid outside
 * solids of at most 2 x 2 micropolygons (a dense mesh's face). */
int geom_grid_tiny(const Grid *g);

/* Groups gs's tiny grids into clusters of neighbours of one object and
 * those into clusters of clusters (GridSet.grid_cluster, .clusters;
 * geom/cluster.c), replacing any made before. Run once the grids are
 * final. Returns 0, or -1 when out of memory (then there are none). */
int geom_cluster_grids(GridSet *gs);

/* Vertex count of a grid. */
static inline size_t geom_grid_n_vertices(const Grid *g)
{
    return g->triangular ? (size_t)(g->nu + 1) * (g->nu + 2) / 2 : (size_t)g->nu * g->nv;
}

/* Index, within a triangular grid of n subdivisions, of vertex (i, j). */
static inline uint32_t geom_tri_vertex(uint32_t n, uint32_t i, uint32_t j)
{
    return j * (n + 1) - j * (j - 1) / 2 + i;
}

/* What vertex i (of grid g) shades with: the shading normal (N without
 * one), the texture coordinates and their derivatives with respect to
 * (u, v) ((u, v) and the identity without), and the colour and opacity
 * (dflt without). */
static inline Vec3 geom_vertex_normal(const GridSet *gs, const Grid *g, size_t i)
{
    return (g->primvars & GEOM_PV_N) ? gs->Ns[i] : gs->N[i];
}

static inline void geom_vertex_st(const GridSet *gs, const Grid *g, size_t i, float st[2],
                                  float dst[4])
{
    if (g->primvars & GEOM_PV_ST) {
        st[0] = gs->st[i][0], st[1] = gs->st[i][1];
        for (int k = 0; k < 4; k++)
            dst[k] = gs->dst[i][k];
    } else {
        st[0] = gs->uv[i][0], st[1] = gs->uv[i][1];
        dst[0] = 1.0f, dst[1] = 0.0f, dst[2] = 0.0f, dst[3] = 1.0f;
    }
}

static inline Vec3 geom_vertex_color(const GridSet *gs, const Grid *g, size_t i, Vec3 dflt)
{
    return (g->primvars & GEOM_PV_CS) ? gs->Cs[i] : dflt;
}

static inline Vec3 geom_vertex_opacity(const GridSet *gs, const Grid *g, size_t i, Vec3 dflt)
{
    return (g->primvars & GEOM_PV_OS) ? gs->Os[i] : dflt;
}

/* Bernstein polynomials of degree 3 at t, and their derivatives. */
void geom_bezier_basis(float t, float b[4], float db[4]);

#endif /* RAYES_GEOM_GEOM_H */
