/*
 * tests/fuzz/fuzz_ply.c — a libFuzzer target for the PLY reader of
 * io/ply.h. The buffer is not NUL-terminated, so AddressSanitizer catches
 * any read past the end; a successful parse must give faces of 3 or 4
 * vertices whose indices are in range, a failed one a one-line message.
 *
 * Build: tests/fuzz/CMakeLists.txt (clang, -DRAYES_FUZZ=ON). Run:
 *   fuzz_ply -max_total_time=300 CORPUS_COPY_DIR
 * with a copy of tests/fuzz/corpus_ply/ as the corpus.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/ply.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    PlyMesh m;
    char err[512];
    err[0] = '\0';
    RayesError e = io_ply_parse("fuzz.ply", data, size, &m, err, sizeof err);
    if (e != RAYES_OK) {
        if (err[0] == '\0' || strchr(err, '\n') != NULL || m.P != NULL)
            abort();
        return 0;
    }
    size_t k = 0;
    for (size_t f = 0; f < m.n_faces; f++) {
        if (m.n_verts[f] != 3 && m.n_verts[f] != 4)
            abort();
        for (int i = 0; i < m.n_verts[f]; i++, k++)
            if (m.indices[k] < 0 || (size_t)m.indices[k] >= m.n_vertices)
                abort();
    }
    if (k != m.n_indices)
        abort();
    io_ply_mesh_fini(&m);
    return 0;
}
