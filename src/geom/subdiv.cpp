/*
 * geom/subdiv.cpp — subdivision surfaces through OpenSubdiv's Bfr
 * (subdiv.h): the one C++ file of rayes, a C interface over the library.
 *
 * The mesh's topology and tags go into a Far::TopologyRefiner; a
 * Bfr::RefinerSurfaceFactory gives each face its Surface (the exact limit
 * surface, as one or more parametric patches), and each Surface's patch
 * points are prepared once, here, so that evaluation at dicing is a pure
 * function of (patch, u, v). Point data is laid out per channel: the
 * vertex channel holds P and the vertex primitive variables side by side
 * (one evaluation gives both, with derivatives); the varying and
 * face-varying channels hold theirs. Uniform and constant values are
 * copied per face.
 */
#include "geom/subdiv.h"

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

using namespace OpenSubdiv;

#define SUBDIV_APPROX_LEVEL 6 /* Bfr's refinement level near extraordinary vertices */

namespace {

typedef Bfr::Surface<float> Surface;
typedef Far::TopologyDescriptor Descriptor;

/* The control mesh's topology and tags as OpenSubdiv takes them (the
 * arrays are d's, borrowed). */
static Descriptor topology(const SubdivDesc *d)
{
    Descriptor desc;
    desc.numVertices = (int)d->n_points;
    desc.numFaces = (int)d->n_faces;
    desc.numVertsPerFace = d->n_verts;
    desc.vertIndicesPerFace = d->indices;
    desc.numCreases = (int)d->n_creases;
    desc.creaseVertexIndexPairs = d->crease_edges;
    desc.creaseWeights = d->crease_sharpness;
    desc.numCorners = (int)d->n_corners;
    desc.cornerVertexIndices = d->corner_points;
    desc.cornerWeights = d->corner_sharpness;
    desc.numHoles = (int)d->n_holes;
    desc.holeIndices = d->hole_faces;
    return desc;
}

enum { CLASS_CONSTANT = 0, CLASS_UNIFORM = 1, CLASS_VARYING = 2, CLASS_VERTEX = 3, CLASS_FACEVARYING = 4 };

/* Where one primitive variable sits in a channel's points. */
struct Slot {
    unsigned bit;
    int offset, size;
};

/* Point data of one kind and the patch points of every face's surface. */
struct Channel {
    int size = 0;                    /* floats per point */
    std::vector<Slot> slots;
    std::vector<float> points;       /* the mesh's points (or face-varying values) */
    std::vector<float> patch_points; /* every face's, back to back */
};

struct Face {
    Surface vtx, var, fvar;
    size_t vtx_at = 0, var_at = 0, fvar_at = 0; /* offsets into the channels' patch points */
    float lo[3], hi[3];              /* control point bounds */
};

struct Patch {
    uint32_t face;
    int tri;                         /* a Loop triangle */
    int sub;                         /* its corner of a face split into sub-faces, or -1 */
    float o[2], J[2][2];             /* face (u, v) = o + J (u, v) of the patch */
};

thread_local std::string osd_error;

void on_osd_error(Far::ErrorType, const char *message)
{
    if (osd_error.empty())
        osd_error = message;
}

} // namespace

struct SubdivMesh {
    std::unique_ptr<Far::TopologyRefiner> refiner;
    std::vector<Face> faces;
    std::vector<Patch> patches;
    Channel vtx, var, fvar;
    std::vector<Slot> uniform_slots, constant_slots;
    int uniform_size = 0;
    std::vector<float> uniform, constant; /* per face; once */
};

static void set_error(char *err, size_t n, const char *msg)
{
    if (err && n)
        std::snprintf(err, n, "%s", msg);
}

/* The channel of a class interpolated by a surface, or NULL. */
static Channel *channel_of(SubdivMesh *m, int cls)
{
    switch (cls) {
    case CLASS_VERTEX: return &m->vtx;
    case CLASS_VARYING: return &m->var;
    case CLASS_FACEVARYING: return &m->fvar;
    default: return nullptr;
    }
}

/* Interleaves the point data of a channel: P first for the vertex one. */
static void fill_points(const SubdivDesc *d, Channel *c, int cls, size_t count, const float *P)
{
    c->points.assign(count * (size_t)c->size, 0.0f);
    for (size_t i = 0; i < count; i++) {
        float *out = &c->points[i * (size_t)c->size];
        if (P)
            std::memcpy(out, P + 3 * i, 3 * sizeof(float));
        for (int k = 0; k < d->n_pv; k++)
            if (d->pv[k].cls == cls)
                for (const Slot &s : c->slots)
                    if (s.bit == d->pv[k].bit)
                        std::memcpy(out + s.offset, d->pv[k].data + i * (size_t)s.size,
                                    (size_t)s.size * sizeof(float));
    }
}

