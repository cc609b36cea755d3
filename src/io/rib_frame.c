/*
 * io/rib_frame.c — the block structure of a RIB file: frames (FrameBegin
 * and FrameEnd: the first pass lists them, the second reads only the
 * selected one), worlds (WorldBegin fixes the camera and turns the
 * transform into world_from_object; WorldEnd flushes the lights) and
 * object definitions (ObjectBegin records into a recording sink,
 * rib_record.c, replayed per ObjectInstance with its transform). Archives
 * are read by rib.c, which reads files.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_reader.h"

/* ------------------------------------------------------------ objects */

static Object *find_object(Rib *r, const char *key)
{
    for (size_t k = 0; k < r->n_objects; k++)
        if (strcmp(r->objects[k].key, key) == 0)
            return &r->objects[k];
    return NULL;
}

/* The object of that key, made if new (its recording, if any, freed: a
 * handle defined again is replaced). NULL after an error. */
static Object *define_object(Rib *r, const char *key)
{
    Object *o = find_object(r, key);
    if (o) {
        rib_recording_free(o->rec);
        o->rec = NULL;
        return o;
    }
    if (r->n_objects >= 65536) {
        rib_error(r, "more than 65536 objects");
        return NULL;
    }
    Object *no = realloc(r->objects, (r->n_objects + 1) * sizeof *no);
    if (!no) {
        rib_error(r, "out of memory");
        return NULL;
    }
    r->objects = no;
    o = &r->objects[r->n_objects++];
    snprintf(o->key, sizeof o->key, "%s", key);
    o->rec = NULL;
    return o;
}

/* A sink with instances (object_begin) gets the block as a master; one
 * without records it for replay as copies (rib_record.c). Either way the
 * block starts at the identity transform and its attributes are saved. */
static int h_object_begin(Rib *r, const Args *a)
{
    size_t i = 0;
    if (r->rec || r->in_object)
        return rib_error(r, "ObjectBegin inside an object definition");
    if (rib_get_handle(r, a, &i, r->rec_key) != 0)
        return -1;
    if (r->sink->object_begin) {
        if (r->sink->object_begin(r->sink->target, r->rec_key) != RAYES_OK)
            return rib_sink_failed(r, r->sink);
        r->in_object = 1;
        r->object_surface = r->a.surface;
        r->object_color_gen = r->a.color_gen;
        r->object_cs_gen = r->a.cs_gen;
        r->object_os_gen = r->a.os_gen;
    } else {
        r->rec = rib_recording_new();
        if (!r->rec)
            return rib_error(r, "out of memory");
        r->rec_sink = rib_recording_sink(r->rec);
    }
    memset(&r->recorded, 0, sizeof r->recorded);
    memcpy(r->rec_saved_M, r->a.M, sizeof r->rec_saved_M);
    rib_mat_identity(r->a.M);
    if (rib_push(r, 1) != 0)
        return -1;
    r->a.area = 0; /* area lights do not instance (the block's quads are geometry) */
    return 0;
}

static int h_object_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->rec && !r->in_object)
        return rib_error(r, "ObjectEnd without ObjectBegin");
    rib_pop(r, 1);
    memcpy(r->a.M, r->rec_saved_M, sizeof r->a.M);
    if (r->in_object) {
        r->in_object = 0;
        if (r->sink->object_end(r->sink->target) != RAYES_OK)
            return rib_sink_failed(r, r->sink);
        return define_object(r, r->rec_key) ? 0 : -1;
    }
    Object *o = define_object(r, r->rec_key);
    if (!o)
        return -1;
    o->rec = r->rec;
    r->rec = NULL;
    return 0;
}

/* An instance: to a sink with instances, the current state (transform,
 * shader and colour, light links) then object_instance; nested in a
 * block (the sink's, RenderMan allows it) the block's state. Else the
 * recording replayed under the current transform. */
