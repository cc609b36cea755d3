/*
 * io/pbrt_options.c — the scene-wide options before WorldBegin
 * (pbrt_internal.h): Camera, Film, Sampler, Integrator and PixelFilter
 * fill the IoSettings and the camera (each fails after WorldBegin; values
 * out of range are errors, unsupported types warnings), ColorSpace warns
 * unless it is srgb, and WorldBegin sends the camera to the sink and
 * starts the world. WorldEnd (pbrt-v3's) does nothing.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "io/text.h"

/* ------------------------------------------------------------ directives */

int pbrt_d_colorspace(Parser *P, const Token *t)
{
    char name[64];
    Token w;
    if (pbrt_expect_string(P, name, sizeof name, "a colour space name", &w) != 0)
        return -1;
    if (strcmp(name, "srgb") != 0)
        pbrt_warn_at(P, w.line, w.col, "colorspace",
                     "ColorSpace \"%.40s\": rayes works in linear sRGB; colours are taken as "
                     "they are", name);
    (void)t;
    return 0;
}

#define PBRT_MAX_LENS_ELEMENTS 256

/* The effective focal length (mm) of a realistic camera's lens file
 * (pbrt's: radius, thickness, index of refraction of the medium after the
 * interface (0: air, the aperture stop), aperture diameter per line, in mm,
 * from the scene to the film), by paraxial ray transfer; -1 with the error
 * set. */
static double lens_focal_length(Parser *P, const Token *t, const char *file)
{
    char path[PBRT_PATH], err[600];
    if (pbrt_resolve(P, t, file, path, sizeof path) != 0)
        return -1;
    size_t size;
    char *text = text_read_file(path, &size, err, sizeof err);
    if (!text) {
        pbrt_fail_at(P, t->line, t->col, "Camera \"realistic\": %s", err);
        return -1;
    }
    double v[4 * PBRT_MAX_LENS_ELEMENTS];
    size_t n = 0;
    int bad = 0;
    for (char *s = text; !bad && *s;) {
        if (*s == '#') {
            while (*s && *s != '\n')
                s++;
        } else if (strchr(" \t\r\n,", *s)) {
            s++;
        } else {
            char *end;
            double x = strtod(s, &end);
            if (end == s || !isfinite(x) || n >= sizeof v / sizeof v[0])
                bad = 1;
            else
                v[n++] = x, s = end;
        }
    }
    free(text);
    /* (height, index times angle) through each interface, then its gap */
    double a = 1, b = 0, c = 0, d = 1, n1 = 1;
    for (size_t i = 0; !bad && i + 3 < n; i += 4) {
        double radius = v[i], gap = v[i + 1], n2 = v[i + 2] > 0 ? v[i + 2] : 1;
        double power = radius != 0 ? (n2 - n1) / radius : 0;
        c -= power * a, d -= power * b;       /* refraction: [1 0; -power 1] */
        a += gap / n2 * c, b += gap / n2 * d; /* the gap: [1 gap/n2; 0 1] */
        n1 = n2;
    }
    double f = c < 0 ? -1 / c : -1;
    if (bad || n == 0 || n % 4 != 0 || !(f > 0) || !isfinite(f)) {
        pbrt_fail_at(P, t->line, t->col,
                     "Camera \"realistic\": %s: expected lines of radius, "
                     "thickness, index and aperture of a focusing lens system",
                     path);
        return -1;
    }
    return f;
}

/* A realistic camera as a thin lens of its lens system's focal length:
 * the image distance at its focus distance into P->lens_image (mm; the
 * field of view follows from the film's diagonal, emit_camera), the
 * aperture (mm, scene units taken as metres, as pbrt scales the lens) as
 * depth of field. */
