/*
 * tests/fuzz/fuzz_rib.c — a libFuzzer target for the RIB reader of
 * io/rib.h (ASCII and binary RIB, gzip buffers): every input is parsed
 * into a fresh scene through the scene sink, which is then released. The
 * buffer is not NUL-terminated, so AddressSanitizer catches any read past
 * the end; a successful parse must leave an empty error message, a failed
 * one a one-line message. Archives are looked up beside "fuzz.rib" (the
 * working directory) and Geometry "teapot" is skipped (no data directory).
 *
 * Build: tests/fuzz/CMakeLists.txt (clang, -DRAYES_FUZZ=ON). Run:
 *   fuzz_rib -max_total_time=300 CORPUS_COPY_DIR
 * with a copy of tests/fuzz/corpus_rib/ as the corpus.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "rayes/rayes.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    RayesScene *scene = rayes_scene_new();
    if (!scene)
        return 0;
    char err[512];
    err[0] = '\0';
    IoSink sink = io_sink_scene(scene);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    RayesError e = io_rib_parse("fuzz.rib", data, size, &sink, &opt, &settings, err, sizeof err);
    if (e == RAYES_OK && err[0] != '\0')
        abort();
    if (e != RAYES_OK && (err[0] == '\0' || strchr(err, '\n') != NULL))
        abort();
    if (e == RAYES_OK)
        (void)rayes_scene_commit(scene); /* a scene the API refuses is not a reader bug */
    rayes_scene_release(scene);
    return 0;
}
