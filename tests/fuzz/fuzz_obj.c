/*
 * tests/fuzz/fuzz_obj.c — a libFuzzer target for the OBJ reader of
 * io/obj.h: every input is parsed twice, into a fresh scene (committed
 * when the parse succeeds) and into the RIB writer (io/rib_write.h), whose
 * output goes to /dev/null. The buffer is not NUL-terminated, so
 * AddressSanitizer catches any read past the end; a successful parse must
 * leave an empty error message, a failed one a one-line message naming
 * "fuzz.obj:". An input is the OBJ up to its first NUL byte; what follows
 * is written as m.mtl beside it (in a scratch directory made once), so
 * "mtllib m.mtl" fuzzes the MTL reader too; other names find nothing.
 * The directory is removed at exit.
 *
 * Build and run: make fuzz (tests/fuzz/CMakeLists.txt), seeds in
 * tests/fuzz/corpus_obj/.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/obj.h"
#include "io/rib_write.h"
#include "rayes/rayes.h"

#include <unistd.h>

static char dir[64] = "/tmp/rayes-fuzz-obj-XXXXXX";
static char name[128], mtl[128];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The scratch directory goes when the fuzzer exits (libFuzzer's runs end
 * in exit()), so test runs leave nothing in /tmp. */
static void remove_scratch(void)
{
    unlink(mtl);
    rmdir(dir);
}

static void check_message(RayesError e, const char *err)
{
    if (e == RAYES_OK && err[0] != '\0')
        abort();
    if (e != RAYES_OK && (err[0] == '\0' || strchr(err, '\n') != NULL))
        abort();
    if (e == RAYES_ERROR_PARSE && strncmp(err, dir, strlen(dir)) != 0)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const unsigned char empty[1] = "";
    static FILE *devnull;
    const unsigned char *text = size ? data : empty;
    if (!name[0]) {
        if (!mkdtemp(dir))
            abort();
        snprintf(name, sizeof name, "%s/fuzz.obj", dir);
        snprintf(mtl, sizeof mtl, "%s/m.mtl", dir);
        atexit(remove_scratch);
    }
    const unsigned char *nul = size ? memchr(data, 0, size) : NULL;
    FILE *f = fopen(mtl, "wb");
    if (!f)
        abort();
    if (nul)
        fwrite(nul + 1, 1, size - (size_t)(nul + 1 - data), f);
    fclose(f);
    if (nul)
        size = (size_t)(nul - data);
    char err[512];
    IoSettings settings;
    IoReadOptions ro = {NULL, -1};

    RayesScene *scene = rayes_scene_new();
    if (!scene)
        return 0;
    IoSink sink = io_sink_scene(scene);
    io_settings_init(&settings);
    RayesError e = io_obj_parse(name, text, size, &sink, &ro, &settings, err, sizeof err);
    check_message(e, err);
    if (e == RAYES_OK && rayes_scene_commit(scene) != RAYES_OK)
        abort();
    rayes_scene_release(scene);

    RibWriter *w = io_rib_writer_new();
    if (!w)
        return 0;
    if (!devnull)
        devnull = fopen("/dev/null", "w");
    sink = io_rib_writer_sink(w);
    /* the scene's limit on where geometry may lie (1e18 from the origin)
     * is the renderer's, not the file's: a RIB file may hold it */
    int limit = e != RAYES_OK && strstr(err, "geometry reaches beyond") != NULL;
    RayesError e2 = io_obj_parse(name, text, size, &sink, &ro, &settings, err, sizeof err);
    if ((e == RAYES_OK) != (e2 == RAYES_OK) && !(limit && e2 == RAYES_OK))
        abort(); /* both sinks accept what the reader sends */
    if (e2 == RAYES_OK && devnull && io_rib_writer_finish(w, &settings, devnull, err, sizeof err))
        abort();
    io_rib_writer_free(w);
    return 0;
}