static int realistic_camera(Parser *P, const Token *t, ParamList *pl)
{
    const char *file = pbrt_get_string(pl, "lensfile", NULL);
    if (!file)
        return FAIL_TOK(P, t, "Camera \"realistic\": expected \"string lensfile\"");
    double f = lens_focal_length(P, t, file);
    double focus = pbrt_get_float(pl, "focusdistance", 10.0);
    double aperture = pbrt_get_float(pl, "aperturediameter", 1.0);
    if (f < 0)
        return -1;
    if (!(focus > 0.001 * f) || !isfinite(focus) || !(aperture >= 0) || !isfinite(aperture))
        return FAIL_TOK(P, t,
                        "Camera \"realistic\": expected focusdistance beyond the lens "
                        "and aperturediameter >= 0");
    double fm = 0.001 * f; /* metres */
    P->lens_image = f * focus / (focus - fm);
    P->lens_radius = (float)(0.0005 * aperture);
    P->focal_distance = (float)focus;
    pbrt_warn_at(P, t->line, t->col, "realistic camera",
                 "Camera \"realistic\": a thin lens of its lens system's focal length (%.1f mm) "
                 "and aperture; the system's distortion and vignetting are not rendered",
                 f);
    return 0;
}

int pbrt_d_camera(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 0);
    if (!r)
        r = pbrt_name_and_params(P, type, sizeof type, "a camera type", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    memcpy(P->camera_from_world, P->gs.ctm, sizeof P->camera_from_world);
    snprintf(P->camera_medium, sizeof P->camera_medium, "%s", P->gs.outside);
    P->camera_line = t->line, P->camera_col = t->col;
    memcpy(P->camera_from_world_end, P->gs.ctm_end, sizeof P->camera_from_world_end);
    double inv[16];
    if (pbrt_mat_inverse(P->gs.ctm, inv) != 0) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Camera: the camera transform is singular");
    }
    r = pbrt_set_coordsys(P, t, "camera", inv);
    P->projection = strcmp(type, "orthographic") == 0 ? RAYES_PROJECTION_ORTHOGRAPHIC
                                                      : RAYES_PROJECTION_PERSPECTIVE;
    int realistic = strcmp(type, "realistic") == 0;
    if (strcmp(type, "perspective") != 0 && strcmp(type, "orthographic") != 0 && !realistic)
        pbrt_warn_at(P, t->line, t->col, "camera type",
                     "Camera \"%.40s\" is not supported; using a perspective camera", type);
    P->fov = (float)pbrt_get_float(&pl, "fov", 90.0);
    if (!(P->fov > 0 && P->fov < 180)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Camera: expected fov between 0 and 180 degrees");
    }
    Param *sw = pbrt_find(&pl, "screenwindow");
    P->have_screen = sw && sw->n_num == 4;
    for (int i = 0; P->have_screen && i < 4; i++)
        P->screen[i] = (float)sw->num[i];
    double open = pbrt_get_float(&pl, "shutteropen", 0.0);
    double close = pbrt_get_float(&pl, "shutterclose", 1.0);
    double lens = pbrt_get_float(&pl, "lensradius", 0.0);
    double focus = pbrt_get_float(&pl, "focaldistance", 1e6);
    if (!isfinite(open) || !isfinite(close) || close <= open) {
        /* pbrt-v4 refuses it too: the image is scaled by the exposure time */
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Camera: expected shutteropen < shutterclose (the shutter must "
                        "open), found %g %g", open, close);
    }
    if (!(lens >= 0) || !isfinite(lens) || !(focus > 0) || !isfinite(focus)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Camera: expected lensradius >= 0 and focaldistance > 0, found %g %g",
                        lens, focus);
    }
    P->shutter[0] = (float)open, P->shutter[1] = (float)close;
    P->lens_radius = (float)lens, P->focal_distance = (float)focus;
    P->lens_image = 0;
    if (realistic && realistic_camera(P, t, &pl) != 0) {
        pbrt_params_free(&pl);
        return -1;
    }
    pbrt_warn_unused(P, &pl, "Camera", type);
    pbrt_params_free(&pl);
    return r;
}

