/*
 * io/bpt.h — the Bezier patch file format of ../shared/data/teapot.bpt:
 * '#' comment lines; the patch count; one line of 16 one-based control
 * point indices per patch (row-major 4 x 4, u fastest); the point count;
 * one "x y z" line per point.
 */
#ifndef RAYES_IO_BPT_H
#define RAYES_IO_BPT_H

#include <stddef.h>

#include "io/sink.h"

/* Reads the file and sends its patches to the sink (which places
 * them with its current transform and shader). On a malformed file returns nonzero, adds
 * nothing, and fills err with one line "file:line:col: what was expected"
 * ("file:line:" for an index checked after reading). Running out of memory
 * while adding patches may leave the ones already added. */
RayesError io_read_bpt(const char *path, const IoSink *sink, char *err, size_t err_size);

/* The same from a buffer (for tests and fuzzing); name is used in errors. */
RayesError io_parse_bpt(const char *name, const char *text, size_t size, const IoSink *sink,
                        char *err, size_t err_size);

#endif /* RAYES_IO_BPT_H */
