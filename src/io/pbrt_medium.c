/*
 * io/pbrt_medium.c — pbrt-v4's participating media (pbrt_internal.h):
 * MakeNamedMedium of type "homogeneous", "uniformgrid" and "nanovdb",
 * MediumInterface, and the rayes volumes (rayes_scene_volume_inside with
 * the built-in "homogeneous" shader) that the shapes naming a medium
 * bound. docs/pbrt.md lists the mapping:
 *
 *   extinction = (sigma_a + sigma_s) scale, albedo = sigma_s / (sigma_a +
 *   sigma_s), g = g, emission = sigma_a scale Le Lescale (pbrt's source
 *   term sigma_a Le), density = 1, or the grid: a "densitygrid" pattern
 *   (uniformgrid, its p0 p1 in the medium's space) or a "nanovdb" pattern
 *   (the file's "density" grid, its world space the medium's space).
 *
 * A shape with a different medium on each side (MediumInterface) bounds
 * both: it is recorded (pbrt_shape.c, bound_media) into each medium's
 * bound, turned so that the medium lies behind its normals, and at the
 * end of the file each bound is sent as one object seen by no ray, then
 * the medium's volume inside it (rayes_scene_volume_inside): a liquid
 * closed by its flat top (medium inside) and the glass's wall (medium
 * outside) fills what they close. The march's box is the scene's bounds
 * for a homogeneous medium (where the shapes leave it open, a ray stays in
 * it, as pbrt's ray stays in its medium to the next interface), the
 * shapes' for a nanovdb one and p0..p1 in the medium's space for a
 * uniformgrid, where its density is. The camera's medium (the outside
 * medium current at Camera) fills a box around every shape outside
 * ObjectBegin and the camera, made at the end of the file; a shape whose
 * outside medium is the camera's is in it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

static Medium *find_medium(Parser *P, const char *name)
{
    for (size_t i = P->n_media; i-- > 0;)
        if (strcmp(P->media[i].name, name) == 0)
            return &P->media[i];
    return NULL;
}

/* sigma_a, sigma_s, scale, g, Le and Lescale into md; pbrt's defaults
 * for the type (homogeneous: its "default" scattering, grids: 1 and 1). */
static int medium_coefficients(Parser *P, ParamList *pl, Medium *md)
{
    int homogeneous = strcmp(md->type, "homogeneous") == 0;
    static const float one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    static const float sa_default[3] = {.0011f, .0024f, .014f},
                       ss_default[3] = {2.55f, 3.21f, 3.77f};
    float sa[3], ss[3], Le[3];
    if (pbrt_get_color(P, pl, "sigma_a", homogeneous ? sa_default : one, sa, NULL) < 0 ||
        pbrt_get_color(P, pl, "sigma_s", homogeneous ? ss_default : one, ss, NULL) < 0 ||
        pbrt_get_color(P, pl, "Le", zero, Le, NULL) < 0)
        return -1;
    float scale = (float)pbrt_get_float(pl, "scale", 1.0);
    /* older pbrt-v4 spelled it LeScale, and the temperature offset
     * temperaturecutoff (read when temperatureoffset is not given) */
    float Lescale = (float)pbrt_get_float(pl, "Lescale", pbrt_get_float(pl, "LeScale", 1.0));
    md->Lescale = Lescale;
    md->temp_offset = (float)pbrt_get_float(pl, "temperatureoffset",
                                            pbrt_get_float(pl, "temperaturecutoff", 0.0));
    md->temp_scale = (float)pbrt_get_float(pl, "temperaturescale", 1.0);
    md->g = (float)pbrt_get_float(pl, "g", 0.0);
    for (int c = 0; c < 3; c++) {
        float st = sa[c] + ss[c];
        md->extinction[c] = st * scale;
        md->albedo[c] = st > 0.0f ? ss[c] / st : 0.0f;
        md->emission[c] = sa[c] * scale * Le[c] * Lescale;
    }
    return 0;
}

