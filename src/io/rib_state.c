/*
 * io/rib_state.c — the graphics state of the RIB reader: transforms and
 * the AttributeBegin/TransformBegin stack, coordinate systems, the camera
 * and image options (Format, Projection, Display, PixelSamples, ...) that
 * go to IoSettings or to the camera at WorldBegin, the attributes that
 * are values of Attr (colour, orientation, shading rate, Basis, ray
 * visibility and opacity modes), and Attribute and Option. Before
 * WorldBegin the current transform is camera_from_object, after it
 * world_from_object (Attr.M).
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_reader.h"

/* --------------------------------------------------------- transforms */

/* Concatenates m onto the current transform, and onto each of its motion
 * samples when it moves. */
static void concat(Rib *r, const float m[16])
{
    rib_mat_mul(r->a.M, m, r->a.M);
    for (int k = 0; k < r->a.n_motion; k++)
        rib_mat_mul(r->a.motion_M[k], m, r->a.motion_M[k]);
}

static int h_translate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3], m[16];
    if (rib_get_floats(r, a, &i, v, 3, "dx dy dz") != 0)
        return -1;
    rib_mat_identity(m);
    m[3] = v[0], m[7] = v[1], m[11] = v[2];
    concat(r, m);
    return 0;
}

static int h_scale(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3], m[16];
    if (rib_get_floats(r, a, &i, v, 3, "sx sy sz") != 0)
        return -1;
    rib_mat_identity(m);
    m[0] = v[0], m[5] = v[1], m[10] = v[2];
    concat(r, m);
    return 0;
}

static int h_rotate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4], m[16];
    if (rib_get_floats(r, a, &i, v, 4, "angle dx dy dz") != 0)
        return -1;
    if (!(sqrt((double)v[1] * v[1] + (double)v[2] * v[2] + (double)v[3] * v[3]) > 0))
        return rib_error(r, "the rotation axis is zero");
    rib_mat_rotate(v[0], v + 1, m);
    concat(r, m);
    return 0;
}

/* RenderMan's shear: points move along the second vector (a), so that the
 * first (d1, at angle theta from a) turns by the given angle toward it:
 * p' = p + k (p . b) a, b the unit vector in their plane perpendicular to
 * a on d1's side, k = cot(theta - angle) - cot(theta). The angle must lie
 * in (theta - 180, theta) degrees, as the specification says. */
static int h_skew(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[7], m[16];
    if (rib_get_floats(r, a, &i, v, 7, "angle dx1 dy1 dz1 dx2 dy2 dz2") != 0)
        return -1;
    double d1[3] = {v[1], v[2], v[3]}, ax[3] = {v[4], v[5], v[6]};
    double l1 = sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
    double la = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    if (!(l1 > 0) || !(la > 0) || !isfinite(l1) || !isfinite(la) || !isfinite(v[0]))
        return rib_error(r, "expected two finite non-zero vectors and a finite angle");
    double dot = 0, b[3], lb = 0;
    for (int k = 0; k < 3; k++)
        ax[k] /= la, d1[k] /= l1, dot += d1[k] * ax[k];
    for (int k = 0; k < 3; k++)
        b[k] = d1[k] - dot * ax[k], lb += b[k] * b[k];
    lb = sqrt(lb);
    double theta = acos(fmax(-1.0, fmin(1.0, dot))), angle = v[0] * M_PI / 180;
    if (!(lb > 1e-9) || !(angle < theta) || !(angle > theta - M_PI))
        return rib_error(r,
                         "expected an angle between %g and %g degrees (the vectors are %g "
                         "degrees apart), found %g",
                         theta * 180 / M_PI - 180, theta * 180 / M_PI, theta * 180 / M_PI, v[0]);
    double k = 1 / tan(theta - angle) - 1 / tan(theta);
    rib_mat_identity(m);
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++)
            m[4 * row + col] += (float)(k * ax[row] * b[col] / lb);
    concat(r, m);
    return 0;
}

static int get_matrix(Rib *r, const Args *a, float m[16])
{
    size_t i = 0;
    float v[16];
    if (rib_get_floats(r, a, &i, v, 16, "a 4 x 4 matrix") != 0)
        return -1;
    for (int row = 0; row < 4; row++) /* RIB matrices map row vectors: transpose */
        for (int col = 0; col < 4; col++)
            m[4 * row + col] = v[4 * col + row];
    return 0;
}

static int h_transform(Rib *r, const Args *a)
{
    r->a.n_motion = 0;
    return get_matrix(r, a, r->a.M);
}

static int h_concat(Rib *r, const Args *a)
{
    float m[16];
    if (get_matrix(r, a, m) != 0)
        return -1;
    concat(r, m);
    return 0;
}

static int h_identity(Rib *r, const Args *a)
{
    (void)a;
    rib_mat_identity(r->a.M);
    r->a.n_motion = 0;
    return 0;
}

