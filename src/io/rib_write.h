/*
 * io/rib_write.h — an IoSink (io/sink.h) that writes what it is told as
 * ASCII RIB, so every reader doubles as a converter (`rayes convert`,
 * docs/scene-files.md).
 *
 * The calls may come in any order (a reader may set the camera after the
 * geometry, and render settings are known only when the reader is done),
 * so the world is kept in memory and the whole file is written by
 * io_rib_writer_finish: the settings (Format, PixelSamples, PixelFilter,
 * Exposure, Display, CropWindow), the search paths, Projection and the
 * camera transform (the current transform at WorldBegin, RenderMan's
 * camera space: +z forward, +y up, +x right), then WorldBegin, the world,
 * WorldEnd. Floats are printed with %.9g, so they read back exactly.
 *
 * Mapping (RenderMan conventions; matrices are written transposed, as RIB
 * multiplies row vectors):
 *   set_transform      TransformEnd / TransformBegin + ConcatTransform
 *                      (nothing for the identity)
 *   set_shader         Color (Cs, else 1 1 1), Opacity (Os, when not 1),
 *                      Surface with typed inline parameters
 *   set_displacement   Displacement (NULL or "": Displacement "null")
 *   displacement bound Attribute "displacementbound" "sphere" in world space
 *   bicubic_patch      Basis "bezier" 3 "bezier" 3 (once) + Patch "bicubic"
 *   primitive vars     after P, "<class> normal N", "<class> float[2] st",
 *                      "<class> color Cs" with rayes.h's class names
 *   quadrics           Sphere, Cylinder, Cone, Disk, Paraboloid, Hyperboloid,
 *                      Torus (in AttributeBegin + ReverseOrientation when
 *                      flagged)
 *   area_light         AttributeBegin, AreaLightSource "arealight" N
 *                      "color lightcolor" L, Polygon, AttributeEnd
 *   light              LightSource with parameters ("from"/"to" as points)
 *   blobby             Blobby with its arrays as given
 *   solids             SolidBegin "op" ... SolidEnd (no TransformBegin of the writer's
 *                      straddles a block)
 *
 * Not thread-safe; one writer per file.
 */
#ifndef RAYES_IO_RIB_WRITE_H
#define RAYES_IO_RIB_WRITE_H

#include <stdio.h>

#include "io/sink.h"

typedef struct RibWriter RibWriter;

/* A new writer with an empty world, or NULL when out of memory. */
RibWriter *io_rib_writer_new(void);

/* The sink whose calls w records (borrowed: valid while w lives). */
IoSink io_rib_writer_sink(RibWriter *w);

/* Writes the whole RIB to out: settings may be NULL (none given). Returns
 * RAYES_ERROR_IO (err filled) when out cannot be written. */
RayesError io_rib_writer_finish(RibWriter *w, const IoSettings *settings, FILE *out, char *err,
                                size_t err_size);

void io_rib_writer_free(RibWriter *w);

#endif /* RAYES_IO_RIB_WRITE_H */
