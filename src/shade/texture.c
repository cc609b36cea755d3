/*
 * shade/texture.c — see texture.h: name resolution, MIP reduction, the level
 * cache (one mutex, an LRU list of unpinned resident levels, a byte budget)
 * and footprint-filtered lookups.
 *
 * Memory layout: a level's texels are RGBA floats, row-major, top row first,
 * w * h * 16 bytes; level sizes are max(1, w0 >> k) x max(1, h0 >> k), fixed
 * when the texture is first read, so they are read without the lock.
 * A resident level is on the LRU list exactly when no lookup pins it.
 */
#include "shade/texture.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/image.h"
#include "util/check.h"
#include "util/log.h"

#define TEXTURE_MAX_LEVELS 32
#define TEXTURE_MAX_PROBES 8

typedef struct Texture Texture;

typedef struct Level {
    int w, h;                  /* texels */
    float *texels;             /* RGBA, NULL when not resident */
    int refs;                  /* lookups pinning it */
    struct Level *prev, *next; /* LRU list (most recent first) while resident and unpinned */
} Level;

struct Texture {
    char *name;                /* as the shader gave it */
    char *path;                /* the file found, or NULL: missing or unreadable */
    int n_levels;
    Level levels[TEXTURE_MAX_LEVELS];
    Texture *next;
};

struct TextureSystem {
    pthread_mutex_t lock;      /* guards everything below but lookups and the level sizes */
    char **dirs;               /* the search path's directories */
    size_t n_dirs;
    uint64_t budget, bytes, peak;
    float width;               /* factor on every footprint */
    Texture *textures;
    Level lru;                 /* sentinel of the LRU list */
    uint64_t n_textures, missing, loads, file_reads, evictions;
    atomic_uint_least64_t lookups;
};

/* ------------------------------------------------------------- system */

static int split_path(TextureSystem *ts, const char *path)
{
    if (!path || !path[0])
        return 0;
    char *copy = strdup(path);
    size_t n = 1;
    for (const char *c = path; *c; c++)
        n += *c == ':';
    ts->dirs = calloc(n, sizeof *ts->dirs);
    if (!copy || !ts->dirs) {
        free(copy);
        return -1;
    }
    char *save = NULL;
    for (char *d = strtok_r(copy, ":", &save); d; d = strtok_r(NULL, ":", &save))
        if (!(ts->dirs[ts->n_dirs++] = strdup(d))) {
            free(copy);
            return -1;
        }
    free(copy);
    return 0;
}

TextureSystem *texture_system_new(const char *search_path, uint64_t budget_bytes, float width)
{
    TextureSystem *ts = calloc(1, sizeof *ts);
    if (!ts)
        return NULL;
    pthread_mutex_init(&ts->lock, NULL);
    ts->budget = budget_bytes;
    ts->width = isfinite(width) && width > 0.0f ? width : 0.0f;
    ts->lru.prev = ts->lru.next = &ts->lru;
    atomic_init(&ts->lookups, 0);
    if (split_path(ts, search_path) != 0) {
        texture_system_free(ts);
        return NULL;
    }
    return ts;
}

void texture_system_free(TextureSystem *ts)
{
    if (!ts)
        return;
    for (Texture *t = ts->textures, *next; t; t = next) {
        next = t->next;
        for (int l = 0; l < t->n_levels; l++)
            free(t->levels[l].texels);
        free(t->name);
        free(t->path);
        free(t);
    }
    for (size_t i = 0; i < ts->n_dirs; i++)
        free(ts->dirs[i]);
    free(ts->dirs);
    pthread_mutex_destroy(&ts->lock);
    free(ts);
}

void texture_get_stats(TextureSystem *ts, TextureStats *st)
{
    pthread_mutex_lock(&ts->lock);
    *st = (TextureStats){
        .lookups = atomic_load(&ts->lookups), .textures = ts->n_textures,
        .missing = ts->missing, .loads = ts->loads, .file_reads = ts->file_reads,
        .evictions = ts->evictions, .bytes = ts->bytes, .peak_bytes = ts->peak,
        .budget_bytes = ts->budget,
    };
    pthread_mutex_unlock(&ts->lock);
}

