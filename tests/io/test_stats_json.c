/*
 * tests/io/test_stats_json.c — the statistics JSON of io/stats_json.h: a
 * 16 x 16, 1 spp render of the built-in "cornell" scene through the public
 * API, written to a file and read back by a small strict JSON parser (in
 * this file, RFC 8259 syntax; it rejects what python's json.load would)
 * that checks the nested keys the command line promises and that
 * rays/total is the sum of the four ray types. Also: the parser itself
 * rejects broken JSON, scene names are escaped, and a save into a missing
 * directory fails with one line and leaves nothing behind.
 *
 * Scratch files go under RAYES_TEST_TMP/io_stats_json (other tests share
 * RAYES_TEST_TMP and may run at the same time).
 */
#include <ctype.h>
#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "io/stats_json.h"
#include "rayes/rayes.h"
#include "test.h"

#ifndef RAYES_TEST_TMP
#error "RAYES_TEST_TMP must name a scratch directory"
#endif

#define SCRATCH_DIR RAYES_TEST_TMP "/io_stats_json"

/* ------------------------------------------------- a small JSON reader */

typedef enum JsonType { J_NULL, J_BOOL, J_NUMBER, J_STRING, J_ARRAY, J_OBJECT } JsonType;

#define JSON_MAX_NODES 512

/* A parsed document: nodes in document order; a node's children follow it
 * and have it as parent. */
typedef struct JsonNode {
    JsonType type;
    int parent;       /* index of the enclosing array or object, -1 for the root */
    char key[64];     /* member name inside an object, "" otherwise */
    double number;    /* J_NUMBER */
    char string[256]; /* J_STRING, unescaped (\u escapes below 0x80 only) */
    int n_children;
} JsonNode;

typedef struct Json {
    const char *p, *end;
    JsonNode nodes[JSON_MAX_NODES];
    int n;
    int depth;
} Json;

static int json_value(Json *j, int parent, const char *key);

static void json_ws(Json *j)
{
    while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r'))
        j->p++;
}

static int json_lit(Json *j, const char *word)
{
    size_t n = strlen(word);
    if ((size_t)(j->end - j->p) < n || memcmp(j->p, word, n) != 0)
        return -1;
    j->p += n;
    return 0;
}

/* A string into out (truncated to size); -1 on bad syntax. */
static int json_string(Json *j, char *out, size_t size)
{
    size_t n = 0;
    if (j->p >= j->end || *j->p != '"')
        return -1;
    j->p++;
    while (j->p < j->end && *j->p != '"') {
        unsigned char c = (unsigned char)*j->p++;
        if (c < 0x20)
            return -1;
        if (c == '\\') {
            if (j->p >= j->end)
                return -1;
            char e = *j->p++;
            const char *from = "\"\\/bfnrt", *to = "\"\\/\b\f\n\r\t";
            if (e == 'u') {
                unsigned v = 0;
                for (int k = 0; k < 4; k++, j->p++) {
                    if (j->p >= j->end || !isxdigit((unsigned char)*j->p))
                        return -1;
                    v = v * 16 + (unsigned)(isdigit((unsigned char)*j->p)
                                                ? *j->p - '0'
                                                : tolower((unsigned char)*j->p) - 'a' + 10);
                }
                c = v < 0x80 ? (unsigned char)v : '?';
            } else if (e != '\0' && strchr(from, e)) {
                c = (unsigned char)to[strchr(from, e) - from];
            } else {
                return -1;
            }
        }
        if (n + 1 < size)
            out[n++] = (char)c;
    }
    if (j->p >= j->end)
        return -1;
    j->p++;
    out[n] = '\0';
    return 0;
}

/* A number by the JSON grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)? */
static int json_number(Json *j, double *out)
{
    const char *s = j->p;
    const char *q = s;
    if (q < j->end && *q == '-')
        q++;
    if (q < j->end && *q == '0')
        q++;
    else if (q < j->end && *q >= '1' && *q <= '9')
        while (q < j->end && isdigit((unsigned char)*q))
            q++;
    else
        return -1;
    if (q < j->end && *q == '.') {
        if (++q >= j->end || !isdigit((unsigned char)*q))
            return -1;
        while (q < j->end && isdigit((unsigned char)*q))
            q++;
    }
    if (q < j->end && (*q == 'e' || *q == 'E')) {
        q++;
        if (q < j->end && (*q == '+' || *q == '-'))
            q++;
        if (q >= j->end || !isdigit((unsigned char)*q))
            return -1;
        while (q < j->end && isdigit((unsigned char)*q))
            q++;
    }
    char buf[64];
    if ((size_t)(q - s) >= sizeof buf)
        return -1;
    memcpy(buf, s, (size_t)(q - s));
    buf[q - s] = '\0';
    *out = strtod(buf, NULL);
    j->p = q;
    return 0;
}

