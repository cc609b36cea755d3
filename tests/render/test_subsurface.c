/*
 * Subsurface scattering (memo 6.2) in renders: a thick marble slab lit
 * from above reflects the dipole's total diffuse reflectance (Jensen
 * 2001's closed form, computed here on its own) times E / pi, through the
 * coat's Fresnel transmission; a thin slab lit from below glows on top
 * (light bleeds through) and an opaque plate inside it (the same mesh:
 * an internal blocker) darkens the top; subsurface rays never leave their
 * object (an unlit sphere overlapping a lit one stays black); the
 * irradiance cache gives the uncached image within noise; images do not
 * depend on threads or the irradiance cache's budget; irradiance fills take
 * their own shadow-ray count (uncached hits the camera's); 4 subsurface
 * rays read cached irradiance at the resolutions 64 do.
 *
 * Units: mm. The camera looks down the z axis at the slabs' top (z = 0)
 * from 400 mm, seeing its central 40 mm.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "test.h"

enum { RES = 16 };

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

static RayesScene *new_scene(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 400}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up,
                                 (float)(2.0 * atan(20.0 / 400.0) * 180.0 / M_PI)) == RAYES_OK);
    return s;
}

/* A marble subsurface shader without coat highlights. */
static void marble(RayesScene *s, const char *profile)
{
    RayesParam p[3] = {ps("preset", "marble"), pf("Ks", 0.0f), ps("profile", profile)};
    CHECK(rayes_scene_set_shader(s, "subsurface", p, 3) == RAYES_OK);
}

