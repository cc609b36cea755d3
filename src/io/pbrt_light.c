/*
 * io/pbrt_light.c — LightSource and AreaLightSource (pbrt_internal.h).
 * LightSource maps point, spot, distant and infinite lights onto rayes'
 * pointlight, spotlight, distantlight and environmentlight (pbrt's power
 * and illuminance become an intensity) and sends them at once, also
 * inside ObjectBegin. AreaLightSource only sets the graphics state's area
 * light; the shapes that follow emit (pbrt_shape.c). Media are
 * pbrt_medium.c's.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/pbrt_internal.h"

/* ------------------------------------------------------------ directives */

int pbrt_d_arealight(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 1);
    if (!r)
        r = pbrt_name_and_params(P, type, sizeof type, "an area light type", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    memset(&P->gs.area, 0, sizeof P->gs.area);
    if (strcmp(type, "diffuse") != 0) {
        pbrt_warn_at(P, t->line, t->col, "area light type", "AreaLightSource \"%.40s\" is not "
                     "supported; the shapes that follow do not emit", type);
        pbrt_params_free(&pl);
        return 0;
    }
    float L[3];
    if (pbrt_get_emission(P, &pl, "L", L) < 0) {
        pbrt_params_free(&pl);
        return -1;
    }
    double scale = pbrt_get_float(&pl, "scale", 1.0);
    Param *tw = pbrt_find(&pl, "twosided");
    P->gs.area.twosided = tw && tw->n_num > 0 && tw->num[0] != 0;
    (void)pbrt_find(&pl, "nsamples"); /* pbrt-v3's samples a light: rayes' shadow rays */
    (void)pbrt_find(&pl, "samples");
    const char *file = pbrt_get_string(&pl, "filename", NULL);
    if (file && file[0]) { /* the image's colours, as pbrt-v4 (which refuses an L beside it) */
        if (pbrt_resolve(P, t, file, P->gs.area.filename, sizeof P->gs.area.filename) != 0) {
            pbrt_params_free(&pl);
            return -1;
        }
        if (pbrt_find(&pl, "L"))
            pbrt_warn_at(P, t->line, t->col, "area filename L",
                         "AreaLightSource: \"L\" beside "
                         "\"filename\" is ignored (pbrt-v4 refuses both); the image's colours "
                         "emit");
        L[0] = L[1] = L[2] = 1.0f;
    }
    double power = pbrt_get_float(&pl, "power", 0.0);
    P->gs.area.power = power > 0 && isfinite(power) ? power : 0.0;
    for (int c = 0; c < 3; c++)
        P->gs.area.L[c] = P->gs.area.L_base[c] = (float)(L[c] * scale);
    P->gs.area.on = 1;
    pbrt_warn_unused(P, &pl, "AreaLightSource", type);
    pbrt_params_free(&pl);
    return 0;
}

void pbrt_area_power(Parser *P, size_t n_prims, double area)
{
    double k = 1.0;
    if (P->gs.area.power > 0 && area > 0 && isfinite(area))
        k = P->gs.area.power * (double)n_prims / (PI * area * (P->gs.area.twosided ? 2 : 1));
    for (int c = 0; c < 3; c++)
        P->gs.area.L[c] = (float)(P->gs.area.L_base[c] * k);
}

