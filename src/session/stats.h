/*
 * session/stats.h — the statistics of one render as a RayesStats list
 * (rayes.h), named as the JSON keys are: "rays/shadow", "time/total_s",
 * "shading_points/by_depth" ...
 */
#ifndef RAYES_SESSION_STATS_H
#define RAYES_SESSION_STATS_H

#include "cache/cache.h"
#include "geom/geom.h"
#include "rayes/rayes.h"
#include "render/render.h"
#include "shade/texture.h"

typedef struct SessionTimes {
    double total_s, prepare_s, render_s;
    double render_cpu_s; /* the process's CPU time over render_s (0: not measured) */
    int pbgi;            /* point-based GI ran its passes before render_s: */
    double pbgi_cloud_s, pbgi_bounces_s, pbgi_octree_s;
} SessionTimes;

/* A new statistics list (free with rayes_stats_free), or NULL. */
RayesStats *session_stats_new(const RenderSettings *set, const RenderStats *rs, const GridSet *gs,
                              const SessionTimes *times, size_t accel_bytes);

/* Adds the "cache" block: budget_bytes and, per resolution, lookups, hits,
 * misses, fills, evictions, entries, bytes and hit_rate (radiosity only for
 * now; a later data type adds a per-type split). */
void session_stats_add_cache(RayesStats *stats, const CacheStats *cs);

/* Adds the "textures" block: lookups, textures, missing, loads (MIP levels
 * built), file_reads, evictions, bytes, peak_bytes and budget_bytes. */
void session_stats_add_textures(RayesStats *stats, const TextureStats *ts);

/* Adds one statistic; name must be static. */
void session_stats_add_count(RayesStats *stats, const char *name, uint64_t value);
void session_stats_add_real(RayesStats *stats, const char *name, double value);

#endif /* RAYES_SESSION_STATS_H */
