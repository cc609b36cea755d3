/*
 * app/checkpoint.c — saving and resuming a render's finished tiles
 * (checkpoint.h).
 *
 * File layout (this machine's byte order: a checkpoint resumes on the
 * machine, or the farm's kind of machine, that wrote it):
 *   "RAYESCK2", digest (u64), width, height, tile size, crop x0 y0 x1 y1,
 *   tiles x, tiles y, AOV bits (i32 each), a byte per tile (1: done), then
 *   the done tiles' pixels in tile order, w * h * 4 floats each, each
 *   followed by its AOVs, w * h * rayes_aov_channels floats.
 */
#include "app/checkpoint.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/tiles.h"
#include "util/log.h"

#define MAGIC "RAYESCK2"
#define HEADER_INTS 10

enum { TILE_PENDING = 0, TILE_RESUMED = 1, TILE_DONE = 2 };

struct Checkpoint {
    char path[4200], tmp[4220];
    uint64_t digest;
    int width, height;
    TileGrid g;             /* the render's tiles */
    unsigned char *state;   /* TILE_* per tile */
    float *rgba;            /* the frame, width * height * 4: finished tiles' pixels */
    unsigned aovs;          /* the render's AOVs (RayesRenderOptions.aovs) */
    int k;                  /* their channels */
    float *aov;             /* the frame's, width * height * k: finished tiles' */
    int next;               /* the tile source's next candidate */
    int resumed;            /* tiles read from the file */
    double every_s, last_save;
    char error[600];        /* the first failed periodic save */
    pthread_mutex_t lock;
};

/* ------------------------------------------------------------- digest */

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

#define HASH(h, field) ((h) = fnv((h), &(field), sizeof(field)))

uint64_t checkpoint_digest(const char *scene, int frame, const RayesRenderOptions *o,
                           const void *extra, size_t n_extra)
{
    uint64_t h = fnv(0xcbf29ce484222325ull, scene, strlen(scene));
    FILE *f = fopen(scene, "rb");
    if (f) { /* a file: its bytes (files it includes are not read) */
        unsigned char buf[65536];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0)
            h = fnv(h, buf, n);
        fclose(f);
    }
    /* the options that change pixels (not threads, budgets or callbacks; a
     * budget of 0 turns its cache off) */
    int cache = o->cache && o->cache_mb > 0.0;
    int opacity_cache = o->opacity_cache && o->opacity_cache_mb > 0.0;
    int irradiance_cache = o->irradiance_cache && o->irradiance_cache_mb > 0.0;
    HASH(h, frame);
    HASH(h, o->width), HASH(h, o->height), HASH(h, o->spp), HASH(h, o->bounces);
    HASH(h, o->shadow_rays), HASH(h, o->shadow_rays_deep), HASH(h, o->diffuse_rays);
    HASH(h, o->diffuse_rays_deep), HASH(h, o->specular_depth), HASH(h, o->filter);
    HASH(h, o->filter_width), HASH(h, o->seed), HASH(h, o->tile_size), HASH(h, cache);
    HASH(h, o->cache_resolution), HASH(h, o->cache_k), HASH(h, o->hider);
    HASH(h, o->irradiance), HASH(h, o->texture_width), HASH(h, o->grid_size);
    HASH(h, o->branch_depth), HASH(h, o->dice_offscreen), HASH(h, o->dice_isotropic);
    HASH(h, o->vertex_budget), HASH(h, o->crop), HASH(h, opacity_cache);
    HASH(h, o->volume_step), HASH(h, o->subsurface_rays), HASH(h, irradiance_cache);
    HASH(h, o->irradiance_shadow_rays), HASH(h, o->cache_fine_depth), HASH(h, o->aovs);
    return extra && n_extra ? fnv(h, extra, n_extra) : h;
}

/* The file's header after the digest. */
static void header(const Checkpoint *c, int32_t h[HEADER_INTS])
{
    int32_t v[HEADER_INTS] = {c->width,     c->height,       c->g.size,    c->g.crop[0],
                              c->g.crop[1], c->g.crop[2],    c->g.crop[3], c->g.tiles_x,
                              c->g.tiles_y, (int32_t)c->aovs};
    memcpy(h, v, sizeof v);
}

static int n_tiles(const Checkpoint *c)
{
    return tile_count(&c->g);
}

/* ------------------------------------------------------------- the file */

static int read_exact(FILE *f, void *p, size_t n)
{
    return fread(p, 1, n, f) == n ? 0 : -1;
}

/* Reads c->path into c's tiles if it is a checkpoint of this render: 1
 * read, 0 none or another render's (noted), -1 a damaged file (err). */
