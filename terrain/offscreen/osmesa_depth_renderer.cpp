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

namespace {

// Eye space of one render: x = p.u - a_mid, y = p.v - b_mid, z = p.w - c_hi
// (<= 0, the source at z = 0), with the depth range [z_near, z_far] enclosing
// the geometry.
struct EyeSpace {
  double a_mid, b_mid, c_hi, z_near, z_far;
};

EyeSpace eye_space(const DepthMap& map, double c_lo, double c_hi) {
  const double margin = 1e-3 * (c_hi - c_lo) + 1e-3;
  return {map.a0 + 0.5 * map.width * map.texel, map.b0 + 0.5 * map.height * map.texel, c_hi,
          -margin, (c_hi - c_lo) + margin};
}

void load_view(const LightFrame& f, const EyeSpace& eye) {
  const GLdouble view[16] = {f.u.x(), f.v.x(), f.w.x(), 0, f.u.y(),    f.v.y(),    f.w.y(),   0,
                             f.u.z(), f.v.z(), f.w.z(), 0, -eye.a_mid, -eye.b_mid, -eye.c_hi, 1};
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view);
}

// A tile of the map in eye-space x (left) and y (bottom), `w` x `h` texels.
struct Tile {
  int x, y, w, h;
  double left, bottom, right, top;
};

Tile tile_at(const DepthMap& map, const EyeSpace& eye, int tx, int ty) {
  Tile t{tx, ty, std::min(kTile, map.width - tx), std::min(kTile, map.height - ty), 0, 0, 0, 0};
  t.left = map.a0 + tx * map.texel - eye.a_mid;
  t.bottom = map.b0 + ty * map.texel - eye.b_mid;
  t.right = t.left + t.w * map.texel;
  t.top = t.bottom + t.h * map.texel;
  return t;
}

// Rows [row0, row1] of the height field with their height range, so that a
// chunk outside a tile is not drawn.
struct GroundChunk {
  int row0, row1;
  double h_lo, h_hi;
};

std::vector<GroundChunk> ground_chunks(const GroundGeometry* ground) {
  std::vector<GroundChunk> chunks;
  if (!ground || !ground->heights) return chunks;
  const auto& h = *ground->heights;
  for (int r0 = 0; r0 < h.height() - 1; r0 += kGroundChunk) {
    const int r1 = std::min(r0 + kGroundChunk, h.height() - 1);
    double lo = 1e300, hi = -1e300;
    for (int r = r0; r <= r1; ++r)
      for (int x = 0; x < h.width(); ++x)
        lo = std::min<double>(lo, h(x, r)), hi = std::max<double>(hi, h(x, r));
    chunks.push_back({r0, r1, lo, hi});
  }
  return chunks;
}

// Does the light-space box of the chunk's world box overlap the tile?
bool chunk_meets_tile(const GroundGeometry& ground, const GroundChunk& chunk, const LightFrame& f,
                      const EyeSpace& eye, const Tile& tile) {
  const auto& h = *ground.heights;
  double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p(ground.x0 + ((corner & 1) ? (h.width() - 1) * ground.dx : 0.0),
                            ground.y0 - ((corner & 2) ? chunk.row1 : chunk.row0) * ground.dy,
                            (corner & 4) ? chunk.h_hi : chunk.h_lo);
    const double a = p.dot(f.u) - eye.a_mid, b = p.dot(f.v) - eye.b_mid;
    a_lo = std::min(a_lo, a), a_hi = std::max(a_hi, a);
    b_lo = std::min(b_lo, b), b_hi = std::max(b_hi, b);
  }
  return !(a_hi < tile.left || a_lo > tile.right || b_hi < tile.bottom || b_lo > tile.top);
}

// Vertex and index buffers reused across draws.
struct DrawBuffers {
  std::vector<float> vertices;
  std::vector<GLuint> indices;

  void draw() const {
    glVertexPointer(3, GL_FLOAT, 0, vertices.data());
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT,
                   indices.data());
  }
};

