/*
 * shade/light.h — light sources (DESIGN.md "Lights").
 *
 * Area lights (one-sided quads, one-sided disks, spheres emitting outward,
 * meshes of triangles emitting from their fronts or both sides) and the
 * environment (dome) light have radiance and are sampled by
 * direction with a solid-angle pdf, so the direct-lighting service can
 * weigh their samples against BSDF samples (multiple importance sampling);
 * light_intersect gives the radiance and pdf of a BSDF-sampled direction.
 * Point, spot and distant lights are deltas: one direction, no pdf. Ambient
 * lights only add to the ambient service.
 *
 * Radiometry (RenderMan's): a point or spot light of intensity I (times
 * lightcolor) gives irradiance I / d^2 at normal incidence; a distant light
 * gives I. Area and environment lights emit radiance intensity * lightcolor
 * (times the map). Every quantity is world space.
 *
 * Environment maps are latitude-longitude, +y up: row 0 is straight up, the
 * last row straight down; the map's centre (u = 1/2) is the direction +z and
 * u grows toward -x, so a camera looking along +z with +y up sees the map
 * unmirrored, centred. The light's transform (when it was made) rotates the
 * map. Lookups take the nearest pixel, the same function the sampler draws.
 *
 * A light made under a moving transform moves within the frame: the
 * lighting services take it at each ray's time (light_at_time; DESIGN.md
 * "Motion blur and depth of field").
 *
 * Memory: a Light owns its map or mesh (light_fini frees them).
 * Thread-safety: every function but light_env_load, light_env_sky,
 * light_mesh_init and light_fini only reads the light.
 */
#ifndef RAYES_SHADE_LIGHT_H
#define RAYES_SHADE_LIGHT_H

#include <stddef.h>
#include <stdint.h>

#include "util/vec.h"

typedef enum LightType {
    LIGHT_QUAD = 0,
    LIGHT_DISK = 1,
    LIGHT_SPHERE = 2,
    LIGHT_POINT = 3,
    LIGHT_SPOT = 4,
    LIGHT_DISTANT = 5,
    LIGHT_AMBIENT = 6,
    LIGHT_ENVIRONMENT = 7,
    LIGHT_MESH = 8,
    LIGHT_UBER = 9
} LightType;

#define LIGHT_CATEGORY_MAX 128
#define LIGHT_MAX_TIMES 16 /* a moving light's time samples, at most (RAYES_MAX_TIMES) */

/* An environment light's guide bins (LightGuide, below). */
#define LIGHT_GUIDE_U 16
#define LIGHT_GUIDE_V 8
#define LIGHT_GUIDE_BINS (LIGHT_GUIDE_U * LIGHT_GUIDE_V)

/* A latitude-longitude map with its sampling distribution: pixel (x, y)
 * weighted by its luminance times sin(theta) at its centre, drawn as a row
 * (marginal cdf) then a column (that row's conditional cdf). Each cdf has
 * a guide table (Chen's cutpoints): guide[k] is the interval holding k / n
 * of n, where the search for a number of [k / n, (k + 1) / n) starts, so
 * that inverting takes a step or two on average, not log2(n). */
typedef struct LightEnvMap {
    int width, height;
    float *rgb;         /* width * height * 3, top row first */
    float *row_cdf;     /* height + 1 */
    float *col_cdf;     /* height * (width + 1) */
    float *pixel_pdf;   /* width * height: probability of drawing the pixel */
    int *row_guide;     /* height: row_cdf's */
    int *col_guide;     /* height * width: each row's col_cdf's */
    /* Its guide bins (LightGuide): bin (i, j) holds the pixels of columns
     * bin_x0[i] .. bin_x0[i + 1] - 1 and rows bin_y0[j] .. bin_y0[j + 1] - 1
     * (pixel x is in bin x * LIGHT_GUIDE_U / width); band_cdf[i * (height
     * + 1) + y] sums pixel_pdf over rows above y of column band i, and
     * bin_mass[j * LIGHT_GUIDE_U + i] is the bin's probability. */
    int bin_x0[LIGHT_GUIDE_U + 1], bin_y0[LIGHT_GUIDE_V + 1];
    double *band_cdf; /* double: a sky row's share beside a sun's in its band */
    float bin_mass[LIGHT_GUIDE_BINS];
} LightEnvMap;

