/*
 * shade/texture.h — image textures: files found on a search path, read,
 * MIP-mapped, cached within a memory budget and filtered by the shading
 * point's footprint by OpenImageIO's TextureSystem (texture.cpp, the one
 * C++ file of shade, behind this C interface; DESIGN.md "Textures").
 *
 * A TextureSystem belongs to one render. Textures are named as shaders name
 * them; a name is resolved once (as given, then in each directory of the
 * search path). Every format OpenImageIO reads is a texture: EXR, TIFF and
 * maketx's tiled, MIP-mapped .tx files, PNG, JPEG, TGA, HDR, ... Untiled
 * files get their MIP levels on first use. Integer files not marked linear
 * are sRGB and come back linear. A lookup's result never depends on what
 * was cached, on the budget or on threads.
 *
 * Thread-safety: texture_lookup may be called from any number of threads.
 */
#ifndef RAYES_SHADE_TEXTURE_H
#define RAYES_SHADE_TEXTURE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct TextureSystem TextureSystem;

typedef struct TextureStats {
    uint64_t lookups;        /* points looked up */
    uint64_t textures;       /* distinct names asked for */
    uint64_t missing;        /* of those, names that could not be read */
    uint64_t loads;          /* MIP levels built from a file (first loads and reloads) */
    uint64_t file_reads;     /* image files read */
    uint64_t evictions;      /* levels evicted to make room */
    uint64_t bytes;          /* resident texel bytes at the end */
    uint64_t peak_bytes;     /* largest resident texel bytes */
    uint64_t budget_bytes;
} TextureStats;

/* A new texture system: search_path is colon-separated directories (NULL
 * or "" for none), budget_bytes the most texel memory kept resident (0:
 * nothing is kept; every lookup reads its file), width a factor on every
 * lookup's ds and dt (RenderMan's "width": 1 normally, 0 point-samples).
 * Returns NULL when out of memory. */
TextureSystem *texture_system_new(const char *search_path, uint64_t budget_bytes, float width);
void texture_system_free(TextureSystem *ts);

/* Looks up n points of texture `name` at (s[i], t[i]) ((0, 0) is the top
 * left corner, wrapping periodically), filtered over ds[i] x dt[i] in
 * texture space (full widths; ds or dt NULL: point sampling, bilinear on
 * level 0) by OpenImageIO's anisotropic MIP filter. Writes linear rgb and
 * alpha (alpha may be NULL; 1 when the file has none; grey files are grey
 * in rgb). Returns 0, or -1 when the texture cannot be read: one warning
 * naming the file per system, rgb 0 and alpha 1. */
int texture_lookup(TextureSystem *ts, const char *name, size_t n, const float *s, const float *t,
                   const float *ds, const float *dt, float (*rgb)[3], float *alpha);

/* What a lookup finds outside [0, 1]: the image again (periodic), black
 * (and alpha 0), or its edge's texels (pbrt's "repeat", "black" and
 * "clamp"). */
typedef enum TextureWrap {
    TEXTURE_WRAP_REPEAT,
    TEXTURE_WRAP_BLACK,
    TEXTURE_WRAP_CLAMP
} TextureWrap;

/* texture_lookup with the texels' encoding given, as pbrt's imagemap gives
 * it: NULL or "" the file's own (integer files sRGB unless they say they
 * are linear), "sRGB", "linear" (integer texels as they are, over their
 * maximum) or "gamma G" (raised to G); and the wrap. Float files are
 * linear whatever it says. The same file under two encodings is two
 * textures. */
int texture_lookup_encoded(TextureSystem *ts, const char *name, const char *encoding,
                           TextureWrap wrap, size_t n, const float *s, const float *t,
                           const float *ds, const float *dt, float (*rgb)[3], float *alpha);

/* How many channels texture `name` has (3 rgb, 4 rgba, 1 grey, 2 grey and
 * alpha), found as a lookup finds it; 0 when it cannot be read. */
int texture_channels(TextureSystem *ts, const char *name, const char *encoding);

/* The statistics so far (loads: tiles read; file_reads: files opened;
 * evictions: tiles no longer resident; bytes: OpenImageIO's cache memory;
 * peak_bytes: an estimate from its peak tile count). */
void texture_get_stats(TextureSystem *ts, TextureStats *stats);

/* Reads a whole image (level 0) of any format OpenImageIO knows into a new
 * array of linear RGBA (malloc; grey as grey, alpha 1 when none, sRGB
 * integer files decoded). Returns 0, or -1 with a message in err. For
 * environment maps, which are sampled by their pixels. */
int texture_read_image(const char *path, int *w, int *h, float **rgba, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif

#endif /* RAYES_SHADE_TEXTURE_H */
