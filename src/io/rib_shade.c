/*
 * io/rib_shade.c — shaders and lights of the RIB reader, and bringing the
 * sink up to date before each primitive (rib_emit_begin: transform,
 * visibility and opacity mode, shader and colour, displacement, shading
 * rate, light links), sending
 * only what changed since the sink last heard it (SinkState).
 *
 * Shaders: a name built in or known to the sink (a plugin on its search
 * path) is kept with the parameters the API can take; another name
 * becomes matte (with its Ka, Kd) with one warning. Lights: which are on
 * is an attribute (a bit per light in Attr, saved by AttributeBegin, not
 * by TransformBegin; LightSource turns the new light on, Illuminate on or
 * off). A light is sent at the first geometry after its LightSource, on
 * or off, or at WorldEnd if it is on then (one that no geometry followed
 * and that is off at the end lights nothing, and is not sent); each
 * geometry's objects get the light links EXCEPT the lights that are off
 * for it. A light still lights the geometry before its LightSource (as
 * every light did before light linking), and area lights light
 * everything.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/rib_reader.h"
#include "util/grow.h"
#include "util/vec.h"

/* ---------------------------------------------------------- emission */

static const float white[3] = {1, 1, 1};

static int send_shader(Rib *r, const IoSink *s, const float Cs[3])
{
    const ShaderRec *sh = r->a.surface;
    size_t n = sh ? sh->n : 0;
    RayesParam *p = malloc((n + 2) * sizeof *p);
    if (!p)
        return rib_error(r, "out of memory");
    if (n)
        memcpy(p, sh->params, n * sizeof *p);
    p[n++] = (RayesParam){"Cs", RAYES_PARAM_COLOR, {Cs[0], Cs[1], Cs[2]}, NULL};
    if (memcmp(r->a.Os, white, sizeof white) != 0)
        p[n++] = (RayesParam){"Os", RAYES_PARAM_COLOR, {r->a.Os[0], r->a.Os[1], r->a.Os[2]}, NULL};
    /* no Surface: matte, or RenderMan's defaultsurface in a file without
     * lights (which matte would draw black) */
    const char *name = sh ? sh->name : r->unlit_file ? "defaultsurface" : "matte";
    RayesError e = s->set_shader(s->target, name, p, n);
    free(p);
    return e == RAYES_OK ? 0 : rib_sink_failed(r, s);
}

static int light_on(const Attr *a, size_t k)
{
    return (a->on[k / 8] >> (k % 8)) & 1;
}

static void set_light_on(Attr *a, size_t k, int on)
{
    unsigned bit = 1u << (k % 8);
    a->on[k / 8] = (unsigned char)(on ? a->on[k / 8] | bit : a->on[k / 8] & ~bit);
}

/* Where a light keeps the string parameter of that name. */
static char *light_string(Light *L, const char *name)
{
    return strcmp(name, "mapname") == 0 || strcmp(name, "slidename") == 0 ? L->mapname
           : strcmp(name, "mapping") == 0                                 ? L->mapping
           : strcmp(name, "shape") == 0                                   ? L->shape
           : strcmp(name, "lighttype") == 0                               ? L->lighttype
                                                                          : L->category;
}

static int send_light(Rib *r, Light *L)
{
    const IoSink *s = r->sink;
    size_t index = s->light_count(s->target);
    for (size_t i = 0; i < L->n; i++) { /* the array may have moved since */
        L->params[i].name = L->names[i];
        if (L->params[i].type == RAYES_PARAM_STRING)
            L->params[i].string = light_string(L, L->names[i]);
        if (L->params[i].type == RAYES_PARAM_FLOATS) /* the blocker's matrix */
            L->params[i].floats = L->blocker;
    }
    int moving = L->n_motion > 1 && s->set_transform_motion;
    if (L->n_motion > 1 && !s->set_transform_motion)
        rib_warn_once(r, "MotionBegin", "this sink has no motion blur: the first sample of "
                                        "each motion block is used");
    if (L->own_visibility && s->set_visibility) { /* the geometry's is sent again after */
        if (s->set_visibility(s->target, L->visibility) != RAYES_OK)
            return rib_sink_failed(r, s);
        r->real.have_visibility = 0;
    }
    if ((moving ? s->set_transform_motion(s->target, (size_t)L->n_motion, L->motion_time,
                                          (const float(*)[16])L->motion_M)
                : s->set_transform(s->target, L->M)) != RAYES_OK ||
        s->light(s->target, L->type, L->params, L->n) != RAYES_OK)
        return rib_sink_failed(r, s);
    L->index = (long)index;
    r->real.have_M = 0;
    return 0;
}

/* Before geometry (not in an object definition) or an instance: sends the
 * lights never sent, on or off (so that the links of this geometry can
 * exclude them), then the light links (EXCEPT the sent
 * lights that are off) if they changed; new links need a new object, so
 * the shader is sent again. */
int rib_send_lights(Rib *r)
{
    const IoSink *s = r->sink;
    size_t n = 0;
    int changed = 0;
    for (size_t k = 0; k < r->n_lights; k++) {
        Light *L = &r->lights[k];
        if (L->index < 0 && send_light(r, L) != 0)
            return -1;
        if (light_on(&r->a, k))
            continue;
        if (n >= r->n_links || r->links[n] != (size_t)L->index) {
            size_t *nl = realloc(r->links, (n + 1) * sizeof *nl);
            if (!nl)
                return rib_error(r, "out of memory");
            r->links = nl;
            r->links[n] = (size_t)L->index;
            changed = 1;
        }
        n++;
    }
    if (!changed && n == r->n_links)
        return 0;
    r->n_links = n;
    if (s->set_light_links(s->target, n ? RAYES_LIGHT_LINKS_EXCEPT : RAYES_LIGHT_LINKS_ALL,
                           r->links, n) != RAYES_OK)
        return rib_sink_failed(r, s);
    r->real.have_shader = 0;
    return 0;
}

/* Sends the visibility and the opacity mode when they changed; both are
 * properties of the objects made next, so the shader (which makes one) is
 * sent again after them. Sinks without the methods (older ones) keep
 * every object visible. */
