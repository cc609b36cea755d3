/*
 * io/stats_json.h — statistics as JSON. Names with slashes nest:
 * "rays/shadow" becomes {"rays": {"shadow": N}}. The list must keep names
 * that share a prefix together (session/stats.c does).
 */
#ifndef RAYES_IO_STATS_JSON_H
#define RAYES_IO_STATS_JSON_H

#include <stdio.h>

#include "rayes/rayes.h"

/* Writes {"scene": scene, ...stats} to f. */
void io_stats_json_write(FILE *f, const RayesStats *stats, const char *scene);

/* The same into a file, atomically (temporary file, then rename). */
RayesError io_stats_json_save(const char *path, const RayesStats *stats, const char *scene,
                              char *err, size_t err_size);

#endif /* RAYES_IO_STATS_JSON_H */
