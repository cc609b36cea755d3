/*
 * app/cli.c — what the commands of the rayes program (main.c) and the
 * viewer (view.c) share: the usage text, parsing the command line into
 * Args, usage errors (status 2), loading the scene a command names, and
 * merging a scene file's settings under the command line's.
 */
#include "app/cli.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/builtin.h"
#include "io/scene_file.h"

static const char scene_text[] =
    "SCENE is a scene file (.rib, .rib.gz, .pbrt, .obj) or a built-in scene:\n"
    "cornell (default), cornell-teapots, cornell-teapots-displaced, cornell-spheres,\n"
    "cornell-brick (needs the plugin brick.so: --shader-path build/examples/shaders),\n"
    "cornell-teapots-motion (motion blur and depth of field).\n"
    "A scene file's image size, samples, filter, depths and displays are used unless\n"
    "the command line gives them.\n";

static const char render_options[] =
    "options:\n"
    "  -o FILE                 output image, .exr or .png (repeatable; default: the\n"
    "                          scene file's displays, else SCENE.exr)\n"
    "  --frame N               the frame of a RIB file to read (default: the last)\n"
    "  --frames LIST           render these frames one after another: 1-100x2, 1,5,9-12;\n"
    "                          '#'s in -o names become the frame number (out.####.exr)\n"
    "  --skip-existing         skip a frame whose outputs all exist (a farm's retry)\n"
    "  --progress json|bar     json: one JSON object per line on standard output (progress,\n"
    "                          each frame's end) for farm managers; bar (default)\n"
    "  --checkpoint SECONDS    save the finished tiles to OUTPUT.checkpoint this often\n"
    "                          (0: after every tile) and when interrupted\n"
    "  --resume                render only the tiles OUTPUT.checkpoint lacks; the image is\n"
    "                          the same bytes as an uninterrupted render's\n"
    "  --res W[xH]             resolution in pixels (default 512x512); W alone keeps a\n"
    "                          scene file's aspect ratio (else square)\n"
    "  --spp N                 pixel samples (default 4)\n"
    "  --max-spp N             adaptive sampling: a noisy pixel takes further blocks of\n"
    "                          --spp samples, up to N (default 0: off)\n"
    "  --adaptive-error E      until its mean's relative standard error is E (default\n"
    "                          0.02)\n"
    "  --clamp V               scale each camera sample down so no component exceeds V\n"
    "                          (fewer fireflies, biased darker; default 0: off)\n"
    "  --png-curve srgb|linear PNG colour: the sRGB curve, or values as they are\n"
    "                          (RenderMan's 8-bit files; default: RIB files before\n"
    "                          RenderMan 19 linear, others sRGB)\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  --bounces N             maximum diffuse depth (default 1)\n"
    "  --quality Q             preview (4 shadow, 4 diffuse rays), final (64; 1024 at\n"
    "                          depth 0, 64 deeper), reference (16 and 256 at depth 0,\n"
    "                          1 and 1 deeper, 64 pixel samples, nothing cached);\n"
    "                          later options override it\n"
    "  --shadow-rays N         shadow rays per shading point and light\n"
    "  --subsurface-rays N     subsurface rays per shading point of a subsurface material\n"
    "                          (default 4 preview, 64 final)\n"
    "  --irradiance-shadow-rays N  shadow rays per light at irradiance cache fills\n"
    "                          (default: --shadow-rays, at most 16)\n"
    "  --diffuse-rays N        diffuse rays per shading point (all depths; a glossy lobe\n"
    "                          takes its share, 4 alpha^2 of them, at least 16)\n"
    "  --diffuse-rays-deep N   diffuse rays per shading point below depth 0\n"
    "  --specular-depth N      maximum specular depth (default 4)\n"
    "  --branch-depth N        points shallower than N (diffuse + specular depth) trace\n"
    "                          reflection and refraction both and several glossy rays;\n"
    "                          deeper ones follow one lobe (default 1: camera hits)\n"
    "  --filter F              pixel filter: box (default), gaussian, triangle,\n"
    "                          catmull-rom, mitchell or lanczos\n"
    "  --filter-width W        filter width in pixels (default 1 box, 2 gaussian and\n"
    "                          triangle, 4 catmull-rom and mitchell, 6 lanczos)\n"
    "  --seed N                changes every random number (default 0)\n"
    "  --cache on|off          the radiosity cache at diffuse hits (default on; off for\n"
    "                          --quality reference)\n"
    "  --cache-mb MB           cache budget in megabytes (default 100; 0: --cache off)\n"
    "  --cache-split C,M,F     budget shares of coarse, medium, fine (default .25,.25,.5);\n"
    "                          each lends the others what it leaves unused\n"
    "  --irradiance-cache on|off  cache the irradiance subsurface rays find (default on)\n"
    "  --irradiance-cache-mb MB   the irradiance entries' budget in megabytes (default 20)\n"
    "  --env-guide on|off      draw an environment light's samples where each grid sees it\n"
    "                          (default on; off in --quality reference)\n"
    "  --opacity-cache on|off  cache opacity() results for shadow and transmission rays\n"
    "                          (default on)\n"
    "  --opacity-cache-mb MB   the opacity entries' budget in megabytes (default 20)\n"
    "  --volume-step S         volumes are marched in steps of S fine voxels (default 1)\n"
    "  --crop X0,X1,Y0,Y1      render only this window of the image (RenderMan's CropWindow,\n"
    "                          0 to 1, y down): the same pixels as the whole frame's; PNG\n"
    "                          holds the window, EXR it as the data window of the frame\n"
    "  --cache-resolution R    auto (by ray differentials), coarse, medium or fine\n"
    "  --cache-k K             use the coarsest resolution whose micropolygons are at\n"
    "                          most K times the ray footprint (default 1)\n"
    "  --cache-fine-depth N    hits of diffuse depth above N read the medium resolution\n"
    "                          at finest (default 1; 128: by differentials alone)\n"
    "  --gridsize N            micropolygons per grid, at most (default 256, or the\n"
    "                          scene file's; 1 to 4096): the size of a cache entry\n"
    "  --dice-offscreen F      micropolygons off screen up to F times longer (default 4;\n"
    "                          1 to 1000; 1 dices them as if on screen)\n"
    "  --dice-isotropic        dice on-screen patches by distance, as finely along the\n"
    "                          view as across it (RenderMan's rasterorient 0)\n"
    "  --vertex-budget M       grid vertices of the scene, at most, in millions (default\n"
    "                          20; 0: none): a scene needing more is diced coarser\n"
    "  --hider raytrace|grid   shade every camera hit (default), or once per vertex of\n"
    "                          each visible grid and interpolate (PRMan's REYES mode;\n"
    "                          default for --quality final)\n"
    "  --irradiance on|off     irradiance interpolation with gradients at depth 0 (grid\n"
    "                          hider; on for --quality final)\n"
    "  --gi raytrace|pointbased  indirect diffuse by diffuse rays and the radiosity cache\n"
    "                          (default), or point-based GI from a point cloud of disks\n"
    "  --pbgi-solid-angle SR   point-based GI: octree nodes under SR steradians gather as\n"
    "                          one cluster (default 0.05)\n"
    "  --pbgi-raster N         point-based GI: cube raster of N x N pixels a face (default\n"
    "                          8; even, 2 to 64)\n"
    "  --pointcloud-out FILE.ply  point-based GI: write the point cloud (binary PLY)\n"
    "  --texture-mb MB         texture cache budget in megabytes (default 64)\n"
    "  --data DIR              data directory (teapot.bpt); default $RAYES_DATA, else\n"
    "                          ../shared/data beside the checkout that built rayes\n"
    "  --shader-path DIRS      directories of shader plugins NAME.so, ':'-separated;\n"
    "                          searched before $RAYES_SHADER_PATH\n"
    "  --default-light         a headlight (a distant light along the view) when the\n"
    "                          scene has no lights\n"
    "  --look-from X,Y,Z       the camera's eye, world space (replaces the scene's\n"
    "                          camera: perspective; OBJ files have none of their own)\n"
    "  --look-at X,Y,Z         the point it looks at (default: along the scene's view)\n"
    "  --up X,Y,Z              its up direction (default 0,1,0)\n"
    "  --fov DEG               its vertical field of view (default 40)\n"
    "  --stats FILE.json       write statistics as JSON\n"
    "  --aov LIST              arbitrary output variables written as float channels beside\n"
    "                          the colour of EXR outputs, a comma-separated list of z (Z:\n"
    "                          depth), N (world normal), P (world position), id (object),\n"
    "                          patch (the grid, the radiosity cache's entry), cache (the\n"
    "                          resolution diffuse rays read: 0 coarse to 2 fine), albedo\n"
    "                          (the colour surfaces reflect, for denoisers), all\n"
    "  --replay-rays           keep the render's rays and trace them again unshaded: the\n"
    "                          summary and the statistics' replay block say what ray\n"
    "                          casting alone costs (48 bytes a ray while rendering)\n"
    "  --quiet                 no progress bar and no summary\n";

