/*
 * io/rib.c — the RIB reader of rib.h (docs/rib.md says what is supported,
 * mapped, warned about and skipped): reading and dispatch. This file reads
 * files and archives (ReadArchive, DelayedReadArchive: found beside the
 * reading file or on the archive search path, up to 32 deep), their
 * requests and arguments, sends each request to its handler (the request
 * tables of the reader's files, rib_reader.h), and runs the two passes.
 *
 * A file is read twice. The first pass drives a sink that does nothing:
 * it checks the whole stream (so bad input reaches no scene) and lists the
 * frames, which of them render an image (not a shadow-map pass), so that
 * frame -1 can mean "the last frame that renders an image". The second
 * pass reads that frame (and everything outside frames) into the caller's
 * sink. Every file and archive is read whole through zlib (gzopen/gzread
 * pass plain files through), so .rib and .rib.gz share one path.
 *
 * Limits (bad input fails cleanly): archive depth 32, attribute stack
 * 1024, files up to 1 GB uncompressed, arguments per request 1,000,000.
 */
#include "io/rib.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#include "io/rib_cond.h"
#include "io/rib_reader.h"
#include "io/zip.h"
#include "util/log.h"

/* -------------------------------------------------------------- files */

/* The whole file through zlib (plain or gzip); new buffer or NULL. */
static unsigned char *read_gz(const char *path, size_t *size, char *err, size_t err_size)
{
    gzFile f = gzopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open the file", path);
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            snprintf(err, err_size, "%s: out of memory", path);
            break;
        }
        if (n == cap) {
            if (cap >= RIB_MAX_FILE_BYTES) {
                snprintf(err, err_size, "%s: larger than 1 GB uncompressed", path);
                free(buf);
                buf = NULL;
                break;
            }
            unsigned char *b = realloc(buf, cap * 2);
            if (!b) {
                free(buf);
                buf = NULL;
                continue;
            }
            buf = b;
            cap *= 2;
        }
        int got = gzread(f, buf + n, (unsigned)(cap - n > (1u << 30) ? (1u << 30) : cap - n));
        if (got < 0) {
            int code;
            snprintf(err, err_size, "%s: cannot read the file (%s)", path, gzerror(f, &code));
            free(buf);
            buf = NULL;
            break;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    gzclose(f);
    *size = n;
    return buf;
}

/* A gzip buffer inflated (io_rib_parse of compressed data); NULL on error. */
static unsigned char *inflate_buffer(const unsigned char *data, size_t size, size_t *out_size)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit2(&z, 15 + 32) != Z_OK)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    z.next_in = (unsigned char *)data;
    z.avail_in = (uInt)(size > UINT32_MAX ? UINT32_MAX : size);
    int ret = Z_OK;
    while (buf && ret == Z_OK) {
        if (n == cap) {
            unsigned char *b = cap < RIB_MAX_FILE_BYTES / 4 ? realloc(buf, cap * 2) : NULL;
            if (!b) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = b;
            cap *= 2;
        }
        z.next_out = buf + n;
        z.avail_out = (uInt)(cap - n);
        ret = inflate(&z, Z_NO_FLUSH);
        n = cap - z.avail_out;
        if (ret == Z_BUF_ERROR && z.avail_in == 0)
            break;
    }
    inflateEnd(&z);
    if (buf && ret != Z_STREAM_END) {
        free(buf);
        buf = NULL;
    }
    *out_size = n;
    return buf;
}

/* ------------------------------------------------------------ parsing */

static void args_clear(Args *a)
{
    for (size_t i = 0; i < a->n; i++) {
        free(a->v[i].d);
        if (a->v[i].s)
            for (size_t k = 0; k < a->v[i].n; k++)
                free(a->v[i].s[k]);
        free(a->v[i].s);
    }
    a->n = 0;
}

static Arg *args_push(Rib *r, Args *a, const RibToken *t)
{
    if (a->n >= RIB_MAX_ARGS) {
        rib_lex_error_at(r->lx, t->line, t->col, "more than %d arguments", RIB_MAX_ARGS);
        return NULL;
    }
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 16;
        Arg *v = realloc(a->v, cap * sizeof *v);
        if (!v) {
            rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
            return NULL;
        }
        a->v = v;
        a->cap = cap;
    }
    Arg *g = &a->v[a->n++];
    memset(g, 0, sizeof *g);
    g->line = t->line;
    g->col = t->col;
    return g;
}

static int add_num(Rib *r, Arg *g, double v, size_t *cap, const RibToken *t)
{
    if (!isfinite(v) || fabs(v) > FLT_MAX)
        return rib_lex_error_at(r->lx, t->line, t->col, "a number out of range");
    if (g->n == *cap) {
        size_t c = *cap ? 2 * *cap : 4;
        double *d = realloc(g->d, c * sizeof *d);
        if (!d)
            return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
        g->d = d;
        *cap = c;
    }
    g->d[g->n++] = v;
    return 0;
}

static int add_str(Rib *r, Arg *g, const RibToken *t, size_t *cap)
{
    if (g->n == *cap) {
        size_t c = *cap ? 2 * *cap : 4;
        char **s = realloc(g->s, c * sizeof *s);
        if (!s)
            return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
        g->s = s;
        *cap = c;
    }
    char *copy = malloc(t->len + 1);
    if (!copy)
        return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
    memcpy(copy, t->str, t->len + 1);
    g->s[g->n++] = copy;
    return 0;
}

