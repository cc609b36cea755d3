/*
 * RenderMan 19 and later in RIB files (io/rib_ris.c): Bxdf classes as
 * rayes' shaders, Light classes as its lights (radiance, exposure,
 * areaNormalize, the sun's solid angle, on after their block, unseen by
 * the camera unless said), RenderMan 19-20's Geometry "rectlight" under
 * AreaLightSource, Integrator's maxPathLength as bounces; rendered, a
 * PxrRectLight lights a box as the same quad as a classic area light
 * does, and a PxrTexture reaches the diffuse colour that references it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "rayes/rayes.h"
#include "record_sink.h"
#include "rib_round_trip.h"
#include "test.h"

static Record rec;
static IoSettings settings;
static char err[1024];

static RayesError rib(const char *text)
{
    return record_rib_said(&rec, text, &settings, err, sizeof err);
}

#define WORLD(body) "Projection \"perspective\" \"fov\" 40\nWorldBegin\n" body "\nWorldEnd\n"
#define TRI "Polygon \"P\" [0 0 1 1 0 1 1 1 1]\n"

static float param(const RecShader *s, const char *name, int c)
{
    const RayesParam *p = rec_param(s, name);
    return p ? p->value[c] : NAN;
}

/* The shader the one triangle after a Bxdf was made with. */
static const RecShader *bxdf(const char *line)
{
    char text[1024];
    snprintf(text, sizeof text, WORLD("%s\n" TRI), line);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_shader >= 1);
    return &rec.shader[rec.n_shader - 1];
}

static void test_bxdfs(void)
{
    const RecShader *s = bxdf("Bxdf \"PxrDiffuse\" \"d\" \"color diffuseColor\" [0.2 0.4 0.6]");
    CHECK(strcmp(s->name, "diffuse") == 0);
    CHECK_NEAR(param(s, "reflectance", 2), 0.6, 1e-6);
    s = bxdf("Bxdf \"PxrLMDiffuse\" \"d\" \"color frontColor\" [0.1 0.2 0.3]");
    CHECK(strcmp(s->name, "diffuse") == 0 && fabsf(param(s, "reflectance", 1) - 0.2f) < 1e-6f);
    /* PxrSurface: the diffuse lobe (times its gain) under the specular
     * one; the specular lobe alone, artistic or physical; glass */
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float diffuseGain\" [0.5] \"color diffuseColor\" "
             "[0.8 0.6 0.4] \"color specularFaceColor\" [0.04 0.04 0.04] "
             "\"float specularRoughness\" [0.3]");
    CHECK(strcmp(s->name, "coateddiffuse") == 0);
    CHECK_NEAR(param(s, "reflectance", 0), 0.4, 1e-6);
    CHECK_NEAR(param(s, "roughness", 0), 0.3, 1e-6);
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float diffuseGain\" [0] "
             "\"color specularFaceColor\" [1 0.8 0.3]");
    CHECK(strcmp(s->name, "conductor") == 0);
    CHECK_NEAR(param(s, "reflectance", 2), 0.3, 1e-6);
    CHECK_NEAR(param(s, "roughness", 0), 0.2, 1e-6); /* RenderMan's default */
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float diffuseGain\" [0] \"int specularFresnelMode\" "
             "[1] \"color specularIor\" [0.2 0.9 1.1] \"color specularExtinctionCoeff\" [3.9 "
             "2.4 2.1]");
    CHECK(strcmp(s->name, "conductor") == 0);
    CHECK_NEAR(param(s, "eta", 1), 0.9, 1e-6);
    CHECK_NEAR(param(s, "k", 0), 3.9, 1e-6);
    /* the lobe that shines gives the conductor its colour and roughness */
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float diffuseGain\" [0] \"color specularEdgeColor\" "
             "[1 1 1]");
    CHECK(strcmp(s->name, "conductor") == 0 && param(s, "reflectance", 0) == 1.0f);
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float diffuseGain\" [0] \"color clearcoatFaceColor\" "
             "[0.5 0.5 0.5] \"float clearcoatRoughness\" [0.05]");
    CHECK(strcmp(s->name, "conductor") == 0 && param(s, "reflectance", 1) == 0.5f);
    CHECK_NEAR(param(s, "roughness", 0), 0.05, 1e-6);
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float refractionGain\" [1] \"float glassIor\" [1.33]");
    CHECK(strcmp(s->name, "dielectric") == 0 && fabsf(param(s, "eta", 0) - 1.33f) < 1e-6f);
    CHECK(param(s, "transmitcolor", 0) == 1.0f); /* clear by default */
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float refractionGain\" [1] \"color refractionColor\" "
             "[0 0.9 0]");
    CHECK(strcmp(s->name, "dielectric") == 0 && param(s, "transmitcolor", 0) == 0.0f &&
          fabsf(param(s, "transmitcolor", 1) - 0.9f) < 1e-6f); /* green glass (it was clear) */
    s = bxdf("Bxdf \"PxrSurface\" \"s\"");
    CHECK(strcmp(s->name, "diffuse") == 0); /* RenderMan's default: 0.18 grey, no specular */
    CHECK_NEAR(param(s, "reflectance", 0), 0.18, 1e-6);
    /* PxrDisney: a conductor when metallic; its default base colour */
    s = bxdf("Bxdf \"PxrDisney\" \"m\" \"color baseColor\" [0.9 0.6 0.2] \"float metallic\" [1]");
    CHECK(strcmp(s->name, "conductor") == 0 && fabsf(param(s, "reflectance", 1) - 0.6f) < 1e-6f);
    s = bxdf("Bxdf \"PxrDisney\" \"m\"");
    CHECK(strcmp(s->name, "coateddiffuse") == 0);
    CHECK_NEAR(param(s, "reflectance", 2), 0.8, 1e-6);
    s = bxdf("Bxdf \"PxrConstant\" \"c\" \"color emitColor\" [2 1 0.5]");
    CHECK(strcmp(s->name, "matte") == 0 && param(s, "Kd", 0) == 0.0f);
    CHECK_NEAR(param(s, "Ke", 0), 2, 1e-6);
    s = bxdf("Bxdf \"PxrGlass\" \"g\" \"float ior\" [1.6]");
    CHECK(strcmp(s->name, "dielectric") == 0 && fabsf(param(s, "eta", 0) - 1.6f) < 1e-6f);
    /* an unknown class: a grey diffuse, with a warning, not an error */
    s = bxdf("Bxdf \"PxrMarschnerHair\" \"h\" \"float diffuseGain\" [1]");
    CHECK(strcmp(s->name, "diffuse") == 0);
    /* a PxrTexture without a file is not translated: warned, the value used */
    CHECK(rib(WORLD("Pattern \"PxrTexture\" \"t\"\nBxdf \"PxrDiffuse\" \"d\" \"reference color "
                    "diffuseColor\" [\"t:resultRGB\"]\n" TRI)) == RAYES_OK);
    CHECK(strcmp(rec.shader[rec.n_shader - 1].name, "diffuse") == 0);
    /* a pattern rayes has not passes its input's colour on, through a chain */
    CHECK(rib(WORLD("Pattern \"PxrExposure\" \"e\" \"color inputRGB\" [0.8 0.05 0.05]\n"
                    "Pattern \"PxrColorCorrect\" \"c\" \"reference color inputRGB\" "
                    "[\"e:resultRGB\"]\nBxdf \"PxrDiffuse\" \"d\" \"reference color "
                    "diffuseColor\" [\"c:resultRGB\"]\n" TRI)) == RAYES_OK);
    if (rec.n_shader >= 1) {
        const RecShader *pass = &rec.shader[rec.n_shader - 1];
        CHECK(strcmp(pass->name, "diffuse") == 0);
        CHECK_NEAR(param(pass, "reflectance", 0), 0.8, 1e-6);
        CHECK_NEAR(param(pass, "reflectance", 1), 0.05, 1e-6);
    }
    /* a class named in other capitals (as a Mac's or Windows's plugin
     * lookup finds it) */
    s = bxdf("Bxdf \"PXRDisney\" \"d\" \"color baseColor\" [0.1 0.6 0.5] \"float metallic\" [1]");
    CHECK(strcmp(s->name, "conductor") == 0 && fabsf(param(s, "reflectance", 1) - 0.6f) < 1e-6f);
    /* Bxdf is an attribute, as Surface is (after the block, the default:
     * in a file without lights, RenderMan's defaultsurface) */
    CHECK(rib(WORLD("AttributeBegin\nBxdf \"PxrDiffuse\" \"d\"\nAttributeEnd\n" TRI)) == RAYES_OK);
    CHECK(rec.n_shader >= 1 && strcmp(rec.shader[rec.n_shader - 1].name, "defaultsurface") == 0);
    CHECK(rib(WORLD("LightSource \"pointlight\" 1\nAttributeBegin\nBxdf \"PxrDiffuse\" \"d\"\n"
                    "AttributeEnd\n" TRI)) == RAYES_OK);
    CHECK(rec.n_shader >= 1 && strcmp(rec.shader[rec.n_shader - 1].name, "matte") == 0);
}