static int h_perspective(Rib *r, const Args *a)
{
    size_t i = 0;
    float fov;
    if (rib_get_floats(r, a, &i, &fov, 1, "fov") != 0)
        return -1;
    if (!(fov > 0 && fov < 180))
        return rib_error(r, "fov must be in (0, 180)");
    float t = (float)tan(fov * M_PI / 360), m[16] = {1 / t, 0, 0, 0, 0, 1 / t, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    rib_warn_once(r, "Perspective", "Perspective concatenates a projective matrix; use Projection");
    concat(r, m);
    return 0;
}

int rib_push(Rib *r, int attribute)
{
    if (r->depth >= RIB_MAX_STACK)
        return rib_error(r, "more than %d nested blocks", RIB_MAX_STACK);
    if (!r->stack) {
        r->stack = malloc(RIB_MAX_STACK * sizeof *r->stack);
        if (!r->stack)
            return rib_error(r, "out of memory");
    }
    r->stack[r->depth].a = r->a;
    r->stack[r->depth].solid_op = -1;
    r->stack[r->depth].solid_sent = 0;
    r->stack[r->depth++].attribute = attribute;
    return 0;
}

int rib_pop(Rib *r, int attribute)
{
    if (r->depth == 0) {
        rib_warn_once(r, attribute ? "AttributeEnd" : "TransformEnd", "%s without a matching begin",
                  r->req);
        return 0;
    }
    StackEntry *s = &r->stack[--r->depth];
    static const char *const block[3] = {"TransformBegin", "AttributeBegin", "SolidBegin"};
    if (s->attribute != attribute)
        rib_warn_once(r, "unbalanced", "%s closes a %s block", r->req, block[s->attribute]);
    if (attribute) {
        r->a = s->a;
    } else {
        memcpy(r->a.M, s->a.M, sizeof r->a.M);
        r->a.n_motion = s->a.n_motion;
        memcpy(r->a.motion_time, s->a.motion_time, sizeof r->a.motion_time);
        memcpy(r->a.motion_M, s->a.motion_M, sizeof r->a.motion_M);
    }
    return 0;
}

/* SolidBegin "primitive" | "union" | "intersection" | "difference":
 * RenderMan's CSG (rayes_scene_solid_begin). The block saves the
 * attributes and the transform as AttributeBegin does (as Aqsis's and
 * PRMan's do). A solid inside a primitive solid is left out of the tree
 * (one warning), as Aqsis does; a sink without solids draws their
 * primitives (one warning). */
static int h_solid_begin(Rib *r, const Args *a)
{
    static const char *const names[] = {"primitive", "union", "intersection", "difference"};
    size_t i = 0;
    const char *op = rib_get_string(r, a, &i, "a solid operation");
    if (!op)
        return -1;
    int k = 0;
    while (k < 4 && strcmp(op, names[k]) != 0)
        k++;
    if (k == 4)
        return rib_error(r, "unknown solid operation \"%s\"; expected primitive, union, "
                            "intersection or difference",
                         op);
    int inner = -1, sent = 1; /* the innermost open solid's operation; all sent */
    for (size_t d = r->depth; d-- > 0;)
        if (r->stack[d].attribute == 2) {
            inner = r->stack[d].solid_op;
            sent = r->stack[d].solid_sent;
            break;
        }
    if (rib_push(r, 2) != 0)
        return -1;
    StackEntry *e = &r->stack[r->depth - 1];
    e->solid_op = k;
    if (inner == RAYES_SOLID_PRIMITIVE || !sent) {
        rib_warn_once(r, "solid in primitive",
                      "a solid inside a primitive solid is left out of the CSG tree (its "
                      "primitives belong to the primitive solid)");
        e->solid_op = RAYES_SOLID_PRIMITIVE;
        return 0;
    }
    if (!r->in_world && !r->rec && !r->in_object)
        return 0;
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (!s->solid_begin || !s->solid_end) {
        rib_warn_once(r, "solid sink",
                      "this sink has no solids: they are drawn as the union of their primitives");
        return 0;
    }
    if (s->solid_begin(s->target, (RayesSolidOp)k) != RAYES_OK)
        return rib_sink_failed(r, s);
    e->solid_sent = 1;
    return 0;
}

static int h_solid_end(Rib *r, const Args *a)
{
    (void)a;
    if (r->depth == 0 || r->stack[r->depth - 1].attribute != 2) {
        rib_warn_once(r, "SolidEnd", "SolidEnd without a matching SolidBegin");
        return r->depth ? rib_pop(r, 2) : 0;
    }
    if (r->stack[r->depth - 1].solid_sent) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        if (s->solid_end && s->solid_end(s->target) != RAYES_OK)
            return rib_sink_failed(r, s);
    }
    return rib_pop(r, 2);
}

static int h_attribute_begin(Rib *r, const Args *a) { (void)a; return rib_push(r, 1); }
static int h_attribute_end(Rib *r, const Args *a) { (void)a; return rib_pop(r, 1); }
static int h_transform_begin(Rib *r, const Args *a) { (void)a; return rib_push(r, 0); }
static int h_transform_end(Rib *r, const Args *a) { (void)a; return rib_pop(r, 0); }

static int h_coordinate_system(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a coordinate system name");
    if (!name)
        return -1;
    size_t k = 0;
    while (k < r->n_coordsys && strncmp(&r->coordsys_names[64 * k], name, 63) != 0)
        k++;
    if (k == r->n_coordsys) {
        if (k >= 4096)
            return rib_error(r, "more than 4096 coordinate systems");
        char *nn = realloc(r->coordsys_names, 64 * (k + 1));
        if (nn)
            r->coordsys_names = nn;
        float *nm = realloc(r->coordsys_M, 16 * (k + 1) * sizeof *nm);
        if (nm)
            r->coordsys_M = nm;
        int *nw = realloc(r->coordsys_world, (k + 1) * sizeof *nw);
        if (nw)
            r->coordsys_world = nw;
        if (!nn || !nm || !nw)
            return rib_error(r, "out of memory");
        snprintf(&r->coordsys_names[64 * k], 64, "%s", name);
        r->n_coordsys++;
    }
    memcpy(&r->coordsys_M[16 * k], r->a.M, 16 * sizeof(float));
    r->coordsys_world[k] = r->in_world;
    return 0;
}

/* world_from_camera, or the identity (with a warning) when singular. */
void rib_world_from_camera(Rib *r, float m[16])
{
    if (rib_mat_inverse(r->camera_from_world, m) != 0) {
        rib_warn_once(r, "singular camera", "the camera transform is singular");
        rib_mat_identity(m);
    }
}

static int h_coordsys_transform(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a coordinate system name");
    if (!name)
        return -1;
    r->a.n_motion = 0;
    if (strcmp(name, "world") == 0) {
        if (r->in_world)
            rib_mat_identity(r->a.M);
        else
            rib_warn_once(r, "coordsys world", "CoordSysTransform \"world\" before WorldBegin ignored");
        return 0;
    }
    if (strcmp(name, "camera") == 0) {
        if (r->in_world)
            rib_world_from_camera(r, r->a.M);
        else
            rib_mat_identity(r->a.M);
        return 0;
    }
    if (rib_coordsys(r, name, r->a.M) != 0)
        return rib_error(r, "unknown coordinate system \"%s\"", name);
    return 0;
}

