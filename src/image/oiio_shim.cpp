// A small C interface over OpenImageIO for src/image/mod.rs.
//
// OIIO's API is C++ (unique_ptr, std::string, exceptions), which Rust cannot call. Every
// function here catches all exceptions, because one unwinding into Rust is undefined
// behaviour, and reports failure as a nonzero return plus a message in the caller's buffer.

#include <OpenImageIO/imageio.h>

#include <cstddef>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

namespace {

// Must match `PixelType::code` in mod.rs.
enum ShimPixelType { SHIM_F32 = 0, SHIM_F16 = 1, SHIM_U8 = 2, SHIM_U16 = 3 };

void set_error(char *buf, size_t len, const std::string &msg) {
    if (buf == nullptr || len == 0)
        return;
    size_t n = msg.size() < len - 1 ? msg.size() : len - 1;
    std::memcpy(buf, msg.data(), n);
    buf[n] = '\0';
}

// OIIO keeps errors both per object and globally (for failed factory calls); report
// whichever has text, so the user sees OIIO's own reason.
std::string oiio_reason(const std::string &object_error) {
    // Always fetched: this also clears it, so a stale message cannot leak into a later call.
    std::string global = OIIO::geterror();
    if (!object_error.empty())
        return object_error;
    if (!global.empty())
        return global;
    return "no reason given by OpenImageIO";
}

bool pixel_type_desc(int code, OIIO::TypeDesc *out) {
    switch (code) {
    case SHIM_F32: *out = OIIO::TypeDesc::FLOAT; return true;
    case SHIM_F16: *out = OIIO::TypeDesc::HALF; return true;
    case SHIM_U8: *out = OIIO::TypeDesc::UINT8; return true;
    case SHIM_U16: *out = OIIO::TypeDesc::UINT16; return true;
    default: return false;
    }
}

// Runs `body`, which returns 0 or 1 and reports its own failures in `err`, and turns any
// exception into a failure with its message: one unwinding into Rust is undefined
// behaviour.
template <typename Body> int guarded(char *err, size_t err_len, Body body) {
    try {
        return body();
    } catch (const std::exception &e) {
        set_error(err, err_len, std::string("OpenImageIO threw: ") + e.what());
    } catch (...) {
        set_error(err, err_len, "OpenImageIO threw an unknown exception");
    }
    return 1;
}

}  // namespace

// An open image file being read: keeps OIIO's reader between the two read calls.
struct OiioInput {
    std::unique_ptr<OIIO::ImageInput> in;
};

extern "C" {

// Writes interleaved float pixels to `write_path` in the format `path`'s extension names,
// converted by OIIO to `pixel_type` (the caller writes to a temporary name and renames).
// With 2 or 4 channels the last one is alpha. `display` says the caller has already
// sRGB-encoded the colour and un-premultiplied it: OIIO must store the values as given (by
// default it would divide by alpha itself, in the encoded space) and label them sRGB. The
// pixels are the window at (`x`, `y`) of a `full_width` x `full_height` frame (EXR's data
// and display windows), and the `attributes` pairs of names and values go into the header
// as strings.
int hairtrace_oiio_write(const char *path, const char *write_path, int width, int height,
                  int channels, const float *pixels, int pixel_type, int display, int x, int y,
                  int full_width, int full_height, const char *const *attribute_names,
                  const char *const *attribute_values, size_t attributes, char *err,
                  size_t err_len) {
    return guarded(err, err_len, [&] {
        OIIO::TypeDesc format;
        if (!pixel_type_desc(pixel_type, &format)) {
            set_error(err, err_len, "unknown pixel type code " + std::to_string(pixel_type));
            return 1;
        }
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            set_error(err, err_len, oiio_reason(""));
            return 1;
        }
        OIIO::ImageSpec spec(width, height, channels, format);
        spec.x = x;
        spec.y = y;
        spec.full_x = 0;
        spec.full_y = 0;
        spec.full_width = full_width;
        spec.full_height = full_height;
        for (size_t i = 0; i < attributes; i++)
            spec.attribute(attribute_names[i], attribute_values[i]);
        if (channels == 2) {
            // OIIO names two channels "R", "G"; they are grey and alpha.
            spec.channelnames = {"Y", "A"};
            spec.alpha_channel = 1;
        }
        spec.attribute("oiio:ColorSpace", display ? "sRGB" : "Linear");
        if (display)
            spec.attribute("oiio:UnassociatedAlpha", 1);
        if (!out->open(write_path, spec)) {
            set_error(err, err_len, oiio_reason(out->geterror()));
            return 1;
        }
        if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels)) {
            std::string reason = oiio_reason(out->geterror());
            out->close();
            set_error(err, err_len, reason);
            return 1;
        }
        if (!out->close()) {
            set_error(err, err_len, oiio_reason(out->geterror()));
            return 1;
        }
        return 0;
    });
}