/* ------------------------------------------------------- files, levels */

/* The file a name stands for: as given, then in each directory of the
 * search path. New string, or NULL if none is readable. */
static char *resolve(const TextureSystem *ts, const char *name)
{
    if (access(name, R_OK) == 0)
        return strdup(name);
    if (name[0] == '/')
        return NULL;
    for (size_t i = 0; i < ts->n_dirs; i++) {
        size_t len = strlen(ts->dirs[i]) + strlen(name) + 2;
        char *p = malloc(len);
        if (!p)
            return NULL;
        snprintf(p, len, "%s/%s", ts->dirs[i], name);
        if (access(p, R_OK) == 0)
            return p;
        free(p);
    }
    return NULL;
}

static RayesError read_image(const char *path, int *w, int *h, float **rgba, char *err,
                             size_t err_size)
{
    switch (image_format_from_path(path)) {
    case IMAGE_FORMAT_EXR: return image_read_exr(path, w, h, rgba, err, err_size);
    case IMAGE_FORMAT_PNG: return image_read_png(path, w, h, rgba, err, err_size);
    default: break;
    }
    snprintf(err, err_size, "%s: not an .exr or .png file", path);
    return RAYES_ERROR_INVALID_ARGUMENT;
}

/* One output texel's weights over the input along an axis of n texels
 * reduced to m: the box filter of the output texel's footprint. Even n: 2
 * taps of 1/2; odd n = 2m + 1: taps 2i, 2i + 1, 2i + 2 with weights
 * (m - i) / n, m / n, (i + 1) / n; n = 1: the texel itself. */
static int taps(int n, int i, int first[1], float w[3])
{
    if (n == 1) {
        first[0] = 0;
        w[0] = 1.0f;
        return 1;
    }
    first[0] = 2 * i;
    if (n % 2 == 0) {
        w[0] = w[1] = 0.5f;
        return 2;
    }
    int m = n / 2;
    w[0] = (float)(m - i) / (float)n;
    w[1] = (float)m / (float)n;
    w[2] = (float)(i + 1) / (float)n;
    return 3;
}

/* The next level of a w x h RGBA image: new, max(1, w/2) x max(1, h/2). */
static float *reduce(const float *in, int w, int h)
{
    int mw = RY_MAX(w / 2, 1), mh = RY_MAX(h / 2, 1);
    float *row = malloc((size_t)mw * h * 4 * sizeof *row);
    float *out = malloc((size_t)mw * mh * 4 * sizeof *out);
    if (!row || !out) {
        free(row);
        free(out);
        return NULL;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < mw; x++) {
            int f;
            float wt[3];
            int k = taps(w, x, &f, wt);
            for (int c = 0; c < 4; c++) {
                float sum = 0.0f;
                for (int j = 0; j < k; j++)
                    sum += wt[j] * in[((size_t)y * w + f + j) * 4 + c];
                row[((size_t)y * mw + x) * 4 + c] = sum;
            }
        }
    for (int y = 0; y < mh; y++) {
        int f;
        float wt[3];
        int k = taps(h, y, &f, wt);
        for (int x = 0; x < mw; x++)
            for (int c = 0; c < 4; c++) {
                float sum = 0.0f;
                for (int j = 0; j < k; j++)
                    sum += wt[j] * row[((size_t)(f + j) * mw + x) * 4 + c];
                out[((size_t)y * mw + x) * 4 + c] = sum;
            }
    }
    free(row);
    return out;
}

/* Reduces bufs[0] (level 0, owned by the caller) to the whole pyramid:
 * bufs[1 .. n_levels) are new. Returns 0, or -1 (none of them left). */
static int reduce_all(const Texture *tex, float **bufs)
{
    for (int l = 1; l < tex->n_levels; l++)
        if (!(bufs[l] = reduce(bufs[l - 1], tex->levels[l - 1].w, tex->levels[l - 1].h))) {
            for (int k = 1; k < l; k++)
                free(bufs[k]);
            return -1;
        }
    return 0;
}

