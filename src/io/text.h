/*
 * io/text.h — a small tokenizer for the line-oriented text formats: numbers
 * separated by white space, '#' comments to the end of the line, and errors
 * that name file:line:col and what was expected. Reentrant.
 */
#ifndef RAYES_IO_TEXT_H
#define RAYES_IO_TEXT_H

#include <stddef.h>

typedef struct TextReader {
    const char *name;   /* file name for errors */
    const char *p, *end;
    long line;          /* 1-based line of p; 0 in an error means "the file" */
    const char *line_start;
    char *err;
    size_t err_size;
} TextReader;

void text_init(TextReader *r, const char *name, const char *text, size_t size, char *err,
               size_t err_size);

/* Formats "name:line:col: message" into the reader's err; returns -1. */
int text_error(TextReader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The next integer in [lo, hi]; -1 with an error naming `what` otherwise. */
int text_long(TextReader *r, long *out, long lo, long hi, const char *what);

/* The next finite float; -1 with an error naming `what` otherwise. */
int text_float(TextReader *r, float *out, const char *what);

/* Nonzero if only white space and comments remain. */
int text_at_end(TextReader *r);

/* The whole file, NUL-terminated (new, free()), or NULL with err filled.
 * Read through zlib, which passes plain files through: gzip-compressed
 * files (pbrt-v4's `Include "hair.pbrt.gz"`) read as plain ones do. At
 * most TEXT_MAX_FILE_BYTES uncompressed. */
#define TEXT_MAX_FILE_BYTES ((size_t)4 << 30)
char *text_read_file(const char *path, size_t *size, char *err, size_t err_size);

#endif /* RAYES_IO_TEXT_H */