/* A box's p0 and p1 (default 0 0 0 and 1 1 1) for the type. */
static int medium_box(Parser *P, const Token *t, ParamList *pl, Medium *md)
{
    const double *p0 = pbrt_get_point(pl, "p0"), *p1 = pbrt_get_point(pl, "p1");
    for (int k = 0; k < 3; k++) {
        md->p0[k] = p0 ? (float)p0[k] : 0.0f;
        md->p1[k] = p1 ? (float)p1[k] : 1.0f;
        if (!(md->p1[k] > md->p0[k]))
            return FAIL_TOK(P, t, "%s: expected p0 below p1 on every axis", md->type);
    }
    return 0;
}

/* cloud's density, wispiness and frequency, and its box. */
static int medium_cloud(Parser *P, const Token *t, ParamList *pl, Medium *md)
{
    md->cloud[0] = (float)pbrt_get_float(pl, "density", 1.0);
    md->cloud[1] = (float)pbrt_get_float(pl, "wispiness", 1.0);
    md->cloud[2] = (float)pbrt_get_float(pl, "frequency", 5.0);
    for (int k = 0; k < 3; k++)
        if (!isfinite(md->cloud[k]) || fabsf(md->cloud[k]) > 1e6f)
            return FAIL_TOK(P, t, "cloud: expected density, wispiness and frequency within 1e6");
    return medium_box(P, t, pl, md);
}

/* uniformgrid's nx ny nz, density, p0 and p1. */
static int medium_grid(Parser *P, const Token *t, ParamList *pl, Medium *md)
{
    static const char *const counts[3] = {"nx", "ny", "nz"};
    size_t n = 1;
    for (int k = 0; k < 3; k++) {
        double v = pbrt_get_float(pl, counts[k], 1.0);
        if (!(v >= 1 && v <= 1 << 20))
            return FAIL_TOK(P, t, "uniformgrid: expected %s from 1 to 2^20, found %g", counts[k],
                            v);
        md->res[k] = (size_t)v;
        n *= md->res[k];
    }
    Param *d = pbrt_find(pl, "density");
    if (!d || d->n_num != n)
        return FAIL_TOK(P, t, "uniformgrid: expected nx ny nz = %zu \"density\" values, found %zu",
                        n, d ? d->n_num : 0);
    md->density = malloc(n * sizeof *md->density);
    if (!md->density)
        return FAIL_TOK(P, t, "out of memory");
    for (size_t i = 0; i < n; i++)
        md->density[i] = (float)d->num[i];
    return medium_box(P, t, pl, md);
}