/* Members or elements after the opening bracket, up to the closing one. */
static int json_container(Json *j, int self, char close)
{
    json_ws(j);
    if (j->p < j->end && *j->p == close) {
        j->p++;
        return 0;
    }
    for (;;) {
        char key[64] = "";
        json_ws(j);
        if (close == '}') {
            if (json_string(j, key, sizeof key) != 0)
                return -1;
            json_ws(j);
            if (j->p >= j->end || *j->p++ != ':')
                return -1;
        }
        if (json_value(j, self, key) != 0)
            return -1;
        j->nodes[self].n_children++;
        json_ws(j);
        if (j->p >= j->end)
            return -1;
        char c = *j->p++;
        if (c == close)
            return 0;
        if (c != ',')
            return -1;
    }
}

static int json_value(Json *j, int parent, const char *key)
{
    json_ws(j);
    if (j->n == JSON_MAX_NODES || j->depth > 32 || j->p >= j->end)
        return -1;
    int self = j->n++;
    JsonNode *node = &j->nodes[self];
    memset(node, 0, sizeof *node);
    node->parent = parent;
    snprintf(node->key, sizeof node->key, "%s", key);
    char c = *j->p;
    int r;
    j->depth++;
    if (c == '{' || c == '[') {
        node->type = c == '{' ? J_OBJECT : J_ARRAY;
        j->p++;
        r = json_container(j, self, c == '{' ? '}' : ']');
    } else if (c == '"') {
        node->type = J_STRING;
        r = json_string(j, node->string, sizeof node->string);
    } else if (c == 't' || c == 'f') {
        node->type = J_BOOL;
        r = json_lit(j, c == 't' ? "true" : "false");
    } else if (c == 'n') {
        node->type = J_NULL;
        r = json_lit(j, "null");
    } else {
        node->type = J_NUMBER;
        r = json_number(j, &node->number);
    }
    j->depth--;
    return r;
}

/* Parses a whole document (nothing but white space after the value);
 * returns 0 or -1. Duplicate keys in an object are an error too. */
static int json_parse(Json *j, const char *text, size_t size)
{
    j->p = text;
    j->end = text + size;
    j->n = 0;
    j->depth = 0;
    if (json_value(j, -1, "") != 0)
        return -1;
    json_ws(j);
    if (j->p != j->end)
        return -1;
    for (int a = 0; a < j->n; a++)
        for (int b = a + 1; b < j->n; b++)
            if (j->nodes[a].parent == j->nodes[b].parent && j->nodes[a].parent >= 0 &&
                j->nodes[j->nodes[a].parent].type == J_OBJECT &&
                strcmp(j->nodes[a].key, j->nodes[b].key) == 0)
                return -1;
    return 0;
}

/* The node at a slash-separated path of object keys ("rays/total"), or NULL. */
static const JsonNode *json_find(const Json *j, const char *path)
{
    int at = 0;
    while (*path) {
        const char *slash = strchr(path, '/');
        size_t len = slash ? (size_t)(slash - path) : strlen(path);
        int next = -1;
        for (int k = at + 1; k < j->n && next < 0; k++)
            if (j->nodes[k].parent == at && strlen(j->nodes[k].key) == len &&
                strncmp(j->nodes[k].key, path, len) == 0)
                next = k;
        if (next < 0 || j->nodes[at].type != J_OBJECT)
            return NULL;
        at = next;
        path += len + (slash ? 1 : 0);
    }
    return &j->nodes[at];
}

static int json_ok(const char *text)
{
    static Json j;
    return json_parse(&j, text, strlen(text)) == 0;
}

/* ------------------------------------------------------------- helpers */

static const char *scratch(char *buf, size_t n, const char *name)
{
    mkdir(SCRATCH_DIR, 0777); /* EEXIST is fine */
    snprintf(buf, n, "%s/%s", SCRATCH_DIR, name);
    return buf;
}