/* --aov's list: names of RayesAov, comma-separated. */
unsigned aov_named(const char *name, size_t n)
{
    static const struct {
        const char *name;
        unsigned aov;
    } names[] = {
        {"z", RAYES_AOV_Z},           {"Z", RAYES_AOV_Z},         {"zfiltered", RAYES_AOV_Z},
        {"N", RAYES_AOV_N},           {"normal", RAYES_AOV_N},    {"P", RAYES_AOV_P},
        {"id", RAYES_AOV_ID},         {"patch", RAYES_AOV_PATCH}, {"cache", RAYES_AOV_CACHE},
        {"albedo", RAYES_AOV_ALBEDO}, {"all", RAYES_AOV_ALL}};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
        if (strlen(names[k].name) == n && strncmp(names[k].name, name, n) == 0)
            return names[k].aov;
    return 0;
}

static unsigned parse_aovs(const char *v)
{
    unsigned aovs = 0;
    for (const char *s = v; *s;) {
        size_t n = strcspn(s, ",");
        unsigned aov = aov_named(s, n);
        if (!aov)
            die_usage("--aov: expected z, N, P, id, patch, cache, albedo or all (comma-separated), "
                      "found "
                      "\"%.*s\"",
                      (int)n, s);
        aovs |= aov;
        s += n + (s[n] == ',');
    }
    if (!aovs)
        die_usage("--aov: expected z, N, P, id, patch, cache, albedo or all");
    return aovs;
}

