/*
 * shade/oiio/texture.cpp — image textures through OpenImageIO's
 * TextureSystem (texture.h): the one C++ file of shade, a C interface over
 * the library, built as the module librayes_oiio.so that texture.c loads
 * on first use (texture_module.h); its texture_* functions are hidden and
 * reached through the module's table.
 *
 * Each render owns a private OIIO TextureSystem with the render's memory
 * budget (its "max_memory_MB"). OIIO reads every format it knows (EXR,
 * TIFF and maketx's .tx, PNG, JPEG, TGA, HDR, ...), makes MIP levels of
 * untiled files on first use (automip, in tiles of 64), and filters by the
 * footprint (its anisotropic MIP filter, bilinear within a level). A
 * lookup's result is a pure function of the file and its arguments, never
 * of what the cache holds, of the budget or of threads.
 *
 * Names are resolved here (as given, then in each directory of the search
 * path) so that a missing file gets one warning naming it. Files whose
 * texels are integers and whose colour space is not said to be linear
 * (8- and 16-bit PNG, JPEG, TGA) are sRGB. OIIO 2.4's TextureSystem filters
 * what a file holds, and filtering sRGB values then decoding them darkens
 * every blurred edge (a black and white checker filters to 0.21, not
 * 0.5), so an untiled sRGB file is read through LinearInput, an
 * ImageInput that hands the cache the file decoded to linear float, and
 * its MIP levels are made from those. A tiled sRGB file (a .tx made from
 * 8-bit texels without maketx's --colorconvert) is decoded after
 * filtering, the best OIIO 2.4 allows. Grey files are grey in all three
 * channels; files without alpha have alpha 1.
 *
 * Thread-safety: texture_lookup may be called from any number of threads
 * (OIIO's TextureSystem is thread-safe); the name table has a mutex.
 */
#include "shade/texture.h"
#include "shade/texture_module.h"

#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <unistd.h>
#include <unordered_map>
#include <vector>

extern "C" {
#include "util/log.h" /* log_warning: defined at the end, forwarded to the host */
}

namespace {

/* What a name resolved to. */
struct Entry {
    OIIO::ustring path;     /* empty: missing or unreadable */
    int channels = 0;       /* in the file */
    float decode = 0.0f;    /* after filtering: 0 none, -1 sRGB, else this gamma */
};

float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

/* A texel value made linear by decode (Entry.decode). */
float decoded(float c, float decode)
{
    if (decode == 0.0f)
        return c;
    return decode < 0.0f ? srgb_to_linear(c) : std::pow(std::fmax(c, 0.0f), decode);
}

/* sRGB for integer formats unless the file's colour space says linear. */
bool is_srgb(const OIIO::ImageSpec &spec)
{
    std::string cs = spec.get_string_attribute("oiio:ColorSpace");
    for (char &c : cs)
        c = (char)std::tolower((unsigned char)c);
    if (cs.find("linear") != std::string::npos || cs == "raw" || cs == "scene_linear")
        return false;
    if (cs.find("srgb") != std::string::npos)
        return true;
    return !spec.format.is_floating_point();
}

/* The name under which the cache knows a file decoded to linear: the
 * path, then "#rayes-linear" (from sRGB) or "#rayes-gamma-G". */
const char *const decode_mark = "#rayes-";

std::string decoded_name(const std::string &path, float decode)
{
    if (decode < 0.0f)
        return path + decode_mark + "linear";
    char g[32];
    std::snprintf(g, sizeof g, "gamma-%.9g", (double)decode);
    return path + decode_mark + g;
}

/* An ImageInput over a file decoded from sRGB to linear float, whole, for
 * the cache (which reads it by scanlines and makes its MIP levels). */
class LinearInput final : public OIIO::ImageInput {
  public:
    const char *format_name() const override { return "rayes-linear"; }
    bool open(const std::string &name, OIIO::ImageSpec &newspec) override
    {
        size_t mark = name.rfind(decode_mark);
        if (mark == std::string::npos)
            return false;
        std::string path = name.substr(0, mark), how = name.substr(mark + std::strlen(decode_mark));
        float decode = how == "linear" ? -1.0f : std::strtof(how.c_str() + 6, nullptr);
        auto in = OIIO::ImageInput::open(path);
        if (!in)
            return false;
        const OIIO::ImageSpec &spec = in->spec();
        nc_ = spec.nchannels;
        width_ = spec.width;
        pixels_.resize((size_t)spec.width * (size_t)spec.height * (size_t)nc_);
        if (!in->read_image(0, 0, 0, nc_, OIIO::TypeDesc::FLOAT, pixels_.data()))
            return false;
        int colour = nc_ >= 3 ? 3 : 1; /* the alpha channel stays as it is */
        for (size_t i = 0; i < pixels_.size(); i += (size_t)nc_)
            for (int c = 0; c < colour; c++)
                pixels_[i + (size_t)c] = decoded(pixels_[i + (size_t)c], decode);
        m_spec = OIIO::ImageSpec(spec.width, spec.height, nc_, OIIO::TypeDesc::FLOAT);
        m_spec.channelnames = spec.channelnames;
        m_spec.alpha_channel = spec.alpha_channel;
        newspec = m_spec;
        return true;
    }
    bool close() override
    {
        pixels_.clear();
        return true;
    }
    bool read_native_scanline(int subimage, int miplevel, int y, int z, void *data) override
    {
        (void)z;
        if (subimage != 0 || miplevel != 0 || y < 0 || y >= m_spec.height)
            return false;
        size_t row = (size_t)width_ * (size_t)nc_;
        std::memcpy(data, &pixels_[(size_t)y * row], row * sizeof(float));
        return true;
    }