int pbrt_d_film(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (pbrt_need_world(P, t, 0) ||
        pbrt_name_and_params(P, type, sizeof type, "a film type", &pl, NULL)) {
        pbrt_params_free(&pl);
        return -1;
    }
    IoSettings *s = P->settings;
    double w = pbrt_get_float(&pl, "xresolution", 1280),
           h = pbrt_get_float(&pl, "yresolution", 720);
    if (!(w >= 1 && w <= 65536 && h >= 1 && h <= 65536)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected resolutions from 1 to 65536");
    }
    s->width = (int)w, s->height = (int)h;
    double diagonal = pbrt_get_float(&pl, "diagonal", 35.0);
    if (!(diagonal > 0) || !isfinite(diagonal)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected a diagonal > 0 (mm), found %g", diagonal);
    }
    P->film_diagonal = diagonal;
    const char *file = pbrt_get_string(&pl, "filename", NULL);
    if (file) {
        IoDisplay *d = &s->displays[0];
        memset(d, 0, sizeof *d);
        snprintf(d->name, sizeof d->name, "%s", file);
        const char *dot = strrchr(file, '.');
        snprintf(d->type, sizeof d->type, "%s", dot && strcmp(dot, ".exr") == 0   ? "openexr"
                                                : dot && strcmp(dot, ".png") == 0 ? "png"
                                                                                  : "file");
        snprintf(d->mode, sizeof d->mode, "rgba");
        s->n_displays = 1;
    }
    Param *crop = pbrt_find(&pl, "cropwindow");
    if (crop && crop->n_num == 4)
        for (int i = 0; i < 4; i++)
            s->crop[i] = (float)fmin(1.0, fmax(0.0, crop->num[i]));
    /* pbrt-v4's imaging ratio, the exposure time (the camera's shutter)
     * times iso / 100, scales the image (io_pbrt_parse); a sensor's
     * spectral response and white balance are not modelled (warned) */
    double iso = pbrt_get_float(&pl, "iso", 100.0);
    if (!(iso > 0) || !isfinite(iso)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected iso > 0, found %g", iso);
    }
    P->iso = (float)iso;
    /* pbrt-v3's image film: "scale" multiplies the image (as iso / 100
     * does) and "maxsampleluminance" clamps samples */
    double v3_scale = pbrt_get_float(&pl, "scale", 1.0);
    if (!(v3_scale > 0) || !isfinite(v3_scale)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected scale > 0, found %g", v3_scale);
    }
    P->iso *= (float)v3_scale;
    /* pbrt-v4 clamps each sample's largest component to this (infinite by
     * default): rayes's sample clamp */
    double mcv = pbrt_get_float(&pl, "maxcomponentvalue",
                                pbrt_get_float(&pl, "maxsampleluminance", INFINITY));
    if (!(mcv > 0)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected maxcomponentvalue > 0, found %g", mcv);
    }
    if (isfinite(mcv))
        s->sample_clamp = (float)mcv;
    /* pbrt-v4's gbuffer film: an EXR of the colour with the first hit's
     * albedo, depth, normal and position, which rayes's AOVs are (in world
     * space, where pbrt's default is the camera's) */
    int gbuffer = strcmp(type, "gbuffer") == 0 && file && s->n_displays == 1 &&
                  strcmp(s->displays[0].type, "openexr") == 0;
    if (gbuffer) {
        snprintf(s->displays[0].mode, sizeof s->displays[0].mode, "rgba,albedo,z,N,P");
        const char *space = pbrt_get_string(&pl, "coordinatesystem", "camera");
        if (strcmp(space, "world") != 0)
            pbrt_warn_at(P, t->line, t->col, "gbuffer space",
                         "Film \"gbuffer\": N and P are written in world space, not \"%.40s\"",
                         space);
    } else if (strcmp(type, "rgb") != 0 && strcmp(type, "image") != 0) { /* v3's is "image" */
        pbrt_warn_at(P, t->line, t->col, "film type", "Film \"%.40s\": written as an rgb film",
                     type);
    }
    pbrt_warn_unused(P, &pl, "Film", type);
    pbrt_params_free(&pl);
    return 0;
}

int pbrt_d_sampler(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (pbrt_need_world(P, t, 0) ||
        pbrt_name_and_params(P, type, sizeof type, "a sampler type", &pl, NULL)) {
        pbrt_params_free(&pl);
        return -1;
    }
    double spp = pbrt_get_float(&pl, "pixelsamples", 16);
    if (!(spp >= 1 && spp <= 1e6)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Sampler: expected pixelsamples from 1 to 1000000");
    }
    P->settings->spp = (int)spp;
    pbrt_find(&pl, "seed");
    pbrt_find(&pl, "randomization");
    pbrt_warn_unused(P, &pl, "Sampler", type);
    pbrt_params_free(&pl);
    return 0;
}

