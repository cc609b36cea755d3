/*
 * io/stats_json.c — the JSON writer of stats_json.h. Nesting follows the
 * slash-separated names: when a name's prefix differs from the previous
 * one, the objects that end are closed and the new ones opened.
 */
#include "io/stats_json.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define MAX_DEPTH 8

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* Splits name into at most MAX_DEPTH components; returns their count. */
static int split(const char *name, char parts[MAX_DEPTH][64])
{
    int n = 0;
    while (*name && n < MAX_DEPTH) {
        const char *slash = strchr(name, '/');
        size_t len = slash ? (size_t)(slash - name) : strlen(name);
        snprintf(parts[n++], 64, "%.*s", (int)len, name);
        name += len + (slash ? 1 : 0);
    }
    return n;
}

static void indent(FILE *f, int depth)
{
    for (int i = 0; i < depth; i++)
        fputs("  ", f);
}

static void value(FILE *f, const RayesStat *s)
{
    switch (s->kind) {
    case RAYES_STAT_COUNT: fprintf(f, "%llu", (unsigned long long)s->count); break;
    case RAYES_STAT_REAL: fprintf(f, "%.6g", s->real); break;
    case RAYES_STAT_STRING: json_string(f, s->string ? s->string : ""); break;
    case RAYES_STAT_COUNTS:
        fputc('[', f);
        for (size_t i = 0; i < s->n_counts; i++)
            fprintf(f, "%s%llu", i ? ", " : "", (unsigned long long)s->counts[i]);
        fputc(']', f);
        break;
    }
}

/* Starts a member of the innermost open object: a comma unless it is the
 * object's first, a new line, the indented key. */
static void key(FILE *f, int depth, const char *name, int *fresh)
{
    fputs(*fresh ? "\n" : ",\n", f);
    indent(f, depth + 1);
    json_string(f, name);
    fputs(": ", f);
    *fresh = 0;
}

void io_stats_json_write(FILE *f, const RayesStats *stats, const char *scene)
{
    char open[MAX_DEPTH][64];
    int n_open = 0, fresh = 1;
    fputc('{', f);
    key(f, 0, "scene", &fresh);
    json_string(f, scene ? scene : "");
    for (size_t i = 0; i < rayes_stats_size(stats); i++) {
        const RayesStat *s = rayes_stats_get(stats, i);
        char parts[MAX_DEPTH][64];
        int n = split(s->name, parts);
        int common = 0;
        while (common < n_open && common < n - 1 && strcmp(open[common], parts[common]) == 0)
            common++;
        for (; n_open > common; n_open--) {
            fputc('\n', f);
            indent(f, n_open);
            fputc('}', f);
        }
        for (int k = common; k < n - 1; k++) {
            key(f, n_open, parts[k], &fresh);
            fputc('{', f);
            snprintf(open[n_open++], 64, "%s", parts[k]);
            fresh = 1;
        }
        key(f, n_open, parts[n - 1], &fresh);
        value(f, s);
    }
    for (; n_open > 0; n_open--) {
        fputc('\n', f);
        indent(f, n_open);
        fputc('}', f);
    }
    fputs("\n}\n", f);
}

RayesError io_stats_json_save(const char *path, const RayesStats *stats, const char *scene,
                              char *err, size_t err_size)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(err, err_size, "%s: cannot write: %s", path, strerror(errno));
        return RAYES_ERROR_IO;
    }
    io_stats_json_write(f, stats, scene);
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        snprintf(err, err_size, "%s: cannot write: %s", path, strerror(errno));
        unlink(tmp);
        return RAYES_ERROR_IO;
    }
    return RAYES_OK;
}
