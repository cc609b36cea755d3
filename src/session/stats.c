/*
 * session/stats.c — RayesStats: a flat list of named statistics in a fixed
 * order. Names and strings are static or owned by the list.
 */
#include "session/stats.h"

#include <stdlib.h>
#include <string.h>

#include "util/log.h"

#define MAX_STATS 256

struct RayesStats {
    RayesStat items[MAX_STATS];
    size_t n;
    uint64_t by_depth[RENDER_MAX_DEPTH + 1];
    uint64_t by_segment[GEOM_MAX_TIMES - 1];
};

static void count(RayesStats *s, const char *name, uint64_t v)
{
    if (s->n < MAX_STATS)
        s->items[s->n++] = (RayesStat){.name = name, .kind = RAYES_STAT_COUNT, .count = v};
}

static void real(RayesStats *s, const char *name, double v)
{
    if (s->n < MAX_STATS)
        s->items[s->n++] = (RayesStat){.name = name, .kind = RAYES_STAT_REAL, .real = v};
}

/* Object instances (DESIGN.md "Instances"): how many, the masters' grids
 * and vertices (held once), the vertices flattened copies would hold, and
 * the radiosity cache fills of instanced grids per instance (each
 * instance fills its own entries; with no eviction, fills are entries). */
static void add_instances(RayesStats *s, const RenderStats *rs, const GridSet *gs)
{
    uint64_t *vertices = calloc(gs->n_masters + 1, sizeof *vertices);
    uint64_t grids = 0, master_vertices = 0, flattened = 0, micropolygons = 0;
    for (size_t k = 0; k < gs->n_grids; k++)
        if (gs->grids[k].master) {
            const Grid *g = &gs->grids[k];
            grids++;
            master_vertices += geom_grid_n_vertices(g);
            micropolygons += g->triangular ? (uint64_t)g->nu * g->nu
                                           : (uint64_t)(g->nu - 1) * (uint64_t)(g->nv - 1);
            if (vertices)
                vertices[gs->grids[k].master] += geom_grid_n_vertices(&gs->grids[k]);
        }
    for (size_t i = 0; vertices && i < gs->n_instances; i++)
        flattened += vertices[gs->instances[i].master + 1];
    free(vertices);
    count(s, "instances/count", gs->n_instances);
    count(s, "instances/masters", gs->n_masters);
    count(s, "instances/master_grids", grids);
    count(s, "instances/master_vertices", master_vertices);
    count(s, "instances/master_micropolygons", micropolygons);
    count(s, "instances/flattened_vertices", flattened);
    count(s, "instances/radiosity_fills", rs->instance_fills);
    real(s, "instances/radiosity_entries_per_instance",
         (double)rs->instance_fills / (double)gs->n_instances);
}