static const char view_options[] =
    "view options (and every option above; docs/view.md):\n"
    "  --passes N              window: refine to N samples per pixel after each edit\n"
    "                          (default 256); headless: render N passes in all\n"
    "  --exposure E            display: colour times 2^E (default 0)\n"
    "  --gamma G               display: colour to the power 1/G (default 1)\n"
    "  --script FILE|-         edit commands, one per line after a pass number\n"
    "  --headless              no window: render the passes and run the script\n"
    "  --screenshot FILE.png   the window's pixels after --passes passes\n";

static const char convert_text[] =
    "usage: rayes convert SCENE OUT.rib [--data DIR] [--frame N] [--quiet]\n"
    "\n"
    "Writes SCENE (a scene file or a built-in scene, as rayes render reads it) as\n"
    "ASCII RIB (docs/convert.md says what is kept).\n"
    "\n"
    "options:\n"
    "  --data DIR              data directory (teapot.bpt); default $RAYES_DATA, else\n"
    "                          ../shared/data beside the checkout that built rayes\n"
    "  --frame N               the frame of a RIB file to read (default: the last)\n"
    "  --quiet                 no \"wrote OUT.rib\" line\n";

static const char assemble_text[] =
    "usage: rayes assemble OUT.exr PART.exr...\n"
    "\n"
    "Puts the crops of one frame (renders with --crop, written as EXR: each file's\n"
    "data window is its crop) together into OUT.exr. Crops that tile the frame give\n"
    "the bytes of the whole frame's render.\n";

void print_usage(FILE *f)
{
    fputs("usage: rayes render [SCENE] [options]\n"
          "       rayes view [SCENE] [options] [view options]\n"
          "       rayes convert SCENE OUT.rib [--data DIR] [--frame N] [--quiet]\n"
          "       rayes assemble OUT.exr PART.exr...\n"
          "       rayes --help | --version\n"
          "       rayes COMMAND --help\n"
          "\n",
          f);
    fputs(scene_text, f);
    fputs("convert writes SCENE as ASCII RIB.\n\n", f);
    fputs(render_options, f);
    fputc('\n', f);
    fputs(view_options, f);
}

void print_command_usage(const char *command, FILE *f)
{
    if (strcmp(command, "convert") == 0) {
        fputs(convert_text, f);
        return;
    }
    if (strcmp(command, "assemble") == 0) {
        fputs(assemble_text, f);
        return;
    }
    int view = strcmp(command, "view") == 0;
    fputs(view ? "usage: rayes view [SCENE] [options] [view options]\n\n"
               : "usage: rayes render [SCENE] [options]\n\n",
          f);
    fputs(scene_text, f);
    fputc('\n', f);
    fputs(render_options, f);
    if (view) {
        fputc('\n', f);
        fputs(view_options, f);
    }
}

void die_usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("rayes: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputs(" (rayes --help shows the usage)\n", stderr);
    va_end(ap);
    exit(2);
}

long parse_long(const char *opt, const char *s, long lo, long hi)
{
    char *end;
    errno = 0;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || *s == '\0' || *end != '\0' || errno != 0 || v < lo || v > hi)
        die_usage("%s: expected an integer from %ld to %ld, got \"%s\"", opt, lo, hi,
                  s ? s : "nothing");
    return v;
}

static float parse_float(const char *opt, const char *s, float lo, float hi)
{
    char *end;
    errno = 0;
    float v = s ? strtof(s, &end) : 0.0f;
    if (!s || *s == '\0' || *end != '\0' || errno != 0 || !(v >= lo && v <= hi))
        die_usage("%s: expected a number from %g to %g, got \"%s\"", opt, lo, hi,
                  s ? s : "nothing");
    return v;
}

