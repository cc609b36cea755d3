/*
 * io/rib_lex.c — see rib_lex.h. Binary codes (RISpec 3.2 Appendix C.2):
 *   0200-0203        integer of 1-4 bytes, big-endian, two's complement
 *   0204-0217        fixed point: 0200 + 4d + w, w+1 bytes, d of them fraction
 *   0220-0237        string of 0-15 bytes
 *   0240-0243        string whose length takes 1-4 bytes
 *   0244, 0245       float32, float64 (big-endian IEEE)
 *   0246 c           encoded request c
 *   0310-0313        float32 array whose length takes 1-4 bytes
 *   0314 c s         defines encoded request c as string s
 *   0315, 0316 n s   defines encoded string n (1 or 2 bytes) as string s
 *   0317, 0320 n     encoded string n
 * Everything else from 0200 up is reserved and an error; bytes below 0200
 * are ASCII RIB.
 */
#include "io/rib_lex.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RIB_MAX_TOKEN_BYTES (64u << 20) /* one string or float array */

void rib_lex_init(RibLexer *lx, const char *name, const unsigned char *data, size_t size,
                  char *err, size_t err_size)
{
    memset(lx, 0, sizeof *lx);
    lx->name = name;
    lx->p = data;
    lx->end = data + size;
    lx->line = 1;
    lx->line_start = data;
    lx->err = err;
    lx->err_size = err_size;
}

void rib_lex_fini(RibLexer *lx)
{
    for (int i = 0; i < 256; i++)
        free(lx->requests[i]);
    if (lx->strings) {
        for (size_t i = 0; i < RIB_MAX_ENCODED_STRINGS; i++)
            free(lx->strings[i]);
        free(lx->strings);
    }
    free(lx->buf);
    free(lx->floats);
    memset(lx, 0, sizeof *lx);
}

int rib_lex_error_at(RibLexer *lx, long line, long col, const char *fmt, ...)
{
    char msg[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(lx->err, lx->err_size, "%s:%ld:%ld: %s", lx->name, line, col, msg);
    return -1;
}

static long col_of(const RibLexer *lx, const unsigned char *p)
{
    return (long)(p - lx->line_start) + 1;
}

static int lex_error(RibLexer *lx, const unsigned char *at, const char *what)
{
    return rib_lex_error_at(lx, lx->line, col_of(lx, at), "%s", what);
}

static int buf_reserve(RibLexer *lx, size_t n)
{
    if (n <= lx->buf_cap)
        return 0;
    size_t cap = lx->buf_cap ? lx->buf_cap : 64;
    while (cap < n)
        cap *= 2;
    char *b = realloc(lx->buf, cap);
    if (!b)
        return -1;
    lx->buf = b;
    lx->buf_cap = cap;
    return 0;
}

static int is_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || c == 0;
}

/* An unsigned big-endian integer of n (1-4) bytes; -1 if the input ends. */
static int read_uint(RibLexer *lx, int n, uint32_t *out)
{
    if (lx->end - lx->p < n)
        return -1;
    uint32_t v = 0;
    for (int i = 0; i < n; i++)
        v = v << 8 | *lx->p++;
    *out = v;
    return 0;
}

static int set_string(RibLexer *lx, RibToken *t, const unsigned char *s, size_t n)
{
    if (buf_reserve(lx, n + 1) != 0)
        return lex_error(lx, lx->p, "out of memory for a string");
    memcpy(lx->buf, s, n);
    lx->buf[n] = '\0';
    t->type = RIB_TOK_STRING;
    t->str = lx->buf;
    t->len = n;
    return 0;
}

/* A binary string token (0220-0243) at *p; sets the token. */
static int binary_string(RibLexer *lx, RibToken *t, int code, const unsigned char *at)
{
    uint32_t n;
    if (code < 0240)
        n = (uint32_t)(code - 0220);
    else if (read_uint(lx, code - 0240 + 1, &n) != 0)
        return lex_error(lx, at, "the file ends inside a binary string length");
    if ((size_t)(lx->end - lx->p) < n)
        return lex_error(lx, at, "the file ends inside a binary string");
    if (n > RIB_MAX_TOKEN_BYTES)
        return lex_error(lx, at, "a binary string longer than 64 MB");
    int e = set_string(lx, t, lx->p, n);
    lx->p += n;
    return e;
}

