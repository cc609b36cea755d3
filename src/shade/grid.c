/*
 * shade/grid.c — voxel grids of density (grid.h): pbrt-v4's uniform grid
 * and NanoVDB float grids.
 *
 * A NanoVDB file (nanovdb/util/IO.h, format 32.x) is a sequence of
 * segments: a 16-byte header (magic "NanoVDB0", version, grid count,
 * codec), then per grid 176 bytes of metadata and its name, then the grids'
 * buffers one after another, each as in memory when the codec is none.
 * Metadata and header are little-endian and read here byte by byte; the
 * grid buffer is copied whole into 8-byte aligned memory and read through
 * PNanoVDB.h with bounds checks on (PNANOVDB_BUF_BOUNDS_CHECK), so a damaged
 * grid reads zeros rather than memory beyond it. Values sit at integer
 * index coordinates (NanoVDB's and OpenVDB's convention), and sampling is
 * trilinear as nanovdb::SampleFromVoxels<.., 1> (pbrt-v4's NanoVDBMedium).
 */
#define PNANOVDB_C
#define PNANOVDB_BUF_BOUNDS_CHECK
#include <nanovdb/PNanoVDB.h>

#include "shade/grid.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FILE_HEADER_SIZE 16u
#define FILE_META_SIZE 176u /* IO.h's MetaData */
#define MAX_NAME 256u

struct VoxelGrid {
    int is_nanovdb;
    /* uniform grid */
    size_t res[3];      /* nx, ny, nz */
    float p0[3], p1[3]; /* the box */
    float to_index[3];  /* samples per unit length */
    float *values;      /* nx ny nz, x fastest */
    /* NanoVDB */
    uint32_t *words; /* the grid buffer (8-byte aligned) */
    uint32_t type;   /* PNANOVDB_GRID_TYPE_..., one grid_type_scalar accepts */
    pnanovdb_buf_t buf;
    pnanovdb_grid_handle_t grid;
    pnanovdb_root_handle_t root;
};

VoxelGrid *grid_new_dense(const size_t res[3], const float *values, size_t n_values,
                          const float p0[3], const float p1[3], char *err, size_t err_size)
{
    size_t n = 1;
    for (int k = 0; k < 3; k++) {
        if (res[k] == 0 || res[k] > ((size_t)1 << 20) || n > SIZE_MAX / res[k]) {
            snprintf(err, err_size, "the counts nx ny nz must be 1 to 2^20");
            return NULL;
        }
        n *= res[k];
        if (!(p1[k] > p0[k])) {
            snprintf(err, err_size, "the box p0 p1 is empty");
            return NULL;
        }
    }
    if (n_values != n || !values) {
        snprintf(err, err_size, "\"density\" has %zu values, not nx ny nz = %zu", n_values, n);
        return NULL;
    }
    VoxelGrid *g = calloc(1, sizeof *g);
    float *v = malloc(n * sizeof *v);
    if (!g || !v) {
        free(g), free(v);
        snprintf(err, err_size, "out of memory");
        return NULL;
    }
    memcpy(v, values, n * sizeof *v);
    g->values = v;
    for (int k = 0; k < 3; k++) {
        g->res[k] = res[k];
        g->p0[k] = p0[k];
        g->p1[k] = p1[k];
        g->to_index[k] = (float)res[k] / (p1[k] - p0[k]);
    }
    return g;
}

/* ------------------------------------------------------------ NanoVDB */

static uint64_t le64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--)
        v = v << 8 | b[k];
    return v;
}

static uint32_t le32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* One grid's metadata: what finding and copying it needs. */
typedef struct GridMeta {
    uint64_t grid_size, file_size; /* bytes in memory, on disk */
    uint32_t type;                 /* PNANOVDB_GRID_TYPE_... */
    char name[MAX_NAME];
} GridMeta;