/* --look-from, --look-at, --up: "X,Y,Z", each finite. */
static void parse_point(const char *opt, const char *s, float out[3])
{
    char buf[256], *save = NULL;
    snprintf(buf, sizeof buf, "%s", s ? s : "");
    for (int i = 0; i < 3; i++) {
        char *tok = strtok_r(i == 0 ? buf : NULL, ",", &save);
        if (!tok)
            die_usage("%s: expected X,Y,Z, got \"%s\"", opt, s ? s : "nothing");
        out[i] = parse_float(opt, tok, -1e30f, 1e30f);
    }
    if (strtok_r(NULL, ",", &save))
        die_usage("%s: expected X,Y,Z, got \"%s\"", opt, s);
}

/* --res W or WxH; returns 1 for W alone (a square, unless the scene file
 * gives an aspect ratio: merge_settings). */
static int parse_res(const char *s, RayesRenderOptions *o)
{
    char w[32];
    const char *x = s ? strchr(s, 'x') : NULL;
    if (s && x && (size_t)(x - s) < sizeof w) {
        snprintf(w, sizeof w, "%.*s", (int)(x - s), s);
        o->width = (int)parse_long("--res", w, 1, 65536);
        o->height = (int)parse_long("--res", x + 1, 1, 65536);
        return 0;
    }
    o->width = o->height = (int)parse_long("--res", s, 1, 65536);
    return 1;
}

static void parse_split(const char *s, float split[3])
{
    char buf[128], *save = NULL;
    snprintf(buf, sizeof buf, "%s", s);
    float sum = 0.0f;
    for (int i = 0; i < 3; i++) {
        char *tok = strtok_r(i == 0 ? buf : NULL, ",", &save);
        split[i] = parse_float("--cache-split", tok, 0.0f, 1.0f);
        sum += split[i];
    }
    if (strtok_r(NULL, ",", &save) || sum > 1.0001f)
        die_usage("--cache-split: expected three shares C,M,F summing to at most 1, got \"%s\"",
                  s);
}

/* --crop xmin,xmax,ymin,ymax in [0, 1] (RenderMan's CropWindow). */
static void parse_crop(const char *s, float crop[4])
{
    char buf[128], *save = NULL;
    snprintf(buf, sizeof buf, "%s", s);
    for (int i = 0; i < 4; i++) {
        char *tok = strtok_r(i == 0 ? buf : NULL, ",", &save);
        crop[i] = parse_float("--crop", tok, 0.0f, 1.0f);
    }
    if (strtok_r(NULL, ",", &save) || !(crop[0] < crop[1]) || !(crop[2] < crop[3]))
        die_usage("--crop: expected xmin,xmax,ymin,ymax in [0, 1] with xmin < xmax and ymin < "
                  "ymax, got \"%s\"",
                  s);
}

static int parse_resolution(const char *s)
{
    static const char *const names[] = {"coarse", "medium", "fine"};
    if (strcmp(s, "auto") == 0)
        return -1;
    for (int i = 0; i < 3; i++)
        if (strcmp(s, names[i]) == 0)
            return i;
    die_usage("--cache-resolution: expected auto, coarse, medium or fine, got \"%s\"", s);
}

static RayesQuality parse_quality(const char *s)
{
    if (s && strcmp(s, "preview") == 0)
        return RAYES_QUALITY_PREVIEW;
    if (s && strcmp(s, "final") == 0)
        return RAYES_QUALITY_FINAL;
    if (s && strcmp(s, "reference") == 0)
        return RAYES_QUALITY_REFERENCE;
    die_usage("--quality: expected preview, final or reference, got \"%s\"", s ? s : "nothing");
}

