/*
 * app/distribute.c — a frame over the ranks of an Open MPI job
 * (distribute.h).
 *
 * Messages (MPI_COMM_WORLD, point to point):
 *   TAG_ASK   rank r -> 0, empty: a render thread of r wants a tile
 *   TAG_GIVE  0 -> r, one int: the tile's index, or -1: none left
 *   TAG_TILE  r -> 0, bytes: x y w h (4 ints), w h 4 floats of pixels, then
 *             w h k floats of their AOVs (k = rayes_aov_channels, often 0)
 *   TAG_DONE  r -> 0, STAT_COUNT doubles: r's statistics; its last message
 * A rank's messages to rank 0 arrive in the order sent (MPI's ordering
 * between one pair on one communicator), so its tiles precede its DONE.
 *
 * Threads: MPI is asked for MPI_THREAD_MULTIPLE and needs at least
 * MPI_THREAD_SERIALIZED: every MPI call here is made under mpi_lock.
 * Rank 0's answering thread polls (MPI_Iprobe, then a 0.2 ms sleep)
 * rather than blocking, so it never holds the lock while waiting.
 *
 * A rank that dies ends the job through mpirun (Open MPI aborts the other
 * ranks and reports which rank died and how), never a hang here.
 */
#include "app/distribute.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/stats_json.h"

#ifdef RAYES_HAVE_MPI
#include <mpi.h>
#include <pthread.h>
#include <time.h>

#include "app/tiles.h"

enum { TAG_ASK = 1, TAG_GIVE = 2, TAG_TILE = 3, TAG_DONE = 4 };

/* The statistics a rank reports (rayes_stats names; hit rates are
 * weighted by lookups when added up). */
static const char *const stat_names[] = {
    "rays/total",          "rays/shadow",         "rays/diffuse",          "shading_points/total",
    "cache/coarse/lookups", "cache/medium/lookups", "cache/fine/lookups",   "cache/coarse/hit_rate",
    "cache/medium/hit_rate", "cache/fine/hit_rate", "time/prepare_s",       "time/render_s"};
#define STAT_COUNT (int)(sizeof stat_names / sizeof stat_names[0])
#define STAT_TILES STAT_COUNT /* one more: the tiles the rank rendered */

struct Distributed {
    int rank, size;
    pthread_mutex_t mpi_lock;   /* every MPI call */
    pthread_mutex_t tiles_lock; /* rank 0: next, tiles_of; other ranks: aov */
    /* the frame */
    TileGrid g;
    int width;
    int next;                   /* rank 0: tiles handed out */
    int (*band)[2];             /* rank 0: per rank, its band's tiles not handed out [lo, hi) */
    int *owner;                 /* rank 0: per tile, the rank that rendered it */
    float *remote;              /* rank 0: the other ranks' tiles, width x height x 4 */
    int k;                      /* AOV channels a pixel (RayesRenderOptions.aovs) */
    float *remote_aov;          /* rank 0: the other ranks' AOVs, width x height x k */
    const float *aov;           /* other ranks: the frame's AOVs (tile_aov_done's) */
    double (*stats)[STAT_COUNT + 1]; /* rank 0: per rank */
    int rendered;               /* this rank's tiles */
    pthread_t answering;
    int answering_started;
    char error[300];
};

static double stat_value(const RayesStats *s, const char *name)
{
    const RayesStat *st = s ? rayes_stats_find(s, name) : NULL;
    return !st ? 0.0 : st->kind == RAYES_STAT_REAL ? st->real : (double)st->count;
}

Distributed *distribute_begin(int *argc, char ***argv)
{
    const char *size = getenv("OMPI_COMM_WORLD_SIZE");
    if (!size || atoi(size) < 2)
        return NULL; /* not under mpirun, or one rank: no MPI at all */
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "rayes: MPI_Init failed\n");
        exit(1);
    }
    Distributed *d = calloc(1, sizeof *d);
    if (!d || provided < MPI_THREAD_SERIALIZED) {
        fprintf(stderr, "rayes: %s\n",
                d ? "MPI gives no MPI_THREAD_SERIALIZED support" : "out of memory");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    pthread_mutex_init(&d->mpi_lock, NULL);
    pthread_mutex_init(&d->tiles_lock, NULL);
    return d;
}