/* Guided sampling of an environment light (DESIGN.md "Lights"): its
 * directions cut into LIGHT_GUIDE_U x LIGHT_GUIDE_V bins of the map's
 * latitude-longitude parameters (a map's bins end at pixel edges), and
 * its own pdf reweighted per bin by weights a caller knows better (how
 * much of each bin a surface sees): pdf(wi) = the light's pdf(wi) x
 * scale[bin of wi]. Drawn as a bin (by mass x weight), then a direction
 * of the bin by the light's own distribution there. Any positive weights
 * keep every estimate unbiased; a weight of 0 leaves its bin's light out. */
typedef struct LightGuide {
    float cdf[LIGHT_GUIDE_BINS + 1]; /* over the bins, of mass x weight */
    float scale[LIGHT_GUIDE_BINS];   /* weight / sum of mass x weight */
} LightGuide;

/* A mesh light's triangles (world space) in clusters of neighbours, at
 * most LIGHT_MESH_CLUSTERS: a point draws a cluster by an importance its
 * bounds give from there (LightMeshView), then a triangle of it by area,
 * then a point uniformly in the triangle. */
#define LIGHT_MESH_CLUSTERS 16

typedef struct LightCluster {
    Vec3 lo, hi;              /* bounds */
    Vec3 centre;              /* of the ball around the bounds */
    float radius2;            /* its radius squared */
    Vec3 axis;                /* unit; every face's front lies within the cone about it */
    float cos_cone, sin_cone; /* the cone's half-angle (cos_cone -1: any direction) */
    float area;
    uint32_t start, end; /* its triangles in LightMesh.v's order */
} LightCluster;

typedef struct LightMesh {
    size_t n;            /* triangles */
    Vec3 *v;             /* 3 n corners, cluster by cluster; the front is
                            (v1 - v0) x (v2 - v0) */
    float *cdf;          /* n + 1: within each cluster from 0 (at start) to 1 (end) */
    uint8_t *cluster_of; /* n: triangle k of the scene's order (prim first_prim + k) */
    LightCluster cluster[LIGHT_MESH_CLUSTERS];
    int n_clusters;
    uint32_t first_prim; /* the scene primitive of its first triangle */
    float area;          /* the whole mesh's */
    Vec3 lo, hi;         /* bounds */
    /* An emission texture (light_mesh_texture): the radiance at a point is
     * L times the image at its (s, t), bilinear, clamped at its edges,
     * (0, 0) its top left. NULL: L everywhere. */
    float *st;       /* 6 a triangle, in v's order: its corners' (s, t) */
    uint32_t *place; /* n: triangle k of the scene's order -> its place in v */
    float *tex;      /* tex_w x tex_h linear rgb, top row first */
    int tex_w, tex_h;
} LightMesh;

/* A mesh light's clusters weighed as seen from one point: cdf over them. */
typedef struct LightMeshView {
    int n;
    float cdf[LIGHT_MESH_CLUSTERS + 1]; /* cdf[n] the total; 0: nothing reaches the point */
} LightMeshView;

/* Barzel's light ("Lighting Controls for Computer Cinematography", 1997;
 * RenderMan's uberlight): a delta light at the origin of its own space
 * aiming along +z, whose intensity at a point is shaped in that space, not
 * physically: cut on and off by depth, a chosen distance falloff, a
 * superellipse cross-section, a beam falloff, a slide and projected noise;
 * its shadows may be off, coloured, cast from elsewhere (the cheat) or by
 * a blocker, a superellipse that stands in no ray's way (light_uber). */
typedef struct LightUber {
    int omni;     /* 1: every direction, depth = distance */
    int parallel; /* 1: rays along +z, shadows toward z = cuton */
    float cuton, cutoff, nearedge, faredge;
    float falloff, falloffdist, maxintensity, maxratio; /* maxratio: over intensity */
    float shearx, sheary, width, height, wedge, hedge, roundness, beam;
    float cos_cone; /* spot: the cone holding the cross-section */
    float noiseamp, noisefreq;
    Vec3 noiseoffset; /* in the light's space */
    Vec3 shadowcolor; /* what a shadowed point gets instead of lightcolor */
    Vec3 cheat;       /* the shadows' origin moved by this (light space) */
    int slide;        /* 1: env is a slide over the cross-section */
    int blocker;      /* 1: a blocker in the plane z = 0 of blocker_from_world */
    Mat4 blocker_from_world;
    float bwidth, bheight, bwedge, bhedge, bround;
} LightUber;