/* The face-varying values of d, shared where a point's corners agree: the
 * value indices per face corner, and the distinct values into c->points. */
static std::vector<int> share_facevarying(const SubdivDesc *d, Channel *c, size_t n_corners)
{
    std::vector<float> per_corner((size_t)c->size * n_corners);
    for (int k = 0; k < d->n_pv; k++)
        if (d->pv[k].cls == CLASS_FACEVARYING)
            for (const Slot &s : c->slots)
                if (s.bit == d->pv[k].bit)
                    for (size_t i = 0; i < n_corners; i++)
                        std::memcpy(&per_corner[i * (size_t)c->size + (size_t)s.offset],
                                    d->pv[k].data + i * (size_t)s.size,
                                    (size_t)s.size * sizeof(float));
    std::map<std::pair<int, std::string>, int> seen;
    std::vector<int> index(n_corners);
    c->points.clear();
    for (size_t i = 0; i < n_corners; i++) {
        const float *v = &per_corner[i * (size_t)c->size];
        std::string key(reinterpret_cast<const char *>(v), (size_t)c->size * sizeof(float));
        auto got = seen.emplace(std::make_pair(d->indices[i], key), (int)seen.size());
        if (got.second)
            c->points.insert(c->points.end(), v, v + c->size);
        index[i] = got.first->second;
    }
    return index;
}

static Sdc::Options sdc_options(const SubdivDesc *d)
{
    Sdc::Options o;
    o.SetVtxBoundaryInterpolation(d->interpolate_boundary == 1   ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                  : d->interpolate_boundary == 2 ? Sdc::Options::VTX_BOUNDARY_EDGE_ONLY
                                                                 : Sdc::Options::VTX_BOUNDARY_NONE);
    static const Sdc::Options::FVarLinearInterpolation fvar[4] = {
        Sdc::Options::FVAR_LINEAR_NONE, Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1,
        Sdc::Options::FVAR_LINEAR_BOUNDARIES, Sdc::Options::FVAR_LINEAR_CORNERS_ONLY};
    int f = d->facevarying_boundary;
    o.SetFVarLinearInterpolation(fvar[f >= 0 && f <= 3 ? f : 1]);
    return o;
}

/* Prepares the patch points of one surface of a channel. */
static size_t prepare(Channel *c, const Surface &s)
{
    size_t at = c->patch_points.size();
    c->patch_points.resize(at + (size_t)s.GetNumPatchPoints() * (size_t)c->size);
    s.PreparePatchPoints(c->points.data(), Surface::PointDescriptor(c->size),
                         c->patch_points.data() + at, Surface::PointDescriptor(c->size));
    return at;
}

/* The patches of face f: one, or one per corner of a face split into
 * quad sub-faces. */
static void add_patches(SubdivMesh *m, uint32_t f, const Surface &s)
{
    Bfr::Parameterization param = s.GetParameterization();
    Patch p = {f, param.GetType() == Bfr::Parameterization::TRI, -1, {0, 0}, {{1, 0}, {0, 1}}};
    if (!param.HasSubFaces()) {
        m->patches.push_back(p);
        return;
    }
    for (int sub = 0; sub < param.GetFaceSize(); sub++) {
        float c00[2] = {0, 0}, c10[2] = {1, 0}, c01[2] = {0, 1}, o[2], a[2], b[2];
        param.ConvertNormalizedSubFaceToCoord(sub, c00, o);
        param.ConvertNormalizedSubFaceToCoord(sub, c10, a);
        param.ConvertNormalizedSubFaceToCoord(sub, c01, b);
        p.sub = sub;
        p.o[0] = o[0], p.o[1] = o[1];
        p.J[0][0] = a[0] - o[0], p.J[1][0] = a[1] - o[1];
        p.J[0][1] = b[0] - o[0], p.J[1][1] = b[1] - o[1];
        m->patches.push_back(p);
    }
}