/* The most diffuse bounces a pbrt maxdepth gives (maxdepth - 1 up to it). */
enum { PBRT_DIFFUSE_BOUNCES = 8 };

int pbrt_d_integrator(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (pbrt_need_world(P, t, 0) ||
        pbrt_name_and_params(P, type, sizeof type, "an integrator type", &pl, NULL)) {
        pbrt_params_free(&pl);
        return -1;
    }
    double depth = pbrt_get_float(&pl, "maxdepth", 5);
    if (!(depth >= 0 && depth <= 1e6)) {
        pbrt_params_free(&pl);
        return FAIL_TOK(P, t, "Integrator: expected maxdepth >= 0");
    }
    /* pbrt's maxdepth 1 is direct light only: rayes' 0 diffuse bounces.
     * Specular paths past the branch depth follow one lobe, so a deep
     * specular depth is cheap. Each diffuse bounce is cached apart and
     * costs about as much as the first, while the light it adds falls as
     * the albedo's power: past PBRT_DIFFUSE_BOUNCES the bounces stop, with
     * one warning (docs/pbrt.md: the Cornell box's figures). */
    int bounces = depth >= 1 ? (int)fmin(depth - 1, 1e6) : 0;
    /* pbrt-v3's directlighting and whitted: direct light and specular
     * paths alone, maxdepth their specular depth */
    if (strcmp(type, "directlighting") == 0 || strcmp(type, "whitted") == 0)
        bounces = 0;
    P->settings->bounces = bounces < PBRT_DIFFUSE_BOUNCES ? bounces : PBRT_DIFFUSE_BOUNCES;
    P->settings->specular_depth = (int)fmin(depth, 64);
    if (bounces > PBRT_DIFFUSE_BOUNCES && !(P->options && P->options->bounces_given))
        pbrt_warn_at(P, t->line, t->col, "maxdepth",
                     "Integrator \"maxdepth\" %g: %d diffuse bounces, not %d (each costs "
                     "about as much as the first and adds less than the one before; "
                     "--bounces N for more), specular depth %d",
                     depth, PBRT_DIFFUSE_BOUNCES, bounces, P->settings->specular_depth);
    if (strcmp(type, "ambientocclusion") == 0 || strcmp(type, "sppm") == 0 ||
        strcmp(type, "mlt") == 0)
        pbrt_warn_at(P, t->line, t->col, "integrator",
                     "Integrator \"%.40s\": rayes renders with its own integrator (radiosity "
                     "cache)", type);
    pbrt_find(&pl, "regularize");
    pbrt_find(&pl, "lightsampler");
    pbrt_find(&pl, "strategy"); /* pbrt-v3 directlighting's: rayes samples every light */
    pbrt_warn_unused(P, &pl, "Integrator", type);
    pbrt_params_free(&pl);
    return 0;
}

int pbrt_d_filter(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (pbrt_need_world(P, t, 0) ||
        pbrt_name_and_params(P, type, sizeof type, "a filter type", &pl, NULL)) {
        pbrt_params_free(&pl);
        return -1;
    }
    /* pbrt-v4's filters and default radii; rayes' width is the diameter. */
    static const struct {
        const char *name;
        double radius;
    } filters[] = {{"box", 0.5}, {"gaussian", 1.5}, {"triangle", 2}, {"mitchell", 2},
                   {"sinc", 4}, {"lanczos", 4}};
    int k = 0, n = (int)(sizeof filters / sizeof filters[0]);
    while (k < n && strcmp(type, filters[k].name) != 0)
        k++;
    if (k < n) {
        /* pbrt-v3 called the radii xwidth and ywidth, and Gaussian's
         * falloff alpha (ignored, as v4's sigma is) */
        double rx =
            pbrt_get_float(&pl, "xradius", pbrt_get_float(&pl, "xwidth", filters[k].radius));
        double ry = pbrt_get_float(&pl, "yradius", pbrt_get_float(&pl, "ywidth", rx));
        pbrt_find(&pl, "sigma");
        pbrt_find(&pl, "alpha");
        double B = pbrt_get_float(&pl, "B", 1.0 / 3), C = pbrt_get_float(&pl, "C", 1.0 / 3);
        double tau = pbrt_get_float(&pl, "tau", 3);
        if (fabs(B - 1.0 / 3) > 1e-3 || fabs(C - 1.0 / 3) > 1e-3 || fabs(tau - 3) > 1e-3)
            pbrt_warn_at(P, t->line, t->col, "filter parameters",
                         "PixelFilter \"%s\": rayes' Mitchell has B = C = 1/3 and its sinc "
                         "tau = 3; other values are not used",
                         filters[k].name);
        P->settings->filter = io_filter_named(filters[k].name, NULL);
        P->settings->filter_width = (float)fmax(0.01, rx + ry);
        pbrt_warn_unused(P, &pl, "PixelFilter", type);
    } else {
        pbrt_warn_at(P, t->line, t->col, "filter",
                     "PixelFilter \"%.40s\" is not supported; using the renderer's default filter",
                     type);
    }
    pbrt_params_free(&pl);
    return 0;
}