typedef struct Light {
    LightType type;
    Vec3 P[4];          /* quad corners as a bilinear patch: P00, P10, P01, P11 */
    Vec3 L;             /* radiance (area, environment) or intensity * lightcolor */
    float intensity;    /* L = intensity * color, kept apart for edits */
    Vec3 color;
    Vec3 from;          /* point, spot position; disk and sphere centre */
    Vec3 dir;           /* spot axis, distant light's direction of travel (unit) */
    Vec3 ex, ey;        /* disk: world images of the object x and y radii */
    Vec3 normal;        /* disk: unit emitting side */
    float radius;       /* sphere */
    float area;         /* disk */
    float cos_outer, cos_inner, beam; /* spot: cone edge, full beam, beamdistribution */
    float cone, cone_start;           /* quad, disk: the emission's cone (PxrRectLight's coneAngle,
                                         USD's shaping:cone), radians off the normal: the light
                                         fades from cone_start to cone and is 0 beyond; 0: none */
    Mat4 world_from_light, light_from_world; /* environment: the map's rotation */
    LightEnvMap *env;                        /* environment: NULL for a constant one; point and spot
                                                lights: their intensity by direction, or NULL */
    int map_projection;                      /* point and spot lights: env is an image projected
                                                along the light's +z (see light_sample), not a
                                                latitude-longitude map of directions */
    float map_tan;                           /* that projection's tan(fov / 2) */
    LightMesh *mesh;    /* mesh: its triangles */
    int two_sided;      /* mesh: emits from both sides */
    int emitter;        /* mesh: the scene object camera rays see it as (its own
                           Embree scene answers a BSDF direction: light_mesh_finish) */
    char category[LIGHT_CATEGORY_MAX]; /* comma-separated names */
    uint32_t seen_by; /* environment: the RayesRayType bits of the rays that see it as
                         the background (the visibility when it was made) */
    int shadowless;   /* 1: nothing shadows it (shadow rays are not traced) */
    int nondiffuse;   /* 1: it adds nothing to direct lighting's diffuse output */
    int nonspecular;  /* 1: nor to its specular one (RenderMan's __nonspecular) */
    LightUber uber;   /* uberlight: its shaping, in world_from_light's space */
    /* A light moving within the frame (made under a moving transform):
     * where it is at time t is the light above (at time[0]) moved by delta
     * blended linearly between the samples around t (light_at_time). */
    int n_times;        /* 0: still */
    float time[LIGHT_MAX_TIMES];
    Mat4 delta[LIGHT_MAX_TIMES]; /* world_from_light(time k) light_from_world(time 0) */
} Light;

/* A direction from a point toward a light. */
typedef struct LightSample {
    Vec3 wi;            /* unit, from the point toward the light */
    float dist;         /* to the light's surface or position; INFINITY for
                           distant and environment lights */
    Vec3 Li;            /* radiance (area, environment) or irradiance at
                           normal incidence (delta lights) */
    float pdf;          /* solid-angle pdf; 0 for delta lights */
} LightSample;

/* Point and unnormalised normal (dPda x dPdb, the emitting side; its length
 * is the area Jacobian) of a quad light at (a, b) in [0,1]^2. */
static inline void light_quad_eval(const Light *l, float a, float b, Vec3 *P, Vec3 *n)
{
    Vec3 e0 = v3_lerp(l->P[0], l->P[1], a), e1 = v3_lerp(l->P[2], l->P[3], a);
    *P = v3_lerp(e0, e1, b);
    Vec3 da = v3_lerp(v3_sub(l->P[1], l->P[0]), v3_sub(l->P[3], l->P[2]), b);
    *n = v3_cross(da, v3_sub(e1, e0));
}

/* Nonzero for lights with radiance sampled by area or direction (quad,
 * disk, sphere, environment): the ones weighed with MIS. */
static inline int light_is_area(const Light *l)
{
    return l->type == LIGHT_QUAD || l->type == LIGHT_DISK || l->type == LIGHT_SPHERE ||
           l->type == LIGHT_ENVIRONMENT || l->type == LIGHT_MESH;
}

/* What an uberlight sends toward a point: s as light_sample gives it (wi
 * toward the light, Li what arrives unshadowed), Ls what arrives where
 * the shadow ray is blocked (shadowcolor's), the shadow ray (sw, sdist:
 * toward the origin of its shadows), and the share a blocker lets through.
 * Arriving: Ls + (Li - Ls) * unblocked * transmittance along the ray. */
typedef struct LightUberSample {
    LightSample s;
    Vec3 Ls;
    Vec3 sw;
    float sdist;
    float unblocked;
} LightUberSample;

/* An uberlight as seen from o: 0 when it sends nothing there, else fills
 * *u. light_sample gives u->s with the blocker applied and no shadows. */