static int send_visibility(Rib *r, const IoSink *s, SinkState *st)
{
    const Attr *a = &r->a;
    if (s->set_visibility && (!st->have_visibility || st->visibility != a->visibility)) {
        if (s->set_visibility(s->target, a->visibility) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->visibility = a->visibility;
        st->have_visibility = 1;
        st->have_shader = 0;
    }
    if (s->set_opacity_mode && (!st->have_opacity_mode || st->hitmode != a->hitmode ||
                                st->opacity_cache != a->opacity_cache)) {
        if (s->set_opacity_mode(s->target, (RayesTransmissionHitMode)a->hitmode,
                                a->opacity_cache) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->hitmode = a->hitmode;
        st->opacity_cache = a->opacity_cache;
        st->have_opacity_mode = 1;
        st->have_shader = 0;
    }
    return 0;
}

/* The current transform, moving or not, and the dice blur, if changed. */
static int send_transform(Rib *r, const IoSink *s, SinkState *st)
{
    int moving = r->a.n_motion > 1 && s->set_transform_motion;
    if (r->a.n_motion > 1 && !s->set_transform_motion)
        rib_warn_once(r, "MotionBegin", "this sink has no motion blur: the first sample of "
                                        "each motion block is used");
    size_t bytes = (size_t)r->a.n_motion * sizeof r->a.motion_M[0];
    if (!st->have_M || memcmp(st->M, r->a.M, sizeof st->M) != 0 ||
        st->n_motion != (moving ? r->a.n_motion : 0) ||
        (moving && memcmp(st->motion_M, r->a.motion_M, bytes) != 0)) {
        RayesError e = moving ? s->set_transform_motion(s->target, (size_t)r->a.n_motion,
                                                        r->a.motion_time,
                                                        (const float(*)[16])r->a.motion_M)
                              : s->set_transform(s->target, r->a.M);
        if (e != RAYES_OK)
            return rib_sink_failed(r, s);
        memcpy(st->M, r->a.M, sizeof st->M);
        st->n_motion = moving ? r->a.n_motion : 0;
        if (moving)
            memcpy(st->motion_M, r->a.motion_M, bytes);
        st->have_M = 1;
    }
    if (s->set_dice_blur && (!st->have_blur || st->motionfactor != r->a.motionfactor ||
                             st->focusfactor != r->a.focusfactor)) {
        if (s->set_dice_blur(s->target, r->a.motionfactor, r->a.focusfactor) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->motionfactor = r->a.motionfactor;
        st->focusfactor = r->a.focusfactor;
        st->have_blur = 1;
    }
    return 0;
}

int rib_block_color_only(const Rib *r)
{
    return r->in_object && !r->recorded.have_shader && r->a.surface == r->object_surface &&
           r->a.color_gen != r->object_color_gen;
}

int rib_collapsed(Rib *r)
{
    int n = r->a.n_motion > 1 ? r->a.n_motion : 1;
    for (int k = 0; k < n; k++) {
        const float *m = n > 1 ? r->a.motion_M[k] : r->a.M;
        int finite = 1;
        for (int i = 0; i < 16; i++)
            finite &= isfinite(m[i]) != 0;
        Mat4 inv;
        if (finite && !mat4_invert(mat4_from_array(m), &inv)) {
            rib_warn_once(r, "singular transform",
                          "%s under a singular transform (a Scale of 0) is flat or a point: not "
                          "drawn",
                          r->req);
            return 1;
        }
    }
    return 0;
}

/* Brings the sink up to date before a primitive; Cs overrides the
 * colour (a per-face colour) when not NULL. 1: skip (outside the world,
 * or collapsed by a singular transform, as RenderMan draws nothing). */
int rib_emit_begin(Rib *r, const float *Cs)
{
    if (!r->in_world && !r->rec && !r->in_object) {
        rib_warn_once(r, "outside world", "geometry outside WorldBegin/WorldEnd is ignored");
        return 1;
    }
    if (rib_collapsed(r))
        return 1;
    if (!r->rec && !r->in_object && rib_send_lights(r) != 0)
        return -1;
    if (r->a.atmosphere && !r->rec && !r->in_object) {
        if (!r->world_atmosphere)
            r->world_atmosphere = r->a.atmosphere;
        else if (r->world_atmosphere != r->a.atmosphere)
            rib_warn_once(r, "atmospheres",
                          "rayes renders one Atmosphere per scene: that of the first primitive "
                          "under one; this primitive's is not used");
    }
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (send_transform(r, s, st) != 0)
        return -1;
    if (send_visibility(r, s, st) != 0)
        return -1;
    if (Cs) {
        if (send_shader(r, s, Cs) != 0)
            return -1;
        st->have_shader = 0;
    } else if (r->in_object && !st->have_shader && r->a.surface == r->object_surface &&
               (r->a.color_gen == r->object_color_gen || r->pv_block_color)) {
        /* no Surface in the block yet, nor a Color (or one the primitive
         * carries as Cs): each instance's shader */
    } else if (!st->have_shader || st->surface != r->a.surface || st->color_gen != r->a.color_gen) {
        if (rib_block_color_only(r))
            rib_warn_once(r, "object color",
                          "a %s in an ObjectBegin block that sets Color but no Surface takes "
                          "the Surface current at ObjectBegin, not each instance's (it carries "
                          "no colour of its own)",
                          r->req);
        if (send_shader(r, s, r->a.Cs) != 0)
            return -1;
        st->surface = r->a.surface;
        st->color_gen = r->a.color_gen;
        st->have_shader = 1;
    }
    if (!st->have_displacement || st->displacement != r->a.displacement) {
        const ShaderRec *d = r->a.displacement;
        if (s->set_displacement(s->target, d ? d->name : NULL, d ? d->params : NULL,
                                d ? d->n : 0) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->displacement = d;
        st->have_displacement = 1;
    }
    if (!st->have_rate || st->rate != r->a.shading_rate) {
        if (s->set_shading_rate(s->target, r->a.shading_rate) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->rate = r->a.shading_rate;
        st->have_rate = 1;
    }
    if (!st->have_bound || st->bound != r->a.bound) {
        if (s->set_displacement_bound(s->target, r->a.bound) != RAYES_OK)
            return rib_sink_failed(r, s);
        st->bound = r->a.bound;
        st->have_bound = 1;
    }
    return 0;
}

/* ------------------------------------------------------------ shaders */

static const char *const builtin_surfaces[] = {
    "matte",      "plastic",        "metal",   "shinymetal", "constant",   "glass",
    "mirror",     "paintedplastic", "diffuse", "conductor",  "dielectric", "coateddiffuse",
    "subsurface", "defaultsurface", "glow",    NULL};
static const char *const builtin_displacements[] = {"bumpy", "fractal", "displace", NULL};
/* rayes' pattern classes (rayes_scene_pattern): pbrt-v4's textures. */
static const char *const builtin_patterns[] = {
    "constant", "scale", "mix",      "directionmix", "checkerboard", "imagemap", "bilerp",
    "dots",     "fbm",   "wrinkled", "windy",        "marble",       "cloud",    "densitygrid",
    "nanovdb",  NULL};

static int in_list(const char *const *list, const char *s)
{
    for (int k = 0; list[k]; k++)
        if (strcmp(list[k], s) == 0)
            return 1;
    return 0;
}

/* Whether a Pattern of that name reached the sink. */
static int pattern_sent(const Rib *r, const char *name)
{
    for (const ShaderRec *s = r->shaders; s; s = s->next)
        if (s->pattern[0] && strcmp(s->pattern, name) == 0)
            return 1;
    return 0;
}

const char *rib_pattern_name(const Rib *r, const char *ref, char *buf, size_t size)
{
    if (pattern_sent(r, ref))
        return ref;
    const char *colon = strrchr(ref, ':'); /* RenderMan's "pattern:output" */
    size_t len = colon ? (size_t)(colon - ref) : strlen(ref);
    if (colon && len < size) {
        memcpy(buf, ref, len);
        buf[len] = '\0';
        if (pattern_sent(r, buf))
            return buf;
    }
    /* an unbuilt pattern whose input is a pattern passes that pattern on */
    for (size_t k = r->n_stand_ins; k-- > 0;) {
        const struct PatternStandIn *si = &r->stand_ins[k];
        if (strlen(si->name) == len && strncmp(si->name, ref, len) == 0)
            return si->alias[0] && strlen(si->alias) < size ? strcpy(buf, si->alias) : NULL;
    }
    return NULL;
}

/* The newest record sent under pattern name, or NULL. */
static const ShaderRec *sent_as(const Rib *r, const char *name)
{
    const ShaderRec *s = r->shaders; /* newest first */
    while (s && !(s->pattern[0] && strcmp(s->pattern, name) == 0))
        s = s->next;
    return s;
}

const char *rib_pattern_ref(Rib *r, const char *ref, char *buf, size_t size)
{
    static const char *const outputs[] = {"resultR", "resultG", "resultB", "resultA", "resultF"};
    const char *colon = strrchr(ref, ':');
    int ch = -1;
    for (int k = 0; colon && k < 5; k++)
        if (strcmp(colon + 1, outputs[k]) == 0)
            ch = k == 4 ? 0 : k;
    char base_ref[160], base_buf[160];
    if (ch < 0 || (size_t)(colon - ref) >= sizeof base_ref)
        return rib_pattern_name(r, ref, buf, size);
    memcpy(base_ref, ref, (size_t)(colon - ref));
    base_ref[colon - ref] = '\0';
    /* the image: the pattern of that name, or the one a stand-in passes on */
    const char *name = rib_pattern_name(r, base_ref, base_buf, sizeof base_buf);
    if (!name)
        return rib_pattern_name(r, ref, buf, size);
    if (strlen(name) >= size)
        return NULL;
    memcpy(buf, name, strlen(name) + 1);
    const ShaderRec *base = sent_as(r, name);
    if (!base || !base->channels || strlen(ref) >= sizeof base->pattern || base->n >= 15 ||
        !r->sink->pattern)
        return buf;
    /* the channel's own pattern, made once per definition of the image (a
     * name used again for another texture gets its own) */
    const ShaderRec *made = sent_as(r, ref);
    if (made && made->of == base)
        return ref;
    RayesParam q[16];
    size_t n = 0;
    for (size_t k = 0; k < base->n; k++)
        if (strcmp(base->params[k].name, "channel") != 0)
            q[n++] = base->params[k];
    q[n++] = (RayesParam){"channel", RAYES_PARAM_FLOAT, {(float)ch, 0, 0}, NULL};
    ShaderRec *v = rib_shader_rec(r, base->name, q, n);
    const IoSink *s = r->sink;
    if (!v || s->set_transform(s->target, r->a.M) != RAYES_OK ||
        s->pattern(s->target, ref, v->name, v->params, v->n) != RAYES_OK)
        return buf; /* the image's colour, as before */
    r->real.have_M = 0;
    snprintf(v->pattern, sizeof v->pattern, "%s", ref);
    v->of = base;
    return ref;
}

int rib_pattern_stand_in(const Rib *r, const char *ref, float rgb[3])
{
    const char *colon = strrchr(ref, ':');
    size_t n = colon ? (size_t)(colon - ref) : strlen(ref);
    for (size_t k = r->n_stand_ins; k-- > 0;) {
        const struct PatternStandIn *si = &r->stand_ins[k];
        if (strlen(si->name) == n && strncmp(si->name, ref, n) == 0) {
            memcpy(rgb, si->rgb, 3 * sizeof *rgb);
            return 1;
        }
    }
    return 0;
}

/* An unbuilt pattern's stand-in: the colour of its input (the first of
 * RenderMan's usual names for a pattern's main input that it gives, a
 * constant or another stand-in), kept under its name. */
static int add_stand_in(Rib *r, const char *name, const Param *p, size_t n)
{
    static const char *const inputs[] = {"inputRGB", "inputColor", "colorIn",     "input",
                                         "color1",   "inputA",     "defaultColor"};
    float rgb[3] = {0, 0, 0};
    char alias[160] = "";
    int found = 0;
    for (size_t k = 0; !found && k < sizeof inputs / sizeof inputs[0]; k++) {
        const Param *q = rib_find_param(p, n, inputs[k]);
        if (!q)
            continue;
        char buf[160];
        const char *via = q->d.reference && q->d.ty == TY_STRING && q->v->n == 1
                              ? rib_pattern_ref(r, q->v->s[0], buf, sizeof buf)
                              : NULL;
        if (via) {
            snprintf(alias, sizeof alias, "%s", via);
            found = 1;
        } else if (q->d.reference && q->d.ty == TY_STRING && q->v->n == 1)
            found = rib_pattern_stand_in(r, q->v->s[0], rgb);
        else if (rib_is_num(q->v) && (q->v->n == 3 || q->v->n == 1)) {
            for (int c = 0; c < 3; c++)
                rgb[c] = (float)q->v->d[q->v->n == 3 ? c : 0];
            found = 1;
        }
    }
    if (!found || strlen(name) >= sizeof r->stand_ins[0].name)
        return 0;
    if (r->n_stand_ins == r->cap_stand_ins) {
        size_t c = r->cap_stand_ins ? 2 * r->cap_stand_ins : 16;
        struct PatternStandIn *m = realloc(r->stand_ins, c * sizeof *m);
        if (!m)
            return rib_error(r, "out of memory");
        r->stand_ins = m, r->cap_stand_ins = c;
    }
    struct PatternStandIn *si = &r->stand_ins[r->n_stand_ins++];
    snprintf(si->name, sizeof si->name, "%s", name);
    memcpy(si->rgb, rgb, sizeof rgb);
    snprintf(si->alias, sizeof si->alias, "%s", alias);
    return 0;
}

/* make_shader's flags: keep only Kd and Ka (a stand-in for an unknown
 * shader); pass float arrays (a Pattern's data, densitygrid's density). */
#define SHADER_ONLY_K 1
#define SHADER_ARRAYS 2

/* An empty shader record of name with room for n parameters, kept on the
 * reader's list (freed with it); NULL with the error set. */
static ShaderRec *new_shader(Rib *r, const char *name, size_t n)
{
    ShaderRec *sh = calloc(1, sizeof *sh);
    if (sh)
        sh->params = calloc(n + 1, sizeof *sh->params);
    if (!sh || !sh->params) {
        free(sh);
        rib_error(r, "out of memory");
        return NULL;
    }
    sh->next = r->shaders;
    r->shaders = sh;
    snprintf(sh->name, sizeof sh->name, "%s", name);
    return sh;
}

/* A new shader record of name with the parameters the API can take. */
static ShaderRec *make_shader(Rib *r, const char *name, const Param *p, size_t n, int flags)
{
    ShaderRec *sh = new_shader(r, name, n);
    if (!sh)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        const Param *q = &p[i];
        if ((flags & SHADER_ONLY_K) && strcmp(q->d.name, "Kd") != 0 && strcmp(q->d.name, "Ka") != 0)
            continue;
        if (!q->declared)
            continue;
        RayesParam o = {NULL, RAYES_PARAM_NONE, {0, 0, 0}, NULL};
        char ref[160];
        const char *pattern =
            q->d.reference && q->v->n == 1 ? rib_pattern_ref(r, q->v->s[0], ref, sizeof ref) : NULL;
        if (q->d.reference && q->v->n == 1 && !pattern) {
            char key[128];
            snprintf(key, sizeof key, "reference %.100s", q->v->s[0]);
            rib_warn_once(r, key,
                          "\"%s\" of \"%s\" names the pattern \"%.100s\", which is "
                          "not defined or of a class rayes has not; its default is used",
                          q->d.name, name, q->v->s[0]);
            continue;
        }
        if (q->d.ty == TY_STRING && q->v->n == 1) {
            o.type = q->d.reference ? RAYES_PARAM_PATTERN : RAYES_PARAM_STRING;
            o.string = rib_strdup(pattern ? pattern : rib_texture_source(r, q->v->s[0]));
            if (!o.string)
                return NULL;
        } else if ((q->d.ty == TY_FLOAT || q->d.ty == TY_INT) && q->v->n == 1) {
            o.type = RAYES_PARAM_FLOAT;
            o.value[0] = (float)q->v->d[0];
        } else if ((flags & SHADER_ARRAYS) && q->d.ty == TY_FLOAT && q->v->n > 1) {
            float *v = malloc(q->v->n * sizeof *v);
            if (!v) {
                rib_error(r, "out of memory");
                return NULL;
            }
            for (size_t k = 0; k < q->v->n; k++)
                v[k] = (float)q->v->d[k];
            o.type = RAYES_PARAM_FLOATS;
            o.floats = v;
            o.n_floats = q->v->n;
        } else if (q->d.ty == TY_COLOR || q->d.ty == TY_POINT) {
            if (q->v->n != 3)
                continue;
            o.type = RAYES_PARAM_COLOR;
            for (int c = 0; c < 3; c++)
                o.value[c] = (float)q->v->d[c];
        } else {
            continue;
        }
        o.name = rib_strdup(q->d.name);
        if (!o.name) {
            free((char *)o.string);
            free((float *)o.floats);
            return NULL;
        }
        sh->params[sh->n++] = o;
    }
    return sh;
}

ShaderRec *rib_shader_rec(Rib *r, const char *name, const RayesParam *p, size_t n)
{
    ShaderRec *sh = new_shader(r, name, n);
    if (!sh)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        RayesParam o = p[i];
        o.name = rib_strdup(p[i].name);
        o.string = p[i].string ? rib_strdup(p[i].string) : NULL;
        o.floats = NULL;
        if (!o.name || (p[i].string && !o.string)) {
            free((char *)o.name);
            free((char *)o.string);
            rib_error(r, "out of memory");
            return NULL;
        }
        sh->params[sh->n++] = o;
    }
    return sh;
}

/* A built-in shader name, or one the sink knows (a plugin on its search
 * path). */
static int shader_known(Rib *r, const char *const *builtins, const char *name)
{
    return in_list(builtins, name) ||
           (r->sink->has_shader && r->sink->has_shader(r->sink->target, name));
}

/* A shader named by a path ("shaders/plastic", as some exporters and
 * course files name the compiled shader): its last component when the
 * whole name is neither built in nor a plugin. */
static const char *shader_name(Rib *r, const char *const *builtins, const char *name)
{
    const char *slash = strrchr(name, '/');
    return slash && slash[1] && !shader_known(r, builtins, name) ? slash + 1 : name;
}

/* The RenderMan Companion's copies of the classics under its own names
 * (Listings 16.2 and 16.4: the same parameters and bodies) and its glow
 * (16.26), as files written with its shader set name them. */
static const char *surface_alias(const char *name)
{
    static const char *const alias[][2] = {
        {"RCPlastic", "plastic"}, {"RCMatte", "matte"}, {"RCGlow", "glow"}};
    for (size_t k = 0; k < sizeof alias / sizeof alias[0]; k++)
        if (strcmp(name, alias[k][0]) == 0)
            return alias[k][1];
    return name;
}

/* A shader request's name and parameters (free *p); -1 on error. */
static int shader_args(Rib *r, const Args *a, const char **name, Param **p, size_t *n)
{
    size_t i = 0;
    *name = rib_get_string(r, a, &i, "a shader name");
    return *name && rib_get_params(r, a, i, p, n) == 0 ? 0 : -1;
}

static int h_surface(Rib *r, const Args *a)
{
    const char *name;
    Param *p;
    size_t n;
    if (shader_args(r, a, &name, &p, &n) != 0)
        return -1;
    name = shader_name(r, builtin_surfaces, name);
    if (!shader_known(r, builtin_surfaces, name)) /* a plugin of that name comes first */
        name = surface_alias(name);
    int known = shader_known(r, builtin_surfaces, name);
    if (!known) { /* only Ka and Kd are kept: the others' values are not checked */
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            if (strcmp(p[i].d.name, "Ka") == 0 || strcmp(p[i].d.name, "Kd") == 0)
                p[k++] = p[i];
        n = k;
    }
    static const Counts one = {1, 1, 1, 1};
    if (rib_check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    /* in a file without lights, RenderMan's own stand-in, which needs none */
    const char *instead = r->unlit_file ? "defaultsurface" : "matte";
    if (!known) {
        char key[128];
        snprintf(key, sizeof key, "surface %s", name);
        rib_warn_once(r, key,
                      "surface shader \"%s\" is neither built in nor a plugin on the shader "
                      "path: %s instead (with its Ka, Kd)",
                      name, instead);
    }
    ShaderRec *sh = make_shader(r, known ? name : instead, p, n, known ? 0 : SHADER_ONLY_K);
    free(p);
    if (!sh)
        return -1;
    r->a.surface = sh;
    return 0;
}

static int h_displacement(Rib *r, const Args *a)
{
    const char *name;
    Param *p;
    size_t n;
    if (shader_args(r, a, &name, &p, &n) != 0)
        return -1;
    static const Counts one = {1, 1, 1, 1};
    if (rib_check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    if (strcmp(name, "null") == 0 || name[0] == '\0') { /* RenderMan's "no shader" */
        r->a.displacement = NULL;
        free(p);
        return 0;
    }
    name = shader_name(r, builtin_displacements, name);
    if (!shader_known(r, builtin_displacements, name)) {
        char key[128];
        snprintf(key, sizeof key, "displacement %s", name);
        rib_warn_once(r, key,
                  "displacement shader \"%s\" is neither built in nor a plugin on the shader path: "
                  "no displacement",
                  name);
        r->a.displacement = NULL;
        free(p);
        return 0;
    }
    ShaderRec *sh = make_shader(r, name, p, n, 0);
    free(p);
    if (!sh)
        return -1;
    r->a.displacement = sh;
    return 0;
}

/* Light shaders of other renderers that are an environment (dome) light,
 * usually with occlusion: rayes' environmentlight stands in for them. */
static const char *const environment_lights[] = {"envlight",     "envlight2", "occlusionlight",
                                                 "domelight",    "skylight",  "ambientocclusion",
                                                 "PxrDomeLight", NULL};

/* The names their environment map goes by: rayes' mapname (and mapping),
 * then those of production light shaders and RenderMan's PxrDomeLight. */
static const char *const environment_maps[] = {"mapname",        "envmap",      "envname",
                                               "environmentmap", "texturename", "lightColorMap",
                                               "filename",       NULL};

/* An environment light's string parameter q as rayes' mapname or mapping
 * into L; 0 if q is neither. */
static int environment_map(Rib *r, Light *L, const Param *q, RayesParam *o, char *name, size_t size)
{
    int map = in_list(environment_maps, q->d.name);
    if ((!map && strcmp(q->d.name, "mapping") != 0) || q->d.ty != TY_STRING || q->v->n != 1)
        return 0;
    snprintf(name, size, "%s", map ? "mapname" : "mapping");
    char *dst = light_string(L, name);
    snprintf(dst, map ? sizeof L->mapname : sizeof L->mapping, "%s",
             map ? rib_texture_source(r, q->v->s[0]) : q->v->s[0]);
    *o = (RayesParam){.name = name, .type = RAYES_PARAM_STRING, .string = dst};
    return 1;
}

/* Whether a texture name is a readable file as given or on the texture
 * search path (the file's, then $RAYES_TEXTURE_PATH), as the scene will
 * look for it. */
int rib_texture_found(const Rib *r, const char *name)
{
    if (access(name, R_OK) == 0)
        return 1;
    const char *env = getenv("RAYES_TEXTURE_PATH");
    const char *paths[2] = {r->texture_path, env ? env : ""};
    char path[4096];
    for (int k = 0; k < 2 && name[0] != '/'; k++)
        for (const char *d = paths[k]; *d;) {
            size_t len = strcspn(d, ":");
            if (len > 0 &&
                (size_t)snprintf(path, sizeof path, "%.*s/%s", (int)len, d, name) < sizeof path &&
                access(path, R_OK) == 0)
                return 1;
            d += len + (d[len] == ':');
        }
    return 0;
}

/* Whether name looks like a file's (a path or a name with an extension),
 * not a word such as "raytrace" or "vertical". */
static int file_like(const char *name)
{
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    return base[0] && (strchr(base, '.') || base != name);
}

int rib_find_above(const char *file, const char *name, int levels, char *out, size_t size)
{
    const char *slash = strrchr(file, '/');
    char dir[4096];
    if (slash == file)
        snprintf(dir, sizeof dir, "/");
    else if ((size_t)snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - file) : 1,
                              slash ? file : ".") >= sizeof dir)
        return -1;
    for (int up = 0; up <= levels; up++) {
        struct stat st;
        if ((size_t)snprintf(out, size, "%s/%s", dir, name) >= size)
            return -1;
        if (stat(out, &st) == 0 && S_ISREG(st.st_mode) && access(out, R_OK) == 0)
            return 0;
        if (strlen(dir) + 4 >= sizeof dir)
            return -1;
        strcat(dir, "/..");
    }
    return -1;
}

/* name beside the file being read or in one of the RIB_TEXTURE_UP
 * directories above it, kept in r; NULL if none holds it. */
#define RIB_TEXTURE_UP 4
static const char *beside_scene(Rib *r, const char *name)
{
    char path[4096];
    if (rib_find_above(r->file, name, RIB_TEXTURE_UP, path, sizeof path) != 0)
        return NULL;
    for (size_t k = 0; k < r->n_found; k++) /* the same path, kept once */
        if (strcmp(r->found[k], path) == 0)
            return r->found[k];
    char *kept = rib_strdup(path);
    if (!kept || util_grow((void **)&r->found, &r->cap_found, r->n_found, sizeof *r->found) != 0) {
        free(kept);
        return NULL;
    }
    return r->found[r->n_found++] = kept;
}

const char *rib_texture_source(Rib *r, const char *name)
{
    for (size_t k = r->n_made; k-- > 0;) /* the last made of a name counts */
        if (strcmp(r->made[k].made, name) == 0)
            return r->made[k].from;
    /* PRMan reads a relative name from the working directory (the
     * project's, where the file was rendered); rendered from elsewhere,
     * the file's own directory and those above it hold it */
    if (name[0] && name[0] != '/' && file_like(name) && !rib_texture_found(r, name)) {
        const char *found = beside_scene(r, name);
        if (found)
            return found;
    }
    return name;
}

static Light *find_light(Rib *r, const char *handle)
{
    for (size_t k = 0; k < r->n_lights; k++)
        if (strcmp(r->lights[k].handle, handle) == 0)
            return &r->lights[k];
    return NULL;
}

Light *rib_new_light(Rib *r, const char *handle, const char *type)
{
    if (r->n_lights >= RIB_MAX_LIGHTS) {
        rib_error(r, "more than %d lights", RIB_MAX_LIGHTS);
        return NULL;
    }
    /* A handle used before: a second light; the first keeps lighting as
     * it is, and the handle names the new one from now on. */
    Light *L = find_light(r, handle);
    if (L)
        L->handle[0] = '\0';
    r->lit = 1;
    Light *nl = realloc(r->lights, (r->n_lights + 1) * sizeof *nl);
    if (!nl) {
        rib_error(r, "out of memory");
        return NULL;
    }
    r->lights = nl;
    L = &r->lights[r->n_lights++];
    memset(L, 0, sizeof *L);
    snprintf(L->handle, sizeof L->handle, "%s", handle);
    snprintf(L->type, sizeof L->type, "%s", type);
    memcpy(L->M, r->a.M, sizeof L->M);
    L->pre_world = !r->in_world;
    if (r->in_world && r->a.n_motion > 1) { /* a light moving within the frame */
        L->n_motion = r->a.n_motion;
        memcpy(L->motion_time, r->a.motion_time, (size_t)L->n_motion * sizeof *L->motion_time);
        memcpy(L->motion_M, r->a.motion_M, (size_t)L->n_motion * sizeof L->motion_M[0]);
    }
    L->index = -1;
    set_light_on(&r->a, (size_t)(L - r->lights), 1);
    return L;
}

void rib_light_param(Light *L, const char *name, RayesParamType type, const float v[3],
                     const char *string)
{
    size_t at = 0; /* a parameter of that name is replaced */
    while (at < L->n && strcmp(L->names[at], name) != 0)
        at++;
    if (at >= RIB_LIGHT_PARAMS)
        return;
    RayesParam *o = &L->params[at];
    snprintf(L->names[at], sizeof L->names[0], "%s", name);
    *o = (RayesParam){.name = L->names[at], .type = type};
    if (type == RAYES_PARAM_STRING) {
        char *dst = light_string(L, name);
        size_t size = dst == L->mapname     ? sizeof L->mapname
                      : dst == L->mapping   ? sizeof L->mapping
                      : dst == L->shape     ? sizeof L->shape
                      : dst == L->lighttype ? sizeof L->lighttype
                                            : sizeof L->category;
        snprintf(dst, size, "%s", string);
        o->string = dst;
    } else {
        for (int c = 0; c < (type == RAYES_PARAM_COLOR ? 3 : 1); c++)
            o->value[c] = v[c];
    }
    L->n += at == L->n;
}

static int intensity(const Param *q)
{
    return strcmp(q->d.name, "intensity") == 0;
}

/* uberlight's parameters (Barzel's light as Gritz's shader names them)
 * that rayes reads; the others (shadow map lookups, shadownsamps) are not
 * needed by ray-traced shadows. */
static const char *const uber_floats[] = {
    "cuton",        "cutoff",       "nearedge",     "faredge",
    "falloff",      "falloffdist",  "maxintensity", "parallelrays",
    "shearx",       "sheary",       "width",        "height",
    "wedge",        "hedge",        "roundness",    "beamdistribution",
    "noiseamp",     "noisefreq",    "blockerwidth", "blockerheight",
    "blockerwedge", "blockerhedge", "blockerround", NULL};
static const char *const uber_vectors[] = {"noiseoffset", "shadowcolor", "shadowcheat", NULL};
static const char *const uber_others[] = {
    "intensity",     "lightcolor",     "lighttype",     "slidename",  "shadowmap",
    "shadowname",    "raytraceshadow", "blockercoords", "shadows",    "blockermatrix",
    "__nonspecular", "nonspecular",    "__nondiffuse",  "nondiffuse", NULL};

/* The shader declares its parameters: an uberlight's that rayes reads
 * need no Declare (their values' kind and count are checked where read). */
static void uber_declare(Param *p, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!p[k].declared &&
            (in_list(uber_floats, p[k].d.name) || in_list(uber_vectors, p[k].d.name) ||
             in_list(uber_others, p[k].d.name))) {
            p[k].declared = 1;
            p[k].d.array = rib_is_num(p[k].v) && p[k].v->n > 0 ? (int)p[k].v->n : 1;
        }
}

/* L's blocker matrix (L->blocker, filled) as its "blockermatrix". */
static void blocker_param(Light *L)
{
    if (L->n >= RIB_LIGHT_PARAMS)
        return;
    snprintf(L->names[L->n], sizeof L->names[0], "blockermatrix");
    L->params[L->n] = (RayesParam){
        .name = L->names[L->n], .type = RAYES_PARAM_FLOATS, .floats = L->blocker, .n_floats = 16};
    L->n++;
}

/* A float parameter's value, or def. */
static double param_float(const Param *p, size_t n, const char *name, double def)
{
    const Param *q = rib_find_param(p, n, name);
    return q && rib_is_num(q->v) && q->v->n >= 1 && isfinite(q->v->d[0]) ? q->v->d[0] : def;
}

/* A colour parameter (three values, or one for all), or def. */
static void param_color(const Param *p, size_t n, const char *name, double def, double out[3])
{
    const Param *q = rib_find_param(p, n, name);
    int ok = q && rib_is_num(q->v) && (q->v->n == 1 || q->v->n == 3);
    for (int c = 0; c < 3; c++)
        out[c] =
            ok && isfinite(q->v->d[q->v->n == 3 ? c : 0]) ? q->v->d[q->v->n == 3 ? c : 0] : def;
}

/* l_uber's Maya cone: coneAngle (degrees, its full width; Maya's least,
 * 0.006, means none) and penumbraAngle narrow the spot to a round cross
 * section of half width tan(coneAngle / 2), fading to tan((coneAngle +
 * penumbraAngle) / 2), where width and height were wider. */
static void cone_shape(Light *L, const Param *p, size_t n)
{
    double cone = param_float(p, n, "coneAngle", 0.006);
    if (!(cone > 0.006) || cone >= 179.0)
        return;
    double pen = fmax(param_float(p, n, "penumbraAngle", 0.0), 0.0);
    double inner = tan(cone * M_PI / 360.0);
    double outer = tan(fmin(cone + pen, 179.0) * M_PI / 360.0);
    double w = fmin(param_float(p, n, "width", 1.0), inner);
    double h = fmin(param_float(p, n, "height", 1.0), inner);
    const float v[4][3] = {{(float)w}, {(float)h}, {(float)(outer - w)}, {(float)(outer - h)}};
    static const char *const names[4] = {"width", "height", "wedge", "hedge"};
    for (int k = 0; k < 4; k++)
        rib_light_param(L, names[k], RAYES_PARAM_FLOAT, v[k], NULL);
    static const float round[3] = {1, 0, 0};
    rib_light_param(L, "roundness", RAYES_PARAM_FLOAT, round, NULL);
}

/* An uberlight's parameters into L (intensity and lightcolor are read as
 * any light's): its shaping, slide, blocker (its coordinate system's
 * matrix), and whether it casts shadows, which in RenderMan it does only
 * with a shadow map or BMRT's raytraceshadow (rayes traces them either
 * way). Parameters need no declaration (the shader declares them). */
static int uber_params(Rib *r, Light *L, const Param *p, size_t n, int l_uber)
{
    int shadows = 0;
    for (size_t k = 0; k < n; k++) {
        const Param *q = &p[k];
        const char *nm = q->d.name;
        int num = rib_is_num(q->v), str = !num && q->v->n == 1;
        if (str && (strcmp(nm, "shadowmap") == 0 || strcmp(nm, "shadowname") == 0 ||
                    (l_uber && strlen(nm) == 3 && nm[0] == 's' && strchr("pn", nm[1]) &&
                     strchr("xyz", nm[2])))) {
            /* l_uber's spx ... snz: a point light's six shadow maps */
            shadows |= q->v->s[0][0] != '\0';
        } else if (num && q->v->n == 1 && strcmp(nm, "raytraceshadow") == 0) {
            shadows |= q->v->d[0] != 0.0;
        } else if (num && q->v->n == 1 && strcmp(nm, "shadows") == 0) {
            shadows = q->v->d[0] != 0.0 ? 1 : -1; /* rayes' own, as written: it decides */
        } else if (num && q->v->n == 16 && strcmp(nm, "blockermatrix") == 0) {
            for (int c = 0; c < 16; c++) /* rayes' own: world_from_blocker as written */
                L->blocker[c] = (float)q->v->d[c];
            blocker_param(L);
        } else if (num && q->v->n == 1 &&
                   (strcmp(nm, "__nonspecular") == 0 || strcmp(nm, "nonspecular") == 0 ||
                    strcmp(nm, "__nondiffuse") == 0 || strcmp(nm, "nondiffuse") == 0)) {
            float v[3] = {(float)q->v->d[0], 0, 0};
            rib_light_param(L, strstr(nm, "specular") ? "__nonspecular" : "__nondiffuse",
                            RAYES_PARAM_FLOAT, v, NULL);
        } else if (num && q->v->n == 1 && in_list(uber_floats, nm)) {
            /* maxintensity is an intensity: RenderMan's, pi times rayes' */
            float v[3] = {(float)(q->v->d[0] * (strcmp(nm, "maxintensity") == 0 ? M_PI : 1.0)), 0,
                          0};
            rib_light_param(L, nm, RAYES_PARAM_FLOAT, v, NULL);
        } else if (num && q->v->n == 3 && in_list(uber_vectors, nm)) {
            float v[3] = {(float)q->v->d[0], (float)q->v->d[1], (float)q->v->d[2]};
            rib_light_param(L, nm, RAYES_PARAM_COLOR, v, NULL);
        } else if (num && q->v->n == 1 && strcmp(nm, "lighttype") == 0) {
            /* Lancaster's l_uber (Maya's lights): 0 spot, 2 BMRT's area,
             * 3 directional (parallel rays), else omni */
            int k = (int)q->v->d[0];
            if (k == 2)
                rib_warn_once(r, "uber lighttype",
                              "uberlight: lighttype \"arealight\" is not built in; \"omni\" "
                              "instead");
            if (k == 3) {
                static const float one[3] = {1, 0, 0};
                rib_light_param(L, "parallelrays", RAYES_PARAM_FLOAT, one, NULL);
            }
            rib_light_param(L, "lighttype", RAYES_PARAM_STRING, NULL, k == 0 ? "spot" : "omni");
        } else if (str && strcmp(nm, "lighttype") == 0) {
            const char *t = q->v->s[0];
            if (strcmp(t, "spot") != 0 && strcmp(t, "omni") != 0) {
                rib_warn_once(r, "uber lighttype",
                              "uberlight: lighttype \"%.32s\" is not built in; \"omni\" instead",
                              t);
                t = "omni";
            }
            rib_light_param(L, "lighttype", RAYES_PARAM_STRING, NULL, t);
        } else if (str && strcmp(nm, "slidename") == 0 && q->v->s[0][0]) {
            const char *t = rib_texture_source(r, q->v->s[0]);
            if (!rib_texture_found(r, t))
                rib_warn_once(r, "uber slide",
                              "uberlight: slide \"%.200s\" is not found as given nor on the "
                              "texture search path; no slide",
                              t);
            else
                rib_light_param(L, "slidename", RAYES_PARAM_STRING, NULL, t);
        } else if (str && strcmp(nm, "blockercoords") == 0 && q->v->s[0][0]) {
            if (rib_coordsys(r, q->v->s[0], L->blocker) != 0)
                return rib_error(r, "uberlight: unknown blockercoords \"%.64s\"", q->v->s[0]);
            blocker_param(L);
        }
    }
    for (int k = 0; l_uber && k < 2; k++) /* l_uber's edges are sharp unless said */
        if (!rib_find_param(p, n, k ? "hedge" : "wedge")) {
            static const float zero[3] = {0, 0, 0};
            rib_light_param(L, k ? "hedge" : "wedge", RAYES_PARAM_FLOAT, zero, NULL);
        }
    if (l_uber)
        cone_shape(L, p, n);
    double falloff = param_float(p, n, "falloff", 0.0);
    double falloffdist = param_float(p, n, "falloffdist", 1.0);
    if ((falloff == 0.0 || l_uber) && !(falloffdist > 0.0)) {
        /* unused without falloff (l_uber writes 0); with it, l_uber's law
         * (1 / (d - falloffdist))^falloff is 1 / d^falloff, Barzel's with a
         * falloffdist of 1 */
        static const float one[3] = {1, 0, 0};
        rib_light_param(L, "falloffdist", RAYES_PARAM_FLOAT, one, NULL);
    } else if (l_uber && falloff != 0.0) {
        rib_warn_once(r, "l_uber falloff",
                      "l_uber: its distance falloff (1 / (d - falloffdist))^falloff is taken as "
                      "Barzel's (falloffdist / d)^falloff");
    }
    if (!rib_find_param(p, n, "maxintensity")) { /* RenderMan's default 1: pi of rayes' */
        const float pi[3] = {(float)M_PI, 0, 0};
        rib_light_param(L, "maxintensity", RAYES_PARAM_FLOAT, pi, NULL);
    }
    if (shadows == 0 && r->a.shadows > 0)
        shadows = 1; /* BMRT's Attribute "light" "shadows" "on" */
    if (shadows <= 0 || r->a.shadows < 0) {
        static const float off[3] = {0, 0, 0};
        rib_light_param(L, "shadows", RAYES_PARAM_FLOAT, off, NULL);
    }
    return 0;
}

/* Whether a light shader of RenderMan's casts shadows when nothing else
 * says: pointlight, spotlight and distantlight trace none; shadowpoint,
 * shadowspot and shadowdistant, and the stand-ins for lights rayes does
 * not have, cast their maps' (shadowname, or shadowpoint's six sf*
 * faces; "raytrace" among them), which rayes traces; rayes' other lights
 * (environment, area) cast theirs. */
static int casts_shadows(const char *name, const char *type, const Param *p, size_t n)
{
    if (strcmp(type, "pointlight") != 0 && strcmp(type, "spotlight") != 0 &&
        strcmp(type, "distantlight") != 0)
        return 1;
    if (strcmp(name, type) == 0)
        return 0; /* pointlight, spotlight, distantlight: none; the others by their map */
    for (size_t k = 0; k < n; k++) {
        const char *nm = p[k].d.name;
        int map =
            strcmp(nm, "shadowname") == 0 || (strncmp(nm, "sf", 2) == 0 && strchr("pn", nm[2]) &&
                                              nm[2] && strchr("xyz", nm[3]) && nm[3] && !nm[4]);
        if (map && !rib_is_num(p[k].v) && p[k].v->n == 1 && p[k].v->s[0][0])
            return 1;
    }
    return 0;
}

/* Whether name holds word, in any case. */
static int names_it(const char *name, const char *word)
{
    size_t n = strlen(word);
    for (const char *s = name; *s; s++)
        if (strncasecmp(s, word, n) == 0)
            return 1;
    return 0;
}

/* The classic light that stands in for a light shader rayes does not
 * have, by what its parameters and name say it is: a cone ("coneangle")
 * a spotlight; "distant", "directional" or "sun" in its name a distant
 * light; "point", or a "from" without a "to", a point light (but not a
 * point light without falloff, "nofall"); else NULL. */
static const char *stand_in_light(const char *name, const Param *p, size_t n)
{
    if (rib_find_param(p, n, "coneangle"))
        return "spotlight";
    if (names_it(name, "distant") || names_it(name, "directional") || names_it(name, "sun"))
        return "distantlight";
    if (names_it(name, "nofall"))
        return NULL;
    if (names_it(name, "point") || (rib_find_param(p, n, "from") && !rib_find_param(p, n, "to")))
        return "pointlight"; /* by name, or a position alone (a studio's shadowlight) */
    return NULL;
}

/* A spot light's cone as RenderMan's spotlight computes it: cos(coneangle)
 * and cos(coneangle - conedeltaangle), whatever the angles (students write
 * degrees where radians belong: coneangle 20 is 20 radians, whose cosine
 * PRMan takes). L's cone, in degrees by now, becomes the angles in
 * [0, 180] of those cosines (the same for angles in range). */
static void fold_cone(Light *L)
{
    float *cone = NULL, *delta = NULL;
    for (size_t i = 0; i < L->n; i++) {
        if (L->params[i].type != RAYES_PARAM_FLOAT)
            continue;
        if (strcmp(L->params[i].name, "coneangle") == 0)
            cone = &L->params[i].value[0];
        else if (strcmp(L->params[i].name, "conedeltaangle") == 0)
            delta = &L->params[i].value[0];
    }
    if (!cone)
        return;
    double a = *cone * M_PI / 180, d = delta ? *delta * M_PI / 180 : 0.0;
    double outer = acos(cos(a)), inner = acos(cos(a - d));
    *cone = (float)fmax(outer * 180 / M_PI, 1e-3); /* (0, 180] */
    if (delta)
        *delta = (float)fmax((outer - inner) * 180 / M_PI, 0.0);
}

/* Whether a light's "from" and "to" (RenderMan's defaults 0 0 0 and
 * 0 0 1) are one point: a direction of zero length. */
static int aims_nowhere(const Param *p, size_t n)
{
    double from[3] = {0, 0, 0}, to[3] = {0, 0, 1};
    const Param *f = rib_find_param(p, n, "from"), *t = rib_find_param(p, n, "to");
    for (int c = 0; c < 3; c++) {
        if (f && rib_is_num(f->v) && f->v->n == 3)
            from[c] = f->v->d[c];
        if (t && rib_is_num(t->v) && t->v->n == 3)
            to[c] = t->v->d[c];
    }
    return from[0] == to[0] && from[1] == to[1] && from[2] == to[2];
}

static int h_light_source(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a light shader name");
    if (name && strrchr(name, '/') && strrchr(name, '/')[1])
        name = strrchr(name, '/') + 1; /* "shaders/pointlight": a path's last component */
    char handle[RIB_MAX_HANDLE];
    if (!name)
        return -1;
    if (i < a->n && (a->n - i) % 2 == 1) { /* parameters come in pairs: the odd one out */
        if (rib_get_handle(r, a, &i, handle) != 0)
            return -1;
    } else {
        snprintf(handle, sizeof handle, "@%zu", r->n_lights);
    }
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    static const Counts one = {1, 1, 1, 1};
    int l_uber = strcmp(name, "l_uber") == 0; /* Lancaster's, with Maya's controls */
    if (strcmp(name, "uberlight") == 0 || l_uber)
        uber_declare(p, n);
    if (rib_check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    const char *type = NULL, *stand_in = NULL;
    int spot = 0;
    if (strcmp(name, "pointlight") == 0 || strcmp(name, "shadowpoint") == 0)
        type = "pointlight";
    else if (strcmp(name, "distantlight") == 0 || strcmp(name, "shadowdistant") == 0)
        type = "distantlight";
    else if (strcmp(name, "spotlight") == 0 || strcmp(name, "shadowspot") == 0)
        type = "spotlight", spot = 1;
    else if (strcmp(name, "ambientlight") == 0)
        type = "ambientlight";
    else if (strcmp(name, "environmentlight") == 0)
        type = "environmentlight";
    else if (strcmp(name, "arealight") == 0) /* rayes' own (what the writer writes) */
        type = "arealight";
    else if (strcmp(name, "uberlight") == 0 || l_uber) /* Barzel's */
        type = "uberlight";
    else if (in_list(environment_lights, name)) {
        /* Production environment and occlusion lights: an environment
         * light (of their map, if given), whose shadow rays give the
         * occlusion. */
        type = "environmentlight";
        char key[128];
        snprintf(key, sizeof key, "light %s", name);
        rib_warn_once(r, key,
                      "light shader \"%s\" is not built in: an environmentlight of its intensity, "
                      "lightcolor and map instead (ambient occlusion from its shadow rays; sample "
                      "counts and other parameters are not read)",
                      name);
    }
    if (r->rec || r->in_object) {
        rib_warn_once(r, "light in object", "lights inside ObjectBegin are ignored");
        type = NULL;
    } else if (!type && strcmp(name, "indirectlight") == 0) {
        rib_warn_once(r, "light indirectlight", "light shader \"indirectlight\" is skipped: rayes "
                                                "computes indirect light itself (--bounces)");
    } else if (!type && (stand_in = stand_in_light(name, p, n)) != NULL) {
        type = stand_in;
        spot = strcmp(type, "spotlight") == 0;
        char key[128];
        snprintf(key, sizeof key, "light %s", name);
        rib_warn_once(r, key,
                      "light shader \"%s\" is not built in: a %s of its intensity, lightcolor, "
                      "from and to%s instead (its other parameters are not read)",
                      name, type, spot ? ", cone and beam distribution" : "");
    } else if (!type) {
        char key[128];
        snprintf(key, sizeof key, "light %s", name);
        rib_warn_once(r, key, "light shader \"%s\" is not built in; the light is skipped", name);
    }
    if (type && (strcmp(type, "distantlight") == 0 || strcmp(type, "spotlight") == 0) &&
        aims_nowhere(p, n)) {
        rib_warn_once(r, "light from to",
                      "light \"%s\": \"from\" and \"to\" coincide, so it "
                      "shines nowhere; skipped",
                      name);
        type = NULL;
    }
    if (!type) {
        free(p);
        return 0;
    }
    Light *L = rib_new_light(r, handle, type);
    if (!L) {
        free(p);
        return -1;
    }
    int env = !stand_in && strcmp(type, "environmentlight") == 0;
    if (env || (!stand_in && strcmp(type, "arealight") == 0)) {
        /* its shape, or the background, is seen as the attributes say */
        L->own_visibility = 1;
        L->visibility = r->a.visibility;
    }
    static const char *const names[] = {
        "intensity",    "lightcolor", "sundirection", "haziness",       "groundcolor",
        "from",         "to",         "coneangle",    "conedeltaangle", "beamdistribution",
        "__category",   "fov",        "shape",        "width",          "height",
        "radius",       "shadows",    "__nondiffuse", "__nonspecular",  "cone",
        "conesoftness", NULL};
    int mapped = strcmp(type, "pointlight") == 0 || strcmp(type, "spotlight") == 0;
    int area_map = strcmp(type, "arealight") == 0; /* a quad's image over it */
    /* RenderMan's point, spot and distant lights: diffuse() sums Cl (L.N)
     * with no 1/pi, so their intensity is pi times rayes' (DESIGN.md,
     * "Lights"); the default intensity 1 too */
    int uber = strcmp(type, "uberlight") == 0;
    int unit = mapped || uber || strcmp(type, "distantlight") == 0;
    if (unit && !rib_find_param(p, n, "intensity")) {
        RayesParam *o = &L->params[L->n];
        snprintf(L->names[L->n], sizeof L->names[0], "intensity");
        *o =
            (RayesParam){.name = L->names[L->n], .type = RAYES_PARAM_FLOAT, .value = {(float)M_PI}};
        L->n++;
    }
    for (size_t k = 0; k < n && L->n < RIB_LIGHT_PARAMS; k++) {
        const Param *q = &p[k];
        /* a map: a point or spot light's intensity by direction (rayes'
         * own), or an environment's */
        int map_param =
            env ||
            (mapped && (strcmp(q->d.name, "mapname") == 0 || strcmp(q->d.name, "mapping") == 0)) ||
            (area_map && strcmp(q->d.name, "mapname") == 0);
        if (map_param &&
            environment_map(r, L, q, &L->params[L->n], L->names[L->n], sizeof L->names[0])) {
            /* a map that is not there (for a production light, a renderer's
             * own format elsewhere): an even light, a constant environment */
            if ((mapped || area_map || strcmp(name, "environmentlight") != 0) && L->mapname[0] &&
                strcmp(L->names[L->n], "mapname") == 0 && !rib_texture_found(r, L->mapname)) {
                int even = mapped || area_map;
                rib_warn_once(r, even ? "point light map" : "light map",
                              "light%s \"%s\": map \"%.200s\" is not found as given nor on the "
                              "texture search path; %s",
                              even ? "" : " shader", name, L->mapname,
                              even ? "the light is even" : "a constant environment");
                L->mapname[0] = '\0';
                continue;
            }
            L->n++;
            continue;
        }
        if (env && strcmp(q->d.name, "intensity") != 0 && strcmp(q->d.name, "lightcolor") != 0 &&
            strcmp(q->d.name, "__category") != 0 && strcmp(q->d.name, "sundirection") != 0 &&
            strcmp(q->d.name, "haziness") != 0 && strcmp(q->d.name, "groundcolor") != 0)
            continue; /* an environment light has no position or cone (a sky has its sun) */
        if (!in_list(names, q->d.name) || (!q->declared && !(uber && intensity(q))))
            continue;
        if (uber && !intensity(q) && strcmp(q->d.name, "lightcolor") != 0 &&
            strcmp(q->d.name, "__category") != 0)
            continue; /* the shaping's are uber_params' */
        RayesParam *o = &L->params[L->n];
        snprintf(L->names[L->n], sizeof L->names[0], "%s", q->d.name);
        o->name = L->names[L->n];
        if (q->d.ty == TY_STRING) {
            if (q->v->n != 1 ||
                (strcmp(q->d.name, "shape") != 0 && strcmp(q->d.name, "__category") != 0))
                continue; /* a string where a number belongs */
            char *dst = light_string(L, q->d.name);
            snprintf(dst, dst == L->shape ? sizeof L->shape : sizeof L->category, "%s", q->v->s[0]);
            o->type = RAYES_PARAM_STRING;
            o->string = dst;
        } else if (q->v->n == 3) {
            o->type = RAYES_PARAM_COLOR;
            for (int c = 0; c < 3; c++)
                o->value[c] = (float)(q->v->d[c] * (unit && intensity(q) ? M_PI : 1.0));
        } else if (q->v->n == 1) {
            o->type = RAYES_PARAM_FLOAT;
            o->value[0] = (float)(q->v->d[0] * (unit && intensity(q) ? M_PI : 1.0));
            if (spot && (strcmp(q->d.name, "coneangle") == 0 ||
                         strcmp(q->d.name, "conedeltaangle") == 0))
                o->value[0] = (float)(o->value[0] * 180 / M_PI); /* RenderMan gives radians */
        } else {
            continue;
        }
        L->n++;
    }
    if (spot)
        fold_cone(L);
    int e = uber ? uber_params(r, L, p, n, l_uber) : 0;
    const Param *said = rib_find_param(p, n, "shadows");
    if (!uber && !(said && said->declared) &&
        (r->a.shadows < 0 || (r->a.shadows == 0 && !casts_shadows(name, type, p, n)))) {
        static const float off[3] = {0, 0, 0};
        rib_light_param(L, "shadows", RAYES_PARAM_FLOAT, off, NULL);
    }
    free(p);
    return e;
}

int rib_add_area_handle(Rib *r, const char *handle)
{
    if (r->n_area_handles >= RIB_MAX_LIGHTS)
        return rib_error(r, "more than %d area light handles", RIB_MAX_LIGHTS);
    char(*nh)[RIB_MAX_HANDLE] = realloc(r->area_handles, (r->n_area_handles + 1) * sizeof *nh);
    if (!nh)
        return rib_error(r, "out of memory");
    r->area_handles = nh;
    snprintf(nh[r->n_area_handles++], RIB_MAX_HANDLE, "%s", handle);
    return 0;
}

static int h_area_light(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a light shader name");
    if (name && strrchr(name, '/') && strrchr(name, '/')[1])
        name = strrchr(name, '/') + 1; /* "shaders/pointlight": a path's last component */
    char handle[RIB_MAX_HANDLE];
    if (!name)
        return -1;
    if (i < a->n && (a->n - i) % 2 == 1) {
        if (rib_get_handle(r, a, &i, handle) != 0 || rib_add_area_handle(r, handle) != 0)
            return -1;
    }
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    /* RenderMan 19 and 20's PxrAreaLight and PxrStdAreaLight add an
     * exposure (a power of 2) and spell the colour lightColor */
    const Param *in = rib_find_param(p, n, "intensity"), *lc = rib_find_param(p, n, "lightcolor");
    const Param *ex = rib_find_param(p, n, "exposure");
    if (!lc)
        lc = rib_find_param(p, n, "lightColor");
    float I = in && rib_is_num(in->v) && in->v->n == 1 ? (float)in->v->d[0] : 1;
    if (ex && rib_is_num(ex->v) && ex->v->n == 1)
        I *= exp2f(fminf(fmaxf((float)ex->v->d[0], -126.0f), 126.0f));
    for (int c = 0; c < 3; c++)
        r->a.area_L[c] = I * (lc && rib_is_num(lc->v) && lc->v->n == 3 ? (float)lc->v->d[c] : 1);
    const Param *an = rib_find_param(p, n, "areaNormalize");
    r->a.area_normalize = an && rib_is_num(an->v) && an->v->n == 1 && an->v->d[0] != 0;
    /* BMRT's arealight (and Pixie's) takes a point light's intensity; rayes'
     * own, as its writer writes it, only a radiance in lightcolor */
    r->a.area_point_units = strcmp(name, "arealight") == 0 && in != NULL;
    r->a.area_map[0] = '\0';
    for (size_t k = 0; k < n; k++) /* an envsphere's map (rib_ris.c) */
        if (p[k].d.ty == TY_STRING && p[k].v->n == 1 &&
            (in_list(environment_maps, p[k].d.name) || strcmp(p[k].d.name, "rman__EnvMap") == 0 ||
             strcmp(p[k].d.name, "lightcolormap") == 0))
            snprintf(r->a.area_map, sizeof r->a.area_map, "%s", p[k].v->s[0]);
    r->a.area_texture[0] = '\0'; /* rayes' own: an emission texture over the shapes' st */
    const Param *tx = rib_find_param(p, n, "texturename");
    if (tx && tx->d.ty == TY_STRING && tx->v->n == 1 && tx->v->s[0][0]) {
        if (strlen(tx->v->s[0]) >= sizeof r->a.area_texture)
            rib_warn_once(r, "area texture long",
                          "AreaLightSource: texturename longer than %zu "
                          "characters; the light is untextured",
                          sizeof r->a.area_texture - 1);
        else
            snprintf(r->a.area_texture, sizeof r->a.area_texture, "%s", tx->v->s[0]);
    }
    const Param *pv = rib_find_param(p, n, "rman__LightPrimaryVisibility");
    r->a.area_unseen = pv && rib_is_num(pv->v) && pv->v->n == 1 && pv->v->d[0] == 0;
    const Param *ts = rib_find_param(p, n, "twosided");
    r->a.area_twosided = ts && rib_is_num(ts->v) && ts->v->n == 1 && ts->v->d[0] != 0;
    r->lit = 1;
    free(p);
    if (r->in_object) {
        rib_warn_once(r, "area light in object",
                      "area lights inside ObjectBegin are ignored (their quads are geometry)");
        return 0;
    }
    r->a.area = 1;
    return 0;
}

static int h_illuminate(Rib *r, const Args *a)
{
    size_t i = 0;
    char handle[RIB_MAX_HANDLE];
    float on;
    if (rib_get_handle(r, a, &i, handle) != 0 || rib_get_floats(r, a, &i, &on, 1, "0 or 1") != 0)
        return -1;
    Light *L = find_light(r, handle);
    if (!L) {
        for (size_t k = 0; k < r->n_area_handles; k++)
            if (strcmp(r->area_handles[k], handle) == 0) {
                if (on == 0) /* on, it says what rayes does already */
                    rib_warn_once(r, "Illuminate area",
                                  "Illuminate of the area light %s is ignored: "
                                  "area lights light everything",
                                  rib_handle_name(handle));
                return 0;
            }
        /* a light skipped (a shader rayes does not have) or never given:
         * RenderMan reports it and goes on */
        rib_warn_once(r, "Illuminate unknown",
                      "Illuminate: no light has the handle %s; ignored (a light skipped?)",
                      rib_handle_name(handle));
        return 0;
    }
    set_light_on(&r->a, (size_t)(L - r->lights), on != 0);
    return 0;
}

/* The world's atmosphere, once its primitives are all sent: its volume
 * shader, then the atmosphere (rayes_scene_atmosphere). */
static int send_atmosphere(Rib *r)
{
    const ShaderRec *sh = r->world_atmosphere;
    r->world_atmosphere = NULL;
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (!s->atmosphere) {
        rib_warn_once(r, "atmosphere sink", "this output takes no Atmosphere; it is dropped");
        return 0;
    }
    st->have_shader = 0; /* the next primitive's shader is sent again */
    if (s->set_shader(s->target, sh->name, sh->params, sh->n) != RAYES_OK ||
        s->atmosphere(s->target) != RAYES_OK)
        return rib_sink_failed(r, s);
    return 0;
}

/* At WorldEnd: sends the world's atmosphere and the lights on then that
 * were never sent, and ends the world's lights (the next world starts
 * with none, and all links). */
int rib_flush_lights(Rib *r)
{
    if (r->world_atmosphere && send_atmosphere(r) != 0)
        return -1;
    for (size_t k = 0; k < r->n_lights; k++) {
        Light *L = &r->lights[k];
        if (L->index < 0 && light_on(&r->a, k) && send_light(r, L) != 0)
            return -1;
    }
    r->n_lights = 0;
    r->n_area_handles = 0;
    memset(r->a.on, 0, sizeof r->a.on);
    r->real.have_M = 0;
    return 0;
}

int rib_pattern_define(Rib *r, const char *type, const char *name, Param *p, size_t n,
                       ShaderRec *sh)
{
    const IoSink *s = r->sink;
    if ((!sh && !in_list(builtin_patterns, type)) || !s->pattern) {
        char key[128];
        snprintf(key, sizeof key, "pattern %.100s", type);
        rib_warn_once(
            r, key,
            "Pattern \"%s\" is not a class rayes has (of RenderMan's Pxr patterns PxrTexture, "
            "PxrNormalMap, PxrBump, PxrFractal, PxrChecker, PxrMix, PxrExposure, scalar "
            "PxrDispTransform and PxrManifold2D are built); "
            "ignored: colours that reference it take its input's colour or pattern (inputRGB, "
            "inputColor, ...), others keep their defaults",
            type);
        int e = add_stand_in(r, name, p, n);
        free(p);
        return e;
    }
    if (!sh)
        sh = make_shader(r, type, p, n, SHADER_ARRAYS);
    free(p);
    if (!sh)
        return -1;
    type = sh->name;
    if (s->set_transform(s->target, r->a.M) != RAYES_OK ||
        s->pattern(s->target, name, type, sh->params, sh->n) != RAYES_OK)
        return rib_sink_failed(r, s);
    snprintf(sh->pattern, sizeof sh->pattern, "%s", name);
    r->real.have_M = 0;
    return 0;
}

/* ------------------------------------------------------------ atmosphere */

/* The homogeneous medium of RenderMan's standard fog and of Gritz's smoke
 * shaders (docs/rib.md "Atmosphere"): extinction, albedo and emission per
 * unit length into q (count returned). A light's Cl in RSL is pi times
 * the radiance rayes' lights give, and the isotropic phase function 1 / (4
 * pi) of it is scattered: a shader's in-scattering k Cl per unit length is
 * an albedo of 4 k / sigma_t. */
static size_t atmosphere_params(Rib *r, const char *name, const Param *p, size_t n, RayesParam q[3])
{
    double ext[3], alb[3] = {0, 0, 0}, emi[3] = {0, 0, 0};
    if (strcmp(name, "fog") == 0) { /* Ci = mix(background, Ci, exp(-d / distance)) */
        double dist = param_float(p, n, "distance", 1.0), bg[3];
        param_color(p, n, "background", 0.0, bg);
        dist = dist > 1e-30 ? dist : 1e-30;
        for (int c = 0; c < 3; c++)
            ext[c] = 1.0 / dist, emi[c] = bg[c] / dist;
    } else if (strcmp(name, "noisysmoke") == 0 || rib_find_param(p, n, "density") ||
               rib_find_param(p, n, "lightscale")) {
        /* BMRT's noisysmoke (the uberlight figures call it smoke): extinction
         * density scatter, and lightscale Cl density (1 - exp(-density
         * stepsize scatter)) scattered per unit length (its steps' dC = dO
         * lighttau) */
        double noise = param_float(p, n, "use_noise", 1.0) != 0.0 ? 0.5 : 1.0;
        double g = param_float(p, n, "density", 60.0) * noise, s[3];
        double ss = param_float(p, n, "stepsize", 0.1), k = param_float(p, n, "lightscale", 15.0);
        int lit = param_float(p, n, "use_lighting", 1.0) != 0.0;
        param_color(p, n, "scatter", 1.0, s);
        for (int c = 0; c < 3; c++) {
            ext[c] = g * s[c];
            double dO = 1.0 - exp(-g * ss * s[c]), e = k * g * dO; /* per unit length, per Cl */
            if (lit)
                alb[c] = ext[c] > 0.0 ? 4.0 * e / ext[c] : 0.0;
            else
                emi[c] = e;
        }
    } else { /* the Advanced RenderMan's smoke: density 0.5 of opacdensity, lightdensity */
        double od = param_float(p, n, "opacdensity", 1.0);
        double ld = param_float(p, n, "lightdensity", 1.0), s[3];
        param_color(p, n, "scatter", 1.0, s);
        for (int c = 0; c < 3; c++) {
            ext[c] = 0.5 * od * s[c];
            alb[c] = ext[c] > 0.0 ? 4.0 * 0.5 * ld / ext[c] : 0.0;
        }
    }
    if ((strcmp(name, "fog") != 0 && param_float(p, n, "use_noise", 0.0) != 0.0) ||
        param_float(p, n, "smokeoctaves", 0.0) > 0.0)
        rib_warn_once(r, "atmosphere noise",
                      "Atmosphere \"%s\": its noise is not reproduced (the smoke's mean "
                      "density instead)",
                      name);
    q[0] = (RayesParam){.name = "extinction", .type = RAYES_PARAM_COLOR};
    q[1] = (RayesParam){.name = "albedo", .type = RAYES_PARAM_COLOR};
    q[2] = (RayesParam){.name = "emission", .type = RAYES_PARAM_COLOR};
    for (int c = 0; c < 3; c++) {
        q[0].value[c] = (float)fmin(fmax(ext[c], 0.0), 1e30);
        q[1].value[c] = (float)fmin(fmax(alb[c], 0.0), 1e30);
        q[2].value[c] = (float)fmin(fmax(emi[c], 0.0), 1e30);
    }
    return 3;
}

/* Atmosphere "name" params: RenderMan's fog, Gritz's smoke and noisysmoke
 * as a homogeneous medium, rayes' own volume shaders as given; "null" (or
 * "") none; others (depthcue among them) are skipped with one warning. */
static int h_atmosphere(Rib *r, const Args *a)
{
    const char *name;
    Param *p;
    size_t n;
    if (shader_args(r, a, &name, &p, &n) != 0)
        return -1;
    static const char *const own[] = {"homogeneous", "turbulence", NULL};
    static const char *const mapped[] = {"fog", "smoke", "noisysmoke", NULL};
    ShaderRec *sh = NULL;
    if (in_list(own, name)) {
        static const Counts one = {1, 1, 1, 1};
        if (rib_check_counts(r, p, n, &one) != 0) {
            free(p);
            return -1;
        }
        sh = make_shader(r, name, p, n, 0);
    } else if (in_list(mapped, name)) {
        RayesParam q[3];
        sh = rib_shader_rec(r, "homogeneous", q, atmosphere_params(r, name, p, n, q));
    } else {
        if (name[0] && strcmp(name, "null") != 0) {
            char key[128];
            snprintf(key, sizeof key, "atmosphere %.100s", name);
            rib_warn_once(r, key,
                          "atmosphere shader \"%s\" is not built in (fog, smoke, noisysmoke, "
                          "homogeneous, turbulence); no atmosphere",
                          name);
        }
        free(p);
        r->a.atmosphere = NULL;
        return 0;
    }
    free(p);
    if (!sh)
        return -1;
    r->a.atmosphere = sh;
    return 0;
}

/* ------------------------------------------------------------ requests */

const RibRequest rib_shade_requests[] = {
    {"Atmosphere", h_atmosphere},
    {"Surface", h_surface},
    {"Displacement", h_displacement},
    {"LightSource", h_light_source},
    {"AreaLightSource", h_area_light},
    {"Illuminate", h_illuminate},
    {NULL, NULL},
};