int distribute_rank(const Distributed *d)
{
    return d ? d->rank : 0;
}

/* ------------------------------------------------------------ rank 0 */

/* The next tile for a rank, or -1. Each rank has a band of the frame's
 * tiles (row by row, a size-th of them), which it takes from the front,
 * so that its cache holds radiosity of one region; a rank whose band is
 * done takes from the back of the band with the most left. */
static int take_tile(Distributed *d, int rank)
{
    pthread_mutex_lock(&d->tiles_lock);
    int b = rank;
    if (d->band[b][0] >= d->band[b][1]) {
        b = -1;
        for (int k = 0, most = 0; k < d->size; k++)
            if (d->band[k][1] - d->band[k][0] > most)
                b = k, most = d->band[k][1] - d->band[k][0];
    }
    int t = b < 0 ? -1 : b == rank ? d->band[b][0]++ : --d->band[b][1];
    if (t >= 0) {
        d->owner[t] = rank;
        d->next++;
    }
    pthread_mutex_unlock(&d->tiles_lock);
    return t;
}

static int local_source(void *user, int tiles_x, int tiles_y)
{
    Distributed *d = user;
    (void)tiles_x, (void)tiles_y;
    int t = take_tile(d, 0);
    d->rendered += t >= 0;
    return t;
}

/* A TILE message's pixels into d->remote. */
static void put_tile(Distributed *d, const unsigned char *buf, int n)
{
    int r[4];
    if (n < (int)sizeof r)
        return;
    memcpy(r, buf, sizeof r);
    if (r[0] < 0 || r[1] < 0 || r[2] <= 0 || r[3] <= 0 || r[0] + r[2] > d->g.crop[2] ||
        r[1] + r[3] > d->g.crop[3] ||
        n != (int)(sizeof r + sizeof(float) * (size_t)(4 + d->k) * r[2] * r[3]))
        return;
    const float *px = (const float *)(buf + sizeof r);
    for (int y = 0; y < r[3]; y++)
        memcpy(&d->remote[4 * ((size_t)(r[1] + y) * d->width + r[0])], px + 4 * y * r[2],
               sizeof(float) * 4 * (size_t)r[2]);
    px += 4 * (size_t)r[2] * r[3];
    for (int y = 0; y < r[3] && d->k; y++)
        memcpy(&d->remote_aov[(size_t)d->k * ((size_t)(r[1] + y) * d->width + r[0])],
               px + (size_t)d->k * y * r[2], sizeof(float) * (size_t)d->k * (size_t)r[2]);
}

/* Rank 0's answering thread: tiles to the asking ranks, their tiles and
 * statistics in, until every other rank has said DONE. */
