/*
 * io/bpt.c — the patch file reader of bpt.h. The whole file is parsed and
 * checked (counts, index ranges, finite numbers, nothing left over) before
 * any patch reaches the scene, so bad input adds nothing.
 */
#include "io/bpt.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/text.h"

#define MAX_BPT_COUNT 10000000L

typedef struct Bpt {
    long n_patches, n_points;
    long *index;   /* 16 per patch, zero-based */
    long *line;    /* line of each index, for errors found after reading */
    float *points; /* 3 per point */
} Bpt;

static int parse(TextReader *r, Bpt *b)
{
    /* Counts are capped by the bytes left in the input (a patch or a point
     * needs several), so a tiny file cannot ask for a huge allocation, while
     * a merely truncated file still gets "found the end of the file". */
    long room = (long)(r->end - r->p);
    if (text_long(r, &b->n_patches, 1, MAX_BPT_COUNT, "a patch count") != 0)
        return -1;
    if (b->n_patches > room + 16)
        return text_error(r, "the patch count %ld is larger than the file can hold", b->n_patches);
    b->index = malloc((size_t)b->n_patches * 16 * sizeof *b->index);
    b->line = malloc((size_t)b->n_patches * 16 * sizeof *b->line);
    if (!b->index || !b->line)
        return text_error(r, "out of memory for %ld patches", b->n_patches);
    for (long p = 0; p < b->n_patches; p++)
        for (int k = 0; k < 16; k++) {
            long v;
            if (text_long(r, &v, 1, MAX_BPT_COUNT, "a control point index (16 per patch)") != 0)
                return -1;
            b->index[p * 16 + k] = v - 1;
            b->line[p * 16 + k] = r->line;
        }
    room = (long)(r->end - r->p);
    if (text_long(r, &b->n_points, 1, MAX_BPT_COUNT, "a point count") != 0)
        return -1;
    if (b->n_points > room + 16)
        return text_error(r, "the point count %ld is larger than the file can hold", b->n_points);
    b->points = malloc((size_t)b->n_points * 3 * sizeof *b->points);
    if (!b->points)
        return text_error(r, "out of memory for %ld points", b->n_points);
    for (long i = 0; i < 3 * b->n_points; i++)
        if (text_float(r, &b->points[i], "a coordinate (x y z per point)") != 0)
            return -1;
    if (!text_at_end(r))
        return text_error(r, "expected the end of the file after %ld points", b->n_points);
    for (long i = 0; i < 16 * b->n_patches; i++)
        if (b->index[i] >= b->n_points) {
            r->line = b->line[i];
            r->p = r->line_start = r->end; /* no column: the token is long gone */
            snprintf(r->err, r->err_size, "%s:%ld: patch %ld uses point %ld but the file has %ld points",
                     r->name, r->line, i / 16 + 1, b->index[i] + 1, b->n_points);
            return -1;
        }
    return 0;
}

RayesError io_parse_bpt(const char *name, const char *text, size_t size, const IoSink *sink,
                        char *err, size_t err_size)
{
    TextReader r;
    text_init(&r, name, text, size, err, err_size);
    Bpt b = {0};
    RayesError e = RAYES_OK;
    if (parse(&r, &b) != 0)
        e = RAYES_ERROR_PARSE;
    for (long p = 0; e == RAYES_OK && p < b.n_patches; p++) {
        float P[16][3];
        for (int k = 0; k < 16; k++)
            memcpy(P[k], &b.points[3 * b.index[p * 16 + k]], sizeof P[k]);
        e = sink->bicubic_patch(sink->target, (const float(*)[3])P, NULL, 0);
        if (e != RAYES_OK)
            snprintf(err, err_size, "%s: %s", name, sink->get_error(sink->target));
    }
    free(b.index);
    free(b.line);
    free(b.points);
    return e;
}

RayesError io_read_bpt(const char *path, const IoSink *sink, char *err, size_t err_size)
{
    size_t size;
    char *text = text_read_file(path, &size, err, err_size);
    if (!text)
        return RAYES_ERROR_IO;
    RayesError e = io_parse_bpt(path, text, size, sink, err, err_size);
    free(text);
    return e;
}
