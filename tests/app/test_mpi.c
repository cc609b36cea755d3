/*
 * tests/app/test_mpi.c — one frame over the ranks of an Open MPI job
 * (src/app/distribute.c): `mpirun --oversubscribe -np 3 rayes render ...`
 * writes the same bytes as one process, with the ray-tracing and the grid
 * hider, and prints every rank's share; a rank killed mid-frame ends the
 * job with a non-zero status and no image, not a hang. Skipped (with a
 * note) where mpirun is not installed or rayes was built without MPI.
 */
#include <dirent.h>
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

#define SCRATCH RAYES_TEST_TMP "/app_mpi"

/* "mpirun ... -np N" as this user may run it (root needs its flag); leaks
 * inside Open MPI are not ours to report under AddressSanitizer. */
static void mpirun(char *buf, size_t n, int ranks)
{
    snprintf(buf, n, "mpirun %s--oversubscribe -np %d",
             getuid() == 0 ? "--allow-run-as-root " : "", ranks);
}

static int have_mpi(void)
{
    if (system("command -v mpirun >/dev/null 2>&1") != 0) {
        fprintf(stderr, "  mpirun not installed: skipped\n");
        return 0;
    }
    char cmd[1024];
    /* built with MPI: the program links Open MPI's library */
    snprintf(cmd, sizeof cmd, "ldd %s 2>/dev/null | grep -q libmpi", RAYES_BIN);
    if (system(cmd) != 0) {
        fprintf(stderr, "  rayes built without Open MPI: skipped\n");
        return 0;
    }
    return 1;
}

static void test_same_bytes_as_one_process(void)
{
    mkdir(SCRATCH, 0755);
    if (!have_mpi())
        return;
    const char *modes[2] = {"--quality preview --spp 4",
                            "--quality final --spp 1 --diffuse-rays 16 --aov all"};
    for (int m = 0; m < 2; m++) {
        char cmd[2048], mpi[256], one[512], many[512], out[512];
        snprintf(one, sizeof one, SCRATCH "/one-%d.exr", m);
        snprintf(many, sizeof many, SCRATCH "/three-%d.exr", m);
        snprintf(out, sizeof out, SCRATCH "/three-%d.txt", m);
        unlink(many);
        snprintf(cmd, sizeof cmd, "%s render cornell --res 96 %s --threads 2 --quiet -o %s",
                 RAYES_BIN, modes[m], one);
        CHECK(system(cmd) == 0);
        mpirun(mpi, sizeof mpi, 3);
        snprintf(cmd, sizeof cmd,
                 "ASAN_OPTIONS=detect_leaks=0 %s %s render cornell --res 96 %s --threads 1 -o %s "
                 "--stats %s.json >%s 2>&1",
                 mpi, RAYES_BIN, modes[m], many, many, out);
        int rc = system(cmd);
        CHECK(rc == 0);
        CHECK(same_bytes(one, many));
        char text[8192] = "";
        FILE *f = fopen(out, "r");
        size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
        text[n] = '\0';
        if (f)
            fclose(f);
        CHECK(strstr(text, "rank 0 ") && strstr(text, "rank 1 ") && strstr(text, "rank 2 ") &&
              strstr(text, "all ranks     3 ranks, 9 tiles"));
        if (rc != 0 || !strstr(text, "all ranks"))
            fprintf(stderr, "%s\n", text);
        /* the statistics file: rank 0's, and every rank's with their total */
        char json[520], jtext[16384] = "";
        snprintf(json, sizeof json, "%s.json", many);
        FILE *jf = fopen(json, "r");
        size_t jn = jf ? fread(jtext, 1, sizeof jtext - 1, jf) : 0;
        jtext[jn] = '\0';
        if (jf)
            fclose(jf);
        CHECK(strstr(jtext, "\"mpi\": {\"ranks\": 3, \"per_rank\": [") &&
              strstr(jtext, "{\"rank\": 2, \"tiles\": ") &&
              strstr(jtext, "\"total\": {\"tiles\": 9, \"rays/total\": "));
    }
}

/* The pids of rayes processes whose command line holds tag. */
static int find_ranks(const char *tag, pid_t *pids, int max)
{
    int n = 0;
    DIR *proc = opendir("/proc");
    struct dirent *e;
    while (proc && (e = readdir(proc)) && n < max) {
        char path[300], cmd[4096];
        if (e->d_name[0] < '0' || e->d_name[0] > '9')
            continue;
        snprintf(path, sizeof path, "/proc/%s/cmdline", e->d_name);
        FILE *f = fopen(path, "rb");
        size_t len = f ? fread(cmd, 1, sizeof cmd - 1, f) : 0;
        if (f)
            fclose(f);
        cmd[len] = '\0';
        for (size_t i = 0; i + 1 < len; i++)
            if (cmd[i] == '\0')
                cmd[i] = ' ';
        if (strstr(cmd, tag) && strstr(cmd, "rayes render") && !strstr(cmd, "mpirun") &&
            !strstr(cmd, "sh -c"))
            pids[n++] = (pid_t)atoi(e->d_name);
    }
    if (proc)
        closedir(proc);
    return n;
}

static void test_dead_rank_ends_the_job(void)
{
    if (!have_mpi())
        return;
    unlink(SCRATCH "/killed.exr");
    char cmd[2048], mpi[256];
    mpirun(mpi, sizeof mpi, 3);
    snprintf(cmd, sizeof cmd,
             "ASAN_OPTIONS=detect_leaks=0 timeout 120 %s %s render cornell --res 256 --spp 256 --threads 1 --quiet -o "
             SCRATCH "/killed.exr >" SCRATCH "/killed.txt 2>&1",
             mpi, RAYES_BIN);
    fflush(NULL);
    pid_t job = fork();
    if (job == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    pid_t ranks[8];
    int n = 0;
    for (int i = 0; i < 3000 && n < 3; i++) { /* up to 30 s for the three ranks */
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
        n = find_ranks("killed.exr", ranks, 8);
    }
    CHECK(n == 3);
    struct timespec ts = {0, 500000000};
    nanosleep(&ts, NULL);
    if (n > 0)
        kill(ranks[n - 1], SIGKILL);
    int st = 0;
    waitpid(job, &st, 0);
    int code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    fprintf(stderr, "mpirun after a rank was killed: status %d\n", code);
    CHECK(code != 0 && code != 124); /* failed, and not by the timeout */
    CHECK(!file_exists(SCRATCH "/killed.exr"));
}

TEST_MAIN(TEST(test_same_bytes_as_one_process), TEST(test_dead_rank_ends_the_job))