/* The shutter, the camera's motion (its transform at the end time) and
 * the lens, after the camera. */
static int emit_time(Parser *P, const Token *t)
{
    const IoSink *s = P->sink;
    int moving = memcmp(P->camera_from_world, P->camera_from_world_end,
                        sizeof P->camera_from_world) != 0;
    if (!s->set_shutter || !s->set_camera_motion || !s->set_depth_of_field) {
        if (moving || P->lens_radius > 0)
            pbrt_warn_at(P, t->line, t->col, "time",
                         "this sink has no motion blur or depth of field: a still pinhole "
                         "camera is used");
        return 0;
    }
    RayesError e = s->set_shutter(s->target, P->shutter[0], P->shutter[1]);
    if (e == RAYES_OK && moving) {
        if (!pbrt_mat_finite(P->camera_from_world_end))
            return FAIL_TOK(P, t, "the camera's end transform is not finite");
        float m[2][16], times[2] = {(float)P->transform_times[0], (float)P->transform_times[1]};
        pbrt_mat_to_float(P->camera_from_world, m[0]);
        pbrt_mat_to_float(P->camera_from_world_end, m[1]);
        e = s->set_camera_motion(s->target, 2, times, (const float(*)[16])m);
    }
    if (e == RAYES_OK && P->lens_radius > 0)
        e = s->set_depth_of_field(s->target, P->lens_radius, P->focal_distance);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

static int emit_camera(Parser *P, const Token *t)
{
    float m[16];
    if (!pbrt_mat_finite(P->camera_from_world))
        return FAIL_TOK(P, t, "the camera transform is not finite");
    pbrt_mat_to_float(P->camera_from_world, m);
    float fov = P->fov;
    if (P->lens_image > 0) { /* a realistic camera: the film's shorter side over the lens */
        double w = P->settings && P->settings->width > 0 ? P->settings->width : 1280,
               h = P->settings && P->settings->height > 0 ? P->settings->height : 720;
        double side = P->film_diagonal * fmin(w, h) / hypot(w, h);
        fov = (float)(2 * atan(0.5 * side / P->lens_image) * 180 / PI);
    }
    RayesError e = P->sink->set_camera_matrix(P->sink->target, m, P->projection, fov,
                                              P->have_screen ? P->screen : NULL);
    if (e != RAYES_OK)
        return pbrt_sink_failed(P, t, e);
    return emit_time(P, t);
}

int pbrt_d_worldbegin(Parser *P, const Token *t)
{
    if (pbrt_need_world(P, t, 0) != 0)
        return -1;
    P->world = 1;
    pbrt_mat_identity(P->gs.ctm);
    pbrt_mat_identity(P->gs.ctm_end);
    if (pbrt_set_coordsys(P, t, "world", P->gs.ctm) != 0)
        return -1;
    if (P->settings->width == 0) {
        P->settings->width = 1280; /* pbrt's default film */
        P->settings->height = 720;
    }
    return emit_camera(P, t);
}

int pbrt_d_worldend(Parser *P, const Token *t)
{
    (void)P, (void)t; /* pbrt-v3's; the file ends the world in v4 */
    return 0;
}