static int load(Checkpoint *c, char *err, size_t err_size)
{
    FILE *f = fopen(c->path, "rb");
    if (!f)
        return 0;
    char magic[8];
    uint64_t digest;
    int32_t hdr[HEADER_INTS];
    int32_t want[HEADER_INTS];
    header(c, want);
    int r = -1;
    if (read_exact(f, magic, 8) || memcmp(magic, MAGIC, 8) || read_exact(f, &digest, 8) ||
        read_exact(f, hdr, sizeof hdr)) {
        snprintf(err, err_size, "%s: not a rayes checkpoint, or truncated", c->path);
    } else if (digest != c->digest || memcmp(hdr, want, sizeof hdr) != 0) {
        fprintf(stderr, "rayes: note: %s: a checkpoint of another scene or other options; "
                        "starting afresh\n", c->path);
        r = 0;
    } else if (read_exact(f, c->state, (size_t)n_tiles(c))) {
        snprintf(err, err_size, "%s: truncated checkpoint", c->path);
    } else {
        r = 1;
        for (int t = 0; t < n_tiles(c) && r == 1; t++) {
            if (c->state[t] == TILE_PENDING)
                continue;
            c->state[t] = TILE_RESUMED;
            c->resumed++;
            int q[4];
            tile_rect(&c->g, t, q);
            for (int y = 0; y < q[3] && r == 1; y++)
                if (read_exact(f, &c->rgba[4 * ((size_t)(q[1] + y) * c->width + q[0])],
                               sizeof(float) * 4 * (size_t)q[2])) {
                    snprintf(err, err_size, "%s: truncated checkpoint", c->path);
                    r = -1;
                }
            for (int y = 0; y < q[3] && r == 1 && c->k; y++)
                if (read_exact(f, &c->aov[(size_t)c->k * ((size_t)(q[1] + y) * c->width + q[0])],
                               sizeof(float) * (size_t)c->k * (size_t)q[2])) {
                    snprintf(err, err_size, "%s: truncated checkpoint", c->path);
                    r = -1;
                }
        }
    }
    fclose(f);
    if (r != 1) { /* nothing of it is used */
        memset(c->state, 0, (size_t)n_tiles(c));
        c->resumed = 0;
    }
    return r;
}