/* Reads the arguments of a request up to the next request (left in *t). */
static int read_args(Rib *r, Args *a, RibToken *t)
{
    for (;;) {
        if (rib_lex_next(r->lx, t) != 0)
            return -1;
        if (t->type == RIB_TOK_REQUEST || t->type == RIB_TOK_EOF)
            return 0;
        if (t->type == RIB_TOK_RBRACKET)
            return rib_lex_error_at(r->lx, t->line, t->col, "']' without '['");
        Arg *g = args_push(r, a, t);
        if (!g)
            return -1;
        size_t cap = 0;
        if (t->type == RIB_TOK_NUMBER) {
            g->kind = ARG_NUM;
            if (add_num(r, g, t->num, &cap, t) != 0)
                return -1;
        } else if (t->type == RIB_TOK_STRING) {
            g->kind = ARG_STR;
            if (add_str(r, g, t, &cap) != 0)
                return -1;
        } else if (t->type == RIB_TOK_FLOATS) {
            g->kind = ARG_NUMS;
            for (size_t k = 0; k < t->n_floats; k++)
                if (add_num(r, g, t->floats[k], &cap, t) != 0)
                    return -1;
        } else { /* '[' */
            g->kind = ARG_NUMS;
            int strings = -1;
            long l0 = t->line, c0 = t->col;
            for (;;) {
                if (rib_lex_next(r->lx, t) != 0)
                    return -1;
                if (t->type == RIB_TOK_RBRACKET)
                    break;
                int is_str = t->type == RIB_TOK_STRING;
                if (t->type != RIB_TOK_NUMBER && t->type != RIB_TOK_STRING &&
                    t->type != RIB_TOK_FLOATS)
                    return rib_lex_error_at(r->lx, l0, c0, "the array has no closing ']'");
                if (strings >= 0 && strings != is_str)
                    return rib_lex_error_at(r->lx, t->line, t->col,
                                            "an array mixes numbers and strings");
                strings = is_str;
                g->kind = is_str ? ARG_STRS : ARG_NUMS;
                int e = 0;
                if (is_str)
                    e = add_str(r, g, t, &cap);
                else if (t->type == RIB_TOK_NUMBER)
                    e = add_num(r, g, t->num, &cap, t);
                else
                    for (size_t k = 0; e == 0 && k < t->n_floats; k++)
                        e = add_num(r, g, t->floats[k], &cap, t);
                if (e != 0)
                    return -1;
            }
        }
    }
}

/* ----------------------------------------------------------- archives */

static int run(Rib *r, const char *name, const unsigned char *data, size_t size);

/* Archives must be regular files (not devices or pipes, which could
 * stream forever). */
static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* Reads an archive's text (named name, its first line first_line) inside
 * the current request, which is the current one again after. */
static int run_archive(Rib *r, const char *name, const unsigned char *data, size_t size,
                       long first_line)
{
    RibLexer *outer = r->lx;
    const char *outer_file = r->file;
    char req[64];
    long line = r->req_line, col = r->req_col;
    memcpy(req, r->req, sizeof req);
    r->archive_depth++;
    r->first_line = first_line;
    int e = run(r, name, data, size);
    r->first_line = 1;
    r->archive_depth--;
    r->lx = outer;
    r->file = outer_file;
    memcpy(r->req, req, sizeof req);
    r->req_line = line, r->req_col = col;
    return e;
}

/* Inline archive text read at most, in all: an archive read twice by
 * each of 30 others nested would be 2^30 reads of it. */
#define RIB_MAX_INLINE_READ ((size_t)256 << 20)

/* Reads an inline archive's text as a ReadArchive reads a file. */
static int read_inline(Rib *r, const struct InlineArchive *ia)
{
    r->inline_read += ia->size;
    if (r->inline_read > RIB_MAX_INLINE_READ)
        return rib_error(r,
                         "inline archives read more than %zu MB of text in all (archives "
                         "reading each other many times?)",
                         RIB_MAX_INLINE_READ >> 20);
    return run_archive(r, ia->file, (const unsigned char *)ia->text, ia->size, ia->line);
}

/* Directories above the including file's that a relative archive name is
 * looked for in, last. */
#define RIB_ARCHIVE_UP 4

static int read_archive(Rib *r, const char *name_in)
{
    if (r->archive_depth >= RIB_MAX_ARCHIVE_DEPTH)
        return rib_error(r, "archives nested more than %d deep (a loop?)", RIB_MAX_ARCHIVE_DEPTH);
    /* "file.zip!member": a member of a zip file, found as the file is */
    char name[2048];
    snprintf(name, sizeof name, "%s", name_in);
    char *bang = strstr(name, ".zip!");
    const char *member = NULL;
    if (bang) {
        bang[4] = '\0';
        member = bang + 5;
    }
    for (size_t k = r->n_inline; k-- > 0;) { /* the newest of that name */
        const struct InlineArchive *ia = &r->inline_archives[k];
        if (strcmp(ia->name, name_in) == 0)
            return read_inline(r, ia);
    }
    char path[4096] = "";
    if (name[0] == '/') {
        snprintf(path, sizeof path, "%s", name);
    } else {
        const char *slash = strrchr(r->file, '/');
        int dir = slash ? (int)(slash - r->file) : 0;
        snprintf(path, sizeof path, "%.*s%s%s", dir, r->file, slash ? "/" : "", name);
        if (!file_exists(path)) {
            char buf[4096];
            snprintf(buf, sizeof buf, "%s", r->archive_path);
            for (char *save = NULL, *d = strtok_r(buf, ":", &save); d;
                 d = strtok_r(NULL, ":", &save)) {
                char cand[4096];
                snprintf(cand, sizeof cand, "%s/%s", d, name);
                if (file_exists(cand)) {
                    snprintf(path, sizeof path, "%s", cand);
                    break;
                }
            }
        }
        /* then the working directory, as PRMan reads it (exporters write
         * paths from the project's directory they render in) */
        if (!file_exists(path) && file_exists(name))
            snprintf(path, sizeof path, "%s", name);
        /* then the directories above the including file's: the project's
         * directory, when rayes runs elsewhere */
        char cand[4096];
        if (!file_exists(path) &&
            rib_find_above(r->file, name, RIB_ARCHIVE_UP, cand, sizeof cand) == 0)
            memcpy(path, cand, sizeof path);
    }
    char err[600];
    size_t size;
    if (!file_exists(path))
        return rib_error(r,
                         "archive \"%s\": not found (as %s, in the working directory, in the "
                         "directories above the file's, nor on the archive search path)",
                         name_in, path);
    unsigned char *data =
        member ? io_zip_member(path, member, RIB_MAX_FILE_BYTES, &size, err, sizeof err)
               : read_gz(path, &size, err, sizeof err);
    if (!data)
        return rib_error(r, "archive \"%s\": %s", name_in, err);
    char *path_copy = rib_strdup(path);
    int e = path_copy ? run_archive(r, path_copy, data, size, 1) : rib_error(r, "out of memory");
    free(path_copy);
    free(data);
    return e;
}

static int h_read_archive(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "an archive name");
    return name ? read_archive(r, name) : -1;
}