// Opens `path` and reports the size of its first subimage, where that lies in its full
// frame (`origin_and_full`: x, y, full width, full height), whether its pixels are stored
// as integers (so the caller knows to decode sRGB), its alpha channel (-1 if none) and
// whether that alpha is straight rather than premultiplied. Alpha is left as the file
// stores it, so the caller can premultiply after decoding. On success `*handle` must be
// released with hairtrace_oiio_close.
int hairtrace_oiio_open(const char *path, OiioInput **handle, int *width, int *height,
                 int *channels, int *origin_and_full, int *integer_format, int *alpha_channel,
                 int *unassociated_alpha, char *err, size_t err_len) {
    return guarded(err, err_len, [&] {
        *handle = nullptr;
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) {
            set_error(err, err_len, oiio_reason(""));
            return 1;
        }
        const OIIO::ImageSpec &spec = in->spec();
        if (spec.depth > 1) {
            set_error(err, err_len, "volume images (depth " + std::to_string(spec.depth) +
                                        ") are not supported");
            return 1;
        }
        *width = spec.width;
        *height = spec.height;
        *channels = spec.nchannels;
        origin_and_full[0] = spec.x - spec.full_x;
        origin_and_full[1] = spec.y - spec.full_y;
        origin_and_full[2] = spec.full_width;
        origin_and_full[3] = spec.full_height;
        *integer_format = spec.format.is_floating_point() ? 0 : 1;
        *alpha_channel = spec.alpha_channel;
        *unassociated_alpha = spec.get_int_attribute("oiio:UnassociatedAlpha", 0) ? 1 : 0;
        *handle = new OiioInput{std::move(in)};
        return 0;
    });
}

// Reads the whole first subimage as interleaved floats into `pixels`, which holds
// `len` floats (width * height * channels from hairtrace_oiio_open).
int hairtrace_oiio_read(OiioInput *handle, float *pixels, size_t len, char *err, size_t err_len) {
    return guarded(err, err_len, [&] {
        const OIIO::ImageSpec &spec = handle->in->spec();
        size_t expected = size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels);
        if (len != expected) {
            set_error(err, err_len, "pixel buffer holds " + std::to_string(len) +
                                        " floats, the image needs " + std::to_string(expected));
            return 1;
        }
        if (!handle->in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels)) {
            set_error(err, err_len, oiio_reason(handle->in->geterror()));
            return 1;
        }
        return 0;
    });
}

// The open file's string attributes as NUL-terminated names and values one after the
// other, in `buf` of `len` bytes; `*needed` is the size they take, so a caller whose
// buffer was too small (nothing is written then) calls again with a larger one.
int hairtrace_oiio_attributes(OiioInput *handle, char *buf, size_t len, size_t *needed,
                              char *err, size_t err_len) {
    return guarded(err, err_len, [&] {
        std::string all;
        for (const OIIO::ParamValue &p : handle->in->spec().extra_attribs) {
            if (p.type() != OIIO::TypeDesc::STRING || p.nvalues() != 1)
                continue;
            all += p.name().string();
            all += '\0';
            all += p.get_string();
            all += '\0';
        }
        *needed = all.size();
        if (all.size() <= len && !all.empty())
            std::memcpy(buf, all.data(), all.size());
        return 0;
    });
}

// Closes the file and frees the handle; NULL is a no-op.
void hairtrace_oiio_close(OiioInput *handle) {
    if (handle == nullptr)
        return;
    try {
        handle->in->close();
    } catch (...) {
        // Nothing useful to report from a close after a completed read.
    }
    delete handle;
}

}  // extern "C"