int checkpoint_save(Checkpoint *c, char *err, size_t err_size)
{
    FILE *f = fopen(c->tmp, "wb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot write checkpoint: %s", c->tmp, strerror(errno));
        return -1;
    }
    int32_t hdr[HEADER_INTS];
    header(c, hdr);
    int ok = fwrite(MAGIC, 1, 8, f) == 8 && fwrite(&c->digest, 8, 1, f) == 1 &&
             fwrite(hdr, sizeof hdr, 1, f) == 1;
    unsigned char *done = malloc((size_t)n_tiles(c));
    ok = ok && done;
    for (int t = 0; ok && t < n_tiles(c); t++)
        done[t] = c->state[t] != TILE_PENDING;
    ok = ok && fwrite(done, 1, (size_t)n_tiles(c), f) == (size_t)n_tiles(c);
    for (int t = 0; ok && t < n_tiles(c); t++) {
        if (!done[t])
            continue;
        int q[4];
        tile_rect(&c->g, t, q);
        for (int y = 0; ok && y < q[3]; y++)
            ok = fwrite(&c->rgba[4 * ((size_t)(q[1] + y) * c->width + q[0])], sizeof(float) * 4,
                        (size_t)q[2], f) == (size_t)q[2];
        for (int y = 0; ok && c->k && y < q[3]; y++)
            ok = fwrite(&c->aov[(size_t)c->k * ((size_t)(q[1] + y) * c->width + q[0])],
                        sizeof(float) * (size_t)c->k, (size_t)q[2], f) == (size_t)q[2];
    }
    free(done);
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(c->tmp, c->path) != 0) {
        snprintf(err, err_size, "%s: cannot write checkpoint: %s", c->path, strerror(errno));
        unlink(c->tmp);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------- the render */

static int source(void *user, int tiles_x, int tiles_y)
{
    Checkpoint *c = user;
    if (tiles_x != c->g.tiles_x || tiles_y != c->g.tiles_y)
        return c->next++ < tiles_x * tiles_y ? c->next - 1 : -1; /* not ours: every tile */
    while (c->next < n_tiles(c) && c->state[c->next] != TILE_PENDING)
        c->next++;
    return c->next < n_tiles(c) ? c->next++ : -1;
}

/* Before tile_done, on the same thread: the tile's AOVs. */
static void tile_aov_done(void *user, int x, int y, int w, int h, const float *aov, int channels,
                          int stride)
{
    Checkpoint *c = user;
    if (channels != c->k || tile_at(&c->g, x, y) < 0)
        return;
    pthread_mutex_lock(&c->lock);
    for (int r = 0; r < h; r++)
        memcpy(&c->aov[(size_t)c->k * ((size_t)(y + r) * c->width + x)],
               &aov[(size_t)c->k * ((size_t)(y + r) * stride + x)],
               sizeof(float) * (size_t)c->k * (size_t)w);
    pthread_mutex_unlock(&c->lock);
}

static void tile_done(void *user, int x, int y, int w, int h, const float *rgba, int stride)
{
    Checkpoint *c = user;
    int t = tile_at(&c->g, x, y);
    if (t < 0)
        return; /* cannot be one of its tiles */
    pthread_mutex_lock(&c->lock);
    for (int r = 0; r < h; r++)
        memcpy(&c->rgba[4 * ((size_t)(y + r) * c->width + x)],
               &rgba[4 * ((size_t)(y + r) * stride + x)], sizeof(float) * 4 * (size_t)w);
    c->state[t] = TILE_DONE;
    double now = time_now();
    if (now - c->last_save >= c->every_s) {
        char err[600];
        if (checkpoint_save(c, err, sizeof err) != 0 && !c->error[0])
            snprintf(c->error, sizeof c->error, "%s", err);
        c->last_save = now;
    }
    pthread_mutex_unlock(&c->lock);
}

Checkpoint *checkpoint_new(const char *path, uint64_t digest, const RayesRenderOptions *o,
                           double every_s, int resume, char *err, size_t err_size)
{
    Checkpoint *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, err_size, "out of memory");
        return NULL;
    }
    snprintf(c->path, sizeof c->path, "%s", path);
    snprintf(c->tmp, sizeof c->tmp, "%s.tmp", path);
    c->digest = digest;
    c->width = o->width, c->height = o->height;
    c->g = tile_grid(o);
    c->every_s = every_s;
    c->last_save = time_now();
    c->state = calloc((size_t)n_tiles(c) + 1, 1);
    c->rgba = calloc((size_t)c->width * (size_t)c->height * 4, sizeof(float));
    c->aovs = o->aovs;
    c->k = rayes_aov_channels(o->aovs);
    c->aov =
        c->k ? calloc((size_t)c->width * (size_t)c->height * (size_t)c->k, sizeof(float)) : NULL;
    pthread_mutex_init(&c->lock, NULL);
    if (!c->state || !c->rgba || (c->k && !c->aov)) {
        snprintf(err, err_size, "%s: out of memory", path);
        checkpoint_free(c);
        return NULL;
    }
    if (resume && load(c, err, err_size) < 0) {
        checkpoint_free(c);
        return NULL;
    }
    return c;
}

int checkpoint_resumed_tiles(const Checkpoint *c)
{
    return c->resumed;
}

void checkpoint_attach(Checkpoint *c, RayesRenderOptions *o)
{
    o->tile_source = source;
    o->tile_source_user = c;
    o->tile_done = tile_done;
    o->tile_aov_done = c->k ? tile_aov_done : NULL;
    o->tile_user = c;
}

const char *checkpoint_error(const Checkpoint *c)
{
    return c->error[0] ? c->error : NULL;
}

void checkpoint_fill(const Checkpoint *c, RayesImage *img)
{
    if (img->width != c->width || img->height != c->height)
        return;
    for (int t = 0; t < n_tiles(c); t++) {
        if (c->state[t] != TILE_RESUMED)
            continue;
        int q[4];
        tile_rect(&c->g, t, q);
        for (int y = 0; y < q[3]; y++) {
            size_t at = (size_t)(q[1] + y) * c->width + q[0];
            memcpy(&img->rgba[4 * at], &c->rgba[4 * at], sizeof(float) * 4 * (size_t)q[2]);
            if (c->k && img->aov && img->aovs == c->aovs)
                memcpy(&img->aov[(size_t)c->k * at], &c->aov[(size_t)c->k * at],
                       sizeof(float) * (size_t)c->k * (size_t)q[2]);
        }
    }
}

void checkpoint_remove(const Checkpoint *c)
{
    unlink(c->path);
    unlink(c->tmp);
}

void checkpoint_free(Checkpoint *c)
{
    if (!c)
        return;
    pthread_mutex_destroy(&c->lock);
    free(c->state);
    free(c->rgba);
    free(c->aov);
    free(c);
}
