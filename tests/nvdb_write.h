/*
 * tests/nvdb_write.h — writes the smallest valid NanoVDB float grid the
 * tests need, by hand in C (the project has no C++): one root tile, one
 * upper node (32^3), one lower node (16^3) and one leaf (8^3) holding
 * voxels (0..7)^3 of index space, with a map of voxel size h and origin o
 * (world = o + h * index). Offsets and sizes are PNanoVDB.h's (float
 * grids), the file header and metadata nanovdb/util/IO.h's. Checked by
 * nanovdb_validate and nanovdb_print (test_grid.c runs them when
 * installed). The checksum is "none" (all bits set), which readers skip.
 */
#ifndef RAYES_TEST_NVDB_WRITE_H
#define RAYES_TEST_NVDB_WRITE_H

#define PNANOVDB_C
#include <nanovdb/PNanoVDB.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void nvdb_put32(unsigned char *b, size_t at, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        b[at + k] = (unsigned char)(v >> 8 * k);
}

static void nvdb_put64(unsigned char *b, size_t at, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        b[at + k] = (unsigned char)(v >> 8 * k);
}

static void nvdb_putf(unsigned char *b, size_t at, float v)
{
    memcpy(b + at, &v, 4);
}

static void nvdb_putd(unsigned char *b, size_t at, double v)
{
    memcpy(b + at, &v, 8);
}

/* The grid buffer (*size bytes, malloc'd): values[x][y][z] at index
 * (x, y, z). */
static unsigned char *nvdb_grid(const char *name, const float values[8][8][8], double h,
                                const double o[3], size_t *size)
{
    const pnanovdb_grid_type_constants_t *c =
        &pnanovdb_grid_type_constants[PNANOVDB_GRID_TYPE_FLOAT];
    const size_t tree = PNANOVDB_GRID_SIZE, root = tree + PNANOVDB_TREE_SIZE;
    const size_t upper = root + c->root_size + c->root_tile_size;
    const size_t lower = upper + c->upper_size, leaf = lower + c->lower_size;
    *size = leaf + c->leaf_size;
    unsigned char *b = calloc(1, *size);
    if (!b)
        return NULL;
    float lo = values[0][0][0], hi = lo;
    for (int i = 0; i < 512; i++) {
        float v = values[i >> 6][i >> 3 & 7][i & 7];
        lo = v < lo ? v : lo, hi = v > hi ? v : hi;
    }
    /* grid */
    nvdb_put64(b, PNANOVDB_GRID_OFF_MAGIC, PNANOVDB_MAGIC_NUMBER);
    nvdb_put64(b, PNANOVDB_GRID_OFF_CHECKSUM, ~(uint64_t)0);
    nvdb_put32(b, PNANOVDB_GRID_OFF_VERSION,
               PNANOVDB_MAJOR_VERSION_NUMBER << 21 | PNANOVDB_MINOR_VERSION_NUMBER << 10 |
                   PNANOVDB_PATCH_VERSION_NUMBER);
    nvdb_put32(b, PNANOVDB_GRID_OFF_FLAGS,
               PNANOVDB_GRID_FLAGS_HAS_BBOX | PNANOVDB_GRID_FLAGS_HAS_MIN_MAX);
    nvdb_put32(b, PNANOVDB_GRID_OFF_GRID_COUNT, 1);
    nvdb_put64(b, PNANOVDB_GRID_OFF_GRID_SIZE, *size);
    memcpy(b + PNANOVDB_GRID_OFF_GRID_NAME, name, strlen(name) + 1);
    size_t map = PNANOVDB_GRID_OFF_MAP;
    for (int k = 0; k < 3; k++) {
        nvdb_putf(b, map + PNANOVDB_MAP_OFF_MATF + 16 * k, (float)h);
        nvdb_putf(b, map + PNANOVDB_MAP_OFF_INVMATF + 16 * k, (float)(1.0 / h));
        nvdb_putf(b, map + PNANOVDB_MAP_OFF_VECF + 4 * k, (float)o[k]);
        nvdb_putd(b, map + PNANOVDB_MAP_OFF_MATD + 32 * k, h);
        nvdb_putd(b, map + PNANOVDB_MAP_OFF_INVMATD + 32 * k, 1.0 / h);
        nvdb_putd(b, map + PNANOVDB_MAP_OFF_VECD + 8 * k, o[k]);
        /* world bounds of the voxels' cubes, as NanoVDB's builder gives them */
        nvdb_putd(b, PNANOVDB_GRID_OFF_WORLD_BBOX + 8 * k, o[k] - 0.5 * h);
        nvdb_putd(b, PNANOVDB_GRID_OFF_WORLD_BBOX + 24 + 8 * k, o[k] + 7.5 * h);
        nvdb_putd(b, PNANOVDB_GRID_OFF_VOXEL_SIZE + 8 * k, h);
    }
    nvdb_putf(b, map + PNANOVDB_MAP_OFF_TAPERF, 1.0f);
    nvdb_putd(b, map + PNANOVDB_MAP_OFF_TAPERD, 1.0);
    nvdb_put32(b, PNANOVDB_GRID_OFF_GRID_CLASS, PNANOVDB_GRID_CLASS_FOG_VOLUME);
    nvdb_put32(b, PNANOVDB_GRID_OFF_GRID_TYPE, PNANOVDB_GRID_TYPE_FLOAT);
    /* tree: offsets from the tree to each level's first node */
    nvdb_put64(b, tree + PNANOVDB_TREE_OFF_NODE_OFFSET_LEAF, leaf - tree);
    nvdb_put64(b, tree + PNANOVDB_TREE_OFF_NODE_OFFSET_LOWER, lower - tree);
    nvdb_put64(b, tree + PNANOVDB_TREE_OFF_NODE_OFFSET_UPPER, upper - tree);
    nvdb_put64(b, tree + PNANOVDB_TREE_OFF_NODE_OFFSET_ROOT, root - tree);
    for (int k = 0; k < 3; k++)
        nvdb_put32(b, tree + PNANOVDB_TREE_OFF_NODE_COUNT_LEAF + 4 * k, 1);
    nvdb_put64(b, tree + PNANOVDB_TREE_OFF_VOXEL_COUNT, 512);
    /* root: bounds, one tile (key of (0,0,0) is 0) whose child is the upper node */
    for (int k = 0; k < 3; k++)
        nvdb_put32(b, root + PNANOVDB_ROOT_OFF_BBOX_MAX + 4 * k, 7);
    nvdb_put32(b, root + PNANOVDB_ROOT_OFF_TABLE_SIZE, 1);
    nvdb_putf(b, root + c->root_off_min, lo);
    nvdb_putf(b, root + c->root_off_max, hi);
    nvdb_put64(b, root + c->root_size + PNANOVDB_ROOT_TILE_OFF_CHILD, upper - root);
    /* upper and lower nodes: child 0, offsets from the node */
    size_t node[2] = {upper, lower}, child[2] = {lower, leaf};
    size_t mask[2] = {PNANOVDB_UPPER_OFF_CHILD_MASK, PNANOVDB_LOWER_OFF_CHILD_MASK};
    size_t table[2] = {c->upper_off_table, c->lower_off_table};
    size_t off_min[2] = {c->upper_off_min, c->lower_off_min};
    for (int n = 0; n < 2; n++) {
        for (int k = 0; k < 3; k++)
            nvdb_put32(b, node[n] + PNANOVDB_UPPER_OFF_BBOX_MAX + 4 * k, 7);
        nvdb_put32(b, node[n] + mask[n], 1);
        nvdb_putf(b, node[n] + off_min[n], lo);
        nvdb_putf(b, node[n] + off_min[n] + 4, hi);
        nvdb_put64(b, node[n] + table[n], child[n] - node[n]);
    }
    /* leaf: bbox (0,0,0) + (7,7,7), all voxels active, values x-major */
    nvdb_put32(b, leaf + PNANOVDB_LEAF_OFF_BBOX_DIF_AND_FLAGS, 7u | 7u << 8 | 7u << 16);
    for (int k = 0; k < 16; k++)
        nvdb_put32(b, leaf + PNANOVDB_LEAF_OFF_VALUE_MASK + 4 * k, 0xffffffffu);
    nvdb_putf(b, leaf + c->leaf_off_min, lo);
    nvdb_putf(b, leaf + c->leaf_off_max, hi);
    for (int i = 0; i < 512; i++)
        nvdb_putf(b, leaf + c->leaf_off_table + 4 * i, values[i >> 6][i >> 3 & 7][i & 7]);
    return b;
}