int pbrt_d_makenamedmedium(Parser *P, const Token *t)
{
    char name[128];
    ParamList pl = {0};
    if (pbrt_name_and_params(P, name, sizeof name, "a medium name", &pl, NULL) != 0) {
        pbrt_params_free(&pl);
        return -1;
    }
    Medium md = {0};
    snprintf(md.name, sizeof md.name, "%s", name);
    memcpy(md.m, P->gs.ctm, sizeof md.m);
    const char *type = pbrt_get_string(&pl, "type", "");
    if (strcmp(type, "heterogeneous") == 0) /* pbrt-v3's name for the same grid */
        type = "uniformgrid";
    int r = 0;
    if (strcmp(type, "homogeneous") != 0 && strcmp(type, "uniformgrid") != 0 &&
        strcmp(type, "cloud") != 0 && strcmp(type, "nanovdb") != 0) {
        char key[96];
        snprintf(key, sizeof key, "medium %.60s", type);
        pbrt_warn_at(P, t->line, t->col, key,
                     "MakeNamedMedium: medium type \"%.40s\" is not supported; shapes filled "
                     "with \"%.60s\" are empty",
                     type, name);
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
        snprintf(md.type, sizeof md.type, "none");
    } else {
        snprintf(md.type, sizeof md.type, "%s", type);
        r = medium_coefficients(P, &pl, &md);
        if (!r && strcmp(type, "uniformgrid") == 0)
            r = medium_grid(P, t, &pl, &md);
        if (!r && strcmp(type, "cloud") == 0)
            r = medium_cloud(P, t, &pl, &md);
        if (!r && strcmp(type, "nanovdb") == 0) {
            const char *file = pbrt_get_string(&pl, "filename", "");
            if (!file[0])
                r = FAIL_TOK(P, t, "nanovdb: expected a \"filename\"");
            else
                r = pbrt_resolve(P, t, file, md.filename, sizeof md.filename);
            /* the grids' names (pbrt-v4's gridname and temperaturename) */
            snprintf(md.grids[0], sizeof md.grids[0], "%s",
                     pbrt_get_string(&pl, "gridname", "density"));
            snprintf(md.grids[1], sizeof md.grids[1], "%s",
                     pbrt_get_string(&pl, "temperaturename", "temperature"));
        }
    }
    if (!r)
        pbrt_warn_unused(P, &pl, "MakeNamedMedium", type);
    pbrt_params_free(&pl);
    if (r) {
        free(md.density);
        return -1;
    }
    Medium *grown = realloc(P->media, (P->n_media + 1) * sizeof *grown);
    if (!grown) {
        free(md.density);
        return FAIL_TOK(P, t, "out of memory");
    }
    P->media = grown;
    P->media[P->n_media++] = md;
    return 0;
}

int pbrt_d_mediuminterface(Parser *P, const Token *t)
{
    (void)t; /* before WorldBegin too: the medium current at Camera is the camera's */
    char in[128], out[128];
    Token next;
    if (pbrt_expect_string(P, in, sizeof in, "a medium name (inside)", NULL) != 0 ||
        pbrt_peek(P, &next) != 0)
        return -1;
    if (next.kind == TOK_STRING) {
        if (pbrt_expect_string(P, out, sizeof out, "a medium name (outside)", NULL) != 0)
            return -1;
    } else {
        memcpy(out, in, sizeof out); /* one name: both sides */
    }
    snprintf(P->gs.inside, sizeof P->gs.inside, "%s", in);
    snprintf(P->gs.outside, sizeof P->gs.outside, "%s", out);
    return 0;
}

/* The homogeneous shader's parameters for md into q; returns the count. */
static size_t medium_params(const Medium *md, RayesParam q[9])
{
    size_t n = 0;
    q[n++] = (RayesParam){.name = "extinction", .type = RAYES_PARAM_COLOR};
    memcpy(q[0].value, md->extinction, sizeof q[0].value);
    q[n++] = (RayesParam){.name = "albedo", .type = RAYES_PARAM_COLOR};
    memcpy(q[1].value, md->albedo, sizeof q[1].value);
    q[n++] = (RayesParam){.name = "g", .type = RAYES_PARAM_FLOAT, .value = {md->g, 0, 0}};
    q[n++] = (RayesParam){.name = "emission", .type = RAYES_PARAM_COLOR};
    memcpy(q[3].value, md->emission, sizeof q[3].value);
    if (md->pattern[0])
        q[n++] =
            (RayesParam){.name = "density", .type = RAYES_PARAM_PATTERN, .string = md->pattern};
    if (md->temperature[0]) { /* pbrt's emission sigma_a Lescale B(T) */
        q[n++] = (RayesParam){
            .name = "temperature", .type = RAYES_PARAM_PATTERN, .string = md->temperature};
        q[n++] = (RayesParam){
            .name = "temperatureoffset", .type = RAYES_PARAM_FLOAT, .value = {md->temp_offset}};
        q[n++] = (RayesParam){
            .name = "temperaturescale", .type = RAYES_PARAM_FLOAT, .value = {md->temp_scale}};
        q[n++] = (RayesParam){
            .name = "blackbodyscale", .type = RAYES_PARAM_FLOAT, .value = {md->Lescale}};
    }
    return n;
}