int light_uber_sample(const Light *l, Vec3 o, LightUberSample *u);

/* Barzel's superellipse clip at (x, y): 0 inside the superellipse of
 * half-axes (a, b), 1 outside the one of (A, B), smooth between; roundness
 * 0 gives rectangles, 1 ellipses. */
float light_superellipse(float x, float y, float a, float b, float A, float B, float roundness);

/* Nonzero if every point of an area light (quad, disk, sphere) lies below
 * the plane through o with unit normal n, by a margin: no direction from o
 * with a positive cosine to n reaches it, so a lit point facing n gets
 * nothing from it and its samples can be skipped. 0 for the others. */
int light_below_plane(const Light *l, Vec3 o, Vec3 n);

/* A ball holding an area light (quad, disk, sphere), as seen from one
 * point o: a direction from o that misses the ball misses the light, and
 * costs one dot product to reject instead of light_intersect's tests (the
 * BSDF strategies' directions, most of which miss a small light). The
 * ball is a little larger than the light, for rounding: it never rejects
 * a direction light_intersect would take. */
typedef struct LightBound {
    Vec3 dc;            /* from o to the ball's centre */
    float d2;           /* |dc|^2 */
    float r2;           /* the ball's radius squared, margin included */
    int all;            /* o inside the ball, or an unbounded light: no rejection */
} LightBound;

void light_bound_init(const Light *l, Vec3 o, LightBound *b);

/* 0 if the ray from the bound's point along unit wi misses the ball (so
 * light_intersect would return 0), else 1. */
static inline int light_bound_may_hit(const LightBound *b, Vec3 wi)
{
    if (b->all)
        return 1;
    float proj = v3_dot(b->dc, wi);
    return proj > 0.0f && b->d2 - proj * proj <= b->r2;
}

/* Nonzero if the light belongs to a selection as shader.h's direct_lighting
 * says: NULL or "" every light; "name" lights whose category list holds
 * name; "-name" those whose list does not. */
int light_category_match(const Light *l, const char *category);

/* Samples the light as seen from o with (a, b) in [0,1)^2. Returns 0 when
 * the light sends nothing toward o (behind a one-sided emitter, outside a
 * spot cone, o inside a sphere light), else fills *s. */
int light_sample(const Light *l, Vec3 o, float a, float b, LightSample *s);

/* The area or environment light along the ray o + t wi (wi unit), ignoring
 * everything else: returns 1 and fills *s (dist the hit distance, Li the
 * radiance, pdf what light_sample would give wi) if the ray meets its
 * emitting side, else 0. A mesh light has no search of its own here (0):
 * the renderer finds the hit in the emitter's Embree scene and calls
 * light_mesh_finish. */
int light_intersect(const Light *l, Vec3 o, Vec3 wi, LightSample *s);

/* Makes l a mesh light of n triangles (corners v, 3 n, world space; the
 * front is (v1 - v0) x (v2 - v0)), clustered; triangles without area are
 * kept, never drawn. Returns 0, or -1 when out of memory or when no
 * triangle has area. */
int light_mesh_init(Light *l, const Vec3 *v, size_t n, int two_sided);

/* The largest side of an emission texture kept (light_mesh_texture). */
#define LIGHT_TEXTURE_MAX 2048

/* Gives mesh light l (just made by light_mesh_init from the same n
 * triangles) an emission texture: st holds each triangle's corners' (s, t),
 * 6 floats a triangle in light_mesh_init's order, path names an image any
 * format OpenImageIO reads (integer files sRGB, decoded to linear). Returns
 * 0, or -1 with a message in err (the image cannot be read, or memory). */
int light_mesh_texture(Light *l, const float *st, const char *path, char *err, size_t err_size);

/* What a quad's or disk's emission cone (Light.cone) leaves of its
 * radiance toward a direction at cos_y to its normal: 1 within the cone's
 * start, fading by a smoothstep to 0 at its edge; 1 without a cone. */
float light_cone_factor(const Light *l, float cos_y);

/* A mesh light's radiance at point P of its triangle tri (the scene's
 * order): L, times its texture there when it has one. */
Vec3 light_mesh_radiance(const Light *l, uint32_t tri, Vec3 P);

/* Weighs a mesh light's clusters for the point o with normal N (zero: no
 * horizon), each by its area over the distance squared, times bounds on
 * the cosines at both ends: a cluster whose faces all face away from o, or
 * that lies wholly below o's horizon, gets 0 (it could give nothing). */
void light_mesh_view(const Light *l, Vec3 o, Vec3 N, LightMeshView *v);

