/*
 * app/distribute.h — one frame rendered by the ranks of an Open MPI job
 * (`mpirun -np N rayes render ...`).
 *
 * Every rank loads and prepares the scene and renders the tiles it is
 * given with its own threads and its own caches. Rank 0 hands tiles out
 * (a thread of it answers the other ranks' requests over point-to-point
 * messages while its own render threads take tiles from the same list,
 * in order), receives the other ranks' finished tiles and statistics,
 * and writes the image, which is the same bytes as a single process's:
 * a pixel does not depend on the tiles rendered with it.
 *
 * Without Open MPI at build time, or when not started by mpirun (no
 * OMPI_COMM_WORLD_SIZE in the environment), or with one rank, nothing
 * here touches MPI and the command renders as one process.
 */
#ifndef RAYES_APP_DISTRIBUTE_H
#define RAYES_APP_DISTRIBUTE_H

#include <stdio.h>

#include "rayes/rayes.h"

typedef struct Distributed Distributed;

/* Joins the MPI job this process was started in, if any, with more than
 * one rank: a new Distributed, or NULL (one process). Exits with a message
 * if MPI cannot start. */
Distributed *distribute_begin(int *argc, char ***argv);

int distribute_rank(const Distributed *d);

/* Before a frame's render: sets o's tile source (and on ranks above 0 its
 * tile_done) to this rank's share; rank 0 starts answering the others. */
int distribute_frame_begin(Distributed *d, RayesRenderOptions *o, char *err, size_t err_size);

/* After this rank's render of the frame (stats may be NULL after a
 * failure): ranks above 0 send their statistics; rank 0 waits for every
 * rank, copies their tiles into img and keeps their statistics. 0, or -1
 * with err filled. */
int distribute_frame_end(Distributed *d, RayesImage *img, const RayesStats *stats, char *err,
                         size_t err_size);

/* Rank 0: the last frame's statistics per rank and in total, as summary
 * lines. */
void distribute_print_summary(const Distributed *d, FILE *out);

/* Rank 0 (or one process, d NULL): the statistics file of the frame,
 * stats as io_stats_json_save writes them and, in a job, an "mpi" object
 * with every rank's tiles, rays, shading points, cache lookups and hit
 * rates, prepare and render times, and their total. 0, or -1 with err. */
int distribute_save_stats(const Distributed *d, const char *path, const RayesStats *stats,
                          const char *scene, char *err, size_t err_size);

void distribute_end(Distributed *d);

#endif