/* Sends a grid medium's density pattern, once, in the medium's space. */
static int send_density(Parser *P, const Token *t, Medium *md)
{
    if (md->sent || strcmp(md->type, "homogeneous") == 0)
        return 0;
    snprintf(md->pattern, sizeof md->pattern, "medium %zu:%.120s", (size_t)(md - P->media),
             md->name);
    md->sent = 1;
    if (strcmp(md->type, "uniformgrid") == 0) {
        RayesParam q[6] = {
            {.name = "nx", .type = RAYES_PARAM_FLOAT, .value = {(float)md->res[0]}},
            {.name = "ny", .type = RAYES_PARAM_FLOAT, .value = {(float)md->res[1]}},
            {.name = "nz", .type = RAYES_PARAM_FLOAT, .value = {(float)md->res[2]}},
            {.name = "p0", .type = RAYES_PARAM_COLOR, .value = {md->p0[0], md->p0[1], md->p0[2]}},
            {.name = "p1", .type = RAYES_PARAM_COLOR, .value = {md->p1[0], md->p1[1], md->p1[2]}},
            {.name = "density",
             .type = RAYES_PARAM_FLOATS,
             .floats = md->density,
             .n_floats = md->res[0] * md->res[1] * md->res[2]}};
        return pbrt_emit_pattern_in(P, t, md->m, md->pattern, "densitygrid", q, 6);
    }
    if (strcmp(md->type, "cloud") == 0) {
        RayesParam q[3] = {
            {.name = "density", .type = RAYES_PARAM_FLOAT, .value = {md->cloud[0]}},
            {.name = "wispiness", .type = RAYES_PARAM_FLOAT, .value = {md->cloud[1]}},
            {.name = "frequency", .type = RAYES_PARAM_FLOAT, .value = {md->cloud[2]}}};
        return pbrt_emit_pattern_in(P, t, md->m, md->pattern, "cloud", q, 3);
    }
    RayesParam q[3] = {{.name = "filename", .type = RAYES_PARAM_STRING, .string = md->filename},
                       {.name = "grid", .type = RAYES_PARAM_STRING, .string = md->grids[0]},
                       {.name = "optional", .type = RAYES_PARAM_FLOAT, .value = {1}}};
    if (pbrt_emit_pattern_in(P, t, md->m, md->pattern, "nanovdb", q, 2) != 0)
        return -1;
    q[1].string = md->grids[1];
    if (md->Lescale == 0.0f) /* no emission asked for: the grid is not read */
        return 0;
    /* its temperature grid, if the file has one (pbrt reads it if there) */
    snprintf(md->temperature, sizeof md->temperature, "%s temperature", md->pattern);
    return pbrt_emit_pattern_in(P, t, md->m, md->temperature, "nanovdb", q, 3);
}

/* A medium whose density lies in its box p0..p1 (medium space) alone:
 * the box into grid, as the volume's bound takes it; 0 for the others. */
static int own_box(const Medium *md, float grid[6])
{
    if (strcmp(md->type, "uniformgrid") != 0 && strcmp(md->type, "cloud") != 0)
        return 0;
    for (int k = 0; k < 3; k++)
        grid[2 * k] = md->p0[k], grid[2 * k + 1] = md->p1[k];
    return 1;
}

/* Grows box (world space; *have: it holds a point) by the Shape just read
 * (its bounds' corners under the CTM). */
static void grow_box(const Parser *P, float *box, int *have)
{
    const double *m = P->gs.ctm;
    const float *b = P->shape_bound;
    for (int c = 0; c < 8; c++) {
        double p[3] = {b[c & 1], b[2 + (c >> 1 & 1)], b[4 + (c >> 2)]};
        for (int k = 0; k < 3; k++) {
            float v = (float)(m[4 * k] * p[0] + m[4 * k + 1] * p[1] + m[4 * k + 2] * p[2] +
                              m[4 * k + 3]);
            if (!*have || v < box[2 * k])
                box[2 * k] = v;
            if (!*have || v > box[2 * k + 1])
                box[2 * k + 1] = v;
        }
        *have = 1;
    }
}