const IoSink *rib_out_sink(Rib *r, SinkState **st)
{
    *st = r->rec || r->in_object ? &r->recorded : &r->real;
    return r->rec ? &r->rec_sink : r->sink;
}

int rib_coordsys(Rib *r, const char *name, float M[16])
{
    for (size_t k = r->n_coordsys; k-- > 0;)
        if (strcmp(&r->coordsys_names[64 * k], name) == 0) {
            const float *m = &r->coordsys_M[16 * k];
            if (r->in_world && !r->coordsys_world[k]) {
                float wc[16];
                rib_world_from_camera(r, wc);
                rib_mat_mul(wc, m, M);
            } else {
                memcpy(M, m, 16 * sizeof *m);
            }
            return 0;
        }
    return -1;
}

/* ------------------------------------------------------------ options */

/* Shutter open close: the interval camera rays sample (motion blur). */
static int h_shutter(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    if (rib_get_floats(r, a, &i, v, 2, "open close") != 0)
        return -1;
    if (!isfinite(v[0]) || !isfinite(v[1]) || v[1] < v[0])
        return rib_error(r, "expected finite open <= close, found %g %g", v[0], v[1]);
    r->shutter[0] = v[0], r->shutter[1] = v[1];
    return 0;
}

/* DepthOfField fstop focallength focaldistance (no arguments: a pinhole):
 * a thin lens of radius focallength / (2 fstop), camera-space units. */
static int h_depth_of_field(Rib *r, const Args *a)
{
    if (a->n == 0) {
        r->dof[0] = 0.0f;
        return 0;
    }
    size_t i = 0;
    float v[3];
    if (rib_get_floats(r, a, &i, v, 3, "fstop focallength focaldistance") != 0)
        return -1;
    if (!(v[0] > 0.0f) || !(v[1] >= 0.0f) || !(v[2] > 0.0f) || !isfinite(v[1]) ||
        !isfinite(v[2]))
        return rib_error(r, "expected fstop > 0, focallength >= 0 and "
                            "focaldistance > 0, found %g %g %g",
                         v[0], v[1], v[2]);
    memcpy(r->dof, v, sizeof r->dof);
    if (isinf(v[0]))
        r->dof[0] = 0.0f; /* RenderMan's infinite fstop: a pinhole */
    return 0;
}

static int h_format(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3];
    if (rib_get_floats(r, a, &i, v, 2, "width height") != 0)
        return -1;
    if (i < a->n && rib_get_floats(r, a, &i, v + 2, 1, "the pixel aspect ratio") != 0)
        return -1;
    if (!(v[0] >= 1 && v[0] <= 65536 && v[1] >= 1 && v[1] <= 65536))
        return rib_error(r, "the image size must be 1 to 65536 pixels");
    r->width = r->settings->width = (int)v[0];
    r->height = r->settings->height = (int)v[1];
    if (i == 3 && v[2] != 1 && v[2] != -1)
        rib_warn_once(r, "pixel aspect", "pixel aspect ratio %g treated as 1", (double)v[2]);
    return 0;
}

static int h_frame_aspect(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (rib_get_floats(r, a, &i, &v, 1, "the frame aspect ratio") != 0)
        return -1;
    if (!(v > 0))
        return rib_error(r, "the frame aspect ratio must be positive");
    r->frame_aspect = v;
    return 0;
}

static int h_screen_window(Rib *r, const Args *a)
{
    size_t i = 0;
    if (rib_get_floats(r, a, &i, r->screen, 4, "left right bottom top") != 0)
        return -1;
    r->have_screen = 1;
    return 0;
}

static int h_crop_window(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4];
    if (rib_get_floats(r, a, &i, v, 4, "xmin xmax ymin ymax") != 0)
        return -1;
    for (int k = 0; k < 4; k++)
        r->settings->crop[k] = v[k] < 0 ? 0 : v[k] > 1 ? 1 : v[k];
    return 0;
}

static int h_projection(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a projection name");
    if (!name)
        return -1;
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    const Param *fov = rib_find_param(p, n, "fov");
    int e = 0;
    /* RenderMan 21 and later name them PxrPerspective (PxrCamera), PxrOrthographic */
    if (strcmp(name, "orthographic") == 0 || strcmp(name, "PxrOrthographic") == 0) {
        r->projection = RAYES_PROJECTION_ORTHOGRAPHIC;
    } else {
        if (strcmp(name, "perspective") != 0 && strcmp(name, "PxrPerspective") != 0 &&
            strcmp(name, "PxrCamera") != 0) /* PxrCamera: RenderMan 22's, its lens effects unread */
            rib_warn_once(r, name, "projection \"%s\" is not supported; perspective used", name);
        r->projection = RAYES_PROJECTION_PERSPECTIVE;
        r->fov = 90;
        if (fov) {
            if (!rib_is_num(fov->v) || fov->v->n != 1 || !(fov->v->d[0] > 0 && fov->v->d[0] < 180))
                e = rib_arg_error(r, fov->v, "\"fov\" needs one angle in (0, 180) degrees");
            else
                r->fov = (float)fov->v->d[0];
        }
    }
    free(p);
    return e;
}

static int h_clipping(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    /* Rays start at the eye and go to infinity: the clipping planes only
     * matter to a z-buffer, and are read and ignored. */
    return rib_get_floats(r, a, &i, v, 2, "near far");
}

static int h_pixel_samples(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    if (rib_get_floats(r, a, &i, v, 2, "xsamples ysamples") != 0)
        return -1;
    if (!(v[0] >= 1 && v[0] <= 1024 && v[1] >= 1 && v[1] <= 1024))
        return rib_error(r, "pixel samples must be 1 to 1024 per axis");
    r->settings->spp = (int)roundf(v[0]) * (int)roundf(v[1]);
    return 0;
}

