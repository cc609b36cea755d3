/*
 * io/obj.c — the Wavefront OBJ reader of obj.h, with its MTL material
 * libraries (docs/obj.md).
 *
 * The whole file (and every MTL it names) is read and checked before the
 * first sink call, so bad input adds nothing: vertices and faces go into
 * growable arrays, materials into a table looked up by name. Then, per
 * material in order of first use, the faces become one polygon mesh of
 * triangles and convex quads (n-gons and concave quads are ear-clipped),
 * emissive quads become area lights, and a default camera (and a default
 * distant light when nothing emits) frame the bounds of what was drawn.
 *
 * Statements end at a newline; a backslash before the newline continues
 * the statement. Errors: "file:line:col: what was expected". Unknown and
 * unsupported statements: one warning per keyword and file.
 *
 * Memory: everything is freed before returning; nothing is kept. Reentrant.
 */
#include "io/obj.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/text.h"
#include "util/colour.h"
#include "util/log.h"

#define OBJ_MAX_EARCLIP 1024 /* bigger faces are fanned (ear clipping is cubic) */
#define OBJ_MAX_WARNED 64

/* ------------------------------------------------------------ arrays */

typedef struct FloatVec {
    float *a;
    size_t n, cap;
} FloatVec;

typedef struct IntVec {
    int *a;
    size_t n, cap;
} IntVec;

static int grow(void **a, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 64;
    while (c < need) {
        if (c > SIZE_MAX / 2 / elem)
            return -1;
        c *= 2;
    }
    void *b = realloc(*a, c * elem);
    if (!b)
        return -1;
    *a = b;
    *cap = c;
    return 0;
}

static int fpush(FloatVec *v, float x)
{
    if (grow((void **)&v->a, &v->cap, v->n + 1, sizeof *v->a) != 0)
        return -1;
    v->a[v->n++] = x;
    return 0;
}

static int ipush(IntVec *v, int x)
{
    if (v->n >= INT_MAX || grow((void **)&v->a, &v->cap, v->n + 1, sizeof *v->a) != 0)
        return -1;
    v->a[v->n++] = x;
    return 0;
}

/* ------------------------------------------------------------- lexer */

/* A line-oriented tokenizer over a bounded buffer (no NUL needed). */
typedef struct Lexer {
    const char *name;       /* file name for messages */
    const char *p, *end;
    const char *line_start;
    long line;              /* 1-based */
    char *err;
    size_t err_size;
} Lexer;

