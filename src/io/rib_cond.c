/*
 * io/rib_cond.c — the expressions of RIB's conditional blocks (IfBegin
 * and ElseIf, RenderMan 15 and later): numbers, 'strings' or "strings",
 * $variables and ${variables}, defined(name), ( ), !, comparisons
 * (== != < > <= >=) and && ||. No variable is defined here (rayes keeps
 * no user options), so defined() is false and a $variable is undefined,
 * which compares false with anything: "!defined(RMSTREE)" and
 * "!defined(user:pass) || $user:pass == 'beauty'" take their first
 * branch, as PRMan takes them when nothing sets those names.
 */
#include "io/rib_cond.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct Value {
    int kind; /* 0 undefined, 1 number, 2 string */
    double num;
    const char *s; /* a string: its first character in the expression */
    size_t n;
} Value;

typedef struct Cond {
    const char *p;
    int bad, depth;
} Cond;

static void skip_space(Cond *c)
{
    while (isspace((unsigned char)*c->p))
        c->p++;
}

static int accept(Cond *c, const char *op)
{
    skip_space(c);
    size_t n = strlen(op);
    if (strncmp(c->p, op, n) != 0)
        return 0;
    c->p += n;
    return 1;
}

static int truth(Value v)
{
    return v.kind == 1 ? v.num != 0 : v.kind == 2 ? v.n > 0 : 0;
}

static Value number(double x)
{
    return (Value){.kind = 1, .num = x};
}

static int name_char(int ch)
{
    return isalnum(ch) || ch == '_' || ch == ':' || ch == '.';
}

static Value expr_or(Cond *c);

static Value primary(Cond *c)
{
    skip_space(c);
    const char *p = c->p;
    if (*p == '(') {
        c->p++;
        if (++c->depth > 64) {
            c->bad = 1;
            return number(0);
        }
        Value v = expr_or(c);
        c->depth--;
        if (!accept(c, ")"))
            c->bad = 1;
        return v;
    }
    if (*p == '\'' || *p == '"') {
        const char *end = strchr(p + 1, *p);
        if (!end) {
            c->bad = 1;
            return number(0);
        }
        c->p = end + 1;
        return (Value){.kind = 2, .s = p + 1, .n = (size_t)(end - p - 1)};
    }
    if (*p == '$') { /* a variable: none is defined */
        p++;
        if (*p == '{') {
            const char *end = strchr(p, '}');
            if (!end) {
                c->bad = 1;
                return number(0);
            }
            c->p = end + 1;
        } else {
            while (name_char((unsigned char)*p))
                p++;
            c->p = p;
        }
        return (Value){.kind = 0};
    }
    if (isdigit((unsigned char)*p) || *p == '.' || *p == '-' || *p == '+') {
        char *end;
        double x = strtod(p, &end);
        if (end == p) {
            c->bad = 1;
            return number(0);
        }
        c->p = end;
        return number(x);
    }
    if (strncmp(p, "defined", 7) == 0) {
        c->p = p + 7;
        if (!accept(c, "(")) {
            c->bad = 1;
            return number(0);
        }
        skip_space(c);
        while (name_char((unsigned char)*c->p))
            c->p++;
        if (!accept(c, ")"))
            c->bad = 1;
        return number(0);
    }
    if (strncmp(p, "true", 4) == 0 && !name_char((unsigned char)p[4])) {
        c->p = p + 4;
        return number(1);
    }
    if (strncmp(p, "false", 5) == 0 && !name_char((unsigned char)p[5])) {
        c->p = p + 5;
        return number(0);
    }
    c->bad = 1; /* a function or word this reader does not know */
    return number(0);
}

static Value unary(Cond *c)
{
    if (accept(c, "!")) {
        if (++c->depth > 64) {
            c->bad = 1;
            return number(0);
        }
        Value v = unary(c);
        c->depth--;
        return number(!truth(v));
    }
    return primary(c);
}

/* a op b; an undefined side compares false (true for !=) */
static Value compare(Value a, const char *op, Value b)
{
    int ne = strcmp(op, "!=") == 0;
    if (a.kind == 0 || b.kind == 0)
        return number(ne);
    double d;
    if (a.kind == 1 && b.kind == 1) {
        d = a.num < b.num ? -1 : a.num > b.num ? 1 : 0;
    } else {
        char x[256], y[256];
        if (a.kind == 1)
            snprintf(x, sizeof x, "%g", a.num);
        else
            snprintf(x, sizeof x, "%.*s", (int)(a.n < 255 ? a.n : 255), a.s);
        if (b.kind == 1)
            snprintf(y, sizeof y, "%g", b.num);
        else
            snprintf(y, sizeof y, "%.*s", (int)(b.n < 255 ? b.n : 255), b.s);
        d = strcmp(x, y);
    }
    if (strcmp(op, "==") == 0)
        return number(d == 0);
    if (ne)
        return number(d != 0);
    if (strcmp(op, "<=") == 0)
        return number(d <= 0);
    if (strcmp(op, ">=") == 0)
        return number(d >= 0);
    return number(op[0] == '<' ? d < 0 : d > 0);
}

static Value expr_cmp(Cond *c)
{
    Value a = unary(c);
    static const char *const ops[] = {"==", "!=", "<=", ">=", "<", ">"};
    for (int k = 0; k < 6; k++)
        if (accept(c, ops[k]))
            return compare(a, ops[k], unary(c));
    return a;
}

static Value expr_and(Cond *c)
{
    Value a = expr_cmp(c);
    while (accept(c, "&&")) {
        Value b = expr_cmp(c);
        a = number(truth(a) && truth(b));
    }
    return a;
}

static Value expr_or(Cond *c)
{
    Value a = expr_and(c);
    while (accept(c, "||")) {
        Value b = expr_and(c);
        a = number(truth(a) || truth(b));
    }
    return a;
}

int rib_condition(const char *expr, int *value)
{
    Cond c = {.p = expr};
    Value v = expr_or(&c);
    skip_space(&c);
    if (c.bad || *c.p) {
        *value = 1;
        return -1;
    }
    *value = truth(v);
    return 0;
}
