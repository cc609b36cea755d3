/*
 * shade/plugin.c — loading shader classes from shared objects, and the
 * process-wide registry of those loaded (plugin.h).
 *
 * The registry is a singly linked list behind one mutex; loads are rare
 * (a scene's set_shader calls), lookups by the renderer never come here
 * (instances hold their class pointer). Entries and their handles are
 * never freed: a class must outlive every instance made of it, and
 * instances may live in scenes the registry cannot see.
 */
#include "shade/plugin.h"

#include <dlfcn.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "shade/shade.h"

typedef struct Plugin {
    char *path;                    /* real path of the file, owned */
    void *handle;                  /* dlopen handle, never closed */
    const RayesShaderClass *cls;   /* the checked class */
    struct Plugin *next;
} Plugin;

static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;
static Plugin *registry;           /* guarded by registry_lock */

/* Bytes a parameter of that type occupies in cls, or 0 for an unknown type. */
static size_t param_bytes(const RayesShaderClass *cls, RayesParamType type)
{
    switch (type) {
    case RAYES_PARAM_FLOAT:
        return sizeof(float);
    case RAYES_PARAM_COLOR:
        return 3 * sizeof(float);
    case RAYES_PARAM_STRING:
        return shade_string_bytes(cls);
    default:
        return 0;
    }
}

static int check_param(const RayesShaderClass *cls, size_t i, char *err, size_t err_size)
{
    const RayesShaderParamDesc *d = &cls->params[i];
    if (!d->name || d->name[0] == '\0' || strlen(d->name) > 255) {
        snprintf(err, err_size, "parameter %zu has no name (or an absurd one)", i);
        return -1;
    }
    size_t bytes = param_bytes(cls, d->type);
    if (bytes == 0) {
        snprintf(err, err_size, "parameter \"%s\" has unknown type %d; expected float, color or "
                 "string", d->name, (int)d->type);
        return -1;
    }
    if (d->offset > cls->params_size || bytes > cls->params_size - d->offset) {
        snprintf(err, err_size,
                 "parameter \"%s\" lies outside the parameter block (offset %zu + %zu bytes, "
                 "params_size %zu)",
                 d->name, d->offset, bytes, cls->params_size);
        return -1;
    }
    if (d->type != RAYES_PARAM_STRING && d->offset % _Alignof(float) != 0) {
        snprintf(err, err_size, "parameter \"%s\" has offset %zu, not aligned for floats",
                 d->name, d->offset);
        return -1;
    }
    int n = d->type == RAYES_PARAM_COLOR ? 3 : d->type == RAYES_PARAM_FLOAT ? 1 : 0;
    for (int k = 0; k < n; k++)
        if (!isfinite(d->default_value[k])) {
            snprintf(err, err_size, "parameter \"%s\" has a non-finite default", d->name);
            return -1;
        }
    for (size_t j = 0; j < i; j++)
        if (strcmp(cls->params[j].name, d->name) == 0) {
            snprintf(err, err_size, "parameter \"%s\" is listed twice", d->name);
            return -1;
        }
    return 0;
}

int shade_plugin_check_class(const RayesShaderClass *cls, const char *name, char *err,
                             size_t err_size)
{
    if (!cls) {
        snprintf(err, err_size, "%s returned no class (NULL)", RAYES_SHADER_ENTRY_NAME);
        return -1;
    }
    /* abi_version is the first member in every version: read it before anything else. */
    if (cls->abi_version != RAYES_SHADER_ABI_VERSION) {
        snprintf(err, err_size, "shader ABI version %u, this renderer needs %u",
                 (unsigned)cls->abi_version, (unsigned)RAYES_SHADER_ABI_VERSION);
        return -1;
    }
    if (cls->struct_size < sizeof(RayesShaderClass) || cls->struct_size > PLUGIN_MAX_STRUCT_SIZE) {
        snprintf(err, err_size, "class struct_size %u, expected at least %zu",
                 (unsigned)cls->struct_size, sizeof(RayesShaderClass));
        return -1;
    }
    if (!cls->name || strcmp(cls->name, name) != 0) {
        snprintf(err, err_size, "the class is named \"%.64s\", expected \"%.64s\" (the file's name)",
                 cls->name ? cls->name : "(null)", name);
        return -1;
    }
    if (!cls->lighting) {
        snprintf(err, err_size, "class \"%s\" has no lighting method (required)", name);
        return -1;
    }
    if (shade_class_flags(cls) & SHADE_CLASS_CHILDREN) { /* rayes' own bit: a built-in mix */
        snprintf(err, err_size, "class \"%s\" sets flag bit 31, which is rayes' own", name);
        return -1;
    }
    if (cls->params_size > PLUGIN_MAX_PARAMS_SIZE || cls->scratch_size > PLUGIN_MAX_SCRATCH_SIZE) {
        snprintf(err, err_size, "class \"%s\" has params_size %zu and scratch_size %zu; at most "
                 "%u and %u bytes are allowed", name, cls->params_size, cls->scratch_size,
                 PLUGIN_MAX_PARAMS_SIZE, PLUGIN_MAX_SCRATCH_SIZE);
        return -1;
    }
    if (cls->n_params && !cls->params) {
        snprintf(err, err_size, "class \"%s\" has n_params %zu but no parameter table", name,
                 cls->n_params);
        return -1;
    }
    if (cls->n_params > 4096) {
        snprintf(err, err_size, "class \"%s\" has n_params %zu; at most 4096", name,
                 cls->n_params);
        return -1;
    }
    for (size_t i = 0; i < cls->n_params; i++)
        if (check_param(cls, i, err, err_size) != 0)
            return -1;
    return 0;
}