/* The metadata at data[*at] into m; advances *at. -1 if truncated. */
static int read_meta(const unsigned char *data, size_t size, size_t *at, GridMeta *m)
{
    if (size - *at < FILE_META_SIZE)
        return -1;
    const unsigned char *b = data + *at;
    m->grid_size = le64(b);
    m->file_size = le64(b + 8);
    m->type = le32(b + 32);
    uint32_t name_size = le32(b + 136);
    *at += FILE_META_SIZE;
    if (size - *at < name_size)
        return -1;
    size_t len = strnlen((const char *)data + *at, name_size);
    if (len >= MAX_NAME)
        len = MAX_NAME - 1;
    for (size_t k = 0; k < len; k++) { /* names reach one-line messages */
        unsigned char ch = data[*at + k];
        m->name[k] = ch >= 0x20 && ch < 0x7f ? (char)ch : '?';
    }
    m->name[len] = '\0';
    *at += name_size;
    return 0;
}

/* The NanoVDB grid types read as a scalar density: 1 if type is one. */
static int grid_type_scalar(uint32_t type)
{
    switch (type) {
    case PNANOVDB_GRID_TYPE_FLOAT:
    case PNANOVDB_GRID_TYPE_DOUBLE:
    case PNANOVDB_GRID_TYPE_HALF:
    case PNANOVDB_GRID_TYPE_FP4:
    case PNANOVDB_GRID_TYPE_FP8:
    case PNANOVDB_GRID_TYPE_FP16:
    case PNANOVDB_GRID_TYPE_FPN:
        return 1;
    default:
        return 0;
    }
}

/* A grid of that type made from the bytes of one grid; NULL with err
 * filled if its structure cannot be that grid's. */
static VoxelGrid *make_nanovdb(const unsigned char *bytes, uint64_t size, uint32_t type,
                               const char *path, const char *name, char *err, size_t err_size)
{
    if (size < PNANOVDB_GRID_SIZE + PNANOVDB_TREE_SIZE || size > ((uint64_t)1 << 40)) {
        snprintf(err, err_size, "%s: grid \"%s\" has an impossible size (%llu bytes)", path, name,
                 (unsigned long long)size);
        return NULL;
    }
    VoxelGrid *g = calloc(1, sizeof *g);
    uint64_t *aligned = malloc((size_t)(size + 7) / 8 * 8);
    if (!g || !aligned) {
        free(g), free(aligned);
        snprintf(err, err_size, "%s: out of memory", path);
        return NULL;
    }
    memcpy(aligned, bytes, (size_t)size);
    g->is_nanovdb = 1;
    g->type = type;
    g->words = (uint32_t *)aligned;
    g->buf = pnanovdb_make_buf(g->words, size / 4);
    g->grid.address.byte_offset = 0;
    pnanovdb_tree_handle_t tree = pnanovdb_grid_get_tree(g->buf, g->grid);
    g->root = pnanovdb_tree_get_root(g->buf, tree);
    uint64_t root_at = g->root.address.byte_offset;
    uint64_t tiles = pnanovdb_root_get_tile_count(g->buf, g->root);
    const char *why = NULL;
    if (pnanovdb_grid_get_magic(g->buf, g->grid) != PNANOVDB_MAGIC_NUMBER)
        why = "the grid's magic number is wrong";
    else if (pnanovdb_grid_get_grid_type(g->buf, g->grid) != type)
        why = "the grid's type disagrees with its metadata";
    else if (root_at >= size || tiles > (size - root_at) / PNANOVDB_ROOT_TILE_BASE_SIZE)
        why = "its root node lies beyond the grid";
    if (why) {
        snprintf(err, err_size, "%s: grid \"%s\" is damaged (%s)", path, name, why);
        grid_free(g);
        return NULL;
    }
    return g;
}

/* The grid m describes, whose bytes on disk start at data (size bytes to
 * the file's end), if it is an uncompressed scalar grid; else NULL with
 * err filled. */
static VoxelGrid *open_grid(const GridMeta *m, unsigned codec, const unsigned char *data,
                            size_t size, const char *path, char *err, size_t err_size)
{
    if (codec != 0) {
        snprintf(err, err_size,
                 "%s: grid \"%s\" is compressed (%s); rayes reads uncompressed files "
                 "(nanovdb_convert without -z or -b)",
                 path, m->name,
                 codec == 1   ? "zip"
                 : codec == 2 ? "blosc"
                              : "unknown codec");
    } else if (!grid_type_scalar(m->type)) {
        snprintf(err, err_size,
                 "%s: grid \"%s\" is not a scalar grid (NanoVDB type %u; rayes reads float, "
                 "half, double, Fp4, Fp8, Fp16 and FpN)",
                 path, m->name, m->type);
    } else if (m->file_size != m->grid_size || m->file_size > size) {
        snprintf(err, err_size, "%s: truncated NanoVDB file (grid \"%s\")", path, m->name);
    } else {
        return make_nanovdb(data, m->grid_size, m->type, path, m->name, err, err_size);
    }
    return NULL;
}

