/*
 * io/rib_lex.h — the RIB tokenizer (internal to the RIB reader): ASCII RIB
 * (comments, strings with escapes, numbers, brackets, request names) and
 * binary RIB (RISpec 3.2 Appendix C.2, byte codes 0200-0377), mixed freely
 * in one stream. Works on a bounded buffer (never reads past its end) and
 * reports "file:line:col: what was expected". Reentrant: every table
 * (encoded requests, encoded strings) lives in the RibLexer, one per file,
 * as a binary stream's definitions are local to the stream.
 *
 * Memory: token strings and float arrays live in buffers of the lexer and
 * are valid until the next rib_lex_next; rib_lex_fini frees everything.
 */
#ifndef RAYES_IO_RIB_LEX_H
#define RAYES_IO_RIB_LEX_H

#include <stddef.h>

typedef enum RibTokenType {
    RIB_TOK_EOF = 0,
    RIB_TOK_REQUEST,  /* a request name, ASCII or encoded (0246) */
    RIB_TOK_NUMBER,   /* num */
    RIB_TOK_STRING,   /* str (NUL-terminated, len bytes; may contain NULs in binary) */
    RIB_TOK_LBRACKET, /* '[' */
    RIB_TOK_RBRACKET, /* ']' */
    RIB_TOK_FLOATS    /* a binary float array (0310-0313): floats[0..n_floats) */
} RibTokenType;

typedef struct RibToken {
    RibTokenType type;
    double num;
    const char *str;
    size_t len;
    const float *floats;
    size_t n_floats;
    long line, col; /* where the token starts, 1-based */
} RibToken;

#define RIB_MAX_ENCODED_STRINGS 65536

typedef struct RibLexer {
    const char *name;                 /* file name for messages */
    const unsigned char *p, *end;
    long line;
    const unsigned char *line_start;
    char *requests[256];              /* encoded request names (0314), owned */
    char **strings;                   /* encoded strings (0315/0316), owned, lazily allocated */
    char *buf;                        /* the current token's text */
    size_t buf_cap;
    int in_definition;                /* reading the string of a definition (no nesting) */
    float *floats;                    /* the current binary float array */
    size_t floats_cap;
    char *err;
    size_t err_size;
} RibLexer;

void rib_lex_init(RibLexer *lx, const char *name, const unsigned char *data, size_t size,
                  char *err, size_t err_size);
void rib_lex_fini(RibLexer *lx);

/* The next token into *t; 0, or -1 with the lexer's err filled. */
int rib_lex_next(RibLexer *lx, RibToken *t);

/* Formats "name:line:col: message" into err; returns -1. */
int rib_lex_error_at(RibLexer *lx, long line, long col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif /* RAYES_IO_RIB_LEX_H */
