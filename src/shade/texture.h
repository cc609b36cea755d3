/*
 * shade/texture.h — image textures: files found on a search path, MIP-mapped
 * at load, filtered by the shading point's footprint, kept in a cache with a
 * memory budget (DESIGN.md "Decisions made in rayes", Textures).
 *
 * A TextureSystem belongs to one render. Textures are named as shaders name
 * them; a name is resolved once (as given, then in each directory of the
 * search path) and read with image_read_exr or image_read_png (PNG is
 * decoded from sRGB to linear). Each texture is a pyramid of MIP levels;
 * level k + 1 is the exact box-filtered average of level k (2 x 2 texels for
 * even sizes, 3 texels with fractional end weights for odd ones), so every
 * level has the mean of level 0 and texel i of a level of width w covers
 * [i / w, (i + 1) / w) in s.
 *
 * The cache: MIP levels are the unit. A level is loaded when a lookup first
 * needs it (the file is read and the pyramid reduced down to it), kept while
 * the resident bytes fit the budget, and evicted least-recently-used when a
 * new level needs the room. A level in use by a lookup is pinned. A level
 * that cannot fit is built for the lookup that needs it and freed after it.
 * A level's texels are a pure function of the file, so a lookup's result
 * never depends on what was cached, on the budget or on threads.
 *
 * Thread-safety: texture_lookup may be called from any number of threads;
 * one mutex guards the table and the LRU list, and files are read without
 * it held.
 */
#ifndef RAYES_SHADE_TEXTURE_H
#define RAYES_SHADE_TEXTURE_H

#include <stddef.h>
#include <stdint.h>

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
 * level 0). The filter: ceil(major / minor) (at most 8) bilinear-trilinear
 * probes spread along the footprint's major axis, at the MIP level whose
 * texels are max(minor, major / probes) wide, blended linearly between the
 * two nearest levels. Writes linear rgb and alpha (alpha may be NULL; 1
 * when the file has none). Returns 0, or -1 when the texture cannot be
 * read: one warning naming the file per system, rgb 0 and alpha 1. */
int texture_lookup(TextureSystem *ts, const char *name, size_t n, const float *s, const float *t,
                   const float *ds, const float *dt, float (*rgb)[3], float *alpha);

/* The statistics so far. */
void texture_get_stats(TextureSystem *ts, TextureStats *stats);

#endif /* RAYES_SHADE_TEXTURE_H */
