/*
 * shade/grid.h — voxel grids of density for the "densitygrid" and
 * "nanovdb" patterns (pattern.h): pbrt-v4's uniform grid (nx x ny x nz
 * values over a box) and a float grid of a NanoVDB file, read with
 * NanoVDB's C header PNanoVDB.h. Both are sampled trilinearly between
 * voxel centres.
 *
 * A grid is immutable once made: any number of threads may sample it
 * (NanoVDB's read accessor, the one mutable thing, lives on the caller's
 * stack). The grid owns its values (the whole NanoVDB grid buffer, as in
 * the file).
 */
#ifndef RAYES_SHADE_GRID_H
#define RAYES_SHADE_GRID_H

#include <stddef.h>

typedef struct VoxelGrid VoxelGrid;

/* A uniform grid of res[0] x res[1] x res[2] values (x fastest) whose
 * voxels tile the box p0..p1: values sit at voxel centres, trilinear
 * between them, and samples beyond the outer centres read 0 as pbrt's
 * SampledGrid does (so the box's outer half voxels fade out). Returns NULL with err filled for a
 * count of 0, a count that is not nx ny nz, an empty box or no memory. The caller owns the result;
 * values are copied. */
VoxelGrid *grid_new_dense(const size_t res[3], const float *values, size_t n_values,
                          const float p0[3], const float p1[3], char *err, size_t err_size);

/* The float grid called name in the NanoVDB file at path (read whole,
 * once). Returns NULL with err filled with one line naming the file for a
 * file that cannot be read, is truncated, has the wrong magic number or
 * version, is compressed, has no grid of that name, or whose grid is not
 * a float grid. The caller owns the result. */
VoxelGrid *grid_read_nanovdb(const char *path, const char *name, char *err, size_t err_size);

/* Nonzero when err, as grid_read_nanovdb filled it, says only that the
 * file has no grid of the name asked for (an optional grid's absence). */
int grid_error_missing(const char *err);

/* As grid_read_nanovdb, from the file's bytes (path only names it in
 * messages): the fuzz target's entry. */
VoxelGrid *grid_parse_nanovdb(const unsigned char *data, size_t size, const char *name,
                              const char *path, char *err, size_t err_size);

/* The grid at the n points p (the grid's own space: the box's, or the
 * NanoVDB file's world space) into out. */
void grid_sample(const VoxelGrid *g, size_t n, const float (*p)[3], float *out);

void grid_free(VoxelGrid *g);

#endif /* RAYES_SHADE_GRID_H */
