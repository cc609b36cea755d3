/*
 * app/assemble.c — the crops of one frame into one EXR (assemble.h).
 *
 * Every part must have the first part's display window; overlapping parts
 * agree where they overlap (they are crops of one frame), so later ones
 * simply overwrite. The output's data window is the union of the parts'
 * (the whole frame when they tile it); pixels in it that no part covers
 * are 0 and are reported.
 */
#include "app/assemble.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/cli.h"
#include "image/image.h"

/* Part path into *full (made at the first part's display size), growing
 * the union u of data windows (x0 y0 x1 y1); 0, or 1 after printing why. */
static int add_part(const char *path, float **full, int size[2], int u[4])
{
    char err[1024];
    int disp[2], win[4];
    float *px = NULL;
    int others = 0;
    if (image_read_exr_parts(path, disp, win, &px, &others, err, sizeof err) != RAYES_OK) {
        fprintf(stderr, "rayes: %s\n", err);
        return 1;
    }
    if (others)
        fprintf(stderr,
                "rayes: warning: %s: its %d channels besides R, G, B, A (AOVs) are not "
                "joined; the assembled image holds colour alone\n",
                path, others);
    if (!*full) {
        size[0] = disp[0], size[1] = disp[1];
        *full = calloc((size_t)disp[0] * (size_t)disp[1] * 4, sizeof(float));
        u[0] = win[0], u[1] = win[1], u[2] = win[0] + win[2], u[3] = win[1] + win[3];
    }
    int bad = !*full || disp[0] != size[0] || disp[1] != size[1] || win[0] < 0 || win[1] < 0 ||
              win[0] + win[2] > size[0] || win[1] + win[3] > size[1];
    if (bad)
        fprintf(stderr,
                "rayes: %s: a %d x %d frame with its crop at %d,%d (%d x %d); expected a crop "
                "of the %d x %d frame of the first part\n",
                path, disp[0], disp[1], win[0], win[1], win[2], win[3], size[0], size[1]);
    for (int y = 0; !bad && y < win[3]; y++)
        memcpy(*full + 4 * ((size_t)(win[1] + y) * size[0] + win[0]), px + 4 * (size_t)y * win[2],
               sizeof(float) * 4 * (size_t)win[2]);
    if (!bad) {
        u[0] = win[0] < u[0] ? win[0] : u[0];
        u[1] = win[1] < u[1] ? win[1] : u[1];
        u[2] = win[0] + win[2] > u[2] ? win[0] + win[2] : u[2];
        u[3] = win[1] + win[3] > u[3] ? win[1] + win[3] : u[3];
    }
    free(px);
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
    float *full = NULL;
    int size[2] = {0, 0}, u[4] = {0, 0, 0, 0}, status = 0;
    for (int i = 3; i < argc && status == 0; i++)
        status = add_part(argv[i], &full, size, u);
    if (status == 0) {
        int win[4] = {u[0], u[1], u[2] - u[0], u[3] - u[1]};
        char err[1024];
        if (image_write_exr_window(out, size[0], size[1], full, win, 0, err, sizeof err) !=
            RAYES_OK) {
            fprintf(stderr, "rayes: %s\n", err);
            status = 1;
        }
    }
    free(full);
    return status;
}