static int h_procedural(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *kind = rib_get_string(r, a, &i, "a procedural name");
    if (!kind)
        return -1;
    if (strcmp(kind, "DelayedReadArchive") == 0 && i < a->n && a->v[i].kind == ARG_STRS &&
        a->v[i].n >= 1)
        return read_archive(r, a->v[i].s[0]);
    char key[128];
    snprintf(key, sizeof key, "procedural %s", kind);
    rib_warn_once(r, key, "Procedural \"%s\" is not supported and skipped", kind);
    return 0;
}

/* Procedural2 "DelayedReadArchive2" "SimpleBound" "string filename" [f]
 * ...: RenderMan 20's form of DelayedReadArchive (what RenderMan for Maya
 * writes), read here as ReadArchive; other kinds are skipped. */
static int h_procedural2(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *kind = rib_get_string(r, a, &i, "a procedural name");
    if (!kind || !rib_get_string(r, a, &i, "a bound function name"))
        return -1;
    char key[128];
    snprintf(key, sizeof key, "procedural2 %s", kind);
    if (strcmp(kind, "DelayedReadArchive2") != 0) {
        rib_warn_once(r, key, "Procedural2 \"%s\" is not supported and skipped", kind);
        return 0;
    }
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    const Param *f = rib_find_param(p, n, "filename");
    char *name = f && f->d.ty == TY_STRING && f->v->n == 1 ? rib_strdup(f->v->s[0]) : NULL;
    free(p);
    if (!name)
        return rib_error(r, "Procedural2 \"DelayedReadArchive2\" needs a \"string filename\"");
    int e = read_archive(r, name);
    free(name);
    return e;
}

/* GeometricRepresentation "primitive" is every surface's default; points
 * and lines (a wireframe) are drawn as surfaces, with one warning. */
static int h_geometric_representation(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *kind = rib_get_string(r, a, &i, "a representation name");
    if (!kind)
        return -1;
    if (strcmp(kind, "primitive") != 0)
        rib_warn_once(r, "GeometricRepresentation",
                      "GeometricRepresentation \"%s\" is not supported: surfaces are drawn", kind);
    return 0;
}

/* ----------------------------------------------------------- dispatch */

/* MotionBegin [t0 t1 ...]: the requests up to MotionEnd are the samples of
 * one transform (each applied to the transform before the block) or of one
 * primitive (deformation, through the sink's motion_begin/end), in order. */
static int h_motion_begin(Rib *r, const Args *a)
{
    if (a->n < 1 || (a->v[0].kind != ARG_NUMS && a->v[0].kind != ARG_NUM))
        return rib_error(r, "expected an array of times");
    const Arg *t = &a->v[0];
    if (t->n < 1 || t->n > RIB_MAX_TIMES)
        return rib_error(r, "expected 1 to %d times, found %zu", RIB_MAX_TIMES, t->n);
    for (size_t k = 0; k < t->n; k++) {
        if (!isfinite(t->d[k]) || (k > 0 && !(t->d[k] > t->d[k - 1])))
            return rib_error(r, "expected finite, increasing times");
        r->motion_time[k] = (float)t->d[k];
    }
    r->motion = 1;
    r->motion_seen = 0;
    r->motion_n = t->n;
    r->motion_kind = 0;
    memcpy(r->motion_pre, r->a.M, sizeof r->motion_pre);
    r->motion_pre_n = r->a.n_motion;
    memcpy(r->motion_pre_time, r->a.motion_time, sizeof r->motion_pre_time);
    memcpy(r->motion_pre_M, r->a.motion_M, sizeof r->motion_pre_M);
    return 0;
}

static int is_transform_request(const char *q)
{
    static const char *const names[] = {"Translate", "Rotate", "Scale", "ConcatTransform",
                                        "Transform", "Skew", "Perspective", "Identity", NULL};
    for (int k = 0; names[k]; k++)
        if (strcmp(q, names[k]) == 0)
            return 1;
    return 0;
}

/* The most a transform turns between two samples sent on (radians): the
 * renderer blends samples linearly, which cuts a turn's arc by its chord
 * (an object turning 90 degrees between two samples would shrink to 0.71
 * of its size half way); 10 degrees leaves 0.4%. */
#define RIB_MOTION_TURN ((float)(M_PI / 18))

/* Whether every sample of the block is request q. */
static int all_samples(const Rib *r, const char *q)
{
    for (size_t k = 0; k < r->motion_n; k++)
        if (strcmp(r->motion_req[k], q) != 0)
            return 0;
    return 1;
}

/* M before the block at time t: an earlier block's samples blended (a
 * motion block after another, as a child's transform moves within its
 * parent's), else the one matrix. */
static void pre_at(const Rib *r, float t, float out[16])
{
    int n = r->motion_pre_n;
    const float *tm = r->motion_pre_time;
    if (n < 2) {
        memcpy(out, r->motion_pre, 16 * sizeof *out);
        return;
    }
    int k = 0;
    while (k + 1 < n && t > tm[k + 1])
        k++;
    if (k + 1 >= n || t <= tm[k])
        memcpy(out, r->motion_pre_M[k + 1 >= n ? n - 1 : k], 16 * sizeof *out);
    else if (t == tm[k + 1])
        memcpy(out, r->motion_pre_M[k + 1], 16 * sizeof *out);
    else
        rib_mat_blend(r->motion_pre_M[k], r->motion_pre_M[k + 1], (t - tm[k]) / (tm[k + 1] - tm[k]),
                      out);
}

/* The block's own transform a fraction f from its sample k to k + 1
 * (local: each sample in the frame before the block). */
static void local_between(const Rib *r, float local[][16], int rotate, size_t k, float f,
                          float L[16])
{
    if (f <= 0.0f)
        memcpy(L, local[k], 16 * sizeof *L);
    else if (rotate)
        rib_mat_rotate(r->motion_rotate[k][0] +
                           f * (r->motion_rotate[k + 1][0] - r->motion_rotate[k][0]),
                       r->motion_rotate[k] + 1, L);
    else
        rib_mat_blend(local[k], local[k + 1], f, L);
}

/* A transform motion block's samples, more of them where its request
 * turns, at most RIB_MAX_TIMES: Rotates about one axis move their angle
 * (as PRMan moves a request's parameters: Rotate 0 to Rotate 360 spins
 * once); other turning requests are blended in their own frame (about
 * their origin; Transform's is the world's), rotation by slerp.
 * Translate and Scale move linearly already. When the transform before
 * the block moved too (an earlier block), each sample is the block's
 * request at its time after that motion at the same time, at the times of
 * both blocks. */
