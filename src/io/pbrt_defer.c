/*
 * io/pbrt_defer.c — forward references of the pbrt reader
 * (pbrt_internal.h). pbrt-v4 reads the whole file before it makes named
 * materials and textures and then its shapes, so a file may use a name
 * before defining it: pbrt-v4-scenes' contemporary bathroom gives its
 * lights `NamedMaterial "light"` before it includes its materials, and the
 * watercolor scene's materials name textures defined further down.
 *
 * rayes streams shapes to the sink as it reads them, so a directive that
 * needs a name not yet defined is read again later, from a copy of its
 * lexer (every file's text lives until the parse ends) and the graphics
 * state it was read in: a Shape whose NamedMaterial is undefined at the
 * file's end, with the material it names then (pbrt_shape.c); a
 * MakeNamedMaterial that names an undefined texture (or a mix an undefined
 * material) when a NamedMaterial first asks for it (pbrt_material.c). A
 * name still undefined then is the error pbrt gives, at the NamedMaterial
 * (or the texture's parameter) that used it; a NamedMaterial no shape
 * follows is no error, as in pbrt. This file holds what both use: the
 * lists of deferred directives and reading one again.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

/* Directives deferred at most per list: each holds a graphics state
 * (about 4 KB), so at most about 1 GB. */
#define PBRT_MAX_DEFERRED (1u << 18)

Deferred *pbrt_defer(Parser *P, DeferList *list, const Lexer *at, const Token *t)
{
    if (list->n >= PBRT_MAX_DEFERRED) {
        FAIL_TOK(P, t, "more than %u directives wait for a name defined later", PBRT_MAX_DEFERRED);
        return NULL;
    }
    if (list->n == list->cap) {
        size_t c = list->cap ? 2 * list->cap : 16;
        Deferred *d = realloc(list->d, c * sizeof *d);
        if (!d) {
            FAIL_TOK(P, t, "out of memory");
            return NULL;
        }
        list->d = d, list->cap = c;
    }
    Deferred *d = &list->d[list->n++];
    memset(d, 0, sizeof *d);
    d->lx = *at;
    d->lx.parent = NULL; /* read the directive alone: its file's end ends it */
    d->lx.text = NULL;
    d->lx.next = NULL;
    d->t = *t;
    d->gs = P->gs;
    return d;
}

int pbrt_reread(Parser *P, const Deferred *d, const GState *gs,
                int (*fn)(Parser *P, const Token *t))
{
    Lexer lx = d->lx, *saved_lx = P->lx;
    GState saved_gs = P->gs;
    int saved_peek = P->has_peek, saved_rereading = P->rereading;
    Token saved_tok = P->peeked;
    P->lx = &lx;
    P->has_peek = 0;
    P->gs = *gs;
    P->rereading++; /* how deep: mixes read again inside one another */
    int r = fn(P, &d->t);
    P->lx = saved_lx;
    P->gs = saved_gs;
    P->has_peek = saved_peek;
    P->peeked = saved_tok;
    P->rereading = saved_rereading;
    return r;
}

int pbrt_undefined_material(Parser *P, const GState *gs, const char *what)
{
    Lexer at = {.name = gs->pending_file}, *lx = P->lx;
    P->lx = &at;
    pbrt_fail_at(P, gs->pending_line, gs->pending_col,
                 "NamedMaterial: expected a material defined with MakeNamedMaterial%s, found "
                 "\"%.60s\"",
                 what, gs->pending);
    P->lx = lx;
    return -1;
}

void pbrt_defer_free(Parser *P)
{
    free(P->shapes.d);
    free(P->defs.d);
}