/* Reads tex's file again and builds its pyramid into bufs (all new).
 * Returns 0, or -1 (nothing left allocated). Runs without the lock. */
static int build_levels(const Texture *tex, float **bufs)
{
    int w, h;
    char err[300];
    if (read_image(tex->path, &w, &h, &bufs[0], err, sizeof err) != RAYES_OK)
        return -1;
    if (w != tex->levels[0].w || h != tex->levels[0].h || reduce_all(tex, bufs) != 0) {
        free(bufs[0]); /* the file changed under us, or out of memory */
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------- the LRU cache */

static uint64_t level_bytes(const Level *lv)
{
    return (uint64_t)lv->w * (uint64_t)lv->h * 4 * sizeof(float);
}

static void lru_unlink(Level *lv)
{
    lv->prev->next = lv->next;
    lv->next->prev = lv->prev;
    lv->prev = lv->next = NULL;
}

static void lru_push(TextureSystem *ts, Level *lv)
{
    lv->next = ts->lru.next;
    lv->prev = &ts->lru;
    ts->lru.next->prev = lv;
    ts->lru.next = lv;
}

/* Makes buf the resident texels of lv (unpinned, most recent), evicting the
 * least recently used unpinned levels for room. Returns 1, or 0 if it
 * cannot fit (the caller keeps buf). Lock held. */
static int store_level(TextureSystem *ts, Level *lv, float *buf)
{
    uint64_t need = level_bytes(lv);
    if (need > ts->budget)
        return 0;
    while (ts->bytes + need > ts->budget && ts->lru.prev != &ts->lru) {
        Level *victim = ts->lru.prev;
        lru_unlink(victim);
        free(victim->texels);
        victim->texels = NULL;
        ts->bytes -= level_bytes(victim);
        ts->evictions++;
    }
    if (ts->bytes + need > ts->budget)
        return 0; /* the rest is pinned */
    lv->texels = buf;
    lv->refs = 0;
    ts->bytes += need;
    ts->peak = RY_MAX(ts->peak, ts->bytes);
    lru_push(ts, lv);
    return 1;
}

static void pin(Level *lv)
{
    if (lv->refs++ == 0)
        lru_unlink(lv);
}

/* Keeps the built levels other than `want` that are not resident, as far
 * as the budget allows (coarsest first, so the finest are the most recent);
 * frees the rest. Lock held. */
static void store_others(TextureSystem *ts, Texture *tex, float **bufs, int want)
{
    for (int k = tex->n_levels - 1; k >= 0; k--)
        if (k != want && (tex->levels[k].texels || !store_level(ts, &tex->levels[k], bufs[k])))
            free(bufs[k]);
}

/* A level as one lookup batch holds it. */
typedef struct LevelRef {
    int held;                  /* acquired by this batch */
    const float *texels;       /* NULL if the file could not be read again */
    Level *pinned;             /* the resident level pinned, or NULL */
    float *owned;              /* texels built for this batch alone */
} LevelRef;

static void acquire(TextureSystem *ts, Texture *tex, int l, LevelRef *r)
{
    Level *lv = &tex->levels[l];
    r->held = 1;
    pthread_mutex_lock(&ts->lock);
    if (lv->texels) {
        pin(lv);
        r->texels = lv->texels;
        r->pinned = lv;
        pthread_mutex_unlock(&ts->lock);
        return;
    }
    pthread_mutex_unlock(&ts->lock);
    float *bufs[TEXTURE_MAX_LEVELS] = {0};
    int ok = build_levels(tex, bufs) == 0;
    pthread_mutex_lock(&ts->lock);
    if (!ok) {
        pthread_mutex_unlock(&ts->lock);
        char key[64];
        snprintf(key, sizeof key, "texture-reread:%s", tex->name);
        log_warning_once(key, "texture \"%s\": %s could not be read again; black", tex->name,
                         tex->path);
        return;
    }
    ts->file_reads++;
    ts->loads += (uint64_t)tex->n_levels;
    store_others(ts, tex, bufs, l);
    if (lv->texels) /* another thread loaded it meanwhile */
        free(bufs[l]);
    else if (!store_level(ts, lv, bufs[l])) {
        pthread_mutex_unlock(&ts->lock);
        r->texels = r->owned = bufs[l];
        return;
    }
    pin(lv);
    r->texels = lv->texels;
    r->pinned = lv;
    pthread_mutex_unlock(&ts->lock);
}

static void release(TextureSystem *ts, LevelRef *r)
{
    if (r->pinned) {
        pthread_mutex_lock(&ts->lock);
        if (--r->pinned->refs == 0)
            lru_push(ts, r->pinned);
        pthread_mutex_unlock(&ts->lock);
    }
    free(r->owned);
    *r = (LevelRef){0};
}

/* The texture of that name, read for the first time if new (its pyramid
 * kept as far as it fits); NULL when out of memory. */
static Texture *find_texture(TextureSystem *ts, const char *name)
{
    pthread_mutex_lock(&ts->lock);
    for (Texture *t = ts->textures; t; t = t->next)
        if (strcmp(t->name, name) == 0) {
            pthread_mutex_unlock(&ts->lock);
            return t;
        }
    pthread_mutex_unlock(&ts->lock);

    Texture *nt = calloc(1, sizeof *nt);
    char err[300] = "";
    float *rgba = NULL;
    int w = 0, h = 0;
    if (!nt || !(nt->name = strdup(name))) {
        free(nt);
        return NULL;
    }
    nt->path = resolve(ts, name);
    if (!nt->path)
        snprintf(err, sizeof err, "not found as given nor on the texture search path");
    else if (read_image(nt->path, &w, &h, &rgba, err, sizeof err) != RAYES_OK) {
        free(nt->path);
        nt->path = NULL;
    }
    float *bufs[TEXTURE_MAX_LEVELS] = {0};
    if (nt->path) {
        for (int l = 0; l < TEXTURE_MAX_LEVELS; l++) {
            nt->levels[l].w = RY_MAX(w >> l, 1);
            nt->levels[l].h = RY_MAX(h >> l, 1);
            nt->n_levels = l + 1;
            if (nt->levels[l].w == 1 && nt->levels[l].h == 1)
                break;
        }
        bufs[0] = rgba;
        if (reduce_all(nt, bufs) != 0) {
            snprintf(err, sizeof err, "%s: out of memory for its MIP levels", nt->path);
            free(rgba);
            free(nt->path);
            nt->path = NULL;
        }
    }

    pthread_mutex_lock(&ts->lock);
    for (Texture *t = ts->textures; t; t = t->next)
        if (strcmp(t->name, name) == 0) { /* another thread was first */
            pthread_mutex_unlock(&ts->lock);
            for (int l = 0; nt->path && l < nt->n_levels; l++)
                free(bufs[l]);
            free(nt->path);
            free(nt->name);
            free(nt);
            return t;
        }
    nt->next = ts->textures;
    ts->textures = nt;
    ts->n_textures++;
    if (!nt->path) {
        ts->missing++;
        log_warning("texture \"%s\": %s; shading continues without it", name, err);
    } else {
        ts->file_reads++;
        ts->loads += (uint64_t)nt->n_levels;
        store_others(ts, nt, bufs, -1);
    }
    pthread_mutex_unlock(&ts->lock);
    return nt;
}

/* ------------------------------------------------------------ lookups */

static float wrap01(float s)
{
    if (!isfinite(s))
        return 0.0f;
    return s - floorf(s);
}

static int wrap_index(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

/* Bilinear, periodic, texel centres at (i + 0.5) / w; adds weight * value. */
static void bilinear(const Level *lv, const float *texels, float s, float t, float weight,
                     float acc[4])
{
    if (!texels)
        return;
    float x = wrap01(s) * (float)lv->w - 0.5f, y = wrap01(t) * (float)lv->h - 0.5f;
    float x0f = floorf(x), y0f = floorf(y), fx = x - x0f, fy = y - y0f;
    int x0 = wrap_index((int)x0f, lv->w), x1 = wrap_index((int)x0f + 1, lv->w);
    int y0 = wrap_index((int)y0f, lv->h), y1 = wrap_index((int)y0f + 1, lv->h);
    const float *a = texels + ((size_t)y0 * lv->w + x0) * 4;
    const float *b = texels + ((size_t)y0 * lv->w + x1) * 4;
    const float *c = texels + ((size_t)y1 * lv->w + x0) * 4;
    const float *d = texels + ((size_t)y1 * lv->w + x1) * 4;
    for (int k = 0; k < 4; k++)
        acc[k] += weight * ((1.0f - fy) * ((1.0f - fx) * a[k] + fx * b[k]) +
                            fy * ((1.0f - fx) * c[k] + fx * d[k]));
}

static float footprint(const float *d, size_t i)
{
    float v = d ? fabsf(d[i]) : 0.0f;
    return isfinite(v) ? v : 0.0f;
}

/* One point: probes along the major axis, each trilinear. */
static void filter_point(TextureSystem *ts, Texture *tex, LevelRef *refs, float s, float t,
                         float ds, float dt, float out[4])
{
    const Level *l0 = &tex->levels[0];
    float fw = ds * (float)l0->w, fh = dt * (float)l0->h; /* level-0 texels */
    float major = fmaxf(fw, fh), minor = fminf(fw, fh);
    int probes = 1;
    if (major > 1.0f)
        probes = minor * TEXTURE_MAX_PROBES <= major ? TEXTURE_MAX_PROBES
                                                     : (int)ceilf(major / minor);
    float width = fmaxf(minor, major / (float)probes);
    float lambda = width > 1.0f ? log2f(width) : 0.0f;
    lambda = fminf(lambda, (float)(tex->n_levels - 1));
    int la = (int)floorf(lambda), lb = RY_MIN(la + 1, tex->n_levels - 1);
    float f = lambda - (float)la;
    int levels[2] = {la, lb};
    for (int k = 0; k < (f > 0.0f ? 2 : 1); k++)
        if (!refs[levels[k]].held)
            acquire(ts, tex, levels[k], &refs[levels[k]]);
    memset(out, 0, 4 * sizeof *out);
    int along_s = fw >= fh;
    for (int p = 0; p < probes; p++) {
        float off = ((float)p + 0.5f) / (float)probes - 0.5f;
        float ps = along_s ? s + off * ds : s, pt = along_s ? t : t + off * dt;
        float wa = (1.0f - f) / (float)probes, wb = f / (float)probes;
        bilinear(&tex->levels[la], refs[la].texels, ps, pt, wa, out);
        if (f > 0.0f)
            bilinear(&tex->levels[lb], refs[lb].texels, ps, pt, wb, out);
    }
}

int texture_lookup(TextureSystem *ts, const char *name, size_t n, const float *s, const float *t,
                   const float *ds, const float *dt, float (*rgb)[3], float *alpha)
{
    atomic_fetch_add(&ts->lookups, (uint64_t)n);
    Texture *tex = name && name[0] ? find_texture(ts, name) : NULL;
    if (!tex || !tex->path) {
        memset(rgb, 0, n * sizeof *rgb);
        for (size_t i = 0; alpha && i < n; i++)
            alpha[i] = 1.0f;
        return -1;
    }
    LevelRef refs[TEXTURE_MAX_LEVELS] = {0};
    for (size_t i = 0; i < n; i++) {
        float v[4];
        filter_point(ts, tex, refs, s[i], t[i], ts->width * footprint(ds, i),
                     ts->width * footprint(dt, i), v);
        memcpy(rgb[i], v, sizeof rgb[i]);
        if (alpha)
            alpha[i] = v[3];
    }
    for (int l = 0; l < tex->n_levels; l++)
        if (refs[l].held)
            release(ts, &refs[l]);
    return 0;
}