static void motion_transforms(Rib *r)
{
    size_t n = r->motion_n, total = 1, n_extra = 0;
    float inv[16], pre[16], local[RIB_MAX_TIMES][16], extra[RIB_MAX_TIMES];
    int sub[RIB_MAX_TIMES], any = r->motion_pre_n > 1;
    int rotate = all_samples(r, "Rotate"), whole = 1;
    for (size_t k = 0; k < n; k++) /* Transform and Identity set the whole matrix */
        whole &=
            strcmp(r->motion_req[k], "Transform") == 0 || strcmp(r->motion_req[k], "Identity") == 0;
    for (size_t k = 1; rotate && k < n; k++) { /* one axis, the same direction */
        const float *a = r->motion_rotate[0] + 1, *b = r->motion_rotate[k] + 1;
        double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
        double lb = sqrt((double)b[0] * b[0] + (double)b[1] * b[1] + (double)b[2] * b[2]);
        double d = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
        rotate = la > 0 && lb > 0 && d > 0.999999;
    }
    int turning = n >= 2 && (rotate || whole || all_samples(r, "ConcatTransform"));
    if (!turning && !any)
        return;
    for (size_t k = 0; k < n; k++) {
        pre_at(r, r->motion_time[k], pre);
        if (whole)
            memcpy(local[k], r->motion_M[k], sizeof local[k]);
        else if (rib_mat_inverse(pre, inv) == 0)
            rib_mat_mul(inv, r->motion_M[k], local[k]);
        else
            return; /* a singular transform before the block: its samples as they are */
    }
    for (size_t k = 0; k + 1 < n; k++) {
        float turn = !turning ? 0.0f
                     : rotate ? fabsf(r->motion_rotate[k + 1][0] - r->motion_rotate[k][0]) *
                                    (float)(M_PI / 180)
                              : rib_mat_turn(local[k], local[k + 1]);
        float steps = ceilf(turn / RIB_MOTION_TURN - 1e-3f); /* 90 degrees: 9 */
        sub[k] = steps > 1 ? (int)fminf(steps, 64) : 1;
        any |= sub[k] > 1;
        total += (size_t)sub[k];
    }
    if (!any)
        return;
    for (int j = 0; !whole && j < r->motion_pre_n; j++) { /* the earlier block's own times */
        size_t k = 0;
        while (k < n && r->motion_time[k] != r->motion_pre_time[j])
            k++;
        if (k == n && n + n_extra < RIB_MAX_TIMES)
            extra[n_extra++] = r->motion_pre_time[j];
    }
    total += n_extra;
    while (total > RIB_MAX_TIMES) { /* the most samples where the most turn */
        size_t big = 0;
        for (size_t k = 1; k + 1 < n; k++)
            if (sub[k] > sub[big])
                big = k;
        sub[big]--;
        total--;
    }
    float times[RIB_MAX_TIMES], M[RIB_MAX_TIMES][16], L[16];
    size_t m = 0, own[RIB_MAX_TIMES]; /* own: 1 + the block's sample, kept exact */
    for (size_t k = 0; k < n; k++)
        for (int j = 0; j < (k + 1 < n ? sub[k] : 1); j++, m++) {
            float f = j == 0 ? 0.0f : (float)j / (float)sub[k];
            times[m] = j == 0 ? r->motion_time[k]
                              : r->motion_time[k] + f * (r->motion_time[k + 1] - r->motion_time[k]);
            local_between(r, local, rotate, k, f, M[m]);
            own[m] = j == 0 ? k + 1 : 0;
        }
    for (size_t e = 0; e < n_extra; e++, m++) { /* sorted in below */
        float t = extra[e];
        size_t k = 0;
        while (k + 1 < n && t > r->motion_time[k + 1])
            k++;
        float f = k + 1 < n ? (t - r->motion_time[k]) / (r->motion_time[k + 1] - r->motion_time[k])
                            : 0.0f;
        local_between(r, local, rotate, k, fmaxf(f, 0.0f), M[m]);
        times[m] = t;
        own[m] = 0;
    }
    for (size_t i = 1; i < m; i++) /* insertion sort by time */
        for (size_t j = i; j > 0 && times[j - 1] > times[j]; j--) {
            float t = times[j];
            size_t o = own[j];
            times[j] = times[j - 1], times[j - 1] = t;
            own[j] = own[j - 1], own[j - 1] = o;
            memcpy(L, M[j], sizeof L);
            memcpy(M[j], M[j - 1], sizeof L);
            memcpy(M[j - 1], L, sizeof L);
        }
    for (size_t k = 0; k < m; k++) {
        if (own[k])
            memcpy(M[k], r->motion_M[own[k] - 1], sizeof M[k]);
        if (own[k] || whole)
            continue;
        pre_at(r, times[k], pre);
        memcpy(L, M[k], sizeof L);
        rib_mat_mul(pre, L, M[k]);
    }
    r->motion_n = m;
    memcpy(r->motion_time, times, m * sizeof *times);
    memcpy(r->motion_M, M, m * sizeof M[0]);
}

static int motion_end(Rib *r)
{
    r->motion = 0;
    if (r->motion_kind != 0 && (size_t)r->motion_seen != r->motion_n)
        return rib_error(r, "the block has %d requests for %zu times", r->motion_seen,
                         r->motion_n);
    if (r->motion_kind == 1) {
        motion_transforms(r);
        memcpy(r->a.M, r->motion_M[0], sizeof r->a.M);
        r->a.n_motion = r->motion_n > 1 ? (int)r->motion_n : 0;
        memcpy(r->a.motion_time, r->motion_time, r->motion_n * sizeof *r->motion_time);
        memcpy(r->a.motion_M, r->motion_M, r->motion_n * sizeof r->motion_M[0]);
        return 0;
    }
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (r->motion_kind == 2 && r->motion_n > 1 && s->motion_end && s->motion_begin && !r->a.area &&
        s->motion_end(s->target) != RAYES_OK)
        return rib_sink_failed(r, s);
    return 0;
}

/* One request inside a motion block (the sample motion_seen). Returns 1 if
 * it was consumed here, else 0 (dispatch runs it), or -1. */