static int h_object_instance(Rib *r, const Args *a)
{
    size_t i = 0;
    char key[RIB_MAX_HANDLE];
    if (rib_get_handle(r, a, &i, key) != 0)
        return -1;
    Object *o = find_object(r, key);
    if (!o)
        return rib_error(r, "no object has the handle %s", rib_handle_name(key));
    if (r->rec) /* the first pass (a sink without instances) cannot tell: the second says */
        return r->pass == 1 ? 0 : rib_error(r, "ObjectInstance inside an object definition");
    if (r->sink->object_instance) {
        int skip = rib_emit_begin(r, NULL);
        if (skip)
            return skip < 0 ? -1 : 0;
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        if (s->object_instance(s->target, key) != RAYES_OK)
            return rib_sink_failed(r, s);
        return 0;
    }
    if (!r->in_world) {
        rib_warn_once(r, "outside world", "geometry outside WorldBegin/WorldEnd is ignored");
        return 0;
    }
    if (rib_collapsed(r))
        return 0;
    if (rib_send_lights(r) != 0)
        return -1;
    RayesError e = rib_recording_replay(o->rec, r->sink, r->a.M);
    memset(&r->real, 0, sizeof r->real); /* the replay changed the sink's state */
    return e == RAYES_OK ? 0 : rib_sink_failed(r, r->sink);
}

/* ------------------------------------------------------ worlds, frames */

/* The shutter, the camera's motion and the lens, at WorldBegin. */
static int send_time(Rib *r, const IoSink *s)
{
    float open = r->shutter[0] + r->shutter_offset, close = r->shutter[1] + r->shutter_offset;
    int blur = close > open || r->camera_motion > 1 || r->dof[0] > 0.0f;
    if (blur && (!s->set_shutter || !s->set_camera_motion || !s->set_depth_of_field)) {
        rib_warn_once(r, "time", "this sink has no motion blur or depth of field: a still "
                                 "pinhole camera is used");
        return 0;
    }
    if (close > open && s->set_shutter(s->target, open, close) != RAYES_OK)
        return rib_sink_failed(r, s);
    if (r->camera_motion > 1 &&
        s->set_camera_motion(s->target, (size_t)r->camera_motion, r->camera_motion_time,
                             (const float(*)[16])r->camera_motion_M) != RAYES_OK)
        return rib_sink_failed(r, s);
    if (r->dof[0] > 0.0f &&
        s->set_depth_of_field(s->target, r->dof[1] / (2.0f * r->dof[0]), r->dof[2]) != RAYES_OK)
        return rib_sink_failed(r, s);
    return 0;
}

/* The named camera a world is seen from: the one Display's "string
 * camera" names, or, when the transform at WorldBegin places no camera
 * (the identity: RenderMan 22's layout restores it after declaring its
 * camera), the last declared; else NULL (the current transform is the
 * camera, as in classic files). */
static const struct NamedCamera *named_camera(const Rib *r)
{
    for (int k = 0; r->display_camera[0] && k < r->n_cameras; k++)
        if (strcmp(r->cameras[k].name, r->display_camera) == 0)
            return &r->cameras[k];
    float id[16];
    rib_mat_identity(id);
    return r->n_cameras > 0 && memcmp(r->a.M, id, sizeof id) == 0 ? &r->cameras[r->n_cameras - 1]
                                                                  : NULL;
}