static int build(SubdivMesh *m, const SubdivDesc *d, char *err, size_t err_size)
{
    size_t n_corners = 0;
    for (size_t f = 0; f < d->n_faces; f++)
        n_corners += (size_t)d->n_verts[f];
    /* Channels: P and vertex variables, varying, face-varying. */
    m->vtx.size = 3;
    for (int k = 0; k < d->n_pv; k++) {
        const SubdivPrimvar &v = d->pv[k];
        Channel *c = channel_of(m, v.cls);
        if (c) {
            c->slots.push_back({v.bit, c->size, v.size});
            c->size += v.size;
        } else if (v.cls == CLASS_UNIFORM) {
            m->uniform_slots.push_back({v.bit, m->uniform_size, v.size});
            m->uniform_size += v.size;
        } else {
            m->constant_slots.push_back({v.bit, (int)m->constant.size(), v.size});
            m->constant.insert(m->constant.end(), v.data, v.data + v.size);
        }
    }
    fill_points(d, &m->vtx, CLASS_VERTEX, d->n_points, d->P);
    if (m->var.size)
        fill_points(d, &m->var, CLASS_VARYING, d->n_points, nullptr);
    std::vector<int> fvar_index;
    if (m->fvar.size)
        fvar_index = share_facevarying(d, &m->fvar, n_corners);
    if (m->uniform_size) {
        m->uniform.assign(d->n_faces * (size_t)m->uniform_size, 0.0f);
        for (int k = 0; k < d->n_pv; k++)
            if (d->pv[k].cls == CLASS_UNIFORM)
                for (const Slot &s : m->uniform_slots)
                    if (s.bit == d->pv[k].bit)
                        for (size_t f = 0; f < d->n_faces; f++)
                            std::memcpy(&m->uniform[f * (size_t)m->uniform_size + (size_t)s.offset],
                                        d->pv[k].data + f * (size_t)s.size,
                                        (size_t)s.size * sizeof(float));
    }

    Descriptor desc = topology(d);
    Descriptor::FVarChannel channel;
    if (m->fvar.size) {
        channel.numValues = (int)(m->fvar.points.size() / (size_t)m->fvar.size);
        channel.valueIndices = fvar_index.data();
        desc.numFVarChannels = 1;
        desc.fvarChannels = &channel;
    }
    static const Sdc::SchemeType schemes[3] = {Sdc::SCHEME_CATMARK, Sdc::SCHEME_LOOP,
                                               Sdc::SCHEME_BILINEAR};
    osd_error.clear();
    Far::SetErrorCallback(on_osd_error);
    m->refiner.reset(Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(schemes[d->scheme], sdc_options(d))));
    Far::SetErrorCallback(nullptr);
    if (!m->refiner) {
        std::string msg = "OpenSubdiv refused the topology";
        if (!osd_error.empty())
            msg += ": " + osd_error;
        set_error(err, err_size, msg.c_str());
        return -1;
    }

    Bfr::RefinerSurfaceFactory<>::Options options;
    /* Near extraordinary vertices Bfr approximates the limit surface with
     * patches of a refinement level; its default for smooth ones (2) is
     * 5e-4 off a cube of side 2 (OpenSubdiv's own limit points,
     * tests/scene/test_subdiv.c); 6 is within float rounding. */
    options.SetApproxLevelSmooth(SUBDIV_APPROX_LEVEL);
    if (m->fvar.size)
        options.SetDefaultFVarID(0);
    Bfr::RefinerSurfaceFactory<> factory(*m->refiner, options);
    m->faces.resize(d->n_faces);
    for (size_t f = 0; f < d->n_faces; f++) {
        Face &face = m->faces[f];
        if (!factory.InitVertexSurface((int)f, &face.vtx) || !face.vtx.IsValid())
            continue; /* a hole, or a boundary face with no limit surface */
        if (m->var.size && !factory.InitVaryingSurface((int)f, &face.var))
            continue;
        if (m->fvar.size && !factory.InitFaceVaryingSurface((int)f, &face.fvar))
            continue;
        face.vtx_at = prepare(&m->vtx, face.vtx);
        if (m->var.size)
            face.var_at = prepare(&m->var, face.var);
        if (m->fvar.size)
            face.fvar_at = prepare(&m->fvar, face.fvar);
        face.vtx.BoundControlPoints(&m->vtx.patch_points[face.vtx_at],
                                    Surface::PointDescriptor(3, m->vtx.size), face.lo, face.hi);
        add_patches(m, (uint32_t)f, face.vtx);
    }
    return 0;
}

extern "C" SubdivMesh *geom_subdiv_new(const SubdivDesc *d, char *err, size_t err_size)
{
    if (d->scheme == SUBDIV_LOOP)
        for (size_t f = 0; f < d->n_faces; f++)
            if (d->n_verts[f] != 3) {
                char msg[128];
                std::snprintf(msg, sizeof msg, "face %zu has %d vertices; Loop takes triangles",
                              f, d->n_verts[f]);
                set_error(err, err_size, msg);
                return nullptr;
            }
    SubdivMesh *m = new (std::nothrow) SubdivMesh;
    if (!m) {
        set_error(err, err_size, "out of memory");
        return nullptr;
    }
    try {
        if (build(m, d, err, err_size) != 0) {
            delete m;
            return nullptr;
        }
    } catch (const std::bad_alloc &) {
        delete m;
        set_error(err, err_size, "out of memory");
        return nullptr;
    }
    return m;
}