RayesStats *session_stats_new(const RenderSettings *set, const RenderStats *rs, const GridSet *gs,
                              const SessionTimes *t, size_t accel_bytes)
{
    RayesStats *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    real(s, "time/total_s", t->total_s);
    real(s, "time/prepare_s", t->prepare_s);
    real(s, "time/render_s", t->render_s);
    if (t->render_cpu_s > 0.0)
        real(s, "time/render_cpu_s", t->render_cpu_s);
    if (t->pbgi) { /* in the time block: the JSON nests consecutive names */
        real(s, "time/pbgi_cloud_s", t->pbgi_cloud_s);
        real(s, "time/pbgi_bounces_s", t->pbgi_bounces_s);
        real(s, "time/pbgi_octree_s", t->pbgi_octree_s);
    }
    uint64_t total = 0;
    int deepest = 0;
    for (int d = 0; d <= RENDER_MAX_DEPTH; d++) {
        s->by_depth[d] = rs->shading_points[d];
        total += rs->shading_points[d];
        if (rs->shading_points[d])
            deepest = d;
    }
    count(s, "shading_points/total", total);
    s->items[s->n++] = (RayesStat){.name = "shading_points/by_depth", .kind = RAYES_STAT_COUNTS,
                                   .counts = s->by_depth, .n_counts = (size_t)deepest + 1};
    count(s, "rays/total", rs->rays_camera + rs->rays_shadow + rs->rays_diffuse + rs->rays_specular);
    count(s, "rays/camera", rs->rays_camera);
    count(s, "rays/shadow", rs->rays_shadow);
    count(s, "rays/diffuse", rs->rays_diffuse);
    count(s, "rays/specular", rs->rays_specular);
    count(s, "rays/transmission", rs->rays_transmission); /* of rays/shadow: they marched */
    count(s, "rays/subsurface", rs->rays_subsurface);     /* not in rays/total */
    if (set->max_spp > set->spp) {
        count(s, "adaptive/max_spp", (uint64_t)set->max_spp);
        real(s, "adaptive/error", set->adaptive_error);
        count(s, "adaptive/pixels_at_max", rs->adaptive_pixels_max);
    }
    count(s, "lighting/ambient_points", rs->ambient_lookups);
    count(s, "opacity/shading_points", rs->opacity_points);
    count(s, "opacity/transparent_hits", rs->transparent_hits);
    count(s, "opacity/holes", rs->holes);
    count(s, "opacity/hole_points", rs->hole_points);
    count(s, "opacity/table_lookups", rs->table_lookups);
    count(s, "opacity/table_fills", rs->table_fills);
    count(s, "volume/steps", rs->volume_steps);
    count(s, "subsurface/points", rs->subsurface_points);
    count(s, "subsurface/irradiance_points", rs->irradiance_points);
    count(s, "grids", gs->n_grids);
    count(s, "grid_vertices", gs->n_vertices);
    count(s, "clusters/count", gs->n_clusters);
    count(s, "clusters/lookups", rs->cluster_lookups);
    /* Motion blur: the geometry's time samples, its moving grids, and the
     * radiosity entries filled for them per motion segment. */
    uint64_t moving = 0;
    for (size_t g = 0; g < gs->n_grids; g++)
        moving += gs->grids[g].moving;
    int n_times = gs->n_times > 1 ? gs->n_times : 1;
    count(s, "motion/time_samples", (uint64_t)n_times);
    count(s, "motion/moving_grids", moving);
    memcpy(s->by_segment, rs->segment_fills, sizeof s->by_segment);
    if (s->n < MAX_STATS)
        s->items[s->n++] = (RayesStat){.name = "motion/fills_by_segment",
                                       .kind = RAYES_STAT_COUNTS, .counts = s->by_segment,
                                       .n_counts = (size_t)(n_times > 1 ? n_times - 1 : 1)};
    count(s, "grid_size", (uint64_t)set->grid_size);
    count(s, "memory/peak_rss_bytes", mem_peak_rss_bytes());
    count(s, "memory/accel_bytes", accel_bytes);
    size_t geom_bytes = gs->n_vertices * (4 * sizeof(Vec3) + 2 * sizeof(float)) +
                        gs->n_grids * sizeof(Grid) + gs->n_subs * sizeof(GridSub) +
                        (gs->grid_cluster ? gs->n_grids * sizeof *gs->grid_cluster : 0) +
                        gs->n_clusters * sizeof(GeomCluster) +
                        (size_t)(n_times - 1) * gs->n_motion_vertices * 4 * sizeof(Vec3);
    count(s, "memory/grid_bytes", geom_bytes);
    count(s, "memory/opacity_table_bytes", rs->table_bytes);
    count(s, "resolution/width", (uint64_t)set->width);
    count(s, "resolution/height", (uint64_t)set->height);
    count(s, "spp", (uint64_t)set->spp);
    count(s, "threads", (uint64_t)set->threads);
    count(s, "bounces", (uint64_t)set->bounces);
    count(s, "shadow_rays", (uint64_t)set->shadow_rays);
    count(s, "irradiance_shadow_rays", (uint64_t)set->irradiance_shadow_rays);
    count(s, "diffuse_rays", (uint64_t)set->diffuse_rays);
    if (set->irradiance) {
        count(s, "irradiance/records", rs->irradiance_records);
        count(s, "irradiance/interpolated", rs->irradiance_interpolated);
    }
    if (gs->n_instances)
        add_instances(s, rs, gs);
    if (s->n < MAX_STATS)
        s->items[s->n++] = (RayesStat){.name = "hider", .kind = RAYES_STAT_STRING,
                                       .string = set->hider ? "grid" : "raytrace"};
    return s;
}

