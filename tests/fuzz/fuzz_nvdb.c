/*
 * tests/fuzz/fuzz_nvdb.c — a libFuzzer target for the NanoVDB reader of
 * shade/grid.h. An input is either a file's bytes, or "EDIT" followed by
 * edits of 5 bytes (a little-endian offset, a byte to XOR there) to the
 * valid grid nvdb_write.h makes (300 KB, too big for a seed), so that
 * mutations reach the tree as well as the header. A failed read must give
 * a one-line message naming the file; a grid read must sample anywhere
 * without reading outside its buffer.
 *
 * Build: tests/fuzz/CMakeLists.txt (clang, -DRAYES_FUZZ=ON). Run:
 *   fuzz_nvdb -max_total_time=300 CORPUS_COPY_DIR
 * with a copy of tests/fuzz/corpus_nvdb/ as the corpus.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "nvdb_write.h"
#include "shade/grid.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The valid file's bytes, made once. */
static unsigned char *valid_file(size_t *size)
{
    static unsigned char *file;
    static size_t file_size;
    if (!file) {
        static float v[8][8][8];
        for (int i = 0; i < 512; i++)
            v[i >> 6][i >> 3 & 7][i & 7] = (float)i;
        const double o[3] = {0, 0, 0};
        const char *path = "fuzz_nvdb_seed.nvdb";
        if (nvdb_write(path, "density", (const float(*)[8][8])v, 1.0, o) != 0)
            abort();
        FILE *f = fopen(path, "rb");
        file = malloc(400000);
        file_size = f && file ? fread(file, 1, 400000, f) : 0;
        if (f)
            fclose(f);
        remove(path);
    }
    *size = file_size;
    return file;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    unsigned char *edited = NULL;
    if (size >= 4 && memcmp(data, "EDIT", 4) == 0) {
        size_t n;
        const unsigned char *base = valid_file(&n);
        edited = malloc(n);
        if (!edited)
            return 0;
        memcpy(edited, base, n);
        for (size_t k = 4; k + 5 <= size; k += 5) {
            uint32_t at = (uint32_t)data[k] | (uint32_t)data[k + 1] << 8 |
                          (uint32_t)data[k + 2] << 16 | (uint32_t)data[k + 3] << 24;
            edited[at % n] ^= data[k + 4];
        }
        data = edited, size = n;
    }
    /* a copy of exactly size bytes, so AddressSanitizer sees reads past the end */
    unsigned char *copy = malloc(size ? size : 1);
    if (!copy)
        abort();
    memcpy(copy, data, size);
    char err[512] = "";
    VoxelGrid *g = grid_parse_nanovdb(copy, size, "density", "fuzz.nvdb", err, sizeof err);
    if (!g) {
        if (strncmp(err, "fuzz.nvdb: ", 11) != 0 || strchr(err, '\n'))
            abort();
    } else {
        float p[64][3], out[64];
        for (int i = 0; i < 64; i++)
            for (int k = 0; k < 3; k++)
                p[i][k] = (float)((i * 7 + k * 13) % 23) - 6.5f + 0.25f * (float)k;
        grid_sample(g, 64, (const float(*)[3])p, out);
        grid_free(g);
    }
    free(copy);
    free(edited);
    return 0;
}