static int lex_error_at(Lexer *L, const char *at, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int lex_error_at(Lexer *L, const char *at, const char *fmt, ...)
{
    char msg[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(L->err, L->err_size, "%s:%ld:%ld: %s", L->name, L->line,
             (long)(at - L->line_start) + 1, msg);
    return -1;
}

/* The length of a backslash-newline continuation at q, or 0. */
static size_t continuation(const Lexer *L, const char *q)
{
    if (*q != '\\' || q + 1 >= L->end)
        return 0;
    if (q[1] == '\n')
        return 2;
    return q[1] == '\r' && q + 2 < L->end && q[2] == '\n' ? 3 : 0;
}

static int blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/* Skips blanks and backslash-newline continuations, not newlines. */
static void lex_blank(Lexer *L)
{
    while (L->p < L->end) {
        size_t k;
        if (blank(*L->p)) {
            L->p++;
        } else if ((k = continuation(L, L->p)) > 0) {
            L->p += k;
            L->line++;
            L->line_start = L->p;
        } else {
            break;
        }
    }
}

/* The next token of the statement: *tok and its length (0 at the end of the
 * statement: a newline, a comment or the end of the file). */
static size_t lex_token(Lexer *L, const char **tok)
{
    lex_blank(L);
    *tok = L->p;
    const char *q = L->p;
    while (q < L->end && !blank(*q) && *q != '\n' && *q != '#' && !continuation(L, q))
        q++;
    L->p = q;
    return (size_t)(q - *tok);
}

/* Moves past the end of the current statement (what is left of it, its
 * comment and its newline). A comment ends at its newline, backslash or not. */
static void lex_next_line(Lexer *L)
{
    int comment = 0;
    while (L->p < L->end) {
        char c = *L->p;
        size_t k = comment ? 0 : continuation(L, L->p);
        if (k > 0) {
            L->p += k;
            L->line++;
            L->line_start = L->p;
            continue;
        }
        L->p++;
        if (c == '#')
            comment = 1;
        else if (c == '\n') {
            L->line++;
            L->line_start = L->p;
            return;
        }
    }
}

/* Quotes a token for a message: printable ASCII, at most 20 characters. */
static void shown(char out[32], const char *tok, size_t n)
{
    size_t k = 0;
    for (; k < 20 && k < n; k++)
        out[k] = tok[k] >= 0x20 && tok[k] < 0x7f && tok[k] != '"' ? tok[k] : '?';
    snprintf(out + k, 32 - k, "%s", n > 20 ? "..." : "");
}

static int lex_expected(Lexer *L, const char *tok, size_t n, const char *what)
{
    char s[32];
    if (n == 0)
        return lex_error_at(L, tok, "expected %s, found the end of the line", what);
    shown(s, tok, n);
    return lex_error_at(L, tok, "expected %s, found \"%s\"", what, s);
}

static int parse_float(const char *tok, size_t n, float *out)
{
    char buf[64];
    if (n == 0 || n >= sizeof buf)
        return -1;
    memcpy(buf, tok, n);
    buf[n] = '\0';
    char *endp;
    double v = strtod(buf, &endp);
    if (*endp != '\0' || !isfinite(v) || fabs(v) > 1e30)
        return -1;
    *out = (float)v;
    return 0;
}

static int lex_float(Lexer *L, float *out, const char *what)
{
    const char *tok;
    size_t n = lex_token(L, &tok);
    return parse_float(tok, n, out) == 0 ? 0 : lex_expected(L, tok, n, what);
}

/* Nonzero (with an error) if the statement has more tokens. */
static int lex_expect_end(Lexer *L, const char *what)
{
    const char *tok;
    size_t n = lex_token(L, &tok);
    return n == 0 ? 0 : lex_expected(L, tok, n, what);
}

/* --------------------------------------------------------- the reader */

typedef struct Material {
    char name[128];
    float Kd[3], Ks[3], Ke[3];
    float Ns;           /* Phong exponent; -1: not given */
    float d, Tr;        /* dissolve (the opacity) and transparency; -1 not given */
    float Tf[3];        /* transmission filter; Tf[0] -1 not given */
    float Ni;           /* index of refraction; -1 not given */
    int illum;          /* illumination model, read, not rendered */
    char map_Kd[1024];  /* texture path, resolved against the MTL's directory; "" none */
    char map_Ks[1024];  /* the specular colour's texture, resolved likewise; "" none */
    char map_Ke[1024];  /* the emission's texture (a textured mesh light), likewise; "" none */
    int map_Ks_sent;    /* its pattern made */
    char map_d[1024];   /* the opacity's texture (a cut-out), resolved likewise; "" none */
    int map_d_channel;  /* its channel: 0-3, or -2 the matte (alpha if any, else grey) */
    int map_d_sent;     /* its pattern made (once per material) */
    char bump[1024];    /* bump, map_bump, norm, disp, ...: a height or normal map; "" none */
    float bump_mult;    /* -bm: the height's scale, the normal's strength */
    int bump_sent;      /* its two patterns made */
    float Pr, Pm;       /* the PBR extension's roughness and metallic; -1 not given */
    char map_Pr[1024];  /* their textures (grey), resolved as map_Kd; "" none */
    char map_Pm[1024];
    int map_Pr_channel, map_Pm_channel; /* -imfchan: the channel read (0 by default) */
    int pbr_sent;       /* the PBR patterns made */
    int defined;        /* given by a newmtl */
} Material;

typedef struct Obj {
    const char *name;        /* the OBJ file, for messages */
    char dir[2048];          /* its directory with a final '/', or "" */
    FloatVec v;              /* x y z per vertex */
    FloatVec vc;             /* r g b per vertex (v x y z r g b) while every vertex so far
                                has one */
    int vc_broken;           /* some vertex has no colour: none are used */
    float vc_max;            /* the largest component given (over 1: 0-255 values) */
    size_t n_vt, n_vn;       /* counts */
    FloatVec vt, vn;         /* u v per texture coordinate, x y z per normal */
    IntVec face_nv;          /* vertices per face */
    IntVec face_idx;         /* 0-based vertex indices, face after face (per corner) */
    IntVec face_vt, face_vn; /* per corner: 0-based vt and vn indices, -1 none */
    IntVec face_mat;         /* material per face, -1 the default */
    IntVec face_s;           /* smoothing group per face, 0 off */
    int cur_s;               /* the s statement's group in force, 0 off */
    int any_s;               /* some face is in a smoothing group */
    float *smooth_N;         /* per corner: its smoothing group's normal at its vertex
                                (obj_smooth_normals), NULL when no face is in one */
    Material *mats;
    size_t n_mats, cap_mats;
    int cur_mat;             /* usemtl's, -1 the default */
    char warned[OBJ_MAX_WARNED][40];
    int n_warned;
    char *err;
    size_t err_size;
} Obj;

/* One warning per key and file read. */
static void obj_warn(Obj *o, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void obj_warn(Obj *o, const char *key, const char *fmt, ...)
{
    for (int i = 0; i < o->n_warned; i++)
        if (strcmp(o->warned[i], key) == 0)
            return;
    if (o->n_warned == OBJ_MAX_WARNED)
        return;
    snprintf(o->warned[o->n_warned++], sizeof o->warned[0], "%s", key);
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    log_warning("%s", msg);
}

static int oom(Lexer *L)
{
    return lex_error_at(L, L->p, "out of memory");
}

static int is_kw(const char *tok, size_t n, const char *kw)
{
    return strlen(kw) == n && memcmp(tok, kw, n) == 0;
}

/* An MTL statement's keyword, in any capitals: writers differ ("map_kd",
 * "MAP_KD", "map_Bump"), and no two of MTL's keywords differ by case
 * alone in meaning. */
static int is_mtl_kw(const char *tok, size_t n, const char *kw)
{
    return strlen(kw) == n && strncasecmp(tok, kw, n) == 0;
}

/* The material of that name (created undefined if new), or -1 when out of
 * memory. */
static int material_find(Obj *o, const char *tok, size_t n)
{
    char name[128];
    snprintf(name, sizeof name, "%.*s", (int)(n < 127 ? n : 127), tok);
    for (size_t i = 0; i < o->n_mats; i++)
        if (strcmp(o->mats[i].name, name) == 0)
            return (int)i;
    if (o->n_mats >= 65536 ||
        grow((void **)&o->mats, &o->cap_mats, o->n_mats + 1, sizeof *o->mats) != 0)
        return -1;
    Material *m = &o->mats[o->n_mats];
    memset(m, 0, sizeof *m);
    snprintf(m->name, sizeof m->name, "%s", name);
    m->Kd[0] = m->Kd[1] = m->Kd[2] = 0.8f;
    m->Ns = -1.0f;
    m->d = m->Tr = m->Tf[0] = m->Ni = m->Pr = m->Pm = -1.0f;
    m->illum = -1;
    m->bump_mult = 1.0f;
    return (int)o->n_mats++;
}

/* ----------------------------------------------------------- MTL */

/* "r [g b]" (one value: grey); "spectral" and "xyz" are refused. */
static int mtl_color(Lexer *L, float c[3])
{
    const char *tok;
    const char *save = L->p;
    size_t n = lex_token(L, &tok);
    if (is_kw(tok, n, "spectral") || is_kw(tok, n, "xyz"))
        return lex_error_at(L, tok, "expected an RGB colour (spectral and xyz colours are not "
                                    "supported)");
    L->p = save;
    if (lex_float(L, &c[0], "a colour component") != 0)
        return -1;
    n = lex_token(L, &tok);
    if (n == 0) {
        c[1] = c[2] = c[0];
        return 0;
    }
    if (parse_float(tok, n, &c[1]) != 0)
        return lex_expected(L, tok, n, "a colour component");
    return lex_float(L, &c[2], "the third colour component") == 0
               ? lex_expect_end(L, "the end of the line after three colour components")
               : -1;
}

/* Whether path names a readable file. */
static int readable(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && access(path, R_OK) == 0;
}

/* path's components after its first `from` bytes (a directory that
 * exists, "" for the working one) matched against the directories' entries
 * regardless of case, in place: a Windows-authored MTL's "Textures/Wall.JPG"
 * for the disk's "textures/wall.jpg". Returns 0 when every component was
 * found. */
static int match_case(char *path, size_t from)
{
    for (char *comp = path + from; *comp;) {
        char *end = strchr(comp, '/');
        size_t len = end ? (size_t)(end - comp) : strlen(comp);
        if (len == 0) { /* a leading or doubled slash */
            comp++;
            continue;
        }
        char dir[4096];
        if (comp == path)
            snprintf(dir, sizeof dir, ".");
        else
            snprintf(dir, sizeof dir, "%.*s", (int)(comp - path), path);
        DIR *d = opendir(dir);
        if (!d)
            return -1;
        const struct dirent *e;
        int found = 0;
        while (!found && (e = readdir(d)) != NULL)
            if (strlen(e->d_name) == len && strncasecmp(e->d_name, comp, len) == 0) {
                memcpy(comp, e->d_name, len);
                found = 1;
            }
        closedir(d);
        if (!found)
            return -1;
        comp += len;
    }
    return 0;
}

/* The file of a map statement as found on this machine, into out: the
 * name relative to the MTL's directory (or absolute); else with Windows'
 * backslashes as slashes; else matched regardless of case; else its
 * tails beside the MTL, longest first (an absolute path of the machine
 * that wrote it, "C:\\Users\\...\\textures\\wood.jpg"). Not found at all,
 * the name as written (the texture's lookup then warns). Returns the
 * length written, or -1 when it does not fit. */
static int map_path(const char *mtl_dir, const char *name, size_t n, char *out, size_t size)
{
    const char *dir = name[0] == '/' ? "" : mtl_dir;
    int w = snprintf(out, size, "%s%.*s", dir, (int)n, name);
    if (w < 0 || (size_t)w >= size)
        return -1;
    if (readable(out))
        return w;
    char first[4096];
    snprintf(first, sizeof first, "%s", out);
    for (char *c = out + strlen(dir); *c; c++)
        if (*c == '\\')
            *c = '/';
    if (readable(out) || (match_case(out, strlen(dir)) == 0 && readable(out)))
        return w;
    /* another machine's path ("C:/Users/.../textures/wall.png"): its
     * tails beside the MTL, longest first ("textures/wall.png", then
     * "wall.png") */
    char written[4096];
    snprintf(written, sizeof written, "%s", out + strlen(dir));
    for (const char *t = strchr(written, '/'); t; t = strchr(t + 1, '/')) {
        char alt[4096];
        if ((size_t)snprintf(alt, sizeof alt, "%s%s", mtl_dir, t + 1) < sizeof alt &&
            (readable(alt) || (match_case(alt, strlen(mtl_dir)) == 0 && readable(alt)))) {
            w = snprintf(out, size, "%s", alt);
            return w < 0 || (size_t)w >= size ? -1 : w;
        }
    }
    w = snprintf(out, size, "%s", first);
    return w < 0 || (size_t)w >= size ? -1 : w;
}

/* map_Kd [options] file: the last token is the file name, or where no
 * such file is found and a longer tail of the statement (after its last
 * option) names one, that tail: a name with spaces, as Blender writes
 * "my texture.png". */
static int mtl_map(Lexer *L, const char *mtl_dir, char *out, size_t out_size)
{
    const char *tok, *start[64], *last = NULL;
    size_t n, last_n = 0;
    int k = 0;
    while ((n = lex_token(L, &tok)) > 0) {
        if (k < 64)
            start[k++] = tok;
        last = tok;
        last_n = n;
    }
    if (!last)
        return lex_expected(L, tok, 0, "a texture file name");
    if (map_path(mtl_dir, last, last_n, out, out_size) < 0)
        return lex_expected(L, last, last_n, "a shorter texture path");
    const char *end = last + last_n;
    for (int j = k - 2; j >= 0 && !readable(out) && start[j][0] != '-'; j--) {
        char alt[4096];
        if (map_path(mtl_dir, start[j], (size_t)(end - start[j]), alt, sizeof alt) >= 0 &&
            readable(alt) && strlen(alt) < out_size)
            snprintf(out, out_size, "%s", alt);
    }
    return 0;
}

/* A map's "-imfchan c" option (r, g, b: that channel; m: the matte;
 * l, z: the first), read ahead of mtl_map: the channel, def when not
 * given. The lexer is left where it was. */
static int map_channel(Lexer *L, int def)
{
    Lexer save = *L;
    const char *tok;
    size_t n;
    int ch = def;
    while ((n = lex_token(L, &tok)) > 0)
        if (is_kw(tok, n, "-imfchan")) {
            n = lex_token(L, &tok);
            ch = n == 1 && tok[0] == 'r'   ? 0
                 : n == 1 && tok[0] == 'g' ? 1
                 : n == 1 && tok[0] == 'b' ? 2
                 : n == 1 && tok[0] == 'm' ? -2
                                           : 0;
        }
    *L = save;
    return ch;
}

/* A bump map's "-bm mult" option, read ahead of mtl_map into *mult (left
 * as it is when not given). The lexer is left where it was. */
static int map_bump_mult(Lexer *L, float *mult)
{
    Lexer save = *L;
    const char *tok;
    size_t n;
    while ((n = lex_token(L, &tok)) > 0)
        if (is_kw(tok, n, "-bm")) {
            n = lex_token(L, &tok);
            if (parse_float(tok, n, mult) != 0)
                return lex_expected(L, tok, n, "a bump multiplier after -bm");
        }
    *L = save;
    return 0;
}

static void dir_of(const char *path, char *dir, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(dir, size, "%.*s", (int)(slash - path + 1), path);
    else
        dir[0] = '\0';
}

/* One MTL statement of material m (-1: before any newmtl). */
static int mtl_statement(Obj *o, Lexer *L, const char *mtl_dir, const char *kw, size_t n,
                         int *m)
{
    if (is_mtl_kw(kw, n, "newmtl")) {
        const char *tok;
        size_t k = lex_token(L, &tok);
        if (k == 0)
            return lex_expected(L, tok, k, "a material name");
        if ((*m = material_find(o, tok, k)) < 0)
            return oom(L);
        o->mats[*m].defined = 1;
        return 0;
    }
    if (*m < 0)
        return lex_error_at(L, kw, "expected newmtl before the first material statement");
    Material *mt = &o->mats[*m];
    float f;
    if (is_mtl_kw(kw, n, "Kd"))
        return mtl_color(L, mt->Kd);
    if (is_mtl_kw(kw, n, "Ks"))
        return mtl_color(L, mt->Ks);
    if (is_mtl_kw(kw, n, "Ke")) {
        if (mtl_color(L, mt->Ke) != 0)
            return -1;
        if (mt->Ke[0] < 0 || mt->Ke[1] < 0 || mt->Ke[2] < 0)
            return lex_error_at(L, kw, "Ke: an emission must not be negative");
        return 0;
    }
    if (is_mtl_kw(kw, n, "Tf")) {
        if (mtl_color(L, mt->Tf) != 0)
            return -1;
        for (int c = 0; c < 3; c++)
            mt->Tf[c] = fminf(fmaxf(mt->Tf[c], 0.0f), 1.0f);
        return 0;
    }
    if (is_mtl_kw(kw, n, "Ka")) {
        float c[3];
        return mtl_color(L, c); /* read; rayes has no ambient colour per material */
    }
    if (is_mtl_kw(kw, n, "Ns") || is_mtl_kw(kw, n, "d") || is_mtl_kw(kw, n, "Tr") ||
        is_mtl_kw(kw, n, "Ni") || is_mtl_kw(kw, n, "sharpness") || is_mtl_kw(kw, n, "Pr") ||
        is_mtl_kw(kw, n, "Pm")) {
        /* "d -halo 0.5" is legal */
        const char *save = L->p, *tok;
        size_t k = lex_token(L, &tok);
        if (!is_kw(tok, k, "-halo"))
            L->p = save;
        if (lex_float(L, &f, "a number") != 0 || lex_expect_end(L, "the end of the line") != 0)
            return -1;
        if (is_mtl_kw(kw, n, "Ns"))
            mt->Ns = f;
        else if (is_mtl_kw(kw, n, "d"))
            mt->d = fminf(fmaxf(f, 0.0f), 1.0f);
        else if (is_mtl_kw(kw, n, "Tr"))
            mt->Tr = fminf(fmaxf(f, 0.0f), 1.0f);
        else if (is_mtl_kw(kw, n, "Ni"))
            mt->Ni = f;
        else if (is_mtl_kw(kw, n, "Pr"))
            mt->Pr = fminf(fmaxf(f, 0.0f), 1.0f);
        else if (is_mtl_kw(kw, n, "Pm"))
            mt->Pm = fminf(fmaxf(f, 0.0f), 1.0f);
        return 0;
    }
    if (is_mtl_kw(kw, n, "illum")) {
        const char *tok;
        size_t k = lex_token(L, &tok);
        if (parse_float(tok, k, &f) != 0 || f != floorf(f) || f < 0 || f > 10)
            return lex_expected(L, tok, k, "an illumination model from 0 to 10");
        mt->illum = (int)f;
        return lex_expect_end(L, "the end of the line");
    }
    if (is_mtl_kw(kw, n, "map_Kd"))
        return mtl_map(L, mtl_dir, mt->map_Kd, sizeof mt->map_Kd);
    if (is_mtl_kw(kw, n, "map_Ks"))
        return mtl_map(L, mtl_dir, mt->map_Ks, sizeof mt->map_Ks);
    if (is_mtl_kw(kw, n, "map_Ke"))
        return mtl_map(L, mtl_dir, mt->map_Ke, sizeof mt->map_Ke);
    if (is_mtl_kw(kw, n, "map_Pr")) { /* packed textures name their channel */
        mt->map_Pr_channel = map_channel(L, 0);
        return mtl_map(L, mtl_dir, mt->map_Pr, sizeof mt->map_Pr);
    }
    if (is_mtl_kw(kw, n, "map_Pm")) {
        mt->map_Pm_channel = map_channel(L, 0);
        return mtl_map(L, mtl_dir, mt->map_Pm, sizeof mt->map_Pm);
    }
    if (is_mtl_kw(kw, n, "map_d")) {
        mt->map_d_channel = map_channel(L, -2);
        return mtl_map(L, mtl_dir, mt->map_d, sizeof mt->map_d);
    }
    if (is_mtl_kw(kw, n, "bump") || is_mtl_kw(kw, n, "map_bump") || is_mtl_kw(kw, n, "norm") ||
        is_mtl_kw(kw, n, "map_norm") || is_mtl_kw(kw, n, "disp") || is_mtl_kw(kw, n, "map_disp")) {
        /* the first wins: files name one bump several ways ("map_bump",
         * "bump", then "norm" of its normal map) */
        float mult = 1.0f;
        char file[1024];
        if (map_bump_mult(L, &mult) != 0 || mtl_map(L, mtl_dir, file, sizeof file) != 0)
            return -1;
        if (!mt->bump[0]) {
            snprintf(mt->bump, sizeof mt->bump, "%s", file);
            mt->bump_mult = mult;
        }
        return 0;
    }
    char key[40];
    snprintf(key, sizeof key, "mtl %.*s", (int)(n < 30 ? n : 30), kw);
    char s[32];
    shown(s, kw, n);
    obj_warn(o, key, "%s:%ld: MTL statement \"%s\" ignored (not supported)", L->name, L->line, s);
    return 0;
}

static int mtl_parse(Obj *o, const char *path, const char *text, size_t size)
{
    Lexer L = {path, text, text + size, text, 1, o->err, o->err_size};
    char mtl_dir[2048];
    dir_of(path, mtl_dir, sizeof mtl_dir);
    int m = -1;
    while (L.p < L.end) {
        const char *kw;
        size_t n = lex_token(&L, &kw);
        if (n > 0 && mtl_statement(o, &L, mtl_dir, kw, n, &m) != 0)
            return -1;
        lex_next_line(&L);
    }
    return 0;
}

/* Reads each MTL the statement names; a missing one is a warning. */
/* One material library, path as found (map_path); 0, or -1 on a parse
 * error. A file that cannot be read is a warning. */
static int obj_mtl_file(Obj *o, Lexer *L, const char *path)
{
    struct stat st;
    char why[512];
    size_t size = 0;
    char *text = NULL;
    if (stat(path, &st) != 0)
        snprintf(why, sizeof why, "%s", strerror(errno));
    else if (!S_ISREG(st.st_mode) || st.st_size > (1 << 28))
        snprintf(why, sizeof why, "not a regular file of at most 256 MB");
    else
        text = text_read_file(path, &size, why, sizeof why);
    if (!text) {
        obj_warn(o, path, "%s:%ld: material library %s: %s; its materials are matte grey", L->name,
                 L->line, path, why);
        return 0;
    }
    int r = mtl_parse(o, path, text, size);
    free(text);
    return r;
}

/* mtllib a.mtl ...: each file, relative to the OBJ's directory and found
 * as a map's file is (Windows' backslashes, other capitals); when some is
 * not found and the whole list names one file, that file (a name with
 * spaces: Blender writes "mtllib my scene.mtl"). */
static int obj_mtllib(Obj *o, Lexer *L)
{
    const char *tok, *start[64], *end = NULL;
    size_t n, len[64];
    int k = 0;
    while ((n = lex_token(L, &tok)) > 0) {
        if (k < 64)
            start[k] = tok, len[k++] = n;
        end = tok + n;
    }
    if (k == 0)
        return lex_expected(L, tok, 0, "a material library file name");
    char path[4096];
    int all = 1;
    for (int j = 0; j < k && all; j++)
        all = map_path(o->dir, start[j], len[j], path, sizeof path) >= 0 && readable(path);
    if (!all && k > 1 &&
        map_path(o->dir, start[0], (size_t)(end - start[0]), path, sizeof path) >= 0 &&
        readable(path))
        return obj_mtl_file(o, L, path);
    for (int j = 0; j < k; j++) {
        if (map_path(o->dir, start[j], len[j], path, sizeof path) < 0)
            return lex_expected(L, start[j], len[j], "a shorter material library path");
        if (obj_mtl_file(o, L, path) != 0)
            return -1;
    }
    return 0;
}

/* ----------------------------------------------------------- OBJ */

/* One index of a face corner: 1-based, or negative (relative to count). */
static int corner_index(Lexer *L, const char *tok, size_t n, size_t count, const char *what,
                        int *out)
{
    char buf[32];
    if (n == 0 || n >= sizeof buf)
        return lex_expected(L, tok, n, what);
    memcpy(buf, tok, n);
    buf[n] = '\0';
    char *endp;
    errno = 0;
    long v = strtol(buf, &endp, 10);
    if (*endp != '\0' || errno != 0)
        return lex_expected(L, tok, n, what);
    long i = v > 0 ? v - 1 : (long)count + v;
    if (count == 0)
        return lex_error_at(L, tok, "expected %s, found %ld with none defined before this line",
                            what, v);
    if (v == 0 || i < 0 || (size_t)i >= count)
        return lex_error_at(L, tok, "expected %s from 1 to %zu (or -1 to -%zu), found %ld", what,
                            count, count, v);
    *out = (int)i;
    return 0;
}

/* "v", "v/vt", "v//vn" or "v/vt/vn"; *ti and *ni are -1 when absent. */
static int face_corner(Obj *o, Lexer *L, const char *tok, size_t n, int *vi, int *ti, int *ni)
{
    const char *s1 = memchr(tok, '/', n);
    size_t n0 = s1 ? (size_t)(s1 - tok) : n;
    *ti = *ni = -1;
    if (corner_index(L, tok, n0, o->v.n / 3, "a vertex index", vi) != 0)
        return -1;
    if (!s1)
        return 0;
    const char *t = s1 + 1, *end = tok + n;
    const char *s2 = memchr(t, '/', (size_t)(end - t));
    size_t n1 = s2 ? (size_t)(s2 - t) : (size_t)(end - t);
    if ((n1 > 0 || !s2) && corner_index(L, t, n1, o->n_vt, "a texture coordinate index",
                                         ti) != 0)
        return -1;
    if (!s2)
        return 0;
    t = s2 + 1;
    return corner_index(L, t, (size_t)(end - t), o->n_vn, "a normal index", ni);
}

static int obj_face(Obj *o, Lexer *L, const char *kw)
{
    const char *tok;
    size_t n;
    int count = 0;
    while ((n = lex_token(L, &tok)) > 0) {
        int vi, ti, ni;
        if (face_corner(o, L, tok, n, &vi, &ti, &ni) != 0)
            return -1;
        if (ipush(&o->face_idx, vi) != 0 || ipush(&o->face_vt, ti) != 0 ||
            ipush(&o->face_vn, ni) != 0)
            return oom(L);
        count++;
    }
    if (count < 3) {
        o->face_idx.n -= (size_t)count;
        o->face_vt.n -= (size_t)count;
        o->face_vn.n -= (size_t)count;
        return lex_error_at(L, count ? tok : kw, "expected at least 3 vertices in a face, found %d",
                            count);
    }
    if (ipush(&o->face_nv, count) != 0 || ipush(&o->face_mat, o->cur_mat) != 0 ||
        ipush(&o->face_s, o->cur_s) != 0)
        return oom(L);
    o->any_s |= o->cur_s != 0;
    return 0;
}

/* v x y z [w] or v x y z r g b: the position is kept, and the colour
 * while every vertex has one. */
static int obj_vertex(Obj *o, Lexer *L)
{
    float x[3], extra[4];
    for (int k = 0; k < 3; k++)
        if (lex_float(L, &x[k], "a vertex coordinate") != 0)
            return -1;
    const char *tok;
    size_t n;
    int more = 0;
    while ((n = lex_token(L, &tok)) > 0) {
        if (more == 4 || parse_float(tok, n, &extra[more]) != 0)
            return lex_expected(L, tok, n, more == 4 ? "the end of the line" : "a number");
        more++;
    }
    const float *rgb = extra;
    if (more == 2)
        return lex_expected(L, tok, 0, "the third colour component");
    if (o->v.n / 3 >= INT_MAX - 1)
        return lex_error_at(L, L->p, "too many vertices");
    for (int k = 0; k < 3; k++)
        if (fpush(&o->v, x[k]) != 0)
            return oom(L);
    if (more == 3 && !o->vc_broken) { /* a colour: kept while every vertex has one */
        for (int k = 0; k < 3; k++)
            if (fpush(&o->vc, rgb[k]) != 0)
                return oom(L);
        o->vc_max = fmaxf(o->vc_max, fmaxf(rgb[0], fmaxf(rgb[1], rgb[2])));
    } else if (more != 3) {
        o->vc_broken = 1;
    }
    return 0;
}

/* vt u [v [w]], vn x y z: checked, counted, and the first keep values
 * (missing ones 0) pushed onto values. */
static int obj_attribute(Lexer *L, int min, int max, int keep, size_t *count, FloatVec *values)
{
    const char *tok;
    size_t n;
    int k = 0;
    float f[3] = {0, 0, 0};
    while ((n = lex_token(L, &tok)) > 0) {
        if (k == max || parse_float(tok, n, &f[k]) != 0)
            return lex_expected(L, tok, n, k == max ? "the end of the line" : "a number");
        k++;
    }
    if (k < min)
        return lex_expected(L, tok, 0, "a number");
    if (*count >= INT_MAX - 1)
        return lex_error_at(L, L->p, "too many vertex attributes");
    for (int c = 0; c < keep; c++)
        if (fpush(values, f[c]) != 0)
            return oom(L);
    (*count)++;
    return 0;
}

static int obj_statement(Obj *o, Lexer *L, const char *kw, size_t n)
{
    if (is_kw(kw, n, "v"))
        return obj_vertex(o, L);
    if (is_kw(kw, n, "vt"))
        return obj_attribute(L, 1, 3, 2, &o->n_vt, &o->vt);
    if (is_kw(kw, n, "vn"))
        return obj_attribute(L, 3, 3, 3, &o->n_vn, &o->vn);
    if (is_kw(kw, n, "f") || is_kw(kw, n, "fo"))
        return obj_face(o, L, kw);
    if (is_kw(kw, n, "s")) { /* s N, s off (0): the smoothing group of the faces after */
        const char *tok;
        size_t k = lex_token(L, &tok);
        double g;
        char *end = NULL, buf[32];
        snprintf(buf, sizeof buf, "%.*s", (int)(k < 31 ? k : 31), k ? tok : "");
        g = k ? strtod(buf, &end) : 0.0;
        if (is_kw(tok, k, "off") || (end && *end == '\0' && g == 0.0))
            o->cur_s = 0;
        else if (end && *end == '\0' && g > 0.0 && isfinite(g))
            o->cur_s = (int)fmod(floor(g), 2147483647.0) + 1; /* large (bitmask) groups too */
        else { /* "s", "s on" (exporters write them): group 1; other words, one warning */
            if (k && !is_kw(tok, k, "on"))
                obj_warn(o, "s value", "%s:%ld: \"s %.20s\": taken as smoothing group 1", L->name,
                         L->line, buf);
            o->cur_s = 2; /* group 1's */
        }
        while (lex_token(L, &tok) > 0)
            ;
        return 0;
    }
    if (is_kw(kw, n, "g") || is_kw(kw, n, "o")) {
        const char *tok; /* names: read, not used */
        while (lex_token(L, &tok) > 0)
            ;
        return 0;
    }
    if (is_kw(kw, n, "usemtl")) {
        const char *tok;
        size_t k = lex_token(L, &tok);
        if (k == 0)
            return lex_expected(L, tok, k, "a material name");
        if ((o->cur_mat = material_find(o, tok, k)) < 0)
            return oom(L);
        return 0;
    }
    if (is_kw(kw, n, "mtllib"))
        return obj_mtllib(o, L);
    char key[40], s[32];
    snprintf(key, sizeof key, "obj %.*s", (int)(n < 30 ? n : 30), kw);
    shown(s, kw, n);
    obj_warn(o, key, "%s:%ld: OBJ statement \"%s\" ignored (not supported)", L->name, L->line,
             s);
    return 0;
}

static int obj_parse_text(Obj *o, const char *text, size_t size)
{
    Lexer L = {o->name, text, text + size, text, 1, o->err, o->err_size};
    while (L.p < L.end) {
        const char *kw;
        size_t n = lex_token(&L, &kw);
        if (n > 0 && obj_statement(o, &L, kw, n) != 0)
            return -1;
        lex_next_line(&L);
    }
    return 0;
}

/* ------------------------------------------------------ triangulation */

typedef struct Mesh {
    IntVec nv, idx;   /* faces of 3 or 4 corners: indices into Obj.face_idx (vt, vn) */
} Mesh;

static const float *vtx(const Obj *o, int i)
{
    return &o->v.a[3 * (size_t)i];
}

/* Newell's normal of the polygon (twice its vector area). */
static void newell(const Obj *o, const int *f, int n, double N[3])
{
    N[0] = N[1] = N[2] = 0.0;
    for (int i = 0; i < n; i++) {
        const float *a = vtx(o, f[i]), *b = vtx(o, f[(i + 1) % n]);
        N[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        N[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        N[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
}

/* Projects the polygon on the plane of its dominant normal axis, turned
 * so that the polygon runs counter-clockwise in 2D. */
static void project(const Obj *o, const int *f, int n, const double N[3], double (*q)[2])
{
    int k = fabs(N[0]) > fabs(N[1]) ? (fabs(N[0]) > fabs(N[2]) ? 0 : 2)
                                    : (fabs(N[1]) > fabs(N[2]) ? 1 : 2);
    int i = (k + 1) % 3, j = (k + 2) % 3;
    double s = N[k] < 0 ? -1.0 : 1.0;
    for (int c = 0; c < n; c++) {
        const float *p = vtx(o, f[c]);
        q[c][0] = p[i];
        q[c][1] = s * p[j];
    }
}

static double cross2(const double a[2], const double b[2], const double c[2])
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static int same(const double a[2], const double b[2])
{
    return a[0] == b[0] && a[1] == b[1];
}

/* Nonzero if p lies in the triangle abc (counter-clockwise) or on its
 * edges: a vertex on the new diagonal a-c must block the ear too. Copies
 * of the corners do not block. */
static int inside(const double a[2], const double b[2], const double c[2], const double p[2])
{
    if (same(p, a) || same(p, b) || same(p, c))
        return 0;
    return cross2(a, b, p) >= 0.0 && cross2(b, c, p) >= 0.0 && cross2(c, a, p) >= 0.0;
}

static int mesh_face(Mesh *m, int a, int b, int c, int d)
{
    if (ipush(&m->nv, d < 0 ? 3 : 4) != 0 || ipush(&m->idx, a) != 0 || ipush(&m->idx, b) != 0 ||
        ipush(&m->idx, c) != 0 || (d >= 0 && ipush(&m->idx, d) != 0))
        return -1;
    return 0;
}

/* Ear clipping of a simple polygon (concave allowed) in its 2D projection
 * (O(n^2) per ear at worst, so big faces are fanned instead);
 * when no ear is found (a self-intersecting or degenerate polygon) the
 * first remaining vertex is clipped anyway, so every input ends. */
static int ear_clip(Mesh *m, int base, int n, double (*q)[2])
{
    int *next = malloc((size_t)n * 2 * sizeof *next);
    if (!next)
        return -1;
    int *prev = next + n;
    for (int i = 0; i < n; i++) {
        next[i] = (i + 1) % n;
        prev[i] = (i + n - 1) % n;
    }
    int left = n, cur = 0, tried = 0, r = 0;
    while (left > 3 && r == 0) {
        int a = prev[cur], b = cur, c = next[cur];
        int ear = cross2(q[a], q[b], q[c]) > 0.0;
        for (int k = next[c]; ear && k != a; k = next[k])
            ear = !inside(q[a], q[b], q[c], q[k]);
        if (ear || tried == left) {
            r = mesh_face(m, base + a, base + b, base + c, -1);
            next[a] = c;
            prev[c] = a;
            left--;
            tried = 0;
            cur = c;
        } else {
            tried++;
            cur = c;
        }
    }
    if (r == 0)
        r = mesh_face(m, base + prev[cur], base + cur, base + next[cur], -1);
    free(next);
    return r;
}

/* The face of n corners from corner base into m: triangles and convex
 * quads as they are, others split. */
static int triangulate(Obj *o, Mesh *m, int base, int n)
{
    const int *f = &o->face_idx.a[base];
    double N[3];
    newell(o, f, n, N);
    if (!(N[0] * N[0] + N[1] * N[1] + N[2] * N[2] > 0.0)) {
        obj_warn(o, "degenerate", "%s: faces of zero area skipped", o->name);
        return 0;
    }
    if (n == 3)
        return mesh_face(m, base, base + 1, base + 2, -1);
    if (n > OBJ_MAX_EARCLIP) {
        obj_warn(o, "fan", "%s: faces of more than %d vertices are split as fans", o->name,
                 OBJ_MAX_EARCLIP);
        for (int i = 1; i + 1 < n; i++)
            if (mesh_face(m, base, base + i, base + i + 1, -1) != 0)
                return -1;
        return 0;
    }
    double(*q)[2] = malloc((size_t)n * sizeof *q);
    if (!q)
        return -1;
    project(o, f, n, N, q);
    int convex = n == 4;
    for (int i = 0; convex && i < 4; i++)
        convex = cross2(q[i], q[(i + 1) % 4], q[(i + 2) % 4]) > 0.0;
    int r = convex ? mesh_face(m, base, base + 1, base + 2, base + 3) : ear_clip(m, base, n, q);
    free(q);
    return r;
}

/* ----------------------------------------------------------- output */

typedef struct Emit {
    Obj *o;
    const IoSink *sink;
    int n_area_lights;
    float lo[3], hi[3];  /* bounds of the vertices drawn */
    int *local;          /* global vertex -> mesh vertex, -1 unused */
    FloatVec P;
    int bumped; /* the last material sent had a bump map (a displacement) */
    const IoReadOptions *ro; /* the caller's view, for the default light; may be NULL */
} Emit;

static RayesError sink_fail(Emit *e, RayesError r, const char *what)
{
    const char *why = e->sink->get_error ? e->sink->get_error(e->sink->target) : "";
    snprintf(e->o->err, e->o->err_size, "%s: %s: %s", e->o->name, what,
             why && why[0] ? why : rayes_error_string(r));
    return r;
}

static RayesError set_shader(Emit *e, const char *name, const RayesParam *p, size_t n,
                             const char *mat)
{
    RayesError r = e->sink->set_shader(e->sink->target, name, p, n);
    if (r != RAYES_OK) {
        char what[200];
        snprintf(what, sizeof what, "material \"%s\"", mat);
        return sink_fail(e, r, what);
    }
    return RAYES_OK;
}

static float max3(const float c[3])
{
    return fmaxf(c[0], fmaxf(c[1], c[2]));
}

/* Ns, a Phong exponent, as RenderMan's roughness (the highlight falls as
 * cos^(1/roughness)): 1/Ns, clamped to [0.001, 1]; 0.1 when not given. */
static float roughness_of(float Ns)
{
    if (Ns < 0.0f)
        return 0.1f;
    return Ns <= 1.0f ? 1.0f : fmaxf(1.0f / Ns, 0.001f);
}

/* Whether m's illumination model is one of MTL's transparent ones (4 and
 * 9 glass, 6 and 7 refraction), whose light through is Tf's. */
static int transparent_model(const Material *m)
{
    return m->illum == 4 || m->illum == 6 || m->illum == 7 || m->illum == 9;
}

/* What material m lets through, per channel, into T. A transparent model
 * (illum 4, 6, 7, 9) passes its Tf when one is given other than white
 * (Sibenik's windows: "d 0", "Tf 0.07 0.63 0.07", "illum 4"; or "d 1" with
 * a yellow Tf), else 1 - d. Any other passes 1 - its opacity: d, else
 * 1 - Tr, else 1 (both given, d wins: some programs write Tr as d's
 * synonym, "d 1 Tr 1"); there an opacity of 0 — every surface of the
 * material invisible — is an exporter's mistake (3ds Max's and others'
 * "d 0" on opaque walls, as Cesium's obj2gltf reads it too) and is taken
 * as opaque, with one warning. */
static void material_transmission(Obj *o, const Material *m, float T[3])
{
    float d = m->d >= 0.0f ? m->d : m->Tr >= 0.0f ? 1.0f - m->Tr : 1.0f;
    int tinted = m->Tf[0] >= 0.0f && !(m->Tf[0] == 1.0f && m->Tf[1] == 1.0f && m->Tf[2] == 1.0f);
    if (transparent_model(m)) {
        for (int c = 0; c < 3; c++)
            T[c] = tinted ? m->Tf[c] : 1.0f - d;
        return;
    }
    if (!(d > 0.0f)) {
        obj_warn(o, "opacity 0",
                 "%s: material \"%s\" (and any other so made) has %s, which would make it "
                 "invisible; taken as opaque",
                 o->name, m->name, m->d >= 0.0f ? "d 0" : "Tr 1");
        d = 1.0f;
    }
    T[0] = T[1] = T[2] = 1.0f - d;
}

/* Whether material m is clear glass: refraction on (illum 6 or 7) with an
 * index above 1, untextured and untinted, and either dark (glass's Kd is
 * black or nearly) or at least half transparent — not an opaque
 * material an exporter marked so (a coloured surface of Ni 1.45 and d 0.9
 * stays that surface, a little transparent). */
static int clear_glass(Obj *o, const Material *m)
{
    if (!((m->illum == 6 || m->illum == 7) && m->Ni > 1.01f) || m->map_Kd[0] || m->map_d[0] ||
        (m->Tf[0] >= 0.0f && m->Tf[0] + m->Tf[1] + m->Tf[2] < 3.0f))
        return 0;
    float T[3];
    material_transmission(o, m, T);
    return max3(m->Kd) <= 0.2f || T[0] >= 0.5f;
}

/* Sends pattern name of class cls for material m's part what ("map_d",
 * "its bump map"); RAYES_OK, or the sink's error said. */
static RayesError obj_pattern(Emit *e, const Material *m, const char *what, const char *name,
                              const char *cls, const RayesParam *q, size_t n)
{
    RayesError r = e->sink->pattern(e->sink->target, name, cls, q, n);
    if (r == RAYES_OK)
        return r;
    char said[200];
    snprintf(said, sizeof said, "material \"%s\": %s", m->name, what);
    return sink_fail(e, r, said);
}

/* The opacity of material m as the reserved shader parameter "Os" in *out
 * (its name NULL for an opaque material): d, or map_d's texture (times d),
 * a pattern made once per material under a name that starts with a space
 * (cutout holds it). The texture's values are opacities, read linear. */
static RayesError opacity_of(Emit *e, Material *m, char cutout[48], RayesParam *out)
{
    float T[3];
    material_transmission(e->o, m, T);
    float d = 1.0f - (T[0] + T[1] + T[2]) / 3.0f;
    out->name = NULL;
    if (!m->map_d[0]) {
        if (T[0] > 0.0f || T[1] > 0.0f || T[2] > 0.0f)
            *out = (RayesParam){"Os", RAYES_PARAM_COLOR, {1 - T[0], 1 - T[1], 1 - T[2]}, NULL};
        return RAYES_OK;
    }
    snprintf(cutout, 48, " obj map_d %zu", (size_t)(m - e->o->mats));
    if (!m->map_d_sent) {
        if (!e->sink->pattern) {
            obj_warn(e->o, "map_d sink", "%s: map_d cut-outs are not kept by this output",
                     e->o->name);
            return RAYES_OK;
        }
        RayesParam q[4] = {{"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_d},
                           {"encoding", RAYES_PARAM_STRING, {0, 0, 0}, "linear"},
                           {"channel", RAYES_PARAM_FLOAT, {(float)m->map_d_channel, 0, 0}, NULL},
                           {"scale", RAYES_PARAM_FLOAT, {d, 0, 0}, NULL}};
        RayesError r = obj_pattern(e, m, "map_d", cutout, "imagemap", q, 4);
        if (r != RAYES_OK)
            return r;
        m->map_d_sent = 1;
    }
    *out = (RayesParam){"Os", RAYES_PARAM_PATTERN, {1, 1, 1}, cutout};
    return RAYES_OK;
}

/* The bump map of material m (NULL: none) as the sink's displacement and
 * *out, the shader's "normalmap" parameter (its name NULL without one).
 * The file is read both ways, as a height map (imagemap channel -3: a
 * bump, the shading normal of the surface displaced by height times -bm
 * object units, the surface where it is) and as a tangent-space normal
 * map (-4, of strength -bm), the texture module telling which it is from
 * its texels (docs/obj.md); the other reads as flat. Two patterns made
 * once per material, under names that start with a space (names holds
 * them). A material without a bump after one with ends the displacement. */
static RayesError bump_of(Emit *e, Material *m, char names[2][48], RayesParam *out)
{
    out->name = NULL;
    if (!m || !m->bump[0]) {
        RayesError r = RAYES_OK;
        if (e->bumped && e->sink->set_displacement)
            r = e->sink->set_displacement(e->sink->target, "", NULL, 0);
        e->bumped = 0;
        return r == RAYES_OK ? r : sink_fail(e, r, "the end of a bump map");
    }
    if (!e->sink->pattern || !e->sink->set_displacement) {
        obj_warn(e->o, "bump sink", "%s: bump and normal maps are not kept by this output",
                 e->o->name);
        return RAYES_OK;
    }
    size_t k = (size_t)(m - e->o->mats);
    snprintf(names[0], 48, " obj bump %zu height", k);
    snprintf(names[1], 48, " obj bump %zu normal", k);
    char what[200];
    snprintf(what, sizeof what, "material \"%s\": its bump map", m->name);
    for (int j = 0; j < 2 && !m->bump_sent; j++) {
        RayesParam q[4] = {{"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->bump},
                           {"encoding", RAYES_PARAM_STRING, {0, 0, 0}, "linear"},
                           {"channel", RAYES_PARAM_FLOAT, {j == 0 ? -3.0f : -4.0f, 0, 0}, NULL},
                           {"scale", RAYES_PARAM_FLOAT, {m->bump_mult, 0, 0}, NULL}};
        RayesError r = obj_pattern(e, m, "its bump map", names[j], "imagemap", q, 4);
        if (r != RAYES_OK)
            return r;
    }
    m->bump_sent = 1;
    const RayesParam d[2] = {{"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, names[0]},
                             {"__bump", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL}};
    RayesError r = e->sink->set_displacement(e->sink->target, "displace", d, 2);
    if (r != RAYES_OK)
        return sink_fail(e, r, what);
    e->bumped = 1;
    *out = (RayesParam){"normalmap", RAYES_PARAM_PATTERN, {0.5f, 0.5f, 1}, names[1]};
    return RAYES_OK;
}

/* Whether m uses the PBR extension (Blender's "PBR extensions", three.js
 * and Model I/O write it): a roughness or metallic, given or mapped. */
static int pbr_material(const Material *m)
{
    return m->Pr >= 0.0f || m->Pm >= 0.0f || m->map_Pr[0] || m->map_Pm[0];
}

/* The PBR patterns of material m (once): its base colour (map_Kd, sRGB),
 * its roughness as rayes' (alpha squared: the map's Disney roughness to
 * the fourth, as scale patterns of it by itself) and its metallic (map_Pm,
 * linear), those it maps, under names[0..2]. */
static RayesError pbr_patterns(Emit *e, Material *m, char names[3][48])
{
    size_t k = (size_t)(m - e->o->mats);
    snprintf(names[0], 48, " obj Kd %zu", k);
    snprintf(names[1], 48, " obj Pr %zu", k);
    snprintf(names[2], 48, " obj Pm %zu", k);
    if (m->pbr_sent)
        return RAYES_OK;
    RayesError r = RAYES_OK;
    if (m->map_Kd[0]) {
        const RayesParam q = {"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_Kd};
        r = obj_pattern(e, m, "its textures", names[0], "imagemap", &q, 1);
    }
    if (r == RAYES_OK && m->map_Pr[0]) {
        char r1[48], r2[48];
        snprintf(r1, sizeof r1, " obj Pr1 %zu", k);
        snprintf(r2, sizeof r2, " obj Pr2 %zu", k);
        const RayesParam q[3] = {
            {"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_Pr},
            {"encoding", RAYES_PARAM_STRING, {0, 0, 0}, "linear"},
            {"channel", RAYES_PARAM_FLOAT, {(float)m->map_Pr_channel, 0, 0}, NULL}};
        const RayesParam sq[2] = {{"tex", RAYES_PARAM_PATTERN, {0, 0, 0}, r1},
                                  {"scale", RAYES_PARAM_PATTERN, {0, 0, 0}, r1}};
        const RayesParam fourth[2] = {{"tex", RAYES_PARAM_PATTERN, {0, 0, 0}, r2},
                                      {"scale", RAYES_PARAM_PATTERN, {0, 0, 0}, r2}};
        r = obj_pattern(e, m, "its textures", r1, "imagemap", q, 3);
        if (r == RAYES_OK)
            r = obj_pattern(e, m, "its textures", r2, "scale", sq, 2);
        if (r == RAYES_OK)
            r = obj_pattern(e, m, "its textures", names[1], "scale", fourth, 2);
    }
    if (r == RAYES_OK && m->map_Pm[0]) {
        const RayesParam q[3] = {
            {"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_Pm},
            {"encoding", RAYES_PARAM_STRING, {0, 0, 0}, "linear"},
            {"channel", RAYES_PARAM_FLOAT, {(float)m->map_Pm_channel, 0, 0}, NULL}};
        r = obj_pattern(e, m, "its textures", names[2], "imagemap", q, 3);
    }
    m->pbr_sent = r == RAYES_OK;
    return r;
}

/* A material of the PBR extension (its maps need a sink with patterns), the
 * metallic-roughness model of glTF
 * and Disney's principled BSDF: a dielectric lobe (coateddiffuse: the
 * base colour under a glossy coat) and a metal one (conductor of the base
 * colour's reflectance), each of GGX alpha = Pr^2 (0.5 when not given),
 * mixed by the metallic (0 when not given; a map, or between 0 and 1: the
 * "mix" shader). p holds the parameters so far (a normal map, the opacity),
 * n of them; the lobes take the normal map, the surface the opacity. */
static RayesError pbr_shader(Emit *e, Material *m, RayesParam p[16], size_t n)
{
    char names[3][48];
    RayesError r = pbr_patterns(e, m, names);
    if (r != RAYES_OK)
        return r;
    float rough = m->Pr >= 0.0f ? m->Pr : 0.5f;
    RayesParam base =
        m->map_Kd[0]
            ? (RayesParam){"reflectance", RAYES_PARAM_PATTERN, {1, 1, 1}, names[0]}
            : (RayesParam){"reflectance", RAYES_PARAM_COLOR, {m->Kd[0], m->Kd[1], m->Kd[2]}, NULL};
    RayesParam r4 =
        m->map_Pr[0]
            ? (RayesParam){"roughness", RAYES_PARAM_PATTERN, {0, 0, 0}, names[1]}
            : (RayesParam){
                  "roughness", RAYES_PARAM_FLOAT, {rough * rough * rough * rough, 0, 0}, NULL};
    float metal = m->Pm >= 0.0f ? m->Pm : 0.0f;
    const char *one = !m->map_Pm[0] && metal <= 0.0f   ? "coateddiffuse"
                      : !m->map_Pm[0] && metal >= 1.0f ? "conductor"
                                                       : NULL;
    RayesParam lobe[3] = {base, r4, {NULL, RAYES_PARAM_FLOAT, {0, 0, 0}, NULL}};
    size_t n_lobe = 2, n_surface = 0;
    RayesParam surface[2];
    for (size_t i = 0; i < n; i++) /* the normal map goes to the lobes */
        if (strcmp(p[i].name, "normalmap") == 0)
            lobe[n_lobe++] = p[i];
        else
            surface[n_surface++] = p[i];
    if (one) {
        memcpy(p, surface, n_surface * sizeof *p);
        memcpy(p + n_surface, lobe, n_lobe * sizeof *p);
        return set_shader(e, one, p, n_surface + n_lobe, m->name);
    }
    static const char *const prefixed[2][3] = {{"a:reflectance", "a:roughness", "a:normalmap"},
                                               {"b:reflectance", "b:roughness", "b:normalmap"}};
    size_t c = 0;
    memcpy(p, surface, n_surface * sizeof *p);
    c = n_surface;
    p[c++] = (RayesParam){"a", RAYES_PARAM_STRING, {0, 0, 0}, "coateddiffuse"};
    p[c++] = (RayesParam){"b", RAYES_PARAM_STRING, {0, 0, 0}, "conductor"};
    p[c++] = m->map_Pm[0] ? (RayesParam){"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, names[2]}
                          : (RayesParam){"amount", RAYES_PARAM_FLOAT, {metal, 0, 0}, NULL};
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < n_lobe; i++) {
            p[c] = lobe[i];
            p[c++].name = prefixed[k][i];
        }
    return set_shader(e, "mix", p, c, m->name);
}

/* The shader of a material (NULL: the default, matte grey). A map_Kd
 * replaces Kd, as Blender's and Mitsuba's importers read it (the MTL
 * standard multiplies them, but exporters write their default Kd beside
 * the map: 3ds Max's 0.588 made Sponza half as bright). */
static RayesError material_shader(Emit *e, Material *m)
{
    static const float grey[3] = {0.8f, 0.8f, 0.8f}, white[3] = {1, 1, 1};
    const float *Kd = !m ? grey : m->map_Kd[0] ? white : m->Kd;
    RayesParam p[16];
    size_t n = 0;
    char bumps[2][48];
    RayesError r = bump_of(e, m, bumps, &p[n]);
    if (r != RAYES_OK)
        return r;
    n += p[n].name != NULL;
    if (m && pbr_material(m) &&
        (e->sink->pattern || !(m->map_Kd[0] || m->map_Pr[0] || m->map_Pm[0]))) {
        char cutout[48];
        RayesError r2 = opacity_of(e, m, cutout, &p[n]);
        if (r2 != RAYES_OK)
            return r2;
        n += p[n].name != NULL;
        return pbr_shader(e, m, p, n);
    }
    if (m && clear_glass(e->o, m)) {
        /* a sheet of glass that reflects by Fresnel's law and lets the
         * rest through unbent (a window is a single face; a solid
         * refracting glass would bend light into the room behind it) */
        const RayesParam eta = {"eta", RAYES_PARAM_FLOAT, {fminf(m->Ni, 10.0f), 0, 0}, NULL};
        return set_shader(e, "thindielectric", &eta, 1, m->name);
    }
    p[n++] = (RayesParam){"Cs", RAYES_PARAM_COLOR, {Kd[0], Kd[1], Kd[2]}, NULL};
    if (!m)
        return set_shader(e, "matte", p, n, "(none)");
    char cutout[48];
    r = opacity_of(e, m, cutout, &p[n]);
    if (r != RAYES_OK)
        return r;
    n += p[n].name != NULL;
    float ks = max3(m->Ks);
    char ks_map[48];
    snprintf(ks_map, sizeof ks_map, " obj Ks %zu", (size_t)(m - e->o->mats));
    int mapped = m->map_Ks[0] && e->sink->pattern;
    if (mapped && !m->map_Ks_sent) { /* map_Ks times Ks (the map alone when Ks is 0) */
        const RayesParam q[2] = {{"filename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_Ks},
                                 {"scale", RAYES_PARAM_FLOAT, {ks > 0.0f ? ks : 1.0f, 0, 0}, NULL}};
        if ((r = obj_pattern(e, m, "map_Ks", ks_map, "imagemap", q, 2)) != RAYES_OK)
            return r;
        m->map_Ks_sent = 1;
    }
    if (!m->map_Kd[0] && !(ks > 0.0f) && !mapped)
        return set_shader(e, "matte", p, n, m->name);
    p[n++] = (RayesParam){"Kd", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL};
    p[n++] = (RayesParam){"Ks", RAYES_PARAM_FLOAT, {ks > 0.0f || mapped ? 1.0f : 0.0f, 0, 0}, NULL};
    p[n++] = (RayesParam){"roughness", RAYES_PARAM_FLOAT, {roughness_of(m->Ns), 0, 0}, NULL};
    if (mapped)
        p[n++] = (RayesParam){"specularcolor", RAYES_PARAM_PATTERN, {1, 1, 1}, ks_map};
    else if (ks > 0.0f)
        p[n++] = (RayesParam){"specularcolor", RAYES_PARAM_COLOR,
                              {m->Ks[0], m->Ks[1], m->Ks[2]}, NULL};
    if (m->map_Kd[0])
        p[n++] = (RayesParam){"texturename", RAYES_PARAM_STRING, {0, 0, 0}, m->map_Kd};
    return set_shader(e, m->map_Kd[0] ? "paintedplastic" : "plastic", p, n, m->name);
}

/* Smoothing groups: every corner's normal in o->smooth_N. A corner of a
 * face in group g > 0 takes the sum of the area-weighted (Newell) normals
 * of the faces of group g around its vertex, across materials, as OBJ's
 * smoothing groups mean; a corner of a face in no group takes its face's
 * normal (flat). The sums live in an open-addressed table keyed by
 * (vertex, group). Returns 0, or -1 when out of memory. */
static int obj_smooth_normals(Obj *o)
{
    size_t corners = o->face_idx.n, cap = 16;
    while (cap < 2 * corners)
        cap *= 2;
    uint64_t *keys = malloc(cap * sizeof *keys);
    double(*sum)[3] = calloc(cap, sizeof *sum);
    o->smooth_N = malloc((3 * corners + 1) * sizeof *o->smooth_N);
    double(*face_N)[3] = malloc((o->face_nv.n + 1) * sizeof *face_N);
    size_t *slot = malloc((corners + 1) * sizeof *slot);
    int ok = keys && sum && o->smooth_N && face_N && slot;
    for (size_t i = 0; ok && i < cap; i++)
        keys[i] = UINT64_MAX;
    size_t c = 0;
    for (size_t f = 0; ok && f < o->face_nv.n; c += (size_t)o->face_nv.a[f], f++) {
        const int *fv = &o->face_idx.a[c];
        newell(o, fv, o->face_nv.a[f], face_N[f]);
        for (int j = 0; j < o->face_nv.a[f] && o->face_s.a[f] != 0; j++) {
            uint64_t key = ((uint64_t)(uint32_t)fv[j] << 32) | (uint32_t)o->face_s.a[f];
            size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (cap - 1);
            while (keys[h] != UINT64_MAX && keys[h] != key)
                h = (h + 1) & (cap - 1);
            keys[h] = key;
            slot[c + (size_t)j] = h;
            for (int a = 0; a < 3; a++)
                sum[h][a] += face_N[f][a];
        }
    }
    c = 0;
    for (size_t f = 0; ok && f < o->face_nv.n; c += (size_t)o->face_nv.a[f], f++)
        for (int j = 0; j < o->face_nv.a[f]; j++) {
            const double *v = o->face_s.a[f] != 0 ? sum[slot[c + (size_t)j]] : face_N[f];
            double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            const double *u = len > 0.0 ? v : face_N[f]; /* opposite faces cancelled */
            len = len > 0.0 ? len : sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            for (int a = 0; a < 3; a++)
                o->smooth_N[3 * (c + (size_t)j) + (size_t)a] =
                    len > 0.0 ? (float)(u[a] / len) : (a == 2 ? 1.0f : 0.0f);
        }
    free(keys);
    free(sum);
    free(face_N);
    free(slot);
    return ok ? 0 : -1;
}

/* The facevarying N (vn) and st (vt: t = 1 - v, OBJ's v running up the
 * image) of mesh m's corners into pv, when every corner has them (with
 * one warning when only some do). Returns the count; the data are in
 * *store (free it). */
static size_t corner_primvars(Emit *e, const Mesh *m, RayesPrimvar pv[2], float **store)
{
    const Obj *o = e->o;
    size_t n = m->idx.n, k = 0;
    int has[2] = {1, 1}, any[2] = {0, 0};
    for (size_t i = 0; i < n; i++) {
        int c = m->idx.a[i], vals[2] = {o->face_vn.a[c], o->face_vt.a[c]};
        for (int q = 0; q < 2; q++)
            has[q] &= vals[q] >= 0, any[q] |= vals[q] >= 0;
    }
    if (o->smooth_N) /* every corner has a normal: vn, its smoothing group's or its face's */
        has[0] = 1, any[0] = 0;
    for (int q = 0; q < 2; q++)
        if (any[q] && !has[q])
            obj_warn(e->o, q ? "some vt" : "some vn", "%s: faces of one material with and "
                     "without %s: the %s are not used", o->name, q ? "vt" : "vn",
                     q ? "texture coordinates" : "normals");
    *store = has[0] || has[1] ? malloc(n * 5 * sizeof **store) : NULL;
    if (!*store)
        return 0;
    float *N = *store, *st = *store + 3 * n;
    for (size_t i = 0; i < n; i++) {
        int c = m->idx.a[i];
        if (has[0])
            memcpy(N + 3 * i,
                   o->face_vn.a[c] >= 0 ? &o->vn.a[3 * (size_t)o->face_vn.a[c]]
                                        : &o->smooth_N[3 * (size_t)c],
                   3 * sizeof *N);
        if (has[1]) {
            const float *t = &o->vt.a[2 * (size_t)o->face_vt.a[c]];
            st[2 * i] = t[0], st[2 * i + 1] = 1.0f - t[1];
        }
    }
    if (has[0])
        pv[k++] = (RayesPrimvar){"N", RAYES_PRIMVAR_FACEVARYING, N, n};
    if (has[1])
        pv[k++] = (RayesPrimvar){"st", RAYES_PRIMVAR_FACEVARYING, st, n};
    return k;
}

/* The colours of mesh m's points (e->local's order) as linear Cs in *Cs
 * (malloc'd; NULL when the file's vertices do not all have one): the
 * values are sRGB-encoded, as scanners and MeshLab write them, over 1 or
 * (when some exceeds 1) over 255. Returns 0, or -1 when out of memory. */
static int vertex_colours(Emit *e, const Mesh *m, float **Cs)
{
    const Obj *o = e->o;
    *Cs = NULL;
    if (o->vc_broken || o->vc.n != o->v.n || o->vc.n == 0)
        return 0;
    size_t n_points = e->P.n / 3;
    float *c = malloc((3 * n_points + 1) * sizeof *c), k = o->vc_max > 1.0f ? 1.0f / 255.0f : 1.0f;
    if (!c)
        return -1;
    for (size_t i = 0; i < m->idx.n; i++) {
        int g = o->face_idx.a[m->idx.a[i]], l = e->local[g];
        for (int a = 0; a < 3; a++)
            c[3 * (size_t)l + (size_t)a] = colour_srgb_to_linear(
                fminf(fmaxf(o->vc.a[3 * (size_t)g + (size_t)a] * k, 0.0f), 1.0f));
    }
    *Cs = c;
    return 0;
}

/* The faces of mesh m as one polygon mesh, with only the points they use. */
static RayesError emit_mesh(Emit *e, const Mesh *m, const char *mat)
{
    if (m->nv.n == 0)
        return RAYES_OK;
    IntVec idx = {malloc(m->idx.n * sizeof(int)), m->idx.n, m->idx.n};
    e->P.n = 0;
    RayesError r = idx.a ? RAYES_OK : RAYES_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < m->idx.n && r == RAYES_OK; i++) {
        int g = e->o->face_idx.a[m->idx.a[i]];
        if (e->local[g] < 0) {
            const float *p = vtx(e->o, g);
            e->local[g] = (int)(e->P.n / 3);
            for (int k = 0; k < 3; k++) {
                if (fpush(&e->P, p[k]) != 0)
                    r = RAYES_ERROR_OUT_OF_MEMORY;
                e->lo[k] = fminf(e->lo[k], p[k]);
                e->hi[k] = fmaxf(e->hi[k], p[k]);
            }
        }
        idx.a[i] = e->local[g];
    }
    RayesPrimvar pv[3];
    float *store = NULL, *Cs = NULL;
    size_t n_pv = r == RAYES_OK ? corner_primvars(e, m, pv, &store) : 0;
    if (r == RAYES_OK && vertex_colours(e, m, &Cs) != 0)
        r = RAYES_ERROR_OUT_OF_MEMORY;
    if (Cs)
        pv[n_pv++] = (RayesPrimvar){"Cs", RAYES_PRIMVAR_VERTEX, Cs, e->P.n / 3};
    for (size_t i = 0; i < m->idx.n; i++)
        e->local[e->o->face_idx.a[m->idx.a[i]]] = -1;
    if (r == RAYES_OK) {
        r = e->sink->polygon_mesh(e->sink->target, m->nv.n, m->nv.a, idx.a, e->P.n / 3, e->P.a,
                                  pv, n_pv);
        if (r != RAYES_OK) {
            char what[200];
            snprintf(what, sizeof what, "the faces of material \"%s\"", mat);
            r = sink_fail(e, r, what);
        }
    } else {
        snprintf(e->o->err, e->o->err_size, "%s: out of memory", e->o->name);
    }
    free(store);
    free(Cs);
    free(idx.a);
    return r;
}

/* 1 when material mt's emission is its map_Ke over the faces of m: every
 * corner has a vt and the sink takes textured lights (else one warning:
 * the emission is Ke alone). */
static int light_textured(Emit *e, const Material *mt, const Mesh *m)
{
    if (!mt->map_Ke[0])
        return 0;
    int all_vt = 1;
    for (size_t k = 0; k < m->idx.n && all_vt; k++)
        all_vt = e->o->face_vt.a[m->idx.a[k]] >= 0;
    if (all_vt && e->sink->area_light_mesh_textured && e->sink->area_light_mesh)
        return 1;
    obj_warn(e->o, "map_Ke untextured",
             "%s: material \"%s\": map_Ke needs %s; it emits Ke "
             "alone",
             e->o->name, mt->name,
             all_vt ? "a scene that takes textured lights" : "vt on every corner of its faces");
    return 0;
}

/* The faces of an emissive material as one mesh light (its corners' points
 * in file order), textured by map_Ke over their vt when textured. */
static RayesError emit_light_mesh(Emit *e, const Material *mt, const Mesh *m, int textured)
{
    size_t n_corners = 0;
    for (size_t f = 0; f < m->nv.n; f++)
        n_corners += (size_t)m->nv.a[f];
    float *P = malloc(3 * n_corners * sizeof *P);
    int *idx = malloc(n_corners * sizeof *idx);
    float *st = textured ? malloc(2 * n_corners * sizeof *st) : NULL;
    RayesError r = RAYES_ERROR_OUT_OF_MEMORY;
    if (P && idx && (st || !textured)) {
        for (size_t k = 0; k < n_corners; k++) {
            memcpy(&P[3 * k], vtx(e->o, e->o->face_idx.a[m->idx.a[k]]), 3 * sizeof *P);
            for (int a = 0; a < 3; a++) {
                e->lo[a] = fminf(e->lo[a], P[3 * k + (size_t)a]);
                e->hi[a] = fmaxf(e->hi[a], P[3 * k + (size_t)a]);
            }
            idx[k] = (int)k;
            if (st) { /* t = 1 - v: OBJ's v runs up the image */
                size_t ti = (size_t)e->o->face_vt.a[m->idx.a[k]];
                st[2 * k] = e->o->vt.a[2 * ti];
                st[2 * k + 1] = 1.0f - e->o->vt.a[2 * ti + 1];
            }
        }
        const float *Ke = mt->Ke;
        r = textured ? e->sink->area_light_mesh_textured(e->sink->target, m->nv.n, m->nv.a, idx,
                                                         n_corners, P, st, Ke, 0, mt->map_Ke)
                     : e->sink->area_light_mesh(e->sink->target, m->nv.n, m->nv.a, idx, n_corners,
                                                P, Ke, 0);
        if (r != RAYES_OK)
            r = sink_fail(e, r, "an emissive mesh");
        e->n_area_lights++;
    } else {
        snprintf(e->o->err, e->o->err_size, "%s: out of memory", e->o->name);
    }
    free(P);
    free(idx);
    free(st);
    return r;
}

/* The faces of an emissive material: at most AREA_QUADS quads are quad
 * lights, other faces one mesh light; for a sink without mesh lights,
 * the faces but quads are constant-shaded polygons (seen, but lighting
 * nothing), with a warning. */
#define AREA_QUADS 4
static RayesError emit_emitter(Emit *e, const Material *mt, const Mesh *m)
{
    int few_quads = m->nv.n <= AREA_QUADS;
    for (size_t f = 0; f < m->nv.n && few_quads; f++)
        few_quads = m->nv.a[f] == 4;
    if (m->nv.n == 0) /* a material no face uses */
        return RAYES_OK;
    int textured = light_textured(e, mt, m);
    if ((!few_quads || textured) && e->sink->area_light_mesh)
        return emit_light_mesh(e, mt, m, textured);
    Mesh rest = {{0}, {0}};
    RayesError r = RAYES_OK;
    size_t k = 0;
    for (size_t f = 0; f < m->nv.n && r == RAYES_OK; k += (size_t)m->nv.a[f], f++) {
        if (m->nv.a[f] == 3) {
            if (mesh_face(&rest, m->idx.a[k], m->idx.a[k + 1], m->idx.a[k + 2], -1) != 0)
                r = RAYES_ERROR_OUT_OF_MEMORY;
            continue;
        }
        float P[4][3];
        for (int c = 0; c < 4; c++) {
            memcpy(P[c], vtx(e->o, e->o->face_idx.a[m->idx.a[k + (size_t)c]]), sizeof P[c]);
            for (int a = 0; a < 3; a++) {
                e->lo[a] = fminf(e->lo[a], P[c][a]);
                e->hi[a] = fmaxf(e->hi[a], P[c][a]);
            }
        }
        r = e->sink->area_light(e->sink->target, P, mt->Ke);
        if (r != RAYES_OK)
            r = sink_fail(e, r, "an emissive quad");
        e->n_area_lights++;
    }
    if (r == RAYES_OK && rest.nv.n > 0) {
        obj_warn(e->o, "emitter", "%s: material \"%s\": only quads emit light (area lights); its "
                                  "other faces are shaded constant and light nothing",
                 e->o->name, mt->name);
        RayesParam p = {"Cs", RAYES_PARAM_COLOR, {mt->Ke[0], mt->Ke[1], mt->Ke[2]}, NULL};
        r = set_shader(e, "constant", &p, 1, mt->name);
        if (r == RAYES_OK)
            r = emit_mesh(e, &rest, mt->name);
    }
    if (r == RAYES_ERROR_OUT_OF_MEMORY && !e->o->err[0])
        snprintf(e->o->err, e->o->err_size, "%s: out of memory", e->o->name);
    free(rest.nv.a);
    free(rest.idx.a);
    return r;
}

/* The faces of material mi (-1: the default) in file order. */
/* Whether every corner of the face whose first corner is base has a vt. */
static int face_has_vt(const Obj *o, size_t base, int n)
{
    for (int j = 0; j < n; j++)
        if (o->face_vt.a[base + (size_t)j] < 0)
            return 0;
    return 1;
}

/* The faces of material mi (-1: the default) in file order: those whose
 * corners all have texture coordinates as one mesh, the others as another
 * (an object without a UV map sharing a textured object's material takes
 * nothing from it). */
static RayesError emit_material(Emit *e, int mi)
{
    Obj *o = e->o;
    Mesh m[2] = {{{0}, {0}}, {{0}, {0}}}; /* with vt, without */
    Material *mt = mi >= 0 ? &o->mats[mi] : NULL;
    /* a map without a colour emits the map's colours (Ke 0 or missing, as
     * exporters write it beside the map) */
    if (mt && mt->map_Ke[0] && !(max3(mt->Ke) > 0.0f))
        mt->Ke[0] = mt->Ke[1] = mt->Ke[2] = 1.0f;
    int emits = mt && max3(mt->Ke) > 0.0f; /* one mesh (vt or not) */
    RayesError r = RAYES_OK;
    size_t k = 0;
    for (size_t f = 0; f < o->face_nv.n && r == RAYES_OK; k += (size_t)o->face_nv.a[f], f++)
        if (o->face_mat.a[f] == mi &&
            triangulate(o, &m[!emits && !face_has_vt(o, k, o->face_nv.a[f])], (int)k,
                        o->face_nv.a[f]) != 0)
            r = RAYES_ERROR_OUT_OF_MEMORY;
    if (m[0].nv.n == 0) { /* one mesh when no face has vt */
        Mesh t = m[0];
        m[0] = m[1], m[1] = t;
    }
    if (r != RAYES_OK)
        snprintf(o->err, o->err_size, "%s: out of memory", o->name);
    else if (emits) {
        char none[2][48];
        RayesParam unused;
        if ((r = bump_of(e, NULL, none, &unused)) == RAYES_OK) /* lights are not bumped */
            r = emit_emitter(e, mt, &m[0]);
    } else if (m[0].nv.n > 0 && (r = material_shader(e, mt)) == RAYES_OK) {
        for (int j = 0; j < 2 && r == RAYES_OK; j++)
            r = emit_mesh(e, &m[j], mt ? mt->name : "(none)");
    }
    for (int j = 0; j < 2; j++) {
        free(m[j].nv.a);
        free(m[j].idx.a);
    }
    return r;
}

static void unit3(float v[3])
{
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3 && len > 0.0f; k++)
        v[k] /= len;
}

/* The default camera: on the +z side of the bounds' centre, looking down
 * -z with +y up, far enough that the bounding sphere fits a 40 degree
 * field of view. The default light follows the view the image is made
 * from (this one, or the caller's, view): seen from outside the bounds, a
 * distant light of intensity 1 from the view's upper left and behind
 * (the direction (-1, 1, 1) from the centre for the default view); from
 * inside them (a room, a courtyard), where walls would shadow any light
 * from outside, a headlight: a distant light along the view that casts no
 * shadows, as --default-light adds. */
static RayesError emit_camera(Emit *e, int light)
{
    float c[3], r2 = 0.0f;
    int empty = !(e->lo[0] <= e->hi[0]);
    for (int k = 0; k < 3; k++) {
        c[k] = empty ? 0.0f : 0.5f * (e->lo[k] + e->hi[k]);
        float h = empty ? 1.0f : 0.5f * (e->hi[k] - e->lo[k]);
        r2 += h * h;
    }
    float r = fmaxf(sqrtf(r2), 1e-3f);
    float d = r / sinf(20.0f * (float)M_PI / 180.0f);
    const float eye[3] = {c[0], c[1], c[2] + d}, up[3] = {0, 1, 0};
    RayesError res = e->sink->set_camera(e->sink->target, eye, c, up, 40.0f);
    if (res != RAYES_OK)
        return sink_fail(e, res, "the default camera");
    if (!light)
        return RAYES_OK;
    /* the view the image is made from: the caller's eye, point and up
     * where it sets them (a point not set is straight ahead) */
    unsigned v = e->ro ? e->ro->view : 0;
    float E[3], Z[3], Y[3], X[3];
    for (int k = 0; k < 3; k++) {
        E[k] = v & IO_VIEW_FROM ? e->ro->view_from[k] : eye[k];
        Z[k] = v & IO_VIEW_AT ? e->ro->view_at[k] - E[k] : c[k] - eye[k];
        Y[k] = v & IO_VIEW_UP ? e->ro->view_up[k] : up[k];
    }
    unit3(Z);
    float yz = Y[0] * Z[0] + Y[1] * Z[1] + Y[2] * Z[2];
    for (int k = 0; k < 3; k++)
        Y[k] -= yz * Z[k];
    unit3(Y);
    X[0] = Z[1] * Y[2] - Z[2] * Y[1]; /* the image's right */
    X[1] = Z[2] * Y[0] - Z[0] * Y[2];
    X[2] = Z[0] * Y[1] - Z[1] * Y[0];
    int inside = !empty;
    for (int k = 0; k < 3; k++)
        inside &= E[k] > e->lo[k] && E[k] < e->hi[k];
    RayesParam p[4] = {
        {"from", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
        {"to", RAYES_PARAM_COLOR, {Z[0], Z[1], Z[2]}, NULL},
        {"intensity", RAYES_PARAM_FLOAT, {(float)M_PI, 0, 0}, NULL}, /* facing: Cs */
        {"shadows", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
    };
    if (!inside)
        for (int k = 0; k < 3; k++) /* toward the centre from the view's upper left, behind */
            p[0].value[k] = c[k] + d * (Y[k] - X[k] - Z[k]), p[1].value[k] = c[k];
    res = e->sink->light(e->sink->target, "distantlight", p, inside ? 4 : 3);
    return res == RAYES_OK ? RAYES_OK : sink_fail(e, res, "the default light");
}

static RayesError obj_emit(Obj *o, const IoSink *sink, const IoReadOptions *ro)
{
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    Emit e = {.o = o,
              .sink = sink,
              .ro = ro,
              .lo = {INFINITY, INFINITY, INFINITY},
              .hi = {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t i = 0; i < o->n_mats; i++)
        if (!o->mats[i].defined)
            obj_warn(o, o->mats[i].name, "%s: material \"%s\" is not defined; matte grey used",
                     o->name, o->mats[i].name);
    e.local = malloc((o->v.n / 3 + 1) * sizeof *e.local);
    if (!e.local) {
        snprintf(o->err, o->err_size, "%s: out of memory", o->name);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < o->v.n / 3; i++)
        e.local[i] = -1;
    RayesError r = sink->set_transform(sink->target, identity);
    if (r != RAYES_OK)
        r = sink_fail(&e, r, "the transform");
    /* undefined materials are the default */
    for (size_t f = 0; f < o->face_mat.n; f++)
        if (o->face_mat.a[f] >= 0 && !o->mats[o->face_mat.a[f]].defined)
            o->face_mat.a[f] = -1;
    int some_vn = 0, all_vn = 1; /* corners without vn beside ones with: their faces' */
    for (size_t c = 0; c < o->face_vn.n; c++)
        some_vn |= o->face_vn.a[c] >= 0, all_vn &= o->face_vn.a[c] >= 0;
    if (r == RAYES_OK && (o->any_s || (some_vn && !all_vn)) && obj_smooth_normals(o) != 0) {
        snprintf(o->err, o->err_size, "%s: out of memory", o->name);
        r = RAYES_ERROR_OUT_OF_MEMORY;
    }
    for (int mi = -1; mi < (int)o->n_mats && r == RAYES_OK; mi++)
        r = emit_material(&e, mi);
    if (r == RAYES_OK)
        r = emit_camera(&e, e.n_area_lights == 0);
    free(e.local);
    free(e.P.a);
    return r;
}

/* ------------------------------------------------------------- entry */

RayesError io_obj_parse(const char *name, const unsigned char *data, size_t size,
                        const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                        char *err, size_t err_size)
{
    (void)settings; /* OBJ sets no render settings */
    Obj o = {.name = name, .cur_mat = -1, .err = err, .err_size = err_size};
    err[0] = '\0';
    dir_of(name, o.dir, sizeof o.dir);
    RayesError r = RAYES_OK;
    if (obj_parse_text(&o, (const char *)data, size) != 0)
        r = strstr(err, "out of memory") ? RAYES_ERROR_OUT_OF_MEMORY : RAYES_ERROR_PARSE;
    else
        r = obj_emit(&o, sink, options);
    free(o.v.a);
    free(o.vc.a);
    free(o.face_nv.a);
    free(o.face_idx.a);
    free(o.face_vt.a);
    free(o.face_vn.a);
    free(o.vt.a);
    free(o.vn.a);
    free(o.face_mat.a);
    free(o.face_s.a);
    free(o.smooth_N);
    free(o.mats);
    return r;
}

RayesError io_obj_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                       IoSettings *settings, char *err, size_t err_size)
{
    size_t size = 0;
    char *text = text_read_file(path, &size, err, err_size);
    if (!text)
        return RAYES_ERROR_IO;
    RayesError r = io_obj_parse(path, (const unsigned char *)text, size, sink, options, settings,
                                err, err_size);
    free(text);
    return r;
}