extern "C" void geom_subdiv_free(SubdivMesh *m)
{
    delete m;
}

extern "C" size_t geom_subdiv_n_patches(const SubdivMesh *m)
{
    return m->patches.size();
}

extern "C" size_t geom_subdiv_patch_face(const SubdivMesh *m, size_t patch)
{
    return m->patches[patch].face;
}

extern "C" int geom_subdiv_patch_triangular(const SubdivMesh *m, size_t patch)
{
    return m->patches[patch].tri;
}

/* The curve of a mesh edge walked from point a toward point b for the
 * fraction h of its length (1, or 1/2 to its midpoint): keyed by its
 * points in increasing order, t running from the lower one. */
static void edge_side(int a, int b, float h, uint64_t key[2], float t[2])
{
    key[0] = 1, key[1] = (uint64_t)(uint32_t)std::min(a, b) << 32 | (uint32_t)std::max(a, b);
    t[0] = a < b ? 0.0f : 1.0f;
    t[1] = a < b ? h : 1.0f - h;
}

extern "C" int geom_subdiv_patch_side(const SubdivMesh *m, size_t patch, int side,
                                      uint64_t key[2], float t[2])
{
    const Patch &p = m->patches[patch];
    Far::ConstIndexArray v = m->refiner->GetLevel(0).GetFaceVertices((int)p.face);
    int n = v.size();
    if (p.tri) { /* corners v0 (0,0), v1 (1,0), v2 (0,1); side k from v_k to v_k+1 */
        if (side > 2)
            return 0;
        edge_side(v[side], v[(side + 1) % 3], 1.0f, key, t);
        return 1;
    }
    if (p.sub < 0) { /* corners v0 (0,0), v1 (1,0), v2 (1,1), v3 (0,1) */
        static const int from[4] = {0, 1, 3, 0}, to[4] = {1, 2, 2, 3};
        edge_side(v[from[side]], v[to[side]], 1.0f, key, t);
        return 1;
    }
    /* Ptex sub-face k: the corner k at (0,0), u toward the midpoint of
     * edge k (to k + 1), v toward that of edge k - 1; its other two sides
     * run from those midpoints to the face's centre, inside the face. */
    int k = p.sub, next = (k + 1) % n, prev = (k + n - 1) % n;
    if (side == 0 || side == 3) {
        edge_side(v[k], v[side == 0 ? next : prev], 0.5f, key, t);
        return 1;
    }
    key[0] = 2, key[1] = (uint64_t)p.face << 32 | (uint32_t)(side == 1 ? k : prev);
    t[0] = 0.0f, t[1] = 1.0f;
    return 1;
}

namespace {

/* A point for Far::PrimvarRefiner. */
struct Point3 {
    float p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0.0f; }
    void AddWithWeight(const Point3 &o, float w)
    {
        for (int k = 0; k < 3; k++)
            p[k] += w * o.p[k];
    }
};

} // namespace

extern "C" float *geom_subdiv_refine_uniform(const SubdivDesc *d, int level, int limit, size_t *n)
{
    *n = 0;
    Descriptor desc = topology(d);
    static const Sdc::SchemeType schemes[3] = {Sdc::SCHEME_CATMARK, Sdc::SCHEME_LOOP,
                                               Sdc::SCHEME_BILINEAR};
    std::unique_ptr<Far::TopologyRefiner> r(Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(schemes[d->scheme], sdc_options(d))));
    if (!r)
        return nullptr;
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = true; /* PrimvarRefiner::Limit needs it */
    r->RefineUniform(uniform);
    std::vector<Point3> pts((size_t)r->GetNumVerticesTotal());
    std::memcpy(pts.data(), d->P, d->n_points * sizeof(Point3));
    Far::PrimvarRefiner pr(*r);
    Point3 *src = pts.data();
    for (int l = 1; l <= level; l++) {
        Point3 *dst = src + r->GetLevel(l - 1).GetNumVertices();
        pr.Interpolate(l, src, dst);
        src = dst;
    }
    size_t count = (size_t)r->GetLevel(level).GetNumVertices();
    std::vector<Point3> out(src, src + count);
    Point3 *dst = out.data();
    if (limit)
        pr.Limit(src, dst);
    float *P = (float *)std::malloc(count * sizeof(Point3));
    if (P) {
        std::memcpy(P, out.data(), count * sizeof(Point3));
        *n = count;
    }
    return P;
}

