/*
 * app/tiles.h — a render's tiles as the renderer cuts them (render.c):
 * tile_size squares over the crop window's pixels, row by row, the crop
 * window's pixels from ceil(W xmin) to ceil(W xmax) - 1 (session.c). The
 * checkpoint and the distributed render name tiles by this index.
 */
#ifndef RAYES_APP_TILES_H
#define RAYES_APP_TILES_H

#include <math.h>

#include "rayes/rayes.h"

typedef struct TileGrid {
    int crop[4];          /* pixels x0 y0 x1 y1 (x1, y1 excluded) */
    int size;             /* a tile's side, pixels */
    int tiles_x, tiles_y;
} TileGrid;

static inline TileGrid tile_grid(const RayesRenderOptions *o)
{
    TileGrid g;
    g.crop[0] = (int)ceil((double)o->width * o->crop[0] - 0.01);
    g.crop[2] = (int)ceil((double)o->width * o->crop[1] - 0.01);
    g.crop[1] = (int)ceil((double)o->height * o->crop[2] - 0.01);
    g.crop[3] = (int)ceil((double)o->height * o->crop[3] - 0.01);
    g.size = o->tile_size > 0 ? o->tile_size : 1;
    g.tiles_x = (g.crop[2] - g.crop[0] + g.size - 1) / g.size;
    g.tiles_y = (g.crop[3] - g.crop[1] + g.size - 1) / g.size;
    return g;
}

static inline int tile_count(const TileGrid *g)
{
    return g->tiles_x * g->tiles_y;
}

/* Tile t's pixels: x, y, w, h. */
static inline void tile_rect(const TileGrid *g, int t, int r[4])
{
    r[0] = g->crop[0] + (t % g->tiles_x) * g->size;
    r[1] = g->crop[1] + (t / g->tiles_x) * g->size;
    r[2] = (r[0] + g->size < g->crop[2] ? r[0] + g->size : g->crop[2]) - r[0];
    r[3] = (r[1] + g->size < g->crop[3] ? r[1] + g->size : g->crop[3]) - r[1];
}

/* The index of the tile whose corner is pixel (x, y), or -1. */
static inline int tile_at(const TileGrid *g, int x, int y)
{
    if ((x - g->crop[0]) % g->size || (y - g->crop[1]) % g->size || x < g->crop[0] ||
        y < g->crop[1])
        return -1;
    int t = (y - g->crop[1]) / g->size * g->tiles_x + (x - g->crop[0]) / g->size;
    return t < tile_count(g) ? t : -1;
}

#endif
