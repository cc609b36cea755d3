/*
 * app/cli.h — what the commands of the rayes program (main.c) and the
 * viewer (view.c) share, implemented by cli.c: arguments, loading a
 * scene, usage errors.
 */
#ifndef RAYES_APP_CLI_H
#define RAYES_APP_CLI_H

#include <stdio.h>

#include "image/image.h"
#include "io/sink.h"
#include "rayes/rayes.h"

#define MAX_OUTPUTS 8

/* Options given on the command line, which win over a scene file's. */
enum {
    SET_RES = 1,
    SET_SPP = 2,
    SET_FILTER = 4,
    SET_FILTER_WIDTH = 8,
    SET_BOUNCES = 16,
    SET_SPECULAR_DEPTH = 32,
    SET_GRID_SIZE = 64,
    SET_TEXTURE_MB = 128,
    SET_CROP = 256,
    SET_OPACITY_CACHE_MB = 512,
    SET_MAX_SPP = 1024,
    SET_ADAPTIVE_ERROR = 2048,
    SET_CLAMP = 4096,
    SET_RES_WIDTH = 8192 /* --res W alone: the height follows the file's aspect ratio */
};

/* Camera options the command line gave (Args.camera). */
enum { CAMERA_FROM = 1, CAMERA_AT = 2, CAMERA_UP = 4, CAMERA_FOV = 8 };

/* An image to write. */
typedef struct Output {
    char path[600];
    ImageFormat format;
    int no_alpha; /* a display of mode "rgb": R, G, B only */
    int display;  /* a scene file's display: it writes aovs (and colour unless no_colour);
                     else (-o) colour and every AOV rendered */
    unsigned aovs;
    int no_colour; /* a display of AOVs alone ("z", "N"): their channels, no R, G, B, A */
} Output;

typedef struct Args {
    const char *scene;          /* a built-in scene's name or a scene file */
    Output outputs[MAX_OUTPUTS];
    int n_outputs;
    int frame;                  /* --frame: the RIB frame to read; -1 the last */
    const char *frames;         /* --frames LIST: frames to render one after another */
    int skip_existing;          /* --skip-existing: a frame whose outputs exist is skipped */
    int progress_json;          /* --progress json: machine-readable lines on standard output */
    double checkpoint_s;        /* --checkpoint SECONDS: save finished tiles this often; -1 never */
    int resume;                 /* --resume: render only the tiles a checkpoint lacks */
    unsigned set;               /* SET_*: options the command line gave */
    const char *stats_path;
    const char *data_dir;
    const char *shader_path;    /* --shader-path: put before the scene's own shader path */
    int quiet;
    int default_light;          /* --default-light: a headlight for a scene without lights */
    unsigned camera;            /* CAMERA_*: the camera options given */
    float look_from[3], look_at[3], up[3], fov; /* --look-from, --look-at, --up, --fov */
    int png_curve;              /* --png-curve: IO_CURVE_*, IO_CURVE_UNSAID: the scene file's */
    RayesRenderOptions opt;
    /* rayes view */
    int view;                   /* set before parse_args: the view options are accepted */
    int headless;               /* --headless: no window */
    const char *script;         /* --script FILE ("-": standard input) */
    int passes;                 /* --passes N: stop after N passes (0: never, in a window) */
    const char *screenshot;     /* --screenshot FILE: the window's pixels after --passes */
    float exposure, gamma;      /* display: colour * 2^exposure, then ^(1 / gamma) */
} Args;

/* Parses `rayes COMMAND ...` into a (argv[2] on); dies with status 2 on a
 * usage error. */
void parse_args(int argc, char **argv, Args *a);

/* The integer s, the value of option opt, in [lo, hi]; dies with a usage
 * error otherwise. */
long parse_long(const char *opt, const char *s, long lo, long hi);

/* The RayesAov bits an AOV's name (its first n characters) stands for, or
 * 0: z (Z, RenderMan's denoiser's zfiltered), N (normal), P, id, patch,
 * cache, all. --aov's list and a RIB display's mode both read them. */
unsigned aov_named(const char *name, size_t n);

/* Prints "rayes: MESSAGE" and the usage hint, exits with status 2. */
void die_usage(const char *fmt, ...) __attribute__((noreturn, format(printf, 1, 2)));

/* The data directory (teapot.bpt) when no --data gives one: $RAYES_DATA,
 * else ../shared/data beside the checkout whose build/ holds this program
 * (the benchmark data's place), when it holds teapot.bpt; else NULL. */
const char *default_data_dir(void);

/* Builds the scene `scene` names (a scene file, else a built-in scene)
 * into sink; settings receive what a file gives. */
RayesError load_scene(const char *scene, const IoReadOptions *ro, const IoSink *sink,
                      IoSettings *settings, char *err, size_t err_size);

/* The exit status of a failed load (2 for an unknown built-in, else 1). */
int load_status(const char *scene, RayesError e);

/* The file's settings where the command line gave none. */
void merge_settings(Args *a, const IoSettings *s);

/* A loaded scene's camera (before its commit) replaced by the command
 * line's --look-from, --look-at, --up and --fov, when any is given: a
 * still pinhole perspective camera at the given eye (else the scene's)
 * looking at the given point (else along the scene's view), up the given
 * direction (else the scene's camera's), of the given field of view
 * across the image's shorter side (else 40 degrees), of the scene
 * camera's handedness (RIB's and pbrt's left-handed camera spaces, OBJ's
 * right-handed view: the image is not mirrored). Returns what setting it
 * returned (the scene's error names a degenerate view). */
RayesError command_line_camera(const Args *a, RayesScene *scene);

/* The reader's options for a's scene and frame: the data folder, whether
 * the bounces are given, the command line's view (for OBJ's default light). */
IoReadOptions read_options(const Args *a, int frame);

/* A loaded scene without lights (before its commit): one warning, or with
 * --default-light (or a file that asks for one, s->headlight) a headlight,
 * a distant light of intensity 1 along the view that casts no shadows. Returns what adding it
 * returned (RAYES_OK when nothing was added). */
RayesError default_light(const Args *a, const IoSettings *s, RayesScene *scene);

/* The usage text of every command, to f. */
void print_usage(FILE *f);

/* The usage text of one command ("render", "view" or "convert"), to f. */
void print_command_usage(const char *command, FILE *f);

#endif /* RAYES_APP_CLI_H */