static void session_stats_add_cache_types(RayesStats *s, const CacheStats *cs);

void session_stats_add_cache(RayesStats *s, const CacheStats *cs)
{
    static const char *const names[CACHE_N_LEVELS][8] = {
        {"cache/coarse/lookups", "cache/coarse/hits", "cache/coarse/misses", "cache/coarse/fills",
         "cache/coarse/evictions", "cache/coarse/entries", "cache/coarse/bytes",
         "cache/coarse/hit_rate"},
        {"cache/medium/lookups", "cache/medium/hits", "cache/medium/misses", "cache/medium/fills",
         "cache/medium/evictions", "cache/medium/entries", "cache/medium/bytes",
         "cache/medium/hit_rate"},
        {"cache/fine/lookups", "cache/fine/hits", "cache/fine/misses", "cache/fine/fills",
         "cache/fine/evictions", "cache/fine/entries", "cache/fine/bytes", "cache/fine/hit_rate"},
    };
    count(s, "cache/budget_bytes", cs->budget_bytes);
    count(s, "cache/peak_bytes", cs->peak_total_bytes);
    for (int l = 0; l < CACHE_N_LEVELS; l++) {
        const CacheCounters *c = &cs->counters[l][CACHE_RADIOSITY];
        count(s, names[l][0], c->lookups);
        count(s, names[l][1], c->hits);
        count(s, names[l][2], c->misses);
        count(s, names[l][3], c->fills);
        count(s, names[l][4], c->evictions);
        count(s, names[l][5], cs->entries[l]);
        count(s, names[l][6], cs->bytes[l]);
        real(s, names[l][7], c->lookups ? (double)c->hits / (double)c->lookups : 0.0);
    }
    /* What threads cost each other in the cache, every level and type:
     * lookups that waited for another thread's fill of the same entry, how
     * long, and lookups that found their shard locked. */
    uint64_t waits = 0, wait_ns = 0, contended = 0;
    for (int l = 0; l < CACHE_N_LEVELS; l++)
        for (int t = 0; t < CACHE_N_TYPES; t++) {
            waits += cs->counters[l][t].waits;
            wait_ns += cs->counters[l][t].wait_ns;
            contended += cs->counters[l][t].contended;
        }
    count(s, "cache/threads/waits", waits);
    real(s, "cache/threads/wait_s", 1e-9 * (double)wait_ns);
    count(s, "cache/threads/contended", contended);
    session_stats_add_cache_types(s, cs);
}

/* Each data type's own counters (memo 6: one cache, keys with a data
 * type): cache/radiosity/LEVEL/... and cache/opacity/LEVEL/..., for the
 * types that had a budget or lookups. */