/* The preset first (it sets ray counts), then every other option in order. */
void parse_args(int argc, char **argv, Args *a)
{
    RayesQuality q = RAYES_QUALITY_PREVIEW;
    for (int i = 2; i < argc; i++)
        if (strcmp(argv[i], "--quality") == 0)
            q = parse_quality(i + 1 < argc ? argv[i + 1] : NULL);
    rayes_render_options_init(&a->opt, q);
    a->frame = -1;
    a->checkpoint_s = -1.0;
    a->gamma = 1.0f;
    for (int i = 2; i < argc; i++) {
        const char *o = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        RayesRenderOptions *opt = &a->opt;
        if (o[0] != '-') {
            if (a->scene)
                die_usage("only one scene may be given (\"%s\" and \"%s\")", a->scene, o);
            a->scene = o;
            continue;
        }
        if (strcmp(o, "--quiet") == 0) {
            a->quiet = 1;
            continue;
        }
        if (strcmp(o, "--skip-existing") == 0) {
            a->skip_existing = 1;
            continue;
        }
        if (strcmp(o, "--resume") == 0) {
            a->resume = 1;
            continue;
        }
        if (strcmp(o, "--dice-isotropic") == 0) {
            opt->dice_isotropic = 1;
            continue;
        }
        if (strcmp(o, "--default-light") == 0) {
            a->default_light = 1;
            continue;
        }
        if (strcmp(o, "--replay-rays") == 0) {
            opt->replay_rays = 1;
            continue;
        }
        if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0) {
            print_command_usage(a->view ? "view" : "render", stdout);
            exit(0);
        }
        if (strcmp(o, "--headless") == 0 && a->view) {
            a->headless = 1;
            continue;
        }
        if (!v)
            die_usage("%s: expected a value", o);
        i++;
        if (strcmp(o, "-o") == 0) {
            if (a->n_outputs == MAX_OUTPUTS)
                die_usage("-o: at most %d outputs", MAX_OUTPUTS);
            Output *out = &a->outputs[a->n_outputs++];
            out->format = image_format_from_path(v);
            if (out->format == IMAGE_FORMAT_UNKNOWN)
                die_usage("-o %s: expected a file name ending in .exr or .png", v);
            if (strlen(v) >= sizeof out->path)
                die_usage("-o: the file name is too long");
            snprintf(out->path, sizeof out->path, "%s", v);
        } else if (strcmp(o, "--res") == 0) {
            a->set = (a->set & ~(unsigned)SET_RES_WIDTH) | SET_RES |
                     (parse_res(v, opt) ? SET_RES_WIDTH : 0);
        } else if (strcmp(o, "--spp") == 0) {
            opt->spp = (int)parse_long(o, v, 1, 1 << 20);
            a->set |= SET_SPP;
        } else if (strcmp(o, "--max-spp") == 0) {
            opt->max_spp = (int)parse_long(o, v, 0, 1 << 20);
            a->set |= SET_MAX_SPP;
        } else if (strcmp(o, "--adaptive-error") == 0) {
            opt->adaptive_error = parse_float(o, v, 1e-6f, 1e6f);
            a->set |= SET_ADAPTIVE_ERROR;
        } else if (strcmp(o, "--png-curve") == 0) {
            if (strcmp(v, "srgb") != 0 && strcmp(v, "linear") != 0)
                die_usage("--png-curve: expected srgb or linear, found \"%s\"", v);
            a->png_curve = v[0] == 's' ? IO_CURVE_SRGB : IO_CURVE_LINEAR;
        } else if (strcmp(o, "--look-from") == 0) {
            parse_point(o, v, a->look_from);
            a->camera |= CAMERA_FROM;
        } else if (strcmp(o, "--look-at") == 0) {
            parse_point(o, v, a->look_at);
            a->camera |= CAMERA_AT;
        } else if (strcmp(o, "--up") == 0) {
            parse_point(o, v, a->up);
            a->camera |= CAMERA_UP;
        } else if (strcmp(o, "--fov") == 0) {
            a->fov = parse_float(o, v, 0.01f, 179.0f);
            a->camera |= CAMERA_FOV;
        } else if (strcmp(o, "--clamp") == 0) {
            opt->sample_clamp = parse_float(o, v, 0.0f, 1e30f);
            a->set |= SET_CLAMP;
        } else if (strcmp(o, "--frame") == 0)
            a->frame = (int)parse_long(o, v, 0, INT_MAX);
        else if (strcmp(o, "--frames") == 0)
            a->frames = v;
        else if (strcmp(o, "--checkpoint") == 0)
            a->checkpoint_s = parse_float(o, v, 0.0f, 1e7f);
        else if (strcmp(o, "--aov") == 0)
            opt->aovs |= parse_aovs(v);
        else if (strcmp(o, "--progress") == 0) {
            if (strcmp(v, "json") != 0 && strcmp(v, "bar") != 0)
                die_usage("--progress: expected json or bar, got \"%s\"", v);
            a->progress_json = strcmp(v, "json") == 0;
        }
        else if (strcmp(o, "--threads") == 0)
            opt->threads = (int)parse_long(o, v, 0, 1024);
        else if (strcmp(o, "--bounces") == 0) {
            opt->bounces = (int)parse_long(o, v, 0, 64);
            a->set |= SET_BOUNCES;
        }
        else if (strcmp(o, "--quality") == 0)
            continue;
        else if (strcmp(o, "--shadow-rays") == 0)
            opt->shadow_rays = opt->shadow_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--subsurface-rays") == 0)
            opt->subsurface_rays = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--irradiance-shadow-rays") == 0)
            opt->irradiance_shadow_rays = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays") == 0)
            opt->diffuse_rays = opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--diffuse-rays-deep") == 0)
            opt->diffuse_rays_deep = (int)parse_long(o, v, 0, 1 << 20);
        else if (strcmp(o, "--specular-depth") == 0) {
            opt->specular_depth = (int)parse_long(o, v, 0, 64);
            a->set |= SET_SPECULAR_DEPTH;
        } else if (strcmp(o, "--branch-depth") == 0) {
            opt->branch_depth = (int)parse_long(o, v, 1, 129);
        } else if (strcmp(o, "--filter") == 0) {
            a->set |= SET_FILTER;
            int k = io_filter_named(v, NULL);
            if (k < 0)
                die_usage("--filter: expected box, gaussian, triangle, catmull-rom, mitchell or "
                          "lanczos, got \"%s\"", v);
            opt->filter = (RayesFilter)k;
        } else if (strcmp(o, "--filter-width") == 0) {
            opt->filter_width = parse_float(o, v, 0.01f, 16.0f);
            a->set |= SET_FILTER_WIDTH;
        } else if (strcmp(o, "--seed") == 0)
            opt->seed = (uint64_t)parse_long(o, v, 0, LONG_MAX);
        else if (strcmp(o, "--cache") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--cache: expected on or off, got \"%s\"", v);
            opt->cache = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--cache-mb") == 0)
            opt->cache_mb = parse_float(o, v, 0.0f, 1e7f);
        else if (strcmp(o, "--irradiance-cache") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--irradiance-cache: expected on or off, got \"%s\"", v);
            opt->irradiance_cache = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--irradiance-cache-mb") == 0)
            opt->irradiance_cache_mb = parse_float(o, v, 0.0f, 1e7f);
        else if (strcmp(o, "--env-guide") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--env-guide: expected on or off, got \"%s\"", v);
            opt->env_guide = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--opacity-cache") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--opacity-cache: expected on or off, got \"%s\"", v);
            opt->opacity_cache = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--opacity-cache-mb") == 0) {
            opt->opacity_cache_mb = parse_float(o, v, 0.0f, 1e7f);
            a->set |= SET_OPACITY_CACHE_MB;
        } else if (strcmp(o, "--volume-step") == 0)
            opt->volume_step = parse_float(o, v, 0.01f, 1000.0f);
        else if (strcmp(o, "--cache-split") == 0)
            parse_split(v, opt->cache_split);
        else if (strcmp(o, "--crop") == 0) {
            parse_crop(v, opt->crop);
            a->set |= SET_CROP;
        }
        else if (strcmp(o, "--cache-resolution") == 0)
            opt->cache_resolution = parse_resolution(v);
        else if (strcmp(o, "--cache-k") == 0)
            opt->cache_k = parse_float(o, v, 1e-3f, 1e3f);
        else if (strcmp(o, "--cache-fine-depth") == 0)
            opt->cache_fine_depth = (int)parse_long(o, v, 0, 128);
        else if (strcmp(o, "--gridsize") == 0) {
            opt->grid_size = (int)parse_long(o, v, 1, 4096);
            a->set |= SET_GRID_SIZE;
        } else if (strcmp(o, "--dice-offscreen") == 0)
            opt->dice_offscreen = parse_float(o, v, 1.0f, 1000.0f);
        else if (strcmp(o, "--vertex-budget") == 0)
            opt->vertex_budget = 1e6 * parse_float(o, v, 0.0f, 1e6f);
        else if (strcmp(o, "--hider") == 0) {
            if (strcmp(v, "raytrace") != 0 && strcmp(v, "grid") != 0)
                die_usage("--hider: expected raytrace or grid, got \"%s\"", v);
            opt->hider = strcmp(v, "grid") == 0 ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
        } else if (strcmp(o, "--irradiance") == 0) {
            if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0)
                die_usage("--irradiance: expected on or off, got \"%s\"", v);
            opt->irradiance = strcmp(v, "on") == 0;
        } else if (strcmp(o, "--gi") == 0) {
            if (strcmp(v, "raytrace") != 0 && strcmp(v, "pointbased") != 0)
                die_usage("--gi: expected raytrace or pointbased, got \"%s\"", v);
            opt->gi = strcmp(v, "pointbased") == 0 ? RAYES_GI_POINTBASED : RAYES_GI_RAYTRACE;
        } else if (strcmp(o, "--pbgi-solid-angle") == 0)
            opt->pbgi_max_solid_angle = parse_float(o, v, 1e-6f, 12.57f);
        else if (strcmp(o, "--pbgi-raster") == 0) {
            opt->pbgi_raster = (int)parse_long(o, v, 2, 64);
            if (opt->pbgi_raster % 2)
                die_usage("--pbgi-raster: expected an even number, got \"%s\"", v);
        } else if (strcmp(o, "--pointcloud-out") == 0)
            opt->pointcloud_out = v;
        else if (strcmp(o, "--texture-mb") == 0) {
            opt->texture_mb = parse_float(o, v, 0.0f, 1e7f);
            a->set |= SET_TEXTURE_MB;
        } else if (strcmp(o, "--data") == 0)
            a->data_dir = v;
        else if (strcmp(o, "--stats") == 0)
            a->stats_path = v;
        else if (strcmp(o, "--shader-path") == 0)
            a->shader_path = v;
        else if (a->view && strcmp(o, "--script") == 0)
            a->script = v;
        else if (a->view && strcmp(o, "--passes") == 0)
            a->passes = (int)parse_long(o, v, 0, 1 << 20);
        else if (a->view && strcmp(o, "--screenshot") == 0)
            a->screenshot = v;
        else if (a->view && strcmp(o, "--exposure") == 0)
            a->exposure = parse_float(o, v, -30.0f, 30.0f);
        else if (a->view && strcmp(o, "--gamma") == 0)
            a->gamma = parse_float(o, v, 0.05f, 20.0f);
        else
            die_usage("unknown option \"%s\"", o);
    }
    if (!(a->set & SET_FILTER_WIDTH))
        io_filter_named(io_filter_name(a->opt.filter), &a->opt.filter_width);
    if (!a->scene)
        a->scene = "cornell";
    if (!a->data_dir)
        a->data_dir = default_data_dir();
}