/* Why the current Shape's media cannot be rendered here, or NULL. */
static const char *bound_skip(const Parser *P)
{
    return P->recording                                          ? "inside ObjectBegin"
           : !P->sink->volume || !P->sink->pattern               ? "this output takes no volumes"
           : !P->sink->volume_inside || !P->sink->set_visibility ? "this output takes no bounded "
                                                                   "volumes"
                                                                 : NULL;
}

/* The name of the medium on one side of the current Shape that it may
 * bound (0 its inside, 1 its outside), or NULL: none, or the same on both
 * sides. */
static const char *side_name(const Parser *P, int side)
{
    const char *name = side ? P->gs.outside : P->gs.inside;
    return name[0] && strcmp(P->gs.inside, P->gs.outside) != 0 ? name : NULL;
}

int pbrt_medium_shape(Parser *P, const Token *t)
{
    if (P->have_shape_bound && !P->recording) /* shapes inside ObjectBegin: placed by instances */
        grow_box(P, P->world_bound, &P->have_world_bound);
    for (int side = 0; side < 2; side++) {
        const char *name = side_name(P, side);
        if (!name)
            continue;
        const Medium *md = find_medium(P, name);
        if (!md)
            return FAIL_TOK(P, t,
                            "MediumInterface names the medium \"%.60s\", which no "
                            "MakeNamedMedium defined",
                            name);
        const char *skip = bound_skip(P);
        if (skip && strcmp(md->type, "none") != 0 && strcmp(name, P->camera_medium) != 0)
            pbrt_warn_at(P, t->line, t->col, skip, "medium \"%.60s\": %s; not rendered", name,
                         skip);
    }
    return 0;
}

Medium *pbrt_medium_bounded(Parser *P, int side)
{
    const char *name = side_name(P, side);
    if (!name || strcmp(name, P->camera_medium) == 0 || bound_skip(P))
        return NULL;
    Medium *md = find_medium(P, name);
    return md && strcmp(md->type, "none") != 0 ? md : NULL;
}

void pbrt_medium_grow(Parser *P, Medium *md, const Token *t)
{
    if (!md->file)
        md->file = P->lx->name, md->line = t->line, md->col = t->col;
    if (P->have_shape_bound)
        grow_box(P, md->box, &md->have_box);
}

/* box widened by a thousandth of its diagonal (at least 1e-3) on each
 * axis: surfaces on its sides are in it, and a flat one (a medium named
 * by one disk) is a box; 0 if it is not finite. */
static int padded(const float in[6], float box[6])
{
    float diag = 0.0f;
    for (int k = 0; k < 3; k++)
        diag += (in[2 * k + 1] - in[2 * k]) * (in[2 * k + 1] - in[2 * k]);
    float pad = fmaxf(1e-3f * sqrtf(diag), 1e-3f);
    for (int k = 0; k < 3; k++) {
        float a = in[2 * k], b = in[2 * k + 1]; /* in may be box */
        box[2 * k] = a - pad, box[2 * k + 1] = b + pad;
    }
    for (int k = 0; k < 6; k++)
        if (!isfinite(box[k]))
            return 0;
    return 1;
}

