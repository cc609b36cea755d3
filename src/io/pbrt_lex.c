/*
 * io/pbrt_lex.c — what every file of the pbrt-v4 reader uses: messages
 * (errors naming file:line:col, warnings once per kind and read), the
 * tokens of a file and its numbers and strings, 4 x 4 matrices, paths
 * relative to the reading file, and the named coordinate systems. It calls
 * no other file of the reader.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "io/text.h"
#include "util/log.h"

/* ------------------------------------------------------------ messages */

/* Messages are one line: names from the file may hold escaped newlines. */
static void one_line(char *msg)
{
    for (; *msg; msg++)
        if ((unsigned char)*msg < 0x20 || *msg == 0x7f)
            *msg = '?';
}

int pbrt_fail_at(Parser *P, long line, long col, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    one_line(msg);
    snprintf(P->err, P->err_size, "%s:%ld:%ld: %s", P->lx->name, line, col, msg);
    return -1;
}

void pbrt_warn_at(Parser *P, long line, long col, const char *key, const char *fmt, ...)
{
    for (size_t i = 0; i < P->n_warned; i++)
        if (strncmp(P->warned[i], key, sizeof P->warned[i] - 1) == 0)
            return;
    if (P->n_warned >= PBRT_MAX_WARNED)
        return;
    snprintf(P->warned[P->n_warned++], sizeof P->warned[0], "%s", key);
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    one_line(msg);
    log_warning("%s:%ld:%ld: %s", P->lx->name, line, col, msg);
}

/* A printable copy of a token for messages (at most 40 characters). */
const char *pbrt_shown(const Token *t, char buf[48])
{
    if (t->kind == TOK_END)
        return "the end of the file";
    size_t k = 0;
    buf[k++] = '"';
    for (size_t i = 0; i < t->n && k < 42; i++)
        buf[k++] = t->s[i] >= 0x20 && t->s[i] < 0x7f && t->s[i] != '"' ? t->s[i] : '?';
    if (t->n > 40) {
        buf[k - 1] = '.';
    }
    buf[k++] = '"';
    buf[k] = '\0';
    return buf;
}

/* ------------------------------------------------------------ lexer */

static void skip_space(Lexer *l)
{
    while (l->p < l->end) {
        char c = *l->p;
        if (c == '\n') {
            l->p++;
            l->line++;
            l->line_start = l->p;
        } else if (c == '#') {
            while (l->p < l->end && *l->p != '\n')
                l->p++;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            l->p++;
        } else {
            break;
        }
    }
}

static int lex(Parser *P, Token *t)
{
    Lexer *l = P->lx;
    skip_space(l);
    t->line = l->line;
    t->col = (long)(l->p - l->line_start) + 1;
    t->s = l->p;
    t->n = 0;
    if (l->p >= l->end) {
        if (l->parent) {
            /* an included file ends: the tokens go on in the file that
             * included it, the last directive's parameters too */
            P->lx = l->parent;
            P->depth--;
            return lex(P, t);
        }
        t->kind = TOK_END;
        return 0;
    }
    char c = *l->p;
    if (c == '[' || c == ']') {
        t->kind = c == '[' ? TOK_LBRACKET : TOK_RBRACKET;
        t->n = 1;
        l->p++;
        return 0;
    }
    if (c == '"') {
        const char *q = ++l->p;
        while (q < l->end && *q != '"' && *q != '\n') {
            if (*q == '\\' && q + 1 < l->end && q[1] != '\n')
                q++;
            q++;
        }
        if (q >= l->end || *q != '"')
            return FAIL_TOK(P, t, "expected a closing quote before the end of the line");
        t->kind = TOK_STRING;
        t->s = l->p;
        t->n = (size_t)(q - l->p);
        l->p = q + 1;
        return 0;
    }
    const char *q = l->p;
    while (q < l->end && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n' && *q != '\f' &&
           *q != '\v' && *q != '"' && *q != '[' && *q != ']' && *q != '#')
        q++;
    t->kind = TOK_WORD;
    t->n = (size_t)(q - l->p);
    l->p = q;
    return 0;
}

int pbrt_next(Parser *P, Token *t)
{
    if (P->has_peek) {
        *t = P->peeked;
        P->has_peek = 0;
        return 0;
    }
    return lex(P, t);
}

int pbrt_peek(Parser *P, Token *t)
{
    if (!P->has_peek) {
        if (lex(P, &P->peeked) != 0)
            return -1;
        P->has_peek = 1;
    }
    *t = P->peeked;
    return 0;
}

int pbrt_word_is(const Token *t, const char *w)
{
    return t->kind == TOK_WORD && t->n == strlen(w) && memcmp(t->s, w, t->n) == 0;
}

/* The string's contents with escapes resolved, into buf (error if long). */
int pbrt_string_value(Parser *P, const Token *t, char *buf, size_t size)
{
    size_t k = 0;
    for (size_t i = 0; i < t->n; i++) {
        char c = t->s[i];
        if (c == '\\' && i + 1 < t->n) {
            c = t->s[++i];
            c = c == 'n' ? '\n' : c == 't' ? '\t' : c == 'r' ? '\r' : c;
        }
        if (c == '\0')
            return FAIL_TOK(P, t, "expected a string without NUL characters");
        if (k + 1 >= size)
            return FAIL_TOK(P, t, "expected a string of at most %zu characters", size - 1);
        buf[k++] = c;
    }
    buf[k] = '\0';
    return 0;
}

