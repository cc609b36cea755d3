/*
 * app/checkpoint.h — `--checkpoint SECONDS` and `--resume`: a long render
 * saves the tiles it has finished, and a later run of the same command
 * renders only the others (RayesRenderOptions.tile_source), its image the
 * same bytes as an uninterrupted render's (a pixel does not depend on which
 * tiles were rendered with it).
 *
 * The file (OUTPUT.checkpoint beside the first output) holds a digest of
 * what decides the pixels (the scene file's bytes, the frame, the options
 * that change pixels), the frame's size and tiles, a byte per tile and the
 * finished tiles' pixels. It is written whole to a temporary name and
 * renamed, so a run killed while writing leaves the previous checkpoint.
 * A checkpoint whose digest differs from the run's is ignored with a note
 * (the scene or options changed); it is removed once the outputs are
 * written.
 *
 * Threads: checkpoint_attach's callbacks run on render threads; the
 * checkpoint serializes them with its own lock.
 */
#ifndef RAYES_APP_CHECKPOINT_H
#define RAYES_APP_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "rayes/rayes.h"

typedef struct Checkpoint Checkpoint;

/* A digest of what decides the pixels of a render of scene (a file, whose
 * bytes are read, or a built-in name) at frame with options o, and the
 * n bytes of extra (the command line's camera; NULL, 0: none). */
uint64_t checkpoint_digest(const char *scene, int frame, const RayesRenderOptions *o,
                           const void *extra, size_t n);

/* A checkpoint at path for a render with options o, saved every every_s
 * seconds (0: after every tile); with resume, the tiles of a matching
 * checkpoint already at path are taken as done. NULL (err filled) when out
 * of memory or when path holds a checkpoint that cannot be read. */
Checkpoint *checkpoint_new(const char *path, uint64_t digest, const RayesRenderOptions *o,
                           double every_s, int resume, char *err, size_t err_size);

/* Tiles taken from the file (0 without one). */
int checkpoint_resumed_tiles(const Checkpoint *c);

/* Sets o's tile_source and tile_done to the checkpoint's (it must outlive
 * the render). */
void checkpoint_attach(Checkpoint *c, RayesRenderOptions *o);

/* Writes the finished tiles now; 0, or -1 with err filled. */
int checkpoint_save(Checkpoint *c, char *err, size_t err_size);

/* The first error a periodic save met, or NULL. */
const char *checkpoint_error(const Checkpoint *c);

/* Copies the resumed tiles' pixels into img (a render of the other tiles). */
void checkpoint_fill(const Checkpoint *c, RayesImage *img);

/* Removes the file (the outputs are written). */
void checkpoint_remove(const Checkpoint *c);

void checkpoint_free(Checkpoint *c);

#endif