/* Appends the 6 quads of the box [x0,x1] x [y0,y1] x [z0,z1] to a mesh. */
static void box(float h, float z0, float z1, int *nv, int *idx, float *P, int *n_faces,
                int *n_points)
{
    static const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                    {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    int base = *n_points;
    for (int k = 0; k < 8; k++) {
        float *p = P + 3 * (base + k);
        p[0] = (k & 1) ? h : -h;
        p[1] = (k & 2) ? h : -h;
        p[2] = (k & 4) ? z1 : z0;
    }
    for (int f = 0; f < 6; f++) {
        nv[*n_faces] = 4;
        for (int v = 0; v < 4; v++)
            idx[4 * *n_faces + v] = base + faces[f][v];
        (*n_faces)++;
    }
    *n_points += 8;
}

/* A slab of half width h from z0 to 0, and with `blocker` an opaque plate
 * of the same object inside it (the plate is a box too, so one mesh). */
static void slab(RayesScene *s, float h, float z0, int blocker)
{
    int nv[12], idx[48], n_faces = 0, n_points = 0;
    float P[16 * 3];
    box(h, z0, 0.0f, nv, idx, P, &n_faces, &n_points);
    if (blocker)
        box(0.8f * h, 0.55f * z0, 0.45f * z0, nv, idx, P, &n_faces, &n_points);
    CHECK(rayes_scene_polygon_mesh(s, (size_t)n_faces, nv, idx, (size_t)n_points, P) == RAYES_OK);
}

static void distant_light(RayesScene *s, float dz)
{
    RayesParam p[3] = {(RayesParam){"from", RAYES_PARAM_COLOR, {0, 0, dz}, NULL},
                       (RayesParam){"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                       pf("intensity", 1.0f)};
    CHECK(rayes_scene_light(s, "distantlight", p, 3) == RAYES_OK);
}

/* stats (may be NULL) receives the render's statistics. */
static RayesImage *render_res(RayesScene *s, int res, int threads, int rays, int cached, double mb,
                              RayesStats **stats)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = res;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 0;
    o.subsurface_rays = rays;
    o.irradiance_cache = cached;
    o.irradiance_cache_mb = mb;
    if (mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.cache_mb = o.opacity_cache_mb = 0.0, o.env_guide = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

static RayesImage *render(RayesScene *s, int threads, int rays, int cached, double mb)
{
    return render_res(s, RES, threads, rays, cached, mb, NULL);
}

static uint64_t stat(const RayesStats *st, const char *name)
{
    const RayesStat *x = rayes_stats_find(st, name);
    return x ? x->count : 0;
}

static void mean_rgb(const RayesImage *img, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    size_t n = img ? (size_t)img->width * img->height : 0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            out[c] += img->rgba[4 * i + c] / (double)n;
}

/* Jensen 2001's total diffuse reflectance, eq. 8, and Fdr for eta. */
static double rd_closed_form(double sigma_s, double sigma_a, double eta)
{
    double alpha = sigma_s / (sigma_s + sigma_a);
    double fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    double A = (1.0 + fdr) / (1.0 - fdr), q = sqrt(3.0 * (1.0 - alpha));
    return alpha / 2.0 * (1.0 + exp(-4.0 / 3.0 * A * q)) * exp(-q);
}

static const double marble_s[3] = {2.19, 2.62, 3.00}, marble_a[3] = {0.0021, 0.0041, 0.0071};

/* The top of a slab 60 mm thick lit from straight above (E = 1): Rd / pi
 * times the coat's transmission 1 - F0 at normal incidence, per channel. */
static void test_thick_slab_reflects_dipole_rd(void)
{
    const char *profiles[2] = {"dipole", "burley"};
    for (int k = 0; k < 2; k++) {
        RayesScene *s = new_scene();
        marble(s, profiles[k]);
        slab(s, 400.0f, -60.0f, 0);
        distant_light(s, 1.0f);
        RayesImage *img = render(s, 2, 256, 1, 20.0);
        double got[3], f0 = pow(0.3 / 2.3, 2.0);
        mean_rgb(img, got);
        for (int c = 0; c < 3; c++) {
            double want = rd_closed_form(marble_s[c], marble_a[c], 1.3) / M_PI * (1.0 - f0);
            CHECK_NEAR(got[c], want, 0.03 * want);
        }
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* A white furnace: a medium of albedo 1 (no absorption; sigma_s' 100 per
 * mm, so the diffusion reaches about 2 mm) in uniform light of radiance 1
 * from every direction (E = pi on the slab's top) gives back all but the
 * dipole's own shortfall and the coat's Fresnel: Rd(alpha' -> 1) (1 -
 * F0), Rd from the closed form at the renderer's largest albedo. */
static void test_white_furnace_conserves_energy(void)
{
    RayesScene *s = new_scene();
    RayesParam p[3] = {{"sigma_s", RAYES_PARAM_COLOR, {100, 100, 100}, NULL},
                       {"sigma_a", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                       pf("Ks", 0.0f)};
    CHECK(rayes_scene_set_shader(s, "subsurface", p, 3) == RAYES_OK);
    slab(s, 400.0f, -60.0f, 0);
    RayesParam env[1] = {pf("intensity", 1.0f)};
    CHECK(rayes_scene_light(s, "environmentlight", env, 1) == RAYES_OK);
    RayesImage *img = render(s, 2, 64, 1, 20.0);
    double got[3], f0 = pow(0.3 / 2.3, 2.0),
                   want = rd_closed_form(0.99999, 0.00001, 1.3) * (1 - f0);
    mean_rgb(img, got);
    CHECK(want > 0.95);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(got[c], want, 0.03 * want);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* RenderMan's classic parameters: albedo is the total diffuse reflectance
 * and diffusemeanfreepath 1 / sigma_tr, in mm times unitlength scene
 * units: a thick slab lit from above reflects albedo E / pi (1 - F0),
 * F0 of ior 1.4. */
static void test_renderman_albedo_and_mean_free_path(void)
{
    RayesScene *s = new_scene();
    RayesParam p[5] = {{"albedo", RAYES_PARAM_COLOR, {0.8f, 0.5f, 0.2f}, NULL},
                       {"diffusemeanfreepath", RAYES_PARAM_COLOR, {4.0f, 2.0f, 1.0f}, NULL},
                       pf("ior", 1.4f),
                       pf("unitlength", 2.0f),
                       pf("Ks", 0.0f)};
    CHECK(rayes_scene_set_shader(s, "subsurface", p, 5) == RAYES_OK);
    slab(s, 400.0f, -60.0f, 0);
    distant_light(s, 1.0f);
    RayesImage *img = render(s, 2, 256, 1, 20.0);
    double got[3], f0 = pow(0.4 / 2.4, 2.0);
    mean_rgb(img, got);
    for (int c = 0; c < 3; c++) {
        double want = p[0].value[c] / M_PI * (1.0 - f0);
        CHECK_NEAR(got[c], want, 0.03 * want);
    }
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* Mean brightness of the top of a 6 mm marble slab lit from below. */
static double backlit_top(int blocker)
{
    RayesScene *s = new_scene();
    marble(s, "dipole");
    slab(s, 400.0f, -6.0f, blocker);
    distant_light(s, -1.0f);
    RayesImage *img = render(s, 2, 64, 1, 20.0);
    double m[3];
    mean_rgb(img, m);
    rayes_image_free(img);
    rayes_scene_release(s);
    return (m[0] + m[1] + m[2]) / 3.0;
}

static void test_light_bleeds_through_and_blockers_stop_it(void)
{
    double open = backlit_top(0), blocked = backlit_top(1);
    CHECK(open > 0.01);          /* marble's diffusion length is about 8 mm */
    CHECK(blocked < 0.3 * open); /* the plate stops most of it */
}

/* Two subsurface spheres overlap, two objects (each set_shader makes
 * one); only B is lit (light links), and neither casts shadows, so B's
 * surface inside A is lit on either side. A's rays cross it: if they hit
 * it they would bring B's light into A. A's pixels must stay black. */
static void test_rays_never_leave_their_object(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 400}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 20.0f) == RAYES_OK);
    distant_light(s, 1.0f);
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ONLY, NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_CAMERA) == RAYES_OK); /* casts no shadow */
    marble(s, "dipole");
    float m[16] = {1, 0, 0, -15, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 30.0f) == RAYES_OK); /* A, left, unlit */
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ALL, NULL, 0) == RAYES_OK);
    marble(s, "dipole"); /* a shader makes a new object */
    m[3] = 15.0f;
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 30.0f) == RAYES_OK); /* B, right, lit */
    RayesImage *img = render(s, 2, 16, 1, 20.0);
    double left = 0.0, right = 0.0;
    for (int y = 0; img && y < RES; y++)
        for (int x = 0; x < RES; x++) {
            const float *p = img->rgba + 4 * (y * RES + x);
            double v = p[0] + p[1] + p[2];
            if (x < RES / 4) /* A only (B spans x > -15 mm) */
                left = fmax(left, v);
            else if (x >= 3 * RES / 4)
                right = fmax(right, v);
        }
    CHECK(right > 0.05);
    CHECK(left == 0.0);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A marble sphere lit from behind and above, seen from the front. */
static RayesScene *sphere_scene(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 150}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 20.0f) == RAYES_OK);
    RayesParam lp[2] = {(RayesParam){"from", RAYES_PARAM_COLOR, {80, 30, -40}, NULL},
                        pf("intensity", 8000.0f)};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    marble(s, "dipole");
    CHECK(rayes_scene_sphere(s, 10.0f) == RAYES_OK);
    return s;
}