#define NO_GRID "no grid " /* the message of a grid that is not in the file */

VoxelGrid *grid_parse_nanovdb(const unsigned char *data, size_t size, const char *name,
                              const char *path, char *err, size_t err_size)
{
    size_t at = 0;
    char names[160] = "";
    while (at < size) {
        if (size - at < FILE_HEADER_SIZE) {
            snprintf(err, err_size, "%s: truncated NanoVDB file (a header of %zu bytes)", path,
                     size - at);
            return NULL;
        }
        uint64_t magic = le64(data + at);
        uint32_t major = le32(data + at + 8) >> 21 & 0x7ffu;
        unsigned count = (unsigned)data[at + 12] | (unsigned)data[at + 13] << 8;
        unsigned codec = (unsigned)data[at + 14] | (unsigned)data[at + 15] << 8;
        if (magic != PNANOVDB_MAGIC_NUMBER) {
            snprintf(err, err_size, "%s: not a NanoVDB file (wrong magic number)", path);
            return NULL;
        }
        if (major != PNANOVDB_MAJOR_VERSION_NUMBER) {
            snprintf(err, err_size, "%s: NanoVDB file format %u, rayes reads %d", path, major,
                     PNANOVDB_MAJOR_VERSION_NUMBER);
            return NULL;
        }
        at += FILE_HEADER_SIZE;
        GridMeta *meta = calloc(count ? count : 1, sizeof *meta);
        if (!meta) {
            snprintf(err, err_size, "%s: out of memory", path);
            return NULL;
        }
        for (unsigned k = 0; k < count; k++)
            if (read_meta(data, size, &at, &meta[k]) != 0) {
                free(meta);
                snprintf(err, err_size, "%s: truncated NanoVDB file (grid metadata)", path);
                return NULL;
            }
        int done = 0;
        VoxelGrid *g = NULL;
        for (unsigned k = 0; k < count && !done; k++) {
            const GridMeta *m = &meta[k];
            done = strcmp(m->name, name) == 0 || m->file_size > size - at;
            if (strcmp(m->name, name) == 0) {
                g = open_grid(m, codec, data + at, size - at, path, err, err_size);
            } else if (done) {
                snprintf(err, err_size, "%s: truncated NanoVDB file (grid \"%s\")", path, m->name);
            } else {
                size_t used = strlen(names);
                if (snprintf(names + used, sizeof names - used, "%s\"%s\"", used ? ", " : "",
                             m->name) >= (int)(sizeof names - used))
                    names[used] = '\0'; /* a name the list has no room for is left out */
                at += (size_t)m->file_size;
            }
        }
        free(meta);
        if (done)
            return g;
    }
    snprintf(err, err_size, "%s: " NO_GRID "\"%s\" (the file has %s)", path, name,
             names[0] ? names : "no grids");
    return NULL;
}

int grid_error_missing(const char *err)
{
    return err && strstr(err, ": " NO_GRID "\"") != NULL;
}

VoxelGrid *grid_read_nanovdb(const char *path, const char *name, char *err, size_t err_size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open", path);
        return NULL;
    }
    unsigned char *data = NULL;
    size_t size = 0, cap = 0;
    for (;;) {
        if (size == cap) {
            size_t grown = cap ? 2 * cap : 1 << 16;
            unsigned char *d = realloc(data, grown);
            if (!d) {
                free(data);
                fclose(f);
                snprintf(err, err_size, "%s: out of memory", path);
                return NULL;
            }
            data = d, cap = grown;
        }
        size_t got = fread(data + size, 1, cap - size, f);
        size += got;
        if (got == 0)
            break;
    }
    int bad = ferror(f);
    fclose(f);
    VoxelGrid *g = NULL;
    if (bad)
        snprintf(err, err_size, "%s: read error", path);
    else
        g = grid_parse_nanovdb(data, size, name, path, err, err_size);
    free(data);
    return g;
}

/* ------------------------------------------------------------ sampling */