extern "C" void geom_subdiv_patch_bounds(const SubdivMesh *m, size_t patch, float lo[3],
                                         float hi[3])
{
    const Face &f = m->faces[m->patches[patch].face];
    std::memcpy(lo, f.lo, sizeof f.lo);
    std::memcpy(hi, f.hi, sizeof f.hi);
}

/* Evaluates one channel's surface at the patch's (u, v): size floats of
 * value and of derivatives with respect to the patch's u and v. */
static void eval_channel(const Channel &c, const Surface &s, size_t at, const Patch &p, float u,
                         float v, float *val, float *du, float *dv)
{
    float uv[2] = {p.o[0] + p.J[0][0] * u + p.J[0][1] * v, p.o[1] + p.J[1][0] * u + p.J[1][1] * v};
    float fu[32], fv[32];
    s.Evaluate(uv, &c.patch_points[at], Surface::PointDescriptor(c.size), val, fu, fv);
    for (int k = 0; k < c.size; k++) {
        du[k] = fu[k] * p.J[0][0] + fv[k] * p.J[1][0];
        dv[k] = fu[k] * p.J[0][1] + fv[k] * p.J[1][1];
    }
}

extern "C" void geom_subdiv_eval(const SubdivMesh *m, size_t patch, float u, float v, float P[3],
                                 float dPdu[3], float dPdv[3])
{
    const Patch &p = m->patches[patch];
    const Face &f = m->faces[p.face];
    float val[32], du[32], dv[32];
    eval_channel(m->vtx, f.vtx, f.vtx_at, p, u, v, val, du, dv);
    std::memcpy(P, val, 3 * sizeof(float));
    std::memcpy(dPdu, du, 3 * sizeof(float));
    std::memcpy(dPdv, dv, 3 * sizeof(float));
}

/* Writes the variables of slots from a channel's value and derivatives. */
static unsigned put(const std::vector<Slot> &slots, const float *val, const float *du,
                    const float *dv, float N[3], float st[2], float dst[4], float Cs[3],
                    float Os[3])
{
    unsigned bits = 0;
    for (const Slot &s : slots) {
        const float *x = val + s.offset;
        if (s.bit == 1u) /* GEOM_PV_N */
            std::memcpy(N, x, 3 * sizeof(float));
        else if (s.bit == 2u) { /* GEOM_PV_ST */
            std::memcpy(st, x, 2 * sizeof(float));
            if (du) {
                dst[0] = du[s.offset], dst[1] = dv[s.offset];
                dst[2] = du[s.offset + 1], dst[3] = dv[s.offset + 1];
            } else
                dst[0] = dst[1] = dst[2] = dst[3] = 0.0f;
        } else
            std::memcpy(s.bit == 4u ? Cs : Os, x, 3 * sizeof(float)); /* GEOM_PV_CS, _OS */
        bits |= s.bit;
    }
    return bits;
}

extern "C" unsigned geom_subdiv_primvars(const SubdivMesh *m, size_t patch, float u, float v,
                                         float N[3], float st[2], float dst[4], float Cs[3],
                                         float Os[3])
{
    const Patch &p = m->patches[patch];
    const Face &f = m->faces[p.face];
    float val[32], du[32], dv[32];
    unsigned bits = 0;
    if (m->vtx.slots.size()) {
        eval_channel(m->vtx, f.vtx, f.vtx_at, p, u, v, val, du, dv);
        bits |= put(m->vtx.slots, val, du, dv, N, st, dst, Cs, Os);
    }
    if (m->var.size) {
        eval_channel(m->var, f.var, f.var_at, p, u, v, val, du, dv);
        bits |= put(m->var.slots, val, du, dv, N, st, dst, Cs, Os);
    }
    if (m->fvar.size) {
        eval_channel(m->fvar, f.fvar, f.fvar_at, p, u, v, val, du, dv);
        bits |= put(m->fvar.slots, val, du, dv, N, st, dst, Cs, Os);
    }
    if (m->uniform_size)
        bits |= put(m->uniform_slots, &m->uniform[p.face * (size_t)m->uniform_size], nullptr,
                    nullptr, N, st, dst, Cs, Os);
    if (!m->constant.empty())
        bits |= put(m->constant_slots, m->constant.data(), nullptr, nullptr, N, st, dst, Cs, Os);
    return bits;
}