static void *answer(void *arg)
{
    Distributed *d = arg;
    int done = 0;
    while (done < d->size - 1) {
        int flag = 0;
        MPI_Status st;
        pthread_mutex_lock(&d->mpi_lock);
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
        if (flag && st.MPI_TAG == TAG_ASK) {
            MPI_Recv(NULL, 0, MPI_BYTE, st.MPI_SOURCE, TAG_ASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            int t = take_tile(d, st.MPI_SOURCE);
            MPI_Send(&t, 1, MPI_INT, st.MPI_SOURCE, TAG_GIVE, MPI_COMM_WORLD);
        } else if (flag && st.MPI_TAG == TAG_TILE) {
            int n = 0;
            MPI_Get_count(&st, MPI_BYTE, &n);
            unsigned char *buf = malloc(n > 0 ? (size_t)n : 1);
            MPI_Recv(buf, n, MPI_BYTE, st.MPI_SOURCE, TAG_TILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            if (buf)
                put_tile(d, buf, n);
            free(buf);
        } else if (flag && st.MPI_TAG == TAG_DONE) {
            MPI_Recv(d->stats[st.MPI_SOURCE], STAT_COUNT + 1, MPI_DOUBLE, st.MPI_SOURCE,
                     TAG_DONE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            done++;
        }
        pthread_mutex_unlock(&d->mpi_lock);
        if (!flag) {
            struct timespec ts = {0, 200000};
            nanosleep(&ts, NULL);
        }
    }
    return NULL;
}

/* ------------------------------------------------------- other ranks */

static int remote_source(void *user, int tiles_x, int tiles_y)
{
    Distributed *d = user;
    (void)tiles_x, (void)tiles_y;
    int t = -1;
    pthread_mutex_lock(&d->mpi_lock);
    MPI_Send(NULL, 0, MPI_BYTE, 0, TAG_ASK, MPI_COMM_WORLD);
    MPI_Recv(&t, 1, MPI_INT, 0, TAG_GIVE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    pthread_mutex_unlock(&d->mpi_lock);
    d->rendered += t >= 0; /* the render calls sources one at a time */
    return t;
}

/* Just before send_tile, on the same thread: where the frame's AOVs are
 * (the same buffer for every tile of a frame). */
static void note_aov(void *user, int x, int y, int w, int h, const float *aov, int channels,
                     int stride)
{
    Distributed *d = user;
    (void)x, (void)y, (void)w, (void)h, (void)stride;
    pthread_mutex_lock(&d->tiles_lock); /* render threads write it at once */
    if (channels == d->k)
        d->aov = aov;
    pthread_mutex_unlock(&d->tiles_lock);
}

static void send_tile(void *user, int x, int y, int w, int h, const float *rgba, int stride)
{
    Distributed *d = user;
    int r[4] = {x, y, w, h};
    pthread_mutex_lock(&d->tiles_lock);
    const float *frame_aov = d->aov;
    pthread_mutex_unlock(&d->tiles_lock);
    int k = frame_aov ? d->k : 0; /* rank 0 refuses a tile short of its AOVs */
    size_t n = sizeof r + sizeof(float) * (size_t)(4 + k) * (size_t)w * (size_t)h;
    unsigned char *buf = malloc(n);
    if (!buf) {
        fprintf(stderr, "rayes: rank %d: out of memory\n", d->rank);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    memcpy(buf, r, sizeof r);
    for (int j = 0; j < h; j++)
        memcpy(buf + sizeof r + sizeof(float) * 4 * (size_t)j * w,
               &rgba[4 * ((size_t)(y + j) * stride + x)], sizeof(float) * 4 * (size_t)w);
    unsigned char *aov = buf + sizeof r + sizeof(float) * 4 * (size_t)w * h;
    for (int j = 0; j < h && k; j++)
        memcpy(aov + sizeof(float) * (size_t)k * j * w,
               &frame_aov[(size_t)k * ((size_t)(y + j) * stride + x)],
               sizeof(float) * (size_t)k * (size_t)w);
    pthread_mutex_lock(&d->mpi_lock);
    MPI_Send(buf, (int)n, MPI_BYTE, 0, TAG_TILE, MPI_COMM_WORLD);
    pthread_mutex_unlock(&d->mpi_lock);
    free(buf);
}

/* ------------------------------------------------------------ frames */

int distribute_frame_begin(Distributed *d, RayesRenderOptions *o, char *err, size_t err_size)
{
    d->g = tile_grid(o);
    d->width = o->width;
    d->next = 0;
    d->rendered = 0;
    d->k = rayes_aov_channels(o->aovs);
    d->aov = NULL;
    if (d->rank != 0) {
        o->tile_source = remote_source;
        o->tile_source_user = d;
        o->tile_done = send_tile;
        o->tile_aov_done = d->k ? note_aov : NULL;
        o->tile_user = d;
        return 0;
    }
    free(d->owner), free(d->remote), free(d->remote_aov), free(d->stats), free(d->band);
    d->band = calloc((size_t)d->size, sizeof *d->band);
    for (int r = 0; d->band && r < d->size; r++) {
        d->band[r][0] = (int)((long)tile_count(&d->g) * r / d->size);
        d->band[r][1] = (int)((long)tile_count(&d->g) * (r + 1) / d->size);
    }
    d->owner = calloc((size_t)tile_count(&d->g) + 1, sizeof *d->owner);
    d->remote = calloc((size_t)o->width * (size_t)o->height * 4, sizeof(float));
    d->remote_aov =
        d->k ? calloc((size_t)o->width * (size_t)o->height * (size_t)d->k, sizeof(float)) : NULL;
    d->stats = calloc((size_t)d->size, sizeof *d->stats);
    if (!d->owner || !d->remote || (d->k && !d->remote_aov) || !d->stats || !d->band) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    o->tile_source = local_source;
    o->tile_source_user = d;
    d->answering_started = pthread_create(&d->answering, NULL, answer, d) == 0;
    if (!d->answering_started) {
        snprintf(err, err_size, "cannot start the thread that hands out tiles");
        return -1;
    }
    return 0;
}

int distribute_frame_end(Distributed *d, RayesImage *img, const RayesStats *stats, char *err,
                         size_t err_size)
{
    double mine[STAT_COUNT + 1];
    for (int k = 0; k < STAT_COUNT; k++)
        mine[k] = stat_value(stats, stat_names[k]);
    mine[STAT_TILES] = d->rendered;
    if (d->rank != 0) {
        pthread_mutex_lock(&d->mpi_lock);
        MPI_Send(mine, STAT_COUNT + 1, MPI_DOUBLE, 0, TAG_DONE, MPI_COMM_WORLD);
        pthread_mutex_unlock(&d->mpi_lock);
        return 0;
    }
    if (d->answering_started)
        pthread_join(d->answering, NULL);
    d->answering_started = 0;
    memcpy(d->stats[0], mine, sizeof mine);
    if (!img)
        return 0;
    int left = tile_count(&d->g) - d->next; /* never handed out: a render cancelled */
    for (int t = 0; t < tile_count(&d->g); t++) {
        int q[4];
        tile_rect(&d->g, t, q);
        if (d->owner[t] == 0)
            continue;
        for (int y = 0; y < q[3]; y++) {
            size_t at = (size_t)(q[1] + y) * d->width + q[0];
            memcpy(&img->rgba[4 * at], &d->remote[4 * at], sizeof(float) * 4 * (size_t)q[2]);
            if (d->k && img->aov && img->aov_channels == d->k)
                memcpy(&img->aov[(size_t)d->k * at], &d->remote_aov[(size_t)d->k * at],
                       sizeof(float) * (size_t)d->k * (size_t)q[2]);
        }
    }
    if (left) {
        snprintf(err, err_size, "%d tiles were never rendered", left);
        return -1;
    }
    return 0;
}

void distribute_print_summary(const Distributed *d, FILE *out)
{
    if (!d || d->rank != 0 || !d->stats)
        return;
    double total[STAT_COUNT + 1] = {0}, hits[3] = {0};
    for (int r = 0; r < d->size; r++) {
        const double *s = d->stats[r];
        fprintf(out,
                "  rank %-3d      %.0f tiles, %.0f rays, %.0f shading pts, fine hit rate "
                "%.2f%%, %.2f s prepare, %.2f s render\n",
                r, s[STAT_TILES], s[0], s[3], 100.0 * s[9], s[10], s[11]);
        for (int k = 0; k <= STAT_COUNT; k++)
            total[k] += s[k];
        for (int l = 0; l < 3; l++)
            hits[l] += s[7 + l] * s[4 + l];
    }
    fprintf(out,
            "  all ranks     %d ranks, %.0f tiles, %.0f rays, %.0f shading pts, hit rates "
            "%.2f / %.2f / %.2f%%\n",
            d->size, total[STAT_TILES], total[0], total[3],
            total[4] > 0 ? 100.0 * hits[0] / total[4] : 0.0,
            total[5] > 0 ? 100.0 * hits[1] / total[5] : 0.0,
            total[6] > 0 ? 100.0 * hits[2] / total[6] : 0.0);
}

int distribute_save_stats(const Distributed *d, const char *path, const RayesStats *stats,
                          const char *scene, char *err, size_t err_size)
{
    if (!d || !d->stats)
        return io_stats_json_save(path, stats, scene, err, err_size) == RAYES_OK ? 0 : -1;
    /* rank 0's statistics as usual, then "mpi": every rank's and their sum */
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    if (!mem) {
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    io_stats_json_write(mem, stats, scene);
    fclose(mem);
    while (len > 0 && (text[len - 1] == '\n' || text[len - 1] == '}'))
        if (text[--len] == '}')
            break;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        free(text);
        snprintf(err, err_size, "%s: cannot write", tmp);
        return -1;
    }
    fwrite(text, 1, len, f);
    free(text);
    double total[STAT_COUNT + 1] = {0}, hits[3] = {0};
    fprintf(f, ",\n  \"mpi\": {\"ranks\": %d, \"per_rank\": [", d->size);
    for (int r = 0; r < d->size; r++) {
        const double *v = d->stats[r];
        fprintf(f, "%s\n    {\"rank\": %d, \"tiles\": %.0f", r ? "," : "", r, v[STAT_TILES]);
        for (int k = 0; k < STAT_COUNT; k++)
            fprintf(f, ", \"%s\": %.17g", stat_names[k], v[k]);
        fprintf(f, "}");
        for (int k = 0; k <= STAT_COUNT; k++)
            total[k] += v[k];
        for (int l = 0; l < 3; l++)
            hits[l] += v[7 + l] * v[4 + l];
    }
    fprintf(f, "],\n    \"total\": {\"tiles\": %.0f", total[STAT_TILES]);
    for (int k = 0; k < 7; k++) /* the counts; hit rates weighted by lookups */
        fprintf(f, ", \"%s\": %.17g", stat_names[k], total[k]);
    for (int l = 0; l < 3; l++)
        fprintf(f, ", \"%s\": %.17g", stat_names[7 + l],
                total[4 + l] > 0 ? hits[l] / total[4 + l] : 0.0);
    fprintf(f, "}}\n}\n");
    if (fclose(f) != 0 || rename(tmp, path) != 0) {
        unlink(tmp);
        snprintf(err, err_size, "%s: cannot write", path);
        return -1;
    }
    return 0;
}

void distribute_end(Distributed *d)
{
    if (!d)
        return;
    MPI_Finalize();
    free(d->owner), free(d->remote), free(d->remote_aov), free(d->stats), free(d->band);
    pthread_mutex_destroy(&d->mpi_lock);
    pthread_mutex_destroy(&d->tiles_lock);
    free(d);
}

#else /* without Open MPI: one process, always */

Distributed *distribute_begin(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    const char *size = getenv("OMPI_COMM_WORLD_SIZE");
    if (size && atoi(size) > 1) {
        fprintf(stderr, "rayes: started by mpirun, but built without Open MPI "
                        "(apt-get install libopenmpi-dev, then rebuild)\n");
        exit(1);
    }
    return NULL;
}

int distribute_rank(const Distributed *d)
{
    (void)d;
    return 0;
}

int distribute_frame_begin(Distributed *d, RayesRenderOptions *o, char *err, size_t err_size)
{
    (void)d, (void)o, (void)err, (void)err_size;
    return 0;
}

int distribute_frame_end(Distributed *d, RayesImage *img, const RayesStats *stats, char *err,
                         size_t err_size)
{
    (void)d, (void)img, (void)stats, (void)err, (void)err_size;
    return 0;
}

void distribute_print_summary(const Distributed *d, FILE *out)
{
    (void)d, (void)out;
}

int distribute_save_stats(const Distributed *d, const char *path, const RayesStats *stats,
                          const char *scene, char *err, size_t err_size)
{
    (void)d;
    return io_stats_json_save(path, stats, scene, err, err_size) == RAYES_OK ? 0 : -1;
}

void distribute_end(Distributed *d)
{
    (void)d;
}

#endif
