/*
 * render/optable.h — private to render/: the coarse opacity of transparent
 * grids, in a table beside the grids (memo 6.1's opacity cache, its
 * coarse level, and the fine level of grids of one micropolygon).
 *
 * A shadow ray through foliage crosses a dozen cut-out leaves, each asking
 * its grid's coarse opacity: hundreds of millions of lookups over tens of
 * thousands of grids, in no order a thread's local part of the cache could
 * keep (its slots missed four lookups in five, and each miss took two
 * shard locks). A coarse opacity entry is at most four RGB halves, and a
 * grid has one whatever the ray's depth and side (the memo's assumption),
 * so the coarse level of every transparent grid that a fill may shade
 * lives here, indexed by grid: a lookup is an atomic load. So does the
 * fine level of a grid of one micropolygon (a leaf diced whole), as small,
 * which every ray finer than the grid asks for. Grids seen
 * through an object instance have a table per instance (made when the
 * instance is first asked), while the tables' bytes stay within a budget;
 * past it, and for moving grids, the cache serves as before.
 *
 * A slot is filled once, by whichever thread claims it; a thread that
 * finds it being filled fills its own copy (a fill depends only on its
 * key: the same bytes). The table lives for one frame.
 *
 * Thread-safety: optable_values may be called from all workers at once.
 */
#ifndef RAYES_RENDER_OPTABLE_H
#define RAYES_RENDER_OPTABLE_H

#include "cache/cache.h"
#include "render/path.h"

/* The most values a coarse level holds (a quad grid's four points). */
#define OPTABLE_VALUES 4

/* For a frame of rs, its instances' tables within budget_bytes (all of
 * them together); NULL when no object's opacity is cached and shaded (a
 * pattern or an opacity method), or out of memory. */
OpacityTable *optable_new(const RenderScene *rs, size_t budget_bytes);
void optable_free(OpacityTable *t);

/* The opacity values (n RGB halves) of key's still grid (key->type
 * CACHE_OPACITY) at its coarse level, or at its fine level when that holds
 * at most OPTABLE_VALUES (a grid of one micropolygon), filled by
 * fill(user, key, n, ...) on first use (*filled set to 1); into scratch
 * when another thread is filling the slot. NULL: the table does not hold
 * this grid (the cache does). */
const uint16_t *optable_values(OpacityTable *t, const CacheKey *key, size_t n, CacheFillFn fill,
                               void *user, uint16_t scratch[3 * OPTABLE_VALUES], int *filled);

/* Bytes the table holds now (index and slots). */
size_t optable_bytes(const OpacityTable *t);

#endif /* RAYES_RENDER_OPTABLE_H */