static void test_cached_matches_uncached(void)
{
    RayesScene *s = sphere_scene();
    /* 96 pixels: the sphere is diced finely enough for grids to follow its
     * terminator (a 16 pixel one is a few micropolygons across, and the
     * cached irradiance, linear across each, is 4% too bright) */
    RayesStats *st_on = NULL, *st_off = NULL;
    RayesImage *on = render_res(s, 96, 2, 64, 1, 20.0, &st_on),
               *off = render_res(s, 96, 2, 64, 0, 20.0, &st_off);
    uint64_t lookups = stat(st_on, "cache/irradiance/fine/lookups") +
                       stat(st_on, "cache/irradiance/medium/lookups") +
                       stat(st_on, "cache/irradiance/coarse/lookups");
    uint64_t rays = stat(st_on, "rays/subsurface"), points = stat(st_on, "subsurface/points");
    /* every point casts a probe and 64 rays, the same with the cache off;
     * cached, each hit is a lookup and far fewer points are shaded for
     * irradiance than hits looked up; uncached, every hit is shaded */
    CHECK(points > 0 && rays == 65 * points && stat(st_off, "rays/subsurface") == rays);
    CHECK(lookups > points && stat(st_on, "subsurface/irradiance_points") < lookups / 10);
    CHECK(stat(st_off, "cache/irradiance/fine/lookups") == 0);
    CHECK(stat(st_off, "subsurface/irradiance_points") > lookups / 2);
    rayes_stats_free(st_on);
    rayes_stats_free(st_off);
    double a[3], b[3];
    mean_rgb(on, a);
    mean_rgb(off, b);
    for (int c = 0; c < 3; c++) {
        CHECK(b[c] > 0.001);
        CHECK_NEAR(a[c], b[c], 0.02 * b[c]);
    }
    rayes_image_free(on);
    rayes_image_free(off);
    rayes_scene_release(s);
}