  private:
    std::vector<float> pixels_;
    int nc_ = 0, width_ = 0;
};

OIIO::ImageInput *create_linear_input()
{
    return new LinearInput;
}

} // namespace

struct TextureSystem {
    OIIO::TextureSystem *oiio;
    std::vector<std::string> dirs;
    float width;
    uint64_t budget;
    std::mutex lock;        /* guards names and the counts below */
    std::unordered_map<std::string, Entry> names;
    uint64_t missing = 0;
    std::atomic<uint64_t> lookups{0};
};

extern "C" TextureSystem *texture_system_new(const char *search_path, uint64_t budget_bytes,
                                              float width)
{
    TextureSystem *ts = new (std::nothrow) TextureSystem;
    if (!ts)
        return nullptr;
    try {
        ts->width = width;
        ts->budget = budget_bytes;
        if (search_path) {
            std::string p = search_path;
            for (size_t at = 0; at <= p.size();) {
                size_t end = p.find(':', at);
                if (end == std::string::npos)
                    end = p.size();
                if (end > at)
                    ts->dirs.push_back(p.substr(at, end - at));
                at = end + 1;
            }
        }
        ts->oiio = OIIO::TextureSystem::create(false);
        if (!ts->oiio) {
            delete ts;
            return nullptr;
        }
        /* OIIO's smallest cache is a few tiles; the budget is in MB. */
        ts->oiio->attribute("max_memory_MB", (float)((double)budget_bytes / 1e6));
        ts->oiio->attribute("automip", 1);
        ts->oiio->attribute("autotile", 64);
        ts->oiio->attribute("gray_to_rgb", 1);
        ts->oiio->attribute("max_open_files", 100);
    } catch (...) {
        delete ts;
        return nullptr;
    }
    return ts;
}

extern "C" void texture_system_free(TextureSystem *ts)
{
    if (!ts)
        return;
    if (ts->oiio) {
        (void)ts->oiio->geterror();
        OIIO::TextureSystem::destroy(ts->oiio, true);
    }
    delete ts;
}

/* The file a name stands for: as given, then in each directory of the
 * search path; "" if none is readable. */
static std::string resolve(const TextureSystem *ts, const char *name)
{
    if (access(name, R_OK) == 0)
        return name;
    if (name[0] == '/')
        return "";
    for (const std::string &d : ts->dirs) {
        std::string p = d + "/" + name;
        if (access(p.c_str(), R_OK) == 0)
            return p;
    }
    return "";
}

/* How integer texels of a file decode (Entry.decode) under an encoding:
 * "" the file's own (sRGB unless it says linear), "sRGB", "linear",
 * "gamma G". Float texels are linear whatever the encoding says. */
static float decode_of(const OIIO::ImageSpec &spec, const char *encoding)
{
    float g = 0.0f;
    if (!encoding || !encoding[0])
        return is_srgb(spec) ? -1.0f : 0.0f;
    if (spec.format.is_floating_point() || std::strcmp(encoding, "linear") == 0)
        return 0.0f;
    if (std::sscanf(encoding, "gamma %f", &g) == 1 && g > 0.0f)
        return g;
    return -1.0f;
}

/* The entry of a name under an encoding, resolved and opened on first use
 * (one warning when it cannot be read). */
