/*
 * tests/fuzz/fuzz_bpt.c — a libFuzzer target for the Bezier patch reader
 * of io/bpt.h: every input is parsed into a fresh scene, which is then
 * released. The buffer is not NUL-terminated (libFuzzer's data ends at
 * size), so AddressSanitizer catches any read past the end; a successful
 * parse must leave an empty error message, a failed one a one-line message.
 *
 * Build: tests/fuzz/CMakeLists.txt (clang, -DRAYES_FUZZ=ON). Run:
 *   fuzz_bpt -max_total_time=300 CORPUS_COPY_DIR
 * with a copy of tests/fuzz/corpus_bpt/ as the corpus.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/bpt.h"
#include "rayes/rayes.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    RayesScene *scene = rayes_scene_new();
    if (!scene)
        return 0;
    char err[512];
    err[0] = '\0';
    static const char empty[1] = "";
    const char *text = size ? (const char *)data : empty;
    IoSink sink = io_sink_scene(scene);
    RayesError e = io_parse_bpt("fuzz.bpt", text, size, &sink, err, sizeof err);
    if (e == RAYES_OK && err[0] != '\0')
        abort();
    if (e != RAYES_OK && (err[0] == '\0' || strchr(err, '\n') != NULL))
        abort();
    if (e == RAYES_OK && rayes_scene_commit(scene) != RAYES_OK)
        abort();
    rayes_scene_release(scene);
    return 0;
}