/* light_sample for a mesh light seen as v says (from the same o). */
int light_mesh_sample(const Light *l, const LightMeshView *v, Vec3 o, float a, float b,
                      LightSample *s);

/* A mesh light met at distance t along wi (unit) from o on its triangle tri (the
 * scene's order) where the unit geometric normal is Ng (front as above):
 * 1 and *s filled (the pdf light_mesh_sample would give with v) if that
 * side emits, else 0. */
int light_mesh_finish(const Light *l, const LightMeshView *v, uint32_t tri, Vec3 o, Vec3 wi,
                      float t, Vec3 Ng, LightSample *s);

/* The probability that the environment light's own sampling draws a
 * direction of guide bin b (the bins' sum is 1; 0 for an empty map). */
float light_guide_mass(const Light *l, int b);

/* A direction of bin b of an environment light drawn from (a, c) in
 * [0, 1)^2 by the light's distribution within the bin; s->pdf is the
 * light's own (unguided) pdf. 0 when the bin sends nothing. */
int light_guide_bin_sample(const Light *l, int b, float a, float c, LightSample *s);

/* Makes g from weights w[b] >= 0 of the environment light l's bins.
 * Returns 0 (g unusable) when no bin has both mass and weight. */
int light_guide_init(const Light *l, const float *w, LightGuide *g);

/* light_sample of an environment light drawn by guide g. */
int light_guide_sample(const Light *l, const LightGuide *g, float a, float b, LightSample *s);

/* The factor g puts on the light's own pdf toward world direction wi
 * (unit): light_intersect's pdf times this is the guided draw's. */
float light_guide_factor(const Light *l, const LightGuide *g, Vec3 wi);

/* The environment light's radiance along world direction d (unit). */
Vec3 light_env_radiance(const Light *l, Vec3 d);

/* 0 when the environment light l sends nothing along world direction d
 * (unit): its guide bin there is black (or the light is); 1 when it may.
 * Reads no pixel of the map (a small table), so a caller can test a
 * direction's occlusion before paying for the map's look-up. */
int light_env_may_emit(const Light *l, Vec3 d);

/* How an environment map's pixels lie on the sphere of directions. */
enum {
    LIGHT_MAP_LATLONG = 0,    /* rayes' latitude-longitude (y up) */
    LIGHT_MAP_OCTAHEDRAL = 1, /* pbrt-v4's equal-area octahedral square */
    LIGHT_MAP_LATLONG_ZUP = 2 /* pbrt-v3's latitude-longitude: +z up, longitude from +x to +y */
};

/* Reads an environment map (any format OpenImageIO reads, linear) and
 * builds its distribution. A latitude-longitude map (LIGHT_MAP_LATLONG)
 * is used as it is; a square equal-area octahedral map (pbrt-v4's,
 * LIGHT_MAP_OCTAHEDRAL: light-space direction d at Clarberg's
 * EqualAreaSphereToSquare(d), its (0, 0) the top left) is resampled,
 * bilinearly, into a latitude-longitude map of twice its width; pbrt-v3's
 * z-up latitude-longitude (LIGHT_MAP_LATLONG_ZUP) into rayes' of its size.
 * Returns 0, or -1 with a one-line message in err. */
int light_env_load(Light *l, const char *path, int layout, char *err, size_t err_size);

/* An environment map of a clear sky (util/sky.h: Preetham et al.'s, in
 * cd/m^2, the sun's disk left out: a distant light is the sun) for the
 * sun direction sun (light space, +y the zenith) and turbidity, 512 x 256
 * latitude-longitude; below the horizon a Lambertian ground of albedo
 * ground lit by that sky and sun. Returns 0, or -1 with a message. */
int light_env_sky(Light *l, const float sun[3], float turbidity, const float ground[3], char *err,
                  size_t err_size);

/* The light at time t: l itself when it is still, else *tmp, made from l
 * moved to t (positions, axes, sizes; an environment map's rotation),
 * sharing l's map. Mesh lights are still (the scene makes them so). */
const Light *light_at_time(const Light *l, float t, Light *tmp);

/* Frees what the light owns. */
void light_fini(Light *l);

/* RenderMan's smoothstep. */
static inline float light_smoothstep(float lo, float hi, float x)
{
    if (x <= lo)
        return 0.0f;
    if (x >= hi)
        return 1.0f;
    float t = (x - lo) / (hi - lo);
    return t * t * (3.0f - 2.0f * t);
}

#endif /* RAYES_SHADE_LIGHT_H */
