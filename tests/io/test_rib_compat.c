/*
 * Classic RIB files as RenderMan reads them (io/rib.c, rib_state.c,
 * rib_shade.c, rib_prim.c): requests RenderMan accepts that used to stop
 * a file (GeometricRepresentation, Illuminate of a light that was
 * skipped, Hider counts of 0, ri.h's "wrap" and "nowrap", RenderMan 20's
 * Procedural2 "DelayedReadArchive2").
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "rayes/rayes.h"
#include "record_sink.h"
#include "test.h"

static Record rec;
static IoSettings settings;
static char err[1024];

static RayesError rib(const char *text)
{
    RayesError e = record_rib(&rec, text, &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    return e;
}

#define WORLD(body) "Projection \"perspective\" \"fov\" 40\nWorldBegin\n" body "\nWorldEnd\n"
#define DISTANT "LightSource \"distantlight\" 2 \"from\" [0 0 -1] \"to\" [0 0 0]\n"
#define QUAD "Polygon \"P\" [0 0 1 1 0 1 1 1 1 0 1 1]\n"

static void test_requests_renderman_accepts(void)
{
    (void)rec_param;
    CHECK(rib(WORLD("GeometricRepresentation \"primitive\"\n" QUAD)) == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    CHECK(rib(WORLD("GeometricRepresentation \"lines\"\n" QUAD)) == RAYES_OK && rec.n_mesh == 1);
    CHECK(rib(WORLD("GeometricRepresentation\n" QUAD)) != RAYES_OK); /* no name */
    /* a light rayes skips, then Illuminate of it: the rest still lights */
    CHECK(rib(WORLD("LightSource \"uberlight\" 1 \"intensity\" 1\nIlluminate 1 1\n" DISTANT
                    "Illuminate 7 0\n" QUAD)) == RAYES_OK);
    CHECK(rec.n_light == 1 && rec.n_mesh == 1);
    /* Hider counts of 0: RenderMan's own choice (RenderMan for Maya) */
    CHECK(rib("Hider \"raytrace\" \"int minsamples\" [0] \"int maxsamples\" [64]\n" WORLD(QUAD)) ==
          RAYES_OK);
    CHECK(settings.spp <= 0 && settings.max_spp == 64);
    CHECK(rib("Hider \"raytrace\" \"int minsamples\" [-1]\n" WORLD(QUAD)) != RAYES_OK);
    /* ri.h's RI_WRAP and RI_NOWRAP */
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"nowrap\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 1);
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"wrap\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 2); /* wrapped in u: the closing patch too */
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"around\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) != RAYES_OK);
    rib(WORLD("Curves \"linear\" [2] \"nowrap\" \"P\" [0 0 1 0 1 1] \"constantwidth\" [0.1]"));
    CHECK(strstr(err, "curves") != NULL && strstr(err, "periodic") == NULL); /* read to the sink */
}

static void test_procedural2(void)
{
    const char *path = RAYES_TEST_TMP "/compat_archive.rib";
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(QUAD, f);
    fclose(f);
    char text[1024];
    snprintf(text, sizeof text,
             WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\" \"string filename\" "
                   "[\"%s\"] \"float[6] bound\" [0 1 0 1 0 1]\n" QUAD),
             path);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_mesh == 2); /* the archive's quad and the file's */
    /* other kinds are skipped; the archive kind needs its file name */
    CHECK(rib(WORLD("Procedural2 \"DynamicLoad\" \"SimpleBound\" \"string dsoname\" [\"x.so\"]\n" QUAD)) ==
          RAYES_OK);
    CHECK(rec.n_mesh == 1);
    CHECK(rib(WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\"\n")) != RAYES_OK);
    CHECK(strstr(err, "filename") != NULL);
    CHECK(rib(WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\" \"string filename\" "
                    "[\"no/such.rib\"]\n")) != RAYES_OK);
    remove(path);
}

TEST_MAIN(TEST(test_requests_renderman_accepts), TEST(test_procedural2))