static Entry entry_of(TextureSystem *ts, const char *name, const char *encoding)
{
    std::string key = std::string(name) + '\n' + (encoding ? encoding : "");
    {
        std::lock_guard<std::mutex> g(ts->lock);
        auto it = ts->names.find(key);
        if (it != ts->names.end())
            return it->second;
    }
    Entry e;
    std::string why;
    std::string path = resolve(ts, name);
    if (path.empty())
        why = "not found as given nor on the texture search path";
    else {
        /* The file's own spec: the cache's says "tiled" of autotiled files. */
        OIIO::ImageSpec spec;
        auto in = OIIO::ImageInput::open(path);
        if (in)
            spec = in->spec();
        else {
            why = OIIO::geterror();
            if (why.empty())
                why = path + ": not an image OpenImageIO reads";
        }
        if (in) {
            e.path = OIIO::ustring(path);
            e.channels = spec.nchannels;
            e.decode = decode_of(spec, encoding);
            if (e.decode != 0.0f && spec.tile_width == 0) { /* decoded before filtering */
                OIIO::ustring linear(decoded_name(path, e.decode));
                if (ts->oiio->imagecache()->add_file(linear, create_linear_input)) {
                    e.path = linear;
                    e.decode = 0.0f;
                } else
                    (void)ts->oiio->geterror();
            }
        }
    }
    std::lock_guard<std::mutex> g(ts->lock);
    auto got = ts->names.emplace(key, e);
    if (got.second && e.path.empty()) {
        ts->missing++;
        log_warning("texture \"%s\": %s; shading continues without it", name, why.c_str());
    }
    return got.first->second;
}

extern "C" int texture_lookup(TextureSystem *ts, const char *name, size_t n, const float *s,
                              const float *t, const float *ds, const float *dt, float (*rgb)[3],
                              float *alpha)
{
    return texture_lookup_encoded(ts, name, NULL, TEXTURE_WRAP_REPEAT, n, s, t, ds, dt, rgb, alpha);
}

extern "C" int texture_lookup_encoded(TextureSystem *ts, const char *name, const char *encoding,
                                      TextureWrap wrap, size_t n, const float *s, const float *t,
                                      const float *ds, const float *dt, float (*rgb)[3],
                                      float *alpha)
{
    ts->lookups.fetch_add(n, std::memory_order_relaxed);
    Entry e = name && name[0] ? entry_of(ts, name, encoding) : Entry();
    if (e.path.empty()) {
        std::memset(rgb, 0, n * sizeof *rgb);
        for (size_t i = 0; alpha && i < n; i++)
            alpha[i] = 1.0f;
        return -1;
    }
    OIIO::TextureOpt opt;
    opt.swrap = opt.twrap = wrap == TEXTURE_WRAP_BLACK   ? OIIO::TextureOpt::WrapBlack
                            : wrap == TEXTURE_WRAP_CLAMP ? OIIO::TextureOpt::WrapClamp
                                                         : OIIO::TextureOpt::WrapPeriodic;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    opt.mipmode = OIIO::TextureOpt::MipModeAniso;
    int has_alpha = e.channels == 2 || e.channels >= 4;
    for (size_t i = 0; i < n; i++) {
        float dsx = ds ? std::fabs(ds[i]) * ts->width : 0.0f;
        float dty = dt ? std::fabs(dt[i]) * ts->width : 0.0f;
        float v[4] = {0, 0, 0, 1};
        int nc = e.channels == 2 ? 2 : has_alpha ? 4 : 3;
        float got[4] = {0, 0, 0, 1};
        if (!ts->oiio->texture(e.path, opt, s[i], t[i], dsx, 0.0f, 0.0f, dty, nc, got)) {
            (void)ts->oiio->geterror();
            got[0] = got[1] = got[2] = 0.0f, got[3] = 1.0f;
        }
        if (e.channels == 2) /* grey and alpha */
            v[0] = v[1] = v[2] = got[0], v[3] = got[1];
        else
            std::memcpy(v, got, sizeof v);
        if (!has_alpha)
            v[3] = 1.0f;
        for (int c = 0; c < 3; c++)
            rgb[i][c] = decoded(v[c], e.decode);
        if (alpha)
            alpha[i] = v[3];
    }
    return 0;
}

extern "C" int texture_channels(TextureSystem *ts, const char *name, const char *encoding)
{
    Entry e = name && name[0] ? entry_of(ts, name, encoding) : Entry();
    return e.path.empty() ? 0 : e.channels;
}