/* One medium's bound and its volume. */
static int send_bounded(Parser *P, Medium *md, const Token *t)
{
    double identity[16];
    pbrt_mat_identity(identity);
    float box[6];
    int whole = strcmp(md->type, "homogeneous") == 0 && P->have_world_bound;
    if (!padded(whole ? P->world_bound : md->box, box)) {
        pbrt_warn_at(P, t->line, t->col, "medium bounds",
                     "medium \"%.60s\": its shapes' bounds are not finite; not rendered", md->name);
        return 0;
    }
    if (pbrt_emit_bound(P, t, &md->bound) != 0 || send_density(P, t, md) != 0)
        return -1;
    RayesParam q[9];
    size_t n = medium_params(md, q);
    /* The march's box: a uniformgrid's density is in its box, a nanovdb's
     * in its shapes'; a homogeneous medium fills the scene's bounds. The
     * volume is only inside its shapes either way, but a ray that crosses
     * them into the medium where they leave it open stays in it to its next
     * surface, as in pbrt (a fog behind a room's front wall). */
    int r;
    float grid[6];
    if (own_box(md, grid)) {
        r = pbrt_emit_volume(P, t, md->m, q, n, grid, 1);
    } else {
        r = pbrt_emit_volume(P, t, identity, q, n, box, 1);
    }
    if (r != 0 || pbrt_shown_again(P, t) != 0)
        return -1;
    P->shape_hidden = 0;
    return 0;
}

int pbrt_media_send(Parser *P)
{
    Lexer *top = P->lx;
    for (size_t i = 0; i < P->n_media; i++) {
        Medium *md = &P->media[i];
        if (!md->bound.n_ops)
            continue;
        /* messages name the file of the medium's first shape */
        Lexer at = *top;
        at.name = md->file ? md->file : top->name;
        P->lx = &at;
        Token t = {.line = md->line, .col = md->col};
        int r = send_bounded(P, md, &t);
        P->lx = top;
        if (r != 0)
            return -1;
    }
    return 0;
}

void pbrt_media_free(Parser *P)
{
    for (size_t i = 0; i < P->n_media; i++) {
        free(P->media[i].density);
        pbrt_object_free(&P->media[i].bound);
    }
    free(P->media);
}

int pbrt_medium_camera(Parser *P)
{
    if (!P->camera_medium[0])
        return 0;
    Token t = {.line = P->camera_line, .col = P->camera_col};
    Medium *md = find_medium(P, P->camera_medium);
    if (!md)
        return FAIL_TOK(P, &t,
                        "the camera's medium \"%.60s\" (MediumInterface) was never defined by "
                        "MakeNamedMedium",
                        P->camera_medium);
    if (strcmp(md->type, "none") == 0)
        return 0;
    if (!P->sink->volume || !P->sink->pattern) {
        pbrt_warn_at(P, t.line, t.col, "camera medium",
                     "the camera's medium \"%.60s\": this output takes no volumes; not rendered",
                     md->name);
        return 0;
    }
    /* the scene's bounds and the eye, widened by a thousandth of the
     * diagonal (and at least 1e-3) so that surfaces on the bounds are in */
    double eye_m[16];
    if (pbrt_mat_inverse(P->camera_from_world, eye_m) != 0)
        return 0; /* reported at Camera */
    float eye[3] = {(float)eye_m[3], (float)eye_m[7], (float)eye_m[11]}, box[6];
    for (int k = 0; k < 3; k++) {
        box[2 * k] = P->have_world_bound ? fminf(P->world_bound[2 * k], eye[k]) : eye[k];
        box[2 * k + 1] = P->have_world_bound ? fmaxf(P->world_bound[2 * k + 1], eye[k]) : eye[k];
    }
    if (!padded(box, box)) {
        pbrt_warn_at(P, t.line, t.col, "camera medium bounds",
                     "the camera's medium \"%.60s\": the scene's bounds are not finite; not "
                     "rendered",
                     md->name);
        return 0;
    }
    if (send_density(P, &t, md) != 0)
        return -1;
    RayesParam q[9];
    size_t n = medium_params(md, q);
    float grid[6];
    if (own_box(md, grid)) /* pbrt clips them to it */
        return pbrt_emit_volume(P, &t, md->m, q, n, grid, 0);
    double identity[16];
    pbrt_mat_identity(identity);
    return pbrt_emit_volume(P, &t, identity, q, n, box, 0);
}