int pbrt_parse_number(const Token *t, double *out)
{
    char buf[64];
    if (t->kind != TOK_WORD || t->n == 0 || t->n >= sizeof buf)
        return -1;
    memcpy(buf, t->s, t->n);
    buf[t->n] = '\0';
    char *endp;
    errno = 0;
    double v = strtod(buf, &endp);
    if (*endp != '\0' || errno != 0 || !isfinite(v) || fabs(v) > 1e30)
        return -1;
    *out = v;
    return 0;
}

int pbrt_expect_number(Parser *P, double *out, const char *what)
{
    Token t;
    char b[48];
    if (pbrt_next(P, &t) != 0)
        return -1;
    if (pbrt_parse_number(&t, out) != 0)
        return FAIL_TOK(P, &t, "expected %s, found %s", what, pbrt_shown(&t, b));
    return 0;
}

int pbrt_expect_string(Parser *P, char *buf, size_t size, const char *what, Token *where)
{
    Token t;
    char b[48];
    if (pbrt_next(P, &t) != 0)
        return -1;
    if (where)
        *where = t;
    if (t.kind != TOK_STRING)
        return FAIL_TOK(P, &t, "expected %s (a quoted string), found %s", what, pbrt_shown(&t, b));
    return pbrt_string_value(P, &t, buf, size);
}

/* n numbers, optionally between brackets. */
int pbrt_expect_numbers(Parser *P, double *out, int n, const char *what)
{
    Token t;
    if (pbrt_peek(P, &t) != 0)
        return -1;
    int bracket = t.kind == TOK_LBRACKET;
    if (bracket)
        pbrt_next(P, &t);
    for (int i = 0; i < n; i++)
        if (pbrt_expect_number(P, &out[i], what) != 0)
            return -1;
    if (bracket) {
        char b[48];
        if (pbrt_next(P, &t) != 0)
            return -1;
        if (t.kind != TOK_RBRACKET)
            return FAIL_TOK(P, &t, "expected \"]\" after %d numbers, found %s", n,
                            pbrt_shown(&t, b));
    }
    return 0;
}

/* ------------------------------------------------------------ matrices */

void pbrt_mat_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1;
}

void pbrt_mat_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = s;
        }
    memcpy(out, r, sizeof r);
}

double pbrt_mat_det3(const double m[16])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

/* Gauss-Jordan with partial pivoting; -1 if singular. */
int pbrt_mat_inverse(const double m[16], double out[16])
{
    double a[4][8];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 8; j++)
            a[i][j] = j < 4 ? m[4 * i + j] : (j - 4 == i);
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (!(fabs(a[piv][c]) > 1e-300))
            return -1;
        for (int j = 0; j < 8; j++) {
            double t = a[c][j];
            a[c][j] = a[piv][j];
            a[piv][j] = t;
        }
        double d = a[c][c];
        for (int j = 0; j < 8; j++)
            a[c][j] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int j = 0; j < 8; j++)
                    a[r][j] -= f * a[c][j];
            }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            out[4 * i + j] = a[i][j + 4];
    return 0;
}

int pbrt_mat_finite(const double m[16])
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i]) || fabs(m[i]) > 1e30)
            return 0;
    return 1;
}

void pbrt_mat_to_float(const double m[16], float out[16])
{
    for (int i = 0; i < 16; i++)
        out[i] = (float)m[i];
}

void pbrt_cross3d(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

double pbrt_dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* ------------------------------------------------------------ paths */

int pbrt_resolve(Parser *P, const Token *t, const char *file, char *out, size_t size)
{
    int n = file[0] == '/' || !P->lx->dir[0] ? snprintf(out, size, "%s", file)
                                             : snprintf(out, size, "%s/%s", P->lx->dir, file);
    if (n < 0 || (size_t)n >= size)
        return FAIL_TOK(P, t, "the path \"%.40s...\" is too long", file);
    return 0;
}

/* ------------------------------------------------------------ state */

int pbrt_need_world(Parser *P, const Token *t, int inside)
{
    if (P->world != inside)
        return FAIL_TOK(P, t, inside ? "expected WorldBegin before this directive"
                                     : "expected this directive before WorldBegin");
    return 0;
}

int pbrt_set_coordsys(Parser *P, const Token *t, const char *name, const double m[16])
{
    for (size_t i = 0; i < P->n_coordsys; i++)
        if (strcmp(P->coordsys[i].name, name) == 0) {
            memcpy(P->coordsys[i].m, m, sizeof P->coordsys[i].m);
            return 0;
        }
    if ((P->n_coordsys & (P->n_coordsys - 1)) == 0) {
        Named *n = realloc(P->coordsys, (P->n_coordsys ? 2 * P->n_coordsys : 1) * sizeof *n);
        if (!n)
            return FAIL_TOK(P, t, "out of memory");
        P->coordsys = n;
    }
    Named *c = &P->coordsys[P->n_coordsys++];
    snprintf(c->name, sizeof c->name, "%s", name);
    memcpy(c->m, m, sizeof c->m);
    return 0;
}