static int h_pixel_filter(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a filter name");
    float w[2];
    if (!name || rib_get_floats(r, a, &i, w, 2, "xwidth ywidth") != 0)
        return -1;
    if (!(w[0] > 0 && w[0] <= 64))
        return rib_error(r, "the filter width must be in (0, 64] pixels");
    int k = io_filter_named(name, NULL);
    if (k < 0) {
        rib_warn_once(r, name, "pixel filter \"%s\" is not built in; the gaussian (nearest "
                           "smooth filter) is used with the same width", name);
        k = RAYES_FILTER_GAUSSIAN;
    }
    r->settings->filter = k;
    r->settings->filter_width = w[0];
    return 0;
}

static int h_exposure(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    if (rib_get_floats(r, a, &i, v, 2, "gain gamma") != 0)
        return -1;
    if (!(v[0] > 0 && v[1] > 0))
        return rib_error(r, "gain and gamma must be positive");
    r->settings->exposure_gain = v[0];
    r->settings->exposure_gamma = v[1];
    return 0;
}

/* Imager "background": the image composited over a colour (the
 * "bgcolor", "background" or "color" parameter; white by default), as
 * RenderMan's background imager shader does; other imagers are warned. */
static int h_imager(Rib *r, const Args *a)
{
    size_t i = 0, n = 0;
    const char *name = rib_get_string(r, a, &i, "an imager shader name");
    if (!name)
        return -1;
    if (strcmp(name, "background") != 0) {
        rib_warn_once(r, "imager",
                      "Imager \"%s\" is not supported; ignored (rayes has "
                      "\"background\")",
                      name);
        return 0;
    }
    Param *p = NULL;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    float bg[3] = {1.0f, 1.0f, 1.0f};
    static const char *const names[] = {"bgcolor", "background", "color"};
    for (int k = 0; k < 3; k++) {
        const Param *q = rib_find_param(p, n, names[k]);
        if (!q)
            continue;
        if (q->v->kind != ARG_NUMS || q->v->n != 3) {
            size_t got = q->v->n;
            free(p);
            return rib_error(r, "\"%s\" needs one colour (3 numbers), found %zu", names[k],
                             got);
        }
        for (int c = 0; c < 3; c++)
            bg[c] = fabs(q->v->d[c]) <= FLT_MAX ? (float)q->v->d[c] : 0.0f;
        break;
    }
    free(p);
    for (int c = 0; c < 3; c++)
        r->settings->background[c] = bg[c];
    r->settings->background[3] = 1.0f;
    return 0;
}

static int h_quantize(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4];
    /* Quantisation follows the output file's type (8-bit PNG, float EXR). */
    if (!rib_get_string(r, a, &i, "the kind (\"rgba\" or \"z\")"))
        return -1;
    return rib_get_floats(r, a, &i, v, 4, "one min max dither");
}

static int is_shadow_display(const char *type, const char *mode)
{
    return strcmp(type, "zfile") == 0 || strcmp(type, "shadow") == 0 || strcmp(mode, "z") == 0;
}

/* Camera "name": the camera as it is now (its transform) kept under that
 * name, for WorldBegin (rib_frame.c); RenderMan 22's files declare it in
 * a TransformBegin block and pick it by Display's "string camera". */
static int h_camera(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a camera name");
    if (!name)
        return -1;
    if (r->in_world) {
        rib_warn_once(r, "camera in world", "Camera inside the world is ignored");
        return 0;
    }
    int k = 0;
    while (k < r->n_cameras && strcmp(r->cameras[k].name, name) != 0)
        k++;
    if (k == (int)(sizeof r->cameras / sizeof r->cameras[0])) {
        rib_warn_once(r, "cameras", "more than %zu named cameras: the others are ignored",
                      sizeof r->cameras / sizeof r->cameras[0]);
        return 0;
    }
    snprintf(r->cameras[k].name, sizeof r->cameras[k].name, "%s", name);
    memcpy(r->cameras[k].M, r->a.M, sizeof r->a.M);
    if (k == r->n_cameras)
        r->n_cameras++;
    return 0;
}

static int h_display(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "an image name");
    const char *type = name ? rib_get_string(r, a, &i, "a display type") : NULL;
    const char *mode = type ? rib_get_string(r, a, &i, "a display mode") : NULL;
    if (!mode)
        return -1;
    IoSettings *s = r->settings;
    int extra = name[0] == '+';
    if (!extra) {
        s->n_displays = 0;
        r->shadow_display = is_shadow_display(type, mode);
    }
    if (s->n_displays >= IO_MAX_DISPLAYS) {
        rib_warn_once(r, "displays", "more than %d displays: the others are ignored", IO_MAX_DISPLAYS);
        return 0;
    }
    for (size_t k = i; !extra && k + 1 < a->n; k++) /* "string camera" ["name"] */
        if (a->v[k].kind == ARG_STR && a->v[k].n == 1 &&
            (strcmp(a->v[k].s[0], "camera") == 0 || strcmp(a->v[k].s[0], "string camera") == 0) &&
            (a->v[k + 1].kind == ARG_STR || a->v[k + 1].kind == ARG_STRS) && a->v[k + 1].n >= 1)
            snprintf(r->display_camera, sizeof r->display_camera, "%s", a->v[k + 1].s[0]);
    IoDisplay *d = &s->displays[s->n_displays++];
    snprintf(d->name, sizeof d->name, "%s", name + extra);
    snprintf(d->type, sizeof d->type, "%s", type);
    snprintf(d->mode, sizeof d->mode, "%s", mode);
    return 0;
}

/* One count of a Hider parameter (RenderMan's "minsamples",
 * "maxsamples"), or 0 if absent or 0 (RenderMan's own choice, which
 * RenderMan for Maya writes); -1 on error. */
static int hider_count(Rib *r, const Param *p, size_t n, const char *name)
{
    const Param *q = rib_find_param(p, n, name);
    if (!q)
        return 0;
    if (!rib_is_num(q->v) || q->v->n != 1 || !(q->v->d[0] >= 0 && q->v->d[0] <= 1 << 20))
        return rib_arg_error(r, q->v, "\"%s\" needs one count from 0 to 1048576", name);
    return (int)q->v->d[0];
}

