/*
 * tests/app/test_farm.c — the command lines of docs/farm.md, run as the
 * farm would run them, with the scheduler's variables set by hand: the
 * Slurm array task's command for tasks 1 and 2 of a three-frame RIB file
 * (each writes its own frame; a requeued task skips its finished frame),
 * an OpenCue layer's command with its #IFRAME# token replaced, and a frame
 * cut into four crops put together by `rayes assemble`, the same bytes as
 * the whole frame (and a part of another frame refused, nothing written).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/files.h"
#include "test.h"

#define SCRATCH RAYES_TEST_TMP "/app_farm"

static long mtime_ns(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_mtim.tv_sec * 1000000000L + st.st_mtim.tv_nsec : -1;
}

/* Runs a shell command in SCRATCH, rayes being $RAYES; its status. */
static int sh(const char *cmd)
{
    char full[4096];
    snprintf(full, sizeof full, "cd %s && RAYES=%s; ( %s ) >>farm.log 2>&1", SCRATCH, RAYES_BIN,
             cmd);
    int rc = system(full);
    return rc == -1 ? -1 : WEXITSTATUS(rc);
}

static void write_frames(void)
{
    mkdir(SCRATCH, 0755);
    mkdir(SCRATCH "/renders", 0755);
    FILE *f = fopen(SCRATCH "/shot010.rib", "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("Format 32 24 1\n", f);
    for (int n = 1; n <= 3; n++)
        fprintf(f,
                "FrameBegin %d\nWorldBegin\nLightSource \"distantlight\" 1\n"
                "Translate %d 0 5\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n",
                n, n - 2);
    fclose(f);
}

/* The Slurm array task of docs/farm.md, tasks 1 and 2, then task 1
 * requeued. */
static void test_slurm_array_task(void)
{
    write_frames();
    const char *task =
        "exec $RAYES render shot010.rib --frames \"$SLURM_ARRAY_TASK_ID\" "
        "-o \"renders/shot010.####.exr\" --threads \"$SLURM_CPUS_PER_TASK\" "
        "--skip-existing --checkpoint 600 --resume --progress json";
    char cmd[2048];
    unlink(SCRATCH "/renders/shot010.0001.exr");
    unlink(SCRATCH "/renders/shot010.0002.exr");
    unlink(SCRATCH "/renders/shot010.0003.exr");
    for (int id = 1; id <= 2; id++) {
        snprintf(cmd, sizeof cmd, "(SLURM_ARRAY_TASK_ID=%d SLURM_CPUS_PER_TASK=2; export "
                 "SLURM_ARRAY_TASK_ID SLURM_CPUS_PER_TASK; %s)", id, task);
        CHECK(sh(cmd) == 0);
    }
    CHECK(file_exists(SCRATCH "/renders/shot010.0001.exr") &&
          file_exists(SCRATCH "/renders/shot010.0002.exr") &&
          !file_exists(SCRATCH "/renders/shot010.0003.exr"));
    CHECK(!same_bytes(SCRATCH "/renders/shot010.0001.exr", SCRATCH "/renders/shot010.0002.exr"));
    CHECK(!file_exists(SCRATCH "/renders/shot010.0001.exr.checkpoint"));
    long before = mtime_ns(SCRATCH "/renders/shot010.0001.exr");
    snprintf(cmd, sizeof cmd, "(SLURM_ARRAY_TASK_ID=1 SLURM_CPUS_PER_TASK=2; export "
             "SLURM_ARRAY_TASK_ID SLURM_CPUS_PER_TASK; %s)", task);
    CHECK(sh(cmd) == 0); /* requeued: skipped */
    CHECK(mtime_ns(SCRATCH "/renders/shot010.0001.exr") == before);
}

/* The OpenCue layer command with its token replaced, as OpenCue does. */
static void test_opencue_token(void)
{
    write_frames();
    const char *layer = "$RAYES render shot010.rib --frames #IFRAME# -o "
                        "renders/shot010.####.exr --skip-existing --checkpoint 600 --resume "
                        "--progress json";
    char cmd[2048], out[2100];
    size_t k = 0;
    for (const char *c = layer; *c && k + 2 < sizeof cmd;) {
        if (strncmp(c, "#IFRAME#", 8) == 0) {
            cmd[k++] = '3';
            c += 8;
        } else {
            cmd[k++] = *c++;
        }
    }
    cmd[k] = '\0';
    unlink(SCRATCH "/renders/shot010.0003.exr");
    snprintf(out, sizeof out, "%s > opencue.json", cmd);
    CHECK(sh(out) == 0);
    CHECK(file_exists(SCRATCH "/renders/shot010.0003.exr"));
    char text[4096] = "";
    FILE *f = fopen(SCRATCH "/opencue.json", "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    if (f)
        fclose(f);
    CHECK(strstr(text, "{\"event\": \"frame\", \"frame\": 3, \"status\": 0") != NULL);
}

/* The four quarters of the cornell frame at 96 x 64 with options extra,
 * into parts/PREFIX0.exr to parts/PREFIX3.exr. */
static void render_crops(const char *extra, const char *prefix)
{
    const char *crops[4] = {"0,0.5,0,0.5", "0.5,1,0,0.5", "0,0.5,0.5,1", "0.5,1,0.5,1"};
    for (int i = 0; i < 4; i++) {
        char cmd[512];
        snprintf(cmd, sizeof cmd,
                 "$RAYES render cornell --res 96x64 --spp 2 --quiet --crop %s %s -o "
                 "parts/%s%d.exr",
                 crops[i], extra, prefix, i);
        CHECK(sh(cmd) == 0);
    }
}

/* A text file's start into buf ("" if it cannot be read). */
static void read_text(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, size - 1, f) : 0;
    buf[n] = '\0';
    if (f)
        fclose(f);
}

/* Four crops and rayes assemble: the whole frame's bytes, AOVs too. */
static void test_crops_assembled(void)
{
    mkdir(SCRATCH, 0755);
    mkdir(SCRATCH "/parts", 0755);
    unlink(SCRATCH "/poster.exr");
    CHECK(sh("$RAYES render cornell --res 96x64 --spp 2 --quiet -o whole.exr") == 0);
    render_crops("", "p");
    CHECK(sh("$RAYES assemble poster.exr parts/p0.exr parts/p1.exr parts/p2.exr parts/p3.exr") ==
          0);
    CHECK(same_bytes(SCRATCH "/poster.exr", SCRATCH "/whole.exr"));
    /* a part of a frame of another size */
    CHECK(sh("$RAYES render cornell --res 48x32 --spp 1 --quiet --crop 0,0.5,0,0.5 -o "
             "parts/other.exr") == 0);
    unlink(SCRATCH "/mixed.exr");
    CHECK(sh("$RAYES assemble mixed.exr parts/p0.exr parts/other.exr 2>mixed.err") == 1);
    CHECK(!file_exists(SCRATCH "/mixed.exr"));
    char err[1024];
    read_text(SCRATCH "/mixed.err", err, sizeof err);
    CHECK(strstr(err, "parts/other.exr: a 48 x 32 frame") != NULL);
    CHECK(sh("$RAYES assemble only-one.exr") == 2);
    /* parts with AOVs: joined too, the whole frame's bytes; a part without
     * them leaves the colour alone, with a warning */
    CHECK(sh("$RAYES render cornell --res 96x64 --spp 2 --quiet --aov z,N,id -o whole-aov.exr") ==
          0);
    render_crops("--aov z,N,id", "a");
    CHECK(sh("$RAYES assemble joined.exr parts/a0.exr parts/a1.exr parts/a2.exr parts/a3.exr") ==
          0);
    CHECK(same_bytes(SCRATCH "/joined.exr", SCRATCH "/whole-aov.exr"));
    CHECK(sh("$RAYES assemble mixed-aov.exr parts/a0.exr parts/p1.exr parts/p2.exr parts/p3.exr "
             "2>mixed-aov.err") == 0);
    CHECK(same_bytes(SCRATCH "/mixed-aov.exr", SCRATCH "/whole.exr"));
    read_text(SCRATCH "/mixed-aov.err", err, sizeof err);
    CHECK(strstr(err, "parts/p1.exr") && strstr(err, "colour alone"));
}

TEST_MAIN(TEST(test_slurm_array_task), TEST(test_opencue_token), TEST(test_crops_assembled))