static int motion_request(Rib *r, const char *q, const Args *a, int (*run)(Rib *, const Args *))
{
    size_t k = (size_t)r->motion_seen++;
    if (k >= r->motion_n)
        return rib_error(r, "the motion block has more requests than its %zu times",
                         r->motion_n);
    int transform = is_transform_request(q);
    if (r->motion_kind && r->motion_kind != (transform ? 1 : 2))
        return rib_error(r, "a motion block holds the samples of one request (transforms, "
                            "or one primitive)");
    r->motion_kind = transform ? 1 : 2;
    if (transform) {
        snprintf(r->motion_req[k], sizeof r->motion_req[k], "%.19s", q);
        size_t i = 0; /* a Rotate's parameters, which motion_turns moves (the
                         request checks them itself) */
        if (strcmp(q, "Rotate") == 0 &&
            (a->n < 1 || rib_get_floats(r, a, &i, r->motion_rotate[k], 4, "angle dx dy dz") != 0))
            r->motion_req[k][0] = '\0';
        pre_at(r, r->motion_time[k], r->a.M);
        r->a.n_motion = 0;
        int rc = run(r, a);
        memcpy(r->motion_M[k], r->a.M, sizeof r->a.M);
        return rc < 0 ? -1 : 1;
    }
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (!s->motion_begin || r->motion_n < 2 || r->a.area) {
        if (k == 0)
            return 0;
        if (r->a.area)
            rib_warn_once(r, "MotionBegin area",
                          "emitting geometry does not deform: the first "
                          "sample of its motion block is used");
        else
            rib_warn_once(r, "MotionBegin",
                          "deformation blur is not supported here: the first "
                          "sample of each motion block is used");
        return 1;
    }
    if (k > 0)
        return 0;
    /* The state first, so that the block holds the samples alone. */
    int skip = rib_emit_begin(r, NULL);
    if (skip != 0)
        return skip < 0 ? -1 : 1;
    if (s->motion_begin(s->target, r->motion_n, r->motion_time) != RAYES_OK)
        return rib_sink_failed(r, s);
    return 0;
}

static int h_nothing(Rib *r, const Args *a)
{
    (void)r, (void)a;
    return 0;
}

/* DetailRange minvisible lowertransition uppertransition maxvisible:
 * RenderMan's level of detail. rayes renders the most detailed
 * representation (the one whose range is open to infinity, RenderMan's
 * RI_INFINITY) and skips the others, instead of measuring the Detail
 * bound's raster size: the choice RenderMan makes close up, never two
 * representations overlapping. */
static int h_detail_range(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4];
    if (rib_get_floats(r, a, &i, v, 4,
                       "4 numbers (minvisible lowertransition "
                       "uppertransition maxvisible)") != 0)
        return -1;
    if (!(v[0] <= v[1] && v[1] <= v[2] && v[2] <= v[3]))
        return rib_error(r, "expected 4 numbers in order, found %g %g %g %g", v[0], v[1], v[2],
                         v[3]);
    r->a.lod_coarse = v[3] < 1e30f;
    rib_warn_once(r, "DetailRange",
                  "DetailRange: the most detailed representation (its range "
                  "open to infinity) is rendered, the others skipped");
    return 0;
}

/* TextureCoordinates s1 t1 s2 t2 s3 t3 s4 t4: st at the corners of a
 * Patch without its own (RenderMan's default 0 0 1 0 0 1 1 1 is (u, v));
 * an attribute. Patch meshes and quadrics keep (u, v). */
static int h_texture_coordinates(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[8];
    if (rib_get_floats(r, a, &i, v, 8, "8 numbers (s1 t1 s2 t2 s3 t3 s4 t4)") != 0)
        return -1;
    static const float unit[8] = {0, 0, 1, 0, 0, 1, 1, 1};
    r->a.have_texcoords = 0;
    for (int k = 0; k < 8; k++) {
        if (!isfinite(v[k]))
            return rib_error(r, "TextureCoordinates: expected finite numbers");
        r->a.texcoords[k] = v[k];
        r->a.have_texcoords |= v[k] != unit[k];
    }
    return 0;
}

static int h_skip(Rib *r, const Args *a)
{
    (void)a;
    char key[96];
    snprintf(key, sizeof key, "request %s", r->req);
    rib_warn_once(r, key, "%s is not supported; read and skipped", r->req);
    return 0;
}

/* ShadingInterpolation "smooth" is what rayes does (the grid hider
 * interpolates its vertices' colours; the ray tracing hider shades every
 * hit): nothing to say. "constant" (flat micropolygons) warns. */
static int h_shading_interpolation(Rib *r, const Args *a)
{
    if (a->n == 1 && a->v[0].s && a->v[0].n == 1 && strcmp(a->v[0].s[0], "smooth") == 0)
        return 0;
    return h_skip(r, a);
}

/* Matte 0 is every surface's default: nothing to say; Matte 1 (a holdout)
 * is drawn as an ordinary surface, with one warning. */
static int h_matte(Rib *r, const Args *a)
{
    if (a->n == 1 && rib_is_num(&a->v[0]) && a->v[0].n == 1 && a->v[0].d[0] == 0.0)
        return 0;
    rib_warn_once(r, "request Matte",
                  "Matte 1 (a holdout) is not supported; the surface is drawn as any other");
    return 0;
}

/* MakeTexture "picture" "texture" ... and MakeLatLongEnvironment (the
 * same two names first): to rayes the made texture is the picture itself
 * (OpenImageIO MIP-maps any image as it reads it, and a latitude-longitude
 * picture is what environments read), so from here on the texture's name
 * stands for the picture's; the wrap modes and filter are not kept. */
static int h_make_texture(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *in = rib_get_string(r, a, &i, "a picture name");
    const char *out = in ? rib_get_string(r, a, &i, "a texture name") : NULL;
    if (!out)
        return -1;
    char key[96];
    snprintf(key, sizeof key, "made %s", r->req);
    if (strlen(in) >= sizeof r->made->from || strlen(out) >= sizeof r->made->made ||
        !rib_texture_found(r, in)) {
        rib_warn_once(r, key,
                      "%s: the picture \"%.200s\" is not found (or its name is too long); "
                      "\"%.200s\" is not made",
                      r->req, in, out);
        return 0;
    }
    RibTextureAlias *m = realloc(r->made, (r->n_made + 1) * sizeof *m);
    if (!m)
        return rib_error(r, "out of memory");
    r->made = m;
    snprintf(m[r->n_made].made, sizeof m->made, "%s", out);
    snprintf(m[r->n_made].from, sizeof m->from, "%s", in);
    r->n_made++;
    return 0;
}