/* Hider "raytrace" "int minsamples" m "int maxsamples" M: RenderMan RIS's
 * adaptive pixel sampling, m samples everywhere (PixelSamples' place) and
 * up to M where the pixel is noisy (RayesRenderOptions.max_spp). */
static int h_hider(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a hider name");
    if (!name)
        return -1;
    if (strcmp(name, "hidden") != 0 && strcmp(name, "raytrace") != 0)
        rib_warn_once(r, name, "hider \"%s\" is not supported; rays are traced", name);
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    int lo = hider_count(r, p, n, "minsamples"), hi = hider_count(r, p, n, "maxsamples");
    free(p);
    if (lo < 0 || hi < 0)
        return -1;
    if (lo > 0)
        r->settings->spp = lo;
    if (hi > 0)
        r->settings->max_spp = hi;
    return 0;
}

static int h_pixel_variance(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (rib_get_floats(r, a, &i, &v, 1, "a pixel variance") != 0)
        return -1;
    if (!(v > 0.0f && v < 1e6f))
        return rib_error(r, "PixelVariance must be positive, found %g", (double)v);
    r->settings->adaptive_error = v;
    return 0;
}

static int h_shading_rate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (rib_get_floats(r, a, &i, &v, 1, "a shading rate") != 0)
        return -1;
    if (!(v > 0))
        return rib_error(r, "the shading rate must be positive");
    r->a.shading_rate = v;
    return 0;
}

static int h_sides(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (rib_get_floats(r, a, &i, &v, 1, "1 or 2") != 0)
        return -1;
    if (v != 1 && v != 2)
        return rib_error(r, "expected 1 or 2, found %g", (double)v);
    return 0;
}

static int h_orientation(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *o = rib_get_string(r, a, &i, "an orientation");
    if (!o)
        return -1;
    static const char *const names[] = {"outside", "inside", "lh", "rh"};
    for (int k = 0; k < 4; k++)
        if (strcmp(o, names[k]) == 0) {
            r->a.orient = k;
            return 0;
        }
    return rib_error(r, "expected \"outside\", \"inside\", \"lh\" or \"rh\", found \"%s\"", o);
}

static int h_reverse_orientation(Rib *r, const Args *a)
{
    (void)a;
    r->a.orient ^= 1; /* outside <-> inside, lh <-> rh */
    return 0;
}

static int h_color(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3];
    if (rib_get_floats(r, a, &i, v, 3, "a colour") != 0)
        return -1;
    int colour = strcmp(r->req, "Color") == 0;
    memcpy(colour ? r->a.Cs : r->a.Os, v, sizeof v);
    r->a.color_gen = ++r->next_gen;
    *(colour ? &r->a.cs_gen : &r->a.os_gen) = r->a.color_gen;
    return 0;
}

/* -------------------------------------------------- attributes, options */

/* A search path with "&" (the previous value, prev) expanded and "@" (the
 * default, none) dropped, into path_out (4096 bytes, truncated at an
 * entry). */
static void expand_search_path(const char *prev, const char *path, char *out)
{
    char buf[4096];
    out[0] = '\0';
    snprintf(buf, sizeof buf, "%s", path);
    for (char *save = NULL, *e = strtok_r(buf, ":", &save); e; e = strtok_r(NULL, ":", &save)) {
        const char *add = strcmp(e, "&") == 0 ? prev : strcmp(e, "@") == 0 ? "" : e;
        if (!add[0])
            continue;
        size_t len = strlen(out), k = strlen(add);
        if (len + k + 2 > 4096)
            break;
        if (len)
            out[len++] = ':';
        memcpy(out + len, add, k + 1);
    }
}

static int search_path(Rib *r, const char *kind, const char *path)
{
    char out[4096];
    if (strcmp(kind, "archive") == 0 || strcmp(kind, "resource") == 0) {
        expand_search_path(r->archive_path, path, out);
        snprintf(r->archive_path, sizeof r->archive_path, "%s", out);
    }
    if (strcmp(kind, "texture") == 0 || strcmp(kind, "resource") == 0) {
        expand_search_path(r->texture_path, path, out);
        snprintf(r->texture_path, sizeof r->texture_path, "%s", out);
    }
    if (strcmp(kind, "shader") == 0 || strcmp(kind, "texture") == 0 ||
        strcmp(kind, "resource") == 0) {
        const IoSink *s = r->sink;
        if (strcmp(kind, "resource") == 0)
            return (s->set_search_path(s->target, "shader", path) != RAYES_OK ||
                    s->set_search_path(s->target, "texture", path) != RAYES_OK)
                       ? rib_sink_failed(r, s)
                       : 0;
        if (s->set_search_path(s->target, kind, path) != RAYES_OK)
            return rib_sink_failed(r, s);
    }
    return 0;
}

/* Option "limits" "gridsize": RenderMan's micropolygons per grid. rayes'
 * grids have at most 64 x 64 micropolygons, so a larger value is clamped. */
static int set_grid_size(Rib *r, double g)
{
    if (!(g >= 1 && g <= 1e9) || g != floor(g))
        return rib_error(r, "Option \"limits\" \"gridsize\": expected a positive integer, "
                            "found %g", g);
    if (g > 4096)
        rib_warn_once(r, "gridsize", "Option \"limits\" \"gridsize\" %.0f: clamped to 4096 "
                                 "(64 x 64 micropolygons)", g);
    r->settings->grid_size = g > 4096 ? 4096 : (int)g;
    return 0;
}

/* The ray-type bits of Attribute "visibility"'s names: PRMan's "camera",
 * "diffuse", "specular", "transmission", the older "trace" (diffuse and
 * specular alike) and "indirect" (PRMan 13's indirect, diffuse rays); 0
 * for another name. */
static uint32_t visibility_bits(const char *name)
{
    return strcmp(name, "camera") == 0         ? RAYES_RAY_CAMERA
           : strcmp(name, "diffuse") == 0      ? RAYES_RAY_DIFFUSE
           : strcmp(name, "specular") == 0     ? RAYES_RAY_SPECULAR
           : strcmp(name, "transmission") == 0 ? RAYES_RAY_SHADOW
           : strcmp(name, "trace") == 0        ? RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR
           : strcmp(name, "indirect") == 0     ? RAYES_RAY_DIFFUSE
                                               : 0u;
}

