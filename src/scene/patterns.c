/*
 * scene/patterns.c — the scene's patterns (rayes_scene_pattern) and the
 * binding of shader parameters to them (RAYES_PARAM_PATTERN values of
 * set_shader, set_displacement and edit_shader; DESIGN.md "Patterns"),
 * and finding the texture files the scene reads itself (environment maps).
 *
 * Patterns are named; a name defined again is replaced for later
 * references, while instances and patterns that took the earlier one keep
 * it. Every pattern made lives as long as the scene (renders borrow them
 * through the shader instances that bind them), so nothing dangles when a
 * name is redefined during a progressive session. One editing thread, as
 * for every scene call.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene.h"
#include "shade/pattern.h"

static void set_error(RayesScene *s, const char *msg)
{
    if (s->error[0] == '\0')
        snprintf(s->error, sizeof s->error, "%s", msg);
}

/* The latest pattern of that name, or NULL (a PatternFind). */
static const Pattern *find_pattern(void *data, const char *name)
{
    const RayesScene *s = data;
    for (size_t i = s->n_patterns; i-- > 0;)
        if (strcmp(s->patterns[i].name, name) == 0)
            return s->patterns[i].pattern;
    return NULL;
}

static int params_finite(const RayesParam *q)
{
    if (q->type == RAYES_PARAM_STRING || q->type == RAYES_PARAM_PATTERN)
        return 1;
    if (q->type == RAYES_PARAM_FLOATS) {
        if (q->n_floats && !q->floats)
            return 0;
        for (size_t k = 0; k < q->n_floats; k++)
            if (!isfinite(q->floats[k]))
                return 0;
        return 1;
    }
    return isfinite(q->value[0]) && isfinite(q->value[1]) && isfinite(q->value[2]);
}

/* pattern_new, with nanovdb's "filename" found on the texture search path
 * first (as images are). */
static Pattern *make_pattern(RayesScene *s, const char *type, const RayesParam *params,
                             size_t n_params, const float m[16], char *err, size_t err_size)
{
    if (!type || strcmp(type, "nanovdb") != 0 || n_params > 16)
        return pattern_new(type, params, n_params, m, find_pattern, s, err, err_size);
    RayesParam copy[16];
    char path[1024];
    memcpy(copy, params, n_params * sizeof *params);
    for (size_t i = 0; i < n_params; i++)
        if (copy[i].name && strcmp(copy[i].name, "filename") == 0 &&
            copy[i].type == RAYES_PARAM_STRING && copy[i].string &&
            scene_find_texture(s, copy[i].string, path, sizeof path) == 0)
            copy[i].string = path;
    return pattern_new(type, copy, n_params, m, find_pattern, s, err, err_size);
}

RayesError rayes_scene_pattern(RayesScene *s, const char *name, const char *type,
                               const RayesParam *params, size_t n_params)
{
    if (!s || !name || !name[0] || !type || (n_params && !params))
        return RAYES_ERROR_INVALID_ARGUMENT;
    for (size_t i = 0; i < n_params; i++)
        if (!params_finite(&params[i])) {
            set_error(s, "pattern: a parameter is not finite");
            return RAYES_ERROR_INVALID_ARGUMENT;
        }
    char err[512], msg[sizeof s->error];
    float m[16];
    memcpy(m, s->world_from_object.m, sizeof m);
    Pattern *p = make_pattern(s, type, params, n_params, m, err, sizeof err);
    if (!p) {
        snprintf(msg, sizeof msg, "pattern \"%.64s\": %.420s", name, err);
        set_error(s, msg);
        return strcmp(err, "out of memory") == 0 ? RAYES_ERROR_OUT_OF_MEMORY
                                                 : RAYES_ERROR_INVALID_ARGUMENT;
    }
    if (s->n_patterns == s->cap_patterns) {
        size_t cap = s->cap_patterns ? 2 * s->cap_patterns : 16;
        ScenePattern *grown = realloc(s->patterns, cap * sizeof *grown);
        if (!grown) {
            pattern_free(p);
            set_error(s, "out of memory");
            return RAYES_ERROR_OUT_OF_MEMORY;
        }
        s->patterns = grown;
        s->cap_patterns = cap;
    }
    char *copy = strdup(name);
    if (!copy) {
        pattern_free(p);
        set_error(s, "out of memory");
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    s->patterns[s->n_patterns++] = (ScenePattern){copy, p};
    scene_mark(s, SCENE_CHANGE_SHADING);
    return RAYES_OK;
}

const struct RayesPattern *scene_find_pattern(const RayesScene *s, const char *name)
{
    return name ? find_pattern((void *)s, name) : NULL;
}

RayesError scene_bind_patterns(RayesScene *s, ShaderInstance *inst, const RayesParam *params,
                               size_t n_params)
{
    char err[256], msg[400];
    for (size_t i = 0; i < n_params; i++) {
        if (params[i].type != RAYES_PARAM_PATTERN)
            continue;
        const Pattern *p = params[i].string ? find_pattern(s, params[i].string) : NULL;
        if (!p) {
            snprintf(msg, sizeof msg,
                     "shader \"%s\": parameter \"%s\" names no pattern (\"%.64s\")",
                     inst->cls->name, params[i].name, params[i].string ? params[i].string : "");
            set_error(s, msg);
            return RAYES_ERROR_INVALID_ARGUMENT;
        }
        if (shade_instance_bind(inst, params[i].name, p, err, sizeof err) != 0) {
            set_error(s, err);
            return strcmp(err, "out of memory") == 0 ? RAYES_ERROR_OUT_OF_MEMORY
                                                     : RAYES_ERROR_INVALID_ARGUMENT;
        }
    }
    return RAYES_OK;
}

int scene_find_texture(const RayesScene *s, const char *name, char *out, size_t size)
{
    const char *env = getenv("RAYES_TEXTURE_PATH");
    const char *mine = s->search_paths[SCENE_SEARCH_PATH_TEXTURE]; /* not scene_search_path:
                                                                     scene.c calls this file */
    const char *paths[2] = {mine ? mine : "", env ? env : ""};
    if (access(name, R_OK) == 0 || name[0] == '/')
        return snprintf(out, size, "%s", name) < (int)size ? 0 : -1;
    for (int k = 0; k < 2; k++)
        for (const char *d = paths[k]; *d;) {
            size_t len = strcspn(d, ":");
            if (len > 0 && snprintf(out, size, "%.*s/%s", (int)len, d, name) < (int)size &&
                access(out, R_OK) == 0)
                return 0;
            d += len + (d[len] == ':');
        }
    return snprintf(out, size, "%s", name) < (int)size ? 0 : -1;
}

void scene_patterns_free(RayesScene *s)
{
    for (size_t i = 0; i < s->n_patterns; i++) {
        free(s->patterns[i].name);
        pattern_free(s->patterns[i].pattern);
    }
    free(s->patterns);
    s->patterns = NULL;
    s->n_patterns = s->cap_patterns = 0;
}