/* ArchiveBegin "name" ... ArchiveEnd: an inline archive, kept (its text)
 * for a ReadArchive of its name; nothing in it is read here. */
static int h_archive_begin(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "an archive name");
    if (!name)
        return -1;
    free(r->archive_name);
    if (!(r->archive_name = rib_strdup(name)))
        return rib_error(r, "out of memory");
    r->archive_block = 1;
    r->archive_nest = 0;
    r->archive_body = NULL;
    r->archive_line = r->req_line;
    return 0;
}

/* At the ArchiveEnd of an inline archive: its text kept. */
static int archive_end(Rib *r)
{
    r->archive_block = 0;
    const unsigned char *body = r->archive_body ? r->archive_body : r->req_at;
    int binary = 0;
    for (const unsigned char *c = body; body && r->req_at && c < r->req_at && !binary; c++)
        binary = *c >= 0200;
    if (!body || !r->req_at || r->req_at < body || binary) {
        rib_warn_once(r, "inline archive",
                      "ArchiveBegin \"%s\": an inline archive in binary "
                      "RIB is not kept; ReadArchive of its name looks for a file",
                      r->archive_name);
        return 0;
    }
    if (r->n_inline == r->cap_inline) {
        size_t c = r->cap_inline ? 2 * r->cap_inline : 8;
        struct InlineArchive *n = realloc(r->inline_archives, c * sizeof *n);
        if (!n)
            return rib_error(r, "out of memory");
        r->inline_archives = n, r->cap_inline = c;
    }
    struct InlineArchive *ia = &r->inline_archives[r->n_inline];
    size_t size = (size_t)(r->req_at - body);
    ia->name = r->archive_name;
    r->archive_name = NULL;
    ia->file = rib_strdup(r->file);
    ia->text = malloc(size ? size : 1);
    ia->size = size;
    ia->line = r->archive_body ? r->archive_line : r->req_line;
    r->n_inline++;
    if (!ia->file || !ia->text)
        return rib_error(r, "out of memory");
    memcpy(ia->text, body, size);
    return 0;
}

/* The requests of no concern's file: version, motion blocks, and those
 * read and skipped. dispatch looks in the files' tables, then here. */
static const RibRequest own_requests[] = {
    {"version", h_nothing},
    {"ErrorHandler", h_nothing},
    {"MotionBegin", h_motion_begin},
    {"ArchiveBegin", h_archive_begin},
    {"ReadArchive", h_read_archive},
    {"Procedural", h_procedural},
    /* tier 1 and 2: read and skipped with one warning per request name */
    {"Procedural2", h_procedural2},
    {"GeometricRepresentation", h_geometric_representation},
    {"DisplayChannel", h_skip},
    {"DisplayFilter", h_skip},
    {"SampleFilter", h_skip},
    {"MakeShadow", h_skip},
    {"MakeTexture", h_make_texture},
    {"MakeBump", h_skip},
    {"MakeCubeFaceEnvironment", h_skip},
    {"MakeLatLongEnvironment", h_make_texture},
    {"MakeBrickMap", h_skip},
    {"Interior", h_skip},
    {"Exterior", h_skip},
    {"Deformation", h_skip},
    {"Detail", h_nothing},
    {"DetailRange", h_detail_range},
    {"RelativeDetail", h_skip},
    {"GeometricApproximation", h_skip},
    {"ShadingInterpolation", h_shading_interpolation},
    {"ShaderLayer", h_skip},
    {"ConnectShaderLayers", h_skip},
    {"Shader", h_skip},
    {"Matte", h_matte},
    {"TextureCoordinates", h_texture_coordinates},
    {"Bound", h_skip},
    {"ColorSamples", h_skip},
    {"ClippingPlane", h_skip},
    {"Resource", h_skip},
    {"ResourceBegin", h_skip},
    {"ResourceEnd", h_skip},
    {"System", h_skip},
    {"PixelSampleImager", h_skip},
    {"ArchiveRecord", h_nothing},
    {"EditBegin", h_skip},
    {"EditEnd", h_skip},
    {"CameraBegin", h_skip},
    {"CameraEnd", h_skip},
    {"MakeOcclusion", h_skip},
    {"VolumePixelSamples", h_skip},
    {"VPInterior", h_skip},
    {"VPSurface", h_skip},
    {"VPAtmosphere", h_skip},
    {"EditWorldBegin", h_skip},
    {"EditWorldEnd", h_skip},
    {"EditAttributeBegin", h_skip},
    {"EditAttributeEnd", h_skip},
    {NULL, NULL},
};

static const RibRequest *const tables[] = {
    rib_frame_requests,  rib_state_requests, rib_params_requests,
    rib_shade_requests,  rib_ris_requests,   rib_prim_requests,
    rib_curves_requests, rib_nurbs_requests, own_requests};

/* IfBegin "expr", ElseIf "expr", Else, IfEnd: which branch is read
 * (rib_cond.c evaluates; nothing is defined, so defined() is false). */
static int conditional(Rib *r, const Args *a)
{
    const char *q = r->req;
    int begin = strcmp(q, "IfBegin") == 0, elseif = strcmp(q, "ElseIf") == 0;
    unsigned char *top = r->n_cond ? &r->cond[r->n_cond - 1] : NULL;
    if (!begin && !top)
        return rib_error(r, "%s without IfBegin", q);
    int value = 1;
    if (begin || elseif) {
        size_t i = 0;
        const char *expr = rib_get_string(r, a, &i, "a condition");
        if (!expr)
            return -1;
        int evaluate = begin ? !top || *top == 0 : *top == 1;
        if (evaluate && rib_condition(expr, &value) != 0)
            rib_warn_once(r, "condition",
                          "%s \"%.100s\": an expression rayes cannot evaluate; "
                          "its branch is read",
                          q, expr);
    }
    if (begin) {
        if (r->n_cond == (int)sizeof r->cond)
            return rib_error(r, "IfBegin nested more than %zu deep", sizeof r->cond);
        r->cond[r->n_cond++] = top && *top != 0 ? 3 : value ? 0 : 1;
    } else if (strcmp(q, "IfEnd") == 0) {
        r->n_cond--;
    } else if (*top == 0) {
        *top = 2; /* a branch was read: the rest are not */
    } else if (*top == 1 && (!elseif || value)) {
        *top = 0;
    }
    return 0;
}

