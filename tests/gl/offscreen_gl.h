// An OpenGL 3.3 core context drawing into memory (OSMesa, llvmpipe), for the viewer's GL tests.
#pragma once

// GL prototypes first (GL_GLEXT_PROTOTYPES), then OSMesa, which includes GL/gl.h too.
#include "app/viewer/gl.h"
// (kept apart so the include sorter leaves this order)
#include <GL/osmesa.h>

#include <vector>

#include "app/viewer/image_view.h"

namespace lancer::viewer::testing {

class OffscreenGl {
  public:
    /// A w x h colour buffer, with a depth buffer when `depthBits` > 0.
    OffscreenGl(int w, int h, int depthBits = 0)
        : w_(w), h_(h), buffer_(size_t(w) * size_t(h) * 4) {
        const int attribs[] = {OSMESA_FORMAT,
                               OSMESA_RGBA,
                               OSMESA_DEPTH_BITS,
                               depthBits,
                               OSMESA_PROFILE,
                               OSMESA_CORE_PROFILE,
                               OSMESA_CONTEXT_MAJOR_VERSION,
                               3,
                               OSMESA_CONTEXT_MINOR_VERSION,
                               3,
                               0};
        ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
        if (ctx_ && !OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, w, h)) {
            OSMesaDestroyContext(ctx_);
            ctx_ = nullptr;
        }
    }
    ~OffscreenGl() {
        if (ctx_) OSMesaDestroyContext(ctx_);
    }
    OffscreenGl(const OffscreenGl&) = delete;
    OffscreenGl& operator=(const OffscreenGl&) = delete;
    bool ok() const { return ctx_ != nullptr; }
    /// The framebuffer as RGBA8, row 0 on top.
    std::vector<uint8_t> read() const {
        glFinish();
        return readFramebuffer(w_, h_);
    }
    /// Fill the framebuffer with one colour.
    void clear(float r, float g, float b) const {
        glViewport(0, 0, w_, h_);
        glClearColor(r, g, b, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }

  private:
    int w_, h_;
    std::vector<uint8_t> buffer_;
    OSMesaContext ctx_ = nullptr;
};

}  // namespace lancer::viewer::testing