/* The last light made. */
static const RecShader *light(void)
{
    CHECK(rec.n_light >= 1);
    return &rec.light[rec.n_light > 0 ? rec.n_light - 1 : 0];
}

static void test_lights(void)
{
    /* radiance intensity 2^exposure lightColor, kept as intensity (its
     * largest channel) and colour; a unit square emitting toward +z */
    CHECK(rib(WORLD("AttributeBegin\nLight \"PxrRectLight\" \"k\" \"float intensity\" [2] "
                    "\"float exposure\" [1] \"color lightColor\" [1 0.5 0.25]\nAttributeEnd\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_light == 1 && strcmp(light()->name, "arealight") == 0);
    CHECK_NEAR(param(light(), "intensity", 0), 4, 1e-6);
    CHECK_NEAR(param(light(), "lightcolor", 1), 0.5, 1e-6);
    const RayesParam *shape = rec_param(light(), "shape");
    CHECK(shape && strcmp(shape->string, "quad") == 0);
    CHECK(rec_param(light(), "shadows") == NULL);
    /* enableShadows 0 and a diffuse multiplier of 0 are rayes' own controls */
    CHECK(rib(WORLD("Light \"PxrRectLight\" \"k\" \"int enableShadows\" [0] \"float diffuse\" [0] "
                    "\"float coneAngle\" [20]\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 1 && param(light(), "shadows", 0) == 0.0f &&
          param(light(), "__nondiffuse", 0) == 1.0f && rec_param(light(), "__nonspecular") == NULL);
    /* a rect light's coneAngle is rayes' arealight cone (degrees) */
    CHECK(param(light(), "cone", 0) == 20.0f && param(light(), "conesoftness", 0) == 0.0f);
    /* and what the writer writes back reads so */
    CHECK(rib(WORLD("LightSource \"arealight\" 1 \"float cone\" [30] \"float conesoftness\" "
                    "[0.25]\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 1 && param(light(), "cone", 0) == 30.0f &&
          param(light(), "conesoftness", 0) == 0.25f);
    /* on after its block: the triangle is linked to every light */
    CHECK(rec.links_mode == RAYES_LIGHT_LINKS_ALL);
    /* areaNormalize: over the area of the square as scaled (2 x 3) and
     * turned */
    CHECK(rib(WORLD("AttributeBegin\nRotate 30 1 0 0\nScale 2 3 1\nLight \"PxrRectLight\" \"k\" "
                    "\"float intensity\" [12] \"int areaNormalize\" [1]\nAttributeEnd\n" TRI)) ==
          RAYES_OK);
    CHECK_NEAR(param(light(), "intensity", 0), 2, 1e-5);
    /* a colour temperature tints the light (6500 K white), its luminance
     * kept */
    CHECK(rib(WORLD("Light \"PxrSphereLight\" \"w\" \"int enableTemperature\" [1] \"float "
                    "temperature\" [6500]\nLight \"PxrSphereLight\" \"c\" \"float intensity\" "
                    "[2] \"int enableTemperature\" [1] \"float temperature\" [3000]\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_light == 2);
    if (rec.n_light == 2) {
        float c[3], w[3];
        for (int k = 0; k < 3; k++) {
            w[k] = param(&rec.light[0], "intensity", 0) * param(&rec.light[0], "lightcolor", k);
            c[k] = param(&rec.light[1], "intensity", 0) * param(&rec.light[1], "lightcolor", k);
        }
        CHECK(fabsf(w[0] - w[1]) < 1e-4f && fabsf(w[2] - w[1]) < 1e-4f);
        CHECK(c[0] > 1.2f * c[1] && c[1] > 1.5f * c[2]); /* 3000 K: orange */
        CHECK_NEAR(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2], 2, 1e-4);
    }
    /* PxrEnvDayLight: rayes' sky and a distant sun shining from its
     * direction; RenderMan 21's +z zenith (what a Rotate -90 1 0 0 turns
     * up) is rayes' +y */
    CHECK(rib(WORLD("Light \"PxrEnvDayLight\" \"d\" \"vector sunDirection\" [0.6 0.8 0]\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_light == 2);
    if (rec.n_light == 2) {
        const RayesParam *m = rec_param(&rec.light[0], "mapping");
        CHECK(strcmp(rec.light[0].name, "environmentlight") == 0 && m &&
              strcmp(m->string, "sky") == 0);
        CHECK_NEAR(param(&rec.light[0], "sundirection", 1), 0.8, 1e-6);
        CHECK_NEAR(param(&rec.light[0], "intensity", 0), 1e-5, 1e-9);
        CHECK(strcmp(rec.light[1].name, "distantlight") == 0);
        CHECK_NEAR(param(&rec.light[1], "to", 0), -0.6, 1e-5);
        CHECK_NEAR(param(&rec.light[1], "to", 1), -0.8, 1e-5);
        /* the sun at 37 degrees up: Hottel's beam, about 0.13 cd/m^2 x 1e-5 x 0.53 degrees' solid
         * angle */
        float lum = 0;
        for (int k = 0; k < 3; k++)
            lum += (k == 0   ? 0.2126f
                    : k == 1 ? 0.7152f
                             : 0.0722f) *
                   param(&rec.light[1], "intensity", 0) * param(&rec.light[1], "lightcolor", k);
        printf("  the sun's irradiance: %.4f\n", lum);
        CHECK(lum > 0.65f && lum < 0.9f);
    }
    CHECK(rib(WORLD("Rotate -90 1 0 0\nLight \"PxrEnvDayLight\" \"d\" \"vector sunDirection\" "
                    "[0 0 1] \"float haziness\" [4]\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 2);
    if (rec.n_light == 2) {
        CHECK_NEAR(param(&rec.light[0], "sundirection", 1), 1, 1e-6);
        CHECK_NEAR(param(&rec.light[0], "haziness", 0), 4, 1e-6);
    }
    /* a date's sun in that frame: the heliodon's +y zenith as it is (the
     * June noon at 40 degrees north, 73 degrees up) */
    CHECK(
        rib(WORLD("Rotate -90 1 0 0\nLight \"PxrEnvDayLight\" \"d\" \"int month\" [6] \"int day\" "
                  "[21] \"float hour\" [12] \"float zone\" [-8] \"float latitude\" [40] \"float "
                  "longitude\" [-120]\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 2 && param(&rec.light[0], "sundirection", 1) > 0.9f);
    /* disks and spheres of diameter 1 */
    CHECK(rib(WORLD("Light \"PxrSphereLight\" \"b\"\nLight \"PxrDiskLight\" \"d\"\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_light == 2);
    CHECK(strcmp(rec_param(&rec.light[0], "shape")->string, "sphere") == 0);
    CHECK_NEAR(param(&rec.light[0], "radius", 0), 0.5, 0);
    CHECK(strcmp(rec_param(&rec.light[1], "shape")->string, "disk") == 0);
    /* the sun: RenderMan's default radiance over a disk of 0.53 degrees,
     * irradiance = radiance x solid angle, along +z */
    CHECK(rib(WORLD("Light \"PxrDistantLight\" \"sun\"\n" TRI)) == RAYES_OK);
    CHECK(strcmp(light()->name, "distantlight") == 0);
    double omega = 2 * M_PI * (1 - cos(0.265 * M_PI / 180));
    CHECK_NEAR(param(light(), "intensity", 0), 50000 * omega, 1e-3);
    CHECK_NEAR(param(light(), "to", 2), 1, 0);
    CHECK(rib(WORLD("Light \"PxrDistantLight\" \"sun\" \"float intensity\" [3] "
                    "\"int areaNormalize\" [1]\n" TRI)) == RAYES_OK);
    CHECK_NEAR(param(light(), "intensity", 0), 3, 1e-6);
    CHECK(rib(WORLD("Light \"PxrDomeLight\" \"sky\" \"float intensity\" [0.5]\n" TRI)) ==
          RAYES_OK);
    CHECK(strcmp(light()->name, "environmentlight") == 0);
    /* classes rayes does not translate: skipped with a warning */
    CHECK(rib(WORLD("Light \"PxrMeshLight\" \"m\"\nLight \"PxrAovLight\" \"a\"\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_light == 0);
    /* Illuminate turns one off */
    CHECK(rib(WORLD("Light \"PxrRectLight\" \"k\"\nIlluminate \"k\" 0\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 1 && rec.links_mode == RAYES_LIGHT_LINKS_EXCEPT);
    /* a light needs its handle */
    CHECK(rib(WORLD("Light \"PxrRectLight\"\n")) != RAYES_OK);
}

static void test_geometry_lights(void)
{
    /* RenderMan 19 and 20: the light's shape as Geometry under
     * AreaLightSource, its exposure and lightColor */
    CHECK(rib(WORLD("AttributeBegin\nAreaLightSource \"PxrStdAreaLight\" \"a\" \"float "
                    "exposure\" [2] \"color lightColor\" [1 1 0.5]\nBxdf \"PxrLightEmission\" "
                    "\"e\"\nGeometry \"rectlight\"\nAttributeEnd\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 1 && strcmp(light()->name, "arealight") == 0);
    CHECK_NEAR(param(light(), "intensity", 0), 4, 1e-6);
    CHECK_NEAR(param(light(), "lightcolor", 2), 0.5, 1e-6);
    CHECK(rec.links_mode == RAYES_LIGHT_LINKS_ALL); /* area lights light everything */
    CHECK(rib(WORLD("AreaLightSource \"PxrStdAreaLight\" \"a\"\nGeometry \"spherelight\"\n"
                    "Geometry \"envsphere\"\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 2 && strcmp(rec.light[1].name, "environmentlight") == 0);
    /* outside AreaLightSource the shapes are skipped */
    CHECK(rib(WORLD("Geometry \"rectlight\"\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 0);
}

static void test_integrator(void)
{
    /* no Integrator: PRMan's PxrDefault, a light at the camera, which a file
     * without lights asks for */
    CHECK(rib(WORLD("Bxdf \"PxrDiffuse\" \"d\"\n" TRI)) == RAYES_OK && settings.headlight == 1);
    CHECK(rib("Integrator \"PxrPathTracer\" \"pt\"\n" WORLD("Bxdf \"PxrDiffuse\" \"d\"\n" TRI)) ==
              RAYES_OK &&
          settings.headlight == 0);
    CHECK(rib(WORLD("Light \"PxrDomeLight\" \"dome\"\nBxdf \"PxrDiffuse\" \"d\"\n" TRI)) ==
              RAYES_OK &&
          settings.headlight == 0);
    CHECK(rib(WORLD("Surface \"matte\"\n" TRI)) == RAYES_OK && settings.headlight == 0);
    CHECK(rib("Integrator \"PxrPathTracer\" \"pt\" \"int maxPathLength\" [4]\n" WORLD(TRI)) ==
          RAYES_OK);
    CHECK(settings.bounces == 3 && settings.specular_depth == 4);
    CHECK(rib("Integrator \"PxrVCM\" \"v\" \"int maxPathLength\" [20]\n" WORLD(TRI)) == RAYES_OK);
    CHECK(settings.bounces == 8 && settings.specular_depth == 20); /* capped, as pbrt's */
    CHECK(rib("Integrator \"PxrDirectLighting\" \"d\"\n" WORLD(TRI)) == RAYES_OK);
    CHECK(settings.bounces == 0);
    CHECK(rib("Integrator \"PxrPathTracer\" \"pt\" \"int maxPathLength\" [-1]\n" WORLD(TRI)) !=
          RAYES_OK);
}

/* RenderMan 21's names for the image size and the projections. */
static void test_options(void)
{
    CHECK(rib("Option \"ri\" \"int[2] FormatResolution\" [320 200] \"float "
              "FormatPixelAspectRatio\" [1]\nProjection \"PxrPerspective\" \"float fov\" [30]\n"
              "WorldBegin\n" TRI "WorldEnd\n") == RAYES_OK);
    CHECK(settings.width == 320 && settings.height == 200);
    CHECK(rib("Option \"ri\" \"int[2] FormatResolution\" [0 200]\n" WORLD(TRI)) != RAYES_OK);
    CHECK(rib("Projection \"PxrOrthographic\"\nWorldBegin\n" TRI "WorldEnd\n") == RAYES_OK);
}

enum { SIZE = 32 };

/* A box open toward the camera lit from its ceiling by light (a RIB
 * fragment placed in the ceiling's frame: z = 0, emitting down). */
static void box_text(char *text, size_t size, const char *light, const char *extra)
{
    snprintf(text, size,
             "Projection \"perspective\" \"fov\" [40]\nTranslate 0 0 3.5\nWorldBegin\n"
             "AttributeBegin\nTranslate 0 0.99 0\nRotate 90 1 0 0\nScale 0.6 0.6 1\n%s\n"
             "AttributeEnd\n%s\n"
             "Bxdf \"PxrDiffuse\" \"w\" \"color diffuseColor\" [0.7 0.7 0.7]\n"
             "Polygon \"P\" [-1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1]\n"
             "Polygon \"P\" [-1 -1 1  1 -1 1  1 1 1  -1 1 1]\n"
             "Polygon \"P\" [-1 1 -1  -1 1 1  1 1 1  1 1 -1]\n"
             "Polygon \"P\" [-1 -1 -1  -1 -1 1  -1 1 1  -1 1 -1]\n"
             "Polygon \"P\" [1 -1 -1  1 1 -1  1 1 1  1 -1 1]\n"
             "WorldEnd\n",
             light, extra);
}

/* A RIB text rendered at SIZE x SIZE, 4 samples, no bounces. */
static RayesImage *render_text(const char *text)
{
    RayesError e;
    RayesScene *s = rib_read_scene(text, &e, err, sizeof err);
    RayesImage *img = NULL;
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    CHECK(e == RAYES_OK);
    if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = SIZE;
        o.spp = 4;
        o.threads = 2;
        o.bounces = 0;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

static RayesImage *render_box(const char *light, const char *extra)
{
    char text[4096];
    box_text(text, sizeof text, light, extra);
    return render_text(text);
}

/* The mean of channel c over rows y0 and down. */
static double mean(const RayesImage *a, int c, int y0)
{
    double t = 0;
    for (int i = y0 * SIZE; i < SIZE * SIZE; i++)
        t += a->rgba[4 * i + c];
    return t / ((SIZE - y0) * SIZE);
}

/* The light's pixels: the top rows' middle, where the ceiling light is. */
static double light_pixels(const RayesImage *a)
{
    double t = 0;
    for (int y = 0; y < SIZE / 8; y++)
        for (int x = SIZE / 2 - 2; x < SIZE / 2 + 2; x++)
            t += a->rgba[4 * (y * SIZE + x) + 1];
    return t;
}

static void test_rendered(void)
{
    /* a PxrRectLight seen by the camera is the quad a classic area light
     * of the same radiance and corners makes: the same image */
    RayesImage *ris = render_box("Attribute \"visibility\" \"int camera\" [1]\n"
                                 "Light \"PxrRectLight\" \"k\" \"float intensity\" [3] "
                                 "\"float exposure\" [1] \"color lightColor\" [1 0.8 0.6]",
                                 "");
    RayesImage *classic =
        render_box("AreaLightSource \"arealight\" 1 "
                   "\"lightcolor\" [6 4.8 3.6]\n"
                   "Polygon \"P\" [-0.5 -0.5 0  0.5 -0.5 0  0.5 0.5 0  -0.5 0.5 0]",
                   "");
    RayesImage *unseen = render_box("Light \"PxrRectLight\" \"k\" \"float intensity\" [6] "
                                    "\"color lightColor\" [1 0.8 0.6]",
                                    "");
    CHECK(ris && classic && unseen);
    if (ris && classic && unseen) {
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean(ris, c, 0), mean(classic, c, 0), 0.005 * mean(classic, c, 0));
        CHECK(mean(ris, 1, 0) > 0.05);
        /* unseen by the camera (RenderMan 21's default): the light's
         * pixels are the dark ceiling behind it, the room below as lit */
        CHECK(light_pixels(unseen) < 0.2 * light_pixels(ris));
        CHECK_NEAR(mean(unseen, 0, SIZE / 4), mean(ris, 0, SIZE / 4), 0.01 * mean(ris, 0, SIZE / 4));
    }
    /* written as rayes' own RIB and read back: the same image, the light
     * unseen as before */
    char text[4096];
    box_text(text, sizeof text,
             "Light \"PxrRectLight\" \"k\" \"float intensity\" [6] \"color lightColor\" [1 0.8 "
             "0.6]",
             "");
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written != NULL);
    RayesImage *back = written ? render_text(written) : NULL;
    CHECK(back && unseen && memcmp(back->rgba, unseen->rgba, sizeof(float) * 4 * SIZE * SIZE) == 0);
    free(written);
    rayes_image_free(back);
    /* lights under a mirroring transform, as exporters write them, still
     * emit along their +z; RenderMan 19-20's rectlight is seen as its
     * block's visibility says */
    RayesImage *mirrored = render_box("Scale -1 1 1\nLight \"PxrRectLight\" \"k\" \"float "
                                      "intensity\" [6] \"color lightColor\" [1 0.8 0.6]",
                                      "");
    RayesImage *hidden = render_box("Attribute \"visibility\" \"int camera\" [0]\n"
                                    "AreaLightSource \"PxrStdAreaLight\" \"a\" \"float "
                                    "exposure\" [1] \"float intensity\" [3] \"color lightColor\" "
                                    "[1 0.8 0.6]\nGeometry \"rectlight\"",
                                    "");
    CHECK(mirrored && hidden && unseen);
    if (mirrored && hidden && unseen) {
        /* the same square, its corners in another order: the same light */
        CHECK_NEAR(mean(mirrored, 0, 0), mean(unseen, 0, 0), 0.01 * mean(unseen, 0, 0));
        CHECK(memcmp(hidden->rgba, unseen->rgba, sizeof(float) * 4 * SIZE * SIZE) == 0);
    }
    rayes_image_free(mirrored);
    rayes_image_free(hidden);
    rayes_image_free(ris);
    rayes_image_free(classic);
    rayes_image_free(unseen);
    /* a PxrTexture referenced by diffuseColor colours the right wall */
    FILE *f = fopen(RAYES_TEST_TMP "/test_rib_ris_red.ppm", "wb");
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "P6 2 2 255\n");
        for (int i = 0; i < 4; i++)
            fputc(255, f), fputc(0, f), fputc(0, f);
        fclose(f);
    }
    RayesImage *tex = render_box(
        "Light \"PxrRectLight\" \"k\" \"float intensity\" [6]",
        "AttributeBegin\nPattern \"PxrTexture\" \"t\" \"string filename\" [\"" RAYES_TEST_TMP
        "/test_rib_ris_red.ppm\"]\nBxdf \"PxrDiffuse\" \"r\" \"reference color diffuseColor\" "
        "[\"t:resultRGB\"]\nPolygon \"P\" [0.99 -1 -1  0.99 1 -1  0.99 1 1  0.99 -1 1] \"st\" "
        "[0 0 0 1 1 1 1 0]\nAttributeEnd");
    CHECK(tex != NULL);
    if (tex) { /* the right wall's pixels: red, not grey */
        double r = 0, g = 0;
        for (int y = SIZE / 4; y < 3 * SIZE / 4; y++)
            for (int x = 7 * SIZE / 8; x < SIZE; x++)
                r += tex->rgba[4 * (y * SIZE + x)], g += tex->rgba[4 * (y * SIZE + x) + 1];
        CHECK(r > 0.01 && g < 0.05 * r);
    }
    rayes_image_free(tex);
}

/* A dome (RenderMan 21's Light, RenderMan 20's envsphere) is the
 * background the camera sees, unless the attributes hide it; hidden, it
 * still lights; written and read back, it stays hidden. */
static void test_dome_visibility(void)
{
#define DOME_SCENE(attr, light)                                                                    \
    "Projection \"perspective\" \"fov\" [40]\nWorldBegin\nAttributeBegin\n" attr light             \
    "AttributeEnd\nBxdf \"PxrDiffuse\" \"d\"\nTranslate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n"
#define DOME "Light \"PxrDomeLight\" \"dome\" \"float intensity\" [0.5]\n"
#define ENVSPHERE(pv)                                                                              \
    "AreaLightSource \"PxrStdEnvMapLight\" \"e\" \"float intensity\" [0.5]" pv                     \
    "\nGeometry \"envsphere\"\n"
#define HIDE "Attribute \"visibility\" \"int camera\" [0]\n"
    RayesImage *seen = render_text(DOME_SCENE("", DOME));
    RayesImage *hidden = render_text(DOME_SCENE(HIDE, DOME));
    RayesImage *env_hidden =
        render_text(DOME_SCENE("", ENVSPHERE(" \"float rman__LightPrimaryVisibility\" [0]")));
    RayesImage *env_attr = render_text(DOME_SCENE(HIDE, ENVSPHERE("")));
    char *written = rib_round_trip(DOME_SCENE(HIDE, DOME), err, sizeof err);
    RayesImage *back = written ? render_text(written) : NULL;
    CHECK(seen && hidden && env_hidden && env_attr && back);
    if (seen && hidden && env_hidden && env_attr && back) {
        int corner = 0, centre = 4 * (SIZE / 2 * SIZE + SIZE / 2);
        CHECK_NEAR(seen->rgba[corner], 0.5, 1e-4); /* the dome's radiance */
        CHECK(hidden->rgba[corner] == 0.0f && hidden->rgba[corner + 3] == 0.0f);
        CHECK(env_hidden->rgba[corner] == 0.0f && env_attr->rgba[corner] == 0.0f);
        CHECK(hidden->rgba[centre] > 0.1f); /* the sphere: lit by the hidden dome */
        CHECK_NEAR(hidden->rgba[centre], seen->rgba[centre], 1e-6);
        CHECK(memcmp(back->rgba, hidden->rgba, sizeof(float) * 4 * SIZE * SIZE) == 0);
    }
    free(written);
    rayes_image_free(seen);
    rayes_image_free(hidden);
    rayes_image_free(env_hidden);
    rayes_image_free(env_attr);
    rayes_image_free(back);
#undef DOME_SCENE
#undef DOME
#undef ENVSPHERE
#undef HIDE
}

/* PxrSurface's refractionColor tints its glass at each crossing: a
 * sphere against a white dome shows it twice (0.9^2 green) and a little
 * white reflection. */
static void test_tinted_glass(void)
{
    RayesImage *img = render_text(
        "Projection \"perspective\" \"fov\" [20]\nWorldBegin\nAttributeBegin\n"
        "Attribute \"visibility\" \"int camera\" [1]\n"
        "Light \"PxrDomeLight\" \"dome\" \"float intensity\" [1]\nAttributeEnd\n"
        "Bxdf \"PxrSurface\" \"g\" \"float diffuseGain\" [0] \"float refractionGain\" [1] "
        "\"color refractionColor\" [0 0.9 0] \"float glassRoughness\" [0]\n"
        "Translate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    CHECK(img != NULL);
    if (img) { /* the middle 8 x 8 pixels (deeper crossings end by roulette) */
        double c[3] = {0, 0, 0};
        for (int y = SIZE / 2 - 4; y < SIZE / 2 + 4; y++)
            for (int x = SIZE / 2 - 4; x < SIZE / 2 + 4; x++)
                for (int k = 0; k < 3; k++)
                    c[k] += img->rgba[4 * (y * SIZE + x) + k] / 64.0;
        printf("  green glass against a white dome: %.3f %.3f %.3f\n", c[0], c[1], c[2]);
        CHECK(c[1] > 0.7 && c[1] < 0.9); /* 0.04 + 0.96^2 0.81, and inner reflections */
        CHECK(c[0] < 0.1 && c[2] < 0.1);
    }
    rayes_image_free(img);
}

/* The mean of channel c over the pixels x0 <= x < x1, y0 <= y < y1. */
static double region(const RayesImage *a, int c, int x0, int x1, int y0, int y1)
{
    double t = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            t += a->rgba[4 * (y * SIZE + x) + c];
    return t / ((x1 - x0) * (y1 - y0));
}

/* PxrTexture as PRMan reads it: t inverted by default (a quad whose st
 * runs up, as Maya's do, shows the image's top row at its top), texels as
 * they are unless linearize; a PxrChecker of a manifold's 2 x 1 checks. */
static void test_patterns_rendered(void)
{
    FILE *f = fopen(RAYES_TEST_TMP "/test_rib_ris_rb.ppm", "wb"); /* top red, bottom blue */
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "P6 2 2 255\n");
        static const unsigned char px[12] = {255, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0, 255};
        fwrite(px, 1, sizeof px, f);
        fclose(f);
    }
    f = fopen(RAYES_TEST_TMP "/test_rib_ris_grey.ppm", "wb");
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "P6 1 1 255\n");
        fputc(128, f), fputc(128, f), fputc(128, f);
        fclose(f);
    }
#define PATTERN_SCENE(pattern)                                                                     \
    "Projection \"orthographic\"\nWorldBegin\nTranslate 0 0 5\n"                                   \
    "Light \"PxrDomeLight\" \"d\" \"float intensity\" [1]\n" pattern                               \
    "Bxdf \"PxrDiffuse\" \"x\" \"reference color diffuseColor\" [\"p:resultRGB\"]\n"               \
    "Polygon \"P\" [-1 1 0  1 1 0  1 -1 0  -1 -1 0] \"st\" [0 1  1 1  1 0  0 0]\nWorldEnd\n"
#define TEX(file, extra)                                                                           \
    "Pattern \"PxrTexture\" \"p\" \"string filename\" [\"" RAYES_TEST_TMP "/" file "\"] " extra "\n"
    RayesImage *dflt = render_text(PATTERN_SCENE(TEX("test_rib_ris_rb.ppm", "")));
    RayesImage *upright =
        render_text(PATTERN_SCENE(TEX("test_rib_ris_rb.ppm", "\"int invertT\" [0]")));
    RayesImage *raw = render_text(PATTERN_SCENE(TEX("test_rib_ris_grey.ppm", "")));
    RayesImage *lin =
        render_text(PATTERN_SCENE(TEX("test_rib_ris_grey.ppm", "\"int linearize\" [1]")));
    RayesImage *check = render_text(PATTERN_SCENE(
        "Pattern \"PxrManifold2D\" \"m\" \"float scaleS\" [2]\n"
        "Pattern \"PxrChecker\" \"p\" \"color colorA\" [1 1 0] \"color colorB\" [0 0 1] "
        "\"reference struct manifold\" [\"m:result\"]\n"));
    CHECK(dflt && upright && raw && lin && check);
    if (dflt && upright && raw && lin && check) {
        int q = SIZE / 4, h = SIZE / 2;
        /* the top quarter's middle, the bottom quarter's */
        /* the rows through the texels' centres (a 2 x 2 image, bilinear) */
        printf("  top row: red %.3f blue %.3f; invertT 0: red %.3f blue %.3f\n",
               region(dflt, 0, q, 3 * q, q - 1, q + 1), region(dflt, 2, q, 3 * q, q - 1, q + 1),
               region(upright, 0, q, 3 * q, q - 1, q + 1),
               region(upright, 2, q, 3 * q, q - 1, q + 1));
        CHECK(region(dflt, 0, q, 3 * q, q - 1, q + 1) > 0.8);
        CHECK(region(dflt, 2, q, 3 * q, q - 1, q + 1) < 0.1);
        CHECK(region(dflt, 2, q, 3 * q, 3 * q - 1, 3 * q + 1) > 0.8);
        CHECK(region(upright, 2, q, 3 * q, q - 1, q + 1) > 0.8);
        CHECK(region(upright, 0, q, 3 * q, q - 1, q + 1) < 0.1);
        /* 128 / 255 as it is, and through sRGB's inverse: 0.216 */
        printf("  grey texel: %.3f raw, %.3f linearized\n", region(raw, 1, q, 3 * q, q, 3 * q),
               region(lin, 1, q, 3 * q, q, 3 * q));
        CHECK_NEAR(region(raw, 1, q, 3 * q, q, 3 * q), 128.0 / 255.0, 0.03);
        CHECK_NEAR(region(lin, 1, q, 3 * q, q, 3 * q), 0.216, 0.01);
        /* two checks across, one up: yellow then blue along the top half */
        double left = region(check, 0, 4, q, 4, h - 4),
               right = region(check, 0, h + 4, 3 * q, 4, h - 4);
        double below = region(check, 0, 4, q, h + 4, SIZE - 4);
        printf("  checker: %.3f %.3f above, %.3f below\n", left, right, below);
        CHECK((left > 0.8 && right < 0.05) || (left < 0.05 && right > 0.8));
        CHECK(fabs(below - left) < 0.05); /* one check up: the same below */
    }
    rayes_image_free(dflt);
    rayes_image_free(upright);
    rayes_image_free(raw);
    rayes_image_free(lin);
    rayes_image_free(check);
#undef PATTERN_SCENE
#undef TEX
}

/* LightFilter binds to the lights after it in its block:
 * PxrIntMultLightFilter scales them (intensity 2^exposure colorTint);
 * lights after the block, and filters rayes does not build, leave them
 * as they are; EnableLightFilter is read. They refused the file. */
static void test_light_filters(void)
{
    CHECK(rib(WORLD("AttributeBegin\n"
                    "LightFilter \"PxrIntMultLightFilter\" \"f\" \"float intensity\" [3] "
                    "\"float exposure\" [-1] \"color colorTint\" [1 0.5 1]\n"
                    "Light \"PxrRectLight\" \"a\" \"float intensity\" [2]\n"
                    "AttributeEnd\n"
                    "Light \"PxrRectLight\" \"b\" \"float intensity\" [2]\n"
                    "LightFilter \"PxrBarnDoorLightFilter\" \"d\" \"float top\" [0.2]\n"
                    "Light \"PxrRectLight\" \"c\" \"float intensity\" [2]\n"
                    "EnableLightFilter \"c\" \"d\" 0\n" TRI)) == RAYES_OK);
    CHECK(rec.n_light == 3);
    if (rec.n_light == 3) {
        CHECK_NEAR(param(&rec.light[0], "intensity", 0), 3, 1e-6); /* 2 x 3 / 2 */
        CHECK_NEAR(param(&rec.light[0], "lightcolor", 1), 0.5, 1e-6);
        CHECK_NEAR(param(&rec.light[1], "intensity", 0), 2, 1e-6);
        CHECK_NEAR(param(&rec.light[2], "intensity", 0), 2, 1e-6);
    }
}

/* PxrMeshLight: the geometry after it in its block emits intensity
 * times lightColor (a quad as a quad light, triangles as a mesh light);
 * geometry after the block does not. */
/* PxrRectLight's coneAngle: the floor below the light as lit as without a
 * cone, the walls beyond it dark (no bounces); coneSoftness fades the
 * edge, leaving the walls between. */
static void test_light_cone(void)
{
    RayesImage *full = render_box("Light \"PxrRectLight\" \"k\" \"float intensity\" [6]", "");
    RayesImage *cone = render_box(
        "Light \"PxrRectLight\" \"k\" \"float intensity\" [6] \"float coneAngle\" [25]", "");
    RayesImage *soft = render_box("Light \"PxrRectLight\" \"k\" \"float intensity\" [6] "
                                  "\"float coneAngle\" [60] \"float coneSoftness\" [0.5]",
                                  "");
    CHECK(full && cone && soft);
    if (full && cone && soft) {
        double floor_full = region(full, 1, 12, 20, 27, 32),
               floor_cone = region(cone, 1, 12, 20, 27, 32);
        double wall_full = region(full, 1, 0, 3, 4, 14), wall_cone = region(cone, 1, 0, 3, 4, 14);
        double wall_soft = region(soft, 1, 0, 3, 4, 14);
        printf("  floor: %.4f, cone 25 %.4f; wall: %.4f, cone 25 %.4f, cone 60 soft %.4f\n",
               floor_full, floor_cone, wall_full, wall_cone, wall_soft);
        CHECK(fabs(floor_cone - floor_full) < 0.03 * floor_full);
        CHECK(wall_cone < 0.05 * wall_full && wall_full > 0.01);
        CHECK(wall_soft > wall_cone && wall_soft < wall_full);
    }
    rayes_image_free(full);
    rayes_image_free(cone);
    rayes_image_free(soft);
}

/* PxrCylinderLight: a tube along its x, 1 long and 1 across, lights the
 * room as the same tube made by a classic area light's Cylinder does. */
static void test_cylinder_light(void)
{
    CHECK(rib(WORLD("Light \"PxrCylinderLight\" \"t\" \"float intensity\" [2]\n" TRI)) == RAYES_OK);
    const RayesParam *shape = rec.n_light == 1 ? rec_param(light(), "shape") : NULL;
    CHECK(shape && strcmp(shape->string, "cylinder") == 0 && param(light(), "radius", 0) == 0.5f);
    RayesImage *tube = render_box("Scale 0.6 0.6 0.6\nTranslate 0 0 0.5\n"
                                  "Light \"PxrCylinderLight\" \"t\" \"float intensity\" [3]",
                                  "");
    RayesImage *classic = render_box("Scale 0.6 0.6 0.6\nTranslate 0 0 0.5\nRotate 90 0 1 0\n"
                                     "Attribute \"visibility\" \"int camera\" [0]\n"
                                     "AreaLightSource \"arealight\" 1 \"lightcolor\" [3 3 3]\n"
                                     "Cylinder 0.5 -0.5 0.5 360",
                                     "");
    CHECK(tube && classic);
    if (tube && classic) {
        double a = mean(tube, 1, 0), b = mean(classic, 1, 0);
        printf("  PxrCylinderLight %.4f, a classic Cylinder area light %.4f\n", a, b);
        CHECK(a > 0.02 && fabs(a - b) < 0.03 * b);
    }
    rayes_image_free(tube);
    rayes_image_free(classic);
}

static void test_mesh_light(void)
{
    CHECK(rib(WORLD(
              "AttributeBegin\n"
              "Light \"PxrMeshLight\" \"m\" \"float intensity\" [2] \"color lightColor\" [1 0.5 "
              "0.25] \"float exposure\" [1]\n"
              "Polygon \"P\" [0 0 1  1 0 1  1 1 1  0 1 1]\n"
              "PointsPolygons [3 3] [0 1 2 0 2 3] \"P\" [0 0 2  1 0 2  1 1 2  0 1 2.5]\n"
              "AttributeEnd\n" TRI)) == RAYES_OK);
    CHECK(rec.n_area == 1 && rec.n_mesh_light == 1 && rec.n_mesh == 1);
    CHECK(rec.area_L[0][0] == 4.0f && rec.area_L[0][2] == 1.0f); /* 2 x 2^1 x colour */
    CHECK(rec.mesh_light_faces[0] == 2 && rec.mesh_light_L[0][1] == 2.0f);
    /* areaNormalize: the radiance over each shape's area (a 2 x 2 quad) */
    CHECK(
        rib(WORLD("AttributeBegin\n"
                  "Light \"PxrMeshLight\" \"m\" \"float intensity\" [8] \"int areaNormalize\" [1]\n"
                  "Polygon \"P\" [0 0 1  2 0 1  2 2 1  0 2 1]\nAttributeEnd\n")) == RAYES_OK);
    CHECK(rec.n_area == 1 && fabsf(rec.area_L[0][0] - 2.0f) < 1e-5f);
    /* an output without patterns (this recording one) drops RenderMan's
     * bumps, displacements and fractals and reads on */
    CHECK(rib(WORLD(
              "Pattern \"PxrFractal\" \"f\" \"int layers\" [40]\n"
              "Pattern \"PxrBump\" \"b\" \"reference float inputBump\" [\"f:resultF\"]\n"
              "Displace \"PxrDisplace\" \"d\" \"reference float dispScalar\" [\"f:resultF\"]\n"
              "Bxdf \"PxrDiffuse\" \"x\" \"reference normal bumpNormal\" [\"b:resultN\"]\n" TRI)) ==
          RAYES_OK);
    CHECK(rec.n_mesh == 1);
}

/* PxrSurface's subsurface lobe: rayes' subsurface (memo 6.2) of
 * RenderMan's albedo and diffuse mean free path (subsurfaceDmfp times its
 * colour, mm) in unitLength's scale, the model's profile; lit from behind,
 * a sphere of it glows on the side the camera sees, where a diffuse one
 * is dark. */
static void test_subsurface_lobe(void)
{
    const RecShader *s =
        bxdf("Bxdf \"PxrSurface\" \"s\" \"float subsurfaceGain\" [1] "
             "\"color subsurfaceColor\" [0.5 0.4 0.3] \"float subsurfaceDmfp\" [2] "
             "\"color subsurfaceDmfpColor\" [1 0.5 0.25] \"float unitLength\" [0.2]");
    CHECK(strcmp(s->name, "subsurface") == 0);
    CHECK_NEAR(param(s, "albedo", 1), 0.4, 1e-6);
    CHECK_NEAR(param(s, "diffusemeanfreepath", 0), 2.0, 1e-6);
    CHECK_NEAR(param(s, "diffusemeanfreepath", 2), 0.5, 1e-6);
    CHECK_NEAR(param(s, "unitlength", 0), 0.2, 1e-6);
    CHECK_NEAR(param(s, "Ks", 0), 0.0, 1e-6); /* no specular lobe */
    const RayesParam *prof = rec_param(s, "profile");
    CHECK(prof && prof->string && strcmp(prof->string, "dipole") == 0);
    s = bxdf("Bxdf \"PxrSurface\" \"s\" \"float subsurfaceGain\" [1] \"int subsurfaceType\" [2] "
             "\"color specularFaceColor\" [0.04 0.04 0.04]");
    prof = rec_param(s, "profile");
    CHECK(prof && prof->string && strcmp(prof->string, "burley") == 0);
    CHECK_NEAR(param(s, "Ks", 0), 1.0, 1e-6);
    CHECK_NEAR(param(s, "diffusemeanfreepath", 1), 10 * 0.557, 1e-5); /* RenderMan's defaults */
#define BACKLIT(bxdf)                                                                              \
    "Projection \"orthographic\"\nScreenWindow -1.2 1.2 -1.2 1.2\nWorldBegin\nTranslate 0 0 5\n"   \
    "AttributeBegin\nRotate 180 0 1 0\n"                                                           \
    "Light \"PxrDistantLight\" \"s\" \"float intensity\" [3] \"int areaNormalize\" [1]\n"          \
    "AttributeEnd\n" bxdf "\nSphere 1 -1 1 360\nWorldEnd\n"
    RayesImage *sss = render_text(BACKLIT("Bxdf \"PxrSurface\" \"a\" \"float subsurfaceGain\" [1] "
                                          "\"float unitLength\" [1]"));
    RayesImage *dif =
        render_text(BACKLIT("Bxdf \"PxrSurface\" \"b\" \"color diffuseColor\" [0.8 0.8 0.8]"));
    CHECK(sss && dif);
    if (sss && dif) {
        int q = SIZE / 4;
        double a = region(sss, 1, q, 3 * q, q, 3 * q), b = region(dif, 1, q, 3 * q, q, 3 * q);
        printf("  lit from behind, the middle: subsurface %.4f, diffuse %.4f\n", a, b);
        CHECK(a > 0.02 && b < 0.001);
    }
    rayes_image_free(sss);
    rayes_image_free(dif);
#undef BACKLIT
}

/* The spread of channel c over the pixels whose alpha is over 1/2, and
 * their count. */
static double spread(const RayesImage *a, int c, int *count)
{
    double sum = 0.0, sq = 0.0;
    int m = 0;
    for (int k = 0; k < SIZE * SIZE; k++)
        if (a->rgba[4 * k + 3] > 0.5f) {
            double v = a->rgba[4 * k + c];
            sum += v, sq += v * v, m++;
        }
    *count = m;
    return m ? sqrt(fmax(sq / m - (sum / m) * (sum / m), 0.0)) : 0.0;
}

/* RIS bump and displacement: a PxrBump of a PxrFractal on a Bxdf's
 * bumpNormal bends the shading normals of a plane lit from the side (the
 * flat plane's pixels all alike; scale 0 gives the flat image), a PxrBump
 * of a texture with a step bends them along the step alone; PxrDisplace
 * moves a sphere's surface by dispScalar dispAmount in object units
 * (through a PxrDispTransform's centring too). */
static void test_bump_and_displacement(void)
{
    /* left half 0, right half 1: flat but for ramps between the halves'
     * middle texels, at s = 1/2 and (repeated) at s = 0 */
    FILE *f = fopen(RAYES_TEST_TMP "/test_rib_ris_step.ppm", "wb");
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "P6 8 1 255\n");
        for (int k = 0; k < 24; k++)
            fputc(k < 12 ? 0 : 255, f);
        fclose(f);
    }
#define PLANE(pattern, bump)                                                                       \
    "Projection \"orthographic\"\nWorldBegin\nTranslate 0 0 5\n"                                   \
    "AttributeBegin\nRotate -70 0 1 0\n"                                                           \
    "Light \"PxrDistantLight\" \"s\" \"float intensity\" [2] \"int areaNormalize\" [1]\n"          \
    "AttributeEnd\n" pattern                                                                       \
    "Bxdf \"PxrDiffuse\" \"x\" \"color diffuseColor\" [0.5 0.5 0.5] " bump                         \
    "\nPolygon \"P\" [-1 1 0  1 1 0  1 -1 0  -1 -1 0] \"st\" [0 1  1 1  1 0  0 0]\nWorldEnd\n"
#define FRACTAL(scale)                                                                             \
    "Pattern \"PxrFractal\" \"f\" \"float frequency\" [1.5]\n"                                     \
    "Pattern \"PxrBump\" \"b\" \"reference float inputBump\" [\"f:resultF\"] \"float scale\" "     \
    "[" scale "]\n"
#define BUMP "\"reference normal bumpNormal\" [\"b:resultN\"]"
    RayesImage *flat = render_text(PLANE("", ""));
    RayesImage *bumped = render_text(PLANE(FRACTAL("0.1"), BUMP));
    RayesImage *zero = render_text(PLANE(FRACTAL("0"), BUMP));
    RayesImage *step =
        render_text(PLANE("Pattern \"PxrBump\" \"b\" \"string filename\" [\"" RAYES_TEST_TMP
                          "/test_rib_ris_step.ppm\"] \"float scale\" [0.2]\n",
                          BUMP));
    CHECK(flat && bumped && zero && step);
    if (flat && bumped && zero && step) {
        int nf = 0, nb = 0;
        double sf = spread(flat, 1, &nf), sb = spread(bumped, 1, &nb);
        printf("  plane lit from the side: spread %.4f flat, %.4f bumped (%d, %d pixels)\n", sf, sb,
               nf, nb);
        CHECK(nf == SIZE * SIZE && nb == SIZE * SIZE);
        CHECK(sf < 0.002 && sb > 0.01);
        double worst = 0.0;
        for (int k = 0; k < 4 * SIZE * SIZE; k++)
            worst = fmax(worst, fabs((double)zero->rgba[k] - flat->rgba[k]));
        CHECK(worst < 1e-4);
        /* the step's ridge in the middle columns; the halves as flat */
        double mid = region(step, 1, SIZE / 2 - 1, SIZE / 2 + 1, 4, SIZE - 4);
        double left = region(step, 1, SIZE / 8 + 1, 3 * SIZE / 8 - 1, 4, SIZE - 4);
        double right = region(step, 1, 5 * SIZE / 8 + 1, 7 * SIZE / 8 - 1, 4, SIZE - 4);
        double plain = region(flat, 1, 2, SIZE - 2, 4, SIZE - 4);
        printf("  step bump: %.4f left, %.4f middle, %.4f right, flat %.4f\n", left, mid, right,
               plain);
        CHECK(fabs(left - plain) < 0.01 * plain && fabs(right - plain) < 0.01 * plain);
        CHECK(fabs(mid - plain) > 0.1 * plain);
    }
    rayes_image_free(flat);
    rayes_image_free(bumped);
    rayes_image_free(zero);
    rayes_image_free(step);
    /* a sphere of radius 1 (0.5 in its object space, scaled by 2) pushed
     * out by 0.25 object units: radius 1.5, 2.25 times the pixels */
#define BALL(pattern, displace)                                                                    \
    "Projection \"orthographic\"\nScreenWindow -2 2 -2 2\nWorldBegin\n"                            \
    "Translate 0 0 5\nLight \"PxrDomeLight\" \"d\" \"float intensity\" [1]\nScale 2 2 2\n"         \
    "Attribute \"displacementbound\" \"float sphere\" [0.5]\n" pattern displace                    \
    "Bxdf \"PxrDiffuse\" \"x\"\nSphere 0.5 -0.5 0.5 360\nWorldEnd\n"
#define HALF_TEX                                                                                   \
    "Pattern \"PxrTexture\" \"t\" \"string filename\" [\"" RAYES_TEST_TMP                          \
    "/test_rib_ris_grey.ppm\"]\n"
    RayesImage *ball = render_text(BALL("", ""));
    RayesImage *pushed =
        render_text(BALL("", "Displace \"PxrDisplace\" \"p\" \"float dispScalar\" [0.25]\n"));
    RayesImage *textured =
        render_text(BALL(HALF_TEX, "Displace \"PxrDisplace\" \"p\" "
                                   "\"reference float dispScalar\" [\"t:resultR\"] "
                                   "\"float dispAmount\" [0.5]\n"));
    RayesImage *centred = render_text(
        BALL(HALF_TEX "Pattern \"PxrDispTransform\" \"c\" \"reference float dispScalar\" "
                      "[\"t:resultR\"] \"int dispRemapMode\" [1] \"float dispCenter\" [0.502]\n",
             "Displace \"PxrDisplace\" \"p\" \"reference float dispScalar\" [\"c:resultF\"]\n"));
    CHECK(ball && pushed && textured && centred);
    if (ball && pushed && textured && centred) {
        double a0 = region(ball, 3, 0, SIZE, 0, SIZE), a1 = region(pushed, 3, 0, SIZE, 0, SIZE);
        double a2 = region(textured, 3, 0, SIZE, 0, SIZE),
               a3 = region(centred, 3, 0, SIZE, 0, SIZE);
        printf("  sphere coverage: %.4f, displaced %.4f (x %.3f), textured %.4f, centred %.4f\n",
               a0, a1, a1 / a0, a2, a3);
        CHECK_NEAR(a1 / a0, 2.25, 0.12);
        double r2 = 1.0 + 2.0 * 0.5 * 128.0 / 255.0; /* the grey texel, half, doubled */
        CHECK_NEAR(a2 / a0, r2 * r2, 0.12);
        CHECK_NEAR(a3, a0, 0.03 * a0);
    }
    rayes_image_free(ball);
    rayes_image_free(pushed);
    rayes_image_free(textured);
    rayes_image_free(centred);
#undef PLANE
#undef FRACTAL
#undef BUMP
#undef BALL
#undef HALF_TEX
}

TEST_MAIN(TEST(test_bxdfs), TEST(test_lights), TEST(test_geometry_lights), TEST(test_integrator),
          TEST(test_options), TEST(test_rendered), TEST(test_dome_visibility),
          TEST(test_tinted_glass), TEST(test_patterns_rendered), TEST(test_bump_and_displacement),
          TEST(test_subsurface_lobe), TEST(test_light_cone), TEST(test_cylinder_light),
          TEST(test_mesh_light), TEST(test_light_filters))
