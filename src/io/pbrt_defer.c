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
 * file's end, with the material it names then; a MakeNamedMaterial that
 * names an undefined texture (or a mix an undefined material) when a
 * NamedMaterial first asks for it. A name still undefined then is the
 * error pbrt gives, at the NamedMaterial (or the MakeNamedMaterial) that
 * used it; a NamedMaterial no shape follows is no error, as in pbrt.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

/* Shapes deferred at most: each holds a graphics state (about 3 KB). */
#define PBRT_MAX_DEFERRED (1u << 20)

/* The message of a NamedMaterial at gs's pending name that names no
 * material: at that NamedMaterial, in its file. Returns -1. */
static int undefined(Parser *P, const GState *gs, const char *what)
{
    Lexer at = {.name = gs->pending_file}, *lx = P->lx;
    P->lx = &at;
    pbrt_fail_at(P, gs->pending_line, gs->pending_col,
                 "NamedMaterial: expected a material defined with MakeNamedMaterial%s, found "
                 "\"%.60s\"", what, gs->pending);
    P->lx = lx;
    return -1;
}

/* Appends a deferred directive (its lexer as it is now, after its name t). */
static Deferred *defer(Parser *P, Deferred **list, size_t *n, size_t *cap, const Lexer *at,
                       const Token *t)
{
    if (*n >= PBRT_MAX_DEFERRED) {
        FAIL_TOK(P, t, "more than %u directives wait for a name defined later", PBRT_MAX_DEFERRED);
        return NULL;
    }
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 16;
        Deferred *d = realloc(*list, c * sizeof *d);
        if (!d) {
            FAIL_TOK(P, t, "out of memory");
            return NULL;
        }
        *list = d, *cap = c;
    }
    Deferred *d = &(*list)[(*n)++];
    memset(d, 0, sizeof *d);
    d->lx = *at;
    d->lx.parent = NULL; /* read the directive alone: its file's end ends it */
    d->lx.text = NULL;
    d->lx.next = NULL;
    d->t = *t;
    d->gs = P->gs;
    return d;
}

/* Reads directive d again with handler fn, under its graphics state gs;
 * the parser's lexer and state are restored after. */
static int reread(Parser *P, const Deferred *d, const GState *gs,
                  int (*fn)(Parser *, const Token *))
{
    Lexer lx = d->lx, *saved_lx = P->lx;
    GState saved_gs = P->gs;
    int saved_peek = P->has_peek, saved_rereading = P->rereading;
    Token saved_tok = P->peeked;
    P->lx = &lx;
    P->has_peek = 0;
    P->gs = *gs;
    P->rereading = 1;
    int r = fn(P, &d->t);
    P->lx = saved_lx;
    P->gs = saved_gs;
    P->has_peek = saved_peek;
    P->peeked = saved_tok;
    P->rereading = saved_rereading;
    return r;
}

int pbrt_defer_shape(Parser *P, const Token *t)
{
    if (!P->gs.pending[0] || P->rereading)
        return 0;
    if (P->recording) /* an object's shapes are replayed by instances as they come */
        return undefined(P, &P->gs, " before an ObjectBegin's shapes");
    if (!defer(P, &P->shapes, &P->n_shapes, &P->cap_shapes, P->lx, t))
        return -1;
    char type[64];
    ParamList pl = {0};
    int r = pbrt_name_and_params(P, type, sizeof type, "a shape type", &pl, NULL);
    pbrt_params_free(&pl);
    return r ? -1 : 1;
}

int pbrt_defer_material(Parser *P, const Lexer *at, const Token *t, const char *name, int r)
{
    if (!r || !P->missing_texture || P->rereading || P->recording)
        return r;
    Deferred *d = defer(P, &P->defs, &P->n_defs, &P->cap_defs, at, t);
    if (!d)
        return -1;
    snprintf(d->name, sizeof d->name, "%s", name);
    if (P->err_size)
        P->err[0] = '\0'; /* not an error yet */
    return 0;
}

static const Material *find_material(const Parser *P, const char *name)
{
    for (size_t i = P->n_materials; i-- > 0;)
        if (strcmp(P->materials[i].name, name) == 0)
            return &P->materials[i].m;
    return NULL;
}

const Material *pbrt_named_material(Parser *P, const char *name, int *r)
{
    *r = 0;
    const Material *m = find_material(P, name);
    for (size_t i = P->n_defs; !m && i-- > 0;) {
        Deferred *d = &P->defs[i];
        if (d->done || strcmp(d->name, name) != 0)
            continue;
        d->done = 1; /* no loop through a mix of itself */
        Deferred copy = *d; /* reading it again may grow P->defs */
        if (reread(P, &copy, &copy.gs, pbrt_d_makenamedmaterial) != 0) {
            P->defs[i].done = 0; /* a mix being read may be deferred in turn, and ask again */
            *r = -1;
            return NULL;
        }
        m = find_material(P, name);
    }
    return m;
}

int pbrt_deferred_shapes(Parser *P)
{
    for (size_t i = 0; i < P->n_shapes; i++) {
        GState gs = P->shapes[i].gs;
        int r;
        const Material *m = pbrt_named_material(P, gs.pending, &r);
        if (r)
            return -1;
        if (!m)
            return undefined(P, &gs, "");
        gs.material = *m;
        gs.pending[0] = '\0';
        if (reread(P, &P->shapes[i], &gs, pbrt_d_shape) != 0)
            return -1;
    }
    return 0;
}

void pbrt_defer_free(Parser *P)
{
    free(P->shapes);
    free(P->defs);
}
