/*
 * render/pbgi.h — point-based global illumination (Christensen 2008; the
 * memo's section 5.3 and Figure 5), rayes's second GI mode (`--gi
 * pointbased`, DESIGN.md "Point-based global illumination").
 *
 * Pass 1 shades every grid of the diced scene, on and off camera, at its
 * vertices with diffuselighting (direct lighting only), both sides, and
 * turns each micropolygon into a disk: position, normal, area, radiosity of
 * either side (outgoing radiance, as the radiosity cache holds it). Pass 2 (bounces > 1) reshades
 * the grids with the indirect-diffuse service answered by the cloud itself.
 * Pass 3 is the render: the indirect-diffuse service gathers from an
 * octree over the disks, whose nodes carry order-2 spherical harmonics (9
 * coefficients) of their emitted power and projected area, by rasterising
 * near disks and far clusters front to back into a small cube raster
 * around the shading point, where nearer surfaces cover farther ones; with
 * irradiance interpolation the grid hider's records are such gathers with
 * gradients (pbgi_record, irrgrid.h).
 *
 * A cloud is immutable once built and read by every thread; a gather is a
 * pure function of the cloud and the point, so images do not depend on
 * threads. Each gathering thread has its own PbgiRaster.
 */
#ifndef RAYES_RENDER_PBGI_H
#define RAYES_RENDER_PBGI_H

#include <stddef.h>
#include <stdint.h>

#include "render/irradiance.h"
#include "render/path.h"

#define PBGI_SH 9 /* spherical-harmonic coefficients, order 2 */

typedef struct PbgiDisk {
    float P[3];    /* centre, world */
    float N[3];    /* unit normal: the side that emits */
    float area;    /* scene units^2 */
    float L[3];    /* radiosity: outgoing radiance on the normal's side (as the cache's) */
    float Lb[3];   /* the back side's (against the normal); 0: black from behind */
} PbgiDisk;

typedef struct PbgiNode {
    float c[3];                /* centre of its disks' bounding box, world */
    float r;                   /* bounding sphere about c, disks' radii included */
    uint32_t first;            /* leaf: its first disk; else its first child node */
    uint16_t count;            /* leaf: disks; else children (contiguous) */
    uint8_t leaf;              /* 1: a leaf */
} PbgiNode;

/* A node's harmonics, apart from the nodes the traversal reads (24 bytes
 * each, a cache line for three): read only where a node is a cluster. */
typedef struct PbgiCluster {
    float power[PBGI_SH][3];   /* SH of the power toward w: sum L A max(0, N.w), RGB */
    float area[PBGI_SH];       /* SH of the projected area facing w: sum A max(0, N.w) */
} PbgiCluster;

typedef struct PbgiCloud {
    PbgiDisk *disks;           /* in octree order; owned */
    uint32_t *perm;            /* disk k was disk perm[k] of the order given to _new */
    size_t n_disks;
    PbgiNode *nodes;           /* nodes[0] is the root; owned */
    PbgiCluster *clusters;     /* per node: its harmonics; owned */
    size_t n_nodes;
    float max_solid_angle;     /* a node smaller than this (steradians) is one cluster */
    int raster;                /* cube raster: raster x raster pixels a face */
    float (*pix_dir)[3];       /* per pixel, those above the horizon first: its unit
                                  direction, local frame (z = the normal) */
    float *pix_weight;         /* its cos(theta) d(omega), normalised to sum to pi over
                                  the upper pixels; 0 below the horizon */
    float *pix_omega;          /* its solid angle, steradians */
    int *pix_of;               /* 6 raster^2: a cube pixel's (face, row, column) index in
                                  the arrays above */
    int n_pix;                 /* pixels: 6 raster^2 (below the horizon too, so that
                                  fragments across it keep their shares) */
    int n_upper;               /* those above the horizon, first: 3 raster^2 */
    int (*wall_pix)[2];        /* per wall between two upper pixels (p, q): their indices */
    float (*wall_vec)[3];      /* its unit normal into q on the sphere (local frame) times
                                  the integral of cos(theta) along it */
    int n_walls;
} PbgiCloud;

/* A thread's scratch raster for gathers. */
typedef struct PbgiRaster {
    float *cov;                /* n_pix coverages in [0, 1] */
    float (*col)[3];           /* n_pix coverage-weighted radiances */
    float *tmp;                /* n_pix: a large fragment's coverages */
    float *dist;               /* n_pix coverage-weighted distances of the fragments */
} PbgiRaster;

/* Seconds of each pass and what it made. */
typedef struct PbgiTimes {
    double cloud_s;            /* pass 1: shading the grids into disks */
    double bounces_s;          /* pass 2: further bounces on the cloud */
    double octree_s;           /* building the octree (both passes' builds) */
} PbgiTimes;

/* A cloud over n disks (taken over: freed with the cloud, reordered) with
 * the gather's quality knobs: max_solid_angle in (0, 4 pi], raster even, 2
 * to 64. NULL when out of memory. */
PbgiCloud *pbgi_cloud_new(PbgiDisk *disks, size_t n, float max_solid_angle, int raster);
void pbgi_cloud_free(PbgiCloud *cloud);

/* Replaces the disks' radiosities (L[i] and back side's Lb[i] for the disk
 * given i-th to _new) and recomputes the nodes' harmonics. */
void pbgi_cloud_relight(PbgiCloud *cloud, const float (*L)[3], const float (*Lb)[3]);

/* A scratch raster for cloud's gathers, and its release. 0: done; -1: out
 * of memory. */
int pbgi_raster_init(PbgiRaster *r, const PbgiCloud *cloud);
void pbgi_raster_fini(PbgiRaster *r);

/* The indirect diffuse at P with unit normal N from the cloud: the
 * cosine-weighted mean of the radiance arriving over the hemisphere (the
 * irradiance over pi, as the indirect-diffuse service defines it). */
Vec3 pbgi_gather(const PbgiCloud *cloud, PbgiRaster *r, Vec3 P, Vec3 N);

/* The same gather as an irradiance record (irradiance.h) at P, N: its
 * irradiance (pi times pbgi_gather's), rotational and translational
 * gradients from the raster's pixels and their depths, and validity
 * radius (irradiance interpolation over grids, irrgrid.h). */
void pbgi_record(const PbgiCloud *cloud, PbgiRaster *r, Vec3 P, Vec3 N, IrrRecord *rec);

/* Passes 1 and 2 over the render scene: a cloud with set's quality knobs
 * (set->pbgi_max_solid_angle, set->pbgi_raster) of every grid (surfaces,
 * curves, points) with a shader, bounces - 1 further bounces computed on it. Shaders call
 * `services` (render_services). Adds the passes' shading points and rays to
 * stats and their times to *times. NULL when out of memory. */
PbgiCloud *pbgi_build(const RenderScene *rs, const RenderSettings *set,
                      const RayesShaderServices *services, RenderStats *stats, PbgiTimes *times);

/* Writes the cloud as binary little-endian PLY: a vertex element of float
 * x y z nx ny nz area r g b (radiosity) back_r back_g back_b (the back
 * side's). 0, or -1 with a one-line message
 * in err. */
int pbgi_write_ply(const PbgiCloud *cloud, const char *path, char *err, size_t err_size);

#endif /* RAYES_RENDER_PBGI_H */