extern "C" void texture_get_stats(TextureSystem *ts, TextureStats *st)
{
    std::memset(st, 0, sizeof *st);
    st->lookups = ts->lookups.load();
    {
        std::lock_guard<std::mutex> g(ts->lock);
        st->textures = ts->names.size();
        st->missing = ts->missing;
    }
    long long v = 0;
    int iv = 0;
    if (ts->oiio->getattribute("stat:tiles_created", OIIO::TypeDesc::INT, &iv))
        st->loads = (uint64_t)iv;
    if (ts->oiio->getattribute("stat:open_files_created", OIIO::TypeDesc::INT, &iv))
        st->file_reads = (uint64_t)iv;
    int current = 0;
    if (ts->oiio->getattribute("stat:tiles_current", OIIO::TypeDesc::INT, &current))
        st->evictions = st->loads > (uint64_t)current ? st->loads - (uint64_t)current : 0;
    if (ts->oiio->getattribute("stat:cache_memory_used", OIIO::TypeDesc::INT64, &v))
        st->bytes = (uint64_t)v;
    int peak = 0;
    if (ts->oiio->getattribute("stat:tiles_peak", OIIO::TypeDesc::INT, &peak) && st->loads)
        st->peak_bytes = st->bytes && current ? st->bytes / (uint64_t)current * (uint64_t)peak
                                              : 0;
    st->budget_bytes = ts->budget;
}

extern "C" int texture_read_image(const char *path, int *w, int *h, float **rgba, char *err,
                                  size_t err_size)
{
    *rgba = nullptr;
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        std::string why = OIIO::geterror();
        std::snprintf(err, err_size, "%s", why.empty() ? "cannot be read" : why.c_str());
        return -1;
    }
    const OIIO::ImageSpec &spec = in->spec();
    int nc = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || nc <= 0 ||
        (uint64_t)spec.width * (uint64_t)spec.height > (1ull << 28)) {
        std::snprintf(err, err_size, "%s: an image of %d x %d is out of range", path, spec.width,
                      spec.height);
        return -1;
    }
    size_t n = (size_t)spec.width * (size_t)spec.height;
    std::vector<float> px(n * (size_t)nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, px.data())) {
        std::snprintf(err, err_size, "%s: %s", path, in->geterror().c_str());
        return -1;
    }
    bool srgb = is_srgb(spec);
    float *out = (float *)std::malloc(n * 4 * sizeof *out);
    if (!out) {
        std::snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        const float *p = &px[i * (size_t)nc];
        float v[4] = {p[0], nc >= 3 ? p[1] : p[0], nc >= 3 ? p[2] : p[0],
                      nc == 2 ? p[1] : nc >= 4 ? p[3] : 1.0f};
        for (int c = 0; c < 3; c++)
            out[4 * i + (size_t)c] = srgb ? srgb_to_linear(v[c]) : v[c];
        out[4 * i + 3] = v[3];
    }
    *w = spec.width;
    *h = spec.height;
    *rgba = out;
    return 0;
}

/* ------------------------------------------------- the module's table */

static void (*host_warning)(const char *message);

/* util/log.h's, for this file: formatted here, said by the host. */
extern "C" void log_warning(const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (host_warning)
        host_warning(buf);
    else
        std::fprintf(stderr, "rayes: warning: %s\n", buf);
}

static void set_warning(void (*warn)(const char *message))
{
    host_warning = warn;
}

static void *system_new(const char *search_path, uint64_t budget_bytes, float width)
{
    return texture_system_new(search_path, budget_bytes, width);
}

static void system_free(void *ts)
{
    texture_system_free(static_cast<TextureSystem *>(ts));
}

static int lookup(void *ts, const char *name, const char *encoding, TextureWrap wrap, size_t n,
                  const float *s, const float *t, const float *ds, const float *dt, float (*rgb)[3],
                  float *alpha)
{
    return texture_lookup_encoded(static_cast<TextureSystem *>(ts), name, encoding, wrap, n, s, t,
                                  ds, dt, rgb, alpha);
}

static void get_stats(void *ts, TextureStats *stats)
{
    texture_get_stats(static_cast<TextureSystem *>(ts), stats);
}

static int channels(void *ts, const char *name, const char *encoding)
{
    return texture_channels(static_cast<TextureSystem *>(ts), name, encoding);
}

extern "C" __attribute__((visibility("default"))) const TextureModule *rayes_texture_module(void)
{
    static const TextureModule table = {
        TEXTURE_MODULE_VERSION, set_warning, system_new, system_free, lookup, get_stats, channels,
        texture_read_image};
    return &table;
}