const char *default_data_dir(void)
{
    const char *env = getenv("RAYES_DATA");
    if (env)
        return env;
    static char dir[PATH_MAX + 32];
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return NULL;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash)
        return NULL;
    *slash = '\0'; /* CHECKOUT/build: the data is CHECKOUT/../shared/data */
    char probe[PATH_MAX + 64];
    snprintf(dir, sizeof dir, "%s/../../shared/data", exe);
    snprintf(probe, sizeof probe, "%s/teapot.bpt", dir);
    return access(probe, R_OK) == 0 ? dir : NULL;
}

/* Builds the scene `scene` names (a scene file, else a built-in scene)
 * into sink; settings receive what a file gives. */
RayesError load_scene(const char *scene, const IoReadOptions *ro, const IoSink *sink,
                      IoSettings *settings, char *err, size_t err_size)
{
    io_settings_init(settings);
    if (io_is_scene_file(scene))
        return io_read_scene_file(scene, sink, ro, settings, err, err_size);
    return io_builtin_scene(scene, ro->data_dir, sink, err, err_size);
}

/* The exit status of a failed load: an unknown built-in name is a usage
 * error, everything else bad input. */
int load_status(const char *scene, RayesError e)
{
    return !io_is_scene_file(scene) && e == RAYES_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

/* The file's settings where the command line gave none. */
void merge_settings(Args *a, const IoSettings *s)
{
    RayesRenderOptions *o = &a->opt;
    if (!(a->set & SET_RES) && s->width > 0 && s->height > 0) {
        o->width = s->width;
        o->height = s->height;
    } else if ((a->set & SET_RES_WIDTH) && s->width > 0 && s->height > 0) {
        /* a width alone keeps the file's framing: a 1280 x 720 file at --res 640 is 640 x 360 */
        double h = (double)o->width * s->height / s->width;
        o->height = h < 1.0 ? 1 : h > 65536.0 ? 65536 : (int)(h + 0.5);
    }
    if (!(a->set & SET_SPP) && s->spp > 0)
        o->spp = s->spp;
    if (!(a->set & (SET_MAX_SPP | SET_SPP)) && s->max_spp > 0)
        o->max_spp = s->max_spp; /* --spp alone: the samples asked, none added */
    if (!(a->set & SET_ADAPTIVE_ERROR) && s->adaptive_error > 0.0f)
        o->adaptive_error = s->adaptive_error;
    if (!(a->set & SET_CLAMP) && s->sample_clamp > 0.0f)
        o->sample_clamp = s->sample_clamp;
    if (!(a->set & SET_FILTER) && s->filter >= RAYES_FILTER_BOX && s->filter <= RAYES_FILTER_LANCZOS) {
        o->filter = (RayesFilter)s->filter;
        if (!(a->set & SET_FILTER_WIDTH))
            io_filter_named(io_filter_name(o->filter), &o->filter_width);
    }
    if (!(a->set & SET_FILTER_WIDTH) && s->filter_width > 0.0f)
        o->filter_width = s->filter_width;
    if (!(a->set & SET_BOUNCES) && s->bounces >= 0)
        o->bounces = s->bounces < 64 ? s->bounces : 64;
    if (!(a->set & SET_SPECULAR_DEPTH) && s->specular_depth >= 0)
        o->specular_depth = s->specular_depth < 64 ? s->specular_depth : 64;
    if (!(a->set & SET_GRID_SIZE) && s->grid_size > 0)
        o->grid_size = s->grid_size;
    if (!(a->set & SET_TEXTURE_MB) && s->texture_mb > 0.0)
        o->texture_mb = s->texture_mb;
    if (!(a->set & SET_OPACITY_CACHE_MB) && s->opacity_cache_mb > 0.0)
        o->opacity_cache_mb = s->opacity_cache_mb;
    if (!(a->set & SET_CROP))
        memcpy(o->crop, s->crop, sizeof o->crop);
}

/* v normalised, or v itself when it has no length. */
static void normalise3(float v[3])
{
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3 && len > 0.0f; k++)
        v[k] /= len;
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

RayesError command_line_camera(const Args *a, RayesScene *scene)
{
    if (!a->camera)
        return RAYES_OK;
    float eye[3], x[3], y[3], z[3], at[3], up[3], yz[3];
    RayesError e = rayes_scene_get_camera(scene, eye, x, y, z);
    if (e != RAYES_OK)
        return e;
    cross3(y, z, yz); /* the scene's camera's handedness: x = +-(y cross z) */
    float hand = x[0] * yz[0] + x[1] * yz[1] + x[2] * yz[2] < 0.0f ? -1.0f : 1.0f;
    if (a->camera & CAMERA_FROM)
        memcpy(eye, a->look_from, sizeof eye);
    for (int k = 0; k < 3; k++) {
        at[k] = a->camera & CAMERA_AT ? a->look_at[k] : eye[k] + z[k];
        up[k] = a->camera & CAMERA_UP ? a->up[k] : y[k];
    }
    /* the new frame: z toward the point, y the up made perpendicular to
     * it, x on the scene's side, so the image is not mirrored */
    float Z[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, X[3], Y[3];
    normalise3(Z);
    float d = up[0] * Z[0] + up[1] * Z[1] + up[2] * Z[2];
    for (int k = 0; k < 3; k++)
        Y[k] = up[k] - d * Z[k];
    normalise3(Y);
    cross3(Y, Z, X);
    float xl = sqrtf(X[0] * X[0] + X[1] * X[1] + X[2] * X[2]);
    if (!(xl > 1e-6f)) /* the eye on the point, or up along the view */
        return rayes_scene_set_camera(scene, eye, at, up, 40.0f); /* says which */
    float m[16] = {0};
    const float *rows[3] = {X, Y, Z};
    for (int r = 0; r < 3; r++) {
        float sign = r == 0 ? hand / xl : 1.0f;
        for (int c = 0; c < 3; c++)
            m[4 * r + c] = sign * rows[r][c];
        m[4 * r + 3] = -(m[4 * r] * eye[0] + m[4 * r + 1] * eye[1] + m[4 * r + 2] * eye[2]);
    }
    m[15] = 1.0f;
    e = rayes_scene_set_camera_matrix(scene, m, RAYES_PROJECTION_PERSPECTIVE,
                                      a->camera & CAMERA_FOV ? a->fov : 40.0f, NULL);
    return e == RAYES_OK ? rayes_scene_set_depth_of_field(scene, 0.0f, 1.0f) : e;
}

IoReadOptions read_options(const Args *a, int frame)
{
    IoReadOptions ro = {
        .data_dir = a->data_dir, .frame = frame, .bounces_given = (a->set & SET_BOUNCES) != 0};
    ro.view = (a->camera & CAMERA_FROM ? IO_VIEW_FROM : 0) |
              (a->camera & CAMERA_AT ? IO_VIEW_AT : 0) | (a->camera & CAMERA_UP ? IO_VIEW_UP : 0);
    memcpy(ro.view_from, a->look_from, sizeof ro.view_from);
    memcpy(ro.view_at, a->look_at, sizeof ro.view_at);
    memcpy(ro.view_up, a->up, sizeof ro.view_up);
    return ro;
}

RayesError default_light(const Args *a, const IoSettings *s, RayesScene *scene)
{
    if (rayes_scene_light_count(scene) > 0)
        return RAYES_OK;
    if (!a->default_light && !s->headlight) {
        fprintf(stderr, "rayes: warning: %s: the scene has no lights (--default-light adds a "
                        "headlight)\n", a->scene);
        return RAYES_OK;
    }
    float eye[3], x[3], y[3], z[3];
    RayesError e = rayes_scene_get_camera(scene, eye, x, y, z);
    if (e != RAYES_OK)
        return e;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    /* no shadows: a camera inside a room would have them all (the wall
     * behind it), and in front of the camera there are none to see */
    RayesParam p[4] = {{"from", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                       {"to", RAYES_PARAM_COLOR, {z[0], z[1], z[2]}, NULL},
                       {"intensity", RAYES_PARAM_FLOAT, {(float)M_PI, 0, 0}, NULL}, /* Cs */
                       {"shadows", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL}};
    if ((e = rayes_scene_set_transform(scene, identity)) == RAYES_OK)
        e = rayes_scene_light(scene, "distantlight", p, 4);
    if (e == RAYES_OK && !a->quiet)
        fprintf(stderr, "rayes: note: %s: the scene has no lights; a headlight was added\n",
                a->scene);
    return e;
}