static int dispatch(Rib *r, const Args *a)
{
    const char *q = r->req;
    if (r->done)
        return 0;
    if (r->archive_block) {
        if (!r->archive_body && strcmp(q, "ArchiveEnd") != 0 && r->req_at) {
            /* from its line's start (columns hold) when only blanks come before it */
            const unsigned char *at = r->req_at, *start = at - (r->req_col - 1);
            while (at > start && (at[-1] == ' ' || at[-1] == '\t'))
                at--;
            r->archive_body = r->req_line != r->archive_line && at == start ? start : r->req_at;
            r->archive_line = r->req_line;
        }
        if (strcmp(q, "ArchiveBegin") == 0)
            r->archive_nest++; /* kept in the text, read with it */
        else if (strcmp(q, "ArchiveEnd") == 0 && r->archive_nest > 0)
            r->archive_nest--;
        else if (strcmp(q, "ArchiveEnd") == 0)
            return archive_end(r);
        return 0;
    }
    if (strcmp(q, "IfBegin") == 0 || strcmp(q, "ElseIf") == 0 || strcmp(q, "Else") == 0 ||
        strcmp(q, "IfEnd") == 0)
        return conditional(r, a); /* in skipped frames too: both passes keep one stack */
    if (r->n_cond && r->cond[r->n_cond - 1] != 0)
        return 0; /* a branch not taken */
    if (r->skipping && strcmp(q, "FrameEnd") != 0)
        return 0;
    if (r->motion && strcmp(q, "MotionEnd") == 0)
        return motion_end(r);
    if (!r->motion && strcmp(q, "MotionEnd") == 0)
        return rib_error(r, "MotionEnd without MotionBegin");
    for (size_t t = 0; t < sizeof tables / sizeof tables[0]; t++)
        for (const RibRequest *k = tables[t]; k->name; k++)
            if (strcmp(k->name, q) == 0) {
                if ((tables[t] == rib_prim_requests || tables[t] == rib_curves_requests ||
                     tables[t] == rib_nurbs_requests) &&
                    r->a.lod_coarse)
                    return 0;
                r->pv_block_color = 0;
                if (r->motion) {
                    int done = motion_request(r, q, a, k->fn);
                    if (done != 0)
                        return done < 0 ? -1 : 0;
                }
                return k->fn(r, a);
            }
    return rib_error(r, "unknown request (expected a RIB request such as WorldBegin or Polygon)");
}

static int run(Rib *r, const char *name, const unsigned char *data, size_t size)
{
    RibLexer lx;
    rib_lex_init(&lx, name, data, size, r->err, r->err_size);
    lx.line = r->first_line; /* an inline archive's text: its lines in its file */
    r->first_line = 1;
    r->lx = &lx;
    r->file = name;
    Args args = {0};
    RibToken t;
    int e = rib_lex_next(&lx, &t);
    while (e == 0 && t.type != RIB_TOK_EOF) {
        if (t.type != RIB_TOK_REQUEST) {
            e = rib_lex_error_at(&lx, t.line, t.col, "expected a request name, found %s",
                                 t.type == RIB_TOK_STRING ? "a string" :
                                 t.type == RIB_TOK_LBRACKET ? "'['" : "a number");
            break;
        }
        snprintf(r->req, sizeof r->req, "%s", t.str);
        r->req_line = t.line;
        r->req_col = t.col;
        /* where it starts, if written out (ASCII: a name is on one line,
         * the lexer's) */
        const unsigned char *at = lx.line_start + t.col - 1;
        r->req_at = t.line == lx.line && at < lx.end && *at == (unsigned char)t.str[0] ? at : NULL;
        args_clear(&args);
        e = read_args(r, &args, &t);
        if (e == 0)
            e = dispatch(r, &args);
    }
    if (e == 0 && r->archive_block) /* its text would end in another */
        e = rib_error(r, "ArchiveBegin \"%s\": the text ends before its ArchiveEnd",
                      r->archive_name ? r->archive_name : "");
    r->archive_block = 0;
    r->archive_body = NULL;
    args_clear(&args);
    free(args.v);
    rib_lex_fini(&lx);
    r->lx = NULL;
    return e;
}

/* --------------------------------------------------------------- entry */