/* The older "string transmission": "transparent" hides the object from
 * shadow rays; "opaque" and "Os" use Os alone (the primitive hit mode;
 * rayes does not force Os to 1), "shader" the shader. */
static int visibility_string(Rib *r, const char *v)
{
    int mode = strcmp(v, "shader") == 0                           ? RAYES_TRANSMISSION_SHADER
               : strcmp(v, "Os") == 0 || strcmp(v, "opaque") == 0 ? RAYES_TRANSMISSION_PRIMITIVE
                                                                  : -1;
    if (mode < 0 && strcmp(v, "transparent") != 0)
        return rib_error(r,
                         "Attribute \"visibility\" \"transmission\": expected "
                         "\"transparent\", \"opaque\", \"Os\" or \"shader\", found \"%.64s\"",
                         v);
    if (mode < 0) {
        r->a.visibility &= ~(uint32_t)RAYES_RAY_SHADOW;
        return 0;
    }
    r->a.visibility |= RAYES_RAY_SHADOW;
    r->a.hitmode = mode;
    return 0;
}

/* BMRT's Attribute "render" "string casts_shadows": "none" (hidden from
 * shadow rays), "opaque" and "Os" (Os alone), "shade" (the shader), as
 * "transmission" takes them. 0 done, -1 error, 1 not ours. */
static int attribute_render(Rib *r, const Param *q)
{
    if (strcmp(q->d.name, "casts_shadows") != 0 || q->v->n != 1 || rib_is_num(q->v))
        return 1;
    const char *v = q->v->s[0];
    if (strcmp(v, "none") == 0)
        return visibility_string(r, "transparent");
    if (strcmp(v, "shade") == 0)
        return visibility_string(r, "shader");
    if (strcmp(v, "opaque") == 0 || strcmp(v, "Os") == 0)
        return visibility_string(r, v);
    return rib_error(r,
                     "Attribute \"render\" \"casts_shadows\": expected \"none\", \"opaque\", "
                     "\"Os\" or \"shade\", found \"%.64s\"",
                     v);
}

/* Attributes that choose what rayes always does: the value that asks for
 * it is taken silently, another is said once (rayes keeps its way). 0
 * done, 1 not one of them. */
static int attribute_always(Rib *r, const char *group, const Param *q)
{
    static const struct {
        const char *group, *name, *what;
    } always[] = {
        {"render", "truedisplacement", "rayes always displaces the surface itself"},
        {"trace", "displacements", "rays always see the displaced surface"},
        {"dice", "binary", "rayes always dices at powers of two (for crack-free stitching)"},
    };
    for (size_t k = 0; k < sizeof always / sizeof always[0]; k++) {
        if (strcmp(group, always[k].group) != 0 || strcmp(q->d.name, always[k].name) != 0 ||
            !rib_is_num(q->v) || q->v->n != 1)
            continue;
        if (q->v->d[0] != 1) {
            char key[96];
            snprintf(key, sizeof key, "always %s:%s", group, q->d.name);
            rib_warn_once(r, key, "Attribute \"%s\" \"%s\" %g: %s; ignored", group, q->d.name,
                          q->v->d[0], always[k].what);
        }
        return 0;
    }
    return 1;
}

/* One parameter of Attribute "visibility": 0 done, -1 error, 1 not ours. */
static int attribute_visibility(Rib *r, const Param *q)
{
    uint32_t bits = visibility_bits(q->d.name);
    if (!bits || q->v->n != 1)
        return 1;
    if (!rib_is_num(q->v))
        return bits == RAYES_RAY_SHADOW ? visibility_string(r, q->v->s[0]) : 1;
    if (q->v->d[0] != 0)
        r->a.visibility |= bits;
    else
        r->a.visibility &= ~bits;
    if (bits & RAYES_RAY_CAMERA)
        r->a.camera_said = q->v->d[0] != 0;
    return 0;
}

/* One parameter of Attribute "shade": "string transmissionhitmode"
 * ("primitive" or "shader") and rayes' "int opacitycache" (0: this
 * object's opacity is never cached). 0 done, -1 error, 1 not ours. */
static int attribute_shade(Rib *r, const Param *q)
{
    if (q->v->n != 1)
        return 1;
    if (strcmp(q->d.name, "opacitycache") == 0 && rib_is_num(q->v)) {
        r->a.opacity_cache = q->v->d[0] != 0;
        return 0;
    }
    if (strcmp(q->d.name, "transmissionhitmode") != 0 || rib_is_num(q->v))
        return 1;
    const char *v = q->v->s[0];
    if (strcmp(v, "primitive") != 0 && strcmp(v, "shader") != 0)
        return rib_error(r,
                         "Attribute \"shade\" \"transmissionhitmode\": expected "
                         "\"primitive\" or \"shader\", found \"%.64s\"",
                         v);
    r->a.hitmode = v[0] == 'p' ? RAYES_TRANSMISSION_PRIMITIVE : RAYES_TRANSMISSION_SHADER;
    return 0;
}

/* Option "limits" "opacitycachememory": RenderMan's opacity cache, in KB. */
static int set_opacity_cache_memory(Rib *r, double kb)
{
    if (!(kb > 0 && kb <= 1e10))
        return rib_error(r,
                         "Option \"limits\" \"opacitycachememory\": expected a positive "
                         "size in KB, found %g",
                         kb);
    r->settings->opacity_cache_mb = kb * 1024.0 / 1e6;
    return 0;
}

