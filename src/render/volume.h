/*
 * render/volume.h — private to render/: volumes (memo 6.1), boxes filled
 * by a medium whose shader's opacity() is the extinction coefficient per
 * unit length (the memo's convention) and whose lighting() is the light
 * the medium scatters and emits toward the ray per unit length.
 *
 * Rays cross volumes by ray marching (a jittered step along the segment
 * inside the box; DESIGN.md "Volumes" says why not delta tracking): shadow
 * and transmission rays multiply exp(-sum sigma_t dt); camera and specular
 * rays add the light scattered toward them, single scattering with
 * shadows; diffuse rays see the extinction only. With the opacity cache,
 * extinction is read from bricks of 8 x 8 x 8 voxels cached like grids at
 * three resolutions (9^3, 3^3 and 2^3 points), data type opacity, chosen
 * by the ray's footprint, and interpolated trilinearly.
 *
 * Volumes are not in Embree: every ray clips itself against each box.
 */
#ifndef RAYES_RENDER_VOLUME_H
#define RAYES_RENDER_VOLUME_H

#include "render/path.h"

/* Voxels along a brick's side at the fine resolution. */
#define VOLUME_BRICK 8

/* The prepared form of a volume. */
typedef struct RenderVolume {
    uint32_t object;             /* its RenderObject (shader, Cs, Os) */
    Mat4 world_from_object, object_from_world;
    Vec3 lo, hi;                 /* the box, object space */
    int n_vox[3];                /* fine voxels along each axis */
    Vec3 cell;                   /* a fine voxel's size, object space */
    int n_brick[3];              /* bricks along each axis */
    uint32_t key_base;           /* cache keys: patch key_base + brick index */
    float voxel;                 /* a fine voxel's size, world units (the march step) */
    int64_t inside;              /* -1, or the RenderObject whose surfaces bound it: a ray's
                                    segment is in it only when the ray leaves that object
                                    through its back (rayes_scene_volume_inside) */
    int hidden_bound;            /* 1: that object is seen by no ray (a pbrt "interface"
                                    shape): a ray is in the volume between its crossings of
                                    the object's surfaces, found in its own scene */
    int shadow_crosses;          /* 1: shadow rays cross that object (hidden, or letting them
                                    through: a glass's thin shadow), so transmission finds their
                                    segments inside it the same way */
    int atmosphere;              /* 1: RenderMan's atmosphere (rayes_scene_atmosphere): camera
                                    rays that hit a surface see it, no other ray */
    int uniform;                 /* 1: the same extinction everywhere (the homogeneous shader
                                    without patterns): transmittance takes one step, scattering
                                    one per lighting point */
} RenderVolume;

/* Fills v for the box [lo, hi] of object space under world_from_object,
 * with fine voxels of about voxel world units (at most VOLUME_MAX_VOXELS
 * along an axis); its bricks' cache keys start at key_base. Returns the
 * number of bricks (the next volume's key_base offset), or 0 if the box is
 * empty or the transform singular. */
uint32_t volume_init(RenderVolume *v, uint32_t object, const Mat4 *world_from_object, Vec3 lo,
                     Vec3 hi, float voxel, uint32_t key_base);

#define VOLUME_MAX_VOXELS 512

/* 1 if obj's shader gives every point of its volume the same extinction
 * and albedo (the built-in homogeneous shader with no parameter bound to a
 * pattern), so marching it finely gains nothing. */
int volume_uniform(const RenderObject *obj);

/* The transmittance of the volumes along ray's [tnear, tfar] (diff its
 * differential): 1 without volumes. Counts transmission rays and steps. */
Vec3 volume_transmittance(Worker *w, const Ray *ray, RayDiff diff);

/* The light the volumes send toward ray->o along ray->d from [tnear,
 * tmax] (camera and specular rays of type kind, at the given depths, the
 * key naming its random numbers), and in *T the transmittance over that
 * segment, by which what lies beyond it is seen. leaving: the object
 * whose back the segment ends on (-1: none), for volumes inside one; hit:
 * the segment ends on a surface (an atmosphere is seen only then). */
Vec3 volume_radiance(Worker *w, const Ray *ray, float tmax, int64_t leaving, int hit, uint32_t kind,
                     int diffuse_depth, int specular_depth, uint64_t key, RayDiff diff, Vec3 *T);

#endif /* RAYES_RENDER_VOLUME_H */