/* The whole file, NUL-terminated (free()), or NULL. */
static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = malloc(1 << 16);
    size_t n = buf ? fread(buf, 1, (1 << 16) - 1, f) : 0;
    fclose(f);
    if (buf)
        buf[n] = '\0';
    *size = n;
    return buf;
}

/* Renders the built-in scene at 16 x 16, 1 spp; the stats are new. */
static RayesStats *render_cornell(void)
{
    RayesScene *scene = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(scene);
    RayesError e = io_builtin_scene("cornell", NULL, &sink, err, sizeof err);
    if (e == RAYES_OK)
        e = rayes_scene_commit(scene);
    CHECK(e == RAYES_OK);
    if (e != RAYES_OK) {
        fprintf(stderr, "  %s\n", err);
        rayes_scene_release(scene);
        return NULL;
    }
    RayesRenderOptions opt;
    rayes_render_options_init(&opt, RAYES_QUALITY_PREVIEW);
    opt.width = opt.height = 16;
    opt.spp = 1;
    opt.threads = 2;
    RayesImage *img = NULL;
    RayesStats *stats = NULL;
    CHECK(rayes_render(scene, &opt, &img, &stats) == RAYES_OK);
    CHECK(img != NULL && stats != NULL);
    rayes_image_free(img);
    rayes_scene_release(scene);
    return stats;
}

/* --------------------------------------------------------------- tests */

/* The checker must be a real one: it fails on each kind of broken JSON. */
static void test_checker_rejects_bad_json(void)
{
    CHECK(json_ok("{\"a\": {\"b\": [1, 2.5e-3, -0]}, \"c\": \"x\\n\\u0041\", \"d\": null}"));
    CHECK(json_ok(" [true, false, {}, []] \n"));
    static const char *const bad[] = {
        "",       "{",          "{\"a\": 1,}",     "{\"a\" 1}",       "{a: 1}",
        "[1 2]",  "[1,]",       "{\"a\": nan}",    "{\"a\": inf}",    "{\"a\": 01}",
        "{\"a\": 1.}", "{\"a\": .5}", "{\"a\": \"x\ny\"}", "{\"a\": 1} {}", "{\"a\": 1, \"a\": 2}",
        "{\"a\": \"\\x\"}", "{\"a\": tru}", "{\"a\": 1}}", "'a'",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(!json_ok(bad[i]));
        if (json_ok(bad[i]))
            fprintf(stderr, "  accepted: %s\n", bad[i]);
    }
}