static RayesError null_camera(void *t, const float *e, const float *a, const float *u, float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    return RAYES_OK;
}
static RayesError null_camera_matrix(void *t, const float m[16], RayesProjection p, float f,
                                     const float s[4])
{
    (void)t, (void)m, (void)p, (void)f, (void)s;
    return RAYES_OK;
}
static RayesError null_matrix(void *t, const float m[16]) { (void)t, (void)m; return RAYES_OK; }
static RayesError null_named(void *t, const char *n, const RayesParam *p, size_t k)
{
    (void)t, (void)n, (void)p, (void)k;
    return RAYES_OK;
}
static RayesError null_float(void *t, float f) { (void)t, (void)f; return RAYES_OK; }
static RayesError null_path(void *t, const char *k, const char *p)
{
    (void)t, (void)k, (void)p;
    return RAYES_OK;
}
static RayesError null_p4(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_p16(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_mesh(void *t, size_t nf, const int *nv, const int *ix, size_t np,
                            const float *P, const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)nf, (void)nv, (void)ix, (void)np, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_quadric(void *t, RayesQuadric q, const float *p, size_t n, unsigned f)
{
    (void)t, (void)q, (void)p, (void)n, (void)f;
    return RAYES_OK;
}
static RayesError null_area(void *t, const float P[4][3], const float L[3])
{
    (void)t, (void)P, (void)L;
    return RAYES_OK;
}
static RayesError null_links(void *t, RayesLightLinks m, const size_t *l, size_t n)
{
    (void)t, (void)m, (void)l, (void)n;
    return RAYES_OK;
}
static RayesError null_subdiv(void *t, RayesSubdivScheme s, size_t nf, const int *nv, const int *ix,
                              size_t np, const float *P, const RayesSubdivTags *g,
                              const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)s, (void)nf, (void)nv, (void)ix, (void)np, (void)P, (void)g, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_curves(void *t, const RayesCurves *c, const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)c, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_points(void *t, RayesPointShape s, size_t np, const float *P,
                              const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)s, (void)np, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_pattern(void *t, const char *name, const char *type, const RayesParam *p,
                               size_t n)
{
    (void)t, (void)name, (void)type, (void)p, (void)n;
    return RAYES_OK;
}
static size_t null_count(void *t) { (void)t; return 0; }
static const char *null_error(void *t) { (void)t; return ""; }

static const IoSink null_sink = {
    NULL,       null_camera,  null_camera_matrix, null_matrix, null_named, null_named,
    null_float, null_path,    null_float,         null_p4,     null_p16,   null_mesh,
    null_float, null_quadric, null_area,          null_named,  null_links, null_count,
    null_error, NULL,         null_subdiv,        null_curves, null_points, null_pattern};

static void rib_init(Rib *r, int pass, const IoSink *sink, const IoReadOptions *opt,
                     IoSettings *settings, char *err, size_t err_size)
{
    memset(r, 0, sizeof *r);
    r->pass = pass;
    r->sink = sink;
    r->opt = opt;
    r->settings = settings;
    r->err = err;
    r->err_size = err_size;
    rib_mat_identity(r->a.M);
    rib_mat_identity(r->camera_from_world);
    static const float white[3] = {1, 1, 1};
    memcpy(r->a.Cs, white, sizeof white);
    memcpy(r->a.Os, white, sizeof white);
    r->a.shading_rate = 1;
    r->a.visibility = RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR | RAYES_RAY_SHADOW;
    r->a.opacity_cache = 1;
    int step;
    rib_basis_named("bezier", r->a.ubasis, &step);
    rib_basis_named("bezier", r->a.vbasis, &step);
    r->a.ustep = r->a.vstep = step;
    r->projection = RAYES_PROJECTION_ORTHOGRAPHIC; /* RenderMan's default */
    r->fov = 90;
    r->first_line = 1;
    r->selected = -1;
    r->top_name = "";
}

static void rib_fini(Rib *r)
{
    free(r->stack);
    while (r->shaders) {
        ShaderRec *s = r->shaders;
        r->shaders = s->next;
        for (size_t i = 0; i < s->n; i++) {
            free((char *)s->params[i].name);
            free((char *)s->params[i].string);
            free((float *)s->params[i].floats);
        }
        free(s->params);
        free(s);
    }
    rib_trims_free(r);
    free(r->decls);
    free(r->lights);
    free(r->made);
    for (size_t k = 0; k < r->n_found; k++)
        free(r->found[k]);
    free(r->found);
    free(r->area_handles);
    free(r->links);
    for (size_t k = 0; k < r->n_objects; k++)
        rib_recording_free(r->objects[k].rec);
    free(r->objects);
    rib_recording_free(r->rec);
    free(r->coordsys_names);
    free(r->coordsys_M);
    free(r->coordsys_world);
    free(r->frames);
    for (size_t k = 0; k < r->n_inline; k++) {
        free(r->inline_archives[k].name);
        free(r->inline_archives[k].file);
        free(r->inline_archives[k].text);
    }
    free(r->inline_archives);
    free(r->stand_ins);
    free(r->manifolds);
    free(r->bumps);
    free(r->archive_name);
    for (size_t k = 0; k < r->n_warned; k++)
        free(r->warned[k]);
}

RayesError io_rib_parse(const char *name, const unsigned char *data, size_t size,
                        const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                        char *err, size_t err_size)
{
    if (err_size)
        err[0] = '\0';
    unsigned char *inflated = NULL;
    if (size >= 2 && data[0] == 0x1f && data[1] == 0x8b) {
        size_t n;
        inflated = inflate_buffer(data, size, &n);
        if (!inflated) {
            snprintf(err, err_size, "%s: not a valid gzip stream", name);
            return RAYES_ERROR_PARSE;
        }
        data = inflated;
        size = n;
    }
    static const unsigned char empty[1] = {0};
    if (!data)
        data = empty, size = 0;
    /* pass 1: check everything, list the frames */
    IoSettings scratch;
    io_settings_init(&scratch);
    Rib r;
    rib_init(&r, 1, &null_sink, options, &scratch, err, err_size);
    r.top_name = name;
    int e = run(&r, name, data, size);
    if (e == 0 && r.rec)
        e = rib_error(&r, "the file ends inside an object definition (ObjectBegin)");
    long selected = -1;
    int frame = options ? options->frame : -1;
    if (e == 0 && r.n_frames > 0) {
        for (size_t k = 0; k < r.n_frames; k++)
            if (frame >= 0 ? r.frames[k].number == frame && selected < 0 : r.frames[k].renders)
                selected = (long)k;
        if (selected < 0 && frame < 0)
            selected = (long)r.n_frames - 1;
        if (selected < 0) {
            snprintf(err, err_size, "%s: the file has no frame %d (FrameBegin %d)", name, frame,
                     frame);
            e = -1;
        }
    } else if (e == 0 && frame >= 0) {
        snprintf(err, err_size, "%s: the file has no frames (FrameBegin), so no frame %d", name,
                 frame);
        e = -1;
    }
    int lit = r.lit, ris = r.ris, integrator = r.integrator;
    rib_fini(&r);
    if (e == 0) { /* pass 2: the selected frame into the sink */
        rib_init(&r, 2, sink, options, settings, err, err_size);
        r.top_name = name;
        r.selected = selected;
        r.unlit_file = !lit;
        e = run(&r, name, data, size);
        if (e == 0 && r.n_lights > 0)
            e = rib_flush_lights(&r); /* a file without WorldEnd */
        /* RenderMan 19 and later with no Integrator: PRMan's PxrDefault,
         * a light at the camera, which a file without lights shows */
        if (e == 0 && ris && !integrator && !lit)
            settings->headlight = 1;
        /* 8-bit files as RenderMan writes them (its Exposure the only
         * curve), unless the file says otherwise or is RenderMan 19's or
         * later (physically based, seen through sRGB) */
        if (settings->png_curve == IO_CURVE_UNSAID)
            settings->png_curve = ris ? IO_CURVE_SRGB : IO_CURVE_LINEAR;
        rib_fini(&r);
    }
    free(inflated);
    for (char *c = err; e != 0 && *c; c++) /* names from the file may hold newlines */
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    return e == 0 ? RAYES_OK : RAYES_ERROR_PARSE;
}

RayesError io_rib_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                       IoSettings *settings, char *err, size_t err_size)
{
    size_t size;
    unsigned char *data = read_gz(path, &size, err, err_size);
    if (!data)
        return RAYES_ERROR_IO;
    RayesError e = io_rib_parse(path, data, size, sink, options, settings, err, err_size);
    free(data);
    return e;
}