static float dense_at(const VoxelGrid *g, long x, long y, long z)
{
    if (x < 0 || y < 0 || z < 0 || (size_t)x >= g->res[0] || (size_t)y >= g->res[1] ||
        (size_t)z >= g->res[2])
        return 0.0f;
    return g->values[((size_t)z * g->res[1] + (size_t)y) * g->res[0] + (size_t)x];
}

static float nano_at(const VoxelGrid *g, pnanovdb_readaccessor_t *acc, long x, long y, long z)
{
    pnanovdb_coord_t ijk = {(int32_t)x, (int32_t)y, (int32_t)z};
    pnanovdb_uint32_t level;
    pnanovdb_address_t a =
        pnanovdb_readaccessor_get_value_address_and_level(g->type, g->buf, acc, &ijk, &level);
    switch (g->type) { /* quantized leaves decode; their tiles are floats */
    case PNANOVDB_GRID_TYPE_DOUBLE:
        return (float)pnanovdb_read_double(g->buf, a);
    case PNANOVDB_GRID_TYPE_HALF:
        return pnanovdb_read_half(g->buf, a);
    case PNANOVDB_GRID_TYPE_FP4:
        return pnanovdb_root_fp4_read_float(g->buf, a, &ijk, level);
    case PNANOVDB_GRID_TYPE_FP8:
        return pnanovdb_root_fp8_read_float(g->buf, a, &ijk, level);
    case PNANOVDB_GRID_TYPE_FP16:
        return pnanovdb_root_fp16_read_float(g->buf, a, &ijk, level);
    case PNANOVDB_GRID_TYPE_FPN:
        return pnanovdb_root_fpn_read_float(g->buf, a, &ijk, level);
    default:
        return pnanovdb_read_float(g->buf, a);
    }
}

/* Trilinear from the eight values around index point q (values at
 * integer coordinates); 0 for points too far out to index. */
static float trilinear(const VoxelGrid *g, pnanovdb_readaccessor_t *acc, const float q[3])
{
    const float far = 1e9f;
    if (!(fabsf(q[0]) < far && fabsf(q[1]) < far && fabsf(q[2]) < far))
        return 0.0f;
    long i[3];
    float f[3], v[8];
    for (int k = 0; k < 3; k++) {
        float fl = floorf(q[k]);
        i[k] = (long)fl;
        f[k] = q[k] - fl;
    }
    for (int c = 0; c < 8; c++) {
        long x = i[0] + (c & 1), y = i[1] + (c >> 1 & 1), z = i[2] + (c >> 2);
        v[c] = acc ? nano_at(g, acc, x, y, z) : dense_at(g, x, y, z);
    }
    for (int c = 0; c < 4; c++) /* along x, then y, then z */
        v[c] = v[2 * c] + f[0] * (v[2 * c + 1] - v[2 * c]);
    for (int c = 0; c < 2; c++)
        v[c] = v[2 * c] + f[1] * (v[2 * c + 1] - v[2 * c]);
    return v[0] + f[2] * (v[1] - v[0]);
}

void grid_sample(const VoxelGrid *g, size_t n, const float (*p)[3], float *out)
{
    pnanovdb_readaccessor_t acc;
    if (g->is_nanovdb)
        pnanovdb_readaccessor_init(&acc, g->root);
    for (size_t i = 0; i < n; i++) {
        float q[3];
        if (g->is_nanovdb) {
            pnanovdb_vec3_t w = {p[i][0], p[i][1], p[i][2]};
            pnanovdb_vec3_t x = pnanovdb_grid_world_to_indexf(g->buf, g->grid, &w);
            q[0] = x.x, q[1] = x.y, q[2] = x.z;
        } else {
            int inside = 1;
            for (int k = 0; k < 3; k++) { /* pbrt's SampledGrid: centres at (i + 0.5) / n */
                inside &= p[i][k] >= g->p0[k] && p[i][k] <= g->p1[k];
                q[k] = (p[i][k] - g->p0[k]) * g->to_index[k] - 0.5f;
            }
            if (!inside) {
                out[i] = 0.0f;
                continue;
            }
        }
        out[i] = trilinear(g, g->is_nanovdb ? &acc : NULL, q);
    }
}

void grid_free(VoxelGrid *g)
{
    if (!g)
        return;
    free(g->values);
    free(g->words);
    free(g);
}