void draw_mesh(const Mesh& mesh, DrawBuffers& buffers) {
  buffers.vertices.resize(mesh.positions.size() * 3);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) buffers.vertices[3 * i + k] = mesh.positions[i][k];
  buffers.indices.resize(mesh.triangles.size() * 3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      buffers.indices[3 * t + k] = static_cast<GLuint>(mesh.triangles[t][k]);
  buffers.draw();
}

// The chunk's rows as two triangles per cell.
void draw_ground_chunk(const GroundGeometry& ground, const GroundChunk& chunk,
                       DrawBuffers& buffers) {
  const auto& h = *ground.heights;
  const int w = h.width(), rows = chunk.row1 - chunk.row0 + 1;
  buffers.vertices.resize(static_cast<std::size_t>(w) * rows * 3);
  for (int r = 0; r < rows; ++r)
    for (int x = 0; x < w; ++x) {
      float* v = &buffers.vertices[(static_cast<std::size_t>(r) * w + x) * 3];
      v[0] = static_cast<float>(ground.x0 + x * ground.dx);
      v[1] = static_cast<float>(ground.y0 - (chunk.row0 + r) * ground.dy);
      v[2] = h(x, chunk.row0 + r);
    }
  buffers.indices.clear();
  for (int r = 0; r + 1 < rows; ++r)
    for (int x = 0; x + 1 < w; ++x) {
      const GLuint i00 = static_cast<GLuint>(r * w + x), i10 = i00 + 1;
      const GLuint i01 = i00 + static_cast<GLuint>(w), i11 = i01 + 1;
      buffers.indices.insert(buffers.indices.end(), {i00, i01, i10, i10, i01, i11});
    }
  buffers.draw();
}

// Reads the tile's depth buffer back into map.top (empty where nothing was drawn).
void read_tile_depth(DepthMap& map, const EyeSpace& eye, const Tile& tile,
                     std::vector<float>& depth) {
  depth.resize(static_cast<std::size_t>(tile.w) * tile.h);
  glReadPixels(0, 0, tile.w, tile.h, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  check_gl("render a depth map");
  for (int j = 0; j < tile.h; ++j)
    for (int i = 0; i < tile.w; ++i) {
      const float d = depth[static_cast<std::size_t>(j) * tile.w + i];
      if (d >= 1.0f) continue;
      map.top[static_cast<std::size_t>(tile.y + j) * map.width + tile.x + i] =
          static_cast<float>(-(eye.z_near + d * (eye.z_far - eye.z_near)));
    }
}

}  // namespace

void OsmesaDepthRenderer::render(DepthMap& map, double c_lo, double c_hi,
                                 const std::vector<const Mesh*>& meshes,
                                 const GroundGeometry* ground) {
  if (!OSMesaMakeCurrent(impl_->context, impl_->pixel.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw Error("cannot make the OSMesa context current");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
  map.top.assign(static_cast<std::size_t>(map.width) * map.height, DepthMap::kEmpty);
  map.c_ref = c_hi;
  const EyeSpace eye = eye_space(map, c_lo, c_hi);
  load_view(map.frame, eye);
  glEnableClientState(GL_VERTEX_ARRAY);
  const std::vector<GroundChunk> chunks = ground_chunks(ground);
  DrawBuffers buffers;
  std::vector<float> depth;
  for (int ty = 0; ty < map.height; ty += kTile) {
    for (int tx = 0; tx < map.width; tx += kTile) {
      const Tile tile = tile_at(map, eye, tx, ty);
      glViewport(0, 0, tile.w, tile.h);
      glMatrixMode(GL_PROJECTION);
      glLoadIdentity();
      glOrtho(tile.left, tile.right, tile.bottom, tile.top, eye.z_near, eye.z_far);
      glClearDepth(1.0);
      glClear(GL_DEPTH_BUFFER_BIT);
      for (const Mesh* mesh : meshes) draw_mesh(*mesh, buffers);
      for (const GroundChunk& chunk : chunks)
        if (chunk_meets_tile(*ground, chunk, map.frame, eye, tile))
          draw_ground_chunk(*ground, chunk, buffers);
      read_tile_depth(map, eye, tile, depth);
    }
  }
  glDisableClientState(GL_VERTEX_ARRAY);
}

}  // namespace drift::terrain
