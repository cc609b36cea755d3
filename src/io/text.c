/*
 * io/text.c — see text.h. Tokens are parsed from a bounded buffer: a token
 * is copied (at most 63 characters) before strtol/strtod see it, so a file
 * without a final newline or NUL is never read past its end.
 */
#include "io/text.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

void text_init(TextReader *r, const char *name, const char *text, size_t size, char *err,
               size_t err_size)
{
    r->name = name;
    r->p = text;
    r->end = text + size;
    r->line = 1;
    r->line_start = text;
    r->err = err;
    r->err_size = err_size;
}

int text_error(TextReader *r, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->line > 0)
        snprintf(r->err, r->err_size, "%s:%ld:%ld: %s", r->name, r->line,
                 (long)(r->p - r->line_start) + 1, msg);
    else
        snprintf(r->err, r->err_size, "%s: %s", r->name, msg);
    return -1;
}

static void skip_space(TextReader *r)
{
    while (r->p < r->end) {
        char c = *r->p;
        if (c == '\n') {
            r->p++;
            r->line++;
            r->line_start = r->p;
        } else if (c == '#') {
            while (r->p < r->end && *r->p != '\n')
                r->p++;
        } else if (isspace((unsigned char)c)) {
            r->p++;
        } else {
            break;
        }
    }
}

/* Copies the next token into buf; returns its length (0 at the end). */
static size_t token(TextReader *r, char *buf, size_t size)
{
    skip_space(r);
    size_t n = 0;
    const char *q = r->p;
    while (q < r->end && !isspace((unsigned char)*q) && *q != '#') {
        if (n + 1 < size)
            buf[n] = *q;
        n++;
        q++;
    }
    buf[n < size ? n : size - 1] = '\0';
    return n;
}

static int describe_token(TextReader *r, const char *tok, size_t n, const char *what)
{
    if (n == 0)
        return text_error(r, "expected %s, found the end of the file", what);
    char shown[24]; /* printable ASCII only: errors are one clean line */
    size_t k = 0;
    for (; k < 20 && tok[k]; k++)
        shown[k] = tok[k] >= 0x20 && tok[k] < 0x7f && tok[k] != '"' ? tok[k] : '?';
    shown[k] = '\0';
    return text_error(r, "expected %s, found \"%s%s\"", what, shown, n > 20 ? "..." : "");
}

int text_long(TextReader *r, long *out, long lo, long hi, const char *what)
{
    char tok[64];
    size_t n = token(r, tok, sizeof tok);
    char *endp;
    errno = 0;
    long v = n > 0 && n < sizeof tok ? strtol(tok, &endp, 10) : 0;
    if (n == 0 || n >= sizeof tok || *endp != '\0' || errno != 0)
        return describe_token(r, tok, n, what);
    if (v < lo || v > hi)
        return text_error(r, "expected %s from %ld to %ld, found %ld", what, lo, hi, v);
    r->p += n;
    *out = v;
    return 0;
}

int text_float(TextReader *r, float *out, const char *what)
{
    char tok[64];
    size_t n = token(r, tok, sizeof tok);
    char *endp;
    errno = 0;
    double v = n > 0 && n < sizeof tok ? strtod(tok, &endp) : 0.0;
    if (n == 0 || n >= sizeof tok || *endp != '\0' || !isfinite(v) || fabs(v) > 1e30)
        return describe_token(r, tok, n, what);
    r->p += n;
    *out = (float)v;
    return 0;
}

int text_at_end(TextReader *r)
{
    skip_space(r);
    return r->p >= r->end;
}

char *text_read_file(const char *path, size_t *size, char *err, size_t err_size)
{
    errno = 0;
    gzFile f = gzopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open: %s", path,
                 errno ? strerror(errno) : "out of memory");
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    const char *why = buf ? NULL : "out of memory";
    while (!why) {
        if (n + 1 >= cap) {
            char *b = cap >= TEXT_MAX_FILE_BYTES ? NULL : realloc(buf, cap * 2);
            if (!b) {
                why = cap >= TEXT_MAX_FILE_BYTES ? "larger than 4 GB" : "out of memory";
                break;
            }
            buf = b;
            cap *= 2;
        }
        size_t want = cap - 1 - n > (1u << 30) ? (1u << 30) : cap - 1 - n;
        int got = gzread(f, buf + n, (unsigned)want);
        if (got < 0) {
            int code;
            why = gzerror(f, &code);
            break;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    gzclose(f);
    if (why) {
        snprintf(err, err_size, "%s: %s", path, why);
        free(buf);
        return NULL;
    }
    buf[n] = '\0';
    *size = n;
    return buf;
}