static void test_same_image_whatever_threads_and_budget(void)
{
    RayesScene *s = sphere_scene();
    RayesImage *a = render(s, 2, 16, 1, 20.0), *b = render(s, 1, 16, 1, 20.0),
               *c = render(s, 3, 16, 1, 0.01), *u1 = render(s, 1, 16, 0, 20.0),
               *u2 = render(s, 2, 16, 0, 20.0);
    size_t bytes = (size_t)RES * RES * 4 * sizeof(float);
    CHECK(a && b && c && u1 && u2);
    if (a && b && c && u1 && u2) {
        CHECK(memcmp(a->rgba, b->rgba, bytes) == 0);
        CHECK(memcmp(a->rgba, c->rgba, bytes) == 0);
        CHECK(memcmp(u1->rgba, u2->rgba, bytes) == 0);
    }
    RayesImage *all[5] = {a, b, c, u1, u2};
    for (int k = 0; k < 5; k++)
        rayes_image_free(all[k]);
    rayes_scene_release(s);
}

/* The marble sphere under a spherical area light (its shadow rays per
 * point are the count asked for), rendered in preview (4 shadow and 4
 * subsurface rays) with fill_rays shadow rays at irradiance fills (0: the
 * default). */
static RayesImage *area_render(RayesScene *s, int threads, int cached, int fill_rays,
                               RayesStats **st)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 32;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 0;
    o.irradiance_cache = cached;
    o.irradiance_shadow_rays = fill_rays;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    return img;
}