static void test_render_stats_file(void)
{
    RayesStats *stats = render_cornell();
    if (!stats)
        return;
    char path[512], err[512];
    scratch(path, sizeof path, "stats.json");
    remove(path);
    CHECK(io_stats_json_save(path, stats, "cornell", err, sizeof err) == RAYES_OK);
    rayes_stats_free(stats);

    size_t size = 0;
    char *text = slurp(path, &size);
    CHECK(text != NULL);
    if (!text)
        return;
    static Json j;
    int valid = json_parse(&j, text, size) == 0;
    CHECK(valid);
    CHECK(size > 0 && text[size - 1] == '\n');
    if (!valid)
        fprintf(stderr, "  not valid JSON:\n%s\n", text);
    free(text);
    if (!valid)
        return;
    CHECK(j.nodes[0].type == J_OBJECT);

    static const char *const numbers[] = {
        "time/total_s", "time/prepare_s", "time/render_s", "shading_points/total",
        "rays/total", "rays/camera", "rays/shadow", "rays/diffuse", "rays/specular", "grids",
        "grid_vertices", "memory/peak_rss_bytes", "spp", "threads",
    };
    for (size_t i = 0; i < sizeof numbers / sizeof numbers[0]; i++) {
        const JsonNode *n = json_find(&j, numbers[i]);
        CHECK(n != NULL && n->type == J_NUMBER && n->number >= 0.0);
        if (!n || n->type != J_NUMBER)
            fprintf(stderr, "  missing number %s\n", numbers[i]);
    }
    const JsonNode *scene = json_find(&j, "scene");
    CHECK(scene && scene->type == J_STRING && strcmp(scene->string, "cornell") == 0);
    const JsonNode *by_depth = json_find(&j, "shading_points/by_depth");
    CHECK(by_depth && by_depth->type == J_ARRAY && by_depth->n_children >= 1);
    const JsonNode *res = json_find(&j, "resolution");
    CHECK(res && res->type == J_OBJECT);
    const JsonNode *w = json_find(&j, "resolution/width"), *h = json_find(&j, "resolution/height");
    CHECK(w && w->number == 16.0 && h && h->number == 16.0);
    CHECK(json_find(&j, "spp") && json_find(&j, "spp")->number == 1.0);
    CHECK(json_find(&j, "threads") && json_find(&j, "threads")->number == 2.0);

    const JsonNode *total = json_find(&j, "rays/total");
    double sum = 0.0;
    static const char *const kinds[] = {"rays/camera", "rays/shadow", "rays/diffuse",
                                        "rays/specular"};
    for (int k = 0; k < 4; k++)
        sum += json_find(&j, kinds[k]) ? json_find(&j, kinds[k])->number : -1e30;
    CHECK(total && total->number == sum);
    /* 16 x 16 pixels, 1 sample each: one camera ray per sample. */
    CHECK(json_find(&j, "rays/camera") && json_find(&j, "rays/camera")->number == 256.0);
    CHECK(total && total->number > 256.0);
    const JsonNode *sp = json_find(&j, "shading_points/total");
    double depth_sum = 0.0;
    int by_depth_index = by_depth ? (int)(by_depth - j.nodes) : -2;
    for (int k = 0; k < j.n; k++)
        if (j.nodes[k].parent == by_depth_index)
            depth_sum += j.nodes[k].number;
    CHECK(sp && sp->number == depth_sum && sp->number > 0.0);
    CHECK(json_find(&j, "grids") && json_find(&j, "grids")->number > 0.0);
    const JsonNode *rss = json_find(&j, "memory/peak_rss_bytes");
    CHECK(rss && rss->number > 1e5);
    const JsonNode *t = json_find(&j, "time/total_s"), *tp = json_find(&j, "time/prepare_s"),
                   *tr = json_find(&j, "time/render_s");
    CHECK(t && tp && tr && t->number + 1e-5 >= tp->number + tr->number - 1e-5);
}

/* Names with quotes, backslashes and control characters stay valid JSON. */
static void test_scene_name_escaped(void)
{
    RayesStats *stats = render_cornell();
    if (!stats)
        return;
    static const char *const names[] = {"we\"ird\\name\n\ttab\x01", "", NULL};
    static const char *const expect[] = {"we\"ird\\name\n\ttab\x01", "", ""};
    for (int i = 0; i < 3; i++) {
        char *buf = NULL;
        size_t size = 0;
        FILE *f = open_memstream(&buf, &size);
        CHECK(f != NULL);
        if (!f)
            break;
        io_stats_json_write(f, stats, names[i]);
        fclose(f);
        static Json j;
        CHECK(json_parse(&j, buf, size) == 0);
        const JsonNode *scene = json_find(&j, "scene");
        CHECK(scene && scene->type == J_STRING && strcmp(scene->string, expect[i]) == 0);
        free(buf);
    }
    rayes_stats_free(stats);
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    if (!d)
        return -1;
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

static void test_save_failure(void)
{
    RayesStats *stats = render_cornell();
    if (!stats)
        return;
    char path[512], err[512] = "";
    scratch(path, sizeof path, "missing-dir/stats.json");
    CHECK(io_stats_json_save(path, stats, "cornell", err, sizeof err) == RAYES_ERROR_IO);
    CHECK(strstr(err, "missing-dir/stats.json") != NULL);
    CHECK(strchr(err, '\n') == NULL);

    /* A save over an existing file replaces it whole and leaves no temporary. */
    char dir[512];
    scratch(dir, sizeof dir, "replace");
    mkdir(dir, 0777);
    scratch(path, sizeof path, "replace/stats.json");
    FILE *f = fopen(path, "w");
    if (f) {
        fputs("old", f);
        fclose(f);
    }
    CHECK(io_stats_json_save(path, stats, "cornell", err, sizeof err) == RAYES_OK);
    CHECK(count_entries(dir) == 1);
    size_t size = 0;
    char *text = slurp(path, &size);
    CHECK(text && json_ok(text));
    free(text);
    rayes_stats_free(stats);
}

TEST_MAIN(TEST(test_checker_rejects_bad_json), TEST(test_render_stats_file),
          TEST(test_scene_name_escaped), TEST(test_save_failure))
