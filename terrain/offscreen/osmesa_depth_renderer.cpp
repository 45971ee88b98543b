#include "terrain/offscreen/osmesa_depth_renderer.h"

#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "terrain/error.h"

namespace drift::terrain {

namespace {
constexpr int kTile = 4096;       // texels a side per draw (64 MiB of float depth)
constexpr int kGroundChunk = 64;  // rows of the height field per draw call

void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    throw Error(std::string("OpenGL (OSMesa) failed to ") + what + " (error 0x" +
                std::to_string(e) + "); is Mesa's llvmpipe installed?");
  }
}
}  // namespace

struct OsmesaDepthRenderer::Impl {
  OSMesaContext context = nullptr;
  std::array<unsigned char, 4> pixel{};  // the default framebuffer is unused
  GLuint fbo = 0, depth = 0;
};

OsmesaDepthRenderer::OsmesaDepthRenderer() : impl_(std::make_unique<Impl>()) {
  impl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (!impl_->context) throw Error("cannot create an OSMesa context (off-screen OpenGL)");
  if (!OSMesaMakeCurrent(impl_->context, impl_->pixel.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    OSMesaDestroyContext(impl_->context);
    throw Error("cannot make the OSMesa context current");
  }
  glGenFramebuffers(1, &impl_->fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
  glGenRenderbuffers(1, &impl_->depth);
  glBindRenderbuffer(GL_RENDERBUFFER, impl_->depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, kTile, kTile);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, impl_->depth);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw Error("OSMesa: the 32-bit float depth framebuffer is incomplete");
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // either side of a surface stops snow or touches ground
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  check_gl("set up the depth framebuffer");
}

OsmesaDepthRenderer::~OsmesaDepthRenderer() {
  if (!impl_ || !impl_->context) return;
  glDeleteRenderbuffers(1, &impl_->depth);
  glDeleteFramebuffers(1, &impl_->fbo);
  OSMesaDestroyContext(impl_->context);
}

void OsmesaDepthRenderer::render(DepthMap& map, double c_lo, double c_hi,
                                 const std::vector<const Mesh*>& meshes,
                                 const GroundGeometry* ground) {
  if (!OSMesaMakeCurrent(impl_->context, impl_->pixel.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw Error("cannot make the OSMesa context current");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
  map.top.assign(static_cast<std::size_t>(map.width) * map.height, DepthMap::kEmpty);
  map.c_ref = c_hi;
  const LightFrame& f = map.frame;
  // Eye space: x = p.u - a_mid, y = p.v - b_mid, z = p.w - c_hi (<= 0, the source at z = 0).
  const double a_mid = map.a0 + 0.5 * map.width * map.texel;
  const double b_mid = map.b0 + 0.5 * map.height * map.texel;
  const double margin = 1e-3 * (c_hi - c_lo) + 1e-3;
  const double z_near = -margin, z_far = (c_hi - c_lo) + margin;
  const GLdouble view[16] = {f.u.x(), f.v.x(), f.w.x(), 0, f.u.y(), f.v.y(), f.w.y(), 0,
                             f.u.z(), f.v.z(), f.w.z(), 0, -a_mid,  -b_mid,  -c_hi,   1};
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view);
  glEnableClientState(GL_VERTEX_ARRAY);

  // Ground chunks with their bounding boxes, for culling against each tile.
  struct Chunk {
    int row0, row1;
    double h_lo, h_hi;
  };
  std::vector<Chunk> chunks;
  if (ground && ground->heights) {
    const auto& h = *ground->heights;
    for (int r0 = 0; r0 < h.height() - 1; r0 += kGroundChunk) {
      const int r1 = std::min(r0 + kGroundChunk, h.height() - 1);
      double lo = 1e300, hi = -1e300;
      for (int r = r0; r <= r1; ++r)
        for (int x = 0; x < h.width(); ++x)
          lo = std::min<double>(lo, h(x, r)), hi = std::max<double>(hi, h(x, r));
      chunks.push_back({r0, r1, lo, hi});
    }
  }
  std::vector<float> vertices;
  std::vector<GLuint> indices;
  std::vector<float> depth;

  for (int ty = 0; ty < map.height; ty += kTile) {
    for (int tx = 0; tx < map.width; tx += kTile) {
      const int tw = std::min(kTile, map.width - tx), th = std::min(kTile, map.height - ty);
      const double left = map.a0 + tx * map.texel - a_mid, bottom = map.b0 + ty * map.texel - b_mid;
      glViewport(0, 0, tw, th);
      glMatrixMode(GL_PROJECTION);
      glLoadIdentity();
      glOrtho(left, left + tw * map.texel, bottom, bottom + th * map.texel, z_near, z_far);
      glClearDepth(1.0);
      glClear(GL_DEPTH_BUFFER_BIT);

      for (const Mesh* mesh : meshes) {
        vertices.resize(mesh->positions.size() * 3);
        for (std::size_t i = 0; i < mesh->positions.size(); ++i)
          for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh->positions[i][k];
        indices.resize(mesh->triangles.size() * 3);
        for (std::size_t t = 0; t < mesh->triangles.size(); ++t)
          for (int k = 0; k < 3; ++k)
            indices[3 * t + k] = static_cast<GLuint>(mesh->triangles[t][k]);
        glVertexPointer(3, GL_FLOAT, 0, vertices.data());
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT,
                       indices.data());
      }
      for (const Chunk& chunk : chunks) {
        const auto& h = *ground->heights;
        // Cull: light-space box of the chunk's world box against the tile.
        double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
        for (int corner = 0; corner < 8; ++corner) {
          const Eigen::Vector3d p(
              ground->x0 + ((corner & 1) ? (h.width() - 1) * ground->dx : 0.0),
              ground->y0 - ((corner & 2) ? chunk.row1 : chunk.row0) * ground->dy,
              (corner & 4) ? chunk.h_hi : chunk.h_lo);
          const double a = p.dot(f.u) - a_mid, b = p.dot(f.v) - b_mid;
          a_lo = std::min(a_lo, a), a_hi = std::max(a_hi, a);
          b_lo = std::min(b_lo, b), b_hi = std::max(b_hi, b);
        }
        if (a_hi < left || a_lo > left + tw * map.texel || b_hi < bottom ||
            b_lo > bottom + th * map.texel)
          continue;
        const int w = h.width(), rows = chunk.row1 - chunk.row0 + 1;
        vertices.resize(static_cast<std::size_t>(w) * rows * 3);
        for (int r = 0; r < rows; ++r)
          for (int x = 0; x < w; ++x) {
            float* v = &vertices[(static_cast<std::size_t>(r) * w + x) * 3];
            v[0] = static_cast<float>(ground->x0 + x * ground->dx);
            v[1] = static_cast<float>(ground->y0 - (chunk.row0 + r) * ground->dy);
            v[2] = h(x, chunk.row0 + r);
          }
        indices.clear();
        for (int r = 0; r + 1 < rows; ++r)
          for (int x = 0; x + 1 < w; ++x) {
            const GLuint i00 = static_cast<GLuint>(r * w + x), i10 = i00 + 1;
            const GLuint i01 = i00 + static_cast<GLuint>(w), i11 = i01 + 1;
            indices.insert(indices.end(), {i00, i01, i10, i10, i01, i11});
          }
        glVertexPointer(3, GL_FLOAT, 0, vertices.data());
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT,
                       indices.data());
      }
      depth.resize(static_cast<std::size_t>(tw) * th);
      glReadPixels(0, 0, tw, th, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
      check_gl("render a depth map");
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i) {
          const float d = depth[static_cast<std::size_t>(j) * tw + i];
          if (d >= 1.0f) continue;
          map.top[static_cast<std::size_t>(ty + j) * map.width + tx + i] =
              static_cast<float>(-(z_near + d * (z_far - z_near)));
        }
    }
  }
  glDisableClientState(GL_VERTEX_ARRAY);
}

}  // namespace drift::terrain
