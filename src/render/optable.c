/*
 * render/optable.c — the coarse opacity of transparent grids, indexed by
 * grid (optable.h).
 */
#include "render/optable.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "util/check.h"
#include "util/half.h"

enum { SLOT_EMPTY = 0, SLOT_FILLING = 1, SLOT_READY = 2 };

typedef struct Slot {
    _Atomic uint32_t state;
    uint16_t v[3 * OPTABLE_VALUES];
} Slot;

struct OpacityTable {
    const RenderScene *rs;
    uint32_t *index;          /* per grid: its coarse level's slot in the world's table (a
                                 world grid) or in an instance's (a master's), its fine
                                 level's next if small_fine; or UINT32_MAX: none */
    Slot *world;              /* the world grids' slots */
    size_t n_world;
    uint32_t *master_slots;   /* per master: the slots of an instance's table */
    _Atomic(Slot *) *inst;    /* per instance: its table, NULL until asked */
    size_t budget;            /* for the instances' tables together */
    _Atomic size_t inst_bytes;
};

/* 1 if the opacity of obj may be shaded into a cache entry: cached, and a
 * pattern or an opacity method (Os alone is read from the grid). */
static int shaded_opacity(const RenderObject *obj)
{
    return obj->transparent && obj->opacity_cached && (obj->opacity_shader || obj->Os_pattern);
}

/* 1 if grid g's fine level fits a slot (a grid of one micropolygon,
 * whose coarse level is its inset points or its centroid): such grids,
 * leaves diced whole, are asked at their fine level by every ray finer
 * than the grid. */
static int small_fine(const Grid *g)
{
    size_t n = g->triangular ? (size_t)(g->nu + 1) * (size_t)(g->nu + 2) / 2
                             : (size_t)g->nu * (size_t)g->nv;
    return n <= OPTABLE_VALUES;
}

static Slot *slots_new(size_t n)
{
    Slot *s = malloc((n ? n : 1) * sizeof *s);
    for (size_t i = 0; s && i < n; i++)
        atomic_init(&s[i].state, SLOT_EMPTY);
    return s;
}

OpacityTable *optable_new(const RenderScene *rs, size_t budget_bytes)
{
    const GridSet *gs = rs->gs;
    int any = 0;
    for (size_t o = 0; o < rs->n_objects && !any; o++)
        any = shaded_opacity(&rs->objects[o]);
    if (!any)
        return NULL;
    OpacityTable *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->rs = rs;
    t->budget = budget_bytes;
    atomic_init(&t->inst_bytes, 0);
    t->index = malloc((gs->n_grids ? gs->n_grids : 1) * sizeof *t->index);
    t->master_slots = calloc(gs->n_masters + 1, sizeof *t->master_slots);
    t->inst = calloc(gs->n_instances + 1, sizeof *t->inst);
    if (!t->index || !t->master_slots || !t->inst) {
        optable_free(t);
        return NULL;
    }
    for (size_t i = 0; i < gs->n_instances; i++)
        atomic_init(&t->inst[i], NULL);
    for (size_t i = 0; i < gs->n_grids; i++) {
        const Grid *g = &gs->grids[i];
        t->index[i] = UINT32_MAX;
        if (g->moving)
            continue;
        uint32_t n = 1u + (uint32_t)small_fine(g);
        if (g->master) { /* whatever its object: an instance may give it one */
            t->index[i] = t->master_slots[g->master - 1];
            t->master_slots[g->master - 1] += n;
        } else if (shaded_opacity(render_object(rs, (uint32_t)i, 0))) {
            t->index[i] = (uint32_t)t->n_world;
            t->n_world += n;
        }
    }
    t->world = slots_new(t->n_world);
    if (!t->world) {
        optable_free(t);
        return NULL;
    }
    return t;
}

void optable_free(OpacityTable *t)
{
    if (!t)
        return;
    for (size_t i = 0; t->inst && i < t->rs->gs->n_instances; i++)
        free(atomic_load_explicit(&t->inst[i], memory_order_relaxed));
    free(t->inst);
    free(t->master_slots);
    free(t->world);
    free(t->index);
    free(t);
}

/* Instance i's table, made on first use while the tables fit the budget;
 * NULL past it. */
static Slot *instance_slots(OpacityTable *t, uint32_t i)
{
    Slot *s = atomic_load_explicit(&t->inst[i], memory_order_acquire);
    if (s)
        return s;
    size_t n = t->master_slots[t->rs->gs->instances[i].master];
    size_t bytes = n * sizeof *s;
    size_t used = atomic_fetch_add(&t->inst_bytes, bytes);
    if (used + bytes > t->budget || !(s = slots_new(n))) {
        atomic_fetch_sub(&t->inst_bytes, bytes);
        return NULL;
    }
    Slot *expected = NULL;
    if (!atomic_compare_exchange_strong_explicit(&t->inst[i], &expected, s, memory_order_acq_rel,
                                                 memory_order_acquire)) {
        free(s); /* another thread's came first */
        atomic_fetch_sub(&t->inst_bytes, bytes);
        return expected;
    }
    return s;
}

static void fill_values(const CacheKey *key, size_t n, CacheFillFn fill, void *user, uint16_t *v)
{
    float out[OPTABLE_VALUES][3];
    fill(user, key, n, out);
    for (size_t i = 0; i < n; i++) /* as the cache stores them */
        for (int k = 0; k < 3; k++)
            v[3 * i + k] = half_from_float_clamped(out[i][k]);
}

const uint16_t *optable_values(OpacityTable *t, const CacheKey *key, size_t n, CacheFillFn fill,
                               void *user, uint16_t scratch[3 * OPTABLE_VALUES], int *filled)
{
    *filled = 0;
    RY_DCHECK(key->type == CACHE_OPACITY);
    if (!t || key->patch >= t->rs->gs->n_grids || key->segment || n > OPTABLE_VALUES ||
        key->level == CACHE_MEDIUM)
        return NULL;
    const Grid *g = &t->rs->gs->grids[key->patch];
    uint32_t k = t->index[key->patch];
    if (k == UINT32_MAX || (key->instance == 0) == (g->master != 0))
        return NULL;
    if (key->level == CACHE_FINE) {
        if (!small_fine(g))
            return NULL;
        k++;
    }
    Slot *slots = key->instance ? instance_slots(t, key->instance - 1) : t->world;
    if (!slots)
        return NULL;
    Slot *s = &slots[k];
    uint32_t state = atomic_load_explicit(&s->state, memory_order_acquire);
    if (state == SLOT_READY)
        return s->v;
    if (state == SLOT_EMPTY &&
        atomic_compare_exchange_strong_explicit(&s->state, &state, SLOT_FILLING,
                                                memory_order_acquire, memory_order_acquire)) {
        fill_values(key, n, fill, user, s->v);
        *filled = 1;
        atomic_store_explicit(&s->state, SLOT_READY, memory_order_release);
        return s->v;
    }
    if (state == SLOT_READY) /* filled between the load and the exchange */
        return s->v;
    fill_values(key, n, fill, user, scratch); /* being filled: a copy of our own */
    *filled = 1;
    return scratch;
}

size_t optable_bytes(const OpacityTable *t)
{
    if (!t)
        return 0;
    const GridSet *gs = t->rs->gs;
    return gs->n_grids * sizeof *t->index + t->n_world * sizeof(Slot) +
           atomic_load(&((OpacityTable *)t)->inst_bytes);
}