/* IO.h's stringHash of a grid name. */
static uint64_t nvdb_name_hash(const char *s)
{
    uint64_t hash = 0;
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        uint64_t overflow = hash >> 56;
        hash = hash * 67 + *p + overflow;
    }
    return hash;
}

/* Writes path: one segment of one uncompressed grid. Returns 0 or -1. */
static int nvdb_write(const char *path, const char *name, const float values[8][8][8], double h,
                      const double o[3])
{
    size_t size, name_size = strlen(name) + 1;
    unsigned char *grid = nvdb_grid(name, values, h, o, &size);
    unsigned char head[16 + 176] = {0};
    if (!grid)
        return -1;
    nvdb_put64(head, 0, PNANOVDB_MAGIC_NUMBER);
    memcpy(head + 8, grid + PNANOVDB_GRID_OFF_VERSION, 4);
    head[12] = 1; /* grid count; codec 0 (none) */
    unsigned char *m = head + 16;
    nvdb_put64(m, 0, size); /* in memory */
    nvdb_put64(m, 8, size); /* on disk */
    nvdb_put64(m, 16, nvdb_name_hash(name));
    nvdb_put64(m, 24, 512);
    nvdb_put32(m, 32, PNANOVDB_GRID_TYPE_FLOAT);
    nvdb_put32(m, 36, PNANOVDB_GRID_CLASS_FOG_VOLUME);
    memcpy(m + 40, grid + PNANOVDB_GRID_OFF_WORLD_BBOX, 48);
    for (int k = 0; k < 3; k++)
        nvdb_put32(m, 100 + 4 * k, 7); /* index bounds (0,0,0) to (7,7,7) */
    memcpy(m + 112, grid + PNANOVDB_GRID_OFF_VOXEL_SIZE, 24);
    nvdb_put32(m, 136, (uint32_t)name_size);
    for (int k = 0; k < 4; k++)
        nvdb_put32(m, 140 + 4 * k, 1); /* nodes per level, root last */
    memcpy(m + 172, grid + PNANOVDB_GRID_OFF_VERSION, 4);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(head, 1, sizeof head, f) == sizeof head &&
             fwrite(name, 1, name_size, f) == name_size && fwrite(grid, 1, size, f) == size;
    ok = f && fclose(f) == 0 && ok;
    free(grid);
    return ok ? 0 : -1;
}

#endif /* RAYES_TEST_NVDB_WRITE_H */