static const char *const typed_names[4][CACHE_N_LEVELS][7] = {
#define TYPE_NAMES(t)                                                                              \
    {                                                                                              \
        {                                                                                          \
            "cache/" t "/coarse/lookups",   "cache/" t "/coarse/hits",                             \
            "cache/" t "/coarse/misses",    "cache/" t "/coarse/fills",                            \
            "cache/" t "/coarse/evictions", "cache/" t "/coarse/entries",                          \
            "cache/" t "/coarse/hit_rate"},                                                        \
            {"cache/" t "/medium/lookups",   "cache/" t "/medium/hits",                            \
             "cache/" t "/medium/misses",    "cache/" t "/medium/fills",                           \
             "cache/" t "/medium/evictions", "cache/" t "/medium/entries",                         \
             "cache/" t "/medium/hit_rate"},                                                       \
        {                                                                                          \
            "cache/" t "/fine/lookups", "cache/" t "/fine/hits", "cache/" t "/fine/misses",        \
                "cache/" t "/fine/fills", "cache/" t "/fine/evictions",                            \
                "cache/" t "/fine/entries", "cache/" t "/fine/hit_rate"                            \
        }                                                                                          \
    }
    TYPE_NAMES("radiosity"), TYPE_NAMES("opacity"), TYPE_NAMES("irradiance"), TYPE_NAMES("guide")
#undef TYPE_NAMES
};

static void session_stats_add_cache_types(RayesStats *s, const CacheStats *cs)
{
    static const int types[4] = {CACHE_RADIOSITY, CACHE_OPACITY, CACHE_IRRADIANCE, CACHE_GUIDE};
    static const char *const budgets[4] = {
        "cache/radiosity/budget_bytes", "cache/opacity/budget_bytes",
        "cache/irradiance/budget_bytes", "cache/guide/budget_bytes"};
    static const char *const peaks[4] = {"cache/radiosity/peak_bytes", "cache/opacity/peak_bytes",
                                         "cache/irradiance/peak_bytes", "cache/guide/peak_bytes"};
    for (int k = 0; k < 4; k++) {
        int t = types[k];
        uint64_t lookups = 0;
        for (int l = 0; l < CACHE_N_LEVELS; l++)
            lookups += cs->counters[l][t].lookups;
        if (cs->type_budget_bytes[t] == 0 && lookups == 0)
            continue;
        count(s, budgets[k], cs->type_budget_bytes[t]);
        count(s, peaks[k], cs->type_peak_bytes[t]); /* past the budget: it borrowed */
        for (int l = 0; l < CACHE_N_LEVELS; l++) {
            const CacheCounters *c = &cs->counters[l][t];
            const char *const *n = typed_names[k][l];
            count(s, n[0], c->lookups);
            count(s, n[1], c->hits);
            count(s, n[2], c->misses);
            count(s, n[3], c->fills);
            count(s, n[4], c->evictions);
            count(s, n[5], cs->type_entries[t][l]);
            real(s, n[6], c->lookups ? (double)c->hits / (double)c->lookups : 0.0);
        }
    }
}

void session_stats_add_textures(RayesStats *s, const TextureStats *ts)
{
    count(s, "textures/lookups", ts->lookups);
    count(s, "textures/textures", ts->textures);
    count(s, "textures/missing", ts->missing);
    count(s, "textures/loads", ts->loads);
    count(s, "textures/file_reads", ts->file_reads);
    count(s, "textures/evictions", ts->evictions);
    count(s, "textures/bytes", ts->bytes);
    count(s, "textures/peak_bytes", ts->peak_bytes);
    count(s, "textures/budget_bytes", ts->budget_bytes);
}

size_t rayes_stats_size(const RayesStats *s)
{
    return s ? s->n : 0;
}

const RayesStat *rayes_stats_get(const RayesStats *s, size_t i)
{
    return s && i < s->n ? &s->items[i] : NULL;
}

const RayesStat *rayes_stats_find(const RayesStats *s, const char *name)
{
    for (size_t i = 0; s && i < s->n; i++)
        if (strcmp(s->items[i].name, name) == 0)
            return &s->items[i];
    return NULL;
}

void rayes_stats_free(RayesStats *s)
{
    free(s);
}

void session_stats_add_count(RayesStats *stats, const char *name, uint64_t value)
{
    count(stats, name, value);
}

void session_stats_add_real(RayesStats *stats, const char *name, double value)
{
    real(stats, name, value);
}