static int h_option_attribute(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *group = rib_get_string(r, a, &i, "a name");
    Param *p;
    size_t n;
    if (!group || rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    int option = strcmp(r->req, "Option") == 0, e = 0;
    for (size_t k = 0; k < n && e == 0; k++) {
        const Param *q = &p[k];
        int mine = option                             ? 1
                   : strcmp(group, "visibility") == 0 ? attribute_visibility(r, q)
                   : strcmp(group, "shade") == 0      ? attribute_shade(r, q)
                   : strcmp(group, "render") == 0     ? attribute_render(r, q)
                                                      : 1;
        if (mine == 1 && !option)
            mine = attribute_always(r, group, q);
        if (mine <= 0) {
            e = mine;
        } else if (option && strcmp(group, "searchpath") == 0 && q->v->kind != ARG_NUM &&
                   q->v->kind != ARG_NUMS && q->v->n == 1) {
            e = search_path(r, q->d.name, q->v->s[0]);
        } else if (!option && strcmp(group, "light") == 0 && strcmp(q->d.name, "shadows") == 0 &&
                   !rib_is_num(q->v) && q->v->n == 1) {
            /* BMRT's ray-traced shadows of the lights that follow */
            if (strcmp(q->v->s[0], "on") == 0 || strcmp(q->v->s[0], "off") == 0)
                r->a.shadows = strcmp(q->v->s[0], "on") == 0 ? 1 : -1;
            else
                rib_warn_once(r, "light shadows",
                              "Attribute \"light\" \"shadows\" \"%.16s\": expected \"on\" or "
                              "\"off\"; ignored",
                              q->v->s[0]);
        } else if (!option && strcmp(group, "displacementbound") == 0 &&
                   strcmp(q->d.name, "sphere") == 0 && rib_is_num(q->v) && q->v->n == 1) {
            r->a.bound = (float)fabs(q->v->d[0]);
        } else if (!option && strcmp(group, "trace") == 0 && rib_is_num(q->v) && q->v->n == 1 &&
                   (strcmp(q->d.name, "maxdiffusedepth") == 0 ||
                    strcmp(q->d.name, "maxspeculardepth") == 0)) {
            /* PRMan's ray depths; rayes has one per render, so the last wins */
            double d = q->v->d[0]; /* NaN (a binary float) counts as 0 */
            int depth = !(d > 0) ? 0 : d > 1e6 ? 1000000 : (int)d;
            if (q->d.name[3] == 'd')
                r->settings->bounces = depth;
            else
                r->settings->specular_depth = depth;
        } else if (option && strcmp(group, "trace") == 0 && strcmp(q->d.name, "maxdepth") == 0 &&
                   rib_is_num(q->v) && q->v->n == 1) {
            /* the older RenderMans' (and Aqsis's, 3Delight's) depth of traced
             * rays: rayes's specular depth (its diffuse bounces are its own) */
            double d = q->v->d[0];
            r->settings->specular_depth = !(d > 0) ? 0 : d > 1e6 ? 1000000 : (int)d;
        } else if (option && strcmp(group, "limits") == 0 && strcmp(q->d.name, "gridsize") == 0 &&
                   rib_is_num(q->v) && (q->v->n == 1 || q->v->n == 2)) {
            /* Aqsis's older form gives a grid's sides: [32 32], 1024 */
            e = set_grid_size(r, q->v->n == 2 ? q->v->d[0] * q->v->d[1] : q->v->d[0]);
        } else if (option && strcmp(group, "limits") == 0 &&
                   strcmp(q->d.name, "texturememory") == 0 && rib_is_num(q->v) && q->v->n == 1) {
            /* RenderMan's texture cache, in KB */
            double kb = q->v->d[0];
            if (!(kb > 0 && kb <= 1e10))
                e = rib_error(r,
                              "Option \"limits\" \"texturememory\": expected a positive "
                              "size in KB, found %g",
                              kb);
            else
                r->settings->texture_mb = kb * 1024.0 / 1e6;
        } else if (option && strcmp(group, "limits") == 0 &&
                   strcmp(q->d.name, "opacitycachememory") == 0 && rib_is_num(q->v) &&
                   q->v->n == 1) {
            e = set_opacity_cache_memory(r, q->v->d[0]);
        } else if (!option && strcasecmp(group, "ri") == 0 &&
                   strcmp(q->d.name, "Orientation") == 0 && !rib_is_num(q->v) && q->v->n == 1) {
            /* RenderMan 22's Attribute "Ri": the requests' attributes */
            static const char *const names[] = {"outside", "inside", "lh", "rh"};
            int k = 0;
            while (k < 4 && strcmp(q->v->s[0], names[k]) != 0)
                k++;
            if (k < 4)
                r->a.orient = k;
            else
                e = rib_error(r,
                              "Attribute \"Ri\" \"Orientation\": expected \"outside\", "
                              "\"inside\", \"lh\" or \"rh\", found \"%.60s\"",
                              q->v->s[0]);
        } else if (!option && strcasecmp(group, "ri") == 0 &&
                   strcmp(q->d.name, "ShadingRate") == 0 && rib_is_num(q->v) && q->v->n == 1 &&
                   q->v->d[0] > 0) {
            r->a.shading_rate = (float)q->v->d[0];
        } else if (!option && strcasecmp(group, "ri") == 0 && strcmp(q->d.name, "Sides") == 0) {
            /* rayes shades both sides, as Sides 2 */
        } else if (option && strcasecmp(group, "ri") == 0 &&
                   strcmp(q->d.name, "FormatResolution") == 0 && rib_is_num(q->v) && q->v->n == 2) {
            /* RenderMan 21 and later's Format */
            double w = q->v->d[0], h = q->v->d[1];
            if (!(w >= 1 && w <= 65536 && h >= 1 && h <= 65536))
                e = rib_error(r, "the image size must be 1 to 65536 pixels");
            else {
                r->width = r->settings->width = (int)w;
                r->height = r->settings->height = (int)h;
            }
        } else if (option && strcasecmp(group, "ri") == 0 &&
                   strcmp(q->d.name, "FormatPixelAspectRatio") == 0 && rib_is_num(q->v) &&
                   q->v->n == 1) {
            if (q->v->d[0] != 1)
                rib_warn_once(r, "pixel aspect", "pixel aspect ratio %g treated as 1", q->v->d[0]);
        } else if (!option && strcmp(group, "trimcurve") == 0 && strcmp(q->d.name, "sense") == 0 &&
                   !rib_is_num(q->v) && q->v->n == 1) {
            const char *v = q->v->s[0]; /* which side of the trim loops is cut away */
            if (strcmp(v, "inside") == 0 || strcmp(v, "outside") == 0)
                r->a.trim_outside = v[0] == 'o';
            else
                e = rib_error(r,
                              "Attribute \"trimcurve\" \"sense\": expected \"inside\" or "
                              "\"outside\", found \"%.64s\"",
                              v);
        } else if (!option && strcmp(group, "dice") == 0 && strcmp(q->d.name, "roundcurve") == 0 &&
                   rib_is_num(q->v) && q->v->n == 1) {
            r->a.roundcurve = q->v->d[0] != 0;
        } else if (!option && strcmp(group, "dice") == 0 &&
                   (strcmp(q->d.name, "motionfactor") == 0 ||
                    strcmp(q->d.name, "focusfactor") == 0) &&
                   rib_is_num(q->v) && q->v->n == 1) {
            double f = q->v->d[0];
            if (!(f >= 0 && f <= 1e6))
                e = rib_error(r, "Attribute \"dice\" \"%s\": expected a factor >= 0, found %g",
                              q->d.name, f);
            else if (q->d.name[0] == 'm')
                r->a.motionfactor = (float)f;
            else
                r->a.focusfactor = (float)f;
        } else if (option && strcmp(group, "shutter") == 0 && strcmp(q->d.name, "offset") == 0 &&
                   rib_is_num(q->v) && q->v->n == 1) {
            if (!isfinite(q->v->d[0]))
                e = rib_error(r, "Option \"shutter\" \"offset\": expected a finite time");
            else
                r->shutter_offset = (float)q->v->d[0];
        } else if (option && strcmp(group, "rayes") == 0 && strcmp(q->d.name, "pngcurve") == 0 &&
                   q->d.ty == TY_STRING && q->v->n == 1) {
            const char *c = q->v->s[0];
            if (strcmp(c, "srgb") != 0 && strcmp(c, "linear") != 0)
                e = rib_error(r,
                              "Option \"rayes\" \"pngcurve\": expected \"srgb\" or "
                              "\"linear\", found \"%s\"",
                              c);
            else
                r->settings->png_curve = c[0] == 's' ? IO_CURVE_SRGB : IO_CURVE_LINEAR;
        } else if (strcmp(group, "identifier") == 0 || strcmp(group, "user") == 0) {
            /* names are for messages only; user data is for the user's own
             * shaders (PRMan keeps it without a word) */
        } else if (!(!option && strcmp(group, "displacementbound") == 0)) {
            char key[160];
            snprintf(key, sizeof key, "%s %s:%s", r->req, group, q->d.name);
            rib_warn_once(r, key, "%s \"%s\" \"%s\" is not supported and ignored", r->req, group,
                      q->d.name);
        }
    }
    free(p);
    return e;
}

static int get_basis(Rib *r, const Args *a, size_t *i, float m[16])
{
    if (*i < a->n && a->v[*i].kind == ARG_STR) {
        int step;
        const char *name = a->v[(*i)++].s[0];
        if (rib_basis_named(name, m, &step) != 0)
            return rib_error(r, "unknown basis \"%s\" (bezier, b-spline, catmull-rom, hermite, "
                                "power or 16 numbers)", name);
        return 0;
    }
    return rib_get_floats(r, a, i, m, 16, "a basis name or matrix");
}

static int h_basis(Rib *r, const Args *a)
{
    size_t i = 0;
    float ub[16], vb[16], us, vs;
    if (get_basis(r, a, &i, ub) != 0 || rib_get_floats(r, a, &i, &us, 1, "the u step") != 0 ||
        get_basis(r, a, &i, vb) != 0 || rib_get_floats(r, a, &i, &vs, 1, "the v step") != 0)
        return -1;
    if (!(us >= 1 && us <= 4 && vs >= 1 && vs <= 4) || us != floorf(us) || vs != floorf(vs))
        return rib_error(r, "steps must be integers from 1 to 4");
    memcpy(r->a.ubasis, ub, sizeof ub);
    memcpy(r->a.vbasis, vb, sizeof vb);
    r->a.ustep = (int)us;
    r->a.vstep = (int)vs;
    return 0;
}


/* ------------------------------------------------------------ requests */

const RibRequest rib_state_requests[] = {
    {"AttributeBegin", h_attribute_begin},
    {"AttributeEnd", h_attribute_end},
    {"SolidBegin", h_solid_begin},
    {"SolidEnd", h_solid_end},
    {"TransformBegin", h_transform_begin},
    {"TransformEnd", h_transform_end},
    {"Identity", h_identity},
    {"Transform", h_transform},
    {"ConcatTransform", h_concat},
    {"Translate", h_translate},
    {"Rotate", h_rotate},
    {"Scale", h_scale},
    {"Skew", h_skew},
    {"Perspective", h_perspective},
    {"CoordinateSystem", h_coordinate_system},
    {"ScopedCoordinateSystem", h_coordinate_system},
    {"CoordSysTransform", h_coordsys_transform},
    {"Format", h_format},
    {"FrameAspectRatio", h_frame_aspect},
    {"ScreenWindow", h_screen_window},
    {"CropWindow", h_crop_window},
    {"Projection", h_projection},
    {"Clipping", h_clipping},
    {"Shutter", h_shutter},
    {"DepthOfField", h_depth_of_field},
    {"PixelSamples", h_pixel_samples},
    {"PixelFilter", h_pixel_filter},
    {"PixelVariance", h_pixel_variance},
    {"Exposure", h_exposure},
    {"Quantize", h_quantize},
    {"Imager", h_imager},
    {"Display", h_display},
    {"Camera", h_camera},
    {"Hider", h_hider},
    {"ShadingRate", h_shading_rate},
    {"Sides", h_sides},
    {"Orientation", h_orientation},
    {"ReverseOrientation", h_reverse_orientation},
    {"Color", h_color},
    {"Opacity", h_color},
    {"Attribute", h_option_attribute},
    {"Option", h_option_attribute},
    {"Basis", h_basis},
    {NULL, NULL},
};