/* dlerror's message without the file name it usually starts with. */
static const char *dl_reason(const char *path)
{
    const char *e = dlerror();
    if (!e)
        return "unknown dlopen error";
    size_t n = strlen(path);
    if (strncmp(e, path, n) == 0 && strncmp(e + n, ": ", 2) == 0)
        return e + n + 2;
    return e;
}

/* Opens and checks the file; called with registry_lock held. */
static const RayesShaderClass *load_locked(const char *path, const char *real, const char *name,
                                           char *err, size_t err_size)
{
    for (Plugin *p = registry; p; p = p->next)
        if (strcmp(p->path, real) == 0) {
            if (strcmp(p->cls->name, name) == 0)
                return p->cls;
            snprintf(err, err_size, "%s: the class is named \"%.64s\", expected \"%.64s\"", path,
                     p->cls->name, name);
            return NULL;
        }
    void *handle = dlopen(real, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        snprintf(err, err_size, "%s: cannot load: %s", path, dl_reason(real));
        return NULL;
    }
    dlerror();
    void *sym = dlsym(handle, RAYES_SHADER_ENTRY_NAME);
    if (!sym) {
        snprintf(err, err_size, "%s: no %s function; not a rayes shader plugin", path,
                 RAYES_SHADER_ENTRY_NAME);
        dlclose(handle);
        return NULL;
    }
    RayesShaderEntry entry;
    memcpy(&entry, &sym, sizeof entry); /* object pointer to function pointer, as POSIX allows */
    const RayesShaderClass *cls = entry();
    char why[384];
    if (shade_plugin_check_class(cls, name, why, sizeof why) != 0) {
        snprintf(err, err_size, "%s: %s", path, why);
        dlclose(handle);
        return NULL;
    }
    Plugin *p = calloc(1, sizeof *p);
    char *copy = strdup(real);
    if (!p || !copy) {
        snprintf(err, err_size, "%s: out of memory", path);
        free(p);
        free(copy);
        dlclose(handle);
        return NULL;
    }
    p->path = copy;
    p->handle = handle;
    p->cls = cls;
    p->next = registry;
    registry = p;
    return cls;
}

const RayesShaderClass *shade_plugin_load(const char *path, const char *name, char *err,
                                          size_t err_size)
{
    char *real = realpath(path, NULL);
    if (!real) {
        snprintf(err, err_size, "%s: cannot open: no such file", path);
        return NULL;
    }
    pthread_mutex_lock(&registry_lock);
    const RayesShaderClass *cls = load_locked(path, real, name, err, err_size);
    pthread_mutex_unlock(&registry_lock);
    free(real);
    return cls;
}

/* Appends text to err at *used, truncating with "..." when full. */
static void append(char *err, size_t err_size, size_t *used, const char *text)
{
    if (*used + 1 >= err_size)
        return;
    int n = snprintf(err + *used, err_size - *used, "%s", text);
    if (n < 0 || (size_t)n >= err_size - *used) {
        *used = err_size - 1;
        if (err_size > 4)
            memcpy(err + err_size - 4, "...", 4);
        return;
    }
    *used += (size_t)n;
}

const RayesShaderClass *shade_plugin_find(const char *name, const char *search_path, char *err,
                                          size_t err_size)
{
    if (!name || name[0] == '\0' || strchr(name, '/') || strlen(name) > 255) {
        snprintf(err, err_size, "unknown shader \"%.64s\": a shader name is a file name without "
                 "\".so\" and without '/'", name ? name : "(null)");
        return NULL;
    }
    const char *dirs = search_path ? search_path : "";
    for (const char *d = dirs; *d;) {
        size_t n = strcspn(d, ":");
        if (n > 0 && n < PATH_MAX) {
            char file[PATH_MAX + 300];
            snprintf(file, sizeof file, "%.*s/%s.so", (int)n, d, name);
            if (access(file, F_OK) == 0)
                return shade_plugin_load(file, name, err, err_size);
        }
        d += n + (d[n] == ':');
    }
    size_t used = 0;
    char head[640];
    snprintf(head, sizeof head, "unknown shader \"%.255s\": not built in, and no %.255s.so in ",
             name, name);
    append(err, err_size, &used, head);
    int any = 0;
    for (const char *d = dirs; *d;) {
        size_t n = strcspn(d, ":");
        if (n > 0) {
            char dir[PATH_MAX];
            snprintf(dir, sizeof dir, "%s%.*s", any ? ", " : "", (int)(n < 4000 ? n : 4000), d);
            append(err, err_size, &used, dir);
            any = 1;
        }
        d += n + (d[n] == ':');
    }
    if (!any)
        append(err, err_size, &used, "the shader search path (it is empty)");
    return NULL;
}