static int h_world_begin(Rib *r, const Args *a)
{
    (void)a;
    if (r->in_world)
        return rib_error(r, "WorldBegin inside a world block");
    if (r->pass == 1 && r->in_frame && r->n_frames > 0)
        r->frames[r->n_frames - 1].renders |= !r->shadow_display;
    if (r->worlds++ > 0 && !r->in_frame)
        rib_warn_once(r, "worlds", "several world blocks outside frames are read into one scene");
    memcpy(r->camera_from_world, r->a.M, sizeof r->a.M);
    const struct NamedCamera *cam = named_camera(r);
    if (cam)
        memcpy(r->camera_from_world, cam->M, sizeof cam->M);
    r->camera_motion = r->a.n_motion;
    memcpy(r->camera_motion_time, r->a.motion_time, sizeof r->camera_motion_time);
    memcpy(r->camera_motion_M, r->a.motion_M, sizeof r->camera_motion_M);
    rib_mat_identity(r->a.M);
    r->a.n_motion = 0;
    r->in_world = 1;
    r->world_depth = r->depth;
    float sw[4];
    const float *screen = NULL;
    if (r->have_screen) {
        screen = r->screen;
    } else if (r->frame_aspect > 0) {
        float fa = r->frame_aspect;
        float s[4] = {-fa, fa, -1, 1}, t[4] = {-1, 1, -1 / fa, 1 / fa};
        memcpy(sw, fa >= 1 ? s : t, sizeof sw);
        screen = sw;
    }
    if (r->width == 0) {
        /* no Format: RenderMan's 640 x 480, or 640 wide at the frame's
         * aspect ratio (FrameAspectRatio, else ScreenWindow's), so that
         * the picture is not stretched */
        float aspect = 4.0f / 3.0f;
        if (r->frame_aspect > 0)
            aspect = r->frame_aspect;
        else if (r->have_screen && r->screen[3] > r->screen[2] && r->screen[1] > r->screen[0])
            aspect = (r->screen[1] - r->screen[0]) / (r->screen[3] - r->screen[2]);
        float h = roundf(640.0f / aspect);
        r->settings->width = 640;
        r->settings->height = h >= 1 && h <= 65536 ? (int)h : 480;
    }
    const IoSink *s = r->sink;
    if (s->set_camera_matrix(s->target, r->camera_from_world, (RayesProjection)r->projection,
                             r->fov, screen) != RAYES_OK)
        return rib_sink_failed(r, s);
    if (send_time(r, s) != 0)
        return -1;
    float wc[16];
    rib_world_from_camera(r, wc);
    for (size_t k = 0; k < r->n_lights; k++)
        if (r->lights[k].pre_world) {
            rib_mat_mul(wc, r->lights[k].M, r->lights[k].M);
            for (size_t i = 0; i < r->lights[k].n; i++) /* an uberlight's blocker too */
                if (r->lights[k].params[i].type == RAYES_PARAM_FLOATS)
                    rib_mat_mul(wc, r->lights[k].blocker, r->lights[k].blocker);
            r->lights[k].pre_world = 0;
        }
    memset(&r->real, 0, sizeof r->real);
    return 0;
}

static int h_world_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->in_world)
        return rib_error(r, "WorldEnd without WorldBegin");
    r->in_world = 0;
    memcpy(r->a.M, r->camera_from_world, sizeof r->a.M);
    return rib_flush_lights(r);
}

static int h_frame_begin(Rib *r, const Args *a)
{
    size_t i = 0;
    float n = 0;
    if (i < a->n && rib_get_floats(r, a, &i, &n, 1, "a frame number") != 0)
        return -1;
    if (!(fabsf(n) <= 1e9f) || n != floorf(n))
        return rib_error(r, "the frame number must be an integer, found %g", n);
    if (r->in_frame)
        return rib_error(r, "FrameBegin inside a frame");
    long ordinal = r->frame_ordinal++;
    r->in_frame = 1;
    if (r->pass == 1) {
        Frame *f = realloc(r->frames, (r->n_frames + 1) * sizeof *f);
        if (!f)
            return rib_error(r, "out of memory");
        r->frames = f;
        r->frames[r->n_frames++] = (Frame){(long)n, 0};
        r->frame_saved = *r->settings;
        r->frame_saved_shadow = r->shadow_display;
    } else if (ordinal != r->selected) {
        r->skipping = 1;
    }
    return 0;
}

static int h_frame_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->in_frame)
        return rib_error(r, "FrameEnd without FrameBegin");
    r->in_frame = 0;
    if (r->pass == 1) { /* frames keep their options to themselves */
        *r->settings = r->frame_saved;
        r->shadow_display = r->frame_saved_shadow;
    } else if (!r->skipping) {
        r->done = 1; /* the selected frame is read */
    }
    r->skipping = 0;
    return 0;
}


/* ------------------------------------------------------------ requests */

const RibRequest rib_frame_requests[] = {
    {"FrameBegin", h_frame_begin}, {"FrameEnd", h_frame_end}, {"WorldBegin", h_world_begin},
    {"WorldEnd", h_world_end}, {"ObjectBegin", h_object_begin}, {"ObjectEnd", h_object_end},
    {"ObjectInstance", h_object_instance},
    {NULL, NULL},
};