static float float_of_bits(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static int binary_float_array(RibLexer *lx, RibToken *t, int code, const unsigned char *at)
{
    uint32_t n;
    if (read_uint(lx, code - 0310 + 1, &n) != 0)
        return lex_error(lx, at, "the file ends inside a binary float array length");
    if ((size_t)(lx->end - lx->p) / 4 < n)
        return lex_error(lx, at, "the file ends inside a binary float array");
    if (n > lx->floats_cap) {
        float *f = realloc(lx->floats, (size_t)n * sizeof *f);
        if (!f)
            return lex_error(lx, at, "out of memory for a float array");
        lx->floats = f;
        lx->floats_cap = n;
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t bits = 0;
        read_uint(lx, 4, &bits);
        lx->floats[i] = float_of_bits(bits);
    }
    t->type = RIB_TOK_FLOATS;
    t->floats = lx->floats;
    t->n_floats = n;
    return 0;
}

/* The string of a definition (0314-0316): the next token, which must be a
 * string; returns a new copy or NULL with err filled. */
static char *definition_string(RibLexer *lx, const unsigned char *at, const char *what)
{
    RibToken s;
    lx->in_definition = 1;
    int e = rib_lex_next(lx, &s);
    lx->in_definition = 0;
    if (e != 0)
        return NULL;
    if (s.type != RIB_TOK_STRING) {
        lex_error(lx, at, what);
        return NULL;
    }
    char *copy = malloc(s.len + 1);
    if (!copy) {
        lex_error(lx, at, "out of memory");
        return NULL;
    }
    memcpy(copy, s.str, s.len + 1);
    return copy;
}

/* One binary token at lx->p (a byte >= 0200). Returns 1 for a definition
 * (no token: the caller goes on), 0 for a token, -1 for an error. */
static int binary_token(RibLexer *lx, RibToken *t)
{
    const unsigned char *at = lx->p;
    int code = *lx->p++;
    uint32_t u;
    if (code <= 0217) {
        int w = (code - 0200) & 3, d = (code - 0200) >> 2;
        if (read_uint(lx, w + 1, &u) != 0)
            return lex_error(lx, at, "the file ends inside a binary number");
        int bits = 8 * (w + 1);
        int64_t v = (int64_t)u;
        if (bits < 64 && (u >> (bits - 1)) & 1)
            v -= (int64_t)1 << bits;
        t->type = RIB_TOK_NUMBER;
        t->num = ldexp((double)v, -8 * d);
        return 0;
    }
    if (code <= 0243)
        return binary_string(lx, t, code, at);
    if (code == 0244 || code == 0245) {
        uint32_t hi, lo = 0;
        if (read_uint(lx, 4, &hi) != 0 || (code == 0245 && read_uint(lx, 4, &lo) != 0))
            return lex_error(lx, at, "the file ends inside a binary float");
        t->type = RIB_TOK_NUMBER;
        if (code == 0244) {
            t->num = float_of_bits(hi);
        } else {
            uint64_t b = (uint64_t)hi << 32 | lo;
            double dv;
            memcpy(&dv, &b, sizeof dv);
            t->num = dv;
        }
        return 0;
    }
    if (code == 0246) {
        if (read_uint(lx, 1, &u) != 0)
            return lex_error(lx, at, "the file ends inside an encoded request");
        if (!lx->requests[u])
            return rib_lex_error_at(lx, lx->line, col_of(lx, at),
                                    "encoded request %u was not defined (0314)", (unsigned)u);
        t->type = RIB_TOK_REQUEST;
        t->str = lx->requests[u];
        t->len = strlen(t->str);
        return 0;
    }
    if (code >= 0310 && code <= 0313)
        return binary_float_array(lx, t, code, at);
    if (lx->in_definition && code >= 0314 && code <= 0316)
        return lex_error(lx, at, "a binary definition inside a definition");
    if (code == 0314) {
        if (read_uint(lx, 1, &u) != 0)
            return lex_error(lx, at, "the file ends inside an encoded request definition");
        char *s = definition_string(lx, at, "expected a string naming the encoded request");
        if (!s)
            return -1;
        if (!s[0] || strlen(s) > 63) {
            free(s);
            return lex_error(lx, at, "an encoded request name must have 1 to 63 characters");
        }
        free(lx->requests[u]);
        lx->requests[u] = s;
        return 1;
    }
    if (code == 0315 || code == 0316 || code == 0317 || code == 0320) {
        int def = code <= 0316;
        if (read_uint(lx, def ? code - 0315 + 1 : code - 0317 + 1, &u) != 0)
            return lex_error(lx, at, "the file ends inside an encoded string number");
        if (!lx->strings) {
            lx->strings = calloc(RIB_MAX_ENCODED_STRINGS, sizeof *lx->strings);
            if (!lx->strings)
                return lex_error(lx, at, "out of memory");
        }
        if (def) {
            char *s = definition_string(lx, at, "expected a string for the encoded string");
            if (!s)
                return -1;
            free(lx->strings[u]);
            lx->strings[u] = s;
            return 1;
        }
        if (!lx->strings[u])
            return rib_lex_error_at(lx, lx->line, col_of(lx, at),
                                    "encoded string %u was not defined (0315)", (unsigned)u);
        t->type = RIB_TOK_STRING;
        t->str = lx->strings[u];
        t->len = strlen(t->str);
        return 0;
    }
    return rib_lex_error_at(lx, lx->line, col_of(lx, at), "reserved binary RIB byte 0%o", code);
}

/* A string between double quotes or, as PRMan also reads them (Python
 * exporters write them: LegoToR's ['name']), single quotes. */
static int ascii_string(RibLexer *lx, RibToken *t)
{
    const unsigned char *at = lx->p++;
    long line0 = lx->line, col0 = col_of(lx, at);
    int quote = *at;
    size_t n = 0;
    for (;;) {
        if (lx->p >= lx->end)
            return rib_lex_error_at(lx, line0, col0, "the string has no closing '%c'", quote);
        if (buf_reserve(lx, n + 2) != 0)
            return lex_error(lx, at, "out of memory for a string");
        if (n > RIB_MAX_TOKEN_BYTES)
            return lex_error(lx, at, "a string longer than 64 MB");
        int c = *lx->p++;
        if (c == quote)
            break;
        if (c == '\n') {
            lx->line++;
            lx->line_start = lx->p;
        }
        if (c == '\\' && lx->p < lx->end) {
            c = *lx->p++;
            switch (c) {
            case 'n': c = '\n'; break;
            case 'r': c = '\r'; break;
            case 't': c = '\t'; break;
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case '\n':
                lx->line++;
                lx->line_start = lx->p;
                continue;
            default:
                if (c >= '0' && c <= '7') {
                    int v = c - '0';
                    for (int k = 0; k < 2 && lx->p < lx->end && *lx->p >= '0' && *lx->p <= '7'; k++)
                        v = v * 8 + (*lx->p++ - '0');
                    c = v & 0xff;
                }
            }
        }
        lx->buf[n++] = (char)c;
    }
    lx->buf[n] = '\0';
    t->type = RIB_TOK_STRING;
    t->str = lx->buf;
    t->len = n;
    return 0;
}

static int ascii_number(RibLexer *lx, RibToken *t)
{
    const unsigned char *at = lx->p, *q = lx->p;
    char tmp[64];
    size_t n = 0;
    while (q < lx->end && n < sizeof tmp - 1 &&
           ((*q >= '0' && *q <= '9') || *q == '.' || *q == '-' || *q == '+' || *q == 'e' ||
            *q == 'E'))
        tmp[n++] = (char)*q++;
    tmp[n] = '\0';
    char *stop;
    double v = strtod(tmp, &stop);
    if (stop == tmp || (size_t)(stop - tmp) != n || !isfinite(v))
        return rib_lex_error_at(lx, lx->line, col_of(lx, at), "expected a number, found '%s'", tmp);
    lx->p = q;
    t->type = RIB_TOK_NUMBER;
    t->num = v;
    return 0;
}

static int ascii_request(RibLexer *lx, RibToken *t)
{
    const unsigned char *q = lx->p;
    while (q < lx->end && *q < 0200 && !is_space(*q) && *q != '#' && *q != '"' && *q != '\'' &&
           *q != '[' && *q != ']')
        q++;
    size_t n = (size_t)(q - lx->p);
    if (n > 63)
        return lex_error(lx, lx->p, "a request name longer than 63 characters");
    int e = set_string(lx, t, lx->p, n);
    lx->p = q;
    t->type = RIB_TOK_REQUEST;
    return e;
}

int rib_lex_next(RibLexer *lx, RibToken *t)
{
    for (;;) {
        while (lx->p < lx->end && *lx->p < 0200 && is_space(*lx->p)) {
            if (*lx->p++ == '\n') {
                lx->line++;
                lx->line_start = lx->p;
            }
        }
        memset(t, 0, sizeof *t);
        t->line = lx->line;
        t->col = col_of(lx, lx->p);
        if (lx->p >= lx->end) {
            t->type = RIB_TOK_EOF;
            return 0;
        }
        int c = *lx->p;
        if (c == '#') {
            while (lx->p < lx->end && *lx->p != '\n')
                lx->p++;
            continue;
        }
        if (c >= 0200) {
            int e = binary_token(lx, t);
            if (e == 1)
                continue;
            return e;
        }
        if (c == '"' || c == '\'')
            return ascii_string(lx, t);
        if (c == '[' || c == ']') {
            lx->p++;
            t->type = c == '[' ? RIB_TOK_LBRACKET : RIB_TOK_RBRACKET;
            return 0;
        }
        if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.')
            return ascii_number(lx, t);
        if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_')
            return ascii_request(lx, t);
        return rib_lex_error_at(lx, lx->line, col_of(lx, lx->p),
                                "unexpected character 0x%02x (expected a request, a number, a "
                                "string or a bracket)",
                                c);
    }
}
