/*
 * tests/app/test_checkpoint.c — `--checkpoint` and `--resume` (src/app/
 * checkpoint.c) through the command line: a render stopped (SIGSTOP, as
 * soon as its first checkpoint exists, then SIGKILL: a crash) and resumed
 * writes the same bytes as an uninterrupted render (its AOVs too), having
 * rendered only the missing tiles, and removes its checkpoint; SIGTERM saves one and
 * exits 143; a checkpoint of other options is ignored with a note; a
 * damaged one is one line naming it, status 1, no output; a bad
 * --checkpoint value is a usage error.
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "app/files.h"
#include "test.h"

#define DIR RAYES_TEST_TMP "/app_checkpoint"
#define SCENE "cornell", "--res", "192", "--spp", "16", "--quiet" /* 36 tiles of 32 */

/* Starts rayes with args (NULL-terminated) in DIR, stdout and stderr to
 * DIR/NAME.out and .err; returns its pid. */
static pid_t start(const char *name, const char *const *args)
{
    fflush(NULL); /* or the child's freopen writes the parent's buffered lines again */
    pid_t pid = fork();
    if (pid == 0) {
        char out[512], err[512];
        snprintf(out, sizeof out, "%s/%s.out", DIR, name);
        snprintf(err, sizeof err, "%s/%s.err", DIR, name);
        if (chdir(DIR) != 0 || !freopen(out, "w", stdout) || !freopen(err, "w", stderr))
            _exit(127);
        const char *argv[64] = {RAYES_BIN, "render"};
        int n = 2;
        for (int i = 0; args[i] && n < 63; i++)
            argv[n++] = args[i];
        argv[n] = NULL;
        execv(RAYES_BIN, (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static int finish(pid_t pid)
{
    int st;
    if (waitpid(pid, &st, 0) != pid)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int run(const char *name, const char *const *args)
{
    return finish(start(name, args));
}

static void read_text(const char *name, const char *ext, char *buf, size_t size)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s.%s", DIR, name, ext);
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, size - 1, f) : 0;
    buf[n] = '\0';
    if (f)
        fclose(f);
}

/* Waits up to 60 s for path to exist. */
static int wait_for(const char *path)
{
    for (int i = 0; i < 60000; i++) {
        if (file_exists(path))
            return 1;
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
    return 0;
}

/* Waits up to 60 s for the file at path to hold text. */
static int wait_for_text(const char *path, const char *text)
{
    for (int i = 0; i < 60000; i++) {
        char buf[4096] = "";
        FILE *f = fopen(path, "r");
        if (f) {
            size_t n = fread(buf, 1, sizeof buf - 1, f);
            buf[n] = '\0';
            fclose(f);
            if (strstr(buf, text))
                return 1;
        }
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
    return 0;
}

/* A render stopped at its first checkpoint and resumed is the same bytes
 * as a whole one; with aovs (--aov's value, or NULL) its AOV channels too. */
static void resume_after_crash(const char *aovs)
{
    mkdir(DIR, 0755);
    const char *out = aovs ? "crash-aov.exr" : "crash.exr",
               *whole = aovs ? "full-aov.exr" : "full.exr";
    char ck[256], path[256], full_path[256];
    snprintf(ck, sizeof ck, DIR "/%s.checkpoint", out);
    snprintf(path, sizeof path, DIR "/%s", out);
    snprintf(full_path, sizeof full_path, DIR "/%s", whole);
    unlink(ck);
    unlink(path);
    const char *aov = aovs ? "--aov" : NULL; /* ends the lists here without AOVs */
    const char *full[] = {SCENE, "--threads", "2", "-o", whole, aov, aovs, NULL};
    CHECK(run("full", full) == 0);
    /* one thread, a checkpoint after every tile; frozen at the first */
    const char *part[] = {SCENE, "--threads", "1", "--checkpoint", "0", "-o", out, aov, aovs, NULL};
    pid_t pid = start("crash", part);
    CHECK(wait_for(ck));
    kill(pid, SIGSTOP);
    CHECK(!file_exists(path)); /* stopped before the end */
    kill(pid, SIGKILL);
    finish(pid);
    CHECK(file_exists(ck) && !file_exists(path));
    /* resumed on two threads: the rest of the tiles, the same bytes */
    const char *resume[] = {"cornell",  "--res", "192", "--spp", "16", "--threads", "2",
                            "--resume", "-o",    out,   aov,     aovs, NULL};
    CHECK(run("resume", resume) == 0);
    char text[4096];
    read_text("resume", "out", text, sizeof text);
    int tiles = 0;
    const char *at = strstr(text, "resumed");
    CHECK(at && sscanf(at, "resumed %d tiles", &tiles) == 1);
    fprintf(stderr, "resumed %d of 36 tiles%s\n", tiles, aovs ? " with AOVs" : "");
    CHECK(tiles >= 1 && tiles < 36);
    CHECK(same_bytes(path, full_path));
    CHECK(!file_exists(ck)); /* removed once written */
}

static void test_resume_after_crash(void)
{
    resume_after_crash(NULL);
}

static void test_resume_with_aovs(void)
{
    resume_after_crash("all");
}

static void test_sigterm_saves(void)
{
    unlink(DIR "/term.exr.checkpoint");
    unlink(DIR "/term.exr");
    unlink(DIR "/term.out"); /* an earlier run's progress lines are not this one's */
    const char *args[] = {SCENE,        "--threads", "1",  "--checkpoint", "1000",
                          "--progress", "json",      "-o", "term.exr",     NULL};
    pid_t pid = start("term", args);
    /* wait for its first progress line (a tile done, the handler long
     * installed: a fixed wait was too short under ThreadSanitizer on a
     * loaded machine, and the signal came before the handler), then ask it
     * to stop */
    CHECK(wait_for_text(DIR "/term.out", "\"event\": \"progress\""));
    kill(pid, SIGTERM);
    int status = finish(pid);
    if (status == 0) { /* finished first: nothing to test on this machine */
        fprintf(stderr, "  the render finished before SIGTERM: skipped\n");
        return;
    }
    CHECK(status == 143);
    CHECK(!file_exists(DIR "/term.exr"));
    CHECK(file_exists(DIR "/term.exr.checkpoint"));
    const char *resume[] = {SCENE, "--threads", "2", "--resume", "-o", "term.exr", NULL};
    CHECK(run("term-resume", resume) == 0);
    CHECK(same_bytes(DIR "/term.exr", DIR "/full.exr"));
}

static void test_other_options_and_damage(void)
{
    /* a checkpoint of 16 samples does not resume a render of 8 */
    const char *part[] = {SCENE, "--threads", "1", "--checkpoint", "0", "-o", "other.exr", NULL};
    unlink(DIR "/other.exr.checkpoint");
    unlink(DIR "/bad.exr");
    unlink(DIR "/u.exr");
    pid_t pid = start("other", part);
    CHECK(wait_for(DIR "/other.exr.checkpoint"));
    kill(pid, SIGKILL);
    finish(pid);
    const char *eight[] = {"cornell", "--res", "192", "--spp", "8", "--quiet", "--resume",
                           "-o", "other.exr", NULL};
    CHECK(run("other-resume", eight) == 0);
    char err[4096];
    read_text("other-resume", "err", err, sizeof err);
    CHECK(strstr(err, "other.exr.checkpoint: a checkpoint of another scene or other options") !=
          NULL);
    /* a damaged one */
    FILE *f = fopen(DIR "/bad.exr.checkpoint", "w");
    if (f) {
        fputs("not a checkpoint", f);
        fclose(f);
    }
    const char *bad[] = {SCENE, "--resume", "-o", "bad.exr", NULL};
    CHECK(run("bad", bad) == 1);
    read_text("bad", "err", err, sizeof err);
    CHECK(strstr(err, "bad.exr.checkpoint: not a rayes checkpoint") != NULL);
    CHECK(strchr(err, '\n') == err + strlen(err) - 1);
    CHECK(!file_exists(DIR "/bad.exr"));
    /* a bad value */
    const char *usage[] = {SCENE, "--checkpoint", "soon", "-o", "u.exr", NULL};
    CHECK(run("usage", usage) == 2);
    CHECK(!file_exists(DIR "/u.exr"));
}

TEST_MAIN(TEST(test_resume_after_crash), TEST(test_resume_with_aovs), TEST(test_sigterm_saves),
          TEST(test_other_options_and_damage))
