/*
 * app/assemble.c — the crops of one frame into one EXR (assemble.h).
 *
 * Every part must have the first part's display window; overlapping parts
 * agree where they overlap (they are crops of one frame), so later ones
 * simply overwrite. The output's data window is the union of the parts'
 * (the whole frame when they tile it); pixels in it that no part covers
 * are 0 and are reported. AOV channels are joined alike when every part
 * has the same ones.
 */
#include "app/assemble.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/cli.h"
#include "image/image.h"

#define ASSEMBLE_MAX_AOV 64

/* The frame being assembled: colour, and the AOVs every part carries
 * alike (their channels' names and order those of the first part). */
typedef struct Frame {
    float *full, *aov;
    int size[2], u[4]; /* display size; union of data windows x0 y0 x1 y1 */
    int n_aov;         /* -1 before the first part; 0: none (or parts differ) */
    char names[ASSEMBLE_MAX_AOV][IMAGE_AOV_NAME];
} Frame;

/* Part path into f (made at the first part's display size); 0, or 1
 * after printing why. */
static int add_part(const char *path, Frame *f)
{
    char err[1024], names[ASSEMBLE_MAX_AOV][IMAGE_AOV_NAME];
    int disp[2], win[4], n_aov = 0, others = 0;
    float *px = NULL, *aov = NULL;
    if (image_read_exr_aov(path, disp, win, &px, &aov, &n_aov, names, ASSEMBLE_MAX_AOV, &others,
                           err, sizeof err) != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        return 1;
    }
    if (!f->full) {
        f->size[0] = disp[0], f->size[1] = disp[1];
        f->full = calloc((size_t)disp[0] * (size_t)disp[1] * 4, sizeof(float));
        f->u[0] = win[0], f->u[1] = win[1], f->u[2] = win[0] + win[2], f->u[3] = win[1] + win[3];
        f->n_aov = n_aov;
        memcpy(f->names, names, sizeof names);
        f->aov =
            n_aov ? calloc((size_t)disp[0] * (size_t)disp[1] * (size_t)n_aov, sizeof(float)) : NULL;
    }
    int bad = !f->full || (f->n_aov && !f->aov) || disp[0] != f->size[0] || disp[1] != f->size[1] ||
              win[0] < 0 || win[1] < 0 || win[0] + win[2] > f->size[0] ||
              win[1] + win[3] > f->size[1];
    if (bad)
        fprintf(stderr,
                "rayes: %s: a %d x %d frame with its crop at %d,%d (%d x %d); expected a crop "
                "of the %d x %d frame of the first part\n",
                path, disp[0], disp[1], win[0], win[1], win[2], win[3], f->size[0], f->size[1]);
    int same = n_aov == f->n_aov && memcmp(names, f->names, (size_t)n_aov * sizeof names[0]) == 0;
    if (!bad && f->n_aov && !same) {
        fprintf(stderr,
                "rayes: warning: %s: its AOV channels are not the first part's; the "
                "assembled image holds colour alone\n",
                path);
        free(f->aov);
        f->aov = NULL, f->n_aov = 0;
    }
    if (!bad && others > n_aov)
        fprintf(stderr,
                "rayes: warning: %s: %d of its channels (subsampled, or past %d) are not "
                "joined\n",
                path, others - n_aov, ASSEMBLE_MAX_AOV);
    for (int y = 0; !bad && y < win[3]; y++) {
        size_t to = (size_t)(win[1] + y) * f->size[0] + win[0], from = (size_t)y * win[2];
        memcpy(f->full + 4 * to, px + 4 * from, sizeof(float) * 4 * (size_t)win[2]);
        if (f->n_aov)
            memcpy(f->aov + (size_t)f->n_aov * to, aov + (size_t)f->n_aov * from,
                   sizeof(float) * (size_t)f->n_aov * (size_t)win[2]);
    }
    if (!bad) {
        f->u[0] = win[0] < f->u[0] ? win[0] : f->u[0];
        f->u[1] = win[1] < f->u[1] ? win[1] : f->u[1];
        f->u[2] = win[0] + win[2] > f->u[2] ? win[0] + win[2] : f->u[2];
        f->u[3] = win[1] + win[3] > f->u[3] ? win[1] + win[3] : f->u[3];
    }
    free(px);
    free(aov);
    return bad;
}

int cmd_assemble(int argc, char **argv)
{
    if (argc >= 3 && (strcmp(argv[2], "--help") == 0 || strcmp(argv[2], "-h") == 0)) {
        print_command_usage("assemble", stdout);
        return 0;
    }
    if (argc < 4)
        die_usage("assemble: expected OUT.exr and at least one PART.exr");
    const char *out = argv[2];
    if (image_format_from_path(out) != IMAGE_FORMAT_EXR)
        die_usage("assemble: %s: expected an output name ending in .exr", out);
    static Frame f; /* a few kB of names */
    memset(&f, 0, sizeof f);
    f.n_aov = -1;
    int status = 0;
    for (int i = 3; i < argc && status == 0; i++)
        status = add_part(argv[i], &f);
    if (status == 0) {
        int win[4] = {f.u[0], f.u[1], f.u[2] - f.u[0], f.u[3] - f.u[1]};
        const char *names[ASSEMBLE_MAX_AOV];
        for (int k = 0; k < f.n_aov; k++)
            names[k] = f.names[k];
        char err[1024];
        if (image_write_exr_aov(out, f.size[0], f.size[1], f.full, win, 0, f.aov,
                                f.aov ? f.n_aov : 0, names, err, sizeof err) != RAYES_OK) {
            fprintf(stderr, "rayes: %s\n", err);
            status = 1;
        }
    }
    free(f.full);
    free(f.aov);
    return status;
}