int pbrt_d_light(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 1);
    if (!r)
        r = pbrt_name_and_params(P, type, sizeof type, "a light type", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    double scale = pbrt_get_float(&pl, "scale", 1.0), power = pbrt_get_float(&pl, "power", 0.0);
    (void)pbrt_find(&pl, "nsamples"); /* pbrt-v3's samples a light: rayes' shadow rays */
    float col[3];
    RayesParam lp[8];
    char map_path[4096];
    size_t n = 0;
    const char *rtype = NULL;
    double zero3[3] = {0, 0, 0}, z1[3] = {0, 0, 1};
    if (P->recording)
        pbrt_warn_at(P, t->line, t->col, "instanced light", "LightSource inside ObjectBegin: the "
                     "light is added once, not per instance");
    if (strcmp(type, "point") == 0 || strcmp(type, "spot") == 0) {
        if (pbrt_get_emission(P, &pl, "I", col) < 0)
            r = -1;
        const double *from = pbrt_get_point(&pl, "from");
        from = from ? from : zero3;
        lp[n++] = (RayesParam){.name = "from", .type = RAYES_PARAM_COLOR,
                               .value = {(float)from[0], (float)from[1], (float)from[2]}};
        double k_e = 4 * PI;
        if (type[0] == 's') {
            const double *to = pbrt_get_point(&pl, "to");
            to = to ? to : z1;
            double cone = pbrt_get_float(&pl, "coneangle", 30),
                   delta = pbrt_get_float(&pl, "conedeltaangle", 5);
            lp[n++] = (RayesParam){.name = "to", .type = RAYES_PARAM_COLOR,
                                   .value = {(float)to[0], (float)to[1], (float)to[2]}};
            lp[n++] = (RayesParam){
                .name = "coneangle", .type = RAYES_PARAM_FLOAT, .value = {(float)cone}};
            lp[n++] = (RayesParam){.name = "conedeltaangle", .type = RAYES_PARAM_FLOAT,
                                   .value = {(float)delta}};
            lp[n++] = (RayesParam){.name = "beamdistribution", .type = RAYES_PARAM_FLOAT};
            double c0 = cos(cone * PI / 180), c1 = cos((cone - delta) * PI / 180);
            k_e = 2 * PI * ((1 - c1) + (c1 - c0) / 2);
        }
        if (power > 0) /* as pbrt-v4: an rgb colour's own luminance stays in it */
            scale *= power / k_e;
        rtype = type[0] == 's' ? "spotlight" : "pointlight";
    } else if (strcmp(type, "distant") == 0) {
        if (pbrt_get_emission(P, &pl, "L", col) < 0)
            r = -1;
        const double *from = pbrt_get_point(&pl, "from"), *to = pbrt_get_point(&pl, "to");
        from = from ? from : zero3;
        to = to ? to : z1;
        lp[n++] = (RayesParam){.name = "from", .type = RAYES_PARAM_COLOR,
                               .value = {(float)from[0], (float)from[1], (float)from[2]}};
        lp[n++] = (RayesParam){.name = "to", .type = RAYES_PARAM_COLOR,
                               .value = {(float)to[0], (float)to[1], (float)to[2]}};
        double E = pbrt_get_float(&pl, "illuminance", 0.0);
        if (E > 0)
            scale *= E;
        rtype = "distantlight";
    } else if (strcmp(type, "infinite") == 0) {
        if (pbrt_get_emission(P, &pl, "L", col) < 0)
            r = -1;
        const char *file = pbrt_get_string(&pl, "filename", NULL);
        const char *v3_map = file ? NULL : pbrt_get_string(&pl, "mapname", NULL);
        if ((file || v3_map) && !r) {
            /* pbrt-v4's maps are equal-area octahedral squares; pbrt-v3's
             * ("mapname") latitude-longitude maps with +z up */
            r = pbrt_resolve(P, t, file ? file : v3_map, map_path, sizeof map_path);
            lp[n++] =
                (RayesParam){.name = "mapname", .type = RAYES_PARAM_STRING, .string = map_path};
            lp[n++] = (RayesParam){.name = "mapping",
                                   .type = RAYES_PARAM_STRING,
                                   .string = file ? "octahedral" : "latlong-zup"};
        }
        if (pbrt_get_float(&pl, "illuminance", 0.0) > 0)
            pbrt_warn_at(P, t->line, t->col, "infinite illuminance", "LightSource \"infinite\": "
                         "\"illuminance\" is not supported; using scale");
        if (pbrt_find(&pl, "portal")) /* the same image, drawn with more noise indoors */
            pbrt_warn_at(P, t->line, t->col, "infinite portal",
                         "LightSource \"infinite\": \"portal\" is not used to sample the light; "
                         "the whole environment is sampled (the same image, noisier indoors)");
        rtype = "environmentlight";
    } else if (strcmp(type, "goniometric") == 0 || strcmp(type, "projection") == 0) {
        /* a point light at the light space's origin, its intensity by
         * direction from an image: goniometric, an equal-area octahedral
         * square about the light's y axis (pbrt swaps y and z) times I;
         * projection, an image projected along +z over fov degrees */
        int gonio = type[0] == 'g';
        if (gonio && pbrt_get_emission(P, &pl, "I", col) < 0)
            r = -1;
        if (!gonio)
            col[0] = col[1] = col[2] = 1;
        /* pbrt-v3 names the image "mapname"; its goniometric one is a
         * z-up latitude-longitude map (v4's an octahedral square) */
        const char *file = pbrt_get_string(&pl, "filename", NULL);
        const char *v3_map = file ? NULL : pbrt_get_string(&pl, "mapname", NULL);
        if (!file && !v3_map && !r)
            r = FAIL_TOK(P, t, "LightSource \"%s\": expected \"string filename\"", type);
        if (!r)
            r = pbrt_resolve(P, t, file ? file : v3_map, map_path, sizeof map_path);
        lp[n++] = (RayesParam){.name = "mapname", .type = RAYES_PARAM_STRING, .string = map_path};
        lp[n++] = (RayesParam){.name = "mapping",
                               .type = RAYES_PARAM_STRING,
                               .string = !gonio ? "projection"
                                         : file ? "octahedral"
                                                : "latlong-zup"};
        if (!gonio)
            lp[n++] = (RayesParam){.name = "fov",
                                   .type = RAYES_PARAM_FLOAT,
                                   .value = {(float)pbrt_get_float(&pl, "fov", 90.0)}};
        if (pbrt_find(&pl, "power"))
            pbrt_warn_at(P, t->line, t->col, "map light power",
                         "LightSource \"%s\": \"power\" "
                         "is not supported (it needs the image's mean); using scale",
                         type);
        if (!r) {
            lp[n++] = (RayesParam){
                .name = "intensity", .type = RAYES_PARAM_FLOAT, .value = {(float)scale}};
            lp[n++] = (RayesParam){
                .name = "lightcolor", .type = RAYES_PARAM_COLOR, .value = {col[0], col[1], col[2]}};
            pbrt_warn_unused(P, &pl, "LightSource", type);
            double m[16], swap[16];
            pbrt_mat_identity(swap);
            if (gonio) { /* pbrt's goniometric images have +y up: y and z swapped */
                swap[5] = swap[10] = 0;
                swap[6] = swap[9] = 1;
            }
            pbrt_mat_mul(P->gs.ctm, swap, m);
            r = pbrt_emit_light(P, t, m, "pointlight", lp, n);
        }
        pbrt_params_free(&pl);
        return r;
    } else {
        char key[96];
        snprintf(key, sizeof key, "light %.60s", type);
        pbrt_warn_at(P, t->line, t->col, key, "LightSource \"%.40s\" is not supported; skipped",
                     type);
        pbrt_params_free(&pl);
        return 0;
    }
    if (!r) {
        lp[n++] =
            (RayesParam){.name = "intensity", .type = RAYES_PARAM_FLOAT, .value = {(float)scale}};
        lp[n++] = (RayesParam){.name = "lightcolor", .type = RAYES_PARAM_COLOR,
                               .value = {col[0], col[1], col[2]}};
        pbrt_warn_unused(P, &pl, "LightSource", type);
        double m[16];
        memcpy(m, P->gs.ctm, sizeof m);
        if (strcmp(rtype, "distantlight") == 0 || strcmp(rtype, "environmentlight") == 0) {
            /* pbrt turns only directions by these lights' transform: a
             * perspective row is dropped (sssdragon's sky has one) */
            m[12] = m[13] = m[14] = 0.0;
            m[15] = 1.0;
        }
        r = pbrt_emit_light(P, t, m, rtype, lp, n);
    }
    pbrt_params_free(&pl);
    return r;
}