static void test_irradiance_fills_take_their_own_shadow_rays(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 150}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    static const float at_light[16] = {1, 0, 0, 80, 0, 1, 0, 30, 0, 0, 1, -40, 0, 0, 0, 1};
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 20.0f) == RAYES_OK);
    RayesParam lp[3] = {ps("shape", "sphere"), pf("radius", 10.0f), pf("intensity", 80.0f)};
    CHECK(rayes_scene_set_transform(s, at_light) == RAYES_OK);
    CHECK(rayes_scene_light(s, "arealight", lp, 3) == RAYES_OK);
    CHECK(rayes_scene_set_transform(s, identity) == RAYES_OK);
    marble(s, "dipole");
    CHECK(rayes_scene_sphere(s, 10.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesStats *def = NULL, *sixteen = NULL, *sixty = NULL, *one = NULL, *u4 = NULL, *u64 = NULL;
    RayesImage *a = area_render(s, 2, 1, 0, &def), *b = area_render(s, 2, 1, 16, &sixteen),
               *c = area_render(s, 2, 1, 64, &sixty), *d = area_render(s, 1, 1, 0, &one),
               *e = area_render(s, 2, 0, 4, &u4), *f = area_render(s, 2, 0, 64, &u64);
    /* the default is the camera's count, 4 in preview */
    CHECK(stat(def, "irradiance_shadow_rays") == 4 &&
          stat(sixteen, "irradiance_shadow_rays") == 16);
    /* the same fills, more shadow rays at each of their points; the
     * camera hits' rays are the same */
    uint64_t pts = stat(def, "subsurface/irradiance_points");
    CHECK(pts > 0 && stat(sixteen, "subsurface/irradiance_points") == pts);
    CHECK(stat(def, "rays/shadow") < stat(sixteen, "rays/shadow"));
    CHECK(stat(sixteen, "rays/shadow") < stat(sixty, "rays/shadow"));
    CHECK(stat(sixty, "rays/shadow") - stat(def, "rays/shadow") >= pts);
    /* uncached, every subsurface hit takes the camera's shadow rays, the
     * option unused */
    CHECK(stat(u4, "rays/shadow") == stat(u64, "rays/shadow"));
    size_t bytes = (size_t)32 * 32 * 4 * sizeof(float);
    CHECK(a && b && d && e && f);
    if (a && b && d && e && f) {
        CHECK(memcmp(a->rgba, d->rgba, bytes) == 0); /* threads */
        CHECK(memcmp(a->rgba, b->rgba, bytes) != 0);
        CHECK(memcmp(e->rgba, f->rgba, bytes) == 0);
    }
    /* the camera's 8 with 8, and at most 16: final's 64 give 16 (DESIGN.md) */
    for (int k = 0; k < 2; k++) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, k ? RAYES_QUALITY_FINAL : RAYES_QUALITY_PREVIEW);
        o.width = o.height = 16;
        o.spp = 1;
        o.bounces = 0;
        if (!k)
            o.shadow_rays = o.shadow_rays_deep = 8;
        RayesImage *fin = NULL;
        RayesStats *fst = NULL;
        CHECK(rayes_render(s, &o, &fin, &fst) == RAYES_OK);
        CHECK(stat(fst, "shadow_rays") == (k ? 64u : 8u) &&
              stat(fst, "irradiance_shadow_rays") == (k ? 16u : 8u));
        rayes_image_free(fin);
        rayes_stats_free(fst);
    }
    RayesImage *imgs[6] = {a, b, c, d, e, f};
    RayesStats *sts[6] = {def, sixteen, sixty, one, u4, u64};
    for (int k = 0; k < 6; k++) {
        rayes_image_free(imgs[k]);
        rayes_stats_free(sts[k]);
    }
    rayes_scene_release(s);
}

/* The share of irradiance lookups at a level. */
static double level_share(const RayesStats *st, const char *level)
{
    static const char *const all[3] = {"coarse", "medium", "fine"};
    char name[64];
    double sum = 0.0, mine = 0.0;
    for (int l = 0; l < 3; l++) {
        snprintf(name, sizeof name, "cache/irradiance/%s/lookups", all[l]);
        double n = (double)stat(st, name);
        sum += n;
        if (!strcmp(all[l], level))
            mine = n;
    }
    return sum > 0.0 ? mine / sum : 0.0;
}

static void test_few_rays_read_final_resolutions(void)
{
    /* With 4 rays a ray's own footprint would pick coarse levels, whose
     * interpolant is biased; lookups are no coarser than 64 rays'
     * (SUBSURFACE_LOOKUP_RAYS), so preview reads the levels final does. */
    RayesScene *s = new_scene();
    marble(s, "dipole");
    slab(s, 60.0f, -6.0f, 0); /* flat, so coarse levels are allowed */
    distant_light(s, 1.0f);
    RayesStats *four = NULL, *sixty = NULL;
    RayesImage *a = render_res(s, 32, 2, 4, 1, 20.0, &four),
               *b = render_res(s, 32, 2, 64, 1, 20.0, &sixty);
    CHECK(stat(four, "subsurface/points") > 0);
    for (int l = 0; l < 3; l++) {
        const char *level = l == 0 ? "coarse" : l == 1 ? "medium" : "fine";
        CHECK_NEAR(level_share(four, level), level_share(sixty, level), 0.1);
    }
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_stats_free(four);
    rayes_stats_free(sixty);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_thick_slab_reflects_dipole_rd), TEST(test_white_furnace_conserves_energy),
          TEST(test_renderman_albedo_and_mean_free_path),
          TEST(test_light_bleeds_through_and_blockers_stop_it),
          TEST(test_rays_never_leave_their_object), TEST(test_cached_matches_uncached),
          TEST(test_same_image_whatever_threads_and_budget),
          TEST(test_irradiance_fills_take_their_own_shadow_rays),
          TEST(test_few_rays_read_final_resolutions))
