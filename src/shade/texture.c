/*
 * shade/texture.c — texture.h for the renderer: a texture system that
 * loads OpenImageIO (the module librayes_oiio.so, oiio/texture.cpp) on its
 * first lookup, and an image reader that loads it on first use
 * (texture_module.h says why).
 *
 * The module is looked for, in order: as $RAYES_OIIO_MODULE names it;
 * beside the running program (/proc/self/exe); where the build put it; and
 * on the loader's path. When it cannot be loaded, one warning says why and
 * every lookup fails as a missing texture does (black, alpha 1).
 *
 * Thread-safety: the module is loaded once (pthread_once); each system
 * makes its OpenImageIO system once, under its mutex, and the lookups
 * after that are the module's (thread-safe).
 */
#include "shade/texture.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "shade/texture_module.h"
#include "util/log.h"

struct TextureSystem {
    char *search_path;        /* owned; NULL: none */
    uint64_t budget;
    float width;
    pthread_mutex_t lock;     /* guards making impl */
    void *_Atomic impl;       /* the module's system, once made */
    atomic_int failed;        /* the module or its system could not be made */
};

static pthread_once_t module_once = PTHREAD_ONCE_INIT;
static const TextureModule *module;

static void module_warning(const char *message)
{
    log_warning("%s", message);
}

/* dlopen of path, or NULL with the reason appended to why. */
static void *try_open(const char *path, char *why, size_t size)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        size_t used = strlen(why);
        const char *e = dlerror();
        snprintf(why + used, size - used, "%s%s", used ? "; " : "", e ? e : path);
    }
    return h;
}

static void load_module(void)
{
    char why[2048] = "", path[PATH_MAX + 64];
    void *h = NULL;
    const char *env = getenv("RAYES_OIIO_MODULE");
    if (env && env[0])
        h = try_open(env, why, sizeof why);
    if (!h) {
        ssize_t n = readlink("/proc/self/exe", path, PATH_MAX);
        if (n > 0) {
            path[n] = '\0';
            char *slash = strrchr(path, '/');
            if (slash) {
                snprintf(slash + 1, sizeof path - (size_t)(slash + 1 - path), "%s",
                         TEXTURE_MODULE_FILE);
                if (access(path, R_OK) == 0)
                    h = try_open(path, why, sizeof why);
            }
        }
    }
#ifdef RAYES_OIIO_MODULE_BUILD
    if (!h && access(RAYES_OIIO_MODULE_BUILD, R_OK) == 0)
        h = try_open(RAYES_OIIO_MODULE_BUILD, why, sizeof why);
#endif
    if (!h)
        h = try_open(TEXTURE_MODULE_FILE, why, sizeof why);
    TextureModuleEntry entry = NULL;
    if (h) {
        *(void **)&entry = dlsym(h, TEXTURE_MODULE_ENTRY);
        if (!entry) {
            const char *e = dlerror();
            snprintf(why, sizeof why, "%s", e ? e : "no " TEXTURE_MODULE_ENTRY);
        }
    }
    const TextureModule *m = entry ? entry() : NULL;
    if (m && m->version != TEXTURE_MODULE_VERSION) {
        snprintf(why, sizeof why, "version %u, expected %u", (unsigned)m->version,
                 (unsigned)TEXTURE_MODULE_VERSION);
        m = NULL;
    }
    if (!m) {
        log_warning("textures: OpenImageIO's module %s cannot be loaded (%s); textures and "
                    "environment maps are unavailable",
                    TEXTURE_MODULE_FILE, why);
        return;
    }
    m->set_warning(module_warning);
    module = m;
}

static const TextureModule *get_module(void)
{
    pthread_once(&module_once, load_module);
    return module;
}

TextureSystem *texture_system_new(const char *search_path, uint64_t budget_bytes, float width)
{
    TextureSystem *ts = calloc(1, sizeof *ts);
    if (!ts)
        return NULL;
    if (search_path && !(ts->search_path = strdup(search_path))) {
        free(ts);
        return NULL;
    }
    ts->budget = budget_bytes;
    ts->width = width;
    pthread_mutex_init(&ts->lock, NULL);
    atomic_init(&ts->impl, NULL);
    atomic_init(&ts->failed, 0);
    return ts;
}

void texture_system_free(TextureSystem *ts)
{
    if (!ts)
        return;
    void *impl = atomic_load(&ts->impl);
    if (impl)
        module->system_free(impl);
    pthread_mutex_destroy(&ts->lock);
    free(ts->search_path);
    free(ts);
}

/* The module's system, made on first use; NULL when it cannot be. */
static void *impl_of(TextureSystem *ts)
{
    void *impl = atomic_load(&ts->impl);
    if (impl || atomic_load(&ts->failed))
        return impl;
    pthread_mutex_lock(&ts->lock);
    impl = atomic_load(&ts->impl);
    if (!impl && !atomic_load(&ts->failed)) {
        const TextureModule *m = get_module();
        impl = m ? m->system_new(ts->search_path, ts->budget, ts->width) : NULL;
        if (impl)
            atomic_store(&ts->impl, impl);
        else
            atomic_store(&ts->failed, 1);
    }
    pthread_mutex_unlock(&ts->lock);
    return impl;
}

int texture_lookup(TextureSystem *ts, const char *name, size_t n, const float *s, const float *t,
                   const float *ds, const float *dt, float (*rgb)[3], float *alpha)
{
    return texture_lookup_encoded(ts, name, NULL, TEXTURE_WRAP_REPEAT, n, s, t, ds, dt, rgb, alpha);
}

int texture_lookup_encoded(TextureSystem *ts, const char *name, const char *encoding,
                           TextureWrap wrap, size_t n, const float *s, const float *t,
                           const float *ds, const float *dt, float (*rgb)[3], float *alpha)
{
    void *impl = impl_of(ts);
    if (impl)
        return module->lookup(impl, name, encoding, wrap, n, s, t, ds, dt, rgb, alpha);
    memset(rgb, 0, n * sizeof *rgb);
    for (size_t i = 0; alpha && i < n; i++)
        alpha[i] = 1.0f;
    return -1;
}

int texture_channels(TextureSystem *ts, const char *name, const char *encoding)
{
    void *impl = impl_of(ts);
    return impl ? module->channels(impl, name, encoding) : 0;
}

void texture_get_stats(TextureSystem *ts, TextureStats *stats)
{
    void *impl = atomic_load(&ts->impl);
    if (impl) {
        module->get_stats(impl, stats);
        return;
    }
    memset(stats, 0, sizeof *stats);
    stats->budget_bytes = ts->budget;
}

int texture_read_image(const char *path, int *w, int *h, float **rgba, char *err, size_t err_size)
{
    const TextureModule *m = get_module();
    if (!m) {
        *rgba = NULL;
        snprintf(err, err_size, "%s: OpenImageIO's module %s cannot be loaded", path,
                 TEXTURE_MODULE_FILE);
        return -1;
    }
    return m->read_image(path, w, h, rgba, err, err_size);
}
